#!/usr/bin/env bash
# assets.sh - emissive glTF assets: the tool's default render (`rad render`, classic radiosity
# with per-pixel direct light) against the path tracer (`rad trace --spp 256`), the ratio of
# mean linear radiance (1 = the importer and the solver keep all the emitted light) and SSIM
# (`rad compare`). The assets: the glTF Cornell boxes of tests/data (the lamp's radiance as
# emissiveFactor x KHR_materials_emissive_strength, plain and with a checker emissiveTexture),
# and every .gltf / .glb with "emissive" in its JSON found in RAD_DATA_DIR or in the folder
# given as the third argument (for instance the Khronos glTF sample models' EmissiveStrengthTest,
# which is not part of this repository). Never part of make test.
#   bash tests/bench/assets.sh build/rad OUT.md [DIR]
set -eu
. "$(dirname "${BASH_SOURCE[0]}")/machine.sh"
RAD=$1
OUT=$2
DIR=${3:-${RAD_DATA_DIR:-}}
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
TMP=$(mktemp -d "${TMPDIR:-/tmp}/rad_assets_bench.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
SIZE="--size 64x64"
assets="$HERE/tests/data/cornell.gltf $HERE/tests/data/cornell_textured.gltf"
if [ -n "$DIR" ] && [ -d "$DIR" ]; then
    for f in "$DIR"/*.gltf "$DIR"/*.glb "$DIR"/*/*.gltf "$DIR"/*/glTF/*.gltf; do
        [ -r "$f" ] && grep -aq emissive "$f" && assets="$assets $f"
    done
fi
{
    echo
    echo "## Emissive glTF assets against the path tracer"
    echo
    bench_machine
    echo "\`rad render\` (default: classic radiosity, per-pixel direct light) and \`rad trace --spp 256\`, \`$SIZE\`,"
    echo "the file's camera or the default framing; ratio of mean linear radiance and SSIM (\`rad compare\`)."
    echo
    echo "| asset | triangles | render (s) | trace (s) | mean render / trace | SSIM |"
    echo "|---|---:|---:|---:|---:|---:|"
} >> "$OUT"
# seconds: render prints "wrote F (WxH, method) in S s", trace "rad trace: S s (N samples/s)"
secs() {
    awk '/wrote .* in [0-9.]+ s/ { for (i = 1; i <= NF; ++i) if ($i == "in") t = $(i + 1) }
         /^rad trace: [0-9.]+ s \(/ { t = $3 } END { print t }' "$1"
}
for f in $assets; do
    name=$(basename "$f")
    if ! "$RAD" render "$f" $SIZE -o "$TMP/r.pfm" > "$TMP/r.txt" 2>&1 ||
        ! "$RAD" trace "$f" $SIZE --spp 256 -o "$TMP/t.pfm" > "$TMP/t.txt" 2>&1; then
        echo "| $name | - | - | - | failed: $(tail -1 "$TMP/r.txt" "$TMP/t.txt" | tr '|\n' '/ ' | head -c 120) | - |" >> "$OUT"
        continue
    fi
    tris=$("$RAD" info "$f" 2> /dev/null | awk 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i ~ /^triangles/) print $(i - 1) }')
    "$RAD" compare "$TMP/r.pfm" "$TMP/t.pfm" > "$TMP/c.txt" 2> /dev/null || true
    ratio=$(awk '/^mean:/ { for (i = 1; i <= NF; ++i) if ($i == "=") print $(i + 1) }' "$TMP/c.txt")
    ssim=$(awk '/^SSIM/ { print $2 }' "$TMP/c.txt")
    printf '| %s | %s | %s | %s | %.4f | %.4f |\n' "$name" "${tris:--}" "$(secs "$TMP/r.txt")" "$(secs "$TMP/t.txt")" \
        "${ratio:-0}" "${ssim:-0}" >> "$OUT"
done
