/* lights.c - lights given on the command line (--sun, --sky, --point, --spot, --area), added to
   the scene file's own lights by every command that lights a scene (render, trace, bake).

   One option per light, repeatable; numbers separated by commas, parts by colons; an RGB is
   three numbers or one (grey). Units follow the library's rad_light (>>api_light) except the
   sky, which is given as the radiance one sees in it:
     --sun DIR:RGB              directional light travelling along DIR (0,-1,0: straight down);
                                RGB = irradiance in W/m^2 on a surface facing it
     --sky RGB                  constant sky of radiance RGB (W m^-2 sr^-1) in every direction
                                not blocked by the scene; an unoccluded surface receives pi RGB
                                (the library's exitance E_0 = pi RGB)
     --point POS:RGB            point light; RGB = intensity in W/sr (irradiance I / d^2 at
                                distance d, quadratic falloff)
     --spot POS:DIR:ANGLES:RGB  spot light at POS aimed along DIR; ANGLES = OUTER or
                                INNER,OUTER half-angles in degrees (full intensity inside
                                INNER, smoothstep to 0 at OUTER; one angle: a hard edge);
                                RGB = intensity in W/sr on the axis
     --env FILE[:SCALE[:ROT]]   environment map: an equirectangular Radiance .hdr (stb_image)
                                or .exr (tinyexr) of radiance in W m^-2 sr^-1, times SCALE
                                (default 1), turned ROT degrees about +Y (+X towards +Z);
                                +Y is up, the top row the zenith, the left edge looks along
                                +X (the library's RAD_LIGHT_ENVIRONMENT convention)
     --sky-model preetham:T[:SCALE] --sun-time LAT:DAY:HOUR
                                Preetham's clear sky of turbidity T (1.7 .. 10) as a 256 x 128
                                environment map, plus its sun as a directional light, for the
                                sun at latitude LAT degrees, day of year DAY, local solar time
                                HOUR (rad_sky_preetham, rad_sun_direction: +X east, +Z south);
                                units luminance / 683 (W m^-2 sr^-1 at 683 lm/W), times SCALE
     --area P:U:V:RGB           emissive parallelogram P, P+U, P+U+V, P+V (two triangles of a
                                mesh "area_light_K", albedo 0), emitting radiance RGB
                                (W m^-2 sr^-1) from the side U x V points to: an area light
                                exactly like an emissive triangle of the file
   The analytic lights are appended to tool_scene.lights; the area lights are appended to
   the scene description before rad_scene_create (tool_open_world_lit), so every method,
   the path tracer and the bake see the same lights. */
#include "tool.h"
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LIGHTS_DEG 0.017453292519943295

const char *tool_light_help(void)
{
    return "lights added to the scene's own (repeatable; RGB is R,G,B or one grey value, each 0 to 1e20):\n"
           "  --sun DIR:RGB      directional light travelling along DIR (0,-1,0: down); RGB = irradiance\n"
           "                     in W/m^2 on a surface facing it\n"
           "  --sky RGB          uniform sky of radiance RGB (W/m^2/sr): an unoccluded surface gets pi RGB\n"
           "  --point POS:RGB    point light; RGB = intensity in W/sr (irradiance I/d^2)\n"
           "  --spot POS:DIR:ANGLES:RGB  spot light aimed along DIR; ANGLES = OUTER or INNER,OUTER\n"
           "                     half-angles in degrees (smooth edge from INNER to OUTER); RGB = intensity W/sr\n"
           "  --area P:U:V:RGB   emissive parallelogram P, P+U, P+U+V, P+V of radiance RGB (W/m^2/sr),\n"
           "                     emitting towards U x V (an area light like an emissive triangle)\n"
           "  --env FILE[:SCALE[:ROT]]  environment map: equirectangular .hdr or .exr of radiance\n"
           "                     (W/m^2/sr) times SCALE, turned ROT degrees about +Y; +Y up, top row =\n"
           "                     zenith, left edge looks along +X, a quarter across along +Z\n"
           "  --sky-model preetham:T[:SCALE] --sun-time LAT:DAY:HOUR  Preetham's clear sky (turbidity\n"
           "                     T in 1.7..10) and its sun for latitude LAT, day of year DAY, solar time\n"
           "                     HOUR (+X east, +Z south); units: luminance / 683 lm/W, times SCALE\n";
}

/* 'count' comma-separated finite numbers filling the whole of [s, s + len); 0 on success */
static int parse_numbers(const char *s, size_t len, float *out, int count)
{
    char buf[256], *p, *end;
    int i;
    if (len == 0 || len >= sizeof buf) return 1;
    memcpy(buf, s, len);
    buf[len] = 0;
    p = buf;
    for (i = 0; i < count; ++i) {
        double v;
        if (i > 0) {
            if (*p != ',') return 1;
            ++p;
        }
        if (!*p || *p == ',' || *p == ' ') return 1;
        v = strtod(p, &end);
        if (end == p || !(v == v) || fabs(v) > 1e30) return 1;
        out[i] = (float)v;
        p = end;
    }
    return *p != 0;
}

/* An RGB: three numbers or one grey value, each in [0, TOOL_MAX_LIGHT_VALUE]; 0 on success,
   1 when not numbers >= 0, 2 when one is beyond the limit */
static int parse_rgb(const char *s, size_t len, float *rgb)
{
    if (parse_numbers(s, len, rgb, 3) != 0) {
        if (parse_numbers(s, len, rgb, 1) != 0) return 1;
        rgb[1] = rgb[2] = rgb[0];
    }
    if (!(rgb[0] >= 0.0f && rgb[1] >= 0.0f && rgb[2] >= 0.0f)) return 1;
    return rgb[0] > TOOL_MAX_LIGHT_VALUE || rgb[1] > TOOL_MAX_LIGHT_VALUE || rgb[2] > TOOL_MAX_LIGHT_VALUE ? 2 : 0;
}

/* "DIR is too long (...)" into buf, or NULL when v is fine (tool_vector_problem) */
static const char *vector_why(const float *v, int direction, const char *name, char *buf, size_t cap)
{
    const char *w = tool_vector_problem(v, direction);
    if (!w) return NULL;
    snprintf(buf, cap, "%s %s", name, w);
    return buf;
}

static float len3(const float *v) { return sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

/* splits text at ':' into at most 'max' parts; the number of parts */
static int split_parts(const char *text, const char **part, size_t *plen, int max)
{
    int n = 0;
    const char *p = text;
    for (;;) {
        const char *c = strchr(p, ':');
        if (n == max) return max + 1;
        part[n] = p;
        plen[n] = c ? (size_t)(c - p) : strlen(p);
        ++n;
        if (!c) return n;
        p = c + 1;
    }
}

void tool_lights_free(tool_lights *L)
{
    uint32_t i;
    if (!L) return;
    for (i = 0; i < L->env_count; ++i) {
        rad_environment_destroy(L->envs[i]);
        tool_image_free(&L->env_images[i]);
    }
    free(L->envs);
    free(L->env_images);
    free(L->lights);
    free(L->areas);
    memset(L, 0, sizeof *L);
}

/* keeps env (and the image it borrows) in L and appends a light of 'scale' that uses it */
static int lights_keep_env(const char *cmd, tool_lights *L, rad_environment *env, tool_image *img, float scale)
{
    rad_environment **e = (rad_environment **)realloc(L->envs, sizeof *e * (L->env_count + 1u));
    tool_image *im;
    rad_light *g;
    if (e) L->envs = e;
    im = e ? (tool_image *)realloc(L->env_images, sizeof *im * (L->env_count + 1u)) : NULL;
    if (im) L->env_images = im;
    g = im ? (rad_light *)realloc(L->lights, sizeof *g * (L->count + 1u)) : NULL;
    if (!g) {
        fprintf(stderr, "rad %s: out of memory\n", cmd);
        rad_environment_destroy(env);
        tool_image_free(img);
        return 2;
    }
    L->lights = g;
    L->envs[L->env_count] = env;
    L->env_images[L->env_count++] = *img;
    memset(&L->lights[L->count], 0, sizeof L->lights[0]);
    L->lights[L->count].type = RAD_LIGHT_ENVIRONMENT;
    L->lights[L->count].color[0] = L->lights[L->count].color[1] = L->lights[L->count].color[2] = scale;
    L->lights[L->count++].environment = env;
    return 1;
}

static int lights_has_ext(const char *path, const char *ext)
{
    size_t n = strlen(path), m = strlen(ext), i;
    if (n < m) return 0;
    for (i = 0; i < m; ++i)
        if (tolower((unsigned char)path[n - m + i]) != ext[i]) return 0;
    return 1;
}

/* --env FILE[:SCALE[:ROT]]: the trailing ':'-parts that are numbers are SCALE and ROT */
static int lights_env_option(const char *cmd, const char *text, tool_lights *L)
{
    char path[4096], err[512];
    float num[2] = { 1.0f, 0.0f }, v;
    int nn = 0, k;
    size_t len = strlen(text);
    tool_image img;
    rad_environment_desc d;
    rad_environment *env = NULL;
    rad_result r;
    if (len >= sizeof path) {
        fprintf(stderr, "rad %s: --env: the path is too long\n", cmd);
        return 2;
    }
    memcpy(path, text, len + 1);
    while (nn < 2) {
        char *colon = strrchr(path, ':');
        if (!colon || parse_numbers(colon + 1, strlen(colon + 1), &v, 1)) break;
        for (k = nn; k > 0; --k) num[k] = num[k - 1];
        num[0] = v;
        ++nn;
        *colon = '\0';
    }
    if (nn == 1) num[1] = 0.0f; /* parsed right to left: one number is SCALE */
    if (!(num[0] >= 0.0f)) {
        fprintf(stderr, "rad %s: bad --env '%s': SCALE must be a number >= 0\n", cmd, text);
        return 2;
    }
    if (lights_has_ext(path, ".exr")) k = tool_image_read_exr(path, &img, err, sizeof err);
    else if (lights_has_ext(path, ".hdr") || lights_has_ext(path, ".rgbe")) k = tool_image_read_hdr(path, &img, err, sizeof err);
    else {
        fprintf(stderr, "rad %s: bad --env '%s': the map must be a Radiance .hdr or an OpenEXR .exr\n", cmd, text);
        return 2;
    }
    if (k != 0) {
        fprintf(stderr, "rad %s: --env: %s\n", cmd, err);
        return 2;
    }
    memset(&d, 0, sizeof d);
    d.pixels = img.rgb, d.width = (uint32_t)img.width, d.height = (uint32_t)img.height;
    d.rotation = (float)(num[1] * LIGHTS_DEG);
    r = rad_environment_create(&d, NULL, &env);
    if (r != RAD_SUCCESS) {
        fprintf(stderr, "rad %s: --env '%s': %s (a NaN, Inf or negative pixel, or a bad size)\n", cmd, path, rad_result_string(r));
        tool_image_free(&img);
        return 2;
    }
    return lights_keep_env(cmd, L, env, &img, num[0]);
}

/* --sky-model and --sun-time both given: the sky map and the sun */
static int lights_make_sky(const char *cmd, tool_lights *L)
{
    tool_image img;
    rad_light sun;
    rad_environment_desc d;
    rad_environment *env = NULL;
    float dir[3];
    rad_result r;
    int k;
    if (rad_sun_direction(L->sun_time[0], L->sun_time[1], L->sun_time[2], dir) != RAD_SUCCESS) {
        fprintf(stderr, "rad %s: bad --sun-time: LAT in [-90, 90], DAY in [1, 366], HOUR in [0, 24]\n", cmd);
        return 2;
    }
    if (!(dir[1] > 0.0f)) {
        fprintf(stderr, "rad %s: --sun-time %g:%g:%g puts the sun below the horizon (elevation %.1f degrees): the sky model "
                "holds in daylight only\n", cmd, (double)L->sun_time[0], (double)L->sun_time[1], (double)L->sun_time[2],
                asin((double)dir[1]) / LIGHTS_DEG);
        return 2;
    }
    if (tool_image_alloc(&img, 256, 128) != 0) {
        fprintf(stderr, "rad %s: out of memory\n", cmd);
        return 2;
    }
    r = rad_sky_preetham(L->sky_turbidity, dir, 256, 128, img.rgb, &sun, NULL);
    if (r == RAD_SUCCESS) {
        size_t i;
        for (i = 0; i < 3u * 256u * 128u; ++i) img.rgb[i] *= L->sky_scale;
        for (k = 0; k < 3; ++k) sun.color[k] *= L->sky_scale;
        memset(&d, 0, sizeof d);
        d.pixels = img.rgb, d.width = 256, d.height = 128;
        r = rad_environment_create(&d, NULL, &env);
    }
    if (r != RAD_SUCCESS) {
        fprintf(stderr, "rad %s: --sky-model: %s\n", cmd, rad_result_string(r));
        tool_image_free(&img);
        return 2;
    }
    fprintf(stderr, "rad %s: sky model preetham turbidity %g, sun %.1f degrees up at azimuth %.1f (from north, east "
            "positive), sun irradiance %g,%g,%g\n", cmd, (double)L->sky_turbidity, asin((double)dir[1]) / LIGHTS_DEG,
            atan2((double)dir[0], -(double)dir[2]) / LIGHTS_DEG, (double)sun.color[0], (double)sun.color[1], (double)sun.color[2]);
    if ((k = lights_keep_env(cmd, L, env, &img, 1.0f)) != 1) return k;
    {
        rad_light *g = (rad_light *)realloc(L->lights, sizeof *g * (L->count + 1u));
        if (!g) { fprintf(stderr, "rad %s: out of memory\n", cmd); return 2; }
        L->lights = g;
        L->lights[L->count++] = sun;
    }
    return 1;
}

int tool_light_option(const char *cmd, int argc, char **argv, int *a, tool_lights *L)
{
    static const char *const names[] = {"--sun", "--sky", "--point", "--spot", "--area"};
    static const char *const forms[] = {"DIR:RGB, e.g. 0.3,-1,0.2:5", "RGB, e.g. 0.4,0.5,0.8", "POS:RGB, e.g. 0,1.5,0:10",
                                        "POS:DIR:ANGLES:RGB, e.g. 0,1.9,0:0,-1,0:20,30:10",
                                        "P:U:V:RGB, e.g. -0.2,1.9,-0.2:0.4,0,0:0,0,0.4:15"};
    static const int nparts[] = {2, 1, 2, 4, 4};
    const char *opt = argv[*a], *text, *part[5], *why = NULL;
    char buf[160];
    size_t plen[5];
    int i, n, rgb;
    rad_light li;
    tool_area_light al;
    if (!strcmp(opt, "--env")) {
        if (*a + 1 >= argc) {
            fprintf(stderr, "rad %s: --env needs a value (FILE.hdr[:SCALE[:ROT_DEGREES]], e.g. sky.hdr:1:90)\n", cmd);
            return 2;
        }
        return lights_env_option(cmd, argv[++*a], L);
    }
    if (!strcmp(opt, "--sky-model") || !strcmp(opt, "--sun-time")) {
        int model = !strcmp(opt, "--sky-model"), np;
        float num[3];
        const char *v;
        if (*a + 1 >= argc) {
            fprintf(stderr, "rad %s: %s needs a value (%s)\n", cmd, opt, model ? "preetham:T[:SCALE], e.g. preetham:3" :
                    "LAT:DAY:HOUR, e.g. 48.1:172:15.5");
            return 2;
        }
        v = argv[++*a];
        if (L->sky_parts & (model ? 1u : 2u)) {
            fprintf(stderr, "rad %s: %s given twice (one sky model per command)\n", cmd, opt);
            return 2;
        }
        if (model) {
            np = split_parts(v, part, plen, 3);
            if (np < 2 || plen[0] != 8 || strncmp(v, "preetham", 8) || parse_numbers(part[1], plen[1], num, 1) ||
                (np == 3 && parse_numbers(part[2], plen[2], num + 1, 1))) {
                fprintf(stderr, "rad %s: bad --sky-model '%s' (want preetham:T[:SCALE], e.g. preetham:3)\n", cmd, v);
                return 2;
            }
            if (np == 2) num[1] = 1.0f;
            if (!(num[0] >= 1.7f && num[0] <= 10.0f) || !(num[1] >= 0.0f)) {
                fprintf(stderr, "rad %s: bad --sky-model '%s': turbidity T in [1.7, 10], SCALE >= 0\n", cmd, v);
                return 2;
            }
            L->sky_turbidity = num[0], L->sky_scale = num[1];
            L->sky_parts |= 1u;
        } else {
            np = split_parts(v, part, plen, 3);
            if (np != 3 || parse_numbers(part[0], plen[0], num, 1) || parse_numbers(part[1], plen[1], num + 1, 1) ||
                parse_numbers(part[2], plen[2], num + 2, 1)) {
                fprintf(stderr, "rad %s: bad --sun-time '%s' (want LAT:DAY:HOUR, e.g. 48.1:172:15.5)\n", cmd, v);
                return 2;
            }
            memcpy(L->sun_time, num, sizeof num);
            L->sky_parts |= 2u;
        }
        return L->sky_parts == 3u ? lights_make_sky(cmd, L) : 1;
    }
    for (i = 0; i < 5; ++i)
        if (!strcmp(opt, names[i])) break;
    if (i == 5) return 0;
    if (*a + 1 >= argc) {
        fprintf(stderr, "rad %s: %s needs a value (%s)\n", cmd, opt, forms[i]);
        return 2;
    }
    text = argv[++*a];
    memset(&li, 0, sizeof li);
    memset(&al, 0, sizeof al);
    li.falloff = RAD_FALLOFF_QUADRATIC;
    n = split_parts(text, part, plen, 4);
    if (n != nparts[i]) {
        why = "wrong number of ':'-separated parts";
    } else if ((rgb = parse_rgb(part[n - 1], plen[n - 1], i == 4 ? al.radiance : li.color)) != 0) {
        why = rgb == 1 ? "the RGB is not one or three numbers >= 0"
                       : "the RGB has a value above 1e20, which overflows the light's transport in float";
    } else switch (i) {
    case 0:
        li.type = RAD_LIGHT_DIRECTIONAL;
        if (parse_numbers(part[0], plen[0], li.direction, 3)) why = "DIR is not three numbers";
        else why = vector_why(li.direction, 1, "DIR", buf, sizeof buf);
        break;
    case 1:
        li.type = RAD_LIGHT_SKY;
        for (n = 0; n < 3; ++n) li.color[n] *= 3.14159265358979323846f; /* radiance to exitance E_0 */
        break;
    case 2:
        li.type = RAD_LIGHT_POINT;
        if (parse_numbers(part[0], plen[0], li.position, 3)) why = "POS is not three numbers";
        break;
    case 3: {
        float ang[2];
        li.type = RAD_LIGHT_SPOT;
        if (parse_numbers(part[0], plen[0], li.position, 3)) why = "POS is not three numbers";
        else if (parse_numbers(part[1], plen[1], li.direction, 3)) why = "DIR is not three numbers";
        else if ((why = vector_why(li.direction, 1, "DIR", buf, sizeof buf)) != NULL) break;
        else if (parse_numbers(part[2], plen[2], ang, 2) == 0) {
            if (!(ang[0] >= 0.0f && ang[1] > ang[0] && ang[1] <= 180.0f)) why = "ANGLES must be 0 <= INNER < OUTER <= 180 degrees";
            li.inner_angle = (float)(ang[0] * LIGHTS_DEG), li.outer_angle = (float)(ang[1] * LIGHTS_DEG);
        } else if (parse_numbers(part[2], plen[2], ang, 1) == 0) {
            if (!(ang[0] > 0.0f && ang[0] <= 180.0f)) why = "ANGLES: OUTER must be in (0, 180] degrees";
            li.inner_angle = li.outer_angle = (float)(ang[0] * LIGHTS_DEG);
        } else why = "ANGLES is not OUTER or INNER,OUTER in degrees";
        break;
    }
    default: {
        float c[3];
        if (parse_numbers(part[0], plen[0], al.p, 3) || parse_numbers(part[1], plen[1], al.u, 3) ||
            parse_numbers(part[2], plen[2], al.v, 3)) {
            why = "P, U and V must be three numbers each";
            break;
        }
        c[0] = al.u[1] * al.v[2] - al.u[2] * al.v[1];
        c[1] = al.u[2] * al.v[0] - al.u[0] * al.v[2];
        c[2] = al.u[0] * al.v[1] - al.u[1] * al.v[0];
        /* U x V is the light's normal: it must normalise in float as a direction does */
        if (tool_vector_problem(c, 1)) why = !(len3(c) > 0.0f) ? "U and V span no area" : "U and V: their area (|U x V|) does not fit a float";
        break;
    }
    }
    if (why) {
        fprintf(stderr, "rad %s: bad %s '%s': %s (want %s)\n", cmd, opt, text, why, forms[i]);
        return 2;
    }
    if (i == 4) {
        tool_area_light *g = (tool_area_light *)realloc(L->areas, sizeof *g * (L->area_count + 1u));
        if (!g) { fprintf(stderr, "rad %s: out of memory\n", cmd); return 2; }
        L->areas = g;
        L->areas[L->area_count++] = al;
    } else {
        rad_light *g = (rad_light *)realloc(L->lights, sizeof *g * (L->count + 1u));
        if (!g) { fprintf(stderr, "rad %s: out of memory\n", cmd); return 2; }
        L->lights = g;
        L->lights[L->count++] = li;
    }
    return 1;
}

/* the scene description with the area lights appended (meshes, materials, names) */
typedef struct lights_storage {
    rad_mesh_desc *meshes;
    rad_material *materials;
    const char **material_names;
    float *positions;   /* 12 per area light */
    char *names;        /* 32 per area light: mesh names, then material names */
} lights_storage;

static void storage_free(lights_storage *s)
{
    if (!s) return;
    free(s->meshes);
    free(s->materials);
    free((void *)s->material_names);
    free(s->positions);
    free(s->names);
    free(s);
}

void tool_lights_release(void *storage) { storage_free((lights_storage *)storage); }

/* appends the area lights to f->desc; the arrays are kept in *out (NULL when none) */
static int add_areas(tool_scene *f, const tool_lights *L, lights_storage **out)
{
    lights_storage *s;
    uint32_t nm = f->desc.mesh_count, nmat = f->desc.material_count, i, k;
    static const uint32_t quad[6] = {0, 1, 2, 0, 2, 3};
    *out = NULL;
    if (!L || !L->area_count) return 0;
    s = (lights_storage *)calloc(1, sizeof *s);
    if (!s) return 1;
    s->meshes = (rad_mesh_desc *)calloc((size_t)nm + L->area_count, sizeof *s->meshes);
    s->materials = (rad_material *)calloc((size_t)nmat + L->area_count, sizeof *s->materials);
    s->material_names = (const char **)calloc((size_t)nmat + L->area_count, sizeof(char *));
    s->positions = (float *)calloc((size_t)L->area_count * 12u, sizeof(float));
    s->names = (char *)calloc((size_t)L->area_count * 2u, 32);
    if (!s->meshes || !s->materials || !s->material_names || !s->positions || !s->names) {
        storage_free(s);
        return 1;
    }
    if (nm) memcpy(s->meshes, f->desc.meshes, sizeof *s->meshes * nm);
    if (nmat) memcpy(s->materials, f->desc.materials, sizeof *s->materials * nmat);
    for (i = 0; i < nmat; ++i) s->material_names[i] = f->material_names ? f->material_names[i] : "";
    for (i = 0; i < L->area_count; ++i) {
        const tool_area_light *al = &L->areas[i];
        float *p = s->positions + 12 * (size_t)i;
        char *mesh_name = s->names + 64 * (size_t)i, *mat_name = mesh_name + 32;
        rad_mesh_desc *md = &s->meshes[nm + i];
        rad_material *mt = &s->materials[nmat + i];
        for (k = 0; k < 3; ++k) {
            p[k] = al->p[k];
            p[3 + k] = al->p[k] + al->u[k];
            p[6 + k] = al->p[k] + al->u[k] + al->v[k];
            p[9 + k] = al->p[k] + al->v[k];
            mt->emission[k] = al->radiance[k];
        }
        snprintf(mesh_name, 32, "area_light_%u", i + 1u);
        snprintf(mat_name, 32, "area_light_%u", i + 1u);
        md->name = mesh_name;
        md->positions = p;
        md->vertex_count = 4;
        md->indices = quad;
        md->triangle_count = 2;
        md->material = nmat + i;
        s->material_names[nmat + i] = mat_name;
    }
    f->desc.meshes = s->meshes;
    f->desc.mesh_count = nm + L->area_count;
    f->desc.materials = s->materials;
    f->desc.material_count = nmat + L->area_count;
    f->material_names = s->material_names;
    *out = s;
    return 0;
}

int tool_add_lights(const char *cmd, tool_scene *f, const tool_lights *L, void **storage)
{
    lights_storage *s = NULL;
    uint32_t i, counts[5] = {0, 0, 0, 0, 0};
    *storage = NULL;
    if (L && (L->sky_parts == 1u || L->sky_parts == 2u)) {
        fprintf(stderr, "rad %s: %s needs %s too\n", cmd, L->sky_parts == 1u ? "--sky-model" : "--sun-time",
                L->sky_parts == 1u ? "--sun-time LAT:DAY:HOUR" : "--sky-model preetham:T");
        return 1;
    }
    if (!L || (!L->count && !L->area_count)) return 0;
    if (add_areas(f, L, &s)) {
        fprintf(stderr, "rad %s: out of memory for the area lights\n", cmd);
        return 1;
    }
    if (L->count) {
        rad_light *g = (rad_light *)realloc(f->lights, sizeof *g * ((size_t)f->light_count + L->count));
        if (!g) {
            storage_free(s);
            fprintf(stderr, "rad %s: out of memory for the lights\n", cmd);
            return 1;
        }
        memcpy(g + f->light_count, L->lights, sizeof *g * L->count);
        f->lights = g;
        f->light_count += L->count;
    }
    for (i = 0; i < L->count; ++i)
        if ((int)L->lights[i].type >= 0 && (int)L->lights[i].type < 5) counts[L->lights[i].type]++;
    fprintf(stderr, "rad %s: lights from the command line: %u sun, %u sky, %u environment, %u point, %u spot, %u area\n",
            cmd, counts[RAD_LIGHT_DIRECTIONAL], counts[RAD_LIGHT_SKY], counts[RAD_LIGHT_ENVIRONMENT], counts[RAD_LIGHT_POINT],
            counts[RAD_LIGHT_SPOT], L->area_count);
    *storage = s;
    return 0;
}

uint64_t tool_lights_hash(const rad_light *lights, uint32_t count, uint64_t h)
{
    uint32_t i;
    /* field by field: the structs are memset, but the hash should not depend on that */
    for (i = 0; i < count; ++i) {
        const rad_light *l = &lights[i];
        uint32_t t = (uint32_t)l->type, f = (uint32_t)l->falloff;
        h = rad_hash64(&t, sizeof t, h);
        h = rad_hash64(l->color, sizeof l->color, h);
        h = rad_hash64(l->position, sizeof l->position, h);
        h = rad_hash64(l->direction, sizeof l->direction, h);
        h = rad_hash64(&f, sizeof f, h);
        h = rad_hash64(&l->min_distance, sizeof(float), h);
        h = rad_hash64(&l->inner_angle, sizeof(float), h);
        h = rad_hash64(&l->outer_angle, sizeof(float), h);
        if (l->type == RAD_LIGHT_ENVIRONMENT && l->environment) {
            /* the map through its power and its radiance in 256 fixed directions */
            double pw = rad_environment_power(l->environment);
            uint32_t k;
            h = rad_hash64(&pw, sizeof pw, h);
            for (k = 0; k < 256u; ++k) {
                float z = 1.0f - (2.0f * (float)k + 1.0f) / 256.0f, r = sqrtf(1.0f - z * z), ph = 2.39996323f * (float)k;
                float dir[3], rgb[3];
                dir[0] = r * cosf(ph), dir[1] = z, dir[2] = r * sinf(ph);
                rad_environment_radiance(l->environment, dir, rgb);
                h = rad_hash64(rgb, sizeof rgb, h);
            }
        }
    }
    return h;
}
