/* cmd_export.c - rad export: any scene the tool loads (the built-in 'cornell' or a file assimp
   reads) written as Wavefront OBJ + MTL, so that what the tool sees can be opened elsewhere
   and read back (the tool checks compare the built-in box with its exported OBJ).

   rad export SCENE -o OUT.obj

   What is written: one 'o NAME' per mesh (its vertices, then its triangles, a 'usemtl' line
   wherever the material changes), and OUT.mtl beside it (named by a relative 'mtllib' line)
   with one 'newmtl' per material: Kd = albedo, Ke = emitted radiance (the importer reads Ke
   as radiance, so the round trip keeps the light). Numbers are printed with 9 significant
   digits, which a float reads back exactly. What OBJ cannot hold is reported on stderr and
   left out: the scene's camera (written as a comment, with the --camera/--fov options that
   restore it), analytic lights, and albedo and emission textures (the material's colour
   factor, Kd or Ke, is written).
   Both files go through one tool_output_set (two temporaries renamed into place only when
   both are complete), and neither may be a file the scene was read from. */
#include "tool.h"
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void export_usage(FILE *f)
{
    fprintf(f, "usage: rad export SCENE -o OUT.obj\n"
               "  writes SCENE ('cornell' or any file rad reads) as OUT.obj and OUT.mtl beside it:\n"
               "  one 'o' per mesh, one 'usemtl' per run of a material, Kd = albedo, Ke = emitted\n"
               "  radiance. The camera goes into a comment (with the --camera and --fov that restore\n"
               "  it); analytic lights and albedo and emission textures are left out with a warning.\n");
}

/* a name usable after 'o', 'usemtl' and 'newmtl': no whitespace or control characters */
static void clean_name(const char *name, char *buf, size_t cap)
{
    size_t i = 0;
    if (name)
        for (; name[i] && i + 1 < cap; ++i) {
            unsigned char c = (unsigned char)name[i];
            buf[i] = (isspace(c) || iscntrl(c) || c == '#') ? '_' : (char)c;
        }
    buf[i] = '\0';
}

static void write_rgb(FILE *f, const char *key, const float *v)
{
    fprintf(f, "%s %.9g %.9g %.9g\n", key, (double)v[0], (double)v[1], (double)v[2]);
}

int tool_cmd_export(int argc, char **argv)
{
    const char *cmd = "export", *scene_name = NULL, *out_path = NULL;
    char err[1024], mtl_path[4096], name[256];
    const char *outs[2];
    const char *mtl_base;
    tool_scene ts;
    tool_output obj, mtl;
    const rad_scene_desc *d;
    uint32_t m, t, k, textured = 0, written_tris = 0;
    uint64_t base = 1; /* OBJ indices count from 1 over the whole file */
    int a, ok;
    size_t l;
    for (a = 0; a < argc; ++a) {
        const char *o = argv[a];
        if (!strcmp(o, "--help") || !strcmp(o, "-h")) { export_usage(stdout); return 0; }
        if (!strcmp(o, "-o")) {
            if (a + 1 >= argc) { fprintf(stderr, "rad %s: -o needs a value\n", cmd); return 2; }
            out_path = argv[++a];
        } else if (o[0] == '-' && o[1]) {
            fprintf(stderr, "rad %s: unknown option '%s'\n", cmd, o);
            export_usage(stderr);
            return 2;
        } else if (!scene_name) scene_name = o;
        else { fprintf(stderr, "rad %s: more than one scene given\n", cmd); return 2; }
    }
    if (!scene_name || !out_path) {
        fprintf(stderr, "rad %s: %s\n", cmd, !scene_name ? "no scene given" : "no output file given (-o OUT.obj)");
        export_usage(stderr);
        return 2;
    }
    l = strlen(out_path);
    if (l < 5 || (strcmp(out_path + l - 4, ".obj") && strcmp(out_path + l - 4, ".OBJ")) || out_path[l - 5] == '/') {
        fprintf(stderr, "rad %s: -o wants a .obj file, got '%s'\n", cmd, out_path);
        return 2;
    }
    if (l - 4 + 5 > sizeof mtl_path) { fprintf(stderr, "rad %s: output path too long\n", cmd); return 2; }
    memcpy(mtl_path, out_path, l - 4);
    memcpy(mtl_path + l - 4, out_path[l - 3] == 'O' ? ".MTL" : ".mtl", 5);
    mtl_base = strrchr(mtl_path, '/') ? strrchr(mtl_path, '/') + 1 : mtl_path;
    /* neither output may be a file the scene is read from (the scene, its MTL files, its
       textures: known once it is loaded) */
    if (tool_check_output(cmd, out_path, &scene_name, 1) || tool_check_output(cmd, mtl_path, &scene_name, 1))
        return 1;
    if (tool_load_scene(scene_name, &ts, err, sizeof err) != 0) {
        fprintf(stderr, "rad %s: %s\n", cmd, err);
        return 1;
    }
    outs[0] = out_path;
    outs[1] = mtl_path;
    if (tool_check_outputs(cmd, outs, 2, ts.input_files, (int)ts.input_file_count)) {
        tool_free_scene(&ts);
        return 1;
    }
    d = &ts.desc;
    if (tool_output_open(&mtl, mtl_path) != 0) {
        fprintf(stderr, "rad %s: %s\n", cmd, tool_output_error());
        tool_free_scene(&ts);
        return 1;
    }
    if (tool_output_open(&obj, out_path) != 0) {
        fprintf(stderr, "rad %s: %s\n", cmd, tool_output_error());
        tool_output_abort(&mtl);
        tool_free_scene(&ts);
        return 1;
    }

    /* materials: "m<index>" keeps the names unique whatever the file called them */
    fprintf(mtl.f, "# written by rad export from '%s': Kd = albedo, Ke = emitted radiance (W m^-2 sr^-1)\n", scene_name);
    for (m = 0; m < d->material_count; ++m) {
        const rad_material *mat = &d->materials[m];
        clean_name(ts.material_names ? ts.material_names[m] : NULL, name, sizeof name);
        fprintf(mtl.f, "newmtl m%u%s%s\n", m, name[0] ? "_" : "", name);
        write_rgb(mtl.f, "Kd", mat->albedo);
        write_rgb(mtl.f, "Ke", mat->emission);
        if (mat->texture || mat->emission_texture) ++textured;
    }

    fprintf(obj.f, "# written by rad export from '%s'\n", scene_name);
    if (ts.has_camera) /* else render and trace choose one from the geometry, as for the source */
        fprintf(obj.f, "# camera: --camera %.9g,%.9g,%.9g:%.9g,%.9g,%.9g:%.9g,%.9g,%.9g --fov %.9g\n",
                (double)ts.camera.position[0], (double)ts.camera.position[1], (double)ts.camera.position[2],
                (double)ts.camera.target[0], (double)ts.camera.target[1], (double)ts.camera.target[2],
                (double)ts.camera.up[0], (double)ts.camera.up[1], (double)ts.camera.up[2],
                (double)ts.camera.fov_y_degrees);
    fprintf(obj.f, "mtllib %s\n", mtl_base);
    for (m = 0; m < d->mesh_count; ++m) {
        const rad_mesh_desc *md = &d->meshes[m];
        size_t stride = md->position_stride ? md->position_stride : 3 * sizeof(float);
        uint32_t last = RAD_NONE;
        clean_name(md->name, name, sizeof name);
        if (name[0]) fprintf(obj.f, "o %s\n", name);
        else fprintf(obj.f, "o mesh%u\n", m);
        for (k = 0; k < md->vertex_count; ++k) {
            const float *p = (const float *)(const void *)((const char *)md->positions + (size_t)k * stride);
            fprintf(obj.f, "v %.9g %.9g %.9g\n", (double)p[0], (double)p[1], (double)p[2]);
        }
        for (t = 0; t < md->triangle_count; ++t) {
            uint32_t mat = md->material_ids ? md->material_ids[t] : md->material, v[3];
            for (k = 0; k < 3; ++k) v[k] = md->indices ? md->indices[3 * (size_t)t + k] : 3 * t + k;
            if (v[0] >= md->vertex_count || v[1] >= md->vertex_count || v[2] >= md->vertex_count) continue;
            if (mat != last && mat < d->material_count) {
                clean_name(ts.material_names ? ts.material_names[mat] : NULL, name, sizeof name);
                fprintf(obj.f, "usemtl m%u%s%s\n", mat, name[0] ? "_" : "", name);
                last = mat;
            }
            fprintf(obj.f, "f %llu %llu %llu\n", (unsigned long long)(base + v[0]), (unsigned long long)(base + v[1]),
                    (unsigned long long)(base + v[2]));
            ++written_tris;
        }
        base += md->vertex_count;
    }
    {
        /* the two files name each other's materials: they replace the old pair together, and
           each is checked on its own so that an error names the file that hit it */
        tool_output_set set;
        memset(&set, 0, sizeof set);
        ok = tool_output_set_add(&set, &mtl, !ferror(mtl.f)) == 0;
        if (!ok) tool_output_abort(&obj);
        else ok = tool_output_set_add(&set, &obj, !ferror(obj.f)) == 0;
        if (!ok || tool_output_set_commit(&set) != 0) {
            fprintf(stderr, "rad %s: %s\n", cmd, tool_output_error());
            tool_free_scene(&ts);
            return 1;
        }
    }
    if (ts.light_count)
        fprintf(stderr, "rad %s: warning: %u analytic lights left out (OBJ has no lights)\n", cmd, ts.light_count);
    if (textured)
        fprintf(stderr, "rad %s: warning: %u textured materials written with their colour factors only (albedo and emission textures left out)\n",
                cmd, textured);
    printf("wrote %s and %s (%u meshes, %u triangles, %u materials)\n", out_path, mtl_path, d->mesh_count, written_tris,
           d->material_count);
    tool_free_scene(&ts);
    return 0;
}
