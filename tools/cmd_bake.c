/* cmd_bake.c - `rad bake`: a solution computed (the classic one by classic.c) and saved.

   rad bake SCENE -o FILE.radb [--method classic|multibounce|temporal|stochastic|hierarchical|aavp|vp] [--solver jacobi|gauss-seidel|direct]
            [--bounces K] [--patches N] [--max-edge L] [--samples S] [--light-samples N]
            [method options, see methods.c] [--threads N]

   Direct light as the source: the direct irradiance D of every patch (emissive triangles and the
   file's analytic lights, with shadow rays) gives the source E = rho D; the emitters' own
   emission stays out of the system. The solver gives the indirect light L, B = E + L, and
   H = F B = F (E + L) is the irradiance from the secondary sources that the renderer adds to
   its per-pixel direct light. The bake holds the patches, F, E and B (rad_save_memory), plus
   the vectors "L", "H" and "D" and a user section "rad.options" with the options the patches
   were made with, so `rad render --bake` can check that the file fits the scene (with the
   library's signature section, which also holds the hash of rad.options: tool_sign_options).
   --method multibounce, temporal, stochastic and hierarchical bake through methods.c
   (tool_method_bake); aavp
   and vp save the virtual patches with sparse rows (bake_vp). */
#include "tool.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* The sections as a container written to path (a temporary renamed into place); its size in
   *out_size. 0, or 1 with the message printed. */
static int write_sections(const char *cmd, const char *path, const rad_section *secs, uint32_t k, size_t *out_size)
{
    void *dst;
    rad_result r;
    int rc = 1;
    if ((r = rad_container_size(secs, k, out_size)) != RAD_SUCCESS) return tool_fail(cmd, "rad_container_size", r);
    dst = tool_calloc(*out_size, 1);
    if ((r = rad_container_write(secs, k, dst, *out_size)) != RAD_SUCCESS) tool_fail(cmd, "rad_container_write", r);
    else if (tool_write_file(path, dst, *out_size) != 0) fprintf(stderr, "rad %s: %s\n", cmd, tool_output_error());
    else rc = 0;
    free(dst);
    return rc;
}

/* rad_save_memory's container plus our sections, written to 'path'. rad merge (cmd_merge.c)
   writes the same sections in the same order from a sharded bake's parts: change both. */
static int save_bake(const char *cmd, const char *path, const tool_world *w, const tool_classic_options *o,
                     const tool_classic *c)
{
    rad_context ctx;
    void *buf = NULL;
    size_t size = 0, dst_size = 0;
    rad_container *ct = NULL;
    rad_section *secs;
    tool_bake_info info;
    rad_bake_signature sig;
    uint32_t count, i, k = 0, n = c->patches->count;
    rad_result r;
    int rc = 1;
    tool_context(&ctx, NULL);
    if ((r = rad_save_memory(c->patches, &c->ff->matrix, c->E, c->B, &ctx, &buf, &size)) != RAD_SUCCESS)
        return tool_fail(cmd, "rad_save_memory", r);
    if ((r = rad_container_create(buf, size, &ctx, &ct)) != RAD_SUCCESS) {
        rad_free_buffer(buf, &ctx);
        return tool_fail(cmd, "rad_container_create", r);
    }
    count = rad_container_section_count(ct);
    secs = (rad_section *)tool_calloc((size_t)count + 4, sizeof(rad_section));
    for (i = 0; i < count; ++i) secs[k++] = *rad_container_section(ct, i);
    tool_bake_info_fill(&info, w, o);
    tool_sign_options(secs, k, &info, w, &sig);
    secs[k].type = RAD_SECTION_VECTOR, secs[k].elem_size = 12, secs[k].count = n, secs[k].data = c->L;
    strcpy(secs[k++].name, "L");
    secs[k].type = RAD_SECTION_VECTOR, secs[k].elem_size = 12, secs[k].count = n, secs[k].data = c->H;
    strcpy(secs[k++].name, "H");
    secs[k].type = RAD_SECTION_VECTOR, secs[k].elem_size = 12, secs[k].count = n, secs[k].data = c->D;
    strcpy(secs[k++].name, "D");
    secs[k].type = TOOL_SECTION_OPTIONS, secs[k].elem_size = sizeof info, secs[k].count = 1, secs[k].data = &info;
    strcpy(secs[k++].name, "rad.options");
    if (write_sections(cmd, path, secs, k, &dst_size)) goto done;
    printf("wrote %s: %u patches, %u sections, %lu bytes\n", path, n, k, (unsigned long)dst_size);
    rc = 0;
done:
    free(secs);
    rad_container_destroy(ct);
    rad_free_buffer(buf, &ctx);
    return rc;
}

/* the bytes to 'path' (a temporary renamed into place); 0 or 1 (message printed) */
static int write_bytes(const char *cmd, const char *path, const void *data, size_t size)
{
    if (tool_write_file(path, data, size) != 0) {
        fprintf(stderr, "rad %s: %s\n", cmd, tool_output_error());
        return 1;
    }
    return 0;
}

/* --method aavp|vp: the virtual patches with sparse rows (rad_vp_sections, named "vp"), their
   source E = rho D at the samples (vector "E"), the scene's signature with the hash of the
   options (resolution, face points, light samples in rad.options) and rad.options itself.
   rad render --method aavp|vp (or --proxy) --bake FILE loads it instead of building. */
static int bake_vp(const char *cmd, const char *path, const tool_world *w, const tool_classic_options *o,
                   const tool_method_options *mo)
{
    rad_vp_options vo;
    rad_virtual_patches *vp = NULL;
    rad_direct_options dopt;
    rad_section secs[RAD_VP_MAX_SECTIONS + 3];
    tool_bake_info info;
    rad_bake_signature sig;
    rad_context ctx;
    rad_result r;
    float *E = NULL;
    size_t dst_size = 0;
    uint32_t k = 0;
    int rc = 1;
    rad_vp_options_default(&vo);
    vo.resolution = mo->vp_resolution;
    vo.face_points = mo->face_points;
    vo.kind = mo->method == TOOL_VP ? RAD_VP_CLUSTERED : RAD_VP_AXIS_ALIGNED;
    vo.storage = RAD_STORAGE_SPARSE;
    tool_context(&ctx, "virtual patches");
    r = rad_vp_create(w->scene, &w->rc, &vo, &ctx, &vp);
    tool_progress_end();
    if (r != RAD_SUCCESS) return tool_fail(cmd, "rad_vp_create", r);
    E = (float *)tool_calloc(3 * (size_t)vp->count, sizeof(float));
    rad_direct_options_default(&dopt);
    dopt.exclude_emitters = 0;
    dopt.light_samples = o->light_samples;
    tool_context(&ctx, "direct light");
    r = rad_vp_sources(vp, &w->rc, w->file.lights, w->file.light_count, &dopt, RAD_SOURCE_DIRECT, E, &ctx);
    tool_progress_end();
    tool_context(&ctx, NULL);
    if (r != RAD_SUCCESS) {
        tool_fail(cmd, "rad_vp_sources", r);
        goto done;
    }
    if ((r = rad_vp_sections(vp, "vp", secs, &k)) != RAD_SUCCESS) {
        tool_fail(cmd, "rad_vp_sections", r);
        goto done;
    }
    memset(&info, 0, sizeof info);
    info.magic = 0x52414442u;
    info.patches = vp->count;
    info.samples = mo->face_points;
    info.solver = (uint32_t)mo->method;
    info.bounces = mo->vp_resolution;
    info.light_samples = o->light_samples;
    info.triangle_count = w->scene->triangle_count;
    memset(&sig, 0, sizeof sig);
    if ((r = rad_scene_hash(w->scene, &sig.geometry, &sig.materials)) != RAD_SUCCESS) {
        tool_fail(cmd, "rad_scene_hash", r);
        goto done;
    }
    sig.options = tool_options_hash(&info, w);
    memset(&secs[k], 0, 3 * sizeof secs[0]);
    secs[k].type = RAD_SECTION_VECTOR, secs[k].elem_size = 12, secs[k].count = vp->count, secs[k].data = E;
    strcpy(secs[k++].name, "E");
    secs[k].type = RAD_SECTION_SIGNATURE, secs[k].elem_size = sizeof sig, secs[k].count = 1, secs[k].data = &sig;
    strcpy(secs[k++].name, "signature");
    secs[k].type = TOOL_SECTION_OPTIONS, secs[k].elem_size = sizeof info, secs[k].count = 1, secs[k].data = &info;
    strcpy(secs[k++].name, "rad.options");
    if (write_sections(cmd, path, secs, k, &dst_size)) goto done;
    printf("wrote %s: %s, %u virtual patches at resolution %u, %llu non-zeros, %lu bytes\n", path,
           tool_method_name(mo->method), vp->count, mo->vp_resolution,
           (unsigned long long)vp->matrix.row_offsets[vp->count], (unsigned long)dst_size);
    rc = 0;
done:
    free(E);
    rad_vp_destroy(vp);
    return rc;
}

static int parse_shard(const char *cmd, const tool_arg *t, const char *v, void *field)
{
    (void)t;
    return tool_parse_shard(cmd, v, (tool_shard_spec *)field) ? 2 : 0;
}

static int parse_rows(const char *cmd, const tool_arg *t, const char *v, void *field)
{
    (void)t;
    return tool_parse_rows(cmd, v, (tool_shard_spec *)field) ? 2 : 0;
}

static int parse_threads(const char *cmd, const tool_arg *t, const char *v, void *field)
{
    return tool_parse_threads(cmd, t->name, v, (uint32_t *)field) ? 2 : 0;
}

#define BA(f) offsetof(tool_bake_args, f)
/* rad bake's own options (the classic, method and light options are their files' tables) */
static const tool_arg bake_table[] = {
    {TOOL_ARG_STRING, "-o", "FILE", BA(out), 0, 0, 0, 0, NULL, NULL, NULL, NULL, 0, "output file (required)"},
    {TOOL_ARG_TEXT, NULL, NULL, 0, 0, 0, 0, 0, NULL, NULL, NULL, NULL, 0,
     "  --method M         classic (default), multibounce, temporal, stochastic, hierarchical,\n"
     "                     aavp or vp\n"},
    {TOOL_ARG_CUSTOM, "--shard", "I/N", BA(shard), 0, 0, 0, 0, NULL, NULL, NULL, parse_shard, 0,
     "classic: bake part I of N (0 <= I < N) into FILE; rad merge joins the N parts into the\n"
     "bake itself (docs/distributed.md)"},
    {TOOL_ARG_CUSTOM, "--rows", "A:B", BA(shard), 0, 0, 0, 0, NULL, NULL, NULL, parse_rows, 0,
     "classic: bake the part holding rows A to B-1 (instead of --shard)"},
    {TOOL_ARG_CUSTOM, "--threads", "N", BA(threads), 0, 0, 0, 0, NULL, NULL, NULL, parse_threads, 0,
     "worker threads (default: all cores; at most 1024)"},
    {TOOL_ARG_END, NULL, NULL, 0, 0, 0, 0, 0, NULL, NULL, NULL, NULL, 0, NULL}
};

static void bake_usage(FILE *f)
{
    static char own[4096];
    tool_args_help_into(bake_table, 0, own, sizeof own);
    fprintf(f, "usage: rad bake SCENE -o FILE.radb [--method classic|multibounce|temporal|stochastic|hierarchical|aavp|vp] [options]\n"
               "Computes patches, form factors and the patches' direct light E = rho D, then by method:\n"
               "  classic      the indirect solution L; saves patches, F, E, B = E + L (and L, H = F B, D)\n"
               "  multibounce  F_mb = sum_k (rho o F)^k, stored as float, half or compressed\n"
               "               (BC1, 3xBC4); saves patches, E, D, F's row sums and F_mb (no F)\n"
               "  temporal     alias tables over the rows of F (or of F_mb's channels); saves\n"
               "               patches, E, D, F's row sums and the tables (no F)\n"
               "  stochastic   no F: L by stochastic Jacobi or random walks over rays; saves patches, E, D,\n"
               "               row sums estimated by rays and L\n"
               "  hierarchical the hierarchical solution (--hr-*), its H resampled onto the patches as\n"
               "               L = rho H; saved as the stochastic bake (patches, E, D, row sums by rays, L)\n"
               "  aavp, vp     virtual patches (--vp-resolution, --face-points) with sparse rows and\n"
               "               their E; rad render --method aavp|vp or --proxy aavp|vp --bake loads them\n"
               "%s%s%s%s",
            own, tool_classic_help(), tool_method_help(0), tool_light_help());
}

int tool_bake_parse(const char *cmd, int argc, char **argv, tool_bake_args *args)
{
    int a, rc;
    memset(args, 0, sizeof *args);
    tool_classic_options_default(&args->o);
    tool_method_options_default(&args->mo);
    for (a = 0; a < argc; ++a) {
        const char *opt = argv[a];
        if (!strcmp(opt, "--help") || !strcmp(opt, "-h")) { bake_usage(stdout); return 0; }
        rc = tool_method_option(cmd, argc, argv, &a, &args->mo);
        if (rc == 2) return 2;
        if (rc == 1) continue;
        rc = tool_classic_option(cmd, argc, argv, &a, &args->o);
        if (rc == 2) return 2;
        if (rc == 1) continue;
        rc = tool_light_option(cmd, argc, argv, &a, &args->lights);
        if (rc == 2) return 2;
        if (rc == 1) continue;
        rc = tool_args_parse(cmd, bake_table, args, NULL, argc, argv, &a);
        if (rc == 2) return 2;
        if (rc == 1) continue;
        if (opt[0] == '-' && opt[1]) {
            fprintf(stderr, "rad %s: unknown option '%s' (see rad bake --help)\n", cmd, opt);
            return 2;
        } else if (!args->scene) args->scene = opt;
        else { fprintf(stderr, "rad %s: more than one scene given\n", cmd); return 2; }
    }
    if (!args->scene || !args->out) {
        fprintf(stderr, "rad %s: %s\n", cmd, !args->scene ? "no scene given" : "no output file given (-o FILE.radb)");
        bake_usage(stderr);
        return 2;
    }
    if (args->shard.rows && args->shard.count) {
        fprintf(stderr, "rad %s: --shard and --rows both choose the part: give one\n", cmd);
        return 2;
    }
    if ((args->shard.rows || args->shard.count) && args->mo.method != TOOL_CLASSIC) {
        fprintf(stderr, "rad %s: --shard and --rows split the classic bake's form factors; --method %s builds on the "
                        "whole matrix (merge a classic bake, or bake it on one machine)\n",
                cmd, tool_method_name(args->mo.method));
        return 2;
    }
    if (tool_method_check(cmd, 0, &args->mo, &args->o)) return 2;
    tool_dense_plan(&args->o, &args->mo, 1);
    return -1;
}

static int bake_main(const char *cmd, tool_bake_args *args)
{
    tool_world w;
    tool_classic c;
    double t0 = tool_seconds();
    int rc;
    if (tool_check_output(cmd, args->out, &args->scene, 1)) return 1;
    tool_set_threads((int)args->threads);
    if (tool_open_world_lit(cmd, args->scene, &args->lights, &w)) return 1;
    if (args->mo.method == TOOL_VP || args->mo.method == TOOL_AAVP) {
        rc = bake_vp(cmd, args->out, &w, &args->o, &args->mo);
        tool_close_world(&w);
        if (rc == 0) fprintf(stderr, "rad %s: done in %.2f s\n", cmd, tool_seconds() - t0);
        return rc;
    }
    if (args->mo.method != TOOL_CLASSIC || args->shard.rows || args->shard.count) {
        void *buf = NULL;
        size_t size = 0;
        if (args->mo.method != TOOL_CLASSIC) rc = tool_method_bake(cmd, &w, &args->o, &args->mo, &buf, &size);
        else rc = tool_bake_part(cmd, &w, &args->o, &args->shard, &buf, &size);
        if (rc == 0) rc = write_bytes(cmd, args->out, buf, size);
        if (rc == 0)
            printf("wrote %s: %s, %lu bytes\n", args->out,
                   args->mo.method != TOOL_CLASSIC ? tool_method_name(args->mo.method) : "a part of a classic bake",
                   (unsigned long)size);
        free(buf);
        tool_close_world(&w);
        if (rc == 0) fprintf(stderr, "rad %s: done in %.2f s\n", cmd, tool_seconds() - t0);
        return rc;
    }
    if (tool_classic_solve(cmd, &w, &args->o, &c)) {
        tool_close_world(&w);
        return 1;
    }
    rc = save_bake(cmd, args->out, &w, &args->o, &c);
    tool_classic_free(&c);
    tool_close_world(&w);
    if (rc == 0) fprintf(stderr, "rad %s: done in %.2f s\n", cmd, tool_seconds() - t0);
    return rc;
}

int tool_cmd_bake(int argc, char **argv)
{
    tool_bake_args args;
    int rc = tool_bake_parse("bake", argc, argv, &args);
    if (rc < 0) rc = bake_main("bake", &args);
    tool_lights_free(&args.lights);
    return rc;
}
