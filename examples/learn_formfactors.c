/* learn_formfactors.c - the form factor between two patches, three ways, against the closed form.

   Two unit squares face each other at distance 1 (Howell's catalogue, C-11: identical parallel
   opposed rectangles), each square one mesh of two triangles. The form factor F_12 is the
   fraction of the light leaving square 1 that reaches square 2:
       F_12 = 1/A_1 Int_A1 Int_A2 cos(t1) cos(t2) / (pi r^2) dA2 dA1.
   radiosity.h computes it three ways (docs/methods/formfactor-*.md):
     analytic     the inner integral in closed form (Lambert's contour integral) at n x n points
                  of the emitter: accurate already at one point per triangle here;
     Monte Carlo  'samples' point pairs (lattice points on the emitter, Hammersley points rotated
                  by the seed on the receiver), the kernel cos cos / (pi r^2) averaged: no contour
                  integral, and an error that the seed moves and the samples shrink;
     hemicube     a hemicube at each triangle's centroid (Cohen and Greenberg 1985): cells of
                  the item buffer times delta form factors. Its error falls with the resolution
                  down to the centroid's point-to-area value, not the area average.
   Usage: learn_formfactors (no arguments). Prints one line per method and setting. */
#define RADIOSITY_IMPLEMENTATION
#include "radiosity.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

static const float quads[2][12] = {
    { 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0 },  /* z = 0, front (counter-clockwise) facing +z */
    { 0, 0, 1, 0, 1, 1, 1, 1, 1, 1, 0, 1 }   /* z = 1, facing -z */
};
static const uint32_t quad_idx[6] = { 0, 1, 2, 0, 2, 3 };

/* Howell C-11 for a x b rectangles at gap c */
static double c11(double a, double b, double c)
{
    double X = a / c, Y = b / c, pi = 3.14159265358979323846;
    return 2.0 / (pi * X * Y) *
           (log(sqrt((1 + X * X) * (1 + Y * Y) / (1 + X * X + Y * Y))) + X * sqrt(1 + Y * Y) * atan(X / sqrt(1 + Y * Y)) +
            Y * sqrt(1 + X * X) * atan(Y / sqrt(1 + X * X)) - X * atan(X) - Y * atan(Y));
}

/* F from square 1 (mesh 0) to square 2 (mesh 1): area-weighted sum over the triangle patches */
static double square_ff(const rad_patches *P, const rad_raycaster *rc, const rad_form_factor_options *o)
{
    rad_form_factors *ff = NULL;
    double num = 0.0, den = 0.0;
    uint32_t i, j, n = P->count;
    if (rad_form_factors_dense(P, rc, o, NULL, &ff) != RAD_SUCCESS) return -1.0;
    for (i = 0; i < n; ++i) {
        if (P->scene->meshes[P->patches[i].triangle] != 0) continue;
        for (j = 0; j < n; ++j)
            if (P->scene->meshes[P->patches[j].triangle] == 1)
                num += P->patches[i].area * (double)ff->matrix.dense[(size_t)i * n + j];
        den += P->patches[i].area;
    }
    rad_form_factors_destroy(ff);
    return num / den;
}

int main(void)
{
    rad_mesh_desc meshes[2];
    rad_material mat;
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    rad_patches *P = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_form_factor_options o;
    double exact = c11(1.0, 1.0, 1.0), f;
    static const uint32_t analytic[3] = { 1, 16, 256 }, mc[3] = { 1, 4, 16 }, hemi[4] = { 8, 32, 128, 512 };
    uint32_t k, seed;
    int m;
    memset(meshes, 0, sizeof(meshes));
    memset(&mat, 0, sizeof(mat));
    memset(&desc, 0, sizeof(desc));
    for (m = 0; m < 2; ++m) {
        meshes[m].name = m ? "top" : "bottom";
        meshes[m].positions = quads[m];
        meshes[m].vertex_count = 4;
        meshes[m].indices = quad_idx;
        meshes[m].triangle_count = 2;
    }
    mat.albedo[0] = mat.albedo[1] = mat.albedo[2] = 0.5f;
    desc.meshes = meshes;
    desc.mesh_count = 2;
    desc.materials = &mat;
    desc.material_count = 1;
    if (rad_scene_create(&desc, NULL, &scene) != RAD_SUCCESS || rad_patches_create(scene, NULL, NULL, &P) != RAD_SUCCESS ||
        rad_bvh_create(scene, NULL, &bvh) != RAD_SUCCESS) {
        fprintf(stderr, "learn_formfactors: cannot build the scene\n");
        return 1;
    }
    rad_bvh_raycaster(bvh, &rc);
    printf("two unit squares at distance 1 (%u triangle patches); closed form (Howell C-11) F_12 = %.6f\n\n", P->count, exact);
    printf("%-12s %-22s %10s %10s\n", "method", "setting", "F_12", "rel. error");
    rad_form_factor_options_default(&o);
    for (k = 0; k < 3; ++k) {
        o.method = RAD_FF_ANALYTIC;
        o.samples = analytic[k];
        f = square_ff(P, &rc, &o);
        printf("%-12s %4u points per pair    %10.6f %+10.2e\n", "analytic", analytic[k], f, f / exact - 1.0);
    }
    for (k = 0; k < 3; ++k) {
        /* Monte Carlo is random: the spread over seeds shows the 1/sqrt(samples) noise */
        double sum = 0.0, sum2 = 0.0;
        for (seed = 0; seed < 8; ++seed) {
            o.method = RAD_FF_MONTE_CARLO;
            o.samples = mc[k];
            o.seed = seed;
            f = square_ff(P, &rc, &o);
            sum += f;
            sum2 += f * f;
        }
        f = sum / 8.0;
        printf("%-12s %4u pairs (8 seeds)    %10.6f %+10.2e  (spread %.2e)\n", "Monte Carlo", 16u * mc[k], f, f / exact - 1.0,
               sqrt(sum2 / 8.0 - f * f > 0.0 ? sum2 / 8.0 - f * f : 0.0) / exact);
    }
    o.seed = 0;
    for (k = 0; k < 4; ++k) {
        o.method = RAD_FF_HEMICUBE;
        o.hemicube_resolution = hemi[k];
        f = square_ff(P, NULL, &o);
        printf("%-12s %4u x %-4u cells       %10.6f %+10.2e\n", "hemicube", hemi[k], hemi[k], f, f / exact - 1.0);
    }
    for (k = 0, f = 0.0; k < P->count; ++k) /* the limit of the hemicube: point to area at the centroids */
        if (P->scene->meshes[P->patches[k].triangle] == 0)
            f += P->patches[k].area * rad_ff_point_polygon(P->patches[k].centroid, P->patches[k].normal, quads[1], 4);
    printf("%-12s %-22s %10.6f %+10.2e\n", "centroids", "point to area, exact", f, f / exact - 1.0);
    printf("\nMonte Carlo takes 16x the pairs asked for patches this close (at most 256). The hemicube\n"
           "converges to the centroids' point-to-area value, not the area average: split the squares into\n"
           "smaller patches (more centroids) to bring it to the area average.\n");
    rad_bvh_destroy(bvh);
    rad_patches_destroy(P);
    rad_scene_destroy(scene);
    return 0;
}
