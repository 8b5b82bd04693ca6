/* world.c - the scene a command works on (tool_world: the file, its lights and those of the
   command line, the validated scene and its BVH) and a camera for a scene that has none.
   Apart from common.c so that the helpers there call nothing above them (lights.c uses them,
   and the world uses lights.c). */
#include "tool.h"
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int tool_open_world(const char *cmd, const char *path_or_name, tool_world *w)
{
    return tool_open_world_lit(cmd, path_or_name, NULL, w);
}

int tool_open_world_lit(const char *cmd, const char *path_or_name, const tool_lights *lights,
                            tool_world *w)
{
    char err[1024];
    rad_context ctx;
    rad_result r;
    memset(w, 0, sizeof *w);
    if (tool_load_scene(path_or_name, &w->file, err, sizeof err) != 0) {
        fprintf(stderr, "rad %s: %s\n", cmd, err);
        return 1;
    }
    w->file_light_count = w->file.light_count;
    if (tool_add_lights(cmd, &w->file, lights, &w->lights_storage)) {
        tool_free_scene(&w->file);
        return 1;
    }
    tool_context(&ctx, NULL);
    if ((r = rad_scene_create(&w->file.desc, &ctx, &w->scene)) != RAD_SUCCESS) {
        tool_close_world(w);
        return tool_fail(cmd, "rad_scene_create", r);
    }
    if (w->scene->skipped_triangles)
        fprintf(stderr, "rad: warning: %u degenerate triangles skipped\n", w->scene->skipped_triangles);
    if ((r = rad_bvh_create(w->scene, &ctx, &w->bvh)) != RAD_SUCCESS) {
        tool_close_world(w);
        return tool_fail(cmd, "rad_bvh_create", r);
    }
    rad_bvh_raycaster(w->bvh, &w->rc);
    return 0;
}

void tool_close_world(tool_world *w)
{
    rad_bvh_destroy(w->bvh);
    rad_scene_destroy(w->scene);
    tool_free_scene(&w->file);
    tool_lights_release(w->lights_storage);
    memset(w, 0, sizeof *w);
}

/* ---- a camera for a scene that has none ------------------------------------------------ */

/* How much of a candidate view sees the front of surfaces: a grid of camera rays, counting the
   hits on front faces and on back faces (the patches are one-sided: a back face renders black),
   and the front hits within 3% of the bounds' depth of the side of the bounds facing the camera
   (the shell: a building seen from outside shows its outer wall, not what it holds). */
static void camera_score(const rad_scene *scene, const rad_raycaster *rc, const rad_camera *cam, int width, int height,
                         uint32_t *front, uint32_t *back, uint32_t *shell)
{
    enum { GRID = 24 };
    rad_ray rays[GRID * GRID];
    rad_hit hits[GRID * GRID];
    uint32_t n = 0, k;
    int x, y;
    const float *v = cam->target, *p = cam->position;
    float dir[3], len, near_side = 0.0f, depth = 0.0f;
    *front = *back = *shell = 0;
    for (k = 0; k < 3; ++k) dir[k] = v[k] - p[k];
    len = sqrtf(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    for (k = 0; k < 3 && len > 0.0f; ++k) {
        dir[k] /= len;
        /* the view directions are along the axes: the side facing the camera and the depth */
        near_side += dir[k] * (dir[k] > 0.0f ? scene->bounds_min[k] : scene->bounds_max[k]);
        depth += fabsf(dir[k]) * (scene->bounds_max[k] - scene->bounds_min[k]);
    }
    for (y = 0; y < GRID; ++y)
        for (x = 0; x < GRID; ++x)
            rad_camera_ray(cam, (uint32_t)width, (uint32_t)height, ((float)x + 0.5f) * (float)width / GRID,
                           ((float)y + 0.5f) * (float)height / GRID, &rays[n++]);
    if (rc->intersect(rc->user, rays, n, hits) != RAD_SUCCESS) return;
    for (k = 0; k < n; ++k) {
        const float *nt;
        if (hits[k].triangle == RAD_NONE || hits[k].triangle >= scene->triangle_count) continue;
        nt = scene->normals + 3 * (size_t)hits[k].triangle;
        if (nt[0] * rays[k].dir[0] + nt[1] * rays[k].dir[1] + nt[2] * rays[k].dir[2] < 0.0f) {
            float along = 0.0f;
            int j;
            ++*front;
            for (j = 0; j < 3; ++j) along += dir[j] * (rays[k].origin[j] + hits[k].t * rays[k].dir[j]);
            if (along - near_side < 0.03f * depth) ++*shell;
        } else
            ++*back;
    }
}

/* the bounds' extent along candidate i's axis */
static float view_depth(const float *ext, int i)
{
    return ext[(i % 6) / 2 == 0 ? 2 : (i % 6) / 2 == 1 ? 0 : 1];
}

void tool_choose_camera(const char *cmd, const rad_scene *scene, const rad_raycaster *rc, int width, int height,
                            rad_camera *cam)
{
    /* view directions in order of preference: along +z first (the Cornell box's camera and
       the old default), then the other horizontal ones, then from above and from below */
    static const float dirs[6][3] = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {-1, 0, 0}, {0, -1, 0}, {0, 1, 0}};
    static const char *const names[6] = {"+z", "-z", "+x", "-x", "-y (from above)", "+y (from below)"};
    const float *lo = scene->bounds_min, *hi = scene->bounds_max;
    float c[3], ext[3], r = 0.0f, d, fov = 39.3077f;
    rad_camera cand[12];
    uint32_t front[12], back[12], shell[12], best_front = 0;
    int i, k, pick = -1;
    for (k = 0; k < 3; ++k) {
        c[k] = 0.5f * (lo[k] + hi[k]);
        ext[k] = hi[k] - lo[k];
        r += ext[k] * ext[k];
    }
    r = 0.5f * sqrtf(r);
    if (!(r > 0.0f)) r = 1.0f;
    d = r / sinf(0.5f * fov / 57.29577951f);
    for (i = 0; i < 12; ++i) {
        const float *v = dirs[i % 6];
        rad_camera *q = &cand[i];
        for (k = 0; k < 3; ++k) {
            /* 0-5: outside, the bounding sphere in view; 6-11: inside, near the side of the
               bounds behind the camera, looking across */
            float back_off = i < 6 ? d : 0.45f * ext[k];
            q->position[k] = c[k] - v[k] * back_off;
            q->target[k] = q->position[k] + v[k];
        }
        q->up[0] = 0.0f, q->up[1] = v[1] != 0.0f ? 0.0f : 1.0f, q->up[2] = v[1] != 0.0f ? 1.0f : 0.0f;
        q->fov_y_degrees = i < 6 ? fov : 75.0f; /* inside: wide, to see the room around the far wall */
        camera_score(scene, rc, q, width, height, &front[i], &back[i], &shell[i]);
    }
    /* a view qualifies when nine in ten of its hits are front faces; outside views come first
       (the first qualifying one seeing at least half as much as the best of them), then the
       inside ones (the one seeing most) */
    for (i = 0; i < 6; ++i)
        if (front[i] > 0 && 10u * front[i] >= 9u * (front[i] + back[i]) && front[i] > best_front) best_front = front[i];
    for (i = 0; i < 6 && pick < 0 && best_front; ++i)
        if (front[i] > 0 && 10u * front[i] >= 9u * (front[i] + back[i]) && 2u * front[i] >= best_front) pick = i;
    /* an outside view of a shell (three in four of its front hits on the outer side) gives way
       to an inside view that qualifies: Sponza's outer wall is not what its user wants to see */
    if (pick >= 0 && 4u * shell[pick] >= 3u * front[pick]) {
        int in = -1;
        for (i = 6; i < 12; ++i)
            if (front[i] > 0 && 10u * front[i] >= 9u * (front[i] + back[i]) &&
                (in < 0 || front[i] > front[in] || (front[i] == front[in] && view_depth(ext, i) > view_depth(ext, in))))
                in = i; /* the most seen; of equals, the longest view (down a nave, not across it) */
        if (in >= 0) pick = in;
    }
    for (i = 6; i < 12 && pick < 0; ++i)
        if (front[i] > 0 && 10u * front[i] >= 9u * (front[i] + back[i]) &&
            (pick < 0 || front[i] > front[pick]))
            pick = i;
    if (pick < 0) { /* nothing clean: the view with the most front faces over back faces */
        long best = 0;
        for (i = 0; i < 12; ++i)
            if ((long)front[i] - (long)back[i] > best) best = (long)front[i] - (long)back[i], pick = i;
        if (pick < 0) pick = 0;
    }
    *cam = cand[pick];
    fprintf(stderr,
            "rad %s: the scene has no camera: bounds (%g, %g, %g) to (%g, %g, %g); chose --camera %g,%g,%g:%g,%g,%g:%g,%g,%g "
            "--fov %g (%s the bounds, looking along %s: %u of %u sample rays see a front face, %u a back face)\n",
            cmd, (double)lo[0], (double)lo[1], (double)lo[2], (double)hi[0], (double)hi[1], (double)hi[2],
            (double)cam->position[0], (double)cam->position[1], (double)cam->position[2], (double)cam->target[0],
            (double)cam->target[1], (double)cam->target[2], (double)cam->up[0], (double)cam->up[1], (double)cam->up[2],
            (double)cam->fov_y_degrees, pick < 6 ? "outside" : "inside", names[pick % 6], front[pick], 24u * 24u,
            back[pick]);
}
