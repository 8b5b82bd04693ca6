/* main.c - the rad program: tool_main (rad.c) dispatches to the subcommands. Kept apart
   so that tools/mpi/rad_mpi.c links every other source of the tool with its own main. */
#include "tool.h"

int main(int argc, char **argv)
{
    return tool_main(argc, argv);
}
