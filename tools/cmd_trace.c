/* cmd_trace.c - rad trace: the reference path tracer (trace.c) on a scene.

   rad trace SCENE [--camera PX,PY,PZ:TX,TY,TZ:UX,UY,UZ] [--fov DEG] [--size WxH] [--spp N]
                   [--seed S] [--max-depth N] [--rr-depth N] [--threads N] [--exposure X]
                   [--sun DIR:RGB] [--sky RGB] [--point POS:RGB] [--spot POS:DIR:ANGLES:RGB]
                   [--area P:U:V:RGB] -o OUT.pfm|OUT.png
   The lights options (lights.c) add to the file's lights exactly as in rad render. */
#include "tool.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/* rad trace's command line */
typedef struct trace_args {
    const char *scene, *out;
    tool_trace_options opt;
    rad_camera cam;          /* --camera (given: TRACE_GIVEN_CAMERA) */
    float fov, exposure;
    uint32_t threads;
    uint32_t given;
} trace_args;
enum { TRACE_GIVEN_CAMERA = 1 };
/* help contexts: --output is -o's other name, not listed */
enum { TRACE_HELP = 1, TRACE_HIDDEN = 2 };

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

/* --size WxH into tool_trace_options' width and height (field: width) */
static int parse_size(const char *cmd, const tool_arg *t, const char *v, void *field)
{
    tool_trace_options *o = (tool_trace_options *)((char *)field - offsetof(tool_trace_options, width));
    (void)t;
    if (tool_parse_size(v, &o->width, &o->height) != 0 || o->width <= 0 || o->height <= 0) {
        fprintf(stderr, "rad %s: --size wants WxH, got '%s'\n", cmd, v);
        return 2;
    }
    return tool_check_size(cmd, o->width, o->height) ? 2 : 0;
}

static int parse_threads(const char *cmd, const tool_arg *t, const char *v, void *field)
{
    return tool_parse_threads(cmd, t->name, v, (uint32_t *)field) ? 2 : 0;
}

#define TA(f) offsetof(trace_args, f)
#define TA_UINT(name, val, f, lo, hi, bad, help) {TOOL_ARG_UINT, name, val, TA(f), lo, hi, 0, 0, bad, NULL, NULL, NULL, 0, help}
#define TA_CUSTOM(name, val, f, fn, given, help) {TOOL_ARG_CUSTOM, name, val, TA(f), 0, 0, 0, given, NULL, NULL, NULL, fn, 0, help}
/* rad trace's options (the lights' are lights.c's table) */
static const tool_arg trace_table[] = {
    TA_CUSTOM("--camera", "PX,PY,PZ:TX,TY,TZ:UX,UY,UZ", cam, parse_camera, TRACE_GIVEN_CAMERA,
              "camera (default: the scene's camera)"),
    {TOOL_ARG_FLOAT, "--fov", "DEG", TA(fov), 0.0, 180.0, TOOL_ARG_LO_OPEN | TOOL_ARG_HI_OPEN, 0, "wants degrees in (0, 180)",
     NULL, NULL, NULL, 0, "vertical field of view (default: the scene's, else 45)"},
    TA_CUSTOM("--size", "WxH", opt.width, parse_size, 0,
              "image size (default 256x256; at most 2 GiB of image: 12 bytes a pixel)"),
    TA_UINT("--spp", "N", opt.spp, 1, 16777216, "must be in 1..16777216", "samples per pixel (default 64)"),
    TA_UINT("--seed", "S", opt.seed, 0, 4294967295.0, "", "random seed (default 0); same seed, same image on any thread count"),
    TA_UINT("--max-depth", "N", opt.max_depth, 1, 100000, "must be in 1..100000", "path length cap (default 64)"),
    TA_UINT("--rr-depth", "N", opt.rr_depth, 1, 100000, "must be in 1..100000",
            "Russian roulette from this bounce on (default 16)"),
    TA_CUSTOM("--threads", "N", threads, parse_threads, 0, "worker threads (default: all cores; at most 1024)"),
    {TOOL_ARG_FLOAT, "--exposure", "X", TA(exposure), 0.0, 1e30, TOOL_ARG_LO_OPEN | TOOL_ARG_HI_OPEN, 0,
     "wants a positive number", NULL, NULL, NULL, 0, "scale before 8-bit sRGB encoding (PNG only; default 1)"},
    {TOOL_ARG_STRING, "-o", "FILE", TA(out), 0, 0, 0, 0, NULL, NULL, NULL, NULL, 0,
     ".pfm (linear float radiance) or .png (8-bit sRGB)"},
    {TOOL_ARG_STRING, "--output", "FILE", TA(out), 0, 0, 0, 0, NULL, NULL, NULL, NULL, TRACE_HIDDEN, "as -o"},
    {TOOL_ARG_END, NULL, NULL, 0, 0, 0, 0, 0, NULL, NULL, NULL, NULL, 0, NULL}
};

static void trace_usage(FILE *f)
{
    static char own[4096];
    tool_args_help_into(trace_table, TRACE_HELP, own, sizeof own);
    fprintf(f, "usage: rad trace SCENE -o OUT.pfm|OUT.png [options]\n"
               "  path-traced reference image (diffuse, next-event estimation + MIS); linear radiance\n"
               "%s%s", own, tool_light_help());
}

/* the command line into ta; -1: go on, else the exit code (--help 0; bad usage 2, printed) */
static int trace_parse(int argc, char **argv, tool_lights *lights, trace_args *ta)
{
    int i, rc;
    size_t n;
    memset(ta, 0, sizeof *ta);
    tool_trace_options_default(&ta->opt);
    ta->exposure = 1.0f;
    for (i = 0; i < argc; ++i) {
        const char *a = argv[i];
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            trace_usage(stdout);
            return 0;
        }
        if ((rc = tool_light_option("trace", argc, argv, &i, lights)) == 0)
            rc = tool_args_parse("trace", trace_table, ta, &ta->given, argc, argv, &i);
        if (rc == 2) return 2;
        if (rc == 1) continue;
        if (a[0] == '-' && a[1]) {
            fprintf(stderr, "rad trace: unknown option '%s'\n", a);
            trace_usage(stderr);
            return 2;
        }
        if (ta->scene) {
            fprintf(stderr, "rad trace: more than one scene ('%s' and '%s')\n", ta->scene, a);
            return 2;
        }
        ta->scene = a;
    }
    if (!ta->scene || !ta->out) {
        trace_usage(stderr);
        return 2;
    }
    n = strlen(ta->out);
    if (n < 4 || (strcmp(ta->out + n - 4, ".pfm") && strcmp(ta->out + n - 4, ".png") && strcmp(ta->out + n - 4, ".PFM") &&
                  strcmp(ta->out + n - 4, ".PNG"))) {
        fprintf(stderr, "rad trace: -o wants a .pfm or .png file, got '%s'\n", ta->out);
        return 2;
    }
    return -1;
}

static double trace_now(void)
{
#ifdef _OPENMP
    return omp_get_wtime();
#else
    return (double)clock() / (double)CLOCKS_PER_SEC;
#endif
}

static int trace_main(int argc, char **argv, tool_lights *lights)
{
    trace_args ta;
    const char *scene_path, *out_path;
    float fov;
    int code = 1;
    char err[512];
    tool_scene ts;
    rad_scene *scene = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_camera cam;
    rad_context ctx;
    tool_image img = { 0, 0, NULL };
    rad_result r;
    double t0, t1;
    void *light_storage = NULL;
    int pr;

    if ((pr = trace_parse(argc, argv, lights, &ta)) >= 0) return pr;
    scene_path = ta.scene;
    out_path = ta.out;
    fov = ta.fov;
    if (tool_check_output("trace", out_path, &scene_path, 1)) return 1;
    tool_set_threads((int)ta.threads);

    memset(&ts, 0, sizeof(ts));
    if (tool_load_scene(scene_path, &ts, err, sizeof(err)) != 0) {
        fprintf(stderr, "rad trace: %s\n", err);
        return 1;
    }
    if (tool_check_outputs("trace", &out_path, 1, ts.input_files, (int)ts.input_file_count) ||
        tool_add_lights("trace", &ts, lights, &light_storage)) {
        tool_free_scene(&ts);
        return 1;
    }
    if (ta.given & TRACE_GIVEN_CAMERA) {
        cam = ta.cam;
        cam.fov_y_degrees = fov > 0.0f ? fov : (ts.has_camera ? ts.camera.fov_y_degrees : 45.0f);
    } else {
        cam = ts.camera;
        if (fov > 0.0f) cam.fov_y_degrees = fov;
        if (!(cam.fov_y_degrees > 0.0f)) cam.fov_y_degrees = 45.0f;
    }

    memset(&ctx, 0, sizeof(ctx));
    ctx.log = tool_log;
    ctx.progress = tool_progress;
    r = rad_scene_create(&ts.desc, &ctx, &scene);
    if (r != RAD_SUCCESS) {
        fprintf(stderr, "rad trace: %s: rad_scene_create failed: %s\n", scene_path, rad_result_string(r));
        goto done;
    }
    r = rad_bvh_create(scene, &ctx, &bvh);
    if (r != RAD_SUCCESS) {
        fprintf(stderr, "rad trace: building the BVH failed: %s\n", rad_result_string(r));
        goto done;
    }
    rad_bvh_raycaster(bvh, &rc);
    if (!(ta.given & TRACE_GIVEN_CAMERA) && !ts.has_camera) {
        tool_choose_camera("trace", scene, &rc, ta.opt.width, ta.opt.height, &cam);
        if (fov > 0.0f) cam.fov_y_degrees = fov;
    }
    {
        uint32_t t, emitters = 0;
        for (t = 0; t < scene->triangle_count; ++t) {
            const float *Le = scene->materials_table[scene->materials[t]].emission;
            if (Le[0] > 0.0f || Le[1] > 0.0f || Le[2] > 0.0f) ++emitters;
        }
        fprintf(stderr, "rad trace: %s: %u triangles, %u emissive, %u analytic lights; %dx%d, %d spp, seed %u\n",
                scene_path, scene->triangle_count, emitters, ts.light_count, ta.opt.width, ta.opt.height, ta.opt.spp,
                ta.opt.seed);
        if (!emitters && !ts.light_count)
            fprintf(stderr, "rad trace: warning: the scene has no emitters and no lights: the image is black\n");
    }
    t0 = trace_now();
    r = (rad_result)tool_trace_image(scene, &rc, ts.lights, ts.light_count, &cam, &ta.opt, &ctx, &img);
    t1 = trace_now();
    if (r != RAD_SUCCESS) {
        fprintf(stderr, "rad trace: path tracing failed: %s\n", rad_result_string(r));
        goto done;
    }
    fprintf(stderr, "rad trace: %.2f s (%.3g samples/s)\n", t1 - t0,
            (double)ta.opt.width * (double)ta.opt.height * (double)ta.opt.spp / (t1 - t0 > 0.0 ? t1 - t0 : 1e-9));
    if (tool_image_write(out_path, &img, ta.exposure) != 0) {
        fprintf(stderr, "rad trace: %s\n", tool_output_error());
        goto done;
    }
    fprintf(stderr, "rad trace: wrote %s\n", out_path);
    code = 0;
done:
    tool_image_free(&img);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(scene);
    tool_free_scene(&ts);
    tool_lights_release(light_storage);
    return code;
}

int tool_cmd_trace(int argc, char **argv)
{
    tool_lights lights;
    int rc;
    memset(&lights, 0, sizeof lights);
    rc = trace_main(argc, argv, &lights);
    tool_lights_free(&lights);
    return rc;
}
