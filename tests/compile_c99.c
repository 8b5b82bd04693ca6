/* compile_c99.c - the header with its implementation compiles as C99 with every warning on,
   and a minimal pipeline runs. */
#define RADIOSITY_IMPLEMENTATION
#include "../radiosity.h"
#include <stdio.h>

int main(void)
{
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    rad_cornell_box(&desc, NULL);
    if (rad_scene_create(&desc, NULL, &scene) != RAD_SUCCESS) return 1;
    if (scene->triangle_count != 32) return 2;
    rad_scene_destroy(scene);
    printf("%s\n", rad_result_string(RAD_SUCCESS));
    return 0;
}
