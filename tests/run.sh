#!/usr/bin/env bash
# Runs every test suite and ends with one line "N passed, N failed[, N skipped]".
# A suite whose tool is missing is skipped (and named); with RAD_TEST_REQUIRE_ALL=1 a skipped
# suite counts as failed. Optional packages are installed first when we can (root with apt-get).
# Independent suites run side by side, RAD_TEST_JOBS at a time (default: the number of CPUs);
# RAD_TEST_STAGES="examples compile" runs only the suites of those names (see the end);
# each writes its own log and its own scratch folder, and the logs are printed in order at the end
# with each suite's wall and CPU seconds. The unit binary that valgrind runs and the rad tool are
# built once, first, and shared by the suites that run them.
set -u
cd "$(dirname "$0")/.."
CC=${CC:-cc}
CXX=${CXX:-c++}
BUILD=${BUILD:-build}/tests
case "$BUILD" in /*) ;; *) BUILD="$PWD/$BUILD" ;; esac
STAGES="$BUILD/stages"
rm -rf "$STAGES" "$BUILD/tmp"
mkdir -p "$BUILD" "$STAGES" "$BUILD/tmp"
JOBS=${RAD_TEST_JOBS:-$(nproc 2>/dev/null || echo 2)}
WARN="-Wall -Wextra -Wpedantic -Wshadow -Werror"
PASSED=0; FAILED=0; SKIPPED=0
SKIPPED_NAMES=""; FAILED_NAMES=""

have() { command -v "$1" >/dev/null 2>&1; }
try_install() { # package...
    if [ "$(id -u)" = 0 ] && have apt-get; then
        echo "installing $* (optional test packages)"
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "$@" >/dev/null 2>&1 ||
            { apt-get update -qq >/dev/null 2>&1 && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "$@" >/dev/null 2>&1; }
    fi
}
pass() { PASSED=$((PASSED + 1)); echo "  ok    $1"; }
fail() { FAILED=$((FAILED + 1)); FAILED_NAMES="$FAILED_NAMES $1"; echo "  FAIL  $1"; }
skip() {
    if [ "${RAD_TEST_REQUIRE_ALL:-0}" = 1 ]; then
        fail "$1 (required but skipped: $2)"
    else
        SKIPPED=$((SKIPPED + 1)); SKIPPED_NAMES="$SKIPPED_NAMES $1"; echo "  SKIP  $1: $2"
    fi
}
# compile step: name, then the command
build() {
    local name=$1; shift
    if "$@" >"$BUILD/$name.log" 2>&1; then return 0; fi
    echo "  build of $name failed:"; sed 's/^/    /' "$BUILD/$name.log" | head -40
    return 1
}
# a unit-test binary: adds its own "N passed, N failed" counts. RAD_TEST_SHARD=i/n in the
# environment runs every n-th test from the i-th (test_main.c).
unit() {
    local name=$1; shift
    local out="$BUILD/$name.out"
    echo "== $name"
    if [ -z "${UNIT_PREBUILT:-}" ]; then
        if ! build "$name" "$@" -o "$BUILD/$name" -lm; then fail "$name (build)"; return; fi
        UNIT_BIN="$BUILD/$name"
    fi
    ${UNIT_WRAP:-} "$UNIT_BIN" >"$out" 2>&1
    local rc=$?
    local line p f
    line=$(grep -E '^[0-9]+ passed, [0-9]+ failed' "$out" | tail -n 1)
    if [ -z "$line" ]; then
        tail -n 30 "$out" | sed 's/^/    /'
        fail "$name (crashed or printed no summary, exit $rc)"; return
    fi
    p=$(echo "$line" | sed -E 's/^([0-9]+) passed.*/\1/')
    f=$(echo "$line" | sed -E 's/^[0-9]+ passed, ([0-9]+) failed.*/\1/')
    PASSED=$((PASSED + p)); FAILED=$((FAILED + f))
    grep -E 'FAIL|error|==[0-9]+==' "$out" | head -40 | sed 's/^/    /'
    if [ "$rc" != 0 ] && [ "$f" = 0 ]; then fail "$name (exit $rc)"; fi
    [ "$f" = 0 ] || FAILED_NAMES="$FAILED_NAMES $name"
    echo "   $line"
}
# a compile-and-run test counted as one test
compile_run() {
    local name=$1; shift
    if build "$name" "$@" && "$BUILD/$name" >"$BUILD/$name.out" 2>&1; then pass "$name"; else fail "$name"; fi
}

# ---- the scheduler -------------------------------------------------------------------------
# stage NAME FUNCTION: runs FUNCTION in the background with fresh counters, its output in
# $STAGES/NAME.log and its counts in $STAGES/NAME.count; at most $JOBS at once.
STAGE_ORDER=""
# RAD_TEST_STAGES="a b": only the suites of those names (and the builds they run)
stage() {
    local name=$1 fn=$2
    wanted "$name" || return 0
    STAGE_ORDER="$STAGE_ORDER $name"
    while [ "$(jobs -rp | wc -l)" -ge "$JOBS" ]; do wait -n; done
    (
        PASSED=0; FAILED=0; SKIPPED=0; SKIPPED_NAMES=""; FAILED_NAMES=""
        export RAD_TEST_TMPDIR="$BUILD/tmp/$name" TMPDIR="$BUILD/tmp/$name"
        mkdir -p "$RAD_TEST_TMPDIR"
        start=$(date +%s)
        "$fn" >"$STAGES/$name.log" 2>&1
        secs=$(( $(date +%s) - start ))
        times >"$STAGES/$name.times" # here, not in $(...): a subshell would count its own children
        cpu=$(cpu_seconds <"$STAGES/$name.times")
        printf '%s %s %s %s %s\n%s\n%s\n' "$PASSED" "$FAILED" "$SKIPPED" "$secs" "$cpu" "$FAILED_NAMES" "$SKIPPED_NAMES" >"$STAGES/$name.count"
        echo "  [$(date +%H:%M:%S)] $name: $PASSED passed, $FAILED failed, $SKIPPED skipped ($secs s, CPU $cpu s)"
    ) &
}
# after NAME: waits until the stage NAME has finished (its counts are written last); a stage
# that runs what another builds calls it first, so it can take its place in the queue at once
after() {
    while [ ! -f "$STAGES/$1.count" ]; do sleep 1; done
}
wanted() {
    local w=" ${RAD_TEST_STAGES:-$1} "
    case "$1" in
        build-unit) [ -n "${w##* unit-O2 *}" ] && [ -n "${w##* valgrind-1 *}" ] && [ -n "${w##* valgrind-2 *}" ] && [ -n "${w##* build-unit *}" ] && return 1 ;;
        build-tool) [ -n "${w##* tool *}" ] && [ -n "${w##* report *}" ] && [ -n "${w##* dist *}" ] && [ -n "${w##* web *}" ] && [ -n "${w##* build-tool *}" ] && return 1 ;;
        *) [ -n "${w##* $1 *}" ] && return 1 ;;
    esac
    return 0
}
# user + system seconds of the finished children, from the second line of `times` on stdin
cpu_seconds() {
    sed -n 2p | awk '{ t = 0; for (i = 1; i <= 2; ++i) { split($i, a, /[ms]/); t += a[1] * 60 + a[2] } printf "%.0f", t }'
}

# ---- what this machine has (installs first: apt-get must not run beside the suites) --------
OMP=""
printf 'int main(void){return 0;}' | $CC -fopenmp -x c - -o /dev/null 2>/dev/null && OMP="-fopenmp"
vk_ready() { [ -f /usr/include/vulkan/vulkan.h ] && have glslangValidator && ls /usr/share/vulkan/icd.d/*.json >/dev/null 2>&1; }
[ -f /usr/include/embree3/rtcore.h ] || try_install libembree-dev
vk_ready || try_install mesa-vulkan-drivers libvulkan-dev glslang-tools
# the Khronos validation layer: test_vulkan turns it on when installed and fails on its messages
[ -f /usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json ] || try_install vulkan-validationlayers
have spirv-val || try_install spirv-tools
# the web suite: Chromium and node/npm (three.js itself comes from npm into build/web, once)
have chromium || try_install chromium
{ have node && have npm; } || try_install npm
{ [ -f /usr/include/assimp/cimport.h ] && [ -f /usr/include/stb/stb_image.h ]; } || try_install libassimp-dev libstb-dev
[ -f /usr/include/tinyexr.h ] || try_install libtinyexr-dev
have clang || try_install clang libclang-rt-14-dev
have valgrind || try_install valgrind
{ have mpicc && have mpirun; } || try_install libopenmpi-dev openmpi-bin
HAVE_ASAN_CLANG=0; HAVE_FUZZER=0
if have clang; then
    printf 'int main(void){return 0;}' | clang -fsanitize=address,undefined -x c - -o /dev/null 2>/dev/null && HAVE_ASAN_CLANG=1
    printf 'int LLVMFuzzerTestOneInput(const unsigned char *d, unsigned long n){(void)d;(void)n;return 0;}' |
        clang -fsanitize=fuzzer -x c - -o /dev/null 2>/dev/null && HAVE_FUZZER=1
fi

export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
SAN="-g -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=all"

# ---- the suites -----------------------------------------------------------------------------
# The full sizes run in the gcc -O2 build; the other code paths (OpenMP, scalar, AVX, native,
# Embree, clang) run every test at the quick sizes, as the sanitizers do.
# unit-O2 runs the binary built for valgrind (the same flags with -g), built once by s_unit_build.
s_unit_build() {
    rm -f "$BUILD/unit-O2-g" # the suites below run it when it exists: never one from an older run
    build unit-O2-g $CC -std=c99 $WARN -O2 -g -I. tests/test_main.c -o "$BUILD/unit-O2-g" -lm || fail "unit-O2 (build)"
}
s_unit_O2() {
    after build-unit
    [ -x "$BUILD/unit-O2-g" ] || return 0
    UNIT_PREBUILT=1 UNIT_BIN="$BUILD/unit-O2-g" unit unit-O2
}
s_unit_openmp() {
    if [ -n "$OMP" ]; then RAD_TEST_QUICK=1 unit unit-O2-openmp $CC -std=c99 $WARN -O2 $OMP -I. tests/test_main.c
    else skip unit-O2-openmp "$CC has no OpenMP"; fi
}
s_unit_scalar() { RAD_TEST_QUICK=1 unit unit-scalar $CC -std=c99 $WARN -O2 -DRAD_NO_SIMD -I. tests/test_main.c; }
s_unit_avx() { RAD_TEST_QUICK=1 unit unit-avx $CC -std=c99 $WARN -O2 -mavx -I. tests/test_main.c; }
# RAD_FMA and gnu99: the FMA kernels and contraction into FMA on (the watertight test must
# hold, and every determinism test within this build); the other native builds run without FMA
s_unit_native() { RAD_TEST_QUICK=1 unit unit-native $CC -std=gnu99 $WARN -O2 -march=native -DRAD_FMA $OMP -I. tests/test_main.c; }
s_unit_embree() {
    if [ -f /usr/include/embree3/rtcore.h ]; then
        RAD_TEST_QUICK=1 unit unit-embree $CC -std=c99 $WARN -O2 $OMP -DRAD_EMBREE -DRAD_TEST_EMBREE -I. tests/test_main.c -lembree3
    else
        skip unit-embree "Embree 3 is not installed (package libembree-dev)"
    fi
}
# The cover subset: the unit tests less those named in tests/cover_skip.txt. The tests it keeps
# run, between them, every basic block of radiosity.h that the whole quick suite runs (measured
# per test with clang's -fsanitize-coverage; docs/performance-notes.md says how to measure it
# again); the tests it leaves out run the same code again at other sizes, orders, seeds or
# thread counts. The short subset leaves out also the tests of tests/short_skip.txt (69 of
# the 5,667 blocks, more than half the cover subset's time). Valgrind and gcc's -O0 sanitizer
# build run the short subset, the two scalar sanitizer builds the cover subset; the sanitizer
# builds of gcc (-O1, this machine's SIMD, OpenMP) and clang (-O2, SSE) and every other build
# run every test. A new test is in both subsets until it is listed.
skip_list() { grep -hv '^#' "$@" | grep . | paste -sd, -; }
COVER_SKIP=$(skip_list tests/cover_skip.txt)
SHORT_SKIP=$(skip_list tests/cover_skip.txt tests/short_skip.txt)
# sanitizers at the quick sizes
s_asan_O0() { RAD_TEST_QUICK=1 RAD_TEST_SKIP="$SHORT_SKIP" unit unit-asan-ubsan-O0-short $CC -std=c99 $WARN -O0 $SAN -I. tests/test_main.c; }
s_asan_O2_scalar() { RAD_TEST_QUICK=1 RAD_TEST_SKIP="$COVER_SKIP" unit unit-asan-ubsan-O2-scalar-cover $CC -std=c99 $WARN -O2 -DRAD_NO_SIMD $SAN -I. tests/test_main.c; }
# the SIMD paths of this machine (AVX2 temporal lanes, BC1/BC4 apply, BVH) and the threads
# under the sanitizers, every test
s_asan_O1_native() { RAD_TEST_QUICK=1 unit unit-asan-ubsan-O1-native $CC -std=c99 $WARN -O1 -march=native $OMP $SAN -I. tests/test_main.c; }

s_compile() {
    compile_run compile-c99 $CC -std=c99 $WARN -I. tests/compile_c99.c -o "$BUILD/compile-c99" -lm
    compile_run compile-cpp11 $CXX -std=c++11 -Wall -Wextra -Wpedantic -Werror -I. tests/compile_cpp.cpp -o "$BUILD/compile-cpp11" -lm
    compile_run compile-static $CC -std=c99 $WARN -Wno-unused-function -I. tests/static_build.c -o "$BUILD/compile-static" -lm
    compile_run compile-custom-alloc $CC -std=c99 $WARN -I. tests/custom_alloc.c -o "$BUILD/compile-custom-alloc" -lm
    compile_run compile-no-glsl $CC -std=c99 $WARN -I. tests/compile_no_glsl.c -o "$BUILD/compile-no-glsl" -lm
    if build link-a $CC -std=c99 $WARN -I. -c tests/link_a.c -o "$BUILD/link_a.o" &&
       build link-b $CXX -std=c++11 -Wall -Wextra -Wpedantic -Werror -I. -c tests/link_b.cpp -o "$BUILD/link_b.o" &&
       build link-main $CC -std=c99 $WARN -I. -c tests/link_main.c -o "$BUILD/link_main.o" &&
       build link-exe $CXX "$BUILD/link_a.o" "$BUILD/link_b.o" "$BUILD/link_main.o" -o "$BUILD/link-c-cpp" -lm &&
       "$BUILD/link-c-cpp" >"$BUILD/link-c-cpp.out" 2>&1; then
        pass link-c-and-cpp
    else
        fail link-c-and-cpp
    fi
    # each unit-test file also builds on its own (fixtures.h, RAD_TEST_MAIN; test_tool.c is one
    # already): no file may use another's helpers (a syntax check; the unit builds compile them)
    local t alone=1
    for t in tests/test_*.c; do
        case "$t" in tests/test_main.c | tests/test_tool.c | tests/test_vulkan.c | tests/test_shading_vulkan.c) continue ;; esac
        build "alone-$(basename "$t" .c)" $CC -std=c99 $WARN $OMP -fsyntax-only -I. "$t" || alone=0
    done
    if [ $alone = 1 ]; then pass test-files-alone; else fail test-files-alone; fi
    fma_opt_in
    # ---- GLSL: the header holds the current tools/glsl/ sources
    if build glsl-embed $CC -std=c99 $WARN -O2 tools/glsl/embed.c -o "$BUILD/glsl_embed" &&
       "$BUILD/glsl_embed" --check radiosity.h >"$BUILD/glsl-embed.out" 2>&1; then
        pass glsl-embed-current
    else
        sed "s/^/    /" "$BUILD/glsl-embed.out" 2>/dev/null
        fail glsl-embed-current
    fi
}

# FMA only with RAD_FMA: a -march=native build of the implementation holds no fused
# multiply-add without it, and some with it (clang when installed: it contracts by default)
fma_opt_in() {
    local fcc=$CC n_off n_on
    have clang && fcc=clang
    if ! have objdump || ! $fcc -march=native -dM -E - </dev/null 2>/dev/null | grep -q __FMA__; then
        skip fma-opt-in "no objdump, or $fcc -march=native has no FMA on this CPU"; return
    fi
    printf '#define RADIOSITY_IMPLEMENTATION\n#include "radiosity.h"\n' >"$BUILD/impl-fma.c"
    if build fma-off $fcc -std=gnu99 -O1 -march=native -I. -c "$BUILD/impl-fma.c" -o "$BUILD/impl-fma-off.o" &&
       build fma-on $fcc -std=gnu99 -O1 -march=native -DRAD_FMA -I. -c "$BUILD/impl-fma.c" -o "$BUILD/impl-fma-on.o"; then
        n_off=$(objdump -d "$BUILD/impl-fma-off.o" | grep -cE 'vf(n)?m(add|sub)')
        n_on=$(objdump -d "$BUILD/impl-fma-on.o" | grep -cE 'vf(n)?m(add|sub)')
        if [ "$n_off" = 0 ] && [ "$n_on" -gt 0 ]; then pass fma-opt-in
        else echo "    fused multiply-adds: $n_off without RAD_FMA (want 0), $n_on with it (want some)"; fail fma-opt-in; fi
    else
        fail fma-opt-in
    fi
}

# what is written twice stays the same: docs/api.md is the header's index, the QUICK START
# comment is examples/quickstart.c, and tests/test_defaults.c covers every option struct
# (tests/check_docs.sh says the command that fixes each)
s_docs() {
    local doc
    for doc in api quickstart defaults; do
        if bash tests/check_docs.sh $doc >"$BUILD/check-docs-$doc.out" 2>&1; then pass "docs-$doc-current"
        else sed "s/^/    /" "$BUILD/check-docs-$doc.out"; fail "docs-$doc-current"; fi
    done
}

# The examples call only the API: each is compiled with
# RADIOSITY_IMPLEMENTATION_INCLUDED predefined (so its own #define RADIOSITY_IMPLEMENTATION brings
# in the declarations only) and linked with one object that holds the implementation, compiled
# once with the same flags, as a program of several files would be, instead of once per program.
# The serial object is built without OpenMP, for the examples that need only a C compiler.
impl_object() { # NAME, then the compiler and its flags
    local name=$1; shift
    printf '#define RADIOSITY_IMPLEMENTATION\n#include "radiosity.h"\n' >"$BUILD/$name.c"
    build "$name" "$@" -I. -c "$BUILD/$name.c" -o "$BUILD/$name.o"
}
s_examples() {
    local EX="$CC -std=c99 $WARN -O2 -DRADIOSITY_IMPLEMENTATION_INCLUDED -I."
    local IMPL_OMP="$OMP $BUILD/impl-examples.o" IMPL_SERIAL="$BUILD/impl-examples-serial.o"
    if ! impl_object impl-examples $CC -std=c99 $WARN -O2 $OMP || ! impl_object impl-examples-serial $CC -std=c99 $WARN -O2; then
        fail "examples (build of the implementation)"; return
    fi
    if build demo $EX examples/cornell.c $IMPL_OMP -o "$BUILD/cornell" -lm &&
       "$BUILD/cornell" --patches 300 --size 96x96 -o "$BUILD/cornell-small.png" >"$BUILD/demo.out" 2>&1 &&
       [ -s "$BUILD/cornell-small.png" ]; then
        pass demo-small
    else
        fail demo-small
    fi
    if build gallery $EX examples/gallery.c $IMPL_SERIAL -o "$BUILD/gallery" -lm &&
       "$BUILD/gallery" --size 12 -o "$BUILD/gallery-small.png" >"$BUILD/gallery.out" 2>&1 &&
       [ -s "$BUILD/gallery-small.png" ]; then
        pass gallery-small
    else
        fail gallery-small
    fi
    # hierarchical radiosity's links as an image
    if build learn-hierarchical $EX examples/learn_hierarchical.c $IMPL_SERIAL -o "$BUILD/learn_hierarchical" -lm &&
       "$BUILD/learn_hierarchical" --eps 1e-2 --size 64 -o "$BUILD/learn-hierarchical.png" >"$BUILD/learn-hierarchical.out" 2>&1 &&
       [ -s "$BUILD/learn-hierarchical.png" ] && grep -q 'links' "$BUILD/learn-hierarchical.out"; then
        pass learn-hierarchical
    else
        fail learn-hierarchical
    fi
    compile_run quickstart $EX examples/quickstart.c $IMPL_SERIAL -o "$BUILD/quickstart" -lm
    compile_run engine_bake $EX examples/engine_bake.c $IMPL_SERIAL -o "$BUILD/engine_bake" -lm
    compile_run engine_runtime $EX examples/engine_runtime.c $IMPL_SERIAL -o "$BUILD/engine_runtime" -lm
    compile_run learn_vertex_light $EX examples/learn_vertex_light.c $IMPL_SERIAL -o "$BUILD/learn_vertex_light" -lm
    if build lightmap-example $EX examples/lightmap.c $IMPL_OMP -o "$BUILD/lightmap" -lm &&
       "$BUILD/lightmap" --size 32 --patches 100 -o "$BUILD/lightmap-small.png" >"$BUILD/lightmap.out" 2>&1 &&
       [ -s "$BUILD/lightmap-small.png" ] && grep -q "valid" "$BUILD/lightmap.out"; then
        pass lightmap-small
    else
        fail lightmap-small
    fi
    # the virtual-patch example builds and, without the external meshes, says it skipped
    if build vp-bunny $EX examples/vp_bunny.c $IMPL_OMP -o "$BUILD/vp_bunny" -lm &&
       "$BUILD/vp_bunny" --data "$BUILD/no-such-data" >"$BUILD/vp_bunny.out" 2>&1 && grep -q skipped "$BUILD/vp_bunny.out"; then
        pass vp-bunny-skip
    else
        fail vp-bunny-skip
    fi
    # the engine loop over virtual patches: every stage timed, and the light reaches the vertices
    if build realtime $EX examples/realtime.c $IMPL_OMP -o "$BUILD/realtime" -lm &&
       "$BUILD/realtime" --patches 200 --frames 12 >"$BUILD/realtime.out" 2>&1 &&
       grep -q "mean per frame over 12 frames: E update" "$BUILD/realtime.out" &&
       awk '$1 == 11 { exit !($5 > 0) }' "$BUILD/realtime.out"; then
        pass realtime-small
    else
        sed "s/^/    /" "$BUILD/realtime.out" 2>/dev/null | tail -5
        fail realtime-small
    fi
    if build walk $EX examples/walk.c $IMPL_OMP -o "$BUILD/walk" -lm &&
       "$BUILD/walk" --grid 2 --m 256 --frames 2 --size 64x36 -o "$BUILD/walk-small" >"$BUILD/walk.out" 2>&1 &&
       [ -s "$BUILD/walk-small_001.png" ]; then
        pass walk-small
    else
        fail walk-small
    fi
    # temporal radiosity under a moving light: frames 0 and 3 written, different, 4 error rows
    if build moving-light $EX examples/moving_light.c $IMPL_OMP -o "$BUILD/moving_light" -lm &&
       "$BUILD/moving_light" --patches 150 --frames 4 --every 3 --size 32x32 -o "$BUILD/moving-small" >"$BUILD/moving-light.out" 2>&1 &&
       [ -s "$BUILD/moving-small_0000.png" ] && [ -s "$BUILD/moving-small_0003.png" ] && [ ! -e "$BUILD/moving-small_0001.png" ] &&
       ! cmp -s "$BUILD/moving-small_0000.png" "$BUILD/moving-small_0003.png" &&
       [ "$(awk -F, 'NR > 1 && $5 >= 0 && $5 < 10' "$BUILD/moving-small.csv" | cut -d, -f2-4 | sort -u | wc -l)" -eq 4 ]; then
        pass moving-light-small
    else
        fail moving-light-small
    fi
    # the teaching examples, at small sizes: each prints its table
    compile_run learn_formfactors $EX examples/learn_formfactors.c $IMPL_SERIAL -o "$BUILD/learn_formfactors" -lm
    if build learn_solvers $EX examples/learn_solvers.c $IMPL_OMP -o "$BUILD/learn_solvers" -lm &&
       "$BUILD/learn_solvers" --patches 100 --iterations 4 >"$BUILD/learn_solvers.out" 2>&1; then
        pass learn_solvers
    else
        fail learn_solvers
    fi
    if build learn_stochastic $EX examples/learn_stochastic.c $IMPL_OMP -o "$BUILD/learn_stochastic" -lm &&
       "$BUILD/learn_stochastic" --patches 60 --max-rays 4000 >"$BUILD/learn_stochastic.out" 2>&1; then
        pass learn_stochastic
    else
        fail learn_stochastic
    fi
}

# ---- web: `rad lightmap -o x.glb` shown by three.js in headless Chromium (tests/web/run.sh)
s_web() {
    if ! have_tool_deps; then skip web "assimp or stb is not installed (packages libassimp-dev libstb-dev)"; return; fi
    after build-tool
    [ -x "$BUILD/rad" ] || { fail "web (no rad: the tool did not build)"; return; }
    echo "== web: three.js shows the baked glb"
    local out rc
    out=$(bash tests/web/run.sh "$BUILD/rad" "$BUILD/web" 2>&1)
    rc=$?
    echo "$out" | grep -v '^skip:' | sed 's/^/  /'
    if [ $rc = 77 ]; then skip web "$(echo "$out" | sed -n 's/^skip: //p' | tail -n 1)"
    elif [ $rc = 0 ]; then pass "web (three.js in Chromium agrees with the tool)"
    else fail web; fi
}

# ---- Vulkan: every GLSL kernel against the CPU path (lavapipe is enough)
s_vulkan() {
    if ! vk_ready; then
        skip vulkan "no Vulkan headers, Vulkan driver or glslangValidator (packages mesa-vulkan-drivers libvulkan-dev glslang-tools)"
        return
    fi
    echo "== GLSL sources compile on their own"
    for f in tools/glsl/*.comp; do
        spv="$BUILD/$(basename "$f").spv"
        if glslangValidator -V --target-env vulkan1.1 "$f" -o "$spv" >"$BUILD/glslang.log" 2>&1 &&
           { ! have spirv-val || spirv-val --target-env vulkan1.1 "$spv" >>"$BUILD/glslang.log" 2>&1; }; then pass "glslang $f"
        else sed 's/^/    /' "$BUILD/glslang.log" | head -20; fail "glslang $f"; fi
    done
    have spirv-val || skip spirv-val "spirv-val is not installed (package spirv-tools)"
    unit vulkan-kernels $CC -std=c99 $WARN -O2 -I. tests/test_vulkan.c -lvulkan
    if build vulkan-example $CC -std=c99 $WARN -O2 -I. examples/vulkan_temporal.c -o "$BUILD/vulkan_temporal" -lvulkan -lm &&
       { if [ -f /usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json ]; then
             VK_INSTANCE_LAYERS=VK_LAYER_KHRONOS_validation "$BUILD/vulkan_temporal" --patches 200 --frames 30 --tmp "$BUILD"
         else "$BUILD/vulkan_temporal" --patches 200 --frames 30 --tmp "$BUILD"; fi; } >"$BUILD/vulkan-example.out" 2>&1 &&
       ! grep -q 'Validation Error' "$BUILD/vulkan-example.out"; then
        pass "vulkan-example ($(tail -n 1 "$BUILD/vulkan-example.out"))"
    else
        tail -n 20 "$BUILD/vulkan-example.out" 2>/dev/null | sed 's/^/    /'
        fail vulkan-example
    fi
    # the GLSL lighting models against C on the same device
    if build shading-vulkan $CC -std=c99 $WARN -O2 -I. tests/test_shading_vulkan.c -o "$BUILD/shading-vulkan" -lvulkan -lm; then
        "$BUILD/shading-vulkan" . >"$BUILD/shading-vulkan.out" 2>&1
        rc=$?
        sed 's/^/    /' "$BUILD/shading-vulkan.out" | tail -n 12
        if [ $rc = 0 ]; then pass shading-vulkan
        elif [ $rc = 77 ]; then skip shading-vulkan "$(grep -m1 '^skip' "$BUILD/shading-vulkan.out")"
        else fail shading-vulkan; fi
    else
        fail "shading-vulkan (build)"
    fi
}

# ---- the rad tool (needs assimp and stb; OpenEXR output with tinyexr when installed)
EXR_CFLAGS=""; EXR_LIB=""
[ -f /usr/include/tinyexr.h ] && { EXR_CFLAGS="-DTOOL_EXR"; EXR_LIB="-ltinyexr"; }
have_tool_deps() { [ -f /usr/include/assimp/cimport.h ] && [ -f /usr/include/stb/stb_image.h ]; }
# The tool's objects, compiled once: rad links them with main.c, rad-mpi with its own main; the
# tool, report and distributed suites all run this rad.
TOOL_OBJ="$BUILD/tool-obj"
s_tool_build() {
    if ! have_tool_deps; then
        skip tool-suites "assimp or stb is not installed (packages libassimp-dev libstb-dev)"
        return
    fi
    local f
    rm -rf "$BUILD/rad" "$TOOL_OBJ" # the suites below run rad when it exists: never one from an older run
    mkdir -p "$TOOL_OBJ"
    for f in tools/*.c; do
        build "tool-$(basename "$f" .c)" $CC -std=c99 $WARN -O2 $OMP -I. $EXR_CFLAGS -c "$f" -o "$TOOL_OBJ/$(basename "$f" .c).o" ||
            { fail "tool-build ($f)"; return; }
    done
    if build tool-link $CC $OMP "$TOOL_OBJ"/*.o -o "$BUILD/rad" -lassimp $EXR_LIB -lm; then pass tool-build; else fail tool-build; fi
}
s_tool() {
    after build-tool
    [ -x "$BUILD/rad" ] || return 0
    echo "== tool tests"
    local out nf ns
    out=$(bash tests/tool_tests.sh "$BUILD/rad" 2>&1)
    echo "$out" | grep -E '^(ok|FAIL|SKIP)' | sed 's/^/  /'
    PASSED=$((PASSED + $(echo "$out" | grep -c '^ok')))
    nf=$(echo "$out" | grep -c '^FAIL')
    FAILED=$((FAILED + nf))
    [ "$nf" = 0 ] || FAILED_NAMES="$FAILED_NAMES tool-tests"
    # skip-data: a check of meshes from RAD_DATA_DIR, which the repository does not hold (never
    # a failure); skip: a missing tool (a failure under RAD_TEST_REQUIRE_ALL=1)
    echo "$out" | grep -E '^skip' | while read -r line; do echo "  $line"; done
    ns=$(echo "$out" | grep -c '^skip ')
    if [ "$ns" -gt 0 ]; then
        if [ "${RAD_TEST_REQUIRE_ALL:-0}" = 1 ]; then FAILED=$((FAILED + ns)); FAILED_NAMES="$FAILED_NAMES tool-tests(skipped)"
        else SKIPPED=$((SKIPPED + ns)); SKIPPED_NAMES="$SKIPPED_NAMES tool-tests"; fi
    fi
}
# the evaluation report at quick quality (make report-quick): every table cell filled, every
# image written (tools/report.sh --check)
s_report() {
    after build-tool
    [ -x "$BUILD/rad" ] || return 0
    if build report-temporal $CC -std=c99 $WARN -O2 $OMP -I. tests/bench/temporal.c -o "$BUILD/temporal" -lm &&
       bash tools/report.sh --quick --out "$BUILD/report-quick" \
           --rad "$BUILD/rad" --temporal-bench "$BUILD/temporal" >"$BUILD/report-quick.log" 2>&1; then
        pass "report-quick ($(tail -n 1 "$BUILD/report-quick.log" | sed 's/.*: \([0-9]* table rows, [0-9]* images\).*/\1/'))"
    else
        fail report-quick; tail -n 20 "$BUILD/report-quick.log" | sed 's/^/    /'
    fi
}
# the distributed bake (tests/dist_tests.sh): shards, merge and, with OpenMPI, tools/rad-mpi
# (the tool's objects linked with its own main)
s_dist() {
    after build-tool
    [ -x "$BUILD/rad" ] || return 0
    local mpi="" out nf ns
    if ! build dist-part-edit $CC -std=c99 $WARN -O2 -I. tests/dist_part_edit.c -o "$BUILD/dist_part_edit" -lm; then
        fail "dist (build)"; return
    fi
    if have mpicc && have mpirun; then
        if build rad-mpi mpicc -std=c99 $WARN -O2 $OMP -I. tools/mpi/rad_mpi.c $(ls "$TOOL_OBJ"/*.o | grep -v '/main\.o$') \
               -o "$BUILD/rad-mpi" -lassimp $EXR_LIB -lm; then
            mpi="$BUILD/rad-mpi"
        else
            fail "rad-mpi (build)"
        fi
    fi
    echo "== distributed bake"
    out=$(bash tests/dist_tests.sh "$BUILD/rad" "$BUILD/dist_part_edit" "$mpi" 2>&1)
    echo "$out" | grep -E '^(ok|FAIL)' | sed 's/^/  /'
    PASSED=$((PASSED + $(echo "$out" | grep -c '^ok')))
    nf=$(echo "$out" | grep -c '^FAIL')
    FAILED=$((FAILED + nf))
    [ "$nf" = 0 ] || FAILED_NAMES="$FAILED_NAMES dist-tests"
    ns=$(echo "$out" | grep -c '^skip ')
    [ "$ns" = 0 ] || skip dist-mpi "$(echo "$out" | grep -m1 '^skip ' | sed 's/^skip [^:]*: //')"
}
s_test_tool() {
    have_tool_deps || return 0
    unit test-tool $CC -std=c99 $WARN -O2 $OMP -I. tests/test_tool.c tools/image.c tools/metrics.c tools/trace.c
}

# ---- clang
s_clang() {
    if ! { have clang && have clang++; }; then skip clang-suites "clang is not installed (package clang)"; return; fi
    RAD_TEST_QUICK=1 unit unit-clang-O2 clang -std=c99 $WARN -O2 -I. tests/test_main.c
    compile_run compile-clang-c99 clang -std=c99 $WARN -I. tests/compile_c99.c -o "$BUILD/compile-clang-c99" -lm
    compile_run compile-clang-cpp11 clang++ -std=c++11 -Wall -Wextra -Wpedantic -Werror -I. tests/compile_cpp.cpp -o "$BUILD/compile-clang-cpp11" -lm
}
s_clang_asan_O2() {
    have clang || return 0
    if [ "$HAVE_ASAN_CLANG" = 1 ]; then
        RAD_TEST_QUICK=1 unit unit-clang-asan-ubsan-O2 clang -std=c99 $WARN -O2 $SAN -I. tests/test_main.c
    else
        skip unit-clang-asan-ubsan "clang's sanitizer runtime is missing (package libclang-rt-14-dev)"
    fi
}
# (gcc's sanitizer build covers -O0; clang's scalar one runs at -O1, three times faster)
s_clang_asan_O1() {
    [ "$HAVE_ASAN_CLANG" = 1 ] || return 0
    RAD_TEST_QUICK=1 RAD_TEST_SKIP="$COVER_SKIP" unit unit-clang-asan-ubsan-O1-scalar-cover clang -std=c99 $WARN -O1 -DRAD_NO_SIMD $SAN -I. tests/test_main.c
}
# libFuzzer smoke runs (the long runs are `make fuzz`, recorded in docs/FUZZING.md); TMPDIR: where
# fuzz_stream writes its input file (left behind when it crashes). One binary holds every
# harness (tests/fuzz/smoke.c, FUZZ_TARGET picks one), so the implementation is compiled once.
FUZZERS="container scene stream multibounce temporal vp"
s_fuzz() {
    have clang || return 0
    if [ "$HAVE_FUZZER" != 1 ]; then skip fuzz-smoke "clang has no libFuzzer runtime (package libclang-rt-14-dev)"; return; fi
    echo "== fuzz smoke"
    local f
    for f in $FUZZERS; do mkdir -p "$BUILD/fuzz/$f"; done
    if ! { build make-corpus $CC -std=c99 -O2 -I. tests/fuzz/make_corpus.c -o "$BUILD/make_corpus" -lm &&
           "$BUILD/make_corpus" "$BUILD/fuzz"; }; then
        fail fuzz-corpus; return
    fi
    rm -f "$BUILD/fuzz_smoke"
    if ! build fuzz-smoke clang -std=c99 -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -I. tests/fuzz/smoke.c -o "$BUILD/fuzz_smoke" -lm; then
        fail "fuzz (build)"; return
    fi
    for f in $FUZZERS; do
        if { ! ls tests/fuzz/crashes/"$f"-* >/dev/null 2>&1 || FUZZ_TARGET=$f "$BUILD/fuzz_smoke" tests/fuzz/crashes/"$f"-* >"$BUILD/fuzz-$f.log" 2>&1; } &&
           FUZZ_TARGET=$f "$BUILD/fuzz_smoke" -max_total_time="${RAD_FUZZ_SECONDS:-15}" -rss_limit_mb=2048 -artifact_prefix="$BUILD/fuzz-$f-" \
               "$BUILD/fuzz/$f" >"$BUILD/fuzz-$f.log" 2>&1; then
            pass "fuzz-$f ($(grep -o 'Done [0-9]* runs' "$BUILD/fuzz-$f.log"))"
        else
            tail -20 "$BUILD/fuzz-$f.log" 2>/dev/null | sed 's/^/    /'
            fail "fuzz-$f"
        fi
    done
}

# ---- valgrind memcheck: the -O2 -g unit build, the cover subset at the quick sizes, in two
# halves that run side by side. What valgrind finds that the sanitizers do not is a read of
# memory never written (and it checks the -O2 code gcc makes, which no sanitizer build runs);
# such a read shows when its code runs, so running each block once is what counts: valgrind
# runs the short subset (above), a quarter of the quick suite's CPU seconds.
VALGRIND_SHARDS=2
s_valgrind_shard() {
    local i=$1
    if ! have valgrind; then [ "$i" != 0 ] || skip valgrind-memcheck "valgrind is not installed (package valgrind)"; return; fi
    after build-unit
    [ -x "$BUILD/unit-O2-g" ] || return 0
    RAD_TEST_QUICK=1 RAD_TEST_SHARD="$i/$VALGRIND_SHARDS" RAD_TEST_SKIP="$SHORT_SKIP" UNIT_PREBUILT=1 UNIT_BIN="$BUILD/unit-O2-g" \
        UNIT_WRAP="valgrind --error-exitcode=99 --leak-check=full --errors-for-leak-kinds=definite,indirect,possible --quiet" \
        unit "valgrind-memcheck-short-$((i + 1))of$VALGRIND_SHARDS"
}
s_valgrind_0() { s_valgrind_shard 0; }
s_valgrind_1() { s_valgrind_shard 1; }

# ---- run: the longest first, so the last to finish are short ----------------------------
echo "running the suites, $JOBS at a time (logs in $STAGES)"
RUN_START=$(date +%s)
# first the shared builds, side by side; the suites that run them wait for them (after)
stage build-unit s_unit_build
stage build-tool s_tool_build
# in the order of their CPU seconds on an idle machine (printed at the end of each run)
stage fuzz s_fuzz
stage valgrind-1 s_valgrind_0
stage valgrind-2 s_valgrind_1
stage asan-O0 s_asan_O0
stage asan-O1-native s_asan_O1_native
stage asan-O2-scalar s_asan_O2_scalar
stage clang-asan-O2 s_clang_asan_O2
stage clang-asan-O1 s_clang_asan_O1
stage unit-O2 s_unit_O2
stage tool s_tool
stage unit-openmp s_unit_openmp
stage unit-scalar s_unit_scalar
stage unit-embree s_unit_embree
stage unit-native s_unit_native
stage vulkan s_vulkan
stage web s_web
stage report s_report
stage clang s_clang
stage unit-avx s_unit_avx
stage examples s_examples
stage compile s_compile
stage docs s_docs
stage test-tool s_test_tool
stage dist s_dist
wait
RUN_SECS=$(( $(date +%s) - RUN_START ))

echo
CPU_TOTAL=0
for name in $STAGE_ORDER; do
    c="$STAGES/$name.count"
    if [ ! -f "$c" ]; then
        echo "== [$name] printed no counts"; cat "$STAGES/$name.log" 2>/dev/null
        FAILED=$((FAILED + 1)); FAILED_NAMES="$FAILED_NAMES $name(stage)"; continue
    fi
    read -r p f s secs cpu <"$c"
    echo "==== [$name: $secs s, CPU $cpu s]"
    cat "$STAGES/$name.log"
    PASSED=$((PASSED + p)); FAILED=$((FAILED + f)); SKIPPED=$((SKIPPED + s)); CPU_TOTAL=$((CPU_TOTAL + cpu))
    FAILED_NAMES="$FAILED_NAMES$(sed -n 2p "$c")"
    SKIPPED_NAMES="$SKIPPED_NAMES$(sed -n 3p "$c")"
done

echo
echo "suites: $RUN_SECS s wall, $CPU_TOTAL s CPU, $JOBS at a time"
[ -z "$SKIPPED_NAMES" ] || echo "skipped suites:$SKIPPED_NAMES"
[ -z "$FAILED_NAMES" ] || echo "failed:$FAILED_NAMES"
if [ "$SKIPPED" -gt 0 ]; then
    echo "$PASSED passed, $FAILED failed, $SKIPPED skipped"
else
    echo "$PASSED passed, $FAILED failed"
fi
[ "$FAILED" = 0 ]
