/* tool.h - what the rad tool's source files share. Each subcommand lives in its own file and
   is dispatched from rad.c; every file includes radiosity.h without the implementation, which
   common.c holds. */
#ifndef TOOL_H
#define TOOL_H
#include "../radiosity.h"
#include <stddef.h>
#include <stdio.h>

/* ---- scenes (import.c) ---------------------------------------------------------------- */

/* A scene loaded for the tool: the descriptor and everything it points to (owned here), plus
   the lights, camera and names that came with it. */
typedef struct tool_scene {
    rad_scene_desc desc;
    rad_camera camera;       /* the file's first camera, or a framing of the bounds from -z (render
                                and trace choose their own then: tool_choose_camera) */
    int has_camera;          /* 1 when the camera came from the file or the built-in scene */
    rad_light *lights;       /* analytic lights found in the file (may be none) */
    uint32_t light_count;
    const char *const *material_names; /* desc.material_count names ("" when unnamed), or NULL */
    const char *const *material_reports; /* per material, lines "  what: ..." saying what the
                                importer used, read and ignored of it (rad info), or NULL */
    const char *const *input_files; /* the files it was read from: the scene file, the MTL
                                       libraries an OBJ names, the textures loaded from disk */
    uint32_t input_file_count;
    void *storage;           /* private */
} tool_scene;

/* 'cornell' (the built-in box) or a file assimp can read (OBJ+MTL, glTF 2.0, FBX, PLY ...).
   Materials: albedo from Kd / glTF base colour (with the base-colour texture sampled through
   the albedo callback), emission (radiance) from Ke / glTF emissiveFactor x
   KHR_materials_emissive_strength, times map_Ke / emissiveTexture through the emission callback. Object and
   group names are kept as mesh names. Returns 0 on success; on failure writes a message to
   err (errlen bytes). */
int tool_load_scene(const char *path_or_name, tool_scene *out, char *err, size_t errlen);
void tool_free_scene(tool_scene *scene);
/* 1 for 'cornell' and a file name whose extension the importer reads (not .radb) */
int tool_is_scene_path(const char *path);

/* --two-sided MODE of every command (rad.c takes it before the command sees its options):
   auto (default) trusts the file's flag (glTF doubleSided; OBJ has none: one-sided), all makes
   every material two-sided, none every material one-sided. */
typedef enum tool_two_sided_mode { TOOL_TWO_SIDED_AUTO = 0, TOOL_TWO_SIDED_ALL = 1, TOOL_TWO_SIDED_NONE = 2 } tool_two_sided_mode;
extern tool_two_sided_mode tool_two_sided;
/* 0 and *out set for "auto", "all" or "none", else 1 */
int tool_two_sided_parse(const char *text, tool_two_sided_mode *out);

/* ---- images (image.c) ------------------------------------------------------------------ */

/* Linear RGB floats, row-major, top row first. */
typedef struct tool_image {
    int width, height;
    float *rgb;
} tool_image;

int tool_image_alloc(tool_image *img, int width, int height); /* 0 on success, zero-filled */
void tool_image_free(tool_image *img);
int tool_image_write_pfm(const char *path, const tool_image *img);         /* 0 on success */
int tool_image_read_pfm(const char *path, tool_image *img, char *err, size_t errlen);
/* sRGB-encoded 8-bit PNG of exposure * linear value, clamped */
int tool_image_write_png(const char *path, const tool_image *img, float exposure);
/* OpenEXR, 32-bit float RGB (tinyexr; without -DTOOL_EXR both fail with a message naming
   the package libtinyexr-dev) */
int tool_image_write_exr(const char *path, const tool_image *img);         /* 0 on success */
int tool_image_read_exr(const char *path, tool_image *img, char *err, size_t errlen);
/* 0 when 'path' names an image format this build writes (.pfm, .png, .exr with tinyexr);
   else prints why ("rad CMD: ...") and returns 2 */
int tool_image_check_format(const char *cmd, const char *path);
/* writes .pfm, .png or .exr by the path's extension: .pfm and .exr ignore 'exposure' (they
   keep the radiance); .png applies it */
int tool_image_write(const char *path, const tool_image *img, float exposure);
/* Reads .png (8-bit sRGB through stb_image, decoded to linear), .exr (tinyexr) or else PFM; 0 on success. */
int tool_image_read(const char *path, tool_image *img, char *err, size_t errlen);
int tool_image_read_png(const char *path, tool_image *img, char *err, size_t errlen);
/* Radiance .hdr (RGBE) through stb_image's stbi_loadf: linear float RGB, top row first */
int tool_image_read_hdr(const char *path, tool_image *img, char *err, size_t errlen);
/* The 8-bit sRGB code of a linear value (clamped to [0,1], rounded): what PNGs store. */
unsigned char tool_image_srgb8(float linear);

/* ---- output files (image.c): every file the tool writes ------------------------------- */
/* A temporary file ".radtmp-XXXXXX" created exclusively (never through a symlink) in the
   destination's folder, renamed onto it by tool_output_commit only when everything was
   written, flushed and synced: a failure leaves the old file (if any) untouched and no
   temporary behind, and a fatal signal (SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGXFSZ, SIGPIPE,
   unless ignored when rad started) removes the open temporaries before the process ends.
   The image writers and the bake writers all use it. */
typedef struct tool_output {
    FILE *f;        /* write here */
    char *path;     /* the destination */
    char *tmp;      /* the temporary */
    int slot;       /* private: the signal handler's record of tmp (0: none) */
    int closed;     /* private: tool_output_close succeeded */
} tool_output;
/* 0, or -1 with the reason in tool_output_error() */
int tool_output_open(tool_output *o, const char *path);
/* ok: 1 when every write succeeded. Flushes, syncs, closes and renames; on any failure
   removes the temporary and returns -1 (reason in tool_output_error()). */
int tool_output_commit(tool_output *o, int ok);
/* the same without the rename: the temporary is complete on disk (0), or removed (-1) */
int tool_output_close(tool_output *o, int ok);
void tool_output_abort(tool_output *o); /* closes and removes the temporary */
/* Files that replace their destinations together (OBJ + MTL, the layers of an SH lightmap):
   each one is written and closed into its temporary (tool_output_set_add), and only when all
   of them are, tool_output_set_commit renames them all; any failure before that removes every
   temporary of the set and leaves each old file as it was. */
#define TOOL_OUTPUT_SET_MAX 8
typedef struct tool_output_set {
    tool_output items[TOOL_OUTPUT_SET_MAX];
    unsigned count;
} tool_output_set; /* zero-initialise */
/* closes o (tool_output_close) into the set; on a failure aborts o and the whole set; 0 or -1 */
int tool_output_set_add(tool_output_set *set, tool_output *o, int ok);
int tool_output_set_commit(tool_output_set *set); /* 0 or -1 (reason in tool_output_error()) */
void tool_output_set_abort(tool_output_set *set);
/* tool_image_write into a set (NULL: written at once); on a failure the set is aborted */
int tool_image_write_into(tool_output_set *set, const char *path, const tool_image *img, float exposure);
/* size bytes to path through the above; 0 or -1 */
int tool_write_file(const char *path, const void *data, size_t size);
/* why the last output (or image write) failed, e.g. "cannot write 'x.png': cannot create a
   file in 'dir': Permission denied" */
const char *tool_output_error(void);
/* Before the work: refuses an output that is one of the inputs (the same file by st_dev and
   st_ino, so another name or a link for it counts), is a directory, or whose folder is
   missing or not writable. 0 when fine, else prints "rad CMD: ..." and returns 1. */
int tool_check_output(const char *cmd, const char *path, const char *const *inputs, int input_count);
/* Refuses two outputs of one command that are the same file, and an output that is one of
   the inputs (e.g. tool_scene.input_files: the scene, its MTL files, its textures): the same
   device and inode where both exist, else the same resolved path. 0, or 1 after printing
   "rad CMD: ..." */
int tool_check_outputs(const char *cmd, const char *const *outputs, int count, const char *const *inputs, int input_count);

/* ---- metrics (metrics.c): MSE, PSNR, SSIM on values clamped to [0,1] ------------------- */
double tool_image_mse(const tool_image *a, const tool_image *b);
double tool_image_psnr(const tool_image *a, const tool_image *b);  /* L = 1; +inf for equal images */
double tool_image_ssim(const tool_image *a, const tool_image *b);  /* per channel, averaged */
/* heat map of the per-pixel mean absolute difference (scaled so 'scale' maps to the top) */
int tool_image_diff_heatmap(const tool_image *a, const tool_image *b, float scale, tool_image *out);

/* ---- reference path tracer (trace.c) ---------------------------------------------------- */
typedef struct tool_trace_options {
    int width, height;
    int spp;                  /* samples per pixel, spread uniformly over the pixel (box filter) */
    uint32_t seed;
    int max_depth;            /* path length cap (default 64) */
    int rr_depth;             /* Russian roulette only after this many bounces (default 16) */
} tool_trace_options;

/* Diffuse path tracing with next-event estimation and multiple importance sampling for the
   scene's emissive triangles, plus the analytic lights (point, spot, directional: NEE only;
   sky: escaping rays). Output: linear radiance (W m^-2 sr^-1). Deterministic for a seed. */
int tool_trace_image(const rad_scene *scene, const rad_raycaster *rc, const rad_light *lights, uint32_t light_count,
                    const rad_camera *camera, const tool_trace_options *options, const rad_context *ctx,
                    tool_image *out);
/* Fills options with the defaults (256x256, 64 spp, seed 0, max_depth 64, rr_depth 16).
   tool_trace_image: 'out' must be zero-initialised or a live image (reallocated when its size
   differs); returns 0 or a rad_result error (INVALID_ARGUMENT, OUT_OF_MEMORY,
   RAYCAST_FAILED, CANCELLED by ctx->progress). Surfaces are one-sided like the patches. */
void tool_trace_options_default(tool_trace_options *options);

/* ---- subcommands: int cmd(int argc, char **argv) with argv[0] the subcommand's first
   argument; return the process exit code (0 ok, 1 failure, 2 usage error) ------------- */
int tool_cmd_formfactors(int argc, char **argv);
int tool_cmd_bake(int argc, char **argv);
int tool_cmd_render(int argc, char **argv);
int tool_cmd_trace(int argc, char **argv);
int tool_cmd_compare(int argc, char **argv);
int tool_cmd_info(int argc, char **argv);
int tool_cmd_export(int argc, char **argv);
int tool_cmd_probes(int argc, char **argv);

/* the rad program (rad.c): dispatches argv[1] to a subcommand; the exit code (main.c) */
int tool_main(int argc, char **argv);

/* ---- shared helpers (common.c) ----------------------------------------------------------- */
/* progress to stderr: a bar when stderr is a terminal, a plain percentage line otherwise */
int tool_progress(void *user, float fraction);
void tool_log(void *user, rad_log_level level, const char *message);
/* --threads N (0: all): sets the OpenMP thread count when built with OpenMP */
void tool_set_threads(int threads);
/* The most --threads accepts: libgomp crashes creating 100000 threads, and more
   threads than this helps no machine the tool runs on. */
#define TOOL_MAX_THREADS 1024u
/* --threads N: a whole number in 0..TOOL_MAX_THREADS; 0 on success, else prints
   "rad CMD: ..." and returns 2 */
int tool_parse_threads(const char *cmd, const char *opt, const char *text, uint32_t *out);
/* parses "PX,PY,PZ:TX,TY,TZ:UX,UY,UZ" (the points finite, within 1e30; the view direction and
   up as tool_vector_problem's directions, not parallel); 0, or 1 with *why saying what is wrong */
int tool_parse_camera(const char *text, rad_camera *out, const char **why);
/* NULL when v is usable, else why not ("is not finite" ...): every component finite and within
   1e30; a direction (direction != 0) also normalisable in float: its squared length finite
   (a direction of length ~2e19 overflows and the library would take it as zero) and not zero */
const char *tool_vector_problem(const float v[3], int direction);
/* parses "WxH"; 0 on success */
int tool_parse_size(const char *text, int *w, int *h);
/* The most memory an image may take (linear RGB floats, 12 bytes a pixel): 2 GiB, e.g.
   16384x8192. --size 32768x32768 would allocate 12 GiB without a word. */
#define TOOL_MAX_IMAGE_BYTES 2147483648.0
/* --size: 0 when the image fits TOOL_MAX_IMAGE_BYTES, else prints "rad CMD: ..." with the
   bytes and returns 2 */
int tool_check_size(const char *cmd, int w, int h);


/* ---- more shared helpers (common.c) ------------------------------------------------------ */
/* A context whose log goes to stderr and whose progress is drawn with 'label' (NULL: no
   progress). */
void tool_context(rad_context *ctx, const char *label);
/* 0: contexts made from now on draw no progress (rad-mpi's ranks other than 0) */
void tool_show_progress(int on);
/* ends a progress line that did not reach 100% */
void tool_progress_end(void);
/* "rad CMD: what failed: RAD_ERROR_...: ..." on stderr; returns 1 */
int tool_fail(const char *cmd, const char *what, rad_result r);
/* calloc of n elements (at least one) that prints and exits on failure */
void *tool_calloc(size_t n, size_t size);
/* qsort order of doubles, ascending */
int tool_cmp_double(const void *a, const void *b);
/* malloc (at least one byte) that prints and exits on failure */
void *tool_malloc(size_t size);
/* The whole file into *data (malloc'd, free with free()) and *size; 0, or 1 after printing
   "rad CMD: cannot read WHAT 'PATH': <the system's reason>" (or that it is empty; cmd NULL:
   nothing printed). */
int tool_read_file(const char *cmd, const char *what, const char *path, void **data, size_t *size);
/* option values: 0 on success, else prints "rad CMD: bad value ..." and returns 2 */
int tool_parse_uint(const char *cmd, const char *opt, const char *text, uint32_t *out);
int tool_parse_float(const char *cmd, const char *opt, const char *text, float *out);
double tool_seconds(void);

/* ---- option tables (options.c) ------------------------------------------------------------ */
/* A command's options as a table of tool_arg rows ending with a TOOL_ARG_END row: each row is an
   option (its name, the value's placeholder, the field it fills in the options struct the
   command passes, the range it accepts, its bit in the struct's 'given' mask) and its help
   text, so that the parser and the --help of a command are the same table. */
typedef enum tool_arg_kind {
    TOOL_ARG_END = 0,  /* ends the table */
    TOOL_ARG_TEXT,     /* no option: help text printed as it is (a heading, a paragraph) */
    TOOL_ARG_FLAG,     /* no value: stores the int (int)lo in the field */
    TOOL_ARG_UINT,     /* a whole number in [lo, hi] into a uint32_t */
    TOOL_ARG_FLOAT,    /* a number in [lo, hi] (flags: either end open) into a float */
    TOOL_ARG_STRING,   /* the text itself into a const char * */
    TOOL_ARG_CHOICE,   /* one of the '|'-separated 'choices': values[i] (NULL: i) into a uint32_t */
    TOOL_ARG_CUSTOM    /* 'parse' reads the value */
} tool_arg_kind;
enum { TOOL_ARG_LO_OPEN = 1, TOOL_ARG_HI_OPEN = 2, TOOL_ARG_NONEMPTY = 4 };
typedef struct tool_arg tool_arg;
/* parses 'value' of option t into field (the target's field); 0, or 2 after printing why */
typedef int (*tool_arg_parse_fn)(const char *cmd, const tool_arg *t, const char *value, void *field);
struct tool_arg {
    tool_arg_kind kind;
    const char *name;        /* "--k" */
    const char *value;       /* its placeholder in the help ("K"; NULL for a flag) */
    size_t field;            /* offsetof the field in the target struct */
    double lo, hi;           /* UINT, FLOAT: the range; FLAG: lo is the value stored */
    unsigned flags;          /* TOOL_ARG_LO_OPEN ... */
    uint32_t given;          /* bits or-ed into *given when the option is taken */
    const char *bad;         /* out of range: "rad CMD: NAME <bad>, not VALUE" */
    const char *choices;     /* CHOICE: "a|b|c" */
    const uint32_t *values;  /* CHOICE: the value of each choice (NULL: its index) */
    tool_arg_parse_fn parse; /* CUSTOM */
    unsigned where;          /* help only: the contexts that list it (0: every one) */
    const char *help;        /* its text; lines after the first are indented to the first's column */
};
/* argv[*a] is an option of the table: parses it (and its value, advancing *a) into target and
   returns 1; 0 when it is not one; 2 on a bad value or a missing one (message printed) */
int tool_args_parse(const char *cmd, const tool_arg *table, void *target, uint32_t *given, int argc, char **argv, int *a);
/* the table's help for the context 'where' (0: every row) into buf, truncated to size bytes */
void tool_args_help_into(const tool_arg *table, unsigned where, char *buf, size_t size);

/* ---- lights from the command line (lights.c) ------------------------------------------- */
/* --area P:U:V:RGB: an emissive parallelogram P, P+U, P+U+V, P+V of radiance RGB */
typedef struct tool_area_light {
    float p[3], u[3], v[3], radiance[3];
} tool_area_light;
/* The largest light value a light option takes (W/m^2, W/sr, W m^-2 sr^-1): past it the
   transport (sky E_0 = pi RGB, times albedo, over bounces) overflows what a bake keeps
   (RAD_BAKE_VALUE_MAX), so the option is refused instead of the save at the end. */
#define TOOL_MAX_LIGHT_VALUE 1e20f
/* What --sun, --sky, --point, --spot and --area gave (units: lights.c and tool_light_help) */
typedef struct tool_lights {
    rad_light *lights;              /* the analytic ones, in the library's units */
    uint32_t count;
    tool_area_light *areas;
    uint32_t area_count;
    rad_environment **envs;         /* --env and --sky-model: the maps lights[] point to */
    tool_image *env_images;         /* their pixels (borrowed by envs) */
    uint32_t env_count;
    float sky_turbidity, sky_scale; /* --sky-model preetham:T[:SCALE] */
    float sun_time[3];              /* --sun-time LAT:DAY:HOUR */
    unsigned sky_parts;             /* 1: --sky-model given, 2: --sun-time given (3: both, made) */
} tool_lights;
/* argv[*a] is one of the light options: parses it (and its value, advancing *a) and returns 1;
   0 when it is not one; 2 on a bad value (message naming the option printed) */
int tool_light_option(const char *cmd, int argc, char **argv, int *a, tool_lights *L);
const char *tool_light_help(void);
void tool_lights_free(tool_lights *L);
/* Appends L to a loaded scene: the analytic lights to f->lights, the area lights to f->desc
   (meshes "area_light_K", emissive materials); *storage keeps the new arrays (free with
   tool_lights_release after the scene is destroyed). Prints what was added. 0 or 1. */
int tool_add_lights(const char *cmd, tool_scene *f, const tool_lights *L, void **storage);
void tool_lights_release(void *storage);
/* rad_hash64 of the lights' fields, continuing from h */
uint64_t tool_lights_hash(const rad_light *lights, uint32_t count, uint64_t h);

/* A scene ready for ray queries: the loaded file, the validated scene and its BVH (world.c). */
typedef struct tool_world {
    tool_scene file;      /* file.lights: the file's lights, then those of the command line */
    rad_scene *scene;
    rad_bvh *bvh;
    rad_raycaster rc;
    uint32_t file_light_count; /* lights of the file itself (the rest came from the command line) */
    void *lights_storage;      /* private (tool_add_lights) */
} tool_world;
/* loads, validates and builds the BVH; prints the error and returns 1 on failure, else 0 */
int tool_open_world(const char *cmd, const char *path_or_name, tool_world *w);
/* the same with the command line's lights added (lights may be NULL) */
int tool_open_world_lit(const char *cmd, const char *path_or_name, const tool_lights *lights,
                            tool_world *w);
void tool_close_world(tool_world *w);
/* A camera for a scene that has none (tool_scene.has_camera 0): of the views from outside
   the bounds along +z, -z, +x, -x, -y, +y (the bounding sphere in view) and from inside them,
   the first outside one whose sample rays hit mostly front faces (fov 39.3 degrees), else the
   inside one that sees most front faces (fov 75, from near the bounds' side behind it); a
   camera behind a box's back wall sees only back faces, which render black.
   Prints the bounds and the camera chosen, as --camera and --fov options, to stderr. */
void tool_choose_camera(const char *cmd, const rad_scene *scene, const rad_raycaster *rc, int width, int height,
                            rad_camera *cam);

/* ---- the classic method: patches, F, direct light, solve (classic.c) ---------------------- */
typedef enum tool_solver { TOOL_JACOBI = 0, TOOL_GAUSS_SEIDEL = 1, TOOL_DIRECT = 2 } tool_solver;
typedef struct tool_classic_options {
    uint32_t patches;        /* --patches N: target patch count (default 2000) */
    float max_edge;          /* --max-edge L (0: none) */
    uint32_t samples;        /* --samples S: form-factor samples per patch pair (default 16) */
    tool_solver solver;  /* --solver jacobi|gauss-seidel|direct */
    uint32_t bounces;        /* --bounces K (Jacobi; default 64) */
    uint32_t light_samples;  /* --light-samples N: shadow rays per point (default 16) */
    int sources_only;        /* 1: tool_classic_solve stops after E (L, B, H stay NULL) */
    int no_form_factors;     /* with sources_only: F is not built (ff stays NULL; --method stochastic) */
    /* the dense build's budget (budget.c): checked by tool_classic_solve before the patches
       (N at least the triangle count) and after them */
    double max_memory;       /* --max-memory SIZE in bytes (0: MemAvailable) */
    int force;               /* --force: build whatever the estimate */
    double dense_bytes_per_n2; /* bytes per N^2 entry the run holds at its peak (0: 4, F alone) */
    double dense_cubic;      /* flops / N^3 beyond the form factors (LU, multibounce) */
    uint32_t dense_local_m;  /* local: capacity M of the 12 M^2 bytes of T (0: none) */
    const char *dense_method; /* the method named in the refusal (NULL: classic) */
    const char *dense_instead; /* the refusal's advice (NULL: --method aavp or vp) */
} tool_classic_options;
void tool_classic_options_default(tool_classic_options *o);
/* argv[*a] is one of the options above: parses it (and its value, advancing *a) and returns
   1; returns 0 when it is not one of them, 2 on a bad value (message printed) */
int tool_classic_option(const char *cmd, int argc, char **argv, int *a, tool_classic_options *o);
const char *tool_classic_help(void);

/* ---- the dense build's budget (budget.c) ------------------------------------------------ */
/* A dense build estimated to take longer than this is refused (without --force). */
#define TOOL_DENSE_MAX_SECONDS 3600.0
/* --max-memory SIZE: bytes with an optional K, M, G or T (powers of 1024); 0 or 2 (printed) */
int tool_parse_bytes(const char *cmd, const char *opt, const char *text, double *out);
/* MemAvailable of /proc/meminfo in bytes; 0 where unknown (then only --max-memory limits) */
double tool_mem_available(void);
struct tool_method_options;
/* Fills o's dense_* fields for the method of mo (bake: a classic bake also writes F twice).
   (methods.c: the costs are the methods') */
void tool_dense_plan(tool_classic_options *o, const struct tool_method_options *mo, int bake);
/* Before a dense build of n patches (lower_bound: n is the triangle count, the patches not made
   yet): 0 when the estimate fits the memory limit and TOOL_DENSE_MAX_SECONDS (or
   o->force); else prints the estimate, the limit and the virtual-patch methods, returns 1. */
int tool_dense_check(const char *cmd, const tool_classic_options *o, uint32_t n, int lower_bound);

/* Patches, dense F, direct irradiance D of the patches (emitters and analytic lights),
   E = rho D (RAD_SOURCE_DIRECT), the indirect solution L, B = E + L and H = F B. */
typedef struct tool_classic {
    rad_patches *patches;
    rad_form_factors *ff;
    float *D, *E, *L, *B, *H;   /* 3N floats each */
    double solve_seconds;       /* the solver call alone (the per-frame cost of the method) */
} tool_classic;
/* prints progress and errors; returns 0 or 1 */
/* Its steps, for the distributed bake (cmd_merge.c): the patches, D and E only (ff, L, B, H
   stay NULL); then, given c->patches, c->E and F, the solve of o->solver into c->L, c->B and
   c->H (allocated here; tool_classic_free or free() them). 0 or 1 (message printed). */
int tool_classic_sources(const char *cmd, const tool_world *w, const tool_classic_options *o,
                             tool_classic *out);
int tool_classic_indirect(const char *cmd, const tool_classic_options *o, const rad_matrix *F,
                              tool_classic *c);
int tool_classic_solve(const char *cmd, const tool_world *w, const tool_classic_options *o,
                           tool_classic *out);
void tool_classic_free(tool_classic *c);

/* The tool's own container sections (user types: the library's are in its rad_section_type
   table), in one place. */
#define TOOL_SECTION_OPTIONS (RAD_SECTION_USER + 1u) /* "rad.options": one tool_bake_info */
#define TOOL_SECTION_METHOD (RAD_SECTION_USER + 2u)  /* "rad.method": one tool_method_info */
#define TOOL_SECTION_ROWSUMS (RAD_SECTION_USER + 3u) /* "rad.rowsums": N floats */
#define TOOL_SECTION_SHARD (RAD_SECTION_USER + 0x20u) /* a distributed bake's part: tool_shard_info */
#define TOOL_SECTION_ROWS (RAD_SECTION_USER + 0x21u)  /* the part's row ranges */
#define TOOL_SECTION_PAIRS (RAD_SECTION_USER + 0x22u) /* the part's pairs */

/* The record a bake stores its options in (TOOL_SECTION_OPTIONS, name "rad.options"). */
typedef struct tool_bake_info {
    uint32_t magic;          /* 0x52414442 */
    uint32_t patches;
    float max_edge;
    uint32_t samples;
    uint32_t solver;
    uint32_t bounces;
    uint32_t light_samples;
    uint32_t triangle_count; /* of the scene baked */
} tool_bake_info;
/* the rad.options record of a bake of w with o */
/* The library's plan (rad_baker_plan with the command line's patch, solve and memory options)
   for 'method' (AUTO: classic or virtual patches; VIRTUAL_PATCHES: the resolution), counting
   'kind' at 'face_points' (0: the default) and 'voxels_per_path' (0: 6.5); the virtual
   patches' CPU held within 4 minutes per 100 000 triangles (at least 10 s). 0 or 1 (printed). */
int tool_plan(const char *cmd, const tool_world *w, const tool_classic_options *o, rad_baker_method method, rad_vp_kind kind,
              uint32_t face_points, float voxels_per_path, rad_baker_choice *plan);
/* No --proxy given to rad lightmap or rad probes: the plan keeps the classic patches, or sets
   *kind to TOOL_PROXY_AAVP and *resolution to its resolution; says which ('what' names the
   output). 0 or 1 (printed). */
int tool_plan_proxy(const char *cmd, const tool_world *w, const tool_classic_options *o, float voxels_per_path,
                    const char *what, int *kind, uint32_t *resolution);
/* The engine tier's bake of the world's scene and lights (one group): d->outputs (and
   d->probe_options) as given, the rest of d filled here; the classic options (patches,
   max edge, samples, light samples, and --solver for classic) become the baker's, with
   'method', 'bounces' (0: no bounce; RAD_MB_INFINITE: Gauss-Seidel) and 'vp_resolution'
   (0: the plan's). A classic bake is refused as tool_dense_check refuses it (at least one
   patch per triangle, then the patches the plan counts); the tier's own budget is not used.
   Prints the plan's reason; 'base' (may be NULL: zeros) gives the baker's options the
   command line does not set (keep, lightmap_samples, vp_kind, vp_face_points, ...).
   0, 1 after printing why, or -1 (nothing done) when nothing in the world emits. */
int tool_baker_run(const char *cmd, const tool_world *w, const tool_classic_options *o, rad_baker_method method,
                   uint32_t bounces, uint32_t vp_resolution, const rad_baker_options *base, rad_baker_desc *d,
                   rad_baker_result **out);
void tool_bake_info_fill(tool_bake_info *info, const tool_world *w, const tool_classic_options *o);
/* The hash of a rad.options record and of the lights given on the command line (w's lights
   past file_light_count; none: the hash of the record alone, as before those options), kept
   in the bake's signature (rad_bake_signature.options) so that a bake's options section and
   lights are known to be the ones it was made with. */
uint64_t tool_options_hash(const tool_bake_info *info, const tool_world *w);
/* Points the signature section among secs[0..count) (written by rad_save_memory with the scene's
   hashes) at *sig, a copy with the options hash of 'info' and w's lights added. */
void tool_sign_options(rad_section *secs, uint32_t count, const tool_bake_info *info, const tool_world *w,
                           rad_bake_signature *sig);

/* ---- lighting models for the direct term (shading.c) ------------------------------------ */
/* "none" (-1) or a rad_shading_model name; 0 on success, else prints and returns 2 */
int tool_parse_shading(const char *cmd, const char *text, int *out_model);
/* Direct radiance at 'count' points (normals n, unit directions to the viewer v, albedos):
   sum over the analytic lights of E V R(l, v, n) for the model, plus albedo / pi times the
   irradiance of the emissive triangles and the sky. 0 on success, 1 (message printed). */
int tool_shade_direct(const tool_world *w, int model, uint32_t light_samples, const float *points,
                          const float *normals, const float *views, const float *albedos, uint32_t count,
                          float *out_rgb);
/* ---- the teaching methods: options (methods.c), bakes (method_bake.c) ------------------------------ */
typedef enum tool_method {
    TOOL_CLASSIC = 0, TOOL_MULTIBOUNCE = 1, TOOL_TEMPORAL = 2, TOOL_PATHTRACE = 3,
    TOOL_STOCHASTIC = 4, /* bakes store the value: the render-only methods after it are never stored */
    TOOL_LOCAL = 5, TOOL_VP = 6, TOOL_AAVP = 7, /* render only (cmd_render.c); vp, aavp also bake_vp (cmd_bake.c) */
    TOOL_HIERARCHICAL = 8, /* cmd_render.c; baked as rho H on patches (tool_method_bake) */
    TOOL_LIGHTMAP = 9      /* render only (cmd_render.c): a lightmap bake shades the indirect light */
} tool_method;
/* --format: the storage of F_mb (the values are the kinds of the header's MB info record) */
typedef enum tool_mb_format {
    TOOL_MB_FLOAT = 0, TOOL_MB_HALF = 1, TOOL_MB_BC1 = 2, TOOL_MB_BC4X3 = 3
} tool_mb_format;

/* Options of the two methods; 'given' has bit TOOL_OPT_x set for each option on the
   command line (to reject options that do not apply and to let render override a bake). */
typedef struct tool_method_options {
    tool_method method;   /* --method */
    uint32_t bounces;         /* --bounces K|inf (RAD_MB_INFINITE); default 64 like classic */
    uint32_t format;          /* --format float|half|bc1|bc4x3 (default bc4x3) */
    float outliers;           /* --outliers P: fraction of F_mb entries kept exactly (default 0.05) */
    int reorder;              /* --reorder / --no-reorder (default on) */
    uint32_t reorder_samples; /* --reorder-samples N (0: exact, the default) */
    uint32_t tile;            /* --tile T: scales per T x T texels, 0: per matrix (default 64) */
    uint32_t mode;            /* --mode feedback|single|multibounce: a rad_temporal_mode (default feedback) */
    uint32_t k;               /* --k K: draws per row and frame (default 10) */
    float w;                  /* --w W: a fixed blend weight (0.998 when --w is not given; unused then) */
    int adaptive;             /* --adaptive: per-row weight (the default; --w W turns it off) */
    uint32_t seed;            /* --seed S (default 0) */
    uint32_t frames;          /* --frames N (render; default 1024) */
    const char *sequence;     /* --sequence DIR (render) */
    uint32_t every;           /* --every N (render; default 1) */
    uint32_t vp_resolution;   /* --vp-resolution R: voxels along the longest axis (default 16) */
    uint32_t vp_max_patches;  /* --vp-max-patches B: the finest resolution with at most B patches (0: off) */
    uint32_t face_points;     /* --face-points P: Hammersley points per voxel face (default 16) */
    uint32_t local_m;         /* --local-m M: local matrix capacity, at most the patches (0, the
                                 default: every patch up to TOOL_LOCAL_M_AUTO_MAX) */
    uint32_t sr_rays;         /* --sr-rays N: stochastic rays of the first iteration / walks (0: the library's 64 per patch) */
    uint32_t sr_iterations;   /* --sr-iterations N: Jacobi shooting iterations at most / walk batches (0: the library's) */
    uint32_t sr_estimator;    /* --sr-estimator jacobi|walk: a rad_stochastic_method (default jacobi) */
    float hr_eps;             /* --hr-eps E: hierarchical BF refinement tolerance (0: 1e-5) */
    float hr_min_area;        /* --hr-min-area A: smallest element, scene units^2 (0: total area / 10000) */
    uint32_t hr_rays;         /* --hr-rays R: points and visibility rays per link, a square (0: 4) */
    uint32_t light_path;      /* --light-path: 0 none, 1 line, 2 circle (render, temporal over a proxy) */
    float path[6];            /* line: P0 (0..2), P1 (3..5); circle: centre (0..2), radius (3) */
    uint32_t light_rays;      /* --light-rays N: shadow rays per moving light and frame (0: every sample) */
    uint32_t proxy;           /* --proxy patches|aavp|vp (tool_proxy; render, with multibounce,
                                 temporal and local: the method runs over virtual patches) */
    uint32_t given;           /* TOOL_OPT_* bits */
} tool_method_options;
/* --proxy: what multibounce, temporal and local run over (default: classic patches) */
typedef enum tool_proxy { TOOL_PROXY_PATCHES = 0, TOOL_PROXY_AAVP = 1, TOOL_PROXY_VP = 2 } tool_proxy;
#define TOOL_OPT_PROXY (1u << 28)
enum {
    TOOL_OPT_BOUNCES = 1u << 0, TOOL_OPT_FORMAT = 1u << 1, TOOL_OPT_OUTLIERS = 1u << 2,
    TOOL_OPT_REORDER = 1u << 3, TOOL_OPT_REORDER_SAMPLES = 1u << 4, TOOL_OPT_TILE = 1u << 5,
    TOOL_OPT_MODE = 1u << 6, TOOL_OPT_K = 1u << 7, TOOL_OPT_W = 1u << 8, TOOL_OPT_ADAPTIVE = 1u << 9,
    TOOL_OPT_SEED = 1u << 10, TOOL_OPT_FRAMES = 1u << 11, TOOL_OPT_SEQUENCE = 1u << 12,
    TOOL_OPT_EVERY = 1u << 13, TOOL_OPT_METHOD = 1u << 14, TOOL_OPT_VP_RESOLUTION = 1u << 15,
    TOOL_OPT_VP_MAX_PATCHES = 1u << 16, TOOL_OPT_FACE_POINTS = 1u << 17, TOOL_OPT_LOCAL_M = 1u << 18,
    TOOL_OPT_SR_RAYS = 1u << 19, TOOL_OPT_SR_ITERATIONS = 1u << 20, TOOL_OPT_SR_ESTIMATOR = 1u << 21,
    TOOL_OPT_HR_EPS = 1u << 22, TOOL_OPT_HR_MIN_AREA = 1u << 23, TOOL_OPT_HR_RAYS = 1u << 24,
    TOOL_OPT_LIGHT_PATH = 1u << 25, TOOL_OPT_LIGHT_RAYS = 1u << 26
};
#define TOOL_OPT_SR (TOOL_OPT_SR_RAYS | TOOL_OPT_SR_ITERATIONS | TOOL_OPT_SR_ESTIMATOR)
#define TOOL_OPT_HR (TOOL_OPT_HR_EPS | TOOL_OPT_HR_MIN_AREA | TOOL_OPT_HR_RAYS)
#define TOOL_OPT_VP (TOOL_OPT_VP_RESOLUTION | TOOL_OPT_VP_MAX_PATCHES | TOOL_OPT_FACE_POINTS)
#define TOOL_OPT_MB_BUILD (TOOL_OPT_FORMAT | TOOL_OPT_OUTLIERS | TOOL_OPT_REORDER | \
                               TOOL_OPT_REORDER_SAMPLES | TOOL_OPT_TILE)
#define TOOL_OPT_TEMPORAL (TOOL_OPT_MODE | TOOL_OPT_K | TOOL_OPT_W | TOOL_OPT_ADAPTIVE)
#define TOOL_OPT_RENDER_ONLY (TOOL_OPT_FRAMES | TOOL_OPT_SEQUENCE | TOOL_OPT_EVERY | \
                                  TOOL_OPT_LIGHT_PATH | TOOL_OPT_LIGHT_RAYS)

/* The default --local-m covers every patch of a scene up to this many (the set is then the
   whole scene and local gives the classic solution): T takes 12 M^2 bytes (192 MiB here) and
   its rebuild 6 M^3 flops (2188 patches: 12.6 s on 2 cores). The old fixed 1024 left half of
   the 2188-patch Cornell box without indirect light (29.5 dB against classic). */
#define TOOL_LOCAL_M_AUTO_MAX 4096u
void tool_method_options_default(tool_method_options *mo);
/* argv[*a] is --method or one of the options above: parses it (and its value, advancing *a)
   and returns 1; 0 when it is not one of them; 2 on a bad value (message printed). */
int tool_method_option(const char *cmd, int argc, char **argv, int *a, tool_method_options *mo);
/* After parsing: rejects options that do not apply to mo->method (and render-only options
   when !render), moves a finite --bounces into o->bounces for classic; 0 or 2 (printed). */
int tool_method_check(const char *cmd, int render, tool_method_options *mo, tool_classic_options *o);
/* the help of the options above for rad render (render 1) or rad bake (0) */
const char *tool_method_help(int render);
enum { TOOL_METHOD_HELP_RENDER = 1, TOOL_METHOD_HELP_BAKE = 2 };
const char *tool_method_name(tool_method method);
/* the names of a multibounce --format (tool_mb_format) and a temporal --mode (rad_temporal_mode) */
const char *tool_mb_format_name(uint32_t format);
const char *tool_temporal_mode_name(uint32_t mode);
/* --method hierarchical: rad_hierarchical_create and solve over the world with E = rho D at
   the elements' centroids (D: rad_direct_irradiance with light_samples shadow rays, emitters
   included, as the classic patches' D) and mo's --hr-* options; prints the counts and the
   form-factor work. 0 (*out owned by the caller) or 1 (message printed). */
int tool_hierarchical_build(const char *cmd, const tool_world *w, const tool_method_options *mo,
                                uint32_t light_samples, rad_hierarchical **out);

/* The user sections the methods add: what was built, and the row sums S_i of F (the halo
   correction of the per-vertex H needs them and these bakes hold no F). --method stochastic
   keeps its options in the same record: rays in k, iterations in bounces, the estimator in
   mode, the seed in seed, the solve's seconds in build_seconds and its rays cast in
   bytes_lo/bytes_hi; its bake holds the solution L as the vector "L" and row sums estimated
   by rays (it builds no F). */
typedef struct tool_method_info {
    uint32_t magic;           /* 0x5241444D */
    uint32_t method;          /* TOOL_MULTIBOUNCE or TOOL_TEMPORAL */
    uint32_t bounces;         /* as given (--bounces; F_mb holds bounces + 1, see methods.c) */
    uint32_t format;          /* tool_mb_format */
    float outliers;
    uint32_t reorder, reorder_samples, tile;
    uint32_t mode;            /* rad_temporal_mode */
    uint32_t k;
    float w;
    uint32_t adaptive, seed;
    float build_seconds;      /* F_mb (+ compression) or alias tables */
    float mse, max_abs_error, source_mean_square; /* compression report (bc1, bc4x3), else 0 */
    uint32_t bytes_lo, bytes_hi; /* bytes the render reads: F_mb storage or alias tables */
} tool_method_info;
#define TOOL_METHOD_MAGIC 0x5241444Du

/* The bake of --method multibounce or temporal as container bytes (malloc'd, free with
   free()): patches, E, D, the row sums, rad.options, rad.method and the method's sections
   (F_mb as "Fmb"; alias tables "F", or "Fmb.r", "Fmb.g", "Fmb.b" in --mode multibounce).
   Prints what was built to stderr. 0 or 1 (message printed). */
int tool_method_bake(const char *cmd, const tool_world *w, const tool_classic_options *o,
                         const tool_method_options *mo, void **out, size_t *out_size);

/* The render side: the indirect light of a loaded bake, step by step. */
typedef struct tool_indirect tool_indirect;
/* mo: the render's options (method, and --k, --w, --adaptive, --seed overriding the bake's).
   Errors name what the bake lacks. 0 or 1 (message printed). */
int tool_indirect_open(const char *cmd, const char *bake_name, const rad_bake *bake,
                           const tool_method_options *mo, tool_indirect **out);
/* multibounce: L = F_mb E (every call the same); temporal: one more frame. Writes the patches'
   irradiance from the secondary sources H = L / rho (3N floats; 0 where rho is 0) and the
   seconds the method's own work took. 0 or 1 (message printed). */
int tool_indirect_step(tool_indirect *m, float *H, double *seconds);
const float *tool_indirect_rowsums(const tool_indirect *m);
void tool_indirect_close(tool_indirect *m);

/* ---- the distributed bake: parts and merge (cmd_merge.c; docs/distributed.md) ----------- */
/* rad bake --shard I/N or --rows A:B */
typedef struct tool_shard_spec {
    uint32_t index, count;        /* --shard I/N (count 0: not given) */
    int rows;                     /* 1: --rows A:B given */
    uint32_t row_begin, row_end;  /* --rows: rows A to B-1 */
} tool_shard_spec;
#define TOOL_MAX_SHARDS 65536u
/* chunks of rows per shard (the snake of tool_shard_ranges) */
#define TOOL_SHARD_CHUNKS 64u
/* "I/N" and "A:B" into s; 0, or 2 with a message */
int tool_parse_shard(const char *cmd, const char *text, tool_shard_spec *s);
int tool_parse_rows(const char *cmd, const char *text, tool_shard_spec *s);
/* The rows of shard I of n over N rows as ranges [ranges[2k], ranges[2k+1]), ascending; returns
   their count (at most TOOL_SHARD_CHUNKS; 0 when n > N leaves the shard nothing). Shards of one n cover the
   rows exactly once, with nearly equal pair counts (rad_form_factor_pair_count). */
uint32_t tool_shard_ranges(uint32_t N, uint32_t I, uint32_t n, uint32_t *ranges);

/* The record a part holds (TOOL_SECTION_SHARD, "rad.shard"), beside its row ranges
   ("rad.rows": uint32 pairs) and its pairs ("F.upper", "F.lower": rad_form_factor_pairs). */
typedef struct tool_shard_info {
    uint32_t magic;           /* TOOL_SHARD_MAGIC */
    uint32_t format;          /* 1 */
    char library[16];         /* RAD_VERSION_STRING of the build that baked it */
    uint32_t patches;         /* N */
    uint32_t shard, shard_count; /* --shard I/N; shard_count 0: --rows */
    uint32_t range_count;
    uint64_t pairs;           /* pairs {i, j}, j > i, of its rows */
    uint64_t pairs_evaluated; /* of those, the facing ones computed */
    double seconds;           /* the form factors of this part (a record of the run) */
} tool_shard_info;
#define TOOL_SHARD_MAGIC 0x52414453u

/* A classic bake's part as container bytes (malloc'd, free with free()). 0 or 1 (printed). */
int tool_bake_part(const char *cmd, const tool_world *w, const tool_classic_options *o,
                       const tool_shard_spec *spec, void **out, size_t *out_size);
/* A part in memory, named for messages (a file name, "rank 2") */
typedef struct tool_part {
    const char *name;
    const void *data;
    size_t size;
} tool_part;
/* Checks the parts, joins them, solves, writes out_path (a temporary renamed into place, so a
   failure leaves nothing). 0, 1 (message printed naming the part and the reason) or 2. */
int tool_merge(const char *cmd, const tool_part *parts, uint32_t count, const char *out_path);
int tool_cmd_merge(int argc, char **argv);

/* rad bake's command line (cmd_bake.c), shared with tools/mpi/rad_mpi.c */
typedef struct tool_bake_args {
    const char *scene, *out;
    tool_classic_options o;
    tool_method_options mo;
    uint32_t threads;
    tool_shard_spec shard;
    tool_lights lights;       /* --sun, --sky, ...: free with tool_lights_free */
} tool_bake_args;
/* -1: go on and bake; else the exit code (--help: 0 after printing it; 2: bad usage, printed).
   args->lights is to be freed (tool_lights_free) whatever it returns. */
int tool_bake_parse(const char *cmd, int argc, char **argv, tool_bake_args *args);
/* ---- lightmaps (cmd_lightmap.c, unwrap.c) ------------------------------------------------ */
int tool_cmd_lightmap(int argc, char **argv);
/* When the user gave no atlas size: pick the smallest square power of two from the default up
   to max_side into which the charts pack, refused when its estimate (bytes_per_texel per
   texel) passes memory_limit (0: no limit; memory_from names where the limit came from). */
typedef struct tool_unwrap_auto {
    uint32_t max_side;
    double bytes_per_texel;
    double memory_limit;
    const char *memory_from;
} tool_unwrap_auto;
/* the largest atlas side the tool picks by itself (a larger one must be asked for) */
#define TOOL_LIGHTMAP_AUTO_MAX 4096u
/* A simple automatic lightmap unwrap (unwrap.c: charts of connected triangles within 30
   degrees, planar projection, shelf packing with 2-texel gutters): 6 floats per scene triangle
   into out_uvs, the chart count into out_charts (may be NULL). *width x *height is the atlas;
   with autosize (may be NULL) a larger square one is chosen when the charts do not fit it,
   written back and said on stderr. 0, or 1 with a message printed as "rad CMD: ..." that
   names size_option and the smallest size that fits when the atlas is too small. */
int tool_unwrap(const char *cmd, const char *size_option, const rad_scene *scene, uint32_t *width, uint32_t *height,
                const tool_unwrap_auto *autosize, float *out_uvs, uint32_t *out_charts);
/* ---- lightmap bakes (lightmap.c), shared by rad lightmap and rad render --method lightmap;
   the virtual patches they and rad probes share (vp.c) --------------------------------- */
/* --proxy aavp|vp: the indirect light from virtual patches instead of classic patches */
typedef struct tool_lightmap_proxy {
    int kind;                /* TOOL_PROXY_AAVP, TOOL_PROXY_VP or TOOL_LIGHTMAP_HIERARCHICAL */
    uint32_t resolution;     /* voxels along the longest axis (0: 16) */
    uint32_t face_points;    /* Hammersley points per voxel face (0: 16) */
    float hr_eps;            /* hierarchical: BF tolerance (0: the tool's 1e-5) */
    uint32_t max_patches;    /* aavp, vp: the finest resolution with at most this many patches
                                (tool_vp_resolution_within; 0: resolution as given) */
} tool_lightmap_proxy;
/* --vp-max-patches B: the finest voxel resolution whose set of 'kind' has at most B patches,
   found by counting (rad_vp_count) from 'start' (0: 16); prints the choice. 0, or 1 after
   printing why (even resolution 1 gives more). */
int tool_vp_resolution_within(const char *cmd, const tool_world *w, rad_vp_kind kind, uint32_t face_points,
                              uint32_t max_patches, uint32_t start, uint32_t *out);
/* A bake of rad bake --method aavp|vp in memory (data, size: kept alive by the caller while
   *ct_out lives): its container, its set "vp" (rad_vp_load; scene may be NULL) and its source
   vector E (3 floats a patch, each in [0, RAD_BAKE_VALUE_MAX], malloc'd). The errors tell a
   damaged file, a bake without virtual patches and damaged virtual patches apart. 0, or 1
   after printing why (nothing to free). */
int tool_vp_bake_open(const char *cmd, const char *path, const void *data, size_t size, const rad_scene *scene,
                      rad_container **ct_out, rad_virtual_patches **vp_out, float **E_out);
/* rad lightmap --proxy hierarchical: the indirect light from the hierarchical solution's smooth
   lookup (rad_lightmap_gather_hierarchical); a kind of its own, past the tool_proxy values */
#define TOOL_LIGHTMAP_HIERARCHICAL 3
/* --proxy aavp|vp (rad lightmap, rad probes): virtual patches of w's scene at px's resolution
   (or the finest within px->max_patches) and face points (CSR rows), E = rho D at their samples (the lights of w, emitters included,
   co->light_samples), L by co->bounces Jacobi bounces (Gauss-Seidel with --solver
   gauss-seidel); *B_out = E + L and *H_out = F (E + L) per virtual patch (3N floats to free;
   either output may be NULL), *solve_seconds the solve and H (may be NULL). Prints what it
   built. 0, or 1 after printing why (nothing left to free). */
int tool_vp_proxy_solve(const char *cmd, const tool_world *w, const tool_classic_options *co, const tool_lightmap_proxy *px,
                        rad_virtual_patches **vp_out, float **B_out, float **H_out, double *solve_seconds);
/* --proxy aavp|vp as the engine tier's options: the kind, face points, sparse rows (keep, as
   tool_vp_proxy_solve builds them) and --solver gauss-seidel into bo, and the resolution
   (px's, the finest within px->max_patches, or the default) into *resolution. 0 or 1 (printed). */
int tool_vp_proxy_options(const char *cmd, const tool_world *w, const tool_classic_options *co, const tool_lightmap_proxy *px,
                          rad_baker_options *bo, uint32_t *resolution);
typedef struct tool_lightmap_baked {
    tool_world w;        /* the world baked: the caller's, or a copy over an unwrapped scene */
    tool_classic cl;     /* the classic solution gathered (patches of w.scene), or zero with a proxy */
    rad_virtual_patches *vp; /* the proxy's set (of w.scene), or NULL */
    rad_hierarchical *hr;    /* --proxy hierarchical: the solution (of w.scene), or NULL */
    uint32_t patches;        /* unknowns of the solution: classic patches or virtual patches */
    double solve_seconds;    /* the solve (K bounces and H = F B) */
    const rad_lightmap *lm;  /* own_lm, or the engine tier's (baked) */
    rad_lightmap *own_lm;
    rad_baker_result *baked; /* the engine tier's bake (kept objects), or NULL */
    float *values;           /* width * height * (3 or 12) floats, dilated and stitched */
    float *uvs;              /* the unwrap's lightmap uvs, or NULL */
    rad_mesh_desc mesh;      /* the unwrap's mesh (w.file.desc of a copy names it) */
    float *mesh_positions, *mesh_uvs; /* its arrays when it drops two-sided twins, or NULL */
    uint32_t *mesh_materials;
    int own_scene;           /* w.scene and w.bvh are ours */
} tool_lightmap_baked;
/* rad lightmap's defaults: atlas side, sample points per texel, shadow rays per sample point
   and patch, rays per texel of the hemisphere gather */
#define TOOL_LIGHTMAP_SIZE 256
#define TOOL_LIGHTMAP_TEXEL_SAMPLES 4u
#define TOOL_LIGHTMAP_VISIBILITY_RAYS 2u
#define TOOL_LIGHTMAP_HEMISPHERE_RAYS 256u
/* tool_lightmap_request.gather: choose by the work, the exact gather up to this many
   sample-patch pairs (its cost grows with them; the hemisphere gather's does not) */
#define TOOL_LIGHTMAP_GATHER_AUTO (-1)
#define TOOL_LIGHTMAP_EXACT_MAX_PAIRS 2e7
/* bytes a texel of the bake holds at its peak, for the automatic atlas size's memory check:
   the texel record and its samples' records, the gathered values (channels floats, twice) */
#define TOOL_LIGHTMAP_TEXEL_BYTES(samples, channels) (29.0 + 29.0 * (double)(samples) + 8.0 * (double)(channels) + 12.0)
/* What tool_lightmap_bake makes (tool_lightmap_request_default: the defaults above, RGB
   without direct light, over the file's uv set, classic patches) */
typedef struct tool_lightmap_request {
    int width, height;           /* atlas texels */
    int auto_size;               /* the user gave no size: an unwrap whose charts do not fit width x
                                    height gets a larger atlas (tool_unwrap_auto; the bake's lm has
                                    the size used) */
    uint32_t texel_samples;      /* sample points per texel */
    uint32_t visibility_rays;    /* shadow rays per sample point and patch */
    int gather;                  /* a rad_lightmap_gather_method, or TOOL_LIGHTMAP_GATHER_AUTO */
    uint32_t hemisphere_rays;    /* rays per texel of the hemisphere gather */
    int sh;                      /* L1 SH of the indirect light instead of RGB irradiance */
    int force_unwrap;            /* unwrap even when the file has a second uv set */
    int direct;                  /* RGB: add the direct light of the lights and emitters per texel */
    const tool_lightmap_proxy *proxy; /* the indirect light from a proxy (NULL: classic patches) */
    uint32_t final_gather;       /* rays per texel of the final gather in front of the solution
                                    (rad_baker_options.lightmap_final_gather; 0: none), or
                                    TOOL_LIGHTMAP_FINAL_GATHER_AUTO; the engine tier's bakes only */
} tool_lightmap_request;
/* tool_lightmap_request.final_gather: TOOL_LIGHTMAP_FINAL_GATHER rays per texel with --proxy
   aavp|vp (their voxel averages miss the first bounce, as the renderer's final gather found),
   none for the classic patches */
#define TOOL_LIGHTMAP_FINAL_GATHER_AUTO 0xFFFFFFFFu
#define TOOL_LIGHTMAP_FINAL_GATHER 32u
void tool_lightmap_request_default(tool_lightmap_request *rq);
/* Solves the classic method (rq->proxy NULL) or virtual patches (E = rho D at their samples, K
   Jacobi bounces of --bounces, Gauss-Seidel with --solver gauss-seidel, H = F (E + L)) over
   the lightmapped world (the file's second uv set, else the unwrap) and bakes rq: texels,
   gather (classic: of B, sh: L1 SH, else RGB irradiance; proxy: rad_lightmap_gather_vp of H,
   RGB only), the direct light per texel when asked, dilation, stitching. Without a proxy a
   scene whose dense build would be refused is refused before the unwrap, naming --proxy aavp.
   Jacobi on the patches as made and aavp|vp at the default face points bake through the
   engine tier (rad_baker_run, the same bits; out->baked holds it). 0, or 1 after printing
   why (out freed). Free with tool_lightmap_bake_free. */
int tool_lightmap_bake(const char *cmd, const tool_world *world, const tool_classic_options *co,
                       const tool_lightmap_request *rq, tool_lightmap_baked *out);
void tool_lightmap_bake_free(tool_lightmap_baked *b);

/* ---- rad render's pieces: the pixels (pixels.c) and the teaching methods (render_methods.c) - */
/* What tool_render_pixels draws: the view and the per-pixel options of the command line */
typedef struct tool_render_view {
    rad_camera cam;
    int width, height;
    uint32_t aa;             /* --aa: stratified samples per pixel */
    uint32_t light_samples;  /* --pixel-light-samples */
    float exposure;          /* --exposure (PNG frames of --sequence) */
    int shading;             /* --shading: a rad_shading_model, or -1 for none (tools/shading.c) */
    uint32_t final_gather;   /* --final-gather N: rays per sample for one traced bounce (0: off) */
} tool_render_view;

/* Where tool_render_pixels takes the irradiance H from the secondary sources at a sample: the
   first of baker (the engine tier's own final gather, rad_baker_irradiance), vp (rad_vp_gather
   of vp_H), hr (the hierarchical solution's smooth lookup) and lm (a bilinear lookup of the
   RGB irradiance lightmap lm_values at the sample's lightmap uv) that is set, else the
   per-vertex Hv of the patches P. */
typedef struct tool_render_source {
    const rad_patches *P;
    const float *Hv;
    const rad_virtual_patches *vp;
    const float *vp_H;
    const rad_hierarchical *hr;
    const rad_lightmap *lm;
    const float *lm_values;
    const rad_baker_result *baker; /* the engine tier's kept solution (rad_baker_irradiance) */
    double gather_seconds;   /* out: the time spent in the gathers and lookups */
} tool_render_source;

/* rad render's command line */
typedef struct tool_render_args {
    const char *scene, *out, *bake; /* SCENE, -o, --bake */
    tool_classic_options o;
    tool_method_options mo;
    tool_render_view view;
    float fov;               /* --fov (0: the camera's) */
    uint32_t spp;            /* --spp: pathtrace samples per pixel */
    uint32_t threads;        /* --threads */
    uint32_t lm_size, lm_samples, lm_vis; /* --lightmap-size, --texel-samples, --visibility-rays */
    uint32_t given;          /* TOOL_RENDER_GIVEN_* */
} tool_render_args;
/* tool_render_args.given: --camera; --lightmap-size (else an unwrap too fine for it gets a larger
   atlas); one of the lightmap options */
enum { TOOL_RENDER_GIVEN_CAMERA = 1, TOOL_RENDER_GIVEN_LM_SIZE = 2, TOOL_RENDER_GIVEN_LM = 4, TOOL_RENDER_GIVEN_FINAL_GATHER = 8 };
/* The image of the radiosity methods: per sample the direct light D at the hit (shadow rays),
   H from src, radiance albedo / pi (D + H) plus emission; each pixel the mean of its samples,
   added into img (zeroed by the caller). 0 or 1 (printed). */
int tool_render_pixels(const tool_world *w, const tool_render_view *view, tool_render_source *src, tool_image *img);
/* Per-vertex H of the patches without dark halos where a patch is partly covered
   (rad_patches_vertex_irradiance): S the row sums of F, or F itself. 0 or 1 (printed). */
int tool_vertex_H_rowsums(const rad_patches *P, const float *S, const float *H, float *Hv);
int tool_vertex_H(const rad_patches *P, const rad_matrix *F, const float *H, float *Hv);
/* --method multibounce|temporal|stochastic, and hierarchical from a bake: the bake (--bake,
   checked against the scene) or one made here, then the patches' H and the pixels */
int tool_render_with_method(const char *cmd, const tool_world *w, const tool_render_args *ra, tool_image *img);
/* --method hierarchical (no bake) and --method local */
int tool_render_hr_method(const char *cmd, const tool_world *w, const tool_render_args *ra, tool_image *img);
int tool_render_local_method(const char *cmd, const tool_world *w, const tool_render_args *ra, tool_image *img);
/* --method aavp|vp from a --bake file or under a --proxy (multibounce, temporal, its frames), and
   --method classic from a --bake file */
int tool_render_vp_method(const char *cmd, const tool_world *w, const tool_render_args *ra, tool_image *img);
int tool_render_classic_bake(const char *cmd, const tool_world *w, const tool_render_args *ra, tool_image *img);
/* 0 when a loaded bake was made from this scene and these options, else 1 (printed) */
int tool_bake_fits_scene(const char *cmd, const char *bake_path, const rad_bake *bake, const tool_world *w);
/* why rad_load_file refused a bake, printed */
void tool_bake_load_failed(const char *cmd, const char *path, rad_result r);

/* ---- glTF output (gltf_write.c; the convention: docs/engine-formats.md) ------------------- */
/* A baked RGB irradiance lightmap and the scene it was baked over, for engines */
typedef struct tool_gltf_lightmap {
    const rad_scene *scene;            /* the triangles, with the lightmap uvs the bake used */
    const rad_scene *mesh_scene;       /* the same triangles in the same order whose meshes and
                                          names group them (the scene before an unwrap), or NULL */
    const char *const *material_names; /* scene->material_count names, or NULL */
    const rad_camera *camera;          /* written as a camera node, or NULL */
    float aspect;                      /* the view's width / height (0: left to the engine) */
    const rad_lightmap *lightmap;
    const float *values;               /* 3 floats a texel, dilated and stitched */
    const char *hdr_name;              /* the HDR copy's file name as the extras name it, or NULL */
} tool_gltf_lightmap;
/* 1 for a .glb or .gltf name */
int tool_gltf_is_path(const char *path);
/* the HDR copy beside OUT.glb|gltf: OUT.lightmap.exr with OpenEXR support, else
   OUT.lightmap.pfm; and for a .gltf its buffer OUT.bin (NULL for a .glb). malloc'd. */
char *tool_gltf_hdr_path(const char *path);
char *tool_gltf_bin_path(const char *path);
/* Writes path (.glb: one file; .gltf: it and its .bin) into the set (committed by the
   caller). 0, or 1 after printing "rad CMD: ..." (the set aborted). */
int tool_gltf_write(const char *cmd, const char *path, const tool_gltf_lightmap *in, tool_output_set *set);

#endif
