/* cmd_merge.c - the distributed bake: `rad bake --shard I/N | --rows A:B` writes a part,
   `rad merge PART... -o FILE.radb` joins the parts into the bake a single `rad bake` writes.

   A part holds the pairs {i, j}, j > i, of its rows (rad_form_factor_pairs: each unordered
   pair is computed by exactly one part, and F_ji comes with F_ij by reciprocity, with the
   bits of the single bake), and what the merge needs to finish the bake without the scene:
   the patches, E, D, the signature (scene hashes and the options' hash), rad.options, and a
   rad.shard record (library version, patch count, which shard, the pairs it holds). Every
   part computes the patches and the direct light itself (cheap beside the pairs: N rays per
   light sample against N^2 / 2 pairs), so the merge can check that the parts agree on them
   byte for byte.

   The merge refuses, naming the part and the reason: a file that is no part, parts of another
   library version, of other scenes (geometry or materials hash), with other options (naming
   the option), with patches or direct light that differ, rows given twice, and rows missing
   (a missing shard by its number). Then it assembles F, solves as `rad bake` does (the
   solver and bounces of rad.options) and writes the sections of cmd_bake.c's save_bake in
   its order, so the output equals the single bake byte for byte (a part's run record, the
   seconds, stays in the part). docs/distributed.md. */
#include "tool.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* ---- the shard split ------------------------------------------------------------------- */

int tool_parse_shard(const char *cmd, const char *text, tool_shard_spec *s)
{
    unsigned long i, n;
    char *end;
    if (!text || *text < '0' || *text > '9') goto bad;
    i = strtoul(text, &end, 10);
    if (*end != '/' || end[1] < '0' || end[1] > '9') goto bad;
    n = strtoul(end + 1, &end, 10);
    if (*end != '\0' || n == 0 || n > TOOL_MAX_SHARDS || i >= n) goto bad;
    s->index = (uint32_t)i;
    s->count = (uint32_t)n;
    return 0;
bad:
    fprintf(stderr, "rad %s: bad value '%s' for --shard (want I/N with 0 <= I < N <= %u)\n", cmd, text ? text : "",
            TOOL_MAX_SHARDS);
    return 2;
}

int tool_parse_rows(const char *cmd, const char *text, tool_shard_spec *s)
{
    unsigned long a, b;
    char *end;
    if (!text || *text < '0' || *text > '9') goto bad;
    a = strtoul(text, &end, 10);
    if (*end != ':' || end[1] < '0' || end[1] > '9') goto bad;
    b = strtoul(end + 1, &end, 10);
    if (*end != '\0' || b > 0xFFFFFFFFul || a >= b) goto bad;
    s->rows = 1;
    s->row_begin = (uint32_t)a;
    s->row_end = (uint32_t)b;
    return 0;
bad:
    fprintf(stderr, "rad %s: bad value '%s' for --rows (want A:B, the rows A to B-1, A < B)\n", cmd, text ? text : "");
    return 2;
}

/* Shard I of n: the rows cut into K = min(N, 64 n) chunks dealt out in a snake (0 1 .. n-1,
   n-1 .. 1 0, ...), so each shard gets chunks from the top of the triangle, where a row has
   many pairs j > i, and from the bottom, where it has few, and from every part of the scene:
   the cost of a pair varies with where it is (near pairs take 16x the points, rays cross
   different geometry), and 64 chunks a shard average that out where 8 did not.
   Adjacent chunks of one shard are joined. */
uint32_t tool_shard_ranges(uint32_t N, uint32_t I, uint32_t n, uint32_t *ranges)
{
    uint32_t K = N < TOOL_SHARD_CHUNKS * n ? N : TOOL_SHARD_CHUNKS * n, q, count = 0;
    for (q = 0; q < K; ++q) {
        uint32_t round = q / n, pos = q % n, shard = (round & 1u) ? n - 1u - pos : pos;
        uint32_t b = (uint32_t)((uint64_t)q * N / K), e = (uint32_t)((uint64_t)(q + 1u) * N / K);
        if (shard != I || b == e) continue;
        if (count && ranges[2 * count - 1] == b) ranges[2 * count - 1] = e;
        else ranges[2 * count] = b, ranges[2 * count + 1] = e, ++count;
    }
    return count;
}

/* ---- writing a part -------------------------------------------------------------------- */

int tool_bake_part(const char *cmd, const tool_world *w, const tool_classic_options *o,
                       const tool_shard_spec *spec, void **out, size_t *out_size)
{
    tool_classic c;
    rad_form_factor_options fo;
    rad_context ctx;
    rad_result r;
    tool_bake_info info;
    tool_shard_info sh;
    rad_bake_signature sig;
    rad_container *ct = NULL;
    rad_section *secs = NULL;
    void *base = NULL, *dst = NULL;
    size_t base_size = 0, dst_size = 0;
    uint32_t ranges[2 * TOOL_SHARD_CHUNKS], nr, N, k, i, count;
    uint64_t pairs = 0;
    float *up = NULL, *lo = NULL;
    double t0;
    clock_t c0;
    int rc = 1;
    *out = NULL;
    *out_size = 0;
    if (tool_classic_sources(cmd, w, o, &c)) return 1;
    N = c.patches->count;
    if (spec->rows) {
        if (spec->row_end > N) {
            fprintf(stderr, "rad %s: --rows %u:%u is beyond the %u patches (rows 0:%u)\n", cmd, spec->row_begin, spec->row_end,
                    N, N);
            goto done;
        }
        ranges[0] = spec->row_begin, ranges[1] = spec->row_end, nr = 1;
    } else {
        nr = tool_shard_ranges(N, spec->index, spec->count, ranges);
    }
    for (k = 0; k < nr; ++k) pairs += rad_form_factor_pair_count(N, ranges[2 * k], ranges[2 * k + 1]);
    if (pairs > (uint64_t)((size_t)-1 / sizeof(float))) {
        fprintf(stderr, "rad %s: %llu pairs do not fit in memory addresses\n", cmd, (unsigned long long)pairs);
        goto done;
    }
    up = (float *)tool_calloc((size_t)pairs, sizeof(float));
    lo = (float *)tool_calloc((size_t)pairs, sizeof(float));
    memset(&sh, 0, sizeof sh);
    sh.magic = TOOL_SHARD_MAGIC;
    sh.format = 1;
    strncpy(sh.library, RAD_VERSION_STRING, sizeof sh.library - 1);
    sh.patches = N;
    sh.shard = spec->rows ? 0 : spec->index;
    sh.shard_count = spec->rows ? 0 : spec->count;
    sh.range_count = nr;
    sh.pairs = pairs;
    rad_form_factor_options_default(&fo);
    fo.samples = o->samples;
    t0 = tool_seconds();
    c0 = clock();
    tool_context(&ctx, "form factors");
    /* one call for all the ranges: the threads share every row of the part */
    r = rad_form_factor_pairs(c.patches, &w->rc, &fo, ranges, nr, up, lo, &sh.pairs_evaluated, &ctx);
    tool_progress_end();
    if (r != RAD_SUCCESS) {
        tool_fail(cmd, "rad_form_factor_pairs", r);
        goto done;
    }
    sh.seconds = tool_seconds() - t0;
    if (spec->rows) fprintf(stderr, "rad %s: rows %u:%u", cmd, ranges[0], ranges[1]);
    else fprintf(stderr, "rad %s: shard %u/%u (%u row ranges)", cmd, spec->index, spec->count, nr);
    fprintf(stderr, ": %llu of %llu pairs (%.1f%%), %llu evaluated, in %.2f s (%.2f s CPU)\n", (unsigned long long)pairs,
            (unsigned long long)rad_form_factor_pair_count(N, 0, N),
            100.0 * (double)pairs / (double)(rad_form_factor_pair_count(N, 0, N) + (N < 2)),
            (unsigned long long)sh.pairs_evaluated, sh.seconds, (double)(clock() - c0) / CLOCKS_PER_SEC);

    /* patches, vertices, triangles, E and the signature, then ours */
    tool_context(&ctx, NULL);
    if ((r = rad_save_memory(c.patches, NULL, c.E, NULL, &ctx, &base, &base_size)) != RAD_SUCCESS) {
        tool_fail(cmd, "rad_save_memory", r);
        goto done;
    }
    if ((r = rad_container_create(base, base_size, &ctx, &ct)) != RAD_SUCCESS) {
        tool_fail(cmd, "rad_container_create", r);
        goto done;
    }
    count = rad_container_section_count(ct);
    secs = (rad_section *)tool_calloc((size_t)count + 6, sizeof(rad_section));
    for (i = 0; i < count; ++i) secs[i] = *rad_container_section(ct, i);
    tool_bake_info_fill(&info, w, o);
    tool_sign_options(secs, count, &info, w, &sig);
    k = count;
    secs[k].type = RAD_SECTION_VECTOR, secs[k].elem_size = 12, secs[k].count = N, secs[k].data = c.D;
    strcpy(secs[k++].name, "D");
    secs[k].type = TOOL_SECTION_OPTIONS, secs[k].elem_size = sizeof info, secs[k].count = 1, secs[k].data = &info;
    strcpy(secs[k++].name, "rad.options");
    secs[k].type = TOOL_SECTION_SHARD, secs[k].elem_size = sizeof sh, secs[k].count = 1, secs[k].data = &sh;
    strcpy(secs[k++].name, "rad.shard");
    secs[k].type = TOOL_SECTION_ROWS, secs[k].elem_size = 8, secs[k].count = nr, secs[k].data = ranges;
    strcpy(secs[k++].name, "rad.rows");
    secs[k].type = TOOL_SECTION_PAIRS, secs[k].elem_size = 4, secs[k].count = pairs, secs[k].data = up;
    strcpy(secs[k++].name, "F.upper");
    secs[k].type = TOOL_SECTION_PAIRS, secs[k].elem_size = 4, secs[k].count = pairs, secs[k].data = lo;
    strcpy(secs[k++].name, "F.lower");
    if ((r = rad_container_size(secs, k, &dst_size)) != RAD_SUCCESS) {
        tool_fail(cmd, "rad_container_size", r);
        goto done;
    }
    dst = malloc(dst_size);
    if (!dst) {
        fprintf(stderr, "rad %s: out of memory for a part of %lu bytes\n", cmd, (unsigned long)dst_size);
        goto done;
    }
    if ((r = rad_container_write(secs, k, dst, dst_size)) != RAD_SUCCESS) {
        tool_fail(cmd, "rad_container_write", r);
        goto done;
    }
    *out = dst;
    *out_size = dst_size;
    dst = NULL;
    rc = 0;
done:
    free(dst);
    free(secs);
    rad_container_destroy(ct);
    rad_free_buffer(base, &ctx);
    free(up);
    free(lo);
    tool_classic_free(&c);
    return rc;
}

/* ---- merging --------------------------------------------------------------------------- */

/* one part, opened and checked on its own */
typedef struct part_view {
    rad_bake *bake;
    const tool_shard_info *sh;
    const tool_bake_info *info;
    const rad_bake_signature *sig;
    const uint32_t *ranges;
    const float *up, *lo;
    const rad_section *keep[5]; /* patches, vertices, triangles, E, D: equal in every part */
} part_view;

static const char *const keep_names[5] = {"patches", "vertices", "triangles", "E", "D"};

static int open_part(const char *cmd, const tool_part *p, part_view *v)
{
    rad_context ctx;
    rad_result r;
    const rad_container *ct;
    const rad_section *s;
    uint64_t pairs = 0;
    uint32_t k, N;
    static const uint32_t keep_types[5] = {RAD_SECTION_PATCHES, RAD_SECTION_PATCH_VERTICES, RAD_SECTION_TRIANGLES,
                                           RAD_SECTION_VECTOR, RAD_SECTION_VECTOR};
    memset(v, 0, sizeof *v);
    tool_context(&ctx, NULL);
    if ((r = rad_load_memory(p->data, p->size, &ctx, &v->bake)) != RAD_SUCCESS) {
        fprintf(stderr, "rad %s: %s is not a readable bake part: %s\n", cmd, p->name, rad_result_string(r));
        return 1;
    }
    ct = v->bake->container;
    s = rad_container_find(ct, TOOL_SECTION_SHARD, "rad.shard");
    if (!s) {
        fprintf(stderr, "rad %s: %s is not a part of a sharded bake (it has no rad.shard section; "
                        "rad bake --shard I/N or --rows A:B writes parts)\n", cmd, p->name);
        return 1;
    }
    if (s->elem_size != sizeof *v->sh || s->count != 1 || ((const tool_shard_info *)s->data)->magic != TOOL_SHARD_MAGIC ||
        ((const tool_shard_info *)s->data)->format != 1) {
        fprintf(stderr, "rad %s: %s holds a rad.shard record of another format (another version of rad?)\n", cmd, p->name);
        return 1;
    }
    v->sh = (const tool_shard_info *)s->data;
    N = v->bake->patches.count;
    s = rad_container_find(ct, TOOL_SECTION_OPTIONS, "rad.options");
    if (!s || s->elem_size != sizeof *v->info || s->count != 1 || !v->bake->signature) {
        fprintf(stderr, "rad %s: %s has no rad.options record or signature\n", cmd, p->name);
        return 1;
    }
    v->info = (const tool_bake_info *)s->data;
    v->sig = v->bake->signature;
    for (k = 0; k < 5; ++k) {
        v->keep[k] = rad_container_find(ct, keep_types[k], k >= 3 ? keep_names[k] : NULL);
        if (!v->keep[k]) {
            fprintf(stderr, "rad %s: %s has no '%s' section\n", cmd, p->name, keep_names[k]);
            return 1;
        }
    }
    if (v->sh->patches != N) {
        fprintf(stderr, "rad %s: %s: its rad.shard record says %u patches, it holds %u\n", cmd, p->name, v->sh->patches, N);
        return 1;
    }
    s = rad_container_find(ct, TOOL_SECTION_ROWS, "rad.rows");
    if (!s || s->elem_size != 8 || s->count != v->sh->range_count) {
        fprintf(stderr, "rad %s: %s: its row ranges (rad.rows) are missing or do not match rad.shard\n", cmd, p->name);
        return 1;
    }
    v->ranges = (const uint32_t *)s->data;
    for (k = 0; k < v->sh->range_count; ++k) {
        uint32_t b = v->ranges[2 * k], e = v->ranges[2 * k + 1];
        if (b >= e || e > N || (k && b < v->ranges[2 * k - 1])) {
            fprintf(stderr, "rad %s: %s: row range %u:%u is empty, beyond the %u patches or out of order\n", cmd, p->name, b,
                    e, N);
            return 1;
        }
        pairs += rad_form_factor_pair_count(N, b, e);
    }
    for (k = 0; k < 2; ++k) {
        s = rad_container_find(ct, TOOL_SECTION_PAIRS, k ? "F.lower" : "F.upper");
        if (!s || s->elem_size != 4 || s->count != pairs || pairs != v->sh->pairs) {
            fprintf(stderr, "rad %s: %s: %s is missing or does not hold the %llu pairs of its rows\n", cmd, p->name,
                    k ? "F.lower" : "F.upper", (unsigned long long)pairs);
            return 1;
        }
        if (k) v->lo = (const float *)s->data;
        else v->up = (const float *)s->data;
    }
    return 0;
}

/* 0 when part b agrees with part a on everything but its rows; else prints why */
static int same_bake(const char *cmd, const tool_part *pa, const part_view *a, const tool_part *pb,
                     const part_view *b)
{
    const tool_bake_info *x = a->info, *y = b->info;
    uint32_t k;
    if (strncmp(a->sh->library, b->sh->library, sizeof a->sh->library)) {
        fprintf(stderr, "rad %s: %s was baked by radiosity.h %.16s and %s by %.16s: the parts of one bake come from one "
                        "version\n", cmd, pa->name, a->sh->library, pb->name, b->sh->library);
        return 1;
    }
    if (a->sig->geometry != b->sig->geometry || a->sig->materials != b->sig->materials || x->triangle_count != y->triangle_count) {
        fprintf(stderr, "rad %s: %s and %s were baked from different scenes (%s hash %016llx vs %016llx)\n", cmd, pa->name,
                pb->name, a->sig->geometry != b->sig->geometry ? "geometry" : "materials",
                (unsigned long long)(a->sig->geometry != b->sig->geometry ? a->sig->geometry : a->sig->materials),
                (unsigned long long)(a->sig->geometry != b->sig->geometry ? b->sig->geometry : b->sig->materials));
        return 1;
    }
    if (memcmp(x, y, sizeof *x) || a->sig->options != b->sig->options) {
        char what[160];
        if (x->patches != y->patches) sprintf(what, "--patches %u vs %u", x->patches, y->patches);
        else if (x->max_edge != y->max_edge) sprintf(what, "--max-edge %g vs %g", (double)x->max_edge, (double)y->max_edge);
        else if (x->samples != y->samples) sprintf(what, "--samples %u vs %u", x->samples, y->samples);
        else if (x->solver != y->solver) sprintf(what, "--solver %u vs %u", x->solver, y->solver);
        else if (x->bounces != y->bounces) sprintf(what, "--bounces %u vs %u", x->bounces, y->bounces);
        else if (x->light_samples != y->light_samples)
            sprintf(what, "--light-samples %u vs %u", x->light_samples, y->light_samples);
        else sprintf(what, "the lights given on the command line, or the rad.options records");
        fprintf(stderr, "rad %s: %s and %s were baked with different options (%s)\n", cmd, pa->name, pb->name, what);
        return 1;
    }
    if (a->sh->patches != b->sh->patches) {
        fprintf(stderr, "rad %s: %s has %u patches and %s %u\n", cmd, pa->name, a->sh->patches, pb->name, b->sh->patches);
        return 1;
    }
    for (k = 0; k < 5; ++k) {
        const rad_section *s = a->keep[k], *t = b->keep[k];
        if (s->elem_size != t->elem_size || s->count != t->count ||
            memcmp(s->data, t->data, (size_t)s->count * s->elem_size)) {
            fprintf(stderr, "rad %s: %s and %s agree on scene and options but their '%s' sections differ (a build or "
                            "machine that computes other bits?)\n", cmd, pa->name, pb->name, keep_names[k]);
            return 1;
        }
    }
    if ((a->sh->shard_count == 0) != (b->sh->shard_count == 0) || a->sh->shard_count != b->sh->shard_count) {
        if (a->sh->shard_count && b->sh->shard_count) {
            fprintf(stderr, "rad %s: %s is shard %u/%u and %s shard %u/%u: the shards of one bake have one count\n", cmd,
                    pa->name, a->sh->shard, a->sh->shard_count, pb->name, b->sh->shard, b->sh->shard_count);
            return 1;
        }
    }
    return 0;
}

typedef struct range_ref {
    uint32_t begin, end, part;
} range_ref;

static int range_cmp(const void *a, const void *b)
{
    const range_ref *x = (const range_ref *)a, *y = (const range_ref *)b;
    return x->begin < y->begin ? -1 : x->begin > y->begin ? 1 : (x->part < y->part ? -1 : x->part > y->part);
}

/* every row in exactly one part; else prints what is given twice or missing */
static int check_cover(const char *cmd, const tool_part *parts, const part_view *v, uint32_t count)
{
    uint32_t N = v[0].sh->patches, n = v[0].sh->shard_count, p, k, total = 0, at = 0, missing = 0, first = 0;
    range_ref *rr;
    int all_shards = 1;
    for (p = 0; p < count; ++p) {
        total += v[p].sh->range_count;
        if (v[p].sh->shard_count != n || n == 0) all_shards = 0;
    }
    /* shards first: the duplicate or missing one by its number */
    if (all_shards) {
        uint32_t *seen = (uint32_t *)tool_calloc(n, sizeof(uint32_t));
        for (p = 0; p < count; ++p) {
            uint32_t I = v[p].sh->shard;
            if (I >= n) {
                fprintf(stderr, "rad %s: %s says it is shard %u of %u\n", cmd, parts[p].name, I, n);
                free(seen);
                return 1;
            }
            if (seen[I]) {
                fprintf(stderr, "rad %s: shard %u/%u is given twice (%s and %s)\n", cmd, I, n, parts[seen[I] - 1].name,
                        parts[p].name);
                free(seen);
                return 1;
            }
            seen[I] = p + 1;
        }
        for (k = 0; k < n; ++k)
            if (!seen[k]) {
                if (!missing) fprintf(stderr, "rad %s: shard", cmd), first = k;
                if (missing < 16) fprintf(stderr, "%s %u", missing ? "," : "", k);
                else if (missing == 16) fprintf(stderr, ", ...");
                ++missing;
            }
        free(seen);
        if (missing == 1)
            fprintf(stderr, " of %u is missing (%u of %u parts given): bake it with --shard %u/%u\n", n, count, n, first, n);
        else if (missing)
            fprintf(stderr, " of %u are missing (%u of %u parts given): bake each with --shard I/%u\n", n, count, n, n);
        if (missing) return 1;
    }
    rr = (range_ref *)tool_calloc(total, sizeof(range_ref));
    for (p = 0, k = 0; p < count; ++p) {
        uint32_t q;
        for (q = 0; q < v[p].sh->range_count; ++q, ++k)
            rr[k].begin = v[p].ranges[2 * q], rr[k].end = v[p].ranges[2 * q + 1], rr[k].part = p;
    }
    qsort(rr, total, sizeof *rr, range_cmp);
    for (k = 0; k < total; ++k) {
        if (rr[k].begin < at) {
            const range_ref *o = &rr[k - 1];
            uint32_t q;
            for (q = 0; q < k; ++q)
                if (rr[q].end > rr[k].begin) { o = &rr[q]; break; }
            fprintf(stderr, "rad %s: rows %u:%u of %s overlap rows %u:%u of %s: each row belongs to one part\n", cmd,
                    rr[k].begin, rr[k].end, parts[rr[k].part].name, o->begin, o->end, parts[o->part].name);
            free(rr);
            return 1;
        }
        if (rr[k].begin > at) {
            fprintf(stderr, "rad %s: rows %u:%u are in no part (bake them with --rows %u:%u)\n", cmd, at, rr[k].begin, at,
                    rr[k].begin);
            free(rr);
            return 1;
        }
        at = rr[k].end;
    }
    free(rr);
    if (at < N) {
        fprintf(stderr, "rad %s: rows %u:%u are in no part (bake them with --rows %u:%u)\n", cmd, at, N, at, N);
        return 1;
    }
    return 0;
}

int tool_merge(const char *cmd, const tool_part *parts, uint32_t count, const char *out_path)
{
    part_view *v;
    tool_classic c;
    tool_classic_options o;
    rad_matrix F;
    rad_section secs[11];
    rad_result r;
    float *full = NULL;
    void *dst = NULL;
    size_t dst_size = 0;
    uint32_t p, N, k;
    uint64_t evaluated = 0;
    double seconds = 0.0, t0 = tool_seconds();
    int rc = 1;
    memset(&c, 0, sizeof c);
    if (count == 0) {
        fprintf(stderr, "rad %s: no parts given\n", cmd);
        return 2;
    }
    v = (part_view *)tool_calloc(count, sizeof *v);
    for (p = 0; p < count; ++p)
        if (open_part(cmd, &parts[p], &v[p])) goto done;
    if (strncmp(v[0].sh->library, RAD_VERSION_STRING, sizeof v[0].sh->library)) {
        fprintf(stderr, "rad %s: %s was baked by radiosity.h %.16s, this rad is %s: merge with the version that baked it\n",
                cmd, parts[0].name, v[0].sh->library, RAD_VERSION_STRING);
        goto done;
    }
    for (p = 1; p < count; ++p)
        if (same_bake(cmd, &parts[0], &v[0], &parts[p], &v[p])) goto done;
    if (check_cover(cmd, parts, v, count)) goto done;

    /* F: the diagonal 0, each pair from the part that holds its row */
    N = v[0].sh->patches;
    full = (float *)tool_calloc((size_t)N * N, sizeof(float));
    for (p = 0; p < count; ++p) {
        uint64_t at = 0;
        for (k = 0; k < v[p].sh->range_count; ++k) {
            uint32_t i, j;
            for (i = v[p].ranges[2 * k]; i < v[p].ranges[2 * k + 1]; ++i)
                for (j = i + 1; j < N; ++j, ++at) {
                    float a = v[p].up[at], b = v[p].lo[at];
                    /* what rad_load_memory would refuse is not written (NaN fails too) */
                    if (!(a >= 0.0f && a <= RAD_BAKE_VALUE_MAX && b >= 0.0f && b <= RAD_BAKE_VALUE_MAX)) {
                        fprintf(stderr, "rad %s: %s: the form factors of patches %u and %u are %g and %g (finite, >= 0 "
                                        "expected)\n", cmd, parts[p].name, i, j, (double)a, (double)b);
                        goto done;
                    }
                    full[(size_t)i * N + j] = a;
                    full[(size_t)j * N + i] = b;
                }
        }
        evaluated += v[p].sh->pairs_evaluated;
        seconds += v[p].sh->seconds;
    }
    memset(&F, 0, sizeof F);
    F.rows = F.cols = N;
    F.storage = RAD_STORAGE_DENSE;
    F.dense = full;

    /* the solve of rad bake, with its options */
    tool_classic_options_default(&o);
    o.patches = v[0].info->patches;
    o.max_edge = v[0].info->max_edge;
    o.samples = v[0].info->samples;
    o.solver = (tool_solver)v[0].info->solver;
    o.bounces = v[0].info->bounces;
    o.light_samples = v[0].info->light_samples;
    c.patches = &v[0].bake->patches;
    c.E = (float *)tool_calloc(3 * (size_t)N, sizeof(float));
    memcpy(c.E, v[0].keep[3]->data, 12 * (size_t)N);
    fprintf(stderr, "rad %s: %u parts, %u patches, %llu pairs evaluated (%.2f s of form factors in the parts)\n", cmd,
            count, N, (unsigned long long)evaluated, seconds);
    if (tool_classic_indirect(cmd, &o, &F, &c)) goto done;

    /* save_bake's sections in its order (cmd_bake.c) */
    for (k = 0; k < 3; ++k) secs[k] = *v[0].keep[k];
    memset(&secs[3], 0, sizeof secs[3] * 8);
    secs[3].type = RAD_SECTION_FF_DENSE, secs[3].elem_size = 4, secs[3].count = (uint64_t)N * N, secs[3].data = full;
    strcpy(secs[3].name, "F");
    secs[4] = *v[0].keep[3];
    secs[5].type = RAD_SECTION_VECTOR, secs[5].elem_size = 12, secs[5].count = N, secs[5].data = c.B;
    strcpy(secs[5].name, "B");
    secs[6] = *rad_container_find(v[0].bake->container, RAD_SECTION_SIGNATURE, NULL);
    secs[7].type = RAD_SECTION_VECTOR, secs[7].elem_size = 12, secs[7].count = N, secs[7].data = c.L;
    strcpy(secs[7].name, "L");
    secs[8].type = RAD_SECTION_VECTOR, secs[8].elem_size = 12, secs[8].count = N, secs[8].data = c.H;
    strcpy(secs[8].name, "H");
    secs[9] = *v[0].keep[4];
    secs[10] = *rad_container_find(v[0].bake->container, TOOL_SECTION_OPTIONS, "rad.options");
    if ((r = rad_container_size(secs, 11, &dst_size)) != RAD_SUCCESS) {
        tool_fail(cmd, "rad_container_size", r);
        goto done;
    }
    dst = malloc(dst_size);
    if (!dst) {
        fprintf(stderr, "rad %s: out of memory for a bake of %lu bytes\n", cmd, (unsigned long)dst_size);
        goto done;
    }
    if ((r = rad_container_write(secs, 11, dst, dst_size)) != RAD_SUCCESS) {
        tool_fail(cmd, "rad_container_write", r);
        goto done;
    }
    /* the solution's vectors are checked as rad_save_memory checks them (F was, above; the
       rest was loaded from the parts): what is written loads, without a second pass over F */
    for (k = 0; k < 3 * N; ++k)
        if (!(fabsf(c.B[k]) <= RAD_BAKE_VALUE_MAX && fabsf(c.L[k]) <= RAD_BAKE_VALUE_MAX &&
              fabsf(c.H[k]) <= RAD_BAKE_VALUE_MAX)) {
            fprintf(stderr, "rad %s: the solution of patch %u is not finite (B %g, L %g, H %g)\n", cmd, k / 3,
                    (double)c.B[k], (double)c.L[k], (double)c.H[k]);
            goto done;
        }
    if (tool_write_file(out_path, dst, dst_size) != 0) {
        fprintf(stderr, "rad %s: %s\n", cmd, tool_output_error());
        goto done;
    }
    printf("wrote %s: %u patches, 11 sections, %lu bytes\n", out_path, N, (unsigned long)dst_size);
    fprintf(stderr, "rad %s: merged in %.2f s\n", cmd, tool_seconds() - t0);
    rc = 0;
done:
    free(dst);
    free(full);
    free(c.E);
    free(c.L);
    free(c.B);
    free(c.H);
    for (p = 0; p < count; ++p) rad_bake_destroy(v[p].bake);
    free(v);
    return rc;
}

/* ---- rad merge ------------------------------------------------------------------------- */

static void merge_usage(FILE *f)
{
    fprintf(f, "usage: rad merge PART.radb... -o FILE.radb [--threads N]\n"
               "Joins the parts of a sharded bake (rad bake SCENE --shard I/N or --rows A:B) into the\n"
               "bake a single rad bake writes, byte for byte: checks that the parts come from one\n"
               "scene, one set of options and one library version, and that they hold every row once\n"
               "(a missing shard is named), then solves and writes. The scene is not needed.\n"
               "  -o FILE            output file (required)\n"
               "  --threads N        worker threads for the solve (default: all cores; at most 1024)\n");
}

/* a whole file into malloc'd memory (malloc: aligned as the loader wants); 0 or 1 */
static int read_part(const char *cmd, const char *path, tool_part *p)
{
    FILE *f = fopen(path, "rb");
    long len;
    void *data;
    p->name = path;
    p->data = NULL;
    p->size = 0;
    if (!f || fseek(f, 0, SEEK_END) != 0 || (len = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
        if (f) fclose(f);
        fprintf(stderr, "rad %s: cannot read '%s'\n", cmd, path);
        return 1;
    }
    data = malloc(len > 0 ? (size_t)len : 1);
    if (!data || (len > 0 && fread(data, 1, (size_t)len, f) != (size_t)len)) {
        free(data);
        fclose(f);
        fprintf(stderr, "rad %s: cannot read '%s'\n", cmd, path);
        return 1;
    }
    fclose(f);
    p->data = data;
    p->size = (size_t)len;
    return 0;
}

int tool_cmd_merge(int argc, char **argv)
{
    const char *cmd = "merge", *out_path = NULL;
    const char **inputs;
    tool_part *parts;
    uint32_t n = 0, threads = 0, i;
    int a, rc = 1;
    inputs = (const char **)tool_calloc((size_t)argc + 1, sizeof *inputs);
    for (a = 0; a < argc; ++a) {
        const char *opt = argv[a];
        if (!strcmp(opt, "--help") || !strcmp(opt, "-h")) {
            merge_usage(stdout);
            free(inputs);
            return 0;
        }
        if ((!strcmp(opt, "-o") || !strcmp(opt, "--threads")) && a + 1 >= argc) {
            fprintf(stderr, "rad %s: %s needs a value\n", cmd, opt);
            free(inputs);
            return 2;
        }
        if (!strcmp(opt, "-o")) out_path = argv[++a];
        else if (!strcmp(opt, "--threads")) {
            if (tool_parse_threads(cmd, opt, argv[++a], &threads)) { free(inputs); return 2; }
        } else if (opt[0] == '-' && opt[1]) {
            fprintf(stderr, "rad %s: unknown option '%s' (see rad merge --help)\n", cmd, opt);
            free(inputs);
            return 2;
        } else inputs[n++] = opt;
    }
    if (!n || !out_path) {
        fprintf(stderr, "rad %s: %s\n", cmd, !n ? "no parts given" : "no output file given (-o FILE.radb)");
        merge_usage(stderr);
        free(inputs);
        return 2;
    }
    if (tool_check_output(cmd, out_path, inputs, (int)n)) { free(inputs); return 1; }
    tool_set_threads((int)threads);
    parts = (tool_part *)tool_calloc(n, sizeof *parts);
    for (i = 0; i < n; ++i)
        if (read_part(cmd, inputs[i], &parts[i])) goto done;
    rc = tool_merge(cmd, parts, n, out_path);
done:
    for (i = 0; i < n; ++i) free((void *)(size_t)parts[i].data);
    free(parts);
    free(inputs);
    return rc;
}
