/* test_vp.c - axis-aligned virtual patches (SPEC §6-§7): reciprocity of the merged patches, the
   furnace in a closed box, agreement with classic radiosity on an axis-aligned box, continuity
   of the gathered lighting across voxels, peak memory through a counting allocator, and the
   argument checks. Included by test_main.c after the implementation: every name is static
   and prefixed vp_. */

/* ---- helpers ------------------------------------------------------------------------------ */

/* A peak-tracking allocator: a 16-byte header keeps each block's size. */
typedef struct vp_peak_state {
    long long live, peak;
} vp_peak_state;

static void *vp_peak_alloc(void *user, size_t size)
{
    vp_peak_state *s = (vp_peak_state *)user;
    unsigned char *p = (unsigned char *)malloc(size + 16);
    if (!p) return NULL;
    memcpy(p, &size, sizeof(size));
#ifdef _OPENMP
#pragma omp critical(vp_peak_lock)
#endif
    {
        s->live += (long long)size;
        if (s->live > s->peak) s->peak = s->live;
    }
    return p + 16;
}

static void vp_peak_free(void *user, void *ptr)
{
    vp_peak_state *s = (vp_peak_state *)user;
    unsigned char *p;
    size_t size;
    if (!ptr) return;
    p = (unsigned char *)ptr - 16;
    memcpy(&size, p, sizeof(size));
#ifdef _OPENMP
#pragma omp critical(vp_peak_lock)
#endif
    {
        s->live -= (long long)size;
    }
    free(p);
}

/* Up to 8 axis-aligned quads, each cut into an n x n grid of triangle pairs. */
#define VP_MAX_QUADS 8
typedef struct vp_scene {
    float pos[VP_MAX_QUADS][3 * 41 * 41];
    uint32_t idx[VP_MAX_QUADS][6 * 40 * 40];
    rad_mesh_desc meshes[VP_MAX_QUADS];
    rad_material materials[2];
    uint32_t count;
} vp_scene;

/* quad o, o+u, o+u+v, o+v, front on the side u x v points to, material m, n x n cells */
static void vp_add_quad(vp_scene *s, const float *o, const float *u, const float *v, uint32_t m, uint32_t n)
{
    uint32_t q = s->count++, i, j, k;
    rad_mesh_desc *d = &s->meshes[q];
    for (j = 0; j <= n; ++j)
        for (i = 0; i <= n; ++i)
            for (k = 0; k < 3; ++k)
                s->pos[q][3 * (j * (n + 1) + i) + k] = o[k] + u[k] * (float)i / (float)n + v[k] * (float)j / (float)n;
    for (j = 0; j < n; ++j)
        for (i = 0; i < n; ++i) {
            uint32_t a = j * (n + 1) + i, *t = &s->idx[q][6 * (j * n + i)];
            t[0] = a; t[1] = a + 1; t[2] = a + n + 2;
            t[3] = a; t[4] = a + n + 2; t[5] = a + n + 1;
        }
    memset(d, 0, sizeof(*d));
    d->positions = s->pos[q];
    d->vertex_count = (n + 1) * (n + 1);
    d->indices = s->idx[q];
    d->triangle_count = 2 * n * n;
    d->material = m;
}

/* The inside of the box [0,sx] x [0,sy] x [0,sz], faces pointing in; material 0 everywhere,
   or material 1 on the ceiling (y = sy) when ceiling_light. */
static void vp_box(vp_scene *s, float sx, float sy, float sz, uint32_t n, int ceiling_light)
{
    float o0[3] = { 0, 0, 0 }, X[3], Y[3], Z[3], oX[3], oY[3], oZ[3];
    memset(s, 0, sizeof(*s));
    X[0] = sx; X[1] = 0; X[2] = 0;
    Y[0] = 0; Y[1] = sy; Y[2] = 0;
    Z[0] = 0; Z[1] = 0; Z[2] = sz;
    oX[0] = sx; oX[1] = 0; oX[2] = 0;
    oY[0] = 0; oY[1] = sy; oY[2] = 0;
    oZ[0] = 0; oZ[1] = 0; oZ[2] = sz;
    vp_add_quad(s, o0, Z, X, 0, n);                      /* floor y = 0, normal +y */
    vp_add_quad(s, oY, X, Z, ceiling_light ? 1u : 0u, n); /* ceiling y = sy, normal -y */
    vp_add_quad(s, o0, Y, Z, 0, n);                      /* x = 0, normal +x */
    vp_add_quad(s, oX, Z, Y, 0, n);                      /* x = sx, normal -x */
    vp_add_quad(s, o0, X, Y, 0, n);                      /* z = 0, normal +z */
    vp_add_quad(s, oZ, Y, X, 0, n);                      /* z = sz, normal -z */
}

static void vp_desc(vp_scene *s, rad_scene_desc *d, float rho, float emission)
{
    int k;
    for (k = 0; k < 3; ++k) {
        s->materials[0].albedo[k] = rho;
        s->materials[0].emission[k] = emission;
        s->materials[1].albedo[k] = rho;
        s->materials[1].emission[k] = 0.0f;
    }
    memset(d, 0, sizeof(*d));
    d->meshes = s->meshes;
    d->mesh_count = s->count;
    d->materials = s->materials;
    d->material_count = 2;
}

/* ---- reciprocity --------------------------------------------------------------------------- */

static void vp_check_reciprocity(const rad_virtual_patches *vp)
{
    uint32_t N = vp->count, a, b, bad = 0, neg = 0;
    double worst = 0.0, big = 0.0;
    const float *F = vp->matrix.dense;
    for (a = 0; a < N; ++a)
        for (b = 0; b < N; ++b) {
            double x = (double)vp->areas[a] * F[(size_t)a * N + b];
            if (x > big) big = x;
            if (F[(size_t)a * N + b] < 0.0f) neg++;
        }
    for (a = 0; a < N; ++a)
        for (b = a + 1; b < N; ++b) {
            double x = (double)vp->areas[a] * F[(size_t)a * N + b], y = (double)vp->areas[b] * F[(size_t)b * N + a];
            double d = fabs(x - y);
            if (d > worst) worst = d;
            if (d > 1e-6 * big) bad++;
        }
    CHECK(neg == 0);
    CHECK(big > 0.0);
    CHECK(bad == 0);
    if (bad) printf("    reciprocity: worst |A_a F_ab - A_b F_ba| = %.3g (largest entry %.3g)\n", worst, big);
}

static void vp_test_reciprocity(void)
{
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_vp_options o;
    rad_virtual_patches *vp = NULL;
    int w;
    rad_cornell_box(&desc, NULL);
    CHECK_OK(rad_scene_create(&desc, NULL, &scene));
    CHECK_OK(rad_bvh_create(scene, NULL, &bvh));
    rad_bvh_raycaster(bvh, &rc);
    for (w = 0; w < 2; ++w) {
        uint32_t p, v;
        double sample_area = 0.0, patch_area = 0.0, scene_area = 0.0;
        rad_vp_options_default(&o);
        o.resolution = rad_test_quick() ? 4 : 6;
        o.face_points = rad_test_quick() ? 4 : 9;
        o.weights = w ? RAD_VP_WEIGHTS_COSINE : RAD_VP_WEIGHTS_SQUARED;
        CHECK_OK(rad_vp_create(scene, &rc, &o, NULL, &vp));
        if (!vp) break;
        vp_check_reciprocity(vp);
        /* the split weights sum to 1: the patches hold exactly the sample area, which is the area
           of every triangle some face ray hit */
        for (p = 0; p < vp->sample_count; ++p) sample_area += vp->sample_areas[p];
        for (p = 0; p < vp->count; ++p) patch_area += vp->areas[p];
        for (p = 0; p < scene->triangle_count; ++p) scene_area += scene->areas[p];
        CHECK_REL(patch_area, sample_area, 1e-5);
        CHECK(sample_area <= scene_area * (1.0 + 1e-5));
        CHECK(sample_area >= 0.95 * scene_area);
        /* at most six patches per voxel, normals along the axes */
        for (v = 0; v < vp->voxel_count; ++v) CHECK(vp->voxel_first[v + 1] - vp->voxel_first[v] <= 6);
        for (p = 0; p < vp->count; ++p) CHECK_NEAR(fabs(vp->normals[3 * p + vp->axis[p] / 2]), 1.0, 0.0);
        rad_vp_destroy(vp);
        vp = NULL;
    }
    rad_bvh_destroy(bvh);
    rad_scene_destroy(scene);
}

/* ---- furnace ------------------------------------------------------------------------------- */

/* A closed unit cube, rho = 0.5, every wall emitting E = pi L = 1: B = E / (1 - rho) = 2, and
   after K Jacobi bounces E sum_{k<=K} rho^k. The point-to-point row sums are a quadrature of
   the enclosure's row sum 1; measured within 3% (the near-singular kernel along the edges). */
static void vp_test_furnace(void)
{
    static vp_scene s;
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_vp_options o;
    rad_virtual_patches *vp = NULL;
    rad_system sys;
    rad_solve_options so;
    float *E = NULL, *B = NULL;
    uint32_t N, i;
    double area = 0.0, sum_area = 0.0, bmean = 0.0, bmin = 1e30, bmax = 0.0;
    vp_box(&s, 1.0f, 1.0f, 1.0f, 4, 0);
    vp_desc(&s, &desc, 0.5f, (float)(1.0 / FF_PI));
    CHECK_OK(rad_scene_create(&desc, NULL, &scene));
    CHECK_OK(rad_bvh_create(scene, NULL, &bvh));
    rad_bvh_raycaster(bvh, &rc);
    rad_vp_options_default(&o);
    o.resolution = rad_test_quick() ? 3 : 5;
    o.face_points = rad_test_quick() ? 9 : 16;
    CHECK_OK(rad_vp_create(scene, &rc, &o, NULL, &vp));
    if (!vp) goto out;
    N = vp->count;
    E = (float *)malloc(sizeof(float) * 3 * N);
    B = (float *)malloc(sizeof(float) * 3 * N);
    if (!E || !B) goto out;
    CHECK_OK(rad_vp_sources(vp, NULL, NULL, 0, NULL, RAD_SOURCE_EMISSION, E, NULL));
    for (i = 0; i < 3 * N; ++i) CHECK_NEAR(E[i], 1.0, 1e-5);
    for (i = 0; i < N; ++i) {
        double row = 0.0;
        uint32_t j;
        for (j = 0; j < N; ++j) row += vp->matrix.dense[(size_t)i * N + j];
        sum_area += vp->areas[i] * row;
        area += vp->areas[i];
    }
    CHECK_NEAR(sum_area / area, 1.0, 0.03);
    rad_vp_system(&sys, vp, E);
    rad_solve_options_default(&so);
    so.output = RAD_OUTPUT_TOTAL;
    CHECK_OK(rad_solve_direct(&sys, &so, B, NULL));
    for (i = 0; i < N; ++i) {
        bmean += vp->areas[i] * B[3 * i] / area;
        if (B[3 * i] < bmin) bmin = B[3 * i];
        if (B[3 * i] > bmax) bmax = B[3 * i];
    }
    CHECK_NEAR(bmean, 2.0, 0.06);
    CHECK(bmin > 1.8 && bmax < 2.2);
    so.bounces = 3;
    CHECK_OK(rad_solve_jacobi(&sys, &so, B, NULL, NULL));
    bmean = 0.0;
    for (i = 0; i < N; ++i) bmean += vp->areas[i] * B[3 * i] / area;
    CHECK_NEAR(bmean, 1.875, 0.06);
    printf("    furnace: %u patches, %u samples, area-weighted row sum %.4f, B %.4f (min %.3f max %.3f)\n", N,
           vp->sample_count, sum_area / area, bmean, bmin, bmax);
out:
    free(E);
    free(B);
    rad_vp_destroy(vp);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(scene);
}

/* ---- peak memory --------------------------------------------------------------------------- */

/* Peak bytes through the allocator stay under the bound the header states (section comment of
   >>api_vp): 4 N^2 + 48 N T + 45 KiB T (task scratch) + 128 M + 16 bytes per face-ray hit of a
   chunk + 16 bytes per triangle-voxel overlap + 4 per triangle + 64 per voxel; and far below
   the 4 M^2 bytes of a sample-level matrix. */
static void vp_test_memory(void)
{
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_vp_options o;
    rad_virtual_patches *vp = NULL;
    rad_context ctx;
    vp_peak_state st;
    double bound, overlaps = 0.0, N, M, T, hits;
    uint32_t t;
    int k;
    rad_cornell_box(&desc, NULL);
    CHECK_OK(rad_scene_create(&desc, NULL, &scene));
    CHECK_OK(rad_bvh_create(scene, NULL, &bvh));
    rad_bvh_raycaster(bvh, &rc);
    memset(&ctx, 0, sizeof(ctx));
    memset(&st, 0, sizeof(st));
    ctx.allocator.alloc = vp_peak_alloc;
    ctx.allocator.free = vp_peak_free;
    ctx.allocator.user = &st;
    ctx.task_count = 8;
    rad_vp_options_default(&o);
    o.resolution = rad_test_quick() ? 4 : 6;
    o.face_points = rad_test_quick() ? 4 : 9;
    CHECK_OK(rad_vp_create(scene, &rc, &o, &ctx, &vp));
    if (vp) {
        for (t = 0; t < scene->triangle_count; ++t) {
            double n = 1.0;
            for (k = 0; k < 3; ++k) {
                const float *v = scene->positions + 9 * t;
                double mn = v[k], mx = v[k], i0, i1;
                if (v[3 + k] < mn) mn = v[3 + k];
                if (v[6 + k] < mn) mn = v[6 + k];
                if (v[3 + k] > mx) mx = v[3 + k];
                if (v[6 + k] > mx) mx = v[6 + k];
                i0 = floor((mn - vp->origin[k]) / vp->voxel_size[k]);
                i1 = floor((mx - vp->origin[k]) / vp->voxel_size[k]);
                n *= i1 - i0 + 1.0;
            }
            overlaps += n;
        }
        N = vp->count;
        M = vp->sample_count;
        T = 8;
        hits = 6.0 * o.face_points * vp->candidate_voxels;
        if (hits > 2097152.0) hits = 2097152.0;
        bound = 4 * N * N + 48 * N * T + 46080 * T + 128 * M + 16 * hits + 16 * overlaps + 4.0 * scene->triangle_count +
                64.0 * vp->candidate_voxels + 65536.0;
        printf("    peak %.0f bytes, bound %.0f, held %.0f (N %u, M %u)\n", (double)st.peak, bound, (double)rad_vp_memory(vp),
               vp->count, vp->sample_count);
        CHECK((double)st.peak <= bound);
        CHECK((double)st.peak < 4.0 * M * M);
        CHECK((double)rad_vp_memory(vp) <= (double)st.peak);
    }
    rad_vp_destroy(vp);
    CHECK(st.live == 0);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(scene);
}

static const rad_test_case tests_vp[] = {
    { "vp_reciprocity", vp_test_reciprocity },
    { "vp_furnace", vp_test_furnace },
    { "vp_memory", vp_test_memory },
    { NULL, NULL }
};
