/* cmd_render.c - `rad render`: the command line, the camera, the method (the library's plan
   when none is given) and the image written. The engine tier bakes the production methods
   (classic and virtual patches, rad_baker_run) and the pixels read its solution
   (rad_baker_irradiance); pixels.c draws every radiosity image; render_methods.c holds the
   teaching methods step by step over the method-level calls (multibounce, temporal,
   stochastic, hierarchical, local, --bake files); lightmap.c the lightmap bake.

   Classic and virtual patches in memory (render_baked): the engine tier's bake with the
   command line's --solver, --bounces (0: none, inf: Gauss-Seidel), --max-edge and
   --face-points, its H read at each sample by rad_baker_irradiance. Virtual patches
   (Shcherbakov 2025, ch. 5; vp: RAD_VP_CLUSTERED, aavp: RAD_VP_AXIS_ALIGNED) at --vp-resolution
   or at the finest resolution within --vp-max-patches; from --bake or under --proxy
   render_vp_method: E of the bake or rad_vp_sources, the same solve or the proxy's method,
   H = F (E + L) per patch, gathered at each sample's hit point (rad_vp_gather per batch).

   Every radiosity method prints one line for scripts (tools/report.sh) on stderr:
   "rad render: timing: method=M patches=N frames=F [bounces=K ]step_ms_median=X step_ms_min=Y",
   the method's own per-frame work: the engine tier's whole bake (classic, vp and aavp in
   memory; plus resolution), the solve of a --bake file (K Jacobi bounces), one F_mb E product
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
        steps = (double *)tool_malloc(sizeof(double) * mo->frames);
        for (f = 0; f < mo->frames; ++f) {
            double ts = tool_seconds();
            if ((r = rad_temporal_step(tp, E, NULL, NULL)) != RAD_SUCCESS) { what = "rad_temporal_step"; goto done; }
            steps[f] = tool_seconds() - ts;
        }
        memcpy(L, rad_temporal_indirect(tp), sizeof(float) * 3 * (size_t)n);
        qsort(steps, mo->frames, sizeof(double), tool_cmp_double);
        *step_seconds = steps[mo->frames / 2];
        fprintf(stderr, "rad %s: temporal over %u virtual patches: %u frames, k %u, tables %.1f MiB, step %.3f ms (median)\n",
                cmd, n, mo->frames, mo->k, (double)(rad_alias_tables_memory(tables[0]) * count) / 1048576.0,
                1e3 * *step_seconds);
    } else if (mo->method == TOOL_LOCAL) {
        rad_row_source src;
        rad_local_options lo;
        uint32_t m = mo->local_m ? mo->local_m : (n < TOOL_LOCAL_M_AUTO_MAX ? n : TOOL_LOCAL_M_AUTO_MAX);
        proxy_near *d2 = (proxy_near *)tool_malloc(sizeof(proxy_near) * (size_t)n);
        if (m > n) m = n;
        order = (uint32_t *)tool_malloc(sizeof(uint32_t) * (size_t)n);
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
static int proxy_temporal_frames(const char *cmd, const tool_world *w, const tool_render_args *ra,
                                 const rad_virtual_patches *vp, float *E, float *L, double *step_seconds)
{
    const tool_method_options *mo = &ra->mo;
    int width = ra->view.width, height = ra->view.height;
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
    double *te = (double *)tool_malloc(sizeof(double) * frames), *ts = (double *)tool_malloc(sizeof(double) * frames);
    float *B = (float *)tool_malloc(sizeof(float) * 3 * (size_t)n), *H = (float *)tool_malloc(sizeof(float) * 3 * (size_t)n);
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
    lo.direct.light_samples = ra->o.light_samples; /* as rad_vp_sources got them for the still image */
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
            tool_render_source src;
            memset(&frame, 0, sizeof frame);
            for (i = 0; i < 3 * n; ++i) B[i] = E[i] + L[i];
            if ((r = rad_matrix_multiply(&vp->matrix, B, H, &ctx)) != RAD_SUCCESS) { what = "rad_matrix_multiply"; goto done; }
            snprintf(path, sizeof path, "%s/frame_%05u.png", mo->sequence, f);
            if (tool_image_alloc(&frame, width, height) != 0) {
                fprintf(stderr, "rad %s: out of memory for a %dx%d image\n", cmd, width, height);
                rc = 1;
                goto done;
            }
            memset(&src, 0, sizeof src);
            src.vp = vp;
            src.vp_H = H;
            rc = tool_render_pixels(w, &ra->view, &src, &frame);
            if (rc == 0 && tool_image_write_png(path, &frame, ra->view.exposure) != 0) {
                fprintf(stderr, "rad %s: %s\n", cmd, tool_output_error());
                rc = 1;
            }
            tool_image_free(&frame);
            if (rc) goto done;
        }
    }
    qsort(te, frames, sizeof(double), tool_cmp_double);
    qsort(ts, frames, sizeof(double), tool_cmp_double);
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

/* --bake FILE with --method aavp|vp: tool_vp_bake_open, then checked against the scene's
   signature, the options record and the kind asked for */
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

/* --method vp|aavp: virtual patches, E at their samples, the classic solve on
   their matrix (Jacobi K bounces; inf: Gauss-Seidel), H = F (E + L) per patch, and the
   classic per-pixel render with H gathered at each sample's hit point. */
static int render_vp_method(const char *cmd, const tool_world *w, const tool_render_args *ra, tool_image *img)
{
    const char *bake_path = ra->bake;
    const tool_classic_options *o = &ra->o;
    const tool_method_options *mo = &ra->mo;
    rad_virtual_patches *vp = NULL;
    tool_render_source src;
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
    if (!E) E = (float *)tool_malloc(sizeof(float) * 3 * (size_t)n);
    L = (float *)tool_malloc(sizeof(float) * 3 * (size_t)n);
    B = (float *)tool_malloc(sizeof(float) * 3 * (size_t)n);
    H = (float *)tool_malloc(sizeof(float) * 3 * (size_t)n);
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
            if (proxy_temporal_frames(cmd, w, ra, vp, E, L, &t_step)) rc = 1;
        } else if (mo->proxy) {
            r = RAD_SUCCESS;
            if (proxy_indirect(cmd, vp, E, mo, &ra->view.cam, L, &t_step)) rc = 1;
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
        memset(&src, 0, sizeof src);
        src.vp = vp;
        src.vp_H = H;
        t0 = tool_seconds();
        rc = tool_render_pixels(w, &ra->view, &src, img);
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
                    1e3 * t_step, 1e3 * t_step, 1e3 * t_build, 1e3 * t_E, 1e3 * src.gather_seconds,
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

/* No --method (and no --bake): the library's plan picks classic or AAVP and the resolution
   from the scene and the budget (rad_baker_plan), and says so before the work. A
   virtual-patch method (or proxy) without --vp-resolution or --vp-max-patches takes the
   plan's resolution the same way. */
static int render_default_method(const char *cmd, const tool_world *w, const tool_classic_options *o,
                                 tool_method_options *mo, float voxels_per_path)
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
    bo.vp_voxels_per_path = voxels_per_path;
    /* count the kind that will be built: a clustered set has more patches at one resolution */
    bo.vp_kind = !chosen && (mo->method == TOOL_VP || mo->proxy == TOOL_PROXY_VP) ? RAD_VP_CLUSTERED : RAD_VP_AXIS_ALIGNED;
    bo.vp_face_points = mo->face_points; /* and with the face points it will be built with */
    tool_context(&ctx, NULL);
    if ((r = rad_baker_plan(w->scene, &w->rc, &bo, &ctx, &plan)) != RAD_SUCCESS) return tool_fail(cmd, "rad_baker_plan", r);
    if (plan.method == RAD_BAKER_VIRTUAL_PATCHES) {
        /* The virtual patches' CPU follows the scene's size: 4 minutes per 100 000 triangles
           (at least ten seconds; Sponza's resolutions fit), so that a small scene whose mean
           free path asks for a fine set (touching objects, thousands of emitting triangles)
           is not baked for minutes; the library's 10 minutes above still decide between
           classic and virtual patches. */
        double size_budget = 240.0 * (double)w->scene->triangle_count / 1e5;
        if (size_budget < 10.0) size_budget = 10.0;
        if (plan.estimated_seconds > size_budget) {
            bo.method = RAD_BAKER_VIRTUAL_PATCHES;
            bo.max_seconds = size_budget;
            if ((r = rad_baker_plan(w->scene, &w->rc, &bo, &ctx, &plan)) != RAD_SUCCESS) return tool_fail(cmd, "rad_baker_plan", r);
        }
    }
    if (plan.method == RAD_BAKER_VIRTUAL_PATCHES) {
        if (chosen) mo->method = TOOL_AAVP;
        mo->vp_resolution = plan.vp_resolution;
    }
    if (!chosen)
        fprintf(stderr, "rad %s: no --vp-resolution given: resolution %u from the scene (%u %s patches, about %.0f MiB and "
                "%.0f s of CPU for the bake)\n",
                cmd, plan.vp_resolution, plan.patch_count, bo.vp_kind == RAD_VP_CLUSTERED ? "vp" : "aavp",
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
    rq.proxy = ra->mo.proxy ? &px : NULL;
    if (ra->given & TOOL_RENDER_GIVEN_FINAL_GATHER) rq.final_gather = ra->view.final_gather;
    if (tool_lightmap_bake(cmd, w, &ra->o, &rq, &bk)) return 1;
    fprintf(stderr, "rad %s: timing: method=lightmap%s patches=%u frames=1 bounces=%u step_ms_median=%.6f "
                    "step_ms_min=%.6f\n",
            cmd, ra->mo.proxy == TOOL_PROXY_VP ? " proxy=vp" : ra->mo.proxy ? " proxy=aavp" : "", bk.patches,
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

/* --bake of the classic method: the bake checked against the scene, and its H (stored, or
   F B); *bake_out and *H_owned (NULL when the bake holds H) to free. 0 or 1 (printed). */
static int classic_bake_open(const char *cmd, const tool_world *w, const char *bake_path, rad_bake **bake_out,
                             const float **H, float **H_owned)
{
    rad_bake *bake = NULL;
    const rad_section *hs;
    rad_context ctx;
    rad_result r;
    int rc;
    *bake_out = NULL;
    *H_owned = NULL;
    tool_context(&ctx, NULL);
    if ((r = rad_load_file(bake_path, &ctx, &bake)) != RAD_SUCCESS) {
        tool_bake_load_failed(cmd, bake_path, r);
        return 1;
    }
    rc = tool_bake_fits_scene(cmd, bake_path, bake, w);
    if (rc == 0 && (bake->F.rows == 0 || !bake->B)) {
        fprintf(stderr, "rad %s: bake '%s' holds no form factors or no solution B%s\n", cmd, bake_path,
                rad_container_find(bake->container, TOOL_SECTION_METHOD, "rad.method")
                    ? " (it is a multibounce or temporal bake: render it with that --method)"
                    : "");
        rc = 1;
    }
    if (rc) {
        rad_bake_destroy(bake);
        return 1;
    }
    bake->patches.scene = w->scene;
    hs = rad_container_find(bake->container, RAD_SECTION_VECTOR, "H");
    if (hs && hs->elem_size == 12 && hs->count == bake->patches.count) {
        *H = (const float *)hs->data;
    } else {
        /* H = F (E + L) = F B */
        *H_owned = (float *)tool_malloc(sizeof(float) * 3 * bake->patches.count);
        if ((r = rad_matrix_multiply(&bake->F, bake->B, *H_owned, &ctx)) != RAD_SUCCESS) {
            free(*H_owned);
            *H_owned = NULL;
            rad_bake_destroy(bake);
            return tool_fail(cmd, "rad_matrix_multiply", r);
        }
        *H = *H_owned;
    }
    fprintf(stderr, "rad %s: bake '%s': %u patches\n", cmd, bake_path, bake->patches.count);
    *bake_out = bake;
    return 0;
}

/* --method classic --bake: the bake's solution, per-vertex H, the classic render */
static int render_classic_method(const char *cmd, const tool_world *w, const tool_render_args *ra, tool_image *img)
{
    rad_bake *bake = NULL;
    const float *H = NULL;
    float *Hv, *Hmine = NULL;
    tool_render_source src;
    int rc;
    if (classic_bake_open(cmd, w, ra->bake, &bake, &H, &Hmine)) return 1;
    Hv = (float *)tool_malloc(sizeof(float) * 3 * (size_t)bake->patches.vertex_count);
    rc = tool_vertex_H(&bake->patches, &bake->F, H, Hv);
    memset(&src, 0, sizeof src);
    src.P = &bake->patches;
    src.Hv = Hv;
    if (rc == 0) rc = tool_render_pixels(w, &ra->view, &src, img);
    free(Hv);
    free(Hmine);
    rad_bake_destroy(bake);
    return rc;
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
                                                      : render_vp_method(cmd, w, ra, img);
    /* hierarchical here: from a bake (resampled onto its patches) */
    if (mo->method == TOOL_MULTIBOUNCE || mo->method == TOOL_TEMPORAL || mo->method == TOOL_STOCHASTIC ||
        mo->method == TOOL_HIERARCHICAL)
        return tool_render_with_method(cmd, w, ra, img);
    if (mo->method == TOOL_PATHTRACE) return render_pathtrace(cmd, w, ra, img);
    return render_classic_method(cmd, w, ra, img);
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
