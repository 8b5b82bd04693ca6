/* rad - command-line tool built on radiosity.h: one program with subcommands.

       rad help | rad CMD --help
       rad formfactors SCENE   group form factors between the scene's named objects
       rad bake SCENE -o FILE.radb     a solution, saved (classic, multibounce, temporal, stochastic, vp, aavp)
       rad merge PART... -o FILE.radb  the parts of a sharded bake (bake --shard I/N) joined
       rad render SCENE -o OUT.png|OUT.pfm     an image (classic, multibounce or temporal
                                       radiosity, or path tracing)
       rad trace SCENE -o OUT  the reference path tracer
       (render, trace, bake: --sun, --sky, --point, --spot, --area, --env add lights: lights.c)
       rad compare A B         image metrics
       rad info FILE.radb      what a bake holds
       rad export SCENE -o OUT.obj     the scene as OBJ + MTL
       rad probes SCENE -o OUT.json|OUT.bin    irradiance probes (SH L2) on a grid
       rad lightmap SCENE -o OUT.pfm|OUT.png   a lightmap over the second uv set (cmd_lightmap.c)

   This file holds the dispatcher and the help; common.c holds the implementation of
   radiosity.h and the shared helpers of tool.h, cmd_*.c one command each. Exit codes: 0 ok,
   1 failure, 2 usage error. */
#include "tool.h"
#include <stdio.h>
#include <string.h>

/* ---- help ------------------------------------------------------------------------------ */

static void usage(FILE *f)
{
    fprintf(f, "usage: rad COMMAND [options]        (rad COMMAND --help for its options)\n"
               "commands:\n"
               "  help                     this text\n"
               "  version                  the library version\n"
               "  formfactors SCENE        group form factors between the scene's named objects\n"
               "  bake SCENE -o FILE.radb  compute and save a solution: --method classic|multibounce|temporal|\n"
               "                           stochastic|hierarchical|vp|aavp\n"
               "                           --shard I/N or --rows A:B: one part of it (docs/distributed.md)\n"
               "  merge PART... -o FILE    join the parts of a sharded bake into the bake itself\n"
               "  render SCENE -o OUT      render an image (.png, .pfm or .exr):\n"
               "                           --method classic|multibounce|temporal|local|stochastic|vp|aavp|\n"
               "                           hierarchical|lightmap|pathtrace\n"
               "                           [--bake FILE.radb]\n"
               "  trace SCENE -o OUT       the reference path tracer\n"
               "  compare A B              compare two images (MSE, PSNR, SSIM)\n"
               "  info FILE.radb | SCENE   list what a bake holds and check it; a scene's materials\n"
               "  export SCENE -o OUT.obj  write the scene as OBJ + MTL (Kd albedo, Ke emission)\n"
               "  probes SCENE -o OUT      irradiance probes (SH L2) on a grid: OUT.json or OUT.bin;\n"
               "                           --proxy aavp|vp for buildings too big for classic patches\n"
               "  lightmap SCENE -o OUT    bake a lightmap (.pfm or .png) over the second uv set, or an\n"
               "                           automatic unwrap; --sh for L1 spherical harmonics\n"
               "SCENE is 'cornell' (the built-in Cornell box) or a file assimp reads\n"
               "(OBJ+MTL, glTF 2.0, FBX, PLY ...). Every command takes --threads N (default: all cores;\n"
               "at most 1024). render, trace, bake, lightmap and probes add lights to the file's own:\n"
               "--sun DIR:RGB, --sky RGB, --point POS:RGB, --spot POS:DIR:ANGLES:RGB, --area P:U:V:RGB,\n"
               "--env FILE.hdr|.exr[:SCALE[:ROT]] (an equirectangular environment map)\n"
               "(units: rad render --help). Surfaces: --two-sided [auto|all|none] (every command; default\n"
               "auto: glTF doubleSided materials are two-sided, the rest one-sided as wound; bare\n"
               "--two-sided: all). Dense methods (classic, multibounce, temporal, local) refuse\n"
               "a build estimated beyond the free memory (--max-memory SIZE) or an hour; --force runs it\n"
               "anyway.\n");
}

/* ---- dispatch -------------------------------------------------------------------------- */

/* main.c calls it; tools/mpi/rad_mpi.c links the other sources with a main of its own */
int tool_main(int argc, char **argv)
{
    static const struct {
        const char *name;
        int (*fn)(int, char **);
    } cmds[] = {{"formfactors", tool_cmd_formfactors}, {"bake", tool_cmd_bake},       {"render", tool_cmd_render},
                {"trace", tool_cmd_trace},             {"compare", tool_cmd_compare}, {"info", tool_cmd_info},
                {"export", tool_cmd_export},           {"probes", tool_cmd_probes},   {"merge", tool_cmd_merge},
                {"lightmap", tool_cmd_lightmap}};
    size_t i;
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    if (!strcmp(argv[1], "help") || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
        if (argc > 2 && strcmp(argv[1], "help") == 0) {
            char *h[1];
            h[0] = (char *)"--help";
            for (i = 0; i < sizeof cmds / sizeof cmds[0]; ++i)
                if (!strcmp(argv[2], cmds[i].name)) return cmds[i].fn(1, h);
        }
        usage(stdout);
        return 0;
    }
    if (!strcmp(argv[1], "version") || !strcmp(argv[1], "--version")) {
        printf("rad (radiosity.h %s)\n", RAD_VERSION_STRING);
        return 0;
    }
    {
        /* --two-sided [MODE] applies to every command's scene: taken out of argv here */
        int a, o = 2;
        for (a = 2; a < argc; ++a) {
            if (!strcmp(argv[a], "--two-sided")) {
                if (a + 1 < argc && tool_two_sided_parse(argv[a + 1], &tool_two_sided) == 0) ++a;
                else if (a + 1 < argc && argv[a + 1][0] != '-' && strchr(argv[a + 1], '.') == NULL &&
                         strcmp(argv[a + 1], "cornell") != 0) {
                    fprintf(stderr, "rad: --two-sided wants auto, all or none, got '%s'\n", argv[a + 1]);
                    return 2;
                } else tool_two_sided = TOOL_TWO_SIDED_ALL;
                continue;
            }
            argv[o++] = argv[a];
        }
        argc = o;
    }
    for (i = 0; i < sizeof cmds / sizeof cmds[0]; ++i)
        if (!strcmp(argv[1], cmds[i].name)) return cmds[i].fn(argc - 2, argv + 2);
    fprintf(stderr, "rad: unknown command '%s' (try 'rad help')\n", argv[1]);
    return 2;
}
