/* cmd_lightmap.c - rad lightmap: a lightmap of a scene over its second uv set.

   rad lightmap SCENE -o OUT.pfm|OUT.exr|OUT.png [--layers OUT.radr] [--size N|WxH] [--sh] [--texel-samples N] [--proxy aavp|vp]
                [--visibility-rays N] [--gather exact|hemisphere] [--hemisphere-rays N] [--final-gather N] [--unwrap] [--render VIEW.png|.pfm [--render-size WxH] [--aa N]]
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
   compare with `rad trace` (rad compare). --layers saves the engine tier's bake itself
   (rad_baker_result_save_memory: its light layers and metadata) for an engine's
   rad_baker_result_load_file; `rad info` describes it. */
#include "tool.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* rad lightmap's command line */
typedef struct lightmap_args {
    const char *scene, *out, *render; /* SCENE, -o, --render */
    const char *layers;        /* --layers */
    tool_classic_options co;
    tool_lightmap_request rq;  /* --size, --sh, --texel-samples, --visibility-rays, --gather, ... */
    tool_lightmap_proxy px;    /* --proxy and its options */
    int rw, rh;                /* --render-size */
    uint32_t aa;               /* --aa: N x N samples a pixel of --render */
    float exposure;            /* --exposure */
    uint32_t threads;
    uint32_t given;            /* LIGHTMAP_GIVEN_* */
} lightmap_args;
enum { LIGHTMAP_GIVEN_SIZE = 1, LIGHTMAP_GIVEN_VP = 2, LIGHTMAP_GIVEN_HR = 4, LIGHTMAP_GIVEN_PROXY = 8 };

/* --size N|WxH into the request's width and height (field: width) */
static int parse_atlas_size(const char *cmd, const tool_arg *t, const char *v, void *field)
{
    tool_lightmap_request *rq = (tool_lightmap_request *)((char *)field - offsetof(tool_lightmap_request, width));
    if (strchr(v, 'x')) {
        if (tool_parse_size(v, &rq->width, &rq->height)) {
            fprintf(stderr, "rad %s: bad --size '%s'\n", cmd, v);
            return 2;
        }
    } else {
        uint32_t n;
        if (tool_parse_uint(cmd, t->name, v, &n)) return 2;
        rq->width = rq->height = (int)(n > 16384u ? 16385u : n);
    }
    if (rq->width < 4 || rq->height < 4 || rq->width > 16384 || rq->height > 16384) {
        fprintf(stderr, "rad %s: --size must be 4 to 16384 texels a side\n", cmd);
        return 2;
    }
    return 0;
}

/* --render-size WxH into rw, rh (field: rw) */
static int parse_render_size(const char *cmd, const tool_arg *t, const char *v, void *field)
{
    lightmap_args *la = (lightmap_args *)((char *)field - offsetof(lightmap_args, rw));
    (void)t;
    if (tool_parse_size(v, &la->rw, &la->rh) || tool_check_size(cmd, la->rw, la->rh)) {
        fprintf(stderr, "rad %s: bad --render-size '%s'\n", cmd, v);
        return 2;
    }
    return 0;
}

static int parse_threads(const char *cmd, const tool_arg *t, const char *v, void *field)
{
    return tool_parse_threads(cmd, t->name, v, (uint32_t *)field) ? 2 : 0;
}

static const uint32_t proxy_values[] = {TOOL_PROXY_PATCHES, TOOL_PROXY_AAVP, TOOL_PROXY_VP, TOOL_LIGHTMAP_HIERARCHICAL};
static const uint32_t gather_values[] = {RAD_LIGHTMAP_GATHER_EXACT, RAD_LIGHTMAP_GATHER_HEMISPHERE};
#define LA(f) offsetof(lightmap_args, f)
#define LA_UINT(name, val, f, lo, hi, given, bad, help) \
    {TOOL_ARG_UINT, name, val, LA(f), lo, hi, 0, given, bad, NULL, NULL, NULL, 0, help}
#define LA_FLAG(name, f, help) {TOOL_ARG_FLAG, name, NULL, LA(f), 1, 0, 0, 0, NULL, NULL, NULL, NULL, 0, help}
#define LA_CUSTOM(name, val, f, fn, given, help) \
    {TOOL_ARG_CUSTOM, name, val, LA(f), 0, 0, 0, given, NULL, NULL, NULL, fn, 0, help}
/* rad lightmap's own options (the classic and light options are classic.c's and lights.c's) */
static const tool_arg lightmap_table[] = {
    {TOOL_ARG_STRING, "-o", "FILE", LA(out), 0, 0, 0, 0, NULL, NULL, NULL, NULL, 0,
     "the lightmap: .pfm or .exr (linear irradiance, W m^-2) or .png (exposure applied); or\n"
     ".glb / .gltf: the scene for engines, with TEXCOORD_1, the lightmap as a PNG image named in\n"
     "each material's extras, its HDR copy beside it and the view as a camera\n"
     "(docs/engine-formats.md; RGB only, not --sh)"},
    {TOOL_ARG_STRING, "--layers", "FILE", LA(layers), 0, 0, 0, 0, NULL, NULL, NULL, NULL, 0,
     "also save the engine tier's bake as one file (.radr: its light layers and metadata,\n"
     "rad_baker_result_load_file mixes them again; docs/engine-formats.md); rad info FILE\n"
     "describes it. Needs the tier's bake: the patches or --proxy aavp|vp, and a scene\n"
     "that emits light"},
    LA_CUSTOM("--size", "N|WxH", rq.width, parse_atlas_size, LIGHTMAP_GIVEN_SIZE,
              "atlas texels (default 256; with an unwrap whose charts do not fit, the smallest\n"
              "power of two up to 4096 that they fit, said on stderr)"),
    LA_FLAG("--sh", rq.sh,
            "L1 spherical harmonics of the indirect light (4 PFM or EXR files OUT.L00.pfm\n"
            "OUT.L1m1.pfm OUT.L10.pfm OUT.L11.pfm; see docs/methods/lightmap.md)"),
    LA_UINT("--texel-samples", "N", rq.texel_samples, 1, 16, 0, "must be 1 to 16",
            "sample points per texel, a square grid (default 4, at most 16)"),
    LA_UINT("--visibility-rays", "N", rq.visibility_rays, 1, 64, 0, "must be 1 to 64",
            "shadow rays per sample point and patch (default 2, at most 64)"),
    {TOOL_ARG_CHOICE, "--gather", "M", LA(rq.gather), 0, 0, 0, 0, NULL, "exact|hemisphere", gather_values, NULL, 0,
     "exact (every patch's form factor from every sample) or hemisphere (the brightest\n"
     "patches exactly, the rest by rays; its cost does not grow with the patches); default:\n"
     "hemisphere when samples x patches exceeds 2e7"},
    LA_UINT("--hemisphere-rays", "N", rq.hemisphere_rays, 1, 65536, 0, "must be 1 to 65536",
            "rays per texel of the hemisphere gather (default 256, at most 65536)"),
    LA_UINT("--final-gather", "N", rq.final_gather, 0, 4096, 0, "is at most 4096",
            "trace the first bounce from each texel with N rays (direct light at the hits, the\n"
            "solution's irradiance there) instead of reading it off the patches' averages\n"
            "(default: 32 with --proxy aavp|vp, 0 with the classic patches; the engine tier's\n"
            "bakes: the patches or --proxy aavp|vp; not --sh)"),
    LA_FLAG("--unwrap", rq.force_unwrap, "unwrap even when the file has a second uv set"),
    {TOOL_ARG_CHOICE, "--proxy", "P", LA(px.kind), 0, 0, 0, LIGHTMAP_GIVEN_PROXY, NULL, "patches|aavp|vp|hierarchical", proxy_values, NULL, 0,
     "the indirect light from patches (the classic solution, default), aavp or vp (virtual\n"
     "patches: a few thousand unknowns whatever the triangle count, for real buildings; each\n"
     "texel gathers their H at its sample points; RGB only, not --sh), or hierarchical (the\n"
     "hierarchical solution's smooth lookup at each sample)"},
    LA_UINT("--vp-resolution", "R", px.resolution, 1, 4096, LIGHTMAP_GIVEN_VP, "must be 1 to 4096",
            "--proxy aavp|vp: voxels along the longest axis (default 16)"),
    LA_UINT("--face-points", "P", px.face_points, 1, 4096, LIGHTMAP_GIVEN_VP, "must be 1 to 4096",
            "--proxy aavp|vp: Hammersley points per voxel face (default 16)"),
    {TOOL_ARG_FLOAT, "--hr-eps", "E", LA(px.hr_eps), 0.0, 1.0, TOOL_ARG_LO_OPEN | TOOL_ARG_HI_OPEN, LIGHTMAP_GIVEN_HR,
     "must be in (0, 1)", NULL, NULL, NULL, 0,
     "--proxy hierarchical: refinement tolerance (default 1e-7 per triangle, from 1e-5 to 1e-2)"},
    {TOOL_ARG_STRING, "--render", "VIEW", LA(render), 0, 0, 0, 0, NULL, NULL, NULL, NULL, 0,
     "also render the camera view shaded from the lightmap (.png, .pfm, .exr; not with --sh):\n"
     "radiance = emission + albedo x irradiance / pi"},
    LA_CUSTOM("--render-size", "WxH", rw, parse_render_size, 0, "its size (default 256x256)"),
    LA_UINT("--aa", "N", aa, 1, 16, 0, "must be 1 to 16",
            "--render: N x N samples a pixel (default 2: 4 samples; 4 gives rad render's 16)"),
    {TOOL_ARG_FLOAT, "--exposure", "X", LA(exposure), 0.0, 1e30, TOOL_ARG_LO_OPEN, 0, "must be > 0", NULL, NULL, NULL, 0,
     "PNG only: scale of the irradiance before 8-bit sRGB (default 1/pi: the radiance of a\n"
     "white surface)"},
    LA_CUSTOM("--threads", "N", threads, parse_threads, 0, "worker threads (default: all cores)"),
    {TOOL_ARG_END, NULL, NULL, 0, 0, 0, 0, 0, NULL, NULL, NULL, NULL, 0, NULL}
};

static void lightmap_usage(FILE *f)
{
    static char own[8192];
    tool_args_help_into(lightmap_table, 0, own, sizeof own);
    fprintf(f, "usage: rad lightmap SCENE -o OUT.pfm|OUT.exr|OUT.png|OUT.glb|OUT.gltf [options]\n"
               "  bakes the classic radiosity solution into a lightmap over the second uv set\n"
               "  (glTF TEXCOORD_1); meshes without one are unwrapped automatically (simple charts)\n"
               "%s%s%s",
            own, tool_classic_help(), tool_light_help());
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

/* the engine tier's result (rad_baker_result_save_memory) into the set at path; 0, or 1 after
   printing why (the set aborted) */
static int lightmap_write_layers(const char *path, const rad_baker_result *R, tool_output_set *set)
{
    rad_context ctx;
    tool_output o;
    void *buf = NULL;
    size_t size = 0;
    rad_result r;
    int ok;
    tool_context(&ctx, NULL);
    if ((r = rad_baker_result_save_memory(R, &ctx, &buf, &size)) != RAD_SUCCESS) {
        fprintf(stderr, "rad lightmap: cannot save the bake: %s\n", rad_result_string(r));
        tool_output_set_abort(set);
        return 1;
    }
    if (tool_output_open(&o, path) != 0) {
        fprintf(stderr, "rad lightmap: %s\n", tool_output_error());
        rad_free_buffer(buf, &ctx);
        tool_output_set_abort(set);
        return 1;
    }
    ok = fwrite(buf, 1, size, o.f) == size;
    rad_free_buffer(buf, &ctx);
    if (tool_output_set_add(set, &o, ok) != 0) {
        fprintf(stderr, "rad lightmap: %s\n", tool_output_error());
        return 1;
    }
    return 0;
}

static int lightmap_is_png(const char *path)
{
    size_t n = strlen(path);
    return n >= 4 && (!strcmp(path + n - 4, ".png") || !strcmp(path + n - 4, ".PNG"));
}

/* the command line into la; -1: go on, else the exit code (--help 0; bad usage 2, printed) */
static int lightmap_parse(int argc, char **argv, tool_lights *lights, lightmap_args *la)
{
    int a, k;
    memset(la, 0, sizeof *la);
    tool_classic_options_default(&la->co);
    tool_lightmap_request_default(&la->rq);
    la->rw = la->rh = 256;
    la->aa = 2;
    la->exposure = 0.31830988f; /* 1/pi */
    for (a = 0; a < argc; ++a) {
        const char *o = argv[a];
        if (!strcmp(o, "--help") || !strcmp(o, "-h")) {
            lightmap_usage(stdout);
            return 0;
        }
        if ((k = tool_classic_option("lightmap", argc, argv, &a, &la->co)) == 0 &&
            (k = tool_light_option("lightmap", argc, argv, &a, lights)) == 0)
            k = tool_args_parse("lightmap", lightmap_table, la, &la->given, argc, argv, &a);
        if (k == 2) return 2;
        if (k == 1) continue;
        if (o[0] == '-' && o[1]) {
            fprintf(stderr, "rad lightmap: unknown option '%s' (try rad lightmap --help)\n", o);
            return 2;
        }
        if (la->scene) {
            fprintf(stderr, "rad lightmap: more than one scene ('%s', '%s')\n", la->scene, o);
            return 2;
        }
        la->scene = o;
    }
    if (!la->scene || !la->out) {
        lightmap_usage(stderr);
        return 2;
    }
    if ((la->given & LIGHTMAP_GIVEN_VP) && (!la->px.kind || la->px.kind == TOOL_LIGHTMAP_HIERARCHICAL)) {
        fprintf(stderr, "rad lightmap: --vp-resolution and --face-points are for --proxy aavp|vp\n");
        return 2;
    }
    if ((la->given & LIGHTMAP_GIVEN_HR) && la->px.kind != TOOL_LIGHTMAP_HIERARCHICAL) {
        fprintf(stderr, "rad lightmap: --hr-eps is for --proxy hierarchical\n");
        return 2;
    }
    if (la->px.kind && la->rq.sh) {
        fprintf(stderr, "rad lightmap: --sh needs the classic gather (the virtual patches' gather has no direction): leave out --proxy\n");
        return 2;
    }
    if (la->rq.sh && la->rq.final_gather != TOOL_LIGHTMAP_FINAL_GATHER_AUTO && la->rq.final_gather) {
        fprintf(stderr, "rad lightmap: --final-gather gathers RGB irradiance: leave out --sh\n");
        return 2;
    }
    if (la->rq.sh && lightmap_is_png(la->out)) {
        fprintf(stderr, "rad lightmap: --sh writes PFM or EXR files (PNG cannot hold negative coefficients): use -o NAME.pfm or NAME.exr\n");
        return 2;
    }
    if (la->rq.sh && la->render) {
        fprintf(stderr, "rad lightmap: --render shades from the RGB lightmap: leave out --sh\n");
        return 2;
    }
    if (tool_gltf_is_path(la->out) && la->rq.sh) {
        fprintf(stderr, "rad lightmap: a .glb or .gltf carries the RGB lightmap: leave out --sh\n");
        return 2;
    }
    if (la->layers && la->px.kind == TOOL_LIGHTMAP_HIERARCHICAL) {
        fprintf(stderr, "rad lightmap: --layers saves the engine tier's bake, and --proxy hierarchical bakes without it: "
                        "use the patches or --proxy aavp|vp\n");
        return 2;
    }
    if (tool_check_size("lightmap", la->rq.width, la->rq.height)) return 2;
    if ((!tool_gltf_is_path(la->out) && tool_image_check_format("lightmap", la->out)) ||
        (la->render && tool_image_check_format("lightmap", la->render)))
        return 2;
    return -1;
}

static int lightmap_main(int argc, char **argv, tool_lights *lights)
{
    lightmap_args la;
    const char *scene_path, *out_path, *render_path;
    int rw, rh;
    uint32_t aa;
    tool_world w;
    tool_lightmap_baked bk;
    tool_lightmap_request rq;
    const rad_lightmap *lm = NULL;
    int width, height, sh, code = 1;
    uint32_t i, ch;
    const float *values = NULL;
    float exposure;
    char *gltf_hdr = NULL, *gltf_bin = NULL; /* -o OUT.glb|gltf: the files beside it */
    if ((code = lightmap_parse(argc, argv, lights, &la)) >= 0) return code;
    code = 1;
    memset(&bk, 0, sizeof bk);
    if (tool_gltf_is_path(la.out)) {
        gltf_hdr = tool_gltf_hdr_path(la.out);
        gltf_bin = tool_gltf_bin_path(la.out);
    }
    scene_path = la.scene;
    out_path = la.out;
    render_path = la.render;
    rw = la.rw;
    rh = la.rh;
    aa = la.aa;
    width = la.rq.width;
    height = la.rq.height;
    sh = la.rq.sh;
    exposure = la.exposure;
    {
        /* the files written: OUT (or its four SH layers) and the view; checked before the
           work, and again against every file the scene was read from once it is loaded */
        static const char *const tags[4] = {"L00", "L1m1", "L10", "L11"};
        char *layers[4] = {NULL, NULL, NULL, NULL};
        const char *outs[8];
        int n = 0, bad = 0, k;
        if (sh)
            for (k = 0; k < 4; ++k) outs[n++] = layers[k] = lightmap_tagged(out_path, tags[k]);
        else
            outs[n++] = out_path;
        if (render_path) outs[n++] = render_path;
        if (la.layers) outs[n++] = la.layers;
        if (gltf_hdr) outs[n++] = gltf_hdr;
        if (gltf_bin) outs[n++] = gltf_bin;
        for (k = 0; k < n && !bad; ++k) bad = tool_check_output("lightmap", outs[k], &scene_path, 1);
        if (!bad) bad = tool_check_outputs("lightmap", outs, n, &scene_path, 1);
        tool_set_threads((int)la.threads);
        if (!bad && tool_open_world_lit("lightmap", scene_path, lights, &w)) bad = 2;
        if (!bad && tool_check_outputs("lightmap", outs, n, w.file.input_files, (int)w.file.input_file_count)) {
            tool_close_world(&w);
            bad = 1;
        }
        for (k = 0; k < 4; ++k) free(layers[k]);
        if (bad) {
            free(gltf_hdr);
            free(gltf_bin);
            return 1;
        }
    }
    rq = la.rq;
    rq.auto_size = !(la.given & LIGHTMAP_GIVEN_SIZE);
    rq.direct = !sh;
    /* no --proxy (and RGB: the SH gather is the patches'): the plan keeps the classic patches
       or takes virtual patches where their dense build would not fit; a traced first bounce
       (the proxies' default) lets it ask for 4 voxels a mean free path */
    if (!(la.given & LIGHTMAP_GIVEN_PROXY) && !sh &&
        tool_plan_proxy("lightmap", &w, &la.co, rq.final_gather == TOOL_LIGHTMAP_FINAL_GATHER_AUTO || rq.final_gather ? 4.0f : 0.0f,
                        "the lightmap's indirect light", &la.px.kind, &la.px.resolution))
        goto done;
    rq.proxy = la.px.kind ? &la.px : NULL;
    if (tool_lightmap_bake("lightmap", &w, &la.co, &rq, &bk)) goto done;
    if (la.layers && !bk.baked) {
        fprintf(stderr, "rad lightmap: --layers saves the engine tier's bake, and this one was made without it (nothing "
                        "in the scene emits light)\n");
        goto done;
    }
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
            if (tool_image_write_into(&set, paths[l] ? paths[l] : gltf_hdr ? gltf_hdr : out_path, &img, exposure) != 0) {
                fprintf(stderr, "rad lightmap: %s\n", tool_output_error());
                bad = 1;
            }
            tool_image_free(&img);
        }
        if (!bad && gltf_hdr) {
            /* the scene for engines, its camera the view --render draws */
            tool_gltf_lightmap gl;
            rad_camera cam = bk.w.file.camera;
            if (!bk.w.file.has_camera) tool_choose_camera("lightmap", bk.w.scene, &bk.w.rc, rw, rh, &cam);
            if (!(cam.fov_y_degrees > 0.0f)) cam.fov_y_degrees = 45.0f;
            memset(&gl, 0, sizeof gl);
            gl.scene = bk.w.scene;
            gl.mesh_scene = w.scene;
            gl.material_names = w.file.material_names;
            gl.camera = &cam;
            gl.aspect = (float)rw / (float)rh;
            gl.lightmap = lm;
            gl.values = values;
            gl.hdr_name = strrchr(gltf_hdr, '/') ? strrchr(gltf_hdr, '/') + 1 : gltf_hdr;
            bad = tool_gltf_write("lightmap", out_path, &gl, &set);
        }
        if (!bad && la.layers && lightmap_write_layers(la.layers, bk.baked, &set)) bad = 1;
        if (!bad && render_path && lightmap_render(&bk.w, lm, values, rw, rh, (int)aa, render_path, exposure, &set)) {
            tool_output_set_abort(&set);
            bad = 1;
        }
        if (!bad && tool_output_set_commit(&set) != 0) {
            fprintf(stderr, "rad lightmap: %s\n", tool_output_error());
            bad = 1;
        }
        for (l = 0; l < layers; ++l) {
            if (!bad) fprintf(stderr, "rad lightmap: wrote %s\n", paths[l] ? paths[l] : gltf_hdr ? gltf_hdr : out_path);
            free(paths[l]);
        }
        if (bad) goto done;
        if (gltf_hdr) fprintf(stderr, "rad lightmap: wrote %s%s%s\n", out_path, gltf_bin ? " and " : "", gltf_bin ? gltf_bin : "");
        if (render_path) fprintf(stderr, "rad lightmap: wrote the view %s\n", render_path);
        if (la.layers)
            fprintf(stderr, "rad lightmap: wrote the engine tier's bake %s (light groups: %u; rad info describes it)\n", la.layers,
                    bk.baked->group_count);
    }
    code = 0;
done:
    free(gltf_hdr);
    free(gltf_bin);
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
