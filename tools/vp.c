/* vp.c - virtual patches for the commands that share them (render, lightmap, probes, info):
   the finest resolution within a patch budget, a virtual-patch bake read back, and the proxy
   solve (E at the samples, Jacobi bounces, H = F (E + L)) of rad lightmap and rad probes. */
#include "tool.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
    *E_out = (float *)tool_calloc(3 * (size_t)vp->count, sizeof(float));
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

int tool_vp_proxy_solve(const char *cmd, const tool_world *w, const tool_classic_options *co, const tool_lightmap_proxy *px,
                        rad_virtual_patches **vp_out, float **B_out, float **H_out, double *solve_seconds)
{
    rad_vp_options vo;
    rad_direct_options dopt;
    rad_solve_options so;
    rad_system sys;
    rad_context ctx;
    rad_result r;
    rad_virtual_patches *vp = NULL;
    float *E, *L, *H = NULL;
    uint32_t n, i;
    double t0 = tool_seconds();
    *vp_out = NULL;
    if (B_out) *B_out = NULL;
    if (H_out) *H_out = NULL;
    rad_vp_options_default(&vo);
    if (px->resolution) vo.resolution = px->resolution;
    if (px->face_points) vo.face_points = px->face_points;
    if (px->kind == TOOL_PROXY_VP) vo.kind = RAD_VP_CLUSTERED;
    if (px->max_patches && tool_vp_resolution_within(cmd, w, vo.kind, vo.face_points, px->max_patches, 0, &vo.resolution))
        return 1;
    /* CSR rows: O(non-zeros), as rad render --proxy keeps them */
    vo.storage = RAD_STORAGE_SPARSE;
    tool_context(&ctx, "virtual patches");
    r = rad_vp_create(w->scene, &w->rc, &vo, &ctx, &vp);
    tool_progress_end();
    if (r != RAD_SUCCESS) return tool_fail(cmd, "rad_vp_create", r);
    n = vp->count;
    fprintf(stderr, "rad %s: %s virtual patches at resolution %u: %u patches, %u voxels, %u samples, %.1f MiB, built in %.2f s\n",
            cmd, px->kind == TOOL_PROXY_VP ? "vp" : "aavp", vo.resolution, n, vp->voxel_count, vp->sample_count,
            (double)rad_vp_memory(vp) / 1048576.0, tool_seconds() - t0);
    E = (float *)tool_calloc(3 * (size_t)n, sizeof(float));
    L = (float *)tool_calloc(3 * (size_t)n, sizeof(float));
    rad_direct_options_default(&dopt);
    dopt.exclude_emitters = 0;
    dopt.light_samples = co->light_samples;
    tool_context(&ctx, "direct light");
    r = rad_vp_sources(vp, &w->rc, w->file.lights, w->file.light_count, &dopt, RAD_SOURCE_DIRECT, E, &ctx);
    tool_progress_end();
    if (r != RAD_SUCCESS) { tool_fail(cmd, "rad_vp_sources", r); goto fail; }
    t0 = tool_seconds();
    rad_vp_system(&sys, vp, E);
    rad_solve_options_default(&so);
    so.output = RAD_OUTPUT_INDIRECT;
    so.bounces = co->bounces;
    tool_context(&ctx, NULL);
    if (co->solver == TOOL_GAUSS_SEIDEL) {
        r = rad_solve_gauss_seidel(&sys, &so, L, NULL, &ctx);
        if (r == RAD_ERROR_NOT_CONVERGED) {
            fprintf(stderr, "rad %s: warning: Gauss-Seidel did not converge\n", cmd);
            r = RAD_SUCCESS;
        }
    } else if (co->bounces) {
        r = rad_solve_jacobi(&sys, &so, L, NULL, &ctx);
    } else {
        memset(L, 0, sizeof(float) * 3 * (size_t)vp->count); /* --bounces 0: no indirect light */
        r = RAD_SUCCESS;
    }
    if (r != RAD_SUCCESS) { tool_fail(cmd, "solve", r); goto fail; }
    for (i = 0; i < 3 * n; ++i) L[i] += E[i];
    if (H_out) {
        H = (float *)tool_calloc(3 * (size_t)n, sizeof(float));
        if ((r = rad_matrix_multiply(&vp->matrix, L, H, &ctx)) != RAD_SUCCESS) { tool_fail(cmd, "rad_matrix_multiply", r); goto fail; }
    }
    if (solve_seconds) *solve_seconds = tool_seconds() - t0;
    free(E);
    if (B_out) *B_out = L; else free(L);
    if (H_out) *H_out = H;
    *vp_out = vp;
    return 0;
fail:
    free(E);
    free(L);
    free(H);
    rad_vp_destroy(vp);
    return 1;
}

int tool_vp_proxy_options(const char *cmd, const tool_world *w, const tool_classic_options *co, const tool_lightmap_proxy *px,
                          rad_baker_options *bo, uint32_t *resolution)
{
    rad_vp_options vo;
    rad_vp_options_default(&vo);
    if (px->face_points) vo.face_points = px->face_points;
    if (px->resolution) vo.resolution = px->resolution;
    bo->vp_kind = px->kind == TOOL_PROXY_VP ? RAD_VP_CLUSTERED : RAD_VP_AXIS_ALIGNED;
    bo->vp_face_points = vo.face_points;
    bo->keep = 1;
    if (co->solver == TOOL_GAUSS_SEIDEL) bo->solver = RAD_BAKER_SOLVE_GAUSS_SEIDEL;
    *resolution = vo.resolution;
    return px->max_patches && tool_vp_resolution_within(cmd, w, bo->vp_kind, vo.face_points, px->max_patches, 0, resolution);
}
