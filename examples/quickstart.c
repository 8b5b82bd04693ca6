/* quickstart.c - the smallest complete use of radiosity.h, as in the README: the built-in
   Cornell box, about 1000 patches, form factors with the built-in BVH, emission as the
   source, 16 Jacobi bounces, and the radiosity of a few patches printed. */
#define RADIOSITY_IMPLEMENTATION
#include "radiosity.h"
#include <stdio.h>
#include <stdlib.h>

int main(void)
{
    rad_scene_desc desc;
    rad_camera cam;
    rad_scene *scene = NULL;
    rad_patches *patches = NULL;
    rad_bvh *bvh = NULL;
    rad_form_factors *ff = NULL;
    rad_patch_options popt;
    rad_form_factor_options fopt;
    rad_solve_options sopt;
    rad_raycaster rc;
    rad_system sys;
    float *E, *B;
    uint32_t i;

    rad_cornell_box(&desc, &cam);                             // built-in scene (static data)
    if (rad_scene_create(&desc, NULL, &scene) != RAD_SUCCESS) return 1;
    rad_patch_options_default(&popt);
    popt.target_count = 1000;                                 // about 1000 patches
    if (rad_patches_create(scene, &popt, NULL, &patches) != RAD_SUCCESS) return 1;
    if (rad_bvh_create(scene, NULL, &bvh) != RAD_SUCCESS) return 1;
    rad_bvh_raycaster(bvh, &rc);                              // or plug in your own tracer
    rad_form_factor_options_default(&fopt);
    if (rad_form_factors_dense(patches, &rc, &fopt, NULL, &ff) != RAD_SUCCESS) return 1;

    E = (float *)malloc(sizeof(float) * 3 * patches->count);
    B = (float *)malloc(sizeof(float) * 3 * patches->count);
    if (!E || !B) return 1;
    rad_sources(patches, RAD_SOURCE_EMISSION, NULL, E);       // E = pi * emitted radiance
    rad_system_init(&sys, &ff->matrix, patches, E);
    rad_solve_options_default(&sopt);
    sopt.output = RAD_OUTPUT_TOTAL;                           // B = E + L_16
    sopt.bounces = 16;
    if (rad_solve_jacobi(&sys, &sopt, B, NULL, NULL) != RAD_SUCCESS) return 1;

    for (i = 0; i < patches->count; i += patches->count / 4)
        printf("patch %4u on '%s': B = %.3f %.3f %.3f W/m^2\n", i,
               scene->mesh_names[scene->meshes[patches->patches[i].triangle]], B[3 * i], B[3 * i + 1], B[3 * i + 2]);

    free(E);
    free(B);
    rad_form_factors_destroy(ff);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(patches);
    rad_scene_destroy(scene);
    return 0;
}
