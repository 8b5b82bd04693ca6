#!/usr/bin/env bash
# sponza.sh - how much of the light the virtual patches keep on a real building (the accuracy
# that matters to users with real meshes): the Sponza atrium under a sun and under a sky window above the open roof,
# `rad render --method aavp|vp` at about 4k and 12k patches against `rad trace --spp 256`:
# ratio of mean radiance, PSNR and SSIM (`rad compare`), the build's wall time and peak memory.
#   RAD_DATA_DIR=DIR bash tests/bench/sponza.sh build/rad OUT.md
# The mesh is a public model outside the repository (docs/data.md); without it the section
# says it skipped.
set -eu
. "$(dirname "${BASH_SOURCE[0]}")/machine.sh"
RAD=$1
OUT=$2
SPONZA="${RAD_DATA_DIR:-}/sponza.obj"
if [ -z "${RAD_DATA_DIR:-}" ] || [ ! -r "$SPONZA" ]; then
    printf '\n## Sponza against the path tracer\n\nskipped: no sponza.obj in RAD_DATA_DIR (docs/data.md)\n' >> "$OUT"
    exit 0
fi
TMP=$(mktemp -d "${TMPDIR:-/tmp}/rad_sponza_bench.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
CAMERA="--camera -10,3,0:10,4,0:0,1,0 --fov 60 --size 64x48"
SUN="--sun 0.3,-1,0.2:3"
SKY="--area -18,16.5,-8:36,0,0:0,0,16:1"
field() { awk -v k="$1" '$1 == k { print $2 }'; }
# wall seconds and peak KiB into $TMP/time.txt when GNU time is there
timed() { if [ -x /usr/bin/time ]; then /usr/bin/time -f "%e %M" -o "$TMP/time.txt" "$@"; else "$@"; fi; }
"$RAD" trace "$SPONZA" $SUN $CAMERA --spp 256 -o "$TMP/ref_sun.pfm" 2> /dev/null
"$RAD" trace "$SPONZA" $SKY $CAMERA --spp 256 -o "$TMP/ref_sky.pfm" 2> /dev/null
{
    echo
    echo "## Sponza against the path tracer"
    echo
    bench_machine
    echo "The Dabrovic Sponza atrium (66 453 triangles, one stone albedo), \`$CAMERA\`, lit by a sun"
    echo "(\`$SUN\`) or by a one-sided sky window above the open roof (\`$SKY\`), so most of the"
    echo "building sees bounced light only. \`rad bake --method M --vp-resolution R\` then"
    echo "\`rad render --method M --bake\` against \`rad trace --spp 256\`: the ratio of mean linear radiance"
    echo "(1 = no light lost), PSNR and SSIM (\`rad compare\`); the bake's wall time and peak RSS"
    echo "(GNU time), $(nproc) threads."
    echo
    echo "| light | method | resolution | patches | mean / trace | PSNR (dB) | SSIM | bake (s) | peak (MiB) |"
    echo "|---|---|---:|---:|---:|---:|---:|---:|---:|"
} >> "$OUT"
for light in sun sky; do
    if [ $light = sun ]; then L=$SUN; else L=$SKY; fi
    for mr in "aavp 16" "aavp 28" "vp 16" "vp 23"; do
        set -- $mr
        echo "- -" > "$TMP/time.txt"
        if ! timed "$RAD" bake "$SPONZA" --method "$1" --vp-resolution "$2" $L \
                -o "$TMP/set.radb" > "$TMP/bake.txt" 2>&1; then
            echo "| $light | $1 | $2 | failed: $(tail -n 1 "$TMP/bake.txt" | head -c 80 | tr '|' ' ') | | | | | |" >> "$OUT"
            continue
        fi
        patches=$(sed -n 's/.*, \([0-9]*\) virtual patches.*/\1/p' "$TMP/bake.txt" | tail -n 1)
        "$RAD" render "$SPONZA" --method "$1" --bake "$TMP/set.radb" $L $CAMERA -o "$TMP/img.pfm" > /dev/null 2>&1
        "$RAD" compare "$TMP/img.pfm" "$TMP/ref_$light.pfm" > "$TMP/cmp.txt" 2> /dev/null || true
        ratio=$(sed -n 's/.*A \/ B = //p' "$TMP/cmp.txt")
        psnr=$(field PSNR: < "$TMP/cmp.txt")
        ssim=$(field SSIM: < "$TMP/cmp.txt")
        read -r secs kib < "$TMP/time.txt"
        mib=-
        [ "$kib" != - ] && mib=$((kib / 1024))
        echo "| $light | $1 | $2 | $patches | $ratio | $psnr | $ssim | $secs | $mib |" >> "$OUT"
    done
done
