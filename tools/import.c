/* import.c - scenes for the rad tool: the built-in Cornell box, or any file assimp reads
   (OBJ+MTL, glTF 2.0, FBX, PLY ...).

   Geometry: assimp triangulates; vertices are welded here with a tolerance relative to each
   mesh's size (weld_mesh; assimp's own weld is absolute and broke small scenes); the node graph is walked here
   (instead of aiProcess_PreTransformVertices, which merges meshes of the same material and so
   loses object names), every mesh's vertices are transformed by its node's accumulated
   matrix, and meshes are grouped by name (the mesh's own name, else its node's name) into one
   rad_mesh_desc per name, so `o floor` / `g floor` in an OBJ becomes the mesh "floor" even
   when it uses several materials.
   Materials: albedo = Kd / glTF base colour (times the base-colour texture, sRGB-decoded, when
   there is one and the mesh has uvs: sampled through the albedo callback), clamped into
   [0, 0.999] with a warning; emission = Ke / glTF emissiveFactor x KHR_materials_emissive_strength
   (read from the glTF JSON here: assimp 5.2 drops it), as radiance, times the emission
   texture (map_Ke / emissiveTexture, sRGB-decoded, unclamped) through the emission callback;
   glTF's KHR_texture_transform on either texture is applied to the uvs in the lookup.
   What each material used and what it ignored is kept for `rad info` (material_reports).
   Lights: point, spot and directional lights of the file become rad_light (their node's
   transform applied). Camera: the file's first camera, else a default framing. */
#include "tool.h"
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#endif
#include <assimp/cimport.h>
#include <assimp/scene.h>
#include <assimp/postprocess.h>
#include <assimp/material.h>
#include <assimp/version.h>
#define STB_IMAGE_STATIC /* private copy: image.c has its own */
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
/* stb_image.h with STB_IMAGE_STATIC declares stbi_set_unpremultiply_on_load_thread static and
   never defines it: GCC reports that at the end of the file, outside the push/pop above */
#pragma GCC diagnostic ignored "-Wunused-function"
#endif

#define ALBEDO_MAX 0.999f

typedef struct imp_texture {
    int width, height;
    float *rgb;           /* linear */
    char path[256];
    float *alpha;         /* the alpha channel when the image has one, else its first channel
                             (a grey map_d), both as stored (not sRGB-decoded) */
    int has_alpha;        /* 1 when the image has an alpha channel */
    float alpha_scale;    /* an opacity texture's factor (glTF baseColorFactor alpha), else 1 */
    int has_xf;           /* glTF KHR_texture_transform: uv' = xf (u, v, 1) in glTF's uvs (v down) */
    float xf[6];
} imp_texture;

typedef struct imp_group {
    char *name;
    float *positions;     /* 3 per vertex */
    float *uvs;           /* 2 per vertex, or NULL */
    float *uvs2;          /* the second uv set (the lightmap's: glTF TEXCOORD_1), 2 per vertex */
    uint32_t *indices;
    uint32_t *material_ids;
    uint32_t vertex_count, vertex_cap;
    uint32_t triangle_count, triangle_cap;
    int any_uv;
    int all_uv2;          /* 1 while every mesh added has a second uv set */
    int meshes_added;
} imp_group;

typedef struct imp_storage {
    rad_mesh_desc *meshes;
    imp_group *groups;
    uint32_t group_count, group_cap;
    rad_material *materials;
    char **material_names;
    uint32_t material_count;
    imp_texture *textures;
    uint32_t texture_count;
    char **material_reports;  /* per material: what the import used and ignored (rad info) */
    int any_emission_texture;
    int any_cutout;
    char **inputs;          /* the files read: the scene, its MTL libraries, its textures */
    uint32_t input_count;
    int builtin;
    uint64_t *wound_against;  /* per material: triangles wound against their shading normals */
    uint64_t *wound_total;    /* per material: triangles with shading normals */
} imp_storage;

static void *xrealloc(void *p, size_t size);

/* path to the list of files the scene was read from (once each) */
static void add_input(imp_storage *st, const char *path)
{
    uint32_t i;
    size_t n = strlen(path);
    char **g;
    for (i = 0; i < st->input_count; ++i)
        if (!strcmp(st->inputs[i], path)) return;
    g = (char **)xrealloc(st->inputs, sizeof *g * (st->input_count + 1u));
    st->inputs = g;
    g[st->input_count] = (char *)xrealloc(NULL, n + 1);
    memcpy(g[st->input_count++], path, n + 1);
}

/* the MTL files an OBJ names (mtllib lines), resolved against the OBJ's folder, as inputs */
static void add_obj_mtllibs(imp_storage *st, const char *obj)
{
    FILE *f;
    char line[2048], full[4096];
    size_t n = strlen(obj);
    const char *slash = strrchr(obj, '/');
    int dir = slash ? (int)(slash - obj + 1) : 0;
    if (n < 4 || (strcmp(obj + n - 4, ".obj") && strcmp(obj + n - 4, ".OBJ"))) return;
    if (!(f = fopen(obj, "r"))) return;
    while (fgets(line, sizeof line, f)) {
        char *p = line, *e;
        while (*p == ' ' || *p == '\t') ++p;
        if (strncmp(p, "mtllib", 6) || !(p[6] == ' ' || p[6] == '\t')) continue;
        p += 6;
        while (*p == ' ' || *p == '\t') ++p;
        for (e = p + strlen(p); e > p && isspace((unsigned char)e[-1]); --e) {
        }
        *e = '\0';
        if (!*p) continue;
        if (*p == '/') snprintf(full, sizeof full, "%s", p);
        else snprintf(full, sizeof full, "%.*s%s", dir, obj, p);
        add_input(st, full);
    }
    fclose(f);
}

static void set_err(char *err, size_t errlen, const char *fmt, const char *a, const char *b)
{
    if (err && errlen) snprintf(err, errlen, fmt, a ? a : "", b ? b : "");
}

static float srgb_to_linear(float c)
{
    return c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f);
}

/* a lookup's uv: NaN read as 0, the texture's KHR_texture_transform applied, wrapped into [0, 1) */
static void texture_uv(const imp_texture *t, float *pu, float *pv)
{
    float u = *pu, v = *pv;
    if (!(u == u)) u = 0.0f; /* NaN */
    if (!(v == v)) v = 0.0f;
    if (t->has_xf) { /* the transform acts on glTF's uvs, whose v assimp turned into 1 - v */
        float g = 1.0f - v, tu = t->xf[0] * u + t->xf[1] * g + t->xf[2];
        v = 1.0f - (t->xf[3] * u + t->xf[4] * g + t->xf[5]);
        u = tu;
        if (!(u - u == 0.0f)) u = 0.0f; /* inf or NaN from a huge scale */
        if (!(v - v == 0.0f)) v = 0.0f;
    }
    *pu = u - floorf(u);
    *pv = v - floorf(v);
}

/* bilinear, repeat wrap, v up (assimp's convention: v = 0 is the bottom row of the image),
   clamped into [0, hi] */
static void texture_sample(const imp_storage *st, uint32_t texture, float u, float v, float hi, float out_rgb[3])
{
    const imp_texture *t;
    float x, y, fx, fy;
    int x0, y0, x1, y1, c;
    if (texture == 0 || texture > st->texture_count) { out_rgb[0] = out_rgb[1] = out_rgb[2] = 0.5f; return; }
    t = &st->textures[texture - 1];
    texture_uv(t, &u, &v);
    x = u * (float)t->width - 0.5f;
    y = (1.0f - v) * (float)t->height - 0.5f;
    fx = x - floorf(x);
    fy = y - floorf(y);
    x0 = (int)floorf(x);
    y0 = (int)floorf(y);
    x0 = ((x0 % t->width) + t->width) % t->width;
    y0 = ((y0 % t->height) + t->height) % t->height;
    x1 = (x0 + 1) % t->width;
    y1 = (y0 + 1) % t->height;
    for (c = 0; c < 3; ++c) {
        float a = t->rgb[3 * ((size_t)y0 * t->width + x0) + c], b = t->rgb[3 * ((size_t)y0 * t->width + x1) + c];
        float d = t->rgb[3 * ((size_t)y1 * t->width + x0) + c], e = t->rgb[3 * ((size_t)y1 * t->width + x1) + c];
        float val = (1 - fy) * ((1 - fx) * a + fx * b) + fy * ((1 - fx) * d + fx * e);
        out_rgb[c] = val < 0.0f ? 0.0f : (val > hi ? hi : val);
    }
}

static void albedo_lookup(void *user, uint32_t texture, float u, float v, float out_rgb[3])
{
    texture_sample((const imp_storage *)user, texture, u, v, ALBEDO_MAX, out_rgb);
}

/* the emission texture's linear RGB (the factor multiplies it in the library) */
static void emission_lookup(void *user, uint32_t texture, float u, float v, float out_rgb[3])
{
    texture_sample((const imp_storage *)user, texture, u, v, 1e30f, out_rgb);
}

/* the opacity (alpha x factor) of an opacity texture, bilinear like texture_sample */
static float opacity_lookup(void *user, uint32_t texture, float u, float v)
{
    const imp_storage *st = (const imp_storage *)user;
    const imp_texture *t;
    float x, y, fx, fy, a, b, d, e;
    int x0, y0, x1, y1;
    if (texture == 0 || texture > st->texture_count) return 1.0f;
    t = &st->textures[texture - 1];
    texture_uv(t, &u, &v);
    x = u * (float)t->width - 0.5f;
    y = (1.0f - v) * (float)t->height - 0.5f;
    fx = x - floorf(x);
    fy = y - floorf(y);
    x0 = (int)floorf(x);
    y0 = (int)floorf(y);
    x0 = ((x0 % t->width) + t->width) % t->width;
    y0 = ((y0 % t->height) + t->height) % t->height;
    x1 = (x0 + 1) % t->width;
    y1 = (y0 + 1) % t->height;
    a = t->alpha[(size_t)y0 * t->width + x0], b = t->alpha[(size_t)y0 * t->width + x1];
    d = t->alpha[(size_t)y1 * t->width + x0], e = t->alpha[(size_t)y1 * t->width + x1];
    return t->alpha_scale * ((1 - fy) * ((1 - fx) * a + fx * b) + fy * ((1 - fx) * d + fx * e));
}

static void *xrealloc(void *p, size_t size)
{
    void *q = realloc(p, size ? size : 1);
    if (!q) {
        fprintf(stderr, "rad: out of memory importing the scene (%lu bytes)\n", (unsigned long)size);
        exit(1);
    }
    return q;
}

static char *xstrdup(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = (char *)xrealloc(NULL, n);
    memcpy(d, s, n);
    return d;
}

static void free_storage(imp_storage *st)
{
    uint32_t i;
    if (!st) return;
    for (i = 0; i < st->group_count; ++i) {
        free(st->groups[i].name);
        free(st->groups[i].positions);
        free(st->groups[i].uvs);
        free(st->groups[i].uvs2);
        free(st->groups[i].indices);
        free(st->groups[i].material_ids);
    }
    for (i = 0; i < st->texture_count; ++i) free(st->textures[i].rgb), free(st->textures[i].alpha);
    for (i = 0; st->material_names && i < st->material_count; ++i) free(st->material_names[i]);
    for (i = 0; i < st->input_count; ++i) free(st->inputs[i]);
    free(st->inputs);
    free(st->material_names);
    for (i = 0; st->material_reports && i < st->material_count; ++i) free(st->material_reports[i]);
    free(st->material_reports);
    free(st->groups);
    free(st->meshes);
    free(st->materials);
    free(st->wound_against);
    free(st->wound_total);
    free(st->textures);
    free(st);
}

void tool_free_scene(tool_scene *scene)
{
    if (!scene) return;
    free_storage((imp_storage *)scene->storage);
    free(scene->lights);
    memset(scene, 0, sizeof *scene);
}

/* ---- textures ---------------------------------------------------------------------------- */

static const char *base_dir_join(const char *file, const char *rel, char *buf, size_t buflen)
{
    const char *slash = strrchr(file, '/');
    size_t dl = slash ? (size_t)(slash - file + 1) : 0, rl = strlen(rel);
    if (rel[0] == '/') dl = 0;
    if (dl + rl + 1 > buflen) {
        buf[0] = 0;
        return buf;
    }
    memcpy(buf, file, dl);
    memcpy(buf + dl, rel, rl + 1);
    return buf;
}

/* index+1 of the texture, 0 when it cannot be loaded (warns). 'prefix' keeps copies apart:
   an emission texture ("emissive:") is never clamped like an albedo one, even when both are
   the same file. */
static uint32_t load_texture_as(imp_storage *st, const struct aiScene *sc, const char *file, const char *tpath,
                                const char *prefix)
{
    unsigned char *px = NULL;
    int w = 0, h = 0, comp = 0;
    uint32_t i;
    char full[1024], key[256];
    imp_texture *t;
    snprintf(key, sizeof key, "%s%s", prefix, tpath);
    for (i = 0; i < st->texture_count; ++i)
        if (!st->textures[i].has_xf && !strncmp(st->textures[i].path, key, sizeof st->textures[i].path - 1)) return i + 1;
    if (tpath[0] == '*') {
        unsigned idx = (unsigned)atoi(tpath + 1);
        if (idx < sc->mNumTextures) {
            const struct aiTexture *tex = sc->mTextures[idx];
            if (tex->mHeight == 0) {
                px = stbi_load_from_memory((const unsigned char *)tex->pcData, (int)tex->mWidth, &w, &h, &comp, 4);
            } else {
                size_t k, n = (size_t)tex->mWidth * tex->mHeight;
                w = (int)tex->mWidth;
                h = (int)tex->mHeight;
                comp = 4;
                px = (unsigned char *)malloc(4 * n);
                if (px)
                    for (k = 0; k < n; ++k) {
                        px[4 * k] = tex->pcData[k].r;
                        px[4 * k + 1] = tex->pcData[k].g;
                        px[4 * k + 2] = tex->pcData[k].b;
                        px[4 * k + 3] = tex->pcData[k].a;
                    }
            }
        }
    } else {
        for (i = 0; i < sc->mNumTextures && !px; ++i) /* embedded, named by its file name */
            if (sc->mTextures[i]->mHeight == 0 && !strcmp(sc->mTextures[i]->mFilename.data, tpath))
                px = stbi_load_from_memory((const unsigned char *)sc->mTextures[i]->pcData, (int)sc->mTextures[i]->mWidth,
                                           &w, &h, &comp, 4);
        if (!px && (px = stbi_load(base_dir_join(file, tpath, full, sizeof full), &w, &h, &comp, 4)) != NULL)
            add_input(st, full);
    }
    if (!px || w <= 0 || h <= 0) {
        fprintf(stderr, "rad: warning: texture '%s' could not be loaded (%s); using the material colour\n", tpath,
                stbi_failure_reason() ? stbi_failure_reason() : "unknown");
        if (px) stbi_image_free(px);
        return 0;
    }
    st->textures = (imp_texture *)xrealloc(st->textures, sizeof(imp_texture) * (st->texture_count + 1));
    t = &st->textures[st->texture_count];
    memset(t, 0, sizeof *t);
    {
        size_t pl = strlen(key);
        if (pl >= sizeof t->path) pl = sizeof t->path - 1;
        memcpy(t->path, key, pl);
        t->path[pl] = 0;
    }
    t->width = w;
    t->height = h;
    t->rgb = (float *)xrealloc(NULL, sizeof(float) * 3 * (size_t)w * (size_t)h);
    t->alpha = (float *)xrealloc(NULL, sizeof(float) * (size_t)w * (size_t)h);
    t->has_alpha = comp == 2 || comp == 4;
    t->alpha_scale = 1.0f;
    {
        float lut[256];
        size_t k, n = (size_t)w * (size_t)h;
        int ch;
        for (i = 0; i < 256; ++i) lut[i] = srgb_to_linear((float)i / 255.0f);
        for (k = 0; k < n; ++k) {
            for (ch = 0; ch < 3; ++ch) t->rgb[3 * k + (size_t)ch] = lut[px[4 * k + (size_t)ch]];
            t->alpha[k] = (float)px[4 * k + (t->has_alpha ? 3u : 0u)] / 255.0f;
        }
    }
    stbi_image_free(px);
    return ++st->texture_count;
}

static uint32_t load_texture(imp_storage *st, const struct aiScene *sc, const char *file, const char *tpath)
{
    return load_texture_as(st, sc, file, tpath, "");
}

/* ---- materials --------------------------------------------------------------------------- */

static const char *js_get(const char *o, const char *name);
static void js_string(const char *v, char *out, size_t cap);

/* A private opacity texture for a cutout: the alpha of image 'tpath' (its alpha channel;
   without one, 1 when 'grey' is 0, else its first channel) times 'scale', or with tpath NULL
   a single texel of alpha 'scale'. Returns its id, 0 when the image cannot be loaded. */
static uint32_t opacity_texture(imp_storage *st, const struct aiScene *sc, const char *file, const char *tpath, float scale,
                                int grey)
{
    char prefix[64];
    uint32_t id;
    imp_texture *t;
    size_t q, n;
    snprintf(prefix, sizeof prefix, "opacity:%g:%d:", (double)scale, grey);
    if (tpath) {
        id = load_texture_as(st, sc, file, tpath, prefix);
        if (!id) return 0;
    } else {
        for (id = 0; id < st->texture_count; ++id)
            if (!strcmp(st->textures[id].path, prefix)) return id + 1;
        st->textures = (imp_texture *)xrealloc(st->textures, sizeof(imp_texture) * (st->texture_count + 1));
        t = &st->textures[st->texture_count];
        memset(t, 0, sizeof *t);
        memcpy(t->path, prefix, strlen(prefix) + 1);
        t->width = t->height = 1;
        t->rgb = (float *)xrealloc(NULL, 3 * sizeof(float));
        t->rgb[0] = t->rgb[1] = t->rgb[2] = 0.5f;
        t->alpha = (float *)xrealloc(NULL, sizeof(float));
        t->alpha[0] = 1.0f;
        t->has_alpha = 1;
        id = ++st->texture_count;
    }
    t = &st->textures[id - 1];
    t->alpha_scale = scale;
    n = (size_t)t->width * t->height;
    if (!t->has_alpha && !grey)
        for (q = 0; q < n; ++q) t->alpha[q] = 1.0f;
    return id;
}

/* The largest emission (radiance) accepted: what the tool's other inputs allow (1e30). */
#define EMISSION_MAX 1e30f
/* no KHR_materials_emissive_strength in a glTF material (gltf_emissive_strength) */
#define GLTF_NO_STRENGTH (-1e300)

/* Alpha cutouts of material m, a stage of convert_material (1 on a bad alphaCutoff, with err).
   glTF alphaMode MASK: the surface is there where baseColorTexture alpha x
   baseColorFactor alpha >= alphaCutoff (default 0.5); BLEND is approximated the same way
   at 0.5 (partial transmission is not modelled). OBJ map_d: its alpha channel, else its
   grey value, at 0.5; a constant d < 1 without map_d is not a cutout (reported, ignored). */
static int material_cutout(imp_storage *st, const struct aiScene *sc, const char *file, const struct aiMaterial *m,
                           uint32_t index, const char *mname, const char *gm, float base_alpha, rad_material *out, char *err,
                           size_t errlen)
{
    char mode[32] = "";
    const char *v;
    double cutoff = 0.5;
    struct aiString bp;
    int have_tex = aiGetMaterialTexture(m, aiTextureType_BASE_COLOR, 0, &bp, NULL, NULL, NULL, NULL, NULL, NULL) ==
                       aiReturn_SUCCESS ||
                   aiGetMaterialTexture(m, aiTextureType_DIFFUSE, 0, &bp, NULL, NULL, NULL, NULL, NULL, NULL) == aiReturn_SUCCESS;
    if (gm && (v = js_get(gm, "alphaMode")) != NULL) js_string(v, mode, sizeof mode);
    if (!strcmp(mode, "MASK") && (v = js_get(gm, "alphaCutoff")) != NULL) {
        cutoff = strtod(v, NULL);
        if (!(cutoff >= 0.0 && cutoff <= 1.0)) {
            if (err && errlen)
                snprintf(err, errlen, "'%s': material %u '%s': alphaCutoff %g is out of range (want [0, 1])", file, index,
                         mname, cutoff);
            return 1;
        }
    }
    if ((!strcmp(mode, "MASK") || !strcmp(mode, "BLEND")) && cutoff > 0.0) {
        if (!(base_alpha >= 0.0f && base_alpha <= 1.0f)) base_alpha = 1.0f;
        /* a factor alone at or above the cutoff leaves nothing to cut */
        if (have_tex || base_alpha < (float)cutoff)
            out->opacity_texture = opacity_texture(st, sc, file, have_tex ? bp.data : NULL, base_alpha, 0);
    } else if (!gm && aiGetMaterialTexture(m, aiTextureType_OPACITY, 0, &bp, NULL, NULL, NULL, NULL, NULL, NULL) ==
                          aiReturn_SUCCESS) {
        out->opacity_texture = opacity_texture(st, sc, file, bp.data, 1.0f, 1);
    }
    if (out->opacity_texture) {
        out->alpha_cutoff = (float)cutoff;
        st->any_cutout = 1;
    }
    return 0;
}

/* 0, or 1 with the reason in err (a negative, NaN, infinite or overflowing emission: it used
   to become 0 without a word). *clamped: set to 1 when the albedo was clamped into
   [0, ALBEDO_MAX] (the warning waits until it is known which materials are used). */
static int convert_material(imp_storage *st, const struct aiScene *sc, const char *file, const struct aiMaterial *m,
                            uint32_t index, double json_strength, const char *gm, rad_material *out, unsigned char *clamped_out,
                            char *err, size_t errlen)
{
    struct aiColor4D c;
    struct aiString name, tpath;
    float strength = 1.0f, scale[3] = {1, 1, 1};
    ai_real fv;
    unsigned int one = 1;
    int k, have_base = 0, clamped = 0;
    float base_alpha = 1.0f;
    memset(out, 0, sizeof *out);
    out->albedo[0] = out->albedo[1] = out->albedo[2] = 0.5f;
    if (aiGetMaterialColor(m, AI_MATKEY_BASE_COLOR, &c) == aiReturn_SUCCESS) {
        out->albedo[0] = c.r, out->albedo[1] = c.g, out->albedo[2] = c.b;
        base_alpha = c.a;
        have_base = 1;
    }
    if (!have_base && aiGetMaterialColor(m, AI_MATKEY_COLOR_DIFFUSE, &c) == aiReturn_SUCCESS)
        out->albedo[0] = c.r, out->albedo[1] = c.g, out->albedo[2] = c.b;
    if (aiGetMaterialString(m, AI_MATKEY_NAME, &name) != aiReturn_SUCCESS) name.length = 0, name.data[0] = 0;
    if (aiGetMaterialColor(m, AI_MATKEY_COLOR_EMISSIVE, &c) == aiReturn_SUCCESS)
        out->emission[0] = c.r, out->emission[1] = c.g, out->emission[2] = c.b;
    if (aiGetMaterialFloatArray(m, AI_MATKEY_EMISSIVE_INTENSITY, &fv, &one) == aiReturn_SUCCESS) {
        if (!(fv >= 0 && fv <= EMISSION_MAX)) {
            if (err && errlen)
                snprintf(err, errlen, "'%s': material %u '%s': emissive strength %g is out of range (want a finite value in [0, %g])",
                         file, index, name.data, (double)fv, (double)EMISSION_MAX);
            return 1;
        }
        strength = (float)fv;
    } else if (json_strength != GLTF_NO_STRENGTH) { /* KHR_materials_emissive_strength, read from the JSON */
        if (!(json_strength >= 0.0 && json_strength <= (double)EMISSION_MAX)) {
            if (err && errlen)
                snprintf(err, errlen, "'%s': material %u '%s': emissive strength %g is out of range (want a finite value in [0, %g])",
                         file, index, name.data, json_strength, (double)EMISSION_MAX);
            return 1;
        }
        strength = (float)json_strength;
    }
    for (k = 0; k < 3; ++k) {
        float e = out->emission[k], es = e * strength;
        /* e * strength: an overflow to inf is caught like an inf in the file */
        if (!(e >= 0.0f && e <= EMISSION_MAX) || !(es >= 0.0f && es <= EMISSION_MAX)) {
            if (err && errlen)
                snprintf(err, errlen,
                         "'%s': material %u '%s': emission (Ke, or emissive x strength) %g %g %g is out of range "
                         "(want finite values in [0, %g])",
                         file, index, name.data, (double)(out->emission[0] * strength), (double)(out->emission[1] * strength),
                         (double)(out->emission[2] * strength), (double)EMISSION_MAX);
            return 1;
        }
    }
    for (k = 0; k < 3; ++k) out->emission[k] *= strength;
    /* emission texture (glTF emissiveTexture, OBJ map_Ke): multiplied by the factor above */
    if (aiGetMaterialTexture(m, aiTextureType_EMISSIVE, 0, &tpath, NULL, NULL, NULL, NULL, NULL, NULL) == aiReturn_SUCCESS &&
        (out->emission[0] > 0.0f || out->emission[1] > 0.0f || out->emission[2] > 0.0f)) {
        uint32_t id = load_texture_as(st, sc, file, tpath.data, "emissive:");
        if (id) {
            out->emission_texture = id;
            st->any_emission_texture = 1;
        }
    }
    /* glTF doubleSided (and a few other formats' two-sided flags) */
    {
        int two = 0;
        unsigned int n2 = 1;
        if (aiGetMaterialIntegerArray(m, AI_MATKEY_TWOSIDED, &two, &n2) == aiReturn_SUCCESS && two) out->two_sided = 1;
    }
    /* texture: base colour (glTF) or diffuse (OBJ map_Kd ...) */
    if (aiGetMaterialTexture(m, aiTextureType_BASE_COLOR, 0, &tpath, NULL, NULL, NULL, NULL, NULL, NULL) == aiReturn_SUCCESS ||
        aiGetMaterialTexture(m, aiTextureType_DIFFUSE, 0, &tpath, NULL, NULL, NULL, NULL, NULL, NULL) == aiReturn_SUCCESS) {
        uint32_t id = load_texture(st, sc, file, tpath.data);
        if (id) {
            /* the texture is multiplied by the colour factor (glTF, MTL); bake the factor into
               a private copy of the texels so the callback stays a plain lookup */
            imp_texture *t = &st->textures[id - 1];
            size_t q, n = (size_t)t->width * t->height;
            for (k = 0; k < 3; ++k) scale[k] = out->albedo[k];
            if (!(scale[0] == 1.0f && scale[1] == 1.0f && scale[2] == 1.0f)) {
                /* a new texture entry for this factor */
                st->textures = (imp_texture *)xrealloc(st->textures, sizeof(imp_texture) * (st->texture_count + 1));
                t = &st->textures[id - 1];
                {
                    char tag[256];
                    snprintf(tag, sizeof tag, "%.200s@%g,%g,%g", t->path, (double)scale[0], (double)scale[1],
                             (double)scale[2]);
                    st->textures[st->texture_count] = *t;
                    memcpy(st->textures[st->texture_count].path, tag, sizeof tag);
                }
                st->textures[st->texture_count].rgb = (float *)xrealloc(NULL, sizeof(float) * 3 * n);
                st->textures[st->texture_count].alpha = (float *)xrealloc(NULL, sizeof(float) * n);
                memcpy(st->textures[st->texture_count].alpha, t->alpha, sizeof(float) * n);
                for (q = 0; q < n; ++q)
                    for (k = 0; k < 3; ++k)
                        st->textures[st->texture_count].rgb[3 * q + k] = t->rgb[3 * q + k] * scale[k];
                id = ++st->texture_count;
                t = &st->textures[id - 1];
            }
            /* a white texel (255 in 8 bits) is 1 and becomes 0.999 silently: only a factor that
               lifts texels above 1 is worth the warning */
            for (q = 0; q < 3 * n; ++q)
                if (t->rgb[q] > ALBEDO_MAX) {
                    if (t->rgb[q] > 1.0f) clamped = 1;
                    t->rgb[q] = ALBEDO_MAX;
                }
            out->texture = id;
        }
    }
    if (material_cutout(st, sc, file, m, index, name.data, gm, base_alpha, out, err, errlen)) return 1;
    for (k = 0; k < 3; ++k) {
        if (!(out->albedo[k] >= 0.0f)) out->albedo[k] = 0.0f, clamped = 1;
        if (out->albedo[k] > ALBEDO_MAX) { /* a textured material's factor 1 (the glTF default) is no news */
            if (!out->texture || out->albedo[k] > 1.0f) clamped = 1;
            out->albedo[k] = ALBEDO_MAX;
        }
    }
    *clamped_out = (unsigned char)clamped;
    return 0;
}

/* ---- assimp's log ------------------------------------------------------------------------- */

/* assimp reports what it repaired or dropped only to its logger: a glTF with an out-of-range
   index lost a triangle with exit 0. While a file is imported its warnings and
   errors are shown (at most LOG_SHOWN), and one saying faces were dropped for out-of-range
   indices fails the import with that reason. */
#define LOG_SHOWN 10
static struct {
    unsigned shown, more;
    char fatal[512];
} g_log;

static void assimp_log(const char *message, char *user)
{
    const char *text = message;
    size_t n;
    int warn = !strncmp(message, "Warn", 4), error = !strncmp(message, "Error", 5);
    (void)user;
    if (!warn && !error) return; /* Info, Debug */
    if (strstr(message, ": ")) text = strstr(message, ": ") + 2; /* "Warn,  T0: text" */
    n = strlen(text);
    while (n && (text[n - 1] == '\n' || text[n - 1] == '\r')) --n;
    if (!g_log.fatal[0] && (strstr(text, "out-of-range") || strstr(text, "out of range")) &&
        (strstr(text, "dropped") || strstr(text, "ignored") || strstr(text, "skipp") || strstr(text, "remov"))) {
        snprintf(g_log.fatal, sizeof g_log.fatal, "%.*s", (int)(n < 400 ? n : 400), text);
        return;
    }
    if (g_log.shown < LOG_SHOWN) {
        fprintf(stderr, "rad: warning: assimp: %.*s\n", (int)n, text);
        ++g_log.shown;
    } else {
        ++g_log.more;
    }
}

static const struct aiScene *import_logged(const char *path, unsigned flags)
{
    const struct aiScene *sc;
    struct aiLogStream stream;
    memset(&g_log, 0, sizeof g_log);
    stream.callback = assimp_log;
    stream.user = NULL;
    aiEnableVerboseLogging(AI_FALSE);
    aiAttachLogStream(&stream);
    sc = aiImportFile(path, flags);
    aiDetachAllLogStreams();
    if (g_log.more) fprintf(stderr, "rad: warning: assimp: %u more warnings\n", g_log.more);
    return sc;
}

/* ---- glTF extensions the file requires ------------------------------------------------------- */

/* A glTF file lists in "extensionsRequired" the extensions a reader must implement to load it
   (EXT_meshopt_compression, KHR_draco_mesh_compression: compressed geometry). When assimp
   fails on such a file its message names a symptom ("buffer ... missing the uri"), so the
   list is read here from the JSON (the .gltf text, or a .glb's first chunk) and named in the
   error. Writes "A, B" into out and returns how many; 0 when the file is not glTF or lists
   none. */
#define GLTF_JSON_MAX (64u << 20)
static unsigned gltf_required_extensions(const char *path, char *out, size_t cap)
{
    FILE *f;
    char *json = NULL, *p;
    unsigned char head[20];
    size_t n = 0, len = strlen(path), used = 0;
    unsigned count = 0;
    int glb;
    if (cap) out[0] = '\0';
    if (!((len > 5 && (!strcmp(path + len - 5, ".gltf") || !strcmp(path + len - 5, ".GLTF"))) ||
          (len > 4 && (!strcmp(path + len - 4, ".glb") || !strcmp(path + len - 4, ".GLB")))))
        return 0;
    if (!(f = fopen(path, "rb"))) return 0;
    glb = fread(head, 1, 20, f) == 20 && !memcmp(head, "glTF", 4);
    if (glb) {
        /* 12-byte header, then the first chunk: its length, its type "JSON", its bytes */
        uint32_t clen = (uint32_t)head[12] | (uint32_t)head[13] << 8 | (uint32_t)head[14] << 16 | (uint32_t)head[15] << 24;
        if (memcmp(head + 16, "JSON", 4) || clen > GLTF_JSON_MAX) { fclose(f); return 0; }
        json = (char *)xrealloc(NULL, (size_t)clen + 1);
        n = fread(json, 1, clen, f);
    } else {
        rewind(f);
        json = (char *)xrealloc(NULL, (size_t)GLTF_JSON_MAX + 1);
        n = fread(json, 1, GLTF_JSON_MAX, f);
    }
    fclose(f);
    json[n] = '\0';
    /* "extensionsRequired" : [ "A" , "B" ] */
    for (p = strstr(json, "\"extensionsRequired\""); p && !count; p = strstr(p + 1, "\"extensionsRequired\"")) {
        char *q = p + 20;
        while (*q == ' ' || *q == '\t' || *q == '\r' || *q == '\n') ++q;
        if (*q++ != ':') continue;
        while (*q == ' ' || *q == '\t' || *q == '\r' || *q == '\n') ++q;
        if (*q++ != '[') continue;
        for (;;) {
            char *e;
            while (*q == ' ' || *q == '\t' || *q == '\r' || *q == '\n' || *q == ',') ++q;
            if (*q != '"') break;
            e = strchr(q + 1, '"');
            if (!e) break;
            if (used + (size_t)(e - q) + 3 < cap) {
                used += (size_t)snprintf(out + used, cap - used, "%s%.*s", count ? ", " : "", (int)(e - q - 1), q + 1);
                ++count;
            }
            q = e + 1;
        }
    }
    free(json);
    return count;
}

/* ---- glTF materials as the JSON has them ------------------------------------------------------ */

/* assimp 5.2 reads neither KHR_materials_emissive_strength nor tells which material
   properties it dropped, so the "materials" array is read here with a small JSON walker (no
   allocation; NULL on malformed input, which then only loses the report and the strength). */
#define JS_DEPTH 64

static const char *js_ws(const char *p)
{
    while (p && (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n')) ++p;
    return p;
}

static const char *js_skip_depth(const char *p, int depth)
{
    p = js_ws(p);
    if (!p || !*p || depth > JS_DEPTH) return NULL;
    if (*p == '"') {
        for (++p; *p && *p != '"'; ++p)
            if (*p == '\\' && p[1]) ++p;
        return *p == '"' ? p + 1 : NULL;
    }
    if (*p == '{' || *p == '[') {
        char close = *p == '{' ? '}' : ']';
        p = js_ws(p + 1);
        if (p && *p == close) return p + 1;
        for (;;) {
            if (close == '}') {
                p = js_skip_depth(p, depth + 1); /* the key */
                p = js_ws(p);
                if (!p || *p != ':') return NULL;
                ++p;
            }
            p = js_ws(js_skip_depth(p, depth + 1));
            if (!p) return NULL;
            if (*p == ',') { ++p; continue; }
            return *p == close ? p + 1 : NULL;
        }
    }
    while (*p && *p != ',' && *p != '}' && *p != ']' && *p != ' ' && *p != '\n' && *p != '\r' && *p != '\t') ++p;
    return p;
}

static const char *js_skip(const char *p) { return js_skip_depth(p, 0); }

/* The i-th member of object o ('{'): its key into key (cap bytes) and a pointer to its value;
   NULL past the end */
static const char *js_member(const char *o, unsigned i, char *key, size_t cap)
{
    const char *p = js_ws(o);
    unsigned n = 0;
    if (!p || *p != '{') return NULL;
    p = js_ws(p + 1);
    while (p && *p == '"') {
        const char *k = p + 1, *e = js_skip(p), *v;
        if (!e) return NULL;
        v = js_ws(e);
        if (!v || *v != ':') return NULL;
        v = js_ws(v + 1);
        if (n++ == i) {
            size_t len = (size_t)(e - 1 - k);
            if (len >= cap) len = cap - 1;
            memcpy(key, k, len);
            key[len] = 0;
            return v;
        }
        p = js_ws(js_skip(v));
        if (p && *p == ',') p = js_ws(p + 1);
    }
    return NULL;
}

/* the value of 'name' in object o, or NULL */
static const char *js_get(const char *o, const char *name)
{
    char key[128];
    const char *v;
    unsigned i;
    for (i = 0; (v = js_member(o, i, key, sizeof key)) != NULL; ++i)
        if (!strcmp(key, name)) return v;
    return NULL;
}

/* element i of array a ('['), or NULL */
static const char *js_at(const char *a, unsigned i)
{
    const char *p = js_ws(a);
    unsigned n = 0;
    if (!p || *p != '[') return NULL;
    p = js_ws(p + 1);
    if (p && *p == ']') return NULL;
    while (p) {
        if (n++ == i) return p;
        p = js_ws(js_skip(p));
        if (!p || *p != ',') return NULL;
        p = js_ws(p + 1);
    }
    return NULL;
}

static void js_string(const char *v, char *out, size_t cap)
{
    const char *e = v && *v == '"' ? js_skip(v) : NULL;
    size_t len = e ? (size_t)(e - v - 2) : 0;
    if (len >= cap) len = cap - 1;
    if (e) memcpy(out, v + 1, len);
    out[len] = 0;
}

/* The JSON of a .gltf, or of a .glb's first chunk; NULL when the file is neither (free it) */
static char *gltf_json(const char *path)
{
    FILE *f;
    char *json = NULL;
    unsigned char head[20];
    size_t n = 0, len = strlen(path);
    if (!((len > 5 && (!strcmp(path + len - 5, ".gltf") || !strcmp(path + len - 5, ".GLTF"))) ||
          (len > 4 && (!strcmp(path + len - 4, ".glb") || !strcmp(path + len - 4, ".GLB")))))
        return NULL;
    if (!(f = fopen(path, "rb"))) return NULL;
    if (fread(head, 1, 20, f) == 20 && !memcmp(head, "glTF", 4)) {
        uint32_t clen = (uint32_t)head[12] | (uint32_t)head[13] << 8 | (uint32_t)head[14] << 16 | (uint32_t)head[15] << 24;
        if (memcmp(head + 16, "JSON", 4) || clen > GLTF_JSON_MAX) { fclose(f); return NULL; }
        json = (char *)xrealloc(NULL, (size_t)clen + 1);
        n = fread(json, 1, clen, f);
    } else {
        rewind(f);
        json = (char *)xrealloc(NULL, (size_t)GLTF_JSON_MAX + 1);
        n = fread(json, 1, GLTF_JSON_MAX, f);
    }
    fclose(f);
    json[n] = '\0';
    return json;
}

/* glTF material i of the JSON's "materials", or NULL */
static const char *gltf_material(const char *json, unsigned i)
{
    const char *mats = json ? js_get(json, "materials") : NULL;
    return mats ? js_at(mats, i) : NULL;
}

/* KHR_materials_emissive_strength of glTF material m, or GLTF_NO_STRENGTH when it has none (a
   value that is not a number gives NaN; it and a negative one are refused by convert_material) */
static double gltf_emissive_strength(const char *m)
{
    const char *ext = m ? js_get(m, "extensions") : NULL, *ks, *v;
    if (!ext || !(ks = js_get(ext, "KHR_materials_emissive_strength"))) return GLTF_NO_STRENGTH;
    v = js_get(ks, "emissiveStrength");
    if (!v) return 1.0; /* the extension's default */
    if (!((*v >= '0' && *v <= '9') || *v == '-' || *v == '.')) return (double)NAN;
    return strtod(v, NULL);
}

/* appends to a report line list */
static void rep_add(char **r, const char *fmt, const char *a, const char *b)
{
    char line[600];
    size_t n = *r ? strlen(*r) : 0;
    snprintf(line, sizeof line, fmt, a ? a : "", b ? b : "");
    *r = (char *)xrealloc(*r, n + strlen(line) + 2);
    memcpy(*r + n, line, strlen(line));
    (*r)[n + strlen(line)] = '\n';
    (*r)[n + strlen(line) + 1] = 0;
}

/* appends "item what" to the comma-separated list in buf (cap bytes), "..." once it is full */
static void list_add(char *buf, size_t cap, const char *item, const char *what)
{
    size_t n = strlen(buf), need = strlen(item) + strlen(what) + 2;
    if (n + need + 4 < cap) snprintf(buf + n, cap - n, "%s%s%s", n ? ", " : "", item, what);
    else if (n + 5 < cap && strcmp(buf + (n > 3 ? n - 3 : 0), "...")) snprintf(buf + n, cap - n, ", ...");
}

/* whether texture-info object t carries KHR_texture_transform */
static int gltf_has_transform(const char *t)
{
    const char *e = t ? js_get(t, "extensions") : NULL;
    return e && js_get(e, "KHR_texture_transform") != NULL;
}

/* The glTF part of a material's report: what of m (its JSON object) the importer used, read
   or ignored, each property and extension by name. */
static void gltf_report(const char *m, char **r)
{
    static const char *const used[] = {"name", "pbrMetallicRoughness", "emissiveFactor", "emissiveTexture",
                                       "extensions", "doubleSided", "alphaMode", "alphaCutoff", NULL};
    char key[128], val[64], ign[1024] = "";
    const char *v, *pbr = js_get(m, "pbrMetallicRoughness"), *ext = js_get(m, "extensions");
    unsigned i, j, transform = 0;
    size_t n;
    if ((v = js_get(m, "doubleSided")) != NULL)
        rep_add(r, "  doubleSided: %s (used unless --two-sided all|none overrides it)", !strncmp(v, "true", 4) ? "true" : "false", NULL);
    if ((v = js_get(m, "alphaMode")) != NULL) {
        char cut[64] = "";
        const char *c = js_get(m, "alphaCutoff");
        js_string(v, val, sizeof val);
        if (c) snprintf(cut, sizeof cut, ", alphaCutoff %g", strtod(c, NULL));
        rep_add(r, "  alphaMode: %s%s (used: see cutout)", val, cut);
    }
    transform += gltf_has_transform(js_get(m, "emissiveTexture"));
    if (pbr) transform += gltf_has_transform(js_get(pbr, "baseColorTexture"));
    if (transform) rep_add(r, "  KHR_texture_transform: used (offset, rotation, scale; a texCoord in it is ignored)%s%s", NULL, NULL);
    for (i = 0; (v = js_member(m, i, key, sizeof key)) != NULL; ++i) {
        for (j = 0; used[j] && strcmp(used[j], key); ++j) {}
        if (!used[j])
            list_add(ign, sizeof ign, key, strstr(key, "Texture") ? " (not diffuse)" : "");
    }
    for (i = 0; pbr && (v = js_member(pbr, i, key, sizeof key)) != NULL; ++i)
        if (strcmp(key, "baseColorFactor") && strcmp(key, "baseColorTexture"))
            list_add(ign, sizeof ign, key, " (not diffuse)");
    for (i = 0; ext && (v = js_member(ext, i, key, sizeof key)) != NULL; ++i)
        if (strcmp(key, "KHR_materials_emissive_strength"))
            list_add(ign, sizeof ign, key, " (extension)");
    if ((n = strlen(ign)) > 0) rep_add(r, "  ignored: %s%s", ign, NULL);
}

/* ---- vertex welding ------------------------------------------------------------------------ */

/* assimp's aiProcess_JoinIdenticalVertices joins vertices closer than an absolute 1e-5: a
   Cornell box scaled by 3e-5 lost corners (the floor-to-ceiling form factor moved by 8%) and
   at 1e-5 whole triangles collapsed. The tool welds here instead, within each assimp
   mesh (like assimp), with a tolerance relative to that mesh's size: positions within
   WELD_REL x its bounding-box diagonal, and uvs and normals within assimp's 1e-5 (they do not
   scale with the scene), make one vertex. So the result does not depend on the scene's units. */
#define WELD_REL 1e-6
#define WELD_ATTR_EPS 1e-5

typedef struct weld_table {
    int64_t *cell;       /* 3 per kept vertex: its grid cell */
    uint32_t *next;      /* the next kept vertex in the same cell (UINT32_MAX: none) */
    uint32_t *slot;      /* hash table of cells: the first kept vertex of the cell (UINT32_MAX: empty) */
    uint32_t mask;
} weld_table;

static uint32_t weld_hash(const int64_t c[3])
{
    uint64_t h = (uint64_t)c[0] * 0x9E3779B97F4A7C15ull ^ (uint64_t)c[1] * 0xC2B2AE3D27D4EB4Full ^
                 (uint64_t)c[2] * 0x165667B19E3779F9ull;
    return (uint32_t)(h ^ (h >> 29));
}

/* the slot of cell c: the one holding it, or the empty one where it goes */
static uint32_t weld_find(const weld_table *t, const int64_t c[3])
{
    uint32_t i = weld_hash(c) & t->mask;
    for (;;) {
        uint32_t r = t->slot[i];
        if (r == UINT32_MAX) return i;
        if (t->cell[3 * (size_t)r] == c[0] && t->cell[3 * (size_t)r + 1] == c[1] && t->cell[3 * (size_t)r + 2] == c[2])
            return i;
        i = (i + 1) & t->mask;
    }
}

static int weld_same(const struct aiMesh *m, uint32_t a, uint32_t b, double tol)
{
    const struct aiVector3D *p = m->mVertices;
    double dx = (double)p[a].x - p[b].x, dy = (double)p[a].y - p[b].y, dz = (double)p[a].z - p[b].z;
    if (!(dx * dx + dy * dy + dz * dz <= tol * tol)) return 0;
    if (m->mTextureCoords[0]) {
        const struct aiVector3D *t = m->mTextureCoords[0];
        if (!(fabs((double)t[a].x - t[b].x) <= WELD_ATTR_EPS && fabs((double)t[a].y - t[b].y) <= WELD_ATTR_EPS)) return 0;
    }
    if (m->mTextureCoords[1]) { /* the lightmap's uv set: a vertex on a chart seam stays two */
        const struct aiVector3D *t = m->mTextureCoords[1];
        if (!(fabs((double)t[a].x - t[b].x) <= WELD_ATTR_EPS && fabs((double)t[a].y - t[b].y) <= WELD_ATTR_EPS)) return 0;
    }
    if (m->mNormals) {
        const struct aiVector3D *n = m->mNormals;
        dx = (double)n[a].x - n[b].x, dy = (double)n[a].y - n[b].y, dz = (double)n[a].z - n[b].z;
        if (!(dx * dx + dy * dy + dz * dz <= WELD_ATTR_EPS * WELD_ATTR_EPS)) return 0;
    }
    return 1;
}

/* remap[v]: the kept vertex v becomes (kept vertices are numbered in order of first use);
   returns how many are kept */
static uint32_t weld_mesh(const struct aiMesh *m, uint32_t *remap, uint32_t *kept_of)
{
    uint32_t n = m->mNumVertices, v, kept = 0, cap = 16;
    double bmin[3] = {0, 0, 0}, bmax[3] = {0, 0, 0}, diag = 0.0, tol, cell;
    int k, any = 0;
    weld_table t;
    for (v = 0; v < n; ++v) {
        double q[3];
        q[0] = m->mVertices[v].x, q[1] = m->mVertices[v].y, q[2] = m->mVertices[v].z;
        if (!(fabs(q[0]) <= 3.4e38 && fabs(q[1]) <= 3.4e38 && fabs(q[2]) <= 3.4e38)) continue; /* NaN, inf */
        for (k = 0; k < 3; ++k) {
            if (!any || q[k] < bmin[k]) bmin[k] = q[k];
            if (!any || q[k] > bmax[k]) bmax[k] = q[k];
        }
        any = 1;
    }
    for (k = 0; k < 3; ++k) diag += (bmax[k] - bmin[k]) * (bmax[k] - bmin[k]);
    diag = sqrt(diag);
    tol = WELD_REL * diag;
    cell = tol > 0.0 ? tol : 1.0; /* all at one point: exact matches only */
    while (cap < 2 * (uint64_t)n && cap < 0x80000000u) cap *= 2;
    t.cell = (int64_t *)xrealloc(NULL, sizeof(int64_t) * 3 * (n ? n : 1));
    t.next = (uint32_t *)xrealloc(NULL, sizeof(uint32_t) * (n ? n : 1));
    t.slot = (uint32_t *)xrealloc(NULL, sizeof(uint32_t) * cap);
    t.mask = cap - 1;
    memset(t.slot, 0xFF, sizeof(uint32_t) * cap);
    for (v = 0; v < n; ++v) {
        double q[3];
        int64_t c[3], d[3];
        int dx, dy, dz, found = 0;
        uint32_t s;
        q[0] = m->mVertices[v].x, q[1] = m->mVertices[v].y, q[2] = m->mVertices[v].z;
        if (!(fabs(q[0]) <= 3.4e38 && fabs(q[1]) <= 3.4e38 && fabs(q[2]) <= 3.4e38)) {
            kept_of[kept] = v; /* not welded: rad_scene_create names it */
            remap[v] = kept++;
            continue;
        }
        for (k = 0; k < 3; ++k) c[k] = (int64_t)floor((q[k] - bmin[k]) / cell);
        for (dx = -1; dx <= 1 && !found; ++dx)
            for (dy = -1; dy <= 1 && !found; ++dy)
                for (dz = -1; dz <= 1 && !found; ++dz) {
                    uint32_t r;
                    d[0] = c[0] + dx, d[1] = c[1] + dy, d[2] = c[2] + dz;
                    for (r = t.slot[weld_find(&t, d)]; r != UINT32_MAX; r = t.next[r])
                        if (weld_same(m, kept_of[r], v, tol)) {
                            remap[v] = r;
                            found = 1;
                            break;
                        }
                }
        if (found) continue;
        kept_of[kept] = v;
        memcpy(t.cell + 3 * (size_t)kept, c, sizeof c);
        s = weld_find(&t, c);
        t.next[kept] = t.slot[s]; /* UINT32_MAX for a new cell */
        t.slot[s] = kept;
        remap[v] = kept++;
    }
    free(t.cell);
    free(t.next);
    free(t.slot);
    return kept;
}

/* ---- geometry ---------------------------------------------------------------------------- */

static void mat_mul(const struct aiMatrix4x4 *a, const struct aiMatrix4x4 *b, struct aiMatrix4x4 *o)
{
    const float *A = &a->a1, *B = &b->a1;
    float R[16];
    int i, j, k;
    for (i = 0; i < 4; ++i)
        for (j = 0; j < 4; ++j) {
            float s = 0.0f;
            for (k = 0; k < 4; ++k) s += A[4 * i + k] * B[4 * k + j];
            R[4 * i + j] = s;
        }
    memcpy(&o->a1, R, sizeof R);
}

static void xform_point(const struct aiMatrix4x4 *m, const float p[3], float o[3])
{
    o[0] = m->a1 * p[0] + m->a2 * p[1] + m->a3 * p[2] + m->a4;
    o[1] = m->b1 * p[0] + m->b2 * p[1] + m->b3 * p[2] + m->b4;
    o[2] = m->c1 * p[0] + m->c2 * p[1] + m->c3 * p[2] + m->c4;
}

static void xform_dir(const struct aiMatrix4x4 *m, const float p[3], float o[3])
{
    o[0] = m->a1 * p[0] + m->a2 * p[1] + m->a3 * p[2];
    o[1] = m->b1 * p[0] + m->b2 * p[1] + m->b3 * p[2];
    o[2] = m->c1 * p[0] + m->c2 * p[1] + m->c3 * p[2];
}

static imp_group *group_for(imp_storage *st, const char *name)
{
    uint32_t i;
    for (i = 0; i < st->group_count; ++i)
        if (!strcmp(st->groups[i].name, name)) return &st->groups[i];
    if (st->group_count == st->group_cap) {
        st->group_cap = st->group_cap ? 2 * st->group_cap : 16;
        st->groups = (imp_group *)xrealloc(st->groups, sizeof(imp_group) * st->group_cap);
    }
    memset(&st->groups[st->group_count], 0, sizeof(imp_group));
    st->groups[st->group_count].name = xstrdup(name);
    return &st->groups[st->group_count++];
}

/* yfov (radians) of the perspective camera of the glTF node named 'name', 0 when none is found */
static float gltf_camera_yfov(const char *json, const char *name)
{
    const char *nodes = js_get(json, "nodes"), *cams = js_get(json, "cameras"), *n, *v, *cam, *persp;
    char nn[256];
    unsigned i;
    for (i = 0; nodes && cams && (n = js_at(nodes, i)) != NULL; ++i) {
        if (!(v = js_get(n, "name"))) continue;
        js_string(v, nn, sizeof nn);
        if (strcmp(nn, name) || !(v = js_get(n, "camera"))) continue;
        cam = js_at(cams, (unsigned)strtoul(v, NULL, 10));
        persp = cam ? js_get(cam, "perspective") : NULL;
        v = persp ? js_get(persp, "yfov") : NULL;
        return v ? (float)strtod(v, NULL) : 0.0f;
    }
    return 0.0f;
}

typedef struct walk_state {
    imp_storage *st;
    const struct aiScene *sc;
    tool_scene *out;
    int camera_done;
    unsigned unnamed;
    uint32_t bad_indices;  /* faces with an index past the mesh's vertices (dropped) */
    const char *gltf;      /* the glTF JSON when the file is glTF (its cameras are read from it) */
} walk_state;

static void add_mesh(walk_state *ws, const struct aiMesh *mesh, const struct aiNode *node, const struct aiMatrix4x4 *m)
{
    char fallback[32];
    const char *name = mesh->mName.length ? mesh->mName.data : node->mName.length ? node->mName.data : NULL;
    imp_group *g;
    uint32_t base, f, v, k, kept, tri = 0, *remap, *kept_of;
    float det;
    if (!name) {
        snprintf(fallback, sizeof fallback, "mesh%u", ws->unnamed++);
        name = fallback;
    }
    if (!(mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) return;
    g = group_for(ws->st, name);
    if ((uint64_t)g->vertex_count + mesh->mNumVertices > 0xFFFFFFF0u) return;
    remap = (uint32_t *)xrealloc(NULL, sizeof(uint32_t) * (mesh->mNumVertices ? mesh->mNumVertices : 1));
    kept_of = (uint32_t *)xrealloc(NULL, sizeof(uint32_t) * (mesh->mNumVertices ? mesh->mNumVertices : 1));
    kept = weld_mesh(mesh, remap, kept_of);
    base = g->vertex_count;
    if (g->vertex_count + kept > g->vertex_cap) {
        while (g->vertex_count + kept > g->vertex_cap) g->vertex_cap = g->vertex_cap ? 2 * g->vertex_cap : 256;
        g->positions = (float *)xrealloc(g->positions, sizeof(float) * 3 * g->vertex_cap);
        g->uvs = (float *)xrealloc(g->uvs, sizeof(float) * 2 * g->vertex_cap);
        g->uvs2 = (float *)xrealloc(g->uvs2, sizeof(float) * 2 * g->vertex_cap);
    }
    for (k = 0; k < kept; ++k) {
        float p[3];
        v = kept_of[k];
        p[0] = mesh->mVertices[v].x, p[1] = mesh->mVertices[v].y, p[2] = mesh->mVertices[v].z;
        xform_point(m, p, g->positions + 3 * (size_t)(base + k));
        if (mesh->mTextureCoords[0]) {
            g->uvs[2 * (size_t)(base + k)] = mesh->mTextureCoords[0][v].x;
            g->uvs[2 * (size_t)(base + k) + 1] = mesh->mTextureCoords[0][v].y;
        } else {
            g->uvs[2 * (size_t)(base + k)] = g->uvs[2 * (size_t)(base + k) + 1] = 0.0f;
        }
        /* assimp's texture v runs up (OpenGL); the lightmap's v runs down like glTF's */
        g->uvs2[2 * (size_t)(base + k)] = mesh->mTextureCoords[1] ? mesh->mTextureCoords[1][v].x : 0.0f;
        g->uvs2[2 * (size_t)(base + k) + 1] = mesh->mTextureCoords[1] ? 1.0f - mesh->mTextureCoords[1][v].y : 0.0f;
    }
    if (mesh->mTextureCoords[0]) g->any_uv = 1;
    g->all_uv2 = (g->meshes_added == 0 || g->all_uv2) && mesh->mTextureCoords[1] != NULL;
    g->meshes_added++;
    g->vertex_count += kept;
    /* a mirroring transform flips the winding */
    det = m->a1 * (m->b2 * m->c3 - m->b3 * m->c2) - m->a2 * (m->b1 * m->c3 - m->b3 * m->c1) +
          m->a3 * (m->b1 * m->c2 - m->b2 * m->c1);
    for (f = 0; f < mesh->mNumFaces; ++f)
        if (mesh->mFaces[f].mNumIndices == 3) ++tri;
    if (g->triangle_count + tri > g->triangle_cap) {
        while (g->triangle_count + tri > g->triangle_cap) g->triangle_cap = g->triangle_cap ? 2 * g->triangle_cap : 256;
        g->indices = (uint32_t *)xrealloc(g->indices, sizeof(uint32_t) * 3 * g->triangle_cap);
        g->material_ids = (uint32_t *)xrealloc(g->material_ids, sizeof(uint32_t) * g->triangle_cap);
    }
    for (f = 0; f < mesh->mNumFaces; ++f) {
        const struct aiFace *face = &mesh->mFaces[f];
        uint32_t *ix;
        if (face->mNumIndices != 3) continue;
        ix = g->indices + 3 * (size_t)g->triangle_count;
        if (face->mIndices[0] >= mesh->mNumVertices || face->mIndices[1] >= mesh->mNumVertices ||
            face->mIndices[2] >= mesh->mNumVertices) {
            ++ws->bad_indices; /* assimp checks; counted should one slip through */
            continue;
        }
        if (mesh->mNormals && mesh->mMaterialIndex < ws->st->material_count) {
            /* in the mesh's own space: a mirroring transform flips winding and normals alike */
            const struct aiVector3D *a = &mesh->mVertices[face->mIndices[0]], *b = &mesh->mVertices[face->mIndices[1]],
                                    *c = &mesh->mVertices[face->mIndices[2]];
            double e1[3], e2[3], dot = 0.0;
            int q;
            e1[0] = (double)b->x - a->x, e1[1] = (double)b->y - a->y, e1[2] = (double)b->z - a->z;
            e2[0] = (double)c->x - a->x, e2[1] = (double)c->y - a->y, e2[2] = (double)c->z - a->z;
            for (q = 0; q < 3; ++q) {
                const struct aiVector3D *n = &mesh->mNormals[face->mIndices[q]];
                dot += (e1[1] * e2[2] - e1[2] * e2[1]) * n->x + (e1[2] * e2[0] - e1[0] * e2[2]) * n->y +
                       (e1[0] * e2[1] - e1[1] * e2[0]) * n->z;
            }
            ws->st->wound_total[mesh->mMaterialIndex]++;
            if (dot < 0.0) ws->st->wound_against[mesh->mMaterialIndex]++;
        }
        ix[0] = base + remap[face->mIndices[0]];
        ix[1] = base + remap[det < 0 ? face->mIndices[2] : face->mIndices[1]];
        ix[2] = base + remap[det < 0 ? face->mIndices[1] : face->mIndices[2]];
        g->material_ids[g->triangle_count++] = mesh->mMaterialIndex;
    }
    free(remap);
    free(kept_of);
}

static void walk(walk_state *ws, const struct aiNode *node, const struct aiMatrix4x4 *parent)
{
    struct aiMatrix4x4 m;
    uint32_t i;
    mat_mul(parent, &node->mTransformation, &m);
    for (i = 0; i < node->mNumMeshes; ++i)
        if (node->mMeshes[i] < ws->sc->mNumMeshes) add_mesh(ws, ws->sc->mMeshes[node->mMeshes[i]], node, &m);
    /* lights and the first camera named like this node */
    for (i = 0; i < ws->sc->mNumLights; ++i) {
        const struct aiLight *l = ws->sc->mLights[i];
        rad_light *rl;
        float p[3], d[3];
        if (strcmp(l->mName.data, node->mName.data) != 0) continue;
        if (l->mType != aiLightSource_POINT && l->mType != aiLightSource_SPOT && l->mType != aiLightSource_DIRECTIONAL) {
            fprintf(stderr, "rad: warning: light '%s' of an unsupported type is ignored\n", l->mName.data);
            continue;
        }
        ws->out->lights = (rad_light *)xrealloc(ws->out->lights, sizeof(rad_light) * (ws->out->light_count + 1));
        rl = &ws->out->lights[ws->out->light_count++];
        memset(rl, 0, sizeof *rl);
        p[0] = l->mPosition.x, p[1] = l->mPosition.y, p[2] = l->mPosition.z;
        d[0] = l->mDirection.x, d[1] = l->mDirection.y, d[2] = l->mDirection.z;
        xform_point(&m, p, rl->position);
        xform_dir(&m, d, rl->direction);
        rl->color[0] = l->mColorDiffuse.r, rl->color[1] = l->mColorDiffuse.g, rl->color[2] = l->mColorDiffuse.b;
        rl->falloff = RAD_FALLOFF_QUADRATIC;
        if (l->mType == aiLightSource_POINT) rl->type = RAD_LIGHT_POINT;
        else if (l->mType == aiLightSource_DIRECTIONAL) rl->type = RAD_LIGHT_DIRECTIONAL;
        else {
            rl->type = RAD_LIGHT_SPOT;
            rl->inner_angle = 0.5f * l->mAngleInnerCone; /* assimp: full cone angles */
            rl->outer_angle = 0.5f * l->mAngleOuterCone;
            if (!(rl->outer_angle > rl->inner_angle)) rl->outer_angle = rl->inner_angle + 1e-3f;
        }
    }
    if (!ws->camera_done)
        for (i = 0; i < ws->sc->mNumCameras; ++i) {
            const struct aiCamera *c = ws->sc->mCameras[i];
            float p[3], t[3], u[3], pos[3], dir[3], up[3], aspect;
            if (strcmp(c->mName.data, node->mName.data) != 0) continue;
            p[0] = c->mPosition.x, p[1] = c->mPosition.y, p[2] = c->mPosition.z;
            t[0] = c->mLookAt.x, t[1] = c->mLookAt.y, t[2] = c->mLookAt.z;
            u[0] = c->mUp.x, u[1] = c->mUp.y, u[2] = c->mUp.z;
            aspect = c->mAspect > 0.0f ? c->mAspect : 1.0f;
            /* mHorizontalFOV is half the horizontal angle */
            ws->out->camera.fov_y_degrees = 2.0f * atanf(tanf(c->mHorizontalFOV) / aspect) * 57.29577951f;
            if (ws->gltf) {
                /* glTF: the camera sits at its node's origin looking along -Z, +Y up, with the
                   vertical angle yfov. assimp 5.2 copies the node's translation into mPosition
                   (applied twice with the node's matrix) and gives yfov x aspect as
                   mHorizontalFOV (the whole angle), so both come from the file instead. */
                float yfov = gltf_camera_yfov(ws->gltf, node->mName.data);
                p[0] = p[1] = p[2] = 0.0f;
                t[0] = t[1] = 0.0f, t[2] = -1.0f;
                u[0] = 0.0f, u[1] = 1.0f, u[2] = 0.0f;
                ws->out->camera.fov_y_degrees = (yfov > 0.0f ? yfov : c->mHorizontalFOV / aspect) * 57.29577951f;
            }
            xform_point(&m, p, pos);
            xform_dir(&m, t, dir);
            xform_dir(&m, u, up);
            memcpy(ws->out->camera.position, pos, sizeof pos);
            ws->out->camera.target[0] = pos[0] + dir[0];
            ws->out->camera.target[1] = pos[1] + dir[1];
            ws->out->camera.target[2] = pos[2] + dir[2];
            memcpy(ws->out->camera.up, up, sizeof up);
            ws->out->has_camera = 1;
            ws->camera_done = 1;
            break;
        }
    for (i = 0; i < node->mNumChildren; ++i) walk(ws, node->mChildren[i], &m);
}

static void default_camera(const float bmin[3], const float bmax[3], rad_camera *cam)
{
    float c[3], r = 0.0f, d;
    int k;
    for (k = 0; k < 3; ++k) {
        c[k] = 0.5f * (bmin[k] + bmax[k]);
        r += (bmax[k] - bmin[k]) * (bmax[k] - bmin[k]);
    }
    r = 0.5f * sqrtf(r);
    cam->fov_y_degrees = 39.3077f;
    d = r / sinf(0.5f * cam->fov_y_degrees / 57.29577951f);
    /* in front of the scene, looking along +z (like the Cornell camera), y up */
    cam->position[0] = c[0], cam->position[1] = c[1], cam->position[2] = c[2] - d;
    memcpy(cam->target, c, sizeof c);
    cam->up[0] = 0.0f, cam->up[1] = 1.0f, cam->up[2] = 0.0f;
}

/* up to n numbers of JSON array a into out; how many were read */
static int js_floats(const char *a, float *out, int n)
{
    int k;
    const char *v;
    for (k = 0; k < n && (v = js_at(a, (unsigned)k)) != NULL; ++k) out[k] = (float)strtod(v, NULL);
    return k;
}

/* 1 when glTF material m has the base colour and emissive factor of assimp's material am */
static int gltf_same_factors(const char *m, const struct aiMaterial *am)
{
    float base[4] = {1, 1, 1, 1}, em[3] = {0, 0, 0};
    const char *pbr = js_get(m, "pbrMetallicRoughness"), *v;
    struct aiColor4D c;
    int k;
    if (pbr && (v = js_get(pbr, "baseColorFactor")) != NULL) js_floats(v, base, 4);
    if ((v = js_get(m, "emissiveFactor")) != NULL) js_floats(v, em, 3);
    if (aiGetMaterialColor(am, AI_MATKEY_BASE_COLOR, &c) == aiReturn_SUCCESS)
        for (k = 0; k < 3; ++k)
            if (!(fabsf((&c.r)[k] - base[k]) <= 1e-5f)) return 0;
    if (aiGetMaterialColor(am, AI_MATKEY_COLOR_EMISSIVE, &c) != aiReturn_SUCCESS) c.r = c.g = c.b = 0.0f;
    for (k = 0; k < 3; ++k)
        if (!(fabsf((&c.r)[k] - em[k]) <= 1e-5f)) return 0;
    return 1;
}

/* The glTF material (its JSON object) that assimp's material i is, or NULL (assimp's default
   material). assimp does not keep the file's order (it numbers materials as meshes first use
   them), so a named material is found by its name; an unnamed one among the unnamed by its
   base colour and emissive factor. *ambiguous: set when unnamed candidates alike in both
   differ in their emissive strength (which one is which cannot be told). */
static const char *material_json(const char *json, uint32_t i, const char *name, const struct aiMaterial *am, int *ambiguous)
{
    const char *m, *nm, *found = NULL;
    char jn[256];
    unsigned j;
    *ambiguous = 0;
    if (!json) return NULL;
    for (j = 0; (m = gltf_material(json, j)) != NULL; ++j) {
        nm = js_get(m, "name");
        if (nm) js_string(nm, jn, sizeof jn);
        else jn[0] = 0;
        if (name[0]) {
            if (!strcmp(jn, name)) return m;
            continue;
        }
        if (jn[0] || !gltf_same_factors(m, am)) continue;
        if (!found || j == i) {
            if (found && gltf_emissive_strength(found) != gltf_emissive_strength(m)) *ambiguous = 1;
            found = m;
        } else if (gltf_emissive_strength(found) != gltf_emissive_strength(m)) {
            *ambiguous = 1;
        }
    }
    return found;
}

/* KHR_texture_transform of texture-info object ti as the matrix of texture_sample, 0 when ti
   has none. glTF: uv' = T(offset) R(rotation) S(scale) uv, R = [cos sin; -sin cos]. */
static int gltf_texture_transform(const char *ti, float xf[6])
{
    const char *e = ti ? js_get(ti, "extensions") : NULL, *x = e ? js_get(e, "KHR_texture_transform") : NULL, *v;
    float off[2] = {0, 0}, sc[2] = {1, 1}, r = 0.0f, c, s;
    if (!x) return 0;
    if ((v = js_get(x, "offset")) != NULL) js_floats(v, off, 2);
    if ((v = js_get(x, "scale")) != NULL) js_floats(v, sc, 2);
    if ((v = js_get(x, "rotation")) != NULL) r = (float)strtod(v, NULL);
    c = cosf(r), s = sinf(r);
    xf[0] = c * sc[0], xf[1] = s * sc[1], xf[2] = off[0];
    xf[3] = -s * sc[0], xf[4] = c * sc[1], xf[5] = off[1];
    return 1;
}

/* gives texture *id (index+1) the transform xf: a new entry (its own copy of the texels)
   unless the texture already has exactly it */
static void texture_with_transform(imp_storage *st, uint32_t *id, const float xf[6])
{
    imp_texture *t;
    size_t n;
    uint32_t i;
    if (!*id) return;
    for (i = 0; i < st->texture_count; ++i) { /* the same image and transform already made */
        const imp_texture *o = &st->textures[i];
        if (o->has_xf && !memcmp(o->xf, xf, sizeof o->xf) && o->rgb && st->textures[*id - 1].rgb &&
            !strcmp(o->path, st->textures[*id - 1].path)) {
            *id = i + 1;
            return;
        }
    }
    st->textures = (imp_texture *)xrealloc(st->textures, sizeof(imp_texture) * (st->texture_count + 1));
    t = &st->textures[st->texture_count];
    *t = st->textures[*id - 1];
    n = 3 * (size_t)t->width * (size_t)t->height;
    t->rgb = (float *)xrealloc(NULL, sizeof(float) * n);
    memcpy(t->rgb, st->textures[*id - 1].rgb, sizeof(float) * n);
    if (t->alpha) { /* its own alpha too: every entry frees its own */
        t->alpha = (float *)xrealloc(NULL, sizeof(float) * (n / 3));
        memcpy(t->alpha, st->textures[*id - 1].alpha, sizeof(float) * (n / 3));
    }
    t->has_xf = 1;
    memcpy(t->xf, xf, sizeof t->xf);
    *id = ++st->texture_count;
}

/* KHR_texture_transform on glTF material gm's base-colour (with its alpha, the cutout's opacity)
   and emissive textures */
static void gltf_apply_transforms(imp_storage *st, rad_material *m, const char *gm)
{
    const char *pbr = gm ? js_get(gm, "pbrMetallicRoughness") : NULL;
    float xf[6];
    if (pbr && gltf_texture_transform(js_get(pbr, "baseColorTexture"), xf)) {
        if (m->texture) texture_with_transform(st, &m->texture, xf);
        if (m->opacity_texture) texture_with_transform(st, &m->opacity_texture, xf); /* the same image's alpha */
    }
    if (m->emission_texture && gltf_texture_transform(js_get(gm, "emissiveTexture"), xf))
        texture_with_transform(st, &m->emission_texture, xf);
}

static const char *texture_name(const imp_storage *st, uint32_t id)
{
    const char *p = id && id <= st->texture_count ? st->textures[id - 1].path : "";
    return !strncmp(p, "emissive:", 9) ? p + 9 : p;
}

/* What material i became and what of it was left out, for `rad info` (several lines).
   gm: its glTF JSON object (is_gltf: the file is glTF; gm NULL there: assimp's own). */
static void material_report(imp_storage *st, const struct aiMaterial *am, uint32_t i, const char *gm, int is_gltf)
{
    static const struct { enum aiTextureType type; const char *what; } other[] = {
        {aiTextureType_NORMALS, "normal map"}, {aiTextureType_HEIGHT, "bump/height map"},
        {aiTextureType_SPECULAR, "specular map"}, {aiTextureType_SHININESS, "shininess map"},
        {aiTextureType_AMBIENT, "ambient map"},
        {aiTextureType_DISPLACEMENT, "displacement map"}, {aiTextureType_LIGHTMAP, "lightmap/occlusion map"},
        {aiTextureType_REFLECTION, "reflection map"}, {aiTextureType_METALNESS, "metalness map"},
        {aiTextureType_DIFFUSE_ROUGHNESS, "roughness map"}, {aiTextureType_UNKNOWN, "unknown-type map"}};
    const rad_material *m = &st->materials[i];
    char **r = &st->material_reports[i], buf[512];
    struct aiColor4D c;
    struct aiString tp;
    unsigned k;
    snprintf(buf, sizeof buf, "%g %g %g", (double)m->albedo[0], (double)m->albedo[1], (double)m->albedo[2]);
    if (m->texture) rep_add(r, "  albedo: texture '%s' x %s", texture_name(st, m->texture), buf);
    else rep_add(r, "  albedo: %s%s", buf, NULL);
    if (m->emission[0] > 0.0f || m->emission[1] > 0.0f || m->emission[2] > 0.0f) {
        double strength = gm ? gltf_emissive_strength(gm) : -1.0;
        char f[200] = "";
        if (strength >= 0.0 && aiGetMaterialColor(am, AI_MATKEY_COLOR_EMISSIVE, &c) == aiReturn_SUCCESS)
            snprintf(f, sizeof f, " (emissiveFactor %g %g %g x KHR_materials_emissive_strength %g)", (double)c.r, (double)c.g,
                     (double)c.b, strength);
        snprintf(buf, sizeof buf, "%g %g %g%s", (double)m->emission[0], (double)m->emission[1], (double)m->emission[2], f);
        if (m->emission_texture) rep_add(r, "  emission (radiance): texture '%s' x %s", texture_name(st, m->emission_texture), buf);
        else rep_add(r, "  emission (radiance): %s%s", buf, NULL);
    } else if (aiGetMaterialTexture(am, aiTextureType_EMISSIVE, 0, &tp, NULL, NULL, NULL, NULL, NULL, NULL) == aiReturn_SUCCESS) {
        rep_add(r, "  emission texture '%s': ignored (the emission factor, Ke or emissiveFactor, is 0)%s", tp.data, NULL);
    }
    if (is_gltf && gm) gltf_report(gm, r);
    else if (is_gltf) rep_add(r, "  (not in the file's materials: the importer's default)%s%s", NULL, NULL);
    if (!is_gltf && !m->opacity_texture) { /* a constant transparency is not a cutout */
        ai_real d = 1;
        unsigned int one = 1;
        if (aiGetMaterialFloatArray(am, AI_MATKEY_OPACITY, &d, &one) == aiReturn_SUCCESS && d < 1) {
            snprintf(buf, sizeof buf, "%g", (double)d);
            rep_add(r, "  ignored: opacity d %s (a constant transparency is not a cutout: the surface is opaque)%s", buf, NULL);
        }
    }
    if (!is_gltf) /* other formats: the texture kinds assimp found that radiosity does not use */
        for (k = 0; k < sizeof other / sizeof other[0]; ++k)
            if (aiGetMaterialTextureCount(am, other[k].type) > 0 &&
                aiGetMaterialTexture(am, other[k].type, 0, &tp, NULL, NULL, NULL, NULL, NULL, NULL) == aiReturn_SUCCESS)
                rep_add(r, "  ignored: %s '%s' (not diffuse)", other[k].what, tp.data);
}

int tool_is_scene_path(const char *path)
{
    const char *dot = path ? strrchr(path, '.') : NULL;
    if (path && !strcmp(path, "cornell")) return 1;
    return dot && strcmp(dot, ".radb") != 0 && aiIsExtensionSupported(dot) == AI_TRUE;
}

tool_two_sided_mode tool_two_sided = TOOL_TWO_SIDED_AUTO;

/* A one-sided triangle is taken as wound: its front is the counter-clockwise side, whatever
   its shading normals say. When many disagree with their normals the file most likely has
   mixed windings (its surfaces would show black backs), so say so and name the remedy. */
static void warn_mixed_windings(const imp_storage *st, const char *file)
{
    uint64_t against = 0, total = 0;
    uint32_t i;
    for (i = 0; i < st->material_count; ++i)
        if (!st->materials[i].two_sided) {
            against += st->wound_against[i];
            total += st->wound_total[i];
        }
    if (total && against * 100u >= total)
        fprintf(stderr, "rad: warning: '%s': %llu of %llu one-sided triangles are wound against their normals (mixed "
                "windings?): their fronts face away from the normals; --two-sided all makes every surface two-sided\n",
                file, (unsigned long long)against, (unsigned long long)total);
}

int tool_two_sided_parse(const char *text, tool_two_sided_mode *out)
{
    if (!text) return 1;
    if (!strcmp(text, "auto")) *out = TOOL_TWO_SIDED_AUTO;
    else if (!strcmp(text, "all")) *out = TOOL_TWO_SIDED_ALL;
    else if (!strcmp(text, "none")) *out = TOOL_TWO_SIDED_NONE;
    else return 1;
    return 0;
}

/* The built-in Cornell box ("cornell"): rad_cornell_box's static tables, copied only when --two-sided all sets the flag. */
static int load_cornell(tool_scene *out, char *err, size_t errlen)
{
    imp_storage *st;
    uint32_t i;
    st = (imp_storage *)calloc(1, sizeof *st);
    if (!st) return set_err(err, errlen, "out of memory%s%s", NULL, NULL), 1;
    static const char *const cornell_names[4] = {"white", "red", "green", "light"};
    st->builtin = 1;
    rad_cornell_box(&out->desc, &out->camera);
    if (out->desc.material_count == 4) out->material_names = cornell_names;
    out->has_camera = 1;
    out->storage = st;
    if (tool_two_sided == TOOL_TWO_SIDED_ALL) {
        /* the built-in materials are static: a copy takes the flag */
        st->material_count = out->desc.material_count;
        st->materials = (rad_material *)xrealloc(NULL, sizeof(rad_material) * st->material_count);
        memcpy(st->materials, out->desc.materials, sizeof(rad_material) * st->material_count);
        for (i = 0; i < st->material_count; ++i) st->materials[i].two_sided = 1;
        out->desc.materials = st->materials;
    }
    return 0;
}

/* Imports the file with assimp, or NULL with err saying why (unread extensions, a broken file, no meshes). */
static const struct aiScene *import_checked(const char *path_or_name, char *err, size_t errlen)
{
    const struct aiScene *sc;
    sc = import_logged(path_or_name, aiProcess_Triangulate | aiProcess_SortByPType); /* welding: weld_mesh */
    if (!sc) {
        char exts[512];
        unsigned ne = gltf_required_extensions(path_or_name, exts, sizeof exts);
        if (ne && err && errlen)
            snprintf(err, errlen,
                     "cannot import '%s': %s; the file requires the glTF extension%s %s (its extensionsRequired), "
                     "which this importer (assimp %u.%u.%u) could not read",
                     path_or_name, aiGetErrorString(), ne > 1 ? "s" : "", exts, aiGetVersionMajor(), aiGetVersionMinor(),
                     aiGetVersionPatch());
        else set_err(err, errlen, "cannot import '%s': %s", path_or_name, aiGetErrorString());
        return NULL;
    }
    if (g_log.fatal[0]) {
        set_err(err, errlen, "'%s' is broken: assimp: %s", path_or_name, g_log.fatal);
        aiReleaseImport(sc);
        return NULL;
    }
    if (!sc->mRootNode || sc->mNumMeshes == 0) {
        set_err(err, errlen, "'%s' has no meshes%s", path_or_name, NULL);
        aiReleaseImport(sc);
        return NULL;
    }
    return sc;
}

/* Allocates the per-material tables (materials, names, winding counts, reports) and returns the clamped flags. */
static unsigned char *material_tables(imp_storage *st, const struct aiScene *sc, tool_scene *out)
{
    unsigned char *clamped;
    uint32_t i;
    st->material_count = sc->mNumMaterials ? sc->mNumMaterials : 1;
    st->materials = (rad_material *)xrealloc(NULL, sizeof(rad_material) * st->material_count);
    memset(st->materials, 0, sizeof(rad_material) * st->material_count);
    st->material_names = (char **)xrealloc(NULL, sizeof(char *) * st->material_count);
    st->wound_against = (uint64_t *)xrealloc(NULL, sizeof(uint64_t) * st->material_count);
    st->wound_total = (uint64_t *)xrealloc(NULL, sizeof(uint64_t) * st->material_count);
    memset(st->wound_against, 0, sizeof(uint64_t) * st->material_count);
    memset(st->wound_total, 0, sizeof(uint64_t) * st->material_count);
    clamped = (unsigned char *)xrealloc(NULL, st->material_count);
    memset(clamped, 0, st->material_count);
    for (i = 0; i < st->material_count; ++i) {
        struct aiString mname;
        if (i >= sc->mNumMaterials || aiGetMaterialString(sc->mMaterials[i], AI_MATKEY_NAME, &mname) != aiReturn_SUCCESS)
            mname.length = 0, mname.data[0] = 0;
        st->material_names[i] = xstrdup(mname.data);
    }
    out->material_names = (const char *const *)st->material_names;
    st->material_reports = (char **)xrealloc(NULL, sizeof(char *) * st->material_count);
    memset(st->material_reports, 0, sizeof(char *) * st->material_count);
    out->material_reports = (const char *const *)st->material_reports;
    return clamped;
}

/* Converts every material (grey for assimp's missing one); 1 with err set when one cannot be told or converted. */
static int convert_materials(imp_storage *st, const struct aiScene *sc, const char *path_or_name, const char *json,
                             unsigned char *clamped, char *err, size_t errlen)
{
    uint32_t i;
    for (i = 0; i < st->material_count; ++i) {
        if (i < sc->mNumMaterials) {
            int ambiguous = 0;
            const char *gm = material_json(json, i, st->material_names[i], sc->mMaterials[i], &ambiguous);
            if (ambiguous) {
                char n[32];
                snprintf(n, sizeof n, "%u", i);
                set_err(err, errlen,
                        "'%s': material %s is unnamed, and so are other glTF materials of the same base colour and emissive "
                        "factor but another KHR_materials_emissive_strength: which is which cannot be told (give the "
                        "materials names)",
                        path_or_name, n);
                return 1;
            }
            if (convert_material(st, sc, path_or_name, sc->mMaterials[i], i, gltf_emissive_strength(gm), json ? gm : NULL,
                                 &st->materials[i],
                                 &clamped[i], err, errlen)) {
                return 1;
            }
            gltf_apply_transforms(st, &st->materials[i], gm);
            material_report(st, sc->mMaterials[i], i, json ? gm : NULL, json != NULL);
        } else st->materials[i].albedo[0] = st->materials[i].albedo[1] = st->materials[i].albedo[2] = 0.5f;
    }
    return 0;
}

/* One warning for the first clamped material, except assimp's default material when no
   triangle uses it: assimp adds one to every glTF (base colour 1, always clamped) and a
   "DefaultMaterial" to every OBJ, and warned about it where the file's own materials
   were fine. Frees clamped. */
static void warn_clamped(imp_storage *st, unsigned char *clamped)
{
    uint32_t i;
    {
        unsigned char *used = (unsigned char *)xrealloc(NULL, st->material_count);
        uint32_t g, t;
        memset(used, 0, st->material_count);
        for (g = 0; g < st->group_count; ++g)
            for (t = 0; t < st->groups[g].triangle_count; ++t)
                if (st->groups[g].material_ids[t] < st->material_count) used[st->groups[g].material_ids[t]] = 1;
        for (i = 0; i < st->material_count; ++i) {
            const char *mn = st->material_names[i];
            if (!clamped[i] || (!used[i] && (!mn[0] || !strcmp(mn, AI_DEFAULT_MATERIAL_NAME)))) continue;
            fprintf(stderr, "rad: warning: material %u '%s'%s: albedo clamped into [0, %g] (radiosity needs albedo < 1)\n", i,
                    mn, !mn[0] || !strcmp(mn, AI_DEFAULT_MATERIAL_NAME) ? " (assimp's default material)" : "",
                    (double)ALBEDO_MAX);
            break;
        }
        free(used);
        free(clamped);
    }
}

/* One rad_mesh_desc per imported group (uvs only where a textured material needs them); returns the triangle count and
   grows bmin/bmax over the vertices. */
static uint32_t build_meshes(imp_storage *st, float bmin[3], float bmax[3])
{
    uint32_t i, k, tris = 0;
    st->meshes = (rad_mesh_desc *)xrealloc(NULL, sizeof(rad_mesh_desc) * (st->group_count ? st->group_count : 1));
    memset(st->meshes, 0, sizeof(rad_mesh_desc) * (st->group_count ? st->group_count : 1));
    for (i = 0; i < st->group_count; ++i) {
        imp_group *g = &st->groups[i];
        rad_mesh_desc *md = &st->meshes[i];
        uint32_t t;
        md->name = g->name;
        md->positions = g->positions;
        md->vertex_count = g->vertex_count;
        md->indices = g->indices;
        md->triangle_count = g->triangle_count;
        md->material_ids = g->material_ids;
        if (g->all_uv2) md->lightmap_uvs = g->uvs2;
        for (t = 0; t < g->triangle_count; ++t)
            if (st->materials[g->material_ids[t]].texture || st->materials[g->material_ids[t]].emission_texture ||
                st->materials[g->material_ids[t]].opacity_texture) {
                md->uvs = g->uvs; /* zeros when the file had none */
                if (!g->any_uv) fprintf(stderr, "rad: warning: mesh '%s' has a textured material but no uvs\n", g->name);
                break;
            }
        tris += g->triangle_count;
        for (k = 0; k < 3 * g->vertex_count; ++k) {
            float v = g->positions[k];
            if (v < bmin[k % 3]) bmin[k % 3] = v;
            if (v > bmax[k % 3]) bmax[k % 3] = v;
        }
    }
    return tris;
}

/* Applies --two-sided to every material and adds its sides and cutout to the material's report. */
static void finish_materials(imp_storage *st)
{
    uint32_t i;
    for (i = 0; i < st->material_count; ++i) {
        if (tool_two_sided == TOOL_TWO_SIDED_ALL) st->materials[i].two_sided = 1;
        if (tool_two_sided == TOOL_TWO_SIDED_NONE) st->materials[i].two_sided = 0;
        if (st->material_reports) {
            const rad_material *m = &st->materials[i];
            rep_add(&st->material_reports[i], "  sides: %s", m->two_sided ? "two (each side receives, reflects and emits)"
                                                                          : "one (front counter-clockwise, the back absorbs)", NULL);
            if (m->opacity_texture) {
                char what[400];
                const imp_texture *t = &st->textures[m->opacity_texture - 1];
                const char *p = strchr(strchr(strchr(t->path, ':') + 1, ':') + 1, ':') + 1;
                snprintf(what, sizeof what, "alpha %s%s%s x %g >= %g (rays pass the rest; patches keep their opaque part)",
                         p[0] ? "of '" : "", p[0] ? p : "constant 1", p[0] ? (t->has_alpha ? "' (alpha channel)" : "' (grey)") : "",
                         (double)t->alpha_scale, (double)m->alpha_cutoff);
                rep_add(&st->material_reports[i], "  cutout: %s%s", what, NULL);
            } else {
                rep_add(&st->material_reports[i], "  cutout: none (opaque)%s%s", NULL, NULL);
            }
        }
    }
}

int tool_load_scene(const char *path_or_name, tool_scene *out, char *err, size_t errlen)
{
    const struct aiScene *sc;
    imp_storage *st;
    walk_state ws;
    struct aiMatrix4x4 id;
    uint32_t tris = 0;
    unsigned char *clamped = NULL;
    char *json = NULL;
    float bmin[3] = {1e30f, 1e30f, 1e30f}, bmax[3] = {-1e30f, -1e30f, -1e30f};
    memset(out, 0, sizeof *out);
    if (!path_or_name || !*path_or_name) {
        set_err(err, errlen, "no scene given%s%s", NULL, NULL);
        return 1;
    }
    if (!strcmp(path_or_name, "cornell")) return load_cornell(out, err, errlen);
    sc = import_checked(path_or_name, err, errlen);
    if (!sc) return 1;
    st = (imp_storage *)calloc(1, sizeof *st);
    if (!st) {
        aiReleaseImport(sc);
        return set_err(err, errlen, "out of memory%s%s", NULL, NULL), 1;
    }
    out->storage = st;
    /* materials */
    clamped = material_tables(st, sc, out);
    json = gltf_json(path_or_name);
    if (convert_materials(st, sc, path_or_name, json, clamped, err, errlen)) {
        free(clamped);
        free(json);
        aiReleaseImport(sc);
        tool_free_scene(out);
        return 1;
    }
    /* geometry, lights, camera */
    memset(&id, 0, sizeof id);
    id.a1 = id.b2 = id.c3 = id.d4 = 1.0f;
    memset(&ws, 0, sizeof ws);
    ws.st = st;
    ws.sc = sc;
    ws.out = out;
    ws.gltf = json;
    walk(&ws, sc->mRootNode, &id);
    free(json);
    aiReleaseImport(sc);
    warn_clamped(st, clamped);
    if (ws.bad_indices) {
        char n[32];
        snprintf(n, sizeof n, "%u", ws.bad_indices);
        set_err(err, errlen, "'%s' is broken: %s faces have an index past their mesh's vertices", path_or_name, n);
        tool_free_scene(out);
        return 1;
    }
    tris = build_meshes(st, bmin, bmax);
    if (tris == 0) {
        set_err(err, errlen, "'%s' has no triangles%s", path_or_name, NULL);
        tool_free_scene(out);
        return 1;
    }
    out->desc.meshes = st->meshes;
    out->desc.mesh_count = st->group_count;
    out->desc.materials = st->materials;
    out->desc.material_count = st->material_count;
    out->desc.albedo_lookup = st->texture_count ? albedo_lookup : NULL;
    out->desc.albedo_user = st;
    out->desc.emission_lookup = st->any_emission_texture ? emission_lookup : NULL;
    out->desc.emission_user = st;
    out->desc.opacity_lookup = st->any_cutout ? opacity_lookup : NULL;
    out->desc.opacity_user = st;
    out->desc.flags = RAD_SCENE_SKIP_DEGENERATE;
    finish_materials(st);
    warn_mixed_windings(st, path_or_name);
    add_input(st, path_or_name);
    add_obj_mtllibs(st, path_or_name);
    out->input_files = (const char *const *)st->inputs;
    out->input_file_count = st->input_count;
    if (!out->has_camera) default_camera(bmin, bmax, &out->camera);
    return 0;
}
