/* trace.c - the reference path tracer of the rad tool.

   What it computes: the radiance seen through each pixel (box filter: spp samples spread over
   the pixel's area by stratified jitter on an sx x sy grid, sx * sy = spp) for the same light
   transport model the radiosity solvers use:
     - every surface is Lambertian with the albedo of rad_scene_albedo at the hit (textures
       work); surfaces are ONE-SIDED like the radiosity patches: the front is the CCW side
       (scene->normals); a ray that hits a back face ends there (nothing reflected or emitted).
       A two-sided material's triangle is two scene triangles back to back (rad_scene.twins),
       and the raycaster reports the one whose front faces the ray, so both of its sides
       reflect and emit, each on its own, with no code here;
     - emissive triangles emit radiance = material emission from their front only;
     - analytic lights: directional, point and spot lights by next-event estimation only (delta
       lights, same falloff and spot smoothstep as rad_direct_irradiance), the sky
       (RAD_LIGHT_SKY, colour = exitance E0) as a constant radiance E0 / pi seen by every ray
       that escapes the scene (camera rays included), an environment map
       (RAD_LIGHT_ENVIRONMENT) as its radiance in the escaping ray's direction times the
       light's colour.
   Environment maps also get next-event estimation: one direction per vertex and map drawn
   from the map's own distribution (rad_environment_sample, the one rad_direct_irradiance
   uses), combined with the cosine continuation by the power heuristic (an escaping
   continuation ray then weighs the map's radiance by its share against rad_environment_pdf).
   Estimator: next-event estimation for the area lights (one emitter per vertex, chosen with
   probability proportional to its power pi * area * (Lr + Lg + Lb), a point uniform on it)
   combined with the BSDF (cosine) sample by multiple importance sampling with the power
   heuristic; camera rays that hit an emitter's front see its radiance with weight 1.
   Path length: at most max_depth segments; Russian roulette (survival = max throughput
   channel, at most 0.95) only from bounce rr_depth on.
   Self-intersection: origins offset along the geometric normal by 1e-5 * scene->diagonal, tmin
   0; shadow rays to an emitter point stop at the point offset from the emitter likewise.
   Random numbers: a counter-based hash of (seed, pixel, sample, bounce, dimension), so the
   image does not depend on the thread count or the order rows run in. Each pixel's samples
   are summed in double in sample order. */
#include "tool.h"
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#define TOOL__TPI 3.14159265358979323846
#define TOOL__DIMS_PER_BOUNCE 8u

void tool_trace_options_default(tool_trace_options *o)
{
    if (!o) return;
    memset(o, 0, sizeof(*o));
    o->width = 256;
    o->height = 256;
    o->spp = 64;
    o->seed = 0;
    o->max_depth = 64;
    o->rr_depth = 16;
}

typedef struct tool__tracer {
    const rad_scene *S;
    const rad_raycaster *rc;
    const rad_light *lights;
    uint32_t light_count;
    const rad_camera *cam;
    tool_trace_options o;
    int sx, sy;              /* pixel strata */
    float eps;
    uint32_t emitter_count;
    uint32_t *emitters;      /* triangle of each emitter */
    double *cdf;             /* emitter_count + 1, cdf[0] = 0, cdf[n] = 1 */
    float *select_pdf;       /* per triangle: probability to be chosen (0 for non-emitters) */
    float sky[3];            /* radiance of escaping rays */
    const rad_light *env[8]; /* environment lights (at most 8) */
    uint32_t env_count;
    int has_delta;
    tool_image *out;
    volatile int failed;
    uint32_t row0;           /* first row of the current batch (parallel_for path) */
} tool__tracer;

/* lowbias32 (C. Wellons): a good 32-bit integer hash */
static uint32_t tool__th(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

/* uniform in [0,1) from (seed, pixel, sample, dimension) */
static float tool__rnd(uint32_t seed, uint32_t pixel, uint32_t sample, uint32_t dim)
{
    uint32_t h = tool__th(seed ^ tool__th(pixel ^ tool__th(sample ^ tool__th(dim + 0x9E3779B9u))));
    return (float)(h >> 8) * (1.0f / 16777216.0f);
}

static float tool__tdot(const float *a, const float *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* orthonormal basis around unit n (Duff et al. 2017) */
static void tool__basis(const float *n, float *t1, float *t2)
{
    float s = n[2] >= 0.0f ? 1.0f : -1.0f;
    float a = -1.0f / (s + n[2]);
    float b = n[0] * n[1] * a;
    t1[0] = 1.0f + s * n[0] * n[0] * a;
    t1[1] = s * b;
    t1[2] = -s * n[0];
    t2[0] = b;
    t2[1] = s + n[1] * n[1] * a;
    t2[2] = -n[1];
}

/* power heuristic (beta = 2) weight of the strategy with density a against b */
static float tool__mis(float a, float b)
{
    float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

static uint32_t tool__pick_emitter(const tool__tracer *T, float u)
{
    uint32_t lo = 0, hi = T->emitter_count; /* find i with cdf[i] <= u < cdf[i+1] */
    double du = (double)u;
    while (hi - lo > 1) {
        uint32_t mid = (lo + hi) / 2;
        if (T->cdf[mid] <= du) lo = mid;
        else hi = mid;
    }
    /* skip zero-probability entries (cannot be chosen) */
    while (lo + 1 < T->emitter_count && !(T->cdf[lo + 1] > T->cdf[lo])) ++lo;
    return lo;
}

/* shadow ray from p (offset along n) to q (offset along qn when given) or along dir */
static int tool__visible(const tool__tracer *T, const float *p, const float *n, const float *q, const float *qn,
                        const float *dir, int *ok)
{
    rad_ray ray;
    uint8_t occ = 1;
    int k;
    for (k = 0; k < 3; ++k) ray.origin[k] = p[k] + n[k] * T->eps;
    ray.tmin = 0.0f;
    if (q) {
        float len;
        for (k = 0; k < 3; ++k) ray.dir[k] = q[k] + (qn ? qn[k] * T->eps : 0.0f) - ray.origin[k];
        len = sqrtf(tool__tdot(ray.dir, ray.dir));
        ray.tmax = len > 2.0f * T->eps ? 1.0f - T->eps / len : 0.5f;
    } else {
        for (k = 0; k < 3; ++k) ray.dir[k] = dir[k];
        ray.tmax = FLT_MAX;
    }
    if (T->rc->occluded(T->rc->user, &ray, 1, &occ) != RAD_SUCCESS) {
        *ok = 0;
        return 0;
    }
    return !occ;
}

/* an escaping ray gathers the sky and each environment map, MIS-weighted against their sampling */
static void tool__trace_escape(const tool__tracer *T, const rad_ray *ray, int depth, float prev_pdf, const float *thr,
                               float *L)
{
    uint32_t l;
    int k;
    for (k = 0; k < 3; ++k) L[k] += thr[k] * T->sky[k];
    for (l = 0; l < T->env_count; ++l) {
        const rad_light *li = T->env[l];
        float rgb[3], w = depth > 0 ? tool__mis(prev_pdf, rad_environment_pdf(li->environment, ray->dir)) : 1.0f;
        rad_environment_radiance(li->environment, ray->dir, rgb);
        for (k = 0; k < 3; ++k) L[k] += thr[k] * li->color[k] * rgb[k] * w;
    }
}

/* a hit emitter adds its emission, MIS-weighted against next-event estimation after the first bounce */
static void tool__trace_emitted(const tool__tracer *T, const rad_hit *hit, uint32_t tri, float cosi, int depth,
                                float prev_pdf, const float *thr, float *L)
{
    const rad_scene *S = T->S;
    const float *Le;
    float Lt[3];
    int k;
    Le = S->materials_table[S->materials[tri]].emission;
    if (Le[0] > 0.0f || Le[1] > 0.0f || Le[2] > 0.0f) {
        float w = 1.0f;
        rad_scene_emission(S, tri, hit->b1, hit->b2, Lt); /* the factor times the emission texture there */
        Le = Lt;
        if (depth > 0) {
            float pl = T->select_pdf[tri] / S->areas[tri] * hit->t * hit->t / cosi;
            w = tool__mis(prev_pdf, pl);
        }
        for (k = 0; k < 3; ++k) L[k] += thr[k] * Le[k] * w;
    }
}

/* next-event estimation towards one point of one area light; returns 0 when a ray query failed */
static int tool__trace_nee_area(const tool__tracer *T, uint32_t pixel, uint32_t sample, uint32_t dim, uint32_t tri,
                                const float *p, const float *n, const float *albedo, const float *thr, float *L, int *ok)
{
    const rad_scene *S = T->S;
    const uint32_t seed = T->o.seed;
    int k;
    uint32_t e = tool__pick_emitter(T, tool__rnd(seed, pixel, sample, dim + 0));
    uint32_t lt = T->emitters[e];
    if (lt != tri) { /* a point in a cutout's hole emits nothing (skipped below) */
        const float *lv = S->positions + 9 * (size_t)lt, *ln = S->normals + 3 * (size_t)lt;
        float u1 = tool__rnd(seed, pixel, sample, dim + 1), u2 = tool__rnd(seed, pixel, sample, dim + 2);
        float su = sqrtf(u1), b0 = 1.0f - su, bb1 = u2 * su, bb2 = 1.0f - b0 - bb1;
        float q[3], d[3], d2, dist, cs, cl, lL[3];
        rad_scene_emission(S, lt, bb1, bb2, lL); /* at the light's sample point: textures vary it */
        if (!rad_scene_opaque(S, lt, bb1, bb2)) lL[0] = lL[1] = lL[2] = 0.0f;
        for (k = 0; k < 3; ++k) {
            q[k] = b0 * lv[k] + bb1 * lv[3 + k] + bb2 * lv[6 + k];
            d[k] = q[k] - p[k];
        }
        d2 = tool__tdot(d, d);
        if (d2 > 0.0f) {
            dist = sqrtf(d2);
            cs = tool__tdot(d, n) / dist;
            cl = -tool__tdot(d, ln) / dist;
            if (cs > 0.0f && cl > 0.0f && tool__visible(T, p, n, q, ln, NULL, ok)) {
                float pl = T->select_pdf[lt] / S->areas[lt] * d2 / cl; /* solid angle */
                float pb = cs / (float)TOOL__TPI;
                float f = tool__mis(pl, pb) * cs / ((float)TOOL__TPI * pl);
                for (k = 0; k < 3; ++k) L[k] += thr[k] * albedo[k] * lL[k] * f;
            }
            if (!*ok) return 0;
        }
    }
    return 1;
}

/* environment maps: one direction from each map's distribution; returns 0 when a ray query failed */
static int tool__trace_nee_env(const tool__tracer *T, uint32_t pixel, uint32_t sample, uint32_t dim, const float *p,
                               const float *n, const float *albedo, const float *thr, float *L, int *ok)
{
    const uint32_t seed = T->o.seed;
    int k;
    uint32_t l;
    for (l = 0; l < T->env_count; ++l) {
        const rad_light *li = T->env[l];
        float dd[3], rgb[3], pe, cs, f;
        pe = rad_environment_sample(li->environment, tool__rnd(seed, pixel, sample, dim + 6),
                                    tool__rnd(seed, pixel, sample, dim + 7), dd);
        if (!(pe > 0.0f)) continue;
        cs = tool__tdot(dd, n);
        if (!(cs > 0.0f)) continue;
        if (!tool__visible(T, p, n, NULL, NULL, dd, ok)) {
            if (!*ok) return 0;
            continue;
        }
        rad_environment_radiance(li->environment, dd, rgb);
        f = tool__mis(pe, cs / (float)TOOL__TPI) * cs / ((float)TOOL__TPI * pe);
        for (k = 0; k < 3; ++k) L[k] += thr[k] * albedo[k] * li->color[k] * rgb[k] * f;
    }
    return 1;
}

/* delta lights (no MIS): each directional, point and spot light that sees p; returns 0 when a ray query failed */
static int tool__trace_nee_delta(const tool__tracer *T, const float *p, const float *n, const float *albedo,
                                 const float *thr, float *L, int *ok)
{
    const rad_scene *S = T->S;
    int k;
    uint32_t l;
    for (l = 0; l < T->light_count; ++l) {
        const rad_light *li = &T->lights[l];
        float w[3], dd[3], cs;
        if (li->type == RAD_LIGHT_DIRECTIONAL) {
            float len;
            for (k = 0; k < 3; ++k) dd[k] = -li->direction[k];
            len = sqrtf(tool__tdot(dd, dd));
            if (!(len > 0.0f)) continue;
            for (k = 0; k < 3; ++k) dd[k] /= len;
            cs = tool__tdot(dd, n);
            if (!(cs > 0.0f)) continue;
            for (k = 0; k < 3; ++k) w[k] = li->color[k] * cs;
            if (!tool__visible(T, p, n, NULL, NULL, dd, ok)) {
                if (!*ok) return 0;
                continue;
            }
        } else if (li->type == RAD_LIGHT_POINT || li->type == RAD_LIGHT_SPOT) {
            float dist, dc, atten, md = li->min_distance > 0.0f ? li->min_distance : 1e-6f * S->diagonal;
            for (k = 0; k < 3; ++k) dd[k] = li->position[k] - p[k];
            dist = sqrtf(tool__tdot(dd, dd));
            if (!(dist > 0.0f)) continue;
            cs = tool__tdot(dd, n) / dist;
            if (!(cs > 0.0f)) continue;
            dc = dist > md ? dist : md;
            atten = li->falloff == RAD_FALLOFF_LINEAR ? 1.0f / dc : 1.0f / (dc * dc);
            if (li->type == RAD_LIGHT_SPOT) {
                float axis[3], alen, ca, ci = cosf(li->inner_angle), co = cosf(li->outer_angle), s;
                for (k = 0; k < 3; ++k) axis[k] = li->direction[k];
                alen = sqrtf(tool__tdot(axis, axis));
                if (!(alen > 0.0f)) continue;
                ca = -tool__tdot(dd, axis) / (dist * alen);
                if (ci > co) {
                    s = (ca - co) / (ci - co);
                    s = s < 0.0f ? 0.0f : (s > 1.0f ? 1.0f : s);
                    atten *= s * s * (3.0f - 2.0f * s);
                } else if (!(ca >= co)) {
                    atten = 0.0f;
                }
                if (!(atten > 0.0f)) continue;
            }
            for (k = 0; k < 3; ++k) w[k] = li->color[k] * cs * atten;
            if (!tool__visible(T, p, n, li->position, NULL, NULL, ok)) {
                if (!*ok) return 0;
                continue;
            }
        } else {
            continue; /* sky and maps: above and on escaping rays */
        }
        /* reflected radiance = albedo / pi * irradiance */
        for (k = 0; k < 3; ++k) L[k] += thr[k] * albedo[k] * w[k] / (float)TOOL__TPI;
    }
    return 1;
}

/* continues the path with a cosine-weighted direction and Russian roulette; returns 0 when the path ends */
static int tool__trace_bounce(const tool__tracer *T, uint32_t pixel, uint32_t sample, uint32_t dim, int depth,
                              const float *p, const float *n, const float *albedo, rad_ray *ray, float *thr,
                              float *prev_pdf)
{
    const uint32_t seed = T->o.seed;
    float t1[3], t2[3];
    int k;
    /* the throughput gains the albedo */
    {
        float u1 = tool__rnd(seed, pixel, sample, dim + 3), u2 = tool__rnd(seed, pixel, sample, dim + 4);
        float r = sqrtf(u1), ph = 2.0f * (float)TOOL__TPI * u2, cz = sqrtf(1.0f - u1 > 0.0f ? 1.0f - u1 : 0.0f);
        float cx = r * cosf(ph), cy = r * sinf(ph), len;
        tool__basis(n, t1, t2);
        for (k = 0; k < 3; ++k) {
            ray->origin[k] = p[k] + n[k] * T->eps;
            ray->dir[k] = t1[k] * cx + t2[k] * cy + n[k] * cz;
        }
        len = sqrtf(tool__tdot(ray->dir, ray->dir));
        for (k = 0; k < 3; ++k) ray->dir[k] /= len;
        ray->tmin = 0.0f;
        ray->tmax = FLT_MAX;
        *prev_pdf = cz / (float)TOOL__TPI;
        if (!(*prev_pdf > 0.0f)) return 0;
        for (k = 0; k < 3; ++k) thr[k] *= albedo[k];
    }
    if (depth + 1 >= T->o.rr_depth) {
        float q = thr[0] > thr[1] ? thr[0] : thr[1];
        q = q > thr[2] ? q : thr[2];
        if (q > 0.95f) q = 0.95f;
        if (!(tool__rnd(seed, pixel, sample, dim + 5) < q)) return 0;
        for (k = 0; k < 3; ++k) thr[k] /= q;
    }
    return 1;
}

/* radiance of one camera sample; *ok = 0 when a ray query failed */
static void tool__trace_sample(const tool__tracer *T, uint32_t pixel, uint32_t sample, float px, float py,
                              double *acc, int *ok)
{
    const rad_scene *S = T->S;
    rad_ray ray;
    float thr[3] = { 1.0f, 1.0f, 1.0f }, L[3] = { 0.0f, 0.0f, 0.0f };
    float prev_pdf = 0.0f; /* solid-angle density of the BSDF sample that made 'ray' (0: camera) */
    int depth, k;
    rad_camera_ray(T->cam, (uint32_t)T->o.width, (uint32_t)T->o.height, px, py, &ray);
    for (depth = 0; depth < T->o.max_depth; ++depth) {
        rad_hit hit;
        const float *v, *n;
        float p[3], albedo[3], cosi;
        uint32_t tri, dim = (uint32_t)depth * TOOL__DIMS_PER_BOUNCE;
        if (T->rc->intersect(T->rc->user, &ray, 1, &hit) != RAD_SUCCESS) {
            *ok = 0;
            return;
        }
        if (hit.triangle == RAD_NONE || hit.triangle >= S->triangle_count) {
            tool__trace_escape(T, &ray, depth, prev_pdf, thr, L);
            break;
        }
        tri = hit.triangle;
        v = S->positions + 9 * (size_t)tri;
        n = S->normals + 3 * (size_t)tri;
        cosi = -tool__tdot(ray.dir, n); /* ray.dir is unit */
        if (!(cosi > 0.0f)) break;     /* back face: one-sided, black */
        for (k = 0; k < 3; ++k) p[k] = v[k] + hit.b1 * (v[3 + k] - v[k]) + hit.b2 * (v[6 + k] - v[k]);
        tool__trace_emitted(T, &hit, tri, cosi, depth, prev_pdf, thr, L);
        if (depth + 1 >= T->o.max_depth) break;
        rad_scene_albedo(S, tri, hit.b1, hit.b2, albedo);
        if (!(albedo[0] > 0.0f || albedo[1] > 0.0f || albedo[2] > 0.0f)) break;
        if (T->emitter_count && !tool__trace_nee_area(T, pixel, sample, dim, tri, p, n, albedo, thr, L, ok)) return;
        if (!tool__trace_nee_env(T, pixel, sample, dim, p, n, albedo, thr, L, ok)) return;
        if (T->has_delta && !tool__trace_nee_delta(T, p, n, albedo, thr, L, ok)) return;
        if (!tool__trace_bounce(T, pixel, sample, dim, depth, p, n, albedo, &ray, thr, &prev_pdf)) break;
    }
    for (k = 0; k < 3; ++k)
        if (L[k] == L[k] && L[k] < FLT_MAX) acc[k] += (double)L[k]; /* a NaN/Inf sample is dropped */
}

static int tool__trace_row(tool__tracer *T, int y)
{
    int x, s, ok = 1;
    for (x = 0; x < T->o.width && ok; ++x) {
        uint32_t pixel = (uint32_t)y * (uint32_t)T->o.width + (uint32_t)x;
        double acc[3] = { 0.0, 0.0, 0.0 };
        float *dst = T->out->rgb + 3 * (size_t)pixel;
        for (s = 0; s < T->o.spp && ok; ++s) {
            /* stratum (s % sx, s / sx) of an sx x sy grid, jittered inside */
            int cx = s % T->sx, cy = s / T->sx;
            float jx = tool__rnd(T->o.seed, pixel, (uint32_t)s, 0xFFFFFF00u);
            float jy = tool__rnd(T->o.seed, pixel, (uint32_t)s, 0xFFFFFF01u);
            float px = (float)x + ((float)cx + jx) / (float)T->sx;
            float py = (float)y + ((float)cy + jy) / (float)T->sy;
            tool__trace_sample(T, pixel, (uint32_t)s, px, py, acc, &ok);
        }
        dst[0] = (float)(acc[0] / (double)T->o.spp);
        dst[1] = (float)(acc[1] / (double)T->o.spp);
        dst[2] = (float)(acc[2] / (double)T->o.spp);
    }
    return ok;
}

static void tool__trace_task(void *data, uint32_t index)
{
    tool__tracer *T = (tool__tracer *)data;
    if (T->failed) return;
    if (!tool__trace_row(T, (int)(T->row0 + index))) T->failed = 1;
}

/* emitters and their selection probabilities (by power), as a CDF for next-event estimation */
static int tool__trace_emitters(tool__tracer *T)
{
    const rad_scene *S = T->S;
    uint32_t t, e;
    double total = 0.0;
    for (t = 0; t < S->triangle_count; ++t) {
        const float *Le = S->materials_table[S->materials[t]].emission;
        if (Le[0] > 0.0f || Le[1] > 0.0f || Le[2] > 0.0f) T->emitter_count++;
    }
    T->select_pdf = (float *)calloc(S->triangle_count, sizeof(float));
    if (!T->select_pdf) return RAD_ERROR_OUT_OF_MEMORY;
    if (T->emitter_count) {
        T->emitters = (uint32_t *)malloc(sizeof(uint32_t) * T->emitter_count);
        T->cdf = (double *)malloc(sizeof(double) * (T->emitter_count + 1u));
        if (!T->emitters || !T->cdf) {
            free(T->emitters);
            free(T->cdf);
            free(T->select_pdf);
            return RAD_ERROR_OUT_OF_MEMORY;
        }
        for (t = 0, e = 0; t < S->triangle_count; ++t) {
            const float *Le = S->materials_table[S->materials[t]].emission;
            if (Le[0] > 0.0f || Le[1] > 0.0f || Le[2] > 0.0f) {
                double pw = TOOL__TPI * (double)S->areas[t] * ((double)Le[0] + (double)Le[1] + (double)Le[2]);
                T->emitters[e] = t;
                T->cdf[e] = total;
                total += pw;
                ++e;
            }
        }
        for (e = 0; e < T->emitter_count; ++e) {
            double pw = (e + 1 < T->emitter_count ? T->cdf[e + 1] : total) - T->cdf[e];
            T->select_pdf[T->emitters[e]] = (float)(pw / total);
            T->cdf[e] /= total;
        }
        T->cdf[T->emitter_count] = 1.0;
    }
    return RAD_SUCCESS;
}

int tool_trace_image(const rad_scene *scene, const rad_raycaster *rc, const rad_light *lights, uint32_t light_count,
                    const rad_camera *camera, const tool_trace_options *options, const rad_context *ctx,
                    tool_image *out)
{
    tool__tracer T;
    uint32_t l;
    double run = 0.0;
    int y, batch, result = RAD_SUCCESS, s;
    if (!scene || !rc || !rc->intersect || !rc->occluded || !camera || !out || (light_count && !lights))
        return RAD_ERROR_INVALID_ARGUMENT;
    memset(&T, 0, sizeof(T));
    if (options) T.o = *options;
    else tool_trace_options_default(&T.o);
    if (T.o.max_depth <= 0) T.o.max_depth = 64;
    if (T.o.rr_depth <= 0) T.o.rr_depth = 16;
    if (T.o.width <= 0 || T.o.height <= 0 || T.o.spp <= 0) return RAD_ERROR_INVALID_ARGUMENT;
    T.S = scene;
    T.rc = rc;
    T.lights = lights;
    T.light_count = light_count;
    T.cam = camera;
    T.eps = 1e-5f * scene->diagonal;
    /* strata: sx the largest divisor of spp not above sqrt(spp) */
    for (s = (int)sqrt((double)T.o.spp); s > 1 && T.o.spp % s != 0; --s) {
    }
    T.sx = s < 1 ? 1 : s;
    T.sy = T.o.spp / T.sx;
    for (l = 0; l < light_count; ++l) {
        const rad_light *li = &lights[l];
        int k;
        for (k = 0; k < 3; ++k)
            if (!(li->color[k] >= -FLT_MAX && li->color[k] <= FLT_MAX)) return RAD_ERROR_NON_FINITE;
        if (li->type == RAD_LIGHT_SKY) {
            for (k = 0; k < 3; ++k) T.sky[k] += li->color[k] / (float)TOOL__TPI;
        } else if (li->type == RAD_LIGHT_DIRECTIONAL || li->type == RAD_LIGHT_POINT || li->type == RAD_LIGHT_SPOT) {
            T.has_delta = 1;
        } else if (li->type == RAD_LIGHT_ENVIRONMENT && li->environment && T.env_count < 8u) {
            T.env[T.env_count++] = li;
        } else {
            return RAD_ERROR_INVALID_ARGUMENT;
        }
    }
    if (out->width != T.o.width || out->height != T.o.height || !out->rgb) {
        tool_image_free(out);
        if (tool_image_alloc(out, T.o.width, T.o.height) != 0) return RAD_ERROR_OUT_OF_MEMORY;
    }
    T.out = out;
    result = tool__trace_emitters(&T);
    if (result != RAD_SUCCESS) return result;
    /* rows in batches; progress and cancellation between batches on the calling thread */
    batch = T.o.height / 64;
    if (batch < 1) batch = 1;
    for (y = 0; y < T.o.height && result == RAD_SUCCESS; y += batch) {
        int y1 = y + batch < T.o.height ? y + batch : T.o.height;
        if (ctx && ctx->parallel_for) {
            T.row0 = (uint32_t)y;
            ctx->parallel_for(ctx->parallel_user, (uint32_t)(y1 - y), tool__trace_task, &T);
        } else {
            int yy;
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 1)
#endif
            for (yy = y; yy < y1; ++yy) {
                if (!T.failed && !tool__trace_row(&T, yy)) T.failed = 1;
            }
        }
        if (T.failed) result = RAD_ERROR_RAYCAST_FAILED;
        run = (double)y1 / (double)T.o.height;
        if (result == RAD_SUCCESS && ctx && ctx->progress && ctx->progress(ctx->progress_user, (float)run) != 0)
            result = RAD_ERROR_CANCELLED;
    }
    free(T.emitters);
    free(T.cdf);
    free(T.select_pdf);
    return result;
}
