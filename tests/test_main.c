/* test_main.c - the unit tests: one translation unit holding the implementation and every
   test file. Usage: test_main [NAME-SUBSTRING]. Prints "N passed, N failed" last.
   Environment: RAD_TEST_QUICK=1 smaller sizes; RAD_TEST_SHARD=i/n every n-th test from the
   i-th; RAD_TEST_SKIP=a,b leaves out the tests of those names; RAD_TEST_TIMES=1 CPU seconds per test; RAD_TEST_TMPDIR where scratch files go. */
#define RADIOSITY_IMPLEMENTATION
/* small chunks, so the sparse virtual-patch build's chunking is exercised (vp_sparse_rows) */
#define RAD_VP_ROW_CHUNK_BYTES 65536u
#include "../radiosity.h"
#include "test.h"

static void rad__bvh_destroy_real(rad_bvh *bvh) { rad_bvh_destroy(bvh); }

#ifdef RAD_TEST_EMBREE
/* The Embree suite: every raycaster the tests take from a BVH is an Embree raycaster over the
   same triangles, so the whole suite checks the Embree backend against the same expectations. */
#define RAD_TEST_EMBREE_MAX 256
static struct { const rad_bvh *bvh; rad_embree *embree; } rad_test_embree_map[RAD_TEST_EMBREE_MAX];

static void rad_test_embree_raycaster(const rad_bvh *bvh, rad_raycaster *out)
{
    rad_scene fake;
    float *pos;
    uint32_t i, slot = RAD_TEST_EMBREE_MAX;
    rad_embree *e = NULL;
    rad_bvh_raycaster(bvh, out); /* a fallback that keeps tests running if Embree fails */
    if (!bvh) return;
    for (i = 0; i < RAD_TEST_EMBREE_MAX; ++i) {
        if (rad_test_embree_map[i].bvh == bvh) { rad_embree_raycaster(rad_test_embree_map[i].embree, out); return; }
        if (!rad_test_embree_map[i].bvh && slot == RAD_TEST_EMBREE_MAX) slot = i;
    }
    pos = (float *)malloc(sizeof(float) * 9 * bvh->tri_count);
    if (!pos || slot == RAD_TEST_EMBREE_MAX) { free(pos); printf("    FAIL embree map full\n"); rad_test_failures++; return; }
    for (i = 0; i < bvh->leaf_count; ++i) { /* the BVH's own copy of the triangles, lane by lane */
        const rad__tri4 *q = &bvh->leaves[i];
        uint32_t j, c, a;
        for (j = 0; j < 4; ++j)
            if (q->id[j] != RAD_NONE)
                for (c = 0; c < 3; ++c)
                    for (a = 0; a < 3; ++a) pos[9 * (size_t)q->id[j] + 3 * c + a] = q->v[c][a][j];
    }
    memset(&fake, 0, sizeof(fake));
    fake.positions = pos;
    fake.triangle_count = bvh->tri_count;
    if (rad_embree_create(&fake, NULL, &e) != RAD_SUCCESS) { printf("    FAIL rad_embree_create\n"); rad_test_failures++; free(pos); return; }
    free(pos);
    rad_test_embree_map[slot].bvh = bvh;
    rad_test_embree_map[slot].embree = e;
    rad_embree_raycaster(e, out);
}

static void rad_test_embree_bvh_destroy(rad_bvh *bvh)
{
    uint32_t i;
    for (i = 0; i < RAD_TEST_EMBREE_MAX; ++i)
        if (bvh && rad_test_embree_map[i].bvh == bvh) {
            rad_embree_destroy(rad_test_embree_map[i].embree);
            rad_test_embree_map[i].bvh = NULL;
            rad_test_embree_map[i].embree = NULL;
        }
    rad_bvh_destroy(bvh);
}
#define rad_bvh_raycaster(bvh, out) rad_test_embree_raycaster(bvh, out)
#define rad_bvh_destroy(bvh) rad_test_embree_bvh_destroy(bvh)
#endif

#include "test_scene.c"
#include "test_formfactor.c"
#include "test_hemicube.c"
#include "test_hierarchical.c"
#include "test_solve.c"
#include "test_stochastic.c"
#include "test_light.c"
#include "test_embree.c"
#include "test_container.c"
#include "test_multibounce.c"
#include "test_temporal.c"
#include "test_local.c"
#include "test_vp.c"
#include "test_vp_runtime.c"
#include "test_regress.c"
#include "test_robust.c"
#include "test_api.c"
#include "test_alloc.c"
#include "test_shading.c"
#include "test_glsl.c"
#include "test_probes.c"
#include "test_lightmap.c"

static const rad_test_case *const rad_test_tables[] = { tests_scene, tests_formfactor, tests_hemicube, tests_hierarchical, tests_solve, tests_stochastic, tests_light, tests_embree, tests_container, tests_multibounce, tests_temporal, tests_local, tests_vp, tests_vp_runtime, tests_regress, tests_robust, tests_api, tests_alloc, tests_shading, tests_glsl, tests_probes, tests_lightmap };

/* 1 when 'name' is one of the comma-separated names in 'list' */
static int rad_test_listed(const char *list, const char *name)
{
    size_t n = strlen(name);
    const char *p = list;
    while (*p) {
        const char *e = strchr(p, ',');
        size_t len = e ? (size_t)(e - p) : strlen(p);
        if (len == n && strncmp(p, name, n) == 0) return 1;
        if (!e) break;
        p = e + 1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    int passed = 0, failed = 0;
    int times = getenv("RAD_TEST_TIMES") != NULL; /* CPU seconds per test, to keep the suite short */
    size_t t;
    unsigned shard = 0, shards = 1, index = 0; /* RAD_TEST_SHARD=i/n: every n-th test from the i-th */
    const char *sh = getenv("RAD_TEST_SHARD"), *skip = getenv("RAD_TEST_SKIP");
    if (sh && (sscanf(sh, "%u/%u", &shard, &shards) != 2 || shards == 0 || shard >= shards)) {
        printf("RAD_TEST_SHARD='%s' is not i/n with i < n\n", sh);
        return 2;
    }
    (void)&rad_test_quick; /* helpers some builds do not call */
    (void)&rad__bvh_destroy_real;
#ifdef RAD_TEST_EMBREE
    (void)&rad_test_embree_raycaster;
    (void)&rad_test_embree_bvh_destroy;
#endif
    for (t = 0; t < sizeof(rad_test_tables) / sizeof(rad_test_tables[0]); ++t) {
        const rad_test_case *c;
        for (c = rad_test_tables[t]; c->name; ++c) {
            if (argc > 1 && !strstr(c->name, argv[1])) continue;
            if (skip && rad_test_listed(skip, c->name)) continue;
            if (index++ % shards != shard) continue;
            clock_t t0;
            rad_test_failures = 0;
            printf("%s\n", c->name);
            fflush(stdout);
            t0 = clock();
            c->fn();
            if (times) printf("  time %s %.2f s\n", c->name, (double)(clock() - t0) / CLOCKS_PER_SEC);
            if (rad_test_failures) { printf("  FAILED %s (%d checks)\n", c->name, rad_test_failures); failed++; }
            else passed++;
        }
    }
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
