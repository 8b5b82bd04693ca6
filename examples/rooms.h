/* rooms.h - a generated large scene for the local multi-bounce matrix (docs/methods/local.md): rows of
   rooms along corridors, and a form-factor row source that computes rows on demand.
   Used by examples/walk.c and tests/bench/local.c. Public domain or MIT.

   Layout (metres, y up): 'nz' rows of 'nx' rooms, each room R x R (R = 4) and H = 3 high;
   between two rows a corridor C = 2 wide runs the whole length in x. Every room has a door
   (1 x 2.2) into each neighbouring room and into the corridor beside it; walls are one-sided,
   facing into their room, inset 5 cm from the cell boundary. Each room has a 0.6 x 0.6
   ceiling light, each corridor one every 4 m; one wall of each room is coloured (red, green
   or blue in turn). Every room and every corridor is one mesh ("cell"): the mesh index of a
   patch's triangle is its cell.

   rooms_scene(nx, nz, &desc, &g) fills a rad_scene_desc (arrays owned by g, freed by
   rooms_free). An 8 x 8 grid cut with max_area 0.1 m^2 gives 72 160 patches, 10 x 10 with
   0.2 m^2 69 372.

   The row source (rooms_rows_init, rooms_rows_source) is an approximation that makes rows
   cheap enough for a 50k-patch walk on a CPU: F_ij is the unoccluded point-to-point form
   factor between centroids (the distance clamped from below as in rad_ff_point_point, by
   the larger of the two patches) when i and j lie in the same cell, 0
   otherwise (the light through doors is ignored), times one global scale that brings the
   largest row sum to 0.99. The scale keeps reciprocity A_i F_ij = A_j F_ji exact and every
   row sum <= 0.99 (energy conservation); baking the real form factors (rad_form_factors_sparse
   and rad_row_source_bake) is the production path, far too slow for N = 50k on this machine. */
#ifndef ROOMS_H_INCLUDED
#define ROOMS_H_INCLUDED
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "../radiosity.h"

#define ROOMS_R 4.0f
#define ROOMS_C 2.0f
#define ROOMS_H 3.0f
#define ROOMS_DOOR_W 1.0f
#define ROOMS_DOOR_H 2.2f
#define ROOMS_INSET 0.05f

typedef struct rooms_geometry {
    uint32_t nx, nz, cells;
    float *positions;          /* 9 floats per triangle, every cell's triangles in turn */
    uint32_t *materials;       /* per triangle */
    uint32_t *cell_first;      /* cells + 1: first triangle of each cell */
    rad_mesh_desc *meshes;
    rad_material mats[7];
    uint32_t tri_count, tri_cap;
} rooms_geometry;

static void rooms_free(rooms_geometry *g)
{
    free(g->positions);
    free(g->materials);
    free(g->cell_first);
    free(g->meshes);
    memset(g, 0, sizeof(*g));
}

static int rooms__tri(rooms_geometry *g, const float *a, const float *b, const float *c, uint32_t m)
{
    if (g->tri_count == g->tri_cap) {
        uint32_t cap = g->tri_cap ? 2 * g->tri_cap : 1024;
        float *p = (float *)realloc(g->positions, sizeof(float) * 9 * cap);
        uint32_t *q;
        if (!p) return 0;
        g->positions = p;
        q = (uint32_t *)realloc(g->materials, sizeof(uint32_t) * cap);
        if (!q) return 0;
        g->materials = q;
        g->tri_cap = cap;
    }
    memcpy(g->positions + 9 * (size_t)g->tri_count, a, 3 * sizeof(float));
    memcpy(g->positions + 9 * (size_t)g->tri_count + 3, b, 3 * sizeof(float));
    memcpy(g->positions + 9 * (size_t)g->tri_count + 6, c, 3 * sizeof(float));
    g->materials[g->tri_count++] = m;
    return 1;
}

/* the rectangle [u0,u1] x [v0,v1] on the plane 'axis' = w, facing +axis (face > 0) or -axis;
   u, v are the next two axes in turn */
static int rooms__rect(rooms_geometry *g, int axis, float w, float u0, float u1, float v0, float v1, int face, uint32_t m)
{
    float p[4][3];
    int ua = (axis + 1) % 3, va = (axis + 2) % 3, k;
    if (!(u1 > u0) || !(v1 > v0)) return 1;
    for (k = 0; k < 4; ++k) {
        p[k][axis] = w;
        p[k][ua] = (k == 1 || k == 2) ? u1 : u0;
        p[k][va] = (k >= 2) ? v1 : v0;
    }
    /* (u1-u0, 0) x (.., v1-v0) points along +axis for this order */
    if (face > 0) return rooms__tri(g, p[0], p[1], p[2], m) && rooms__tri(g, p[0], p[2], p[3], m);
    return rooms__tri(g, p[0], p[2], p[1], m) && rooms__tri(g, p[0], p[3], p[2], m);
}

/* a vertical wall on plane 'axis' (0: x, 2: z) = w spanning [a, b] along the other horizontal
   axis, with a door centred at 'door' (NAN: none) */
static int rooms__wall(rooms_geometry *g, int axis, float w, float a, float b, float door, int face, uint32_t m)
{
    /* rooms__rect's (u, v): for axis 0 u = y, v = z; for axis 2 u = x, v = y */
    if (door != door) {
        return axis == 0 ? rooms__rect(g, 0, w, 0.0f, ROOMS_H, a, b, face, m) : rooms__rect(g, 2, w, a, b, 0.0f, ROOMS_H, face, m);
    } else {
        float d0 = door - 0.5f * ROOMS_DOOR_W, d1 = door + 0.5f * ROOMS_DOOR_W;
        if (axis == 0)
            return rooms__rect(g, 0, w, 0.0f, ROOMS_H, a, d0, face, m) && rooms__rect(g, 0, w, 0.0f, ROOMS_H, d1, b, face, m) &&
                   rooms__rect(g, 0, w, ROOMS_DOOR_H, ROOMS_H, d0, d1, face, m);
        return rooms__rect(g, 2, w, a, d0, 0.0f, ROOMS_H, face, m) && rooms__rect(g, 2, w, d1, b, 0.0f, ROOMS_H, face, m) &&
               rooms__rect(g, 2, w, d0, d1, ROOMS_DOOR_H, ROOMS_H, face, m);
    }
}

/* a box cell [x0,x1] x [z0,z1] with floor, ceiling and the four walls (doors where asked) */
static int rooms__box(rooms_geometry *g, float x0, float x1, float z0, float z1, const float *door_x0, const float *door_x1,
                      const float *door_z0, const float *door_z1, uint32_t colour_wall)
{
    float nan = (float)NAN;
    int ok = 1;
    x0 += ROOMS_INSET; x1 -= ROOMS_INSET; z0 += ROOMS_INSET; z1 -= ROOMS_INSET;
    /* floor (faces +y; u = z, v = x for axis 1) and ceiling */
    ok = ok && rooms__rect(g, 1, 0.0f, z0, z1, x0, x1, 1, 1u);
    ok = ok && rooms__rect(g, 1, ROOMS_H, z0, z1, x0, x1, -1, 2u);
    ok = ok && rooms__wall(g, 0, x0, z0, z1, door_x0 ? *door_x0 : nan, 1, colour_wall == 0 ? 3u : 0u);
    ok = ok && rooms__wall(g, 0, x1, z0, z1, door_x1 ? *door_x1 : nan, -1, colour_wall == 1 ? 4u : 0u);
    ok = ok && rooms__wall(g, 2, z0, x0, x1, door_z0 ? *door_z0 : nan, 1, colour_wall == 2 ? 5u : 0u);
    ok = ok && rooms__wall(g, 2, z1, x0, x1, door_z1 ? *door_z1 : nan, -1, colour_wall == 3 ? 3u : 0u);
    return ok;
}

/* a 0.6 x 0.6 ceiling light centred at (x, z), facing down, 1 cm below the ceiling */
static int rooms__light(rooms_geometry *g, float x, float z)
{
    return rooms__rect(g, 1, ROOMS_H - 0.01f, z - 0.3f, z + 0.3f, x - 0.3f, x + 0.3f, -1, 6u);
}

/* z of the south edge of room row r, and of the corridor after row r */
static float rooms__row_z(uint32_t r) { return (float)r * (ROOMS_R + ROOMS_C); }

static int rooms_scene(uint32_t nx, uint32_t nz, rad_scene_desc *desc, rooms_geometry *g)
{
    uint32_t i, r, cell = 0;
    int ok = 1;
    static const float alb[7][3] = {{0.7f, 0.7f, 0.7f}, {0.5f, 0.45f, 0.4f}, {0.75f, 0.75f, 0.75f}, {0.7f, 0.2f, 0.15f},
                                    {0.2f, 0.6f, 0.2f}, {0.2f, 0.3f, 0.7f}, {0.8f, 0.8f, 0.8f}};
    memset(g, 0, sizeof(*g));
    if (nx == 0 || nz == 0) return 0;
    g->nx = nx;
    g->nz = nz;
    g->cells = nx * nz + (nz - 1);
    g->cell_first = (uint32_t *)calloc(g->cells + 1, sizeof(uint32_t));
    g->meshes = (rad_mesh_desc *)calloc(g->cells, sizeof(rad_mesh_desc));
    if (!g->cell_first || !g->meshes) { rooms_free(g); return 0; }
    for (i = 0; i < 7; ++i) {
        memcpy(g->mats[i].albedo, alb[i], sizeof(alb[i]));
        g->mats[i].emission[0] = g->mats[i].emission[1] = g->mats[i].emission[2] = i == 6 ? 8.0f : 0.0f;
        g->mats[i].texture = 0;
        g->mats[i].two_sided = 0;
        g->mats[i].emission_texture = 0;
        g->mats[i].opacity_texture = 0;
        g->mats[i].alpha_cutoff = 0.0f;
    }
    for (r = 0; r < nz && ok; ++r) {
        float z0 = rooms__row_z(r), z1 = z0 + ROOMS_R, dz = z0 + 0.5f * ROOMS_R;
        for (i = 0; i < nx && ok; ++i) {
            float x0 = (float)i * ROOMS_R, x1 = x0 + ROOMS_R, dx = x0 + 0.5f * ROOMS_R;
            g->cell_first[cell++] = g->tri_count;
            ok = rooms__box(g, x0, x1, z0, z1, i > 0 ? &dz : NULL, i + 1 < nx ? &dz : NULL, r > 0 ? &dx : NULL,
                            r + 1 < nz ? &dx : NULL, (i + r) % 4u) &&
                 rooms__light(g, dx, dz);
        }
        if (r + 1 < nz && ok) {
            /* the corridor north of row r: a door opposite every room on both sides */
            float c0 = z1, c1 = rooms__row_z(r + 1), x;
            g->cell_first[cell++] = g->tri_count;
            c0 += ROOMS_INSET; c1 -= ROOMS_INSET;
            ok = rooms__rect(g, 1, 0.0f, c0, c1, ROOMS_INSET, (float)nx * ROOMS_R - ROOMS_INSET, 1, 1u) &&
                 rooms__rect(g, 1, ROOMS_H, c0, c1, ROOMS_INSET, (float)nx * ROOMS_R - ROOMS_INSET, -1, 2u) &&
                 rooms__wall(g, 0, ROOMS_INSET, c0, c1, (float)NAN, 1, 0u) &&
                 rooms__wall(g, 0, (float)nx * ROOMS_R - ROOMS_INSET, c0, c1, (float)NAN, -1, 0u);
            for (i = 0; i < nx && ok; ++i) {
                float a = (float)i * ROOMS_R + (i == 0 ? ROOMS_INSET : 0.0f), b = (float)(i + 1) * ROOMS_R - (i + 1 == nx ? ROOMS_INSET : 0.0f);
                float d = ((float)i + 0.5f) * ROOMS_R;
                ok = rooms__wall(g, 2, c0, a, b, d, 1, 0u) && rooms__wall(g, 2, c1, a, b, d, -1, 0u);
            }
            for (x = 2.0f; x < (float)nx * ROOMS_R && ok; x += 4.0f) ok = rooms__light(g, x, 0.5f * (c0 + c1));
        }
    }
    if (!ok) { rooms_free(g); return 0; }
    g->cell_first[cell] = g->tri_count;
    for (i = 0; i < g->cells; ++i) {
        g->meshes[i].positions = g->positions + 9 * (size_t)g->cell_first[i];
        g->meshes[i].vertex_count = 3 * (g->cell_first[i + 1] - g->cell_first[i]);
        g->meshes[i].triangle_count = g->cell_first[i + 1] - g->cell_first[i];
        g->meshes[i].material_ids = g->materials + g->cell_first[i];
    }
    memset(desc, 0, sizeof(*desc));
    desc->meshes = g->meshes;
    desc->mesh_count = g->cells;
    desc->materials = g->mats;
    desc->material_count = 7;
    return 1;
}

/* A camera path along the first corridor (or through the rooms of row 0 when nz == 1):
   position and target at time t in [0, 1]. */
static void rooms_camera(const rooms_geometry *g, float t, rad_camera *cam)
{
    float zc = g->nz > 1 ? ROOMS_R + 0.5f * ROOMS_C : 0.5f * ROOMS_R, len = (float)g->nx * ROOMS_R;
    float x = 0.6f + t * (len - 1.2f);
    memset(cam, 0, sizeof(*cam));
    cam->position[0] = x; cam->position[1] = 1.6f; cam->position[2] = zc;
    cam->target[0] = x + 1.0f; cam->target[1] = 1.4f; cam->target[2] = zc + 0.35f * (float)sin(6.0 * (double)t);
    cam->up[1] = 1.0f;
    cam->fov_y_degrees = 70.0f;
}

/* ---- the row source ---- */

typedef struct rooms_rows {
    const rad_patches *patches;
    uint32_t *cell_of;         /* per patch */
    uint32_t *cell_start;      /* cells + 1 */
    uint32_t *cell_patches;    /* patches grouped by cell */
    float scale;
    uint64_t rows_fetched;
} rooms_rows;

/* unoccluded point-to-point form factor between centroids, with the distance clamped from
   below by the larger patch (so A_i F_ij = A_j F_ji holds exactly) */
static float rooms__ff(const rad_patches *p, uint32_t i, uint32_t j)
{
    const rad_patch *a = &p->patches[i], *b = &p->patches[j];
    float d[3], r2, ci, cj, big = a->area > b->area ? a->area : b->area;
    d[0] = b->centroid[0] - a->centroid[0]; d[1] = b->centroid[1] - a->centroid[1]; d[2] = b->centroid[2] - a->centroid[2];
    r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    ci = d[0] * a->normal[0] + d[1] * a->normal[1] + d[2] * a->normal[2];
    cj = -(d[0] * b->normal[0] + d[1] * b->normal[1] + d[2] * b->normal[2]);
    if (!(ci > 0.0f) || !(cj > 0.0f) || !(r2 > 0.0f)) return 0.0f;
    /* cos_i cos_j / (pi r^2) * A_j with cos = c / r */
    return b->area * ci * cj / (3.14159265f * r2 * (r2 > big / 3.14159265f ? r2 : big / 3.14159265f));
}

static rad_result rooms_rows_fetch(void *user, uint32_t row, uint32_t capacity, uint32_t *cols, float *vals, uint32_t *count)
{
    rooms_rows *s = (rooms_rows *)user;
    uint32_t c = s->cell_of[row], q, k = 0;
    for (q = s->cell_start[c]; q < s->cell_start[c + 1]; ++q) {
        uint32_t j = s->cell_patches[q];
        float f;
        if (j == row) continue;
        f = rooms__ff(s->patches, row, j) * s->scale;
        if (f > 0.0f) {
            if (k >= capacity) return RAD_ERROR_SIZE_MISMATCH;
            cols[k] = j;
            vals[k++] = f;
        }
    }
    *count = k;
    s->rows_fetched++;
    return RAD_SUCCESS;
}

static void rooms_rows_free(rooms_rows *s)
{
    free(s->cell_of);
    free(s->cell_start);
    free(s->cell_patches);
    memset(s, 0, sizeof(*s));
}

/* groups the patches by cell and finds the global scale (one pass over every row: O(sum of
   cell sizes squared)) */
static int rooms_rows_init(rooms_rows *s, const rad_patches *p)
{
    uint32_t i, cells = 0;
    int ii;
    double worst = 0.0;
    memset(s, 0, sizeof(*s));
    s->patches = p;
    s->cell_of = (uint32_t *)malloc(sizeof(uint32_t) * p->count);
    if (!s->cell_of) return 0;
    for (i = 0; i < p->count; ++i) {
        s->cell_of[i] = p->scene->meshes[p->patches[i].triangle];
        if (s->cell_of[i] + 1 > cells) cells = s->cell_of[i] + 1;
    }
    s->cell_start = (uint32_t *)calloc(cells + 1, sizeof(uint32_t));
    s->cell_patches = (uint32_t *)malloc(sizeof(uint32_t) * p->count);
    if (!s->cell_start || !s->cell_patches) { rooms_rows_free(s); return 0; }
    for (i = 0; i < p->count; ++i) s->cell_start[s->cell_of[i] + 1]++;
    for (i = 0; i < cells; ++i) s->cell_start[i + 1] += s->cell_start[i];
    {
        uint32_t *fill = (uint32_t *)malloc(sizeof(uint32_t) * (cells + 1));
        if (!fill) { rooms_rows_free(s); return 0; }
        memcpy(fill, s->cell_start, sizeof(uint32_t) * (cells + 1));
        for (i = 0; i < p->count; ++i) s->cell_patches[fill[s->cell_of[i]]++] = i;
        free(fill);
    }
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 64) reduction(max : worst)
#endif
    for (ii = 0; ii < (int)p->count; ++ii) {
        uint32_t c = s->cell_of[ii], q;
        double sum = 0.0;
        for (q = s->cell_start[c]; q < s->cell_start[c + 1]; ++q)
            if (s->cell_patches[q] != (uint32_t)ii) sum += rooms__ff(p, (uint32_t)ii, s->cell_patches[q]);
        if (sum > worst) worst = sum;
    }
    s->scale = worst > 0.0 ? (float)(0.99 / worst) : 1.0f;
    return 1;
}

static void rooms_rows_source(rooms_rows *s, rad_row_source *src)
{
    memset(src, 0, sizeof(*src));
    src->n = s->patches->count;
    src->areas = s->patches->areas;
    src->albedo = s->patches->albedo;
    src->fetch = rooms_rows_fetch;
    src->user = s;
}
#endif
