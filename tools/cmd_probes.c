/* cmd_probes.c - `rad probes`: irradiance probes (SH L2) from the classic solution or from
   virtual patches.

   rad probes SCENE -o OUT.json|OUT.bin [--spacing S] [--rays R] [--patch-samples N] [--indirect]
              [--band4] [--proxy aavp|vp [--vp-resolution R | --vp-max-patches B] [--face-points P]
              [--vp-rays N]]
              [classic options: --patches N ...] [lights: --sun, --sky, --point, --spot, --area]
              [--threads N]

   Solves the scene as `rad bake` does (B = E + L with the direct light as the source, emitters
   out of the system), or with --proxy aavp|vp over virtual patches as `rad lightmap --proxy`
   does (tool_vp_proxy_solve; rad_probes_create_vp gathers the probes from them: a scene too
   big for the dense classic build is refused without --proxy, naming it), places a probe grid over the scene's bounds (rad_probes_create; probes
   inside geometry moved out or disabled) and writes every probe's position, state and its 27
   irradiance coefficients (docs/methods/probes.md). By default the probes hold all the light
   (the direct light of the emitters and the file's lights is added: RAD_PROBES_DIRECT);
   --indirect keeps only the indirect light, for a renderer that draws direct light per pixel.
   --band4 also bakes and writes the 9 band-4 coefficients per colour (RAD_PROBES_BAND4): the
   irradiance is then E(n) = sum_i E_i Y_i(n) + sum_m F_m Z_m(n) (rad_sh_l4_irradiance).

   OUT.json: { "format": "radiosity.h probes", "version": 1, "basis": ..., "light": "total" or
   "indirect", "grid": { "dims": [x, y, z], "origin": [x, y, z], "spacing": s }, "count": n,
   "probes": [ { "p": [x, y, z], "state": "valid"|"moved"|"disabled", "sh": [[r, g, b] x 9] } ] }
   with --band4 also "basis_band4" and per probe "band4": [[r, g, b] x 9] (F_0..F_8).
   OUT.bin (little-endian, all 4-byte fields): "RADPROBE" (8 bytes), version 1, count, flags (1:
   total light, 2: band 4), dims[3], origin[3] (float), spacing (float), then per probe
   position[3] (float), state (uint32, rad_probe_state), coefficients[27] (float, E_i of channel
   c at 3 i + c) and, with flag 2, band4[27] (float, F_m of channel c at 3 m + c).
   The file is written to a temporary and renamed into place. */
#include "tool.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* rad probes' command line */
typedef struct probes_args {
    const char *scene, *out;
    tool_classic_options o;
    rad_probe_options po;
    tool_lightmap_proxy px;  /* --proxy and the virtual patches' options */
    uint32_t threads;
    int indirect;            /* --indirect: only the indirect light */
    int band4;               /* --band4 */
    uint32_t given;          /* PROBES_GIVEN_* */
} probes_args;
enum { PROBES_GIVEN_VP = 1, PROBES_GIVEN_VP_RAYS = 2, PROBES_GIVEN_PATCH_SAMPLES = 4, PROBES_GIVEN_PROXY = 8 };

static int parse_threads(const char *cmd, const tool_arg *t, const char *v, void *field)
{
    return tool_parse_threads(cmd, t->name, v, (uint32_t *)field) ? 2 : 0;
}

static const uint32_t proxy_values[] = {TOOL_PROXY_PATCHES, TOOL_PROXY_AAVP, TOOL_PROXY_VP};
#define PA(f) offsetof(probes_args, f)
#define PA_UINT(name, val, f, lo, hi, given, bad, help) \
    {TOOL_ARG_UINT, name, val, PA(f), lo, hi, 0, given, bad, NULL, NULL, NULL, 0, help}
#define PA_FLAG(name, f, help) {TOOL_ARG_FLAG, name, NULL, PA(f), 1, 0, 0, 0, NULL, NULL, NULL, NULL, 0, help}
/* rad probes' own options (the classic and light options are classic.c's and lights.c's) */
static const tool_arg probes_table[] = {
    {TOOL_ARG_STRING, "-o", "FILE", PA(out), 0, 0, 0, 0, NULL, NULL, NULL, NULL, 0,
     "OUT.json (text) or OUT.bin (binary; layout in tools/cmd_probes.c)"},
    {TOOL_ARG_FLOAT, "--spacing", "S", PA(po.spacing), 0.0, 1e30, TOOL_ARG_LO_OPEN, 0, "must be > 0", NULL, NULL, NULL, 0,
     "grid spacing in scene units (default: the largest extent / 8)"},
    PA_UINT("--rays", "R", po.rays, 1, 65536, 0, "must be in 1..65536",
            "rays per probe for the inside-geometry test (default 256)"),
    PA_UINT("--patch-samples", "N", po.patch_samples, 1, 256, PROBES_GIVEN_PATCH_SAMPLES, "must be in 1..256",
            "points per patch for the probes' gather (default 4; classic patches)"),
    PA_FLAG("--indirect", indirect, "only the indirect light (default: direct light too)"),
    PA_FLAG("--band4", band4, "also band 4 (9 more coefficients per colour: sharper E(n) than L2)"),
    {TOOL_ARG_CHOICE, "--proxy", "P", PA(px.kind), 0, 0, 0, PROBES_GIVEN_PROXY, NULL, "patches|aavp|vp", proxy_values, NULL, 0,
     "the light from classic patches (patches, the default) or from virtual patches, aavp or vp:\n"
     "a few thousand unknowns whatever the triangle count, for real buildings (rad_probes_create_vp)"},
    PA_UINT("--vp-resolution", "R", px.resolution, 1, 4096, PROBES_GIVEN_VP, "must be 1 to 4096",
            "--proxy: voxels along the longest axis (default 16)"),
    PA_UINT("--vp-max-patches", "B", px.max_patches, 1, 4294967295.0, PROBES_GIVEN_VP, "must be at least 1",
            "--proxy: the finest resolution with at most B patches"),
    PA_UINT("--face-points", "P", px.face_points, 1, 4096, PROBES_GIVEN_VP, "must be 1 to 4096",
            "--proxy: Hammersley points per voxel face (default 16)"),
    PA_UINT("--vp-rays", "N", po.vp_rays, 1, 65536, PROBES_GIVEN_VP_RAYS, "must be in 1..65536",
            "--proxy: gather rays per probe (default 2048)"),
    {TOOL_ARG_CUSTOM, "--threads", "N", PA(threads), 0, 0, 0, 0, NULL, NULL, NULL, parse_threads, 0,
     "worker threads (default: all cores; at most 1024)"},
    {TOOL_ARG_END, NULL, NULL, 0, 0, 0, 0, 0, NULL, NULL, NULL, NULL, 0, NULL}
};

static void probes_usage(FILE *f)
{
    static char own[4096];
    tool_args_help_into(probes_table, 0, own, sizeof own);
    fprintf(f, "usage: rad probes SCENE -o OUT.json|OUT.bin [--spacing S] [--rays R] [--indirect] [--proxy aavp|vp] [options]\n"
               "Solves the scene (classic radiosity, or virtual patches with --proxy; direct light as the source) and\n"
               "bakes SH L2 irradiance probes on a grid over its bounds: E(n) = sum_i E_i Y_i(n) (docs/methods/probes.md).\n"
               "%s%s%s",
            own, tool_classic_help(), tool_light_help());
}

/* the command line into pa; -1: go on, else the exit code (--help 0; bad usage 2, printed) */
static int probes_parse(const char *cmd, int argc, char **argv, tool_lights *lights, probes_args *pa)
{
    int a, rc;
    size_t len;
    memset(pa, 0, sizeof *pa);
    tool_classic_options_default(&pa->o);
    rad_probe_options_default(&pa->po);
    for (a = 0; a < argc; ++a) {
        const char *opt = argv[a];
        if (!strcmp(opt, "--help") || !strcmp(opt, "-h")) {
            probes_usage(stdout);
            return 0;
        }
        if ((rc = tool_classic_option(cmd, argc, argv, &a, &pa->o)) == 0 &&
            (rc = tool_light_option(cmd, argc, argv, &a, lights)) == 0)
            rc = tool_args_parse(cmd, probes_table, pa, &pa->given, argc, argv, &a);
        if (rc == 2) return 2;
        if (rc == 1) continue;
        if (opt[0] == '-' && opt[1]) {
            fprintf(stderr, "rad %s: unknown option '%s' (see rad probes --help)\n", cmd, opt);
            return 2;
        }
        if (pa->scene) {
            fprintf(stderr, "rad %s: more than one scene given\n", cmd);
            return 2;
        }
        pa->scene = opt;
    }
    if (!pa->scene || !pa->out) {
        fprintf(stderr, "rad %s: %s\n", cmd, !pa->scene ? "no scene given" : "no output file given (-o OUT.json|OUT.bin)");
        probes_usage(stderr);
        return 2;
    }
    if ((pa->given & PROBES_GIVEN_VP) && !pa->px.kind) {
        fprintf(stderr, "rad %s: --vp-resolution, --vp-max-patches and --face-points are for --proxy aavp|vp\n", cmd);
        return 2;
    }
    if (pa->px.resolution && pa->px.max_patches) {
        fprintf(stderr, "rad %s: --vp-resolution and --vp-max-patches exclude each other\n", cmd);
        return 2;
    }
    if ((pa->given & PROBES_GIVEN_VP_RAYS) && !pa->px.kind) {
        fprintf(stderr, "rad %s: --vp-rays is for --proxy aavp|vp (classic patches: --patch-samples)\n", cmd);
        return 2;
    }
    if ((pa->given & PROBES_GIVEN_PATCH_SAMPLES) && pa->px.kind) {
        fprintf(stderr, "rad %s: --patch-samples is for classic patches (with --proxy: --vp-rays)\n", cmd);
        return 2;
    }
    if (pa->px.kind && pa->o.solver == TOOL_DIRECT) {
        fprintf(stderr, "rad %s: --solver direct is for classic patches: with --proxy use jacobi or gauss-seidel\n", cmd);
        return 2;
    }
    len = strlen(pa->out);
    if (!(len >= 5 && !strcmp(pa->out + len - 5, ".json")) && !(len >= 4 && !strcmp(pa->out + len - 4, ".bin"))) {
        fprintf(stderr, "rad %s: the output must end in .json or .bin: '%s'\n", cmd, pa->out);
        return 2;
    }
    if (pa->band4) pa->po.flags |= RAD_PROBES_BAND4;
    if (!pa->indirect) pa->po.flags |= RAD_PROBES_DIRECT;
    return -1;
}

static const char *state_name(uint8_t s)
{
    return s == RAD_PROBE_VALID ? "valid" : s == RAD_PROBE_MOVED ? "moved" : "disabled";
}

static int put_u32(FILE *f, uint32_t v)
{
    unsigned char b[4];
    b[0] = (unsigned char)v; b[1] = (unsigned char)(v >> 8); b[2] = (unsigned char)(v >> 16); b[3] = (unsigned char)(v >> 24);
    return fwrite(b, 1, 4, f) == 4;
}

static int put_f32(FILE *f, float x)
{
    uint32_t v;
    memcpy(&v, &x, 4);
    return put_u32(f, v);
}

/* What the file holds: the probes of the engine tier's result or of a rad_probes. */
typedef struct probes_view {
    uint32_t n, dims[3];
    float origin[3], spacing;
    const float *pos, *co, *b4;
    const uint8_t *st;
} probes_view;

/* 1 when every write succeeded */
static int write_probes(FILE *f, int json, const probes_view *v, int total)
{
    uint32_t n = v->n, i, k;
    const uint32_t *dims = v->dims;
    const float *origin = v->origin, spacing = v->spacing;
    const float *pos = v->pos, *co = v->co, *b4 = v->b4;
    const uint8_t *st = v->st;
    int ok = 1;
    if (json) {
        ok &= fprintf(f, "{\n  \"format\": \"radiosity.h probes\",\n  \"version\": 1,\n"
                         "  \"basis\": \"real SH L2, irradiance coefficients E_i (W/m^2): E(n) = sum_i E_i Y_i(n), "
                         "Y0 = 0.282095, Y1..3 = 0.488603 (y, z, x), Y4 = 1.092548 xy, Y5 = 1.092548 yz, "
                         "Y6 = 0.315392 (3z^2 - 1), Y7 = 1.092548 xz, Y8 = 0.546274 (x^2 - y^2)\",\n"
                         "  \"light\": \"%s\",\n  \"grid\": { \"dims\": [%u, %u, %u], \"origin\": [%.9g, %.9g, %.9g], "
                         "\"spacing\": %.9g },\n  \"count\": %u,\n  \"probes\": [\n",
                      total ? "total" : "indirect", dims[0], dims[1], dims[2], (double)origin[0], (double)origin[1],
                      (double)origin[2], (double)spacing, n) > 0;
        if (b4)
            ok &= fprintf(f, "  \"basis_band4\": \"band-4 irradiance coefficients F_m, added: E(n) += sum_m F_m Z_m(n), "
                             "Z0 = 2.503343 xy(x^2 - y^2), Z1 = 1.770131 yz(3x^2 - y^2), Z2 = 0.946175 xy(7z^2 - 1), "
                             "Z3 = 0.669047 yz(7z^2 - 3), Z4 = 0.105786 (35z^4 - 30z^2 + 3), Z5 = 0.669047 xz(7z^2 - 3), "
                             "Z6 = 0.473087 (x^2 - y^2)(7z^2 - 1), Z7 = 1.770131 xz(x^2 - 3y^2), "
                             "Z8 = 0.625836 (x^4 - 6x^2 y^2 + y^4)\",\n") > 0;
        for (i = 0; i < n && ok; ++i) {
            const float *c = co + 27 * (size_t)i;
            ok &= fprintf(f, "    { \"p\": [%.9g, %.9g, %.9g], \"state\": \"%s\", \"sh\": [", (double)pos[3 * i],
                          (double)pos[3 * i + 1], (double)pos[3 * i + 2], state_name(st[i])) > 0;
            for (k = 0; k < 9; ++k)
                ok &= fprintf(f, "%s[%.9g, %.9g, %.9g]", k ? ", " : "", (double)c[3 * k], (double)c[3 * k + 1],
                              (double)c[3 * k + 2]) > 0;
            if (b4) {
                const float *g = b4 + 27 * (size_t)i;
                ok &= fprintf(f, "], \"band4\": [") > 0;
                for (k = 0; k < 9; ++k)
                    ok &= fprintf(f, "%s[%.9g, %.9g, %.9g]", k ? ", " : "", (double)g[3 * k], (double)g[3 * k + 1],
                                  (double)g[3 * k + 2]) > 0;
            }
            ok &= fprintf(f, "] }%s\n", i + 1 < n ? "," : "") > 0;
        }
        ok &= fprintf(f, "  ]\n}\n") > 0;
        return ok;
    }
    ok &= fwrite("RADPROBE", 1, 8, f) == 8;
    ok &= put_u32(f, 1) && put_u32(f, n) && put_u32(f, (total ? 1u : 0u) | (b4 ? 2u : 0u));
    for (k = 0; k < 3; ++k) ok &= put_u32(f, dims[k]);
    for (k = 0; k < 3; ++k) ok &= put_f32(f, origin[k]);
    ok &= put_f32(f, spacing);
    for (i = 0; i < n && ok; ++i) {
        for (k = 0; k < 3; ++k) ok &= put_f32(f, pos[3 * (size_t)i + k]);
        ok &= put_u32(f, st[i]);
        for (k = 0; k < 27; ++k) ok &= put_f32(f, co[27 * (size_t)i + k]);
        if (b4)
            for (k = 0; k < 27; ++k) ok &= put_f32(f, b4[27 * (size_t)i + k]);
    }
    return ok;
}

/* The classic probes by the engine tier: one bake of the scene and its lights with the
   probes' options (RAD_PROBES_DIRECT unless --indirect, band 4), for the solver and patches
   it offers (Jacobi bounces on the patches as made); 1 (printed) on failure, -1 when the
   command line asks for what it does not offer. */
static int probes_baked(const char *cmd, const tool_world *w, const probes_args *pa, rad_baker_result **out)
{
    const tool_lightmap_proxy *px = &pa->px;
    rad_baker_desc d;
    rad_baker_options bo;
    uint32_t res = 0;
    *out = NULL;
    memset(&bo, 0, sizeof bo);
    if (px->kind && tool_vp_proxy_options(cmd, w, &pa->o, px, &bo, &res)) return 1;
    memset(&d, 0, sizeof d);
    d.outputs = RAD_BAKER_PROBES;
    d.probe_options = &pa->po;
    return tool_baker_run(cmd, w, &pa->o, px->kind ? RAD_BAKER_VIRTUAL_PATCHES : RAD_BAKER_CLASSIC, pa->o.bounces,
                          res, &bo, &d, out);
}

static int probes_main(int argc, char **argv, tool_lights *lights)
{
    const char *cmd = "probes";
    probes_args pa;
    tool_world w;
    tool_classic c;
    rad_virtual_patches *vp = NULL;
    float *vp_B = NULL;
    rad_probes *pr = NULL;
    rad_baker_result *R = NULL;
    probes_view v;
    char weights[64] = "";
    rad_context ctx;
    tool_output out;
    uint32_t i, counts[3] = {0, 0, 0};
    double t0 = tool_seconds(), tp;
    int rc, json, total;
    rad_result r;
    memset(&c, 0, sizeof c);
    if ((rc = probes_parse(cmd, argc, argv, lights, &pa)) >= 0) return rc;
    json = strlen(pa.out) >= 5 && !strcmp(pa.out + strlen(pa.out) - 5, ".json");
    total = !pa.indirect;
    if (tool_check_output(cmd, pa.out, &pa.scene, 1)) return 1;
    tool_set_threads((int)pa.threads);
    if (tool_open_world_lit(cmd, pa.scene, lights, &w)) return 1;
    /* no --proxy: the plan keeps the classic patches or takes virtual patches where their dense
       build would not fit */
    if (!(pa.given & PROBES_GIVEN_PROXY) &&
        tool_plan_proxy(cmd, &w, &pa.o, 0.0f, "the probes' light", &pa.px.kind, &pa.px.resolution)) {
        tool_close_world(&w);
        return 1;
    }
    /* a scene too big for the dense classic build is refused with the way out */
    pa.o.dense_instead = "--proxy aavp or --proxy vp (the probes' light from virtual patches: a few thousand whatever the "
                      "triangle count; --vp-resolution R sets how many)";
    if (probes_baked(cmd, &w, &pa, &R) == 1) {
        tool_close_world(&w);
        return 1;
    }
    if (R) {
        if (pa.px.kind)
            fprintf(stderr, "rad %s: %s virtual patches at resolution %u: %u patches (the engine tier's bake)\n", cmd,
                    pa.px.kind == TOOL_PROXY_VP ? "vp" : "aavp", R->vp_resolution, R->patch_count);
    } else if (pa.px.kind) {
        if (tool_vp_proxy_solve(cmd, &w, &pa.o, &pa.px, &vp, &vp_B, NULL, NULL)) {
            tool_close_world(&w);
            return 1;
        }
    } else if (tool_classic_solve(cmd, &w, &pa.o, &c)) {
        tool_close_world(&w);
        return 1;
    }
    tool_context(&ctx, "probes");
    tp = tool_seconds();
    r = R   ? RAD_SUCCESS
        : vp ? rad_probes_create_vp(vp, &w.rc, w.file.lights, w.file.light_count, NULL, 0, &pa.po, vp_B, &ctx, &pr)
             : rad_probes_create(c.patches, &w.rc, w.file.lights, w.file.light_count, NULL, 0, &pa.po, c.B, &ctx, &pr);
    tool_progress_end();
    rc = 1;
    if (r != RAD_SUCCESS) {
        tool_fail(cmd, vp ? "rad_probes_create_vp" : "rad_probes_create", r);
        goto done;
    }
    tp = tool_seconds() - tp;
    memset(&v, 0, sizeof v);
    if (R) {
        v.n = R->probe_count;
        memcpy(v.dims, R->probe_grid, sizeof v.dims);
        memcpy(v.origin, R->probe_origin, sizeof v.origin);
        v.spacing = R->probe_spacing;
        v.pos = R->probe_positions;
        v.co = R->probes;
        v.b4 = R->probe_band4;
        v.st = R->probe_states;
    } else {
        v.n = rad_probes_count(pr);
        rad_probes_grid(pr, v.dims, v.origin, &v.spacing);
        v.pos = rad_probes_positions(pr);
        v.co = rad_probes_coefficients(pr);
        v.b4 = rad_probes_band4(pr);
        v.st = rad_probes_states(pr);
    }
    for (i = 0; i < v.n; ++i) counts[v.st[i] % 3u]++;
    if (tool_output_open(&out, pa.out) != 0) {
        fprintf(stderr, "rad %s: %s\n", cmd, tool_output_error());
        goto done;
    }
    if (tool_output_commit(&out, write_probes(out.f, json, &v, total)) != 0) {
        fprintf(stderr, "rad %s: %s\n", cmd, tool_output_error());
        goto done;
    }
    if (pr) snprintf(weights, sizeof weights, ", %lu weights", (unsigned long)rad_probes_entry_count(pr));
    printf("wrote %s: %u probes (%u valid, %u moved out of geometry, %u disabled)%s, %s light%s%s\n", pa.out, v.n,
           counts[RAD_PROBE_VALID], counts[RAD_PROBE_MOVED], counts[RAD_PROBE_DISABLED], weights,
           total ? "total" : "indirect", v.b4 ? ", band 4" : "",
           pa.px.kind ? (pa.px.kind == TOOL_PROXY_VP ? ", over vp virtual patches" : ", over aavp virtual patches") : "");
    fprintf(stderr, "rad %s: probes gathered in %.2f s; done in %.2f s\n", cmd, tp, tool_seconds() - t0);
    rc = 0;
done:
    rad_baker_result_destroy(R);
    rad_probes_destroy(pr);
    free(vp_B);
    rad_vp_destroy(vp);
    tool_classic_free(&c);
    tool_close_world(&w);
    return rc;
}

int tool_cmd_probes(int argc, char **argv)
{
    tool_lights lights;
    int rc;
    memset(&lights, 0, sizeof lights);
    rc = probes_main(argc, argv, &lights);
    tool_lights_free(&lights);
    return rc;
}
