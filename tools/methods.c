/* methods.c - the method options of `rad bake` and `rad render`: the table of --method and
   what goes with it, the checks of what excludes what, and the dense build's cost per method
   (tool_dense_plan). The bakes and the per-patch indirect light of the teaching methods are
   method_bake.c's. */
#include "tool.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- options ------------------------------------------------------------------------------ */

void tool_method_options_default(tool_method_options *mo)
{
    memset(mo, 0, sizeof *mo);
    mo->method = TOOL_CLASSIC;
    mo->bounces = 64;
    mo->format = TOOL_MB_BC4X3;
    mo->outliers = 0.05f;
    mo->reorder = RAD_REORDER_MATCH;
    mo->tile = 64;
    mo->mode = RAD_TEMPORAL_FEEDBACK;
    mo->k = 10;
    mo->w = 0.998f;
    /* a still image from `rad render --method temporal` alone should match classic: the
       adaptive weight (B is the running mean of the frames until the estimator's variance says
       otherwise) with 1024 frames. Measured against classic at the same patches (Cornell box,
       2188 patches, 64x64): the old default (fixed w 0.998, 64 frames: B reaches only
       1 - 0.998^64 = 12% of the light) PSNR 28.5 dB, SSIM 0.789; adaptive 64 frames 50.0 dB,
       0.9989; adaptive 1024 frames, the default, see CHANGELOG. A box of albedo 0.9 converges
       slower (many bounces): adaptive 256 frames SSIM 0.990, 1024 frames 0.9994. A frame
       costs k N draws (0.3 ms at N = 2188), so 1024 frames stay small beside the render. */
    mo->adaptive = 1;
    mo->frames = 1024;
    mo->every = 1;
    mo->vp_resolution = 16;
    mo->face_points = 16;
    mo->local_m = 0; /* every patch up to TOOL_LOCAL_M_AUTO_MAX (cmd_render.c) */
}

const char *tool_method_name(tool_method method)
{
    switch (method) {
    case TOOL_MULTIBOUNCE: return "multibounce";
    case TOOL_TEMPORAL: return "temporal";
    case TOOL_PATHTRACE: return "pathtrace";
    case TOOL_STOCHASTIC: return "stochastic";
    case TOOL_LOCAL: return "local";
    case TOOL_VP: return "vp";
    case TOOL_AAVP: return "aavp";
    case TOOL_HIERARCHICAL: return "hierarchical";
    case TOOL_LIGHTMAP: return "lightmap";
    default: return "classic";
    }
}

const char *tool_mb_format_name(uint32_t f)
{
    static const char *const names[] = {"float", "half", "bc1", "bc4x3"};
    return f < 4 ? names[f] : "?";
}

const char *tool_temporal_mode_name(uint32_t m)
{
    return m == RAD_TEMPORAL_SINGLE ? "single" : m == RAD_TEMPORAL_MULTIBOUNCE ? "multibounce" : "feedback";
}

/* --method: the names in tool_method order */
static const char method_names[] = "classic|multibounce|temporal|pathtrace|stochastic|local|vp|aavp|hierarchical|lightmap";

static int parse_method(const char *cmd, const tool_arg *t, const char *v, void *field)
{
    int i = 0;
    const char *p = method_names;
    (void)t;
    for (;;) {
        const char *e = strchr(p, '|');
        size_t len = e ? (size_t)(e - p) : strlen(p);
        if (strlen(v) == len && !strncmp(p, v, len)) break;
        if (!e) {
            fprintf(stderr, "rad %s: unknown method '%s' (classic, multibounce, temporal, stochastic%s)\n", cmd, v,
                    strcmp(cmd, "render") ? "" : ", pathtrace, local, vp, aavp, hierarchical or lightmap");
            return 2;
        }
        p = e + 1;
        ++i;
    }
    *(tool_method *)field = (tool_method)i;
    return 0;
}

static int parse_bounces(const char *cmd, const tool_arg *t, const char *v, void *field)
{
    uint32_t *b = (uint32_t *)field;
    if (!strcmp(v, "inf")) {
        *b = RAD_MB_INFINITE;
        return 0;
    }
    if (tool_parse_uint(cmd, t->name, v, b)) return 2;
    if (*b >= 0xFFFFFFF0u) {
        fprintf(stderr, "rad %s: --bounces %s is too large (use 'inf' for the full solution)\n", cmd, v);
        return 2;
    }
    return 0;
}

static int parse_tile(const char *cmd, const tool_arg *t, const char *v, void *field)
{
    uint32_t *tile = (uint32_t *)field;
    if (tool_parse_uint(cmd, t->name, v, tile)) return 2;
    if (*tile % 4 != 0) {
        fprintf(stderr, "rad %s: --tile must be a multiple of 4 (0: one scale per matrix), not %s\n", cmd, v);
        return 2;
    }
    return 0;
}

static int parse_hr_rays(const char *cmd, const tool_arg *t, const char *v, void *field)
{
    uint32_t *r = (uint32_t *)field, n = 1;
    if (tool_parse_uint(cmd, t->name, v, r)) return 2;
    while (n * n < *r) ++n;
    if (*r == 0 || *r > 64 || n * n != *r) {
        fprintf(stderr, "rad %s: --hr-rays must be a square from 1 to 64 (1, 4, 9 ...), not %s\n", cmd, v);
        return 2;
    }
    return 0;
}

/* --light-path line:P0:P1 or circle:C:R into mo->light_path and mo->path (field: light_path) */
static int parse_light_path(const char *cmd, const tool_arg *t, const char *v, void *field)
{
    tool_method_options *mo = (tool_method_options *)((char *)field - offsetof(tool_method_options, light_path));
    float *q = mo->path;
    char tail;
    int ok = 0;
    (void)t;
    memset(mo->path, 0, sizeof mo->path);
    if (!strncmp(v, "line:", 5))
        ok = sscanf(v + 5, "%f,%f,%f:%f,%f,%f%c", q, q + 1, q + 2, q + 3, q + 4, q + 5, &tail) == 6, mo->light_path = 1;
    else if (!strncmp(v, "circle:", 7))
        ok = sscanf(v + 7, "%f,%f,%f:%f%c", q, q + 1, q + 2, q + 3, &tail) == 4 && q[3] > 0.0f, mo->light_path = 2;
    ok = ok && !tool_vector_problem(q, 0) && !tool_vector_problem(q + 3, 0); /* finite, within 1e30 */
    if (!ok) {
        fprintf(stderr, "rad %s: --light-path must be line:X0,Y0,Z0:X1,Y1,Z1 or circle:CX,CY,CZ:R (R > 0), not '%s'\n",
                cmd, v);
        return 2;
    }
    return 0;
}

static const uint32_t format_values[] = {TOOL_MB_FLOAT, TOOL_MB_HALF, TOOL_MB_BC1, TOOL_MB_BC4X3};
static const uint32_t mode_values[] = {RAD_TEMPORAL_FEEDBACK, RAD_TEMPORAL_SINGLE, RAD_TEMPORAL_MULTIBOUNCE};
static const uint32_t estimator_values[] = {RAD_STOCHASTIC_JACOBI, RAD_STOCHASTIC_WALK};
static const uint32_t proxy_values[] = {TOOL_PROXY_PATCHES, TOOL_PROXY_AAVP, TOOL_PROXY_VP};

/* the contexts of the help: rad render lists every option, rad bake those it bakes with */
#define R TOOL_METHOD_HELP_RENDER
#define B TOOL_METHOD_HELP_BAKE
#define MO(f) offsetof(tool_method_options, f)
#define TEXT(where, text) {TOOL_ARG_TEXT, NULL, NULL, 0, 0, 0, 0, 0, NULL, NULL, NULL, NULL, where, text}
#define UINT(name, val, f, lo, hi, bit, bad, where, help) \
    {TOOL_ARG_UINT, name, val, MO(f), lo, hi, 0, bit, bad, NULL, NULL, NULL, where, help}
#define FLOAT(name, val, f, lo, hi, flags, bit, bad, where, help) \
    {TOOL_ARG_FLOAT, name, val, MO(f), lo, hi, flags, bit, bad, NULL, NULL, NULL, where, help}
#define CHOICE(name, val, f, choices, values, bit, where, help) \
    {TOOL_ARG_CHOICE, name, val, MO(f), 0, 0, 0, bit, NULL, choices, values, NULL, where, help}
#define CUSTOM(name, val, f, fn, bit, where, help) \
    {TOOL_ARG_CUSTOM, name, val, MO(f), 0, 0, 0, bit, NULL, NULL, NULL, fn, where, help}
#define FLAG(name, f, v, bit, where, help) {TOOL_ARG_FLAG, name, NULL, MO(f), v, 0, 0, bit, NULL, NULL, NULL, NULL, where, help}

/* The options of the methods (rad render and rad bake): the parser and the help. */
static const tool_arg method_args[] = {
    CUSTOM("--method", "M", method, parse_method, TOOL_OPT_METHOD, R,
           "default (render): classic, or aavp at the scene's resolution when the dense matrix would\n"
           "not fit 1 GiB or 10 CPU-minutes (rad_baker_plan, said on stderr before the work; the\n"
           "resolution within 4 CPU-minutes of bake per 100k triangles, at least 10 s);\n"
           "classic (radiosity + per-pixel direct light), multibounce (the indirect light\n"
           "L = F_mb E), temporal (alias-table frames), stochastic, pathtrace, local (local matrix of\n"
           "the patches nearest the camera), vp or aavp (virtual patches), hierarchical (quadtrees and\n"
           "links, Hanrahan et al. 1991), lightmap (classic, or virtual patches with --proxy aavp|vp,\n"
           "baked into a lightmap, the indirect light looked up per pixel)"),
    TEXT(R, "multibounce and temporal (without --bake: baked here first; with --bake the bake's own):\n"),
    TEXT(B, "multibounce:\n"),
    CUSTOM("--bounces", "K|inf", bounces, parse_bounces, TOOL_OPT_BOUNCES, 0,
           "multibounce, temporal --mode multibounce, vp, aavp, lightmap: bounces of the solution as\n"
           "classic --bounces (F_mb holds K + 1, the renderer's gather: the image of K equals classic\n"
           "--bounces K; inf: the full solution, Gauss-Seidel to 1e-6 for vp and aavp; default 64)"),
    CHOICE("--format", "F", format, "float|half|bc1|bc4x3", format_values, TOOL_OPT_FORMAT, 0,
           "multibounce: F_mb storage float, half, bc1 or bc4x3 (default)"),
    FLOAT("--outliers", "P", outliers, 0.0, 1.0, TOOL_ARG_HI_OPEN, TOOL_OPT_OUTLIERS,
          "must be a fraction in [0, 1) (e.g. 0.05)", 0,
          "multibounce bc1/bc4x3: fraction of the entries kept exactly (default 0.05)"),
    FLAG("--reorder", reorder, RAD_REORDER_MATCH, TOOL_OPT_REORDER, 0,
         "multibounce bc1/bc4x3: row/column reordering (the default)"),
    FLAG("--no-reorder", reorder, RAD_REORDER_NONE, TOOL_OPT_REORDER, 0, "no reordering"),
    UINT("--reorder-samples", "N", reorder_samples, 0, 4294967295.0, TOOL_OPT_REORDER_SAMPLES, "", 0,
         "reordering distances on N coordinates (default 0: all)"),
    CUSTOM("--tile", "T", tile, parse_tile, TOOL_OPT_TILE, 0,
           "multibounce bc1/bc4x3: scales per T x T texels (a multiple of 4), 0: per matrix (default 64)"),
    TEXT(B, "temporal (alias tables; k, w, adaptive and seed are the render's defaults):\n"),
    CHOICE("--mode", "M", mode, "feedback|single|multibounce", mode_values, TOOL_OPT_MODE, 0,
           "temporal: feedback (default: samples E + B, converges to L_inf), single (one bounce) or\n"
           "multibounce (alias tables over the channels of F_mb, with --bounces)"),
    TEXT(R, "temporal (these override the bake's; the defaults give a still image within 0.001 SSIM\n"
            "of classic on the Cornell box):\n"),
    UINT("--frames", "N", frames, 1, 10000000, TOOL_OPT_FRAMES, "must be in 1..10000000", R,
         "frames to step; the image shows the last (default 1024)"),
    UINT("--k", "K", k, 1, 65536, TOOL_OPT_K, "must be in 1..65536", 0, "draws per patch and frame (default 10)"),
    FLAG("--adaptive", adaptive, 1, TOOL_OPT_ADAPTIVE, 0,
         "per-patch blend weight from the estimator's variance (the default: B is the running\n"
         "mean of the frames at first, so it converges fast)"),
    FLOAT("--w", "W", w, 0.0, 1.0, TOOL_ARG_HI_OPEN, TOOL_OPT_W, "must be in [0, 1)", 0,
          "a fixed blend weight in [0, 1) instead (B starts at 0 and reaches 1 - W^N of the\n"
          "solution after N frames: W 0.998 needs ~2300 for 99%)"),
    UINT("--seed", "S", seed, 0, 4294967295.0, TOOL_OPT_SEED, "", 0,
         "generator seed of temporal and stochastic (default 0; same seed, same image on any thread\n"
         "count); also the path tracer's seed"),
    {TOOL_ARG_STRING, "--sequence", "DIR", MO(sequence), 0, 0, TOOL_ARG_NONEMPTY, TOOL_OPT_SEQUENCE, "needs a directory",
     NULL, NULL, NULL, R, "also write DIR/frame_NNNNN.png every --every N frames (and the last)"},
    UINT("--every", "N", every, 1, 4294967295.0, TOOL_OPT_EVERY, "must be > 0", R, "with --sequence (default 1)"),
    CUSTOM("--light-path", "P", light_path, parse_light_path, TOOL_OPT_LIGHT_PATH, R,
           "temporal --proxy aavp|vp: the last --point or --spot light moves, one step per frame:\n"
           "line:X0,Y0,Z0:X1,Y1,Z1 (from the first point at frame 1 to the second at the last) or\n"
           "circle:CX,CY,CZ:R (a horizontal circle, one turn over the frames); E at the samples is\n"
           "updated every frame (rad_vp_lights) and --sequence shows the light moving"),
    UINT("--light-rays", "N", light_rays, 0, 4294967295.0, TOOL_OPT_LIGHT_RAYS, "", R,
         "with --light-path: shadow rays per light and frame, the samples re-tested in turn\n"
         "(default 0: every sample every frame; shadows at most samples / N frames old, the\n"
         "light's falloff exact every frame)"),
    TEXT(0, "stochastic (stochastic radiosity: the classic patches and E, no F; rays sample it, so the\n"
            "solution is noisy and the noise falls as 1/sqrt(rays); docs/methods/stochastic.md):\n"),
    CHOICE("--sr-estimator", "E", sr_estimator, "jacobi|walk", estimator_values, TOOL_OPT_SR_ESTIMATOR, 0,
           "jacobi (default: stochastic Jacobi, shooting) or walk (random walks, collision estimator)"),
    UINT("--sr-rays", "N", sr_rays, 1, 67108864, TOOL_OPT_SR_RAYS, "must be in 1..67108864", 0,
         "rays of the first Jacobi iteration, later ones in proportion to their power; walks per\n"
         "batch (default 64 per patch)"),
    UINT("--sr-iterations", "N", sr_iterations, 1, 1000000, TOOL_OPT_SR_ITERATIONS, "must be in 1..1000000", 0,
         "Jacobi: shooting iterations at most (default 256; they stop when the unshot power is below\n"
         "1e-4 of the source); walk: batches averaged (default 1)"),
    TEXT(0, "vp (clustered virtual patches) and aavp (axis-aligned virtual patches); any mesh size, no\n"
            "per-triangle patches (--patches etc. are ignored); indirect light gathered per pixel from\n"
            "the voxel grid:\n"),
    UINT("--vp-resolution", "R", vp_resolution, 1, 1024, TOOL_OPT_VP_RESOLUTION, "must be in 1..1024", 0,
         "voxels along the longest axis of the scene (render: measured from the scene; else 16)"),
    UINT("--vp-max-patches", "B", vp_max_patches, 1, 1000000, TOOL_OPT_VP_MAX_PATCHES, "must be in 1..1000000", R,
         "the finest resolution whose patch count is at most B (replaces --vp-resolution; found\n"
         "by counting at predicted resolutions, one build)"),
    UINT("--face-points", "P", face_points, 1, 4096, TOOL_OPT_FACE_POINTS, "must be in 1..4096", 0,
         "Hammersley points per voxel face (default 16)"),
    CHOICE("--proxy", "P", proxy, "patches|aavp|vp", proxy_values, TOOL_OPT_PROXY, R,
           "multibounce, temporal, local, lightmap: run over patches (default), aavp or vp (virtual\n"
           "patches with sparse rows, built with --vp-resolution etc.; E at their samples, the\n"
           "indirect light gathered per pixel as --method aavp)"),
    TEXT(R, "local (local multi-bounce matrix; classic patches and F, T = (I - rho F_S)^-1 - I\n"
            "of the set S, the full solution within S; render only):\n"),
    UINT("--local-m", "M", local_m, 1, 1000000, TOOL_OPT_LOCAL_M, "must be in 1..1000000", R,
         "capacity: S = the M patches nearest the camera (default: every patch, up to 4096: T takes\n"
         "12 M^2 bytes, 192 MiB at 4096, and its rebuild 6 M^3 flops). L = T E over P_Vis x P_Lit:\n"
         "patches outside S (or not visible) get no indirect light and light outside S is not bounced"),
    TEXT(0, "hierarchical (Hanrahan et al. 1991: quadtrees on the triangles, links by BF refinement,\n"
            "solved to convergence; --bounces is not used; a bake resamples it onto the patches):\n"),
    FLOAT("--hr-eps", "E", hr_eps, 0.0, 1.0, TOOL_ARG_LO_OPEN | TOOL_ARG_HI_OPEN, TOOL_OPT_HR_EPS,
          "must be in (0, 1) (e.g. 1e-3)", 0, "refinement tolerance, a fraction of the source power (default 1e-7 per triangle,\n"
          "from 1e-5 to 1e-2)"),
    FLOAT("--hr-min-area", "A", hr_min_area, 0.0, 1e30, TOOL_ARG_LO_OPEN, TOOL_OPT_HR_MIN_AREA,
          "must be a positive area", 0, "smallest element area, scene units^2 (default: total area / 10000)"),
    CUSTOM("--hr-rays", "R", hr_rays, parse_hr_rays, TOOL_OPT_HR_RAYS, 0,
           "points and visibility rays per link: 1, 4, 9 ... 64 (default 4; 1 from 10^5 triangles)"),
    {TOOL_ARG_END, NULL, NULL, 0, 0, 0, 0, 0, NULL, NULL, NULL, NULL, 0, NULL}
};
#undef R
#undef B

const char *tool_method_help(int render)
{
    static char buf[2][12288];
    char *b = buf[render ? 0 : 1];
    tool_args_help_into(method_args, render ? TOOL_METHOD_HELP_RENDER : TOOL_METHOD_HELP_BAKE, b, sizeof buf[0]);
    return b;
}

int tool_method_option(const char *cmd, int argc, char **argv, int *a, tool_method_options *mo)
{
    return tool_args_parse(cmd, method_args, mo, &mo->given, argc, argv, a);
}

/* the first option of 'bits' that was given */
static const char *given_name(uint32_t bits)
{
    static const char *const names[] = {"--bounces", "--format", "--outliers", "--reorder/--no-reorder",
                                        "--reorder-samples", "--tile", "--mode", "--k", "--w", "--adaptive",
                                        "--seed", "--frames", "--sequence", "--every", "--method",
                                        "--vp-resolution", "--vp-max-patches", "--face-points", "--local-m",
                                        "--sr-rays", "--sr-iterations", "--sr-estimator",
                                        "--hr-eps", "--hr-min-area", "--hr-rays", "--light-path", "--light-rays"};
    uint32_t i;
    for (i = 0; i < sizeof names / sizeof names[0]; ++i)
        if (bits & (1u << i)) return names[i];
    return "?";
}

/* --proxy aavp|vp: render only, with multibounce, temporal, local or lightmap; the proxy's F_mb is
   float and its frames are not written one by one, so the options for those are refused */
static int proxy_check(const char *cmd, int render, const tool_method_options *mo)
{
    uint32_t bad;
    if (!mo->proxy) return 0;
    if (!render) {
        fprintf(stderr, "rad %s: --proxy is an option of rad render (bake virtual patches with --method aavp|vp)\n", cmd);
        return 2;
    }
    if (mo->method == TOOL_LIGHTMAP && mo->proxy) {
        /* the lightmap bake builds the set at one resolution (rad lightmap --proxy) */
        if (mo->given & TOOL_OPT_VP_MAX_PATCHES) {
            fprintf(stderr, "rad %s: --vp-max-patches is not an option of --method lightmap --proxy: give --vp-resolution\n", cmd);
            return 2;
        }
        return 0;
    }
    if (mo->method != TOOL_MULTIBOUNCE && mo->method != TOOL_TEMPORAL && mo->method != TOOL_LOCAL) {
        fprintf(stderr, "rad %s: --proxy %s is for --method multibounce, temporal, local or lightmap, not %s\n", cmd,
                mo->proxy == TOOL_PROXY_VP ? "vp" : "aavp", tool_method_name(mo->method));
        return 2;
    }
    bad = mo->given & (TOOL_OPT_MB_BUILD |
                       (mo->method == TOOL_TEMPORAL ? 0u : TOOL_OPT_SEQUENCE | TOOL_OPT_EVERY));
    if (bad) {
        fprintf(stderr, "rad %s: %s is not an option of --proxy %s (its F_mb is float; one image, no sequence)\n", cmd,
                given_name(bad), mo->proxy == TOOL_PROXY_VP ? "vp" : "aavp");
        return 2;
    }
    if ((mo->given & TOOL_OPT_VP_RESOLUTION) && (mo->given & TOOL_OPT_VP_MAX_PATCHES)) {
        fprintf(stderr, "rad %s: --vp-resolution and --vp-max-patches exclude each other\n", cmd);
        return 2;
    }
    return 0;
}

int tool_method_check(const char *cmd, int render, tool_method_options *mo, tool_classic_options *o)
{
    /* with --proxy the virtual patches' options belong to the proxy */
    uint32_t g = mo->given & ~(mo->proxy ? TOOL_OPT_VP : 0u), bad = 0;
    const char *want = NULL;
    if (proxy_check(cmd, render, mo)) return 2;
    if ((mo->given & (TOOL_OPT_LIGHT_PATH | TOOL_OPT_LIGHT_RAYS)) && render &&
        (mo->method != TOOL_TEMPORAL || !mo->proxy)) {
        fprintf(stderr, "rad %s: %s is for --method temporal --proxy aavp|vp\n", cmd,
                given_name(mo->given & (TOOL_OPT_LIGHT_PATH | TOOL_OPT_LIGHT_RAYS)));
        return 2;
    }
    if ((mo->given & TOOL_OPT_LIGHT_RAYS) && !(mo->given & TOOL_OPT_LIGHT_PATH)) {
        fprintf(stderr, "rad %s: --light-rays needs --light-path\n", cmd);
        return 2;
    }
    if (!render && (g & TOOL_OPT_RENDER_ONLY)) {
        fprintf(stderr, "rad %s: %s is an option of rad render\n", cmd, given_name(g & TOOL_OPT_RENDER_ONLY));
        return 2;
    }
    if (!render && mo->method == TOOL_LIGHTMAP) {
        fprintf(stderr, "rad %s: method 'lightmap' is render-only (rad lightmap writes the lightmap itself)\n", cmd);
        return 2;
    }
    if (!render && mo->method == TOOL_LOCAL) {
        fprintf(stderr, "rad %s: method 'local' is render-only (rad render --method local builds it in memory: its "
                        "matrix depends on the camera; a classic bake holds its F)\n", cmd);
        return 2;
    }
    if (!render && (mo->method == TOOL_VP || mo->method == TOOL_AAVP) && (g & TOOL_OPT_VP_MAX_PATCHES)) {
        fprintf(stderr, "rad %s: --vp-max-patches is an option of rad render (bake with --vp-resolution)\n", cmd);
        return 2;
    }
    if (mo->method >= TOOL_LOCAL) {
        uint32_t other = mo->method == TOOL_LOCAL          ? TOOL_OPT_VP | TOOL_OPT_BOUNCES | TOOL_OPT_HR
                         : mo->method == TOOL_HIERARCHICAL ? TOOL_OPT_VP | TOOL_OPT_BOUNCES | TOOL_OPT_LOCAL_M
                         : mo->method == TOOL_LIGHTMAP     ? TOOL_OPT_VP | TOOL_OPT_LOCAL_M | TOOL_OPT_HR
                                                               : TOOL_OPT_LOCAL_M | TOOL_OPT_HR;
        bad = g & (TOOL_OPT_MB_BUILD | TOOL_OPT_TEMPORAL | TOOL_OPT_RENDER_ONLY | TOOL_OPT_SEED |
                   TOOL_OPT_SR | other);
        if (bad) {
            fprintf(stderr, "rad %s: %s is not an option of --method %s%s\n", cmd, given_name(bad),
                    tool_method_name(mo->method),
                    mo->method == TOOL_LOCAL && (bad & TOOL_OPT_BOUNCES) ? " (T is the full solution in the set)"
                    : mo->method == TOOL_HIERARCHICAL && (bad & TOOL_OPT_BOUNCES) ? " (it solves to convergence)"
                                                                                          : "");
            return 2;
        }
        if ((g & TOOL_OPT_VP_RESOLUTION) && (g & TOOL_OPT_VP_MAX_PATCHES)) {
            fprintf(stderr, "rad %s: --vp-resolution and --vp-max-patches exclude each other\n", cmd);
            return 2;
        }
        /* the lightmap's solve (classic or over the proxy) runs Jacobi with the classic option */
        if (mo->method == TOOL_LIGHTMAP && (g & TOOL_OPT_BOUNCES)) {
            if (mo->bounces == RAD_MB_INFINITE) {
                fprintf(stderr, "rad %s: --bounces inf is not for --method lightmap (Jacobi needs a count; or --solver gauss-seidel)\n", cmd);
                return 2;
            }
            o->bounces = mo->bounces;
        }
        return 0;
    }
    if (g & (TOOL_OPT_VP | TOOL_OPT_LOCAL_M | TOOL_OPT_HR)) {
        fprintf(stderr, "rad %s: %s is for --method %s, not %s\n", cmd,
                given_name(g & (TOOL_OPT_VP | TOOL_OPT_LOCAL_M | TOOL_OPT_HR)),
                (g & TOOL_OPT_VP) ? "vp or aavp" : (g & TOOL_OPT_LOCAL_M) ? "local" : "hierarchical",
                tool_method_name(mo->method));
        return 2;
    }
    if ((g & TOOL_OPT_SR) && mo->method != TOOL_STOCHASTIC) {
        fprintf(stderr, "rad %s: %s is for --method stochastic, not %s\n", cmd, given_name(g & TOOL_OPT_SR),
                tool_method_name(mo->method));
        return 2;
    }
    if (!render && mo->method == TOOL_PATHTRACE) {
        fprintf(stderr, "rad %s: method 'pathtrace' needs no bake (use rad render --method pathtrace)\n", cmd);
        return 2;
    }
    switch (mo->method) {
    case TOOL_CLASSIC:
        bad = g & (TOOL_OPT_MB_BUILD | TOOL_OPT_TEMPORAL | TOOL_OPT_RENDER_ONLY |
                   (render ? 0u : TOOL_OPT_SEED));
        want = (bad & TOOL_OPT_MB_BUILD) ? "multibounce" : "temporal";
        if (!bad && mo->bounces == RAD_MB_INFINITE) {
            fprintf(stderr, "rad %s: --bounces inf is for --method multibounce (classic Jacobi needs a count)\n", cmd);
            return 2;
        }
        if (g & TOOL_OPT_BOUNCES) o->bounces = mo->bounces;
        break;
    case TOOL_PATHTRACE:
        bad = g & (TOOL_OPT_MB_BUILD | TOOL_OPT_TEMPORAL | TOOL_OPT_RENDER_ONLY | TOOL_OPT_BOUNCES);
        want = (bad & TOOL_OPT_MB_BUILD) || (bad & TOOL_OPT_BOUNCES) ? "multibounce" : "temporal";
        break;
    case TOOL_MULTIBOUNCE:
        bad = g & (TOOL_OPT_TEMPORAL | TOOL_OPT_RENDER_ONLY | TOOL_OPT_SEED);
        want = "temporal";
        break;
    case TOOL_STOCHASTIC:
        bad = g & (TOOL_OPT_MB_BUILD | TOOL_OPT_BOUNCES | TOOL_OPT_TEMPORAL | TOOL_OPT_RENDER_ONLY);
        want = (bad & (TOOL_OPT_MB_BUILD | TOOL_OPT_BOUNCES)) ? "multibounce" : "temporal";
        break;
    default:
        bad = g & TOOL_OPT_MB_BUILD;
        want = "multibounce";
        if (!bad && (g & TOOL_OPT_BOUNCES) && mo->mode != RAD_TEMPORAL_MULTIBOUNCE) {
            fprintf(stderr, "rad %s: --bounces is for --mode multibounce with --method temporal (mode %s samples F)\n",
                    cmd, tool_temporal_mode_name(mo->mode));
            return 2;
        }
        if (!bad && (g & TOOL_OPT_W) && (g & TOOL_OPT_ADAPTIVE)) {
            fprintf(stderr, "rad %s: --w and --adaptive exclude each other\n", cmd);
            return 2;
        }
        if (g & TOOL_OPT_W) mo->adaptive = 0; /* a fixed weight replaces the adaptive default */
        if (!bad && (g & TOOL_OPT_EVERY) && !(g & TOOL_OPT_SEQUENCE)) {
            fprintf(stderr, "rad %s: --every needs --sequence DIR\n", cmd);
            return 2;
        }
        break;
    }
    if (bad) {
        fprintf(stderr, "rad %s: %s is for --method %s, not %s\n", cmd, given_name(bad), want,
                tool_method_name(mo->method));
        return 2;
    }
    if (mo->method == TOOL_MULTIBOUNCE && mo->format <= TOOL_MB_HALF &&
        (g & (TOOL_OPT_OUTLIERS | TOOL_OPT_REORDER | TOOL_OPT_REORDER_SAMPLES | TOOL_OPT_TILE))) {
        fprintf(stderr, "rad %s: %s is for the compressed formats (--format bc1 or bc4x3), not %s\n", cmd,
                given_name(g & (TOOL_OPT_OUTLIERS | TOOL_OPT_REORDER | TOOL_OPT_REORDER_SAMPLES |
                                TOOL_OPT_TILE)),
                tool_mb_format_name(mo->format));
        return 2;
    }
    return 0;
}

/* The dense build's cost per method (the check itself, tool_dense_check, is budget.c's: it
   knows no method, so that budget.c, classic.c and methods.c call one way only). */
void tool_dense_plan(tool_classic_options *o, const tool_method_options *mo, int bake)
{
    double per = 4.0; /* F */
    o->dense_local_m = 0;
    o->dense_method = tool_method_name(mo->method);
    o->dense_cubic = 0.0;
    switch (mo->method) {
    case TOOL_MULTIBOUNCE:
        per += mo->format == TOOL_MB_HALF ? 22.0 : 28.0;
        o->dense_cubic = 2.0 * ceil(log2((double)(mo->bounces > 1024u ? 1024u : mo->bounces) + 2.0));
        break;
    case TOOL_TEMPORAL:
        if (mo->mode == RAD_TEMPORAL_MULTIBOUNCE) {
            per += 28.0 + 3.0 * 12.0;
            o->dense_cubic = 2.0 * ceil(log2((double)(mo->bounces > 1024u ? 1024u : mo->bounces) + 2.0));
        } else {
            per += 12.0;
        }
        break;
    case TOOL_LOCAL:
        o->dense_local_m = mo->local_m ? mo->local_m : TOOL_LOCAL_M_AUTO_MAX;
        break;
    default:
        if (o->solver == TOOL_DIRECT) {
            per += 8.0;
            o->dense_cubic = 1.0 / 3.0;
        }
        if (bake) per += 8.0; /* the container buffer and the file's copy of F */
        break;
    }
    o->dense_bytes_per_n2 = per;
}
