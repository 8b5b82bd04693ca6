/* gltf_write.c - a baked lightmap and its scene as glTF 2.0 for engines: `rad lightmap SCENE
   -o OUT.glb|OUT.gltf`.

   What is written (the convention is documented in docs/engine-formats.md):
   - one node and mesh per scene mesh, one primitive per material in it, not indexed (three
     vertices a triangle: the scene is a triangle soup with per-triangle normals), with
     POSITION, NORMAL (the triangle's), TEXCOORD_0 (the scene's uvs; without them the lightmap
     uvs again, as glTF numbers uv sets without gaps) and
     TEXCOORD_1 (the lightmap uvs the bake used: the file's second set or the unwrap's);
     a two-sided material's two sides are two one-sided triangles with their own lightmap uvs;
   - materials as their constant colours: baseColorFactor = albedo, metallic 0, roughness 1,
     emissiveFactor with KHR_materials_emissive_strength for radiance above 1;
   - the lightmap (RGB irradiance, W m^-2) as one PNG image inside the binary buffer: 8-bit
     sRGB of irradiance / scale, with scale the largest texel value of the atlas, so that
     irradiance = scale x sRGB-decode(texel); each material names it in its extras as
     "RAD_lightmap": { "texture", "texCoord": 1, "encoding": "srgb", "scale", "hdr" };
   - the HDR copy beside the file (OUT.lightmap.exr with OpenEXR support, else
     OUT.lightmap.pfm), linear float irradiance, named in "hdr";
   - the camera of the view as a camera node (the file's camera, or the one rad trace picks).
   The GLB is a 12-byte header and two chunks, JSON then BIN, each padded to 4 bytes (glTF 2.0
   section 4.4); a .gltf keeps the same JSON with the buffer in OUT.bin beside it. */
#include "tool.h"
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#endif
#include <stb/stb_image_write.h> /* the implementation is in image.c */
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

/* a growable byte buffer; 'failed' once an allocation did not succeed */
typedef struct gw_buf {
    unsigned char *data;
    size_t size, cap;
    int failed;
} gw_buf;

static void gw_reserve(gw_buf *b, size_t more)
{
    size_t cap;
    unsigned char *p;
    if (b->failed) return;
    if (more > (size_t)-1 / 2 - b->size) { b->failed = 1; return; }
    if (b->size + more <= b->cap) return;
    cap = b->cap ? b->cap : 4096;
    while (cap < b->size + more) cap *= 2;
    p = (unsigned char *)realloc(b->data, cap);
    if (!p) { b->failed = 1; return; }
    b->data = p;
    b->cap = cap;
}

static void gw_put(gw_buf *b, const void *data, size_t n)
{
    gw_reserve(b, n);
    if (b->failed) return;
    memcpy(b->data + b->size, data, n);
    b->size += n;
}

static void gw_printf(gw_buf *b, const char *fmt, ...)
{
    va_list ap;
    int n;
    char small[256];
    va_start(ap, fmt);
    n = vsnprintf(small, sizeof small, fmt, ap);
    va_end(ap);
    if (n < 0) { b->failed = 1; return; }
    if ((size_t)n < sizeof small) { gw_put(b, small, (size_t)n); return; }
    gw_reserve(b, (size_t)n + 1);
    if (b->failed) return;
    va_start(ap, fmt);
    vsnprintf((char *)b->data + b->size, (size_t)n + 1, fmt, ap);
    va_end(ap);
    b->size += (size_t)n;
}

static void gw_align4(gw_buf *b, unsigned char fill)
{
    while (b->size % 4) gw_put(b, &fill, 1);
}

static void gw_u32(gw_buf *b, uint32_t v)
{
    unsigned char p[4];
    p[0] = (unsigned char)v, p[1] = (unsigned char)(v >> 8), p[2] = (unsigned char)(v >> 16), p[3] = (unsigned char)(v >> 24);
    gw_put(b, p, 4);
}

/* glTF stores floats little-endian: write them byte by byte whatever the host */
static void gw_f32(gw_buf *b, float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    gw_u32(b, u);
}

/* the length of the well-formed UTF-8 sequence at s (1 to 4), or 0 */
static int gw_utf8_length(const unsigned char *s)
{
    int n = s[0] < 0x80 ? 1 : (s[0] & 0xE0) == 0xC0 && s[0] >= 0xC2 ? 2 : (s[0] & 0xF0) == 0xE0 ? 3
          : (s[0] & 0xF8) == 0xF0 && s[0] <= 0xF4 ? 4 : 0, i;
    for (i = 1; i < n; ++i)
        if ((s[i] & 0xC0) != 0x80) return 0;
    return n;
}

/* a JSON string: quotes, backslashes and control characters escaped; a byte that is not part
   of well-formed UTF-8 (an OBJ's Latin-1 name) becomes '?', since JSON text is UTF-8 */
static void gw_string(gw_buf *b, const char *s)
{
    const unsigned char *p = (const unsigned char *)(s ? s : "");
    gw_put(b, "\"", 1);
    while (*p) {
        int n = gw_utf8_length(p);
        if (*p == '"' || *p == '\\') gw_printf(b, "\\%c", *p);
        else if (*p < 0x20) gw_printf(b, "\\u%04x", *p);
        else if (n == 0) gw_put(b, "?", 1);
        else gw_put(b, p, (size_t)n);
        p += n ? n : 1;
    }
    gw_put(b, "\"", 1);
}

/* a file name as a relative URI (RFC 3986): bytes outside the unreserved set percent-encoded */
static void gw_uri(gw_buf *b, const char *name)
{
    const unsigned char *p = (const unsigned char *)name;
    gw_put(b, "\"", 1);
    for (; *p; ++p) {
        if ((*p >= 'A' && *p <= 'Z') || (*p >= 'a' && *p <= 'z') || (*p >= '0' && *p <= '9') || *p == '-' || *p == '.' ||
            *p == '_' || *p == '~')
            gw_put(b, p, 1);
        else
            gw_printf(b, "%%%02X", *p);
    }
    gw_put(b, "\"", 1);
}

/* the file name of a path (what a .gltf or the extras refer to: files beside it) */
static const char *gw_base(const char *path)
{
    const char *s = strrchr(path, '/');
    return s ? s + 1 : path;
}

/* path with its extension replaced by 'ext' (".lightmap.exr", ".bin"); malloc'd */
static char *gw_sibling(const char *path, const char *ext)
{
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    size_t stem = (dot && (!slash || dot > slash)) ? (size_t)(dot - path) : strlen(path);
    char *out = (char *)tool_calloc(stem + strlen(ext) + 1, 1);
    memcpy(out, path, stem);
    memcpy(out + stem, ext, strlen(ext) + 1);
    return out;
}

static int gw_has_ext(const char *path, const char *ext)
{
    size_t n = strlen(path), e = strlen(ext), i;
    if (n < e) return 0;
    for (i = 0; i < e; ++i) {
        char c = path[n - e + i];
        if (c >= 'A' && c <= 'Z') c = (char)(c - 'A' + 'a');
        if (c != ext[i]) return 0;
    }
    return 1;
}

int tool_gltf_is_path(const char *path)
{
    return path && (gw_has_ext(path, ".glb") || gw_has_ext(path, ".gltf"));
}

char *tool_gltf_hdr_path(const char *path)
{
#ifdef TOOL_EXR
    return gw_sibling(path, ".lightmap.exr");
#else
    return gw_sibling(path, ".lightmap.pfm");
#endif
}

char *tool_gltf_bin_path(const char *path)
{
    return gw_has_ext(path, ".gltf") ? gw_sibling(path, ".bin") : NULL;
}

/* the unit quaternion (x, y, z, w) of a rotation matrix given by its columns */
static void gw_quat(const double X[3], const double Y[3], const double Z[3], double q[4])
{
    double tr = X[0] + Y[1] + Z[2], s;
    if (tr > 0.0) {
        s = 2.0 * sqrt(tr + 1.0);
        q[3] = 0.25 * s, q[0] = (Y[2] - Z[1]) / s, q[1] = (Z[0] - X[2]) / s, q[2] = (X[1] - Y[0]) / s;
    } else if (X[0] > Y[1] && X[0] > Z[2]) {
        s = 2.0 * sqrt(1.0 + X[0] - Y[1] - Z[2]);
        q[3] = (Y[2] - Z[1]) / s, q[0] = 0.25 * s, q[1] = (Y[0] + X[1]) / s, q[2] = (Z[0] + X[2]) / s;
    } else if (Y[1] > Z[2]) {
        s = 2.0 * sqrt(1.0 + Y[1] - X[0] - Z[2]);
        q[3] = (Z[0] - X[2]) / s, q[0] = (Y[0] + X[1]) / s, q[1] = 0.25 * s, q[2] = (Z[1] + Y[2]) / s;
    } else {
        s = 2.0 * sqrt(1.0 + Z[2] - X[0] - Y[1]);
        q[3] = (X[1] - Y[0]) / s, q[0] = (Z[0] + X[2]) / s, q[1] = (Z[1] + Y[2]) / s, q[2] = 0.25 * s;
    }
}

static void gw_cross(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1], o[1] = a[2] * b[0] - a[0] * b[2], o[2] = a[0] * b[1] - a[1] * b[0];
}

static int gw_normalize(double v[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(l > 0.0)) return 0;
    v[0] /= l, v[1] /= l, v[2] /= l;
    return 1;
}

/* glTF cameras look down their local -z with +y up; the rad camera's right is view x up
   (rad_camera_ray), so the node's rotation has the columns right, true up, -view */
static int gw_camera_rotation(const rad_camera *c, double q[4])
{
    double f[3], up[3], r[3], u[3], z[3];
    int i;
    for (i = 0; i < 3; ++i) f[i] = (double)c->target[i] - c->position[i], up[i] = c->up[i];
    if (!gw_normalize(f)) return 0;
    gw_cross(f, up, r);
    if (!gw_normalize(r)) return 0;
    gw_cross(r, f, u);
    for (i = 0; i < 3; ++i) z[i] = -f[i];
    gw_quat(r, u, z, q);
    return 1;
}

/* stb_image_write's sink into a gw_buf */
static void gw_png_sink(void *user, void *data, int size)
{
    if (size > 0) gw_put((gw_buf *)user, data, (size_t)size);
}

/* triangles ordered by (mesh, material) so that each primitive is a run */
static const uint32_t *gw_sort_meshes, *gw_sort_materials;
static int gw_tri_cmp(const void *pa, const void *pb)
{
    uint32_t a = *(const uint32_t *)pa, b = *(const uint32_t *)pb;
    const uint32_t *me = gw_sort_meshes, *ma = gw_sort_materials;
    if (me[a] != me[b]) return me[a] < me[b] ? -1 : 1;
    if (ma[a] != ma[b]) return ma[a] < ma[b] ? -1 : 1;
    return a < b ? -1 : a > b;
}

/* The lightmap as 8-bit sRGB of irradiance / scale, scale the atlas's largest value, PNG-encoded into png. */
static int gw_encode_lightmap(const tool_gltf_lightmap *in, size_t n_texels, unsigned char **ppx, gw_buf *png, float *pscale)
{
    const rad_lightmap *lm = in->lightmap;
    unsigned char *px;
    float scale = 0.0f;
    uint32_t i, texel;
    for (i = 0; i < 3 * (uint32_t)n_texels; ++i)
        if (in->values[i] > scale) scale = in->values[i];
    if (!(scale > 0.0f)) scale = 1.0f;
    *pscale = scale;
    px = *ppx = (unsigned char *)malloc(3 * n_texels);
    if (!px) return 1;
    for (texel = 0; texel < 3 * (uint32_t)n_texels; ++texel) px[texel] = tool_image_srgb8(in->values[texel] / scale);
    if (!stbi_write_png_to_func(gw_png_sink, png, (int)lm->width, (int)lm->height, 3, px, (int)lm->width * 3) || png->failed)
        return 1;
    free(px);
    *ppx = NULL;
    return 0;
}

/* Sorts the triangles by mesh and material and cuts them into primitives: runs of one mesh and material. */
static void gw_primitives(const rad_scene *s, const rad_scene *ms, uint32_t *order, uint32_t *run_start, uint32_t *run_count,
                          uint32_t *prim_mesh, uint32_t *pnprim, uint32_t *pnmesh)
{
    uint32_t t, nprim = 0, nmesh = 0;
    for (t = 0; t < s->triangle_count; ++t) order[t] = t;
    gw_sort_meshes = ms->meshes;
    gw_sort_materials = s->materials;
    qsort(order, s->triangle_count, sizeof(uint32_t), gw_tri_cmp);
    for (t = 0; t < s->triangle_count; ++t) {
        if (t == 0 || ms->meshes[order[t]] != ms->meshes[order[t - 1]] || s->materials[order[t]] != s->materials[order[t - 1]]) {
            run_start[nprim] = t;
            prim_mesh[nprim] = ms->meshes[order[t]];
            if (t == 0 || ms->meshes[order[t]] != ms->meshes[order[t - 1]]) ++nmesh;
            ++nprim;
        }
        ++run_count[nprim - 1];
    }
    *pnprim = nprim;
    *pnmesh = nmesh;
}

/* The binary buffer: per primitive its attribute arrays (each in its own tightly packed view), then the PNG. */
static void gw_binary(const rad_scene *s, const uint32_t *order, const uint32_t *run_start, const uint32_t *run_count,
                      uint32_t nprim, const gw_buf *png, gw_buf *pbin, size_t *poff_n, size_t *poff_uv1, size_t *poff_uv0,
                      uint32_t *ppng_view)
{
    gw_buf bin = *pbin;
    uint32_t i, k, t, prim;
    for (prim = 0; prim < nprim; ++prim)
        for (k = 0; k < run_count[prim]; ++k) {
            t = order[run_start[prim] + k];
            for (i = 0; i < 9; ++i) gw_f32(&bin, s->positions[9 * (size_t)t + i]);
        }
    /* (each attribute in its own tightly packed view; the layout loop below repeats the order) */
    {
        size_t off_n, off_uv1, off_uv0;
        off_n = bin.size;
        for (prim = 0; prim < nprim; ++prim)
            for (k = 0; k < run_count[prim]; ++k) {
                t = order[run_start[prim] + k];
                for (i = 0; i < 3; ++i) {
                    gw_f32(&bin, s->normals[3 * (size_t)t]);
                    gw_f32(&bin, s->normals[3 * (size_t)t + 1]);
                    gw_f32(&bin, s->normals[3 * (size_t)t + 2]);
                }
            }
        off_uv1 = bin.size;
        for (prim = 0; prim < nprim; ++prim)
            for (k = 0; k < run_count[prim]; ++k) {
                t = order[run_start[prim] + k];
                for (i = 0; i < 6; ++i) gw_f32(&bin, s->lightmap_uvs[6 * (size_t)t + i]);
            }
        off_uv0 = bin.size;
        for (prim = 0; prim < nprim; ++prim)
            for (k = 0; k < run_count[prim]; ++k) {
                t = order[run_start[prim] + k];
                /* the scene's uvs have v up (assimp's convention); glTF's runs down. A
                   scene without uvs gets the lightmap's: glTF numbers the uv sets from 0
                   without gaps, so TEXCOORD_1 needs a TEXCOORD_0 */
                for (i = 0; i < 3; ++i) {
                    if (s->uvs) {
                        gw_f32(&bin, s->uvs[6 * (size_t)t + 2 * i]);
                        gw_f32(&bin, 1.0f - s->uvs[6 * (size_t)t + 2 * i + 1]);
                    } else {
                        gw_f32(&bin, s->lightmap_uvs[6 * (size_t)t + 2 * i]);
                        gw_f32(&bin, s->lightmap_uvs[6 * (size_t)t + 2 * i + 1]);
                    }
                }
            }
        *ppng_view = (uint32_t)bin.size;
        gw_put(&bin, png->data, png->size);
        gw_align4(&bin, 0);
        *poff_n = off_n;
        *poff_uv1 = off_uv1;
        *poff_uv0 = off_uv0;
    }
    *pbin = bin;
}

/* The JSON's asset (with the lightmap's extras), scene, nodes (one per mesh, then the camera) and camera. */
static void gw_json_nodes(const char *cmd, const tool_gltf_lightmap *in, const rad_scene *ms, const uint32_t *prim_mesh,
                          uint32_t nprim, uint32_t nmesh, float scale, gw_buf *pjs)
{
    const rad_scene *s = in->scene;
    const rad_lightmap *lm = in->lightmap;
    gw_buf js = *pjs;
    uint32_t mesh, prim;
    gw_printf(&js, "{\"asset\":{\"version\":\"2.0\",\"generator\":\"radiosity.h rad %s (%s)\"",
              cmd, RAD_VERSION_STRING);
    gw_printf(&js, ",\"extras\":{\"RAD_lightmap\":{\"width\":%u,\"height\":%u,\"encoding\":\"srgb\",\"scale\":%.9g,"
                   "\"quantity\":\"irradiance\",\"texture\":0,\"texCoord\":1",
              lm->width, lm->height, (double)scale);
    if (in->hdr_name) { gw_printf(&js, ",\"hdr\":"); gw_string(&js, in->hdr_name); }
    gw_printf(&js, "}}}");
    gw_printf(&js, ",\"extensionsUsed\":[\"KHR_materials_emissive_strength\"]");
    gw_printf(&js, ",\"scene\":0,\"scenes\":[{\"nodes\":[");
    for (mesh = 0; mesh < nmesh; ++mesh) gw_printf(&js, "%s%u", mesh ? "," : "", mesh);
    if (in->camera) gw_printf(&js, "%s%u", nmesh ? "," : "", nmesh);
    gw_printf(&js, "]}]");
    /* nodes: one per mesh, then the camera */
    gw_printf(&js, ",\"nodes\":[");
    for (mesh = 0, prim = 0; mesh < nmesh; ++mesh) {
        uint32_t id = prim_mesh[prim];
        gw_printf(&js, "%s{\"mesh\":%u", mesh ? "," : "", mesh);
        if (ms->mesh_names && id < ms->mesh_count && ms->mesh_names[id] && ms->mesh_names[id][0]) {
            gw_printf(&js, ",\"name\":");
            gw_string(&js, ms->mesh_names[id]);
        }
        gw_printf(&js, "}");
        while (prim < nprim && prim_mesh[prim] == id) ++prim;
    }
    if (in->camera) {
        double q[4];
        const rad_camera *c = in->camera;
        if (!gw_camera_rotation(c, q)) q[0] = q[1] = q[2] = 0.0, q[3] = 1.0;
        gw_printf(&js, "%s{\"camera\":0,\"name\":\"rad view\",\"translation\":[%.9g,%.9g,%.9g],\"rotation\":[%.9g,%.9g,%.9g,%.9g]}",
                  nmesh ? "," : "", (double)c->position[0], (double)c->position[1], (double)c->position[2], q[0], q[1], q[2],
                  q[3]);
    }
    gw_printf(&js, "]");
    if (in->camera) {
        double diag = s->diagonal > 0.0f ? (double)s->diagonal : 1.0;
        gw_printf(&js, ",\"cameras\":[{\"name\":\"rad view\",\"type\":\"perspective\",\"perspective\":{\"yfov\":%.9g,\"znear\":%.9g,\"zfar\":%.9g",
                  (double)in->camera->fov_y_degrees * 3.14159265358979323846 / 180.0, 1e-3 * diag, 1e2 * diag);
        if (in->aspect > 0.0f) gw_printf(&js, ",\"aspectRatio\":%.9g", (double)in->aspect);
        gw_printf(&js, "}}]");
    }
    *pjs = js;
}

/* The JSON's meshes with their primitives, the buffer views (one per accessor, then the PNG) and the accessors. */
static void gw_json_meshes(const rad_scene *s, const uint32_t *order, const uint32_t *run_start, const uint32_t *run_count,
                           const uint32_t *prim_mesh, uint32_t nprim, uint32_t nmesh, uint32_t views_per_prim, size_t off_n,
                           size_t off_uv1, size_t off_uv0, uint32_t png_view, const gw_buf *png, gw_buf *pjs)
{
    gw_buf js = *pjs;
    uint32_t i, k, prim, mesh;
    /* meshes and their primitives; accessors 4 per primitive:
       POSITION, NORMAL, TEXCOORD_1, TEXCOORD_0 */
    gw_printf(&js, ",\"meshes\":[");
    for (mesh = 0, prim = 0; mesh < nmesh; ++mesh) {
        uint32_t id = prim_mesh[prim], first = 1;
        gw_printf(&js, "%s{\"primitives\":[", mesh ? "," : "");
        for (; prim < nprim && prim_mesh[prim] == id; ++prim, first = 0) {
            uint32_t a = views_per_prim * prim;
            /* TEXCOORD_0 first: assimp reads the sets in the order written and refuses a gap */
            gw_printf(&js, "%s{\"attributes\":{\"POSITION\":%u,\"NORMAL\":%u,\"TEXCOORD_0\":%u,\"TEXCOORD_1\":%u}",
                      first ? "" : ",", a, a + 1, a + 3, a + 2);
            gw_printf(&js, ",\"material\":%u,\"mode\":4}", s->materials[order[run_start[prim]]]);
        }
        gw_printf(&js, "]}");
    }
    gw_printf(&js, "]");
    /* buffer views: one per accessor (the arrays above, primitive by primitive), then the PNG */
    gw_printf(&js, ",\"bufferViews\":[");
    {
        size_t done = 0; /* triangles written before this primitive */
        for (prim = 0; prim < nprim; ++prim) {
            size_t c = run_count[prim];
            gw_printf(&js, "%s{\"buffer\":0,\"byteOffset\":%lu,\"byteLength\":%lu,\"target\":34962}", prim ? "," : "",
                      (unsigned long)(36u * done), (unsigned long)(36u * c));
            gw_printf(&js, ",{\"buffer\":0,\"byteOffset\":%lu,\"byteLength\":%lu,\"target\":34962}",
                      (unsigned long)(off_n + 36u * done), (unsigned long)(36u * c));
            gw_printf(&js, ",{\"buffer\":0,\"byteOffset\":%lu,\"byteLength\":%lu,\"target\":34962}",
                      (unsigned long)(off_uv1 + 24u * done), (unsigned long)(24u * c));
            gw_printf(&js, ",{\"buffer\":0,\"byteOffset\":%lu,\"byteLength\":%lu,\"target\":34962}",
                          (unsigned long)(off_uv0 + 24u * done), (unsigned long)(24u * c));
            done += c;
        }
        gw_printf(&js, "%s{\"buffer\":0,\"byteOffset\":%lu,\"byteLength\":%lu}", nprim ? "," : "", (unsigned long)png_view,
                  (unsigned long)png->size);
    }
    gw_printf(&js, "]");
    /* accessors: POSITION carries its bounds (the spec requires min and max) */
    gw_printf(&js, ",\"accessors\":[");
    for (prim = 0; prim < nprim; ++prim) {
        float lo[3], hi[3];
        uint32_t c = 3u * run_count[prim];
        for (i = 0; i < 3; ++i) lo[i] = hi[i] = s->positions[9 * (size_t)order[run_start[prim]] + i];
        for (k = 0; k < run_count[prim]; ++k) {
            const float *p = s->positions + 9 * (size_t)order[run_start[prim] + k];
            for (i = 0; i < 9; ++i) {
                if (p[i] < lo[i % 3]) lo[i % 3] = p[i];
                if (p[i] > hi[i % 3]) hi[i % 3] = p[i];
            }
        }
        gw_printf(&js, "%s{\"bufferView\":%u,\"componentType\":5126,\"count\":%u,\"type\":\"VEC3\",\"min\":[%.9g,%.9g,%.9g],"
                       "\"max\":[%.9g,%.9g,%.9g]}",
                  prim ? "," : "", views_per_prim * prim, c, (double)lo[0], (double)lo[1], (double)lo[2], (double)hi[0],
                  (double)hi[1], (double)hi[2]);
        gw_printf(&js, ",{\"bufferView\":%u,\"componentType\":5126,\"count\":%u,\"type\":\"VEC3\"}", views_per_prim * prim + 1, c);
        gw_printf(&js, ",{\"bufferView\":%u,\"componentType\":5126,\"count\":%u,\"type\":\"VEC2\"}", views_per_prim * prim + 2, c);
        gw_printf(&js, ",{\"bufferView\":%u,\"componentType\":5126,\"count\":%u,\"type\":\"VEC2\"}", views_per_prim * prim + 3, c);
    }
    gw_printf(&js, "]");
    *pjs = js;
}

/* The JSON's lightmap sampler, image and texture, and the materials (constant colours naming the lightmap). */
static void gw_json_materials(const char *cmd, const char *path, const tool_gltf_lightmap *in, uint32_t nprim,
                              uint32_t views_per_prim, float scale, gw_buf *pjs)
{
    const rad_scene *s = in->scene;
    gw_buf js = *pjs;
    uint32_t k;
    int warned = 0;
    /* the lightmap: clamped, linear, no mipmaps (mip levels would mix neighbouring charts) */
    gw_printf(&js, ",\"samplers\":[{\"magFilter\":9729,\"minFilter\":9729,\"wrapS\":33071,\"wrapT\":33071}]");
    gw_printf(&js, ",\"images\":[{\"bufferView\":%u,\"mimeType\":\"image/png\",\"name\":\"lightmap\"}]",
              views_per_prim * nprim);
    gw_printf(&js, ",\"textures\":[{\"sampler\":0,\"source\":0,\"name\":\"lightmap\"}]");
    /* materials: constant colours, each naming the lightmap in its extras */
    gw_printf(&js, ",\"materials\":[");
    for (k = 0; k < s->material_count; ++k) {
        const rad_material *m = &s->materials_table[k];
        float em = m->emission[0];
        if (m->emission[1] > em) em = m->emission[1];
        if (m->emission[2] > em) em = m->emission[2];
        if (m->texture && !warned) {
            fprintf(stderr, "rad %s: warning: '%s' carries the materials' constant colours: base-colour textures are not "
                            "copied (the lightmap holds irradiance, so the engine's own textures apply)\n", cmd, path);
            warned = 1;
        }
        gw_printf(&js, "%s{", k ? "," : "");
        if (in->material_names && in->material_names[k] && in->material_names[k][0]) {
            gw_printf(&js, "\"name\":");
            gw_string(&js, in->material_names[k]);
            gw_printf(&js, ",");
        }
        gw_printf(&js, "\"pbrMetallicRoughness\":{\"baseColorFactor\":[%.9g,%.9g,%.9g,1],\"metallicFactor\":0,"
                       "\"roughnessFactor\":1}",
                  (double)m->albedo[0], (double)m->albedo[1], (double)m->albedo[2]);
        if (em > 0.0f) {
            float f = em > 1.0f ? em : 1.0f;
            gw_printf(&js, ",\"emissiveFactor\":[%.9g,%.9g,%.9g]", (double)(m->emission[0] / f), (double)(m->emission[1] / f),
                      (double)(m->emission[2] / f));
            if (f > 1.0f) gw_printf(&js, ",\"extensions\":{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":%.9g}}", (double)f);
        }
        gw_printf(&js, ",\"extras\":{\"RAD_lightmap\":{\"texture\":0,\"texCoord\":1,\"encoding\":\"srgb\",\"scale\":%.9g",
                  (double)scale);
        if (in->hdr_name) { gw_printf(&js, ",\"hdr\":"); gw_string(&js, in->hdr_name); }
        gw_printf(&js, "}}}");
    }
    gw_printf(&js, "]");
    *pjs = js;
}

/* The files: a GLB (header, JSON chunk, BIN chunk), or the .bin then the .gltf (file takes over js);
   0 when written, 1 out of memory, 2 an output error. */
static int gw_files(const char *path, int glb, const char *bin_path, gw_buf *js, const gw_buf *bin, gw_buf *file,
                    tool_output_set *set)
{
    tool_output o;
    if (glb) {
        gw_u32(file, 0x46546C67u); /* "glTF" */
        gw_u32(file, 2u);
        gw_u32(file, (uint32_t)(12u + 8u + js->size + 8u + bin->size));
        gw_u32(file, (uint32_t)js->size);
        gw_u32(file, 0x4E4F534Au); /* "JSON" */
        gw_put(file, js->data, js->size);
        gw_u32(file, (uint32_t)bin->size);
        gw_u32(file, 0x004E4942u); /* "BIN\0" */
        gw_put(file, bin->data, bin->size);
        if (file->failed) return 1;
    } else {
        if (tool_output_open(&o, bin_path) != 0) return 2;
        errno = 0;
        if (tool_output_set_add(set, &o, fwrite(bin->data, 1, bin->size, o.f) == bin->size) != 0) return 2;
        *file = *js;
        memset(js, 0, sizeof *js);
    }
    if (tool_output_open(&o, path) != 0) return 2;
    if (tool_output_set_add(set, &o, fwrite(file->data, 1, file->size, o.f) == file->size) != 0) return 2;
    return 0;
}

int tool_gltf_write(const char *cmd, const char *path, const tool_gltf_lightmap *in, tool_output_set *set)
{
    const rad_scene *s = in->scene;
    /* the meshes (and their names) that group the triangles */
    const rad_scene *ms = in->mesh_scene && in->mesh_scene->triangle_count == s->triangle_count ? in->mesh_scene : s;
    const rad_lightmap *lm = in->lightmap;
    gw_buf bin, js, png, file;
    uint32_t *order = NULL, nprim = 0, nmesh = 0;
    uint32_t *run_start = NULL, *run_count = NULL, *prim_mesh = NULL;
    size_t n_texels = (size_t)lm->width * lm->height, vbytes;
    unsigned char *px = NULL;
    float scale = 0.0f;
    int glb = gw_has_ext(path, ".glb"), ok = 0;
    uint32_t views_per_prim = 4u, png_view; /* POSITION, NORMAL, TEXCOORD_1, TEXCOORD_0 */
    char *bin_path = NULL;
    memset(&bin, 0, sizeof bin);
    memset(&js, 0, sizeof js);
    memset(&png, 0, sizeof png);
    memset(&file, 0, sizeof file);
    if (!s->lightmap_uvs) {
        fprintf(stderr, "rad %s: cannot write '%s': the baked scene has no lightmap uvs\n", cmd, path);
        return 1;
    }
    /* POSITION, NORMAL, TEXCOORD_1 and TEXCOORD_0: 40 bytes a vertex, 3 vertices a triangle;
       a GLB's chunk lengths and a glTF accessor's offsets are 32-bit */
    vbytes = (size_t)40 * 3u * s->triangle_count;
    if ((double)vbytes + 4.0 * (double)n_texels > 4.0e9) {
        fprintf(stderr, "rad %s: cannot write '%s': %u triangles and a %ux%u lightmap pass the 4 GB a glTF buffer holds\n",
                cmd, path, s->triangle_count, lm->width, lm->height);
        return 1;
    }

    /* the lightmap as 8-bit sRGB of irradiance / scale, scale the atlas's largest value */
    if (gw_encode_lightmap(in, n_texels, &px, &png, &scale)) goto oom;

    /* primitives: runs of one mesh and material */
    order = (uint32_t *)tool_calloc(s->triangle_count, sizeof(uint32_t));
    run_start = (uint32_t *)tool_calloc(s->triangle_count, sizeof(uint32_t));
    run_count = (uint32_t *)tool_calloc(s->triangle_count, sizeof(uint32_t));
    prim_mesh = (uint32_t *)tool_calloc(s->triangle_count, sizeof(uint32_t));
    gw_primitives(s, ms, order, run_start, run_count, prim_mesh, &nprim, &nmesh);

    /* the binary buffer: per primitive its attribute arrays, then the PNG */
    {
        size_t off_n, off_uv1, off_uv0;
        gw_binary(s, order, run_start, run_count, nprim, &png, &bin, &off_n, &off_uv1, &off_uv0, &png_view);
        if (bin.failed) goto oom;

        /* the JSON */
        gw_json_nodes(cmd, in, ms, prim_mesh, nprim, nmesh, scale, &js);
        gw_json_meshes(s, order, run_start, run_count, prim_mesh, nprim, nmesh, views_per_prim, off_n, off_uv1, off_uv0,
                       png_view, &png, &js);
        gw_json_materials(cmd, path, in, nprim, views_per_prim, scale, &js);
        gw_printf(&js, ",\"buffers\":[{\"byteLength\":%lu", (unsigned long)bin.size);
        if (!glb) {
            bin_path = tool_gltf_bin_path(path);
            gw_printf(&js, ",\"uri\":");
            gw_uri(&js, gw_base(bin_path));
        }
        gw_printf(&js, "}]}");
        gw_align4(&js, ' ');
        if (js.failed) goto oom;
    }

    /* the files */
    switch (gw_files(path, glb, bin_path, &js, &bin, &file, set)) {
    case 1: goto oom;
    case 2: goto io;
    default: break;
    }
    ok = 1;
    goto done;
oom:
    fprintf(stderr, "rad %s: out of memory writing '%s'\n", cmd, path);
    tool_output_set_abort(set);
    goto done;
io:
    fprintf(stderr, "rad %s: %s\n", cmd, tool_output_error());
    tool_output_set_abort(set);
done:
    free(px);
    free(order);
    free(run_start);
    free(run_count);
    free(prim_mesh);
    free(bin.data);
    free(js.data);
    free(png.data);
    free(file.data);
    free(bin_path);
    return ok ? 0 : 1;
}
