/* link_a.c - the implementation unit of the C + C++ link test. */
#define RADIOSITY_IMPLEMENTATION
#include "../radiosity.h"
int link_a_triangles(void)
{
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    int n;
    rad_cornell_box(&desc, NULL);
    if (rad_scene_create(&desc, NULL, &scene) != RAD_SUCCESS) return -1;
    n = (int)scene->triangle_count;
    rad_scene_destroy(scene);
    return n;
}
