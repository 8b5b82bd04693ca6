/* cmd_info.c - `rad info FILE.radb`: what a baked-data container holds, after checking it
   (rad_container_open validates every size, offset and checksum; rad_load_memory every
   index). A damaged file gives the loader's error and detail and exit code 1. */
#include "tool.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *type_name(uint32_t type)
{
    switch (type) {
    case RAD_SECTION_PATCHES: return "PATCHES";
    case RAD_SECTION_PATCH_VERTICES: return "PATCH_VERTICES";
    case RAD_SECTION_TRIANGLES: return "TRIANGLES";
    case RAD_SECTION_FF_DENSE: return "FF_DENSE";
    case RAD_SECTION_FF_ROW_OFFSETS: return "FF_ROW_OFFSETS";
    case RAD_SECTION_FF_COLUMNS: return "FF_COLUMNS";
    case RAD_SECTION_FF_VALUES: return "FF_VALUES";
    case RAD_SECTION_VECTOR: return "VECTOR";
    case RAD_TOOL_SECTION_OPTIONS: return "USER(rad options)";
    default: return type >= RAD_SECTION_USER ? "USER" : "UNKNOWN";
    }
}

static void info_usage(FILE *f)
{
    fprintf(f, "usage: rad info FILE.radb\n"
               "Checks a bake (sizes, offsets, checksums, indices) and lists its sections, patch count,\n"
               "form-factor matrix and vectors. Exit code 1 with the loader's error for damaged files.\n");
}

int rad_cmd_info(int argc, char **argv)
{
    const char *cmd = "info", *path = NULL;
    FILE *f;
    long len;
    void *data;
    rad_container *ct = NULL;
    rad_bake *bake = NULL;
    rad_context ctx;
    rad_result r;
    uint32_t i, count;
    int a;
    for (a = 0; a < argc; ++a) {
        if (!strcmp(argv[a], "--help") || !strcmp(argv[a], "-h")) { info_usage(stdout); return 0; }
        if (!strcmp(argv[a], "--threads") && a + 1 < argc) { ++a; continue; }
        if (argv[a][0] == '-' && argv[a][1]) { fprintf(stderr, "rad %s: unknown option '%s'\n", cmd, argv[a]); return 2; }
        if (path) { fprintf(stderr, "rad %s: more than one file given\n", cmd); return 2; }
        path = argv[a];
    }
    if (!path) { fprintf(stderr, "rad %s: no file given\n", cmd); info_usage(stderr); return 2; }
    f = fopen(path, "rb");
    if (!f) { fprintf(stderr, "rad %s: cannot open '%s'\n", cmd, path); return 1; }
    if (fseek(f, 0, SEEK_END) != 0 || (len = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
        fclose(f);
        fprintf(stderr, "rad %s: cannot read '%s'\n", cmd, path);
        return 1;
    }
    data = malloc(len > 0 ? (size_t)len : 1); /* malloc: aligned for any type, as the loader wants */
    if (!data || (len > 0 && fread(data, 1, (size_t)len, f) != (size_t)len)) {
        fclose(f);
        free(data);
        fprintf(stderr, "rad %s: cannot read '%s'\n", cmd, path);
        return 1;
    }
    fclose(f);
    rad_tool_context(&ctx, NULL);
    if ((r = rad_container_open(data, (size_t)len, &ctx, &ct)) != RAD_SUCCESS) {
        fprintf(stderr, "rad %s: '%s' is not a valid bake: %s\n", cmd, path, rad_result_string(r));
        free(data);
        return 1;
    }
    count = rad_container_section_count(ct);
    printf("%s: %ld bytes, container version %u, %u sections\n", path, len, RAD_CONTAINER_VERSION, count);
    printf("  %-3s %-18s %-14s %9s %12s %14s  %s\n", "#", "type", "name", "elem size", "count", "bytes", "checksum");
    for (i = 0; i < count; ++i) {
        const rad_section *s = rad_container_section(ct, i);
        printf("  %-3u %-18s %-14s %9u %12llu %14llu  OK\n", i, type_name(s->type), s->name[0] ? s->name : "-",
               s->elem_size, (unsigned long long)s->count, (unsigned long long)s->count * s->elem_size);
    }
    if ((r = rad_load_memory(data, (size_t)len, &ctx, &bake)) != RAD_SUCCESS) {
        fprintf(stderr, "rad %s: '%s' holds sections but not a valid bake: %s\n", cmd, path, rad_result_string(r));
        rad_container_close(ct);
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
    {
        const rad_section *s = rad_container_find(ct, RAD_TOOL_SECTION_OPTIONS, "rad.options");
        if (s && s->elem_size == sizeof(rad_tool_bake_info) && s->count == 1) {
            rad_tool_bake_info info;
            memcpy(&info, s->data, sizeof info);
            if (info.magic == 0x52414442u)
                printf("baked with: --patches %u --max-edge %g --samples %u --solver %s --bounces %u --light-samples %u "
                       "(scene of %u triangles)\n",
                       info.patches, (double)info.max_edge, info.samples,
                       info.solver == 1 ? "gauss-seidel" : info.solver == 2 ? "direct" : "jacobi", info.bounces,
                       info.light_samples, info.triangle_count);
        }
    }
    printf("checksums: all OK\n");
    rad_bake_destroy(bake);
    rad_container_close(ct);
    free(data);
    return 0;
}
