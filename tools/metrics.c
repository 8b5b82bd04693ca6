/* metrics.c - image metrics (MSE, PSNR, SSIM) on LINEAR values clamped to [0,1] (L = 1).

   MSE   mean of (a - b)^2 over every pixel and channel.
   PSNR  10 log10(1 / MSE); +inf for equal images.
   SSIM  Wang et al. 2004: 11x11 Gaussian window (sigma 1.5, normalised to sum 1), biased local
         moments, C1 = 0.01^2, C2 = 0.03^2, mean over the valid region (W-10) x (H-10), computed
         per channel (R, G, B) and averaged. Images narrower or lower than 11 pixels use one
         window covering the whole image with uniform weights. All sums in double. */
#include "tool.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define TOOL__SSIM_WIN 11
#define TOOL__SSIM_RAD 5

static double rad__clamp01(float v)
{
    if (!(v > 0.0f)) return 0.0; /* NaN compares as 0 */
    if (v >= 1.0f) return 1.0;
    return (double)v;
}

static int tool__same_size(const tool_image *a, const tool_image *b)
{
    return a && b && a->rgb && b->rgb && a->width == b->width && a->height == b->height && a->width > 0 &&
           a->height > 0;
}

double tool_image_mse(const tool_image *a, const tool_image *b)
{
    size_t i, n;
    double sum = 0.0;
    if (!tool__same_size(a, b)) return NAN;
    n = (size_t)a->width * (size_t)a->height * 3u;
    for (i = 0; i < n; ++i) {
        double d = rad__clamp01(a->rgb[i]) - rad__clamp01(b->rgb[i]);
        sum += d * d;
    }
    return sum / (double)n;
}

double tool_image_psnr(const tool_image *a, const tool_image *b)
{
    double mse = tool_image_mse(a, b);
    if (mse != mse) return NAN;
    if (mse == 0.0) return INFINITY;
    return 10.0 * log10(1.0 / mse);
}

static double tool__ssim_formula(double mx, double my, double sxx, double syy, double sxy)
{
    const double C1 = 0.01 * 0.01, C2 = 0.03 * 0.03;
    return ((2.0 * mx * my + C1) * (2.0 * sxy + C2)) / ((mx * mx + my * my + C1) * (sxx + syy + C2));
}

/* one channel of SSIM, whole image as a single uniform window (tiny images) */
static double tool__ssim_global(const tool_image *a, const tool_image *b, int c)
{
    size_t i, n = (size_t)a->width * (size_t)a->height;
    double mx = 0, my = 0, xx = 0, yy = 0, xy = 0;
    for (i = 0; i < n; ++i) {
        double x = rad__clamp01(a->rgb[3 * i + (size_t)c]), y = rad__clamp01(b->rgb[3 * i + (size_t)c]);
        mx += x;
        my += y;
        xx += x * x;
        yy += y * y;
        xy += x * y;
    }
    mx /= (double)n;
    my /= (double)n;
    return tool__ssim_formula(mx, my, xx / (double)n - mx * mx, yy / (double)n - my * my, xy / (double)n - mx * my);
}

double tool_image_ssim(const tool_image *a, const tool_image *b)
{
    double g[TOOL__SSIM_WIN], gsum = 0.0, total = 0.0;
    double *plane = NULL, *tmp = NULL;
    int W, H, VW, VH, c, x, y, k, q;
    if (!tool__same_size(a, b)) return NAN;
    W = a->width;
    H = a->height;
    if (W < TOOL__SSIM_WIN || H < TOOL__SSIM_WIN)
        return (tool__ssim_global(a, b, 0) + tool__ssim_global(a, b, 1) + tool__ssim_global(a, b, 2)) / 3.0;
    VW = W - (TOOL__SSIM_WIN - 1);
    VH = H - (TOOL__SSIM_WIN - 1);
    for (k = 0; k < TOOL__SSIM_WIN; ++k) {
        double d = (double)(k - TOOL__SSIM_RAD);
        g[k] = exp(-d * d / (2.0 * 1.5 * 1.5));
        gsum += g[k];
    }
    for (k = 0; k < TOOL__SSIM_WIN; ++k) g[k] /= gsum;
    /* 5 input planes (x, y, x^2, y^2, xy), filtered horizontally into tmp (VW x H each) */
    plane = (double *)malloc(sizeof(double) * 2u * (size_t)W * (size_t)H);
    tmp = (double *)malloc(sizeof(double) * 5u * (size_t)VW * (size_t)H);
    if (!plane || !tmp) {
        free(plane);
        free(tmp);
        return NAN;
    }
    for (c = 0; c < 3; ++c) {
        double sum = 0.0;
        for (y = 0; y < H; ++y)
            for (x = 0; x < W; ++x) {
                size_t i = (size_t)y * (size_t)W + (size_t)x;
                plane[2 * i] = rad__clamp01(a->rgb[3 * i + (size_t)c]);
                plane[2 * i + 1] = rad__clamp01(b->rgb[3 * i + (size_t)c]);
            }
        for (y = 0; y < H; ++y)
            for (x = 0; x < VW; ++x) {
                double s[5] = { 0, 0, 0, 0, 0 };
                for (k = 0; k < TOOL__SSIM_WIN; ++k) {
                    size_t i = (size_t)y * (size_t)W + (size_t)(x + k);
                    double px = plane[2 * i], py = plane[2 * i + 1];
                    s[0] += g[k] * px;
                    s[1] += g[k] * py;
                    s[2] += g[k] * px * px;
                    s[3] += g[k] * py * py;
                    s[4] += g[k] * px * py;
                }
                for (q = 0; q < 5; ++q) tmp[5 * ((size_t)y * (size_t)VW + (size_t)x) + (size_t)q] = s[q];
            }
        for (y = 0; y < VH; ++y)
            for (x = 0; x < VW; ++x) {
                double s[5] = { 0, 0, 0, 0, 0 };
                for (k = 0; k < TOOL__SSIM_WIN; ++k)
                    for (q = 0; q < 5; ++q) s[q] += g[k] * tmp[5 * ((size_t)(y + k) * (size_t)VW + (size_t)x) + (size_t)q];
                sum += tool__ssim_formula(s[0], s[1], s[2] - s[0] * s[0], s[3] - s[1] * s[1], s[4] - s[0] * s[1]);
            }
        total += sum / ((double)VW * (double)VH);
    }
    free(plane);
    free(tmp);
    return total / 3.0;
}

/* linear-RGB colour map (black, purple, red, orange, yellow, white: an "inferno"-like ramp
   given in sRGB and decoded so the 8-bit PNG shows these colours) */
static void tool__heat(double t, float out[3])
{
    static const double stops[6][3] = {
        { 0.0, 0.0, 0.0 }, { 0.34, 0.06, 0.43 }, { 0.73, 0.21, 0.33 },
        { 0.98, 0.55, 0.04 }, { 0.98, 0.90, 0.15 }, { 1.0, 1.0, 1.0 }
    };
    double f;
    int i, k;
    if (!(t > 0.0)) t = 0.0;
    if (t > 1.0) t = 1.0;
    f = t * 5.0;
    i = (int)f;
    if (i > 4) i = 4;
    f -= (double)i;
    for (k = 0; k < 3; ++k) {
        double s = stops[i][k] + (stops[i + 1][k] - stops[i][k]) * f;
        out[k] = (float)(s <= 0.04045 ? s / 12.92 : pow((s + 0.055) / 1.055, 2.4));
    }
}

int tool_image_diff_heatmap(const tool_image *a, const tool_image *b, float scale, tool_image *out)
{
    size_t i, n;
    if (!out || !tool__same_size(a, b)) return -1;
    if (tool_image_alloc(out, a->width, a->height) != 0) return -1;
    n = (size_t)a->width * (size_t)a->height;
    for (i = 0; i < n; ++i) {
        double d = 0.0;
        int k;
        for (k = 0; k < 3; ++k) d += fabs(rad__clamp01(a->rgb[3 * i + (size_t)k]) - rad__clamp01(b->rgb[3 * i + (size_t)k]));
        d /= 3.0;
        tool__heat(scale > 0.0f ? d / (double)scale : 0.0, out->rgb + 3 * i);
    }
    return 0;
}
