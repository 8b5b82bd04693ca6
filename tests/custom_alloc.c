/* custom_alloc.c - the compile-time allocator macros replace malloc/realloc/free everywhere:
   every allocation of a small pipeline goes through them and all are freed. */
#include <stdlib.h>
static long g_live, g_total;
static void *count_malloc(size_t n) { g_live++; g_total++; return malloc(n); }
static void *count_realloc(void *p, size_t n) { if (!p) { g_live++; g_total++; } return realloc(p, n); }
static void count_free(void *p) { if (p) g_live--; free(p); }
#define RAD_MALLOC(n) count_malloc(n)
#define RAD_REALLOC(p, n) count_realloc(p, n)
#define RAD_FREE(p) count_free(p)
#define RADIOSITY_IMPLEMENTATION
#include "../radiosity.h"
#include <stdio.h>

int main(void)
{
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    rad_patches *patches = NULL;
    rad_bvh *bvh = NULL;
    rad_form_factors *ff = NULL;
    rad_patch_options po;
    rad_raycaster rc;
    rad_cornell_box(&desc, NULL);
    if (rad_scene_create(&desc, NULL, &scene) != RAD_SUCCESS) return 1;
    rad_patch_options_default(&po);
    po.target_count = 60;
    if (rad_patches_create(scene, &po, NULL, &patches) != RAD_SUCCESS) return 2;
    if (rad_bvh_create(scene, NULL, &bvh) != RAD_SUCCESS) return 3;
    rad_bvh_raycaster(bvh, &rc);
    if (rad_form_factors_sparse(patches, &rc, NULL, NULL, &ff) != RAD_SUCCESS) return 4;
    if (g_total < 10 || g_live <= 0) { printf("allocations not routed: total %ld live %ld\n", g_total, g_live); return 5; }
    rad_form_factors_destroy(ff);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(patches);
    rad_scene_destroy(scene);
    if (g_live != 0) { printf("leak: %ld live allocations\n", g_live); return 6; }
    printf("%ld allocations, all freed\n", g_total);
    return 0;
}
