/* render_methods.c - `rad render`'s teaching methods, each step by step over the method-level
   calls of the library (the engine tier bakes the production methods: cmd_render.c), and the
   renders of `rad bake` files. Every image is drawn by tool_render_pixels (pixels.c).

   Multibounce and temporal (tool_render_with_method, render_method): the patches' H from
   methods.c (L = F_mb E, or the temporal frames, H = L / rho) and the halo correction from
   the bake's row sums of F; a stochastic solve and a hierarchical bake read the same way.

   Local (tool_render_local_method; Shcherbakov 2025, ch. 4, in docs/references.md): the
   classic patches, F and E; a rad_local of capacity --local-m M (default: every patch, up to
   TOOL_LOCAL_M_AUTO_MAX) filled with the M patches nearest the camera (rad_local_nearest, one
   rad_local_rebuild), L = T E over P_Vis x P_Lit (rad_local_visible, rad_local_lit), H = L /
   rho and the classic render; patches outside the set or not visible get no indirect light.

   Hierarchical (tool_render_hr_method): the quadtrees and links (method_bake.c), H looked up
   per sample.

   Virtual patches from a --bake file or under a --proxy (tool_render_vp_method; Shcherbakov
   2025, ch. 5): E of the bake or rad_vp_sources, Jacobi --bounces K (inf: Gauss-Seidel) or the
   proxy's method (multibounce, temporal and its frames), H = F (E + L) per patch, gathered at
   each sample's hit point (rad_vp_gather per batch). Classic from a --bake file
   (tool_render_classic_bake): its H (stored, or F B) smoothed to the patch vertices. */
#include "tool.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#if defined(__unix__) || defined(__APPLE__)
#include <sys/resource.h> /* getrusage: peak memory in the vp timing line */
#include <sys/stat.h> /* mkdir for --sequence */
#endif

/* the bake's options section, or NULL */
static const tool_bake_info *tool_bake_info_of(const rad_bake *bake)
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
int tool_bake_fits_scene(const char *cmd, const char *bake_path, const rad_bake *bake, const tool_world *w)
{
    const tool_bake_info *info = tool_bake_info_of(bake);
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
                         const tool_render_args *ra, tool_image *img)
{
    const tool_method_options *mo = &ra->mo;
    const tool_render_view *view = &ra->view;
    int width = view->width, height = view->height;
    float exposure = view->exposure;
    tool_indirect *m = NULL;
    const rad_patches *P = &bake->patches;
    tool_render_source src;
    uint32_t frames = mo->method == TOOL_TEMPORAL ? mo->frames : 1u, f;
    /* multibounce: the product is repeated (same result each time) so its time is a median */
    uint32_t reps = mo->method == TOOL_TEMPORAL ? frames : 9u;
    double t = 0.0, sum = 0.0, tmin = 1e300, tmax = 0.0, *times;
    float *H, *Hv;
    int rc = 0;
    if (tool_indirect_open(cmd, bake_name, bake, mo, &m)) return 1;
    times = (double *)tool_malloc(sizeof(double) * reps);
    H = (float *)tool_malloc(sizeof(float) * 3 * (size_t)P->count);
    Hv = (float *)tool_malloc(sizeof(float) * 3 * (size_t)P->vertex_count);
    memset(&src, 0, sizeof src);
    src.P = P;
    src.Hv = Hv;
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
            if (rc == 0) rc = tool_vertex_H_rowsums(P, tool_indirect_rowsums(m), H, Hv);
            if (rc == 0) rc = tool_render_pixels(w, view, &src, &frame);
            if (rc == 0 && tool_image_write_png(path, &frame, exposure) != 0) {
                fprintf(stderr, "rad %s: %s\n", cmd, tool_output_error());
                rc = 1;
            }
            tool_image_free(&frame);
        }
    }
    for (f = frames + 1; f <= reps && rc == 0; ++f) rc = tool_indirect_step(m, H, &times[f - 1]);
    if (rc == 0) {
        qsort(times, reps, sizeof(double), tool_cmp_double);
        /* one line for scripts (tools/report.sh): the method's per-frame work alone */
        fprintf(stderr, "rad %s: timing: method=%s patches=%u frames=%u step_ms_median=%.6f step_ms_min=%.6f\n", cmd,
                tool_method_name(mo->method), P->count, reps, 1e3 * times[reps / 2], 1e3 * times[0]);
        if (mo->method == TOOL_TEMPORAL)
            fprintf(stderr, "rad %s: %u frames, temporal step %.3f ms per frame (min %.3f, max %.3f), %.3f s in all\n",
                    cmd, frames, 1e3 * sum / frames, 1e3 * tmin, 1e3 * tmax, sum);
        else if (mo->method == TOOL_MULTIBOUNCE)
            fprintf(stderr, "rad %s: L = F_mb E in %.3f ms\n", cmd, 1e3 * sum);
        rc = tool_vertex_H_rowsums(P, tool_indirect_rowsums(m), H, Hv);
    }
    if (rc == 0) rc = tool_render_pixels(w, view, &src, img);
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
void tool_bake_load_failed(const char *cmd, const char *path, rad_result r)
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
int tool_render_with_method(const char *cmd, const tool_world *w, const tool_render_args *ra, tool_image *img)
{
    const char *bake_path = ra->bake;
    const tool_method_options *mo = &ra->mo;
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
            tool_bake_load_failed(cmd, bake_path, r);
            return 1;
        }
        if (tool_bake_fits_scene(cmd, bake_path, bake, w)) {
            rad_bake_destroy(bake);
            return 1;
        }
    } else {
        if (tool_method_bake(cmd, w, &ra->o, mo, &buf, &size)) return 1;
        if ((r = rad_load_memory(buf, size, &ctx, &bake)) != RAD_SUCCESS) {
            free(buf);
            return tool_fail(cmd, "rad_load_memory", r);
        }
        bake_path = "(made here)";
    }
    bake->patches.scene = w->scene;
    rc = render_method(cmd, w, bake, bake_path, ra, img);
    rad_bake_destroy(bake);
    free(buf);
    return rc;
}

/* --method hierarchical: the solution (tool_hierarchical_build), then the classic render
   with H looked up at each sample */
int tool_render_hr_method(const char *cmd, const tool_world *w, const tool_render_args *ra, tool_image *img)
{
    rad_hierarchical *h = NULL;
    tool_render_source src;
    rad_hierarchical_stats st;
    double t0 = tool_seconds(), t_solve;
    int rc;
    if (tool_hierarchical_build(cmd, w, &ra->mo, ra->o.light_samples, &h)) return 1;
    t_solve = tool_seconds() - t0;
    rad_hierarchical_get_stats(h, &st);
    memset(&src, 0, sizeof src);
    src.hr = h;
    t0 = tool_seconds();
    rc = tool_render_pixels(w, &ra->view, &src, img);
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
int tool_render_local_method(const char *cmd, const tool_world *w, const tool_render_args *ra, tool_image *img)
{
    tool_classic_options o = ra->o;
    const tool_method_options *mo = &ra->mo;
    const rad_camera *cam = &ra->view.cam;
    int width = ra->view.width, height = ra->view.height;
    tool_render_source view_src;
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
    areas = (float *)tool_malloc(sizeof(float) * n);
    albedo = (float *)tool_malloc(sizeof(float) * 3 * (size_t)n);
    L = (float *)tool_malloc(sizeof(float) * 3 * (size_t)n);
    H = (float *)tool_malloc(sizeof(float) * 3 * (size_t)n);
    set = (uint32_t *)tool_malloc(sizeof(uint32_t) * m);
    vis = (uint32_t *)tool_malloc(sizeof(uint32_t) * m);
    lit = (uint32_t *)tool_malloc(sizeof(uint32_t) * m);
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
        qsort(times, 9, sizeof(double), tool_cmp_double);
        fprintf(stderr, "rad %s: local matrix: M = %u of %u patches, |P_Vis| = %u, |P_Lit| = %u, %.1f MiB\n", cmd, m,
                n, nvis, nlit, (double)rad_local_memory(local) / 1048576.0);
        fprintf(stderr, "rad %s: timing: method=local patches=%u frames=9 step_ms_median=%.6f step_ms_min=%.6f "
                        "rebuild_ms=%.3f local_m=%u visible=%u lit=%u\n",
                cmd, n, 1e3 * times[4], 1e3 * times[0], 1e3 * t_rebuild, m, nvis, nlit);
        /* H = L / rho: the irradiance from the secondary sources (0 where rho is 0) */
        for (i = 0; i < 3 * n; ++i) H[i] = albedo[i] > 0.0f ? L[i] / albedo[i] : 0.0f;
        Hv = (float *)tool_malloc(sizeof(float) * 3 * (size_t)sol.patches->vertex_count);
        rc = tool_vertex_H(sol.patches, &sol.ff->matrix, H, Hv);
        memset(&view_src, 0, sizeof view_src);
        view_src.P = sol.patches;
        view_src.Hv = Hv;
        if (rc == 0) rc = tool_render_pixels(w, &ra->view, &view_src, img);
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
int tool_render_vp_method(const char *cmd, const tool_world *w, const tool_render_args *ra, tool_image *img)
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
int tool_render_classic_bake(const char *cmd, const tool_world *w, const tool_render_args *ra, tool_image *img)
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
