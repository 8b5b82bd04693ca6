/* tools/glsl/embed.c - writes the canonical GLSL sources of tools/glsl/ into radiosity.h (the >>api_glsl section).

       embed [--check] [HEADER]      (HEADER defaults to radiosity.h; run from the repository root)

   Two regions of the header are generated, and nothing else is touched:
     between "/" "* >>glsl ids begin *" "/" and "/" "* >>glsl ids end *" "/"   the rad_glsl_id enum
     between "/" "* >>glsl begin *" "/"     and "/" "* >>glsl end *" "/"       the sources, as string
         pieces of at most RAD_PIECE characters (C99 guarantees 4095 per literal), cut at line ends
   --check writes nothing and exits 1 when the header differs from what would be written (the
   test suite runs it, so a header older than its tools/glsl/ files fails the tests).

   A kernel may include a shared piece of tools/glsl/ (`#include "reduce.glsl"`): the header's
   copy holds the piece pasted in place (read_expanded), so users need no includer.
   Adding a kernel is one line in 'kernels' below (ids stay in table order: append at the end so
   the numbers users may have stored do not change). Plain C99, no dependencies: CI machines may
   lack Python. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define RAD_PIECE 4000u

typedef struct kernel { const char *id, *path; } kernel;

static const kernel kernels[] = {
    { "RAD_GLSL_GATHER_DENSE", "tools/glsl/gather_dense.comp" },
    { "RAD_GLSL_GATHER_CSR", "tools/glsl/gather_csr.comp" },
    { "RAD_GLSL_MB_APPLY_FLOAT", "tools/glsl/mb_apply_float.comp" },
    { "RAD_GLSL_MB_APPLY_HALF", "tools/glsl/mb_apply_half.comp" },
    { "RAD_GLSL_TEMPORAL_STEP", "tools/glsl/temporal_step.comp" },
    { "RAD_GLSL_MB_APPLY_BLOCKS", "tools/glsl/mb_apply_blocks.comp" },
    { "RAD_GLSL_ALIAS_BUILD", "tools/glsl/alias_build.comp" },
    { "RAD_GLSL_LIGHTING", "tools/glsl/lighting.glsl" }, /* an include: every lighting model (>>shading) */
    { "RAD_GLSL_LOCAL_APPLY", "tools/glsl/local_apply.comp" },
    { "RAD_GLSL_LOCAL_VECTORS", "tools/glsl/local_vectors.comp" },
    { "RAD_GLSL_LOCAL_UPDATE", "tools/glsl/local_update.comp" },
    { "RAD_GLSL_VP_GATHER", "tools/glsl/vp_gather.comp" },
    { "RAD_GLSL_PROBE_UPDATE", "tools/glsl/probe_update.comp" },
    { "RAD_GLSL_LIGHTMAP_REFRESH", "tools/glsl/lightmap_refresh.comp" },
    { "RAD_GLSL_LAYER_MIX", "tools/glsl/layer_mix.comp" },
    { "RAD_GLSL_LAYER_MIX_RGB9E5", "tools/glsl/layer_mix_rgb9e5.comp" },
};
#define KERNELS (sizeof(kernels) / sizeof(kernels[0]))

typedef struct buf { char *p; size_t n, cap; } buf;

static void put(buf *b, const char *s, size_t n)
{
    if (b->n + n + 1 > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        while (b->n + n + 1 > cap) cap *= 2;
        b->p = (char *)realloc(b->p, cap);
        if (!b->p) { fprintf(stderr, "tools/glsl/embed: out of memory\n"); exit(1); }
        b->cap = cap;
    }
    memcpy(b->p + b->n, s, n);
    b->n += n;
    b->p[b->n] = 0;
}
static void puts_(buf *b, const char *s) { put(b, s, strlen(s)); }

static char *read_all(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    buf b = { NULL, 0, 0 };
    char tmp[65536];
    size_t got;
    if (!f) { fprintf(stderr, "tools/glsl/embed: cannot open '%s'\n", path); exit(1); }
    while ((got = fread(tmp, 1, sizeof(tmp), f)) > 0) put(&b, tmp, got);
    fclose(f);
    if (!b.p) put(&b, "", 0);
    *len = b.n;
    return b.p;
}

/* The source of a kernel as the header holds it: a line `#include "NAME"` is replaced by the
   text of tools/glsl/NAME (one level: the includes are small shared pieces such as reduce.glsl)
   and the `#extension GL_GOOGLE_include_directive` line that allowed it is dropped, so the
   embedded kernels compile without an includer, as shaderc or a driver gets them from memory. */
static char *read_expanded(const char *path, size_t *len)
{
    static const char ext[] = "#extension GL_GOOGLE_include_directive";
    size_t n, at = 0;
    char *src = read_all(path, &n);
    buf out = { NULL, 0, 0 };
    while (at < n) {
        const char *nl = (const char *)memchr(src + at, '\n', n - at);
        size_t ln = nl ? (size_t)(nl - (src + at)) + 1 : n - at;
        const char *line = src + at;
        if (ln >= sizeof(ext) - 1 && !memcmp(line, ext, sizeof(ext) - 1)) {
            /* dropped */
        } else if (ln > 10 && !memcmp(line, "#include \"", 10)) {
            char inc[512];
            const char *q = (const char *)memchr(line + 10, '"', ln - 10), *slash = strrchr(path, '/');
            size_t dir = slash ? (size_t)(slash - path) + 1 : 0, name, ilen;
            char *text;
            if (!q || (name = (size_t)(q - (line + 10))) == 0 || dir + name >= sizeof(inc)) {
                fprintf(stderr, "tools/glsl/embed: a malformed #include in '%s'\n", path);
                exit(1);
            }
            memcpy(inc, path, dir);
            memcpy(inc + dir, line + 10, name);
            inc[dir + name] = 0;
            text = read_all(inc, &ilen);
            if (ilen == 0 || text[ilen - 1] != '\n' || !strncmp(text, "#include", 8) || strstr(text, "\n#include")) {
                fprintf(stderr, "tools/glsl/embed: '%s' (included by '%s') is empty, lacks a final newline or includes again\n", inc, path);
                exit(1);
            }
            put(&out, text, ilen);
            free(text);
        } else {
            put(&out, line, ln);
        }
        at += ln;
    }
    free(src);
    if (!out.p) put(&out, "", 0);
    *len = out.n;
    return out.p;
}

/* the part of 'path' after the last '/' */
static const char *base_name(const char *path)
{
    const char *s = strrchr(path, '/');
    return s ? s + 1 : path;
}

/* C string literal of one line (with its newline) */
static void literal(buf *b, const char *s, size_t n)
{
    size_t i;
    puts_(b, "    \"");
    for (i = 0; i < n; ++i) {
        unsigned char ch = (unsigned char)s[i];
        if (ch == '\\') puts_(b, "\\\\");
        else if (ch == '"') puts_(b, "\\\"");
        else if (ch == '\n') puts_(b, "\\n");
        else if (ch == '\t') puts_(b, "\\t");
        else if (ch == '?') puts_(b, "\\?"); /* no trigraphs */
        else if (ch > 126) { /* UTF-8 in comments: three-digit octal escapes, the same bytes */
            char esc[8];
            sprintf(esc, "\\%03o", (unsigned)ch);
            puts_(b, esc);
        } else if (ch < 32) {
            fprintf(stderr, "tools/glsl/embed: control byte %u in a GLSL source (only newline and tab are allowed)\n", ch);
            exit(1);
        } else put(b, (const char *)&ch, 1);
    }
    puts_(b, "\"\n");
}

static void gen_ids(buf *b)
{
    size_t k;
    char line[256];
    puts_(b, "typedef enum rad_glsl_id {\n");
    for (k = 0; k < KERNELS; ++k) {
        sprintf(line, "    %-26s = %2u, /* %s */\n", kernels[k].id, (unsigned)k, kernels[k].path);
        puts_(b, line);
    }
    sprintf(line, "    RAD_GLSL_COUNT = %u\n} rad_glsl_id;\n", (unsigned)KERNELS);
    puts_(b, line);
}

static void gen_sources(buf *b)
{
    size_t k;
    char line[512];
    unsigned pieces[64];
    size_t lengths[64];
    if (KERNELS > 64) { fprintf(stderr, "tools/glsl/embed: too many kernels\n"); exit(1); }
    for (k = 0; k < KERNELS; ++k) {
        size_t len, at = 0;
        char *src = read_expanded(kernels[k].path, &len);
        unsigned piece = 0;
        if (len == 0 || src[len - 1] != '\n') {
            fprintf(stderr, "tools/glsl/embed: '%s' is empty or does not end with a newline\n", kernels[k].path);
            exit(1);
        }
        lengths[k] = len;
        while (at < len) {
            size_t start = at, n;
            sprintf(line, "static const char rad__glsl_%u_%u[] =\n", (unsigned)k, piece);
            puts_(b, line);
            /* whole lines while they fit */
            while (at < len) {
                const char *nl = (const char *)memchr(src + at, '\n', len - at);
                size_t ln = (size_t)(nl - (src + at)) + 1;
                if (ln > RAD_PIECE) { fprintf(stderr, "tools/glsl/embed: a line of '%s' is too long\n", kernels[k].path); exit(1); }
                if (at - start + ln > RAD_PIECE) break;
                literal(b, src + at, ln);
                at += ln;
            }
            n = at - start;
            (void)n;
            b->n -= 1; /* the last literal's newline */
            puts_(b, ";\n");
            ++piece;
        }
        pieces[k] = piece;
        sprintf(line, "static const char *const rad__glsl_pieces_%u[] = {", (unsigned)k);
        puts_(b, line);
        {
            unsigned p;
            for (p = 0; p < piece; ++p) {
                sprintf(line, "%s rad__glsl_%u_%u", p ? "," : "", (unsigned)k, p);
                puts_(b, line);
            }
        }
        puts_(b, " };\n");
        free(src);
    }
    puts_(b, "static const rad__glsl_entry rad__glsl_table[RAD_GLSL_COUNT] = {\n");
    for (k = 0; k < KERNELS; ++k) {
        sprintf(line, "    { \"%s\", rad__glsl_pieces_%u, %uu, %luu }%s\n", base_name(kernels[k].path), (unsigned)k,
                pieces[k], (unsigned long)lengths[k], k + 1 < KERNELS ? "," : "");
        puts_(b, line);
    }
    puts_(b, "};\n");
}

/* replaces the text between the lines holding 'begin' and 'end' with 'body' */
static int splice(buf *out, const char *text, const char *begin, const char *end, const buf *body, const char *header)
{
    const char *b = strstr(text, begin), *e, *b_eol;
    if (!b || !(e = strstr(b, end)) || strstr(e + 1, begin)) {
        fprintf(stderr, "tools/glsl/embed: '%s' needs exactly one '%s' ... '%s' region\n", header, begin, end);
        return 0;
    }
    b_eol = strchr(b, '\n');
    while (e > text && e[-1] != '\n') --e; /* start of the end marker's line */
    if (!b_eol || b_eol >= e + 1) { fprintf(stderr, "tools/glsl/embed: markers out of order in '%s'\n", header); return 0; }
    put(out, text, (size_t)(b_eol + 1 - text));
    put(out, body->p, body->n);
    puts_(out, e);
    return 1;
}

int main(int argc, char **argv)
{
    const char *header = "radiosity.h";
    int check = 0, i;
    size_t len;
    char *text;
    buf ids = { NULL, 0, 0 }, src = { NULL, 0, 0 }, step = { NULL, 0, 0 }, out = { NULL, 0, 0 };
    for (i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--check")) check = 1;
        else if (argv[i][0] == '-') { fprintf(stderr, "usage: glsl_embed [--check] [HEADER]\n"); return 2; }
        else header = argv[i];
    }
    text = read_all(header, &len);
    gen_ids(&ids);
    gen_sources(&src);
    if (!splice(&step, text, "/* >>glsl ids begin */", "/* >>glsl ids end */", &ids, header)) return 1;
    if (!splice(&out, step.p, "/* >>glsl begin */", "/* >>glsl end */", &src, header)) return 1;
    if (check) {
        if (out.n != len || memcmp(out.p, text, len) != 0) {
            fprintf(stderr, "tools/glsl/embed: %s is out of date with tools/glsl/ (run 'make glsl')\n", header);
            return 1;
        }
        printf("tools/glsl/embed: %s is up to date (%u kernels)\n", header, (unsigned)KERNELS);
        return 0;
    }
    if (out.n != len || memcmp(out.p, text, len) != 0) {
        FILE *f = fopen(header, "wb");
        if (!f || fwrite(out.p, 1, out.n, f) != out.n || fclose(f) != 0) {
            fprintf(stderr, "tools/glsl/embed: cannot write '%s'\n", header);
            return 1;
        }
        printf("tools/glsl/embed: wrote %u kernels into %s\n", (unsigned)KERNELS, header);
    } else {
        printf("tools/glsl/embed: %s already up to date\n", header);
    }
    free(text); free(ids.p); free(src.p); free(step.p); free(out.p);
    return 0;
}
