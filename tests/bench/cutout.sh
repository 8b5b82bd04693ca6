#!/usr/bin/env bash
# cutout.sh - alpha-cutout foliage: a canopy of leaf cards (a grid of tilted, two-sided quads
# whose base-colour texture's alpha is a leaf shape with holes, glTF alphaMode MASK) over a
# floor under a uniform sky. The light through the holes, seen on the floor from below the
# canopy: the tool's default render (`rad render`, classic radiosity) against the path tracer
# (`rad trace`, same cutouts), ratio of mean linear radiance and SSIM (`rad compare`), and the
# same scene with the leaves opaque (alphaMode OPAQUE) to show what the cutouts change.
# METHODS (default: the tool's default only) adds rows for other --method values on the cutout
# scene: hierarchical radiosity and virtual patches see through the holes but reflect over
# the cards' full area (docs/methods/cutout.md). Never part of make test.
#   [SPP=512] [METHODS="hierarchical aavp"] bash tests/bench/cutout.sh build/rad [OUT.md]
set -eu
RAD=$1
OUT=${2:-/dev/stdout}
TMP=$(mktemp -d "${TMPDIR:-/tmp}/rad_cutout_bench.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
SPP=${SPP:-512}
python3 - "$TMP" <<'PY'
import base64, json, math, struct, sys, zlib
d = sys.argv[1]
def png(w, h, px):
    raw = b"".join(b"\0" + bytes(r) for r in px)
    def chunk(t, data):
        c = struct.pack(">I", len(data)) + t + data
        return c + struct.pack(">I", zlib.crc32(t + data) & 0xffffffff)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
# a leaf: an ellipse along the card's diagonal, with a row of round holes along its midrib
N = 128
rows = []
for y in range(N):
    r = []
    for x in range(N):
        u, v = (x + 0.5) / N - 0.5, (y + 0.5) / N - 0.5
        a, b = (u + v) / math.sqrt(2), (u - v) / math.sqrt(2)
        inside = (a / 0.48) ** 2 + (b / 0.24) ** 2 <= 1
        for c in (-0.25, 0.0, 0.25):
            if (a - c) ** 2 + (b - 0.1) ** 2 < 0.05 ** 2: inside = False
        r += [255, 255, 255, 255 if inside else 0]
    rows.append(r)
img = png(N, N, rows)
pos, uv, idx = [], [], []
def quad(corners, uvs):
    base = len(pos) // 3
    for p in corners: pos.extend(p)
    for t in uvs: uv.extend(t)
    idx.extend([base, base + 1, base + 2, base, base + 2, base + 3])
quad([(0, 0, 4), (4, 0, 4), (4, 0, 0), (0, 0, 0)], [(0, 0), (1, 0), (1, 1), (0, 1)])  # floor, facing up
nfloor = len(idx)
G, S = 8, 0.55  # 8 x 8 leaves, 0.55 wide, tilted by a pseudo-random angle
for i in range(G):
    for j in range(G):
        cx, cz = 0.25 + (i + 0.5) * 3.5 / G, 0.25 + (j + 0.5) * 3.5 / G
        h = 1.0 + 0.25 * math.sin(3.1 * i + 1.7 * j)
        t = 0.5 * math.sin(2.3 * i - 1.1 * j)
        ex, ey = S / 2 * math.cos(t), S / 2 * math.sin(t)
        quad([(cx - ex, h - ey, cz + S / 2), (cx + ex, h + ey, cz + S / 2), (cx + ex, h + ey, cz - S / 2), (cx - ex, h - ey, cz - S / 2)],
             [(0, 0), (1, 0), (1, 1), (0, 1)])
def write(mode, name):
    buf = struct.pack("<%df" % len(pos), *pos) + struct.pack("<%df" % len(uv), *uv) + struct.pack("<%dI" % len(idx), *idx)
    nv = len(pos) // 3
    g = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
         "nodes": [{"mesh": 0, "name": "floor"}, {"mesh": 1, "name": "leaves"}],
         "materials": [{"name": "floor", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}},
                       {"name": "leaf", "doubleSided": True, "alphaMode": mode, "alphaCutoff": 0.5,
                        "pbrMetallicRoughness": {"baseColorFactor": [0.3, 0.5, 0.2, 1], "baseColorTexture": {"index": 0}}}],
         "meshes": [{"name": "floor", "primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]},
                    {"name": "leaves", "primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 3, "material": 1}]}],
         "images": [{"uri": "data:image/png;base64," + base64.b64encode(img).decode()}],
         "textures": [{"source": 0}],
         "buffers": [{"byteLength": len(buf), "uri": "data:application/octet-stream;base64," + base64.b64encode(buf).decode()}],
         "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 12 * nv},
                         {"buffer": 0, "byteOffset": 12 * nv, "byteLength": 8 * nv},
                         {"buffer": 0, "byteOffset": 20 * nv, "byteLength": 4 * len(idx)}],
         "accessors": [{"bufferView": 0, "componentType": 5126, "count": nv, "type": "VEC3",
                        "min": [min(pos[k::3]) for k in range(3)], "max": [max(pos[k::3]) for k in range(3)]},
                       {"bufferView": 1, "componentType": 5126, "count": nv, "type": "VEC2"},
                       {"bufferView": 2, "componentType": 5125, "count": nfloor, "type": "SCALAR"},
                       {"bufferView": 2, "byteOffset": 4 * nfloor, "componentType": 5125, "count": len(idx) - nfloor, "type": "SCALAR"}]}
    if mode == "OPAQUE": del g["materials"][1]["alphaCutoff"]
    open(d + "/" + name, "w").write(json.dumps(g))
write("MASK", "foliage.gltf")
write("OPAQUE", "foliage_opaque.gltf")
PY
VIEW="--camera 2,0.6,2:2,0,2:0,0,1 --fov 100 --size 64x64 --sky 1,1,1"
secs() {
    awk '/wrote .* in [0-9.]+ s/ { for (i = 1; i <= NF; ++i) if ($i == "in") t = $(i + 1) }
         /^rad trace: [0-9.]+ s \(/ { t = $3 } END { print t }' "$1"
}
{
    echo
    echo "## Alpha-cutout foliage against the path tracer"
    echo
    echo "64 two-sided leaf cards (alphaMode MASK, a leaf-shaped alpha with holes) over a floor under a"
    echo "uniform sky (\`--sky 1,1,1\`), the floor seen from under the canopy (\`$VIEW\`):"
    echo "\`rad render\` at its defaults and \`rad trace --spp $SPP\`, ratio of mean linear radiance and SSIM."
    echo
    echo "| leaves | render (s) | trace (s) | mean render | mean trace | render / trace | SSIM |"
    echo "|---|---:|---:|---:|---:|---:|---:|"
} >> "$OUT"
for f in foliage foliage_opaque ${METHODS:-}; do
    m=""
    scene=$f
    case $f in foliage*) ;; *) m="--method $f" scene=foliage ;; esac
    # shellcheck disable=SC2086
    "$RAD" render "$TMP/$scene.gltf" $VIEW $m -o "$TMP/r.pfm" > "$TMP/r.txt" 2>&1
    # shellcheck disable=SC2086
    [ -n "$m" ] || "$RAD" trace "$TMP/$f.gltf" $VIEW --spp "$SPP" -o "$TMP/t.pfm" > "$TMP/t.txt" 2>&1
    [ "$f" != foliage ] || cp "$TMP/t.pfm" "$TMP/t_cut.pfm"
    [ -z "$m" ] || cp "$TMP/t_cut.pfm" "$TMP/t.pfm"
    "$RAD" compare "$TMP/r.pfm" "$TMP/t.pfm" > "$TMP/c.txt" 2> /dev/null || true
    mr=$(awk '/^mean:/ { print $2 }' "$TMP/c.txt")
    mt=$(awk '/^mean:/ { print $3 }' "$TMP/c.txt")
    ratio=$(awk '/^mean:/ { for (i = 1; i <= NF; ++i) if ($i == "=") print $(i + 1) }' "$TMP/c.txt")
    ssim=$(awk '/^SSIM/ { print $2 }' "$TMP/c.txt")
    printf '| %s | %s | %s | %s | %s | %.4f | %.4f |\n' "$(case $f in foliage) echo "cutout (MASK)" ;; foliage_opaque) echo opaque ;; *) echo "cutout, --method $f" ;; esac)" \
        "$(secs "$TMP/r.txt")" "$(secs "$TMP/t.txt")" "${mr:--}" "${mt:--}" "${ratio:-0}" "${ssim:-0}" >> "$OUT"
done
