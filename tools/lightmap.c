/* lightmap.c - the lightmap bake that rad lightmap and rad render --method lightmap share
   (tool_lightmap_bake in tool.h): the solution (classic, virtual patches or hierarchical) over
   the lightmapped world, then texels, gather, direct light, dilation and stitching. */
#include "tool.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void tool_lightmap_bake_free(tool_lightmap_baked *b)
{
    free(b->values);
    rad_lightmap_destroy(b->lm);
    tool_classic_free(&b->cl);
    rad_vp_destroy(b->vp);
    rad_hierarchical_destroy(b->hr);
    if (b->own_scene) {
        rad_bvh_destroy(b->w.bvh);
        rad_scene_destroy(b->w.scene);
    }
    free(b->uvs);
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
    rad_scene_desc desc;
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
            mesh.positions = pos;
            mesh.vertex_count = 3 * k;
            mesh.uvs = tuv;
            mesh.triangle_count = k;
            mesh.material_ids = mat;
        }
        desc = w->file.desc;
        desc.meshes = &mesh;
        desc.mesh_count = 1;
        w2.scene = NULL;
        w2.bvh = NULL;
        out->own_scene = 1;
        out->w = w2;
        tool_context(&ctx, NULL);
        r = rad_scene_create(&desc, &ctx, &out->w.scene);
        if (w->scene->twins) { /* the scene keeps copies */
            free((void *)mesh.positions);
            free((void *)mesh.uvs);
            free((void *)mesh.material_ids);
        }
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

void tool_lightmap_request_default(tool_lightmap_request *rq)
{
    memset(rq, 0, sizeof *rq);
    rq->width = rq->height = TOOL_LIGHTMAP_SIZE;
    rq->texel_samples = TOOL_LIGHTMAP_TEXEL_SAMPLES;
    rq->visibility_rays = TOOL_LIGHTMAP_VISIBILITY_RAYS;
    rq->gather = TOOL_LIGHTMAP_GATHER_AUTO;
    rq->hemisphere_rays = TOOL_LIGHTMAP_HEMISPHERE_RAYS;
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
    if (lightmap_solve(cmd, co, proxy, out, &vp_H)) goto fail;
    /* the gather wants the total radiosity of the secondary sources: B = E + L */
    t0 = tool_seconds();
    rad_lightmap_options_default(&lo);
    lo.width = (uint32_t)width;
    lo.height = (uint32_t)height;
    lo.samples = texel_samples;
    tool_context(&ctx, "lightmap texels");
    r = rad_lightmap_create(w->scene, &w->rc, &lo, &ctx, &out->lm);
    tool_progress_end();
    if (r != RAD_SUCCESS) { tool_fail(cmd, "rad_lightmap_create", r); goto fail; }
    fprintf(stderr, "rad %s: %ux%u texels, %u covered, %u valid, %u of %u samples inside or behind geometry\n", cmd,
            out->lm->width, out->lm->height, out->lm->covered_texels, out->lm->valid_texels, out->lm->invalid_samples,
            out->lm->sample_count);
    if (out->lm->covered_texels == 0) {
        /* nothing to gather into: the map would be all zero */
        fprintf(stderr, "rad %s: the lightmap uv set covers no texel of the %ux%u atlas (its triangles are degenerate "
                        "in uv or lie outside [0,1]): fix the file's second uv set or give --unwrap\n",
                cmd, out->lm->width, out->lm->height);
        goto fail;
    }
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
