#!/usr/bin/env bash
# realtime.sh - the real-time loop over axis-aligned virtual patches (docs/BENCHMARKS.md "Real-time
# loop over AAVP"): tests/bench/realtime.c (proxy build time and peak memory at about 2k and 12k
# patches, per-frame time by stage, lag after a light jump, accuracy against the solve of the
# same patches) on Sponza and the bunny and ogre, then, unless --quick, the converged image of
# `rad render --method temporal --proxy aavp` on Sponza against `rad render --method aavp` (the
# classic solve of the same patches) and against `rad trace`, by `rad compare`.
#   RAD_DATA_DIR=DIR bash tests/bench/realtime.sh [--quick] BUILD_DIR OUT.md
# The meshes are public models outside the repository (docs/data.md); without RAD_DATA_DIR the
# section says it skipped.
set -eu
QUICK=
if [ "${1:-}" = "--quick" ]; then QUICK=--quick; shift; fi
BUILD=$1
OUT=$2
"$BUILD/bench_realtime" $QUICK ${RAD_DATA_DIR:+--data "$RAD_DATA_DIR"} --append "$OUT"
SPONZA="${RAD_DATA_DIR:-}/sponza.obj"
if [ -n "$QUICK" ] || [ -z "${RAD_DATA_DIR:-}" ] || [ ! -r "$SPONZA" ]; then exit 0; fi
TMP=$(mktemp -d "${TMPDIR:-/tmp}/rad_realtime_bench.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
VIEW="--sun 0.3,-1,0.2:3 --point 0,5,0:100 --camera -13,2.5,0:10,5,0:0,1,0 --fov 70 --size 240x135"
metric() { echo "$1" | awk -v k="$2" '$0 ~ k { for (i = 1; i <= NF; ++i) if ($i ~ /^[0-9.eE+-]+$/) { print $i; exit } }'; }
"$BUILD/rad" trace "$SPONZA" $VIEW --spp 256 -o "$TMP/ref.pfm" 2>/dev/null
{
    echo
    echo "Sponza images (240x135, sun + point light at rest, the view of docs/images/sponza_temporal_aavp.png):"
    echo "temporal (300 frames, k 10, adaptive w) and the classic Gauss-Seidel solve of the same AAVP"
    echo "(\`--method aavp --bounces inf\`), each against \`rad trace --spp 256\`, and against each other."
    echo
    echo "| patches at most | temporal vs trace SSIM | PSNR | aavp classic vs trace SSIM | PSNR | temporal vs classic SSIM |"
    echo "|---:|---:|---:|---:|---:|---:|"
} >> "$OUT"
for n in 2000 12000; do
    "$BUILD/rad" render "$SPONZA" $VIEW --method temporal --proxy aavp --vp-max-patches $n --frames 300 -o "$TMP/t.pfm" 2>/dev/null
    "$BUILD/rad" render "$SPONZA" $VIEW --method aavp --vp-max-patches $n --bounces inf -o "$TMP/c.pfm" 2>/dev/null
    a=$("$BUILD/rad" compare "$TMP/t.pfm" "$TMP/ref.pfm")
    b=$("$BUILD/rad" compare "$TMP/c.pfm" "$TMP/ref.pfm")
    c=$("$BUILD/rad" compare "$TMP/t.pfm" "$TMP/c.pfm")
    echo "| $n | $(metric "$a" SSIM) | $(metric "$a" PSNR) | $(metric "$b" SSIM) | $(metric "$b" PSNR) | $(metric "$c" SSIM) |" >> "$OUT"
done
