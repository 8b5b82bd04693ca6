#!/usr/bin/env bash
# direct_noise.sh - per-pixel direct light under an emitter larger than the opening it shines
# through: a 10 x 5 x 10 room open at the top (walls facing in, albedo 0.7) under a 40 x 40
# area light of radiance 1 one unit above the walls, seen from inside. Every radiosity method
# given renders it at the tool's defaults and is compared with `rad trace` at REF_SPP samples
# per pixel (SSIM, PSNR, mean over the reference's mean); with a second binary (BEFORE) the
# same rows for it, measured in the same run. Then the CPU time (user + system, one thread) of
# a default classic render of the built-in Cornell box with each binary, and the same room
# under a uniform sky (--sky 1, no area light) when SKY=1.
#   bash tests/bench/direct_noise.sh build/rad [OUT.md] [BEFORE_RAD]
# Environment: SIZE (default 256x256), REF_SPP (default 4096: about 20 CPU minutes at 256x256),
# REF (an existing reference .pfm of the same SIZE to reuse), METHODS (default
# "classic aavp lightmap"), SKY (0).
set -eu
RAD=$1
OUT=${2:-/dev/stdout}
BEFORE=${3:-}
SIZE=${SIZE:-256x256}
REF_SPP=${REF_SPP:-4096}
METHODS=${METHODS:-classic aavp lightmap}
SKY=${SKY:-0}
TMP=$(mktemp -d "${TMPDIR:-/tmp}/rad_direct_noise.XXXXXX")
trap 'rm -rf "$TMP"' EXIT

cat > "$TMP/room.obj" <<'EOF'
mtllib room.mtl
usemtl wall
v 0 0 0
v 10 0 0
v 10 0 10
v 0 0 10
v 0 5 0
v 10 5 0
v 10 5 10
v 0 5 10
o floor
f 1 4 3
f 1 3 2
o wall_z0
f 1 2 6
f 1 6 5
o wall_z10
f 4 8 7
f 4 7 3
o wall_x0
f 1 5 8
f 1 8 4
o wall_x10
f 2 3 7
f 2 7 6
EOF
printf 'newmtl wall\nKd 0.7 0.7 0.7\n' > "$TMP/room.mtl"
CAM=(--camera 9.5,4.5,9.5:2,0,2:0,1,0 --fov 70 --size "$SIZE")
PANEL=(--area -15,6,-15:40,0,0:0,0,40:1)

# cpu_seconds FILE CMD...: runs CMD on one thread, writes its user + system seconds to FILE
cpu_seconds() {
    local f=$1
    shift
    local TIMEFORMAT='%U %S'
    { time OMP_NUM_THREADS=1 "$@" > /dev/null 2>&1; } 2> "$f.t"
    awk '{ printf "%.1f", $1 + $2 }' "$f.t" > "$f"
}

# row LABEL RAD METHOD LIGHTS...: one table row against $TMP/ref_$SCENE.pfm
row() {
    local label=$1 bin=$2 method=$3
    shift 3
    cpu_seconds "$TMP/cpu" "$bin" render "$TMP/room.obj" "${CAM[@]}" "$@" --method "$method" -o "$TMP/img.pfm"
    local cmp ssim psnr ratio
    cmp=$("$RAD" compare "$TMP/img.pfm" "$TMP/ref_$SCENE.pfm")
    ssim=$(echo "$cmp" | awk '/^SSIM/ { print $2 }')
    psnr=$(echo "$cmp" | awk '/^PSNR/ { print $2 }')
    ratio=$(echo "$cmp" | awk '/A \/ B/ { print $NF }')
    echo "| $SCENE | $method | $label | $ssim | $psnr | $ratio | $(cat "$TMP/cpu") |" >> "$OUT"
}

reference() {
    if [ -n "${REF:-}" ] && [ "$SCENE" = panel ]; then
        cp "$REF" "$TMP/ref_$SCENE.pfm"
    else
        "$RAD" trace "$TMP/room.obj" "${CAM[@]}" "$@" --spp "$REF_SPP" -o "$TMP/ref_$SCENE.pfm" 2> /dev/null
    fi
}

{
    echo
    echo "## Direct light under a large emitter"
    echo
    echo "An open 10 x 5 x 10 room under a 40 x 40 area light (and, with SKY=1, under a uniform sky),"
    echo "$SIZE, each method at the tool's defaults against \`rad trace\` at $REF_SPP spp. CPU: user +"
    echo "system seconds of the whole render on one thread. Target: SSIM >= 0.98, mean within 3%."
    echo
    echo "| scene | method | binary | SSIM | PSNR (dB) | mean / reference | CPU (s) |"
    echo "|---|---|---|---:|---:|---:|---:|"
} >> "$OUT"

SCENE=panel
reference "${PANEL[@]}"
for m in $METHODS; do
    [ -n "$BEFORE" ] && row before "$BEFORE" "$m" "${PANEL[@]}"
    row after "$RAD" "$m" "${PANEL[@]}"
done
if [ "$SKY" = 1 ]; then
    SCENE=sky
    reference --sky 1
    for m in $METHODS; do
        [ -n "$BEFORE" ] && row before "$BEFORE" "$m" --sky 1
        row after "$RAD" "$m" --sky 1
    done
fi

{
    echo
    echo "| Cornell box, \`rad render cornell\` (classic, defaults) | CPU (s) |"
    echo "|---|---:|"
} >> "$OUT"
if [ -n "$BEFORE" ]; then
    cpu_seconds "$TMP/cpu" "$BEFORE" render cornell -o "$TMP/c.pfm"
    echo "| before | $(cat "$TMP/cpu") |" >> "$OUT"
fi
cpu_seconds "$TMP/cpu" "$RAD" render cornell -o "$TMP/c.pfm"
echo "| after | $(cat "$TMP/cpu") |" >> "$OUT"
