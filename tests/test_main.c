/* test_main.c - the unit tests: one translation unit holding the implementation and every
   test file. Usage: test_main [NAME-SUBSTRING]. Prints "N passed, N failed" last. */
#define RADIOSITY_IMPLEMENTATION
#include "../radiosity.h"
#include "test.h"

#include "test_scene.c"
#include "test_formfactor.c"
#include "test_solve.c"
#include "test_light.c"

static const rad_test_case *const rad_test_tables[] = { tests_scene, tests_formfactor, tests_solve, tests_light };

int main(int argc, char **argv)
{
    int passed = 0, failed = 0;
    size_t t;
    for (t = 0; t < sizeof(rad_test_tables) / sizeof(rad_test_tables[0]); ++t) {
        const rad_test_case *c;
        for (c = rad_test_tables[t]; c->name; ++c) {
            if (argc > 1 && !strstr(c->name, argv[1])) continue;
            rad_test_failures = 0;
            printf("%s\n", c->name);
            fflush(stdout);
            c->fn();
            if (rad_test_failures) { printf("  FAILED %s (%d checks)\n", c->name, rad_test_failures); failed++; }
            else passed++;
        }
    }
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
