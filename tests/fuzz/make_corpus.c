/* make_corpus.c - writes the fuzzers' seed corpora into DIR/<harness>/ (the folders must
   exist):
   - container: valid bakes of the Cornell box (dense and sparse, with and without vectors);
   - scene: scene inputs describing a quad and the Cornell box's first meshes in
     fuzz_scene.c's byte format;
   - stream: CSR bakes (what rad_row_stream_create reads), at two sizes;
   - multibounce: F_mb of a small Cornell box as saved by rad_multibounce_sections and
     rad_multibounce_blocks_sections: float, half with permutations, 3xBC4 with scale tiles,
     permutations and outliers, BC1 with one scale and none, BC1 with all of them, and one
     container holding several objects;
   - temporal: alias tables as saved by rad_alias_tables_sections: compact tables of the
     sparse F, wide tables of the dense F, and the three per-channel tables of F_mb
     (Fmb.r, Fmb.g, Fmb.b) in one container;
   - vp: virtual-patch sets of the Cornell box as saved by rad_vp_sections (a coarse grid so
     the inputs stay small): axis-aligned dense, axis-aligned CSR, clustered with cosine
     weights, and two sets in one container.
   Usage: make_corpus DIR */
#define RADIOSITY_IMPLEMENTATION
#include "../../radiosity.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void write_file(const char *dir, const char *name, const void *data, size_t size)
{
    char path[1024];
    FILE *f;
    snprintf(path, sizeof(path), "%s/%s", dir, name);
    f = fopen(path, "wb");
    if (!f) { fprintf(stderr, "cannot write %s\n", path); exit(1); }
    fwrite(data, 1, size, f);
    fclose(f);
}

static void write_sections(const char *dir, const char *name, const rad_section *s, uint32_t count)
{
    size_t size;
    void *buf;
    if (rad_container_size(s, count, &size) != RAD_SUCCESS || !(buf = malloc(size)) ||
        rad_container_write(s, count, buf, size) != RAD_SUCCESS) {
        fprintf(stderr, "cannot build %s/%s\n", dir, name);
        exit(1);
    }
    write_file(dir, name, buf, size);
    free(buf);
}

static void need(rad_result r, const char *what)
{
    if (r != RAD_SUCCESS) { fprintf(stderr, "make_corpus: %s: %s\n", what, rad_result_string(r)); exit(1); }
}

/* the multi-bounce and alias-table seeds, from a smaller Cornell box (fast inputs) */
static void write_method_seeds(const char *root, const rad_scene *s, const rad_raycaster *rc)
{
    char mdir[1024], tdir[1024];
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_patches *P = NULL;
    rad_form_factors *dense = NULL, *sparse = NULL;
    rad_multibounce *mb = NULL, *half = NULL, *perm = NULL;
    rad_multibounce_blocks *bc4 = NULL, *bc1 = NULL, *bc1p = NULL;
    rad_block_options bo;
    rad_alias_tables *compact = NULL, *wide = NULL, *ch[3] = { NULL, NULL, NULL };
    rad_section sec[4 * RAD_MB_MAX_SECTIONS];
    uint32_t k, total, c;
    static const char *const chname[3] = { "Fmb.r", "Fmb.g", "Fmb.b" };
    snprintf(mdir, sizeof(mdir), "%s/multibounce", root);
    snprintf(tdir, sizeof(tdir), "%s/temporal", root);
    rad_patch_options_default(&po);
    po.target_count = 12;
    need(rad_patches_create(s, &po, NULL, &P), "patches");
    rad_form_factor_options_default(&fo);
    fo.samples = 1;
    need(rad_form_factors_dense(P, rc, &fo, NULL, &dense), "dense form factors");
    fo.drop_threshold = 1e-3f;
    need(rad_form_factors_sparse(P, rc, &fo, NULL, &sparse), "sparse form factors");
    need(rad_multibounce_create(&dense->matrix, P->albedo, NULL, NULL, &mb), "F_mb");
    need(rad_multibounce_reorder(mb, 0, NULL, &perm), "reorder");
    need(rad_multibounce_convert(perm, RAD_MB_HALF, NULL, &half), "half");
    rad_block_options_default(&bo);
    bo.tile = 8;
    need(rad_multibounce_blocks_create(mb, &bo, NULL, &bc4, NULL), "3xBC4");
    bo.format = RAD_BLOCK_BC1;
    bo.tile = 0;
    bo.outlier_fraction = 0.0f;
    bo.reorder = RAD_REORDER_NONE;
    need(rad_multibounce_blocks_create(mb, &bo, NULL, &bc1, NULL), "BC1");
    bo.tile = 4;
    bo.outlier_fraction = 0.1f;
    bo.reorder = RAD_REORDER_GREEDY;
    need(rad_multibounce_blocks_create(mb, &bo, NULL, &bc1p, NULL), "BC1 with outliers");
    need(rad_multibounce_sections(mb, "Fmb", sec, &k), "sections");
    write_sections(mdir, "float.radb", sec, k);
    need(rad_multibounce_sections(half, "Fmb", sec, &k), "sections");
    write_sections(mdir, "half_perm.radb", sec, k);
    need(rad_multibounce_blocks_sections(bc4, "Fmb", sec, &k), "sections");
    write_sections(mdir, "bc4_tiles_perm_outliers.radb", sec, k);
    need(rad_multibounce_blocks_sections(bc1, "Fmb", sec, &k), "sections");
    write_sections(mdir, "bc1_plain.radb", sec, k);
    need(rad_multibounce_blocks_sections(bc1p, "Fmb", sec, &k), "sections");
    write_sections(mdir, "bc1_tiles_perm_outliers.radb", sec, k);
    total = 0;
    need(rad_multibounce_sections(mb, "Fmb", sec, &k), "sections");
    total += k;
    need(rad_multibounce_sections(half, "Fmb-half", sec + total, &k), "sections");
    total += k;
    need(rad_multibounce_blocks_sections(bc1, "Fmb-bc1", sec + total, &k), "sections");
    total += k;
    write_sections(mdir, "several.radb", sec, total);
    /* alias tables */
    need(rad_alias_tables_create(&sparse->matrix, RAD_ALIAS_AUTO, NULL, &compact), "compact alias tables");
    need(rad_alias_tables_create(&dense->matrix, RAD_ALIAS_WIDE, NULL, &wide), "wide alias tables");
    for (c = 0; c < 3; ++c)
        need(rad_alias_tables_create_dense(mb->planes + (size_t)c * mb->n * mb->n, mb->n, RAD_ALIAS_AUTO, NULL, &ch[c]),
             "per-channel alias tables");
    rad_alias_tables_sections(compact, "F", sec, NULL);
    write_sections(tdir, "compact.radb", sec, 3);
    rad_alias_tables_sections(wide, "F", sec, NULL);
    write_sections(tdir, "wide.radb", sec, 3);
    for (c = 0; c < 3; ++c) rad_alias_tables_sections(ch[c], chname[c], sec + 3 * c, NULL);
    write_sections(tdir, "fmb_channels.radb", sec, 9);
    for (c = 0; c < 3; ++c) rad_alias_tables_destroy(ch[c]);
    rad_alias_tables_destroy(compact);
    rad_alias_tables_destroy(wide);
    rad_multibounce_blocks_destroy(bc1p);
    rad_multibounce_blocks_destroy(bc1);
    rad_multibounce_blocks_destroy(bc4);
    rad_multibounce_destroy(half);
    rad_multibounce_destroy(perm);
    rad_multibounce_destroy(mb);
    rad_form_factors_destroy(dense);
    rad_form_factors_destroy(sparse);
    rad_patches_destroy(P);
}

/* the virtual-patch seeds: coarse sets of the Cornell box (2 voxels along its longest axis, one
   point per voxel face: inputs of a few kilobytes) */
static void write_vp_seeds(const char *root, const rad_scene *s, const rad_raycaster *rc)
{
    char dir[1024];
    rad_vp_options o;
    rad_virtual_patches *aa = NULL, *csr = NULL, *cl = NULL;
    rad_section sec[2 * RAD_VP_MAX_SECTIONS];
    uint32_t k, k2;
    snprintf(dir, sizeof(dir), "%s/vp", root);
    rad_vp_options_default(&o);
    o.resolution = 2;
    o.face_points = 1;
    o.share_rays = 4;
    need(rad_vp_create(s, rc, &o, NULL, &aa), "axis-aligned virtual patches");
    o.storage = RAD_STORAGE_SPARSE;
    o.drop_threshold = 1e-3f;
    need(rad_vp_create(s, rc, &o, NULL, &csr), "sparse virtual patches");
    o.storage = RAD_STORAGE_DENSE;
    o.drop_threshold = 0.0f;
    o.kind = RAD_VP_CLUSTERED;
    o.max_clusters = 3;
    o.weights = RAD_VP_WEIGHTS_COSINE;
    need(rad_vp_create(s, rc, &o, NULL, &cl), "clustered virtual patches");
    need(rad_vp_sections(aa, "vp", sec, &k), "sections");
    write_sections(dir, "aavp_dense.radb", sec, k);
    need(rad_vp_sections(csr, "vp", sec, &k), "sections");
    write_sections(dir, "aavp_csr.radb", sec, k);
    need(rad_vp_sections(cl, "vp", sec, &k), "sections");
    write_sections(dir, "clustered.radb", sec, k);
    need(rad_vp_sections(aa, "a", sec, &k), "sections");
    need(rad_vp_sections(csr, "b", sec + k, &k2), "sections");
    write_sections(dir, "two_sets.radb", sec, k + k2);
    rad_vp_destroy(cl);
    rad_vp_destroy(csr);
    rad_vp_destroy(aa);
}

static void put_f(unsigned char **p, float v) { memcpy(*p, &v, 4); *p += 4; }

int main(int argc, char **argv)
{
    rad_scene_desc d;
    rad_scene *s = NULL;
    rad_patches *P = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_form_factors *dense = NULL, *sparse = NULL;
    float *E;
    void *buf;
    size_t size;
    uint32_t i;
    char dir[5][1024];
    static const char *const sub[5] = { "container", "scene", "stream", "multibounce", "temporal" };
    if (argc != 2) { fprintf(stderr, "usage: make_corpus DIR (with DIR/container, scene, stream, multibounce, temporal, vp)\n"); return 2; }
    for (i = 0; i < 5; ++i) snprintf(dir[i], sizeof(dir[i]), "%s/%s", argv[1], sub[i]);
    rad_cornell_box(&d, NULL);
    if (rad_scene_create(&d, NULL, &s) != RAD_SUCCESS) return 1;
    rad_patch_options_default(&po);
    po.target_count = 40;
    rad_patches_create(s, &po, NULL, &P);
    rad_bvh_create(s, NULL, &bvh);
    rad_bvh_raycaster(bvh, &rc);
    rad_form_factor_options_default(&fo);
    fo.samples = 1;
    rad_form_factors_dense(P, &rc, &fo, NULL, &dense);
    fo.drop_threshold = 1e-3f;
    rad_form_factors_sparse(P, &rc, &fo, NULL, &sparse);
    E = (float *)malloc(sizeof(float) * 3 * P->count);
    rad_sources(P, RAD_SOURCE_EMISSION, NULL, E);
    if (rad_save_memory(P, &dense->matrix, E, E, NULL, &buf, &size) == RAD_SUCCESS) { write_file(dir[0], "dense.radb", buf, size); rad_free_buffer(buf, NULL); }
    if (rad_save_memory(P, &sparse->matrix, E, NULL, NULL, &buf, &size) == RAD_SUCCESS) {
        write_file(dir[0], "sparse.radb", buf, size);
        write_file(dir[2], "sparse.radb", buf, size);
        rad_free_buffer(buf, NULL);
    }
    if (rad_save_memory(P, NULL, NULL, NULL, NULL, &buf, &size) == RAD_SUCCESS) { write_file(dir[0], "patches.radb", buf, size); rad_free_buffer(buf, NULL); }
    /* scene seeds: header (meshes-1, materials, target, flags), materials, then per mesh
       (vertex count, triangle count, use ids), positions, indices, ids, material */
    {
        unsigned char seed[2048], *p = seed;
        static const float quad[12] = { 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0 };
        *p++ = 0; *p++ = 2; *p++ = 20; *p++ = 0;
        put_f(&p, 0.5f); put_f(&p, 0.5f); put_f(&p, 0.5f); put_f(&p, 0.0f); put_f(&p, 0.0f); put_f(&p, 0.0f);
        put_f(&p, 0.7f); put_f(&p, 0.2f); put_f(&p, 0.1f); put_f(&p, 1.0f); put_f(&p, 1.0f); put_f(&p, 1.0f);
        *p++ = 4; *p++ = 2; *p++ = 1;
        for (i = 0; i < 12; ++i) put_f(&p, quad[i]);
        *p++ = 0; *p++ = 1; *p++ = 2; *p++ = 0; *p++ = 2; *p++ = 3;
        *p++ = 0; *p++ = 1;
        *p++ = 0;
        put_f(&p, 0.5f); put_f(&p, 0.5f); put_f(&p, 1.0f);
        write_file(dir[1], "quad.bin", seed, (size_t)(p - seed));
        /* the Cornell box's floor, back wall and light as three meshes */
        p = seed;
        *p++ = 2; *p++ = 2; *p++ = 60; *p++ = 1;
        put_f(&p, 0.725f); put_f(&p, 0.71f); put_f(&p, 0.68f); put_f(&p, 0.0f); put_f(&p, 0.0f); put_f(&p, 0.0f);
        put_f(&p, 0.78f); put_f(&p, 0.78f); put_f(&p, 0.78f); put_f(&p, 17.0f); put_f(&p, 12.0f); put_f(&p, 4.0f);
        for (i = 0; i < 3; ++i) {
            const rad_mesh_desc *m = &d.meshes[i == 2 ? 5 : i * 2];
            uint32_t v;
            *p++ = 4; *p++ = 2; *p++ = 0;
            for (v = 0; v < 12; ++v) put_f(&p, m->positions[v]);
            for (v = 0; v < 6; ++v) *p++ = (unsigned char)m->indices[v];
            *p++ = 0; *p++ = 0;
            *p++ = (unsigned char)(i == 2 ? 1 : 0);
        }
        put_f(&p, 0.3f); put_f(&p, 0.5f); put_f(&p, 0.3f);
        write_file(dir[1], "cornell3.bin", seed, (size_t)(p - seed));
    }
    /* a smaller CSR bake for the stream (fewer entries per row: faster inputs) */
    {
        rad_patches *Q = NULL;
        rad_form_factors *q = NULL;
        po.target_count = 12;
        fo.drop_threshold = 1e-2f;
        if (rad_patches_create(s, &po, NULL, &Q) == RAD_SUCCESS && rad_form_factors_sparse(Q, &rc, &fo, NULL, &q) == RAD_SUCCESS &&
            rad_save_memory(Q, &q->matrix, NULL, NULL, NULL, &buf, &size) == RAD_SUCCESS) {
            write_file(dir[2], "sparse_small.radb", buf, size);
            rad_free_buffer(buf, NULL);
        }
        rad_form_factors_destroy(q);
        rad_patches_destroy(Q);
    }
    write_method_seeds(argv[1], s, &rc);
    write_vp_seeds(argv[1], s, &rc);
    free(E);
    rad_form_factors_destroy(dense);
    rad_form_factors_destroy(sparse);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(P);
    rad_scene_destroy(s);
    return 0;
}
