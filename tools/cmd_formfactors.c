/* cmd_formfactors.c - rad formfactors: group form factors between the scene's named objects
   (the area-weighted mean of the patch form factors from one group to another). */
#include "tool.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void formfactors_usage(FILE *f)
{
    fprintf(f, "usage: rad formfactors SCENE [--patches N] [--max-edge L] [--samples S] [--ff M] [--hemicube-res R]\n"
               "                        [--max-memory SIZE] [--force] [--threads N]\n"
               "Prints one line 'FROM TO VALUE' per ordered pair of named objects: the area-weighted\n"
               "group form factor F_GH = sum_{i in G} A_i sum_{j in H} F_ij / sum_{i in G} A_i.\n"
               "  --patches N   target patch count (default 2000)\n"
               "  --max-edge L  longest patch edge (default: no limit)\n"
               "  --samples S   points per patch pair (default 16, up to 256; analytic and montecarlo)\n"
               "  --ff M        analytic (default: the point-to-polygon integral at S points of the other\n"
               "                patch, one visibility ray each), montecarlo (S point pairs) or hemicube\n"
               "                (a hemicube at each patch centroid with an item buffer; no rays)\n"
               "  --hemicube-res R  cells across the hemicube's top face (default 128; even, 4 to 2048)\n"
               "  --max-memory SIZE, --force   the dense build's limit (rad render --help)\n"
               "  --threads N   worker threads (default: all cores; at most 1024)\n");
}

/* ---- formfactors ----------------------------------------------------------------------- */

int tool_cmd_formfactors(int argc, char **argv)
{
    const char *scene_name = NULL, *cmd = "formfactors";
    uint32_t patches_target = 2000, samples = 16, threads = 0, G, H, i, j, gc, hemicube_res = 0;
    rad_ff_method ff_method = RAD_FF_ANALYTIC;
    float max_edge = 0.0f;
    tool_world w;
    rad_patches *P = NULL;
    rad_form_factors *ff = NULL;
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_context ctx;
    rad_result r;
    double *num, *den;
    int a;
    tool_classic_options budget;
    tool_classic_options_default(&budget);
    for (a = 0; a < argc; ++a) {
        const char *o = argv[a];
        int need = !strcmp(o, "--patches") || !strcmp(o, "--samples") || !strcmp(o, "--threads") || !strcmp(o, "--max-edge") ||
                   !strcmp(o, "--ff") || !strcmp(o, "--hemicube-res");
        if (!strcmp(o, "--help") || !strcmp(o, "-h")) { formfactors_usage(stdout); return 0; }
        if (!strcmp(o, "--force")) { budget.force = 1; continue; }
        if (!strcmp(o, "--max-memory")) {
            if (a + 1 >= argc) { fprintf(stderr, "rad %s: %s needs a value\n", cmd, o); return 2; }
            if (tool_parse_bytes(cmd, o, argv[++a], &budget.max_memory)) return 2;
            continue;
        }
        if (need && a + 1 >= argc) { fprintf(stderr, "rad %s: %s needs a value\n", cmd, o); return 2; }
        if (!strcmp(o, "--patches")) { if (tool_parse_uint(cmd, o, argv[++a], &patches_target)) return 2; }
        else if (!strcmp(o, "--samples")) { if (tool_parse_uint(cmd, o, argv[++a], &samples)) return 2; }
        else if (!strcmp(o, "--threads")) { if (tool_parse_threads(cmd, o, argv[++a], &threads)) return 2; }
        else if (!strcmp(o, "--max-edge")) { if (tool_parse_float(cmd, o, argv[++a], &max_edge)) return 2; }
        else if (!strcmp(o, "--hemicube-res")) { if (tool_parse_uint(cmd, o, argv[++a], &hemicube_res)) return 2; }
        else if (!strcmp(o, "--ff")) {
            const char *m = argv[++a];
            if (!strcmp(m, "analytic")) ff_method = RAD_FF_ANALYTIC;
            else if (!strcmp(m, "montecarlo") || !strcmp(m, "monte-carlo")) ff_method = RAD_FF_MONTE_CARLO;
            else if (!strcmp(m, "hemicube")) ff_method = RAD_FF_HEMICUBE;
            else { fprintf(stderr, "rad %s: unknown --ff '%s' (analytic, montecarlo or hemicube)\n", cmd, m); return 2; }
        }
        else if (o[0] == '-' && o[1]) { fprintf(stderr, "rad %s: unknown option '%s'\n", cmd, o); return 2; }
        else if (!scene_name) scene_name = o;
        else { fprintf(stderr, "rad %s: more than one scene given\n", cmd); return 2; }
    }
    if (!scene_name) { fprintf(stderr, "rad %s: no scene given\n", cmd); formfactors_usage(stderr); return 2; }
    if (samples == 0 || max_edge < 0.0f) { fprintf(stderr, "rad %s: --samples must be > 0, --max-edge >= 0\n", cmd); return 2; }
    tool_set_threads((int)threads);
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
