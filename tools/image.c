/* image.c - linear RGB float images for the rad tool: PFM read/write, PNG write (8-bit sRGB,
   through stb_image_write) and PNG read (through stb_image, decoded from sRGB to linear).

   PFM (Portable Float Map): a text header "PF\n<width> <height>\n<scale>\n" followed by
   width*height*3 binary floats, little-endian when scale < 0 (what we write: -1.0), rows stored
   BOTTOM row first. rad_image keeps the top row first, so rows are flipped on the way in and
   out. "Pf" (greyscale) files are read too and replicated to RGB. */
#include "tool.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <ctype.h>

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#pragma GCC diagnostic ignored "-Wtype-limits"
#pragma GCC diagnostic ignored "-Wdouble-promotion"
#pragma GCC diagnostic ignored "-Wconversion"
#endif
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#include <stb/stb_image.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

int rad_image_alloc(rad_image *img, int width, int height)
{
    size_t n;
    if (!img) return -1;
    img->width = img->height = 0;
    img->rgb = NULL;
    if (width <= 0 || height <= 0) return -1;
    if ((size_t)width > ((size_t)-1) / 3u / sizeof(float) / (size_t)height) return -1;
    n = (size_t)width * (size_t)height * 3u;
    img->rgb = (float *)calloc(n, sizeof(float));
    if (!img->rgb) return -1;
    img->width = width;
    img->height = height;
    return 0;
}

void rad_image_free(rad_image *img)
{
    if (!img) return;
    free(img->rgb);
    img->rgb = NULL;
    img->width = img->height = 0;
}

static int rad__host_little_endian(void)
{
    const uint32_t one = 1u;
    unsigned char b;
    memcpy(&b, &one, 1);
    return b == 1;
}

static void rad__swap4(unsigned char *p)
{
    unsigned char t = p[0];
    p[0] = p[3];
    p[3] = t;
    t = p[1];
    p[1] = p[2];
    p[2] = t;
}

int rad_image_write_pfm(const char *path, const rad_image *img)
{
    FILE *f;
    int y, ok = 1;
    size_t row = 0;
    unsigned char *buf = NULL;
    if (!path || !img || !img->rgb || img->width <= 0 || img->height <= 0) return -1;
    f = fopen(path, "wb");
    if (!f) return -1;
    if (fprintf(f, "PF\n%d %d\n-1.0\n", img->width, img->height) < 0) ok = 0;
    row = (size_t)img->width * 3u * sizeof(float);
    if (ok && !rad__host_little_endian()) {
        buf = (unsigned char *)malloc(row);
        if (!buf) ok = 0;
    }
    for (y = img->height - 1; ok && y >= 0; --y) {
        const float *src = img->rgb + (size_t)y * (size_t)img->width * 3u;
        if (buf) {
            size_t k;
            memcpy(buf, src, row);
            for (k = 0; k < row; k += 4) rad__swap4(buf + k);
            if (fwrite(buf, 1, row, f) != row) ok = 0;
        } else if (fwrite(src, 1, row, f) != row) {
            ok = 0;
        }
    }
    free(buf);
    if (fclose(f) != 0) ok = 0;
    return ok ? 0 : -1;
}

/* reads one whitespace-separated header token (skipping '#' comments); 0 on success */
static int rad__pfm_token(FILE *f, char *tok, size_t cap)
{
    int c;
    size_t n = 0;
    for (;;) {
        c = fgetc(f);
        if (c == EOF) return -1;
        if (c == '#') {
            while (c != '\n' && c != EOF) c = fgetc(f);
            continue;
        }
        if (!isspace(c)) break;
    }
    while (c != EOF && !isspace(c)) {
        if (n + 1 >= cap) return -1;
        tok[n++] = (char)c;
        c = fgetc(f);
    }
    tok[n] = '\0';
    /* c is the single whitespace byte that ends the token (the last one precedes the data) */
    return 0;
}

int rad_image_read_pfm(const char *path, rad_image *img, char *err, size_t errlen)
{
    FILE *f;
    char tok[64];
    int channels, w, h, y, x, swap;
    double scale;
    char *end;
    float *row = NULL;
    if (err && errlen) err[0] = '\0';
    if (!path || !img) return -1;
    img->width = img->height = 0;
    img->rgb = NULL;
    f = fopen(path, "rb");
    if (!f) {
        if (err) snprintf(err, errlen, "%s: cannot open", path);
        return -1;
    }
    if (rad__pfm_token(f, tok, sizeof(tok)) != 0 || (strcmp(tok, "PF") != 0 && strcmp(tok, "Pf") != 0)) {
        if (err) snprintf(err, errlen, "%s: not a PFM file (no 'PF' or 'Pf' magic)", path);
        fclose(f);
        return -1;
    }
    channels = tok[1] == 'F' ? 3 : 1;
    if (rad__pfm_token(f, tok, sizeof(tok)) != 0 || (w = (int)strtol(tok, &end, 10)) <= 0 || *end ||
        rad__pfm_token(f, tok, sizeof(tok)) != 0 || (h = (int)strtol(tok, &end, 10)) <= 0 || *end ||
        rad__pfm_token(f, tok, sizeof(tok)) != 0 || ((scale = strtod(tok, &end)), *end) || scale == 0.0 ||
        !(scale == scale)) {
        if (err) snprintf(err, errlen, "%s: bad PFM header", path);
        fclose(f);
        return -1;
    }
    swap = (scale < 0.0) != rad__host_little_endian();
    if (rad_image_alloc(img, w, h) != 0) {
        if (err) snprintf(err, errlen, "%s: %dx%d image: out of memory", path, w, h);
        fclose(f);
        return -1;
    }
    row = (float *)malloc((size_t)w * (size_t)channels * sizeof(float));
    if (!row) {
        if (err) snprintf(err, errlen, "%s: out of memory", path);
        rad_image_free(img);
        fclose(f);
        return -1;
    }
    for (y = h - 1; y >= 0; --y) {
        float *dst = img->rgb + (size_t)y * (size_t)w * 3u;
        size_t count = (size_t)w * (size_t)channels;
        if (fread(row, sizeof(float), count, f) != count) {
            if (err) snprintf(err, errlen, "%s: truncated PFM data", path);
            free(row);
            rad_image_free(img);
            fclose(f);
            return -1;
        }
        if (swap) {
            size_t k;
            for (k = 0; k < count; ++k) rad__swap4((unsigned char *)(row + k));
        }
        for (x = 0; x < w; ++x) {
            if (channels == 3) {
                dst[3 * x] = row[3 * x];
                dst[3 * x + 1] = row[3 * x + 1];
                dst[3 * x + 2] = row[3 * x + 2];
            } else {
                dst[3 * x] = dst[3 * x + 1] = dst[3 * x + 2] = row[x];
            }
        }
    }
    free(row);
    fclose(f);
    return 0;
}

/* linear -> sRGB transfer function (IEC 61966-2-1), input clamped to [0,1] */
static double rad__srgb_encode(double v)
{
    if (!(v > 0.0)) return 0.0;
    if (v >= 1.0) return 1.0;
    return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

static double rad__srgb_decode(double v)
{
    return v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4);
}

unsigned char rad_image_srgb8(float linear)
{
    return (unsigned char)(rad__srgb_encode((double)linear) * 255.0 + 0.5);
}

int rad_image_write_png(const char *path, const rad_image *img, float exposure)
{
    unsigned char *px;
    size_t i, n;
    int ok;
    if (!path || !img || !img->rgb || img->width <= 0 || img->height <= 0) return -1;
    n = (size_t)img->width * (size_t)img->height * 3u;
    px = (unsigned char *)malloc(n);
    if (!px) return -1;
    for (i = 0; i < n; ++i) px[i] = rad_image_srgb8(img->rgb[i] * exposure);
    ok = stbi_write_png(path, img->width, img->height, 3, px, img->width * 3);
    free(px);
    return ok ? 0 : -1;
}

int rad_image_read_png(const char *path, rad_image *img, char *err, size_t errlen)
{
    int w, h, comp, x, y;
    unsigned char *px;
    float table[256];
    if (err && errlen) err[0] = '\0';
    if (!path || !img) return -1;
    img->width = img->height = 0;
    img->rgb = NULL;
    px = stbi_load(path, &w, &h, &comp, 3);
    if (!px) {
        if (err) snprintf(err, errlen, "%s: cannot read PNG (%s)", path, stbi_failure_reason());
        return -1;
    }
    if (rad_image_alloc(img, w, h) != 0) {
        if (err) snprintf(err, errlen, "%s: out of memory", path);
        stbi_image_free(px);
        return -1;
    }
    for (x = 0; x < 256; ++x) table[x] = (float)rad__srgb_decode((double)x / 255.0);
    for (y = 0; y < h; ++y)
        for (x = 0; x < 3 * w; ++x) img->rgb[(size_t)y * (size_t)w * 3u + (size_t)x] = table[px[(size_t)y * (size_t)w * 3u + (size_t)x]];
    stbi_image_free(px);
    return 0;
}

static int rad__has_ext(const char *path, const char *ext)
{
    size_t n = strlen(path), m = strlen(ext), i;
    if (n < m) return 0;
    for (i = 0; i < m; ++i)
        if (tolower((unsigned char)path[n - m + i]) != tolower((unsigned char)ext[i])) return 0;
    return 1;
}

int rad_image_write(const char *path, const rad_image *img, float exposure)
{
    if (!path) return -1;
    /* PFM holds the radiance itself: exposure applies to the 8-bit PNG only */
    if (rad__has_ext(path, ".pfm")) return rad_image_write_pfm(path, img);
    if (rad__has_ext(path, ".png")) return rad_image_write_png(path, img, exposure);
    return -1;
}

int rad_image_read(const char *path, rad_image *img, char *err, size_t errlen)
{
    if (path && rad__has_ext(path, ".png")) return rad_image_read_png(path, img, err, errlen);
    return rad_image_read_pfm(path, img, err, errlen);
}
