/* classic.c - the classic radiosity solution the tool's commands share: options and their
   parsing, patches, F, direct light as the source E = rho D, the solve and H = F (E + L)
   (tool_classic_*), and the signature of a bake's options (tool_bake_info_fill,
   tool_options_hash, tool_sign_options). cmd_bake.c saves it; render, lightmap,
   probes, merge and the methods of methods.c call it. */
#include "tool.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

void tool_classic_options_default(tool_classic_options *o)
{
    memset(o, 0, sizeof *o);
    o->patches = 2000;
    o->max_edge = 0.0f;
    o->samples = 16;
    o->solver = TOOL_JACOBI;
    o->bounces = 64;
    o->light_samples = 16;
}

static int parse_solver(const char *cmd, const tool_arg *t, const char *v, void *field)
{
    tool_solver *s = (tool_solver *)field;
    (void)t;
    if (!strcmp(v, "jacobi")) *s = TOOL_JACOBI;
    else if (!strcmp(v, "gauss-seidel") || !strcmp(v, "gs")) *s = TOOL_GAUSS_SEIDEL;
    else if (!strcmp(v, "direct") || !strcmp(v, "lu")) *s = TOOL_DIRECT;
    else {
        fprintf(stderr, "rad %s: unknown solver '%s' (jacobi, gauss-seidel or direct)\n", cmd, v);
        return 2;
    }
    return 0;
}

static int parse_memory(const char *cmd, const tool_arg *t, const char *v, void *field)
{
    return tool_parse_bytes(cmd, t->name, v, (double *)field);
}

#define CO(f) offsetof(tool_classic_options, f)
/* The classic method's options (every command that builds patches): the parser and the help. */
static const tool_arg classic_args[] = {
    {TOOL_ARG_CUSTOM, "--solver", "S", CO(solver), 0, 0, 0, 0, NULL, NULL, NULL, parse_solver, 0,
     "jacobi (default), gauss-seidel or direct (LU)"},
    {TOOL_ARG_UINT, "--bounces", "K", CO(bounces), 0, 4294967295.0, 0, 0, "", NULL, NULL, NULL, 0,
     "Jacobi bounces of indirect light (default 64)"},
    {TOOL_ARG_UINT, "--patches", "N", CO(patches), 1, 4294967295.0, 0, 0, "must be > 0", NULL, NULL, NULL, 0,
     "target patch count (default 2000)"},
    {TOOL_ARG_FLOAT, "--max-edge", "L", CO(max_edge), 0, 1e30, 0, 0, "must be >= 0", NULL, NULL, NULL, 0,
     "longest patch edge (default: no limit)"},
    {TOOL_ARG_UINT, "--samples", "S", CO(samples), 1, 256, 0, 0, "must be 1 to 256", NULL, NULL, NULL, 0,
     "form-factor points per patch pair (default 16, up to 256)"},
    {TOOL_ARG_UINT, "--light-samples", "N", CO(light_samples), 1, 65536, 0, 0, "must be 1 to 65536", NULL, NULL, NULL, 0,
     "shadow rays per point and light for the patches' direct light (default 16, at most 65536)"},
    {TOOL_ARG_CUSTOM, "--max-memory", "SIZE", CO(max_memory), 0, 0, 0, 0, NULL, NULL, NULL, parse_memory, 0,
     "refuse a dense N x N build estimated above SIZE (e.g. 8G; default: the\n"
     "MemAvailable of /proc/meminfo); builds estimated over an hour are refused too"},
    {TOOL_ARG_FLAG, "--force", NULL, CO(force), 1, 0, 0, 0, NULL, NULL, NULL, NULL, 0, "build it whatever the estimate"},
    {TOOL_ARG_END, NULL, NULL, 0, 0, 0, 0, 0, NULL, NULL, NULL, NULL, 0, NULL}
};

const char *tool_classic_help(void)
{
    static char buf[4096];
    tool_args_help_into(classic_args, 0, buf, sizeof buf);
    return buf;
}

int tool_classic_option(const char *cmd, int argc, char **argv, int *a, tool_classic_options *o)
{
    return tool_args_parse(cmd, classic_args, o, NULL, argc, argv, a);
}

void tool_classic_free(tool_classic *c)
{
    rad_form_factors_destroy(c->ff);
    rad_patches_destroy(c->patches);
    free(c->D);
    free(c->E);
    free(c->L);
    free(c->B);
    free(c->H);
    memset(c, 0, sizeof *c);
}

int tool_classic_sources(const char *cmd, const tool_world *w, const tool_classic_options *o,
                             tool_classic *out)
{
    rad_patch_options po;
    rad_direct_options dopt;
    rad_context ctx;
    rad_result r;
    uint32_t n;
    double t0 = tool_seconds();
    memset(out, 0, sizeof *out);
    tool_context(&ctx, NULL);
    rad_patch_options_default(&po);
    po.target_count = o->patches;
    po.max_edge = o->max_edge;
    /* at least one patch per triangle: a scene too big for F is refused before any work */
    if (tool_dense_check(cmd, o, w->scene->triangle_count, 1)) return 1;
    if ((r = rad_patches_create(w->scene, &po, &ctx, &out->patches)) != RAD_SUCCESS)
        return tool_fail(cmd, "rad_patches_create", r);
    n = out->patches->count;
    fprintf(stderr, "rad %s: %u triangles, %u patches\n", cmd, w->scene->triangle_count, n);
    if (tool_dense_check(cmd, o, n, 0)) {
        tool_classic_free(out);
        return 1;
    }
    out->D = (float *)tool_calloc(3 * (size_t)n, sizeof(float));
    out->E = (float *)tool_calloc(3 * (size_t)n, sizeof(float));
    rad_direct_options_default(&dopt);
    dopt.exclude_emitters = 0;
    dopt.light_samples = o->light_samples;
    tool_context(&ctx, "direct light");
    r = rad_direct_patches(out->patches, &w->rc, w->file.lights, w->file.light_count, &dopt, out->D, &ctx);
    tool_progress_end();
    if (r != RAD_SUCCESS) {
        tool_classic_free(out);
        return tool_fail(cmd, "rad_direct_patches", r);
    }
    /* E = rho D: direct light is the source, emission stays out of the system (the renderer adds D per pixel) */
    if ((r = rad_sources(out->patches, RAD_SOURCE_DIRECT, out->D, out->E)) != RAD_SUCCESS) {
        tool_classic_free(out);
        return tool_fail(cmd, "rad_sources", r);
    }
    fprintf(stderr, "rad %s: direct light in %.2f s\n", cmd, tool_seconds() - t0);
    return 0;
}

int tool_classic_indirect(const char *cmd, const tool_classic_options *o, const rad_matrix *F,
                              tool_classic *c)
{
    rad_solve_options so;
    rad_solve_stats stats;
    rad_system sys;
    rad_context ctx;
    rad_result r;
    uint32_t n = c->patches->count, i;
    double t1;
    c->L = (float *)tool_calloc(3 * (size_t)n, sizeof(float));
    c->B = (float *)tool_calloc(3 * (size_t)n, sizeof(float));
    c->H = (float *)tool_calloc(3 * (size_t)n, sizeof(float));
    rad_system_init(&sys, F, c->patches, c->E);
    rad_solve_options_default(&so);
    so.output = RAD_OUTPUT_INDIRECT;
    so.bounces = o->bounces;
    memset(&stats, 0, sizeof stats);
    tool_context(&ctx, "solve");
    t1 = tool_seconds();
    switch (o->solver) {
    case TOOL_GAUSS_SEIDEL:
        r = rad_solve_gauss_seidel(&sys, &so, c->L, &stats, &ctx);
        if (r == RAD_ERROR_NOT_CONVERGED) {
            fprintf(stderr, "rad %s: warning: Gauss-Seidel did not converge (residual %g after %u sweeps)\n", cmd,
                    stats.residual, stats.iterations);
            r = RAD_SUCCESS;
        }
        break;
    case TOOL_DIRECT: r = rad_solve_direct(&sys, &so, c->L, &ctx); break;
    /* --bounces 0: no indirect light (L stays 0; a solve's bounces of 0 would be its default) */
    default: r = o->bounces ? rad_solve_jacobi(&sys, &so, c->L, &stats, &ctx) : RAD_SUCCESS; break;
    }
    c->solve_seconds = tool_seconds() - t1;
    tool_progress_end();
    if (r != RAD_SUCCESS) return tool_fail(cmd, "solve", r);
    for (i = 0; i < 3 * n; ++i) c->B[i] = c->E[i] + c->L[i];
    tool_context(&ctx, NULL);
    if ((r = rad_matrix_multiply(F, c->B, c->H, &ctx)) != RAD_SUCCESS) return tool_fail(cmd, "rad_matrix_multiply", r);
    fprintf(stderr, "rad %s: %s solve in %.2f s\n", cmd,
            o->solver == TOOL_GAUSS_SEIDEL ? "Gauss-Seidel" : o->solver == TOOL_DIRECT ? "direct (LU)" : "Jacobi",
            c->solve_seconds);
    return 0;
}

int tool_classic_solve(const char *cmd, const tool_world *w, const tool_classic_options *o,
                           tool_classic *out)
{
    rad_form_factor_options fo;
    rad_context ctx;
    rad_result r;
    uint32_t n;
    double t0;
    clock_t c0;
    if (tool_classic_sources(cmd, w, o, out)) return 1;
    if (o->sources_only && o->no_form_factors) return 0;
    n = out->patches->count;
    t0 = tool_seconds();
    c0 = clock();
    rad_form_factor_options_default(&fo);
    fo.samples = o->samples;
    tool_context(&ctx, "form factors");
    r = rad_form_factors_dense(out->patches, &w->rc, &fo, &ctx, &out->ff);
    tool_progress_end();
    if (r != RAD_SUCCESS) {
        tool_classic_free(out);
        return tool_fail(cmd, "rad_form_factors_dense", r);
    }
    /* the CPU time too: the work of a sharded bake is compared with it (docs/distributed.md) */
    fprintf(stderr, "rad %s: form factors %u x %u (%.1f MB), %llu pairs evaluated, in %.2f s (%.2f s CPU)\n", cmd, n, n,
            4.0 * n * (double)n / 1e6, (unsigned long long)out->ff->pairs_evaluated, tool_seconds() - t0,
            (double)(clock() - c0) / CLOCKS_PER_SEC);
    if (o->sources_only) return 0;
    if (tool_classic_indirect(cmd, o, &out->ff->matrix, out)) {
        tool_classic_free(out);
        return 1;
    }
    return 0;
}

int tool_plan(const char *cmd, const tool_world *w, const tool_classic_options *o, rad_baker_method method, rad_vp_kind kind,
              uint32_t face_points, float voxels_per_path, rad_baker_choice *plan)
{
    rad_baker_options bo;
    rad_context ctx;
    rad_result r;
    memset(&bo, 0, sizeof bo);
    bo.method = method;
    bo.max_memory = o->max_memory;
    bo.patches = o->patches;
    bo.ff_samples = o->samples;
    bo.bounces = o->bounces;
    bo.light_samples = o->light_samples;
    bo.vp_voxels_per_path = voxels_per_path;
    bo.vp_kind = kind;
    bo.vp_face_points = face_points;
    tool_context(&ctx, NULL);
    if ((r = rad_baker_plan(w->scene, &w->rc, &bo, &ctx, plan)) != RAD_SUCCESS) return tool_fail(cmd, "rad_baker_plan", r);
    if (plan->method == RAD_BAKER_VIRTUAL_PATCHES) {
        /* The virtual patches' CPU follows the scene's size: 4 minutes per 100 000 triangles
           (at least ten seconds; Sponza's resolutions fit), so that a small scene whose mean
           free path asks for a fine set (touching objects, thousands of emitting triangles)
           is not baked for minutes; the library's 10 minutes above still decide between
           classic and virtual patches. */
        double size_budget = 240.0 * (double)w->scene->triangle_count / 1e5;
        if (size_budget < 10.0) size_budget = 10.0;
        if (plan->estimated_seconds > size_budget) {
            bo.method = RAD_BAKER_VIRTUAL_PATCHES;
            bo.max_seconds = size_budget;
            if ((r = rad_baker_plan(w->scene, &w->rc, &bo, &ctx, plan)) != RAD_SUCCESS) return tool_fail(cmd, "rad_baker_plan", r);
        }
    }
    return 0;
}

int tool_plan_proxy(const char *cmd, const tool_world *w, const tool_classic_options *o, float voxels_per_path,
                    const char *what, int *kind, uint32_t *resolution)
{
    rad_baker_choice plan;
    if (tool_plan(cmd, w, o, RAD_BAKER_AUTO, RAD_VP_AXIS_ALIGNED, 0, voxels_per_path, &plan)) return 1;
    if (plan.method != RAD_BAKER_VIRTUAL_PATCHES) {
        fprintf(stderr, "rad %s: no --proxy given: the classic patches (%u, within the plan's budget; --proxy aavp|vp to "
                        "choose)\n", cmd, plan.patch_count);
        return 0;
    }
    *kind = TOOL_PROXY_AAVP;
    *resolution = plan.vp_resolution;
    fprintf(stderr, "rad %s: no --proxy given: %s from aavp virtual patches at --vp-resolution %u (%u patches, about "
                    "%.0f MiB and %.0f s of CPU for the bake; the classic patches' dense build would not fit; --proxy "
                    "patches to insist)\n",
            cmd, what, plan.vp_resolution, plan.patch_count, plan.estimated_bytes / 1048576.0, plan.estimated_seconds);
    return 0;
}

int tool_baker_run(const char *cmd, const tool_world *w, const tool_classic_options *o, rad_baker_method method,
                   uint32_t bounces, uint32_t vp_resolution, const rad_baker_options *base, rad_baker_desc *d,
                   rad_baker_result **out)
{
    rad_baker_options bo;
    rad_baker_light *bl;
    rad_context ctx;
    rad_result r;
    uint32_t i, emits = w->file.light_count > 0;
    *out = NULL;
    /* a dense build over the budget is refused first, lit or not (as the tool's own solve does) */
    if (method == RAD_BAKER_CLASSIC && tool_dense_check(cmd, o, w->scene->triangle_count, 1)) return 1;
    for (i = 0; i < w->file.desc.material_count; ++i) {
        const float *e = w->file.desc.materials[i].emission;
        emits |= e[0] > 0.0f || e[1] > 0.0f || e[2] > 0.0f;
    }
    if (!emits) return -1; /* the tier refuses a scene where nothing emits: the caller's own path draws it black */
    if (base) bo = *base;
    else memset(&bo, 0, sizeof bo);
    bo.method = method;
    /* the tool's own checks decide (tool_dense_check on the counted patches, --force; the
       resolution of virtual patches is the command line's or the plan's already): the tier's
       budget is set out of the way */
    bo.max_memory = bo.max_seconds = 1e29;
    bo.patches = o->patches;
    bo.ff_samples = o->samples;
    bo.bounces = bounces;
    bo.light_samples = o->light_samples;
    bo.vp_resolution = vp_resolution;
    /* the solve of the command line: classic's --solver, else --bounces 0 (no bounce) or inf
       (every bounce, by Gauss-Seidel; its estimate counts the default sweeps) */
    if (!(base && base->solver)) /* else the caller's (a proxy's Gauss-Seidel) */
        bo.solver = method == RAD_BAKER_CLASSIC && o->solver == TOOL_GAUSS_SEIDEL ? RAD_BAKER_SOLVE_GAUSS_SEIDEL
                    : method == RAD_BAKER_CLASSIC && o->solver == TOOL_DIRECT      ? RAD_BAKER_SOLVE_DIRECT
                    : bounces == 0                                                  ? RAD_BAKER_SOLVE_NONE
                    : bounces == RAD_MB_INFINITE                                    ? RAD_BAKER_SOLVE_GAUSS_SEIDEL
                                                                                    : RAD_BAKER_SOLVE_JACOBI;
    if (bounces == RAD_MB_INFINITE) bo.bounces = 0;
    bo.max_edge = o->max_edge;
    if (method == RAD_BAKER_CLASSIC) {
        rad_baker_choice plan;
        memset(&ctx, 0, sizeof ctx); /* quiet: the run logs the same plan */
        if ((r = rad_baker_plan(w->scene, &w->rc, &bo, &ctx, &plan)) != RAD_SUCCESS) return tool_fail(cmd, "rad_baker_plan", r);
        if (tool_dense_check(cmd, o, plan.patch_count, 0)) return 1;
    }
    bl = (rad_baker_light *)tool_calloc(w->file.light_count ? w->file.light_count : 1u, sizeof *bl);
    for (i = 0; i < w->file.light_count; ++i) bl[i].light = w->file.lights[i];
    d->scene = w->file.desc;
    /* the world's BVH is over rad_scene_create of this same description: the tier casts
       through it instead of building a second one (RAYCASTER in >>api_bake) */
    d->raycaster = &w->rc;
    d->lights = bl;
    d->light_count = w->file.light_count;
    d->group_count = 1;
    tool_context(&ctx, "bake");
    r = rad_baker_run(d, &bo, &ctx, out);
    tool_progress_end();
    free(bl);
    if (r != RAD_SUCCESS) return tool_fail(cmd, "rad_baker_run", r);
    fprintf(stderr, "rad %s: %s\n", cmd, (*out)->reason);
    return 0;
}

void tool_bake_info_fill(tool_bake_info *info, const tool_world *w, const tool_classic_options *o)
{
    memset(info, 0, sizeof *info);
    info->magic = 0x52414442u;
    info->patches = o->patches;
    info->max_edge = o->max_edge;
    info->samples = o->samples;
    info->solver = (uint32_t)o->solver;
    info->bounces = o->bounces;
    info->light_samples = o->light_samples;
    info->triangle_count = w->scene->triangle_count;
}

uint64_t tool_options_hash(const tool_bake_info *info, const tool_world *w)
{
    uint64_t h = rad_hash64(info, sizeof *info, RAD_HASH64_INIT);
    /* the command line's lights, so that a bake lit by --sun is not rendered under another sun;
       none leaves the hash of bakes made before those options unchanged */
    if (w && w->file.light_count > w->file_light_count)
        h = tool_lights_hash(w->file.lights + w->file_light_count, w->file.light_count - w->file_light_count, h);
    return h;
}

void tool_sign_options(rad_section *secs, uint32_t count, const tool_bake_info *info, const tool_world *w,
                           rad_bake_signature *sig)
{
    uint32_t i;
    for (i = 0; i < count; ++i)
        if (secs[i].type == RAD_SECTION_SIGNATURE && secs[i].elem_size == sizeof *sig && secs[i].count == 1) {
            memcpy(sig, secs[i].data, sizeof *sig);
            sig->options = tool_options_hash(info, w);
            secs[i].data = sig;
        }
}
