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

static void trace_usage(FILE *f)
{
    fprintf(f, "usage: rad trace SCENE -o OUT.pfm|OUT.png [options]\n"
               "  path-traced reference image (diffuse, next-event estimation + MIS); linear radiance\n"
               "  --camera PX,PY,PZ:TX,TY,TZ:UX,UY,UZ   camera (default: the scene's camera)\n"
               "  --fov DEG          vertical field of view (default: the scene's, else 45)\n"
               "  --size WxH         image size (default 256x256; at most 2 GiB of image: 12 bytes a pixel)\n"
               "  --spp N            samples per pixel (default 64)\n"
               "  --seed S           random seed (default 0); same seed, same image on any thread count\n"
               "  --max-depth N      path length cap (default 64)\n"
               "  --rr-depth N       Russian roulette from this bounce on (default 16)\n"
               "  --threads N        worker threads (default: all cores; at most 1024)\n"
               "  --exposure X       scale before 8-bit sRGB encoding (PNG only; default 1)\n"
               "  -o FILE            .pfm (linear float radiance) or .png (8-bit sRGB)\n"
               "%s", tool_light_help());
}

static double trace_now(void)
{
#ifdef _OPENMP
    return omp_get_wtime();
#else
    return (double)clock() / (double)CLOCKS_PER_SEC;
#endif
}

static int parse_int(const char *s, long lo, long hi, long *out)
{
    char *end;
    long v;
    if (!s || !*s) return -1;
    v = strtol(s, &end, 10);
    if (*end || v < lo || v > hi) return -1;
    *out = v;
    return 0;
}

static int trace_main(int argc, char **argv, tool_lights *lights)
{
    const char *scene_path = NULL, *out_path = NULL, *camera_text = NULL;
    tool_trace_options opt;
    float fov = 0.0f, exposure = 1.0f;
    long threads = 0, v;
    int i, code = 1;
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
    int lr;

    tool_trace_options_default(&opt);
    for (i = 0; i < argc; ++i) {
        const char *a = argv[i], *next = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            trace_usage(stdout);
            return 0;
        }
        lr = tool_light_option("trace", argc, argv, &i, lights);
        if (lr == 2) return 2;
        if (lr == 1) continue;
        if (a[0] != '-' || !a[1]) {
            if (scene_path) {
                fprintf(stderr, "rad trace: more than one scene ('%s' and '%s')\n", scene_path, a);
                return 2;
            }
            scene_path = a;
            continue;
        }
        if (!next) {
            fprintf(stderr, "rad trace: %s needs a value\n", a);
            return 2;
        }
        ++i;
        if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
            out_path = next;
        } else if (!strcmp(a, "--camera")) {
            camera_text = next;
        } else if (!strcmp(a, "--fov")) {
            char *end;
            fov = strtof(next, &end);
            if (*end || !(fov > 0.0f && fov < 180.0f)) {
                fprintf(stderr, "rad trace: --fov wants degrees in (0, 180), got '%s'\n", next);
                return 2;
            }
        } else if (!strcmp(a, "--size")) {
            if (tool_parse_size(next, &opt.width, &opt.height) != 0 || opt.width <= 0 || opt.height <= 0) {
                fprintf(stderr, "rad trace: --size wants WxH, got '%s'\n", next);
                return 2;
            }
            if (tool_check_size("trace", opt.width, opt.height)) return 2;
        } else if (!strcmp(a, "--spp")) {
            if (parse_int(next, 1, 1L << 24, &v) != 0) {
                fprintf(stderr, "rad trace: --spp wants a positive integer, got '%s'\n", next);
                return 2;
            }
            opt.spp = (int)v;
        } else if (!strcmp(a, "--seed")) {
            if (parse_int(next, 0, 0xFFFFFFFFL, &v) != 0) {
                fprintf(stderr, "rad trace: --seed wants an integer in [0, 2^32), got '%s'\n", next);
                return 2;
            }
            opt.seed = (uint32_t)v;
        } else if (!strcmp(a, "--max-depth")) {
            if (parse_int(next, 1, 100000, &v) != 0) {
                fprintf(stderr, "rad trace: --max-depth wants a positive integer, got '%s'\n", next);
                return 2;
            }
            opt.max_depth = (int)v;
        } else if (!strcmp(a, "--rr-depth")) {
            if (parse_int(next, 1, 100000, &v) != 0) {
                fprintf(stderr, "rad trace: --rr-depth wants a positive integer, got '%s'\n", next);
                return 2;
            }
            opt.rr_depth = (int)v;
        } else if (!strcmp(a, "--threads")) {
            uint32_t t = 0;
            if (tool_parse_threads("trace", a, next, &t)) return 2;
            threads = (long)t;
        } else if (!strcmp(a, "--exposure")) {
            char *end;
            exposure = strtof(next, &end);
            if (*end || !(exposure > 0.0f && exposure < 1e30f)) {
                fprintf(stderr, "rad trace: --exposure wants a positive number, got '%s'\n", next);
                return 2;
            }
        } else {
            fprintf(stderr, "rad trace: unknown option '%s'\n", a);
            trace_usage(stderr);
            return 2;
        }
    }
    if (!scene_path || !out_path) {
        trace_usage(stderr);
        return 2;
    }
    {
        size_t n = strlen(out_path);
        if (n < 4 || (strcmp(out_path + n - 4, ".pfm") && strcmp(out_path + n - 4, ".png") &&
                      strcmp(out_path + n - 4, ".PFM") && strcmp(out_path + n - 4, ".PNG"))) {
            fprintf(stderr, "rad trace: -o wants a .pfm or .png file, got '%s'\n", out_path);
            return 2;
        }
    }
    if (tool_check_output("trace", out_path, &scene_path, 1)) return 1;
    tool_set_threads((int)threads);

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
    if (camera_text) {
        memset(&cam, 0, sizeof(cam));
        const char *why;
        if (tool_parse_camera(camera_text, &cam, &why) != 0) {
            fprintf(stderr, "rad trace: bad --camera '%s': %s\n", camera_text, why);
            tool_free_scene(&ts);
            tool_lights_release(light_storage);
            return 2;
        }
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
    if (!camera_text && !ts.has_camera) {
        tool_choose_camera("trace", scene, &rc, opt.width, opt.height, &cam);
        if (fov > 0.0f) cam.fov_y_degrees = fov;
    }
    {
        uint32_t t, emitters = 0;
        for (t = 0; t < scene->triangle_count; ++t) {
            const float *Le = scene->materials_table[scene->materials[t]].emission;
            if (Le[0] > 0.0f || Le[1] > 0.0f || Le[2] > 0.0f) ++emitters;
        }
        fprintf(stderr, "rad trace: %s: %u triangles, %u emissive, %u analytic lights; %dx%d, %d spp, seed %u\n",
                scene_path, scene->triangle_count, emitters, ts.light_count, opt.width, opt.height, opt.spp,
                opt.seed);
        if (!emitters && !ts.light_count)
            fprintf(stderr, "rad trace: warning: the scene has no emitters and no lights: the image is black\n");
    }
    t0 = trace_now();
    r = (rad_result)tool_trace_image(scene, &rc, ts.lights, ts.light_count, &cam, &opt, &ctx, &img);
    t1 = trace_now();
    if (r != RAD_SUCCESS) {
        fprintf(stderr, "rad trace: path tracing failed: %s\n", rad_result_string(r));
        goto done;
    }
    fprintf(stderr, "rad trace: %.2f s (%.3g samples/s)\n", t1 - t0,
            (double)opt.width * (double)opt.height * (double)opt.spp / (t1 - t0 > 0.0 ? t1 - t0 : 1e-9));
    if (tool_image_write(out_path, &img, exposure) != 0) {
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
