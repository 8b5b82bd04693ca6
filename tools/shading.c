/* shading.c - 'rad render --shading MODEL': the lighting models of radiosity.h (>>shading,
   from Korobeinikov 2022 in docs/references.md) applied to the direct term of the classic render.

   How a model combines with the radiosity solution. Radiosity computes diffuse transport
   only, so the indirect irradiance H (and the solution itself) stays Lambertian with the
   scene's albedo: the pixel gets albedo / pi * H whatever the model. The model replaces
   the response to the ANALYTIC lights (directional, point, spot), whose direction l at each
   point is known: each contributes E V R(l, v, n), with E the light's irradiance on a
   surface facing it, V its visibility (shadow ray) and R = f max(n.l, 0) the model's
   response (rad_shading_eval). Emissive triangles (area lights) and the sky light a point
   from many directions at once; they stay Lambertian: albedo / pi * D_rest. The model's
   diffuse albedo is the scene's albedo at the point; its other parameters are the
   defaults of rad_*_params_default (e.g. Phong ks 0.3 shininess 32, microfacet GGX
   alpha 0.3, F0 0.04, Lambert diffuse term). The diffuse models (Lambert, half-Lambert,
   banded, Minnaert, Oren-Nayar) therefore only change how the scene's albedo answers the
   direct light; the specular ones (Phong, Blinn-Phong, microfacet) add highlights on top
   of a diffuse radiosity solution, which does not see them (no glossy interreflection). */
#include "tool.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>

int tool_parse_shading(const char *cmd, const char *text, int *out_model)
{
    rad_shading_model m;
    int i;
    if (!strcmp(text, "none")) { *out_model = -1; return 0; }
    if (rad_shading_model_from_name(text, &m) == RAD_SUCCESS) { *out_model = (int)m; return 0; }
    fprintf(stderr, "rad %s: unknown shading model '%s' (none", cmd, text);
    for (i = 0; i < (int)RAD_SHADING_MODEL_COUNT; ++i) fprintf(stderr, ", %s", rad_shading_model_name((rad_shading_model)i));
    fprintf(stderr, ")\n");
    return 2;
}

/* the material of one point: the model's defaults with the scene's albedo as diffuse albedo */
static void shading_material(rad_shading_model model, const float *albedo, rad_shading *s)
{
    int k;
    rad_shading_default(s, model);
    for (k = 0; k < 3; ++k) {
        float a = albedo[k] < 0.0f ? 0.0f : (albedo[k] > 1.0f ? 1.0f : albedo[k]);
        s->lambert.albedo[k] = s->half_lambert.albedo[k] = s->banded.albedo[k] = a;
        s->phong.diffuse[k] = s->minnaert.albedo[k] = s->oren_nayar.albedo[k] = s->microfacet.albedo[k] = a;
    }
}

int tool_shade_direct(const tool_world *w, int model, uint32_t light_samples, const float *points,
                          const float *normals, const float *views, const float *albedos, uint32_t count,
                          float *out_rgb)
{
    const rad_light *lights = w->file.lights;
    uint32_t nl = w->file.light_count, j, k, i, nrest = 0;
    rad_light *rest = NULL;
    float *dirs = NULL, *irr = NULL;
    rad_direct_options dopt;
    rad_context quiet;
    rad_result r = RAD_SUCCESS;
    rad_shading s;
    int result = 0;
    rad_direct_options_default(&dopt);
    dopt.light_samples = light_samples;
    tool_context(&quiet, NULL);
    dirs = (float *)malloc(sizeof(float) * 3 * (count ? count : 1));
    irr = (float *)malloc(sizeof(float) * 3 * (count ? count : 1));
    rest = (rad_light *)malloc(sizeof(rad_light) * (nl ? nl : 1));
    if (!dirs || !irr || !rest) { result = tool_fail("render", "shading", RAD_ERROR_OUT_OF_MEMORY); goto done; }
    for (i = 0; i < count; ++i) out_rgb[3 * i] = out_rgb[3 * i + 1] = out_rgb[3 * i + 2] = 0.0f;
    /* the analytic lights, one at a time: irradiance on a surface facing the light (the
       "normal" handed to rad_direct_irradiance is l itself), times R(l, v, n) */
    dopt.exclude_emitters = 1;
    for (j = 0; j < nl; ++j) {
        const rad_light *L = &lights[j];
        if (L->type == RAD_LIGHT_SKY || L->type == RAD_LIGHT_ENVIRONMENT) { rest[nrest++] = *L; continue; }
        for (i = 0; i < count; ++i) {
            float d[3], len;
            if (L->type == RAD_LIGHT_DIRECTIONAL) { d[0] = -L->direction[0]; d[1] = -L->direction[1]; d[2] = -L->direction[2]; }
            else for (k = 0; k < 3; ++k) d[k] = L->position[k] - points[3 * i + k];
            len = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            if (!(len > 0.0f)) { d[0] = normals[3 * i]; d[1] = normals[3 * i + 1]; d[2] = normals[3 * i + 2]; len = 1.0f; }
            for (k = 0; k < 3; ++k) dirs[3 * i + k] = d[k] / len;
        }
        r = rad_direct_irradiance(w->scene, &w->rc, L, 1, &dopt, points, dirs, count, irr, &quiet);
        if (r != RAD_SUCCESS) { result = tool_fail("render", "rad_direct_irradiance (shading)", r); goto done; }
        for (i = 0; i < count; ++i) {
            float R[3];
            if (irr[3 * i] == 0.0f && irr[3 * i + 1] == 0.0f && irr[3 * i + 2] == 0.0f) continue;
            shading_material((rad_shading_model)model, albedos + 3 * i, &s);
            r = rad_shading_eval(&s, dirs + 3 * i, views + 3 * i, normals + 3 * i, NULL, NULL, R, &quiet);
            if (r != RAD_SUCCESS) { result = tool_fail("render", "rad_shading_eval", r); goto done; }
            for (k = 0; k < 3; ++k) out_rgb[3 * i + k] += irr[3 * i + k] * R[k];
        }
    }
    /* emissive triangles and the sky: Lambertian */
    dopt.exclude_emitters = 0;
    r = rad_direct_irradiance(w->scene, &w->rc, rest, nrest, &dopt, points, normals, count, irr, &quiet);
    if (r != RAD_SUCCESS) { result = tool_fail("render", "rad_direct_irradiance (area lights)", r); goto done; }
    for (i = 0; i < 3 * count; ++i) out_rgb[i] += albedos[i] * (float)(1.0 / 3.14159265358979323846) * irr[i];
done:
    free(dirs);
    free(irr);
    free(rest);
    return result;
}
