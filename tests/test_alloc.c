/* test_alloc.c - allocation failure injected at every allocation of the method builds beyond
   the core, whose own allocations the scene tests cover: multi-bounce matrix, its block compression, alias
   tables and the temporal state with two steps. Every call returns success or
   RAD_ERROR_OUT_OF_MEMORY, nothing leaks and no block is overrun (the counting allocator of
   test_scene.c with its canaries). */
#include "fixtures.h"


static void al_test_methods(void)
{
    rad_scene_desc d;
    rad_scene *s = NULL;
    rad_patches *P = NULL;
    rad_bvh *b = NULL;
    rad_raycaster rc;
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_form_factors *ff = NULL;
    sc_alloc_state st;
    rad_context ctx;
    float *E = NULL, *out = NULL;
    long n, total = 1;
    rad_cornell_box(&d, NULL);
    CHECK_OK(rad_scene_create(&d, NULL, &s));
    rad_patch_options_default(&po);
    po.target_count = 48;
    CHECK_OK(rad_patches_create(s, &po, NULL, &P));
    CHECK_OK(rad_bvh_create(s, NULL, &b));
    rad_bvh_raycaster(b, &rc);
    rad_form_factor_options_default(&fo);
    fo.samples = 1;
    CHECK_OK(rad_form_factors_dense(P, &rc, &fo, NULL, &ff));
    if (!ff) goto done;
    E = (float *)malloc(sizeof(float) * 3 * P->count);
    out = (float *)malloc(sizeof(float) * 3 * P->count);
    CHECK_OK(rad_sources(P, RAD_SOURCE_EMISSION, NULL, E));
    memset(&ctx, 0, sizeof(ctx));
    ctx.allocator.alloc = sc_alloc_fn;
    ctx.allocator.free = sc_free_fn;
    ctx.allocator.user = &st;
    for (n = 0; n <= total; ++n) {
        rad_multibounce_options mo;
        rad_block_options bo;
        rad_multibounce *mb = NULL;
        rad_multibounce_blocks *blocks = NULL;
        rad_alias_tables *tables = NULL;
        rad_temporal *tp = NULL;
        rad_temporal_options to;
        const rad_alias_tables *list[1];
        rad_result r[6];
        int k, failed = 0;
        memset(&st, 0, sizeof(st));
        st.fail_at = n;
        for (k = 0; k < 6; ++k) r[k] = RAD_SUCCESS;
        rad_multibounce_options_default(&mo);
        rad_block_options_default(&bo);
        bo.tile = 16;
        r[0] = rad_multibounce_create(&ff->matrix, P->albedo, &mo, &ctx, &mb);
        if (r[0] == RAD_SUCCESS) r[1] = rad_multibounce_blocks_create(mb, &bo, &ctx, &blocks, NULL);
        r[2] = rad_alias_tables_create(&ff->matrix, RAD_ALIAS_AUTO, &ctx, &tables);
        if (r[2] == RAD_SUCCESS) {
            list[0] = tables;
            rad_temporal_options_default(&to);
            r[3] = rad_temporal_create(list, 1, P->albedo, &to, &ctx, &tp);
            if (r[3] == RAD_SUCCESS) {
                r[4] = rad_temporal_step(tp, E, NULL, out);
                if (r[4] == RAD_SUCCESS) r[5] = rad_temporal_step(tp, E, NULL, out);
            }
        }
        for (k = 0; k < 6; ++k) {
            if (r[k] != RAD_SUCCESS && r[k] != RAD_ERROR_OUT_OF_MEMORY) {
                printf("    fail_at %ld: step %d returned %s\n", n, k, rad_result_string(r[k]));
                CHECK(0);
            }
            if (r[k] != RAD_SUCCESS) failed = 1;
        }
        if (n > 0 && n <= st.calls) CHECK(failed); /* the failed allocation must be reported */
        rad_temporal_destroy(tp);
        rad_alias_tables_destroy(tables);
        rad_multibounce_blocks_destroy(blocks);
        rad_multibounce_destroy(mb);
        if (st.allocs != st.frees || st.live_bytes != 0 || st.corrupt != 0) {
            printf("    fail_at %ld: %ld allocs, %ld frees, %lld live bytes, %ld overruns\n", n, st.allocs, st.frees,
                   st.live_bytes, st.corrupt);
            CHECK(0);
        }
        if (n == 0) total = st.calls;
    }
    CHECK(total >= 6);
done:
    free(E);
    free(out);
    rad_form_factors_destroy(ff);
    rad_bvh_destroy(b);
    rad_patches_destroy(P);
    rad_scene_destroy(s);
}

static const rad_test_case tests_alloc[] = {
    { "alloc_failure_methods", al_test_methods },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_alloc)
