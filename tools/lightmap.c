/* lightmap.c - the lightmap bake that rad lightmap and rad render --method lightmap share
   (tool_lightmap_bake in tool.h): the lightmapped world (the file's second uv set or the
   unwrap), then the engine tier's bake (rad_baker_run with its lightmap options) where it
   offers the solution asked for, else the tool's own steps: the solution (classic, virtual
   patches or hierarchical), texels, gather, direct light, dilation and stitching. */
#include "tool.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void tool_lightmap_bake_free(tool_lightmap_baked *b)
{
    free(b->values);
    rad_lightmap_destroy(b->own_lm);
    rad_baker_result_destroy(b->baked);
    tool_classic_free(&b->cl);
    rad_vp_destroy(b->vp);
    rad_hierarchical_destroy(b->hr);
    if (b->own_scene) {
        rad_bvh_destroy(b->w.bvh);
        rad_scene_destroy(b->w.scene);
    }
    free(b->uvs);
    free(b->mesh_positions);
    free(b->mesh_uvs);
    free(b->mesh_materials);
    memset(b, 0, sizeof *b);
}

/* The world the lightmap is baked over, into out->w: the caller's (its file's second uv set), or a
   copy over the automatic unwrap when a mesh has none or rq->force_unwrap (the atlas may grow:
   *width, *height). 0, or 1 after printing why (the caller frees out). */
static int lightmap_world(const char *cmd, const tool_world *w, const tool_classic_options *co,
                          const tool_lightmap_request *rq, int *width, int *height, tool_lightmap_baked *out)
{
    tool_world w2 = *w;
    rad_mesh_desc mesh;
    rad_context ctx;
    rad_result r;
    /* the lightmap uv set: the file's, or an unwrap into a copy of the scene */
    if (rq->force_unwrap || !w->scene->lightmap_uvs || memchr(w->scene->lightmapped, 0, w->scene->triangle_count)) {
        if (!rq->force_unwrap && w->scene->lightmap_uvs)
            fprintf(stderr, "rad %s: some meshes have no second uv set: unwrapping the whole scene\n", cmd);
        uint32_t uw = (uint32_t)*width, uh = (uint32_t)*height;
        tool_unwrap_auto au;
        out->uvs = (float *)tool_calloc(6 * (size_t)w->scene->triangle_count, sizeof(float));
        /* the estimate: the texel records (flags, position, normal, sample index: 29 bytes),
           the samples (position, normal, triangle, validity: 29 bytes each) and the values
           with one working copy, plus an RGB image of the atlas */
        au.max_side = TOOL_LIGHTMAP_AUTO_MAX;
        au.bytes_per_texel = TOOL_LIGHTMAP_TEXEL_BYTES(rq->texel_samples ? rq->texel_samples : TOOL_LIGHTMAP_TEXEL_SAMPLES,
                                                        rq->sh ? 12u : 3u);
        if (co->max_memory > 0.0) au.memory_limit = co->max_memory, au.memory_from = "--max-memory";
        else au.memory_limit = tool_mem_available(), au.memory_from = "MemAvailable in /proc/meminfo";
        if (tool_unwrap(cmd, strcmp(cmd, "render") ? "--size" : "--lightmap-size", w->scene, &uw, &uh,
                        rq->auto_size ? &au : NULL, out->uvs, NULL))
            return 1;
        *width = (int)uw;
        *height = (int)uh;
        memset(&mesh, 0, sizeof mesh);
        mesh.name = "unwrapped";
        mesh.positions = w->scene->positions;
        mesh.vertex_count = 3 * w->scene->triangle_count;
        mesh.uvs = w->scene->uvs;
        mesh.triangle_count = w->scene->triangle_count;
        mesh.material_ids = w->scene->materials;
        mesh.lightmap_uvs = out->uvs;
        if (w->scene->twins) {
            /* a two-sided pair is two scene triangles, and the copy's two-sided materials pair
               them again: the mesh takes the first side of each pair only (the side the
               file's normals chose), else every sheet would be four coincident triangles */
            const rad_scene *S = w->scene;
            uint32_t t, k = 0;
            float *pos = (float *)tool_calloc(9 * (size_t)S->triangle_count, sizeof(float));
            float *tuv = S->uvs ? (float *)tool_calloc(6 * (size_t)S->triangle_count, sizeof(float)) : NULL;
            uint32_t *mat = (uint32_t *)tool_calloc((size_t)S->triangle_count, sizeof(uint32_t));
            for (t = 0; t < S->triangle_count; ++t) {
                if (S->twins[t] != RAD_NONE && S->twins[t] < t) continue;
                memcpy(pos + 9 * (size_t)k, S->positions + 9 * (size_t)t, 9 * sizeof(float));
                if (tuv) memcpy(tuv + 6 * (size_t)k, S->uvs + 6 * (size_t)t, 6 * sizeof(float));
                memmove(out->uvs + 6 * (size_t)k, out->uvs + 6 * (size_t)t, 6 * sizeof(float));
                mat[k++] = S->materials[t];
            }
            mesh.positions = out->mesh_positions = pos;
            mesh.vertex_count = 3 * k;
            mesh.uvs = out->mesh_uvs = tuv;
            mesh.triangle_count = k;
            mesh.material_ids = out->mesh_materials = mat;
        }
        /* the copy's file names the unwrapped mesh: the engine tier bakes it (kept until freed) */
        out->mesh = mesh;
        w2.file.desc.meshes = &out->mesh;
        w2.file.desc.mesh_count = 1;
        w2.scene = NULL;
        w2.bvh = NULL;
        out->own_scene = 1;
        out->w = w2;
        tool_context(&ctx, NULL);
        r = rad_scene_create(&out->w.file.desc, &ctx, &out->w.scene);
        if (r != RAD_SUCCESS) { tool_fail(cmd, "rad_scene_create", r); return 1; }
        if ((r = rad_bvh_create(out->w.scene, &ctx, &out->w.bvh)) != RAD_SUCCESS) { tool_fail(cmd, "rad_bvh_create", r); return 1; }
        rad_bvh_raycaster(out->w.bvh, &out->w.rc);
    } else {
        out->w = w2;
        fprintf(stderr, "rad %s: using the file's second uv set\n", cmd);
    }
    return 0;
}

/* The solution the texels gather: hierarchical, the proxy's virtual patches (their H into
   *vp_H), or classic patches. 0, or 1 after printing why. */
static int lightmap_solve(const char *cmd, const tool_classic_options *co, const tool_lightmap_proxy *proxy,
                          tool_lightmap_baked *out, float **vp_H)
{
    const tool_world *w = &out->w;
    if (proxy && proxy->kind == TOOL_LIGHTMAP_HIERARCHICAL) {
        tool_method_options mo;
        rad_hierarchical_stats hs;
        double th = tool_seconds();
        tool_method_options_default(&mo);
        mo.hr_eps = proxy->hr_eps;
        if (tool_hierarchical_build(cmd, w, &mo, co->light_samples, &out->hr)) return 1;
        rad_hierarchical_get_stats(out->hr, &hs);
        out->patches = hs.leaves;
        out->solve_seconds = tool_seconds() - th;
    } else if (proxy) {
        if (tool_vp_proxy_solve(cmd, w, co, proxy, &out->vp, NULL, vp_H, &out->solve_seconds)) return 1;
        out->patches = out->vp->count;
    } else {
        if (tool_classic_solve(cmd, w, co, &out->cl)) return 1;
        out->patches = out->cl.patches->count;
        out->solve_seconds = out->cl.solve_seconds;
    }
    return 0;
}

/* Prints the texels' counts; 1 after printing why when the uv set covers none (nothing to
   gather into: the map would be all zero). */
static int lightmap_texels_report(const char *cmd, const rad_lightmap *lm)
{
    fprintf(stderr, "rad %s: %ux%u texels, %u covered, %u valid, %u of %u samples inside or behind geometry\n", cmd,
            lm->width, lm->height, lm->covered_texels, lm->valid_texels, lm->invalid_samples, lm->sample_count);
    if (lm->covered_texels > 0) return 0;
    fprintf(stderr, "rad %s: the lightmap uv set covers no texel of the %ux%u atlas (its triangles are degenerate "
                    "in uv or lie outside [0,1]): fix the file's second uv set or give --unwrap\n",
            cmd, lm->width, lm->height);
    return 1;
}

/* The bake by the engine tier (rad_baker_run over out->w's file, keep: the texels stay in the
   result) for what it offers: Jacobi bounces on the patches as made, or aavp|vp proxies at the
   default face points; the gather options, the direct light per texel and the stitching are
   the tier's lightmap options. 0, 1 after printing why (the caller frees out), or -1 when the
   request is not one of those (nothing done). */
static int lightmap_by_tier(const char *cmd, const tool_classic_options *co, const tool_lightmap_request *rq, int width,
                            int height, tool_lightmap_baked *out)
{
    const tool_lightmap_proxy *px = rq->proxy;
    rad_baker_desc d;
    rad_baker_options bo;
    rad_lightmap_gather_options go;
    rad_baker_result *R = NULL;
    const rad_lightmap *lm;
    size_t n;
    double t0 = tool_seconds();
    int rc;
    uint32_t res = 0;
    if (px && px->kind != TOOL_PROXY_AAVP && px->kind != TOOL_PROXY_VP) return -1;
    memset(&bo, 0, sizeof bo);
    if (px && tool_vp_proxy_options(cmd, &out->w, co, px, &bo, &res)) return 1;
    bo.keep = 1; /* the texels for the caller */
    bo.lightmap_samples = rq->texel_samples;
    bo.lightmap_final_gather = rq->final_gather != TOOL_LIGHTMAP_FINAL_GATHER_AUTO ? rq->final_gather
                               : px                                               ? TOOL_LIGHTMAP_FINAL_GATHER
                                                                                  : 0u;
    /* the plan's message names the voxels a path it asked for: 4 when the texels trace the first bounce */
    bo.vp_voxels_per_path = bo.lightmap_final_gather ? 4.0f : 0.0f;
    rad_lightmap_gather_options_default(&go);
    go.encoding = rq->sh ? RAD_LIGHTMAP_SH_L1 : RAD_LIGHTMAP_IRRADIANCE;
    go.visibility_rays = rq->visibility_rays;
    go.hemisphere_rays = rq->hemisphere_rays;
    if (rq->gather == TOOL_LIGHTMAP_GATHER_AUTO) bo.lightmap_exact_pairs = TOOL_LIGHTMAP_EXACT_MAX_PAIRS;
    else go.method = (rad_lightmap_gather_method)rq->gather;
    memset(&d, 0, sizeof d);
    d.outputs = RAD_BAKER_LIGHTMAP;
    d.lightmap_width = (uint32_t)width;
    d.lightmap_height = (uint32_t)height;
    d.lightmap_gather = &go;
    d.lightmap_flags = RAD_BAKER_LIGHTMAP_STITCH | (rq->direct && !rq->sh ? RAD_BAKER_LIGHTMAP_DIRECT : 0u);
    rc = tool_baker_run(cmd, &out->w, co, px ? RAD_BAKER_VIRTUAL_PATCHES : RAD_BAKER_CLASSIC, co->bounces,
                        res, &bo, &d, &R);
    if (rc) return rc;
    out->baked = R;
    out->lm = lm = rad_baker_result_lightmap(R);
    out->patches = R->patch_count;
    out->solve_seconds = tool_seconds() - t0; /* the whole bake: the tier does not split it */
    if (px)
        fprintf(stderr, "rad %s: %s virtual patches at resolution %u: %u patches (the engine tier's bake)\n", cmd,
                px->kind == TOOL_PROXY_VP ? "vp" : "aavp", R->vp_resolution, R->patch_count);
    if (bo.lightmap_final_gather)
        fprintf(stderr, "rad %s: final gather of the first bounce, %u rays a texel%s\n", cmd, bo.lightmap_final_gather,
                rq->final_gather == TOOL_LIGHTMAP_FINAL_GATHER_AUTO ? " (the virtual patches' default; --final-gather 0: off)" : "");
    if (lightmap_texels_report(cmd, lm)) return 1;
    if (!px && !bo.lightmap_final_gather && (rq->gather == RAD_LIGHTMAP_GATHER_HEMISPHERE ||
                (rq->gather == TOOL_LIGHTMAP_GATHER_AUTO && (double)lm->sample_count * R->patch_count > bo.lightmap_exact_pairs)))
        fprintf(stderr, "rad %s: hemisphere gather, %u rays a texel (--gather exact for the exact one)\n", cmd, rq->hemisphere_rays);
    n = (size_t)R->lightmap_channels * lm->width * lm->height;
    out->values = (float *)tool_calloc(n, sizeof(float));
    memcpy(out->values, R->lightmap, n * sizeof(float));
    fprintf(stderr, "rad %s: lightmap baked in %.2f s with the engine tier's %s bake (%ux%u, %.1f MiB of values); %u seams, "
                    "largest jump %.4g before stitching, %.4g after\n",
            cmd, out->solve_seconds, px ? "virtual-patch" : "classic", lm->width, lm->height, (double)n * sizeof(float) / 1048576.0,
            R->lightmap_seams.seams, (double)R->lightmap_seams.max_jump_before, (double)R->lightmap_seams.max_jump_after);
    return 0;
}

void tool_lightmap_request_default(tool_lightmap_request *rq)
{
    memset(rq, 0, sizeof *rq);
    rq->width = rq->height = TOOL_LIGHTMAP_SIZE;
    rq->texel_samples = TOOL_LIGHTMAP_TEXEL_SAMPLES;
    rq->visibility_rays = TOOL_LIGHTMAP_VISIBILITY_RAYS;
    rq->gather = TOOL_LIGHTMAP_GATHER_AUTO;
    rq->hemisphere_rays = TOOL_LIGHTMAP_HEMISPHERE_RAYS;
    rq->final_gather = TOOL_LIGHTMAP_FINAL_GATHER_AUTO;
}

int tool_lightmap_bake(const char *cmd, const tool_world *world, const tool_classic_options *co,
                       const tool_lightmap_request *rq, tool_lightmap_baked *out)
{
    int width = rq->width, height = rq->height, gather = rq->gather, sh = rq->sh;
    uint32_t texel_samples = rq->texel_samples, vis = rq->visibility_rays, hemi_rays = rq->hemisphere_rays;
    const tool_lightmap_proxy *proxy = rq->proxy;
    tool_classic_options co2 = *co;
    float *vp_H = NULL;
    double t_all = tool_seconds();
    rad_lightmap_options lo;
    rad_lightmap_gather_options go;
    rad_lightmap_seam_stats st;
    rad_context ctx;
    rad_result r;
    uint32_t ch;
    double t0;
    const tool_world *w = world;
    memset(out, 0, sizeof *out);
    if (proxy && sh) {
        fprintf(stderr, "rad %s: --sh needs the classic gather (the virtual patches' gather has no direction): leave out --proxy\n", cmd);
        return 1;
    }
    if (proxy && co->solver == TOOL_DIRECT) {
        fprintf(stderr, "rad %s: --solver direct is for classic patches: with --proxy use jacobi or gauss-seidel\n", cmd);
        return 1;
    }
    /* a scene too big for the dense classic build is refused before the unwrap, with the way out */
    co2.dense_instead = "--proxy aavp or --proxy vp (the lightmap's indirect light from virtual patches: a few thousand "
                        "whatever the triangle count; --vp-resolution R sets how many)";
    co = &co2;
    if (!proxy && tool_dense_check(cmd, co, w->scene->triangle_count, 1)) return 1;
    if (lightmap_world(cmd, world, co, rq, &width, &height, out)) goto fail;
    w = &out->w;
    {
        int k = lightmap_by_tier(cmd, co, rq, width, height, out);
        if (k > 0) goto fail;
        if (k == 0) return 0;
    }
    if (rq->final_gather != TOOL_LIGHTMAP_FINAL_GATHER_AUTO && rq->final_gather) {
        fprintf(stderr, "rad %s: --final-gather is for the engine tier's bakes: the patches or --proxy aavp|vp in a "
                        "scene that emits light\n", cmd);
        goto fail;
    }
    if (proxy && proxy->kind != TOOL_LIGHTMAP_HIERARCHICAL && rq->final_gather == TOOL_LIGHTMAP_FINAL_GATHER_AUTO)
        fprintf(stderr, "rad %s: no final gather per texel off the engine tier's bake: the texels read the voxel averages "
                        "(the engine tier's bakes trace the first bounce)\n", cmd);
    if (lightmap_solve(cmd, co, proxy, out, &vp_H)) goto fail;
    /* the gather wants the total radiosity of the secondary sources: B = E + L */
    t0 = tool_seconds();
    rad_lightmap_options_default(&lo);
    lo.width = (uint32_t)width;
    lo.height = (uint32_t)height;
    lo.samples = texel_samples;
    tool_context(&ctx, "lightmap texels");
    r = rad_lightmap_create(w->scene, &w->rc, &lo, &ctx, &out->own_lm);
    out->lm = out->own_lm;
    tool_progress_end();
    if (r != RAD_SUCCESS) { tool_fail(cmd, "rad_lightmap_create", r); goto fail; }
    if (lightmap_texels_report(cmd, out->lm)) goto fail;
    rad_lightmap_gather_options_default(&go);
    go.encoding = sh ? RAD_LIGHTMAP_SH_L1 : RAD_LIGHTMAP_IRRADIANCE;
    go.visibility_rays = vis;
    go.hemisphere_rays = hemi_rays;
    ch = rad_lightmap_channels(go.encoding);
    out->values = (float *)tool_calloc((size_t)width * height * ch, sizeof(float));
    if (proxy) {
        tool_context(&ctx, "lightmap gather");
        r = out->hr ? rad_lightmap_gather_hierarchical(out->lm, out->hr, RAD_HIERARCHICAL_GATHERED, out->values, &ctx)
                    : rad_lightmap_gather_vp(out->lm, out->vp, vp_H, out->values, &ctx);
        tool_progress_end();
        if (r != RAD_SUCCESS) { tool_fail(cmd, out->hr ? "rad_lightmap_gather_hierarchical" : "rad_lightmap_gather_vp", r); goto fail; }
    } else {
        /* the exact gather costs samples x patches form factors: past ~2e7 the rays win */
        if (gather == TOOL_LIGHTMAP_GATHER_AUTO)
            gather = (double)out->lm->sample_count * out->cl.patches->count > TOOL_LIGHTMAP_EXACT_MAX_PAIRS
                         ? RAD_LIGHTMAP_GATHER_HEMISPHERE
                         : RAD_LIGHTMAP_GATHER_EXACT;
        go.method = (rad_lightmap_gather_method)gather;
        if (go.method == RAD_LIGHTMAP_GATHER_HEMISPHERE)
            fprintf(stderr, "rad %s: hemisphere gather, %u rays a texel (--gather exact for the exact one)\n", cmd, hemi_rays);
        tool_context(&ctx, "lightmap gather");
        r = rad_lightmap_gather(out->lm, out->cl.patches, out->cl.B, &w->rc, &go, out->values, &ctx);
        tool_progress_end();
        if (r != RAD_SUCCESS) { tool_fail(cmd, "rad_lightmap_gather", r); goto fail; }
    }
    if (rq->direct && !sh) {
        rad_direct_options dopt;
        rad_direct_options_default(&dopt);
        dopt.exclude_emitters = 0;
        dopt.light_samples = co->light_samples;
        tool_context(&ctx, "lightmap direct");
        r = rad_lightmap_direct(out->lm, &w->rc, w->file.lights, w->file.light_count, &dopt, out->values, &ctx);
        tool_progress_end();
        if (r != RAD_SUCCESS) { tool_fail(cmd, "rad_lightmap_direct", r); goto fail; }
    }
    tool_context(&ctx, NULL);
    if ((r = rad_lightmap_dilate(out->lm, ch, out->values, 0, &ctx)) != RAD_SUCCESS) { tool_fail(cmd, "rad_lightmap_dilate", r); goto fail; }
    if ((r = rad_lightmap_stitch(out->lm, ch, out->values, 0, &st, &ctx)) != RAD_SUCCESS) { tool_fail(cmd, "rad_lightmap_stitch", r); goto fail; }
    fprintf(stderr, "rad %s: lightmap baked in %.2f s (%.2f s with the %s solution; %ux%u, %.1f MiB of values); %u seams, "
                    "largest jump %.4g before stitching, %.4g after\n", cmd, tool_seconds() - t0, tool_seconds() - t_all,
            out->hr ? "hierarchical" : proxy ? "virtual-patch" : "classic", out->lm->width, out->lm->height,
            (double)width * height * ch * sizeof(float) / 1048576.0, st.seams, (double)st.max_jump_before,
            (double)st.max_jump_after);
    free(vp_H);
    return 0;
fail:
    free(vp_H);
    tool_lightmap_bake_free(out);
    return 1;
}
