# tool_cutout.sh - alpha cutouts in the rad tool (sourced by tool_tests.sh, which defines RAD,
# TMP, ok, fail, close and pfm_mean).

# A floor (unit square at y = 0, facing up, albedo 0.5) lit by an emitter (unit square at
# y = 0.5, facing down, radiance 1), with a black screen at y = 0.25 over [-0.5, 1.5]^2 between
# them whose base-colour texture's alpha is a checkerboard (cells of 4 texels, 64 x 64 texels
# over the screen: half of it holes). The generator writes it as glTF (alphaMode given) and as
# OBJ with map_d, and once more with the screen open and the emitter itself a MASK cutout of
# the same checkerboard (cells of 1/16 over the unit emitter); the PNG is written with zlib by
# hand.
co_gen() { # co_gen DIR
    python3 - "$1" <<'PY'
import base64, json, struct, sys, zlib
d = sys.argv[1]
def png(w, h, px):  # px: rows of RGBA bytes
    raw = b"".join(b"\0" + bytes(r) for r in px)
    def chunk(t, data):
        c = struct.pack(">I", len(data)) + t + data
        return c + struct.pack(">I", zlib.crc32(t + data) & 0xffffffff)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
rows = []
for y in range(64):
    r = []
    for x in range(64):
        r += [0, 0, 0, 255 if ((x // 4 + y // 4) % 2 == 0) else 0]
    rows.append(r)
img = png(64, 64, rows)
open(d + "/checker.png", "wb").write(img)
quads = [  # corners (counter-clockwise seen from the front), uvs
    ([(0, 0, 1), (1, 0, 1), (1, 0, 0), (0, 0, 0)], "floor"),
    ([(0, 0.5, 0), (1, 0.5, 0), (1, 0.5, 1), (0, 0.5, 1)], "light"),
    ([(-0.5, 0.25, -0.5), (1.5, 0.25, -0.5), (1.5, 0.25, 1.5), (-0.5, 0.25, 1.5)], "screen")]
uv = [(0, 0), (1, 0), (1, 1), (0, 1)]
def gltf(mode, factor_alpha, name, light_mask=False):
    pos, tex, idx = [], [], []
    for q, _ in quads:
        for p in q: pos += p
        for t in uv: tex += t
    for k in range(3): idx += [4 * k, 4 * k + 1, 4 * k + 2, 4 * k, 4 * k + 2, 4 * k + 3]
    buf = struct.pack("<%df" % len(pos), *pos) + struct.pack("<%df" % len(tex), *tex) + struct.pack("<%dI" % len(idx), *idx)
    screen = {"name": "screen", "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, factor_alpha],
              "baseColorTexture": {"index": 0}}, "alphaMode": mode}
    if mode == "MASK": screen["alphaCutoff"] = 0.5
    if factor_alpha < 1: del screen["pbrMetallicRoughness"]["baseColorTexture"]
    light = {"name": "light", "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]}, "emissiveFactor": [1, 1, 1]}
    if light_mask:
        light["alphaMode"] = "MASK"
        light["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    g = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1, 2]}],
         "nodes": [{"mesh": k, "name": quads[k][1]} for k in range(3)],
         "materials": [{"name": "floor", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}},
                       light, screen],
         "meshes": [{"name": quads[k][1], "primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2 + k,
                     "material": k}]} for k in range(3)],
         "images": [{"uri": "data:image/png;base64," + base64.b64encode(img).decode()}],
         "textures": [{"source": 0}],
         "buffers": [{"byteLength": len(buf), "uri": "data:application/octet-stream;base64," + base64.b64encode(buf).decode()}],
         "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 144}, {"buffer": 0, "byteOffset": 144, "byteLength": 96},
                         {"buffer": 0, "byteOffset": 240, "byteLength": 72}],
         "accessors": [{"bufferView": 0, "componentType": 5126, "count": 12, "type": "VEC3", "min": [-0.5, 0, -0.5],
                        "max": [1.5, 0.5, 1.5]},
                       {"bufferView": 1, "componentType": 5126, "count": 12, "type": "VEC2"}] +
                      [{"bufferView": 2, "byteOffset": 24 * k, "componentType": 5125, "count": 6, "type": "SCALAR"}
                       for k in range(3)]}
    open(d + "/" + name, "w").write(json.dumps(g))
gltf("MASK", 1.0, "mask.gltf")
gltf("OPAQUE", 1.0, "opaque.gltf")
gltf("BLEND", 0.3, "blend.gltf")  # a constant alpha below 0.5: the screen is all hole
gltf("BLEND", 0.3, "lightmask.gltf", True)  # the open screen, and the emitter a checkerboard cutout
with open(d + "/screen.mtl", "w") as f:
    f.write("newmtl floor\nKd 0.5 0.5 0.5\nnewmtl light\nKd 0 0 0\nKe 1 1 1\nnewmtl screen\nKd 0 0 0\nmap_d checker.png\n")
with open(d + "/screen.obj", "w") as f:
    f.write("mtllib screen.mtl\n")
    for q, _ in quads:
        for p in q: f.write("v %g %g %g\n" % p)
    for t in uv: f.write("vt %g %g\n" % t)
    for k, (q, n) in enumerate(quads):
        f.write("o %s\nusemtl %s\nf %d/1 %d/2 %d/3 %d/4\n" % (n, n, 4 * k + 1, 4 * k + 2, 4 * k + 3, 4 * k + 4))
PY
}
mkdir -p "$TMP/cut"
if ! co_gen "$TMP/cut" 2> "$TMP/err.txt"; then
    fail "cutout scenes generated" "$(head -c 300 "$TMP/err.txt")"
else
    # rad info names the cutout and what it was made of; the floor is opaque
    "$RAD" info "$TMP/cut/mask.gltf" > "$TMP/cut/info.txt" 2>&1
    grep -q "cutout: alpha of .* x 1 >= 0.5" "$TMP/cut/info.txt" && grep -q "cutout: none" "$TMP/cut/info.txt" &&
        ok "rad info lists the glTF MASK cutout" || fail "rad info lists the glTF MASK cutout" "$(grep -i "cutout\|alpha" "$TMP/cut/info.txt" | head -5)"
    "$RAD" info "$TMP/cut/screen.obj" > "$TMP/cut/info2.txt" 2>&1
    grep -q "cutout: alpha of 'checker.png' (alpha channel) x 1 >= 0.5" "$TMP/cut/info2.txt" &&
        ok "rad info lists the OBJ map_d cutout" || fail "rad info lists the OBJ map_d cutout" "$(grep -i "cutout" "$TMP/cut/info2.txt" | head -5)"
    # The floor's centre seen from below the screen (the camera between screen and floor):
    # through the checkerboard it gets half of what it gets with no screen (BLEND at alpha 0.3,
    # all hole), in rad trace and rad render alike; OPAQUE blocks everything.
    co_view="--camera 0.5,0.1,0.5:0.5,0,0.5:0,0,1 --fov 20 --size 8x8"
    co_val() { # co_val trace|render FILE
        # shellcheck disable=SC2086
        if [ "$1" = trace ]; then "$RAD" trace "$2" $co_view --spp 512 -o "$TMP/cut/v.pfm" > /dev/null 2>> "$TMP/err.txt"
        else "$RAD" render "$2" $co_view --patches 400 -o "$TMP/cut/v.pfm" > /dev/null 2>> "$TMP/err.txt"; fi &&
            pfm_mean "$TMP/cut/v.pfm"
    }
    for co_cmd in trace render; do
        co_open=$(co_val $co_cmd "$TMP/cut/blend.gltf")
        co_half=$(co_val $co_cmd "$TMP/cut/mask.gltf")
        co_obj=$(co_val $co_cmd "$TMP/cut/screen.obj")
        co_solid=$(co_val $co_cmd "$TMP/cut/opaque.gltf")
        co_lamp=$(co_val $co_cmd "$TMP/cut/lightmask.gltf")
        co_expect=$(awk -v o="$co_open" 'BEGIN { printf "%.9g\n", o / 2 }')
        awk -v o="$co_open" 'BEGIN { exit !(o > 0.05) }' && close "$co_half" "$co_expect" 0.05 && close "$co_obj" "$co_expect" 0.05 &&
            [ "$co_solid" = "0" ] && close "$co_lamp" "$co_expect" 0.05 &&
            ok "cutout screen, rad $co_cmd: MASK $co_half, map_d $co_obj and a MASK emitter $co_lamp = half of open $co_open; OPAQUE $co_solid" ||
            fail "cutout screen, rad $co_cmd" "MASK $co_half, map_d $co_obj, MASK emitter $co_lamp, open (BLEND 0.3) $co_open, OPAQUE $co_solid; $(head -c 300 "$TMP/err.txt")"
    done
fi
