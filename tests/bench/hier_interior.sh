#!/usr/bin/env bash
# hier_interior.sh - a furnished interior of 150k+ triangles for hierarchical radiosity at scale:
# the Sponza atrium (stone) with the Nefertiti bust (painted plaster) on its floor, 166k
# triangles (HIER_OGRE=1 adds the ogre, clay, for 290k), lit by an emissive panel over the open roof (Ke 10, facing down).
# Writes OUT.obj and OUT.mtl, or with a rad binary also runs `rad render --method hierarchical`
# and `rad trace` and prints the energy ratio (rad compare), CPU seconds and peak memory.
#   RAD_DATA_DIR=DIR bash tests/bench/hier_interior.sh OUT                  (scene only)
#   RAD_DATA_DIR=DIR bash tests/bench/hier_interior.sh OUT build/rad [rad render options]
# The meshes are public models outside the repository (docs/data.md); without them it says so
# and exits 0. Not part of make test. RAD_TRACE_SPP (default 256) sets the reference's samples.
set -eu
OUT=$1
shift
RAD=${1:-}
[ $# -gt 0 ] && shift
D=${RAD_DATA_DIR:-}
for m in sponza nefertiti ${HIER_OGRE:+ogre}; do
    if [ -z "$D" ] || [ ! -r "$D/$m.obj" ]; then echo "skipped: no $m.obj in RAD_DATA_DIR (docs/data.md)"; exit 0; fi
done
{
    echo "newmtl stone"; echo "Kd 0.7 0.68 0.63"
    echo "newmtl clay"; echo "Kd 0.55 0.45 0.35"
    echo "newmtl plaster"; echo "Kd 0.8 0.75 0.6"
    echo "newmtl panel"; echo "Kd 0 0 0"; echo "Ke 10 10 10"
} > "$OUT.mtl"
# Appends OBJ $1's triangles with material $2, scaled to height $3 and standing with its lowest
# point at ($4, $5, $6) (faces fan-triangulated; normals and uvs dropped).
place() {
    awk -v M="$2" -v H="$3" -v X="$4" -v Y="$5" -v Z="$6" -v base="$(grep -c '^v ' "$OUT.obj" || true)" '
        FNR == NR { if ($1 == "v") { if (n == 0 || $2 < x0) x0 = $2; if (n == 0 || $2 > x1) x1 = $2;
                                     if (n == 0 || $3 < y0) y0 = $3; if (n == 0 || $3 > y1) y1 = $3;
                                     if (n == 0 || $4 < z0) z0 = $4; if (n == 0 || $4 > z1) z1 = $4; n++ } next }
        FNR == 1 { print "usemtl " M }
        $1 == "v" { s = H / (y1 - y0); printf "v %.6g %.6g %.6g\n", X + s * ($2 - (x0 + x1) / 2), Y + s * ($3 - y0), Z + s * ($4 - (z0 + z1) / 2); nv++; next }
        $1 == "f" { for (i = 2; i <= NF; i++) { split($i, p, "/"); k[i] = p[1] < 0 ? nv + p[1] + 1 : p[1] }
                    for (i = 3; i < NF; i++) printf "f %d %d %d\n", base + k[2], base + k[i], base + k[i + 1]; next }
    ' "$1" "$1" >> "$OUT.obj"
}
{
    echo "mtllib $(basename "$OUT").mtl"
    echo "usemtl stone"
    awk '$1 == "v" { print $1, $2, $3, $4; next } $1 == "f" { s = "f"; for (i = 2; i <= NF; i++) { split($i, p, "/"); s = s " " p[1] } print s }' "$D/sponza.obj"
} > "$OUT.obj"
[ -z "${HIER_OGRE:-}" ] || place "$D/ogre.obj" clay 3 -4 0.09 1
place "$D/nefertiti.obj" plaster 1.5 3 0.09 -1.5
# the panel: 36 x 16 at y = 16.5 over the roof opening, wound to face down
nv=$(grep -c '^v ' "$OUT.obj")
{
    echo "usemtl panel"
    echo "v -18 16.5 -8"; echo "v 18 16.5 -8"; echo "v 18 16.5 8"; echo "v -18 16.5 8"
    echo "f $((nv + 1)) $((nv + 2)) $((nv + 3))"; echo "f $((nv + 1)) $((nv + 3)) $((nv + 4))"
} >> "$OUT.obj"
echo "wrote $OUT.obj: $(grep -c '^f ' "$OUT.obj") triangles"
[ -n "$RAD" ] || exit 0
CAMERA="--camera -10,3,0:10,4,0:0,1,0 --fov 60 --size 64x48"
SPP=${RAD_TRACE_SPP:-256}
if [ ! -r "$OUT.ref.pfm" ]; then
    /usr/bin/time -f "trace: %U %S user/sys s, %M KiB" "$RAD" trace "$OUT.obj" $CAMERA --spp "$SPP" -o "$OUT.ref.pfm" > /dev/null
fi
/usr/bin/time -f "hierarchical: %U %S user/sys s, %M KiB peak" "$RAD" render "$OUT.obj" --method hierarchical $CAMERA "$@" -o "$OUT.hr.pfm" 2>&1 |
    tr '\r' '\n' | grep -v '%' || true
"$RAD" compare "$OUT.hr.pfm" "$OUT.ref.pfm" 2>&1 | grep -i "A / B\|PSNR\|SSIM" || true
