/* rad_mpi.c - `rad-mpi bake SCENE -o FILE.radb [rad bake's classic options]`: the sharded
   classic bake (rad bake --shard I/N) with one shard per MPI rank, merged by rank 0 into the
   bake a single `rad bake` writes, byte for byte (docs/distributed.md).

       mpirun -np 64 tools/rad-mpi bake scene.gltf --patches 100000 -o scene.radb

   Each rank loads the scene and bakes its part in memory (tool_bake_part); rank 0 gathers
   the parts and merges them (tool_merge: the same checks as rad merge). A rank that fails
   prints its message, prefixed with its rank, and the whole run exits 1 with nothing written:
   only rank 0 writes, through a temporary renamed into place after the merge succeeded. Built
   with mpicc from the rad tool's sources but tools/main.c (make rad-mpi); the library knows
   nothing of MPI. Threads per rank: --threads N, else OMP_NUM_THREADS, else the
   cores this rank may use divided by the ranks on its node. */
#include "../tool.h"
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/* parts move in pieces of at most this many bytes (MPI counts are int) */
#define TOOL_MPI_CHUNK ((size_t)1 << 30)

static void usage(FILE *f)
{
    fprintf(f, "usage: mpirun -np N rad-mpi bake SCENE -o FILE.radb [options of rad bake --method classic]\n"
               "Bakes shard I of N on rank I (rad bake --shard I/N) and merges the parts on rank 0 into\n"
               "the bake a single rad bake writes. A failing rank fails the run; nothing is written then.\n"
               "Options: those of rad bake (rad bake --help) but --method, --shard and --rows.\n");
}

static void send_bytes(const unsigned char *p, size_t n, int to)
{
    while (n > 0) {
        size_t k = n < TOOL_MPI_CHUNK ? n : TOOL_MPI_CHUNK;
        MPI_Send((void *)(size_t)p, (int)k, MPI_BYTE, to, 1, MPI_COMM_WORLD);
        p += k;
        n -= k;
    }
}

static void recv_bytes(unsigned char *p, size_t n, int from)
{
    while (n > 0) {
        size_t k = n < TOOL_MPI_CHUNK ? n : TOOL_MPI_CHUNK;
        MPI_Recv(p, (int)k, MPI_BYTE, from, 1, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        p += k;
        n -= k;
    }
}

/* the threads of this rank when --threads is not given */
static void choose_threads(uint32_t given)
{
#ifdef _OPENMP
    MPI_Comm node;
    int local = 1, procs;
    if (given || getenv("OMP_NUM_THREADS")) {
        tool_set_threads((int)given);
        return;
    }
    MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
    MPI_Comm_size(node, &local);
    MPI_Comm_free(&node);
    procs = omp_get_num_procs(); /* the cores this rank is bound to, when mpirun binds it */
    tool_set_threads(procs / local > 1 ? procs / local : 1);
#else
    (void)given;
#endif
}

int main(int argc, char **argv)
{
    tool_bake_args args;
    tool_world w;
    char cmd[64];
    void *part = NULL;
    size_t part_size = 0;
    int rank, ranks, rc = -1, fail = 0, any = 0;
    double t0;
    MPI_Init(&argc, &argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    t0 = MPI_Wtime();
    sprintf(cmd, "mpi bake [rank %d/%d]", rank, ranks);
    tool_show_progress(rank == 0); /* one progress line, not one per rank */
    /* the command line: rank 0 says what is wrong with it, once */
    if (rank == 0) {
        if (argc < 2 || strcmp(argv[1], "bake")) {
            if (argc >= 2 && (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") || !strcmp(argv[1], "help"))) {
                usage(stdout);
                rc = 0;
            } else {
                usage(stderr);
                rc = 2;
            }
        } else {
            rc = tool_bake_parse("mpi bake", argc - 2, argv + 2, &args);
            if (rc < 0 && (args.shard.count || args.shard.rows || (args.mo.given & TOOL_OPT_METHOD))) {
                fprintf(stderr, "rad mpi bake: the ranks are the shards (--shard, --rows) and the method is classic "
                                "(--method): leave them out\n");
                rc = 2;
            }
            if (rc < 0 && tool_check_output("mpi bake", args.out, &args.scene, 1)) rc = 1;
        }
    }
    MPI_Bcast(&rc, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (rc >= 0) {
        if (rank == 0 && argc >= 2 && !strcmp(argv[1], "bake")) tool_lights_free(&args.lights);
        MPI_Finalize();
        return rc;
    }
    if (rank != 0 && tool_bake_parse(cmd, argc - 2, argv + 2, &args) >= 0) fail = 1; /* rank 0 accepted it */
    if (!fail) {
        tool_shard_spec spec;
        memset(&spec, 0, sizeof spec);
        spec.index = (uint32_t)rank;
        spec.count = (uint32_t)ranks;
        choose_threads(args.threads);
        if (tool_open_world_lit(cmd, args.scene, &args.lights, &w)) fail = 1;
        else {
            fail = tool_bake_part(cmd, &w, &args.o, &spec, &part, &part_size) != 0;
            tool_close_world(&w);
        }
    }
    tool_lights_free(&args.lights);
    MPI_Allreduce(&fail, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (any) {
        if (rank == 0) fprintf(stderr, "rad mpi bake: a rank failed (its message is above): nothing written\n");
        free(part);
        MPI_Finalize();
        return 1;
    }
    {
        uint64_t mine = part_size, *sizes = NULL;
        if (rank == 0) sizes = (uint64_t *)tool_calloc((size_t)ranks, sizeof *sizes);
        MPI_Gather(&mine, 1, MPI_UINT64_T, sizes, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
        if (rank == 0) {
            tool_part *parts = (tool_part *)tool_calloc((size_t)ranks, sizeof *parts);
            char (*names)[32] = (char (*)[32])tool_calloc((size_t)ranks, sizeof *names);
            int r;
            for (r = 0; r < ranks; ++r) {
                sprintf(names[r], "rank %d", r);
                parts[r].name = names[r];
                parts[r].size = (size_t)sizes[r];
                if (r == 0) {
                    parts[r].data = part;
                } else {
                    unsigned char *buf = (unsigned char *)malloc(sizes[r] ? (size_t)sizes[r] : 1);
                    if (!buf) {
                        fprintf(stderr, "rad mpi bake: out of memory for the part of rank %d\n", r);
                        MPI_Abort(MPI_COMM_WORLD, 1);
                    }
                    recv_bytes(buf, (size_t)sizes[r], r);
                    parts[r].data = buf;
                }
            }
            rc = tool_merge("mpi bake", parts, (uint32_t)ranks, args.out);
            for (r = 1; r < ranks; ++r) free((void *)(size_t)parts[r].data);
            free(parts);
            free(names);
            free(sizes);
            if (rc == 0) fprintf(stderr, "rad mpi bake: %d ranks, done in %.2f s\n", ranks, MPI_Wtime() - t0);
        } else {
            send_bytes((const unsigned char *)part, part_size, 0);
        }
    }
    free(part);
    MPI_Bcast(&rc, 1, MPI_INT, 0, MPI_COMM_WORLD);
    MPI_Finalize();
    return rc;
}
