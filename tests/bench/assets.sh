#!/usr/bin/env bash
# assets.sh - real glTF assets, as shipped, at the tool's defaults against the path tracer.
# Every asset is rendered by `rad render` with its default method (classic radiosity with
# per-pixel direct light) and with --method aavp, vp and lightmap, every other setting the
# tool's own but the image size, and by `rad trace --spp SPP` (once per asset); the table has
# the ratio of mean linear radiance (render / trace: 1 = the importer and the method keep all
# the light) and SSIM (`rad compare`), and the wall and CPU seconds of each render (the
# machine's load is printed: on a shared machine compare CPU seconds, not wall).
# The assets:
#   - tests/data: the glTF Cornell boxes (emissiveFactor x KHR_materials_emissive_strength,
#     plain and with a checker emissiveTexture), the showcase room (showcase.glb: two-sided
#     single-sheet walls and curtain, alpha-masked leaf cards, an emissive-textured screen)
#     lit by its sky showcase_sky.hdr, and Blender's exported test scenes of
#     tests/data/gltf-blender-io (doubleSided spheres, alpha mask and blend quads, 18 emissive
#     spheres) and the Khronos sample model TextureTransformTest;
#   - every .gltf / .glb in DIR (the third argument, else RAD_DATA_DIR) and its subfolders
#     down to DIR/NAME/glTF*/ (the layout of the Khronos glTF sample assets) whose JSON has
#     "emissive", "doubleSided" or "alphaMode": for instance the Khronos sample models
#     EmissiveStrengthTest, TwoSidedPlane, AlphaBlendModeTest (docs/data.md says where to get
#     them).
# A scene with no emitter of its own is lit by a uniform sky of radiance 1 (--sky 1), the same
# for render and trace. A dense build (classic, lightmap) over MAXTRIS triangles (default
# 5000: every triangle is at least one patch, so an N x N matrix) is listed as skipped with its
# triangle count unless MAXTRIS is raised. Never part of make test.
#   bash tests/bench/assets.sh build/rad OUT.md [DIR]
# Environment: SIZE (default 64x64), SPP (default 512), METHODS (default "default aavp vp
# lightmap"), MAXTRIS, ONLY (an extended regular expression: only the assets whose name
# matches).
set -eu
. "$(dirname "${BASH_SOURCE[0]}")/machine.sh"
RAD=$1
OUT=$2
DIR=${3:-${RAD_DATA_DIR:-}}
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
TMP=$(mktemp -d "${TMPDIR:-/tmp}/rad_assets_bench.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
SIZE=${SIZE:-64x64}
SPP=${SPP:-512}
METHODS=${METHODS:-default aavp vp lightmap}
MAXTRIS=${MAXTRIS:-5000}
D=$HERE/tests/data
B=$D/gltf-blender-io
# NAME|FILE|LIGHT ARGUMENTS ("" for the file's own emitters, "auto": the sky when it has none)
assets="cornell.gltf|$D/cornell.gltf|
cornell_textured.gltf|$D/cornell_textured.gltf|
showcase.glb|$D/showcase.glb|--env $D/showcase_sky.hdr
blender 01_single_vs_double_sided|$B/01_single_vs_double_sided/01_single_vs_double_sided.gltf|auto
blender 01_alpha_mask|$B/01_alpha_mask/01_alpha_mask.gltf|auto
blender 01_alpha_blend|$B/01_alpha_blend/01_alpha_blend.gltf|auto
blender 14_emission_strength|$B/14_emission_strength/14_emission_strength.gltf|auto
khronos TextureTransformTest|$D/khronos/TextureTransformTest/TextureTransformTest.gltf|auto"
if [ -n "$DIR" ] && [ -d "$DIR" ]; then
    for f in "$DIR"/*.gltf "$DIR"/*.glb "$DIR"/*/*.gltf "$DIR"/*/*.glb "$DIR"/*/glTF*/*.gltf "$DIR"/*/glTF*/*.glb; do
        [ -r "$f" ] && grep -aqE 'emissive|doubleSided|alphaMode' "$f" &&
            assets="$assets
$(basename "$f")|$f|auto"
    done
fi
cpu_wall() { # LOG of bash's time (TIMEFORMAT "%R %U %S"): "wall cpu"
    awk 'END { printf "%.1f %.1f", $1, $2 + $3 }' "$1"
}
{
    echo
    echo "## Real glTF assets at the tool's defaults against the path tracer"
    echo
    bench_machine
    echo "\`rad render\` at its defaults (the default method, classic, and aavp, vp, lightmap) against"
    echo "\`rad trace --spp $SPP\`, \`--size $SIZE\`, the file's camera or the tool's framing; energy = mean"
    echo "linear radiance render / trace, SSIM of \`rad compare\`; seconds wall / CPU."
    echo
    echo "| asset | triangles | light | method | render s (wall / CPU) | trace s (wall / CPU) | energy | SSIM |"
    echo "|---|---:|---|---|---:|---:|---:|---:|"
} >> "$OUT"
TIMEFORMAT="%R %U %S"
printf '%s\n' "$assets" | while IFS='|' read -r name f light; do
    [ -n "$name" ] || continue
    [ -z "${ONLY:-}" ] || printf '%s\n' "$name" | grep -qE "$ONLY" || continue
    if ! "$RAD" info "$f" > "$TMP/info.txt" 2> "$TMP/info.err"; then
        echo "| $name | - | - | - | - | - | import failed: $(tail -1 "$TMP/info.err" | tr '|\n' '/ ' | head -c 120) | - |" >> "$OUT"
        continue
    fi
    tris=$(awk 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i ~ /^triangles/) print $(i - 1) }' "$TMP/info.txt")
    if [ "$light" = auto ]; then
        if grep -q "emission (radiance)" "$TMP/info.txt"; then light=""; else light="--sky 1"; fi
    fi
    shown=${light:-own emitters}
    shown=${shown//$D\//}
    # shellcheck disable=SC2086
    if ! { time "$RAD" trace "$f" $light --size "$SIZE" --spp "$SPP" -o "$TMP/t.pfm" > "$TMP/t.txt" 2>&1; } 2> "$TMP/t.time"; then
        echo "| $name | $tris | $shown | - | - | - | trace failed: $(tail -1 "$TMP/t.txt" | tr '|\n' '/ ' | head -c 120) | - |" >> "$OUT"
        continue
    fi
    tt=$(cpu_wall "$TMP/t.time")
    for m in $METHODS; do
        margs=""
        [ "$m" = default ] || margs="--method $m"
        if { [ "$m" = default ] || [ "$m" = lightmap ]; } && [ "${tris:-0}" -gt "$MAXTRIS" ]; then
            echo "| $name | $tris | $shown | $m | skipped: dense build of $tris patches (MAXTRIS=$MAXTRIS) | ${tt// / / } | - | - |" >> "$OUT"
            continue
        fi
        # shellcheck disable=SC2086
        if ! { time "$RAD" render "$f" $light $margs --size "$SIZE" -o "$TMP/r.pfm" > "$TMP/r.txt" 2>&1; } 2> "$TMP/r.time"; then
            echo "| $name | $tris | $shown | $m | failed: $(grep -v '%$' "$TMP/r.txt" | tail -1 | tr '|\n' '/ ' | head -c 120) | ${tt// / / } | - | - |" >> "$OUT"
            continue
        fi
        "$RAD" compare "$TMP/r.pfm" "$TMP/t.pfm" > "$TMP/c.txt" 2> /dev/null || true
        ratio=$(awk '/^mean:/ { for (i = 1; i <= NF; ++i) if ($i == "=") print $(i + 1) }' "$TMP/c.txt")
        ssim=$(awk '/^SSIM/ { print $2 }' "$TMP/c.txt")
        rt=$(cpu_wall "$TMP/r.time")
        printf '| %s | %s | %s | %s | %s | %s | %.4f | %.4f |\n' "$name" "${tris:--}" "$shown" "$m" "${rt// / / }" "${tt// / / }" \
            "${ratio:-0}" "${ssim:-0}" >> "$OUT"
    done
done
