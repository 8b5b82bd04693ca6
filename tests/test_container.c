/* test_container.c - baked data: round trips (dense, sparse, vectors), and every corruption
   class rejected with its own error: truncation at every section, flipped bytes anywhere,
   another version, an out-of-range index behind a valid checksum, unaligned input. */
#include "fixtures.h"


typedef struct ct_fixture {
    rad_scene *scene;
    rad_patches *P;
    rad_bvh *bvh;
    rad_form_factors *dense, *sparse;
    float *E, *B;
} ct_fixture;

static int ct_setup(ct_fixture *f)
{
    rad_scene_desc d;
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_raycaster rc;
    uint32_t i;
    memset(f, 0, sizeof(*f));
    rad_cornell_box(&d, NULL);
    if (rad_scene_create(&d, NULL, &f->scene) != RAD_SUCCESS) return 0;
    rad_patch_options_default(&po);
    po.target_count = 120;
    if (rad_patches_create(f->scene, &po, NULL, &f->P) != RAD_SUCCESS) return 0;
    if (rad_bvh_create(f->scene, NULL, &f->bvh) != RAD_SUCCESS) return 0;
    rad_bvh_raycaster(f->bvh, &rc);
    rad_form_factor_options_default(&fo);
    fo.samples = 4;
    if (rad_form_factors_dense(f->P, &rc, &fo, NULL, &f->dense) != RAD_SUCCESS) return 0;
    fo.drop_threshold = 1e-4f;
    if (rad_form_factors_sparse(f->P, &rc, &fo, NULL, &f->sparse) != RAD_SUCCESS) return 0;
    f->E = (float *)malloc(sizeof(float) * 3 * f->P->count);
    f->B = (float *)malloc(sizeof(float) * 3 * f->P->count);
    for (i = 0; i < 3 * f->P->count; ++i) { f->E[i] = (float)i * 0.5f; f->B[i] = (float)i * 0.25f + 1.0f; }
    return 1;
}

static void ct_teardown(ct_fixture *f)
{
    free(f->E);
    free(f->B);
    rad_form_factors_destroy(f->dense);
    rad_form_factors_destroy(f->sparse);
    rad_bvh_destroy(f->bvh);
    rad_patches_destroy(f->P);
    rad_scene_destroy(f->scene);
}

static void ct_test_round_trip(void)
{
    ct_fixture f;
    void *buf = NULL;
    size_t size = 0;
    rad_bake *b = NULL;
    int pass;
    if (!ct_setup(&f)) { CHECK(0); ct_teardown(&f); return; }
    for (pass = 0; pass < 2; ++pass) {
        const rad_matrix *F = pass == 0 ? &f.dense->matrix : &f.sparse->matrix;
        uint32_t i;
        CHECK_OK(rad_save_memory(f.P, F, f.E, f.B, NULL, &buf, &size));
        CHECK(size % 64 == 0);
        CHECK_OK(rad_load_memory(buf, size, NULL, &b));
        if (!b) { rad_free_buffer(buf, NULL); continue; }
        CHECK(b->patches.count == f.P->count);
        CHECK(b->patches.vertex_count == f.P->vertex_count);
        CHECK(b->patches.triangle_count == f.P->triangle_count);
        CHECK(memcmp(b->patches.patches, f.P->patches, sizeof(rad_patch) * f.P->count) == 0);
        CHECK(memcmp(b->patches.vertices, f.P->vertices, 12 * (size_t)f.P->vertex_count) == 0);
        CHECK(memcmp(b->patches.first_patch, f.P->first_patch, 4 * (size_t)f.P->triangle_count) == 0);
        CHECK(memcmp(b->patches.areas, f.P->areas, 4 * (size_t)f.P->count) == 0);
        CHECK(memcmp(b->patches.albedo, f.P->albedo, 12 * (size_t)f.P->count) == 0);
        CHECK(b->E && memcmp(b->E, f.E, 12 * (size_t)f.P->count) == 0);
        CHECK(b->B && memcmp(b->B, f.B, 12 * (size_t)f.P->count) == 0);
        CHECK(b->F.rows == f.P->count && b->F.storage == F->storage);
        if (F->storage == RAD_STORAGE_DENSE) {
            CHECK(memcmp(b->F.dense, F->dense, 4 * (size_t)F->rows * F->cols) == 0);
        } else {
            uint64_t nnz = F->row_offsets[F->rows];
            CHECK(memcmp(b->F.row_offsets, F->row_offsets, 8 * ((size_t)F->rows + 1)) == 0);
            CHECK(memcmp(b->F.columns, F->columns, 4 * (size_t)nnz) == 0);
            CHECK(memcmp(b->F.values, F->values, 4 * (size_t)nnz) == 0);
        }
        /* the loaded patches work with the patch functions */
        for (i = 0; i < 20; ++i) {
            float w1[3], w2[3];
            uint32_t t = i % f.P->triangle_count;
            CHECK(rad_patches_locate(&b->patches, t, 0.3f, 0.2f, w1) == rad_patches_locate(f.P, t, 0.3f, 0.2f, w2));
        }
        CHECK(rad_container_section_count(b->container) >= 5);
        CHECK(rad_container_find(b->container, RAD_SECTION_VECTOR, "B") != NULL);
        CHECK(rad_container_find(b->container, RAD_SECTION_VECTOR, "nope") == NULL);
        rad_bake_destroy(b);
        b = NULL;
        rad_free_buffer(buf, NULL);
        buf = NULL;
    }
#ifndef RAD_NO_STDIO
    {
        const char *path = rad_test_path("ct_round_trip.radb");
        rad_result r = rad_save_file(path, f.P, &f.dense->matrix, NULL, f.B, NULL);
        CHECK_OK(r);
        CHECK_OK(rad_load_file(path, NULL, &b));
        CHECK(b && b->E == NULL && b->B != NULL && b->F.storage == RAD_STORAGE_DENSE);
        rad_bake_destroy(b);
        remove(path);
        CHECK_RESULT(rad_load_file("/nonexistent/dir/x.radb", NULL, &b), RAD_ERROR_IO);
        CHECK(b == NULL);
        CHECK_RESULT(rad_save_file("/nonexistent/dir/x.radb", f.P, NULL, NULL, NULL, NULL), RAD_ERROR_IO);
    }
#endif
    ct_teardown(&f);
}

static void ct_test_corruption(void)
{
    ct_fixture f;
    void *buf = NULL;
    size_t size = 0, cut, i;
    unsigned char *copy;
    rad_bake *b = NULL;
    uint32_t sec, nsec, flips = 0, wrong = 0;
    if (!ct_setup(&f)) { CHECK(0); ct_teardown(&f); return; }
    CHECK_OK(rad_save_memory(f.P, &f.sparse->matrix, f.E, f.B, NULL, &buf, &size));
    copy = (unsigned char *)malloc(size);
    nsec = rad__get32((unsigned char *)buf + 8);
    /* truncation: at every section boundary, inside every section, and inside the header/table */
    for (sec = 0; sec <= nsec; ++sec) {
        size_t ends[3];
        int k;
        if (sec < nsec) {
            const unsigned char *e = (const unsigned char *)buf + 64 + 64 * (size_t)sec;
            ends[0] = (size_t)rad__get64(e + 16);
            ends[1] = ends[0] + (size_t)rad__get64(e + 24) / 2;
            ends[2] = ends[0] + (size_t)rad__get64(e + 24) - 1;
        } else {
            ends[0] = 10; ends[1] = 63; ends[2] = 64 + 64 * (size_t)nsec - 1;
        }
        for (k = 0; k < 3; ++k) {
            cut = ends[k];
            if (cut >= size) continue;
            memcpy(copy, buf, cut);
            CHECK_RESULT(rad_load_memory(copy, cut, NULL, &b), RAD_ERROR_TRUNCATED);
            CHECK(b == NULL);
        }
    }
    /* a flipped bit anywhere is caught: header and table bytes all, data bytes at a stride */
    for (i = 0; i < size; i += (i < 64 + 64 * (size_t)nsec) ? 1 : 97) {
        rad_result r;
        memcpy(copy, buf, size);
        copy[i] ^= 0x10;
        r = rad_load_memory(copy, size, NULL, &b);
        flips++;
        if (r == RAD_SUCCESS) {
            /* only padding bytes between sections may change unnoticed: check it was one */
            int in_section = 0;
            for (sec = 0; sec < nsec; ++sec) {
                const unsigned char *e = (const unsigned char *)buf + 64 + 64 * (size_t)sec;
                if (i >= rad__get64(e + 16) && i < rad__get64(e + 16) + rad__get64(e + 24)) in_section = 1;
            }
            if (i < 64 + 64 * (size_t)nsec || in_section) { wrong++; printf("    flip at %zu accepted\n", i); }
            rad_bake_destroy(b);
            b = NULL;
        } else if (r != RAD_ERROR_CORRUPT && r != RAD_ERROR_TRUNCATED && r != RAD_ERROR_VERSION) {
            wrong++;
            printf("    flip at %zu: %s\n", i, rad_result_string(r));
        }
    }
    CHECK(flips > 100);
    CHECK(wrong == 0);
    /* another version, with a valid header checksum */
    memcpy(copy, buf, size);
    rad__put32(copy + 4, 2);
    rad__put32(copy + 60, rad__crc32(copy, 60));
    CHECK_RESULT(rad_load_memory(copy, size, NULL, &b), RAD_ERROR_VERSION);
    /* not a container at all */
    memcpy(copy, buf, size);
    memcpy(copy, "GIF8", 4);
    CHECK_RESULT(rad_load_memory(copy, size, NULL, &b), RAD_ERROR_CORRUPT);
    /* out-of-range indices behind valid checksums: a patch vertex, a patch triangle, a CSR column */
    for (sec = 0; sec < nsec; ++sec) {
        unsigned char *e;
        uint32_t type;
        memcpy(copy, buf, size);
        e = copy + 64 + 64 * (size_t)sec;
        type = rad__get32(e);
        if (type == RAD_SECTION_PATCHES) {
            rad_patch *p = (rad_patch *)(void *)(copy + rad__get64(e + 16));
            p[3].vertices[1] = f.P->vertex_count + 5;
            ct_fix_section_crc(copy, sec);
            CHECK_RESULT(rad_load_memory(copy, size, NULL, &b), RAD_ERROR_INDEX_OUT_OF_RANGE);
            memcpy(copy, buf, size);
            p[7].triangle = 1000000;
            ct_fix_section_crc(copy, sec);
            CHECK_RESULT(rad_load_memory(copy, size, NULL, &b), RAD_ERROR_INDEX_OUT_OF_RANGE);
            memcpy(copy, buf, size);
            p[2].albedo[1] = 1.5f;
            ct_fix_section_crc(copy, sec);
            CHECK_RESULT(rad_load_memory(copy, size, NULL, &b), RAD_ERROR_ALBEDO_RANGE);
        } else if (type == RAD_SECTION_FF_COLUMNS && rad__get64(e + 8) > 0) {
            uint32_t *col = (uint32_t *)(void *)(copy + rad__get64(e + 16));
            col[0] = f.P->count + 1;
            ct_fix_section_crc(copy, sec);
            CHECK_RESULT(rad_load_memory(copy, size, NULL, &b), RAD_ERROR_INDEX_OUT_OF_RANGE);
        } else if (type == RAD_SECTION_TRIANGLES) {
            uint32_t *tv = (uint32_t *)(void *)(copy + rad__get64(e + 16));
            tv[1] = 70000;
            ct_fix_section_crc(copy, sec);
            CHECK_RESULT(rad_load_memory(copy, size, NULL, &b), RAD_ERROR_INDEX_OUT_OF_RANGE);
        } else if (type == RAD_SECTION_VECTOR) {
            float *v = (float *)(void *)(copy + rad__get64(e + 16));
            v[4] = (float)NAN;
            ct_fix_section_crc(copy, sec);
            CHECK_RESULT(rad_load_memory(copy, size, NULL, &b), RAD_ERROR_NON_FINITE);
        }
    }
    /* unaligned input and NULLs */
    CHECK_RESULT(rad_load_memory((const unsigned char *)buf + 1, size - 1, NULL, &b), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_load_memory(NULL, size, NULL, &b), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_load_memory(buf, size, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    {
        void *none = (void *)1;
        size_t none_size = 1;
        CHECK_RESULT(rad_save_memory(NULL, NULL, NULL, NULL, NULL, &none, &none_size), RAD_ERROR_INVALID_ARGUMENT);
        CHECK(none == NULL && none_size == 0);
    }
    free(copy);
    rad_free_buffer(buf, NULL);
    ct_teardown(&f);
}

/* a matrix that does not match the patches is refused when saving */
static void ct_test_save_mismatch(void)
{
    ct_fixture f;
    rad_matrix m;
    void *buf = NULL;
    size_t size = 0;
    if (!ct_setup(&f)) { CHECK(0); ct_teardown(&f); return; }
    m = f.dense->matrix;
    m.rows = m.cols = f.P->count - 1;
    CHECK_RESULT(rad_save_memory(f.P, &m, NULL, NULL, NULL, &buf, &size), RAD_ERROR_SIZE_MISMATCH);
    CHECK(buf == NULL && size == 0);
    ct_teardown(&f);
}

/* the generic layer: user sections round-trip with their names */
static void ct_test_user_sections(void)
{
    rad_section s[2];
    const double payload[3] = { 1.0, 2.5, -3.0 };
    const char text[] = "hello";
    size_t size = 0;
    void *buf;
    rad_container *c = NULL;
    const rad_section *q;
    memset(s, 0, sizeof(s));
    s[0].type = RAD_SECTION_USER + 1; s[0].elem_size = 8; s[0].count = 3; s[0].data = payload; strcpy(s[0].name, "doubles");
    s[1].type = RAD_SECTION_USER + 2; s[1].elem_size = 1; s[1].count = sizeof(text); s[1].data = text; strcpy(s[1].name, "text");
    CHECK_OK(rad_container_size(s, 2, &size));
    buf = malloc(size);
    CHECK_RESULT(rad_container_write(s, 2, buf, size - 1), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_OK(rad_container_write(s, 2, buf, size));
    CHECK_OK(rad_container_create(buf, size, NULL, &c));
    q = rad_container_find(c, RAD_SECTION_USER + 1, "doubles");
    CHECK(q && q->count == 3 && memcmp(q->data, payload, sizeof(payload)) == 0);
    q = rad_container_find(c, RAD_SECTION_USER + 2, NULL);
    CHECK(q && strcmp((const char *)q->data, "hello") == 0);
    CHECK(rad_container_section(c, 2) == NULL);
    rad_container_destroy(c);
    free(buf);
}

/* every allocation of save and load fails in turn (the counting allocator of test_scene.c):
   each call returns success or RAD_ERROR_OUT_OF_MEMORY and nothing leaks */
static void ct_test_alloc_failure(void)
{
    ct_fixture f;
    sc_alloc_state st;
    rad_context ctx;
    long total, n;
    if (!ct_setup(&f)) { CHECK(0); ct_teardown(&f); return; }
    memset(&ctx, 0, sizeof(ctx));
    ctx.allocator.alloc = sc_alloc_fn;
    ctx.allocator.free = sc_free_fn;
    ctx.allocator.user = &st;
    for (n = 0, total = 1; n <= total; ++n) {
        void *buf = NULL;
        size_t size = 0;
        rad_bake *b = NULL;
        rad_result r1, r2 = RAD_SUCCESS;
        memset(&st, 0, sizeof(st));
        st.fail_at = n;
        r1 = rad_save_memory(f.P, &f.sparse->matrix, f.E, f.B, &ctx, &buf, &size);
        if (r1 == RAD_SUCCESS) {
            r2 = rad_load_memory(buf, size, &ctx, &b);
            rad_bake_destroy(b);
            rad_free_buffer(buf, &ctx);
        }
        CHECK(r1 == RAD_SUCCESS || r1 == RAD_ERROR_OUT_OF_MEMORY);
        CHECK(r2 == RAD_SUCCESS || r2 == RAD_ERROR_OUT_OF_MEMORY);
        CHECK(n == 0 || r1 != RAD_SUCCESS || r2 != RAD_SUCCESS || n > st.calls);
        CHECK(st.allocs == st.frees && st.live_bytes == 0 && st.corrupt == 0);
        if (n == 0) total = st.calls;
    }
    CHECK(total >= 5);
    ct_teardown(&f);
}

/* ---- values behind valid checksums, and the scene signature ------------------------------ */

/* float 'index' of section (type, name) set to 'value': rad_load_memory gives 'expected' and
   a message that contains 'what', "entry <index>" and 'shown' (the value as %g prints it) */
static void ct_expect_value(const void *buf, size_t size, uint32_t type, const char *name, uint64_t index, float value,
                            rad_result expected, const char *what, const char *shown)
{
    rad_context ctx;
    rad_bake *b = NULL;
    char entry[40];
    unsigned char *copy = ct_poke(buf, size, type, name, (size_t)index * 4u, &value, 4);
    CHECK(copy != NULL);
    if (!copy) return;
    ct_log_context(&ctx);
    CHECK_RESULT(rad_load_memory(copy, size, &ctx, &b), expected);
    CHECK(b == NULL || expected == RAD_SUCCESS);
    if (expected != RAD_SUCCESS) {
        snprintf(entry, sizeof(entry), "entry %llu ", (unsigned long long)index);
        if (!strstr(ct_log_last, what) || !strstr(ct_log_last, entry) || !strstr(ct_log_last, shown)) {
            printf("    message '%s' lacks '%s', '%s' or '%s'\n", ct_log_last, what, entry, shown);
            CHECK(0);
        }
    }
    rad_bake_destroy(b);
    free(copy);
}

/* rad_save_memory's bake plus the application's vector "H" (as rad bake writes it) */
static void *ct_save_with_h(const ct_fixture *f, const rad_matrix *F, uint32_t h_count, size_t *out_size)
{
    void *buf = NULL, *dst = NULL;
    size_t size = 0;
    rad_container *ct = NULL;
    rad_section s[16];
    uint32_t k = 0, i;
    *out_size = 0;
    if (rad_save_memory(f->P, F, f->E, f->B, NULL, &buf, &size) != RAD_SUCCESS) return NULL;
    if (rad_container_create(buf, size, NULL, &ct) == RAD_SUCCESS && rad_container_section_count(ct) < 15) {
        for (i = 0; i < rad_container_section_count(ct); ++i) s[k++] = *rad_container_section(ct, i);
        memset(&s[k], 0, sizeof(s[k]));
        s[k].type = RAD_SECTION_VECTOR;
        s[k].elem_size = 12;
        s[k].count = h_count;
        s[k].data = f->B;
        strcpy(s[k++].name, "H");
        if (rad_container_size(s, k, out_size) == RAD_SUCCESS && (dst = malloc(*out_size)) != NULL &&
            rad_container_write(s, k, dst, *out_size) != RAD_SUCCESS) {
            free(dst);
            dst = NULL;
        }
    }
    rad_container_destroy(ct);
    rad_free_buffer(buf, NULL);
    return dst;
}

/* Bakes with valid checksums but NaN, 3e38 or negative values: every loader value
   is checked once at load (NON_FINITE for NaN/Inf, CORRUPT for a finite value out of range),
   the message names the section, the entry and the value; rad_save_memory refuses to write
   what would not load. */
static void ct_test_bad_values(void)
{
    ct_fixture f;
    void *buf;
    size_t size = 0;
    rad_bake *b = NULL;
    rad_context ctx;
    const float qnan = (float)NAN;
    if (!ct_setup(&f)) { CHECK(0); ct_teardown(&f); return; }
    buf = ct_save_with_h(&f, &f.dense->matrix, f.P->count, &size);
    CHECK(buf != NULL);
    if (buf) {
        CHECK_OK(rad_load_memory(buf, size, NULL, &b));
        rad_bake_destroy(b);
        b = NULL;
        ct_expect_value(buf, size, RAD_SECTION_FF_DENSE, "F", 5, qnan, RAD_ERROR_NON_FINITE, "FF_DENSE", "nan");
        ct_expect_value(buf, size, RAD_SECTION_FF_DENSE, "F", 5, 3e38f, RAD_ERROR_CORRUPT, "FF_DENSE", "3e+38");
        ct_expect_value(buf, size, RAD_SECTION_FF_DENSE, "F", 5, -0.25f, RAD_ERROR_CORRUPT, "FF_DENSE", "negative");
        ct_expect_value(buf, size, RAD_SECTION_FF_DENSE, "F", 5, -0.0f, RAD_SUCCESS, "", "");
        ct_expect_value(buf, size, RAD_SECTION_VECTOR, "H", 7, qnan, RAD_ERROR_NON_FINITE, "vector 'H'", "nan");
        ct_expect_value(buf, size, RAD_SECTION_VECTOR, "H", 7, (float)INFINITY, RAD_ERROR_NON_FINITE, "vector 'H'", "inf");
        ct_expect_value(buf, size, RAD_SECTION_VECTOR, "H", 7, 3e38f, RAD_ERROR_CORRUPT, "vector 'H'", "3e+38");
        ct_expect_value(buf, size, RAD_SECTION_VECTOR, "H", 7, RAD_BAKE_VALUE_MAX, RAD_SUCCESS, "", "");
        ct_expect_value(buf, size, RAD_SECTION_VECTOR, "E", 1, -3e38f, RAD_ERROR_CORRUPT, "vector 'E'", "-3e+38");
        ct_expect_value(buf, size, RAD_SECTION_VECTOR, "B", 2, qnan, RAD_ERROR_NON_FINITE, "vector 'B'", "nan");
        ct_expect_value(buf, size, RAD_SECTION_PATCH_VERTICES, "vertices", 4, 3e38f, RAD_ERROR_CORRUPT, "PATCH_VERTICES", "3e+38");
        {
            /* patch 2's area and emission (rad_patch: area at byte 24, emission at 40) */
            static const float bad[3] = { (float)INFINITY, -1.0f, 3e38f };
            static const size_t at[3] = { 2 * sizeof(rad_patch) + 24, 2 * sizeof(rad_patch) + 40, 2 * sizeof(rad_patch) + 44 };
            static const rad_result want[3] = { RAD_ERROR_NON_FINITE, RAD_ERROR_NEGATIVE_EMISSION, RAD_ERROR_CORRUPT };
            int q;
            for (q = 0; q < 3; ++q) {
                unsigned char *copy = ct_poke(buf, size, RAD_SECTION_PATCHES, "patches", at[q], &bad[q], 4);
                CHECK(copy != NULL);
                if (!copy) continue;
                ct_log_context(&ctx);
                CHECK_RESULT(rad_load_memory(copy, size, &ctx, &b), want[q]);
                CHECK(strstr(ct_log_last, "patch 2 ") != NULL && strstr(ct_log_last, q ? "emission" : "area") != NULL);
                rad_bake_destroy(b);
                b = NULL;
                free(copy);
            }
        }
        free(buf);
    }
    /* a vector of the application's with the wrong length */
    buf = ct_save_with_h(&f, &f.dense->matrix, f.P->count - 1, &size);
    CHECK(buf != NULL);
    if (buf) {
        ct_log_context(&ctx);
        CHECK_RESULT(rad_load_memory(buf, size, &ctx, &b), RAD_ERROR_SIZE_MISMATCH);
        CHECK(strstr(ct_log_last, "vector 'H'") != NULL);
        free(buf);
    }
    /* the CSR values */
    buf = ct_save_with_h(&f, &f.sparse->matrix, f.P->count, &size);
    CHECK(buf != NULL);
    if (buf) {
        ct_expect_value(buf, size, RAD_SECTION_FF_VALUES, "F", 3, 3e38f, RAD_ERROR_CORRUPT, "FF_VALUES", "3e+38");
        ct_expect_value(buf, size, RAD_SECTION_FF_VALUES, "F", 3, -1.0f, RAD_ERROR_CORRUPT, "FF_VALUES", "negative");
        ct_expect_value(buf, size, RAD_SECTION_FF_VALUES, "F", 3, qnan, RAD_ERROR_NON_FINITE, "FF_VALUES", "nan");
        free(buf);
    }
    /* what would not load is not written */
    {
        const uint32_t n3 = 3 * f.P->count;
        float *E = (float *)malloc(sizeof(float) * n3), *D = (float *)malloc(sizeof(float) * f.P->count * f.P->count);
        rad_matrix m = f.dense->matrix;
        void *out = NULL;
        size_t out_size = 0;
        if (E && D) {
            memcpy(E, f.E, sizeof(float) * n3);
            E[4] = 3e38f;
            CHECK_RESULT(rad_save_memory(f.P, NULL, E, NULL, NULL, &out, &out_size), RAD_ERROR_CORRUPT);
            E[4] = qnan;
            CHECK_RESULT(rad_save_memory(f.P, NULL, NULL, E, NULL, &out, &out_size), RAD_ERROR_NON_FINITE);
            CHECK(out == NULL && out_size == 0);
            memcpy(D, f.dense->matrix.dense, sizeof(float) * f.P->count * f.P->count);
            D[9] = -0.5f;
            m.dense = D;
            CHECK_RESULT(rad_save_memory(f.P, &m, NULL, NULL, NULL, &out, &out_size), RAD_ERROR_CORRUPT);
        }
        free(E);
        free(D);
    }
    ct_teardown(&f);
}

/* the FNV-1a of the doc block, written out here from its text */
static uint64_t ct_fnv_words(uint64_t h, const void *words, size_t n)
{
    const unsigned char *p = (const unsigned char *)words;
    size_t i, k;
    for (i = 0; i < n; ++i) {
        uint32_t w;
        memcpy(&w, p + 4 * i, 4);
        for (k = 0; k < 4; ++k) h = (h ^ ((w >> (8 * k)) & 0xFFu)) * 0x100000001B3ull;
    }
    return h;
}

/* A scene of the same triangle count with one vertex moved, or one albedo changed, is refused
   with the reason; the same scene is accepted; a bake saved without a scene loads and is
   checked by its triangle count only (with a warning); the options hash is compared when both
   sides have one, so a bake of other options is not used as if it were this one. */
static void ct_test_signature(void)
{
    ct_fixture f;
    rad_scene_desc d;
    rad_mesh_desc meshes[16];
    rad_material mats[16];
    rad_scene *moved = NULL, *recoloured = NULL;
    rad_context ctx;
    void *buf = NULL;
    size_t size = 0;
    rad_bake *b = NULL;
    uint64_t g = 0, m = 0, want;
    float *pos = NULL;
    const float *orig;
    uint32_t t;
    CHECK(rad_hash64("", 0, RAD_HASH64_INIT) == 0xCBF29CE484222325ull);
    CHECK(rad_hash64("a", 1, RAD_HASH64_INIT) == 0xAF63DC4C8601EC8Cull);
    CHECK(rad_hash64("foobar", 6, RAD_HASH64_INIT) == 0x85944171F73967E8ull);
    if (!ct_setup(&f)) { CHECK(0); ct_teardown(&f); return; }
    /* the hashes are the documented ones */
    CHECK_OK(rad_scene_hash(f.scene, &g, &m));
    want = ct_fnv_words(RAD_HASH64_INIT, &f.scene->triangle_count, 1);
    want = ct_fnv_words(want, f.scene->positions, 9u * (size_t)f.scene->triangle_count);
    CHECK(g == want && g != 0);
    want = ct_fnv_words(RAD_HASH64_INIT, &f.scene->triangle_count, 1);
    for (t = 0; t < f.scene->triangle_count; ++t) {
        const rad_material *mt = &f.scene->materials_table[f.scene->materials[t]];
        want = ct_fnv_words(want, mt->albedo, 3);
        want = ct_fnv_words(want, mt->emission, 3);
        want = ct_fnv_words(want, &mt->texture, 1);
    }
    {
        const uint32_t no_uvs = 0;
        CHECK(f.scene->uvs == NULL);
        want = ct_fnv_words(want, &no_uvs, 1);
    }
    CHECK(m == want && m != g);
    {
        uint64_t g2 = 1, m2 = 1;
        CHECK_RESULT(rad_scene_hash(NULL, &g2, &m2), RAD_ERROR_INVALID_ARGUMENT);
        CHECK(g2 == 0 && m2 == 0);
    }

    /* the same counts, one vertex moved / one albedo changed */
    rad_cornell_box(&d, NULL);
    CHECK(d.mesh_count <= 16 && d.material_count <= 16);
    memcpy(meshes, d.meshes, sizeof(rad_mesh_desc) * d.mesh_count);
    memcpy(mats, d.materials, sizeof(rad_material) * d.material_count);
    pos = (float *)malloc(sizeof(float) * 3 * meshes[0].vertex_count);
    CHECK(meshes[0].position_stride == 0 || meshes[0].position_stride == 3 * sizeof(float));
    orig = meshes[0].positions;
    memcpy(pos, orig, sizeof(float) * 3 * meshes[0].vertex_count);
    pos[1] += 0.01f;
    meshes[0].positions = pos;
    d.meshes = meshes;
    CHECK_OK(rad_scene_create(&d, NULL, &moved));
    meshes[0].positions = orig; /* back to the original geometry */
    mats[0].albedo[1] *= 0.5f;
    d.materials = mats;
    CHECK_OK(rad_scene_create(&d, NULL, &recoloured));

    CHECK_OK(rad_save_memory(f.P, &f.dense->matrix, f.E, f.B, NULL, &buf, &size));
    CHECK_OK(rad_load_memory(buf, size, NULL, &b));
    if (b && moved && recoloured) {
        CHECK(b->signature != NULL);
        if (b->signature) {
            CHECK(b->signature->geometry == g && b->signature->materials == m && b->signature->options == 0);
        }
        CHECK(moved->triangle_count == f.scene->triangle_count);
        ct_log_context(&ctx);
        CHECK_OK(rad_bake_matches_scene(b, f.scene, 0, &ctx));
        CHECK_OK(rad_bake_matches_scene(b, f.scene, 1234, &ctx)); /* the bake has no options hash */
        CHECK(ct_log_last[0] == '\0');
        CHECK_RESULT(rad_bake_matches_scene(b, moved, 0, &ctx), RAD_ERROR_SCENE_MISMATCH);
        CHECK(strstr(ct_log_last, "the geometry differs") != NULL && strstr(ct_log_last, "materials") != NULL);
        CHECK_RESULT(rad_bake_matches_scene(b, recoloured, 0, &ctx), RAD_ERROR_SCENE_MISMATCH);
        CHECK(strstr(ct_log_last, "the materials differ") != NULL && strstr(ct_log_last, "geometry differs") == NULL);
        CHECK_RESULT(rad_bake_matches_scene(NULL, f.scene, 0, &ctx), RAD_ERROR_INVALID_ARGUMENT);
        CHECK_RESULT(rad_bake_matches_scene(b, NULL, 0, &ctx), RAD_ERROR_INVALID_ARGUMENT);
    }
    rad_bake_destroy(b);
    b = NULL;
    /* an options hash written into the signature (as rad bake does): compared when both have one */
    {
        rad_bake_signature sig;
        unsigned char *copy;
        memset(&sig, 0, sizeof(sig));
        sig.geometry = g;
        sig.materials = m;
        sig.options = 1234;
        copy = ct_poke(buf, size, RAD_SECTION_SIGNATURE, "signature", 0, &sig, sizeof(sig));
        CHECK(copy != NULL);
        if (copy) {
            CHECK_OK(rad_load_memory(copy, size, NULL, &b));
            ct_log_context(&ctx);
            if (b) {
                CHECK_OK(rad_bake_matches_scene(b, f.scene, 1234, &ctx));
                CHECK_OK(rad_bake_matches_scene(b, f.scene, 0, &ctx));
                CHECK_RESULT(rad_bake_matches_scene(b, f.scene, 4321, &ctx), RAD_ERROR_SCENE_MISMATCH);
                CHECK(strstr(ct_log_last, "the options differ") != NULL);
                if (moved) {
                    CHECK_RESULT(rad_bake_matches_scene(b, moved, 4321, &ctx), RAD_ERROR_SCENE_MISMATCH);
                    CHECK(strstr(ct_log_last, "the geometry and options differ") != NULL);
                }
            }
            rad_bake_destroy(b);
            b = NULL;
            free(copy);
        }
    }
    rad_free_buffer(buf, NULL);
    buf = NULL;
    /* a bake saved without its scene (as before the signature existed) */
    {
        rad_patches P = *f.P;
        P.scene = NULL;
        CHECK_OK(rad_save_memory(&P, NULL, f.E, NULL, NULL, &buf, &size));
        CHECK_OK(rad_load_memory(buf, size, NULL, &b));
        if (b) {
            CHECK(b->signature == NULL && rad_container_find(b->container, RAD_SECTION_SIGNATURE, NULL) == NULL);
            ct_log_context(&ctx);
            CHECK_OK(rad_bake_matches_scene(b, moved ? moved : f.scene, 0, &ctx));
            CHECK(ct_log_warnings == 1 && strstr(ct_log_last, "no signature") != NULL);
            b->patches.triangle_count--; /* another triangle count is refused even so */
            CHECK_RESULT(rad_bake_matches_scene(b, f.scene, 0, &ctx), RAD_ERROR_SCENE_MISMATCH);
            CHECK(strstr(ct_log_last, "geometry differs") != NULL);
            b->patches.triangle_count++;
        }
        rad_bake_destroy(b);
        rad_free_buffer(buf, NULL);
    }
    rad_scene_destroy(moved);
    rad_scene_destroy(recoloured);
    free(pos);
    ct_teardown(&f);
}

/* The one table of section ids: every id the library writes has the name of its enumerator,
   the gaps between the ranges have none, user types are "USER". */
static void ct_test_section_names(void)
{
    CHECK(strcmp(rad_section_type_name(RAD_SECTION_PATCHES), "PATCHES") == 0);
    CHECK(strcmp(rad_section_type_name(RAD_SECTION_SIGNATURE), "SIGNATURE") == 0);
    CHECK(strcmp(rad_section_type_name(RAD_SECTION_MB_INFO), "MB_INFO") == 0);
    CHECK(strcmp(rad_section_type_name(RAD_SECTION_MB_OUTLIER_VALUES), "MB_OUTLIER_VALUES") == 0);
    CHECK(strcmp(rad_section_type_name(RAD_SECTION_TEMPORAL_BINS), "TEMPORAL_BINS") == 0);
    CHECK(strcmp(rad_section_type_name(RAD_SECTION_VP_INFO), "VP_INFO") == 0);
    CHECK(strcmp(rad_section_type_name(RAD_SECTION_VP_SAMPLE_TRIANGLES), "VP_SAMPLE_TRIANGLES") == 0);
    CHECK(strcmp(rad_section_type_name(RAD_SECTION_USER + 7u), "USER") == 0);
    CHECK(rad_section_type_name(0) == NULL);
    CHECK(rad_section_type_name(10) == NULL);
    CHECK(rad_section_type_name(RAD_SECTION_VP_SAMPLE_TRIANGLES + 1u) == NULL);
}

static const rad_test_case tests_container[] = {
    { "container_round_trip", ct_test_round_trip },
    { "container_corruption", ct_test_corruption },
    { "container_save_mismatch", ct_test_save_mismatch },
    { "container_user_sections", ct_test_user_sections },
    { "container_alloc_failure", ct_test_alloc_failure },
    { "container_bad_values", ct_test_bad_values },
    { "container_signature", ct_test_signature },
    { "container_section_names", ct_test_section_names },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_container)
