/* radiosity.h - v0.1.0 - diffuse global illumination by the radiosity method
   public domain or MIT, your choice (see end of file)

   Do this:
       #define RADIOSITY_IMPLEMENTATION
   before you include this file in *one* C or C++ file to create the implementation.

       // in every file that uses the library
       #include "radiosity.h"

       // in exactly one file
       #define RADIOSITY_IMPLEMENTATION
       #include "radiosity.h"

   QUICK START (examples/quickstart.c, compiled by the tests)

       #define RADIOSITY_IMPLEMENTATION
       #include "radiosity.h"
       #include <stdio.h>
       #include <stdlib.h>

       int main(void)
       {
           rad_scene_desc desc;
           rad_camera cam;
           rad_scene *scene = NULL;
           rad_patches *patches = NULL;
           rad_bvh *bvh = NULL;
           rad_form_factors *ff = NULL;
           rad_patch_options popt;
           rad_form_factor_options fopt;
           rad_solve_options sopt;
           rad_raycaster rc;
           rad_system sys;
           float *E, *B;
           uint32_t i;

           rad_cornell_box(&desc, &cam);                             // built-in scene (static data)
           if (rad_scene_create(&desc, NULL, &scene) != RAD_SUCCESS) return 1;
           rad_patch_options_default(&popt);
           popt.target_count = 1000;                                 // about 1000 patches
           if (rad_patches_create(scene, &popt, NULL, &patches) != RAD_SUCCESS) return 1;
           if (rad_bvh_create(scene, NULL, &bvh) != RAD_SUCCESS) return 1;
           rad_bvh_raycaster(bvh, &rc);                              // or plug in your own tracer
           rad_form_factor_options_default(&fopt);
           if (rad_form_factors_dense(patches, &rc, &fopt, NULL, &ff) != RAD_SUCCESS) return 1;

           E = (float *)malloc(sizeof(float) * 3 * patches->count);
           B = (float *)malloc(sizeof(float) * 3 * patches->count);
           if (!E || !B) return 1;
           rad_sources(patches, RAD_SOURCE_EMISSION, NULL, E);       // E = pi * emitted radiance
           rad_system_init(&sys, &ff->matrix, patches, E);
           rad_solve_options_default(&sopt);
           sopt.output = RAD_OUTPUT_TOTAL;                           // B = E + L_16
           sopt.bounces = 16;
           if (rad_solve_jacobi(&sys, &sopt, B, NULL, NULL) != RAD_SUCCESS) return 1;

           for (i = 0; i < patches->count; i += patches->count / 4)
               printf("patch %4u on '%s': B = %.3f %.3f %.3f W/m^2\n", i,
                      scene->mesh_names[scene->meshes[patches->patches[i].triangle]], B[3 * i], B[3 * i + 1], B[3 * i + 2]);

           free(E);
           free(B);
           rad_form_factors_destroy(ff);
           rad_bvh_destroy(bvh);
           rad_patches_destroy(patches);
           rad_scene_destroy(scene);
           return 0;
       }

   CONTENTS
       1. OPTIONS                  compile-time macros
       2. THE METHOD               what is computed, in one page
       3. UNITS AND CONVENTIONS    colours, E, what each solver returns
       4. MEMORY                   allocators, ownership, sizes
       5. ERRORS                   rad_result, the logger
       6. THREADING                parallel_for hook, progress and cancel, determinism
       7. RAY QUERIES              the callback table, the built-in BVH, self-intersection
       8. EMBREE                   the optional Embree 3 backend
       9. BAKED DATA               the container format
      10. GLSL                     compute kernels for the GPU, as source text
      11. NUMERICAL ROBUSTNESS     epsilons, singularities, validation
      12. WHAT radiosity.h DOES NOT DO
      13. HISTORY

   1. OPTIONS
       macro                      default            where to set it
       -------------------------  -----------------  -------------------------------------------
       RADIOSITY_IMPLEMENTATION   (undefined)        one .c/.cpp file, before the include
       RADIOSITY_STATIC           (undefined)        everywhere: every function becomes static
       RAD_DLL                    (undefined)        everywhere (Windows): dllexport in the
                                                     implementing file, dllimport elsewhere
       RAD_MALLOC/REALLOC/FREE    malloc/realloc/free implementing file; all three or none
       RAD_ASSERT(x)              assert(x)          implementing file (internal invariants only;
                                                     bad input is an error code, never an assert)
       RAD_NO_STDIO               (undefined)        everywhere: removes rad_save_file and
                                                     rad_load_file (no <stdio.h> file access)
       RAD_NO_SIMD                (undefined)        implementing file: scalar code only. SIMD
                                                     (SSE2/AVX) is used only when the compiler
                                                     already enables it (-msse2 is the x86-64
                                                     default, -mavx / -march=native for AVX).
       RAD_NO_HUGEPAGES           (undefined)        implementing file (Linux): alias tables of
                                                     4 MiB or more are not 2 MiB aligned nor
                                                     advised MADV_HUGEPAGE (see >>api_temporal)
       _OPENMP                    (set by -fopenmp)  implementing file: the default parallel_for
                                                     runs tasks on OpenMP threads

   2. THE METHOD
       A scene is a set of triangles with Lambertian materials. It is cut into patches (one per
       triangle or finer). The form factor F_ij is the fraction of the energy leaving patch i
       that reaches patch j. With albedo rho and a source term E, radiosity satisfies
           B_i = E_i + rho_i * sum_j F_ij B_j            (per colour channel)
       Bounces: B^0 = E, B^k = (rho o F) B^(k-1); the indirect light after K bounces is
       L_K = sum_{k=1..K} B^k and the full solution is B = E + L_inf.

   3. UNITS AND CONVENTIONS
       - Colours are linear RGB, three floats per patch, interleaved (r0 g0 b0 r1 g1 b1 ...).
       - Lengths are whatever the scene uses; nothing assumes metres. Epsilons are relative
         to the scene's bounding-box diagonal.
       - Material emission is RADIANCE L (W m^-2 sr^-1, as OBJ Ke and glTF emissive). The
         exitance of a Lambertian emitter, the quantity radiosity works with, is pi * L.
       - Radiosity B and the source E are exitances (W m^-2). A Lambertian surface of
         radiosity B shows radiance B / pi.
       - Irradiance D, H (W m^-2) is what arrives; a patch reflects rho * irradiance.
       - WHAT E IS. rad_sources() builds E one of two explicit ways, never both:
           RAD_SOURCE_EMISSION  E_i = pi * L_i (emitters only). The solution then holds the
                                direct light at patch resolution.
           RAD_SOURCE_DIRECT    E_i = rho_i * D_i, D_i the direct irradiance from every light
                                (analytic lights and emissive triangles alike, with shadow
                                rays). The emitters' own emission is NOT placed in the system.
                                This is what engines want: they draw direct light per pixel and
                                add rho/pi * (D_pixel + H_pixel), H = F (E + L) the irradiance
                                from the secondary sources (rad_matrix_multiply).
         Mixing the two counts the emitters twice (about 2x too bright in the Cornell box).
       - WHAT THE SOLVERS RETURN. Every solver takes rad_solve_options.output:
           RAD_OUTPUT_INDIRECT  L = B - E (the bounces only; the default)
           RAD_OUTPUT_TOTAL     B = E + L
       - Triangles are wound counter-clockwise seen from the front; the front is the side that
         emits and receives. Patches are one-sided.

   4. MEMORY
       Every object is created by a rad_*_create call that returns RAD_SUCCESS and writes an
       owning pointer, and freed by exactly one rad_*_destroy call (NULL is accepted). Inputs
       are borrowed for the duration of the call and copied where kept; each function's
       comment says so. Output arrays the caller provides (float *out) are filled during the
       call: after an error or a cancel their contents are unspecified (partial results), never
       out of bounds. Owning outputs (rad_x **out) are set to NULL on failure.
       Allocation goes through rad_context.allocator when set (its user pointer is passed to
       every call), else through RAD_MALLOC / RAD_FREE. Every size computation is checked for
       overflow before allocating: an N*N matrix that does not fit in size_t returns
       RAD_ERROR_SIZE_OVERFLOW.

   5. ERRORS
       Every fallible function returns rad_result: RAD_SUCCESS (0) or a negative code;
       rad_result_string() names it. Detail ("triangle 12 of mesh 'floor' has zero area")
       goes to rad_context.log when set. There is no global error state.
       Non-finite values, one rule for every solver and run-time product (rad_matrix_multiply,
       the solvers, rad_multibounce_apply, rad_multibounce_blocks_apply, rad_local_apply,
       rad_temporal_step): a NaN or Inf in the input vector is refused before any work, and
       an output value that overflows float is reported; both return RAD_ERROR_NON_FINITE
       with the index in the log, so a success never carries NaN or Inf. After an overflow
       the output array holds unspecified values (a temporal state is left as before the
       step). Each check is one pass over the vector, O(N) beside the product's O(N^2) or
       O(N k).

   6. THREADING
       radiosity.h never starts a thread. Long calls split their work into tasks and run them
       through rad_context.parallel_for; the default runs them one after another, or on OpenMP
       threads when the implementing file is compiled with OpenMP. Tasks write disjoint
       outputs and reductions happen in a fixed order, so results are bit-identical whatever
       the number of threads (same inputs, same seed, same build).
       rad_context.progress is called on the calling thread between batches of tasks with the
       fraction done; returning non-zero cancels the call, which frees what it allocated and
       returns RAD_ERROR_CANCELLED.
       Objects are immutable after creation: any number of threads may read one (query a BVH,
       read patches, solve with the same matrix) at the same time.

   7. RAY QUERIES
       All visibility goes through a rad_raycaster: two batched callbacks, occluded() and
       intersect(), plus a user pointer. Both are called from several tasks at once and must be
       thread-safe. The built-in BVH (rad_bvh_*) implements the table with a binned-SAH build
       and a watertight ray/triangle test; it is the reference the tests use.
       Self-intersection: rays that start or end on a surface are offset along the surface
       normal by ray_epsilon (relative to the scene diagonal) and their [tmin, tmax] interval
       excludes the same distance at both ends. The raycaster itself reports any hit in
       (tmin, tmax) and adds no epsilon of its own.

   8. EMBREE
       With RAD_EMBREE defined in the implementing file (and -lembree3), rad_embree_create
       builds an Embree 3 device and scene from a rad_scene (robust flag, high build quality,
       Embree-owned padded buffers) and rad_embree_raycaster fills the same rad_raycaster table
       the BVH fills; rad_embree_wrap adopts a committed RTCScene you already have. Embree's
       errors go to rad_context.log. Rays are checked before Embree sees them: a ray with NaN
       or Inf is a miss (as in the built-in BVH); a ray with tmin < 0 or a coordinate beyond
       Embree's range (about 1.8e18) makes the call return RAD_ERROR_RAYCAST_FAILED. Without RAD_EMBREE the functions exist and return
       RAD_ERROR_UNAVAILABLE, so code can probe with rad_embree_available().

   9. BAKED DATA
       rad_save_memory / rad_save_file write patches, a form-factor matrix (dense or CSR) and
       named RGB vectors ("E", "B") into one container; rad_load_memory reads it in place (the
       bytes must be 8-byte aligned and outlive the rad_bake) and rad_load_file reads a file.
       Layout: a 64-byte header (magic "RADB", version, section count, file size, flags, CRC-32
       of the section table, CRC-32 of the header), 64-byte table entries (type, element size,
       count, offset, bytes, CRC-32, name), then the sections, each on a 64-byte boundary.
       Section data is in the writer's byte order, recorded in the flags; a reader of the other
       byte order refuses it (RAD_ERROR_VERSION). Every size, offset, checksum and index is
       checked before use: a truncated file gives RAD_ERROR_TRUNCATED, a damaged one
       RAD_ERROR_CORRUPT, another version RAD_ERROR_VERSION, an index out of range
       RAD_ERROR_INDEX_OUT_OF_RANGE; nothing is read outside the given bytes. Behind a valid
       checksum every value a loader hands out is checked once, at load: NaN or infinity gives
       RAD_ERROR_NON_FINITE, a negative form factor, F_mb entry, scale or alias total, or a
       magnitude beyond RAD_BAKE_VALUE_MAX (1e30), RAD_ERROR_CORRUPT. A signature section
       records hashes of the scene's geometry and materials (rad_scene_hash) and of the
       application's options; rad_bake_matches_scene refuses a bake of another scene
       (RAD_ERROR_SCENE_MISMATCH, naming what differs). New section types never change the
       container version: a bake without a signature still loads. Applications add their own
       sections (types >= RAD_SECTION_USER) through rad_container_write.

  10. GLSL
       The GPU paths are GLSL 4.50 compute kernels embedded as text (>>api_glsl): get one with
       rad_glsl_source(RAD_GLSL_TEMPORAL_STEP, buf, size, &len) (or rad_glsl_pieces), compile
       it with glslang or shaderc and dispatch it on your own Vulkan device; radiosity.h never
       touches a GPU. Kernels: dense and CSR gather (one bounce), multi-bounce apply from
       float, half and BC1 / 3xBC4 textures (with outliers and permutations), the temporal
       step (the same random draws as the CPU), the alias-table build for streamed rows, and
       the local multi-bounce matrix's apply and add (rank-1 update, rank-2 when evicting) on
       a matrix kept resident on the GPU, and virtual-patch gathering at surface points;
       RAD_GLSL_LIGHTING is the include with every lighting model (>>api_shading).
       Descriptor set 0 of std430 buffers (plus combined image samplers for the textures),
       push constants mirrored by the rad_glsl_*_push structs, workgroup x size from
       specialization constant 0 (RAD_GLSL_SPEC_LOCAL_SIZE), a workgroup (gathers, applies) or
       an invocation (temporal step, alias build, local pre-pass, vp gather) per row, and
       row_offset / row_count / base in every kernel so a matrix larger than one
       storage-buffer range (128 MiB on lavapipe) runs in chunks. Bindings: the >>api_glsl section. Canonical
       sources: the .comp files in glsl/ of the repository (make glsl regenerates the header's copy);
       tests/test_vulkan.c runs every kernel against the CPU path; examples/vulkan_temporal.c
       is a complete program.

  11. NUMERICAL ROBUSTNESS
       - rad_scene_create validates everything: NaN/Inf positions or normals, indices out of
         range, zero-area triangles (rejected, or skipped and counted with
         RAD_SCENE_SKIP_DEGENERATE), albedo outside [0,1), negative or non-finite emission,
         material index out of range, empty scenes, sizes that overflow.
       - Point-to-point form factors clamp |r|^2 from below by s_j / pi (the squared radius of
         a disk of the area the point stands for), which bounds the kernel by
         cos cos / s_j * s_j = 1 for coincident points.
       - Patch-to-patch form factors integrate the emitter side with the centroids of an n x n
         sub-triangle lattice (the midpoint rule: no bias toward any corner) and the receiver
         side analytically; pairs closer than twice their size get 16x the points, because the
         integrand is nearly singular along a shared edge. Measured against the closed forms
         of Howell's catalogue (docs/references.md) at default quality: relative errors
         below 1e-4 with patches a tenth of the shapes' size, a few 1e-4 at a quarter (the
         tests hold every case to 1e-3).
       - The BVH's box test widens every slab by 1 + 2 gamma_3 (Ize 2013) and its triangle
         test is watertight (Woop, Benthin, Wald 2013), so rays through shared edges and
         vertices are never lost.
       - The polygon kernel clips the receiver to the sample point's upper half-space and
         returns 0 when the point is behind the receiver, so there is no sign ambiguity.

  12. WHAT radiosity.h DOES NOT DO
       - Specular or glossy transport: radiosity is diffuse light exchange.
       - Parse scene files: meshes come in as arrays (tools/rad imports OBJ, glTF, FBX, PLY
         through assimp).
       - Start threads, touch the GPU itself, or keep global state.

  13. HISTORY
       0.1.0  scene input and validation, patches, built-in BVH (4-wide, SSE), Embree
              backend, form factors (analytic, Monte Carlo, point-to-point; dense, sparse,
              row ranges), Jacobi, Gauss-Seidel, progressive refinement, LU; direct light;
              built-in Cornell box; baked-data container; multi-bounce matrix with BC1/BC4
              compression and reordering; temporal radiosity with alias tables; local
              matrix (Sherman-Morrison); virtual and axis-aligned virtual patches; lighting
              models and microfacet BRDFs; embedded GLSL kernels for every run-time step.
       The full history is in CHANGELOG.md.
*/

#ifndef RADIOSITY_H
#define RADIOSITY_H

#include <stddef.h>
#include <stdint.h>

#define RAD_VERSION_MAJOR 0
#define RAD_VERSION_MINOR 1
#define RAD_VERSION_PATCH 0
#define RAD_VERSION_STRING "0.1.0"

#ifndef RAD_API
#  ifdef RADIOSITY_STATIC
#    define RAD_API static
#  elif defined(_WIN32) && defined(RAD_DLL)
#    ifdef RADIOSITY_IMPLEMENTATION
#      define RAD_API __declspec(dllexport)
#    else
#      define RAD_API __declspec(dllimport)
#    endif
#  else
#    define RAD_API extern
#  endif
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ======================================================================================== */
/* >>api_core: results, allocators, logging, threading hooks                                */
/* ======================================================================================== */

typedef enum rad_result {
    RAD_SUCCESS = 0,
    RAD_ERROR_INVALID_ARGUMENT = -1,      /* NULL pointer, zero count, bad option value */
    RAD_ERROR_OUT_OF_MEMORY = -2,         /* an allocation failed */
    RAD_ERROR_SIZE_OVERFLOW = -3,         /* a size (often N*N) does not fit its type */
    RAD_ERROR_EMPTY_SCENE = -4,           /* no triangles (or none left after skipping) */
    RAD_ERROR_INDEX_OUT_OF_RANGE = -5,    /* a vertex index >= vertex_count */
    RAD_ERROR_NON_FINITE = -6,            /* NaN or Inf in positions, normals, uvs, lights */
    RAD_ERROR_DEGENERATE_TRIANGLE = -7,   /* a triangle of zero (or subnormal) area */
    RAD_ERROR_ALBEDO_RANGE = -8,          /* albedo outside [0,1) (material or callback) */
    RAD_ERROR_NEGATIVE_EMISSION = -9,     /* emission < 0 or not finite */
    RAD_ERROR_MATERIAL_OUT_OF_RANGE = -10,/* a material index >= material_count */
    RAD_ERROR_CANCELLED = -11,            /* the progress callback asked to stop */
    RAD_ERROR_NOT_CONVERGED = -12,        /* an iterative solver hit max_iterations */
    RAD_ERROR_SINGULAR = -13,             /* the direct solve met a zero pivot */
    RAD_ERROR_UNAVAILABLE = -14,          /* a backend not compiled in */
    RAD_ERROR_RAYCAST_FAILED = -15,       /* a ray callback returned an error */
    RAD_ERROR_SIZE_MISMATCH = -16,        /* arrays or matrices of incompatible sizes */
    RAD_ERROR_IO = -17,                   /* a file could not be opened, read or written */
    RAD_ERROR_TRUNCATED = -18,            /* baked data ends before its sections do */
    RAD_ERROR_CORRUPT = -19,              /* bad magic, checksum, table or section layout, or a
                                             stored value outside its range */
    RAD_ERROR_VERSION = -20,              /* baked data of an unsupported container version */
    RAD_ERROR_SCENE_MISMATCH = -21,       /* baked data made from another scene or other options */
    RAD_ERROR_SCALE_RANGE = -22           /* a scene larger or smaller than RAD_SCENE_MAX/MIN_SIZE */
} rad_result;

/* A static English name and description of a result ("RAD_ERROR_NON_FINITE: ..."). */
RAD_API const char *rad_result_string(rad_result result);

typedef enum rad_log_level { RAD_LOG_ERROR = 0, RAD_LOG_WARNING = 1, RAD_LOG_INFO = 2 } rad_log_level;

/* Allocation callbacks. alloc must return memory aligned for any type (like malloc) or NULL;
   free accepts NULL. Both receive 'user'. Leave both NULL for RAD_MALLOC / RAD_FREE. */
typedef struct rad_allocator {
    void *(*alloc)(void *user, size_t size);
    void (*free)(void *user, void *ptr);
    void *user;
} rad_allocator;

/* A task function: runs task 'index' of a parallel_for. */
typedef void (*rad_task_fn)(void *data, uint32_t index);

/* Runs fn(data, i) for every i in [0, count), in any order, on any threads, and returns when
   all have finished. Tasks never call back into parallel_for. */
typedef void (*rad_parallel_for_fn)(void *user, uint32_t count, rad_task_fn fn, void *data);

/* Hooks shared by every long call. Zero-initialise it (or pass NULL) for the defaults. */
typedef struct rad_context {
    rad_allocator allocator;
    /* Detail messages for errors and warnings; called on the calling thread. */
    void (*log)(void *user, rad_log_level level, const char *message);
    void *log_user;
    /* Default: serial, or OpenMP when the implementation is compiled with it. */
    rad_parallel_for_fn parallel_for;
    void *parallel_user;
    /* Number of tasks a call splits into (0: 64). More tasks balance load better. */
    uint32_t task_count;
    /* fraction in [0,1]; return non-zero to cancel. Called on the calling thread. */
    int (*progress)(void *user, float fraction);
    void *progress_user;
} rad_context;

/* ======================================================================================== */
/* >>api_scene: scene input and validation                                                  */
/* ======================================================================================== */

#define RAD_NONE 0xFFFFFFFFu

/* Albedo lookup by texture coordinate: writes the linear RGB albedo at (u, v) of 'texture'
   (the material's texture id, never 0). Must be thread-safe. Values must lie in [0,1). */
typedef void (*rad_albedo_fn)(void *user, uint32_t texture, float u, float v, float out_rgb[3]);

typedef struct rad_material {
    float albedo[3];    /* diffuse reflectance, each channel in [0, 1) */
    float emission[3];  /* emitted RADIANCE L (W m^-2 sr^-1), >= 0; exitance is pi * L */
    uint32_t texture;   /* 0: none; else passed to rad_scene_desc.albedo_lookup, whose
                           result replaces albedo (needs uvs on the mesh) */
} rad_material;

typedef struct rad_mesh_desc {
    const char *name;              /* optional; copied */
    const float *positions;        /* x y z floats, 'position_stride' bytes apart */
    size_t position_stride;        /* 0: 3 * sizeof(float) */
    uint32_t vertex_count;
    const float *normals;          /* optional shading normals (unused by the solver) */
    size_t normal_stride;          /* 0: 3 * sizeof(float) */
    const float *uvs;              /* optional u v, needed for textured materials */
    size_t uv_stride;              /* 0: 2 * sizeof(float) */
    const uint32_t *indices;       /* 3 per triangle; NULL: vertices taken in threes */
    uint32_t triangle_count;
    const uint32_t *material_ids;  /* one per triangle; NULL: every triangle uses 'material' */
    uint32_t material;
} rad_mesh_desc;

typedef enum rad_scene_flags {
    RAD_SCENE_SKIP_DEGENERATE = 1  /* drop zero-area triangles instead of failing; counted in
                                      rad_scene.skipped_triangles */
} rad_scene_flags;

typedef struct rad_scene_desc {
    const rad_mesh_desc *meshes;
    uint32_t mesh_count;
    const rad_material *materials;
    uint32_t material_count;
    rad_albedo_fn albedo_lookup;   /* optional */
    void *albedo_user;
    uint32_t flags;                /* rad_scene_flags */
} rad_scene_desc;

/* The validated scene, flattened: one array of triangles with world positions. Read-only.
   Triangle t has vertices positions[9t .. 9t+8] (three xyz), normal normals[3t..3t+2]
   (geometric, unit, from the winding), area areas[t], material materials[t], mesh meshes[t],
   and the index it had in its mesh, source_triangles[t]. */
typedef struct rad_scene {
    uint32_t triangle_count;
    float *positions;
    float *normals;
    float *uvs;                    /* 6 per triangle, or NULL when no mesh had uvs */
    float *areas;
    uint32_t *materials;
    uint32_t *meshes;
    uint32_t *source_triangles;
    uint32_t material_count;
    rad_material *materials_table;
    uint32_t mesh_count;
    char **mesh_names;             /* mesh_count strings ("" when unnamed) */
    rad_albedo_fn albedo_lookup;
    void *albedo_user;
    float bounds_min[3], bounds_max[3];
    float diagonal;                /* |bounds_max - bounds_min| */
    uint32_t skipped_triangles;    /* degenerate triangles dropped (RAD_SCENE_SKIP_DEGENERATE) */
    rad_allocator allocator;       /* private: the allocator that made it */
} rad_scene;

/* The scene sizes (bounding-box diagonal, in the scene's units) the library supports: ray
   tests, form factors and light stay accurate from one to the other (tested at both ends);
   rad_scene_create refuses a scene outside with RAD_ERROR_SCALE_RANGE. */
#define RAD_SCENE_MIN_SIZE 1e-15
#define RAD_SCENE_MAX_SIZE 1e18

/* Validates 'desc' and copies it into a new scene.
   Parameters: desc (borrowed for the call), ctx (optional), out (receives an owning pointer).
   Errors: INVALID_ARGUMENT, EMPTY_SCENE, INDEX_OUT_OF_RANGE, NON_FINITE, DEGENERATE_TRIANGLE,
   ALBEDO_RANGE, NEGATIVE_EMISSION, MATERIAL_OUT_OF_RANGE, SIZE_OVERFLOW, SCALE_RANGE,
   OUT_OF_MEMORY; the logger names the mesh and triangle. Thread safety: reentrant. Cost: O(triangles). */
RAD_API rad_result rad_scene_create(const rad_scene_desc *desc, const rad_context *ctx, rad_scene **out);
RAD_API void rad_scene_destroy(rad_scene *scene);

/* Albedo of triangle t at barycentrics (b1, b2) (weights of vertices 1 and 2): the material's
   albedo, or the texture lookup at the interpolated uv. */
RAD_API void rad_scene_albedo(const rad_scene *scene, uint32_t triangle, float b1, float b2, float out_rgb[3]);

/* A pinhole camera. fov_y_degrees is the full vertical field of view. */
typedef struct rad_camera {
    float position[3];
    float target[3];
    float up[3];
    float fov_y_degrees;
} rad_camera;

/* The built-in Cornell box: the original Cornell geometry in metres (the same scene as
   the cornell.obj of docs/data.md: 16 quads, 32 triangles) with the common RGB materials
   (white 0.725 0.71 0.68, red 0.63 0.065 0.05, green 0.14 0.45 0.091, light albedo 0.78 and
   radiance 17 12 4, one-sided, facing down, 0.1 mm below the ceiling) and its camera
   (0.278 0.273 -0.8 looking along +z, vertical fov 39.3077). Meshes: floor, ceiling, back,
   green (x = 0, right in the image), red (x ~ 0.55, left), light, shortblock, tallblock.
   Everything 'desc' points to is static and read-only. Either output may be NULL. */
RAD_API void rad_cornell_box(rad_scene_desc *desc, rad_camera *camera);

/* ======================================================================================== */
/* >>api_patches: patches                                                                   */
/* ======================================================================================== */

typedef struct rad_patch {
    float centroid[3];
    float normal[3];
    float area;
    float albedo[3];      /* mean albedo over the patch (texture-averaged when textured) */
    float emission[3];    /* emitted radiance L of the material */
    uint32_t triangle;    /* scene triangle it lies on */
    uint32_t vertices[3]; /* indices into rad_patches.vertices, counter-clockwise */
} rad_patch;

typedef struct rad_patch_options {
    float max_area;       /* 0: no limit */
    float max_edge;       /* 0: no limit */
    uint32_t target_count;/* 0: none; else max_area is set to total area / target_count
                             (the result is near, not equal to, the target) */
    uint32_t albedo_samples; /* texture samples per patch when textured (0: 16) */
} rad_patch_options;

/* Patches: each scene triangle is cut into n*n congruent triangles (n >= 1, the smallest
   that meets max_area and max_edge). Vertices shared by patches of the same plane orientation
   are welded, so per-vertex values (rad_patches_vertex_values) are smooth across triangle
   edges but not across creases. Read-only after creation. */
typedef struct rad_patches {
    uint32_t count;
    rad_patch *patches;
    uint32_t vertex_count;
    float *vertices;          /* 3 floats per vertex */
    uint32_t triangle_count;
    uint32_t *first_patch;    /* per scene triangle: index of its first patch */
    uint32_t *subdivision;    /* per scene triangle: n */
    float *areas;             /* count floats, copies of patches[i].area (for rad_system) */
    float *albedo;            /* 3*count floats (for rad_system) */
    const rad_scene *scene;   /* borrowed: the scene must outlive the patches */
    rad_allocator allocator;  /* private */
} rad_patches;

RAD_API void rad_patch_options_default(rad_patch_options *options);

/* Cuts the scene into patches. scene is borrowed and must outlive the result.
   Errors: INVALID_ARGUMENT (negative or non-finite option), SIZE_OVERFLOW (more than 2^32-2
   patches), ALBEDO_RANGE (texture callback out of range), OUT_OF_MEMORY.
   Thread safety: reentrant. Cost: O(patches). */
RAD_API rad_result rad_patches_create(const rad_scene *scene, const rad_patch_options *options,
                                      const rad_context *ctx, rad_patches **out);
RAD_API void rad_patches_destroy(rad_patches *patches);

/* The patch containing the point of scene triangle 'triangle' at barycentrics (b1, b2), and
   the weights of that patch's three vertices at the point (for smooth interpolation).
   Returns RAD_NONE when the triangle index is out of range. O(1). */
RAD_API uint32_t rad_patches_locate(const rad_patches *patches, uint32_t triangle, float b1, float b2,
                                    float out_weights[3]);

/* Per-vertex values from per-patch values: each vertex gets the area-weighted mean of the
   patches that share it. 'channels' floats per patch and per vertex. */
RAD_API rad_result rad_patches_vertex_values(const rad_patches *patches, const float *patch_values,
                                             uint32_t channels, float *out_vertex_values);

/* Per-vertex irradiance without dark halos. A patch partly covered by other geometry (under a
   block, under a one-sided light a hair below the ceiling) has a small H only because part of
   its area sees nothing; a plain vertex average smears that into the visible surface around the
   contact. So the value at vertex v is (mean radiosity seen) x (how much is seen):
       H_v = [sum_i A_i H_i / sum_i A_i S_i] * S_v,
   the sums over the patches sharing v, S_v the area-weighted mean of S over those patches that
   are not partly covered (S_i >= 3/4 of the largest S at v). S (one float per patch) is the
   row sum of F (sum_j F_ij, how much of its hemisphere a patch sees: rad_matrix_multiply by
   ones); NULL gives rad_patches_vertex_values. H: 3 floats per patch; out: 3 per patch vertex.
   Errors: INVALID_ARGUMENT, NON_FINITE (H or S not finite, S < 0), OUT_OF_MEMORY. O(patches). */
RAD_API rad_result rad_patches_vertex_irradiance(const rad_patches *patches, const float *H, const float *S,
                                                 float *out_vertex_H, const rad_context *ctx);

/* Values at the vertices of one of the scene's own meshes, for an engine that draws that mesh:
   'mesh' is the index the mesh had in rad_scene_desc.meshes and 'desc' the same description
   (its vertex count and indices). vertex_values: 3 floats per patch vertex (from
   rad_patches_vertex_values or rad_patches_vertex_irradiance). Each triangle corner takes the
   value interpolated at that corner of its patch; a vertex shared by several triangles gets
   the area-weighted mean over them (so a crease averages its sides, as the mesh's own smooth
   normals do), and a vertex no triangle uses (or only skipped degenerate ones) gets 0.
   out: 3 * desc->vertex_count floats. Errors: INVALID_ARGUMENT (mesh >= the scene's mesh count,
   a NULL pointer), INDEX_OUT_OF_RANGE (an index >= desc->vertex_count, or the scene has triangles
   of that mesh beyond desc->triangle_count: another description), OUT_OF_MEMORY.
   O(triangles of the scene). */
RAD_API rad_result rad_patches_gather_mesh(const rad_patches *patches, const float *vertex_values, uint32_t mesh,
                                           const rad_mesh_desc *desc, float *out, const rad_context *ctx);

/* ======================================================================================== */
/* >>api_rays: ray queries and the built-in BVH                                             */
/* ======================================================================================== */

typedef struct rad_ray {
    float origin[3];
    float tmin;
    float dir[3];          /* need not be unit; t is in units of |dir| */
    float tmax;
} rad_ray;

typedef struct rad_hit {
    float t;               /* distance along the ray in units of |dir| */
    uint32_t triangle;     /* scene triangle, RAD_NONE on a miss */
    float b1, b2;          /* barycentric weights of vertices 1 and 2 */
} rad_hit;

/* The ray-query table. Both functions must be thread-safe and return RAD_SUCCESS, or an
   error that the library passes on (as RAD_ERROR_RAYCAST_FAILED). */
typedef struct rad_raycaster {
    void *user;
    /* out_occluded[i] = 1 when anything is hit with tmin < t < tmax, else 0. */
    rad_result (*occluded)(void *user, const rad_ray *rays, uint32_t count, uint8_t *out_occluded);
    /* out_hits[i] = the closest hit with tmin < t < tmax, triangle = RAD_NONE if none. */
    rad_result (*intersect)(void *user, const rad_ray *rays, uint32_t count, rad_hit *out_hits);
} rad_raycaster;

typedef struct rad_bvh rad_bvh;

/* Builds the BVH over the scene's triangles: binned SAH down to leaves of at most 4 triangles
   (stored side by side and tested together with SIMD), collapsed to 8-wide nodes when the
   implementing file is compiled with AVX, else 4-wide (SSE; scalar under RAD_NO_SIMD). The
   subtrees below the top levels are built in parallel through ctx->parallel_for; the tree does
   not depend on the thread count. scene is borrowed only for the call (the BVH copies the
   triangles). Errors: INVALID_ARGUMENT, OUT_OF_MEMORY, SIZE_OVERFLOW (2^29 triangles or more).
   Cost: O(T log T). */
RAD_API rad_result rad_bvh_create(const rad_scene *scene, const rad_context *ctx, rad_bvh **out);
RAD_API void rad_bvh_destroy(rad_bvh *bvh);
/* Fills a raycaster table that queries 'bvh' (which must outlive its use). */
RAD_API void rad_bvh_raycaster(const rad_bvh *bvh, rad_raycaster *out);
/* Bytes the BVH holds (nodes and triangles). */
RAD_API size_t rad_bvh_memory(const rad_bvh *bvh);

/* ---- Embree 3 backend (compiled only with RAD_EMBREE; always declared) ----
   Define RAD_EMBREE in the implementing file and link Embree 3 (-lembree3) to use Embree for
   every ray query. Without it these functions return RAD_ERROR_UNAVAILABLE (and
   rad_embree_raycaster fills a table whose callbacks are NULL). The Embree headers are
   included by the implementation only. Thread safety: queries from any number of threads. */
typedef struct rad_embree rad_embree;

/* 1 when the library was compiled with RAD_EMBREE, else 0. */
RAD_API int rad_embree_available(void);
/* Builds an Embree device and scene (RTC_SCENE_FLAG_ROBUST, high build quality) over the
   scene's triangles, copied into Embree-owned buffers (scene is borrowed for the call).
   Embree's errors are sent to ctx->log. Errors: UNAVAILABLE, INVALID_ARGUMENT,
   OUT_OF_MEMORY, RAYCAST_FAILED (Embree could not create the device or the scene). */
RAD_API rad_result rad_embree_create(const rad_scene *scene, const rad_context *ctx, rad_embree **out);
/* Wraps a user's committed RTCScene (passed as void * so this header needs no Embree types).
   A hit on (geomID, primID) is reported as triangle first_triangle[geomID] + primID; pass
   first_triangle = NULL when geometry 0 holds the scene's triangles in order. The scene is
   borrowed: it must outlive the returned object, which does not release it. */
RAD_API rad_result rad_embree_wrap(void *rtc_scene, const uint32_t *first_triangle, uint32_t geometry_count,
                                   const rad_context *ctx, rad_embree **out);
RAD_API void rad_embree_destroy(rad_embree *embree);
/* Fills a raycaster table that queries 'embree' (which must outlive its use). */
RAD_API void rad_embree_raycaster(const rad_embree *embree, rad_raycaster *out);
/* Bytes Embree reported allocating for the device and scene made by rad_embree_create
   (through its memory monitor); 0 for a wrapped scene. */
RAD_API size_t rad_embree_memory(const rad_embree *embree);

/* A camera ray through the point (px, py) of a width x height image, px right, py down,
   pixel centres at +0.5. dir is unit, tmin 0, tmax +huge. */
RAD_API void rad_camera_ray(const rad_camera *camera, uint32_t width, uint32_t height, float px, float py,
                            rad_ray *out);

/* ======================================================================================== */
/* >>api_formfactor: form factors                                                           */
/* ======================================================================================== */

typedef enum rad_storage { RAD_STORAGE_DENSE = 0, RAD_STORAGE_SPARSE = 1 } rad_storage;

/* A non-owning view of a rows x cols matrix of floats: dense row-major, or CSR. Every
   function that takes a CSR view checks its structure first (row_offsets[0] = 0, never
   decreasing; columns ascending and < cols) and refuses a bad one with RAD_ERROR_CORRUPT;
   row_offsets[rows] must be the length of columns and values, which no check can see. */
typedef struct rad_matrix {
    uint32_t rows, cols;
    rad_storage storage;
    const float *dense;            /* rows*cols floats, row-major */
    const uint64_t *row_offsets;   /* CSR: rows+1 offsets into columns/values */
    const uint32_t *columns;       /* CSR: ascending within a row */
    const float *values;
} rad_matrix;

typedef enum rad_ff_method {
    RAD_FF_ANALYTIC = 0,   /* analytic inner integral (point to polygon) at 'samples' points on
                              the emitting patch, visibility from one ray per point (default) */
    RAD_FF_MONTE_CARLO = 1,/* 'samples' point pairs on both patches, kernel and one ray each */
    RAD_FF_HEMICUBE = 2    /* Cohen and Greenberg's hemicube at each patch's centroid, with an
                              item buffer for visibility (HEMICUBE below; no raycaster) */
} rad_ff_method;

typedef struct rad_form_factor_options {
    rad_ff_method method;
    uint32_t samples;       /* points per patch pair (0: 16), rounded to a square n*n and
                               capped at 256: the emitter points are the centroids of the
                               patch's n x n sub-triangles (exact centroid, midpoint rule); the
                               visibility targets are rotated Hammersley points. Pairs closer
                               than twice their size get 16x the points. */
    float ray_epsilon;      /* relative to the scene diagonal (0: 1e-5; at most 1e-2); the
                               hemicube's near-plane distance */
    float drop_threshold;   /* sparse: entries below it are dropped (0 keeps non-zeros) */
    uint32_t seed;          /* decorrelates visibility sample points (any value) */
    int skip_visibility;    /* non-zero: V = 1 everywhere (unoccluded form factors) */
    uint32_t hemicube_resolution; /* RAD_FF_HEMICUBE: cells across the top face (0: 128); even,
                               4 to 2048, else INVALID_ARGUMENT. Other methods ignore it. */
} rad_form_factor_options;

/* An owning form-factor matrix; 'matrix' views its storage. */
typedef struct rad_form_factors {
    rad_matrix matrix;
    uint64_t rays_cast;        /* visibility rays the build cast */
    uint64_t pairs_evaluated;  /* unordered patch pairs whose value was computed (the
                                  hemicube: ordered pairs drawn, see HEMICUBE) */
    rad_allocator allocator;   /* private */
    void *storage;             /* private */
} rad_form_factors;

/* Defaults: RAD_FF_ANALYTIC, samples 16, ray_epsilon 1e-5, hemicube_resolution 128, the rest 0. */
RAD_API void rad_form_factor_options_default(rad_form_factor_options *options);

/* HEMICUBE (RAD_FF_HEMICUBE; Cohen and Greenberg 1985). Row i is what a hemicube at patch i's
   centroid, oriented by its normal, sees: the point-to-area form factors from the centroid,
   the classic method's assumption (accurate when a patch is small against its distance to
   the others; a patch next to i gets the centroid's value, not the area average). The
   hemicube has a top face of res x res cells at unit distance along the normal and four side
   faces of res x res/2 cells (res = hemicube_resolution; its side axes are the branchless
   orthonormal basis of the normal, Duff et al. 2017). Every other patch is drawn into each
   face it reaches: projected, clipped against the near plane at ray_epsilon times the scene
   diagonal (nearer geometry is cut away; a patch whose plane passes closer than that to the
   centroid is edge-on and skipped), and point-sampled at the cell centres with a depth test
   (an item buffer: each cell holds the nearest patch covering its centre; a centre on an edge
   shared by two patches goes to exactly one of them). Patch i itself and everything behind
   its plane are skipped. F_ij is the sum over the cells that j holds of the closed-form delta
   form factors (the midpoint rule: top cell dA / (pi (x^2 + y^2 + 1)^2), side cell
   z dA / (pi (y^2 + z^2 + 1)^2) in the face's coordinates), whose total over the hemicube
   differs from 1 by O(1/res^2). Every patch occludes, seen from either side, but one seen from
   behind receives nothing (its cells count for no column).
   Consequences: visibility is the item buffer, so the raycaster is not used (may be NULL);
   samples and seed are ignored; skip_visibility counts the cells of every front-facing patch
   with no depth test. Each row is computed on its own: A_i F_ij = A_j F_ji holds only up to
   the discretisation, and the dense call computes all N rows (rows, dense and sparse give the
   same bits). ALIASING: a patch covering few cells as seen from i gets a whole number of cells'
   delta form factors, 0 when it falls between centres; pick res so that the smallest patch
   covers several cells from its neighbours. rays_cast stays 0; pairs_evaluated counts the
   ordered pairs (i, j) with j covering some cell centre of i's hemicube (before the depth
   test). Cost per row: O(N + 3 res^2) plus the cells each patch covers; scratch 24 res^2
   bytes per task (fewer tasks when that would pass 256 MiB; the results do not depend on the
   task count). */

/* The row range [row_begin, row_end) of the N x N form-factor matrix, dense, into out_rows
   ((row_end - row_begin) * N floats, row-major). Each unordered pair {i, j} is computed once,
   from the sample points of the smaller patch (the lower index on a tie); the other entry
   follows by reciprocity, so A_i F_ij = A_j F_ji holds exactly, no area ratio can overflow,
   and any split of the rows gives the same bits as the full matrix (RAD_FF_HEMICUBE computes
   each row on its own instead: HEMICUBE above). raycaster may be NULL only with
   skip_visibility or RAD_FF_HEMICUBE. Thread safety: reentrant; uses
   ctx->parallel_for. Cost: O((row_end-row_begin) N samples). docs/methods/formfactor-analytic.md. */
RAD_API rad_result rad_form_factor_rows(const rad_patches *patches, const rad_raycaster *raycaster,
                                        const rad_form_factor_options *options, uint32_t row_begin,
                                        uint32_t row_end, float *out_rows, const rad_context *ctx);

/* The dense N x N matrix (N = patches->count; SIZE_OVERFLOW when N*N*4 bytes does not fit).
   Computes each unordered pair once: half the work of N rows (the hemicube: N rows). Same
   values as the rows call. */
RAD_API rad_result rad_form_factors_dense(const rad_patches *patches, const rad_raycaster *raycaster,
                                          const rad_form_factor_options *options, const rad_context *ctx,
                                          rad_form_factors **out);

/* The sparse (CSR) matrix: entries <= drop_threshold are dropped (exact zeros always).
   Built row batch by row batch with rad_form_factor_rows, so it never holds N*N floats but
   computes every pair twice. */
RAD_API rad_result rad_form_factors_sparse(const rad_patches *patches, const rad_raycaster *raycaster,
                                           const rad_form_factor_options *options, const rad_context *ctx,
                                           rad_form_factors **out);
RAD_API void rad_form_factors_destroy(rad_form_factors *ff);

/* Point to polygon, unoccluded, analytic (Lambert's contour integral): the form factor from a
   differential area at p with unit normal n to the convex or simple polygon 'vertices'
   (count points, 3 floats each, counter-clockwise seen from its front). The polygon is clipped
   to p's upper half-space; returns 0 when p is behind the polygon's plane. docs/methods/formfactor-analytic.md. */
RAD_API float rad_ff_point_polygon(const float p[3], const float n[3], const float *vertices, uint32_t count);

/* Point to point, the kernel of Monte Carlo form factors and virtual patches, without visibility:
   s_j cos(r, n_i) cos(-r, n_j) / (pi max(|r|^2, s_j / pi)), 0 when either cosine is <= 0. */
RAD_API float rad_ff_point_point(const float pi_[3], const float ni[3], const float pj[3], const float nj[3],
                                 float sj);

/* ======================================================================================== */
/* >>api_solve: classic solvers                                                             */
/* ======================================================================================== */

typedef enum rad_output { RAD_OUTPUT_INDIRECT = 0, RAD_OUTPUT_TOTAL = 1 } rad_output;

/* The linear system B = E + (rho o F) B. All pointers borrowed. */
typedef struct rad_system {
    const rad_matrix *F;     /* N x N form factors */
    const float *albedo;     /* 3N, each in [0,1): the solvers refuse others (ALBEDO_RANGE) */
    const float *E;          /* 3N source (see UNITS AND CONVENTIONS) */
    const float *areas;      /* N, needed by progressive refinement only */
    uint32_t n;
} rad_system;

/* Residual report: return non-zero to stop early (the solver then returns RAD_SUCCESS with
   what it has). residual is the largest change of any B_i in the sweep divided by max_i |E_i|
   for Gauss-Seidel, the total unshot power / the initial power for progressive refinement. */
typedef int (*rad_residual_fn)(void *user, uint32_t iteration, double residual);

typedef struct rad_solve_options {
    rad_output output;         /* RAD_OUTPUT_INDIRECT (default) or RAD_OUTPUT_TOTAL */
    uint32_t bounces;          /* Jacobi: K (default 8; 0 returns 0 indirect / E total) */
    double tolerance;          /* Gauss-Seidel, shooting: relative (0: 1e-6) */
    uint32_t max_iterations;   /* GS sweeps (0: 1000), shooting steps (0: 100 N) */
    rad_residual_fn on_residual;
    void *residual_user;
} rad_solve_options;

typedef struct rad_solve_stats {
    uint32_t iterations;       /* bounces, sweeps or shooting steps done */
    double residual;           /* last residual (see rad_residual_fn) */
} rad_solve_stats;

RAD_API void rad_solve_options_default(rad_solve_options *options);
/* Fills 'system' from patches (albedo, areas), a matrix and E. */
RAD_API void rad_system_init(rad_system *system, const rad_matrix *F, const rad_patches *patches, const float *E);

/* out = F x for RGB vectors (3 floats per row/column). Dense or CSR. Parallel over rows.
   out must not alias x. Cost: one pass over F. */
RAD_API rad_result rad_matrix_multiply(const rad_matrix *F, const float *x, float *out, const rad_context *ctx);

/* Jacobi bounces: B^0 = E, B^k = (rho o F) B^(k-1); out = L_K or E + L_K. O(K N^2). docs/methods/classic.md. */
RAD_API rad_result rad_solve_jacobi(const rad_system *system, const rad_solve_options *options, float *out,
                                    rad_solve_stats *stats, const rad_context *ctx);
/* Gauss-Seidel sweeps in patch order until the residual is below tolerance. Serial.
   Returns NOT_CONVERGED (out still written) after max_iterations. */
RAD_API rad_result rad_solve_gauss_seidel(const rad_system *system, const rad_solve_options *options, float *out,
                                          rad_solve_stats *stats, const rad_context *ctx);
/* Progressive refinement (Southwell shooting, Cohen et al. 1988): shoots the patch with the
   largest unshot power A_i |dB_i| (summed over channels); dB_j += rho_j F_ij A_i / A_j dB_i.
   Needs system->areas. Reports the residual after every step. O(N) per step. */
RAD_API rad_result rad_solve_progressive(const rad_system *system, const rad_solve_options *options, float *out,
                                         rad_solve_stats *stats, const rad_context *ctx);
/* Direct solve of (I - rho o F) B = E by LU with partial pivoting in double precision, per
   channel. O(N^3) time, 8 N^2 bytes. For small N, teaching, and as the reference. */
RAD_API rad_result rad_solve_direct(const rad_system *system, const rad_solve_options *options, float *out,
                                    const rad_context *ctx);

/* ======================================================================================== */
/* >>api_light: lights and the source term                                                  */
/* ======================================================================================== */

typedef enum rad_light_type {
    RAD_LIGHT_DIRECTIONAL = 0, /* sun: 'color' is the irradiance on a surface facing it;
                                  'direction' points from the light into the scene */
    RAD_LIGHT_POINT = 1,       /* 'color' is the intensity (W/sr) */
    RAD_LIGHT_SPOT = 2,        /* point light limited to a cone around 'direction' */
    RAD_LIGHT_SKY = 3          /* constant sky: 'color' is its exitance E_0 (= pi * its
                                  radiance), the irradiance on an unoccluded surface */
} rad_light_type;

typedef enum rad_falloff {
    RAD_FALLOFF_QUADRATIC = 0, /* I / d^2 (physical) */
    RAD_FALLOFF_LINEAR = 1     /* I / d (the linear falloff of Korobeinikov 2022; not physical) */
} rad_falloff;

typedef struct rad_light {
    rad_light_type type;
    float color[3];
    float position[3];         /* point, spot */
    float direction[3];        /* directional, spot (need not be unit) */
    rad_falloff falloff;       /* point, spot */
    float min_distance;        /* point, spot: d is clamped from below to this (0: 1e-6 of
                                  the scene diagonal) */
    float inner_angle;         /* spot: half-angles in radians; full intensity inside inner, */
    float outer_angle;         /* smoothstep to 0 at outer (outer > inner) */
} rad_light;

typedef struct rad_direct_options {
    uint32_t samples;          /* points per patch (0: 16), rounded to a square n*n: the centroids
                                  of the patch's n x n sub-triangles */
    uint32_t light_samples;    /* shadow rays per point per area light and sky (0: 16) */
    int include_emitters;      /* non-zero (default): emissive triangles are area lights;
                                  0 leaves them out (a zeroed struct has no emitters: start
                                  from rad_direct_options_default) */
    float ray_epsilon;         /* relative to the scene diagonal (0: 1e-5; at most 1e-2) */
    uint32_t seed;
} rad_direct_options;

RAD_API void rad_direct_options_default(rad_direct_options *options);

/* Direct irradiance D (W m^-2, RGB) at arbitrary points with unit normals: the lights, the
   sky (cosine-weighted shadow rays) and, when include_emitters, every emissive triangle
   (analytic point-to-polygon irradiance pi L F times the unoccluded share of 'light_samples'
   shadow rays, each weighted by its point's cos cos / r^2, so a partly hidden large emitter
   gets the light of its visible part). A point receives nothing from behind its normal; normals need not
   be unit (they are normalized), a zero one is refused. 'samples' is unused here.
   Errors: INVALID_ARGUMENT (bad light type, falloff, direction, spot angles, a negative
   min_distance, a zero normal or ray_epsilon outside (0, 1e-2]), NON_FINITE (a non-finite light field or point, or irradiance that
   overflows float), NEGATIVE_EMISSION (a negative light colour), RAYCAST_FAILED. */
RAD_API rad_result rad_direct_irradiance(const rad_scene *scene, const rad_raycaster *raycaster,
                                         const rad_light *lights, uint32_t light_count,
                                         const rad_direct_options *options, const float *points,
                                         const float *normals, uint32_t count, float *out_irradiance,
                                         const rad_context *ctx);

/* Mean direct irradiance over each patch ('samples' lattice points per patch), 3N floats.
   A patch's own triangle never lights it. */
RAD_API rad_result rad_direct_patches(const rad_patches *patches, const rad_raycaster *raycaster,
                                      const rad_light *lights, uint32_t light_count,
                                      const rad_direct_options *options, float *out_irradiance,
                                      const rad_context *ctx);

typedef enum rad_source_mode {
    RAD_SOURCE_EMISSION = 0,   /* E_i = pi * L_i: emitters are the source */
    RAD_SOURCE_DIRECT = 1      /* E_i = rho_i * D_i: direct light is the source; emission is
                                  kept out of the system */
} rad_source_mode;

/* Builds E (3N floats) from the patches one of the two ways of UNITS AND CONVENTIONS.
   direct_irradiance (3N) is required for RAD_SOURCE_DIRECT and must be NULL for
   RAD_SOURCE_EMISSION (passing it there is the double-counting mistake: INVALID_ARGUMENT).
   A NaN or Inf in it is NON_FINITE, a negative value INVALID_ARGUMENT; out_E is written only on
   success. */
RAD_API rad_result rad_sources(const rad_patches *patches, rad_source_mode mode, const float *direct_irradiance,
                               float *out_E);

/* ---- final gather: one traced bounce in front of a radiosity solution ----
   A proxy (patches or virtual patches) holds radiosity as an average over each patch, so a
   point that sees more of the lit scene than its patch's average (open floors, the faces a
   camera sees) gets too little indirect light, and a coarse proxy blurs it. The final gather
   traces that one bounce instead: from each point, 'rays' cosine-distributed rays (stratified,
   rotated per point); at each front-facing hit the reflected light is rho(hit) (D(hit) + H(hit))
   with D the direct irradiance there (rad_direct_irradiance with the lights and emitters) and
   H the indirect irradiance the solution gives there (the caller's lookup: rad_vp_gather of
   H = F B for virtual patches, the per-vertex irradiance of patches), so
       out(p) = (1 / rays) sum_k rho_k (D_k + H_k)          (indirect irradiance at p)
   Misses and back faces give 0 (the sky and the emitters are direct light at p, counted by
   rad_direct_irradiance there). The proxy's error then enters only through H at the hits,
   one bounce further away. Cost per point: 'rays' closest-hit rays, 'rays' direct-light
   evaluations (light_samples shadow rays per area light each) and 'rays' lookups. */
typedef struct rad_final_gather_options {
    uint32_t rays;           /* per point (0: 64; at most 4096) */
    uint32_t light_samples;  /* shadow rays per hit and area light or sky (0: 4) */
    float ray_epsilon;       /* relative to the scene diagonal (0: 1e-5; at most 1e-2) */
    uint32_t seed;           /* decorrelates runs; same seed, same bits on any thread count */
} rad_final_gather_options;

/* H at 'count' hit points: hits[i] (triangle, barycentrics), points 3 floats, unit geometric
   normals 3 floats; writes 3 floats per point of indirect irradiance into out. Called from
   the thread that called rad_final_gather, with up to 65536 points at a time. */
typedef rad_result (*rad_gather_lookup_fn)(void *user, const rad_hit *hits, const float *points, const float *normals,
                                           uint32_t count, float *out_irradiance);

RAD_API void rad_final_gather_options_default(rad_final_gather_options *options);

/* Indirect irradiance (3 floats per point) at 'count' points with normals (normalized here;
   a zero one is refused), as above. lookup may be NULL (H = 0: exactly the first bounce of
   the lights). Errors: INVALID_ARGUMENT (NULL input, rays above 4096, a zero normal, bad
   light or ray_epsilon), NON_FINITE (a point, normal or result), RAYCAST_FAILED, CANCELLED,
   OUT_OF_MEMORY, or what lookup returned. Thread safety: reentrant; the ray work runs through
   ctx->parallel_for. */
RAD_API rad_result rad_final_gather(const rad_scene *scene, const rad_raycaster *raycaster, const rad_light *lights,
                                    uint32_t light_count, const rad_final_gather_options *options,
                                    rad_gather_lookup_fn lookup, void *lookup_user, const float *points,
                                    const float *normals, uint32_t count, float *out_irradiance, const rad_context *ctx);


/* ======================================================================================== */
/* >>api_shading: lighting models and BRDFs                                                 */
/* ======================================================================================== */

/* Local lighting models for the direct term and the final shading (docs/methods/shading.md; the set of
   models of Korobeinikov 2022, docs/references.md).
   Radiosity gives the indirect light of diffuse surfaces; these functions give the response
   of a surface to one light direction, the same in C and in glsl/lighting.glsl.

   CONVENTION. l (towards the light), v (towards the viewer) and n (the normal) are unit
   vectors. Two quantities are offered:
     f  the BRDF (sr^-1): outgoing radiance L_o = f * max(n.l, 0) * E, with E the light's
        irradiance on a surface facing it (rad_light.color for a directional light,
        I / d^2 for a point light). rad_shading_brdf() returns it.
     R  the response: L_o = R * E. For every model that has a BRDF, R = f * max(n.l, 0).
        rad_shading_eval() returns it; this is what a shader adds per light.
   The models usually stated as an "intensity" (a cosine-like number in
   [0,1]) are scaled by albedo / pi so that a white model of intensity cos(theta) is exactly
   Lambert: R = albedo / pi * intensity. For banded, f = R / (n.l). Half-Lambert (wrap)
   lights points with n.l < 0, so it has no BRDF: rad_shading_brdf() refuses it.
   Physical (reciprocal f(l,v) = f(v,l) and energy-conserving Integral f (n.l) dl <= 1 for
   albedos <= 1; tests/test_shading.c measures both): Lambert; Phong and Blinn-Phong in their
   normalized forms with kd + ks <= 1; Oren-Nayar nearly (the qualitative model: at albedo 1
   its directional albedo reaches 1.0105 at grazing view for sigma = 0.25, and stays <= 1 for
   sigma >= 0.5: 0.83 at sigma 1); the microfacet model with the Shirley diffuse term or none (with
   Shirley at albedo 1 the sum reaches 1.0015 at grazing view). The Lambert diffuse
   term (1 - F(n,l)) albedo / pi (the default, as in Korobeinikov 2022) is neither
   reciprocal nor energy-conserving with the specular term (measured 1.07 at albedo 1).
   Minnaert is reciprocal, energy-conserving only for k >= 1. Banded and half-Lambert are
   neither. Every model returns 0 (f and R) when n.v <= 0: surfaces are one-sided. */

typedef enum rad_shading_model {
    RAD_SHADING_LAMBERT = 0,      /* f = albedo / pi */
    RAD_SHADING_HALF_LAMBERT = 1, /* R = albedo / pi * max(0, (n.l + w) / (1 + w))^p (Valve's
                                     half-Lambert: w = 1, p = 2; w = 0, p = 1 is Lambert) */
    RAD_SHADING_BANDED = 2,       /* R = albedo / pi * ceil(bands * max(n.l, 0)) / bands */
    RAD_SHADING_PHONG = 3,        /* f = kd / pi + ks (s + 2) / (2 pi) max(0, r.v)^s,
                                     r = 2 (n.l) n - l (normalized modified Phong, Lewis 1994) */
    RAD_SHADING_BLINN_PHONG = 4,  /* f = kd / pi + ks c(s) max(0, n.h)^s, h = (l + v) / |l + v|,
                                     c(s) = (s + 2)(s + 4) / (8 pi (2^(-s/2) + s)): the
                                     normalization that makes the lobe's albedo at normal
                                     incidence exactly 1 (Real-Time Rendering; the common
                                     (s + 8) / (8 pi) overshoots it, by up to 7.5 % at s = 9) */
    RAD_SHADING_MINNAERT = 5,     /* f = albedo (k + 1) / (2 pi) (max(n.l n.v, 1e-6))^(k - 1)
                                     (Minnaert 1941; albedo at normal incidence = albedo) */
    RAD_SHADING_OREN_NAYAR = 6,   /* f = albedo / pi (A + B max(0, cos(phi_l - phi_v)) sin(a) tan(b)),
                                     A = 1 - 0.5 s^2 / (s^2 + 0.33), B = 0.45 s^2 / (s^2 + 0.09),
                                     a = max(theta_l, theta_v), b = min (Oren, Nayar 1994,
                                     qualitative model); computed as (l.v - n.l n.v) / max(n.l, n.v) */
    RAD_SHADING_MICROFACET = 7,   /* f = F(h,l) G2(l,v,h) D(h) / (4 |n.l| |n.v|) + f_diffuse (Cook & Torrance 1982) */
    RAD_SHADING_MODEL_COUNT = 8
} rad_shading_model;

typedef enum rad_ndf {
    RAD_NDF_BECKMANN = 0,         /* Beckmann; Lambda: the rational approximation of Walter et al. 2007 */
    RAD_NDF_GGX = 1               /* Walter et al. 2007; Lambda: exact */
} rad_ndf;

typedef enum rad_masking {
    RAD_MASKING_SEPARABLE = 0,         /* G2 = G1(v, h) G1(l, h)                (Heitz 2014) */
    RAD_MASKING_HEIGHT_CORRELATED = 1  /* G2 = chi(h.v) chi(h.l) / (1 + L(v) + L(l)) (Heitz 2014) */
} rad_masking;

typedef enum rad_diffuse_term {
    RAD_DIFFUSE_NONE = 0,         /* specular only */
    RAD_DIFFUSE_LAMBERT = 1,      /* (1 - F(n,l)) albedo / pi, F the Schlick term below (Korobeinikov 2022) */
    RAD_DIFFUSE_SHIRLEY = 2       /* (1 - F0) 21 albedo / (20 pi) (1 - (1 - n.l)^5) (1 - (1 - n.v)^5)
                                     (Shirley et al. 1997) */
} rad_diffuse_term;

/* Ranges are checked by rad_shading_validate (and so by the two entries). Albedos, kd, ks,
   f0 and f90 are per channel in [0, 1]. */
typedef struct rad_lambert_params { float albedo[3]; } rad_lambert_params;
typedef struct rad_half_lambert_params {
    float albedo[3];
    float wrap;                   /* w in [0, 1]; default 1 */
    float exponent;               /* p in [1, 8]; default 2 */
} rad_half_lambert_params;
typedef struct rad_banded_params {
    float albedo[3];
    uint32_t bands;               /* in [1, 256]; default 4 */
} rad_banded_params;
typedef struct rad_phong_params {  /* Phong and Blinn-Phong */
    float diffuse[3];             /* kd; default 0.5 */
    float specular[3];            /* ks; default 0.3; physical when kd + ks <= 1 */
    float shininess;              /* s in [1, 10000]; default 32 */
} rad_phong_params;
typedef struct rad_minnaert_params {
    float albedo[3];
    float k;                      /* in [0, 4]; 1 is Lambert; < 1 flattens the disc and
                                     brightens the limb (lunar look); default 0.8 */
} rad_minnaert_params;
typedef struct rad_oren_nayar_params {
    float albedo[3];
    float sigma;                  /* roughness, standard deviation of facet slopes in radians,
                                     in [0, 1.5]; 0 is Lambert; default 0.5 */
} rad_oren_nayar_params;
typedef struct rad_microfacet_params {
    rad_ndf ndf;                  /* default GGX */
    rad_masking masking;          /* default height-correlated */
    rad_diffuse_term diffuse;     /* default Lambert */
    float alpha_x, alpha_y;       /* roughness along t and b, each in [1e-3, 1]; equal values
                                     make the model isotropic (t and b then unused); default 0.3 */
    float f0[3];                  /* Fresnel reflectance at normal incidence; default 0.04 */
    float f90[3];                 /* ... at grazing incidence (generalized Schlick); default 1 */
    float fresnel_exponent;       /* 1/p of the generalized form, in [1, 10]; 5 is Schlick's; default 5 */
    float albedo[3];              /* rho of the diffuse term; default 0.5 */
} rad_microfacet_params;

/* A material for the shading entries: the model and its parameters (only model's member is
   read). */
typedef struct rad_shading {
    rad_shading_model model;
    rad_lambert_params lambert;
    rad_half_lambert_params half_lambert;
    rad_banded_params banded;
    rad_phong_params phong;       /* RAD_SHADING_PHONG and RAD_SHADING_BLINN_PHONG */
    rad_minnaert_params minnaert;
    rad_oren_nayar_params oren_nayar;
    rad_microfacet_params microfacet;
} rad_shading;

/* The documented defaults. Thread-safe, O(1). */
RAD_API void rad_lambert_params_default(rad_lambert_params *p);
RAD_API void rad_half_lambert_params_default(rad_half_lambert_params *p);
RAD_API void rad_banded_params_default(rad_banded_params *p);
RAD_API void rad_phong_params_default(rad_phong_params *p);
RAD_API void rad_minnaert_params_default(rad_minnaert_params *p);
RAD_API void rad_oren_nayar_params_default(rad_oren_nayar_params *p);
RAD_API void rad_microfacet_params_default(rad_microfacet_params *p);
/* Every member at its default and s->model = model. */
RAD_API void rad_shading_default(rad_shading *s, rad_shading_model model);

/* A model's name ("lambert", "half-lambert", "banded", "phong", "blinn-phong", "minnaert",
   "oren-nayar", "microfacet"), or NULL for a value out of range; and the reverse (returns
   INVALID_ARGUMENT for an unknown name). */
RAD_API const char *rad_shading_model_name(rad_shading_model model);
RAD_API rad_result rad_shading_model_from_name(const char *name, rad_shading_model *out_model);

/* Checks the model and the ranges of its parameters (only the active model's struct).
   Errors: INVALID_ARGUMENT (NULL, unknown model or enum, parameter out of range; the logger
   names it), NON_FINITE (a NaN or Inf parameter). Thread-safe, O(1). */
RAD_API rad_result rad_shading_validate(const rad_shading *s, const rad_context *ctx);

/* The two evaluation entries (see CONVENTION above; docs/methods/shading.md).
   l, v, n: non-zero finite 3-vectors, normalized here. t, b: the tangent frame, used only
   by an anisotropic microfacet model (alpha_x != alpha_y); there t is required, made
   orthogonal to n here, and b may be NULL (then b = n x t) or is made orthogonal to n and t.
   out_rgb: 3 floats, written on success.
   rad_shading_brdf writes f; rad_shading_eval writes R (f * max(n.l, 0), or the half-Lambert
   response).
   Errors: INVALID_ARGUMENT (NULL pointer, bad parameters as rad_shading_validate, a zero
   vector, t missing or parallel to n for an anisotropic model, half-Lambert given to
   rad_shading_brdf), NON_FINITE (a non-finite vector component). Thread-safe, O(1), no
   allocation. For a hot loop: rad_shading_pack once, then rad_shade. */
RAD_API rad_result rad_shading_brdf(const rad_shading *s, const float l[3], const float v[3], const float n[3],
                                    const float t[3], const float b[3], float out_rgb[3], const rad_context *ctx);
RAD_API rad_result rad_shading_eval(const rad_shading *s, const float l[3], const float v[3], const float n[3],
                                    const float t[3], const float b[3], float out_rgb[3], const rad_context *ctx);

/* Terms of the microfacet model, to compose your own (docs/methods/shading.md). Plain float math:
   the caller guarantees valid inputs (cosines in [-1, 1], roughness in (0, 1]); nothing is
   checked. All thread-safe and O(1). 'nm' is n.m, 'tm' t.m, 'bm' b.m for the microfacet
   normal m (usually h). */
RAD_API float rad_ndf_beckmann(float nm, float alpha);                                   /* Beckmann */
RAD_API float rad_ndf_beckmann_aniso(float nm, float tm, float bm, float alpha_x, float alpha_y); /* Beckmann, anisotropic */
RAD_API float rad_ndf_ggx(float nm, float alpha);                                        /* GGX */
RAD_API float rad_ndf_ggx_aniso(float nm, float tm, float bm, float alpha_x, float alpha_y);      /* GGX, anisotropic */
/* The Smith variable a = n.s / sqrt(alpha_x^2 (t.s)^2 + alpha_y^2 (b.s)^2) (Heitz 2014; with
   alpha_x = alpha_y = alpha it is n.s / (alpha sqrt(1 - (n.s)^2)), since (t.s)^2 + (b.s)^2 = 1 - (n.s)^2). Returns
   +inf for s = n (no masking); requires n.s > 0. */
RAD_API float rad_smith_a(float ns, float ts, float bs, float alpha_x, float alpha_y);
/* Lambda(a) for a > 0: GGX (exact); Beckmann's rational approximation (Walter et al. 2007; 0 for
   a >= 1.6); Beckmann's exact form (with erf; C only, the reference for the
   approximation). Each returns 0 for a = +inf. */
RAD_API float rad_lambda_ggx(float a);
RAD_API float rad_lambda_beckmann(float a);
RAD_API float rad_lambda_beckmann_exact(float a);
/* G1 = chi+(m.s) / (1 + Lambda(s)) (Heitz 2014). */
RAD_API float rad_smith_g1(float ms, float lambda_s);
/* G2 separable G1(v) G1(l) and height-correlated 1 / (1 + Lambda(v) + Lambda(l)) (Heitz 2014). */
RAD_API float rad_smith_g2_separable(float mv, float ml, float lambda_v, float lambda_l);
RAD_API float rad_smith_g2_height_correlated(float mv, float ml, float lambda_v, float lambda_l);
/* Schlick's Fresnel F0 + (1 - F0)(1 - max(c, 0))^5 (Schlick 1994) and its generalized form
   F0 + (F90 - F0)(1 - max(c, 0))^exponent (Real-Time Rendering; exponent = 1/p). One channel. */
RAD_API float rad_fresnel_schlick(float f0, float c);
RAD_API float rad_fresnel_schlick_f90(float f0, float f90, float exponent, float c);
/* Diffuse terms, one channel: Lambert (1 - F) albedo / pi (F = F(n,l)), Shirley
   et al. (1 - F0) 21 albedo / (20 pi) (1 - (1 - nl+)^5)(1 - (1 - nv+)^5). */
RAD_API float rad_diffuse_lambert(float albedo, float F);
RAD_API float rad_diffuse_shirley(float albedo, float f0, float nl, float nv);

/* The std430 mirror of glsl/lighting.glsl's ShadingParams (96 bytes, vec4-aligned):
   albedo (albedo, or kd for Phong), specular (ks), f0, f90, p = (alpha_x, alpha_y, model
   parameter: wrap / shininess / k / sigma, second parameter: half-Lambert exponent / bands /
   Fresnel exponent), mode = (model, ndf, masking, diffuse). */
typedef struct rad_shading_gpu {
    float albedo[4];
    float specular[4];
    float f0[4];
    float f90[4];
    float p[4];
    int32_t mode[4];
} rad_shading_gpu;

/* Validates a material and packs it for rad_shade and the GLSL functions. Errors as
   rad_shading_validate. Thread-safe, O(1). */
RAD_API rad_result rad_shading_pack(const rad_shading *s, rad_shading_gpu *out, const rad_context *ctx);

/* The unchecked evaluator behind both entries, the C twin of GLSL rad_shade(): f (out_f)
   and R (out_r; either may be NULL) for a material packed by rad_shading_pack and unit l, v,
   n, with t, b an orthonormal tangent frame (read only when anisotropic; may be NULL then).
   Garbage in, garbage out; no allocation; thread-safe; O(1). */
RAD_API void rad_shade(const rad_shading_gpu *g, const float l[3], const float v[3], const float n[3], const float t[3],
                       const float b[3], float out_f[3], float out_r[3]);


/* ======================================================================================== */
/* >>api_container: baked data                                                              */
/* ======================================================================================== */

/* One versioned binary container for everything a bake produces (docs/methods/container.md). Layout, all
   little-endian: a 64-byte header ("RADB", version, section count, table offset, file size,
   flags, CRC-32 of the table, CRC-32 of the header), a table of 64-byte section entries (type, element size, element count,
   offset, byte size, CRC-32 of the data, a 24-byte name), and the section data, each section
   starting on a 64-byte boundary so the file can be memory-mapped and read in place.
   Loading validates every size, offset, checksum and index before anything is used.
   VERSIONING: RAD_CONTAINER_VERSION changes only when the header or the table entry layout
   changes (a reader refuses another version with RAD_ERROR_VERSION). New section types are
   added without a version change: readers look sections up by type and name and skip the
   ones they do not know, so a file without a newer section (RAD_SECTION_SIGNATURE, added
   in 0.1.0) still loads, and an older reader loads a newer file.
   VALUES: behind a valid checksum a section may still hold values that would make every
   later step NaN, infinite or slow, so each loader (rad_load_memory, rad_multibounce_load,
   rad_multibounce_blocks_load, rad_alias_tables_view) checks the values it hands out, once,
   in O(size of the section): every float is finite (else RAD_ERROR_NON_FINITE) and of
   magnitude at most RAD_BAKE_VALUE_MAX (patch areas excepted: they grow with the square of
   the scene's scale), patch emission is >= 0 (RAD_ERROR_NEGATIVE_EMISSION), and the quantities that are non-negative by
   definition (form factors, F_mb entries, block scales, outliers, alias totals) are >= 0
   (else RAD_ERROR_CORRUPT); the logger names the section, the entry and the value. */
#define RAD_CONTAINER_VERSION 1u
/* The largest magnitude a loader accepts in a float section: 1e30, so that a sum of up to
   3e8 such values (more than any row holds) stays finite. Nothing physical comes near (form
   factors are <= 1, F_mb entries <= 1 / (1 - max albedo) <= 2^24); rad_save_memory refuses
   larger values in what it writes, so whatever it writes loads. */
#define RAD_BAKE_VALUE_MAX 1e30f

typedef enum rad_section_type {
    RAD_SECTION_PATCHES = 1,         /* rad_patch records */
    RAD_SECTION_PATCH_VERTICES = 2,  /* 3 floats per welded vertex */
    RAD_SECTION_TRIANGLES = 3,       /* 2 uint32 per scene triangle: first patch, subdivision */
    RAD_SECTION_FF_DENSE = 4,        /* N*N floats, row-major */
    RAD_SECTION_FF_ROW_OFFSETS = 5,  /* CSR: N+1 uint64 */
    RAD_SECTION_FF_COLUMNS = 6,      /* CSR: uint32 */
    RAD_SECTION_FF_VALUES = 7,       /* CSR: floats */
    RAD_SECTION_VECTOR = 8,          /* a named RGB vector, 3N floats ("E", "B", "L", "H", ...) */
    RAD_SECTION_SIGNATURE = 9,       /* one rad_bake_signature ("signature"): what it was made from */
    RAD_SECTION_USER = 0x10000       /* types from here up are the application's own */
} rad_section_type;

/* One section, for writing (data borrowed) or as found by rad_container_find (data points
   into the container's bytes). */
typedef struct rad_section {
    uint32_t type;
    uint32_t elem_size;     /* bytes per element */
    uint64_t count;         /* elements */
    const void *data;       /* count * elem_size bytes */
    char name[24];          /* NUL-terminated, may be empty */
} rad_section;

typedef struct rad_container rad_container;

/* Bytes that rad_container_write needs for these sections (SIZE_OVERFLOW if it overflows). */
RAD_API rad_result rad_container_size(const rad_section *sections, uint32_t count, size_t *out_bytes);
/* Writes the container into dst (dst_size >= rad_container_size). */
RAD_API rad_result rad_container_write(const rad_section *sections, uint32_t count, void *dst, size_t dst_size);
/* Validates 'size' bytes at 'data' (borrowed: they must outlive the container, which reads
   them in place: memory-mapped files work) and opens them. Errors: TRUNCATED, CORRUPT,
   VERSION, INVALID_ARGUMENT, OUT_OF_MEMORY; the logger says which section and why. */
RAD_API rad_result rad_container_open(const void *data, size_t size, const rad_context *ctx, rad_container **out);
RAD_API void rad_container_close(rad_container *container);
RAD_API uint32_t rad_container_section_count(const rad_container *container);
/* Section i (0 <= i < count), or NULL. */
RAD_API const rad_section *rad_container_section(const rad_container *container, uint32_t index);
/* The first section of 'type' whose name equals 'name' (any name when name is NULL), or NULL. */
RAD_API const rad_section *rad_container_find(const rad_container *container, uint32_t type, const char *name);

/* What a bake was made from (section RAD_SECTION_SIGNATURE, one 32-byte element), so that a
   bake of another scene with the same triangle and patch counts is refused instead of
   rendering silently wrong (rad_bake_matches_scene). A field of 0 was not recorded. */
typedef struct rad_bake_signature {
    uint64_t geometry;       /* rad_scene_hash: the triangles' positions */
    uint64_t materials;      /* rad_scene_hash: each triangle's albedo, emission, texture id, uvs */
    uint64_t options;        /* the application's hash of the options it baked with (rad_hash64) */
    uint64_t reserved;       /* 0; readers ignore it */
} rad_bake_signature;

/* FNV-1a, 64 bits, over 'size' bytes, continuing from 'hash' (RAD_HASH64_INIT to start):
   for each byte, hash = (hash ^ byte) * 0x100000001B3. rad_hash64("a", 1, RAD_HASH64_INIT)
   is 0xAF63DC4C8601EC8C. Pure, O(size). */
#define RAD_HASH64_INIT 0xCBF29CE484222325ull
RAD_API uint64_t rad_hash64(const void *data, size_t size, uint64_t hash);
/* The two hashes of a signature, stable across platforms, byte orders and builds (only the
   scene's input values enter, as the little-endian bytes of their IEEE bit patterns, never
   values the library derives from them):
     geometry  = rad_hash64 of triangle_count (uint32), then per triangle its 9 position floats;
     materials = rad_hash64 of triangle_count, then per triangle its material's albedo[3],
                 emission[3] (floats) and texture (uint32), then 1 and the 6 uv floats per
                 triangle when the scene has uvs, else 0.
   Indices are covered (positions are per triangle), and the geometric normals and areas follow
   from the positions; shading normals are not kept by rad_scene, and a texture's contents
   (the albedo_lookup callback) cannot be hashed, only its id. Either output may be NULL.
   Errors: INVALID_ARGUMENT. Cost: O(triangles), no allocation. Thread safety: pure. */
RAD_API rad_result rad_scene_hash(const rad_scene *scene, uint64_t *out_geometry, uint64_t *out_materials);

/* A loaded bake: patches (usable with rad_patches_locate, rad_patches_vertex_values and
   rad_system_init; patches.scene is NULL, set it before calling functions that need the
   scene), the form-factor matrix (rows == 0 when the bake has none) and the named vectors.
   Everything points into the loaded bytes; free it with rad_bake_destroy, never with
   rad_patches_destroy. */
typedef struct rad_bake {
    rad_patches patches;
    rad_matrix F;
    const float *E;          /* "E" vector or NULL */
    const float *B;          /* "B" vector (the solution as saved) or NULL */
    const rad_bake_signature *signature; /* NULL when the bake has none (saved without a scene) */
    rad_container *container;
    void *owned;             /* private: bytes read from a file */
    rad_allocator allocator; /* private */
} rad_bake;

/* Saves patches (required), a matrix (optional: NULL) and the vectors E and B (optional:
   NULL; 3 * patches->count floats) into a new buffer *out of *out_size bytes, allocated with
   ctx's allocator (free it with rad_free_buffer). When patches->scene is set, a signature
   section records its rad_scene_hash (options 0: an application that wants its options
   checked too rewrites that section with its own hash in 'options'). Values that a loader
   would refuse (see VALUES above) are refused here: NON_FINITE, CORRUPT. */
RAD_API rad_result rad_save_memory(const rad_patches *patches, const rad_matrix *F, const float *E, const float *B,
                                   const rad_context *ctx, void **out, size_t *out_size);
RAD_API void rad_free_buffer(void *buffer, const rad_context *ctx);
/* Opens a saved bake in place (data borrowed, must outlive the bake) and checks every index:
   patch vertices < vertex count, patch triangles < triangle count, CSR offsets monotone and
   columns < N, vector and matrix sizes equal to the patch count; and every value (VALUES
   above): the form factors and every RAD_SECTION_VECTOR section (E, B and the application's
   "H", "L", ...: each must hold 3N floats). A signature section, when present, must be one
   32-byte element. Errors: the container's, NON_FINITE, CORRUPT, INDEX_OUT_OF_RANGE,
   SIZE_MISMATCH, ALBEDO_RANGE, DEGENERATE_TRIANGLE, OUT_OF_MEMORY. */
RAD_API rad_result rad_load_memory(const void *data, size_t size, const rad_context *ctx, rad_bake **out);
RAD_API void rad_bake_destroy(rad_bake *bake);
/* RAD_SUCCESS when 'bake' was made from 'scene': the same triangle count and, when the bake
   has a signature, the same geometry and materials hashes (rad_scene_hash), and the same
   options hash when both 'options' and the bake's are non-zero. Otherwise
   RAD_ERROR_SCENE_MISMATCH, and the logger says what differs (geometry, materials, options)
   with both hashes. A bake without a signature (saved without a scene) is checked by its
   triangle count only, with a warning through the logger. Errors: INVALID_ARGUMENT,
   SCENE_MISMATCH. Cost: O(triangles). */
RAD_API rad_result rad_bake_matches_scene(const rad_bake *bake, const rad_scene *scene, uint64_t options,
                                          const rad_context *ctx);
#ifndef RAD_NO_STDIO
/* The same, through a file. Saving writes '<path>.partial' in the same folder and renames it
   into place only when complete, so a failed save leaves the old file as it was (IO). Loading
   reads the 64-byte header first and refuses a folder (IO), a file without the container
   magic (CORRUPT) or one shorter than its header says (TRUNCATED) before reading the rest. */
RAD_API rad_result rad_save_file(const char *path, const rad_patches *patches, const rad_matrix *F, const float *E,
                                 const float *B, const rad_context *ctx);
RAD_API rad_result rad_load_file(const char *path, const rad_context *ctx, rad_bake **out);
#endif

/* ======================================================================================== */
/* >>api_glsl: GLSL compute kernels                                                         */
/* ======================================================================================== */

/* The compute kernels, as GLSL 4.50 source text the application compiles (with
   glslang or shaderc) and dispatches on its own Vulkan 1.1+ device (Vulkan GLSL: push
   constants and specialization constants): radiosity.h never touches a GPU. The canonical
   sources are the files glsl/<name> of the repository; the copy in the >>glsl section is
   generated from them (make glsl) and a test fails when it is out of date. Every kernel is compiled and run by tests/test_vulkan.c on a Vulkan device
   (Mesa's lavapipe in CI) and compared with the CPU function named in its entry.

   COMMON RULES
   - Compute only. Descriptor set 0, bindings as listed, every buffer a std430 storage buffer
     of 32-bit scalars (float, uint) or uint64 row offsets read as uvec2 (low word first: the
     little-endian layout of rad_matrix.row_offsets and rad_alias_tables.row_offsets, uploaded
     unchanged). RGB vectors are 3N interleaved floats, as everywhere in radiosity.h.
   - Workgroup: layout(local_size_x_id = 0): specialization constant RAD_GLSL_SPEC_LOCAL_SIZE
     (id 0) sets the x size (default 1 when not specialized; 64 to 256 are good choices, any
     size up to maxComputeWorkGroupInvocations works). Nothing depends on the subgroup size.
   - Dispatch. The gathers and applies (GATHER_*, MB_APPLY_*, LOCAL_APPLY, LOCAL_UPDATE) run
     ONE WORKGROUP PER ROW: dispatch row_count groups in x (at most
     maxComputeWorkGroupCount[0], 65535 guaranteed: chunk longer runs); the group's
     invocations read the row at consecutive addresses with a stride of the group size and sum
     in shared memory (12 bytes per invocation). The temporal step, the alias build and
     VP_GATHER run ONE INVOCATION PER ROW (point): ceil(row_count / size) groups
     (LOCAL_VECTORS: per row or column, see its entry).
   - Push constants: one block per kernel, at most 64 bytes (Vulkan guarantees 128), mirrored
     by the rad_glsl_*_push structs below (only 4-byte members, no padding; sizes and offsets
     checked at compile time).
   - CHUNKING. Every kernel processes rows [row_offset, row_offset + row_count) and reads the
     big array (the matrix, its entries or bins) relative to a base, so a matrix larger than
     one storage-buffer range (maxStorageBufferRange: 128 MiB on lavapipe, 4 GiB on most
     desktop drivers) is processed as several dispatches, each binding only its rows: bind the
     range from an offset rounded down to minStorageBufferOffsetAlignment and pass the
     remainder, in elements, as the base. Small arrays (vectors, row offsets) are bound whole.
   - Results agree with the CPU path to float rounding: the tests accept 1e-5 relative. The
     temporal kernel draws the same indices as rad_temporal_step (same generator, same alias
     draw, integer arithmetic), so it is compared directly.

   THE KERNELS (binding: contents)
   RAD_GLSL_GATHER_DENSE   one classic bounce, out_i = rho_i sum_j F_ij E_j (+ E_i),
       as rad_solve_jacobi with bounces = 1. Push: rad_glsl_gather_dense_push.
       0: F, row-major, rows of the chunk (F[row_offset][0] at element f_base)  1: E (3N)
       2: albedo (3N)  3: out (3N; rows of the chunk written)
   RAD_GLSL_GATHER_CSR     the same with a CSR matrix. Push: rad_glsl_gather_csr_push.
       0: row offsets (N + 1 uint64)  1: columns  2: values (entry k at element k - entry_base)
       3: E  4: albedo  5: out
   RAD_GLSL_MB_APPLY_FLOAT out = F_mb E (+ E) as rad_multibounce_apply, float planes.
       Push: rad_glsl_mb_apply_push; flags RAD_GLSL_FLAG_TOTAL, RAD_GLSL_FLAG_PERMUTED.
       0, 1, 2: the R, G, B planes (rows of the chunk, plane row row_offset at element base)
       3: E (original order)  4: col_perm  5: row_perm (bind any buffer when not PERMUTED)
       6: out (original order; rows row_perm[row_offset ..] written)
   RAD_GLSL_MB_APPLY_HALF  the same with binary16 planes (rad_multibounce.half uploaded
       unchanged, read as uint words with unpackHalf2x16; base counted in halves). Each plane's
       buffer and each bound range must cover whole 4-byte words: pad a plane of odd N^2 to a
       multiple of 4 bytes and round a chunk's range up, or the word holding its last value
       reads as zero (robust buffer access).
   RAD_GLSL_TEMPORAL_STEP  one frame of rad_temporal_step with a fixed weight (the adaptive
       weight stays on the CPU). Push: rad_glsl_temporal_push.
       0: row offsets of the tables (rows + 1 uint64, in bins)  1: bins (2 or 3 words each;
       word w of the tables, bin b starting at w = b * words, at element w - word_base)
       2: totals T_i  3: E  4: albedo  5: B^prev  6: B^next (ping-pong the two buffers
       between frames)  7: bins per row, RAD_GLSL_FLAG_PADDED only (else bind any buffer).
       MULTIBOUNCE mode with three table sets: three dispatches, channel c, sample_base c * k,
       table set c bound. PADDED: the tables as RAD_GLSL_ALIAS_BUILD writes them (binding 0 =
       its input row offsets, 2 and 7 its totals and counts), sampled without compaction.
   RAD_GLSL_MB_APPLY_BLOCKS  out = F~ E (+ E) as rad_multibounce_blocks_apply: the blocks
       uploaded unchanged as VK_FORMAT_BC1_RGB_UNORM_BLOCK or three VK_FORMAT_BC4_UNORM_BLOCK
       images (feature textureCompressionBC), decoded by the texture unit with texelFetch
       (decoders round differently: within 2/255 per channel of rad_bc1_decode_block and
       rad_bc4_decode_block, measured 1.6/255 on lavapipe), times the tile scales, plus the
       exact outliers. Push: rad_glsl_mb_blocks_push; flags RAD_GLSL_FLAG_TOTAL, _PERMUTED,
       _BC1, _OUTLIERS. 0, 1, 2: combined image samplers (BC1:
       the one image at all three; BC4X3: R, G, B planes)  3: scales (3 per tile)  4: E
       5: col_perm  6: row_perm  7: outlier offsets (N + 1 uint64)  8: outlier columns
       9: outlier values (3 each)  10: out. Rows are texel rows (chunks of row_offset, row_count
       with row_offset + row_count <= N); the outlier arrays are bound whole (indexed by
       original row), which limits them to one storage range (N of about 14 000 at 5%), and
       the image to maxImageDimension2D texels (16384 on lavapipe).
   RAD_GLSL_ALIAS_BUILD    alias tables of streamed rows (docs/methods/temporal.md), the bins of
       rad_alias_build_row (Vose in double: needs the shaderFloat64 feature; bit-identical where
       double arithmetic is IEEE, as on lavapipe). Push: rad_glsl_alias_build_push; flags
       RAD_GLSL_FLAG_DENSE (rows of cols values, no column array). 0: input row offsets
       (rows + 1 uint64)  1: columns  2: values (entry k at k - entry_base)  3: bins out, padded
       layout: row i's bins from bin row_offsets[i] + i (room for its entries + 1), at word
       (b - out_base) * words  4: scratch, one double per output bin  5: scratch, one uint per
       output bin  6: bin count per row (0: a negative or non-finite entry, or a column >= cols)
       7: T_i per row. RAD_GLSL_TEMPORAL_STEP samples this layout directly (RAD_GLSL_FLAG_PADDED).
   RAD_GLSL_LIGHTING       an include, not a kernel: every lighting model and BRDF term of
       >>api_shading as GLSL functions named as in C (rad_shade ...), no #version line: put
       its text after yours (or resolve an #include to it). Its results agree with the C
       functions to 1e-5 relative (tests/test_shading_vulkan.c, through glsl/lighting_eval.comp;
       the header's copy is checked equal to glsl/lighting.glsl).
   RAD_GLSL_LOCAL_APPLY    L_i = sum_{j in P_Lit} T_ij E_j (+ E_i) for i in P_Vis, as rad_local_apply,
       on the planes of a rad_local (>>api_local; uploaded unchanged or kept resident on the
       GPU). Push: rad_glsl_local_apply_push; flags RAD_GLSL_FLAG_TOTAL. ONE WORKGROUP PER
       VISIBLE ENTRY. 0, 1, 2: the R, G, B planes (stride m = capacity; the rows slot_offset ..
       slot_offset + slot_count - 1, row slot_offset at element base)  3: E (3n, world order)
       4: lit map, slot_end uints: the world patch whose E lights column j, or RAD_NONE
       (unlit or free slot)  5: slot of each visible entry  6: world patch of each visible entry
       7: out (3n; the visible patches written). Chunks: an entry whose slot is outside the
       bound rows is skipped, so each chunk's dispatch may take the whole visible list.
   RAD_GLSL_LOCAL_VECTORS and RAD_GLSL_LOCAL_UPDATE  rad_local_add on T resident on the GPU:
       the host keeps the slot bookkeeping (which slot, which member to evict) and streams only
       the new patch's row and column over the slots, a_c[j] = rho_c[patch(j)] A_n F_nj / A_j and
       b_c[j] = rho_c[n] F_nj (3 m floats each, channel-major, zero outside the members and at
       the evicted slot), the list nz of the slots where F_nj != 0, and rho_n F_nn. VECTORS is
       the small pre-pass: u = (I + T) a, v = b (I + T) (pass RAD_GLSL_LOCAL_PASS_GATHER, one
       dispatch per row chunk, one invocation per row or column: max(row_count, end)
       invocations), the corrections of the fused exact downdate when the add evicts slot ev
       (pass _EVICT, end invocations) and s = 1 - ann - b.u with the factors of the exact or
       first-order form (pass _SCALARS, 3 invocations), in float, into a work buffer of
       RAD_GLSL_LOCAL_WORK_FLOATS(m) floats; UPDATE is the O(M^2) pass, ONE WORKGROUP PER ROW:
       T += cuv u v - c r / g (rank 1, or rank 2 when evicting), the new row coef v and column
       coef u, T_kk. Pushes: rad_glsl_local_vectors_push, rad_glsl_local_update_push; the
       layout of the work buffer is in glsl/local_vectors.comp. VECTORS bindings: 0, 1, 2
       planes (the chunk's rows at base; passes 1 and 2 read none: bind any range)  3: a
       4: b  5: nz  6: work. UPDATE bindings: 0, 1, 2 planes (read-write, the chunk's rows)
       3: work. A kernel cannot return an error: when s <= 1e-12 in some channel (rows that
       break energy conservation: the CPU's RAD_ERROR_SINGULAR) UPDATE writes nothing; read s
       (work[12 m + c]) back to detect it. With RAD_LOCAL_EVICT_DROP an add into a full set is
       a plain add (ev = RAD_NONE) into the dropped member's slot k, with that member out of
       the slot map: row and column k are overwritten as the drop would have zeroed them.
       Each dispatch reads what the one before it wrote (pass 0's chunks accumulate v): in
       one command buffer, put a compute-to-compute buffer memory barrier (shader write to
       shader read) between consecutive dispatches, and before LOCAL_APPLY reads the planes.
       The standalone rad_local_evict (a rank-1 downdate) has no kernel; hiding and showing
       members (rad_local_remove, re-adding a hidden member) touch no plane. Measured on
       lavapipe (tests/test_vulkan.c), T resident through 54 adds into M = 48 (the last 6 into
       a full set: rank 2, or after a drop): at most 9.7e-7 relative from rad_local_add's
       planes (exact and first-order), the float pre-pass against the CPU's double u, v, s.
   RAD_GLSL_VP_GATHER      virtual-patch gathering at surface points (vertices, G-buffer
       texels), as rad_vp_gather: split-weight (or, clustered, N . n) normal weights in each
       voxel of the 2x2x2 block, trilinear weights across the voxels, voxels missing or with no
       patch facing n skipped (>>api_vp). Push: rad_glsl_vp_gather_push (the grid of the
       rad_virtual_patches); flags RAD_GLSL_FLAG_COSINE (weights RAD_VP_WEIGHTS_COSINE),
       _CLUSTERED. ONE INVOCATION PER POINT. 0: points (3 floats each)  1: unit normals
       (3 each)  2: values per patch (3N: B, L or H)  3: voxel_keys (voxel_count uint64, as
       uvec2)  4: voxel_patch (6 per voxel)  5: patch normals (3N; read only when CLUSTERED,
       else bind any buffer)  6: out (3 per point). Chunks: bindings 0, 1 and 6 hold the
       chunk's points from element base (bind the three at the same offset). The grid
       coordinate is computed as a float pair (TwoSum / Dekker products: the CPU uses double),
       because its float rounding, about 1e-7 dims absolute, is large against small trilinear
       weights (measured: 3e-5 relative without it, 2.9e-7 with it, on lavapipe). */

/* >>glsl ids begin */
typedef enum rad_glsl_id {
    RAD_GLSL_GATHER_DENSE      =  0, /* glsl/gather_dense.comp */
    RAD_GLSL_GATHER_CSR        =  1, /* glsl/gather_csr.comp */
    RAD_GLSL_MB_APPLY_FLOAT    =  2, /* glsl/mb_apply_float.comp */
    RAD_GLSL_MB_APPLY_HALF     =  3, /* glsl/mb_apply_half.comp */
    RAD_GLSL_TEMPORAL_STEP     =  4, /* glsl/temporal_step.comp */
    RAD_GLSL_MB_APPLY_BLOCKS   =  5, /* glsl/mb_apply_blocks.comp */
    RAD_GLSL_ALIAS_BUILD       =  6, /* glsl/alias_build.comp */
    RAD_GLSL_LIGHTING          =  7, /* glsl/lighting.glsl */
    RAD_GLSL_LOCAL_APPLY       =  8, /* glsl/local_apply.comp */
    RAD_GLSL_LOCAL_VECTORS     =  9, /* glsl/local_vectors.comp */
    RAD_GLSL_LOCAL_UPDATE      = 10, /* glsl/local_update.comp */
    RAD_GLSL_VP_GATHER         = 11, /* glsl/vp_gather.comp */
    RAD_GLSL_COUNT = 12
} rad_glsl_id;
/* >>glsl ids end */

#define RAD_GLSL_SPEC_LOCAL_SIZE 0u   /* specialization constant id of the workgroup x size */
#define RAD_GLSL_FLAG_TOTAL 1u        /* gather, multi-bounce apply: add E (RAD_OUTPUT_TOTAL) */
#define RAD_GLSL_FLAG_PERMUTED 2u     /* multi-bounce apply: row_perm and col_perm are bound */
#define RAD_GLSL_FLAG_ALBEDO 1u       /* temporal: X *= rho (SINGLE, FEEDBACK) */
#define RAD_GLSL_FLAG_FEEDBACK 2u     /* temporal: sample V = E + B^prev (FEEDBACK) */
#define RAD_GLSL_FLAG_PADDED 4u       /* temporal: tables in the padded layout of RAD_GLSL_ALIAS_BUILD */
#define RAD_GLSL_FLAG_BC1 4u          /* block apply: one BC1 image (else three BC4 images) */
#define RAD_GLSL_FLAG_OUTLIERS 8u     /* block apply: the outlier arrays are bound */
#define RAD_GLSL_FLAG_DENSE 1u        /* alias build: dense rows, no column array */
#define RAD_GLSL_FLAG_FIRST_CHUNK 1u  /* local vectors, pass 0: the first row chunk (v = b + ...) */
#define RAD_GLSL_FLAG_FIRST_ORDER 2u  /* local vectors, pass 2: RAD_LOCAL_FIRST_ORDER factors */
#define RAD_GLSL_LOCAL_PASS_GATHER 0u  /* local vectors: u, c, v, r from T (row-chunked) */
#define RAD_GLSL_LOCAL_PASS_EVICT 1u   /* local vectors: the fused downdate's corrections (evicting adds) */
#define RAD_GLSL_LOCAL_PASS_SCALARS 2u /* local vectors: s and the factors, 3 invocations */
/* floats of the local-update work buffer for capacity m (u, v, c, r per channel, 12 scalars) */
#define RAD_GLSL_FLAG_COSINE 1u       /* vp gather: RAD_VP_WEIGHTS_COSINE split weights */
#define RAD_GLSL_FLAG_CLUSTERED 2u    /* vp gather: RAD_VP_CLUSTERED (w = N_a . n; binding 5 read) */
#define RAD_GLSL_LOCAL_WORK_FLOATS(m) (12u * (uint64_t)(m) + 12u)

/* Push-constant mirrors (C layout == GLSL layout; all members 4 bytes). */
typedef struct rad_glsl_gather_dense_push {
    uint32_t row_offset, row_count, cols, f_base, flags;
} rad_glsl_gather_dense_push;
typedef struct rad_glsl_gather_csr_push {
    uint32_t row_offset, row_count, entry_base, flags;
} rad_glsl_gather_csr_push;
typedef struct rad_glsl_mb_apply_push {   /* RAD_GLSL_MB_APPLY_FLOAT and _HALF */
    uint32_t n, row_offset, row_count, base, flags;
} rad_glsl_mb_apply_push;
typedef struct rad_glsl_temporal_push {
    uint32_t seed, frame;          /* rad_temporal_options.seed; the frame being computed (0, 1, ...) */
    uint32_t row_offset, row_count;
    uint32_t n;                    /* N: the environment's column */
    uint32_t samples;              /* k */
    uint32_t words;                /* (uint32_t)rad_alias_tables.format: 2 or 3 */
    uint32_t flags;                /* RAD_GLSL_FLAG_ALBEDO, _FEEDBACK, _PADDED */
    uint32_t channel;              /* 3: RGB from one table set; 0..2: this channel only */
    uint32_t sample_base;          /* channel * k with three table sets, else 0 */
    uint32_t word_base;            /* low 32 bits of the tables' word index at element 0 of binding 1 */
    float weight;                  /* w */
    float env[3];                  /* E_0 */
} rad_glsl_temporal_push;
typedef struct rad_glsl_mb_blocks_push {
    uint32_t n, row_offset, row_count;
    uint32_t tile, tiles_per_row;  /* rad_multibounce_blocks.tile, .tiles_per_row */
    uint32_t flags;
} rad_glsl_mb_blocks_push;
typedef struct rad_glsl_alias_build_push {
    uint32_t row_offset, row_count;
    uint32_t cols;                 /* N: the environment's column */
    uint32_t words;                /* 2 (RAD_ALIAS_COMPACT, cols <= 65535) or 3 (RAD_ALIAS_WIDE) */
    uint32_t entry_base;           /* low 32 bits of the entry at element 0 of bindings 1, 2 */
    uint32_t out_base;             /* low 32 bits of the bin at element 0 of bindings 3, 4, 5 */
    uint32_t flags;                /* RAD_GLSL_FLAG_DENSE */
} rad_glsl_alias_build_push;
typedef struct rad_glsl_local_apply_push {
    uint32_t m, end;               /* rad_local.capacity (plane stride), rad_local.slot_end */
    uint32_t row_offset, row_count; /* visible entries of this dispatch */
    uint32_t slot_offset, slot_count; /* plane rows held by bindings 0..2 */
    uint32_t base;                 /* element of bindings 0..2 holding plane row slot_offset */
    uint32_t flags;                /* RAD_GLSL_FLAG_TOTAL */
} rad_glsl_local_apply_push;
typedef struct rad_glsl_local_vectors_push {
    uint32_t m, end;               /* capacity; slots in use after the add */
    uint32_t row_offset, row_count, base; /* pass 0: the plane rows bound */
    uint32_t nnz;                  /* slots in the nz list */
    uint32_t ev;                   /* the slot evicted by this add, or RAD_NONE */
    uint32_t pass;                 /* RAD_GLSL_LOCAL_PASS_* */
    uint32_t flags;                /* RAD_GLSL_FLAG_FIRST_CHUNK, _FIRST_ORDER */
    float ann[3];                  /* rho_n F_nn per channel */
} rad_glsl_local_vectors_push;
typedef struct rad_glsl_local_update_push {
    uint32_t m, end, row_offset, row_count, base;
    uint32_t k;                    /* the new patch's slot */
    uint32_t ev;                   /* the slot evicted by this add (== k), or RAD_NONE */
} rad_glsl_local_update_push;
typedef struct rad_glsl_vp_gather_push {
    float origin[3];               /* rad_virtual_patches.origin */
    float voxel_size[3];           /* .voxel_size */
    uint32_t dims[3];              /* .dims */
    uint32_t voxel_count;          /* .voxel_count */
    uint32_t row_offset, row_count; /* the points of this dispatch */
    uint32_t base;                 /* element of bindings 0, 1, 6 holding point row_offset's x */
    uint32_t flags;                /* RAD_GLSL_FLAG_COSINE, _CLUSTERED */
} rad_glsl_vp_gather_push;

/* The file name of kernel 'id' ("gather_dense.comp"), or NULL for an unknown id. Pure. */
RAD_API const char *rad_glsl_name(rad_glsl_id id);

/* The source of kernel 'id' in pieces: returns an array of *out_count string pointers (static
   storage, never freed) whose concatenation is the source, or NULL (and 0) for an unknown id.
   Each piece is at most 4000 characters and ends at a line end. Pure, thread-safe. */
RAD_API const char *const *rad_glsl_pieces(rad_glsl_id id, uint32_t *out_count);

/* The whole source of kernel 'id' (the pieces concatenated), NUL-terminated, into dst.
   *out_length (optional) receives the length without the NUL, on success and when dst is too
   small. Call with dst = NULL and dst_size = 0 to ask for the length. Errors:
   INVALID_ARGUMENT (unknown id; dst NULL with out_length NULL or dst_size > 0), SIZE_MISMATCH
   (dst_size <= length: nothing written). Pure, thread-safe, no allocation. Cost: O(length). */
RAD_API rad_result rad_glsl_source(rad_glsl_id id, char *dst, size_t dst_size, size_t *out_length);

/* ======================================================================================== */
/* >>api_multibounce: multi-bounce matrix and its compression                               */
/* ======================================================================================== */

/* docs/methods/multibounce.md (Shcherbakov 2025, ch. 3). The albedo and K bounces folded into one RGB matrix,
       F_mb = sum_{k=1..K} (rho o F)^k        (K = inf: (I - rho o F)^-1 - I)
   so that L_K = F_mb E costs one matrix-vector product whatever K is. Limits: the albedo is
   baked in (changing a material means rebuilding) and K is fixed at build time.
   Storage: three N x N planes (R, G, B), row-major, float or IEEE binary16. Optional row and
   column permutations: plane entry (i', j') is F_mb[row_perm[i']][col_perm[j']].
   Compression (rad_multibounce_blocks_*): outliers kept exactly in a sparse list, greedy
   row/column reordering (the greedy chain of Shcherbakov 2025, optionally refined: rad_block_options.reorder), scaling into [0,1] per matrix or per tile, and
   GPU block encoding, bit-exact with the Khronos Data Format specification: BC1 (one RGB
   texture) or three BC4 planes. Texel (x, y) of the matrix image is entry (row y, column x) of
   the permuted matrix; 4x4 blocks, block (bx, by) at byte 8 * (ceil(N/4) * by + bx); the image
   is padded to a multiple of 4 with zeros. The bytes upload unchanged as
   VK_FORMAT_BC1_RGB_UNORM_BLOCK / VK_FORMAT_BC4_UNORM_BLOCK images of ceil(N/4)*4 texels square. */

#define RAD_MB_INFINITE 0xFFFFFFFFu   /* rad_multibounce_options.bounces: K = infinity */

/* Container section types of the multi-bounce objects (16..31 are reserved for them). */
#define RAD_SECTION_MB_INFO 16u            /* 16 uint32: see rad_multibounce_sections */
#define RAD_SECTION_MB_FLOAT 17u           /* 3 N^2 floats: the R, G, B planes */
#define RAD_SECTION_MB_HALF 18u            /* 3 N^2 binary16 values */
#define RAD_SECTION_MB_ROW_PERM 19u        /* N uint32 */
#define RAD_SECTION_MB_COL_PERM 20u        /* N uint32 */
#define RAD_SECTION_MB_BC1 21u             /* ceil(N/4)^2 8-byte BC1 blocks */
#define RAD_SECTION_MB_BC4 22u             /* 3 ceil(N/4)^2 8-byte BC4 blocks: R plane, G, B */
#define RAD_SECTION_MB_SCALES 23u          /* 3 floats (R, G, B) per scale tile */
#define RAD_SECTION_MB_OUTLIER_OFFSETS 24u /* N+1 uint64, CSR by original row */
#define RAD_SECTION_MB_OUTLIER_COLUMNS 25u /* uint32 original columns */
#define RAD_SECTION_MB_OUTLIER_VALUES 26u  /* 3 floats (exact RGB) per outlier */
#define RAD_MB_MAX_SECTIONS 10u            /* most sections one object writes */

typedef enum rad_mb_precision { RAD_MB_FLOAT = 0, RAD_MB_HALF = 1 } rad_mb_precision;

typedef struct rad_multibounce_options {
    uint32_t bounces;          /* K >= 1, or RAD_MB_INFINITE (default 3; 0 is INVALID_ARGUMENT:
                                  start from rad_multibounce_options_default) */
    rad_mb_precision precision;/* storage of the result (default RAD_MB_FLOAT) */
    double tolerance;          /* K = inf: Neumann doubling stops once max row sum of
                                  (rho o F)^m <= tolerance (0: 1e-8) */
    uint32_t max_doublings;    /* K = inf: NOT_CONVERGED after this many (0: 40) */
} rad_multibounce_options;

/* An owning multi-bounce matrix (or, after rad_multibounce_load, a view into container bytes). */
typedef struct rad_multibounce {
    uint32_t n;                /* N */
    uint32_t bounces;          /* K (RAD_MB_INFINITE for the full solution) */
    rad_mb_precision precision;
    const float *planes;       /* RAD_MB_FLOAT: 3 N^2 floats, plane c at c * N^2; else NULL */
    const uint16_t *half;      /* RAD_MB_HALF: 3 N^2 binary16 values; else NULL */
    const uint32_t *row_perm;  /* NULL (identity) or N indices: new row i' is old row row_perm[i'] */
    const uint32_t *col_perm;  /* NULL (identity) or N indices: new column j' is old column col_perm[j'] */
    rad_allocator allocator;   /* private */
    void *storage;             /* private (NULL for a view) */
    uint32_t info[16];         /* private: the RAD_SECTION_MB_INFO record */
} rad_multibounce;

RAD_API void rad_multibounce_options_default(rad_multibounce_options *options);

/* Builds F_mb from a form-factor matrix F (N x N, dense or CSR; borrowed) and the albedo
   (3N floats, each in [0,1); borrowed). Finite K uses the doubling S_2m = S_m + A^m S_m,
   A^2m = A^m A^m and S_m+1 = A + A S_m along the binary digits of K (K = 3: 2 products, K = 8: 5;
   K = 1: none), K = inf doubles until the tail is below the tolerance; each product is a
   packed, cache-blocked single-precision GEMM run through ctx->parallel_for (bits depend on the
   build's SIMD, not on the number of threads). Progress is reported after each product.
   Errors: INVALID_ARGUMENT, SIZE_MISMATCH, ALBEDO_RANGE, SIZE_OVERFLOW, OUT_OF_MEMORY,
   NOT_CONVERGED (K = inf), CANCELLED. Thread safety: reentrant. Cost: O(N^3 log K) time per
   channel, 16 N^2 bytes of scratch plus the 12 N^2 (6 N^2 half) bytes of the result. docs/methods/multibounce.md. */
RAD_API rad_result rad_multibounce_create(const rad_matrix *F, const float *albedo,
                                          const rad_multibounce_options *options, const rad_context *ctx,
                                          rad_multibounce **out);
/* A copy of 'src' in another precision (float -> half rounds to nearest even; half -> float
   is exact), keeping its permutations. Cost: O(N^2). */
RAD_API rad_result rad_multibounce_convert(const rad_multibounce *src, rad_mb_precision precision,
                                           const rad_context *ctx, rad_multibounce **out);
/* A copy of 'src' with rows and columns reordered greedily (docs/methods/compression.md, see
   rad_block_options.reorder_samples; always RAD_REORDER_GREEDY); only for an unpermuted src. Cost: O(N^3) exact,
   O(N^2 samples) sampled. */
RAD_API rad_result rad_multibounce_reorder(const rad_multibounce *src, uint32_t samples, const rad_context *ctx,
                                           rad_multibounce **out);
RAD_API void rad_multibounce_destroy(rad_multibounce *mb);

/* out = F_mb E (RAD_OUTPUT_INDIRECT: L_K) or E + F_mb E (RAD_OUTPUT_TOTAL), E and out 3N
   interleaved RGB floats in the original patch order (permutations are applied inside). One
   pass over the three planes, parallel over rows; half planes are widened on the fly (F16C
   when the build has it). out must not alias E. Thread safety: reentrant (mb is read only).
   Cost: O(N^2), 12 N^2 (6 N^2) bytes read. docs/methods/multibounce.md. */
RAD_API rad_result rad_multibounce_apply(const rad_multibounce *mb, const float *E, float *out, rad_output output,
                                         const rad_context *ctx);

/* IEEE 754 binary16 conversion: round to nearest, ties to even; overflow gives infinity,
   subnormals are kept, NaN stays NaN. */
RAD_API uint16_t rad_half_from_float(float value);
RAD_API float rad_half_to_float(uint16_t value);

/* ---- block compression ---- */

typedef enum rad_block_format {
    RAD_BLOCK_BC1 = 0,         /* one BC1 texture: RGB565 endpoints, 0.5 byte per entry (all 3 channels) */
    RAD_BLOCK_BC4X3 = 1        /* three BC4 textures (R, G, B): 8-bit endpoints, 1.5 bytes per entry */
} rad_block_format;

#define RAD_REORDER_NONE 0        /* rad_block_options.reorder: keep the patch order */
#define RAD_REORDER_GREEDY 1      /* greedy nearest-neighbour chain (Shcherbakov 2025) */
#define RAD_REORDER_GREEDY_2OPT 2 /* the greedy chain, then 2-opt reversals that shorten it */
#define RAD_REORDER_GROUPS 3      /* 2-opt chain, then swaps between the groups of four rows
                                     (columns) that make each 4x4 block's rows more alike */
#define RAD_REORDER_MATCH 4       /* groups of four by greedy matching (rows into pairs, pairs
                                     into fours) on the same distance, then the group swaps */

/* Start from rad_block_options_default: here zero is a setting, not the default (a zeroed
   struct asks for BC1, no outliers, no reordering and one scale per channel). */
typedef struct rad_block_options {
    rad_block_format format;   /* default RAD_BLOCK_BC4X3 (0 is RAD_BLOCK_BC1) */
    float outlier_fraction;    /* the largest fraction p of the N^2 entries (by their largest
                                  channel) go exactly into the sparse list, zeros left in place;
                                  0 disables the step (default 0.05) */
    int reorder;               /* row and column reordering: RAD_REORDER_NONE (0),
                                  RAD_REORDER_GREEDY (1, Shcherbakov 2025),
                                  RAD_REORDER_GREEDY_2OPT (2), RAD_REORDER_GROUPS (3: 12-30%
                                  lower MSE than GREEDY on the Cornell F_mb with 1-5%
                                  outliers) or RAD_REORDER_MATCH (4, the default: a further
                                  3% (BC1) / 6% (3xBC4) lower than GROUPS at N = 1850 for
                                  the same build time; see BENCHMARKS.md) */
    uint32_t reorder_samples;  /* 0: L2 distances over all coordinates (the literal algorithm,
                                  through a Gram matrix); else over this many evenly spaced
                                  coordinates (faster, a little worse; default 0) */
    uint32_t tile;             /* scales per tile x tile texels (a multiple of 4); 0: one scale
                                  per channel for the whole matrix (default 64) */
} rad_block_options;

/* What rad_multibounce_blocks_create did, step by step. */
typedef struct rad_block_report {
    uint64_t outlier_count;
    float outlier_threshold;   /* smallest magnitude that went to the outlier list */
    int reordered;
    uint32_t tiles;            /* scale tiles (1 when per matrix) */
    size_t bytes_float_f;      /* the single-channel float F: 4 N^2 */
    size_t bytes_float_mb;     /* the RGB float F_mb: 12 N^2 */
    size_t bytes_blocks, bytes_scales, bytes_outliers, bytes_permutations;
    size_t bytes_total;        /* everything rad_multibounce_blocks_apply reads */
    double mse;                /* mean squared error of the decoded matrix against the source, over 3 N^2 entries */
    double max_abs_error;
    double source_mean_square; /* mean of the squared source entries (to put mse in scale) */
} rad_block_report;

/* A compressed multi-bounce matrix; all arrays owned (or views after _load). */
typedef struct rad_multibounce_blocks {
    uint32_t n, bounces;
    rad_block_format format;
    uint32_t blocks_per_row;         /* ceil(N/4): the image is blocks_per_row*4 texels square */
    const uint8_t *blocks;           /* BC1: blocks_per_row^2 blocks; BC4X3: three such planes (R, G, B) */
    uint32_t tile;                   /* scale tile in texels (0: per matrix) */
    uint32_t tiles_per_row;          /* ceil(N / tile), 1 when per matrix */
    const float *scales;             /* 3 floats per tile, tiles row-major: decoded * scale = value */
    const uint32_t *row_perm;        /* NULL or N: texel row y holds original row row_perm[y] */
    const uint32_t *col_perm;        /* NULL or N: texel column x holds original column col_perm[x] */
    uint64_t outlier_count;
    const uint64_t *outlier_offsets; /* N+1, CSR by original row (NULL when there are none) */
    const uint32_t *outlier_columns; /* original columns */
    const float *outlier_values;     /* 3 floats (exact RGB) per outlier */
    rad_allocator allocator;         /* private */
    void *storage;                   /* private */
    uint32_t info[16];               /* private */
} rad_multibounce_blocks;

RAD_API void rad_block_options_default(rad_block_options *options);

/* Compresses mb (float or half, unpermuted) by the pipeline of rad_block_options; report
   (optional) says what each step did and the decoded-matrix error. Errors: INVALID_ARGUMENT,
   OUT_OF_MEMORY, SIZE_OVERFLOW, CANCELLED. Thread safety: reentrant. Cost: O(N^2 log N) for
   the outliers, O(N^3) for exact reordering (two Gram matrices) or O(N^2 samples), plus
   O(N^2) per 2-opt / group-swap pass (at most 64 passes each) or per matching round (a few),
   O(N^2) encoding. Scratch at the peak about 40 N^2 bytes with exact distances (working
   planes, the coordinates twice and a Gram matrix). Deterministic: the same bytes whatever
   the number of threads. docs/methods/compression.md. */
RAD_API rad_result rad_multibounce_blocks_create(const rad_multibounce *mb, const rad_block_options *options,
                                                 const rad_context *ctx, rad_multibounce_blocks **out,
                                                 rad_block_report *report);
RAD_API void rad_multibounce_blocks_destroy(rad_multibounce_blocks *blocks);

/* out = F~ E (or E + F~ E) with F~ the compressed matrix: E is permuted on input, blocks are
   used on the fly block row by block row (never the whole matrix), the outliers added
   exactly and the result un-permuted on output. 3xBC4: every entry used equals the value of
   rad_bc4_decode_block times its scale, on the scalar path (RAD_NO_SIMD) and the AVX2 one
   (branch-free palettes, divisions by FMA-corrected reciprocals) alike; only the order of
   the float sums differs. BC1 is a lookup-table product that never forms the palette: per
   block column and row byte (4 texels' indices) two endpoint weights per channel and mode
   (the palette is linear in the endpoints), built once per apply (12 KiB per block column),
   then per block and row one multiply-add of the endpoints with the row byte's entry; its
   entries equal rad_bc1_decode_block's within a few float roundings (1e-6 relative, tested).
   Parallel over block rows (BC1: and over block columns for the tables). Thread safety:
   reentrant. Cost: O(N^2) work (on the CPU about as many multiply-adds as a dense float
   apply: compute-bound, see BENCHMARKS.md), bytes_total bytes read; BC1 also writes and
   reads 3072 N bytes of tables (scratch memory). docs/methods/compression.md. */
RAD_API rad_result rad_multibounce_blocks_apply(const rad_multibounce_blocks *blocks, const float *E, float *out,
                                                rad_output output, const rad_context *ctx);
/* The decoded matrix in the original order (3 N^2 floats: R, G, B planes) with outliers, for
   tests and error measurements. Cost: O(N^2). */
RAD_API rad_result rad_multibounce_blocks_decode(const rad_multibounce_blocks *blocks, float *out_planes,
                                                 const rad_context *ctx);

/* Single 4x4 blocks, texel (x, y) at index 4y + x. Decoders follow the specification's real
   division (Khronos Data Format specification), rounded once: every palette value is an integer numerator over an
   integer denominator (e.g. (2 c0 + c1) / 93 for a 5-bit BC1 channel), one correctly rounded
   float division, so no compiler contraction changes it. BC1 writes 16 RGB triples (48
   floats), BC4 16 values. The encoders
   clamp their input to [0,1] and choose the better of the two modes of the format by squared
   error against the exact decoder. Thread safety: pure functions. */
RAD_API void rad_bc1_decode_block(const uint8_t block[8], float out_rgb[48]);
RAD_API void rad_bc4_decode_block(const uint8_t block[8], float out_values[16]);
RAD_API void rad_bc1_encode_block(const float rgb[48], uint8_t out_block[8]);
RAD_API void rad_bc4_encode_block(const float values[16], uint8_t out_block[8]);

/* ---- baked data ---- */

/* Section descriptors (data borrowed from the object, which must outlive the write) for
   rad_container_size / rad_container_write; every section carries 'name' (at most 23 bytes),
   so several matrices can share a container. out_sections must hold RAD_MB_MAX_SECTIONS;
   *out_count receives how many were written. The info record (RAD_SECTION_MB_INFO, 16 uint32):
   version 1, kind (0 float, 1 half, 2 BC1, 3 BC4X3), N, K, tile, tiles_per_row, flags (1: row
   and column permutations present, 2: outliers present), the rest 0. */
RAD_API rad_result rad_multibounce_sections(const rad_multibounce *mb, const char *name, rad_section *out_sections,
                                            uint32_t *out_count);
RAD_API rad_result rad_multibounce_blocks_sections(const rad_multibounce_blocks *blocks, const char *name,
                                                   rad_section *out_sections, uint32_t *out_count);
/* Opens the object called 'name' from an open container as a view: its arrays point into the
   container's bytes (which must outlive it); destroy it with the usual destroy call. Every
   size is checked against N, permutations must be bijections of [0, N), outlier offsets
   monotone and columns < N; every value (F_mb entries, float or half, scales, outliers)
   finite, >= 0 and at most RAD_BAKE_VALUE_MAX (>>api_container VALUES). Errors: CORRUPT (a
   missing or malformed section, a bad permutation, a negative or too large value),
   NON_FINITE (NaN or infinity; the logger names the section, entry and value),
   INDEX_OUT_OF_RANGE (an outlier column >= N), OUT_OF_MEMORY, INVALID_ARGUMENT. Cost: O(N^2)
   for the float and half planes, O(N^2 / 16 + outliers) for blocks, once. */
RAD_API rad_result rad_multibounce_load(const rad_container *container, const char *name, const rad_context *ctx,
                                        rad_multibounce **out);
RAD_API rad_result rad_multibounce_blocks_load(const rad_container *container, const char *name,
                                               const rad_context *ctx, rad_multibounce_blocks **out);

/* ======================================================================================== */
/* >>api_local: local multi-bounce matrix for large scenes                                  */
/* ======================================================================================== */

/* docs/methods/local.md (Shcherbakov 2025, ch. 4). An open world does not fit an N x N matrix, so only a set S of at
   most M patches (the ones nearest the camera, or any set the caller chooses) carries the
   multi-bounce transport
       T = sum_{k>=1} A^k = (I - A)^-1 - I,      A = rho o F restricted to S   (per channel)
   kept as three M x M float planes (R, G, B) indexed by slot. The global form factors stay
   in RAM or on disk and are read one sparse row at a time through a rad_row_source; columns
   come from reciprocity, F_jn = A_n F_nj / A_j.
   - Adding patch n (row r_j = F_nj, column c_j = F_jn, j in S): a = rho_S o c, b = rho_n r,
     u = (I + T) a, v = b (I + T), s = 1 - A_nn - b . u. Exact (Sherman-Morrison, default):
     T_SS += u v / s, T_Sn = u / s, T_nS = v / s, T_nn = 1/s - 1. u, v and s are accumulated
     in double (u and v only over the slots where the new row is non-zero); T is stored and
     updated in float (one vectorised pass). Cost O(M^2) per patch. Measured drift against a
     direct inverse: 7e-7 relative after 260 adds (tests), 4e-6 after 4096 (bench/local.c).
   - The update of Shcherbakov 2025 (RAD_LOCAL_FIRST_ORDER) in this library's convention (the receiving
     row carries the albedo): d = b . a (the "double reflection": light leaving n, reflected
     once by S, back on n); the row and column are scaled by (1 + d) instead of 1/s, and the
     old matrix gets the product of the two: T_Sn = (1+d) u, T_nS = (1+d) v,
     T_SS += (1+d)^2 u v, T_nn = d. It ignores the return paths through T and the higher
     powers of d; the tests measure how far it lands from the exact form.
   - Removing a patch takes it out of the displayed set but not out of the system (it stays
     in the world and only stops being drawn): it becomes a hidden member,
     skipped by rad_local_apply's default row and column sets, and the light paths through it
     stay in T exactly. Its slot is reused when an add finds the set full: the hidden member
     hidden longest ago is then evicted. Eviction (also callable directly) is, by default, the
     exact Sherman-Morrison downdate, T_ij -= T_ik T_kj / (1 + T_kk) for slot k, so T is at all
     times exactly (I - A)^-1 - I over the members, visible and hidden: bounded by the
     physical limit, row sums below rho_max / (1 - rho_max). Adding a hidden patch again only
     shows it (O(1)). RAD_LOCAL_EVICT_DROP is the literal removal of Shcherbakov 2025: the row and column
     are dropped and the paths through the patch stay in T; but if that patch re-enters, its
     new row and column count those paths a second time, and a camera moving back and forth
     makes T grow without bound (measured in tests/test_local.c: on the 260-patch Cornell box
     the largest row sum passes the bound at the 13th round trip and s <= 0 at the 25th).
     An add into a full set fuses the downdate of the evicted member with its own update:
     with c = T[:, e], r = T[e, :], g = 1 + T_ee, u = a + T a - c (r.a) / g,
     v = b + b T - (b.c) r / g, and one rank-2 pass T += -c r / g + u v / s.
   - Apply: L_i = sum_{j in P_Lit} T_ij E_j for i in P_Vis (Shcherbakov 2025, ch. 4).
   - Rebuild (the comparison for the update cost): T of a whole set from scratch, by a
     blocked Gauss-Jordan inverse (default) or the K = infinity multi-bounce build. */

/* The sparse rows of the global form-factor matrix. fetch writes row 'row' of F (F_row,j for
   every j with a non-zero entry: at most 'capacity' = n entries, any order, each column once;
   rad_local refuses a repeat with CORRUPT) into out_columns / out_values and the entry count
   into *out_count, and returns RAD_SUCCESS or an error the library passes on. It is called from the calling thread only (a streamed
   reader needs no lock). areas (n) and albedo (3n, each channel in [0,1)) are borrowed. */
typedef rad_result (*rad_row_fetch_fn)(void *user, uint32_t row, uint32_t capacity, uint32_t *out_columns,
                                       float *out_values, uint32_t *out_count);

typedef struct rad_row_source {
    uint32_t n;                /* patches in the world */
    const float *areas;        /* n patch areas (reciprocity) */
    const float *albedo;       /* 3n albedos */
    rad_row_fetch_fn fetch;
    void *user;
} rad_row_source;

/* A row source over a form-factor matrix in memory (dense or CSR, n x n; borrowed, as are
   areas and albedo: they must outlive the source). With a rad_bake opened in place over a
   memory-mapped file (rad_load_memory on the mapping), opening reads the file once (it
   checks every section's checksum); after that the system may drop the pages and rows are
   paged in as they are read. rad_row_stream_open never reads the matrix whole. Errors: INVALID_ARGUMENT, SIZE_MISMATCH
   (not square). Cost O(1); a fetch costs O(row entries) (O(n) for a dense matrix). */
RAD_API rad_result rad_row_source_matrix(const rad_matrix *F, const float *areas, const float *albedo,
                                         rad_row_source *out);
/* The same over a loaded bake's matrix, areas and albedo. Errors: INVALID_ARGUMENT (no bake
   or a bake without a matrix). */
RAD_API rad_result rad_row_source_bake(const rad_bake *bake, rad_row_source *out);
#ifndef RAD_NO_STDIO
/* Rows streamed from a container file saved by rad_save_file / rad_save_memory with a CSR
   matrix: the header, the section table, the patches (areas and albedos kept: 16 bytes per
   patch) and the row offsets (8 bytes per patch) are read and checked when it opens (magic,
   version, checksums of the header, the table, the patches and the offsets; monotone
   offsets that end at the column and value counts); each fetch then reads one row's columns
   and values with two seeks and two reads, so the matrix is never in memory. The matrix
   sections' checksums are not verified (that would read them whole): every fetched row is
   checked instead (strictly ascending columns < N, finite values >= 0; CORRUPT otherwise,
   logged through the context given here).
   Errors: IO (the file cannot be opened or read), TRUNCATED, CORRUPT, VERSION, ALBEDO_RANGE,
   INVALID_ARGUMENT (no CSR matrix in the file), OUT_OF_MEMORY. Thread safety: one stream per
   thread (fetches move the file position). Seeks go through fseek, so where long is 32 bits
   a row beyond 2 GiB into the file fails with IO. */
typedef struct rad_row_stream rad_row_stream;
RAD_API rad_result rad_row_stream_open(const char *path, const rad_context *ctx, rad_row_stream **out);
/* Fills a row source that reads through 'stream' (which must outlive it). */
RAD_API void rad_row_stream_source(rad_row_stream *stream, rad_row_source *out);
/* Bytes the stream holds in memory (areas, albedos, row offsets). */
RAD_API size_t rad_row_stream_memory(const rad_row_stream *stream);
RAD_API void rad_row_stream_close(rad_row_stream *stream);
#endif

typedef enum rad_local_update {
    RAD_LOCAL_EXACT = 0,       /* Sherman-Morrison: T is (I - A)^-1 - I of the set (default) */
    RAD_LOCAL_FIRST_ORDER = 1  /* Shcherbakov 2025's formulas (see above) */
} rad_local_update;

typedef enum rad_local_eviction {
    RAD_LOCAL_EVICT_DOWNDATE = 0, /* exact downdate: paths through the evicted patch leave T (default) */
    RAD_LOCAL_EVICT_DROP = 1      /* Shcherbakov 2025's form: drop the row and column, keep the paths (see above) */
} rad_local_eviction;

typedef enum rad_local_rebuild_method {
    RAD_LOCAL_REBUILD_INVERSE = 0, /* blocked Gauss-Jordan inverse of I - A: 2 M^3 flops per channel (default) */
    RAD_LOCAL_REBUILD_NEUMANN = 1  /* the K = infinity multi-bounce build (rad_multibounce_create):
                                      Neumann doubling, about 2 log2(K) GEMMs */
} rad_local_rebuild_method;

typedef struct rad_local_options {
    uint32_t capacity;         /* M, the most members (visible and hidden) the set holds (default
                                  1024; 0 is INVALID_ARGUMENT: start from rad_local_options_default) */
    rad_local_update update;   /* default RAD_LOCAL_EXACT */
    rad_local_eviction evict;  /* default RAD_LOCAL_EVICT_DOWNDATE */
    rad_local_rebuild_method rebuild; /* default RAD_LOCAL_REBUILD_INVERSE */
} rad_local_options;

/* A local multi-bounce matrix. Everything public is read-only. Slot s holds patch
   slot_patch[s] (RAD_NONE when free), hidden when slot_hidden[s] is 1; patch_slot[p] is the
   slot of world patch p (RAD_NONE when p is not a member). planes: plane c (R, G, B) starts at c * capacity^2, row-major,
   row = receiving slot, stride capacity; rows and columns of free slots are zero. */
typedef struct rad_local {
    uint32_t capacity;         /* M */
    uint32_t count;            /* visible members */
    uint32_t hidden;           /* hidden members (removed, not yet evicted) */
    uint32_t slot_end;         /* one past the highest slot in use (loops stop there) */
    uint32_t n;                /* patches in the world */
    rad_local_update update;
    rad_local_eviction evict;
    rad_local_rebuild_method rebuild;
    const uint32_t *slot_patch;
    const uint8_t *slot_hidden;
    const uint32_t *patch_slot;
    const float *planes;
    uint64_t adds, removes, evictions; /* statistics */
    rad_row_source source;     /* private: a copy of the caller's table */
    rad_allocator allocator;   /* private */
    void *storage;             /* private */
    void *scratch;             /* private */
} rad_local;

RAD_API void rad_local_options_default(rad_local_options *options);

/* Creates an empty set of capacity M over 'source' (copied; what it points to is borrowed
   and must outlive the object). Memory: 12 M^2 bytes of planes, 4 n bytes for patch_slot,
   O(n + tasks M) bytes of scratch. Errors: INVALID_ARGUMENT (NULL, capacity 0 or > n, bad
   update kind, a source without fetch, areas or albedo), ALBEDO_RANGE, SIZE_OVERFLOW,
   OUT_OF_MEMORY. Cost: O(M^2 + n). */
RAD_API rad_result rad_local_create(const rad_row_source *source, const rad_local_options *options,
                                    const rad_context *ctx, rad_local **out);
RAD_API void rad_local_destroy(rad_local *local);

/* Adds world patch 'patch' to the set. A hidden member is only shown again (O(1)). Else one
   row fetch and the update of 'update' (see the section comment) into the lowest free slot;
   when the set is full, the member hidden longest ago is evicted into the same pass (exact
   downdate fused with the update) or dropped first (RAD_LOCAL_EVICT_DROP). Errors: INDEX_OUT_OF_RANGE (patch >= n), INVALID_ARGUMENT
   (already a visible member, or the set is full of visible members), RAYCAST_FAILED-like errors of
   the fetch are passed on unchanged, INDEX_OUT_OF_RANGE (a fetched column >= n),
   NON_FINITE (a fetched value is not finite or negative), SINGULAR (s <= 0: the rows
   break energy conservation). On error the set is unchanged, except that a hidden member
   may have been evicted to make room (only before a SINGULAR). Thread safety: not on the same
   object; uses ctx->parallel_for. Cost: O(slot_end^2) per channel. docs/methods/local.md. */
RAD_API rad_result rad_local_add(rad_local *local, uint32_t patch, const rad_context *ctx);
/* Removes 'patch' from the displayed set: it becomes a hidden member and the transport
   through it is kept (see the section comment). Errors: INDEX_OUT_OF_RANGE,
   INVALID_ARGUMENT (not a visible member). Cost: O(1). */
RAD_API rad_result rad_local_remove(rad_local *local, uint32_t patch, const rad_context *ctx);
/* Takes member 'patch' (visible or hidden) out of the system and frees its slot: the exact
   downdate (RAD_LOCAL_EVICT_DOWNDATE) or the drop of Shcherbakov 2025 (RAD_LOCAL_EVICT_DROP). Errors:
   INDEX_OUT_OF_RANGE, INVALID_ARGUMENT (not a member). Thread safety: not on the same object;
   uses ctx->parallel_for. Cost: O(slot_end^2) per channel (downdate), O(slot_end) (drop). */
RAD_API rad_result rad_local_evict(rad_local *local, uint32_t patch, const rad_context *ctx);
/* Replaces the set by 'patches' (count <= M, no repeats; all visible) and computes T from
   scratch: the rows are fetched, A = rho o F_S assembled densely and T = (I - A)^-1 - I
   computed by 'rebuild' of the options: a blocked Gauss-Jordan inverse in float (no
   pivoting: I - A is strictly diagonally dominant by rows), 64-wide pivot blocks, the
   trailing updates through the multi-bounce GEMM (2 count^3 flops per channel), or the
   K = infinity multi-bounce build. The reference an update is measured against. Errors:
   those of rad_local_add, SINGULAR (a pivot block that cannot be inverted), and of
   rad_multibounce_create. On error the set is empty. Cost: see the methods; 4 count^2 bytes
   of scratch (inverse) or 28 count^2 (Neumann). */
RAD_API rad_result rad_local_rebuild(rad_local *local, const uint32_t *patches, uint32_t count,
                                     const rad_context *ctx);
/* out_i = sum_{j in lit} T_ij E_j (RAD_OUTPUT_INDIRECT) or E_i + that (RAD_OUTPUT_TOTAL) for
   every i in 'visible'. E and out are 3n interleaved RGB floats indexed by world patch; only
   the visible patches' entries of out are written. visible / lit list world patches that
   are members (hidden ones allowed: a lit patch behind the camera still lights the scene);
   NULL means every visible member. Errors: INVALID_ARGUMENT, INDEX_OUT_OF_RANGE (a
   patch >= n or not in the set), NON_FINITE (E not finite or the result overflows). Thread
   safety: reentrant (local is read only). Cost: O(|visible| slot_end). docs/methods/local.md. */
RAD_API rad_result rad_local_apply(const rad_local *local, const float *E, const uint32_t *visible,
                                   uint32_t visible_count, const uint32_t *lit, uint32_t lit_count,
                                   rad_output output, float *out, const rad_context *ctx);
/* Bytes the object holds (planes, maps and scratch). */
RAD_API size_t rad_local_memory(const rad_local *local);

/* ---- choosing the sets ---- */

/* The 'count' patches whose centroids are nearest 'position' (count <= patches->count),
   nearest first, ties by index, into out_patches. Works on a loaded bake's patches.
   Errors: INVALID_ARGUMENT, NON_FINITE (position), OUT_OF_MEMORY. Thread safety: reentrant.
   Cost: O(n log n), 8n bytes of scratch. docs/methods/local.md. */
RAD_API rad_result rad_local_nearest(const rad_patches *patches, const float position[3], uint32_t count,
                                     uint32_t *out_patches, const rad_context *ctx);
/* P_Vis: the candidates that 'camera' (aspect = width / height) can see. A patch is visible
   when its front faces the camera and one of four points on it (the centroid and the
   midpoints between the centroid and each vertex) lies inside the view frustum with the
   segment to the camera unoccluded (one occlusion ray per point inside the frustum, through
   'raycaster', origin pushed off the surface by 1e-4 of the distance). out_visible (at
   least count entries) receives the visible candidates in their input order, *out_count
   how many. A patch seen only between the four points is missed (the test is conservative
   for small patches, not for large ones). Errors: INVALID_ARGUMENT, NON_FINITE (camera),
   INDEX_OUT_OF_RANGE (a candidate >= patches->count), RAYCAST_FAILED (the callback's error),
   OUT_OF_MEMORY. Thread safety: reentrant. Cost: at most 4 rays per candidate, one batch. */
RAD_API rad_result rad_local_visible(const rad_patches *patches, const rad_raycaster *raycaster,
                                     const rad_camera *camera, float aspect, const uint32_t *candidates,
                                     uint32_t count, uint32_t *out_visible, uint32_t *out_count,
                                     const rad_context *ctx);
/* P_Lit: the candidates whose source E (3n floats indexed by world patch) exceeds
   'threshold' (>= 0) in some channel, in input order. Errors: INVALID_ARGUMENT (NULL, a
   negative or non-finite threshold). Cost: O(count). */
RAD_API rad_result rad_local_lit(const float *E, const uint32_t *candidates, uint32_t count, float threshold,
                                 uint32_t *out_lit, uint32_t *out_count);

/* ======================================================================================== */
/* >>api_temporal: temporal radiosity                                                       */
/* ======================================================================================== */

/* Temporal radiosity (docs/methods/temporal.md; Shcherbakov 2025, ch. 6; Shcherbakov et al.
   2023, sec. 3.2 and 4) spreads the O(N^2) gather
   L = G E over frames at O(N k) per frame: each row G_i of a non-negative matrix (a row of F,
   or one channel of the multi-bounce matrix F_mb) is read as a probability distribution over
   its non-zero entries plus the ENVIRONMENT ENTRY G_i0 = max(0, 1 - S_i) (S_i = the row sum,
   accumulated in double), whose value is the sky/ambient radiosity E_0. With
   T_i = S_i + G_i0 (1 when S_i <= 1, S_i when the row sums to more than 1),
   sum_{j=0..N} G_ij E_j = T_i * Expectation[E_J], J drawn with probability G_ij / T_i.
   Every frame draws k indices J per row from an alias table, forms X_i = T_i * mean(E_J)
   (times rho_i when G = F) and blends B_i = w B_i^prev + (1 - w) X_i.

   ALIAS TABLES. One table per row over the row's entries with value > 0, in ascending column
   order, followed by the environment entry when G_i0 > 0; a row always has at least one bin
   (an all-zero row has only the environment entry, T_i = 1). Built by Vose's O(n) method,
   robust variant (Vose 1991): q_b = n w_b / W with W accumulated in double; worklists
   Small (q < 1) and Large (q >= 1) kept as stacks in ascending bin order; while both are
   non-empty pop l from Small and g from Large, prob[l] = q_l, alias[l] = g,
   q_g = (q_g + q_l) - 1, push g on Small if q_g < 1 else on Large; bins left in either list
   get prob = 1 and alias = themselves. The probability becomes the 32-bit integer
   threshold = min(floor(prob * 2^32 + 0.5), 2^32 - 1) (computed in double).

   Column indices name patches 0..cols-1; the index 'cols' (== N) names the environment, so a
   shader can append E_0 as element N of the sampled vector and never branch.

   Two layouts of a bin (rad_alias_tables.format):
     RAD_ALIAS_COMPACT (2 uint32 words, 8 bytes; needs cols <= 65535):
        word0 = threshold, word1 = column | (alias_column << 16)
     RAD_ALIAS_WIDE    (3 uint32 words, 12 bytes; any cols < 2^32 - 1):
        word0 = threshold, word1 = column, word2 = alias_column
   where 'column' is the bin's own column and 'alias_column' the column of its alias bin
   (equal to 'column' when prob = 1), so a draw reads exactly one bin.

   THE RANDOM NUMBERS (exact; a GLSL kernel reproduces them bit for bit). All arithmetic is
   on uint32 with wrap-around (GLSL 'uint'):
       h(v):  s = v * 747796405u + 2891336453u;
              t = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
              return (t >> 22u) ^ t;                               (PCG-RXS-M-XS hash)
       key   = h(h(h(seed) ^ frame) ^ row)
       u1    = h(key ^ (sample * 0x9E3779B9u))
       u2    = h(u1 ^ 0x68E31DA4u)
   sample numbering: for table set c (c = 0 when one table serves every channel, else the
   channel 0..2) and draw s (0..k-1) of row 'row', sample = c * k + s.
   THE DRAW from a row with n bins starting at bin 'first':
       b      = high 32 bits of the 64-bit product (uint64)u1 * n     (GLSL: umulExtended)
       column = (u2 < threshold[first + b]) ? column[first + b] : alias_column[first + b]
   Test vectors (rad_temporal_random(seed, frame, row, sample) -> u1, u2):
       (0, 0, 0, 0)                    -> 0x8D324821, 0x5A5950DF
       (1, 2, 3, 4)                    -> 0xBE9148C4, 0xB2A7FCBE
       (0xDEADBEEF, 1000, 10421, 63)   -> 0xA62F1C1E, 0x399CE3D2
   (checked by tests/test_temporal.c; see rad_temporal_random.)

   THE STEP (rad_temporal_step), per row i, per channel set c, in this order and in float:
       acc = 0 (float, RGB); for s = 0..k-1: J = draw; acc += V_J   (V = the sampled vector)
       X_i = acc * (T_i / k)         (T_i / k computed in float)
       mode SINGLE, FEEDBACK: X_i *= rho_i (per channel)
       B_i = w_i * B_i^prev + (1 - w_i) * X_i
   V_j = E_j (SINGLE, MULTIBOUNCE) or E_j + B_j^prev (FEEDBACK), V_N = E_0. With one table set
   per channel (MULTIBOUNCE with 3 tables) channel c only accumulates its own component.
   The OUTPUT IS THE INDIRECT LIGHT (never E itself): add E for the total. */

#define RAD_SECTION_TEMPORAL_ROW_OFFSETS 32u /* alias tables: rows + 1 uint64, offsets in bins */
#define RAD_SECTION_TEMPORAL_BINS 33u        /* alias tables: the bins, 2 or 3 uint32 words each */
#define RAD_SECTION_TEMPORAL_TOTALS 34u      /* alias tables: T_i, one float per row */

typedef enum rad_alias_format {
    RAD_ALIAS_AUTO = 0,    /* compact when cols <= 65535, else wide (the builders' choice) */
    RAD_ALIAS_COMPACT = 2, /* 8 bytes per bin (value = words per bin) */
    RAD_ALIAS_WIDE = 3     /* 12 bytes per bin */
} rad_alias_format;

/* Alias tables for every row of an N x N matrix. Built by rad_alias_tables_* (owning: free
   with rad_alias_tables_destroy) or viewed from a container (rad_alias_tables_view). */
typedef struct rad_alias_tables {
    uint32_t rows, cols;           /* cols = N: the environment's column index */
    rad_alias_format format;       /* RAD_ALIAS_COMPACT or RAD_ALIAS_WIDE (never AUTO here) */
    const uint64_t *row_offsets;   /* rows + 1: row i's bins are [row_offsets[i], row_offsets[i+1]) */
    const uint32_t *bins;          /* row_offsets[rows] * format words */
    const float *totals;           /* T_i per row */
    uint64_t source_entries;       /* float entries of the source matrix (dense: rows*cols; CSR: nnz) */
    void *storage;                 /* private */
    rad_allocator allocator;       /* private */
} rad_alias_tables;

/* Tables for every row of F (dense or CSR). F is borrowed only during the call.
   Rows are built in parallel (ctx->parallel_for); the result does not depend on threads.
   Errors: INVALID_ARGUMENT (non-square F, a negative or non-finite entry: the logger names
   it), SIZE_OVERFLOW, OUT_OF_MEMORY, CANCELLED. Cost: O(nnz), two passes over F.
   Memory: 8 (compact) or 12 (wide) bytes per non-zero entry + 1 bin per row, 12 bytes per row.
   HUGE PAGES (Linux, unless RAD_NO_HUGEPAGES): a block of 4 MiB or more is allocated 2 MiB
   larger through the context's allocator, placed 2 MiB aligned inside it and advised
   madvise(MADV_HUGEPAGE) before it is written, so that transparent huge pages back it even
   in the kernel's 'madvise' mode: every draw of the step is a random read into the tables,
   and with 4 KiB pages most draws also miss the TLB (about 15% of the step's time at
   N = 10832, BENCHMARKS.md). A hint only: where the kernel declines, nothing changes.
   Thread safety: reentrant. docs/methods/temporal.md. */
RAD_API rad_result rad_alias_tables_create(const rad_matrix *F, rad_alias_format format, const rad_context *ctx,
                                           rad_alias_tables **out);

/* Tables for one channel of a dense N x N row-major float plane (for instance channel c of a
   multi-bounce matrix F_mb, whose rows may sum to more than 1: T_i then carries the sum).
   plane is borrowed only during the call. Same errors and cost as rad_alias_tables_create. */
RAD_API rad_result rad_alias_tables_create_dense(const float *plane, uint32_t n, rad_alias_format format,
                                                 const rad_context *ctx, rad_alias_tables **out);

RAD_API void rad_alias_tables_destroy(rad_alias_tables *tables);

/* Bytes the tables' bins, offsets and totals take. */
RAD_API size_t rad_alias_tables_memory(const rad_alias_tables *tables);

/* STREAMED ROWS (Shcherbakov et al. 2023, sec. 4): the table of one row built at run time into caller memory.
   columns: ascending column indices (< cols) of the 'count' values, or NULL when 'values' is
   a dense row of count == cols entries. Entries <= 0 are skipped, exactly as the whole-matrix
   builders do, so the bins are bit-identical to theirs. out_bins: room for count + 1 bins of
   'format' words (COMPACT needs cols <= 65535; AUTO is resolved from cols as above).
   scratch: rad_alias_row_scratch_size(count) bytes, 8-byte aligned. Writes the bin count to
   *out_bin_count and T_i to *out_total. Errors: INVALID_ARGUMENT (negative, non-finite, a
   column >= cols), SIZE_OVERFLOW. Cost: O(count). Thread safety: reentrant, no allocation. */
RAD_API size_t rad_alias_row_scratch_size(uint32_t count);
RAD_API rad_result rad_alias_build_row(const uint32_t *columns, const float *values, uint32_t count, uint32_t cols,
                                       rad_alias_format format, uint32_t *out_bins, uint32_t *out_bin_count,
                                       float *out_total, void *scratch);

/* The generator of the doc block above: writes u1 and u2 of (seed, frame, row, sample).
   Pure, 32-bit integer operations only. */
RAD_API void rad_temporal_random(uint32_t seed, uint32_t frame, uint32_t row, uint32_t sample, uint32_t out[2]);

/* One draw from n bins (in 'format' layout) with the random words u1, u2: the column
   (== cols for the environment). Pure. */
RAD_API uint32_t rad_alias_draw(const uint32_t *bins, uint32_t n, rad_alias_format format, uint32_t u1, uint32_t u2);

/* Sections for writing the tables into a container (rad_container_write), named 'name'
   (up to 23 characters; the three sections share it). Data borrowed from the tables. */
RAD_API void rad_alias_tables_sections(const rad_alias_tables *tables, const char *name, rad_section out[3]);

/* A non-owning view of tables stored in a container under 'name', validated once (offsets
   monotone, bin counts in [1, N + 1], columns and aliases <= cols, totals > 0 and at most
   RAD_BAKE_VALUE_MAX; the thresholds are probabilities in [0, 1] by their encoding). *out
   points into the container, which must outlive it; do not destroy a view.
   Errors: INVALID_ARGUMENT (missing sections), NON_FINITE (a NaN or infinite total),
   CORRUPT (anything else; the logger says which row and value). Cost: O(rows + bins). */
RAD_API rad_result rad_alias_tables_view(const rad_container *container, const char *name, const rad_context *ctx,
                                         rad_alias_tables *out);

typedef enum rad_temporal_mode {
    RAD_TEMPORAL_SINGLE = 0,     /* G = F, X_i times rho_i: one bounce of E (L_1) */
    RAD_TEMPORAL_FEEDBACK = 1,   /* G = F, samples E + B^prev: converges to L_inf (docs/methods/temporal.md) */
    RAD_TEMPORAL_MULTIBOUNCE = 2 /* G = a channel of F_mb (albedo already inside): no rho */
} rad_temporal_mode;

/* The most draws per row and frame rad_temporal_create accepts: the step costs k N draws, and
   beyond a few hundred the exact product (rad_matrix_multiply, N per row) is cheaper. */
#define RAD_TEMPORAL_MAX_SAMPLES 65536u

typedef struct rad_temporal_options {
    rad_temporal_mode mode;
    uint32_t samples;      /* k draws per row and frame (default 10; 1 to RAD_TEMPORAL_MAX_SAMPLES,
                              0 is INVALID_ARGUMENT: start from rad_temporal_options_default) */
    float weight;          /* fixed w in [0, 1) (default 0.998; 0 keeps no history) */
    uint32_t seed;         /* generator seed */
    int adaptive;          /* non-zero: per-row w from the estimator's variance (see below) */
    float noise_target;    /* adaptive: target relative std of B_i in steady state (default 0.01) */
    float weight_max;      /* adaptive: upper bound of w_i (default 0.999) */
    float change_sigma;    /* adaptive: change test threshold in standard deviations (default 5) */
} rad_temporal_options;

/* ADAPTIVE WEIGHT (the open problem stated by Shcherbakov et al. 2023). Per row, on the scalar x = sum of the
   channels of X_i, with c_i = frames since the row's (re)start:
     a = max(1/(c_i + 1), 1/64); m_i += a (x - m_i); v_i += a ((x - m_i)^2 - v_i)   (in float)
     steady weight: r = (target m_i)^2 / v_i; w_ss = (1 - r) / (1 + r) clamped to
       [0, weight_max] (w_ss = 0 when v_i = 0), because an exponential moving average of
       independent X has Var(B) = (1 - w)/(1 + w) Var(X);
     w_i = min(w_ss, c_i / (c_i + 1)): after a restart B is the plain mean of the samples so far.
   Change test (from the 5th frame after a restart): with sd_i = sqrt(v_i), d_i = EMA at rate
   1/4 of (x - b_i) clamped to [-3 sd_i, 3 sd_i] (b_i = the channel sum of B_i^prev; the clamp
   keeps single heavy-tailed samples from triggering it); the EMA of independent values has a
   standard deviation of sqrt(1/7) = 0.378 of theirs, so when |d_i| > change_sigma * 0.378 sd_i
   and |d_i| > target * |b_i| the row restarts (c_i = 0: it drops w for the next frames).
   rad_temporal_signal_change restarts every row at the next step. Made for lights that jump
   and then stay: a light that moves a little every frame seldom trips the test, so w_i climbs
   to weight_max and B lags (examples/moving_light.c, a light circling the box: 48.5% error
   against 15.3% with a fixed w = 0.8); for such motion cap weight_max (the lag is about
   1 / (1 - w) frames) or use a fixed weight. */
RAD_API void rad_temporal_options_default(rad_temporal_options *options);

typedef struct rad_temporal rad_temporal;

/* Temporal state for N = tables[0]->rows patches. tables: table_count (1, or 3 in
   MULTIBOUNCE mode: one per channel) borrowed tables, which must outlive the state; all of
   the same size N x N. albedo: 3N floats, borrowed, required for SINGLE and FEEDBACK, unused
   (may be NULL) for MULTIBOUNCE. B starts at 0. Errors: INVALID_ARGUMENT, SIZE_MISMATCH,
   OUT_OF_MEMORY. Thread safety: reentrant. Memory: O(N). docs/methods/temporal.md. */
RAD_API rad_result rad_temporal_create(const rad_alias_tables *const *tables, uint32_t table_count, const float *albedo,
                                       const rad_temporal_options *options, const rad_context *ctx,
                                       rad_temporal **out);
RAD_API void rad_temporal_destroy(rad_temporal *temporal);

/* B = 0, frame = 0, adaptive statistics cleared: as just created. */
RAD_API void rad_temporal_reset(rad_temporal *temporal);

/* Adaptive mode: E changed sharply (a light moved or switched); every row restarts at the
   next step. No effect with a fixed weight. */
RAD_API void rad_temporal_signal_change(rad_temporal *temporal);

/* One frame: E (3N floats, borrowed during the call), E0 (the sky/environment RGB value, NULL
   for 0). Advances the frame counter. Writes the new indirect light B (3N floats, never
   including E) to out_indirect when it is not NULL; rad_temporal_indirect returns it too.
   Parallel over rows through ctx->parallel_for; the bits do not depend on the thread count
   or task split (each row's draws depend only on seed, frame, row and sample).
   Errors: INVALID_ARGUMENT, NON_FINITE (E or E0 not finite, or B overflows float: the
   step is then undone). Cost: O(N k) random reads into the tables and E: the draws
   are software-pipelined (each task hashes and prefetches the bins of the draws 64 to 128
   ahead of the one it resolves, across rows; with AVX2 and compact tables 8 rows side by
   side, one per vector lane), so the misses overlap instead of waiting one by one
   (BENCHMARKS.md: about 3.7 ns per draw on one core with tables of 450 MB).
   Thread safety: one thread at a time per state. docs/methods/temporal.md. */
RAD_API rad_result rad_temporal_step(rad_temporal *temporal, const float *E, const float E0[3], float *out_indirect);

/* The current indirect light (3N floats, owned by the state, valid until the next step). */
RAD_API const float *rad_temporal_indirect(const rad_temporal *temporal);
/* Frames stepped since create or reset (the 'frame' of the generator for the next step). */
RAD_API uint32_t rad_temporal_frame(const rad_temporal *temporal);
/* Adaptive mode: the weights w_i the last step used (N floats), else NULL. */
RAD_API const float *rad_temporal_weights(const rad_temporal *temporal);

/* ======================================================================================== */
/* >>api_vp: virtual patches for high-polygon scenes                                        */
/* ======================================================================================== */

/* Virtual patches (docs/methods/virtual-patches.md, docs/methods/aavp.md; Shcherbakov 2025,
   ch. 5; Shcherbakov et al. 2023, sec. 3.1): a radiosity proxy with no geometry,
   built automatically from any mesh, so that a scene of 10^5-10^7 triangles is solved with
   about 10^4 unknowns. Axis-aligned (the default, the variant Shcherbakov et al. 2023 recommend) or
   general (clustered, below).
   BUILD (rad_vp_create):
     1. The scene bounds, widened by 0.4827 voxel on each side (walls on the bounds then lie
        near voxel centres, never on a voxel face nor in a thin sliver of a voxel whose few
        samples sit next to a perpendicular wall), are cut into voxels of size h = (hx, hy,
        hz). Candidate voxels are those a triangle's bounding box overlaps.
     2. On each of the 6 faces of a candidate voxel, 'face_points' Hammersley points
        ((s + 1/2)/P, radical inverse of s) cast a ray inward, perpendicular to the face and
        limited to the voxel. A hit is a SAMPLE: position, triangle t, the triangle's geometric
        normal, albedo (rad_scene_albedo at the hit, so textures go through the albedo
        callback). Voxels without a sample are dropped.
     3. Sample area s_i = S_t / (number of samples on triangle t).
     4. Each sample is split over the axes a = +x, -x, +y, -y, +z, -z with weights w_ia
        summing to 1 (rad_vp_weights), and per voxel and axis merged into one patch:
            A_a = sum_i w_ia s_i        c_a = sum_i w_ia s_i c_i / A_a       normal e_a
        A voxel axis without samples has no patch, so a voxel holds 1 to 6 patches.
        DEPARTURE (area correction): s_i = S_t / n_t counts only the triangles some face ray
        hit; on a mesh finer than the face-point spacing most triangles get no sample and the
        patches would hold a fraction of the surface (row sums far below 1). So every
        triangle is clipped to the voxels its bounds overlap, and per voxel and axis the
        weights w_ia of the voxel's samples are multiplied by (exact clipped area weighted by
        the triangles' split weights) / (sum_i w_ia s_i): A_a is then the exact surface area
        of that voxel and axis, and sample_weights holds the corrected weights.
     5. Form factors, never stored per sample: with the symmetric point-to-point kernel
            G_ij = s_i s_j cos_i cos_j / (pi max(|r|^2, max(e_i, e_j) / pi)) V(p_i, p_j)
        (rad_ff_point_point's kernel times s_i; the near-point clamp uses the larger of the two samples'
        areas after the area correction above, e_i = s_i sum_a w_ia, so it is symmetric and
        a pair of coincident samples transfers at most the smaller area), the exchanged
        energy P_ab = sum_i sum_j w_ia w_jb G_ij is accumulated in double, one row voxel at a
        time, over the pairs i < j (visibility: see VISIBILITY; rays always go from the lower
        sample index to the higher), mirrored
        (P_ba = P_ab) and divided: F_ab = P_ab / A_a. This is the axis merge of docs/methods/aavp.md (row
        F_a,j = sum_i w_ia s_i F_ij / A_a, column F_j,a = sum_i w_ia F_ji) applied to both
        indices, so A_a F_ab = A_b F_ba holds to float rounding.
     6. Row sums above 1 (the point kernel next to a tiny patch overshoots: rows up to 1.68
        in the bunny-and-ogre scene at 16 voxels) are scaled down without breaking
        reciprocity: with c_a = 1 / max(1, sum_b P_ab / A_a),
        F_ab = P_ab min(c_a, c_b) / A_a, so every row sums to at most 1 and every solver
        converges. In a closed box this lowers the mean row sum by about 1% (keep_row_sums
        turns it off).
   VISIBILITY. One shadow ray per sample pair costs M^2 / 2 rays (a bunny in the Cornell box
   at 47 000 samples: 7.8e8 rays, 157 s on 2 cores), so by default the kernel is summed over
   every sample pair but visibility is estimated per pair of voxels (u, v): 'visibility_rays'
   sample pairs are drawn with probability proportional to their kernel G_ij (stratified on
   the cumulative sum, offsets from a hash of u and v, so the result is deterministic), one
   shadow ray each, and the fraction unoccluded, V_uv, scales every P_ab with a in u and b in
   v. When a voxel pair has at most that many pairs, every pair gets its ray and V_uv is the
   kernel-weighted mean. V_uv is shared by both directions, so reciprocity is unchanged. The
   pair list of one voxel pair is thinned systematically beyond 16384 entries.
   MEMORY (peak, through ctx's allocator): the N x N float matrix, about 100 bytes per sample,
   T x (6 N doubles + 1024 rays + 16384 12-byte pair records) of task scratch (T = the
   context's task count, at most the voxel count), 4 bytes per triangle, 16 bytes per
   triangle-voxel overlap and 64 per candidate voxel, the face-ray hits of a chunk of
   candidate voxels (at most 2^21 hits, 32 MiB), and for clustering T x 8 (2 n kc + n^2 + 9 n)
   bytes (n: the most samples in one voxel, at most 6 face_points; kc: metric_columns).
   Nothing is O(samples^2).
   MEASURED (examples/vp_bunny.c, 2 shared cores, BENCHMARKS.md): the bunny in the Cornell box
   (69 463 triangles) at 24 voxels: 107 342 samples, 6 196 patches, 20 s, 212 MiB peak; the
   bunny and the ogre (193 471 triangles) at 30 voxels: 168 602 samples, 9 638 patches, 103 s,
   479 MiB; image SSIM against the path tracer 0.989 (classic radiosity on decimated copies
   with a similar patch count: 0.984 and 0.979).
   COST: O(M^2) kernel evaluations and up to M^2/2 shadow rays for M samples; M grows with the
   number of non-empty voxels times 6 face_points (times the hit rate).
   USE: rad_vp_system makes a rad_system for every classic solver (the matrix is dense
   row-major rad_matrix); rad_vp_sources gives the primary light E per patch; rad_vp_gather
   brings any per-patch value (B, L, the irradiance H = F (E + L)) back to surface points with
   normal weights and trilinear filtering that skips voxels without a patch facing the normal.
   GENERAL VIRTUAL PATCHES (kind RAD_VP_CLUSTERED, docs/methods/virtual-patches.md). Per voxel every sample
   starts as a cluster (area e_i = s_i times the voxel's area correction: exact clipped area /
   sum of s_i; colour, normal, form-factor row and column); the pair with the smallest
       M(a,b) = (1 + |c_a - c_b|) (2 - n_a . n_b) (1 + sqrt(sum_k (F_ak - F_bk)^2 + (F_ka - F_kb)^2))
   is merged (row: area-weighted mean, column: sum, colour: area-weighted mean, normal: the
   normalized area-weighted mean, area: sum; Shcherbakov 2025, ch. 5) until max_clusters remain. DEPARTURE:
   the metric's rows and columns are the unoccluded point-to-point form factors to
   'metric_columns' samples spread over the scene (every M / metric_columns-th sample), not all
   M: the full rows would cost M^2 per voxel pass. Each sample then belongs to one patch
   (weight = the area correction), and the form factors are built by step 5 unchanged, so the
   merged rows and columns are exactly these merge rules applied to the whole sample matrix, with
   visibility. E uses w_ij = max(0, N_j . n_i) over the voxel's samples (rad_vp_from_samples)
   and gathering w_j = max(0, N_j . n), both normalized.
   LIMITS: light leaks through walls thinner than a voxel (the filter blends voxels on both
   sides when the normal finds patches in both); a point whose 2x2x2 neighbourhood holds no
   patch facing its normal gets 0. */

typedef enum rad_vp_weights {
    RAD_VP_WEIGHTS_SQUARED = 0, /* w_a = max(0, n . e_a)^2: sums to exactly 1 (the default) */
    RAD_VP_WEIGHTS_COSINE = 1   /* the cosines max(0, n . e_a) of Shcherbakov 2025, divided by their sum (1 to sqrt 3) */
} rad_vp_weights;

/* Which proxy rad_vp_create builds. */
typedef enum rad_vp_kind {
    RAD_VP_AXIS_ALIGNED = 0,    /* at most six patches per voxel, one per axis direction */
    RAD_VP_CLUSTERED = 1        /* general virtual patches: per voxel, greedy clustering of the
                                   samples into at most max_clusters patches */
} rad_vp_kind;

/* The six axis directions, in patch order inside a voxel. */
typedef enum rad_vp_axis {
    RAD_VP_POS_X = 0, RAD_VP_NEG_X = 1, RAD_VP_POS_Y = 2, RAD_VP_NEG_Y = 3, RAD_VP_POS_Z = 4, RAD_VP_NEG_Z = 5
} rad_vp_axis;

typedef struct rad_vp_options {
    float voxel_size[3];      /* per axis, world units; all 0 (default): cubes, 'resolution' of
                                 them along the longest axis of the scene bounds */
    uint32_t resolution;      /* default 16 */
    uint32_t face_points;     /* Hammersley points per voxel face (default 16, at most 4096) */
    rad_vp_weights weights;   /* default RAD_VP_WEIGHTS_SQUARED */
    float ray_epsilon;        /* relative to the scene diagonal (0: 1e-5; at most 1e-2) */
    int skip_visibility;      /* non-zero: V = 1 between samples (unoccluded form factors) */
    uint32_t visibility_rays; /* shadow rays per pair of voxels (default 16, at most 1024); 0:
                                 one ray per pair of samples (the literal form: cost
                                 M^2 / 2 rays). See VISIBILITY in the section comment. */
    int keep_row_sums;        /* non-zero: skip step 6 (rows may then sum to more than 1) */
    rad_vp_kind kind;         /* default RAD_VP_AXIS_ALIGNED */
    uint32_t max_clusters;    /* RAD_VP_CLUSTERED: Q, patches per voxel at most (1..6, default 6) */
    uint32_t metric_columns;  /* RAD_VP_CLUSTERED: samples used as the columns k of the metric's
                                 form-factor term (default 64, at most 4096) */
} rad_vp_options;

/* Axis-aligned virtual patches with their form factors. Read-only after creation.
   Patch p lies in voxel voxel[p] (an index into the voxel arrays) and faces axis axis[p]
   (RAD_VP_CLUSTERED: axis[p] is the cluster's slot 0..5 in its voxel and normals[p] its normal);
   the patches of voxel v are [voxel_first[v], voxel_first[v + 1]), in axis order.
   Samples are grouped by voxel the same way ([sample_first[v], sample_first[v + 1])). */
typedef struct rad_virtual_patches {
    uint32_t count;             /* N: patches */
    float *areas;               /* N: A_a */
    float *albedo;              /* 3N: c_a */
    float *normals;             /* 3N: the axis unit vectors */
    uint8_t *axis;              /* N: rad_vp_axis */
    uint32_t *voxel;            /* N */
    rad_matrix matrix;          /* N x N dense row-major F_ab (a view of storage owned here) */
    /* the grid */
    float origin[3];            /* corner of voxel (0, 0, 0) */
    float voxel_size[3];
    uint32_t dims[3];           /* voxels per axis */
    uint32_t voxel_count;       /* non-empty voxels */
    uint64_t *voxel_keys;       /* ascending: ix + dims[0] * (iy + dims[1] * iz) */
    uint32_t *voxel_first;      /* voxel_count + 1: first patch of each voxel */
    uint32_t *voxel_patch;      /* 6 per voxel: the patch of each axis, or RAD_NONE */
    uint32_t *sample_first;     /* voxel_count + 1: first sample of each voxel */
    /* the samples */
    uint32_t sample_count;      /* M */
    float *sample_positions;    /* 3M */
    float *sample_normals;      /* 3M: the geometric normals of their triangles */
    float *sample_albedo;       /* 3M */
    float *sample_areas;        /* M: s_i */
    float *sample_weights;      /* 6M: w_ia times the area correction of (voxel, axis a) */
    uint32_t *sample_triangles; /* M */
    /* what the build did */
    uint32_t candidate_voxels;  /* voxels overlapped by triangle bounds (step 1) */
    uint64_t face_rays;         /* rays cast from voxel faces */
    uint64_t pair_rays;         /* shadow rays between samples */
    const rad_scene *scene;     /* borrowed: must outlive this object */
    rad_vp_kind kind;
    rad_vp_weights weights;
    rad_allocator allocator;    /* private */
} rad_virtual_patches;

RAD_API void rad_vp_options_default(rad_vp_options *options);

/* Builds axis-aligned virtual patches for 'scene' (borrowed; must outlive the result).
   raycaster: its intersect() casts the face rays, its occluded() the shadow rays between
   samples (not needed with skip_visibility); borrowed for the call.
   Errors: INVALID_ARGUMENT (NULL input, negative or non-finite voxel size, bad weights or
   ray_epsilon), SIZE_OVERFLOW (a grid beyond 2^62 cells or an N x N matrix that does not fit:
   use bigger voxels), EMPTY_SCENE (no face ray hit anything), RAYCAST_FAILED, CANCELLED,
   OUT_OF_MEMORY. The logger says which. Thread safety: reentrant; uses ctx->parallel_for and
   reports progress (face rays 10%, form factors 90%). Deterministic: the same bits whatever
   the thread count. Cost and memory: see the section comment. docs/methods/virtual-patches.md. */
RAD_API rad_result rad_vp_create(const rad_scene *scene, const rad_raycaster *raycaster, const rad_vp_options *options,
                                 const rad_context *ctx, rad_virtual_patches **out);
RAD_API void rad_vp_destroy(rad_virtual_patches *vp);
/* Bytes the object holds (matrix, patches, voxels, samples). */
RAD_API size_t rad_vp_memory(const rad_virtual_patches *vp);

/* Fills 'system' for the classic solvers (rad_solve_*): F = vp->matrix, albedo, areas, n, and
   the source E (3N floats, borrowed). */
RAD_API void rad_vp_system(rad_system *system, const rad_virtual_patches *vp, const float *E);

/* Per-patch values from per-sample values (the primary light, normalized):
   out_a = sum_i w_ia s_i v_i / A_a over the samples i of a's voxel (axis-aligned), or
   out_j = sum_i w_ij s_i v_i / sum_i w_ij s_i with w_ij = max(0, N_j . n_i) (clustered). sample_values: 3M floats
   (for instance rho_i D_i from the engine's own shadow maps); out: 3N floats.
   Errors: INVALID_ARGUMENT. O(M). */
RAD_API rad_result rad_vp_from_samples(const rad_virtual_patches *vp, const float *sample_values, float *out);

/* The source E per patch (3N floats) one of the two ways of UNITS AND CONVENTIONS, through
   rad_vp_from_samples: RAD_SOURCE_DIRECT: v_i = rho_i D_i, D_i the direct irradiance at
   sample i (rad_direct_irradiance with the lights; the emitters' own emission is kept out);
   RAD_SOURCE_EMISSION: v_i = pi L_i of the sample's material (lights unused, raycaster may be
   NULL). Errors: those of rad_direct_irradiance, OUT_OF_MEMORY. Cost: O(M) direct-light
   evaluations. docs/methods/virtual-patches.md. */
RAD_API rad_result rad_vp_sources(const rad_virtual_patches *vp, const rad_raycaster *raycaster,
                                  const rad_light *lights, uint32_t light_count, const rad_direct_options *options,
                                  rad_source_mode mode, float *out_E, const rad_context *ctx);

/* Gathering at one surface point p with unit normal n (docs/methods/virtual-patches.md): in each
   voxel of the 2x2x2 block around p (by voxel centres), L(v) = sum_a w_a(n) x_a / sum_a w_a(n)
   over v's patches (w_a the split weights of rad_vp_weights; clustered: w_j = max(0, N_j . n));
   voxels missing or with no patch
   facing n are skipped, and L = sum_v t_v L(v) / sum_v t_v with the trilinear weights t_v.
   values: 3N floats per patch (B, L or H); out: 3 floats. Returns the number of voxels that
   contributed (0: out is 0). Pure, thread-safe, O(1). */
RAD_API uint32_t rad_vp_gather_point(const rad_virtual_patches *vp, const float *values, const float p[3],
                                     const float n[3], float out[3]);

/* The same at 'count' points (3 floats each) with unit normals, in parallel through
   ctx->parallel_for. out: 3 * count floats. Errors: INVALID_ARGUMENT, NON_FINITE (a point or
   normal). */
RAD_API rad_result rad_vp_gather(const rad_virtual_patches *vp, const float *values, const float *points,
                                 const float *normals, uint32_t count, float *out, const rad_context *ctx);

/* Per-vertex values of a mesh (for instance one of the scene's own meshes): its vertices with
   its normals, or, when mesh->normals is NULL, the area-weighted mean of the normals of the
   triangles around each vertex. out: 3 * mesh->vertex_count floats (a vertex no triangle uses
   gets 0). Errors: INVALID_ARGUMENT, INDEX_OUT_OF_RANGE, NON_FINITE, OUT_OF_MEMORY. */
RAD_API rad_result rad_vp_gather_mesh(const rad_virtual_patches *vp, const float *values, const rad_mesh_desc *mesh,
                                      float *out, const rad_context *ctx);

#ifdef __cplusplus
}
#endif

#endif /* RADIOSITY_H */

/* ---- stop here if you only want the API; the implementation follows ---- */

#if defined(RADIOSITY_IMPLEMENTATION) && !defined(RADIOSITY_IMPLEMENTATION_INCLUDED)
#define RADIOSITY_IMPLEMENTATION_INCLUDED

#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <float.h>
#include <stdio.h>
#include <limits.h>
#include <stdarg.h>

#if defined(RAD_MALLOC) && defined(RAD_REALLOC) && defined(RAD_FREE)
/* all three given */
#elif !defined(RAD_MALLOC) && !defined(RAD_REALLOC) && !defined(RAD_FREE)
#  define RAD_MALLOC(size) malloc(size)
#  define RAD_REALLOC(ptr, size) realloc(ptr, size)
#  define RAD_FREE(ptr) free(ptr)
#else
#  error "radiosity.h: define all of RAD_MALLOC, RAD_REALLOC and RAD_FREE, or none of them"
#endif

#ifndef RAD_ASSERT
#  include <assert.h>
#  define RAD_ASSERT(x) assert(x)
#endif

#if !defined(RAD_NO_SIMD) && (defined(__SSE2__) || defined(_M_X64) || (defined(_M_IX86_FP) && _M_IX86_FP >= 2))
#  define RAD__SSE2 1
#  include <emmintrin.h>
#endif
#if !defined(RAD_NO_SIMD) && defined(__AVX__)
#  define RAD__AVX 1
#  include <immintrin.h>
#endif

/* Linux: madvise(MADV_HUGEPAGE) on large alias tables (>>temporal). Strict ISO C (-std=c99)
   hides the declaration in <sys/mman.h>; the function and the value 14 (asm-generic, which
   these architectures use) are Linux ABI. */
#if defined(__linux__) && !defined(RAD_NO_HUGEPAGES)
#  include <sys/mman.h>
#  if defined(MADV_HUGEPAGE)
#    define RAD__MADV_HUGEPAGE MADV_HUGEPAGE
#  elif !defined(__cplusplus) && (defined(__x86_64__) || defined(__i386__) || defined(__aarch64__) || defined(__arm__) || \
                                  defined(__riscv) || defined(__powerpc64__))
extern int madvise(void *addr, size_t length, int advice);
#    define RAD__MADV_HUGEPAGE 14
#  endif
#endif

#define RAD__PI 3.14159265358979323846
#define RAD__MAX_SAMPLES 256u
/* ray offsets above 1% of the scene's diagonal step over walls and change the answer */
#define RAD__MAX_RAY_EPSILON 1e-2f
#define RAD__RAY_BATCH 1024u

/* compile-time checks: layouts shaders and files will rely on */
typedef char rad__check_ray_size[(sizeof(rad_ray) == 32) ? 1 : -1];
typedef char rad__check_hit_size[(sizeof(rad_hit) == 16) ? 1 : -1];
typedef char rad__check_float_size[(sizeof(float) == 4) ? 1 : -1];

/* ======================================================================================== */
/* >>core: results, allocation, logging, tasks                                              */
/* ======================================================================================== */

RAD_API const char *rad_result_string(rad_result result)
{
    switch (result) {
    case RAD_SUCCESS: return "RAD_SUCCESS: no error";
    case RAD_ERROR_INVALID_ARGUMENT: return "RAD_ERROR_INVALID_ARGUMENT: a NULL pointer, zero count or bad option";
    case RAD_ERROR_OUT_OF_MEMORY: return "RAD_ERROR_OUT_OF_MEMORY: an allocation failed";
    case RAD_ERROR_SIZE_OVERFLOW: return "RAD_ERROR_SIZE_OVERFLOW: a size does not fit its type";
    case RAD_ERROR_EMPTY_SCENE: return "RAD_ERROR_EMPTY_SCENE: the scene has no triangles";
    case RAD_ERROR_INDEX_OUT_OF_RANGE: return "RAD_ERROR_INDEX_OUT_OF_RANGE: a vertex index is out of range";
    case RAD_ERROR_NON_FINITE: return "RAD_ERROR_NON_FINITE: NaN or infinity in the input";
    case RAD_ERROR_DEGENERATE_TRIANGLE: return "RAD_ERROR_DEGENERATE_TRIANGLE: a triangle has zero area";
    case RAD_ERROR_ALBEDO_RANGE: return "RAD_ERROR_ALBEDO_RANGE: an albedo is outside [0, 1)";
    case RAD_ERROR_NEGATIVE_EMISSION: return "RAD_ERROR_NEGATIVE_EMISSION: an emission is negative or not finite";
    case RAD_ERROR_MATERIAL_OUT_OF_RANGE: return "RAD_ERROR_MATERIAL_OUT_OF_RANGE: a material index is out of range";
    case RAD_ERROR_CANCELLED: return "RAD_ERROR_CANCELLED: the progress callback cancelled the call";
    case RAD_ERROR_NOT_CONVERGED: return "RAD_ERROR_NOT_CONVERGED: the iteration limit was reached";
    case RAD_ERROR_SINGULAR: return "RAD_ERROR_SINGULAR: the system matrix is singular";
    case RAD_ERROR_UNAVAILABLE: return "RAD_ERROR_UNAVAILABLE: the feature is not compiled in";
    case RAD_ERROR_RAYCAST_FAILED: return "RAD_ERROR_RAYCAST_FAILED: a ray-query callback failed";
    case RAD_ERROR_SIZE_MISMATCH: return "RAD_ERROR_SIZE_MISMATCH: sizes of the inputs do not match";
    case RAD_ERROR_IO: return "RAD_ERROR_IO: a file could not be opened, read or written";
    case RAD_ERROR_TRUNCATED: return "RAD_ERROR_TRUNCATED: the baked data is truncated";
    case RAD_ERROR_CORRUPT: return "RAD_ERROR_CORRUPT: the baked data is corrupted (checksum, table or layout)";
    case RAD_ERROR_VERSION: return "RAD_ERROR_VERSION: the baked data has an unsupported version";
    case RAD_ERROR_SCENE_MISMATCH: return "RAD_ERROR_SCENE_MISMATCH: the baked data was made from another scene or other options";
    case RAD_ERROR_SCALE_RANGE: return "RAD_ERROR_SCALE_RANGE: the scene is larger or smaller than the library supports";
    }
    return "RAD_ERROR_UNKNOWN: not a rad_result value";
}

typedef struct rad__ctx {
    rad_allocator allocator;
    void (*log)(void *user, rad_log_level level, const char *message);
    void *log_user;
    rad_parallel_for_fn parallel_for;
    void *parallel_user;
    uint32_t tasks;
    int (*progress)(void *user, float fraction);
    void *progress_user;
} rad__ctx;

static void rad__parallel_default(void *user, uint32_t count, rad_task_fn fn, void *data)
{
#ifdef _OPENMP
    int i, n = (int)count;
    (void)user;
#pragma omp parallel for schedule(dynamic, 1)
    for (i = 0; i < n; ++i) fn(data, (uint32_t)i);
#else
    uint32_t i;
    (void)user;
    for (i = 0; i < count; ++i) fn(data, i);
#endif
}

static void rad__ctx_init(rad__ctx *c, const rad_context *ctx)
{
    memset(c, 0, sizeof(*c));
    if (ctx) {
        if (ctx->allocator.alloc && ctx->allocator.free) c->allocator = ctx->allocator;
        c->log = ctx->log;
        c->log_user = ctx->log_user;
        c->parallel_for = ctx->parallel_for;
        c->parallel_user = ctx->parallel_user;
        c->tasks = ctx->task_count;
        c->progress = ctx->progress;
        c->progress_user = ctx->progress_user;
    }
    if (!c->parallel_for) c->parallel_for = rad__parallel_default;
    if (c->tasks == 0) c->tasks = 64;
    if (c->tasks > 4096) c->tasks = 4096;
}

static void *rad__alloc(const rad_allocator *a, size_t size)
{
    if (size == 0) size = 1;
    if (a->alloc) return a->alloc(a->user, size);
    return RAD_MALLOC(size);
}

static void rad__free(const rad_allocator *a, void *p)
{
    if (!p) return;
    if (a->free) a->free(a->user, p);
    else RAD_FREE(p);
}

/* Grows a buffer from old_size to new_size bytes, keeping the contents. */
static void *rad__realloc(const rad_allocator *a, void *p, size_t old_size, size_t new_size)
{
    void *q;
    if (!a->alloc) return RAD_REALLOC(p, new_size ? new_size : 1);
    q = rad__alloc(a, new_size);
    if (!q) return NULL;
    if (p) {
        memcpy(q, p, old_size < new_size ? old_size : new_size);
        rad__free(a, p);
    }
    return q;
}

/* a * b into *out; returns 0 on overflow */
static int rad__mul(size_t a, size_t b, size_t *out)
{
    if (a != 0 && b > (size_t)-1 / a) return 0;
    *out = a * b;
    return 1;
}

static int rad__mul3(size_t a, size_t b, size_t c, size_t *out)
{
    size_t t;
    return rad__mul(a, b, &t) && rad__mul(t, c, out);
}

/* Allocates count * size bytes, checking the product. */
static void *rad__alloc_array(const rad_allocator *a, size_t count, size_t size)
{
    size_t bytes;
    if (!rad__mul(count, size, &bytes)) return NULL;
    return rad__alloc(a, bytes);
}

#if defined(__GNUC__) || defined(__clang__)
__attribute__((format(printf, 3, 4)))
#endif
static void rad__log(const rad__ctx *c, rad_log_level level, const char *fmt, ...)
{
    char buf[512];
    va_list ap;
    if (!c || !c->log) return;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof(buf), fmt, ap);
    va_end(ap);
    c->log(c->log_user, level, buf);
}

static int rad__finite(float x) { return x == x && x - x == 0.0f; }
static int rad__finite3(const float *v) { return rad__finite(v[0]) && rad__finite(v[1]) && rad__finite(v[2]); }

/* Inputs and outputs never carry NaN or Inf (ERRORS in the top comment): a value that
   overflowed float (an emitter or light far too strong for the scene's scale, a system that
   diverges) is reported instead. */
static rad_result rad__check_input(const rad__ctx *c, const char *what, const float *v, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i)
        if (!rad__finite(v[i])) {
            rad__log(c, RAD_LOG_ERROR, "%s: input value %llu (patch %llu channel %u) is %g: inputs must be finite", what,
                     (unsigned long long)i, (unsigned long long)(i / 3u), (unsigned)(i % 3u), (double)v[i]);
            return RAD_ERROR_NON_FINITE;
        }
    return RAD_SUCCESS;
}

static rad_result rad__check_output(const rad__ctx *c, const char *what, const float *v, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i)
        if (!rad__finite(v[i])) {
            rad__log(c, RAD_LOG_ERROR, "%s: value %llu is %g (overflows float: lights or emission too strong for this scene)",
                     what, (unsigned long long)i, (double)v[i]);
            return RAD_ERROR_NON_FINITE;
        }
    return RAD_SUCCESS;
}

/* vector helpers */
static void rad__sub(float *o, const float *a, const float *b) { o[0] = a[0] - b[0]; o[1] = a[1] - b[1]; o[2] = a[2] - b[2]; }
static float rad__dot(const float *a, const float *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void rad__cross(float *o, const float *a, const float *b)
{
    float x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2], z = a[0] * b[1] - a[1] * b[0];
    o[0] = x; o[1] = y; o[2] = z;
}
static float rad__len(const float *a) { return (float)sqrt((double)rad__dot(a, a)); }
static void rad__normalize(float *a)
{
    float l = rad__len(a);
    if (l > 0.0f) { a[0] /= l; a[1] /= l; a[2] /= l; }
}

/* ---- tasks over rows, with progress and cancel ---- */

/* Processes one row on task 'task' (0 <= task < tasks). Returns RAD_SUCCESS or an error. */
typedef rad_result (*rad__row_fn)(void *data, uint32_t row, uint32_t task);

typedef struct rad__rows_job {
    rad__row_fn fn;
    void *data;
    uint32_t begin, end, tasks;
    rad_result *results;
} rad__rows_job;

static void rad__rows_task(void *d, uint32_t index)
{
    rad__rows_job *job = (rad__rows_job *)d;
    uint32_t row;
    rad_result r = RAD_SUCCESS;
    /* cyclic distribution balances rows of unequal cost (triangular workloads) */
    for (row = job->begin + index; row < job->end && r == RAD_SUCCESS; row += job->tasks) r = job->fn(job->data, row, index);
    job->results[index] = r;
}

/* Runs fn over rows [0, count) in batches, parallel inside a batch; progress after each batch.
   'tasks' is the number of task slots the caller prepared scratch for. */
static rad_result rad__for_rows(const rad__ctx *c, uint32_t count, uint32_t tasks, rad__row_fn fn, void *data)
{
    rad__rows_job job;
    uint32_t batches, b, t;
    rad_result r = RAD_SUCCESS;
    if (count == 0) return RAD_SUCCESS;
    job.results = (rad_result *)rad__alloc_array(&c->allocator, tasks, sizeof(rad_result));
    if (!job.results) {
        rad__log(c, RAD_LOG_ERROR, "out of memory for %u task results", tasks);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    job.fn = fn;
    job.data = data;
    job.tasks = tasks;
    batches = count / tasks;
    if (batches < 1) batches = 1;
    if (batches > 100) batches = 100;
    if (!c->progress) batches = 1;
    for (b = 0; b < batches && r == RAD_SUCCESS; ++b) {
        job.begin = (uint32_t)((uint64_t)count * b / batches);
        job.end = (uint32_t)((uint64_t)count * (b + 1) / batches);
        for (t = 0; t < tasks; ++t) job.results[t] = RAD_SUCCESS;
        c->parallel_for(c->parallel_user, tasks, rad__rows_task, &job);
        for (t = 0; t < tasks; ++t)
            if (job.results[t] != RAD_SUCCESS) { r = job.results[t]; break; }
        /* tasks cannot log (they may run on other threads): their failure is reported here */
        if (r == RAD_ERROR_RAYCAST_FAILED)
            rad__log(c, RAD_LOG_ERROR, "a ray query callback (occluded or intersect) returned an error while rows %u to %u of %u "
                     "ran: the call stops", job.begin, job.end - 1u, count);
        else if (r != RAD_SUCCESS)
            rad__log(c, RAD_LOG_ERROR, "rows %u to %u of %u: %s", job.begin, job.end - 1u, count, rad_result_string(r));
        if (r == RAD_SUCCESS && c->progress && c->progress(c->progress_user, (float)(b + 1) / (float)batches)) {
            r = RAD_ERROR_CANCELLED;
            rad__log(c, RAD_LOG_INFO, "cancelled by the progress callback after %u of %u rows", job.end, count);
        }
    }
    rad__free(&c->allocator, job.results);
    return r;
}

/* ---- sampling ---- */

static float rad__radical_inverse(uint32_t i)
{
    i = (i << 16) | (i >> 16);
    i = ((i & 0x00ff00ffu) << 8) | ((i & 0xff00ff00u) >> 8);
    i = ((i & 0x0f0f0f0fu) << 4) | ((i & 0xf0f0f0f0u) >> 4);
    i = ((i & 0x33333333u) << 2) | ((i & 0xccccccccu) >> 2);
    i = ((i & 0x55555555u) << 1) | ((i & 0xaaaaaaaau) >> 1);
    return (float)((double)i * (1.0 / 4294967296.0));
}

static uint32_t rad__hash(uint32_t x)
{
    x ^= x >> 16; x *= 0x7feb352du;
    x ^= x >> 15; x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

static float rad__frac(float x) { return x - (float)floor((double)x); }

/* Hammersley point s of n in the open unit square, Cranley-Patterson rotated by (r1, r2). */
static void rad__hammersley(uint32_t s, uint32_t n, float r1, float r2, float *u1, float *u2)
{
    float a = ((float)s + 0.5f) / (float)n;
    float b = rad__radical_inverse(s) + 0.5f / (float)n;
    a = rad__frac(a + r1);
    b = rad__frac(b + r2);
    /* keep strictly inside (0,1) so triangle points never sit on an edge */
    if (a < 1e-6f) a = 1e-6f;
    if (a > 1.0f - 1e-6f) a = 1.0f - 1e-6f;
    if (b < 1e-6f) b = 1e-6f;
    if (b > 1.0f - 1e-6f) b = 1.0f - 1e-6f;
    *u1 = a;
    *u2 = b;
}

/* Uniform point on triangle (v0, v1, v2) from (u1, u2) by the square-root map. */
static void rad__triangle_point(const float *v0, const float *v1, const float *v2, float u1, float u2, float *out)
{
    float su = (float)sqrt((double)u1);
    float b0 = 1.0f - su, b1 = u2 * su, b2 = su * (1.0f - u2);
    int k;
    for (k = 0; k < 3; ++k) out[k] = b0 * v0[k] + b1 * v1[k] + b2 * v2[k];
}

/* Point s of n*n on a triangle: the centroid of sub-triangle s of its n x n subdivision (the
   ordering of rad_patches: row j holds n - j up then n - j - 1 down triangles). The points have
   exactly the triangle's centroid and equal weights: the midpoint rule on sub-triangles. */
static void rad__lattice_point(const float *v0, const float *v1, const float *v2, uint32_t n, uint32_t s, float *out)
{
    uint32_t j = 0, row, i;
    float a, b;
    int k;
    while (j + 1 < n && s >= (row = 2u * (n - j) - 1u)) { s -= row; ++j; }
    if (s < n - j) { i = s; a = ((float)i + 1.0f / 3.0f) / (float)n; b = ((float)j + 1.0f / 3.0f) / (float)n; }
    else { i = s - (n - j); a = ((float)i + 2.0f / 3.0f) / (float)n; b = ((float)j + 2.0f / 3.0f) / (float)n; }
    for (k = 0; k < 3; ++k) out[k] = v0[k] + a * (v1[k] - v0[k]) + b * (v2[k] - v0[k]);
}

/* the side of the sample lattice for a requested sample count: n*n points, n >= 1 */
static uint32_t rad__lattice_side(uint32_t samples)
{
    uint32_t n = (uint32_t)floor(sqrt((double)samples) + 0.5);
    return n ? n : 1u;
}

/* ======================================================================================== */
/* >>scene: scene input and validation                                                      */
/* ======================================================================================== */

static const float *rad__strided(const float *base, size_t stride, uint32_t i)
{
    return (const float *)(const void *)((const char *)base + stride * (size_t)i);
}

static const char *rad__mesh_name(const rad_mesh_desc *m) { return (m->name && m->name[0]) ? m->name : "(unnamed)"; }

/* Twice the area vector of a triangle in double into cr (length into *len). Returns 0 when the
   triangle is degenerate: zero area, collinear to within float precision relative to its
   longest edge, or an area too small for float. */
static int rad__triangle_cross(const float *p0, const float *p1, const float *p2, double *cr, double *len)
{
    double e1[3], e2[3], l1, l2, l3, lmax;
    int k;
    for (k = 0; k < 3; ++k) {
        e1[k] = (double)p1[k] - (double)p0[k];
        e2[k] = (double)p2[k] - (double)p0[k];
    }
    cr[0] = e1[1] * e2[2] - e1[2] * e2[1];
    cr[1] = e1[2] * e2[0] - e1[0] * e2[2];
    cr[2] = e1[0] * e2[1] - e1[1] * e2[0];
    *len = sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
    l1 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
    l2 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
    l3 = (e2[0] - e1[0]) * (e2[0] - e1[0]) + (e2[1] - e1[1]) * (e2[1] - e1[1]) + (e2[2] - e1[2]) * (e2[2] - e1[2]);
    lmax = l1 > l2 ? l1 : l2;
    lmax = lmax > l3 ? lmax : l3;
    return (*len > 1e-10 * lmax) && (0.5 * *len >= (double)FLT_MIN);
}

static uint32_t rad__mesh_index(const rad_mesh_desc *m, uint32_t t, int k)
{
    return m->indices ? m->indices[3 * (size_t)t + (size_t)k] : 3 * t + (uint32_t)k;
}

RAD_API void rad_scene_destroy(rad_scene *scene)
{
    rad_allocator a;
    uint32_t i;
    if (!scene) return;
    a = scene->allocator;
    rad__free(&a, scene->positions);
    rad__free(&a, scene->normals);
    rad__free(&a, scene->uvs);
    rad__free(&a, scene->areas);
    rad__free(&a, scene->materials);
    rad__free(&a, scene->meshes);
    rad__free(&a, scene->source_triangles);
    rad__free(&a, scene->materials_table);
    if (scene->mesh_names)
        for (i = 0; i < scene->mesh_count; ++i) rad__free(&a, scene->mesh_names[i]);
    rad__free(&a, scene->mesh_names);
    rad__free(&a, scene);
}

static rad_result rad__validate_materials(const rad_scene_desc *desc, const rad__ctx *c)
{
    uint32_t i;
    int k;
    if (desc->material_count > 0 && !desc->materials) {
        rad__log(c, RAD_LOG_ERROR, "material_count is %u but materials is NULL", desc->material_count);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    for (i = 0; i < desc->material_count; ++i) {
        const rad_material *m = &desc->materials[i];
        for (k = 0; k < 3; ++k) {
            if (!rad__finite(m->albedo[k]) || m->albedo[k] < 0.0f || m->albedo[k] >= 1.0f) {
                rad__log(c, RAD_LOG_ERROR, "material %u: albedo channel %d is %g, outside [0, 1)", i, k, (double)m->albedo[k]);
                return RAD_ERROR_ALBEDO_RANGE;
            }
            if (!rad__finite(m->emission[k]) || m->emission[k] < 0.0f) {
                rad__log(c, RAD_LOG_ERROR, "material %u: emission channel %d is %g (must be finite and >= 0)", i, k,
                         (double)m->emission[k]);
                return RAD_ERROR_NEGATIVE_EMISSION;
            }
        }
        if (m->texture != 0 && !desc->albedo_lookup) {
            rad__log(c, RAD_LOG_ERROR, "material %u has texture %u but the scene has no albedo_lookup callback", i, m->texture);
            return RAD_ERROR_INVALID_ARGUMENT;
        }
    }
    return RAD_SUCCESS;
}

/* Validates one mesh; counts its usable triangles into *kept. */
static rad_result rad__validate_mesh(const rad_scene_desc *desc, uint32_t mi, const rad__ctx *c, uint32_t *kept)
{
    const rad_mesh_desc *m = &desc->meshes[mi];
    size_t ps = m->position_stride ? m->position_stride : 3 * sizeof(float);
    size_t ns = m->normal_stride ? m->normal_stride : 3 * sizeof(float);
    size_t us = m->uv_stride ? m->uv_stride : 2 * sizeof(float);
    uint32_t v, t;
    int k;
    *kept = 0;
    if (m->triangle_count == 0) return RAD_SUCCESS;
    if (!m->positions) {
        rad__log(c, RAD_LOG_ERROR, "mesh %u '%s': positions is NULL", mi, rad__mesh_name(m));
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    if (ps < 3 * sizeof(float) || (m->normals && ns < 3 * sizeof(float)) || (m->uvs && us < 2 * sizeof(float))) {
        rad__log(c, RAD_LOG_ERROR, "mesh %u '%s': a stride is smaller than its element", mi, rad__mesh_name(m));
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    if (!m->indices && (uint64_t)m->triangle_count * 3u > (uint64_t)m->vertex_count) {
        rad__log(c, RAD_LOG_ERROR, "mesh %u '%s': %u triangles without indices need %llu vertices, have %u", mi,
                 rad__mesh_name(m), m->triangle_count, (unsigned long long)m->triangle_count * 3u, m->vertex_count);
        return RAD_ERROR_INDEX_OUT_OF_RANGE;
    }
    for (v = 0; v < m->vertex_count; ++v) {
        const float *p = rad__strided(m->positions, ps, v);
        if (!rad__finite3(p)) {
            rad__log(c, RAD_LOG_ERROR, "mesh %u '%s': vertex %u has a non-finite position (%g %g %g)", mi,
                     rad__mesh_name(m), v, (double)p[0], (double)p[1], (double)p[2]);
            return RAD_ERROR_NON_FINITE;
        }
        if (m->normals && !rad__finite3(rad__strided(m->normals, ns, v))) {
            rad__log(c, RAD_LOG_ERROR, "mesh %u '%s': vertex %u has a non-finite normal", mi, rad__mesh_name(m), v);
            return RAD_ERROR_NON_FINITE;
        }
        if (m->uvs) {
            const float *uv = rad__strided(m->uvs, us, v);
            if (!rad__finite(uv[0]) || !rad__finite(uv[1])) {
                rad__log(c, RAD_LOG_ERROR, "mesh %u '%s': vertex %u has a non-finite uv", mi, rad__mesh_name(m), v);
                return RAD_ERROR_NON_FINITE;
            }
        }
    }
    for (t = 0; t < m->triangle_count; ++t) {
        uint32_t idx[3], mat = m->material_ids ? m->material_ids[t] : m->material;
        double cr[3], cl;
        const float *p[3];
        for (k = 0; k < 3; ++k) {
            idx[k] = rad__mesh_index(m, t, k);
            if (idx[k] >= m->vertex_count) {
                rad__log(c, RAD_LOG_ERROR, "mesh %u '%s': triangle %u index %d is %u, vertex_count is %u", mi,
                         rad__mesh_name(m), t, k, idx[k], m->vertex_count);
                return RAD_ERROR_INDEX_OUT_OF_RANGE;
            }
            p[k] = rad__strided(m->positions, ps, idx[k]);
        }
        if (mat >= desc->material_count) {
            rad__log(c, RAD_LOG_ERROR, "mesh %u '%s': triangle %u uses material %u, material_count is %u", mi,
                     rad__mesh_name(m), t, mat, desc->material_count);
            return RAD_ERROR_MATERIAL_OUT_OF_RANGE;
        }
        if (desc->materials[mat].texture != 0 && !m->uvs) {
            rad__log(c, RAD_LOG_ERROR, "mesh %u '%s': triangle %u uses textured material %u but the mesh has no uvs", mi,
                     rad__mesh_name(m), t, mat);
            return RAD_ERROR_INVALID_ARGUMENT;
        }
        if (!rad__triangle_cross(p[0], p[1], p[2], cr, &cl)) {
            if (desc->flags & RAD_SCENE_SKIP_DEGENERATE) continue;
            rad__log(c, RAD_LOG_ERROR, "mesh %u '%s': triangle %u has zero area (vertices %u %u %u)", mi, rad__mesh_name(m),
                     t, idx[0], idx[1], idx[2]);
            return RAD_ERROR_DEGENERATE_TRIANGLE;
        }
        ++*kept;
    }
    return RAD_SUCCESS;
}

RAD_API rad_result rad_scene_create(const rad_scene_desc *desc, const rad_context *ctx, rad_scene **out)
{
    rad__ctx c;
    rad_scene *s;
    rad_result r;
    uint64_t total = 0, input = 0;
    uint32_t mi, t, n, dst;
    int k, any_uv = 0;
    rad__ctx_init(&c, ctx);
    if (!out) return RAD_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    if (!desc) return RAD_ERROR_INVALID_ARGUMENT;
    if (desc->mesh_count > 0 && !desc->meshes) {
        rad__log(&c, RAD_LOG_ERROR, "mesh_count is %u but meshes is NULL", desc->mesh_count);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    r = rad__validate_materials(desc, &c);
    if (r != RAD_SUCCESS) return r;
    for (mi = 0; mi < desc->mesh_count; ++mi) {
        uint32_t kept;
        r = rad__validate_mesh(desc, mi, &c, &kept);
        if (r != RAD_SUCCESS) return r;
        total += kept;
        input += desc->meshes[mi].triangle_count;
        if (desc->meshes[mi].uvs) any_uv = 1;
    }
    if (total == 0) {
        rad__log(&c, RAD_LOG_ERROR, "the scene has no triangles (%llu given, %llu degenerate)", (unsigned long long)input,
                 (unsigned long long)(input - total));
        return RAD_ERROR_EMPTY_SCENE;
    }
    if (total >= (uint64_t)RAD_NONE) {
        rad__log(&c, RAD_LOG_ERROR, "%llu triangles: at most %u are supported", (unsigned long long)total, RAD_NONE - 1u);
        return RAD_ERROR_SIZE_OVERFLOW;
    }
    n = (uint32_t)total;
    s = (rad_scene *)rad__alloc(&c.allocator, sizeof(rad_scene));
    if (!s) return RAD_ERROR_OUT_OF_MEMORY;
    memset(s, 0, sizeof(*s));
    s->allocator = c.allocator;
    s->triangle_count = n;
    s->material_count = desc->material_count;
    s->skipped_triangles = (uint32_t)(input - total);
    s->albedo_lookup = desc->albedo_lookup;
    s->albedo_user = desc->albedo_user;
    s->positions = (float *)rad__alloc_array(&c.allocator, (size_t)n * 9u, sizeof(float));
    s->normals = (float *)rad__alloc_array(&c.allocator, (size_t)n * 3u, sizeof(float));
    s->areas = (float *)rad__alloc_array(&c.allocator, n, sizeof(float));
    s->materials = (uint32_t *)rad__alloc_array(&c.allocator, n, sizeof(uint32_t));
    s->meshes = (uint32_t *)rad__alloc_array(&c.allocator, n, sizeof(uint32_t));
    s->source_triangles = (uint32_t *)rad__alloc_array(&c.allocator, n, sizeof(uint32_t));
    s->materials_table = (rad_material *)rad__alloc_array(&c.allocator, desc->material_count, sizeof(rad_material));
    s->mesh_names = (char **)rad__alloc_array(&c.allocator, desc->mesh_count, sizeof(char *));
    if (any_uv) s->uvs = (float *)rad__alloc_array(&c.allocator, (size_t)n * 6u, sizeof(float));
    if (!s->positions || !s->normals || !s->areas || !s->materials || !s->meshes || !s->source_triangles ||
        !s->materials_table || !s->mesh_names || (any_uv && !s->uvs)) {
        rad_scene_destroy(s);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    memset(s->mesh_names, 0, sizeof(char *) * desc->mesh_count);
    s->mesh_count = desc->mesh_count;
    if (desc->material_count) memcpy(s->materials_table, desc->materials, sizeof(rad_material) * desc->material_count);
    for (mi = 0; mi < desc->mesh_count; ++mi) {
        const char *name = desc->meshes[mi].name ? desc->meshes[mi].name : "";
        size_t len = strlen(name);
        s->mesh_names[mi] = (char *)rad__alloc(&c.allocator, len + 1);
        if (!s->mesh_names[mi]) { rad_scene_destroy(s); return RAD_ERROR_OUT_OF_MEMORY; }
        memcpy(s->mesh_names[mi], name, len + 1);
    }
    for (k = 0; k < 3; ++k) { s->bounds_min[k] = FLT_MAX; s->bounds_max[k] = -FLT_MAX; }
    dst = 0;
    for (mi = 0; mi < desc->mesh_count; ++mi) {
        const rad_mesh_desc *m = &desc->meshes[mi];
        size_t ps = m->position_stride ? m->position_stride : 3 * sizeof(float);
        size_t us = m->uv_stride ? m->uv_stride : 2 * sizeof(float);
        for (t = 0; t < m->triangle_count; ++t) {
            double cr[3], cl;
            float tri[9], *P;
            int v;
            for (v = 0; v < 3; ++v) memcpy(tri + 3 * v, rad__strided(m->positions, ps, rad__mesh_index(m, t, v)), 3 * sizeof(float));
            /* decide before writing: a skipped triangle must not touch the arrays (sized for the kept ones) */
            if (!rad__triangle_cross(tri, tri + 3, tri + 6, cr, &cl)) continue; /* skipped (validation checked the flag) */
            P = s->positions + 9 * (size_t)dst;
            memcpy(P, tri, sizeof(tri));
            if (s->uvs)
                for (v = 0; v < 3; ++v) {
                    const float *uv = m->uvs ? rad__strided(m->uvs, us, rad__mesh_index(m, t, v)) : NULL;
                    s->uvs[6 * (size_t)dst + 2 * (size_t)v] = uv ? uv[0] : 0.0f;
                    s->uvs[6 * (size_t)dst + 2 * (size_t)v + 1] = uv ? uv[1] : 0.0f;
                }
            for (k = 0; k < 3; ++k) s->normals[3 * (size_t)dst + (size_t)k] = (float)(cr[k] / cl);
            s->areas[dst] = (float)(0.5 * cl);
            s->materials[dst] = m->material_ids ? m->material_ids[t] : m->material;
            s->meshes[dst] = mi;
            s->source_triangles[dst] = t;
            for (v = 0; v < 3; ++v)
                for (k = 0; k < 3; ++k) {
                    if (P[3 * v + k] < s->bounds_min[k]) s->bounds_min[k] = P[3 * v + k];
                    if (P[3 * v + k] > s->bounds_max[k]) s->bounds_max[k] = P[3 * v + k];
                }
            ++dst;
        }
    }
    RAD_ASSERT(dst == n);
    {
        double d2 = 0.0, diag;
        for (k = 0; k < 3; ++k) {
            double e = (double)s->bounds_max[k] - (double)s->bounds_min[k];
            d2 += e * e;
        }
        diag = sqrt(d2);
        if (!(diag >= RAD_SCENE_MIN_SIZE && diag <= RAD_SCENE_MAX_SIZE)) {
            rad__log(&c, RAD_LOG_ERROR, "the scene's bounding box diagonal is %g units: the library supports %g to %g (rescale "
                     "the scene, e.g. to meters)", diag, RAD_SCENE_MIN_SIZE, RAD_SCENE_MAX_SIZE);
            rad_scene_destroy(s);
            return RAD_ERROR_SCALE_RANGE;
        }
        s->diagonal = (float)diag;
    }
    *out = s;
    return RAD_SUCCESS;
}

RAD_API void rad_scene_albedo(const rad_scene *scene, uint32_t triangle, float b1, float b2, float out_rgb[3])
{
    const rad_material *m;
    if (!out_rgb) return;
    out_rgb[0] = out_rgb[1] = out_rgb[2] = 0.0f;
    if (!scene || triangle >= scene->triangle_count) return;
    m = &scene->materials_table[scene->materials[triangle]];
    if (m->texture && scene->albedo_lookup && scene->uvs) {
        const float *uv = scene->uvs + 6 * (size_t)triangle;
        float b0 = 1.0f - b1 - b2;
        float u = b0 * uv[0] + b1 * uv[2] + b2 * uv[4];
        float v = b0 * uv[1] + b1 * uv[3] + b2 * uv[5];
        scene->albedo_lookup(scene->albedo_user, m->texture, u, v, out_rgb);
    } else {
        out_rgb[0] = m->albedo[0];
        out_rgb[1] = m->albedo[1];
        out_rgb[2] = m->albedo[2];
    }
}

/* ---- the built-in Cornell box (original Cornell data in metres, as the cornell.obj of docs/data.md) ---- */

static const float rad__cornell_positions[] = {
    /* floor */ 0.5528f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.5592f, 0.5496f, 0.0f, 0.5592f,
    /* ceiling */ 0.5560f, 0.5488f, 0.0f, 0.5560f, 0.5488f, 0.5592f, 0.0f, 0.5488f, 0.5592f, 0.0f, 0.5488f, 0.0f,
    /* back */ 0.5496f, 0.0f, 0.5592f, 0.0f, 0.0f, 0.5592f, 0.0f, 0.5488f, 0.5592f, 0.5560f, 0.5488f, 0.5592f,
    /* green */ 0.0f, 0.0f, 0.5592f, 0.0f, 0.0f, 0.0f, 0.0f, 0.5488f, 0.0f, 0.0f, 0.5488f, 0.5592f,
    /* red */ 0.5528f, 0.0f, 0.0f, 0.5496f, 0.0f, 0.5592f, 0.5560f, 0.5488f, 0.5592f, 0.5560f, 0.5488f, 0.0f,
    /* light */ 0.3430f, 0.5487f, 0.2270f, 0.3430f, 0.5487f, 0.3320f, 0.2130f, 0.5487f, 0.3320f, 0.2130f, 0.5487f, 0.2270f,
    /* short block */
    0.1300f, 0.1650f, 0.0650f, 0.0820f, 0.1650f, 0.2250f, 0.2400f, 0.1650f, 0.2720f, 0.2900f, 0.1650f, 0.1140f,
    0.2900f, 0.0f, 0.1140f, 0.2900f, 0.1650f, 0.1140f, 0.2400f, 0.1650f, 0.2720f, 0.2400f, 0.0f, 0.2720f,
    0.1300f, 0.0f, 0.0650f, 0.1300f, 0.1650f, 0.0650f, 0.2900f, 0.1650f, 0.1140f, 0.2900f, 0.0f, 0.1140f,
    0.0820f, 0.0f, 0.2250f, 0.0820f, 0.1650f, 0.2250f, 0.1300f, 0.1650f, 0.0650f, 0.1300f, 0.0f, 0.0650f,
    0.2400f, 0.0f, 0.2720f, 0.2400f, 0.1650f, 0.2720f, 0.0820f, 0.1650f, 0.2250f, 0.0820f, 0.0f, 0.2250f,
    /* tall block */
    0.4230f, 0.3300f, 0.2470f, 0.2650f, 0.3300f, 0.2960f, 0.3140f, 0.3300f, 0.4560f, 0.4720f, 0.3300f, 0.4060f,
    0.4230f, 0.0f, 0.2470f, 0.4230f, 0.3300f, 0.2470f, 0.4720f, 0.3300f, 0.4060f, 0.4720f, 0.0f, 0.4060f,
    0.4720f, 0.0f, 0.4060f, 0.4720f, 0.3300f, 0.4060f, 0.3140f, 0.3300f, 0.4560f, 0.3140f, 0.0f, 0.4560f,
    0.3140f, 0.0f, 0.4560f, 0.3140f, 0.3300f, 0.4560f, 0.2650f, 0.3300f, 0.2960f, 0.2650f, 0.0f, 0.2960f,
    0.2650f, 0.0f, 0.2960f, 0.2650f, 0.3300f, 0.2960f, 0.4230f, 0.3300f, 0.2470f, 0.4230f, 0.0f, 0.2470f
};

/* quads (a b c d) -> triangles (a b c) (a c d), vertices local to each mesh */
static const uint32_t rad__cornell_quad_indices[] = {
    0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7, 8, 9, 10, 8, 10, 11, 12, 13, 14, 12, 14, 15, 16, 17, 18, 16, 18, 19
};

static const rad_material rad__cornell_materials[4] = {
    { { 0.725f, 0.71f, 0.68f }, { 0.0f, 0.0f, 0.0f }, 0 },    /* white */
    { { 0.63f, 0.065f, 0.05f }, { 0.0f, 0.0f, 0.0f }, 0 },    /* red */
    { { 0.14f, 0.45f, 0.091f }, { 0.0f, 0.0f, 0.0f }, 0 },    /* green */
    { { 0.78f, 0.78f, 0.78f }, { 17.0f, 12.0f, 4.0f }, 0 }    /* light */
};

#define RAD__CORNELL_MESH(name, first_vertex, quads, mat)                                                      \
    { name, rad__cornell_positions + 3 * (first_vertex), 0, 4 * (quads), NULL, 0, NULL, 0, rad__cornell_quad_indices, \
      2 * (quads), NULL, mat }

static const rad_mesh_desc rad__cornell_meshes[8] = {
    RAD__CORNELL_MESH("floor", 0, 1, 0),      RAD__CORNELL_MESH("ceiling", 4, 1, 0),
    RAD__CORNELL_MESH("back", 8, 1, 0),       RAD__CORNELL_MESH("green", 12, 1, 2),
    RAD__CORNELL_MESH("red", 16, 1, 1),       RAD__CORNELL_MESH("light", 20, 1, 3),
    RAD__CORNELL_MESH("shortblock", 24, 5, 0), RAD__CORNELL_MESH("tallblock", 44, 5, 0)
};
#undef RAD__CORNELL_MESH

RAD_API void rad_cornell_box(rad_scene_desc *desc, rad_camera *camera)
{
    if (desc) {
        memset(desc, 0, sizeof(*desc));
        desc->meshes = rad__cornell_meshes;
        desc->mesh_count = 8;
        desc->materials = rad__cornell_materials;
        desc->material_count = 4;
    }
    if (camera) {
        camera->position[0] = 0.278f; camera->position[1] = 0.273f; camera->position[2] = -0.8f;
        camera->target[0] = 0.278f; camera->target[1] = 0.273f; camera->target[2] = 0.0f;
        camera->up[0] = 0.0f; camera->up[1] = 1.0f; camera->up[2] = 0.0f;
        camera->fov_y_degrees = 39.3077f;
    }
}

/* ======================================================================================== */
/* >>patches: patches, welding, locating, per-vertex values                                 */
/* ======================================================================================== */

RAD_API void rad_patch_options_default(rad_patch_options *options)
{
    if (!options) return;
    memset(options, 0, sizeof(*options));
    options->albedo_samples = 16;
}

RAD_API void rad_patches_destroy(rad_patches *p)
{
    rad_allocator a;
    if (!p) return;
    a = p->allocator;
    rad__free(&a, p->patches);
    rad__free(&a, p->vertices);
    rad__free(&a, p->first_patch);
    rad__free(&a, p->subdivision);
    rad__free(&a, p->areas);
    rad__free(&a, p->albedo);
    rad__free(&a, p);
}

/* local index of the up (i, j) and down (i, j) sub-triangles of an n x n subdivision: row j
   holds n - j up triangles then n - j - 1 down triangles */
static uint32_t rad__sub_row(uint32_t n, uint32_t j) { return j * (2u * n - 1u) - j * (j - 1u); }
static uint32_t rad__sub_up(uint32_t n, uint32_t i, uint32_t j) { return rad__sub_row(n, j) + i; }
static uint32_t rad__sub_down(uint32_t n, uint32_t i, uint32_t j) { return rad__sub_row(n, j) + (n - j) + i; }
/* lattice point (i, j) of a triangle subdivided n times, i along v0->v1, j along v0->v2;
   row j holds n + 1 - j points */
static uint32_t rad__lattice(uint32_t n, uint32_t i, uint32_t j) { return j * (n + 1u) - (j * (j - 1u)) / 2u + i; }

typedef struct rad__weld {
    uint64_t *keys;      /* hash table of cell keys, 0 = empty */
    uint32_t *heads;     /* first vertex in the cell */
    uint32_t *next;      /* chain of vertices in a cell */
    float *normals;      /* per welded vertex: the normal of the plane it was made on */
    size_t capacity;     /* power of two */
} rad__weld;

static uint64_t rad__cell_key(int64_t x, int64_t y, int64_t z)
{
    uint64_t h = (uint64_t)x * 0x9E3779B97F4A7C15ull;
    h ^= (uint64_t)y * 0xC2B2AE3D27D4EB4Full + (h << 6) + (h >> 2);
    h ^= (uint64_t)z * 0x165667B19E3779F9ull + (h << 6) + (h >> 2);
    return h | 1u;
}

static size_t rad__weld_slot(const rad__weld *w, uint64_t key)
{
    size_t mask = w->capacity - 1, i = (size_t)(key ^ (key >> 29)) & mask;
    while (w->keys[i] != 0 && w->keys[i] != key) i = (i + 1) & mask;
    return i;
}

/* The welded vertex at p on a plane of normal tn, created when there is none within eps. */
static uint32_t rad__weld_vertex(rad__weld *w, float *vertices, uint32_t *nv, const float *p, const float *tn, float eps,
                                 const float *origin)
{
    /* cells relative to the scene's bounds: at most diagonal / eps = 1e6 per axis, whatever
       the absolute coordinates (no int64 overflow for scenes far from the origin) */
    int64_t cx = (int64_t)floor(((double)p[0] - (double)origin[0]) / (double)eps),
            cy = (int64_t)floor(((double)p[1] - (double)origin[1]) / (double)eps),
            cz = (int64_t)floor(((double)p[2] - (double)origin[2]) / (double)eps), dx, dy, dz;
    uint64_t key;
    size_t slot;
    uint32_t q;
    for (dz = -1; dz <= 1; ++dz)
        for (dy = -1; dy <= 1; ++dy)
            for (dx = -1; dx <= 1; ++dx) {
                key = rad__cell_key(cx + dx, cy + dy, cz + dz);
                slot = rad__weld_slot(w, key);
                if (w->keys[slot] != key) continue;
                for (q = w->heads[slot]; q != RAD_NONE; q = w->next[q]) {
                    float d[3];
                    rad__sub(d, vertices + 3 * (size_t)q, p);
                    if (rad__dot(d, d) <= eps * eps && rad__dot(w->normals + 3 * (size_t)q, tn) > 0.999f) return q;
                }
            }
    key = rad__cell_key(cx, cy, cz);
    slot = rad__weld_slot(w, key);
    q = (*nv)++;
    memcpy(vertices + 3 * (size_t)q, p, 3 * sizeof(float));
    memcpy(w->normals + 3 * (size_t)q, tn, 3 * sizeof(float));
    if (w->keys[slot] != key) { w->keys[slot] = key; w->heads[slot] = RAD_NONE; }
    w->next[q] = w->heads[slot];
    w->heads[slot] = q;
    return q;
}

/* Mean textured albedo over the sub-triangle with corner barycentrics lb (of triangle t). */
static rad_result rad__patch_albedo(const rad_scene *scene, uint32_t t, const float lb[3][2], uint32_t samples,
                                    const rad__ctx *c, float *out)
{
    double acc[3] = { 0.0, 0.0, 0.0 };
    uint32_t s;
    int k;
    uint32_t side = rad__lattice_side(samples);
    samples = side * side;
    for (s = 0; s < samples; ++s) {
        float q[3], rgb[3];
        rad__lattice_point(lb[0], lb[1], lb[2], side, s, q); /* in the triangle's (b1, b2) plane */
        rad_scene_albedo(scene, t, q[0], q[1], rgb);
        for (k = 0; k < 3; ++k) {
            if (!rad__finite(rgb[k]) || rgb[k] < 0.0f || rgb[k] >= 1.0f) {
                rad__log(c, RAD_LOG_ERROR, "albedo_lookup returned %g (channel %d) on triangle %u: outside [0, 1)", (double)rgb[k],
                         k, t);
                return RAD_ERROR_ALBEDO_RANGE;
            }
            acc[k] += rgb[k];
        }
    }
    for (k = 0; k < 3; ++k) out[k] = (float)(acc[k] / (double)samples);
    return RAD_SUCCESS;
}

RAD_API rad_result rad_patches_create(const rad_scene *scene, const rad_patch_options *options, const rad_context *ctx,
                                      rad_patches **out)
{
    rad__ctx c;
    rad_patch_options o;
    rad_patches *P;
    rad__weld w;
    uint64_t total = 0, lattice_total = 0;
    uint32_t t, nv = 0;
    float max_area, max_edge, eps;
    uint32_t *lattice_ids = NULL;
    size_t lattice_cap = 0;
    rad_result r = RAD_SUCCESS;
    rad__ctx_init(&c, ctx);
    if (!out) return RAD_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    if (!scene) return RAD_ERROR_INVALID_ARGUMENT;
    if (options) o = *options; else rad_patch_options_default(&o);
    if (!rad__finite(o.max_area) || o.max_area < 0.0f || !rad__finite(o.max_edge) || o.max_edge < 0.0f) {
        rad__log(&c, RAD_LOG_ERROR, "patch options: max_area %g and max_edge %g must be finite and >= 0", (double)o.max_area,
                 (double)o.max_edge);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    if (o.albedo_samples == 0) o.albedo_samples = 16;
    if (o.albedo_samples > RAD__MAX_SAMPLES) o.albedo_samples = RAD__MAX_SAMPLES;
    max_area = o.max_area;
    max_edge = o.max_edge;
    if (o.target_count > 0) {
        double sum = 0.0;
        for (t = 0; t < scene->triangle_count; ++t) sum += scene->areas[t];
        max_area = (float)(sum / (double)o.target_count);
    }
    P = (rad_patches *)rad__alloc(&c.allocator, sizeof(rad_patches));
    if (!P) return RAD_ERROR_OUT_OF_MEMORY;
    memset(P, 0, sizeof(*P));
    P->allocator = c.allocator;
    P->scene = scene;
    P->triangle_count = scene->triangle_count;
    P->first_patch = (uint32_t *)rad__alloc_array(&c.allocator, scene->triangle_count, sizeof(uint32_t));
    P->subdivision = (uint32_t *)rad__alloc_array(&c.allocator, scene->triangle_count, sizeof(uint32_t));
    if (!P->first_patch || !P->subdivision) { rad_patches_destroy(P); return RAD_ERROR_OUT_OF_MEMORY; }
    for (t = 0; t < scene->triangle_count; ++t) {
        const float *v = scene->positions + 9 * (size_t)t;
        float e[3][3];
        double n = 1.0, le = 0.0;
        int k;
        rad__sub(e[0], v + 3, v);
        rad__sub(e[1], v + 6, v + 3);
        rad__sub(e[2], v, v + 6);
        for (k = 0; k < 3; ++k) { double l = rad__len(e[k]); if (l > le) le = l; }
        if (max_edge > 0.0f) { double m = ceil(le / (double)max_edge); if (m > n) n = m; }
        if (max_area > 0.0f) { double m = ceil(sqrt((double)scene->areas[t] / (double)max_area)); if (m > n) n = m; }
        if (!(n < 65536.0)) {
            rad__log(&c, RAD_LOG_ERROR, "triangle %u would be cut %g times per edge (more than 65535)", t, n);
            rad_patches_destroy(P);
            return RAD_ERROR_SIZE_OVERFLOW;
        }
        P->subdivision[t] = (uint32_t)n;
        P->first_patch[t] = (uint32_t)total;
        total += (uint64_t)n * (uint64_t)n;
        lattice_total += ((uint64_t)n + 1u) * ((uint64_t)n + 2u) / 2u;
        if (total >= (uint64_t)RAD_NONE || lattice_total >= (uint64_t)RAD_NONE) {
            rad__log(&c, RAD_LOG_ERROR, "more than %u patches: reduce the subdivision", RAD_NONE - 1u);
            rad_patches_destroy(P);
            return RAD_ERROR_SIZE_OVERFLOW;
        }
    }
    P->count = (uint32_t)total;
    P->patches = (rad_patch *)rad__alloc_array(&c.allocator, P->count, sizeof(rad_patch));
    P->areas = (float *)rad__alloc_array(&c.allocator, P->count, sizeof(float));
    P->albedo = (float *)rad__alloc_array(&c.allocator, (size_t)P->count * 3u, sizeof(float));
    P->vertices = (float *)rad__alloc_array(&c.allocator, (size_t)lattice_total * 3u, sizeof(float));
    memset(&w, 0, sizeof(w));
    w.capacity = 16;
    while (w.capacity < (size_t)lattice_total * 2u) w.capacity <<= 1;
    w.keys = (uint64_t *)rad__alloc_array(&c.allocator, w.capacity, sizeof(uint64_t));
    w.heads = (uint32_t *)rad__alloc_array(&c.allocator, w.capacity, sizeof(uint32_t));
    w.next = (uint32_t *)rad__alloc_array(&c.allocator, (size_t)lattice_total, sizeof(uint32_t));
    w.normals = (float *)rad__alloc_array(&c.allocator, (size_t)lattice_total * 3u, sizeof(float));
    if (!P->patches || !P->areas || !P->albedo || !P->vertices || !w.keys || !w.heads || !w.next || !w.normals) {
        r = RAD_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    memset(w.keys, 0, w.capacity * sizeof(uint64_t));
    /* weld distance: far below any patch size, far above float rounding of the positions */
    eps = scene->diagonal * 1e-6f;
    for (t = 0; t < scene->triangle_count && r == RAD_SUCCESS; ++t) {
        const float *v = scene->positions + 9 * (size_t)t, *tn = scene->normals + 3 * (size_t)t;
        const rad_material *mat = &scene->materials_table[scene->materials[t]];
        uint32_t n = P->subdivision[t], i, j, base = P->first_patch[t];
        size_t lcount = ((size_t)n + 1u) * ((size_t)n + 2u) / 2u;
        float sub_area = scene->areas[t] / ((float)n * (float)n);
        if (lcount > lattice_cap) {
            rad__free(&c.allocator, lattice_ids);
            lattice_ids = (uint32_t *)rad__alloc_array(&c.allocator, lcount, sizeof(uint32_t));
            lattice_cap = lcount;
            if (!lattice_ids) { lattice_cap = 0; r = RAD_ERROR_OUT_OF_MEMORY; break; }
        }
        for (j = 0; j <= n; ++j)
            for (i = 0; i + j <= n; ++i) {
                float p[3], a = (float)i / (float)n, b = (float)j / (float)n;
                int k;
                for (k = 0; k < 3; ++k) p[k] = v[k] + a * (v[3 + k] - v[k]) + b * (v[6 + k] - v[k]);
                if (i == n) memcpy(p, v + 3, sizeof(p)); /* corners exactly */
                if (j == n) memcpy(p, v + 6, sizeof(p));
                lattice_ids[rad__lattice(n, i, j)] = rad__weld_vertex(&w, P->vertices, &nv, p, tn, eps, scene->bounds_min);
            }
        for (j = 0; j < n && r == RAD_SUCCESS; ++j)
            for (i = 0; i + j < n && r == RAD_SUCCESS; ++i) {
                int up;
                for (up = 1; up >= 0 && r == RAD_SUCCESS; --up) {
                    uint32_t idx, a0, a1, a2;
                    float lb[3][2];
                    rad_patch *pt;
                    int k;
                    if (up) {
                        idx = base + rad__sub_up(n, i, j);
                        a0 = lattice_ids[rad__lattice(n, i, j)];
                        a1 = lattice_ids[rad__lattice(n, i + 1, j)];
                        a2 = lattice_ids[rad__lattice(n, i, j + 1)];
                        lb[0][0] = (float)i; lb[0][1] = (float)j;
                        lb[1][0] = (float)(i + 1); lb[1][1] = (float)j;
                        lb[2][0] = (float)i; lb[2][1] = (float)(j + 1);
                    } else {
                        if (i + j + 2 > n) continue;
                        idx = base + rad__sub_down(n, i, j);
                        a0 = lattice_ids[rad__lattice(n, i + 1, j)];
                        a1 = lattice_ids[rad__lattice(n, i + 1, j + 1)];
                        a2 = lattice_ids[rad__lattice(n, i, j + 1)];
                        lb[0][0] = (float)(i + 1); lb[0][1] = (float)j;
                        lb[1][0] = (float)(i + 1); lb[1][1] = (float)(j + 1);
                        lb[2][0] = (float)i; lb[2][1] = (float)(j + 1);
                    }
                    pt = &P->patches[idx];
                    pt->vertices[0] = a0; pt->vertices[1] = a1; pt->vertices[2] = a2;
                    pt->triangle = t;
                    pt->area = sub_area;
                    memcpy(pt->normal, tn, 3 * sizeof(float));
                    memcpy(pt->emission, mat->emission, 3 * sizeof(float));
                    for (k = 0; k < 3; ++k)
                        pt->centroid[k] = (P->vertices[3 * (size_t)a0 + (size_t)k] + P->vertices[3 * (size_t)a1 + (size_t)k] +
                                           P->vertices[3 * (size_t)a2 + (size_t)k]) / 3.0f;
                    if (mat->texture && scene->albedo_lookup && scene->uvs) {
                        for (k = 0; k < 3; ++k) { lb[k][0] /= (float)n; lb[k][1] /= (float)n; }
                        r = rad__patch_albedo(scene, t, (const float(*)[2])lb, o.albedo_samples, &c, pt->albedo);
                    } else {
                        memcpy(pt->albedo, mat->albedo, 3 * sizeof(float));
                    }
                    P->areas[idx] = pt->area;
                    memcpy(P->albedo + 3 * (size_t)idx, pt->albedo, 3 * sizeof(float));
                }
            }
    }
    P->vertex_count = nv;
done:
    rad__free(&c.allocator, lattice_ids);
    rad__free(&c.allocator, w.keys);
    rad__free(&c.allocator, w.heads);
    rad__free(&c.allocator, w.next);
    rad__free(&c.allocator, w.normals);
    if (r != RAD_SUCCESS) { rad_patches_destroy(P); return r; }
    *out = P;
    return RAD_SUCCESS;
}

RAD_API uint32_t rad_patches_locate(const rad_patches *patches, uint32_t triangle, float b1, float b2, float out_weights[3])
{
    uint32_t n, i, j;
    float x, y, fx, fy, w[3];
    if (out_weights) out_weights[0] = out_weights[1] = out_weights[2] = 0.0f;
    if (!patches || triangle >= patches->triangle_count) return RAD_NONE;
    if (!(b1 >= 0.0f)) b1 = 0.0f; /* also catches NaN */
    if (!(b2 >= 0.0f)) b2 = 0.0f;
    if (b1 > 1.0f) b1 = 1.0f;     /* also catches +Inf */
    if (b2 > 1.0f) b2 = 1.0f;
    if (b1 + b2 > 1.0f) { float s = b1 + b2; b1 /= s; b2 /= s; }
    n = patches->subdivision[triangle];
    x = b1 * (float)n;
    y = b2 * (float)n;
    i = (uint32_t)x;
    j = (uint32_t)y;
    if (j > n - 1) j = n - 1;
    if (i + j > n - 1) i = n - 1 - j;
    fx = x - (float)i;
    fy = y - (float)j;
    if (fx + fy <= 1.0f || i + j + 2 > n) {
        /* up triangle (i,j) (i+1,j) (i,j+1): p = corner + fx e1 + fy e2 */
        w[1] = fx < 0.0f ? 0.0f : fx;
        w[2] = fy < 0.0f ? 0.0f : fy;
        if (w[1] + w[2] > 1.0f) { float s = w[1] + w[2]; w[1] /= s; w[2] /= s; }
        w[0] = 1.0f - w[1] - w[2];
        if (out_weights) memcpy(out_weights, w, sizeof(w));
        return patches->first_patch[triangle] + rad__sub_up(n, i, j);
    }
    /* down triangle (i+1,j) (i+1,j+1) (i,j+1): p = (i+1,j) + a (0,1) + b (-1,1) */
    w[2] = 1.0f - fx;
    w[1] = fy - w[2];
    if (w[1] < 0.0f) w[1] = 0.0f;
    if (w[2] < 0.0f) w[2] = 0.0f;
    if (w[1] + w[2] > 1.0f) { float s = w[1] + w[2]; w[1] /= s; w[2] /= s; }
    w[0] = 1.0f - w[1] - w[2];
    if (out_weights) memcpy(out_weights, w, sizeof(w));
    return patches->first_patch[triangle] + rad__sub_down(n, i, j);
}

RAD_API rad_result rad_patches_vertex_values(const rad_patches *patches, const float *patch_values, uint32_t channels,
                                             float *out_vertex_values)
{
    double *acc;
    size_t total;
    uint32_t i, v, k;
    rad_allocator a;
    if (!patches || !patch_values || !out_vertex_values || channels == 0) return RAD_ERROR_INVALID_ARGUMENT;
    a = patches->allocator;
    if (!rad__mul((size_t)patches->vertex_count, (size_t)channels + 1u, &total)) return RAD_ERROR_SIZE_OVERFLOW;
    acc = (double *)rad__alloc_array(&a, total, sizeof(double));
    if (!acc) return RAD_ERROR_OUT_OF_MEMORY;
    memset(acc, 0, total * sizeof(double));
    for (i = 0; i < patches->count; ++i) {
        const rad_patch *p = &patches->patches[i];
        for (v = 0; v < 3; ++v) {
            double *dst = acc + (size_t)p->vertices[v] * ((size_t)channels + 1u);
            for (k = 0; k < channels; ++k) dst[k] += (double)p->area * (double)patch_values[(size_t)i * channels + k];
            dst[channels] += p->area;
        }
    }
    for (v = 0; v < patches->vertex_count; ++v) {
        const double *src = acc + (size_t)v * ((size_t)channels + 1u);
        for (k = 0; k < channels; ++k)
            out_vertex_values[(size_t)v * channels + k] = src[channels] > 0.0 ? (float)(src[k] / src[channels]) : 0.0f;
    }
    rad__free(&a, acc);
    return RAD_SUCCESS;
}

RAD_API rad_result rad_patches_vertex_irradiance(const rad_patches *patches, const float *H, const float *S,
                                                 float *out_vertex_H, const rad_context *ctx)
{
    rad__ctx c;
    float *S_v, *S_max, *S_area;
    uint32_t n, nv, i, k;
    rad_result r;
    rad__ctx_init(&c, ctx);
    if (!patches || !H || !out_vertex_H) {
        rad__log(&c, RAD_LOG_ERROR, "rad_patches_vertex_irradiance: patches, H and out_vertex_H are required");
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    n = patches->count;
    nv = patches->vertex_count;
    for (i = 0; i < 3 * n; ++i)
        if (!rad__finite(H[i])) {
            rad__log(&c, RAD_LOG_ERROR, "rad_patches_vertex_irradiance: H of patch %u is not finite", i / 3);
            return RAD_ERROR_NON_FINITE;
        }
    if (!S) return rad_patches_vertex_values(patches, H, 3, out_vertex_H);
    for (i = 0; i < n; ++i)
        if (!rad__finite(S[i]) || S[i] < 0.0f) {
            rad__log(&c, RAD_LOG_ERROR, "rad_patches_vertex_irradiance: row sum S of patch %u is %g (finite, >= 0 expected)",
                     i, (double)S[i]);
            return RAD_ERROR_NON_FINITE;
        }
    S_v = (float *)rad__alloc_array(&c.allocator, 3 * (size_t)nv, sizeof(float));
    if (!S_v) return RAD_ERROR_OUT_OF_MEMORY;
    S_max = S_v + nv;
    S_area = S_max + nv;
    /* the bracket: vertex means of H and of S, both area-weighted over the patches at v */
    r = rad_patches_vertex_values(patches, H, 3, out_vertex_H);
    if (r == RAD_SUCCESS) r = rad_patches_vertex_values(patches, S, 1, S_v);
    if (r == RAD_SUCCESS) {
        for (i = 0; i < nv; ++i) S_max[i] = S_area[i] = 0.0f;
        for (i = 0; i < n; ++i)
            for (k = 0; k < 3; ++k) {
                uint32_t v = patches->patches[i].vertices[k];
                if (S[i] > S_max[v]) S_max[v] = S[i];
            }
        for (i = 0; i < nv; ++i) {
            float scale = S_v[i] > 0.0f ? 1.0f / S_v[i] : 0.0f;
            for (k = 0; k < 3; ++k) out_vertex_H[3 * (size_t)i + k] *= scale;
            S_v[i] = 0.0f;
        }
        /* S_v: how much the uncovered patches at v see */
        for (i = 0; i < n; ++i)
            for (k = 0; k < 3; ++k) {
                uint32_t v = patches->patches[i].vertices[k];
                if (S[i] >= 0.75f * S_max[v]) {
                    S_v[v] += patches->patches[i].area * S[i];
                    S_area[v] += patches->patches[i].area;
                }
            }
        for (i = 0; i < nv; ++i) {
            float s_v = S_area[i] > 0.0f ? S_v[i] / S_area[i] : 0.0f;
            for (k = 0; k < 3; ++k) out_vertex_H[3 * (size_t)i + k] *= s_v;
        }
    }
    rad__free(&c.allocator, S_v);
    return r;
}

RAD_API rad_result rad_patches_gather_mesh(const rad_patches *patches, const float *vertex_values, uint32_t mesh,
                                           const rad_mesh_desc *desc, float *out, const rad_context *ctx)
{
    rad__ctx c;
    const rad_scene *S;
    double *acc;
    uint32_t t, k, m, V;
    rad__ctx_init(&c, ctx);
    if (!patches || !patches->scene || !vertex_values || !desc || !out) {
        rad__log(&c, RAD_LOG_ERROR, "rad_patches_gather_mesh: patches, vertex_values, desc and out are required");
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    S = patches->scene;
    if (mesh >= S->mesh_count) {
        rad__log(&c, RAD_LOG_ERROR, "rad_patches_gather_mesh: mesh %u, but the scene has %u meshes", mesh, S->mesh_count);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    V = desc->vertex_count;
    acc = (double *)rad__alloc_array(&c.allocator, 4 * (size_t)V + 1u, sizeof(double));
    if (!acc) return RAD_ERROR_OUT_OF_MEMORY;
    memset(acc, 0, (4 * (size_t)V + 1u) * sizeof(double));
    for (t = 0; t < S->triangle_count; ++t) {
        uint32_t j = S->source_triangles[t], id[3];
        static const float corner[3][2] = { { 0.0f, 0.0f }, { 1.0f, 0.0f }, { 0.0f, 1.0f } };
        if (S->meshes[t] != mesh) continue;
        if (j >= desc->triangle_count) {
            rad__log(&c, RAD_LOG_ERROR, "rad_patches_gather_mesh: the scene's mesh %u has triangle %u, desc has %u triangles",
                     mesh, j, desc->triangle_count);
            rad__free(&c.allocator, acc);
            return RAD_ERROR_INDEX_OUT_OF_RANGE;
        }
        for (k = 0; k < 3; ++k) {
            id[k] = desc->indices ? desc->indices[3 * (size_t)j + k] : 3 * j + k;
            if (id[k] >= V) {
                rad__log(&c, RAD_LOG_ERROR, "rad_patches_gather_mesh: triangle %u has vertex index %u >= %u", j, id[k], V);
                rad__free(&c.allocator, acc);
                return RAD_ERROR_INDEX_OUT_OF_RANGE;
            }
        }
        for (k = 0; k < 3; ++k) {
            float w[3];
            uint32_t p = rad_patches_locate(patches, t, corner[k][0], corner[k][1], w);
            double *dst = acc + 4 * (size_t)id[k];
            if (p == RAD_NONE) continue;
            for (m = 0; m < 3; ++m) {
                const float *src = vertex_values + 3 * (size_t)patches->patches[p].vertices[m];
                dst[0] += (double)S->areas[t] * w[m] * src[0];
                dst[1] += (double)S->areas[t] * w[m] * src[1];
                dst[2] += (double)S->areas[t] * w[m] * src[2];
            }
            dst[3] += S->areas[t];
        }
    }
    for (k = 0; k < V; ++k) {
        const double *src = acc + 4 * (size_t)k;
        for (m = 0; m < 3; ++m) out[3 * (size_t)k + m] = src[3] > 0.0 ? (float)(src[m] / src[3]) : 0.0f;
    }
    rad__free(&c.allocator, acc);
    return RAD_SUCCESS;
}

/* ======================================================================================== */
/* >>bvh: the built-in BVH (binned SAH, watertight triangle test)                           */
/* ======================================================================================== */

typedef struct rad__bvh_node {
    float bmin[3];
    uint32_t first;   /* leaf: first triangle; inner: left child (right = first + 1) */
    float bmax[3];
    uint32_t count;   /* triangles in a leaf, 0 for an inner node */
} rad__bvh_node;

/* The traversal structure: RAD__BVH_W-wide nodes collapsed from the binary SAH tree, so one
   SIMD slab test checks all child boxes: 8 wide with AVX (one 256-bit test), else 4 wide (SSE,
   or the scalar loop under RAD_NO_SIMD). Empty slots have child RAD_NONE. */
#if defined(RAD__AVX)
#  define RAD__BVH_W 8
#else
#  define RAD__BVH_W 4
#endif
typedef struct rad__bvhw {
    float lo[3][RAD__BVH_W], hi[3][RAD__BVH_W]; /* per axis, per child */
    uint32_t child[RAD__BVH_W]; /* RAD__BVH4_LEAF | leaf block for a leaf, else node index */
    uint32_t count[RAD__BVH_W]; /* triangles of a leaf child (1 to 4) */
} rad__bvhw;
#define RAD__BVH4_LEAF 0x80000000u

/* A leaf's triangles (at most four) side by side, so one SIMD pass tests them all: lane j of
   v[c][a] is coordinate a of vertex c of triangle j. Unused lanes are zero (id RAD_NONE) and
   never tested. */
typedef struct rad__tri4 {
    float v[3][3][4];
    uint32_t id[4];           /* scene triangle of each lane */
} rad__tri4;

struct rad_bvh {
    rad__bvhw *nodes;
    uint32_t node_count;
    rad__tri4 *leaves;
    uint32_t leaf_count;
    uint32_t tri_count;
    rad_allocator allocator;
};

#define RAD__BVH_BINS 16
#define RAD__BVH_LEAF 4
#define RAD__BVH_STACK 128
#define RAD__BVH_SAH_DEPTH 64

typedef struct rad__aabb { float lo[3], hi[3]; } rad__aabb;

static void rad__aabb_empty(rad__aabb *b)
{
    b->lo[0] = b->lo[1] = b->lo[2] = FLT_MAX;
    b->hi[0] = b->hi[1] = b->hi[2] = -FLT_MAX;
}
static void rad__aabb_grow(rad__aabb *b, const float *lo, const float *hi)
{
    int k;
    /* selects rather than conditional stores: they compile to min/max without branches,
       which the build's binning loop mispredicted (a NaN keeps the old bound either way) */
    for (k = 0; k < 3; ++k) {
        b->lo[k] = lo[k] < b->lo[k] ? lo[k] : b->lo[k];
        b->hi[k] = hi[k] > b->hi[k] ? hi[k] : b->hi[k];
    }
}
static float rad__aabb_area(const rad__aabb *b)
{
    float dx = b->hi[0] - b->lo[0], dy = b->hi[1] - b->lo[1], dz = b->hi[2] - b->lo[2];
    if (dx < 0.0f) return 0.0f;
    return dx * dy + dy * dz + dz * dx;
}

RAD_API void rad_bvh_destroy(rad_bvh *bvh)
{
    rad_allocator a;
    if (!bvh) return;
    a = bvh->allocator;
    rad__free(&a, bvh->nodes);
    rad__free(&a, bvh->leaves);
    rad__free(&a, bvh);
}

RAD_API size_t rad_bvh_memory(const rad_bvh *bvh)
{
    if (!bvh) return 0;
    return sizeof(*bvh) + (size_t)bvh->node_count * sizeof(rad__bvhw) + (size_t)bvh->leaf_count * sizeof(rad__tri4);
}

/* A triangle reference of the build: its bounds and scene triangle. The build sorts these in
   place, so every pass over a node's range reads memory in order. */
typedef struct rad__bref { float lo[3], hi[3]; uint32_t id; } rad__bref;

/* bin of a centroid coordinate, in double so coordinates near +-FLT_MAX cannot overflow, and
   never converting a NaN or out-of-range value to int */
static int rad__bvh_bin(float cen, float lo, double scale)
{
    double x = ((double)cen - (double)lo) * scale;
    if (!(x > 0.0)) return 0;
    if (!(x < (double)RAD__BVH_BINS)) return RAD__BVH_BINS - 1;
    return (int)x;
}

/* the centroid coordinate of a reference (lo + hi may overflow) */
#define RAD__BREF_CEN(r, a) (0.5f * (r)->lo[a] + 0.5f * (r)->hi[a])

/* Binned SAH split of binary node 'node' over refs[first, first + count): stores its bounds and
   returns the split position (refs partitioned around it), or 0 when it stays a leaf. */
static uint32_t rad__bvh_split(rad__bvh_node *node, rad__bref *refs, uint32_t depth)
{
    uint32_t first = node->first, count = node->count, best_axis = 3, best_split = 0, mid, i;
    rad__aabb nb, cb, bins[3][RAD__BVH_BINS];
    uint32_t cnt[3][RAD__BVH_BINS];
    double scale[3];
    float best_cost = FLT_MAX;
    int axis, use[3];
    rad__aabb_empty(&nb);
    rad__aabb_empty(&cb);
    for (i = first; i < first + count; ++i) {
        const rad__bref *r = &refs[i];
        float c[3];
        c[0] = RAD__BREF_CEN(r, 0); c[1] = RAD__BREF_CEN(r, 1); c[2] = RAD__BREF_CEN(r, 2);
        rad__aabb_grow(&nb, r->lo, r->hi);
        rad__aabb_grow(&cb, c, c);
    }
    memcpy(node->bmin, nb.lo, sizeof(nb.lo));
    memcpy(node->bmax, nb.hi, sizeof(nb.hi));
    /* a leaf's triangles are tested together in one SIMD pass (rad__wray_tri4), about the cost
       of testing one: any range that fits in a leaf is one */
    if (count <= RAD__BVH_LEAF) return 0;
    /* past RAD__BVH_SAH_DEPTH levels, ranges are split in half: the depth stays below
       RAD__BVH_SAH_DEPTH + 32, so traversal stacks of RAD__BVH_STACK entries never overflow */
    for (axis = 0; axis < 3; ++axis) {
        double extent = (double)cb.hi[axis] - (double)cb.lo[axis];
        uint32_t bi;
        use[axis] = depth < RAD__BVH_SAH_DEPTH && extent > 0.0;
        scale[axis] = use[axis] ? (double)RAD__BVH_BINS / extent : 0.0;
        for (bi = 0; bi < RAD__BVH_BINS; ++bi) { rad__aabb_empty(&bins[axis][bi]); cnt[axis][bi] = 0; }
    }
    if (use[0] || use[1] || use[2]) {
        /* one pass bins all three axes */
        for (i = first; i < first + count; ++i) {
            const rad__bref *r = &refs[i];
            for (axis = 0; axis < 3; ++axis) {
                int bin = rad__bvh_bin(RAD__BREF_CEN(r, axis), cb.lo[axis], scale[axis]);
                cnt[axis][bin]++;
                rad__aabb_grow(&bins[axis][bin], r->lo, r->hi);
            }
        }
    }
    for (axis = 0; axis < 3; ++axis) {
        rad__aabb left, right;
        uint32_t right_count[RAD__BVH_BINS], lc = 0, rc = 0, bi;
        float right_area[RAD__BVH_BINS];
        if (!use[axis]) continue;
        rad__aabb_empty(&right);
        for (bi = RAD__BVH_BINS - 1; bi > 0; --bi) {
            rad__aabb_grow(&right, bins[axis][bi].lo, bins[axis][bi].hi);
            rc += cnt[axis][bi];
            right_area[bi] = rad__aabb_area(&right);
            right_count[bi] = rc;
        }
        rad__aabb_empty(&left);
        for (bi = 0; bi + 1 < RAD__BVH_BINS; ++bi) {
            float cost;
            rad__aabb_grow(&left, bins[axis][bi].lo, bins[axis][bi].hi);
            lc += cnt[axis][bi];
            if (lc == 0 || right_count[bi + 1] == 0) continue;
            cost = (float)lc * rad__aabb_area(&left) + (float)right_count[bi + 1] * right_area[bi + 1];
            if (cost < best_cost) { best_cost = cost; best_axis = (uint32_t)axis; best_split = bi + 1; }
        }
    }
    /* SAH with a traversal step costing one triangle test: stop when splitting does not pay */
    /* (ranges of at most RAD__BVH_LEAF triangles returned as leaves above) */
    if (best_axis == 3) {
        mid = first + count / 2; /* all centroids equal, or too deep: split the range */
    } else {
        uint32_t lo = first, hi = first + count;
        while (lo < hi) {
            if ((uint32_t)rad__bvh_bin(RAD__BREF_CEN(&refs[lo], best_axis), cb.lo[best_axis], scale[best_axis]) < best_split) {
                ++lo;
            } else {
                rad__bref t = refs[lo];
                --hi;
                refs[lo] = refs[hi];
                refs[hi] = t;
            }
        }
        mid = lo;
        if (mid == first || mid == first + count) mid = first + count / 2;
    }
    return mid;
}

/* Builds the subtree under binary node 'root' (at 'depth'), its nodes numbered from 'next' on
   in pairs. Returns its leaf count. */
static uint32_t rad__bvh_build_sub(rad__bvh_node *tree, rad__bref *refs, uint32_t root, uint32_t depth0, uint32_t next)
{
    uint32_t stack[4 * (RAD__BVH_SAH_DEPTH + 40)], sp = 0, leaves = 0;
    stack[sp++] = root;
    stack[sp++] = depth0;
    while (sp > 0) {
        uint32_t depth = stack[--sp], ni = stack[--sp], mid, k2, first, count;
        mid = rad__bvh_split(&tree[ni], refs, depth);
        if (!mid) { ++leaves; continue; }
        first = tree[ni].first;
        count = tree[ni].count;
        k2 = next;
        next += 2;
        tree[k2].first = first;
        tree[k2].count = mid - first;
        tree[k2 + 1].first = mid;
        tree[k2 + 1].count = first + count - mid;
        tree[ni].first = k2;
        tree[ni].count = 0;
        stack[sp++] = k2 + 1;
        stack[sp++] = depth + 1;
        stack[sp++] = k2;
        stack[sp++] = depth + 1;
    }
    return leaves;
}

typedef struct rad__bvh_job {
    rad__bvh_node *tree;
    rad__bref *refs;
    uint32_t *task_node, *task_depth, *task_leaves;
} rad__bvh_job;

static void rad__bvh_task(void *data, uint32_t i)
{
    rad__bvh_job *j = (rad__bvh_job *)data;
    uint32_t ni = j->task_node[i];
    /* a subtree over refs[first, first + count) has fewer than 2 count nodes below its root:
       numbering them from 2 first keeps every subtree in its own part of the array */
    j->task_leaves[i] = rad__bvh_build_sub(j->tree, j->refs, ni, j->task_depth[i], 2u * j->tree[ni].first);
}

/* Collapses the binary tree 'bin' into RAD__BVH_W-wide nodes: each wide node opens the largest
   inner child of its binary node until it has RAD__BVH_W children. 'stack' has room for 4
   entries per leaf. */
static rad_result rad__bvhw_collapse(rad_bvh *b, const rad__bvh_node *bin, uint32_t root, uint32_t *stack,
                                     const float *positions, const uint32_t *order)
{
    uint32_t sp = 0;
    b->node_count = 1;
    stack[sp++] = root; /* binary node */
    stack[sp++] = 0; /* its 4-wide node */
    while (sp > 0) {
        uint32_t n4 = stack[--sp], bi = stack[--sp], slots[RAD__BVH_W], ns = 0, k;
        rad__bvhw *node = &b->nodes[n4];
        if (bin[bi].count) {
            slots[ns++] = bi; /* a leaf root (tiny scenes) */
        } else {
            slots[ns++] = bin[bi].first;
            slots[ns++] = bin[bi].first + 1;
            while (ns < RAD__BVH_W) {
                float best = -1.0f;
                uint32_t bk = RAD__BVH_W;
                for (k = 0; k < ns; ++k) {
                    const rad__bvh_node *q = &bin[slots[k]];
                    float dx = q->bmax[0] - q->bmin[0], dy = q->bmax[1] - q->bmin[1], dz = q->bmax[2] - q->bmin[2];
                    float area = dx * dy + dy * dz + dz * dx;
                    if (q->count == 0 && area > best) { best = area; bk = k; }
                }
                if (bk == RAD__BVH_W) break;
                slots[ns++] = bin[slots[bk]].first + 1;
                slots[bk] = bin[slots[bk]].first;
            }
        }
        for (k = 0; k < RAD__BVH_W; ++k) {
            int a;
            if (k >= ns) {
                for (a = 0; a < 3; ++a) { node->lo[a][k] = 0.0f; node->hi[a][k] = 0.0f; }
                node->child[k] = RAD_NONE;
                node->count[k] = 0;
                continue;
            }
            for (a = 0; a < 3; ++a) { node->lo[a][k] = bin[slots[k]].bmin[a]; node->hi[a][k] = bin[slots[k]].bmax[a]; }
            if (bin[slots[k]].count) {
                rad__tri4 *q = &b->leaves[b->leaf_count];
                uint32_t j, c;
                memset(q, 0, sizeof(*q));
                for (j = 0; j < 4; ++j) q->id[j] = RAD_NONE;
                for (j = 0; j < bin[slots[k]].count; ++j) {
                    const float *v = positions + 9 * (size_t)order[bin[slots[k]].first + j];
                    for (c = 0; c < 3; ++c)
                        for (a = 0; a < 3; ++a) q->v[c][a][j] = v[3 * c + (uint32_t)a];
                    q->id[j] = order[bin[slots[k]].first + j];
                }
                node->child[k] = RAD__BVH4_LEAF | b->leaf_count++;
                node->count[k] = bin[slots[k]].count;
            } else {
                uint32_t m = b->node_count++;
                node->child[k] = m;
                node->count[k] = 0;
                stack[sp++] = slots[k];
                stack[sp++] = m;
                node = &b->nodes[n4];
            }
        }
    }
    return RAD_SUCCESS;
}

RAD_API rad_result rad_bvh_create(const rad_scene *scene, const rad_context *ctx, rad_bvh **out)
{
    rad__ctx c;
    rad_bvh *b;
    rad__bvh_node *tree = NULL;
    rad__bref *refs = NULL;
    uint32_t n, i, sp = 0, top, tasks = 0, leaves = 0, threshold, root;
    uint32_t *stack = NULL, *task_node = NULL, *task_depth = NULL, *task_leaves = NULL, *order = NULL;
    rad_result r;
    rad__ctx_init(&c, ctx);
    if (!out) return RAD_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    if (!scene || scene->triangle_count == 0) return RAD_ERROR_INVALID_ARGUMENT;
    n = scene->triangle_count;
    if (n >= RAD__BVH4_LEAF / 4u) {
        rad__log(&c, RAD_LOG_ERROR, "the built-in BVH holds at most %u triangles", RAD__BVH4_LEAF / 4u - 1u);
        return RAD_ERROR_SIZE_OVERFLOW;
    }
    b = (rad_bvh *)rad__alloc(&c.allocator, sizeof(rad_bvh));
    if (!b) return RAD_ERROR_OUT_OF_MEMORY;
    memset(b, 0, sizeof(*b));
    b->allocator = c.allocator;
    b->tri_count = n;
    /* subtrees number their nodes below 2 n (rad__bvh_task), the top levels from 2 n on */
    tree = (rad__bvh_node *)rad__alloc_array(&c.allocator, 4u * (size_t)n + 2u, sizeof(rad__bvh_node));
    refs = (rad__bref *)rad__alloc_array(&c.allocator, n, sizeof(rad__bref));
    stack = (uint32_t *)rad__alloc_array(&c.allocator, 4u * (size_t)n + 4u, sizeof(uint32_t));
    task_node = (uint32_t *)rad__alloc_array(&c.allocator, 3u * (size_t)n, sizeof(uint32_t));
    order = (uint32_t *)rad__alloc_array(&c.allocator, n, sizeof(uint32_t));
    if (!tree || !refs || !stack || !task_node || !order) {
        rad__free(&c.allocator, refs); rad__free(&c.allocator, stack); rad__free(&c.allocator, tree);
        rad__free(&c.allocator, task_node); rad__free(&c.allocator, order);
        rad_bvh_destroy(b);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    task_depth = task_node + n;
    task_leaves = task_node + 2u * (size_t)n;
    for (i = 0; i < n; ++i) {
        const float *v = scene->positions + 9 * (size_t)i;
        int k;
        for (k = 0; k < 3; ++k) {
            float lo = v[k], hi = v[k];
            if (v[3 + k] < lo) lo = v[3 + k];
            if (v[6 + k] < lo) lo = v[6 + k];
            if (v[3 + k] > hi) hi = v[3 + k];
            if (v[6 + k] > hi) hi = v[6 + k];
            refs[i].lo[k] = lo;
            refs[i].hi[k] = hi;
        }
        refs[i].id = i;
    }
    /* the top levels one node at a time, down to subtrees small enough to balance the threads;
       those are then built in parallel (the tree does not depend on the thread count) */
    threshold = n / 64u > 1024u ? n / 64u : 1024u;
    root = top = 2u * n;
    tree[root].first = 0;
    tree[root].count = n;
    top++;
    stack[sp++] = root;
    stack[sp++] = 0;
    while (sp > 0) {
        uint32_t depth = stack[--sp], ni = stack[--sp], mid, first, count;
        if (tree[ni].count <= threshold) {
            task_node[tasks] = ni;
            task_depth[tasks++] = depth;
            continue;
        }
        mid = rad__bvh_split(&tree[ni], refs, depth);
        if (!mid) { ++leaves; continue; }
        first = tree[ni].first;
        count = tree[ni].count;
        tree[top].first = first;
        tree[top].count = mid - first;
        tree[top + 1].first = mid;
        tree[top + 1].count = first + count - mid;
        tree[ni].first = top;
        tree[ni].count = 0;
        stack[sp++] = top + 1;
        stack[sp++] = depth + 1;
        stack[sp++] = top;
        stack[sp++] = depth + 1;
        top += 2;
    }
    if (tasks > 0) {
        rad__bvh_job job;
        job.tree = tree;
        job.refs = refs;
        job.task_node = task_node;
        job.task_depth = task_depth;
        job.task_leaves = task_leaves;
        if (tasks == 1) rad__bvh_task(&job, 0);
        else c.parallel_for(c.parallel_user, tasks, rad__bvh_task, &job);
        for (i = 0; i < tasks; ++i) leaves += task_leaves[i];
    }
    for (i = 0; i < n; ++i) order[i] = refs[i].id;
    /* a binary tree of L leaves has L - 1 inner nodes, and each 4-wide node opens at least one
       of them (or is the root leaf of a one-leaf tree) */
    b->nodes = (rad__bvhw *)rad__alloc_array(&c.allocator, leaves, sizeof(rad__bvhw));
    b->leaves = (rad__tri4 *)rad__alloc_array(&c.allocator, leaves, sizeof(rad__tri4));
    r = (b->nodes && b->leaves) ? rad__bvhw_collapse(b, tree, root, stack, scene->positions, order) : RAD_ERROR_OUT_OF_MEMORY;
    rad__free(&c.allocator, refs);
    rad__free(&c.allocator, stack);
    rad__free(&c.allocator, task_node);
    rad__free(&c.allocator, order);
    rad__free(&c.allocator, tree);
    if (r != RAD_SUCCESS) { rad_bvh_destroy(b); return r; }
    *out = b;
    return RAD_SUCCESS;
}

/* Per-ray constants of the watertight test (Woop, Benthin, Wald 2013). */
typedef struct rad__wray {
    float o[3], d[3], inv[3];
    float sx, sy, sz;
    int kx, ky, kz;
    float tmin, tmax;
} rad__wray;

static void rad__wray_init(rad__wray *w, const rad_ray *r)
{
    float ax = (float)fabs((double)r->dir[0]), ay = (float)fabs((double)r->dir[1]), az = (float)fabs((double)r->dir[2]);
    int k;
    for (k = 0; k < 3; ++k) {
        w->o[k] = r->origin[k];
        w->d[k] = r->dir[k];
        w->inv[k] = 1.0f / r->dir[k]; /* +-inf for 0: the slab test handles it */
    }
    w->kz = (ax > ay) ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
    w->kx = (w->kz + 1) % 3;
    w->ky = (w->kx + 1) % 3;
    if (w->d[w->kz] < 0.0f) { int t = w->kx; w->kx = w->ky; w->ky = t; }
    w->sx = w->d[w->kx] / w->d[w->kz];
    w->sy = w->d[w->ky] / w->d[w->kz];
    w->sz = 1.0f / w->d[w->kz];
    w->tmin = r->tmin;
    w->tmax = r->tmax;
}

#if !defined(RAD__SSE2)
/* Watertight ray/triangle test, both faces. Returns 1 with t, b1, b2 on a hit in (tmin, tmax).
   rad__wray_tri4 performs the same operations on four triangles at once with SIMD. */
static int rad__wray_tri(const rad__wray *w, const float *v, float tmax, float *t_out, float *b1, float *b2)
{
    float A[3], B[3], C[3], Ax, Ay, Bx, By, Cx, Cy, U, V, W, det, T;
    int k;
    for (k = 0; k < 3; ++k) { A[k] = v[k] - w->o[k]; B[k] = v[3 + k] - w->o[k]; C[k] = v[6 + k] - w->o[k]; }
    Ax = A[w->kx] - w->sx * A[w->kz]; Ay = A[w->ky] - w->sy * A[w->kz];
    Bx = B[w->kx] - w->sx * B[w->kz]; By = B[w->ky] - w->sy * B[w->kz];
    Cx = C[w->kx] - w->sx * C[w->kz]; Cy = C[w->ky] - w->sy * C[w->kz];
    /* Each product its own statement: a compiler may fuse a * b - c * d into one FMA, which
       breaks the antisymmetry of a shared edge's test between its two triangles by up to one
       rounding, and rays slip between them. Standard C fuses only within an expression, but
       gcc with -std=gnu* (and any compiler with -ffp-contract=fast) fuses across statements,
       so with FMA hardware any result within rounding of 0 is redone too. The redo is in
       double, where a product of two floats is exact. */
    {
        float cb = Cx * By, cy = Cy * Bx, ac = Ax * Cy, ay = Ay * Cx, ba = Bx * Ay, bb = By * Ax;
        U = cb - cy;
        V = ac - ay;
        W = ba - bb;
#if defined(__FMA__)
        if (fabsf(U) <= 1.2e-7f * (fabsf(cb) + fabsf(cy)) || fabsf(V) <= 1.2e-7f * (fabsf(ac) + fabsf(ay)) ||
            fabsf(W) <= 1.2e-7f * (fabsf(ba) + fabsf(bb)))
#else
        if (U == 0.0f || V == 0.0f || W == 0.0f)
#endif
        {
            U = (float)((double)Cx * (double)By - (double)Cy * (double)Bx);
            V = (float)((double)Ax * (double)Cy - (double)Ay * (double)Cx);
            W = (float)((double)Bx * (double)Ay - (double)By * (double)Ax);
        }
    }
    if ((U < 0.0f || V < 0.0f || W < 0.0f) && (U > 0.0f || V > 0.0f || W > 0.0f)) return 0;
    det = U + V + W;
    if (det == 0.0f) return 0;
    /* U, V, W scale as length^2, so the numerator of t (length^3) is formed in double: in
       float it overflows beyond scenes of about 1e12 and underflows below 1e-13 */
    T = (float)(((double)U * (double)(w->sz * A[w->kz]) + (double)V * (double)(w->sz * B[w->kz]) +
                 (double)W * (double)(w->sz * C[w->kz])) / (double)det);
    if (!(T > w->tmin && T < tmax)) return 0;
    *t_out = T;
    *b1 = V / det;
    *b2 = W / det;
    return 1;
}
#endif

/* Slab test of a ray against the child boxes of a node: bit k of the result is set when
   child k is hit within [tmin, tmax]; tnear[k] receives its entry distance. Zero direction
   components were replaced by +-1e-30 in inv (no NaN from 0 * inf). Each slab's far distance
   is widened by 1 + 2 gamma_3 (Ize 2013), so rounding never culls a box the ray touches (rays
   through shared vertices on box faces). */
static int rad__bvhw_boxes(const rad__bvhw *n, const float *o, const float *inv, float tmin, float tmax, float *tnear)
{
#if defined(RAD__AVX)
    __m256 t0 = _mm256_set1_ps(tmin), t1 = _mm256_set1_ps(tmax * 1.0000004f + 1e-30f), widen = _mm256_set1_ps(1.0000004f);
    int a;
    for (a = 0; a < 3; ++a) {
        __m256 oa = _mm256_set1_ps(o[a]), ia = _mm256_set1_ps(inv[a]);
        __m256 x = _mm256_mul_ps(_mm256_sub_ps(_mm256_loadu_ps(n->lo[a]), oa), ia);
        __m256 y = _mm256_mul_ps(_mm256_sub_ps(_mm256_loadu_ps(n->hi[a]), oa), ia);
        t0 = _mm256_max_ps(t0, _mm256_min_ps(x, y));
        t1 = _mm256_min_ps(t1, _mm256_mul_ps(_mm256_max_ps(x, y), widen));
    }
    _mm256_storeu_ps(tnear, t0);
    return _mm256_movemask_ps(_mm256_cmp_ps(t0, t1, _CMP_LE_OQ));
#elif defined(RAD__SSE2)
    __m128 t0 = _mm_set1_ps(tmin), t1 = _mm_set1_ps(tmax * 1.0000004f + 1e-30f), widen = _mm_set1_ps(1.0000004f);
    int a;
    for (a = 0; a < 3; ++a) {
        __m128 oa = _mm_set1_ps(o[a]), ia = _mm_set1_ps(inv[a]);
        __m128 x = _mm_mul_ps(_mm_sub_ps(_mm_loadu_ps(n->lo[a]), oa), ia);
        __m128 y = _mm_mul_ps(_mm_sub_ps(_mm_loadu_ps(n->hi[a]), oa), ia);
        t0 = _mm_max_ps(t0, _mm_min_ps(x, y));
        t1 = _mm_min_ps(t1, _mm_mul_ps(_mm_max_ps(x, y), widen));
    }
    _mm_storeu_ps(tnear, t0);
    return _mm_movemask_ps(_mm_cmple_ps(t0, t1));
#else
    int k, a, mask = 0;
    for (k = 0; k < RAD__BVH_W; ++k) {
        float t0 = tmin, t1 = tmax * 1.0000004f + 1e-30f;
        for (a = 0; a < 3; ++a) {
            float x = (n->lo[a][k] - o[a]) * inv[a], y = (n->hi[a][k] - o[a]) * inv[a];
            float lo = x < y ? x : y, hi = (x < y ? y : x) * 1.0000004f;
            if (lo > t0) t0 = lo;
            if (hi < t1) t1 = hi;
        }
        tnear[k] = t0;
        if (t0 <= t1) mask |= 1 << k;
    }
    return mask;
#endif
}

/* index of the lowest set bit of a nonzero mask */
static uint32_t rad__low_bit(uint32_t m)
{
#if defined(__GNUC__) || defined(__clang__)
    return (uint32_t)__builtin_ctz(m);
#else
    uint32_t k = 0;
    while (!(m & 1u)) { m >>= 1; ++k; }
    return k;
#endif
}

/* The triangles of leaf q (count of them) against the ray, in lane order, as rad__wray_tri
   would test them one by one: returns the last lane that hit (each hit lowers *tmax, so it is
   the closest, the first of equal ones), or -1. With 'any' it returns at the first hit. */
static int rad__wray_tri4(const rad__wray *w, const rad__tri4 *q, uint32_t count, int any, float *tmax, float *t_out,
                          float *b1, float *b2)
{
#if defined(RAD__SSE2)
    /* the vertex transform and the edge functions of rad__wray_tri, four triangles per
       instruction; each lane performs the same operations as the scalar test, so a vertex or
       an edge shared by two triangles gets the same values in every lane (watertight) */
    __m128 sx = _mm_set1_ps(w->sx), sy = _mm_set1_ps(w->sy), zero = _mm_setzero_ps();
    __m128 ox = _mm_set1_ps(w->o[w->kx]), oy = _mm_set1_ps(w->o[w->ky]), oz = _mm_set1_ps(w->o[w->kz]);
    __m128 Az = _mm_sub_ps(_mm_loadu_ps(q->v[0][w->kz]), oz), Bz = _mm_sub_ps(_mm_loadu_ps(q->v[1][w->kz]), oz),
           Cz = _mm_sub_ps(_mm_loadu_ps(q->v[2][w->kz]), oz);
    __m128 Ax = _mm_sub_ps(_mm_sub_ps(_mm_loadu_ps(q->v[0][w->kx]), ox), _mm_mul_ps(sx, Az));
    __m128 Ay = _mm_sub_ps(_mm_sub_ps(_mm_loadu_ps(q->v[0][w->ky]), oy), _mm_mul_ps(sy, Az));
    __m128 Bx = _mm_sub_ps(_mm_sub_ps(_mm_loadu_ps(q->v[1][w->kx]), ox), _mm_mul_ps(sx, Bz));
    __m128 By = _mm_sub_ps(_mm_sub_ps(_mm_loadu_ps(q->v[1][w->ky]), oy), _mm_mul_ps(sy, Bz));
    __m128 Cx = _mm_sub_ps(_mm_sub_ps(_mm_loadu_ps(q->v[2][w->kx]), ox), _mm_mul_ps(sx, Cz));
    __m128 Cy = _mm_sub_ps(_mm_sub_ps(_mm_loadu_ps(q->v[2][w->ky]), oy), _mm_mul_ps(sy, Cz));
    __m128 cb = _mm_mul_ps(Cx, By), cy = _mm_mul_ps(Cy, Bx), ac = _mm_mul_ps(Ax, Cy), ay = _mm_mul_ps(Ay, Cx);
    __m128 ba = _mm_mul_ps(Bx, Ay), bb = _mm_mul_ps(By, Ax);
    __m128 U = _mm_sub_ps(cb, cy), V = _mm_sub_ps(ac, ay), W = _mm_sub_ps(ba, bb), redo;
    float u[4], v[4], ww[4], az[4], bz[4], cz[4];
    int lanes = (1 << count) - 1, hit_mask, redo_mask, found = -1, j;
#if defined(__FMA__)
    {
        /* as in rad__wray_tri: the compiler may fuse these products into FMAs, so any result
           within rounding of zero is redone in double */
        __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff)), eps = _mm_set1_ps(1.2e-7f);
        redo = _mm_or_ps(_mm_or_ps(_mm_cmple_ps(_mm_and_ps(U, abs_mask),
                                                _mm_mul_ps(eps, _mm_add_ps(_mm_and_ps(cb, abs_mask), _mm_and_ps(cy, abs_mask)))),
                                   _mm_cmple_ps(_mm_and_ps(V, abs_mask),
                                                _mm_mul_ps(eps, _mm_add_ps(_mm_and_ps(ac, abs_mask), _mm_and_ps(ay, abs_mask))))),
                         _mm_cmple_ps(_mm_and_ps(W, abs_mask),
                                      _mm_mul_ps(eps, _mm_add_ps(_mm_and_ps(ba, abs_mask), _mm_and_ps(bb, abs_mask)))));
    }
#else
    redo = _mm_or_ps(_mm_or_ps(_mm_cmpeq_ps(U, zero), _mm_cmpeq_ps(V, zero)), _mm_cmpeq_ps(W, zero));
#endif
    redo_mask = _mm_movemask_ps(redo) & lanes;
    /* a lane is out when its edge functions have both signs (a NaN makes every compare false) */
    hit_mask = ~_mm_movemask_ps(_mm_and_ps(_mm_or_ps(_mm_or_ps(_mm_cmplt_ps(U, zero), _mm_cmplt_ps(V, zero)), _mm_cmplt_ps(W, zero)),
                                           _mm_or_ps(_mm_or_ps(_mm_cmpgt_ps(U, zero), _mm_cmpgt_ps(V, zero)), _mm_cmpgt_ps(W, zero)))) &
               lanes;
    if (!(hit_mask | redo_mask)) return -1;
    _mm_storeu_ps(u, U); _mm_storeu_ps(v, V); _mm_storeu_ps(ww, W);
    _mm_storeu_ps(az, Az); _mm_storeu_ps(bz, Bz); _mm_storeu_ps(cz, Cz);
    if (redo_mask) {
        float xa[4], ya[4], xb[4], yb[4], xc[4], yc[4];
        _mm_storeu_ps(xa, Ax); _mm_storeu_ps(ya, Ay); _mm_storeu_ps(xb, Bx);
        _mm_storeu_ps(yb, By); _mm_storeu_ps(xc, Cx); _mm_storeu_ps(yc, Cy);
        for (j = 0; j < 4; ++j) {
            if (!(redo_mask & (1 << j))) continue;
            u[j] = (float)((double)xc[j] * (double)yb[j] - (double)yc[j] * (double)xb[j]);
            v[j] = (float)((double)xa[j] * (double)yc[j] - (double)ya[j] * (double)xc[j]);
            ww[j] = (float)((double)xb[j] * (double)ya[j] - (double)yb[j] * (double)xa[j]);
            if ((u[j] < 0.0f || v[j] < 0.0f || ww[j] < 0.0f) && (u[j] > 0.0f || v[j] > 0.0f || ww[j] > 0.0f))
                hit_mask &= ~(1 << j);
            else
                hit_mask |= 1 << j;
        }
    }
    for (j = 0; j < 4; ++j) {
        float det, T;
        if (!(hit_mask & (1 << j))) continue;
        det = u[j] + v[j] + ww[j];
        if (det == 0.0f) continue;
        T = (float)(((double)u[j] * (double)(w->sz * az[j]) + (double)v[j] * (double)(w->sz * bz[j]) +
                     (double)ww[j] * (double)(w->sz * cz[j])) / (double)det);
        if (!(T > w->tmin && T < *tmax)) continue;
        *tmax = *t_out = T;
        *b1 = v[j] / det;
        *b2 = ww[j] / det;
        found = j;
        if (any) break;
    }
    return found;
#else
    float tri[9], t, c1, c2;
    int found = -1;
    uint32_t j, c, a;
    for (j = 0; j < count; ++j) {
        for (c = 0; c < 3; ++c)
            for (a = 0; a < 3; ++a) tri[3 * c + a] = q->v[c][a][j];
        if (!rad__wray_tri(w, tri, *tmax, &t, &c1, &c2)) continue;
        *tmax = *t_out = t;
        *b1 = c1;
        *b2 = c2;
        found = (int)j;
        if (any) break;
    }
    return found;
#endif
}

static int rad__bvh_trace(const rad_bvh *bvh, const rad_ray *ray, int any, rad_hit *hit)
{
    rad__wray w;
    /* a node pushes at most RAD__BVH_W - 1 children more than it pops, once per level */
    uint32_t stack[(RAD__BVH_W - 1) * RAD__BVH_STACK], sp = 0;
    float stack_t[(RAD__BVH_W - 1) * RAD__BVH_STACK], tmax = ray->tmax, inv[3];
    int found = 0, a;
    if (!(ray->tmax > ray->tmin)) return 0;
    rad__wray_init(&w, ray);
    for (a = 0; a < 3; ++a) {
        float d = ray->dir[a];
        if (fabs((double)d) < 1e-30) d = d < 0.0f ? -1e-30f : 1e-30f;
        inv[a] = 1.0f / d;
    }
    stack[sp] = 0;
    stack_t[sp++] = ray->tmin;
    while (sp > 0) {
        const rad__bvhw *n;
        float tn[RAD__BVH_W];
        uint32_t order[RAD__BVH_W], no = 0, k, ni;
        int mask;
        --sp;
        if (stack_t[sp] > tmax) continue; /* entered beyond the closest hit found since */
        ni = stack[sp];
        n = &bvh->nodes[ni];
        mask = rad__bvhw_boxes(n, w.o, inv, ray->tmin, tmax, tn);
        while (mask) {
            uint32_t ch;
            k = rad__low_bit((uint32_t)mask);
            mask &= mask - 1;
            ch = n->child[k];
            if (ch == RAD_NONE) continue;
            if (ch & RAD__BVH4_LEAF) {
                const rad__tri4 *q = &bvh->leaves[ch & ~RAD__BVH4_LEAF];
                float t = 0.0f, b1 = 0.0f, b2 = 0.0f;
                int j = rad__wray_tri4(&w, q, n->count[k], any, &tmax, &t, &b1, &b2);
                if (j >= 0) {
                    found = 1;
                    if (any) return 1;
                    hit->t = t;
                    hit->triangle = q->id[j];
                    hit->b1 = b1;
                    hit->b2 = b2;
                }
            } else {
                order[no++] = k;
            }
        }
        /* push inner children far to near, so the nearest is visited first */
        if (no == 1) {
            stack[sp] = n->child[order[0]];
            stack_t[sp++] = tn[order[0]];
            continue;
        }
        while (no > 0) {
            uint32_t far = 0, q;
            for (q = 1; q < no; ++q)
                if (tn[order[q]] > tn[order[far]]) far = q;
            stack[sp] = n->child[order[far]];
            stack_t[sp++] = tn[order[far]];
            order[far] = order[--no];
        }
    }
    return found;
}

static rad_result rad__bvh_occluded(void *user, const rad_ray *rays, uint32_t count, uint8_t *out)
{
    const rad_bvh *bvh = (const rad_bvh *)user;
    uint32_t i;
    rad_hit h;
    for (i = 0; i < count; ++i) out[i] = (uint8_t)rad__bvh_trace(bvh, &rays[i], 1, &h);
    return RAD_SUCCESS;
}

static rad_result rad__bvh_intersect(void *user, const rad_ray *rays, uint32_t count, rad_hit *out)
{
    const rad_bvh *bvh = (const rad_bvh *)user;
    uint32_t i;
    for (i = 0; i < count; ++i) {
        out[i].t = rays[i].tmax;
        out[i].triangle = RAD_NONE;
        out[i].b1 = out[i].b2 = 0.0f;
        rad__bvh_trace(bvh, &rays[i], 0, &out[i]);
    }
    return RAD_SUCCESS;
}

RAD_API void rad_bvh_raycaster(const rad_bvh *bvh, rad_raycaster *out)
{
    if (!out) return;
    out->user = (void *)(uintptr_t)bvh;
    out->occluded = rad__bvh_occluded;
    out->intersect = rad__bvh_intersect;
}

/* ---- Embree 3 backend ---- */

#ifdef RAD_EMBREE
#include <embree3/rtcore.h>

struct rad_embree {
    RTCDevice device;        /* NULL for a wrapped scene */
    RTCScene scene;
    uint32_t *first;         /* per geometry: first triangle (wrapped scenes), or NULL */
    uint32_t geometry_count;
    rad_allocator allocator;
    void (*log)(void *user, rad_log_level level, const char *message);
    void *log_user;
    size_t memory;           /* device memory reported by the monitor (bytes, >= 0) */
};

static void rad__embree_error(void *user, enum RTCError code, const char *str)
{
    rad_embree *e = (rad_embree *)user;
    char buf[512];
    if (!e || !e->log) return;
    snprintf(buf, sizeof(buf), "Embree error %d: %s", (int)code, str ? str : "");
    e->log(e->log_user, RAD_LOG_ERROR, buf);
}

static bool rad__embree_monitor(void *user, ssize_t bytes, bool post)
{
    rad_embree *e = (rad_embree *)user;
    (void)post;
    /* called from Embree's build threads: a plain counter, read only after the build */
    if (bytes > 0) e->memory += (size_t)bytes;
    else if ((size_t)(-bytes) <= e->memory) e->memory -= (size_t)(-bytes);
    return true;
}

RAD_API int rad_embree_available(void) { return 1; }

RAD_API void rad_embree_destroy(rad_embree *e)
{
    rad_allocator a;
    if (!e) return;
    a = e->allocator;
    if (e->device) {
        if (e->scene) rtcReleaseScene(e->scene);
        rtcReleaseDevice(e->device);
    }
    rad__free(&a, e->first);
    rad__free(&a, e);
}

RAD_API rad_result rad_embree_create(const rad_scene *scene, const rad_context *ctx, rad_embree **out)
{
    rad__ctx c;
    rad_embree *e;
    RTCGeometry g;
    float *v;
    unsigned int *idx;
    uint32_t t;
    rad__ctx_init(&c, ctx);
    if (!out) return RAD_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    if (!scene || scene->triangle_count == 0) return RAD_ERROR_INVALID_ARGUMENT;
    e = (rad_embree *)rad__alloc(&c.allocator, sizeof(rad_embree));
    if (!e) return RAD_ERROR_OUT_OF_MEMORY;
    memset(e, 0, sizeof(*e));
    e->allocator = c.allocator;
    e->log = c.log;
    e->log_user = c.log_user;
    e->device = rtcNewDevice(NULL);
    if (!e->device) {
        rad__log(&c, RAD_LOG_ERROR, "rtcNewDevice failed (Embree error %d)", (int)rtcGetDeviceError(NULL));
        rad__free(&c.allocator, e);
        return RAD_ERROR_RAYCAST_FAILED;
    }
    rtcSetDeviceErrorFunction(e->device, rad__embree_error, e);
    rtcSetDeviceMemoryMonitorFunction(e->device, rad__embree_monitor, e);
    e->scene = rtcNewScene(e->device);
    g = rtcNewGeometry(e->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (!e->scene || !g) { rad_embree_destroy(e); return RAD_ERROR_RAYCAST_FAILED; }
    rtcSetSceneFlags(e->scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(e->scene, RTC_BUILD_QUALITY_HIGH);
    /* Embree-owned buffers: Embree pads them for its 16-byte loads */
    v = (float *)rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                         3 * (size_t)scene->triangle_count);
    idx = (unsigned int *)rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned int),
                                                  scene->triangle_count);
    if (!v || !idx) { rtcReleaseGeometry(g); rad_embree_destroy(e); return RAD_ERROR_OUT_OF_MEMORY; }
    memcpy(v, scene->positions, 9 * sizeof(float) * (size_t)scene->triangle_count);
    for (t = 0; t < 3 * scene->triangle_count; ++t) idx[t] = t;
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(e->scene, g, 0);
    rtcReleaseGeometry(g);
    rtcCommitScene(e->scene);
    if (rtcGetDeviceError(e->device) != RTC_ERROR_NONE) { rad_embree_destroy(e); return RAD_ERROR_RAYCAST_FAILED; }
    *out = e;
    return RAD_SUCCESS;
}

RAD_API rad_result rad_embree_wrap(void *rtc_scene, const uint32_t *first_triangle, uint32_t geometry_count,
                                   const rad_context *ctx, rad_embree **out)
{
    rad__ctx c;
    rad_embree *e;
    rad__ctx_init(&c, ctx);
    if (!out) return RAD_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    if (!rtc_scene || (first_triangle && geometry_count == 0)) return RAD_ERROR_INVALID_ARGUMENT;
    e = (rad_embree *)rad__alloc(&c.allocator, sizeof(rad_embree));
    if (!e) return RAD_ERROR_OUT_OF_MEMORY;
    memset(e, 0, sizeof(*e));
    e->allocator = c.allocator;
    e->scene = (RTCScene)rtc_scene;
    if (first_triangle) {
        e->first = (uint32_t *)rad__alloc_array(&c.allocator, geometry_count, sizeof(uint32_t));
        if (!e->first) { rad__free(&c.allocator, e); return RAD_ERROR_OUT_OF_MEMORY; }
        memcpy(e->first, first_triangle, sizeof(uint32_t) * geometry_count);
        e->geometry_count = geometry_count;
    }
    *out = e;
    return RAD_SUCCESS;
}

RAD_API size_t rad_embree_memory(const rad_embree *e) { return e ? e->memory : 0; }

static void rad__embree_ray(const rad_ray *r, struct RTCRay *er)
{
    er->org_x = r->origin[0]; er->org_y = r->origin[1]; er->org_z = r->origin[2];
    er->dir_x = r->dir[0]; er->dir_y = r->dir[1]; er->dir_z = r->dir[2];
    er->tnear = r->tmin;
    er->tfar = r->tmax;
    er->time = 0.0f;
    er->mask = 0xFFFFFFFFu;
    er->id = 0;
    er->flags = 0;
}

/* Embree accepts only rays it considers valid (debug builds assert): 1 = pass it on,
   0 = NaN/Inf or empty interval (a miss, as for the built-in BVH), -1 = finite but outside
   Embree's range (coordinates beyond about 1.8e18, or tmin < 0): reported as an error. */
static int rad__embree_ray_ok(const rad_embree *e, const rad_ray *r)
{
    int k;
    for (k = 0; k < 3; ++k)
        if (!rad__finite(r->origin[k]) || !rad__finite(r->dir[k])) return 0;
    if (r->tmin != r->tmin || r->tmax != r->tmax || !(r->tmax > r->tmin)) return 0;
    for (k = 0; k < 3; ++k)
        if (fabs((double)r->origin[k]) > 1.8e18 || fabs((double)r->dir[k]) > 1.8e18) break;
    if (k < 3 || r->tmin < 0.0f) {
        if (e->log) e->log(e->log_user, RAD_LOG_ERROR, "Embree: a ray has tmin < 0 or a coordinate beyond 1.8e18 (Embree's range)");
        return -1;
    }
    return 1;
}

static rad_result rad__embree_occluded(void *user, const rad_ray *rays, uint32_t count, uint8_t *out)
{
    const rad_embree *e = (const rad_embree *)user;
    struct RTCIntersectContext ic;
    uint32_t i;
    rtcInitIntersectContext(&ic);
    for (i = 0; i < count; ++i) {
        struct RTCRay er;
        int ok = rad__embree_ray_ok(e, &rays[i]);
        if (ok < 0) return RAD_ERROR_RAYCAST_FAILED;
        if (ok == 0) { out[i] = 0; continue; }
        rad__embree_ray(&rays[i], &er);
        rtcOccluded1(e->scene, &ic, &er);
        out[i] = (uint8_t)(er.tfar < 0.0f && er.tfar == -INFINITY);
    }
    return RAD_SUCCESS;
}

static rad_result rad__embree_intersect(void *user, const rad_ray *rays, uint32_t count, rad_hit *out)
{
    const rad_embree *e = (const rad_embree *)user;
    struct RTCIntersectContext ic;
    uint32_t i;
    rtcInitIntersectContext(&ic);
    for (i = 0; i < count; ++i) {
        struct RTCRayHit rh;
        int ok = rad__embree_ray_ok(e, &rays[i]);
        out[i].t = rays[i].tmax;
        out[i].triangle = RAD_NONE;
        out[i].b1 = out[i].b2 = 0.0f;
        if (ok < 0) return RAD_ERROR_RAYCAST_FAILED;
        if (ok == 0) continue;
        rad__embree_ray(&rays[i], &rh.ray);
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(e->scene, &ic, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
        if (e->first && rh.hit.geomID >= e->geometry_count) continue;
        out[i].t = rh.ray.tfar;
        out[i].triangle = (e->first ? e->first[rh.hit.geomID] : 0u) + rh.hit.primID;
        out[i].b1 = rh.hit.u;
        out[i].b2 = rh.hit.v;
    }
    return RAD_SUCCESS;
}

RAD_API void rad_embree_raycaster(const rad_embree *e, rad_raycaster *out)
{
    if (!out) return;
    out->user = (void *)(uintptr_t)e;
    out->occluded = e ? rad__embree_occluded : NULL;
    out->intersect = e ? rad__embree_intersect : NULL;
}

#else /* !RAD_EMBREE */

RAD_API int rad_embree_available(void) { return 0; }
RAD_API rad_result rad_embree_create(const rad_scene *scene, const rad_context *ctx, rad_embree **out)
{
    (void)scene; (void)ctx;
    if (out) *out = NULL;
    return RAD_ERROR_UNAVAILABLE;
}
RAD_API rad_result rad_embree_wrap(void *rtc_scene, const uint32_t *first_triangle, uint32_t geometry_count,
                                   const rad_context *ctx, rad_embree **out)
{
    (void)rtc_scene; (void)first_triangle; (void)geometry_count; (void)ctx;
    if (out) *out = NULL;
    return RAD_ERROR_UNAVAILABLE;
}
RAD_API void rad_embree_destroy(rad_embree *embree) { (void)embree; }
RAD_API void rad_embree_raycaster(const rad_embree *embree, rad_raycaster *out)
{
    (void)embree;
    if (!out) return;
    out->user = NULL;
    out->occluded = NULL;
    out->intersect = NULL;
}
RAD_API size_t rad_embree_memory(const rad_embree *embree) { (void)embree; return 0; }

#endif /* RAD_EMBREE */



RAD_API void rad_camera_ray(const rad_camera *cam, uint32_t width, uint32_t height, float px, float py, rad_ray *out)
{
    float f[3], r[3], u[3], h, x, y;
    int k;
    if (!out) return;
    memset(out, 0, sizeof(*out));
    if (!cam || width == 0 || height == 0) return;
    rad__sub(f, cam->target, cam->position);
    rad__normalize(f);
    rad__cross(r, f, cam->up);
    rad__normalize(r);
    rad__cross(u, r, f);
    h = (float)tan(0.5 * (double)cam->fov_y_degrees * RAD__PI / 180.0);
    x = (2.0f * px / (float)width - 1.0f) * h * (float)width / (float)height;
    y = (1.0f - 2.0f * py / (float)height) * h;
    for (k = 0; k < 3; ++k) {
        out->origin[k] = cam->position[k];
        out->dir[k] = f[k] + x * r[k] + y * u[k];
    }
    rad__normalize(out->dir);
    out->tmin = 0.0f;
    out->tmax = FLT_MAX;
}

/* ======================================================================================== */
/* >>formfactor: form factors                                                               */
/* ======================================================================================== */

#define RAD__HC_DEFAULT_RES 128u
#define RAD__HC_MIN_RES 4u
#define RAD__HC_MAX_RES 2048u
/* scratch of all the tasks' hemicubes together: fewer tasks above it (the results do not
   depend on the task count) */
#define RAD__HC_SCRATCH_BYTES ((size_t)256 << 20)
#define RAD__HC_NONE 0xFFFFFFFFu  /* a cell that sees nothing */
#define RAD__HC_BACK 0xFFFFFFFEu  /* a cell that sees a patch from behind: counts for no column */

/* Contour integral over one convex polygon q (points relative to the receiver point, in its
   upper half-space), against unit normal n, in double. Signed by the winding. */
static double rad__contour(const double (*q)[3], int count, const double *n)
{
    double sum = 0.0, r[4][3];
    int i, k;
    for (i = 0; i < count; ++i) {
        double l = sqrt(q[i][0] * q[i][0] + q[i][1] * q[i][1] + q[i][2] * q[i][2]);
        if (!(l > 0.0)) return 0.0; /* the point is on the polygon's boundary */
        for (k = 0; k < 3; ++k) r[i][k] = q[i][k] / l;
    }
    for (i = 0; i < count; ++i) {
        const double *a = r[i], *b = r[(i + 1) % count];
        double c[3], cl, d;
        c[0] = a[1] * b[2] - a[2] * b[1];
        c[1] = a[2] * b[0] - a[0] * b[2];
        c[2] = a[0] * b[1] - a[1] * b[0];
        cl = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        if (!(cl > 1e-300)) continue;
        d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        sum += atan2(cl, d) * (n[0] * c[0] + n[1] * c[1] + n[2] * c[2]) / cl;
    }
    return sum;
}

/* Point-to-triangle kernel: p, n the receiver point and unit normal, v 9 floats. Clips the
   triangle to n.(x - p) >= 0. Returns the signed contour sum / (2 pi). */
static double rad__ff_point_tri(const double *p, const double *n, const float *v)
{
    double q[3][3], d[3], out[4][3];
    int i, k, m = 0;
    for (i = 0; i < 3; ++i) {
        for (k = 0; k < 3; ++k) q[i][k] = (double)v[3 * i + k] - p[k];
        d[i] = q[i][0] * n[0] + q[i][1] * n[1] + q[i][2] * n[2];
    }
    if (d[0] <= 0.0 && d[1] <= 0.0 && d[2] <= 0.0) return 0.0;
    if (d[0] >= 0.0 && d[1] >= 0.0 && d[2] >= 0.0) return rad__contour((const double(*)[3])q, 3, n) / (2.0 * RAD__PI);
    for (i = 0; i < 3; ++i) {
        int j = (i + 1) % 3;
        if (d[i] >= 0.0) { for (k = 0; k < 3; ++k) out[m][k] = q[i][k]; ++m; }
        if ((d[i] > 0.0 && d[j] < 0.0) || (d[i] < 0.0 && d[j] > 0.0)) {
            double t = d[i] / (d[i] - d[j]);
            for (k = 0; k < 3; ++k) out[m][k] = q[i][k] + t * (q[j][k] - q[i][k]);
            ++m;
        }
    }
    if (m < 3) return 0.0;
    return rad__contour((const double(*)[3])out, m, n) / (2.0 * RAD__PI);
}

RAD_API float rad_ff_point_polygon(const float p[3], const float n[3], const float *vertices, uint32_t count)
{
    double P[3], N[3], pn[3] = { 0.0, 0.0, 0.0 }, sum = 0.0, side = 0.0, nl;
    uint32_t i;
    int k;
    if (!p || !n || !vertices || count < 3) return 0.0f;
    for (k = 0; k < 3; ++k) { P[k] = p[k]; N[k] = n[k]; }
    nl = sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]);
    if (!(nl > 0.0)) return 0.0f;
    for (k = 0; k < 3; ++k) N[k] /= nl;
    /* polygon normal (Newell) and the side p is on */
    for (i = 0; i < count; ++i) {
        const float *a = vertices + 3 * (size_t)i, *b = vertices + 3 * (size_t)((i + 1) % count);
        pn[0] += ((double)a[1] - b[1]) * ((double)a[2] + b[2]);
        pn[1] += ((double)a[2] - b[2]) * ((double)a[0] + b[0]);
        pn[2] += ((double)a[0] - b[0]) * ((double)a[1] + b[1]);
    }
    for (k = 0; k < 3; ++k) side += pn[k] * ((double)p[k] - (double)vertices[k]);
    if (!(side > 0.0)) return 0.0f;
    /* fan of triangles: interior edges cancel in the contour sum */
    for (i = 1; i + 1 < count; ++i) {
        float tri[9];
        for (k = 0; k < 3; ++k) {
            tri[k] = vertices[k];
            tri[3 + k] = vertices[3 * (size_t)i + (size_t)k];
            tri[6 + k] = vertices[3 * (size_t)(i + 1) + (size_t)k];
        }
        sum += rad__ff_point_tri(P, N, tri);
    }
    return (float)fabs(sum);
}

RAD_API float rad_ff_point_point(const float pi_[3], const float ni[3], const float pj[3], const float nj[3], float sj)
{
    float r[3], d2, d, ci, cj, floor2;
    if (!pi_ || !ni || !pj || !nj || !(sj > 0.0f) || !rad__finite(sj)) return 0.0f;
    rad__sub(r, pj, pi_);
    d2 = rad__dot(r, r);
    if (!(d2 > 0.0f)) return 0.0f;
    d = (float)sqrt((double)d2);
    ci = rad__dot(r, ni) / d;
    cj = -rad__dot(r, nj) / d;
    if (!(ci > 0.0f) || !(cj > 0.0f)) return 0.0f;
    floor2 = sj / (float)RAD__PI;
    if (d2 < floor2) d2 = floor2;
    return sj * ci * cj / ((float)RAD__PI * d2);
}

RAD_API void rad_form_factor_options_default(rad_form_factor_options *o)
{
    if (!o) return;
    memset(o, 0, sizeof(*o));
    o->method = RAD_FF_ANALYTIC;
    o->samples = 16;
    o->ray_epsilon = 1e-5f;
    o->hemicube_resolution = RAD__HC_DEFAULT_RES;
}

/* shared state of one form-factor computation */
typedef struct rad__ff {
    const rad_patches *P;
    const rad_raycaster *rc;
    rad_form_factor_options o;
    float eps;                    /* absolute ray epsilon */
    float *pts;                   /* samples * 3 floats per patch: the emitter-side points */
    /* per task scratch */
    rad_ray *rays;                /* RAD__RAY_BATCH per task */
    uint8_t *occ;
    float *ray_w;                 /* contribution of each ray */
    uint32_t *ray_slot;           /* column slot of each ray */
    double *acc;                  /* N per task */
    uint64_t *rays_cast, *pairs;  /* per task counters */
    /* output */
    float *out;
    uint32_t row_begin;           /* rows call: matrix row of out's first row */
    size_t out_stride;
    int dense_mode;               /* 1: compute j > i and mirror into a full N x N 'out' */
    uint32_t tasks;
    /* RAD_FF_HEMICUBE (the pair fields above stay NULL) */
    uint32_t hc_res;
    double hc_near;               /* absolute near-plane distance */
    double *hc_centre;            /* res cell centres across a face, -1 .. 1 (a side face's
                                     heights are the upper half, 0 .. 1) */
    double *hc_dtop, *hc_dside;   /* delta form factors: res x res, res x res/2, row-major */
    uint32_t *hc_item;            /* per task 3 res^2 cells: the top face, then the 4 sides */
    float *hc_depth;              /* per task, the same cells: 1 / depth of the nearest item */
} rad__ff;

static void rad__ff_patch_corners(const rad__ff *f, uint32_t i, float *v)
{
    const rad_patch *p = &f->P->patches[i];
    int k, m;
    for (m = 0; m < 3; ++m)
        for (k = 0; k < 3; ++k) v[3 * m + k] = f->P->vertices[3 * (size_t)p->vertices[m] + (size_t)k];
}

/* 1 when the pair can exchange light at all: some corner of each patch strictly in front of
   the other (a coplanar or back-to-back pair is 0 without any work) */
static int rad__ff_facing(const float *vi, const float *ni, const float *vj, const float *nj)
{
    int m, a = 0, b = 0;
    for (m = 0; m < 3; ++m) {
        float d1[3], d2[3];
        rad__sub(d1, vj + 3 * m, vi);
        rad__sub(d2, vi + 3 * m, vj);
        if (rad__dot(d1, ni) > 0.0f) a = 1;
        if (rad__dot(d2, nj) > 0.0f) b = 1;
    }
    return a && b;
}

static rad_result rad__ff_flush(rad__ff *f, uint32_t task, uint32_t count)
{
    rad_ray *rays = f->rays + (size_t)task * RAD__RAY_BATCH;
    uint8_t *occ = f->occ + (size_t)task * RAD__RAY_BATCH;
    const float *w = f->ray_w + (size_t)task * RAD__RAY_BATCH;
    const uint32_t *slot = f->ray_slot + (size_t)task * RAD__RAY_BATCH;
    double *acc = f->acc + (size_t)task * f->P->count;
    uint32_t k;
    if (count == 0) return RAD_SUCCESS;
    if (f->rc->occluded(f->rc->user, rays, count, occ) != RAD_SUCCESS) return RAD_ERROR_RAYCAST_FAILED;
    f->rays_cast[task] += count;
    for (k = 0; k < count; ++k)
        if (!occ[k]) acc[slot[k]] += (double)w[k];
    return RAD_SUCCESS;
}

/* Accumulates into acc[slot] S times the canonical value of the pair (lo, hi): the sum over
   lo's S sample points of kernel * visibility. Rays go to the task's batch. */
static rad_result rad__ff_pair(rad__ff *f, uint32_t lo, uint32_t hi, uint32_t slot, uint32_t task, uint32_t *nrays)
{
    const rad_patch *pl = &f->P->patches[lo], *ph = &f->P->patches[hi];
    float vl[9], vh[9], r1, r2, d[3], rl = 0.0f, rh = 0.0f, scale = 1.0f, xs[3], xy[6 * RAD__MAX_SAMPLES];
    double wk[RAD__MAX_SAMPLES], total = 0.0, ksum = 0.0;
    uint32_t S = f->o.samples, s, h, m, nside = 1;
    double *acc = f->acc + (size_t)task * f->P->count, PN[3];
    int k, near;
    rad__ff_patch_corners(f, lo, vl);
    rad__ff_patch_corners(f, hi, vh);
    acc[slot] = 0.0;
    if (!rad__ff_facing(vl, pl->normal, vh, ph->normal)) return RAD_SUCCESS;
    f->pairs[task]++;
    h = rad__hash(f->o.seed ^ rad__hash(lo * 0x9E3779B9u ^ rad__hash(hi)));
    r1 = (float)(h & 0xFFFFu) / 65536.0f;
    r2 = (float)(h >> 16) / 65536.0f;
    for (k = 0; k < 3; ++k) PN[k] = pl->normal[k];
    /* near pairs (closer than twice their sizes, e.g. sharing an edge) have a nearly singular
       integrand: they get a lattice of side 4n (16x the points, at most RAD__MAX_SAMPLES),
       computed here, each weighted S / (16 S) */
    for (m = 0; m < 3; ++m) {
        rad__sub(d, vl + 3 * m, pl->centroid);
        if (rad__dot(d, d) > rl) rl = rad__dot(d, d);
        rad__sub(d, vh + 3 * m, ph->centroid);
        if (rad__dot(d, d) > rh) rh = rad__dot(d, d);
    }
    rad__sub(d, pl->centroid, ph->centroid);
    near = rad__dot(d, d) < 4.0f * (rl + rh + 2.0f * (float)sqrt((double)rl * (double)rh));
    if (near && S < RAD__MAX_SAMPLES) {
        nside = rad__lattice_side(S) * 4u;
        while (nside * nside > RAD__MAX_SAMPLES) --nside;
        S = nside * nside;
        scale = (float)f->o.samples / (float)S;
    } else {
        near = 0;
    }
    /* Analytic method: the pair's value is sum_s F(x_s) V_s. One ray per point to a uniform
       point y_s of the source measures the visible share of its area, not of its form factor,
       so a large or long source half hidden behind an edge lost (or gained) light. Each ray
       carries instead its share k_s / sum k of the pair's total W = sum_s F(x_s), with k the
       kernel cos cos / r^2 of its two points (a ratio estimator, exact when nothing occludes:
       the shares sum to W). The Monte Carlo method's weights are its kernel already. */
    for (s = 0; s < S; ++s) {
        const float *x = xs;
        float y[3], u1, u2, w, dxy[3];
        if (near) {
            rad__lattice_point(vl, vl + 3, vl + 6, nside, s, xs);
        } else {
            x = f->pts + ((size_t)lo * S + s) * 3u;
        }
        wk[s] = 0.0;
        rad__sub(dxy, x, vh);
        if (!(rad__dot(dxy, ph->normal) > 0.0f)) continue; /* x is behind the receiver */
        rad__hammersley(s, S, r1, r2, &u1, &u2);
        rad__triangle_point(vh, vh + 3, vh + 6, u1, u2, y);
        memcpy(xy + 6 * s, x, 3 * sizeof(float));
        memcpy(xy + 6 * s + 3, y, 3 * sizeof(float));
        if (f->o.method == RAD_FF_ANALYTIC) {
            double P[3], kern;
            float r2y;
            for (k = 0; k < 3; ++k) P[k] = x[k];
            w = (float)fabs(rad__ff_point_tri(P, PN, vh)) * scale;
            if (!(w > 0.0f)) continue;
            total += (double)w;
            rad__sub(dxy, y, x);
            r2y = rad__dot(dxy, dxy);
            kern = r2y > 0.0f ? (double)rad__dot(dxy, pl->normal) * -(double)rad__dot(dxy, ph->normal) / ((double)r2y * (double)r2y)
                              : 0.0;
            wk[s] = kern > 0.0 ? kern : 0.0;
            ksum += wk[s];
        } else {
            w = rad_ff_point_point(x, pl->normal, y, ph->normal, ph->area) * scale;
            wk[s] = w > 0.0f ? (double)w : 0.0;
        }
    }
    for (s = 0; s < S; ++s) {
        const float *x = xy + 6 * s, *y = xy + 6 * s + 3;
        float w;
        if (f->o.method == RAD_FF_ANALYTIC) w = ksum > 0.0 ? (float)(total * wk[s] / ksum) : 0.0f;
        else w = (float)wk[s];
        if (!(w > 0.0f)) continue;
        if (f->o.skip_visibility) {
            acc[slot] += (double)w;
            continue;
        }
        {
            size_t at = (size_t)task * RAD__RAY_BATCH + *nrays;
            rad_ray *ray = f->rays + at;
            float len;
            for (k = 0; k < 3; ++k) {
                ray->origin[k] = x[k] + pl->normal[k] * f->eps;
                ray->dir[k] = (y[k] + ph->normal[k] * f->eps) - ray->origin[k];
            }
            len = rad__len(ray->dir);
            ray->tmin = 0.0f;
            ray->tmax = len > 2.0f * f->eps ? 1.0f - f->eps / len : 0.5f;
            f->ray_w[at] = w;
            f->ray_slot[at] = slot;
            if (++*nrays == RAD__RAY_BATCH) {
                rad_result r = rad__ff_flush(f, task, *nrays);
                *nrays = 0;
                if (r != RAD_SUCCESS) return r;
            }
        }
    }
    return RAD_SUCCESS;
}

/* The patch a pair is integrated from: the smaller one (the lower index on a tie). Its points
   carry the outer integral and the larger one gets the analytic inner integral; the other
   entry is F_ba = F_ab A_a / A_b with A_a / A_b <= 1, which cannot overflow whatever the area
   ratio, and which is the more accurate direction. */
static int rad__ff_from_i(const rad__ff *f, uint32_t i, uint32_t j)
{
    float ai = f->P->areas[i], aj = f->P->areas[j];
    return ai < aj || (ai == aj && i < j);
}

/* ---- the hemicube (Cohen and Greenberg 1985; HEMICUBE in >>api_formfactor) ---- */

/* The coefficients e of the edge function e0 x + e1 y + e2 of the projected edge p -> r times
   'sign' (positive on the left of the edge when sign is 1). They are computed from the two
   endpoints in a fixed order (smaller x, then smaller y, first) and negated when the edge
   runs the other way, so two polygons that share the edge get exactly opposite values at
   every point, whatever the compiler contracts into fused multiply-adds: a cell centre on the
   edge goes to exactly one of them (the tie rule of rad__hc_draw). */
static void rad__hc_edge(const double *p, const double *r, double sign, double *e)
{
    int swap = r[0] < p[0] || (r[0] == p[0] && r[1] < p[1]);
    const double *lo = swap ? r : p, *hi = swap ? p : r;
    double s = swap ? -sign : sign;
    e[0] = s * (lo[1] - hi[1]);
    e[1] = s * (hi[0] - lo[0]);
    e[2] = s * (lo[0] * hi[1] - lo[1] * hi[0]);
}

/* Draws triangle q (three points in one face's frame, relative to the hemicube's centre: a and
   b across the face, d along its axis) into that face: 'rows' rows of res cells whose centres
   are x = centre[ix], y = centre[y0 + iy] (y0 = 0 for the top face, res/2 for a side face,
   whose b / d runs from 0 to 1 only), its item, depth and delta form factor arrays starting
   at item, depth, dff. With acc (no visibility) adds the delta form factor of every covered
   cell to *acc; else keeps in each cell the nearest item so far (depth holds 1 / distance along
   the face's axis, 0 for none). Returns 1 when the triangle covered some cell centre. */
static int rad__hc_draw(const rad__ff *f, const double (*q)[3], uint32_t rows, uint32_t y0, uint32_t *item, float *depth,
                        const double *dff, uint32_t value, double *acc)
{
    const uint32_t res = f->hc_res;
    const double znear = f->hc_near, *ctr = f->hc_centre, half = 0.5 * (double)res, blo = y0 ? 0.0 : -1.0;
    double poly[4][3], xy[4][2], edge[4][3], e1[3], e2[3], m[3], w[3], k, len, area = 0.0;
    double xmin, xmax, ymin, ymax, fx0, fx1, fy0, fy1;
    uint32_t ix0, ix1, iy0, iy1, ix, iy;
    int n = 0, ne = 0, v, kk, drawn = 0;
    /* outside the face's frustum: every point beyond the near plane or one of the four sides */
    if (q[0][2] < znear && q[1][2] < znear && q[2][2] < znear) return 0;
    if (q[0][0] > q[0][2] && q[1][0] > q[1][2] && q[2][0] > q[2][2]) return 0;
    if (q[0][0] < -q[0][2] && q[1][0] < -q[1][2] && q[2][0] < -q[2][2]) return 0;
    if (q[0][1] > q[0][2] && q[1][1] > q[1][2] && q[2][1] > q[2][2]) return 0;
    if (q[0][1] < blo * q[0][2] && q[1][1] < blo * q[1][2] && q[2][1] < blo * q[2][2]) return 0;
    /* the triangle's plane m . x = k; 1 / distance along the axis at (x, y) is w . (x, y, 1). A
       plane passing within the near distance of the centre is seen edge-on: nothing to draw */
    for (kk = 0; kk < 3; ++kk) { e1[kk] = q[1][kk] - q[0][kk]; e2[kk] = q[2][kk] - q[0][kk]; }
    m[0] = e1[1] * e2[2] - e1[2] * e2[1];
    m[1] = e1[2] * e2[0] - e1[0] * e2[2];
    m[2] = e1[0] * e2[1] - e1[1] * e2[0];
    len = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
    k = m[0] * q[0][0] + m[1] * q[0][1] + m[2] * q[0][2];
    if (!(fabs(k) > znear * len)) return 0;
    for (kk = 0; kk < 3; ++kk) w[kk] = m[kk] / k;
    /* clip against d >= znear; a new point is interpolated from the inside end of its edge, so a
       clipped edge shared by two triangles gives both the same point */
    for (v = 0; v < 3; ++v) {
        const double *p = q[v], *r = q[(v + 1) % 3];
        int pin = p[2] >= znear, rin = r[2] >= znear;
        if (pin) { for (kk = 0; kk < 3; ++kk) poly[n][kk] = p[kk]; ++n; }
        if (pin != rin) {
            const double *in = pin ? p : r, *out = pin ? r : p;
            double t = (in[2] - znear) / (in[2] - out[2]);
            for (kk = 0; kk < 2; ++kk) poly[n][kk] = in[kk] + t * (out[kk] - in[kk]);
            poly[n][2] = znear;
            ++n;
        }
    }
    if (n < 3) return 0;
    for (v = 0; v < n; ++v) { xy[v][0] = poly[v][0] / poly[v][2]; xy[v][1] = poly[v][1] / poly[v][2]; }
    xmin = xmax = xy[0][0];
    ymin = ymax = xy[0][1];
    for (v = 0; v < n; ++v) {
        const double *p = xy[v], *r = xy[(v + 1) % n];
        area += p[0] * r[1] - r[0] * p[1];
        if (p[0] < xmin) xmin = p[0];
        if (p[0] > xmax) xmax = p[0];
        if (p[1] < ymin) ymin = p[1];
        if (p[1] > ymax) ymax = p[1];
    }
    if (!(area != 0.0)) return 0;
    for (v = 0; v < n; ++v) {
        rad__hc_edge(xy[v], xy[(v + 1) % n], area > 0.0 ? 1.0 : -1.0, edge[ne]);
        if (edge[ne][0] != 0.0 || edge[ne][1] != 0.0) ++ne; /* a zero-length edge bounds nothing */
    }
    /* the cells whose centres the bounding box may hold, one cell wider each way (the edge
       functions decide) */
    fx0 = floor(xmin * half + half - 0.5);
    fx1 = ceil(xmax * half + half - 0.5);
    fy0 = floor(ymin * half + half - 0.5 - (double)y0);
    fy1 = ceil(ymax * half + half - 0.5 - (double)y0);
    if (!(fx1 >= 0.0 && fx0 <= (double)(res - 1u) && fy1 >= 0.0 && fy0 <= (double)(rows - 1u))) return 0;
    ix0 = fx0 > 0.0 ? (uint32_t)fx0 : 0u;
    ix1 = fx1 < (double)(res - 1u) ? (uint32_t)fx1 : res - 1u;
    iy0 = fy0 > 0.0 ? (uint32_t)fy0 : 0u;
    iy1 = fy1 < (double)(rows - 1u) ? (uint32_t)fy1 : rows - 1u;
    for (iy = iy0; iy <= iy1; ++iy) {
        double y = ctr[y0 + iy], lo = (double)ix0, hi = (double)ix1, slo = lo, shi = hi;
        int tall[4], tslow[4], nall = 0, nslow = 0, out = 0;
        /* The row's span. An edge parallel to the row (e0 = 0) has one value along it: it keeps
           or drops the whole row. Where another edge crosses the row gives the span, one cell
           wider each way; the cells more than a cell inside every crossing are inside those
           edges whatever the rounding (the crossing is good to far less than a cell, the edge
           function there far larger than its rounding). The edge functions decide every other
           cell, and the nearly horizontal edges (|e0| <= 1e-6 |e1|: an imprecise crossing)
           every cell. Each edge is evaluated at one place only, so a centre on an edge shared
           by two triangles still goes to exactly one. */
        for (v = 0; v < ne && !out; ++v) {
            const double *e = edge[v];
            double cross;
            if (e[0] == 0.0) {
                double val = e[1] * y + e[2];
                if (!(val > 0.0 || (val == 0.0 && e[1] > 0.0))) out = 1;
                continue;
            }
            tall[nall++] = v;
            if (!(fabs(e[0]) > 1e-6 * fabs(e[1]))) { tslow[nslow++] = v; continue; }
            /* the crossing in cell units, clamped to the face and a few cells beyond (which
               changes no bound) and rounded down by truncating a positive number: floor()
               is a library call on plain x86-64 */
            cross = -(e[1] * y + e[2]) / e[0] * half + half - 0.5;
            cross = cross > -4.0 ? (cross < (double)res + 4.0 ? cross : (double)res + 4.0) : -4.0;
            cross = (double)(long)(cross + 8.0) - 8.0;
            if (e[0] > 0.0) {
                if (cross - 1.0 > lo) lo = cross - 1.0;
                if (cross + 2.0 > slo) slo = cross + 2.0;
            } else {
                if (cross + 2.0 < hi) hi = cross + 2.0;
                if (cross - 1.0 < shi) shi = cross - 1.0;
            }
        }
        if (out || !(lo <= hi)) continue;
        for (ix = (uint32_t)lo; ix <= (uint32_t)hi; ++ix) {
            double x = ctr[ix];
            size_t cell = (size_t)iy * res + ix;
            const int *list = (double)ix < slo || (double)ix > shi ? tall : tslow;
            int count = list == tall ? nall : nslow, t;
            float inv;
            for (t = 0; t < count; ++t) {
                const double *e = edge[list[t]];
                double val = e[0] * x + e[1] * y + e[2];
                if (val > 0.0) continue;
                /* on the edge: the polygon whose edge function has (e0, e1) > 0 in lexical order
                   takes the centre; its neighbour across the edge has the negated function */
                if (val == 0.0 && (e[0] > 0.0 || (e[0] == 0.0 && e[1] > 0.0))) continue;
                break;
            }
            if (t < count) continue;
            drawn = 1;
            if (acc) { *acc += dff[cell]; continue; }
            inv = (float)(w[0] * x + w[1] * y + w[2]);
            if (inv > depth[cell]) { depth[cell] = inv; item[cell] = value; }
        }
    }
    return drawn;
}

/* Row i by the hemicube at patch i's centroid. */
static rad_result rad__hc_row(rad__ff *f, uint32_t i, uint32_t task)
{
    const rad_patches *P = f->P;
    const rad_patch *pi = &P->patches[i];
    const uint32_t N = P->count, res = f->hc_res, half = res / 2u;
    const size_t top = (size_t)res * res, side = (size_t)res * half, cells = top + 4u * side;
    uint32_t *item = f->hc_item + (size_t)task * cells;
    float *depth = f->hc_depth + (size_t)task * cells;
    float *row = f->out + (size_t)(i - f->row_begin) * f->out_stride;
    double *acc = f->acc + (size_t)task * N, c[3], n[3], u[3], v[3], sg, a, b;
    const int skip = f->o.skip_visibility != 0;
    uint32_t j, m, face;
    size_t cell;
    int k;
    for (k = 0; k < 3; ++k) { c[k] = pi->centroid[k]; n[k] = pi->normal[k]; }
    /* the side axes: the branchless orthonormal basis of n (Duff et al. 2017) */
    sg = n[2] >= 0.0 ? 1.0 : -1.0;
    a = -1.0 / (sg + n[2]);
    b = n[0] * n[1] * a;
    u[0] = 1.0 + sg * n[0] * n[0] * a; u[1] = sg * b; u[2] = -sg * n[0];
    v[0] = b; v[1] = sg + n[1] * n[1] * a; v[2] = -n[1];
    memset(acc, 0, sizeof(double) * N);
    if (!skip) {
        memset(item, 0xFF, sizeof(uint32_t) * cells); /* RAD__HC_NONE */
        memset(depth, 0, sizeof(float) * cells);
    }
    for (j = 0; j < N; ++j) {
        const rad_patch *pj = &P->patches[j];
        double L[3][3], q[3][3], front = 0.0;
        uint32_t value;
        int drawn = 0;
        if (j == i) continue;
        /* the corners in the hemicube's frame (u, v, n) */
        for (m = 0; m < 3; ++m) {
            const float *x = P->vertices + 3 * (size_t)pj->vertices[m];
            double d[3];
            for (k = 0; k < 3; ++k) d[k] = (double)x[k] - c[k];
            L[m][0] = d[0] * u[0] + d[1] * u[1] + d[2] * u[2];
            L[m][1] = d[0] * v[0] + d[1] * v[1] + d[2] * v[2];
            L[m][2] = d[0] * n[0] + d[1] * n[1] + d[2] * n[2];
            if (m == 0) front = -(d[0] * pj->normal[0] + d[1] * pj->normal[1] + d[2] * pj->normal[2]);
        }
        if (L[0][2] <= 0.0 && L[1][2] <= 0.0 && L[2][2] <= 0.0) continue; /* behind i's plane, or in it */
        if (skip && !(front > 0.0)) continue;
        value = front > 0.0 ? j : RAD__HC_BACK; /* seen from behind: occludes, receives nothing */
        for (face = 0; face < 5; ++face) {
            size_t off = face == 0 ? 0 : top + (size_t)(face - 1u) * side;
            for (m = 0; m < 3; ++m) {
                const double *l = L[m];
                double *o = q[m];
                switch (face) {
                case 0: o[0] = l[0]; o[1] = l[1]; o[2] = l[2]; break;  /* top: (u, v) across, n along */
                case 1: o[0] = l[1]; o[1] = l[2]; o[2] = l[0]; break;  /* +u: (v, n) across */
                case 2: o[0] = l[1]; o[1] = l[2]; o[2] = -l[0]; break; /* -u */
                case 3: o[0] = l[0]; o[1] = l[2]; o[2] = l[1]; break;  /* +v: (u, n) across */
                default: o[0] = l[0]; o[1] = l[2]; o[2] = -l[1]; break; /* -v */
                }
            }
            drawn |= rad__hc_draw(f, (const double(*)[3])q, face ? half : res, face ? half : 0u, item + off, depth + off,
                                  face ? f->hc_dside : f->hc_dtop, value, skip ? acc + j : NULL);
        }
        if (drawn) f->pairs[task]++;
    }
    if (!skip) {
        for (cell = 0; cell < top; ++cell)
            if (item[cell] < N) acc[item[cell]] += f->hc_dtop[cell];
        for (face = 1; face < 5; ++face) {
            const uint32_t *it = item + top + (size_t)(face - 1u) * side;
            for (cell = 0; cell < side; ++cell)
                if (it[cell] < N) acc[it[cell]] += f->hc_dside[cell];
        }
    }
    for (j = 0; j < N; ++j) row[j] = (float)acc[j];
    row[i] = 0.0f;
    return RAD_SUCCESS;
}

static rad_result rad__ff_row(void *data, uint32_t i, uint32_t task)
{
    rad__ff *f = (rad__ff *)data;
    uint32_t N = f->P->count, j, nrays = 0;
    double *acc = f->acc + (size_t)task * N;
    float inv_s = 1.0f / (float)f->o.samples;
    rad_result r;
    if (f->o.method == RAD_FF_HEMICUBE) return rad__hc_row(f, i, task);
    /* dense mode: only j > i, each pair written both ways; rows mode: every j. Either way a
       pair is computed from the same side with the same points, so the bits agree. */
    for (j = f->dense_mode ? i + 1 : 0; j < N; ++j) {
        if (j == i) { acc[j] = 0.0; continue; }
        r = rad__ff_from_i(f, i, j) ? rad__ff_pair(f, i, j, j, task, &nrays) : rad__ff_pair(f, j, i, j, task, &nrays);
        if (r != RAD_SUCCESS) return r;
    }
    r = rad__ff_flush(f, task, nrays);
    if (r != RAD_SUCCESS) return r;
    if (f->dense_mode) {
        float *row = f->out + (size_t)i * N;
        row[i] = 0.0f;
        for (j = i + 1; j < N; ++j) {
            float v = (float)acc[j] * inv_s;
            if (rad__ff_from_i(f, i, j)) {
                row[j] = v;
                f->out[(size_t)j * N + i] = v * (f->P->areas[i] / f->P->areas[j]);
            } else {
                f->out[(size_t)j * N + i] = v;
                row[j] = v * (f->P->areas[j] / f->P->areas[i]);
            }
        }
    } else {
        float *row = f->out + (size_t)(i - f->row_begin) * f->out_stride;
        for (j = 0; j < N; ++j) {
            float v = (float)acc[j] * inv_s;
            if (j == i) row[j] = 0.0f;
            else if (rad__ff_from_i(f, i, j)) row[j] = v;
            else row[j] = v * (f->P->areas[j] / f->P->areas[i]);
        }
    }
    return RAD_SUCCESS;
}

static void rad__ff_release(rad__ff *f, const rad_allocator *a)
{
    rad__free(a, f->pts);
    rad__free(a, f->rays);
    rad__free(a, f->occ);
    rad__free(a, f->ray_w);
    rad__free(a, f->ray_slot);
    rad__free(a, f->acc);
    rad__free(a, f->rays_cast);
    rad__free(a, f->pairs);
    rad__free(a, f->hc_centre);
    rad__free(a, f->hc_dtop);
    rad__free(a, f->hc_dside);
    rad__free(a, f->hc_item);
    rad__free(a, f->hc_depth);
    memset(f, 0, sizeof(*f));
}

/* The hemicube's tables and per-task scratch (rad__ff_setup has checked the options). */
static rad_result rad__hc_setup(rad__ff *f, const rad__ctx *c)
{
    const uint32_t res = f->o.hemicube_resolution, half = res / 2u, N = f->P->count;
    const size_t cells = 3u * (size_t)res * res, per_task = cells * (sizeof(uint32_t) + sizeof(float));
    const double h = 2.0 / (double)res, da = h * h;
    uint32_t ix, iy, T = f->tasks;
    if (per_task >= RAD__HC_SCRATCH_BYTES) T = 1;
    else if (T > RAD__HC_SCRATCH_BYTES / per_task) T = (uint32_t)(RAD__HC_SCRATCH_BYTES / per_task);
    f->tasks = T;
    f->hc_res = res;
    f->hc_near = (double)f->eps;
    f->hc_centre = (double *)rad__alloc_array(&c->allocator, res, sizeof(double));
    f->hc_dtop = (double *)rad__alloc_array(&c->allocator, (size_t)res * res, sizeof(double));
    f->hc_dside = (double *)rad__alloc_array(&c->allocator, (size_t)res * half, sizeof(double));
    f->hc_item = (uint32_t *)rad__alloc_array(&c->allocator, (size_t)T * cells, sizeof(uint32_t));
    f->hc_depth = (float *)rad__alloc_array(&c->allocator, (size_t)T * cells, sizeof(float));
    f->acc = (double *)rad__alloc_array(&c->allocator, (size_t)T * N, sizeof(double));
    f->rays_cast = (uint64_t *)rad__alloc_array(&c->allocator, T, sizeof(uint64_t));
    f->pairs = (uint64_t *)rad__alloc_array(&c->allocator, T, sizeof(uint64_t));
    if (!f->hc_centre || !f->hc_dtop || !f->hc_dside || !f->hc_item || !f->hc_depth || !f->acc || !f->rays_cast || !f->pairs) {
        rad__log(c, RAD_LOG_ERROR, "out of memory for the scratch of %u hemicubes of resolution %u (%u patches)", T, res, N);
        rad__ff_release(f, &c->allocator);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    memset(f->rays_cast, 0, sizeof(uint64_t) * T);
    memset(f->pairs, 0, sizeof(uint64_t) * T);
    /* cell centres -1 + (ix + 1/2) h; the delta form factors of the midpoint rule: a top cell
       at (x, y, 1) subtends dA / (pi r^4), a side cell at (1, x, y) y dA / (pi r^4), with
       r^2 = x^2 + y^2 + 1 */
    for (ix = 0; ix < res; ++ix) f->hc_centre[ix] = ((double)(2u * ix + 1u) - (double)res) / (double)res;
    for (iy = 0; iy < res; ++iy)
        for (ix = 0; ix < res; ++ix) {
            double x = f->hc_centre[ix], y = f->hc_centre[iy], r2 = x * x + y * y + 1.0;
            f->hc_dtop[(size_t)iy * res + ix] = da / (RAD__PI * r2 * r2);
        }
    for (iy = 0; iy < half; ++iy)
        for (ix = 0; ix < res; ++ix) {
            double x = f->hc_centre[ix], y = f->hc_centre[half + iy], r2 = x * x + y * y + 1.0;
            f->hc_dside[(size_t)iy * res + ix] = y * da / (RAD__PI * r2 * r2);
        }
    return RAD_SUCCESS;
}

static rad_result rad__ff_setup(rad__ff *f, const rad_patches *P, const rad_raycaster *rc, const rad_form_factor_options *o,
                                const rad__ctx *c)
{
    uint32_t i, s, T;
    memset(f, 0, sizeof(*f));
    if (!P) return RAD_ERROR_INVALID_ARGUMENT;
    if (o) f->o = *o; else rad_form_factor_options_default(&f->o);
    if (f->o.samples == 0) f->o.samples = 16;
    if (f->o.samples > RAD__MAX_SAMPLES) f->o.samples = RAD__MAX_SAMPLES;
    f->o.samples = rad__lattice_side(f->o.samples) * rad__lattice_side(f->o.samples); /* a square */
    if (f->o.ray_epsilon == 0.0f) f->o.ray_epsilon = 1e-5f;
    if (f->o.hemicube_resolution == 0) f->o.hemicube_resolution = RAD__HC_DEFAULT_RES;
    if (!(f->o.ray_epsilon > 0.0f && f->o.ray_epsilon <= RAD__MAX_RAY_EPSILON) || !rad__finite(f->o.drop_threshold) ||
        f->o.drop_threshold < 0.0f ||
        (f->o.method != RAD_FF_ANALYTIC && f->o.method != RAD_FF_MONTE_CARLO && f->o.method != RAD_FF_HEMICUBE)) {
        rad__log(c, RAD_LOG_ERROR, "form factor options: method %d, ray_epsilon %g (must be in (0, %g]) or drop_threshold %g "
                 "(finite, >= 0) is bad", (int)f->o.method, (double)f->o.ray_epsilon, (double)RAD__MAX_RAY_EPSILON,
                 (double)f->o.drop_threshold);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    if (f->o.method == RAD_FF_HEMICUBE && (f->o.hemicube_resolution < RAD__HC_MIN_RES ||
                                           f->o.hemicube_resolution > RAD__HC_MAX_RES || (f->o.hemicube_resolution & 1u))) {
        rad__log(c, RAD_LOG_ERROR, "form factor options: hemicube_resolution %u must be even and in [%u, %u] (0: %u)",
                 f->o.hemicube_resolution, RAD__HC_MIN_RES, RAD__HC_MAX_RES, RAD__HC_DEFAULT_RES);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    if (!f->o.skip_visibility && f->o.method != RAD_FF_HEMICUBE && (!rc || !rc->occluded)) {
        rad__log(c, RAD_LOG_ERROR,
                 "form factors need a raycaster with occluded() unless skip_visibility is set or the method is RAD_FF_HEMICUBE");
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    if (!P->scene) {
        rad__log(c, RAD_LOG_ERROR, "form factors need patches->scene (set it on loaded patches)");
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    f->P = P;
    f->rc = rc;
    f->eps = f->o.ray_epsilon * P->scene->diagonal;
    T = c->tasks;
    if (T > P->count) T = P->count;
    if (T == 0) T = 1;
    f->tasks = T;
    if (f->o.method == RAD_FF_HEMICUBE) return rad__hc_setup(f, c);
    f->pts = (float *)rad__alloc_array(&c->allocator, (size_t)P->count * f->o.samples, 3 * sizeof(float));
    f->rays = (rad_ray *)rad__alloc_array(&c->allocator, (size_t)T * RAD__RAY_BATCH, sizeof(rad_ray));
    f->occ = (uint8_t *)rad__alloc_array(&c->allocator, (size_t)T * RAD__RAY_BATCH, 1);
    f->ray_w = (float *)rad__alloc_array(&c->allocator, (size_t)T * RAD__RAY_BATCH, sizeof(float));
    f->ray_slot = (uint32_t *)rad__alloc_array(&c->allocator, (size_t)T * RAD__RAY_BATCH, sizeof(uint32_t));
    f->acc = (double *)rad__alloc_array(&c->allocator, (size_t)T * P->count, sizeof(double));
    f->rays_cast = (uint64_t *)rad__alloc_array(&c->allocator, T, sizeof(uint64_t));
    f->pairs = (uint64_t *)rad__alloc_array(&c->allocator, T, sizeof(uint64_t));
    if (!f->pts || !f->rays || !f->occ || !f->ray_w || !f->ray_slot || !f->acc || !f->rays_cast || !f->pairs) {
        rad__ff_release(f, &c->allocator);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    memset(f->rays_cast, 0, sizeof(uint64_t) * T);
    memset(f->pairs, 0, sizeof(uint64_t) * T);
    /* the emitter-side sample points of every patch: the same lattice points for every pair */
    for (i = 0; i < P->count; ++i) {
        float v[9];
        rad__ff_patch_corners(f, i, v);
        for (s = 0; s < f->o.samples; ++s)
            rad__lattice_point(v, v + 3, v + 6, rad__lattice_side(f->o.samples), s, f->pts + ((size_t)i * f->o.samples + s) * 3u);
    }
    return RAD_SUCCESS;
}

static void rad__ff_totals(const rad__ff *f, uint64_t *rays, uint64_t *pairs)
{
    uint32_t t;
    *rays = 0;
    *pairs = 0;
    for (t = 0; t < f->tasks; ++t) { *rays += f->rays_cast[t]; *pairs += f->pairs[t]; }
}

/* rows call: task rows are numbered from 0; the matrix row is row_begin + that */
static rad_result rad__ff_row_offset(void *data, uint32_t row, uint32_t task)
{
    rad__ff *f = (rad__ff *)data;
    return rad__ff_row(data, f->row_begin + row, task);
}

RAD_API rad_result rad_form_factor_rows(const rad_patches *patches, const rad_raycaster *raycaster,
                                        const rad_form_factor_options *options, uint32_t row_begin, uint32_t row_end,
                                        float *out_rows, const rad_context *ctx)
{
    rad__ctx c;
    rad__ff f;
    rad_result r;
    rad__ctx_init(&c, ctx);
    if (!patches || !out_rows || row_begin > row_end || row_end > patches->count) return RAD_ERROR_INVALID_ARGUMENT;
    if (row_end == row_begin) return RAD_SUCCESS;
    if (row_end - row_begin < c.tasks) c.tasks = row_end - row_begin;
    r = rad__ff_setup(&f, patches, raycaster, options, &c);
    if (r != RAD_SUCCESS) return r;
    f.out = out_rows;
    f.row_begin = row_begin;
    f.out_stride = patches->count;
    r = rad__for_rows(&c, row_end - row_begin, f.tasks, rad__ff_row_offset, &f);
    rad__ff_release(&f, &c.allocator);
    return r;
}

RAD_API void rad_form_factors_destroy(rad_form_factors *ff)
{
    rad_allocator a;
    if (!ff) return;
    a = ff->allocator;
    rad__free(&a, ff->storage);
    rad__free(&a, (void *)(uintptr_t)ff->matrix.row_offsets);
    rad__free(&a, (void *)(uintptr_t)ff->matrix.columns);
    rad__free(&a, (void *)(uintptr_t)ff->matrix.values);
    rad__free(&a, ff);
}

RAD_API rad_result rad_form_factors_dense(const rad_patches *patches, const rad_raycaster *raycaster,
                                          const rad_form_factor_options *options, const rad_context *ctx,
                                          rad_form_factors **out)
{
    rad__ctx c;
    rad__ff f;
    rad_result r;
    rad_form_factors *ff;
    size_t bytes;
    uint32_t N;
    rad__ctx_init(&c, ctx);
    if (!out) return RAD_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    if (!patches) return RAD_ERROR_INVALID_ARGUMENT;
    N = patches->count;
    if (!rad__mul3(N, N, sizeof(float), &bytes)) {
        rad__log(&c, RAD_LOG_ERROR, "a dense %u x %u matrix does not fit in memory addresses", N, N);
        return RAD_ERROR_SIZE_OVERFLOW;
    }
    ff = (rad_form_factors *)rad__alloc(&c.allocator, sizeof(rad_form_factors));
    if (!ff) return RAD_ERROR_OUT_OF_MEMORY;
    memset(ff, 0, sizeof(*ff));
    ff->allocator = c.allocator;
    ff->storage = rad__alloc(&c.allocator, bytes);
    if (!ff->storage) {
        rad__log(&c, RAD_LOG_ERROR, "cannot allocate %llu bytes for a dense %u x %u matrix", (unsigned long long)bytes, N, N);
        rad_form_factors_destroy(ff);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    r = rad__ff_setup(&f, patches, raycaster, options, &c);
    if (r != RAD_SUCCESS) { rad_form_factors_destroy(ff); return r; }
    f.out = (float *)ff->storage;
    if (f.o.method == RAD_FF_HEMICUBE) {
        f.out_stride = N; /* every row on its own, as the rows call */
    } else {
        f.dense_mode = 1;
        /* the last row has no j > i: write its diagonal here */
        f.out[(size_t)N * N - 1] = 0.0f;
    }
    r = rad__for_rows(&c, N, f.tasks, rad__ff_row, &f);
    rad__ff_totals(&f, &ff->rays_cast, &ff->pairs_evaluated);
    rad__ff_release(&f, &c.allocator);
    if (r != RAD_SUCCESS) { rad_form_factors_destroy(ff); return r; }
    ff->matrix.rows = ff->matrix.cols = N;
    ff->matrix.storage = RAD_STORAGE_DENSE;
    ff->matrix.dense = (const float *)ff->storage;
    *out = ff;
    return RAD_SUCCESS;
}

RAD_API rad_result rad_form_factors_sparse(const rad_patches *patches, const rad_raycaster *raycaster,
                                           const rad_form_factor_options *options, const rad_context *ctx,
                                           rad_form_factors **out)
{
    rad__ctx c;
    rad__ff f;
    rad_result r = RAD_SUCCESS;
    rad_form_factors *ff;
    uint32_t N, batch, b0, j;
    float *buf = NULL, thr;
    uint64_t *offs = NULL, nnz = 0, cap = 0, rays = 0, pairs = 0;
    uint32_t *cols = NULL;
    float *vals = NULL;
    int (*user_progress)(void *, float);
    rad__ctx_init(&c, ctx);
    if (!out) return RAD_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    if (!patches) return RAD_ERROR_INVALID_ARGUMENT;
    N = patches->count;
    r = rad__ff_setup(&f, patches, raycaster, options, &c);
    if (r != RAD_SUCCESS) return r;
    thr = f.o.drop_threshold;
    /* rows per batch: about 16M floats of scratch, at least one row per task */
    batch = (uint32_t)(((size_t)1 << 24) / (N ? N : 1));
    if (batch < f.tasks) batch = f.tasks;
    if (batch > N) batch = N;
    ff = (rad_form_factors *)rad__alloc(&c.allocator, sizeof(rad_form_factors));
    buf = (float *)rad__alloc_array(&c.allocator, (size_t)batch * N, sizeof(float));
    offs = (uint64_t *)rad__alloc_array(&c.allocator, (size_t)N + 1u, sizeof(uint64_t));
    if (!ff || !buf || !offs) { r = RAD_ERROR_OUT_OF_MEMORY; goto fail; }
    memset(ff, 0, sizeof(*ff));
    ff->allocator = c.allocator;
    f.out = buf;
    f.out_stride = N;
    offs[0] = 0;
    user_progress = c.progress;
    c.progress = NULL; /* progress is reported per batch below */
    for (b0 = 0; b0 < N && r == RAD_SUCCESS; b0 += batch) {
        uint32_t b1 = b0 + batch > N ? N : b0 + batch, i;
        f.row_begin = b0;
        r = rad__for_rows(&c, b1 - b0, f.tasks, rad__ff_row_offset, &f);
        if (r != RAD_SUCCESS) break;
        for (i = b0; i < b1; ++i) {
            const float *row = buf + (size_t)(i - b0) * N;
            for (j = 0; j < N; ++j) {
                if (!(row[j] > thr) || row[j] == 0.0f) continue;
                if (nnz == cap) {
                    uint64_t ncap = cap ? cap * 2u : 1024u;
                    size_t ob, nb;
                    uint32_t *nc;
                    float *nv;
                    if (!rad__mul((size_t)ncap, sizeof(float), &nb) || ncap != (uint64_t)(size_t)ncap) {
                        r = RAD_ERROR_SIZE_OVERFLOW;
                        goto fail;
                    }
                    ob = (size_t)cap * sizeof(float);
                    nc = (uint32_t *)rad__realloc(&c.allocator, cols, ob, nb);
                    if (!nc) { r = RAD_ERROR_OUT_OF_MEMORY; goto fail; }
                    cols = nc;
                    nv = (float *)rad__realloc(&c.allocator, vals, ob, nb);
                    if (!nv) { r = RAD_ERROR_OUT_OF_MEMORY; goto fail; }
                    vals = nv;
                    cap = ncap;
                }
                cols[nnz] = j;
                vals[nnz] = row[j];
                ++nnz;
            }
            offs[i + 1] = nnz;
        }
        if (user_progress && user_progress(c.progress_user, (float)b1 / (float)N)) r = RAD_ERROR_CANCELLED;
    }
    if (r != RAD_SUCCESS) goto fail;
    rad__ff_totals(&f, &rays, &pairs);
    rad__ff_release(&f, &c.allocator);
    rad__free(&c.allocator, buf);
    ff->rays_cast = rays;
    ff->pairs_evaluated = pairs;
    ff->matrix.rows = ff->matrix.cols = N;
    ff->matrix.storage = RAD_STORAGE_SPARSE;
    ff->matrix.row_offsets = offs;
    ff->matrix.columns = cols ? cols : (uint32_t *)rad__alloc(&c.allocator, sizeof(uint32_t));
    ff->matrix.values = vals ? vals : (float *)rad__alloc(&c.allocator, sizeof(float));
    if (!ff->matrix.columns || !ff->matrix.values) { rad_form_factors_destroy(ff); return RAD_ERROR_OUT_OF_MEMORY; }
    *out = ff;
    return RAD_SUCCESS;
fail:
    rad__ff_release(&f, &c.allocator);
    rad__free(&c.allocator, buf);
    rad__free(&c.allocator, offs);
    rad__free(&c.allocator, cols);
    rad__free(&c.allocator, vals);
    rad__free(&c.allocator, ff);
    return r;
}

/* ======================================================================================== */
/* >>solve: classic solvers                                                                 */
/* ======================================================================================== */

RAD_API void rad_solve_options_default(rad_solve_options *o)
{
    if (!o) return;
    memset(o, 0, sizeof(*o));
    o->output = RAD_OUTPUT_INDIRECT;
    o->bounces = 8;
    o->tolerance = 1e-6;
}

RAD_API void rad_system_init(rad_system *system, const rad_matrix *F, const rad_patches *patches, const float *E)
{
    if (!system) return;
    memset(system, 0, sizeof(*system));
    system->F = F;
    system->E = E;
    if (patches) {
        system->albedo = patches->albedo;
        system->areas = patches->areas;
        system->n = patches->count;
    } else if (F) {
        system->n = F->rows;
    }
}

/* A matrix view before use. CSR structure is checked in full (offsets from 0, never
   decreasing; columns ascending and < cols): a hand-built matrix cannot send a product out
   of its arrays. O(rows + non-zeros), beside the O(non-zeros) of any use of it. */
static rad_result rad__check_matrix(const rad_matrix *F, const rad__ctx *c)
{
    uint32_t i;
    uint64_t p;
    if (!F) return RAD_ERROR_INVALID_ARGUMENT;
    if (F->storage == RAD_STORAGE_DENSE) return F->dense ? RAD_SUCCESS : RAD_ERROR_INVALID_ARGUMENT;
    if (F->storage != RAD_STORAGE_SPARSE || !F->row_offsets || !F->columns || !F->values) return RAD_ERROR_INVALID_ARGUMENT;
    if (F->rows > 0 && F->row_offsets[0] != 0) {
        rad__log(c, RAD_LOG_ERROR, "CSR matrix: row_offsets[0] is %llu, must be 0", (unsigned long long)F->row_offsets[0]);
        return RAD_ERROR_CORRUPT;
    }
    for (i = 0; i < F->rows; ++i) {
        uint64_t b = F->row_offsets[i], e = F->row_offsets[i + 1];
        if (e < b || e - b > F->cols) {
            rad__log(c, RAD_LOG_ERROR, "CSR matrix: row %u spans offsets %llu to %llu (must not decrease nor exceed %u columns)", i,
                     (unsigned long long)b, (unsigned long long)e, F->cols);
            return RAD_ERROR_CORRUPT;
        }
        for (p = b; p < e; ++p)
            if (F->columns[p] >= F->cols || (p > b && F->columns[p] <= F->columns[p - 1])) {
                rad__log(c, RAD_LOG_ERROR, "CSR matrix: row %u has column %u at entry %llu (columns must ascend and be < %u)", i,
                         F->columns[p], (unsigned long long)p, F->cols);
                return RAD_ERROR_CORRUPT;
            }
    }
    return RAD_SUCCESS;
}

/* options every solver shares: a known output kind, a finite non-negative tolerance */
static rad_result rad__check_solve_options(const rad_solve_options *o, const rad__ctx *c)
{
    if (!o) return RAD_SUCCESS;
    if ((o->output != RAD_OUTPUT_INDIRECT && o->output != RAD_OUTPUT_TOTAL) || !(o->tolerance >= 0.0) ||
        o->tolerance - o->tolerance != 0.0) {
        rad__log(c, RAD_LOG_ERROR, "solve options: output must be RAD_OUTPUT_INDIRECT or RAD_OUTPUT_TOTAL and tolerance finite and >= 0");
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    return RAD_SUCCESS;
}

static rad_result rad__check_system(const rad_system *s, const rad__ctx *c)
{
    rad_result r;
    size_t i;
    if (!s || !s->albedo || !s->E) return RAD_ERROR_INVALID_ARGUMENT;
    r = rad__check_matrix(s->F, c);
    if (r != RAD_SUCCESS) return r;
    if (s->F->rows != s->n || s->F->cols != s->n || s->n == 0) {
        rad__log(c, RAD_LOG_ERROR, "system: the matrix is %u x %u but n is %u", s->F->rows, s->F->cols, s->n);
        return s->n == 0 ? RAD_ERROR_INVALID_ARGUMENT : RAD_ERROR_SIZE_MISMATCH;
    }
    for (i = 0; i < 3 * (size_t)s->n; ++i)
        if (!(s->albedo[i] >= 0.0f && s->albedo[i] < 1.0f)) {
            rad__log(c, RAD_LOG_ERROR, "system: albedo of patch %llu channel %u is %g (must be in [0,1): the system diverges)",
                     (unsigned long long)(i / 3u), (unsigned)(i % 3u), (double)s->albedo[i]);
            return RAD_ERROR_ALBEDO_RANGE;
        }
    return r;
}

/* dot products of one dense row with three vectors (structure of arrays) */
static void rad__dot3(const float *row, const float *xr, const float *xg, const float *xb, uint32_t n, float *o)
{
    uint32_t j = 0;
    float sr = 0.0f, sg = 0.0f, sb = 0.0f;
#if defined(RAD__AVX)
    {
        __m256 ar = _mm256_setzero_ps(), ag = _mm256_setzero_ps(), ab = _mm256_setzero_ps();
        __m256 ar2 = _mm256_setzero_ps(), ag2 = _mm256_setzero_ps(), ab2 = _mm256_setzero_ps();
        float t[8];
        int k;
        /* six independent sums keep the adders busy; the matrix row streams once */
        for (; j + 16 <= n; j += 16) {
            __m256 f = _mm256_loadu_ps(row + j), f2 = _mm256_loadu_ps(row + j + 8);
            _mm_prefetch((const char *)(row + j + 256), _MM_HINT_T0); /* 1 KiB ahead */
            ar = _mm256_add_ps(ar, _mm256_mul_ps(f, _mm256_loadu_ps(xr + j)));
            ag = _mm256_add_ps(ag, _mm256_mul_ps(f, _mm256_loadu_ps(xg + j)));
            ab = _mm256_add_ps(ab, _mm256_mul_ps(f, _mm256_loadu_ps(xb + j)));
            ar2 = _mm256_add_ps(ar2, _mm256_mul_ps(f2, _mm256_loadu_ps(xr + j + 8)));
            ag2 = _mm256_add_ps(ag2, _mm256_mul_ps(f2, _mm256_loadu_ps(xg + j + 8)));
            ab2 = _mm256_add_ps(ab2, _mm256_mul_ps(f2, _mm256_loadu_ps(xb + j + 8)));
        }
        ar = _mm256_add_ps(ar, ar2);
        ag = _mm256_add_ps(ag, ag2);
        ab = _mm256_add_ps(ab, ab2);
        _mm256_storeu_ps(t, ar); for (k = 0; k < 8; ++k) sr += t[k];
        _mm256_storeu_ps(t, ag); for (k = 0; k < 8; ++k) sg += t[k];
        _mm256_storeu_ps(t, ab); for (k = 0; k < 8; ++k) sb += t[k];
    }
#elif defined(RAD__SSE2)
    {
        __m128 ar = _mm_setzero_ps(), ag = _mm_setzero_ps(), ab = _mm_setzero_ps();
        __m128 ar2 = _mm_setzero_ps(), ag2 = _mm_setzero_ps(), ab2 = _mm_setzero_ps();
        float t[4];
        int k;
        for (; j + 8 <= n; j += 8) {
            __m128 f = _mm_loadu_ps(row + j), f2 = _mm_loadu_ps(row + j + 4);
            _mm_prefetch((const char *)(row + j + 256), _MM_HINT_T0); /* 1 KiB ahead */
            ar = _mm_add_ps(ar, _mm_mul_ps(f, _mm_loadu_ps(xr + j)));
            ag = _mm_add_ps(ag, _mm_mul_ps(f, _mm_loadu_ps(xg + j)));
            ab = _mm_add_ps(ab, _mm_mul_ps(f, _mm_loadu_ps(xb + j)));
            ar2 = _mm_add_ps(ar2, _mm_mul_ps(f2, _mm_loadu_ps(xr + j + 4)));
            ag2 = _mm_add_ps(ag2, _mm_mul_ps(f2, _mm_loadu_ps(xg + j + 4)));
            ab2 = _mm_add_ps(ab2, _mm_mul_ps(f2, _mm_loadu_ps(xb + j + 4)));
        }
        _mm_storeu_ps(t, _mm_add_ps(ar, ar2)); for (k = 0; k < 4; ++k) sr += t[k];
        _mm_storeu_ps(t, _mm_add_ps(ag, ag2)); for (k = 0; k < 4; ++k) sg += t[k];
        _mm_storeu_ps(t, _mm_add_ps(ab, ab2)); for (k = 0; k < 4; ++k) sb += t[k];
    }
#endif
    for (; j < n; ++j) {
        sr += row[j] * xr[j];
        sg += row[j] * xg[j];
        sb += row[j] * xb[j];
    }
    o[0] = sr;
    o[1] = sg;
    o[2] = sb;
}

#if defined(RAD__AVX)
/* two rows at once: each load of x serves both rows, so x (in L2) is read half as often */
static void rad__dot3x2(const float *r0, const float *r1, const float *xr, const float *xg, const float *xb, uint32_t n,
                        float *o0, float *o1)
{
    __m256 a0 = _mm256_setzero_ps(), a1 = _mm256_setzero_ps(), a2 = _mm256_setzero_ps();
    __m256 b0 = _mm256_setzero_ps(), b1 = _mm256_setzero_ps(), b2 = _mm256_setzero_ps();
    float t[8], s[6] = { 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f };
    uint32_t j = 0;
    int k;
    for (; j + 8 <= n; j += 8) {
        __m256 f = _mm256_loadu_ps(r0 + j), g = _mm256_loadu_ps(r1 + j);
        __m256 x0 = _mm256_loadu_ps(xr + j), x1 = _mm256_loadu_ps(xg + j), x2 = _mm256_loadu_ps(xb + j);
        _mm_prefetch((const char *)(r0 + j + 256), _MM_HINT_T0);
        _mm_prefetch((const char *)(r1 + j + 256), _MM_HINT_T0);
        a0 = _mm256_add_ps(a0, _mm256_mul_ps(f, x0));
        a1 = _mm256_add_ps(a1, _mm256_mul_ps(f, x1));
        a2 = _mm256_add_ps(a2, _mm256_mul_ps(f, x2));
        b0 = _mm256_add_ps(b0, _mm256_mul_ps(g, x0));
        b1 = _mm256_add_ps(b1, _mm256_mul_ps(g, x1));
        b2 = _mm256_add_ps(b2, _mm256_mul_ps(g, x2));
    }
    _mm256_storeu_ps(t, a0); for (k = 0; k < 8; ++k) s[0] += t[k];
    _mm256_storeu_ps(t, a1); for (k = 0; k < 8; ++k) s[1] += t[k];
    _mm256_storeu_ps(t, a2); for (k = 0; k < 8; ++k) s[2] += t[k];
    _mm256_storeu_ps(t, b0); for (k = 0; k < 8; ++k) s[3] += t[k];
    _mm256_storeu_ps(t, b1); for (k = 0; k < 8; ++k) s[4] += t[k];
    _mm256_storeu_ps(t, b2); for (k = 0; k < 8; ++k) s[5] += t[k];
    for (; j < n; ++j) {
        s[0] += r0[j] * xr[j]; s[1] += r0[j] * xg[j]; s[2] += r0[j] * xb[j];
        s[3] += r1[j] * xr[j]; s[4] += r1[j] * xg[j]; s[5] += r1[j] * xb[j];
    }
    o0[0] = s[0]; o0[1] = s[1]; o0[2] = s[2];
    o1[0] = s[3]; o1[1] = s[4]; o1[2] = s[5];
}
#endif

typedef struct rad__mv {
    const rad_matrix *F;
    const float *x;          /* interleaved RGB */
    const float *soa;        /* dense: x as three arrays of n */
    float *out;
    uint32_t tasks;
} rad__mv;

static void rad__mv_task(void *data, uint32_t t)
{
    const rad__mv *m = (const rad__mv *)data;
    const rad_matrix *F = m->F;
    /* chunk boundaries on even rows: rows 2k and 2k+1 always share the two-row kernel, so the
       bits do not depend on the number of tasks */
    uint32_t r0 = (uint32_t)((uint64_t)F->rows * t / m->tasks) & ~1u, r1 = (uint32_t)((uint64_t)F->rows * (t + 1) / m->tasks) & ~1u, i;
    if (t + 1 == m->tasks) r1 = F->rows;
    for (i = r0; i < r1; ++i) {
        if (F->storage == RAD_STORAGE_DENSE) {
            const float *xr = m->soa, *xg = m->soa + F->cols, *xb = m->soa + 2 * (size_t)F->cols;
#if defined(RAD__AVX)
            if (i + 1 < r1) {
                rad__dot3x2(F->dense + (size_t)i * F->cols, F->dense + (size_t)(i + 1) * F->cols, xr, xg, xb, F->cols,
                            m->out + 3 * (size_t)i, m->out + 3 * (size_t)(i + 1));
                ++i;
                continue;
            }
#endif
            rad__dot3(F->dense + (size_t)i * F->cols, xr, xg, xb, F->cols, m->out + 3 * (size_t)i);
        } else {
            uint64_t k;
            float s0 = 0.0f, s1 = 0.0f, s2 = 0.0f;
            for (k = F->row_offsets[i]; k < F->row_offsets[i + 1]; ++k) {
                const float *xj = m->x + 3 * (size_t)F->columns[k];
                float v = F->values[k];
                s0 += v * xj[0];
                s1 += v * xj[1];
                s2 += v * xj[2];
            }
            m->out[3 * (size_t)i] = s0;
            m->out[3 * (size_t)i + 1] = s1;
            m->out[3 * (size_t)i + 2] = s2;
        }
    }
}

/* out = F x; soa is scratch of 3 * cols floats (dense only) */
static void rad__matvec(const rad__ctx *c, const rad_matrix *F, const float *x, float *out, float *soa)
{
    rad__mv m;
    uint32_t j, tasks = c->tasks;
    if (F->storage == RAD_STORAGE_DENSE) {
        for (j = 0; j < F->cols; ++j) {
            soa[j] = x[3 * (size_t)j];
            soa[(size_t)F->cols + j] = x[3 * (size_t)j + 1];
            soa[2 * (size_t)F->cols + j] = x[3 * (size_t)j + 2];
        }
    }
    if (tasks > F->rows) tasks = F->rows ? F->rows : 1;
    m.F = F;
    m.x = x;
    m.soa = soa;
    m.out = out;
    m.tasks = tasks;
    c->parallel_for(c->parallel_user, tasks, rad__mv_task, &m);
}

RAD_API rad_result rad_matrix_multiply(const rad_matrix *F, const float *x, float *out, const rad_context *ctx)
{
    rad__ctx c;
    float *soa = NULL;
    rad_result r;
    rad__ctx_init(&c, ctx);
    r = rad__check_matrix(F, &c);
    if (r != RAD_SUCCESS) return r;
    if (!x || !out || x == out) return RAD_ERROR_INVALID_ARGUMENT;
    if (F->rows == 0) return RAD_SUCCESS;
    if (rad__check_input(&c, "rad_matrix_multiply", x, 3 * (size_t)F->cols) != RAD_SUCCESS) return RAD_ERROR_NON_FINITE;
    if (F->storage == RAD_STORAGE_DENSE) {
        soa = (float *)rad__alloc_array(&c.allocator, (size_t)F->cols * 3u, sizeof(float));
        if (!soa) return RAD_ERROR_OUT_OF_MEMORY;
    }
    rad__matvec(&c, F, x, out, soa);
    rad__free(&c.allocator, soa);
    return rad__check_output(&c, "rad_matrix_multiply", out, 3 * (size_t)F->rows);
}

static void rad__finish_output(const rad_system *s, rad_output output, float *B_total_or_L, int have_total)
{
    /* converts in place between B (total) and L = B - E as the caller asked */
    size_t i, n3 = 3 * (size_t)s->n;
    if (have_total && output == RAD_OUTPUT_INDIRECT)
        for (i = 0; i < n3; ++i) B_total_or_L[i] -= s->E[i];
    if (!have_total && output == RAD_OUTPUT_TOTAL)
        for (i = 0; i < n3; ++i) B_total_or_L[i] += s->E[i];
}

RAD_API rad_result rad_solve_jacobi(const rad_system *s, const rad_solve_options *options, float *out, rad_solve_stats *stats,
                                    const rad_context *ctx)
{
    rad__ctx c;
    rad_solve_options o;
    float *cur, *tmp, *soa = NULL;
    size_t n3, i;
    uint32_t k;
    rad_result r;
    rad__ctx_init(&c, ctx);
    r = rad__check_system(s, &c);
    if (r != RAD_SUCCESS) return r;
    if (!out) return RAD_ERROR_INVALID_ARGUMENT;
    if (options) o = *options; else rad_solve_options_default(&o);
    if (rad__check_solve_options(&o, &c) != RAD_SUCCESS) return RAD_ERROR_INVALID_ARGUMENT;
    n3 = 3 * (size_t)s->n;
    cur = (float *)rad__alloc_array(&c.allocator, n3, sizeof(float));
    tmp = (float *)rad__alloc_array(&c.allocator, n3, sizeof(float));
    if (s->F->storage == RAD_STORAGE_DENSE) soa = (float *)rad__alloc_array(&c.allocator, n3, sizeof(float));
    if (!cur || !tmp || (s->F->storage == RAD_STORAGE_DENSE && !soa)) {
        rad__free(&c.allocator, cur); rad__free(&c.allocator, tmp); rad__free(&c.allocator, soa);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    memcpy(cur, s->E, n3 * sizeof(float));
    for (i = 0; i < n3; ++i) out[i] = 0.0f;
    for (k = 0; k < o.bounces; ++k) {
        rad__matvec(&c, s->F, cur, tmp, soa);
        for (i = 0; i < n3; ++i) {
            cur[i] = s->albedo[i] * tmp[i];
            out[i] += cur[i];
        }
        if (c.progress && c.progress(c.progress_user, (float)(k + 1) / (float)o.bounces)) { r = RAD_ERROR_CANCELLED; break; }
    }
    rad__free(&c.allocator, cur);
    rad__free(&c.allocator, tmp);
    rad__free(&c.allocator, soa);
    if (r != RAD_SUCCESS) return r;
    rad__finish_output(s, o.output, out, 0);
    if (stats) { stats->iterations = o.bounces; stats->residual = 0.0; }
    return rad__check_output(&c, "Jacobi", out, n3);
}

/* sum_j F_ij x_j over j != i for RGB x; *diag receives F_ii */
static void rad__row_gather(const rad_matrix *F, uint32_t i, const float *x, double *o, double *diag)
{
    double s0 = 0.0, s1 = 0.0, s2 = 0.0;
    *diag = 0.0;
    if (F->storage == RAD_STORAGE_DENSE) {
        const float *row = F->dense + (size_t)i * F->cols;
        uint32_t j;
        for (j = 0; j < F->cols; ++j) {
            double v = row[j];
            if (j == i) { *diag = v; continue; }
            s0 += v * x[3 * (size_t)j];
            s1 += v * x[3 * (size_t)j + 1];
            s2 += v * x[3 * (size_t)j + 2];
        }
    } else {
        uint64_t k;
        for (k = F->row_offsets[i]; k < F->row_offsets[i + 1]; ++k) {
            uint32_t j = F->columns[k];
            double v = F->values[k];
            if (j == i) { *diag = v; continue; }
            s0 += v * x[3 * (size_t)j];
            s1 += v * x[3 * (size_t)j + 1];
            s2 += v * x[3 * (size_t)j + 2];
        }
    }
    o[0] = s0; o[1] = s1; o[2] = s2;
}

RAD_API rad_result rad_solve_gauss_seidel(const rad_system *s, const rad_solve_options *options, float *out,
                                          rad_solve_stats *stats, const rad_context *ctx)
{
    rad__ctx c;
    rad_solve_options o;
    size_t n3, i;
    uint32_t it, row, max_it;
    double maxE = 0.0, residual = 0.0, tol;
    rad_result r = RAD_ERROR_NOT_CONVERGED;
    rad__ctx_init(&c, ctx);
    {
        rad_result checked = rad__check_system(s, &c); /* logs once */
        if (checked != RAD_SUCCESS) return checked;
    }
    if (!out) return RAD_ERROR_INVALID_ARGUMENT;
    if (options) o = *options; else rad_solve_options_default(&o);
    if (rad__check_solve_options(&o, &c) != RAD_SUCCESS) return RAD_ERROR_INVALID_ARGUMENT;
    tol = o.tolerance > 0.0 ? o.tolerance : 1e-6;
    max_it = o.max_iterations ? o.max_iterations : 1000;
    n3 = 3 * (size_t)s->n;
    memcpy(out, s->E, n3 * sizeof(float));
    for (i = 0; i < n3; ++i) if (fabs((double)s->E[i]) > maxE) maxE = fabs((double)s->E[i]);
    if (maxE == 0.0) r = RAD_SUCCESS, it = 0;
    else
        for (it = 0; it < max_it;) {
            double maxd = 0.0;
            for (row = 0; row < s->n; ++row) {
                double g[3], diag;
                int k;
                rad__row_gather(s->F, row, out, g, &diag);
                for (k = 0; k < 3; ++k) {
                    size_t at = 3 * (size_t)row + (size_t)k;
                    double rho = s->albedo[at], nb = ((double)s->E[at] + rho * g[k]) / (1.0 - rho * diag);
                    double d = fabs(nb - (double)out[at]);
                    if (d > maxd) maxd = d;
                    out[at] = (float)nb;
                }
            }
            ++it;
            residual = maxd / maxE;
            if (o.on_residual && o.on_residual(o.residual_user, it, residual)) { r = RAD_SUCCESS; break; }
            if (residual < tol) { r = RAD_SUCCESS; break; }
            if (c.progress && c.progress(c.progress_user, (float)it / (float)max_it)) { r = RAD_ERROR_CANCELLED; break; }
        }
    if (stats) { stats->iterations = it; stats->residual = residual; }
    if (r == RAD_ERROR_CANCELLED) return r;
    rad__finish_output(s, o.output, out, 1);
    if (rad__check_output(&c, "Gauss-Seidel", out, n3) != RAD_SUCCESS) return RAD_ERROR_NON_FINITE;
    if (r == RAD_ERROR_NOT_CONVERGED)
        rad__log(&c, RAD_LOG_WARNING, "Gauss-Seidel: residual %g after %u sweeps (tolerance %g)", residual, it, tol);
    return r;
}

RAD_API rad_result rad_solve_progressive(const rad_system *s, const rad_solve_options *options, float *out,
                                         rad_solve_stats *stats, const rad_context *ctx)
{
    rad__ctx c;
    rad_solve_options o;
    float *dB;
    size_t n3;
    uint32_t step = 0, i, max_steps;
    double initial = 0.0, residual = 1.0, tol;
    rad_result r = RAD_ERROR_NOT_CONVERGED;
    rad__ctx_init(&c, ctx);
    {
        rad_result checked = rad__check_system(s, &c); /* logs once */
        if (checked != RAD_SUCCESS) return checked;
    }
    if (!out || !s->areas) {
        rad__log(&c, RAD_LOG_ERROR, "progressive refinement needs system->areas");
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    if (options) o = *options; else rad_solve_options_default(&o);
    if (rad__check_solve_options(&o, &c) != RAD_SUCCESS) return RAD_ERROR_INVALID_ARGUMENT;
    tol = o.tolerance > 0.0 ? o.tolerance : 1e-6;
    max_steps = o.max_iterations ? o.max_iterations : (s->n > 42949672u ? 0xFFFFFFFFu : 100u * s->n);
    n3 = 3 * (size_t)s->n;
    dB = (float *)rad__alloc_array(&c.allocator, n3, sizeof(float));
    if (!dB) return RAD_ERROR_OUT_OF_MEMORY;
    memcpy(out, s->E, n3 * sizeof(float));
    memcpy(dB, s->E, n3 * sizeof(float));
    for (i = 0; i < s->n; ++i)
        initial += (double)s->areas[i] * (fabs((double)dB[3 * (size_t)i]) + fabs((double)dB[3 * (size_t)i + 1]) +
                                          fabs((double)dB[3 * (size_t)i + 2]));
    if (initial == 0.0) { r = RAD_SUCCESS; residual = 0.0; }
    while (r == RAD_ERROR_NOT_CONVERGED) {
        double best = -1.0, total = 0.0, shot[3], ai;
        uint32_t bi = 0;
        for (i = 0; i < s->n; ++i) {
            double p = (double)s->areas[i] * (fabs((double)dB[3 * (size_t)i]) + fabs((double)dB[3 * (size_t)i + 1]) +
                                              fabs((double)dB[3 * (size_t)i + 2]));
            total += p;
            if (p > best) { best = p; bi = i; }
        }
        residual = total / initial;
        if (step > 0 && o.on_residual && o.on_residual(o.residual_user, step, residual)) { r = RAD_SUCCESS; break; }
        if (residual < tol) { r = RAD_SUCCESS; break; }
        if (step >= max_steps) break;
        /* shoot bi: every j receives rho_j F_ji dB_bi with F_ji = F_ij A_i / A_j */
        shot[0] = dB[3 * (size_t)bi]; shot[1] = dB[3 * (size_t)bi + 1]; shot[2] = dB[3 * (size_t)bi + 2];
        dB[3 * (size_t)bi] = dB[3 * (size_t)bi + 1] = dB[3 * (size_t)bi + 2] = 0.0f;
        ai = s->areas[bi];
        if (s->F->storage == RAD_STORAGE_DENSE) {
            const float *row = s->F->dense + (size_t)bi * s->F->cols;
            uint32_t j;
            for (j = 0; j < s->n; ++j) {
                double f = row[j];
                int k;
                if (f == 0.0) continue;
                f *= ai / (double)s->areas[j];
                for (k = 0; k < 3; ++k) {
                    size_t at = 3 * (size_t)j + (size_t)k;
                    float d = (float)((double)s->albedo[at] * f * shot[k]);
                    out[at] += d;
                    dB[at] += d;
                }
            }
        } else {
            uint64_t q;
            for (q = s->F->row_offsets[bi]; q < s->F->row_offsets[bi + 1]; ++q) {
                uint32_t j = s->F->columns[q];
                double f = (double)s->F->values[q] * ai / (double)s->areas[j];
                int k;
                for (k = 0; k < 3; ++k) {
                    size_t at = 3 * (size_t)j + (size_t)k;
                    float d = (float)((double)s->albedo[at] * f * shot[k]);
                    out[at] += d;
                    dB[at] += d;
                }
            }
        }
        ++step;
        if (c.progress && (step & 1023u) == 0 && c.progress(c.progress_user, (float)(1.0 - residual))) {
            r = RAD_ERROR_CANCELLED;
            break;
        }
    }
    rad__free(&c.allocator, dB);
    if (stats) { stats->iterations = step; stats->residual = residual; }
    if (r == RAD_ERROR_CANCELLED) return r;
    rad__finish_output(s, o.output, out, 1);
    if (rad__check_output(&c, "progressive refinement", out, n3) != RAD_SUCCESS) return RAD_ERROR_NON_FINITE;
    if (r == RAD_ERROR_NOT_CONVERGED)
        rad__log(&c, RAD_LOG_WARNING, "progressive refinement: residual %g after %u steps (tolerance %g)", residual, step, tol);
    return r;
}

typedef struct rad__lu_job {
    double *M;
    uint32_t n, k, tasks;
} rad__lu_job;

static void rad__lu_task(void *data, uint32_t t)
{
    const rad__lu_job *j = (const rad__lu_job *)data;
    uint32_t rows = j->n - j->k - 1, r0 = j->k + 1 + (uint32_t)((uint64_t)rows * t / j->tasks),
             r1 = j->k + 1 + (uint32_t)((uint64_t)rows * (t + 1) / j->tasks), i, c;
    const double *pk = j->M + (size_t)j->k * j->n;
    for (i = r0; i < r1; ++i) {
        double *ri = j->M + (size_t)i * j->n, l = ri[j->k] / pk[j->k];
        ri[j->k] = l;
        if (l == 0.0) continue;
        for (c = j->k + 1; c < j->n; ++c) ri[c] -= l * pk[c];
    }
}

RAD_API rad_result rad_solve_direct(const rad_system *s, const rad_solve_options *options, float *out, const rad_context *ctx)
{
    rad__ctx c;
    rad_solve_options o;
    double *M = NULL, *b = NULL;
    uint32_t *piv = NULL, n, ch, i, j, k;
    size_t bytes;
    rad_result r = RAD_SUCCESS;
    int factored = -1;
    rad__ctx_init(&c, ctx);
    {
        rad_result checked = rad__check_system(s, &c); /* logs once */
        if (checked != RAD_SUCCESS) return checked;
    }
    if (!out) return RAD_ERROR_INVALID_ARGUMENT;
    if (options) o = *options; else rad_solve_options_default(&o);
    if (rad__check_solve_options(&o, &c) != RAD_SUCCESS) return RAD_ERROR_INVALID_ARGUMENT;
    n = s->n;
    if (!rad__mul3(n, n, sizeof(double), &bytes)) return RAD_ERROR_SIZE_OVERFLOW;
    M = (double *)rad__alloc(&c.allocator, bytes);
    b = (double *)rad__alloc_array(&c.allocator, n, sizeof(double));
    piv = (uint32_t *)rad__alloc_array(&c.allocator, n, sizeof(uint32_t));
    if (!M || !b || !piv) { r = RAD_ERROR_OUT_OF_MEMORY; goto done; }
    for (ch = 0; ch < 3 && r == RAD_SUCCESS; ++ch) {
        /* reuse the factorization when this channel's albedo equals an earlier one's */
        int same = factored >= 0;
        for (i = 0; i < n && same; ++i) same = s->albedo[3 * (size_t)i + ch] == s->albedo[3 * (size_t)i + (uint32_t)factored];
        if (!same) {
            for (i = 0; i < n; ++i) {
                double rho = s->albedo[3 * (size_t)i + ch];
                double *row = M + (size_t)i * n;
                if (s->F->storage == RAD_STORAGE_DENSE) {
                    const float *fr = s->F->dense + (size_t)i * n;
                    for (j = 0; j < n; ++j) row[j] = -rho * (double)fr[j];
                } else {
                    uint64_t q;
                    for (j = 0; j < n; ++j) row[j] = 0.0;
                    for (q = s->F->row_offsets[i]; q < s->F->row_offsets[i + 1]; ++q) row[s->F->columns[q]] = -rho * (double)s->F->values[q];
                }
                row[i] += 1.0;
            }
            for (k = 0; k < n; ++k) {
                double best = fabs(M[(size_t)k * n + k]);
                uint32_t p = k;
                rad__lu_job job;
                for (i = k + 1; i < n; ++i)
                    if (fabs(M[(size_t)i * n + k]) > best) { best = fabs(M[(size_t)i * n + k]); p = i; }
                if (!(best > 1e-14)) {
                    rad__log(&c, RAD_LOG_ERROR, "direct solve: pivot %g in column %u (channel %u)", best, k, ch);
                    r = RAD_ERROR_SINGULAR;
                    break;
                }
                piv[k] = p;
                if (p != k)
                    for (j = 0; j < n; ++j) {
                        double t = M[(size_t)k * n + j];
                        M[(size_t)k * n + j] = M[(size_t)p * n + j];
                        M[(size_t)p * n + j] = t;
                    }
                if (k + 1 < n) {
                    job.M = M;
                    job.n = n;
                    job.k = k;
                    job.tasks = c.tasks < n - k - 1 ? c.tasks : n - k - 1;
                    /* small trailing blocks are not worth a parallel_for (its overhead dominates) */
                    if ((uint64_t)(n - k - 1) * (n - k - 1) < 65536u) {
                        job.tasks = 1;
                        rad__lu_task(&job, 0);
                    } else {
                        c.parallel_for(c.parallel_user, job.tasks, rad__lu_task, &job);
                    }
                }
            }
            if (r != RAD_SUCCESS) break;
            factored = (int)ch;
        }
        for (i = 0; i < n; ++i) b[i] = s->E[3 * (size_t)i + ch];
        for (k = 0; k < n; ++k) {
            if (piv[k] != k) { double t = b[k]; b[k] = b[piv[k]]; b[piv[k]] = t; }
        }
        for (i = 0; i < n; ++i) {
            const double *row = M + (size_t)i * n;
            double acc = b[i];
            for (j = 0; j < i; ++j) acc -= row[j] * b[j];
            b[i] = acc;
        }
        for (i = n; i-- > 0;) {
            const double *row = M + (size_t)i * n;
            double acc = b[i];
            for (j = i + 1; j < n; ++j) acc -= row[j] * b[j];
            b[i] = acc / row[i];
        }
        for (i = 0; i < n; ++i) out[3 * (size_t)i + ch] = (float)b[i];
        if (c.progress && c.progress(c.progress_user, (float)(ch + 1) / 3.0f)) r = RAD_ERROR_CANCELLED;
    }
    if (r == RAD_SUCCESS) {
        if (o.output == RAD_OUTPUT_INDIRECT)
            for (i = 0; i < 3 * n; ++i) out[i] -= s->E[i];
        r = rad__check_output(&c, "direct solve", out, 3 * (size_t)n);
    }
done:
    rad__free(&c.allocator, M);
    rad__free(&c.allocator, b);
    rad__free(&c.allocator, piv);
    return r;
}

/* ======================================================================================== */
/* >>light: direct light and the source term                                                */
/* ======================================================================================== */

RAD_API void rad_direct_options_default(rad_direct_options *o)
{
    if (!o) return;
    memset(o, 0, sizeof(*o));
    o->samples = 16;
    o->light_samples = 16;
    o->include_emitters = 1;
    o->ray_epsilon = 1e-5f;
}

#define RAD__DIRECT_GROUP 64u /* points per task row when lighting arbitrary points */

typedef struct rad__direct {
    const rad_scene *S;
    const rad_raycaster *rc;
    const rad_light *lights;
    uint32_t light_count;
    rad_direct_options o;
    float eps;
    uint32_t *emitters;          /* emissive triangles */
    uint32_t emitter_count;
    /* per task scratch */
    rad_ray *rays;
    uint8_t *occ;
    float *ray_w;                /* 3 per ray */
    uint32_t *ray_slot;
    double *acc;                 /* 3 * RAD__DIRECT_GROUP per task */
    /* job */
    const float *points, *normals;
    uint32_t count;
    const rad_patches *P;        /* patch mode when set */
    float *out;
} rad__direct;

static rad_result rad__direct_flush(rad__direct *d, uint32_t task, uint32_t count)
{
    rad_ray *rays = d->rays + (size_t)task * RAD__RAY_BATCH;
    uint8_t *occ = d->occ + (size_t)task * RAD__RAY_BATCH;
    const float *w = d->ray_w + (size_t)task * RAD__RAY_BATCH * 3u;
    const uint32_t *slot = d->ray_slot + (size_t)task * RAD__RAY_BATCH;
    double *acc = d->acc + (size_t)task * RAD__DIRECT_GROUP * 3u;
    uint32_t k;
    if (count == 0) return RAD_SUCCESS;
    if (d->rc->occluded(d->rc->user, rays, count, occ) != RAD_SUCCESS) return RAD_ERROR_RAYCAST_FAILED;
    for (k = 0; k < count; ++k)
        if (!occ[k]) {
            acc[3 * (size_t)slot[k]] += w[3 * (size_t)k];
            acc[3 * (size_t)slot[k] + 1] += w[3 * (size_t)k + 1];
            acc[3 * (size_t)slot[k] + 2] += w[3 * (size_t)k + 2];
        }
    return RAD_SUCCESS;
}

/* queues a shadow ray from p (offset along n) to 'to' (a point, offset along to_n when given)
   or along 'dir' to infinity, carrying weight w (scaled by 'scale') into slot */
static rad_result rad__direct_ray(rad__direct *d, uint32_t task, uint32_t *nrays, const float *p, const float *n,
                                  const float *to, const float *to_n, const float *dir, const float *w, float scale,
                                  uint32_t slot)
{
    size_t at = (size_t)task * RAD__RAY_BATCH + *nrays;
    rad_ray *ray = d->rays + at;
    int k;
    for (k = 0; k < 3; ++k) ray->origin[k] = p[k] + n[k] * d->eps;
    if (to) {
        float len;
        for (k = 0; k < 3; ++k) ray->dir[k] = to[k] + (to_n ? to_n[k] * d->eps : 0.0f) - ray->origin[k];
        len = rad__len(ray->dir);
        ray->tmin = 0.0f;
        ray->tmax = len > 2.0f * d->eps ? 1.0f - d->eps / len : 0.5f;
    } else {
        for (k = 0; k < 3; ++k) ray->dir[k] = dir[k];
        ray->tmin = 0.0f;
        ray->tmax = FLT_MAX;
    }
    for (k = 0; k < 3; ++k) d->ray_w[3 * at + (size_t)k] = w[k] * scale;
    d->ray_slot[at] = slot;
    if (++*nrays == RAD__RAY_BATCH) {
        rad_result r = rad__direct_flush(d, task, *nrays);
        *nrays = 0;
        return r;
    }
    return RAD_SUCCESS;
}

/* Two unit tangents completing the unit normal n to a frame. */
static void rad__tangent_frame(const float *n, float *t1, float *t2)
{
    float a[3] = { 1.0f, 0.0f, 0.0f };
    if (fabs((double)n[0]) > 0.5) { a[0] = 0.0f; a[1] = 1.0f; }
    rad__cross(t1, n, a);
    rad__normalize(t1);
    rad__cross(t2, n, t1);
}

/* Direction s of n cosine-distributed ones around n (frame t1, t2): Hammersley point s of n,
   rotated by the two 16-bit halves of h, lifted from the disk. */
static void rad__cosine_dir(const float *n, const float *t1, const float *t2, uint32_t s, uint32_t count, uint32_t h,
                            float *dir)
{
    float u1, u2, rr, ph;
    int k;
    rad__hammersley(s, count, (float)(h & 0xFFFFu) / 65536.0f, (float)(h >> 16) / 65536.0f, &u1, &u2);
    rr = (float)sqrt((double)u1);
    ph = (float)(2.0 * RAD__PI) * u2;
    for (k = 0; k < 3; ++k)
        dir[k] = t1[k] * rr * (float)cos((double)ph) + t2[k] * rr * (float)sin((double)ph) + n[k] * (float)sqrt((double)(1.0f - u1));
}

/* all lights at one point into slot, each contribution times 'scale' */
static rad_result rad__direct_point(rad__direct *d, uint32_t task, uint32_t *nrays, const float *p, const float *n,
                                    uint32_t slot, float scale, uint32_t seed)
{
    uint32_t l, s, L = d->o.light_samples;
    rad_result r;
    int k;
    for (l = 0; l < d->light_count; ++l) {
        const rad_light *li = &d->lights[l];
        float v[3], w[3], dist, cosn;
        if (li->type == RAD_LIGHT_DIRECTIONAL) {
            for (k = 0; k < 3; ++k) v[k] = -li->direction[k];
            rad__normalize(v);
            cosn = rad__dot(v, n);
            if (!(cosn > 0.0f)) continue;
            for (k = 0; k < 3; ++k) w[k] = li->color[k] * cosn;
            r = rad__direct_ray(d, task, nrays, p, n, NULL, NULL, v, w, scale, slot);
            if (r != RAD_SUCCESS) return r;
        } else if (li->type == RAD_LIGHT_POINT || li->type == RAD_LIGHT_SPOT) {
            float dc, atten, md = li->min_distance > 0.0f ? li->min_distance : 1e-6f * d->S->diagonal;
            rad__sub(v, li->position, p);
            dist = rad__len(v);
            if (!(dist > 0.0f)) continue;
            cosn = rad__dot(v, n) / dist;
            if (!(cosn > 0.0f)) continue;
            dc = dist > md ? dist : md;
            atten = li->falloff == RAD_FALLOFF_LINEAR ? 1.0f / dc : 1.0f / (dc * dc);
            if (li->type == RAD_LIGHT_SPOT) {
                float axis[3], ca, ci = (float)cos((double)li->inner_angle), co = (float)cos((double)li->outer_angle), t;
                memcpy(axis, li->direction, sizeof(axis));
                rad__normalize(axis);
                ca = -rad__dot(v, axis) / dist;
                if (ci > co) {
                    t = (ca - co) / (ci - co);
                    t = t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
                    atten *= t * t * (3.0f - 2.0f * t);
                } else if (!(ca >= co)) {
                    atten = 0.0f;
                }
                if (!(atten > 0.0f)) continue;
            }
            for (k = 0; k < 3; ++k) w[k] = li->color[k] * cosn * atten;
            r = rad__direct_ray(d, task, nrays, p, n, li->position, NULL, NULL, w, scale, slot);
            if (r != RAD_SUCCESS) return r;
        } else if (li->type == RAD_LIGHT_SKY) {
            /* cosine-weighted directions: unoccluded fraction of the hemisphere times E_0 */
            float t1[3], t2[3];
            uint32_t h = rad__hash(seed ^ 0x5bd1e995u ^ l);
            rad__tangent_frame(n, t1, t2);
            for (s = 0; s < L; ++s) {
                float dir[3];
                rad__cosine_dir(n, t1, t2, s, L, h, dir);
                r = rad__direct_ray(d, task, nrays, p, n, NULL, NULL, dir, li->color, scale / (float)L, slot);
                if (r != RAD_SUCCESS) return r;
            }
        }
    }
    if (d->o.include_emitters) {
        double P[3], N[3], ks[RAD__MAX_SAMPLES], ksum;
        float ys[3 * RAD__MAX_SAMPLES];
        for (k = 0; k < 3; ++k) { P[k] = p[k]; N[k] = n[k]; }
        for (l = 0; l < d->emitter_count; ++l) {
            uint32_t t = d->emitters[l], h;
            const float *tv = d->S->positions + 9 * (size_t)t, *tn = d->S->normals + 3 * (size_t)t;
            const float *Le = d->S->materials_table[d->S->materials[t]].emission;
            float dv[3], F, w[3], r1, r2;
            rad__sub(dv, p, tv);
            if (!(rad__dot(dv, tn) > 0.0f)) continue; /* behind the emitter, or on its plane */
            F = (float)fabs(rad__ff_point_tri(P, N, tv));
            if (!(F > 0.0f)) continue;
            for (k = 0; k < 3; ++k) w[k] = (float)RAD__PI * Le[k] * F;
            h = rad__hash(seed ^ rad__hash(t + 0x68e31da4u));
            r1 = (float)(h & 0xFFFFu) / 65536.0f;
            r2 = (float)(h >> 16) / 65536.0f;
            /* Each shadow ray carries its sample's share of the kernel cos cos / r^2 (zero
               behind p's plane): the visible fraction is then weighted as the form factor
               weights the emitter's points. Equal shares were exact only when visibility does
               not depend on where the point lies (a large emitter seen through an opening got
               a fraction of its light). Unoccluded, the shares sum to the analytic F. */
            ksum = 0.0;
            for (s = 0; s < L; ++s) {
                float u1, u2, *y = ys + 3 * s, dy[3], r2y;
                double kern;
                rad__hammersley(s, L, r1, r2, &u1, &u2);
                rad__triangle_point(tv, tv + 3, tv + 6, u1, u2, y);
                rad__sub(dy, y, p);
                r2y = rad__dot(dy, dy);
                kern = r2y > 0.0f ? (double)rad__dot(dy, n) * -(double)rad__dot(dy, tn) / ((double)r2y * (double)r2y) : 0.0;
                ks[s] = kern > 0.0 ? kern : 0.0;
                ksum += ks[s];
            }
            for (s = 0; s < L; ++s) {
                float share = ksum > 0.0 ? (float)(ks[s] / ksum) : 1.0f / (float)L;
                if (!(share > 0.0f)) continue;
                r = rad__direct_ray(d, task, nrays, p, n, ys + 3 * s, tn, NULL, w, scale * share, slot);
                if (r != RAD_SUCCESS) return r;
            }
        }
    }
    return RAD_SUCCESS;
}

static rad_result rad__direct_row(void *data, uint32_t row, uint32_t task)
{
    rad__direct *d = (rad__direct *)data;
    double *acc = d->acc + (size_t)task * RAD__DIRECT_GROUP * 3u;
    uint32_t nrays = 0, i, first, count;
    rad_result r = RAD_SUCCESS;
    uint32_t seed = rad__hash(d->o.seed + 0x9E3779B9u * (row + 1u));
    if (d->P) {
        /* patch mode: 'samples' points of patch 'row', averaged into slot 0 */
        const rad_patch *pt = &d->P->patches[row];
        float v[9];
        uint32_t s, S = d->o.samples;
        int m, k;
        for (m = 0; m < 3; ++m)
            for (k = 0; k < 3; ++k) v[3 * m + k] = d->P->vertices[3 * (size_t)pt->vertices[m] + (size_t)k];
        acc[0] = acc[1] = acc[2] = 0.0;
        for (s = 0; s < S && r == RAD_SUCCESS; ++s) {
            float x[3];
            rad__lattice_point(v, v + 3, v + 6, rad__lattice_side(S), s, x);
            r = rad__direct_point(d, task, &nrays, x, pt->normal, 0, 1.0f / (float)S, rad__hash(seed + s));
        }
        if (r == RAD_SUCCESS) r = rad__direct_flush(d, task, nrays);
        if (r != RAD_SUCCESS) return r;
        for (k = 0; k < 3; ++k) d->out[3 * (size_t)row + (size_t)k] = (float)acc[k];
        return RAD_SUCCESS;
    }
    first = row * RAD__DIRECT_GROUP;
    count = d->count - first < RAD__DIRECT_GROUP ? d->count - first : RAD__DIRECT_GROUP;
    for (i = 0; i < 3 * count; ++i) acc[i] = 0.0;
    for (i = 0; i < count && r == RAD_SUCCESS; ++i) {
        const float *p = d->points + 3 * (size_t)(first + i), *n = d->normals + 3 * (size_t)(first + i);
        r = rad__direct_point(d, task, &nrays, p, n, i, 1.0f, rad__hash(seed + i));
    }
    if (r == RAD_SUCCESS) r = rad__direct_flush(d, task, nrays);
    if (r != RAD_SUCCESS) return r;
    for (i = 0; i < 3 * count; ++i) d->out[3 * (size_t)first + i] = (float)acc[i];
    return RAD_SUCCESS;
}

static rad_result rad__direct_run(rad__direct *d, const rad__ctx *c, uint32_t rows)
{
    uint32_t T = c->tasks < rows ? c->tasks : rows, t, ne = 0;
    rad_result r;
    if (T == 0) return RAD_SUCCESS;
    d->rays = (rad_ray *)rad__alloc_array(&c->allocator, (size_t)T * RAD__RAY_BATCH, sizeof(rad_ray));
    d->occ = (uint8_t *)rad__alloc_array(&c->allocator, (size_t)T * RAD__RAY_BATCH, 1);
    d->ray_w = (float *)rad__alloc_array(&c->allocator, (size_t)T * RAD__RAY_BATCH, 3 * sizeof(float));
    d->ray_slot = (uint32_t *)rad__alloc_array(&c->allocator, (size_t)T * RAD__RAY_BATCH, sizeof(uint32_t));
    d->acc = (double *)rad__alloc_array(&c->allocator, (size_t)T * RAD__DIRECT_GROUP, 3 * sizeof(double));
    d->emitters = (uint32_t *)rad__alloc_array(&c->allocator, d->S->triangle_count, sizeof(uint32_t));
    if (!d->rays || !d->occ || !d->ray_w || !d->ray_slot || !d->acc || !d->emitters) {
        r = RAD_ERROR_OUT_OF_MEMORY;
    } else {
        for (t = 0; t < d->S->triangle_count; ++t) {
            const float *e = d->S->materials_table[d->S->materials[t]].emission;
            if (e[0] > 0.0f || e[1] > 0.0f || e[2] > 0.0f) d->emitters[ne++] = t;
        }
        d->emitter_count = ne;
        r = rad__for_rows(c, rows, T, rad__direct_row, d);
    }
    rad__free(&c->allocator, d->rays);
    rad__free(&c->allocator, d->occ);
    rad__free(&c->allocator, d->ray_w);
    rad__free(&c->allocator, d->ray_slot);
    rad__free(&c->allocator, d->acc);
    rad__free(&c->allocator, d->emitters);
    return r;
}

static rad_result rad__direct_setup(rad__direct *d, const rad_scene *S, const rad_raycaster *rc, const rad_light *lights,
                                    uint32_t light_count, const rad_direct_options *options, const rad__ctx *c)
{
    uint32_t l;
    memset(d, 0, sizeof(*d));
    if (!S || !rc || !rc->occluded || (light_count > 0 && !lights)) return RAD_ERROR_INVALID_ARGUMENT;
    if (options) d->o = *options; else rad_direct_options_default(&d->o);
    if (d->o.samples == 0) d->o.samples = 16;
    if (d->o.samples > RAD__MAX_SAMPLES) d->o.samples = RAD__MAX_SAMPLES;
    d->o.samples = rad__lattice_side(d->o.samples) * rad__lattice_side(d->o.samples); /* a square */
    if (d->o.light_samples == 0) d->o.light_samples = 16;
    if (d->o.light_samples > RAD__MAX_SAMPLES) d->o.light_samples = RAD__MAX_SAMPLES;
    if (d->o.ray_epsilon == 0.0f) d->o.ray_epsilon = 1e-5f;
    if (!(d->o.ray_epsilon > 0.0f && d->o.ray_epsilon <= RAD__MAX_RAY_EPSILON)) {
        rad__log(c, RAD_LOG_ERROR, "direct light options: ray_epsilon %g must be in (0, %g] (relative to the scene diagonal)",
                 (double)d->o.ray_epsilon, (double)RAD__MAX_RAY_EPSILON);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    for (l = 0; l < light_count; ++l) {
        const rad_light *li = &lights[l];
        if (!rad__finite3(li->color) || !rad__finite3(li->position) || !rad__finite3(li->direction) ||
            !rad__finite(li->min_distance) || !rad__finite(li->inner_angle) || !rad__finite(li->outer_angle)) {
            rad__log(c, RAD_LOG_ERROR, "light %u has a non-finite field", l);
            return RAD_ERROR_NON_FINITE;
        }
        if (li->color[0] < 0.0f || li->color[1] < 0.0f || li->color[2] < 0.0f) {
            rad__log(c, RAD_LOG_ERROR, "light %u has a negative colour", l);
            return RAD_ERROR_NEGATIVE_EMISSION;
        }
        if ((int)li->type < 0 || (int)li->type > RAD_LIGHT_SKY || (li->falloff != RAD_FALLOFF_QUADRATIC && li->falloff != RAD_FALLOFF_LINEAR) ||
            li->min_distance < 0.0f ||
            ((li->type == RAD_LIGHT_DIRECTIONAL || li->type == RAD_LIGHT_SPOT) && rad__dot(li->direction, li->direction) == 0.0f) ||
            (li->type == RAD_LIGHT_SPOT && (li->inner_angle < 0.0f || li->outer_angle < li->inner_angle || li->outer_angle > (float)RAD__PI))) {
            rad__log(c, RAD_LOG_ERROR, "light %u: bad type, falloff, direction or spot angles", l);
            return RAD_ERROR_INVALID_ARGUMENT;
        }
    }
    d->S = S;
    d->rc = rc;
    d->lights = lights;
    d->light_count = light_count;
    d->eps = d->o.ray_epsilon * S->diagonal;
    return RAD_SUCCESS;
}

/* Points first .. first + count - 1 and their normals: finite (else NON_FINITE) and non-zero
   (else INVALID_ARGUMENT), each logged with 'what'; the unit normals into unit (3 per point). */
static rad_result rad__unit_normals(const rad__ctx *c, const char *what, const float *points, const float *normals,
                                    uint32_t first, uint32_t count, float *unit)
{
    uint32_t i;
    for (i = first; i < first + count; ++i)
        if (!rad__finite3(points + 3 * (size_t)i) || !rad__finite3(normals + 3 * (size_t)i)) {
            rad__log(c, RAD_LOG_ERROR, "%s: point %u or its normal is not finite", what, i);
            return RAD_ERROR_NON_FINITE;
        }
    for (i = 0; i < count; ++i) {
        const float *n = normals + 3 * (size_t)(first + i);
        double len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
        int k;
        if (!(len > 0.0) || len - len != 0.0) {
            rad__log(c, RAD_LOG_ERROR, "%s: the normal of point %u has length %g (must be non-zero)", what, first + i, len);
            return RAD_ERROR_INVALID_ARGUMENT;
        }
        for (k = 0; k < 3; ++k) unit[3 * (size_t)i + (size_t)k] = (float)((double)n[k] / len);
    }
    return RAD_SUCCESS;
}

RAD_API rad_result rad_direct_irradiance(const rad_scene *scene, const rad_raycaster *raycaster, const rad_light *lights,
                                         uint32_t light_count, const rad_direct_options *options, const float *points,
                                         const float *normals, uint32_t count, float *out_irradiance, const rad_context *ctx)
{
    rad__ctx c;
    rad__direct d;
    rad_result r;
    float *unit;
    rad__ctx_init(&c, ctx);
    if (!points || !normals || !out_irradiance) return RAD_ERROR_INVALID_ARGUMENT;
    r = rad__direct_setup(&d, scene, raycaster, lights, light_count, options, &c);
    if (r != RAD_SUCCESS) return r;
    /* the cosines need unit normals: the caller's are normalized into a copy */
    unit = (float *)rad__alloc_array(&c.allocator, count ? (size_t)count : 1u, 3 * sizeof(float));
    if (!unit) {
        rad__log(&c, RAD_LOG_ERROR, "direct irradiance: out of memory for %u normals", count);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    r = rad__unit_normals(&c, "direct irradiance", points, normals, 0, count, unit);
    if (r != RAD_SUCCESS) {
        rad__free(&c.allocator, unit);
        return r;
    }
    d.points = points;
    d.normals = unit;
    d.count = count;
    d.out = out_irradiance;
    r = rad__direct_run(&d, &c, (count + RAD__DIRECT_GROUP - 1) / RAD__DIRECT_GROUP);
    rad__free(&c.allocator, unit);
    return r == RAD_SUCCESS ? rad__check_output(&c, "direct irradiance", out_irradiance, 3 * (size_t)count) : r;
}

RAD_API rad_result rad_direct_patches(const rad_patches *patches, const rad_raycaster *raycaster, const rad_light *lights,
                                      uint32_t light_count, const rad_direct_options *options, float *out_irradiance,
                                      const rad_context *ctx)
{
    rad__ctx c;
    rad__direct d;
    rad_result r;
    rad__ctx_init(&c, ctx);
    if (!patches || !out_irradiance) return RAD_ERROR_INVALID_ARGUMENT;
    r = rad__direct_setup(&d, patches->scene, raycaster, lights, light_count, options, &c);
    if (r != RAD_SUCCESS) return r;
    d.P = patches;
    d.out = out_irradiance;
    r = rad__direct_run(&d, &c, patches->count);
    return r == RAD_SUCCESS ? rad__check_output(&c, "direct irradiance", out_irradiance, 3 * (size_t)patches->count) : r;
}

RAD_API rad_result rad_sources(const rad_patches *patches, rad_source_mode mode, const float *direct_irradiance, float *out_E)
{
    uint32_t i;
    int k;
    if (!patches || !out_E) return RAD_ERROR_INVALID_ARGUMENT;
    if (mode == RAD_SOURCE_EMISSION) {
        if (direct_irradiance) return RAD_ERROR_INVALID_ARGUMENT; /* that would count the lights twice */
        for (i = 0; i < patches->count; ++i)
            for (k = 0; k < 3; ++k)
                if (!rad__finite((float)RAD__PI * patches->patches[i].emission[k])) return RAD_ERROR_NON_FINITE; /* pi L overflows */
        for (i = 0; i < patches->count; ++i)
            for (k = 0; k < 3; ++k) out_E[3 * (size_t)i + (size_t)k] = (float)RAD__PI * patches->patches[i].emission[k];
        return RAD_SUCCESS;
    }
    if (mode == RAD_SOURCE_DIRECT) {
        if (!direct_irradiance) return RAD_ERROR_INVALID_ARGUMENT;
        for (i = 0; i < 3 * patches->count; ++i)
            if (!rad__finite(direct_irradiance[i])) return RAD_ERROR_NON_FINITE;
        for (i = 0; i < 3 * patches->count; ++i)
            if (direct_irradiance[i] < 0.0f) return RAD_ERROR_INVALID_ARGUMENT; /* finite but no irradiance */
        for (i = 0; i < 3 * patches->count; ++i) out_E[i] = patches->albedo[i] * direct_irradiance[i];
        return RAD_SUCCESS;
    }
    return RAD_ERROR_INVALID_ARGUMENT;
}

/* ---- final gather ---- */

#define RAD__FG_CHUNK 65536u /* hit points per lookup call */

typedef struct rad__fg {
    const rad_scene *S;
    const rad_raycaster *rc;
    const float *points, *normals; /* the chunk's points (unit normals) */
    uint32_t rays, seed, first;    /* first: index of the chunk's first point */
    float eps;
    rad_ray *ray_buf;              /* per task RAD__RAY_BATCH */
    rad_hit *hits;                 /* the chunk's hits, rays per point */
    float *hit_p, *hit_n;          /* 3 per hit (kept where hits[].triangle is not RAD_NONE) */
} rad__fg;

static rad_result rad__fg_row(void *data, uint32_t row, uint32_t task)
{
    rad__fg *g = (rad__fg *)data;
    const float *p = g->points + 3 * (size_t)row, *n = g->normals + 3 * (size_t)row;
    rad_ray *rays = g->ray_buf + (size_t)task * RAD__RAY_BATCH;
    float t1[3], t2[3];
    uint32_t seed = rad__hash(g->seed ^ rad__hash(g->first + row + 0x68E31DA4u)), k0, k;
    int c;
    rad__tangent_frame(n, t1, t2);
    for (k0 = 0; k0 < g->rays; k0 += RAD__RAY_BATCH) {
        uint32_t m = g->rays - k0 < RAD__RAY_BATCH ? g->rays - k0 : RAD__RAY_BATCH;
        rad_hit *h = g->hits + (size_t)row * g->rays + k0;
        for (k = 0; k < m; ++k) {
            rad__cosine_dir(n, t1, t2, k0 + k, g->rays, seed, rays[k].dir);
            for (c = 0; c < 3; ++c) rays[k].origin[c] = p[c] + n[c] * g->eps;
            rays[k].tmin = 0.0f;
            rays[k].tmax = FLT_MAX;
        }
        if (g->rc->intersect(g->rc->user, rays, m, h) != RAD_SUCCESS) return RAD_ERROR_RAYCAST_FAILED;
        for (k = 0; k < m; ++k) {
            size_t at = 3 * ((size_t)row * g->rays + k0 + k);
            uint32_t t = h[k].triangle;
            const float *v, *nt;
            if (t == RAD_NONE || t >= g->S->triangle_count) { /* a miss: packed out below */
                h[k].triangle = RAD_NONE;
                continue;
            }
            v = g->S->positions + 9 * (size_t)t;
            nt = g->S->normals + 3 * (size_t)t;
            for (c = 0; c < 3; ++c) {
                g->hit_p[at + (size_t)c] = v[c] + h[k].b1 * (v[3 + c] - v[c]) + h[k].b2 * (v[6 + c] - v[c]);
                g->hit_n[at + (size_t)c] = nt[c];
            }
            if (!(rad__dot(nt, rays[k].dir) < 0.0f)) h[k].triangle = RAD_NONE; /* a back face: one-sided, black */
        }
    }
    return RAD_SUCCESS;
}

RAD_API void rad_final_gather_options_default(rad_final_gather_options *o)
{
    if (!o) return;
    memset(o, 0, sizeof(*o));
    o->rays = 64;
    o->light_samples = 4;
    o->ray_epsilon = 1e-5f;
}

RAD_API rad_result rad_final_gather(const rad_scene *scene, const rad_raycaster *raycaster, const rad_light *lights,
                                    uint32_t light_count, const rad_final_gather_options *options,
                                    rad_gather_lookup_fn lookup, void *lookup_user, const float *points,
                                    const float *normals, uint32_t count, float *out, const rad_context *ctx)
{
    rad__ctx c;
    rad__fg g;
    rad_final_gather_options o;
    rad_direct_options dopt;
    rad_context quiet;
    float *unit = NULL, *D = NULL, *H = NULL, *albedo = NULL;
    uint32_t per, first, i, T, *owner = NULL;
    rad_result r = RAD_SUCCESS;
    rad__ctx_init(&c, ctx);
    if (!scene || !raycaster || !raycaster->intersect || !raycaster->occluded || !points || !normals || !out) {
        rad__log(&c, RAD_LOG_ERROR, "final gather: NULL scene, raycaster (with intersect and occluded), points, normals or output");
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    if (options) o = *options; else rad_final_gather_options_default(&o);
    if (o.rays == 0) o.rays = 64;
    if (o.light_samples == 0) o.light_samples = 4;
    if (o.ray_epsilon == 0.0f) o.ray_epsilon = 1e-5f;
    if (o.rays > 4096 || !(o.ray_epsilon > 0.0f && o.ray_epsilon <= RAD__MAX_RAY_EPSILON)) {
        rad__log(&c, RAD_LOG_ERROR, "final gather: rays %u (at most 4096) or ray_epsilon %g (in (0, %g]) out of range", o.rays,
                 (double)o.ray_epsilon, (double)RAD__MAX_RAY_EPSILON);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    if (count == 0) return RAD_SUCCESS;
    memset(&g, 0, sizeof(g));
    g.S = scene;
    g.rc = raycaster;
    g.rays = o.rays;
    g.seed = o.seed;
    g.eps = o.ray_epsilon * scene->diagonal;
    rad_direct_options_default(&dopt);
    dopt.light_samples = o.light_samples;
    dopt.ray_epsilon = o.ray_epsilon;
    dopt.seed = rad__hash(o.seed + 0x5BD1E995u);
    /* the direct-light calls inside run without progress: this call's progress counts points */
    if (ctx) quiet = *ctx;
    else memset(&quiet, 0, sizeof(quiet));
    quiet.progress = NULL;
    per = RAD__FG_CHUNK / o.rays;
    if (per == 0) per = 1;
    T = c.tasks < per ? c.tasks : per;
    unit = (float *)rad__alloc_array(&c.allocator, per, 3 * sizeof(float));
    g.ray_buf = (rad_ray *)rad__alloc_array(&c.allocator, (size_t)T * RAD__RAY_BATCH, sizeof(rad_ray));
    g.hits = (rad_hit *)rad__alloc_array(&c.allocator, (size_t)per * o.rays, sizeof(rad_hit));
    g.hit_p = (float *)rad__alloc_array(&c.allocator, (size_t)per * o.rays, 3 * sizeof(float));
    g.hit_n = (float *)rad__alloc_array(&c.allocator, (size_t)per * o.rays, 3 * sizeof(float));
    D = (float *)rad__alloc_array(&c.allocator, (size_t)per * o.rays, 3 * sizeof(float));
    H = (float *)rad__alloc_array(&c.allocator, (size_t)per * o.rays, 3 * sizeof(float));
    albedo = (float *)rad__alloc_array(&c.allocator, (size_t)per * o.rays, 3 * sizeof(float));
    owner = (uint32_t *)rad__alloc_array(&c.allocator, (size_t)per * o.rays, sizeof(uint32_t)); /* each hit's point */
    if (!unit || !g.ray_buf || !g.hits || !g.hit_p || !g.hit_n || !D || !H || !albedo || !owner) {
        rad__log(&c, RAD_LOG_ERROR, "final gather: out of memory for %u points of %u rays", per, o.rays);
        r = RAD_ERROR_OUT_OF_MEMORY;
    }
    for (first = 0; first < count && r == RAD_SUCCESS; first += per) {
        uint32_t m = count - first < per ? count - first : per, nh = 0, k;
        size_t hits = (size_t)m * o.rays, j;
        r = rad__unit_normals(&c, "final gather", points, normals, first, m, unit);
        if (r != RAD_SUCCESS) break;
        g.points = points + 3 * (size_t)first;
        g.normals = unit;
        g.first = first;
        r = rad__for_rows(&c, m, T, rad__fg_row, &g);
        if (r != RAD_SUCCESS) break;
        /* the front-facing hits, packed to the front of the hit arrays */
        for (j = 0; j < hits; ++j) {
            if (g.hits[j].triangle == RAD_NONE) continue;
            if (j != nh) {
                g.hits[nh] = g.hits[j];
                memcpy(g.hit_p + 3 * (size_t)nh, g.hit_p + 3 * j, 3 * sizeof(float));
                memcpy(g.hit_n + 3 * (size_t)nh, g.hit_n + 3 * j, 3 * sizeof(float));
            }
            owner[nh++] = (uint32_t)(j / o.rays);
        }
        if (nh > 0) {
            r = rad_direct_irradiance(scene, raycaster, lights, light_count, &dopt, g.hit_p, g.hit_n, nh, D, &quiet);
            if (r != RAD_SUCCESS) {
                rad__log(&c, RAD_LOG_ERROR, "final gather: direct light at the hits failed: %s", rad_result_string(r));
                break;
            }
            if (lookup) {
                r = lookup(lookup_user, g.hits, g.hit_p, g.hit_n, nh, H);
                if (r != RAD_SUCCESS) {
                    rad__log(&c, RAD_LOG_ERROR, "final gather: the lookup callback returned %s", rad_result_string(r));
                    break;
                }
            } else {
                memset(H, 0, sizeof(float) * 3 * (size_t)nh);
            }
            for (j = 0; j < nh; ++j) rad_scene_albedo(scene, g.hits[j].triangle, g.hits[j].b1, g.hits[j].b2, albedo + 3 * j);
        }
        for (i = 0; i < m; ++i) out[3 * (size_t)(first + i)] = out[3 * (size_t)(first + i) + 1] = out[3 * (size_t)(first + i) + 2] = 0.0f;
        for (j = 0; j < nh; ++j) {
            uint32_t pt = first + owner[j];
            for (k = 0; k < 3; ++k)
                out[3 * (size_t)pt + k] += albedo[3 * j + k] * (D[3 * j + k] + H[3 * j + k]) / (float)o.rays;
        }
        if (c.progress && c.progress(c.progress_user, (float)((double)(first + m) / (double)count))) {
            rad__log(&c, RAD_LOG_INFO, "final gather: cancelled by the progress callback after %u of %u points", first + m, count);
            r = RAD_ERROR_CANCELLED;
        }
    }
    rad__free(&c.allocator, unit);
    rad__free(&c.allocator, g.ray_buf);
    rad__free(&c.allocator, g.hits);
    rad__free(&c.allocator, g.hit_p);
    rad__free(&c.allocator, g.hit_n);
    rad__free(&c.allocator, D);
    rad__free(&c.allocator, H);
    rad__free(&c.allocator, albedo);
    rad__free(&c.allocator, owner);
    return r == RAD_SUCCESS ? rad__check_output(&c, "final gather", out, 3 * (size_t)count) : r;
}

/* ======================================================================================== */
/* >>shading: lighting models and BRDFs                                                     */
/* ======================================================================================== */

/* Everything here is float arithmetic written in the same order as glsl/lighting.glsl, so
   that the C and GLSL results agree to a few ulps (the tests compare them). */

#define RAD__INV_PI 0.318309886183790671537767526745f

RAD_API void rad_lambert_params_default(rad_lambert_params *p)
{
    if (!p) return;
    p->albedo[0] = p->albedo[1] = p->albedo[2] = 0.5f;
}

RAD_API void rad_half_lambert_params_default(rad_half_lambert_params *p)
{
    if (!p) return;
    p->albedo[0] = p->albedo[1] = p->albedo[2] = 0.5f;
    p->wrap = 1.0f;
    p->exponent = 2.0f;
}

RAD_API void rad_banded_params_default(rad_banded_params *p)
{
    if (!p) return;
    p->albedo[0] = p->albedo[1] = p->albedo[2] = 0.5f;
    p->bands = 4;
}

RAD_API void rad_phong_params_default(rad_phong_params *p)
{
    if (!p) return;
    p->diffuse[0] = p->diffuse[1] = p->diffuse[2] = 0.5f;
    p->specular[0] = p->specular[1] = p->specular[2] = 0.3f;
    p->shininess = 32.0f;
}

RAD_API void rad_minnaert_params_default(rad_minnaert_params *p)
{
    if (!p) return;
    p->albedo[0] = p->albedo[1] = p->albedo[2] = 0.5f;
    p->k = 0.8f;
}

RAD_API void rad_oren_nayar_params_default(rad_oren_nayar_params *p)
{
    if (!p) return;
    p->albedo[0] = p->albedo[1] = p->albedo[2] = 0.5f;
    p->sigma = 0.5f;
}

RAD_API void rad_microfacet_params_default(rad_microfacet_params *p)
{
    int k;
    if (!p) return;
    p->ndf = RAD_NDF_GGX;
    p->masking = RAD_MASKING_HEIGHT_CORRELATED;
    p->diffuse = RAD_DIFFUSE_LAMBERT;
    p->alpha_x = p->alpha_y = 0.3f;
    for (k = 0; k < 3; ++k) {
        p->f0[k] = 0.04f;
        p->f90[k] = 1.0f;
        p->albedo[k] = 0.5f;
    }
    p->fresnel_exponent = 5.0f;
}

RAD_API void rad_shading_default(rad_shading *s, rad_shading_model model)
{
    if (!s) return;
    memset(s, 0, sizeof(*s));
    s->model = model;
    rad_lambert_params_default(&s->lambert);
    rad_half_lambert_params_default(&s->half_lambert);
    rad_banded_params_default(&s->banded);
    rad_phong_params_default(&s->phong);
    rad_minnaert_params_default(&s->minnaert);
    rad_oren_nayar_params_default(&s->oren_nayar);
    rad_microfacet_params_default(&s->microfacet);
}

static const char *const rad__shading_names[RAD_SHADING_MODEL_COUNT] = {
    "lambert", "half-lambert", "banded", "phong", "blinn-phong", "minnaert", "oren-nayar", "microfacet"
};

RAD_API const char *rad_shading_model_name(rad_shading_model model)
{
    if ((int)model < 0 || (int)model >= (int)RAD_SHADING_MODEL_COUNT) return NULL;
    return rad__shading_names[model];
}

RAD_API rad_result rad_shading_model_from_name(const char *name, rad_shading_model *out_model)
{
    int i;
    if (!name || !out_model) return RAD_ERROR_INVALID_ARGUMENT;
    for (i = 0; i < (int)RAD_SHADING_MODEL_COUNT; ++i)
        if (strcmp(name, rad__shading_names[i]) == 0) {
            *out_model = (rad_shading_model)i;
            return RAD_SUCCESS;
        }
    return RAD_ERROR_INVALID_ARGUMENT;
}

/* value in [lo, hi]: 0 ok, else the error (NON_FINITE or INVALID_ARGUMENT), logged */
static rad_result rad__shading_range(const rad__ctx *c, const char *what, const float *x, int count, float lo, float hi)
{
    int k;
    for (k = 0; k < count; ++k) {
        if (!rad__finite(x[k])) {
            rad__log(c, RAD_LOG_ERROR, "shading: %s[%d] is not finite", what, k);
            return RAD_ERROR_NON_FINITE;
        }
        if (x[k] < lo || x[k] > hi) {
            rad__log(c, RAD_LOG_ERROR, "shading: %s[%d] = %g is outside [%g, %g]", what, k, (double)x[k], (double)lo,
                     (double)hi);
            return RAD_ERROR_INVALID_ARGUMENT;
        }
    }
    return RAD_SUCCESS;
}

static rad_result rad__shading_validate(const rad_shading *s, const rad__ctx *c)
{
    rad_result r = RAD_SUCCESS;
    if (!s) return RAD_ERROR_INVALID_ARGUMENT;
    switch (s->model) {
    case RAD_SHADING_LAMBERT: return rad__shading_range(c, "lambert.albedo", s->lambert.albedo, 3, 0.0f, 1.0f);
    case RAD_SHADING_HALF_LAMBERT:
        if ((r = rad__shading_range(c, "half_lambert.albedo", s->half_lambert.albedo, 3, 0.0f, 1.0f)) != RAD_SUCCESS) return r;
        if ((r = rad__shading_range(c, "half_lambert.wrap", &s->half_lambert.wrap, 1, 0.0f, 1.0f)) != RAD_SUCCESS) return r;
        return rad__shading_range(c, "half_lambert.exponent", &s->half_lambert.exponent, 1, 1.0f, 8.0f);
    case RAD_SHADING_BANDED:
        if (s->banded.bands < 1 || s->banded.bands > 256) {
            rad__log(c, RAD_LOG_ERROR, "shading: banded.bands = %u is outside [1, 256]", s->banded.bands);
            return RAD_ERROR_INVALID_ARGUMENT;
        }
        return rad__shading_range(c, "banded.albedo", s->banded.albedo, 3, 0.0f, 1.0f);
    case RAD_SHADING_PHONG:
    case RAD_SHADING_BLINN_PHONG:
        if ((r = rad__shading_range(c, "phong.diffuse", s->phong.diffuse, 3, 0.0f, 1.0f)) != RAD_SUCCESS) return r;
        if ((r = rad__shading_range(c, "phong.specular", s->phong.specular, 3, 0.0f, 1.0f)) != RAD_SUCCESS) return r;
        return rad__shading_range(c, "phong.shininess", &s->phong.shininess, 1, 1.0f, 10000.0f);
    case RAD_SHADING_MINNAERT:
        if ((r = rad__shading_range(c, "minnaert.albedo", s->minnaert.albedo, 3, 0.0f, 1.0f)) != RAD_SUCCESS) return r;
        return rad__shading_range(c, "minnaert.k", &s->minnaert.k, 1, 0.0f, 4.0f);
    case RAD_SHADING_OREN_NAYAR:
        if ((r = rad__shading_range(c, "oren_nayar.albedo", s->oren_nayar.albedo, 3, 0.0f, 1.0f)) != RAD_SUCCESS) return r;
        return rad__shading_range(c, "oren_nayar.sigma", &s->oren_nayar.sigma, 1, 0.0f, 1.5f);
    case RAD_SHADING_MICROFACET: {
        const rad_microfacet_params *m = &s->microfacet;
        if ((int)m->ndf < 0 || (int)m->ndf > (int)RAD_NDF_GGX || (int)m->masking < 0 ||
            (int)m->masking > (int)RAD_MASKING_HEIGHT_CORRELATED || (int)m->diffuse < 0 ||
            (int)m->diffuse > (int)RAD_DIFFUSE_SHIRLEY) {
            rad__log(c, RAD_LOG_ERROR, "shading: microfacet ndf %d, masking %d or diffuse %d is not a valid value",
                     (int)m->ndf, (int)m->masking, (int)m->diffuse);
            return RAD_ERROR_INVALID_ARGUMENT;
        }
        if ((r = rad__shading_range(c, "microfacet.alpha_x", &m->alpha_x, 1, 1e-3f, 1.0f)) != RAD_SUCCESS) return r;
        if ((r = rad__shading_range(c, "microfacet.alpha_y", &m->alpha_y, 1, 1e-3f, 1.0f)) != RAD_SUCCESS) return r;
        if ((r = rad__shading_range(c, "microfacet.f0", m->f0, 3, 0.0f, 1.0f)) != RAD_SUCCESS) return r;
        if ((r = rad__shading_range(c, "microfacet.f90", m->f90, 3, 0.0f, 1.0f)) != RAD_SUCCESS) return r;
        if ((r = rad__shading_range(c, "microfacet.fresnel_exponent", &m->fresnel_exponent, 1, 1.0f, 10.0f)) != RAD_SUCCESS)
            return r;
        return rad__shading_range(c, "microfacet.albedo", m->albedo, 3, 0.0f, 1.0f);
    }
    case RAD_SHADING_MODEL_COUNT: break;
    }
    rad__log(c, RAD_LOG_ERROR, "shading: unknown model %d", (int)s->model);
    return RAD_ERROR_INVALID_ARGUMENT;
}

RAD_API rad_result rad_shading_validate(const rad_shading *s, const rad_context *ctx)
{
    rad__ctx c;
    rad__ctx_init(&c, ctx);
    return rad__shading_validate(s, &c);
}

static void rad__shading_pack(const rad_shading *s, rad_shading_gpu *g)
{
    int k;
    const float *alb = s->lambert.albedo;
    memset(g, 0, sizeof(*g));
    g->mode[0] = (int32_t)s->model;
    switch (s->model) {
    case RAD_SHADING_HALF_LAMBERT:
        alb = s->half_lambert.albedo;
        g->p[2] = s->half_lambert.wrap;
        g->p[3] = s->half_lambert.exponent;
        break;
    case RAD_SHADING_BANDED:
        alb = s->banded.albedo;
        g->p[3] = (float)s->banded.bands;
        break;
    case RAD_SHADING_PHONG:
    case RAD_SHADING_BLINN_PHONG:
        alb = s->phong.diffuse;
        for (k = 0; k < 3; ++k) g->specular[k] = s->phong.specular[k];
        g->p[2] = s->phong.shininess;
        break;
    case RAD_SHADING_MINNAERT: alb = s->minnaert.albedo; g->p[2] = s->minnaert.k; break;
    case RAD_SHADING_OREN_NAYAR: alb = s->oren_nayar.albedo; g->p[2] = s->oren_nayar.sigma; break;
    case RAD_SHADING_MICROFACET:
        alb = s->microfacet.albedo;
        for (k = 0; k < 3; ++k) {
            g->f0[k] = s->microfacet.f0[k];
            g->f90[k] = s->microfacet.f90[k];
        }
        g->p[0] = s->microfacet.alpha_x;
        g->p[1] = s->microfacet.alpha_y;
        g->p[3] = s->microfacet.fresnel_exponent;
        g->mode[1] = (int32_t)s->microfacet.ndf;
        g->mode[2] = (int32_t)s->microfacet.masking;
        g->mode[3] = (int32_t)s->microfacet.diffuse;
        break;
    default: break;
    }
    for (k = 0; k < 3; ++k) g->albedo[k] = alb[k];
}

RAD_API rad_result rad_shading_pack(const rad_shading *s, rad_shading_gpu *out, const rad_context *ctx)
{
    rad__ctx c;
    rad_result r;
    rad__ctx_init(&c, ctx);
    if (!out) return RAD_ERROR_INVALID_ARGUMENT;
    if ((r = rad__shading_validate(s, &c)) != RAD_SUCCESS) return r;
    rad__shading_pack(s, out);
    return RAD_SUCCESS;
}

/* ---- terms of the microfacet model ---- */

RAD_API float rad_ndf_beckmann(float nm, float alpha)
{
    float a2 = alpha * alpha, c2 = nm * nm;
    if (!(nm > 0.0f)) return 0.0f;
    return expf((c2 - 1.0f) / (a2 * c2)) / ((float)RAD__PI * a2 * c2 * c2);
}

RAD_API float rad_ndf_beckmann_aniso(float nm, float tm, float bm, float alpha_x, float alpha_y)
{
    float c2 = nm * nm, e;
    if (!(nm > 0.0f)) return 0.0f;
    e = (tm * tm / (alpha_x * alpha_x) + bm * bm / (alpha_y * alpha_y)) / c2;
    return expf(-e) / ((float)RAD__PI * alpha_x * alpha_y * c2 * c2);
}

RAD_API float rad_ndf_ggx(float nm, float alpha)
{
    float a2 = alpha * alpha, d;
    if (!(nm > 0.0f)) return 0.0f;
    d = 1.0f + nm * nm * (a2 - 1.0f);
    return a2 / ((float)RAD__PI * d * d);
}

RAD_API float rad_ndf_ggx_aniso(float nm, float tm, float bm, float alpha_x, float alpha_y)
{
    float d;
    if (!(nm > 0.0f)) return 0.0f;
    d = tm * tm / (alpha_x * alpha_x) + bm * bm / (alpha_y * alpha_y) + nm * nm;
    return 1.0f / ((float)RAD__PI * alpha_x * alpha_y * d * d);
}

RAD_API float rad_smith_a(float ns, float ts, float bs, float alpha_x, float alpha_y)
{
    float d2 = alpha_x * alpha_x * ts * ts + alpha_y * alpha_y * bs * bs;
    if (!(d2 > 0.0f)) return HUGE_VALF;
    return ns / sqrtf(d2);
}

RAD_API float rad_lambda_ggx(float a)
{
    if (!(a < HUGE_VALF)) return 0.0f;
    return 0.5f * (-1.0f + sqrtf(1.0f + 1.0f / (a * a)));
}

RAD_API float rad_lambda_beckmann(float a)
{
    if (!(a < 1.6f)) return 0.0f;
    return (1.0f - 1.259f * a + 0.396f * a * a) / (3.535f * a + 2.181f * a * a);
}

RAD_API float rad_lambda_beckmann_exact(float a)
{
    double x = (double)a;
    if (!(a < HUGE_VALF)) return 0.0f;
    return (float)(0.5 * (erf(x) - 1.0) + exp(-x * x) / (2.0 * x * sqrt(RAD__PI)));
}

RAD_API float rad_smith_g1(float ms, float lambda_s) { return ms > 0.0f ? 1.0f / (1.0f + lambda_s) : 0.0f; }

RAD_API float rad_smith_g2_separable(float mv, float ml, float lambda_v, float lambda_l)
{
    return (mv > 0.0f && ml > 0.0f) ? 1.0f / ((1.0f + lambda_v) * (1.0f + lambda_l)) : 0.0f;
}

RAD_API float rad_smith_g2_height_correlated(float mv, float ml, float lambda_v, float lambda_l)
{
    return (mv > 0.0f && ml > 0.0f) ? 1.0f / (1.0f + lambda_v + lambda_l) : 0.0f;
}

RAD_API float rad_fresnel_schlick(float f0, float c)
{
    float x = 1.0f - (c > 0.0f ? c : 0.0f), x2 = x * x;
    return f0 + (1.0f - f0) * (x2 * x2 * x);
}

RAD_API float rad_fresnel_schlick_f90(float f0, float f90, float exponent, float c)
{
    return f0 + (f90 - f0) * powf(1.0f - (c > 0.0f ? c : 0.0f), exponent);
}

RAD_API float rad_diffuse_lambert(float albedo, float F) { return (1.0f - F) * albedo * RAD__INV_PI; }

RAD_API float rad_diffuse_shirley(float albedo, float f0, float nl, float nv)
{
    float a = 1.0f - (nl > 0.0f ? nl : 0.0f), b = 1.0f - (nv > 0.0f ? nv : 0.0f);
    float a5 = a * a * a * a * a, b5 = b * b * b * b * b;
    return (1.0f - f0) * (21.0f / 20.0f) * albedo * RAD__INV_PI * (1.0f - a5) * (1.0f - b5);
}

/* ---- the evaluator, the mirror of glsl/lighting.glsl's shade() ---- */

static float rad__sdot(const float *a, const float *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Lambda from n.s, t.s, b.s without forming a (no division by zero at s = n) */
static float rad__shading_lambda(int ndf, int iso, float ns, float ts, float bs, float ax, float ay)
{
    float d2 = iso ? ax * ax * (1.0f - ns * ns) : ax * ax * ts * ts + ay * ay * bs * bs;
    float a;
    if (!(d2 > 0.0f)) return 0.0f;
    if (ndf == (int)RAD_NDF_GGX) return 0.5f * (-1.0f + sqrtf(1.0f + d2 / (ns * ns)));
    a = ns / sqrtf(d2);
    return rad_lambda_beckmann(a);
}

/* f and R of a packed material for unit l, v, n and orthonormal t, b (any when isotropic) */
static void rad__shade(const rad_shading_gpu *g, const float *l, const float *v, const float *n, const float *t,
                       const float *b, float *out_f, float *out_r)
{
    float nl = rad__sdot(n, l), nv = rad__sdot(n, v), f[3] = {0.0f, 0.0f, 0.0f}, rr[3] = {0.0f, 0.0f, 0.0f};
    int k, model = g->mode[0];
    if (nv > 0.0f) {
        if (model == (int)RAD_SHADING_HALF_LAMBERT) {
            float x = (nl + g->p[2]) / (1.0f + g->p[2]);
            float q = powf(x > 0.0f ? x : 0.0f, g->p[3]);
            for (k = 0; k < 3; ++k) rr[k] = g->albedo[k] * RAD__INV_PI * q;
        } else if (nl > 0.0f) {
            if (model == (int)RAD_SHADING_LAMBERT) {
                for (k = 0; k < 3; ++k) f[k] = g->albedo[k] * RAD__INV_PI;
            } else if (model == (int)RAD_SHADING_BANDED) {
                float q = ceilf(g->p[3] * nl) / g->p[3] / nl;
                for (k = 0; k < 3; ++k) f[k] = g->albedo[k] * RAD__INV_PI * q;
            } else if (model == (int)RAD_SHADING_PHONG) {
                float r[3], rv, s = g->p[2], q;
                for (k = 0; k < 3; ++k) r[k] = 2.0f * nl * n[k] - l[k];
                rv = rad__sdot(r, v);
                q = (s + 2.0f) * (0.5f * RAD__INV_PI) * powf(rv > 0.0f ? rv : 0.0f, s);
                for (k = 0; k < 3; ++k) f[k] = g->albedo[k] * RAD__INV_PI + g->specular[k] * q;
            } else if (model == (int)RAD_SHADING_BLINN_PHONG) {
                float h[3], len, nh = 0.0f, s = g->p[2], q;
                for (k = 0; k < 3; ++k) h[k] = l[k] + v[k];
                len = sqrtf(rad__sdot(h, h));
                if (len > 0.0f) nh = rad__sdot(n, h) / len;
                q = (s + 2.0f) * (s + 4.0f) * (0.125f * RAD__INV_PI) / (exp2f(-0.5f * s) + s) * powf(nh > 0.0f ? nh : 0.0f, s);
                for (k = 0; k < 3; ++k) f[k] = g->albedo[k] * RAD__INV_PI + g->specular[k] * q;
            } else if (model == (int)RAD_SHADING_MINNAERT) {
                float kk = g->p[2], c = nl * nv;
                float q = (kk + 1.0f) * (0.5f * RAD__INV_PI) * powf(c > 1e-6f ? c : 1e-6f, kk - 1.0f);
                for (k = 0; k < 3; ++k) f[k] = g->albedo[k] * q;
            } else if (model == (int)RAD_SHADING_OREN_NAYAR) {
                float s2 = g->p[2] * g->p[2], A = 1.0f - 0.5f * s2 / (s2 + 0.33f), B = 0.45f * s2 / (s2 + 0.09f);
                float s = rad__sdot(l, v) - nl * nv, q = s > 0.0f ? s / (nl > nv ? nl : nv) : 0.0f;
                for (k = 0; k < 3; ++k) f[k] = g->albedo[k] * RAD__INV_PI * (A + B * q);
            } else if (model == (int)RAD_SHADING_MICROFACET) {
                float h[3], len, nh, th, bh, lh, vh, ax = g->p[0], ay = g->p[1], D, G, lv, ll, sp;
                int iso = ax == ay, ndf = g->mode[1];
                for (k = 0; k < 3; ++k) h[k] = l[k] + v[k];
                len = sqrtf(rad__sdot(h, h));
                if (len > 0.0f) {
                    for (k = 0; k < 3; ++k) h[k] /= len;
                    nh = rad__sdot(n, h); lh = rad__sdot(l, h); vh = rad__sdot(v, h);
                    if (iso) {
                        th = bh = 0.0f;
                        D = ndf == (int)RAD_NDF_GGX ? rad_ndf_ggx(nh, ax) : rad_ndf_beckmann(nh, ax);
                    } else {
                        th = rad__sdot(t, h); bh = rad__sdot(b, h);
                        D = ndf == (int)RAD_NDF_GGX ? rad_ndf_ggx_aniso(nh, th, bh, ax, ay)
                                                    : rad_ndf_beckmann_aniso(nh, th, bh, ax, ay);
                    }
                    lv = rad__shading_lambda(ndf, iso, nv, iso ? 0.0f : rad__sdot(t, v), iso ? 0.0f : rad__sdot(b, v), ax, ay);
                    ll = rad__shading_lambda(ndf, iso, nl, iso ? 0.0f : rad__sdot(t, l), iso ? 0.0f : rad__sdot(b, l), ax, ay);
                    G = g->mode[2] == (int)RAD_MASKING_SEPARABLE ? rad_smith_g2_separable(vh, lh, lv, ll)
                                                                : rad_smith_g2_height_correlated(vh, lh, lv, ll);
                    sp = G * D / (4.0f * nl * nv);
                    for (k = 0; k < 3; ++k) f[k] = rad_fresnel_schlick_f90(g->f0[k], g->f90[k], g->p[3], lh) * sp;
                }
                for (k = 0; k < 3; ++k) {
                    if (g->mode[3] == (int)RAD_DIFFUSE_LAMBERT)
                        f[k] += rad_diffuse_lambert(g->albedo[k], rad_fresnel_schlick_f90(g->f0[k], g->f90[k], g->p[3], nl));
                    else if (g->mode[3] == (int)RAD_DIFFUSE_SHIRLEY)
                        f[k] += rad_diffuse_shirley(g->albedo[k], g->f0[k], nl, nv);
                }
            }
            for (k = 0; k < 3; ++k) rr[k] = f[k] * nl;
        }
    }
    for (k = 0; k < 3; ++k) {
        if (out_f) out_f[k] = f[k];
        if (out_r) out_r[k] = rr[k];
    }
}

/* normalizes src into dst; 0 on a zero or non-finite vector (result set) */
static rad_result rad__shading_unit(const rad__ctx *c, const char *what, const float *src, float *dst)
{
    double len;
    int k;
    if (!rad__finite3(src)) {
        rad__log(c, RAD_LOG_ERROR, "shading: vector %s is not finite", what);
        return RAD_ERROR_NON_FINITE;
    }
    len = sqrt((double)src[0] * src[0] + (double)src[1] * src[1] + (double)src[2] * src[2]);
    if (!(len > 1e-30)) {
        rad__log(c, RAD_LOG_ERROR, "shading: vector %s has zero length", what);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    for (k = 0; k < 3; ++k) dst[k] = (float)(src[k] / len);
    return RAD_SUCCESS;
}

static rad_result rad__shading_entry(const rad_shading *s, const float *l, const float *v, const float *n,
                                     const float *t, const float *b, float *out, int want_f, const rad_context *ctx)
{
    rad__ctx c;
    rad_result r;
    rad_shading_gpu g;
    float L[3], V[3], N[3], T[3] = {0.0f, 0.0f, 0.0f}, B[3] = {0.0f, 0.0f, 0.0f};
    int k;
    rad__ctx_init(&c, ctx);
    if (!s || !l || !v || !n || !out) {
        rad__log(&c, RAD_LOG_ERROR, "shading: NULL material, vector or output");
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    if ((r = rad__shading_validate(s, &c)) != RAD_SUCCESS) return r;
    if (want_f && s->model == RAD_SHADING_HALF_LAMBERT) {
        rad__log(&c, RAD_LOG_ERROR, "shading: half-Lambert lights n.l < 0 and has no BRDF; use rad_shading_eval");
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    if ((r = rad__shading_unit(&c, "l", l, L)) != RAD_SUCCESS) return r;
    if ((r = rad__shading_unit(&c, "v", v, V)) != RAD_SUCCESS) return r;
    if ((r = rad__shading_unit(&c, "n", n, N)) != RAD_SUCCESS) return r;
    if (s->model == RAD_SHADING_MICROFACET && s->microfacet.alpha_x != s->microfacet.alpha_y) {
        float tt[3], d;
        if (!t) {
            rad__log(&c, RAD_LOG_ERROR, "shading: an anisotropic microfacet model needs the tangent t");
            return RAD_ERROR_INVALID_ARGUMENT;
        }
        if (!rad__finite3(t) || (b && !rad__finite3(b))) {
            rad__log(&c, RAD_LOG_ERROR, "shading: vector t or b is not finite");
            return RAD_ERROR_NON_FINITE;
        }
        d = rad__sdot(t, N);
        for (k = 0; k < 3; ++k) tt[k] = t[k] - d * N[k];
        if ((r = rad__shading_unit(&c, "t (minus its n component)", tt, T)) != RAD_SUCCESS) return r;
        if (b) {
            float bb[3], e = rad__sdot(b, N), f = rad__sdot(b, T);
            for (k = 0; k < 3; ++k) bb[k] = b[k] - e * N[k] - f * T[k];
            if ((r = rad__shading_unit(&c, "b (minus its n and t components)", bb, B)) != RAD_SUCCESS) return r;
        } else {
            B[0] = N[1] * T[2] - N[2] * T[1];
            B[1] = N[2] * T[0] - N[0] * T[2];
            B[2] = N[0] * T[1] - N[1] * T[0];
        }
    }
    rad__shading_pack(s, &g);
    if (want_f) rad__shade(&g, L, V, N, T, B, out, NULL);
    else rad__shade(&g, L, V, N, T, B, NULL, out);
    return RAD_SUCCESS;
}

RAD_API rad_result rad_shading_brdf(const rad_shading *s, const float l[3], const float v[3], const float n[3],
                                    const float t[3], const float b[3], float out_rgb[3], const rad_context *ctx)
{
    return rad__shading_entry(s, l, v, n, t, b, out_rgb, 1, ctx);
}

RAD_API rad_result rad_shading_eval(const rad_shading *s, const float l[3], const float v[3], const float n[3],
                                    const float t[3], const float b[3], float out_rgb[3], const rad_context *ctx)
{
    return rad__shading_entry(s, l, v, n, t, b, out_rgb, 0, ctx);
}

RAD_API void rad_shade(const rad_shading_gpu *g, const float l[3], const float v[3], const float n[3], const float t[3],
                       const float b[3], float out_f[3], float out_r[3])
{
    static const float zero[3] = { 0.0f, 0.0f, 0.0f };
    rad__shade(g, l, v, n, t ? t : zero, b ? b : zero, out_f, out_r);
}

typedef char rad__check_shading_gpu_size[(sizeof(rad_shading_gpu) == 96) ? 1 : -1];

/* ======================================================================================== */
/* >>container: baked data                                                                  */
/* ======================================================================================== */

typedef char rad__check_patch_size[(sizeof(rad_patch) == 68) ? 1 : -1];
typedef char rad__check_signature_size[(sizeof(rad_bake_signature) == 32) ? 1 : -1];

#define RAD__HEADER_BYTES 64u
#define RAD__ENTRY_BYTES 64u
#define RAD__ALIGN 64u
#define RAD__FLAG_BIG_ENDIAN 1u

struct rad_container {
    rad_section *sections;
    uint32_t count;
    rad_allocator allocator;
};

static uint32_t rad__crc32(const void *data, size_t size)
{
    static const uint32_t nibble[16] = { 0x00000000u, 0x1DB71064u, 0x3B6E20C8u, 0x26D930ACu, 0x76DC4190u, 0x6B6B51F4u,
                                         0x4DB26158u, 0x5005713Cu, 0xEDB88320u, 0xF00F9344u, 0xD6D6A3E8u, 0xCB61B38Cu,
                                         0x9B64C2B0u, 0x86D3D2D4u, 0xA00AE278u, 0xBDBDF21Cu };
    const unsigned char *p = (const unsigned char *)data;
    uint32_t c = 0xFFFFFFFFu;
    size_t i;
    for (i = 0; i < size; ++i) {
        c ^= p[i];
        c = (c >> 4) ^ nibble[c & 15u];
        c = (c >> 4) ^ nibble[c & 15u];
    }
    return c ^ 0xFFFFFFFFu;
}

static void rad__put32(unsigned char *p, uint32_t v) { p[0] = (unsigned char)v; p[1] = (unsigned char)(v >> 8); p[2] = (unsigned char)(v >> 16); p[3] = (unsigned char)(v >> 24); }
static void rad__put64(unsigned char *p, uint64_t v) { rad__put32(p, (uint32_t)v); rad__put32(p + 4, (uint32_t)(v >> 32)); }
static uint32_t rad__get32(const unsigned char *p) { return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24; }
static uint64_t rad__get64(const unsigned char *p) { return (uint64_t)rad__get32(p) | (uint64_t)rad__get32(p + 4) << 32; }
static int rad__host_big_endian(void) { const uint32_t one = 1; return *(const unsigned char *)&one == 0; }
static uint64_t rad__align_up(uint64_t x) { return (x + (RAD__ALIGN - 1)) & ~(uint64_t)(RAD__ALIGN - 1); }

RAD_API rad_result rad_container_size(const rad_section *sections, uint32_t count, size_t *out_bytes)
{
    uint64_t at, bytes;
    uint32_t i;
    if (!out_bytes || (count > 0 && !sections)) return RAD_ERROR_INVALID_ARGUMENT;
    if (count > 0x00FFFFFFu) return RAD_ERROR_SIZE_OVERFLOW;
    at = rad__align_up(RAD__HEADER_BYTES + (uint64_t)RAD__ENTRY_BYTES * count);
    for (i = 0; i < count; ++i) {
        if (sections[i].elem_size == 0 || (sections[i].count > 0 && !sections[i].data)) return RAD_ERROR_INVALID_ARGUMENT;
        if (sections[i].count > UINT64_MAX / sections[i].elem_size) return RAD_ERROR_SIZE_OVERFLOW;
        bytes = sections[i].count * sections[i].elem_size;
        if (bytes > UINT64_MAX - at - RAD__ALIGN) return RAD_ERROR_SIZE_OVERFLOW;
        at = rad__align_up(at + bytes);
    }
    if (at > (uint64_t)(size_t)-1) return RAD_ERROR_SIZE_OVERFLOW;
    *out_bytes = (size_t)at;
    return RAD_SUCCESS;
}

RAD_API rad_result rad_container_write(const rad_section *sections, uint32_t count, void *dst, size_t dst_size)
{
    unsigned char *base = (unsigned char *)dst;
    size_t need;
    uint64_t at;
    uint32_t i;
    rad_result r = rad_container_size(sections, count, &need);
    if (r != RAD_SUCCESS) return r;
    if (!dst || dst_size < need) return RAD_ERROR_INVALID_ARGUMENT;
    memset(base, 0, need);
    at = rad__align_up(RAD__HEADER_BYTES + (uint64_t)RAD__ENTRY_BYTES * count);
    for (i = 0; i < count; ++i) {
        unsigned char *e = base + RAD__HEADER_BYTES + (size_t)RAD__ENTRY_BYTES * i;
        uint64_t bytes = sections[i].count * sections[i].elem_size;
        size_t nl = 0;
        if (bytes) memcpy(base + at, sections[i].data, (size_t)bytes);
        rad__put32(e, sections[i].type);
        rad__put32(e + 4, sections[i].elem_size);
        rad__put64(e + 8, sections[i].count);
        rad__put64(e + 16, at);
        rad__put64(e + 24, bytes);
        rad__put32(e + 32, rad__crc32(base + at, (size_t)bytes));
        while (nl < sizeof(sections[i].name) - 1 && sections[i].name[nl]) ++nl;
        memcpy(e + 40, sections[i].name, nl);
        at = rad__align_up(at + bytes);
    }
    memcpy(base, "RADB", 4);
    rad__put32(base + 4, RAD_CONTAINER_VERSION);
    rad__put32(base + 8, count);
    rad__put32(base + 12, RAD__HEADER_BYTES);
    rad__put64(base + 16, RAD__HEADER_BYTES);
    rad__put64(base + 24, (uint64_t)need);
    rad__put32(base + 32, rad__host_big_endian() ? RAD__FLAG_BIG_ENDIAN : 0u);
    rad__put32(base + 36, rad__crc32(base + RAD__HEADER_BYTES, (size_t)RAD__ENTRY_BYTES * count)); /* the table */
    rad__put32(base + 60, rad__crc32(base, 60));
    return RAD_SUCCESS;
}

RAD_API void rad_container_close(rad_container *c)
{
    rad_allocator a;
    if (!c) return;
    a = c->allocator;
    rad__free(&a, c->sections);
    rad__free(&a, c);
}

RAD_API rad_result rad_container_open(const void *data, size_t size, const rad_context *ctx, rad_container **out)
{
    rad__ctx c;
    const unsigned char *p = (const unsigned char *)data;
    uint64_t file_size, table, first_data;
    uint32_t count, i, flags;
    rad_container *ct;
    rad__ctx_init(&c, ctx);
    if (!out) return RAD_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    if (!data) return RAD_ERROR_INVALID_ARGUMENT;
    if (((uintptr_t)data & 7u) != 0) {
        rad__log(&c, RAD_LOG_ERROR, "baked data must start on an 8-byte boundary (it is read in place)");
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    if (size < RAD__HEADER_BYTES) {
        rad__log(&c, RAD_LOG_ERROR, "baked data: %llu bytes, shorter than the %u-byte header", (unsigned long long)size, RAD__HEADER_BYTES);
        return size >= 4 && memcmp(p, "RADB", 4) != 0 ? RAD_ERROR_CORRUPT : RAD_ERROR_TRUNCATED;
    }
    if (memcmp(p, "RADB", 4) != 0) {
        rad__log(&c, RAD_LOG_ERROR, "baked data: no RADB magic (not a radiosity.h container)");
        return RAD_ERROR_CORRUPT;
    }
    if (rad__get32(p + 60) != rad__crc32(p, 60)) {
        rad__log(&c, RAD_LOG_ERROR, "baked data: header checksum mismatch");
        return RAD_ERROR_CORRUPT;
    }
    if (rad__get32(p + 4) != RAD_CONTAINER_VERSION) {
        rad__log(&c, RAD_LOG_ERROR, "baked data: container version %u, this library reads version %u", rad__get32(p + 4),
                 RAD_CONTAINER_VERSION);
        return RAD_ERROR_VERSION;
    }
    flags = rad__get32(p + 32);
    if ((flags & ~RAD__FLAG_BIG_ENDIAN) != 0 || ((flags & RAD__FLAG_BIG_ENDIAN) != 0) != rad__host_big_endian()) {
        rad__log(&c, RAD_LOG_ERROR, "baked data: flags %#x (byte order or features this build does not read)", flags);
        return RAD_ERROR_VERSION;
    }
    count = rad__get32(p + 8);
    table = rad__get64(p + 16);
    file_size = rad__get64(p + 24);
    if (rad__get32(p + 12) != RAD__HEADER_BYTES || table != RAD__HEADER_BYTES || count > 0x00FFFFFFu) {
        rad__log(&c, RAD_LOG_ERROR, "baked data: bad header (header size %u, table offset %llu, %u sections)", rad__get32(p + 12),
                 (unsigned long long)table, count);
        return RAD_ERROR_CORRUPT;
    }
    if (file_size > (uint64_t)size) {
        rad__log(&c, RAD_LOG_ERROR, "baked data: %llu bytes given, the container is %llu bytes", (unsigned long long)size,
                 (unsigned long long)file_size);
        return RAD_ERROR_TRUNCATED;
    }
    first_data = rad__align_up(RAD__HEADER_BYTES + (uint64_t)RAD__ENTRY_BYTES * count);
    if (first_data > file_size) {
        rad__log(&c, RAD_LOG_ERROR, "baked data: the table of %u sections does not fit in %llu bytes", count, (unsigned long long)file_size);
        return RAD_ERROR_CORRUPT;
    }
    if (rad__get32(p + 36) != rad__crc32(p + RAD__HEADER_BYTES, (size_t)RAD__ENTRY_BYTES * count)) {
        rad__log(&c, RAD_LOG_ERROR, "baked data: section table checksum mismatch");
        return RAD_ERROR_CORRUPT;
    }
    ct = (rad_container *)rad__alloc(&c.allocator, sizeof(rad_container));
    if (!ct) return RAD_ERROR_OUT_OF_MEMORY;
    ct->allocator = c.allocator;
    ct->count = count;
    ct->sections = (rad_section *)rad__alloc_array(&c.allocator, count ? count : 1u, sizeof(rad_section));
    if (!ct->sections) { rad__free(&c.allocator, ct); return RAD_ERROR_OUT_OF_MEMORY; }
    for (i = 0; i < count; ++i) {
        const unsigned char *e = p + RAD__HEADER_BYTES + (size_t)RAD__ENTRY_BYTES * i;
        rad_section *sec = &ct->sections[i];
        uint64_t off = rad__get64(e + 16), bytes = rad__get64(e + 24), n = rad__get64(e + 8);
        uint32_t esz = rad__get32(e + 4), k;
        const char *why = NULL;
        memset(sec, 0, sizeof(*sec));
        sec->type = rad__get32(e);
        sec->elem_size = esz;
        sec->count = n;
        memcpy(sec->name, e + 40, 24);
        if (sec->name[23] != 0) why = "its name is not NUL-terminated";
        else if (esz == 0 || n > UINT64_MAX / esz || n * esz != bytes) why = "element size x count differs from its byte size";
        else if (off % RAD__ALIGN != 0 || off < first_data) why = "its offset is misaligned or inside the table";
        else if (bytes > file_size || off > file_size - bytes) why = "it extends past the end of the container";
        else if (rad__get32(e + 32) != rad__crc32(p + off, (size_t)bytes)) why = "checksum mismatch";
        for (k = 36; k < 40 && !why; ++k)
            if (e[k]) why = "reserved bytes are not zero";
        if (why) {
            rad__log(&c, RAD_LOG_ERROR, "baked data: section %u (type %u, '%.23s'): %s", i, sec->type, sec->name, why);
            rad_container_close(ct);
            return RAD_ERROR_CORRUPT;
        }
        sec->data = p + off;
    }
    *out = ct;
    return RAD_SUCCESS;
}

RAD_API uint32_t rad_container_section_count(const rad_container *c) { return c ? c->count : 0; }

RAD_API const rad_section *rad_container_section(const rad_container *c, uint32_t index)
{
    return (c && index < c->count) ? &c->sections[index] : NULL;
}

RAD_API const rad_section *rad_container_find(const rad_container *c, uint32_t type, const char *name)
{
    uint32_t i;
    if (!c) return NULL;
    for (i = 0; i < c->count; ++i)
        if (c->sections[i].type == type && (!name || strcmp(c->sections[i].name, name) == 0)) return &c->sections[i];
    return NULL;
}

static void rad__section(rad_section *s, uint32_t type, uint32_t elem_size, uint64_t count, const void *data, const char *name)
{
    memset(s, 0, sizeof(*s));
    s->type = type;
    s->elem_size = elem_size;
    s->count = count;
    s->data = data;
    if (name) {
        size_t n = strlen(name);
        if (n > sizeof(s->name) - 1) n = sizeof(s->name) - 1;
        memcpy(s->name, name, n);
    }
}

/* The value rule of every loader (>>api_container VALUES): n floats, each finite (else
   NON_FINITE) and of magnitude <= RAD_BAKE_VALUE_MAX, and >= 0 when 'nonneg' (-0 passes)
   (else CORRUPT). One branch-free pass on the bit patterns (NaN and infinity have larger
   magnitude bits than any finite bound), then the first bad entry is found again for the
   message, which names 'what', the entry and its value. */
static rad_result rad__check_values(const rad__ctx *c, const char *what, const float *v, uint64_t n, int nonneg)
{
    const float vmax = RAD_BAKE_VALUE_MAX;
    uint32_t maxbits, sign = nonneg ? 0x80000000u : 0u, bad = 0;
    uint64_t i, j;
    memcpy(&maxbits, &vmax, 4);
    for (i = 0; i < n && !bad; i += 4096) {
        uint64_t e = n - i < 4096 ? n : i + 4096;
        for (j = i; j < e; ++j) {
            uint32_t b;
            memcpy(&b, v + j, 4);
            bad |= (uint32_t)((b & 0x7FFFFFFFu) > maxbits) | (uint32_t)((b & sign) != 0 && b != sign);
        }
    }
    if (!bad) return RAD_SUCCESS;
    for (i = 0; i < n; ++i) {
        const float x = v[i];
        if (!rad__finite(x)) {
            rad__log(c, RAD_LOG_ERROR, "baked data: %s: entry %llu is %g (not finite)", what, (unsigned long long)i, (double)x);
            return RAD_ERROR_NON_FINITE;
        }
        if (x > vmax || x < -vmax || (nonneg && x < 0.0f)) {
            rad__log(c, RAD_LOG_ERROR, "baked data: %s: entry %llu is %g (%s)", what, (unsigned long long)i, (double)x,
                     nonneg && x < 0.0f ? "negative" : "beyond RAD_BAKE_VALUE_MAX = 1e30");
            return RAD_ERROR_CORRUPT;
        }
    }
    return RAD_SUCCESS; /* not reached */
}

static int rad__all_finite(const float *v, uint64_t n)
{
    uint64_t i;
    for (i = 0; i < n; ++i)
        if (!rad__finite(v[i])) return 0;
    return 1;
}

/* the float fields of a patch record: finite (NON_FINITE), of magnitude <= RAD_BAKE_VALUE_MAX
   (CORRUPT) except the area (it grows with the square of the scene's scale, and rad_system
   only divides areas by areas), emission >= 0 (NEGATIVE_EMISSION) */
static rad_result rad__check_patch_values(const rad__ctx *c, const rad_patch *p, uint32_t i)
{
    float f[13];
    uint32_t k;
    memcpy(f, p->centroid, 3 * sizeof(float));
    memcpy(f + 3, p->normal, 3 * sizeof(float));
    f[6] = p->area;
    memcpy(f + 7, p->albedo, 3 * sizeof(float));
    memcpy(f + 10, p->emission, 3 * sizeof(float));
    for (k = 0; k < 13; ++k)
        if (!rad__all_finite(f + k, 1) || (k != 6 && (f[k] > RAD_BAKE_VALUE_MAX || f[k] < -RAD_BAKE_VALUE_MAX))) {
            const int finite = rad__finite(f[k]);
            rad__log(c, RAD_LOG_ERROR, "baked data: patch %u (PATCHES) has %s %g (%s)", i,
                     k < 3 ? "centroid" : k < 6 ? "normal" : k == 6 ? "area" : k < 10 ? "albedo" : "emission", (double)f[k],
                     finite ? "beyond RAD_BAKE_VALUE_MAX = 1e30" : "not finite");
            return finite ? RAD_ERROR_CORRUPT : RAD_ERROR_NON_FINITE;
        }
    for (k = 10; k < 13; ++k)
        if (f[k] < 0.0f) {
            rad__log(c, RAD_LOG_ERROR, "baked data: patch %u (PATCHES) has emission %g", i, (double)f[k]);
            return RAD_ERROR_NEGATIVE_EMISSION;
        }
    return RAD_SUCCESS;
}

/* ---- scene hashes and the signature ---- */

RAD_API uint64_t rad_hash64(const void *data, size_t size, uint64_t hash)
{
    const unsigned char *p = (const unsigned char *)data;
    size_t i;
    if (!p) return hash;
    for (i = 0; i < size; ++i) hash = (hash ^ p[i]) * 0x100000001B3ull;
    return hash;
}

/* hash of n uint32 words (or float bit patterns) as little-endian bytes */
static uint64_t rad__hash_words(uint64_t h, const void *words, size_t n)
{
    const unsigned char *p = (const unsigned char *)words;
    size_t i;
    for (i = 0; i < n; ++i) {
        uint32_t w;
        unsigned char b[4];
        memcpy(&w, p + 4 * i, 4);
        rad__put32(b, w);
        h = rad_hash64(b, 4, h);
    }
    return h;
}

RAD_API rad_result rad_scene_hash(const rad_scene *scene, uint64_t *out_geometry, uint64_t *out_materials)
{
    uint64_t g = RAD_HASH64_INIT, m = RAD_HASH64_INIT;
    uint32_t t, flag;
    if (out_geometry) *out_geometry = 0;
    if (out_materials) *out_materials = 0;
    if (!scene || !scene->positions || !scene->materials || !scene->materials_table) return RAD_ERROR_INVALID_ARGUMENT;
    g = rad__hash_words(g, &scene->triangle_count, 1);
    g = rad__hash_words(g, scene->positions, 9u * (size_t)scene->triangle_count);
    m = rad__hash_words(m, &scene->triangle_count, 1);
    for (t = 0; t < scene->triangle_count; ++t) {
        const uint32_t mi = scene->materials[t];
        if (mi >= scene->material_count) return RAD_ERROR_INVALID_ARGUMENT;
        m = rad__hash_words(m, scene->materials_table[mi].albedo, 3);
        m = rad__hash_words(m, scene->materials_table[mi].emission, 3);
        m = rad__hash_words(m, &scene->materials_table[mi].texture, 1);
    }
    flag = scene->uvs ? 1u : 0u;
    m = rad__hash_words(m, &flag, 1);
    if (scene->uvs) m = rad__hash_words(m, scene->uvs, 6u * (size_t)scene->triangle_count);
    if (out_geometry) *out_geometry = g;
    if (out_materials) *out_materials = m;
    return RAD_SUCCESS;
}

RAD_API rad_result rad_bake_matches_scene(const rad_bake *bake, const rad_scene *scene, uint64_t options, const rad_context *ctx)
{
    rad__ctx c;
    const rad_bake_signature *s;
    uint64_t g = 0, m = 0;
    int dg, dm, dopt;
    rad_result r;
    rad__ctx_init(&c, ctx);
    if (!bake || !scene) return RAD_ERROR_INVALID_ARGUMENT;
    if (bake->patches.triangle_count != scene->triangle_count) {
        rad__log(&c, RAD_LOG_ERROR, "baked data was made from another scene: the geometry differs (%u triangles in the bake, %u in the scene)",
                 bake->patches.triangle_count, scene->triangle_count);
        return RAD_ERROR_SCENE_MISMATCH;
    }
    s = bake->signature;
    if (!s) {
        rad__log(&c, RAD_LOG_WARNING, "baked data has no signature (saved without its scene, or by an older version): only its triangle count (%u) was compared",
                 scene->triangle_count);
        return RAD_SUCCESS;
    }
    if ((r = rad_scene_hash(scene, &g, &m)) != RAD_SUCCESS) return r;
    dg = s->geometry != 0 && s->geometry != g;
    dm = s->materials != 0 && s->materials != m;
    dopt = options != 0 && s->options != 0 && s->options != options;
    if (!dg && !dm && !dopt) return RAD_SUCCESS;
    {
        const char *part[3];
        char list[64];
        int np = 0, i;
        if (dg) part[np++] = "geometry";
        if (dm) part[np++] = "materials";
        if (dopt) part[np++] = "options";
        list[0] = '\0';
        for (i = 0; i < np; ++i) {
            if (i > 0) strcat(list, i == np - 1 ? " and " : ", ");
            strcat(list, part[i]);
        }
        rad__log(&c, RAD_LOG_ERROR,
                 "baked data was made from another scene or with other options: the %s differ%s (bake / scene hashes: geometry "
                 "%016llx / %016llx, materials %016llx / %016llx, options %016llx / %016llx)",
                 list, np == 1 && !dm && !dopt ? "s" : "", (unsigned long long)s->geometry, (unsigned long long)g,
                 (unsigned long long)s->materials, (unsigned long long)m, (unsigned long long)s->options,
                 (unsigned long long)options);
    }
    return RAD_ERROR_SCENE_MISMATCH;
}

RAD_API void rad_free_buffer(void *buffer, const rad_context *ctx)
{
    rad__ctx c;
    rad__ctx_init(&c, ctx);
    rad__free(&c.allocator, buffer);
}

RAD_API rad_result rad_save_memory(const rad_patches *P, const rad_matrix *F, const float *E, const float *B,
                                   const rad_context *ctx, void **out, size_t *out_size)
{
    rad__ctx c;
    rad_section s[9];
    rad_bake_signature sig;
    uint32_t n = 0, t, *tri = NULL;
    size_t bytes;
    void *buf;
    rad_result r;
    rad__ctx_init(&c, ctx);
    if (!out || !out_size) return RAD_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    *out_size = 0;
    if (!P || P->count == 0) return RAD_ERROR_INVALID_ARGUMENT;
    if (F) {
        r = rad__check_matrix(F, &c);
        if (r != RAD_SUCCESS) return r;
        if (F->rows != P->count || F->cols != P->count) {
            rad__log(&c, RAD_LOG_ERROR, "save: the matrix is %u x %u but there are %u patches", F->rows, F->cols, P->count);
            return RAD_ERROR_SIZE_MISMATCH;
        }
        /* what the loader would refuse is not written */
        r = F->storage == RAD_STORAGE_DENSE
                ? rad__check_values(&c, "dense form factors (FF_DENSE)", F->dense, (uint64_t)F->rows * F->cols, 1)
                : rad__check_values(&c, "sparse form factors (FF_VALUES)", F->values, F->row_offsets[F->rows], 1);
        if (r != RAD_SUCCESS) return r;
    }
    for (t = 0; t < P->count; ++t)
        if ((r = rad__check_patch_values(&c, &P->patches[t], t)) != RAD_SUCCESS) return r;
    if (E && (r = rad__check_values(&c, "vector 'E'", E, 3u * (uint64_t)P->count, 0)) != RAD_SUCCESS) return r;
    if (B && (r = rad__check_values(&c, "vector 'B'", B, 3u * (uint64_t)P->count, 0)) != RAD_SUCCESS) return r;
    memset(&sig, 0, sizeof(sig));
    if (P->scene && (r = rad_scene_hash(P->scene, &sig.geometry, &sig.materials)) != RAD_SUCCESS) return r;
    tri = (uint32_t *)rad__alloc_array(&c.allocator, (size_t)P->triangle_count * 2u, sizeof(uint32_t));
    if (!tri) return RAD_ERROR_OUT_OF_MEMORY;
    for (t = 0; t < P->triangle_count; ++t) { tri[2 * (size_t)t] = P->first_patch[t]; tri[2 * (size_t)t + 1] = P->subdivision[t]; }
    rad__section(&s[n++], RAD_SECTION_PATCHES, sizeof(rad_patch), P->count, P->patches, "patches");
    rad__section(&s[n++], RAD_SECTION_PATCH_VERTICES, 3 * sizeof(float), P->vertex_count, P->vertices, "vertices");
    rad__section(&s[n++], RAD_SECTION_TRIANGLES, 2 * sizeof(uint32_t), P->triangle_count, tri, "triangles");
    if (F && F->storage == RAD_STORAGE_DENSE) {
        rad__section(&s[n++], RAD_SECTION_FF_DENSE, sizeof(float), (uint64_t)F->rows * F->cols, F->dense, "F");
    } else if (F) {
        uint64_t nnz = F->row_offsets[F->rows];
        rad__section(&s[n++], RAD_SECTION_FF_ROW_OFFSETS, sizeof(uint64_t), (uint64_t)F->rows + 1u, F->row_offsets, "F");
        rad__section(&s[n++], RAD_SECTION_FF_COLUMNS, sizeof(uint32_t), nnz, F->columns, "F");
        rad__section(&s[n++], RAD_SECTION_FF_VALUES, sizeof(float), nnz, F->values, "F");
    }
    if (E) rad__section(&s[n++], RAD_SECTION_VECTOR, 3 * sizeof(float), P->count, E, "E");
    if (B) rad__section(&s[n++], RAD_SECTION_VECTOR, 3 * sizeof(float), P->count, B, "B");
    if (P->scene) rad__section(&s[n++], RAD_SECTION_SIGNATURE, (uint32_t)sizeof(sig), 1, &sig, "signature");
    r = rad_container_size(s, n, &bytes);
    if (r != RAD_SUCCESS) { rad__free(&c.allocator, tri); return r; }
    buf = rad__alloc(&c.allocator, bytes);
    if (!buf) { rad__free(&c.allocator, tri); return RAD_ERROR_OUT_OF_MEMORY; }
    r = rad_container_write(s, n, buf, bytes);
    rad__free(&c.allocator, tri);
    if (r != RAD_SUCCESS) { rad__free(&c.allocator, buf); return r; }
    *out = buf;
    *out_size = bytes;
    return RAD_SUCCESS;
}

RAD_API void rad_bake_destroy(rad_bake *b)
{
    rad_allocator a;
    if (!b) return;
    a = b->allocator;
    rad_container_close(b->container);
    rad__free(&a, b->patches.areas);
    rad__free(&a, b->patches.albedo);
    rad__free(&a, b->patches.first_patch);
    rad__free(&a, b->patches.subdivision);
    rad__free(&a, b->owned);
    rad__free(&a, b);
}

/* the single section of 'type' (named when name is given), checked for its element size */
static rad_result rad__bake_section(const rad__ctx *c, const rad_container *ct, uint32_t type, const char *name,
                                    uint32_t elem_size, int required, const rad_section **out)
{
    const rad_section *s = rad_container_find(ct, type, name);
    *out = NULL;
    if (!s) {
        if (!required) return RAD_SUCCESS;
        rad__log(c, RAD_LOG_ERROR, "baked data: section of type %u ('%s') is missing", type, name ? name : "");
        return RAD_ERROR_CORRUPT;
    }
    if (s->elem_size != elem_size) {
        rad__log(c, RAD_LOG_ERROR, "baked data: section type %u has %u-byte elements, expected %u", type, s->elem_size, elem_size);
        return RAD_ERROR_CORRUPT;
    }
    *out = s;
    return RAD_SUCCESS;
}

static rad_result rad__bake_fill(rad_bake *b, const rad__ctx *c)
{
    const rad_section *sp, *sv, *st, *sd, *so, *sc, *sx, *se, *sb;
    rad_result r;
    uint32_t N, i, k;
    uint64_t T;
    if ((r = rad__bake_section(c, b->container, RAD_SECTION_PATCHES, NULL, sizeof(rad_patch), 1, &sp)) != RAD_SUCCESS) return r;
    if ((r = rad__bake_section(c, b->container, RAD_SECTION_PATCH_VERTICES, NULL, 12, 1, &sv)) != RAD_SUCCESS) return r;
    if ((r = rad__bake_section(c, b->container, RAD_SECTION_TRIANGLES, NULL, 8, 1, &st)) != RAD_SUCCESS) return r;
    if (sp->count == 0 || sp->count >= RAD_NONE || sv->count >= RAD_NONE || st->count >= RAD_NONE) {
        rad__log(c, RAD_LOG_ERROR, "baked data: %llu patches, %llu vertices, %llu triangles (out of range)",
                 (unsigned long long)sp->count, (unsigned long long)sv->count, (unsigned long long)st->count);
        return RAD_ERROR_CORRUPT;
    }
    N = (uint32_t)sp->count;
    T = st->count;
    b->patches.count = N;
    b->patches.patches = (rad_patch *)(uintptr_t)sp->data;
    b->patches.vertex_count = (uint32_t)sv->count;
    b->patches.vertices = (float *)(uintptr_t)sv->data;
    b->patches.triangle_count = (uint32_t)T;
    if ((r = rad__check_values(c, "patch vertices (PATCH_VERTICES)", b->patches.vertices, sv->count * 3u, 0)) != RAD_SUCCESS) return r;
    b->patches.first_patch = (uint32_t *)rad__alloc_array(&b->allocator, T ? (size_t)T : 1u, sizeof(uint32_t));
    b->patches.subdivision = (uint32_t *)rad__alloc_array(&b->allocator, T ? (size_t)T : 1u, sizeof(uint32_t));
    b->patches.areas = (float *)rad__alloc_array(&b->allocator, N, sizeof(float));
    b->patches.albedo = (float *)rad__alloc_array(&b->allocator, (size_t)N * 3u, sizeof(float));
    if (!b->patches.first_patch || !b->patches.subdivision || !b->patches.areas || !b->patches.albedo) return RAD_ERROR_OUT_OF_MEMORY;
    for (i = 0; i < (uint32_t)T; ++i) {
        const uint32_t *tv = (const uint32_t *)st->data + 2 * (size_t)i;
        uint64_t n = tv[1];
        b->patches.first_patch[i] = tv[0];
        b->patches.subdivision[i] = tv[1];
        if (n == 0 || n > 65535u || (uint64_t)tv[0] + n * n > N) {
            rad__log(c, RAD_LOG_ERROR, "baked data: triangle %u claims patches [%u, %llu) of %u", i, tv[0],
                     (unsigned long long)((uint64_t)tv[0] + n * n), N);
            return RAD_ERROR_INDEX_OUT_OF_RANGE;
        }
    }
    for (i = 0; i < N; ++i) {
        const rad_patch *p = &b->patches.patches[i];
        for (k = 0; k < 3; ++k)
            if (p->vertices[k] >= b->patches.vertex_count) {
                rad__log(c, RAD_LOG_ERROR, "baked data: patch %u uses vertex %u of %u", i, p->vertices[k], b->patches.vertex_count);
                return RAD_ERROR_INDEX_OUT_OF_RANGE;
            }
        if (p->triangle >= T) {
            rad__log(c, RAD_LOG_ERROR, "baked data: patch %u lies on triangle %u of %llu", i, p->triangle, (unsigned long long)T);
            return RAD_ERROR_INDEX_OUT_OF_RANGE;
        }
        if ((r = rad__check_patch_values(c, p, i)) != RAD_SUCCESS) return r;
        if (!(p->area > 0.0f)) {
            rad__log(c, RAD_LOG_ERROR, "baked data: patch %u has area %g", i, (double)p->area);
            return RAD_ERROR_DEGENERATE_TRIANGLE;
        }
        for (k = 0; k < 3; ++k)
            if (p->albedo[k] < 0.0f || p->albedo[k] >= 1.0f) {
                rad__log(c, RAD_LOG_ERROR, "baked data: patch %u has albedo %g", i, (double)p->albedo[k]);
                return RAD_ERROR_ALBEDO_RANGE;
            }
        b->patches.areas[i] = p->area;
        memcpy(b->patches.albedo + 3 * (size_t)i, p->albedo, 3 * sizeof(float));
    }
    /* form factors: dense, or the three CSR sections, or none */
    if ((r = rad__bake_section(c, b->container, RAD_SECTION_FF_DENSE, NULL, 4, 0, &sd)) != RAD_SUCCESS) return r;
    if ((r = rad__bake_section(c, b->container, RAD_SECTION_FF_ROW_OFFSETS, NULL, 8, 0, &so)) != RAD_SUCCESS) return r;
    if ((r = rad__bake_section(c, b->container, RAD_SECTION_FF_COLUMNS, NULL, 4, 0, &sc)) != RAD_SUCCESS) return r;
    if ((r = rad__bake_section(c, b->container, RAD_SECTION_FF_VALUES, NULL, 4, 0, &sx)) != RAD_SUCCESS) return r;
    if (sd) {
        if (sd->count != (uint64_t)N * N) {
            rad__log(c, RAD_LOG_ERROR, "baked data: dense matrix of %llu entries for %u patches", (unsigned long long)sd->count, N);
            return RAD_ERROR_SIZE_MISMATCH;
        }
        if ((r = rad__check_values(c, "dense form factors (FF_DENSE)", (const float *)sd->data, sd->count, 1)) != RAD_SUCCESS)
            return r;
        b->F.rows = b->F.cols = N;
        b->F.storage = RAD_STORAGE_DENSE;
        b->F.dense = (const float *)sd->data;
    } else if (so || sc || sx) {
        const uint64_t *off;
        const uint32_t *col;
        if (!so || !sc || !sx || so->count != (uint64_t)N + 1u || sc->count != sx->count) {
            rad__log(c, RAD_LOG_ERROR, "baked data: incomplete or inconsistent CSR sections");
            return RAD_ERROR_CORRUPT;
        }
        off = (const uint64_t *)so->data;
        col = (const uint32_t *)sc->data;
        if (off[0] != 0 || off[N] != sc->count) {
            rad__log(c, RAD_LOG_ERROR, "baked data: CSR offsets start at %llu and end at %llu, %llu entries",
                     (unsigned long long)off[0], (unsigned long long)off[N], (unsigned long long)sc->count);
            return RAD_ERROR_CORRUPT;
        }
        for (i = 0; i < N; ++i) {
            uint64_t q;
            if (off[i + 1] < off[i] || off[i + 1] > sc->count) {
                rad__log(c, RAD_LOG_ERROR, "baked data: CSR row %u offsets are not monotone", i);
                return RAD_ERROR_CORRUPT;
            }
            for (q = off[i]; q < off[i + 1]; ++q) {
                if (col[q] >= N) {
                    rad__log(c, RAD_LOG_ERROR, "baked data: CSR row %u has column %u of %u", i, col[q], N);
                    return RAD_ERROR_INDEX_OUT_OF_RANGE;
                }
                if (q > off[i] && col[q] <= col[q - 1]) {
                    rad__log(c, RAD_LOG_ERROR, "baked data: CSR row %u columns are not ascending", i);
                    return RAD_ERROR_CORRUPT;
                }
            }
        }
        if ((r = rad__check_values(c, "sparse form factors (FF_VALUES)", (const float *)sx->data, sx->count, 1)) != RAD_SUCCESS)
            return r;
        b->F.rows = b->F.cols = N;
        b->F.storage = RAD_STORAGE_SPARSE;
        b->F.row_offsets = off;
        b->F.columns = col;
        b->F.values = (const float *)sx->data;
    }
    /* every vector, not only E and B: the application's ("H", "L", ...) are read in place too */
    for (k = 0; k < rad_container_section_count(b->container); ++k) {
        const rad_section *s = rad_container_section(b->container, k);
        char what[48];
        if (s->type != RAD_SECTION_VECTOR) continue;
        if (s->elem_size != 12u || s->count != N) {
            rad__log(c, RAD_LOG_ERROR, "baked data: vector '%s' has %llu elements of %u bytes, expected %u RGB triples", s->name,
                     (unsigned long long)s->count, s->elem_size, N);
            return RAD_ERROR_SIZE_MISMATCH;
        }
        snprintf(what, sizeof(what), "vector '%s'", s->name);
        if ((r = rad__check_values(c, what, (const float *)s->data, s->count * 3u, 0)) != RAD_SUCCESS) return r;
    }
    if ((r = rad__bake_section(c, b->container, RAD_SECTION_VECTOR, "E", 12, 0, &se)) != RAD_SUCCESS) return r;
    if ((r = rad__bake_section(c, b->container, RAD_SECTION_VECTOR, "B", 12, 0, &sb)) != RAD_SUCCESS) return r;
    b->E = se ? (const float *)se->data : NULL;
    b->B = sb ? (const float *)sb->data : NULL;
    if ((r = rad__bake_section(c, b->container, RAD_SECTION_SIGNATURE, NULL, (uint32_t)sizeof(rad_bake_signature), 0, &se)) != RAD_SUCCESS)
        return r;
    if (se && se->count != 1u) {
        rad__log(c, RAD_LOG_ERROR, "baked data: the signature section holds %llu records, expected 1", (unsigned long long)se->count);
        return RAD_ERROR_CORRUPT;
    }
    b->signature = se ? (const rad_bake_signature *)se->data : NULL;
    return RAD_SUCCESS;
}

static rad_result rad__load(const void *data, size_t size, void *owned, const rad__ctx *c, const rad_context *ctx,
                            rad_bake **out)
{
    rad_bake *b = (rad_bake *)rad__alloc(&c->allocator, sizeof(rad_bake));
    rad_result r;
    if (!b) { rad__free(&c->allocator, owned); return RAD_ERROR_OUT_OF_MEMORY; }
    memset(b, 0, sizeof(*b));
    b->allocator = c->allocator;
    b->owned = owned;
    b->patches.allocator = c->allocator;
    r = rad_container_open(data, size, ctx, &b->container);
    if (r == RAD_SUCCESS) r = rad__bake_fill(b, c);
    if (r != RAD_SUCCESS) { rad_bake_destroy(b); return r; }
    *out = b;
    return RAD_SUCCESS;
}

RAD_API rad_result rad_load_memory(const void *data, size_t size, const rad_context *ctx, rad_bake **out)
{
    rad__ctx c;
    rad__ctx_init(&c, ctx);
    if (!out) return RAD_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    if (!data) return RAD_ERROR_INVALID_ARGUMENT;
    return rad__load(data, size, NULL, &c, ctx, out);
}

#ifndef RAD_NO_STDIO
/* Writes 'size' bytes to '<path>.partial' beside path and renames it over path only when
   every byte is written and closed: a failed save leaves the old file (or none) in place. */
static rad_result rad__write_file_atomic(const rad__ctx *c, const char *path, const void *data, size_t size)
{
    size_t len = strlen(path);
    char *tmp = (char *)rad__alloc(&c->allocator, len + 9u);
    FILE *f;
    int ok;
    if (!tmp) {
        rad__log(c, RAD_LOG_ERROR, "saving '%s': out of memory for the temporary name", path);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    memcpy(tmp, path, len);
    memcpy(tmp + len, ".partial", 9u);
    f = fopen(tmp, "wb");
    if (!f) {
        rad__log(c, RAD_LOG_ERROR, "cannot open '%s' for writing (the folder must exist and be writable)", tmp);
        rad__free(&c->allocator, tmp);
        return RAD_ERROR_IO;
    }
    ok = fwrite(data, 1, size, f) == size;
    ok = (fclose(f) == 0) && ok;
    if (ok && rename(tmp, path) != 0) {
        /* where rename does not replace an existing file (Windows), replace it by hand */
        ok = remove(path) == 0 && rename(tmp, path) == 0;
    }
    if (!ok) {
        remove(tmp);
        rad__log(c, RAD_LOG_ERROR, "cannot write '%s' (disk full or not writable): the old file, if any, is unchanged", path);
    }
    rad__free(&c->allocator, tmp);
    return ok ? RAD_SUCCESS : RAD_ERROR_IO;
}

RAD_API rad_result rad_save_file(const char *path, const rad_patches *patches, const rad_matrix *F, const float *E,
                                 const float *B, const rad_context *ctx)
{
    rad__ctx c;
    void *buf = NULL;
    size_t size = 0;
    rad_result r;
    rad__ctx_init(&c, ctx);
    if (!path) return RAD_ERROR_INVALID_ARGUMENT;
    r = rad_save_memory(patches, F, E, B, ctx, &buf, &size);
    if (r != RAD_SUCCESS) return r;
    r = rad__write_file_atomic(&c, path, buf, size);
    rad__free(&c.allocator, buf);
    return r;
}

RAD_API rad_result rad_load_file(const char *path, const rad_context *ctx, rad_bake **out)
{
    rad__ctx c;
    FILE *f;
    long len;
    void *buf;
    unsigned char head[64];
    size_t got;
    rad__ctx_init(&c, ctx);
    if (!out) return RAD_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    if (!path) return RAD_ERROR_INVALID_ARGUMENT;
    f = fopen(path, "rb");
    if (!f) {
        rad__log(&c, RAD_LOG_ERROR, "cannot open '%s'", path);
        return RAD_ERROR_IO;
    }
    /* the header first: a folder, a file of another kind or a truncated bake is refused
       before anything of its size is allocated or read */
    got = fread(head, 1, sizeof(head), f);
    if (got < sizeof(head)) {
        int err = ferror(f);
        fclose(f);
        rad__log(&c, RAD_LOG_ERROR, err ? "cannot read '%s' (a folder, or not readable)" :
                 "'%s' is shorter than a container header (64 bytes)", path);
        return err ? RAD_ERROR_IO : RAD_ERROR_TRUNCATED;
    }
    if (memcmp(head, "RADB", 4) != 0) {
        fclose(f);
        rad__log(&c, RAD_LOG_ERROR, "'%s' is not a radiosity.h container (no RADB magic)", path);
        return RAD_ERROR_CORRUPT;
    }
    if (fseek(f, 0, SEEK_END) != 0 || (len = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
        fclose(f);
        rad__log(&c, RAD_LOG_ERROR, "cannot size '%s'", path);
        return RAD_ERROR_IO;
    }
    if (rad__get64(head + 24) > (uint64_t)len) {
        fclose(f);
        rad__log(&c, RAD_LOG_ERROR, "'%s' has %ld bytes, its header says %llu: the file is truncated", path, len,
                 (unsigned long long)rad__get64(head + 24));
        return RAD_ERROR_TRUNCATED;
    }
    buf = rad__alloc(&c.allocator, (size_t)len);
    if (!buf) {
        fclose(f);
        rad__log(&c, RAD_LOG_ERROR, "loading '%s': out of memory for its %ld bytes", path, len);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    if (fread(buf, 1, (size_t)len, f) != (size_t)len) {
        fclose(f);
        rad__free(&c.allocator, buf);
        rad__log(&c, RAD_LOG_ERROR, "cannot read '%s'", path);
        return RAD_ERROR_IO;
    }
    fclose(f);
    return rad__load(buf, (size_t)len, buf, &c, ctx, out);
}
#endif

/* ======================================================================================== */
/* >>glsl: GLSL compute kernels (generated sources, access)                                 */
/* ======================================================================================== */

/* push-constant mirrors: the GLSL blocks are 4-byte members in declaration order */
typedef char rad__check_glsl_dense_push[(sizeof(rad_glsl_gather_dense_push) == 20 &&
                                         offsetof(rad_glsl_gather_dense_push, f_base) == 12 &&
                                         offsetof(rad_glsl_gather_dense_push, flags) == 16) ? 1 : -1];
typedef char rad__check_glsl_csr_push[(sizeof(rad_glsl_gather_csr_push) == 16 &&
                                       offsetof(rad_glsl_gather_csr_push, entry_base) == 8 &&
                                       offsetof(rad_glsl_gather_csr_push, flags) == 12) ? 1 : -1];
typedef char rad__check_glsl_mb_push[(sizeof(rad_glsl_mb_apply_push) == 20 &&
                                      offsetof(rad_glsl_mb_apply_push, base) == 12 &&
                                      offsetof(rad_glsl_mb_apply_push, flags) == 16) ? 1 : -1];
typedef char rad__check_glsl_temporal_push[(sizeof(rad_glsl_temporal_push) == 60 &&
                                            offsetof(rad_glsl_temporal_push, words) == 24 &&
                                            offsetof(rad_glsl_temporal_push, word_base) == 40 &&
                                            offsetof(rad_glsl_temporal_push, weight) == 44 &&
                                            offsetof(rad_glsl_temporal_push, env) == 48) ? 1 : -1];
typedef char rad__check_glsl_blocks_push[(sizeof(rad_glsl_mb_blocks_push) == 24 &&
                                          offsetof(rad_glsl_mb_blocks_push, tile) == 12 &&
                                          offsetof(rad_glsl_mb_blocks_push, flags) == 20) ? 1 : -1];
typedef char rad__check_glsl_local_apply_push[(sizeof(rad_glsl_local_apply_push) == 32 &&
                                               offsetof(rad_glsl_local_apply_push, slot_offset) == 16 &&
                                               offsetof(rad_glsl_local_apply_push, flags) == 28) ? 1 : -1];
typedef char rad__check_glsl_local_vectors_push[(sizeof(rad_glsl_local_vectors_push) == 48 &&
                                                 offsetof(rad_glsl_local_vectors_push, nnz) == 20 &&
                                                 offsetof(rad_glsl_local_vectors_push, flags) == 32 &&
                                                 offsetof(rad_glsl_local_vectors_push, ann) == 36) ? 1 : -1];
typedef char rad__check_glsl_local_update_push[(sizeof(rad_glsl_local_update_push) == 28 &&
                                                offsetof(rad_glsl_local_update_push, base) == 16 &&
                                                offsetof(rad_glsl_local_update_push, ev) == 24) ? 1 : -1];
typedef char rad__check_glsl_vp_gather_push[(sizeof(rad_glsl_vp_gather_push) == 56 &&
                                             offsetof(rad_glsl_vp_gather_push, dims) == 24 &&
                                             offsetof(rad_glsl_vp_gather_push, row_offset) == 40 &&
                                             offsetof(rad_glsl_vp_gather_push, flags) == 52) ? 1 : -1];
typedef char rad__check_glsl_alias_push[(sizeof(rad_glsl_alias_build_push) == 28 &&
                                         offsetof(rad_glsl_alias_build_push, entry_base) == 16 &&
                                         offsetof(rad_glsl_alias_build_push, flags) == 24) ? 1 : -1];

typedef struct rad__glsl_entry {
    const char *name;
    const char *const *pieces;
    uint32_t count;
    uint32_t length;
} rad__glsl_entry;

/* Generated by glsl/embed.c from the files glsl/<name>: edit those, then run make glsl. */
/* >>glsl begin */
static const char rad__glsl_0_0[] =
    "#version 450\n"
    "// radiosity.h kernel RAD_GLSL_GATHER_DENSE: one classic bounce with a dense form-factor matrix,\n"
    "//   out_i = rho_i * sum_j F_ij E_j            (flags bit 0 clear: RAD_OUTPUT_INDIRECT)\n"
    "//   out_i = E_i + rho_i * sum_j F_ij E_j      (flags bit 0 set:   RAD_OUTPUT_TOTAL)\n"
    "// for rows i = row_offset .. row_offset + row_count - 1. ONE WORKGROUP PER ROW: dispatch\n"
    "// row_count groups; the invocations of a group read the row with a stride of the group size\n"
    "// (consecutive invocations read consecutive columns) and sum in shared memory.\n"
    "// Chunking: binding 0 holds the rows of this chunk only; F_ij is F[f_base + (i - row_offset) * cols + j],\n"
    "// so a matrix larger than one storage-buffer range runs as several dispatches.\n"
    "layout(local_size_x_id = 0) in;\n"
    "layout(std430, set = 0, binding = 0) readonly buffer MatrixF { float F[]; };\n"
    "layout(std430, set = 0, binding = 1) readonly buffer VectorE { float E[]; };      // 3 N, RGB interleaved\n"
    "layout(std430, set = 0, binding = 2) readonly buffer Albedo { float rho[]; };     // 3 N\n"
    "layout(std430, set = 0, binding = 3) buffer Output { float outv[]; };             // 3 N\n"
    "layout(push_constant) uniform Push {\n"
    "    uint row_offset;  // first row of this dispatch (global index)\n"
    "    uint row_count;   // rows in this dispatch (= workgroups)\n"
    "    uint cols;        // N\n"
    "    uint f_base;      // element of binding 0 that holds F[row_offset][0]\n"
    "    uint flags;       // bit 0: add E (total)\n"
    "} pc;\n"
    "\n"
    "shared vec3 partial[gl_WorkGroupSize.x];\n"
    "\n"
    "void main()\n"
    "{\n"
    "    uint r = gl_WorkGroupID.x, lid = gl_LocalInvocationID.x;\n"
    "    if (r >= pc.row_count) return;               // the whole group: barriers stay uniform\n"
    "    uint i = pc.row_offset + r;\n"
    "    uint at = pc.f_base + r * pc.cols;\n"
    "    precise vec3 acc = vec3(0.0);\n"
    "    for (uint j = lid; j < pc.cols; j += gl_WorkGroupSize.x) {\n"
    "        float f = F[at + j];\n"
    "        acc += f * vec3(E[3u * j], E[3u * j + 1u], E[3u * j + 2u]);\n"
    "    }\n"
    "    partial[lid] = acc;\n"
    "    barrier();\n"
    "    for (uint width = gl_WorkGroupSize.x; width > 1u; ) {   // any group size, no subgroup assumption\n"
    "        uint h = (width + 1u) / 2u;\n"
    "        if (lid < width - h) partial[lid] += partial[lid + h];\n"
    "        barrier();\n"
    "        width = h;\n"
    "    }\n"
    "    if (lid != 0u) return;\n"
    "    precise vec3 o = partial[0] * vec3(rho[3u * i], rho[3u * i + 1u], rho[3u * i + 2u]);\n"
    "    if ((pc.flags & 1u) != 0u) o += vec3(E[3u * i], E[3u * i + 1u], E[3u * i + 2u]);\n"
    "    outv[3u * i] = o.x;\n"
    "    outv[3u * i + 1u] = o.y;\n"
    "    outv[3u * i + 2u] = o.z;\n"
    "}\n";
static const char *const rad__glsl_pieces_0[] = { rad__glsl_0_0 };
static const char rad__glsl_1_0[] =
    "#version 450\n"
    "// radiosity.h kernel RAD_GLSL_GATHER_CSR: one classic bounce with a CSR (sparse) form-factor matrix,\n"
    "//   out_i = rho_i * sum_k values[k] E_columns[k]  (+ E_i when flags bit 0 is set)\n"
    "// for rows i = row_offset .. row_offset + row_count - 1, ONE WORKGROUP PER ROW (dispatch\n"
    "// row_count groups; the group strides over the row's entries and sums in shared memory).\n"
    "// Binding 0 holds all N + 1 row offsets as uint64 (two uint words each, low word first, as\n"
    "// rad_matrix.row_offsets stores them). Chunking: bindings 1 and 2 may hold only the entries of\n"
    "// this chunk's rows; entry k of the matrix is element k - entry_base of them (entry_base = the\n"
    "// low 32 bits of the first entry index the bound ranges start at; a chunk spans < 2^32 entries).\n"
    "layout(local_size_x_id = 0) in;\n"
    "layout(std430, set = 0, binding = 0) readonly buffer RowOffsets { uvec2 row_offsets[]; };\n"
    "layout(std430, set = 0, binding = 1) readonly buffer Columns { uint columns[]; };\n"
    "layout(std430, set = 0, binding = 2) readonly buffer Values { float values[]; };\n"
    "layout(std430, set = 0, binding = 3) readonly buffer VectorE { float E[]; };      // 3 N\n"
    "layout(std430, set = 0, binding = 4) readonly buffer Albedo { float rho[]; };     // 3 N\n"
    "layout(std430, set = 0, binding = 5) buffer Output { float outv[]; };             // 3 N\n"
    "layout(push_constant) uniform Push {\n"
    "    uint row_offset;  // first row of this dispatch (global index)\n"
    "    uint row_count;   // rows in this dispatch (= workgroups)\n"
    "    uint entry_base;  // low 32 bits of the entry index at element 0 of bindings 1 and 2\n"
    "    uint flags;       // bit 0: add E (total)\n"
    "} pc;\n"
    "\n"
    "shared vec3 partial[gl_WorkGroupSize.x];\n"
    "\n"
    "void main()\n"
    "{\n"
    "    uint r = gl_WorkGroupID.x, lid = gl_LocalInvocationID.x;\n"
    "    if (r >= pc.row_count) return;\n"
    "    uint i = pc.row_offset + r;\n"
    "    uint k0 = row_offsets[i].x - pc.entry_base;       // wraps correctly: only the difference matters\n"
    "    uint count = row_offsets[i + 1u].x - row_offsets[i].x;\n"
    "    precise vec3 acc = vec3(0.0);\n"
    "    for (uint e = lid; e < count; e += gl_WorkGroupSize.x) {\n"
    "        uint j = columns[k0 + e];\n"
    "        acc += values[k0 + e] * vec3(E[3u * j], E[3u * j + 1u], E[3u * j + 2u]);\n"
    "    }\n"
    "    partial[lid] = acc;\n"
    "    barrier();\n"
    "    for (uint width = gl_WorkGroupSize.x; width > 1u; ) {\n"
    "        uint h = (width + 1u) / 2u;\n"
    "        if (lid < width - h) partial[lid] += partial[lid + h];\n"
    "        barrier();\n"
    "        width = h;\n"
    "    }\n"
    "    if (lid != 0u) return;\n"
    "    precise vec3 o = partial[0] * vec3(rho[3u * i], rho[3u * i + 1u], rho[3u * i + 2u]);\n"
    "    if ((pc.flags & 1u) != 0u) o += vec3(E[3u * i], E[3u * i + 1u], E[3u * i + 2u]);\n"
    "    outv[3u * i] = o.x;\n"
    "    outv[3u * i + 1u] = o.y;\n"
    "    outv[3u * i + 2u] = o.z;\n"
    "}\n";
static const char *const rad__glsl_pieces_1[] = { rad__glsl_1_0 };
static const char rad__glsl_2_0[] =
    "#version 450\n"
    "// radiosity.h kernel RAD_GLSL_MB_APPLY_FLOAT: the multi-bounce apply L = F_mb E with float planes\n"
    "// (rad_multibounce with precision RAD_MB_FLOAT). Plane row i' (permuted order) is original row\n"
    "// row_perm[i'], plane column j' is original column col_perm[j'] (identity when flags bit 1 is clear):\n"
    "//   out[row_perm[i']] = sum_j' plane_c[i'][j'] * E[col_perm[j']]  (+ E[row_perm[i']] when flags bit 0)\n"
    "// for plane rows i' = row_offset .. row_offset + row_count - 1, channels c = R, G, B.\n"
    "// ONE WORKGROUP PER ROW: dispatch row_count groups; the group strides over the columns.\n"
    "// Chunking: bindings 0..2 may hold only this chunk's rows; entry (i', j') of plane c is element\n"
    "// base + (i' - row_offset) * n + j' of binding c.\n"
    "layout(local_size_x_id = 0) in;\n"
    "layout(std430, set = 0, binding = 0) readonly buffer PlaneR { float R[]; };\n"
    "layout(std430, set = 0, binding = 1) readonly buffer PlaneG { float G[]; };\n"
    "layout(std430, set = 0, binding = 2) readonly buffer PlaneB { float B[]; };\n"
    "layout(std430, set = 0, binding = 3) readonly buffer VectorE { float E[]; };       // 3 N, original order\n"
    "layout(std430, set = 0, binding = 4) readonly buffer ColPerm { uint col_perm[]; }; // N (unused without bit 1)\n"
    "layout(std430, set = 0, binding = 5) readonly buffer RowPerm { uint row_perm[]; }; // N (unused without bit 1)\n"
    "layout(std430, set = 0, binding = 6) buffer Output { float outv[]; };              // 3 N, original order\n"
    "layout(push_constant) uniform Push {\n"
    "    uint n;           // N\n"
    "    uint row_offset;  // first plane row of this dispatch\n"
    "    uint row_count;   // rows in this dispatch (= workgroups)\n"
    "    uint base;        // element of bindings 0..2 that holds plane row row_offset, column 0\n"
    "    uint flags;       // bit 0: add E (total); bit 1: row_perm / col_perm are bound\n"
    "} pc;\n"
    "\n"
    "shared vec3 partial[gl_WorkGroupSize.x];\n"
    "\n"
    "void main()\n"
    "{\n"
    "    uint r = gl_WorkGroupID.x, lid = gl_LocalInvocationID.x;\n"
    "    if (r >= pc.row_count) return;\n"
    "    bool perm = (pc.flags & 2u) != 0u;\n"
    "    uint ip = pc.row_offset + r;\n"
    "    uint at = pc.base + r * pc.n;\n"
    "    precise vec3 acc = vec3(0.0);\n"
    "    for (uint j = lid; j < pc.n; j += gl_WorkGroupSize.x) {\n"
    "        uint e = 3u * (perm \? col_perm[j] : j);\n"
    "        acc += vec3(R[at + j], G[at + j], B[at + j]) * vec3(E[e], E[e + 1u], E[e + 2u]);\n"
    "    }\n"
    "    partial[lid] = acc;\n"
    "    barrier();\n"
    "    for (uint width = gl_WorkGroupSize.x; width > 1u; ) {\n"
    "        uint h = (width + 1u) / 2u;\n"
    "        if (lid < width - h) partial[lid] += partial[lid + h];\n"
    "        barrier();\n"
    "        width = h;\n"
    "    }\n"
    "    if (lid != 0u) return;\n"
    "    uint o = 3u * (perm \? row_perm[ip] : ip);\n"
    "    precise vec3 s = partial[0];\n"
    "    if ((pc.flags & 1u) != 0u) s += vec3(E[o], E[o + 1u], E[o + 2u]);\n"
    "    outv[o] = s.x;\n"
    "    outv[o + 1u] = s.y;\n"
    "    outv[o + 2u] = s.z;\n"
    "}\n";
static const char *const rad__glsl_pieces_2[] = { rad__glsl_2_0 };
static const char rad__glsl_3_0[] =
    "#version 450\n"
    "// radiosity.h kernel RAD_GLSL_MB_APPLY_HALF: the multi-bounce apply L = F_mb E with IEEE binary16\n"
    "// planes (rad_multibounce with precision RAD_MB_HALF), uploaded unchanged: two values per uint\n"
    "// word, the lower-addressed value in the low 16 bits (little-endian), so no 16-bit storage\n"
    "// feature is needed. Same bindings, push constants, permutations, dispatch (one workgroup per\n"
    "// row) and chunking as RAD_GLSL_MB_APPLY_FLOAT, with 'base' counted in binary16 values (it may\n"
    "// be odd). Buffers and bound ranges must cover whole 32-bit words: round a range's end up to a\n"
    "// multiple of 4 bytes, or the word holding the last value reads as zero.\n"
    "layout(local_size_x_id = 0) in;\n"
    "layout(std430, set = 0, binding = 0) readonly buffer PlaneR { uint R[]; };\n"
    "layout(std430, set = 0, binding = 1) readonly buffer PlaneG { uint G[]; };\n"
    "layout(std430, set = 0, binding = 2) readonly buffer PlaneB { uint B[]; };\n"
    "layout(std430, set = 0, binding = 3) readonly buffer VectorE { float E[]; };\n"
    "layout(std430, set = 0, binding = 4) readonly buffer ColPerm { uint col_perm[]; };\n"
    "layout(std430, set = 0, binding = 5) readonly buffer RowPerm { uint row_perm[]; };\n"
    "layout(std430, set = 0, binding = 6) buffer Output { float outv[]; };\n"
    "layout(push_constant) uniform Push {\n"
    "    uint n;\n"
    "    uint row_offset;\n"
    "    uint row_count;\n"
    "    uint base;        // binary16 value of bindings 0..2 that holds plane row row_offset, column 0\n"
    "    uint flags;       // bit 0: add E (total); bit 1: row_perm / col_perm are bound\n"
    "} pc;\n"
    "\n"
    "shared vec3 partial[gl_WorkGroupSize.x];\n"
    "\n"
    "float half_at(uint word, uint h) { vec2 v = unpackHalf2x16(word); return (h & 1u) != 0u \? v.y : v.x; }\n"
    "\n"
    "void main()\n"
    "{\n"
    "    uint r = gl_WorkGroupID.x, lid = gl_LocalInvocationID.x;\n"
    "    if (r >= pc.row_count) return;\n"
    "    bool perm = (pc.flags & 2u) != 0u;\n"
    "    uint ip = pc.row_offset + r;\n"
    "    uint at = pc.base + r * pc.n;\n"
    "    precise vec3 acc = vec3(0.0);\n"
    "    for (uint j = lid; j < pc.n; j += gl_WorkGroupSize.x) {\n"
    "        uint e = 3u * (perm \? col_perm[j] : j), h = at + j;\n"
    "        vec3 f = vec3(half_at(R[h >> 1u], h), half_at(G[h >> 1u], h), half_at(B[h >> 1u], h));\n"
    "        acc += f * vec3(E[e], E[e + 1u], E[e + 2u]);\n"
    "    }\n"
    "    partial[lid] = acc;\n"
    "    barrier();\n"
    "    for (uint width = gl_WorkGroupSize.x; width > 1u; ) {\n"
    "        uint h = (width + 1u) / 2u;\n"
    "        if (lid < width - h) partial[lid] += partial[lid + h];\n"
    "        barrier();\n"
    "        width = h;\n"
    "    }\n"
    "    if (lid != 0u) return;\n"
    "    uint o = 3u * (perm \? row_perm[ip] : ip);\n"
    "    precise vec3 s = partial[0];\n"
    "    if ((pc.flags & 1u) != 0u) s += vec3(E[o], E[o + 1u], E[o + 2u]);\n"
    "    outv[o] = s.x;\n"
    "    outv[o + 1u] = s.y;\n"
    "    outv[o + 2u] = s.z;\n"
    "}\n";
static const char *const rad__glsl_pieces_3[] = { rad__glsl_3_0 };
static const char rad__glsl_4_0[] =
    "#version 450\n"
    "// radiosity.h kernel RAD_GLSL_TEMPORAL_STEP: one frame of temporal radiosity (rad_temporal_step\n"
    "// with a fixed weight), drawing exactly the indices the CPU draws: the counter-based generator\n"
    "// and the alias draw of the >>api_temporal doc block, in 32-bit integer arithmetic. One invocation per row i\n"
    "// (dispatch ceil(row_count / group size) groups):\n"
    "//   acc = 0; for s = 0..k-1: J = draw(sample = sample_base + s); acc += V_J\n"
    "//   X = acc * (T_i / k); X *= rho_i (flags bit 0); B_i = w B_i^prev + (1 - w) X\n"
    "// V_j = E_j, or E_j + B_j^prev (flags bit 1: FEEDBACK); V_N = env (the sky E_0).\n"
    "// channel = 3: one table set serves R, G and B. channel = c < 3: this dispatch uses table set c\n"
    "// (MULTIBOUNCE with three tables, sample_base = c k) and reads and writes component c only.\n"
    "// Chunking: binding 1 may hold only this chunk's bins: word w of the tables (bin b starts at word\n"
    "// b * words) is element w - word_base of it (word_base: low 32 bits; a chunk spans < 2^32 words).\n"
    "// PADDED tables (flags bit 2), as RAD_GLSL_ALIAS_BUILD writes them for streamed rows: row i's\n"
    "// bins start at bin row_offsets[i] + i (binding 0 = the input entry offsets) and counts[i]\n"
    "// (binding 7) says how many there are, so the build's output is sampled without compaction.\n"
    "layout(local_size_x_id = 0) in;\n"
    "layout(std430, set = 0, binding = 0) readonly buffer RowOffsets { uvec2 row_offsets[]; }; // rows + 1 uint64, in bins\n"
    "layout(std430, set = 0, binding = 1) readonly buffer Bins { uint bins[]; };              // 2 or 3 words per bin\n"
    "layout(std430, set = 0, binding = 2) readonly buffer Totals { float totals[]; };         // T_i per row\n"
    "layout(std430, set = 0, binding = 3) readonly buffer VectorE { float E[]; };             // 3 N\n"
    "layout(std430, set = 0, binding = 4) readonly buffer Albedo { float rho[]; };            // 3 N (flags bit 0)\n"
    "layout(std430, set = 0, binding = 5) readonly buffer Previous { float Bprev[]; };        // 3 N\n"
    "layout(std430, set = 0, binding = 6) buffer Next { float Bnext[]; };                     // 3 N\n"
    "layout(std430, set = 0, binding = 7) readonly buffer Counts { uint counts[]; };          // bins per row (bit 2)\n"
    "layout(push_constant) uniform Push {\n"
    "    uint seed;        // rad_temporal_options.seed\n"
    "    uint frame;       // rad_temporal_frame() before the step\n"
    "    uint row_offset;  // first row of this dispatch\n"
    "    uint row_count;   // rows in this dispatch\n"
    "    uint n;           // N: the environment's column index\n"
    "    uint samples;     // k\n"
    "    uint words;       // 2 (RAD_ALIAS_COMPACT) or 3 (RAD_ALIAS_WIDE)\n"
    "    uint flags;       // bit 0: multiply by rho (SINGLE, FEEDBACK); bit 1: V = E + B^prev (FEEDBACK); bit 2: PADDED\n"
    "    uint channel;     // 3: RGB from one table set; 0..2: this channel only\n"
    "    uint sample_base; // channel * k with three table sets, else 0\n"
    "    uint word_base;   // low 32 bits of the tables' word index at element 0 of binding 1\n"
    "    float weight;     // w in [0, 1)\n"
    "    float env_r, env_g, env_b; // E_0\n"
    "} pc;\n"
    "\n"
    "uint rad_pcg(uint v)\n"
    "{\n"
    "    uint s = v * 747796405u + 2891336453u;\n"
    "    uint t = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;\n"
    "    return (t >> 22u) ^ t;\n"
    "}\n"
    "\n"
    "float value_at(uint j, uint c)\n"
    "{\n"
    "    if (j >= pc.n) return c == 0u \? pc.env_r : (c == 1u \? pc.env_g : pc.env_b);\n"
    "    float v = E[3u * j + c];\n"
    "    if ((pc.flags & 2u) != 0u) v += Bprev[3u * j + c];\n"
    "    return v;\n"
    "}\n"
    "\n"
    "void main()\n"
    "{\n"
    "    uint r = gl_GlobalInvocationID.x;\n"
    "    if (r >= pc.row_count) return;\n"
    "    uint i = pc.row_offset + r;\n"
    "    uint key = rad_pcg(rad_pcg(rad_pcg(pc.seed) ^ pc.frame) ^ i);\n"
    "    bool padded = (pc.flags & 4u) != 0u;\n"
    "    uint first = row_offsets[i].x + (padded \? i : 0u);\n"
    "    uint nb = padded \? counts[i] : row_offsets[i + 1u].x - row_offsets[i].x;\n"
    "    uint c0 = pc.channel < 3u \? pc.channel : 0u, c1 = pc.channel < 3u \? pc.channel : 2u;\n"
    "    precise float acc[3] = float[3](0.0, 0.0, 0.0);\n"
    "    for (uint s = 0u; s < pc.samples; ++s) {\n"
    "        uint u1 = rad_pcg(key ^ ((pc.sample_base + s) * 0x9E3779B9u));\n";
static const char rad__glsl_4_1[] =
    "        uint u2 = rad_pcg(u1 ^ 0x68E31DA4u);\n"
    "        uint hi, lo;\n"
    "        umulExtended(u1, nb, hi, lo);\n"
    "        uint w = (first + hi) * pc.words - pc.word_base, j;   // wraps correctly: only the difference matters\n"
    "        if (pc.words == 2u) j = u2 < bins[w] \? (bins[w + 1u] & 0xFFFFu) : (bins[w + 1u] >> 16u);\n"
    "        else j = u2 < bins[w] \? bins[w + 1u] : bins[w + 2u];\n"
    "        for (uint c = c0; c <= c1; ++c) acc[c] += value_at(j, c);\n"
    "    }\n"
    "    precise float scale = totals[i] / float(pc.samples);\n"
    "    for (uint c = c0; c <= c1; ++c) {\n"
    "        precise float x = acc[c] * scale;\n"
    "        if ((pc.flags & 1u) != 0u) x *= rho[3u * i + c];\n"
    "        precise float b = pc.weight * Bprev[3u * i + c] + (1.0 - pc.weight) * x;\n"
    "        Bnext[3u * i + c] = b;\n"
    "    }\n"
    "}\n";
static const char *const rad__glsl_pieces_4[] = { rad__glsl_4_0, rad__glsl_4_1 };
static const char rad__glsl_5_0[] =
    "#version 450\n"
    "// radiosity.h kernel RAD_GLSL_MB_APPLY_BLOCKS: the multi-bounce apply from the block-compressed\n"
    "// matrix (rad_multibounce_blocks), as rad_multibounce_blocks_apply: the texture unit decodes the\n"
    "// blocks (texelFetch), each texel is multiplied by its tile's scale, the outliers are added\n"
    "// exactly and the permutations are applied:\n"
    "//   out[row_perm[y]] = sum_x decoded(x, y) * scale(tile of x, y) * E[col_perm[x]]\n"
    "//                      + sum over the outliers of original row row_perm[y] of value * E[column]\n"
    "//                      (+ E[row_perm[y]] when flags bit 0 is set)\n"
    "// for texel rows y = row_offset .. row_offset + row_count - 1 (<= N), RGB. ONE WORKGROUP PER ROW:\n"
    "// dispatch row_count groups; the group strides over the columns (neighbouring invocations fetch\n"
    "// neighbouring texels) and sums in shared memory.\n"
    "// Formats: RAD_BLOCK_BC1 (flags bit 2): one VK_FORMAT_BC1_RGB_UNORM_BLOCK image bound to\n"
    "// bindings 0, 1 and 2 (its .rgb is read from binding 0); RAD_BLOCK_BC4X3: three\n"
    "// VK_FORMAT_BC4_UNORM_BLOCK images (R, G, B planes) at bindings 0, 1, 2 (.r of each). The images\n"
    "// are blocks_per_row * 4 texels square; texel (x, y) is entry (row y, column x).\n"
    "// The outlier arrays are bound whole (they are indexed by original row, which a chunk of\n"
    "// permuted rows does not keep contiguous): with the default 5% of N^2 they fit 128 MiB up to\n"
    "// N of about 14 000.\n"
    "layout(local_size_x_id = 0) in;\n"
    "layout(set = 0, binding = 0) uniform sampler2D texR;   // BC1: the RGB texture; BC4X3: R plane\n"
    "layout(set = 0, binding = 1) uniform sampler2D texG;   // BC4X3: G plane (BC1: any, unused)\n"
    "layout(set = 0, binding = 2) uniform sampler2D texB;   // BC4X3: B plane (BC1: any, unused)\n"
    "layout(std430, set = 0, binding = 3) readonly buffer Scales { float scales[]; };          // 3 per tile\n"
    "layout(std430, set = 0, binding = 4) readonly buffer VectorE { float E[]; };              // 3 N\n"
    "layout(std430, set = 0, binding = 5) readonly buffer ColPerm { uint col_perm[]; };        // N (flags bit 1)\n"
    "layout(std430, set = 0, binding = 6) readonly buffer RowPerm { uint row_perm[]; };        // N (flags bit 1)\n"
    "layout(std430, set = 0, binding = 7) readonly buffer OutlierOffsets { uvec2 out_off[]; }; // N + 1 uint64 (bit 3)\n"
    "layout(std430, set = 0, binding = 8) readonly buffer OutlierColumns { uint out_col[]; };  // (bit 3)\n"
    "layout(std430, set = 0, binding = 9) readonly buffer OutlierValues { float out_val[]; };  // 3 per outlier (bit 3)\n"
    "layout(std430, set = 0, binding = 10) buffer Output { float outv[]; };                    // 3 N\n"
    "layout(push_constant) uniform Push {\n"
    "    uint n;             // N\n"
    "    uint row_offset;    // first texel row of this dispatch\n"
    "    uint row_count;     // rows in this dispatch\n"
    "    uint tile;          // scale tile in texels (0: one scale per channel)\n"
    "    uint tiles_per_row; // ceil(N / tile), 1 when tile is 0\n"
    "    uint flags;         // bit 0: add E; bit 1: permuted; bit 2: BC1 (else BC4X3); bit 3: outliers bound\n"
    "} pc;\n"
    "\n"
    "shared vec3 partial[gl_WorkGroupSize.x];\n"
    "\n"
    "void main()\n"
    "{\n"
    "    uint r = gl_WorkGroupID.x, lid = gl_LocalInvocationID.x;\n"
    "    if (r >= pc.row_count) return;\n"
    "    bool perm = (pc.flags & 2u) != 0u, bc1 = (pc.flags & 4u) != 0u;\n"
    "    uint y = pc.row_offset + r;\n"
    "    uint trow = pc.tile != 0u \? (y / pc.tile) * pc.tiles_per_row : 0u;\n"
    "    precise vec3 acc = vec3(0.0);\n"
    "    for (uint x = lid; x < pc.n; x += gl_WorkGroupSize.x) {\n"
    "        ivec2 p = ivec2(int(x), int(y));\n"
    "        vec3 d = bc1 \? texelFetch(texR, p, 0).rgb\n"
    "                     : vec3(texelFetch(texR, p, 0).r, texelFetch(texG, p, 0).r, texelFetch(texB, p, 0).r);\n"
    "        uint t = 3u * (trow + (pc.tile != 0u \? x / pc.tile : 0u));\n"
    "        uint e = 3u * (perm \? col_perm[x] : x);\n"
    "        acc += (d * vec3(scales[t], scales[t + 1u], scales[t + 2u])) * vec3(E[e], E[e + 1u], E[e + 2u]);\n"
    "    }\n"
    "    uint i = perm \? row_perm[y] : y;\n"
    "    precise vec3 s = vec3(0.0);\n"
    "    if ((pc.flags & 8u) != 0u) {\n"
    "        uint k0 = out_off[i].x, count = out_off[i + 1u].x - k0;\n";
static const char rad__glsl_5_1[] =
    "        for (uint k = k0 + lid; k < k0 + count; k += gl_WorkGroupSize.x) {\n"
    "            uint j = 3u * out_col[k];\n"
    "            s += vec3(out_val[3u * k], out_val[3u * k + 1u], out_val[3u * k + 2u]) * vec3(E[j], E[j + 1u], E[j + 2u]);\n"
    "        }\n"
    "    }\n"
    "    partial[lid] = acc + s;\n"
    "    barrier();\n"
    "    for (uint width = gl_WorkGroupSize.x; width > 1u; ) {\n"
    "        uint h = (width + 1u) / 2u;\n"
    "        if (lid < width - h) partial[lid] += partial[lid + h];\n"
    "        barrier();\n"
    "        width = h;\n"
    "    }\n"
    "    if (lid != 0u) return;\n"
    "    precise vec3 o = partial[0];\n"
    "    if ((pc.flags & 1u) != 0u) o += vec3(E[3u * i], E[3u * i + 1u], E[3u * i + 2u]);\n"
    "    outv[3u * i] = o.x;\n"
    "    outv[3u * i + 1u] = o.y;\n"
    "    outv[3u * i + 2u] = o.z;\n"
    "}\n";
static const char *const rad__glsl_pieces_5[] = { rad__glsl_5_0, rad__glsl_5_1 };
static const char rad__glsl_6_0[] =
    "#version 450\n"
    "// radiosity.h kernel RAD_GLSL_ALIAS_BUILD: alias tables of streamed rows built on the GPU\n"
    "// (docs/methods/temporal.md), the same bins as rad_alias_build_row (Vose's robust variant in double, the\n"
    "// order of operations of the >>api_temporal doc block; bit-identical where double arithmetic is\n"
    "// IEEE, as on lavapipe), one invocation per row.\n"
    "// Input rows in CSR form: row i's entries are k = in_off[i] .. in_off[i+1]-1 (uint64, global), at\n"
    "// element k - entry_base of bindings 1 and 2; flags bit 0 (DENSE): no columns bound, the column\n"
    "// of entry k is k - in_off[i]. Entries <= 0 are skipped; a negative or non-finite entry or a\n"
    "// column >= cols makes the row's bin count 0 (the CPU builder returns INVALID_ARGUMENT).\n"
    "// Output, padded layout: row i gets room for (its entry count + 1) bins starting at bin\n"
    "// in_off[i] + i (bin b at word (b - out_base) * words of binding 3); counts[i] receives the bins\n"
    "// written and totals[i] T_i. Binding 4 (double) and 5 (uint) are scratch of one element per\n"
    "// output bin at the same positions. Needs the shaderFloat64 feature.\n"
    "// RAD_GLSL_TEMPORAL_STEP samples this layout directly (its PADDED flag).\n"
    "layout(local_size_x_id = 0) in;\n"
    "layout(std430, set = 0, binding = 0) readonly buffer RowOffsets { uvec2 in_off[]; }; // rows + 1 uint64\n"
    "layout(std430, set = 0, binding = 1) readonly buffer Columns { uint columns[]; };    // (not DENSE)\n"
    "layout(std430, set = 0, binding = 2) readonly buffer Values { float values[]; };\n"
    "layout(std430, set = 0, binding = 3) buffer Bins { uint bins[]; };                   // 2 or 3 words per bin\n"
    "layout(std430, set = 0, binding = 4) buffer ScratchQ { double q[]; };\n"
    "layout(std430, set = 0, binding = 5) buffer ScratchStack { uint stack[]; };\n"
    "layout(std430, set = 0, binding = 6) buffer Counts { uint counts[]; };               // per row (global index)\n"
    "layout(std430, set = 0, binding = 7) buffer Totals { float totals[]; };              // per row (global index)\n"
    "layout(push_constant) uniform Push {\n"
    "    uint row_offset;  // first row of this dispatch\n"
    "    uint row_count;   // rows in this dispatch\n"
    "    uint cols;        // N: the environment's column (COMPACT needs cols <= 65535)\n"
    "    uint words;       // 2 (RAD_ALIAS_COMPACT) or 3 (RAD_ALIAS_WIDE)\n"
    "    uint entry_base;  // low 32 bits of the entry index at element 0 of bindings 1 and 2\n"
    "    uint out_base;    // low 32 bits of the bin index at element 0 of bindings 3, 4 and 5\n"
    "    uint flags;       // bit 0: DENSE rows (no column array)\n"
    "} pc;\n"
    "\n"
    "void set_bin(uint b, uint threshold, uint col, uint alias_col)\n"
    "{\n"
    "    uint w = b * pc.words;\n"
    "    bins[w] = threshold;\n"
    "    if (pc.words == 2u) bins[w + 1u] = col | (alias_col << 16u);\n"
    "    else { bins[w + 1u] = col; bins[w + 2u] = alias_col; }\n"
    "}\n"
    "\n"
    "uint col_of(uint b) { return pc.words == 2u \? (bins[b * 2u + 1u] & 0xFFFFu) : bins[b * 3u + 1u]; }\n"
    "\n"
    "void main()\n"
    "{\n"
    "    uint r = gl_GlobalInvocationID.x;\n"
    "    if (r >= pc.row_count) return;\n"
    "    uint i = pc.row_offset + r;\n"
    "    uint k0 = in_off[i].x, count = in_off[i + 1u].x - k0;\n"
    "    uint b0 = k0 + i - pc.out_base;          // this row's first bin (local)\n"
    "    bool dense = (pc.flags & 1u) != 0u;\n"
    "    precise double W = 0.0;\n"
    "    uint n = 0u;\n"
    "    for (uint e = 0u; e < count; ++e) {\n"
    "        float v = values[k0 - pc.entry_base + e];\n"
    "        uint col = dense \? e : columns[k0 - pc.entry_base + e];\n"
    "        if (isnan(v) || isinf(v) || v < 0.0 || col >= pc.cols) { counts[i] = 0u; totals[i] = 0.0; return; }\n"
    "        if (v > 0.0) {\n"
    "            q[b0 + n] = double(v);\n"
    "            set_bin(b0 + n, 0xFFFFFFFFu, col, col);\n"
    "            W += double(v);\n"
    "            ++n;\n"
    "        }\n"
    "    }\n"
    "    precise double env = 1.0 - W;\n"
    "    double total = W;\n"
    "    if (env > 0.0) {\n"
    "        q[b0 + n] = env;\n"
    "        set_bin(b0 + n, 0xFFFFFFFFu, pc.cols, pc.cols);\n"
    "        ++n;\n"
    "        total = 1.0;\n"
    "    }\n"
    "    W += env > 0.0 \? env : 0.0;\n"
    "    // Vose, robust variant: Small grows up from stack[0], Large down from stack[n-1]\n"
    "    uint small_top = 0u, large_bottom = n;\n";
static const char rad__glsl_6_1[] =
    "    for (uint b = 0u; b < n; ++b) {\n"
    "        precise double qb = double(n) * q[b0 + b] / W;\n"
    "        q[b0 + b] = qb;\n"
    "        if (qb < 1.0) stack[b0 + small_top++] = b;\n"
    "        else stack[b0 + --large_bottom] = b;\n"
    "    }\n"
    "    while (small_top > 0u && large_bottom < n) {\n"
    "        uint l = stack[b0 + --small_top], g = stack[b0 + large_bottom++];\n"
    "        precise double p = q[b0 + l] * 4294967296.0 + 0.5;\n"
    "        set_bin(b0 + l, p >= 4294967295.0 \? 0xFFFFFFFFu : uint(p), col_of(b0 + l), col_of(b0 + g));\n"
    "        precise double qg = (q[b0 + g] + q[b0 + l]) - 1.0;\n"
    "        q[b0 + g] = qg;\n"
    "        if (qg < 1.0) stack[b0 + small_top++] = g;\n"
    "        else stack[b0 + --large_bottom] = g;\n"
    "    }\n"
    "    counts[i] = n;\n"
    "    totals[i] = float(total);\n"
    "}\n";
static const char *const rad__glsl_pieces_6[] = { rad__glsl_6_0, rad__glsl_6_1 };
static const char rad__glsl_7_0[] =
    "// lighting.glsl - the lighting models and BRDF terms of radiosity.h (docs/methods/shading.md, >>shading),\n"
    "// GLSL 450. An include: no #version; it defines only functions and one struct, all named\n"
    "// as their C counterparts (rad_ndf_ggx ...). The arithmetic is written in the same order as\n"
    "// the C code so the results agree to float rounding (tests/test_shading_vulkan.c checks\n"
    "// 1e-5 relative). Conventions (l, v, n unit; f the BRDF; R = f * max(n.l, 0) the response)\n"
    "// are those of the >>api_shading comment in radiosity.h.\n"
    "//\n"
    "// Including it: either with GL_GOOGLE_include_directive (as glsl/lighting_eval.comp does:\n"
    "// glslangValidator resolves it relative to the including file), or by pasting this file's\n"
    "// text after your #version line.\n"
    "#ifndef RAD_LIGHTING_GLSL\n"
    "#define RAD_LIGHTING_GLSL\n"
    "\n"
    "#define RAD_SHADING_LAMBERT 0\n"
    "#define RAD_SHADING_HALF_LAMBERT 1\n"
    "#define RAD_SHADING_BANDED 2\n"
    "#define RAD_SHADING_PHONG 3\n"
    "#define RAD_SHADING_BLINN_PHONG 4\n"
    "#define RAD_SHADING_MINNAERT 5\n"
    "#define RAD_SHADING_OREN_NAYAR 6\n"
    "#define RAD_SHADING_MICROFACET 7\n"
    "#define RAD_NDF_BECKMANN 0\n"
    "#define RAD_NDF_GGX 1\n"
    "#define RAD_MASKING_SEPARABLE 0\n"
    "#define RAD_MASKING_HEIGHT_CORRELATED 1\n"
    "#define RAD_DIFFUSE_NONE 0\n"
    "#define RAD_DIFFUSE_LAMBERT 1\n"
    "#define RAD_DIFFUSE_SHIRLEY 2\n"
    "\n"
    "const float RAD_PI = 3.14159265358979323846;\n"
    "const float RAD_INV_PI = 0.318309886183790671537767526745;\n"
    "\n"
    "// The std430 mirror of rad_shading_gpu (96 bytes), filled by rad_shading_pack():\n"
    "// albedo (or kd), specular (ks), f0, f90, p = (alpha_x, alpha_y, wrap / shininess / k / sigma,\n"
    "// half-Lambert exponent / bands / Fresnel exponent), mode = (model, ndf, masking, diffuse).\n"
    "struct RadShadingParams {\n"
    "    vec4 albedo;\n"
    "    vec4 specular;\n"
    "    vec4 f0;\n"
    "    vec4 f90;\n"
    "    vec4 p;\n"
    "    ivec4 mode;\n"
    "};\n"
    "\n"
    "// Beckmann NDF\n"
    "float rad_ndf_beckmann(float nm, float alpha)\n"
    "{\n"
    "    float a2 = alpha * alpha, c2 = nm * nm;\n"
    "    if (!(nm > 0.0)) return 0.0;\n"
    "    return exp((c2 - 1.0) / (a2 * c2)) / (RAD_PI * a2 * c2 * c2);\n"
    "}\n"
    "\n"
    "// Beckmann NDF, anisotropic\n"
    "float rad_ndf_beckmann_aniso(float nm, float tm, float bm, float alpha_x, float alpha_y)\n"
    "{\n"
    "    float c2 = nm * nm;\n"
    "    if (!(nm > 0.0)) return 0.0;\n"
    "    float e = (tm * tm / (alpha_x * alpha_x) + bm * bm / (alpha_y * alpha_y)) / c2;\n"
    "    return exp(-e) / (RAD_PI * alpha_x * alpha_y * c2 * c2);\n"
    "}\n"
    "\n"
    "// GGX NDF (Walter et al. 2007)\n"
    "float rad_ndf_ggx(float nm, float alpha)\n"
    "{\n"
    "    float a2 = alpha * alpha;\n"
    "    if (!(nm > 0.0)) return 0.0;\n"
    "    float d = 1.0 + nm * nm * (a2 - 1.0);\n"
    "    return a2 / (RAD_PI * d * d);\n"
    "}\n"
    "\n"
    "// GGX NDF, anisotropic\n"
    "float rad_ndf_ggx_aniso(float nm, float tm, float bm, float alpha_x, float alpha_y)\n"
    "{\n"
    "    if (!(nm > 0.0)) return 0.0;\n"
    "    float d = tm * tm / (alpha_x * alpha_x) + bm * bm / (alpha_y * alpha_y) + nm * nm;\n"
    "    return 1.0 / (RAD_PI * alpha_x * alpha_y * d * d);\n"
    "}\n"
    "\n"
    "// the Smith variable a (anisotropic; the isotropic form when alpha_x = alpha_y); the largest float for\n"
    "// s = n (C returns +inf there; both give Lambda = 0)\n"
    "float rad_smith_a(float ns, float ts, float bs, float alpha_x, float alpha_y)\n"
    "{\n"
    "    float d2 = alpha_x * alpha_x * ts * ts + alpha_y * alpha_y * bs * bs;\n"
    "    if (!(d2 > 0.0)) return 3.402823466e38;\n"
    "    return ns / sqrt(d2);\n"
    "}\n"
    "\n"
    "// Lambda of GGX (exact), for a > 0\n"
    "// (Beckmann's exact Lambda needs erf, which GLSL lacks: it is C only.)\n"
    "float rad_lambda_ggx(float a)\n"
    "{\n"
    "    return 0.5 * (-1.0 + sqrt(1.0 + 1.0 / (a * a)));\n"
    "}\n"
    "\n"
    "// Lambda of Beckmann, rational approximation (Walter et al. 2007)\n"
    "float rad_lambda_beckmann(float a)\n"
    "{\n"
    "    if (!(a < 1.6)) return 0.0;\n"
    "    return (1.0 - 1.259 * a + 0.396 * a * a) / (3.535 * a + 2.181 * a * a);\n"
    "}\n"
    "\n"
    "// Smith G1 (Heitz 2014)\n"
    "float rad_smith_g1(float ms, float lambda_s) { return ms > 0.0 \? 1.0 / (1.0 + lambda_s) : 0.0; }\n"
    "\n"
    "// Smith G2, separable and height-correlated (Heitz 2014)\n"
    "float rad_smith_g2_separable(float mv, float ml, float lambda_v, float lambda_l)\n"
    "{\n"
    "    return (mv > 0.0 && ml > 0.0) \? 1.0 / ((1.0 + lambda_v) * (1.0 + lambda_l)) : 0.0;\n"
    "}\n"
    "\n";
static const char rad__glsl_7_1[] =
    "float rad_smith_g2_height_correlated(float mv, float ml, float lambda_v, float lambda_l)\n"
    "{\n"
    "    return (mv > 0.0 && ml > 0.0) \? 1.0 / (1.0 + lambda_v + lambda_l) : 0.0;\n"
    "}\n"
    "\n"
    "// Schlick's Fresnel and its generalized F90 form (one channel)\n"
    "float rad_fresnel_schlick(float f0, float c)\n"
    "{\n"
    "    float x = 1.0 - (c > 0.0 \? c : 0.0), x2 = x * x;\n"
    "    return f0 + (1.0 - f0) * (x2 * x2 * x);\n"
    "}\n"
    "\n"
    "float rad_fresnel_schlick_f90(float f0, float f90, float exponent, float c)\n"
    "{\n"
    "    return f0 + (f90 - f0) * pow(1.0 - (c > 0.0 \? c : 0.0), exponent);\n"
    "}\n"
    "\n"
    "// diffuse terms: Lambert (1 - F) and Shirley et al. 1997 (one channel)\n"
    "float rad_diffuse_lambert(float albedo, float F) { return (1.0 - F) * albedo * RAD_INV_PI; }\n"
    "\n"
    "float rad_diffuse_shirley(float albedo, float f0, float nl, float nv)\n"
    "{\n"
    "    float a = 1.0 - (nl > 0.0 \? nl : 0.0), b = 1.0 - (nv > 0.0 \? nv : 0.0);\n"
    "    float a5 = a * a * a * a * a, b5 = b * b * b * b * b;\n"
    "    return (1.0 - f0) * (21.0 / 20.0) * albedo * RAD_INV_PI * (1.0 - a5) * (1.0 - b5);\n"
    "}\n"
    "\n"
    "// Lambda from n.s, t.s, b.s without forming a (no division by zero at s = n)\n"
    "float rad_shading_lambda(int ndf, bool iso, float ns, float ts, float bs, float ax, float ay)\n"
    "{\n"
    "    float d2 = iso \? ax * ax * (1.0 - ns * ns) : ax * ax * ts * ts + ay * ay * bs * bs;\n"
    "    if (!(d2 > 0.0)) return 0.0;\n"
    "    if (ndf == RAD_NDF_GGX) return 0.5 * (-1.0 + sqrt(1.0 + d2 / (ns * ns)));\n"
    "    return rad_lambda_beckmann(ns / sqrt(d2));\n"
    "}\n"
    "\n"
    "// f (out_f) and R (return value) for unit l, v, n and an orthonormal t, b (anything when the\n"
    "// model is isotropic). f is 0 for half-Lambert, which has no BRDF.\n"
    "vec3 rad_shade(RadShadingParams g, vec3 l, vec3 v, vec3 n, vec3 t, vec3 b, out vec3 out_f)\n"
    "{\n"
    "    float nl = dot(n, l), nv = dot(n, v);\n"
    "    vec3 f = vec3(0.0), rr = vec3(0.0);\n"
    "    int model = g.mode.x;\n"
    "    if (nv > 0.0) {\n"
    "        if (model == RAD_SHADING_HALF_LAMBERT) {\n"
    "            float x = (nl + g.p.z) / (1.0 + g.p.z);\n"
    "            float q = pow(x > 0.0 \? x : 0.0, g.p.w);\n"
    "            rr = g.albedo.xyz * RAD_INV_PI * q;\n"
    "        } else if (nl > 0.0) {\n"
    "            if (model == RAD_SHADING_LAMBERT) {\n"
    "                f = g.albedo.xyz * RAD_INV_PI;\n"
    "            } else if (model == RAD_SHADING_BANDED) {\n"
    "                float q = ceil(g.p.w * nl) / g.p.w / nl;\n"
    "                f = g.albedo.xyz * RAD_INV_PI * q;\n"
    "            } else if (model == RAD_SHADING_PHONG) {\n"
    "                vec3 r = 2.0 * nl * n - l;\n"
    "                float rv = dot(r, v), s = g.p.z;\n"
    "                float q = (s + 2.0) * (0.5 * RAD_INV_PI) * pow(rv > 0.0 \? rv : 0.0, s);\n"
    "                f = g.albedo.xyz * RAD_INV_PI + g.specular.xyz * q;\n"
    "            } else if (model == RAD_SHADING_BLINN_PHONG) {\n"
    "                vec3 h = l + v;\n"
    "                float len = sqrt(dot(h, h)), nh = 0.0, s = g.p.z;\n"
    "                if (len > 0.0) nh = dot(n, h) / len;\n"
    "                float q = (s + 2.0) * (s + 4.0) * (0.125 * RAD_INV_PI) / (exp2(-0.5 * s) + s) * pow(nh > 0.0 \? nh : 0.0, s);\n"
    "                f = g.albedo.xyz * RAD_INV_PI + g.specular.xyz * q;\n"
    "            } else if (model == RAD_SHADING_MINNAERT) {\n"
    "                float kk = g.p.z, c = nl * nv;\n"
    "                float q = (kk + 1.0) * (0.5 * RAD_INV_PI) * pow(c > 1e-6 \? c : 1e-6, kk - 1.0);\n"
    "                f = g.albedo.xyz * q;\n"
    "            } else if (model == RAD_SHADING_OREN_NAYAR) {\n"
    "                float s2 = g.p.z * g.p.z, A = 1.0 - 0.5 * s2 / (s2 + 0.33), B = 0.45 * s2 / (s2 + 0.09);\n"
    "                float s = dot(l, v) - nl * nv, q = s > 0.0 \? s / (nl > nv \? nl : nv) : 0.0;\n"
    "                f = g.albedo.xyz * RAD_INV_PI * (A + B * q);\n"
    "            } else if (model == RAD_SHADING_MICROFACET) {\n"
    "                float ax = g.p.x, ay = g.p.y;\n"
    "                bool iso = ax == ay;\n"
    "                int ndf = g.mode.y;\n"
    "                vec3 h = l + v;\n"
    "                float len = sqrt(dot(h, h));\n"
    "                if (len > 0.0) {\n"
    "                    h /= len;\n"
    "                    float nh = dot(n, h), lh = dot(l, h), vh = dot(v, h), D;\n"
    "                    if (iso) {\n";
static const char rad__glsl_7_2[] =
    "                        D = ndf == RAD_NDF_GGX \? rad_ndf_ggx(nh, ax) : rad_ndf_beckmann(nh, ax);\n"
    "                    } else {\n"
    "                        float th = dot(t, h), bh = dot(b, h);\n"
    "                        D = ndf == RAD_NDF_GGX \? rad_ndf_ggx_aniso(nh, th, bh, ax, ay)\n"
    "                                               : rad_ndf_beckmann_aniso(nh, th, bh, ax, ay);\n"
    "                    }\n"
    "                    float lv = rad_shading_lambda(ndf, iso, nv, iso \? 0.0 : dot(t, v), iso \? 0.0 : dot(b, v), ax, ay);\n"
    "                    float ll = rad_shading_lambda(ndf, iso, nl, iso \? 0.0 : dot(t, l), iso \? 0.0 : dot(b, l), ax, ay);\n"
    "                    float G = g.mode.z == RAD_MASKING_SEPARABLE \? rad_smith_g2_separable(vh, lh, lv, ll)\n"
    "                                                               : rad_smith_g2_height_correlated(vh, lh, lv, ll);\n"
    "                    float sp = G * D / (4.0 * nl * nv);\n"
    "                    for (int k = 0; k < 3; ++k) f[k] = rad_fresnel_schlick_f90(g.f0[k], g.f90[k], g.p.w, lh) * sp;\n"
    "                }\n"
    "                for (int k = 0; k < 3; ++k) {\n"
    "                    if (g.mode.w == RAD_DIFFUSE_LAMBERT)\n"
    "                        f[k] += rad_diffuse_lambert(g.albedo[k], rad_fresnel_schlick_f90(g.f0[k], g.f90[k], g.p.w, nl));\n"
    "                    else if (g.mode.w == RAD_DIFFUSE_SHIRLEY)\n"
    "                        f[k] += rad_diffuse_shirley(g.albedo[k], g.f0[k], nl, nv);\n"
    "                }\n"
    "            }\n"
    "            rr = f * nl;\n"
    "        }\n"
    "    }\n"
    "    out_f = f;\n"
    "    return rr;\n"
    "}\n"
    "\n"
    "#endif\n";
static const char *const rad__glsl_pieces_7[] = { rad__glsl_7_0, rad__glsl_7_1, rad__glsl_7_2 };
static const char rad__glsl_8_0[] =
    "#version 450\n"
    "// radiosity.h kernel RAD_GLSL_LOCAL_APPLY: the local multi-bounce apply of rad_local_apply\n"
    "// (docs/methods/local.md): for every visible entry r = row_offset .. row_offset + row_count - 1,\n"
    "// with slot i = vis_slot[r] and world patch p = vis_patch[r],\n"
    "//   out[p] = sum_{j < end, lit_patch[j] != NONE} T_c[i][j] * E[lit_patch[j]]   (+ E[p] when flags bit 0)\n"
    "// for channels c = R, G, B. T is rad_local.planes: three M x M planes, row = receiving slot,\n"
    "// stride m. ONE WORKGROUP PER VISIBLE ENTRY: dispatch row_count groups; the group strides over\n"
    "// the columns j < end and sums in shared memory.\n"
    "// Chunking: bindings 0..2 may hold only plane rows slot_offset .. slot_offset + slot_count - 1\n"
    "// (row i at element base + (i - slot_offset) * m); an entry whose slot lies outside them is\n"
    "// skipped, so one dispatch per chunk over the whole visible list (or over the part of a list\n"
    "// sorted by slot that falls in the chunk) covers every row.\n"
    "layout(local_size_x_id = 0) in;\n"
    "layout(std430, set = 0, binding = 0) readonly buffer PlaneR { float R[]; };\n"
    "layout(std430, set = 0, binding = 1) readonly buffer PlaneG { float G[]; };\n"
    "layout(std430, set = 0, binding = 2) readonly buffer PlaneB { float B[]; };\n"
    "layout(std430, set = 0, binding = 3) readonly buffer VectorE { float E[]; };        // 3 n, world order\n"
    "layout(std430, set = 0, binding = 4) readonly buffer LitPatch { uint lit_patch[]; }; // end: patch of slot j, or ~0u\n"
    "layout(std430, set = 0, binding = 5) readonly buffer VisSlot { uint vis_slot[]; };   // visible entries: slots\n"
    "layout(std430, set = 0, binding = 6) readonly buffer VisPatch { uint vis_patch[]; }; // visible entries: patches\n"
    "layout(std430, set = 0, binding = 7) buffer Output { float outv[]; };               // 3 n, world order\n"
    "layout(push_constant) uniform Push {\n"
    "    uint m;            // M: rad_local.capacity, the plane stride\n"
    "    uint end;          // rad_local.slot_end: columns j < end\n"
    "    uint row_offset;   // first visible entry of this dispatch\n"
    "    uint row_count;    // visible entries in this dispatch (= workgroups)\n"
    "    uint slot_offset;  // first plane row held by bindings 0..2\n"
    "    uint slot_count;   // plane rows held by bindings 0..2\n"
    "    uint base;         // element of bindings 0..2 that holds plane row slot_offset, column 0\n"
    "    uint flags;        // bit 0: add E (RAD_OUTPUT_TOTAL)\n"
    "} pc;\n"
    "\n"
    "shared vec3 partial[gl_WorkGroupSize.x];\n"
    "\n"
    "void main()\n"
    "{\n"
    "    uint r = gl_WorkGroupID.x, lid = gl_LocalInvocationID.x;\n"
    "    if (r >= pc.row_count) return;                    // the whole group: barriers stay uniform\n"
    "    uint i = vis_slot[pc.row_offset + r];\n"
    "    if (i < pc.slot_offset || i - pc.slot_offset >= pc.slot_count) return; // another chunk's row\n"
    "    uint at = pc.base + (i - pc.slot_offset) * pc.m;\n"
    "    precise vec3 acc = vec3(0.0);\n"
    "    for (uint j = lid; j < pc.end; j += gl_WorkGroupSize.x) {\n"
    "        uint p = lit_patch[j];\n"
    "        if (p == 0xFFFFFFFFu) continue;\n"
    "        acc += vec3(R[at + j], G[at + j], B[at + j]) * vec3(E[3u * p], E[3u * p + 1u], E[3u * p + 2u]);\n"
    "    }\n"
    "    partial[lid] = acc;\n"
    "    barrier();\n"
    "    for (uint width = gl_WorkGroupSize.x; width > 1u; ) {\n"
    "        uint h = (width + 1u) / 2u;\n"
    "        if (lid < width - h) partial[lid] += partial[lid + h];\n"
    "        barrier();\n"
    "        width = h;\n"
    "    }\n"
    "    if (lid != 0u) return;\n"
    "    uint o = 3u * vis_patch[pc.row_offset + r];\n"
    "    precise vec3 s = partial[0];\n"
    "    if ((pc.flags & 1u) != 0u) s += vec3(E[o], E[o + 1u], E[o + 2u]);\n"
    "    outv[o] = s.x;\n"
    "    outv[o + 1u] = s.y;\n"
    "    outv[o + 2u] = s.z;\n"
    "}\n";
static const char *const rad__glsl_pieces_8[] = { rad__glsl_8_0 };
static const char rad__glsl_9_0[] =
    "#version 450\n"
    "// radiosity.h kernel RAD_GLSL_LOCAL_VECTORS: the small pre-pass of a local-matrix add\n"
    "// (rad_local_add, docs/methods/local.md) computed from T resident on the GPU: the vectors u, v and the scalar\n"
    "// s of the Sherman-Morrison update (fused with the exact downdate of slot ev when an add evicts),\n"
    "// which RAD_GLSL_LOCAL_UPDATE then applies. T is rad_local.planes (three M x M planes, stride m,\n"
    "// row = receiving slot). The host streams only the new patch's row and column over the slots:\n"
    "//   a_c[j] = rho_c[patch(j)] * A_n F_nj / A_j (column by reciprocity), b_c[j] = rho_c[n] * F_nj\n"
    "// for member slots j != ev (zero elsewhere; channel-major, a[c * m + j]), nz = the slots with a\n"
    "// non-zero F_nj (any order), ann_c = rho_c[n] F_nn. Work buffer (binding 6), channel c at c * 4m:\n"
    "//   u[j] at +j, v[j] at +m + j, c[j] = T[j][ev] at +2m + j, r[j] = T[ev][j] at +3m + j;\n"
    "//   then 12 scalars at 12m: s[3], cuv[3] (rank-1 factor), coef[3] (new row/column factor), tnn[3].\n"
    "// Passes (push 'pass'), run in this order, each one dispatch (or one per row chunk for pass 0):\n"
    "//   0  GATHER, row-chunked: ONE INVOCATION PER ITEM, max(row_count, end) invocations.\n"
    "//      Invocation x as row i = row_offset + x: u[i] = a[i] + sum_p T[i][nz_p] a[nz_p], c[i] = T[i][ev];\n"
    "//      as column j = x < end: v[j] (=, flags bit 0 on the first chunk; else +=) b[j] +\n"
    "//      sum over nz_p in the chunk of b[nz_p] T[nz_p][j]; r[j] = T[ev][j] when ev is in the chunk.\n"
    "//   1  EVICT (only when ev != ~0u), end invocations, reads no plane: with g = 1 + r[ev],\n"
    "//      u[i] -= c[i] (r.a) / g, v[i] -= (b.c) r[i] / g, u[ev] = v[ev] = 0.\n"
    "//   2  SCALARS, 3 invocations (one per channel): s = 1 - ann - b.u, and the factors:\n"
    "//      exact (flags bit 1 clear): cuv = coef = 1/s, tnn = 1/s - 1 (as (ann + b.u) / s); first order (bit 1 set,\n"
    "//      RAD_LOCAL_FIRST_ORDER): d = ann + b.a, coef = 1 + d, cuv = (1 + d)^2, tnn = d.\n"
    "// Float arithmetic (the CPU accumulates u, v, s in double): within 1e-5 relative of rad_local_add\n"
    "// for the tested sets. A kernel cannot fail: s <= 1e-12 (rows that break energy conservation)\n"
    "// makes RAD_GLSL_LOCAL_UPDATE leave T unchanged; read s back to detect it.\n"
    "layout(local_size_x_id = 0) in;\n"
    "layout(std430, set = 0, binding = 0) readonly buffer PlaneR { float R[]; };\n"
    "layout(std430, set = 0, binding = 1) readonly buffer PlaneG { float G[]; };\n"
    "layout(std430, set = 0, binding = 2) readonly buffer PlaneB { float B[]; };\n"
    "layout(std430, set = 0, binding = 3) readonly buffer VecA { float a[]; };   // 3 m, channel-major\n"
    "layout(std430, set = 0, binding = 4) readonly buffer VecB { float b[]; };   // 3 m, channel-major\n"
    "layout(std430, set = 0, binding = 5) readonly buffer NonZero { uint nz[]; }; // nnz slots\n"
    "layout(std430, set = 0, binding = 6) buffer Work { float w[]; };            // 12 m + 12\n"
    "layout(push_constant) uniform Push {\n"
    "    uint m;            // M: rad_local.capacity, the plane stride\n"
    "    uint end;          // slots in use after the add: max(new slot + 1, rad_local.slot_end)\n"
    "    uint row_offset;   // pass 0: first plane row held by bindings 0..2\n"
    "    uint row_count;    // pass 0: plane rows held by bindings 0..2 (row_offset + row_count <= end)\n"
    "    uint base;         // pass 0: element of bindings 0..2 that holds plane row row_offset, column 0\n"
    "    uint nnz;          // entries of nz\n"
    "    uint ev;           // the slot evicted by this add, or 0xFFFFFFFF\n"
    "    uint pass;         // 0, 1, 2 (see above)\n"
    "    uint flags;        // bit 0: first chunk of pass 0 (v = b + ...); bit 1: first-order update\n"
    "    float ann_r, ann_g, ann_b; // rho_n F_nn per channel\n"
    "} pc;\n"
    "\n"
    "float plane(uint c, uint e) { return c == 0u \? R[e] : c == 1u \? G[e] : B[e]; }\n"
    "\n"
    "void main()\n"
    "{\n"
    "    uint x = gl_GlobalInvocationID.x, m = pc.m, c;\n"
    "    bool evict = pc.ev != 0xFFFFFFFFu;\n"
    "    if (pc.pass == 0u) {\n"
    "        if (x < pc.row_count) { // row i of the chunk\n"
    "            uint i = pc.row_offset + x, at = pc.base + x * m;\n"
    "            for (c = 0u; c < 3u; ++c) {\n";
static const char rad__glsl_9_1[] =
    "                precise float acc = a[c * m + i];\n"
    "                for (uint p = 0u; p < pc.nnz; ++p) acc += plane(c, at + nz[p]) * a[c * m + nz[p]];\n"
    "                w[c * 4u * m + i] = acc;\n"
    "                w[c * 4u * m + 2u * m + i] = (evict && i != pc.ev) \? plane(c, at + pc.ev) : 0.0;\n"
    "            }\n"
    "        }\n"
    "        if (x < pc.end) { // column j\n"
    "            uint j = x;\n"
    "            bool ev_here = evict && pc.ev >= pc.row_offset && pc.ev - pc.row_offset < pc.row_count;\n"
    "            for (c = 0u; c < 3u; ++c) {\n"
    "                precise float acc = (pc.flags & 1u) != 0u \? b[c * m + j] : w[c * 4u * m + m + j];\n"
    "                for (uint p = 0u; p < pc.nnz; ++p) {\n"
    "                    uint r = nz[p];\n"
    "                    if (r >= pc.row_offset && r - pc.row_offset < pc.row_count)\n"
    "                        acc += b[c * m + r] * plane(c, pc.base + (r - pc.row_offset) * m + j);\n"
    "                }\n"
    "                w[c * 4u * m + m + j] = acc;\n"
    "                if (ev_here) w[c * 4u * m + 3u * m + j] = plane(c, pc.base + (pc.ev - pc.row_offset) * m + j);\n"
    "            }\n"
    "        }\n"
    "    } else if (pc.pass == 1u) {\n"
    "        if (x >= pc.end || !evict) return;\n"
    "        for (c = 0u; c < 3u; ++c) {\n"
    "            uint o = c * 4u * m;\n"
    "            float g = 1.0 + w[o + 3u * m + pc.ev];\n"
    "            precise float ra = 0.0, bc = 0.0;  // r.a and b.c (a and b are zero at ev)\n"
    "            for (uint p = 0u; p < pc.nnz; ++p) {\n"
    "                uint j = nz[p];\n"
    "                ra += w[o + 3u * m + j] * a[c * m + j];\n"
    "                bc += b[c * m + j] * w[o + 2u * m + j];\n"
    "            }\n"
    "            if (x == pc.ev) {\n"
    "                w[o + x] = 0.0;\n"
    "                w[o + m + x] = 0.0;\n"
    "            } else {\n"
    "                w[o + x] -= w[o + 2u * m + x] * (ra / g);\n"
    "                w[o + m + x] -= (bc / g) * w[o + 3u * m + x];\n"
    "            }\n"
    "        }\n"
    "    } else if (pc.pass == 2u) {\n"
    "        if (x >= 3u) return;\n"
    "        c = x;\n"
    "        precise float bu = 0.0, ba = 0.0;\n"
    "        for (uint p = 0u; p < pc.nnz; ++p) {\n"
    "            uint j = nz[p];\n"
    "            bu += b[c * m + j] * w[c * 4u * m + j];\n"
    "            ba += b[c * m + j] * a[c * m + j];\n"
    "        }\n"
    "        float ann = c == 0u \? pc.ann_r : c == 1u \? pc.ann_g : pc.ann_b;\n"
    "        precise float q = ann + bu, s = 1.0 - q; // q: no cancellation\n"
    "        uint o = 12u * m;\n"
    "        w[o + c] = s;\n"
    "        if ((pc.flags & 2u) == 0u) {\n"
    "            w[o + 3u + c] = 1.0 / s;\n"
    "            w[o + 6u + c] = 1.0 / s;\n"
    "            w[o + 9u + c] = q / s;                 // 1/s - 1 without its cancellation\n"
    "        } else {\n"
    "            precise float d = ann + ba;\n"
    "            w[o + 3u + c] = (1.0 + d) * (1.0 + d);\n"
    "            w[o + 6u + c] = 1.0 + d;\n"
    "            w[o + 9u + c] = d;\n"
    "        }\n"
    "    }\n"
    "}\n";
static const char *const rad__glsl_pieces_9[] = { rad__glsl_9_0, rad__glsl_9_1 };
static const char rad__glsl_10_0[] =
    "#version 450\n"
    "// radiosity.h kernel RAD_GLSL_LOCAL_UPDATE: the O(M^2) pass of a local-matrix add\n"
    "// (rad_local_add, docs/methods/local.md) on T resident on the GPU, after RAD_GLSL_LOCAL_VECTORS filled the work\n"
    "// buffer (its comment has the layout: u, v, c, r per channel and the scalars s, cuv, coef, tnn).\n"
    "// For plane rows i = row_offset .. row_offset + row_count - 1 (all < end), channels R, G, B:\n"
    "//   i == k (the new patch's slot):  T[k][j] = coef v[j] (j != k), T[k][k] = tnn\n"
    "//   else: T[i][j] += cuv u[i] v[j] - c[i] r[j] / g   (j < end, j != k; the second term only when\n"
    "//         an add evicts slot ev = k, g = 1 + r[ev]: the exact downdate fused into a rank-2 pass)\n"
    "//         T[i][k] = coef u[i]\n"
    "// which is rad_local_add's update, new row and new column; with the factors of the first-order\n"
    "// form when RAD_GLSL_LOCAL_VECTORS ran with it. Nothing is written when some channel has\n"
    "// s <= 1e-12 (the CPU returns RAD_ERROR_SINGULAR and leaves T unchanged). Rows and columns >= end\n"
    "// are not touched. ONE WORKGROUP PER ROW: dispatch row_count groups; the group strides over j.\n"
    "// Chunking: bindings 0..2 may hold only this chunk's rows, row i at element base + (i - row_offset) * m.\n"
    "layout(local_size_x_id = 0) in;\n"
    "layout(std430, set = 0, binding = 0) buffer PlaneR { float R[]; };\n"
    "layout(std430, set = 0, binding = 1) buffer PlaneG { float G[]; };\n"
    "layout(std430, set = 0, binding = 2) buffer PlaneB { float B[]; };\n"
    "layout(std430, set = 0, binding = 3) readonly buffer Work { float w[]; }; // 12 m + 12, from LOCAL_VECTORS\n"
    "layout(push_constant) uniform Push {\n"
    "    uint m;            // M: rad_local.capacity, the plane stride\n"
    "    uint end;          // slots in use after the add (as given to RAD_GLSL_LOCAL_VECTORS)\n"
    "    uint row_offset;   // first plane row of this dispatch\n"
    "    uint row_count;    // rows in this dispatch (= workgroups)\n"
    "    uint base;         // element of bindings 0..2 that holds plane row row_offset, column 0\n"
    "    uint k;            // the new patch's slot\n"
    "    uint ev;           // the slot evicted by this add (then ev == k), or 0xFFFFFFFF\n"
    "} pc;\n"
    "\n"
    "void update(uint c, uint at, uint i)\n"
    "{\n"
    "    uint m = pc.m, o = c * 4u * m, s = 12u * m, lid = gl_LocalInvocationID.x;\n"
    "    float cuv = w[s + 3u + c], coef = w[s + 6u + c];\n"
    "    if (i == pc.k) {\n"
    "        for (uint j = lid; j < pc.end; j += gl_WorkGroupSize.x) {\n"
    "            precise float t = j == pc.k \? w[s + 9u + c] : coef * w[o + m + j];\n"
    "            if (c == 0u) R[at + j] = t; else if (c == 1u) G[at + j] = t; else B[at + j] = t;\n"
    "        }\n"
    "        return;\n"
    "    }\n"
    "    precise float ui = cuv * w[o + i];\n"
    "    precise float ci = pc.ev != 0xFFFFFFFFu \? -w[o + 2u * m + i] / (1.0 + w[o + 3u * m + pc.ev]) : 0.0;\n"
    "    for (uint j = lid; j < pc.end; j += gl_WorkGroupSize.x) {\n"
    "        precise float t;\n"
    "        if (j == pc.k) t = coef * w[o + i];\n"
    "        else {\n"
    "            t = c == 0u \? R[at + j] : c == 1u \? G[at + j] : B[at + j];\n"
    "            if (ui != 0.0 || ci != 0.0) t += ci * w[o + 3u * m + j] + ui * w[o + m + j];\n"
    "        }\n"
    "        if (c == 0u) R[at + j] = t; else if (c == 1u) G[at + j] = t; else B[at + j] = t;\n"
    "    }\n"
    "}\n"
    "\n"
    "void main()\n"
    "{\n"
    "    uint r = gl_WorkGroupID.x;\n"
    "    if (r >= pc.row_count) return;\n"
    "    uint s = 12u * pc.m;\n"
    "    for (uint c = 0u; c < 3u; ++c)\n"
    "        if (!(w[s + c] > 1e-12)) return; // singular: T stays as it was\n"
    "    uint at = pc.base + r * pc.m, i = pc.row_offset + r;\n"
    "    for (uint c = 0u; c < 3u; ++c) update(c, at, i);\n"
    "}\n";
static const char *const rad__glsl_pieces_10[] = { rad__glsl_10_0 };
static const char rad__glsl_11_0[] =
    "#version 450\n"
    "// radiosity.h kernel RAD_GLSL_VP_GATHER: virtual-patch gathering at surface points, as\n"
    "// rad_vp_gather / rad_vp_gather_point (docs/methods/virtual-patches.md). For point i with unit\n"
    "// normal n: in each voxel v of the 2x2x2 block around p (by voxel centres; the grid coordinate\n"
    "// x = (p - origin) / voxel_size - 1/2 clamped to [-2, dims + 1], base = floor(x), g = x - base),\n"
    "//   L(v) = sum_a w_a x_a / sum_a w_a over v's patches a with w_a > 0\n"
    "// (axis-aligned: w_a the split weights of n, max(0, +-n_k)^2 or max(0, +-n_k) normalized to\n"
    "// sum 1 (flags bit 0: cosine); clustered, flags bit 1: w_a = N_a . n); voxels outside the grid,\n"
    "// empty or with no patch facing n are skipped, and\n"
    "//   out_i = sum_v t_v L(v) / sum_v t_v       (t_v the trilinear weights; 0 when no voxel is used;\n"
    "//   the plain mean of the used L(v) when their t_v sum to 0)\n"
    "// ONE INVOCATION PER POINT: dispatch ceil(row_count / size) groups for the points\n"
    "// row_offset .. row_offset + row_count - 1. Chunking: bindings 0, 1 and 6 may hold only this\n"
    "// chunk's points, point i at elements base + 3 (i - row_offset) .. + 2 of each (bind the three at\n"
    "// the same element offset). Voxel keys are the uint64 rad_virtual_patches.voxel_keys (ascending,\n"
    "// ix + dims0 (iy + dims1 iz)), read as uvec2 (low word first) and found by binary search.\n"
    "layout(local_size_x_id = 0) in;\n"
    "layout(std430, set = 0, binding = 0) readonly buffer Points { float P[]; };       // 3 per point\n"
    "layout(std430, set = 0, binding = 1) readonly buffer Normals { float Nrm[]; };    // 3 per point, unit\n"
    "layout(std430, set = 0, binding = 2) readonly buffer Values { float X[]; };       // 3 N, per patch\n"
    "layout(std430, set = 0, binding = 3) readonly buffer VoxelKeys { uvec2 keys[]; }; // voxel_count uint64\n"
    "layout(std430, set = 0, binding = 4) readonly buffer VoxelPatch { uint vpatch[]; }; // 6 per voxel, or ~0u\n"
    "layout(std430, set = 0, binding = 5) readonly buffer PatchNormals { float PN[]; }; // 3 N (clustered only)\n"
    "layout(std430, set = 0, binding = 6) buffer Output { float outv[]; };             // 3 per point\n"
    "layout(push_constant) uniform Push {\n"
    "    float origin_x, origin_y, origin_z;   // rad_virtual_patches.origin\n"
    "    float size_x, size_y, size_z;         // .voxel_size\n"
    "    uint dims_x, dims_y, dims_z;          // .dims\n"
    "    uint voxel_count;                     // .voxel_count\n"
    "    uint row_offset;                      // first point of this dispatch\n"
    "    uint row_count;                       // points in this dispatch\n"
    "    uint base;                            // element of bindings 0, 1, 6 holding point row_offset\n"
    "    uint flags;                           // bit 0: cosine split weights; bit 1: clustered\n"
    "} pc;\n"
    "\n"
    "uvec2 mul64(uint a, uvec2 b) { uint hi, lo; umulExtended(a, b.x, hi, lo); return uvec2(lo, hi + a * b.y); }\n"
    "uvec2 add64(uvec2 a, uint b) { uint c; uint lo = uaddCarry(a.x, b, c); return uvec2(lo, a.y + c); }\n"
    "bool less64(uvec2 a, uvec2 b) { return a.y < b.y || (a.y == b.y && a.x < b.x); }\n"
    "\n"
    "uint find_voxel(uvec2 key)\n"
    "{\n"
    "    uint lo = 0u, hi = pc.voxel_count;\n"
    "    while (lo < hi) {\n"
    "        uint mid = lo + (hi - lo) / 2u;\n"
    "        if (less64(keys[mid], key)) lo = mid + 1u; else hi = mid;\n"
    "    }\n"
    "    return lo < pc.voxel_count && keys[lo] == key \? lo : 0xFFFFFFFFu;\n"
    "}\n"
    "\n"
    "// a + b exactly, as the pair (sum, error) (Knuth's TwoSum)\n"
    "vec2 two_sum(float a, float b)\n"
    "{\n"
    "    precise float s = a + b;\n"
    "    precise float bb = s - a;\n"
    "    precise float e = (a - (s - bb)) + (b - bb);\n"
    "    return vec2(s, e);\n"
    "}\n"
    "// a * b exactly, as the pair (product, error) (Dekker, Veltkamp's split; no fma needed)\n"
    "vec2 two_prod(float a, float b)\n"
    "{\n"
    "    precise float ca = 4097.0 * a, cb = 4097.0 * b;\n"
    "    precise float ah = ca - (ca - a), bh = cb - (cb - b);\n"
    "    precise float al = a - ah, bl = b - bh;\n"
    "    precise float q = a * b;\n"
    "    precise float e = ((ah * bh - q) + ah * bl + al * bh) + al * bl;\n"
    "    return vec2(q, e);\n"
    "}\n"
    "// (p - o) / s - 1/2 as an unevaluated float pair (hi, lo), to about 1e-14 relative\n";
static const char rad__glsl_11_1[] =
    "vec2 grid_coordinate(float p, float o, float s)\n"
    "{\n"
    "    vec2 d = two_sum(p, -o);                      // p - o exactly\n"
    "    precise float q = d.x / s;\n"
    "    vec2 qs = two_prod(q, s);\n"
    "    precise float r = ((d.x - qs.x) - qs.y) + d.y; // the remainder d - q s\n"
    "    precise float ql = r / s;\n"
    "    vec2 x = two_sum(q, -0.5);\n"
    "    precise float lo = x.y + ql;\n"
    "    return vec2(x.x, lo);\n"
    "}\n"
    "\n"
    "void main()\n"
    "{\n"
    "    uint r = gl_GlobalInvocationID.x;\n"
    "    if (r >= pc.row_count) return;\n"
    "    uint at = pc.base + 3u * r;\n"
    "    vec3 p = vec3(P[at], P[at + 1u], P[at + 2u]), n = vec3(Nrm[at], Nrm[at + 1u], Nrm[at + 2u]);\n"
    "    vec3 origin = vec3(pc.origin_x, pc.origin_y, pc.origin_z), size = vec3(pc.size_x, pc.size_y, pc.size_z);\n"
    "    uvec3 dims = uvec3(pc.dims_x, pc.dims_y, pc.dims_z);\n"
    "    bool clustered = (pc.flags & 2u) != 0u;\n"
    "    // the split weights of n (+x, -x, +y, -y, +z, -z)\n"
    "    vec3 wp = max(n, vec3(0.0)), wm = max(-n, vec3(0.0));\n"
    "    if ((pc.flags & 1u) == 0u) { wp *= wp; wm *= wm; }\n"
    "    float wsum = wp.x + wm.x + wp.y + wm.y + wp.z + wm.z;\n"
    "    float w[6] = float[6](wp.x, wm.x, wp.y, wm.y, wp.z, wm.z);\n"
    "    if (wsum > 0.0) for (int a = 0; a < 6; ++a) w[a] /= wsum;\n"
    "    // the grid coordinate as a float pair (the CPU computes it in double: a float x would carry\n"
    "    // an absolute error of about 1e-7 dims, large against the small trilinear weights)\n"
    "    ivec3 b;\n"
    "    vec3 g0, g1;\n"
    "    for (int k = 0; k < 3; ++k) {\n"
    "        vec2 x = grid_coordinate(p[k], origin[k], size[k]);\n"
    "        float top = float(dims[k]) + 1.0;\n"
    "        if (x.x < -2.0 || (x.x == -2.0 && x.y < 0.0)) x = vec2(-2.0, 0.0);\n"
    "        if (x.x > top || (x.x == top && x.y > 0.0)) x = vec2(top, 0.0);\n"
    "        float fb = floor(x.x);\n"
    "        precise float f = x.x - fb;             // exact\n"
    "        if (f + x.y < 0.0) fb -= 1.0; else if (f + x.y >= 1.0) fb += 1.0;\n"
    "        f = x.x - fb;\n"
    "        b[k] = int(fb);\n"
    "        g1[k] = f + x.y;                        // the weight of the upper cell, g\n"
    "        g0[k] = (1.0 - f) - x.y;                // 1 - g, from the pair: no cancellation near g = 1\n"
    "    }\n"
    "    precise vec3 acc = vec3(0.0), facc = vec3(0.0);\n"
    "    precise float tsum = 0.0;\n"
    "    uint used = 0u;\n"
    "    for (uint corner = 0u; corner < 8u; ++corner) {\n"
    "        ivec3 bit = ivec3(int(corner & 1u), int((corner >> 1) & 1u), int((corner >> 2) & 1u));\n"
    "        ivec3 cell = b + bit;\n"
    "        if (any(lessThan(cell, ivec3(0))) || any(greaterThanEqual(uvec3(cell), dims))) continue;\n"
    "        vec3 tt = mix(g0, g1, vec3(bit));\n"
    "        float t = tt.x * tt.y * tt.z;\n"
    "        uvec2 key = add64(mul64(dims.x, add64(mul64(dims.y, uvec2(uint(cell.z), 0u)), uint(cell.y))), uint(cell.x));\n"
    "        uint v = find_voxel(key);\n"
    "        if (v == 0xFFFFFFFFu) continue;\n"
    "        precise vec3 L = vec3(0.0);\n"
    "        precise float ws = 0.0;\n"
    "        for (uint a = 0u; a < 6u; ++a) {\n"
    "            uint q = vpatch[6u * v + a];\n"
    "            if (q == 0xFFFFFFFFu) continue;\n"
    "            float wa = clustered \? dot(vec3(PN[3u * q], PN[3u * q + 1u], PN[3u * q + 2u]), n) : w[a];\n"
    "            if (!(wa > 0.0)) continue;\n"
    "            ws += wa;\n"
    "            L += wa * vec3(X[3u * q], X[3u * q + 1u], X[3u * q + 2u]);\n"
    "        }\n"
    "        if (!(ws > 0.0)) continue; // nothing in this voxel faces n\n"
    "        used++;\n"
    "        acc += t * L / ws;\n"
    "        facc += L / ws;\n"
    "        tsum += t;\n"
    "    }\n"
    "    vec3 o = used == 0u \? vec3(0.0) : (tsum > 0.0 \? acc / tsum : facc / float(used));\n"
    "    outv[at] = o.x;\n"
    "    outv[at + 1u] = o.y;\n"
    "    outv[at + 2u] = o.z;\n"
    "}\n";
static const char *const rad__glsl_pieces_11[] = { rad__glsl_11_0, rad__glsl_11_1 };
static const rad__glsl_entry rad__glsl_table[RAD_GLSL_COUNT] = {
    { "gather_dense.comp", rad__glsl_pieces_0, 1u, 2494u },
    { "gather_csr.comp", rad__glsl_pieces_1, 1u, 2706u },
    { "mb_apply_float.comp", rad__glsl_pieces_2, 1u, 2780u },
    { "mb_apply_half.comp", rad__glsl_pieces_3, 1u, 2666u },
    { "temporal_step.comp", rad__glsl_pieces_4, 2u, 4728u },
    { "mb_apply_blocks.comp", rad__glsl_pieces_5, 2u, 4704u },
    { "alias_build.comp", rad__glsl_pieces_6, 2u, 4700u },
    { "lighting.glsl", rad__glsl_pieces_7, 3u, 9441u },
    { "local_apply.comp", rad__glsl_pieces_8, 1u, 3519u },
    { "local_vectors.comp", rad__glsl_pieces_9, 2u, 6673u },
    { "local_update.comp", rad__glsl_pieces_10, 1u, 3425u },
    { "vp_gather.comp", rad__glsl_pieces_11, 2u, 7417u }
};
/* >>glsl end */

RAD_API const char *rad_glsl_name(rad_glsl_id id)
{
    if ((unsigned)id >= (unsigned)RAD_GLSL_COUNT) return NULL;
    return rad__glsl_table[id].name;
}

RAD_API const char *const *rad_glsl_pieces(rad_glsl_id id, uint32_t *out_count)
{
    if ((unsigned)id >= (unsigned)RAD_GLSL_COUNT) {
        if (out_count) *out_count = 0;
        return NULL;
    }
    if (out_count) *out_count = rad__glsl_table[id].count;
    return rad__glsl_table[id].pieces;
}

RAD_API rad_result rad_glsl_source(rad_glsl_id id, char *dst, size_t dst_size, size_t *out_length)
{
    const rad__glsl_entry *e;
    uint32_t p;
    size_t at = 0;
    if ((unsigned)id >= (unsigned)RAD_GLSL_COUNT || (!dst && !out_length)) return RAD_ERROR_INVALID_ARGUMENT;
    e = &rad__glsl_table[id];
    if (out_length) *out_length = e->length;
    if (!dst) return dst_size == 0 ? RAD_SUCCESS : RAD_ERROR_INVALID_ARGUMENT;
    if (dst_size <= e->length) return RAD_ERROR_SIZE_MISMATCH;
    for (p = 0; p < e->count; ++p) {
        size_t n = strlen(e->pieces[p]);
        memcpy(dst + at, e->pieces[p], n);
        at += n;
    }
    RAD_ASSERT(at == e->length);
    dst[at] = '\0';
    return RAD_SUCCESS;
}

/* ======================================================================================== */
/* >>multibounce: multi-bounce matrix, GEMM, binary16, BC1/BC4, compression, container      */
/* ======================================================================================== */

#if defined(RAD__AVX) && defined(__AVX2__)
#  define RAD__MB_AVX2 1
#endif
#if defined(RAD__AVX) && defined(__FMA__)
#  define RAD__MB_FMA 1
#endif
#if defined(RAD__AVX) && defined(__F16C__)
#  define RAD__MB_F16C 1
#endif

#if defined(RAD__MB_FMA)
#  define RAD__MB_MADD(a, b, c) _mm256_fmadd_ps(a, b, c)
#  define RAD__MB_MADD4(a, b, c) _mm_fmadd_ps(a, b, c)
#else
#  define RAD__MB_MADD(a, b, c) _mm256_add_ps(c, _mm256_mul_ps(a, b))
#  define RAD__MB_MADD4(a, b, c) _mm_add_ps(c, _mm_mul_ps(a, b))
#endif

#define RAD__MB_MR 6u
#define RAD__MB_NR 16u
#define RAD__MB_KC 256u
#define RAD__MB_MC 96u
#define RAD__MB_NC 2048u

/* ---- binary16 ---- */

RAD_API uint16_t rad_half_from_float(float value)
{
    uint32_t x, sign, h;
    memcpy(&x, &value, sizeof(x));
    sign = (x >> 16) & 0x8000u;
    x &= 0x7FFFFFFFu;
    if (x > 0x7F800000u) return (uint16_t)(sign | 0x7E00u | ((x >> 13) & 0x3FFu)); /* NaN stays NaN */
    if (x >= 0x477FF000u) return (uint16_t)(sign | 0x7C00u);                     /* >= 65520: infinity */
    if (x < 0x38800000u) {                                                         /* below 2^-14: subnormal */
        uint32_t mant, shift, rem, half;
        if (x < 0x33000000u) return (uint16_t)sign;                                /* <= 2^-25: zero */
        mant = (x & 0x7FFFFFu) | 0x800000u;
        shift = 126u - (x >> 23);                                                  /* 14..24 */
        h = mant >> shift;
        rem = mant & ((1u << shift) - 1u);
        half = 1u << (shift - 1u);
        if (rem > half || (rem == half && (h & 1u))) ++h;
        return (uint16_t)(sign | h);
    }
    h = (x - 0x38000000u) >> 13;                                                   /* rebias 127 -> 15 */
    if ((x & 0x1FFFu) > 0x1000u || ((x & 0x1FFFu) == 0x1000u && (h & 1u))) ++h;    /* carries into the exponent */
    return (uint16_t)(sign | h);
}

RAD_API float rad_half_to_float(uint16_t value)
{
    uint32_t sign = ((uint32_t)value & 0x8000u) << 16, e = ((uint32_t)value >> 10) & 31u, m = (uint32_t)value & 0x3FFu, x;
    float f;
    if (e == 0) {
        f = (float)m * 5.9604644775390625e-8f; /* m * 2^-24, exact */
        return sign ? -f : f;
    }
    x = sign | (e == 31u ? 0x7F800000u | (m << 13) : ((e + 112u) << 23) | (m << 13));
    memcpy(&f, &x, sizeof(f));
    return f;
}

/* ---- objects ---- */

RAD_API void rad_multibounce_options_default(rad_multibounce_options *o)
{
    if (!o) return;
    memset(o, 0, sizeof(*o));
    o->bounces = 3;
    o->precision = RAD_MB_FLOAT;
    o->tolerance = 1e-8;
    o->max_doublings = 40;
}

RAD_API void rad_block_options_default(rad_block_options *o)
{
    if (!o) return;
    memset(o, 0, sizeof(*o));
    o->format = RAD_BLOCK_BC4X3;
    o->outlier_fraction = 0.05f;
    o->reorder = RAD_REORDER_MATCH;
    o->reorder_samples = 0;
    o->tile = 64;
}

RAD_API void rad_multibounce_destroy(rad_multibounce *mb)
{
    rad_allocator a;
    if (!mb) return;
    a = mb->allocator;
    rad__free(&a, mb->storage);
    rad__free(&a, mb);
}

RAD_API void rad_multibounce_blocks_destroy(rad_multibounce_blocks *b)
{
    rad_allocator a;
    if (!b) return;
    a = b->allocator;
    rad__free(&a, b->storage);
    rad__free(&a, b);
}

/* One allocation holding 'parts' arrays of the given byte sizes, each 64-byte aligned. */
static void *rad__mb_carve(const rad__ctx *c, const size_t *bytes, uint32_t parts, void **out_parts, rad_result *r)
{
    size_t total = 0, at;
    uint32_t i;
    unsigned char *base;
    for (i = 0; i < parts; ++i) {
        size_t b = (bytes[i] + 63u) & ~(size_t)63u;
        if (b < bytes[i] || total + b < total || total + b + 64u < total) { *r = RAD_ERROR_SIZE_OVERFLOW; return NULL; }
        total += b;
    }
    base = (unsigned char *)rad__alloc(&c->allocator, total + 64u);
    if (!base) { *r = RAD_ERROR_OUT_OF_MEMORY; return NULL; }
    at = (size_t)((64u - ((uintptr_t)base & 63u)) & 63u);
    for (i = 0; i < parts; ++i) {
        out_parts[i] = bytes[i] ? (void *)(base + at) : NULL;
        at += (bytes[i] + 63u) & ~(size_t)63u;
    }
    *r = RAD_SUCCESS;
    return base;
}

static void rad__mb_info(uint32_t *info, uint32_t kind, uint32_t n, uint32_t k, uint32_t tile, uint32_t tiles, uint32_t flags)
{
    memset(info, 0, 16 * sizeof(uint32_t));
    info[0] = 1u;
    info[1] = kind;
    info[2] = n;
    info[3] = k;
    info[4] = tile;
    info[5] = tiles;
    info[6] = flags;
}

/* ---- GEMM: C (m x n) += A (m x k) B (k x n), row-major, packed and cache-blocked ---- */

typedef struct rad__gemm {
    const float *A, *B;
    float *C;
    size_t lda, ldb, ldc;
    uint32_t m, n, k;
    uint32_t pc, kc, jc, nc;
    const float *bp;   /* packed B block: ceil(nc/NR) panels of kc x NR */
    float *ap;         /* packed A: one MC x KC slab per row chunk */
} rad__gemm;

static void rad__mb_kernel(uint32_t kc, const float *a, const float *b, float *c, size_t ldc, uint32_t mr, uint32_t nr)
{
    uint32_t i, j, p;
#if defined(RAD__AVX)
    __m256 c0[RAD__MB_MR], c1[RAD__MB_MR];
    float tmp[RAD__MB_MR][RAD__MB_NR];
    for (i = 0; i < RAD__MB_MR; ++i) { c0[i] = _mm256_setzero_ps(); c1[i] = _mm256_setzero_ps(); }
    for (p = 0; p < kc; ++p) {
        __m256 b0 = _mm256_loadu_ps(b + (size_t)p * RAD__MB_NR), b1 = _mm256_loadu_ps(b + (size_t)p * RAD__MB_NR + 8);
        const float *ap = a + (size_t)p * RAD__MB_MR;
        for (i = 0; i < RAD__MB_MR; ++i) {
            __m256 av = _mm256_broadcast_ss(ap + i);
#if defined(RAD__MB_FMA)
            c0[i] = _mm256_fmadd_ps(av, b0, c0[i]);
            c1[i] = _mm256_fmadd_ps(av, b1, c1[i]);
#else
            c0[i] = _mm256_add_ps(c0[i], _mm256_mul_ps(av, b0));
            c1[i] = _mm256_add_ps(c1[i], _mm256_mul_ps(av, b1));
#endif
        }
    }
    if (mr == RAD__MB_MR && nr == RAD__MB_NR) {
        for (i = 0; i < RAD__MB_MR; ++i) {
            float *ci = c + (size_t)i * ldc;
            _mm256_storeu_ps(ci, _mm256_add_ps(_mm256_loadu_ps(ci), c0[i]));
            _mm256_storeu_ps(ci + 8, _mm256_add_ps(_mm256_loadu_ps(ci + 8), c1[i]));
        }
        return;
    }
    for (i = 0; i < RAD__MB_MR; ++i) { _mm256_storeu_ps(tmp[i], c0[i]); _mm256_storeu_ps(tmp[i] + 8, c1[i]); }
#else
    float tmp[RAD__MB_MR][RAD__MB_NR];
    memset(tmp, 0, sizeof(tmp));
    for (p = 0; p < kc; ++p) {
        const float *ap = a + (size_t)p * RAD__MB_MR, *bq = b + (size_t)p * RAD__MB_NR;
        for (i = 0; i < RAD__MB_MR; ++i) {
            float av = ap[i];
            for (j = 0; j < RAD__MB_NR; ++j) tmp[i][j] += av * bq[j];
        }
    }
#endif
    for (i = 0; i < mr; ++i)
        for (j = 0; j < nr; ++j) c[(size_t)i * ldc + j] += tmp[i][j];
}

static void rad__gemm_task(void *data, uint32_t t)
{
    const rad__gemm *g = (const rad__gemm *)data;
    uint32_t ic = t * RAD__MB_MC, mc = g->m - ic < RAD__MB_MC ? g->m - ic : RAD__MB_MC, q, p, i, kk;
    float *ap = g->ap + (size_t)t * RAD__MB_MC * RAD__MB_KC;
    uint32_t panels_a = (mc + RAD__MB_MR - 1) / RAD__MB_MR, panels_b = (g->nc + RAD__MB_NR - 1) / RAD__MB_NR;
    for (q = 0; q < panels_a; ++q)
        for (kk = 0; kk < g->kc; ++kk)
            for (i = 0; i < RAD__MB_MR; ++i) {
                uint32_t row = q * RAD__MB_MR + i;
                ap[((size_t)q * g->kc + kk) * RAD__MB_MR + i] = row < mc ? g->A[(size_t)(ic + row) * g->lda + g->pc + kk] : 0.0f;
            }
    for (p = 0; p < panels_b; ++p) {
        uint32_t nr = g->nc - p * RAD__MB_NR < RAD__MB_NR ? g->nc - p * RAD__MB_NR : RAD__MB_NR;
        for (q = 0; q < panels_a; ++q) {
            uint32_t mr = mc - q * RAD__MB_MR < RAD__MB_MR ? mc - q * RAD__MB_MR : RAD__MB_MR;
            rad__mb_kernel(g->kc, ap + (size_t)q * g->kc * RAD__MB_MR, g->bp + (size_t)p * g->kc * RAD__MB_NR,
                           g->C + (size_t)(ic + q * RAD__MB_MR) * g->ldc + g->jc + p * RAD__MB_NR, g->ldc, mr, nr);
        }
    }
}

/* C += A B. The summation order of every entry is fixed (k blocks in order), so the bits do
   not depend on the number of tasks. */
static rad_result rad__mb_gemm(const rad__ctx *c, uint32_t m, uint32_t n, uint32_t k, const float *A, size_t lda,
                               const float *B, size_t ldb, float *C, size_t ldc)
{
    rad__gemm g;
    float *bp, *ap;
    uint32_t chunks = (m + RAD__MB_MC - 1) / RAD__MB_MC, jc, pc;
    size_t bp_count = (size_t)RAD__MB_KC * (RAD__MB_NC + RAD__MB_NR), ap_count;
    if (m == 0 || n == 0 || k == 0) return RAD_SUCCESS;
    if (!rad__mul((size_t)chunks, (size_t)RAD__MB_MC * RAD__MB_KC, &ap_count)) return RAD_ERROR_SIZE_OVERFLOW;
    bp = (float *)rad__alloc_array(&c->allocator, bp_count, sizeof(float));
    ap = (float *)rad__alloc_array(&c->allocator, ap_count, sizeof(float));
    if (!bp || !ap) { rad__free(&c->allocator, bp); rad__free(&c->allocator, ap); return RAD_ERROR_OUT_OF_MEMORY; }
    g.A = A; g.B = B; g.C = C; g.lda = lda; g.ldb = ldb; g.ldc = ldc; g.m = m; g.n = n; g.k = k;
    g.bp = bp; g.ap = ap;
    for (jc = 0; jc < n; jc += RAD__MB_NC) {
        g.jc = jc;
        g.nc = n - jc < RAD__MB_NC ? n - jc : RAD__MB_NC;
        for (pc = 0; pc < k; pc += RAD__MB_KC) {
            uint32_t panels = (g.nc + RAD__MB_NR - 1) / RAD__MB_NR, p, kk, j;
            g.pc = pc;
            g.kc = k - pc < RAD__MB_KC ? k - pc : RAD__MB_KC;
            for (p = 0; p < panels; ++p)
                for (kk = 0; kk < g.kc; ++kk) {
                    float *dst = bp + ((size_t)p * g.kc + kk) * RAD__MB_NR;
                    const float *src = B + (size_t)(pc + kk) * ldb + jc + p * RAD__MB_NR;
                    uint32_t cols = g.nc - p * RAD__MB_NR < RAD__MB_NR ? g.nc - p * RAD__MB_NR : RAD__MB_NR;
                    for (j = 0; j < cols; ++j) dst[j] = src[j];
                    for (; j < RAD__MB_NR; ++j) dst[j] = 0.0f;
                }
            c->parallel_for(c->parallel_user, chunks, rad__gemm_task, &g);
        }
    }
    rad__free(&c->allocator, bp);
    rad__free(&c->allocator, ap);
    return RAD_SUCCESS;
}

/* ---- building F_mb ---- */

static double rad__mb_max_row_sum(const float *M, uint32_t n)
{
    double best = 0.0;
    uint32_t i, j;
    for (i = 0; i < n; ++i) {
        double s = 0.0;
        const float *row = M + (size_t)i * n;
        for (j = 0; j < n; ++j) s += fabs((double)row[j]);
        if (s > best) best = s;
    }
    return best;
}

typedef struct rad__mb_build {
    const rad__ctx *c;
    uint32_t n, products, total;
    size_t nn;
} rad__mb_build;

/* dst = add (or 0) + X Y */
static rad_result rad__mb_product(rad__mb_build *b, float *dst, const float *add, const float *X, const float *Y)
{
    rad_result r;
    if (add) memcpy(dst, add, b->nn * sizeof(float));
    else memset(dst, 0, b->nn * sizeof(float));
    r = rad__mb_gemm(b->c, b->n, b->n, b->n, X, b->n, Y, b->n, dst, b->n);
    if (r != RAD_SUCCESS) return r;
    ++b->products;
    if (b->c->progress && b->c->progress(b->c->progress_user, b->total ? (float)b->products / (float)b->total : 0.5f))
        return RAD_ERROR_CANCELLED;
    return RAD_SUCCESS;
}

/* S = sum_{k=1..K} A^k into out (A, s, t, p, q are n*n scratch; A holds rho o F) */
static rad_result rad__mb_series(rad__mb_build *b, uint32_t K, double tol, uint32_t max_doublings, float *A, float *s,
                                 float *t, float *p, float *q, float *out)
{
    float *S = s, *T = t, *P = A, *Q = p, *R = q, *swap;
    rad_result r = RAD_SUCCESS;
    int bit = 31;
    memcpy(S, A, b->nn * sizeof(float));
    if (K == RAD_MB_INFINITE) {
        uint32_t d = 0;
        while (rad__mb_max_row_sum(P, b->n) > tol) {
            if (d++ >= max_doublings) {
                rad__log(b->c, RAD_LOG_ERROR, "multibounce: ||(rho o F)^m|| still above %g after %u doublings", tol, max_doublings);
                return RAD_ERROR_NOT_CONVERGED;
            }
            r = rad__mb_product(b, T, S, P, S);                      /* S_2m = S_m + A^m S_m */
            if (r != RAD_SUCCESS) return r;
            swap = S; S = T; T = swap;
            r = rad__mb_product(b, Q, NULL, P, P);                   /* A^2m */
            if (r != RAD_SUCCESS) return r;
            swap = P; P = Q; Q = (swap == A) ? R : swap;
        }
    } else {
        while (bit > 0 && !((K >> bit) & 1u)) --bit;
        for (--bit; bit >= 0; --bit) {
            int more = bit > 0;
            r = rad__mb_product(b, T, S, P, S);                      /* S_2m = S_m + A^m S_m */
            if (r != RAD_SUCCESS) return r;
            swap = S; S = T; T = swap;
            if (more) {
                r = rad__mb_product(b, Q, NULL, P, P);               /* A^2m */
                if (r != RAD_SUCCESS) return r;
                swap = P; P = Q; Q = (swap == A) ? R : swap;
            }
            if ((K >> bit) & 1u) {
                r = rad__mb_product(b, T, A, A, S);                  /* S_m+1 = A + A S_m */
                if (r != RAD_SUCCESS) return r;
                swap = S; S = T; T = swap;
                if (more) {
                    r = rad__mb_product(b, Q, NULL, A, P);           /* A^m+1 */
                    if (r != RAD_SUCCESS) return r;
                    swap = P; P = Q; Q = swap;
                }
            }
        }
    }
    memcpy(out, S, b->nn * sizeof(float));
    return RAD_SUCCESS;
}

static uint32_t rad__mb_products(uint32_t K)
{
    uint32_t n = 0;
    int bit = 31;
    if (K == RAD_MB_INFINITE) return 0;
    while (bit > 0 && !((K >> bit) & 1u)) --bit;
    for (--bit; bit >= 0; --bit) n += (bit > 0 ? 2u : 1u) + (((K >> bit) & 1u) ? (bit > 0 ? 2u : 1u) : 0u);
    return n;
}

RAD_API rad_result rad_multibounce_create(const rad_matrix *F, const float *albedo, const rad_multibounce_options *options,
                                          const rad_context *ctx, rad_multibounce **out)
{
    rad__ctx c;
    rad_multibounce_options o;
    rad_multibounce *mb = NULL;
    rad__mb_build b;
    float *scratch = NULL, *planes = NULL;
    size_t nn, bytes[1];
    void *parts[1];
    uint32_t n, ch, i, j;
    rad_result r;
    rad__ctx_init(&c, ctx);
    if (!out) return RAD_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    r = rad__check_matrix(F, &c);
    if (r == RAD_ERROR_CORRUPT) return r;
    if (r != RAD_SUCCESS || !albedo) return RAD_ERROR_INVALID_ARGUMENT;
    if (options) o = *options; else rad_multibounce_options_default(&o);
    if (o.bounces == 0 || (o.precision != RAD_MB_FLOAT && o.precision != RAD_MB_HALF) || !(o.tolerance >= 0.0)) {
        rad__log(&c, RAD_LOG_ERROR, "multibounce: bounces must be >= 1 (or RAD_MB_INFINITE), precision float or half");
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    if (o.tolerance == 0.0) o.tolerance = 1e-8;
    if (o.max_doublings == 0) o.max_doublings = 40;
    n = F->rows;
    if (n == 0 || F->cols != n) {
        rad__log(&c, RAD_LOG_ERROR, "multibounce: the matrix is %u x %u, not square", F->rows, F->cols);
        return n == 0 ? RAD_ERROR_INVALID_ARGUMENT : RAD_ERROR_SIZE_MISMATCH;
    }
    for (i = 0; i < 3 * n; ++i)
        if (!(albedo[i] >= 0.0f && albedo[i] < 1.0f)) {
            rad__log(&c, RAD_LOG_ERROR, "multibounce: albedo %g of patch %u is outside [0,1)", (double)albedo[i], i / 3u);
            return RAD_ERROR_ALBEDO_RANGE;
        }
    if (!rad__mul((size_t)n, (size_t)n, &nn) || !rad__mul3(nn, 3, sizeof(float), &bytes[0])) return RAD_ERROR_SIZE_OVERFLOW;
    mb = (rad_multibounce *)rad__alloc(&c.allocator, sizeof(*mb));
    if (!mb) return RAD_ERROR_OUT_OF_MEMORY;
    memset(mb, 0, sizeof(*mb)); /* before anything can fail: the fail path destroys it */
    mb->allocator = c.allocator;
    scratch = (float *)rad__alloc_array(&c.allocator, nn, 5 * sizeof(float));
    if (!scratch) { r = RAD_ERROR_OUT_OF_MEMORY; goto fail; }
    mb->storage = rad__mb_carve(&c, bytes, 1, parts, &r);
    if (!mb->storage) goto fail;
    planes = (float *)parts[0];
    b.c = &c; b.n = n; b.nn = nn; b.products = 0;
    b.total = 3u * rad__mb_products(o.bounces);
    for (ch = 0; ch < 3; ++ch) {
        float *A = scratch;
        for (i = 0; i < n; ++i) {
            float rho = albedo[3 * (size_t)i + ch], *row = A + (size_t)i * n;
            if (F->storage == RAD_STORAGE_DENSE) {
                const float *fr = F->dense + (size_t)i * n;
                for (j = 0; j < n; ++j) row[j] = rho * fr[j];
            } else {
                uint64_t q;
                memset(row, 0, (size_t)n * sizeof(float));
                for (q = F->row_offsets[i]; q < F->row_offsets[i + 1]; ++q)
                    if (F->columns[q] < n) row[F->columns[q]] = rho * F->values[q];
            }
        }
        r = rad__mb_series(&b, o.bounces, o.tolerance, o.max_doublings, A, scratch + nn, scratch + 2 * nn, scratch + 3 * nn,
                           scratch + 4 * nn, planes + (size_t)ch * nn);
        if (r != RAD_SUCCESS) goto fail;
    }
    rad__free(&c.allocator, scratch);
    scratch = NULL;
    mb->n = n;
    mb->bounces = o.bounces;
    mb->precision = RAD_MB_FLOAT;
    mb->planes = planes;
    rad__mb_info(mb->info, 0u, n, o.bounces, 0u, 0u, 0u);
    if (o.precision == RAD_MB_HALF) {
        rad_multibounce *h = NULL;
        r = rad_multibounce_convert(mb, RAD_MB_HALF, ctx, &h);
        rad_multibounce_destroy(mb);
        if (r != RAD_SUCCESS) return r;
        mb = h;
    }
    *out = mb;
    return RAD_SUCCESS;
fail:
    rad__free(&c.allocator, scratch);
    rad_multibounce_destroy(mb);
    return r;
}

/* a new object of n, k, precision, with room for permutations when perms */
static rad_result rad__mb_new(const rad__ctx *c, uint32_t n, uint32_t k, rad_mb_precision precision, int perms,
                              rad_multibounce **out)
{
    rad_multibounce *mb;
    size_t nn, bytes[3];
    void *parts[3];
    rad_result r;
    if (!rad__mul((size_t)n, (size_t)n, &nn) || !rad__mul3(nn, 3, precision == RAD_MB_HALF ? 2u : 4u, &bytes[0]))
        return RAD_ERROR_SIZE_OVERFLOW;
    bytes[1] = bytes[2] = perms ? (size_t)n * sizeof(uint32_t) : 0;
    mb = (rad_multibounce *)rad__alloc(&c->allocator, sizeof(*mb));
    if (!mb) return RAD_ERROR_OUT_OF_MEMORY;
    memset(mb, 0, sizeof(*mb));
    mb->allocator = c->allocator;
    mb->storage = rad__mb_carve(c, bytes, 3, parts, &r);
    if (!mb->storage) { rad__free(&c->allocator, mb); return r; }
    mb->n = n;
    mb->bounces = k;
    mb->precision = precision;
    if (precision == RAD_MB_HALF) mb->half = (const uint16_t *)parts[0];
    else mb->planes = (const float *)parts[0];
    mb->row_perm = (const uint32_t *)parts[1];
    mb->col_perm = (const uint32_t *)parts[2];
    rad__mb_info(mb->info, precision == RAD_MB_HALF ? 1u : 0u, n, k, 0u, 0u, perms ? 1u : 0u);
    *out = mb;
    return RAD_SUCCESS;
}

static rad_result rad__mb_check(const rad_multibounce *mb)
{
    if (!mb || mb->n == 0) return RAD_ERROR_INVALID_ARGUMENT;
    if (mb->precision == RAD_MB_FLOAT ? !mb->planes : (mb->precision != RAD_MB_HALF || !mb->half)) return RAD_ERROR_INVALID_ARGUMENT;
    if ((mb->row_perm == NULL) != (mb->col_perm == NULL)) return RAD_ERROR_INVALID_ARGUMENT;
    return RAD_SUCCESS;
}

RAD_API rad_result rad_multibounce_convert(const rad_multibounce *src, rad_mb_precision precision, const rad_context *ctx,
                                           rad_multibounce **out)
{
    rad__ctx c;
    rad_multibounce *mb = NULL;
    size_t i, total;
    rad_result r;
    rad__ctx_init(&c, ctx);
    if (!out) return RAD_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    if (rad__mb_check(src) != RAD_SUCCESS || (precision != RAD_MB_FLOAT && precision != RAD_MB_HALF)) return RAD_ERROR_INVALID_ARGUMENT;
    r = rad__mb_new(&c, src->n, src->bounces, precision, src->row_perm != NULL, &mb);
    if (r != RAD_SUCCESS) return r;
    total = 3 * (size_t)src->n * src->n;
    if (precision == RAD_MB_HALF) {
        uint16_t *h = (uint16_t *)mb->half;
        for (i = 0; i < total; ++i) h[i] = src->planes ? rad_half_from_float(src->planes[i]) : src->half[i];
    } else {
        float *f = (float *)mb->planes;
        for (i = 0; i < total; ++i) f[i] = src->planes ? src->planes[i] : rad_half_to_float(src->half[i]);
    }
    if (src->row_perm) {
        memcpy((uint32_t *)mb->row_perm, src->row_perm, (size_t)src->n * sizeof(uint32_t));
        memcpy((uint32_t *)mb->col_perm, src->col_perm, (size_t)src->n * sizeof(uint32_t));
    }
    *out = mb;
    return RAD_SUCCESS;
}

/* ---- applying F_mb ---- */

static float rad__mb_dot(const float *a, const float *x, uint32_t n)
{
    uint32_t j = 0;
    float s = 0.0f;
#if defined(RAD__AVX)
    {
        __m256 s0 = _mm256_setzero_ps(), s1 = _mm256_setzero_ps(), s2 = _mm256_setzero_ps(), s3 = _mm256_setzero_ps();
        float t[8];
        int k;
        for (; j + 32 <= n; j += 32) {
            s0 = _mm256_add_ps(s0, _mm256_mul_ps(_mm256_loadu_ps(a + j), _mm256_loadu_ps(x + j)));
            s1 = _mm256_add_ps(s1, _mm256_mul_ps(_mm256_loadu_ps(a + j + 8), _mm256_loadu_ps(x + j + 8)));
            s2 = _mm256_add_ps(s2, _mm256_mul_ps(_mm256_loadu_ps(a + j + 16), _mm256_loadu_ps(x + j + 16)));
            s3 = _mm256_add_ps(s3, _mm256_mul_ps(_mm256_loadu_ps(a + j + 24), _mm256_loadu_ps(x + j + 24)));
        }
        _mm256_storeu_ps(t, _mm256_add_ps(_mm256_add_ps(s0, s1), _mm256_add_ps(s2, s3)));
        for (k = 0; k < 8; ++k) s += t[k];
    }
#endif
    for (; j < n; ++j) s += a[j] * x[j];
    return s;
}

static float rad__mb_dot_half(const uint16_t *a, const float *x, uint32_t n)
{
    uint32_t j = 0;
    float s = 0.0f;
#if defined(RAD__MB_F16C)
    {
        __m256 s0 = _mm256_setzero_ps(), s1 = _mm256_setzero_ps(), s2 = _mm256_setzero_ps(), s3 = _mm256_setzero_ps();
        float t[8];
        int k;
        for (; j + 32 <= n; j += 32) {
            s0 = _mm256_add_ps(s0, _mm256_mul_ps(_mm256_cvtph_ps(_mm_loadu_si128((const __m128i *)(a + j))), _mm256_loadu_ps(x + j)));
            s1 = _mm256_add_ps(s1, _mm256_mul_ps(_mm256_cvtph_ps(_mm_loadu_si128((const __m128i *)(a + j + 8))), _mm256_loadu_ps(x + j + 8)));
            s2 = _mm256_add_ps(s2, _mm256_mul_ps(_mm256_cvtph_ps(_mm_loadu_si128((const __m128i *)(a + j + 16))), _mm256_loadu_ps(x + j + 16)));
            s3 = _mm256_add_ps(s3, _mm256_mul_ps(_mm256_cvtph_ps(_mm_loadu_si128((const __m128i *)(a + j + 24))), _mm256_loadu_ps(x + j + 24)));
        }
        _mm256_storeu_ps(t, _mm256_add_ps(_mm256_add_ps(s0, s1), _mm256_add_ps(s2, s3)));
        for (k = 0; k < 8; ++k) s += t[k];
    }
#endif
    for (; j < n; ++j) s += rad_half_to_float(a[j]) * x[j];
    return s;
}

typedef struct rad__mb_apply {
    const rad_multibounce *mb;
    const float *x;    /* 3 n, SoA, permuted column order */
    float *y;          /* 3 n, SoA, permuted row order */
    uint32_t tasks;
} rad__mb_apply;

static void rad__mb_apply_task(void *data, uint32_t t)
{
    const rad__mb_apply *a = (const rad__mb_apply *)data;
    uint32_t n = a->mb->n, i0 = (uint32_t)((uint64_t)n * t / a->tasks), i1 = (uint32_t)((uint64_t)n * (t + 1) / a->tasks), i, ch;
    size_t nn = (size_t)n * n;
    /* plane by plane: one sequential stream at a time (interleaving the three planes' rows
       cost the half apply 1.45x at N = 5696, see BENCHMARKS.md); every y is the same dot */
    for (ch = 0; ch < 3; ++ch)
        for (i = i0; i < i1; ++i) {
            size_t at = ch * nn + (size_t)i * n;
            a->y[ch * (size_t)n + i] = a->mb->planes ? rad__mb_dot(a->mb->planes + at, a->x + ch * (size_t)n, n)
                                                     : rad__mb_dot_half(a->mb->half + at, a->x + ch * (size_t)n, n);
        }
}

/* x (SoA, 3 * padded) = E permuted by col_perm (zero padding up to 'padded') */
static void rad__mb_gather(const float *E, const uint32_t *col_perm, uint32_t n, uint32_t padded, float *x)
{
    uint32_t j, ch;
    for (ch = 0; ch < 3; ++ch) {
        float *xc = x + (size_t)ch * padded;
        for (j = 0; j < n; ++j) xc[j] = E[3 * (size_t)(col_perm ? col_perm[j] : j) + ch];
        for (; j < padded; ++j) xc[j] = 0.0f;
    }
}

/* out (interleaved) = y (SoA, stride 'stride', permuted rows) un-permuted */
static void rad__mb_scatter(const float *y, uint32_t stride, const uint32_t *row_perm, uint32_t n, float *out)
{
    uint32_t i, ch;
    for (i = 0; i < n; ++i)
        for (ch = 0; ch < 3; ++ch) out[3 * (size_t)(row_perm ? row_perm[i] : i) + ch] = y[(size_t)ch * stride + i];
}

RAD_API rad_result rad_multibounce_apply(const rad_multibounce *mb, const float *E, float *out, rad_output output,
                                         const rad_context *ctx)
{
    rad__ctx c;
    rad__mb_apply a;
    float *x;
    uint32_t n;
    size_t i;
    rad__ctx_init(&c, ctx);
    if (rad__mb_check(mb) != RAD_SUCCESS || !E || !out || E == out) return RAD_ERROR_INVALID_ARGUMENT;
    n = mb->n;
    if (rad__check_input(&c, "rad_multibounce_apply", E, 3 * (size_t)n) != RAD_SUCCESS) return RAD_ERROR_NON_FINITE;
    x = (float *)rad__alloc_array(&c.allocator, (size_t)n, 6 * sizeof(float));
    if (!x) return RAD_ERROR_OUT_OF_MEMORY;
    rad__mb_gather(E, mb->col_perm, n, n, x);
    a.mb = mb;
    a.x = x;
    a.y = x + 3 * (size_t)n;
    a.tasks = c.tasks < n ? c.tasks : n;
    c.parallel_for(c.parallel_user, a.tasks, rad__mb_apply_task, &a);
    rad__mb_scatter(a.y, n, mb->row_perm, n, out);
    if (output == RAD_OUTPUT_TOTAL)
        for (i = 0; i < 3 * (size_t)n; ++i) out[i] += E[i];
    rad__free(&c.allocator, x);
    return rad__check_output(&c, "rad_multibounce_apply", out, 3 * (size_t)n);
}

/* ---- greedy reordering (Shcherbakov 2025, ch. 3) ---- */

/* Greedy chain over the n items whose Gram matrix is G (n x n): order[0] = 0, then each next
   item is the unplaced one nearest (L2, |a|^2 + |b|^2 - 2 a.b) to the last placed. O(n^2). */
static rad_result rad__mb_chain(const rad__ctx *c, const float *G, uint32_t n, uint32_t *order)
{
    unsigned char *used = (unsigned char *)rad__alloc(&c->allocator, n);
    uint32_t p, j, cur = 0;
    if (!used) return RAD_ERROR_OUT_OF_MEMORY;
    memset(used, 0, n);
    order[0] = 0;
    used[0] = 1;
    for (p = 1; p < n; ++p) {
        const float *g = G + (size_t)cur * n;
        double best = DBL_MAX;
        uint32_t bj = 0;
        for (j = 0; j < n; ++j) {
            double d;
            if (used[j]) continue;
            d = (double)G[(size_t)j * n + j] - 2.0 * (double)g[j];   /* |cur|^2 is the same for all j */
            if (d < best) { best = d; bj = j; }
        }
        order[p] = bj;
        used[bj] = 1;
        cur = bj;
    }
    rad__free(&c->allocator, used);
    return RAD_SUCCESS;
}

/* 2-opt refinement of the open chain 'order' on the same L2 distance (G a Gram matrix,
   overwritten by the distances): reverse order[i+1..j] whenever that shortens the chain,
   first improvement, until a pass finds nothing or after 'passes' passes. The greedy chain's
   late steps jump between far-apart leftovers; reversals remove those long edges. O(n^2) per
   pass plus O(n) per accepted move. */
/* The Gram matrix G (n x n) overwritten by the L2 distances |a - b|, symmetric to the bit
   whatever the GEMM's rounding, zero on the diagonal. O(n^2). */
static rad_result rad__mb_distances(const rad__ctx *c, float *G, uint32_t n)
{
    float *diag = (float *)rad__alloc_array(&c->allocator, n, sizeof(float));
    uint32_t i, j;
    if (!diag) return RAD_ERROR_OUT_OF_MEMORY;
    for (i = 0; i < n; ++i) diag[i] = G[(size_t)i * n + i];
    for (i = 0; i < n; ++i)
        for (j = 0; j < n; ++j) {
            float d2 = diag[i] + diag[j] - 2.0f * G[(size_t)i * n + j];
            G[(size_t)i * n + j] = i == j ? 0.0f : (d2 > 0.0f ? sqrtf(d2) : 0.0f);
        }
    rad__free(&c->allocator, diag);
    for (i = 0; i < n; ++i)
        for (j = i + 1; j < n; ++j) G[(size_t)j * n + i] = G[(size_t)i * n + j];
    return RAD_SUCCESS;
}

static rad_result rad__mb_two_opt(const rad__ctx *c, float *G, uint32_t n, uint32_t *order, uint32_t passes)
{
    uint32_t i, j, pass;
    rad_result r = rad__mb_distances(c, G, n);
    if (r != RAD_SUCCESS) return r;
    for (pass = 0; pass < passes && n > 3; ++pass) {
        int improved = 0;
        /* i = n means "before the start": reversing a prefix order[0..j] */
        for (i = 0; i + 2 <= n; ++i) {
            uint32_t a = i == 0 ? 0 : order[i - 1], b = order[i];
            const float *Da = G + (size_t)a * n, *Db = G + (size_t)b * n;
            float dab = i == 0 ? 0.0f : Da[b];
            for (j = i + 1; j < n; ++j) {
                uint32_t cc = order[j];
                float before, after;
                if (j + 1 < n) {
                    uint32_t d = order[j + 1];
                    before = dab + G[(size_t)cc * n + d];
                    after = (i == 0 ? 0.0f : Da[cc]) + Db[d];
                } else {
                    before = dab;
                    after = i == 0 ? 0.0f : Da[cc];
                }
                if (after < before - 1e-6f * before) {
                    uint32_t lo = i, hi = j;
                    while (lo < hi) { uint32_t t = order[lo]; order[lo++] = order[hi]; order[hi--] = t; }
                    b = order[i];
                    Db = G + (size_t)b * n;
                    dab = i == 0 ? 0.0f : Da[b];
                    improved = 1;
                }
            }
        }
        if (!improved) break;
    }
    return RAD_SUCCESS;
}

/* Only the split of the rows (columns) into aligned groups of four decides which entries
   share a 4x4 block, not the order of the groups. Pairwise swaps between two full groups
   that lower the summed within-group squared distance (4 x the squared distance to the group
   mean, from the distance matrix D), first improvement, at most 'passes' passes. O(n^2) per
   pass. */
static void rad__mb_group_swaps(const float *D, uint32_t n, uint32_t *order, uint32_t passes)
{
    uint32_t full = n & ~3u, pa, pb, pass, k;
    for (pass = 0; pass < passes && full >= 8u; ++pass) {
        int improved = 0;
        for (pa = 0; pa < full; ++pa) {
            uint32_t ga = pa & ~3u;
            for (pb = ga + 4u; pb < full; ++pb) {
                uint32_t p = order[pa], q = order[pb], gb = pb & ~3u;
                const float *Dp = D + (size_t)p * n, *Dq = D + (size_t)q * n;
                float delta = 0.0f, base = 0.0f;
                for (k = 0; k < 4u; ++k) {
                    uint32_t a = order[ga + k], b = order[gb + k];
                    if (a != p) { delta += Dq[a] * Dq[a] - Dp[a] * Dp[a]; base += Dp[a] * Dp[a]; }
                    if (b != q) { delta += Dp[b] * Dp[b] - Dq[b] * Dq[b]; base += Dq[b] * Dq[b]; }
                }
                if (delta < -1e-6f * base) {
                    order[pa] = q;
                    order[pb] = p;
                    improved = 1;
                }
            }
        }
        if (!improved) break;
    }
}

/* ---- grouping by matching (RAD_REORDER_MATCH) ---- */

typedef struct rad__mb_edge {
    float w;
    uint32_t a, b; /* a < b */
} rad__mb_edge;

static int rad__mb_edge_cmp(const void *x, const void *y)
{
    const rad__mb_edge *p = (const rad__mb_edge *)x, *q = (const rad__mb_edge *)y;
    if (p->w != q->w) return p->w < q->w ? -1 : 1;
    if (p->a != q->a) return p->a < q->a ? -1 : 1;
    return p->b < q->b ? -1 : (p->b > q->b ? 1 : 0);
}

/* Cost of putting items i and j together: the sum of the squared distances (D: distances)
   between the 'per' members of i and those of j. */
static float rad__mb_match_cost(const float *D, uint32_t n, const uint32_t *members, uint32_t per, uint32_t i, uint32_t j)
{
    float s = 0.0f;
    uint32_t a, b;
    for (a = 0; a < per; ++a) {
        const float *Da = D + (size_t)members[i * per + a] * n;
        for (b = 0; b < per; ++b) {
            float d = Da[members[j * per + b]];
            s += d * d;
        }
    }
    return s;
}

#define RAD__MB_MATCH_K 8u

/* Greedy matching of m items (each 'per' members of the n rows): the edges from every free
   item to its RAD__MB_MATCH_K cheapest free partners, cheapest first, each taken when both
   ends are free; repeated on the items left free until fewer than two remain. partner[i] =
   the item matched to i, or UINT32_MAX (at most one is left when m is odd). Deterministic
   (ties by index). O(f^2 per^2) per round for f free items; rounds are few (each takes at
   least the cheapest edge, usually almost all). */
static rad_result rad__mb_match(const rad__ctx *c, const float *D, uint32_t n, const uint32_t *members, uint32_t per, uint32_t m,
                                uint32_t *partner)
{
    uint32_t *freel = (uint32_t *)rad__alloc_array(&c->allocator, m, sizeof(uint32_t));
    rad__mb_edge *e = (rad__mb_edge *)rad__alloc_array(&c->allocator, (size_t)m * RAD__MB_MATCH_K, sizeof(rad__mb_edge));
    uint32_t i, nf;
    if (!freel || !e) {
        rad__free(&c->allocator, freel);
        rad__free(&c->allocator, e);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    for (i = 0; i < m; ++i) partner[i] = UINT32_MAX;
    for (;;) {
        size_t ne = 0, q;
        uint32_t fi, fj;
        nf = 0;
        for (i = 0; i < m; ++i)
            if (partner[i] == UINT32_MAX) freel[nf++] = i;
        if (nf < 2) break;
        for (fi = 0; fi < nf; ++fi) {
            float bw[RAD__MB_MATCH_K];
            uint32_t bj[RAD__MB_MATCH_K], cnt = 0, k;
            for (fj = 0; fj < nf; ++fj) {
                float w;
                if (fj == fi) continue;
                w = rad__mb_match_cost(D, n, members, per, freel[fi], freel[fj]);
                if (cnt == RAD__MB_MATCH_K && !(w < bw[cnt - 1])) continue;
                k = cnt < RAD__MB_MATCH_K ? cnt++ : cnt - 1;
                while (k > 0 && w < bw[k - 1]) { bw[k] = bw[k - 1]; bj[k] = bj[k - 1]; --k; }
                bw[k] = w;
                bj[k] = freel[fj];
            }
            for (k = 0; k < cnt; ++k) {
                e[ne].w = bw[k];
                e[ne].a = freel[fi] < bj[k] ? freel[fi] : bj[k];
                e[ne].b = freel[fi] < bj[k] ? bj[k] : freel[fi];
                ++ne;
            }
        }
        qsort(e, ne, sizeof(rad__mb_edge), rad__mb_edge_cmp);
        for (q = 0; q < ne; ++q)
            if (partner[e[q].a] == UINT32_MAX && partner[e[q].b] == UINT32_MAX) {
                partner[e[q].a] = e[q].b;
                partner[e[q].b] = e[q].a;
            }
    }
    rad__free(&c->allocator, freel);
    rad__free(&c->allocator, e);
    return RAD_SUCCESS;
}

/* Groups of four by two rounds of matching on the squared distances (D: distances): rows
   into pairs, then pairs into quadruples (cost: the four cross squared distances, so the sum
   of a quadruple's six is what the two rounds minimise); the quadruples follow each other in
   the order of a greedy chain over them (so that scale tiles hold alike rows), then the
   members of an unmatched pair and an unmatched row. The greedy chain builds groups as runs
   of a path, which strands rows; matching looks at every row's nearest partners at once.
   O(n^2) per round plus O(n^2 / 16 * 16) for the chain. */
static rad_result rad__mb_match_groups(const rad__ctx *c, const float *D, uint32_t n, uint32_t *order)
{
    uint32_t np = 0, nq = 0, i, k, at = 0, cur = 0;
    uint32_t *partner = (uint32_t *)rad__alloc_array(&c->allocator, n, sizeof(uint32_t));
    uint32_t *ident = (uint32_t *)rad__alloc_array(&c->allocator, n, sizeof(uint32_t));
    uint32_t *pairs = (uint32_t *)rad__alloc_array(&c->allocator, n, sizeof(uint32_t));
    uint32_t *quads = (uint32_t *)rad__alloc_array(&c->allocator, n, sizeof(uint32_t));
    unsigned char *used = (unsigned char *)rad__alloc(&c->allocator, n);
    rad_result r = RAD_ERROR_OUT_OF_MEMORY;
    if (!partner || !ident || !pairs || !quads || !used) goto done;
    for (i = 0; i < n; ++i) ident[i] = i;
    r = rad__mb_match(c, D, n, ident, 1u, n, partner);
    if (r != RAD_SUCCESS) goto done;
    for (i = 0; i < n; ++i)
        if (partner[i] != UINT32_MAX && i < partner[i]) { pairs[2 * np] = i; pairs[2 * np + 1] = partner[i]; ++np; }
    r = rad__mb_match(c, D, n, pairs, 2u, np, partner);
    if (r != RAD_SUCCESS) goto done;
    for (i = 0; i < np; ++i)
        if (partner[i] != UINT32_MAX && i < partner[i]) {
            quads[4 * nq] = pairs[2 * i];
            quads[4 * nq + 1] = pairs[2 * i + 1];
            quads[4 * nq + 2] = pairs[2 * partner[i]];
            quads[4 * nq + 3] = pairs[2 * partner[i] + 1];
            ++nq;
        }
    /* greedy chain over the quadruples, from the first */
    memset(used, 0, n);
    for (k = 0; k < nq; ++k) {
        uint32_t q, best_q = cur;
        float best = FLT_MAX;
        if (k > 0)
            for (q = 0; q < nq; ++q) {
                float w;
                if (used[q]) continue;
                w = rad__mb_match_cost(D, n, quads, 4u, cur, q);
                if (w < best) { best = w; best_q = q; }
            }
        used[best_q] = 1;
        cur = best_q;
        for (i = 0; i < 4; ++i) order[at++] = quads[4 * cur + i];
    }
    memset(used, 0, n);
    for (i = 0; i < at; ++i) used[order[i]] = 1;
    for (i = 0; i < n; ++i)
        if (!used[i]) order[at++] = i;
    r = RAD_SUCCESS;
done:
    rad__free(&c->allocator, partner);
    rad__free(&c->allocator, ident);
    rad__free(&c->allocator, pairs);
    rad__free(&c->allocator, quads);
    rad__free(&c->allocator, used);
    return r;
}

/* Row and column orders of the RGB planes W (3 n^2 floats) by the greedy chain (method
   RAD_REORDER_GREEDY), the chain refined by 2-opt (RAD_REORDER_GREEDY_2OPT), then by group
   swaps (RAD_REORDER_GROUPS), or by matching and group swaps (RAD_REORDER_MATCH),
   distances over all 3n coordinates of a row/column (samples == 0) or over 'samples' evenly
   spaced ones. */
static rad_result rad__mb_reorder_perms(const rad__ctx *c, const float *W, uint32_t n, uint32_t samples, int method,
                                        uint32_t *row_perm, uint32_t *col_perm)
{
    uint32_t coords = 3u * n, s, i, j, pass;
    size_t nn = (size_t)n * n;
    float *X = NULL, *XT = NULL, *G = NULL;
    rad_result r = RAD_SUCCESS;
    if (samples == 0 || samples > coords) samples = coords;
    X = (float *)rad__alloc_array(&c->allocator, (size_t)samples * n, sizeof(float));
    XT = (float *)rad__alloc_array(&c->allocator, (size_t)samples * n, sizeof(float));
    G = (float *)rad__alloc_array(&c->allocator, nn, sizeof(float));
    if (!X || !XT || !G) { r = RAD_ERROR_OUT_OF_MEMORY; goto done; }
    for (pass = 0; pass < 2 && r == RAD_SUCCESS; ++pass) {
        /* pass 0, columns: X (samples x n) holds sampled rows (coordinates) of the stacked planes;
           pass 1, rows: X holds sampled columns; G = X^T X */
        for (s = 0; s < samples; ++s) {
            uint32_t coord = (uint32_t)((uint64_t)s * coords / samples), ch = coord / n, k = coord % n;
            const float *P = W + (size_t)ch * nn;
            for (j = 0; j < n; ++j) X[(size_t)s * n + j] = pass == 0 ? P[(size_t)k * n + j] : P[(size_t)j * n + k];
        }
        for (s = 0; s < samples; ++s)
            for (i = 0; i < n; ++i) XT[(size_t)i * samples + s] = X[(size_t)s * n + i];
        memset(G, 0, nn * sizeof(float));
        r = rad__mb_gemm(c, n, n, samples, XT, samples, X, n, G, n);
        if (method == RAD_REORDER_MATCH) {
            if (r == RAD_SUCCESS) r = rad__mb_distances(c, G, n);
            if (r == RAD_SUCCESS) r = rad__mb_match_groups(c, G, n, pass == 0 ? col_perm : row_perm);
            if (r == RAD_SUCCESS) rad__mb_group_swaps(G, n, pass == 0 ? col_perm : row_perm, 64u);
            continue;
        }
        if (r == RAD_SUCCESS) r = rad__mb_chain(c, G, n, pass == 0 ? col_perm : row_perm);
        if (r == RAD_SUCCESS && method >= RAD_REORDER_GREEDY_2OPT) r = rad__mb_two_opt(c, G, n, pass == 0 ? col_perm : row_perm, 64u);
        if (r == RAD_SUCCESS && method == RAD_REORDER_GROUPS) rad__mb_group_swaps(G, n, pass == 0 ? col_perm : row_perm, 64u);
    }
done:
    rad__free(&c->allocator, X);
    rad__free(&c->allocator, XT);
    rad__free(&c->allocator, G);
    return r;
}

/* float planes of mb (widened into *owned when half) */
static const float *rad__mb_float_planes(const rad__ctx *c, const rad_multibounce *mb, float **owned)
{
    size_t i, total = 3 * (size_t)mb->n * mb->n;
    *owned = NULL;
    if (mb->planes) return mb->planes;
    *owned = (float *)rad__alloc_array(&c->allocator, total, sizeof(float));
    if (!*owned) return NULL;
    for (i = 0; i < total; ++i) (*owned)[i] = rad_half_to_float(mb->half[i]);
    return *owned;
}

RAD_API rad_result rad_multibounce_reorder(const rad_multibounce *src, uint32_t samples, const rad_context *ctx,
                                           rad_multibounce **out)
{
    rad__ctx c;
    rad_multibounce *mb = NULL;
    float *owned = NULL;
    const float *W;
    uint32_t n, i, j, ch;
    size_t nn;
    rad_result r;
    rad__ctx_init(&c, ctx);
    if (!out) return RAD_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    if (rad__mb_check(src) != RAD_SUCCESS || src->row_perm) return RAD_ERROR_INVALID_ARGUMENT;
    n = src->n;
    nn = (size_t)n * n;
    r = rad__mb_new(&c, n, src->bounces, src->precision, 1, &mb);
    if (r != RAD_SUCCESS) return r;
    W = rad__mb_float_planes(&c, src, &owned);
    if (!W) { rad_multibounce_destroy(mb); return RAD_ERROR_OUT_OF_MEMORY; }
    r = rad__mb_reorder_perms(&c, W, n, samples, RAD_REORDER_GREEDY, (uint32_t *)mb->row_perm, (uint32_t *)mb->col_perm);
    if (r == RAD_SUCCESS)
        for (ch = 0; ch < 3; ++ch)
            for (i = 0; i < n; ++i) {
                size_t to = ch * nn + (size_t)i * n, from = ch * nn + (size_t)mb->row_perm[i] * n;
                for (j = 0; j < n; ++j) {
                    size_t f = from + mb->col_perm[j];
                    if (src->planes) ((float *)mb->planes)[to + j] = src->planes[f];
                    else ((uint16_t *)mb->half)[to + j] = src->half[f];
                }
            }
    rad__free(&c.allocator, owned);
    if (r != RAD_SUCCESS) { rad_multibounce_destroy(mb); return r; }
    *out = mb;
    return RAD_SUCCESS;
}

/* ---- BC1 and BC4 blocks (Khronos Data Format specification) ---- */

/* The palettes are the specification's real-valued formulas rounded once: an integer
   numerator over an integer denominator (e.g. (2 c0 + c1) / (3 * 31)), one correctly rounded
   division. No intermediate rounding, so no compiler contraction can change a value (the
   BC1 apply folds the palette into its tables instead: within 1e-6 of these values). */
static void rad__bc1_palette(uint32_t c0, uint32_t c1, float pal[4][3])
{
    static const uint32_t shift[3] = { 11u, 5u, 0u }, mask[3] = { 31u, 63u, 31u };
    int k;
    for (k = 0; k < 3; ++k) {
        uint32_t a = (c0 >> shift[k]) & mask[k], b = (c1 >> shift[k]) & mask[k];
        float d = (float)mask[k];
        pal[0][k] = (float)a / d;
        pal[1][k] = (float)b / d;
        if (c0 > c1) {
            pal[2][k] = (float)(2u * a + b) / (3.0f * d);
            pal[3][k] = (float)(a + 2u * b) / (3.0f * d);
        } else {
            pal[2][k] = (float)(a + b) / (2.0f * d);
            pal[3][k] = 0.0f;
        }
    }
}

static void rad__bc4_palette(uint32_t r0, uint32_t r1, float pal[8])
{
    uint32_t k;
    pal[0] = (float)r0 / 255.0f;
    pal[1] = (float)r1 / 255.0f;
    if (r0 > r1) {
        for (k = 2; k < 8; ++k) pal[k] = (float)((8u - k) * r0 + (k - 1u) * r1) / (7.0f * 255.0f);
    } else {
        for (k = 2; k < 6; ++k) pal[k] = (float)((6u - k) * r0 + (k - 1u) * r1) / (5.0f * 255.0f);
        pal[6] = 0.0f;
        pal[7] = 1.0f;
    }
}

static uint64_t rad__bc4_bits(const uint8_t *b)
{
    return (uint64_t)b[2] | (uint64_t)b[3] << 8 | (uint64_t)b[4] << 16 | (uint64_t)b[5] << 24 | (uint64_t)b[6] << 32 |
           (uint64_t)b[7] << 40;
}

RAD_API void rad_bc1_decode_block(const uint8_t block[8], float out_rgb[48])
{
    float pal[4][3];
    uint32_t c0 = (uint32_t)block[0] | (uint32_t)block[1] << 8, c1 = (uint32_t)block[2] | (uint32_t)block[3] << 8;
    uint32_t w = (uint32_t)block[4] | (uint32_t)block[5] << 8 | (uint32_t)block[6] << 16 | (uint32_t)block[7] << 24, t;
    rad__bc1_palette(c0, c1, pal);
    for (t = 0; t < 16; ++t) {
        const float *p = pal[(w >> (2 * t)) & 3u];
        out_rgb[3 * t] = p[0];
        out_rgb[3 * t + 1] = p[1];
        out_rgb[3 * t + 2] = p[2];
    }
}

RAD_API void rad_bc4_decode_block(const uint8_t block[8], float out_values[16])
{
    float pal[8];
    uint64_t bits = rad__bc4_bits(block);
    uint32_t t;
    rad__bc4_palette(block[0], block[1], pal);
    for (t = 0; t < 16; ++t) out_values[t] = pal[(bits >> (3 * t)) & 7u];
}

static float rad__clamp01(float v) { return v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f; } /* NaN -> 0 */

static uint32_t rad__bc1_pack(const float *rgb)
{
    uint32_t r = (uint32_t)(rad__clamp01(rgb[0]) * 31.0f + 0.5f), g = (uint32_t)(rad__clamp01(rgb[1]) * 63.0f + 0.5f),
             b = (uint32_t)(rad__clamp01(rgb[2]) * 31.0f + 0.5f);
    return r << 11 | g << 5 | b;
}

/* squared error of endpoints (c0, c1) with the best code per texel; codes into *w */
static float rad__bc1_eval(const float *rgb, uint32_t c0, uint32_t c1, uint32_t *w)
{
    float pal[4][3], err = 0.0f;
    uint32_t t, k, codes = 0;
    rad__bc1_palette(c0, c1, pal);
    for (t = 0; t < 16; ++t) {
        float best = FLT_MAX;
        uint32_t bk = 0;
        for (k = 0; k < 4; ++k) {
            float d0 = pal[k][0] - rgb[3 * t], d1 = pal[k][1] - rgb[3 * t + 1], d2 = pal[k][2] - rgb[3 * t + 2];
            float d = d0 * d0 + d1 * d1 + d2 * d2;
            if (d < best) { best = d; bk = k; }
        }
        codes |= bk << (2 * t);
        err += best;
    }
    *w = codes;
    return err;
}

/* endpoints along the principal axis of the texels with mask bit set */
static void rad__bc1_fit(const float *rgb, uint32_t mask, float *e0, float *e1)
{
    double mean[3] = { 0, 0, 0 }, cov[6] = { 0, 0, 0, 0, 0, 0 }, axis[3] = { 1, 1, 1 }, tmin = DBL_MAX, tmax = -DBL_MAX;
    uint32_t t, cnt = 0, it;
    int k;
    for (t = 0; t < 16; ++t)
        if (mask >> t & 1u) { for (k = 0; k < 3; ++k) mean[k] += rgb[3 * t + k]; ++cnt; }
    for (k = 0; k < 3; ++k) mean[k] /= (double)cnt;
    for (t = 0; t < 16; ++t)
        if (mask >> t & 1u) {
            double d0 = rgb[3 * t] - mean[0], d1 = rgb[3 * t + 1] - mean[1], d2 = rgb[3 * t + 2] - mean[2];
            cov[0] += d0 * d0; cov[1] += d0 * d1; cov[2] += d0 * d2; cov[3] += d1 * d1; cov[4] += d1 * d2; cov[5] += d2 * d2;
        }
    for (it = 0; it < 8; ++it) {
        double a0 = cov[0] * axis[0] + cov[1] * axis[1] + cov[2] * axis[2];
        double a1 = cov[1] * axis[0] + cov[3] * axis[1] + cov[4] * axis[2];
        double a2 = cov[2] * axis[0] + cov[4] * axis[1] + cov[5] * axis[2];
        double l = sqrt(a0 * a0 + a1 * a1 + a2 * a2);
        if (!(l > 1e-30)) break;
        axis[0] = a0 / l; axis[1] = a1 / l; axis[2] = a2 / l;
    }
    for (t = 0; t < 16; ++t)
        if (mask >> t & 1u) {
            double p = (rgb[3 * t] - mean[0]) * axis[0] + (rgb[3 * t + 1] - mean[1]) * axis[1] + (rgb[3 * t + 2] - mean[2]) * axis[2];
            if (p < tmin) tmin = p;
            if (p > tmax) tmax = p;
        }
    for (k = 0; k < 3; ++k) {
        e0[k] = (float)(mean[k] + tmax * axis[k]);
        e1[k] = (float)(mean[k] + tmin * axis[k]);
    }
}

/* least-squares endpoints for the codes w in the given mode; returns 0 when singular */
static int rad__bc1_refit(const float *rgb, uint32_t w, int four, float *e0, float *e1)
{
    double aa = 0, ab = 0, bb = 0, ax[3] = { 0, 0, 0 }, bx[3] = { 0, 0, 0 }, det;
    uint32_t t;
    int k;
    for (t = 0; t < 16; ++t) {
        uint32_t code = (w >> (2 * t)) & 3u;
        double a, b;
        if (four) {
            static const double wa[4] = { 1.0, 0.0, 2.0 / 3.0, 1.0 / 3.0 };
            a = wa[code];
        } else {
            static const double wa[4] = { 1.0, 0.0, 0.5, -1.0 };
            if (code == 3u) continue;
            a = wa[code];
        }
        b = 1.0 - a;
        aa += a * a; ab += a * b; bb += b * b;
        for (k = 0; k < 3; ++k) { ax[k] += a * rgb[3 * t + k]; bx[k] += b * rgb[3 * t + k]; }
    }
    det = aa * bb - ab * ab;
    if (!(fabs(det) > 1e-12)) return 0;
    for (k = 0; k < 3; ++k) {
        e0[k] = (float)((ax[k] * bb - bx[k] * ab) / det);
        e1[k] = (float)((bx[k] * aa - ax[k] * ab) / det);
    }
    return 1;
}

RAD_API void rad_bc1_encode_block(const float rgb_in[48], uint8_t out[8])
{
    float rgb[48], e0[3], e1[3], best = FLT_MAX;
    uint32_t t, mask = 0, bc0 = 0, bc1 = 0, bw = 0, mode, it;
    for (t = 0; t < 48; ++t) rgb[t] = rad__clamp01(rgb_in[t]);
    for (t = 0; t < 16; ++t)
        if (rgb[3 * t] > 0.0f || rgb[3 * t + 1] > 0.0f || rgb[3 * t + 2] > 0.0f) mask |= 1u << t;
    if (mask == 0) { memset(out, 0, 8); return; } /* all black: c0 = c1 = 0, codes 0 */
    for (mode = 0; mode < 2; ++mode) {             /* 0: four colours (c0 > c1), 1: three + black */
        rad__bc1_fit(rgb, mode == 0 ? 0xFFFFu : mask, e0, e1);
        for (it = 0; it < 3; ++it) {
            uint32_t c0 = rad__bc1_pack(e0), c1 = rad__bc1_pack(e1), w;
            float err;
            if (mode == 0 ? c0 < c1 : c0 > c1) { uint32_t s = c0; c0 = c1; c1 = s; }
            err = rad__bc1_eval(rgb, c0, c1, &w);
            if (err < best) { best = err; bc0 = c0; bc1 = c1; bw = w; }
            if (!rad__bc1_refit(rgb, w, c0 > c1, e0, e1)) break;
        }
    }
    out[0] = (uint8_t)bc0; out[1] = (uint8_t)(bc0 >> 8);
    out[2] = (uint8_t)bc1; out[3] = (uint8_t)(bc1 >> 8);
    out[4] = (uint8_t)bw; out[5] = (uint8_t)(bw >> 8); out[6] = (uint8_t)(bw >> 16); out[7] = (uint8_t)(bw >> 24);
}

static float rad__bc4_eval(const float *v, uint32_t r0, uint32_t r1, uint64_t *bits)
{
    float pal[8], err = 0.0f;
    uint64_t codes = 0;
    uint32_t t, k;
    rad__bc4_palette(r0, r1, pal);
    for (t = 0; t < 16; ++t) {
        float best = FLT_MAX;
        uint32_t bk = 0;
        for (k = 0; k < 8; ++k) {
            float d = (pal[k] - v[t]) * (pal[k] - v[t]);
            if (d < best) { best = d; bk = k; }
        }
        codes |= (uint64_t)bk << (3 * t);
        err += best;
    }
    *bits = codes;
    return err;
}

RAD_API void rad_bc4_encode_block(const float values[16], uint8_t out[8])
{
    float v[16], lo = 1.0f, hi = 0.0f, ilo = 1.0f, ihi = 0.0f, best = FLT_MAX;
    uint64_t bbits = 0, bits;
    uint32_t t, br0 = 0, br1 = 0;
    int a, b, inner = 0;
    for (t = 0; t < 16; ++t) {
        v[t] = rad__clamp01(values[t]);
        if (v[t] < lo) lo = v[t];
        if (v[t] > hi) hi = v[t];
        if (v[t] > 0.0f && v[t] < 1.0f) {
            if (v[t] < ilo) ilo = v[t];
            if (v[t] > ihi) ihi = v[t];
            inner = 1;
        }
    }
    /* eight-value mode (r0 > r1): endpoints around the range */
    for (a = -1; a <= 1; ++a)
        for (b = -1; b <= 1; ++b) {
            int r0 = (int)ceil((double)hi * 255.0) + a, r1 = (int)floor((double)lo * 255.0) + b;
            float err;
            if (r0 > 255) r0 = 255;
            if (r1 < 0) r1 = 0;
            if (r0 <= r1) continue;
            err = rad__bc4_eval(v, (uint32_t)r0, (uint32_t)r1, &bits);
            if (err < best) { best = err; br0 = (uint32_t)r0; br1 = (uint32_t)r1; bbits = bits; }
        }
    /* six values plus exact 0 and 1 (r0 <= r1): endpoints around the values strictly inside */
    if (!inner) ilo = ihi = 0.0f;
    for (a = 0; a <= 1; ++a)
        for (b = 0; b <= 1; ++b) {
            int r0 = a ? (int)ceil((double)ilo * 255.0) : (int)floor((double)ilo * 255.0);
            int r1 = b ? (int)ceil((double)ihi * 255.0) : (int)floor((double)ihi * 255.0);
            float err;
            if (r0 > r1) continue;
            err = rad__bc4_eval(v, (uint32_t)r0, (uint32_t)r1, &bits);
            if (err < best) { best = err; br0 = (uint32_t)r0; br1 = (uint32_t)r1; bbits = bits; }
        }
    out[0] = (uint8_t)br0;
    out[1] = (uint8_t)br1;
    for (t = 0; t < 6; ++t) out[2 + t] = (uint8_t)(bbits >> (8 * t));
}

/* ---- compression ---- */

static uint32_t rad__mb_tile_index(const rad_multibounce_blocks *b, uint32_t bx, uint32_t by)
{
    if (b->tile == 0) return 0;
    return (by * 4u / b->tile) * b->tiles_per_row + bx * 4u / b->tile;
}

static uint32_t rad__f32_bits(float f) { uint32_t u; memcpy(&u, &f, sizeof(u)); return u; }

typedef struct rad__mb_encode {
    rad_multibounce_blocks *b;
    const float *Wp;        /* permuted working planes, outliers removed */
    double *sse;            /* per block row */
    float *max_err;         /* per block row */
} rad__mb_encode;

static rad_result rad__mb_encode_row(void *data, uint32_t by, uint32_t task)
{
    const rad__mb_encode *e = (const rad__mb_encode *)data;
    rad_multibounce_blocks *b = e->b;
    uint32_t n = b->n, bpr = b->blocks_per_row, bx, t, ch;
    size_t nn = (size_t)n * n, nblocks = (size_t)bpr * bpr;
    double sse = 0.0;
    float maxe = 0.0f;
    (void)task;
    for (bx = 0; bx < bpr; ++bx) {
        const float *scale = b->scales + 3 * (size_t)rad__mb_tile_index(b, bx, by);
        float tex[48], dec[48];
        for (t = 0; t < 16; ++t) {
            uint32_t y = by * 4u + t / 4u, x = bx * 4u + t % 4u;
            for (ch = 0; ch < 3; ++ch) {
                float v = (y < n && x < n) ? e->Wp[ch * nn + (size_t)y * n + x] : 0.0f;
                tex[3 * t + ch] = scale[ch] > 0.0f ? v / scale[ch] : 0.0f;
            }
        }
        if (b->format == RAD_BLOCK_BC1) {
            uint8_t *blk = (uint8_t *)b->blocks + 8 * ((size_t)by * bpr + bx);
            rad_bc1_encode_block(tex, blk);
            rad_bc1_decode_block(blk, dec);
        } else {
            for (ch = 0; ch < 3; ++ch) {
                float v[16], d[16];
                uint8_t *blk = (uint8_t *)b->blocks + 8 * (ch * nblocks + (size_t)by * bpr + bx);
                for (t = 0; t < 16; ++t) v[t] = tex[3 * t + ch];
                rad_bc4_encode_block(v, blk);
                rad_bc4_decode_block(blk, d);
                for (t = 0; t < 16; ++t) dec[3 * t + ch] = d[t];
            }
        }
        for (t = 0; t < 16; ++t) {
            uint32_t y = by * 4u + t / 4u, x = bx * 4u + t % 4u;
            if (y >= n || x >= n) continue;
            for (ch = 0; ch < 3; ++ch) {
                float err = dec[3 * t + ch] * scale[ch] - e->Wp[ch * nn + (size_t)y * n + x];
                sse += (double)err * err;
                if (fabsf(err) > maxe) maxe = fabsf(err);
            }
        }
    }
    e->sse[by] = sse;
    e->max_err[by] = maxe;
    return RAD_SUCCESS;
}

/* threshold bits T and how many entries equal to T to take so that 'target' entries of the
   largest magnitude are chosen (radix select on the float bits; magnitudes are >= 0) */
static rad_result rad__mb_select(const rad__ctx *c, const float *W, size_t nn, uint64_t target, uint32_t *T, uint64_t *take_equal)
{
    uint64_t *hist = (uint64_t *)rad__alloc_array(&c->allocator, 65536u, sizeof(uint64_t)), above = 0;
    size_t i;
    uint32_t hb, lb;
    if (!hist) return RAD_ERROR_OUT_OF_MEMORY;
    memset(hist, 0, 65536u * sizeof(uint64_t));
    for (i = 0; i < nn; ++i) {
        float m = fabsf(W[i]);
        if (fabsf(W[nn + i]) > m) m = fabsf(W[nn + i]);
        if (fabsf(W[2 * nn + i]) > m) m = fabsf(W[2 * nn + i]);
        hist[rad__f32_bits(m) >> 16]++;
    }
    for (hb = 65535u; hb > 0 && above + hist[hb] < target; --hb) above += hist[hb];
    memset(hist, 0, 65536u * sizeof(uint64_t));
    for (i = 0; i < nn; ++i) {
        float m = fabsf(W[i]);
        uint32_t u;
        if (fabsf(W[nn + i]) > m) m = fabsf(W[nn + i]);
        if (fabsf(W[2 * nn + i]) > m) m = fabsf(W[2 * nn + i]);
        u = rad__f32_bits(m);
        if (u >> 16 == hb) hist[u & 0xFFFFu]++;
    }
    for (lb = 65535u; lb > 0 && above + hist[lb] < target; --lb) above += hist[lb];
    *T = hb << 16 | lb;
    *take_equal = target > above ? target - above : 0;
    if (*T == 0) *take_equal = 0; /* zeros stay in place */
    rad__free(&c->allocator, hist);
    return RAD_SUCCESS;
}

RAD_API rad_result rad_multibounce_blocks_create(const rad_multibounce *mb, const rad_block_options *options,
                                                 const rad_context *ctx, rad_multibounce_blocks **out,
                                                 rad_block_report *report)
{
    rad__ctx c;
    rad_block_options o;
    rad_multibounce_blocks *b = NULL;
    float *owned = NULL, *W = NULL, *Wp = NULL, *max_err = NULL;
    double *sse = NULL;
    const float *src;
    uint32_t n, bpr, tpr, planes, i, j, ch, T = 0;
    uint64_t target = 0, take_equal = 0, taken = 0, count = 0, *row_count = NULL;
    size_t nn, nblocks, total, bytes[7];
    void *parts[7];
    rad__mb_encode enc;
    rad_result r;
    rad__ctx_init(&c, ctx);
    if (!out) return RAD_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    if (report) memset(report, 0, sizeof(*report));
    if (rad__mb_check(mb) != RAD_SUCCESS || mb->row_perm) return RAD_ERROR_INVALID_ARGUMENT;
    if (options) o = *options; else rad_block_options_default(&o);
    if ((o.format != RAD_BLOCK_BC1 && o.format != RAD_BLOCK_BC4X3) || !(o.outlier_fraction >= 0.0f && o.outlier_fraction < 1.0f) ||
        (o.tile % 4u) != 0 || o.reorder < RAD_REORDER_NONE || o.reorder > RAD_REORDER_MATCH) {
        rad__log(&c, RAD_LOG_ERROR, "blocks: bad options (format %d, outlier fraction %g, tile %u: a multiple of 4, reorder %d: 0..4)",
                 (int)o.format, (double)o.outlier_fraction, o.tile, o.reorder);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    n = mb->n;
    nn = (size_t)n * n;
    bpr = (n + 3u) / 4u;
    tpr = o.tile ? (n + o.tile - 1u) / o.tile : 1u;
    planes = o.format == RAD_BLOCK_BC1 ? 1u : 3u;
    if (!rad__mul((size_t)bpr, (size_t)bpr, &nblocks) || !rad__mul3(nblocks, planes, 8, &bytes[0]) ||
        !rad__mul3(nn, 3, sizeof(float), &total))
        return RAD_ERROR_SIZE_OVERFLOW;
    src = rad__mb_float_planes(&c, mb, &owned);
    W = (float *)rad__alloc(&c.allocator, total);
    row_count = (uint64_t *)rad__alloc_array(&c.allocator, (size_t)n + 1u, sizeof(uint64_t));
    sse = (double *)rad__alloc_array(&c.allocator, bpr, sizeof(double));
    max_err = (float *)rad__alloc_array(&c.allocator, bpr, sizeof(float));
    b = (rad_multibounce_blocks *)rad__alloc(&c.allocator, sizeof(*b));
    if (b) { memset(b, 0, sizeof(*b)); b->allocator = c.allocator; } /* before the fail path destroys it */
    if (!src || !W || !row_count || !sse || !max_err || !b) { r = RAD_ERROR_OUT_OF_MEMORY; goto done; }
    memcpy(W, src, total);

    /* 1. outliers: count per row in the order they will be taken */
    if (o.outlier_fraction > 0.0f) {
        target = (uint64_t)((double)o.outlier_fraction * (double)nn);
        if (target > 0) {
            r = rad__mb_select(&c, W, nn, target, &T, &take_equal);
            if (r != RAD_SUCCESS) goto done;
        }
    }
    row_count[0] = 0;
    for (i = 0; i < n; ++i) {
        uint64_t k = 0;
        if (target > 0)
            for (j = 0; j < n; ++j) {
                size_t at = (size_t)i * n + j;
                float m = fabsf(W[at]);
                uint32_t u;
                if (fabsf(W[nn + at]) > m) m = fabsf(W[nn + at]);
                if (fabsf(W[2 * nn + at]) > m) m = fabsf(W[2 * nn + at]);
                u = rad__f32_bits(m);
                if (u > T || (u == T && taken < take_equal)) { if (u == T) ++taken; ++k; }
            }
        row_count[i + 1] = row_count[i] + k;
    }
    count = row_count[n];

    /* storage: blocks, scales, permutations, outliers */
    if (!rad__mul3((size_t)tpr * tpr, 3, sizeof(float), &bytes[1])) { r = RAD_ERROR_SIZE_OVERFLOW; goto done; }
    bytes[2] = bytes[3] = o.reorder ? (size_t)n * sizeof(uint32_t) : 0;
    bytes[4] = count ? ((size_t)n + 1u) * sizeof(uint64_t) : 0;
    if (!rad__mul((size_t)count, sizeof(uint32_t), &bytes[5]) || !rad__mul3((size_t)count, 3, sizeof(float), &bytes[6])) {
        r = RAD_ERROR_SIZE_OVERFLOW;
        goto done;
    }
    b->storage = rad__mb_carve(&c, bytes, 7, parts, &r);
    if (!b->storage) goto done;
    b->n = n;
    b->bounces = mb->bounces;
    b->format = o.format;
    b->blocks_per_row = bpr;
    b->blocks = (const uint8_t *)parts[0];
    b->tile = o.tile;
    b->tiles_per_row = tpr;
    b->scales = (const float *)parts[1];
    b->row_perm = (const uint32_t *)parts[2];
    b->col_perm = (const uint32_t *)parts[3];
    b->outlier_count = count;
    b->outlier_offsets = (const uint64_t *)parts[4];
    b->outlier_columns = (const uint32_t *)parts[5];
    b->outlier_values = (const float *)parts[6];
    if (count) {
        uint64_t *off = (uint64_t *)b->outlier_offsets, k = 0;
        uint32_t *cols = (uint32_t *)b->outlier_columns;
        float *vals = (float *)b->outlier_values;
        memcpy(off, row_count, ((size_t)n + 1u) * sizeof(uint64_t));
        taken = 0;
        for (i = 0; i < n; ++i)
            for (j = 0; j < n; ++j) {
                size_t at = (size_t)i * n + j;
                float m = fabsf(W[at]);
                uint32_t u;
                if (fabsf(W[nn + at]) > m) m = fabsf(W[nn + at]);
                if (fabsf(W[2 * nn + at]) > m) m = fabsf(W[2 * nn + at]);
                u = rad__f32_bits(m);
                if (u > T || (u == T && taken < take_equal)) {
                    if (u == T) ++taken;
                    cols[k] = j;
                    for (ch = 0; ch < 3; ++ch) { vals[3 * k + ch] = W[ch * nn + at]; W[ch * nn + at] = 0.0f; }
                    ++k;
                }
            }
    }
    if (report) {
        report->outlier_count = count;
        { float th; memcpy(&th, &T, sizeof(th)); report->outlier_threshold = count ? th : 0.0f; }
    }

    /* 2. greedy reordering */
    if (o.reorder) {
        r = rad__mb_reorder_perms(&c, W, n, o.reorder_samples, o.reorder, (uint32_t *)b->row_perm, (uint32_t *)b->col_perm);
        if (r != RAD_SUCCESS) goto done;
        Wp = (float *)rad__alloc(&c.allocator, total);
        if (!Wp) { r = RAD_ERROR_OUT_OF_MEMORY; goto done; }
        for (ch = 0; ch < 3; ++ch)
            for (i = 0; i < n; ++i) {
                const float *from = W + ch * nn + (size_t)b->row_perm[i] * n;
                float *to = Wp + ch * nn + (size_t)i * n;
                for (j = 0; j < n; ++j) to[j] = from[b->col_perm[j]];
            }
    }

    /* 3. scales: the largest value of each channel in each tile */
    {
        float *s = (float *)b->scales;
        const float *P = Wp ? Wp : W;
        memset(s, 0, bytes[1]);
        for (ch = 0; ch < 3; ++ch)
            for (i = 0; i < n; ++i)
                for (j = 0; j < n; ++j) {
                    float v = P[ch * nn + (size_t)i * n + j];
                    size_t t = o.tile ? (size_t)(i / o.tile) * tpr + j / o.tile : 0;
                    if (v > s[3 * t + ch]) s[3 * t + ch] = v;
                }
    }

    /* 4. block encoding, parallel over block rows, with the error of each */
    enc.b = b;
    enc.Wp = Wp ? Wp : W;
    enc.sse = sse;
    enc.max_err = max_err;
    r = rad__for_rows(&c, bpr, c.tasks < bpr ? c.tasks : bpr, rad__mb_encode_row, &enc);
    if (r != RAD_SUCCESS) goto done;
    rad__mb_info(b->info, o.format == RAD_BLOCK_BC1 ? 2u : 3u, n, mb->bounces, o.tile, tpr,
                 (o.reorder ? 1u : 0u) | (count ? 2u : 0u));
    if (report) {
        double s = 0.0, ms = 0.0;
        float me = 0.0f;
        size_t q;
        for (i = 0; i < bpr; ++i) { s += sse[i]; if (max_err[i] > me) me = max_err[i]; }
        for (q = 0; q < 3 * nn; ++q) ms += (double)src[q] * src[q];
        report->reordered = o.reorder != 0;
        report->tiles = tpr * tpr;
        report->bytes_float_f = nn * sizeof(float);
        report->bytes_float_mb = total;
        report->bytes_blocks = bytes[0];
        report->bytes_scales = bytes[1];
        report->bytes_permutations = bytes[2] + bytes[3];
        report->bytes_outliers = bytes[4] + bytes[5] + bytes[6];
        report->bytes_total = bytes[0] + bytes[1] + bytes[2] + bytes[3] + bytes[4] + bytes[5] + bytes[6];
        report->mse = s / (3.0 * (double)nn);
        report->max_abs_error = me;
        report->source_mean_square = ms / (3.0 * (double)nn);
    }
    *out = b;
    b = NULL;
    r = RAD_SUCCESS;
done:
    rad__free(&c.allocator, owned);
    rad__free(&c.allocator, W);
    rad__free(&c.allocator, Wp);
    rad__free(&c.allocator, row_count);
    rad__free(&c.allocator, sse);
    rad__free(&c.allocator, max_err);
    rad_multibounce_blocks_destroy(b);
    return r;
}

/* ---- applying and decoding the compressed form ---- */

typedef struct rad__mb_bapply {
    const rad_multibounce_blocks *b;
    const float *xp;     /* 3 * padded, SoA, permuted columns */
    const float *xe;     /* 3 * bpr * 16: x expanded for the two-column SIMD lanes (BC4) */
    float *y;            /* 3 * padded, SoA, permuted rows */
    float *lut;          /* BC1: the tables of block columns c0..c1-1, 256 x 12 partial sums each */
    uint32_t c0, c1;     /* BC1: the block columns of this pass */
    float *y2;           /* BC1: per block row 12 sums (R, G, B x 4 rows), task t's rows shifted
                            by 16 t floats so that no two tasks write one cache line */
    uint32_t padded, tasks;
    const uint32_t *tile_col; /* per block column: its tile column */
    const float *E;      /* outliers: original order */
    float *out;
} rad__mb_bapply;

#if defined(RAD__MB_AVX2)
/* x / d, correctly rounded, as the scalar decoder divides: with FMA, the reciprocal product
   m = x r (r = 1/d) corrected once by the residual, m + (x - m d) r. For every quotient the
   BC1 and BC4 palettes form (endpoints over 31, 63, 255; interpolants over 3, 5, 7; all
   endpoint pairs) this equals the division: tests/test_multibounce.c checks all of them. */
static inline __m256 rad__mb_div(__m256 x, __m256 d, __m256 r)
{
#if defined(RAD__MB_FMA)
    __m256 m = _mm256_mul_ps(x, r);
    return _mm256_fmadd_ps(_mm256_fnmadd_ps(m, d, x), r, m);
#else
    (void)r;
    return _mm256_div_ps(x, d);
#endif
}

static inline __m128 rad__mb_div4(__m128 x, __m128 d, __m128 r)
{
#if defined(RAD__MB_FMA)
    __m128 m = _mm_mul_ps(x, r);
    return _mm_fmadd_ps(_mm_fnmadd_ps(m, d, x), r, m);
#else
    (void)r;
    return _mm_div_ps(x, d);
#endif
}
#else
static void rad__mb_block_palettes(const rad_multibounce_blocks *b, const uint8_t *blk, size_t nblocks, const float *scale,
                                   float pal[3][8])
{
    uint32_t ch, k;
    for (ch = 0; ch < 3; ++ch) {
        const uint8_t *q = blk + 8 * ch * nblocks;
        rad__bc4_palette(q[0], q[1], pal[ch]);
        for (k = 0; k < 8; ++k) pal[ch][k] *= scale[ch];
    }
    (void)b;
}
#endif

/* 3xBC4: each block decoded on the fly (the palette vectors permuted by the 3-bit indices,
   8 texels per multiply-add). A lookup table over half-rows would need 8 palette slots for
   2 texels, twice the multiply-adds of this decode. */
static void rad__mb_bapply_task(void *data, uint32_t t)
{
    const rad__mb_bapply *a = (const rad__mb_bapply *)data;
    const rad_multibounce_blocks *b = a->b;
    uint32_t bpr = b->blocks_per_row, by0 = (uint32_t)((uint64_t)bpr * t / a->tasks), by1 = (uint32_t)((uint64_t)bpr * (t + 1) / a->tasks);
    uint32_t by, bx, ch, y, x, i;
    size_t nblocks = (size_t)bpr * bpr;
    for (by = by0; by < by1; ++by) {
        float acc[3][4];
        const uint8_t *row = b->blocks + 8 * (size_t)by * bpr;
#if defined(RAD__MB_AVX2)
        __m256 v0 = _mm256_setzero_ps(), v1 = _mm256_setzero_ps(), v2 = _mm256_setzero_ps();
        float lanes[8];
        const __m256i seven = _mm256_set1_epi32(7);
        const __m256i s4a = _mm256_setr_epi32(0, 12, 0, 12, 3, 15, 3, 15), s4b = _mm256_setr_epi32(6, 18, 6, 18, 9, 21, 9, 21);
        const float *srow = b->scales + 3 * (size_t)(b->tile ? (by * 4u / b->tile) * b->tiles_per_row : 0u);
        /* BC4 palette lane k = (W0[k] r0 + W1[k] r1 + C[k]) / D[k]: the decoder's integer
           numerator over its denominator (lanes 0, 1: the endpoints over 255; 6-value mode
           lanes 6, 7: the constants 0 and 1 over 1); index [0] the 6-value mode (r0 <= r1),
           [1] the 8-value one */
        __m256 bw0[2], bw1[2], bc[2], bd[2], br[2];
        bw0[0] = _mm256_setr_ps(1.0f, 0.0f, 4.0f, 3.0f, 2.0f, 1.0f, 0.0f, 0.0f);     /* 6-value mode (r0 <= r1) */
        bw1[0] = _mm256_setr_ps(0.0f, 1.0f, 1.0f, 2.0f, 3.0f, 4.0f, 0.0f, 0.0f);
        bc[0] = _mm256_setr_ps(0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 1.0f);
        bd[0] = _mm256_setr_ps(255.0f, 255.0f, 1275.0f, 1275.0f, 1275.0f, 1275.0f, 1.0f, 1.0f);
        bw0[1] = _mm256_setr_ps(1.0f, 0.0f, 6.0f, 5.0f, 4.0f, 3.0f, 2.0f, 1.0f);     /* 8-value mode */
        bw1[1] = _mm256_setr_ps(0.0f, 1.0f, 1.0f, 2.0f, 3.0f, 4.0f, 5.0f, 6.0f);
        bc[1] = _mm256_setzero_ps();
        bd[1] = _mm256_setr_ps(255.0f, 255.0f, 1785.0f, 1785.0f, 1785.0f, 1785.0f, 1785.0f, 1785.0f);
        br[0] = _mm256_div_ps(_mm256_set1_ps(1.0f), bd[0]);
        br[1] = _mm256_div_ps(_mm256_set1_ps(1.0f), bd[1]);
        for (bx = 0; bx < bpr; ++bx) {
            const uint8_t *blk = row + 8 * (size_t)bx;
            const float *scale = srow + 3 * (size_t)a->tile_col[bx];
            const float *xe = a->xe + 16 * (size_t)bx;
            size_t xs = 16 * (size_t)bpr;
            __m256 *vv[3];
            vv[0] = &v0; vv[1] = &v1; vv[2] = &v2;
            for (ch = 0; ch < 3; ++ch) {
                const uint8_t *q = blk + 8 * ch * nblocks;
                int lo = (int)((uint32_t)q[2] | (uint32_t)q[3] << 8 | (uint32_t)q[4] << 16);
                int hi = (int)((uint32_t)q[5] | (uint32_t)q[6] << 8 | (uint32_t)q[7] << 16);
                __m256i wv = _mm256_setr_epi32(lo, lo, hi, hi, lo, lo, hi, hi);
                /* branch-free: the encoder mixes both modes */
                uint32_t m = q[0] > q[1];
                __m256 num = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(bw0[m], _mm256_set1_ps((float)q[0])),
                                                         _mm256_mul_ps(bw1[m], _mm256_set1_ps((float)q[1]))), bc[m]);
                __m256 p = _mm256_mul_ps(rad__mb_div(num, bd[m], br[m]), _mm256_set1_ps(scale[ch]));
                __m256i ia = _mm256_and_si256(_mm256_srlv_epi32(wv, s4a), seven), ib = _mm256_and_si256(_mm256_srlv_epi32(wv, s4b), seven);
                *vv[ch] = RAD__MB_MADD(_mm256_permutevar8x32_ps(p, ia), _mm256_loadu_ps(xe + ch * xs), *vv[ch]);
                *vv[ch] = RAD__MB_MADD(_mm256_permutevar8x32_ps(p, ib), _mm256_loadu_ps(xe + ch * xs + 8), *vv[ch]);
            }
        }
        _mm256_storeu_ps(lanes, v0); for (y = 0; y < 4; ++y) acc[0][y] = lanes[y] + lanes[4 + y];
        _mm256_storeu_ps(lanes, v1); for (y = 0; y < 4; ++y) acc[1][y] = lanes[y] + lanes[4 + y];
        _mm256_storeu_ps(lanes, v2); for (y = 0; y < 4; ++y) acc[2][y] = lanes[y] + lanes[4 + y];
        (void)x;
#else
        memset(acc, 0, sizeof(acc));
        for (bx = 0; bx < bpr; ++bx) {
            const uint8_t *blk = row + 8 * (size_t)bx;
            const float *scale = b->scales + 3 * (size_t)rad__mb_tile_index(b, bx, by);
            float pal[3][8];
            rad__mb_block_palettes(b, blk, nblocks, scale, pal);
            for (ch = 0; ch < 3; ++ch) {
                uint64_t bits = rad__bc4_bits(blk + 8 * ch * nblocks);
                for (y = 0; y < 4; ++y)
                    for (x = 0; x < 4; ++x)
                        acc[ch][y] += pal[ch][(bits >> (3 * (4 * y + x))) & 7u] * a->xp[(size_t)ch * a->padded + 4 * bx + x];
            }
        }
#endif
        for (ch = 0; ch < 3; ++ch)
            for (y = 0; y < 4; ++y) a->y[(size_t)ch * a->padded + 4 * by + y] = acc[ch][y];
    }
    (void)i;
}

/* BC1 as a lookup-table product. Row y of a 4x4 block is one byte of indices (2 bits per
   texel), and that row's share of out is sum_x pal[idx_x] E_x = sum_k pal[k] M_k(byte) with
   M_k(byte) the sum of the block column's four E values whose index is k. The palette is
   linear in the endpoints (per channel, codes a and b over d = 31 or 63): 4-colour mode
   (a, b, (2a + b)/3, (a + 2b)/3)/d, 3-colour mode (a, b, (a + b)/2, 0)/d, so
       sum_k pal[k] M_k = (a/d) A + (b/d) B,  A = M_0 + (2 M_2 + M_3)/3, B = M_1 + (M_2 + 2 M_3)/3
   (3-colour: A = M_0 + M_2/2, B = M_1 + M_2/2). Per apply, per block column, a table of A
   and B for the 256 bytes in both modes (12 floats per byte: R G B of A and B in 3-colour
   mode, then in 4-colour mode); a block row costs, per block, its endpoints as one vector
   (a_R a_G a_B b_R b_G b_B)/d and one multiply-add per row with the entry of the row's byte
   in the block's mode. No palette is formed: 6 multiply-adds for 12 texel-channels. The tile
   scale multiplies a row's sum over the blocks of one scale tile once. The result equals
   decode-then-multiply up to float rounding (the palette's thirds are folded into the table
   instead of rounded per block; tests/test_multibounce.c allows 1e-5 of the magnitude).
   Block columns go in passes of RAD__MB_LUT_PASS (2.25 MiB of tables, kept in L3): per pass
   two parallel loops, the pass's tables (parallel over columns), then every block row over
   them, in tiles of RAD__MB_LUT_TILE columns (768 KiB of tables; L2 is 1 MiB here) so that a
   tile's tables stay in L2 while a task's block rows pass over them (BENCHMARKS.md: 1.2x
   faster than the exact palette per block). Slower alternatives measured: all tables first
   (1.5x slower at N = 5696: 17 MB of tables written and read back through DRAM, more than
   the 15 MB of blocks), tables per task (the work repeats in every task, 64 by default),
   16-float entries (one cache line each), palettes looked up in tables over the endpoint
   codes (L2 traffic), the exact palette per block times sums by code (M_0..M_3: the palette
   was two thirds of the instructions), nibble tables small enough for L1 (twice the loads:
   2x slower), the outliers added inside the block loop (their rows then come in permuted
   order), a sweep down two block columns at a time with their tables in L1 and the row sums
   in memory (2.8x slower at N = 5696: consecutive block rows are a row of blocks apart,
   11 KiB, so every block is on another page). */
#define RAD__MB_LUT_TILE 64u
#define RAD__MB_LUT_PASS 192u
#define RAD__MB_LUT_ENTRY 12u
#define RAD__MB_LUT_STRIDE 3072u /* floats per block column: 256 entries of 12 */
#define RAD__MB_LUT_PAD 8u       /* zeros after a pass's tables: the 8-float load of the last entry's 4-colour half */

/* the tables of block columns bx0..bx1-1 into lut (RAD__MB_LUT_STRIDE floats per column) */
static void rad__mb_lut_build(const rad__mb_bapply *a, uint32_t bx0, uint32_t bx1, float *lut)
{
    /* weights of a texel with code k in A and B: 3-colour, then 4-colour mode */
    static const float wa[2][4] = { { 1.0f, 0.0f, 0.5f, 0.0f }, { 1.0f, 0.0f, 2.0f / 3.0f, 1.0f / 3.0f } };
    static const float wb[2][4] = { { 0.0f, 1.0f, 0.5f, 0.0f }, { 0.0f, 1.0f, 1.0f / 3.0f, 2.0f / 3.0f } };
    uint32_t bx, v, ch, j, m, x;
    for (bx = bx0; bx < bx1; ++bx) {
        /* lo[n]: texels 0 and 1 with the codes of nibble n; hi[n]: texels 2 and 3 */
        float lo[16][12], hi[16][12];
        float *T = lut + RAD__MB_LUT_STRIDE * (size_t)(bx - bx0);
        for (v = 0; v < 16; ++v)
            for (m = 0; m < 2; ++m)
                for (ch = 0; ch < 3; ++ch) {
                    const float *e = a->xp + (size_t)ch * a->padded + 4 * (size_t)bx;
                    float la = 0.0f, lb = 0.0f, ha = 0.0f, hb = 0.0f;
                    for (x = 0; x < 2; ++x) {
                        const uint32_t code = (v >> (2 * x)) & 3u;
                        la += wa[m][code] * e[x];
                        lb += wb[m][code] * e[x];
                        ha += wa[m][code] * e[2 + x];
                        hb += wb[m][code] * e[2 + x];
                    }
                    lo[v][6 * m + ch] = la;
                    lo[v][6 * m + 3 + ch] = lb;
                    hi[v][6 * m + ch] = ha;
                    hi[v][6 * m + 3 + ch] = hb;
                }
        for (v = 0; v < 256; ++v)
            for (j = 0; j < RAD__MB_LUT_ENTRY; ++j) T[RAD__MB_LUT_ENTRY * v + j] = lo[v & 15u][j] + hi[v >> 4][j];
    }
}

static void rad__mb_lut_task(void *data, uint32_t t)
{
    const rad__mb_bapply *a = (const rad__mb_bapply *)data;
    uint32_t w = a->c1 - a->c0, bx0 = a->c0 + w * t / a->tasks, bx1 = a->c0 + w * (t + 1) / a->tasks;
    rad__mb_lut_build(a, bx0, bx1, a->lut + RAD__MB_LUT_STRIDE * (size_t)(bx0 - a->c0));
}

static void rad__mb_bc1_task(void *data, uint32_t t)
{
    const rad__mb_bapply *a = (const rad__mb_bapply *)data;
    const rad_multibounce_blocks *b = a->b;
    uint32_t bpr = b->blocks_per_row, by0 = (uint32_t)((uint64_t)bpr * t / a->tasks), by1 = (uint32_t)((uint64_t)bpr * (t + 1) / a->tasks);
    uint32_t tb = b->tile ? b->tile / 4u : bpr, c0, c1, by, bx, s, e, ch, y;
#if defined(RAD__MB_AVX2)
    /* endpoints (a_R a_G a_B b_R b_G b_B 0 0) / d from the word c0 | c1 << 16 on 8 lanes */
    const __m256i ep_shift = _mm256_setr_epi32(11, 5, 0, 27, 21, 16, 0, 0);
    const __m256i ep_mask = _mm256_setr_epi32(31, 63, 31, 31, 63, 31, 0, 0);
    const __m256 ep_rcp = _mm256_setr_ps(1.0f / 31.0f, 1.0f / 63.0f, 1.0f / 31.0f, 1.0f / 31.0f, 1.0f / 63.0f, 1.0f / 31.0f, 0.0f, 0.0f);
    const __m256i to_b = _mm256_setr_epi32(3, 4, 5, 6, 7, 7, 7, 7);
#endif
    for (c0 = a->c0; c0 < a->c1; c0 = c1) {
        const float *lut = a->lut + RAD__MB_LUT_STRIDE * (size_t)(c0 - a->c0);
        c1 = a->c1 - c0 < RAD__MB_LUT_TILE ? a->c1 : c0 + RAD__MB_LUT_TILE;
        for (by = by0; by < by1; ++by) {
            const uint8_t *row = b->blocks + 8 * (size_t)by * bpr;
            for (s = c0; s < c1; s = e) {
                const float *scale = b->scales + 3 * (size_t)rad__mb_tile_index(b, s, by);
                float *yo = a->y2 + 16 * (size_t)t + 12 * (size_t)by;
                e = (s / tb + 1u) * tb;
                if (e > c1) e = c1;
#if defined(RAD__MB_AVX2)
                {
                    __m256 r0 = _mm256_setzero_ps(), r1 = _mm256_setzero_ps(), r2 = _mm256_setzero_ps(), r3 = _mm256_setzero_ps();
                    __m128 q0, q1, q2, q3;
                    for (bx = s; bx < e; ++bx) {
                        const uint8_t *blk = row + 8 * (size_t)bx;
                        const uint32_t k0 = (uint32_t)blk[0] | (uint32_t)blk[1] << 8, k1 = (uint32_t)blk[2] | (uint32_t)blk[3] << 8;
                        /* the row's entry in the block's mode: 3-colour at +0, 4-colour (c0 > c1)
                           at +6; by arithmetic, not a comparison, which gcc 12 made a branch (the
                           encoder mixes both modes: mispredicted about half the time, 1.2x slower) */
                        const float *T = lut + RAD__MB_LUT_STRIDE * (size_t)(bx - c0) + 6u * ((k1 - k0) >> 31);
                        const __m256 ep = _mm256_mul_ps(
                            _mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srlv_epi32(_mm256_set1_epi32((int)(k0 | k1 << 16)), ep_shift), ep_mask)),
                            ep_rcp);
                        r0 = RAD__MB_MADD(ep, _mm256_loadu_ps(T + RAD__MB_LUT_ENTRY * (size_t)blk[4]), r0);
                        r1 = RAD__MB_MADD(ep, _mm256_loadu_ps(T + RAD__MB_LUT_ENTRY * (size_t)blk[5]), r1);
                        r2 = RAD__MB_MADD(ep, _mm256_loadu_ps(T + RAD__MB_LUT_ENTRY * (size_t)blk[6]), r2);
                        r3 = RAD__MB_MADD(ep, _mm256_loadu_ps(T + RAD__MB_LUT_ENTRY * (size_t)blk[7]), r3);
                    }
                    /* lanes 0-2 (a/d) A and 3-5 (b/d) B: row y's RGB = their sum (lanes 6-7:
                       zero endpoints times whatever followed the entry, never used) */
                    q0 = _mm_add_ps(_mm256_castps256_ps128(r0), _mm256_castps256_ps128(_mm256_permutevar8x32_ps(r0, to_b)));
                    q1 = _mm_add_ps(_mm256_castps256_ps128(r1), _mm256_castps256_ps128(_mm256_permutevar8x32_ps(r1, to_b)));
                    q2 = _mm_add_ps(_mm256_castps256_ps128(r2), _mm256_castps256_ps128(_mm256_permutevar8x32_ps(r2, to_b)));
                    q3 = _mm_add_ps(_mm256_castps256_ps128(r3), _mm256_castps256_ps128(_mm256_permutevar8x32_ps(r3, to_b)));
                    _MM_TRANSPOSE4_PS(q0, q1, q2, q3); /* q0 = R of rows 0-3, q1 = G, q2 = B */
                    _mm_storeu_ps(yo, _mm_add_ps(_mm_loadu_ps(yo), _mm_mul_ps(q0, _mm_set1_ps(scale[0]))));
                    _mm_storeu_ps(yo + 4, _mm_add_ps(_mm_loadu_ps(yo + 4), _mm_mul_ps(q1, _mm_set1_ps(scale[1]))));
                    _mm_storeu_ps(yo + 8, _mm_add_ps(_mm_loadu_ps(yo + 8), _mm_mul_ps(q2, _mm_set1_ps(scale[2]))));
                    (void)ch;
                    (void)y;
                }
#else
                {
                    /* acc[y][j]: row y's sum of ep[j] times the entry's j-th value */
                    float acc[4][6];
                    uint32_t j;
                    memset(acc, 0, sizeof(acc));
                    for (bx = s; bx < e; ++bx) {
                        const uint8_t *blk = row + 8 * (size_t)bx;
                        const uint32_t k0 = (uint32_t)blk[0] | (uint32_t)blk[1] << 8, k1 = (uint32_t)blk[2] | (uint32_t)blk[3] << 8;
                        const float *T = lut + RAD__MB_LUT_STRIDE * (size_t)(bx - c0) + 6u * ((k1 - k0) >> 31);
                        float ep[6];
                        ep[0] = (float)((k0 >> 11) & 31u) * (1.0f / 31.0f);
                        ep[1] = (float)((k0 >> 5) & 63u) * (1.0f / 63.0f);
                        ep[2] = (float)(k0 & 31u) * (1.0f / 31.0f);
                        ep[3] = (float)((k1 >> 11) & 31u) * (1.0f / 31.0f);
                        ep[4] = (float)((k1 >> 5) & 63u) * (1.0f / 63.0f);
                        ep[5] = (float)(k1 & 31u) * (1.0f / 31.0f);
                        for (y = 0; y < 4; ++y) {
                            const float *m = T + RAD__MB_LUT_ENTRY * (size_t)blk[4 + y];
                            for (j = 0; j < 6; ++j) acc[y][j] += ep[j] * m[j];
                        }
                    }
                    for (ch = 0; ch < 3; ++ch)
                        for (y = 0; y < 4; ++y) yo[4 * ch + y] += (acc[y][ch] + acc[y][3 + ch]) * scale[ch];
                }
#endif
            }
        }
    }
}

static void rad__mb_outlier_task(void *data, uint32_t t)
{
    const rad__mb_bapply *a = (const rad__mb_bapply *)data;
    const rad_multibounce_blocks *b = a->b;
    uint32_t i0 = (uint32_t)((uint64_t)b->n * t / a->tasks), i1 = (uint32_t)((uint64_t)b->n * (t + 1) / a->tasks), i;
    for (i = i0; i < i1; ++i) {
        uint64_t k;
        float s0 = 0.0f, s1 = 0.0f, s2 = 0.0f;
        for (k = b->outlier_offsets[i]; k < b->outlier_offsets[i + 1]; ++k) {
            const float *v = b->outlier_values + 3 * k, *e = a->E + 3 * (size_t)b->outlier_columns[k];
            s0 += v[0] * e[0];
            s1 += v[1] * e[1];
            s2 += v[2] * e[2];
        }
        a->out[3 * (size_t)i] += s0;
        a->out[3 * (size_t)i + 1] += s1;
        a->out[3 * (size_t)i + 2] += s2;
    }
}

static rad_result rad__mb_blocks_check(const rad_multibounce_blocks *b)
{
    if (!b || b->n == 0 || !b->blocks || !b->scales || b->blocks_per_row != (b->n + 3u) / 4u) return RAD_ERROR_INVALID_ARGUMENT;
    if ((b->row_perm == NULL) != (b->col_perm == NULL)) return RAD_ERROR_INVALID_ARGUMENT;
    if (b->outlier_count && (!b->outlier_offsets || !b->outlier_columns || !b->outlier_values)) return RAD_ERROR_INVALID_ARGUMENT;
    return RAD_SUCCESS;
}

RAD_API rad_result rad_multibounce_blocks_apply(const rad_multibounce_blocks *b, const float *E, float *out, rad_output output,
                                                const rad_context *ctx)
{
    rad__ctx c;
    rad__mb_bapply a;
    float *scratch, *xe;
    uint32_t *tile_col, n, padded, bpr, bx, ch, h, l;
    size_t i, tabs;
    int bc1;
    rad__ctx_init(&c, ctx);
    if (rad__mb_blocks_check(b) != RAD_SUCCESS || !E || !out || E == out) return RAD_ERROR_INVALID_ARGUMENT;
    n = b->n;
    if (rad__check_input(&c, "rad_multibounce_blocks_apply", E, 3 * (size_t)n) != RAD_SUCCESS) return RAD_ERROR_NON_FINITE;
    bpr = b->blocks_per_row;
    padded = 4u * bpr;
    bc1 = b->format == RAD_BLOCK_BC1;
    /* xp, y (3 padded each), then xe (BC4: 12 padded) or the tables of one pass and y2 (BC1) */
    a.tasks = c.tasks < bpr ? c.tasks : bpr;
    tabs = bc1 ? (size_t)(bpr < RAD__MB_LUT_PASS ? bpr : RAD__MB_LUT_PASS) * RAD__MB_LUT_STRIDE + RAD__MB_LUT_PAD + 12 * (size_t)bpr + 16 * (size_t)a.tasks
               : 12 * (size_t)padded;
    if (!rad__mul3((size_t)padded, 6u, sizeof(float), &i) || tabs > ((size_t)-1 - i) / sizeof(float))
        return RAD_ERROR_SIZE_OVERFLOW;
    scratch = (float *)rad__alloc(&c.allocator, i + tabs * sizeof(float));
    if (!scratch) return RAD_ERROR_OUT_OF_MEMORY;
    rad__mb_gather(E, b->col_perm, n, padded, scratch);
    xe = scratch + 6 * (size_t)padded;
    if (!bc1)
        for (ch = 0; ch < 3; ++ch)
            for (bx = 0; bx < bpr; ++bx)
                for (h = 0; h < 2; ++h)
                    for (l = 0; l < 8; ++l)
                        xe[(size_t)ch * 16 * bpr + 16 * (size_t)bx + 8 * h + l] = scratch[(size_t)ch * padded + 4 * bx + 2 * h + l / 4];
    tile_col = (uint32_t *)rad__alloc_array(&c.allocator, bpr, sizeof(uint32_t));
    if (!tile_col) { rad__free(&c.allocator, scratch); return RAD_ERROR_OUT_OF_MEMORY; }
    for (bx = 0; bx < bpr; ++bx) tile_col[bx] = b->tile ? bx * 4u / b->tile : 0u;
    a.tile_col = tile_col;
    a.b = b;
    a.xp = scratch;
    a.xe = xe;
    a.lut = xe;
    a.y = scratch + 3 * (size_t)padded;
    a.padded = padded;
    a.E = E;
    a.out = out;
    if (bc1) {
        /* per pass: its tables (parallel over columns), then all block rows over them */
        uint32_t t, tasks = a.tasks, by, y;
        a.y2 = xe + (size_t)(bpr < RAD__MB_LUT_PASS ? bpr : RAD__MB_LUT_PASS) * RAD__MB_LUT_STRIDE + RAD__MB_LUT_PAD;
        memset(a.y2 - RAD__MB_LUT_PAD, 0, (RAD__MB_LUT_PAD + 12 * (size_t)bpr + 16 * (size_t)tasks) * sizeof(float));
        for (a.c0 = 0; a.c0 < bpr; a.c0 = a.c1) {
            a.c1 = bpr - a.c0 < RAD__MB_LUT_PASS ? bpr : a.c0 + RAD__MB_LUT_PASS;
            a.tasks = c.tasks < a.c1 - a.c0 ? c.tasks : a.c1 - a.c0;
            c.parallel_for(c.parallel_user, a.tasks, rad__mb_lut_task, &a);
            a.tasks = tasks;
            c.parallel_for(c.parallel_user, a.tasks, rad__mb_bc1_task, &a);
        }
        for (t = 0; t < tasks; ++t)
            for (by = (uint32_t)((uint64_t)bpr * t / tasks); by < (uint32_t)((uint64_t)bpr * (t + 1) / tasks); ++by)
                for (ch = 0; ch < 3; ++ch)
                    for (y = 0; y < 4; ++y) a.y[(size_t)ch * padded + 4 * by + y] = a.y2[16 * (size_t)t + 12 * (size_t)by + 4 * ch + y];
    } else {
        a.tasks = c.tasks < bpr ? c.tasks : bpr;
        c.parallel_for(c.parallel_user, a.tasks, rad__mb_bapply_task, &a);
    }
    rad__mb_scatter(a.y, padded, b->row_perm, n, out);
    if (b->outlier_count) {
        a.tasks = c.tasks < n ? c.tasks : n;
        c.parallel_for(c.parallel_user, a.tasks, rad__mb_outlier_task, &a);
    }
    if (output == RAD_OUTPUT_TOTAL)
        for (i = 0; i < 3 * (size_t)n; ++i) out[i] += E[i];
    rad__free(&c.allocator, scratch);
    rad__free(&c.allocator, tile_col);
    return rad__check_output(&c, "rad_multibounce_blocks_apply", out, 3 * (size_t)n);
}

RAD_API rad_result rad_multibounce_blocks_decode(const rad_multibounce_blocks *b, float *out_planes, const rad_context *ctx)
{
    uint32_t n, bpr, bx, by, t, ch, i;
    size_t nn, nblocks;
    (void)ctx;
    if (rad__mb_blocks_check(b) != RAD_SUCCESS || !out_planes) return RAD_ERROR_INVALID_ARGUMENT;
    n = b->n;
    nn = (size_t)n * n;
    bpr = b->blocks_per_row;
    nblocks = (size_t)bpr * bpr;
    for (by = 0; by < bpr; ++by)
        for (bx = 0; bx < bpr; ++bx) {
            const float *scale = b->scales + 3 * (size_t)rad__mb_tile_index(b, bx, by);
            float dec[48];
            if (b->format == RAD_BLOCK_BC1) {
                rad_bc1_decode_block(b->blocks + 8 * ((size_t)by * bpr + bx), dec);
            } else {
                for (ch = 0; ch < 3; ++ch) {
                    float d[16];
                    rad_bc4_decode_block(b->blocks + 8 * (ch * nblocks + (size_t)by * bpr + bx), d);
                    for (t = 0; t < 16; ++t) dec[3 * t + ch] = d[t];
                }
            }
            for (t = 0; t < 16; ++t) {
                uint32_t y = by * 4u + t / 4u, x = bx * 4u + t % 4u, oy, ox;
                if (y >= n || x >= n) continue;
                oy = b->row_perm ? b->row_perm[y] : y;
                ox = b->col_perm ? b->col_perm[x] : x;
                for (ch = 0; ch < 3; ++ch) out_planes[ch * nn + (size_t)oy * n + ox] = dec[3 * t + ch] * scale[ch];
            }
        }
    for (i = 0; i < n && b->outlier_count; ++i) {
        uint64_t k;
        for (k = b->outlier_offsets[i]; k < b->outlier_offsets[i + 1]; ++k)
            for (ch = 0; ch < 3; ++ch) out_planes[ch * nn + (size_t)i * n + b->outlier_columns[k]] += b->outlier_values[3 * k + ch];
    }
    return RAD_SUCCESS;
}

/* ---- container sections ---- */

RAD_API rad_result rad_multibounce_sections(const rad_multibounce *mb, const char *name, rad_section *s, uint32_t *out_count)
{
    uint32_t k = 0;
    uint64_t total;
    if (!s || !out_count) return RAD_ERROR_INVALID_ARGUMENT;
    *out_count = 0;
    if (rad__mb_check(mb) != RAD_SUCCESS) return RAD_ERROR_INVALID_ARGUMENT;
    total = 3u * (uint64_t)mb->n * mb->n;
    rad__section(&s[k++], RAD_SECTION_MB_INFO, sizeof(uint32_t), 16, mb->info, name);
    if (mb->planes) rad__section(&s[k++], RAD_SECTION_MB_FLOAT, sizeof(float), total, mb->planes, name);
    else rad__section(&s[k++], RAD_SECTION_MB_HALF, sizeof(uint16_t), total, mb->half, name);
    if (mb->row_perm) {
        rad__section(&s[k++], RAD_SECTION_MB_ROW_PERM, sizeof(uint32_t), mb->n, mb->row_perm, name);
        rad__section(&s[k++], RAD_SECTION_MB_COL_PERM, sizeof(uint32_t), mb->n, mb->col_perm, name);
    }
    *out_count = k;
    return RAD_SUCCESS;
}

RAD_API rad_result rad_multibounce_blocks_sections(const rad_multibounce_blocks *b, const char *name, rad_section *s,
                                                   uint32_t *out_count)
{
    uint32_t k = 0;
    uint64_t nblocks;
    if (!s || !out_count) return RAD_ERROR_INVALID_ARGUMENT;
    *out_count = 0;
    if (rad__mb_blocks_check(b) != RAD_SUCCESS) return RAD_ERROR_INVALID_ARGUMENT;
    nblocks = (uint64_t)b->blocks_per_row * b->blocks_per_row;
    rad__section(&s[k++], RAD_SECTION_MB_INFO, sizeof(uint32_t), 16, b->info, name);
    if (b->format == RAD_BLOCK_BC1) rad__section(&s[k++], RAD_SECTION_MB_BC1, 8, nblocks, b->blocks, name);
    else rad__section(&s[k++], RAD_SECTION_MB_BC4, 8, 3 * nblocks, b->blocks, name);
    rad__section(&s[k++], RAD_SECTION_MB_SCALES, 3 * sizeof(float), (uint64_t)b->tiles_per_row * b->tiles_per_row, b->scales, name);
    if (b->row_perm) {
        rad__section(&s[k++], RAD_SECTION_MB_ROW_PERM, sizeof(uint32_t), b->n, b->row_perm, name);
        rad__section(&s[k++], RAD_SECTION_MB_COL_PERM, sizeof(uint32_t), b->n, b->col_perm, name);
    }
    if (b->outlier_count) {
        rad__section(&s[k++], RAD_SECTION_MB_OUTLIER_OFFSETS, sizeof(uint64_t), (uint64_t)b->n + 1u, b->outlier_offsets, name);
        rad__section(&s[k++], RAD_SECTION_MB_OUTLIER_COLUMNS, sizeof(uint32_t), b->outlier_count, b->outlier_columns, name);
        rad__section(&s[k++], RAD_SECTION_MB_OUTLIER_VALUES, 3 * sizeof(float), b->outlier_count, b->outlier_values, name);
    }
    *out_count = k;
    return RAD_SUCCESS;
}

/* the section of 'type' called 'name' with elem_size and count as given (CORRUPT otherwise) */
static rad_result rad__mb_section(const rad__ctx *c, const rad_container *ct, uint32_t type, const char *name, uint32_t elem_size,
                                  uint64_t count, const void **out)
{
    const rad_section *s = rad_container_find(ct, type, name);
    *out = NULL;
    if (!s) {
        rad__log(c, RAD_LOG_ERROR, "multibounce '%s': section type %u is missing", name ? name : "", type);
        return RAD_ERROR_CORRUPT;
    }
    if (s->elem_size != elem_size || s->count != count) {
        rad__log(c, RAD_LOG_ERROR, "multibounce '%s': section type %u has %llu elements of %u bytes, expected %llu of %u",
                 name ? name : "", type, (unsigned long long)s->count, s->elem_size, (unsigned long long)count, elem_size);
        return RAD_ERROR_CORRUPT;
    }
    *out = s->data;
    return RAD_SUCCESS;
}

static rad_result rad__mb_load_info(const rad__ctx *c, const rad_container *ct, const char *name, uint32_t *info)
{
    const void *p;
    rad_result r = rad__mb_section(c, ct, RAD_SECTION_MB_INFO, name, sizeof(uint32_t), 16, &p);
    if (r != RAD_SUCCESS) return r;
    memcpy(info, p, 16 * sizeof(uint32_t));
    if (info[0] != 1u) {
        rad__log(c, RAD_LOG_ERROR, "multibounce '%s': info version %u (expected 1)", name ? name : "", info[0]);
        return RAD_ERROR_VERSION;
    }
    if (info[2] == 0 || info[3] == 0 || info[1] > 3u || (info[6] & ~3u)) {
        rad__log(c, RAD_LOG_ERROR, "multibounce '%s': bad info record (kind %u, N %u, K %u, flags %u)", name ? name : "", info[1],
                 info[2], info[3], info[6]);
        return RAD_ERROR_CORRUPT;
    }
    return RAD_SUCCESS;
}

/* both permutations (when flagged), checked to be bijections of [0, n) */
static rad_result rad__mb_load_perms(const rad__ctx *c, const rad_container *ct, const char *name, uint32_t n, int present,
                                     const uint32_t **row_perm, const uint32_t **col_perm)
{
    const void *p[2];
    unsigned char *seen;
    uint32_t k, i;
    rad_result r = RAD_SUCCESS;
    *row_perm = *col_perm = NULL;
    if (!present) return RAD_SUCCESS;
    if ((r = rad__mb_section(c, ct, RAD_SECTION_MB_ROW_PERM, name, sizeof(uint32_t), n, &p[0])) != RAD_SUCCESS) return r;
    if ((r = rad__mb_section(c, ct, RAD_SECTION_MB_COL_PERM, name, sizeof(uint32_t), n, &p[1])) != RAD_SUCCESS) return r;
    seen = (unsigned char *)rad__alloc(&c->allocator, n);
    if (!seen) return RAD_ERROR_OUT_OF_MEMORY;
    for (k = 0; k < 2 && r == RAD_SUCCESS; ++k) {
        const uint32_t *perm = (const uint32_t *)p[k];
        memset(seen, 0, n);
        for (i = 0; i < n; ++i) {
            if (perm[i] >= n || seen[perm[i]]) {
                rad__log(c, RAD_LOG_ERROR, "multibounce '%s': the %s permutation is not a bijection (entry %u = %u)", name ? name : "",
                         k == 0 ? "row" : "column", i, perm[i]);
                r = RAD_ERROR_CORRUPT;
                break;
            }
            seen[perm[i]] = 1;
        }
    }
    rad__free(&c->allocator, seen);
    if (r == RAD_SUCCESS) { *row_perm = (const uint32_t *)p[0]; *col_perm = (const uint32_t *)p[1]; }
    return r;
}

/* rad__check_values for binary16 F_mb planes: every value finite and >= 0 (any finite half is
   below RAD_BAKE_VALUE_MAX) */
static rad_result rad__check_halves(const rad__ctx *c, const char *name, const uint16_t *h, uint64_t n)
{
    uint64_t i;
    uint32_t bad = 0;
    for (i = 0; i < n; ++i) bad |= (uint32_t)((h[i] & 0x7FFFu) >= 0x7C00u) | (uint32_t)(h[i] > 0x8000u);
    if (!bad) return RAD_SUCCESS;
    for (i = 0; i < n; ++i)
        if ((h[i] & 0x7FFFu) >= 0x7C00u || h[i] > 0x8000u) {
            const int nonfinite = (h[i] & 0x7FFFu) >= 0x7C00u;
            rad__log(c, RAD_LOG_ERROR, "baked data: multibounce '%s' half planes (MB_HALF): entry %llu is %g (%s)", name ? name : "",
                     (unsigned long long)i, (double)rad_half_to_float(h[i]), nonfinite ? "not finite" : "negative");
            return nonfinite ? RAD_ERROR_NON_FINITE : RAD_ERROR_CORRUPT;
        }
    return RAD_SUCCESS;
}

RAD_API rad_result rad_multibounce_load(const rad_container *ct, const char *name, const rad_context *ctx, rad_multibounce **out)
{
    rad__ctx c;
    rad_multibounce *mb;
    uint32_t info[16];
    const void *data;
    uint64_t total;
    rad_result r;
    rad__ctx_init(&c, ctx);
    if (!out) return RAD_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    if (!ct) return RAD_ERROR_INVALID_ARGUMENT;
    r = rad__mb_load_info(&c, ct, name, info);
    if (r != RAD_SUCCESS) return r;
    if (info[1] > 1u || (info[6] & 2u)) {
        rad__log(&c, RAD_LOG_ERROR, "multibounce '%s': kind %u is not a dense matrix", name ? name : "", info[1]);
        return RAD_ERROR_CORRUPT;
    }
    total = 3u * (uint64_t)info[2] * info[2];
    if (total / 3u / info[2] != info[2] || total > (uint64_t)((size_t)-1) / 4u) return RAD_ERROR_SIZE_OVERFLOW;
    r = rad__mb_section(&c, ct, info[1] ? RAD_SECTION_MB_HALF : RAD_SECTION_MB_FLOAT, name, info[1] ? 2u : 4u, total, &data);
    if (r != RAD_SUCCESS) return r;
    if (info[1]) {
        r = rad__check_halves(&c, name, (const uint16_t *)data, total);
    } else {
        char what[64];
        snprintf(what, sizeof(what), "multibounce '%s' float planes (MB_FLOAT)", name ? name : "");
        r = rad__check_values(&c, what, (const float *)data, total, 1);
    }
    if (r != RAD_SUCCESS) return r;
    mb = (rad_multibounce *)rad__alloc(&c.allocator, sizeof(*mb));
    if (!mb) return RAD_ERROR_OUT_OF_MEMORY;
    memset(mb, 0, sizeof(*mb));
    mb->allocator = c.allocator;
    mb->n = info[2];
    mb->bounces = info[3];
    mb->precision = info[1] ? RAD_MB_HALF : RAD_MB_FLOAT;
    if (info[1]) mb->half = (const uint16_t *)data;
    else mb->planes = (const float *)data;
    memcpy(mb->info, info, sizeof(info));
    r = rad__mb_load_perms(&c, ct, name, mb->n, (info[6] & 1u) != 0, &mb->row_perm, &mb->col_perm);
    if (r != RAD_SUCCESS) { rad_multibounce_destroy(mb); return r; }
    *out = mb;
    return RAD_SUCCESS;
}

RAD_API rad_result rad_multibounce_blocks_load(const rad_container *ct, const char *name, const rad_context *ctx,
                                               rad_multibounce_blocks **out)
{
    rad__ctx c;
    rad_multibounce_blocks *b;
    uint32_t info[16], n, bpr, tpr;
    const void *p;
    uint64_t nblocks, i;
    rad_result r;
    rad__ctx_init(&c, ctx);
    if (!out) return RAD_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    if (!ct) return RAD_ERROR_INVALID_ARGUMENT;
    r = rad__mb_load_info(&c, ct, name, info);
    if (r != RAD_SUCCESS) return r;
    n = info[2];
    bpr = (uint32_t)(((uint64_t)n + 3u) / 4u);
    tpr = info[4] ? (uint32_t)(((uint64_t)n + info[4] - 1u) / info[4]) : 1u;
    if (info[1] < 2u || (info[4] % 4u) != 0 || info[5] != tpr) {
        rad__log(&c, RAD_LOG_ERROR, "multibounce '%s': kind %u, tile %u, %u tiles per row do not describe blocks of N = %u",
                 name ? name : "", info[1], info[4], info[5], n);
        return RAD_ERROR_CORRUPT;
    }
    b = (rad_multibounce_blocks *)rad__alloc(&c.allocator, sizeof(*b));
    if (!b) return RAD_ERROR_OUT_OF_MEMORY;
    memset(b, 0, sizeof(*b));
    b->allocator = c.allocator;
    b->n = n;
    b->bounces = info[3];
    b->format = info[1] == 2u ? RAD_BLOCK_BC1 : RAD_BLOCK_BC4X3;
    b->blocks_per_row = bpr;
    b->tile = info[4];
    b->tiles_per_row = tpr;
    memcpy(b->info, info, sizeof(info));
    nblocks = (uint64_t)bpr * bpr;
    r = rad__mb_section(&c, ct, info[1] == 2u ? RAD_SECTION_MB_BC1 : RAD_SECTION_MB_BC4, name, 8, info[1] == 2u ? nblocks : 3u * nblocks, &p);
    b->blocks = (const uint8_t *)p;
    if (r == RAD_SUCCESS) {
        r = rad__mb_section(&c, ct, RAD_SECTION_MB_SCALES, name, 3 * sizeof(float), (uint64_t)tpr * tpr, &p);
        b->scales = (const float *)p;
        if (r == RAD_SUCCESS) {
            char what[64];
            snprintf(what, sizeof(what), "multibounce '%s' block scales (MB_SCALES)", name ? name : "");
            r = rad__check_values(&c, what, b->scales, 3u * (uint64_t)tpr * tpr, 1);
        }
    }
    if (r == RAD_SUCCESS) r = rad__mb_load_perms(&c, ct, name, n, (info[6] & 1u) != 0, &b->row_perm, &b->col_perm);
    if (r == RAD_SUCCESS && (info[6] & 2u)) {
        const rad_section *cols = rad_container_find(ct, RAD_SECTION_MB_OUTLIER_COLUMNS, name);
        r = rad__mb_section(&c, ct, RAD_SECTION_MB_OUTLIER_OFFSETS, name, sizeof(uint64_t), (uint64_t)n + 1u, &p);
        b->outlier_offsets = (const uint64_t *)p;
        if (r == RAD_SUCCESS) {
            b->outlier_count = b->outlier_offsets[n];
            if (!cols || b->outlier_offsets[0] != 0) {
                rad__log(&c, RAD_LOG_ERROR, "multibounce '%s': outlier offsets do not start at 0 or columns are missing", name ? name : "");
                r = RAD_ERROR_CORRUPT;
            }
            for (i = 0; i < n && r == RAD_SUCCESS; ++i)
                if (b->outlier_offsets[i + 1] < b->outlier_offsets[i]) {
                    rad__log(&c, RAD_LOG_ERROR, "multibounce '%s': outlier offsets decrease at row %u", name ? name : "", (uint32_t)i);
                    r = RAD_ERROR_CORRUPT;
                }
        }
        if (r == RAD_SUCCESS) r = rad__mb_section(&c, ct, RAD_SECTION_MB_OUTLIER_COLUMNS, name, sizeof(uint32_t), b->outlier_count, &p);
        b->outlier_columns = (const uint32_t *)p;
        if (r == RAD_SUCCESS) r = rad__mb_section(&c, ct, RAD_SECTION_MB_OUTLIER_VALUES, name, 3 * sizeof(float), b->outlier_count, &p);
        b->outlier_values = (const float *)p;
        for (i = 0; i < b->outlier_count && r == RAD_SUCCESS; ++i)
            if (b->outlier_columns[i] >= n) {
                rad__log(&c, RAD_LOG_ERROR, "multibounce '%s': outlier %llu has column %u >= N = %u", name ? name : "",
                         (unsigned long long)i, b->outlier_columns[i], n);
                r = RAD_ERROR_INDEX_OUT_OF_RANGE;
            }
        if (r == RAD_SUCCESS) {
            char what[64];
            snprintf(what, sizeof(what), "multibounce '%s' outliers (MB_OUTLIER_VALUES)", name ? name : "");
            r = rad__check_values(&c, what, b->outlier_values, 3u * b->outlier_count, 1);
        }
    }
    if (r != RAD_SUCCESS) { rad_multibounce_blocks_destroy(b); return r; }
    *out = b;
    return RAD_SUCCESS;
}

/* ======================================================================================== */
/* >>local: local multi-bounce matrix for large scenes                                      */
/* ======================================================================================== */

static rad_result rad__row_matrix_fetch(void *user, uint32_t row, uint32_t capacity, uint32_t *out_columns,
                                        float *out_values, uint32_t *out_count)
{
    const rad_matrix *F = (const rad_matrix *)user;
    uint32_t k = 0, j;
    if (row >= F->rows) return RAD_ERROR_INDEX_OUT_OF_RANGE;
    if (F->storage == RAD_STORAGE_DENSE) {
        const float *r = F->dense + (size_t)row * F->cols;
        for (j = 0; j < F->cols; ++j)
            if (r[j] != 0.0f) {
                if (k >= capacity) return RAD_ERROR_SIZE_MISMATCH;
                out_columns[k] = j;
                out_values[k++] = r[j];
            }
    } else {
        uint64_t b = F->row_offsets[row], e = F->row_offsets[row + 1], p;
        if (e < b || e - b > capacity) return RAD_ERROR_SIZE_MISMATCH;
        for (p = b; p < e; ++p) {
            out_columns[k] = F->columns[p];
            out_values[k++] = F->values[p];
        }
    }
    *out_count = k;
    return RAD_SUCCESS;
}

RAD_API rad_result rad_row_source_matrix(const rad_matrix *F, const float *areas, const float *albedo,
                                         rad_row_source *out)
{
    if (!F || !areas || !albedo || !out) return RAD_ERROR_INVALID_ARGUMENT;
    if (F->rows == 0 || (F->storage == RAD_STORAGE_DENSE ? !F->dense : (F->storage != RAD_STORAGE_SPARSE || !F->row_offsets ||
                                                                        !F->columns || !F->values)))
        return RAD_ERROR_INVALID_ARGUMENT;
    if (F->rows != F->cols) return RAD_ERROR_SIZE_MISMATCH;
    memset(out, 0, sizeof(*out));
    out->n = F->rows;
    out->areas = areas;
    out->albedo = albedo;
    out->fetch = rad__row_matrix_fetch;
    out->user = (void *)(uintptr_t)F;
    return RAD_SUCCESS;
}

RAD_API rad_result rad_row_source_bake(const rad_bake *bake, rad_row_source *out)
{
    if (!bake || !out || bake->F.rows == 0 || bake->F.rows != bake->patches.count) return RAD_ERROR_INVALID_ARGUMENT;
    return rad_row_source_matrix(&bake->F, bake->patches.areas, bake->patches.albedo, out);
}

#ifndef RAD_NO_STDIO
struct rad_row_stream {
    FILE *f;
    uint32_t n;
    float *areas, *albedo;
    uint64_t *offsets;         /* n + 1 */
    uint64_t col_at, val_at;   /* file offsets of the CSR columns and values */
    size_t bytes;
    rad_allocator allocator;
    rad__ctx log;              /* the context given at open: fetch failures are logged through it */
};

RAD_API void rad_row_stream_close(rad_row_stream *s)
{
    rad_allocator a;
    if (!s) return;
    a = s->allocator;
    if (s->f) fclose(s->f);
    rad__free(&a, s->areas);
    rad__free(&a, s->albedo);
    rad__free(&a, s->offsets);
    rad__free(&a, s);
}

static int rad__stream_read(FILE *f, uint64_t at, void *dst, size_t bytes)
{
    if (at > (uint64_t)LONG_MAX || fseek(f, (long)at, SEEK_SET) != 0) return 0;
    return fread(dst, 1, bytes, f) == bytes;
}

static rad_result rad__stream_fetch(void *user, uint32_t row, uint32_t capacity, uint32_t *out_columns, float *out_values,
                                    uint32_t *out_count)
{
    rad_row_stream *s = (rad_row_stream *)user;
    uint64_t b, e;
    uint32_t k, count;
    if (row >= s->n) return RAD_ERROR_INDEX_OUT_OF_RANGE;
    b = s->offsets[row];
    e = s->offsets[row + 1];
    if (e - b > capacity) return RAD_ERROR_SIZE_MISMATCH;
    count = (uint32_t)(e - b);
    if (count > 0 && (!rad__stream_read(s->f, s->col_at + 4u * b, out_columns, 4u * (size_t)count) ||
                      !rad__stream_read(s->f, s->val_at + 4u * b, out_values, 4u * (size_t)count)))
        return RAD_ERROR_IO;
    /* the matrix sections are not checksummed here (that would read them whole): every row
       is checked for what CSR promises instead, ascending columns below n and values >= 0 */
    for (k = 0; k < count; ++k)
        if (out_columns[k] >= s->n || (k > 0 && out_columns[k] <= out_columns[k - 1]) || !rad__finite(out_values[k]) ||
            out_values[k] < 0.0f) {
            rad__log(&s->log, RAD_LOG_ERROR, "row stream: row %u entry %u (column %u, value %g) breaks the CSR rules "
                     "(ascending columns < %u, finite values >= 0): the file is corrupt", row, k, out_columns[k],
                     (double)out_values[k], s->n);
            return RAD_ERROR_CORRUPT;
        }
    *out_count = count;
    return RAD_SUCCESS;
}

RAD_API void rad_row_stream_source(rad_row_stream *s, rad_row_source *out)
{
    if (!out) return;
    memset(out, 0, sizeof(*out));
    if (!s) return;
    out->n = s->n;
    out->areas = s->areas;
    out->albedo = s->albedo;
    out->fetch = rad__stream_fetch;
    out->user = s;
}

RAD_API size_t rad_row_stream_memory(const rad_row_stream *s) { return s ? s->bytes : 0; }

RAD_API rad_result rad_row_stream_open(const char *path, const rad_context *ctx, rad_row_stream **out)
{
    rad__ctx c;
    rad_row_stream *s;
    unsigned char head[RAD__HEADER_BYTES], *table = NULL, *buf = NULL;
    uint64_t file_size, actual, off[4] = {0, 0, 0, 0}, cnt[4] = {0, 0, 0, 0};
    uint32_t count, i, crc[4] = {0, 0, 0, 0}, found = 0;
    long end;
    rad_result r = RAD_SUCCESS;
    rad__ctx_init(&c, ctx);
    if (!out) return RAD_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    if (!path) return RAD_ERROR_INVALID_ARGUMENT;
    s = (rad_row_stream *)rad__alloc(&c.allocator, sizeof(rad_row_stream));
    if (!s) return RAD_ERROR_OUT_OF_MEMORY;
    memset(s, 0, sizeof(*s));
    s->allocator = c.allocator;
    s->log = c;
    s->f = fopen(path, "rb");
    if (!s->f) {
        rad__log(&c, RAD_LOG_ERROR, "row stream: cannot open '%s'", path);
        rad_row_stream_close(s);
        return RAD_ERROR_IO;
    }
    if (fseek(s->f, 0, SEEK_END) != 0 || (end = ftell(s->f)) < 0) { r = RAD_ERROR_IO; goto fail; }
    actual = (uint64_t)end;
    if (actual < RAD__HEADER_BYTES || !rad__stream_read(s->f, 0, head, RAD__HEADER_BYTES)) {
        rad__log(&c, RAD_LOG_ERROR, "row stream: '%s' is shorter than the container header", path);
        r = RAD_ERROR_TRUNCATED;
        goto fail;
    }
    if (memcmp(head, "RADB", 4) != 0 || rad__get32(head + 60) != rad__crc32(head, 60)) {
        rad__log(&c, RAD_LOG_ERROR, "row stream: '%s': no RADB magic or a bad header checksum", path);
        r = RAD_ERROR_CORRUPT;
        goto fail;
    }
    if (rad__get32(head + 4) != RAD_CONTAINER_VERSION || (rad__get32(head + 32) & ~RAD__FLAG_BIG_ENDIAN) != 0u ||
        ((rad__get32(head + 32) & RAD__FLAG_BIG_ENDIAN) != 0u) != rad__host_big_endian()) {
        rad__log(&c, RAD_LOG_ERROR, "row stream: '%s': container version %u or byte order this build does not read", path,
                 rad__get32(head + 4));
        r = RAD_ERROR_VERSION;
        goto fail;
    }
    count = rad__get32(head + 8);
    file_size = rad__get64(head + 24);
    if (rad__get64(head + 16) != RAD__HEADER_BYTES || count > 0x00FFFFFFu) { r = RAD_ERROR_CORRUPT; goto fail; }
    if (file_size > actual) {
        rad__log(&c, RAD_LOG_ERROR, "row stream: '%s' has %llu bytes, the container %llu", path, (unsigned long long)actual,
                 (unsigned long long)file_size);
        r = RAD_ERROR_TRUNCATED;
        goto fail;
    }
    table = (unsigned char *)rad__alloc_array(&c.allocator, count ? count : 1u, RAD__ENTRY_BYTES);
    if (!table) { r = RAD_ERROR_OUT_OF_MEMORY; goto fail; }
    if ((uint64_t)RAD__HEADER_BYTES + (uint64_t)RAD__ENTRY_BYTES * count > file_size ||
        !rad__stream_read(s->f, RAD__HEADER_BYTES, table, (size_t)RAD__ENTRY_BYTES * count)) {
        r = RAD_ERROR_TRUNCATED;
        goto fail;
    }
    if (rad__get32(head + 36) != rad__crc32(table, (size_t)RAD__ENTRY_BYTES * count)) {
        rad__log(&c, RAD_LOG_ERROR, "row stream: '%s': section table checksum mismatch", path);
        r = RAD_ERROR_CORRUPT;
        goto fail;
    }
    /* 0: patches, 1: row offsets, 2: columns, 3: values (the first of each type) */
    for (i = 0; i < count; ++i) {
        const unsigned char *e = table + (size_t)RAD__ENTRY_BYTES * i;
        uint32_t type = rad__get32(e), esz = rad__get32(e + 4), want, slot;
        uint64_t n = rad__get64(e + 8), at = rad__get64(e + 16), bytes = rad__get64(e + 24);
        if (type == RAD_SECTION_PATCHES) { slot = 0; want = (uint32_t)sizeof(rad_patch); }
        else if (type == RAD_SECTION_FF_ROW_OFFSETS) { slot = 1; want = 8u; }
        else if (type == RAD_SECTION_FF_COLUMNS) { slot = 2; want = 4u; }
        else if (type == RAD_SECTION_FF_VALUES) { slot = 3; want = 4u; }
        else continue;
        if (found & (1u << slot)) continue;
        if (esz != want || n > UINT64_MAX / esz || n * esz != bytes || bytes > file_size || at > file_size - bytes) {
            rad__log(&c, RAD_LOG_ERROR, "row stream: '%s': section %u (type %u) has a bad size or extends past the end", path, i, type);
            r = RAD_ERROR_CORRUPT;
            goto fail;
        }
        off[slot] = at;
        cnt[slot] = n;
        crc[slot] = rad__get32(e + 32);
        found |= 1u << slot;
    }
    if (found != 15u || cnt[0] == 0 || cnt[0] > 0xFFFFFFFEu || cnt[1] != cnt[0] + 1 || cnt[2] != cnt[3]) {
        rad__log(&c, RAD_LOG_ERROR, "row stream: '%s' holds no patches with a CSR form-factor matrix of matching size", path);
        r = found != 15u ? RAD_ERROR_INVALID_ARGUMENT : RAD_ERROR_CORRUPT;
        goto fail;
    }
    s->n = (uint32_t)cnt[0];
    s->col_at = off[2];
    s->val_at = off[3];
    s->areas = (float *)rad__alloc_array(&c.allocator, s->n, sizeof(float));
    s->albedo = (float *)rad__alloc_array(&c.allocator, s->n, 3 * sizeof(float));
    s->offsets = (uint64_t *)rad__alloc_array(&c.allocator, (size_t)s->n + 1u, sizeof(uint64_t));
    buf = (unsigned char *)rad__alloc_array(&c.allocator, s->n, sizeof(rad_patch));
    if (!s->areas || !s->albedo || !s->offsets || !buf) { r = RAD_ERROR_OUT_OF_MEMORY; goto fail; }
    s->bytes = sizeof(*s) + (size_t)s->n * 16u + ((size_t)s->n + 1u) * 8u;
    if (!rad__stream_read(s->f, off[0], buf, (size_t)s->n * sizeof(rad_patch)) ||
        !rad__stream_read(s->f, off[1], s->offsets, ((size_t)s->n + 1u) * 8u)) {
        r = RAD_ERROR_IO;
        goto fail;
    }
    if (rad__crc32(buf, (size_t)s->n * sizeof(rad_patch)) != crc[0] || rad__crc32((const unsigned char *)s->offsets, ((size_t)s->n + 1u) * 8u) != crc[1]) {
        rad__log(&c, RAD_LOG_ERROR, "row stream: '%s': checksum mismatch in the patches or the row offsets", path);
        r = RAD_ERROR_CORRUPT;
        goto fail;
    }
    for (i = 0; i < s->n; ++i) {
        rad_patch p;
        uint32_t k;
        memcpy(&p, buf + (size_t)i * sizeof(rad_patch), sizeof(rad_patch));
        s->areas[i] = p.area;
        for (k = 0; k < 3; ++k) s->albedo[3 * (size_t)i + k] = p.albedo[k];
        if (s->offsets[i + 1] < s->offsets[i]) {
            rad__log(&c, RAD_LOG_ERROR, "row stream: '%s': row offsets decrease at row %u", path, i);
            r = RAD_ERROR_CORRUPT;
            goto fail;
        }
    }
    if (s->offsets[0] != 0 || s->offsets[s->n] != cnt[2]) {
        rad__log(&c, RAD_LOG_ERROR, "row stream: '%s': row offsets do not span the %llu entries", path, (unsigned long long)cnt[2]);
        r = RAD_ERROR_CORRUPT;
        goto fail;
    }
    rad__free(&c.allocator, table);
    rad__free(&c.allocator, buf);
    *out = s;
    return RAD_SUCCESS;
fail:
    if (r == RAD_ERROR_IO) rad__log(&c, RAD_LOG_ERROR, "row stream: reading '%s' failed", path);
    rad__free(&c.allocator, table);
    rad__free(&c.allocator, buf);
    rad_row_stream_close(s);
    return r;
}
#endif

RAD_API void rad_local_options_default(rad_local_options *options)
{
    if (!options) return;
    memset(options, 0, sizeof(*options));
    options->capacity = 1024;
    options->update = RAD_LOCAL_EXACT;
    options->evict = RAD_LOCAL_EVICT_DOWNDATE;
    options->rebuild = RAD_LOCAL_REBUILD_INVERSE;
}

/* private scratch of a rad_local */
typedef struct rad__local_scratch {
    uint32_t *row_columns;   /* n: the fetched row */
    float *row_values;       /* n */
    double *a, *b, *u, *v;   /* 3 M each, channel-major: x[c * M + slot] */
    float *vf;               /* 3 M: v rounded to float for the update passes */
    double *cc;              /* 3 M: column of the slot evicted by a fused add */
    uint32_t *nz;            /* M: slots where the new row is non-zero */
    uint8_t *seen;           /* n bits, all clear between fetches: repeated columns are rejected */
} rad__local_scratch;

typedef struct rad__local_storage {
    float *planes;
    uint32_t *slot_patch, *patch_slot;
    uint8_t *slot_hidden;
    uint64_t *hide_order;    /* M: when each hidden member was hidden */
    uint64_t hide_clock;
    rad__local_scratch s;
    size_t bytes;
} rad__local_storage;

RAD_API void rad_local_destroy(rad_local *local)
{
    rad_allocator a;
    if (!local) return;
    a = local->allocator;
    rad__free(&a, local->storage);
    rad__free(&a, local);
}

RAD_API rad_result rad_local_create(const rad_row_source *source, const rad_local_options *options,
                                    const rad_context *ctx, rad_local **out)
{
    rad__ctx c;
    rad_local_options o;
    rad_local *L;
    rad__local_storage *st;
    size_t sizes[14], total = 0, mm, off, part;
    unsigned char *mem;
    uint32_t i, M, k;
    rad__ctx_init(&c, ctx);
    if (out) *out = NULL;
    if (!source || !out) return RAD_ERROR_INVALID_ARGUMENT;
    if (options) o = *options; else rad_local_options_default(&o);
    if (!source->fetch || !source->areas || !source->albedo || source->n == 0) {
        rad__log(&c, RAD_LOG_ERROR, "rad_local_create: the row source needs n > 0, fetch, areas and albedo");
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    if (o.capacity == 0 || o.capacity > source->n || (o.update != RAD_LOCAL_EXACT && o.update != RAD_LOCAL_FIRST_ORDER) ||
        (o.evict != RAD_LOCAL_EVICT_DOWNDATE && o.evict != RAD_LOCAL_EVICT_DROP) ||
        (o.rebuild != RAD_LOCAL_REBUILD_INVERSE && o.rebuild != RAD_LOCAL_REBUILD_NEUMANN)) {
        rad__log(&c, RAD_LOG_ERROR, "rad_local_create: capacity %u must be in [1, n = %u], update and evict 0 or 1 (got %d, %d)",
                 o.capacity, source->n, (int)o.update, (int)o.evict);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    for (i = 0; i < source->n; ++i) {
        float ar = source->areas[i];
        if (!rad__finite(ar) || !(ar > 0.0f)) {
            rad__log(&c, RAD_LOG_ERROR, "rad_local_create: area of patch %u is %g (must be finite and > 0)", i, (double)ar);
            return RAD_ERROR_INVALID_ARGUMENT;
        }
        for (k = 0; k < 3; ++k) {
            float rho = source->albedo[3 * (size_t)i + k];
            if (!(rho >= 0.0f && rho < 1.0f)) {
                rad__log(&c, RAD_LOG_ERROR, "rad_local_create: albedo of patch %u channel %u is %g (must be in [0,1))", i, k,
                         (double)rho);
                return RAD_ERROR_ALBEDO_RANGE;
            }
        }
    }
    M = o.capacity;
    if (!rad__mul3((size_t)M, (size_t)M, 3 * sizeof(float), &mm)) return RAD_ERROR_SIZE_OVERFLOW;
    sizes[0] = mm;                                       /* planes */
    sizes[1] = (size_t)M * sizeof(uint32_t);             /* slot_patch */
    sizes[2] = (size_t)source->n * sizeof(uint32_t);     /* patch_slot */
    sizes[3] = (size_t)source->n * sizeof(uint32_t);     /* row_columns */
    sizes[4] = (size_t)source->n * sizeof(float);        /* row_values */
    sizes[5] = (size_t)M * 3 * sizeof(double);           /* a */
    sizes[6] = sizes[5];                                 /* b */
    sizes[7] = 2 * sizes[5];                             /* u, v */
    sizes[8] = (size_t)M * sizeof(uint32_t);             /* nz */
    sizes[9] = (size_t)M;                                /* slot_hidden */
    sizes[10] = (size_t)M * sizeof(uint64_t);            /* hide_order */
    sizes[11] = (size_t)M * 3 * sizeof(float);           /* vf */
    sizes[12] = (size_t)M * 3 * sizeof(double);          /* cc */
    sizes[13] = ((size_t)source->n + 7u) / 8u;           /* seen */
    total = sizeof(rad__local_storage);
    for (k = 0; k < 14; ++k) {
        part = (sizes[k] + 63u) & ~(size_t)63u;
        if (part < sizes[k] || total + part < total) return RAD_ERROR_SIZE_OVERFLOW;
        total += part;
    }
    L = (rad_local *)rad__alloc(&c.allocator, sizeof(rad_local));
    if (!L) return RAD_ERROR_OUT_OF_MEMORY;
    memset(L, 0, sizeof(*L));
    L->allocator = c.allocator;
    mem = (unsigned char *)rad__alloc(&c.allocator, total + 64u);
    if (!mem) { rad__free(&c.allocator, L); return RAD_ERROR_OUT_OF_MEMORY; }
    L->storage = mem;
    st = (rad__local_storage *)mem;
    memset(st, 0, sizeof(*st));
    off = ((size_t)(uintptr_t)(mem + sizeof(rad__local_storage)) + 63u) & ~(size_t)63u;
    off -= (size_t)(uintptr_t)mem;
    st->planes = (float *)(mem + off); off += (sizes[0] + 63u) & ~(size_t)63u;
    st->slot_patch = (uint32_t *)(mem + off); off += (sizes[1] + 63u) & ~(size_t)63u;
    st->patch_slot = (uint32_t *)(mem + off); off += (sizes[2] + 63u) & ~(size_t)63u;
    st->s.row_columns = (uint32_t *)(mem + off); off += (sizes[3] + 63u) & ~(size_t)63u;
    st->s.row_values = (float *)(mem + off); off += (sizes[4] + 63u) & ~(size_t)63u;
    st->s.a = (double *)(mem + off); off += (sizes[5] + 63u) & ~(size_t)63u;
    st->s.b = (double *)(mem + off); off += (sizes[6] + 63u) & ~(size_t)63u;
    st->s.u = (double *)(mem + off);
    st->s.v = st->s.u + (size_t)3 * M; off += (sizes[7] + 63u) & ~(size_t)63u;
    st->s.nz = (uint32_t *)(mem + off); off += (sizes[8] + 63u) & ~(size_t)63u;
    st->slot_hidden = (uint8_t *)(mem + off); off += (sizes[9] + 63u) & ~(size_t)63u;
    st->hide_order = (uint64_t *)(mem + off); off += (sizes[10] + 63u) & ~(size_t)63u;
    st->s.vf = (float *)(mem + off); off += (sizes[11] + 63u) & ~(size_t)63u;
    st->s.cc = (double *)(mem + off); off += (sizes[12] + 63u) & ~(size_t)63u;
    st->s.seen = (uint8_t *)(mem + off);
    memset(st->s.seen, 0, sizes[13]);
    memset(st->slot_hidden, 0, M);
    st->bytes = total + 64u + sizeof(rad_local);
    memset(st->planes, 0, mm);
    for (i = 0; i < M; ++i) st->slot_patch[i] = RAD_NONE;
    for (i = 0; i < source->n; ++i) st->patch_slot[i] = RAD_NONE;
    L->capacity = M;
    L->n = source->n;
    L->update = o.update;
    L->evict = o.evict;
    L->rebuild = o.rebuild;
    L->slot_hidden = st->slot_hidden;
    L->source = *source;
    L->slot_patch = st->slot_patch;
    L->patch_slot = st->patch_slot;
    L->planes = st->planes;
    L->scratch = &st->s;
    *out = L;
    return RAD_SUCCESS;
}

RAD_API size_t rad_local_memory(const rad_local *local)
{
    return local && local->storage ? ((const rad__local_storage *)local->storage)->bytes : 0;
}

/* ranges [begin, end) of 'count' items split over tasks */
typedef struct rad__local_job {
    rad__local_storage *st;
    uint32_t M, end, tasks, nnz;
    double cuv[3];             /* rank-1 factor per channel */
    uint32_t ev;               /* fused add: the slot evicted in the same pass, else RAD_NONE */
    double g[3];               /* fused add: 1 + T_ee per channel */
    const uint32_t *rows;      /* apply: visible slots */
    uint32_t row_count;
    const float *e;            /* apply: 3 * end floats, channel-major */
    float *y;                  /* apply: 3 per visible row */
} rad__local_job;

static void rad__local_range(uint32_t count, uint32_t tasks, uint32_t t, uint32_t *b, uint32_t *e)
{
    *b = (uint32_t)((uint64_t)count * t / tasks);
    *e = (uint32_t)((uint64_t)count * (t + 1) / tasks);
}

/* u_i = a_i + sum_j T_ij a_j over the slots, in double */
static void rad__local_u_task(void *data, uint32_t t)
{
    const rad__local_job *J = (const rad__local_job *)data;
    const rad__local_scratch *s = &J->st->s;
    size_t MM = (size_t)J->M * J->M;
    uint32_t i0, i1, i, ch, p;
    rad__local_range(J->end, J->tasks, t, &i0, &i1);
    for (ch = 0; ch < 3; ++ch) {
        const double *a = s->a + (size_t)ch * J->M;
        double *u = s->u + (size_t)ch * J->M;
        for (i = i0; i < i1; ++i) {
            const float *row = J->st->planes + ch * MM + (size_t)i * J->M;
            double acc = a[i];
            /* a is non-zero only on the slots of the new row: a sparse gather, exact in double */
            for (p = 0; p < J->nnz; ++p) {
                uint32_t j = s->nz[p];
                acc += (double)row[j] * a[j];
            }
            u[i] = acc;
        }
    }
}

/* v_j = b_j + sum_{i in nz} b_i T_ij for the task's column block */
static void rad__local_v_task(void *data, uint32_t t)
{
    const rad__local_job *J = (const rad__local_job *)data;
    const rad__local_scratch *s = &J->st->s;
    size_t MM = (size_t)J->M * J->M;
    uint32_t j0, j1, j, ch, p;
    rad__local_range(J->end, J->tasks, t, &j0, &j1);
    for (ch = 0; ch < 3; ++ch) {
        const double *b = s->b + (size_t)ch * J->M;
        double *v = s->v + (size_t)ch * J->M;
        for (j = j0; j < j1; ++j) v[j] = b[j];
        for (p = 0; p < J->nnz; ++p) {
            uint32_t i = s->nz[p];
            const float *row = J->st->planes + ch * MM + (size_t)i * J->M;
            double bi = b[i];
            for (j = j0; j < j1; ++j) v[j] += bi * (double)row[j];
        }
    }
}

/* T_ij += (cuv u_i) v_j over the task's rows, in float (u, v and s were accumulated in
   double; this pass is bandwidth-bound and vectorises) */
static void rad__local_update_task(void *data, uint32_t t)
{
    const rad__local_job *J = (const rad__local_job *)data;
    const rad__local_scratch *s = &J->st->s;
    size_t MM = (size_t)J->M * J->M;
    uint32_t i0, i1, i, j, ch;
    rad__local_range(J->end, J->tasks, t, &i0, &i1);
    for (ch = 0; ch < 3; ++ch) {
        const double *u = s->u + (size_t)ch * J->M;
        const float *v = s->vf + (size_t)ch * J->M;
        if (J->ev == RAD_NONE) {
            for (i = i0; i < i1; ++i) {
                float *row = J->st->planes + ch * MM + (size_t)i * J->M;
                float ui = (float)(J->cuv[ch] * u[i]);
                if (ui == 0.0f) continue;
                for (j = 0; j < J->end; ++j) row[j] += ui * v[j];
            }
        } else {
            /* rank 2: the downdate of slot e and the new patch's update in one pass */
            const float *re = J->st->planes + ch * MM + (size_t)J->ev * J->M;
            const double *cc = s->cc + (size_t)ch * J->M;
            for (i = i0; i < i1; ++i) {
                float *row = J->st->planes + ch * MM + (size_t)i * J->M;
                float ui = (float)(J->cuv[ch] * u[i]), ci = (float)(-cc[i] / J->g[ch]);
                if (i == J->ev || (ui == 0.0f && ci == 0.0f)) continue;
                for (j = 0; j < J->end; ++j) row[j] += ci * re[j] + ui * v[j];
            }
        }
    }
}

/* tasks for a pass over 'count' rows of 'count' entries: one (run inline) while the pass is
   too small to pay for waking the default's OpenMP threads; a caller's parallel_for always
   gets the tasks. Every entry is computed by one task in a fixed order: the bits do not
   depend on the number of tasks. */
static uint32_t rad__local_tasks(const rad__ctx *c, uint32_t count)
{
    uint32_t t = c->tasks;
    if (c->parallel_for == rad__parallel_default && (uint64_t)count * count < 131072u) return 1u;
    if (t > count / 16u) t = count / 16u;
    return t ? t : 1u;
}

static void rad__local_run(const rad__ctx *c, uint32_t tasks, rad_task_fn fn, void *data)
{
    if (tasks == 1u) fn(data, 0);
    else c->parallel_for(c->parallel_user, tasks, fn, data);
}

/* fetches row 'patch' and checks it; *count entries in the scratch row */
static rad_result rad__local_fetch(const rad__ctx *c, rad_local *L, uint32_t patch, uint32_t *count)
{
    rad__local_scratch *s = (rad__local_scratch *)L->scratch;
    uint32_t k = 0, p;
    rad_result r = L->source.fetch(L->source.user, patch, L->n, s->row_columns, s->row_values, &k);
    if (r != RAD_SUCCESS) {
        rad__log(c, RAD_LOG_ERROR, "local matrix: fetching row %u failed: %s", patch, rad_result_string(r));
        return r;
    }
    if (k > L->n) {
        rad__log(c, RAD_LOG_ERROR, "local matrix: row %u has %u entries, more than n = %u", patch, k, L->n);
        return RAD_ERROR_SIZE_MISMATCH;
    }
    for (p = 0; p < k; ++p) {
        uint32_t j = s->row_columns[p];
        if (j >= L->n) {
            rad__log(c, RAD_LOG_ERROR, "local matrix: row %u has column %u >= n = %u", patch, j, L->n);
            r = RAD_ERROR_INDEX_OUT_OF_RANGE;
            break;
        }
        if (s->seen[j >> 3] & (1u << (j & 7u))) {
            rad__log(c, RAD_LOG_ERROR, "local matrix: row %u repeats column %u (a row source returns each column once)", patch, j);
            r = RAD_ERROR_CORRUPT;
            break;
        }
        s->seen[j >> 3] |= (uint8_t)(1u << (j & 7u));
        if (!rad__finite(s->row_values[p]) || s->row_values[p] < 0.0f) {
            rad__log(c, RAD_LOG_ERROR, "local matrix: F[%u][%u] = %g (must be finite and >= 0)", patch, j, (double)s->row_values[p]);
            r = RAD_ERROR_NON_FINITE;
            ++p;
            break;
        }
    }
    while (p-- > 0) s->seen[s->row_columns[p] >> 3] = 0; /* clears every byte this row set */
    if (r != RAD_SUCCESS) return r;
    *count = k;
    return RAD_SUCCESS;
}

static uint32_t rad__local_free_slot(const rad_local *L)
{
    uint32_t k;
    for (k = 0; k < L->capacity; ++k)
        if (L->slot_patch[k] == RAD_NONE) return k;
    return RAD_NONE;
}

RAD_API rad_result rad_local_add(rad_local *L, uint32_t patch, const rad_context *ctx)
{
    rad__ctx c;
    rad__local_storage *st;
    rad__local_scratch *s;
    rad__local_job J;
    uint32_t k, count = 0, p, ch, i, end, M, evicted = RAD_NONE;
    double ann[3], coef_col[3], coef_row[3], tnn[3], an, rho_n[3];
    size_t MM;
    rad_result r;
    rad__ctx_init(&c, ctx);
    if (!L) return RAD_ERROR_INVALID_ARGUMENT;
    if (patch >= L->n) {
        rad__log(&c, RAD_LOG_ERROR, "rad_local_add: patch %u >= n = %u", patch, L->n);
        return RAD_ERROR_INDEX_OUT_OF_RANGE;
    }
    st = (rad__local_storage *)L->storage;
    k = L->patch_slot[patch];
    if (k != RAD_NONE && st->slot_hidden[k]) {
        /* a hidden member: its transport is all there, it only becomes visible again */
        st->slot_hidden[k] = 0;
        L->hidden--;
        L->count++;
        return RAD_SUCCESS;
    }
    if (k != RAD_NONE || L->count >= L->capacity) {
        rad__log(&c, RAD_LOG_ERROR, "rad_local_add: patch %u %s", patch,
                 k != RAD_NONE ? "is already in the set" : "does not fit: the set is full of visible members");
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    s = &st->s;
    M = L->capacity;
    MM = (size_t)M * M;
    r = rad__local_fetch(&c, L, patch, &count);
    if (r != RAD_SUCCESS) return r;
    J.ev = RAD_NONE;
    if (L->count + L->hidden >= L->capacity) {
        /* full: evict the member hidden longest ago. The exact downdate is fused with this
           add (one rank-2 pass instead of two rank-1 passes): with c = T[:, e], r = T[e, :],
           g = 1 + T_ee, the add's vectors over the downdated T are u = a + T a - c (r.a) / g
           and v = b + b T - (b.c) r / g, and T += -c r / g + u v / s. The drop (RAD_LOCAL_EVICT_DROP) is
           cheap and done first. */
        uint32_t oldest = RAD_NONE;
        for (i = 0; i < L->slot_end; ++i)
            if (st->slot_hidden[i] && (oldest == RAD_NONE || st->hide_order[i] < st->hide_order[oldest])) oldest = i;
        if (L->evict == RAD_LOCAL_EVICT_DROP) {
            r = rad_local_evict(L, st->slot_patch[oldest], ctx);
            if (r != RAD_SUCCESS) return r;
        } else {
            J.ev = oldest;
            evicted = st->slot_patch[oldest];
            st->patch_slot[evicted] = RAD_NONE; /* its column is no longer part of the new row */
        }
    }
    k = J.ev != RAD_NONE ? J.ev : rad__local_free_slot(L);
    end = k + 1 > L->slot_end ? k + 1 : L->slot_end;
    for (ch = 0; ch < 3; ++ch) {
        memset(s->a + (size_t)ch * M, 0, sizeof(double) * end);
        memset(s->b + (size_t)ch * M, 0, sizeof(double) * end);
        ann[ch] = 0.0;
        rho_n[ch] = (double)L->source.albedo[3 * (size_t)patch + ch];
    }
    an = (double)L->source.areas[patch];
    J.nnz = 0;
    for (p = 0; p < count; ++p) {
        uint32_t j = s->row_columns[p], sj;
        double f = (double)s->row_values[p];
        if (f == 0.0) continue;
        if (j == patch) {
            for (ch = 0; ch < 3; ++ch) ann[ch] = rho_n[ch] * f;
            continue;
        }
        sj = L->patch_slot[j];
        if (sj == RAD_NONE) continue;
        for (ch = 0; ch < 3; ++ch) {
            /* column from reciprocity: F_jn = A_n F_nj / A_j */
            s->a[(size_t)ch * M + sj] = (double)L->source.albedo[3 * (size_t)j + ch] * (an * f / (double)L->source.areas[j]);
            s->b[(size_t)ch * M + sj] = rho_n[ch] * f;
        }
        s->nz[J.nnz++] = sj;
    }
    J.st = st;
    J.M = M;
    J.end = end;
    J.tasks = rad__local_tasks(&c, end);
    if (J.ev != RAD_NONE)
        for (ch = 0; ch < 3; ++ch) {
            const float *P = st->planes + ch * MM;
            double *cc = s->cc + (size_t)ch * M;
            J.g[ch] = 1.0 + (double)P[(size_t)J.ev * M + J.ev];
            for (i = 0; i < end; ++i) cc[i] = i == J.ev ? 0.0 : (double)P[(size_t)i * M + J.ev];
        }
    rad__local_run(&c, J.tasks, rad__local_u_task, &J);
    if (J.ev != RAD_NONE)
        for (ch = 0; ch < 3; ++ch) {
            double *u = s->u + (size_t)ch * M, ra = u[J.ev] / J.g[ch]; /* a_e = 0: u_e = (T a)_e = r.a */
            const double *cc = s->cc + (size_t)ch * M;
            for (i = 0; i < end; ++i) u[i] -= cc[i] * ra;
            u[J.ev] = 0.0;
        }
    for (ch = 0; ch < 3; ++ch) {
        double bu = 0.0, ba = 0.0, sv, d;
        for (p = 0; p < J.nnz; ++p) {
            uint32_t j = s->nz[p];
            bu += s->b[(size_t)ch * M + j] * s->u[(size_t)ch * M + j];
            ba += s->b[(size_t)ch * M + j] * s->a[(size_t)ch * M + j];
        }
        sv = 1.0 - ann[ch] - bu;
        if (!(sv > 1e-12) || sv != sv) {
            rad__log(&c, RAD_LOG_ERROR, "rad_local_add: patch %u channel %u: s = 1 - b.(I+T)a = %g <= 0 (the form factors or "
                     "albedos break energy conservation)", patch, ch, sv);
            if (evicted != RAD_NONE) st->patch_slot[evicted] = J.ev; /* nothing was written: the set is unchanged */
            return RAD_ERROR_SINGULAR;
        }
        if (L->update == RAD_LOCAL_EXACT) {
            coef_col[ch] = coef_row[ch] = J.cuv[ch] = 1.0 / sv;
            tnn[ch] = 1.0 / sv - 1.0;
        } else {
            d = ann[ch] + ba;
            coef_col[ch] = coef_row[ch] = 1.0 + d;
            J.cuv[ch] = (1.0 + d) * (1.0 + d);
            tnn[ch] = d;
        }
    }
    rad__local_run(&c, J.tasks, rad__local_v_task, &J);
    if (J.ev != RAD_NONE)
        for (ch = 0; ch < 3; ++ch) {
            double *v = s->v + (size_t)ch * M, bc = v[J.ev] / J.g[ch]; /* b_e = 0: v_e = (b T)_e = b.c */
            const float *re = st->planes + ch * MM + (size_t)J.ev * M;
            for (i = 0; i < end; ++i) v[i] -= bc * (double)re[i];
            v[J.ev] = 0.0;
        }
    for (i = 0; i < 3 * M; ++i) s->vf[i] = (float)s->v[i];
    rad__local_run(&c, J.tasks, rad__local_update_task, &J);
    for (ch = 0; ch < 3; ++ch) {
        float *P = st->planes + ch * MM;
        const double *u = s->u + (size_t)ch * M, *v = s->v + (size_t)ch * M;
        for (i = 0; i < end; ++i) {
            P[(size_t)k * M + i] = (float)(coef_row[ch] * v[i]);
            P[(size_t)i * M + k] = (float)(coef_col[ch] * u[i]);
        }
        P[(size_t)k * M + k] = (float)tnn[ch];
    }
    if (evicted != RAD_NONE) {
        st->slot_hidden[k] = 0;
        L->hidden--;
        L->evictions++;
    }
    st->slot_patch[k] = patch;
    st->patch_slot[patch] = k;
    L->slot_end = end;
    L->count++;
    L->adds++;
    return RAD_SUCCESS;
}

RAD_API rad_result rad_local_remove(rad_local *L, uint32_t patch, const rad_context *ctx)
{
    rad__ctx c;
    rad__local_storage *st;
    uint32_t k;
    rad__ctx_init(&c, ctx);
    if (!L) return RAD_ERROR_INVALID_ARGUMENT;
    if (patch >= L->n) {
        rad__log(&c, RAD_LOG_ERROR, "rad_local_remove: patch %u >= n = %u", patch, L->n);
        return RAD_ERROR_INDEX_OUT_OF_RANGE;
    }
    st = (rad__local_storage *)L->storage;
    k = L->patch_slot[patch];
    if (k == RAD_NONE || st->slot_hidden[k]) {
        rad__log(&c, RAD_LOG_ERROR, "rad_local_remove: patch %u is not a visible member", patch);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    st->slot_hidden[k] = 1;
    st->hide_order[k] = st->hide_clock++;
    L->count--;
    L->hidden++;
    L->removes++;
    return RAD_SUCCESS;
}

/* T_ij -= T_ik T_kj / (1 + T_kk) over the task's rows (i, j != k): the inverse of the
   system without slot k, from the block inverse formula */
static void rad__local_downdate_task(void *data, uint32_t t)
{
    const rad__local_job *J = (const rad__local_job *)data;
    size_t MM = (size_t)J->M * J->M;
    uint32_t i0, i1, i, j, ch, k = J->nnz;
    rad__local_range(J->end, J->tasks, t, &i0, &i1);
    for (ch = 0; ch < 3; ++ch) {
        float *P = J->st->planes + ch * MM;
        const float *v = J->st->s.vf + (size_t)ch * J->M;   /* row k / (1 + T_kk) */
        for (i = i0; i < i1; ++i) {
            float *row = P + (size_t)i * J->M;
            float tik = row[k];
            if (i == k || tik == 0.0f) continue;
            for (j = 0; j < J->end; ++j) row[j] -= tik * v[j];
            row[k] = 0.0f;
        }
    }
}

RAD_API rad_result rad_local_evict(rad_local *L, uint32_t patch, const rad_context *ctx)
{
    rad__ctx c;
    rad__local_storage *st;
    rad__local_job J;
    uint32_t k, i, j, ch, M;
    size_t MM;
    rad__ctx_init(&c, ctx);
    if (!L) return RAD_ERROR_INVALID_ARGUMENT;
    if (patch >= L->n) {
        rad__log(&c, RAD_LOG_ERROR, "rad_local_evict: patch %u >= n = %u", patch, L->n);
        return RAD_ERROR_INDEX_OUT_OF_RANGE;
    }
    k = L->patch_slot[patch];
    if (k == RAD_NONE) {
        rad__log(&c, RAD_LOG_ERROR, "rad_local_evict: patch %u is not a member", patch);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    st = (rad__local_storage *)L->storage;
    M = L->capacity;
    MM = (size_t)M * M;
    if (L->evict == RAD_LOCAL_EVICT_DOWNDATE) {
        for (ch = 0; ch < 3; ++ch) {
            const float *rowk = st->planes + ch * MM + (size_t)k * M;
            double g = 1.0 + (double)rowk[k];
            float *v = st->s.vf + (size_t)ch * M;
            for (j = 0; j < L->slot_end; ++j) v[j] = (float)((double)rowk[j] / g);
        }
        J.st = st;
        J.M = M;
        J.end = L->slot_end;
        J.nnz = k;
        J.tasks = rad__local_tasks(&c, J.end);
        rad__local_run(&c, J.tasks, rad__local_downdate_task, &J);
    }
    for (ch = 0; ch < 3; ++ch) {
        float *P = st->planes + ch * MM;
        memset(P + (size_t)k * M, 0, sizeof(float) * L->slot_end);
        for (i = 0; i < L->slot_end; ++i) P[(size_t)i * M + k] = 0.0f;
    }
    if (st->slot_hidden[k]) L->hidden--; else L->count--;
    st->slot_hidden[k] = 0;
    st->slot_patch[k] = RAD_NONE;
    st->patch_slot[patch] = RAD_NONE;
    while (L->slot_end > 0 && st->slot_patch[L->slot_end - 1] == RAD_NONE) L->slot_end--;
    L->evictions++;
    return RAD_SUCCESS;
}

static void rad__local_clear(rad_local *L)
{
    rad__local_storage *st = (rad__local_storage *)L->storage;
    uint32_t i, ch, M = L->capacity;
    size_t MM = (size_t)M * M;
    for (ch = 0; ch < 3; ++ch)
        for (i = 0; i < L->slot_end; ++i) memset(st->planes + ch * MM + (size_t)i * M, 0, sizeof(float) * L->slot_end);
    for (i = 0; i < M; ++i)
        if (st->slot_patch[i] != RAD_NONE) { st->patch_slot[st->slot_patch[i]] = RAD_NONE; st->slot_patch[i] = RAD_NONE; }
    memset(st->slot_hidden, 0, M);
    L->slot_end = 0;
    L->count = 0;
    L->hidden = 0;
}

#define RAD__LOCAL_NB 64u

/* In-place inverse of the m x m matrix X (leading dimension ld) by blocked Gauss-Jordan
   sweeps without pivoting (X = I - A is strictly diagonally dominant by rows, and so is
   every Schur complement met on the way). For the pivot block D with row panel R, column
   panel C and the rest O: D' = D^-1, R' = D^-1 R, C' = -C D^-1, O' = O - C D^-1 R; the last
   update, the whole cost (2 m^2 nb per block), runs through the packed GEMM. */
static rad_result rad__local_invert(const rad__ctx *c, float *X, uint32_t m, size_t ld)
{
    uint32_t kb, b, i, j, q;
    float *cbuf, *rbuf, *rp, *dinv, *tmp;
    double *d;
    rad_result r = RAD_SUCCESS;
    size_t mb = (size_t)m * RAD__LOCAL_NB;
    cbuf = (float *)rad__alloc_array(&c->allocator, mb, sizeof(float));
    rbuf = (float *)rad__alloc_array(&c->allocator, mb, sizeof(float));
    rp = (float *)rad__alloc_array(&c->allocator, mb, sizeof(float));
    tmp = (float *)rad__alloc_array(&c->allocator, mb, sizeof(float));
    dinv = (float *)rad__alloc_array(&c->allocator, (size_t)RAD__LOCAL_NB * RAD__LOCAL_NB, sizeof(float));
    d = (double *)rad__alloc_array(&c->allocator, (size_t)RAD__LOCAL_NB * 2u * RAD__LOCAL_NB, sizeof(double));
    if (!cbuf || !rbuf || !rp || !tmp || !dinv || !d) { r = RAD_ERROR_OUT_OF_MEMORY; goto done; }
    for (kb = 0; kb < m && r == RAD_SUCCESS; kb += b) {
        b = m - kb < RAD__LOCAL_NB ? m - kb : RAD__LOCAL_NB;
        /* D^-1 by Gauss-Jordan in double on [D | I] */
        for (i = 0; i < b; ++i)
            for (j = 0; j < 2 * b; ++j) d[(size_t)i * 2 * b + j] = j < b ? (double)X[(size_t)(kb + i) * ld + kb + j] : (j - b == i ? 1.0 : 0.0);
        for (q = 0; q < b && r == RAD_SUCCESS; ++q) {
            double p = d[(size_t)q * 2 * b + q];
            if (!(fabs(p) > 1e-30)) { r = RAD_ERROR_SINGULAR; break; }
            for (j = 0; j < 2 * b; ++j) d[(size_t)q * 2 * b + j] /= p;
            for (i = 0; i < b; ++i) {
                double f = d[(size_t)i * 2 * b + q];
                if (i == q || f == 0.0) continue;
                for (j = 0; j < 2 * b; ++j) d[(size_t)i * 2 * b + j] -= f * d[(size_t)q * 2 * b + j];
            }
        }
        if (r != RAD_SUCCESS) break;
        for (i = 0; i < b; ++i)
            for (j = 0; j < b; ++j) dinv[(size_t)i * b + j] = (float)d[(size_t)i * 2 * b + b + j];
        /* R with the pivot columns zeroed; C negated with the pivot rows zeroed */
        for (i = 0; i < b; ++i) {
            memcpy(rbuf + (size_t)i * m, X + (size_t)(kb + i) * ld, sizeof(float) * m);
            memset(rbuf + (size_t)i * m + kb, 0, sizeof(float) * b);
        }
        for (i = 0; i < m; ++i)
            for (j = 0; j < b; ++j) cbuf[(size_t)i * b + j] = (i >= kb && i < kb + b) ? 0.0f : -X[(size_t)i * ld + kb + j];
        memset(rp, 0, sizeof(float) * (size_t)b * m);
        r = rad__mb_gemm(c, b, m, b, dinv, b, rbuf, m, rp, m);                 /* R' = D^-1 R */
        if (r == RAD_SUCCESS) r = rad__mb_gemm(c, m, m, b, cbuf, b, rp, m, X, ld); /* O += (-C) R' */
        memset(tmp, 0, sizeof(float) * (size_t)m * b);
        if (r == RAD_SUCCESS) r = rad__mb_gemm(c, m, b, b, cbuf, b, dinv, b, tmp, b); /* C' = -C D^-1 */
        if (r != RAD_SUCCESS) break;
        for (i = 0; i < b; ++i)
            for (j = 0; j < m; ++j)
                if (j < kb || j >= kb + b) X[(size_t)(kb + i) * ld + j] = rp[(size_t)i * m + j];
        for (i = 0; i < m; ++i)
            for (j = 0; j < b; ++j)
                X[(size_t)i * ld + kb + j] = (i >= kb && i < kb + b) ? dinv[(size_t)(i - kb) * b + j] : tmp[(size_t)i * b + j];
    }
done:
    rad__free(&c->allocator, cbuf);
    rad__free(&c->allocator, rbuf);
    rad__free(&c->allocator, rp);
    rad__free(&c->allocator, tmp);
    rad__free(&c->allocator, dinv);
    rad__free(&c->allocator, d);
    return r;
}

RAD_API rad_result rad_local_rebuild(rad_local *L, const uint32_t *patches, uint32_t count, const rad_context *ctx)
{
    rad__ctx c;
    rad__local_storage *st;
    rad__local_scratch *s;
    rad_multibounce_options mo;
    rad_multibounce *mb = NULL;
    rad_matrix Fm;
    float *F = NULL, *alb = NULL;
    uint32_t i, p, k, ch, M;
    size_t bytes, MM;
    rad_result r = RAD_SUCCESS;
    rad__ctx_init(&c, ctx);
    if (!L || (count > 0 && !patches)) return RAD_ERROR_INVALID_ARGUMENT;
    rad__local_clear(L);
    if (count > L->capacity) {
        rad__log(&c, RAD_LOG_ERROR, "rad_local_rebuild: %u patches do not fit capacity %u", count, L->capacity);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    if (count == 0) return RAD_SUCCESS;
    st = (rad__local_storage *)L->storage;
    s = &st->s;
    M = L->capacity;
    MM = (size_t)M * M;
    for (i = 0; i < count && r == RAD_SUCCESS; ++i) {
        if (patches[i] >= L->n) {
            rad__log(&c, RAD_LOG_ERROR, "rad_local_rebuild: patch %u >= n = %u", patches[i], L->n);
            r = RAD_ERROR_INDEX_OUT_OF_RANGE;
        } else if (st->patch_slot[patches[i]] != RAD_NONE) {
            rad__log(&c, RAD_LOG_ERROR, "rad_local_rebuild: patch %u is listed twice", patches[i]);
            r = RAD_ERROR_INVALID_ARGUMENT;
        } else {
            st->patch_slot[patches[i]] = i;
            st->slot_patch[i] = patches[i];
        }
    }
    if (r == RAD_SUCCESS) {
        if (!rad__mul3((size_t)count, (size_t)count, sizeof(float), &bytes)) r = RAD_ERROR_SIZE_OVERFLOW;
        else {
            F = (float *)rad__alloc(&c.allocator, bytes);
            alb = (float *)rad__alloc_array(&c.allocator, (size_t)count, 3 * sizeof(float));
            if (!F || !alb) r = RAD_ERROR_OUT_OF_MEMORY;
            else memset(F, 0, bytes);
        }
    }
    for (i = 0; i < count && r == RAD_SUCCESS; ++i) {
        uint32_t got = 0;
        r = rad__local_fetch(&c, L, patches[i], &got);
        for (p = 0; p < got && r == RAD_SUCCESS; ++p) {
            uint32_t j = s->row_columns[p];
            k = j == patches[i] ? i : st->patch_slot[j];
            if (k != RAD_NONE) F[(size_t)i * count + k] = s->row_values[p];
        }
        for (ch = 0; ch < 3; ++ch) alb[3 * (size_t)i + ch] = L->source.albedo[3 * (size_t)patches[i] + ch];
    }
    if (r == RAD_SUCCESS && L->rebuild == RAD_LOCAL_REBUILD_INVERSE) {
        /* X = I - A per channel, straight into the planes, inverted in place, minus I */
        for (ch = 0; ch < 3 && r == RAD_SUCCESS; ++ch) {
            float *P = st->planes + ch * MM;
            for (i = 0; i < count; ++i) {
                float rho = alb[3 * (size_t)i + ch];
                for (k = 0; k < count; ++k) P[(size_t)i * M + k] = (i == k ? 1.0f : 0.0f) - rho * F[(size_t)i * count + k];
            }
            r = rad__local_invert(&c, P, count, M);
            for (i = 0; i < count && r == RAD_SUCCESS; ++i) P[(size_t)i * M + i] -= 1.0f;
        }
        if (r == RAD_SUCCESS) {
            L->slot_end = count;
            L->count = count;
        } else {
            rad__log(&c, RAD_LOG_ERROR, "rad_local_rebuild: the inverse failed: %s", rad_result_string(r));
            L->slot_end = count; /* so that the clear below zeroes what was written */
            rad__local_clear(L);
        }
    } else if (r == RAD_SUCCESS) {
        memset(&Fm, 0, sizeof(Fm));
        Fm.rows = Fm.cols = count;
        Fm.storage = RAD_STORAGE_DENSE;
        Fm.dense = F;
        rad_multibounce_options_default(&mo);
        mo.bounces = RAD_MB_INFINITE;
        r = rad_multibounce_create(&Fm, alb, &mo, ctx, &mb);
    }
    if (r == RAD_SUCCESS && mb) {
        size_t nn = (size_t)count * count;
        for (ch = 0; ch < 3; ++ch)
            for (i = 0; i < count; ++i)
                memcpy(st->planes + ch * MM + (size_t)i * M, mb->planes + ch * nn + (size_t)i * count, sizeof(float) * count);
        L->slot_end = count;
        L->count = count;
    } else if (r != RAD_SUCCESS) {
        /* leave an empty set: undo the maps */
        for (i = 0; i < M; ++i)
            if (st->slot_patch[i] != RAD_NONE) { st->patch_slot[st->slot_patch[i]] = RAD_NONE; st->slot_patch[i] = RAD_NONE; }
    }
    rad_multibounce_destroy(mb);
    rad__free(&c.allocator, F);
    rad__free(&c.allocator, alb);
    return r;
}

static void rad__local_apply_task(void *data, uint32_t t)
{
    const rad__local_job *J = (const rad__local_job *)data;
    size_t MM = (size_t)J->M * J->M;
    uint32_t r0, r1, r, ch;
    rad__local_range(J->row_count, J->tasks, t, &r0, &r1);
    for (r = r0; r < r1; ++r)
        for (ch = 0; ch < 3; ++ch)
            J->y[3 * (size_t)r + ch] = rad__mb_dot(J->st->planes + ch * MM + (size_t)J->rows[r] * J->M,
                                                   J->e + (size_t)ch * J->end, J->end);
}

/* the slots of a list of world patches (or of the whole set when list is NULL) */
static rad_result rad__local_slots(const rad__ctx *c, const rad_local *L, const uint32_t *list, uint32_t count,
                                   const char *what, uint32_t *out, uint32_t *out_count)
{
    uint32_t i, k = 0;
    if (!list) {
        for (i = 0; i < L->slot_end; ++i)
            if (L->slot_patch[i] != RAD_NONE && !L->slot_hidden[i]) out[k++] = i;
    } else
        for (i = 0; i < count; ++i) {
            if (list[i] >= L->n || L->patch_slot[list[i]] == RAD_NONE) {
                rad__log(c, RAD_LOG_ERROR, "rad_local_apply: %s patch %u (entry %u) is %s", what, list[i], i,
                         list[i] >= L->n ? "out of range" : "not in the set");
                return RAD_ERROR_INDEX_OUT_OF_RANGE;
            }
            out[k++] = L->patch_slot[list[i]];
        }
    *out_count = k;
    return RAD_SUCCESS;
}

RAD_API rad_result rad_local_apply(const rad_local *L, const float *E, const uint32_t *visible,
                                   uint32_t visible_count, const uint32_t *lit, uint32_t lit_count,
                                   rad_output output, float *out, const rad_context *ctx)
{
    rad__ctx c;
    rad__local_job J;
    uint32_t *rows = NULL, *cols = NULL, ncols = 0, nrows = 0, i, ch;
    float *e = NULL, *y = NULL;
    rad_result r;
    rad__ctx_init(&c, ctx);
    if (!L || !E || !out || (output != RAD_OUTPUT_INDIRECT && output != RAD_OUTPUT_TOTAL)) return RAD_ERROR_INVALID_ARGUMENT;
    if (L->count + L->hidden == 0) return RAD_SUCCESS;
    rows = (uint32_t *)rad__alloc_array(&c.allocator, visible ? (size_t)visible_count : (size_t)L->slot_end, sizeof(uint32_t));
    cols = (uint32_t *)rad__alloc_array(&c.allocator, lit ? (size_t)lit_count : (size_t)L->slot_end, sizeof(uint32_t));
    e = (float *)rad__alloc_array(&c.allocator, (size_t)L->slot_end, 3 * sizeof(float));
    y = (float *)rad__alloc_array(&c.allocator, visible ? (size_t)visible_count : (size_t)L->slot_end, 3 * sizeof(float));
    if (!rows || !cols || !e || !y) { r = RAD_ERROR_OUT_OF_MEMORY; goto done; }
    r = rad__local_slots(&c, L, visible, visible_count, "visible", rows, &nrows);
    if (r == RAD_SUCCESS) r = rad__local_slots(&c, L, lit, lit_count, "lit", cols, &ncols);
    if (r != RAD_SUCCESS) goto done;
    memset(e, 0, sizeof(float) * 3 * (size_t)L->slot_end);
    for (i = 0; i < ncols; ++i) {
        uint32_t p = L->slot_patch[cols[i]];
        for (ch = 0; ch < 3; ++ch) {
            float x = E[3 * (size_t)p + ch];
            if (!rad__finite(x)) {
                rad__log(&c, RAD_LOG_ERROR, "rad_local_apply: E of patch %u is not finite", p);
                r = RAD_ERROR_NON_FINITE;
                goto done;
            }
            e[(size_t)ch * L->slot_end + cols[i]] = x;
        }
    }
    J.st = (rad__local_storage *)L->storage;
    J.M = L->capacity;
    J.end = L->slot_end;
    J.rows = rows;
    J.row_count = nrows;
    J.e = e;
    J.y = y;
    J.tasks = rad__local_tasks(&c, nrows);
    rad__local_run(&c, J.tasks, rad__local_apply_task, &J);
    r = rad__check_output(&c, "rad_local_apply", y, 3 * (size_t)nrows);
    if (r == RAD_SUCCESS)
        for (i = 0; i < nrows; ++i) {
            uint32_t p = L->slot_patch[rows[i]];
            for (ch = 0; ch < 3; ++ch)
                out[3 * (size_t)p + ch] = y[3 * (size_t)i + ch] + (output == RAD_OUTPUT_TOTAL ? E[3 * (size_t)p + ch] : 0.0f);
        }
done:
    rad__free(&c.allocator, rows);
    rad__free(&c.allocator, cols);
    rad__free(&c.allocator, e);
    rad__free(&c.allocator, y);
    return r;
}

/* ---- choosing the sets ---- */

typedef struct rad__local_key { double d; uint32_t index; } rad__local_key;

static int rad__local_key_cmp(const void *pa, const void *pb)
{
    const rad__local_key *a = (const rad__local_key *)pa, *b = (const rad__local_key *)pb;
    if (a->d != b->d) return a->d < b->d ? -1 : 1;
    return a->index < b->index ? -1 : (a->index > b->index ? 1 : 0);
}

RAD_API rad_result rad_local_nearest(const rad_patches *patches, const float position[3], uint32_t count,
                                     uint32_t *out_patches, const rad_context *ctx)
{
    rad__ctx c;
    rad__local_key *keys;
    uint32_t i;
    rad__ctx_init(&c, ctx);
    if (!patches || !position || !out_patches || count > patches->count) {
        rad__log(&c, RAD_LOG_ERROR, "rad_local_nearest: NULL argument or count %u > patch count", count);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    if (!rad__finite3(position)) {
        rad__log(&c, RAD_LOG_ERROR, "rad_local_nearest: the position is not finite");
        return RAD_ERROR_NON_FINITE;
    }
    if (count == 0) return RAD_SUCCESS;
    keys = (rad__local_key *)rad__alloc_array(&c.allocator, patches->count, sizeof(rad__local_key));
    if (!keys) return RAD_ERROR_OUT_OF_MEMORY;
    for (i = 0; i < patches->count; ++i) {
        const float *q = patches->patches[i].centroid;
        double dx = (double)q[0] - position[0], dy = (double)q[1] - position[1], dz = (double)q[2] - position[2];
        keys[i].d = dx * dx + dy * dy + dz * dz;
        keys[i].index = i;
    }
    qsort(keys, patches->count, sizeof(rad__local_key), rad__local_key_cmp);
    for (i = 0; i < count; ++i) out_patches[i] = keys[i].index;
    rad__free(&c.allocator, keys);
    return RAD_SUCCESS;
}

RAD_API rad_result rad_local_visible(const rad_patches *patches, const rad_raycaster *raycaster,
                                     const rad_camera *camera, float aspect, const uint32_t *candidates,
                                     uint32_t count, uint32_t *out_visible, uint32_t *out_count,
                                     const rad_context *ctx)
{
    rad__ctx c;
    float f[3], r[3], u[3], th, tw;
    rad_ray *rays = NULL;
    uint8_t *occ = NULL;
    uint32_t *owner = NULL, nrays = 0, i, k, s, nv = 0;
    rad_result res = RAD_SUCCESS;
    rad__ctx_init(&c, ctx);
    if (!patches || !raycaster || !raycaster->occluded || !camera || !out_visible || !out_count || (count > 0 && !candidates) ||
        !(aspect > 0.0f) || !rad__finite(aspect)) {
        rad__log(&c, RAD_LOG_ERROR, "rad_local_visible: NULL argument or aspect %g not > 0", (double)aspect);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    *out_count = 0;
    if (!rad__finite3(camera->position) || !rad__finite3(camera->target) || !rad__finite3(camera->up) ||
        !rad__finite(camera->fov_y_degrees)) {
        rad__log(&c, RAD_LOG_ERROR, "rad_local_visible: the camera is not finite");
        return RAD_ERROR_NON_FINITE;
    }
    if (!(camera->fov_y_degrees > 0.0f && camera->fov_y_degrees < 180.0f)) {
        rad__log(&c, RAD_LOG_ERROR, "rad_local_visible: fov_y_degrees %g must be in (0, 180)", (double)camera->fov_y_degrees);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    rad__sub(f, camera->target, camera->position);
    rad__normalize(f);
    rad__cross(r, f, camera->up);
    rad__normalize(r);
    rad__cross(u, r, f);
    th = (float)tan(0.5 * (double)camera->fov_y_degrees * RAD__PI / 180.0);
    tw = th * aspect;
    for (i = 0; i < count; ++i)
        if (candidates[i] >= patches->count) {
            rad__log(&c, RAD_LOG_ERROR, "rad_local_visible: candidate %u is patch %u >= %u", i, candidates[i], patches->count);
            return RAD_ERROR_INDEX_OUT_OF_RANGE;
        }
    if (count == 0) return RAD_SUCCESS;
    rays = (rad_ray *)rad__alloc_array(&c.allocator, (size_t)count * 4u, sizeof(rad_ray));
    occ = (uint8_t *)rad__alloc_array(&c.allocator, (size_t)count * 4u, 1);
    owner = (uint32_t *)rad__alloc_array(&c.allocator, (size_t)count * 4u, sizeof(uint32_t));
    if (!rays || !occ || !owner) { res = RAD_ERROR_OUT_OF_MEMORY; goto done; }
    for (i = 0; i < count; ++i) {
        const rad_patch *p = &patches->patches[candidates[i]];
        float to[3];
        rad__sub(to, camera->position, p->centroid);
        if (!(rad__dot(to, p->normal) > 0.0f)) continue; /* back face */
        for (s = 0; s < 4; ++s) {
            float q[3], d[3], z, x, y, dist;
            for (k = 0; k < 3; ++k)
                q[k] = s == 0 ? p->centroid[k] : 0.5f * (p->centroid[k] + patches->vertices[3 * (size_t)p->vertices[s - 1] + k]);
            rad__sub(d, q, camera->position);
            z = rad__dot(d, f);
            if (!(z > 0.0f)) continue;
            x = rad__dot(d, r) / z;
            y = rad__dot(d, u) / z;
            if (x < -tw || x > tw || y < -th || y > th) continue;
            dist = rad__len(d);
            for (k = 0; k < 3; ++k) {
                rays[nrays].origin[k] = q[k] + p->normal[k] * 1e-4f * dist;
                rays[nrays].dir[k] = camera->position[k] - rays[nrays].origin[k];
            }
            rays[nrays].tmin = 0.0f;
            rays[nrays].tmax = 1.0f;
            owner[nrays++] = i;
        }
    }
    if (nrays > 0) {
        res = raycaster->occluded(raycaster->user, rays, nrays, occ);
        if (res != RAD_SUCCESS) {
            rad__log(&c, RAD_LOG_ERROR, "rad_local_visible: the occlusion callback failed: %s", rad_result_string(res));
            res = RAD_ERROR_RAYCAST_FAILED;
            goto done;
        }
    }
    {
        uint32_t last = RAD_NONE; /* a candidate's rays are consecutive: keep it once */
        for (k = 0; k < nrays; ++k)
            if (!occ[k] && owner[k] != last) {
                out_visible[nv++] = candidates[owner[k]];
                last = owner[k];
            }
    }
    *out_count = nv;
done:
    rad__free(&c.allocator, rays);
    rad__free(&c.allocator, occ);
    rad__free(&c.allocator, owner);
    return res;
}

RAD_API rad_result rad_local_lit(const float *E, const uint32_t *candidates, uint32_t count, float threshold,
                                 uint32_t *out_lit, uint32_t *out_count)
{
    uint32_t i, n = 0;
    if (!E || !out_lit || !out_count || (count > 0 && !candidates) || !(threshold >= 0.0f) || !rad__finite(threshold))
        return RAD_ERROR_INVALID_ARGUMENT;
    for (i = 0; i < count; ++i) {
        const float *e = E + 3 * (size_t)candidates[i];
        if (e[0] > threshold || e[1] > threshold || e[2] > threshold) out_lit[n++] = candidates[i];
    }
    *out_count = n;
    return RAD_SUCCESS;
}

/* ======================================================================================== */
/* >>temporal: temporal radiosity (alias tables, counter-based draws, the step)             */
/* ======================================================================================== */

static uint32_t rad__pcg(uint32_t v)
{
    uint32_t s = v * 747796405u + 2891336453u;
    uint32_t t = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return (t >> 22u) ^ t;
}

static uint32_t rad__temporal_key(uint32_t seed, uint32_t frame, uint32_t row)
{
    return rad__pcg(rad__pcg(rad__pcg(seed) ^ frame) ^ row);
}

RAD_API void rad_temporal_random(uint32_t seed, uint32_t frame, uint32_t row, uint32_t sample, uint32_t out[2])
{
    uint32_t u1 = rad__pcg(rad__temporal_key(seed, frame, row) ^ (sample * 0x9E3779B9u));
    out[0] = u1;
    out[1] = rad__pcg(u1 ^ 0x68E31DA4u);
}

static uint32_t rad__alias_pick(const uint32_t *bins, uint32_t n, uint32_t words, uint32_t u1, uint32_t u2)
{
    uint32_t b = (uint32_t)(((uint64_t)u1 * (uint64_t)n) >> 32);
    const uint32_t *e = bins + (size_t)b * words;
    if (words == 2u) return u2 < e[0] ? (e[1] & 0xFFFFu) : (e[1] >> 16);
    return u2 < e[0] ? e[1] : e[2];
}

RAD_API uint32_t rad_alias_draw(const uint32_t *bins, uint32_t n, rad_alias_format format, uint32_t u1, uint32_t u2)
{
    if (!bins || n == 0 || (format != RAD_ALIAS_COMPACT && format != RAD_ALIAS_WIDE)) return RAD_NONE;
    return rad__alias_pick(bins, n, (uint32_t)format, u1, u2);
}

RAD_API size_t rad_alias_row_scratch_size(uint32_t count)
{
    /* q (double) and one uint32 stack slot per bin, count + 1 bins */
    return ((size_t)count + 1u) * (sizeof(double) + 2u * sizeof(uint32_t));
}

static rad_alias_format rad__alias_resolve(rad_alias_format format, uint32_t cols)
{
    if (format == RAD_ALIAS_AUTO) return cols <= 65535u ? RAD_ALIAS_COMPACT : RAD_ALIAS_WIDE;
    return format;
}

/* One row's bins (shared by every builder, so all give the same bits). c: optional context for
   messages, row: for messages. */
static rad_result rad__alias_row(const uint32_t *columns, const float *values, uint32_t count, uint32_t cols,
                                 rad_alias_format format, uint32_t *out_bins, uint32_t *out_n, float *out_total,
                                 void *scratch, const rad__ctx *c, uint32_t row)
{
    double *q = (double *)scratch, W = 0.0, env, total;
    uint32_t *colof = (uint32_t *)(q + (size_t)count + 1u), *stack = colof + (size_t)count + 1u;
    uint32_t i, n = 0, small_top = 0, large_bottom, words = (uint32_t)format;
    for (i = 0; i < count; ++i) {
        float v = values[i];
        uint32_t col = columns ? columns[i] : i;
        if (!rad__finite(v) || v < 0.0f || col >= cols) {
            rad__log(c, RAD_LOG_ERROR, "alias tables: row %u entry %u (column %u) is %g: entries must be finite, >= 0, column < %u",
                     row, i, col, (double)v, cols);
            return RAD_ERROR_INVALID_ARGUMENT;
        }
        if (v > 0.0f) {
            q[n] = (double)v;
            colof[n] = col;
            W += (double)v;
            ++n;
        }
    }
    env = 1.0 - W;
    if (env > 0.0) {
        q[n] = env;
        colof[n] = cols;
        ++n;
        total = 1.0;
    } else {
        total = W;
    }
    W += env > 0.0 ? env : 0.0;
    /* Vose, robust variant: Small grows up from stack[0], Large down from stack[n-1] */
    large_bottom = n;
    for (i = 0; i < n; ++i) {
        q[i] = (double)n * q[i] / W;
        if (q[i] < 1.0) stack[small_top++] = i;
        else stack[--large_bottom] = i;
    }
    /* Large is stored in reverse; pop from its bottom end (the last pushed) */
    for (i = 0; i < n; ++i) {
        uint32_t *e = out_bins + (size_t)i * words;
        e[0] = 0xFFFFFFFFu;
        if (words == 2u) e[1] = colof[i] | (colof[i] << 16);
        else { e[1] = colof[i]; e[2] = colof[i]; }
    }
    while (small_top > 0 && large_bottom < n) {
        uint32_t l = stack[--small_top], g = stack[large_bottom++];
        double p = q[l] * 4294967296.0 + 0.5;
        uint32_t *e = out_bins + (size_t)l * words;
        e[0] = p >= 4294967295.0 ? 0xFFFFFFFFu : (uint32_t)p;
        if (words == 2u) e[1] = colof[l] | (colof[g] << 16);
        else e[2] = colof[g];
        q[g] = (q[g] + q[l]) - 1.0;
        if (q[g] < 1.0) stack[small_top++] = g;
        else stack[--large_bottom] = g;
    }
    /* leftovers keep prob = 1 (threshold 2^32-1 and alias = itself: always the own column) */
    *out_n = n;
    *out_total = (float)total;
    return RAD_SUCCESS;
}

RAD_API rad_result rad_alias_build_row(const uint32_t *columns, const float *values, uint32_t count, uint32_t cols,
                                       rad_alias_format format, uint32_t *out_bins, uint32_t *out_bin_count,
                                       float *out_total, void *scratch)
{
    if ((!values && count) || !out_bins || !out_bin_count || !out_total || !scratch || cols == 0 || cols == 0xFFFFFFFFu)
        return RAD_ERROR_INVALID_ARGUMENT;
    if (!columns && count != cols) return RAD_ERROR_INVALID_ARGUMENT;
    if (count == 0xFFFFFFFFu) return RAD_ERROR_SIZE_OVERFLOW;
    format = rad__alias_resolve(format, cols);
    if (format != RAD_ALIAS_COMPACT && format != RAD_ALIAS_WIDE) return RAD_ERROR_INVALID_ARGUMENT;
    if (format == RAD_ALIAS_COMPACT && cols > 65535u) return RAD_ERROR_INVALID_ARGUMENT;
    return rad__alias_row(columns, values, count, cols, format, out_bins, out_bin_count, out_total, scratch, NULL, 0);
}

RAD_API void rad_alias_tables_destroy(rad_alias_tables *t)
{
    rad_allocator a;
    if (!t) return;
    a = t->allocator;
    rad__free(&a, t->storage);
    rad__free(&a, t);
}

RAD_API size_t rad_alias_tables_memory(const rad_alias_tables *t)
{
    if (!t || !t->row_offsets) return 0;
    return (size_t)t->row_offsets[t->rows] * (size_t)t->format * 4u + ((size_t)t->rows + 1u) * 8u + (size_t)t->rows * 4u;
}

#define RAD__HUGE_PAGE ((size_t)2u << 20) /* x86-64 and AArch64 (4 KiB base pages) transparent huge page */

/* 'size' bytes for a table block; *raw receives the pointer to free. On Linux, blocks of at
   least two huge pages are placed 2 MiB aligned (over-allocating 2 MiB) and their whole huge
   pages marked MADV_HUGEPAGE before first touch: a draw is a random read into hundreds of MB,
   and with 4 KiB pages nearly every draw also misses the TLB (BENCHMARKS.md). The advice is a
   hint; its failure (kernel without THP, memory not from mmap) changes nothing. */
static unsigned char *rad__alias_alloc(const rad_allocator *a, size_t size, void **raw)
{
#ifdef RAD__MADV_HUGEPAGE
    if (size >= 2u * RAD__HUGE_PAGE && size <= (size_t)-1 - RAD__HUGE_PAGE) {
        unsigned char *p = (unsigned char *)rad__alloc(a, size + RAD__HUGE_PAGE);
        *raw = p;
        if (!p) return NULL;
        p += (RAD__HUGE_PAGE - (size_t)((uintptr_t)p & (RAD__HUGE_PAGE - 1u))) & (RAD__HUGE_PAGE - 1u);
        (void)madvise(p, size & ~(RAD__HUGE_PAGE - 1u), RAD__MADV_HUGEPAGE);
        return p;
    }
#endif
    *raw = rad__alloc(a, size);
    return (unsigned char *)*raw;
}

typedef struct rad__alias_job {
    const rad_matrix *F;        /* or NULL: 'plane' */
    const float *plane;
    uint32_t n;
    rad_alias_format format;
    uint64_t *offsets;          /* pass 1: bins per row at [i+1]; pass 2: prefix sums */
    uint32_t *bins;
    float *totals;
    unsigned char *scratch;     /* per task */
    size_t scratch_stride;
    const rad__ctx *c;
    int pass;
} rad__alias_job;

static rad_result rad__alias_job_row(void *data, uint32_t i, uint32_t task)
{
    rad__alias_job *j = (rad__alias_job *)data;
    const uint32_t *cols = NULL;
    const float *vals;
    uint32_t count, k, nb;
    float total;
    if (j->F && j->F->storage == RAD_STORAGE_SPARSE) {
        uint64_t a = j->F->row_offsets[i], b = j->F->row_offsets[i + 1];
        cols = j->F->columns + a;
        vals = j->F->values + a;
        count = (uint32_t)(b - a);
    } else {
        vals = (j->F ? j->F->dense : j->plane) + (size_t)i * j->n;
        count = j->n;
    }
    if (j->pass == 1) {
        /* count the bins; validate */
        double W = 0.0;
        nb = 0;
        for (k = 0; k < count; ++k) {
            float v = vals[k];
            uint32_t col = cols ? cols[k] : k;
            if (!rad__finite(v) || v < 0.0f || col >= j->n) {
                rad__log(j->c, RAD_LOG_ERROR, "alias tables: row %u entry %u (column %u) is %g: entries must be finite, >= 0, column < %u",
                         i, k, col, (double)v, j->n);
                return RAD_ERROR_INVALID_ARGUMENT;
            }
            if (v > 0.0f) { ++nb; W += (double)v; }
        }
        if (1.0 - W > 0.0) ++nb;
        j->offsets[i + 1] = nb;
        return RAD_SUCCESS;
    }
    {
        rad_result r = rad__alias_row(cols, vals, count, j->n, j->format, j->bins + (size_t)j->offsets[i] * (uint32_t)j->format,
                                      &nb, &total, j->scratch + (size_t)task * j->scratch_stride, j->c, i);
        if (r != RAD_SUCCESS) return r;
        j->totals[i] = total;
        return nb == (uint32_t)(j->offsets[i + 1] - j->offsets[i]) ? RAD_SUCCESS : RAD_ERROR_CORRUPT;
    }
}

static rad_result rad__alias_build(const rad_matrix *F, const float *plane, uint32_t n, rad_alias_format format,
                                   const rad_context *ctx, rad_alias_tables **out)
{
    rad__ctx c;
    rad__alias_job job;
    rad_alias_tables *t;
    rad_result r;
    unsigned char *base;
    size_t off_bytes, tot_bytes, bin_bytes, total, words, bins_off, tot_off;
    uint64_t sum = 0, maxrow;
    uint32_t i, tasks;
    rad__ctx_init(&c, ctx);
    if (!out) return RAD_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    if (n == 0 || n == 0xFFFFFFFFu) return RAD_ERROR_INVALID_ARGUMENT;
    format = rad__alias_resolve(format, n);
    if (format != RAD_ALIAS_COMPACT && format != RAD_ALIAS_WIDE) return RAD_ERROR_INVALID_ARGUMENT;
    if (format == RAD_ALIAS_COMPACT && n > 65535u) {
        rad__log(&c, RAD_LOG_ERROR, "alias tables: the compact format needs N <= 65535 (N = %u)", n);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    tasks = c.tasks < n ? c.tasks : n;
    memset(&job, 0, sizeof(job));
    job.F = F;
    job.plane = plane;
    job.n = n;
    job.format = format;
    job.c = &c;
    job.offsets = (uint64_t *)rad__alloc_array(&c.allocator, (size_t)n + 1u, sizeof(uint64_t));
    if (!job.offsets) return RAD_ERROR_OUT_OF_MEMORY;
    job.pass = 1;
    {
        rad__ctx quiet = c; /* progress is reported by the second pass only */
        quiet.progress = NULL;
        r = rad__for_rows(&quiet, n, tasks, rad__alias_job_row, &job);
    }
    if (r != RAD_SUCCESS) { rad__free(&c.allocator, job.offsets); return r; }
    job.offsets[0] = 0;
    maxrow = n; /* scratch is sized by a row's raw entry count */
    if (F && F->storage == RAD_STORAGE_SPARSE) {
        maxrow = 0;
        for (i = 0; i < n; ++i)
            if (F->row_offsets[i + 1] - F->row_offsets[i] > maxrow) maxrow = F->row_offsets[i + 1] - F->row_offsets[i];
        if (maxrow > n) { rad__free(&c.allocator, job.offsets); return RAD_ERROR_INVALID_ARGUMENT; }
    }
    for (i = 0; i < n; ++i) {
        uint64_t nb = job.offsets[i + 1];
        sum += nb;
        job.offsets[i + 1] = sum;
    }
    words = (size_t)format;
    if (!rad__mul((size_t)n + 1u, sizeof(uint64_t), &off_bytes) || !rad__mul((size_t)n, sizeof(float), &tot_bytes) ||
        sum > (uint64_t)((size_t)-1) || !rad__mul3((size_t)sum, words, sizeof(uint32_t), &bin_bytes)) {
        rad__free(&c.allocator, job.offsets);
        return RAD_ERROR_SIZE_OVERFLOW;
    }
    /* one block: offsets | totals | bins (each start 8-byte aligned) */
    tot_off = off_bytes;
    bins_off = tot_off + ((tot_bytes + 7u) & ~(size_t)7u);
    total = bins_off + bin_bytes;
    if (total < bin_bytes) { rad__free(&c.allocator, job.offsets); return RAD_ERROR_SIZE_OVERFLOW; }
    t = (rad_alias_tables *)rad__alloc(&c.allocator, sizeof(rad_alias_tables));
    if (!t) { rad__free(&c.allocator, job.offsets); return RAD_ERROR_OUT_OF_MEMORY; }
    memset(t, 0, sizeof(*t));
    t->allocator = c.allocator;
    base = rad__alias_alloc(&c.allocator, total, &t->storage);
    job.scratch_stride = (rad_alias_row_scratch_size((uint32_t)maxrow) + 7u) & ~(size_t)7u;
    job.scratch = (unsigned char *)rad__alloc_array(&c.allocator, tasks, job.scratch_stride);
    if (!t->storage || !job.scratch) {
        rad__free(&c.allocator, job.scratch);
        rad__free(&c.allocator, job.offsets);
        rad_alias_tables_destroy(t);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    memcpy(base, job.offsets, off_bytes);
    rad__free(&c.allocator, job.offsets);
    job.offsets = (uint64_t *)(void *)base;
    job.totals = (float *)(void *)(base + tot_off);
    job.bins = (uint32_t *)(void *)(base + bins_off);
    job.pass = 2;
    r = rad__for_rows(&c, n, tasks, rad__alias_job_row, &job);
    rad__free(&c.allocator, job.scratch);
    if (r != RAD_SUCCESS) { rad_alias_tables_destroy(t); return r; }
    t->rows = n;
    t->cols = n;
    t->format = format;
    t->row_offsets = job.offsets;
    t->totals = job.totals;
    t->bins = job.bins;
    t->source_entries = (F && F->storage == RAD_STORAGE_SPARSE) ? F->row_offsets[n] : (uint64_t)n * n;
    *out = t;
    return RAD_SUCCESS;
}

RAD_API rad_result rad_alias_tables_create(const rad_matrix *F, rad_alias_format format, const rad_context *ctx,
                                           rad_alias_tables **out)
{
    rad__ctx c;
    rad_result r;
    rad__ctx_init(&c, ctx);
    r = rad__check_matrix(F, &c);
    if (out) *out = NULL;
    if (r != RAD_SUCCESS) return r;
    if (F->rows != F->cols) {
        rad__log(&c, RAD_LOG_ERROR, "alias tables: the matrix is %u x %u, not square", F->rows, F->cols);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    return rad__alias_build(F, NULL, F->rows, format, ctx, out);
}

RAD_API rad_result rad_alias_tables_create_dense(const float *plane, uint32_t n, rad_alias_format format,
                                                 const rad_context *ctx, rad_alias_tables **out)
{
    if (out) *out = NULL;
    if (!plane) return RAD_ERROR_INVALID_ARGUMENT;
    return rad__alias_build(NULL, plane, n, format, ctx, out);
}

RAD_API void rad_alias_tables_sections(const rad_alias_tables *t, const char *name, rad_section out[3])
{
    if (!out) return;
    memset(out, 0, 3 * sizeof(rad_section));
    if (!t) return;
    rad__section(&out[0], RAD_SECTION_TEMPORAL_ROW_OFFSETS, 8u, (uint64_t)t->rows + 1u, t->row_offsets, name);
    rad__section(&out[1], RAD_SECTION_TEMPORAL_BINS, 4u * (uint32_t)t->format, t->row_offsets[t->rows], t->bins, name);
    rad__section(&out[2], RAD_SECTION_TEMPORAL_TOTALS, 4u, t->rows, t->totals, name);
}

RAD_API rad_result rad_alias_tables_view(const rad_container *ct, const char *name, const rad_context *ctx,
                                         rad_alias_tables *out)
{
    rad__ctx c;
    const rad_section *so, *sb, *st;
    uint32_t n, words, i;
    uint64_t b, nb;
    rad__ctx_init(&c, ctx);
    if (!ct || !out) return RAD_ERROR_INVALID_ARGUMENT;
    memset(out, 0, sizeof(*out));
    so = rad_container_find(ct, RAD_SECTION_TEMPORAL_ROW_OFFSETS, name);
    sb = rad_container_find(ct, RAD_SECTION_TEMPORAL_BINS, name);
    st = rad_container_find(ct, RAD_SECTION_TEMPORAL_TOTALS, name);
    if (!so || !sb || !st) {
        rad__log(&c, RAD_LOG_ERROR, "alias tables: sections for '%s' not found", name ? name : "(any)");
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    if (so->elem_size != 8u || st->elem_size != 4u || (sb->elem_size != 8u && sb->elem_size != 12u) || so->count < 2u ||
        so->count - 1u != st->count || st->count >= 0xFFFFFFFFu || ((uintptr_t)so->data & 7u) != 0) {
        rad__log(&c, RAD_LOG_ERROR, "alias tables: section sizes do not fit together");
        return RAD_ERROR_CORRUPT;
    }
    n = (uint32_t)st->count;
    words = sb->elem_size / 4u;
    if (words == 2u && n > 65535u) {
        rad__log(&c, RAD_LOG_ERROR, "alias tables: compact bins with N = %u > 65535", n);
        return RAD_ERROR_CORRUPT;
    }
    {
        const uint64_t *off = (const uint64_t *)so->data;
        const uint32_t *bins = (const uint32_t *)sb->data;
        const float *tot = (const float *)st->data;
        if (off[0] != 0 || off[n] != sb->count) {
            rad__log(&c, RAD_LOG_ERROR, "alias tables: offsets do not cover the %llu bins", (unsigned long long)sb->count);
            return RAD_ERROR_CORRUPT;
        }
        for (i = 0; i < n; ++i) {
            if (off[i + 1] <= off[i] || off[i + 1] - off[i] > (uint64_t)n + 1u) {
                rad__log(&c, RAD_LOG_ERROR, "alias tables: row %u has a bad bin range", i);
                return RAD_ERROR_CORRUPT;
            }
            if (!rad__finite(tot[i]) || !(tot[i] > 0.0f) || tot[i] > RAD_BAKE_VALUE_MAX) {
                rad__log(&c, RAD_LOG_ERROR, "baked data: alias tables '%s' totals (TEMPORAL_TOTALS): row %u has total %g (%s)",
                         name ? name : "", i, (double)tot[i],
                         !rad__finite(tot[i]) ? "not finite" : tot[i] > 0.0f ? "beyond RAD_BAKE_VALUE_MAX = 1e30" : "not > 0");
                return rad__finite(tot[i]) ? RAD_ERROR_CORRUPT : RAD_ERROR_NON_FINITE;
            }
        }
        for (b = 0, nb = sb->count; b < nb; ++b) {
            const uint32_t *e = bins + (size_t)b * words;
            uint32_t c0 = words == 2u ? (e[1] & 0xFFFFu) : e[1], c1 = words == 2u ? (e[1] >> 16) : e[2];
            if (c0 > n || c1 > n) {
                rad__log(&c, RAD_LOG_ERROR, "alias tables: bin %llu names column %u > N = %u", (unsigned long long)b,
                         c0 > c1 ? c0 : c1, n);
                return RAD_ERROR_CORRUPT;
            }
        }
        out->rows = n;
        out->cols = n;
        out->format = (rad_alias_format)words;
        out->row_offsets = off;
        out->bins = bins;
        out->totals = tot;
        out->source_entries = 0;
    }
    return RAD_SUCCESS;
}

/* ---- the temporal state ---- */

struct rad_temporal {
    const rad_alias_tables *tables[3];
    uint32_t table_count;
    const float *albedo;
    rad_temporal_options o;
    uint32_t n, frame;
    float *B, *B_next;     /* 3N each; B is the current result */
    float *V;              /* FEEDBACK: 3N sampled vector E + B^prev */
    float *w;              /* adaptive: N per-row weights of the last step */
    float *mean, *var, *fast; /* adaptive: N each */
    uint32_t *count;       /* adaptive: frames since restart */
    int restart_all;
    rad__ctx c;
};

RAD_API void rad_temporal_options_default(rad_temporal_options *o)
{
    if (!o) return;
    memset(o, 0, sizeof(*o));
    o->mode = RAD_TEMPORAL_SINGLE;
    o->samples = 10;
    o->weight = 0.998f;
    o->noise_target = 0.01f;
    o->weight_max = 0.999f;
    o->change_sigma = 5.0f;
}

RAD_API void rad_temporal_destroy(rad_temporal *t)
{
    rad_allocator a;
    if (!t) return;
    a = t->c.allocator;
    rad__free(&a, t->B);
    rad__free(&a, t->B_next);
    rad__free(&a, t->V);
    rad__free(&a, t->w);
    rad__free(&a, t->mean);
    rad__free(&a, t->var);
    rad__free(&a, t->fast);
    rad__free(&a, t->count);
    rad__free(&a, t);
}

RAD_API void rad_temporal_reset(rad_temporal *t)
{
    size_t n3;
    if (!t) return;
    n3 = 3u * (size_t)t->n;
    memset(t->B, 0, n3 * sizeof(float));
    memset(t->B_next, 0, n3 * sizeof(float));
    if (t->o.adaptive) {
        memset(t->w, 0, (size_t)t->n * sizeof(float));
        memset(t->mean, 0, (size_t)t->n * sizeof(float));
        memset(t->var, 0, (size_t)t->n * sizeof(float));
        memset(t->fast, 0, (size_t)t->n * sizeof(float));
        memset(t->count, 0, (size_t)t->n * sizeof(uint32_t));
    }
    t->frame = 0;
    t->restart_all = 0;
}

RAD_API void rad_temporal_signal_change(rad_temporal *t)
{
    if (t) t->restart_all = 1;
}

RAD_API const float *rad_temporal_indirect(const rad_temporal *t) { return t ? t->B : NULL; }
RAD_API uint32_t rad_temporal_frame(const rad_temporal *t) { return t ? t->frame : 0; }
RAD_API const float *rad_temporal_weights(const rad_temporal *t) { return (t && t->o.adaptive) ? t->w : NULL; }

RAD_API rad_result rad_temporal_create(const rad_alias_tables *const *tables, uint32_t table_count, const float *albedo,
                                       const rad_temporal_options *options, const rad_context *ctx, rad_temporal **out)
{
    rad__ctx c;
    rad_temporal *t;
    rad_temporal_options o;
    uint32_t k, n;
    rad__ctx_init(&c, ctx);
    if (!out) return RAD_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    if (options) o = *options;
    else rad_temporal_options_default(&o);
    if (!tables || (table_count != 1u && table_count != 3u) || !tables[0]) return RAD_ERROR_INVALID_ARGUMENT;
    if (o.mode != RAD_TEMPORAL_SINGLE && o.mode != RAD_TEMPORAL_FEEDBACK && o.mode != RAD_TEMPORAL_MULTIBOUNCE) {
        rad__log(&c, RAD_LOG_ERROR, "temporal: unknown mode %d", (int)o.mode);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    if (table_count == 3u && o.mode != RAD_TEMPORAL_MULTIBOUNCE) {
        rad__log(&c, RAD_LOG_ERROR, "temporal: three tables (one per channel) need RAD_TEMPORAL_MULTIBOUNCE");
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    if (o.mode != RAD_TEMPORAL_MULTIBOUNCE && !albedo) {
        rad__log(&c, RAD_LOG_ERROR, "temporal: modes SINGLE and FEEDBACK need the albedo");
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    if (o.samples == 0 || o.samples > RAD_TEMPORAL_MAX_SAMPLES || !(o.weight >= 0.0f && o.weight < 1.0f) ||
        (o.adaptive && (!(o.noise_target > 0.0f) || !(o.weight_max >= 0.0f && o.weight_max < 1.0f) ||
                        !(o.change_sigma > 0.0f) || !rad__finite(o.noise_target) || !rad__finite(o.change_sigma)))) {
        rad__log(&c, RAD_LOG_ERROR, "temporal: bad options (samples %u, weight %g, target %g, weight_max %g, sigma %g)", o.samples,
                 (double)o.weight, (double)o.noise_target, (double)o.weight_max, (double)o.change_sigma);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    n = tables[0]->rows;
    for (k = 0; k < table_count; ++k) {
        const rad_alias_tables *tb = tables[k];
        if (!tb || !tb->row_offsets || !tb->bins || !tb->totals || (tb->format != RAD_ALIAS_COMPACT && tb->format != RAD_ALIAS_WIDE))
            return RAD_ERROR_INVALID_ARGUMENT;
        if (tb->rows != n || tb->cols != n || n == 0) {
            rad__log(&c, RAD_LOG_ERROR, "temporal: table %u is %u x %u, expected %u x %u", k, tb->rows, tb->cols, n, n);
            return RAD_ERROR_SIZE_MISMATCH;
        }
    }
    if ((uint64_t)o.samples * table_count > 0xFFFFFFFFull) return RAD_ERROR_INVALID_ARGUMENT;
    t = (rad_temporal *)rad__alloc(&c.allocator, sizeof(rad_temporal));
    if (!t) return RAD_ERROR_OUT_OF_MEMORY;
    memset(t, 0, sizeof(*t));
    t->c = c;
    for (k = 0; k < table_count; ++k) t->tables[k] = tables[k];
    t->table_count = table_count;
    t->albedo = albedo;
    t->o = o;
    t->n = n;
    t->B = (float *)rad__alloc_array(&c.allocator, (size_t)n, 3u * sizeof(float));
    t->B_next = (float *)rad__alloc_array(&c.allocator, (size_t)n, 3u * sizeof(float));
    if (o.mode == RAD_TEMPORAL_FEEDBACK) t->V = (float *)rad__alloc_array(&c.allocator, (size_t)n, 3u * sizeof(float));
    if (o.adaptive) {
        t->w = (float *)rad__alloc_array(&c.allocator, n, sizeof(float));
        t->mean = (float *)rad__alloc_array(&c.allocator, n, sizeof(float));
        t->var = (float *)rad__alloc_array(&c.allocator, n, sizeof(float));
        t->fast = (float *)rad__alloc_array(&c.allocator, n, sizeof(float));
        t->count = (uint32_t *)rad__alloc_array(&c.allocator, n, sizeof(uint32_t));
    }
    if (!t->B || !t->B_next || (o.mode == RAD_TEMPORAL_FEEDBACK && !t->V) ||
        (o.adaptive && (!t->w || !t->mean || !t->var || !t->fast || !t->count))) {
        rad_temporal_destroy(t);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    rad_temporal_reset(t);
    *out = t;
    return RAD_SUCCESS;
}

typedef struct rad__tstep {
    rad_temporal *t;
    const float *V;        /* sampled vector, 3N */
    float env[3];
    uint32_t tasks;
} rad__tstep;

#if defined(__GNUC__) || defined(__clang__)
#  define RAD__PREFETCH(p) __builtin_prefetch(p)
#  define RAD__HOT static inline __attribute__((always_inline)) /* the step's per-draw helpers */
#elif defined(_MSC_VER)
#  define RAD__PREFETCH(p) ((void)0)
#  define RAD__HOT static __forceinline
#else
#  define RAD__PREFETCH(p) ((void)0)
#  define RAD__HOT static inline
#endif
#if defined(RAD__AVX) && defined(__AVX2__) && (defined(__x86_64__) || defined(_M_X64))
#  define RAD__TEMPORAL_AVX2 1 /* hashes 8 draws at once (rad__tpipe_issue8) */
#endif
/* draws whose bins are in flight ahead of the one resolved. AVX2 issues cheaper, so more of
   them overlap: 64 -> 128 took 4.8-5.1 to 4.2-4.5 ns per draw with 450 MB of tables (BENCHMARKS.md) */
#ifndef RAD__TEMPORAL_AHEAD
#  if defined(RAD__TEMPORAL_AVX2)
#    define RAD__TEMPORAL_AHEAD 128u
#  else
#    define RAD__TEMPORAL_AHEAD 64u
#  endif
#endif
#if defined(RAD__TEMPORAL_AVX2) && (RAD__TEMPORAL_AHEAD % 8u) != 0
#  undef RAD__TEMPORAL_AVX2 /* the ring is filled 8 slots at a time */
#endif

/* SOFTWARE PIPELINE of the step. A task's draws form one sequence (row by row, table set by
   set, sample by sample: exactly the order of the sums in the doc block). The producer hashes
   draw d + AHEAD, computes its bin address and prefetches it while the consumer resolves draw
   d, so about AHEAD cache misses are in flight across row boundaries instead of at most one
   row's k. Only the time at which a bin is fetched changes, never which bin or the order of
   the float sums: the bits equal the plain loop's. */
typedef struct rad__tpipe {
    const rad_temporal *t;
    const uint32_t *bins;  /* bins of row 'row' in table set 'set' */
    uint32_t nb, words, key, seedframe, k, sets;
    uint32_t row, set, s, end; /* the next draw to issue; row == end: none left */
    uint32_t mix;              /* (set * k + s) * 0x9E3779B9u of that draw, kept by addition */
    const uint32_t *e[RAD__TEMPORAL_AHEAD]; /* issued draws: the bin ... */
    uint32_t u2[RAD__TEMPORAL_AHEAD];       /* ... and the threshold test's random word */
} rad__tpipe;

static void rad__tpipe_row(rad__tpipe *p)
{
    const rad_alias_tables *tb = p->t->tables[p->set];
    const uint64_t first = tb->row_offsets[p->row];
    p->nb = (uint32_t)(tb->row_offsets[p->row + 1u] - first);
    p->words = (uint32_t)tb->format;
    p->bins = tb->bins + (size_t)first * p->words;
}

/* the issuing side moves past the last draw of a row's table set (rare: out of the hot path) */
static void rad__tpipe_next(rad__tpipe *p)
{
    p->s = 0;
    if (++p->set == p->sets) {
        p->set = 0;
        p->mix = 0;
        if (++p->row >= p->end) return;
        p->key = rad__pcg(p->seedframe ^ p->row);
    }
    rad__tpipe_row(p);
}

/* issues the next draw of the sequence into ring slot 'slot' */
RAD__HOT void rad__tpipe_issue(rad__tpipe *p, uint32_t slot)
{
    uint32_t u1;
    if (p->row >= p->end) return;
    u1 = rad__pcg(p->key ^ p->mix);
    p->mix += 0x9E3779B9u;
    p->u2[slot] = rad__pcg(u1 ^ 0x68E31DA4u);
    p->e[slot] = p->bins + (size_t)(((uint64_t)u1 * (uint64_t)p->nb) >> 32) * p->words;
    RAD__PREFETCH(p->e[slot]);
    if (++p->s == p->k) rad__tpipe_next(p);
}

#if defined(RAD__TEMPORAL_AVX2)
/* rad__pcg on 8 lanes */
RAD__HOT __m256i rad__pcg8(__m256i v)
{
    const __m256i s = _mm256_add_epi32(_mm256_mullo_epi32(v, _mm256_set1_epi32((int)747796405u)),
                                       _mm256_set1_epi32((int)2891336453u));
    const __m256i sh = _mm256_add_epi32(_mm256_srli_epi32(s, 28), _mm256_set1_epi32(4));
    const __m256i t = _mm256_mullo_epi32(_mm256_xor_si256(_mm256_srlv_epi32(s, sh), s), _mm256_set1_epi32(277803737));
    return _mm256_xor_si256(_mm256_srli_epi32(t, 22), t);
}

/* the draw's bin (u1 * nb) >> 32 on 8 lanes: even lanes' products shifted down, odd lanes'
   kept in place */
RAD__HOT __m256i rad__bin8(__m256i u1, __m256i nb)
{
    const __m256i even = _mm256_srli_epi64(_mm256_mul_epu32(u1, nb), 32);
    const __m256i odd = _mm256_mul_epu32(_mm256_srli_epi64(u1, 32), _mm256_srli_epi64(nb, 32));
    return _mm256_blend_epi32(even, odd, 0xAA);
}

/* issues the next 8 draws of the sequence into ring slots slot .. slot + 7, the same words
   and bins as 8 calls of rad__tpipe_issue: both hashes and the bin index on 8 lanes. With
   k >= 8 the 8 draws cross at most one boundary (row or table set): lanes 0 .. m-1 belong to
   the draw's current row and set (A), lanes m .. 7 to the next one (B). Lanes past the task's
   last row repeat A's stream (valid bins of A's row: prefetched, never resolved). */
RAD__HOT void rad__tpipe_issue8(rad__tpipe *p, uint32_t slot)
{
    const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    const __m256i laneg = _mm256_mullo_epi32(lane, _mm256_set1_epi32((int)0x9E3779B9u));
    uint32_t m = p->k - p->s, key_a, mix_a, nb_a, words_a, key_b, mix_b, nb_b, words_b, j;
    const uint32_t *bins_a, *bins_b;
    __m256i inb, vkey, vmix, vnb, u1, u2, idx, inb_lo, inb_hi, base_lo, base_hi, scale_lo, scale_hi;
    if (p->k < 8u || p->row >= p->end) {
        for (j = 0; j < 8u; ++j) rad__tpipe_issue(p, slot + j);
        return;
    }
    if (m > 8u) m = 8u;
    key_a = key_b = p->key;
    mix_a = mix_b = p->mix;
    nb_a = nb_b = p->nb;
    words_a = words_b = p->words;
    bins_a = bins_b = p->bins;
    p->mix += m * 0x9E3779B9u;
    p->s += m;
    if (p->s == p->k) rad__tpipe_next(p);
    if (m < 8u && p->row < p->end) {
        key_b = p->key;
        mix_b = p->mix - m * 0x9E3779B9u; /* lane j >= m: p->mix + (j - m) * 0x9E3779B9u */
        nb_b = p->nb;
        words_b = p->words; /* the table sets may differ in format */
        bins_b = p->bins;
        p->mix += (8u - m) * 0x9E3779B9u;
        p->s += 8u - m; /* < k: 8 - m < 8 <= k */
    }
    inb = _mm256_cmpgt_epi32(lane, _mm256_set1_epi32((int)m - 1));
    vkey = _mm256_blendv_epi8(_mm256_set1_epi32((int)key_a), _mm256_set1_epi32((int)key_b), inb);
    vmix = _mm256_blendv_epi8(_mm256_set1_epi32((int)mix_a), _mm256_set1_epi32((int)mix_b), inb);
    vnb = _mm256_blendv_epi8(_mm256_set1_epi32((int)nb_a), _mm256_set1_epi32((int)nb_b), inb);
    u1 = rad__pcg8(_mm256_xor_si256(vkey, _mm256_add_epi32(vmix, laneg)));
    u2 = rad__pcg8(_mm256_xor_si256(u1, _mm256_set1_epi32(0x68E31DA4)));
    _mm256_storeu_si256((__m256i *)(void *)(p->u2 + slot), u2);
    idx = rad__bin8(u1, vnb);
    /* addresses: bins + bin * words, as 64-bit integers */
    inb_lo = _mm256_cvtepi32_epi64(_mm256_castsi256_si128(inb));
    inb_hi = _mm256_cvtepi32_epi64(_mm256_extracti128_si256(inb, 1));
    scale_lo = _mm256_set1_epi64x((long long)(4u * words_a));
    scale_hi = _mm256_set1_epi64x((long long)(4u * words_b));
    scale_lo = _mm256_blendv_epi8(scale_lo, scale_hi, inb_lo);
    scale_hi = _mm256_blendv_epi8(_mm256_set1_epi64x((long long)(4u * words_a)), scale_hi, inb_hi);
    base_lo = _mm256_set1_epi64x((long long)(uintptr_t)bins_a);
    base_hi = _mm256_set1_epi64x((long long)(uintptr_t)bins_b);
    base_lo = _mm256_blendv_epi8(base_lo, base_hi, inb_lo);
    base_hi = _mm256_blendv_epi8(_mm256_set1_epi64x((long long)(uintptr_t)bins_a), base_hi, inb_hi);
    scale_lo = _mm256_mul_epu32(_mm256_cvtepu32_epi64(_mm256_castsi256_si128(idx)), scale_lo);
    scale_hi = _mm256_mul_epu32(_mm256_cvtepu32_epi64(_mm256_extracti128_si256(idx, 1)), scale_hi);
    base_lo = _mm256_add_epi64(base_lo, scale_lo);
    base_hi = _mm256_add_epi64(base_hi, scale_hi);
    _mm256_storeu_si256((__m256i *)(void *)(p->e + slot), base_lo);
    _mm256_storeu_si256((__m256i *)(void *)(p->e + slot + 4u), base_hi);
    for (j = 0; j < 8u; ++j) RAD__PREFETCH(p->e[slot + j]);
}
#endif

/* resolves the draw in ring slot *q (issued AHEAD draws ago), issues the draw AHEAD after it
   into the freed slot (AVX2: the 8 draws after slots slot-7 .. slot once slot-7 .. slot are
   resolved), advances *q; returns the sampled RGB value (V_J, or env for J = N) */
RAD__HOT const float *rad__tpipe_take(rad__tpipe *p, uint32_t *q, uint32_t words, uint32_t n, const float *V, const float *env)
{
    const uint32_t slot = *q, *e = p->e[slot], u2 = p->u2[slot];
    uint32_t col;
#if defined(RAD__TEMPORAL_AVX2)
    if ((slot & 7u) == 7u) rad__tpipe_issue8(p, slot - 7u);
#else
    rad__tpipe_issue(p, slot);
#endif
    *q = slot + 1u == RAD__TEMPORAL_AHEAD ? 0u : slot + 1u;
    /* written without a conditional: the test is a coin flip, and clang 14 made a branch of
       '?:' here (mispredicted about half the time, ~2x slower than gcc's cmov) */
    if (words == 2u) col = (e[1] >> (16u * (uint32_t)(u2 >= e[0]))) & 0xFFFFu;
    else col = e[1u + (uint32_t)(u2 >= e[0])];
    return col < n ? V + 3u * (size_t)col : env;
}

/* blend of row i: rho (SINGLE, FEEDBACK), the adaptive weight, B_next = w B + (1 - w) X */
static void rad__temporal_finish(rad_temporal *t, uint32_t i, float *X)
{
    float w, *Bn = t->B_next + 3u * (size_t)i;
    const float *Bp = t->B + 3u * (size_t)i;
    if (t->o.mode != RAD_TEMPORAL_MULTIBOUNCE) {
        const float *rho = t->albedo + 3u * (size_t)i;
        X[0] *= rho[0];
        X[1] *= rho[1];
        X[2] *= rho[2];
    }
    if (t->o.adaptive) {
        float x = X[0] + X[1] + X[2], b = Bp[0] + Bp[1] + Bp[2], a, d, wss, sd, r, tgt = t->o.noise_target;
        uint32_t c = t->count[i];
        if (c > 0) {
            /* change test against the current estimate, on x - b winsorized at 3 standard
               deviations so single heavy-tailed samples cannot trigger it */
            sd = (float)sqrt((double)t->var[i]);
            d = x - b;
            if (d > 3.0f * sd) d = 3.0f * sd;
            if (d < -3.0f * sd) d = -3.0f * sd;
            t->fast[i] += 0.25f * (d - t->fast[i]);
            d = t->fast[i] < 0.0f ? -t->fast[i] : t->fast[i];
            if (c >= 4u && d > t->o.change_sigma * 0.378f * sd && d > tgt * (b < 0.0f ? -b : b)) c = 0;
        }
        if (c == 0) {
            t->mean[i] = x;
            t->var[i] = 0.0f;
            t->fast[i] = 0.0f;
        } else {
            a = 1.0f / (float)(c + 1u);
            if (a < 1.0f / 64.0f) a = 1.0f / 64.0f;
            t->mean[i] += a * (x - t->mean[i]);
            t->var[i] += a * ((x - t->mean[i]) * (x - t->mean[i]) - t->var[i]);
        }
        if (t->var[i] > 0.0f) {
            r = tgt * t->mean[i] * tgt * t->mean[i] / t->var[i];
            wss = (1.0f - r) / (1.0f + r);
            if (wss < 0.0f) wss = 0.0f;
            if (wss > t->o.weight_max) wss = t->o.weight_max;
        } else {
            wss = 0.0f;
        }
        w = (float)c / (float)(c + 1u);
        if (w > wss) w = wss;
        t->count[i] = c + 1u < c ? c : c + 1u;
        t->w[i] = w;
    } else {
        w = t->o.weight;
    }
    Bn[0] = w * Bp[0] + (1.0f - w) * X[0];
    Bn[1] = w * Bp[1] + (1.0f - w) * X[1];
    Bn[2] = w * Bp[2] + (1.0f - w) * X[2];
}

#if defined(RAD__TEMPORAL_AVX2)
/* VECTOR STEP (AVX2; every table set compact): eight rows side by side, one lane per row. A
   vector draw is draw s of table set c for 8 consecutive rows; a task's vector draws run block
   of 8 rows by block, set by set, sample by sample. The issuing side hashes vector draw
   d + RAD__TVEC_AHEAD (both words and the bin on 8 lanes) and prefetches its 8 bins while
   vector draw d is resolved with 8 scalar 64-bit loads (the bins) and one masked gather per
   channel (V, or E_0 for the environment column). Each lane adds its own row's values in the
   documented order, so the bits equal the plain loop's; the scalar work per draw is about a
   third of the row-at-a-time pipeline's (rad__tpipe), which matters once the misses overlap. */
#ifndef RAD__TVEC_AHEAD
#  define RAD__TVEC_AHEAD 16u /* vector draws in flight: 128 draws (12, 24, 32 measured slower) */
#endif

typedef struct rad__tvec {
    const rad_temporal *t;
    uint32_t k, sets, end, seedframe;
    uint32_t row, set, s;      /* the next vector draw to issue: rows row .. row + 7 */
    const uint32_t *bins;      /* bins of table set 'set' */
    __m256i key, nb;           /* per lane: the row's key and bin count in set 'set' */
    __m256i first_lo, first_hi; /* per lane: the row's first bin (64-bit), lanes 0-3 and 4-7 */
    uint64_t bin[RAD__TVEC_AHEAD * 8u]; /* issued vector draws: bin numbers in their set ... */
    uint32_t u2[RAD__TVEC_AHEAD * 8u];  /* ... and the threshold test's random words */
} rad__tvec;

/* loads the lanes of block 'row' in table set 'set' (rows past the task's end repeat its last
   row: their draws are issued and resolved, never finished) */
static void rad__tvec_block(rad__tvec *p)
{
    const rad_alias_tables *tb = p->t->tables[p->set];
    uint32_t key[8], nb[8], j;
    uint64_t first[8];
    for (j = 0; j < 8u; ++j) {
        const uint32_t r = p->row + j < p->end ? p->row + j : p->end - 1u;
        first[j] = tb->row_offsets[r];
        nb[j] = (uint32_t)(tb->row_offsets[r + 1u] - first[j]);
        key[j] = r;
    }
    p->bins = tb->bins;
    p->key = rad__pcg8(_mm256_xor_si256(_mm256_set1_epi32((int)p->seedframe), _mm256_loadu_si256((const __m256i *)(const void *)key)));
    p->nb = _mm256_loadu_si256((const __m256i *)(const void *)nb);
    p->first_lo = _mm256_loadu_si256((const __m256i *)(const void *)first);
    p->first_hi = _mm256_loadu_si256((const __m256i *)(const void *)(first + 4));
}

RAD__HOT void rad__tvec_issue(rad__tvec *p, uint32_t slot)
{
    uint64_t *b = p->bin + 8u * slot;
    __m256i u1, idx;
    uint32_t j;
    if (p->row >= p->end) return;
    u1 = rad__pcg8(_mm256_xor_si256(p->key, _mm256_set1_epi32((int)((p->set * p->k + p->s) * 0x9E3779B9u))));
    _mm256_storeu_si256((__m256i *)(void *)(p->u2 + 8u * slot), rad__pcg8(_mm256_xor_si256(u1, _mm256_set1_epi32(0x68E31DA4))));
    idx = rad__bin8(u1, p->nb); /* then first + bin as 64-bit integers */
    _mm256_storeu_si256((__m256i *)(void *)b, _mm256_add_epi64(p->first_lo, _mm256_cvtepu32_epi64(_mm256_castsi256_si128(idx))));
    _mm256_storeu_si256((__m256i *)(void *)(b + 4), _mm256_add_epi64(p->first_hi, _mm256_cvtepu32_epi64(_mm256_extracti128_si256(idx, 1))));
    for (j = 0; j < 8u; ++j) RAD__PREFETCH(p->bins + 2u * (size_t)b[j]);
    if (++p->s < p->k) return;
    p->s = 0;
    if (++p->set == p->sets) {
        p->set = 0;
        p->row += 8u;
        if (p->row >= p->end) return;
    }
    rad__tvec_block(p);
}

/* compact bin b as one 64-bit integer: threshold (low half), column word (high half); x86 is
   little-endian, and a view's bins may be only 4-byte aligned */
RAD__HOT long long rad__bin64(const uint32_t *bins, uint64_t b)
{
    long long v;
    memcpy(&v, bins + 2u * (size_t)b, sizeof(v));
    return v;
}

static void rad__temporal_task_vec(const rad__tstep *st, uint32_t r0, uint32_t r1)
{
    rad_temporal *t = st->t;
    const uint32_t k = t->o.samples, sets = t->table_count;
    const __m256i sign = _mm256_set1_epi32((int)0x80000000u), nvec = _mm256_set1_epi32((int)t->n);
    const __m256i sixteen = _mm256_set1_epi32(16), low16 = _mm256_set1_epi32(0xFFFF);
    const float kf = (float)k;
    const __m256 env0 = _mm256_set1_ps(st->env[0]), env1 = _mm256_set1_ps(st->env[1]), env2 = _mm256_set1_ps(st->env[2]);
    rad__tvec p;
    uint32_t row, c, s, q = 0, j;
    p.t = t;
    p.k = k;
    p.sets = sets;
    p.end = r1;
    p.seedframe = rad__pcg(rad__pcg(t->o.seed) ^ t->frame);
    p.row = r0;
    p.set = 0;
    p.s = 0;
    rad__tvec_block(&p);
    for (j = 0; j < RAD__TVEC_AHEAD; ++j) rad__tvec_issue(&p, j);
    for (row = r0; row < r1; row += 8u) {
        float X[3][8], T[8];
        for (c = 0; c < sets; ++c) {
            const uint32_t *gb = t->tables[c]->bins;
            __m256 a0 = _mm256_setzero_ps(), a1 = a0, a2 = a0, scale;
            for (s = 0; s < k; ++s) {
                /* the 8 bins, read before the slot is reused (scalar loads: two 64-bit gathers
                   cost 10-20% more per draw on the machine of BENCHMARKS.md) */
                const uint64_t *bn = p.bin + 8u * q;
                const __m256i u2 = _mm256_loadu_si256((const __m256i *)(const void *)(p.u2 + 8u * q));
                const __m256i glo = _mm256_set_epi64x(rad__bin64(gb, bn[3]), rad__bin64(gb, bn[2]), rad__bin64(gb, bn[1]), rad__bin64(gb, bn[0]));
                const __m256i ghi = _mm256_set_epi64x(rad__bin64(gb, bn[7]), rad__bin64(gb, bn[6]), rad__bin64(gb, bn[5]), rad__bin64(gb, bn[4]));
                __m256i thr, cw, col, idx3;
                __m256 valid;
                rad__tvec_issue(&p, q);
                q = q + 1u == RAD__TVEC_AHEAD ? 0u : q + 1u;
                /* [t0 c0 t1 c1 | t2 c2 t3 c3], [t4 c4 ..] -> thresholds and column words in lane order */
                thr = _mm256_castps_si256(_mm256_shuffle_ps(_mm256_castsi256_ps(glo), _mm256_castsi256_ps(ghi), 0x88));
                cw = _mm256_castps_si256(_mm256_shuffle_ps(_mm256_castsi256_ps(glo), _mm256_castsi256_ps(ghi), 0xDD));
                thr = _mm256_permute4x64_epi64(thr, 0xD8);
                cw = _mm256_permute4x64_epi64(cw, 0xD8);
                /* u2 < threshold (unsigned): the own column (low half), else the alias (high half) */
                col = _mm256_cmpgt_epi32(_mm256_xor_si256(thr, sign), _mm256_xor_si256(u2, sign));
                col = _mm256_and_si256(_mm256_srlv_epi32(cw, _mm256_andnot_si256(col, sixteen)), low16);
                valid = _mm256_castsi256_ps(_mm256_cmpgt_epi32(nvec, col));
                idx3 = _mm256_add_epi32(col, _mm256_add_epi32(col, col));
                if (sets == 1u) {
                    a0 = _mm256_add_ps(a0, _mm256_mask_i32gather_ps(env0, st->V, idx3, valid, 4));
                    a1 = _mm256_add_ps(a1, _mm256_mask_i32gather_ps(env1, st->V + 1, idx3, valid, 4));
                    a2 = _mm256_add_ps(a2, _mm256_mask_i32gather_ps(env2, st->V + 2, idx3, valid, 4));
                } else {
                    a0 = _mm256_add_ps(a0, _mm256_mask_i32gather_ps(_mm256_set1_ps(st->env[c]), st->V + c, idx3, valid, 4));
                }
            }
            for (j = 0; j < 8u; ++j) T[j] = t->tables[c]->totals[row + j < r1 ? row + j : r1 - 1u];
            scale = _mm256_div_ps(_mm256_loadu_ps(T), _mm256_set1_ps(kf)); /* T_i / k in float */
            if (sets == 1u) {
                _mm256_storeu_ps(X[0], _mm256_mul_ps(a0, scale));
                _mm256_storeu_ps(X[1], _mm256_mul_ps(a1, scale));
                _mm256_storeu_ps(X[2], _mm256_mul_ps(a2, scale));
            } else {
                _mm256_storeu_ps(X[c], _mm256_mul_ps(a0, scale));
            }
        }
        for (j = 0; j < 8u && row + j < r1; ++j) {
            float x[3];
            x[0] = X[0][j];
            x[1] = X[1][j];
            x[2] = X[2][j];
            rad__temporal_finish(t, row + j, x);
        }
    }
}
#endif

static void rad__temporal_task(void *data, uint32_t task)
{
    const rad__tstep *st = (const rad__tstep *)data;
    rad_temporal *t = st->t;
    const uint32_t n = t->n, k = t->o.samples, sets = t->table_count;
    const uint32_t r0 = (uint32_t)((uint64_t)n * task / st->tasks), r1 = (uint32_t)((uint64_t)n * (task + 1u) / st->tasks);
    const float *V = st->V, *env = st->env;
    rad__tpipe p;
    uint32_t i, c, s, q;
    if (r0 >= r1) return;
#if defined(RAD__TEMPORAL_AVX2)
    for (c = 0; c < sets && t->tables[c]->format == RAD_ALIAS_COMPACT; ++c) {}
    if (c == sets) {
        rad__temporal_task_vec(st, r0, r1);
        return;
    }
#endif
    p.t = t;
    p.k = k;
    p.sets = sets;
    p.seedframe = rad__pcg(rad__pcg(t->o.seed) ^ t->frame);
    p.row = r0;
    p.end = r1;
    p.set = 0;
    p.s = 0;
    p.mix = 0;
    p.key = rad__pcg(p.seedframe ^ r0);
    rad__tpipe_row(&p);
#if defined(RAD__TEMPORAL_AVX2)
    for (q = 0; q < RAD__TEMPORAL_AHEAD; q += 8u) rad__tpipe_issue8(&p, q);
#else
    for (q = 0; q < RAD__TEMPORAL_AHEAD; ++q) rad__tpipe_issue(&p, q);
#endif
    q = 0;
    for (i = r0; i < r1; ++i) {
        float X[3];
        /* the sums live in registers (an array indexed by the channel would go through memory
           and chain every draw's add to the previous one's store) */
        if (sets == 1u) {
            const uint32_t words = (uint32_t)t->tables[0]->format;
            float a0 = 0.0f, a1 = 0.0f, a2 = 0.0f, scale;
            for (s = 0; s < k; ++s) {
                const float *v = rad__tpipe_take(&p, &q, words, n, V, env);
                a0 += v[0];
                a1 += v[1];
                a2 += v[2];
            }
            scale = t->tables[0]->totals[i] / (float)k;
            X[0] = a0 * scale;
            X[1] = a1 * scale;
            X[2] = a2 * scale;
        } else {
            for (c = 0; c < 3u; ++c) {
                const uint32_t words = (uint32_t)t->tables[c]->format;
                float a = 0.0f;
                for (s = 0; s < k; ++s) a += rad__tpipe_take(&p, &q, words, n, V, env)[c];
                X[c] = a * (t->tables[c]->totals[i] / (float)k);
            }
        }
        rad__temporal_finish(t, i, X);
    }
}

RAD_API rad_result rad_temporal_step(rad_temporal *t, const float *E, const float E0[3], float *out_indirect)
{
    rad__tstep st;
    float *tmp;
    size_t n3, j;
    if (!t || !E) return RAD_ERROR_INVALID_ARGUMENT;
    n3 = 3u * (size_t)t->n;
    if (rad__check_input(&t->c, "rad_temporal_step", E, n3) != RAD_SUCCESS) return RAD_ERROR_NON_FINITE;
    if (E0 && !rad__finite3(E0)) {
        rad__log(&t->c, RAD_LOG_ERROR, "rad_temporal_step: E0 (%g %g %g) is not finite", (double)E0[0], (double)E0[1], (double)E0[2]);
        return RAD_ERROR_NON_FINITE;
    }
    st.t = t;
    st.env[0] = E0 ? E0[0] : 0.0f;
    st.env[1] = E0 ? E0[1] : 0.0f;
    st.env[2] = E0 ? E0[2] : 0.0f;
    if (t->o.mode == RAD_TEMPORAL_FEEDBACK) {
        for (j = 0; j < n3; ++j) t->V[j] = E[j] + t->B[j];
        st.V = t->V;
    } else {
        st.V = E;
    }
    if (t->restart_all && t->o.adaptive) memset(t->count, 0, (size_t)t->n * sizeof(uint32_t));
    t->restart_all = 0;
    st.tasks = t->c.tasks < t->n ? t->c.tasks : t->n;
    t->c.parallel_for(t->c.parallel_user, st.tasks, rad__temporal_task, &st);
    if (rad__check_output(&t->c, "rad_temporal_step", t->B_next, n3) != RAD_SUCCESS) {
        /* the step is undone: B and the frame stay as they were; adaptive weights restart */
        t->restart_all = 1;
        return RAD_ERROR_NON_FINITE;
    }
    tmp = t->B;
    t->B = t->B_next;
    t->B_next = tmp;
    t->frame++;
    if (out_indirect) memcpy(out_indirect, t->B, n3 * sizeof(float));
    return RAD_SUCCESS;
}

/* ======================================================================================== */
/* >>vp: virtual patches (voxels, face-ray samples, axis-aligned patches, gathering)       */
/* ======================================================================================== */

#define RAD__VP_MARGIN 0.4827f           /* voxels of padding around the scene bounds */
#define RAD__VP_CHUNK_RAYS (1u << 21)     /* face-ray hits kept at once */
#define RAD__VP_PAIRS 16384u              /* pair records per task for sampled visibility */

typedef struct rad__vp_pair {
    uint32_t i, j;
    float g;
} rad__vp_pair;

RAD_API void rad_vp_options_default(rad_vp_options *o)
{
    if (!o) return;
    memset(o, 0, sizeof(*o));
    o->resolution = 16;
    o->face_points = 16;
    o->weights = RAD_VP_WEIGHTS_SQUARED;
    o->ray_epsilon = 1e-5f;
    o->visibility_rays = 16;
    o->kind = RAD_VP_AXIS_ALIGNED;
    o->max_clusters = 6;
    o->metric_columns = 64;
}

/* the six split weights of a unit normal (sum 1) */
static void rad__vp_weights(rad_vp_weights kind, const float *n, float *w)
{
    int k;
    float sum = 0.0f;
    for (k = 0; k < 3; ++k) {
        float p = n[k] > 0.0f ? n[k] : 0.0f, m = n[k] < 0.0f ? -n[k] : 0.0f;
        if (kind == RAD_VP_WEIGHTS_SQUARED) { p *= p; m *= m; }
        w[2 * k] = p;
        w[2 * k + 1] = m;
        sum += p + m;
    }
    if (sum > 0.0f)
        for (k = 0; k < 6; ++k) w[k] /= sum;
}

static int rad__vp_cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : (x > y ? 1 : 0);
}

RAD_API void rad_vp_destroy(rad_virtual_patches *vp)
{
    rad_allocator a;
    if (!vp) return;
    a = vp->allocator;
    rad__free(&a, vp->areas);
    rad__free(&a, vp->albedo);
    rad__free(&a, vp->normals);
    rad__free(&a, vp->axis);
    rad__free(&a, vp->voxel);
    rad__free(&a, (void *)vp->matrix.dense);
    rad__free(&a, vp->voxel_keys);
    rad__free(&a, vp->voxel_first);
    rad__free(&a, vp->voxel_patch);
    rad__free(&a, vp->sample_first);
    rad__free(&a, vp->sample_positions);
    rad__free(&a, vp->sample_normals);
    rad__free(&a, vp->sample_albedo);
    rad__free(&a, vp->sample_areas);
    rad__free(&a, vp->sample_weights);
    rad__free(&a, vp->sample_triangles);
    rad__free(&a, vp);
}

RAD_API size_t rad_vp_memory(const rad_virtual_patches *vp)
{
    size_t n, m, v;
    if (!vp) return 0;
    n = vp->count;
    m = vp->sample_count;
    v = vp->voxel_count;
    return sizeof(*vp) + n * n * sizeof(float) + n * (8 * sizeof(float) + 1 + sizeof(uint32_t)) +
           v * (sizeof(uint64_t) + 8 * sizeof(uint32_t)) + 2 * sizeof(uint32_t) +
           m * (16 * sizeof(float) + sizeof(uint32_t));
}

/* ---- face rays ---- */

typedef struct rad__vp_build {
    const rad_scene *S;
    const rad_raycaster *rc;
    rad_vp_options o;
    rad_virtual_patches *vp;
    float eps;
    uint32_t tasks;
    /* face rays: candidate voxels [chunk_begin, chunk_begin + chunk_count) */
    const uint64_t *cand;
    uint32_t chunk_begin;
    rad_hit *hits;               /* 6 P per voxel of the chunk */
    rad_ray *rays;               /* RAD__RAY_BATCH per task */
    /* pairs */
    uint8_t *occ;                /* RAD__RAY_BATCH per task */
    uint32_t *ray_i, *ray_j;     /* RAD__RAY_BATCH per task */
    float *ray_g;
    double *acc;                 /* 6 N per task */
    uint32_t *sample_voxel;      /* M */
    float *eff;                  /* M: s_i times the sum of its corrected weights (the clamp) */
    float *rowf;                 /* N: 1 / max(1, row sum) */
    /* clustering (RAD_VP_CLUSTERED) */
    float *vscale;               /* per voxel: exact area / sum of s_i */
    uint32_t *cols, kc, nmax;    /* the metric's column samples */
    double *cscratch;            /* per task */
    size_t cper;                 /* doubles per task */
    uint8_t *slot, *ncl;         /* per sample: cluster slot; per voxel: cluster count */
    struct rad__vp_pair *pairs;  /* RAD__VP_PAIRS per task (sampled visibility) */
    uint64_t *rays_cast;         /* per task */
    float *P;                    /* N x N */
} rad__vp_build;

static void rad__vp_cell(const rad_virtual_patches *vp, uint64_t key, uint32_t *c)
{
    c[0] = (uint32_t)(key % vp->dims[0]);
    key /= vp->dims[0];
    c[1] = (uint32_t)(key % vp->dims[1]);
    c[2] = (uint32_t)(key / vp->dims[1]);
}

/* the 6 P face rays of candidate voxel 'row' of the chunk */
static rad_result rad__vp_face_row(void *data, uint32_t row, uint32_t task)
{
    rad__vp_build *b = (rad__vp_build *)data;
    const rad_virtual_patches *vp = b->vp;
    uint32_t P = b->o.face_points, c[3], f, s, n = 0;
    rad_ray *rays = b->rays + (size_t)task * RAD__RAY_BATCH;
    rad_hit *hits = b->hits + (size_t)row * 6u * P;
    float lo[3];
    int k;
    rad__vp_cell(vp, b->cand[b->chunk_begin + row], c);
    for (k = 0; k < 3; ++k) lo[k] = vp->origin[k] + (float)c[k] * vp->voxel_size[k];
    for (f = 0; f < 6; ++f) {
        int ax = (int)(f >> 1), a1 = (ax + 1) % 3, a2 = (ax + 2) % 3;
        int neg = (int)(f & 1u); /* face f = 2 ax: the low face, rays go +ax; 2 ax + 1: high face, rays go -ax */
        for (s = 0; s < P; ++s) {
            rad_ray *r = &rays[n];
            float u = ((float)s + 0.5f) / (float)P, v = rad__radical_inverse(s);
            r->origin[ax] = neg ? lo[ax] + vp->voxel_size[ax] : lo[ax];
            r->origin[a1] = lo[a1] + u * vp->voxel_size[a1];
            r->origin[a2] = lo[a2] + v * vp->voxel_size[a2];
            r->dir[0] = r->dir[1] = r->dir[2] = 0.0f;
            r->dir[ax] = neg ? -vp->voxel_size[ax] : vp->voxel_size[ax];
            r->tmin = 0.0f;
            r->tmax = 1.0f;
            if (++n == RAD__RAY_BATCH) {
                if (b->rc->intersect(b->rc->user, rays, n, hits) != RAD_SUCCESS) return RAD_ERROR_RAYCAST_FAILED;
                hits += n;
                n = 0;
            }
        }
    }
    if (n && b->rc->intersect(b->rc->user, rays, n, hits) != RAD_SUCCESS) return RAD_ERROR_RAYCAST_FAILED;
    return RAD_SUCCESS;
}

/* ---- form factors: one row voxel per call ---- */

static void rad__vp_pair_add(rad__vp_build *b, double *acc, uint32_t u, uint32_t i, uint32_t j, double g)
{
    const rad_virtual_patches *vp = b->vp;
    const float *wi = vp->sample_weights + 6 * (size_t)i, *wj = vp->sample_weights + 6 * (size_t)j;
    uint32_t vj = b->sample_voxel[j], a, c, N = vp->count;
    for (a = 0; a < 6; ++a) {
        double ga;
        if (!(wi[a] > 0.0f)) continue;
        ga = g * (double)wi[a];
        for (c = 0; c < 6; ++c) {
            double gac;
            if (!(wj[c] > 0.0f)) continue;
            gac = ga * (double)wj[c];
            acc[(size_t)a * N + vp->voxel_patch[6 * (size_t)vj + c]] += gac;
            /* both in the row voxel: the transposed entry is a row of this voxel too */
            if (vj == u) acc[(size_t)c * N + vp->voxel_patch[6 * (size_t)u + a]] += gac;
        }
    }
}

static rad_result rad__vp_flush(rad__vp_build *b, uint32_t task, uint32_t u, uint32_t count)
{
    size_t at = (size_t)task * RAD__RAY_BATCH;
    double *acc = b->acc + (size_t)task * 6u * b->vp->count;
    uint32_t k;
    if (count == 0) return RAD_SUCCESS;
    if (b->rc->occluded(b->rc->user, b->rays + at, count, b->occ + at) != RAD_SUCCESS) return RAD_ERROR_RAYCAST_FAILED;
    b->rays_cast[task] += count;
    for (k = 0; k < count; ++k)
        if (!b->occ[at + k]) rad__vp_pair_add(b, acc, u, b->ray_i[at + k], b->ray_j[at + k], (double)b->ray_g[at + k]);
    return RAD_SUCCESS;
}

static rad_result rad__vp_ff_row(void *data, uint32_t u, uint32_t task)
{
    rad__vp_build *b = (rad__vp_build *)data;
    const rad_virtual_patches *vp = b->vp;
    uint32_t N = vp->count, M = vp->sample_count, pf = vp->voxel_first[u], i, j, a, nrays = 0;
    double *acc = b->acc + (size_t)task * 6u * N;
    size_t at = (size_t)task * RAD__RAY_BATCH;
    rad_result r = RAD_SUCCESS;
    for (a = 0; a < 6; ++a) memset(acc + (size_t)a * N + pf, 0, sizeof(double) * (N - pf));
    for (i = vp->sample_first[u]; i < vp->sample_first[u + 1] && r == RAD_SUCCESS; ++i) {
        const float *pi_ = vp->sample_positions + 3 * (size_t)i, *ni = vp->sample_normals + 3 * (size_t)i;
        float ei = b->eff[i];
        for (j = i + 1; j < M; ++j) {
            const float *pj = vp->sample_positions + 3 * (size_t)j, *nj = vp->sample_normals + 3 * (size_t)j;
            float d[3], d2, ci, cj, ej = b->eff[j], fl, g, len;
            int k;
            rad__sub(d, pj, pi_);
            ci = rad__dot(d, ni);
            if (!(ci > 0.0f)) continue;
            cj = -rad__dot(d, nj);
            if (!(cj > 0.0f)) continue;
            d2 = rad__dot(d, d);
            fl = (ei > ej ? ei : ej) / (float)RAD__PI;
            /* cos_i cos_j / d^2 = ci cj / d^4 with the clamp on d^2; each factor s (c / d^2)
               is a length, so no product leaves float's range (s_i s_j alone overflowed in
               scenes of 1e12 and underflowed below 1e-9) */
            g = (vp->sample_areas[i] * (ci / d2)) * (vp->sample_areas[j] * (cj / (d2 > fl ? d2 : fl))) / (float)RAD__PI;
            if (!(g > 0.0f)) continue;
            if (b->o.skip_visibility) {
                rad__vp_pair_add(b, acc, u, i, j, (double)g);
                continue;
            }
            {
                rad_ray *ray = b->rays + at + nrays;
                for (k = 0; k < 3; ++k) {
                    ray->origin[k] = pi_[k] + ni[k] * b->eps;
                    ray->dir[k] = pj[k] + nj[k] * b->eps - ray->origin[k];
                }
                len = rad__len(ray->dir);
                ray->tmin = 0.0f;
                ray->tmax = len > 2.0f * b->eps ? 1.0f - b->eps / len : 0.5f;
                b->ray_i[at + nrays] = i;
                b->ray_j[at + nrays] = j;
                b->ray_g[at + nrays] = g;
                if (++nrays == RAD__RAY_BATCH) {
                    r = rad__vp_flush(b, task, u, nrays);
                    nrays = 0;
                    if (r != RAD_SUCCESS) break;
                }
            }
        }
    }
    if (r == RAD_SUCCESS) r = rad__vp_flush(b, task, u, nrays);
    if (r != RAD_SUCCESS) return r;
    /* the rows of u's patches, columns from u's first patch on */
    for (a = 0; a < 6; ++a) {
        uint32_t p = vp->voxel_patch[6 * (size_t)u + a], c;
        if (p == RAD_NONE) continue;
        for (c = pf; c < N; ++c) b->P[(size_t)p * N + c] = (float)acc[(size_t)a * N + c];
    }
    return RAD_SUCCESS;
}

/* adds 'scale' times the 6 x 6 block p0 (row axis of u, column axis of v) into the row voxel's
   accumulator, and its transpose when v == u */
static void rad__vp_add_block(rad__vp_build *b, double *acc, uint32_t u, uint32_t v, const double *p0, double scale)
{
    const rad_virtual_patches *vp = b->vp;
    uint32_t a, c, N = vp->count;
    for (a = 0; a < 6; ++a) {
        uint32_t pa = vp->voxel_patch[6 * (size_t)u + a];
        if (pa == RAD_NONE) continue;
        for (c = 0; c < 6; ++c) {
            uint32_t pc = vp->voxel_patch[6 * (size_t)v + c];
            double x = p0[6 * a + c] * scale;
            if (pc == RAD_NONE || x == 0.0) continue;
            acc[(size_t)a * N + pc] += x;
            if (v == u) acc[(size_t)c * N + pa] += x;
        }
    }
}

/* row voxel u with visibility sampled per voxel pair (see VISIBILITY) */
static rad_result rad__vp_ff_row_sampled(void *data, uint32_t u, uint32_t task)
{
    rad__vp_build *b = (rad__vp_build *)data;
    const rad_virtual_patches *vp = b->vp;
    uint32_t N = vp->count, pf = vp->voxel_first[u], i, j, a, v, K = b->o.visibility_rays;
    double *acc = b->acc + (size_t)task * 6u * N;
    size_t at = (size_t)task * RAD__RAY_BATCH;
    rad__vp_pair *list = b->pairs ? b->pairs + (size_t)task * RAD__VP_PAIRS : NULL; /* NULL: skip_visibility */
    for (a = 0; a < 6; ++a) memset(acc + (size_t)a * N + pf, 0, sizeof(double) * (N - pf));
    for (v = u; v < vp->voxel_count; ++v) {
        double p0[36], total = 0.0, vis;
        uint32_t n = 0, stride = 1, seen = 0, s, nr = 0;
        memset(p0, 0, sizeof(p0));
        for (i = vp->sample_first[u]; i < vp->sample_first[u + 1]; ++i) {
            const float *pi_ = vp->sample_positions + 3 * (size_t)i, *ni = vp->sample_normals + 3 * (size_t)i;
            const float *wi = vp->sample_weights + 6 * (size_t)i;
            float si = vp->sample_areas[i], ei = b->eff[i];
            double t6[6] = { 0.0, 0.0, 0.0, 0.0, 0.0, 0.0 }; /* sum_j g_ij w_jc */
            for (j = (v == u ? i + 1 : vp->sample_first[v]); j < vp->sample_first[v + 1]; ++j) {
                const float *pj = vp->sample_positions + 3 * (size_t)j, *nj = vp->sample_normals + 3 * (size_t)j;
                const float *wj = vp->sample_weights + 6 * (size_t)j;
                float d[3], d2, ci, cj, sj = vp->sample_areas[j], ej = b->eff[j], fl, g;
                uint32_t c;
                rad__sub(d, pj, pi_);
                ci = rad__dot(d, ni);
                if (!(ci > 0.0f)) continue;
                cj = -rad__dot(d, nj);
                if (!(cj > 0.0f)) continue;
                d2 = rad__dot(d, d);
                fl = (ei > ej ? ei : ej) / (float)RAD__PI;
                g = (si * (ci / d2)) * (sj * (cj / (d2 > fl ? d2 : fl))) / (float)RAD__PI; /* as above */
                if (!(g > 0.0f)) continue;
                for (c = 0; c < 6; ++c) t6[c] += (double)g * (double)wj[c];
                if (b->o.skip_visibility) continue;
                /* the pair list, thinned systematically when full */
                if (seen++ % stride != 0) continue;
                if (n == RAD__VP_PAIRS) {
                    uint32_t q;
                    for (q = 0; q < n / 2; ++q) list[q] = list[2 * q];
                    n /= 2;
                    stride *= 2;
                    if ((seen - 1) % stride != 0) continue;
                }
                list[n].i = i;
                list[n].j = j;
                list[n].g = g;
                ++n;
            }
            for (a = 0; a < 6; ++a)
                if (wi[a] > 0.0f)
                    for (j = 0; j < 6; ++j) p0[6 * a + j] += (double)wi[a] * t6[j];
        }
        if (b->o.skip_visibility || n == 0) {
            if (n == 0 && !b->o.skip_visibility) continue; /* nothing faces each other */
            rad__vp_add_block(b, acc, u, v, p0, 1.0);
            continue;
        }
        for (s = 0; s < n; ++s) total += (double)list[s].g;
        if (n <= K) {
            /* every pair its ray: the kernel-weighted visible fraction */
            for (s = 0; s < n; ++s) {
                const rad__vp_pair *q = &list[s];
                rad_ray *ray = b->rays + at + s;
                const float *pi_ = vp->sample_positions + 3 * (size_t)q->i, *ni = vp->sample_normals + 3 * (size_t)q->i;
                const float *pj = vp->sample_positions + 3 * (size_t)q->j, *nj = vp->sample_normals + 3 * (size_t)q->j;
                float len;
                int k;
                for (k = 0; k < 3; ++k) {
                    ray->origin[k] = pi_[k] + ni[k] * b->eps;
                    ray->dir[k] = pj[k] + nj[k] * b->eps - ray->origin[k];
                }
                len = rad__len(ray->dir);
                ray->tmin = 0.0f;
                ray->tmax = len > 2.0f * b->eps ? 1.0f - b->eps / len : 0.5f;
            }
            nr = n;
        } else {
            /* K pairs drawn with probability proportional to g, stratified */
            uint32_t h = rad__hash(u * 0x9E3779B9u ^ rad__hash(v + 0x632BE5ABu));
            double r = (double)(h >> 8) / 16777216.0, cum = 0.0;
            uint32_t q = 0;
            for (s = 0; s < K; ++s) {
                double target = ((double)s + r) / (double)K * total;
                rad_ray *ray = b->rays + at + s;
                const float *pi_, *ni, *pj, *nj;
                float len;
                int k;
                while (q + 1 < n && cum + (double)list[q].g <= target) cum += (double)list[q++].g;
                pi_ = vp->sample_positions + 3 * (size_t)list[q].i;
                ni = vp->sample_normals + 3 * (size_t)list[q].i;
                pj = vp->sample_positions + 3 * (size_t)list[q].j;
                nj = vp->sample_normals + 3 * (size_t)list[q].j;
                for (k = 0; k < 3; ++k) {
                    ray->origin[k] = pi_[k] + ni[k] * b->eps;
                    ray->dir[k] = pj[k] + nj[k] * b->eps - ray->origin[k];
                }
                len = rad__len(ray->dir);
                ray->tmin = 0.0f;
                ray->tmax = len > 2.0f * b->eps ? 1.0f - b->eps / len : 0.5f;
                b->ray_g[at + s] = 1.0f;
            }
            nr = K;
        }
        if (b->rc->occluded(b->rc->user, b->rays + at, nr, b->occ + at) != RAD_SUCCESS) return RAD_ERROR_RAYCAST_FAILED;
        b->rays_cast[task] += nr;
        vis = 0.0;
        if (n <= K) {
            for (s = 0; s < n; ++s)
                if (!b->occ[at + s]) vis += (double)list[s].g;
            vis /= total;
        } else {
            for (s = 0; s < K; ++s)
                if (!b->occ[at + s]) vis += 1.0;
            vis /= (double)K;
        }
        if (vis > 0.0) rad__vp_add_block(b, acc, u, v, p0, vis);
    }
    for (a = 0; a < 6; ++a) {
        uint32_t p = vp->voxel_patch[6 * (size_t)u + a], c;
        if (p == RAD_NONE) continue;
        for (c = pf; c < N; ++c) b->P[(size_t)p * N + c] = (float)acc[(size_t)a * N + c];
    }
    return RAD_SUCCESS;
}

/* mirror P into the columns left of each row's voxel, then divide by the row's area */
static rad_result rad__vp_mirror_row(void *data, uint32_t p, uint32_t task)
{
    rad__vp_build *b = (rad__vp_build *)data;
    const rad_virtual_patches *vp = b->vp;
    uint32_t N = vp->count, pf = vp->voxel_first[vp->voxel[p]], c;
    (void)task;
    for (c = 0; c < pf; ++c) b->P[(size_t)p * N + c] = b->P[(size_t)c * N + p];
    return RAD_SUCCESS;
}

/* c_p = 1 / max(1, row sum of p) from the symmetric P */
static rad_result rad__vp_rowsum_row(void *data, uint32_t p, uint32_t task)
{
    rad__vp_build *b = (rad__vp_build *)data;
    uint32_t N = b->vp->count, c;
    const float *row = b->P + (size_t)p * N;
    double sum = 0.0;
    (void)task;
    for (c = 0; c < N; ++c) sum += (double)row[c];
    sum /= (double)b->vp->areas[p];
    b->rowf[p] = sum > 1.0 ? (float)(1.0 / sum) : 1.0f;
    return RAD_SUCCESS;
}

static rad_result rad__vp_divide_row(void *data, uint32_t p, uint32_t task)
{
    rad__vp_build *b = (rad__vp_build *)data;
    uint32_t N = b->vp->count, c;
    float *row = b->P + (size_t)p * N, cp = b->rowf[p];
    double inv = 1.0 / (double)b->vp->areas[p];
    (void)task;
    for (c = 0; c < N; ++c) row[c] = (float)((double)row[c] * (double)(cp < b->rowf[c] ? cp : b->rowf[c]) * inv);
    return RAD_SUCCESS;
}

/* grows the sample arrays to hold 'need' samples */
static int rad__vp_grow(rad__vp_build *b, uint32_t *cap, uint32_t need, float **pos, uint32_t **tri, uint32_t **vox,
                        float **bary)
{
    uint32_t n = *cap ? *cap : 1024u;
    float *p2, *b2;
    uint32_t *t2, *v2;
    const rad_allocator *A = &b->vp->allocator;
    if (need <= *cap) return 1;
    while (n < need) n = n > 0x7FFFFFFFu ? 0xFFFFFFFEu : 2u * n;
    p2 = (float *)rad__realloc(A, *pos, sizeof(float) * 3u * *cap, sizeof(float) * 3u * n);
    if (!p2) return 0;
    *pos = p2;
    b2 = (float *)rad__realloc(A, *bary, sizeof(float) * 2u * *cap, sizeof(float) * 2u * n);
    if (!b2) return 0;
    *bary = b2;
    t2 = (uint32_t *)rad__realloc(A, *tri, sizeof(uint32_t) * *cap, sizeof(uint32_t) * n);
    if (!t2) return 0;
    *tri = t2;
    v2 = (uint32_t *)rad__realloc(A, *vox, sizeof(uint32_t) * *cap, sizeof(uint32_t) * n);
    if (!v2) return 0;
    *vox = v2;
    *cap = n;
    return 1;
}

/* area of triangle tv clipped to the box [lo, hi] (Sutherland-Hodgman in double) */
static double rad__vp_clip_area(const float *tv, const double *lo, const double *hi)
{
    double poly[2][12][3], cr[3] = { 0.0, 0.0, 0.0 };
    int n = 3, cur = 0, k, plane, i;
    for (i = 0; i < 3; ++i)
        for (k = 0; k < 3; ++k) poly[0][i][k] = tv[3 * i + k];
    for (plane = 0; plane < 6 && n > 0; ++plane) {
        int ax = plane >> 1, m = 0;
        double bound = (plane & 1) ? hi[ax] : lo[ax], sgn = (plane & 1) ? -1.0 : 1.0;
        for (i = 0; i < n; ++i) {
            const double *a = poly[cur][i], *b = poly[cur][(i + 1) % n];
            double da = sgn * (a[ax] - bound), db = sgn * (b[ax] - bound);
            if (da >= 0.0) { memcpy(poly[1 - cur][m], a, sizeof(poly[0][0])); ++m; }
            if ((da >= 0.0) != (db >= 0.0)) {
                double t = da / (da - db);
                for (k = 0; k < 3; ++k) poly[1 - cur][m][k] = a[k] + t * (b[k] - a[k]);
                ++m;
            }
        }
        n = m;
        cur = 1 - cur;
    }
    for (i = 1; i + 1 < n; ++i) {
        double e1[3], e2[3];
        for (k = 0; k < 3; ++k) { e1[k] = poly[cur][i][k] - poly[cur][0][k]; e2[k] = poly[cur][i + 1][k] - poly[cur][0][k]; }
        cr[0] += e1[1] * e2[2] - e1[2] * e2[1];
        cr[1] += e1[2] * e2[0] - e1[0] * e2[2];
        cr[2] += e1[0] * e2[1] - e1[1] * e2[0];
    }
    return 0.5 * sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
}

/* unoccluded point-to-point form factor from sample i to sample k (area-corrected areas) */
static double rad__vp_ff_pp(const rad__vp_build *b, uint32_t i, uint32_t k)
{
    const rad_virtual_patches *vp = b->vp;
    float d[3], d2, ci, ck, ei = b->eff[i], ek = b->eff[k], fl;
    if (i == k) return 0.0;
    rad__sub(d, vp->sample_positions + 3 * (size_t)k, vp->sample_positions + 3 * (size_t)i);
    ci = rad__dot(d, vp->sample_normals + 3 * (size_t)i);
    ck = -rad__dot(d, vp->sample_normals + 3 * (size_t)k);
    if (!(ci > 0.0f) || !(ck > 0.0f)) return 0.0;
    d2 = rad__dot(d, d);
    fl = (ei > ek ? ei : ek) / (float)RAD__PI;
    return (double)ek * (double)(ci / d2) * (double)(ck / (d2 > fl ? d2 : fl)) / RAD__PI;
}

/* the clustering metric between clusters a and b of a task's scratch */
static double rad__vp_metric(const double *R, const double *C, const double *col, const double *nrm, uint32_t kc, uint32_t a,
                             uint32_t b)
{
    double dc = 0.0, dn, df = 0.0;
    uint32_t t;
    int k;
    for (k = 0; k < 3; ++k) dc += (col[3 * a + k] - col[3 * b + k]) * (col[3 * a + k] - col[3 * b + k]);
    dn = nrm[3 * a] * nrm[3 * b] + nrm[3 * a + 1] * nrm[3 * b + 1] + nrm[3 * a + 2] * nrm[3 * b + 2];
    for (t = 0; t < kc; ++t) {
        double x = R[(size_t)a * kc + t] - R[(size_t)b * kc + t], y = C[(size_t)a * kc + t] - C[(size_t)b * kc + t];
        df += x * x + y * y;
    }
    return (1.0 + sqrt(dc)) * (2.0 - dn) * (1.0 + sqrt(df));
}

/* greedy clustering of voxel v's samples into at most max_clusters (>>api_vp) */
static rad_result rad__vp_cluster_row(void *data, uint32_t v, uint32_t task)
{
    rad__vp_build *b = (rad__vp_build *)data;
    const rad_virtual_patches *vp = b->vp;
    uint32_t s0 = vp->sample_first[v], n = vp->sample_first[v + 1] - s0, Q = b->o.max_clusters, kc = b->kc, i, j, t;
    uint32_t nm = b->nmax, alive;
    double *R = b->cscratch + (size_t)task * b->cper, *C = R + (size_t)nm * kc, *D = C + (size_t)nm * kc;
    double *area = D + (size_t)nm * nm, *col = area + nm, *nrm = col + 3 * (size_t)nm, *label = nrm + 3 * (size_t)nm;
    double *live = label + nm;
    int k;
    if (n <= Q) {
        for (i = 0; i < n; ++i) b->slot[s0 + i] = (uint8_t)i;
        b->ncl[v] = (uint8_t)n;
        return RAD_SUCCESS;
    }
    for (i = 0; i < n; ++i) {
        uint32_t si = s0 + i;
        area[i] = (double)b->eff[si];
        for (k = 0; k < 3; ++k) {
            col[3 * i + k] = (double)vp->sample_albedo[3 * (size_t)si + k];
            nrm[3 * i + k] = (double)vp->sample_normals[3 * (size_t)si + k];
        }
        for (t = 0; t < kc; ++t) {
            R[(size_t)i * kc + t] = rad__vp_ff_pp(b, si, b->cols[t]);
            C[(size_t)i * kc + t] = rad__vp_ff_pp(b, b->cols[t], si);
        }
        label[i] = (double)i;
        live[i] = 1.0;
    }
    for (i = 0; i < n; ++i)
        for (j = i + 1; j < n; ++j) D[(size_t)i * nm + j] = rad__vp_metric(R, C, col, nrm, kc, i, j);
    for (alive = n; alive > Q; --alive) {
        uint32_t ba = 0, bb = 0;
        double best = -1.0, A;
        for (i = 0; i < n; ++i) {
            if (live[i] == 0.0) continue;
            for (j = i + 1; j < n; ++j)
                if (live[j] != 0.0 && (best < 0.0 || D[(size_t)i * nm + j] < best)) { best = D[(size_t)i * nm + j]; ba = i; bb = j; }
        }
        /* merge bb into ba (the merge rules of >>api_vp) */
        A = area[ba] + area[bb];
        for (t = 0; t < kc; ++t) {
            R[(size_t)ba * kc + t] = (area[ba] * R[(size_t)ba * kc + t] + area[bb] * R[(size_t)bb * kc + t]) / A;
            C[(size_t)ba * kc + t] += C[(size_t)bb * kc + t];
        }
        {
            double nn[3], len;
            for (k = 0; k < 3; ++k) {
                col[3 * ba + k] = (area[ba] * col[3 * ba + k] + area[bb] * col[3 * bb + k]) / A;
                nn[k] = area[ba] * nrm[3 * ba + k] + area[bb] * nrm[3 * bb + k];
            }
            len = sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
            if (len > 0.0)
                for (k = 0; k < 3; ++k) nrm[3 * ba + k] = nn[k] / len;
        }
        area[ba] = A;
        live[bb] = 0.0;
        for (i = 0; i < n; ++i)
            if (label[i] == (double)bb) label[i] = (double)ba;
        for (i = 0; i < n; ++i) {
            if (live[i] == 0.0 || i == ba) continue;
            if (i < ba) D[(size_t)i * nm + ba] = rad__vp_metric(R, C, col, nrm, kc, i, ba);
            else D[(size_t)ba * nm + i] = rad__vp_metric(R, C, col, nrm, kc, ba, i);
        }
    }
    /* slots in order of the surviving clusters */
    for (i = 0, t = 0; i < n; ++i)
        if (live[i] != 0.0) live[i] = (double)(++t); /* slot + 1 */
    for (i = 0; i < n; ++i) b->slot[s0 + i] = (uint8_t)(live[(uint32_t)label[i]] - 1.0);
    b->ncl[v] = (uint8_t)t;
    return RAD_SUCCESS;
}

/* maps the form-factor stage's progress to [0.1, 1] */
typedef struct rad__vp_progress {
    int (*fn)(void *user, float fraction);
    void *user;
} rad__vp_progress;

static int rad__vp_progress_fn(void *user, float fraction)
{
    const rad__vp_progress *p = (const rad__vp_progress *)user;
    return p->fn(p->user, 0.1f + 0.9f * fraction);
}

static rad_result rad__vp_build_run(rad__vp_build *b, const rad__ctx *c)
{
    rad_virtual_patches *vp = b->vp;
    const rad_scene *S = b->S;
    const rad_allocator *A = &vp->allocator;
    uint64_t *cand = NULL, total = 0;
    uint32_t ncand = 0, t, P = b->o.face_points, cap = 0, M = 0, chunk, begin, v, i, a, N = 0;
    uint32_t *tri_count = NULL, *s_tri = NULL, *s_vox = NULL, *cand_first = NULL, *voxel_cand = NULL;
    double *cand_area = NULL;
    float *s_pos = NULL, *s_bary = NULL;
    size_t bytes, q;
    rad_result r = RAD_SUCCESS;
    int k;

    /* 1. candidate voxels from triangle bounds */
    for (t = 0; t < S->triangle_count; ++t) {
        const float *tv = S->positions + 9 * (size_t)t;
        uint64_t n = 1;
        for (k = 0; k < 3; ++k) {
            float mn = tv[k], mx = tv[k];
            int64_t i0, i1;
            if (tv[3 + k] < mn) mn = tv[3 + k];
            if (tv[6 + k] < mn) mn = tv[6 + k];
            if (tv[3 + k] > mx) mx = tv[3 + k];
            if (tv[6 + k] > mx) mx = tv[6 + k];
            i0 = (int64_t)floor((double)(mn - vp->origin[k]) / (double)vp->voxel_size[k]);
            i1 = (int64_t)floor((double)(mx - vp->origin[k]) / (double)vp->voxel_size[k]);
            if (i0 < 0) i0 = 0;
            if (i1 > (int64_t)vp->dims[k] - 1) i1 = (int64_t)vp->dims[k] - 1;
            n *= (uint64_t)(i1 >= i0 ? i1 - i0 + 1 : 0);
        }
        total += n;
        if (total > 0xFFFFFFF0u) {
            rad__log(c, RAD_LOG_ERROR, "virtual patches: triangles overlap more than 2^32 voxels (use bigger voxels)");
            return RAD_ERROR_SIZE_OVERFLOW;
        }
    }
    cand = (uint64_t *)rad__alloc_array(A, (size_t)total, sizeof(uint64_t));
    if (!cand) return RAD_ERROR_OUT_OF_MEMORY;
    for (t = 0, q = 0; t < S->triangle_count; ++t) {
        const float *tv = S->positions + 9 * (size_t)t;
        int64_t i0[3], i1[3], x, y, z;
        for (k = 0; k < 3; ++k) {
            float mn = tv[k], mx = tv[k];
            if (tv[3 + k] < mn) mn = tv[3 + k];
            if (tv[6 + k] < mn) mn = tv[6 + k];
            if (tv[3 + k] > mx) mx = tv[3 + k];
            if (tv[6 + k] > mx) mx = tv[6 + k];
            i0[k] = (int64_t)floor((double)(mn - vp->origin[k]) / (double)vp->voxel_size[k]);
            i1[k] = (int64_t)floor((double)(mx - vp->origin[k]) / (double)vp->voxel_size[k]);
            if (i0[k] < 0) i0[k] = 0;
            if (i1[k] > (int64_t)vp->dims[k] - 1) i1[k] = (int64_t)vp->dims[k] - 1;
        }
        for (z = i0[2]; z <= i1[2]; ++z)
            for (y = i0[1]; y <= i1[1]; ++y)
                for (x = i0[0]; x <= i1[0]; ++x)
                    cand[q++] = (uint64_t)x + (uint64_t)vp->dims[0] * ((uint64_t)y + (uint64_t)vp->dims[1] * (uint64_t)z);
    }
    qsort(cand, (size_t)total, sizeof(uint64_t), rad__vp_cmp_u64);
    for (q = 0; q < (size_t)total; ++q)
        if (q == 0 || cand[q] != cand[q - 1]) cand[ncand++] = cand[q];
    vp->candidate_voxels = ncand;
    b->cand = cand;

    /* exact surface area per candidate voxel and axis: each triangle clipped to the voxels its
       bounds overlap, times the split weights of its normal */
    cand_area = (double *)rad__alloc_array(A, ncand, 6 * sizeof(double));
    if (!cand_area) { r = RAD_ERROR_OUT_OF_MEMORY; goto done; }
    memset(cand_area, 0, sizeof(double) * 6u * ncand);
    for (t = 0; t < S->triangle_count; ++t) {
        const float *tv = S->positions + 9 * (size_t)t;
        int64_t i0[3], i1[3], x, y, z;
        float wt[6];
        rad__vp_weights(b->o.weights, S->normals + 3 * (size_t)t, wt);
        for (k = 0; k < 3; ++k) {
            float mn = tv[k], mx = tv[k];
            if (tv[3 + k] < mn) mn = tv[3 + k];
            if (tv[6 + k] < mn) mn = tv[6 + k];
            if (tv[3 + k] > mx) mx = tv[3 + k];
            if (tv[6 + k] > mx) mx = tv[6 + k];
            i0[k] = (int64_t)floor((double)(mn - vp->origin[k]) / (double)vp->voxel_size[k]);
            i1[k] = (int64_t)floor((double)(mx - vp->origin[k]) / (double)vp->voxel_size[k]);
            if (i0[k] < 0) i0[k] = 0;
            if (i1[k] > (int64_t)vp->dims[k] - 1) i1[k] = (int64_t)vp->dims[k] - 1;
        }
        for (z = i0[2]; z <= i1[2]; ++z)
            for (y = i0[1]; y <= i1[1]; ++y)
                for (x = i0[0]; x <= i1[0]; ++x) {
                    uint64_t key = (uint64_t)x + (uint64_t)vp->dims[0] * ((uint64_t)y + (uint64_t)vp->dims[1] * (uint64_t)z);
                    double lo[3], hi[3], ar;
                    uint32_t lo_i = 0, hi_i = ncand;
                    int64_t cell[3];
                    cell[0] = x; cell[1] = y; cell[2] = z;
                    for (k = 0; k < 3; ++k) {
                        lo[k] = (double)vp->origin[k] + (double)cell[k] * (double)vp->voxel_size[k];
                        hi[k] = lo[k] + (double)vp->voxel_size[k];
                    }
                    /* a triangle inside one voxel needs no clipping */
                    ar = (i0[0] == i1[0] && i0[1] == i1[1] && i0[2] == i1[2]) ? (double)S->areas[t] : rad__vp_clip_area(tv, lo, hi);
                    if (!(ar > 0.0)) continue;
                    while (lo_i < hi_i) {
                        uint32_t mid = lo_i + (hi_i - lo_i) / 2;
                        if (cand[mid] < key) lo_i = mid + 1;
                        else hi_i = mid;
                    }
                    for (k = 0; k < 6; ++k) cand_area[6 * (size_t)lo_i + k] += ar * (double)wt[k];
                }
    }

    /* 2. face rays, chunk by chunk; samples appended in voxel order */
    chunk = RAD__VP_CHUNK_RAYS / (6u * P);
    if (chunk < 1) chunk = 1;
    if (chunk > ncand) chunk = ncand;
    b->hits = (rad_hit *)rad__alloc_array(A, (size_t)chunk * 6u * P, sizeof(rad_hit));
    b->rays = (rad_ray *)rad__alloc_array(A, (size_t)b->tasks * RAD__RAY_BATCH, sizeof(rad_ray));
    tri_count = (uint32_t *)rad__alloc_array(A, S->triangle_count, sizeof(uint32_t));
    cand_first = (uint32_t *)rad__alloc_array(A, (size_t)ncand + 1u, sizeof(uint32_t));
    if (!b->hits || !b->rays || !tri_count || !cand_first) { r = RAD_ERROR_OUT_OF_MEMORY; goto done; }
    memset(tri_count, 0, sizeof(uint32_t) * S->triangle_count);
    for (begin = 0; begin < ncand && r == RAD_SUCCESS; begin += chunk) {
        uint32_t cnt = ncand - begin < chunk ? ncand - begin : chunk, h;
        rad__ctx cc = *c;
        cc.progress = NULL; /* progress once per chunk, below */
        b->chunk_begin = begin;
        r = rad__for_rows(&cc, cnt, b->tasks < cnt ? b->tasks : cnt, rad__vp_face_row, b);
        if (r != RAD_SUCCESS) break;
        vp->face_rays += (uint64_t)cnt * 6u * P;
        for (v = 0; v < cnt; ++v) {
            cand_first[begin + v] = M;
            for (h = 0; h < 6u * P; ++h) {
                const rad_hit *hit = &b->hits[(size_t)v * 6u * P + h];
                const float *tv;
                float b0;
                if (hit->triangle == RAD_NONE || hit->triangle >= S->triangle_count) continue;
                if (M == 0xFFFFFFFEu) {
                    rad__log(c, RAD_LOG_ERROR, "virtual patches: more than 2^32 - 2 samples (use fewer face points)");
                    r = RAD_ERROR_SIZE_OVERFLOW;
                    goto done;
                }
                if (!rad__vp_grow(b, &cap, M + 1u, &s_pos, &s_tri, &s_vox, &s_bary)) { r = RAD_ERROR_OUT_OF_MEMORY; goto done; }
                tv = S->positions + 9 * (size_t)hit->triangle;
                b0 = 1.0f - hit->b1 - hit->b2;
                for (k = 0; k < 3; ++k) s_pos[3 * (size_t)M + k] = b0 * tv[k] + hit->b1 * tv[3 + k] + hit->b2 * tv[6 + k];
                s_bary[2 * (size_t)M] = hit->b1;
                s_bary[2 * (size_t)M + 1] = hit->b2;
                s_tri[M] = hit->triangle;
                s_vox[M] = begin + v;
                tri_count[hit->triangle]++;
                ++M;
            }
        }
        if (c->progress && c->progress(c->progress_user, 0.1f * (float)(begin + cnt) / (float)ncand)) r = RAD_ERROR_CANCELLED;
    }
    if (r != RAD_SUCCESS) goto done;
    cand_first[ncand] = M;
    rad__free(A, b->hits);
    b->hits = NULL;
    if (M == 0) {
        rad__log(c, RAD_LOG_ERROR, "virtual patches: no face ray hit the scene (%u candidate voxels)", ncand);
        r = RAD_ERROR_EMPTY_SCENE;
        goto done;
    }

    /* 3. non-empty voxels, samples and their split weights */
    for (v = 0; v < ncand; ++v)
        if (cand_first[v + 1] > cand_first[v]) vp->voxel_count++;
    vp->sample_count = M;
    vp->voxel_keys = (uint64_t *)rad__alloc_array(A, vp->voxel_count, sizeof(uint64_t));
    vp->voxel_first = (uint32_t *)rad__alloc_array(A, (size_t)vp->voxel_count + 1u, sizeof(uint32_t));
    vp->sample_first = (uint32_t *)rad__alloc_array(A, (size_t)vp->voxel_count + 1u, sizeof(uint32_t));
    vp->voxel_patch = (uint32_t *)rad__alloc_array(A, vp->voxel_count, 6 * sizeof(uint32_t));
    vp->sample_normals = (float *)rad__alloc_array(A, M, 3 * sizeof(float));
    vp->sample_albedo = (float *)rad__alloc_array(A, M, 3 * sizeof(float));
    vp->sample_areas = (float *)rad__alloc_array(A, M, sizeof(float));
    vp->sample_weights = (float *)rad__alloc_array(A, M, 6 * sizeof(float));
    b->sample_voxel = (uint32_t *)rad__alloc_array(A, M, sizeof(uint32_t));
    voxel_cand = (uint32_t *)rad__alloc_array(A, vp->voxel_count, sizeof(uint32_t));
    if (!vp->voxel_keys || !vp->voxel_first || !vp->sample_first || !vp->voxel_patch || !vp->sample_normals ||
        !vp->sample_albedo || !vp->sample_areas || !vp->sample_weights || !b->sample_voxel || !voxel_cand) {
        r = RAD_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    for (v = 0, i = 0; v < ncand; ++v) {
        uint32_t s;
        if (cand_first[v + 1] == cand_first[v]) continue;
        vp->voxel_keys[i] = cand[v];
        voxel_cand[i] = v;
        vp->sample_first[i] = cand_first[v];
        for (s = cand_first[v]; s < cand_first[v + 1]; ++s) b->sample_voxel[s] = i;
        ++i;
    }
    vp->sample_first[vp->voxel_count] = M;
    vp->sample_positions = s_pos;
    vp->sample_triangles = s_tri;
    s_pos = NULL;
    s_tri = NULL;
    for (i = 0; i < M; ++i) {
        uint32_t tr = vp->sample_triangles[i];
        memcpy(vp->sample_normals + 3 * (size_t)i, S->normals + 3 * (size_t)tr, 3 * sizeof(float));
        rad_scene_albedo(S, tr, s_bary[2 * (size_t)i], s_bary[2 * (size_t)i + 1], vp->sample_albedo + 3 * (size_t)i);
        for (k = 0; k < 3; ++k)
            if (!(vp->sample_albedo[3 * (size_t)i + k] >= 0.0f && vp->sample_albedo[3 * (size_t)i + k] < 1.0f)) {
                rad__log(c, RAD_LOG_ERROR, "virtual patches: the albedo of triangle %u is outside [0, 1)", tr);
                r = RAD_ERROR_ALBEDO_RANGE;
                goto done;
            }
        vp->sample_areas[i] = S->areas[tr] / (float)tri_count[tr];
        rad__vp_weights(b->o.weights, vp->sample_normals + 3 * (size_t)i, vp->sample_weights + 6 * (size_t)i);
    }

    /* 4. patches: one per voxel and axis with samples; the weights of its samples are scaled
       so that the patch area is the exact clipped area of the voxel's surface on that axis
       (clustered: one per cluster, every sample scaled by its voxel's area correction) */
    if (b->o.kind == RAD_VP_CLUSTERED) {
        uint32_t T = b->tasks < vp->voxel_count ? b->tasks : vp->voxel_count, s;
        rad__ctx cc = *c;
        cc.progress = NULL;
        b->vscale = (float *)rad__alloc_array(A, vp->voxel_count, sizeof(float));
        b->eff = (float *)rad__alloc_array(A, M, sizeof(float));
        b->slot = (uint8_t *)rad__alloc_array(A, M, 1);
        b->ncl = (uint8_t *)rad__alloc_array(A, vp->voxel_count, 1);
        b->kc = b->o.metric_columns < M ? b->o.metric_columns : M;
        b->cols = (uint32_t *)rad__alloc_array(A, b->kc, sizeof(uint32_t));
        b->nmax = 1;
        for (v = 0; v < vp->voxel_count; ++v)
            if (vp->sample_first[v + 1] - vp->sample_first[v] > b->nmax) b->nmax = vp->sample_first[v + 1] - vp->sample_first[v];
        b->cper = 2 * (size_t)b->nmax * b->kc + (size_t)b->nmax * b->nmax + 9 * (size_t)b->nmax;
        b->cscratch = (double *)rad__alloc_array(A, (size_t)T, b->cper * sizeof(double));
        if (!b->vscale || !b->eff || !b->slot || !b->ncl || !b->cols || !b->cscratch) { r = RAD_ERROR_OUT_OF_MEMORY; goto done; }
        for (v = 0; v < vp->voxel_count; ++v) {
            double have = 0.0, exact = 0.0;
            for (a = 0; a < 6; ++a) exact += cand_area[6 * (size_t)voxel_cand[v] + a];
            for (s = vp->sample_first[v]; s < vp->sample_first[v + 1]; ++s) have += (double)vp->sample_areas[s];
            b->vscale[v] = have > 0.0 && exact > 0.0 ? (float)(exact / have) : 1.0f;
            for (s = vp->sample_first[v]; s < vp->sample_first[v + 1]; ++s) b->eff[s] = vp->sample_areas[s] * b->vscale[v];
        }
        for (i = 0; i < b->kc; ++i) b->cols[i] = (uint32_t)(((uint64_t)2 * i + 1) * M / (2 * (uint64_t)b->kc));
        r = rad__for_rows(&cc, vp->voxel_count, T, rad__vp_cluster_row, b);
        if (r != RAD_SUCCESS) goto done;
        for (v = 0; v < vp->voxel_count; ++v) {
            vp->voxel_first[v] = N;
            for (a = 0; a < 6; ++a) vp->voxel_patch[6 * (size_t)v + a] = a < b->ncl[v] ? N++ : RAD_NONE;
            for (s = vp->sample_first[v]; s < vp->sample_first[v + 1]; ++s) {
                for (a = 0; a < 6; ++a) vp->sample_weights[6 * (size_t)s + a] = 0.0f;
                vp->sample_weights[6 * (size_t)s + b->slot[s]] = b->vscale[v];
            }
        }
        rad__free(A, b->eff);
        b->eff = NULL;
    } else for (v = 0; v < vp->voxel_count; ++v) {
        vp->voxel_first[v] = N;
        for (a = 0; a < 6; ++a) {
            uint32_t s;
            double have = 0.0, exact = cand_area[6 * (size_t)voxel_cand[v] + a];
            for (s = vp->sample_first[v]; s < vp->sample_first[v + 1]; ++s)
                have += (double)vp->sample_weights[6 * (size_t)s + a] * (double)vp->sample_areas[s];
            if (have > 0.0 && exact > 0.0) {
                float scale = (float)(exact / have);
                for (s = vp->sample_first[v]; s < vp->sample_first[v + 1]; ++s) vp->sample_weights[6 * (size_t)s + a] *= scale;
            }
            vp->voxel_patch[6 * (size_t)v + a] = have > 0.0 ? N++ : RAD_NONE;
        }
    }
    rad__free(A, cand_area);
    cand_area = NULL;
    rad__free(A, voxel_cand);
    voxel_cand = NULL;
    b->eff = (float *)rad__alloc_array(A, M, sizeof(float));
    if (!b->eff) { r = RAD_ERROR_OUT_OF_MEMORY; goto done; }
    for (i = 0; i < M; ++i) {
        const float *w = vp->sample_weights + 6 * (size_t)i;
        b->eff[i] = vp->sample_areas[i] * (w[0] + w[1] + w[2] + w[3] + w[4] + w[5]);
    }
    vp->voxel_first[vp->voxel_count] = N;
    vp->count = N;
    if (!rad__mul3(N, N, sizeof(float), &bytes)) {
        rad__log(c, RAD_LOG_ERROR, "virtual patches: the %u x %u matrix does not fit in memory (use bigger voxels)", N, N);
        r = RAD_ERROR_SIZE_OVERFLOW;
        goto done;
    }
    vp->areas = (float *)rad__alloc_array(A, N, sizeof(float));
    vp->albedo = (float *)rad__alloc_array(A, N, 3 * sizeof(float));
    vp->normals = (float *)rad__alloc_array(A, N, 3 * sizeof(float));
    vp->axis = (uint8_t *)rad__alloc_array(A, N, 1);
    vp->voxel = (uint32_t *)rad__alloc_array(A, N, sizeof(uint32_t));
    if (!vp->areas || !vp->albedo || !vp->normals || !vp->axis || !vp->voxel) { r = RAD_ERROR_OUT_OF_MEMORY; goto done; }
    for (v = 0; v < vp->voxel_count; ++v)
        for (a = 0; a < 6; ++a) {
            uint32_t p = vp->voxel_patch[6 * (size_t)v + a], s;
            double area = 0.0, col[3] = { 0.0, 0.0, 0.0 };
            if (p == RAD_NONE) continue;
            for (s = vp->sample_first[v]; s < vp->sample_first[v + 1]; ++s) {
                double w = (double)vp->sample_weights[6 * (size_t)s + a] * (double)vp->sample_areas[s];
                area += w;
                for (k = 0; k < 3; ++k) col[k] += w * (double)vp->sample_albedo[3 * (size_t)s + k];
            }
            vp->areas[p] = (float)area;
            for (k = 0; k < 3; ++k) {
                vp->albedo[3 * (size_t)p + k] = (float)(col[k] / area);
                vp->normals[3 * (size_t)p + k] = 0.0f;
            }
            if (b->o.kind == RAD_VP_CLUSTERED) {
                double nn[3] = { 0.0, 0.0, 0.0 }, len;
                for (s = vp->sample_first[v]; s < vp->sample_first[v + 1]; ++s) {
                    double w = (double)vp->sample_weights[6 * (size_t)s + a] * (double)vp->sample_areas[s];
                    for (k = 0; k < 3; ++k) nn[k] += w * (double)vp->sample_normals[3 * (size_t)s + k];
                }
                len = sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
                for (k = 0; k < 3; ++k) vp->normals[3 * (size_t)p + k] = len > 0.0 ? (float)(nn[k] / len) : 0.0f;
            } else {
                vp->normals[3 * (size_t)p + (a >> 1)] = (a & 1u) ? -1.0f : 1.0f;
            }
            vp->axis[p] = (uint8_t)a;
            vp->voxel[p] = v;
        }

    /* 5. form factors, one row voxel per task */
    rad__free(A, s_bary);
    s_bary = NULL;
    rad__free(A, tri_count);
    tri_count = NULL;
    rad__free(A, cand);
    cand = NULL;
    b->cand = NULL;
    rad__free(A, cand_first);
    cand_first = NULL;
    b->P = (float *)rad__alloc(A, bytes);
    if (!b->P) { r = RAD_ERROR_OUT_OF_MEMORY; goto done; }
    vp->matrix.rows = vp->matrix.cols = N;
    vp->matrix.storage = RAD_STORAGE_DENSE;
    vp->matrix.dense = b->P; /* owned by vp from here on */
    {
        uint32_t T = b->tasks < vp->voxel_count ? b->tasks : vp->voxel_count;
        rad__ctx cc = *c;
        rad__vp_progress prog;
        prog.fn = c->progress;
        prog.user = c->progress_user;
        if (c->progress) {
            cc.progress = rad__vp_progress_fn;
            cc.progress_user = &prog;
        }
        b->occ = (uint8_t *)rad__alloc_array(A, (size_t)T * RAD__RAY_BATCH, 1);
        b->ray_i = (uint32_t *)rad__alloc_array(A, (size_t)T * RAD__RAY_BATCH, sizeof(uint32_t));
        b->ray_j = (uint32_t *)rad__alloc_array(A, (size_t)T * RAD__RAY_BATCH, sizeof(uint32_t));
        b->ray_g = (float *)rad__alloc_array(A, (size_t)T * RAD__RAY_BATCH, sizeof(float));
        b->rays_cast = (uint64_t *)rad__alloc_array(A, T, sizeof(uint64_t));
        b->acc = (double *)rad__alloc_array(A, (size_t)T * 6u, (size_t)N * sizeof(double));
        b->rowf = (float *)rad__alloc_array(A, N, sizeof(float));
        if (b->o.visibility_rays > 0 && !b->o.skip_visibility)
            b->pairs = (rad__vp_pair *)rad__alloc_array(A, (size_t)T * RAD__VP_PAIRS, sizeof(rad__vp_pair));
        if (!b->occ || !b->ray_i || !b->ray_j || !b->ray_g || !b->rays_cast || !b->acc || !b->rowf ||
            (b->o.visibility_rays > 0 && !b->o.skip_visibility && !b->pairs)) {
            r = RAD_ERROR_OUT_OF_MEMORY;
            goto done;
        }
        memset(b->rays_cast, 0, sizeof(uint64_t) * T);
        /* progress of this stage maps to [0.1, 1] */
        if (c->progress && c->progress(c->progress_user, 0.1f)) { r = RAD_ERROR_CANCELLED; goto done; }
        r = rad__for_rows(&cc, vp->voxel_count, T, b->o.visibility_rays > 0 ? rad__vp_ff_row_sampled : rad__vp_ff_row, b);
        for (i = 0; i < T; ++i) vp->pair_rays += b->rays_cast[i];
        if (r == RAD_SUCCESS) {
            cc.progress = NULL;
            r = rad__for_rows(&cc, N, T, rad__vp_mirror_row, b);
            if (r == RAD_SUCCESS && !b->o.keep_row_sums) r = rad__for_rows(&cc, N, T, rad__vp_rowsum_row, b);
            else if (r == RAD_SUCCESS)
                for (i = 0; i < N; ++i) b->rowf[i] = 1.0f;
            if (r == RAD_SUCCESS) r = rad__for_rows(&cc, N, T, rad__vp_divide_row, b);
        }
        if (r == RAD_SUCCESS) r = rad__check_output(c, "virtual-patch form factors", vp->matrix.dense, (size_t)N * N);
    }
done:
    rad__free(A, cand);
    rad__free(A, cand_area);
    rad__free(A, voxel_cand);
    rad__free(A, cand_first);
    rad__free(A, tri_count);
    rad__free(A, s_pos);
    rad__free(A, s_tri);
    rad__free(A, s_vox);
    rad__free(A, s_bary);
    rad__free(A, b->hits);
    rad__free(A, b->rays);
    rad__free(A, b->occ);
    rad__free(A, b->ray_i);
    rad__free(A, b->ray_j);
    rad__free(A, b->ray_g);
    rad__free(A, b->rays_cast);
    rad__free(A, b->acc);
    rad__free(A, b->pairs);
    rad__free(A, b->eff);
    rad__free(A, b->rowf);
    rad__free(A, b->vscale);
    rad__free(A, b->cols);
    rad__free(A, b->cscratch);
    rad__free(A, b->slot);
    rad__free(A, b->ncl);
    rad__free(A, b->sample_voxel);
    return r;
}

RAD_API rad_result rad_vp_create(const rad_scene *scene, const rad_raycaster *raycaster, const rad_vp_options *options,
                                 const rad_context *ctx, rad_virtual_patches **out)
{
    rad__ctx c;
    rad__vp_build b;
    rad_virtual_patches *vp;
    rad_result r;
    double cells = 1.0;
    int k, given = 0;
    rad__ctx_init(&c, ctx);
    if (out) *out = NULL;
    if (!scene || !raycaster || !out || !raycaster->intersect) {
        rad__log(&c, RAD_LOG_ERROR, "rad_vp_create: NULL scene, raycaster, intersect callback or output");
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    memset(&b, 0, sizeof(b));
    if (options) b.o = *options; else rad_vp_options_default(&b.o);
    if (b.o.resolution == 0) b.o.resolution = 16;
    if (b.o.face_points == 0) b.o.face_points = 16;
    if (b.o.ray_epsilon == 0.0f) b.o.ray_epsilon = 1e-5f;
    if (b.o.max_clusters == 0) b.o.max_clusters = 6;
    if (b.o.metric_columns == 0) b.o.metric_columns = 64;
    if ((b.o.kind != RAD_VP_AXIS_ALIGNED && b.o.kind != RAD_VP_CLUSTERED) || b.o.max_clusters > 6 || b.o.metric_columns > 4096) {
        rad__log(&c, RAD_LOG_ERROR, "rad_vp_create: bad kind, max_clusters (1..6) or metric_columns (<= 4096)");
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    for (k = 0; k < 3; ++k) {
        if (!rad__finite(b.o.voxel_size[k]) || b.o.voxel_size[k] < 0.0f) {
            rad__log(&c, RAD_LOG_ERROR, "rad_vp_create: voxel_size[%d] = %g is negative or not finite", k, (double)b.o.voxel_size[k]);
            return RAD_ERROR_INVALID_ARGUMENT;
        }
        if (b.o.voxel_size[k] > 0.0f) given++;
    }
    if ((given != 0 && given != 3) || b.o.face_points > 4096u || b.o.visibility_rays > RAD__RAY_BATCH || (b.o.weights != RAD_VP_WEIGHTS_SQUARED && b.o.weights != RAD_VP_WEIGHTS_COSINE) ||
        !(b.o.ray_epsilon > 0.0f && b.o.ray_epsilon <= RAD__MAX_RAY_EPSILON) || (!b.o.skip_visibility && !raycaster->occluded)) {
        rad__log(&c, RAD_LOG_ERROR, "rad_vp_create: voxel_size must be all 0 or all > 0; face_points <= 4096; visibility_rays "
                 "<= 1024; weights valid; ray_epsilon in (0, 1e-2] (got %g); an occluded callback unless skip_visibility",
                 (double)b.o.ray_epsilon);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    vp = (rad_virtual_patches *)rad__alloc(&c.allocator, sizeof(*vp));
    if (!vp) return RAD_ERROR_OUT_OF_MEMORY;
    memset(vp, 0, sizeof(*vp));
    vp->allocator = c.allocator;
    vp->scene = scene;
    vp->weights = b.o.weights;
    vp->kind = b.o.kind;
    for (k = 0; k < 3; ++k) {
        float ext = scene->bounds_max[k] - scene->bounds_min[k], h;
        float longest = scene->bounds_max[0] - scene->bounds_min[0];
        if (scene->bounds_max[1] - scene->bounds_min[1] > longest) longest = scene->bounds_max[1] - scene->bounds_min[1];
        if (scene->bounds_max[2] - scene->bounds_min[2] > longest) longest = scene->bounds_max[2] - scene->bounds_min[2];
        h = given ? b.o.voxel_size[k] : longest / (float)b.o.resolution;
        if (!(h > 0.0f)) h = 1.0f;
        vp->voxel_size[k] = h;
        vp->origin[k] = scene->bounds_min[k] - RAD__VP_MARGIN * h;
        cells = floor((double)(ext + 2.0f * RAD__VP_MARGIN * h) / (double)h) + 1.0;
        if (cells > 4194304.0) {
            rad__log(&c, RAD_LOG_ERROR, "rad_vp_create: %g voxels along axis %d (use bigger voxels)", cells, k);
            rad_vp_destroy(vp);
            return RAD_ERROR_SIZE_OVERFLOW;
        }
        vp->dims[k] = (uint32_t)cells;
    }
    b.S = scene;
    b.rc = raycaster;
    b.vp = vp;
    b.eps = b.o.ray_epsilon * scene->diagonal;
    b.tasks = c.tasks;
    r = rad__vp_build_run(&b, &c);
    if (r != RAD_SUCCESS) {
        rad_vp_destroy(vp);
        return r;
    }
    *out = vp;
    return RAD_SUCCESS;
}

RAD_API void rad_vp_system(rad_system *system, const rad_virtual_patches *vp, const float *E)
{
    if (!system) return;
    memset(system, 0, sizeof(*system));
    if (!vp) return;
    system->F = &vp->matrix;
    system->albedo = vp->albedo;
    system->areas = vp->areas;
    system->E = E;
    system->n = vp->count;
}

RAD_API rad_result rad_vp_from_samples(const rad_virtual_patches *vp, const float *sample_values, float *out)
{
    uint32_t v, a, s;
    int k;
    if (!vp || !sample_values || !out) return RAD_ERROR_INVALID_ARGUMENT;
    for (v = 0; v < vp->voxel_count; ++v)
        for (a = 0; a < 6; ++a) {
            uint32_t p = vp->voxel_patch[6 * (size_t)v + a];
            double acc[3] = { 0.0, 0.0, 0.0 }, wsum = 0.0;
            if (p == RAD_NONE) continue;
            for (s = vp->sample_first[v]; s < vp->sample_first[v + 1]; ++s) {
                double w = (double)vp->sample_weights[6 * (size_t)s + a] * (double)vp->sample_areas[s];
                if (vp->kind == RAD_VP_CLUSTERED) {
                    double cosw = (double)rad__dot(vp->normals + 3 * (size_t)p, vp->sample_normals + 3 * (size_t)s);
                    w = cosw > 0.0 ? cosw * (double)vp->sample_areas[s] : 0.0;
                }
                wsum += w;
                for (k = 0; k < 3; ++k) acc[k] += w * (double)sample_values[3 * (size_t)s + k];
            }
            for (k = 0; k < 3; ++k) out[3 * (size_t)p + k] = wsum > 0.0 ? (float)(acc[k] / wsum) : 0.0f;
        }
    return RAD_SUCCESS;
}

RAD_API rad_result rad_vp_sources(const rad_virtual_patches *vp, const rad_raycaster *raycaster, const rad_light *lights,
                                  uint32_t light_count, const rad_direct_options *options, rad_source_mode mode,
                                  float *out_E, const rad_context *ctx)
{
    rad__ctx c;
    float *v;
    uint32_t i, M;
    rad_result r = RAD_SUCCESS;
    int k;
    rad__ctx_init(&c, ctx);
    if (!vp || !out_E || (mode != RAD_SOURCE_DIRECT && mode != RAD_SOURCE_EMISSION)) return RAD_ERROR_INVALID_ARGUMENT;
    M = vp->sample_count;
    v = (float *)rad__alloc_array(&c.allocator, M, 3 * sizeof(float));
    if (!v) return RAD_ERROR_OUT_OF_MEMORY;
    if (mode == RAD_SOURCE_DIRECT) {
        r = rad_direct_irradiance(vp->scene, raycaster, lights, light_count, options, vp->sample_positions,
                                  vp->sample_normals, M, v, ctx);
        if (r == RAD_SUCCESS)
            for (i = 0; i < 3 * M; ++i) v[i] *= vp->sample_albedo[i];
    } else {
        const rad_scene *S = vp->scene;
        for (i = 0; i < M; ++i) {
            const float *L = S->materials_table[S->materials[vp->sample_triangles[i]]].emission;
            for (k = 0; k < 3; ++k) v[3 * (size_t)i + k] = (float)RAD__PI * L[k];
        }
    }
    if (r == RAD_SUCCESS) r = rad_vp_from_samples(vp, v, out_E);
    rad__free(&c.allocator, v);
    if (r == RAD_SUCCESS) r = rad__check_output(&c, "virtual-patch sources", out_E, 3 * (size_t)vp->count);
    return r;
}

/* index of the voxel with this key, or RAD_NONE */
static uint32_t rad__vp_find(const rad_virtual_patches *vp, uint64_t key)
{
    uint32_t lo = 0, hi = vp->voxel_count;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (vp->voxel_keys[mid] < key) lo = mid + 1;
        else hi = mid;
    }
    return lo < vp->voxel_count && vp->voxel_keys[lo] == key ? lo : RAD_NONE;
}

RAD_API uint32_t rad_vp_gather_point(const rad_virtual_patches *vp, const float *values, const float p[3],
                                     const float n[3], float out[3])
{
    double g[3], acc[3] = { 0.0, 0.0, 0.0 }, tsum = 0.0, facc[3] = { 0.0, 0.0, 0.0 };
    int64_t base[3];
    float w[6];
    uint32_t corner, used = 0;
    int k;
    if (!out) return 0;
    out[0] = out[1] = out[2] = 0.0f;
    if (!vp || !values || !p || !n || !rad__finite3(p) || !rad__finite3(n)) return 0;
    rad__vp_weights(vp->weights, n, w);
    for (k = 0; k < 3; ++k) {
        double x = ((double)p[k] - (double)vp->origin[k]) / (double)vp->voxel_size[k] - 0.5;
        if (x < -2.0) x = -2.0;
        if (x > (double)vp->dims[k] + 1.0) x = (double)vp->dims[k] + 1.0;
        base[k] = (int64_t)floor(x);
        g[k] = x - (double)base[k];
    }
    for (corner = 0; corner < 8; ++corner) {
        int64_t cell[3];
        double t = 1.0, L[3] = { 0.0, 0.0, 0.0 }, ws = 0.0;
        uint32_t v, a;
        int inside = 1;
        for (k = 0; k < 3; ++k) {
            int bit = (int)((corner >> k) & 1u);
            cell[k] = base[k] + bit;
            t *= bit ? g[k] : 1.0 - g[k];
            if (cell[k] < 0 || cell[k] >= (int64_t)vp->dims[k]) inside = 0;
        }
        if (!inside) continue;
        v = rad__vp_find(vp, (uint64_t)cell[0] + (uint64_t)vp->dims[0] * ((uint64_t)cell[1] + (uint64_t)vp->dims[1] * (uint64_t)cell[2]));
        if (v == RAD_NONE) continue;
        for (a = 0; a < 6; ++a) {
            uint32_t q = vp->voxel_patch[6 * (size_t)v + a];
            float wa;
            if (q == RAD_NONE) continue;
            wa = vp->kind == RAD_VP_CLUSTERED ? rad__dot(vp->normals + 3 * (size_t)q, n) : w[a];
            if (!(wa > 0.0f)) continue;
            ws += (double)wa;
            for (k = 0; k < 3; ++k) L[k] += (double)wa * (double)values[3 * (size_t)q + k];
        }
        if (!(ws > 0.0)) continue; /* nothing in this voxel faces n */
        used++;
        for (k = 0; k < 3; ++k) {
            acc[k] += t * L[k] / ws;
            facc[k] += L[k] / ws;
        }
        tsum += t;
    }
    if (!used) return 0;
    for (k = 0; k < 3; ++k) out[k] = tsum > 0.0 ? (float)(acc[k] / tsum) : (float)(facc[k] / (double)used);
    return used;
}

typedef struct rad__vp_gather_job {
    const rad_virtual_patches *vp;
    const float *values, *points, *normals;
    float *out;
    uint32_t count, tasks;
} rad__vp_gather_job;

static void rad__vp_gather_task(void *data, uint32_t task)
{
    rad__vp_gather_job *j = (rad__vp_gather_job *)data;
    uint32_t i0 = (uint32_t)((uint64_t)j->count * task / j->tasks), i1 = (uint32_t)((uint64_t)j->count * (task + 1) / j->tasks), i;
    for (i = i0; i < i1; ++i)
        (void)rad_vp_gather_point(j->vp, j->values, j->points + 3 * (size_t)i, j->normals + 3 * (size_t)i, j->out + 3 * (size_t)i);
}

RAD_API rad_result rad_vp_gather(const rad_virtual_patches *vp, const float *values, const float *points,
                                 const float *normals, uint32_t count, float *out, const rad_context *ctx)
{
    rad__ctx c;
    rad__vp_gather_job j;
    uint32_t i;
    rad__ctx_init(&c, ctx);
    if (!vp || !values || (count && (!points || !normals || !out))) return RAD_ERROR_INVALID_ARGUMENT;
    for (i = 0; i < count; ++i)
        if (!rad__finite3(points + 3 * (size_t)i) || !rad__finite3(normals + 3 * (size_t)i)) {
            rad__log(&c, RAD_LOG_ERROR, "rad_vp_gather: point %u or its normal is not finite", i);
            return RAD_ERROR_NON_FINITE;
        }
    if (count == 0) return RAD_SUCCESS;
    j.vp = vp;
    j.values = values;
    j.points = points;
    j.normals = normals;
    j.out = out;
    j.count = count;
    j.tasks = c.tasks < count ? c.tasks : count;
    c.parallel_for(c.parallel_user, j.tasks, rad__vp_gather_task, &j);
    return RAD_SUCCESS;
}

RAD_API rad_result rad_vp_gather_mesh(const rad_virtual_patches *vp, const float *values, const rad_mesh_desc *mesh,
                                      float *out, const rad_context *ctx)
{
    rad__ctx c;
    float *pts, *nrm;
    size_t ps, ns;
    uint32_t V, T, t, i;
    rad_result r;
    int k;
    rad__ctx_init(&c, ctx);
    if (!vp || !values || !mesh || !out || !mesh->positions) return RAD_ERROR_INVALID_ARGUMENT;
    V = mesh->vertex_count;
    T = mesh->triangle_count;
    if (!mesh->indices && (size_t)T * 3u > V) return RAD_ERROR_INDEX_OUT_OF_RANGE;
    ps = mesh->position_stride ? mesh->position_stride : 3 * sizeof(float);
    ns = mesh->normal_stride ? mesh->normal_stride : 3 * sizeof(float);
    pts = (float *)rad__alloc_array(&c.allocator, V, 3 * sizeof(float));
    nrm = (float *)rad__alloc_array(&c.allocator, V, 3 * sizeof(float));
    if (!pts || !nrm) {
        rad__free(&c.allocator, pts);
        rad__free(&c.allocator, nrm);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    for (i = 0; i < V; ++i) memcpy(pts + 3 * (size_t)i, (const char *)mesh->positions + ps * i, 3 * sizeof(float));
    memset(nrm, 0, sizeof(float) * 3u * V);
    if (mesh->normals) {
        for (i = 0; i < V; ++i) memcpy(nrm + 3 * (size_t)i, (const char *)mesh->normals + ns * i, 3 * sizeof(float));
    } else {
        for (t = 0; t < T; ++t) {
            uint32_t id[3], m;
            float e1[3], e2[3], cr[3];
            for (m = 0; m < 3; ++m) {
                id[m] = mesh->indices ? mesh->indices[3 * (size_t)t + m] : 3u * t + m;
                if (id[m] >= V) {
                    rad__log(&c, RAD_LOG_ERROR, "rad_vp_gather_mesh: triangle %u has vertex index %u >= %u", t, id[m], V);
                    rad__free(&c.allocator, pts);
                    rad__free(&c.allocator, nrm);
                    return RAD_ERROR_INDEX_OUT_OF_RANGE;
                }
            }
            rad__sub(e1, pts + 3 * (size_t)id[1], pts + 3 * (size_t)id[0]);
            rad__sub(e2, pts + 3 * (size_t)id[2], pts + 3 * (size_t)id[0]);
            rad__cross(cr, e1, e2); /* twice the area times the unit normal */
            for (m = 0; m < 3; ++m)
                for (k = 0; k < 3; ++k) nrm[3 * (size_t)id[m] + k] += cr[k];
        }
    }
    for (i = 0; i < V; ++i) rad__normalize(nrm + 3 * (size_t)i);
    r = rad_vp_gather(vp, values, pts, nrm, V, out, ctx);
    rad__free(&c.allocator, pts);
    rad__free(&c.allocator, nrm);
    return r;
}

#endif /* RADIOSITY_IMPLEMENTATION */

/*
------------------------------------------------------------------------------
This software is available under 2 licenses -- choose whichever you prefer.
------------------------------------------------------------------------------
ALTERNATIVE A - MIT License
Copyright (c) 2026 the radiosity.h authors
Permission is hereby granted, free of charge, to any person obtaining a copy of
this software and associated documentation files (the "Software"), to deal in
the Software without restriction, including without limitation the rights to
use, copy, modify, merge, publish, distribute, sublicense, and/or sell copies
of the Software, and to permit persons to whom the Software is furnished to do
so, subject to the following conditions:
The above copyright notice and this permission notice shall be included in all
copies or substantial portions of the Software.
THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR
IMPLIED, INCLUDING BUT NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY,
FITNESS FOR A PARTICULAR PURPOSE AND NONINFRINGEMENT. IN NO EVENT SHALL THE
AUTHORS OR COPYRIGHT HOLDERS BE LIABLE FOR ANY CLAIM, DAMAGES OR OTHER
LIABILITY, WHETHER IN AN ACTION OF CONTRACT, TORT OR OTHERWISE, ARISING FROM,
OUT OF OR IN CONNECTION WITH THE SOFTWARE OR THE USE OR OTHER DEALINGS IN THE
SOFTWARE.
------------------------------------------------------------------------------
ALTERNATIVE B - Public Domain (www.unlicense.org)
This is free and unencumbered software released into the public domain.
Anyone is free to copy, modify, publish, use, compile, sell, or distribute this
software, either in source code form or as a compiled binary, for any purpose,
commercial or non-commercial, and by any means.
In jurisdictions that recognize copyright laws, the author or authors of this
software dedicate any and all copyright interest in the software to the public
domain. We make this dedication for the benefit of the public at large and to
the detriment of our heirs and successors. We intend this dedication to be an
overt act of relinquishment in perpetuity of all present and future rights to
this software under copyright law.
THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR
IMPLIED, INCLUDING BUT NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY,
FITNESS FOR A PARTICULAR PURPOSE AND NONINFRINGEMENT. IN NO EVENT SHALL THE
AUTHORS BE LIABLE FOR ANY CLAIM, DAMAGES OR OTHER LIABILITY, WHETHER IN AN
ACTION OF CONTRACT, TORT OR OTHERWISE, ARISING FROM, OUT OF OR IN CONNECTION
WITH THE SOFTWARE OR THE USE OR OTHER DEALINGS IN THE SOFTWARE.
------------------------------------------------------------------------------
*/
