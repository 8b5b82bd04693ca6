/* method_bake.c - the bakes of the teaching methods of `rad bake` and `rad render` (multi-bounce
   and temporal from Shcherbakov 2025, ch. 3 and 6, and Shcherbakov et al. 2023, listed in
   docs/references.md; stochastic; hierarchical) and the per-patch indirect light they give;
   their options are methods.c's.

   Both take the direct light as the source, as the classic method does: E = rho D (the patches'
   direct light) and the renderer adds per pixel rho/pi (D + H), H being the irradiance from
   the secondary sources. The classic method computes H = F (E + L_K) with F; these bakes hold
   no F, so H comes from the indirect radiosity itself: L_{K+1} = rho o F (E + L_K), hence
   H = L_{K+1} / rho (per channel; 0 where rho is 0, where the pixel's albedo is 0 as well).
   That is why `--bounces K` builds F_mb with K + 1 bounces: the image is then the classic
   image of `--bounces K` (K = inf: the same full solution). The temporal method in mode
   feedback converges to L_inf (mode single gives L_1, i.e. classic --bounces 0; mode
   multibounce samples the channels of F_mb with K + 1 bounces).

   The environment entry of the alias tables (E_0, the sky's radiosity) is 0 here: the scene's
   sky is part of the per-pixel direct light D and of E already, so adding it again would count
   it twice. The halo correction of the per-vertex H needs the row sums S_i of F, stored in
   the user section "rad.rowsums". */
#include "tool.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- bake ---------------------------------------------------------------------------------- */

/* --method stochastic builds no F, so the row sums S_i = sum_j F_ij (the part of patch i's
   hemisphere that sees a patch's front) are estimated by rays: 64 per patch from stratified
   points in cosine-distributed directions, the fraction that lands on a front face. */
#define SR_ROWSUM_RAYS 64u
static rad_result stochastic_rowsums(const tool_world *w, const rad_patches *P, float *S)
{
    rad_ray rays[SR_ROWSUM_RAYS];
    rad_hit hits[SR_ROWSUM_RAYS];
    const float eps = 1e-5f * w->scene->diagonal;
    uint32_t i, k;
    for (i = 0; i < P->count; ++i) {
        const rad_patch *p = &P->patches[i];
        const float *v0 = P->vertices + 3 * (size_t)p->vertices[0], *v1 = P->vertices + 3 * (size_t)p->vertices[1],
                    *v2 = P->vertices + 3 * (size_t)p->vertices[2], *n = p->normal;
        float t1[3], t2[3], a[3] = {1.0f, 0.0f, 0.0f}, len;
        uint32_t seen = 0;
        if (fabsf(n[0]) > 0.5f) a[0] = 0.0f, a[1] = 1.0f;
        t1[0] = n[1] * a[2] - n[2] * a[1], t1[1] = n[2] * a[0] - n[0] * a[2], t1[2] = n[0] * a[1] - n[1] * a[0];
        len = sqrtf(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
        t1[0] /= len, t1[1] /= len, t1[2] /= len;
        t2[0] = n[1] * t1[2] - n[2] * t1[1], t2[1] = n[2] * t1[0] - n[0] * t1[2], t2[2] = n[0] * t1[1] - n[1] * t1[0];
        for (k = 0; k < SR_ROWSUM_RAYS; ++k) {
            /* point: 8 x 8 strata of the unit square folded onto the triangle; direction:
               another 8 x 8 stratification, the two paired by a fixed shuffle */
            float u1 = ((float)(k % 8u) + 0.5f) / 8.0f, u2 = ((float)(k / 8u) + 0.5f) / 8.0f;
            uint32_t q = (k * 37u + 11u) % SR_ROWSUM_RAYS;
            float d1 = ((float)(q % 8u) + 0.5f) / 8.0f, d2 = ((float)(q / 8u) + 0.5f) / 8.0f;
            float rr = sqrtf(d1), ph = 6.28318530718f * d2, z = sqrtf(1.0f - d1), b1, b2;
            int c;
            if (u1 + u2 > 1.0f) u1 = 1.0f - u1, u2 = 1.0f - u2;
            b1 = u1, b2 = u2;
            for (c = 0; c < 3; ++c) {
                rays[k].origin[c] = v0[c] + b1 * (v1[c] - v0[c]) + b2 * (v2[c] - v0[c]) + n[c] * eps;
                rays[k].dir[c] = t1[c] * rr * cosf(ph) + t2[c] * rr * sinf(ph) + n[c] * z;
            }
            rays[k].tmin = 0.0f;
            rays[k].tmax = 3.0e38f;
        }
        if (w->rc.intersect(w->rc.user, rays, SR_ROWSUM_RAYS, hits) != RAD_SUCCESS) return RAD_ERROR_RAYCAST_FAILED;
        for (k = 0; k < SR_ROWSUM_RAYS; ++k) {
            uint32_t t = hits[k].triangle;
            if (t < w->scene->triangle_count) {
                const float *tn = w->scene->normals + 3 * (size_t)t;
                if (tn[0] * rays[k].dir[0] + tn[1] * rays[k].dir[1] + tn[2] * rays[k].dir[2] < 0.0f) ++seen;
            }
        }
        S[i] = (float)seen / (float)SR_ROWSUM_RAYS;
    }
    return RAD_SUCCESS;
}

static uint32_t mb_bounces(uint32_t bounces)
{
    return bounces == RAD_MB_INFINITE ? RAD_MB_INFINITE : bounces + 1u;
}

/* --hr-eps, or the default for T scene triangles (tool_hierarchical_build says why) */
static double hr_tolerance(const tool_method_options *mo, uint32_t T)
{
    double eps = 1e-7 * (double)T;
    return mo->hr_eps > 0.0f ? (double)mo->hr_eps : eps < 1e-5 ? 1e-5 : eps > 1e-2 ? 1e-2 : eps;
}

/* --method hierarchical baked: the solution's H resampled onto the bake's patches, as the
   stochastic bake's L = rho H (the mean of the leaf values at the patch's centroid and half
   way from it to each corner) */
static rad_result hierarchical_to_patches(const rad_hierarchical *h, const rad_scene *s, const rad_patches *P, float *L)
{
    uint32_t i, q, k;
    for (i = 0; i < P->count; ++i) {
        const rad_patch *pt = &P->patches[i];
        const float *T = s->positions + 9 * (size_t)pt->triangle;
        float ax[3], ay[3], aa, bb, ab, det, bc[8], H[12];
        uint32_t tris[4];
        rad_result r;
        for (k = 0; k < 3; ++k) {
            ax[k] = T[3 + k] - T[k];
            ay[k] = T[6 + k] - T[k];
        }
        aa = ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2];
        bb = ay[0] * ay[0] + ay[1] * ay[1] + ay[2] * ay[2];
        ab = ax[0] * ay[0] + ax[1] * ay[1] + ax[2] * ay[2];
        det = aa * bb - ab * ab;
        for (q = 0; q < 4; ++q) {
            float p[3], pa, pb;
            for (k = 0; k < 3; ++k) {
                p[k] = pt->centroid[k];
                if (q > 0) p[k] = 0.5f * (p[k] + P->vertices[3 * (size_t)pt->vertices[q - 1] + k]);
                p[k] -= T[k];
            }
            pa = p[0] * ax[0] + p[1] * ax[1] + p[2] * ax[2];
            pb = p[0] * ay[0] + p[1] * ay[1] + p[2] * ay[2];
            bc[2 * q] = det > 0.0f ? (pa * bb - pb * ab) / det : 1.0f / 3.0f;
            bc[2 * q + 1] = det > 0.0f ? (pb * aa - pa * ab) / det : 1.0f / 3.0f;
            tris[q] = pt->triangle;
        }
        if ((r = rad_hierarchical_lookup(h, RAD_HIERARCHICAL_GATHERED, 0, tris, bc, 4, H)) != RAD_SUCCESS) return r;
        for (k = 0; k < 3; ++k) L[3 * (size_t)i + k] = pt->albedo[k] * 0.25f * (H[k] + H[3 + k] + H[6 + k] + H[9 + k]);
    }
    return RAD_SUCCESS;
}

/* tool_method_bake's state: what each stage builds, freed together by method_bake_free */
typedef struct method_bake {
    const char *cmd;
    const tool_world *w;
    const tool_method_options *mo;
    tool_classic c;                /* patches, D and E (F unless no_form_factors) */
    uint32_t n;
    float *S;                      /* row sums of F */
    float *L;                      /* stochastic, hierarchical: the solution */
    rad_multibounce *mb;
    rad_multibounce_blocks *blocks;
    rad_alias_tables *tables[3];
    tool_method_info mi;
    size_t bytes;                  /* what the render reads (see tool_method_info) */
    rad_result r;                  /* the failing call's result */
} method_bake;

/* the row sums S of F for the halo correction: F times ones, or by rays without F */
static const char *method_bake_rowsums(method_bake *b, int no_form_factors)
{
    uint32_t i, n = b->n;
    float *ones, *rows3;
    rad_context ctx;
    b->S = (float *)tool_calloc(n, sizeof(float));
    if (no_form_factors) {
        b->r = stochastic_rowsums(b->w, b->c.patches, b->S);
        return b->r != RAD_SUCCESS ? "row sums by rays" : NULL;
    }
    tool_context(&ctx, NULL);
    ones = (float *)tool_calloc(3 * (size_t)n, sizeof(float));
    rows3 = (float *)tool_calloc(3 * (size_t)n, sizeof(float));
    for (i = 0; i < 3 * n; ++i) ones[i] = 1.0f;
    b->r = rad_matrix_multiply(&b->c.ff->matrix, ones, rows3, &ctx);
    for (i = 0; i < n; ++i) b->S[i] = rows3[3 * i];
    free(ones);
    free(rows3);
    return b->r != RAD_SUCCESS ? "rad_matrix_multiply" : NULL;
}

/* the rad.method record of mo (the stages add what they built) */
static void method_bake_record(method_bake *b)
{
    const tool_method_options *mo = b->mo;
    tool_method_info *mi = &b->mi;
    memset(mi, 0, sizeof *mi);
    mi->magic = TOOL_METHOD_MAGIC;
    mi->method = (uint32_t)mo->method;
    mi->bounces = mo->bounces;
    mi->format = mo->format;
    mi->outliers = mo->outliers;
    mi->reorder = mo->reorder == RAD_REORDER_NONE ? 0u : (uint32_t)mo->reorder; /* the record: 0 is no reordering */
    mi->reorder_samples = mo->reorder_samples;
    mi->tile = mo->tile;
    mi->mode = (uint32_t)mo->mode;
    mi->k = mo->k;
    mi->w = mo->w;
    mi->adaptive = (uint32_t)mo->adaptive;
    mi->seed = mo->seed;
    if (mo->method == TOOL_STOCHASTIC) {
        mi->k = mo->sr_rays;
        mi->bounces = mo->sr_iterations;
        mi->mode = mo->sr_estimator;
    }
}

/* F_mb of --bounces K (K + 1 built: the renderer's gather), for multibounce and temporal --mode
   multibounce */
static const char *method_bake_fmb(method_bake *b, double t0)
{
    const tool_method_options *mo = b->mo;
    rad_multibounce_options mbo;
    rad_context ctx;
    rad_multibounce_options_default(&mbo);
    mbo.bounces = mb_bounces(mo->bounces);
    mbo.precision = mo->method == TOOL_MULTIBOUNCE && mo->format == TOOL_MB_HALF ? RAD_MB_HALF : RAD_MB_FLOAT;
    tool_context(&ctx, "F_mb");
    b->r = rad_multibounce_create(&b->c.ff->matrix, b->c.patches->albedo, &mbo, &ctx, &b->mb);
    tool_progress_end();
    if (b->r != RAD_SUCCESS) return "rad_multibounce_create";
    if (mbo.bounces == RAD_MB_INFINITE)
        fprintf(stderr, "rad %s: F_mb (inf bounces, %s) built in %.2f s\n", b->cmd,
                mbo.precision == RAD_MB_HALF ? "half" : "float", tool_seconds() - t0);
    else
        fprintf(stderr, "rad %s: F_mb (%u bounces: --bounces %u and the renderer's gather, %s) built in %.2f s\n",
                b->cmd, mbo.bounces, mo->bounces, mbo.precision == RAD_MB_HALF ? "half" : "float", tool_seconds() - t0);
    return NULL;
}

/* multibounce: F_mb as stored: compressed (bc1, bc4x3) with its error report, or float/half */
static const char *method_bake_store_fmb(method_bake *b)
{
    const tool_method_options *mo = b->mo;
    rad_block_options bo;
    rad_block_report report;
    rad_context ctx;
    double t1 = tool_seconds();
    if (mo->format < TOOL_MB_BC1) {
        b->bytes = (size_t)3 * b->n * b->n * (mo->format == TOOL_MB_HALF ? 2u : 4u);
        fprintf(stderr, "rad %s: F_mb %s: %lu bytes\n", b->cmd, tool_mb_format_name(mo->format), (unsigned long)b->bytes);
        return NULL;
    }
    rad_block_options_default(&bo);
    bo.format = mo->format == TOOL_MB_BC1 ? RAD_BLOCK_BC1 : RAD_BLOCK_BC4X3;
    bo.outlier_fraction = mo->outliers > 0.0f ? mo->outliers : -1.0f; /* --outliers 0: none */
    bo.reorder = mo->reorder;
    bo.reorder_samples = mo->reorder_samples;
    bo.tile = mo->tile ? mo->tile : RAD_BLOCK_WHOLE_MATRIX; /* --tile 0: one scale per matrix */
    memset(&report, 0, sizeof report);
    tool_context(&ctx, "compression");
    b->r = rad_multibounce_blocks_create(b->mb, &bo, &ctx, &b->blocks, &report);
    tool_progress_end();
    if (b->r != RAD_SUCCESS) return "rad_multibounce_blocks_create";
    b->bytes = report.bytes_total;
    b->mi.mse = (float)report.mse;
    b->mi.max_abs_error = (float)report.max_abs_error;
    b->mi.source_mean_square = (float)report.source_mean_square;
    fprintf(stderr,
            "rad %s: compressed to %s in %.2f s: %lu bytes (blocks %lu, scales %lu, %llu outliers %lu, "
            "permutations %lu) vs %lu float F_mb, %.1fx; decoded-matrix RMS error %.3g (%.3g%% of the "
            "RMS entry), max %.3g\n",
            b->cmd, tool_mb_format_name(mo->format), tool_seconds() - t1, (unsigned long)report.bytes_total,
            (unsigned long)report.bytes_blocks, (unsigned long)report.bytes_scales,
            (unsigned long long)report.outlier_count, (unsigned long)report.bytes_outliers,
            (unsigned long)report.bytes_permutations, (unsigned long)report.bytes_float_mb,
            report.bytes_total ? (double)report.bytes_float_mb / (double)report.bytes_total : 0.0, sqrt(report.mse),
            report.source_mean_square > 0.0 ? 100.0 * sqrt(report.mse / report.source_mean_square) : 0.0,
            report.max_abs_error);
    return NULL;
}

/* hierarchical: the solution resampled onto the patches as L = rho H (NULL: done; "": failed,
   printed) */
static const char *method_bake_hierarchical(method_bake *b, uint32_t light_samples)
{
    rad_hierarchical *h = NULL;
    rad_hierarchical_stats st;
    if (tool_hierarchical_build(b->cmd, b->w, b->mo, light_samples, &h)) return "";
    b->L = (float *)tool_calloc(3 * (size_t)b->n, sizeof(float));
    b->r = hierarchical_to_patches(h, b->w->scene, b->c.patches, b->L);
    rad_hierarchical_get_stats(h, &st);
    rad_hierarchical_destroy(h);
    if (b->r != RAD_SUCCESS) return "rad_hierarchical_lookup";
    b->bytes = (size_t)st.links; /* the record's byte count holds the links here */
    b->mi.k = st.leaves;
    b->mi.bounces = st.rounds;
    b->mi.w = (float)hr_tolerance(b->mo, b->w->scene->triangle_count);
    return NULL;
}

static const char *method_bake_stochastic(method_bake *b, double t0)
{
    const tool_method_options *mo = b->mo;
    rad_stochastic_options sto;
    rad_stochastic_stats st;
    rad_context ctx;
    rad_stochastic_options_default(&sto);
    sto.method = (rad_stochastic_method)mo->sr_estimator;
    sto.rays = mo->sr_rays;
    sto.iterations = mo->sr_iterations;
    sto.seed = mo->seed;
    b->L = (float *)tool_calloc(3 * (size_t)b->n, sizeof(float));
    tool_context(&ctx, "stochastic radiosity");
    b->r = rad_solve_stochastic(b->c.patches, &b->w->rc, b->c.E, &sto, b->L, &st, &ctx);
    tool_progress_end();
    if (b->r != RAD_SUCCESS) return "rad_solve_stochastic";
    b->bytes = (size_t)st.rays_cast; /* the record's byte count holds the rays cast here */
    fprintf(stderr, "rad %s: stochastic radiosity (%s) in %.2f s: %u iterations, %llu rays, unshot %.2g\n", b->cmd,
            sto.method == RAD_STOCHASTIC_WALK ? "walk" : "jacobi", tool_seconds() - t0, st.iterations,
            (unsigned long long)st.rays_cast, st.unshot);
    return NULL;
}

/* temporal: alias tables over F's rows, or over F_mb's three channels in --mode multibounce */
static const char *method_bake_alias(method_bake *b, double t0)
{
    uint32_t i, n = b->n;
    uint64_t bins = 0, entries = 0;
    rad_context ctx;
    tool_context(&ctx, "alias tables");
    b->r = RAD_SUCCESS;
    if (b->mo->mode == RAD_TEMPORAL_MULTIBOUNCE) {
        for (i = 0; i < 3 && b->r == RAD_SUCCESS; ++i)
            b->r = rad_alias_tables_create_dense(b->mb->planes + (size_t)i * n * n, n, RAD_ALIAS_AUTO, &ctx, &b->tables[i]);
    } else {
        b->r = rad_alias_tables_create(&b->c.ff->matrix, RAD_ALIAS_AUTO, &ctx, &b->tables[0]);
    }
    tool_progress_end();
    if (b->r != RAD_SUCCESS) return "alias tables";
    for (i = 0; i < 3 && b->tables[i]; ++i) {
        b->bytes += rad_alias_tables_memory(b->tables[i]);
        bins += b->tables[i]->row_offsets[n];
        entries += b->tables[i]->source_entries;
    }
    fprintf(stderr,
            "rad %s: alias tables (%s) built in %.2f s: %llu bins, %lu bytes (%.2f bytes per bin) from a "
            "%llu-entry float matrix (%lu bytes)\n",
            b->cmd, tool_temporal_mode_name(b->mo->mode), tool_seconds() - t0, (unsigned long long)bins, (unsigned long)b->bytes,
            bins ? (double)b->bytes / (double)bins : 0.0, (unsigned long long)entries, (unsigned long)(entries * 4u));
    return NULL;
}

/* the container: patches and E (and D as a vector) from the library's writer, then ours */
static const char *method_bake_write(method_bake *b, const tool_classic_options *o, void **out, size_t *out_size)
{
    const tool_method_options *mo = b->mo;
    tool_bake_info info;
    rad_bake_signature sig;
    rad_container *ct = NULL;
    rad_section *secs = NULL;
    rad_context ctx;
    void *base = NULL, *dst = NULL;
    size_t base_size = 0, dst_size = 0;
    uint32_t i, k = 0, count, n = b->n;
    const char *what = NULL;
    tool_context(&ctx, NULL);
    if ((b->r = rad_save_memory(b->c.patches, NULL, b->c.E, NULL, &ctx, &base, &base_size)) != RAD_SUCCESS) {
        what = "rad_save_memory";
        goto done;
    }
    if ((b->r = rad_container_create(base, base_size, &ctx, &ct)) != RAD_SUCCESS) {
        what = "rad_container_create";
        goto done;
    }
    count = rad_container_section_count(ct);
    secs = (rad_section *)tool_calloc((size_t)count + 4 + 3 * 3 + RAD_MB_MAX_SECTIONS, sizeof(rad_section));
    for (i = 0; i < count; ++i) secs[k++] = *rad_container_section(ct, i);
    memset(&info, 0, sizeof info);
    info.magic = 0x52414442u;
    info.patches = o->patches;
    info.max_edge = o->max_edge;
    info.samples = o->samples;
    info.solver = (uint32_t)o->solver;
    info.bounces = mo->bounces;
    info.light_samples = o->light_samples;
    info.triangle_count = b->w->scene->triangle_count;
    tool_sign_options(secs, k, &info, b->w, &sig);
    secs[k].type = RAD_SECTION_VECTOR, secs[k].elem_size = 12, secs[k].count = n, secs[k].data = b->c.D;
    strcpy(secs[k++].name, "D");
    secs[k].type = TOOL_SECTION_ROWSUMS, secs[k].elem_size = 4, secs[k].count = n, secs[k].data = b->S;
    strcpy(secs[k++].name, "rad.rowsums");
    secs[k].type = TOOL_SECTION_OPTIONS, secs[k].elem_size = sizeof info, secs[k].count = 1, secs[k].data = &info;
    strcpy(secs[k++].name, "rad.options");
    secs[k].type = TOOL_SECTION_METHOD, secs[k].elem_size = sizeof b->mi, secs[k].count = 1, secs[k].data = &b->mi;
    strcpy(secs[k++].name, "rad.method");
    if (mo->method == TOOL_MULTIBOUNCE) {
        uint32_t added = 0;
        b->r = b->blocks ? rad_multibounce_blocks_sections(b->blocks, "Fmb", secs + k, &added)
                         : rad_multibounce_sections(b->mb, "Fmb", secs + k, &added);
        if (b->r != RAD_SUCCESS) {
            what = "multi-bounce sections";
            goto done;
        }
        k += added;
    } else if (mo->method == TOOL_STOCHASTIC || mo->method == TOOL_HIERARCHICAL) {
        secs[k].type = RAD_SECTION_VECTOR, secs[k].elem_size = 12, secs[k].count = n, secs[k].data = b->L;
        strcpy(secs[k++].name, "L");
    } else if (mo->mode == RAD_TEMPORAL_MULTIBOUNCE) {
        static const char *const names[3] = {"Fmb.r", "Fmb.g", "Fmb.b"};
        for (i = 0; i < 3; ++i, k += 3) rad_alias_tables_sections(b->tables[i], names[i], secs + k, NULL);
    } else {
        rad_alias_tables_sections(b->tables[0], "F", secs + k, NULL);
        k += 3;
    }
    if ((b->r = rad_container_size(secs, k, &dst_size)) != RAD_SUCCESS) {
        what = "rad_container_size";
        goto done;
    }
    dst = tool_calloc(dst_size, 1);
    if ((b->r = rad_container_write(secs, k, dst, dst_size)) != RAD_SUCCESS) {
        what = "rad_container_write";
        goto done;
    }
    *out = dst;
    *out_size = dst_size;
    dst = NULL;
done:
    free(dst);
    free(secs);
    rad_container_destroy(ct);
    rad_free_buffer(base, &ctx);
    return what;
}

int tool_method_bake(const char *cmd, const tool_world *w, const tool_classic_options *o,
                         const tool_method_options *mo, void **out, size_t *out_size)
{
    tool_classic_options so = *o;
    method_bake b;
    const char *what = NULL;
    double t0;
    uint32_t i;
    *out = NULL;
    *out_size = 0;
    memset(&b, 0, sizeof b);
    b.cmd = cmd;
    b.w = w;
    b.mo = mo;
    so.sources_only = 1;
    so.no_form_factors = mo->method == TOOL_STOCHASTIC || mo->method == TOOL_HIERARCHICAL;
    if (tool_classic_solve(cmd, w, &so, &b.c)) return 1;
    b.n = b.c.patches->count;
    what = method_bake_rowsums(&b, so.no_form_factors);
    method_bake_record(&b);
    t0 = tool_seconds();
    if (!what && (mo->method == TOOL_MULTIBOUNCE || (mo->method == TOOL_TEMPORAL && mo->mode == RAD_TEMPORAL_MULTIBOUNCE)))
        what = method_bake_fmb(&b, t0);
    if (!what)
        what = mo->method == TOOL_MULTIBOUNCE     ? method_bake_store_fmb(&b)
               : mo->method == TOOL_HIERARCHICAL ? method_bake_hierarchical(&b, o->light_samples)
               : mo->method == TOOL_STOCHASTIC   ? method_bake_stochastic(&b, t0)
                                                 : method_bake_alias(&b, t0);
    b.mi.build_seconds = (float)(tool_seconds() - t0);
    b.mi.bytes_lo = (uint32_t)((uint64_t)b.bytes & 0xFFFFFFFFu);
    b.mi.bytes_hi = (uint32_t)((uint64_t)b.bytes >> 32);
    if (!what) what = method_bake_write(&b, o, out, out_size);
    if (what && *what) tool_fail(cmd, what, b.r);
    for (i = 0; i < 3; ++i) rad_alias_tables_destroy(b.tables[i]);
    rad_multibounce_blocks_destroy(b.blocks);
    rad_multibounce_destroy(b.mb);
    free(b.S);
    free(b.L);
    tool_classic_free(&b.c);
    return what ? 1 : 0;
}

/* ---- render side ---------------------------------------------------------------------------- */

struct tool_indirect {
    const char *cmd;
    tool_method method;
    uint32_t n;
    const float *E, *albedo, *S;
    rad_multibounce *mb;
    rad_multibounce_blocks *blocks;
    rad_alias_tables tables[3];
    rad_temporal *temporal;
    float *L;
    const float *Ls;        /* stochastic: the bake's solution L */
    double solve_seconds;   /* stochastic: the solve's time, the method's per-frame work */
    rad_context ctx;
};

void tool_indirect_close(tool_indirect *m)
{
    if (!m) return;
    rad_temporal_destroy(m->temporal);
    rad_multibounce_blocks_destroy(m->blocks);
    rad_multibounce_destroy(m->mb);
    free(m->L);
    free(m);
}

const float *tool_indirect_rowsums(const tool_indirect *m) { return m->S; }

/* stochastic and hierarchical bakes: their solution L, checked */
static int indirect_open_solution(tool_indirect *m, const rad_container *ct, const char *bake_name,
                                  const tool_method_info *mi, const tool_method_options *mo)
{
    const char *cmd = m->cmd;
    uint32_t n = m->n;
    const rad_section *ls = rad_container_find(ct, RAD_SECTION_VECTOR, "L");
    uint32_t i;
    if (!ls || ls->elem_size != 12 || ls->count != n) {
        fprintf(stderr, "rad %s: bake '%s' holds no solution L for its %u patches (vector section L)\n", cmd, bake_name, n);
        return 1;
    }
    m->Ls = (const float *)ls->data;
    for (i = 0; i < 3 * n; ++i)
        if (!(m->Ls[i] >= 0.0f && m->Ls[i] <= RAD_BAKE_VALUE_MAX)) {
            fprintf(stderr, "rad %s: bake '%s': vector L, value %u is %g (not in [0, 1e30])\n", cmd, bake_name, i,
                    (double)m->Ls[i]);
            return 1;
        }
    m->solve_seconds = mi->build_seconds;
    if (mo->method == TOOL_HIERARCHICAL)
        fprintf(stderr, "rad %s: hierarchical (--hr-eps %g: %u leaves, %llu links, resampled onto %u patches), solved in "
                        "%.3f s\n", cmd, (double)mi->w, mi->k, (unsigned long long)(((uint64_t)mi->bytes_hi << 32) | mi->bytes_lo),
                n, (double)mi->build_seconds);
    else
        fprintf(stderr, "rad %s: stochastic (%s), %u patches, %llu rays, solved in %.3f s\n", cmd,
                mi->mode == RAD_STOCHASTIC_WALK ? "walk" : "jacobi", n,
                (unsigned long long)(((uint64_t)mi->bytes_hi << 32) | mi->bytes_lo), (double)mi->build_seconds);
    return 0;
}

/* multibounce: F_mb (float, half or compressed) */
static int indirect_open_fmb(tool_indirect *m, const rad_container *ct, const char *bake_name,
                                  const tool_method_info *mi, const tool_method_options *mo)
{
    const char *cmd = m->cmd;
    uint32_t n = m->n;
    rad_result r;
    (void)mo;
    const rad_section *is = rad_container_find(ct, RAD_SECTION_MB_INFO, "Fmb");
    uint32_t kind = is && is->elem_size == 4 && is->count == 16 ? ((const uint32_t *)is->data)[1] : 99u;
    if (kind > 3) {
        fprintf(stderr, "rad %s: bake '%s' holds no multi-bounce matrix 'Fmb'\n", cmd, bake_name);
        return 1;
    }
    r = kind >= 2 ? rad_multibounce_blocks_load(ct, "Fmb", &m->ctx, &m->blocks)
                  : rad_multibounce_load(ct, "Fmb", &m->ctx, &m->mb);
    if (r == RAD_SUCCESS && (kind >= 2 ? m->blocks->n : m->mb->n) != n) {
        fprintf(stderr, "rad %s: bake '%s': F_mb is %u x %u for %u patches\n", cmd, bake_name,
                kind >= 2 ? m->blocks->n : m->mb->n, kind >= 2 ? m->blocks->n : m->mb->n, n);
        return 1;
    }
    if (r != RAD_SUCCESS) {
        fprintf(stderr, "rad %s: bake '%s': cannot open its multi-bounce matrix\n", cmd, bake_name);
        return tool_fail(cmd, "rad_multibounce_load", r);
    }
    if (mi->bounces == RAD_MB_INFINITE)
        fprintf(stderr, "rad %s: F_mb %s, bounces inf, %u patches\n", cmd, tool_mb_format_name(kind), n);
    else
        fprintf(stderr, "rad %s: F_mb %s, bounces %u (F_mb holds %u with the gather), %u patches\n", cmd,
                tool_mb_format_name(kind), mi->bounces, mi->bounces + 1u, n);
    return 0;
}

/* temporal: the alias tables and the temporal state, the render's --k, --w, --adaptive and
   --seed over the bake's */
static int indirect_open_temporal(tool_indirect *m, const rad_container *ct, const char *bake_name,
                                  const tool_method_info *mi, const tool_method_options *mo)
{
    const char *cmd = m->cmd;
    uint32_t n = m->n;
    rad_result r;
    static const char *const names[3] = {"Fmb.r", "Fmb.g", "Fmb.b"};
    const rad_alias_tables *tp[3];
    rad_temporal_options to;
    uint32_t tcount = mi->mode == RAD_TEMPORAL_MULTIBOUNCE ? 3u : 1u, i;
    for (i = 0; i < tcount; ++i) {
        const char *name = tcount == 3 ? names[i] : "F";
        if (!rad_container_find(ct, RAD_SECTION_TEMPORAL_BINS, name)) {
            fprintf(stderr, "rad %s: bake '%s' holds no alias tables '%s'\n", cmd, bake_name, name);
            return 1;
        }
        if ((r = rad_alias_tables_view(ct, name, &m->ctx, &m->tables[i])) != RAD_SUCCESS) {
            return tool_fail(cmd, "rad_alias_tables_view", r);
        }
        if (m->tables[i].rows != n) {
            fprintf(stderr, "rad %s: bake '%s': alias tables '%s' have %u rows for %u patches\n", cmd, bake_name,
                    name, m->tables[i].rows, n);
            return 1;
        }
        tp[i] = &m->tables[i];
    }
    rad_temporal_options_default(&to);
    to.mode = (rad_temporal_mode)mi->mode;
    to.samples = (mo->given & TOOL_OPT_K) ? mo->k : mi->k;
    to.adaptive = (mo->given & TOOL_OPT_ADAPTIVE) ? 1 : (mo->given & TOOL_OPT_W) ? 0 : (int)mi->adaptive;
    to.weight = (mo->given & TOOL_OPT_W) ? mo->w : mi->w;
    if (to.weight == 0.0f) to.weight = -1.0f; /* --w 0: no history (a weight of 0 is the default) */
    to.seed = (mo->given & TOOL_OPT_SEED) ? mo->seed : mi->seed;
    if ((r = rad_temporal_create(tp, tcount, m->albedo, &to, &m->ctx, &m->temporal)) != RAD_SUCCESS) {
        return tool_fail(cmd, "rad_temporal_create", r);
    }
    fprintf(stderr, "rad %s: temporal, mode %s, k %u, %s%.4g, seed %u, %u patches\n", cmd, tool_temporal_mode_name(mi->mode),
            to.samples, to.adaptive ? "adaptive w, max " : "w ", (double)(to.adaptive ? to.weight_max : to.weight),
            to.seed, n);
    return 0;
}

int tool_indirect_open(const char *cmd, const char *bake_name, const rad_bake *bake,
                           const tool_method_options *mo, tool_indirect **out)
{
    const rad_container *ct = bake->container;
    const rad_section *s;
    tool_method_info mi;
    tool_indirect *m;
    int r;
    uint32_t n = bake->patches.count;
    const char *mname = tool_method_name(mo->method);
    *out = NULL;
    s = rad_container_find(ct, TOOL_SECTION_METHOD, "rad.method");
    if (!s || s->elem_size != sizeof mi || s->count != 1) {
        fprintf(stderr, "rad %s: bake '%s' holds no %s data (no rad.method section: bake it with --method %s)\n", cmd,
                bake_name, mname, mname);
        return 1;
    }
    memcpy(&mi, s->data, sizeof mi);
    if (mi.magic != TOOL_METHOD_MAGIC) {
        fprintf(stderr, "rad %s: bake '%s' has a damaged rad.method section\n", cmd, bake_name);
        return 1;
    }
    if (mi.method != (uint32_t)mo->method) {
        fprintf(stderr, "rad %s: bake '%s' was made with --method %s, not %s\n", cmd, bake_name,
                tool_method_name((tool_method)mi.method), mname);
        return 1;
    }
    if (!bake->E) {
        fprintf(stderr, "rad %s: bake '%s' holds no source vector E\n", cmd, bake_name);
        return 1;
    }
    s = rad_container_find(ct, TOOL_SECTION_ROWSUMS, "rad.rowsums");
    if (!s || s->elem_size != 4 || s->count != n) {
        fprintf(stderr, "rad %s: bake '%s' holds no row sums of F for its %u patches (section rad.rowsums)\n", cmd,
                bake_name, n);
        return 1;
    }
    /* the values this file hands out are checked once here, as the library's loaders check theirs */
    {
        const float *S = (const float *)s->data;
        uint32_t i;
        for (i = 0; i < n; ++i)
            if (!(S[i] >= 0.0f && S[i] <= RAD_BAKE_VALUE_MAX)) {
                fprintf(stderr, "rad %s: bake '%s': section rad.rowsums, entry %u is %g (not in [0, 1e30])\n", cmd, bake_name,
                        i, (double)S[i]);
                return 1;
            }
    }
    if (mo->method == TOOL_TEMPORAL && !(mo->given & TOOL_OPT_K) && (mi.k == 0 || mi.k > RAD_TEMPORAL_MAX_SAMPLES)) {
        fprintf(stderr, "rad %s: bake '%s': section rad.method has k = %u draws per row (1 to %u, as --k)\n", cmd, bake_name,
                mi.k, RAD_TEMPORAL_MAX_SAMPLES);
        return 1;
    }
    m = (tool_indirect *)tool_calloc(1, sizeof *m);
    m->cmd = cmd;
    m->method = mo->method;
    m->n = n;
    m->E = bake->E;
    m->albedo = bake->patches.albedo;
    m->S = (const float *)s->data;
    m->L = (float *)tool_calloc(3 * (size_t)n, sizeof(float));
    tool_context(&m->ctx, NULL);
    if (mo->method == TOOL_STOCHASTIC || mo->method == TOOL_HIERARCHICAL) r = indirect_open_solution(m, ct, bake_name, &mi, mo);
    else if (mo->method == TOOL_MULTIBOUNCE) r = indirect_open_fmb(m, ct, bake_name, &mi, mo);
    else r = indirect_open_temporal(m, ct, bake_name, &mi, mo);
    if (r) {
        tool_indirect_close(m);
        return 1;
    }
    *out = m;
    return 0;
}

int tool_indirect_step(tool_indirect *m, float *H, double *seconds)
{
    rad_result r;
    uint32_t i;
    double t0 = tool_seconds();
    const float *L = m->L;
    if (m->Ls) { /* solved at bake time: its time is the solve's */
        for (i = 0; i < 3 * m->n; ++i) H[i] = m->albedo[i] > 0.0f ? m->Ls[i] / m->albedo[i] : 0.0f;
        *seconds = m->solve_seconds;
        return 0;
    }
    if (m->blocks) r = rad_multibounce_blocks_apply(m->blocks, m->E, m->L, RAD_OUTPUT_INDIRECT, &m->ctx);
    else if (m->mb) r = rad_multibounce_apply(m->mb, m->E, m->L, RAD_OUTPUT_INDIRECT, &m->ctx);
    else {
        r = rad_temporal_step(m->temporal, m->E, NULL, NULL);
        L = rad_temporal_indirect(m->temporal);
    }
    *seconds = tool_seconds() - t0;
    if (r != RAD_SUCCESS)
        return tool_fail(m->cmd, m->temporal ? "rad_temporal_step" : "multi-bounce apply", r);
    /* H = L_{K+1} / rho (see the top of this file) */
    for (i = 0; i < 3 * m->n; ++i) H[i] = m->albedo[i] > 0.0f ? L[i] / m->albedo[i] : 0.0f;
    return 0;
}

/* ---- hierarchical (render only) ------------------------------------------------------------ */

typedef struct hr_source_data {
    const tool_world *w;
    rad_direct_options dopt;
} hr_source_data;

/* E = rho D at the elements' centroids (RAD_SOURCE_DIRECT, as the classic patches) */
static rad_result hr_source(void *user, const float *points, const float *normals, const uint32_t *triangles,
                            const float *albedos, uint32_t count, float *out_E)
{
    const hr_source_data *d = (const hr_source_data *)user;
    rad_context quiet;
    rad_result r;
    uint32_t i;
    (void)triangles;
    tool_context(&quiet, NULL);
    r = rad_direct_irradiance(d->w->scene, &d->w->rc, d->w->file.lights, d->w->file.light_count, &d->dopt, points,
                              normals, count, out_E, &quiet);
    if (r == RAD_SUCCESS)
        for (i = 0; i < 3 * count; ++i) out_E[i] *= albedos[i];
    return r;
}

int tool_hierarchical_build(const char *cmd, const tool_world *w, const tool_method_options *mo,
                                uint32_t light_samples, rad_hierarchical **out)
{
    rad_hierarchical_options ho;
    rad_hierarchical_stats st;
    hr_source_data sd;
    rad_context ctx;
    rad_result r;
    double t0 = tool_seconds();
    *out = NULL;
    rad_hierarchical_options_default(&ho);
    /* finer than the library's teaching default on small scenes: a still image as close to the
       path tracer as classic's at a small part of its rays (docs/performance-notes.md,
       hierarchical radiosity); the links grow with the triangles at one tolerance, so a large
       scene takes a coarser one (1e-7 per triangle, 1e-5 to 1e-2) and one ray per link, which
       keeps 10^5 triangles and more to minutes and under 1 GiB */
    ho.tolerance = hr_tolerance(mo, w->scene->triangle_count);
    if (mo->hr_rays) ho.visibility_rays = mo->hr_rays;
    else if (w->scene->triangle_count >= 100000u) ho.visibility_rays = 1;
    ho.min_area = mo->hr_min_area;
    /* a large scene at a fine tolerance refines coarser once its elements and links reach
       1.5 GiB instead of growing until the machine runs out */
    ho.memory_limit = (uint64_t)1536u << 20;
    sd.w = w;
    rad_direct_options_default(&sd.dopt);
    sd.dopt.exclude_emitters = 0;
    sd.dopt.light_samples = light_samples;
    ho.source = hr_source;
    ho.source_user = &sd;
    tool_context(&ctx, NULL);
    if ((r = rad_hierarchical_create(w->scene, &w->rc, &ho, &ctx, out)) != RAD_SUCCESS)
        return tool_fail(cmd, "rad_hierarchical_create", r);
    tool_context(&ctx, "hierarchical");
    r = rad_hierarchical_solve(*out, &ctx);
    tool_progress_end();
    if (r != RAD_SUCCESS) {
        rad_hierarchical_destroy(*out);
        *out = NULL;
        return tool_fail(cmd, "rad_hierarchical_solve", r);
    }
    rad_hierarchical_get_stats(*out, &st);
    fprintf(stderr, "rad %s: hierarchical: %u triangles, %u elements, %u leaves, %llu links, %llu kernel evaluations, "
                    "%llu rays, %u rounds, %u sweeps, %.0f MiB of elements and links%s in %.2f s\n",
            cmd, w->scene->triangle_count, st.elements, st.leaves, (unsigned long long)st.links,
            (unsigned long long)st.kernel_evaluations, (unsigned long long)st.rays_cast, st.rounds, st.sweeps,
            (double)st.peak_bytes / 1048576.0, st.memory_limited ? " (memory limit reached: refined coarser)" : "",
            tool_seconds() - t0);
    return 0;
}
