/* test_direct_noise.c - the per-point direct light of emitters: the analytic point-to-polygon
   factor against the closed form of a rectangle, the solid-angle sampler of spherical
   triangles (uniform, on the triangle, its mean cosine giving the factor), an unoccluded
   emitter exact for any seed, and, under an emitter larger than the opening it shines
   through, the noise of pixel-sized clusters of points across seeds against the earlier
   estimator (area samples weighted by cos cos / r^2, one rotation per point), the mean against
   the closed form of the visible part, and the same bits in any task order. Everything static
   and prefixed dn_. */
#include "fixtures.h"

#define DN_PI 3.14159265358979323846

/* The form factor from a point to a parallel a x b rectangle at height h with the point under
   one of its corners (the classic closed form). */
static double dn_corner_rect(double a, double b, double h)
{
    double x = a / h, y = b / h, sx = sqrt(1.0 + x * x), sy = sqrt(1.0 + y * y);
    return (x / sx * atan(y / sx) + y / sy * atan(x / sy)) / (2.0 * DN_PI);
}

static void dn_test_analytic_square(void)
{
    static const float sq[12] = { 0, 1, 0, 1, 1, 0, 1, 1, 1, 0, 1, 1 }; /* unit square at y = 1, facing down */
    const float up[3] = { 0, 1, 0 };
    const float heights[3] = { 1.0f, 0.5f, 3.0f };
    int i;
    for (i = 0; i < 3; ++i) {
        double h = heights[i];
        float corner[3] = { 0.0f, 0.0f, 0.0f }, centre[3] = { 0.5f, 0.0f, 0.5f }, off[3] = { 0.25f, 0.0f, 0.75f };
        double want_corner, want_centre, want_off;
        corner[1] = centre[1] = off[1] = (float)(1.0 - h);
        want_corner = dn_corner_rect(1.0, 1.0, h);
        want_centre = 4.0 * dn_corner_rect(0.5, 0.5, h);
        /* a point inside the projection: four corner rectangles around it */
        want_off = dn_corner_rect(0.25, 0.75, h) + dn_corner_rect(0.75, 0.75, h) + dn_corner_rect(0.25, 0.25, h) +
                   dn_corner_rect(0.75, 0.25, h);
        CHECK_REL(rad_ff_point_polygon(corner, up, sq, 4), want_corner, 1e-5);
        CHECK_REL(rad_ff_point_polygon(centre, up, sq, 4), want_centre, 1e-5);
        CHECK_REL(rad_ff_point_polygon(off, up, sq, 4), want_off, 1e-5);
    }
}

/* Arvo's map: every direction lies inside the spherical triangle, the mean cosine over a
   stratified set times the solid angle / pi gives the analytic factor, and the solid angle
   agrees with Van Oosterom and Strackee's formula. */
static void dn_test_sphere_sampler(void)
{
    static const float tris[3][9] = {
        { -1, 1, -1, 2, 1, 0, 0, 1, 3 },           /* over the point, wide */
        { 5, 0.2f, 5, 6, 0.5f, 5, 5, 0.3f, 7 },    /* far and low */
        { -30, 2, -30, 30, 2, -30, 0, 2, 40 }      /* nearly filling the sky */
    };
    const double P[3] = { 0, 0, 0 }, N[3] = { 0, 1, 0 };
    int t;
    for (t = 0; t < 3; ++t) {
        const float *v = tris[t];
        double u[3][3], dd[3], q[4][3], det, dot, vs;
        rad__sph_tri st;
        uint32_t s, S = 4096, inside = 0;
        double sum = 0.0, F;
        int i, k, m;
        for (i = 0; i < 3; ++i) {
            double l = sqrt((double)v[3 * i] * v[3 * i] + (double)v[3 * i + 1] * v[3 * i + 1] + (double)v[3 * i + 2] * v[3 * i + 2]);
            for (k = 0; k < 3; ++k) u[i][k] = v[3 * i + k] / l;
        }
        m = rad__clip_tri(P, N, v, dd, q);
        CHECK(m == 3); /* wholly above */
        CHECK(rad__sph_tri_setup(&st, u[0], u[1], u[2]));
        det = u[0][0] * (u[1][1] * u[2][2] - u[1][2] * u[2][1]) - u[0][1] * (u[1][0] * u[2][2] - u[1][2] * u[2][0]) +
              u[0][2] * (u[1][0] * u[2][1] - u[1][1] * u[2][0]);
        dot = 1.0 + rad__ddot(u[0], u[1]) + rad__ddot(u[1], u[2]) + rad__ddot(u[2], u[0]);
        vs = 2.0 * atan2(fabs(det), dot);
        if (vs < 0.0) vs += 2.0 * DN_PI;
        CHECK_REL(st.area, vs, 1e-6);
        for (s = 0; s < S; ++s) {
            float u1, u2;
            double dir[3], e1[3], e2[3], x[3], tt, den, nrm[3], b1, b2;
            rad__sobol2(s, 0x12345678u, 0x9abcdef0u, &u1, &u2);
            rad__sph_tri_sample(&st, u1, u2, dir);
            sum += dir[1];
            /* the ray from P along dir meets the triangle: barycentrics in [0, 1] */
            for (k = 0; k < 3; ++k) { e1[k] = (double)v[3 + k] - v[k]; e2[k] = (double)v[6 + k] - v[k]; }
            nrm[0] = e1[1] * e2[2] - e1[2] * e2[1], nrm[1] = e1[2] * e2[0] - e1[0] * e2[2], nrm[2] = e1[0] * e2[1] - e1[1] * e2[0];
            den = rad__ddot(dir, nrm);
            tt = ((double)v[0] * nrm[0] + (double)v[1] * nrm[1] + (double)v[2] * nrm[2]) / den;
            for (k = 0; k < 3; ++k) x[k] = dir[k] * tt - v[k];
            {
                double d11 = rad__ddot(e1, e1), d12 = rad__ddot(e1, e2), d22 = rad__ddot(e2, e2);
                double p1 = rad__ddot(x, e1), p2 = rad__ddot(x, e2), D = d11 * d22 - d12 * d12;
                b1 = (d22 * p1 - d12 * p2) / D, b2 = (d11 * p2 - d12 * p1) / D;
                if (tt > 0.0 && b1 >= -1e-6 && b2 >= -1e-6 && b1 + b2 <= 1.0 + 1e-6) ++inside;
            }
        }
        F = rad__ff_point_tri(P, N, v);
        if (getenv("RAD_TEST_VERBOSE"))
            printf("    triangle %d: solid angle %.6f, mean cos x area / pi %.6f, analytic F %.6f\n", t, st.area,
                   sum / S * st.area / DN_PI, fabs(F));
        CHECK(inside == S);
        CHECK_REL(sum / S * st.area / DN_PI, fabs(F), 2e-3);
    }
}

/* ---- the open box under a large emitter (fx_open_box, the scene of light_partly_hidden_emitter) ---- */

/* The estimator this library used before: L points uniform in area on each emitter triangle
   (Hammersley, rotated by a hash of the seed per point), each shadow ray's share of pi L F
   its kernel cos cos / r^2 over the kernel's sum. Kept here as the yardstick. */
static float dn_old_estimate(const fx_open_box *w, const float *p, const float *n, uint32_t L, uint32_t seed)
{
    rad_ray rays[2 * 64];
    uint8_t occ[2 * 64];
    double ks[2 * 64], ksum[2] = { 0.0, 0.0 }, F[2], D = 0.0, P[3], N[3];
    uint32_t t, s, k;
    for (k = 0; k < 3; ++k) P[k] = p[k], N[k] = n[k];
    for (t = 0; t < 2; ++t) {
        const float *tv = w->S->positions + 9 * (size_t)(10 + t), *tn = w->S->normals + 3 * (size_t)(10 + t);
        uint32_t h = rad__hash(seed ^ rad__hash(10 + t + 0x68e31da4u));
        F[t] = fabs(rad__ff_point_tri(P, N, tv));
        for (s = 0; s < L; ++s) {
            float u1, u2, y[3], dy[3], r2;
            rad__hammersley(s, L, (float)(h & 0xFFFFu) / 65536.0f, (float)(h >> 16) / 65536.0f, &u1, &u2);
            rad__triangle_point(tv, tv + 3, tv + 6, u1, u2, y);
            rad__sub(dy, y, p);
            r2 = rad__dot(dy, dy);
            ks[t * L + s] = (double)rad__dot(dy, n) * -(double)rad__dot(dy, tn) / ((double)r2 * r2);
            if (ks[t * L + s] < 0.0) ks[t * L + s] = 0.0;
            ksum[t] += ks[t * L + s];
            rad__segment_ray(&rays[t * L + s], p, n, y, tn, 1e-5f * w->S->diagonal);
        }
    }
    if (w->rc.occluded(w->rc.user, rays, 2 * L, occ) != RAD_SUCCESS) return -1.0f;
    for (t = 0; t < 2; ++t)
        for (s = 0; s < L; ++s)
            if (!occ[t * L + s] && ksum[t] > 0.0) D += DN_PI * F[t] * ks[t * L + s] / ksum[t];
    return (float)D;
}

/* The floor's clusters: C pixel-sized 4 x 4 groups of points, each group's reference the
   analytic light of the visible part of the emitter at its centre (the opening projected from
   the point onto the emitter's plane, 1.2 times the opening). */
#define DN_C 96u
#define DN_G 16u
static void dn_clusters(float *pts, float *nrm, double *ref, int sky)
{
    static const float cor[4][2] = { { 0, 0 }, { 10, 0 }, { 10, 10 }, { 0, 10 } };
    const float up[3] = { 0, 1, 0 };
    uint32_t i, j, q, h = 12345u;
    for (i = 0; i < DN_C; ++i) {
        float cx, cz, vis[12], pc[3];
        h = rad__hash(h + i);
        cx = 0.5f + 9.0f * (float)(h & 0xFFFFu) / 65536.0f;
        cz = 0.5f + 9.0f * (float)(h >> 16) / 65536.0f;
        for (j = 0; j < DN_G; ++j) {
            float *p = pts + 3 * (size_t)(i * DN_G + j), *nn = nrm + 3 * (size_t)(i * DN_G + j);
            p[0] = cx + 0.04f * ((float)(j % 4) + 0.5f) / 4.0f;
            p[1] = 1e-4f;
            p[2] = cz + 0.04f * ((float)(j / 4) + 0.5f) / 4.0f;
            nn[0] = 0.0f, nn[1] = 1.0f, nn[2] = 0.0f;
        }
        pc[0] = cx + 0.02f, pc[1] = 1e-4f, pc[2] = cz + 0.02f;
        for (q = 0; q < 4; ++q) {
            vis[3 * q] = sky ? cor[q][0] : pc[0] + (cor[q][0] - pc[0]) * 1.2f;
            vis[3 * q + 1] = sky ? 5.0f : 6.0f;
            vis[3 * q + 2] = sky ? cor[q][1] : pc[2] + (cor[q][1] - pc[2]) * 1.2f;
        }
        /* the emitter: pi L F of the visible part; the sky (E_0 = 1): F of the opening */
        ref[i] = (sky ? 1.0 : DN_PI) * rad_ff_point_polygon(pc, up, vis, 4);
    }
}

/* the relative spread across seeds of the clusters' means and their mean over the reference,
   for the library (old == 0) or the earlier estimator */
static void dn_spread(const fx_open_box *w, const rad_light *sky, int old, uint32_t seeds, double *rel_sd, double *mean_ratio)
{
    float *pts = (float *)malloc(sizeof(float) * 3 * DN_C * DN_G), *nrm = (float *)malloc(sizeof(float) * 3 * DN_C * DN_G);
    float *out = (float *)malloc(sizeof(float) * 3 * DN_C * DN_G);
    double *ref = (double *)malloc(sizeof(double) * DN_C), *s1 = (double *)calloc(DN_C, sizeof(double));
    double *s2 = (double *)calloc(DN_C, sizeof(double)), var = 0.0, ratio = 0.0;
    uint32_t sd, i, j;
    rad_direct_options o;
    *rel_sd = *mean_ratio = -1.0;
    if (!pts || !nrm || !out || !ref || !s1 || !s2) goto done;
    dn_clusters(pts, nrm, ref, sky != NULL);
    rad_direct_options_default(&o);
    o.exclude_emitters = sky != NULL;
    for (sd = 0; sd < seeds; ++sd) {
        o.seed = 7919u * sd + 1u;
        if (old) {
            for (i = 0; i < DN_C * DN_G; ++i) {
                out[3 * i] = dn_old_estimate(w, pts + 3 * (size_t)i, nrm + 3 * (size_t)i, 16u, rad__hash(o.seed + i));
                if (!(out[3 * i] >= 0.0f)) goto done;
            }
        } else if (rad_direct_irradiance(w->S, &w->rc, sky, sky ? 1u : 0u, &o, pts, nrm, DN_C * DN_G, out, NULL) != RAD_SUCCESS) {
            goto done;
        }
        for (i = 0; i < DN_C; ++i) {
            double a = 0.0;
            for (j = 0; j < DN_G; ++j) a += out[3 * (i * DN_G + j)];
            a /= DN_G;
            s1[i] += a, s2[i] += a * a;
        }
    }
    for (i = 0; i < DN_C; ++i) {
        double mu = s1[i] / seeds, v = s2[i] / seeds - mu * mu;
        var += (v > 0.0 ? v : 0.0) / (ref[i] * ref[i]);
        ratio += mu / ref[i];
    }
    *rel_sd = sqrt(var / DN_C);
    *mean_ratio = ratio / DN_C;
done:
    free(pts); free(nrm); free(out); free(ref); free(s1); free(s2);
}

static void dn_test_partly_hidden_noise(void)
{
    fx_open_box w;
    double sd_new, sd_old, m_new, m_old;
    if (!fx_open_box_make(&w, 1)) {
        CHECK(0);
        fx_open_box_free(&w);
        return;
    }
    dn_spread(&w, NULL, 0, 6, &sd_new, &m_new);
    dn_spread(&w, NULL, 1, 6, &sd_old, &m_old);
    printf("    pixel clusters under the large emitter: relative sd %.4f (earlier estimator %.4f, variance %.0fx lower), "
           "mean / closed form %.4f (earlier %.4f)\n", sd_new, sd_old, sd_old * sd_old / (sd_new * sd_new + 1e-30), m_new, m_old);
    CHECK(sd_new >= 0.0 && sd_old >= 0.0);
    CHECK(sd_new * sd_new * 20.0 < sd_old * sd_old);
    CHECK(sd_new < 0.015);
    CHECK_REL(m_new, 1.0, 0.005);
    /* the earlier estimator was also biased low here (its ratio over a handful of effective
       samples): the new mean is nearer the closed form */
    CHECK(fabs(m_new - 1.0) < fabs(m_old - 1.0));
    fx_open_box_free(&w);
}

/* Under a constant sky the floor sees it through the opening only: the mean of the clusters is
   E_0 times the opening's factor, and the shared stratification of a cluster's points keeps
   its spread low. */
static void dn_test_sky_through_opening(void)
{
    fx_open_box w;
    rad_light sky;
    double sd, m;
    if (!fx_open_box_make(&w, 0)) {
        CHECK(0);
        fx_open_box_free(&w);
        return;
    }
    memset(&sky, 0, sizeof(sky));
    sky.type = RAD_LIGHT_SKY;
    sky.color[0] = sky.color[1] = sky.color[2] = 1.0f;
    dn_spread(&w, &sky, 0, 6, &sd, &m);
    printf("    sky through the opening: relative sd %.4f, mean / closed form %.4f\n", sd, m);
    CHECK(sd >= 0.0 && sd < 0.025); /* one rotation per point stays above this */
    CHECK_REL(m, 1.0, 0.005);
    fx_open_box_free(&w);
}

/* An emitter that nothing hides gives pi L F exactly for any seed, even one filling most of
   the hemisphere (the shares of the rays sum to one); a point under the box's floor gets
   nothing; the result does not depend on the task order. */
static void dn_test_unoccluded_exact(void)
{
    fx_open_box w;
    const float pts[9] = { 5, 5.5f, 5, -10, 5.9f, 20, 30, 5.5f, 5 }, nrm[9] = { 0, 1, 0, 0.3f, 1, 0.2f, -1, 1, 0 };
    float out[9], out2[9];
    rad_direct_options o;
    rad_context ctx;
    uint32_t sd, i;
    if (!fx_open_box_make(&w, 1)) {
        CHECK(0);
        fx_open_box_free(&w);
        return;
    }
    rad_direct_options_default(&o);
    for (sd = 0; sd < 4; ++sd) {
        o.seed = sd;
        CHECK_OK(rad_direct_irradiance(w.S, &w.rc, NULL, 0, &o, pts, nrm, 3, out, NULL));
        for (i = 0; i < 3; ++i) {
            double P[3], N[3], l = sqrt((double)nrm[3 * i] * nrm[3 * i] + (double)nrm[3 * i + 1] * nrm[3 * i + 1] +
                                        (double)nrm[3 * i + 2] * nrm[3 * i + 2]), want = 0.0;
            int k;
            for (k = 0; k < 3; ++k) P[k] = pts[3 * i + k], N[k] = nrm[3 * i + k] / l;
            want = DN_PI * (fabs(rad__ff_point_tri(P, N, w.S->positions + 90)) + fabs(rad__ff_point_tri(P, N, w.S->positions + 99)));
            if (getenv("RAD_TEST_VERBOSE")) printf("    point %u: %.6f, pi L F %.6f\n", i, (double)out[3 * i], want);
            CHECK(want > 0.01);
            CHECK_REL(out[3 * i], want, 1e-4);
        }
    }
    memset(&ctx, 0, sizeof(ctx));
    ctx.parallel_for = fx_reverse_for;
    ctx.task_count = 3;
    o.seed = 3;
    CHECK_OK(rad_direct_irradiance(w.S, &w.rc, NULL, 0, &o, pts, nrm, 3, out2, &ctx));
    CHECK(memcmp(out, out2, sizeof(out)) == 0);
    fx_open_box_free(&w);
}

/* rad__emitter_rays: L for a small emitter, more (a power of two times L, at most 4 L and 256)
   as the emitter's factor grows. */
static void dn_test_ray_count(void)
{
    CHECK(rad__emitter_rays(16, 0.01f) == 16);
    CHECK(rad__emitter_rays(16, 0.25f) == 16);
    CHECK(rad__emitter_rays(16, 0.3f) == 32);
    CHECK(rad__emitter_rays(16, 0.9f) == 64);
    CHECK(rad__emitter_rays(100, 0.9f) == 256);
    CHECK(rad__emitter_rays(256, 0.9f) == 256);
    CHECK(rad__emitter_rays(1, 1.0f) == 4);
}

static const rad_test_case tests_direct_noise[] = {
    { "direct_noise_analytic_square", dn_test_analytic_square },
    { "direct_noise_sphere_sampler", dn_test_sphere_sampler },
    { "direct_noise_partly_hidden", dn_test_partly_hidden_noise },
    { "direct_noise_sky_opening", dn_test_sky_through_opening },
    { "direct_noise_unoccluded_exact", dn_test_unoccluded_exact },
    { "direct_noise_ray_count", dn_test_ray_count },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_direct_noise)
