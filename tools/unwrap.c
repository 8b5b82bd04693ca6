/* unwrap.c - a simple automatic lightmap unwrap for `rad lightmap` when a mesh has no second
   uv set. SIMPLE, not xatlas: charts are grown breadth-first over shared edges (the same
   end points in space) from the first unassigned triangle, taking a neighbour whose normal is
   within 30 degrees of the chart's first triangle; each chart is projected onto the plane of
   that first normal (so it keeps its shape up to a cos 30 squeeze) and boxed; the boxes are
   packed in shelves (tallest first) at the largest common scale that fits the atlas, found by
   bisection, each box with a gutter of 2 texels on every side. No rotation, no overlap check
   inside a chart (a strongly curved chart could fold onto itself within the 30 degrees).
   Every chart costs at least 5 x 5 texels (one texel and its gutters), so a scene of many
   small charts needs a larger atlas whatever its area: when the user gave no size, the tool
   doubles the atlas until the charts pack. */
#include "tool.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define UNWRAP_COS 0.8660254f /* 30 degrees */
#define UNWRAP_PAD 2.0        /* texels of gutter on each side of a chart */

typedef struct uw_edge {
    float a[3], b[3];
    uint32_t tri;
} uw_edge;

static int uw_pcmp(const float *a, const float *b)
{
    int k;
    for (k = 0; k < 3; ++k) {
        if (a[k] < b[k]) return -1;
        if (a[k] > b[k]) return 1;
    }
    return 0;
}

static int uw_edge_cmp(const void *x, const void *y)
{
    const uw_edge *e = (const uw_edge *)x, *f = (const uw_edge *)y;
    int r = uw_pcmp(e->a, f->a);
    if (r) return r;
    r = uw_pcmp(e->b, f->b);
    if (r) return r;
    return e->tri < f->tri ? -1 : e->tri > f->tri ? 1 : 0;
}

typedef struct uw_chart {
    double min[2], max[2];  /* projected bounds, world units */
    double x, y;            /* placed corner, texels */
    uint32_t id;
} uw_chart;

static double uw_rect_w(const uw_chart *c, double s) { return ceil((c->max[0] - c->min[0]) * s) + 2.0 * UNWRAP_PAD; }
static double uw_rect_h(const uw_chart *c, double s) { return ceil((c->max[1] - c->min[1]) * s) + 2.0 * UNWRAP_PAD; }

static int uw_by_height(const void *x, const void *y)
{
    const uw_chart *a = (const uw_chart *)x, *b = (const uw_chart *)y;
    double ha = a->max[1] - a->min[1], hb = b->max[1] - b->min[1];
    if (ha > hb) return -1;
    if (ha < hb) return 1;
    return a->id < b->id ? -1 : a->id > b->id ? 1 : 0;
}

/* shelf packing at scale s (texels per world unit); 1 when every chart fits */
static int uw_pack(uw_chart *c, uint32_t n, double s, uint32_t W, uint32_t H)
{
    double x = 0.0, y = 0.0, shelf = 0.0;
    uint32_t i;
    for (i = 0; i < n; ++i) {
        double w = uw_rect_w(&c[i], s), h = uw_rect_h(&c[i], s);
        if (w > W) return 0;
        if (x + w > W) {
            y += shelf;
            x = 0.0;
            shelf = 0.0;
        }
        if (y + h > H) return 0;
        c[i].x = x;
        c[i].y = y;
        x += w;
        if (h > shelf) shelf = h;
    }
    return 1;
}

/* a scale small enough that every chart of positive extent is one texel plus its gutters */
#define UNWRAP_TINY 1e-12

/* the smallest square power-of-two atlas in [from, to] into which the charts pack (at a
   positive scale), or 0 */
static uint32_t uw_fitting_side(uw_chart *c, uint32_t n, uint32_t from, uint32_t to)
{
    uint32_t p = 4;
    while (p < from) p *= 2;
    for (; p <= to; p *= 2)
        if (uw_pack(c, n, UNWRAP_TINY, p, p)) return p;
    return 0;
}

static void uw_bytes(char *buf, size_t len, double b)
{
    if (b >= 1073741824.0) snprintf(buf, len, "%.1f GiB", b / 1073741824.0);
    else snprintf(buf, len, "%.0f MiB", b / 1048576.0);
}

/* The triangles' neighbours over shared edges (positions equal, either winding) as CSR:
   *first_out (T + 1 offsets) and *adj_out, malloc'd; 0, or 1 when out of memory (the caller
   frees what was set). */
static int uw_adjacency(const rad_scene *scene, uint32_t **first_out, uint32_t **adj_out)
{
    uint32_t T = scene->triangle_count, t, i, *deg = NULL, *first = NULL, *adj = NULL;
    size_t ne = 3 * (size_t)T, k;
    uw_edge *edges = NULL;
    int ok = 0;
    *first_out = *adj_out = NULL;
    edges = (uw_edge *)malloc(sizeof(uw_edge) * ne);
    deg = (uint32_t *)calloc((size_t)T + 1, sizeof(uint32_t));
    if (!edges || !deg) goto done;
    /* adjacency over shared edges: sorted edge records, equal neighbours are adjacent */
    for (t = 0; t < T; ++t)
        for (i = 0; i < 3; ++i) {
            uw_edge *e = &edges[3 * (size_t)t + i];
            const float *a = scene->positions + 9 * (size_t)t + 3 * i, *b = scene->positions + 9 * (size_t)t + 3 * ((i + 1) % 3);
            if (uw_pcmp(a, b) > 0) { const float *x = a; a = b; b = x; }
            memcpy(e->a, a, sizeof e->a);
            memcpy(e->b, b, sizeof e->b);
            e->tri = t;
        }
    qsort(edges, ne, sizeof(uw_edge), uw_edge_cmp);
    for (k = 0; k + 1 < ne; ++k)
        if (!uw_pcmp(edges[k].a, edges[k + 1].a) && !uw_pcmp(edges[k].b, edges[k + 1].b)) {
            deg[edges[k].tri]++;
            deg[edges[k + 1].tri]++;
        }
    *first_out = first = (uint32_t *)malloc(sizeof(uint32_t) * ((size_t)T + 1));
    if (!first) goto done;
    first[0] = 0;
    for (t = 0; t < T; ++t) first[t + 1] = first[t] + deg[t];
    *adj_out = adj = (uint32_t *)malloc(sizeof(uint32_t) * (first[T] ? first[T] : 1u));
    if (!adj) goto done;
    memset(deg, 0, sizeof(uint32_t) * T);
    for (k = 0; k + 1 < ne; ++k)
        if (!uw_pcmp(edges[k].a, edges[k + 1].a) && !uw_pcmp(edges[k].b, edges[k + 1].b)) {
            uint32_t a = edges[k].tri, b = edges[k + 1].tri;
            adj[first[a] + deg[a]++] = b;
            adj[first[b] + deg[b]++] = a;
        }
    ok = 1;
done:
    free(edges);
    free(deg);
    return ok ? 0 : 1;
}

/* No size given and the charts do not fit *width x *height: the smallest square power of two
   that packs them, within autosize's cap and memory, into *width and *height (said on stderr);
   0, or 1 after printing why not. */
static int uw_autosize(const char *cmd, const char *size_option, uw_chart *charts, uint32_t nch,
                       const tool_unwrap_auto *autosize, uint32_t *width, uint32_t *height)
{
    /* no size given: the smallest square power of two that packs, within the cap and memory */
    uint32_t side = uw_fitting_side(charts, nch, *width > *height ? *width : *height, autosize->max_side);
    double bytes = side ? (double)side * side * autosize->bytes_per_texel : 0.0;
    char bbuf[32], lbuf[32];
    if (!side) {
        uint32_t need = uw_fitting_side(charts, nch, 2u * autosize->max_side, 16384u);
        fprintf(stderr, "rad %s: %u charts do not fit a %ux%u atlas, the largest the tool picks by itself", cmd, nch,
                autosize->max_side, autosize->max_side);
        if (need) fprintf(stderr, ": give %s %u (it fits) or a mesh with its own lightmap uvs\n", size_option, need);
        else fprintf(stderr, ", nor the largest allowed (16384): give the meshes their own lightmap uvs\n");
        return 1;
    }
    if (autosize->memory_limit > 0.0 && bytes > autosize->memory_limit) {
        uw_bytes(bbuf, sizeof bbuf, bytes);
        uw_bytes(lbuf, sizeof lbuf, autosize->memory_limit);
        fprintf(stderr, "rad %s: %u charts need a %ux%u atlas, about %s of texels and samples; only %s may be used (%s): "
                        "give the meshes their own lightmap uvs\n",
                cmd, nch, side, side, bbuf, lbuf, autosize->memory_from ? autosize->memory_from : "the memory limit");
        return 1;
    }
    uw_bytes(bbuf, sizeof bbuf, bytes);
    fprintf(stderr, "rad %s: %u charts do not fit the default %ux%u atlas: using %ux%u (about %s; %s N sets it)\n", cmd,
            nch, *width, *height, side, side, bbuf, size_option);
    *width = *height = side;
    return 0;
}

int tool_unwrap(const char *cmd, const char *size_option, const rad_scene *scene, uint32_t *width_io, uint32_t *height_io,
                const tool_unwrap_auto *autosize, float *out_uvs, uint32_t *out_charts)
{
    uint32_t width = *width_io, height = *height_io;
    uint32_t T = scene->triangle_count, t, i, nch = 0, *chart = NULL, *queue = NULL, *first = NULL, *adj = NULL;
    uw_chart *charts = NULL;
    float (*frame)[6] = NULL;  /* per chart: the two axes of its plane */
    double area = 0.0, lo, hi, s;
    int ok = 0, it;
    chart = (uint32_t *)malloc(sizeof(uint32_t) * T);
    queue = (uint32_t *)malloc(sizeof(uint32_t) * T);
    if (!chart || !queue || uw_adjacency(scene, &first, &adj)) goto done;
    /* charts */
    for (t = 0; t < T; ++t) chart[t] = UINT32_MAX;
    charts = (uw_chart *)malloc(sizeof(uw_chart) * (T ? T : 1u));
    frame = (float (*)[6])malloc(sizeof(float) * 6 * (T ? T : 1u));
    if (!charts || !frame) goto done;
    for (t = 0; t < T; ++t) {
        uint32_t head = 0, tail = 0, c = nch;
        const float *n0 = scene->normals + 3 * (size_t)t;
        float a[3] = {1.0f, 0.0f, 0.0f}, *u = frame[c], *v = frame[c] + 3, l;
        if (chart[t] != UINT32_MAX) continue;
        ++nch;
        /* the plane's axes: any two perpendicular to the first normal */
        if (fabsf(n0[0]) > 0.5f) a[0] = 0.0f, a[1] = 1.0f;
        u[0] = n0[1] * a[2] - n0[2] * a[1];
        u[1] = n0[2] * a[0] - n0[0] * a[2];
        u[2] = n0[0] * a[1] - n0[1] * a[0];
        l = sqrtf(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
        u[0] /= l, u[1] /= l, u[2] /= l;
        v[0] = n0[1] * u[2] - n0[2] * u[1];
        v[1] = n0[2] * u[0] - n0[0] * u[2];
        v[2] = n0[0] * u[1] - n0[1] * u[0];
        charts[c].id = c;
        charts[c].min[0] = charts[c].min[1] = 1e300;
        charts[c].max[0] = charts[c].max[1] = -1e300;
        chart[t] = c;
        queue[tail++] = t;
        while (head < tail) {
            uint32_t q = queue[head++], j;
            for (j = 0; j < 3; ++j) {
                const float *p = scene->positions + 9 * (size_t)q + 3 * j;
                double x = (double)p[0] * u[0] + (double)p[1] * u[1] + (double)p[2] * u[2];
                double y = (double)p[0] * v[0] + (double)p[1] * v[1] + (double)p[2] * v[2];
                if (x < charts[c].min[0]) charts[c].min[0] = x;
                if (x > charts[c].max[0]) charts[c].max[0] = x;
                if (y < charts[c].min[1]) charts[c].min[1] = y;
                if (y > charts[c].max[1]) charts[c].max[1] = y;
            }
            for (j = first[q]; j < first[q + 1]; ++j) {
                uint32_t nb = adj[j];
                const float *nn = scene->normals + 3 * (size_t)nb;
                if (chart[nb] != UINT32_MAX || n0[0] * nn[0] + n0[1] * nn[1] + n0[2] * nn[2] < UNWRAP_COS) continue;
                chart[nb] = c;
                queue[tail++] = nb;
            }
        }
        area += (charts[c].max[0] - charts[c].min[0]) * (charts[c].max[1] - charts[c].min[1]);
    }
    /* the largest scale that packs: bisection below the one that fills the atlas exactly */
    qsort(charts, nch, sizeof(uw_chart), uw_by_height);
    if (autosize && !uw_pack(charts, nch, UNWRAP_TINY, width, height) &&
        uw_autosize(cmd, size_option, charts, nch, autosize, &width, &height))
        goto done;
    hi = area > 0.0 ? sqrt((double)width * height / area) : 1.0;
    lo = UNWRAP_TINY;
    if (!uw_pack(charts, nch, UNWRAP_TINY, width, height)) {
        uint32_t side = uw_fitting_side(charts, nch, 4u, 16384u);
        fprintf(stderr, "rad %s: %u charts do not fit a %ux%u atlas even as single texels: ", cmd, nch, width, height);
        if (side) fprintf(stderr, "use %s %u (the smallest power of two that fits)\n", size_option, side);
        else fprintf(stderr, "they do not fit the largest allowed (16384) either: give the meshes their own lightmap uvs\n");
        goto done;
    }
    for (it = 0; it < 40; ++it) {
        double mid = 0.5 * (lo + hi);
        if (uw_pack(charts, nch, mid, width, height)) lo = mid;
        else hi = mid;
    }
    s = lo;
    uw_pack(charts, nch, s, width, height);
    {
        /* charts[] is sorted: find each chart's slot by id */
        uint32_t *slot = queue;
        for (i = 0; i < nch; ++i) slot[charts[i].id] = i;
        for (t = 0; t < T; ++t) {
            uint32_t c = chart[t];
            const uw_chart *ch = &charts[slot[c]];
            const float *u = frame[c], *v = frame[c] + 3;
            for (i = 0; i < 3; ++i) {
                const float *p = scene->positions + 9 * (size_t)t + 3 * i;
                double x = (double)p[0] * u[0] + (double)p[1] * u[1] + (double)p[2] * u[2];
                double y = (double)p[0] * v[0] + (double)p[1] * v[1] + (double)p[2] * v[2];
                out_uvs[6 * (size_t)t + 2 * i] = (float)((ch->x + UNWRAP_PAD + (x - ch->min[0]) * s) / width);
                out_uvs[6 * (size_t)t + 2 * i + 1] = (float)((ch->y + UNWRAP_PAD + (y - ch->min[1]) * s) / height);
            }
        }
    }
    if (out_charts) *out_charts = nch;
    *width_io = width;
    *height_io = height;
    fprintf(stderr, "rad %s: unwrapped %u triangles into %u charts, %.1f texels per unit\n", cmd, T, nch, s);
    ok = 1;
done:
    free(chart);
    free(queue);
    free(first);
    free(adj);
    free(charts);
    free(frame);
    return ok ? 0 : 1;
}
