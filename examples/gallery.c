/* gallery.c - every lighting model of radiosity.h (>>shading, docs/methods/shading.md) on rows
   of spheres, like the model comparison figure of Korobeinikov 2022 (docs/references.md).

   One PNG, one row per model, seven spheres per row sweeping the model's main parameter:
     1 Lambert                 albedo 0.2 .. 0.8
     2 half-Lambert (wrap)     w = 0 .. 1 (p = 2; w = 0 is cos^2, w = 1 Valve's half-Lambert)
     3 banded                  bands 1 .. 7
     4 Phong (normalized)      shininess 2 .. 512
     5 Blinn-Phong (normal.)   shininess 2 .. 512
     6 Minnaert                k = 0.4 .. 1.6
     7 Oren-Nayar              sigma = 0 .. 1.5
     8 Beckmann, isotropic     alpha = 0.05 .. 1   (height-correlated G2, Lambert diffuse)
     9 GGX, isotropic          alpha = 0.05 .. 1
    10 GGX, separable G2       alpha = 0.05 .. 1, Shirley diffuse term
    11 Beckmann, anisotropic   alpha_x = 0.05 .. 1, alpha_y = 0.05 (tangent: horizontal)
    12 GGX, anisotropic        alpha_x = 0.05 .. 1, alpha_y = 0.05
    13 GGX metal (gold F0)     alpha = 0.05 .. 1, no diffuse term
   Lights: a warm directional light from the upper left and a cool point light (quadratic
   falloff) to the lower right in front of each sphere, plus a small ambient irradiance
   shaded as Lambert, the way an engine adds radiosity's indirect irradiance H:
       L = sum_lights E_light * R(l, v, n) + rho / pi * H
   where R = f * max(n.l, 0) is rad_shading_eval's response (the specular lobe of a
   material only ever sees the direct lights: radiosity's indirect light is diffuse).
   Orthographic camera looking down -z, 2 x 2 samples per pixel, exposure, sRGB.

   Build:  cc -std=c99 -O2 -I. examples/gallery.c -o build/gallery -lm   (or: make gallery)
   Run:    build/gallery [--size S] [-o FILE]     S: pixels per sphere (default 96)       */

#define RADIOSITY_IMPLEMENTATION
#include "radiosity.h"
#include "png_write.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>

#define GAL_ROWS 13
#define GAL_COLS 7

static unsigned char gal_srgb8(float v)
{
    float s;
    if (!(v > 0.0f)) v = 0.0f;
    if (v > 1.0f) v = 1.0f;
    s = v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
    return (unsigned char)(s * 255.0f + 0.5f);
}

/* the material of sphere (row, col); x in [0, 1] along the row */
static void gal_material(int row, int col, rad_shading *s)
{
    float x = (float)col / (float)(GAL_COLS - 1), alpha = 0.05f + 0.95f * x * x;
    int k;
    static const rad_shading_model models[7] = { RAD_SHADING_LAMBERT, RAD_SHADING_HALF_LAMBERT, RAD_SHADING_BANDED,
                                                  RAD_SHADING_PHONG, RAD_SHADING_BLINN_PHONG, RAD_SHADING_MINNAERT,
                                                  RAD_SHADING_OREN_NAYAR };
    rad_shading_default(s, row < 7 ? models[row] : RAD_SHADING_MICROFACET);
    switch (row) {
    case 0: for (k = 0; k < 3; ++k) s->lambert.albedo[k] = 0.2f + 0.6f * x; break;
    case 1: s->half_lambert.wrap = x; break;
    case 2: s->banded.bands = (uint32_t)(1 + col); break;
    case 3: case 4: s->phong.shininess = powf(2.0f, 1.0f + 8.0f * x); break;
    case 5: s->minnaert.k = 0.4f + 1.2f * x; break;
    case 6: s->oren_nayar.sigma = 1.5f * x; break;
    default: {
        rad_microfacet_params *m = &s->microfacet;
        m->ndf = (row == 7 || row == 10) ? RAD_NDF_BECKMANN : RAD_NDF_GGX;
        m->alpha_x = m->alpha_y = alpha;
        if (row == 9) { m->masking = RAD_MASKING_SEPARABLE; m->diffuse = RAD_DIFFUSE_SHIRLEY; }
        if (row == 10 || row == 11) m->alpha_y = 0.05f;
        if (row == 12) {
            m->diffuse = RAD_DIFFUSE_NONE;
            m->f0[0] = 1.0f; m->f0[1] = 0.78f; m->f0[2] = 0.34f; /* gold, roughly */
        }
        for (k = 0; k < 3; ++k) m->albedo[k] = 0.5f;
        m->albedo[0] = 0.6f; m->albedo[2] = 0.35f;  /* a warm base colour */
        break;
    }
    }
}

int main(int argc, char **argv)
{
    const char *out_path = "gallery.png";
    int S = 96, a, row, col, px, py, sx, sy, k, status = 0;
    unsigned char *img;
    uint32_t W, H;
    const float v[3] = { 0.0f, 0.0f, 1.0f };
    const float sun_irradiance[3] = { 2.6f, 2.3f, 1.9f }, point_intensity[3] = { 3.0f, 4.0f, 6.5f };
    const float ambient_irradiance[3] = { 0.25f, 0.27f, 0.32f }, exposure = 0.9f;
    float sun_dir[3];
    rad_shading s;

    for (a = 1; a < argc; ++a) {
        if (!strcmp(argv[a], "--size") && a + 1 < argc) {
            S = atoi(argv[++a]);
            if (S < 4 || S > 1024) { fprintf(stderr, "gallery: --size wants 4..1024 pixels per sphere\n"); return 2; }
        } else if (!strcmp(argv[a], "-o") && a + 1 < argc) {
            out_path = argv[++a];
        } else {
            fprintf(stderr, "usage: gallery [--size S] [-o FILE]\n  --size S  pixels per sphere (default 96)\n"
                            "  -o FILE   output PNG (default gallery.png)\n");
            return 2;
        }
    }
    W = (uint32_t)(S * GAL_COLS);
    H = (uint32_t)(S * GAL_ROWS);
    img = (unsigned char *)malloc((size_t)W * H * 3);
    if (!img) return 1;
    sun_dir[0] = -0.55f; sun_dir[1] = 0.6f; sun_dir[2] = 0.58f; /* towards the light */

    for (row = 0; row < GAL_ROWS; ++row)
        for (col = 0; col < GAL_COLS; ++col) {
            gal_material(row, col, &s);
            for (py = 0; py < S; ++py)
                for (px = 0; px < S; ++px) {
                    float acc[3] = { 0.0f, 0.0f, 0.0f };
                    unsigned char *o = img + 3 * ((size_t)(row * S + py) * W + (size_t)(col * S + px));
                    for (sy = 0; sy < 2; ++sy)
                        for (sx = 0; sx < 2; ++sx) {
                            /* sphere of radius 1 filling 90 % of its cell; y up */
                            float x = ((float)px + 0.25f + 0.5f * (float)sx) / (float)S * 2.0f - 1.0f;
                            float y = 1.0f - ((float)py + 0.25f + 0.5f * (float)sy) / (float)S * 2.0f;
                            float r2, n[3], t[3], pl[3], d2, tl, L[3], R[3], albedo_pi[3];
                            x /= 0.9f; y /= 0.9f;
                            r2 = x * x + y * y;
                            if (r2 >= 1.0f) {
                                float bg = 0.03f + 0.02f * (float)((row + col) & 1);
                                for (k = 0; k < 3; ++k) acc[k] += 0.25f * bg;
                                continue;
                            }
                            n[0] = x; n[1] = y; n[2] = sqrtf(1.0f - r2);
                            /* tangent: horizontal, around the vertical axis */
                            t[0] = n[2]; t[1] = 0.0f; t[2] = -n[0];
                            if (t[0] * t[0] + t[2] * t[2] < 1e-8f) { t[0] = 1.0f; t[2] = 0.0f; }
                            for (k = 0; k < 3; ++k) L[k] = 0.0f;
                            /* directional light */
                            if (rad_shading_eval(&s, sun_dir, v, n, t, NULL, R, NULL) != RAD_SUCCESS) { status = 1; goto done; }
                            for (k = 0; k < 3; ++k) L[k] += sun_irradiance[k] * R[k];
                            /* point light at (1.6, -1.2, 2.2) in sphere units, I / d^2 */
                            pl[0] = 1.6f - n[0]; pl[1] = -1.2f - n[1]; pl[2] = 2.2f - n[2];
                            d2 = pl[0] * pl[0] + pl[1] * pl[1] + pl[2] * pl[2];
                            if (rad_shading_eval(&s, pl, v, n, t, NULL, R, NULL) != RAD_SUCCESS) { status = 1; goto done; }
                            for (k = 0; k < 3; ++k) L[k] += point_intensity[k] / d2 * R[k];
                            /* ambient, as radiosity's indirect irradiance: Lambert with the
                               model's diffuse albedo */
                            tl = 1.0f / 3.14159265f;
                            for (k = 0; k < 3; ++k) {
                                float rho = s.model == RAD_SHADING_MICROFACET ? (s.microfacet.diffuse == RAD_DIFFUSE_NONE ? 0.0f : s.microfacet.albedo[k])
                                          : s.model == RAD_SHADING_PHONG || s.model == RAD_SHADING_BLINN_PHONG ? s.phong.diffuse[k]
                                          : s.lambert.albedo[k];
                                if (s.model == RAD_SHADING_HALF_LAMBERT) rho = s.half_lambert.albedo[k];
                                if (s.model == RAD_SHADING_BANDED) rho = s.banded.albedo[k];
                                if (s.model == RAD_SHADING_MINNAERT) rho = s.minnaert.albedo[k];
                                if (s.model == RAD_SHADING_OREN_NAYAR) rho = s.oren_nayar.albedo[k];
                                albedo_pi[k] = rho * tl;
                                acc[k] += 0.25f * exposure * (L[k] + albedo_pi[k] * ambient_irradiance[k]);
                            }
                        }
                    for (k = 0; k < 3; ++k) o[k] = gal_srgb8(acc[k]);
                }
        }
    if (png_write_rgb8(out_path, W, H, img, (size_t)W * 3) != 0) {
        fprintf(stderr, "gallery: cannot write %s\n", out_path);
        status = 1;
    } else {
        printf("gallery: %u x %u pixels, %d models x %d spheres -> %s\n", W, H, GAL_ROWS, GAL_COLS, out_path);
    }
done:
    if (status) fprintf(stderr, "gallery: failed\n");
    free(img);
    return status;
}
