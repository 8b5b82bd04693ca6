/* cmd_info.c - `rad info FILE.radb`: what a baked-data container holds, after checking it
   (rad_container_create validates every size, offset and checksum; rad_load_memory every
   index). A damaged file gives the loader's error and detail and exit code 1.
   A saved engine-tier bake (rad lightmap --layers, rad_baker_result_save_memory) is loaded
   as an engine loads it (rad_baker_result_load_memory) and described: its groups, sizes and
   the plan's reason.
   `rad info SCENE`: the imported scene, and per material what the importer used, read and
   ignored, so that nothing of a material is dropped without a word. */
#include "tool.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The library's name of a section type (rad_section_type_name), the tool's own user sections
   by what they hold. */
static const char *type_name(uint32_t type)
{
    const char *name;
    switch (type) {
    case TOOL_SECTION_OPTIONS: return "USER(rad options)";
    case TOOL_SECTION_METHOD: return "USER(rad method)";
    case TOOL_SECTION_ROWSUMS: return "USER(row sums)";
    default: name = rad_section_type_name(type); return name ? name : "UNKNOWN";
    }
}

/* The method's data opened and checked exactly as rad render opens it (tool_indirect_open:
   the row sums, L, the k of the record, the temporal state ...); 0, or 1 (printed). */
/* A saved rad_baker_result, loaded and described; 0, or 1 when it does not load (printed). */
static int baker_info(const char *path, const void *data, size_t len, const rad_context *ctx)
{
    rad_baker_result *R = NULL;
    rad_result r = rad_baker_result_load_memory(data, len, ctx, &R);
    if (r != RAD_SUCCESS) {
        fprintf(stderr, "rad info: '%s' holds an engine-tier bake that does not load: %s\n", path, rad_result_string(r));
        return 1;
    }
    printf("engine-tier bake: %s, %u patches%s, %u light groups, %u sky layers\n",
           R->method == RAD_BAKER_CLASSIC ? "classic" : "virtual patches", R->patch_count,
           R->method == RAD_BAKER_CLASSIC ? "" : " (virtual)", R->group_count, R->sky_count);
    if (R->vertex_layers) printf("  vertices: %u in %u meshes\n", R->vertex_count, R->mesh_count);
    if (R->lightmap)
        printf("  lightmap: %u x %u, %s%s%s\n", R->lightmap_width, R->lightmap_height,
               R->lightmap_channels == 12 ? "L1 SH (12 floats a texel)" : "RGB", R->lightmap_layers ? ", float layers" : "",
               R->lightmap_rgb9e5 ? ", RGB9E5 layers" : "");
    if (R->probes)
        printf("  probes: %u (grid %u x %u x %u)%s\n", R->probe_count, R->probe_grid[0], R->probe_grid[1], R->probe_grid[2],
               R->probe_band4 ? ", band 4" : "");
    printf("  plan: %s\n", R->reason);
    if (R->scene_hash[0] || R->scene_hash[1])
        printf("  scene: geometry %016llx, materials %016llx\n", (unsigned long long)R->scene_hash[0],
               (unsigned long long)R->scene_hash[1]);
    printf("checksums: all OK; every section agrees with the metadata\n");
    rad_baker_result_destroy(R);
    return 0;
}

static int method_open(const char *path, const rad_bake *bake, uint32_t method)
{
    tool_method_options mo;
    tool_indirect *m = NULL;
    tool_method_options_default(&mo);
    mo.method = (tool_method)method;
    if (tool_indirect_open("info", path, bake, &mo, &m)) return 1;
    tool_indirect_close(m);
    return 0;
}

/* The rad.method record and the method's objects (opened and validated like render does);
   0, or 1 when they do not open (message printed). */
static int method_info(const char *path, const rad_bake *bake, const rad_context *ctx)
{
    const rad_container *ct = bake->container;
    const rad_section *s = rad_container_find(ct, TOOL_SECTION_METHOD, "rad.method");
    tool_method_info mi;
    rad_result r = RAD_SUCCESS;
    uint64_t bytes;
    uint32_t i;
    if (!s || s->elem_size != sizeof mi || s->count != 1) return 0;
    memcpy(&mi, s->data, sizeof mi);
    if (mi.magic != TOOL_METHOD_MAGIC ||
        (mi.method != TOOL_MULTIBOUNCE && mi.method != TOOL_TEMPORAL && mi.method != TOOL_STOCHASTIC &&
         mi.method != TOOL_HIERARCHICAL)) {
        fprintf(stderr, "rad info: the rad.method section is damaged\n");
        return 1;
    }
    bytes = (uint64_t)mi.bytes_lo | ((uint64_t)mi.bytes_hi << 32);
    if (mi.method == TOOL_HIERARCHICAL) { /* the record's fields as methods.c fills them for this method */
        const rad_section *ls = rad_container_find(ct, RAD_SECTION_VECTOR, "L");
        printf("method: hierarchical, --hr-eps %g\n"
               "  solution 'L' (rho H resampled onto the patches): %s, %u leaves, %llu links, %u rounds, solved in %.2f s\n",
               (double)mi.w, ls && ls->elem_size == 12 ? "present" : "MISSING", mi.k, (unsigned long long)bytes, mi.bounces,
               (double)mi.build_seconds);
        if (!ls || ls->elem_size != 12) {
            fprintf(stderr, "rad info: the hierarchical bake holds no vector L\n");
            return 1;
        }
        return method_open(path, bake, mi.method);
    }
    if (mi.method == TOOL_STOCHASTIC) { /* the record's fields as methods.c fills them for this method */
        const rad_section *ls = rad_container_find(ct, RAD_SECTION_VECTOR, "L");
        printf("method: stochastic, --sr-estimator %s, --sr-rays %u, --sr-iterations %u, --seed %u\n"
               "  solution 'L': %s, %llu rays, solved in %.2f s\n",
               mi.mode == RAD_STOCHASTIC_WALK ? "walk" : "jacobi", mi.k, mi.bounces, mi.seed,
               ls && ls->elem_size == 12 ? "present" : "MISSING", (unsigned long long)bytes, (double)mi.build_seconds);
        if (!ls || ls->elem_size != 12) {
            fprintf(stderr, "rad info: the stochastic bake holds no vector L\n");
            return 1;
        }
        return method_open(path, bake, mi.method);
    }
    if (mi.method == TOOL_MULTIBOUNCE) {
        static const char *const fmt[] = {"float", "half", "bc1", "bc4x3"};
        rad_multibounce *mb = NULL;
        rad_multibounce_blocks *bl = NULL;
        char kb[16];
        if (mi.bounces == RAD_MB_INFINITE) strcpy(kb, "inf");
        else snprintf(kb, sizeof kb, "%u", mi.bounces);
        printf("method: multibounce, --bounces %s, --format %s", kb, mi.format < 4 ? fmt[mi.format] : "?");
        if (mi.format >= 2)
            printf(", --outliers %g, %s, --tile %u", (double)mi.outliers, mi.reorder ? "--reorder" : "--no-reorder",
                   mi.tile);
        printf("\n  F_mb 'Fmb': %llu bytes, built in %.2f s", (unsigned long long)bytes, (double)mi.build_seconds);
        if (mi.format >= 2)
            printf("; decoded-matrix RMS error %.3g (%.3g%% of the RMS entry), max %.3g", sqrt((double)mi.mse),
                   mi.source_mean_square > 0.0f ? 100.0 * sqrt((double)mi.mse / (double)mi.source_mean_square) : 0.0,
                   (double)mi.max_abs_error);
        printf("\n");
        r = mi.format >= 2 ? rad_multibounce_blocks_load(ct, "Fmb", ctx, &bl) : rad_multibounce_load(ct, "Fmb", ctx, &mb);
        rad_multibounce_blocks_destroy(bl);
        rad_multibounce_destroy(mb);
    } else {
        static const char *const names[3] = {"Fmb.r", "Fmb.g", "Fmb.b"};
        static const char *const modes[3] = {"single", "feedback", "multibounce"};
        uint32_t count = mi.mode == RAD_TEMPORAL_MULTIBOUNCE ? 3u : 1u;
        printf("method: temporal, --mode %s, --k %u, ", mi.mode < 3 ? modes[mi.mode] : "?", mi.k);
        if (mi.adaptive) printf("--adaptive");
        else printf("--w %g", (double)mi.w);
        printf(", --seed %u\n  alias tables:", mi.seed);
        for (i = 0; i < count && r == RAD_SUCCESS; ++i) {
            rad_alias_tables t;
            if ((r = rad_alias_tables_view(ct, count == 3 ? names[i] : "F", ctx, &t)) == RAD_SUCCESS)
                printf(" '%s' %llu bins (%s)", count == 3 ? names[i] : "F", (unsigned long long)t.row_offsets[t.rows],
                       t.format == RAD_ALIAS_COMPACT ? "8 bytes each" : "12 bytes each");
        }
        printf(", %llu bytes, built in %.2f s\n", (unsigned long long)bytes, (double)mi.build_seconds);
    }
    if (r != RAD_SUCCESS) {
        fprintf(stderr, "rad info: the %s data does not open: %s\n", mi.method == TOOL_MULTIBOUNCE ? "multibounce" : "temporal",
                rad_result_string(r));
        return 1;
    }
    return method_open(path, bake, mi.method);
}

static void info_usage(FILE *f)
{
    fprintf(f, "usage: rad info FILE.radb | SCENE\n"
               "Checks a bake (sizes, offsets, checksums, indices) and lists its sections, patch count,\n"
               "form-factor matrix and vectors, and for multibounce and temporal bakes what was built (F_mb's\n"
               "format, bytes and compression error; the alias tables). Exit code 1 with the loader's error\n"
               "for damaged files.\n"
               "For a scene (cornell, .obj, .gltf, .glb, ... ): its meshes, triangles and lights, and per\n"
               "material what the importer used (albedo and its texture, emission factor, glTF emissive\n"
               "strength and emission texture), what it read but does not use (doubleSided, alphaMode) and\n"
               "what it ignored (other textures and material extensions, each by name).\n");
}

/* `rad info SCENE`: the scene as imported, material by material */
static int scene_info(const char *path)
{
    tool_scene ts;
    char err[1024];
    uint32_t i, t, mi, *count, tris = 0;
    if (tool_load_scene(path, &ts, err, sizeof err)) {
        fprintf(stderr, "rad info: %s\n", err);
        return 1;
    }
    count = (uint32_t *)calloc(ts.desc.material_count ? ts.desc.material_count : 1, sizeof(uint32_t));
    if (!count) { tool_free_scene(&ts); fprintf(stderr, "rad info: out of memory\n"); return 1; }
    for (i = 0; i < ts.desc.mesh_count; ++i) {
        const rad_mesh_desc *m = &ts.desc.meshes[i];
        for (t = 0; t < m->triangle_count; ++t) {
            mi = m->material_ids ? m->material_ids[t] : m->material;
            if (mi < ts.desc.material_count) ++count[mi];
        }
        tris += m->triangle_count;
    }
    printf("%s: %u meshes, %u triangles, %u materials, %u lights\n", path, ts.desc.mesh_count, tris, ts.desc.material_count,
           ts.light_count);
    for (i = 0; i < ts.desc.material_count; ++i) {
        const rad_material *m = &ts.desc.materials[i];
        printf("material %u '%s': %u triangles\n", i, ts.material_names ? ts.material_names[i] : "", count[i]);
        if (ts.material_reports && ts.material_reports[i]) {
            fputs(ts.material_reports[i], stdout);
        } else {
            printf("  albedo: %g %g %g\n", (double)m->albedo[0], (double)m->albedo[1], (double)m->albedo[2]);
            if (m->emission[0] > 0.0f || m->emission[1] > 0.0f || m->emission[2] > 0.0f)
                printf("  emission (radiance): %g %g %g\n", (double)m->emission[0], (double)m->emission[1],
                       (double)m->emission[2]);
        }
    }
    free(count);
    tool_free_scene(&ts);
    return 0;
}

int tool_cmd_info(int argc, char **argv)
{
    const char *cmd = "info", *path = NULL;
    size_t len;
    void *data;
    rad_container *ct = NULL;
    rad_bake *bake = NULL;
    rad_context ctx;
    rad_result r;
    uint32_t i, count;
    int a;
    for (a = 0; a < argc; ++a) {
        if (!strcmp(argv[a], "--help") || !strcmp(argv[a], "-h")) { info_usage(stdout); return 0; }
        if (!strcmp(argv[a], "--threads") && a + 1 < argc) {
            uint32_t t;
            if (tool_parse_threads(cmd, argv[a], argv[a + 1], &t)) return 2;
            ++a;
            continue;
        }
        if (argv[a][0] == '-' && argv[a][1]) { fprintf(stderr, "rad %s: unknown option '%s'\n", cmd, argv[a]); return 2; }
        if (path) { fprintf(stderr, "rad %s: more than one file given\n", cmd); return 2; }
        path = argv[a];
    }
    if (!path) { fprintf(stderr, "rad %s: no file given\n", cmd); info_usage(stderr); return 2; }
    if (tool_is_scene_path(path)) return scene_info(path);
    if (tool_read_file(cmd, "bake", path, &data, &len)) return 1;
    tool_context(&ctx, NULL);
    if ((r = rad_container_create(data, (size_t)len, &ctx, &ct)) != RAD_SUCCESS) {
        fprintf(stderr, "rad %s: '%s' is not a valid bake: %s\n", cmd, path, rad_result_string(r));
        free(data);
        return 1;
    }
    count = rad_container_section_count(ct);
    printf("%s: %llu bytes, container version %u, %u sections\n", path, (unsigned long long)len, RAD_CONTAINER_VERSION, count);
    printf("  %-3s %-20s %-14s %9s %12s %14s  %s\n", "#", "type", "name", "elem size", "count", "bytes", "checksum");
    for (i = 0; i < count; ++i) {
        const rad_section *s = rad_container_section(ct, i);
        printf("  %-3u %-20s %-14s %9u %12llu %14llu  OK\n", i, type_name(s->type), s->name[0] ? s->name : "-",
               s->elem_size, (unsigned long long)s->count, (unsigned long long)s->count * s->elem_size);
    }
    if (rad_container_find(ct, RAD_SECTION_BAKER_INFO, NULL)) {
        int rc = baker_info(path, data, len, &ctx);
        rad_container_destroy(ct);
        free(data);
        return rc;
    }
    {
        /* a virtual-patch bake (rad bake --method aavp|vp): its info record, no classic patches */
        const rad_section *vi = rad_container_find(ct, RAD_SECTION_VP_INFO, NULL), *rows;
        if (vi && !rad_container_find(ct, RAD_SECTION_PATCHES, NULL)) {
            /* opened as render opens it (rad_vp_load and the E check), without a scene */
            rad_container *vct = NULL;
            rad_virtual_patches *vp = NULL;
            float *E = NULL;
            uint32_t rec[16];
            memset(rec, 0, sizeof rec);
            if (vi->elem_size == 4 && vi->count == 16) memcpy(rec, vi->data, sizeof rec);
            rows = rad_container_find(ct, RAD_SECTION_FF_ROW_OFFSETS, vi->name);
            printf("virtual patches '%s': %s, %u patches in %u voxels (grid %u x %u x %u), %u samples, form factors %s\n",
                   vi->name, rec[0] == (uint32_t)RAD_VP_CLUSTERED ? "clustered (vp)" : "axis-aligned (aavp)", rec[2],
                   rec[3], rec[5], rec[6], rec[7], rec[4], rows ? "sparse (CSR)" : "dense");
            rad_container_destroy(ct);
            if (tool_vp_bake_open(cmd, path, data, len, NULL, &vct, &vp, &E)) {
                free(data);
                return 1;
            }
            printf("checksums: all OK; virtual patches, form factors and E: all valid\n");
            free(E);
            rad_vp_destroy(vp);
            rad_container_destroy(vct);
            free(data);
            return 0;
        }
    }
    if ((r = rad_load_memory(data, (size_t)len, &ctx, &bake)) != RAD_SUCCESS) {
        fprintf(stderr, "rad %s: '%s' holds sections but not a valid bake: %s\n", cmd, path, rad_result_string(r));
        rad_container_destroy(ct);
        free(data);
        return 1;
    }
    printf("patches: %u (%u welded vertices, %u scene triangles)\n", bake->patches.count, bake->patches.vertex_count,
           bake->patches.triangle_count);
    if (bake->F.rows)
        printf("form factors: %s %u x %u\n", bake->F.storage == RAD_STORAGE_DENSE ? "dense" : "sparse (CSR)", bake->F.rows,
               bake->F.cols);
    else
        printf("form factors: none\n");
    printf("vectors:");
    {
        int any = 0;
        for (i = 0; i < count; ++i) {
            const rad_section *s = rad_container_section(ct, i);
            if (s->type == RAD_SECTION_VECTOR) {
                printf(" %s", s->name[0] ? s->name : "(unnamed)");
                any = 1;
            }
        }
        printf("%s\n", any ? "" : " none");
    }
    if (bake->signature)
        printf("signature: geometry %016llx, materials %016llx, options %016llx\n",
               (unsigned long long)bake->signature->geometry, (unsigned long long)bake->signature->materials,
               (unsigned long long)bake->signature->options);
    else
        printf("signature: none (a bake of another scene with the same triangle count cannot be told apart)\n");
    {
        const rad_section *s = rad_container_find(ct, TOOL_SECTION_OPTIONS, "rad.options");
        if (s && s->elem_size == sizeof(tool_bake_info) && s->count == 1) {
            tool_bake_info info;
            memcpy(&info, s->data, sizeof info);
            if (info.magic == 0x52414442u && rad_container_find(ct, TOOL_SECTION_METHOD, "rad.method"))
                printf("baked with: --patches %u --max-edge %g --samples %u --light-samples %u (scene of %u triangles)\n",
                       info.patches, (double)info.max_edge, info.samples, info.light_samples, info.triangle_count);
            else if (info.magic == 0x52414442u)
                printf("baked with: --patches %u --max-edge %g --samples %u --solver %s --bounces %u --light-samples %u "
                       "(scene of %u triangles)\n",
                       info.patches, (double)info.max_edge, info.samples,
                       info.solver == 1 ? "gauss-seidel" : info.solver == 2 ? "direct" : "jacobi", info.bounces,
                       info.light_samples, info.triangle_count);
        }
    }
    if (method_info(path, bake, &ctx)) {
        rad_bake_destroy(bake);
        rad_container_destroy(ct);
        free(data);
        return 1;
    }
    printf("checksums: all OK\n");
    rad_bake_destroy(bake);
    rad_container_destroy(ct);
    free(data);
    return 0;
}
