/* test_vp_accuracy.c - virtual patches against the light they should carry: the plan counts
   the kind that is built (a clustered set has more patches than an axis-aligned one at the
   same resolution, so a plan that counted AAVP passed the memory budget for VP), and on
   touching emissive spheres (the shape of Blender's emissive-strength test asset) the
   clustered set carries the source power of the axis-aligned one and gathers the light of
   the crevice where two spheres touch only onto the surface that lies there. Included by
   test_main.c after the implementation: every name is static and prefixed va_. */
#include "fixtures.h"

#define VA_SPHERES 3
#define VA_SEG 24
#define VA_RINGS 20

typedef struct va_world {
    float pos[VA_SPHERES][3 * (VA_RINGS + 1) * (VA_SEG + 1)];
    uint32_t idx[VA_SPHERES][6 * VA_RINGS * VA_SEG];
    rad_mesh_desc meshes[VA_SPHERES];
    rad_material mats[VA_SPHERES];
    rad_scene *scene;
    rad_bvh *bvh;
    rad_raycaster rc;
} va_world;

/* unit spheres (outward, one-sided) at x = 0, 2, 4: each touches the next; the first emits
   4.5, the second 0.3, the third nothing; albedo 0.999 as the asset's white */
static int va_spheres(va_world *w)
{
    rad_scene_desc d;
    uint32_t s, i, j;
    int k;
    memset(w, 0, sizeof(*w));
    for (s = 0; s < VA_SPHERES; ++s) {
        uint32_t t = 0;
        for (j = 0; j <= VA_RINGS; ++j)
            for (i = 0; i <= VA_SEG; ++i) {
                double th = 3.14159265358979 * j / VA_RINGS, ph = 6.28318530717959 * i / VA_SEG;
                float *p = &w->pos[s][3 * (j * (VA_SEG + 1) + i)];
                p[0] = (float)(2.0 * s + sin(th) * cos(ph));
                p[1] = (float)cos(th);
                p[2] = (float)(sin(th) * sin(ph));
            }
        for (j = 0; j < VA_RINGS; ++j)
            for (i = 0; i < VA_SEG; ++i) {
                uint32_t a = j * (VA_SEG + 1) + i, b = a + VA_SEG + 1;
                if (j > 0) { w->idx[s][t++] = a; w->idx[s][t++] = a + 1; w->idx[s][t++] = b; }
                if (j < VA_RINGS - 1) { w->idx[s][t++] = a + 1; w->idx[s][t++] = b + 1; w->idx[s][t++] = b; }
            }
        w->meshes[s].positions = w->pos[s];
        w->meshes[s].vertex_count = (VA_RINGS + 1) * (VA_SEG + 1);
        w->meshes[s].indices = w->idx[s];
        w->meshes[s].triangle_count = t / 3;
        w->meshes[s].material = s;
        for (k = 0; k < 3; ++k) {
            w->mats[s].albedo[k] = 0.999f;
            w->mats[s].emission[k] = s == 0 ? 4.5f : s == 1 ? 0.3f : 0.0f;
        }
    }
    memset(&d, 0, sizeof d);
    d.meshes = w->meshes;
    d.mesh_count = VA_SPHERES;
    d.materials = w->mats;
    d.material_count = VA_SPHERES;
    if (rad_scene_create(&d, NULL, &w->scene) != RAD_SUCCESS) return 0;
    if (rad_bvh_create(w->scene, NULL, &w->bvh) != RAD_SUCCESS) return 0;
    rad_bvh_raycaster(w->bvh, &w->rc);
    return 1;
}

static void va_free(va_world *w)
{
    rad_bvh_destroy(w->bvh);
    rad_scene_destroy(w->scene);
}

/* sum_a A_a E_a (green) of the set of this kind at resolution 3 (voxels of about 2.3 units:
   the contacts lie inside voxels, as in the asset at its resolution 16), and the set */
static double va_source_power(const va_world *w, rad_vp_kind kind, rad_virtual_patches **out, float **E_out)
{
    rad_vp_options o;
    rad_direct_options dopt;
    rad_virtual_patches *vp = NULL;
    float *E;
    double p = 0.0;
    uint32_t i;
    *out = NULL;
    *E_out = NULL;
    rad_vp_options_default(&o);
    o.resolution = 3;
    o.kind = kind;
    CHECK_OK(rad_vp_create(w->scene, &w->rc, &o, NULL, &vp));
    if (!vp) return 0.0;
    E = (float *)calloc(3 * (size_t)vp->count, sizeof(float));
    CHECK(E != NULL);
    if (!E) { rad_vp_destroy(vp); return 0.0; }
    rad_direct_options_default(&dopt);
    dopt.exclude_emitters = 0;
    CHECK_OK(rad_vp_sources(vp, &w->rc, NULL, 0, &dopt, RAD_SOURCE_DIRECT, E, NULL));
    for (i = 0; i < vp->count; ++i) p += (double)vp->areas[i] * (double)E[3 * (size_t)i + 1];
    *out = vp;
    *E_out = E;
    return p;
}

/* The clustered set's source power is the axis-aligned set's (the same samples and the same
   exact area per voxel and axis: clustering only regroups them). One area correction per
   voxel let the samples at the contacts, where the direct light of the emitter is brightest,
   stand for the whole voxel: 20% more power at this resolution. And the gathered irradiance
   on the surface, weighted by area, stays near the patches' own: by normal alone the
   crevice's small bright clusters lit the whole voxel. */
static void va_test_touching_spheres(void)
{
    static va_world w;
    rad_virtual_patches *va = NULL, *vc = NULL;
    float *Ea = NULL, *Ec = NULL;
    double pa, pc;
    CHECK(va_spheres(&w));
    if (!w.scene) return;
    pa = va_source_power(&w, RAD_VP_AXIS_ALIGNED, &va, &Ea);
    pc = va_source_power(&w, RAD_VP_CLUSTERED, &vc, &Ec);
    CHECK(pa > 0.0);
    CHECK_NEAR(pc / pa, 1.0, 1e-3);
    if (vc && Ec) {
        /* E gathered at the triangles' centroids, integrated over the surface by area, against
           sum_a A_a E_a: the gather puts each cluster's light where its surface is */
        const rad_scene *S = w.scene;
        uint32_t T = S->triangle_count, t;
        float *pts = (float *)malloc(sizeof(float) * 3 * T), *out = (float *)malloc(sizeof(float) * 3 * T);
        double g = 0.0;
        CHECK(pts && out);
        if (pts && out) {
            int k;
            for (t = 0; t < T; ++t)
                for (k = 0; k < 3; ++k)
                    pts[3 * t + k] = (S->positions[9 * t + k] + S->positions[9 * t + 3 + k] + S->positions[9 * t + 6 + k]) / 3.0f;
            CHECK_OK(rad_vp_gather(vc, Ec, pts, S->normals, T, out, NULL));
            for (t = 0; t < T; ++t) g += (double)S->areas[t] * (double)out[3 * t + 1];
            if (getenv("VA_PRINT")) printf("gathered / patches %g\n", g / pc);
            CHECK_NEAR(g / pc, 1.0, 0.05);
        }
        free(pts);
        free(out);
    }
    free(Ea);
    free(Ec);
    rad_vp_destroy(va);
    rad_vp_destroy(vc);
    va_free(&w);
}

/* rad_baker_plan counts the kind it is told will be built: with vp_kind RAD_VP_CLUSTERED its
   patch count is rad_vp_count's for a clustered set at the plan's resolution (more than the
   axis-aligned count there), and a budget between the two estimates gives the clustered plan
   a coarser resolution */
typedef struct va_box_world {
    vp_scene *s;
    rad_scene *scene;
    rad_bvh *bvh;
    rad_raycaster rc;
} va_box_world;

/* the inside of a 3 x 1 x 1 box, 6 x 6 cells a face, a lit ceiling */
static int va_box(va_box_world *w)
{
    rad_scene_desc d;
    memset(w, 0, sizeof(*w));
    w->s = (vp_scene *)malloc(sizeof(vp_scene));
    if (!w->s) return 0;
    vp_box(w->s, 3.0f, 1.0f, 1.0f, 6, 1);
    vp_desc(w->s, &d, 0.6f, 0.0f);
    w->s->materials[1].emission[0] = w->s->materials[1].emission[1] = w->s->materials[1].emission[2] = 1.0f;
    if (rad_scene_create(&d, NULL, &w->scene) != RAD_SUCCESS) return 0;
    if (rad_bvh_create(w->scene, NULL, &w->bvh) != RAD_SUCCESS) return 0;
    rad_bvh_raycaster(w->bvh, &w->rc);
    return 1;
}

static void va_box_free(va_box_world *w)
{
    rad_bvh_destroy(w->bvh);
    rad_scene_destroy(w->scene);
    free(w->s);
}

static void va_test_plan_counts_kind(void)
{
    va_box_world pw;
    rad_baker_options o;
    rad_baker_choice pa, pc;
    rad_vp_options vo;
    rad_vp_counts ca, cc;
    CHECK(va_box(&pw));
    if (!pw.scene) { va_box_free(&pw); return; }
    memset(&o, 0, sizeof o);
    o.method = RAD_BAKER_VIRTUAL_PATCHES;
    o.vp_resolution = 8;
    CHECK_OK(rad_baker_plan(pw.scene, &pw.rc, &o, NULL, &pa));
    o.vp_kind = RAD_VP_CLUSTERED;
    CHECK_OK(rad_baker_plan(pw.scene, &pw.rc, &o, NULL, &pc));
    CHECK(pa.vp_kind == RAD_VP_AXIS_ALIGNED && pc.vp_kind == RAD_VP_CLUSTERED);
    rad_vp_options_default(&vo);
    vo.resolution = 8;
    CHECK_OK(rad_vp_count(pw.scene, &pw.rc, &vo, NULL, &ca));
    vo.kind = RAD_VP_CLUSTERED;
    CHECK_OK(rad_vp_count(pw.scene, &pw.rc, &vo, NULL, &cc));
    CHECK(pa.patch_count == ca.patches && pc.patch_count == cc.patches);
    CHECK(cc.patches > ca.patches && pc.estimated_bytes > pa.estimated_bytes);
    /* a budget that holds the axis-aligned set at 8 but not the clustered one */
    o.max_memory = 0.5 * (pa.estimated_bytes + pc.estimated_bytes);
    CHECK_OK(rad_baker_plan(pw.scene, &pw.rc, &o, NULL, &pc));
    CHECK(pc.vp_resolution < 8 && pc.budget_limited && pc.estimated_bytes <= o.max_memory);
    o.vp_kind = RAD_VP_AXIS_ALIGNED;
    CHECK_OK(rad_baker_plan(pw.scene, &pw.rc, &o, NULL, &pa));
    CHECK(pa.vp_resolution == 8 && !pa.budget_limited);
    o.vp_kind = (rad_vp_kind)7;
    CHECK_RESULT(rad_baker_plan(pw.scene, &pw.rc, &o, NULL, &pa), RAD_ERROR_INVALID_ARGUMENT);
    va_box_free(&pw);
}

static const rad_test_case tests_vp_accuracy[] = {
    { "vp_accuracy_touching_spheres", va_test_touching_spheres },
    { "vp_accuracy_plan_counts_kind", va_test_plan_counts_kind },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_vp_accuracy)
