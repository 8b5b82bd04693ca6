/* test_rel.c - reliability at the edges of the number range: row sums too small for a float
   reciprocal, run-time outputs that are not finite, user vectors too long for their squared
   length, and the safe write of rad_save_file. Included by test_main.c after the
   implementation: every name is static and prefixed rl_. */
#include "fixtures.h"

#include <math.h>

/* the Cornell box cut into about 'target' patches */
static int rl_cornell_patches(uint32_t target, rad_scene **scene, rad_patches **P)
{
    rad_scene_desc d;
    rad_patch_options po;
    *scene = NULL;
    *P = NULL;
    rad_cornell_box(&d, NULL);
    if (rad_scene_create(&d, NULL, scene) != RAD_SUCCESS) return 0;
    rad_patch_options_default(&po);
    po.target_count = target;
    if (rad_patches_create(*scene, &po, NULL, P) != RAD_SUCCESS) {
        rad_scene_destroy(*scene);
        *scene = NULL;
        return 0;
    }
    return 1;
}

/* rad_patches_vertex_irradiance: H_v = [sum A H / sum A S] S_v, so the row sums cancel when
   they are equal at every patch: H = 100 everywhere must give 100 at every vertex whatever
   the common S, also one whose float reciprocal overflows (1e-38) and a denormal (1e-45).
   With half the patches at a denormal S and the rest at 1, a vertex touching an S = 1
   patch sees the uncovered mean: still finite and at most H times the area ratio. */
static void rl_test_vertex_irradiance_tiny_rows(void)
{
    static const float svals[4] = { 1.0f, 1e-30f, 1e-38f, 1e-45f };
    rad_scene *scene;
    rad_patches *P;
    float *H, *S, *hv;
    uint32_t i, t, k;
    if (!rl_cornell_patches(100, &scene, &P)) { CHECK(!"cornell patches"); return; }
    H = (float *)malloc(sizeof(float) * 3 * P->count);
    S = (float *)malloc(sizeof(float) * P->count);
    hv = (float *)malloc(sizeof(float) * 3 * P->vertex_count);
    if (H && S && hv) {
        for (i = 0; i < 3 * P->count; ++i) H[i] = 100.0f;
        for (t = 0; t < 4; ++t) {
            uint32_t wrong = 0;
            for (i = 0; i < P->count; ++i) S[i] = svals[t];
            CHECK_OK(rad_patches_vertex_irradiance(P, H, S, hv, NULL));
            for (i = 0; i < 3 * P->vertex_count; ++i) wrong += !(fabsf(hv[i] - 100.0f) <= 1e-3f);
            CHECK(wrong == 0);
        }
        for (i = 0; i < P->count; ++i) S[i] = (i & 1) ? 1e-45f : 1.0f;
        CHECK_OK(rad_patches_vertex_irradiance(P, H, S, hv, NULL));
        for (i = 0; i < P->vertex_count; ++i)
            for (k = 0; k < 3; ++k) CHECK(isfinite(hv[3 * i + k]) && hv[3 * i + k] >= 0.0f);
        /* an H whose vertex value leaves the float range is refused, not returned as Inf */
        for (i = 0; i < P->count; ++i) S[i] = (i & 1) ? 1e-45f : 1.0f;
        for (i = 0; i < 3 * P->count; ++i) H[i] = 3e38f;
        CHECK_RESULT(rad_patches_vertex_irradiance(P, H, S, hv, NULL), RAD_ERROR_NON_FINITE);
    }
    free(H);
    free(S);
    free(hv);
    rad_patches_destroy(P);
    rad_scene_destroy(scene);
}

/* the last error the library logged (the tests check that it names the call and the place) */
static char rl_log_last[512];
static void rl_log(void *user, rad_log_level level, const char *message)
{
    (void)user;
    if (level == RAD_LOG_ERROR) snprintf(rl_log_last, sizeof(rl_log_last), "%s", message);
}

/* the two rooms of fixtures.h (floor lightmapped) with a BVH and patches */
typedef struct rl_rooms {
    lm_soup room, wall, lamp;
    rad_mesh_desc m[3];
    rad_material mats[2];
    rad_scene_desc d;
    rad_scene *S;
    rad_bvh *bvh;
    rad_raycaster rc;
    rad_patches *P;
} rl_rooms;

static int rl_rooms_make(rl_rooms *w)
{
    rad_patch_options po;
    memset(w, 0, sizeof(*w));
    fx_two_rooms(&w->room, &w->wall, &w->lamp, w->m, &w->d, w->mats);
    if (rad_scene_create(&w->d, NULL, &w->S) != RAD_SUCCESS || rad_bvh_create(w->S, NULL, &w->bvh) != RAD_SUCCESS) return 0;
    rad_bvh_raycaster(w->bvh, &w->rc);
    rad_patch_options_default(&po);
    po.max_edge = 0.5f;
    return rad_patches_create(w->S, &po, NULL, &w->P) == RAD_SUCCESS;
}

static void rl_rooms_free(rl_rooms *w)
{
    rad_patches_destroy(w->P);
    rad_bvh_destroy(w->bvh);
    rad_scene_destroy(w->S);
}

static int rl_all_finite(const float *v, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i)
        if (!isfinite(v[i])) return 0;
    return 1;
}

/* rad_lightmap_refresh: finite patch irradiance gives finite texels; a NaN or an Inf in the
   patch that the first row's first vertex reads is refused (NON_FINITE, the texel named),
   not returned as a lightmap with NaN texels; a NaN the caller left in a gutter texel (no
   row: the refresh does not write it) is not the refresh's and is accepted. */
static void rl_test_lightmap_refresh_nonfinite(void)
{
    static const float bad[2] = { NAN, INFINITY };
    rl_rooms w;
    rad_lightmap *lm = NULL;
    rad_lightmap_options lo;
    rad_lightmap_weights *W = NULL;
    rad_context ctx;
    float *H = NULL, *out = NULL;
    uint32_t i, p, b;
    if (!rl_rooms_make(&w)) { CHECK(!"rooms"); rl_rooms_free(&w); return; }
    memset(&ctx, 0, sizeof ctx);
    ctx.log = rl_log;
    rad_lightmap_options_default(&lo);
    lo.width = lo.height = 32;
    CHECK_OK(rad_lightmap_create(w.S, &w.rc, &lo, NULL, &lm));
    if (lm) CHECK_OK(rad_lightmap_weights_create(lm, w.P, NULL, NULL, NULL, &W));
    H = (float *)malloc(sizeof(float) * 3 * w.P->count);
    out = (float *)calloc(3 * 32 * 32, sizeof(float));
    if (W && H && out && W->row_count > 0) {
        for (i = 0; i < 3 * w.P->count; ++i) H[i] = 1.0f;
        CHECK_OK(rad_lightmap_refresh(W, H, out, &ctx));
        CHECK(rl_all_finite(out, 3 * 32 * 32));
        {
            /* a texel without a row (a gutter) between rows holds the caller's value, whatever
               it is: not the refresh's output, so not refused */
            uint32_t r = 0, t, gutter = RAD_NONE;
            for (t = W->row_texels[0]; t < W->row_texels[W->row_count - 1] && gutter == RAD_NONE; ++t) {
                while (r < W->row_count && W->row_texels[r] < t) ++r;
                if (W->row_texels[r] != t) gutter = t;
            }
            CHECK(gutter != RAD_NONE);
            if (gutter != RAD_NONE) {
                out[3 * gutter] = NAN;
                CHECK_OK(rad_lightmap_refresh(W, H, out, &ctx));
                CHECK(isnan(out[3 * gutter]));
                out[3 * gutter] = 0.0f;
            }
        }
        p = W->vertex_patches[W->vertex_first[W->entry_vertices[W->row_first[0]]]];
        for (b = 0; b < 2; ++b) {
            H[3 * p + 1] = bad[b];
            rl_log_last[0] = 0;
            CHECK_RESULT(rad_lightmap_refresh(W, H, out, &ctx), RAD_ERROR_NON_FINITE);
            CHECK(strstr(rl_log_last, "lightmap refresh: texel") != NULL);
            H[3 * p + 1] = 1.0f;
        }
    } else {
        CHECK(!"lightmap weights");
    }
    free(H);
    free(out);
    rad_lightmap_weights_destroy(W);
    rad_lightmap_destroy(lm);
    rl_rooms_free(&w);
}

/* The virtual-patch run-time calls: rad_vp_gather, rad_vp_gather_table_apply and
   rad_vp_from_samples give finite outputs for finite values and refuse (NON_FINITE) per-patch
   or per-sample values that are NaN or infinite, where they returned success with NaN. */
static void rl_test_vp_runtime_nonfinite(void)
{
    rl_rooms w;
    rad_vp_options vo;
    rad_virtual_patches *vp = NULL;
    rad_vp_gather_table *tab = NULL;
    rad_context ctx;
    float pts[3 * 16], nrm[3 * 16], out[3 * 16], *V = NULL, *S = NULL;
    uint32_t i;
    if (!rl_rooms_make(&w)) { CHECK(!"rooms"); rl_rooms_free(&w); return; }
    memset(&ctx, 0, sizeof ctx);
    ctx.log = rl_log;
    rad_vp_options_default(&vo);
    vo.resolution = 6;
    vo.face_points = 4;
    CHECK_OK(rad_vp_create(w.S, &w.rc, &vo, NULL, &vp));
    for (i = 0; i < 16; ++i) {
        pts[3 * i] = 0.05f + 0.06f * (float)i;
        pts[3 * i + 1] = 0.001f;
        pts[3 * i + 2] = 0.5f;
        nrm[3 * i] = 0.0f;
        nrm[3 * i + 1] = 1.0f;
        nrm[3 * i + 2] = 0.0f;
    }
    if (vp) {
        V = (float *)malloc(sizeof(float) * 3 * vp->count);
        S = (float *)malloc(sizeof(float) * 3 * vp->sample_count);
        CHECK_OK(rad_vp_gather_table_create(vp, pts, nrm, 16, NULL, &tab));
    }
    if (vp && V && S && tab) {
        for (i = 0; i < 3 * vp->count; ++i) V[i] = 1.0f;
        for (i = 0; i < 3 * vp->sample_count; ++i) S[i] = 1.0f;
        CHECK_OK(rad_vp_gather(vp, V, pts, nrm, 16, out, &ctx));
        CHECK(rl_all_finite(out, 48));
        CHECK_OK(rad_vp_gather_table_apply(tab, V, out, &ctx));
        CHECK(rl_all_finite(out, 48));
        CHECK_OK(rad_vp_from_samples(vp, S, V));
        for (i = 0; i < 3 * vp->count; ++i) V[i] = NAN;
        rl_log_last[0] = 0;
        CHECK_RESULT(rad_vp_gather(vp, V, pts, nrm, 16, out, &ctx), RAD_ERROR_NON_FINITE);
        CHECK(strstr(rl_log_last, "rad_vp_gather") != NULL);
        rl_log_last[0] = 0;
        CHECK_RESULT(rad_vp_gather_table_apply(tab, V, out, &ctx), RAD_ERROR_NON_FINITE);
        CHECK(strstr(rl_log_last, "rad_vp_gather_table_apply") != NULL);
        S[3 * (vp->sample_count / 2)] = INFINITY;
        CHECK_RESULT(rad_vp_from_samples(vp, S, V), RAD_ERROR_NON_FINITE);
    } else {
        CHECK(!"virtual patches");
    }
    free(V);
    free(S);
    rad_vp_gather_table_destroy(tab);
    rad_vp_destroy(vp);
    rl_rooms_free(&w);
}

/* the floor irradiance sum of one light at 64 floor points of the Cornell box (-1: refused) */
static double rl_floor_light(const rad_scene *S, const rad_raycaster *rc, const rad_light *L, rad_result *res)
{
    float p[3 * 64], n[3 * 64], e[3 * 64];
    rad_direct_options o;
    rad_context ctx;
    double sum = 0.0;
    int i;
    memset(&ctx, 0, sizeof ctx);
    ctx.log = rl_log;
    for (i = 0; i < 64; ++i) {
        p[3 * i] = S->bounds_min[0] + (S->bounds_max[0] - S->bounds_min[0]) * ((float)(i % 8) + 0.5f) / 8.0f;
        p[3 * i + 1] = S->bounds_min[1] + 1e-4f;
        p[3 * i + 2] = S->bounds_min[2] + (S->bounds_max[2] - S->bounds_min[2]) * ((float)(i / 8) + 0.5f) / 8.0f;
        n[3 * i] = 0.0f;
        n[3 * i + 1] = 1.0f;
        n[3 * i + 2] = 0.0f;
    }
    rad_direct_options_default(&o);
    o.exclude_emitters = 1;
    *res = rad_direct_irradiance(S, rc, L, 1, &o, p, n, 64, e, &ctx);
    if (*res != RAD_SUCCESS) return -1.0;
    for (i = 0; i < 64; ++i) sum += e[3 * i];
    return sum;
}

/* Directions of any finite non-zero length keep their direction: a directional and a spot
   light whose direction is scaled by 1e20 (its squared length overflows float) or 1e-25
   (underflows) light the floor exactly as the unit direction does (they gave no light); a
   zero direction is refused with the light named. */
static void rl_test_light_direction_scale(void)
{
    static const float scales[3] = { 1e20f, 1e-25f, 3e38f };
    rad_scene_desc d;
    rad_scene *S = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_light L;
    rad_result r;
    int t, k;
    rad_cornell_box(&d, NULL);
    CHECK_OK(rad_scene_create(&d, NULL, &S));
    if (S) CHECK_OK(rad_bvh_create(S, NULL, &bvh));
    if (!bvh) { rad_scene_destroy(S); return; }
    rad_bvh_raycaster(bvh, &rc);
    for (t = 0; t < 2; ++t) {
        double unit;
        memset(&L, 0, sizeof L);
        L.type = t ? RAD_LIGHT_SPOT : RAD_LIGHT_DIRECTIONAL;
        L.falloff = RAD_FALLOFF_QUADRATIC;
        L.color[0] = L.color[1] = L.color[2] = 5.0f;
        L.position[0] = 0.5f * (S->bounds_min[0] + S->bounds_max[0]);
        L.position[1] = 0.9f * S->bounds_max[1];
        L.position[2] = 0.5f * (S->bounds_min[2] + S->bounds_max[2]);
        L.inner_angle = 0.5f;
        L.outer_angle = 0.6f;
        L.direction[1] = -1.0f;
        L.direction[2] = 0.3f;
        unit = rl_floor_light(S, &rc, &L, &r);
        CHECK_OK(r);
        CHECK(unit > 1.0);
        for (k = 0; k < 3; ++k) {
            L.direction[1] = -scales[k];
            L.direction[2] = 0.3f * scales[k];
            CHECK_REL(rl_floor_light(S, &rc, &L, &r), unit, 1e-5);
            CHECK_OK(r);
        }
        L.direction[0] = L.direction[1] = L.direction[2] = 0.0f;
        rl_log_last[0] = 0;
        CHECK(rl_floor_light(S, &rc, &L, &r) < 0.0);
        CHECK(r == RAD_ERROR_INVALID_ARGUMENT);
        CHECK(strstr(rl_log_last, "light 0") && strstr(rl_log_last, "direction"));
    }
    rad_bvh_destroy(bvh);
    rad_scene_destroy(S);
}

/* rad_probes_sample: a normal of length 1e20 (or 1e-30) samples as the unit normal (it gave
   0); a zero normal is INVALID_ARGUMENT, a NaN one NON_FINITE. The camera: a target 1e30
   away and an up vector of length 1e25 give the ray of the unit camera. */
static void rl_test_probe_normal_camera_scale(void)
{
    rad_scene *S;
    rad_patches *P;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_probes *pr = NULL;
    rad_probe_options pro;
    rad_scene_desc cd;
    rad_camera cam, far;
    rad_ray a, b;
    float *B, q[3] = { 0.3f, 0.1f, 0.3f }, n1[3] = { 0, 1, 0 }, n2[3] = { 0, 1e20f, 0 }, n3[3] = { 0, 1e-30f, 0 };
    float n0[3] = { 0, 0, 0 }, nn[3] = { 0, NAN, 0 }, o1[3], o2[3];
    uint32_t i;
    int k;
    if (!rl_cornell_patches(200, &S, &P)) { CHECK(!"cornell patches"); return; }
    CHECK_OK(rad_bvh_create(S, NULL, &bvh));
    if (bvh) rad_bvh_raycaster(bvh, &rc);
    B = (float *)malloc(sizeof(float) * 3 * P->count);
    if (bvh && B) {
        for (i = 0; i < 3 * P->count; ++i) B[i] = 1.0f;
        rad_probe_options_default(&pro);
        CHECK_OK(rad_probes_create(P, &rc, NULL, 0, NULL, 0, &pro, B, NULL, &pr));
    }
    if (pr) {
        CHECK_OK(rad_probes_sample(pr, q, n1, o1));
        CHECK(o1[0] > 0.0f);
        CHECK_OK(rad_probes_sample(pr, q, n2, o2));
        for (k = 0; k < 3; ++k) CHECK_REL(o2[k], o1[k], 1e-6);
        CHECK_OK(rad_probes_sample(pr, q, n3, o2));
        for (k = 0; k < 3; ++k) CHECK_REL(o2[k], o1[k], 1e-6);
        CHECK_RESULT(rad_probes_sample(pr, q, n0, o2), RAD_ERROR_INVALID_ARGUMENT);
        CHECK_RESULT(rad_probes_sample(pr, q, nn, o2), RAD_ERROR_NON_FINITE);
    }
    rad_cornell_box(&cd, &cam);
    far = cam;
    for (k = 0; k < 3; ++k) {
        far.target[k] = cam.position[k] + 1e30f * (cam.target[k] - cam.position[k]);
        far.up[k] = 1e25f * cam.up[k];
    }
    rad_camera_ray(&cam, 64, 48, 10.5f, 30.5f, &a);
    rad_camera_ray(&far, 64, 48, 10.5f, 30.5f, &b);
    for (k = 0; k < 3; ++k) CHECK_NEAR(b.dir[k], a.dir[k], 1e-5);
    rad_probes_destroy(pr);
    free(B);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(P);
    rad_scene_destroy(S);
}

#if !defined(RAD_NO_STDIO) && defined(__unix__)
#include <sys/stat.h>
#include <sys/wait.h>
#include <dirent.h>
#include <unistd.h>
int symlink(const char *target, const char *linkpath); /* POSIX; strict C99 hides it */

/* entries of folder 'dir' whose name starts with ".rad-" (temporaries left behind) */
static int rl_temporaries(const char *dir)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    int n = 0;
    if (!d) return -1;
    while ((e = readdir(d)) != NULL) n += strncmp(e->d_name, ".rad-", 5) == 0;
    closedir(d);
    return n;
}

/* the patch count of the bake at path (0: it does not load) */
static uint32_t rl_bake_count(const char *path)
{
    rad_bake *b = NULL;
    uint32_t n = 0;
    if (rad_load_file(path, NULL, &b) == RAD_SUCCESS) n = b->patches.count;
    rad_bake_destroy(b);
    return n;
}

/* rad_save_file writes through a new temporary created exclusively beside path, then renames:
   - a symbolic link at the name the writer once used ('<path>.partial') is not followed: the
     file it points to keeps its bytes;
   - an empty folder at path is refused (IO, the logger names it) and still exists after;
   - a path in a missing folder is IO and creates nothing;
   - saving over a bake replaces it, and no temporary is left in the folder;
   - two processes saving different bakes to one path, 6 rounds: both succeed and the file
     left is one of the two, whole (with a shared temporary a loser removed the winner's
     file, or the two writes mixed). */
static void rl_test_save_file_safe(void)
{
    rad_scene *S;
    rad_patches *P1, *P2 = NULL;
    rad_patch_options po;
    rad_context ctx;
    rad_matrix F2;
    float *dense = NULL;
    char dir[512], path[600], link[620], victim[600], folder[600], missing[600], text[32] = { 0 };
    struct stat st;
    FILE *f;
    int round;
    if (!rl_cornell_patches(60, &S, &P1)) { CHECK(!"cornell patches"); return; }
    rad_patch_options_default(&po);
    po.target_count = rad_test_quick() ? 400 : 800;
    CHECK_OK(rad_patches_create(S, &po, NULL, &P2));
    memset(&F2, 0, sizeof F2);
    memset(&ctx, 0, sizeof ctx);
    ctx.log = rl_log;
    snprintf(dir, sizeof dir, "%s", rad_test_path("rel_save"));
    (void)mkdir(dir, 0755);
    snprintf(path, sizeof path, "%s/out.radb", dir);
    snprintf(link, sizeof link, "%s.partial", path);
    snprintf(victim, sizeof victim, "%s/victim.txt", dir);
    snprintf(folder, sizeof folder, "%s/folder.radb", dir);
    snprintf(missing, sizeof missing, "%s/no/such/folder.radb", dir);
    remove(path);
    remove(link);
    if (!P2 || !(dense = (float *)calloc((size_t)P2->count * P2->count, sizeof(float)))) goto done;
    F2.dense = dense;
    F2.rows = F2.cols = P2->count;
    F2.storage = RAD_STORAGE_DENSE;
    f = fopen(victim, "wb");
    if (f) { fputs("precious", f); fclose(f); }
    CHECK(symlink(victim, link) == 0);
    CHECK_OK(rad_save_file(path, P1, NULL, NULL, NULL, &ctx));
    f = fopen(victim, "rb");
    if (f) { CHECK(fread(text, 1, 8, f) == 8); fclose(f); }
    CHECK(strcmp(text, "precious") == 0);
    CHECK(rl_bake_count(path) == P1->count);
    /* a folder at path */
    (void)mkdir(folder, 0755);
    rl_log_last[0] = 0;
    CHECK_RESULT(rad_save_file(folder, P1, NULL, NULL, NULL, &ctx), RAD_ERROR_IO);
    CHECK(strstr(rl_log_last, "folder.radb") && strstr(rl_log_last, "folder"));
    CHECK(stat(folder, &st) == 0 && S_ISDIR(st.st_mode));
    (void)rmdir(folder);
    /* a missing folder */
    CHECK_RESULT(rad_save_file(missing, P1, NULL, NULL, NULL, &ctx), RAD_ERROR_IO);
    CHECK(stat(missing, &st) != 0);
    /* replacing, nothing left behind */
    CHECK_OK(rad_save_file(path, P2, &F2, NULL, NULL, &ctx));
    CHECK(rl_bake_count(path) == P2->count);
    CHECK(rl_temporaries(dir) == 0);
    /* two processes, one path */
    fflush(NULL);
    for (round = 0; round < 6; ++round) {
        pid_t a, b;
        int sa = 1, sb = 1;
        uint32_t n;
        remove(path);
        if ((a = fork()) == 0) _exit(rad_save_file(path, P2, &F2, NULL, NULL, NULL) != RAD_SUCCESS);
        if ((b = fork()) == 0) _exit(rad_save_file(path, P1, NULL, NULL, NULL, NULL) != RAD_SUCCESS);
        if (a > 0) waitpid(a, &sa, 0);
        if (b > 0) waitpid(b, &sb, 0);
        CHECK(a > 0 && b > 0 && WIFEXITED(sa) && WEXITSTATUS(sa) == 0 && WIFEXITED(sb) && WEXITSTATUS(sb) == 0);
        n = rl_bake_count(path);
        CHECK(n == P1->count || n == P2->count);
    }
    CHECK(rl_temporaries(dir) == 0);
done:
    remove(path);
    remove(link);
    remove(victim);
    remove(folder);
    (void)rmdir(dir);
    free(dense);
    rad_patches_destroy(P2);
    rad_patches_destroy(P1);
    rad_scene_destroy(S);
}
#endif

/* The scan every input and output check uses (rad__all_finite: the exponent bits, in blocks
   of 1024): every finite float passes, the extremes included (FLT_MAX, denormals, -0), and a
   NaN, +Inf or -Inf is found wherever it sits: first, last, at the block edges, in the tail. */
static void rl_test_finite_scan(void)
{
    static const size_t sizes[6] = { 1, 3, 1023, 1024, 1025, 5000 };
    const float bad[3] = { NAN, INFINITY, -INFINITY };
    const float good[6] = { FLT_MAX, -FLT_MAX, 1e-45f, -1e-45f, -0.0f, 1.0f };
    float *v = (float *)malloc(sizeof(float) * 5000);
    size_t s, i, at[6];
    int b, k;
    if (!v) { CHECK(!"memory"); return; }
    for (s = 0; s < 6; ++s) {
        size_t n = sizes[s];
        for (i = 0; i < n; ++i) v[i] = good[i % 6];
        CHECK(rad__all_finite(v, n));
        at[0] = 0; at[1] = n - 1; at[2] = n / 2; at[3] = n > 1023 ? 1023 : 0; at[4] = n > 1024 ? 1024 : 0; at[5] = n > 2048 ? 2048 : n - 1;
        for (k = 0; k < 6; ++k)
            for (b = 0; b < 3; ++b) {
                float keep = v[at[k]];
                v[at[k]] = bad[b];
                CHECK(!rad__all_finite(v, n));
                v[at[k]] = keep;
            }
    }
    CHECK(rad__all_finite(v, 0));
    free(v);
}

static const rad_test_case tests_rel[] = {
    { "rel_vertex_irradiance_tiny_rows", rl_test_vertex_irradiance_tiny_rows },
    { "rel_finite_scan", rl_test_finite_scan },
    { "rel_lightmap_refresh_nonfinite", rl_test_lightmap_refresh_nonfinite },
    { "rel_vp_runtime_nonfinite", rl_test_vp_runtime_nonfinite },
    { "rel_light_direction_scale", rl_test_light_direction_scale },
    { "rel_probe_normal_camera_scale", rl_test_probe_normal_camera_scale },
#if !defined(RAD_NO_STDIO) && defined(__unix__)
    { "rel_save_file_safe", rl_test_save_file_safe },
#endif
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_rel)
