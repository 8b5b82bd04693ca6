/* test_glsl.c - the embedded GLSL sources and their access functions (>>api_glsl). The kernels
   themselves are compiled and run against the CPU paths by tests/test_vulkan.c. */
#include "fixtures.h"


static void test_glsl_sources(void)
{
    uint32_t id;
    for (id = 0; id < (uint32_t)RAD_GLSL_COUNT; ++id) {
        size_t len = 0, len2 = 0, at = 0;
        uint32_t count = 0, p;
        const char *const *pieces = rad_glsl_pieces((rad_glsl_id)id, &count);
        char *src;
        CHECK(rad_glsl_name((rad_glsl_id)id) != NULL);
        CHECK_OK(rad_glsl_source((rad_glsl_id)id, NULL, 0, &len));
        CHECK(len > 100);
        CHECK(pieces != NULL && count >= 1);
        src = (char *)malloc(len + 1);
        if (!src || !pieces) { free(src); continue; }
        /* one byte short: refused, nothing written */
        memset(src, 'x', len + 1);
        CHECK_RESULT(rad_glsl_source((rad_glsl_id)id, src, len, &len2), RAD_ERROR_SIZE_MISMATCH);
        CHECK(len2 == len && src[0] == 'x');
        CHECK_OK(rad_glsl_source((rad_glsl_id)id, src, len + 1, NULL));
        CHECK(strlen(src) == len);
        for (p = 0; p < count; ++p) {
            size_t n = strlen(pieces[p]);
            CHECK(n > 0 && n <= 4000 && pieces[p][n - 1] == '\n');
            CHECK(at + n <= len && memcmp(src + at, pieces[p], n) == 0);
            at += n;
        }
        CHECK(at == len);
        if (strstr(rad_glsl_name((rad_glsl_id)id), ".comp")) { /* kernels (includes such as .glsl have no main) */
            CHECK(strncmp(src, "#version 450\n", 13) == 0);
            CHECK(strstr(src, "layout(local_size_x_id = 0) in;") != NULL);
            CHECK(strstr(src, "layout(push_constant)") != NULL);
        }
        free(src);
    }
    CHECK(rad_glsl_name(RAD_GLSL_COUNT) == NULL);
    {
        uint32_t count = 7;
        size_t len = 0;
        char buf[8];
        CHECK(rad_glsl_pieces(RAD_GLSL_COUNT, &count) == NULL && count == 0);
        CHECK_RESULT(rad_glsl_source(RAD_GLSL_COUNT, buf, sizeof(buf), &len), RAD_ERROR_INVALID_ARGUMENT);
        CHECK_RESULT(rad_glsl_source(RAD_GLSL_GATHER_DENSE, NULL, 0, NULL), RAD_ERROR_INVALID_ARGUMENT);
        CHECK_RESULT(rad_glsl_source(RAD_GLSL_GATHER_DENSE, NULL, 5, &len), RAD_ERROR_INVALID_ARGUMENT);
    }
}

static const rad_test_case tests_glsl[] = {
    { "glsl_sources", test_glsl_sources },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_glsl)
