/* test_twosided.c - two-sided materials: the scene's back-to-back copies, the raycasters'
   front-only rule for them (BVH and Embree), a two-sided sheet against the closed form of
   parallel squares, a box of mixed windings against the consistently wound one (classic,
   hierarchical, AAVP), the per-mesh outputs, and one-sided scenes unchanged. */
#include "fixtures.h"

/* A quad (ff_quad) in one mesh, one material. */
static void ts_quad_mesh(rad_mesh_desc *m, const ff_quad *q, uint32_t material)
{
    ff_mesh_quad(m, q);
    m->material = material;
}

/* The scene of one two-sided quad in the plane z = 0 (front +z as wound): two mesh triangles
   become four scene triangles in pairs, back to back. */
static void ts_test_scene_pairs(void)
{
    ff_quad q;
    rad_mesh_desc m;
    rad_scene_desc d;
    rad_material mat = { { 0.5f, 0.5f, 0.5f }, { 0, 0, 0 }, 0, 0, 1, 0, 0.0f };
    rad_scene *s = NULL;
    float nrm[12];
    uint32_t t;
    int k;
    ff_quad_set(&q, 0, 0, 0, 1, 0, 0, 0, 1, 0);
    ts_quad_mesh(&m, &q, 0);
    memset(&d, 0, sizeof(d));
    d.meshes = &m;
    d.mesh_count = 1;
    d.materials = &mat;
    d.material_count = 1;
    CHECK_OK(rad_scene_create(&d, NULL, &s));
    if (!s) return;
    CHECK(s->triangle_count == 4);
    CHECK(s->twins != NULL);
    for (t = 0; s->twins && t < 4; ++t) {
        uint32_t o = t ^ 1u;
        CHECK(s->twins[t] == o);
        CHECK(s->source_triangles[t] == t / 2);
        CHECK(s->materials[t] == 0 && s->meshes[t] == 0);
        CHECK(s->areas[t] == s->areas[o]);
        for (k = 0; k < 3; ++k) CHECK(s->normals[3 * t + k] == -s->normals[3 * o + k]);
        /* corners 0 2 1 of the other side */
        for (k = 0; k < 3; ++k) {
            CHECK(s->positions[9 * t + k] == s->positions[9 * o + k]);
            CHECK(s->positions[9 * t + 3 + k] == s->positions[9 * o + 6 + k]);
        }
    }
    /* without shading normals the first of a pair is the side as wound (+z) */
    CHECK(s->normals[2] > 0.99f && s->normals[3 * 2 + 2] > 0.99f);
    rad_scene_destroy(s);
    /* shading normals pointing to -z make the reversed side the first, the one reported */
    for (k = 0; k < 4; ++k) { nrm[3 * k] = 0.0f; nrm[3 * k + 1] = 0.0f; nrm[3 * k + 2] = -1.0f; }
    m.normals = nrm;
    s = NULL;
    CHECK_OK(rad_scene_create(&d, NULL, &s));
    if (!s) return;
    CHECK(s->normals[2] < -0.99f && s->normals[5] > 0.99f);
    CHECK(s->twins && s->twins[0] == 1 && s->twins[1] == 0);
    rad_scene_destroy(s);
    /* one-sided: no twins array, the mesh order */
    mat.two_sided = 0;
    s = NULL;
    CHECK_OK(rad_scene_create(&d, NULL, &s));
    if (!s) return;
    CHECK(s->triangle_count == 2 && s->twins == NULL);
    rad_scene_destroy(s);
}

/* Rays through a two-sided quad at z = 0 from both sides: the reported triangle is the copy
   whose front faces the ray origin, occlusion is blocked from both sides; a one-sided quad
   is hit from both sides (as before). */
static void ts_check_sides(const rad_scene *s, const rad_raycaster *rc, int two_sided)
{
    uint32_t i, seed = 12345u;
    for (i = 0; i < 200; ++i) {
        rad_ray r;
        rad_hit h;
        uint8_t occ = 0;
        float x, y, z;
        seed = seed * 1664525u + 1013904223u;
        x = 0.05f + 0.9f * (float)(seed >> 8) / 16777216.0f;
        seed = seed * 1664525u + 1013904223u;
        y = 0.05f + 0.9f * (float)(seed >> 8) / 16777216.0f;
        z = (i & 1u) ? 1.0f : -1.0f;
        r.origin[0] = 0.5f; r.origin[1] = 0.5f; r.origin[2] = z;
        r.dir[0] = x - 0.5f; r.dir[1] = y - 0.5f; r.dir[2] = -z;
        r.tmin = 0.0f;
        r.tmax = 2.0f;
        CHECK_OK(rc->intersect(rc->user, &r, 1, &h));
        CHECK_OK(rc->occluded(rc->user, &r, 1, &occ));
        CHECK(occ == 1);
        CHECK(h.triangle != RAD_NONE && h.triangle < s->triangle_count);
        if (h.triangle == RAD_NONE || h.triangle >= s->triangle_count) continue;
        CHECK_NEAR(h.t, 1.0, 1e-5);
        if (two_sided) {
            /* the front of the reported copy faces the origin */
            CHECK(s->normals[3 * h.triangle + 2] * z > 0.0f);
        }
    }
}

static void ts_test_raycasters_report_the_side_seen(void)
{
    ff_quad q;
    rad_mesh_desc m;
    rad_scene_desc d;
    rad_material mat = { { 0.5f, 0.5f, 0.5f }, { 0, 0, 0 }, 0, 0, 1, 0, 0.0f };
    int two;
    ff_quad_set(&q, 0, 0, 0, 1, 0, 0, 0, 1, 0);
    ts_quad_mesh(&m, &q, 0);
    memset(&d, 0, sizeof(d));
    d.meshes = &m;
    d.mesh_count = 1;
    d.materials = &mat;
    d.material_count = 1;
    for (two = 0; two <= 1; ++two) {
        rad_scene *s = NULL;
        rad_bvh *b = NULL;
        rad_raycaster rc;
        mat.two_sided = (uint32_t)two;
        CHECK_OK(rad_scene_create(&d, NULL, &s));
        CHECK_OK(rad_bvh_create(s, NULL, &b));
        if (s && b) {
            /* the built-in BVH itself, also when test_main.c redirects rad_bvh_raycaster */
            rc.user = (void *)b;
            rc.occluded = rad__bvh_occluded;
            rc.intersect = rad__bvh_intersect;
            ts_check_sides(s, &rc, two);
        }
#ifdef RAD_EMBREE
        {
            rad_embree *e = NULL;
            CHECK_OK(rad_embree_create(s, NULL, &e));
            if (e) {
                rad_embree_raycaster(e, &rc);
                ts_check_sides(s, &rc, two);
            }
            rad_embree_destroy(e);
        }
#endif
        rad_bvh_destroy(b);
        rad_scene_destroy(s);
    }
}

#ifdef RAD_EMBREE
/* Random rays in a box of two-sided walls with a two-sided sheet across it: Embree and the
   BVH report the same triangle (so the same side) and the same occlusion. */
static void ts_test_embree_matches_bvh(void)
{
    ff_quad q[7];
    rad_mesh_desc m[7];
    rad_scene_desc d;
    rad_material mat = { { 0.5f, 0.5f, 0.5f }, { 0, 0, 0 }, 0, 0, 1, 0, 0.0f };
    rad_scene *s = NULL;
    rad_bvh *b = NULL;
    rad_embree *e = NULL;
    rad_raycaster rb, re;
    uint32_t i, seed = 99u, diff_hit = 0, diff_occ = 0;
    int f;
    ff_cube_quads(q);
    ff_quad_set(&q[6], 0.2f, 0.2f, 0.5f, 0.6f, 0, 0, 0, 0.6f, 0);
    for (f = 0; f < 7; ++f) ts_quad_mesh(&m[f], &q[f], 0);
    memset(&d, 0, sizeof(d));
    d.meshes = m;
    d.mesh_count = 7;
    d.materials = &mat;
    d.material_count = 1;
    CHECK_OK(rad_scene_create(&d, NULL, &s));
    CHECK_OK(rad_bvh_create(s, NULL, &b));
    CHECK_OK(rad_embree_create(s, NULL, &e));
    if (!s || !b || !e) { rad_embree_destroy(e); rad_bvh_destroy(b); rad_scene_destroy(s); return; }
    rb.user = (void *)b;
    rb.occluded = rad__bvh_occluded;
    rb.intersect = rad__bvh_intersect;
    rad_embree_raycaster(e, &re);
    for (i = 0; i < 5000; ++i) {
        rad_ray r;
        rad_hit hb, he;
        uint8_t ob = 0, oe = 0;
        int k;
        for (k = 0; k < 3; ++k) {
            seed = seed * 1664525u + 1013904223u;
            r.origin[k] = 0.05f + 0.9f * (float)(seed >> 8) / 16777216.0f;
            seed = seed * 1664525u + 1013904223u;
            r.dir[k] = 2.0f * (float)(seed >> 8) / 16777216.0f - 1.0f;
        }
        r.tmin = 0.0f;
        r.tmax = (i & 1u) ? 1e30f : 0.3f;
        CHECK_OK(rb.intersect(rb.user, &r, 1, &hb));
        CHECK_OK(re.intersect(re.user, &r, 1, &he));
        CHECK_OK(rb.occluded(rb.user, &r, 1, &ob));
        CHECK_OK(re.occluded(re.user, &r, 1, &oe));
        /* a ray through a shared edge may name either neighbour, never the other side */
        if (hb.triangle != he.triangle &&
            (hb.triangle == RAD_NONE || he.triangle == RAD_NONE ||
             s->normals[3 * hb.triangle] * s->normals[3 * he.triangle] + s->normals[3 * hb.triangle + 1] * s->normals[3 * he.triangle + 1] +
                     s->normals[3 * hb.triangle + 2] * s->normals[3 * he.triangle + 2] < 0.99f))
            ++diff_hit;
        if (ob != oe) ++diff_occ;
    }
    CHECK(diff_hit == 0);
    CHECK(diff_occ == 0);
    rad_embree_destroy(e);
    rad_bvh_destroy(b);
    rad_scene_destroy(s);
}
#endif

/* Three parallel unit squares at z = -c, 0 and +c, the outer two facing the middle one, which
   is two-sided. Returns the mean radiosity (red) of the middle sheet's side facing down and up
   (middle = 1) or of the lower and upper outer square (middle = 0), after the classic solve. */
static int ts_sheet_solve(const rad_material mats[3], double c, int middle, double *down, double *up)
{
    ff_quad q[3];
    rad_mesh_desc m[3];
    rad_scene_desc d;
    ff_world w;
    rad_form_factors *ff = NULL;
    rad_form_factor_options fo;
    rad_system sys;
    rad_solve_options so;
    float *E = NULL, *B = NULL;
    double s[2] = { 0.0, 0.0 }, a[2] = { 0.0, 0.0 };
    uint32_t i;
    int ok = 0;
    ff_quad_set(&q[0], 0, 0, 0, 1, 0, 0, 0, 1, 0);                  /* the sheet, front +z */
    ff_quad_set(&q[1], 0, 0, (float)-c, 1, 0, 0, 0, 1, 0);          /* below, facing up */
    ff_quad_set(&q[2], 0, 0, (float)c, 0, 1, 0, 1, 0, 0);           /* above, facing down */
    for (i = 0; i < 3; ++i) ts_quad_mesh(&m[i], &q[i], i);
    memset(&d, 0, sizeof(d));
    d.meshes = m;
    d.mesh_count = 3;
    d.materials = mats;
    d.material_count = 3;
    if (!ff_world_make(&d, rad_test_quick() ? 0.25f : 0.125f, 0, &w)) return 0;
    rad_form_factor_options_default(&fo);
    CHECK_OK(rad_form_factors_dense(w.patches, &w.rc, &fo, NULL, &ff));
    E = (float *)calloc(3 * (size_t)w.patches->count, sizeof(float));
    B = (float *)calloc(3 * (size_t)w.patches->count, sizeof(float));
    if (ff && E && B) {
        CHECK_OK(rad_sources(w.patches, RAD_SOURCE_EMISSION, NULL, E));
        rad_system_init(&sys, &ff->matrix, w.patches, E);
        rad_solve_options_default(&so);
        so.output = RAD_OUTPUT_TOTAL;
        so.bounces = 4;
        CHECK_OK(rad_solve_jacobi(&sys, &so, B, NULL, NULL));
        for (i = 0; i < w.patches->count; ++i) {
            const rad_patch *p = &w.patches->patches[i];
            uint32_t mesh = w.scene->meshes[p->triangle];
            int k = middle ? (p->normal[2] > 0.0f) : (mesh == 2);
            if (middle ? mesh != 0 : mesh == 0) continue;
            s[k] += p->area * B[3 * i];
            a[k] += p->area;
        }
        CHECK_NEAR(a[0], 1.0, 1e-5);
        CHECK_NEAR(a[1], 1.0, 1e-5);
        *down = s[0] / a[0];
        *up = s[1] / a[1];
        ok = 1;
    }
    free(E);
    free(B);
    rad_form_factors_destroy(ff);
    ff_world_free(&w);
    return ok;
}

/* A two-sided sheet (albedo rho) between two black emitters of radiance 2 (below, facing up)
   and 0.5 (above, facing down): each side sees only its emitter, so its mean radiosity is
   exactly rho * pi * L * F, F Howell's C-11 for parallel opposed squares. One-sided, the back
   would stay black. */
static void ts_test_sheet_closed_form(void)
{
    const rad_material mats[3] = { { { 0.6f, 0.6f, 0.6f }, { 0, 0, 0 }, 0, 0, 1, 0, 0.0f },
                                   { { 0.0f, 0.0f, 0.0f }, { 2.0f, 2.0f, 2.0f }, 0, 0, 0, 0, 0.0f },
                                   { { 0.0f, 0.0f, 0.0f }, { 0.5f, 0.5f, 0.5f }, 0, 0, 0, 0, 0.0f } };
    const double c = 0.5, rho = 0.6, F = ff_c11(1.0, 1.0, c);
    double down = 0.0, up = 0.0;
    if (!ts_sheet_solve(mats, c, 1, &down, &up)) return;
    CHECK_REL(down, rho * FF_PI * 2.0 * F, 0.01);
    CHECK_REL(up, rho * FF_PI * 0.5 * F, 0.01);
}

/* A two-sided black emitter sheet (radiance 1) between two grey squares facing it: it emits
   from both sides, each receiver gets rho * pi * L * F (one-sided, the upper one would get
   nothing). */
static void ts_test_sheet_emits_both_ways(void)
{
    const rad_material mats[3] = { { { 0.0f, 0.0f, 0.0f }, { 1.0f, 1.0f, 1.0f }, 0, 0, 1, 0, 0.0f },
                                   { { 0.5f, 0.5f, 0.5f }, { 0, 0, 0 }, 0, 0, 0, 0, 0.0f },
                                   { { 0.5f, 0.5f, 0.5f }, { 0, 0, 0 }, 0, 0, 0, 0, 0.0f } };
    const double c = 0.5, F = ff_c11(1.0, 1.0, c);
    double below = 0.0, above = 0.0;
    if (!ts_sheet_solve(mats, c, 0, &below, &above)) return;
    CHECK_REL(below, 0.5 * FF_PI * F, 0.01);
    CHECK_REL(above, 0.5 * FF_PI * F, 0.01);
}

/* ---- a closed box of mixed windings ---- */

/* The unit cube's six faces (fx_cube_faces, fronts inward) as meshes with inward shading
   normals; face 1 (x = 1) emits. flip: each triangle wound outward when its bit in 'flip'
   (bit 2f + k for triangle k of face f) is set; two_sided on the walls' material. */
typedef struct ts_box {
    float pos[72], nrm[72];
    uint32_t idx[6][6];
    rad_mesh_desc m[6];
    rad_material mats[2];
    rad_scene_desc d;
} ts_box;

static void ts_box_make(ts_box *b, uint32_t flip, int two_sided)
{
    int f, k, v;
    memset(b, 0, sizeof(*b));
    fx_cube_faces(b->pos);
    for (f = 0; f < 6; ++f) {
        int a = f / 2;
        for (v = 0; v < 4; ++v)
            for (k = 0; k < 3; ++k) b->nrm[12 * f + 3 * v + k] = k == a ? ((f % 2) ? -1.0f : 1.0f) : 0.0f;
        for (k = 0; k < 2; ++k) {
            uint32_t *t = &b->idx[f][3 * k];
            t[0] = 0;
            t[1] = k ? 2u : 1u;
            t[2] = k ? 3u : 2u;
            if (flip >> (2 * f + k) & 1u) { uint32_t x = t[1]; t[1] = t[2]; t[2] = x; }
        }
        b->m[f].positions = b->pos + 12 * f;
        b->m[f].normals = b->nrm + 12 * f;
        b->m[f].vertex_count = 4;
        b->m[f].indices = b->idx[f];
        b->m[f].triangle_count = 2;
        b->m[f].material = f == 1 ? 1u : 0u;
    }
    for (k = 0; k < 3; ++k) {
        b->mats[0].albedo[k] = 0.6f;
        b->mats[1].albedo[k] = 0.6f;
        b->mats[1].emission[k] = 1.0f;
    }
    /* the emitter stays one-sided: a two-sided one would also light the outside, and the
       hierarchical refinement (relative to the total power) would then differ */
    b->mats[0].two_sided = (uint32_t)two_sided;
    b->d.meshes = b->m;
    b->d.mesh_count = 6;
    b->d.materials = b->mats;
    b->d.material_count = 2;
}

#define TS_PROBES 24
/* Inside-facing points: rays from inside the box to four points on each face. */
static void ts_probe_hits(const rad_raycaster *rc, rad_hit *hits)
{
    /* off the patches' edges (multiples of 1/6 and 1/2 in u, v and u - v), where a tie could
       name either neighbour */
    static const float uv[4][2] = { { 0.3f, 0.38f }, { 0.7f, 0.35f }, { 0.6f, 0.75f }, { 0.2f, 0.8f } };
    int f, j, k;
    for (f = 0; f < 6; ++f)
        for (j = 0; j < 4; ++j) {
            rad_ray r;
            float target[3];
            int a = f / 2;
            target[a] = (f % 2) ? 1.0f : 0.0f;
            target[(a + 1) % 3] = uv[j][0];
            target[(a + 2) % 3] = uv[j][1];
            for (k = 0; k < 3; ++k) {
                r.origin[k] = 0.45f + 0.02f * (float)j;
                r.dir[k] = target[k] - r.origin[k];
            }
            r.tmin = 0.0f;
            r.tmax = 2.0f;
            CHECK_OK(rc->intersect(rc->user, &r, 1, &hits[4 * f + j]));
            CHECK(hits[4 * f + j].triangle != RAD_NONE);
        }
}

/* method 0 classic, 1 hierarchical, 2 AAVP: the radiosity (red) at the probes */
static int ts_box_solve(const ts_box *b, int method, float *out)
{
    rad_scene *s = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_hit hits[TS_PROBES];
    int i, ok = 0;
    CHECK_OK(rad_scene_create(&b->d, NULL, &s));
    if (s) CHECK_OK(rad_bvh_create(s, NULL, &bvh));
    if (!s || !bvh) goto done;
    /* the built-in BVH itself, also in the Embree build of the tests (whose fixture keeps the
       BVH for two-sided scenes): the boxes are compared to 1e-4 with the same ray queries */
    (rad_bvh_raycaster)(bvh, &rc);
    ts_probe_hits(&rc, hits);
    for (i = 0; i < TS_PROBES; ++i)
        if (hits[i].triangle == RAD_NONE) goto done;
    if (method == 0) {
        rad_patches *P = NULL;
        rad_form_factors *ff = NULL;
        float *E = NULL, *B = NULL;
        if (fx_classic_jacobi8(s, &rc, &P, &ff, &E, &B)) {
            for (i = 0; i < TS_PROBES; ++i) {
                float w[3];
                uint32_t p = rad_patches_locate(P, hits[i].triangle, hits[i].b1, hits[i].b2, w);
                out[i] = p == RAD_NONE ? -1.0f : B[3 * p];
            }
            ok = 1;
        }
        free(E);
        free(B);
        rad_form_factors_destroy(ff);
        rad_patches_destroy(P);
    } else if (method == 1) {
        rad_hierarchical_options ho;
        rad_hierarchical *h = NULL;
        uint32_t tri[TS_PROBES];
        float bary[2 * TS_PROBES], val[3 * TS_PROBES];
        rad_hierarchical_options_default(&ho);
        /* the box is convex: without visibility rays the solution has no sampling noise, so
           the one-sided and two-sided boxes (whose elements draw different random rays)
           compare closely */
        ho.skip_visibility = 1;
        CHECK_OK(rad_hierarchical_create(s, &rc, &ho, NULL, &h));
        if (h) CHECK_OK(rad_hierarchical_solve(h, NULL));
        for (i = 0; i < TS_PROBES; ++i) {
            tri[i] = hits[i].triangle;
            bary[2 * i] = hits[i].b1;
            bary[2 * i + 1] = hits[i].b2;
        }
        if (h && rad_hierarchical_lookup(h, RAD_HIERARCHICAL_RADIOSITY, 0, tri, bary, TS_PROBES, val) == RAD_SUCCESS) {
            for (i = 0; i < TS_PROBES; ++i) out[i] = val[3 * i];
            ok = 1;
        }
        rad_hierarchical_destroy(h);
    } else {
        rad_vp_options vo;
        rad_virtual_patches *vp = NULL;
        rad_system sys;
        rad_solve_options so;
        float *E = NULL, *B = NULL;
        rad_vp_options_default(&vo);
        vo.resolution = 6;
        CHECK_OK(rad_vp_create(s, &rc, &vo, NULL, &vp));
        if (vp) {
            E = (float *)calloc(3 * (size_t)vp->count, sizeof(float));
            B = (float *)calloc(3 * (size_t)vp->count, sizeof(float));
        }
        if (E && B) {
            CHECK_OK(rad_vp_sources(vp, &rc, NULL, 0, NULL, RAD_SOURCE_EMISSION, E, NULL));
            rad_vp_system(&sys, vp, E);
            rad_solve_options_default(&so);
            so.output = RAD_OUTPUT_TOTAL;
            so.bounces = 8;
            CHECK_OK(rad_solve_jacobi(&sys, &so, B, NULL, NULL));
            for (i = 0; i < TS_PROBES; ++i) {
                const float *v = s->positions + 9 * (size_t)hits[i].triangle;
                float p[3], o[3];
                int k;
                for (k = 0; k < 3; ++k) p[k] = v[k] + hits[i].b1 * (v[3 + k] - v[k]) + hits[i].b2 * (v[6 + k] - v[k]);
                if (!rad_vp_gather_point(vp, B, p, s->normals + 3 * (size_t)hits[i].triangle, o)) o[0] = -1.0f;
                out[i] = o[0];
            }
            ok = 1;
        }
        free(E);
        free(B);
        rad_vp_destroy(vp);
    }
done:
    rad_bvh_destroy(bvh);
    rad_scene_destroy(s);
    return ok;
}

/* The same box three ways: one-sided and wound consistently inward (the reference), two-sided
   and wound inward, two-sided with half its triangles wound outward. Inside, all three are
   the same surfaces, so every method gives the same radiosity at the same points; one-sided,
   the mixed box would be black on its outward-wound triangles. */
static void ts_test_mixed_winding_box(void)
{
    static const char *names[3] = { "classic", "hierarchical", "aavp" };
    static const double tol[3] = { 1e-4, 1e-4, 5e-3 };
    static ts_box b;
    int method, i;
    for (method = 0; method < 3; ++method) {
        float ref[TS_PROBES], two[TS_PROBES], mixed[TS_PROBES], mean = 0.0f;
        double worst = 0.0;
        ts_box_make(&b, 0u, 0);
        if (!ts_box_solve(&b, method, ref)) { CHECK(0); continue; }
        ts_box_make(&b, 0u, 1);
        if (!ts_box_solve(&b, method, two)) { CHECK(0); continue; }
        ts_box_make(&b, 0x9A1u, 1); /* triangles 0 5 7 8 11 outward (not the emitter's) */
        if (!ts_box_solve(&b, method, mixed)) { CHECK(0); continue; }
        for (i = 0; i < TS_PROBES; ++i) mean += ref[i] / (float)TS_PROBES;
        CHECK(mean > 0.1f);
        for (i = 0; i < TS_PROBES; ++i) {
            double d1 = fabs((double)two[i] - ref[i]) / mean, d2 = fabs((double)mixed[i] - ref[i]) / mean;
            if (d1 > worst) worst = d1;
            if (d2 > worst) worst = d2;
            CHECK(ref[i] > 0.0f);
            CHECK_NEAR(two[i], ref[i], tol[method] * mean);
            CHECK_NEAR(mixed[i], ref[i], tol[method] * mean);
        }
        printf("    %s: largest difference from the one-sided box %.2g of the mean\n", names[method], worst);
    }
}

/* rad_patches_gather_mesh and the lightmap of a two-sided mesh report one side, the one its
   shading normals point out of: the mixed box's per-vertex values equal the consistently
   wound box's. */
static void ts_test_gather_mesh_reports_one_side(void)
{
    static ts_box b;
    float out[2][6][12];
    int v, f, k;
    for (v = 0; v < 2; ++v) {
        rad_scene *s = NULL;
        rad_bvh *bvh = NULL;
        rad_raycaster rc;
        rad_patches *P = NULL;
        rad_form_factors *ff = NULL;
        float *E = NULL, *B = NULL, *vv = NULL;
        ts_box_make(&b, v ? 0x9A1u : 0u, 1);
        CHECK_OK(rad_scene_create(&b.d, NULL, &s));
        if (s) CHECK_OK(rad_bvh_create(s, NULL, &bvh));
        if (!bvh) { rad_scene_destroy(s); return; }
        rad_bvh_raycaster(bvh, &rc);
        if (fx_classic_jacobi8(s, &rc, &P, &ff, &E, &B)) {
            vv = (float *)malloc(sizeof(float) * 3 * P->vertex_count);
            if (vv) {
                CHECK_OK(rad_patches_vertex_values(P, B, 3, vv));
                for (f = 0; f < 6; ++f) CHECK_OK(rad_patches_gather_mesh(P, vv, (uint32_t)f, &b.m[f], out[v][f], NULL));
            }
        }
        free(vv);
        free(E);
        free(B);
        rad_form_factors_destroy(ff);
        rad_patches_destroy(P);
        rad_bvh_destroy(bvh);
        rad_scene_destroy(s);
    }
    for (f = 0; f < 6; ++f)
        for (k = 0; k < 12; ++k) {
            CHECK(out[0][f][k] > 0.05f);
            CHECK_NEAR(out[1][f][k], out[0][f][k], 2e-3 * out[0][f][k]);
        }
}

/* The lightmap of a two-sided sheet (a 1 x 1 square at z = 0, lightmap uvs = x y) over a black
   emitter 0.5 below facing up: its texels hold the side the shading normals point out of and
   nothing of the other. Normals down: every texel's normal is -z and its mean irradiance is
   pi L F, F the closed form for parallel squares (C-11); normals up: +z, and nothing lights
   that side. */
static void ts_test_lightmap_reports_one_side(void)
{
    static const float uvq[8] = { 0, 0, 1, 0, 1, 1, 0, 1 };
    ff_quad q[2];
    rad_mesh_desc m[2];
    rad_scene_desc d;
    rad_material mats[2] = { { { 0.5f, 0.5f, 0.5f }, { 0, 0, 0 }, 0, 0, 1, 0, 0.0f }, { { 0.0f, 0.0f, 0.0f }, { 1.0f, 1.0f, 1.0f }, 0, 0, 0, 0, 0.0f } };
    float nrm[12];
    int side, k;
    ff_quad_set(&q[0], 0, 0, 0, 1, 0, 0, 0, 1, 0);
    ff_quad_set(&q[1], 0, 0, -0.5f, 1, 0, 0, 0, 1, 0);
    ts_quad_mesh(&m[0], &q[0], 0);
    ts_quad_mesh(&m[1], &q[1], 1);
    m[0].lightmap_uvs = uvq;
    m[0].normals = nrm;
    memset(&d, 0, sizeof(d));
    d.meshes = m;
    d.mesh_count = 2;
    d.materials = mats;
    d.material_count = 2;
    for (side = 0; side < 2; ++side) {
        const float nz = side ? 1.0f : -1.0f;
        ff_world w;
        rad_form_factors *ff = NULL;
        rad_form_factor_options fo;
        rad_lightmap *lm = NULL;
        rad_lightmap_options lo;
        rad_lightmap_gather_options go;
        float *E = NULL, *H = NULL;
        double sum = 0.0;
        uint32_t i, valid = 0, wrong = 0;
        for (k = 0; k < 4; ++k) { nrm[3 * k] = 0.0f; nrm[3 * k + 1] = 0.0f; nrm[3 * k + 2] = nz; }
        if (!ff_world_make(&d, 0.25f, 0, &w)) return;
        CHECK(w.scene->lightmapped[0] == 1 && w.scene->lightmapped[1] == 0);
        rad_form_factor_options_default(&fo);
        CHECK_OK(rad_form_factors_dense(w.patches, &w.rc, &fo, NULL, &ff));
        rad_lightmap_options_default(&lo);
        lo.width = lo.height = 8;
        CHECK_OK(rad_lightmap_create(w.scene, &w.rc, &lo, NULL, &lm));
        E = (float *)calloc(3 * (size_t)w.patches->count, sizeof(float));
        H = lm ? (float *)calloc(3 * (size_t)lm->width * lm->height, sizeof(float)) : NULL;
        if (ff && lm && E && H) {
            CHECK_OK(rad_sources(w.patches, RAD_SOURCE_EMISSION, NULL, E));
            rad_lightmap_gather_options_default(&go);
            CHECK_OK(rad_lightmap_gather(lm, w.patches, E, &w.rc, &go, H, NULL));
            for (i = 0; i < lm->width * lm->height; ++i) {
                if (!(lm->flags[i] & RAD_TEXEL_VALID)) continue;
                ++valid;
                if (!(lm->normals[3 * i + 2] * nz > 0.99f)) ++wrong;
                sum += H[3 * i];
            }
            CHECK(valid == 64);
            CHECK(wrong == 0);
            if (side == 0) CHECK_REL(sum / valid, FF_PI * 1.0 * ff_c11(1.0, 1.0, 0.5), 0.02);
            else CHECK(sum == 0.0);
        }
        free(E);
        free(H);
        rad_lightmap_destroy(lm);
        rad_form_factors_destroy(ff);
        ff_world_free(&w);
    }
}

/* A one-sided scene is the scene it always was: the Cornell box flattens to its mesh
   triangles in order, as wound, with no twins array. */
static void ts_test_one_sided_unchanged(void)
{
    rad_scene_desc d;
    rad_scene *s = NULL;
    uint32_t mi, t, dst = 0;
    int k, v;
    rad_cornell_box(&d, NULL);
    CHECK_OK(rad_scene_create(&d, NULL, &s));
    if (!s) return;
    CHECK(s->twins == NULL);
    CHECK(s->triangle_count == 32);
    for (mi = 0; mi < d.mesh_count; ++mi)
        for (t = 0; t < d.meshes[mi].triangle_count && dst < s->triangle_count; ++t, ++dst) {
            CHECK(s->meshes[dst] == mi && s->source_triangles[dst] == t);
            for (v = 0; v < 3; ++v)
                for (k = 0; k < 3; ++k)
                    CHECK(s->positions[9 * dst + 3 * v + k] == d.meshes[mi].positions[3 * d.meshes[mi].indices[3 * t + v] + k]);
        }
    CHECK(dst == 32);
    rad_scene_destroy(s);
}

static const rad_test_case tests_twosided[] = {
    { "twosided_scene_pairs", ts_test_scene_pairs },
    { "twosided_raycasters_report_the_side_seen", ts_test_raycasters_report_the_side_seen },
#ifdef RAD_EMBREE
    { "twosided_embree_matches_bvh", ts_test_embree_matches_bvh },
#endif
    { "twosided_sheet_closed_form", ts_test_sheet_closed_form },
    { "twosided_sheet_emits_both_ways", ts_test_sheet_emits_both_ways },
    { "twosided_mixed_winding_box", ts_test_mixed_winding_box },
    { "twosided_gather_mesh_reports_one_side", ts_test_gather_mesh_reports_one_side },
    { "twosided_lightmap_reports_one_side", ts_test_lightmap_reports_one_side },
    { "twosided_one_sided_unchanged", ts_test_one_sided_unchanged },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_twosided)
