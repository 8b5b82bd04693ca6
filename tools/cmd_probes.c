/* cmd_probes.c - `rad probes`: irradiance probes (SH L2) from the classic solution or from
   virtual patches.

   rad probes SCENE -o OUT.json|OUT.bin [--spacing S] [--rays R] [--patch-samples N] [--indirect]
              [--band4] [--proxy aavp|vp [--vp-resolution R | --vp-max-patches B] [--face-points P]
              [--vp-rays N]]
              [classic options: --patches N ...] [lights: --sun, --sky, --point, --spot, --area]
              [--threads N]

   Solves the scene as `rad bake` does (B = E + L with the direct light as the source, emitters
   out of the system), or with --proxy aavp|vp over virtual patches as `rad lightmap --proxy`
   does (tool_vp_proxy_solve; rad_probes_create_vp gathers the probes from them: a scene too
   big for the dense classic build is refused without --proxy, naming it), places a probe grid over the scene's bounds (rad_probes_create; probes
   inside geometry moved out or disabled) and writes every probe's position, state and its 27
   irradiance coefficients (docs/methods/probes.md). By default the probes hold all the light
   (the direct light of the emitters and the file's lights is added: RAD_PROBES_DIRECT);
   --indirect keeps only the indirect light, for a renderer that draws direct light per pixel.
   --band4 also bakes and writes the 9 band-4 coefficients per colour (RAD_PROBES_BAND4): the
   irradiance is then E(n) = sum_i E_i Y_i(n) + sum_m F_m Z_m(n) (rad_sh_l4_irradiance).

   OUT.json: { "format": "radiosity.h probes", "version": 1, "basis": ..., "light": "total" or
   "indirect", "grid": { "dims": [x, y, z], "origin": [x, y, z], "spacing": s }, "count": n,
   "probes": [ { "p": [x, y, z], "state": "valid"|"moved"|"disabled", "sh": [[r, g, b] x 9] } ] }
   with --band4 also "basis_band4" and per probe "band4": [[r, g, b] x 9] (F_0..F_8).
   OUT.bin (little-endian, all 4-byte fields): "RADPROBE" (8 bytes), version 1, count, flags (1:
   total light, 2: band 4), dims[3], origin[3] (float), spacing (float), then per probe
   position[3] (float), state (uint32, rad_probe_state), coefficients[27] (float, E_i of channel
   c at 3 i + c) and, with flag 2, band4[27] (float, F_m of channel c at 3 m + c).
   The file is written to a temporary and renamed into place. */
#include "tool.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void probes_usage(FILE *f)
{
    fprintf(f, "usage: rad probes SCENE -o OUT.json|OUT.bin [--spacing S] [--rays R] [--indirect] [--proxy aavp|vp] [options]\n"
               "Solves the scene (classic radiosity, or virtual patches with --proxy; direct light as the source) and\n"
               "bakes SH L2 irradiance probes on a grid over its bounds: E(n) = sum_i E_i Y_i(n) (docs/methods/probes.md).\n"
               "  -o FILE            OUT.json (text) or OUT.bin (binary; layout in tools/cmd_probes.c)\n"
               "  --spacing S        grid spacing in scene units (default: the largest extent / 8)\n"
               "  --rays R           rays per probe for the inside-geometry test (default 256)\n"
               "  --patch-samples N  points per patch for the probes' gather (default 4; classic patches)\n"
               "  --indirect         only the indirect light (default: direct light too)\n"
               "  --band4            also band 4 (9 more coefficients per colour: sharper E(n) than L2)\n"
               "  --proxy P          the light from classic patches (patches, the default) or from virtual patches,\n"
               "                     aavp or vp: a few thousand unknowns whatever the triangle count, for real\n"
               "                     buildings (rad_probes_create_vp); --vp-resolution R (default 16) or\n"
               "                     --vp-max-patches B (the finest resolution with at most B patches),\n"
               "                     --face-points P (default 16), --vp-rays N gather rays per probe (default 2048)\n"
               "%s%s"
               "  --threads N        worker threads (default: all cores; at most 1024)\n",
            tool_classic_help(), tool_light_help());
}

static const char *state_name(uint8_t s)
{
    return s == RAD_PROBE_VALID ? "valid" : s == RAD_PROBE_MOVED ? "moved" : "disabled";
}

static int put_u32(FILE *f, uint32_t v)
{
    unsigned char b[4];
    b[0] = (unsigned char)v; b[1] = (unsigned char)(v >> 8); b[2] = (unsigned char)(v >> 16); b[3] = (unsigned char)(v >> 24);
    return fwrite(b, 1, 4, f) == 4;
}

static int put_f32(FILE *f, float x)
{
    uint32_t v;
    memcpy(&v, &x, 4);
    return put_u32(f, v);
}

/* 1 when every write succeeded */
static int write_probes(FILE *f, int json, const rad_probes *pr, int total)
{
    uint32_t n = rad_probes_count(pr), i, dims[3] = {0, 0, 0}, k;
    float origin[3] = {0, 0, 0}, spacing = 0.0f;
    const float *pos = rad_probes_positions(pr), *co = rad_probes_coefficients(pr), *b4 = rad_probes_band4(pr);
    const uint8_t *st = rad_probes_states(pr);
    int ok = 1;
    rad_probes_grid(pr, dims, origin, &spacing);
    if (json) {
        ok &= fprintf(f, "{\n  \"format\": \"radiosity.h probes\",\n  \"version\": 1,\n"
                         "  \"basis\": \"real SH L2, irradiance coefficients E_i (W/m^2): E(n) = sum_i E_i Y_i(n), "
                         "Y0 = 0.282095, Y1..3 = 0.488603 (y, z, x), Y4 = 1.092548 xy, Y5 = 1.092548 yz, "
                         "Y6 = 0.315392 (3z^2 - 1), Y7 = 1.092548 xz, Y8 = 0.546274 (x^2 - y^2)\",\n"
                         "  \"light\": \"%s\",\n  \"grid\": { \"dims\": [%u, %u, %u], \"origin\": [%.9g, %.9g, %.9g], "
                         "\"spacing\": %.9g },\n  \"count\": %u,\n  \"probes\": [\n",
                      total ? "total" : "indirect", dims[0], dims[1], dims[2], (double)origin[0], (double)origin[1],
                      (double)origin[2], (double)spacing, n) > 0;
        if (b4)
            ok &= fprintf(f, "  \"basis_band4\": \"band-4 irradiance coefficients F_m, added: E(n) += sum_m F_m Z_m(n), "
                             "Z0 = 2.503343 xy(x^2 - y^2), Z1 = 1.770131 yz(3x^2 - y^2), Z2 = 0.946175 xy(7z^2 - 1), "
                             "Z3 = 0.669047 yz(7z^2 - 3), Z4 = 0.105786 (35z^4 - 30z^2 + 3), Z5 = 0.669047 xz(7z^2 - 3), "
                             "Z6 = 0.473087 (x^2 - y^2)(7z^2 - 1), Z7 = 1.770131 xz(x^2 - 3y^2), "
                             "Z8 = 0.625836 (x^4 - 6x^2 y^2 + y^4)\",\n") > 0;
        for (i = 0; i < n && ok; ++i) {
            const float *c = co + 27 * (size_t)i;
            ok &= fprintf(f, "    { \"p\": [%.9g, %.9g, %.9g], \"state\": \"%s\", \"sh\": [", (double)pos[3 * i],
                          (double)pos[3 * i + 1], (double)pos[3 * i + 2], state_name(st[i])) > 0;
            for (k = 0; k < 9; ++k)
                ok &= fprintf(f, "%s[%.9g, %.9g, %.9g]", k ? ", " : "", (double)c[3 * k], (double)c[3 * k + 1],
                              (double)c[3 * k + 2]) > 0;
            if (b4) {
                const float *g = b4 + 27 * (size_t)i;
                ok &= fprintf(f, "], \"band4\": [") > 0;
                for (k = 0; k < 9; ++k)
                    ok &= fprintf(f, "%s[%.9g, %.9g, %.9g]", k ? ", " : "", (double)g[3 * k], (double)g[3 * k + 1],
                                  (double)g[3 * k + 2]) > 0;
            }
            ok &= fprintf(f, "] }%s\n", i + 1 < n ? "," : "") > 0;
        }
        ok &= fprintf(f, "  ]\n}\n") > 0;
        return ok;
    }
    ok &= fwrite("RADPROBE", 1, 8, f) == 8;
    ok &= put_u32(f, 1) && put_u32(f, n) && put_u32(f, (total ? 1u : 0u) | (b4 ? 2u : 0u));
    for (k = 0; k < 3; ++k) ok &= put_u32(f, dims[k]);
    for (k = 0; k < 3; ++k) ok &= put_f32(f, origin[k]);
    ok &= put_f32(f, spacing);
    for (i = 0; i < n && ok; ++i) {
        for (k = 0; k < 3; ++k) ok &= put_f32(f, pos[3 * (size_t)i + k]);
        ok &= put_u32(f, st[i]);
        for (k = 0; k < 27; ++k) ok &= put_f32(f, co[27 * (size_t)i + k]);
        if (b4)
            for (k = 0; k < 27; ++k) ok &= put_f32(f, b4[27 * (size_t)i + k]);
    }
    return ok;
}

static int probes_main(int argc, char **argv, tool_lights *lights)
{
    const char *cmd = "probes", *scene_name = NULL, *out_path = NULL;
    tool_classic_options o;
    tool_world w;
    tool_classic c;
    tool_lightmap_proxy px;
    rad_virtual_patches *vp = NULL;
    float *vp_B = NULL;
    rad_probe_options po;
    rad_probes *pr = NULL;
    rad_context ctx;
    tool_output out;
    uint32_t threads = 0, i, counts[3] = {0, 0, 0};
    double t0 = tool_seconds(), tp;
    int a, rc, json, total = 1, px_opts = 0, vp_rays_given = 0, patch_samples_given = 0;
    size_t len;
    rad_result r;
    tool_classic_options_default(&o);
    rad_probe_options_default(&po);
    memset(&px, 0, sizeof px);
    memset(&c, 0, sizeof c);
    for (a = 0; a < argc; ++a) {
        const char *opt = argv[a];
        if (!strcmp(opt, "--help") || !strcmp(opt, "-h")) { probes_usage(stdout); return 0; }
        rc = tool_classic_option(cmd, argc, argv, &a, &o);
        if (rc == 2) return 2;
        if (rc == 1) continue;
        rc = tool_light_option(cmd, argc, argv, &a, lights);
        if (rc == 2) return 2;
        if (rc == 1) continue;
        if (!strcmp(opt, "--indirect")) { total = 0; continue; }
        if (!strcmp(opt, "--band4")) { po.flags |= RAD_PROBES_BAND4; continue; }
        if ((!strcmp(opt, "-o") || !strcmp(opt, "--threads") || !strcmp(opt, "--spacing") || !strcmp(opt, "--rays") ||
             !strcmp(opt, "--patch-samples") || !strcmp(opt, "--proxy") || !strcmp(opt, "--vp-resolution") ||
             !strcmp(opt, "--face-points") || !strcmp(opt, "--vp-rays") || !strcmp(opt, "--vp-max-patches")) &&
            a + 1 >= argc) {
            fprintf(stderr, "rad %s: %s needs a value\n", cmd, opt);
            return 2;
        }
        if (!strcmp(opt, "-o")) out_path = argv[++a];
        else if (!strcmp(opt, "--threads")) { if (tool_parse_threads(cmd, opt, argv[++a], &threads)) return 2; }
        else if (!strcmp(opt, "--spacing")) {
            if (tool_parse_float(cmd, opt, argv[++a], &po.spacing)) return 2;
            if (!(po.spacing > 0.0f)) { fprintf(stderr, "rad %s: --spacing must be > 0\n", cmd); return 2; }
        } else if (!strcmp(opt, "--rays")) {
            if (tool_parse_uint(cmd, opt, argv[++a], &po.rays)) return 2;
            if (po.rays == 0 || po.rays > 65536) { fprintf(stderr, "rad %s: --rays must be in 1..65536\n", cmd); return 2; }
        } else if (!strcmp(opt, "--vp-rays")) {
            if (tool_parse_uint(cmd, opt, argv[++a], &po.vp_rays)) return 2;
            if (po.vp_rays == 0 || po.vp_rays > 65536) { fprintf(stderr, "rad %s: --vp-rays must be in 1..65536\n", cmd); return 2; }
            vp_rays_given = 1;
        } else if (!strcmp(opt, "--patch-samples")) {
            if (tool_parse_uint(cmd, opt, argv[++a], &po.patch_samples)) return 2;
            if (po.patch_samples == 0 || po.patch_samples > 256) {
                fprintf(stderr, "rad %s: --patch-samples must be in 1..256\n", cmd);
                return 2;
            }
            patch_samples_given = 1;
        } else if (!strcmp(opt, "--proxy")) {
            const char *v = argv[++a];
            if (!strcmp(v, "aavp")) px.kind = TOOL_PROXY_AAVP;
            else if (!strcmp(v, "vp")) px.kind = TOOL_PROXY_VP;
            else if (!strcmp(v, "patches")) px.kind = TOOL_PROXY_PATCHES;
            else { fprintf(stderr, "rad %s: unknown --proxy '%s' (patches, aavp or vp)\n", cmd, v); return 2; }
        } else if (!strcmp(opt, "--vp-resolution") || !strcmp(opt, "--face-points")) {
            uint32_t *dst = opt[2] == 'v' ? &px.resolution : &px.face_points;
            if (tool_parse_uint(cmd, opt, argv[++a], dst)) return 2;
            if (*dst == 0 || *dst > 4096u) { fprintf(stderr, "rad %s: %s must be 1 to 4096\n", cmd, opt); return 2; }
            px_opts = 1;
        } else if (!strcmp(opt, "--vp-max-patches")) {
            if (tool_parse_uint(cmd, opt, argv[++a], &px.max_patches)) return 2;
            if (px.max_patches == 0) { fprintf(stderr, "rad %s: --vp-max-patches must be at least 1\n", cmd); return 2; }
            px_opts = 1;
        } else if (opt[0] == '-' && opt[1]) {
            fprintf(stderr, "rad %s: unknown option '%s' (see rad probes --help)\n", cmd, opt);
            return 2;
        } else if (!scene_name) scene_name = opt;
        else { fprintf(stderr, "rad %s: more than one scene given\n", cmd); return 2; }
    }
    if (!scene_name || !out_path) {
        fprintf(stderr, "rad %s: %s\n", cmd, !scene_name ? "no scene given" : "no output file given (-o OUT.json|OUT.bin)");
        probes_usage(stderr);
        return 2;
    }
    if (px_opts && !px.kind) {
        fprintf(stderr, "rad %s: --vp-resolution, --vp-max-patches and --face-points are for --proxy aavp|vp\n", cmd);
        return 2;
    }
    if (px.resolution && px.max_patches) {
        fprintf(stderr, "rad %s: --vp-resolution and --vp-max-patches exclude each other\n", cmd);
        return 2;
    }
    if (vp_rays_given && !px.kind) {
        fprintf(stderr, "rad %s: --vp-rays is for --proxy aavp|vp (classic patches: --patch-samples)\n", cmd);
        return 2;
    }
    if (patch_samples_given && px.kind) {
        fprintf(stderr, "rad %s: --patch-samples is for classic patches (with --proxy: --vp-rays)\n", cmd);
        return 2;
    }
    if (px.kind && o.solver == TOOL_DIRECT) {
        fprintf(stderr, "rad %s: --solver direct is for classic patches: with --proxy use jacobi or gauss-seidel\n", cmd);
        return 2;
    }
    len = strlen(out_path);
    json = len >= 5 && !strcmp(out_path + len - 5, ".json");
    if (!json && !(len >= 4 && !strcmp(out_path + len - 4, ".bin"))) {
        fprintf(stderr, "rad %s: the output must end in .json or .bin: '%s'\n", cmd, out_path);
        return 2;
    }
    if (tool_check_output(cmd, out_path, &scene_name, 1)) return 1;
    tool_set_threads((int)threads);
    if (tool_open_world_lit(cmd, scene_name, lights, &w)) return 1;
    /* a scene too big for the dense classic build is refused with the way out */
    o.dense_instead = "--proxy aavp or --proxy vp (the probes' light from virtual patches: a few thousand whatever the "
                      "triangle count; --vp-resolution R sets how many)";
    if (px.kind) {
        if (tool_vp_proxy_solve(cmd, &w, &o, &px, &vp, &vp_B, NULL, NULL)) {
            tool_close_world(&w);
            return 1;
        }
    } else if (tool_classic_solve(cmd, &w, &o, &c)) {
        tool_close_world(&w);
        return 1;
    }
    if (total) po.flags |= RAD_PROBES_DIRECT;
    tool_context(&ctx, "probes");
    tp = tool_seconds();
    r = vp ? rad_probes_create_vp(vp, &w.rc, w.file.lights, w.file.light_count, NULL, 0, &po, vp_B, &ctx, &pr)
           : rad_probes_create(c.patches, &w.rc, w.file.lights, w.file.light_count, NULL, 0, &po, c.B, &ctx, &pr);
    tool_progress_end();
    rc = 1;
    if (r != RAD_SUCCESS) {
        tool_fail(cmd, vp ? "rad_probes_create_vp" : "rad_probes_create", r);
        goto done;
    }
    tp = tool_seconds() - tp;
    for (i = 0; i < rad_probes_count(pr); ++i) counts[rad_probes_states(pr)[i] % 3u]++;
    if (tool_output_open(&out, out_path) != 0) {
        fprintf(stderr, "rad %s: %s\n", cmd, tool_output_error());
        goto done;
    }
    if (tool_output_commit(&out, write_probes(out.f, json, pr, total)) != 0) {
        fprintf(stderr, "rad %s: %s\n", cmd, tool_output_error());
        goto done;
    }
    printf("wrote %s: %u probes (%u valid, %u moved out of geometry, %u disabled), %lu weights, %s light%s%s\n", out_path,
           rad_probes_count(pr), counts[RAD_PROBE_VALID], counts[RAD_PROBE_MOVED], counts[RAD_PROBE_DISABLED],
           (unsigned long)rad_probes_entry_count(pr), total ? "total" : "indirect", rad_probes_band4(pr) ? ", band 4" : "",
           vp ? (px.kind == TOOL_PROXY_VP ? ", over vp virtual patches" : ", over aavp virtual patches") : "");
    fprintf(stderr, "rad %s: probes gathered in %.2f s; done in %.2f s\n", cmd, tp, tool_seconds() - t0);
    rc = 0;
done:
    rad_probes_destroy(pr);
    free(vp_B);
    rad_vp_destroy(vp);
    tool_classic_free(&c);
    tool_close_world(&w);
    return rc;
}

int tool_cmd_probes(int argc, char **argv)
{
    tool_lights lights;
    int rc;
    memset(&lights, 0, sizeof lights);
    rc = probes_main(argc, argv, &lights);
    tool_lights_free(&lights);
    return rc;
}
