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

   Hierarchical (tool_render_hr_method): the quadtrees and links (methods.c), H looked up per
   sample. */
#include "tool.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#if defined(__unix__) || defined(__APPLE__)
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
