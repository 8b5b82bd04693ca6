/* rad - command-line tool built on radiosity.h.

   This first version knows the built-in Cornell box ("cornell") and prints group form
   factors between its named objects, the quantity a radiosity course starts from:

       rad formfactors cornell [--patches N] [--samples S] [--threads N]

   prints one line "FROM TO VALUE" per ordered pair of objects, where VALUE is the
   area-weighted group form factor F_GH = sum_{i in G} A_i sum_{j in H} F_ij / sum_{i in G} A_i.
   Reading scene files arrives with the importer (see the issues); the scene argument
   accepts only "cornell" until then and says so. */
#define RADIOSITY_IMPLEMENTATION
#include "radiosity.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif
#if defined(__unix__) || defined(__APPLE__)
#include <unistd.h>
#define RAD_TOOL_ISATTY(fd) isatty(fd)
#else
#define RAD_TOOL_ISATTY(fd) 0
#endif

static void usage(FILE *f)
{
    fprintf(f, "usage: rad COMMAND [options]\n"
               "commands:\n"
               "  help                     this text\n"
               "  version                  the library version\n"
               "  formfactors SCENE        group form factors between the scene's named objects\n"
               "                           options: --patches N (default 2000), --samples S (default 16),\n"
               "                                    --threads N (default: all)\n"
               "SCENE is 'cornell' (the built-in Cornell box).\n");
}

static int progress(void *user, float fraction)
{
    static int last = -1;
    int pct = (int)(fraction * 100.0f);
    (void)user;
    if (pct != last) {
        last = pct;
        if (RAD_TOOL_ISATTY(2)) fprintf(stderr, "\r  %3d%%", pct);
        else if (pct % 10 == 0) fprintf(stderr, "  %d%%\n", pct);
        if (pct >= 100 && RAD_TOOL_ISATTY(2)) fprintf(stderr, "\n");
    }
    return 0;
}

static void log_message(void *user, rad_log_level level, const char *message)
{
    (void)user;
    fprintf(stderr, "rad: %s: %s\n", level == RAD_LOG_ERROR ? "error" : "warning", message);
}

static int fail(const char *what, rad_result r)
{
    fprintf(stderr, "rad: %s failed: %s\n", what, rad_result_string(r));
    return 1;
}

static int cmd_formfactors(int argc, char **argv)
{
    const char *scene_name = NULL;
    uint32_t patches_target = 2000, samples = 16, G, H, i, j;
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    rad_patches *P = NULL;
    rad_bvh *bvh = NULL;
    rad_form_factors *ff = NULL;
    rad_raycaster rc;
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_context ctx;
    rad_result r;
    double *num, *den;
    int a;
    for (a = 0; a < argc; ++a) {
        if (!strcmp(argv[a], "--help") || !strcmp(argv[a], "-h")) { usage(stdout); return 0; }
        if (!strcmp(argv[a], "--patches") && a + 1 < argc) patches_target = (uint32_t)strtoul(argv[++a], NULL, 10);
        else if (!strcmp(argv[a], "--samples") && a + 1 < argc) samples = (uint32_t)strtoul(argv[++a], NULL, 10);
        else if (!strcmp(argv[a], "--threads") && a + 1 < argc) {
            int t = atoi(argv[++a]);
#ifdef _OPENMP
            if (t > 0) omp_set_num_threads(t);
#else
            (void)t;
#endif
        } else if (argv[a][0] == '-') { fprintf(stderr, "rad formfactors: unknown option '%s'\n", argv[a]); return 2; }
        else if (!scene_name) scene_name = argv[a];
        else { fprintf(stderr, "rad formfactors: more than one scene given\n"); return 2; }
    }
    if (!scene_name) { fprintf(stderr, "rad formfactors: no scene given\n"); usage(stderr); return 2; }
    if (strcmp(scene_name, "cornell") != 0) {
        fprintf(stderr, "rad formfactors: '%s': only the built-in scene 'cornell' can be read so far "
                        "(scene files need the importer, not built yet)\n", scene_name);
        return 2;
    }
    if (patches_target == 0 || samples == 0) { fprintf(stderr, "rad formfactors: --patches and --samples must be > 0\n"); return 2; }
    memset(&ctx, 0, sizeof(ctx));
    ctx.log = log_message;
    ctx.progress = progress;
    rad_cornell_box(&desc, NULL);
    if ((r = rad_scene_create(&desc, &ctx, &scene)) != RAD_SUCCESS) return fail("scene", r);
    rad_patch_options_default(&po);
    po.target_count = patches_target;
    if ((r = rad_patches_create(scene, &po, &ctx, &P)) != RAD_SUCCESS) return fail("patches", r);
    if ((r = rad_bvh_create(scene, &ctx, &bvh)) != RAD_SUCCESS) return fail("bvh", r);
    rad_bvh_raycaster(bvh, &rc);
    rad_form_factor_options_default(&fo);
    fo.samples = samples;
    fprintf(stderr, "form factors of %u patches\n", P->count);
    if ((r = rad_form_factors_dense(P, &rc, &fo, &ctx, &ff)) != RAD_SUCCESS) return fail("form factors", r);
    G = scene->mesh_count;
    num = (double *)calloc((size_t)G * G, sizeof(double));
    den = (double *)calloc(G, sizeof(double));
    if (!num || !den) { fprintf(stderr, "rad: out of memory\n"); return 1; }
    for (i = 0; i < P->count; ++i) {
        uint32_t gi = scene->meshes[P->patches[i].triangle];
        const float *row = ff->matrix.dense + (size_t)i * P->count;
        den[gi] += P->areas[i];
        for (j = 0; j < P->count; ++j) num[(size_t)gi * G + scene->meshes[P->patches[j].triangle]] += (double)P->areas[i] * row[j];
    }
    for (G = 0; G < scene->mesh_count; ++G)
        for (H = 0; H < scene->mesh_count; ++H)
            printf("%s %s %.6f\n", scene->mesh_names[G], scene->mesh_names[H], num[(size_t)G * scene->mesh_count + H] / den[G]);
    free(num);
    free(den);
    rad_form_factors_destroy(ff);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(P);
    rad_scene_destroy(scene);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 2 || !strcmp(argv[1], "help") || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
        usage(argc < 2 ? stderr : stdout);
        return argc < 2 ? 2 : 0;
    }
    if (!strcmp(argv[1], "version")) { printf("radiosity.h %s\n", RAD_VERSION_STRING); return 0; }
    if (!strcmp(argv[1], "formfactors")) return cmd_formfactors(argc - 2, argv + 2);
    fprintf(stderr, "rad: unknown command '%s' (try 'rad help')\n", argv[1]);
    return 2;
}
