/* fuzz_scene.c - libFuzzer harness for scene creation from raw bytes interpreted as arrays.
   The input is read as: counts (meshes, materials, vertices, triangles, a patch target), then
   raw float bits for materials and positions (NaN, Inf and denormals included) and raw index
   bytes (often out of range). Whatever rad_scene_create accepts then goes through patches,
   the BVH, form factors, direct light and two solvers; every output is scanned for NaN/Inf.
   Build: clang -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -I. tests/fuzz/fuzz_scene.c */
#define RADIOSITY_IMPLEMENTATION
#include "../../radiosity.h"
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

typedef struct reader { const uint8_t *p; size_t n; } reader;
static uint8_t rd8(reader *r) { uint8_t v = 0; if (r->n) { v = *r->p++; r->n--; } return v; }
static float rdf(reader *r)
{
    uint32_t u = (uint32_t)rd8(r) | (uint32_t)rd8(r) << 8 | (uint32_t)rd8(r) << 16 | (uint32_t)rd8(r) << 24;
    float f;
    memcpy(&f, &u, 4);
    return f;
}

static void check_finite(const float *v, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i)
        if (!(v[i] == v[i]) || v[i] - v[i] != 0.0f) abort(); /* a NaN or Inf reached an output */
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    reader r;
    rad_mesh_desc meshes[3];
    rad_material mats[4];
    float pos[3][3 * 48];
    uint32_t idx[3][3 * 32], mids[3][32];
    rad_scene_desc d;
    rad_scene *scene = NULL;
    uint32_t nm, nmat, m, i, target;
    r.p = data;
    r.n = size;
    memset(meshes, 0, sizeof(meshes));
    memset(&d, 0, sizeof(d));
    nm = 1 + rd8(&r) % 3;
    nmat = rd8(&r) % 5;
    target = 1 + rd8(&r) % 200;
    d.flags = rd8(&r) & 1u;
    for (m = 0; m < nmat; ++m) {
        int k;
        for (k = 0; k < 3; ++k) mats[m].albedo[k] = rdf(&r);
        for (k = 0; k < 3; ++k) mats[m].emission[k] = rdf(&r);
        mats[m].texture = 0;
        mats[m].two_sided = 0;
        mats[m].emission_texture = 0;
        mats[m].opacity_texture = 0;
        mats[m].alpha_cutoff = 0.0f;
    }
    for (m = 0; m < nm; ++m) {
        uint32_t nv = rd8(&r) % 49, nt = rd8(&r) % 33, use_ids = rd8(&r) & 1u;
        for (i = 0; i < 3 * nv; ++i) pos[m][i] = rdf(&r);
        for (i = 0; i < 3 * nt; ++i) idx[m][i] = rd8(&r) % (nv + 2u);
        for (i = 0; i < nt; ++i) mids[m][i] = rd8(&r) % (nmat + 1u);
        meshes[m].positions = nv ? pos[m] : NULL;
        meshes[m].vertex_count = nv;
        meshes[m].indices = idx[m];
        meshes[m].triangle_count = nt;
        meshes[m].material_ids = use_ids ? mids[m] : NULL;
        meshes[m].material = rd8(&r) % (nmat + 1u);
    }
    d.meshes = meshes;
    d.mesh_count = nm;
    d.materials = nmat ? mats : NULL;
    d.material_count = nmat;
    if (rad_scene_create(&d, NULL, &scene) == RAD_SUCCESS) {
        rad_patches *P = NULL;
        rad_bvh *bvh = NULL;
        rad_patch_options po;
        rad_patch_options_default(&po);
        po.target_count = target;
        check_finite(scene->positions, 9 * (size_t)scene->triangle_count);
        check_finite(scene->normals, 3 * (size_t)scene->triangle_count);
        check_finite(scene->areas, scene->triangle_count);
        if (rad_patches_create(scene, &po, NULL, &P) == RAD_SUCCESS && P->count <= 400 &&
            rad_bvh_create(scene, NULL, &bvh) == RAD_SUCCESS) {
            rad_raycaster rc;
            rad_form_factors *ff = NULL;
            rad_form_factor_options fo;
            rad_light light;
            float *D = (float *)malloc(sizeof(float) * 3 * P->count), *E = (float *)malloc(sizeof(float) * 3 * P->count);
            float *B = (float *)malloc(sizeof(float) * 3 * P->count);
            rad_direct_options dopt;
            check_finite(P->vertices, 3 * (size_t)P->vertex_count);
            check_finite(P->areas, P->count);
            rad_bvh_raycaster(bvh, &rc);
            rad_form_factor_options_default(&fo);
            fo.samples = 1;
            memset(&light, 0, sizeof(light));
            light.type = RAD_LIGHT_POINT;
            light.color[0] = light.color[1] = light.color[2] = 1.0f;
            light.position[0] = rdf(&r);
            light.position[1] = rdf(&r);
            light.position[2] = rdf(&r);
            rad_direct_options_default(&dopt);
            dopt.samples = 1;
            dopt.light_samples = 2;
            if (D && E && B && rad_form_factors_dense(P, &rc, &fo, NULL, &ff) == RAD_SUCCESS) {
                rad_system sys;
                rad_solve_options so;
                check_finite(ff->matrix.dense, (size_t)P->count * P->count);
                if (rad_direct_patches(P, &rc, &light, 1, &dopt, D, NULL) == RAD_SUCCESS) {
                    check_finite(D, 3 * (size_t)P->count);
                    if (rad_sources(P, RAD_SOURCE_DIRECT, D, E) == RAD_SUCCESS) {
                        check_finite(E, 3 * (size_t)P->count);
                        rad_system_init(&sys, &ff->matrix, P, E);
                        rad_solve_options_default(&so);
                        so.bounces = 3;
                        if (rad_solve_jacobi(&sys, &so, B, NULL, NULL) == RAD_SUCCESS) check_finite(B, 3 * (size_t)P->count);
                        so.max_iterations = 20;
                        if (rad_solve_gauss_seidel(&sys, &so, B, NULL, NULL) == RAD_SUCCESS) check_finite(B, 3 * (size_t)P->count);
                    }
                }
                rad_form_factors_destroy(ff);
            }
            free(D);
            free(E);
            free(B);
        }
        rad_bvh_destroy(bvh);
        rad_patches_destroy(P);
        rad_scene_destroy(scene);
    }
    return 0;
}
