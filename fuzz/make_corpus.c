/* make_corpus.c - writes the fuzzers' seed corpora: valid bakes of the Cornell box (dense and
   sparse, with and without vectors) and scene inputs describing a quad, a box and the Cornell
   box's first meshes in fuzz_scene.c's byte format.
   Usage: make_corpus CONTAINER_DIR SCENE_DIR */
#define RADIOSITY_IMPLEMENTATION
#include "../radiosity.h"
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
    if (argc < 3) { fprintf(stderr, "usage: make_corpus CONTAINER_DIR SCENE_DIR\n"); return 2; }
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
    if (rad_save_memory(P, &dense->matrix, E, E, NULL, &buf, &size) == RAD_SUCCESS) { write_file(argv[1], "dense.radb", buf, size); rad_free_buffer(buf, NULL); }
    if (rad_save_memory(P, &sparse->matrix, E, NULL, NULL, &buf, &size) == RAD_SUCCESS) { write_file(argv[1], "sparse.radb", buf, size); rad_free_buffer(buf, NULL); }
    if (rad_save_memory(P, NULL, NULL, NULL, NULL, &buf, &size) == RAD_SUCCESS) { write_file(argv[1], "patches.radb", buf, size); rad_free_buffer(buf, NULL); }
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
        write_file(argv[2], "quad.bin", seed, (size_t)(p - seed));
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
        write_file(argv[2], "cornell3.bin", seed, (size_t)(p - seed));
    }
    free(E);
    rad_form_factors_destroy(dense);
    rad_form_factors_destroy(sparse);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(P);
    rad_scene_destroy(s);
    return 0;
}
