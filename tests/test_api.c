/* test_api.c - argument checking over the whole public API: every public
   function with NULL pointers, zero sizes, out-of-range indices and bad option values returns
   the documented error without crashing and without writing outputs it should not. Functions
   returning void / float / uint32 / pointers must not crash on NULL and return their neutral
   value. Organised as tables of small named cases; a failing case prints its name.
   Everything static and prefixed api_. */
#include "fixtures.h"


/* A call that once crashed (a NULL dereference in the library, since fixed) is made through
   API_CRASHER so it stands out in the source. */
#define API_CRASHER(desc, stmt) do { stmt; } while (0)

static int api_sentinel_obj;
#define API_SENTINEL(type) ((type *)(void *)&api_sentinel_obj)
#define API_FILL 12345.0f

/* shared objects: the Cornell box at one patch per triangle, everything built from it */
typedef struct api_fx {
    rad_scene_desc desc;
    rad_scene *scene;
    rad_patches *P;
    rad_bvh *bvh;
    rad_raycaster rc;
    rad_form_factors *ffd, *ffs;
    float *E, *B, *buf, *buf2;
    size_t buf_len;          /* floats in buf and buf2: max(3N, N*N, 3 * vertex_count) */
    uint32_t n;
    void *bytes;
    size_t size;
    rad_bake *bake;
    rad_container *ct;
    rad_system sys;
} api_fx;

static api_fx api_f;

/* the fixture is built serially: the OpenMP default pays a parallel region per LU column */
static int api_fx_build(api_fx *f)
{
    rad_form_factor_options fo;
    rad_solve_options so;
    rad_context serial;
    memset(&serial, 0, sizeof(serial));
    serial.parallel_for = fx_serial_for;
    memset(f, 0, sizeof(*f));
    rad_cornell_box(&f->desc, NULL);
    if (rad_scene_create(&f->desc, NULL, &f->scene) != RAD_SUCCESS) return 0;
    if (rad_patches_create(f->scene, NULL, NULL, &f->P) != RAD_SUCCESS) return 0;
    if (rad_bvh_create(f->scene, NULL, &f->bvh) != RAD_SUCCESS) return 0;
    rad_bvh_raycaster(f->bvh, &f->rc);
    f->n = f->P->count;
    rad_form_factor_options_default(&fo);
    fo.samples = 4;
    if (rad_form_factors_dense(f->P, &f->rc, &fo, &serial, &f->ffd) != RAD_SUCCESS) return 0;
    if (rad_form_factors_sparse(f->P, &f->rc, &fo, &serial, &f->ffs) != RAD_SUCCESS) return 0;
    f->buf_len = (size_t)f->n * f->n;
    if (f->buf_len < 3 * (size_t)f->n) f->buf_len = 3 * (size_t)f->n;
    if (f->buf_len < 3 * (size_t)f->P->vertex_count) f->buf_len = 3 * (size_t)f->P->vertex_count;
    f->E = (float *)malloc(sizeof(float) * 3 * f->n);
    f->B = (float *)malloc(sizeof(float) * 3 * f->n);
    f->buf = (float *)malloc(sizeof(float) * f->buf_len);
    f->buf2 = (float *)malloc(sizeof(float) * f->buf_len);
    if (!f->E || !f->B || !f->buf || !f->buf2) return 0;
    if (rad_sources(f->P, RAD_SOURCE_EMISSION, NULL, f->E) != RAD_SUCCESS) return 0;
    rad_system_init(&f->sys, &f->ffd->matrix, f->P, f->E);
    rad_solve_options_default(&so);
    so.output = RAD_OUTPUT_TOTAL;
    if (rad_solve_direct(&f->sys, &so, f->B, &serial) != RAD_SUCCESS) return 0;
    if (rad_save_memory(f->P, &f->ffs->matrix, f->E, f->B, NULL, &f->bytes, &f->size) != RAD_SUCCESS) return 0;
    if (rad_load_memory(f->bytes, f->size, NULL, &f->bake) != RAD_SUCCESS) return 0;
    if (rad_container_create(f->bytes, f->size, NULL, &f->ct) != RAD_SUCCESS) return 0;
    return 1;
}

static void api_fx_free(api_fx *f)
{
    rad_container_destroy(f->ct);
    rad_bake_destroy(f->bake);
    rad_free_buffer(f->bytes, NULL);
    free(f->E); free(f->B); free(f->buf); free(f->buf2);
    rad_form_factors_destroy(f->ffd);
    rad_form_factors_destroy(f->ffs);
    rad_bvh_destroy(f->bvh);
    rad_patches_destroy(f->P);
    rad_scene_destroy(f->scene);
    memset(f, 0, sizeof(*f));
}

static void api_fill(float *p, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i) p[i] = API_FILL;
}

/* 1 when the first n floats are all still API_FILL */
static int api_untouched(const float *p, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i) if (p[i] != API_FILL) return 0;
    return 1;
}

typedef struct api_case { const char *name; void (*fn)(api_fx *f); } api_case;

static void api_run_cases(const api_case *cases)
{
    const api_case *c;
    if (!api_fx_build(&api_f)) { CHECK(0 && "api fixture"); api_fx_free(&api_f); return; }
    for (c = cases; c->name; ++c) {
        int before = rad_test_failures;
        c->fn(&api_f);
        if (rad_test_failures != before) printf("    ^ in case '%s'\n", c->name);
    }
    api_fx_free(&api_f);
}

/* ---- core -------------------------------------------------------------------------------- */

static void api_result_string(api_fx *f)
{
    int r;
    (void)f;
    for (r = -40; r <= 5; ++r) {
        const char *s = rad_result_string((rad_result)r);
        CHECK(s != NULL && s[0] != '\0');
    }
    CHECK(strstr(rad_result_string(RAD_ERROR_SIZE_MISMATCH), "SIZE_MISMATCH") != NULL);
    CHECK(rad_result_string((rad_result)-1000) != NULL);
    CHECK(rad_result_string((rad_result)1000) != NULL);
}

static void api_defaults_null(api_fx *f)
{
    (void)f;
    rad_patch_options_default(NULL);
    rad_form_factor_options_default(NULL);
    rad_solve_options_default(NULL);
    rad_direct_options_default(NULL);
    rad_cornell_box(NULL, NULL);
    rad_system_init(NULL, NULL, NULL, NULL);
    rad_bvh_raycaster(NULL, NULL);
    rad_embree_raycaster(NULL, NULL);
    rad_camera_ray(NULL, 1, 1, 0.5f, 0.5f, NULL);
    rad_free_buffer(NULL, NULL);
    CHECK(1);
}

static void api_destroy_null(api_fx *f)
{
    (void)f;
    rad_scene_destroy(NULL);
    rad_patches_destroy(NULL);
    rad_bvh_destroy(NULL);
    rad_embree_destroy(NULL);
    rad_form_factors_destroy(NULL);
    rad_container_destroy(NULL);
    rad_bake_destroy(NULL);
    CHECK(1);
}

static void api_system_init(api_fx *f)
{
    rad_system s;
    memset(&s, 0xAB, sizeof(s));
    rad_system_init(&s, NULL, NULL, NULL);
    CHECK(s.F == NULL && s.albedo == NULL && s.E == NULL && s.areas == NULL && s.n == 0);
    rad_system_init(&s, &f->ffd->matrix, NULL, f->E);
    CHECK(s.n == f->n && s.albedo == NULL && s.E == f->E);
    rad_system_init(&s, NULL, f->P, NULL);
    CHECK(s.n == f->n && s.albedo == f->P->albedo && s.areas == f->P->areas);
}

static const api_case api_cases_core[] = {
    { "rad_result_string any value", api_result_string },
    { "option defaults and init with NULL", api_defaults_null },
    { "destroy functions accept NULL", api_destroy_null },
    { "rad_system_init partial", api_system_init },
    { NULL, NULL }
};

/* ---- scene ------------------------------------------------------------------------------- */

/* one quad (2 triangles) mesh and one material, editable per case */
typedef struct api_quad {
    float pos[12];
    float nrm[12];
    float uv[8];
    uint32_t idx[6];
    uint32_t mat_ids[2];
    rad_mesh_desc mesh;
    rad_material mat;
    rad_scene_desc desc;
} api_quad;

static void api_quad_init(api_quad *q)
{
    static const float p[12] = { 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0 };
    static const uint32_t id[6] = { 0, 1, 2, 0, 2, 3 };
    int k;
    memset(q, 0, sizeof(*q));
    memcpy(q->pos, p, sizeof(p));
    memcpy(q->idx, id, sizeof(id));
    for (k = 0; k < 4; ++k) { q->nrm[3 * k + 2] = 1.0f; q->uv[2 * k] = p[3 * k]; q->uv[2 * k + 1] = p[3 * k + 1]; }
    q->mesh.name = "quad";
    q->mesh.positions = q->pos;
    q->mesh.vertex_count = 4;
    q->mesh.indices = q->idx;
    q->mesh.triangle_count = 2;
    q->mat.albedo[0] = q->mat.albedo[1] = q->mat.albedo[2] = 0.5f;
    q->desc.meshes = &q->mesh;
    q->desc.mesh_count = 1;
    q->desc.materials = &q->mat;
    q->desc.material_count = 1;
}

/* scene_create on q must fail with 'expected' and set *out = NULL */
static void api_scene_expect(const api_quad *q, rad_result expected, const char *what)
{
    rad_scene *s = API_SENTINEL(rad_scene);
    rad_result r = rad_scene_create(&q->desc, NULL, &s);
    if (r != expected) printf("    scene case '%s': got %s, expected %s\n", what, rad_result_string(r), rad_result_string(expected));
    CHECK(r == expected);
    if (expected != RAD_SUCCESS) CHECK(s == NULL);
    if (r == RAD_SUCCESS && s != API_SENTINEL(rad_scene)) rad_scene_destroy(s);
}

static void api_scene_create_args(api_fx *f)
{
    rad_scene *s = API_SENTINEL(rad_scene);
    api_quad q;
    CHECK_RESULT(rad_scene_create(&f->desc, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_scene_create(NULL, NULL, &s), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(s == NULL);
    api_quad_init(&q);
    api_scene_expect(&q, RAD_SUCCESS, "valid quad");
    api_quad_init(&q); q.desc.meshes = NULL; api_scene_expect(&q, RAD_ERROR_INVALID_ARGUMENT, "meshes NULL, mesh_count 1");
    api_quad_init(&q); q.desc.mesh_count = 0; api_scene_expect(&q, RAD_ERROR_EMPTY_SCENE, "mesh_count 0");
    api_quad_init(&q); q.mesh.triangle_count = 0; api_scene_expect(&q, RAD_ERROR_EMPTY_SCENE, "triangle_count 0");
    api_quad_init(&q); q.desc.materials = NULL; api_scene_expect(&q, RAD_ERROR_INVALID_ARGUMENT, "materials NULL, material_count 1");
    api_quad_init(&q); q.desc.material_count = 0; q.desc.materials = NULL;
    api_scene_expect(&q, RAD_ERROR_MATERIAL_OUT_OF_RANGE, "no materials");
    api_quad_init(&q); q.mesh.positions = NULL; api_scene_expect(&q, RAD_ERROR_INVALID_ARGUMENT, "positions NULL");
    api_quad_init(&q); q.mesh.position_stride = 8; api_scene_expect(&q, RAD_ERROR_INVALID_ARGUMENT, "position_stride 8");
    api_quad_init(&q); q.mesh.normals = q.nrm; q.mesh.normal_stride = 4;
    api_scene_expect(&q, RAD_ERROR_INVALID_ARGUMENT, "normal_stride 4");
    api_quad_init(&q); q.mesh.uvs = q.uv; q.mesh.uv_stride = 4; api_scene_expect(&q, RAD_ERROR_INVALID_ARGUMENT, "uv_stride 4");
    api_quad_init(&q); q.idx[4] = 4; api_scene_expect(&q, RAD_ERROR_INDEX_OUT_OF_RANGE, "index == vertex_count");
    api_quad_init(&q); q.idx[0] = 0xFFFFFFFFu; api_scene_expect(&q, RAD_ERROR_INDEX_OUT_OF_RANGE, "index 2^32-1");
    api_quad_init(&q); q.mesh.indices = NULL; api_scene_expect(&q, RAD_ERROR_INDEX_OUT_OF_RANGE, "no indices, too few vertices");
    api_quad_init(&q); q.mesh.vertex_count = 0; api_scene_expect(&q, RAD_ERROR_INDEX_OUT_OF_RANGE, "vertex_count 0");
    api_quad_init(&q); q.mesh.material = 1; api_scene_expect(&q, RAD_ERROR_MATERIAL_OUT_OF_RANGE, "mesh material 1 of 1");
    api_quad_init(&q); q.mesh.material_ids = q.mat_ids; q.mat_ids[1] = 7;
    api_scene_expect(&q, RAD_ERROR_MATERIAL_OUT_OF_RANGE, "material_ids 7");
    api_quad_init(&q); q.mat.albedo[1] = 1.0f; api_scene_expect(&q, RAD_ERROR_ALBEDO_RANGE, "albedo 1");
    api_quad_init(&q); q.mat.albedo[2] = -0.01f; api_scene_expect(&q, RAD_ERROR_ALBEDO_RANGE, "albedo -0.01");
    api_quad_init(&q); q.mat.albedo[0] = (float)NAN; api_scene_expect(&q, RAD_ERROR_ALBEDO_RANGE, "albedo NaN");
    api_quad_init(&q); q.mat.emission[0] = -1.0f; api_scene_expect(&q, RAD_ERROR_NEGATIVE_EMISSION, "emission -1");
    api_quad_init(&q); q.mat.emission[1] = (float)INFINITY; api_scene_expect(&q, RAD_ERROR_NEGATIVE_EMISSION, "emission inf");
    api_quad_init(&q); q.mat.emission[2] = (float)NAN; api_scene_expect(&q, RAD_ERROR_NEGATIVE_EMISSION, "emission NaN");
    api_quad_init(&q); q.pos[4] = (float)NAN; api_scene_expect(&q, RAD_ERROR_NON_FINITE, "position NaN");
    api_quad_init(&q); q.pos[6] = (float)-INFINITY; api_scene_expect(&q, RAD_ERROR_NON_FINITE, "position -inf");
    api_quad_init(&q); q.mesh.normals = q.nrm; q.nrm[5] = (float)INFINITY; api_scene_expect(&q, RAD_ERROR_NON_FINITE, "normal inf");
    api_quad_init(&q); q.mesh.uvs = q.uv; q.uv[3] = (float)NAN; api_scene_expect(&q, RAD_ERROR_NON_FINITE, "uv NaN");
    api_quad_init(&q); q.idx[2] = 1; api_scene_expect(&q, RAD_ERROR_DEGENERATE_TRIANGLE, "repeated vertex");
    api_quad_init(&q); q.pos[3] = 0.5f; q.pos[4] = 0.5f; q.pos[6] = 1.0f; q.pos[7] = 1.0f; q.idx[5] = 2;
    api_scene_expect(&q, RAD_ERROR_DEGENERATE_TRIANGLE, "collinear vertices");
    api_quad_init(&q); q.idx[2] = 1; q.idx[5] = 2; q.idx[4] = 2; q.desc.flags = RAD_SCENE_SKIP_DEGENERATE;
    api_scene_expect(&q, RAD_ERROR_EMPTY_SCENE, "all degenerate, skipped");
    api_quad_init(&q); q.mat.texture = 3; api_scene_expect(&q, RAD_ERROR_INVALID_ARGUMENT, "texture without albedo_lookup");
}

static void api_scene_queries(api_fx *f)
{
    float rgb[3] = { 7, 7, 7 };
    rad_camera cam;
    rad_ray ray;
    uint32_t i;
    rad_scene_albedo(NULL, 0, 0.2f, 0.2f, rgb);
    CHECK(rgb[0] == 0.0f && rgb[1] == 0.0f && rgb[2] == 0.0f);
    rgb[0] = 7;
    rad_scene_albedo(f->scene, f->scene->triangle_count, 0.2f, 0.2f, rgb);
    CHECK(rgb[0] == 0.0f);
    rad_scene_albedo(f->scene, RAD_NONE, 0.2f, 0.2f, rgb);
    CHECK(rgb[0] == 0.0f);
    rad_scene_albedo(f->scene, 0, (float)NAN, (float)NAN, rgb); /* untextured: the material */
    CHECK(rgb[0] == f->scene->materials_table[f->scene->materials[0]].albedo[0]);
    API_CRASHER("rad_scene_albedo(scene, 0, 0.2, 0.2, out_rgb = NULL)", rad_scene_albedo(f->scene, 0, 0.2f, 0.2f, NULL));
    /* camera rays: NULL camera or zero image size give a zeroed ray */
    memset(&ray, 0xAB, sizeof(ray));
    rad_camera_ray(NULL, 64, 64, 1.0f, 1.0f, &ray);
    CHECK(ray.dir[0] == 0.0f && ray.dir[1] == 0.0f && ray.dir[2] == 0.0f && ray.tmax == 0.0f);
    rad_cornell_box(NULL, &cam);
    memset(&ray, 0xAB, sizeof(ray));
    rad_camera_ray(&cam, 0, 64, 1.0f, 1.0f, &ray);
    CHECK(ray.dir[0] == 0.0f && ray.dir[1] == 0.0f && ray.dir[2] == 0.0f);
    memset(&ray, 0xAB, sizeof(ray));
    rad_camera_ray(&cam, 64, 0, 1.0f, 1.0f, &ray);
    CHECK(ray.dir[0] == 0.0f && ray.dir[1] == 0.0f && ray.dir[2] == 0.0f);
    rad_camera_ray(&cam, 64, 64, 32.0f, 32.0f, &ray);
    CHECK(ray.tmin == 0.0f && ray.tmax > 1e30f && fabs(ray.dir[2] - 1.0) < 1e-3);
    /* a camera at its target or with up along the view: no NaN */
    cam.target[0] = cam.position[0]; cam.target[1] = cam.position[1]; cam.target[2] = cam.position[2];
    rad_camera_ray(&cam, 64, 64, 3.0f, 5.0f, &ray);
    for (i = 0; i < 3; ++i) CHECK(ray.dir[i] == ray.dir[i] && ray.origin[i] == ray.origin[i]);
    rad_cornell_box(NULL, &cam);
    cam.up[0] = 0.0f; cam.up[1] = 0.0f; cam.up[2] = 1.0f;
    rad_camera_ray(&cam, 64, 64, 3.0f, 5.0f, &ray);
    for (i = 0; i < 3; ++i) CHECK(ray.dir[i] == ray.dir[i]);
}

static const api_case api_cases_scene[] = {
    { "rad_scene_create arguments and validation", api_scene_create_args },
    { "rad_scene_albedo, rad_camera_ray", api_scene_queries },
    { NULL, NULL }
};

/* ---- patches and BVH --------------------------------------------------------------------- */

static void api_patches_create_args(api_fx *f)
{
    rad_patches *P = API_SENTINEL(rad_patches);
    rad_patch_options o;
    const float bad[] = { -1.0f, (float)NAN, (float)INFINITY, -(float)INFINITY };
    uint32_t i;
    CHECK_RESULT(rad_patches_create(f->scene, NULL, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_patches_create(NULL, NULL, NULL, &P), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(P == NULL);
    for (i = 0; i < sizeof(bad) / sizeof(bad[0]); ++i) {
        rad_patch_options_default(&o);
        o.max_area = bad[i];
        P = API_SENTINEL(rad_patches);
        CHECK_RESULT(rad_patches_create(f->scene, &o, NULL, &P), RAD_ERROR_INVALID_ARGUMENT);
        CHECK(P == NULL);
        rad_patch_options_default(&o);
        o.max_edge = bad[i];
        P = API_SENTINEL(rad_patches);
        CHECK_RESULT(rad_patches_create(f->scene, &o, NULL, &P), RAD_ERROR_INVALID_ARGUMENT);
        CHECK(P == NULL);
    }
    /* a subdivision past 2^32 patches: SIZE_OVERFLOW (documented), never a huge allocation */
    rad_patch_options_default(&o);
    o.max_edge = f->scene->diagonal * 1e-6f;
    P = API_SENTINEL(rad_patches);
    {
        rad_result r = rad_patches_create(f->scene, &o, NULL, &P);
        CHECK(r == RAD_ERROR_SIZE_OVERFLOW || r == RAD_ERROR_OUT_OF_MEMORY);
        CHECK(P == NULL);
        if (r == RAD_SUCCESS && P != API_SENTINEL(rad_patches)) rad_patches_destroy(P);
    }
}

static void api_patches_queries(api_fx *f)
{
    float w[3] = { 7, 7, 7 };
    uint32_t p;
    CHECK(rad_patches_locate(NULL, 0, 0.2f, 0.2f, w) == RAD_NONE);
    CHECK(w[0] == 0.0f && w[1] == 0.0f && w[2] == 0.0f);
    CHECK(rad_patches_locate(NULL, 0, 0.2f, 0.2f, NULL) == RAD_NONE);
    CHECK(rad_patches_locate(f->P, f->P->triangle_count, 0.2f, 0.2f, w) == RAD_NONE);
    CHECK(rad_patches_locate(f->P, RAD_NONE, 0.2f, 0.2f, w) == RAD_NONE);
    /* out-of-range and NaN barycentrics are clamped: a patch of that triangle */
    p = rad_patches_locate(f->P, 3, (float)NAN, (float)INFINITY, w);
    CHECK(p < f->n && f->P->patches[p].triangle == 3);
    CHECK(w[0] == w[0] && w[1] == w[1] && w[2] == w[2]);
    p = rad_patches_locate(f->P, 3, -5.0f, 9.0f, NULL);
    CHECK(p < f->n && f->P->patches[p].triangle == 3);
    /* vertex values */
    api_fill(f->buf, f->buf_len);
    CHECK_RESULT(rad_patches_vertex_values(NULL, f->B, 3, f->buf), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_patches_vertex_values(f->P, NULL, 3, f->buf), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_patches_vertex_values(f->P, f->B, 0, f->buf), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_patches_vertex_values(f->P, f->B, 3, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(api_untouched(f->buf, f->buf_len));
    CHECK_OK(rad_patches_vertex_values(f->P, f->B, 3, f->buf));
    CHECK_OK(rad_patches_vertex_values(&f->bake->patches, f->B, 3, f->buf)); /* a loaded bake works too */
}

static void api_bvh_args(api_fx *f)
{
    rad_bvh *b = API_SENTINEL(rad_bvh);
    rad_raycaster rc;
    rad_ray ray;
    rad_hit hit;
    uint8_t occ = 7;
    CHECK_RESULT(rad_bvh_create(f->scene, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_bvh_create(NULL, NULL, &b), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(b == NULL);
    CHECK(rad_bvh_memory(NULL) == 0);
    CHECK(rad_bvh_memory(f->bvh) > 0);
    memset(&rc, 0, sizeof(rc));
    rad_bvh_raycaster(f->bvh, &rc);
    CHECK(rc.occluded != NULL && rc.intersect != NULL);
    /* zero-ray batches with NULL arrays */
    CHECK_OK(rc.occluded(rc.user, NULL, 0, NULL));
    CHECK_OK(rc.intersect(rc.user, NULL, 0, NULL));
    /* NaN rays miss, they do not crash */
    ray.origin[0] = (float)NAN; ray.origin[1] = 0.3f; ray.origin[2] = 0.3f;
    ray.dir[0] = 0.0f; ray.dir[1] = 1.0f; ray.dir[2] = 0.0f;
    ray.tmin = 0.0f; ray.tmax = 10.0f;
    CHECK_OK(rc.occluded(rc.user, &ray, 1, &occ));
    CHECK(occ == 0);
    CHECK_OK(rc.intersect(rc.user, &ray, 1, &hit));
    CHECK(hit.triangle == RAD_NONE);
    /* a zero direction */
    ray.origin[0] = 0.3f; ray.dir[1] = 0.0f;
    CHECK_OK(rc.intersect(rc.user, &ray, 1, &hit));
    CHECK(hit.triangle == RAD_NONE);
    /* tmin > tmax */
    ray.dir[1] = 1.0f; ray.tmin = 5.0f; ray.tmax = 1.0f;
    CHECK_OK(rc.occluded(rc.user, &ray, 1, &occ));
    CHECK(occ == 0);
}

static void api_embree_args(api_fx *f)
{
    rad_embree *e = API_SENTINEL(rad_embree);
    rad_raycaster rc;
    uint32_t first = 0;
    rad_result want_null = rad_embree_available() ? RAD_ERROR_INVALID_ARGUMENT : RAD_ERROR_UNAVAILABLE;
    CHECK(rad_embree_available() == 0 || rad_embree_available() == 1);
    CHECK_RESULT(rad_embree_create(NULL, NULL, &e), want_null);
    CHECK(e == NULL);
    CHECK_RESULT(rad_embree_create(f->scene, NULL, NULL), want_null);
    e = API_SENTINEL(rad_embree);
    CHECK_RESULT(rad_embree_wrap(NULL, NULL, 0, NULL, &e), want_null);
    CHECK(e == NULL);
    e = API_SENTINEL(rad_embree);
    CHECK_RESULT(rad_embree_wrap((void *)f, &first, 0, NULL, &e), want_null); /* first_triangle with no geometries */
    CHECK(e == NULL);
    CHECK_RESULT(rad_embree_wrap((void *)f, NULL, 0, NULL, NULL), want_null);
    CHECK(rad_embree_memory(NULL) == 0);
    memset(&rc, 0xAB, sizeof(rc));
    rad_embree_raycaster(NULL, &rc);
    CHECK(rc.occluded == NULL && rc.intersect == NULL);
    if (!rad_embree_available()) {
        e = API_SENTINEL(rad_embree);
        CHECK_RESULT(rad_embree_create(f->scene, NULL, &e), RAD_ERROR_UNAVAILABLE);
        CHECK(e == NULL);
    }
}

static const api_case api_cases_geometry[] = {
    { "rad_patches_create arguments", api_patches_create_args },
    { "rad_patches_locate, rad_patches_vertex_values", api_patches_queries },
    { "rad_bvh_* arguments", api_bvh_args },
    { "rad_embree_* arguments", api_embree_args },
    { NULL, NULL }
};

/* ---- form factors ------------------------------------------------------------------------- */

static void api_ff_kernels(api_fx *f)
{
    const float p[3] = { 0.2f, 0.2f, 0.0f }, n[3] = { 0, 0, 1 }, zero[3] = { 0, 0, 0 }, nanv[3] = { (float)NAN, 0, 1 };
    const float quad[12] = { 0, 0, 1, 0, 1, 1, 1, 1, 1, 1, 0, 1 }; /* at z = 1, facing down (cw seen from above) */
    const float q2[3] = { 0.2f, 0.2f, 1.0f }, nd[3] = { 0, 0, -1 };
    float v;
    (void)f;
    CHECK(rad_ff_point_polygon(NULL, n, quad, 4) == 0.0f);
    CHECK(rad_ff_point_polygon(p, NULL, quad, 4) == 0.0f);
    CHECK(rad_ff_point_polygon(p, n, NULL, 4) == 0.0f);
    CHECK(rad_ff_point_polygon(p, n, quad, 0) == 0.0f);
    CHECK(rad_ff_point_polygon(p, n, quad, 2) == 0.0f);
    CHECK(rad_ff_point_polygon(p, zero, quad, 4) == 0.0f);
    CHECK(rad_ff_point_polygon(p, n, quad, 4) > 0.0f);
    v = rad_ff_point_polygon(nanv, n, quad, 4);
    CHECK(v == v);
    v = rad_ff_point_polygon(p, nanv, quad, 4);
    CHECK(v == v);
    CHECK(rad_ff_point_point(NULL, n, q2, nd, 1.0f) == 0.0f);
    CHECK(rad_ff_point_point(p, NULL, q2, nd, 1.0f) == 0.0f);
    CHECK(rad_ff_point_point(p, n, NULL, nd, 1.0f) == 0.0f);
    CHECK(rad_ff_point_point(p, n, q2, NULL, 1.0f) == 0.0f);
    CHECK(rad_ff_point_point(p, n, q2, nd, 0.0f) == 0.0f);
    CHECK(rad_ff_point_point(p, n, q2, nd, -1.0f) == 0.0f);
    CHECK(rad_ff_point_point(p, n, q2, nd, (float)NAN) == 0.0f);
    CHECK(rad_ff_point_point(p, n, p, nd, 1.0f) == 0.0f); /* coincident points */
    CHECK(rad_ff_point_point(p, n, q2, nd, 0.01f) > 0.0f);
    v = rad_ff_point_point(nanv, n, q2, nd, 1.0f);
    CHECK(v == v);
    v = rad_ff_point_point(p, n, q2, nd, (float)INFINITY);
    CHECK(v == v);
}

/* bad form-factor options: each must give INVALID_ARGUMENT from every entry point */
static void api_ff_bad_options(api_fx *f)
{
    static const uint32_t two_rows[2] = {0, 2};
    rad_form_factor_options o[8];
    uint32_t i, count = 0;
    rad_form_factors *ff;
    for (i = 0; i < 8; ++i) rad_form_factor_options_default(&o[i]);
    o[count++].method = (rad_ff_method)7;
    o[count++].method = (rad_ff_method)-1;
    o[count++].ray_epsilon = -1e-5f;
    o[count++].ray_epsilon = (float)NAN;
    o[count++].ray_epsilon = (float)INFINITY;
    o[count++].drop_threshold = -1.0f;
    o[count++].drop_threshold = (float)NAN;
    o[count++].drop_threshold = (float)INFINITY;
    for (i = 0; i < count; ++i) {
        int before = rad_test_failures;
        api_fill(f->buf, f->buf_len);
        CHECK_RESULT(rad_form_factor_rows(f->P, &f->rc, &o[i], 0, 2, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
        CHECK(api_untouched(f->buf, f->buf_len));
        api_fill(f->buf2, f->buf_len);
        CHECK_RESULT(rad_form_factor_pairs(f->P, &f->rc, &o[i], two_rows, 1, f->buf, f->buf2, NULL, NULL),
                     RAD_ERROR_INVALID_ARGUMENT);
        CHECK(api_untouched(f->buf, f->buf_len) && api_untouched(f->buf2, f->buf_len));
        ff = API_SENTINEL(rad_form_factors);
        CHECK_RESULT(rad_form_factors_dense(f->P, &f->rc, &o[i], NULL, &ff), RAD_ERROR_INVALID_ARGUMENT);
        CHECK(ff == NULL);
        ff = API_SENTINEL(rad_form_factors);
        CHECK_RESULT(rad_form_factors_sparse(f->P, &f->rc, &o[i], NULL, &ff), RAD_ERROR_INVALID_ARGUMENT);
        CHECK(ff == NULL);
        if (rad_test_failures != before) printf("    bad form-factor option %u\n", i);
    }
}

static void api_ff_args(api_fx *f)
{
    rad_form_factors *ff = API_SENTINEL(rad_form_factors);
    rad_raycaster none, half;
    rad_form_factor_options o;
    rad_patches scene_less;
    uint32_t N = f->n;
    memset(&none, 0, sizeof(none));
    half = f->rc;
    half.occluded = NULL;
    rad_form_factor_options_default(&o);
    /* rows */
    api_fill(f->buf, f->buf_len);
    CHECK_RESULT(rad_form_factor_rows(NULL, &f->rc, NULL, 0, 1, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_form_factor_rows(f->P, &f->rc, NULL, 0, 1, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_form_factor_rows(f->P, &f->rc, NULL, 2, 1, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_form_factor_rows(f->P, &f->rc, NULL, 0, N + 1, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_form_factor_rows(f->P, &f->rc, NULL, N + 1, N + 1, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_form_factor_rows(f->P, &f->rc, NULL, 0xFFFFFFFFu, 0xFFFFFFFFu, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_form_factor_rows(f->P, NULL, NULL, 0, 1, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_form_factor_rows(f->P, &none, NULL, 0, 1, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_form_factor_rows(f->P, &half, NULL, 0, 1, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(api_untouched(f->buf, f->buf_len));
    CHECK_OK(rad_form_factor_rows(f->P, &f->rc, NULL, 3, 3, f->buf, NULL)); /* an empty range writes nothing */
    CHECK_OK(rad_form_factor_rows(f->P, &f->rc, NULL, N, N, f->buf, NULL));
    CHECK(api_untouched(f->buf, f->buf_len));
    /* pairs: the same refusals, nothing written; no pairs at all (the last row has no j > i) is fine */
    {
        uint64_t ev = 7;
        uint32_t r[4];
        api_fill(f->buf2, f->buf_len);
        r[0] = 0, r[1] = 1;
        CHECK_RESULT(rad_form_factor_pairs(NULL, &f->rc, NULL, r, 1, f->buf, f->buf2, &ev, NULL), RAD_ERROR_INVALID_ARGUMENT);
        CHECK(ev == 0);
        CHECK_RESULT(rad_form_factor_pairs(f->P, &f->rc, NULL, NULL, 1, f->buf, f->buf2, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
        CHECK_RESULT(rad_form_factor_pairs(f->P, &f->rc, NULL, r, 1, NULL, f->buf2, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
        CHECK_RESULT(rad_form_factor_pairs(f->P, &f->rc, NULL, r, 1, f->buf, NULL, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
        CHECK_RESULT(rad_form_factor_pairs(f->P, NULL, NULL, r, 1, f->buf, f->buf2, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
        CHECK_RESULT(rad_form_factor_pairs(f->P, &half, NULL, r, 1, f->buf, f->buf2, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
        r[0] = 2, r[1] = 1;
        CHECK_RESULT(rad_form_factor_pairs(f->P, &f->rc, NULL, r, 1, f->buf, f->buf2, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
        r[0] = 0, r[1] = N + 1;
        CHECK_RESULT(rad_form_factor_pairs(f->P, &f->rc, NULL, r, 1, f->buf, f->buf2, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
        r[0] = r[1] = 0xFFFFFFFFu;
        CHECK_RESULT(rad_form_factor_pairs(f->P, &f->rc, NULL, r, 1, f->buf, f->buf2, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
        r[0] = 0, r[1] = 2, r[2] = 1, r[3] = 3; /* overlapping */
        CHECK_RESULT(rad_form_factor_pairs(f->P, &f->rc, NULL, r, 2, f->buf, f->buf2, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
        r[0] = N - 1, r[1] = N;
        CHECK_OK(rad_form_factor_pairs(f->P, &f->rc, NULL, r, 1, NULL, NULL, &ev, NULL));
        CHECK(ev == 0);
        CHECK(api_untouched(f->buf, f->buf_len) && api_untouched(f->buf2, f->buf_len));
    }
    o.skip_visibility = 1; /* the raycaster may be NULL then */
    CHECK_OK(rad_form_factor_rows(f->P, NULL, &o, 0, 1, f->buf, NULL));
    o.samples = 0xFFFFFFFFu; /* capped */
    CHECK_OK(rad_form_factor_rows(f->P, NULL, &o, 0, 1, f->buf, NULL));
    /* dense and sparse */
    CHECK_RESULT(rad_form_factors_dense(f->P, &f->rc, NULL, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_form_factors_sparse(f->P, &f->rc, NULL, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_form_factors_dense(NULL, &f->rc, NULL, NULL, &ff), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(ff == NULL);
    ff = API_SENTINEL(rad_form_factors);
    CHECK_RESULT(rad_form_factors_sparse(NULL, &f->rc, NULL, NULL, &ff), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(ff == NULL);
    ff = API_SENTINEL(rad_form_factors);
    CHECK_RESULT(rad_form_factors_dense(f->P, NULL, NULL, NULL, &ff), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(ff == NULL);
    ff = API_SENTINEL(rad_form_factors);
    CHECK_RESULT(rad_form_factors_sparse(f->P, &half, NULL, NULL, &ff), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(ff == NULL);
    /* patches without a scene (a loaded bake before .scene is set): the documented error, not a crash */
    scene_less = *f->P;
    scene_less.scene = NULL;
    (void)scene_less;
    API_CRASHER("rad_form_factor_rows(patches with scene == NULL, ...)",
                CHECK_RESULT(rad_form_factor_rows(&scene_less, &f->rc, NULL, 0, 1, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT));
    API_CRASHER("rad_form_factors_dense(patches with scene == NULL, ...)",
                CHECK_RESULT(rad_form_factors_dense(&scene_less, &f->rc, NULL, NULL, &ff), RAD_ERROR_INVALID_ARGUMENT));
    API_CRASHER("rad_form_factors_sparse(patches with scene == NULL, ...)",
                CHECK_RESULT(rad_form_factors_sparse(&scene_less, &f->rc, NULL, NULL, &ff), RAD_ERROR_INVALID_ARGUMENT));
}

static const api_case api_cases_ff[] = {
    { "rad_ff_point_polygon, rad_ff_point_point", api_ff_kernels },
    { "form factor bad options", api_ff_bad_options },
    { "form factor arguments", api_ff_args },
    { NULL, NULL }
};

/* ---- solvers ------------------------------------------------------------------------------ */

/* run solver s (0 Jacobi, 1 GS, 2 progressive, 3 direct) */
static rad_result api_solve(int s, const rad_system *sys, const rad_solve_options *o, float *out, rad_solve_stats *st)
{
    switch (s) {
    case 0: return rad_solve_jacobi(sys, o, out, st, NULL);
    case 1: return rad_solve_gauss_seidel(sys, o, out, st, NULL);
    case 2: return rad_solve_progressive(sys, o, out, st, NULL);
    default: return rad_solve_direct(sys, o, out, NULL);
    }
}

static const char *const api_solver_names[4] = { "jacobi", "gauss_seidel", "progressive", "direct" };

static void api_solve_args(api_fx *f)
{
    rad_matrix Mbad, Mrect;
    rad_system bad;
    rad_solve_options o;
    rad_solve_stats st;
    int s, k;
    size_t n3 = 3 * (size_t)f->n;
    for (s = 0; s < 4; ++s) {
        int before = rad_test_failures;
        rad_solve_options_default(&o);
        o.max_iterations = 100000;
        api_fill(f->buf, n3);
        CHECK_RESULT(api_solve(s, NULL, &o, f->buf, &st), RAD_ERROR_INVALID_ARGUMENT);
        CHECK_RESULT(api_solve(s, &f->sys, &o, NULL, &st), RAD_ERROR_INVALID_ARGUMENT);
        bad = f->sys; bad.F = NULL;
        CHECK_RESULT(api_solve(s, &bad, &o, f->buf, &st), RAD_ERROR_INVALID_ARGUMENT);
        bad = f->sys; bad.albedo = NULL;
        CHECK_RESULT(api_solve(s, &bad, &o, f->buf, &st), RAD_ERROR_INVALID_ARGUMENT);
        bad = f->sys; bad.E = NULL;
        CHECK_RESULT(api_solve(s, &bad, &o, f->buf, &st), RAD_ERROR_INVALID_ARGUMENT);
        bad = f->sys; bad.n = 0;
        CHECK_RESULT(api_solve(s, &bad, &o, f->buf, &st), RAD_ERROR_INVALID_ARGUMENT);
        bad = f->sys; bad.n = f->n - 1;
        CHECK_RESULT(api_solve(s, &bad, &o, f->buf, &st), RAD_ERROR_SIZE_MISMATCH);
        bad = f->sys; bad.n = f->n + 1;
        CHECK_RESULT(api_solve(s, &bad, &o, f->buf, &st), RAD_ERROR_SIZE_MISMATCH);
        Mrect = f->ffd->matrix; Mrect.cols = f->n - 1;
        bad = f->sys; bad.F = &Mrect;
        CHECK_RESULT(api_solve(s, &bad, &o, f->buf, &st), RAD_ERROR_SIZE_MISMATCH);
        Mbad = f->ffd->matrix; Mbad.dense = NULL;
        bad = f->sys; bad.F = &Mbad;
        CHECK_RESULT(api_solve(s, &bad, &o, f->buf, &st), RAD_ERROR_INVALID_ARGUMENT);
        Mbad = f->ffd->matrix; Mbad.storage = (rad_storage)5;
        CHECK_RESULT(api_solve(s, &bad, &o, f->buf, &st), RAD_ERROR_INVALID_ARGUMENT);
        for (k = 0; k < 3; ++k) {
            Mbad = f->ffs->matrix;
            if (k == 0) Mbad.row_offsets = NULL; else if (k == 1) Mbad.columns = NULL; else Mbad.values = NULL;
            CHECK_RESULT(api_solve(s, &bad, &o, f->buf, &st), RAD_ERROR_INVALID_ARGUMENT);
        }
        if (s == 2) {
            bad = f->sys; bad.areas = NULL;
            CHECK_RESULT(api_solve(s, &bad, &o, f->buf, &st), RAD_ERROR_INVALID_ARGUMENT);
        }
        /* a bad output enum is a bad option value */
        o.output = (rad_output)7;
        CHECK_RESULT(api_solve(s, &f->sys, &o, f->buf, &st), RAD_ERROR_INVALID_ARGUMENT);
        CHECK(api_untouched(f->buf, n3));
        /* NULL options and stats are allowed (defaults) */
        CHECK_OK(api_solve(s, &f->sys, NULL, f->buf, NULL));
        if (rad_test_failures != before) printf("    solver %s\n", api_solver_names[s]);
    }
    /* negative or NaN tolerance (GS and progressive read it) */
    for (s = 1; s <= 2; ++s) {
        int before = rad_test_failures;
        rad_solve_options_default(&o);
        o.tolerance = -1.0;
        api_fill(f->buf, n3);
        CHECK_RESULT(api_solve(s, &f->sys, &o, f->buf, &st), RAD_ERROR_INVALID_ARGUMENT);
        o.tolerance = (double)NAN;
        CHECK_RESULT(api_solve(s, &f->sys, &o, f->buf, &st), RAD_ERROR_INVALID_ARGUMENT);
        if (rad_test_failures != before) printf("    solver %s tolerance\n", api_solver_names[s]);
    }
}

static void api_multiply_args(api_fx *f)
{
    rad_matrix M;
    size_t n3 = 3 * (size_t)f->n;
    api_fill(f->buf, n3);
    CHECK_RESULT(rad_matrix_multiply(NULL, f->E, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_matrix_multiply(&f->ffd->matrix, NULL, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_matrix_multiply(&f->ffd->matrix, f->E, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    memcpy(f->buf2, f->E, sizeof(float) * n3);
    CHECK_RESULT(rad_matrix_multiply(&f->ffd->matrix, f->buf2, f->buf2, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(memcmp(f->buf2, f->E, sizeof(float) * n3) == 0);
    CHECK_RESULT(rad_matrix_multiply(&f->ffs->matrix, f->buf2, f->buf2, NULL), RAD_ERROR_INVALID_ARGUMENT);
    M = f->ffd->matrix; M.storage = (rad_storage)2;
    CHECK_RESULT(rad_matrix_multiply(&M, f->E, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    M = f->ffd->matrix; M.dense = NULL;
    CHECK_RESULT(rad_matrix_multiply(&M, f->E, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    M = f->ffs->matrix; M.columns = NULL;
    CHECK_RESULT(rad_matrix_multiply(&M, f->E, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(api_untouched(f->buf, n3));
    M = f->ffd->matrix; M.rows = 0;
    CHECK_OK(rad_matrix_multiply(&M, f->E, f->buf, NULL)); /* no rows: nothing to write */
    CHECK(api_untouched(f->buf, n3));
}

static const api_case api_cases_solve[] = {
    { "solver arguments", api_solve_args },
    { "rad_matrix_multiply arguments", api_multiply_args },
    { NULL, NULL }
};

/* ---- lights and sources ------------------------------------------------------------------- */

static void api_light_point(rad_light *l)
{
    memset(l, 0, sizeof(*l));
    l->type = RAD_LIGHT_POINT;
    l->color[0] = l->color[1] = l->color[2] = 1.0f;
    l->position[0] = 0.27f; l->position[1] = 0.4f; l->position[2] = 0.27f;
    l->direction[1] = -1.0f;
    l->inner_angle = 0.3f;
    l->outer_angle = 0.6f;
}

/* every direct entry point with these lights must return 'expected' without writing */
static void api_direct_expect(api_fx *f, const rad_light *lights, uint32_t count, const rad_direct_options *o,
                              rad_result expected, const char *what)
{
    float pts[6] = { 0.27f, 0.01f, 0.27f, 0.1f, 0.01f, 0.1f }, nrm[6] = { 0, 1, 0, 0, 1, 0 };
    size_t n3 = 3 * (size_t)f->n;
    rad_result r1, r2;
    api_fill(f->buf, n3);
    r1 = rad_direct_patches(f->P, &f->rc, lights, count, o, f->buf, NULL);
    CHECK(api_untouched(f->buf, n3));
    r2 = rad_direct_irradiance(f->scene, &f->rc, lights, count, o, pts, nrm, 2, f->buf, NULL);
    CHECK(api_untouched(f->buf, n3));
    if (r1 != expected || r2 != expected)
        printf("    direct case '%s': patches %s, irradiance %s, expected %s\n", what, rad_result_string(r1),
               rad_result_string(r2), rad_result_string(expected));
    CHECK(r1 == expected && r2 == expected);
}

static void api_direct_args(api_fx *f)
{
    rad_light l;
    rad_direct_options o;
    rad_raycaster none;
    rad_patches scene_less;
    float pts[6] = { 0.27f, 0.01f, 0.27f, 0.1f, 0.01f, 0.1f }, nrm[6] = { 0, 1, 0, 0, 1, 0 };
    size_t n3 = 3 * (size_t)f->n;
    memset(&none, 0, sizeof(none));
    api_light_point(&l);
    api_fill(f->buf, n3);
    CHECK_RESULT(rad_direct_patches(NULL, &f->rc, &l, 1, NULL, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_direct_patches(f->P, NULL, &l, 1, NULL, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_direct_patches(f->P, &none, &l, 1, NULL, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_direct_patches(f->P, &f->rc, NULL, 1, NULL, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_direct_patches(f->P, &f->rc, &l, 1, NULL, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    scene_less = *f->P;
    scene_less.scene = NULL;
    CHECK_RESULT(rad_direct_patches(&scene_less, &f->rc, &l, 1, NULL, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_direct_patches(&f->bake->patches, &f->rc, &l, 1, NULL, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_direct_irradiance(NULL, &f->rc, &l, 1, NULL, pts, nrm, 2, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_direct_irradiance(f->scene, NULL, &l, 1, NULL, pts, nrm, 2, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_direct_irradiance(f->scene, &none, &l, 1, NULL, pts, nrm, 2, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_direct_irradiance(f->scene, &f->rc, NULL, 1, NULL, pts, nrm, 2, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_direct_irradiance(f->scene, &f->rc, &l, 1, NULL, NULL, nrm, 2, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_direct_irradiance(f->scene, &f->rc, &l, 1, NULL, pts, NULL, 2, f->buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_direct_irradiance(f->scene, &f->rc, &l, 1, NULL, pts, nrm, 2, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    pts[4] = (float)NAN;
    CHECK_RESULT(rad_direct_irradiance(f->scene, &f->rc, &l, 1, NULL, pts, nrm, 2, f->buf, NULL), RAD_ERROR_NON_FINITE);
    pts[4] = 0.01f;
    nrm[5] = (float)INFINITY;
    CHECK_RESULT(rad_direct_irradiance(f->scene, &f->rc, &l, 1, NULL, pts, nrm, 2, f->buf, NULL), RAD_ERROR_NON_FINITE);
    nrm[5] = 0.0f;
    CHECK(api_untouched(f->buf, n3));
    /* zero lights and zero points are valid */
    CHECK_OK(rad_direct_irradiance(f->scene, &f->rc, NULL, 0, NULL, pts, nrm, 0, f->buf, NULL));
    CHECK(api_untouched(f->buf, n3));
    CHECK_OK(rad_direct_patches(f->P, &f->rc, NULL, 0, NULL, f->buf, NULL));
    /* bad lights */
    api_light_point(&l); l.color[1] = (float)NAN; api_direct_expect(f, &l, 1, NULL, RAD_ERROR_NON_FINITE, "colour NaN");
    api_light_point(&l); l.position[2] = (float)INFINITY; api_direct_expect(f, &l, 1, NULL, RAD_ERROR_NON_FINITE, "position inf");
    api_light_point(&l); l.direction[0] = (float)NAN; api_direct_expect(f, &l, 1, NULL, RAD_ERROR_NON_FINITE, "direction NaN");
    api_light_point(&l); l.min_distance = (float)NAN; api_direct_expect(f, &l, 1, NULL, RAD_ERROR_NON_FINITE, "min_distance NaN");
    api_light_point(&l); l.outer_angle = (float)INFINITY; api_direct_expect(f, &l, 1, NULL, RAD_ERROR_NON_FINITE, "outer_angle inf");
    api_light_point(&l); l.color[0] = -1.0f;
    {
        /* the enum documents NEGATIVE_EMISSION; rad_direct_irradiance's comment lists INVALID_ARGUMENT */
        rad_result r = rad_direct_patches(f->P, &f->rc, &l, 1, NULL, f->buf, NULL);
        CHECK(r == RAD_ERROR_NEGATIVE_EMISSION || r == RAD_ERROR_INVALID_ARGUMENT);
    }
    api_light_point(&l); l.type = (rad_light_type)5; api_direct_expect(f, &l, 1, NULL, RAD_ERROR_INVALID_ARGUMENT, "type 5");
    api_light_point(&l); l.type = (rad_light_type)-1; api_direct_expect(f, &l, 1, NULL, RAD_ERROR_INVALID_ARGUMENT, "type -1");
    api_light_point(&l); l.falloff = (rad_falloff)2; api_direct_expect(f, &l, 1, NULL, RAD_ERROR_INVALID_ARGUMENT, "falloff 2");
    api_light_point(&l); l.type = RAD_LIGHT_DIRECTIONAL; l.direction[1] = 0.0f;
    api_direct_expect(f, &l, 1, NULL, RAD_ERROR_INVALID_ARGUMENT, "directional, zero direction");
    api_light_point(&l); l.type = RAD_LIGHT_SPOT; l.direction[1] = 0.0f;
    api_direct_expect(f, &l, 1, NULL, RAD_ERROR_INVALID_ARGUMENT, "spot, zero direction");
    api_light_point(&l); l.type = RAD_LIGHT_SPOT; l.inner_angle = 0.7f;
    api_direct_expect(f, &l, 1, NULL, RAD_ERROR_INVALID_ARGUMENT, "spot, outer < inner");
    api_light_point(&l); l.type = RAD_LIGHT_SPOT; l.inner_angle = -0.1f;
    api_direct_expect(f, &l, 1, NULL, RAD_ERROR_INVALID_ARGUMENT, "spot, inner < 0");
    api_light_point(&l); l.type = RAD_LIGHT_SPOT; l.outer_angle = 4.0f;
    api_direct_expect(f, &l, 1, NULL, RAD_ERROR_INVALID_ARGUMENT, "spot, outer > pi");
    api_light_point(&l); l.min_distance = -1.0f;
    api_direct_expect(f, &l, 1, NULL, RAD_ERROR_INVALID_ARGUMENT, "min_distance -1");
    /* bad options */
    api_light_point(&l);
    rad_direct_options_default(&o); o.ray_epsilon = -1.0f;
    api_direct_expect(f, &l, 1, &o, RAD_ERROR_INVALID_ARGUMENT, "ray_epsilon -1");
    rad_direct_options_default(&o); o.ray_epsilon = (float)NAN;
    api_direct_expect(f, &l, 1, &o, RAD_ERROR_INVALID_ARGUMENT, "ray_epsilon NaN");
    rad_direct_options_default(&o); o.samples = 0xFFFFFFFFu; o.light_samples = 0xFFFFFFFFu; /* capped */
    CHECK_OK(rad_direct_patches(f->P, &f->rc, &l, 1, &o, f->buf, NULL));
}

static void api_sources_args(api_fx *f)
{
    size_t n3 = 3 * (size_t)f->n, i;
    float *D = f->buf2;
    for (i = 0; i < n3; ++i) D[i] = 1.0f;
    api_fill(f->buf, n3);
    CHECK_RESULT(rad_sources(NULL, RAD_SOURCE_EMISSION, NULL, f->buf), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_sources(f->P, RAD_SOURCE_EMISSION, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_sources(f->P, RAD_SOURCE_EMISSION, D, f->buf), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_sources(f->P, RAD_SOURCE_DIRECT, NULL, f->buf), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_sources(f->P, (rad_source_mode)2, D, f->buf), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_sources(f->P, (rad_source_mode)-1, NULL, f->buf), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(api_untouched(f->buf, n3));
    /* a bad value late in D: the error, and out_E untouched (outputs are written only on success) */
    D[n3 - 1] = (float)NAN;
    CHECK_RESULT(rad_sources(f->P, RAD_SOURCE_DIRECT, D, f->buf), RAD_ERROR_NON_FINITE);
    D[n3 - 1] = -1.0f; /* finite: a bad argument, not an overflow */
    CHECK_RESULT(rad_sources(f->P, RAD_SOURCE_DIRECT, D, f->buf), RAD_ERROR_INVALID_ARGUMENT);
    D[n3 - 1] = (float)INFINITY;
    CHECK_RESULT(rad_sources(f->P, RAD_SOURCE_DIRECT, D, f->buf), RAD_ERROR_NON_FINITE);
    if (!api_untouched(f->buf, n3)) printf("    rad_sources(RAD_SOURCE_DIRECT) wrote out_E before failing\n");
    CHECK(api_untouched(f->buf, n3));
    D[n3 - 1] = 1.0f;
    CHECK_OK(rad_sources(f->P, RAD_SOURCE_DIRECT, D, f->buf));
}

static const api_case api_cases_light[] = {
    { "direct light arguments", api_direct_args },
    { "rad_sources arguments", api_sources_args },
    { NULL, NULL }
};

/* ---- containers and bakes ----------------------------------------------------------------- */

static void api_container_args(api_fx *f)
{
    rad_section s[2];
    size_t bytes = 77;
    unsigned char dst[512];
    float data[4] = { 1, 2, 3, 4 };
    rad_container *ct = API_SENTINEL(rad_container);
    void *odd;
    uint32_t i;
    memset(s, 0, sizeof(s));
    s[0].type = RAD_SECTION_USER; s[0].elem_size = 4; s[0].count = 4; s[0].data = data;
    s[1] = s[0];
    CHECK_RESULT(rad_container_size(NULL, 1, &bytes), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_container_size(s, 1, NULL), RAD_ERROR_INVALID_ARGUMENT);
    s[1].elem_size = 0;
    CHECK_RESULT(rad_container_size(s, 2, &bytes), RAD_ERROR_INVALID_ARGUMENT);
    s[1].elem_size = 4; s[1].data = NULL;
    CHECK_RESULT(rad_container_size(s, 2, &bytes), RAD_ERROR_INVALID_ARGUMENT);
    s[1].data = data; s[1].elem_size = 0xFFFFFFFFu; s[1].count = 0xFFFFFFFFFFFFull;
    CHECK_RESULT(rad_container_size(s, 2, &bytes), RAD_ERROR_SIZE_OVERFLOW);
    s[1].elem_size = 1; s[1].count = UINT64_MAX - 16u;
    CHECK_RESULT(rad_container_size(s, 2, &bytes), RAD_ERROR_SIZE_OVERFLOW);
    s[1] = s[0];
    CHECK_RESULT(rad_container_size(s, 0x7FFFFFFFu, &bytes), RAD_ERROR_SIZE_OVERFLOW);
    CHECK(bytes == 77);
    CHECK_OK(rad_container_size(NULL, 0, &bytes));
    CHECK_OK(rad_container_size(s, 2, &bytes));
    CHECK(bytes <= sizeof(dst));
    memset(dst, 0xCD, sizeof(dst));
    CHECK_RESULT(rad_container_write(s, 2, NULL, sizeof(dst)), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_container_write(NULL, 2, dst, sizeof(dst)), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_container_write(s, 2, dst, bytes - 1), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_container_write(s, 2, dst, 0), RAD_ERROR_INVALID_ARGUMENT);
    for (i = 0; i < sizeof(dst); ++i) if (dst[i] != 0xCD) break;
    CHECK(i == sizeof(dst));
    /* open */
    CHECK_RESULT(rad_container_create(f->bytes, f->size, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_container_create(NULL, f->size, NULL, &ct), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(ct == NULL);
    ct = API_SENTINEL(rad_container);
    CHECK_RESULT(rad_container_create(f->bytes, 0, NULL, &ct), RAD_ERROR_TRUNCATED);
    CHECK(ct == NULL);
    ct = API_SENTINEL(rad_container);
    CHECK_RESULT(rad_container_create(f->bytes, 63, NULL, &ct), RAD_ERROR_TRUNCATED);
    CHECK(ct == NULL);
    ct = API_SENTINEL(rad_container);
    CHECK_RESULT(rad_container_create(f->bytes, f->size - 1, NULL, &ct), RAD_ERROR_TRUNCATED);
    CHECK(ct == NULL);
    odd = malloc(f->size + 8);
    if (odd) {
        memcpy((char *)odd + 4, f->bytes, f->size);
        ct = API_SENTINEL(rad_container);
        CHECK_RESULT(rad_container_create((char *)odd + 4, f->size, NULL, &ct), RAD_ERROR_INVALID_ARGUMENT); /* not 8-aligned */
        CHECK(ct == NULL);
        free(odd);
    }
    /* queries */
    CHECK(rad_container_section_count(NULL) == 0);
    CHECK(rad_container_section(NULL, 0) == NULL);
    CHECK(rad_container_section(f->ct, rad_container_section_count(f->ct)) == NULL);
    CHECK(rad_container_section(f->ct, RAD_NONE) == NULL);
    CHECK(rad_container_section(f->ct, 0) != NULL);
    CHECK(rad_container_find(NULL, RAD_SECTION_VECTOR, NULL) == NULL);
    CHECK(rad_container_find(f->ct, RAD_SECTION_VECTOR, "no such name") == NULL);
    CHECK(rad_container_find(f->ct, 0xDEADu, NULL) == NULL);
    CHECK(rad_container_find(f->ct, RAD_SECTION_VECTOR, "E") != NULL);
}

static void api_bake_args(api_fx *f)
{
    void *buf = API_SENTINEL(void);
    size_t sz = 99;
    rad_bake *b = API_SENTINEL(rad_bake);
    rad_matrix M;
    CHECK_RESULT(rad_save_memory(f->P, NULL, NULL, NULL, NULL, NULL, &sz), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_save_memory(f->P, NULL, NULL, NULL, NULL, &buf, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_save_memory(NULL, NULL, NULL, NULL, NULL, &buf, &sz), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(buf == NULL && sz == 0);
    M = f->ffd->matrix; M.rows = f->n - 1;
    buf = API_SENTINEL(void); sz = 99;
    CHECK_RESULT(rad_save_memory(f->P, &M, NULL, NULL, NULL, &buf, &sz), RAD_ERROR_SIZE_MISMATCH);
    CHECK(buf == NULL && sz == 0);
    M = f->ffd->matrix; M.cols = f->n + 1;
    CHECK_RESULT(rad_save_memory(f->P, &M, NULL, NULL, NULL, &buf, &sz), RAD_ERROR_SIZE_MISMATCH);
    M = f->ffs->matrix; M.values = NULL;
    CHECK_RESULT(rad_save_memory(f->P, &M, NULL, NULL, NULL, &buf, &sz), RAD_ERROR_INVALID_ARGUMENT);
    M = f->ffd->matrix; M.storage = (rad_storage)9;
    CHECK_RESULT(rad_save_memory(f->P, &M, NULL, NULL, NULL, &buf, &sz), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(buf == NULL && sz == 0);
    /* load */
    CHECK_RESULT(rad_load_memory(f->bytes, f->size, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_load_memory(NULL, f->size, NULL, &b), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(b == NULL);
    b = API_SENTINEL(rad_bake);
    CHECK_RESULT(rad_load_memory(f->bytes, 0, NULL, &b), RAD_ERROR_TRUNCATED);
    CHECK(b == NULL);
    b = API_SENTINEL(rad_bake);
    CHECK_RESULT(rad_load_memory(f->bytes, f->size / 2, NULL, &b), RAD_ERROR_TRUNCATED);
    CHECK(b == NULL);
#ifndef RAD_NO_STDIO
    CHECK_RESULT(rad_save_file(NULL, f->P, NULL, NULL, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_save_file("/nonexistent-dir-rad-test/x.radb", NULL, NULL, NULL, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_save_file("/nonexistent-dir-rad-test/x.radb", f->P, NULL, NULL, NULL, NULL), RAD_ERROR_IO);
    CHECK_RESULT(rad_load_file(NULL, NULL, &b), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(b == NULL);
    CHECK_RESULT(rad_load_file("/nonexistent-dir-rad-test/x.radb", NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    b = API_SENTINEL(rad_bake);
    CHECK_RESULT(rad_load_file("/nonexistent-dir-rad-test/x.radb", NULL, &b), RAD_ERROR_IO);
    CHECK(b == NULL);
#endif
}

static const api_case api_cases_bake[] = {
    { "rad_container_* arguments", api_container_args },
    { "rad_save_* / rad_load_* arguments", api_bake_args },
    { NULL, NULL }
};

/* ---- context hooks: cancel, raycaster errors, lone allocator callbacks ---------------------- */

static int api_cancel_now(void *user, float fraction)
{
    (void)fraction;
    ++*(int *)user;
    return 1;
}

static rad_result api_rc_fail_occ(void *user, const rad_ray *rays, uint32_t count, uint8_t *out)
{
    (void)user; (void)rays; (void)count; (void)out;
    return RAD_ERROR_OUT_OF_MEMORY;
}

static rad_result api_rc_fail_hit(void *user, const rad_ray *rays, uint32_t count, rad_hit *out)
{
    (void)user; (void)rays; (void)count; (void)out;
    return RAD_ERROR_OUT_OF_MEMORY;
}

static void *api_lone_alloc(void *user, size_t size) { ++*(int *)user; return malloc(size); }

static void api_hooks(api_fx *f)
{
    rad_context ctx;
    rad_form_factors *ff;
    rad_raycaster bad;
    rad_solve_options so;
    rad_light l;
    size_t n3 = 3 * (size_t)f->n;
    int calls = 0;
    rad_result r;
    /* cancel: CANCELLED, nothing returned */
    memset(&ctx, 0, sizeof(ctx));
    ctx.progress = api_cancel_now;
    ctx.progress_user = &calls;
    ff = API_SENTINEL(rad_form_factors);
    CHECK_RESULT(rad_form_factors_dense(f->P, &f->rc, NULL, &ctx, &ff), RAD_ERROR_CANCELLED);
    CHECK(ff == NULL);
    ff = API_SENTINEL(rad_form_factors);
    CHECK_RESULT(rad_form_factors_sparse(f->P, &f->rc, NULL, &ctx, &ff), RAD_ERROR_CANCELLED);
    CHECK(ff == NULL);
    /* after a cancel the output arrays are unspecified (MEMORY): only the result is checked */
    api_fill(f->buf, f->buf_len);
    CHECK_RESULT(rad_form_factor_rows(f->P, &f->rc, NULL, 0, f->n, f->buf, &ctx), RAD_ERROR_CANCELLED);
    rad_solve_options_default(&so);
    api_fill(f->buf, n3);
    CHECK_RESULT(rad_solve_jacobi(&f->sys, &so, f->buf, NULL, &ctx), RAD_ERROR_CANCELLED);
    api_light_point(&l);
    api_fill(f->buf, n3);
    r = rad_direct_patches(f->P, &f->rc, &l, 1, NULL, f->buf, &ctx);
    CHECK(r == RAD_ERROR_CANCELLED);
    CHECK(calls > 0);
    /* a raycaster that fails: RAYCAST_FAILED (output arrays unspecified afterwards) */
    bad.user = NULL;
    bad.occluded = api_rc_fail_occ;
    bad.intersect = api_rc_fail_hit;
    ff = API_SENTINEL(rad_form_factors);
    CHECK_RESULT(rad_form_factors_dense(f->P, &bad, NULL, NULL, &ff), RAD_ERROR_RAYCAST_FAILED);
    CHECK(ff == NULL);
    ff = API_SENTINEL(rad_form_factors);
    CHECK_RESULT(rad_form_factors_sparse(f->P, &bad, NULL, NULL, &ff), RAD_ERROR_RAYCAST_FAILED);
    CHECK(ff == NULL);
    api_fill(f->buf, f->buf_len);
    CHECK_RESULT(rad_form_factor_rows(f->P, &bad, NULL, 0, 2, f->buf, NULL), RAD_ERROR_RAYCAST_FAILED);
    api_fill(f->buf, n3);
    CHECK_RESULT(rad_direct_patches(f->P, &bad, &l, 1, NULL, f->buf, NULL), RAD_ERROR_RAYCAST_FAILED);
    {
        float pts[3] = { 0.27f, 0.01f, 0.27f }, nrm[3] = { 0, 1, 0 };
        api_fill(f->buf, n3);
        CHECK_RESULT(rad_direct_irradiance(f->scene, &bad, &l, 1, NULL, pts, nrm, 1, f->buf, NULL), RAD_ERROR_RAYCAST_FAILED);
    }
    /* an allocator with alloc but no free is ignored (both or neither), so nothing leaks into it */
    memset(&ctx, 0, sizeof(ctx));
    calls = 0;
    ctx.allocator.alloc = api_lone_alloc;
    ctx.allocator.user = &calls;
    ff = NULL;
    CHECK_OK(rad_form_factors_dense(f->P, &f->rc, NULL, &ctx, &ff));
    rad_form_factors_destroy(ff);
    CHECK(calls == 0);
    /* absurd task counts */
    memset(&ctx, 0, sizeof(ctx));
    ctx.task_count = 0xFFFFFFFFu;
    ff = NULL;
    CHECK_OK(rad_form_factors_sparse(f->P, &f->rc, NULL, &ctx, &ff));
    rad_form_factors_destroy(ff);
    CHECK_OK(rad_solve_jacobi(&f->sys, &so, f->buf, NULL, &ctx));
}

static const api_case api_cases_hooks[] = {
    { "cancel, failing raycaster, allocator, task_count", api_hooks },
    { NULL, NULL }
};

static void api_test_core(void) { api_run_cases(api_cases_core); }
static void api_test_scene(void) { api_run_cases(api_cases_scene); }
static void api_test_geometry(void) { api_run_cases(api_cases_geometry); }
static void api_test_formfactor(void) { api_run_cases(api_cases_ff); }
static void api_test_solve(void) { api_run_cases(api_cases_solve); }
static void api_test_light(void) { api_run_cases(api_cases_light); }
static void api_test_bake(void) { api_run_cases(api_cases_bake); }
static void api_test_hooks(void) { api_run_cases(api_cases_hooks); }

static const rad_test_case tests_api[] = {
    { "api_core", api_test_core },
    { "api_scene", api_test_scene },
    { "api_patches_bvh", api_test_geometry },
    { "api_formfactor", api_test_formfactor },
    { "api_solve", api_test_solve },
    { "api_light", api_test_light },
    { "api_bake", api_test_bake },
    { "api_hooks", api_test_hooks },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_api)
