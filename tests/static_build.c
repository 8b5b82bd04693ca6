/* static_build.c - RADIOSITY_STATIC makes every function static; a program that uses part of
   the API still compiles without unused-function warnings being errors (-Wno-unused-function
   is the usual companion of stb-style static builds, so the test allows it). */
#define RADIOSITY_STATIC
#define RADIOSITY_IMPLEMENTATION
#include "../radiosity.h"

int main(void)
{
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    rad_cornell_box(&desc, NULL);
    if (rad_scene_create(&desc, NULL, &scene) != RAD_SUCCESS) return 1;
    rad_scene_destroy(scene);
    return 0;
}
