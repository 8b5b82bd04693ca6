/* test_main.c - the unit tests: one translation unit holding the implementation and every
   test file, run in the order of the table below. Each test file also builds on its own:
   cc -std=c99 -O2 -I. tests/test_vp.c -o build/test_vp -lm (test.h describes the arguments
   and the environment both understand). */
#define RAD_TEST_ALL 1 /* the test files' RAD_TEST_MAIN expand to nothing: main is below */
#include "fixtures.h"

#include "test_scene.c"
#include "test_formfactor.c"
#include "test_hemicube.c"
#include "test_hierarchical.c"
#include "test_solve.c"
#include "test_stochastic.c"
#include "test_light.c"
#include "test_embree.c"
#include "test_container.c"
#include "test_multibounce.c"
#include "test_temporal.c"
#include "test_local.c"
#include "test_vp.c"
#include "test_vp_runtime.c"
#include "test_regress.c"
#include "test_robust.c"
#include "test_api.c"
#include "test_alloc.c"
#include "test_shading.c"
#include "test_glsl.c"
#include "test_probes.c"
#include "test_lightmap.c"
#include "test_rel.c"
#include "test_defaults.c"
#include "test_emissive.c"
#include "test_twosided.c"
#include "test_cutout.c"
#include "test_env.c"
#include "test_bake.c"
#include "test_runtime.c"
#include "test_hier_large.c"
#include "test_hier_scale.c"
#include "test_hier_energy.c"
#include "test_hier_source.c"
#include "test_hier_open.c"
#include "test_direct_noise.c"
#include "test_direct_pool.c"
#include "test_plan.c"
#include "test_plan_small.c"
#include "test_layers.c"
#include "test_vp_accuracy.c"
#include "test_bake_solution.c"
#include "test_bake_probes.c"
#include "test_baker_lightmap.c"
#include "test_rgb9e5.c"
#include "test_lightmap_fg.c"
#include "test_baker_raycaster.c"
#include "test_baker_solver.c"
#include "test_baker_save.c"

static const rad_test_case *const rad_test_tables[] = { tests_scene, tests_formfactor, tests_hemicube, tests_hierarchical, tests_solve, tests_stochastic, tests_light, tests_embree, tests_container, tests_multibounce, tests_temporal, tests_local, tests_vp, tests_vp_runtime, tests_regress, tests_robust, tests_api, tests_alloc, tests_shading, tests_glsl, tests_probes, tests_lightmap, tests_rel, tests_defaults, tests_emissive, tests_twosided, tests_cutout, tests_env, tests_bake, tests_runtime, tests_hier_large, tests_hier_scale, tests_hier_energy, tests_hier_source, tests_hier_open, tests_direct_noise, tests_direct_pool, tests_plan, tests_layers, tests_vp_accuracy, tests_bake_solution, tests_bake_probes, tests_baker_lightmap, tests_plan_small, tests_rgb9e5, tests_lightmap_fg, tests_baker_raycaster, tests_baker_solver, tests_baker_save };

int main(int argc, char **argv)
{
    return rad_test_run(rad_test_tables, sizeof(rad_test_tables) / sizeof(rad_test_tables[0]), argc, argv);
}
