/* main.c - the rad program: tool_main (rad.c) dispatches to the subcommands. Kept apart
   so that tools/mpi/rad_mpi.c links every other source of the tool with its own main. */
#if defined(__linux__) && !defined(_POSIX_C_SOURCE)
#define _POSIX_C_SOURCE 200112L /* setenv, execv */
#endif
#include <stdlib.h>
#if defined(__linux__)
#include <unistd.h>
#endif
#include "tool.h"

int main(int argc, char **argv)
{
#if defined(_OPENMP) && defined(__linux__)
    /* OpenMP threads that run out of work spin at the region's end and between regions, CPU
       time that a shared machine's other work could use; the wait policy is read when the
       runtime loads, before main, so the tool runs itself once more with a passive policy
       (docs/tool.md). A policy or spin count the user set is kept. */
    if (!getenv("OMP_WAIT_POLICY") && !getenv("GOMP_SPINCOUNT") && setenv("OMP_WAIT_POLICY", "passive", 1) == 0)
        execv("/proc/self/exe", argv); /* on failure: on with the runtime's default */
#endif
    return tool_main(argc, argv);
}
