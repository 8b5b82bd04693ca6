/* compile_no_glsl.c - the header built with RAD_NO_GLSL (the kernels' text left out) compiles,
   links and answers: the GLSL functions report the kernels as unavailable, the rest works. */
#define RAD_NO_GLSL
#define RADIOSITY_IMPLEMENTATION
#include "../radiosity.h"
#include <stdio.h>

int main(void)
{
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    uint32_t count = 7;
    size_t length = 7;
    char text[16];
    if (rad_glsl_name(RAD_GLSL_GATHER_DENSE) != NULL) return 1;
    if (rad_glsl_pieces(RAD_GLSL_GATHER_DENSE, &count) != NULL || count != 0) return 2;
    if (rad_glsl_source(RAD_GLSL_GATHER_DENSE, text, sizeof(text), &length) != RAD_ERROR_UNAVAILABLE || length != 0)
        return 3;
    rad_cornell_box(&desc, NULL);
    if (rad_scene_create(&desc, NULL, &scene) != RAD_SUCCESS) return 4;
    if (scene->triangle_count != 32) return 5;
    rad_scene_destroy(scene);
    printf("%s\n", rad_result_string(RAD_ERROR_UNAVAILABLE));
    return 0;
}
