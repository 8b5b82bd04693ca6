/* test_tool.c - tests of the rad tool's image I/O, image metrics and reference path tracer.

   cc -std=c99 -O2 -fopenmp -I. tests/test_tool.c tools/image.c tools/metrics.c tools/trace.c \
      -o build/test_tool -lm

   Prints one line per test and ends with "N passed, N failed"; exits non-zero on failure
   (test.h: the arguments and environment). Temporary files go to $TMPDIR (default /tmp). */
#include "fixtures.h"
#include "../tools/tool.h"
#include <stdint.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wshadow"
#endif
#include <stb/stb_image.h> /* the implementation lives in tools/image.c */
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

static char tmp_path_buf[512];
static const char *tmp_path(const char *name)
{
    const char *dir = getenv("TMPDIR");
    snprintf(tmp_path_buf, sizeof(tmp_path_buf), "%s/rad_test_tool_%s", dir && *dir ? dir : "/tmp", name);
    return tmp_path_buf;
}

static uint32_t lcg_state = 12345u;
static float frand(void)
{
    lcg_state = lcg_state * 1664525u + 1013904223u;
    return (float)(lcg_state >> 8) / 16777216.0f;
}

static void fill(tool_image *img, float v)
{
    size_t i, n = (size_t)img->width * (size_t)img->height * 3u;
    for (i = 0; i < n; ++i) img->rgb[i] = v;
}

/* ---- metrics ----------------------------------------------------------------------------- */

static void test_metrics_identity(void)
{
    tool_image a;
    size_t i;
    CHECK(tool_image_alloc(&a, 40, 30) == 0);
    for (i = 0; i < 40 * 30 * 3; ++i) a.rgb[i] = frand();
    CHECK_NEAR(tool_image_ssim(&a, &a), 1.0, 1e-12);
    CHECK(isinf(tool_image_psnr(&a, &a)) && tool_image_psnr(&a, &a) > 0.0);
    CHECK(tool_image_mse(&a, &a) == 0.0);
    tool_image_free(&a);
}

static void test_metrics_constant(void)
{
    tool_image a, b;
    CHECK(tool_image_alloc(&a, 32, 24) == 0);
    CHECK(tool_image_alloc(&b, 32, 24) == 0);
    fill(&a, 0.5f);
    fill(&b, 0.6f);
    /* (2*0.5*0.6 + C1) C2 / ((0.25 + 0.36 + C1) C2) = 0.6001 / 0.6101 */
    CHECK_NEAR(tool_image_ssim(&a, &b), 0.98360924, 1e-6);
    CHECK_NEAR(tool_image_mse(&a, &b), 0.01, 1e-8);
    /* the image stores floats: 0.6f = 0.600000024, so PSNR is 20 dB to 2e-6; to 1e-9 it is
       the value for the float's exact difference */
    CHECK_NEAR(tool_image_psnr(&a, &b), 20.0, 1e-5);
    CHECK_NEAR(tool_image_psnr(&a, &b), -20.0 * log10((double)0.6f - 0.5), 1e-9);
    tool_image_free(&a);
    tool_image_free(&b);
}

static void test_metrics_constant_exact(void)
{
    /* 0.5 and 0.625 are exact in binary: MSE = 0.015625 exactly, PSNR to 1e-9 */
    tool_image a, b;
    CHECK(tool_image_alloc(&a, 16, 16) == 0);
    CHECK(tool_image_alloc(&b, 16, 16) == 0);
    fill(&a, 0.5f);
    fill(&b, 0.625f);
    CHECK(tool_image_mse(&a, &b) == 0.015625);
    CHECK_NEAR(tool_image_psnr(&a, &b), 10.0 * log10(64.0), 1e-9);
    tool_image_free(&a);
    tool_image_free(&b);
}

static void test_metrics_noise(void)
{
    tool_image a, b;
    size_t i, n = 64 * 48 * 3;
    double s;
    CHECK(tool_image_alloc(&a, 64, 48) == 0);
    CHECK(tool_image_alloc(&b, 64, 48) == 0);
    for (i = 0; i < n; ++i) {
        a.rgb[i] = frand();
        b.rgb[i] = a.rgb[i] + 0.1f * (frand() - 0.5f);
    }
    s = tool_image_ssim(&a, &b);
    CHECK(s < 0.999 && s > 0.5);
    CHECK(tool_image_psnr(&a, &b) > 20.0 && tool_image_psnr(&a, &b) < 60.0);
    printf("    random vs itself + noise: SSIM %.6f, PSNR %.3f dB\n", s, tool_image_psnr(&a, &b));
    tool_image_free(&a);
    tool_image_free(&b);
}

static void test_metrics_clamp(void)
{
    tool_image a, b;
    CHECK(tool_image_alloc(&a, 20, 20) == 0);
    CHECK(tool_image_alloc(&b, 20, 20) == 0);
    fill(&a, 1.0f);
    fill(&b, 1.0f);
    a.rgb[7] = 5.0f;    /* above 1: compares as 1 */
    a.rgb[100] = 1e30f;
    b.rgb[50] = -2.0f;  /* below 0: compares as 0 */
    CHECK_NEAR(tool_image_mse(&a, &b), 1.0 / (20.0 * 20.0 * 3.0), 1e-15);
    b.rgb[50] = 1.0f;
    CHECK(tool_image_mse(&a, &b) == 0.0);
    CHECK(isinf(tool_image_psnr(&a, &b)));
    CHECK_NEAR(tool_image_ssim(&a, &b), 1.0, 1e-12);
    tool_image_free(&a);
    tool_image_free(&b);
}

static void test_metrics_heatmap(void)
{
    tool_image a, b, h = { 0, 0, NULL };
    CHECK(tool_image_alloc(&a, 4, 2) == 0);
    CHECK(tool_image_alloc(&b, 4, 2) == 0);
    a.rgb[3 * 5] = a.rgb[3 * 5 + 1] = a.rgb[3 * 5 + 2] = 0.5f;
    CHECK(tool_image_diff_heatmap(&a, &b, 0.5f, &h) == 0);
    CHECK(h.width == 4 && h.height == 2);
    CHECK(h.rgb[0] == 0.0f && h.rgb[1] == 0.0f && h.rgb[2] == 0.0f);                   /* no difference: black */
    CHECK(h.rgb[15] > 0.99f && h.rgb[16] > 0.99f && h.rgb[17] > 0.99f);                 /* full scale: white */
    tool_image_free(&h);
    tool_image_free(&a);
    tool_image_free(&b);
}

/* ---- images ------------------------------------------------------------------------------ */

static void test_pfm_roundtrip(void)
{
    tool_image a, b = { 0, 0, NULL };
    size_t i, n = 7 * 5 * 3;
    char err[256];
    FILE *f;
    CHECK(tool_image_alloc(&a, 7, 5) == 0);
    for (i = 0; i < n; ++i) a.rgb[i] = (frand() - 0.3f) * 1000.0f * frand() * frand();
    a.rgb[0] = 1.25f;  /* top-left */
    a.rgb[1] = 2.5f;
    a.rgb[2] = 3.75f;
    a.rgb[3 * 4 * 7] = -7.0f; /* bottom-left red */
    a.rgb[5] = 1e-40f; /* subnormal */
    CHECK(tool_image_write_pfm(tmp_path("rt.pfm"), &a) == 0);
    CHECK(tool_image_read_pfm(tmp_path("rt.pfm"), &b, err, sizeof(err)) == 0);
    CHECK(b.width == 7 && b.height == 5);
    if (b.rgb && b.width == 7 && b.height == 5) {
        CHECK(memcmp(a.rgb, b.rgb, n * sizeof(float)) == 0);
        CHECK(b.rgb[0] == 1.25f && b.rgb[1] == 2.5f && b.rgb[2] == 3.75f);
    }
    /* the file stores the bottom row first, little-endian (scale -1) */
    f = fopen(tmp_path("rt.pfm"), "rb");
    CHECK(f != NULL);
    if (f) {
        char hdr[32];
        unsigned char raw[4];
        float v;
        size_t got = fread(hdr, 1, 13, f); /* "PF\n7 5\n-1.0\n" is 12 bytes */
        CHECK(got == 13);
        CHECK(memcmp(hdr, "PF\n7 5\n-1.0\n", 12) == 0);
        fseek(f, 12, SEEK_SET);
        CHECK(fread(raw, 1, 4, f) == 4);
        v = 0.0f;
        {
            uint32_t u = (uint32_t)raw[0] | ((uint32_t)raw[1] << 8) | ((uint32_t)raw[2] << 16) | ((uint32_t)raw[3] << 24);
            memcpy(&v, &u, 4);
        }
        CHECK(v == -7.0f);
        fclose(f);
    }
    /* written through tool_image_write by extension, exposure ignored for PFM */
    tool_image_free(&b);
    CHECK(tool_image_write(tmp_path("rt2.pfm"), &a, 4.0f) == 0);
    CHECK(tool_image_read(tmp_path("rt2.pfm"), &b, err, sizeof(err)) == 0);
    CHECK(b.rgb && memcmp(a.rgb, b.rgb, n * sizeof(float)) == 0);
    tool_image_free(&b);
    /* errors */
    CHECK(tool_image_read_pfm(tmp_path("does-not-exist.pfm"), &b, err, sizeof(err)) != 0 && err[0]);
    tool_image_free(&a);
    remove(tmp_path("rt.pfm"));
    remove(tmp_path("rt2.pfm"));
}

static void test_png_write(void)
{
    tool_image a, b = { 0, 0, NULL };
    int w, h, comp;
    unsigned char *px;
    char err[256];
    CHECK(tool_image_alloc(&a, 3, 2) == 0);
    /* row 0: 0, 0.5, 1 (grey); row 1: 0.18, 2.0, (0.0031308, 0.25, -1) */
    fill(&a, 0.0f);
    a.rgb[3] = a.rgb[4] = a.rgb[5] = 0.5f;
    a.rgb[6] = a.rgb[7] = a.rgb[8] = 1.0f;
    a.rgb[9] = a.rgb[10] = a.rgb[11] = 0.18f;
    a.rgb[12] = a.rgb[13] = a.rgb[14] = 2.0f;
    a.rgb[15] = 0.0031308f;
    a.rgb[16] = 0.25f;
    a.rgb[17] = -1.0f;
    CHECK(tool_image_write(tmp_path("w.png"), &a, 1.0f) == 0);
    px = stbi_load(tmp_path("w.png"), &w, &h, &comp, 3);
    CHECK(px != NULL);
    if (px) {
        CHECK(w == 3 && h == 2);
        CHECK(px[0] == 0 && px[1] == 0 && px[2] == 0);
        CHECK(px[3] == 188 && px[4] == 188 && px[5] == 188); /* 1.055 * 0.5^(1/2.4) - 0.055 = 0.7354 */
        CHECK(px[6] == 255);
        CHECK(px[9] == 118);                                 /* 0.4614 * 255 = 117.7 */
        CHECK(px[12] == 255);                                /* clamped */
        CHECK(px[15] == 10);                                 /* 12.92 * 0.0031308 * 255 = 10.3 */
        CHECK(px[16] == 137);                                /* 0.5371 * 255 = 136.9 */
        CHECK(px[17] == 0);
        stbi_image_free(px);
    }
    /* exposure scales before encoding */
    CHECK(tool_image_write_png(tmp_path("w2.png"), &a, 2.0f) == 0);
    px = stbi_load(tmp_path("w2.png"), &w, &h, &comp, 3);
    CHECK(px != NULL);
    if (px) {
        CHECK(px[3] == 255 && px[16] == 188);
        stbi_image_free(px);
    }
    /* read back through tool_image_read: decoded to linear */
    CHECK(tool_image_read(tmp_path("w.png"), &b, err, sizeof(err)) == 0);
    if (b.rgb) {
        CHECK_NEAR(b.rgb[3], 0.5, 0.003);
        CHECK_NEAR(b.rgb[9], 0.18, 0.002);
        CHECK(b.rgb[6] == 1.0f && b.rgb[0] == 0.0f);
    }
    tool_image_free(&b);
    tool_image_free(&a);
    remove(tmp_path("w.png"));
    remove(tmp_path("w2.png"));
}

/* ---- path tracer ------------------------------------------------------------------------- */

/* A closed unit box [0,1]^3, six faces facing inward (two triangles each); face f uses
   material f (0: x=0, 1: x=1, 2: y=0, 3: y=1, 4: z=0, 5: z=1). */
static float box_pos[6 * 4 * 3];
static uint32_t box_idx[6 * 6];
static uint32_t box_mat[12];

static void make_box(void)
{
    int f, k, axis, side, v;
    for (f = 0; f < 6; ++f) {
        float q[4][3], nrm[3], e1[3], e2[3], want;
        axis = f / 2;
        side = f % 2;
        for (v = 0; v < 4; ++v) {
            int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
            q[v][axis] = (float)side;
            q[v][a1] = (float)(v == 1 || v == 2);
            q[v][a2] = (float)(v >= 2);
        }
        for (k = 0; k < 3; ++k) {
            e1[k] = q[1][k] - q[0][k];
            e2[k] = q[2][k] - q[0][k];
        }
        nrm[0] = e1[1] * e2[2] - e1[2] * e2[1];
        nrm[1] = e1[2] * e2[0] - e1[0] * e2[2];
        nrm[2] = e1[0] * e2[1] - e1[1] * e2[0];
        want = side ? -1.0f : 1.0f; /* inward */
        for (v = 0; v < 4; ++v)
            for (k = 0; k < 3; ++k) box_pos[(f * 4 + v) * 3 + k] = q[v][k];
        if (nrm[axis] * want > 0.0f) {
            uint32_t t[6] = { 0, 1, 2, 0, 2, 3 };
            for (k = 0; k < 6; ++k) box_idx[f * 6 + k] = (uint32_t)(f * 4) + t[k];
        } else {
            uint32_t t[6] = { 0, 2, 1, 0, 3, 2 };
            for (k = 0; k < 6; ++k) box_idx[f * 6 + k] = (uint32_t)(f * 4) + t[k];
        }
        box_mat[2 * f] = box_mat[2 * f + 1] = (uint32_t)f;
    }
}

static rad_scene *box_scene(const rad_material *mats)
{
    rad_mesh_desc m;
    rad_scene_desc d;
    rad_scene *s = NULL;
    make_box();
    memset(&m, 0, sizeof(m));
    memset(&d, 0, sizeof(d));
    m.name = "box";
    m.positions = box_pos;
    m.vertex_count = 24;
    m.indices = box_idx;
    m.triangle_count = 12;
    m.material_ids = box_mat;
    d.meshes = &m;
    d.mesh_count = 1;
    d.materials = mats;
    d.material_count = 6;
    if (rad_scene_create(&d, NULL, &s) != RAD_SUCCESS) return NULL;
    return s;
}

static void image_mean(const tool_image *img, double out[3])
{
    size_t i, n = (size_t)img->width * (size_t)img->height;
    out[0] = out[1] = out[2] = 0.0;
    for (i = 0; i < n; ++i) {
        out[0] += img->rgb[3 * i];
        out[1] += img->rgb[3 * i + 1];
        out[2] += img->rgb[3 * i + 2];
    }
    out[0] /= (double)n;
    out[1] /= (double)n;
    out[2] /= (double)n;
}

/* Furnace: every face emits L and reflects rho, so the radiance is L / (1 - rho) everywhere. */
static void test_trace_furnace(void)
{
    rad_material mats[6];
    rad_scene *s;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_camera cam = { { 0.5f, 0.5f, 0.5f }, { 0.5f, 0.5f, 0.0f }, { 0.0f, 1.0f, 0.0f }, 90.0f };
    tool_trace_options o;
    tool_image img = { 0, 0, NULL };
    double mean[3];
    const float L[3] = { 1.0f, 0.5f, 0.25f }, rho = 0.5f;
    int f, k;
    for (f = 0; f < 6; ++f)
        for (k = 0; k < 3; ++k) {
            mats[f].albedo[k] = rho;
            mats[f].emission[k] = L[k];
            mats[f].texture = 0;
            mats[f].two_sided = 0;
            mats[f].emission_texture = 0;
            mats[f].opacity_texture = 0;
            mats[f].alpha_cutoff = 0.0f;
        }
    s = box_scene(mats);
    CHECK(s != NULL);
    if (!s) return;
    CHECK_OK(rad_bvh_create(s, NULL, &bvh));
    rad_bvh_raycaster(bvh, &rc);
    tool_trace_options_default(&o);
    o.width = 16;
    o.height = 16;
    o.spp = 64;
    o.seed = 7;
    CHECK(tool_trace_image(s, &rc, NULL, 0, &cam, &o, NULL, &img) == 0);
    image_mean(&img, mean);
    printf("    furnace (rho 0.5, L 1 0.5 0.25): mean radiance %.5f %.5f %.5f, exact %.5f %.5f %.5f\n", mean[0], mean[1],
           mean[2], L[0] / (1.0 - rho), L[1] / (1.0 - rho), L[2] / (1.0 - rho));
    for (k = 0; k < 3; ++k) CHECK_REL(mean[k], L[k] / (1.0 - rho), 0.01);
    /* the same with rho 0.8 (longer paths, Russian roulette active): L / 0.2 */
    rad_bvh_destroy(bvh);
    rad_scene_destroy(s);
    for (f = 0; f < 6; ++f)
        for (k = 0; k < 3; ++k) mats[f].albedo[k] = 0.8f;
    s = box_scene(mats);
    bvh = NULL;
    CHECK(s && rad_bvh_create(s, NULL, &bvh) == RAD_SUCCESS);
    if (s && bvh) {
        rad_bvh_raycaster(bvh, &rc);
        o.spp = rad_test_quick() ? 64 : 256;
        CHECK(tool_trace_image(s, &rc, NULL, 0, &cam, &o, NULL, &img) == 0);
        image_mean(&img, mean);
        printf("    furnace (rho 0.8): mean radiance %.5f %.5f %.5f, exact %.5f %.5f %.5f\n", mean[0], mean[1], mean[2],
               L[0] / 0.2, L[1] / 0.2, L[2] / 0.2);
        for (k = 0; k < 3; ++k) CHECK_REL(mean[k], L[k] / 0.2, 0.02);
    }
    tool_image_free(&img);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(s);
}

/* Sky furnace: an open scene (one floor quad facing up, albedo rho) under a sky of exitance
   E0: the camera sees the sky (E0/pi) where it misses and rho E0 / pi on the floor. */
static void test_trace_sky(void)
{
    static const float pos[12] = { -1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1 };
    static const uint32_t idx[6] = { 0, 2, 1, 0, 3, 2 };
    rad_material mat = { { 0.5f, 0.5f, 0.5f }, { 0, 0, 0 }, 0, 0, 0, 0, 0.0f };
    rad_mesh_desc m;
    rad_scene_desc d;
    rad_scene *s = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_light sky;
    rad_camera down = { { 0.0f, 0.5f, 0.0f }, { 0.0f, 0.0f, 0.0f }, { 0.0f, 0.0f, 1.0f }, 30.0f };
    rad_camera up = { { 0.0f, 0.5f, 0.0f }, { 0.0f, 1.0f, 0.0f }, { 0.0f, 0.0f, 1.0f }, 30.0f };
    tool_trace_options o;
    tool_image img = { 0, 0, NULL };
    double mean[3];
    memset(&m, 0, sizeof(m));
    memset(&d, 0, sizeof(d));
    memset(&sky, 0, sizeof(sky));
    m.positions = pos;
    m.vertex_count = 4;
    m.indices = idx;
    m.triangle_count = 2;
    d.meshes = &m;
    d.mesh_count = 1;
    d.materials = &mat;
    d.material_count = 1;
    CHECK_OK(rad_scene_create(&d, NULL, &s));
    if (!s) return;
    CHECK(s->normals[1] > 0.9f);
    CHECK_OK(rad_bvh_create(s, NULL, &bvh));
    rad_bvh_raycaster(bvh, &rc);
    sky.type = RAD_LIGHT_SKY;
    sky.color[0] = sky.color[1] = sky.color[2] = (float)RAD__PI; /* radiance 1 */
    tool_trace_options_default(&o);
    o.width = o.height = 8;
    o.spp = 16;
    CHECK(tool_trace_image(s, &rc, &sky, 1, &up, &o, NULL, &img) == 0);
    image_mean(&img, mean);
    CHECK_NEAR(mean[0], 1.0, 1e-5);
    /* looking down at the floor centre: it sees the whole sky, reflects rho * E0 / pi = 0.5 */
    CHECK(tool_trace_image(s, &rc, &sky, 1, &down, &o, NULL, &img) == 0);
    image_mean(&img, mean);
    printf("    sky over a floor: floor radiance %.5f, exact 0.5\n", mean[0]);
    CHECK_NEAR(mean[0], 0.5, 1e-5); /* every bounce escapes: no variance at all */
    tool_image_free(&img);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(s);
}

/* One emitting face: compare with the classic radiosity solution (patches, dense form factors,
   direct LU solve, radiance = B / pi looked up at each pixel's hit). */
static void test_trace_vs_radiosity(void)
{
    rad_material mats[6];
    rad_scene *s;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_patches *P = NULL;
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_form_factors *ff = NULL;
    rad_system sys;
    rad_solve_options so;
    /* inside the box, looking at the wall x = 0 (the ceiling y = 1 emits); the view (y and z
       in [0.08, 0.92]) stays inside the wall, so every pixel's footprint lies on it */
    rad_camera cam = { { 0.9f, 0.5f, 0.5f }, { 0.0f, 0.5f, 0.5f }, { 0.0f, 1.0f, 0.0f }, 50.0f };
    tool_trace_options o;
    tool_image img = { 0, 0, NULL };
    float *E = NULL, *B = NULL;
    double tr[2][3] = { { 0, 0, 0 }, { 0, 0, 0 } }, ra[2][3] = { { 0, 0, 0 }, { 0, 0, 0 } };
    int f, k, x, y, cnt[2] = { 0, 0 };
    for (f = 0; f < 6; ++f)
        for (k = 0; k < 3; ++k) {
            mats[f].albedo[k] = k == 0 ? 0.5f : (k == 1 ? 0.7f : 0.3f);
            mats[f].emission[k] = f == 3 ? 1.0f : 0.0f;
            mats[f].texture = 0;
            mats[f].two_sided = 0;
            mats[f].emission_texture = 0;
            mats[f].opacity_texture = 0;
            mats[f].alpha_cutoff = 0.0f;
        }
    s = box_scene(mats);
    CHECK(s != NULL);
    if (!s) return;
    CHECK_OK(rad_bvh_create(s, NULL, &bvh));
    rad_bvh_raycaster(bvh, &rc);
    rad_patch_options_default(&po);
    po.target_count = 1200;
    CHECK_OK(rad_patches_create(s, &po, NULL, &P));
    rad_form_factor_options_default(&fo);
    if (P) CHECK_OK(rad_form_factors_dense(P, &rc, &fo, NULL, &ff));
    if (!P || !ff) goto done;
    E = (float *)malloc(sizeof(float) * 3 * P->count);
    B = (float *)malloc(sizeof(float) * 3 * P->count);
    if (!E || !B) goto done;
    CHECK_OK(rad_sources(P, RAD_SOURCE_EMISSION, NULL, E));
    rad_system_init(&sys, &ff->matrix, P, E);
    rad_solve_options_default(&so);
    so.output = RAD_OUTPUT_TOTAL;
    CHECK_OK(rad_solve_direct(&sys, &so, B, NULL));

    tool_trace_options_default(&o);
    o.width = 24;
    o.height = 24;
    o.spp = 256;
    o.seed = 3;
    CHECK(tool_trace_image(s, &rc, NULL, 0, &cam, &o, NULL, &img) == 0);
    /* top half and bottom half of the image separately (the wall is brighter near the light) */
    for (y = 0; y < o.height; ++y)
        for (x = 0; x < o.width; ++x) {
            rad_ray ray;
            rad_hit hit;
            float w[3];
            uint32_t p;
            int half = y < o.height / 2 ? 0 : 1;
            rad_camera_ray(&cam, (uint32_t)o.width, (uint32_t)o.height, (float)x + 0.5f, (float)y + 0.5f, &ray);
            if (rc.intersect(rc.user, &ray, 1, &hit) != RAD_SUCCESS || hit.triangle == RAD_NONE) continue;
            CHECK(hit.triangle < 2); /* the wall x = 0 */
            p = rad_patches_locate(P, hit.triangle, hit.b1, hit.b2, w);
            if (p == RAD_NONE) continue;
            for (k = 0; k < 3; ++k) {
                tr[half][k] += img.rgb[3 * ((size_t)y * (size_t)o.width + (size_t)x) + (size_t)k];
                ra[half][k] += B[3 * (size_t)p + (size_t)k] / RAD__PI;
            }
            cnt[half]++;
        }
    for (f = 0; f < 2; ++f) {
        printf("    %s half of the wall: traced %.5f %.5f %.5f, radiosity (%u patches) %.5f %.5f %.5f\n",
               f ? "bottom" : "top", tr[f][0] / cnt[f], tr[f][1] / cnt[f], tr[f][2] / cnt[f], P->count, ra[f][0] / cnt[f],
               ra[f][1] / cnt[f], ra[f][2] / cnt[f]);
        for (k = 0; k < 3; ++k) CHECK_REL(tr[f][k] / cnt[f], ra[f][k] / cnt[f], 0.01);
    }
done:
    free(E);
    free(B);
    tool_image_free(&img);
    rad_form_factors_destroy(ff);
    rad_patches_destroy(P);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(s);
}

/* tasks in reverse order, one after another: a different schedule than OpenMP's */
static void reverse_parallel_for(void *user, uint32_t count, rad_task_fn fn, void *data)
{
    uint32_t i;
    (void)user;
    for (i = count; i-- > 0;) fn(data, i);
}

static void test_trace_determinism(void)
{
    rad_scene_desc desc;
    rad_camera cam;
    rad_scene *s = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    tool_trace_options o;
    rad_context ctx;
    tool_image a = { 0, 0, NULL }, b = { 0, 0, NULL }, c = { 0, 0, NULL }, d = { 0, 0, NULL };
    size_t bytes;
    rad_cornell_box(&desc, &cam);
    CHECK_OK(rad_scene_create(&desc, NULL, &s));
    if (!s) return;
    CHECK_OK(rad_bvh_create(s, NULL, &bvh));
    rad_bvh_raycaster(bvh, &rc);
    tool_trace_options_default(&o);
    o.width = 32;
    o.height = 24;
    o.spp = 8;
    o.seed = 42;
#ifdef _OPENMP
    omp_set_num_threads(1);
#endif
    CHECK(tool_trace_image(s, &rc, NULL, 0, &cam, &o, NULL, &a) == 0);
#ifdef _OPENMP
    omp_set_num_threads(2);
#endif
    CHECK(tool_trace_image(s, &rc, NULL, 0, &cam, &o, NULL, &b) == 0);
    memset(&ctx, 0, sizeof(ctx));
    ctx.parallel_for = reverse_parallel_for;
    CHECK(tool_trace_image(s, &rc, NULL, 0, &cam, &o, &ctx, &c) == 0);
    o.seed = 43;
    CHECK(tool_trace_image(s, &rc, NULL, 0, &cam, &o, NULL, &d) == 0);
    bytes = (size_t)o.width * (size_t)o.height * 3u * sizeof(float);
    CHECK(a.rgb && b.rgb && c.rgb && d.rgb);
    if (a.rgb && b.rgb && c.rgb && d.rgb) {
        CHECK(memcmp(a.rgb, b.rgb, bytes) == 0); /* 1 vs 2 threads */
        CHECK(memcmp(a.rgb, c.rgb, bytes) == 0); /* reverse task order */
        CHECK(memcmp(a.rgb, d.rgb, bytes) != 0); /* another seed */
        CHECK(tool_image_mse(&a, &d) > 0.0);
    }
    tool_image_free(&a);
    tool_image_free(&b);
    tool_image_free(&c);
    tool_image_free(&d);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(s);
}

/* a camera ray that hits the Cornell light's front sees its radiance (17 12 4); a black
   scene stays black; bad arguments are refused */
static void test_trace_basics(void)
{
    rad_scene_desc desc;
    rad_camera cam, up;
    rad_scene *s = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    tool_trace_options o;
    tool_image img = { 0, 0, NULL };
    rad_cornell_box(&desc, &cam);
    CHECK_OK(rad_scene_create(&desc, NULL, &s));
    if (!s) return;
    CHECK_OK(rad_bvh_create(s, NULL, &bvh));
    rad_bvh_raycaster(bvh, &rc);
    /* from the floor centre of the light's footprint, straight up with a narrow view */
    up = cam;
    up.position[0] = 0.278f;
    up.position[1] = 0.01f;
    up.position[2] = 0.2795f;
    up.target[0] = 0.278f;
    up.target[1] = 1.0f;
    up.target[2] = 0.2795f;
    up.up[0] = 0.0f;
    up.up[1] = 0.0f;
    up.up[2] = 1.0f;
    up.fov_y_degrees = 5.0f;
    tool_trace_options_default(&o);
    o.width = o.height = 4;
    o.spp = 4;
    CHECK(tool_trace_image(s, &rc, NULL, 0, &up, &o, NULL, &img) == 0);
    if (img.rgb) {
        /* emission plus a little light reflected by the light's albedo 0.78 from below */
        CHECK(img.rgb[0] >= 17.0f && img.rgb[0] < 17.5f);
        CHECK(img.rgb[1] >= 12.0f && img.rgb[1] < 12.5f);
        CHECK(img.rgb[2] >= 4.0f && img.rgb[2] < 4.5f);
    }
    o.spp = 0;
    CHECK(tool_trace_image(s, &rc, NULL, 0, &cam, &o, NULL, &img) != 0);
    CHECK(tool_trace_image(NULL, &rc, NULL, 0, &cam, &o, NULL, &img) != 0);
    tool_image_free(&img);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(s);
}

/* a point light above a floor: the irradiance I cos / d^2 by NEE, radiance rho/pi times it */
static void test_trace_point_light(void)
{
    static const float pos[12] = { -1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1 };
    static const uint32_t idx[6] = { 0, 2, 1, 0, 3, 2 };
    rad_material mat = { { 0.5f, 0.5f, 0.5f }, { 0, 0, 0 }, 0, 0, 0, 0, 0.0f };
    rad_mesh_desc m;
    rad_scene_desc d;
    rad_scene *s = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_light li;
    rad_camera down = { { 0.0f, 0.5f, 0.0f }, { 0.0f, 0.0f, 0.0f }, { 0.0f, 0.0f, 1.0f }, 0.5f };
    tool_trace_options o;
    tool_image img = { 0, 0, NULL };
    double mean[3];
    memset(&m, 0, sizeof(m));
    memset(&d, 0, sizeof(d));
    memset(&li, 0, sizeof(li));
    m.positions = pos;
    m.vertex_count = 4;
    m.indices = idx;
    m.triangle_count = 2;
    d.meshes = &m;
    d.mesh_count = 1;
    d.materials = &mat;
    d.material_count = 1;
    CHECK_OK(rad_scene_create(&d, NULL, &s));
    if (!s) return;
    CHECK_OK(rad_bvh_create(s, NULL, &bvh));
    rad_bvh_raycaster(bvh, &rc);
    li.type = RAD_LIGHT_POINT;
    li.color[0] = li.color[1] = li.color[2] = 4.0f;
    li.position[1] = 2.0f;
    tool_trace_options_default(&o);
    o.width = o.height = 2;
    o.spp = 4;
    CHECK(tool_trace_image(s, &rc, &li, 1, &down, &o, NULL, &img) == 0);
    image_mean(&img, mean);
    /* E = 4 / 2^2 = 1 at the centre; L = 0.5 / pi (the view covers a tiny spot) */
    CHECK_REL(mean[0], 0.5 / RAD__PI, 1e-3);
    tool_image_free(&img);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(s);
}

static const rad_test_case tests[] = {
    { "metrics: SSIM(x,x) = 1, PSNR(x,x) = inf", test_metrics_identity },
    { "metrics: constants 0.5 / 0.6 (SSIM 0.98360924, PSNR 20 dB, MSE 0.01)", test_metrics_constant },
    { "metrics: exact MSE/PSNR for 0.5 / 0.625", test_metrics_constant_exact },
    { "metrics: random image vs noisy copy", test_metrics_noise },
    { "metrics: values clamped to [0,1]", test_metrics_clamp },
    { "metrics: difference heat map", test_metrics_heatmap },
    { "image: PFM round trip, bottom row first", test_pfm_roundtrip },
    { "image: PNG 8-bit sRGB values", test_png_write },
    { "trace: basics (emitter radiance, bad arguments)", test_trace_basics },
    { "trace: furnace box L/(1-rho)", test_trace_furnace },
    { "trace: sky light", test_trace_sky },
    { "trace: point light NEE", test_trace_point_light },
    { "trace: agrees with the radiosity solution", test_trace_vs_radiosity },
    { "trace: deterministic across threads and schedules", test_trace_determinism },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests)
