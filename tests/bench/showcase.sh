#!/usr/bin/env bash
# showcase.sh - the README picture: tests/data/showcase.gltf (a room with single-sheet two-sided
# walls, a curtain, alpha-masked leaf cards and an emissive-textured screen, lit through its
# window by the procedural sky tests/data/showcase_sky.hdr; tests/data/mk_showcase.py makes
# both) rendered by `rad render` at its defaults (every setting but the image size is the
# tool's) beside `rad trace`, written side by side (radiosity left, path tracer right) as one
# PNG, with the energy ratio (mean linear radiance, render / trace) and SSIM of `rad compare`.
# Never part of make test (a few minutes on 2 cores).
#   bash tests/bench/showcase.sh [RAD [OUT.png]]   (default build/rad, docs/images/showcase.png)
# Environment: SIZE (default 256x256), SPP (trace samples per pixel, default 256), EXPOSURE
# (of the PNG only, default 1), KEEP=DIR keeps the .pfm images and the logs there.
set -eu
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
RAD=${1:-$HERE/build/rad}
OUT=${2:-$HERE/docs/images/showcase.png}
SIZE=${SIZE:-256x256}
SPP=${SPP:-256}
EXPOSURE=${EXPOSURE:-1}
SCENE=$HERE/tests/data/showcase.gltf
SKY=$HERE/tests/data/showcase_sky.hdr
TMP=${KEEP:-$(mktemp -d "${TMPDIR:-/tmp}/rad_showcase.XXXXXX")}
mkdir -p "$TMP"
[ -n "${KEEP:-}" ] || trap 'rm -rf "$TMP"' EXIT
t0=$(date +%s.%N)
"$RAD" render "$SCENE" --env "$SKY" --size "$SIZE" -o "$TMP/render.pfm" > "$TMP/render.log" 2>&1 ||
    { cat "$TMP/render.log" >&2; exit 1; }
t1=$(date +%s.%N)
"$RAD" trace "$SCENE" --env "$SKY" --size "$SIZE" --spp "$SPP" -o "$TMP/trace.pfm" > "$TMP/trace.log" 2>&1 ||
    { cat "$TMP/trace.log" >&2; exit 1; }
t2=$(date +%s.%N)
"$RAD" compare "$TMP/render.pfm" "$TMP/trace.pfm" > "$TMP/compare.txt"
# side by side: linear radiance x EXPOSURE, sRGB-encoded, a 4-pixel dark gap between
python3 - "$TMP/render.pfm" "$TMP/trace.pfm" "$OUT" "$EXPOSURE" << 'EOF'
import struct, sys, zlib
def pfm(path):
    f = open(path, 'rb')
    kind = f.readline().strip()
    w, h = map(int, f.readline().split())
    scale = float(f.readline())
    n = 3 if kind == b'PF' else 1
    data = struct.unpack(('<' if scale < 0 else '>') + 'f' * (w * h * n), f.read(4 * w * h * n))
    rows = [data[(h - 1 - j) * w * n:(h - j) * w * n] for j in range(h)]  # PFM rows run bottom to top
    return w, h, [[tuple(r[i * n + (k if n == 3 else 0)] for k in range(3)) for i in range(w)] for r in rows]
def srgb(x):
    x = min(max(x, 0.0), 1.0)
    return int(255 * (12.92 * x if x <= 0.0031308 else 1.055 * x ** (1 / 2.4) - 0.055) + 0.5)
(wa, ha, a), (wb, hb, b), e = pfm(sys.argv[1]), pfm(sys.argv[2]), float(sys.argv[4])
gap = 4
rows = []
for j in range(ha):
    row = [tuple(srgb(c * e) for c in p) for p in a[j]] + [(16, 16, 16)] * gap + [tuple(srgb(c * e) for c in p) for p in b[j]]
    rows.append(row)
raw = b''.join(b'\0' + bytes(v for px in r for v in px) for r in rows)
chunk = lambda t, d: struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d) & 0xffffffff)
open(sys.argv[3], 'wb').write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', len(rows[0]), len(rows), 8, 2, 0, 0, 0)) +
                              chunk(b'IDAT', zlib.compress(raw, 9)) + chunk(b'IEND', b''))
EOF
ratio=$(awk '/^mean:/ { for (i = 1; i <= NF; ++i) if ($i == "=") print $(i + 1) }' "$TMP/compare.txt")
ssim=$(awk '/^SSIM/ { print $2 }' "$TMP/compare.txt")
tr=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", b - a }')
tt=$(awk -v a="$t1" -v b="$t2" 'BEGIN { printf "%.1f", b - a }')
echo "showcase $SIZE: rad render (defaults) ${tr} s, rad trace --spp $SPP ${tt} s; energy render / trace = $ratio, SSIM $ssim"
grep -h "warning" "$TMP/render.log" | sort -u | sed 's/^/  render: /' || true
echo "wrote $OUT"
