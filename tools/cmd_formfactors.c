/* cmd_formfactors.c - rad formfactors: group form factors between the scene's named objects
   (the area-weighted mean of the patch form factors from one group to another). */
#include "tool.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* rad formfactors' command line */
typedef struct ff_args {
    uint32_t patches, samples, threads, hemicube_res;
    float max_edge;
    uint32_t method;                 /* a rad_ff_method */
    tool_classic_options budget;     /* --max-memory, --force */
} ff_args;

static int parse_ff(const char *cmd, const tool_arg *t, const char *m, void *field)
{
    uint32_t *method = (uint32_t *)field;
    (void)t;
    if (!strcmp(m, "analytic")) *method = RAD_FF_ANALYTIC;
    else if (!strcmp(m, "montecarlo") || !strcmp(m, "monte-carlo")) *method = RAD_FF_MONTE_CARLO;
    else if (!strcmp(m, "hemicube")) *method = RAD_FF_HEMICUBE;
    else {
        fprintf(stderr, "rad %s: unknown --ff '%s' (analytic, montecarlo or hemicube)\n", cmd, m);
        return 2;
    }
    return 0;
}

static int parse_memory(const char *cmd, const tool_arg *t, const char *v, void *field)
{
    return tool_parse_bytes(cmd, t->name, v, (double *)field);
}

static int parse_threads(const char *cmd, const tool_arg *t, const char *v, void *field)
{
    return tool_parse_threads(cmd, t->name, v, (uint32_t *)field) ? 2 : 0;
}

#define FA(f) offsetof(ff_args, f)
/* rad formfactors' options */
static const tool_arg ff_table[] = {
    {TOOL_ARG_UINT, "--patches", "N", FA(patches), 0, 4294967295.0, 0, 0, "", NULL, NULL, NULL, 0,
     "target patch count (default 2000)"},
    {TOOL_ARG_FLOAT, "--max-edge", "L", FA(max_edge), -1e30, 1e30, 0, 0, "", NULL, NULL, NULL, 0,
     "longest patch edge (default: no limit)"},
    {TOOL_ARG_UINT, "--samples", "S", FA(samples), 0, 4294967295.0, 0, 0, "", NULL, NULL, NULL, 0,
     "points per patch pair (default 16, up to 256; analytic and montecarlo)"},
    {TOOL_ARG_CUSTOM, "--ff", "M", FA(method), 0, 0, 0, 0, NULL, NULL, NULL, parse_ff, 0,
     "analytic (default: the point-to-polygon integral at S points of the other patch, one\n"
     "visibility ray each), montecarlo (S point pairs) or hemicube (a hemicube at each patch\n"
     "centroid with an item buffer; no rays)"},
    {TOOL_ARG_UINT, "--hemicube-res", "R", FA(hemicube_res), 0, 4294967295.0, 0, 0, "", NULL, NULL, NULL, 0,
     "cells across the hemicube's top face (default 128; even, 4 to 2048)"},
    {TOOL_ARG_CUSTOM, "--max-memory", "SIZE", FA(budget.max_memory), 0, 0, 0, 0, NULL, NULL, NULL, parse_memory, 0,
     "the dense build's limit (rad render --help)"},
    {TOOL_ARG_FLAG, "--force", NULL, FA(budget.force), 1, 0, 0, 0, NULL, NULL, NULL, NULL, 0,
     "build it whatever the estimate"},
    {TOOL_ARG_CUSTOM, "--threads", "N", FA(threads), 0, 0, 0, 0, NULL, NULL, NULL, parse_threads, 0,
     "worker threads (default: all cores; at most 1024)"},
    {TOOL_ARG_END, NULL, NULL, 0, 0, 0, 0, 0, NULL, NULL, NULL, NULL, 0, NULL}
};

static void formfactors_usage(FILE *f)
{
    static char own[4096];
    tool_args_help_into(ff_table, 0, own, sizeof own);
    fprintf(f, "usage: rad formfactors SCENE [--patches N] [--max-edge L] [--samples S] [--ff M] [--hemicube-res R]\n"
               "                        [--max-memory SIZE] [--force] [--threads N]\n"
               "Prints one line 'FROM TO VALUE' per ordered pair of named objects: the area-weighted\n"
               "group form factor F_GH = sum_{i in G} A_i sum_{j in H} F_ij / sum_{i in G} A_i.\n"
               "%s",
            own);
}

/* ---- formfactors ----------------------------------------------------------------------- */

int tool_cmd_formfactors(int argc, char **argv)
{
    const char *scene_name = NULL, *cmd = "formfactors";
    uint32_t patches_target, samples, G, H, i, j, gc, hemicube_res;
    rad_ff_method ff_method;
    float max_edge;
    tool_world w;
    rad_patches *P = NULL;
    rad_form_factors *ff = NULL;
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_context ctx;
    rad_result r;
    double *num, *den;
    int a, rc;
    ff_args fa;
    tool_classic_options budget;
    memset(&fa, 0, sizeof fa);
    fa.patches = 2000;
    fa.samples = 16;
    fa.method = RAD_FF_ANALYTIC;
    tool_classic_options_default(&fa.budget);
    for (a = 0; a < argc; ++a) {
        const char *o = argv[a];
        if (!strcmp(o, "--help") || !strcmp(o, "-h")) { formfactors_usage(stdout); return 0; }
        if ((rc = tool_args_parse(cmd, ff_table, &fa, NULL, argc, argv, &a)) == 2) return 2;
        if (rc == 1) continue;
        if (o[0] == '-' && o[1]) { fprintf(stderr, "rad %s: unknown option '%s'\n", cmd, o); return 2; }
        else if (!scene_name) scene_name = o;
        else { fprintf(stderr, "rad %s: more than one scene given\n", cmd); return 2; }
    }
    patches_target = fa.patches;
    samples = fa.samples;
    hemicube_res = fa.hemicube_res;
    max_edge = fa.max_edge;
    ff_method = (rad_ff_method)fa.method;
    budget = fa.budget;
    if (!scene_name) { fprintf(stderr, "rad %s: no scene given\n", cmd); formfactors_usage(stderr); return 2; }
    if (samples == 0 || max_edge < 0.0f) { fprintf(stderr, "rad %s: --samples must be > 0, --max-edge >= 0\n", cmd); return 2; }
    tool_set_threads((int)fa.threads);
    budget.samples = samples;
    if (tool_open_world(cmd, scene_name, &w)) return 1;
    if (tool_dense_check(cmd, &budget, w.scene->triangle_count, 1)) {
        tool_close_world(&w);
        return 1;
    }
    tool_context(&ctx, "form factors");
    rad_patch_options_default(&po);
    po.target_count = patches_target;
    po.max_edge = max_edge;
    if ((r = rad_patches_create(w.scene, &po, &ctx, &P)) != RAD_SUCCESS) {
        tool_close_world(&w);
        return tool_fail(cmd, "rad_patches_create", r);
    }
    rad_form_factor_options_default(&fo);
    fo.samples = samples;
    fo.method = ff_method;
    if (hemicube_res) fo.hemicube_resolution = hemicube_res;
    fprintf(stderr, "rad %s: %u triangles, %u patches\n", cmd, w.scene->triangle_count, P->count);
    if (tool_dense_check(cmd, &budget, P->count, 0)) {
        rad_patches_destroy(P);
        tool_close_world(&w);
        return 1;
    }
    r = rad_form_factors_dense(P, &w.rc, &fo, &ctx, &ff);
    tool_progress_end();
    if (r != RAD_SUCCESS) {
        rad_patches_destroy(P);
        tool_close_world(&w);
        return tool_fail(cmd, "rad_form_factors_dense", r);
    }
    gc = w.scene->mesh_count;
    num = (double *)calloc((size_t)gc * gc, sizeof(double));
    den = (double *)calloc(gc, sizeof(double));
    if (!num || !den) { fprintf(stderr, "rad %s: out of memory\n", cmd); return 1; }
    for (i = 0; i < P->count; ++i) {
        uint32_t gi = w.scene->meshes[P->patches[i].triangle];
        const float *row = ff->matrix.dense + (size_t)i * P->count;
        double *nrow = num + (size_t)gi * gc;
        den[gi] += P->areas[i];
        for (j = 0; j < P->count; ++j)
            if (row[j] != 0.0f) nrow[w.scene->meshes[P->patches[j].triangle]] += (double)P->areas[i] * row[j];
    }
    for (G = 0; G < gc; ++G)
        for (H = 0; H < gc; ++H)
            printf("%s %s %.6f\n", w.scene->mesh_names[G][0] ? w.scene->mesh_names[G] : "-",
                   w.scene->mesh_names[H][0] ? w.scene->mesh_names[H] : "-",
                   den[G] > 0.0 ? num[(size_t)G * gc + H] / den[G] : 0.0);
    free(num);
    free(den);
    rad_form_factors_destroy(ff);
    rad_patches_destroy(P);
    tool_close_world(&w);
    return 0;
}
