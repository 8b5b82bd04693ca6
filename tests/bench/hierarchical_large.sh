#!/usr/bin/env bash
# hierarchical_large.sh - hierarchical radiosity on 10^5 triangles and more: the Sponza atrium
# under a sky window, and Sponza with the ogre and the Stanford bunny standing on its floor;
# `rad render --method hierarchical` against `rad trace`: the ratio of mean radiance (energy),
# PSNR, wall and CPU seconds and peak memory (GNU time). Not part of make test.
#   RAD_DATA_DIR=DIR bash tests/bench/hierarchical_large.sh build/rad [EXTRA rad render OPTIONS]
# e.g. --hr-eps 1e-2 --hr-rays 1. The meshes are public models outside the repository
# (docs/data.md); without them it says so and exits 0.
set -eu
RAD=$1
shift
HR_OPTS=${*:---hr-eps 1e-3}
D=${RAD_DATA_DIR:-}
for m in sponza ogre stanford-bunny; do
    if [ -z "$D" ] || [ ! -r "$D/$m.obj" ]; then echo "skipped: no $m.obj in RAD_DATA_DIR (docs/data.md)"; exit 0; fi
done
TMP=$(mktemp -d "${TMPDIR:-/tmp}/rad_hier_large.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
CAMERA="--camera -10,3,0:10,4,0:0,1,0 --fov 60 --size 64x48"
SKY="--area -18,16.5,-8:36,0,0:0,0,16:1"
SPP=${RAD_TRACE_SPP:-128}
# Appends OBJ $1's triangles to $TMP/scene.obj, scaled to height $2 and standing with its
# lowest point at ($3, $4, $5) (fan-triangulated faces; normals and uvs dropped).
place() {
    awk -v H="$2" -v X="$3" -v Y="$4" -v Z="$5" -v base="$(grep -c '^v ' "$TMP/scene.obj" || true)" '
        FNR == NR { if ($1 == "v") { if (n == 0 || $2 < x0) x0 = $2; if (n == 0 || $2 > x1) x1 = $2;
                                     if (n == 0 || $3 < y0) y0 = $3; if (n == 0 || $3 > y1) y1 = $3;
                                     if (n == 0 || $4 < z0) z0 = $4; if (n == 0 || $4 > z1) z1 = $4; n++ } next }
        $1 == "v" { s = H / (y1 - y0); printf "v %.6g %.6g %.6g\n", X + s * ($2 - (x0 + x1) / 2), Y + s * ($3 - y0), Z + s * ($4 - (z0 + z1) / 2); nv++; next }
        $1 == "f" { for (i = 2; i <= NF; i++) { split($i, p, "/"); k[i] = p[1] < 0 ? nv + p[1] + 1 : p[1] }
                    for (i = 3; i < NF; i++) printf "f %d %d %d\n", base + k[2], base + k[i], base + k[i + 1]; next }
    ' "$1" "$1" >> "$TMP/scene.obj"
}
awk '$1 == "v" { print $1, $2, $3, $4; next } $1 == "f" { s = "f"; for (i = 2; i <= NF; i++) { split($i, p, "/"); s = s " " p[1] } print s }' \
    "$D/sponza.obj" > "$TMP/scene.obj"
cp "$TMP/scene.obj" "$TMP/sponza.obj"
place "$D/ogre.obj" 3 -4 0 1
place "$D/stanford-bunny.obj" 2 2 0 -1.5
timed() { /usr/bin/time -f "%e %U %S %M" -o "$TMP/time.txt" "$@"; }
echo "| scene | triangles | options | mean / trace | PSNR (dB) | wall (s) | CPU (s) | peak (MiB) | hierarchical |"
echo "|---|---:|---|---:|---:|---:|---:|---:|---|"
for scene in sponza scene; do
    "$RAD" trace "$TMP/$scene.obj" $SKY $CAMERA --spp "$SPP" -o "$TMP/ref.pfm" > /dev/null 2>&1
    tris=-
    if ! timed "$RAD" render "$TMP/$scene.obj" --method hierarchical $HR_OPTS $SKY $CAMERA -o "$TMP/img.pfm" > "$TMP/log.txt" 2>&1; then
        echo "| $scene | | $HR_OPTS | failed: $(grep -v '%' "$TMP/log.txt" | tail -n 1 | head -c 100 | tr '|' ' ') | | | | | |"
        continue
    fi
    line=$(grep 'hierarchical: ' "$TMP/log.txt" | tail -n 1 | sed 's/^rad render: hierarchical: //')
    tris=$(echo "$line" | sed 's/ triangles.*//')
    "$RAD" compare "$TMP/img.pfm" "$TMP/ref.pfm" > "$TMP/cmp.txt" 2> /dev/null || true
    ratio=$(sed -n 's/.*A \/ B = //p' "$TMP/cmp.txt")
    psnr=$(awk '$1 == "PSNR:" { print $2 }' "$TMP/cmp.txt")
    read -r wall user sys kib < "$TMP/time.txt"
    cpu=$(awk -v u="$user" -v s="$sys" 'BEGIN { printf "%.1f", u + s }')
    echo "| $(test $scene = sponza && echo Sponza || echo 'Sponza + ogre + bunny') | $tris | $HR_OPTS | $ratio | $psnr | $wall | $cpu | $((kib / 1024)) | $(echo "$line" | cut -d, -f2-6) |"
done
