/* lightmap.c - bake a lightmap (>>api_lightmap, docs/methods/lightmap.md) for the built-in
   Cornell box, every quad given its own cell of the atlas as a second uv set, and write it
   beside a picture of the box shaded by it (camera rays, one lightmap lookup per pixel).
   Usage: lightmap [--size N] [--patches N] [-o OUT.png]   (default 128, 600, lightmap.png) */
#define RADIOSITY_IMPLEMENTATION
#include "radiosity.h"
#include "examples/png_write.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static unsigned char srgb8(float v)
{
    v = v <= 0.0f ? 0.0f : v >= 1.0f ? 1.0f : v;
    v = v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
    return (unsigned char)(v * 255.0f + 0.5f);
}

int main(int argc, char **argv)
{
    rad_scene_desc desc;
    rad_camera cam;
    rad_mesh_desc meshes[16];
    float luv[16][2 * 20];       /* the Cornell meshes have at most 5 quads of 4 vertices */
    rad_scene *scene = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_patches *patches = NULL;
    rad_patch_options popt;
    rad_form_factor_options fopt;
    rad_form_factors *ff = NULL;
    rad_system sys;
    rad_solve_options sopt;
    rad_lightmap *lm = NULL;
    rad_lightmap_options lopt;
    rad_lightmap_seam_stats seams;
    float *E, *B, *H;
    unsigned char *img;
    const char *out = "lightmap.png";
    uint32_t N = 128, target = 600, m, q, cell = 0, cells = 6, i, x, y, W;
    int a;
    for (a = 1; a < argc; ++a) {
        if (!strcmp(argv[a], "--size") && a + 1 < argc) N = (uint32_t)atoi(argv[++a]);
        else if (!strcmp(argv[a], "--patches") && a + 1 < argc) target = (uint32_t)atoi(argv[++a]);
        else if (!strcmp(argv[a], "-o") && a + 1 < argc) out = argv[++a];
        else { fprintf(stderr, "usage: lightmap [--size N] [--patches N] [-o OUT.png]\n"); return 2; }
    }
    if (N < 16 || N > 4096 || target == 0) { fprintf(stderr, "lightmap: --size 16..4096, --patches > 0\n"); return 2; }

    /* the second uv set: quad corners a b c d -> the corners of the quad's cell, 1 texel in */
    rad_cornell_box(&desc, &cam);
    memcpy(meshes, desc.meshes, sizeof(rad_mesh_desc) * desc.mesh_count);
    for (m = 0; m < desc.mesh_count; ++m) {
        if (meshes[m].vertex_count > 20) return 1; /* luv holds 5 quads a mesh */
        for (q = 0; q < meshes[m].vertex_count / 4; ++q, ++cell) {
            static const float cu[4] = { 0, 1, 1, 0 }, cv[4] = { 0, 0, 1, 1 };
            float x0 = (float)(cell % cells) / cells, y0 = (float)(cell / cells) / cells, g = 1.0f / N, s = 1.0f / cells - 2.0f * g;
            for (i = 0; i < 4; ++i) {
                luv[m][8 * q + 2 * i] = x0 + g + s * cu[i];
                luv[m][8 * q + 2 * i + 1] = y0 + g + s * cv[i];
            }
        }
        meshes[m].lightmap_uvs = luv[m];
    }
    desc.meshes = meshes;

    /* the classic solution: emission as the source, B = E + L */
    if (rad_scene_create(&desc, NULL, &scene) != RAD_SUCCESS || rad_bvh_create(scene, NULL, &bvh) != RAD_SUCCESS) return 1;
    rad_bvh_raycaster(bvh, &rc);
    rad_patch_options_default(&popt);
    popt.target_count = target;
    if (rad_patches_create(scene, &popt, NULL, &patches) != RAD_SUCCESS) return 1;
    rad_form_factor_options_default(&fopt);
    if (rad_form_factors_dense(patches, &rc, &fopt, NULL, &ff) != RAD_SUCCESS) return 1;
    E = (float *)malloc(sizeof(float) * 3 * patches->count);
    B = (float *)malloc(sizeof(float) * 3 * patches->count);
    H = (float *)calloc(3 * (size_t)N * N, sizeof(float));
    img = (unsigned char *)calloc(3 * (size_t)2 * N * N, 1);
    if (!E || !B || !H || !img) return 1;
    rad_sources(patches, RAD_SOURCE_EMISSION, NULL, E);
    rad_system_init(&sys, &ff->matrix, patches, E);
    rad_solve_options_default(&sopt);
    sopt.output = RAD_OUTPUT_TOTAL;
    if (rad_solve_gauss_seidel(&sys, &sopt, B, NULL, NULL) != RAD_SUCCESS) return 1;

    /* the lightmap: texels, gather (irradiance from every patch, with visibility), dilation
       into the gutters, seams */
    rad_lightmap_options_default(&lopt);
    lopt.width = lopt.height = N;
    if (rad_lightmap_create(scene, &rc, &lopt, NULL, &lm) != RAD_SUCCESS) return 1;
    if (rad_lightmap_gather(lm, patches, B, &rc, NULL, H, NULL) != RAD_SUCCESS) return 1;
    rad_lightmap_dilate(lm, 3, H, 0, NULL);
    rad_lightmap_stitch(lm, 3, H, 0, &seams, NULL);
    printf("%ux%u texels: %u covered, %u valid; %u seams\n", N, N, lm->covered_texels, lm->valid_texels, seams.seams);

    /* left: the lightmap (irradiance / pi); right: the box, radiance = emission + rho H / pi */
    W = 2 * N;
    for (y = 0; y < N; ++y)
        for (x = 0; x < N; ++x)
            for (i = 0; i < 3; ++i) img[3 * ((size_t)y * W + x) + i] = srgb8(H[3 * ((size_t)y * N + x) + i] / 3.14159265f);
    {
        float f[3], r[3], u[3], tanh_ = tanf(0.5f * cam.fov_y_degrees * 3.14159265f / 180.0f);
        for (i = 0; i < 3; ++i) f[i] = cam.target[i] - cam.position[i];
        r[0] = f[1] * cam.up[2] - f[2] * cam.up[1]; r[1] = f[2] * cam.up[0] - f[0] * cam.up[2]; r[2] = f[0] * cam.up[1] - f[1] * cam.up[0];
        u[0] = r[1] * f[2] - r[2] * f[1]; u[1] = r[2] * f[0] - r[0] * f[2]; u[2] = r[0] * f[1] - r[1] * f[0];
        {
            float lf = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]), lr = sqrtf(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
            float lu = sqrtf(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
            for (i = 0; i < 3; ++i) { f[i] /= lf; r[i] /= lr; u[i] /= lu; }
        }
        for (y = 0; y < N; ++y)
            for (x = 0; x < N; ++x) {
                rad_ray ray;
                rad_hit hit;
                float px = (2.0f * (x + 0.5f) / N - 1.0f) * tanh_, py = (1.0f - 2.0f * (y + 0.5f) / N) * tanh_, c[3];
                for (i = 0; i < 3; ++i) {
                    ray.origin[i] = cam.position[i];
                    ray.dir[i] = f[i] + px * r[i] + py * u[i];
                }
                ray.tmin = 0.0f;
                ray.tmax = 1e30f;
                if (rc.intersect(rc.user, &ray, 1, &hit) != RAD_SUCCESS || hit.triangle == RAD_NONE) continue;
                {
                    const float *t = scene->lightmap_uvs + 6 * (size_t)hit.triangle;
                    const rad_material *mat = &scene->materials_table[scene->materials[hit.triangle]];
                    float uu = t[0] + hit.b1 * (t[2] - t[0]) + hit.b2 * (t[4] - t[0]);
                    float vv = t[1] + hit.b1 * (t[3] - t[1]) + hit.b2 * (t[5] - t[1]);
                    rad_lightmap_sample(lm, 3, H, uu, vv, c);
                    for (i = 0; i < 3; ++i)
                        img[3 * ((size_t)y * W + N + x) + i] = srgb8(mat->emission[i] + mat->albedo[i] * c[i] / 3.14159265f);
                }
            }
    }
    if (png_write_rgb8(out, W, N, img, 3 * (size_t)W) != 0) { fprintf(stderr, "lightmap: cannot write %s\n", out); return 1; }
    printf("wrote %s\n", out);
    free(E); free(B); free(H); free(img);
    rad_lightmap_destroy(lm);
    rad_form_factors_destroy(ff);
    rad_patches_destroy(patches);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(scene);
    return 0;
}
