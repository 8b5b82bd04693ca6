/* image.c - linear RGB float images for the rad tool: PFM read/write, PNG write (8-bit sRGB,
   through stb_image_write) and PNG read (through stb_image, decoded from sRGB to linear).

   PFM (Portable Float Map): a text header "PF\n<width> <height>\n<scale>\n" followed by
   width*height*3 binary floats, little-endian when scale < 0 (what we write: -1.0), rows stored
   BOTTOM row first. tool_image keeps the top row first, so rows are flipped on the way in and
   out. "Pf" (greyscale) files are read too and replicated to RGB.

   OpenEXR (.exr): through tinyexr (Debian libtinyexr-dev) when the tool is built with
   -DTOOL_EXR (the Makefile and tests/run.sh do when /usr/include/tinyexr.h exists): three
   32-bit float channels B, G, R (the alphabetical order EXR files keep), ZIP compression,
   the top row first as in tool_image; reading takes the R, G, B of any EXR tinyexr loads.
   Without it, .exr paths fail with a message naming the package.

   Every file the tool writes goes through tool_output_open/commit below: the bytes go to a
   temporary file in the destination's folder, which is renamed onto the destination only when
   every write, the flush and the close succeeded, so a failed write (a full disk) leaves the
   old file as it was. */
#if !defined(_WIN32) && !defined(_XOPEN_SOURCE)
#define _XOPEN_SOURCE 700 /* mkstemp, fchmod, fsync, sigaction, realpath */
#endif
#include "tool.h"
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <ctype.h>
#include <signal.h>

#if defined(__unix__) || defined(__APPLE__)
#include <sys/stat.h>
#include <unistd.h>
#define TOOL_POSIX 1
#endif

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
#define STBI_ONLY_HDR
#include <stb/stb_image.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

/* ---- safe output ---------------------------------------------------------------------- */

static char g_output_error[1024];

const char *tool_output_error(void)
{
    return g_output_error[0] ? g_output_error : "unknown error";
}

static void output_error(const char *path, const char *what, int errnum)
{
    if (errnum) snprintf(g_output_error, sizeof g_output_error, "%s '%s': %s", what, path, strerror(errnum));
    else snprintf(g_output_error, sizeof g_output_error, "%s '%s'", what, path);
}

/* the folder part of path ("." when none) into buf */
static void output_folder(const char *path, char *buf, size_t cap)
{
    const char *slash = strrchr(path, '/');
    size_t n;
    if (!slash) {
        snprintf(buf, cap, ".");
        return;
    }
    n = (size_t)(slash - path);
    if (n == 0) n = 1; /* "/x" */
    if (n >= cap) n = cap - 1;
    memcpy(buf, path, n);
    buf[n] = '\0';
}

#ifdef TOOL_POSIX
/* path with its folder resolved (realpath of the folder, then the last name), malloc'd, or
   NULL when the folder does not resolve */
static char *output_resolved(const char *path)
{
    char folder[4096], *rf, *out;
    const char *base = strrchr(path, '/');
    size_t n;
    base = base ? base + 1 : path;
    output_folder(path, folder, sizeof folder);
    if (!(rf = realpath(folder, NULL))) return NULL;
    n = strlen(rf) + strlen(base) + 2;
    out = (char *)malloc(n);
    if (out) snprintf(out, n, "%s/%s", rf, base);
    free(rf);
    return out;
}
#endif

/* ---- temporaries removed on a fatal signal ---------------------------------------------- */
/* The temporaries now open, copied into fixed slots so that the handler touches no heap and
   no lock (unlink and raise are async-signal-safe); a slot is filled before it is marked in
   use and marked free before it is reused. */
#define OUTPUT_SLOTS 64
#define OUTPUT_SLOT_PATH 4096
static char g_slot_path[OUTPUT_SLOTS][OUTPUT_SLOT_PATH];
static volatile sig_atomic_t g_slot_used[OUTPUT_SLOTS];

#ifdef TOOL_POSIX
static void output_on_signal(int sig)
{
    int i;
    for (i = 0; i < OUTPUT_SLOTS; ++i)
        if (g_slot_used[i]) (void)unlink(g_slot_path[i]);
    /* the handler was installed with SA_RESETHAND: the default action ends the process as
       the signal would have */
    (void)raise(sig);
}

static void output_install_handlers(void)
{
    static int done;
    static const int sigs[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGXFSZ, SIGPIPE};
    size_t i;
    if (done) return;
    done = 1;
    for (i = 0; i < sizeof sigs / sizeof sigs[0]; ++i) {
        struct sigaction sa, old;
        /* a signal the caller ignores stays ignored (a shell's background job ignores SIGINT;
           'trap "" XFSZ' turns a file-size limit into EFBIG, which the writers report) */
        if (sigaction(sigs[i], NULL, &old) != 0 || old.sa_handler == SIG_IGN) continue;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = output_on_signal;
        sigemptyset(&sa.sa_mask);
        sa.sa_flags = (int)SA_RESETHAND;
        (void)sigaction(sigs[i], &sa, NULL);
    }
}
#endif

static int output_register(const char *tmp)
{
    int i;
    if (strlen(tmp) >= OUTPUT_SLOT_PATH) return -1;
    for (i = 0; i < OUTPUT_SLOTS; ++i)
        if (!g_slot_used[i]) {
            strcpy(g_slot_path[i], tmp);
            g_slot_used[i] = 1;
            return i;
        }
    return -1;
}

static void output_unregister(tool_output *o)
{
    if (o->slot > 0) g_slot_used[o->slot - 1] = 0;
    o->slot = 0;
}

int tool_output_open(tool_output *o, const char *path)
{
    size_t n;
    memset(o, 0, sizeof *o);
    g_output_error[0] = '\0';
    if (!path || !*path) {
        output_error("", "no output file given:", 0);
        return -1;
    }
    n = strlen(path);
    if (path[n - 1] == '/') {
        output_error(path, "cannot write", EISDIR);
        return -1;
    }
    o->path = (char *)malloc(n + 1);
    o->tmp = (char *)malloc(n + 32);
    if (!o->path || !o->tmp) {
        free(o->path), free(o->tmp);
        memset(o, 0, sizeof *o);
        output_error(path, "cannot write", ENOMEM);
        return -1;
    }
    memcpy(o->path, path, n + 1);
#ifdef TOOL_POSIX
    {
        /* "DIR/.radtmp-XXXXXX": the same folder, so the rename cannot cross file systems, and a
           short fixed name, so that any destination name the file system takes works.
           mkstemp creates it with O_EXCL: a symlink or file already there is never followed. */
        const char *slash = strrchr(path, '/');
        size_t dl = slash ? (size_t)(slash - path + 1) : 0;
        int fd, slot;
        mode_t mask;
        struct stat st;
        output_install_handlers();
        if (stat(path, &st) == 0 && S_ISDIR(st.st_mode)) {
            output_error(path, "cannot write", EISDIR);
            tool_output_abort(o);
            return -1;
        }
        memcpy(o->tmp, path, dl);
        snprintf(o->tmp + dl, n + 32 - dl, ".radtmp-XXXXXX");
        fd = mkstemp(o->tmp);
        if (fd < 0) {
            char folder[4096];
            int e = errno;
            output_folder(path, folder, sizeof folder);
            snprintf(g_output_error, sizeof g_output_error, "cannot write '%.400s': cannot create a file in '%.400s': %s", path,
                     folder, strerror(e));
            o->tmp[0] = '\0';
            tool_output_abort(o);
            return -1;
        }
        slot = output_register(o->tmp);
        o->slot = slot + 1;
        /* mkstemp makes the file 0600: give it the old file's mode, or the one a plain fopen
           would (0666 & ~umask) */
        if (stat(path, &st) == 0) {
            (void)fchmod(fd, st.st_mode & 07777);
        } else {
            mask = umask(0);
            umask(mask);
            (void)fchmod(fd, (mode_t)(0666 & ~mask));
        }
        o->f = fdopen(fd, "wb");
        if (!o->f) {
            int e = errno;
            close(fd);
            output_error(path, "cannot write", e);
            tool_output_abort(o);
            return -1;
        }
    }
#else
    snprintf(o->tmp, n + 32, "%s.tmp", path);
    o->f = fopen(o->tmp, "wb");
    if (!o->f) {
        output_error(o->tmp, "cannot create", errno);
        o->tmp[0] = '\0';
        tool_output_abort(o);
        return -1;
    }
    o->slot = output_register(o->tmp) + 1;
#endif
    return 0;
}

void tool_output_abort(tool_output *o)
{
    if (o->f) fclose(o->f);
    if (o->tmp && o->tmp[0]) remove(o->tmp);
    output_unregister(o);
    free(o->tmp);
    free(o->path);
    memset(o, 0, sizeof *o);
}

int tool_output_close(tool_output *o, int ok)
{
    int e = 0;
    if (!o->f) {
        if (!o->closed) {
            tool_output_abort(o);
            return -1;
        }
        return 0;
    }
    if (!ok || ferror(o->f)) {
        if (!g_output_error[0]) {
            /* a failed fprintf keeps no errno: flushing what is left asks the system again
               (ENOSPC, EFBIG, EIO) */
            clearerr(o->f);
            errno = 0;
            e = fflush(o->f) != 0 && errno ? errno : EIO;
            output_error(o->path, "error writing", e);
        }
        tool_output_abort(o);
        return -1;
    }
    errno = 0;
    if (fflush(o->f) != 0) e = errno ? errno : EIO;
#ifdef TOOL_POSIX
    if (!e && fsync(fileno(o->f)) != 0 && errno != EINVAL && errno != EROFS) e = errno; /* the bytes are on disk before the rename */
#endif
    if (fclose(o->f) != 0 && !e) e = errno ? errno : EIO;
    o->f = NULL;
    if (e) {
        output_error(o->path, "error writing", e);
        tool_output_abort(o);
        return -1;
    }
    o->closed = 1;
    return 0;
}

/* the closed temporary onto its destination; 0 or -1 (the temporary removed) */
static int output_rename(tool_output *o)
{
#ifndef TOOL_POSIX
    remove(o->path); /* rename does not replace a file on every system */
#endif
    if (rename(o->tmp, o->path) != 0) {
        output_error(o->path, "cannot replace", errno);
        tool_output_abort(o);
        return -1;
    }
    o->tmp[0] = '\0'; /* it is the destination now */
    tool_output_abort(o);
    return 0;
}

int tool_output_commit(tool_output *o, int ok)
{
    if (tool_output_close(o, ok) != 0) return -1;
    return output_rename(o);
}

void tool_output_set_abort(tool_output_set *set)
{
    unsigned i;
    for (i = 0; i < set->count; ++i) tool_output_abort(&set->items[i]);
    set->count = 0;
}

int tool_output_set_add(tool_output_set *set, tool_output *o, int ok)
{
    if (set->count >= TOOL_OUTPUT_SET_MAX) {
        output_error(o->path ? o->path : "", "too many files in one set to write", 0);
        tool_output_abort(o);
        tool_output_set_abort(set);
        return -1;
    }
    if (tool_output_close(o, ok) != 0) {
        tool_output_set_abort(set);
        return -1;
    }
    set->items[set->count++] = *o;
    memset(o, 0, sizeof *o);
    return 0;
}

int tool_output_set_commit(tool_output_set *set)
{
    unsigned i;
    int rc = 0;
    /* every temporary is complete and on disk: only renames are left, which within one folder
       fail only when the folder changed under us */
    for (i = 0; i < set->count; ++i) {
        if (rc != 0) {
            tool_output_abort(&set->items[i]);
            continue;
        }
        if (output_rename(&set->items[i]) != 0) rc = -1;
    }
    set->count = 0;
    return rc;
}

int tool_write_file(const char *path, const void *data, size_t size)
{
    tool_output o;
    int ok;
    if (tool_output_open(&o, path) != 0) return -1;
    ok = fwrite(data, 1, size, o.f) == size;
    if (!ok) output_error(path, "error writing", errno ? errno : EIO);
    return tool_output_commit(&o, ok);
}

int tool_check_output(const char *cmd, const char *path, const char *const *inputs, int input_count)
{
#ifdef TOOL_POSIX
    struct stat so, si;
    char folder[4096];
    int i;
    if (!path || !*path) return 0;
    if (stat(path, &so) == 0) {
        if (S_ISDIR(so.st_mode)) {
            fprintf(stderr, "rad %s: the output '%s' is a directory\n", cmd, path);
            return 1;
        }
        for (i = 0; i < input_count; ++i)
            if (inputs[i] && stat(inputs[i], &si) == 0 && si.st_dev == so.st_dev && si.st_ino == so.st_ino) {
                fprintf(stderr, "rad %s: the output '%s' is the input '%s': refusing to overwrite it\n", cmd, path,
                        inputs[i]);
                return 1;
            }
    }
    output_folder(path, folder, sizeof folder);
    if (stat(folder, &si) != 0 || !S_ISDIR(si.st_mode)) {
        fprintf(stderr, "rad %s: cannot write '%s': the folder '%s' does not exist\n", cmd, path, folder);
        return 1;
    }
    if (access(folder, W_OK | X_OK) != 0) {
        fprintf(stderr, "rad %s: cannot write '%s': folder '%s': %s\n", cmd, path, folder, strerror(errno));
        return 1;
    }
#else
    int i;
    for (i = 0; i < input_count; ++i)
        if (inputs[i] && path && !strcmp(inputs[i], path)) {
            fprintf(stderr, "rad %s: the output '%s' is the input: refusing to overwrite it\n", cmd, path);
            return 1;
        }
#endif
    return 0;
}

/* 1 when a and b name the same file: the same device and inode where both exist, else the
   same resolved path (the real folder and the last name), so that "x.png" and "./x.png" or a
   link to the folder count as one file before either exists */
static int output_same_file(const char *a, const char *b)
{
#ifdef TOOL_POSIX
    struct stat sa, sb;
    int ea = stat(a, &sa) == 0, eb = stat(b, &sb) == 0, same = 0;
    char *ra, *rb;
    if (ea && eb) return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
    if (ea != eb) return 0;
    ra = output_resolved(a);
    rb = output_resolved(b);
    same = ra && rb && !strcmp(ra, rb);
    free(ra);
    free(rb);
    return same;
#else
    return !strcmp(a, b);
#endif
}

int tool_check_outputs(const char *cmd, const char *const *outputs, int count, const char *const *inputs, int input_count)
{
    int i, j;
    for (i = 0; i < count; ++i) {
        if (!outputs[i]) continue;
        for (j = i + 1; j < count; ++j)
            if (outputs[j] && output_same_file(outputs[i], outputs[j])) {
                fprintf(stderr, "rad %s: two outputs are the same file ('%s' and '%s'): give each its own name\n", cmd,
                        outputs[i], outputs[j]);
                return 1;
            }
        for (j = 0; j < input_count; ++j)
            if (inputs[j] && output_same_file(outputs[i], inputs[j])) {
                fprintf(stderr, "rad %s: the output '%s' is the input '%s' (a file the scene is read from): refusing to overwrite it\n",
                        cmd, outputs[i], inputs[j]);
                return 1;
            }
    }
    return 0;
}

int tool_image_alloc(tool_image *img, int width, int height)
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

void tool_image_free(tool_image *img)
{
    if (!img) return;
    free(img->rgb);
    img->rgb = NULL;
    img->width = img->height = 0;
}

static int tool__host_little_endian(void)
{
    const uint32_t one = 1u;
    unsigned char b;
    memcpy(&b, &one, 1);
    return b == 1;
}

static void tool__swap4(unsigned char *p)
{
    unsigned char t = p[0];
    p[0] = p[3];
    p[3] = t;
    t = p[1];
    p[1] = p[2];
    p[2] = t;
}

/* an image writer's temporary: renamed now (set NULL) or kept in the set */
static int output_finish(tool_output *o, int ok, tool_output_set *set)
{
    return set ? tool_output_set_add(set, o, ok) : tool_output_commit(o, ok);
}

static int write_pfm(const char *path, const tool_image *img, tool_output_set *set)
{
    tool_output o;
    int y, ok = 1;
    size_t row = 0;
    unsigned char *buf = NULL;
    g_output_error[0] = '\0';
    if (!path || !img || !img->rgb || img->width <= 0 || img->height <= 0) {
        output_error(path ? path : "", "no image to write to", 0);
        return -1;
    }
    if (tool_output_open(&o, path) != 0) return -1;
    if (fprintf(o.f, "PF\n%d %d\n-1.0\n", img->width, img->height) < 0) ok = 0;
    row = (size_t)img->width * 3u * sizeof(float);
    if (ok && !tool__host_little_endian()) {
        buf = (unsigned char *)malloc(row);
        if (!buf) ok = 0;
    }
    for (y = img->height - 1; ok && y >= 0; --y) {
        const float *src = img->rgb + (size_t)y * (size_t)img->width * 3u;
        if (buf) {
            size_t k;
            memcpy(buf, src, row);
            for (k = 0; k < row; k += 4) tool__swap4(buf + k);
            if (fwrite(buf, 1, row, o.f) != row) ok = 0;
        } else if (fwrite(src, 1, row, o.f) != row) {
            ok = 0;
        }
    }
    if (!ok) output_error(path, "error writing", errno ? errno : EIO);
    free(buf);
    return output_finish(&o, ok, set);
}

int tool_image_write_pfm(const char *path, const tool_image *img) { return write_pfm(path, img, NULL); }

/* reads one whitespace-separated header token (skipping '#' comments); 0 on success */
static int tool__pfm_token(FILE *f, char *tok, size_t cap)
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

/* a PFM width or height: decimal digits only, 1 to 2^30 (a larger one cannot be an image the
   tool holds; converting it to int would wrap, 4294967312 to 16); 0 when not */
static int pfm_size(const char *tok)
{
    long long v = 0;
    if (!*tok) return 0;
    for (; *tok; ++tok) {
        if (*tok < '0' || *tok > '9') return 0;
        v = 10 * v + (*tok - '0');
        if (v > (1LL << 30)) return 0;
    }
    return (int)v;
}

int tool_image_read_pfm(const char *path, tool_image *img, char *err, size_t errlen)
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
    if (tool__pfm_token(f, tok, sizeof(tok)) != 0 || (strcmp(tok, "PF") != 0 && strcmp(tok, "Pf") != 0)) {
        if (err) snprintf(err, errlen, "%s: not a PFM file (no 'PF' or 'Pf' magic)", path);
        fclose(f);
        return -1;
    }
    channels = tok[1] == 'F' ? 3 : 1;
    if (tool__pfm_token(f, tok, sizeof(tok)) != 0 || (w = pfm_size(tok)) <= 0 ||
        tool__pfm_token(f, tok, sizeof(tok)) != 0 || (h = pfm_size(tok)) <= 0 ||
        tool__pfm_token(f, tok, sizeof(tok)) != 0 || ((scale = strtod(tok, &end)), *end) || scale == 0.0 ||
        !(scale == scale)) {
        if (err) snprintf(err, errlen, "%s: bad PFM header", path);
        fclose(f);
        return -1;
    }
    swap = (scale < 0.0) != tool__host_little_endian();
    if ((double)w * (double)h * 3.0 * sizeof(float) > TOOL_MAX_IMAGE_BYTES) {
        if (err)
            snprintf(err, errlen, "%s: a %dx%d image needs %.0f bytes, more than the limit of %.0f", path, w, h,
                     (double)w * (double)h * 3.0 * sizeof(float), TOOL_MAX_IMAGE_BYTES);
        fclose(f);
        return -1;
    }
    if (tool_image_alloc(img, w, h) != 0) {
        if (err) snprintf(err, errlen, "%s: %dx%d image: out of memory", path, w, h);
        fclose(f);
        return -1;
    }
    row = (float *)malloc((size_t)w * (size_t)channels * sizeof(float));
    if (!row) {
        if (err) snprintf(err, errlen, "%s: out of memory", path);
        tool_image_free(img);
        fclose(f);
        return -1;
    }
    for (y = h - 1; y >= 0; --y) {
        float *dst = img->rgb + (size_t)y * (size_t)w * 3u;
        size_t count = (size_t)w * (size_t)channels;
        if (fread(row, sizeof(float), count, f) != count) {
            if (err) snprintf(err, errlen, "%s: truncated PFM data", path);
            free(row);
            tool_image_free(img);
            fclose(f);
            return -1;
        }
        if (swap) {
            size_t k;
            for (k = 0; k < count; ++k) tool__swap4((unsigned char *)(row + k));
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
static double tool__srgb_encode(double v)
{
    if (!(v > 0.0)) return 0.0;
    if (v >= 1.0) return 1.0;
    return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

static double tool__srgb_decode(double v)
{
    return v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4);
}

unsigned char tool_image_srgb8(float linear)
{
    return (unsigned char)(tool__srgb_encode((double)linear) * 255.0 + 0.5);
}

/* stb_image_write's sink: every chunk to the temporary file, failures remembered */
typedef struct png_sink {
    FILE *f;
    int ok;
    int errnum;
} png_sink;

static void png_sink_write(void *user, void *data, int size)
{
    png_sink *s = (png_sink *)user;
    if (!s->ok || size <= 0) return;
    if (fwrite(data, 1, (size_t)size, s->f) != (size_t)size) {
        s->ok = 0;
        s->errnum = errno ? errno : EIO;
    }
}

static int write_png(const char *path, const tool_image *img, float exposure, tool_output_set *set)
{
    unsigned char *px;
    size_t i, n;
    tool_output o;
    png_sink sink;
    g_output_error[0] = '\0';
    if (!path || !img || !img->rgb || img->width <= 0 || img->height <= 0) {
        output_error(path ? path : "", "no image to write to", 0);
        return -1;
    }
    n = (size_t)img->width * (size_t)img->height * 3u;
    px = (unsigned char *)malloc(n);
    if (!px) {
        output_error(path, "cannot write", ENOMEM);
        return -1;
    }
    for (i = 0; i < n; ++i) px[i] = tool_image_srgb8(img->rgb[i] * exposure);
    if (tool_output_open(&o, path) != 0) {
        free(px);
        return -1;
    }
    /* stbi_write_png ignores fwrite's result (a full disk gave "wrote x.png", exit 0 and a
       truncated file): encode through the callback, which checks every write */
    sink.f = o.f;
    sink.ok = 1;
    sink.errnum = 0;
    if (!stbi_write_png_to_func(png_sink_write, &sink, img->width, img->height, 3, px, img->width * 3)) {
        if (sink.ok) output_error(path, "cannot encode the PNG", ENOMEM);
        sink.ok = 0;
    } else if (!sink.ok) {
        output_error(path, "error writing", sink.errnum);
    }
    free(px);
    return output_finish(&o, sink.ok, set);
}

int tool_image_write_png(const char *path, const tool_image *img, float exposure) { return write_png(path, img, exposure, NULL); }

int tool_image_read_png(const char *path, tool_image *img, char *err, size_t errlen)
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
    if (tool_image_alloc(img, w, h) != 0) {
        if (err) snprintf(err, errlen, "%s: out of memory", path);
        stbi_image_free(px);
        return -1;
    }
    for (x = 0; x < 256; ++x) table[x] = (float)tool__srgb_decode((double)x / 255.0);
    for (y = 0; y < h; ++y)
        for (x = 0; x < 3 * w; ++x) img->rgb[(size_t)y * (size_t)w * 3u + (size_t)x] = table[px[(size_t)y * (size_t)w * 3u + (size_t)x]];
    stbi_image_free(px);
    return 0;
}

int tool_image_read_hdr(const char *path, tool_image *img, char *err, size_t errlen)
{
    int w, h, comp;
    float *px;
    if (err && errlen) err[0] = '\0';
    if (!path || !img) return -1;
    img->width = img->height = 0;
    img->rgb = NULL;
    if (!stbi_is_hdr(path)) {
        if (err) snprintf(err, errlen, "%s: not a Radiance .hdr file (%s)", path,
                          stbi_failure_reason() ? stbi_failure_reason() : "stb_image does not see an HDR header");
        return -1;
    }
    px = stbi_loadf(path, &w, &h, &comp, 3);
    if (!px) {
        if (err) snprintf(err, errlen, "%s: cannot read HDR (%s)", path, stbi_failure_reason());
        return -1;
    }
    if (tool_image_alloc(img, w, h) != 0) {
        if (err) snprintf(err, errlen, "%s: out of memory", path);
        stbi_image_free(px);
        return -1;
    }
    memcpy(img->rgb, px, sizeof(float) * 3u * (size_t)w * (size_t)h);
    stbi_image_free(px);
    return 0;
}

static int tool__has_ext(const char *path, const char *ext)
{
    size_t n = strlen(path), m = strlen(ext), i;
    if (n < m) return 0;
    for (i = 0; i < m; ++i)
        if (tolower((unsigned char)path[n - m + i]) != tolower((unsigned char)ext[i])) return 0;
    return 1;
}

#ifdef TOOL_EXR
#include <tinyexr.h>

static int write_exr(const char *path, const tool_image *img, tool_output_set *set)
{
    EXRHeader hd;
    EXRImage im;
    EXRChannelInfo ch[3];
    int types[3], req[3], c, ok;
    float *planes[3] = { NULL, NULL, NULL };
    unsigned char *mem = NULL;
    const char *err = NULL;
    size_t n, k, size;
    tool_output o;
    g_output_error[0] = '\0';
    if (!path || !img || !img->rgb || img->width <= 0 || img->height <= 0) {
        output_error(path ? path : "", "no image to write to", 0);
        return -1;
    }
    n = (size_t)img->width * (size_t)img->height;
    for (c = 0; c < 3; ++c) {
        planes[c] = (float *)malloc(n * sizeof(float));
        if (!planes[c]) {
            while (c-- > 0) free(planes[c]);
            output_error(path, "out of memory for", ENOMEM);
            return -1;
        }
    }
    for (k = 0; k < n; ++k) { /* B, G, R planes */
        planes[0][k] = img->rgb[3 * k + 2];
        planes[1][k] = img->rgb[3 * k + 1];
        planes[2][k] = img->rgb[3 * k];
    }
    InitEXRHeader(&hd);
    InitEXRImage(&im);
    memset(ch, 0, sizeof(ch));
    ch[0].name[0] = 'B';
    ch[1].name[0] = 'G';
    ch[2].name[0] = 'R';
    for (c = 0; c < 3; ++c) types[c] = req[c] = TINYEXR_PIXELTYPE_FLOAT;
    hd.num_channels = 3;
    hd.channels = ch;
    hd.pixel_types = types;
    hd.requested_pixel_types = req;
    hd.compression_type = TINYEXR_COMPRESSIONTYPE_ZIP;
    im.num_channels = 3;
    im.width = img->width;
    im.height = img->height;
    im.images = (unsigned char **)planes;
    size = SaveEXRImageToMemory(&im, &hd, &mem, &err);
    for (c = 0; c < 3; ++c) free(planes[c]);
    if (size == 0 || !mem) {
        snprintf(g_output_error, sizeof(g_output_error), "cannot encode the EXR '%s': %s", path, err ? err : "tinyexr failed");
        if (err) FreeEXRErrorMessage(err);
        free(mem);
        return -1;
    }
    if (tool_output_open(&o, path) != 0) { free(mem); return -1; }
    ok = fwrite(mem, 1, size, o.f) == size;
    if (!ok) output_error(path, "error writing", errno ? errno : EIO);
    free(mem);
    return output_finish(&o, ok, set);
}

int tool_image_write_exr(const char *path, const tool_image *img) { return write_exr(path, img, NULL); }

int tool_image_read_exr(const char *path, tool_image *img, char *err, size_t errlen)
{
    float *rgba = NULL;
    int w = 0, h = 0;
    const char *msg = NULL;
    size_t k, n;
    if (err && errlen) err[0] = '\0';
    if (!path || !img) return -1;
    img->width = img->height = 0;
    img->rgb = NULL;
    if (LoadEXR(&rgba, &w, &h, path, &msg) != TINYEXR_SUCCESS) {
        if (err) snprintf(err, errlen, "%s: cannot read EXR (%s)", path, msg ? msg : "tinyexr failed");
        if (msg) FreeEXRErrorMessage(msg);
        free(rgba);
        return -1;
    }
    if (tool_image_alloc(img, w, h) != 0) {
        if (err) snprintf(err, errlen, "%s: out of memory", path);
        free(rgba);
        return -1;
    }
    n = (size_t)w * (size_t)h;
    for (k = 0; k < n; ++k) {
        img->rgb[3 * k] = rgba[4 * k];
        img->rgb[3 * k + 1] = rgba[4 * k + 1];
        img->rgb[3 * k + 2] = rgba[4 * k + 2];
    }
    free(rgba);
    return 0;
}
#else
static int write_exr(const char *path, const tool_image *img, tool_output_set *set)
{
    (void)img;
    (void)set;
    output_error(path ? path : "", "cannot write OpenEXR (this rad was built without tinyexr: install libtinyexr-dev "
                 "and rebuild) to", 0);
    return -1;
}

int tool_image_write_exr(const char *path, const tool_image *img) { return write_exr(path, img, NULL); }

int tool_image_read_exr(const char *path, tool_image *img, char *err, size_t errlen)
{
    if (img) { img->width = img->height = 0; img->rgb = NULL; }
    if (err) snprintf(err, errlen, "%s: cannot read OpenEXR: this rad was built without tinyexr (install libtinyexr-dev and rebuild)",
                      path ? path : "");
    return -1;
}
#endif

int tool_image_write_into(tool_output_set *set, const char *path, const tool_image *img, float exposure)
{
    int rc = -1;
    g_output_error[0] = '\0';
    /* PFM holds the radiance itself: exposure applies to the 8-bit PNG only */
    if (!path) output_error("", "no output file given:", 0);
    else if (tool__has_ext(path, ".pfm")) rc = write_pfm(path, img, set);
    else if (tool__has_ext(path, ".png")) rc = write_png(path, img, exposure, set);
    else if (tool__has_ext(path, ".exr")) rc = write_exr(path, img, set);
    else output_error(path, "cannot write (want a .png, .pfm or .exr name)", 0);
    if (rc != 0 && set) tool_output_set_abort(set);
    return rc;
}

int tool_image_write(const char *path, const tool_image *img, float exposure)
{
    return tool_image_write_into(NULL, path, img, exposure);
}

int tool_image_check_format(const char *cmd, const char *path)
{
    if (!path || !(tool__has_ext(path, ".pfm") || tool__has_ext(path, ".png") || tool__has_ext(path, ".exr"))) {
        fprintf(stderr, "rad %s: output '%s' must end in .png, .pfm or .exr\n", cmd, path ? path : "");
        return 2;
    }
#ifndef TOOL_EXR
    if (tool__has_ext(path, ".exr")) {
        fprintf(stderr, "rad %s: cannot write '%s': this rad was built without OpenEXR support (install libtinyexr-dev "
                "and rebuild; the Makefile detects it)\n", cmd, path);
        return 2;
    }
#endif
    return 0;
}

int tool_image_read(const char *path, tool_image *img, char *err, size_t errlen)
{
    if (path && tool__has_ext(path, ".png")) return tool_image_read_png(path, img, err, errlen);
    if (path && tool__has_ext(path, ".exr")) return tool_image_read_exr(path, img, err, errlen);
    return tool_image_read_pfm(path, img, err, errlen);
}
