#!/usr/bin/env bash
# scenes.sh - the test scene set beyond the Cornell box: every method of `rad render` at the
# tool's defaults (no option but the light and the camera) against `rad trace`, on
#   sponza-sky    the Sponza atrium under a one-sided sky window above its open roof
#   sponza-sun    the same under a sun
#   sponza-point  the same lit by a point light in the middle of the court
#   open-room     a generated room lit through a ceiling opening by an emitter larger than the
#                 opening (tests/data/open_room.sh, 11 202 triangles)
#   sponza-bust   166k triangles: the atrium with the Nefertiti bust on its floor under an
#                 emissive panel over the open roof (tests/bench/hier_interior.sh's scene; needs
#                 RAD_DATA_DIR/nefertiti.obj too), against a trace of 8 x SPP samples: at SPP the
#                 trace's own noise under the panel caps the SSIM near 0.87
#   interior      a furnished interior: RAD_DATA_DIR/interior.obj (with its .mtl) when there is
#                 one, and its light in RAD_DATA_DIR/interior.lights (rad options, one line)
# One markdown table to the file given ($2): the ratio of mean linear radiance (1 = no light
# lost or gained), PSNR and SSIM (`rad compare`), the CPU time (user + system) and wall time of
# the whole command, and its peak RSS (GNU time), with what the default chose.
#   RAD_DATA_DIR=DIR bash tests/bench/scenes.sh build/rad OUT.md
# Environment: SCENES and METHODS (space-separated subsets, in the order given), SIZE (64x48),
# SPP (the reference's samples per pixel, 256). The Sponza rows need RAD_DATA_DIR/sponza.obj
# (docs/data.md); a scene without its data says so in the table.
set -u
RAD=$1
OUT=$2
SIZE=${SIZE:-64x48}
SPP=${SPP:-256}
SCENES=${SCENES:-"open-room sponza-sky sponza-sun sponza-point sponza-bust interior"}
METHODS=${METHODS:-"default aavp vp temporal lightmap hierarchical classic"}
TMP=$(mktemp -d "${TMPDIR:-/tmp}/rad_scenes_bench.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
DATA=${RAD_DATA_DIR:-}
field() { awk -v k="$1" '$1 == k { print $2 }'; }
# "wall cpu peak_kib" of the command into $TMP/time.txt (dashes without GNU time)
timed() {
    echo "- - -" > "$TMP/time.txt"
    if [ -x /usr/bin/time ]; then
        /usr/bin/time -f "%e %U %S %M" -o "$TMP/time.raw" "$@" && rc=0 || rc=$?
        awk 'END { if (NF >= 4) printf "%.1f %.1f %d\n", $1, $2 + $3, $4 / 1024 }' "$TMP/time.raw" > "$TMP/time.txt"
        return $rc
    fi
    "$@"
}
{
    echo
    echo "## The scene set: every method at its defaults against the path tracer"
    echo
    echo "\`rad render SCENE --method M\` with nothing but the light and the camera (\`default\`: no"
    echo "\`--method\`, the tool's choice, shown), $SIZE, against \`rad trace --spp $SPP\` of the same view (sponza-bust: 8 times as many)."
    echo "Mean = the ratio of mean linear radiance; PSNR and SSIM on values clamped to [0, 1]"
    echo "(\`rad compare\`); CPU = user + system seconds of the whole command, peak = its peak RSS"
    echo "(GNU time); $(nproc) threads, load $(cut -d' ' -f1-3 /proc/loadavg) at the start."
    echo
    echo "| scene | triangles | method | chose | patches | mean / trace | PSNR (dB) | SSIM | CPU (s) | wall (s) | peak (MiB) |"
    echo "|---|---:|---|---|---:|---:|---:|---:|---:|---:|---:|"
} >> "$OUT"
for scene in $SCENES; do
    CAM=
    spp=$SPP
    case $scene in
    sponza-bust)
        FILE="$TMP/sponza_bust.obj"
        RAD_DATA_DIR="$DATA" bash "$(dirname "$0")/hier_interior.sh" "$TMP/sponza_bust" > /dev/null
        CAM="--camera -10,3,0:10,4,0:0,1,0 --fov 60"
        LIGHT=
        spp=$((8 * SPP))
        ;;
    sponza-*)
        FILE="$DATA/sponza.obj"
        CAM="--camera -10,3,0:10,4,0:0,1,0 --fov 60"
        case $scene in
        sponza-sky) LIGHT="--area -18,16.5,-8:36,0,0:0,0,16:1" ;;
        sponza-sun) LIGHT="--sun 0.3,-1,0.2:3" ;;
        *) LIGHT="--point 0,6,0:60" ;;
        esac
        ;;
    open-room)
        bash "$(dirname "$0")/../data/open_room.sh" "$TMP/open_room" 20
        FILE="$TMP/open_room.obj"
        CAM="--camera 0.3,1.6,3.7:2.6,0.6,1.2:0,1,0 --fov 70"
        LIGHT=
        ;;
    interior)
        FILE="$DATA/interior.obj"
        LIGHT=$(cat "$DATA/interior.lights" 2> /dev/null || true)
        ;;
    *) echo "| $scene | | | unknown scene | | | | | | | |" >> "$OUT"; continue ;;
    esac
    if [ ! -r "$FILE" ]; then
        echo "| $scene | | | skipped: no $(basename "$FILE") in RAD_DATA_DIR (docs/data.md) | | | | | | | |" >> "$OUT"
        continue
    fi
    tris=$("$RAD" info "$FILE" 2> /dev/null | sed -n 's/.* \([0-9][0-9]*\) triangles.*/\1/p' | head -n 1)
    # shellcheck disable=SC2086
    if ! "$RAD" trace "$FILE" $LIGHT $CAM --size $SIZE --spp $spp -o "$TMP/ref.pfm" > /dev/null 2> "$TMP/err.txt"; then
        echo "| $scene | $tris | trace | failed: $(tail -n 1 "$TMP/err.txt" | head -c 80 | tr '|' ' ') | | | | | | | |" >> "$OUT"
        continue
    fi
    for m in $METHODS; do
        case $m in
        default) opt= ;;
        temporal | lightmap | multibounce | local) opt="--method $m --proxy aavp" ;;
        *) opt="--method $m" ;;
        esac
        # shellcheck disable=SC2086
        if ! timed "$RAD" render "$FILE" $opt $LIGHT $CAM --size $SIZE -o "$TMP/img.pfm" > /dev/null 2> "$TMP/err.txt"; then
            read -r wall cpu kib < "$TMP/time.txt"
            why=$(grep -v '^ ' "$TMP/err.txt" | grep -v '%' | tail -n 1 | head -c 90 | tr '|' ' ')
            echo "| $scene | $tris | $m | failed: $why | | | | | $cpu | $wall | $kib |" >> "$OUT"
            continue
        fi
        read -r wall cpu mib < "$TMP/time.txt"
        chose=$(sed -n 's/.*no --method given: chose \([a-z]*\)\( at --vp-resolution \([0-9]*\)\)\{0,1\}.*/\1 \3/p' "$TMP/err.txt" | head -n 1)
        [ -z "$chose" ] && chose=$(sed -n 's/.*no --vp-resolution given: resolution \([0-9]*\).*/resolution \1/p' "$TMP/err.txt" | head -n 1)
        patches=$(sed -n 's/.*timing: method=[a-z]*\( proxy=[a-z]*\)\{0,1\} patches=\([0-9]*\).*/\2/p' "$TMP/err.txt" | tail -n 1)
        "$RAD" compare "$TMP/img.pfm" "$TMP/ref.pfm" > "$TMP/cmp.txt" 2> /dev/null || true
        ratio=$(sed -n 's/.*A \/ B = //p' "$TMP/cmp.txt")
        psnr=$(field PSNR: < "$TMP/cmp.txt")
        ssim=$(field SSIM: < "$TMP/cmp.txt")
        echo "| $scene | $tris | $m | ${chose:-} | ${patches:-} | $ratio | $psnr | $ssim | $cpu | $wall | $mib |" >> "$OUT"
    done
done
