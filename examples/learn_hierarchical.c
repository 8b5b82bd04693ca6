/* learn_hierarchical.c - hierarchical radiosity (Hanrahan, Salzman and Aupperle 1991) on the
   Cornell box, its links drawn as an image: the solution seen through the camera with each
   element flat (the quadtree shows as blocks, fine where light changes fast), and every link
   as a line from the receiver's centroid to the source's, coloured by the receiver's depth in
   its quadtree (red: a whole scene triangle, to yellow, green, cyan, blue as it gets finer).
   docs/methods/hierarchical.md.
       build/learn_hierarchical [--eps E] [--size N] [-o links.png] */
#define RADIOSITY_IMPLEMENTATION
#include "radiosity.h"
#include "png_write.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* the camera's pixel (x, y) of point p; 0 when p is behind the camera */
static int project(const rad_camera *c, int size, const float *p, float *x, float *y)
{
    float f[3], r[3], u[3], d[3], h = (float)tan(0.5 * c->fov_y_degrees * 3.14159265358979 / 180.0), z, l;
    int k;
    for (k = 0; k < 3; ++k) { f[k] = c->target[k] - c->position[k]; d[k] = p[k] - c->position[k]; }
    l = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (k = 0; k < 3; ++k) f[k] /= l;
    r[0] = f[1] * c->up[2] - f[2] * c->up[1]; r[1] = f[2] * c->up[0] - f[0] * c->up[2]; r[2] = f[0] * c->up[1] - f[1] * c->up[0];
    l = sqrtf(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    for (k = 0; k < 3; ++k) r[k] /= l;
    u[0] = r[1] * f[2] - r[2] * f[1]; u[1] = r[2] * f[0] - r[0] * f[2]; u[2] = r[0] * f[1] - r[1] * f[0];
    z = d[0] * f[0] + d[1] * f[1] + d[2] * f[2];
    if (z <= 1e-4f) return 0;
    *x = (0.5f + 0.5f * (d[0] * r[0] + d[1] * r[1] + d[2] * r[2]) / (z * h)) * (float)size;
    *y = (0.5f - 0.5f * (d[0] * u[0] + d[1] * u[1] + d[2] * u[2]) / (z * h)) * (float)size;
    return 1;
}

/* adds colour c times a to the pixels of the segment (x0, y0) - (x1, y1) */
static void line(float *img, int size, float x0, float y0, float x1, float y1, const float *c, float a)
{
    int n = (int)(fabsf(x1 - x0) + fabsf(y1 - y0)) + 1, i, k;
    for (i = 0; i <= n; ++i) {
        float t = (float)i / (float)n;
        int x = (int)(x0 + t * (x1 - x0)), y = (int)(y0 + t * (y1 - y0));
        if (x < 0 || y < 0 || x >= size || y >= size) continue;
        for (k = 0; k < 3; ++k) img[3 * ((size_t)y * size + x) + k] += a * c[k];
    }
}

int main(int argc, char **argv)
{
    static const float depth_colour[5][3] = { { 1, 0.1f, 0.1f }, { 1, 0.9f, 0.1f }, { 0.2f, 1, 0.2f }, { 0.1f, 0.9f, 1 }, { 0.3f, 0.4f, 1 } };
    const char *out = "links.png";
    double eps = 2e-3;
    int size = 512, i, k;
    rad_scene_desc desc;
    rad_camera cam;
    rad_scene *scene = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_hierarchical_options ho;
    rad_hierarchical *h = NULL;
    rad_hierarchical_stats st;
    float *img, *pts, *F;
    unsigned char *png;
    uint32_t *depth;
    uint64_t l;
    for (i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--eps") && i + 1 < argc) eps = atof(argv[++i]);
        else if (!strcmp(argv[i], "--size") && i + 1 < argc) size = atoi(argv[++i]);
        else if (!strcmp(argv[i], "-o") && i + 1 < argc) out = argv[++i];
        else { fprintf(stderr, "usage: %s [--eps E] [--size N] [-o links.png]\n", argv[0]); return 2; }
    }
    if (size < 16 || size > 4096) { fprintf(stderr, "--size must be 16..4096\n"); return 2; }
    rad_cornell_box(&desc, &cam);
    if (rad_scene_create(&desc, NULL, &scene) || rad_bvh_create(scene, NULL, &bvh)) return 1;
    rad_bvh_raycaster(bvh, &rc);
    /* 1. refine and solve: E = pi L of the light, links split until none carries more than eps
          of the light's power (or the elements reach min_area) */
    rad_hierarchical_options_default(&ho);
    ho.tolerance = eps;
    if (rad_hierarchical_create(scene, &rc, &ho, NULL, &h) || rad_hierarchical_solve(h, NULL)) {
        fprintf(stderr, "hierarchical solve failed (check --eps: 0 < E < 1)\n");
        return 1;
    }
    rad_hierarchical_get_stats(h, &st);
    printf("eps %g: %u leaves, %llu links (%.1f per leaf, N^2 would be %.0f), %llu kernel evaluations, %llu rays\n", eps,
           st.leaves, (unsigned long long)st.links, (double)st.links / st.leaves, (double)st.leaves * st.leaves,
           (unsigned long long)st.kernel_evaluations, (unsigned long long)st.rays_cast);
    /* 2. the solution, each leaf flat: B / pi is the radiance the camera sees */
    img = (float *)calloc(3 * (size_t)size * size, sizeof(float));
    png = (unsigned char *)malloc(3 * (size_t)size * size);
    if (!img || !png) return 1;
    for (i = 0; i < size * size; ++i) {
        rad_ray ray;
        rad_hit hit;
        float b[3], bc[2];
        rad_camera_ray(&cam, (uint32_t)size, (uint32_t)size, (float)(i % size) + 0.5f, (float)(i / size) + 0.5f, &ray);
        if (rc.intersect(rc.user, &ray, 1, &hit) || hit.triangle == RAD_NONE) continue;
        bc[0] = hit.b1;
        bc[1] = hit.b2;
        if (rad_hierarchical_lookup(h, RAD_HIERARCHICAL_RADIOSITY, 0, &hit.triangle, bc, 1, b)) continue;
        for (k = 0; k < 3; ++k) img[3 * i + k] = 0.35f * b[k] / 3.14159265f; /* dimmed under the links */
    }
    /* 3. the links, in batches of 4096 */
    pts = (float *)malloc(sizeof(float) * 6 * 4096);
    F = (float *)malloc(sizeof(float) * 4096);
    depth = (uint32_t *)malloc(sizeof(uint32_t) * 2 * 4096);
    if (!pts || !F || !depth) return 1;
    for (l = 0; l < st.links; l += 4096) {
        uint32_t n = st.links - l < 4096 ? (uint32_t)(st.links - l) : 4096u, j;
        if (rad_hierarchical_links(h, l, n, pts, F, depth)) return 1;
        for (j = 0; j < n; ++j) {
            float x0, y0, x1, y1;
            const float *c = depth_colour[depth[2 * j] < 4 ? depth[2 * j] : 4];
            if (project(&cam, size, pts + 6 * j, &x0, &y0) && project(&cam, size, pts + 6 * j + 3, &x1, &y1))
                line(img, size, x0, y0, x1, y1, c, 0.06f);
        }
    }
    for (i = 0; i < 3 * size * size; ++i) {
        float v = img[i] > 1.0f ? 1.0f : img[i];
        png[i] = (unsigned char)(255.0f * powf(v, 1.0f / 2.2f) + 0.5f);
    }
    if (png_write_rgb8(out, size, size, png, size * 3) != 0) { fprintf(stderr, "cannot write %s\n", out); return 1; }
    printf("wrote %s\n", out);
    free(img); free(png); free(pts); free(F); free(depth);
    rad_hierarchical_destroy(h);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(scene);
    return 0;
}
