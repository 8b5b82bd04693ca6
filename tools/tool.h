/* tool.h - what the rad tool's source files share. Each subcommand lives in its own file and
   is dispatched from rad.c; every file includes radiosity.h without the implementation, which
   rad.c holds. */
#ifndef RAD_TOOL_H
#define RAD_TOOL_H
#include "../radiosity.h"
#include <stddef.h>

/* ---- scenes (import.c) ---------------------------------------------------------------- */

/* A scene loaded for the tool: the descriptor and everything it points to (owned here), plus
   the lights, camera and names that came with it. */
typedef struct rad_tool_scene {
    rad_scene_desc desc;
    rad_camera camera;       /* the file's first camera, or a default framing of the bounds */
    int has_camera;          /* 1 when the camera came from the file or the built-in scene */
    rad_light *lights;       /* analytic lights found in the file (may be none) */
    uint32_t light_count;
    void *storage;           /* private */
} rad_tool_scene;

/* 'cornell' (the built-in box) or a file assimp can read (OBJ+MTL, glTF 2.0, FBX, PLY ...).
   Materials: albedo from Kd / glTF base colour (with the base-colour texture sampled through
   the albedo callback), emission (radiance) from Ke / glTF emissive x strength. Object and
   group names are kept as mesh names. Returns 0 on success; on failure writes a message to
   err (errlen bytes). */
int rad_tool_load_scene(const char *path_or_name, rad_tool_scene *out, char *err, size_t errlen);
void rad_tool_free_scene(rad_tool_scene *scene);

/* ---- images (image.c) ------------------------------------------------------------------ */

/* Linear RGB floats, row-major, top row first. */
typedef struct rad_image {
    int width, height;
    float *rgb;
} rad_image;

int rad_image_alloc(rad_image *img, int width, int height); /* 0 on success, zero-filled */
void rad_image_free(rad_image *img);
int rad_image_write_pfm(const char *path, const rad_image *img);         /* 0 on success */
int rad_image_read_pfm(const char *path, rad_image *img, char *err, size_t errlen);
/* sRGB-encoded 8-bit PNG of exposure * linear value, clamped */
int rad_image_write_png(const char *path, const rad_image *img, float exposure);
/* writes .pfm or .png by the path's extension */
int rad_image_write(const char *path, const rad_image *img, float exposure);

/* ---- metrics (metrics.c): REFERENCE.md §6 on values clamped to [0,1] ----------------- */
double rad_image_mse(const rad_image *a, const rad_image *b);
double rad_image_psnr(const rad_image *a, const rad_image *b);  /* L = 1; +inf for equal images */
double rad_image_ssim(const rad_image *a, const rad_image *b);  /* per channel, averaged */
/* heat map of the per-pixel mean absolute difference (scaled so 'scale' maps to the top) */
int rad_image_diff_heatmap(const rad_image *a, const rad_image *b, float scale, rad_image *out);

/* ---- reference path tracer (trace.c) ---------------------------------------------------- */
typedef struct rad_trace_options {
    int width, height;
    int spp;                  /* samples per pixel, spread uniformly over the pixel (box filter) */
    uint32_t seed;
    int max_depth;            /* path length cap (default 64) */
    int rr_depth;             /* Russian roulette only after this many bounces (default 16) */
} rad_trace_options;

/* Diffuse path tracing with next-event estimation and multiple importance sampling for the
   scene's emissive triangles, plus the analytic lights (point, spot, directional: NEE only;
   sky: escaping rays). Output: linear radiance (W m^-2 sr^-1). Deterministic for a seed. */
int rad_trace_image(const rad_scene *scene, const rad_raycaster *rc, const rad_light *lights, uint32_t light_count,
                    const rad_camera *camera, const rad_trace_options *options, const rad_context *ctx,
                    rad_image *out);

/* ---- subcommands: int cmd(int argc, char **argv) with argv[0] the subcommand's first
   argument; return the process exit code (0 ok, 1 failure, 2 usage error) ------------- */
int rad_cmd_formfactors(int argc, char **argv);
int rad_cmd_bake(int argc, char **argv);
int rad_cmd_render(int argc, char **argv);
int rad_cmd_trace(int argc, char **argv);
int rad_cmd_compare(int argc, char **argv);
int rad_cmd_info(int argc, char **argv);

/* ---- shared helpers (rad.c) ------------------------------------------------------------- */
/* progress to stderr: a bar when stderr is a terminal, a plain percentage line otherwise */
int rad_tool_progress(void *user, float fraction);
void rad_tool_log(void *user, rad_log_level level, const char *message);
/* --threads N (0: all): sets the OpenMP thread count when built with OpenMP */
void rad_tool_set_threads(int threads);
/* parses "PX,PY,PZ:TX,TY,TZ:UX,UY,UZ"; 0 on success */
int rad_tool_parse_camera(const char *text, rad_camera *out);
/* parses "WxH"; 0 on success */
int rad_tool_parse_size(const char *text, int *w, int *h);

/* ---- added by trace-metrics ------------------------------------------------------------ */
/* Reads .png (8-bit sRGB through stb_image, decoded to linear) or else PFM; 0 on success. */
int rad_image_read(const char *path, rad_image *img, char *err, size_t errlen);
int rad_image_read_png(const char *path, rad_image *img, char *err, size_t errlen);
/* The 8-bit sRGB code of a linear value (clamped to [0,1], rounded): what PNGs store. */
unsigned char rad_image_srgb8(float linear);
/* rad_image_write: .pfm ignores 'exposure' (PFM keeps the radiance); .png applies it. */
/* Fills options with the defaults (256x256, 64 spp, seed 0, max_depth 64, rr_depth 16).
   rad_trace_image: 'out' must be zero-initialised or a live image (reallocated when its size
   differs); returns 0 or a rad_result error (INVALID_ARGUMENT, OUT_OF_MEMORY,
   RAYCAST_FAILED, CANCELLED by ctx->progress). Surfaces are one-sided like the patches. */
void rad_trace_options_default(rad_trace_options *options);


/* added by tool-core */
/* ---- more shared helpers (rad.c) -------------------------------------------------------- */
/* A context whose log goes to stderr and whose progress is drawn with 'label' (NULL: no
   progress). */
void rad_tool_context(rad_context *ctx, const char *label);
/* ends a progress line that did not reach 100% */
void rad_tool_progress_end(void);
/* "rad CMD: what failed: RAD_ERROR_...: ..." on stderr; returns 1 */
int rad_tool_fail(const char *cmd, const char *what, rad_result r);
/* option values: 0 on success, else prints "rad CMD: bad value ..." and returns 2 */
int rad_tool_parse_uint(const char *cmd, const char *opt, const char *text, uint32_t *out);
int rad_tool_parse_float(const char *cmd, const char *opt, const char *text, float *out);
double rad_tool_seconds(void);

/* A scene ready for ray queries: the loaded file, the validated scene and its BVH. */
typedef struct rad_tool_world {
    rad_tool_scene file;
    rad_scene *scene;
    rad_bvh *bvh;
    rad_raycaster rc;
} rad_tool_world;
/* loads, validates and builds the BVH; prints the error and returns 1 on failure, else 0 */
int rad_tool_open_world(const char *cmd, const char *path_or_name, rad_tool_world *w);
void rad_tool_close_world(rad_tool_world *w);

/* ---- the classic method: patches, F, direct light, solve (cmd_bake.c) --------------------- */
typedef enum rad_tool_solver { RAD_TOOL_JACOBI = 0, RAD_TOOL_GAUSS_SEIDEL = 1, RAD_TOOL_DIRECT = 2 } rad_tool_solver;
typedef struct rad_tool_classic_options {
    uint32_t patches;        /* --patches N: target patch count (default 2000) */
    float max_edge;          /* --max-edge L (0: none) */
    uint32_t samples;        /* --samples S: form-factor samples per patch pair (default 16) */
    rad_tool_solver solver;  /* --solver jacobi|gauss-seidel|direct */
    uint32_t bounces;        /* --bounces K (Jacobi; default 64) */
    uint32_t light_samples;  /* --light-samples N: shadow rays per point (default 16) */
} rad_tool_classic_options;
void rad_tool_classic_options_default(rad_tool_classic_options *o);
/* argv[*a] is one of the options above: parses it (and its value, advancing *a) and returns
   1; returns 0 when it is not one of them, 2 on a bad value (message printed) */
int rad_tool_classic_option(const char *cmd, int argc, char **argv, int *a, rad_tool_classic_options *o);
const char *rad_tool_classic_help(void);

/* Patches, dense F, direct irradiance D of the patches (emitters and analytic lights),
   E = rho D (RAD_SOURCE_DIRECT), the indirect solution L, B = E + L and H = F B. */
typedef struct rad_tool_classic {
    rad_patches *patches;
    rad_form_factors *ff;
    float *D, *E, *L, *B, *H;   /* 3N floats each */
} rad_tool_classic;
/* prints progress and errors; returns 0 or 1 */
int rad_tool_classic_solve(const char *cmd, const rad_tool_world *w, const rad_tool_classic_options *o,
                           rad_tool_classic *out);
void rad_tool_classic_free(rad_tool_classic *c);

/* The user section a bake stores its options in (RAD_SECTION_USER, name "rad.options"). */
typedef struct rad_tool_bake_info {
    uint32_t magic;          /* 0x52414442 */
    uint32_t patches;
    float max_edge;
    uint32_t samples;
    uint32_t solver;
    uint32_t bounces;
    uint32_t light_samples;
    uint32_t triangle_count; /* of the scene baked */
} rad_tool_bake_info;
#define RAD_TOOL_SECTION_OPTIONS (RAD_SECTION_USER + 1u)

/* ---- lighting models for the direct term (shading.c) ------------------------------------ */
/* "none" (-1) or a rad_shading_model name; 0 on success, else prints and returns 2 */
int rad_tool_parse_shading(const char *cmd, const char *text, int *out_model);
/* Direct radiance at 'count' points (normals n, unit directions to the viewer v, albedos):
   sum over the analytic lights of E V R(l, v, n) for the model, plus albedo / pi times the
   irradiance of the emissive triangles and the sky. 0 on success, 1 (message printed). */
int rad_tool_shade_direct(const rad_tool_world *w, int model, uint32_t light_samples, const float *points,
                          const float *normals, const float *views, const float *albedos, uint32_t count,
                          float *out_rgb);

#endif
