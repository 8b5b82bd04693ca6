/* test_scene.c - scene input and validation, patches, context hooks, the built-in Cornell box.
   Included by test_main.c after the implementation: everything is static and prefixed sc_. */
#include "fixtures.h"


/* ---- helpers ---------------------------------------------------------------------------- */

/* 4 vertices of a quad: corner c, edges u and v (normal u x v), into pos[12] */
static void sc_quad(float *pos, const float *c, const float *u, const float *v)
{
    int k;
    for (k = 0; k < 3; ++k) {
        pos[k] = c[k];
        pos[3 + k] = c[k] + u[k];
        pos[6 + k] = c[k] + u[k] + v[k];
        pos[9 + k] = c[k] + v[k];
    }
}

static const uint32_t sc_quad_idx[6] = { 0, 1, 2, 0, 2, 3 };

/* A unit quad in the xz plane facing +y (two triangles), one material. */
typedef struct sc_basic {
    float pos[12];
    float nrm[12];
    float uv[8];
    uint32_t idx[6];
    uint32_t mat_ids[2];
    rad_material mat[2];
    rad_mesh_desc mesh;
    rad_scene_desc desc;
} sc_basic;

static void sc_basic_init(sc_basic *b)
{
    static const float c[3] = { 0, 0, 0 }, u[3] = { 0, 0, 1 }, v[3] = { 1, 0, 0 };
    int i;
    memset(b, 0, sizeof(*b));
    sc_quad(b->pos, c, u, v);
    for (i = 0; i < 4; ++i) {
        b->nrm[3 * i] = 0; b->nrm[3 * i + 1] = 1; b->nrm[3 * i + 2] = 0;
        b->uv[2 * i] = (float)(i & 1); b->uv[2 * i + 1] = (float)(i >> 1);
    }
    memcpy(b->idx, sc_quad_idx, sizeof(b->idx));
    b->mat[0].albedo[0] = 0.5f; b->mat[0].albedo[1] = 0.5f; b->mat[0].albedo[2] = 0.5f;
    b->mat[1] = b->mat[0];
    b->mesh.name = "quad";
    b->mesh.positions = b->pos;
    b->mesh.vertex_count = 4;
    b->mesh.indices = b->idx;
    b->mesh.triangle_count = 2;
    b->mesh.material = 0;
    b->desc.meshes = &b->mesh;
    b->desc.mesh_count = 1;
    b->desc.materials = b->mat;
    b->desc.material_count = 1;
}

/* rad_scene_create must fail with 'expected', set out to NULL, log a message containing
   each non-NULL substring. */
static void sc_expect_fail(const rad_scene_desc *desc, rad_result expected, const char *sub1, const char *sub2, int line)
{
    rad_context ctx;
    sc_log_state log;
    rad_scene *scene = (rad_scene *)(void *)&log; /* a non-NULL garbage value to be overwritten */
    rad_result r;
    memset(&ctx, 0, sizeof(ctx));
    memset(&log, 0, sizeof(log));
    ctx.log = sc_log_fn;
    ctx.log_user = &log;
    r = rad_scene_create(desc, &ctx, &scene);
    if (r != expected) {
        printf("    (case at line %d)\n", line);
        CHECK_RESULT(r, expected);
    }
    if (r == RAD_SUCCESS) rad_scene_destroy(scene);
    else CHECK(scene == NULL);
    if (!(log.count > 0)) { printf("    (case at line %d: no log message)\n", line); CHECK(log.count > 0); }
    if (sub1 && !strstr(log.last, sub1)) { printf("    (line %d: '%s' lacks '%s')\n", line, log.last, sub1); CHECK(0); }
    if (sub2 && !strstr(log.last, sub2)) { printf("    (line %d: '%s' lacks '%s')\n", line, log.last, sub2); CHECK(0); }
}
#define SC_FAIL(desc, code, s1, s2) sc_expect_fail(desc, code, s1, s2, __LINE__)

static void sc_dummy_albedo(void *user, uint32_t texture, float u, float v, float out_rgb[3])
{
    (void)user; (void)texture;
    out_rgb[0] = 0.2f + 0.5f * u; out_rgb[1] = 0.3f; out_rgb[2] = 0.2f + 0.5f * v;
}

/* ---- validation ------------------------------------------------------------------------- */

static void sc_test_validation_indices_finite(void)
{
    sc_basic b;
    float nan = (float)NAN, inf = (float)INFINITY;

    sc_basic_init(&b);
    b.idx[4] = 7;
    SC_FAIL(&b.desc, RAD_ERROR_INDEX_OUT_OF_RANGE, "triangle 1", "quad");

    sc_basic_init(&b);
    b.pos[3 * 2 + 1] = nan;
    SC_FAIL(&b.desc, RAD_ERROR_NON_FINITE, "vertex 2", NULL);
    sc_basic_init(&b);
    b.pos[3 * 3 + 0] = inf;
    SC_FAIL(&b.desc, RAD_ERROR_NON_FINITE, "vertex 3", NULL);

    sc_basic_init(&b);
    b.mesh.normals = b.nrm;
    b.nrm[3 * 1 + 2] = nan;
    SC_FAIL(&b.desc, RAD_ERROR_NON_FINITE, "vertex 1", "normal");

    sc_basic_init(&b);
    b.mesh.uvs = b.uv;
    b.uv[2 * 2 + 1] = nan;
    SC_FAIL(&b.desc, RAD_ERROR_NON_FINITE, "vertex 2", "uv");

    /* non-indexed mesh with too few vertices */
    sc_basic_init(&b);
    b.mesh.indices = NULL;
    SC_FAIL(&b.desc, RAD_ERROR_INDEX_OUT_OF_RANGE, NULL, NULL);
}

static void sc_test_validation_degenerate(void)
{
    sc_basic b;
    rad_scene *scene = NULL;
    float pos[15];
    uint32_t idx[9] = { 0, 1, 2, 0, 2, 3, 0, 1, 4 };
    rad_context actx;
    sc_alloc_state st;
    memset(&st, 0, sizeof(st));
    sc_ctx_alloc(&actx, &st); /* the canaries catch writes past the scene's arrays */

    /* zero area: a repeated vertex */
    sc_basic_init(&b);
    b.idx[3] = 0; b.idx[4] = 0; b.idx[5] = 3;
    SC_FAIL(&b.desc, RAD_ERROR_DEGENERATE_TRIANGLE, "triangle 1", NULL);
    b.desc.flags = RAD_SCENE_SKIP_DEGENERATE;
    b.mesh.uvs = b.uv;
    CHECK_OK(rad_scene_create(&b.desc, &actx, &scene));
    if (scene) {
        CHECK(scene->triangle_count == 1);
        CHECK(scene->skipped_triangles == 1);
        rad_scene_destroy(scene);
        scene = NULL;
    }

    /* collinear: vertex 4 is the midpoint of edge 0-1 */
    sc_basic_init(&b);
    memcpy(pos, b.pos, sizeof(b.pos));
    pos[12] = 0.5f * (pos[0] + pos[3]);
    pos[13] = 0.5f * (pos[1] + pos[4]);
    pos[14] = 0.5f * (pos[2] + pos[5]);
    b.mesh.positions = pos;
    b.mesh.vertex_count = 5;
    b.mesh.indices = idx;
    b.mesh.triangle_count = 3;
    SC_FAIL(&b.desc, RAD_ERROR_DEGENERATE_TRIANGLE, "triangle 2", NULL);
    b.desc.flags = RAD_SCENE_SKIP_DEGENERATE;
    CHECK_OK(rad_scene_create(&b.desc, &actx, &scene));
    if (scene) {
        CHECK(scene->triangle_count == 2);
        CHECK(scene->skipped_triangles == 1);
        CHECK(scene->source_triangles[1] == 1);
        rad_scene_destroy(scene);
        scene = NULL;
    }

    /* every triangle degenerate and skipped: empty */
    sc_basic_init(&b);
    b.idx[1] = 0; b.idx[5] = 2;
    b.desc.flags = RAD_SCENE_SKIP_DEGENERATE;
    SC_FAIL(&b.desc, RAD_ERROR_EMPTY_SCENE, NULL, NULL);
    b.desc.flags = 0;
    SC_FAIL(&b.desc, RAD_ERROR_DEGENERATE_TRIANGLE, "triangle 0", NULL);

    /* the degenerate triangle first: the kept one moves to index 0 */
    sc_basic_init(&b);
    b.idx[0] = 0; b.idx[1] = 0; b.idx[2] = 2;
    b.desc.flags = RAD_SCENE_SKIP_DEGENERATE;
    CHECK_OK(rad_scene_create(&b.desc, &actx, &scene));
    if (scene) {
        CHECK(scene->triangle_count == 1);
        CHECK(scene->skipped_triangles == 1);
        CHECK(scene->source_triangles[0] == 1);
        CHECK_NEAR(scene->areas[0], 0.5, 1e-6);
        rad_scene_destroy(scene);
        scene = NULL;
    }
    CHECK(st.allocs == st.frees);
    CHECK(st.live_bytes == 0);
    /* a skipped triangle at the end of the input must not make rad_scene_create write past
       its arrays (sized for the kept triangles; caught by the allocator's canaries) */
    CHECK(st.corrupt == 0);
}

static void sc_test_validation_materials(void)
{
    sc_basic b;
    float nan = (float)NAN;

    sc_basic_init(&b);
    b.mat[0].albedo[1] = -0.1f;
    SC_FAIL(&b.desc, RAD_ERROR_ALBEDO_RANGE, "material 0", NULL);
    sc_basic_init(&b);
    b.desc.material_count = 2;
    b.mat[1].albedo[2] = 1.0f;
    SC_FAIL(&b.desc, RAD_ERROR_ALBEDO_RANGE, "material 1", NULL);
    sc_basic_init(&b);
    b.mat[0].albedo[0] = nan;
    SC_FAIL(&b.desc, RAD_ERROR_ALBEDO_RANGE, "material 0", NULL);

    sc_basic_init(&b);
    b.mat[0].emission[0] = -1.0f;
    SC_FAIL(&b.desc, RAD_ERROR_NEGATIVE_EMISSION, "material 0", NULL);
    sc_basic_init(&b);
    b.mat[0].emission[2] = nan;
    SC_FAIL(&b.desc, RAD_ERROR_NEGATIVE_EMISSION, "material 0", NULL);
    sc_basic_init(&b);
    b.mat[0].emission[2] = (float)INFINITY;
    SC_FAIL(&b.desc, RAD_ERROR_NEGATIVE_EMISSION, "material 0", NULL);

    /* material index out of range: per-mesh and per-triangle */
    sc_basic_init(&b);
    b.mesh.material = 1;
    SC_FAIL(&b.desc, RAD_ERROR_MATERIAL_OUT_OF_RANGE, "triangle 0", "material 1");
    sc_basic_init(&b);
    b.mat_ids[0] = 0; b.mat_ids[1] = 5;
    b.mesh.material_ids = b.mat_ids;
    SC_FAIL(&b.desc, RAD_ERROR_MATERIAL_OUT_OF_RANGE, "triangle 1", "material 5");

    /* textured material without a callback */
    sc_basic_init(&b);
    b.mat[0].texture = 3;
    b.mesh.uvs = b.uv;
    SC_FAIL(&b.desc, RAD_ERROR_INVALID_ARGUMENT, "material 0", NULL);
    /* textured material with a callback but the mesh has no uvs */
    b.mesh.uvs = NULL;
    b.desc.albedo_lookup = sc_dummy_albedo;
    SC_FAIL(&b.desc, RAD_ERROR_INVALID_ARGUMENT, "triangle 0", "uv");
    /* and with uvs it works, the albedo comes from the callback */
    {
        rad_scene *scene = NULL;
        float rgb[3];
        b.mesh.uvs = b.uv;
        CHECK_OK(rad_scene_create(&b.desc, NULL, &scene));
        if (scene) {
            rad_scene_albedo(scene, 0, 0.0f, 0.0f, rgb);
            CHECK_NEAR(rgb[1], 0.3f, 1e-6);
            rad_scene_destroy(scene);
        }
    }
}

static void sc_test_validation_arguments(void)
{
    sc_basic b;
    rad_scene *scene = NULL;
    rad_scene_desc empty;

    sc_basic_init(&b);
    CHECK_RESULT(rad_scene_create(NULL, NULL, &scene), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(scene == NULL);
    CHECK_RESULT(rad_scene_create(&b.desc, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);

    /* zero meshes */
    memset(&empty, 0, sizeof(empty));
    empty.materials = b.mat;
    empty.material_count = 1;
    SC_FAIL(&empty, RAD_ERROR_EMPTY_SCENE, NULL, NULL);
    /* meshes with zero triangles */
    b.mesh.triangle_count = 0;
    SC_FAIL(&b.desc, RAD_ERROR_EMPTY_SCENE, NULL, NULL);

    /* a position stride smaller than 12 bytes */
    sc_basic_init(&b);
    b.mesh.position_stride = 8;
    SC_FAIL(&b.desc, RAD_ERROR_INVALID_ARGUMENT, "stride", "quad");
    sc_basic_init(&b);
    b.mesh.normals = b.nrm;
    b.mesh.normal_stride = 4;
    SC_FAIL(&b.desc, RAD_ERROR_INVALID_ARGUMENT, "stride", NULL);

    /* NULL positions, NULL meshes with a count, NULL materials with a count */
    sc_basic_init(&b);
    b.mesh.positions = NULL;
    SC_FAIL(&b.desc, RAD_ERROR_INVALID_ARGUMENT, NULL, NULL);
    sc_basic_init(&b);
    b.desc.meshes = NULL;
    SC_FAIL(&b.desc, RAD_ERROR_INVALID_ARGUMENT, NULL, NULL);
    sc_basic_init(&b);
    b.desc.materials = NULL;
    SC_FAIL(&b.desc, RAD_ERROR_INVALID_ARGUMENT, NULL, NULL);
}

static void sc_test_result_strings(void)
{
    int a, c;
    const char *s[17];
    for (a = 0; a <= 16; ++a) {
        s[a] = rad_result_string((rad_result)(-a));
        CHECK(s[a] != NULL && s[a][0] != '\0');
    }
    for (a = 0; a <= 16; ++a)
        for (c = a + 1; c <= 16; ++c) CHECK(strcmp(s[a], s[c]) != 0);
    CHECK(strstr(rad_result_string((rad_result)-999), "UNKNOWN") || strstr(rad_result_string((rad_result)-999), "unknown"));
    for (a = 0; a <= 16; ++a) CHECK(strcmp(s[a], rad_result_string((rad_result)-999)) != 0);
    CHECK(strstr(rad_result_string(RAD_ERROR_NON_FINITE), "NON_FINITE") != NULL);
}

static void sc_test_strided(void)
{
    sc_basic b;
    float inter[4 * 8];
    rad_scene *s1 = NULL, *s2 = NULL;
    int i, k;
    sc_basic_init(&b);
    for (i = 0; i < 4; ++i) {
        for (k = 0; k < 8; ++k) inter[8 * i + k] = 1000.0f + (float)(8 * i + k); /* junk */
        for (k = 0; k < 3; ++k) inter[8 * i + 2 + k] = b.pos[3 * i + k];
    }
    CHECK_OK(rad_scene_create(&b.desc, NULL, &s1));
    b.mesh.positions = inter + 2;
    b.mesh.position_stride = 32;
    CHECK_OK(rad_scene_create(&b.desc, NULL, &s2));
    if (s1 && s2) {
        CHECK(s1->triangle_count == s2->triangle_count);
        CHECK(memcmp(s1->positions, s2->positions, sizeof(float) * 9 * s1->triangle_count) == 0);
        CHECK(memcmp(s1->normals, s2->normals, sizeof(float) * 3 * s1->triangle_count) == 0);
        CHECK(memcmp(s1->areas, s2->areas, sizeof(float) * s1->triangle_count) == 0);
        CHECK(s1->diagonal == s2->diagonal);
        CHECK_NEAR(s1->areas[0], 0.5, 1e-6);
        CHECK_NEAR(s1->normals[1], 1.0, 1e-6);
    }
    rad_scene_destroy(s1);
    rad_scene_destroy(s2);
}

/* ---- patches ------------------------------------------------------------------------------ */

static void sc_test_patch_counts_areas(void)
{
    /* one right triangle, legs 1, hypotenuse sqrt 2, and one 2 x 0.5 rectangle's triangles */
    float pos[] = { 0, 0, 0, 1, 0, 0, 0, 1, 0, /* tri 0 in xy plane, normal +z */
                    0, 0, 1, 2, 0, 1, 2, 0.5f, 1, 0, 0, 1, 2, 0.5f, 1, 0, 0.5f, 1 };
    rad_material mat = { { 0.5f, 0.5f, 0.5f }, { 0, 0, 0 }, 0, 0, 0, 0, 0.0f };
    rad_mesh_desc mesh;
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    rad_patches *P = NULL;
    rad_patch_options po;
    uint32_t t, i;
    float edges[] = { 0.25f, 0.3f, 1.0f, 2.0f };
    int e;
    memset(&mesh, 0, sizeof(mesh));
    mesh.positions = pos;
    mesh.vertex_count = 9;
    mesh.triangle_count = 3;
    memset(&desc, 0, sizeof(desc));
    desc.meshes = &mesh;
    desc.mesh_count = 1;
    desc.materials = &mat;
    desc.material_count = 1;
    CHECK_OK(rad_scene_create(&desc, NULL, &scene));
    if (!scene) return;
    for (e = 0; e < 4; ++e) {
        uint32_t expect_total = 0;
        rad_patch_options_default(&po);
        po.max_edge = edges[e];
        CHECK_OK(rad_patches_create(scene, &po, NULL, &P));
        if (!P) continue;
        CHECK(P->triangle_count == 3);
        for (t = 0; t < 3; ++t) {
            const float *v = scene->positions + 9 * t;
            double le = 0.0, sum = 0.0;
            uint32_t n, k;
            for (k = 0; k < 3; ++k) {
                const float *a = v + 3 * k, *b = v + 3 * ((k + 1) % 3);
                double d = sqrt((double)(a[0] - b[0]) * (a[0] - b[0]) + (double)(a[1] - b[1]) * (a[1] - b[1]) +
                                (double)(a[2] - b[2]) * (a[2] - b[2]));
                if (d > le) le = d;
            }
            n = (uint32_t)ceil(le / (double)edges[e] - 1e-6);
            if (n < 1) n = 1;
            CHECK(P->subdivision[t] == n);
            CHECK(P->first_patch[t] == expect_total);
            for (i = 0; i < n * n; ++i) {
                const rad_patch *p = &P->patches[P->first_patch[t] + i];
                CHECK(p->triangle == t);
                sum += p->area;
                CHECK_REL(p->area, scene->areas[t] / (double)(n * n), 1e-4);
                CHECK_NEAR(p->normal[0] * scene->normals[3 * t] + p->normal[1] * scene->normals[3 * t + 1] +
                               p->normal[2] * scene->normals[3 * t + 2], 1.0, 1e-5);
            }
            CHECK_REL(sum, scene->areas[t], 1e-5);
            expect_total += n * n;
        }
        CHECK(P->count == expect_total);
        for (i = 0; i < P->count; ++i) CHECK(P->areas[i] == P->patches[i].area);
        rad_patches_destroy(P);
        P = NULL;
    }
    /* max_area: the smallest n with area / n^2 <= max_area */
    rad_patch_options_default(&po);
    po.max_area = 0.01f;
    CHECK_OK(rad_patches_create(scene, &po, NULL, &P));
    if (P) {
        CHECK(P->subdivision[0] == 8); /* 0.5 / 64 = 0.0078 <= 0.01 < 0.5 / 49 */
        CHECK(P->subdivision[1] == 8); /* area 0.5: same */
        CHECK(P->subdivision[2] == 8);
        rad_patches_destroy(P);
        P = NULL;
    }
    /* bad options */
    rad_patch_options_default(&po);
    po.max_edge = -1.0f;
    CHECK_RESULT(rad_patches_create(scene, &po, NULL, &P), RAD_ERROR_INVALID_ARGUMENT);
    po.max_edge = (float)NAN;
    CHECK_RESULT(rad_patches_create(scene, &po, NULL, &P), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(P == NULL);
    rad_scene_destroy(scene);
}

static void sc_test_size_overflow(void)
{
    sc_basic b;
    rad_scene *scene = NULL;
    rad_patches *P = (rad_patches *)(void *)&b;
    rad_patch_options po;
    rad_context ctx;
    sc_alloc_state st;
    memset(&st, 0, sizeof(st));
    sc_ctx_alloc(&ctx, &st);
    sc_basic_init(&b);
    CHECK_OK(rad_scene_create(&b.desc, &ctx, &scene));
    if (!scene) return;
    rad_patch_options_default(&po);
    po.max_area = 1e-30f;
    CHECK_RESULT(rad_patches_create(scene, &po, &ctx, &P), RAD_ERROR_SIZE_OVERFLOW);
    CHECK(P == NULL);
    po.max_area = 0.0f;
    po.max_edge = 1e-20f;
    CHECK_RESULT(rad_patches_create(scene, &po, &ctx, &P), RAD_ERROR_SIZE_OVERFLOW);
    rad_scene_destroy(scene);
    CHECK(st.live_bytes == 0);
    CHECK(st.corrupt == 0);
    CHECK(st.allocs == st.frees);
}

static uint32_t sc_rng(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}
static float sc_rngf(uint32_t *s) { return (float)sc_rng(s) / 16777216.0f; }

static void sc_test_patch_locate(void)
{
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    rad_patches *P = NULL;
    rad_patch_options po;
    uint32_t seed = 12345u, it, t;
    float w[3];
    rad_cornell_box(&desc, NULL);
    CHECK_OK(rad_scene_create(&desc, NULL, &scene));
    if (!scene) return;
    rad_patch_options_default(&po);
    po.max_edge = 0.07f;
    CHECK_OK(rad_patches_create(scene, &po, NULL, &P));
    if (!P) { rad_scene_destroy(scene); return; }
    for (it = 0; it < 20000; ++it) {
        float b1 = sc_rngf(&seed), b2 = sc_rngf(&seed), x[3], y[3];
        const float *v;
        const rad_patch *p;
        uint32_t id;
        int k;
        t = sc_rng(&seed) % scene->triangle_count;
        if (it % 7 == 0) b1 = (float)(sc_rng(&seed) % 9) / 8.0f; /* lattice lines */
        if (b1 + b2 > 1.0f) { b1 = 1.0f - b1; b2 = 1.0f - b2; }
        v = scene->positions + 9 * t;
        for (k = 0; k < 3; ++k) x[k] = v[k] + b1 * (v[3 + k] - v[k]) + b2 * (v[6 + k] - v[k]);
        id = rad_patches_locate(P, t, b1, b2, w);
        CHECK(id < P->count);
        if (id >= P->count) continue;
        p = &P->patches[id];
        CHECK(p->triangle == t);
        CHECK_NEAR(w[0] + w[1] + w[2], 1.0, 1e-5);
        CHECK(w[0] >= -1e-5f && w[1] >= -1e-5f && w[2] >= -1e-5f);
        for (k = 0; k < 3; ++k)
            y[k] = w[0] * P->vertices[3 * p->vertices[0] + k] + w[1] * P->vertices[3 * p->vertices[1] + k] +
                   w[2] * P->vertices[3 * p->vertices[2] + k];
        for (k = 0; k < 3; ++k) CHECK_NEAR(y[k], x[k], 1e-5);
        if (rad_test_failures > 20) break;
    }
    CHECK(rad_patches_locate(P, scene->triangle_count, 0.1f, 0.1f, w) == RAD_NONE);
    rad_patches_destroy(P);
    rad_scene_destroy(scene);
}

/* two quads meeting at 90 degrees along the edge x = 0..1, y = 0, z = 0 */
static void sc_test_patch_welding(void)
{
    static const float c[3] = { 0, 0, 0 }, ux[3] = { 1, 0, 0 }, uy[3] = { 0, 1, 0 }, uz[3] = { 0, 0, 1 };
    float floor_pos[12], wall_pos[12];
    rad_material mat = { { 0.5f, 0.5f, 0.5f }, { 0, 0, 0 }, 0, 0, 0, 0, 0.0f };
    rad_mesh_desc meshes[2];
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    rad_patches *P = NULL;
    rad_patch_options po;
    uint32_t i, j, n = 4, shared_diag = 0, crease_pairs = 0, diag_bad = 0, crease_bad = 0;
    sc_quad(floor_pos, c, uz, ux); /* y = 0 plane, normal +y */
    sc_quad(wall_pos, c, ux, uy);  /* z = 0 plane, normal +z */
    memset(meshes, 0, sizeof(meshes));
    meshes[0].positions = floor_pos; meshes[0].vertex_count = 4; meshes[0].indices = sc_quad_idx; meshes[0].triangle_count = 2;
    meshes[1].positions = wall_pos; meshes[1].vertex_count = 4; meshes[1].indices = sc_quad_idx; meshes[1].triangle_count = 2;
    memset(&desc, 0, sizeof(desc));
    desc.meshes = meshes; desc.mesh_count = 2; desc.materials = &mat; desc.material_count = 1;
    CHECK_OK(rad_scene_create(&desc, NULL, &scene));
    if (!scene) return;
    CHECK_NEAR(scene->normals[1], 1.0, 1e-6);
    CHECK_NEAR(scene->normals[3 * 2 + 2], 1.0, 1e-6);
    rad_patch_options_default(&po);
    po.max_edge = 0.26f; /* the diagonal 1.41 gives n = 6 */
    CHECK_OK(rad_patches_create(scene, &po, NULL, &P));
    if (!P) { rad_scene_destroy(scene); return; }
    n = P->subdivision[0];
    CHECK(n == 6);
    /* the two planes: (n+1)^2 welded vertices each, no vertex shared between them */
    CHECK(P->vertex_count == 2 * (n + 1) * (n + 1));
    for (i = 0; i < P->count; ++i)
        for (j = 0; j < P->count; ++j) {
            const rad_patch *a = &P->patches[i], *b = &P->patches[j];
            int ka, kb;
            int same_plane = (a->triangle / 2) == (b->triangle / 2);
            if (a->triangle == b->triangle) continue;
            for (ka = 0; ka < 3; ++ka)
                for (kb = 0; kb < 3; ++kb) {
                    const float *pa = P->vertices + 3 * a->vertices[ka], *pb = P->vertices + 3 * b->vertices[kb];
                    int coincide = fabsf(pa[0] - pb[0]) < 1e-6f && fabsf(pa[1] - pb[1]) < 1e-6f && fabsf(pa[2] - pb[2]) < 1e-6f;
                    if (!coincide) continue;
                    if (same_plane) {
                        shared_diag++;
                        if (a->vertices[ka] != b->vertices[kb]) diag_bad++;
                    } else {
                        crease_pairs++;
                        if (a->vertices[ka] == b->vertices[kb]) crease_bad++;
                    }
                }
        }
    CHECK(shared_diag > 0);
    CHECK(diag_bad == 0);
    CHECK(crease_pairs > 0);
    CHECK(crease_bad == 0);
    rad_patches_destroy(P);
    rad_scene_destroy(scene);
}

static void sc_test_vertex_values(void)
{
    static const float c[3] = { 0, 0, 0 }, ux[3] = { 1, 0, 0 }, uz[3] = { 0, 0, 1 };
    float pos[12];
    rad_material mat = { { 0.5f, 0.5f, 0.5f }, { 0, 0, 0 }, 0, 0, 0, 0, 0.0f };
    rad_mesh_desc mesh;
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    rad_patches *P = NULL;
    rad_patch_options po;
    float *pv, *vv;
    uint32_t i;
    float edge = 0.05f;
    sc_quad(pos, c, uz, ux);
    memset(&mesh, 0, sizeof(mesh));
    mesh.positions = pos; mesh.vertex_count = 4; mesh.indices = sc_quad_idx; mesh.triangle_count = 2;
    memset(&desc, 0, sizeof(desc));
    desc.meshes = &mesh; desc.mesh_count = 1; desc.materials = &mat; desc.material_count = 1;
    CHECK_OK(rad_scene_create(&desc, NULL, &scene));
    if (!scene) return;
    rad_patch_options_default(&po);
    po.max_edge = edge;
    CHECK_OK(rad_patches_create(scene, &po, NULL, &P));
    if (!P) { rad_scene_destroy(scene); return; }
    pv = (float *)malloc(sizeof(float) * 2 * P->count);
    vv = (float *)malloc(sizeof(float) * 2 * P->vertex_count);
    if (pv && vv) {
        double worst = 0.0;
        for (i = 0; i < P->count; ++i) { pv[2 * i] = 3.25f; pv[2 * i + 1] = P->patches[i].centroid[0]; }
        CHECK_OK(rad_patches_vertex_values(P, pv, 2, vv));
        for (i = 0; i < P->vertex_count; ++i) {
            double d = fabs((double)vv[2 * i + 1] - (double)P->vertices[3 * i]);
            CHECK_NEAR(vv[2 * i], 3.25, 1e-6);
            if (d > worst) worst = d;
        }
        /* interior vertices are exact for a linear field up to the lattice; boundary ones are off
           by at most a patch size */
        CHECK(worst <= edge);
        CHECK(worst > 0.0);
        CHECK_RESULT(rad_patches_vertex_values(P, pv, 0, vv), RAD_ERROR_INVALID_ARGUMENT);
        CHECK_RESULT(rad_patches_vertex_values(P, NULL, 1, vv), RAD_ERROR_INVALID_ARGUMENT);
    }
    free(pv);
    free(vv);
    rad_patches_destroy(P);
    rad_scene_destroy(scene);
}

/* rad_patches_vertex_irradiance: on a floor whose patches with x < 0.3 see only 30% of their
   hemisphere (S = 0.3) and the others all of it (S = 1), each seeing radiosity 2 (H = 2 S), a
   vertex touching any uncovered patch gets 2 x 1 = 2 exactly, one inside the covered part
   2 x 0.3; the plain vertex average gives less than 2 on the border (the halo). */
static void sc_test_vertex_irradiance(void)
{
    static const float c[3] = { 0, 0, 0 }, ux[3] = { 1, 0, 0 }, uz[3] = { 0, 0, 1 };
    float pos[12];
    rad_material mat = { { 0.5f, 0.5f, 0.5f }, { 0, 0, 0 }, 0, 0, 0, 0, 0.0f };
    rad_mesh_desc mesh;
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    rad_patches *P = NULL;
    rad_patch_options po;
    float *H, *S, *hv, *plain, *smax;
    uint32_t i, k, border = 0, halo = 0;
    sc_quad(pos, c, uz, ux);
    memset(&mesh, 0, sizeof(mesh));
    mesh.positions = pos; mesh.vertex_count = 4; mesh.indices = sc_quad_idx; mesh.triangle_count = 2;
    memset(&desc, 0, sizeof(desc));
    desc.meshes = &mesh; desc.mesh_count = 1; desc.materials = &mat; desc.material_count = 1;
    CHECK_OK(rad_scene_create(&desc, NULL, &scene));
    if (!scene) return;
    rad_patch_options_default(&po);
    po.max_edge = 0.1f;
    CHECK_OK(rad_patches_create(scene, &po, NULL, &P));
    if (!P) { rad_scene_destroy(scene); return; }
    H = (float *)malloc(sizeof(float) * 3 * P->count);
    S = (float *)malloc(sizeof(float) * P->count);
    hv = (float *)malloc(sizeof(float) * 3 * P->vertex_count);
    plain = (float *)malloc(sizeof(float) * 3 * P->vertex_count);
    smax = (float *)calloc(P->vertex_count, sizeof(float));
    if (H && S && hv && plain && smax) {
        for (i = 0; i < P->count; ++i) {
            S[i] = P->patches[i].centroid[0] < 0.3f ? 0.3f : 1.0f;
            for (k = 0; k < 3; ++k) H[3 * i + k] = 2.0f * S[i] * (float)(k + 1);
            for (k = 0; k < 3; ++k)
                if (S[i] > smax[P->patches[i].vertices[k]]) smax[P->patches[i].vertices[k]] = S[i];
        }
        CHECK_OK(rad_patches_vertex_irradiance(P, H, S, hv, NULL));
        CHECK_OK(rad_patches_vertex_values(P, H, 3, plain));
        for (i = 0; i < P->vertex_count; ++i) {
            for (k = 0; k < 3; ++k) CHECK_REL(hv[3 * i + k], 2.0 * smax[i] * (k + 1), 1e-5);
            if (smax[i] == 1.0f && plain[3 * i] < 1.99f) halo++;
            border += smax[i] == 1.0f;
        }
        CHECK(halo > 0 && halo < border); /* the plain average does darken the border */
        /* no row sums: the plain average */
        CHECK_OK(rad_patches_vertex_irradiance(P, H, NULL, hv, NULL));
        CHECK(memcmp(hv, plain, sizeof(float) * 3 * P->vertex_count) == 0);
        CHECK_RESULT(rad_patches_vertex_irradiance(NULL, H, S, hv, NULL), RAD_ERROR_INVALID_ARGUMENT);
        CHECK_RESULT(rad_patches_vertex_irradiance(P, NULL, S, hv, NULL), RAD_ERROR_INVALID_ARGUMENT);
        CHECK_RESULT(rad_patches_vertex_irradiance(P, H, S, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
        S[P->count - 1] = -0.5f;
        CHECK_RESULT(rad_patches_vertex_irradiance(P, H, S, hv, NULL), RAD_ERROR_NON_FINITE);
        S[P->count - 1] = 1.0f;
        H[1] = (float)NAN;
        CHECK_RESULT(rad_patches_vertex_irradiance(P, H, S, hv, NULL), RAD_ERROR_NON_FINITE);
    }
    free(H); free(S); free(hv); free(plain); free(smax);
    rad_patches_destroy(P);
    rad_scene_destroy(scene);
}

/* rad_patches_gather_mesh: a field linear in position, given at the patch vertices, comes back
   at the Cornell box meshes' own vertices (shared corners, indexed meshes) to float rounding,
   and wrong descriptions are refused. */
static void sc_test_gather_mesh(void)
{
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    rad_patches *P = NULL;
    rad_patch_options po;
    rad_mesh_desc bad;
    uint32_t *idx = NULL;
    float *vv = NULL, *out = NULL;
    uint32_t i, m, k;
    double worst = 0.0;
    rad_cornell_box(&desc, NULL);
    CHECK_OK(rad_scene_create(&desc, NULL, &scene));
    if (!scene) return;
    rad_patch_options_default(&po);
    po.max_edge = 0.12f;
    CHECK_OK(rad_patches_create(scene, &po, NULL, &P));
    if (!P) { rad_scene_destroy(scene); return; }
    vv = (float *)malloc(sizeof(float) * 3 * P->vertex_count);
    out = (float *)malloc(sizeof(float) * 3 * 64);
    if (!vv || !out) goto done;
    for (i = 0; i < P->vertex_count; ++i)
        for (k = 0; k < 3; ++k) vv[3 * i + k] = 1.0f + P->vertices[3 * i] + 2.0f * P->vertices[3 * i + 1] + (float)k * P->vertices[3 * i + 2];
    for (m = 0; m < desc.mesh_count; ++m) {
        const rad_mesh_desc *md = &desc.meshes[m];
        if (md->vertex_count > 64) { CHECK(0 && "mesh too large for the test"); continue; }
        CHECK_OK(rad_patches_gather_mesh(P, vv, m, md, out, NULL));
        for (i = 0; i < md->vertex_count; ++i) {
            const float *q = (const float *)((const char *)md->positions + i * (md->position_stride ? md->position_stride : 12));
            for (k = 0; k < 3; ++k) {
                double want = 1.0 + q[0] + 2.0 * q[1] + (double)k * q[2], d = fabs(out[3 * i + k] - want);
                if (d > worst) worst = d;
            }
        }
    }
    printf("    largest error at the meshes' vertices %.3g\n", worst);
    CHECK(worst < 1e-5);
    CHECK_RESULT(rad_patches_gather_mesh(P, vv, desc.mesh_count, &desc.meshes[0], out, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_patches_gather_mesh(P, NULL, 0, &desc.meshes[0], out, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_patches_gather_mesh(P, vv, 0, NULL, out, NULL), RAD_ERROR_INVALID_ARGUMENT);
    /* a description with fewer triangles or an index past its vertices: another mesh */
    bad = desc.meshes[0];
    bad.triangle_count = 1;
    CHECK_RESULT(rad_patches_gather_mesh(P, vv, 0, &bad, out, NULL), RAD_ERROR_INDEX_OUT_OF_RANGE);
    bad = desc.meshes[0];
    idx = (uint32_t *)malloc(sizeof(uint32_t) * 3 * bad.triangle_count);
    if (idx) {
        for (i = 0; i < 3 * bad.triangle_count; ++i) idx[i] = bad.indices ? bad.indices[i] : i;
        idx[3 * bad.triangle_count - 1] = bad.vertex_count;
        bad.indices = idx;
        CHECK_RESULT(rad_patches_gather_mesh(P, vv, 0, &bad, out, NULL), RAD_ERROR_INDEX_OUT_OF_RANGE);
    }
done:
    free(idx);
    free(vv);
    free(out);
    rad_patches_destroy(P);
    rad_scene_destroy(scene);
}

/* ---- context hooks ------------------------------------------------------------------------ */

/* The whole pipeline on the Cornell box (one patch per triangle) with ctx. Returns the first
   failure code (or SUCCESS); every step's code must be SUCCESS or OUT_OF_MEMORY. Frees all. */
static rad_result sc_pipeline(const rad_context *ctx, int *bad_code)
{
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    rad_patches *P = NULL;
    rad_bvh *bvh = NULL;
    rad_form_factors *ffd = NULL, *ffs = NULL;
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_solve_options so;
    rad_direct_options dopt;
    rad_raycaster rc;
    rad_system sys;
    float *E = NULL, *B = NULL, *D = NULL;
    rad_result r, first = RAD_SUCCESS;
    rad_light sun;
#define SC_STEP(expr)                                                                 \
    do {                                                                              \
        r = (expr);                                                                   \
        if (r != RAD_SUCCESS && r != RAD_ERROR_OUT_OF_MEMORY && r != RAD_ERROR_NOT_CONVERGED) *bad_code = r; \
        if (r != RAD_SUCCESS && first == RAD_SUCCESS) first = r;                      \
    } while (0)
    rad_cornell_box(&desc, NULL);
    SC_STEP(rad_scene_create(&desc, ctx, &scene));
    if (!scene) goto done;
    rad_patch_options_default(&po);
    SC_STEP(rad_patches_create(scene, &po, ctx, &P));
    if (!P) goto done;
    SC_STEP(rad_bvh_create(scene, ctx, &bvh));
    if (!bvh) goto done;
    rad_bvh_raycaster(bvh, &rc);
    rad_form_factor_options_default(&fo);
    fo.samples = 4;
    SC_STEP(rad_form_factors_dense(P, &rc, &fo, ctx, &ffd));
    SC_STEP(rad_form_factors_sparse(P, &rc, &fo, ctx, &ffs));
    if (!ffd) goto done;
    E = (float *)malloc(sizeof(float) * 3 * P->count);
    B = (float *)malloc(sizeof(float) * 3 * P->count);
    D = (float *)malloc(sizeof(float) * 3 * P->count);
    if (!E || !B || !D) goto done;
    CHECK_OK(rad_sources(P, RAD_SOURCE_EMISSION, NULL, E));
    rad_system_init(&sys, &ffd->matrix, P, E);
    rad_solve_options_default(&so);
    so.bounces = 4;
    SC_STEP(rad_solve_jacobi(&sys, &so, B, NULL, ctx));
    SC_STEP(rad_solve_gauss_seidel(&sys, &so, B, NULL, ctx));
    SC_STEP(rad_solve_progressive(&sys, &so, B, NULL, ctx));
    SC_STEP(rad_solve_direct(&sys, &so, B, ctx));
    SC_STEP(rad_matrix_multiply(&ffd->matrix, E, B, ctx));
    if (ffs) {
        rad_system_init(&sys, &ffs->matrix, P, E);
        SC_STEP(rad_solve_jacobi(&sys, &so, B, NULL, ctx));
    }
    rad_direct_options_default(&dopt);
    dopt.samples = 2;
    dopt.light_samples = 2;
    memset(&sun, 0, sizeof(sun));
    sun.type = RAD_LIGHT_DIRECTIONAL;
    sun.color[0] = sun.color[1] = sun.color[2] = 1.0f;
    sun.direction[1] = -1.0f;
    SC_STEP(rad_direct_patches(P, &rc, &sun, 1, &dopt, D, ctx));
done:
    free(E);
    free(B);
    free(D);
    rad_form_factors_destroy(ffd);
    rad_form_factors_destroy(ffs);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(P);
    rad_scene_destroy(scene);
    return first;
#undef SC_STEP
}

static void sc_test_allocator_counting(void)
{
    rad_context ctx;
    sc_alloc_state st;
    int bad = 0;
    memset(&st, 0, sizeof(st));
    sc_ctx_alloc(&ctx, &st);
    CHECK_OK(sc_pipeline(&ctx, &bad));
    CHECK(bad == 0);
    CHECK(st.allocs > 20);
    CHECK(st.allocs == st.frees);
    CHECK(st.live_bytes == 0);
    CHECK(st.corrupt == 0);
    /* an allocator with only one of the two callbacks is ignored (defaults are used) */
    {
        rad_context half;
        rad_scene_desc desc;
        rad_scene *scene = NULL;
        sc_alloc_state st2;
        memset(&st2, 0, sizeof(st2));
        sc_ctx_alloc(&half, &st2);
        half.allocator.free = NULL;
        rad_cornell_box(&desc, NULL);
        CHECK_OK(rad_scene_create(&desc, &half, &scene));
        CHECK(st2.allocs == 0);
        rad_scene_destroy(scene);
    }
}

static void sc_test_allocator_failures(void)
{
    rad_context ctx;
    sc_alloc_state st;
    long total, n, step;
    int bad = 0, oom_seen = 0;
    memset(&st, 0, sizeof(st));
    sc_ctx_alloc(&ctx, &st);
    ctx.parallel_for = fx_serial_for; /* deterministic allocation order */
    ctx.task_count = 4;
    CHECK_OK(sc_pipeline(&ctx, &bad));
    total = st.allocs;
    CHECK(total > 20);
    step = 1;
    for (n = 1; n <= total + 1; n += step) {
        rad_result r;
        memset(&st, 0, sizeof(st));
        st.fail_at = n;
        bad = 0;
        r = sc_pipeline(&ctx, &bad);
        if (bad) { printf("    fail_at %ld: a step returned %s\n", n, rad_result_string((rad_result)bad)); CHECK(0); }
        if (n <= total) {
            CHECK(st.failed == 1);
            CHECK_RESULT(r, RAD_ERROR_OUT_OF_MEMORY);
            if (r == RAD_ERROR_OUT_OF_MEMORY) oom_seen++;
        } else {
            CHECK_OK(r);
        }
        if (st.allocs != st.frees || st.live_bytes != 0) {
            printf("    fail_at %ld: %ld allocs, %ld frees, %lld live bytes\n", n, st.allocs, st.frees, st.live_bytes);
            CHECK(0);
        }
        if (rad_test_failures > 10) break;
    }
    CHECK(oom_seen > 0);
}

typedef struct sc_progress_state {
    int calls, cancel_at, bad_order, out_of_range;
    float last;
} sc_progress_state;

static int sc_progress_fn(void *user, float fraction)
{
    sc_progress_state *s = (sc_progress_state *)user;
    s->calls++;
    if (!(fraction >= 0.0f && fraction <= 1.0f)) s->out_of_range++;
    if (s->calls > 1 && fraction < s->last) s->bad_order++;
    s->last = fraction;
    return s->cancel_at > 0 && s->calls >= s->cancel_at;
}

static void sc_test_progress_cancel(void)
{
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    rad_patches *P = NULL;
    rad_bvh *bvh = NULL;
    rad_form_factors *ff = NULL;
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_raycaster rc;
    rad_context ctx;
    sc_alloc_state st;
    sc_progress_state ps;
    memset(&st, 0, sizeof(st));
    sc_ctx_alloc(&ctx, &st);
    rad_cornell_box(&desc, NULL);
    CHECK_OK(rad_scene_create(&desc, &ctx, &scene));
    if (!scene) return;
    rad_patch_options_default(&po);
    po.target_count = 300;
    CHECK_OK(rad_patches_create(scene, &po, &ctx, &P));
    CHECK_OK(rad_bvh_create(scene, &ctx, &bvh));
    if (!P || !bvh) goto done;
    rad_bvh_raycaster(bvh, &rc);
    rad_form_factor_options_default(&fo);
    fo.samples = 4;
    memset(&ps, 0, sizeof(ps));
    ctx.task_count = 8; /* progress comes between batches of 4 * task_count rows */
    ctx.progress = sc_progress_fn;
    ctx.progress_user = &ps;
    CHECK_OK(rad_form_factors_dense(P, &rc, &fo, &ctx, &ff));
    CHECK(ps.calls >= 2);
    CHECK(ps.bad_order == 0);
    CHECK(ps.out_of_range == 0);
    CHECK(ps.last == 1.0f);
    rad_form_factors_destroy(ff);
    ff = NULL;
    /* cancel at the first call */
    memset(&ps, 0, sizeof(ps));
    ps.cancel_at = 1;
    ff = (rad_form_factors *)(void *)&ps;
    CHECK_RESULT(rad_form_factors_dense(P, &rc, &fo, &ctx, &ff), RAD_ERROR_CANCELLED);
    CHECK(ff == NULL);
    CHECK(ps.calls == 1);
    /* and the sparse build */
    memset(&ps, 0, sizeof(ps));
    ps.cancel_at = 1;
    CHECK_RESULT(rad_form_factors_sparse(P, &rc, &fo, &ctx, &ff), RAD_ERROR_CANCELLED);
    CHECK(ff == NULL);
done:
    rad_form_factors_destroy(ff);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(P);
    rad_scene_destroy(scene);
    CHECK(st.allocs == st.frees);
    CHECK(st.live_bytes == 0);
    CHECK(st.corrupt == 0);
}

/* ---- the built-in Cornell box --------------------------------------------------------------- */

static void sc_test_cornell(void)
{
    static const char *names[8] = { "floor", "ceiling", "back", "green", "red", "light", "shortblock", "tallblock" };
    rad_scene_desc desc;
    rad_camera cam;
    rad_scene *scene = NULL;
    rad_ray ray;
    uint32_t m, total = 0, t;
    int k;
    rad_cornell_box(&desc, &cam);
    rad_cornell_box(NULL, NULL); /* either output may be NULL */
    CHECK(desc.mesh_count == 8);
    CHECK(desc.material_count == 4);
    CHECK(desc.albedo_lookup == NULL);
    for (m = 0; m < desc.mesh_count && m < 8; ++m) {
        CHECK(desc.meshes[m].name && strcmp(desc.meshes[m].name, names[m]) == 0);
        total += desc.meshes[m].triangle_count;
    }
    CHECK(total == 32);
    CHECK_NEAR(desc.materials[0].albedo[0], 0.725, 1e-7); CHECK_NEAR(desc.materials[0].albedo[1], 0.71, 1e-7);
    CHECK_NEAR(desc.materials[0].albedo[2], 0.68, 1e-7);
    CHECK_NEAR(desc.materials[1].albedo[0], 0.63, 1e-7); CHECK_NEAR(desc.materials[1].albedo[1], 0.065, 1e-7);
    CHECK_NEAR(desc.materials[1].albedo[2], 0.05, 1e-7);
    CHECK_NEAR(desc.materials[2].albedo[0], 0.14, 1e-7); CHECK_NEAR(desc.materials[2].albedo[1], 0.45, 1e-7);
    CHECK_NEAR(desc.materials[2].albedo[2], 0.091, 1e-7);
    for (k = 0; k < 3; ++k) {
        CHECK_NEAR(desc.materials[3].albedo[k], 0.78, 1e-7);
        CHECK(desc.materials[0].emission[k] == 0.0f && desc.materials[1].emission[k] == 0.0f &&
              desc.materials[2].emission[k] == 0.0f);
    }
    CHECK(desc.materials[3].emission[0] == 17.0f && desc.materials[3].emission[1] == 12.0f &&
          desc.materials[3].emission[2] == 4.0f);
    /* materials by mesh */
    CHECK(desc.meshes[0].material == 0 && desc.meshes[3].material == 2 && desc.meshes[4].material == 1 &&
          desc.meshes[5].material == 3 && desc.meshes[7].material == 0);
    /* camera */
    CHECK_NEAR(cam.position[0], 0.278, 1e-6); CHECK_NEAR(cam.position[1], 0.273, 1e-6);
    CHECK_NEAR(cam.position[2], -0.8, 1e-6);
    CHECK_NEAR(cam.fov_y_degrees, 39.3077, 1e-4);
    CHECK(cam.target[2] > cam.position[2]);
    CHECK_NEAR(cam.up[1], 1.0, 1e-6);
    rad_camera_ray(&cam, 64, 48, 32.0f, 24.0f, &ray);
    CHECK_NEAR(ray.dir[0], 0.0, 1e-5); CHECK_NEAR(ray.dir[1], 0.0, 1e-5); CHECK_NEAR(ray.dir[2], 1.0, 1e-5);
    CHECK_NEAR(ray.origin[0], 0.278, 1e-6); CHECK_NEAR(ray.origin[2], -0.8, 1e-6);
    CHECK(ray.tmin == 0.0f && ray.tmax > 1e6f);
    rad_camera_ray(&cam, 64, 48, 0.5f, 24.0f, &ray);
    CHECK(ray.dir[0] > 0.1f); /* +x (the red wall) is image left */
    CHECK_NEAR(ray.dir[0] * ray.dir[0] + ray.dir[1] * ray.dir[1] + ray.dir[2] * ray.dir[2], 1.0, 1e-5);
    rad_camera_ray(&cam, 64, 48, 32.0f, 0.5f, &ray);
    CHECK(ray.dir[1] > 0.1f); /* py down: the top row looks up */
    /* vertical fov: the top edge ray is fov/2 above the axis */
    rad_camera_ray(&cam, 64, 48, 32.0f, 0.0f, &ray);
    CHECK_NEAR(atan2(ray.dir[1], ray.dir[2]) * 180.0 / 3.14159265358979, 39.3077 / 2.0, 1e-3);

    CHECK_OK(rad_scene_create(&desc, NULL, &scene));
    if (!scene) return;
    CHECK(scene->triangle_count == 32);
    CHECK(scene->mesh_count == 8);
    CHECK_NEAR(scene->diagonal, 0.9607, 2e-3);
    for (m = 0; m < 8; ++m) CHECK(strcmp(scene->mesh_names[m], names[m]) == 0);
    for (t = 0; t < scene->triangle_count; ++t) {
        const float *nn = scene->normals + 3 * t, *v = scene->positions + 9 * t;
        const char *name = scene->mesh_names[scene->meshes[t]];
        float cen[3], to[3];
        for (k = 0; k < 3; ++k) { cen[k] = (v[k] + v[3 + k] + v[6 + k]) / 3.0f; to[k] = 0.278f - cen[k]; }
        if (!strcmp(name, "floor")) CHECK(nn[1] > 0.99f);
        if (!strcmp(name, "ceiling") || !strcmp(name, "light")) CHECK(nn[1] < -0.99f);
        if (!strcmp(name, "back")) CHECK(nn[2] < -0.99f);
        if (!strcmp(name, "green")) CHECK(nn[0] > 0.99f);
        if (!strcmp(name, "red")) CHECK(nn[0] < -0.99f);
        if (!strcmp(name, "light")) CHECK(v[1] < 0.5488f && v[1] > 0.548f);
        /* walls face the box's interior */
        if (strcmp(name, "shortblock") && strcmp(name, "tallblock")) {
            to[1] = 0.274f - cen[1];
            CHECK(nn[0] * to[0] + nn[1] * to[1] + nn[2] * to[2] > 0.0f);
        }
    }
    rad_scene_destroy(scene);
}

static const rad_test_case tests_scene[] = {
    { "scene_validation_indices_finite", sc_test_validation_indices_finite },
    { "scene_validation_degenerate", sc_test_validation_degenerate },
    { "scene_validation_materials", sc_test_validation_materials },
    { "scene_validation_arguments", sc_test_validation_arguments },
    { "scene_result_strings", sc_test_result_strings },
    { "scene_strided", sc_test_strided },
    { "scene_patch_counts_areas", sc_test_patch_counts_areas },
    { "scene_size_overflow", sc_test_size_overflow },
    { "scene_patch_locate", sc_test_patch_locate },
    { "scene_patch_welding", sc_test_patch_welding },
    { "scene_vertex_values", sc_test_vertex_values },
    { "scene_vertex_irradiance", sc_test_vertex_irradiance },
    { "scene_gather_mesh", sc_test_gather_mesh },
    { "scene_allocator_counting", sc_test_allocator_counting },
    { "scene_allocator_failures", sc_test_allocator_failures },
    { "scene_progress_cancel", sc_test_progress_cancel },
    { "scene_cornell", sc_test_cornell },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_scene)
