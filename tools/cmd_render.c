/* cmd_render.c - `rad render`: the command line, the camera, the method (the library's plan
   when none is given) and the image written. The engine tier bakes the production methods
   (classic and virtual patches, rad_baker_run) and the pixels read its solution
   (rad_baker_irradiance); pixels.c draws every radiosity image; render_methods.c holds the
   teaching methods step by step over the method-level calls (multibounce, temporal,
   stochastic, hierarchical, local, --bake files); lightmap.c the lightmap bake.

   Classic and virtual patches in memory (render_baked): the engine tier's bake with the
   command line's --solver, --bounces (0: none, inf: Gauss-Seidel), --max-edge and
   --face-points (vp: RAD_VP_CLUSTERED, aavp: RAD_VP_AXIS_ALIGNED, at --vp-resolution, within
   --vp-max-patches, or the plan's), its H read at each sample by rad_baker_irradiance.

   Every radiosity method prints one line for scripts (tools/report.sh) on stderr:
   "rad render: timing: method=M patches=N frames=F [bounces=K ]step_ms_median=X step_ms_min=Y",
   the method's own per-frame work: the engine tier's whole bake (classic, vp and aavp in
   memory; plus resolution), the solve of a --bake file (K Jacobi bounces), one F_mb E product
   (median of 9), one temporal step (median over the frames), one local apply L = T E (median
   of 9; plus rebuild_ms), or the virtual patches' solve + H (plus build_ms, sources_ms,
   gather_ms, render_ms, resolution, vp_mib and peak_rss_mib). */
#include "tool.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* No --method (and no --bake): the library's plan picks classic or AAVP and the resolution
   from the scene and the budget (rad_baker_plan), and says so before the work. A
   virtual-patch method (or proxy) without --vp-resolution or --vp-max-patches takes the
   plan's resolution the same way. */
static int render_default_method(const char *cmd, const tool_world *w, const tool_classic_options *o,
                                 tool_method_options *mo, float voxels_per_path)
{
    rad_baker_choice plan;
    int chosen = !(mo->given & TOOL_OPT_METHOD);
    /* count the kind that will be built (a clustered set has more patches at one resolution),
       with the face points it will be built with */
    rad_vp_kind kind = !chosen && (mo->method == TOOL_VP || mo->proxy == TOOL_PROXY_VP) ? RAD_VP_CLUSTERED : RAD_VP_AXIS_ALIGNED;
    if (tool_plan(cmd, w, o, chosen ? RAD_BAKER_AUTO : RAD_BAKER_VIRTUAL_PATCHES, kind, mo->face_points, voxels_per_path,
                  &plan))
        return 1;
    if (plan.method == RAD_BAKER_VIRTUAL_PATCHES) {
        if (chosen) mo->method = TOOL_AAVP;
        mo->vp_resolution = plan.vp_resolution;
    }
    if (!chosen)
        fprintf(stderr, "rad %s: no --vp-resolution given: resolution %u from the scene (%u %s patches, about %.0f MiB and "
                "%.0f s of CPU for the bake)\n",
                cmd, plan.vp_resolution, plan.patch_count, kind == RAD_VP_CLUSTERED ? "vp" : "aavp",
                plan.estimated_bytes / 1048576.0, plan.estimated_seconds);
    else if (plan.method == RAD_BAKER_VIRTUAL_PATCHES)
        fprintf(stderr, "rad %s: no --method given: chose aavp at --vp-resolution %u (about %.0f MiB and %.0f s of CPU for "
                "the bake; give --method to choose)\n", cmd, plan.vp_resolution, plan.estimated_bytes / 1048576.0,
                plan.estimated_seconds);
    else
        fprintf(stderr, "rad %s: no --method given: chose classic (give --method to choose)\n", cmd);
    return 0;
}

/* ---- the command line ------------------------------------------------------------------- */

static int parse_camera(const char *cmd, const tool_arg *t, const char *v, void *field)
{
    const char *why;
    (void)t;
    if (tool_parse_camera(v, (rad_camera *)field, &why)) {
        fprintf(stderr, "rad %s: bad --camera '%s': %s\n", cmd, v, why);
        return 2;
    }
    return 0;
}

/* --size WxH into tool_render_view's width and height (field: width) */
static int parse_size(const char *cmd, const tool_arg *t, const char *v, void *field)
{
    tool_render_view *view = (tool_render_view *)((char *)field - offsetof(tool_render_view, width));
    (void)t;
    if (tool_parse_size(v, &view->width, &view->height)) {
        fprintf(stderr, "rad %s: bad size '%s' (want WxH, e.g. 512x512)\n", cmd, v);
        return 2;
    }
    return tool_check_size(cmd, view->width, view->height) ? 2 : 0;
}

static int parse_shading(const char *cmd, const tool_arg *t, const char *v, void *field)
{
    (void)t;
    return tool_parse_shading(cmd, v, (int *)field) ? 2 : 0;
}

static int parse_threads(const char *cmd, const tool_arg *t, const char *v, void *field)
{
    return tool_parse_threads(cmd, t->name, v, (uint32_t *)field) ? 2 : 0;
}

#define RA(f) offsetof(tool_render_args, f)
#define RA_UINT(name, val, f, lo, hi, given, bad, help) \
    {TOOL_ARG_UINT, name, val, RA(f), lo, hi, 0, given, bad, NULL, NULL, NULL, 0, help}
#define RA_CUSTOM(name, val, f, fn, given, help) \
    {TOOL_ARG_CUSTOM, name, val, RA(f), 0, 0, 0, given, NULL, NULL, NULL, fn, 0, help}
/* rad render's own options (the classic, method and light options are classic.c's,
   methods.c's and lights.c's tables) */
static const tool_arg render_table[] = {
    {TOOL_ARG_STRING, "-o", "FILE", RA(out), 0, 0, 0, 0, NULL, NULL, NULL, NULL, 0,
     "output image: .pfm or .exr (linear radiance; .exr needs libtinyexr-dev at build) or .png\n"
     "(sRGB, exposure applied)"},
    {TOOL_ARG_STRING, "--bake", "FILE.radb", RA(bake), 0, 0, 0, 0, NULL, NULL, NULL, NULL, 0,
     "classic, multibounce, temporal, stochastic, hierarchical, vp, aavp: use a bake of that\n"
     "method made by 'rad bake' from this scene instead of computing it here"},
    RA_CUSTOM("--camera", "PX,PY,PZ:TX,TY,TZ:UX,UY,UZ", view.cam, parse_camera, TOOL_RENDER_GIVEN_CAMERA,
              "camera (default: the scene's)"),
    {TOOL_ARG_FLOAT, "--fov", "DEG", RA(fov), 0.0, 180.0, TOOL_ARG_LO_OPEN | TOOL_ARG_HI_OPEN, 0, "must be in (0, 180)",
     NULL, NULL, NULL, 0, "vertical field of view in degrees (default: the scene's)"},
    RA_CUSTOM("--size", "WxH", view.width, parse_size, 0,
              "image size (default 512x512; at most 2 GiB of image: 12 bytes a pixel)"),
    RA_UINT("--aa", "N", view.aa, 1, 65536, 0, "must be 1 to 65536",
            "radiosity methods: stratified samples per pixel, rounded down to a square (default 16, 1 to 65536)"),
    RA_UINT("--spp", "N", spp, 1, 1048576, 0, "must be in 1..1048576", "pathtrace: samples per pixel (default 64)"),
    {TOOL_ARG_FLOAT, "--exposure", "X", RA(view.exposure), 0.0, 1e30, TOOL_ARG_LO_OPEN, 0, "must be > 0", NULL, NULL,
     NULL, 0, "scale before 8-bit sRGB encoding (PNG only; default 1)"},
    RA_UINT("--pixel-light-samples", "N", view.light_samples, 1, 65536, 0, "must be 1 to 65536",
            "radiosity methods: shadow rays per pixel sample and light (default 16, at most 65536)"),
    RA_UINT("--final-gather", "N", view.final_gather, 0, 4096, TOOL_RENDER_GIVEN_FINAL_GATHER, "is at most 4096",
            "classic, vp, aavp: trace the first bounce from each pixel sample with N rays (direct\n"
            "light at the hits, the solution's irradiance there): the indirect light of points a\n"
            "patch average misrepresents; default: vp, aavp and --proxy (no --sequence) 16 while the\n"
            "image's samples times 16 stay within 2^22 rays, else the rays that fit (off below 4:\n"
            "noise), else 0 (off). lightmap: N rays per texel of the bake instead (default: 32 with\n"
            "--proxy aavp|vp, else 0), as rad lightmap --final-gather"),
    RA_CUSTOM("--shading", "MODEL", view.shading, parse_shading, 0,
              "radiosity methods: lighting model for the analytic lights' direct term: none\n"
              "(default: Lambert through the irradiance), lambert, half-lambert, banded, phong,\n"
              "blinn-phong, minnaert, oren-nayar, microfacet (tools/shading.c says how it combines\n"
              "with the diffuse radiosity solution)"),
    RA_CUSTOM("--threads", "N", threads, parse_threads, 0, "worker threads (default: all cores; at most 1024)"),
    {TOOL_ARG_TEXT, NULL, NULL, 0, 0, 0, 0, 0, NULL, NULL, NULL, NULL, 0,
     "lightmap (the classic solution baked into a lightmap over the second uv set, else the\n"
     "automatic unwrap, as rad lightmap; direct light per pixel, the indirect light a bilinear\n"
     "lookup of the lightmap; --proxy aavp|vp: the indirect light from virtual patches\n"
     "(--vp-resolution R, --face-points P), for scenes the dense classic build cannot hold):\n"},
    RA_UINT("--lightmap-size", "N", lm_size, 4, 16384, TOOL_RENDER_GIVEN_LM_SIZE | TOOL_RENDER_GIVEN_LM, "must be 4 to 16384",
            "atlas side (default 256, or the least power of two to 4096 the unwrap's charts fit)"),
    RA_UINT("--texel-samples", "N", lm_samples, 1, 16, TOOL_RENDER_GIVEN_LM, "must be 1 to 16",
            "sample points per texel (default 4), as rad lightmap"),
    RA_UINT("--visibility-rays", "N", lm_vis, 1, 64, TOOL_RENDER_GIVEN_LM, "must be 1 to 64",
            "shadow rays per sample point and patch (default 2), as rad lightmap"),
    {TOOL_ARG_END, NULL, NULL, 0, 0, 0, 0, 0, NULL, NULL, NULL, NULL, 0, NULL}
};

static void render_usage(FILE *f)
{
    static char own[8192];
    tool_args_help_into(render_table, 0, own, sizeof own);
    fprintf(f,
            "usage: rad render SCENE -o OUT.png|OUT.pfm|OUT.exr [--method classic|multibounce|temporal|local|stochastic|vp|aavp|hierarchical|lightmap|pathtrace] [options]\n"
            "%s"
            "patch and classic solution options (ignored with --bake, which keeps its own):\n"
            "%s"
            "%s"
            "%s",
            own, tool_classic_help(), tool_method_help(1), tool_light_help());
}

static void render_args_default(tool_render_args *ra)
{
    memset(ra, 0, sizeof *ra);
    tool_classic_options_default(&ra->o);
    tool_method_options_default(&ra->mo);
    ra->view.width = ra->view.height = 512;
    ra->view.aa = 16;
    ra->view.light_samples = 16;
    ra->view.exposure = 1.0f;
    ra->view.shading = -1;
    ra->spp = 64;
    ra->lm_size = 256;
    ra->lm_samples = 4;
    ra->lm_vis = 2;
}

/* the command line into ra; -1: go on, else the exit code (--help: 0; bad usage: 2, printed) */
static int render_parse(const char *cmd, int argc, char **argv, tool_lights *lights, tool_render_args *ra)
{
    int a, rc;
    render_args_default(ra);
    for (a = 0; a < argc; ++a) {
        const char *opt = argv[a];
        if (!strcmp(opt, "--help") || !strcmp(opt, "-h")) {
            render_usage(stdout);
            return 0;
        }
        /* --method, --seed and the methods' options first: their --bounces takes 'inf' */
        if ((rc = tool_method_option(cmd, argc, argv, &a, &ra->mo)) == 0 &&
            (rc = tool_classic_option(cmd, argc, argv, &a, &ra->o)) == 0 &&
            (rc = tool_light_option(cmd, argc, argv, &a, lights)) == 0)
            rc = tool_args_parse(cmd, render_table, ra, &ra->given, argc, argv, &a);
        if (rc == 2) return 2;
        if (rc == 1) continue;
        if (opt[0] == '-' && opt[1]) {
            fprintf(stderr, "rad %s: unknown option '%s' (see rad render --help)\n", cmd, opt);
            return 2;
        }
        if (ra->scene) {
            fprintf(stderr, "rad %s: more than one scene given\n", cmd);
            return 2;
        }
        ra->scene = opt;
    }
    if (!ra->scene || !ra->out) {
        fprintf(stderr, "rad %s: %s\n", cmd, !ra->scene ? "no scene given" : "no output file given (-o OUT.png|OUT.pfm)");
        render_usage(stderr);
        return 2;
    }
    return -1;
}

/* the options that exclude each other, the output's format and place; 0, or the exit code */
static int render_check(const char *cmd, tool_render_args *ra)
{
    const tool_method_options *mo = &ra->mo;
    const char *inputs[2];
    if (tool_method_check(cmd, 1, &ra->mo, &ra->o)) return 2;
    if ((ra->given & TOOL_RENDER_GIVEN_LM) && mo->method != TOOL_LIGHTMAP) {
        fprintf(stderr, "rad %s: --lightmap-size, --texel-samples and --visibility-rays are for --method lightmap\n", cmd);
        return 2;
    }
    if (mo->method == TOOL_LIGHTMAP && ra->bake) {
        fprintf(stderr, "rad %s: --method lightmap bakes its own lightmap: --bake is not used\n", cmd);
        return 2;
    }
    tool_dense_plan(&ra->o, mo, 0);
    if (mo->method == TOOL_PATHTRACE && ra->view.shading >= 0) {
        fprintf(stderr, "rad %s: --shading is for the radiosity methods (the path tracer is Lambertian)\n", cmd);
        return 2;
    }
    if (mo->method == TOOL_LOCAL && !mo->proxy && ra->bake) {
        fprintf(stderr, "rad %s: --bake is not used by --method %s (it builds its data here)\n", cmd,
                tool_method_name(mo->method));
        return 2;
    }
    if (mo->method == TOOL_PATHTRACE && ra->bake) {
        fprintf(stderr, "rad %s: --bake is for the radiosity methods (classic, multibounce, temporal), not pathtrace\n", cmd);
        return 2;
    }
    if (tool_image_check_format(cmd, ra->out)) return 2;
    inputs[0] = ra->scene;
    inputs[1] = ra->bake;
    return tool_check_output(cmd, ra->out, inputs, 2) ? 1 : 0;
}

/* --final-gather's default for the virtual patches: a voxel's patch averages the light over
   every sample in it, crevices included, so the open surfaces a camera sees got 10% too little
   first bounce on Sponza; 16 traced rays per pixel sample restore it. The rays are capped at
   2^22 a frame (about 8 CPU-seconds on Sponza, an eighth of its bake), fewer than 4 are not
   worth their noise, and a --sequence (a frame every few steps) keeps the option's 0. */
static uint32_t auto_final_gather(const tool_render_view *v)
{
    uint32_t side = 1, rays;
    double samples;
    while ((side + 1) * (side + 1) <= v->aa) ++side;
    samples = (double)v->width * (double)v->height * (double)(side * side);
    rays = samples * 16.0 <= 4194304.0 ? 16u : (uint32_t)(4194304.0 / samples);
    return rays >= 4u ? rays : 0u;
}

/* the warnings about the scene, and the camera: --camera, else the file's, else one chosen */
static void render_prepare(const char *cmd, const tool_world *w, tool_render_args *ra)
{
    const tool_method_options *mo = &ra->mo;
    rad_camera *cam = &ra->view.cam;
    uint32_t t, emitters = 0;
    for (t = 0; t < w->scene->triangle_count; ++t) {
        const float *Le = w->scene->materials_table[w->scene->materials[t]].emission;
        if (Le[0] > 0.0f || Le[1] > 0.0f || Le[2] > 0.0f) ++emitters;
    }
    if (!emitters && !w->file.light_count)
        fprintf(stderr, "rad %s: warning: the scene has no emitters and no lights: the image is black\n", cmd);
    if ((mo->method <= TOOL_TEMPORAL || mo->method == TOOL_LOCAL || mo->method == TOOL_STOCHASTIC ||
         mo->method == TOOL_LIGHTMAP) &&
        !mo->proxy && mo->method != TOOL_PATHTRACE && !ra->bake && ra->o.patches < w->scene->triangle_count)
        fprintf(stderr, "rad %s: note: --patches %u is below the %u triangles: every triangle is at least one patch\n",
                cmd, ra->o.patches, w->scene->triangle_count);
    if (!(ra->given & TOOL_RENDER_GIVEN_CAMERA)) {
        if (w->file.has_camera) *cam = w->file.camera;
        else tool_choose_camera(cmd, w->scene, &w->rc, ra->view.width, ra->view.height, cam);
    } else /* --camera: the file's field of view, else 45 degrees, as rad trace takes it */
        cam->fov_y_degrees = w->file.has_camera ? w->file.camera.fov_y_degrees : 45.0f;
    if (ra->fov > 0.0f) cam->fov_y_degrees = ra->fov;
}

/* --method lightmap: the lightmap bake (lightmap.c), then the classic render with H looked up
   in the lightmap at each sample */
static int render_lightmap_method(const char *cmd, const tool_world *w, const tool_render_args *ra, tool_image *img)
{
    tool_lightmap_baked bk;
    tool_lightmap_request rq;
    tool_lightmap_proxy px;
    tool_render_source src;
    tool_render_view view;
    int rc;
    tool_lightmap_request_default(&rq);
    rq.width = rq.height = (int)ra->lm_size;
    rq.auto_size = !(ra->given & TOOL_RENDER_GIVEN_LM_SIZE);
    rq.texel_samples = ra->lm_samples;
    rq.visibility_rays = ra->lm_vis;
    memset(&px, 0, sizeof px);
    px.kind = (int)ra->mo.proxy;
    px.resolution = ra->mo.vp_resolution;
    px.face_points = ra->mo.face_points;
    /* no --proxy: the plan keeps the classic patches or takes virtual patches (whose texels
       trace the first bounce unless --final-gather 0) where the dense build would not fit */
    if (!(ra->mo.given & TOOL_OPT_PROXY) &&
        tool_plan_proxy(cmd, w, &ra->o, (ra->given & TOOL_RENDER_GIVEN_FINAL_GATHER) && !ra->view.final_gather ? 0.0f : 4.0f,
                        "the lightmap's indirect light", &px.kind, &px.resolution))
        return 1;
    rq.proxy = px.kind ? &px : NULL;
    if (ra->given & TOOL_RENDER_GIVEN_FINAL_GATHER) rq.final_gather = ra->view.final_gather;
    if (tool_lightmap_bake(cmd, w, &ra->o, &rq, &bk)) return 1;
    fprintf(stderr, "rad %s: timing: method=lightmap%s patches=%u frames=1 bounces=%u step_ms_median=%.6f "
                    "step_ms_min=%.6f\n",
            cmd, px.kind == TOOL_PROXY_VP ? " proxy=vp" : px.kind ? " proxy=aavp" : "", bk.patches,
            ra->o.bounces, 1e3 * bk.solve_seconds, 1e3 * bk.solve_seconds);
    memset(&src, 0, sizeof src);
    src.P = bk.cl.patches;
    src.lm = bk.lm;
    src.lm_values = bk.values;
    view = ra->view;
    view.final_gather = 0; /* --final-gather was the texels' */
    rc = tool_render_pixels(&bk.w, &view, &src, img);
    tool_lightmap_bake_free(&bk);
    return rc;
}

static int render_pathtrace(const char *cmd, const tool_world *w, const tool_render_args *ra, tool_image *img)
{
    tool_trace_options to;
    rad_context ctx;
    rad_result r;
    tool_trace_options_default(&to);
    to.width = ra->view.width;
    to.height = ra->view.height;
    to.spp = (int)ra->spp;
    to.seed = ra->mo.seed;
    tool_context(&ctx, "path tracing");
    r = (rad_result)tool_trace_image(w->scene, &w->rc, w->file.lights, w->file.light_count, &ra->view.cam, &to, &ctx, img);
    tool_progress_end();
    return r != RAD_SUCCESS ? tool_fail(cmd, "tool_trace_image", r) : 0;
}

/* Whether the engine tier bakes the choice on the command line: classic (any --solver,
   --bounces 0, --max-edge) and aavp or vp (any --face-points, --bounces K, 0 or inf), solved
   here. Bakes read with --bake, the proxies and the teaching methods keep their own paths. */
static int render_by_baker(const tool_render_args *ra)
{
    const tool_method_options *mo = &ra->mo;
    if (ra->bake || mo->proxy) return 0;
    return mo->method == TOOL_CLASSIC || mo->method == TOOL_AAVP || mo->method == TOOL_VP;
}

/* The engine tier's bake of the scene and the lights (one group), keeping its solution, and
   the per-pixel render with H from the tier's final gather at each sample. 0 or 1 (printed).
   Where nothing emits (the tier refuses that) the image stays black, as any solve of no light. */
static int render_baked(const char *cmd, const tool_world *w, const tool_render_args *ra, tool_image *img)
{
    const tool_method_options *mo = &ra->mo;
    int classic = mo->method == TOOL_CLASSIC;
    uint32_t res = mo->vp_resolution, bounces = classic ? ra->o.bounces : mo->bounces, patches = 0;
    rad_baker_options bo;
    rad_baker_desc d;
    rad_baker_result *R = NULL;
    tool_render_source src;
    char kb[16];
    double t0;
    int rc;
    memset(&bo, 0, sizeof bo);
    bo.vp_kind = mo->method == TOOL_VP ? RAD_VP_CLUSTERED : RAD_VP_AXIS_ALIGNED;
    bo.vp_face_points = mo->face_points;
    if (!classic && (mo->given & TOOL_OPT_VP_MAX_PATCHES) &&
        tool_vp_resolution_within(cmd, w, bo.vp_kind, mo->face_points, mo->vp_max_patches, mo->vp_resolution, &res))
        return 1;
    memset(&d, 0, sizeof d);
    d.outputs = RAD_BAKER_SOLUTION;
    t0 = tool_seconds();
    rc = tool_baker_run(cmd, w, &ra->o, classic ? RAD_BAKER_CLASSIC : RAD_BAKER_VIRTUAL_PATCHES, bounces,
                        classic ? 0u : res, &bo, &d, &R);
    if (rc > 0) return rc;
    t0 = tool_seconds() - t0;
    if (R) patches = R->patch_count;
    if (R && !classic)
        fprintf(stderr, "rad %s: %s virtual patches at resolution %u: %u patches (the engine tier's bake)\n", cmd,
                tool_method_name(mo->method), R->vp_resolution, R->patch_count);
    /* one line for scripts: the step is the whole bake here (form factors or set, source, bounces) */
    if (bounces == RAD_MB_INFINITE) snprintf(kb, sizeof kb, "inf");
    else snprintf(kb, sizeof kb, "%u", bounces);
    fprintf(stderr, "rad %s: timing: method=%s patches=%u frames=1 bounces=%s step_ms_median=%.6f step_ms_min=%.6f%s%.0u\n",
            cmd, tool_method_name(mo->method), patches, kb, 1e3 * t0, 1e3 * t0, classic ? "" : " resolution=",
            R && !classic ? R->vp_resolution : 0u);
    if (!R) return 0; /* nothing emits: black (render_prepare said so) */
    memset(&src, 0, sizeof src);
    src.baker = R;
    rc = tool_render_pixels(w, &ra->view, &src, img);
    rad_baker_result_destroy(R);
    return rc;
}

/* the image by the method asked for; 0 or 1 (printed) */
static int render_image(const char *cmd, const tool_world *w, const tool_render_args *ra, tool_image *img)
{
    const tool_method_options *mo = &ra->mo;
    if (render_by_baker(ra)) return render_baked(cmd, w, ra, img);
    if (mo->method == TOOL_LIGHTMAP) return render_lightmap_method(cmd, w, ra, img);
    if ((mo->method >= TOOL_LOCAL && !(mo->method == TOOL_HIERARCHICAL && ra->bake)) || mo->proxy)
        return mo->method == TOOL_LOCAL && !mo->proxy ? tool_render_local_method(cmd, w, ra, img)
               : mo->method == TOOL_HIERARCHICAL      ? tool_render_hr_method(cmd, w, ra, img)
                                                      : tool_render_vp_method(cmd, w, ra, img);
    /* hierarchical here: from a bake (resampled onto its patches) */
    if (mo->method == TOOL_MULTIBOUNCE || mo->method == TOOL_TEMPORAL || mo->method == TOOL_STOCHASTIC ||
        mo->method == TOOL_HIERARCHICAL)
        return tool_render_with_method(cmd, w, ra, img);
    if (mo->method == TOOL_PATHTRACE) return render_pathtrace(cmd, w, ra, img);
    return tool_render_classic_bake(cmd, w, ra, img);
}

static int render_main(int argc, char **argv, tool_lights *lights)
{
    const char *cmd = "render";
    tool_render_args ra;
    tool_world w;
    tool_image img;
    int rc, traced;
    double t0 = tool_seconds();
    if ((rc = render_parse(cmd, argc, argv, lights, &ra)) >= 0) return rc;
    if ((rc = render_check(cmd, &ra)) != 0) return rc;
    tool_set_threads((int)ra.threads);
    if (tool_open_world_lit(cmd, ra.scene, lights, &w)) return 1;
    if (tool_check_outputs(cmd, &ra.out, 1, w.file.input_files, (int)w.file.input_file_count)) {
        tool_close_world(&w);
        return 1;
    }
    /* a render that will trace the first bounce (the final gather at its pixels, or at the
       lightmap's texels over virtual patches; given or by default) meets the patches' average
       one bounce later: the plan asks for 4 voxels a mean free path, not 6.5 */
    traced = (ra.given & TOOL_RENDER_GIVEN_FINAL_GATHER) ? ra.view.final_gather != 0
             : ra.mo.method == TOOL_LIGHTMAP        ? ra.mo.proxy == TOOL_PROXY_AAVP || ra.mo.proxy == TOOL_PROXY_VP
                                                    : !ra.mo.sequence && auto_final_gather(&ra.view) != 0;
    if (!ra.bake && (!(ra.mo.given & TOOL_OPT_METHOD) ||
                     ((ra.mo.method == TOOL_AAVP || ra.mo.method == TOOL_VP || ra.mo.proxy == TOOL_PROXY_AAVP ||
                       ra.mo.proxy == TOOL_PROXY_VP) &&
                      !(ra.mo.given & (TOOL_OPT_VP_RESOLUTION | TOOL_OPT_VP_MAX_PATCHES)))) &&
        render_default_method(cmd, &w, &ra.o, &ra.mo, traced ? 4.0f : 0.0f)) {
        tool_close_world(&w);
        return 1;
    }
    render_prepare(cmd, &w, &ra);
    if (!(ra.given & TOOL_RENDER_GIVEN_FINAL_GATHER) && ra.mo.method != TOOL_LIGHTMAP &&
        !ra.mo.sequence && (ra.mo.method == TOOL_AAVP || ra.mo.method == TOOL_VP || ra.mo.proxy) &&
        (ra.view.final_gather = auto_final_gather(&ra.view)) != 0)
        fprintf(stderr, "rad %s: --final-gather %u (the virtual patches' default at %dx%d; --final-gather 0: off)\n", cmd,
                ra.view.final_gather, ra.view.width, ra.view.height);
    memset(&img, 0, sizeof img);
    if (tool_image_alloc(&img, ra.view.width, ra.view.height) != 0) {
        fprintf(stderr, "rad %s: out of memory for a %dx%d image\n", cmd, ra.view.width, ra.view.height);
        tool_close_world(&w);
        return 1;
    }
    rc = render_image(cmd, &w, &ra, &img);
    if (rc == 0 && tool_image_write(ra.out, &img, ra.view.exposure) != 0) {
        fprintf(stderr, "rad %s: %s\n", cmd, tool_output_error());
        rc = 1;
    }
    if (rc == 0)
        printf("wrote %s (%dx%d, %s) in %.2f s\n", ra.out, ra.view.width, ra.view.height, tool_method_name(ra.mo.method),
               tool_seconds() - t0);
    tool_image_free(&img);
    tool_close_world(&w);
    return rc ? 1 : 0;
}

int tool_cmd_render(int argc, char **argv)
{
    tool_lights lights;
    int rc;
    memset(&lights, 0, sizeof lights);
    rc = render_main(argc, argv, &lights);
    tool_lights_free(&lights);
    return rc;
}
