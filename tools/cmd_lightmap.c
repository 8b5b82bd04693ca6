/* cmd_lightmap.c - rad lightmap: a lightmap of a scene over its second uv set.

   rad lightmap SCENE -o OUT.pfm|OUT.exr|OUT.png [--size N|WxH] [--sh] [--texel-samples N] [--proxy aavp|vp]
                [--visibility-rays N] [--gather exact|hemisphere] [--hemisphere-rays N] [--unwrap] [--render VIEW.png|.pfm [--render-size WxH] [--aa N]]
                [classic options] [--threads N] [--exposure X]

   The classic solution (classic.c: patches, F, direct light as the source, B = E + L), or with
   --proxy aavp|vp the virtual patches' (H = F (E + L) per virtual patch, rad_lightmap_gather_vp),
   is gathered into the texels of the lightmap uv set (>>api_lightmap): every mesh's second uv set
   (glTF TEXCOORD_1, assimp's second channel), or, when some mesh has none (or --unwrap), the
   simple automatic unwrap of unwrap.c. RGB: irradiance (W m^-2) = the direct light of the
   lights and emitters per texel + the irradiance from the secondary sources; --sh: the L1
   spherical harmonics of the indirect radiance only (engines add direct light per pixel),
   four files OUT.L00.pfm, OUT.L1m1.pfm, OUT.L10.pfm, OUT.L11.pfm (or .exr; PNG cannot hold the
   negative coefficients). .exr is 32-bit float OpenEXR (image.c, tinyexr). Then dilation into the gutters and seam stitching. --render draws
   the scene's camera view (or the one rad trace would choose) shaded from the lightmap alone:
   radiance = emission + albedo x bilinear lightmap irradiance / pi, N x N samples a pixel, to
   compare with `rad trace` (rad compare). */
#include "tool.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void lightmap_usage(FILE *f)
{
    fprintf(f, "usage: rad lightmap SCENE -o OUT.pfm|OUT.exr|OUT.png [options]\n"
               "  bakes the classic radiosity solution into a lightmap over the second uv set\n"
               "  (glTF TEXCOORD_1); meshes without one are unwrapped automatically (simple charts)\n"
               "  --size N|WxH          atlas texels (default 256; with an unwrap whose charts do not fit,\n"
               "                        the smallest power of two up to 4096 that they fit, said on stderr)\n"
               "  --sh                  L1 spherical harmonics of the indirect light (4 PFM or EXR files\n"
               "                        OUT.L00.pfm OUT.L1m1.pfm OUT.L10.pfm OUT.L11.pfm; see docs/methods/lightmap.md)\n"
               "  --texel-samples N     sample points per texel, a square grid (default 4, at most 16)\n"
               "  --visibility-rays N   shadow rays per sample point and patch (default 2, at most 64)\n"
               "  --gather M            exact (every patch's form factor from every sample) or hemisphere\n"
               "                        (the brightest patches exactly, the rest by rays; its cost does not\n"
               "                        grow with the patches); default: hemisphere when samples x patches\n"
               "                        exceeds 2e7\n"
               "  --hemisphere-rays N   rays per texel of the hemisphere gather (default 256, at most 65536)\n"
               "  --unwrap              unwrap even when the file has a second uv set\n"
               "  --proxy P             the indirect light from patches (the classic solution, default), aavp or\n"
               "                        vp (virtual patches: a few thousand unknowns whatever the triangle count,\n"
               "                        for real buildings; each texel gathers their H at its sample points; RGB\n"
               "                        only, not --sh); --vp-resolution R (default 16), --face-points P (default 16);\n"
               "                        or hierarchical (the hierarchical solution's smooth lookup at each sample;\n"
               "                        --hr-eps E, default 1e-5: coarser is faster on large scenes)\n"
               "  --render VIEW         also render the camera view shaded from the lightmap (.png, .pfm, .exr;\n"
               "                        not with --sh): radiance = emission + albedo x irradiance / pi\n"
               "  --render-size WxH     its size (default 256x256); --aa N: N x N samples a pixel (default 4, as\n"
               "                        rad render's 16 samples)\n"
               "  --exposure X          PNG only: scale of the irradiance before 8-bit sRGB (default 1/pi:\n"
               "                        the radiance of a white surface)\n"
               "  --threads N           worker threads (default: all cores)\n"
               "%s%s", tool_classic_help(), tool_light_help());
}

/* a path with 'tag' inserted before the extension: a.pfm -> a.L00.pfm */
static char *lightmap_tagged(const char *path, const char *tag)
{
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    size_t stem = (dot && (!slash || dot > slash)) ? (size_t)(dot - path) : strlen(path);
    char *out = (char *)tool_calloc(strlen(path) + strlen(tag) + 3, 1);
    memcpy(out, path, stem);
    sprintf(out + stem, ".%s%s", tag, path + stem);
    return out;
}

/* the view shaded from an RGB irradiance lightmap: one closest hit per sample, the lightmap
   read at the hit's lightmap uv; back faces and misses are black (one-sided like rad trace) */
static int lightmap_render(const tool_world *w, const rad_lightmap *lm, const float *values, int width, int height,
                           int aa, const char *path, float exposure, tool_output_set *set)
{
    rad_camera cam = w->file.camera;
    tool_image img;
    int x, y, sx, sy, bad;
    if (!w->file.has_camera) tool_choose_camera("lightmap", w->scene, &w->rc, width, height, &cam);
    if (!(cam.fov_y_degrees > 0.0f)) cam.fov_y_degrees = 45.0f;
    if (tool_image_alloc(&img, width, height)) { fprintf(stderr, "rad lightmap: out of memory for the view\n"); return 1; }
    for (y = 0; y < height; ++y)
        for (x = 0; x < width; ++x) {
            float acc[3] = {0.0f, 0.0f, 0.0f};
            for (sy = 0; sy < aa; ++sy)
                for (sx = 0; sx < aa; ++sx) {
                    rad_ray ray;
                    rad_hit hit;
                    const float *t, *n;
                    float u, v, e[3], rho[3];
                    int k;
                    rad_camera_ray(&cam, (uint32_t)width, (uint32_t)height, x + (sx + 0.5f) / aa, y + (sy + 0.5f) / aa, &ray);
                    if (w->rc.intersect(w->rc.user, &ray, 1, &hit) != RAD_SUCCESS || hit.triangle == RAD_NONE) continue;
                    n = w->scene->normals + 3 * (size_t)hit.triangle;
                    if (n[0] * ray.dir[0] + n[1] * ray.dir[1] + n[2] * ray.dir[2] >= 0.0f) continue;
                    rad_scene_emission(w->scene, hit.triangle, hit.b1, hit.b2, e);
                    for (k = 0; k < 3; ++k) acc[k] += e[k];
                    if (!w->scene->lightmapped[hit.triangle]) continue;
                    t = w->scene->lightmap_uvs + 6 * (size_t)hit.triangle;
                    u = t[0] + hit.b1 * (t[2] - t[0]) + hit.b2 * (t[4] - t[0]);
                    v = t[1] + hit.b1 * (t[3] - t[1]) + hit.b2 * (t[5] - t[1]);
                    rad_lightmap_sample(lm, 3, values, u, v, e);
                    rad_scene_albedo(w->scene, hit.triangle, hit.b1, hit.b2, rho);
                    for (k = 0; k < 3; ++k) acc[k] += rho[k] * e[k] / 3.14159265f;
                }
            for (sx = 0; sx < 3; ++sx) img.rgb[3 * ((size_t)y * width + x) + sx] = acc[sx] / (float)(aa * aa);
        }
    bad = tool_image_write_into(set, path, &img, exposure * 3.14159265f);
    tool_image_free(&img);
    if (bad) { fprintf(stderr, "rad lightmap: %s\n", tool_output_error()); return 1; }
    return 0;
}

static int lightmap_is_png(const char *path)
{
    size_t n = strlen(path);
    return n >= 4 && (!strcmp(path + n - 4, ".png") || !strcmp(path + n - 4, ".PNG"));
}

static int lightmap_main(int argc, char **argv, tool_lights *lights)
{
    const char *scene_path = NULL, *out_path = NULL, *render_path = NULL;
    int rw = 256, rh = 256;
    uint32_t aa = 2;
    tool_classic_options co;
    tool_world w;
    tool_lightmap_baked bk;
    tool_lightmap_request rq;
    const rad_lightmap *lm = NULL;
    int width = TOOL_LIGHTMAP_SIZE, height = TOOL_LIGHTMAP_SIZE, size_given = 0, sh = 0, force_unwrap = 0, a, code = 1;
    uint32_t threads = 0, texel_samples = TOOL_LIGHTMAP_TEXEL_SAMPLES, vis = TOOL_LIGHTMAP_VISIBILITY_RAYS, i, ch,
             hemi_rays = TOOL_LIGHTMAP_HEMISPHERE_RAYS;
    int gather = TOOL_LIGHTMAP_GATHER_AUTO; /* else a rad_lightmap_gather_method */
    tool_lightmap_proxy px;
    int px_opts = 0, hr_opts = 0;
    const float *values = NULL;
    float exposure = 0.31830988f;
    memset(&bk, 0, sizeof bk);
    memset(&px, 0, sizeof px);
    tool_classic_options_default(&co);
    for (a = 0; a < argc; ++a) {
        const char *o = argv[a];
        int k;
        if (!strcmp(o, "--help") || !strcmp(o, "-h")) {
            lightmap_usage(stdout);
            return 0;
        }
        if ((k = tool_classic_option("lightmap", argc, argv, &a, &co)) != 0) {
            if (k == 2) return 2;
            continue;
        }
        if ((k = tool_light_option("lightmap", argc, argv, &a, lights)) != 0) {
            if (k == 2) return 2;
            continue;
        }
        if (!strcmp(o, "--sh")) { sh = 1; continue; }
        if (!strcmp(o, "--proxy") && a + 1 < argc) {
            const char *v = argv[++a];
            if (!strcmp(v, "aavp")) px.kind = TOOL_PROXY_AAVP;
            else if (!strcmp(v, "vp")) px.kind = TOOL_PROXY_VP;
            else if (!strcmp(v, "hierarchical")) px.kind = TOOL_LIGHTMAP_HIERARCHICAL;
            else if (!strcmp(v, "patches")) px.kind = TOOL_PROXY_PATCHES;
            else { fprintf(stderr, "rad lightmap: unknown --proxy '%s' (patches, aavp, vp or hierarchical)\n", v); return 2; }
            continue;
        }
        if ((!strcmp(o, "--vp-resolution") || !strcmp(o, "--face-points")) && a + 1 < argc) {
            uint32_t *dst = o[2] == 'v' ? &px.resolution : &px.face_points, hi = 4096u;
            if (tool_parse_uint("lightmap", o, argv[++a], dst)) return 2;
            if (*dst == 0 || *dst > hi) { fprintf(stderr, "rad lightmap: %s must be 1 to %u\n", o, hi); return 2; }
            px_opts = 1;
            continue;
        }
        if (!strcmp(o, "--hr-eps") && a + 1 < argc) {
            if (tool_parse_float("lightmap", o, argv[++a], &px.hr_eps)) return 2;
            if (!(px.hr_eps > 0.0f && px.hr_eps < 1.0f)) { fprintf(stderr, "rad lightmap: --hr-eps must be in (0, 1)\n"); return 2; }
            hr_opts = 1;
            continue;
        }
        if (!strcmp(o, "--unwrap")) { force_unwrap = 1; continue; }
        if (o[0] == '-' && strcmp(o, "-") != 0 && a + 1 >= argc) {
            fprintf(stderr, "rad lightmap: %s needs a value (or is unknown; try rad lightmap --help)\n", o);
            return 2;
        }
        if (!strcmp(o, "-o")) out_path = argv[++a];
        else if (!strcmp(o, "--render")) render_path = argv[++a];
        else if (!strcmp(o, "--render-size")) {
            if (tool_parse_size(argv[++a], &rw, &rh) || tool_check_size("lightmap", rw, rh)) {
                fprintf(stderr, "rad lightmap: bad --render-size '%s'\n", argv[a]);
                return 2;
            }
        } else if (!strcmp(o, "--aa")) {
            if (tool_parse_uint("lightmap", o, argv[++a], &aa)) return 2;
            if (aa == 0 || aa > 16) { fprintf(stderr, "rad lightmap: --aa must be 1 to 16\n"); return 2; }
        } else if (!strcmp(o, "--size")) {
            const char *v = argv[++a];
            size_given = 1;
            if (strchr(v, 'x')) {
                if (tool_parse_size(v, &width, &height)) { fprintf(stderr, "rad lightmap: bad --size '%s'\n", v); return 2; }
            } else {
                uint32_t n;
                if (tool_parse_uint("lightmap", o, v, &n)) return 2;
                width = height = (int)(n > 16384u ? 16385u : n);
            }
            if (width < 4 || height < 4 || width > 16384 || height > 16384) {
                fprintf(stderr, "rad lightmap: --size must be 4 to 16384 texels a side\n");
                return 2;
            }
        } else if (!strcmp(o, "--texel-samples")) {
            if (tool_parse_uint("lightmap", o, argv[++a], &texel_samples)) return 2;
            if (texel_samples == 0 || texel_samples > 16) { fprintf(stderr, "rad lightmap: --texel-samples must be 1 to 16\n"); return 2; }
        } else if (!strcmp(o, "--visibility-rays")) {
            if (tool_parse_uint("lightmap", o, argv[++a], &vis)) return 2;
            if (vis == 0 || vis > 64) { fprintf(stderr, "rad lightmap: --visibility-rays must be 1 to 64\n"); return 2; }
        } else if (!strcmp(o, "--gather")) {
            const char *v = argv[++a];
            if (v && !strcmp(v, "exact")) gather = RAD_LIGHTMAP_GATHER_EXACT;
            else if (v && !strcmp(v, "hemisphere")) gather = RAD_LIGHTMAP_GATHER_HEMISPHERE;
            else { fprintf(stderr, "rad lightmap: --gather must be exact or hemisphere\n"); return 2; }
        } else if (!strcmp(o, "--hemisphere-rays")) {
            if (tool_parse_uint("lightmap", o, argv[++a], &hemi_rays)) return 2;
            if (hemi_rays == 0 || hemi_rays > 65536) { fprintf(stderr, "rad lightmap: --hemisphere-rays must be 1 to 65536\n"); return 2; }
        } else if (!strcmp(o, "--exposure")) {
            if (tool_parse_float("lightmap", o, argv[++a], &exposure)) return 2;
            if (!(exposure > 0.0f)) { fprintf(stderr, "rad lightmap: --exposure must be > 0\n"); return 2; }
        } else if (!strcmp(o, "--threads")) {
            if (tool_parse_threads("lightmap", o, argv[++a], &threads)) return 2;
        } else if (o[0] == '-' && o[1]) {
            fprintf(stderr, "rad lightmap: unknown option '%s' (try rad lightmap --help)\n", o);
            return 2;
        } else if (!scene_path) {
            scene_path = o;
        } else {
            fprintf(stderr, "rad lightmap: more than one scene ('%s', '%s')\n", scene_path, o);
            return 2;
        }
    }
    if (!scene_path || !out_path) {
        lightmap_usage(stderr);
        return 2;
    }
    if (px_opts && (!px.kind || px.kind == TOOL_LIGHTMAP_HIERARCHICAL)) {
        fprintf(stderr, "rad lightmap: --vp-resolution and --face-points are for --proxy aavp|vp\n");
        return 2;
    }
    if (hr_opts && px.kind != TOOL_LIGHTMAP_HIERARCHICAL) {
        fprintf(stderr, "rad lightmap: --hr-eps is for --proxy hierarchical\n");
        return 2;
    }
    if (px.kind && sh) {
        fprintf(stderr, "rad lightmap: --sh needs the classic gather (the virtual patches' gather has no direction): leave out --proxy\n");
        return 2;
    }
    if (sh && lightmap_is_png(out_path)) {
        fprintf(stderr, "rad lightmap: --sh writes PFM or EXR files (PNG cannot hold negative coefficients): use -o NAME.pfm or NAME.exr\n");
        return 2;
    }
    if (sh && render_path) {
        fprintf(stderr, "rad lightmap: --render shades from the RGB lightmap: leave out --sh\n");
        return 2;
    }
    if (tool_check_size("lightmap", width, height)) return 2;
    if (tool_image_check_format("lightmap", out_path) || (render_path && tool_image_check_format("lightmap", render_path))) return 2;
    {
        /* the files written: OUT (or its four SH layers) and the view; checked before the
           work, and again against every file the scene was read from once it is loaded */
        static const char *const tags[4] = {"L00", "L1m1", "L10", "L11"};
        char *layers[4] = {NULL, NULL, NULL, NULL};
        const char *outs[5];
        int n = 0, bad = 0, k;
        if (sh)
            for (k = 0; k < 4; ++k) outs[n++] = layers[k] = lightmap_tagged(out_path, tags[k]);
        else
            outs[n++] = out_path;
        if (render_path) outs[n++] = render_path;
        for (k = 0; k < n && !bad; ++k) bad = tool_check_output("lightmap", outs[k], &scene_path, 1);
        if (!bad) bad = tool_check_outputs("lightmap", outs, n, &scene_path, 1);
        tool_set_threads((int)threads);
        if (!bad && tool_open_world_lit("lightmap", scene_path, lights, &w)) bad = 2;
        if (!bad && tool_check_outputs("lightmap", outs, n, w.file.input_files, (int)w.file.input_file_count)) {
            tool_close_world(&w);
            bad = 1;
        }
        for (k = 0; k < 4; ++k) free(layers[k]);
        if (bad) return 1;
    }
    tool_lightmap_request_default(&rq);
    rq.width = width;
    rq.height = height;
    rq.auto_size = !size_given;
    rq.texel_samples = texel_samples;
    rq.visibility_rays = vis;
    rq.gather = gather;
    rq.hemisphere_rays = hemi_rays;
    rq.sh = sh;
    rq.force_unwrap = force_unwrap;
    rq.direct = !sh;
    rq.proxy = px.kind ? &px : NULL;
    if (tool_lightmap_bake("lightmap", &w, &co, &rq, &bk)) goto done;
    width = (int)bk.lm->width; /* the unwrap may have chosen a larger atlas */
    height = (int)bk.lm->height;
    lm = bk.lm;
    values = bk.values;
    ch = sh ? 12u : 3u;
    {
        /* the layers (and the --render view) replace the old files together or not at all */
        tool_image img;
        tool_output_set set;
        uint32_t layers = sh ? 4u : 1u, l;
        static const char *const tags[4] = {"L00", "L1m1", "L10", "L11"};
        char *paths[4] = {NULL, NULL, NULL, NULL};
        int bad = 0;
        memset(&set, 0, sizeof set);
        for (l = 0; l < layers && !bad; ++l) {
            paths[l] = sh ? lightmap_tagged(out_path, tags[l]) : NULL;
            if (tool_image_alloc(&img, width, height)) {
                fprintf(stderr, "rad lightmap: out of memory\n");
                tool_output_set_abort(&set);
                bad = 1;
                break;
            }
            for (i = 0; i < (uint32_t)(width * height); ++i) memcpy(img.rgb + 3 * (size_t)i, values + (size_t)i * ch + 3 * l, 3 * sizeof(float));
            if (tool_image_write_into(&set, paths[l] ? paths[l] : out_path, &img, exposure) != 0) {
                fprintf(stderr, "rad lightmap: %s\n", tool_output_error());
                bad = 1;
            }
            tool_image_free(&img);
        }
        if (!bad && render_path && lightmap_render(&bk.w, lm, values, rw, rh, (int)aa, render_path, exposure, &set)) {
            tool_output_set_abort(&set);
            bad = 1;
        }
        if (!bad && tool_output_set_commit(&set) != 0) {
            fprintf(stderr, "rad lightmap: %s\n", tool_output_error());
            bad = 1;
        }
        for (l = 0; l < layers; ++l) {
            if (!bad) fprintf(stderr, "rad lightmap: wrote %s\n", paths[l] ? paths[l] : out_path);
            free(paths[l]);
        }
        if (bad) goto done;
        if (render_path) fprintf(stderr, "rad lightmap: wrote the view %s\n", render_path);
    }
    code = 0;
done:
    tool_lightmap_bake_free(&bk);
    tool_close_world(&w);
    return code;
}

int tool_cmd_lightmap(int argc, char **argv)
{
    tool_lights lights;
    int rc;
    memset(&lights, 0, sizeof lights);
    rc = lightmap_main(argc, argv, &lights);
    tool_lights_free(&lights);
    return rc;
}
