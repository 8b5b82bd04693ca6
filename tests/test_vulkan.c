/* test_vulkan.c - every GLSL kernel of radiosity.h compiled (from the header's embedded source,
   by glslangValidator) and run on a Vulkan device (any: Mesa's lavapipe in CI), compared with
   the CPU path on the same inputs (>>api_glsl). Each kernel runs in row chunks bound at offsets
   (the chunked processing of matrices larger than one storage-buffer range) and with two
   workgroup sizes (specialization constant 0).

       test_vulkan [WORKDIR [NAME]]   (WORKDIR: where .comp/.spv files are written, default the
                                      binary's directory; NAME: run the tests whose name has it)

   Ends with "N passed, N failed" like test_main. Exit 0 when nothing failed. */
#define RADIOSITY_IMPLEMENTATION
#include "../radiosity.h"
#include "vk_util.h"
#include <math.h>
#include <stddef.h>

static int g_passed, g_failed, g_checks_failed;
static double g_worst; /* largest relative error of the current test */
static const char *g_worst_what; /* what g_worst measures */
static vk_ctx g_vk;
static const uint32_t g_local_sizes[2] = { 64, 7 }; /* 7: not a power of two, not a subgroup multiple */

#define T_CHECK(cond)                                                                                \
    do {                                                                                             \
        if (!(cond)) { printf("    FAIL %s:%d: %s\n", __FILE__, __LINE__, #cond); g_checks_failed++; } \
    } while (0)

static uint32_t g_rng = 12345u;
static float frand(void)
{
    g_rng = g_rng * 1664525u + 1013904223u;
    return (float)(g_rng >> 8) / 16777216.0f;
}

/* |gpu - cpu| <= rel * max(|cpu|, floor) elementwise, floor = 1e-3 of the largest |cpu| */
static int compare(const char *what, const float *gpu, const float *cpu, size_t n, double rel)
{
    size_t i, worst = 0;
    double mx = 0.0, err = 0.0;
    for (i = 0; i < n; ++i) mx = fabs(cpu[i]) > mx ? fabs(cpu[i]) : mx;
    for (i = 0; i < n; ++i) {
        double s = fabs(cpu[i]) > 1e-3 * mx ? fabs(cpu[i]) : 1e-3 * mx, e = fabs((double)gpu[i] - cpu[i]) / (s > 0 ? s : 1.0);
        if (!(e <= err)) { err = e; worst = i; }
    }
    if (err > g_worst) g_worst = err;
    if (!(err <= rel)) {
        printf("    FAIL %s: relative error %.3g > %.3g at %lu (gpu %.9g, cpu %.9g)\n", what, err, rel, (unsigned long)worst,
               (double)gpu[worst], (double)cpu[worst]);
        g_checks_failed++;
        return 0;
    }
    return 1;
}

/* a random N x N form-factor-like matrix: non-negative, about 'density' non-zero, rows sum < 0.95 */
static float *random_matrix(uint32_t n, float density)
{
    float *F = (float *)calloc((size_t)n * n, sizeof(float));
    uint32_t i, j;
    if (!F) return NULL;
    for (i = 0; i < n; ++i) {
        double s = 0.0;
        for (j = 0; j < n; ++j) {
            float u = frand();
            if (i != j && u < density) F[(size_t)i * n + j] = frand();
            s += F[(size_t)i * n + j];
        }
        if (s > 0)
            for (j = 0; j < n; ++j) F[(size_t)i * n + j] = (float)(F[(size_t)i * n + j] * (0.3 + 0.6 * frand()) / s);
    }
    return F;
}

static float *random_vector(size_t n, float zero_fraction)
{
    float *v = (float *)malloc(n * sizeof(float));
    size_t i;
    if (!v) return NULL;
    for (i = 0; i < n; ++i) v[i] = frand() < zero_fraction ? 0.0f : frand() * 2.0f;
    return v;
}

/* CSR view of a dense matrix (zeros dropped) */
typedef struct csr { uint64_t *off; uint32_t *col; float *val; } csr;
static rad_matrix make_csr(const float *F, uint32_t n, csr *c)
{
    rad_matrix m;
    uint32_t i, j;
    uint64_t k = 0;
    c->off = (uint64_t *)malloc(((size_t)n + 1) * sizeof(uint64_t));
    c->col = (uint32_t *)malloc((size_t)n * n * sizeof(uint32_t) + 4);
    c->val = (float *)malloc((size_t)n * n * sizeof(float) + 4);
    memset(&m, 0, sizeof(m));
    if (!c->off || !c->col || !c->val) return m;
    for (i = 0; i < n; ++i) {
        c->off[i] = k;
        for (j = 0; j < n; ++j)
            if (F[(size_t)i * n + j] != 0.0f) { c->col[k] = j; c->val[k] = F[(size_t)i * n + j]; ++k; }
    }
    c->off[n] = k;
    m.rows = m.cols = n;
    m.storage = RAD_STORAGE_SPARSE;
    m.row_offsets = c->off;
    m.columns = c->col;
    m.values = c->val;
    return m;
}

/* row chunks used by every test: three uneven pieces */
static void chunks(uint32_t n, uint32_t cut[4])
{
    cut[0] = 0;
    cut[1] = n / 3 + 1;
    cut[2] = (2 * n) / 3 + 3 < n ? (2 * n) / 3 + 3 : n;
    cut[3] = n;
}

/* ---- dense and CSR gather: one classic bounce ------------------------------------------- */

static void test_gather(int sparse)
{
    const uint32_t n = 150;
    float *F = random_matrix(n, sparse ? 0.1f : 0.7f), *E = random_vector(3 * n, 0.5f), *rho = random_vector(3 * n, 0.0f);
    float *cpu = (float *)malloc(3 * n * sizeof(float));
    csr c;
    rad_matrix m;
    rad_system sys;
    rad_solve_options so;
    int ls, total;
    memset(&c, 0, sizeof(c));
    if (!F || !E || !rho || !cpu) { T_CHECK(0); goto done; }
    {
        size_t i;
        for (i = 0; i < 3 * (size_t)n; ++i) rho[i] *= 0.45f; /* [0, 0.9) */
    }
    if (sparse) m = make_csr(F, n, &c);
    else {
        memset(&m, 0, sizeof(m));
        m.rows = m.cols = n;
        m.storage = RAD_STORAGE_DENSE;
        m.dense = F;
    }
    memset(&sys, 0, sizeof(sys));
    sys.F = &m;
    sys.albedo = rho;
    sys.E = E;
    sys.n = n;
    for (ls = 0; ls < 2; ++ls) {
        vk_kernel k;
        vk_buf bF, bC, bV, bO, bE, bR, bOut;
        uint32_t nb = sparse ? 6u : 4u;
        if (!vk_kernel_create(&g_vk, &k, sparse ? RAD_GLSL_GATHER_CSR : RAD_GLSL_GATHER_DENSE, 0, nb,
                              sparse ? (uint32_t)sizeof(rad_glsl_gather_csr_push) : (uint32_t)sizeof(rad_glsl_gather_dense_push),
                              g_local_sizes[ls])) { T_CHECK(0); break; }
        memset(&bC, 0, sizeof(bC)); memset(&bV, 0, sizeof(bV)); memset(&bO, 0, sizeof(bO)); memset(&bF, 0, sizeof(bF));
        if (sparse) {
            T_CHECK(vk_buffer(&g_vk, &bO, ((size_t)n + 1) * 8, c.off));
            T_CHECK(vk_buffer(&g_vk, &bC, c.off[n] * 4, c.col));
            T_CHECK(vk_buffer(&g_vk, &bV, c.off[n] * 4, c.val));
        } else {
            T_CHECK(vk_buffer(&g_vk, &bF, (size_t)n * n * 4, F));
        }
        T_CHECK(vk_buffer(&g_vk, &bE, 3 * n * 4, E));
        T_CHECK(vk_buffer(&g_vk, &bR, 3 * n * 4, rho));
        T_CHECK(vk_buffer(&g_vk, &bOut, 3 * n * 4, NULL));
        for (total = 0; total < 2; ++total) {
            uint32_t cut[4], q;
            rad_solve_options_default(&so);
            so.bounces = 1;
            so.output = total ? RAD_OUTPUT_TOTAL : RAD_OUTPUT_INDIRECT;
            T_CHECK(rad_solve_jacobi(&sys, &so, cpu, NULL, NULL) == RAD_SUCCESS);
            memset(bOut.map, 0xFF, 3 * n * 4); /* NaN: every row must be written */
            chunks(n, cut);
            for (q = 0; q < 3; ++q) {
                vk_range r[6];
                if (cut[q + 1] == cut[q]) continue;
                if (sparse) {
                    rad_glsl_gather_csr_push p;
                    uint32_t base = 0;
                    uint64_t e0 = c.off[cut[q]], e1 = c.off[cut[q + 1]];
                    r[0] = vk_whole(&bO);
                    r[1] = vk_chunk(&g_vk, &bC, 4, e0, e1 - e0, &base);
                    r[2] = vk_chunk(&g_vk, &bV, 4, e0, e1 - e0, &base);
                    r[3] = vk_whole(&bE); r[4] = vk_whole(&bR); r[5] = vk_whole(&bOut);
                    p.row_offset = cut[q];
                    p.row_count = cut[q + 1] - cut[q];
                    p.entry_base = (uint32_t)e0 - base;
                    p.flags = total ? RAD_GLSL_OUTPUT_TOTAL : 0u;
                    T_CHECK(vk_dispatch(&g_vk, &k, r, &p, p.row_count));
                } else {
                    rad_glsl_gather_dense_push p;
                    r[0] = vk_chunk(&g_vk, &bF, 4, (VkDeviceSize)cut[q] * n, (VkDeviceSize)(cut[q + 1] - cut[q]) * n, &p.f_base);
                    r[1] = vk_whole(&bE); r[2] = vk_whole(&bR); r[3] = vk_whole(&bOut);
                    p.row_offset = cut[q];
                    p.row_count = cut[q + 1] - cut[q];
                    p.cols = n;
                    p.flags = total ? RAD_GLSL_OUTPUT_TOTAL : 0u;
                    T_CHECK(vk_dispatch(&g_vk, &k, r, &p, p.row_count));
                }
            }
            compare(sparse ? "csr gather" : "dense gather", (const float *)bOut.map, cpu, 3 * (size_t)n, 1e-5);
        }
        vk_buffer_free(&g_vk, &bF); vk_buffer_free(&g_vk, &bC); vk_buffer_free(&g_vk, &bV); vk_buffer_free(&g_vk, &bO);
        vk_buffer_free(&g_vk, &bE); vk_buffer_free(&g_vk, &bR); vk_buffer_free(&g_vk, &bOut);
        vk_kernel_destroy(&g_vk, &k);
    }
done:
    free(F); free(E); free(rho); free(cpu); free(c.off); free(c.col); free(c.val);
}

static void test_gather_dense(void) { test_gather(0); }
static void test_gather_csr(void) { test_gather(1); }

/* ---- chunked processing of a matrix larger than one storage-buffer range --------------------- */

static void test_gather_over_range(void)
{
    const VkDeviceSize range = g_vk.props.limits.maxStorageBufferRange;
    uint32_t n = 6000, rows_per_chunk, r0, i, j, dispatches = 0;
    float *F, *E, *rho, *cpu;
    rad_matrix m;
    rad_system sys;
    rad_solve_options so;
    vk_kernel k;
    vk_buf bF, bE, bR, bOut;
    int ok = 1;
    if ((VkDeviceSize)n * n * 4 <= range) {
        /* a driver with a large range (4 GiB on most desktop GPUs): a matrix beyond it would not
           fit memory here; still run the chunked path with 8 chunks */
        n = 2000;
    }
    F = (float *)malloc((size_t)n * n * sizeof(float));
    E = random_vector(3 * (size_t)n, 0.5f);
    rho = random_vector(3 * (size_t)n, 0.0f);
    cpu = (float *)malloc(3 * (size_t)n * sizeof(float));
    if (!F || !E || !rho || !cpu) { T_CHECK(0); free(F); free(E); free(rho); free(cpu); return; }
    for (i = 0; i < n; ++i)
        for (j = 0; j < n; ++j) F[(size_t)i * n + j] = (float)((i * 7u + j * 13u) % 17u) * (0.9f / (16.0f * (float)n));
    for (i = 0; i < 3 * n; ++i) rho[i] *= 0.45f;
    memset(&m, 0, sizeof(m));
    m.rows = m.cols = n;
    m.storage = RAD_STORAGE_DENSE;
    m.dense = F;
    memset(&sys, 0, sizeof(sys));
    sys.F = &m;
    sys.albedo = rho;
    sys.E = E;
    sys.n = n;
    rad_solve_options_default(&so);
    so.bounces = 1;
    T_CHECK(rad_solve_jacobi(&sys, &so, cpu, NULL, NULL) == RAD_SUCCESS);
    /* rows per dispatch: what one range holds, less the alignment slack */
    rows_per_chunk = (uint32_t)((range - g_vk.props.limits.minStorageBufferOffsetAlignment) / ((VkDeviceSize)n * 4));
    if ((VkDeviceSize)n * n * 4 <= range) rows_per_chunk = n / 8 + 1;
    if (rows_per_chunk > g_vk.props.limits.maxComputeWorkGroupCount[0]) rows_per_chunk = g_vk.props.limits.maxComputeWorkGroupCount[0];
    if (!vk_kernel_create(&g_vk, &k, RAD_GLSL_GATHER_DENSE, 0, 4, (uint32_t)sizeof(rad_glsl_gather_dense_push), 128)) {
        T_CHECK(0); free(F); free(E); free(rho); free(cpu); return;
    }
    ok &= vk_buffer(&g_vk, &bF, (VkDeviceSize)n * n * 4, F);
    ok &= vk_buffer(&g_vk, &bE, 3 * (VkDeviceSize)n * 4, E);
    ok &= vk_buffer(&g_vk, &bR, 3 * (VkDeviceSize)n * 4, rho);
    ok &= vk_buffer(&g_vk, &bOut, 3 * (VkDeviceSize)n * 4, NULL);
    if (ok) memset(bOut.map, 0xFF, 3 * (size_t)n * 4);
    for (r0 = 0; r0 < n && ok; r0 += rows_per_chunk) {
        rad_glsl_gather_dense_push p;
        vk_range r[4];
        p.row_offset = r0;
        p.row_count = n - r0 < rows_per_chunk ? n - r0 : rows_per_chunk;
        p.cols = n;
        p.flags = 0;
        r[0] = vk_chunk(&g_vk, &bF, 4, (VkDeviceSize)r0 * n, (VkDeviceSize)p.row_count * n, &p.f_base);
        T_CHECK(r[0].range <= range);
        r[1] = vk_whole(&bE); r[2] = vk_whole(&bR); r[3] = vk_whole(&bOut);
        ok &= vk_dispatch(&g_vk, &k, r, &p, p.row_count);
        ++dispatches;
    }
    T_CHECK(ok && dispatches >= 2);
    if (ok) compare("dense gather over the storage-buffer range", (const float *)bOut.map, cpu, 3 * (size_t)n, 1e-5);
    printf("    N = %u: %.1f MiB matrix, maxStorageBufferRange %.1f MiB, %u dispatches\n", n, (double)n * n * 4 / 1048576.0,
           (double)range / 1048576.0, dispatches);
    vk_buffer_free(&g_vk, &bF); vk_buffer_free(&g_vk, &bE); vk_buffer_free(&g_vk, &bR); vk_buffer_free(&g_vk, &bOut);
    vk_kernel_destroy(&g_vk, &k);
    free(F); free(E); free(rho); free(cpu);
}

/* ---- multi-bounce apply, float and half, with and without permutations --------------------- */

static int gpu_mb_apply(const rad_multibounce *mb, const float *E, rad_output output, uint32_t local_size, float *out)
{
    const uint32_t n = mb->n;
    const int half = mb->precision == RAD_MB_HALF;
    const size_t esz = half ? 2u : 4u, nn = (size_t)n * n;
    vk_kernel k;
    vk_buf planes[3], bE, bCol, bRow, bOut;
    uint32_t ch, cut[4], q, idp[1] = { 0 };
    int ok = 1;
    if (!vk_kernel_create(&g_vk, &k, half ? RAD_GLSL_MB_APPLY_HALF : RAD_GLSL_MB_APPLY_FLOAT, 0, 7,
                          (uint32_t)sizeof(rad_glsl_mb_apply_push), local_size)) return 0;
    for (ch = 0; ch < 3; ++ch)
        ok &= vk_buffer(&g_vk, &planes[ch], nn * esz,
                        half ? (const void *)(mb->half + ch * nn) : (const void *)(mb->planes + ch * nn));
    ok &= vk_buffer(&g_vk, &bE, 3 * (size_t)n * 4, E);
    ok &= vk_buffer(&g_vk, &bCol, mb->col_perm ? (size_t)n * 4 : 4, mb->col_perm ? (const void *)mb->col_perm : (const void *)idp);
    ok &= vk_buffer(&g_vk, &bRow, mb->row_perm ? (size_t)n * 4 : 4, mb->row_perm ? (const void *)mb->row_perm : (const void *)idp);
    ok &= vk_buffer(&g_vk, &bOut, 3 * (size_t)n * 4, NULL);
    memset(bOut.map, 0xFF, 3 * (size_t)n * 4);
    chunks(n, cut);
    for (q = 0; q < 3 && ok; ++q) {
        vk_range r[7];
        rad_glsl_mb_apply_push p;
        uint32_t base = 0;
        for (ch = 0; ch < 3; ++ch)
            r[ch] = vk_chunk(&g_vk, &planes[ch], esz, (VkDeviceSize)cut[q] * n, (VkDeviceSize)(cut[q + 1] - cut[q]) * n, &base);
        r[3] = vk_whole(&bE); r[4] = vk_whole(&bCol); r[5] = vk_whole(&bRow); r[6] = vk_whole(&bOut);
        p.n = n;
        p.row_offset = cut[q];
        p.row_count = cut[q + 1] - cut[q];
        p.base = base;
        p.flags = (output == RAD_OUTPUT_TOTAL ? RAD_GLSL_OUTPUT_TOTAL : 0u) | (mb->row_perm ? RAD_GLSL_MB_PERMUTED : 0u);
        if (p.row_count) ok &= vk_dispatch(&g_vk, &k, r, &p, p.row_count);
    }
    if (ok) memcpy(out, bOut.map, 3 * (size_t)n * 4);
    for (ch = 0; ch < 3; ++ch) vk_buffer_free(&g_vk, &planes[ch]);
    vk_buffer_free(&g_vk, &bE); vk_buffer_free(&g_vk, &bCol); vk_buffer_free(&g_vk, &bRow); vk_buffer_free(&g_vk, &bOut);
    vk_kernel_destroy(&g_vk, &k);
    return ok;
}

static void test_mb_apply(void)
{
    const uint32_t n = 91; /* odd: the half planes' chunks start at odd binary16 offsets */
    float *F = random_matrix(n, 0.6f), *E = random_vector(3 * n, 0.4f), *rho = random_vector(3 * n, 0.0f);
    float *cpu = (float *)malloc(3 * n * sizeof(float)), *gpu = (float *)malloc(3 * n * sizeof(float));
    rad_matrix m;
    rad_multibounce_options o;
    rad_multibounce *mb = NULL, *mbh = NULL, *mbp = NULL, *mbph = NULL;
    int v, ls, total;
    size_t i;
    if (!F || !E || !rho || !cpu || !gpu) { T_CHECK(0); goto done; }
    for (i = 0; i < 3 * (size_t)n; ++i) rho[i] *= 0.45f;
    memset(&m, 0, sizeof(m));
    m.rows = m.cols = n;
    m.storage = RAD_STORAGE_DENSE;
    m.dense = F;
    rad_multibounce_options_default(&o);
    o.bounces = 3;
    T_CHECK(rad_multibounce_create(&m, rho, &o, NULL, &mb) == RAD_SUCCESS);
    T_CHECK(mb && rad_multibounce_convert(mb, RAD_MB_HALF, NULL, &mbh) == RAD_SUCCESS);
    T_CHECK(mb && rad_multibounce_reorder(mb, 0, NULL, &mbp) == RAD_SUCCESS);
    T_CHECK(mbp && rad_multibounce_convert(mbp, RAD_MB_HALF, NULL, &mbph) == RAD_SUCCESS);
    if (!mb || !mbh || !mbp || !mbph) goto done;
    T_CHECK(mbp->row_perm != NULL && mbp->col_perm != NULL);
    for (v = 0; v < 4; ++v) {
        const rad_multibounce *x = v == 0 ? mb : v == 1 ? mbh : v == 2 ? mbp : mbph;
        for (ls = 0; ls < 2; ++ls)
            for (total = 0; total < 2; ++total) {
                rad_output out = total ? RAD_OUTPUT_TOTAL : RAD_OUTPUT_INDIRECT;
                T_CHECK(rad_multibounce_apply(x, E, cpu, out, NULL) == RAD_SUCCESS);
                T_CHECK(gpu_mb_apply(x, E, out, g_local_sizes[ls], gpu));
                compare(v == 0 ? "mb float" : v == 1 ? "mb half" : v == 2 ? "mb float permuted" : "mb half permuted", gpu, cpu,
                        3 * (size_t)n, 1e-5);
            }
    }
done:
    rad_multibounce_destroy(mb); rad_multibounce_destroy(mbh); rad_multibounce_destroy(mbp); rad_multibounce_destroy(mbph);
    free(F); free(E); free(rho); free(cpu); free(gpu);
}

/* ---- multi-bounce apply from BC1 / 3xBC4 textures, outliers and permutations ---------------- */

typedef struct gpu_blocks {
    vk_kernel k;
    vk_image img[3];
    vk_buf scales, E, col, row, off, ocol, oval, out;
} gpu_blocks;

static int gpu_blocks_init(gpu_blocks *g, const rad_multibounce_blocks *b, uint32_t local_size)
{
    const uint32_t n = b->n, size = 4u * b->blocks_per_row, planes = b->format == RAD_BLOCK_BC1 ? 1u : 3u;
    const size_t nblocks = (size_t)b->blocks_per_row * b->blocks_per_row;
    const size_t tiles = (size_t)b->tiles_per_row * b->tiles_per_row;
    uint32_t c, zero[2] = { 0, 0 };
    int ok = 1;
    memset(g, 0, sizeof(*g));
    if (!vk_kernel_create(&g_vk, &g->k, RAD_GLSL_MB_APPLY_BLOCKS, 3, 11, (uint32_t)sizeof(rad_glsl_mb_blocks_push), local_size))
        return 0;
    for (c = 0; c < planes; ++c)
        ok &= vk_image_blocks(&g_vk, &g->img[c], planes == 1 ? VK_FORMAT_BC1_RGB_UNORM_BLOCK : VK_FORMAT_BC4_UNORM_BLOCK, size,
                              b->blocks + 8 * nblocks * c, 8 * nblocks);
    ok &= vk_buffer(&g_vk, &g->scales, 3 * tiles * 4, b->scales);
    ok &= vk_buffer(&g_vk, &g->E, 3 * (size_t)n * 4, NULL);
    ok &= vk_buffer(&g_vk, &g->col, b->col_perm ? 4 * (size_t)n : 4, b->col_perm ? (const void *)b->col_perm : (const void *)zero);
    ok &= vk_buffer(&g_vk, &g->row, b->row_perm ? 4 * (size_t)n : 4, b->row_perm ? (const void *)b->row_perm : (const void *)zero);
    ok &= vk_buffer(&g_vk, &g->off, b->outlier_count ? 8 * ((size_t)n + 1) : 8,
                    b->outlier_count ? (const void *)b->outlier_offsets : (const void *)zero);
    ok &= vk_buffer(&g_vk, &g->ocol, b->outlier_count ? 4 * (size_t)b->outlier_count : 4,
                    b->outlier_count ? (const void *)b->outlier_columns : (const void *)zero);
    ok &= vk_buffer(&g_vk, &g->oval, b->outlier_count ? 12 * (size_t)b->outlier_count : 4,
                    b->outlier_count ? (const void *)b->outlier_values : (const void *)zero);
    ok &= vk_buffer(&g_vk, &g->out, 3 * (size_t)n * 4, NULL);
    return ok;
}

static void gpu_blocks_free(gpu_blocks *g)
{
    uint32_t c;
    for (c = 0; c < 3; ++c) vk_image_free(&g_vk, &g->img[c]);
    vk_buffer_free(&g_vk, &g->scales); vk_buffer_free(&g_vk, &g->E); vk_buffer_free(&g_vk, &g->col); vk_buffer_free(&g_vk, &g->row);
    vk_buffer_free(&g_vk, &g->off); vk_buffer_free(&g_vk, &g->ocol); vk_buffer_free(&g_vk, &g->oval); vk_buffer_free(&g_vk, &g->out);
    vk_kernel_destroy(&g_vk, &g->k);
}

static int gpu_blocks_apply(gpu_blocks *g, const rad_multibounce_blocks *b, const float *E, rad_output output, float *out)
{
    const uint32_t n = b->n;
    uint32_t cut[4], q;
    VkImageView views[3];
    int ok = 1;
    memcpy(g->E.map, E, 3 * (size_t)n * 4);
    memset(g->out.map, 0xFF, 3 * (size_t)n * 4);
    views[0] = g->img[0].view;
    views[1] = b->format == RAD_BLOCK_BC1 ? g->img[0].view : g->img[1].view;
    views[2] = b->format == RAD_BLOCK_BC1 ? g->img[0].view : g->img[2].view;
    chunks(n, cut);
    for (q = 0; q < 3 && ok; ++q) {
        vk_range r[11];
        rad_glsl_mb_blocks_push p;
        if (cut[q + 1] == cut[q]) continue;
        memset(r, 0, sizeof(r));
        r[3] = vk_whole(&g->scales); r[4] = vk_whole(&g->E); r[5] = vk_whole(&g->col); r[6] = vk_whole(&g->row);
        r[7] = vk_whole(&g->off); r[8] = vk_whole(&g->ocol); r[9] = vk_whole(&g->oval); r[10] = vk_whole(&g->out);
        p.n = n;
        p.row_offset = cut[q];
        p.row_count = cut[q + 1] - cut[q];
        p.tile = b->tile;
        p.tiles_per_row = b->tiles_per_row;
        p.flags = (output == RAD_OUTPUT_TOTAL ? RAD_GLSL_OUTPUT_TOTAL : 0u) | (b->row_perm ? RAD_GLSL_MB_PERMUTED : 0u) |
                  (b->format == RAD_BLOCK_BC1 ? RAD_GLSL_BLOCKS_BC1 : 0u) | (b->outlier_count ? RAD_GLSL_BLOCKS_OUTLIERS : 0u);
        ok &= vk_dispatch_images(&g_vk, &g->k, views, r, &p, p.row_count);
    }
    if (ok) memcpy(out, g->out.map, 3 * (size_t)n * 4);
    return ok;
}

/* the tile scale of channel ch at original entry (i, j) */
static float block_scale(const rad_multibounce_blocks *b, const uint32_t *inv_row, const uint32_t *inv_col, uint32_t i, uint32_t j,
                         uint32_t ch)
{
    uint32_t y = inv_row[i], x = inv_col[j];
    size_t t = b->tile ? (size_t)(y / b->tile) * b->tiles_per_row + x / b->tile : 0;
    return b->scales[3 * t + ch];
}

static void test_mb_blocks(void)
{
    const uint32_t n = 61; /* not a multiple of 4: padded blocks */
    float *F = random_matrix(n, 0.6f), *E = random_vector(3 * n, 0.3f), *rho = random_vector(3 * n, 0.0f);
    float *cpu = (float *)malloc(3 * n * sizeof(float)), *gpu = (float *)malloc(3 * n * sizeof(float));
    float *dec = (float *)malloc(3 * (size_t)n * n * sizeof(float)), *unit = (float *)calloc(3 * n, sizeof(float));
    uint32_t *inv_row = (uint32_t *)malloc(n * sizeof(uint32_t)), *inv_col = (uint32_t *)malloc(n * sizeof(uint32_t));
    rad_matrix m;
    rad_multibounce_options o;
    rad_multibounce *mb = NULL;
    int fmt, ls, total;
    size_t i;
    if (!F || !E || !rho || !cpu || !gpu || !dec || !unit || !inv_row || !inv_col) { T_CHECK(0); goto done; }
    if (!g_vk.bc) { printf("    FAIL the device has no textureCompressionBC\n"); T_CHECK(0); goto done; }
    for (i = 0; i < 3 * (size_t)n; ++i) rho[i] *= 0.45f;
    memset(&m, 0, sizeof(m));
    m.rows = m.cols = n;
    m.storage = RAD_STORAGE_DENSE;
    m.dense = F;
    rad_multibounce_options_default(&o);
    T_CHECK(rad_multibounce_create(&m, rho, &o, NULL, &mb) == RAD_SUCCESS);
    if (!mb) goto done;
    for (fmt = 0; fmt < 2; ++fmt) {
        rad_block_options bo;
        rad_multibounce_blocks *b = NULL;
        rad_block_options_default(&bo);
        bo.format = fmt ? RAD_BLOCK_BC4X3 : RAD_BLOCK_BC1;
        bo.tile = 16; /* several tiles */
        T_CHECK(rad_multibounce_blocks_create(mb, &bo, NULL, &b, NULL) == RAD_SUCCESS);
        if (!b) continue;
        T_CHECK(b->outlier_count > 0 && b->row_perm != NULL && b->tiles_per_row > 1);
        for (i = 0; i < n; ++i) {
            inv_row[b->row_perm ? b->row_perm[i] : i] = (uint32_t)i;
            inv_col[b->col_perm ? b->col_perm[i] : i] = (uint32_t)i;
        }
        T_CHECK(rad_multibounce_blocks_decode(b, dec, NULL) == RAD_SUCCESS);
        for (ls = 0; ls < 2; ++ls) {
            gpu_blocks g;
            uint32_t j, ch;
            if (!gpu_blocks_init(&g, b, g_local_sizes[ls])) { T_CHECK(0); gpu_blocks_free(&g); continue; }
            /* the decode itself: E = unit vector j gives column j of the decoded matrix; each
               entry within 2/255 of its tile scale of the CPU decoder (rad_bc1/bc4_decode_block) */
            for (j = 0; j < n; j += 3) {
                double worst = 0.0;
                for (i = 0; i < 3 * (size_t)n; ++i) unit[i] = 0.0f;
                unit[3 * j] = unit[3 * j + 1] = unit[3 * j + 2] = 1.0f;
                T_CHECK(gpu_blocks_apply(&g, b, unit, RAD_OUTPUT_INDIRECT, gpu));
                for (i = 0; i < n; ++i)
                    for (ch = 0; ch < 3; ++ch) {
                        float want = dec[ch * (size_t)n * n + i * n + j], s = block_scale(b, inv_row, inv_col, (uint32_t)i, j, ch);
                        double e = fabs((double)gpu[3 * i + ch] - want) - 1e-6 * fabs(want);
                        if (s > 0 && e / s > worst) worst = e / s;
                    }
                if (!(worst <= 2.0 / 255.0)) {
                    printf("    FAIL %s decode, column %u: %.3f/255 of the tile scale from the CPU decoder\n", fmt ? "BC4x3" : "BC1", j, worst * 255);
                    g_checks_failed++;
                    break;
                }
                g_worst_what = "decode difference from the CPU decoder, in 1/255 of the tile scale";
                if (worst * 255.0 > g_worst) g_worst = worst * 255.0;
            }
            /* the apply: per row, within 2/255 of the scale times sum |E| plus float rounding */
            for (total = 0; total < 2; ++total) {
                rad_output out = total ? RAD_OUTPUT_TOTAL : RAD_OUTPUT_INDIRECT;
                T_CHECK(rad_multibounce_blocks_apply(b, E, cpu, out, NULL) == RAD_SUCCESS);
                T_CHECK(gpu_blocks_apply(&g, b, E, out, gpu));
                for (i = 0; i < n; ++i)
                    for (ch = 0; ch < 3; ++ch) {
                        double bound = 1e-5 * fabs(cpu[3 * i + ch]);
                        for (j = 0; j < n; ++j) bound += 2.0 / 255.0 * block_scale(b, inv_row, inv_col, (uint32_t)i, j, ch) * fabs(E[3 * j + ch]);
                        if (!(fabs((double)gpu[3 * i + ch] - cpu[3 * i + ch]) <= bound)) {
                            printf("    FAIL %s apply row %lu channel %u: gpu %.9g cpu %.9g bound %.3g\n", fmt ? "BC4x3" : "BC1",
                                   (unsigned long)i, ch, (double)gpu[3 * i + ch], (double)cpu[3 * i + ch], bound);
                            g_checks_failed++;
                            i = n;
                            break;
                        }
                    }
            }
            gpu_blocks_free(&g);
        }
        rad_multibounce_blocks_destroy(b);
    }
done:
    rad_multibounce_destroy(mb);
    free(F); free(E); free(rho); free(cpu); free(gpu); free(dec); free(unit); free(inv_row); free(inv_col);
}

/* ---- temporal step: same draws as the CPU, several frames ----------------------------------- */

/* runs 'frames' frames of the temporal state's configuration on the GPU and compares each with
   rad_temporal_step on a twin CPU state */
static void temporal_case(const char *what, const rad_alias_tables *const *tables, uint32_t table_count, const float *rho,
                          const rad_temporal_options *o, const float *E, const float env[3], uint32_t frames, uint32_t local_size)
{
    const uint32_t n = tables[0]->rows;
    rad_temporal *t = NULL;
    vk_kernel k;
    vk_buf bOff[3], bBins[3], bTot[3], bE, bR, bB[2];
    uint32_t f, c, q, cut[4], ones[1] = { 0 };
    float *cpu = (float *)malloc(3 * (size_t)n * sizeof(float));
    int ok = 1;
    char label[96];
    if (!cpu || rad_temporal_create(tables, table_count, rho, o, NULL, &t) != RAD_SUCCESS) { T_CHECK(0); free(cpu); return; }
    if (!vk_kernel_create(&g_vk, &k, RAD_GLSL_TEMPORAL_STEP, 0, 8, (uint32_t)sizeof(rad_glsl_temporal_push), local_size)) {
        T_CHECK(0); rad_temporal_destroy(t); free(cpu); return;
    }
    for (c = 0; c < table_count; ++c) {
        const rad_alias_tables *tb = tables[c];
        ok &= vk_buffer(&g_vk, &bOff[c], ((size_t)n + 1) * 8, tb->row_offsets);
        ok &= vk_buffer(&g_vk, &bBins[c], (size_t)tb->row_offsets[n] * (uint32_t)tb->format * 4, tb->bins);
        ok &= vk_buffer(&g_vk, &bTot[c], (size_t)n * 4, tb->totals);
    }
    ok &= vk_buffer(&g_vk, &bE, 3 * (size_t)n * 4, E);
    ok &= vk_buffer(&g_vk, &bR, rho ? 3 * (size_t)n * 4 : 4, rho ? (const void *)rho : (const void *)ones);
    ok &= vk_buffer(&g_vk, &bB[0], 3 * (size_t)n * 4, NULL);
    ok &= vk_buffer(&g_vk, &bB[1], 3 * (size_t)n * 4, NULL);
    chunks(n, cut);
    for (f = 0; f < frames && ok; ++f) {
        const vk_buf *prev = &bB[f & 1u], *next = &bB[(f + 1u) & 1u];
        T_CHECK(rad_temporal_step(t, E, env, cpu) == RAD_SUCCESS);
        memset(next->map, 0xFF, 3 * (size_t)n * 4);
        for (c = 0; c < table_count; ++c)
            for (q = 0; q < 3; ++q) {
                const rad_alias_tables *tb = tables[c];
                rad_glsl_temporal_push p;
                vk_range r[8];
                uint32_t base = 0, words = (uint32_t)tb->format;
                uint64_t b0 = tb->row_offsets[cut[q]], b1 = tb->row_offsets[cut[q + 1]];
                if (cut[q + 1] == cut[q]) continue;
                r[0] = vk_whole(&bOff[c]);
                r[1] = vk_chunk(&g_vk, &bBins[c], 4, b0 * words, (b1 - b0) * words, &base);
                r[2] = vk_whole(&bTot[c]); r[3] = vk_whole(&bE); r[4] = vk_whole(&bR);
                r[5] = vk_whole(prev); r[6] = vk_whole(next); r[7] = vk_whole(&bTot[c]); /* counts: unused */
                memset(&p, 0, sizeof(p));
                p.seed = o->seed;
                p.frame = f;
                p.row_offset = cut[q];
                p.row_count = cut[q + 1] - cut[q];
                p.n = n;
                p.samples = o->samples;
                p.words = words;
                p.flags = (o->mode != RAD_TEMPORAL_MULTIBOUNCE ? RAD_GLSL_TEMPORAL_ALBEDO : 0u) |
                          (o->mode == RAD_TEMPORAL_FEEDBACK ? RAD_GLSL_TEMPORAL_FEEDBACK : 0u);
                p.channel = table_count == 1 ? 3u : c;
                p.sample_base = table_count == 1 ? 0u : c * o->samples;
                p.word_base = (uint32_t)(b0 * words) - base;
                p.weight = o->weight;
                p.env[0] = env ? env[0] : 0.0f;
                p.env[1] = env ? env[1] : 0.0f;
                p.env[2] = env ? env[2] : 0.0f;
                ok &= vk_dispatch(&g_vk, &k, r, &p, p.row_count);
            }
        snprintf(label, sizeof(label), "%s frame %u (local size %u)", what, f, local_size);
        if (ok && !compare(label, (const float *)next->map, cpu, 3 * (size_t)n, 1e-5)) break;
    }
    T_CHECK(ok);
    for (c = 0; c < table_count; ++c) { vk_buffer_free(&g_vk, &bOff[c]); vk_buffer_free(&g_vk, &bBins[c]); vk_buffer_free(&g_vk, &bTot[c]); }
    vk_buffer_free(&g_vk, &bE); vk_buffer_free(&g_vk, &bR); vk_buffer_free(&g_vk, &bB[0]); vk_buffer_free(&g_vk, &bB[1]);
    vk_kernel_destroy(&g_vk, &k);
    rad_temporal_destroy(t);
    free(cpu);
}

static void test_temporal(void)
{
    const uint32_t n = 120;
    float *F = random_matrix(n, 0.3f), *E = random_vector(3 * n, 0.6f), *rho = random_vector(3 * n, 0.0f);
    float env[3] = { 0.3f, 0.5f, 0.9f };
    rad_matrix m;
    rad_alias_tables *tb = NULL, *tw = NULL, *pl[3] = { NULL, NULL, NULL };
    rad_multibounce *mb = NULL;
    rad_multibounce_options mo;
    rad_temporal_options o;
    size_t i;
    int ls;
    if (!F || !E || !rho) { T_CHECK(0); goto done; }
    for (i = 0; i < 3 * (size_t)n; ++i) rho[i] *= 0.45f;
    memset(&m, 0, sizeof(m));
    m.rows = m.cols = n;
    m.storage = RAD_STORAGE_DENSE;
    m.dense = F;
    T_CHECK(rad_alias_tables_create(&m, RAD_ALIAS_COMPACT, NULL, &tb) == RAD_SUCCESS);
    T_CHECK(rad_alias_tables_create(&m, RAD_ALIAS_WIDE, NULL, &tw) == RAD_SUCCESS);
    rad_multibounce_options_default(&mo);
    T_CHECK(rad_multibounce_create(&m, rho, &mo, NULL, &mb) == RAD_SUCCESS);
    if (mb)
        for (i = 0; i < 3; ++i)
            T_CHECK(rad_alias_tables_create_dense(mb->planes + i * (size_t)n * n, n, RAD_ALIAS_AUTO, NULL, &pl[i]) == RAD_SUCCESS);
    if (!tb || !tw || !pl[0] || !pl[1] || !pl[2]) goto done;
    for (ls = 0; ls < 2; ++ls) {
        const rad_alias_tables *one[1];
        rad_temporal_options_default(&o);
        o.seed = 0xC0FFEEu + (uint32_t)ls;
        o.samples = 13;
        o.weight = 0.9f;
        o.mode = RAD_TEMPORAL_SINGLE;
        one[0] = tb;
        temporal_case("temporal single compact", one, 1, rho, &o, E, env, 4, g_local_sizes[ls]);
        o.mode = RAD_TEMPORAL_FEEDBACK;
        one[0] = tw;
        temporal_case("temporal feedback wide", one, 1, rho, &o, E, env, 6, g_local_sizes[ls]);
        o.mode = RAD_TEMPORAL_MULTIBOUNCE;
        o.samples = 5;
        temporal_case("temporal multibounce 3 tables", (const rad_alias_tables *const *)pl, 3, NULL, &o, E, NULL, 4,
                      g_local_sizes[ls]);
    }
done:
    rad_alias_tables_destroy(tb); rad_alias_tables_destroy(tw);
    for (i = 0; i < 3; ++i) rad_alias_tables_destroy(pl[i]);
    rad_multibounce_destroy(mb);
    free(F); free(E); free(rho);
}

/* ---- alias-table build for streamed rows ----------------------------------------------------- */

static void test_alias_build(void)
{
    const uint32_t n = 97;
    float *F = random_matrix(n, 0.2f);
    csr c;
    rad_matrix m;
    uint64_t *padded_off = NULL;
    uint32_t *cpu_bins = NULL;
    void *scratch = NULL;
    int fmt, dense, ls;
    uint32_t i, j;
    memset(&c, 0, sizeof(c));
    if (!F) { T_CHECK(0); return; }
    if (!g_vk.fp64) { printf("    FAIL the device has no shaderFloat64\n"); T_CHECK(0); free(F); return; }
    g_worst_what = "difference from the CPU (bins: rows that differ; temporal frames: relative)";
    /* rows of every kind: empty (only the environment bin), summing to more than 1 (no
       environment bin), a single entry */
    for (j = 0; j < n; ++j) { F[3 * n + j] = 0.0f; F[5 * n + j] *= 3.0f; }
    for (j = 0; j < n; ++j) F[7 * n + j] = j == 11 ? 0.25f : 0.0f;
    m = make_csr(F, n, &c);
    cpu_bins = (uint32_t *)malloc(3 * ((size_t)n + 1) * sizeof(uint32_t));
    scratch = malloc(rad_alias_row_scratch_size(n));
    padded_off = (uint64_t *)malloc(((size_t)n + 1) * sizeof(uint64_t));
    if (!m.rows || !cpu_bins || !scratch || !padded_off) { T_CHECK(0); goto done; }
    for (dense = 0; dense < 2; ++dense) {
        /* input offsets: CSR, or dense rows (entry k of row i at i * n + k) */
        const uint64_t *in_off;
        for (i = 0; i <= n; ++i) padded_off[i] = (uint64_t)i * n;
        in_off = dense ? padded_off : c.off;
        for (fmt = 0; fmt < 2; ++fmt)
            for (ls = 0; ls < 2; ++ls) {
                const uint32_t words = fmt ? 3u : 2u;
                const uint64_t entries = in_off[n], out_bins = entries + n;
                vk_kernel k;
                vk_buf bOff, bCol, bVal, bBins, bQ, bS, bCnt, bTot;
                uint32_t cut[4], q, zero = 0;
                int ok = 1;
                if (!vk_kernel_create(&g_vk, &k, RAD_GLSL_ALIAS_BUILD, 0, 8, (uint32_t)sizeof(rad_glsl_alias_build_push), g_local_sizes[ls])) {
                    T_CHECK(0); goto done;
                }
                ok &= vk_buffer(&g_vk, &bOff, ((size_t)n + 1) * 8, in_off);
                ok &= vk_buffer(&g_vk, &bCol, dense ? 4 : entries * 4, dense ? (const void *)&zero : (const void *)c.col);
                ok &= vk_buffer(&g_vk, &bVal, entries * 4, dense ? (const void *)F : (const void *)c.val);
                ok &= vk_buffer(&g_vk, &bBins, out_bins * words * 4, NULL);
                ok &= vk_buffer(&g_vk, &bQ, out_bins * 8, NULL);
                ok &= vk_buffer(&g_vk, &bS, out_bins * 4, NULL);
                ok &= vk_buffer(&g_vk, &bCnt, (size_t)n * 4, NULL);
                ok &= vk_buffer(&g_vk, &bTot, (size_t)n * 4, NULL);
                chunks(n, cut);
                for (q = 0; q < 3 && ok; ++q) {
                    rad_glsl_alias_build_push p;
                    vk_range r[8];
                    uint32_t ebase = 0, obase = 0, dummy = 0;
                    uint64_t e0 = in_off[cut[q]], e1 = in_off[cut[q + 1]], o0 = e0 + cut[q], o1 = e1 + cut[q + 1];
                    if (cut[q + 1] == cut[q]) continue;
                    r[0] = vk_whole(&bOff);
                    r[1] = dense ? vk_whole(&bCol) : vk_chunk(&g_vk, &bCol, 4, e0, e1 - e0, &ebase);
                    r[2] = vk_chunk(&g_vk, &bVal, 4, e0, e1 - e0, &ebase);
                    /* the three outputs must start at the same bin: bind them from a bin that
                       all three alignments allow (a multiple of 16 bins is 16-byte aligned
                       for 4-, 8- and 12-byte elements alike when the alignment is <= 64) */
                    r[3] = vk_chunk(&g_vk, &bBins, (VkDeviceSize)words * 4, o0 / 16 * 16, o1 - o0 / 16 * 16, &dummy);
                    r[4] = vk_chunk(&g_vk, &bQ, 8, o0 / 16 * 16, o1 - o0 / 16 * 16, &obase);
                    r[5] = vk_chunk(&g_vk, &bS, 4, o0 / 16 * 16, o1 - o0 / 16 * 16, &dummy);
                    r[6] = vk_whole(&bCnt);
                    r[7] = vk_whole(&bTot);
                    p.row_offset = cut[q];
                    p.row_count = cut[q + 1] - cut[q];
                    p.cols = n;
                    p.words = words;
                    p.entry_base = (uint32_t)e0 - ebase;
                    p.out_base = (uint32_t)(o0 / 16 * 16);
                    p.flags = dense ? RAD_GLSL_ALIAS_DENSE : 0u;
                    if (r[3].offset != (o0 / 16 * 16) * words * 4 || r[4].offset != (o0 / 16 * 16) * 8 || obase != 0) {
                        printf("    alignment %lu too coarse for this test\n", (unsigned long)g_vk.props.limits.minStorageBufferOffsetAlignment);
                        ok = 0;
                        break;
                    }
                    ok &= vk_dispatch(&g_vk, &k, r, &p, p.row_count);
                }
                T_CHECK(ok);
                for (i = 0; i < n && ok; ++i) {
                    uint32_t cnt = 0;
                    float total = 0.0f;
                    const uint32_t *gb = (const uint32_t *)bBins.map + (in_off[i] + i) * words;
                    rad_result res = dense ? rad_alias_build_row(NULL, F + (size_t)i * n, n, n, fmt ? RAD_ALIAS_WIDE : RAD_ALIAS_COMPACT,
                                                                 cpu_bins, &cnt, &total, scratch)
                                           : rad_alias_build_row(c.col + c.off[i], c.val + c.off[i], (uint32_t)(c.off[i + 1] - c.off[i]), n,
                                                                 fmt ? RAD_ALIAS_WIDE : RAD_ALIAS_COMPACT, cpu_bins, &cnt, &total, scratch);
                    T_CHECK(res == RAD_SUCCESS);
                    if (((const uint32_t *)bCnt.map)[i] != cnt || ((const float *)bTot.map)[i] != total ||
                        memcmp(gb, cpu_bins, (size_t)cnt * words * 4) != 0) {
                        printf("    FAIL alias build (%s, %s) row %u: %u bins (cpu %u), T %.9g (cpu %.9g)%s\n", dense ? "dense" : "csr",
                               fmt ? "wide" : "compact", i, ((const uint32_t *)bCnt.map)[i], cnt, (double)((const float *)bTot.map)[i],
                               (double)total, ((const uint32_t *)bCnt.map)[i] == cnt ? ", bins differ" : "");
                        g_checks_failed++;
                        g_worst += 1.0;
                        break;
                    }
                }
                if (ok && !dense) {
                    /* the GPU-built padded tables sampled by the temporal step directly: the
                       same frames as the CPU step on tables built on the CPU */
                    rad_alias_tables *tcpu = NULL;
                    rad_temporal *tstate = NULL;
                    rad_temporal_options o;
                    const rad_alias_tables *one[1];
                    vk_kernel kt;
                    vk_buf bE, bR, bB[2];
                    float *E = random_vector(3 * (size_t)n, 0.5f), *rho = random_vector(3 * (size_t)n, 0.0f), *ref = (float *)malloc(12 * (size_t)n);
                    uint32_t f;
                    rad_temporal_options_default(&o);
                    o.mode = RAD_TEMPORAL_FEEDBACK;
                    o.samples = 9;
                    o.weight = 0.8f;
                    o.seed = 77u;
                    T_CHECK(E && rho && ref && rad_alias_tables_create(&m, fmt ? RAD_ALIAS_WIDE : RAD_ALIAS_COMPACT, NULL, &tcpu) == RAD_SUCCESS);
                    one[0] = tcpu;
                    if (tcpu && rad_temporal_create(one, 1, rho, &o, NULL, &tstate) == RAD_SUCCESS &&
                        vk_kernel_create(&g_vk, &kt, RAD_GLSL_TEMPORAL_STEP, 0, 8, (uint32_t)sizeof(rad_glsl_temporal_push), g_local_sizes[ls])) {
                        ok &= vk_buffer(&g_vk, &bE, 12 * (size_t)n, E);
                        ok &= vk_buffer(&g_vk, &bR, 12 * (size_t)n, rho);
                        ok &= vk_buffer(&g_vk, &bB[0], 12 * (size_t)n, NULL);
                        ok &= vk_buffer(&g_vk, &bB[1], 12 * (size_t)n, NULL);
                        for (f = 0; f < 3 && ok; ++f) {
                            rad_glsl_temporal_push p;
                            vk_range r[8];
                            r[0] = vk_whole(&bOff); r[1] = vk_whole(&bBins); r[2] = vk_whole(&bTot); r[3] = vk_whole(&bE);
                            r[4] = vk_whole(&bR); r[5] = vk_whole(&bB[f & 1u]); r[6] = vk_whole(&bB[(f + 1u) & 1u]); r[7] = vk_whole(&bCnt);
                            memset(&p, 0, sizeof(p));
                            p.seed = o.seed;
                            p.frame = f;
                            p.row_count = n;
                            p.n = n;
                            p.samples = o.samples;
                            p.words = words;
                            p.flags = RAD_GLSL_TEMPORAL_ALBEDO | RAD_GLSL_TEMPORAL_FEEDBACK | RAD_GLSL_TEMPORAL_PADDED;
                            p.channel = 3;
                            p.weight = o.weight;
                            ok &= vk_dispatch(&g_vk, &kt, r, &p, n);
                            T_CHECK(rad_temporal_step(tstate, E, NULL, ref) == RAD_SUCCESS);
                            if (ok) compare("temporal step on GPU-built padded tables", (const float *)bB[(f + 1u) & 1u].map, ref, 3 * (size_t)n, 1e-5);
                        }
                        T_CHECK(ok);
                        vk_buffer_free(&g_vk, &bE); vk_buffer_free(&g_vk, &bR); vk_buffer_free(&g_vk, &bB[0]); vk_buffer_free(&g_vk, &bB[1]);
                        vk_kernel_destroy(&g_vk, &kt);
                    } else {
                        T_CHECK(0);
                    }
                    rad_temporal_destroy(tstate);
                    rad_alias_tables_destroy(tcpu);
                    free(E); free(rho); free(ref);
                }
                vk_buffer_free(&g_vk, &bOff); vk_buffer_free(&g_vk, &bCol); vk_buffer_free(&g_vk, &bVal); vk_buffer_free(&g_vk, &bBins);
                vk_buffer_free(&g_vk, &bQ); vk_buffer_free(&g_vk, &bS); vk_buffer_free(&g_vk, &bCnt); vk_buffer_free(&g_vk, &bTot);
                vk_kernel_destroy(&g_vk, &k);
            }
    }
done:
    free(F); free(c.off); free(c.col); free(c.val); free(cpu_bins); free(scratch); free(padded_off);
}

/* ---- local multi-bounce matrix: adds (rank-1, fused evict rank-2) and apply, T resident ------ */

/* the GPU side of a rad_local: the three planes resident, and the per-add buffers */
typedef struct gpu_local {
    vk_kernel kv, ku, ka;
    vk_buf planes[3], a, b, nz, work;
    uint32_t m;
} gpu_local;

/* the row chunks of plane rows [0, end) for the kernels */
static void local_chunk_ranges(const gpu_local *g, uint32_t r0, uint32_t r1, vk_range *r, uint32_t *base)
{
    uint32_t ch;
    for (ch = 0; ch < 3; ++ch)
        r[ch] = vk_chunk(&g_vk, &g->planes[ch], 4, (VkDeviceSize)r0 * g->m, (VkDeviceSize)(r1 - r0) * g->m, base);
}

/* what an engine streams for adding 'patch': the new row and column over the slots, from the
   fetched row F[patch][.] and the slot map before the add (with the evicted member's slot ev
   already out of it), as rad_local_add builds them; then the kernels on the resident planes */
static int gpu_local_add(gpu_local *g, const float *F, uint32_t n, const float *areas, const float *rho,
                         const uint32_t *slot_before, uint32_t patch, uint32_t k, uint32_t ev, uint32_t end, int first_order,
                         const float *ann_override)
{
    float *a = (float *)g->a.map, *b = (float *)g->b.map;
    uint32_t *nz = (uint32_t *)g->nz.map, nnz = 0, j, ch, cut[4], q, first = 1;
    double an = areas[patch];
    float ann[3] = { 0, 0, 0 };
    int ok = 1;
    memset(a, 0, 3 * (size_t)g->m * 4);
    memset(b, 0, 3 * (size_t)g->m * 4);
    for (j = 0; j < n; ++j) {
        float f = F[(size_t)patch * n + j];
        uint32_t sj = slot_before[j];
        if (f == 0.0f) continue;
        if (j == patch) {
            for (ch = 0; ch < 3; ++ch) ann[ch] = (float)((double)rho[3 * patch + ch] * f);
            continue;
        }
        if (sj == RAD_NONE || sj == ev) continue;
        for (ch = 0; ch < 3; ++ch) {
            a[ch * g->m + sj] = (float)((double)rho[3 * j + ch] * (an * f / (double)areas[j]));
            b[ch * g->m + sj] = (float)((double)rho[3 * patch + ch] * f);
        }
        nz[nnz++] = sj;
    }
    if (ann_override) memcpy(ann, ann_override, sizeof(ann));
    chunks(end, cut);
    for (q = 0; q < 3 && ok; ++q) { /* pass 0, per row chunk */
        rad_glsl_local_vectors_push p;
        vk_range r[7];
        if (cut[q + 1] == cut[q]) continue;
        memset(&p, 0, sizeof(p));
        local_chunk_ranges(g, cut[q], cut[q + 1], r, &p.base);
        r[3] = vk_whole(&g->a); r[4] = vk_whole(&g->b); r[5] = vk_whole(&g->nz); r[6] = vk_whole(&g->work);
        p.m = g->m;
        p.end = end;
        p.row_offset = cut[q];
        p.row_count = cut[q + 1] - cut[q];
        p.nnz = nnz;
        p.ev = ev;
        p.pass = RAD_GLSL_LOCAL_PASS_GATHER;
        p.flags = (first ? RAD_GLSL_LOCAL_FIRST_CHUNK : 0u) | (first_order ? RAD_GLSL_LOCAL_FIRST_ORDER : 0u);
        memcpy(p.ann, ann, sizeof(ann));
        first = 0;
        ok &= vk_dispatch(&g_vk, &g->kv, r, &p, p.row_count > end ? p.row_count : end);
    }
    {
        rad_glsl_local_vectors_push p;
        vk_range r[7];
        memset(&p, 0, sizeof(p));
        local_chunk_ranges(g, 0, end, r, &p.base); /* passes 1 and 2 read no plane; any range */
        r[3] = vk_whole(&g->a); r[4] = vk_whole(&g->b); r[5] = vk_whole(&g->nz); r[6] = vk_whole(&g->work);
        p.m = g->m;
        p.end = end;
        p.nnz = nnz;
        p.ev = ev;
        p.flags = first_order ? RAD_GLSL_LOCAL_FIRST_ORDER : 0u;
        memcpy(p.ann, ann, sizeof(ann));
        if (ev != RAD_NONE) {
            p.pass = RAD_GLSL_LOCAL_PASS_EVICT;
            ok &= vk_dispatch(&g_vk, &g->kv, r, &p, end);
        }
        p.pass = RAD_GLSL_LOCAL_PASS_SCALARS;
        ok &= vk_dispatch(&g_vk, &g->kv, r, &p, 3);
    }
    for (q = 0; q < 3 && ok; ++q) { /* the update, per row chunk */
        rad_glsl_local_update_push p;
        vk_range r[4];
        if (cut[q + 1] == cut[q]) continue;
        local_chunk_ranges(g, cut[q], cut[q + 1], r, &p.base);
        r[3] = vk_whole(&g->work);
        p.m = g->m;
        p.end = end;
        p.row_offset = cut[q];
        p.row_count = cut[q + 1] - cut[q];
        p.k = k;
        p.ev = ev;
        ok &= vk_dispatch(&g_vk, &g->ku, r, &p, p.row_count);
    }
    return ok;
}

static int gpu_local_init(gpu_local *g, uint32_t m, uint32_t local_size)
{
    int ok = 1, ch;
    memset(g, 0, sizeof(*g));
    g->m = m;
    ok &= vk_kernel_create(&g_vk, &g->kv, RAD_GLSL_LOCAL_VECTORS, 0, 7, (uint32_t)sizeof(rad_glsl_local_vectors_push), local_size);
    ok &= vk_kernel_create(&g_vk, &g->ku, RAD_GLSL_LOCAL_UPDATE, 0, 4, (uint32_t)sizeof(rad_glsl_local_update_push), local_size);
    ok &= vk_kernel_create(&g_vk, &g->ka, RAD_GLSL_LOCAL_APPLY, 0, 8, (uint32_t)sizeof(rad_glsl_local_apply_push), local_size);
    for (ch = 0; ch < 3; ++ch) {
        ok &= vk_buffer(&g_vk, &g->planes[ch], (VkDeviceSize)m * m * 4, NULL);
        if (ok) memset(g->planes[ch].map, 0, (size_t)m * m * 4); /* an empty set: T = 0 */
    }
    ok &= vk_buffer(&g_vk, &g->a, 3 * (VkDeviceSize)m * 4, NULL);
    ok &= vk_buffer(&g_vk, &g->b, 3 * (VkDeviceSize)m * 4, NULL);
    ok &= vk_buffer(&g_vk, &g->nz, (VkDeviceSize)m * 4, NULL);
    ok &= vk_buffer(&g_vk, &g->work, RAD_GLSL_LOCAL_WORK_FLOATS(m) * 4, NULL);
    return ok;
}

static void gpu_local_free(gpu_local *g)
{
    int ch;
    for (ch = 0; ch < 3; ++ch) vk_buffer_free(&g_vk, &g->planes[ch]);
    vk_buffer_free(&g_vk, &g->a); vk_buffer_free(&g_vk, &g->b); vk_buffer_free(&g_vk, &g->nz); vk_buffer_free(&g_vk, &g->work);
    vk_kernel_destroy(&g_vk, &g->kv); vk_kernel_destroy(&g_vk, &g->ku); vk_kernel_destroy(&g_vk, &g->ka);
}

/* the resident planes against rad_local.planes */
static int gpu_local_compare(const gpu_local *g, const rad_local *L, const char *what)
{
    size_t mm = (size_t)g->m * g->m;
    float *gpu = (float *)malloc(3 * mm * sizeof(float));
    int ch, r;
    if (!gpu) return 0;
    for (ch = 0; ch < 3; ++ch) memcpy(gpu + ch * mm, g->planes[ch].map, mm * 4);
    r = compare(what, gpu, L->planes, 3 * mm, 1e-5);
    free(gpu);
    return r;
}

/* out = T E over the visible entries, the planes bound in three slot chunks */
static int gpu_local_apply(gpu_local *g, const rad_local *L, const float *E, const uint32_t *visible, uint32_t nvis,
                           const uint32_t *lit, uint32_t nlit, rad_output output, float *out)
{
    const uint32_t n = L->n, end = L->slot_end;
    vk_buf bE, bLit, bSlot, bPatch, bOut;
    uint32_t i, cut[4], q;
    int ok = 1;
    ok &= vk_buffer(&g_vk, &bE, 3 * (VkDeviceSize)n * 4, E);
    ok &= vk_buffer(&g_vk, &bLit, (VkDeviceSize)end * 4 + 4, NULL);
    ok &= vk_buffer(&g_vk, &bSlot, (VkDeviceSize)nvis * 4 + 4, NULL);
    ok &= vk_buffer(&g_vk, &bPatch, (VkDeviceSize)nvis * 4 + 4, visible);
    ok &= vk_buffer(&g_vk, &bOut, 3 * (VkDeviceSize)n * 4, NULL);
    if (ok) {
        uint32_t *lp = (uint32_t *)bLit.map, *vs = (uint32_t *)bSlot.map;
        memset(lp, 0xFF, (size_t)end * 4);
        for (i = 0; i < nlit; ++i) lp[L->patch_slot[lit[i]]] = lit[i];
        for (i = 0; i < nvis; ++i) vs[i] = L->patch_slot[visible[i]];
        memset(bOut.map, 0xFF, 3 * (size_t)n * 4); /* NaN: every visible entry must be written */
    }
    chunks(end, cut);
    for (q = 0; q < 3 && ok; ++q) {
        rad_glsl_local_apply_push p;
        vk_range r[8];
        if (cut[q + 1] == cut[q]) continue;
        local_chunk_ranges(g, cut[q], cut[q + 1], r, &p.base);
        r[3] = vk_whole(&bE); r[4] = vk_whole(&bLit); r[5] = vk_whole(&bSlot); r[6] = vk_whole(&bPatch); r[7] = vk_whole(&bOut);
        p.m = g->m;
        p.end = end;
        p.row_offset = 0;
        p.row_count = nvis; /* every entry, each chunk: the kernel skips rows it does not hold */
        p.slot_offset = cut[q];
        p.slot_count = cut[q + 1] - cut[q];
        p.flags = output == RAD_OUTPUT_TOTAL ? RAD_GLSL_OUTPUT_TOTAL : 0u;
        ok &= vk_dispatch(&g_vk, &g->ka, r, &p, nvis);
    }
    if (ok) memcpy(out, bOut.map, 3 * (size_t)n * 4);
    vk_buffer_free(&g_vk, &bE); vk_buffer_free(&g_vk, &bLit); vk_buffer_free(&g_vk, &bSlot); vk_buffer_free(&g_vk, &bPatch);
    vk_buffer_free(&g_vk, &bOut);
    return ok;
}

/* a world with reciprocity (F_ij A_i = F_ji A_j), rows summing to at most 0.9, some F_ii > 0 */
static void local_world(uint32_t n, float *F, float *areas, float *rho)
{
    uint32_t i, j;
    double mx = 0.0;
    for (i = 0; i < n; ++i) areas[i] = 1.0f + frand();
    for (i = 0; i < 3 * n; ++i) rho[i] = 0.85f * frand();
    for (i = 0; i < n; ++i)
        for (j = i; j < n; ++j) {
            float gij = (i == j ? frand() < 0.2f : frand() < 0.5f) ? frand() : 0.0f; /* G symmetric */
            F[(size_t)i * n + j] = gij / areas[i];
            F[(size_t)j * n + i] = gij / areas[j];
        }
    for (i = 0; i < n; ++i) {
        double s = 0.0;
        for (j = 0; j < n; ++j) s += F[(size_t)i * n + j];
        mx = s > mx ? s : mx;
    }
    for (i = 0; i < n * n; ++i) F[i] = (float)(F[i] * 0.9 / mx);
}

static void local_case(const float *F, uint32_t n, const float *areas, const float *rho, uint32_t m, uint32_t local_size,
                       rad_local_update update, rad_local_eviction evict, uint32_t *evicting_adds)
{
    rad_matrix mat;
    rad_row_source src;
    rad_local_options o;
    rad_local *L = NULL;
    gpu_local g;
    uint32_t *before = (uint32_t *)malloc((size_t)n * 4), *order = (uint32_t *)malloc((size_t)n * 4), i, step = 0;
    uint32_t *vis = (uint32_t *)malloc((size_t)n * 4), *lit = (uint32_t *)malloc((size_t)n * 4), nvis = 0, nlit = 0;
    float *E = random_vector(3 * (size_t)n, 0.3f), *cpu = (float *)calloc(3 * (size_t)n, 4), *gpu = (float *)malloc(3 * (size_t)n * 4);
    int ok = 1, total;
    const char *what = update != RAD_LOCAL_EXACT ? "local T after adds (first order)"
                       : evict == RAD_LOCAL_EVICT_DROP ? "local T after adds (exact, evictions by drop)" : "local T after adds (exact)";
    memset(&mat, 0, sizeof(mat));
    mat.rows = mat.cols = n;
    mat.storage = RAD_STORAGE_DENSE;
    mat.dense = F;
    if (!before || !order || !vis || !lit || !E || !cpu || !gpu || !gpu_local_init(&g, m, local_size)) { T_CHECK(0); goto done; }
    rad_local_options_default(&o);
    o.capacity = m;
    o.update = update;
    o.evict = evict;
    T_CHECK(rad_row_source_matrix(&mat, areas, rho, &src) == RAD_SUCCESS);
    T_CHECK(rad_local_create(&src, &o, NULL, &L) == RAD_SUCCESS);
    if (!L) goto done;
    for (i = 0; i < n; ++i) order[i] = (i * 37u + 11u) % n; /* n prime to 37: a permutation */
    /* fill the set, hide 10 members, show one again, fill the free slots, then evict into adds */
    for (i = 0; ok && i < m + 6; ++i) { /* m - 8 adds, 8 into the free slots, 6 evicting */
        uint32_t patch = order[i], k, ev, end, had = L->slot_end;
        int full;
        if (i == m - 8) { /* hide 10 members (the 1st, 4th, ...), then show the 4th again */
            uint32_t h;
            for (h = 0; h < 10; ++h) T_CHECK(rad_local_remove(L, order[3 * h], NULL) == RAD_SUCCESS);
            T_CHECK(rad_local_add(L, order[3], NULL) == RAD_SUCCESS); /* only shown: T unchanged */
        }
        memcpy(before, L->patch_slot, (size_t)n * 4);
        full = L->count + L->hidden >= L->capacity;
        {
            rad_result r = rad_local_add(L, patch, NULL);
            if (r != RAD_SUCCESS) { printf("    FAIL rad_local_add(%u): %s\n", patch, rad_result_string(r)); g_checks_failed++; break; }
        }
        k = L->patch_slot[patch];
        /* the member evicted from slot k is out of the slot map; with RAD_LOCAL_EVICT_DROP the add is a
           plain one into slot k (its old row and column are overwritten, as the drop zeroed them) */
        ev = full && evict == RAD_LOCAL_EVICT_DOWNDATE ? k : RAD_NONE;
        if (full) {
            uint32_t p;
            for (p = 0; p < n; ++p)
                if (before[p] == k) before[p] = RAD_NONE;
            ++*evicting_adds;
        }
        end = k + 1 > had ? k + 1 : had;
        ok &= gpu_local_add(&g, F, n, areas, rho, before, patch, k, ev, end, update == RAD_LOCAL_FIRST_ORDER, NULL);
        if (++step % 8 == 0 || full) ok &= gpu_local_compare(&g, L, what);
    }
    T_CHECK(ok && L->evictions > 0 && L->hidden > 0);
    ok &= gpu_local_compare(&g, L, what);
    /* apply: every visible member receives, every member (hidden ones too) with E != 0 lights */
    for (i = 0; i < n; ++i) {
        uint32_t p = order[i], s = L->patch_slot[p];
        if (s == RAD_NONE) continue;
        if (!L->slot_hidden[s]) vis[nvis++] = p;
        if (i % 3 != 1 || L->slot_hidden[s]) lit[nlit++] = p;
    }
    for (total = 0; ok && total < 2; ++total) {
        rad_output out = total ? RAD_OUTPUT_TOTAL : RAD_OUTPUT_INDIRECT;
        float *gv = (float *)malloc(3 * (size_t)nvis * 4), *cv = (float *)malloc(3 * (size_t)nvis * 4);
        T_CHECK(rad_local_apply(L, E, vis, nvis, lit, nlit, cpu, out, NULL) == RAD_SUCCESS);
        T_CHECK(gpu_local_apply(&g, L, E, vis, nvis, lit, nlit, out, gpu));
        if (gv && cv) {
            for (i = 0; i < 3 * nvis; ++i) { gv[i] = gpu[3 * vis[i / 3] + i % 3]; cv[i] = cpu[3 * vis[i / 3] + i % 3]; }
            compare(total ? "local apply total" : "local apply", gv, cv, 3 * (size_t)nvis, 1e-5);
        } else T_CHECK(0);
        free(gv); free(cv);
    }
    /* rows that break energy conservation (s <= 0): the update leaves T as it was */
    if (ok && update == RAD_LOCAL_EXACT) {
        const float bad[3] = { 1.5f, 0.0f, 0.0f };
        uint32_t k = 0; /* an evicting add (the set is full): slot k of a hidden member */
        while (k < m && !(L->slot_patch[k] != RAD_NONE && L->slot_hidden[k])) ++k;
        for (i = 0; i < n && L->patch_slot[order[i]] != RAD_NONE; ++i) {}
        if (k < m && i < n) {
            memcpy(before, L->patch_slot, (size_t)n * 4);
            T_CHECK(gpu_local_add(&g, F, n, areas, rho, before, order[i], k, k, L->slot_end, 0, bad));
            T_CHECK(((const float *)g.work.map)[12 * m] < 0.0f);
            gpu_local_compare(&g, L, "local T unchanged after a singular add");
        } else T_CHECK(0);
    }
done:
    rad_local_destroy(L);
    gpu_local_free(&g);
    free(before); free(order); free(vis); free(lit); free(E); free(cpu); free(gpu);
}

static void test_local(void)
{
    const uint32_t n = 151, m = 48;
    float *F = (float *)malloc((size_t)n * n * 4), *areas = (float *)malloc(n * 4), *rho = (float *)malloc(3 * n * 4);
    uint32_t evicting = 0;
    if (!F || !areas || !rho) { T_CHECK(0); free(F); free(areas); free(rho); return; }
    local_world(n, F, areas, rho);
    local_case(F, n, areas, rho, m, g_local_sizes[0], RAD_LOCAL_EXACT, RAD_LOCAL_EVICT_DOWNDATE, &evicting);
    local_case(F, n, areas, rho, m, g_local_sizes[1], RAD_LOCAL_EXACT, RAD_LOCAL_EVICT_DOWNDATE, &evicting);
    local_case(F, n, areas, rho, m, g_local_sizes[0], RAD_LOCAL_FIRST_ORDER, RAD_LOCAL_EVICT_DOWNDATE, &evicting);
    local_case(F, n, areas, rho, m, g_local_sizes[1], RAD_LOCAL_EXACT, RAD_LOCAL_EVICT_DROP, &evicting);
    printf("    M = %u of n = %u, %u adds into a full set (rank 2 with the downdate, plain after a drop)\n", m, n, evicting);
    T_CHECK(evicting >= 3);
    free(F); free(areas); free(rho);
}


/* ---- virtual-patch gathering: normal weights, trilinear filter skipping empty voxels ---------- */

/* RAD_GLSL_VP_GATHER at 'npts' points (in three chunks) against rad_vp_gather */
static void vp_run(const rad_virtual_patches *vp, const float *values, const float *pts, const float *nrm, uint32_t npts,
                   uint32_t local_size, const char *what)
{
    const uint32_t count = vp->count;
    const rad_vp_kind kind = vp->kind;
    const rad_vp_weights weights = vp->weights;
    float *cpu = (float *)malloc(3 * (size_t)npts * 4);
    vk_kernel k;
    vk_buf bP, bN, bX, bK, bV, bPN, bO;
    uint32_t cut[4], q;
    int ok = 1;
    if (!cpu) { T_CHECK(0); return; }
    T_CHECK(rad_vp_gather(vp, values, pts, nrm, npts, cpu, NULL) == RAD_SUCCESS);
    if (!vk_kernel_create(&g_vk, &k, RAD_GLSL_VP_GATHER, 0, 7, (uint32_t)sizeof(rad_glsl_vp_gather_push), local_size)) {
        T_CHECK(0);
        free(cpu);
        return;
    }
    ok &= vk_buffer(&g_vk, &bP, 3 * (VkDeviceSize)npts * 4, pts);
    ok &= vk_buffer(&g_vk, &bN, 3 * (VkDeviceSize)npts * 4, nrm);
    ok &= vk_buffer(&g_vk, &bX, 3 * (VkDeviceSize)count * 4, values);
    ok &= vk_buffer(&g_vk, &bK, (VkDeviceSize)vp->voxel_count * 8, vp->voxel_keys);
    ok &= vk_buffer(&g_vk, &bV, 6 * (VkDeviceSize)vp->voxel_count * 4, vp->voxel_patch);
    {
        /* binding 5: the clustered weight's normals times the patch areas */
        float *an = vp->normals && vp->areas ? (float *)malloc(sizeof(float) * 3 * (size_t)count) : NULL;
        uint32_t e;
        for (e = 0; an && e < 3 * count; ++e) an[e] = vp->normals[e] * vp->areas[e / 3];
        /* axis-aligned sets have no normals: the binding is unread, uploaded as before */
        ok &= (an != NULL || !vp->normals || !vp->areas) && vk_buffer(&g_vk, &bPN, 3 * (VkDeviceSize)count * 4, an ? an : vp->normals);
        free(an);
    }
    ok &= vk_buffer(&g_vk, &bO, 3 * (VkDeviceSize)npts * 4, NULL);
    if (ok) memset(bO.map, 0xFF, 3 * (size_t)npts * 4); /* NaN: every point must be written */
    chunks(npts, cut);
    for (q = 0; q < 3 && ok; ++q) {
        rad_glsl_vp_gather_push p;
        vk_range r[7];
        uint32_t b1, b2;
        if (cut[q + 1] == cut[q]) continue;
        r[0] = vk_chunk(&g_vk, &bP, 4, 3 * (VkDeviceSize)cut[q], 3 * (VkDeviceSize)(cut[q + 1] - cut[q]), &p.base);
        r[1] = vk_chunk(&g_vk, &bN, 4, 3 * (VkDeviceSize)cut[q], 3 * (VkDeviceSize)(cut[q + 1] - cut[q]), &b1);
        r[6] = vk_chunk(&g_vk, &bO, 4, 3 * (VkDeviceSize)cut[q], 3 * (VkDeviceSize)(cut[q + 1] - cut[q]), &b2);
        T_CHECK(b1 == p.base && b2 == p.base);
        r[2] = vk_whole(&bX); r[3] = vk_whole(&bK); r[4] = vk_whole(&bV); r[5] = vk_whole(&bPN);
        memcpy(p.origin, vp->origin, sizeof(p.origin));
        memcpy(p.voxel_size, vp->voxel_size, sizeof(p.voxel_size));
        memcpy(p.dims, vp->dims, sizeof(p.dims));
        p.voxel_count = vp->voxel_count;
        p.row_offset = cut[q];
        p.row_count = cut[q + 1] - cut[q];
        p.flags = (weights == RAD_VP_WEIGHTS_COSINE ? RAD_GLSL_VP_COSINE : 0u) | (kind == RAD_VP_CLUSTERED ? RAD_GLSL_VP_CLUSTERED : 0u);
        ok &= vk_dispatch(&g_vk, &k, r, &p, p.row_count);
    }
    T_CHECK(ok);
    if (ok) compare(what, (const float *)bO.map, cpu, 3 * (size_t)npts, 1e-5);
    vk_buffer_free(&g_vk, &bP); vk_buffer_free(&g_vk, &bN); vk_buffer_free(&g_vk, &bX); vk_buffer_free(&g_vk, &bK);
    vk_buffer_free(&g_vk, &bV); vk_buffer_free(&g_vk, &bPN); vk_buffer_free(&g_vk, &bO);
    vk_kernel_destroy(&g_vk, &k);
    free(cpu);
}

/* a grid of 5 x 4 x 6 voxels, about 60% of them present, each axis patch present with
   probability 0.7 (clustered: random unit normals): the gather's skipping is exercised at
   every level (missing voxel, voxel without a patch facing n, outside the grid) */
static void vp_case(rad_vp_kind kind, rad_vp_weights weights, uint32_t local_size, uint32_t *used_hist)
{
    const uint32_t dims[3] = { 5, 4, 6 }, cells = 5 * 4 * 6, npts = 2000;
    rad_virtual_patches vp;
    uint64_t keys[5 * 4 * 6];
    uint32_t vpatch[6 * 5 * 4 * 6], c, a, count = 0, i;
    float normals[3 * 6 * 5 * 4 * 6], areas[6 * 5 * 4 * 6], *values = NULL, *pts = (float *)malloc(3 * (size_t)npts * 4);
    float *nrm = (float *)malloc(3 * (size_t)npts * 4);
    memset(&vp, 0, sizeof(vp));
    vp.origin[0] = -1.0f; vp.origin[1] = 0.5f; vp.origin[2] = 2.0f;
    vp.voxel_size[0] = 0.7f; vp.voxel_size[1] = 0.9f; vp.voxel_size[2] = 0.6f;
    memcpy(vp.dims, dims, sizeof(dims));
    for (c = 0; c < cells; ++c) {
        if (frand() < 0.4f) continue;
        keys[vp.voxel_count] = c;
        for (a = 0; a < 6; ++a) {
            uint32_t *slot = &vpatch[6 * vp.voxel_count + a];
            *slot = RAD_NONE;
            if (frand() < 0.3f) continue;
            *slot = count;
            areas[count] = 0.2f + frand(); /* the clustered gather weighs by area */
            if (kind == RAD_VP_CLUSTERED) {
                float x = frand() - 0.5f, y = frand() - 0.5f, z = frand() - 0.5f, l = sqrtf(x * x + y * y + z * z) + 1e-6f;
                normals[3 * count] = x / l; normals[3 * count + 1] = y / l; normals[3 * count + 2] = z / l;
            } else {
                normals[3 * count] = normals[3 * count + 1] = normals[3 * count + 2] = 0.0f;
                normals[3 * count + a / 2] = a % 2 ? -1.0f : 1.0f;
            }
            ++count;
        }
        vp.voxel_count++;
    }
    vp.count = count;
    vp.voxel_keys = keys;
    vp.voxel_patch = vpatch;
    vp.normals = normals;
    vp.areas = areas;
    vp.kind = kind;
    vp.weights = weights;
    values = random_vector(3 * (size_t)count, 0.1f);
    if (!values || !pts || !nrm) { T_CHECK(0); goto done; }
    for (i = 0; i < npts; ++i) {
        float x = frand() - 0.5f, y = frand() - 0.5f, z = frand() - 0.5f, l;
        uint32_t d;
        if (i % 7 == 0) { /* an axis normal: four split weights are zero */
            float s = i % 2 ? 1.0f : -1.0f;
            x = (i / 7) % 3 == 0 ? s : 0.0f;
            y = (i / 7) % 3 == 1 ? s : 0.0f;
            z = (i / 7) % 3 == 2 ? s : 0.0f;
        }
        l = sqrtf(x * x + y * y + z * z) + 1e-6f;
        nrm[3 * i] = x / l; nrm[3 * i + 1] = y / l; nrm[3 * i + 2] = z / l;
        for (d = 0; d < 3; ++d) /* from one voxel outside the grid to one beyond it; some far away */
            pts[3 * i + d] = vp.origin[d] + vp.voxel_size[d] * ((float)(dims[d] + 2) * frand() - 1.0f) * (i % 97 == 5 ? 9.0f : 1.0f);
    }
    for (i = 0; i < npts; ++i) {
        float o[3];
        uint32_t used = rad_vp_gather_point(&vp, values, pts + 3 * i, nrm + 3 * i, o);
        used_hist[used > 8 ? 8 : used]++;
    }
    vp_run(&vp, values, pts, nrm, npts, local_size, kind == RAD_VP_CLUSTERED ? "vp gather (clustered)"
           : weights == RAD_VP_WEIGHTS_COSINE ? "vp gather (cosine)" : "vp gather");
done:
    free(values); free(pts); free(nrm);
}


/* a built set: three walls of a 4 x 2 x 3 room corner (floor, x = 0, z = 0) as 4 x 4 triangle
   grids, rad_vp_create with 'kind'; points on the walls (with their normals) and inside the
   room (random normals) */
static void vp_built(rad_vp_kind kind, uint32_t local_size)
{
    static const float o[3][3] = { { 0, 0, 0 }, { 0, 0, 0 }, { 0, 0, 0 } };
    static const float U[3][3] = { { 0, 0, 3 }, { 0, 2, 0 }, { 4, 0, 0 } }, V[3][3] = { { 4, 0, 0 }, { 0, 0, 3 }, { 0, 2, 0 } };
    static const float nrm_of[3][3] = { { 0, 1, 0 }, { 1, 0, 0 }, { 0, 0, 1 } };
    float pos[3][3 * 25];
    uint32_t idx[3][6 * 16], q, i, j, d;
    rad_mesh_desc meshes[3];
    rad_material mat;
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_vp_options vo;
    rad_virtual_patches *vp = NULL;
    const uint32_t npts = 1000;
    float *pts = (float *)malloc(3 * (size_t)npts * 4), *nrm = (float *)malloc(3 * (size_t)npts * 4), *values = NULL;
    for (q = 0; q < 3; ++q) {
        for (j = 0; j <= 4; ++j)
            for (i = 0; i <= 4; ++i)
                for (d = 0; d < 3; ++d) pos[q][3 * (j * 5 + i) + d] = o[q][d] + U[q][d] * (float)i / 4.0f + V[q][d] * (float)j / 4.0f;
        for (j = 0; j < 4; ++j)
            for (i = 0; i < 4; ++i) {
                uint32_t a = j * 5 + i, *tri = &idx[q][6 * (j * 4 + i)];
                tri[0] = a; tri[1] = a + 1; tri[2] = a + 6;
                tri[3] = a; tri[4] = a + 6; tri[5] = a + 5;
            }
        memset(&meshes[q], 0, sizeof(meshes[q]));
        meshes[q].positions = pos[q];
        meshes[q].vertex_count = 25;
        meshes[q].indices = idx[q];
        meshes[q].triangle_count = 32;
    }
    memset(&mat, 0, sizeof(mat));
    mat.albedo[0] = mat.albedo[1] = mat.albedo[2] = 0.5f;
    memset(&desc, 0, sizeof(desc));
    desc.meshes = meshes;
    desc.mesh_count = 3;
    desc.materials = &mat;
    desc.material_count = 1;
    if (!pts || !nrm) { T_CHECK(0); goto done; }
    T_CHECK(rad_scene_create(&desc, NULL, &scene) == RAD_SUCCESS);
    if (scene) T_CHECK(rad_bvh_create(scene, NULL, &bvh) == RAD_SUCCESS);
    if (!bvh) goto done;
    rad_bvh_raycaster(bvh, &rc);
    rad_vp_options_default(&vo);
    vo.resolution = 9;
    vo.face_points = 4;
    vo.skip_visibility = 1;
    vo.kind = kind;
    T_CHECK(rad_vp_create(scene, &rc, &vo, NULL, &vp) == RAD_SUCCESS);
    if (!vp) goto done;
    values = random_vector(3 * (size_t)vp->count, 0.0f);
    if (!values) { T_CHECK(0); goto done; }
    for (i = 0; i < npts; ++i) {
        float x = frand() - 0.5f, y = frand() - 0.5f, z = frand() - 0.5f, l = sqrtf(x * x + y * y + z * z) + 1e-6f;
        if (i % 2 == 0) { /* on a wall */
            q = (i / 2) % 3;
            for (d = 0; d < 3; ++d) {
                pts[3 * i + d] = U[q][d] * frand() + V[q][d] * frand();
                nrm[3 * i + d] = nrm_of[q][d];
            }
        } else {
            pts[3 * i] = 4.0f * frand(); pts[3 * i + 1] = 2.0f * frand(); pts[3 * i + 2] = 3.0f * frand();
            nrm[3 * i] = x / l; nrm[3 * i + 1] = y / l; nrm[3 * i + 2] = z / l;
        }
    }
    vp_run(vp, values, pts, nrm, npts, local_size, kind == RAD_VP_CLUSTERED ? "vp gather, built (clustered)" : "vp gather, built");
    printf("    built: %u patches in %u voxels (%u x %u x %u grid)\n", vp->count, vp->voxel_count, vp->dims[0], vp->dims[1], vp->dims[2]);
done:
    rad_vp_destroy(vp);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(scene);
    free(pts); free(nrm); free(values);
}

static void test_vp_gather(void)
{
    uint32_t hist[9], i;
    g_rng = 12345u; /* the same grids whichever tests ran before */
    memset(hist, 0, sizeof(hist));
    vp_case(RAD_VP_AXIS_ALIGNED, RAD_VP_WEIGHTS_SQUARED, g_local_sizes[0], hist);
    vp_case(RAD_VP_AXIS_ALIGNED, RAD_VP_WEIGHTS_COSINE, g_local_sizes[1], hist);
    vp_case(RAD_VP_CLUSTERED, RAD_VP_WEIGHTS_SQUARED, g_local_sizes[0], hist);
    vp_built(RAD_VP_AXIS_ALIGNED, g_local_sizes[1]);
    vp_built(RAD_VP_CLUSTERED, g_local_sizes[0]);
    printf("    points by voxels used (0..8):");
    for (i = 0; i < 9; ++i) printf(" %u", hist[i]);
    printf("\n");
    T_CHECK(hist[0] > 0 && hist[7] + hist[8] > 0 && hist[2] + hist[3] + hist[4] > 0); /* skipping happened, and near-full blocks */
}

/* ---- irradiance probes: the update from a new patch solution --------------------------------- */

/* RAD_GLSL_PROBE_UPDATE against rad_probes_update: Cornell-box probes (grid, direct light on,
   band 4 stored), a random solution B, the probes in three chunks whose entry ranges are bound
   at offsets; the L2 block with two local sizes, then the band-4 block from its weights */
static void test_probe_update(void)
{
    rad_scene_desc d;
    rad_scene *S = NULL;
    rad_patches *P = NULL;
    rad_patch_options po;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_probe_options o;
    rad_probes *pr = NULL;
    float *B = NULL;
    const uint64_t *first;
    const uint32_t *patch;
    const float *weights, *direct, *weights4, *direct4;
    uint32_t n, i, q, cut[4], s;
    size_t entries;
    g_worst_what = "relative error of the coefficients";
    rad_cornell_box(&d, NULL);
    rad_patch_options_default(&po);
    po.target_count = 150;
    if (rad_scene_create(&d, NULL, &S) != RAD_SUCCESS || rad_patches_create(S, &po, NULL, &P) != RAD_SUCCESS ||
        rad_bvh_create(S, NULL, &bvh) != RAD_SUCCESS) { T_CHECK(0); goto done; }
    rad_bvh_raycaster(bvh, &rc);
    rad_probe_options_default(&o);
    o.spacing = 0.12f;
    o.rays = 64;
    o.flags = RAD_PROBES_DIRECT | RAD_PROBES_BAND4;
    if (rad_probes_create(P, &rc, NULL, 0, NULL, 0, &o, NULL, NULL, &pr) != RAD_SUCCESS) { T_CHECK(0); goto done; }
    B = (float *)malloc(3 * (size_t)P->count * 4);
    if (!B) { T_CHECK(0); goto done; }
    for (i = 0; i < 3 * P->count; ++i) B[i] = 2.0f * frand();
    T_CHECK(rad_probes_update(pr, B, NULL) == RAD_SUCCESS);
    n = rad_probes_count(pr);
    entries = rad_probes_entry_count(pr);
    rad_probes_weights(pr, &first, &patch, &weights, &direct);
    rad_probes_weights_band4(pr, &weights4, &direct4);
    if (!weights4 || !direct4) { T_CHECK(0); goto done; }
    printf("    %u probes, %lu entries\n", n, (unsigned long)entries);
    chunks(n, cut);
    for (s = 0; s < 3; ++s) {
        vk_kernel k;
        vk_buf bF, bP, bW, bD, bB, bO;
        int ok = 1;
        if (!vk_kernel_create(&g_vk, &k, RAD_GLSL_PROBE_UPDATE, 0, 6, (uint32_t)sizeof(rad_glsl_probe_update_push), g_local_sizes[s & 1])) {
            T_CHECK(0);
            break;
        }
        ok &= vk_buffer(&g_vk, &bF, ((VkDeviceSize)n + 1) * 8, first);
        ok &= vk_buffer(&g_vk, &bP, (VkDeviceSize)entries * 4, patch);
        ok &= vk_buffer(&g_vk, &bW, 9 * (VkDeviceSize)entries * 4, s == 2 ? weights4 : weights);
        ok &= vk_buffer(&g_vk, &bD, 27 * (VkDeviceSize)n * 4, s == 2 ? direct4 : direct);
        ok &= vk_buffer(&g_vk, &bB, 3 * (VkDeviceSize)P->count * 4, B);
        ok &= vk_buffer(&g_vk, &bO, 27 * (VkDeviceSize)n * 4, NULL);
        if (ok) memset(bO.map, 0xFF, 27 * (size_t)n * 4); /* NaN: every probe must be written */
        for (q = 0; q < 3 && ok; ++q) {
            rad_glsl_probe_update_push p;
            vk_range r[6];
            uint32_t wb;
            VkDeviceSize k0 = first[cut[q]], k1 = first[cut[q + 1]];
            if (cut[q + 1] == cut[q]) continue;
            r[0] = vk_whole(&bF);
            r[1] = vk_chunk(&g_vk, &bP, 4, k0, k1 - k0, &p.entry_base);
            r[2] = vk_chunk(&g_vk, &bW, 4, 9 * k0, 9 * (k1 - k0), &wb);
            r[3] = vk_whole(&bD); r[4] = vk_whole(&bB); r[5] = vk_whole(&bO);
            p.entry_base = (uint32_t)k0 - p.entry_base;
            p.weight_base = (uint32_t)(9 * k0) - wb;
            p.row_offset = cut[q];
            p.row_count = cut[q + 1] - cut[q];
            ok &= vk_dispatch(&g_vk, &k, r, &p, p.row_count);
        }
        T_CHECK(ok);
        /* band 4 sums signed terms that mostly cancel: the GPU's float sum loses more relative to the result */
        if (ok)
            compare(s == 2 ? "probe update, band 4" : "probe update", (const float *)bO.map,
                    s == 2 ? rad_probes_band4(pr) : rad_probes_coefficients(pr), 27 * (size_t)n, s == 2 ? 5e-5 : 1e-5);
        vk_buffer_free(&g_vk, &bF); vk_buffer_free(&g_vk, &bP); vk_buffer_free(&g_vk, &bW);
        vk_buffer_free(&g_vk, &bD); vk_buffer_free(&g_vk, &bB); vk_buffer_free(&g_vk, &bO);
        vk_kernel_destroy(&g_vk, &k);
    }
done:
    free(B);
    rad_probes_destroy(pr);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(P);
    rad_scene_destroy(S);
}

/* ---- lightmaps: the refresh from a new patch irradiance ---------------------------------------- */

/* RAD_GLSL_LIGHTMAP_REFRESH against rad_lightmap_refresh: the Cornell box with one atlas cell per
   quad (as tests/bench/lightmap.c), weights with detail factors from a first refresh, a random patch
   irradiance; both passes in three chunks whose entry ranges are bound at offsets */
static void test_lightmap_refresh(void)
{
    static rad_mesh_desc meshes[16];
    static float luv[16][2 * 20];
    rad_scene_desc d;
    rad_scene *S = NULL;
    rad_patches *P = NULL;
    rad_patch_options po;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_lightmap_options lo;
    rad_lightmap *lm = NULL;
    rad_lightmap_weights *w0 = NULL, *w = NULL, *wv = NULL;
    rad_virtual_patches *vp = NULL;
    rad_vp_options vo;
    float *H = NULL, *base = NULL, *cpu = NULL, *Hv = NULL, *cpuv = NULL;
    uint32_t i, m, q, cell = 0, cut[4], s, texels;
    const uint32_t size = 64, cells = 6;
    g_worst_what = "relative error of the texels";
    rad_cornell_box(&d, NULL);
    memcpy(meshes, d.meshes, sizeof(rad_mesh_desc) * d.mesh_count);
    for (m = 0; m < d.mesh_count; ++m) {
        for (q = 0; q < meshes[m].vertex_count / 4; ++q, ++cell) {
            static const float cu[4] = { 0, 1, 1, 0 }, cv[4] = { 0, 0, 1, 1 };
            float x0 = (float)(cell % cells) / cells, y0 = (float)(cell / cells) / cells, g = 1.0f / size, e = 1.0f / cells - 2.0f * g;
            for (i = 0; i < 4; ++i) { luv[m][8 * q + 2 * i] = x0 + g + e * cu[i]; luv[m][8 * q + 2 * i + 1] = y0 + g + e * cv[i]; }
        }
        meshes[m].lightmap_uvs = luv[m];
    }
    d.meshes = meshes;
    rad_patch_options_default(&po);
    po.target_count = 150;
    if (rad_scene_create(&d, NULL, &S) != RAD_SUCCESS || rad_patches_create(S, &po, NULL, &P) != RAD_SUCCESS ||
        rad_bvh_create(S, NULL, &bvh) != RAD_SUCCESS) { T_CHECK(0); goto done; }
    rad_bvh_raycaster(bvh, &rc);
    rad_lightmap_options_default(&lo);
    lo.width = lo.height = size;
    lo.validity_rays = 4;
    if (rad_lightmap_create(S, &rc, &lo, NULL, &lm) != RAD_SUCCESS) { T_CHECK(0); goto done; }
    texels = size * size;
    H = (float *)malloc(3 * (size_t)P->count * 4);
    base = (float *)calloc(3 * (size_t)texels, 4);
    cpu = (float *)calloc(3 * (size_t)texels, 4);
    if (!H || !base || !cpu) { T_CHECK(0); goto done; }
    /* detail factors that differ from 1: a "bake" from a first irradiance, then a second one */
    for (i = 0; i < 3 * P->count; ++i) H[i] = 0.2f + frand();
    if (rad_lightmap_weights_create(lm, P, NULL, NULL, NULL, &w0) != RAD_SUCCESS ||
        rad_lightmap_refresh(w0, H, base, NULL) != RAD_SUCCESS) { T_CHECK(0); goto done; }
    for (i = 0; i < 3 * texels; ++i) base[i] *= 0.5f + frand();
    if (rad_lightmap_weights_create(lm, P, base, H, NULL, &w) != RAD_SUCCESS) { T_CHECK(0); goto done; }
    for (i = 0; i < 3 * P->count; ++i) H[i] = 2.0f * frand();
    for (i = 0; i < 3 * texels; ++i) cpu[i] = -1.0f; /* texels without a row keep this */
    T_CHECK(rad_lightmap_refresh(w, H, cpu, NULL) == RAD_SUCCESS);
    printf("    %u vertices (%u entries), %u rows (%u entries)\n", w->vertex_count, w->vertex_first[w->vertex_count], w->row_count,
           w->row_first[w->row_count]);
    /* the weights of the virtual-patch gather (stage 1 the identity) run through the same kernel */
    rad_vp_options_default(&vo);
    vo.resolution = 4;
    if (rad_vp_create(S, &rc, &vo, NULL, &vp) != RAD_SUCCESS || rad_lightmap_weights_create_vp(lm, vp, NULL, &wv) != RAD_SUCCESS) {
        T_CHECK(0);
        goto done;
    }
    Hv = (float *)malloc(3 * (size_t)vp->count * 4);
    cpuv = (float *)malloc(3 * (size_t)texels * 4);
    if (!Hv || !cpuv) { T_CHECK(0); goto done; }
    for (i = 0; i < 3 * vp->count; ++i) Hv[i] = 2.0f * frand();
    for (i = 0; i < 3 * texels; ++i) cpuv[i] = -1.0f;
    T_CHECK(rad_lightmap_refresh(wv, Hv, cpuv, NULL) == RAD_SUCCESS);
    for (s = 0; s < 4; ++s) {
        /* s 0, 1: the classic weights at the two workgroup sizes; 2, 3: the virtual patches' */
        const rad_lightmap_weights *W = s < 2 ? w : wv;
        const float *HH = s < 2 ? H : Hv, *ref = s < 2 ? cpu : cpuv;
        uint32_t np = s < 2 ? P->count : vp->count;
        vk_kernel k;
        vk_buf bVF, bVP, bVW, bH, bV, bRT, bRF, bEV, bEW, bO;
        int ok = 1, pass;
        if (!vk_kernel_create(&g_vk, &k, RAD_GLSL_LIGHTMAP_REFRESH, 0, 10, (uint32_t)sizeof(rad_glsl_lightmap_refresh_push), g_local_sizes[s % 2])) {
            T_CHECK(0);
            break;
        }
        ok &= vk_buffer(&g_vk, &bVF, ((VkDeviceSize)W->vertex_count + 1) * 4, W->vertex_first);
        ok &= vk_buffer(&g_vk, &bVP, (VkDeviceSize)W->vertex_first[W->vertex_count] * 4 + 4, W->vertex_patches);
        ok &= vk_buffer(&g_vk, &bVW, (VkDeviceSize)W->vertex_first[W->vertex_count] * 4 + 4, W->vertex_weights);
        ok &= vk_buffer(&g_vk, &bH, 3 * (VkDeviceSize)np * 4, HH);
        ok &= vk_buffer(&g_vk, &bV, 3 * (VkDeviceSize)W->vertex_count * 4 + 4, NULL);
        ok &= vk_buffer(&g_vk, &bRT, (VkDeviceSize)W->row_count * 4 + 4, W->row_texels);
        ok &= vk_buffer(&g_vk, &bRF, ((VkDeviceSize)W->row_count + 1) * 4, W->row_first);
        ok &= vk_buffer(&g_vk, &bEV, (VkDeviceSize)W->row_first[W->row_count] * 4 + 4, W->entry_vertices);
        ok &= vk_buffer(&g_vk, &bEW, (VkDeviceSize)W->row_first[W->row_count] * 4 + 4, W->entry_weights);
        ok &= vk_buffer(&g_vk, &bO, 3 * (VkDeviceSize)texels * 4, NULL);
        if (ok) for (i = 0; i < 3 * texels; ++i) ((float *)bO.map)[i] = -1.0f;
        for (pass = 0; pass < 2 && ok; ++pass) {
            uint32_t n = pass == 0 ? W->vertex_count : W->row_count;
            const uint32_t *first = pass == 0 ? W->vertex_first : W->row_first;
            chunks(n, cut);
            for (q = 0; q < 3 && ok; ++q) {
                rad_glsl_lightmap_refresh_push p;
                vk_range r[10];
                uint32_t unused;
                VkDeviceSize k0 = first[cut[q]], k1 = first[cut[q + 1]];
                if (cut[q + 1] == cut[q]) continue;
                r[0] = vk_whole(&bVF); r[3] = vk_whole(&bH); r[4] = vk_whole(&bV); r[5] = vk_whole(&bRT); r[6] = vk_whole(&bRF);
                r[9] = vk_whole(&bO);
                if (pass == 0) {
                    r[1] = vk_chunk(&g_vk, &bVP, 4, k0, k1 - k0, &p.entry_base);
                    r[2] = vk_chunk(&g_vk, &bVW, 4, k0, k1 - k0, &unused);
                    r[7] = vk_whole(&bEV); r[8] = vk_whole(&bEW);
                } else {
                    r[7] = vk_chunk(&g_vk, &bEV, 4, k0, k1 - k0, &p.entry_base);
                    r[8] = vk_chunk(&g_vk, &bEW, 4, k0, k1 - k0, &unused);
                    r[1] = vk_whole(&bVP); r[2] = vk_whole(&bVW);
                }
                p.entry_base = (uint32_t)k0 - p.entry_base;
                p.pass = pass == 0 ? RAD_GLSL_LIGHTMAP_PASS_VERTICES : RAD_GLSL_LIGHTMAP_PASS_TEXELS;
                p.row_offset = cut[q];
                p.row_count = cut[q + 1] - cut[q];
                ok &= vk_dispatch(&g_vk, &k, r, &p, p.row_count);
            }
        }
        T_CHECK(ok);
        if (ok) compare("lightmap refresh", (const float *)bO.map, ref, 3 * (size_t)texels, 1e-5);
        vk_buffer_free(&g_vk, &bVF); vk_buffer_free(&g_vk, &bVP); vk_buffer_free(&g_vk, &bVW); vk_buffer_free(&g_vk, &bH);
        vk_buffer_free(&g_vk, &bV); vk_buffer_free(&g_vk, &bRT); vk_buffer_free(&g_vk, &bRF); vk_buffer_free(&g_vk, &bEV);
        vk_buffer_free(&g_vk, &bEW); vk_buffer_free(&g_vk, &bO);
        vk_kernel_destroy(&g_vk, &k);
    }
done:
    free(H); free(base); free(cpu); free(Hv); free(cpuv);
    rad_lightmap_weights_destroy(w0);
    rad_lightmap_weights_destroy(w);
    rad_lightmap_weights_destroy(wv);
    rad_vp_destroy(vp);
    rad_lightmap_destroy(lm);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(P);
    rad_scene_destroy(S);
}

/* ---- the C mirrors of the push-constant blocks, against the compiled SPIR-V ------------------ */

/* member names and byte offsets of the push-constant block of a SPIR-V module (from OpMemberName
   and OpMemberDecorate Offset); returns the member count, or -1 */
static int spirv_push_block(const uint32_t *code, size_t words, char names[24][32], uint32_t offsets[24])
{
    size_t at;
    uint32_t ptr = 0, block = 0;
    int count = 0;
    if (words < 5 || code[0] != 0x07230203u) return -1;
    for (at = 5; at < words; at += code[at] >> 16) /* OpVariable %ptr %id PushConstant */
        if ((code[at] >> 16) == 0) return -1;
        else if ((code[at] & 0xFFFFu) == 59u && code[at + 3] == 9u) ptr = code[at + 1];
    for (at = 5; at < words; at += code[at] >> 16) /* OpTypePointer %ptr PushConstant %block */
        if ((code[at] & 0xFFFFu) == 32u && code[at + 1] == ptr) block = code[at + 3];
    if (!ptr || !block) return -1;
    for (at = 5; at < words; at += code[at] >> 16) {
        uint32_t op = code[at] & 0xFFFFu, len = code[at] >> 16;
        if (op == 6u && code[at + 1] == block && code[at + 2] < 24u) { /* OpMemberName */
            snprintf(names[code[at + 2]], 32, "%.*s", (int)((len - 3) * 4), (const char *)(code + at + 3));
            if ((int)code[at + 2] + 1 > count) count = (int)code[at + 2] + 1;
        }
        if (op == 72u && code[at + 1] == block && code[at + 3] == 35u && code[at + 2] < 24u) /* Offset */
            offsets[code[at + 2]] = code[at + 4];
    }
    return count;
}

typedef struct mirror_member { const char *name; size_t offset; } mirror_member;
static int g_mirrored[RAD_GLSL_COUNT];

static void check_mirror(rad_glsl_id id, const mirror_member *m, size_t size)
{
    size_t words = 0;
    uint32_t *code = vk_compile(&g_vk, id, &words), offsets[24];
    char names[24][32];
    int count, i;
    g_mirrored[id] = 1;
    memset(names, 0, sizeof(names));
    memset(offsets, 0xFF, sizeof(offsets));
    if (!code) { T_CHECK(0); return; }
    count = spirv_push_block(code, words, names, offsets);
    free(code);
    if (count <= 0) { printf("    FAIL %s: no push-constant block found in the SPIR-V\n", rad_glsl_name(id)); g_checks_failed++; return; }
    for (i = 0; m[i].name; ++i) {
        if (i >= count || strcmp(names[i], m[i].name) != 0 || offsets[i] != m[i].offset) {
            printf("    FAIL %s: member %d is '%s' at %u in GLSL, the C mirror has '%s' at %lu\n", rad_glsl_name(id), i,
                   i < count ? names[i] : "(none)", i < count ? offsets[i] : 0u, m[i].name, (unsigned long)m[i].offset);
            g_checks_failed++;
            return;
        }
    }
    /* every GLSL member mirrored, and the C struct ends where the last (4-byte) member does */
    T_CHECK(i == count && offsets[count - 1] + 4u == size);
    if (size > g_worst) g_worst = (double)size;
}

#define MM(type, field) { #field, offsetof(type, field) }
static void test_push_mirrors(void)
{
    static const mirror_member dense[] = { MM(rad_glsl_gather_dense_push, row_offset), MM(rad_glsl_gather_dense_push, row_count),
        MM(rad_glsl_gather_dense_push, cols), MM(rad_glsl_gather_dense_push, f_base), MM(rad_glsl_gather_dense_push, flags), { NULL, 0 } };
    static const mirror_member sparse[] = { MM(rad_glsl_gather_csr_push, row_offset), MM(rad_glsl_gather_csr_push, row_count),
        MM(rad_glsl_gather_csr_push, entry_base), MM(rad_glsl_gather_csr_push, flags), { NULL, 0 } };
    static const mirror_member mb[] = { MM(rad_glsl_mb_apply_push, n), MM(rad_glsl_mb_apply_push, row_offset),
        MM(rad_glsl_mb_apply_push, row_count), MM(rad_glsl_mb_apply_push, base), MM(rad_glsl_mb_apply_push, flags), { NULL, 0 } };
    static const mirror_member temporal[] = { MM(rad_glsl_temporal_push, seed), MM(rad_glsl_temporal_push, frame),
        MM(rad_glsl_temporal_push, row_offset), MM(rad_glsl_temporal_push, row_count), MM(rad_glsl_temporal_push, n),
        MM(rad_glsl_temporal_push, samples), MM(rad_glsl_temporal_push, words), MM(rad_glsl_temporal_push, flags),
        MM(rad_glsl_temporal_push, channel), MM(rad_glsl_temporal_push, sample_base), MM(rad_glsl_temporal_push, word_base),
        MM(rad_glsl_temporal_push, weight), { "env_r", offsetof(rad_glsl_temporal_push, env) },
        { "env_g", offsetof(rad_glsl_temporal_push, env) + 4 }, { "env_b", offsetof(rad_glsl_temporal_push, env) + 8 }, { NULL, 0 } };
    static const mirror_member blocks[] = { MM(rad_glsl_mb_blocks_push, n), MM(rad_glsl_mb_blocks_push, row_offset),
        MM(rad_glsl_mb_blocks_push, row_count), MM(rad_glsl_mb_blocks_push, tile), MM(rad_glsl_mb_blocks_push, tiles_per_row),
        MM(rad_glsl_mb_blocks_push, flags), { NULL, 0 } };
    static const mirror_member alias[] = { MM(rad_glsl_alias_build_push, row_offset), MM(rad_glsl_alias_build_push, row_count),
        MM(rad_glsl_alias_build_push, cols), MM(rad_glsl_alias_build_push, words), MM(rad_glsl_alias_build_push, entry_base),
        MM(rad_glsl_alias_build_push, out_base), MM(rad_glsl_alias_build_push, flags), { NULL, 0 } };
    static const mirror_member lapply[] = { MM(rad_glsl_local_apply_push, m), MM(rad_glsl_local_apply_push, end),
        MM(rad_glsl_local_apply_push, row_offset), MM(rad_glsl_local_apply_push, row_count), MM(rad_glsl_local_apply_push, slot_offset),
        MM(rad_glsl_local_apply_push, slot_count), MM(rad_glsl_local_apply_push, base), MM(rad_glsl_local_apply_push, flags), { NULL, 0 } };
    static const mirror_member lvec[] = { MM(rad_glsl_local_vectors_push, m), MM(rad_glsl_local_vectors_push, end),
        MM(rad_glsl_local_vectors_push, row_offset), MM(rad_glsl_local_vectors_push, row_count), MM(rad_glsl_local_vectors_push, base),
        MM(rad_glsl_local_vectors_push, nnz), MM(rad_glsl_local_vectors_push, ev), MM(rad_glsl_local_vectors_push, pass),
        MM(rad_glsl_local_vectors_push, flags), { "ann_r", offsetof(rad_glsl_local_vectors_push, ann) },
        { "ann_g", offsetof(rad_glsl_local_vectors_push, ann) + 4 }, { "ann_b", offsetof(rad_glsl_local_vectors_push, ann) + 8 }, { NULL, 0 } };
    static const mirror_member lupd[] = { MM(rad_glsl_local_update_push, m), MM(rad_glsl_local_update_push, end),
        MM(rad_glsl_local_update_push, row_offset), MM(rad_glsl_local_update_push, row_count), MM(rad_glsl_local_update_push, base),
        MM(rad_glsl_local_update_push, k), MM(rad_glsl_local_update_push, ev), { NULL, 0 } };
    static const mirror_member vpg[] = { { "origin_x", offsetof(rad_glsl_vp_gather_push, origin) },
        { "origin_y", offsetof(rad_glsl_vp_gather_push, origin) + 4 }, { "origin_z", offsetof(rad_glsl_vp_gather_push, origin) + 8 },
        { "size_x", offsetof(rad_glsl_vp_gather_push, voxel_size) }, { "size_y", offsetof(rad_glsl_vp_gather_push, voxel_size) + 4 },
        { "size_z", offsetof(rad_glsl_vp_gather_push, voxel_size) + 8 }, { "dims_x", offsetof(rad_glsl_vp_gather_push, dims) },
        { "dims_y", offsetof(rad_glsl_vp_gather_push, dims) + 4 }, { "dims_z", offsetof(rad_glsl_vp_gather_push, dims) + 8 },
        MM(rad_glsl_vp_gather_push, voxel_count), MM(rad_glsl_vp_gather_push, row_offset), MM(rad_glsl_vp_gather_push, row_count),
        MM(rad_glsl_vp_gather_push, base), MM(rad_glsl_vp_gather_push, flags), { NULL, 0 } };
    static const mirror_member probe[] = { MM(rad_glsl_probe_update_push, row_offset), MM(rad_glsl_probe_update_push, row_count),
        MM(rad_glsl_probe_update_push, entry_base), MM(rad_glsl_probe_update_push, weight_base), { NULL, 0 } };
    static const mirror_member lmix[] = { MM(rad_glsl_layer_mix_push, row_offset), MM(rad_glsl_layer_mix_push, row_count),
        MM(rad_glsl_layer_mix_push, stride), MM(rad_glsl_layer_mix_push, plane_offset), MM(rad_glsl_layer_mix_push, plane_count),
        MM(rad_glsl_layer_mix_push, base), MM(rad_glsl_layer_mix_push, flags), { NULL, 0 } };
    static const mirror_member lmr[] = { MM(rad_glsl_lightmap_refresh_push, pass), MM(rad_glsl_lightmap_refresh_push, row_offset),
        MM(rad_glsl_lightmap_refresh_push, row_count), MM(rad_glsl_lightmap_refresh_push, entry_base), { NULL, 0 } };
    g_worst_what = "push-constant block, bytes";
    check_mirror(RAD_GLSL_GATHER_DENSE, dense, sizeof(rad_glsl_gather_dense_push));
    check_mirror(RAD_GLSL_GATHER_CSR, sparse, sizeof(rad_glsl_gather_csr_push));
    check_mirror(RAD_GLSL_MB_APPLY_FLOAT, mb, sizeof(rad_glsl_mb_apply_push));
    check_mirror(RAD_GLSL_MB_APPLY_HALF, mb, sizeof(rad_glsl_mb_apply_push));
    check_mirror(RAD_GLSL_TEMPORAL_STEP, temporal, sizeof(rad_glsl_temporal_push));
    check_mirror(RAD_GLSL_MB_APPLY_BLOCKS, blocks, sizeof(rad_glsl_mb_blocks_push));
    check_mirror(RAD_GLSL_ALIAS_BUILD, alias, sizeof(rad_glsl_alias_build_push));
    check_mirror(RAD_GLSL_LOCAL_APPLY, lapply, sizeof(rad_glsl_local_apply_push));
    check_mirror(RAD_GLSL_LOCAL_VECTORS, lvec, sizeof(rad_glsl_local_vectors_push));
    check_mirror(RAD_GLSL_LOCAL_UPDATE, lupd, sizeof(rad_glsl_local_update_push));
    check_mirror(RAD_GLSL_VP_GATHER, vpg, sizeof(rad_glsl_vp_gather_push));
    check_mirror(RAD_GLSL_PROBE_UPDATE, probe, sizeof(rad_glsl_probe_update_push));
    check_mirror(RAD_GLSL_LIGHTMAP_REFRESH, lmr, sizeof(rad_glsl_lightmap_refresh_push));
    check_mirror(RAD_GLSL_LAYER_MIX, lmix, sizeof(rad_glsl_layer_mix_push));
    check_mirror(RAD_GLSL_LAYER_MIX_RGB9E5, lmix, sizeof(rad_glsl_layer_mix_push));
    /* every kernel (.comp; includes have no push block) has its mirror checked above */
    {
        uint32_t id;
        for (id = 0; id < (uint32_t)RAD_GLSL_COUNT; ++id)
            if (strstr(rad_glsl_name((rad_glsl_id)id), ".comp") && !g_mirrored[id]) {
                printf("    FAIL %s: its push-constant mirror is not checked here\n", rad_glsl_name((rad_glsl_id)id));
                g_checks_failed++;
            }
    }
}

/* ---- the lighting include, as a user compiles it from memory ----------------------------------- */

/* tools/glsl/lighting_eval.comp (the kernel tests/test_shading_vulkan.c runs against the C models)
   with its #include replaced by the header's RAD_GLSL_LIGHTING text, as its comment tells a host
   without an includer to do, compiled by glslangValidator: the embedded include is usable as is */
static void test_lighting_include(void)
{
    FILE *f = fopen("tools/glsl/lighting_eval.comp", "rb");
    char *eval = NULL, *inc = NULL, path[600], cmd[2000];
    long n;
    size_t len = 0;
    const char *line;
    g_worst_what = "";
    if (!f) { printf("    (tools/glsl/lighting_eval.comp not found: run from the repository root)\n"); T_CHECK(0); return; }
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    fseek(f, 0, SEEK_SET);
    eval = (char *)calloc((size_t)n + 1, 1);
    if (!eval || fread(eval, 1, (size_t)n, f) != (size_t)n) { fclose(f); free(eval); T_CHECK(0); return; }
    fclose(f);
    T_CHECK(rad_glsl_source(RAD_GLSL_LIGHTING, NULL, 0, &len) == RAD_SUCCESS);
    inc = (char *)malloc(len + 1);
    if (!inc || rad_glsl_source(RAD_GLSL_LIGHTING, inc, len + 1, NULL) != RAD_SUCCESS) { free(eval); free(inc); T_CHECK(0); return; }
    snprintf(path, sizeof(path), "%s/lighting_eval_from_header.comp", g_vk.workdir);
    f = fopen(path, "wb");
    if (!f) { free(eval); free(inc); T_CHECK(0); return; }
    /* copy line by line: drop the #extension line, replace the #include line */
    for (line = eval; *line;) {
        const char *end = strchr(line, '\n');
        size_t ln = end ? (size_t)(end - line) + 1 : strlen(line);
        if (!strncmp(line, "#extension GL_GOOGLE_include_directive", 38)) { /* dropped */ }
        else if (!strncmp(line, "#include \"lighting.glsl\"", 24)) fwrite(inc, 1, len, f);
        else fwrite(line, 1, ln, f);
        line += ln;
    }
    fclose(f);
    T_CHECK(strstr(eval, "#include \"lighting.glsl\"") != NULL);
    snprintf(cmd, sizeof(cmd), "glslangValidator -V --target-env vulkan1.1 -o '%s.spv' '%s' > '%s.log' 2>&1", path, path, path);
    if (system(cmd) != 0) { printf("    FAIL the header's lighting include does not compile in %s (see %s.log)\n", path, path); g_checks_failed++; }
    free(eval);
    free(inc);
}

/* ---- the baker's light layers mixed: tests/test_vulkan_layers.h, _rgb9e5.h (packed layers) ---- */

#include "test_vulkan_layers.h"
#include "test_vulkan_layers_rgb9e5.h"

/* ---- the harness ---------------------------------------------------------------------------- */

typedef struct vk_test { const char *name; void (*fn)(void); } vk_test;
static const vk_test g_tests[] = {
    { "vk_push_constant_mirrors", test_push_mirrors },
    { "glsl_lighting_include_from_header", test_lighting_include },
    { "vk_gather_dense", test_gather_dense },
    { "vk_gather_csr", test_gather_csr },
    { "vk_gather_dense_beyond_one_storage_range", test_gather_over_range },
    { "vk_mb_apply_float_half_permuted", test_mb_apply },
    { "vk_temporal_step", test_temporal },
    { "vk_mb_apply_bc1_bc4_outliers_permuted", test_mb_blocks },
    { "vk_alias_build_streamed_rows_then_temporal", test_alias_build },
    { "vk_local_adds_evictions_apply_resident", test_local },
    { "vk_vp_gather_trilinear_skipping", test_vp_gather },
    { "vk_probe_update", test_probe_update },
    { "vk_lightmap_refresh", test_lightmap_refresh },
    { "vk_layer_mix_chunked_accumulate", test_layer_mix },
    { "vk_layer_mix_rgb9e5_bit_equal", test_layer_mix_rgb9e5 },
    { NULL, NULL }
};

int main(int argc, char **argv)
{
    const vk_test *t;
    const char *filter = argc > 2 ? argv[2] : NULL;
    char dir[512];
    const char *slash = strrchr(argv[0], '/');
    /* default work directory: the one the binary is in */
    if (slash && (size_t)(slash - argv[0]) < sizeof(dir)) { memcpy(dir, argv[0], (size_t)(slash - argv[0])); dir[slash - argv[0]] = 0; }
    else strcpy(dir, ".");
    if (!vk_init(&g_vk, argc > 1 ? argv[1] : dir)) {
        printf("no usable Vulkan device\n0 passed, 1 failed\n");
        return 1;
    }
    printf("device: %s (Vulkan %u.%u), minStorageBufferOffsetAlignment %lu, maxStorageBufferRange %u, validation layer %s\n",
           g_vk.props.deviceName, VK_VERSION_MAJOR(g_vk.props.apiVersion), VK_VERSION_MINOR(g_vk.props.apiVersion),
           (unsigned long)g_vk.props.limits.minStorageBufferOffsetAlignment, g_vk.props.limits.maxStorageBufferRange,
           g_vk.validation ? "on" : "not installed");
    for (t = g_tests; t->name; ++t) {
        if (filter && !strstr(t->name, filter)) continue;
        g_checks_failed = 0;
        vk_validation_errors = 0;
        g_worst = 0.0;
        g_worst_what = "relative difference from the CPU path";
        printf("%s\n", t->name);
        t->fn();
        if (vk_validation_errors) { printf("    FAIL %u validation-layer messages\n", vk_validation_errors); g_checks_failed++; }
        if (g_checks_failed) { g_failed++; printf("  FAIL %s\n", t->name); }
        else if (g_worst_what[0]) { g_passed++; printf("  ok (largest %s: %.2g)\n", g_worst_what, g_worst); }
        else { g_passed++; printf("  ok\n"); }
    }
    if (!filter) { /* no kernel without its test */
        uint32_t id;
        int missing = 0;
        for (id = 0; id < (uint32_t)RAD_GLSL_COUNT; ++id)
            if (strstr(rad_glsl_name((rad_glsl_id)id), ".comp") && !vk_created[id]) {
                printf("  FAIL kernel %s was not run by any test\n", rad_glsl_name((rad_glsl_id)id));
                missing = 1;
            }
        if (missing) g_failed++;
        else g_passed++;
        printf("every kernel run by a test: %s\n", missing ? "no" : "yes");
    }
    vk_shutdown(&g_vk);
    printf("%d passed, %d failed\n", g_passed, g_failed);
    return g_failed ? 1 : 0;
}
