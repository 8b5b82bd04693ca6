/* dist_part_edit.c - for tests/dist_tests.sh: copies a part of a sharded bake (rad bake
   --shard) with the library version in its rad.shard record replaced, as a build of another
   version would have written it (the checksums are those of the new bytes, so only the merge's
   version check can refuse it).
       dist_part_edit IN.radb OUT.radb VERSION */
#define RADIOSITY_IMPLEMENTATION
#include "radiosity.h"
#include "tools/tool.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int main(int argc, char **argv)
{
    FILE *f;
    long len;
    unsigned char *in, *out;
    rad_container *ct = NULL;
    rad_section secs[32];
    tool_shard_info sh;
    uint32_t n, i;
    size_t size;
    if (argc != 4 || !(f = fopen(argv[1], "rb"))) return 2;
    fseek(f, 0, SEEK_END);
    len = ftell(f);
    fseek(f, 0, SEEK_SET);
    in = (unsigned char *)malloc((size_t)len);
    if (!in || fread(in, 1, (size_t)len, f) != (size_t)len) return 1;
    fclose(f);
    if (rad_container_create(in, (size_t)len, NULL, &ct) != RAD_SUCCESS) return 1;
    n = rad_container_section_count(ct);
    if (n > 32) return 1;
    for (i = 0; i < n; ++i) {
        secs[i] = *rad_container_section(ct, i);
        if (secs[i].type == TOOL_SECTION_SHARD && secs[i].elem_size == sizeof sh) {
            memcpy(&sh, secs[i].data, sizeof sh);
            memset(sh.library, 0, sizeof sh.library);
            strncpy(sh.library, argv[3], sizeof sh.library - 1);
            secs[i].data = &sh;
        }
    }
    if (rad_container_size(secs, n, &size) != RAD_SUCCESS || !(out = (unsigned char *)malloc(size)) ||
        rad_container_write(secs, n, out, size) != RAD_SUCCESS)
        return 1;
    if (!(f = fopen(argv[2], "wb")) || fwrite(out, 1, size, f) != size || fclose(f) != 0) return 1;
    rad_container_destroy(ct);
    free(in);
    free(out);
    return 0;
}
