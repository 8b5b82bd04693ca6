/* learn_vertex_light.c - bounced light at the vertices of an engine's own meshes, step by
   step with the lower-level calls (examples/engine_bake.c does the same in one call,
   rad_baker_run). The meshes are the built-in Cornell box's (any rad_mesh_desc works), lit by
   its emissive ceiling light and one point light of the engine's; direct light is the source
   (RAD_SOURCE_DIRECT), and the irradiance from bounced light comes back per vertex of each
   mesh, in the mesh's own vertex order. Prints the mean per mesh and checks that every value
   is finite and >= 0 (exit 1 if not). */
#define RADIOSITY_IMPLEMENTATION
#include "radiosity.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int ok(rad_result r, const char *what)
{
    if (r != RAD_SUCCESS) fprintf(stderr, "%s: %s\n", what, rad_result_string(r));
    return r == RAD_SUCCESS;
}

int main(void)
{
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    rad_patches *patches = NULL;
    rad_bvh *bvh = NULL;
    rad_form_factors *ff = NULL;
    rad_patch_options popt;
    rad_form_factor_options fopt;
    rad_direct_options dopt;
    rad_solve_options sopt;
    rad_raycaster rc;
    rad_system sys;
    rad_light lamp;
    float *D = NULL, *E = NULL, *L = NULL, *EL = NULL, *H = NULL, *S = NULL, *Hp = NULL, *out = NULL;
    uint32_t i, m, n, bad = 0;
    int status = 1;

    rad_cornell_box(&desc, NULL);                             /* the engine's meshes */
    memset(&lamp, 0, sizeof lamp);                            /* and one light of its own */
    lamp.type = RAD_LIGHT_POINT;
    lamp.position[0] = 0.28f; lamp.position[1] = 0.35f; lamp.position[2] = 0.28f;
    lamp.color[0] = lamp.color[1] = lamp.color[2] = 0.05f;    /* W/sr */

    if (!ok(rad_scene_create(&desc, NULL, &scene), "rad_scene_create")) goto done;
    rad_patch_options_default(&popt);
    popt.target_count = 800;
    if (!ok(rad_patches_create(scene, &popt, NULL, &patches), "rad_patches_create")) goto done;
    if (!ok(rad_bvh_create(scene, NULL, &bvh), "rad_bvh_create")) goto done;
    rad_bvh_raycaster(bvh, &rc);
    rad_form_factor_options_default(&fopt);
    if (!ok(rad_form_factors_dense(patches, &rc, &fopt, NULL, &ff), "rad_form_factors_dense")) goto done;

    n = patches->count;
    D = (float *)malloc(sizeof(float) * 3 * n);
    E = (float *)malloc(sizeof(float) * 3 * n);
    L = (float *)malloc(sizeof(float) * 3 * n);
    EL = (float *)malloc(sizeof(float) * 3 * n);
    H = (float *)malloc(sizeof(float) * 3 * n);
    S = (float *)malloc(sizeof(float) * n);
    Hp = (float *)malloc(sizeof(float) * 3 * patches->vertex_count);
    out = (float *)malloc(sizeof(float) * 3 * 64);            /* the box's meshes have few vertices */
    if (!D || !E || !L || !EL || !H || !S || !Hp || !out) goto done;

    rad_direct_options_default(&dopt);                        /* emissive triangles + the lamp */
    if (!ok(rad_direct_patches(patches, &rc, &lamp, 1, &dopt, D, NULL), "rad_direct_patches")) goto done;
    if (!ok(rad_sources(patches, RAD_SOURCE_DIRECT, D, E), "rad_sources")) goto done;
    rad_system_init(&sys, &ff->matrix, patches, E);
    rad_solve_options_default(&sopt);                         /* output: the indirect light L */
    if (!ok(rad_solve_jacobi(&sys, &sopt, L, NULL, NULL), "rad_solve_jacobi")) goto done;
    for (i = 0; i < 3 * n; ++i) EL[i] = 1.0f;                 /* row sums: how much each patch sees */
    if (!ok(rad_matrix_multiply(&ff->matrix, EL, H, NULL), "rad_matrix_multiply")) goto done;
    for (i = 0; i < n; ++i) S[i] = H[3 * i];
    for (i = 0; i < 3 * n; ++i) EL[i] = E[i] + L[i];          /* H = F (E + L) */
    if (!ok(rad_matrix_multiply(&ff->matrix, EL, H, NULL), "rad_matrix_multiply")) goto done;
    if (!ok(rad_patches_vertex_irradiance(patches, H, S, Hp, NULL), "rad_patches_vertex_irradiance")) goto done;

    for (m = 0; m < desc.mesh_count; ++m) {
        const rad_mesh_desc *mesh = &desc.meshes[m];
        double mean[3] = { 0, 0, 0 };
        if (mesh->vertex_count > 64) continue;
        if (!ok(rad_patches_gather_mesh(patches, Hp, m, mesh, out, NULL), "rad_patches_gather_mesh")) goto done;
        for (i = 0; i < 3 * mesh->vertex_count; ++i) {
            mean[i % 3] += out[i] / mesh->vertex_count;
            bad += !(out[i] >= 0.0f && out[i] < 1e30f);
        }
        printf("%-10s %2u vertices, mean bounced irradiance %.4f %.4f %.4f W/m^2\n", mesh->name ? mesh->name : "",
               mesh->vertex_count, mean[0], mean[1], mean[2]);
    }
    status = bad ? 1 : 0;
    if (bad) fprintf(stderr, "%u values not finite or negative\n", bad);
done:
    free(D); free(E); free(L); free(EL); free(H); free(S); free(Hp); free(out);
    rad_form_factors_destroy(ff);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(patches);
    rad_scene_destroy(scene);
    return status;
}
