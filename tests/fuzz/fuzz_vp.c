/* fuzz_vp.c - libFuzzer harness for the virtual-patch loader (rad_vp_load: the sets that
   rad bake --method aavp|vp saves). The input goes to rad_container_create (copied into an
   aligned buffer, as a mapped file would be), then a second copy with recomputed checksums
   (fuzz_common.h), so mutations reach the loader's structural, index and value checks. Every
   set a VP_INFO section names (up to 4 per input) is loaded twice: without a scene, and
   against the built-in Cornell box (the scene the seeds were built from, so sample triangles
   are checked against a real triangle count). Each set that loads with the scene is used:
   - solved: three Jacobi bounces of rad_vp_system with a unit source;
   - gathered at 8 fixed points and normals, directly and through a gather table (whose
     entries must name patches below N), and per vertex of the box's first mesh;
   - E from per-sample values (rad_vp_from_samples) and from the scene's emission;
   - a round trip: written through rad_vp_sections into a new container, reopened and loaded
     again, which must give the same bits.
   Outputs must be finite whenever the loaded matrix is tame (fuzz_bounded); loaded sets
   with huge values are counted, not a crash.
   Build: clang -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -I. tests/fuzz/fuzz_vp.c */
#define RADIOSITY_IMPLEMENTATION
#include "../../radiosity.h"
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define FUZZ_MAX_SETS 4u
#define FUZZ_POINTS 8u
#define FUZZ_TAME 1e3f /* matrix entries up to this: three bounces stay far from FLT_MAX */

static rad_scene *fuzz_vp_scene;
static rad_scene_desc fuzz_vp_desc;

static const rad_scene *box_scene(void)
{
    if (!fuzz_vp_scene) {
        rad_cornell_box(&fuzz_vp_desc, NULL);
        if (rad_scene_create(&fuzz_vp_desc, NULL, &fuzz_vp_scene) != RAD_SUCCESS) abort();
    }
    return fuzz_vp_scene;
}

/* 1 when the two sets hold the same bits in every array the sections carry */
static int same_set(const rad_virtual_patches *a, const rad_virtual_patches *b)
{
    size_t N = a->count, M = a->sample_count, V = a->voxel_count, nnz;
    if (b->count != a->count || b->sample_count != a->sample_count || b->voxel_count != a->voxel_count ||
        b->kind != a->kind || b->weights != a->weights || b->matrix.storage != a->matrix.storage)
        return 0;
    if (memcmp(a->areas, b->areas, 4 * N) || memcmp(a->albedo, b->albedo, 12 * N) || memcmp(a->axis, b->axis, N) ||
        memcmp(a->voxel, b->voxel, 4 * N) || memcmp(a->voxel_keys, b->voxel_keys, 8 * V) ||
        memcmp(a->voxel_first, b->voxel_first, 4 * (V + 1)) || memcmp(a->voxel_patch, b->voxel_patch, 24 * V) ||
        memcmp(a->sample_first, b->sample_first, 4 * (V + 1)) || memcmp(a->sample_areas, b->sample_areas, 4 * M) ||
        memcmp(a->sample_weights, b->sample_weights, 24 * M) || memcmp(a->sample_triangles, b->sample_triangles, 4 * M))
        return 0;
    if (a->matrix.storage == RAD_STORAGE_SPARSE) {
        nnz = a->matrix.row_offsets[N];
        return !memcmp(a->matrix.row_offsets, b->matrix.row_offsets, 4 * (N + 1)) &&
               !memcmp(a->matrix.columns, b->matrix.columns, 4 * nnz) && !memcmp(a->matrix.values, b->matrix.values, 4 * nnz);
    }
    return !memcmp(a->matrix.dense, b->matrix.dense, 4 * N * N);
}

static void round_trip(const rad_virtual_patches *vp, const char *name)
{
    rad_section sec[RAD_VP_MAX_SECTIONS];
    uint32_t count = 0;
    size_t bytes;
    void *buf;
    rad_container *ct = NULL;
    rad_virtual_patches *again = NULL;
    if (rad_vp_sections(vp, name, sec, &count) != RAD_SUCCESS || rad_container_size(sec, count, &bytes) != RAD_SUCCESS) abort();
    buf = malloc(bytes);
    if (!buf) return;
    if (rad_container_write(sec, count, buf, bytes) != RAD_SUCCESS || rad_container_create(buf, bytes, NULL, &ct) != RAD_SUCCESS ||
        rad_vp_load(ct, name, vp->scene, NULL, &again) != RAD_SUCCESS || !same_set(vp, again))
        abort();
    rad_vp_destroy(again);
    rad_container_destroy(ct);
    free(buf);
}

static void use_set(const rad_virtual_patches *vp, const char *name)
{
    uint32_t N = vp->count, M = vp->sample_count, i;
    size_t nnz = vp->matrix.storage == RAD_STORAGE_SPARSE ? vp->matrix.row_offsets[N] : (size_t)N * N;
    int tame = fuzz_bounded(vp->matrix.storage == RAD_STORAGE_SPARSE ? vp->matrix.values : vp->matrix.dense, nnz, FUZZ_TAME);
    float *E = fuzz_fill(3 * (size_t)N, 1.0f), *B = fuzz_fill(3 * (size_t)N, 0.0f), *S = fuzz_fill(3 * (size_t)M, 1.0f);
    const rad_mesh_desc *mesh = &fuzz_vp_desc.meshes[0];
    float *V = fuzz_fill(3 * (size_t)mesh->vertex_count, 0.0f);
    float pts[3 * FUZZ_POINTS], nrm[3 * FUZZ_POINTS], out[3 * FUZZ_POINTS], out2[3 * FUZZ_POINTS];
    rad_system sys;
    rad_solve_options so;
    rad_vp_gather_table *tab = NULL;
    if (!tame) fuzz_untamed("virtual-patch matrix entries above 1e3");
    if (!E || !B || !S || !V) goto done;
    for (i = 0; i < FUZZ_POINTS; ++i) {
        pts[3 * i] = 0.5f + 0.1f * (float)i - 0.4f;
        pts[3 * i + 1] = (i & 2) ? 0.01f : 0.5f;
        pts[3 * i + 2] = 0.1f * (float)(i % 5);
        nrm[3 * i] = (i & 4) ? 1.0f : 0.0f;
        nrm[3 * i + 1] = (i & 4) ? 0.0f : ((i & 1) ? 1.0f : -1.0f);
        nrm[3 * i + 2] = 0.0f;
    }
    rad_vp_system(&sys, vp, E);
    rad_solve_options_default(&so);
    so.bounces = 3;
    if (rad_solve_jacobi(&sys, &so, B, NULL, NULL) == RAD_SUCCESS && tame) fuzz_check_finite(B, 3 * (size_t)N);
    /* the gathers blend values with convex weights: finite values give finite outputs */
    if (rad_vp_gather(vp, E, pts, nrm, FUZZ_POINTS, out, NULL) == RAD_SUCCESS) fuzz_check_finite(out, 3 * FUZZ_POINTS);
    if (rad_vp_gather_table_create(vp, pts, nrm, FUZZ_POINTS, NULL, &tab) == RAD_SUCCESS) {
        for (i = 0; i < tab->offsets[tab->count]; ++i)
            if (tab->patch[i] >= N) abort();
        if (rad_vp_gather_table_apply(tab, E, out2, NULL) == RAD_SUCCESS) fuzz_check_finite(out2, 3 * FUZZ_POINTS);
        rad_vp_gather_table_destroy(tab);
    }
    if (rad_vp_gather_mesh(vp, E, mesh, V, NULL) == RAD_SUCCESS) fuzz_check_finite(V, 3 * (size_t)mesh->vertex_count);
    (void)rad_vp_from_samples(vp, S, E);
    (void)rad_vp_sources(vp, NULL, NULL, 0, NULL, RAD_SOURCE_EMISSION, E, NULL);
    round_trip(vp, name);
done:
    free(E);
    free(B);
    free(S);
    free(V);
}

static void exercise(const void *buf, size_t size)
{
    rad_container *ct = NULL;
    uint32_t i, n, sets = 0;
    if (rad_container_create(buf, size, NULL, &ct) != RAD_SUCCESS) return;
    n = rad_container_section_count(ct);
    for (i = 0; i < n && sets < FUZZ_MAX_SETS; ++i) {
        const rad_section *s = rad_container_section(ct, i);
        rad_virtual_patches *vp = NULL;
        char name[sizeof(s->name) + 1];
        if (s->type != RAD_SECTION_VP_INFO) continue;
        memcpy(name, s->name, sizeof(s->name));
        name[sizeof(s->name)] = 0;
        sets++;
        if (rad_vp_load(ct, name, NULL, NULL, &vp) == RAD_SUCCESS) rad_vp_destroy(vp);
        vp = NULL;
        if (rad_vp_load(ct, name, box_scene(), NULL, &vp) == RAD_SUCCESS) {
            use_set(vp, name);
            rad_vp_destroy(vp);
        }
    }
    rad_container_destroy(ct);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    void *buf = malloc(size ? size : 1);
    if (!buf) return 0;
    if (size) memcpy(buf, data, size);
    exercise(buf, size);
    if (size) memcpy(buf, data, size);
    fuzz_fix_checksums((unsigned char *)buf, size);
    exercise(buf, size);
    free(buf);
    return 0;
}
