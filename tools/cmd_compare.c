/* cmd_compare.c - rad compare: MSE, PSNR and SSIM between two images.

   rad compare A B [--exposure E] [--diff OUT.png|OUT.pfm] [--diff-scale X] [--png OUT.png]
                   [--png-exposure X]

   A and B are PFM (linear) or PNG (8-bit sRGB, decoded to linear). The metrics (MSE, PSNR with
   peak L = 1, SSIM per R, G, B channel, averaged: metrics.c) are computed on LINEAR values
   times --exposure E (default 1), clamped to [0,1]: a scene whose radiance reaches 3.5 clamps
   to white wherever it is bright and scored 14 dB for every method; --exposure 0.25 brings it
   into range. E scales the --diff heat map and the --png picture too (--png-exposure X sets
   the picture's alone). Exit status: 0 compared, 1 unreadable images, different sizes or an image with
   NaN or infinite values (the metrics clamp them away, so they are counted and reported:
   an all-NaN render compared as equal to a black one), 2 usage. */
#include "tool.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* how many values of img are NaN / infinite; the first such pixel in *first (-1: none) */
static void count_nonfinite(const tool_image *img, size_t *nan, size_t *inf, long *first)
{
    size_t k, n = (size_t)img->width * (size_t)img->height * 3u;
    *nan = *inf = 0;
    *first = -1;
    for (k = 0; k < n; ++k) {
        float v = img->rgb[k];
        if (v != v) ++*nan;
        else if (v - v != 0.0f) ++*inf;
        else continue;
        if (*first < 0) *first = (long)(k / 3u);
    }
}

/* prints one line when img has NaN or infinite values; returns 1 then */
static double mean_radiance(const tool_image *img)
{
    size_t k, n = (size_t)img->width * (size_t)img->height * 3u, m = 0;
    double sum = 0.0;
    for (k = 0; k < n; ++k)
        if (isfinite(img->rgb[k])) sum += img->rgb[k], ++m;
    return m ? sum / (double)m : 0.0;
}

static int report_nonfinite(const char *name, const char *path, const tool_image *img)
{
    size_t nan, inf;
    long first;
    count_nonfinite(img, &nan, &inf, &first);
    if (!nan && !inf) return 0;
    fprintf(stderr, "rad compare: %s '%s' has %lu NaN and %lu infinite values (first at pixel x=%ld, y=%ld): the metrics below clamp them and mean nothing\n",
            name, path, (unsigned long)nan, (unsigned long)inf, first % img->width, first / img->width);
    printf("nonfinite %s: %lu NaN, %lu inf\n", name, (unsigned long)nan, (unsigned long)inf);
    return 1;
}

/* rad compare's command line */
typedef struct compare_args {
    const char *a, *b, *diff, *png;
    float exposure, scale, png_exposure; /* png_exposure 0: the same as exposure */
} compare_args;

static int parse_png(const char *cmd, const tool_arg *t, const char *v, void *field)
{
    size_t l = strlen(v);
    (void)t;
    if (l < 4 || (strcmp(v + l - 4, ".png") && strcmp(v + l - 4, ".PNG"))) {
        fprintf(stderr, "rad %s: --png wants a .png file, got '%s'\n", cmd, v);
        return 2;
    }
    *(const char **)field = v;
    return 0;
}

#define CA(f) offsetof(compare_args, f)
#define CA_POSITIVE(name, val, f, help) \
    {TOOL_ARG_FLOAT, name, val, CA(f), 0.0, 1e30, TOOL_ARG_LO_OPEN | TOOL_ARG_HI_OPEN, 0, "wants a positive number", NULL, \
     NULL, NULL, 0, help}
/* rad compare's options */
static const tool_arg compare_table[] = {
    CA_POSITIVE("--exposure", "E", exposure,
                "multiply both images by E before the metrics clamp them to [0,1]\n"
                "(default 1; for radiance above 1, e.g. E = 1 / the brightest value)"),
    {TOOL_ARG_STRING, "--diff", "FILE", CA(diff), 0, 0, 0, 0, NULL, NULL, NULL, NULL, 0,
     "heat map of the per-pixel mean absolute difference (black: none)"},
    CA_POSITIVE("--diff-scale", "X", scale, "the difference shown at the top of the colour scale (default: the largest)"),
    {TOOL_ARG_CUSTOM, "--png", "FILE", CA(png), 0, 0, 0, 0, NULL, NULL, NULL, parse_png, 0,
     "also write A as an 8-bit sRGB PNG (times E): one render gives both the .pfm the metrics\n"
     "need and a picture (tools/report.sh)"},
    CA_POSITIVE("--png-exposure", "X", png_exposure, "the PNG's exposure alone (default E), the metrics keep E"),
    {TOOL_ARG_END, NULL, NULL, 0, 0, 0, 0, 0, NULL, NULL, NULL, NULL, 0, NULL}
};

static void compare_usage(FILE *f)
{
    static char own[4096];
    tool_args_help_into(compare_table, 0, own, sizeof own);
    fprintf(f, "usage: rad compare A B [--exposure E] [--diff OUT.png] [--diff-scale X] [--png OUT.png [--png-exposure X]]\n"
               "  A, B               .pfm (linear float) or .png (8-bit sRGB, decoded to linear)\n"
               "%s"
               "  prints MSE, PSNR (peak 1) and SSIM (11x11 Gaussian window, sigma 1.5, per channel,\n"
               "  averaged), all on linear values times E, clamped to [0,1]; and the mean linear\n"
               "  radiance of each (unclamped) with their ratio, the energy check against a reference\n"
               "  exit 1 when an image holds NaN or infinite values (counted on stderr and in a\n"
               "  'nonfinite' line), or the images cannot be read or differ in size\n",
            own);
}

/* the command line into ca; -1: go on, else the exit code (--help 0; bad usage 2, printed) */
static int compare_parse(int argc, char **argv, compare_args *ca)
{
    int i, rc;
    memset(ca, 0, sizeof *ca);
    ca->exposure = 1.0f;
    for (i = 0; i < argc; ++i) {
        const char *s = argv[i];
        if (!strcmp(s, "-h") || !strcmp(s, "--help")) {
            compare_usage(stdout);
            return 0;
        }
        if ((rc = tool_args_parse("compare", compare_table, ca, NULL, argc, argv, &i)) == 2) return 2;
        if (rc == 1) continue;
        if (s[0] == '-' && s[1]) {
            fprintf(stderr, "rad compare: unknown option '%s'\n", s);
            compare_usage(stderr);
            return 2;
        } else if (!ca->a) {
            ca->a = s;
        } else if (!ca->b) {
            ca->b = s;
        } else {
            fprintf(stderr, "rad compare: too many images ('%s')\n", s);
            return 2;
        }
    }
    if (!ca->a || !ca->b) {
        compare_usage(stderr);
        return 2;
    }
    return -1;
}

int tool_cmd_compare(int argc, char **argv)
{
    compare_args ca;
    const char *pa, *pb, *diff, *png;
    float scale, exposure, png_exposure;
    tool_image a = { 0, 0, NULL }, b = { 0, 0, NULL };
    char err[512];
    double mse, psnr, ssim;
    int bad;
    if ((bad = compare_parse(argc, argv, &ca)) >= 0) return bad;
    pa = ca.a;
    pb = ca.b;
    diff = ca.diff;
    png = ca.png;
    scale = ca.scale;
    exposure = ca.exposure;
    png_exposure = ca.png_exposure;
    {
        const char *inputs[2];
        inputs[0] = pa;
        inputs[1] = pb;
        const char *outs[2];
        outs[0] = diff;
        outs[1] = png;
        if ((diff && tool_check_output("compare", diff, inputs, 2)) ||
            (png && tool_check_output("compare", png, inputs, 2)) || tool_check_outputs("compare", outs, 2, inputs, 2))
            return 1;
    }
    if (tool_image_read(pa, &a, err, sizeof(err)) != 0) {
        fprintf(stderr, "rad compare: %s\n", err);
        return 1;
    }
    if (tool_image_read(pb, &b, err, sizeof(err)) != 0) {
        fprintf(stderr, "rad compare: %s\n", err);
        tool_image_free(&a);
        return 1;
    }
    if (a.width != b.width || a.height != b.height) {
        fprintf(stderr, "rad compare: the images differ in size: %s is %dx%d, %s is %dx%d\n", pa, a.width, a.height,
                pb, b.width, b.height);
        tool_image_free(&a);
        tool_image_free(&b);
        return 1;
    }
    bad = report_nonfinite("A", pa, &a);
    bad |= report_nonfinite("B", pb, &b);
    if (exposure != 1.0f) {
        size_t k, n = (size_t)a.width * (size_t)a.height * 3u;
        for (k = 0; k < n; ++k) a.rgb[k] *= exposure, b.rgb[k] *= exposure;
    }
    mse = tool_image_mse(&a, &b);
    psnr = tool_image_psnr(&a, &b);
    ssim = tool_image_ssim(&a, &b);
    printf("A: %s\nB: %s\nsize: %dx%d\n", pa, pb, a.width, a.height);
    if (exposure != 1.0f)
        printf("values: linear times --exposure %g, clamped to [0,1] (PNG decoded from sRGB); peak L = 1\n", (double)exposure);
    else
        printf("values: linear, clamped to [0,1] (PNG decoded from sRGB); peak L = 1\n");
    printf("MSE:  %.9g\n", mse);
    if (isinf(psnr)) printf("PSNR: inf dB (identical after clamping)\n");
    else printf("PSNR: %.4f dB\n", psnr);
    printf("SSIM: %.8f (11x11 Gaussian window, sigma 1.5, per channel R G B, averaged)\n", ssim);
    {
        /* the light each image holds, before any clamp: the energy check against a path tracer */
        double ma = mean_radiance(&a), mb = mean_radiance(&b);
        printf("mean: %.9g %.9g (linear radiance over RGB, finite values, unclamped)", ma, mb);
        if (mb > 0.0) printf("; A / B = %.6f", ma / mb);
        printf("\n");
    }
    {
        /* the unclamped difference: exact format round trips (PFM against EXR) read 0 here */
        size_t k, n = (size_t)a.width * (size_t)a.height * 3u;
        double top = 0.0;
        for (k = 0; k < n; ++k) {
            double d = fabs((double)a.rgb[k] - (double)b.rgb[k]);
            if (d > top || d != d) top = d;
        }
        printf("max |A-B|: %.9g (linear, before clamping)\n", top);
    }
    if (diff) {
        tool_image heat = { 0, 0, NULL };
        if (!(scale > 0.0f)) {
            size_t k, n = (size_t)a.width * (size_t)a.height;
            double top = 0.0;
            for (k = 0; k < n; ++k) {
                double d = 0.0;
                int c;
                for (c = 0; c < 3; ++c) {
                    double x = a.rgb[3 * k + (size_t)c], y = b.rgb[3 * k + (size_t)c];
                    x = x > 0.0 ? (x < 1.0 ? x : 1.0) : 0.0;
                    y = y > 0.0 ? (y < 1.0 ? y : 1.0) : 0.0;
                    d += fabs(x - y);
                }
                if (d / 3.0 > top) top = d / 3.0;
            }
            scale = top > 0.0 ? (float)top : 1.0f;
        }
        if (tool_image_diff_heatmap(&a, &b, scale, &heat) != 0) {
            fprintf(stderr, "rad compare: out of memory for the difference image '%s'\n", diff);
            tool_image_free(&heat);
            tool_image_free(&a);
            tool_image_free(&b);
            return 1;
        }
        if (tool_image_write(diff, &heat, 1.0f) != 0) {
            fprintf(stderr, "rad compare: the difference image: %s\n", tool_output_error());
            tool_image_free(&heat);
            tool_image_free(&a);
            tool_image_free(&b);
            return 1;
        }
        printf("diff: %s (mean |A-B| over RGB; white = %.6g)\n", diff, (double)scale);
        tool_image_free(&heat);
    }
    if (png) {
        /* a holds A times exposure already */
        if (tool_image_write_png(png, &a, png_exposure > 0.0f ? png_exposure / exposure : 1.0f) != 0) {
            fprintf(stderr, "rad compare: %s\n", tool_output_error());
            tool_image_free(&a);
            tool_image_free(&b);
            return 1;
        }
        printf("png: %s (A, exposure %g)\n", png, (double)(png_exposure > 0.0f ? png_exposure : exposure));
    }
    tool_image_free(&a);
    tool_image_free(&b);
    return bad ? 1 : 0;
}
