#!/usr/bin/env bash
# tools/report.sh - the evaluation report: every radiosity method of the `rad` tool
# against the path-traced reference (`rad trace`), with MSE / PSNR / SSIM, per-frame times and
# the published figures of Shcherbakov 2025 (docs/references.md; "T" below) side by side, difference heat maps, and plots
# (per-frame time against N, temporal error against frame, compression error with and without
# reordering). Writes OUT/REPORT.md, OUT/img/*.png, OUT/plots/*.svg, OUT/data/* (raw logs).
#
#   bash tools/report.sh [--quick | --medium] [--out DIR] [--rad PATH] [--temporal-bench PATH]
#                        [--realtime-bench PATH] [--real-only]
#   bash tools/report.sh --check DIR      only check DIR/REPORT.md (every cell, every image)
#
# `make report` runs the full quality into tests/report/ (committed); `make report-quick` a reduced
# one into build/report-quick/ and then --check (tests/run.sh counts it as a test).
# Scenes: the built-in Cornell box, and the Stanford bunny in the box (the box from `rad export
# cornell`, the bunny from RAD_DATA_DIR/stanford-bunny.obj: no default; the section says so and is
# skipped when the file is absent); real scenes (full and medium quality): the Dabrovic Sponza
# from RAD_DATA_DIR/sponza.obj under a sun and under a sky window, every method that runs a real
# scene against `rad trace`, and the real-time loop of build/bench_realtime (tests/bench/realtime.c;
# with the bunny and ogre too when RAD_DATA_DIR holds them); skipped, saying why, without the
# file or in quick mode. --real-only runs that section alone.
#
# Adding a method: one line in METHODS below (id|label|needs dense F|rad render arguments|
# published figure). A row whose --method the built `rad render --help` does not list is kept
# in the table as "not in this build", so rows for methods still on other branches are ready.
set -u
export LC_ALL=C

MODE=full
OUT=
RAD=build/rad
TBENCH=build/temporal
RTBENCH=build/bench_realtime
REAL_ONLY=
CHECK_ONLY=
DATA=${RAD_DATA_DIR:-} # optional: the folder holding stanford-bunny.obj, sponza.obj, ogre.obj
while [ $# -gt 0 ]; do
    case "$1" in
    --quick) MODE=quick ;;
    --medium) MODE=medium ;;
    --full) MODE=full ;;
    --out) OUT=$2; shift ;;
    --rad) RAD=$2; shift ;;
    --temporal-bench) TBENCH=$2; shift ;;
    --check) CHECK_ONLY=$2; shift ;;
    --realtime-bench) RTBENCH=$2; shift ;;
    --real-only) REAL_ONLY=1 ;;
    -h | --help) sed -n '2,25p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "report.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
    esac
    shift
done

# ---- the check (every table cell filled, no failure, every image there) -------------------
check_report() {
    local dir=$1 md=$1/REPORT.md bad=0 n_img=0 n_rows=0 line img
    [ -f "$md" ] || { echo "report check: $md missing"; return 1; }
    while IFS= read -r line; do
        case "$line" in
        '|'*)
            n_rows=$((n_rows + 1))
            if printf '%s\n' "$line" | grep -Eq '\|[[:space:]]*\||FAILED'; then
                echo "report check: empty or failed cell: $line"
                bad=1
            fi ;;
        esac
    done < "$md"
    for img in $(grep -o '!\[[^]]*\]([^)]*)' "$md" | sed 's/.*(\(.*\))/\1/'); do
        n_img=$((n_img + 1))
        if [ ! -s "$dir/$img" ]; then
            echo "report check: image missing: $dir/$img"
            bad=1
        fi
    done
    if grep -q 'TODO\|nan\b' "$md"; then echo "report check: TODO or nan in $md"; bad=1; fi
    echo "report check: $md: $n_rows table rows, $n_img images: $([ $bad = 0 ] && echo ok || echo FAILED)"
    return $bad
}
if [ -n "$CHECK_ONLY" ]; then check_report "$CHECK_ONLY"; exit $?; fi

# ---- settings ----------------------------------------------------------------------------------
case $MODE in
quick)
    OUT=${OUT:-build/report-quick}
    SIZE=64x64 AA=4 SPP=64 PATCHES=300 FRAMES=300 PLS=4
    TSIZES=150,300 CSIZES="150 300" BUNNY_SIZE=48x48 BUNNY_SPP=16 REAL_SIZE= ;;
medium)
    OUT=${OUT:-build/report-medium}
    SIZE=128x128 AA=9 SPP=256 PATCHES=1000 FRAMES=2000 PLS=8
    TSIZES=500,1000,1736 CSIZES="300 600 1000" BUNNY_SIZE=128x128 BUNNY_SPP=64 REAL_SIZE=64x48 ;;
full)
    OUT=${OUT:-report}
    SIZE=256x256 AA=16 SPP=1024 PATCHES=2000 FRAMES=3000 PLS=16
    TSIZES=1736,5485,8786,10422 CSIZES="500 1000 2000" BUNNY_SIZE=256x256 BUNNY_SPP=256 REAL_SIZE=128x96 ;;
esac
REAL_SPP=256 # the real scenes' reference: rad trace at this many samples per pixel
EXPOSURE=1.5     # PNGs only; the metrics use the linear PFMs
DIFF_SCALE=0.1   # the heat maps share one scale: white = mean |ours - reference| of 0.1
CORNELL_CAM="0.278,0.273,-0.8:0.278,0.273,0:0,1,0"
CORNELL_FOV=39.3077

#    id|label|dense|rad render arguments|published figure (T: Shcherbakov 2025)
METHODS='
classic|classic Jacobi, 64 bounces|1|--method classic --bounces 64|T table 2 (radiosity): MSE 0.06658, PSNR 23.53, SSIM 0.8354
classic3|classic Jacobi, 3 bounces|1|--method classic --bounces 3|T ch. 3: SSIM 0.743 (classic, 3 bounces)
mbfloat|multi-bounce F_mb, float, 64 bounces|1|--method multibounce --format float|T ch. 3: one product per frame for any bounce count
mbfloat3|multi-bounce F_mb, float, 3 bounces|1|--method multibounce --format float --bounces 3|T ch. 3: 3x faster than 3 classic bounces; SSIM 0.762
mbbc1|multi-bounce F_mb, BC1 + outliers, reordered|1|--method multibounce --format bc1|T ch. 3: about 10x faster than classic with compression
mbbc4|multi-bounce F_mb, 3xBC4 + outliers, reordered|1|--method multibounce --format bc4x3|T ch. 3: memory 3x below the plain form-factor matrix
temporal|temporal, k 10, w 0.998, after FRAMES frames|1|--method temporal --w 0.998 --frames FRAMES|T table 2 (temporal): MSE 0.06651, PSNR 23.54, SSIM 0.8323
temporal_ad|temporal, k 10, adaptive w, after FRAMES frames|1|--method temporal --adaptive --frames FRAMES|none (beyond T: the adaptive w answers its open problem)
local|local matrix, M = 1024 nearest the camera|1|--method local --local-m 1024|T ch. 4: update cost 6-15x below recomputation
vp|virtual patches|0|--method vp|T ch. 5: 200 000 triangles to 12 000 (or 2 000) patches
aavp|axis-aligned virtual patches|0|--method aavp|T table 3: temporal + AAVP 0.08 ms, SSIM 0.73 (RTXGI 0.17 ms, SSIM 0.66)
'

# Virtual-patch count against accuracy (T ch. 5): `rad render SCENE VP_SWEEP B` for each budget B in
# VP_BUDGETS, run once `rad render --help` lists the method named in VP_SWEEP (x axis: the
# patches= of its timing line, else B). Set VP_SWEEP to the vp method's budget option, e.g.
# VP_SWEEP='--method aavp --vp-max-patches'.
VP_SWEEP=${RAD_REPORT_VP_SWEEP:-}
case $MODE in quick) VP_BUDGETS="100 300" ;; medium) VP_BUDGETS="250 1000 4000" ;; *) VP_BUDGETS="500 2000 8000 12000" ;; esac
VP_BUDGETS=${RAD_REPORT_VP_BUDGETS:-$VP_BUDGETS} # e.g. fewer for a shorter run (each budget counts patches, then builds once)

[ -x "$RAD" ] || { echo "report.sh: $RAD not built (make tools)" >&2; exit 1; }
mkdir -p "$OUT/img" "$OUT/plots" "$OUT/data"
OUT=$(cd "$OUT" && pwd)
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
T_START=$(date +%s)
LOAD_START=$(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null || echo unknown)
HELP=$("$RAD" render --help 2>&1 | grep -- '--method' | head -3)
log() { echo "report: $*" >&2; }
now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }'; }

# metrics of $1 (pfm) against $2 (pfm) -> "MSE PSNR SSIM"; writes the PNG and the heat map
compare() {
    "$RAD" compare "$1" "$2" --diff "$3" --diff-scale $DIFF_SCALE --png "$4" --png-exposure $EXPOSURE > "$TMP/cmp.txt" 2>&1 ||
        return 1
    awk '/^MSE:/ { m = $2 } /^PSNR:/ { p = $2 } /^SSIM:/ { s = $2 } END { printf "%.3g %.2f %.4f\n", m, p, s }' "$TMP/cmp.txt"
}

# the bunny in the box: the built-in box (`rad export cornell`: its white material is m0_white)
# without its two blocks, plus the bunny scaled to 0.25 m and standing in the middle of the floor
# (as tests/bench/rays.c places it)
make_bunny_scene() {
    local dir=$1
    [ -n "$DATA" ] && [ -f "$DATA/stanford-bunny.obj" ] || return 1
    "$RAD" export cornell -o "$dir/box.obj" > /dev/null || return 1
    awk -v base="$(awk '/^v /{n++} END{print n+0}' "$dir/box.obj")" '
        FNR == 1 { file++ }
        file == 1 { if ($1 == "o") skip = ($2 ~ /block/); if (!($1 == "f" && skip)) print; next }
        file == 2 && $1 == "v" { nv++; for (k = 2; k <= 4; ++k) { if (nv == 1 || $k < lo[k]) lo[k] = $k; if (nv == 1 || $k > hi[k]) hi[k] = $k } next }
        file == 3 && FNR == 1 { s = 0.25 / (hi[3] - lo[3]); print "o bunny"; print "usemtl m0_white" }
        file == 3 && $1 == "v" { printf "v %.6f %.6f %.6f\n", ($2 - 0.5 * (lo[2] + hi[2])) * s + 0.28, ($3 - lo[3]) * s + 0.0005, ($4 - 0.5 * (lo[4] + hi[4])) * s + 0.30; next }
        file == 3 && $1 == "f" { printf "f"; for (k = 2; k <= NF; ++k) { split($k, p, "/"); printf " %d", p[1] + base } printf "\n" }
    ' "$dir/box.obj" "$DATA/stanford-bunny.obj" "$DATA/stanford-bunny.obj" > "$dir/bunny-box.obj"
}

# one scene: the reference, then every method; appends its section to $TMP/scenes.md
run_scene() {
    local id=$1 title=$2 scene=$3 size=$4 spp=$5 tris=$6
    local t0 ref="$TMP/$id-reference.pfm" row mid label dense args pub mse psnr ssim ms ms_c="" t_ref shown=$scene
    [ "$scene" = cornell ] || shown=$(basename "$scene")
    local md="$TMP/scene-$id.md" imgs="$TMP/imgs-$id.md"
    local cam="--camera $CORNELL_CAM --fov $CORNELL_FOV"
    [ "$scene" = cornell ] && cam=""
    log "$title: reference (rad trace, $size, $spp spp)"
    t0=$(now)
    if ! "$RAD" trace "$scene" $cam --size "$size" --spp "$spp" -o "$ref" > "$OUT/data/$id-reference.log" 2>&1; then
        printf '\n## %s\n\nFAILED: rad trace (see data/%s-reference.log)\n' "$title" "$id" >> "$TMP/scenes.md"
        return
    fi
    t_ref=$(elapsed "$t0")
    compare "$ref" "$ref" "$TMP/null.png" "$OUT/img/$id-reference.png" > /dev/null
    {
        printf '\n## %s\n\n' "$title"
        printf 'Reference: `rad trace %s %s--size %s --spp %s` (%s s, all threads). Methods: `rad render %s %s--size %s --aa %s --pixel-light-samples %s --patches %s --threads 1` plus the arguments below. ' \
            "$shown" "${cam:+$cam }" "$size" "$spp" "$t_ref" "$shown" "${cam:+$cam }" "$size" "$AA" "$PLS" "$PATCHES"
        printf 'Per-frame time: the method'"'"'s own run-time work per frame as `rad render` reports it (its timing line), on one thread (this 2-core machine is shared; with two threads a small parallel step waits for the scheduler and its time is a multiple of 4 ms): classic = the K Jacobi bounces (K matrix-vector products), multi-bounce = one product `F_mb E` (median of 9), temporal = one `rad_temporal_step` (median over the frames), local = one apply `L = T E` over P_Vis x P_Lit (median of 9; the rebuild of T is rebuild_ms in the log), vp and aavp = the solve on the virtual patches'"'"' matrix (K Jacobi bounces + H = F B; the build, the sources and the per-pixel gather are build_ms, sources_ms and gather_ms in the log). "vs classic" = the classic 64-bounce time / this time. Published values: T = Shcherbakov 2025 (docs/references.md), RTX 3060, its own scene and reference.\n\n'
        printf '| method | `rad render` arguments | MSE | PSNR (dB) | SSIM | per frame (ms) | vs classic | published (T) |\n'
        printf '|---|---|---:|---:|---:|---:|---:|---|\n'
    } > "$md"
    printf '| method | image | difference to the reference (white = %s) |\n|---|---|---|\n' "$DIFF_SCALE" > "$imgs"
    printf '| reference (`rad trace`, %s spp) | ![reference](img/%s-reference.png) | (none) |\n' "$spp" "$id" >> "$imgs"
    while IFS='|' read -r mid label dense args pub; do
        [ -n "$mid" ] || continue
        label=${label//FRAMES/$FRAMES}
        args=${args//FRAMES/$FRAMES}
        local mname=${args#--method }
        mname=${mname%% *}
        if ! printf '%s\n' "$HELP" | grep -Eq "(^|[ |])$mname([] |]|$)"; then
            printf '| %s | `%s` | not in this build | | | | | %s |\n' "$label" "$args" "$pub" | sed 's/| |/| - |/g; s/| |/| - |/g' >> "$md"
            continue
        fi
        if [ "$dense" = 1 ] && [ "$tris" -gt 20000 ]; then
            local gb
            gb=$(awk -v t="$tris" 'BEGIN { printf "%.1f", 4 * t * t / 1e9 }')
            printf '| %s | `%s` | not run: dense F needs >= %s patches (one per triangle), %s GB | - | - | - | - | %s |\n' \
                "$label" "$args" "$tris" "$gb" "$pub" >> "$md"
            continue
        fi
        log "$title: $label"
        if ! "$RAD" render "$scene" $cam --size "$size" --aa "$AA" --pixel-light-samples "$PLS" --patches "$PATCHES" \
            --threads 1 $args -o "$TMP/$id-$mid.pfm" > "$OUT/data/$id-$mid.log" 2>&1; then
            printf '| %s | `%s` | FAILED (data/%s-%s.log) | - | - | - | - | %s |\n' "$label" "$args" "$id" "$mid" "$pub" >> "$md"
            continue
        fi
        ms=$(grep -o 'step_ms_median=[0-9.e+-]*' "$OUT/data/$id-$mid.log" | tail -1 | cut -d= -f2)
        ms=${ms:-FAILED}
        [ "$mid" = classic ] && ms_c=$ms
        read -r mse psnr ssim < <(compare "$TMP/$id-$mid.pfm" "$ref" "$OUT/img/$id-$mid-diff.png" "$OUT/img/$id-$mid.png" ||
            echo FAILED FAILED FAILED)
        local speed="-"
        if [ -n "$ms_c" ] && [ "$ms" != FAILED ]; then
            speed=$(awk -v a="$ms_c" -v b="$ms" 'BEGIN { if (b > 0) printf "%.1fx", a / b; else print "-" }')
        fi
        printf '| %s | `%s` | %s | %s | %s | %s | %s | %s |\n' "$label" "$args" "$mse" "$psnr" "$ssim" \
            "$(awk -v m="$ms" 'BEGIN { m += 0; if (m < 1) printf "%.4f", m; else printf "%.2f", m }')" "$speed" "$pub" >> "$md"
        printf '| %s | ![%s](img/%s-%s.png) | ![difference](img/%s-%s-diff.png) |\n' "$label" "$mid" "$id" "$mid" "$id" "$mid" >> "$imgs"
        printf '%s %s %s %s %s %s\n' "$id" "$mid" "$mse" "$psnr" "$ssim" "$ms" >> "$OUT/data/metrics.txt"
    done <<< "$METHODS"
    { cat "$md"; echo; cat "$imgs"; } >> "$TMP/scenes.md"
}

# ---- real scenes: the Dabrovic Sponza, a real building ------------------------------------------
# The view and lights of docs/performance-notes.md ("Row sums matched to traced shares"); the
# model has no materials, so the script writes a copy with the one stone material that
# tests/bench/realtime.c gives it. Virtual patches at about 2k and 12k (the resolutions of the
# performance notes: AAVP 11 and 28, VP 10 and 23), then temporal and the lightmap over the 2k
# AAVP set, so their rows differ from the AAVP 2k row only by the method.
REAL_CAM="--camera -10,3,0:10,4,0:0,1,0 --fov 60"
REAL_EXPOSURE=4 # Sponza is darker than the Cornell box (mean radiance about 0.1)
REAL_DIFF=0.02  # heat maps of the real scenes: white = mean |ours - reference| of 0.02
#    id|label|rad render arguments
REAL_METHODS='
aavp2k|AAVP, about 2k patches|--method aavp --vp-resolution 11
aavp12k|AAVP, about 12k patches|--method aavp --vp-resolution 28
vp2k|VP (clustered), about 2k patches|--method vp --vp-resolution 10
vp12k|VP (clustered), about 12k patches|--method vp --vp-resolution 23
temporal|temporal over the 2k AAVP (1024 frames, adaptive w)|--method temporal --proxy aavp --vp-resolution 11
lightmap|lightmap over the 2k AAVP, atlas chosen by the tool|--method lightmap --proxy aavp --vp-resolution 11
'
TIME_BIN=
[ -x /usr/bin/time ] && TIME_BIN=/usr/bin/time
# run_timed LOG CMD...: CMD's output into LOG, "wall=S peak_kib=K" into LOG.time
run_timed() {
    local log=$1 t0 rc
    shift
    t0=$(now)
    if [ -n "$TIME_BIN" ]; then
        "$TIME_BIN" -f 'wall=%e peak_kib=%M' -o "$log.time" "$@" > "$log" 2>&1
        rc=$?
    else
        "$@" > "$log" 2>&1
        rc=$?
        echo "wall=$(elapsed "$t0") peak_kib=-" > "$log.time"
    fi
    return $rc
}
# field of LOG.time: timed_field LOG wall|peak_mib
timed_field() {
    awk -v f="$2" '{ for (i = 1; i <= NF; ++i) { split($i, kv, "="); if (kv[1] == "wall" && f == "wall") v = sprintf("%.1f", kv[2])
        if (kv[1] == "peak_kib" && f == "peak_mib") v = kv[2] == "-" ? "-" : sprintf("%.0f", kv[2] / 1024) } }
        END { print (v == "" ? "-" : v) }' "$1.time" 2> /dev/null
}
# metrics of $1 against $2 -> "MSE PSNR SSIM MEAN_RATIO"; writes the PNG and the heat map
compare_real() {
    "$RAD" compare "$1" "$2" --diff "$3" --diff-scale $REAL_DIFF --png "$4" --png-exposure $REAL_EXPOSURE > "$TMP/cmpr.txt" 2>&1 ||
        return 1
    awk '/^MSE:/ { m = $2 } /^PSNR:/ { p = $2 } /^SSIM:/ { s = $2 } /A \/ B = / { r = $NF }
         END { printf "%.3g %.2f %.4f %s\n", m, p, s, (r == "" ? "-" : sprintf("%.3f", r)) }' "$TMP/cmpr.txt"
}
make_sponza_scene() {
    local dir=$1
    [ -n "$DATA" ] && [ -f "$DATA/sponza.obj" ] || return 1
    printf 'newmtl stone\nKd 0.7 0.68 0.63\n' > "$dir/sponza-stone.mtl"
    { printf 'mtllib sponza-stone.mtl\nusemtl stone\n'; grep -v '^\(mtllib\|usemtl\) ' "$DATA/sponza.obj"; } > "$dir/sponza.obj"
}
# one light: the reference, then every method of REAL_METHODS; appends to $TMP/real.md
run_real() {
    local id=$1 title=$2 light=$3 scene=$TMP/sponza.obj ref="$TMP/$1-reference.pfm" mid label args log
    local mse psnr ssim ratio np build ms wall peak extra md="$TMP/real-$1.md" imgs="$TMP/real-imgs-$1.md"
    log "$title: reference (rad trace, $REAL_SIZE, $REAL_SPP spp)"
    if ! run_timed "$OUT/data/$id-reference.log" "$RAD" trace "$scene" $REAL_CAM $light --size "$REAL_SIZE" --spp "$REAL_SPP" -o "$ref"; then
        printf '\n### %s\n\nFAILED: rad trace (see data/%s-reference.log)\n' "$title" "$id" >> "$TMP/real.md"
        return
    fi
    compare_real "$ref" "$ref" "$TMP/null.png" "$OUT/img/$id-reference.png" > /dev/null
    {
        printf '\n### %s\n\n' "$title"
        printf 'Reference: `rad trace sponza.obj %s %s --size %s --spp %s` (%s s wall, all threads, peak %s MiB). Methods: `rad render sponza.obj %s %s --size %s` (the tool'"'"'s defaults otherwise, all threads) plus the arguments below.\n\n' \
            "$REAL_CAM" "$light" "$REAL_SIZE" "$REAL_SPP" "$(timed_field "$OUT/data/$id-reference.log" wall)" \
            "$(timed_field "$OUT/data/$id-reference.log" peak_mib)" "$REAL_CAM" "$light" "$REAL_SIZE"
        printf '| method | `rad render` arguments | patches | mean / trace | SSIM | PSNR (dB) | MSE | proxy build (s) | solve or step (ms) | wall (s) | peak (MiB) |\n'
        printf '|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n'
    } > "$md"
    printf '| method | image | difference to the reference (white = %s) |\n|---|---|---|\n' "$REAL_DIFF" > "$imgs"
    printf '| reference (`rad trace`, %s spp) | ![reference](img/%s-reference.png) | (none) |\n' "$REAL_SPP" "$id" >> "$imgs"
    while IFS='|' read -r mid label args; do
        [ -n "$mid" ] || continue
        log "$title: $label"
        log=$OUT/data/$id-$mid.log
        if ! run_timed "$log" "$RAD" render "$scene" $REAL_CAM $light --size "$REAL_SIZE" $args -o "$TMP/$id-$mid.pfm" ||
            ! read -r mse psnr ssim ratio < <(compare_real "$TMP/$id-$mid.pfm" "$ref" "$OUT/img/$id-$mid-diff.png" "$OUT/img/$id-$mid.png"); then
            printf '| %s | `%s` | FAILED (data/%s-%s.log) | - | - | - | - | - | - | - | - |\n' "$label" "$args" "$id" "$mid" >> "$md"
            continue
        fi
        np=$(grep -o 'patches=[0-9]*' "$log" | tail -1 | cut -d= -f2)
        ms=$(grep -o 'step_ms_median=[0-9.e+-]*' "$log" | tail -1 | cut -d= -f2)
        build=$(grep -o 'build_ms=[0-9.]*' "$log" | tail -1 | cut -d= -f2)
        if [ -n "$build" ]; then build=$(awk -v b="$build" 'BEGIN { printf "%.1f", b / 1000 }')
        else build=$(grep -o 'built in [0-9.]* s' "$log" | tail -1 | awk '{ printf "%.1f", $3 }'); fi
        extra=$(grep -o '[0-9]*x[0-9]* texels' "$log" | tail -1 | sed 's/ texels//')
        [ -n "$extra" ] && label="$label: $extra"
        printf '| %s | `%s` | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n' "$label" "$args" "${np:--}" "$ratio" "$ssim" "$psnr" "$mse" \
            "${build:--}" "$(awk -v m="${ms:-0}" 'BEGIN { if (m < 1) printf "%.4f", m; else printf "%.1f", m }')" \
            "$(timed_field "$log" wall)" "$(timed_field "$log" peak_mib)" >> "$md"
        printf '| %s | ![%s](img/%s-%s.png) | ![difference](img/%s-%s-diff.png) |\n' "$label" "$mid" "$id" "$mid" "$id" "$mid" >> "$imgs"
        printf '%s %s %s %s %s %s %s\n' "$id" "$mid" "$mse" "$psnr" "$ssim" "$ratio" "${ms:--}" >> "$OUT/data/real-metrics.txt"
    done <<< "$REAL_METHODS"
    { cat "$md"; echo; cat "$imgs"; } >> "$TMP/real.md"
}
# the whole section into $TMP/real.md
run_real_scenes() {
    : > "$TMP/real.md"
    : > "$OUT/data/real-metrics.txt"
    if [ -z "$REAL_SIZE" ]; then
        echo "Skipped in $MODE mode (it must stay short and need no meshes from outside the repository): \`make report\` runs this section at full quality, \`bash tools/report.sh --medium\` at 64x48." >> "$TMP/real.md"
        return
    fi
    if ! make_sponza_scene "$TMP"; then
        printf 'Skipped: %s; set RAD_DATA_DIR to the directory that holds `sponza.obj` (docs/data.md).\n' \
            "$([ -n "$DATA" ] && echo "\`$DATA/sponza.obj\` not found" || echo "RAD_DATA_DIR is not set")" >> "$TMP/real.md"
        return
    fi
    {
        echo "The Dabrovic Sponza atrium ($(grep -c '^f ' "$TMP/sponza.obj") faces in \`RAD_DATA_DIR/sponza.obj\`, docs/data.md; the script gives it one stone material, albedo 0.7 0.68 0.63, as tests/bench/realtime.c does),"
        echo "lit by a sun and, separately, by a sky window (a one-sided rectangle above the open roof, facing down, so most of the"
        echo "building sees only bounced light). The dense methods (classic, multi-bounce, temporal and local over patches) need at least one patch"
        echo "per triangle and an N x N matrix (66k triangles: 17.7 GB), so they are not run; the virtual patches are the methods for"
        echo "a real scene, and temporal and the lightmap run over them (\`--proxy aavp\`). Mean / trace = the ratio of the mean linear"
        echo "radiance over all pixels to the reference's (1 = no light lost or gained). Proxy build = the virtual patches' build"
        echo "as the tool reports it (its timing line's build_ms, or the lightmap's \"built in\"); solve or step = the tool's"
        echo "step_ms_median (aavp, vp and lightmap: the solve on the patches, K Jacobi bounces and H = F B; temporal: one"
        echo "\`rad_temporal_step\`, median over the frames); wall and peak = the whole command (\`/usr/bin/time\`: elapsed and maximum"
        echo "resident set size). PNGs at exposure $REAL_EXPOSURE. The sky window's rectangle is scene geometry above the roof, so it"
        echo "enlarges the bounds that the voxel grid divides: the same resolution gives other patch counts than under the sun."
    } >> "$TMP/real.md"
    run_real sponza-sun "Sponza under a sun (\`--sun 0.3,-1,0.2:3\`)" "--sun 0.3,-1,0.2:3"
    run_real sponza-sky "Sponza under a sky window (\`--area -18,16.5,-8:36,0,0:0,0,16:1\`)" "--area -18,16.5,-8:36,0,0:0,0,16:1"
    # the real-time loop (tests/bench/realtime.c): per-frame stages at about 2k and 12k AAVP
    local rt=$OUT/data/realtime.md rtq="" box=""
    [ "$MODE" = full ] || rtq=--quick
    : > "$rt"
    printf '\n### The real-time loop (tests/bench/realtime.c) beside the thesis'"'"'s Table 3\n\n' >> "$TMP/real.md"
    if [ ! -x "$RTBENCH" ]; then
        echo "FAILED: \`$RTBENCH\` is not built (\`make build/bench_realtime\`)." >> "$TMP/real.md"
        return
    fi
    log "real-time loop: Sponza (bench_realtime --scene sponza $rtq)"
    if ! run_timed "$OUT/data/realtime-sponza.log" "$RTBENCH" $rtq --data "$DATA" --scene sponza --append "$rt"; then
        echo "FAILED: \`$RTBENCH --scene sponza\` (see data/realtime-sponza.log)." >> "$TMP/real.md"
        return
    fi
    if [ "$MODE" = full ] && [ -f "$DATA/stanford-bunny.obj" ] && [ -f "$DATA/ogre.obj" ]; then
        log "real-time loop: bunny + ogre in the Cornell box, about 2k patches"
        run_timed "$OUT/data/realtime-box.log" "$RTBENCH" --data "$DATA" --scene box --size 2000 --append "$rt" && box=1
    fi
    {
        echo "tests/bench/realtime.c (the loop of examples/realtime.c), \`$(basename "$RTBENCH") $rtq${rtq:+ }--scene sponza\`$([ -n "$box" ] && echo " and \`--scene box --size 2000\` (the bunny and the ogre, 193k triangles, in the Cornell box)"): a sun and a point light"
        echo "circling the scene; per frame the E update of the virtual patches, one temporal step (k 10, feedback) and the"
        echo "per-vertex gather, medians in ms; lag = frames after the point light jumps until the error is back to its noise"
        echo "(fixed w 0.9 exact E / M/4 rays / adaptive w); power, RMS and vertex L1 = the converged temporal solution against"
        echo "Gauss-Seidel on the same patches. Its own log has the column definitions (data/realtime.md). On a shared machine"
        echo "the wall-clock medians with all threads wait for the scheduler; the one-core CPU times are the work itself."
        echo
        grep -m1 '^| scene | res |' "$rt"
        grep -m1 '^|---|' "$rt"
        grep '^| \(Sponza\|bunny\)' "$rt"
        echo
        echo "The thesis's figure beside ours (Shcherbakov 2025, Table 3: the temporal step on an RTX 3060 GPU, its scene of"
        echo "10 422 polygons; ours: the CPU of this machine, a 66k-triangle atrium):"
        echo
        echo "| figure | thesis, Table 3 (GPU) | ours (CPU, this run) |"
        echo "|---|---|---|"
        # the one-core column: "E / E M/4, step, gather: frame / frame M/4 ms"
        awk -F'|' '/^\| Sponza/ { gsub(/^ +| +$/, "", $4); gsub(/^ +| +$/, "", $12); split($15, c, /, |: /); split(c[4], f, / /)
                s = s (s ? "; " : "") "Sponza, " $4 " patches: step " c[2] " ms, whole frame (E update, step, gather) " f[1] " ms on one core (CPU time; wall with all threads: step " $12 ")" }
            END { printf "| temporal radiosity, time per frame | 0.08 ms (the step) | %s |\n", (s ? s : "-") }' "$rt"
        printf '| temporal radiosity vs a path-traced reference | SSIM 0.73, PSNR 23.54 | temporal over the 2k AAVP (%s frames): sun SSIM %s, PSNR %s; sky window SSIM %s, PSNR %s |\n' 1024 \
            "$(awk '$1 == "sponza-sun" && $2 == "temporal" { print $5 }' "$OUT/data/real-metrics.txt")" \
            "$(awk '$1 == "sponza-sun" && $2 == "temporal" { print $4 }' "$OUT/data/real-metrics.txt")" \
            "$(awk '$1 == "sponza-sky" && $2 == "temporal" { print $5 }' "$OUT/data/real-metrics.txt")" \
            "$(awk '$1 == "sponza-sky" && $2 == "temporal" { print $4 }' "$OUT/data/real-metrics.txt")"
        echo "| RTXGI (probes, same table) | 0.17 ms, SSIM 0.66 | not run here (no GPU) |"
    } >> "$TMP/real.md"
}

if [ -z "$REAL_ONLY" ]; then # everything but the real scenes

: > "$OUT/data/metrics.txt"
: > "$TMP/scenes.md"
run_scene cornell "Cornell box (built-in, the original Cornell data in metres)" cornell "$SIZE" "$SPP" 32
if make_bunny_scene "$TMP"; then
    tris=$(grep -c '^f ' "$TMP/bunny-box.obj")
    cp "$TMP/bunny-box.obj" "$TMP/bunny-box.obj.keep" 2> /dev/null
    run_scene bunny "Stanford bunny in the Cornell box" "$TMP/bunny-box.obj" "$BUNNY_SIZE" "$BUNNY_SPP" "$((tris + 0))"
    {
        printf '\nThe bunny scene is the built-in Cornell box (`rad export cornell`) without its two blocks plus `RAD_DATA_DIR/stanford-bunny.obj` (docs/data.md) scaled to 0.25 m and standing in the middle of the floor (written by this script). '
        printf 'The `rad` tool makes at least one patch per triangle and stores F densely: with %s triangles that is a %s GB matrix (this machine: %s GB of memory) and about %s patch pairs of form factors, which at the measured ~1 Mpairs/s (docs/BENCHMARKS.md a) is hours, so the dense methods (classic, multi-bounce, temporal) were not run on it. The virtual patches are the method meant for it (the local method of rad fetches its rows from the classic dense F, so it is not run here either).\n' \
            "$tris" "$(awk -v t="$tris" 'BEGIN { printf "%.1f", 4 * t * t / 1e9 }')" \
            "$(awk '/MemTotal/ { printf "%.0f", $2 / 1048576 }' /proc/meminfo)" "$(awk -v t="$tris" 'BEGIN { printf "%.1e", t * t / 2 }')"
    } >> "$TMP/scenes.md"
else
    printf '\n## Stanford bunny in the Cornell box\n\nSkipped: %s; set RAD_DATA_DIR to the directory that holds `stanford-bunny.obj`.\n' "$([ -n "$DATA" ] && echo "\`$DATA/stanford-bunny.obj\` not found" || echo "RAD_DATA_DIR is not set")" >> "$TMP/scenes.md"
fi

# ---- plot 1 and 2: temporal against the matrix-vector product (tests/bench/temporal) -------------
TAB_T="$OUT/data/temporal.md"
: > "$TAB_T"
log "temporal against matrix-vector, N = $TSIZES (tests/bench/temporal)"
if [ -x "$TBENCH" ] && "$TBENCH" --sizes "$TSIZES" --append "$TAB_T" --csv "$OUT/data/temporal_error.csv" > "$OUT/data/temporal.log" 2>&1; then
    # rows "| N (target) | step10 | step64 | MV | ..."
    {
        echo "N temporal_k=10 temporal_k=64 matrix-vector published_temporal_k=10 published_matrix-vector"
        awk -F'|' '/^\| [0-9]+ \([0-9]+\) \|/ {
            split($2, a, /[ ()]+/); n = a[2]; t = a[3]
            pt = pm = "-"
            if (t == 1736) { pt = 0.02; pm = 0.34 } else if (t == 5485) { pt = 0.04; pm = 2.94 }
            else if (t == 8786) { pt = 0.06; pm = 7.34 } else if (t == 10422) { pt = 0.08; pm = 12.01 }
            printf "%s %s %s %s - -\n", n, $3 + 0, $4 + 0, $5 + 0
            if (pt != "-") printf "%s - - - %s %s\n", t, pt, pm
        }' "$TAB_T" | sort -n
    } > "$OUT/data/time_vs_n.dat"
    awk -v title="Per-frame time against N (Cornell box)" -v xlabel="patches N" -v ylabel="ms per frame" \
        -v logx=1 -v logy=1 -v markers=1 -f tools/svgplot.awk "$OUT/data/time_vs_n.dat" > "$OUT/plots/time_vs_n.svg"
    { echo "frame fixed_w=0.998 adaptive_w"; tail -n +2 "$OUT/data/temporal_error.csv" | tr ',' ' '; } > "$OUT/data/temporal_error.dat"
    awk -v title="Temporal error against frame (light switched on at frame 3000)" -v xlabel="frame" \
        -v ylabel="relative RMS error vs exact" -v logy=1 -f tools/svgplot.awk "$OUT/data/temporal_error.dat" > "$OUT/plots/temporal_error.svg"
    T_OK=1
else
    T_OK=0
fi

# ---- plot 3: compression error with and without reordering (rad bake) ----------------------
log "compression error with and without reordering, N = $CSIZES"
echo "N BC1_plain BC1_reordered 3xBC4_plain 3xBC4_reordered" > "$OUT/data/compression.dat"
: > "$TMP/comp.md"
for n in $CSIZES; do
    line="" realn=""
    for fmt in bc1 bc4x3; do
        for ro in --no-reorder --reorder; do
            if "$RAD" bake cornell --patches "$n" --method multibounce --bounces 3 --format $fmt $ro -o "$TMP/c.radb" \
                > "$OUT/data/compress-$n-$fmt$ro.log" 2>&1; then
                rms=$(grep -o 'decoded-matrix RMS error [0-9.e+-]*' "$OUT/data/compress-$n-$fmt$ro.log" | awk '{ print $4 }')
                rel=$(grep -o '([0-9.e+-]*% of the RMS entry)' "$OUT/data/compress-$n-$fmt$ro.log" | tr -d '(%' | awk '{ print $1 }')
                bytes=$(grep -o 'compressed to [a-z0-9]* in [0-9.]* s: [0-9]* bytes' "$OUT/data/compress-$n-$fmt$ro.log" | awk '{ print $7 }')
                fbytes=$(grep -o '[0-9]* float F_mb' "$OUT/data/compress-$n-$fmt$ro.log" | awk '{ print $1 }')
                realn=$(grep -o '[0-9]* patches$' "$OUT/data/compress-$n-$fmt$ro.log" | head -1 | awk '{ print $1 }')
                mse=$(awk -v r="${rms:-0}" 'BEGIN { printf "%.3g", r * r }')
                line="$line $mse"
                printf '%s|%s|%s|%s|%s|%s|%s\n' "${realn:-$n}" "$fmt" "${ro#--}" "$mse" "$rel" "$bytes" "$fbytes" >> "$TMP/comp.md"
            else
                line="$line -"
                printf '%s|%s|%s|FAILED|FAILED|FAILED|FAILED\n' "$n" "$fmt" "${ro#--}" >> "$TMP/comp.md"
            fi
        done
    done
    echo "${realn:-$n}$line" >> "$OUT/data/compression.dat"
done
awk -v title="Compression error of F_mb (3 bounces), with and without reordering" -v xlabel="patches N" \
    -v ylabel="MSE of the decoded matrix" -v logx=1 -v logy=1 -v markers=1 -f tools/svgplot.awk \
    "$OUT/data/compression.dat" > "$OUT/plots/compression.svg"

# ---- virtual-patch count against accuracy ------------------------------------------------------
VP_OK=0
vp_method=${VP_SWEEP#--method }
vp_method=${vp_method%% *}
if [ -n "$VP_SWEEP" ] && printf '%s\n' "$HELP" | grep -Eq "(^|[ |])$vp_method([] |]|$)"; then
    echo "patches PSNR_cornell PSNR_bunny" > "$OUT/data/vp_psnr.dat"
    echo "patches SSIM_cornell SSIM_bunny" > "$OUT/data/vp_ssim.dat"
    : > "$TMP/vp.md"
    for sc in cornell bunny; do
        if [ $sc = cornell ]; then scene=cornell cam="" size=$SIZE; else scene=$TMP/bunny-box.obj size=$BUNNY_SIZE
            cam="--camera $CORNELL_CAM --fov $CORNELL_FOV"; fi
        [ -f "$TMP/$sc-reference.pfm" ] || continue
        for b in $VP_BUDGETS; do
            log "virtual patches: $sc, budget $b"
            if "$RAD" render "$scene" $cam --size "$size" --aa "$AA" --pixel-light-samples "$PLS" --threads 1 $VP_SWEEP "$b" \
                -o "$TMP/vp.pfm" > "$OUT/data/vp-$sc-$b.log" 2>&1 &&
                read -r mse psnr ssim < <(compare "$TMP/vp.pfm" "$TMP/$sc-reference.pfm" "$TMP/vpd.png" "$TMP/vp.png"); then
                np=$(grep -o 'patches=[0-9]*' "$OUT/data/vp-$sc-$b.log" | tail -1 | cut -d= -f2)
                ms=$(grep -o 'step_ms_median=[0-9.e+-]*' "$OUT/data/vp-$sc-$b.log" | tail -1 | cut -d= -f2)
                np=${np:-$b}
                printf '| %s | %s | %s | %s | %s | %s | %s |\n' "$sc" "$b" "$np" "$mse" "$psnr" "$ssim" "${ms:--}" >> "$TMP/vp.md"
                if [ $sc = cornell ]; then echo "$np $psnr -" >> "$OUT/data/vp_psnr.dat"; echo "$np $ssim -" >> "$OUT/data/vp_ssim.dat"
                else echo "$np - $psnr" >> "$OUT/data/vp_psnr.dat"; echo "$np - $ssim" >> "$OUT/data/vp_ssim.dat"; fi
            else
                printf '| %s | %s | FAILED (data/vp-%s-%s.log) | - | - | - | - |\n' "$sc" "$b" "$sc" "$b" >> "$TMP/vp.md"
            fi
        done
    done
    for k in psnr ssim; do
        awk -v title="Virtual patches: $(echo $k | tr a-z A-Z) against the patch count" -v xlabel="virtual patches" \
            -v ylabel="$(echo $k | tr a-z A-Z) vs the reference" -v logx=1 -v markers=1 -f tools/svgplot.awk \
            "$OUT/data/vp_$k.dat" > "$OUT/plots/vp_$k.svg"
    done
    VP_OK=1
fi

# ---- the headline: the published figures against ours ------------------------------------------
# m ID FIELD: a metric of a Cornell-box method (2 MSE, 3 PSNR, 4 SSIM, 5 ms), or "-"
m() { awk -v id="$1" -v f="$2" '$1 == "cornell" && $2 == id { v = $(f + 1) } END { print (v == "" ? "-" : v) }' "$OUT/data/metrics.txt"; }
ms() { awk -v v="$(m "$1" 5)" 'BEGIN { if (v == "-") print v; else printf "%.3g", v }'; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { if (a + 0 > 0 && b + 0 > 0) printf "%.1fx", a / b; else print "-" }'; }
{
    echo "| figure | published (T: Shcherbakov 2025) | ours, this run (Cornell box, $SIZE, $PATCHES-patch target) |"
    echo "|---|---|---|"
    echo "| radiosity vs path-traced reference (T table 2) | MSE 0.06658, PSNR 23.53, SSIM 0.8354 | classic 64 bounces: MSE $(m classic 2), PSNR $(m classic 3), SSIM $(m classic 4) |"
    echo "| temporal vs path-traced reference (T table 2) | MSE 0.06651, PSNR 23.54, SSIM 0.8323 | temporal, w 0.998, $FRAMES frames: MSE $(m temporal 2), PSNR $(m temporal 3), SSIM $(m temporal 4); adaptive w: PSNR $(m temporal_ad 3), SSIM $(m temporal_ad 4) |"
    if [ "${T_OK:-0}" = 1 ]; then
        big=$(awk -F'|' '/^\| [0-9]+ \([0-9]+\) \|/ { r = $0 } END { split(r, c, "|"); gsub(/ /, "", c[3]); gsub(/ /, "", c[5]); split(c[2], a, /[ ()]+/); printf "N = %s: step %s ms vs product %s ms", a[2], c[3], c[5] }' "$TAB_T")
        rat=$(awk -F'|' '/^\| [0-9]+ \([0-9]+\) \|/ { r = $0 } END { split(r, c, "|"); gsub(/ /, "", c[6]); print c[6] }' "$TAB_T")
        echo "| temporal step vs matrix-vector product (T table 1, largest N) | N = 10422: 0.08 vs 12.01 ms (150x), GPU | $big ($rat), one CPU thread |"
    fi
    echo "| multi-bounce matrix vs 3 Jacobi bounces (T ch. 3) | 3x faster | $(ratio "$(m classic3 5)" "$(m mbfloat3 5)") ($(ms classic3) ms for 3 bounces vs $(ms mbfloat3) ms for one float F_mb product; the 64-bounce row's product, the same work, took $(ms mbfloat) ms). F_mb is RGB (3 N^2 floats) while F is one N^2 matrix shared by the channels, so on a CPU one F_mb product reads as many bytes as 3 bounces. SSIM $(m mbfloat3 4) vs $(m classic3 4) for 3 classic bounces (T: 0.762 vs 0.743) |"
    echo "| compressed multi-bounce vs classic (T ch. 3) | about 10x faster | BC1: $(ratio "$(m classic 5)" "$(m mbbc1 5)"), 3xBC4: $(ratio "$(m classic 5)" "$(m mbbc4 5)") against 64 classic bounces (CPU decode; T decodes in GPU texture hardware) |"
    awk -F'|' -v nmax="$(echo $CSIZES | awk '{ print $NF }')" '
        { key = $1 "|" $2; if ($3 == "no-reorder") plain[key] = $4; else if ($4 + 0 > 0) { r[$2] = sprintf("%.1fx", plain[key] / $4); n = $1; mem[$2] = sprintf("%.1fx", ($7 / 3) / $6) } }
        END { printf "| reordering cuts the compression MSE (T ch. 3) | 5x | N = %s: BC1 %s, 3xBC4 %s |\n", n, r["bc1"], r["bc4x3"]
              printf "| compressed F_mb memory vs the plain float F (T ch. 3) | 3x below | N = %s: BC1 %s, 3xBC4 %s below (blocks + scales + outliers + permutations) |\n", n, mem["bc1"], mem["bc4x3"] }' "$TMP/comp.md"
    if printf '%s\n' "$HELP" | grep -Eq "(^|[ |])local([] |]|$)"; then :; else
        echo "| local matrix update vs recomputation (T ch. 4) | 6-15x | not in this build (branch \`local\`) |"; fi
    if printf '%s\n' "$HELP" | grep -Eq "(^|[ |])aavp([] |]|$)"; then :; else
        echo "| temporal + AAVP vs RTXGI (T table 3) | 0.08 ms, SSIM 0.73 vs 0.17 ms, SSIM 0.66 | not in this build (branch \`vp\`) |"; fi
} > "$TMP/headline.md"
fi # REAL_ONLY
run_real_scenes

# ---- REPORT.md ------------------------------------------------------------------------------
T_ALL=$(( $(date +%s) - T_START ))
CPU=$(awk -F': ' '/model name/ { print $2; exit }' /proc/cpuinfo 2>/dev/null)
MD="$OUT/REPORT.md"
{
    echo "# radiosity.h evaluation report"
    echo
    echo "Every method of the \`rad\` tool against a path-traced reference, side by side with the figures the"
    echo "Shcherbakov 2025 publishes (T; docs/references.md lists it), all measured in one run of \`tools/report.sh\`."
    echo
    echo "| setting | value |"
    echo "|---|---|"
    echo "| quality | $MODE (\`bash tools/report.sh$([ $MODE = full ] || echo " --$MODE")$([ -n "$REAL_ONLY" ] && echo " --real-only")\`$([ -n "${RAD_REPORT_VP_SWEEP:-}${RAD_REPORT_VP_BUDGETS:-}" ] && echo " with RAD_REPORT_VP_SWEEP='${RAD_REPORT_VP_SWEEP:-}' and RAD_REPORT_VP_BUDGETS='${RAD_REPORT_VP_BUDGETS:-}'"); \`make report\` = full, \`make report-quick\` = quick, checked in CI) |"
    echo "| date | $(date -u '+%Y-%m-%d %H:%M UTC') |"
    echo "| machine | ${CPU:-unknown CPU}, $(nproc) logical CPUs, $(awk '/MemTotal/ { printf "%.0f GB", $2 / 1048576 }' /proc/meminfo) |"
    echo "| load | shared machine: load average $LOAD_START at the start, $(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null) at the end (other jobs ran at the same time, so times are noisy even as medians: the two float F_mb rows do the same work per frame, and their times show the spread) |"
    echo "| library | $("$RAD" version 2>/dev/null) |"
    echo "| run time | $T_ALL s for the whole report |"
    echo
    echo "Metrics: MSE, PSNR (peak 1) and SSIM (Wang et al. 2004: 11x11 Gaussian, sigma 1.5, per channel R, G, B,"
    echo "averaged) on linear radiance clamped to [0,1], computed by \`rad compare\` from the PFM images. The"
    echo "PNGs below are sRGB at exposure $EXPOSURE; the heat maps show the per-pixel mean |ours - reference| over"
    echo "RGB on one shared scale (white = $DIFF_SCALE). T's numbers come from its own scenes, reference"
    echo "and GPU (RTX 3060), so they are context, not a like-for-like target: this report runs on a CPU."
    echo
    if [ -n "$REAL_ONLY" ]; then
        echo "This run: the real-scenes section alone (\`--real-only\`)."
    else
    echo "## Side by side"
    echo
    cat "$TMP/headline.md"
    cat "$TMP/scenes.md"
    echo
    echo "## Temporal radiosity against the matrix-vector product (T table 1)"
    echo
    if [ "$T_OK" = 1 ]; then
        echo "\`build/temporal --sizes $TSIZES\` (tests/bench/temporal.c; the same code as \`make bench\`): Cornell box, single"
        echo "bounce, one thread. Times are medians in ms; the published column is T's RTX 3060 measurement."
        echo
        awk '/^\| N \(target\)/ { on = 1 } on && /^\|/ { print } on && !/^\|/ && NR > 1 { if (printed) exit } on && /^\|/ { printed = 1 }' "$TAB_T" | sed 's/| - |/| none (not a size T measured) |/'
        echo
        echo "![per-frame time against N](plots/time_vs_n.svg)"
        echo
        echo "Lag after a light jump (frames until 90% of the change) and steady noise, fixed against adaptive w:"
        echo
        awk '/^\| N \| lag/ { on = 1 } on && /^\|/ { print; next } on { exit }' "$TAB_T"
        echo
        echo "![temporal error against frame](plots/temporal_error.svg)"
    else
        echo "FAILED: \`$TBENCH\` did not run (see data/temporal.log; \`make build/temporal\`)."
    fi
    echo
    echo "## Compression of the multi-bounce matrix: reordering (T ch. 3)"
    echo
    echo "\`rad bake cornell --patches N --method multibounce --bounces 3 --format F [--reorder|--no-reorder]\`"
    echo "(outliers 5 %, scales per 64x64 tile). MSE of the decoded F_mb over all entries; relative = RMS error /"
    echo "RMS entry. T reports reordering cutting the compression MSE 5x."
    echo
    echo "| N | format | reordering | MSE | relative RMS (%) | bytes | float F_mb bytes | MSE ratio plain / reordered |"
    echo "|---:|---|---|---:|---:|---:|---:|---:|"
    awk -F'|' '{ key = $1 "|" $2; if ($3 == "no-reorder") plain[key] = $4
                 r = "-"; if ($3 == "reorder" && (key in plain) && $4 + 0 > 0) r = sprintf("%.2fx", plain[key] / $4)
                 printf "| %s | %s | %s | %s | %s | %s | %s | %s |\n", $1, $2, $3 == "reorder" ? "yes" : "no", $4, $5, $6, $7, r }' "$TMP/comp.md"
    echo
    echo "![compression error with and without reordering](plots/compression.svg)"
    echo
    echo "## Virtual-patch count against accuracy (T ch. 5)"
    echo
    if [ "$VP_OK" = 1 ]; then
        echo "\`rad render SCENE $VP_SWEEP B\` for B in $VP_BUDGETS, against each scene's reference above."
        echo
        echo "| scene | budget | patches | MSE | PSNR (dB) | SSIM | per frame (ms) |"
        echo "|---|---:|---:|---:|---:|---:|---:|"
        cat "$TMP/vp.md"
        echo
        echo "![PSNR against the virtual-patch count](plots/vp_psnr.svg) ![SSIM against the virtual-patch count](plots/vp_ssim.svg)"
    else
        echo "Not in this build: virtual patches are on another branch (\`vp\`). When \`rad render\`"
        echo "has the method, its rows above fill in, and setting VP_SWEEP in tools/report.sh to its patch-budget"
        echo "option makes this section sweep the budget ($VP_BUDGETS) on both scenes, with PSNR and SSIM plots."
    fi
    fi # REAL_ONLY
    echo
    echo "## Real scenes"
    echo
    cat "$TMP/real.md"
    echo
    echo "## Raw data"
    echo
    echo "data/: the log of every command (the timing lines, the compression reports; *.log.time: wall time and peak memory),"
    echo "metrics.txt and real-metrics.txt (id, method, MSE, PSNR, SSIM, [mean ratio,] ms), realtime.md (tests/bench/realtime.c's tables), temporal.md"
    echo "(the bench's tables), the plots' data files (.dat). Regenerate: \`make report\` (about $((T_ALL / 60 + 1)) min here)."
} > "$MD"
log "wrote $MD in $T_ALL s"
check_report "$OUT"
