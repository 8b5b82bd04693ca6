/* local.c - the local multi-bounce matrix (docs/methods/local.md) on the generated
   rooms-and-corridors scene (examples/rooms.h).

   1. The large scene: 8 x 8 rooms with corridors (about 72 000 patches; --quick: 4 x 4),
      rows computed on demand; the bytes a dense N x N matrix would need.
   2. M = 4096 (--quick: 1024) patches nearest the camera: M exact adds from empty, then the
      same set rebuilt from scratch both ways of rad_local_rebuild (the blocked Gauss-Jordan
      inverse, and the K = infinity multi-bounce build by Neumann doubling); the drift of the
      updated matrix against both.
   3. Per frame, 1%, 5% and 20% of the set replaced (the farthest visible members hidden, the
      next nearest patches added; every add evicts the member hidden longest ago by the exact
      downdate): update time (row fetches included and shown apart), apply time over
      P_Vis x P_Lit (rad_local_visible through the built-in BVH, rad_local_lit), and the
      ratio of a rebuild to update + apply. The drift after the walk against a second rebuild.
   4. Error against the full solution on a scene small enough to solve (2 x 2 rooms, coarse
      patches): a 30-frame camera walk with M = N / 3, L = T E over P_Vis x P_Lit against
      the full-world L_inf restricted to P_Vis (relative L2, mean over frames), for the exact
      update, the first-order update (RAD_LOCAL_FIRST_ORDER) and a rebuild of the set each frame.
   5. Memory: the local matrix, the row buffers, and the global matrix it replaces.

   Everything runs on one thread (a serial parallel_for in the context), so update and
   rebuild are compared on equal terms on a shared machine.

   Build: cc -std=c99 -O3 -march=native -fopenmp -I. tests/bench/local.c -o build/local -lm
   Run:   local [--quick] [--append FILE.md] */
#include "bench_common.h"
#define RADIOSITY_IMPLEMENTATION
#include "../../radiosity.h"
#include "../../examples/rooms.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>

static void serial_for(void *user, uint32_t count, rad_task_fn fn, void *data)
{
    uint32_t i;
    (void)user;
    for (i = 0; i < count; ++i) fn(data, i);
}

static rad_context g_ctx;

/* a row source that times the wrapped one */
typedef struct timed_rows { rad_row_source inner; double seconds; uint64_t rows; } timed_rows;

static rad_result timed_fetch(void *user, uint32_t row, uint32_t capacity, uint32_t *cols, float *vals, uint32_t *count)
{
    timed_rows *t = (timed_rows *)user;
    double t0 = now();
    rad_result r = t->inner.fetch(t->inner.user, row, capacity, cols, vals, count);
    t->seconds += now() - t0;
    t->rows++;
    return r;
}

static void die(const char *what, rad_result r)
{
    fprintf(stderr, "local: %s failed: %s\n", what, rad_result_string(r));
    exit(1);
}

typedef struct world {
    rooms_geometry g;
    rad_scene *scene;
    rad_patches *patches;
    rad_bvh *bvh;
    rad_raycaster rc;
    rooms_rows rows;
    float *E;
    double init_s;
} world;

static void world_make(world *w, uint32_t grid, float max_area)
{
    rad_scene_desc d;
    rad_patch_options po;
    rad_result r;
    double t0;
    memset(w, 0, sizeof(*w));
    if (!rooms_scene(grid, grid, &d, &w->g)) die("rooms_scene", RAD_ERROR_OUT_OF_MEMORY);
    if ((r = rad_scene_create(&d, &g_ctx, &w->scene)) != RAD_SUCCESS) die("rad_scene_create", r);
    rad_patch_options_default(&po);
    po.max_area = max_area;
    if ((r = rad_patches_create(w->scene, &po, &g_ctx, &w->patches)) != RAD_SUCCESS) die("rad_patches_create", r);
    if ((r = rad_bvh_create(w->scene, &g_ctx, &w->bvh)) != RAD_SUCCESS) die("rad_bvh_create", r);
    rad_bvh_raycaster(w->bvh, &w->rc);
    t0 = now();
    if (!rooms_rows_init(&w->rows, w->patches)) die("rooms_rows_init", RAD_ERROR_OUT_OF_MEMORY);
    w->init_s = now() - t0;
    w->E = (float *)malloc(sizeof(float) * 3 * w->patches->count);
    if (!w->E) die("malloc", RAD_ERROR_OUT_OF_MEMORY);
    if ((r = rad_sources(w->patches, RAD_SOURCE_EMISSION, NULL, w->E)) != RAD_SUCCESS) die("rad_sources", r);
}

static void world_free(world *w)
{
    free(w->E);
    rooms_rows_free(&w->rows);
    rad_bvh_destroy(w->bvh);
    rad_patches_destroy(w->patches);
    rad_scene_destroy(w->scene);
    rooms_free(&w->g);
}

/* max |a - b| / max |b| over the members' planes (entries by patch) */
static double plane_drift(const rad_local *a, const rad_local *b)
{
    double d = 0.0, m = 0.0;
    uint32_t ch, i, j, Ma = a->capacity, Mb = b->capacity;
    for (ch = 0; ch < 3; ++ch)
        for (i = 0; i < a->slot_end; ++i) {
            uint32_t pi = a->slot_patch[i], bi;
            if (pi == RAD_NONE) continue;
            bi = b->patch_slot[pi];
            for (j = 0; j < a->slot_end; ++j) {
                uint32_t pj = a->slot_patch[j];
                double x, y;
                if (pj == RAD_NONE) continue;
                x = a->planes[(size_t)ch * Ma * Ma + (size_t)i * Ma + j];
                y = b->planes[(size_t)ch * Mb * Mb + (size_t)bi * Mb + b->patch_slot[pj]];
                if (fabs(x - y) > d) d = fabs(x - y);
                if (fabs(y) > m) m = fabs(y);
            }
        }
    return m > 0.0 ? d / m : d;
}

/* the members of L, visible and hidden */
static uint32_t members(const rad_local *L, uint32_t *out)
{
    uint32_t i, k = 0;
    for (i = 0; i < L->slot_end; ++i)
        if (L->slot_patch[i] != RAD_NONE) out[k++] = L->slot_patch[i];
    return k;
}

/* P_Vis and P_Lit of the visible members for camera 'cam'; apply; returns apply seconds */
static double frame_apply(world *w, const rad_local *L, const rad_camera *cam, uint32_t *cand, uint32_t *vis, uint32_t *lit,
                          float *out, uint32_t *nv_out, uint32_t *nl_out, double *sets_s)
{
    uint32_t i, nc = 0, nv = 0, nl = 0;
    double t0 = now(), t1;
    rad_result r;
    for (i = 0; i < L->slot_end; ++i)
        if (L->slot_patch[i] != RAD_NONE && !L->slot_hidden[i]) cand[nc++] = L->slot_patch[i];
    if ((r = rad_local_visible(w->patches, &w->rc, cam, 16.0f / 9.0f, cand, nc, vis, &nv, &g_ctx)) != RAD_SUCCESS) die("visible", r);
    /* P_Lit over every member: a lit patch behind the camera still lights the scene */
    nc = members(L, cand);
    if ((r = rad_local_lit(w->E, cand, nc, 0.0f, lit, &nl)) != RAD_SUCCESS) die("lit", r);
    t1 = now();
    if ((r = rad_local_apply(L, w->E, vis, nv, lit, nl, out, RAD_OUTPUT_INDIRECT, &g_ctx)) != RAD_SUCCESS) die("apply", r);
    *sets_s = t1 - t0;
    *nv_out = nv;
    *nl_out = nl;
    return now() - t1;
}

static void bench_large(uint32_t grid, uint32_t M)
{
    world w;
    timed_rows tr;
    rad_row_source src;
    rad_local_options o;
    rad_local *L = NULL, *R = NULL, *RN = NULL;
    rad_camera cam;
    uint32_t *near, *cand, *vis, *lit, *mem, n, i, extra = M / 5 + 1, next, f, nv = 0, nl = 0;
    float *out;
    double t0, t_adds, t_rebuild, t_neumann, drift_adds, drift_neumann, sets_s;
    static const double fractions[3] = {0.01, 0.05, 0.20};
    rad_result r;

    world_make(&w, grid, 0.1f);
    n = w.patches->count;
    emit("\n### Large scene: %u x %u rooms with corridors, N = %u patches, M = %u\n\n", grid, grid, n, M);
    emit("Rows on demand (examples/rooms.h: point-to-point within a room or corridor, scale %.3f); grouping and scale pass %.2f s. "
         "A dense N x N float F would take %.1f GiB, the RGB T over all N %.1f GiB.\n\n",
         (double)w.rows.scale, w.init_s, (double)n * n * 4.0 / 1073741824.0, (double)n * n * 12.0 / 1073741824.0);
    rooms_rows_source(&w.rows, &tr.inner);
    tr.seconds = 0.0;
    tr.rows = 0;
    src = tr.inner;
    src.fetch = timed_fetch;
    src.user = &tr;
    near = (uint32_t *)malloc(sizeof(uint32_t) * n);
    cand = (uint32_t *)malloc(sizeof(uint32_t) * n);
    vis = (uint32_t *)malloc(sizeof(uint32_t) * n);
    lit = (uint32_t *)malloc(sizeof(uint32_t) * n);
    mem = (uint32_t *)malloc(sizeof(uint32_t) * n);
    out = (float *)malloc(sizeof(float) * 3 * n);
    if (!near || !cand || !vis || !lit || !mem || !out) die("malloc", RAD_ERROR_OUT_OF_MEMORY);
    rooms_camera(&w.g, 0.3f, &cam);
    if ((r = rad_local_nearest(w.patches, cam.position, M + 2 * extra < n ? M + 2 * extra : n, near, &g_ctx)) != RAD_SUCCESS) die("nearest", r);
    rad_local_options_default(&o);
    o.capacity = M;
    if ((r = rad_local_create(&src, &o, &g_ctx, &L)) != RAD_SUCCESS) die("create", r);
    if ((r = rad_local_create(&src, &o, &g_ctx, &R)) != RAD_SUCCESS) die("create", r);
    o.rebuild = RAD_LOCAL_REBUILD_NEUMANN;
    if ((r = rad_local_create(&src, &o, &g_ctx, &RN)) != RAD_SUCCESS) die("create", r);
    t0 = now();
    for (i = 0; i < M; ++i)
        if ((r = rad_local_add(L, near[i], &g_ctx)) != RAD_SUCCESS) die("add", r);
    t_adds = now() - t0;
    t0 = now();
    if ((r = rad_local_rebuild(R, near, M, &g_ctx)) != RAD_SUCCESS) die("rebuild", r);
    t_rebuild = now() - t0;
    drift_adds = plane_drift(L, R);
    t0 = now();
    if ((r = rad_local_rebuild(RN, near, M, &g_ctx)) != RAD_SUCCESS) die("rebuild", r);
    t_neumann = now() - t0;
    drift_neumann = plane_drift(L, RN);
    rad_local_destroy(RN);
    emit("M exact adds from empty: %.2f s (%.2f ms per add on average). Rebuild of the same set from its rows: blocked "
         "Gauss-Jordan inverse %.2f s, K = inf multi-bounce build (Neumann doubling) %.2f s. Drift of the updated T after M adds "
         "(max |dT| / max T): %.2g against the inverse, %.2g against the Neumann build.\n\n",
         t_adds, 1e3 * t_adds / M, t_rebuild, t_neumann, drift_adds, drift_neumann);
    emit("Per frame (1 thread): k of the M visible members replaced. Update = k hides + k adds, each add evicting the member hidden "
         "longest ago by the exact downdate fused into its update pass (row fetches included, shown apart); apply = L over P_Vis x P_Lit; "
         "sets = P_Vis (4 occlusion rays per candidate) and P_Lit, not included in the ratio.\n\n");
    emit("| change | k | update ms | of which fetch ms | per patch ms | apply ms | P_Vis x P_Lit | sets ms | inverse / (update + apply) | Neumann / (update + apply) | target (>= 15 at 5%%, against the inverse) |\n");
    emit("|---|---|---|---|---|---|---|---|---|---|---|\n");
    next = M;
    for (f = 0; f < 3; ++f) {
        uint32_t k = (uint32_t)(fractions[f] * M + 0.5), hidden = 0, slot;
        double fetch0 = tr.seconds, t_up, t_ap;
        float t = 0.3f + 0.02f * (float)(f + 1);
        t0 = now();
        /* hide the k visible members farthest from the camera (nearest list in reverse) */
        for (i = next; i-- > 0 && hidden < k;) {
            slot = L->patch_slot[near[i]];
            if (slot != RAD_NONE && !L->slot_hidden[slot]) {
                if ((r = rad_local_remove(L, near[i], &g_ctx)) != RAD_SUCCESS) die("remove", r);
                hidden++;
            }
        }
        for (i = 0; i < k; ++i) {
            uint32_t p = near[(next + i) % n];
            if (L->patch_slot[p] != RAD_NONE) continue;
            if ((r = rad_local_add(L, p, &g_ctx)) != RAD_SUCCESS) die("add", r);
        }
        next += k;
        t_up = now() - t0;
        rooms_camera(&w.g, t, &cam);
        t_ap = frame_apply(&w, L, &cam, cand, vis, lit, out, &nv, &nl, &sets_s);
        emit("| %.0f%% | %u | %.1f | %.1f | %.3f | %.2f | %u x %u | %.1f | %.1f | %.1f | %s |\n", 100.0 * fractions[f], k, 1e3 * t_up,
             1e3 * (tr.seconds - fetch0), 1e3 * t_up / k, 1e3 * t_ap, nv, nl, 1e3 * sets_s, t_rebuild / (t_up + t_ap),
             t_neumann / (t_up + t_ap), f == 1 ? (t_rebuild / (t_up + t_ap) >= 15.0 ? "met" : "NOT met") : "");
    }
    {
        uint32_t m = members(L, mem);
        double d;
        t0 = now();
        if ((r = rad_local_rebuild(R, mem, m, &g_ctx)) != RAD_SUCCESS) die("rebuild", r);
        d = plane_drift(L, R);
        emit("\nDrift after the %llu adds and %llu evictions of the whole run against an inverse rebuild of the %u members (%.2f s): "
             "%.2g (max |dT| / max T).\n", (unsigned long long)L->adds, (unsigned long long)L->evictions, m, now() - t0, d);
    }
    emit("\nMemory: local matrix object %.1f MiB (three M x M float planes %.1f MiB, maps and row buffers for N = %u the rest); "
         "rows are read one at a time (at most %u entries, %.1f KiB of buffer). The global F is never resident.\n",
         (double)rad_local_memory(L) / 1048576.0, 12.0 * M * (double)M / 1048576.0, n, n, 8.0 * n / 1024.0);
    rad_local_destroy(L);
    rad_local_destroy(R);
    free(near); free(cand); free(vis); free(lit); free(mem); free(out);
    world_free(&w);
}

/* the full solution of a small scene against the local matrix along a walk */
static void bench_error(void)
{
    world w;
    rad_row_source src;
    rad_local_options o;
    rad_local *L[2] = {NULL, NULL}, *R = NULL;
    rad_multibounce_options mo;
    rad_multibounce *mb = NULL;
    rad_matrix Fm;
    float *F, *Lfull, *out, *outr;
    uint32_t *cols, *near, *cand, *vis, *lit, n, M, i, j, k, frame, frames = 30, nv, nl;
    double err[3] = {0, 0, 0}, errs[3] = {0, 0, 0}, sets_s, gap = 0.0;
    rad_result r;
    world_make(&w, 2, 0.5f);
    n = w.patches->count;
    M = n / 3;
    rooms_rows_source(&w.rows, &src);
    F = (float *)calloc((size_t)n * n, sizeof(float));
    cols = (uint32_t *)malloc(sizeof(uint32_t) * n);
    near = (uint32_t *)malloc(sizeof(uint32_t) * n);
    cand = (uint32_t *)malloc(sizeof(uint32_t) * n);
    vis = (uint32_t *)malloc(sizeof(uint32_t) * n);
    lit = (uint32_t *)malloc(sizeof(uint32_t) * n);
    Lfull = (float *)malloc(sizeof(float) * 3 * n);
    out = (float *)malloc(sizeof(float) * 3 * n);
    outr = (float *)malloc(sizeof(float) * 3 * n);
    if (!F || !cols || !near || !cand || !vis || !lit || !Lfull || !out || !outr) die("malloc", RAD_ERROR_OUT_OF_MEMORY);
    for (i = 0; i < n; ++i) {
        uint32_t c = 0;
        float *vals = F + (size_t)i * n; /* fetch into the row, then scatter in place from the back */
        float *tmp = (float *)malloc(sizeof(float) * n);
        if (!tmp) die("malloc", RAD_ERROR_OUT_OF_MEMORY);
        if ((r = src.fetch(src.user, i, n, cols, tmp, &c)) != RAD_SUCCESS) die("fetch", r);
        for (j = 0; j < c; ++j) vals[cols[j]] = tmp[j];
        free(tmp);
    }
    memset(&Fm, 0, sizeof(Fm));
    Fm.rows = Fm.cols = n;
    Fm.storage = RAD_STORAGE_DENSE;
    Fm.dense = F;
    rad_multibounce_options_default(&mo);
    mo.bounces = RAD_MB_INFINITE;
    if ((r = rad_multibounce_create(&Fm, w.patches->albedo, &mo, &g_ctx, &mb)) != RAD_SUCCESS) die("full multibounce", r);
    if ((r = rad_multibounce_apply(mb, w.E, Lfull, RAD_OUTPUT_INDIRECT, &g_ctx)) != RAD_SUCCESS) die("full apply", r);
    rad_local_options_default(&o);
    o.capacity = M;
    for (k = 0; k < 2; ++k) {
        o.update = k ? RAD_LOCAL_FIRST_ORDER : RAD_LOCAL_EXACT;
        if ((r = rad_local_create(&src, &o, &g_ctx, &L[k])) != RAD_SUCCESS) die("create", r);
    }
    if ((r = rad_local_create(&src, &o, &g_ctx, &R)) != RAD_SUCCESS) die("create", r);
    for (frame = 0; frame < frames; ++frame) {
        rad_camera cam;
        uint32_t V = M * 4 / 5;
        double num[4] = {0, 0, 0, 0}, den = 0.0, nums[3] = {0, 0, 0}, dens = 0.0;
        float *ref = (float *)malloc(sizeof(float) * 3 * n);
        rooms_camera(&w.g, (float)frame / (float)(frames - 1), &cam);
        if ((r = rad_local_nearest(w.patches, cam.position, V, near, &g_ctx)) != RAD_SUCCESS) die("nearest", r);
        for (k = 0; k < 2; ++k) {
            rad_local *X = L[k];
            for (i = 0; i < n; ++i) cand[i] = 0;
            for (i = 0; i < V; ++i) cand[near[i]] = 1;
            for (i = 0; i < X->slot_end; ++i)
                if (X->slot_patch[i] != RAD_NONE && !X->slot_hidden[i] && !cand[X->slot_patch[i]])
                    if ((r = rad_local_remove(X, X->slot_patch[i], &g_ctx)) != RAD_SUCCESS) die("remove", r);
            for (i = 0; i < V; ++i)
                if (X->patch_slot[near[i]] == RAD_NONE || X->slot_hidden[X->patch_slot[near[i]]])
                    if ((r = rad_local_add(X, near[i], &g_ctx)) != RAD_SUCCESS) die("add", r);
        }
        if ((r = rad_local_rebuild(R, near, V, &g_ctx)) != RAD_SUCCESS) die("rebuild", r);
        frame_apply(&w, L[0], &cam, cand, vis, lit, out, &nv, &nl, &sets_s);
        if (!ref) die("malloc", RAD_ERROR_OUT_OF_MEMORY);
        /* the full-world transport of the same sources: sum over P_Lit of T_full E */
        for (i = 0; i < nv; ++i)
            for (j = 0; j < 3; ++j) {
                double a = 0.0;
                uint32_t q;
                for (q = 0; q < nl; ++q) a += (double)mb->planes[(size_t)j * n * n + (size_t)vis[i] * n + lit[q]] * w.E[3 * (size_t)lit[q] + j];
                ref[3 * (size_t)vis[i] + j] = (float)a;
            }
        for (i = 0; i < nv; ++i)
            for (j = 0; j < 3; ++j) {
                double d = (double)out[3 * (size_t)vis[i] + j] - Lfull[3 * (size_t)vis[i] + j];
                double e = (double)out[3 * (size_t)vis[i] + j] - ref[3 * (size_t)vis[i] + j];
                num[0] += d * d;
                nums[0] += e * e;
                den += (double)Lfull[3 * (size_t)vis[i] + j] * Lfull[3 * (size_t)vis[i] + j];
                dens += (double)ref[3 * (size_t)vis[i] + j] * ref[3 * (size_t)vis[i] + j];
            }
        /* the same P_Vis and P_Lit for the first-order and rebuilt matrices (lit: members of each) */
        {
            uint32_t nc = members(L[1], cand), nl1 = 0;
            rad_local_lit(w.E, cand, nc, 0.0f, lit, &nl1);
            if ((r = rad_local_apply(L[1], w.E, vis, nv, lit, nl1, outr, RAD_OUTPUT_INDIRECT, &g_ctx)) != RAD_SUCCESS) die("apply", r);
            for (i = 0; i < nv; ++i)
                for (j = 0; j < 3; ++j) {
                    double d = (double)outr[3 * (size_t)vis[i] + j] - Lfull[3 * (size_t)vis[i] + j];
                    double e = (double)outr[3 * (size_t)vis[i] + j] - ref[3 * (size_t)vis[i] + j];
                    double g = (double)outr[3 * (size_t)vis[i] + j] - out[3 * (size_t)vis[i] + j];
                    num[1] += d * d;
                    nums[1] += e * e;
                    num[3] += g * g;
                }
            nc = members(R, cand);
            rad_local_lit(w.E, cand, nc, 0.0f, lit, &nl1);
            if ((r = rad_local_apply(R, w.E, vis, nv, lit, nl1, outr, RAD_OUTPUT_INDIRECT, &g_ctx)) != RAD_SUCCESS) die("apply", r);
            for (i = 0; i < nv; ++i)
                for (j = 0; j < 3; ++j) {
                    double d = (double)outr[3 * (size_t)vis[i] + j] - Lfull[3 * (size_t)vis[i] + j];
                    double e = (double)outr[3 * (size_t)vis[i] + j] - ref[3 * (size_t)vis[i] + j];
                    num[2] += d * d;
                    nums[2] += e * e;
                }
        }
        for (k = 0; k < 3; ++k) {
            err[k] += den > 0.0 ? sqrt(num[k] / den) / frames : 0.0;
            errs[k] += dens > 0.0 ? sqrt(nums[k] / dens) / frames : 0.0;
        }
        gap += dens > 0.0 ? sqrt(num[3] / dens) / frames : 0.0;
        free(ref);
    }
    emit("\n### Error against the full solution (2 x 2 rooms, N = %u, full L_inf by the K = inf multi-bounce build)\n\n", n);
    emit("Camera walk of %u frames along the corridor; visible set = the %u patches nearest the camera, capacity M = %u (the rest "
         "hold hidden members); L = T E over P_Vis x P_Lit (relative L2 on P_Vis, mean over frames) against (a) the full-world "
         "L_inf, which also has the light of every source outside the set (a local matrix cannot see it), and (b) the full-world "
         "transport of the same sources, sum over P_Lit of T_full E (the error of the matrix itself).\n\n",
         frames, M * 4 / 5, M);
    emit("| matrix | (a) vs full L_inf | (b) vs full transport of P_Lit |\n|---|---|---|\n");
    emit("| exact update (Sherman-Morrison, hidden members kept) | %.4f | %.4f |\n", err[0], errs[0]);
    emit("| first-order update (Shcherbakov 2025) | %.4f | %.4f |\n", err[1], errs[1]);
    emit("| rebuilt each frame from the visible set only | %.4f | %.4f |\n", err[2], errs[2]);
    emit("\nFirst-order against exact on the same frames: %.4f (relative L2, normalised as (b)).\n", gap);
    rad_local_destroy(L[0]);
    rad_local_destroy(L[1]);
    rad_local_destroy(R);
    rad_multibounce_destroy(mb);
    free(F); free(cols); free(near); free(cand); free(vis); free(lit); free(Lfull); free(out); free(outr);
    world_free(&w);
}

int main(int argc, char **argv)
{
    int i, quick = 0, detail = 0;
    uint32_t M = 4096, grid = 8;
    double t0 = now();
    for (i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--quick")) quick = 1;
        else if (!strcmp(argv[i], "--detail")) detail = 1; /* the error table against the full solution */
        else if (!strcmp(argv[i], "--append") && i + 1 < argc) {
            g_md = fopen(argv[++i], "a");
            if (!g_md) { fprintf(stderr, "cannot open %s\n", argv[i]); return 1; }
        } else if (!strcmp(argv[i], "--m") && i + 1 < argc) M = (uint32_t)atoi(argv[++i]);
    }
    if (quick) { M = 1024; grid = 4; }
    memset(&g_ctx, 0, sizeof(g_ctx));
    g_ctx.parallel_for = serial_for;
    g_ctx.task_count = 1;
    emit("\n## Local multi-bounce matrix for large scenes\n\nCPU, 1 thread%s.\n", quick ? " (--quick)" : "");
    emit("\n");
    emit_machine();
    bench_large(grid, M);
    if (detail) bench_error();
    emit("\n(tests/bench/local.c: %.0f s in all)\n", now() - t0);
    if (g_md) fclose(g_md);
    return 0;
}
