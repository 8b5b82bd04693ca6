#!/usr/bin/env bash
# trace.sh - the reference path tracer's noise against time on the built-in Cornell box at
# 256x256: for each spp, two runs with different seeds, their MSE (rad compare: linear values
# clamped to [0,1]) and the time of one run. Appends a table to the file given ($2).
#   bash tests/bench/trace.sh build/rad docs/BENCHMARKS.md
set -eu
. "$(dirname "${BASH_SOURCE[0]}")/machine.sh"
RAD=$1
OUT=$2
TMP=$(mktemp -d "${TMPDIR:-/tmp}/rad_trace_bench.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
{
    echo
    echo "## d) Reference path tracer: noise against samples per pixel"
    echo
    bench_machine
    echo "\`rad trace cornell --size 256x256\` (built-in BVH), two runs with seeds 1 and 2 compared by"
    echo "\`rad compare\` (MSE on linear values clamped to [0,1]); time of one run, $(nproc) threads."
    echo "Target: two seeds within 1e-4 MSE."
    echo
    echo "| spp | MSE between seeds | PSNR (dB) | time of one run (s) |"
    echo "|---:|---:|---:|---:|"
} >> "$OUT"
for spp in 16 32 68 128; do
    t0=$(date +%s.%N)
    "$RAD" trace cornell --size 256x256 --spp $spp --seed 1 -o "$TMP/a.pfm" 2>/dev/null
    t1=$(date +%s.%N)
    "$RAD" trace cornell --size 256x256 --spp $spp --seed 2 -o "$TMP/b.pfm" 2>/dev/null
    cmp=$("$RAD" compare "$TMP/a.pfm" "$TMP/b.pfm")
    mse=$(echo "$cmp" | awk '/MSE/ { for (i = 1; i <= NF; ++i) if ($i ~ /^[0-9.eE+-]+$/) { print $i; exit } }')
    psnr=$(echo "$cmp" | awk '/PSNR/ { for (i = 1; i <= NF; ++i) if ($i ~ /^[0-9.eE+-]+$/) { print $i; exit } }')
    t=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.2f", b - a }')
    echo "| $spp | $mse | $psnr | $t |" | tee -a "$OUT"
done
