// compile_cpp.cpp - the header with its implementation compiles as C++11 with every warning
// on, and a minimal pipeline runs.
#define RADIOSITY_IMPLEMENTATION
#include "../radiosity.h"
#include <cstdio>
#include <vector>

int main()
{
    rad_scene_desc desc;
    rad_scene *scene = nullptr;
    rad_patches *patches = nullptr;
    rad_patch_options po;
    rad_cornell_box(&desc, nullptr);
    if (rad_scene_create(&desc, nullptr, &scene) != RAD_SUCCESS) return 1;
    rad_patch_options_default(&po);
    po.target_count = 100;
    if (rad_patches_create(scene, &po, nullptr, &patches) != RAD_SUCCESS) return 2;
    std::vector<float> E(3 * patches->count);
    if (rad_sources(patches, RAD_SOURCE_EMISSION, nullptr, E.data()) != RAD_SUCCESS) return 3;
    rad_patches_destroy(patches);
    rad_scene_destroy(scene);
    std::printf("%s\n", rad_result_string(RAD_ERROR_NON_FINITE));
    return 0;
}
