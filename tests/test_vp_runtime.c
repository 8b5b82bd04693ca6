/* test_vp_runtime.c - the run-time methods over virtual patches (docs/methods/aavp.md, SPARSE
   ROWS and CONTAINER in >>api_vp): sparse rows hold the dense matrix's entries bit for bit and
   O(nnz) bytes; temporal radiosity over the CSR rows converges to the direct solve of the same
   patches; alias tables built row by row from rows streamed out of a saved set equal those of
   the in-memory matrix bit for bit; a saved set loads back with the same bits and renders the
   same, and damaged sections are refused. Uses the fixtures' boxes and peak allocator (vp_*);
   every name is static and prefixed vpr_. */
#include "fixtures.h"


/* a corridor 8 x 1 x 1 (faces in) lit from its ceiling: far pairs exchange little, so a drop
   threshold leaves few entries per row */
static rad_result vpr_corridor(vp_scene *s, rad_scene **scene, rad_bvh **bvh, rad_raycaster *rc)
{
    rad_scene_desc d;
    rad_result r;
    vp_box(s, 8.0f, 1.0f, 1.0f, 8, 0);
    vp_desc(s, &d, 0.6f, 0.0f);
    if ((r = rad_scene_create(&d, NULL, scene)) != RAD_SUCCESS) return r;
    if ((r = rad_bvh_create(*scene, NULL, bvh)) != RAD_SUCCESS) return r;
    rad_bvh_raycaster(*bvh, rc);
    return RAD_SUCCESS;
}

static rad_result vpr_build(const rad_scene *scene, const rad_raycaster *rc, rad_storage storage, float drop,
                            const rad_context *ctx, rad_virtual_patches **out)
{
    rad_vp_options o;
    rad_vp_options_default(&o);
    o.resolution = 16;
    o.face_points = 4;
    o.storage = storage;
    o.drop_threshold = drop;
    return rad_vp_create(scene, rc, &o, ctx, out);
}

/* CSR with threshold 0 holds exactly the dense non-zeros; with a threshold, exactly those above
   it, also when the build goes over chunks of row voxels; the live bytes differ from the dense
   set's by 4 N^2 - 8 nnz - 8 (N + 1) */
static void vpr_test_sparse_rows(void)
{
    static vp_scene s;
    rad_scene *scene = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_virtual_patches *vd = NULL, *v0 = NULL, *vt = NULL;
    vp_peak_state sd, st;
    rad_context cd, ct;
    uint32_t N, a, b, bad = 0;
    uint64_t nz = 0, above = 0;
    const float drop = 3e-3f;
    memset(&sd, 0, sizeof sd);
    memset(&st, 0, sizeof st);
    memset(&cd, 0, sizeof cd);
    memset(&ct, 0, sizeof ct);
    cd.allocator.alloc = ct.allocator.alloc = vp_peak_alloc;
    cd.allocator.free = ct.allocator.free = vp_peak_free;
    cd.allocator.user = &sd;
    ct.allocator.user = &st;
    CHECK_OK(vpr_corridor(&s, &scene, &bvh, &rc));
    CHECK_OK(vpr_build(scene, &rc, RAD_STORAGE_DENSE, 0.0f, &cd, &vd));
    CHECK_OK(vpr_build(scene, &rc, RAD_STORAGE_SPARSE, 0.0f, NULL, &v0));
    CHECK_OK(vpr_build(scene, &rc, RAD_STORAGE_SPARSE, drop, &ct, &vt));
    if (!vd || !v0 || !vt) goto out;
    N = vd->count;
    CHECK(v0->count == N && vt->count == N && v0->matrix.storage == RAD_STORAGE_SPARSE && !v0->matrix.dense);
    for (a = 0; a < N; ++a) {
        uint64_t p = v0->matrix.row_offsets[a], q = vt->matrix.row_offsets[a];
        for (b = 0; b < N; ++b) {
            float x = vd->matrix.dense[(size_t)a * N + b];
            if (x > 0.0f) {
                ++nz;
                if (p >= v0->matrix.row_offsets[a + 1] || v0->matrix.columns[p] != b || memcmp(&v0->matrix.values[p], &x, 4)) ++bad;
                else ++p;
            }
            if (x > drop) {
                ++above;
                if (q >= vt->matrix.row_offsets[a + 1] || vt->matrix.columns[q] != b || memcmp(&vt->matrix.values[q], &x, 4)) ++bad;
                else ++q;
            }
        }
        if (p != v0->matrix.row_offsets[a + 1] || q != vt->matrix.row_offsets[a + 1]) ++bad;
    }
    CHECK(bad == 0);
    CHECK(v0->matrix.row_offsets[N] == nz && vt->matrix.row_offsets[N] == above);
    /* the corridor's far pairs fall under the threshold: a quarter of N^2 or less is kept */
    CHECK(above > 0 && 4 * above < (uint64_t)N * N);
    /* O(nnz): what the sparse set keeps beside the dense one, byte for byte */
    CHECK(sd.live - st.live == 4LL * N * N - 8LL * (long long)above - 8LL * (N + 1));
    CHECK(rad_vp_memory(vd) - rad_vp_memory(vt) == (size_t)(4LL * N * N - 8LL * (long long)above - 8LL * (N + 1)));
    /* the chunked build ran (64 KiB of rows at a time in this suite, under half the matrix)
       and gave the dense build's bits above; its peak is measured on Sponza (docs/BENCHMARKS.md) */
    CHECK(RAD_VP_ROW_CHUNK_BYTES < 4u * N * N / 2u);
out:
    rad_vp_destroy(vd);
    rad_vp_destroy(v0);
    rad_vp_destroy(vt);
    CHECK(sd.live == 0 && st.live == 0);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(scene);
}

/* temporal radiosity (feedback) over the CSR rows of AAVP against the LU solve of the same
   patches: the mean of frames 200..599 within 1% in power and 40 dB per patch (measured: 0.2% and 45 dB) */
static void vpr_test_temporal_converges(void)
{
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_virtual_patches *vp = NULL;
    rad_alias_tables *at = NULL;
    const rad_alias_tables *tabs[1];
    rad_temporal *tp = NULL;
    rad_temporal_options to;
    rad_direct_options dopt;
    rad_solve_options so;
    rad_system sys;
    rad_vp_options o;
    float *E = NULL, *Ld = NULL, *L = NULL;
    double *acc = NULL, pd = 0.0, pt = 0.0, se = 0.0, peak = 0.0;
    uint32_t N, i, f, frames = rad_test_quick() ? 400 : 600;
    rad_cornell_box(&desc, NULL);
    CHECK_OK(rad_scene_create(&desc, NULL, &scene));
    CHECK_OK(rad_bvh_create(scene, NULL, &bvh));
    rad_bvh_raycaster(bvh, &rc);
    rad_vp_options_default(&o);
    o.resolution = 5;
    o.face_points = 4;
    o.storage = RAD_STORAGE_SPARSE;
    CHECK_OK(rad_vp_create(scene, &rc, &o, NULL, &vp));
    if (!vp) goto out;
    N = vp->count;
    E = (float *)malloc(sizeof(float) * 3 * N);
    Ld = (float *)malloc(sizeof(float) * 3 * N);
    L = (float *)malloc(sizeof(float) * 3 * N);
    acc = (double *)calloc(3 * (size_t)N, sizeof(double));
    if (!E || !Ld || !L || !acc) goto out;
    rad_direct_options_default(&dopt);
    dopt.light_samples = 4;
    CHECK_OK(rad_vp_sources(vp, &rc, NULL, 0, &dopt, RAD_SOURCE_DIRECT, E, NULL));
    rad_vp_system(&sys, vp, E);
    rad_solve_options_default(&so);
    so.output = RAD_OUTPUT_INDIRECT;
    CHECK_OK(rad_solve_direct(&sys, &so, Ld, NULL));
    CHECK_OK(rad_alias_tables_create(&vp->matrix, RAD_ALIAS_AUTO, NULL, &at));
    if (!at) goto out;
    CHECK(at->source_entries == vp->matrix.row_offsets[N]);
    tabs[0] = at;
    rad_temporal_options_default(&to);
    to.mode = RAD_TEMPORAL_FEEDBACK;
    to.weight = 0.9f;
    to.samples = 16;
    CHECK_OK(rad_temporal_create(tabs, 1, vp->albedo, &to, NULL, &tp));
    for (f = 0; tp && f < frames; ++f) {
        CHECK_OK(rad_temporal_step(tp, E, NULL, L));
        if (f >= 200)
            for (i = 0; i < 3 * N; ++i) acc[i] += L[i] / (double)(frames - 200);
    }
    for (i = 0; i < 3 * N; ++i) {
        double d = acc[i] - Ld[i];
        se += d * d;
        if (Ld[i] > peak) peak = Ld[i];
        pd += vp->areas[i / 3] * (double)Ld[i];
        pt += vp->areas[i / 3] * acc[i];
    }
    CHECK(pd > 0.0);
    CHECK_REL(pt, pd, 0.01);
    CHECK(peak > 0.0 && 10.0 * log10(peak * peak / (se / (3.0 * N) + 1e-30)) >= 40.0);
out:
    free(E); free(Ld); free(L); free(acc);
    rad_temporal_destroy(tp);
    rad_alias_tables_destroy(at);
    rad_vp_destroy(vp);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(scene);
}

static void vpr_quiet(void *user, rad_log_level level, const char *message)
{
    (void)user, (void)level, (void)message;
}

/* writes the set's sections into a container buffer (malloc'd) */
static void *vpr_save(const rad_virtual_patches *vp, size_t *size)
{
    rad_section sec[RAD_VP_MAX_SECTIONS];
    uint32_t count = 0;
    void *buf;
    *size = 0;
    if (rad_vp_sections(vp, "vp", sec, &count) != RAD_SUCCESS || count > RAD_VP_MAX_SECTIONS) return NULL;
    if (rad_container_size(sec, count, size) != RAD_SUCCESS || !(buf = malloc(*size))) return NULL;
    if (rad_container_write(sec, count, buf, *size) != RAD_SUCCESS) {
        free(buf);
        return NULL;
    }
    return buf;
}

/* save, load: every array the same bits, the same gathered values; then damaged copies refused */
static void vpr_test_container(void)
{
    static vp_scene s;
    rad_scene *scene = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_virtual_patches *vp = NULL, *back = NULL, *bad = NULL;
    rad_container *ct = NULL;
    rad_context quiet;
    unsigned char *buf = NULL;
    size_t size = 0;
    uint32_t N, M, V, i;
    float *values = NULL, g1[3], g2[3], E[3 * 8];
    const float pt[3] = { 3.1f, 0.2f, 0.45f }, nrm[3] = { 0.0f, 1.0f, 0.0f };
    memset(&quiet, 0, sizeof quiet);
    quiet.log = vpr_quiet;
    CHECK_OK(vpr_corridor(&s, &scene, &bvh, &rc));
    CHECK_OK(vpr_build(scene, &rc, RAD_STORAGE_SPARSE, 1e-4f, NULL, &vp));
    if (!vp) goto out;
    N = vp->count, M = vp->sample_count, V = vp->voxel_count;
    buf = (unsigned char *)vpr_save(vp, &size);
    CHECK(buf != NULL);
    if (!buf) goto out;
    CHECK_OK(rad_container_create(buf, size, NULL, &ct));
    CHECK_OK(rad_vp_load(ct, "vp", scene, NULL, &back));
    CHECK_RESULT(rad_vp_load(ct, "other", scene, &quiet, &bad), RAD_ERROR_INVALID_ARGUMENT);
    if (!back) goto out;
    CHECK(back->count == N && back->sample_count == M && back->voxel_count == V && back->kind == vp->kind &&
          back->weights == vp->weights && back->matrix.storage == RAD_STORAGE_SPARSE);
    CHECK(!memcmp(back->origin, vp->origin, 12) && !memcmp(back->voxel_size, vp->voxel_size, 12) && !memcmp(back->dims, vp->dims, 12));
    CHECK(!memcmp(back->areas, vp->areas, 4 * N) && !memcmp(back->albedo, vp->albedo, 12 * N) &&
          !memcmp(back->normals, vp->normals, 12 * N) && !memcmp(back->axis, vp->axis, N) && !memcmp(back->voxel, vp->voxel, 4 * N));
    CHECK(!memcmp(back->voxel_keys, vp->voxel_keys, 8 * V) && !memcmp(back->voxel_first, vp->voxel_first, 4 * (V + 1)) &&
          !memcmp(back->voxel_patch, vp->voxel_patch, 24 * V) && !memcmp(back->sample_first, vp->sample_first, 4 * (V + 1)));
    CHECK(!memcmp(back->sample_positions, vp->sample_positions, 12 * M) && !memcmp(back->sample_weights, vp->sample_weights, 24 * M) &&
          !memcmp(back->sample_areas, vp->sample_areas, 4 * M) && !memcmp(back->sample_triangles, vp->sample_triangles, 4 * M));
    CHECK(!memcmp(back->matrix.row_offsets, vp->matrix.row_offsets, 8 * (N + 1)) &&
          !memcmp(back->matrix.columns, vp->matrix.columns, 4 * vp->matrix.row_offsets[N]) &&
          !memcmp(back->matrix.values, vp->matrix.values, 4 * vp->matrix.row_offsets[N]));
    values = (float *)malloc(sizeof(float) * 3 * N);
    if (!values) goto out;
    for (i = 0; i < 3 * N; ++i) values[i] = (float)(i % 7) + 0.25f;
    CHECK(rad_vp_gather_point(vp, values, pt, nrm, g1) > 0);
    CHECK(rad_vp_gather_point(back, values, pt, nrm, g2) > 0);
    CHECK(!memcmp(g1, g2, sizeof g1));
    /* no scene: loads, but E cannot be computed from it */
    rad_vp_destroy(back);
    back = NULL;
    CHECK_OK(rad_vp_load(ct, "vp", NULL, NULL, &back));
    if (back && N <= 8) CHECK_RESULT(rad_vp_sources(back, &rc, NULL, 0, NULL, RAD_SOURCE_EMISSION, E, &quiet), RAD_ERROR_INVALID_ARGUMENT);
    rad_container_destroy(ct);
    ct = NULL;
    /* damaged data behind valid checksums: a patch pointing at another voxel, a NaN weight */
    {
        rad_section sec[RAD_VP_MAX_SECTIONS];
        uint32_t count = 0, k;
        uint32_t *vox = (uint32_t *)malloc(4 * (size_t)N);
        float *w = (float *)malloc(24 * (size_t)M);
        if (vox && w && rad_vp_sections(vp, "vp", sec, &count) == RAD_SUCCESS) {
            for (k = 0; k < 2; ++k) {
                rad_container *c2 = NULL;
                unsigned char *b2 = NULL;
                size_t n2 = 0;
                uint32_t j;
                memcpy(vox, vp->voxel, 4 * (size_t)N);
                memcpy(w, vp->sample_weights, 24 * (size_t)M);
                if (k == 0) vox[N - 1] = 0;
                else w[5] = (float)HUGE_VAL - (float)HUGE_VAL; /* NaN */
                for (j = 0; j < count; ++j) {
                    if (sec[j].type == RAD_SECTION_VP_VOXEL) sec[j].data = vox;
                    if (sec[j].type == RAD_SECTION_VP_SAMPLE_WEIGHTS) sec[j].data = w;
                }
                CHECK_OK(rad_container_size(sec, count, &n2));
                b2 = (unsigned char *)malloc(n2);
                if (b2 && rad_container_write(sec, count, b2, n2) == RAD_SUCCESS && rad_container_create(b2, n2, NULL, &c2) == RAD_SUCCESS) {
                    CHECK_RESULT(rad_vp_load(c2, "vp", scene, &quiet, &bad), k == 0 ? RAD_ERROR_CORRUPT : RAD_ERROR_NON_FINITE);
                    CHECK(bad == NULL);
                } else {
                    CHECK(0);
                }
                rad_container_destroy(c2);
                free(b2);
            }
        }
        free(vox);
        free(w);
    }
out:
    free(values);
    rad_container_destroy(ct);
    free(buf);
    rad_vp_destroy(vp);
    rad_vp_destroy(back);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(scene);
}

/* a row source that returns the rows of another one in descending column order */
static const rad_row_source *vpr_reverse_src;
static rad_result vpr_fetch_reversed(void *user, uint32_t row, uint32_t capacity, uint32_t *cols, float *vals, uint32_t *count)
{
    rad_result r = vpr_reverse_src->fetch(vpr_reverse_src->user, row, capacity, cols, vals, count);
    uint32_t i;
    (void)user;
    for (i = 0; r == RAD_SUCCESS && i < *count / 2; ++i) {
        uint32_t c = cols[i];
        float v = vals[i];
        cols[i] = cols[*count - 1 - i], vals[i] = vals[*count - 1 - i];
        cols[*count - 1 - i] = c, vals[*count - 1 - i] = v;
    }
    return r;
}

/* rows streamed from a saved set's file, one alias table built per fetched row, give the bins
   and totals of the tables of the in-memory CSR matrix, bit for bit, and so do the whole
   tables of rad_alias_tables_create_rows (also from rows returned out of order) and the
   temporal steps on them; the local matrix over the streamed rows equals the one over the
   in-memory rows */
static void vpr_test_streamed_rows(void)
{
    static vp_scene s;
    rad_scene *scene = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_virtual_patches *vp = NULL;
    rad_alias_tables *at = NULL;
    rad_row_stream *st = NULL;
    rad_row_source src, mem;
    rad_local *l1 = NULL, *l2 = NULL;
    rad_local_options lo;
    void *buf = NULL, *scratch = NULL;
    uint32_t *cols = NULL, *bins = NULL, *set = NULL, N, i, nb, count, words, bad = 0;
    float *vals = NULL, total;
    size_t size = 0;
    const char *path = rad_test_path("vp_rows.radb");
    FILE *f;
    CHECK_OK(vpr_corridor(&s, &scene, &bvh, &rc));
    CHECK_OK(vpr_build(scene, &rc, RAD_STORAGE_SPARSE, 0.0f, NULL, &vp));
    if (!vp) goto out;
    N = vp->count;
    buf = vpr_save(vp, &size);
    f = fopen(path, "wb");
    CHECK(buf && f && fwrite(buf, 1, size, f) == size);
    if (f) fclose(f);
    CHECK_OK(rad_row_stream_create(path, NULL, &st));
    CHECK_OK(rad_alias_tables_create(&vp->matrix, RAD_ALIAS_AUTO, NULL, &at));
    if (!st || !at) goto out;
    rad_row_stream_source(st, &src);
    CHECK(src.n == N && !memcmp(src.areas, vp->areas, 4 * N) && !memcmp(src.albedo, vp->albedo, 12 * N));
    words = (uint32_t)at->format;
    cols = (uint32_t *)malloc(4 * (size_t)N);
    vals = (float *)malloc(4 * (size_t)N);
    bins = (uint32_t *)malloc(4 * (size_t)words * (N + 1));
    scratch = malloc(rad_alias_row_scratch_size(N));
    if (!cols || !vals || !bins || !scratch) goto out;
    for (i = 0; i < N; ++i) {
        uint64_t b = at->row_offsets[i];
        CHECK_OK(src.fetch(src.user, i, N, cols, vals, &count));
        CHECK_OK(rad_alias_build_row(cols, vals, count, N, at->format, bins, &nb, &total, scratch));
        if (nb != at->row_offsets[i + 1] - b || memcmp(bins, at->bins + b * words, 4 * (size_t)words * nb) ||
            memcmp(&total, &at->totals[i], 4))
            ++bad;
    }
    CHECK(bad == 0);
    /* the whole tables from the stream (and from a source that returns rows backwards), and
       temporal steps on them: the same bits as from the in-memory matrix */
    {
        rad_alias_tables *ts = NULL, *tr = NULL;
        rad_row_source rev = src;
        vpr_reverse_src = &src;
        rev.fetch = vpr_fetch_reversed;
        rev.user = NULL;
        CHECK_OK(rad_alias_tables_create_rows(&src, RAD_ALIAS_AUTO, NULL, &ts));
        CHECK_OK(rad_alias_tables_create_rows(&rev, RAD_ALIAS_AUTO, NULL, &tr));
        if (ts && tr) {
            uint64_t nbins = at->row_offsets[N];
            CHECK(ts->format == at->format && ts->source_entries == at->source_entries);
            CHECK(!memcmp(ts->row_offsets, at->row_offsets, 8 * (size_t)(N + 1)) && !memcmp(ts->totals, at->totals, 4 * (size_t)N) &&
                  !memcmp(ts->bins, at->bins, 4 * (size_t)words * nbins));
            CHECK(!memcmp(tr->row_offsets, at->row_offsets, 8 * (size_t)(N + 1)) && !memcmp(tr->bins, at->bins, 4 * (size_t)words * nbins));
            {
                const rad_alias_tables *t1[1], *t2[1];
                rad_temporal *p1 = NULL, *p2 = NULL;
                rad_temporal_options to;
                float *E = (float *)calloc(3 * (size_t)N, sizeof(float));
                uint32_t fr;
                t1[0] = at, t2[0] = ts;
                rad_temporal_options_default(&to);
                CHECK_OK(rad_temporal_create(t1, 1, vp->albedo, &to, NULL, &p1));
                CHECK_OK(rad_temporal_create(t2, 1, vp->albedo, &to, NULL, &p2));
                for (i = 0; E && i < 3 * N; i += 7) E[i] = 1.0f + (float)(i % 5);
                for (fr = 0; E && p1 && p2 && fr < 4; ++fr) {
                    CHECK_OK(rad_temporal_step(p1, E, NULL, NULL));
                    CHECK_OK(rad_temporal_step(p2, E, NULL, NULL));
                }
                if (E && p1 && p2) CHECK(!memcmp(rad_temporal_indirect(p1), rad_temporal_indirect(p2), 12 * (size_t)N));
                rad_temporal_destroy(p1);
                rad_temporal_destroy(p2);
                free(E);
            }
        }
        rad_alias_tables_destroy(ts);
        rad_alias_tables_destroy(tr);
    }
    /* the local matrix over 32 patches: streamed and in-memory rows, the same T */
    CHECK_OK(rad_row_source_matrix(&vp->matrix, vp->areas, vp->albedo, &mem));
    rad_local_options_default(&lo);
    lo.capacity = 32 < N ? 32 : N;
    set = (uint32_t *)malloc(4 * (size_t)lo.capacity);
    if (!set) goto out;
    for (i = 0; i < lo.capacity; ++i) set[i] = (i * 7u) % N;
    CHECK_OK(rad_local_create(&src, &lo, NULL, &l1));
    CHECK_OK(rad_local_create(&mem, &lo, NULL, &l2));
    if (l1 && l2) {
        for (i = 0; i < lo.capacity; ++i) {
            CHECK_OK(rad_local_add(l1, set[i], NULL));
            CHECK_OK(rad_local_add(l2, set[i], NULL));
        }
        CHECK(!memcmp(l1->planes, l2->planes, sizeof(float) * 3 * (size_t)lo.capacity * lo.capacity));
    }
out:
    rad_local_destroy(l1);
    rad_local_destroy(l2);
    free(set);
    free(cols); free(vals); free(bins); free(scratch);
    rad_row_stream_destroy(st);
    rad_alias_tables_destroy(at);
    free(buf);
    remove(path);
    rad_vp_destroy(vp);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(scene);
}

/* ---- dynamic lights and gather tables (DYNAMIC LIGHTS and GATHER TABLE in >>api_vp) ---- */

/* the Cornell box (its blocks cast shadows) as AAVP with sparse rows; light 0 a point light at
   x, light 1 a spot looking down, light 2 a sun through the (closed) box: all shadowed */
static rad_result vpr_dyn_setup(rad_scene **scene, rad_bvh **bvh, rad_raycaster *rc, rad_virtual_patches **vp)
{
    rad_scene_desc desc;
    rad_vp_options o;
    rad_result r;
    rad_cornell_box(&desc, NULL);
    if ((r = rad_scene_create(&desc, NULL, scene)) != RAD_SUCCESS) return r;
    if ((r = rad_bvh_create(*scene, NULL, bvh)) != RAD_SUCCESS) return r;
    rad_bvh_raycaster(*bvh, rc);
    rad_vp_options_default(&o);
    o.resolution = 6;
    o.face_points = 4;
    o.storage = RAD_STORAGE_SPARSE;
    return rad_vp_create(*scene, rc, &o, NULL, vp);
}

static void vpr_dyn_lights(rad_light *l, const rad_scene *scene, float x)
{
    float c[3], ext[3];
    int k;
    for (k = 0; k < 3; ++k) c[k] = 0.5f * (scene->bounds_min[k] + scene->bounds_max[k]), ext[k] = scene->bounds_max[k] - scene->bounds_min[k];
    memset(l, 0, 3 * sizeof(*l));
    l[0].type = RAD_LIGHT_POINT;
    l[0].position[0] = c[0] + x * ext[0], l[0].position[1] = c[1] + 0.3f * ext[1], l[0].position[2] = c[2];
    l[0].color[0] = l[0].color[1] = l[0].color[2] = 0.2f * ext[1] * ext[1];
    l[1].type = RAD_LIGHT_SPOT;
    l[1].position[0] = c[0] - x * ext[0], l[1].position[1] = c[1] + 0.4f * ext[1], l[1].position[2] = c[2];
    l[1].direction[1] = -1.0f;
    l[1].inner_angle = 0.3f, l[1].outer_angle = 0.6f;
    l[1].color[0] = 0.1f * ext[1] * ext[1], l[1].color[1] = l[1].color[2] = 0.05f * ext[1] * ext[1];
    l[2].type = RAD_LIGHT_DIRECTIONAL;
    l[2].direction[0] = 0.3f, l[2].direction[1] = -1.0f, l[2].direction[2] = 0.2f;
    l[2].color[0] = l[2].color[1] = l[2].color[2] = 2.0f;
}

/* with every sample re-tested each update, rad_vp_lights_update gives rad_vp_sources' E bit for
   bit (point, spot, sun) at two light positions, and to float rounding with the emitters;
   a bad light is refused */
static void vpr_test_dynamic_lights_exact(void)
{
    rad_scene *scene = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_virtual_patches *vp = NULL;
    rad_vp_lights *dl = NULL, *de = NULL;
    rad_vp_lights_options lo;
    rad_direct_options dopt;
    rad_light lights[3];
    rad_context quiet;
    float *E = NULL, *Ex = NULL;
    uint32_t N, i, pass, bad = 0;
    double worst = 0.0;
    CHECK_OK(vpr_dyn_setup(&scene, &bvh, &rc, &vp));
    if (!vp) goto out;
    N = vp->count;
    E = (float *)malloc(sizeof(float) * 3 * N);
    Ex = (float *)malloc(sizeof(float) * 3 * N);
    if (!E || !Ex) goto out;
    rad_vp_lights_options_default(&lo);
    lo.direct.exclude_emitters = 1;
    CHECK_OK(rad_vp_lights_create(vp, &rc, &lo, NULL, &dl));
    lo.direct.exclude_emitters = 0;
    lo.direct.light_samples = 4;
    CHECK_OK(rad_vp_lights_create(vp, &rc, &lo, NULL, &de));
    if (!dl || !de) goto out;
    for (pass = 0; pass < 2; ++pass) {
        vpr_dyn_lights(lights, scene, pass ? -0.3f : 0.25f);
        rad_direct_options_default(&dopt);
        dopt.exclude_emitters = 1;
        CHECK_OK(rad_vp_sources(vp, &rc, lights, 3, &dopt, RAD_SOURCE_DIRECT, Ex, NULL));
        CHECK_OK(rad_vp_lights_update(dl, lights, 3, E, NULL));
        CHECK(rad_vp_lights_rays(dl) > 0 && rad_vp_lights_rays(dl) <= 3u * vp->sample_count);
        for (i = 0; i < 3 * N; ++i) bad += memcmp(&E[i], &Ex[i], sizeof(float)) != 0;
        dopt.exclude_emitters = 0;
        dopt.light_samples = 4;
        CHECK_OK(rad_vp_sources(vp, &rc, lights, 3, &dopt, RAD_SOURCE_DIRECT, Ex, NULL));
        CHECK_OK(rad_vp_lights_update(de, lights, 3, E, NULL));
        for (i = 0; i < 3 * N; ++i) {
            double d = fabs((double)E[i] - (double)Ex[i]) / ((double)Ex[i] + 1e-3);
            if (d > worst) worst = d;
        }
    }
    CHECK(bad == 0);
    CHECK(worst < 1e-5);
    memset(&quiet, 0, sizeof quiet);
    quiet.log = vpr_quiet;
    lights[0].color[0] = -1.0f;
    CHECK(rad_vp_lights_update(dl, lights, 3, E, &quiet) == RAD_ERROR_NEGATIVE_EMISSION);
    CHECK(rad_vp_lights_update(dl, lights, RAD_VP_LIGHTS_MAX + 1, E, &quiet) == RAD_ERROR_INVALID_ARGUMENT);
out:
    free(E); free(Ex);
    rad_vp_lights_destroy(dl);
    rad_vp_lights_destroy(de);
    rad_vp_destroy(vp);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(scene);
}

/* a parallel_for that runs the tasks last to first (any order is allowed) */
static void vpr_reverse_for(void *user, uint32_t count, rad_task_fn fn, void *data)
{
    (void)user;
    while (count) fn(data, --count);
}

/* the per-frame calls on a small set run as one task on the calling thread with the default
   parallel_for; the bits equal those of a caller's parallel_for that splits the same calls into
   7 tasks run in reverse order (E update with a budget and a moving light, the temporal step) */
static void vpr_test_serial_same_bits(void)
{
    rad_scene *scene = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_virtual_patches *vp = NULL;
    rad_vp_lights *d1 = NULL, *d7 = NULL;
    rad_vp_lights_options lo;
    rad_light lights[3];
    rad_alias_tables *at = NULL;
    const rad_alias_tables *tabs[1];
    rad_temporal_options to;
    rad_temporal *t1 = NULL, *t7 = NULL;
    rad_context seven;
    float *E1 = NULL, *E7 = NULL, *L1 = NULL, *L7 = NULL;
    uint32_t N, i, f, bad = 0;
    uint64_t rays1 = 0, rays7 = 0;
    CHECK_OK(vpr_dyn_setup(&scene, &bvh, &rc, &vp));
    if (!vp) goto out;
    N = vp->count;
    E1 = (float *)malloc(sizeof(float) * 3 * N), E7 = (float *)malloc(sizeof(float) * 3 * N);
    L1 = (float *)malloc(sizeof(float) * 3 * N), L7 = (float *)malloc(sizeof(float) * 3 * N);
    if (!E1 || !E7 || !L1 || !L7) goto out;
    memset(&seven, 0, sizeof seven);
    seven.parallel_for = vpr_reverse_for;
    seven.task_count = 7;
    rad_vp_lights_options_default(&lo);
    lo.direct.exclude_emitters = 1;
    lo.rays_per_frame = vp->sample_count / 3u + 1u;
    CHECK_OK(rad_vp_lights_create(vp, &rc, &lo, NULL, &d1));
    CHECK_OK(rad_vp_lights_create(vp, &rc, &lo, NULL, &d7));
    CHECK_OK(rad_alias_tables_create(&vp->matrix, RAD_ALIAS_AUTO, NULL, &at));
    if (!d1 || !d7 || !at) goto out;
    tabs[0] = at;
    rad_temporal_options_default(&to);
    to.mode = RAD_TEMPORAL_FEEDBACK, to.samples = 10, to.adaptive = 1;
    CHECK_OK(rad_temporal_create(tabs, 1, vp->albedo, &to, NULL, &t1));
    CHECK_OK(rad_temporal_create(tabs, 1, vp->albedo, &to, &seven, &t7));
    if (!t1 || !t7) goto out;
    for (f = 0; f < 12; ++f) {
        vpr_dyn_lights(lights, scene, -0.3f + 0.05f * (float)f);
        CHECK_OK(rad_vp_lights_update(d1, lights, 3, E1, NULL));
        CHECK_OK(rad_vp_lights_update(d7, lights, 3, E7, &seven));
        rays1 += rad_vp_lights_rays(d1), rays7 += rad_vp_lights_rays(d7);
        CHECK_OK(rad_temporal_step(t1, E1, NULL, L1));
        CHECK_OK(rad_temporal_step(t7, E7, NULL, L7));
        for (i = 0; i < 3 * N; ++i) bad += (memcmp(&E1[i], &E7[i], sizeof(float)) != 0) + (memcmp(&L1[i], &L7[i], sizeof(float)) != 0);
    }
    CHECK(bad == 0);
    CHECK(rays1 == rays7 && rays1 > 0);
    for (i = 0; i < 3 * N && L1[i] == 0.0f; ++i) {}
    CHECK(i < 3 * N); /* the step did something */
out:
    free(E1), free(E7), free(L1), free(L7);
    rad_temporal_destroy(t1), rad_temporal_destroy(t7);
    rad_alias_tables_destroy(at);
    rad_vp_lights_destroy(d1), rad_vp_lights_destroy(d7);
    rad_vp_destroy(vp);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(scene);
}

/* a bounded budget: P = 5 updates per round; a moved light casts at most the budget per slot,
   its E is stale in the shadows for fewer than P updates, then equals the exact E bit for bit
   and lights at rest cast no more rays;
   temporal radiosity fed by it converges to the direct solve of the new light (within 1%) */
static void vpr_test_dynamic_lights_converge(void)
{
    rad_scene *scene = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_virtual_patches *vp = NULL;
    rad_vp_lights *dl = NULL;
    rad_vp_lights_options lo;
    rad_direct_options dopt;
    rad_light lights[3];
    rad_alias_tables *at = NULL;
    const rad_alias_tables *tabs[1];
    rad_temporal *tp = NULL;
    rad_temporal_options to;
    rad_solve_options so;
    rad_system sys;
    float *E = NULL, *Ex = NULL, *Ld = NULL, *L = NULL;
    uint32_t N, i, f, P = 5, budget, bad = 0, frames = 300;
    double pd = 0.0, pt = 0.0;
    CHECK_OK(vpr_dyn_setup(&scene, &bvh, &rc, &vp));
    if (!vp) goto out;
    N = vp->count;
    E = (float *)malloc(sizeof(float) * 3 * N);
    Ex = (float *)malloc(sizeof(float) * 3 * N);
    Ld = (float *)malloc(sizeof(float) * 3 * N);
    L = (float *)malloc(sizeof(float) * 3 * N);
    if (!E || !Ex || !Ld || !L) goto out;
    budget = (vp->sample_count + P - 1) / P;
    rad_vp_lights_options_default(&lo);
    lo.direct.exclude_emitters = 1; /* as the reference below */
    lo.rays_per_frame = budget;
    CHECK_OK(rad_vp_lights_create(vp, &rc, &lo, NULL, &dl));
    if (!dl) goto out;
    vpr_dyn_lights(lights, scene, 0.25f);
    CHECK_OK(rad_vp_lights_update(dl, lights, 3, E, NULL)); /* the first: every sample */
    vpr_dyn_lights(lights, scene, -0.3f);
    rad_direct_options_default(&dopt);
    dopt.exclude_emitters = 1;
    CHECK_OK(rad_vp_sources(vp, &rc, lights, 3, &dopt, RAD_SOURCE_DIRECT, Ex, NULL));
    for (f = 0; f < P; ++f) {
        CHECK_OK(rad_vp_lights_update(dl, lights, 3, E, NULL));
        CHECK(rad_vp_lights_rays(dl) <= 3u * budget);
        if (f == 0) {
            uint32_t diff = 0;
            for (i = 0; i < 3 * N; ++i) diff += memcmp(&E[i], &Ex[i], sizeof(float)) != 0;
            CHECK(diff > 0); /* the shadows of the old position are still in it */
        }
    }
    for (i = 0; i < 3 * N; ++i) bad += memcmp(&E[i], &Ex[i], sizeof(float)) != 0;
    CHECK(bad == 0);
    /* lights at rest for a whole round: no rays, the same E */
    CHECK_OK(rad_vp_lights_update(dl, lights, 3, E, NULL));
    CHECK(rad_vp_lights_rays(dl) == 0);
    for (i = 0; i < 3 * N; ++i) bad += memcmp(&E[i], &Ex[i], sizeof(float)) != 0;
    CHECK(bad == 0);
    /* the spot turns where it stands: the samples its cone now reaches are tested within a round */
    lights[1].direction[0] = 0.8f;
    CHECK_OK(rad_vp_sources(vp, &rc, lights, 3, &dopt, RAD_SOURCE_DIRECT, Ex, NULL));
    for (f = 0; f < P; ++f) CHECK_OK(rad_vp_lights_update(dl, lights, 3, E, NULL));
    for (i = 0; i < 3 * N; ++i) bad += memcmp(&E[i], &Ex[i], sizeof(float)) != 0;
    CHECK(bad == 0);
    /* the whole loop: temporal radiosity over the updated E reaches the new solution */
    rad_vp_system(&sys, vp, Ex);
    rad_solve_options_default(&so);
    so.output = RAD_OUTPUT_INDIRECT;
    CHECK_OK(rad_solve_direct(&sys, &so, Ld, NULL));
    CHECK_OK(rad_alias_tables_create(&vp->matrix, RAD_ALIAS_AUTO, NULL, &at));
    if (!at) goto out;
    tabs[0] = at;
    rad_temporal_options_default(&to);
    to.mode = RAD_TEMPORAL_FEEDBACK;
    to.weight = 0.9f;
    to.samples = 16;
    CHECK_OK(rad_temporal_create(tabs, 1, vp->albedo, &to, NULL, &tp));
    for (f = 0; tp && f < frames; ++f) {
        CHECK_OK(rad_vp_lights_update(dl, lights, 3, E, NULL));
        CHECK_OK(rad_temporal_step(tp, E, NULL, L));
        if (f >= frames - 100)
            for (i = 0; i < 3 * N; ++i) pt += vp->areas[i / 3] * (double)L[i] / 100.0;
    }
    for (i = 0; i < 3 * N; ++i) pd += vp->areas[i / 3] * (double)Ld[i];
    CHECK(pd > 0.0);
    CHECK_REL(pt, pd, 0.01);
out:
    free(E); free(Ex); free(Ld); free(L);
    rad_temporal_destroy(tp);
    rad_alias_tables_destroy(at);
    rad_vp_lights_destroy(dl);
    rad_vp_destroy(vp);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(scene);
}

/* a gather table at the scene's triangle centroids (and points off the grid) gives rad_vp_gather's
   values to float rounding */
static void vpr_test_gather_table(void)
{
    rad_scene *scene = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_virtual_patches *vp = NULL;
    rad_vp_gather_table *gt = NULL;
    float *x = NULL, *pts = NULL, *nrm = NULL, *a = NULL, *b = NULL;
    uint32_t N, T, i, k, nonzero = 0;
    double worst = 0.0;
    CHECK_OK(vpr_dyn_setup(&scene, &bvh, &rc, &vp));
    if (!vp) goto out;
    N = vp->count;
    T = scene->triangle_count + 2;
    x = (float *)malloc(sizeof(float) * 3 * N);
    pts = (float *)malloc(sizeof(float) * 3 * T);
    nrm = (float *)malloc(sizeof(float) * 3 * T);
    a = (float *)malloc(sizeof(float) * 3 * T);
    b = (float *)malloc(sizeof(float) * 3 * T);
    if (!x || !pts || !nrm || !a || !b) goto out;
    for (i = 0; i < 3 * N; ++i) x[i] = (float)((i * 2654435761u) % 1000u) / 1000.0f;
    for (i = 0; i + 2 < T; ++i)
        for (k = 0; k < 3; ++k) {
            const float *v = scene->positions + 9 * (size_t)i;
            pts[3 * i + k] = (v[k] + v[3 + k] + v[6 + k]) / 3.0f;
            nrm[3 * i + k] = scene->normals[3 * (size_t)i + k];
        }
    for (k = 0; k < 3; ++k) { /* outside the grid, and a point whose normal faces nothing there */
        pts[3 * (T - 2) + k] = 1e3f, nrm[3 * (T - 2) + k] = k == 1 ? 1.0f : 0.0f;
        pts[3 * (T - 1) + k] = scene->bounds_min[k], nrm[3 * (T - 1) + k] = k == 0 ? -1.0f : 0.0f;
    }
    CHECK_OK(rad_vp_gather_table_create(vp, pts, nrm, T, NULL, &gt));
    if (!gt) goto out;
    CHECK(gt->count == T && gt->patches == N && gt->offsets[T - 1] == gt->offsets[T - 2]);
    CHECK_OK(rad_vp_gather_table_apply(gt, x, a, NULL));
    CHECK_OK(rad_vp_gather(vp, x, pts, nrm, T, b, NULL));
    for (i = 0; i < 3 * T; ++i) {
        double d = fabs((double)a[i] - (double)b[i]);
        if (d > worst) worst = d;
        nonzero += b[i] > 0.0f;
    }
    CHECK(nonzero > 3 * (T - 2) / 2);
    CHECK(worst < 1e-5);
out:
    free(x); free(pts); free(nrm); free(a); free(b);
    rad_vp_gather_table_destroy(gt);
    rad_vp_destroy(vp);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(scene);
}

static const rad_test_case tests_vp_runtime[] = {
    { "vp_sparse_rows", vpr_test_sparse_rows },
    { "vp_temporal_converges", vpr_test_temporal_converges },
    { "vp_container", vpr_test_container },
    { "vp_streamed_rows", vpr_test_streamed_rows },
    { "vp_dynamic_lights_exact", vpr_test_dynamic_lights_exact },
    { "vp_dynamic_lights_converge", vpr_test_dynamic_lights_converge },
    { "vp_gather_table", vpr_test_gather_table },
    { "vp_serial_same_bits", vpr_test_serial_same_bits },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_vp_runtime)
