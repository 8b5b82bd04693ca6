/* cmd_render.c - `rad render`: an image of a scene by the classic radiosity method (per-pixel
   direct light + indirect light from the patches) or by path tracing.

   Classic (direct light as the source, as examples/cornell.c): a camera ray per sample finds the surface;
   the direct irradiance D is computed at that point with shadow rays (rad_direct_irradiance:
   the emissive triangles analytically times the unoccluded fraction, plus the file's analytic
   lights); H = F (E + L) = F B, the irradiance from the secondary sources, is smoothed to the
   patch vertices and interpolated; the sample's radiance is albedo/pi * (D + H), plus the
   emitted radiance where the ray sees the front of an emitter. Each pixel is the box-filtered
   mean of --aa stratified samples. The solution is computed in memory, or loaded from a bake
   (--bake FILE.radb: its patches, F, E and B, checked against the scene).

   Multibounce and temporal (render_with_method, render_method): the same pixels, with the
   patches' H from methods.c (L = F_mb E, or the temporal frames, H = L / rho) and the halo
   correction from the bake's row sums of F.

   Local (render_local_method; Shcherbakov 2025, ch. 4, in docs/references.md): the classic patches, F and E; a rad_local of capacity
   --local-m M (default: every patch, up to TOOL_LOCAL_M_AUTO_MAX) filled with the M patches
   nearest the camera (rad_local_nearest, one
   rad_local_rebuild), L = T E over P_Vis x P_Lit (rad_local_visible, rad_local_lit), H = L / rho
   and the classic render; patches outside the set or not visible get no indirect light.
   Virtual patches (render_vp_method; Shcherbakov 2025, ch. 5): rad_vp_create (vp: RAD_VP_CLUSTERED, aavp:
   RAD_VP_AXIS_ALIGNED) at --vp-resolution or at the finest resolution within --vp-max-patches,
   E = rad_vp_sources, Jacobi --bounces K (inf: Gauss-Seidel), H = F (E + L) per patch, and the
   classic per-pixel render with H gathered at each sample's hit point (rad_vp_gather per batch).

   Every radiosity method prints one line for scripts (tools/report.sh) on stderr:
   "rad render: timing: method=M patches=N frames=F [bounces=K ]step_ms_median=X step_ms_min=Y",
   the method's own per-frame work: the classic solve (K Jacobi bounces), one F_mb E product
   (median of 9), one temporal step (median over the frames), one local apply L = T E (median
   of 9; plus rebuild_ms), or the virtual patches' solve + H (plus build_ms, sources_ms,
   gather_ms, render_ms, resolution, vp_mib and peak_rss_mib). */
#include "tool.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#if defined(__unix__) || defined(__APPLE__)
#include <sys/resource.h> /* getrusage: peak memory in the vp timing line */
#include <sys/stat.h> /* mkdir for --sequence */
#endif

#define PI_F 3.14159265358979323846f

static void *xmalloc(size_t size)
{
    void *p = malloc(size ? size : 1);
    if (!p) {
        fprintf(stderr, "rad render: out of memory (%lu bytes)\n", (unsigned long)size);
        exit(1);
    }
    return p;
}

static void render_usage(FILE *f)
{
    fprintf(f,
            "usage: rad render SCENE -o OUT.png|OUT.pfm|OUT.exr [--method classic|multibounce|temporal|local|stochastic|vp|aavp|hierarchical|lightmap|pathtrace] [options]\n"
            "  -o FILE            output image: .pfm or .exr (linear radiance; .exr needs libtinyexr-dev at build) or .png\n"
            "                     (sRGB, exposure applied)\n"
            "  --method M         default: classic, or aavp at the scene's resolution when the dense matrix would\n"
            "                     not fit 1 GiB or 10 CPU-minutes (rad_baker_plan, said on stderr before the work);\n"
            "                     classic (radiosity + per-pixel direct light), multibounce (the\n"
            "                     indirect light L = F_mb E), temporal (alias-table frames), pathtrace, local\n"
            "                     (local matrix of the patches nearest the camera), vp or aavp (virtual patches),\n"
            "                     hierarchical (quadtrees and links, Hanrahan et al. 1991), lightmap (classic,\n"
            "                     or virtual patches with --proxy aavp|vp, baked into a lightmap, the indirect\n"
            "                     light looked up per pixel)\n"
            "  --bake FILE.radb   classic, multibounce, temporal, stochastic, hierarchical: use a bake of\n"
            "                     that method made by\n"
            "                     'rad bake' from this scene instead of computing it here\n"
            "  --camera PX,PY,PZ:TX,TY,TZ:UX,UY,UZ   camera (default: the scene's camera)\n"
            "  --fov DEG          vertical field of view in degrees (default: the scene's)\n"
            "  --size WxH         image size (default 512x512; at most 2 GiB of image: 12 bytes a pixel)\n"
            "  --aa N             radiosity methods: stratified samples per pixel, rounded down to a square (default 16, 1 to 65536)\n"
            "  --spp N            pathtrace: samples per pixel (default 64)\n"
            "  --seed S           pathtrace: random seed (default 0)\n"
            "  --exposure X       scale before 8-bit sRGB encoding (PNG only; default 1)\n"
            "  --pixel-light-samples N   radiosity methods: shadow rays per pixel sample and light (default 16, at most 65536)\n"
            "  --final-gather N   classic, vp, aavp: trace the first bounce from each pixel sample with N\n"
            "                     rays (direct light at the hits, the solution's irradiance there): the\n"
            "                     indirect light of points a patch average misrepresents; default 0 (off)\n"
            "  --shading MODEL    radiosity methods: lighting model for the analytic lights' direct term: none\n"
            "                     (default: Lambert through the irradiance), lambert, half-lambert, banded,\n"
            "                     phong, blinn-phong, minnaert, oren-nayar, microfacet (tools/shading.c says\n"
            "                     how it combines with the diffuse radiosity solution)\n"
            "patch and classic solution options (ignored with --bake, which keeps its own):\n"
            "%s"
            "%s"
            "%s"
            "  --threads N        worker threads (default: all cores; at most 1024)\n",
            tool_classic_help(), tool_method_help(1), tool_light_help());
}

/* Per-vertex H without dark halos where a patch is partly covered (rad_patches_vertex_irradiance).
   S: the row sums of F (how much of its hemisphere each patch sees). */
static int vertex_H_rowsums(const rad_patches *P, const float *S, const float *H, float *Hv)
{
    rad_context ctx;
    rad_result r;
    tool_context(&ctx, NULL);
    r = rad_patches_vertex_irradiance(P, H, S, Hv, &ctx);
    return r == RAD_SUCCESS ? 0 : tool_fail("render", "per-vertex H", r);
}

/* the same with the row sums computed from F */
static int vertex_H(const rad_patches *P, const rad_matrix *F, const float *H, float *Hv)
{
    uint32_t n = P->count, i;
    float *ones = (float *)xmalloc(sizeof(float) * 3 * n), *rs = (float *)xmalloc(sizeof(float) * 3 * n);
    float *S = (float *)xmalloc(sizeof(float) * n);
    rad_context ctx;
    rad_result r;
    int rc;
    tool_context(&ctx, NULL);
    for (i = 0; i < 3 * n; ++i) ones[i] = 1.0f;
    r = rad_matrix_multiply(F, ones, rs, &ctx);
    for (i = 0; i < n; ++i) S[i] = rs[3 * i];
    rc = r == RAD_SUCCESS ? vertex_H_rowsums(P, S, H, Hv) : tool_fail("render", "per-vertex H", r);
    free(ones);
    free(rs);
    free(S);
    return rc;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

typedef struct isect_job {
    const rad_raycaster *rc;
    const rad_ray *rays;
    rad_hit *hits;
    uint32_t count;
    int failed;
} isect_job;

/* --shading: a rad_shading_model, or -1 for none (tools/shading.c) */
static int render_shading = -1;
/* --method vp|aavp: render_classic gathers H at each sample from these (P and Hv unused) */
static const rad_virtual_patches *render_vp = NULL;
static const float *render_vp_H = NULL;
static double render_vp_gather_seconds = 0.0;
/* --method hierarchical: render_classic looks H up at each sample's hit (smooth, halo-fixed) */
static const rad_hierarchical *render_hr = NULL;
static rad_result hr_lookup(const rad_hit *hits, const uint32_t *valid, uint32_t count, float *out);
/* --method lightmap: render_classic reads H at each sample's lightmap uv from this RGB
   irradiance lightmap (bilinear; P and Hv unused) */
static const rad_lightmap *render_lm = NULL;
static const float *render_lm_values = NULL;
static uint32_t render_lm_size = 256, render_lm_samples = 4, render_lm_vis = 2;
static int render_lm_size_given = 0; /* else an unwrap too fine for 256 gets a larger atlas */
/* --final-gather N: rays per pixel sample for one traced bounce (0: off; rad_final_gather) */
static uint32_t render_final_gather = 0;

typedef struct fg_lookup {
    const rad_patches *P; /* classic: per-vertex H of the patches */
    const float *Hv;
} fg_lookup;

/* H at the final gather's hits: the virtual patches' gather, or the patches' per-vertex H */
static rad_result fg_lookup_fn(void *user, const rad_hit *hits, const float *points, const float *normals, uint32_t count,
                               float *out)
{
    const fg_lookup *l = (const fg_lookup *)user;
    uint32_t k;
    int i;
    if (render_vp) {
        rad_context quiet;
        tool_context(&quiet, NULL);
        return rad_vp_gather(render_vp, render_vp_H, points, normals, count, out, &quiet);
    }
    if (render_hr) return hr_lookup(hits, NULL, count, out);
    for (k = 0; k < count; ++k) {
        float wts[3];
        uint32_t p = rad_patches_locate(l->P, hits[k].triangle, hits[k].b1, hits[k].b2, wts);
        const uint32_t *vi;
        if (p == RAD_NONE) { out[3 * k] = out[3 * k + 1] = out[3 * k + 2] = 0.0f; continue; }
        vi = l->P->patches[p].vertices;
        for (i = 0; i < 3; ++i)
            out[3 * k + i] = wts[0] * l->Hv[3 * (size_t)vi[0] + i] + wts[1] * l->Hv[3 * (size_t)vi[1] + i] +
                             wts[2] * l->Hv[3 * (size_t)vi[2] + i];
    }
    return RAD_SUCCESS;
}

/* H of the hierarchical solution at hits[valid[k]] (valid NULL: hits[k]), k < count */
static rad_result hr_lookup(const rad_hit *hits, const uint32_t *valid, uint32_t count, float *out)
{
    uint32_t *tris = (uint32_t *)xmalloc(sizeof(uint32_t) * (count ? count : 1u)), k;
    float *bary = (float *)xmalloc(sizeof(float) * 2 * (count ? count : 1u));
    rad_result r;
    for (k = 0; k < count; ++k) {
        const rad_hit *h = &hits[valid ? valid[k] : k];
        tris[k] = h->triangle;
        bary[2 * k] = h->b1;
        bary[2 * k + 1] = h->b2;
    }
    r = rad_hierarchical_lookup(render_hr, RAD_HIERARCHICAL_GATHERED, 1, tris, bary, count, out);
    free(tris);
    free(bary);
    return r;
}

static int render_classic(const tool_world *w, const rad_patches *P, const float *Hv, const rad_camera *cam,
                          int width, int height, uint32_t aa, uint32_t light_samples, tool_image *img)
{
    const rad_scene *scene = w->scene;
    uint32_t strata, spp;
    size_t batch_cap, total = (size_t)width * height, done_px = 0;
    rad_ray *rays;
    rad_hit *hits;
    float *points, *normals, *irr, *shade_v = NULL, *shade_a = NULL, *shaded = NULL, *gathered = NULL;
    uint32_t *valid;
    rad_direct_options dopt;
    rad_context quiet;
    int y0, rows_per_batch, result = 0;
    float sky[3] = {0.0f, 0.0f, 0.0f};
    uint32_t k, i;
    for (strata = 1; (strata + 1) * (strata + 1) <= aa; ++strata) {
    }
    spp = strata * strata;
    rows_per_batch = (int)(65536 / ((size_t)width * spp));
    if (rows_per_batch < 1) rows_per_batch = 1;
    batch_cap = (size_t)rows_per_batch * width * spp;
    rays = (rad_ray *)xmalloc(sizeof(rad_ray) * batch_cap);
    hits = (rad_hit *)xmalloc(sizeof(rad_hit) * batch_cap);
    points = (float *)xmalloc(sizeof(float) * 3 * batch_cap);
    normals = (float *)xmalloc(sizeof(float) * 3 * batch_cap);
    irr = (float *)xmalloc(sizeof(float) * 3 * batch_cap);
    valid = (uint32_t *)xmalloc(sizeof(uint32_t) * batch_cap);
    if (render_vp || render_hr || render_lm || render_final_gather) gathered = (float *)xmalloc(sizeof(float) * 3 * batch_cap);
    if (render_shading >= 0) {
        shade_v = (float *)xmalloc(sizeof(float) * 3 * batch_cap);
        shade_a = (float *)xmalloc(sizeof(float) * 3 * batch_cap);
        shaded = (float *)xmalloc(sizeof(float) * 3 * batch_cap);
    }
    rad_direct_options_default(&dopt);
    dopt.exclude_emitters = 0;
    dopt.light_samples = light_samples;
    tool_context(&quiet, NULL);
    /* a camera ray that leaves the scene sees the sky's radiance E_0 / pi, as in rad trace */
    for (k = 0; k < w->file.light_count; ++k)
        if (w->file.lights[k].type == RAD_LIGHT_SKY)
            for (i = 0; i < 3; ++i) sky[i] += w->file.lights[k].color[i] / PI_F;

    for (y0 = 0; y0 < height && result == 0; y0 += rows_per_batch) {
        int y1 = y0 + rows_per_batch < height ? y0 + rows_per_batch : height, chunk, nchunks;
        uint32_t count = 0, nvalid = 0;
        int x, y;
        uint32_t s;
        rad_result r;
        for (y = y0; y < y1; ++y)
            for (x = 0; x < width; ++x)
                for (s = 0; s < spp; ++s) {
                    float px = (float)x + ((float)(s % strata) + 0.5f) / (float)strata;
                    float py = (float)y + ((float)(s / strata) + 0.5f) / (float)strata;
                    rad_camera_ray(cam, (uint32_t)width, (uint32_t)height, px, py, &rays[count++]);
                }
        /* primary rays in parallel chunks (the raycaster is thread-safe) */
        nchunks = (int)((count + 4095) / 4096);
        {
            int failed = 0;
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 1) reduction(| : failed)
#endif
            for (chunk = 0; chunk < nchunks; ++chunk) {
                uint32_t b = (uint32_t)chunk * 4096u, e = b + 4096u < count ? b + 4096u : count;
                if (w->rc.intersect(w->rc.user, rays + b, e - b, hits + b) != RAD_SUCCESS) failed |= 1;
            }
            if (failed) {
                result = tool_fail("render", "ray intersection", RAD_ERROR_RAYCAST_FAILED);
                break;
            }
        }
        for (k = 0; k < count; ++k) {
            uint32_t t = hits[k].triangle;
            const float *v, *nt;
            if (t == RAD_NONE || t >= scene->triangle_count) {
                size_t pixel = (size_t)y0 * width + k / spp;
                uint32_t l;
                for (i = 0; i < 3; ++i) img->rgb[3 * pixel + i] += sky[i];
                /* and an environment map its radiance in the ray's direction */
                for (l = 0; l < w->file.light_count; ++l)
                    if (w->file.lights[l].type == RAD_LIGHT_ENVIRONMENT) {
                        float rgb[3];
                        rad_environment_radiance(w->file.lights[l].environment, rays[k].dir, rgb);
                        for (i = 0; i < 3; ++i) img->rgb[3 * pixel + i] += w->file.lights[l].color[i] * rgb[i];
                    }
                hits[k].triangle = RAD_NONE;
                continue;
            }
            nt = scene->normals + 3 * (size_t)t;
            if (nt[0] * rays[k].dir[0] + nt[1] * rays[k].dir[1] + nt[2] * rays[k].dir[2] >= 0.0f) {
                hits[k].triangle = RAD_NONE; /* back face: patches are one-sided, black */
                continue;
            }
            v = scene->positions + 9 * (size_t)t;
            for (i = 0; i < 3; ++i) {
                points[3 * nvalid + i] = v[i] + hits[k].b1 * (v[3 + i] - v[i]) + hits[k].b2 * (v[6 + i] - v[i]);
                normals[3 * nvalid + i] = nt[i];
            }
            valid[nvalid++] = k;
        }
        if (nvalid > 0) {
            r = rad_direct_irradiance(scene, &w->rc, w->file.lights, w->file.light_count, &dopt, points, normals, nvalid,
                                      irr, &quiet);
            if (r != RAD_SUCCESS) {
                result = tool_fail("render", "rad_direct_irradiance", r);
                break;
            }
        }
        if (render_final_gather && nvalid > 0) {
            rad_final_gather_options fo;
            fg_lookup lk;
            double tg = tool_seconds();
            rad_final_gather_options_default(&fo);
            fo.rays = render_final_gather;
            fo.seed = (uint32_t)y0 * 0x9E3779B9u;
            lk.P = P;
            lk.Hv = Hv;
            r = rad_final_gather(scene, &w->rc, w->file.lights, w->file.light_count, &fo, fg_lookup_fn, &lk, points, normals,
                                 nvalid, gathered, &quiet);
            render_vp_gather_seconds += tool_seconds() - tg;
            if (r != RAD_SUCCESS) {
                result = tool_fail("render", "rad_final_gather", r);
                break;
            }
        } else if (render_lm && nvalid > 0) {
            double tg = tool_seconds();
            for (k = 0; k < nvalid; ++k) {
                const rad_hit *h = &hits[valid[k]];
                const float *t = scene->lightmap_uvs + 6 * (size_t)h->triangle;
                float u = t[0] + h->b1 * (t[2] - t[0]) + h->b2 * (t[4] - t[0]);
                float v = t[1] + h->b1 * (t[3] - t[1]) + h->b2 * (t[5] - t[1]);
                rad_lightmap_sample(render_lm, 3, render_lm_values, u, v, gathered + 3 * k);
            }
            render_vp_gather_seconds += tool_seconds() - tg;
        } else if (gathered && nvalid > 0) {
            double tg = tool_seconds();
            r = render_hr ? hr_lookup(hits, valid, nvalid, gathered)
                          : rad_vp_gather(render_vp, render_vp_H, points, normals, nvalid, gathered, &quiet);
            render_vp_gather_seconds += tool_seconds() - tg;
            if (r != RAD_SUCCESS) {
                result = tool_fail("render", "rad_vp_gather", r);
                break;
            }
        }
        if (shaded && nvalid > 0) {
            for (k = 0; k < nvalid; ++k) {
                const rad_ray *ry = &rays[valid[k]];
                float len = sqrtf(ry->dir[0] * ry->dir[0] + ry->dir[1] * ry->dir[1] + ry->dir[2] * ry->dir[2]);
                for (i = 0; i < 3; ++i) shade_v[3 * k + i] = -ry->dir[i] / len;
                rad_scene_albedo(scene, hits[valid[k]].triangle, hits[valid[k]].b1, hits[valid[k]].b2, shade_a + 3 * k);
            }
            if (tool_shade_direct(w, render_shading, light_samples, points, normals, shade_v, shade_a, nvalid, shaded)) {
                result = 1;
                break;
            }
        }
        for (k = 0; k < nvalid; ++k) {
            uint32_t ray = valid[k];
            size_t pixel = (size_t)y0 * width + ray / spp;
            const rad_hit *h = &hits[ray];
            float albedo[3], wts[3], emitted[3];
            uint32_t p = gathered ? 0u : rad_patches_locate(P, h->triangle, h->b1, h->b2, wts);
            const uint32_t *vi;
            if (p == RAD_NONE) continue;
            vi = gathered ? NULL : P->patches[p].vertices;
            rad_scene_albedo(scene, h->triangle, h->b1, h->b2, albedo);
            rad_scene_emission(scene, h->triangle, h->b1, h->b2, emitted);
            for (i = 0; i < 3; ++i) {
                float hi = gathered ? gathered[3 * k + i]
                                    : wts[0] * Hv[3 * (size_t)vi[0] + i] + wts[1] * Hv[3 * (size_t)vi[1] + i] +
                                          wts[2] * Hv[3 * (size_t)vi[2] + i];
                img->rgb[3 * pixel + i] += (shaded ? shaded[3 * k + i] + albedo[i] / PI_F * hi
                                                   : albedo[i] / PI_F * (irr[3 * k + i] + hi)) + emitted[i];
            }
        }
        done_px += (size_t)(y1 - y0) * width;
        tool_progress((void *)(size_t)"render", (float)((double)done_px / (double)total));
    }
    tool_progress_end();
    {
        size_t q;
        float inv = 1.0f / (float)spp;
        for (q = 0; q < 3 * total; ++q) img->rgb[q] *= inv;
    }
    free(rays);
    free(hits);
    free(points);
    free(normals);
    free(irr);
    free(valid);
    free(shade_v);
    free(shade_a);
    free(shaded);
    free(gathered);
    return result;
}

/* the bake's options section, or NULL */
static const tool_bake_info *bake_info(const rad_bake *bake)
{
    const rad_section *s = rad_container_find(bake->container, TOOL_SECTION_OPTIONS, "rad.options");
    const tool_bake_info *info;
    if (!s || s->elem_size != sizeof(tool_bake_info) || s->count != 1) return NULL;
    info = (const tool_bake_info *)s->data;
    return info->magic == 0x52414442u ? info : NULL;
}

/* 0 when a loaded bake was made from this scene (rad_bake_matches_scene: its triangle count,
   geometry and materials, and its options section is the one it was baked with; then the
   patch count its options give on this scene); else 1 with a message */
static int bake_fits_scene(const char *cmd, const char *bake_path, const rad_bake *bake, const tool_world *w)
{
    const tool_bake_info *info = bake_info(bake);
    rad_context ctx;
    rad_result r;
    int rc = 0;
    tool_context(&ctx, NULL);
    if ((r = rad_bake_matches_scene(bake, w->scene, info ? tool_options_hash(info, w) : 0u, &ctx)) != RAD_SUCCESS) {
        /* the same options without this command line's lights: then only the lights differ */
        tool_world bare = *w;
        bare.file_light_count = w->file.light_count;
        if (info && rad_bake_matches_scene(bake, w->scene, tool_options_hash(info, &bare), NULL) == RAD_SUCCESS)
            fprintf(stderr, "rad %s: bake '%s' was made with other lights than this command line's --sun, --sky, "
                            "--point and --spot: give the bake's light options, or render without --bake\n",
                    cmd, bake_path);
        else
            fprintf(stderr, "rad %s: bake '%s' does not fit this scene (%s)%s\n", cmd, bake_path, rad_result_string(r),
                    info ? "; the options hash covers --sun, --sky, --point and --spot: give the bake's own" : "");
        rc = 1;
    } else if (info) {
        /* the same patch options on this scene must give the same patches */
        rad_patch_options po;
        rad_patches *check = NULL;
        rad_patch_options_default(&po);
        po.target_count = info->patches;
        po.max_edge = info->max_edge;
        if ((r = rad_patches_create(w->scene, &po, &ctx, &check)) != RAD_SUCCESS) {
            rc = tool_fail(cmd, "rad_patches_create", r);
        } else if (check->count != bake->patches.count) {
            fprintf(stderr, "rad %s: bake '%s' has %u patches; this scene with its options (--patches %u) gives %u: "
                            "not the scene it was baked from\n",
                    cmd, bake_path, bake->patches.count, info->patches, check->count);
            rc = 1;
        }
        rad_patches_destroy(check);
    } else {
        fprintf(stderr, "rad %s: warning: bake '%s' has no rad.options section; its patches are used as they are\n", cmd,
                bake_path);
    }
    return rc;
}

/* --method multibounce|temporal: the patches' indirect light from the bake's F_mb (one
   product) or alias tables (--frames steps), then the classic pixel pipeline (per-pixel direct
   light + interpolated H). --sequence writes every --every-th frame (and the last) as a PNG. */
static int render_method(const char *cmd, const tool_world *w, const rad_bake *bake, const char *bake_name,
                         const tool_method_options *mo, const rad_camera *cam, int width, int height, uint32_t aa,
                         uint32_t light_samples, float exposure, tool_image *img)
{
    tool_indirect *m = NULL;
    const rad_patches *P = &bake->patches;
    uint32_t frames = mo->method == TOOL_TEMPORAL ? mo->frames : 1u, f;
    /* multibounce: the product is repeated (same result each time) so its time is a median */
    uint32_t reps = mo->method == TOOL_TEMPORAL ? frames : 9u;
    double t = 0.0, sum = 0.0, tmin = 1e300, tmax = 0.0, *times;
    float *H, *Hv;
    int rc = 0;
    if (tool_indirect_open(cmd, bake_name, bake, mo, &m)) return 1;
    times = (double *)xmalloc(sizeof(double) * reps);
    H = (float *)xmalloc(sizeof(float) * 3 * (size_t)P->count);
    Hv = (float *)xmalloc(sizeof(float) * 3 * (size_t)P->vertex_count);
#if defined(__unix__) || defined(__APPLE__)
    if (mo->sequence) mkdir(mo->sequence, 0777); /* may exist; a failure shows when writing */
#endif
    for (f = 1; f <= frames && rc == 0; ++f) {
        rc = tool_indirect_step(m, H, &t);
        times[f - 1] = t;
        sum += t;
        if (t < tmin) tmin = t;
        if (t > tmax) tmax = t;
        if (rc == 0 && mo->sequence && f % mo->every == 0 && f != frames) { /* the last one: below */
            char path[4096];
            tool_image frame;
            memset(&frame, 0, sizeof frame);
            snprintf(path, sizeof path, "%s/frame_%05u.png", mo->sequence, f);
            if (tool_image_alloc(&frame, width, height) != 0) {
                fprintf(stderr, "rad %s: out of memory for a %dx%d image\n", cmd, width, height);
                rc = 1;
            }
            if (rc == 0) rc = vertex_H_rowsums(P, tool_indirect_rowsums(m), H, Hv);
            if (rc == 0) rc = render_classic(w, P, Hv, cam, width, height, aa, light_samples, &frame);
            if (rc == 0 && tool_image_write_png(path, &frame, exposure) != 0) {
                fprintf(stderr, "rad %s: %s\n", cmd, tool_output_error());
                rc = 1;
            }
            tool_image_free(&frame);
        }
    }
    for (f = frames + 1; f <= reps && rc == 0; ++f) rc = tool_indirect_step(m, H, &times[f - 1]);
    if (rc == 0) {
        qsort(times, reps, sizeof(double), cmp_double);
        /* one line for scripts (tools/report.sh): the method's per-frame work alone */
        fprintf(stderr, "rad %s: timing: method=%s patches=%u frames=%u step_ms_median=%.6f step_ms_min=%.6f\n", cmd,
                tool_method_name(mo->method), P->count, reps, 1e3 * times[reps / 2], 1e3 * times[0]);
        if (mo->method == TOOL_TEMPORAL)
            fprintf(stderr, "rad %s: %u frames, temporal step %.3f ms per frame (min %.3f, max %.3f), %.3f s in all\n",
                    cmd, frames, 1e3 * sum / frames, 1e3 * tmin, 1e3 * tmax, sum);
        else if (mo->method == TOOL_MULTIBOUNCE)
            fprintf(stderr, "rad %s: L = F_mb E in %.3f ms\n", cmd, 1e3 * sum);
        rc = vertex_H_rowsums(P, tool_indirect_rowsums(m), H, Hv);
    }
    if (rc == 0) rc = render_classic(w, P, Hv, cam, width, height, aa, light_samples, img);
    if (rc == 0 && mo->sequence) {
        char path[4096];
        snprintf(path, sizeof path, "%s/frame_%05u.png", mo->sequence, frames);
        if (tool_image_write_png(path, img, exposure) != 0) {
            fprintf(stderr, "rad %s: %s\n", cmd, tool_output_error());
            rc = 1;
        }
    }
    free(H);
    free(Hv);
    free(times);
    tool_indirect_close(m);
    return rc;
}

/* Why rad_load_file refused a bake: an intact virtual-patch bake (which holds no classic
   patches) is another method's data, not a damaged file. */
static void bake_load_failed(const char *cmd, const char *path, rad_result r)
{
    void *data = NULL;
    size_t size = 0;
    rad_container *ct = NULL;
    rad_context ctx;
    memset(&ctx, 0, sizeof ctx); /* no log: the load has said what it found */
    if (r == RAD_ERROR_CORRUPT || r == RAD_ERROR_INVALID_ARGUMENT || r == RAD_ERROR_VERSION) {
        if (tool_read_file(NULL, NULL, path, &data, &size) == 0 && rad_container_create(data, size, &ctx, &ct) == RAD_SUCCESS &&
            rad_container_find(ct, RAD_SECTION_VP_INFO, NULL) && !rad_container_find(ct, RAD_SECTION_PATCHES, NULL)) {
            fprintf(stderr, "rad %s: bake '%s' holds virtual patches (rad bake --method aavp|vp), not classic patches: "
                            "render it with --method aavp or vp\n", cmd, path);
            rad_container_destroy(ct);
            free(data);
            return;
        }
        rad_container_destroy(ct);
        free(data);
    }
    fprintf(stderr, "rad %s: cannot load bake '%s': %s\n", cmd, path, rad_result_string(r));
}

/* the bake (--bake, checked against the scene) or one made here, then render_method */
static int render_with_method(const char *cmd, const tool_world *w, const char *bake_path,
                              const tool_classic_options *o, const tool_method_options *mo,
                              const rad_camera *cam, int width, int height, uint32_t aa, uint32_t light_samples,
                              float exposure, tool_image *img)
{
    rad_bake *bake = NULL;
    void *buf = NULL;
    size_t size = 0;
    rad_context ctx;
    rad_result r;
    int rc;
    tool_context(&ctx, NULL);
    if (bake_path) {
        if (mo->given & (TOOL_OPT_MB_BUILD | TOOL_OPT_BOUNCES | TOOL_OPT_MODE | TOOL_OPT_SR |
                         (mo->method == TOOL_STOCHASTIC ? TOOL_OPT_SEED : 0u)))
            fprintf(stderr, "rad %s: warning: the bake '%s' fixes --bounces, --format, --outliers, --reorder, --tile, "
                            "--mode, --sr-* (and the stochastic solve's --seed); those given here are ignored\n",
                    cmd, bake_path);
        if ((r = rad_load_file(bake_path, &ctx, &bake)) != RAD_SUCCESS) {
            bake_load_failed(cmd, bake_path, r);
            return 1;
        }
        if (bake_fits_scene(cmd, bake_path, bake, w)) {
            rad_bake_destroy(bake);
            return 1;
        }
    } else {
        if (tool_method_bake(cmd, w, o, mo, &buf, &size)) return 1;
        if ((r = rad_load_memory(buf, size, &ctx, &bake)) != RAD_SUCCESS) {
            free(buf);
            return tool_fail(cmd, "rad_load_memory", r);
        }
        bake_path = "(made here)";
    }
    bake->patches.scene = w->scene;
    rc = render_method(cmd, w, bake, bake_path, mo, cam, width, height, aa, light_samples, exposure, img);
    rad_bake_destroy(bake);
    free(buf);
    return rc;
}

/* peak resident set of the process in MiB (0 where unknown) */
static double peak_rss_mib(void)
{
#if defined(__unix__) || defined(__APPLE__)
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) == 0)
#if defined(__APPLE__)
        return (double)ru.ru_maxrss / 1048576.0;
#else
        return (double)ru.ru_maxrss / 1024.0;
#endif
#endif
    return 0.0;
}

/* rad_vp_create at 'resolution' (progress labelled), or NULL with the error printed */
static rad_virtual_patches *vp_build(const char *cmd, const tool_world *w, const tool_method_options *mo,
                                     uint32_t resolution)
{
    rad_vp_options vo;
    rad_virtual_patches *vp = NULL;
    rad_context ctx;
    rad_result r;
    rad_vp_options_default(&vo);
    vo.resolution = resolution;
    vo.face_points = mo->face_points;
    if (mo->method == TOOL_VP || mo->proxy == TOOL_PROXY_VP) vo.kind = RAD_VP_CLUSTERED;
    /* the run-time methods over a proxy take its rows as CSR: O(non-zeros) once built */
    if (mo->proxy) vo.storage = RAD_STORAGE_SPARSE;
    tool_context(&ctx, "virtual patches");
    r = rad_vp_create(w->scene, &w->rc, &vo, &ctx, &vp);
    tool_progress_end();
    if (r != RAD_SUCCESS) {
        tool_fail(cmd, "rad_vp_create", r);
        return NULL;
    }
    fprintf(stderr, "rad %s: %s virtual patches at resolution %u: %u patches, %u voxels, %u samples\n", cmd,
            vo.kind == RAD_VP_CLUSTERED ? "vp" : "aavp", resolution, vp->count, vp->voxel_count, vp->sample_count);
    if (vp->matrix.storage == RAD_STORAGE_SPARSE)
        fprintf(stderr, "rad %s: sparse rows: %llu non-zeros (%.1f%% of N^2), %.1f MiB\n", cmd,
                (unsigned long long)vp->matrix.row_offsets[vp->count],
                100.0 * (double)vp->matrix.row_offsets[vp->count] / ((double)vp->count * (double)vp->count),
                (double)rad_vp_memory(vp) / 1048576.0);
    return vp;
}

/* the patch count rad_vp_create would give at 'resolution' (rad_vp_count); 0 or 1 (printed) */
static int vp_count(const char *cmd, const tool_world *w, rad_vp_kind kind, uint32_t face_points, uint32_t resolution,
                    uint32_t *count)
{
    rad_vp_options vo;
    rad_vp_counts cnt;
    rad_context ctx;
    rad_result r;
    rad_vp_options_default(&vo);
    vo.resolution = resolution;
    vo.face_points = face_points;
    vo.kind = kind;
    tool_context(&ctx, NULL);
    if ((r = rad_vp_count(w->scene, &w->rc, &vo, &ctx, &cnt)) != RAD_SUCCESS) return tool_fail(cmd, "rad_vp_count", r);
    *count = cnt.patches;
    return 0;
}

int tool_vp_resolution_within(const char *cmd, const tool_world *w, rad_vp_kind kind, uint32_t face_points,
                              uint32_t max_patches, uint32_t start, uint32_t *out)
{
    /* The finest resolution within the budget, chosen by counting (rad_vp_count: the build up
       to the patches, without the form factors that take nearly all of its time). The count
       grows about as R^2 (surface voxels): predict from the nearest count, count, narrow the
       bracket [lo, hi) to adjacent resolutions. */
    uint32_t lo = 0, hi = 4097, counts = 0, c = 0, res = start ? start : 16;
    double tc = tool_seconds();
    while (counts < 24 && hi - lo > 1) {
        uint32_t next;
        if (vp_count(cmd, w, kind, face_points, res, &c)) return 1;
        ++counts;
        if (c <= max_patches) lo = res;
        else hi = res;
        next = (uint32_t)((double)res * sqrt((double)max_patches / (double)(c ? c : 1)));
        if (next <= lo) next = lo + 1;
        if (next >= hi) next = hi - 1;
        res = next;
    }
    if (lo == 0) {
        fprintf(stderr, "rad %s: --vp-max-patches %u: even resolution 1 gives more patches\n", cmd, max_patches);
        return 1;
    }
    fprintf(stderr, "rad %s: --vp-max-patches %u: resolution %u from %u counts (%.2f s), one build\n", cmd, max_patches, lo,
            counts, tool_seconds() - tc);
    *out = lo;
    return 0;
}

/* --proxy aavp|vp: the indirect radiosity L of the virtual patches by --method multibounce
   (F_mb of K bounces, float: L_K as Jacobi), temporal (alias tables over the CSR rows, or over
   F_mb's channels in --mode multibounce; --frames steps) or local (T of the M patches nearest
   the camera, by voxel centre; L = T E over the set, 0 outside). *step_seconds: the median
   temporal step, else the whole computation. */
typedef struct proxy_near { double d2; uint32_t patch; } proxy_near;
static int cmp_near(const void *a, const void *b)
{
    const proxy_near *x = (const proxy_near *)a, *y = (const proxy_near *)b;
    return x->d2 < y->d2 ? -1 : x->d2 > y->d2 ? 1 : (x->patch > y->patch) - (x->patch < y->patch);
}

static int proxy_indirect(const char *cmd, const rad_virtual_patches *vp, const float *E,
                          const tool_method_options *mo, const rad_camera *cam, float *L, double *step_seconds)
{
    rad_multibounce *mb = NULL;
    rad_alias_tables *tables[3] = {NULL, NULL, NULL};
    rad_temporal *tp = NULL;
    rad_local *local = NULL;
    uint32_t *order = NULL, n = vp->count, i;
    double *steps = NULL, t0 = tool_seconds();
    const char *what = NULL;
    rad_context ctx;
    rad_result r = RAD_SUCCESS;
    tool_context(&ctx, NULL);
    memset(L, 0, sizeof(float) * 3 * (size_t)n);
    if (mo->method == TOOL_MULTIBOUNCE || (mo->method == TOOL_TEMPORAL && mo->mode == RAD_TEMPORAL_MULTIBOUNCE)) {
        rad_multibounce_options mbo;
        rad_multibounce_options_default(&mbo);
        mbo.bounces = mo->bounces;
        tool_context(&ctx, "multi-bounce matrix");
        r = rad_multibounce_create(&vp->matrix, vp->albedo, &mbo, &ctx, &mb);
        tool_progress_end();
        tool_context(&ctx, NULL);
        if (r != RAD_SUCCESS) { what = "rad_multibounce_create"; goto done; }
        if (mo->method == TOOL_MULTIBOUNCE) {
            if ((r = rad_multibounce_apply(mb, E, L, RAD_OUTPUT_INDIRECT, &ctx)) != RAD_SUCCESS) what = "rad_multibounce_apply";
            *step_seconds = tool_seconds() - t0;
            goto done;
        }
    }
    if (mo->method == TOOL_TEMPORAL) {
        const rad_alias_tables *tp3[3];
        rad_temporal_options to;
        uint32_t count = mb ? 3u : 1u, f;
        for (i = 0; i < count && r == RAD_SUCCESS; ++i) {
            r = mb ? rad_alias_tables_create_dense(mb->planes + (size_t)i * n * n, n, RAD_ALIAS_AUTO, &ctx, &tables[i])
                   : rad_alias_tables_create(&vp->matrix, RAD_ALIAS_AUTO, &ctx, &tables[i]);
            tp3[i] = tables[i];
        }
        if (r != RAD_SUCCESS) { what = "alias tables"; goto done; }
        rad_temporal_options_default(&to);
        to.mode = mo->mode;
        to.samples = mo->k;
        to.adaptive = mo->adaptive && !(mo->given & TOOL_OPT_W);
        to.weight = mo->w > 0.0f ? mo->w : -1.0f; /* --w 0: no history */
        to.seed = mo->seed;
        if ((r = rad_temporal_create(tp3, count, vp->albedo, &to, &ctx, &tp)) != RAD_SUCCESS) { what = "rad_temporal_create"; goto done; }
        steps = (double *)xmalloc(sizeof(double) * mo->frames);
        for (f = 0; f < mo->frames; ++f) {
            double ts = tool_seconds();
            if ((r = rad_temporal_step(tp, E, NULL, NULL)) != RAD_SUCCESS) { what = "rad_temporal_step"; goto done; }
            steps[f] = tool_seconds() - ts;
        }
        memcpy(L, rad_temporal_indirect(tp), sizeof(float) * 3 * (size_t)n);
        qsort(steps, mo->frames, sizeof(double), cmp_double);
        *step_seconds = steps[mo->frames / 2];
        fprintf(stderr, "rad %s: temporal over %u virtual patches: %u frames, k %u, tables %.1f MiB, step %.3f ms (median)\n",
                cmd, n, mo->frames, mo->k, (double)(rad_alias_tables_memory(tables[0]) * count) / 1048576.0,
                1e3 * *step_seconds);
    } else if (mo->method == TOOL_LOCAL) {
        rad_row_source src;
        rad_local_options lo;
        uint32_t m = mo->local_m ? mo->local_m : (n < TOOL_LOCAL_M_AUTO_MAX ? n : TOOL_LOCAL_M_AUTO_MAX);
        proxy_near *d2 = (proxy_near *)xmalloc(sizeof(proxy_near) * (size_t)n);
        if (m > n) m = n;
        order = (uint32_t *)xmalloc(sizeof(uint32_t) * (size_t)n);
        for (i = 0; i < n; ++i) {
            uint32_t c[3], k;
            uint64_t key = vp->voxel_keys[vp->voxel[i]];
            double q = 0.0;
            c[0] = (uint32_t)(key % vp->dims[0]);
            c[1] = (uint32_t)((key / vp->dims[0]) % vp->dims[1]);
            c[2] = (uint32_t)(key / vp->dims[0] / vp->dims[1]);
            for (k = 0; k < 3; ++k) {
                double x = (double)vp->origin[k] + ((double)c[k] + 0.5) * (double)vp->voxel_size[k] - (double)cam->position[k];
                q += x * x;
            }
            d2[i].d2 = q;
            d2[i].patch = i;
        }
        qsort(d2, n, sizeof *d2, cmp_near);
        for (i = 0; i < n; ++i) order[i] = d2[i].patch;
        free(d2);
        rad_local_options_default(&lo);
        lo.capacity = m;
        if ((r = rad_row_source_matrix(&vp->matrix, vp->areas, vp->albedo, &src)) != RAD_SUCCESS) { what = "rad_row_source_matrix"; goto done; }
        if ((r = rad_local_create(&src, &lo, &ctx, &local)) != RAD_SUCCESS) { what = "rad_local_create"; goto done; }
        tool_context(&ctx, "local matrix");
        r = rad_local_rebuild(local, order, m, &ctx);
        tool_progress_end();
        tool_context(&ctx, NULL);
        if (r != RAD_SUCCESS) { what = "rad_local_rebuild"; goto done; }
        if ((r = rad_local_apply(local, E, NULL, 0, NULL, 0, L, RAD_OUTPUT_INDIRECT, &ctx)) != RAD_SUCCESS) { what = "rad_local_apply"; goto done; }
        *step_seconds = tool_seconds() - t0;
        fprintf(stderr, "rad %s: local matrix over %u of %u virtual patches (nearest the camera)\n", cmd, m, n);
    }
done:
    free(steps);
    free(order);
    rad_local_destroy(local);
    rad_temporal_destroy(tp);
    for (i = 0; i < 3; ++i) rad_alias_tables_destroy(tables[i]);
    rad_multibounce_destroy(mb);
    return what ? tool_fail(cmd, what, r) : 0;
}

/* --method temporal --proxy aavp|vp with --light-path or --sequence: the frames of a light
   that moves (the last --point or --spot of the command line, along the path; without a path
   every light stays): per frame E at the samples (rad_vp_lights: the falloff exact, the shadows
   re-tested for --light-rays samples per frame, all by default), one temporal step, and with
   --sequence every --every-th frame rendered (H = F (E + L) gathered per pixel, the direct light
   per pixel from the moved light), and the last. The light ends where the last frame puts it,
   so the final image (rendered by the caller from E and L) is that frame. Stage times: their
   medians. */
static int proxy_temporal_frames(const char *cmd, const tool_world *w, const rad_virtual_patches *vp, float *E,
                                 const tool_method_options *mo, const rad_camera *cam, int width, int height,
                                 uint32_t aa, uint32_t light_samples, uint32_t patch_light_samples, float exposure,
                                 float *L, double *step_seconds)
{
    rad_alias_tables *tables = NULL;
    const rad_alias_tables *tp1[1];
    rad_temporal *tp = NULL;
    rad_temporal_options to;
    rad_vp_lights *dyn = NULL;
    rad_vp_lights_options lo;
    rad_light *moving = NULL;
    rad_context ctx;
    rad_result r = RAD_SUCCESS;
    const char *what = NULL;
    uint32_t n = vp->count, f, i, frames = mo->frames;
    double *te = (double *)xmalloc(sizeof(double) * frames), *ts = (double *)xmalloc(sizeof(double) * frames);
    float *B = (float *)xmalloc(sizeof(float) * 3 * (size_t)n), *H = (float *)xmalloc(sizeof(float) * 3 * (size_t)n);
    uint64_t rays = 0;
    int rc = 0;
    tool_context(&ctx, NULL);
    if (mo->light_path) {
        for (i = w->file.light_count; i > w->file_light_count; --i)
            if (w->file.lights[i - 1].type == RAD_LIGHT_POINT || w->file.lights[i - 1].type == RAD_LIGHT_SPOT) {
                moving = &w->file.lights[i - 1]; /* the world's own array: the per-pixel light moves with it */
                break;
            }
        if (!moving) {
            fprintf(stderr, "rad %s: --light-path moves the last --point or --spot light: give one\n", cmd);
            rc = 1;
            goto done;
        }
    }
    if ((r = rad_alias_tables_create(&vp->matrix, RAD_ALIAS_AUTO, &ctx, &tables)) != RAD_SUCCESS) { what = "rad_alias_tables_create"; goto done; }
    tp1[0] = tables;
    rad_temporal_options_default(&to);
    to.mode = mo->mode;
    to.samples = mo->k;
    to.adaptive = mo->adaptive && !(mo->given & TOOL_OPT_W);
    to.weight = mo->w > 0.0f ? mo->w : -1.0f; /* --w 0: no history */
    to.seed = mo->seed;
    if ((r = rad_temporal_create(tp1, 1, vp->albedo, &to, &ctx, &tp)) != RAD_SUCCESS) { what = "rad_temporal_create"; goto done; }
    rad_vp_lights_options_default(&lo);
    lo.rays_per_frame = mo->light_rays;
    lo.direct.exclude_emitters = 0;
    lo.direct.light_samples = patch_light_samples; /* as rad_vp_sources got them for the still image */
#if defined(__unix__) || defined(__APPLE__)
    if (mo->sequence) mkdir(mo->sequence, 0777); /* may exist; a failure shows when writing */
#endif
    if ((r = rad_vp_lights_create(vp, &w->rc, &lo, &ctx, &dyn)) != RAD_SUCCESS) { what = "rad_vp_lights_create"; goto done; }
    for (f = 1; f <= frames; ++f) {
        double t0;
        if (moving) {
            const float *q = mo->path;
            float u = frames > 1 ? (float)(f - 1) / (float)(frames - 1) : 1.0f;
            int k;
            if (mo->light_path == 1) {
                for (k = 0; k < 3; ++k) moving->position[k] = q[k] + u * (q[3 + k] - q[k]);
            } else {
                float a = 6.2831853f * (float)(f - 1) / (float)frames;
                moving->position[0] = q[0] + q[3] * cosf(a);
                moving->position[1] = q[1];
                moving->position[2] = q[2] + q[3] * sinf(a);
            }
        }
        t0 = tool_seconds();
        if ((r = rad_vp_lights_update(dyn, w->file.lights, w->file.light_count, E, &ctx)) != RAD_SUCCESS) { what = "rad_vp_lights_update"; goto done; }
        te[f - 1] = tool_seconds() - t0;
        rays += rad_vp_lights_rays(dyn);
        t0 = tool_seconds();
        if ((r = rad_temporal_step(tp, E, NULL, L)) != RAD_SUCCESS) { what = "rad_temporal_step"; goto done; }
        ts[f - 1] = tool_seconds() - t0;
        if (mo->sequence && (f % mo->every == 0 || f == frames)) { /* the last one too, as render_method */
            char path[4096];
            tool_image frame;
            memset(&frame, 0, sizeof frame);
            for (i = 0; i < 3 * n; ++i) B[i] = E[i] + L[i];
            if ((r = rad_matrix_multiply(&vp->matrix, B, H, &ctx)) != RAD_SUCCESS) { what = "rad_matrix_multiply"; goto done; }
            snprintf(path, sizeof path, "%s/frame_%05u.png", mo->sequence, f);
            if (tool_image_alloc(&frame, width, height) != 0) {
                fprintf(stderr, "rad %s: out of memory for a %dx%d image\n", cmd, width, height);
                rc = 1;
                goto done;
            }
            render_vp = vp, render_vp_H = H;
            rc = render_classic(w, NULL, NULL, cam, width, height, aa, light_samples, &frame);
            render_vp = NULL, render_vp_H = NULL;
            if (rc == 0 && tool_image_write_png(path, &frame, exposure) != 0) {
                fprintf(stderr, "rad %s: %s\n", cmd, tool_output_error());
                rc = 1;
            }
            tool_image_free(&frame);
            if (rc) goto done;
        }
    }
    qsort(te, frames, sizeof(double), cmp_double);
    qsort(ts, frames, sizeof(double), cmp_double);
    *step_seconds = ts[frames / 2];
    fprintf(stderr, "rad %s: temporal over %u virtual patches, %u frames%s: E update %.3f ms (median; %.0f shadow rays per "
                    "frame), temporal step %.3f ms (median)\n",
            cmd, n, frames, moving ? " with a moving light" : "", 1e3 * te[frames / 2], (double)rays / frames,
            1e3 * ts[frames / 2]);
done:
    free(te);
    free(ts);
    free(B);
    free(H);
    rad_vp_lights_destroy(dyn);
    rad_temporal_destroy(tp);
    rad_alias_tables_destroy(tables);
    if (what) return tool_fail(cmd, what, r);
    return rc;
}

/* --method vp|aavp: virtual patches, E at their samples, the classic solve on
   their matrix (Jacobi K bounces; inf: Gauss-Seidel), H = F (E + L) per patch, and the
   classic per-pixel render with H gathered at each sample's hit point. */
/* --bake FILE with --method aavp|vp or --proxy: the set saved by rad bake --method aavp|vp
   (rad_vp_load, checked against the scene's signature and the kind asked for) and its E into
   *E_out; NULL with the error printed */
int tool_vp_bake_open(const char *cmd, const char *path, const void *data, size_t size, const rad_scene *scene,
                      rad_container **ct_out, rad_virtual_patches **vp_out, float **E_out)
{
    rad_container *ct = NULL;
    rad_virtual_patches *vp = NULL;
    const rad_section *vi, *se;
    rad_context ctx;
    rad_result r;
    uint32_t i;
    *ct_out = NULL;
    *vp_out = NULL;
    *E_out = NULL;
    tool_context(&ctx, NULL);
    if ((r = rad_container_create(data, size, &ctx, &ct)) != RAD_SUCCESS) {
        fprintf(stderr, "rad %s: bake '%s' is damaged: %s\n", cmd, path, rad_result_string(r));
        return 1;
    }
    vi = rad_container_find(ct, RAD_SECTION_VP_INFO, "vp");
    if (!vi) {
        fprintf(stderr, "rad %s: bake '%s' holds no virtual patches (bake them with --method aavp|vp)\n", cmd, path);
        rad_container_destroy(ct);
        return 1;
    }
    if ((r = rad_vp_load(ct, "vp", scene, &ctx, &vp)) != RAD_SUCCESS) {
        fprintf(stderr, "rad %s: bake '%s' holds damaged virtual patches: %s\n", cmd, path, rad_result_string(r));
        rad_container_destroy(ct);
        return 1;
    }
    se = rad_container_find(ct, RAD_SECTION_VECTOR, "E");
    if (!se || se->elem_size != 12 || se->count != vp->count) {
        fprintf(stderr, "rad %s: bake '%s' holds no source vector E for its %u patches\n", cmd, path, vp->count);
        rad_vp_destroy(vp);
        rad_container_destroy(ct);
        return 1;
    }
    *E_out = (float *)xmalloc(sizeof(float) * 3 * (size_t)vp->count);
    memcpy(*E_out, se->data, sizeof(float) * 3 * (size_t)vp->count);
    for (i = 0; i < 3 * vp->count; ++i)
        if (!((*E_out)[i] >= 0.0f && (*E_out)[i] <= RAD_BAKE_VALUE_MAX)) {
            fprintf(stderr, "rad %s: bake '%s': E entry %u is %g (not in [0, 1e30])\n", cmd, path, i, (double)(*E_out)[i]);
            free(*E_out);
            *E_out = NULL;
            rad_vp_destroy(vp);
            rad_container_destroy(ct);
            return 1;
        }
    *ct_out = ct;
    *vp_out = vp;
    return 0;
}

static rad_virtual_patches *vp_load_bake(const char *cmd, const char *path, const tool_world *w, int clustered,
                                         float **E_out)
{
    void *buf = NULL;
    size_t size = 0;
    rad_container *ct = NULL;
    rad_virtual_patches *vp = NULL;
    const rad_section *sg;
    rad_result r;
    uint64_t geometry = 0, materials = 0;
    *E_out = NULL;
    if (tool_read_file(cmd, "bake", path, &buf, &size)) return NULL;
    if (tool_vp_bake_open(cmd, path, buf, size, w->scene, &ct, &vp, E_out)) {
        free(buf);
        return NULL;
    }
    sg = rad_container_find(ct, RAD_SECTION_SIGNATURE, NULL);
    if ((r = rad_scene_hash(w->scene, &geometry, &materials)) != RAD_SUCCESS || !sg || sg->elem_size != sizeof(rad_bake_signature) ||
        memcmp(sg->data, &geometry, 8) || memcmp((const unsigned char *)sg->data + 8, &materials, 8)) {
        fprintf(stderr, "rad %s: bake '%s' was not made from this scene (its signature differs)\n", cmd, path);
        goto fail;
    }
    {
        /* the options record and the command line's lights (a bake lit by --sun holds that sun's E) */
        const rad_section *so = rad_container_find(ct, TOOL_SECTION_OPTIONS, "rad.options");
        tool_bake_info info;
        uint64_t want;
        if (!so || so->elem_size != sizeof info || so->count != 1) {
            fprintf(stderr, "rad %s: bake '%s' holds no rad.options record\n", cmd, path);
            goto fail;
        }
        memcpy(&info, so->data, sizeof info);
        want = tool_options_hash(&info, w);
        if (memcmp((const unsigned char *)sg->data + 16, &want, 8)) {
            fprintf(stderr, "rad %s: bake '%s' was made with other lights or options (the --sun, --sky, --point, --spot "
                            "of the bake must be given again)\n", cmd, path);
            goto fail;
        }
    }
    if ((vp->kind == RAD_VP_CLUSTERED) != (clustered != 0)) {
        fprintf(stderr, "rad %s: bake '%s' holds %s virtual patches, not %s\n", cmd, path,
                vp->kind == RAD_VP_CLUSTERED ? "vp" : "aavp", clustered ? "vp" : "aavp");
        goto fail;
    }
    rad_container_destroy(ct);
    free(buf);
    fprintf(stderr, "rad %s: loaded %u virtual patches (%llu non-zeros) from '%s'\n", cmd, vp->count,
            vp->matrix.storage == RAD_STORAGE_SPARSE ? (unsigned long long)vp->matrix.row_offsets[vp->count]
                                                     : (unsigned long long)vp->count * vp->count, path);
    return vp;
fail:
    free(*E_out);
    *E_out = NULL;
    rad_vp_destroy(vp);
    rad_container_destroy(ct);
    free(buf);
    return NULL;
}

static int render_vp_method(const char *cmd, const tool_world *w, const char *bake_path,
                            const tool_classic_options *o, const tool_method_options *mo, const rad_camera *cam,
                            int width, int height, uint32_t aa, uint32_t light_samples, float exposure, tool_image *img)
{
    rad_virtual_patches *vp = NULL;
    rad_direct_options dopt;
    rad_solve_options so;
    rad_solve_stats stats;
    rad_system sys;
    rad_context ctx;
    rad_result r;
    float *E = NULL, *L = NULL, *B = NULL, *H = NULL;
    uint32_t n, i, res = mo->vp_resolution;
    double t0 = tool_seconds(), t_build, t_E, t_solve, t_step = 0.0;
    int rc = 0;
    if (bake_path) {
        if (mo->given & TOOL_OPT_VP) {
            fprintf(stderr, "rad %s: --vp-resolution, --vp-max-patches and --face-points are the bake's with --bake\n", cmd);
            return 1;
        }
        if (!(vp = vp_load_bake(cmd, bake_path, w, mo->method == TOOL_VP || mo->proxy == TOOL_PROXY_VP, &E)))
            return 1;
    } else if (mo->given & TOOL_OPT_VP_MAX_PATCHES) {
        if (tool_vp_resolution_within(cmd, w, mo->method == TOOL_VP || mo->proxy == TOOL_PROXY_VP ? RAD_VP_CLUSTERED
                                                                                                    : RAD_VP_AXIS_ALIGNED,
                                      mo->face_points, mo->vp_max_patches, mo->vp_resolution, &res))
            return 1;
        if (!(vp = vp_build(cmd, w, mo, res))) return 1;
    } else if (!(vp = vp_build(cmd, w, mo, res))) {
        return 1;
    }
    t_build = tool_seconds() - t0;
    n = vp->count;
    if (!E) E = (float *)xmalloc(sizeof(float) * 3 * (size_t)n);
    L = (float *)xmalloc(sizeof(float) * 3 * (size_t)n);
    B = (float *)xmalloc(sizeof(float) * 3 * (size_t)n);
    H = (float *)xmalloc(sizeof(float) * 3 * (size_t)n);
    rad_direct_options_default(&dopt);
    dopt.exclude_emitters = 0;
    dopt.light_samples = o->light_samples;
    tool_context(&ctx, "direct light");
    t0 = tool_seconds();
    r = bake_path ? RAD_SUCCESS /* the bake's E */
                  : rad_vp_sources(vp, &w->rc, w->file.lights, w->file.light_count, &dopt, RAD_SOURCE_DIRECT, E, &ctx);
    tool_progress_end();
    t_E = tool_seconds() - t0;
    if (r != RAD_SUCCESS) rc = tool_fail(cmd, "rad_vp_sources", r);
    if (rc == 0) {
        rad_vp_system(&sys, vp, E);
        rad_solve_options_default(&so);
        so.output = RAD_OUTPUT_INDIRECT;
        so.bounces = mo->bounces;
        memset(&stats, 0, sizeof stats);
        tool_context(&ctx, NULL);
        t0 = tool_seconds();
        if (mo->proxy && mo->method == TOOL_TEMPORAL && (mo->light_path || mo->sequence)) {
            r = RAD_SUCCESS;
            if (proxy_temporal_frames(cmd, w, vp, E, mo, cam, width, height, aa, light_samples, o->light_samples, exposure,
                                      L, &t_step)) rc = 1;
        } else if (mo->proxy) {
            r = RAD_SUCCESS;
            if (proxy_indirect(cmd, vp, E, mo, cam, L, &t_step)) rc = 1;
        } else if (mo->bounces == RAD_MB_INFINITE) {
            r = rad_solve_gauss_seidel(&sys, &so, L, &stats, &ctx);
            if (r == RAD_ERROR_NOT_CONVERGED) {
                fprintf(stderr, "rad %s: warning: Gauss-Seidel did not converge (residual %g after %u sweeps)\n", cmd,
                        stats.residual, stats.iterations);
                r = RAD_SUCCESS;
            }
        } else if (mo->bounces) {
            r = rad_solve_jacobi(&sys, &so, L, &stats, &ctx);
        } else {
            memset(L, 0, sizeof(float) * 3 * (size_t)n); /* --bounces 0: no indirect light */
            r = RAD_SUCCESS;
        }
        for (i = 0; i < 3 * n; ++i) B[i] = E[i] + L[i];
        if (r == RAD_SUCCESS && rc == 0) r = rad_matrix_multiply(&vp->matrix, B, H, &ctx);
        t_solve = tool_seconds() - t0;
        if (!mo->proxy) t_step = t_solve;
        if (r != RAD_SUCCESS) rc = tool_fail(cmd, "solve", r);
    }
    if (rc == 0) {
        render_vp = vp, render_vp_H = H, render_vp_gather_seconds = 0.0;
        t0 = tool_seconds();
        rc = render_classic(w, NULL, NULL, cam, width, height, aa, light_samples, img);
        render_vp = NULL, render_vp_H = NULL;
        /* one line for scripts: step = the solve (K bounces + H = F B) as classic's */
        if (rc == 0) {
            fprintf(stderr, "rad %s: timing: method=%s%s patches=%u frames=%u bounces=%s%.0u step_ms_median=%.6f "
                            "step_ms_min=%.6f build_ms=%.1f sources_ms=%.1f gather_ms=%.1f render_ms=%.1f "
                            "resolution=%u vp_mib=%.1f peak_rss_mib=%.1f\n",
                    cmd, tool_method_name(mo->method),
                    mo->proxy == TOOL_PROXY_VP ? " proxy=vp" : mo->proxy ? " proxy=aavp" : "", n,
                    mo->proxy && mo->method == TOOL_TEMPORAL ? mo->frames : 1u,
                    mo->bounces == RAD_MB_INFINITE ? "inf" : "",
                    mo->bounces == RAD_MB_INFINITE ? 0u : mo->bounces,
                    1e3 * t_step, 1e3 * t_step, 1e3 * t_build, 1e3 * t_E, 1e3 * render_vp_gather_seconds,
                    1e3 * (tool_seconds() - t0), res, (double)rad_vp_memory(vp) / 1048576.0, peak_rss_mib());
        }
    }
    free(E);
    free(L);
    free(B);
    free(H);
    rad_vp_destroy(vp);
    return rc;
}

/* --method hierarchical: the solution (tool_hierarchical_build), then the classic render
   with H looked up at each sample */
static int render_hr_method(const char *cmd, const tool_world *w, const tool_classic_options *o,
                            const tool_method_options *mo, const rad_camera *cam, int width, int height, uint32_t aa,
                            uint32_t light_samples, tool_image *img)
{
    rad_hierarchical *h = NULL;
    rad_hierarchical_stats st;
    double t0 = tool_seconds(), t_solve;
    int rc;
    if (tool_hierarchical_build(cmd, w, mo, o->light_samples, &h)) return 1;
    t_solve = tool_seconds() - t0;
    rad_hierarchical_get_stats(h, &st);
    render_hr = h;
    t0 = tool_seconds();
    rc = render_classic(w, NULL, NULL, cam, width, height, aa, light_samples, img);
    render_hr = NULL;
    if (rc == 0)
        fprintf(stderr, "rad %s: timing: method=hierarchical patches=%u frames=1 step_ms_median=%.6f step_ms_min=%.6f "
                        "links=%llu kernels=%llu rays=%llu render_ms=%.1f\n",
                cmd, st.leaves, 1e3 * t_solve, 1e3 * t_solve, (unsigned long long)st.links,
                (unsigned long long)st.kernel_evaluations, (unsigned long long)st.rays_cast, 1e3 * (tool_seconds() - t0));
    rad_hierarchical_destroy(h);
    return rc;
}

/* --method local: the classic patches, F and E; a local matrix of capacity M over F's
   rows filled with the M patches nearest the camera (rad_local_rebuild), L = T E over P_Vis x
   P_Lit, H = L / rho (L = rho F (E + L) within the set), rendered as classic. */
static int render_local_method(const char *cmd, const tool_world *w, const tool_classic_options *oc,
                               const tool_method_options *mo, const rad_camera *cam, int width, int height,
                               uint32_t aa, uint32_t light_samples, tool_image *img)
{
    tool_classic_options o = *oc;
    tool_classic sol;
    rad_local_options lo;
    rad_local *local = NULL;
    rad_row_source src;
    rad_context ctx;
    rad_result r;
    uint32_t n, m, i, c, nvis = 0, nlit = 0;
    uint32_t *set = NULL, *vis = NULL, *lit = NULL;
    float *areas = NULL, *albedo = NULL, *L = NULL, *H = NULL, *Hv = NULL;
    double t0, t_rebuild = 0.0, times[9];
    int rc = 0, k;
    o.sources_only = 1;
    if (tool_classic_solve(cmd, w, &o, &sol)) return 1;
    n = sol.patches->count;
    if (mo->local_m == 0) { /* the default: the whole scene when it is small enough */
        m = n < TOOL_LOCAL_M_AUTO_MAX ? n : TOOL_LOCAL_M_AUTO_MAX;
        if (m < n)
            fprintf(stderr, "rad %s: warning: the default --local-m covers %u of the %u patches (the nearest to the "
                            "camera; the others get no indirect light): give --local-m %u for all of them\n",
                    cmd, m, n, n);
    } else {
        m = mo->local_m < n ? mo->local_m : n;
        if (mo->local_m > n)
            fprintf(stderr, "rad %s: --local-m %u is more than the %u patches: using %u\n", cmd, mo->local_m, n, n);
    }
    areas = (float *)xmalloc(sizeof(float) * n);
    albedo = (float *)xmalloc(sizeof(float) * 3 * (size_t)n);
    L = (float *)xmalloc(sizeof(float) * 3 * (size_t)n);
    H = (float *)xmalloc(sizeof(float) * 3 * (size_t)n);
    set = (uint32_t *)xmalloc(sizeof(uint32_t) * m);
    vis = (uint32_t *)xmalloc(sizeof(uint32_t) * m);
    lit = (uint32_t *)xmalloc(sizeof(uint32_t) * m);
    for (i = 0; i < n; ++i) {
        areas[i] = sol.patches->patches[i].area;
        for (c = 0; c < 3; ++c) albedo[3 * i + c] = sol.patches->patches[i].albedo[c];
    }
    for (i = 0; i < 3 * n; ++i) L[i] = 0.0f;
    tool_context(&ctx, NULL);
    rad_local_options_default(&lo);
    lo.capacity = m;
    r = rad_row_source_matrix(&sol.ff->matrix, areas, albedo, &src);
    if (r == RAD_SUCCESS) r = rad_local_create(&src, &lo, &ctx, &local);
    if (r == RAD_SUCCESS) r = rad_local_nearest(sol.patches, cam->position, m, set, &ctx);
    if (r == RAD_SUCCESS) {
        t0 = tool_seconds();
        r = rad_local_rebuild(local, set, m, &ctx);
        t_rebuild = tool_seconds() - t0;
    }
    if (r == RAD_SUCCESS)
        r = rad_local_visible(sol.patches, &w->rc, cam, (float)width / (float)height, set, m, vis, &nvis, &ctx);
    if (r == RAD_SUCCESS) r = rad_local_lit(sol.E, set, m, 0.0f, lit, &nlit);
    for (k = 0; k < 9 && r == RAD_SUCCESS; ++k) {
        t0 = tool_seconds();
        r = rad_local_apply(local, sol.E, vis, nvis, lit, nlit, L, RAD_OUTPUT_INDIRECT, &ctx);
        times[k] = tool_seconds() - t0;
    }
    if (r != RAD_SUCCESS) rc = tool_fail(cmd, "local matrix", r);
    if (rc == 0) {
        qsort(times, 9, sizeof(double), cmp_double);
        fprintf(stderr, "rad %s: local matrix: M = %u of %u patches, |P_Vis| = %u, |P_Lit| = %u, %.1f MiB\n", cmd, m,
                n, nvis, nlit, (double)rad_local_memory(local) / 1048576.0);
        fprintf(stderr, "rad %s: timing: method=local patches=%u frames=9 step_ms_median=%.6f step_ms_min=%.6f "
                        "rebuild_ms=%.3f local_m=%u visible=%u lit=%u\n",
                cmd, n, 1e3 * times[4], 1e3 * times[0], 1e3 * t_rebuild, m, nvis, nlit);
        /* H = L / rho: the irradiance from the secondary sources (0 where rho is 0) */
        for (i = 0; i < 3 * n; ++i) H[i] = albedo[i] > 0.0f ? L[i] / albedo[i] : 0.0f;
        Hv = (float *)xmalloc(sizeof(float) * 3 * (size_t)sol.patches->vertex_count);
        rc = vertex_H(sol.patches, &sol.ff->matrix, H, Hv);
        if (rc == 0) rc = render_classic(w, sol.patches, Hv, cam, width, height, aa, light_samples, img);
    }
    rad_local_destroy(local);
    free(areas);
    free(albedo);
    free(L);
    free(H);
    free(Hv);
    free(set);
    free(vis);
    free(lit);
    tool_classic_free(&sol);
    return rc;
}

/* No --method (and no --bake): the library's plan picks classic or AAVP and the resolution
   from the scene and the budget (rad_baker_plan), and says so before the work. A
   virtual-patch method (or proxy) without --vp-resolution or --vp-max-patches takes the
   plan's resolution the same way. */
static int render_default_method(const char *cmd, const tool_world *w, const tool_classic_options *o,
                                 tool_method_options *mo)
{
    rad_baker_options bo;
    rad_baker_choice plan;
    rad_context ctx;
    rad_result r;
    int chosen = !(mo->given & TOOL_OPT_METHOD);
    memset(&bo, 0, sizeof bo);
    bo.method = chosen ? RAD_BAKER_AUTO : RAD_BAKER_VIRTUAL_PATCHES;
    bo.max_memory = o->max_memory;
    bo.patches = o->patches;
    bo.ff_samples = o->samples;
    bo.bounces = o->bounces;
    bo.light_samples = o->light_samples;
    tool_context(&ctx, NULL);
    if ((r = rad_baker_plan(w->scene, &w->rc, &bo, &ctx, &plan)) != RAD_SUCCESS) return tool_fail(cmd, "rad_baker_plan", r);
    if (plan.method == RAD_BAKER_VIRTUAL_PATCHES) {
        if (chosen) mo->method = TOOL_AAVP;
        mo->vp_resolution = plan.vp_resolution;
    }
    if (!chosen)
        fprintf(stderr, "rad %s: no --vp-resolution given: resolution %u from the scene\n", cmd, plan.vp_resolution);
    else if (plan.method == RAD_BAKER_VIRTUAL_PATCHES)
        fprintf(stderr, "rad %s: no --method given: chose aavp at --vp-resolution %u (give --method to choose)\n", cmd,
                plan.vp_resolution);
    else
        fprintf(stderr, "rad %s: no --method given: chose classic (give --method to choose)\n", cmd);
    return 0;
}

static int render_main(int argc, char **argv, tool_lights *lights)
{
    const char *cmd = "render", *scene_name = NULL, *out_path = NULL, *bake_path = NULL, *method;
    tool_classic_options o;
    tool_method_options mo;
    tool_world w;
    rad_camera cam;
    tool_image img;
    rad_context ctx;
    int width = 512, height = 512, a, rc, have_cam = 0, pathtrace;
    uint32_t aa = 16, spp = 64, seed = 0, threads = 0, pixel_light_samples = 16;
    int lightmap_opts = 0;
    float fov = 0.0f, exposure = 1.0f;
    double t0 = tool_seconds();
    tool_classic_options_default(&o);
    tool_method_options_default(&mo);
    memset(&img, 0, sizeof img);
    for (a = 0; a < argc; ++a) {
        const char *opt = argv[a];
        if (!strcmp(opt, "--help") || !strcmp(opt, "-h")) { render_usage(stdout); return 0; }
        rc = tool_method_option(cmd, argc, argv, &a, &mo); /* --method, --seed and the methods' options */
        if (rc == 2) return 2;
        if (rc == 1) continue;
        rc = tool_classic_option(cmd, argc, argv, &a, &o);
        if (rc == 2) return 2;
        if (rc == 1) continue;
        rc = tool_light_option(cmd, argc, argv, &a, lights);
        if (rc == 2) return 2;
        if (rc == 1) continue;
        if (opt[0] == '-' && opt[1] && a + 1 >= argc) {
            fprintf(stderr, "rad %s: %s needs a value (or is unknown; see rad render --help)\n", cmd, opt);
            return 2;
        }
        if (!strcmp(opt, "-o")) out_path = argv[++a];
        else if (!strcmp(opt, "--bake")) bake_path = argv[++a];
        else if (!strcmp(opt, "--camera")) {
            const char *why;
            if (tool_parse_camera(argv[++a], &cam, &why)) {
                fprintf(stderr, "rad %s: bad --camera '%s': %s\n", cmd, argv[a], why);
                return 2;
            }
            have_cam = 1;
        } else if (!strcmp(opt, "--fov")) {
            if (tool_parse_float(cmd, opt, argv[++a], &fov)) return 2;
            if (!(fov > 0.0f && fov < 180.0f)) { fprintf(stderr, "rad %s: --fov must be in (0, 180)\n", cmd); return 2; }
        } else if (!strcmp(opt, "--size")) {
            if (tool_parse_size(argv[++a], &width, &height)) {
                fprintf(stderr, "rad %s: bad size '%s' (want WxH, e.g. 512x512)\n", cmd, argv[a]);
                return 2;
            }
            if (tool_check_size(cmd, width, height)) return 2;
        } else if (!strcmp(opt, "--aa")) {
            if (tool_parse_uint(cmd, opt, argv[++a], &aa)) return 2;
            if (aa == 0 || aa > 65536) { fprintf(stderr, "rad %s: --aa must be 1 to 65536\n", cmd); return 2; }
        } else if (!strcmp(opt, "--spp")) {
            if (tool_parse_uint(cmd, opt, argv[++a], &spp)) return 2;
            if (spp == 0 || spp > 1u << 20) { fprintf(stderr, "rad %s: --spp must be in 1..1048576\n", cmd); return 2; }
        } else if (!strcmp(opt, "--pixel-light-samples")) {
            if (tool_parse_uint(cmd, opt, argv[++a], &pixel_light_samples)) return 2;
            if (pixel_light_samples == 0 || pixel_light_samples > 65536) { fprintf(stderr, "rad %s: %s must be 1 to 65536\n", cmd, opt); return 2; }
        } else if (!strcmp(opt, "--lightmap-size") || !strcmp(opt, "--texel-samples") || !strcmp(opt, "--visibility-rays")) {
            uint32_t *dst = opt[2] == 'l' ? &render_lm_size : opt[2] == 't' ? &render_lm_samples : &render_lm_vis;
            uint32_t lo = opt[2] == 'l' ? 4u : 1u, hi = opt[2] == 'l' ? 16384u : opt[2] == 't' ? 16u : 64u;
            if (tool_parse_uint(cmd, opt, argv[++a], dst)) return 2;
            if (*dst < lo || *dst > hi) { fprintf(stderr, "rad %s: %s must be %u to %u\n", cmd, opt, lo, hi); return 2; }
            if (opt[2] == 'l') render_lm_size_given = 1;
            lightmap_opts = 1;
        } else if (!strcmp(opt, "--final-gather")) {
            if (tool_parse_uint(cmd, opt, argv[++a], &render_final_gather)) return 2;
            if (render_final_gather > 4096) { fprintf(stderr, "rad %s: %s is at most 4096\n", cmd, opt); return 2; }
        } else if (!strcmp(opt, "--exposure")) {
            if (tool_parse_float(cmd, opt, argv[++a], &exposure)) return 2;
            if (!(exposure > 0.0f)) { fprintf(stderr, "rad %s: --exposure must be > 0\n", cmd); return 2; }
        } else if (!strcmp(opt, "--shading")) {
            if (tool_parse_shading(cmd, argv[++a], &render_shading)) return 2;
        } else if (!strcmp(opt, "--threads")) {
            if (tool_parse_threads(cmd, opt, argv[++a], &threads)) return 2;
        } else if (opt[0] == '-' && opt[1]) {
            fprintf(stderr, "rad %s: unknown option '%s' (see rad render --help)\n", cmd, opt);
            return 2;
        } else if (!scene_name) scene_name = opt;
        else { fprintf(stderr, "rad %s: more than one scene given\n", cmd); return 2; }
    }
    if (!scene_name || !out_path) {
        fprintf(stderr, "rad %s: %s\n", cmd, !scene_name ? "no scene given" : "no output file given (-o OUT.png|OUT.pfm)");
        render_usage(stderr);
        return 2;
    }
    if (tool_method_check(cmd, 1, &mo, &o)) return 2;
    if (lightmap_opts && mo.method != TOOL_LIGHTMAP) {
        fprintf(stderr, "rad %s: --lightmap-size, --texel-samples and --visibility-rays are for --method lightmap\n", cmd);
        return 2;
    }
    if (mo.method == TOOL_LIGHTMAP && (bake_path || render_final_gather)) {
        fprintf(stderr, "rad %s: --method lightmap bakes its own lightmap: %s is not used\n", cmd,
                bake_path ? "--bake" : "--final-gather");
        return 2;
    }
    tool_dense_plan(&o, &mo, 0);
    method = tool_method_name(mo.method);
    seed = mo.seed;
    pathtrace = mo.method == TOOL_PATHTRACE;
    if (pathtrace && render_shading >= 0) {
        fprintf(stderr, "rad %s: --shading is for the radiosity methods (the path tracer is Lambertian)\n", cmd);
        return 2;
    }
    if (mo.method == TOOL_LOCAL && !mo.proxy && bake_path) {
        fprintf(stderr, "rad %s: --bake is not used by --method %s (it builds its data here)\n", cmd, method);
        return 2;
    }
    if (pathtrace && bake_path) {
        fprintf(stderr, "rad %s: --bake is for the radiosity methods (classic, multibounce, temporal), not pathtrace\n", cmd);
        return 2;
    }
    if (tool_image_check_format(cmd, out_path)) return 2;
    {
        const char *inputs[2];
        inputs[0] = scene_name;
        inputs[1] = bake_path;
        if (tool_check_output(cmd, out_path, inputs, 2)) return 1;
    }
    tool_set_threads((int)threads);
    if (tool_open_world_lit(cmd, scene_name, lights, &w)) return 1;
    if (tool_check_outputs(cmd, &out_path, 1, w.file.input_files, (int)w.file.input_file_count)) {
        tool_close_world(&w);
        return 1;
    }
    if (!bake_path && (!(mo.given & TOOL_OPT_METHOD) ||
                       ((mo.method == TOOL_AAVP || mo.method == TOOL_VP || mo.proxy == TOOL_PROXY_AAVP ||
                         mo.proxy == TOOL_PROXY_VP) &&
                        !(mo.given & (TOOL_OPT_VP_RESOLUTION | TOOL_OPT_VP_MAX_PATCHES))))) {
        if (render_default_method(cmd, &w, &o, &mo)) {
            tool_close_world(&w);
            return 1;
        }
        method = tool_method_name(mo.method);
    }
    {
        uint32_t t, emitters = 0;
        for (t = 0; t < w.scene->triangle_count; ++t) {
            const float *Le = w.scene->materials_table[w.scene->materials[t]].emission;
            if (Le[0] > 0.0f || Le[1] > 0.0f || Le[2] > 0.0f) ++emitters;
        }
        if (!emitters && !w.file.light_count)
            fprintf(stderr, "rad %s: warning: the scene has no emitters and no lights: the image is black\n", cmd);
        if ((mo.method <= TOOL_TEMPORAL || mo.method == TOOL_LOCAL || mo.method == TOOL_STOCHASTIC ||
             mo.method == TOOL_LIGHTMAP) &&
            !mo.proxy && !pathtrace && !bake_path &&
            o.patches < w.scene->triangle_count)
            fprintf(stderr, "rad %s: note: --patches %u is below the %u triangles: every triangle is at least one patch\n",
                    cmd, o.patches, w.scene->triangle_count);
    }
    if (!have_cam) {
        if (w.file.has_camera) cam = w.file.camera;
        else tool_choose_camera(cmd, w.scene, &w.rc, width, height, &cam);
    } else cam.fov_y_degrees = w.file.camera.fov_y_degrees;
    if (fov > 0.0f) cam.fov_y_degrees = fov;
    if (tool_image_alloc(&img, width, height) != 0) {
        fprintf(stderr, "rad %s: out of memory for a %dx%d image\n", cmd, width, height);
        tool_close_world(&w);
        return 1;
    }

    if (mo.method == TOOL_LIGHTMAP) {
        tool_lightmap_baked bk;
        int lsz = (int)render_lm_size;
        tool_lightmap_proxy px;
        memset(&px, 0, sizeof px);
        px.kind = (int)mo.proxy;
        px.resolution = mo.vp_resolution;
        px.face_points = mo.face_points;
        rc = tool_lightmap_bake(cmd, &w, &o, lsz, lsz, !render_lm_size_given, render_lm_samples, render_lm_vis, -1, 256, 0, 0, 0,
                                mo.proxy ? &px : NULL, &bk);
        if (rc == 0) {
            fprintf(stderr, "rad %s: timing: method=lightmap%s patches=%u frames=1 bounces=%u step_ms_median=%.6f "
                            "step_ms_min=%.6f\n",
                    cmd, mo.proxy == TOOL_PROXY_VP ? " proxy=vp" : mo.proxy ? " proxy=aavp" : "", bk.patches, o.bounces,
                    1e3 * bk.solve_seconds, 1e3 * bk.solve_seconds);
            render_lm = bk.lm;
            render_lm_values = bk.values;
            rc = render_classic(&bk.w, bk.cl.patches, NULL, &cam, width, height, aa, pixel_light_samples, &img);
            render_lm = NULL;
            render_lm_values = NULL;
            tool_lightmap_bake_free(&bk);
        }
        if (rc) {
            tool_image_free(&img);
            tool_close_world(&w);
            return 1;
        }
    } else if ((mo.method >= TOOL_LOCAL && !(mo.method == TOOL_HIERARCHICAL && bake_path)) || mo.proxy) {
        rc = mo.method == TOOL_LOCAL && !mo.proxy
                 ? render_local_method(cmd, &w, &o, &mo, &cam, width, height, aa, pixel_light_samples, &img)
             : mo.method == TOOL_HIERARCHICAL
                 ? render_hr_method(cmd, &w, &o, &mo, &cam, width, height, aa, pixel_light_samples, &img)
                 : render_vp_method(cmd, &w, bake_path, &o, &mo, &cam, width, height, aa, pixel_light_samples, exposure,
                                    &img);
        if (rc) {
            tool_image_free(&img);
            tool_close_world(&w);
            return 1;
        }
    } else if (mo.method == TOOL_MULTIBOUNCE || mo.method == TOOL_TEMPORAL || mo.method == TOOL_STOCHASTIC ||
               mo.method == TOOL_HIERARCHICAL) { /* hierarchical here: from a bake (resampled onto its patches) */
        rc = render_with_method(cmd, &w, bake_path, &o, &mo, &cam, width, height, aa, pixel_light_samples, exposure,
                                &img);
        if (rc) {
            tool_image_free(&img);
            tool_close_world(&w);
            return 1;
        }
    } else if (pathtrace) {
        tool_trace_options to;
        rad_result r;
        tool_trace_options_default(&to);
        to.width = width;
        to.height = height;
        to.spp = (int)spp;
        to.seed = seed;
        tool_context(&ctx, "path tracing");
        r = (rad_result)tool_trace_image(w.scene, &w.rc, w.file.lights, w.file.light_count, &cam, &to, &ctx, &img);
        tool_progress_end();
        if (r != RAD_SUCCESS) {
            tool_image_free(&img);
            tool_close_world(&w);
            return tool_fail(cmd, "tool_trace_image", r);
        }
    } else {
        tool_classic sol;
        rad_bake *bake = NULL;
        const rad_patches *P;
        const float *H;
        float *Hv, *Hmine = NULL;
        memset(&sol, 0, sizeof sol);
        if (bake_path) {
            const rad_section *hs;
            rad_result r;
            tool_context(&ctx, NULL);
            if ((r = rad_load_file(bake_path, &ctx, &bake)) != RAD_SUCCESS) {
                bake_load_failed(cmd, bake_path, r);
                tool_image_free(&img);
                tool_close_world(&w);
                return 1;
            }
            rc = bake_fits_scene(cmd, bake_path, bake, &w);
            if (rc == 0 && (bake->F.rows == 0 || !bake->B)) {
                fprintf(stderr, "rad %s: bake '%s' holds no form factors or no solution B%s\n", cmd, bake_path,
                        rad_container_find(bake->container, TOOL_SECTION_METHOD, "rad.method")
                            ? " (it is a multibounce or temporal bake: render it with that --method)"
                            : "");
                rc = 1;
            }
            if (rc) {
                rad_bake_destroy(bake);
                tool_image_free(&img);
                tool_close_world(&w);
                return 1;
            }
            bake->patches.scene = w.scene;
            P = &bake->patches;
            hs = rad_container_find(bake->container, RAD_SECTION_VECTOR, "H");
            if (hs && hs->elem_size == 12 && hs->count == P->count) {
                H = (const float *)hs->data;
            } else {
                /* H = F (E + L) = F B */
                Hmine = (float *)xmalloc(sizeof(float) * 3 * P->count);
                if ((r = rad_matrix_multiply(&bake->F, bake->B, Hmine, &ctx)) != RAD_SUCCESS) {
                    free(Hmine);
                    rad_bake_destroy(bake);
                    tool_image_free(&img);
                    tool_close_world(&w);
                    return tool_fail(cmd, "rad_matrix_multiply", r);
                }
                H = Hmine;
            }
            fprintf(stderr, "rad %s: bake '%s': %u patches\n", cmd, bake_path, P->count);
        } else {
            if (tool_classic_solve(cmd, &w, &o, &sol)) {
                tool_image_free(&img);
                tool_close_world(&w);
                return 1;
            }
            P = sol.patches;
            H = sol.H;
            fprintf(stderr, "rad %s: timing: method=classic patches=%u frames=1 bounces=%u step_ms_median=%.6f "
                            "step_ms_min=%.6f\n",
                    cmd, P->count, o.bounces, 1e3 * sol.solve_seconds, 1e3 * sol.solve_seconds);
        }
        Hv = (float *)xmalloc(sizeof(float) * 3 * (size_t)P->vertex_count);
        rc = vertex_H(P, bake ? &bake->F : &sol.ff->matrix, H, Hv);
        if (rc == 0) rc = render_classic(&w, P, Hv, &cam, width, height, aa, pixel_light_samples, &img);
        free(Hv);
        free(Hmine);
        rad_bake_destroy(bake);
        tool_classic_free(&sol);
        if (rc) {
            tool_image_free(&img);
            tool_close_world(&w);
            return 1;
        }
    }
    if (tool_image_write(out_path, &img, exposure) != 0) {
        fprintf(stderr, "rad %s: %s\n", cmd, tool_output_error());
        tool_image_free(&img);
        tool_close_world(&w);
        return 1;
    }
    printf("wrote %s (%dx%d, %s) in %.2f s\n", out_path, width, height, method, tool_seconds() - t0);
    tool_image_free(&img);
    tool_close_world(&w);
    return 0;
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
