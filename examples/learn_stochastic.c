/* learn_stochastic.c - the noise of stochastic radiosity against the number of rays.

   Stochastic radiosity (docs/methods/stochastic.md) solves the patch system without a
   form-factor matrix: rays from uniform points of a patch in cosine-distributed directions land
   on patch j with probability F_ij, so shooting power along them estimates (rho o F) B. Its
   answer is random; its error is noise whose standard deviation falls as 1/sqrt(rays).
   For each ray count the program solves the Cornell box 4 times (seeds 1..4) with stochastic
   Jacobi and with random walks and prints
     rays     rays cast per solve (the whole solve: every iteration, every bounce)
     noise    the spread over the seeds: RMS over patches of the standard deviation, relative
              to the mean B
     error    RMS difference from the classic solution (dense F, direct solve) relative to the
              mean B: the noise plus the classic F's own small error
     x sqrt   noise times sqrt(rays): constant when the noise falls as 1/sqrt(rays)
   Usage: learn_stochastic [--patches N] [--max-rays R] (defaults 300 and 256000). */
#define RADIOSITY_IMPLEMENTATION
#include "radiosity.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SEEDS 4

int main(int argc, char **argv)
{
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    rad_patches *P = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_form_factors *ff = NULL;
    rad_patch_options po;
    rad_direct_options dopt;
    rad_solve_options so;
    rad_stochastic_options sto;
    rad_stochastic_stats st;
    rad_system sys;
    float *D, *E, *ref, *B[SEEDS];
    uint32_t patches = 300, max_rays = 256000, n, rays, s, m;
    size_t i;
    double meanB = 0.0;
    int a;
    for (a = 1; a + 1 < argc; a += 2) {
        if (!strcmp(argv[a], "--patches")) patches = (uint32_t)strtoul(argv[a + 1], NULL, 10);
        else if (!strcmp(argv[a], "--max-rays")) max_rays = (uint32_t)strtoul(argv[a + 1], NULL, 10);
    }
    if (patches < 10 || patches > 100000 || max_rays < 1000 || max_rays > 100000000u) {
        fprintf(stderr, "usage: learn_stochastic [--patches N in 10..100000] [--max-rays R in 1000..1e8]\n");
        return 2;
    }
    rad_cornell_box(&desc, NULL);
    rad_patch_options_default(&po);
    po.target_count = patches;
    if (rad_scene_create(&desc, NULL, &scene) != RAD_SUCCESS || rad_patches_create(scene, &po, NULL, &P) != RAD_SUCCESS ||
        rad_bvh_create(scene, NULL, &bvh) != RAD_SUCCESS)
        return 1;
    rad_bvh_raycaster(bvh, &rc);
    n = P->count;
    D = (float *)malloc(3 * sizeof(float) * n);
    E = (float *)malloc(3 * sizeof(float) * n);
    ref = (float *)malloc(3 * sizeof(float) * n);
    for (s = 0; s < SEEDS; ++s) B[s] = (float *)malloc(3 * sizeof(float) * n);
    if (!D || !E || !ref || !B[SEEDS - 1]) return 1;
    /* E = rho D, the direct light as the source (what an engine bakes), and the classic answer */
    rad_direct_options_default(&dopt);
    if (rad_direct_patches(P, &rc, NULL, 0, &dopt, D, NULL) != RAD_SUCCESS || rad_sources(P, RAD_SOURCE_DIRECT, D, E) != RAD_SUCCESS ||
        rad_form_factors_dense(P, &rc, NULL, NULL, &ff) != RAD_SUCCESS)
        return 1;
    rad_system_init(&sys, &ff->matrix, P, E);
    rad_solve_options_default(&so);
    so.output = RAD_OUTPUT_TOTAL;
    if (rad_solve_direct(&sys, &so, ref, NULL) != RAD_SUCCESS) return 1;
    for (i = 0; i < 3 * (size_t)n; ++i) meanB += ref[i] / (3.0 * n);
    printf("Cornell box, %u patches, %d seeds per row; classic: %llu visibility rays for F\n", n, SEEDS,
           (unsigned long long)ff->rays_cast);
    for (m = 0; m < 2; ++m) {
        printf("\n%s\n%12s %10s %10s %10s\n", m ? "random walks (collision estimator)" : "stochastic Jacobi (shooting)",
               "rays", "noise", "error", "x sqrt");
        for (rays = 1000; rays <= max_rays; rays *= 4) {
            double noise = 0.0, err = 0.0;
            rad_stochastic_options_default(&sto);
            sto.method = m ? RAD_STOCHASTIC_WALK : RAD_STOCHASTIC_JACOBI;
            sto.output = RAD_OUTPUT_TOTAL;
            sto.rays = rays;
            for (s = 0; s < SEEDS; ++s) {
                sto.seed = s + 1;
                if (rad_solve_stochastic(P, &rc, E, &sto, B[s], &st, NULL) != RAD_SUCCESS) return 1;
            }
            for (i = 0; i < 3 * (size_t)n; ++i) {
                double mu = 0.0, var = 0.0;
                for (s = 0; s < SEEDS; ++s) mu += B[s][i] / (double)SEEDS;
                for (s = 0; s < SEEDS; ++s) var += (B[s][i] - mu) * (B[s][i] - mu) / (SEEDS - 1.0);
                noise += var;
                for (s = 0; s < SEEDS; ++s) err += (B[s][i] - ref[i]) * (B[s][i] - ref[i]) / (double)SEEDS;
            }
            noise = sqrt(noise / (3.0 * n)) / meanB;
            err = sqrt(err / (3.0 * n)) / meanB;
            printf("%12llu %10.4f %10.4f %10.2f\n", (unsigned long long)st.rays_cast, noise, err,
                   noise * sqrt((double)st.rays_cast));
        }
    }
    printf("\nFour times the rays halve the noise. The classic solution cast its rays once for F and\n"
           "then solves exactly; the stochastic one never stores F (memory O(N), not O(N^2)).\n");
    for (s = 0; s < SEEDS; ++s) free(B[s]);
    free(D); free(E); free(ref);
    rad_form_factors_destroy(ff);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(P);
    rad_scene_destroy(scene);
    return 0;
}
