/* walk.c - a camera walk through a large generated scene with the local multi-bounce matrix
   (docs/methods/local.md): only the M patches nearest the camera carry multi-bounce
   transport, updated as the camera moves, and the global form factors are read one row at
   a time, so the 69 000-patch scene never needs its N x N matrix (about 18 GiB as floats).

   Per frame:
     1. the V = 3M/4 patches nearest the camera (rad_local_nearest) become the visible set:
        members that left are removed (hidden: the light paths through them stay in T until
        their slot is needed), new patches are added (exact Sherman-Morrison update, one
        row fetch each, evicting the member hidden longest ago when the set is full);
     2. P_Vis = visible members the camera sees (frustum, back faces, occlusion rays through
        the built-in BVH), P_Lit = members with a non-zero source E (the ceiling lights);
     3. L = T E over P_Vis x P_Lit (rad_local_apply), B = E + L;
     4. the frame is drawn with one camera ray per pixel: the hit patch shows B / pi (patches
        outside P_Vis show only their own emission: the far lamps glow over black walls,
        which carry no light in this frame) and written as a PNG.
   The source is emission (RAD_SOURCE_EMISSION, docs/methods/direct-light.md): the lamps are the only E, so every wall shows
   light that reached it through the local matrix. Timings of each step go to stdout.

   Build:  cc -std=c99 -O2 -fopenmp -I. examples/walk.c -o build/walk -lm
   Run:    build/walk [--grid G] [--m M] [--frames F] [--size WxH] [--exposure X] [-o PREFIX]
           (defaults: 10 x 10 rooms cut into patches of at most 0.2 m^2, 69 372 patches;
           M = 2048, 16 frames along the first corridor, 320x180, PREFIX "walk" -> walk_000.png) */
#if !defined(_WIN32) && !defined(_POSIX_C_SOURCE)
#  define _POSIX_C_SOURCE 199309L /* clock_gettime */
#endif
#define RADIOSITY_IMPLEMENTATION
#include "radiosity.h"
#include "png_write.h"
#include "rooms.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void check(rad_result r, const char *what)
{
    if (r != RAD_SUCCESS) {
        fprintf(stderr, "walk: %s failed: %s\n", what, rad_result_string(r));
        exit(1);
    }
}

static void *xmalloc(size_t size)
{
    void *p = malloc(size ? size : 1);
    if (!p) {
        fprintf(stderr, "walk: out of memory\n");
        exit(1);
    }
    return p;
}

static unsigned char srgb8(float v)
{
    float s;
    if (!(v > 0.0f)) v = 0.0f;
    if (v > 1.0f) v = 1.0f;
    s = v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
    return (unsigned char)(s * 255.0f + 0.5f);
}

int main(int argc, char **argv)
{
    uint32_t grid = 10, M = 2048, frames = 16, W = 320, H = 180, V, n, i, f;
    float exposure = 1.0f;
    const char *prefix = "walk";
    rooms_geometry g;
    rooms_rows rows;
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    rad_patches *patches = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_patch_options po;
    rad_row_source src;
    rad_local_options lo;
    rad_local *L = NULL;
    float *E, *B;
    uint32_t *near, *cand, *vis, *lit, *wanted;
    unsigned char *image;
    double t0;

    for (i = 1; i < (uint32_t)argc; ++i) {
        if (!strcmp(argv[i], "--grid") && i + 1 < (uint32_t)argc) grid = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--m") && i + 1 < (uint32_t)argc) M = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--frames") && i + 1 < (uint32_t)argc) frames = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--exposure") && i + 1 < (uint32_t)argc) exposure = (float)atof(argv[++i]);
        else if (!strcmp(argv[i], "--size") && i + 1 < (uint32_t)argc) {
            if (sscanf(argv[++i], "%ux%u", &W, &H) != 2) W = 0;
        } else if (!strcmp(argv[i], "-o") && i + 1 < (uint32_t)argc) prefix = argv[++i];
        else {
            fprintf(stderr, "usage: walk [--grid G] [--m M] [--frames F] [--size WxH] [--exposure X] [-o PREFIX]\n");
            return 1;
        }
    }
    if (grid == 0 || grid > 64 || M < 16 || frames == 0 || W == 0 || H == 0 || W > 8192 || H > 8192) {
        fprintf(stderr, "walk: bad option value\n");
        return 1;
    }

    /* 1. the scene, its patches, the BVH and the on-demand rows */
    t0 = now_s();
    if (!rooms_scene(grid, grid, &desc, &g)) check(RAD_ERROR_OUT_OF_MEMORY, "rooms_scene");
    check(rad_scene_create(&desc, NULL, &scene), "rad_scene_create");
    rad_patch_options_default(&po);
    po.max_area = 0.2f;
    check(rad_patches_create(scene, &po, NULL, &patches), "rad_patches_create");
    check(rad_bvh_create(scene, NULL, &bvh), "rad_bvh_create");
    rad_bvh_raycaster(bvh, &rc);
    if (!rooms_rows_init(&rows, patches)) check(RAD_ERROR_OUT_OF_MEMORY, "rooms_rows_init");
    rooms_rows_source(&rows, &src);
    n = patches->count;
    if (M > n) M = n;
    V = M * 3 / 4;
    printf("scene: %u x %u rooms, %u triangles, %u patches (a dense F would take %.1f GiB); M = %u, %u visible; setup %.2f s\n",
           grid, grid, scene->triangle_count, n, (double)n * n * 4.0 / 1073741824.0, M, V, now_s() - t0);

    E = (float *)xmalloc(sizeof(float) * 3 * n);
    B = (float *)xmalloc(sizeof(float) * 3 * n);
    near = (uint32_t *)xmalloc(sizeof(uint32_t) * n);
    cand = (uint32_t *)xmalloc(sizeof(uint32_t) * n);
    vis = (uint32_t *)xmalloc(sizeof(uint32_t) * n);
    lit = (uint32_t *)xmalloc(sizeof(uint32_t) * n);
    wanted = (uint32_t *)xmalloc(sizeof(uint32_t) * n);
    image = (unsigned char *)xmalloc((size_t)W * H * 3);
    check(rad_sources(patches, RAD_SOURCE_EMISSION, NULL, E), "rad_sources");
    rad_local_options_default(&lo);
    lo.capacity = M;
    check(rad_local_create(&src, &lo, NULL, &L), "rad_local_create");
    printf("local matrix: %.1f MiB\n\n", (double)rad_local_memory(L) / 1048576.0);
    printf("frame | added | evicted | update ms | P_Vis x P_Lit | sets ms | apply ms | render ms | file\n");

    for (f = 0; f < frames; ++f) {
        rad_camera cam;
        uint32_t nc = 0, nv = 0, nl = 0, x, y, added0 = (uint32_t)L->adds, ev0 = (uint32_t)L->evictions;
        double t_up, t_sets, t_ap, t_draw;
        char path[512];
        rooms_camera(&g, frames > 1 ? (float)f / (float)(frames - 1) : 0.0f, &cam);

        /* 1. move the visible set */
        t0 = now_s();
        check(rad_local_nearest(patches, cam.position, V, near, NULL), "rad_local_nearest");
        memset(wanted, 0, sizeof(uint32_t) * n);
        for (i = 0; i < V; ++i) wanted[near[i]] = 1;
        for (i = 0; i < L->slot_end; ++i)
            if (L->slot_patch[i] != RAD_NONE && !L->slot_hidden[i] && !wanted[L->slot_patch[i]])
                check(rad_local_remove(L, L->slot_patch[i], NULL), "rad_local_remove");
        for (i = 0; i < V; ++i) {
            uint32_t s = L->patch_slot[near[i]];
            if (s == RAD_NONE || L->slot_hidden[s]) check(rad_local_add(L, near[i], NULL), "rad_local_add");
        }
        t_up = now_s() - t0;

        /* 2. P_Vis and P_Lit */
        t0 = now_s();
        for (i = 0; i < L->slot_end; ++i)
            if (L->slot_patch[i] != RAD_NONE && !L->slot_hidden[i]) cand[nc++] = L->slot_patch[i];
        check(rad_local_visible(patches, &rc, &cam, (float)W / (float)H, cand, nc, vis, &nv, NULL), "rad_local_visible");
        nc = 0;
        for (i = 0; i < L->slot_end; ++i)
            if (L->slot_patch[i] != RAD_NONE) cand[nc++] = L->slot_patch[i];
        check(rad_local_lit(E, cand, nc, 0.0f, lit, &nl), "rad_local_lit");
        t_sets = now_s() - t0;

        /* 3. B = E + T E over P_Vis x P_Lit; everything else black */
        t0 = now_s();
        memcpy(B, E, sizeof(float) * 3 * n); /* the lamps glow everywhere; walls only through T */
        check(rad_local_apply(L, E, vis, nv, lit, nl, B, RAD_OUTPUT_TOTAL, NULL), "rad_local_apply");
        t_ap = now_s() - t0;

        /* 4. draw */
        t0 = now_s();
        for (y = 0; y < H; ++y) {
            rad_ray *rays = (rad_ray *)xmalloc(sizeof(rad_ray) * W);
            rad_hit *hits = (rad_hit *)xmalloc(sizeof(rad_hit) * W);
            for (x = 0; x < W; ++x) rad_camera_ray(&cam, W, H, (float)x + 0.5f, (float)y + 0.5f, &rays[x]);
            check(rc.intersect(rc.user, rays, W, hits), "intersect");
            for (x = 0; x < W; ++x) {
                unsigned char *px = image + 3 * ((size_t)y * W + x);
                float wts[3], rgb[3] = {0.0f, 0.0f, 0.0f};
                uint32_t p = hits[x].triangle == RAD_NONE ? RAD_NONE : rad_patches_locate(patches, hits[x].triangle, hits[x].b1, hits[x].b2, wts);
                if (p != RAD_NONE) {
                    const float *b = B + 3 * (size_t)p;
                    rgb[0] = b[0] / 3.14159265f; rgb[1] = b[1] / 3.14159265f; rgb[2] = b[2] / 3.14159265f;
                }
                px[0] = srgb8(exposure * rgb[0]);
                px[1] = srgb8(exposure * rgb[1]);
                px[2] = srgb8(exposure * rgb[2]);
            }
            free(rays);
            free(hits);
        }
        snprintf(path, sizeof path, "%s_%03u.png", prefix, f);
        if (png_write_rgb8(path, (int)W, (int)H, image, (int)W * 3) != 0) {
            fprintf(stderr, "walk: cannot write %s\n", path);
            return 1;
        }
        t_draw = now_s() - t0;
        printf("%5u | %5u | %7u | %9.1f | %6u x %-4u | %7.1f | %8.2f | %9.1f | %s\n", f, (uint32_t)L->adds - added0,
               (uint32_t)L->evictions - ev0, 1e3 * t_up, nv, nl, 1e3 * t_sets, 1e3 * t_ap, 1e3 * t_draw, path);
        fflush(stdout);
    }

    rad_local_destroy(L);
    free(E); free(B); free(near); free(cand); free(vis); free(lit); free(wanted); free(image);
    rooms_rows_free(&rows);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(patches);
    rad_scene_destroy(scene);
    rooms_free(&g);
    return 0;
}
