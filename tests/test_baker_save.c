/* test_baker_save.c - a rad_baker_result saved and loaded (SAVE AND LOAD in >>api_bake): for
   bakes with two light groups, vertices, a lightmap and probes (a sky layer set, the RGB9E5
   planes, the packed planes alone, band-4 probes, the SH lightmap, virtual patches), the
   loaded result holds every array of the baked one bit for bit, its outputs mixed again equal
   the bake's, and the same group colours and sky mix to the same bits; a loaded result saves
   to the same bytes, matches its scene and not another, is refused by rad_baker_irradiance,
   and a runtime over it gives the frames of a runtime over the bake. Refused with the specific
   error, never a crash: every prefix of a file (a coarse sweep), a flipped byte, bytes off an
   8-byte boundary, a wrong
   container or layout version, a section whose count or element size disagrees with the
   metadata, a missing section, a NaN, a bad probe state or index, a classic bake, and a few
   hundred random byte flips (raw, and behind valid checksums). Included by test_main.c after
   the implementation: every name is static and prefixed bs_. */
#include "fixtures.h"

/* An open corner: a lightmapped floor (2 x 2) and two walls, two point lights (groups 0, 1). */
typedef struct bs_scene {
    lm_soup floor, walls;
    rad_mesh_desc meshes[2];
    rad_material mat;
    rad_baker_light bl[2];
    rad_probe_options po;
    rad_lightmap_gather_options go;
    rad_baker_desc d;
    rad_baker_options o;
} bs_scene;

enum { BS_SKY = 1, BS_RGB9E5 = 2, BS_RGB9E5_ONLY = 4, BS_BAND4 = 8, BS_SH = 16, BS_VP = 32 };

static void bs_corner(bs_scene *s, uint32_t kind)
{
    const float O[3] = { 0, 0, 0 }, X2[3] = { 2, 0, 0 }, Y[3] = { 0, 1, 0 }, Z2[3] = { 0, 0, 2 };
    const float uv0[2] = { 0.02f, 0.02f }, ua[2] = { 0.0f, 0.96f }, ub[2] = { 0.96f, 0.0f };
    int k;
    memset(s, 0, sizeof *s);
    lm_quad(&s->floor, O, Z2, X2, uv0, ua, ub);
    lm_quad(&s->walls, O, X2, Y, NULL, NULL, NULL);
    lm_quad(&s->walls, O, Y, Z2, NULL, NULL, NULL);
    lm_mesh(&s->meshes[0], &s->floor, 0, 1);
    lm_mesh(&s->meshes[1], &s->walls, 0, 0);
    s->mat.albedo[0] = 0.75f, s->mat.albedo[1] = 0.6f, s->mat.albedo[2] = 0.45f;
    for (k = 0; k < 2; ++k) {
        s->bl[k].light.type = RAD_LIGHT_POINT;
        s->bl[k].light.position[0] = k ? 0.4f : 1.2f, s->bl[k].light.position[1] = 0.6f, s->bl[k].light.position[2] = 0.7f;
        s->bl[k].light.color[0] = s->bl[k].light.color[1] = s->bl[k].light.color[2] = 1.0f;
        s->bl[k].group = (uint32_t)k;
    }
    s->d.scene.meshes = s->meshes;
    s->d.scene.mesh_count = 2;
    s->d.scene.materials = &s->mat;
    s->d.scene.material_count = 1;
    s->d.lights = s->bl;
    s->d.light_count = 2;
    s->d.outputs = RAD_BAKER_VERTEX | RAD_BAKER_LIGHTMAP | RAD_BAKER_PROBES;
    s->d.lightmap_width = 16;
    s->d.lightmap_height = 12;
    s->d.probe_spacing = 0.75f; /* a grid */
    s->o.method = kind & BS_VP ? RAD_BAKER_VIRTUAL_PATCHES : RAD_BAKER_CLASSIC;
    s->o.patches = 40;
    s->o.vp_resolution = 4;
    s->o.ff_samples = 2;
    s->o.bounces = 4;
    s->o.light_samples = 4;
    s->o.lightmap_samples = 1;
    if (kind & BS_SKY) s->o.sky_bands = 2, s->o.sky_rays = 8;
    if (kind & BS_RGB9E5) s->d.lightmap_flags |= RAD_BAKER_LIGHTMAP_RGB9E5;
    if (kind & BS_RGB9E5_ONLY) s->d.lightmap_flags |= RAD_BAKER_LIGHTMAP_RGB9E5_ONLY;
    if (kind & BS_BAND4) {
        rad_probe_options_default(&s->po);
        s->po.flags |= RAD_PROBES_BAND4;
        s->d.probe_options = &s->po;
    }
    if (kind & BS_SH) {
        rad_lightmap_gather_options_default(&s->go);
        s->go.encoding = RAD_LIGHTMAP_SH_L1;
        s->d.lightmap_gather = &s->go;
    }
}

/* two arrays of n bytes equal (both NULL, or both there and the same bits) */
static int bs_same(const void *a, const void *b, size_t n)
{
    if (!a || !b) return a == b;
    return memcmp(a, b, n) == 0;
}

/* every array and field of A in B, bit for bit */
static void bs_compare(const rad_baker_result *A, const rad_baker_result *B)
{
    size_t P = (size_t)A->group_count + A->sky_count, nv = 3 * (size_t)A->vertex_count;
    size_t texels = (size_t)A->lightmap_width * A->lightmap_height, nl = A->lightmap_channels * texels;
    size_t np = 27 * (size_t)A->probe_count;
    CHECK(A->method == B->method && A->patch_count == B->patch_count && A->vp_resolution == B->vp_resolution);
    CHECK(A->group_count == B->group_count && A->sky_count == B->sky_count && A->mesh_count == B->mesh_count);
    CHECK(A->vertex_count == B->vertex_count && A->lightmap_width == B->lightmap_width);
    CHECK(A->lightmap_height == B->lightmap_height && A->lightmap_channels == B->lightmap_channels);
    CHECK(A->probe_count == B->probe_count && memcmp(A->probe_grid, B->probe_grid, sizeof A->probe_grid) == 0);
    CHECK(memcmp(A->probe_origin, B->probe_origin, sizeof A->probe_origin) == 0 && A->probe_spacing == B->probe_spacing);
    CHECK(strcmp(A->reason, B->reason) == 0 && strcmp(A->plan.reason, B->plan.reason) == 0);
    CHECK(A->estimated_bytes == B->estimated_bytes && A->estimated_seconds == B->estimated_seconds);
    CHECK(A->plan.method == B->plan.method && A->plan.needed_resolution == B->plan.needed_resolution);
    CHECK(A->plan.estimated_seconds == B->plan.estimated_seconds && A->plan.budget_limited == B->plan.budget_limited);
    CHECK(memcmp(&A->lightmap_seams, &B->lightmap_seams, sizeof A->lightmap_seams) == 0);
    CHECK(A->scene_hash[0] == B->scene_hash[0] && A->scene_hash[1] == B->scene_hash[1] && A->scene_hash[0] != 0);
    CHECK(bs_same(A->vertex_first, B->vertex_first, ((size_t)A->mesh_count + 1) * 4));
    CHECK(bs_same(A->vertex_layers, B->vertex_layers, P * nv * 4));
    CHECK(bs_same(A->vertex, B->vertex, nv * 4));
    CHECK(bs_same(A->lightmap_layers, B->lightmap_layers, P * nl * 4));
    CHECK(bs_same(A->lightmap, B->lightmap, nl * 4));
    CHECK(bs_same(A->lightmap_flags, B->lightmap_flags, texels));
    CHECK(bs_same(A->lightmap_rgb9e5, B->lightmap_rgb9e5, A->group_count * texels * 4));
    CHECK(bs_same(A->probe_positions, B->probe_positions, 3 * (size_t)A->probe_count * 4));
    CHECK(bs_same(A->probe_states, B->probe_states, A->probe_count));
    CHECK(bs_same(A->probe_layers, B->probe_layers, P * np * 4));
    CHECK(bs_same(A->probes, B->probes, np * 4));
    CHECK(bs_same(A->probe_band4_layers, B->probe_band4_layers, A->group_count * np * 4));
    CHECK(bs_same(A->probe_band4, B->probe_band4, np * 4));
}

/* B saved again gives the n bytes of f (the same content: a flip only in padding) */
static int bs_resaves(const rad_baker_result *B, const void *f, size_t n)
{
    void *g = NULL;
    size_t m = 0;
    int same = rad_baker_result_save_memory(B, NULL, &g, &m) == RAD_SUCCESS && m == n && memcmp(f, g, n) == 0;
    rad_free_buffer(g, NULL);
    return same;
}

static void bs_log_quiet(void *user, rad_log_level level, const char *msg)
{
    (void)user, (void)level, (void)msg;
}

/* the last error message, for the checks that it names the section */
static char bs_last[512];
static void bs_log_keep(void *user, rad_log_level level, const char *msg)
{
    (void)user;
    if (level == RAD_LOG_ERROR) snprintf(bs_last, sizeof bs_last, "%s", msg);
}

static void bs_test_roundtrip(void)
{
    static const uint32_t kinds[] = { BS_SKY, BS_RGB9E5 | BS_BAND4, BS_RGB9E5_ONLY, BS_SH, BS_VP };
    size_t q;
    for (q = 0; q < sizeof kinds / sizeof kinds[0]; ++q) {
        bs_scene s;
        rad_baker_result *A = NULL, *B = NULL;
        void *f1 = NULL, *f2 = NULL;
        size_t n1 = 0, n2 = 0;
        rad_context ctx;
        float g[6] = { 0.5f, 1.0f, 2.0f, 1.5f, 0.25f, 0.0f }, sh[12];
        int k;
        memset(&ctx, 0, sizeof ctx);
        ctx.log = bs_log_keep;
        bs_corner(&s, kinds[q]);
        CHECK_OK(rad_baker_run(&s.d, &s.o, NULL, &A));
        if (!A) continue;
        CHECK_OK(rad_baker_result_save_memory(A, NULL, &f1, &n1));
        CHECK_OK(rad_baker_result_load_memory(f1, n1, NULL, &B));
        if (!B) goto next;
        bs_compare(A, B);
        CHECK(!B->kept && !B->solution && rad_baker_result_lightmap(B) == NULL);
        /* loaded and saved again: the same bytes */
        CHECK_OK(rad_baker_result_save_memory(B, NULL, &f2, &n2));
        CHECK(n1 == n2 && f2 && memcmp(f1, f2, n1) == 0);
        /* the same colours (and sky) mix to the same bits */
        CHECK_OK(rad_baker_mix(A, g, NULL));
        CHECK_OK(rad_baker_mix(B, g, NULL));
        bs_compare(A, B);
        if (A->sky_count) {
            for (k = 0; k < 12; ++k) sh[k] = 0.4f - 0.07f * (float)k;
            CHECK_OK(rad_baker_mix_sky(A, g, sh, NULL));
            CHECK_OK(rad_baker_mix_sky(B, g, sh, NULL));
            bs_compare(A, B);
        }
        if (A->lightmap_rgb9e5) {
            size_t texels = (size_t)A->lightmap_width * A->lightmap_height;
            float *x = (float *)malloc(2 * 3 * texels * sizeof(float));
            if (x) {
                CHECK_OK(rad_baker_mix_layers_rgb9e5(A->lightmap_rgb9e5, A->group_count, texels, g, x, NULL));
                CHECK_OK(rad_baker_mix_layers_rgb9e5(B->lightmap_rgb9e5, B->group_count, texels, g, x + 3 * texels, NULL));
                CHECK(memcmp(x, x + 3 * texels, 3 * texels * sizeof(float)) == 0);
            }
            free(x);
        }
        {
            /* no solution kept: rad_baker_irradiance says so */
            rad_hit h;
            float p[3] = { 1, 0, 1 }, nrm[3] = { 0, 1, 0 }, out[3];
            memset(&h, 0, sizeof h);
            bs_last[0] = '\0';
            CHECK(rad_baker_irradiance(B, &h, p, nrm, 1, out, &ctx) == RAD_ERROR_INVALID_ARGUMENT);
            CHECK(strstr(bs_last, "RAD_BAKER_SOLUTION") != NULL);
        }
        {
            /* its scene matches, another (a moved light is not geometry: a moved wall is) does not */
            rad_scene *sc = NULL;
            CHECK_OK(rad_scene_create(&s.d.scene, NULL, &sc));
            if (sc) CHECK_OK(rad_baker_result_matches_scene(B, sc, NULL));
            rad_scene_destroy(sc);
            sc = NULL;
            s.walls.pos[1] += 0.01f;
            CHECK_OK(rad_scene_create(&s.d.scene, NULL, &sc));
            bs_last[0] = '\0';
            if (sc) CHECK(rad_baker_result_matches_scene(B, sc, &ctx) == RAD_ERROR_SCENE_MISMATCH);
            CHECK(strstr(bs_last, "geometry") != NULL);
            rad_scene_destroy(sc);
            s.walls.pos[1] -= 0.01f;
        }
    next:
        rad_free_buffer(f1, NULL);
        rad_free_buffer(f2, NULL);
        rad_baker_result_destroy(A);
        rad_baker_result_destroy(B);
    }
}

/* A runtime over a loaded result (built again from the desc, as for a bake without keep)
   gives the frames of a runtime over the bake itself, bit for bit. */
static void bs_test_runtime(void)
{
    bs_scene s;
    rad_baker_result *A = NULL, *B = NULL;
    rad_baker_runtime *ra = NULL, *rb = NULL;
    rad_baker_frame fa, fb;
    void *f = NULL;
    size_t n = 0;
    rad_light moved[2];
    bs_corner(&s, BS_RGB9E5);
    CHECK_OK(rad_baker_run(&s.d, &s.o, NULL, &A));
    if (A) CHECK_OK(rad_baker_result_save_memory(A, NULL, &f, &n));
    if (f) CHECK_OK(rad_baker_result_load_memory(f, n, NULL, &B));
    if (B) CHECK_OK(rad_baker_runtime_create(&s.d, &s.o, A, NULL, NULL, &ra));
    if (B) CHECK_OK(rad_baker_runtime_create(&s.d, &s.o, B, NULL, NULL, &rb));
    if (ra && rb) {
        moved[0] = s.bl[0].light, moved[1] = s.bl[1].light;
        moved[0].position[0] = 0.8f;
        CHECK_OK(rad_baker_runtime_update(ra, moved, 2, 0.0, &fa));
        CHECK_OK(rad_baker_runtime_update(rb, moved, 2, 0.0, &fb));
        CHECK(memcmp(fa.vertex, fb.vertex, 3 * (size_t)A->vertex_count * sizeof(float)) == 0);
        CHECK(memcmp(fa.lightmap, fb.lightmap, 3 * (size_t)A->lightmap_width * A->lightmap_height * sizeof(float)) == 0);
        CHECK(memcmp(fa.probes, fb.probes, 27 * (size_t)A->probe_count * sizeof(float)) == 0);
    }
    rad_baker_runtime_destroy(ra);
    rad_baker_runtime_destroy(rb);
    rad_free_buffer(f, NULL);
    rad_baker_result_destroy(A);
    rad_baker_result_destroy(B);
}

/* the sections of a saved file, copied so that one can be changed and written again (with
   valid checksums) by bs_rewrite */
typedef struct bs_file {
    rad_section s[24];
    void *data[24];
    uint32_t count;
} bs_file;

static int bs_open(const void *buf, size_t n, bs_file *F)
{
    rad_container *ct = NULL;
    uint32_t i;
    memset(F, 0, sizeof *F);
    if (rad_container_create(buf, n, NULL, &ct) != RAD_SUCCESS) return 0;
    F->count = rad_container_section_count(ct);
    if (F->count > 24) F->count = 24;
    for (i = 0; i < F->count; ++i) {
        size_t bytes;
        F->s[i] = *rad_container_section(ct, i);
        bytes = (size_t)(F->s[i].count * F->s[i].elem_size);
        F->data[i] = malloc(bytes ? bytes : 1);
        if (F->data[i] && bytes) memcpy(F->data[i], F->s[i].data, bytes);
        F->s[i].data = F->data[i];
    }
    rad_container_destroy(ct);
    return 1;
}

static void bs_close(bs_file *F)
{
    uint32_t i;
    for (i = 0; i < F->count; ++i) free(F->data[i]);
}

static bs_file *bs_clone(const bs_file *F, bs_file *G)
{
    uint32_t i;
    *G = *F;
    for (i = 0; i < F->count; ++i) {
        size_t bytes = (size_t)(F->s[i].count * F->s[i].elem_size);
        G->data[i] = malloc(bytes ? bytes : 1);
        if (G->data[i] && bytes) memcpy(G->data[i], F->data[i], bytes);
        G->s[i].data = G->data[i];
    }
    return G;
}

static int bs_find(const bs_file *F, uint32_t type)
{
    uint32_t i;
    for (i = 0; i < F->count; ++i)
        if (F->s[i].type == type) return (int)i;
    return -1;
}

/* the file written again and loaded: the loader's result (B destroyed), and the message */
static rad_result bs_reload(const bs_file *F)
{
    rad_context ctx;
    rad_baker_result *B = NULL;
    size_t n = 0;
    void *buf;
    rad_result r;
    memset(&ctx, 0, sizeof ctx);
    ctx.log = bs_log_keep;
    bs_last[0] = '\0';
    if (rad_container_size(F->s, F->count, &n) != RAD_SUCCESS) return RAD_ERROR_SIZE_OVERFLOW;
    buf = malloc(n);
    if (!buf) return RAD_ERROR_OUT_OF_MEMORY;
    r = rad_container_write(F->s, F->count, buf, n);
    if (r == RAD_SUCCESS) r = rad_baker_result_load_memory(buf, n, &ctx, &B);
    rad_baker_result_destroy(B);
    free(buf);
    return r;
}

/* one changed copy of F: the section of 'type', word 'word' (of 4 bytes) set to v, or its
   count changed by dcount; the result and whether the message names 'name' */
static rad_result bs_hostile(const bs_file *F, uint32_t type, int word, uint32_t v, int dcount, const char *name)
{
    bs_file G;
    int i = bs_find(F, type);
    rad_result r;
    if (i < 0) return RAD_ERROR_INVALID_ARGUMENT;
    bs_clone(F, &G);
    if (word >= 0) memcpy((char *)G.data[i] + 4 * word, &v, 4);
    if (dcount > 0) { /* room for the longer section, zeros */
        size_t old = (size_t)(G.s[i].count * G.s[i].elem_size), add = (size_t)dcount * G.s[i].elem_size;
        void *p = realloc(G.data[i], old + add);
        if (!p) {
            bs_close(&G);
            return RAD_ERROR_OUT_OF_MEMORY;
        }
        memset((char *)p + old, 0, add);
        G.data[i] = p;
        G.s[i].data = p;
    }
    G.s[i].count = (uint64_t)((int64_t)G.s[i].count + dcount);
    r = bs_reload(&G);
    if (name && !strstr(bs_last, name)) {
        printf("    the message '%s' does not name %s\n", bs_last, name);
        r = RAD_ERROR_UNAVAILABLE;
    }
    bs_close(&G);
    return r;
}

static void bs_test_refusals(void)
{
    bs_scene s;
    rad_baker_result *A = NULL, *B = NULL;
    void *f = NULL, *cb = NULL;
    unsigned char *buf;
    size_t n = 0, cn = 0, len;
    rad_context quiet;
    bs_file F;
    uint32_t probe_count;
    memset(&quiet, 0, sizeof quiet);
    quiet.log = bs_log_quiet;
    bs_corner(&s, BS_SKY | BS_BAND4);
    s.o.sky_bands = 0;
    CHECK_OK(rad_baker_run(&s.d, &s.o, NULL, &A));
    if (A) CHECK_OK(rad_baker_result_save_memory(A, NULL, &f, &n));
    if (!f) goto done;
    buf = (unsigned char *)malloc(n);
    if (!buf) goto done;
    /* every prefix in a coarse sweep (and the first 200): TRUNCATED (or CORRUPT below the header) */
    for (len = 0; len < n; len += len < 200 ? 1 : n / 61 + 1) {
        rad_result r;
        memcpy(buf, f, len);
        r = rad_baker_result_load_memory(buf, len, &quiet, &B);
        CHECK(r == RAD_ERROR_TRUNCATED || (len < 64 && r == RAD_ERROR_CORRUPT));
        CHECK(B == NULL);
    }
    /* a flipped byte in each section's data, and in the table: CORRUPT (a checksum); in the
       padding between sections (no checksum covers it) the same result */
    for (len = 64; len < n; len += n / 37 + 1) {
        rad_result r;
        memcpy(buf, f, n);
        buf[len] ^= 0x20;
        r = rad_baker_result_load_memory(buf, n, &quiet, &B);
        CHECK(r == RAD_ERROR_CORRUPT || (r == RAD_SUCCESS && bs_resaves(B, f, n)));
        rad_baker_result_destroy(B);
        B = NULL;
    }
    /* another container version (the header's checksum made right): VERSION */
    memcpy(buf, f, n);
    buf[4] = 2;
    {
        /* the header CRC over bytes 0..59 at 60, as >>api_container lays it out */
        uint32_t crc = 0xFFFFFFFFu, k;
        size_t i;
        for (i = 0; i < 60; ++i) {
            crc ^= buf[i];
            for (k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
        }
        crc ^= 0xFFFFFFFFu;
        buf[60] = (unsigned char)crc, buf[61] = (unsigned char)(crc >> 8), buf[62] = (unsigned char)(crc >> 16),
        buf[63] = (unsigned char)(crc >> 24);
    }
    CHECK_RESULT(rad_baker_result_load_memory(buf, n, &quiet, &B), RAD_ERROR_VERSION);
    /* bytes off an 8-byte boundary: the container's rule, INVALID_ARGUMENT */
    {
        unsigned char *odd = (unsigned char *)malloc(n + 8);
        if (odd) {
            memcpy(odd + 1, f, n);
            CHECK_RESULT(rad_baker_result_load_memory(odd + 1, n, &quiet, &B), RAD_ERROR_INVALID_ARGUMENT);
            free(odd);
        }
    }
    free(buf);
    /* NULLs, and a classic bake's file */
    CHECK_RESULT(rad_baker_result_load_memory(NULL, n, &quiet, &B), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_baker_result_load_memory(f, n, &quiet, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_baker_result_save_memory(NULL, &quiet, &cb, &cn), RAD_ERROR_INVALID_ARGUMENT);
    {
        rad_scene *sc = NULL;
        rad_patches *P = NULL;
        CHECK_OK(rad_scene_create(&s.d.scene, NULL, &sc));
        if (sc) CHECK_OK(rad_patches_create(sc, NULL, NULL, &P));
        if (P) CHECK_OK(rad_save_memory(P, NULL, NULL, NULL, NULL, &cb, &cn));
        if (cb) CHECK_RESULT(rad_baker_result_load_memory(cb, cn, &quiet, &B), RAD_ERROR_INVALID_ARGUMENT);
        rad_free_buffer(cb, NULL);
        rad_patches_destroy(P);
        rad_scene_destroy(sc);
    }
    /* hostile sections behind valid checksums: the specific error, the section named */
    if (!bs_open(f, n, &F)) goto done;
    CHECK_OK(bs_hostile(&F, RAD_SECTION_BAKER_INFO, -1, 0, 0, NULL));
    CHECK_RESULT(bs_hostile(&F, RAD_SECTION_BAKER_INFO, 0, 2, 0, "BAKER_INFO"), RAD_ERROR_VERSION);
    CHECK_RESULT(bs_hostile(&F, RAD_SECTION_BAKER_INFO, 1, 7, 0, "BAKER_INFO"), RAD_ERROR_CORRUPT);
    CHECK_RESULT(bs_hostile(&F, RAD_SECTION_BAKER_INFO, 4, 65, 0, "BAKER_INFO"), RAD_ERROR_CORRUPT);
    CHECK_RESULT(bs_hostile(&F, RAD_SECTION_BAKER_INFO, -1, 0, -1, "BAKER_INFO"), RAD_ERROR_CORRUPT);
    /* counts that would allocate gigabytes are refused by the sections' counts first */
    CHECK_RESULT(bs_hostile(&F, RAD_SECTION_BAKER_INFO, 8, 0x40000000u, 0, "BAKER_LIGHTMAP_FLAGS"), RAD_ERROR_SIZE_MISMATCH);
    CHECK_RESULT(bs_hostile(&F, RAD_SECTION_BAKER_INFO, 7, 0xFFFFFFF0u, 0, "BAKER_VERTEX_FIRST"), RAD_ERROR_CORRUPT);
    memcpy(&probe_count, (const char *)F.data[bs_find(&F, RAD_SECTION_BAKER_INFO)] + 4 * 11, 4);
    CHECK_RESULT(bs_hostile(&F, RAD_SECTION_BAKER_INFO, 11, 0xFFFFFFFFu, 0, "BAKER_INFO"), RAD_ERROR_CORRUPT); /* vs its grid */
    CHECK_RESULT(bs_hostile(&F, RAD_SECTION_BAKER_INFO, 12, 0, 0, "BAKER_INFO"), RAD_ERROR_CORRUPT); /* a grid of 0 x 4 x 4 */
    CHECK_RESULT(bs_hostile(&F, RAD_SECTION_BAKER_PROBE_POSITIONS, -1, 0, -1, "BAKER_PROBE_POSITIONS"), RAD_ERROR_SIZE_MISMATCH);
    CHECK_RESULT(bs_hostile(&F, RAD_SECTION_BAKER_LIGHTMAP_LAYERS, -1, 0, -1, "BAKER_LIGHTMAP_LAYERS"), RAD_ERROR_SIZE_MISMATCH);
    CHECK_RESULT(bs_hostile(&F, RAD_SECTION_BAKER_VERTEX_LAYERS, -1, 0, 3, "BAKER_VERTEX_LAYERS"), RAD_ERROR_SIZE_MISMATCH);
    CHECK_RESULT(bs_hostile(&F, RAD_SECTION_BAKER_PROBE_BAND4, -1, 0, -27, "BAKER_PROBE_BAND4"), RAD_ERROR_SIZE_MISMATCH);
    CHECK_RESULT(bs_hostile(&F, RAD_SECTION_BAKER_VERTEX_LAYERS, 5, 0x7FC00000u, 0, "BAKER_VERTEX_LAYERS"), RAD_ERROR_NON_FINITE);
    CHECK_RESULT(bs_hostile(&F, RAD_SECTION_BAKER_PROBE_LAYERS, 0, 0x7F800000u, 0, "BAKER_PROBE_LAYERS"), RAD_ERROR_NON_FINITE);
    CHECK_RESULT(bs_hostile(&F, RAD_SECTION_BAKER_VERTEX_FIRST, 1, 0xFFFFFFFFu, 0, "BAKER_VERTEX_FIRST"), RAD_ERROR_CORRUPT);
    CHECK_RESULT(bs_hostile(&F, RAD_SECTION_BAKER_PROBE_STATES, 0, 0x07070707u, 0, "BAKER_PROBE_STATES"), RAD_ERROR_CORRUPT);
    CHECK_RESULT(bs_hostile(&F, RAD_SECTION_BAKER_REASON, 0, 0x41414141u, 0, NULL), RAD_SUCCESS);
    {
        /* a reason without its NUL, a wrong element size, a missing section */
        bs_file G;
        int i = bs_find(&F, RAD_SECTION_BAKER_REASON);
        bs_clone(&F, &G);
        memset(G.data[i], 'x', (size_t)G.s[i].count);
        CHECK_RESULT(bs_reload(&G), RAD_ERROR_CORRUPT);
        CHECK(strstr(bs_last, "BAKER_REASON") != NULL);
        bs_close(&G);
        bs_clone(&F, &G);
        i = bs_find(&G, RAD_SECTION_BAKER_PROBE_STATES);
        G.s[i].elem_size = 2, G.s[i].count /= 2;
        CHECK_RESULT(bs_reload(&G), RAD_ERROR_CORRUPT);
        CHECK(strstr(bs_last, "BAKER_PROBE_STATES") != NULL);
        bs_close(&G);
        bs_clone(&F, &G);
        i = bs_find(&G, RAD_SECTION_BAKER_LIGHTMAP_FLAGS);
        G.s[i].type = RAD_SECTION_USER + 5u; /* an unknown section is skipped: this one is then missing */
        CHECK_RESULT(bs_reload(&G), RAD_ERROR_CORRUPT);
        CHECK(strstr(bs_last, "BAKER_LIGHTMAP_FLAGS") != NULL);
        bs_close(&G);
    }
    bs_close(&F);
done:
    rad_free_buffer(f, NULL);
    rad_baker_result_destroy(A);
}

/* random byte flips of a small file, raw (the checksums catch them) and behind valid
   checksums (the loader's own checks): never a crash; a raw flip that loads (in the padding
   between sections) changed nothing */
static void bs_test_fuzz(void)
{
    bs_scene s;
    rad_baker_result *A = NULL, *B = NULL;
    void *f = NULL;
    unsigned char *buf;
    size_t n = 0;
    rad_context quiet;
    bs_file F;
    uint32_t seed = 12345u, it, ok = 0, loaded = 0;
    memset(&quiet, 0, sizeof quiet);
    quiet.log = bs_log_quiet;
    bs_corner(&s, BS_RGB9E5);
    s.d.outputs = RAD_BAKER_VERTEX | RAD_BAKER_LIGHTMAP | RAD_BAKER_PROBES;
    s.d.lightmap_width = s.d.lightmap_height = 4;
    CHECK_OK(rad_baker_run(&s.d, &s.o, NULL, &A));
    if (A) CHECK_OK(rad_baker_result_save_memory(A, NULL, &f, &n));
    if (!f || !(buf = (unsigned char *)malloc(n))) goto done;
    for (it = 0; it < 200; ++it) {
        uint32_t flips = 1 + it % 4, k;
        memcpy(buf, f, n);
        for (k = 0; k < flips; ++k) {
            seed = seed * 1664525u + 1013904223u;
            buf[(seed >> 8) % n] ^= (unsigned char)(1u << (seed >> 29));
        }
        if (rad_baker_result_load_memory(buf, n, &quiet, &B) == RAD_SUCCESS) ok += !bs_resaves(B, f, n);
        rad_baker_result_destroy(B);
        B = NULL;
    }
    CHECK(ok == 0);
    free(buf);
    if (!bs_open(f, n, &F)) goto done;
    for (it = 0; it < 300; ++it) {
        bs_file G;
        uint32_t i, k, flips = 1 + it % 3;
        bs_clone(&F, &G);
        for (k = 0; k < flips; ++k) {
            size_t bytes;
            seed = seed * 1664525u + 1013904223u;
            i = (seed >> 8) % G.count;
            bytes = (size_t)(G.s[i].count * G.s[i].elem_size);
            seed = seed * 1664525u + 1013904223u;
            if (bytes) ((unsigned char *)G.data[i])[(seed >> 4) % bytes] ^= (unsigned char)(1u << (seed >> 29));
        }
        {
            size_t m = 0;
            void *b2;
            if (rad_container_size(G.s, G.count, &m) == RAD_SUCCESS && (b2 = malloc(m)) != NULL) {
                if (rad_container_write(G.s, G.count, b2, m) == RAD_SUCCESS &&
                    rad_baker_result_load_memory(b2, m, &quiet, &B) == RAD_SUCCESS) {
                    ++loaded;
                    /* whatever loads is whole: its outputs mix again */
                    CHECK_OK(rad_baker_mix(B, NULL, NULL));
                }
                rad_baker_result_destroy(B);
                B = NULL;
                free(b2);
            }
        }
        bs_close(&G);
    }
    if (getenv("RAD_TEST_VERBOSE")) printf("    %u of 300 changed files loaded (values changed only)\n", loaded);
    bs_close(&F);
done:
    rad_free_buffer(f, NULL);
    rad_baker_result_destroy(A);
}

#ifndef RAD_NO_STDIO
/* through a file: the same result, and a missing file is IO */
static void bs_test_file(void)
{
    bs_scene s;
    rad_baker_result *A = NULL, *B = NULL;
    rad_context quiet;
    const char *path = rad_test_path("bs_round_trip.radr");
    memset(&quiet, 0, sizeof quiet);
    quiet.log = bs_log_quiet;
    bs_corner(&s, 0);
    CHECK_OK(rad_baker_run(&s.d, &s.o, NULL, &A));
    if (A && rad_baker_result_save_file(path, A, NULL) == RAD_SUCCESS) {
        CHECK_OK(rad_baker_result_load_file(path, NULL, &B));
        if (B) bs_compare(A, B);
        rad_baker_result_destroy(B);
        B = NULL;
        remove(path);
    }
    CHECK_RESULT(rad_baker_result_load_file("/nonexistent/dir/x.radr", &quiet, &B), RAD_ERROR_IO);
    rad_baker_result_destroy(A);
    rad_baker_result_destroy(B);
}
#endif

static const rad_test_case tests_baker_save[] = {
    { "baker_save_roundtrip", bs_test_roundtrip },
    { "baker_save_runtime", bs_test_runtime },
    { "baker_save_refusals", bs_test_refusals },
    { "baker_save_fuzz", bs_test_fuzz },
#ifndef RAD_NO_STDIO
    { "baker_save_file", bs_test_file },
#endif
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_baker_save)
