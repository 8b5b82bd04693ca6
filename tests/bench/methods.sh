#!/usr/bin/env bash
# methods.sh - every method of `rad render` against the reference path tracer on the built-in
# Cornell box with each method's defaults: time of the render, the ratio of mean radiance
# (the energy check), PSNR and SSIM (rad compare). Appends a table to the file given ($2).
#   bash tests/bench/methods.sh build/rad docs/BENCHMARKS.md [--quick]
set -eu
. "$(dirname "${BASH_SOURCE[0]}")/machine.sh"
RAD=$1
OUT=$2
QUICK=${3:-}
SIZE=128x128
SPP=4096
if [ "$QUICK" = "--quick" ]; then SIZE=48x48; SPP=256; fi
TMP=$(mktemp -d "${TMPDIR:-/tmp}/rad_methods_bench.XXXXXX")
trap 'rm -rf "$TMP"' EXIT

seconds() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", b - a }'; }
field() { awk -v k="$1" '$1 == k { print $2 }'; }

t0=$(seconds)
"$RAD" trace cornell --size $SIZE --spp $SPP -o "$TMP/ref.pfm" 2> /dev/null
tref=$(elapsed "$t0" "$(seconds)")
{
    echo
    echo "## e) Every method against the path tracer, Cornell box"
    echo
    bench_machine
    echo "\`rad render cornell --size $SIZE --method M\` with the method's defaults against"
    echo "\`rad trace cornell --spp $SPP\` ($tref s), $(nproc) threads. Mean = the ratio of mean linear"
    echo "radiance (1 = no light lost or gained); PSNR and SSIM on values clamped to [0, 1] (\`rad compare\`)."
    echo "Time is the whole command (scene, patches, form factors, solve, pixels)."
    echo
    echo "| method | time (s) | mean / trace | PSNR (dB) | SSIM |"
    echo "|---|---:|---:|---:|---:|"
} >> "$OUT"
# the methods the tool offers, in the order of its help
methods=$("$RAD" render --help 2>&1 | head -n 1 | sed -n 's/.*--method \([a-z|]*\).*/\1/p' | tr '|' ' ')
done_methods=""
for m in $methods stochastic; do
    [ "$m" = pathtrace ] && continue
    case " $done_methods " in *" $m "*) continue ;; esac
    done_methods="$done_methods $m"
    t0=$(seconds)
    if ! "$RAD" render cornell --size $SIZE --method "$m" -o "$TMP/$m.pfm" > /dev/null 2> "$TMP/err.txt"; then
        echo "| $m | failed: $(head -c 80 "$TMP/err.txt" | tr '\n|' '  ') | | | |" >> "$OUT"
        continue
    fi
    t=$(elapsed "$t0" "$(seconds)")
    "$RAD" compare "$TMP/$m.pfm" "$TMP/ref.pfm" > "$TMP/cmp.txt" 2> /dev/null || true
    ratio=$(sed -n 's/.*A \/ B = //p' "$TMP/cmp.txt")
    psnr=$(field PSNR: < "$TMP/cmp.txt")
    ssim=$(field SSIM: < "$TMP/cmp.txt")
    echo "| $m | $t | $ratio | $psnr | $ssim |" >> "$OUT"
done
