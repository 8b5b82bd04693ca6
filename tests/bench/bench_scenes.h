/* bench_scenes.h - scenes more than one benchmark builds: the Cornell box with a lightmap
   atlas (one cell per quad) and a minimal OBJ reader for the external meshes (the Stanford
   bunny, Sponza). Include it after radiosity.h. The functions are static inline so that a
   program that uses only one of them still compiles without warnings. */
#ifndef RAD_BENCH_SCENES_H
#define RAD_BENCH_SCENES_H
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The Cornell box with lightmap uvs: each quad gets one cell of a 6 x 6 atlas, inset by one
   texel of an N x N map so that neighbouring cells do not bleed into each other. */
static inline rad_scene *bench_cornell_atlas(uint32_t N)
{
    static rad_mesh_desc meshes[16];
    static float luv[16][2 * 20]; /* the blocks have 5 quads of 4 vertices */
    rad_scene_desc desc;
    rad_scene *S = NULL;
    uint32_t m, q, i, cell = 0, cells = 6;
    rad_cornell_box(&desc, NULL);
    memcpy(meshes, desc.meshes, sizeof(rad_mesh_desc) * desc.mesh_count);
    for (m = 0; m < desc.mesh_count; ++m) {
        for (q = 0; q < meshes[m].vertex_count / 4; ++q, ++cell) {
            static const float cu[4] = { 0, 1, 1, 0 }, cv[4] = { 0, 0, 1, 1 };
            float x0 = (float)(cell % cells) / cells, y0 = (float)(cell / cells) / cells, g = 1.0f / N, s = 1.0f / cells - 2.0f * g;
            for (i = 0; i < 4; ++i) { luv[m][8 * q + 2 * i] = x0 + g + s * cu[i]; luv[m][8 * q + 2 * i + 1] = y0 + g + s * cv[i]; }
        }
        meshes[m].lightmap_uvs = luv[m];
    }
    desc.meshes = meshes;
    if (rad_scene_create(&desc, NULL, &S) != RAD_SUCCESS) exit(1);
    return S;
}

/* Reads the "v x y z" and "f" lines of an OBJ file (indices "a", "a/b" or "a/b/c", polygons
   fanned into triangles); 0 when the file cannot be read or has no triangle. The caller frees
   *pos and *idx. */
static inline int bench_load_obj(const char *path, float **pos, uint32_t *nv, uint32_t **idx, uint32_t *nt)
{
    FILE *f = fopen(path, "r");
    char line[1024];
    size_t vc = 0, vcap = 0, tc = 0, tcap = 0;
    float *v = NULL;
    uint32_t *t = NULL;
    if (!f) return 0;
    while (fgets(line, sizeof(line), f)) {
        if (line[0] == 'v' && line[1] == ' ') {
            if (vc == vcap) { vcap = vcap ? 2 * vcap : 4096; v = (float *)realloc(v, vcap * 3 * sizeof(float)); }
            if (sscanf(line + 2, "%f %f %f", &v[3 * vc], &v[3 * vc + 1], &v[3 * vc + 2]) == 3) vc++;
        } else if (line[0] == 'f' && line[1] == ' ') {
            char *p = line + 2, *end;
            unsigned long ix[64];
            int m = 0, j;
            while (m < 64) {
                ix[m] = strtoul(p, &end, 10);
                if (end == p) break;
                m++;
                p = end;
                while (*p && *p != ' ' && *p != '\t' && *p != '\n' && *p != '\r') p++;
            }
            for (j = 2; j < m; ++j) {
                if (ix[0] == 0 || ix[j - 1] == 0 || ix[j] == 0) continue;
                if (tc == tcap) { tcap = tcap ? 2 * tcap : 4096; t = (uint32_t *)realloc(t, tcap * 3 * sizeof(uint32_t)); }
                t[3 * tc] = (uint32_t)ix[0] - 1; t[3 * tc + 1] = (uint32_t)ix[j - 1] - 1; t[3 * tc + 2] = (uint32_t)ix[j] - 1;
                tc++;
            }
        }
    }
    fclose(f);
    *pos = v; *nv = (uint32_t)vc; *idx = t; *nt = (uint32_t)tc;
    return tc > 0;
}
#endif
