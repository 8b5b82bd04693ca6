/* pixels.c - the image of every radiosity method of `rad render` (tool_render_pixels in tool.h).

   Per pixel --aa stratified camera rays find the surfaces; the direct irradiance D is computed
   at each hit with shadow rays (rad_direct_irradiance: the emissive triangles analytically
   times the unoccluded fraction, plus the file's analytic lights, as examples/cornell.c);
   H, the irradiance from the secondary sources, comes from the solution the caller gives
   (tool_render_source: the engine tier's, virtual patches', hierarchical, a lightmap, or the
   patches' per-vertex values, smoothed to the vertices and interpolated), or from a traced
   first bounce (--final-gather); the sample's radiance is albedo/pi * (D + H) plus the
   emitted radiance where the ray sees the front of an emitter; each pixel is the box-filtered
   mean of its samples. */
#include "tool.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI_F 3.14159265358979323846f

/* Per-vertex H without dark halos where a patch is partly covered (rad_patches_vertex_irradiance).
   S: the row sums of F (how much of its hemisphere each patch sees). */
int tool_vertex_H_rowsums(const rad_patches *P, const float *S, const float *H, float *Hv)
{
    rad_context ctx;
    rad_result r;
    tool_context(&ctx, NULL);
    r = rad_patches_vertex_irradiance(P, H, S, Hv, &ctx);
    return r == RAD_SUCCESS ? 0 : tool_fail("render", "per-vertex H", r);
}

/* the same with the row sums computed from F */
int tool_vertex_H(const rad_patches *P, const rad_matrix *F, const float *H, float *Hv)
{
    uint32_t n = P->count, i;
    float *ones = (float *)tool_malloc(sizeof(float) * 3 * n), *rs = (float *)tool_malloc(sizeof(float) * 3 * n);
    float *S = (float *)tool_malloc(sizeof(float) * n);
    rad_context ctx;
    rad_result r;
    int rc;
    tool_context(&ctx, NULL);
    for (i = 0; i < 3 * n; ++i) ones[i] = 1.0f;
    r = rad_matrix_multiply(F, ones, rs, &ctx);
    for (i = 0; i < n; ++i) S[i] = rs[3 * i];
    rc = r == RAD_SUCCESS ? tool_vertex_H_rowsums(P, S, H, Hv) : tool_fail("render", "per-vertex H", r);
    free(ones);
    free(rs);
    free(S);
    return rc;
}

static rad_result hr_lookup(const rad_hierarchical *hr, const rad_hit *hits, const uint32_t *valid, uint32_t count,
                            float *out);

/* H at the final gather's hits: the virtual patches' gather, or the patches' per-vertex H */
static rad_result fg_lookup_fn(void *user, const rad_hit *hits, const float *points, const float *normals, uint32_t count,
                               float *out)
{
    const tool_render_source *l = (const tool_render_source *)user;
    uint32_t k;
    int i;
    if (l->vp) {
        rad_context quiet;
        tool_context(&quiet, NULL);
        return rad_vp_gather(l->vp, l->vp_H, points, normals, count, out, &quiet);
    }
    if (l->hr) return hr_lookup(l->hr, hits, NULL, count, out);
    if (l->baker) {
        /* the engine tier's solution: without this the hits got no bounced light at all */
        rad_context quiet;
        tool_context(&quiet, NULL);
        return rad_baker_irradiance(l->baker, hits, points, normals, count, out, &quiet);
    }
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
static rad_result hr_lookup(const rad_hierarchical *hr, const rad_hit *hits, const uint32_t *valid, uint32_t count,
                            float *out)
{
    uint32_t *tris = (uint32_t *)tool_malloc(sizeof(uint32_t) * (count ? count : 1u)), k;
    float *bary = (float *)tool_malloc(sizeof(float) * 2 * (count ? count : 1u));
    rad_result r;
    for (k = 0; k < count; ++k) {
        const rad_hit *h = &hits[valid ? valid[k] : k];
        tris[k] = h->triangle;
        bary[2 * k] = h->b1;
        bary[2 * k + 1] = h->b2;
    }
    r = rad_hierarchical_lookup(hr, RAD_HIERARCHICAL_GATHERED, 1, tris, bary, count, out);
    free(tris);
    free(bary);
    return r;
}

/* The camera samples of a band of rows in flight through tool_render_pixels: rays, hits, the
   front-face hits among them (valid: their ray index) and what each stage computes there. */
typedef struct pixel_batch {
    uint32_t strata, spp;    /* samples per pixel: strata x strata */
    size_t cap;              /* samples a batch holds */
    int rows;                /* rows per batch */
    rad_ray *rays;
    rad_hit *hits;
    float *points, *normals, *irr; /* per valid hit: position, normal, direct irradiance D */
    float *gathered;         /* per valid hit: H from the source's gather or the final gather (or NULL) */
    rad_hit *vhits;          /* per valid hit: its hit (rad_baker_irradiance) */
    float *shade_v, *shade_a, *shaded; /* --shading: view direction, albedo, direct radiance */
    uint32_t *valid;
    uint32_t count, nvalid;
} pixel_batch;

/* The samples of a batch: 64K, at least one row */
#define RENDER_BATCH_SAMPLES 65536u

static void pixel_batch_alloc(pixel_batch *b, const tool_render_view *view, const tool_render_source *src)
{
    memset(b, 0, sizeof *b);
    for (b->strata = 1; (b->strata + 1) * (b->strata + 1) <= view->aa; ++b->strata) {
    }
    b->spp = b->strata * b->strata;
    b->rows = (int)(RENDER_BATCH_SAMPLES / ((size_t)view->width * b->spp));
    if (b->rows < 1) b->rows = 1;
    b->cap = (size_t)b->rows * view->width * b->spp;
    b->rays = (rad_ray *)tool_malloc(sizeof(rad_ray) * b->cap);
    b->hits = (rad_hit *)tool_malloc(sizeof(rad_hit) * b->cap);
    b->points = (float *)tool_malloc(sizeof(float) * 3 * b->cap);
    b->normals = (float *)tool_malloc(sizeof(float) * 3 * b->cap);
    b->irr = (float *)tool_malloc(sizeof(float) * 3 * b->cap);
    b->valid = (uint32_t *)tool_malloc(sizeof(uint32_t) * b->cap);
    if (src->vp || src->hr || src->lm || src->baker || view->final_gather)
        b->gathered = (float *)tool_malloc(sizeof(float) * 3 * b->cap);
    if (src->baker) b->vhits = (rad_hit *)tool_malloc(sizeof(rad_hit) * b->cap);
    if (view->shading >= 0) {
        b->shade_v = (float *)tool_malloc(sizeof(float) * 3 * b->cap);
        b->shade_a = (float *)tool_malloc(sizeof(float) * 3 * b->cap);
        b->shaded = (float *)tool_malloc(sizeof(float) * 3 * b->cap);
    }
}

static void pixel_batch_free(pixel_batch *b)
{
    free(b->rays);
    free(b->hits);
    free(b->points);
    free(b->normals);
    free(b->irr);
    free(b->valid);
    free(b->shade_v);
    free(b->shade_a);
    free(b->shaded);
    free(b->gathered);
    free(b->vhits);
}

/* Rows y0..y1-1: the stratified camera rays, their hits (in parallel chunks: the raycaster is
   thread-safe), the sky and environment seen by rays that leave the scene added to img, and
   the front-face hits listed in b->valid with their points and normals. 0 or 1 (printed). */
static int batch_primary(const tool_world *w, const tool_render_view *view, pixel_batch *b, int y0, int y1,
                         const float sky[3], tool_image *img)
{
    const rad_scene *scene = w->scene;
    int x, y, chunk, nchunks, failed = 0;
    uint32_t s, k, i;
    b->count = b->nvalid = 0;
    for (y = y0; y < y1; ++y)
        for (x = 0; x < view->width; ++x)
            for (s = 0; s < b->spp; ++s) {
                float px = (float)x + ((float)(s % b->strata) + 0.5f) / (float)b->strata;
                float py = (float)y + ((float)(s / b->strata) + 0.5f) / (float)b->strata;
                rad_camera_ray(&view->cam, (uint32_t)view->width, (uint32_t)view->height, px, py, &b->rays[b->count++]);
            }
    nchunks = (int)((b->count + 4095) / 4096);
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 1) reduction(| : failed)
#endif
    for (chunk = 0; chunk < nchunks; ++chunk) {
        uint32_t cb = (uint32_t)chunk * 4096u, ce = cb + 4096u < b->count ? cb + 4096u : b->count;
        if (w->rc.intersect(w->rc.user, b->rays + cb, ce - cb, b->hits + cb) != RAD_SUCCESS) failed |= 1;
    }
    if (failed) return tool_fail("render", "ray intersection", RAD_ERROR_RAYCAST_FAILED);
    for (k = 0; k < b->count; ++k) {
        uint32_t t = b->hits[k].triangle;
        const float *v, *nt;
        if (t == RAD_NONE || t >= scene->triangle_count) {
            size_t pixel = (size_t)y0 * view->width + k / b->spp;
            uint32_t l;
            for (i = 0; i < 3; ++i) img->rgb[3 * pixel + i] += sky[i];
            /* and an environment map its radiance in the ray's direction */
            for (l = 0; l < w->file.light_count; ++l)
                if (w->file.lights[l].type == RAD_LIGHT_ENVIRONMENT) {
                    float rgb[3];
                    rad_environment_radiance(w->file.lights[l].environment, b->rays[k].dir, rgb);
                    for (i = 0; i < 3; ++i) img->rgb[3 * pixel + i] += w->file.lights[l].color[i] * rgb[i];
                }
            b->hits[k].triangle = RAD_NONE;
            continue;
        }
        nt = scene->normals + 3 * (size_t)t;
        if (nt[0] * b->rays[k].dir[0] + nt[1] * b->rays[k].dir[1] + nt[2] * b->rays[k].dir[2] >= 0.0f) {
            b->hits[k].triangle = RAD_NONE; /* back face: patches are one-sided, black */
            continue;
        }
        v = scene->positions + 9 * (size_t)t;
        for (i = 0; i < 3; ++i) {
            b->points[3 * b->nvalid + i] = v[i] + b->hits[k].b1 * (v[3 + i] - v[i]) + b->hits[k].b2 * (v[6 + i] - v[i]);
            b->normals[3 * b->nvalid + i] = nt[i];
        }
        b->valid[b->nvalid++] = k;
    }
    return 0;
}

/* At the valid hits: the direct irradiance D, and H into b->gathered from the final gather,
   the lightmap, or the virtual patches' or hierarchical gather (none: the caller interpolates
   the patches' per-vertex H); the --shading model's direct radiance. 0 or 1 (printed). */
static int batch_light(const tool_world *w, const tool_render_view *view, tool_render_source *src, pixel_batch *b, int y0)
{
    const rad_scene *scene = w->scene;
    rad_direct_options dopt;
    rad_context quiet;
    rad_result r;
    uint32_t k, i, n = b->nvalid;
    double tg = tool_seconds();
    if (n == 0) return 0;
    tool_context(&quiet, NULL);
    rad_direct_options_default(&dopt);
    dopt.exclude_emitters = 0;
    dopt.light_samples = view->light_samples;
    r = rad_direct_irradiance(scene, &w->rc, w->file.lights, w->file.light_count, &dopt, b->points, b->normals, n, b->irr,
                              &quiet);
    if (r != RAD_SUCCESS) return tool_fail("render", "rad_direct_irradiance", r);
    tg = tool_seconds();
    if (view->final_gather) {
        rad_final_gather_options fo;
        rad_final_gather_options_default(&fo);
        fo.rays = view->final_gather;
        fo.seed = (uint32_t)y0 * 0x9E3779B9u;
        r = rad_final_gather(scene, &w->rc, w->file.lights, w->file.light_count, &fo, fg_lookup_fn, src, b->points,
                             b->normals, n, b->gathered, &quiet);
        if (r != RAD_SUCCESS) return tool_fail("render", "rad_final_gather", r);
    } else if (src->lm) {
        for (k = 0; k < n; ++k) {
            const rad_hit *h = &b->hits[b->valid[k]];
            const float *t = scene->lightmap_uvs + 6 * (size_t)h->triangle;
            float u = t[0] + h->b1 * (t[2] - t[0]) + h->b2 * (t[4] - t[0]);
            float v = t[1] + h->b1 * (t[3] - t[1]) + h->b2 * (t[5] - t[1]);
            rad_lightmap_sample(src->lm, 3, src->lm_values, u, v, b->gathered + 3 * k);
        }
    } else if (src->baker) {
        for (k = 0; k < n; ++k) b->vhits[k] = b->hits[b->valid[k]];
        r = rad_baker_irradiance(src->baker, b->vhits, b->points, b->normals, n, b->gathered, &quiet);
        if (r != RAD_SUCCESS) return tool_fail("render", "rad_baker_irradiance", r);
    } else if (b->gathered) {
        r = src->hr ? hr_lookup(src->hr, b->hits, b->valid, n, b->gathered)
                    : rad_vp_gather(src->vp, src->vp_H, b->points, b->normals, n, b->gathered, &quiet);
        if (r != RAD_SUCCESS) {
            src->gather_seconds += tool_seconds() - tg;
            return tool_fail("render", "rad_vp_gather", r);
        }
    }
    if (b->gathered) src->gather_seconds += tool_seconds() - tg;
    if (!b->shaded) return 0;
    for (k = 0; k < n; ++k) {
        const rad_ray *ry = &b->rays[b->valid[k]];
        const rad_hit *h = &b->hits[b->valid[k]];
        float len = sqrtf(ry->dir[0] * ry->dir[0] + ry->dir[1] * ry->dir[1] + ry->dir[2] * ry->dir[2]);
        for (i = 0; i < 3; ++i) b->shade_v[3 * k + i] = -ry->dir[i] / len;
        rad_scene_albedo(scene, h->triangle, h->b1, h->b2, b->shade_a + 3 * k);
    }
    return tool_shade_direct(w, view->shading, view->light_samples, b->points, b->normals, b->shade_v, b->shade_a, n,
                             b->shaded);
}

/* each valid hit's radiance into its pixel: albedo / pi (D + H) (or the shading model's direct
   radiance + albedo / pi H) plus what it emits */
static void batch_accumulate(const tool_world *w, const tool_render_source *src, const pixel_batch *b, int width, int y0,
                             tool_image *img)
{
    const rad_scene *scene = w->scene;
    const rad_patches *P = src->P;
    const float *Hv = src->Hv;
    uint32_t k, i;
    for (k = 0; k < b->nvalid; ++k) {
        uint32_t ray = b->valid[k];
        size_t pixel = (size_t)y0 * width + ray / b->spp;
        const rad_hit *h = &b->hits[ray];
        float albedo[3], wts[3], emitted[3];
        uint32_t p = b->gathered ? 0u : rad_patches_locate(P, h->triangle, h->b1, h->b2, wts);
        const uint32_t *vi;
        if (p == RAD_NONE) continue;
        vi = b->gathered ? NULL : P->patches[p].vertices;
        rad_scene_albedo(scene, h->triangle, h->b1, h->b2, albedo);
        rad_scene_emission(scene, h->triangle, h->b1, h->b2, emitted);
        for (i = 0; i < 3; ++i) {
            float hi = b->gathered ? b->gathered[3 * k + i]
                                   : wts[0] * Hv[3 * (size_t)vi[0] + i] + wts[1] * Hv[3 * (size_t)vi[1] + i] +
                                         wts[2] * Hv[3 * (size_t)vi[2] + i];
            img->rgb[3 * pixel + i] += (b->shaded ? b->shaded[3 * k + i] + albedo[i] / PI_F * hi
                                                  : albedo[i] / PI_F * (b->irr[3 * k + i] + hi)) + emitted[i];
        }
    }
}

/* The image of the radiosity methods: per sample the direct light D at the hit (shadow rays),
   H from src, radiance albedo / pi (D + H) plus emission; each pixel the mean of its samples.
   0 or 1 (printed). */
int tool_render_pixels(const tool_world *w, const tool_render_view *view, tool_render_source *src, tool_image *img)
{
    pixel_batch b;
    size_t total = (size_t)view->width * view->height, done_px = 0, q;
    float sky[3] = {0.0f, 0.0f, 0.0f}, inv;
    uint32_t k, i;
    int y0, result = 0;
    pixel_batch_alloc(&b, view, src);
    /* a camera ray that leaves the scene sees the sky's radiance E_0 / pi, as in rad trace */
    for (k = 0; k < w->file.light_count; ++k)
        if (w->file.lights[k].type == RAD_LIGHT_SKY)
            for (i = 0; i < 3; ++i) sky[i] += w->file.lights[k].color[i] / PI_F;
    for (y0 = 0; y0 < view->height && result == 0; y0 += b.rows) {
        int y1 = y0 + b.rows < view->height ? y0 + b.rows : view->height;
        result = batch_primary(w, view, &b, y0, y1, sky, img);
        if (result == 0) result = batch_light(w, view, src, &b, y0);
        if (result) break;
        batch_accumulate(w, src, &b, view->width, y0, img);
        done_px += (size_t)(y1 - y0) * view->width;
        tool_progress((void *)(size_t)"render", (float)((double)done_px / (double)total));
    }
    tool_progress_end();
    inv = 1.0f / (float)b.spp;
    for (q = 0; q < 3 * total; ++q) img->rgb[q] *= inv;
    pixel_batch_free(&b);
    return result;
}
