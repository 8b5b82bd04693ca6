#!/usr/bin/env bash
# Runs every test suite and ends with one line "N passed, N failed[, N skipped]".
# A suite whose tool is missing is skipped (and named); with RAD_TEST_REQUIRE_ALL=1 a skipped
# suite counts as failed. Optional packages are installed when we can (root with apt-get).
set -u
cd "$(dirname "$0")/.."
CC=${CC:-cc}
CXX=${CXX:-c++}
BUILD=${BUILD:-build}/tests
mkdir -p "$BUILD"
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
# a unit-test binary: adds its own "N passed, N failed" counts
unit() {
    local name=$1; shift
    local out="$BUILD/$name.out"
    echo "== $name"
    if ! build "$name" "$@" -o "$BUILD/$name" -lm; then fail "$name (build)"; return; fi
    "$BUILD/$name" >"$out" 2>&1
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
    grep -E 'FAIL|error' "$out" | head -40 | sed 's/^/    /'
    if [ "$rc" != 0 ] && [ "$f" = 0 ]; then fail "$name (exit $rc)"; fi
    [ "$f" = 0 ] || FAILED_NAMES="$FAILED_NAMES $name"
    echo "   $line"
}
# a compile-and-run test counted as one test
compile_run() {
    local name=$1; shift
    if build "$name" "$@" && "$BUILD/$name" >"$BUILD/$name.out" 2>&1; then pass "$name"; else fail "$name"; fi
}

OMP=""
printf 'int main(void){return 0;}' | $CC -fopenmp -x c - -o /dev/null 2>/dev/null && OMP="-fopenmp"

# ---- unit tests with the default compiler -------------------------------------------------
unit unit-O2 $CC -std=c99 $WARN -O2 -I. tests/test_main.c
if [ -n "$OMP" ]; then
    unit unit-O2-openmp $CC -std=c99 $WARN -O2 $OMP -I. tests/test_main.c
else
    skip unit-O2-openmp "$CC has no OpenMP"
fi
unit unit-scalar $CC -std=c99 $WARN -O2 -DRAD_NO_SIMD -I. tests/test_main.c
unit unit-avx $CC -std=c99 $WARN -O2 -mavx -I. tests/test_main.c
unit unit-native $CC -std=c99 $WARN -O2 -march=native $OMP -I. tests/test_main.c

# ---- Embree backend (optional: installed when we can) -------------------------------------
[ -f /usr/include/embree3/rtcore.h ] || try_install libembree-dev
if [ -f /usr/include/embree3/rtcore.h ]; then
    unit unit-embree $CC -std=c99 $WARN -O2 $OMP -DRAD_EMBREE -DRAD_TEST_EMBREE -I. tests/test_main.c -lembree3
else
    skip unit-embree "Embree 3 is not installed (package libembree-dev)"
fi

# ---- sanitizers ---------------------------------------------------------------------------
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
SAN="-g -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=all"
RAD_TEST_QUICK=1 unit unit-asan-ubsan-O0 $CC -std=c99 $WARN -O0 $SAN -I. tests/test_main.c
RAD_TEST_QUICK=1 unit unit-asan-ubsan-O2-scalar $CC -std=c99 $WARN -O2 -DRAD_NO_SIMD $SAN -I. tests/test_main.c
# the SIMD paths of this machine (AVX2 temporal lanes, BC1/BC4 apply, BVH) under the sanitizers
RAD_TEST_QUICK=1 unit unit-asan-ubsan-O1-native $CC -std=c99 $WARN -O1 -march=native $OMP $SAN -I. tests/test_main.c

# ---- compile tests ------------------------------------------------------------------------
echo "== compile tests"
compile_run compile-c99 $CC -std=c99 $WARN -I. tests/compile_c99.c -o "$BUILD/compile-c99" -lm
compile_run compile-cpp11 $CXX -std=c++11 -Wall -Wextra -Wpedantic -Werror -I. tests/compile_cpp.cpp -o "$BUILD/compile-cpp11" -lm
compile_run compile-static $CC -std=c99 $WARN -Wno-unused-function -I. tests/static_build.c -o "$BUILD/compile-static" -lm
compile_run compile-custom-alloc $CC -std=c99 $WARN -I. tests/custom_alloc.c -o "$BUILD/compile-custom-alloc" -lm
if build demo $CC -std=c99 $WARN -O2 $OMP -I. examples/cornell.c -o "$BUILD/cornell" -lm &&
   "$BUILD/cornell" --patches 300 --size 96x96 -o "$BUILD/cornell-small.png" >"$BUILD/demo.out" 2>&1 &&
   [ -s "$BUILD/cornell-small.png" ]; then
    pass demo-small
else
    fail demo-small
fi
if build gallery $CC -std=c99 $WARN -O2 -I. examples/gallery.c -o "$BUILD/gallery" -lm &&
   "$BUILD/gallery" --size 12 -o "$BUILD/gallery-small.png" >"$BUILD/gallery.out" 2>&1 &&
   [ -s "$BUILD/gallery-small.png" ]; then
    pass gallery-small
else
    fail gallery-small
fi
compile_run quickstart $CC -std=c99 $WARN -O2 -I. examples/quickstart.c -o "$BUILD/quickstart" -lm
# the virtual-patch example builds and, without the shared data, says it skipped
if build vp-bunny $CC -std=c99 $WARN -O2 $OMP -I. examples/vp_bunny.c -o "$BUILD/vp_bunny" -lm &&
   "$BUILD/vp_bunny" --data "$BUILD/no-such-data" >"$BUILD/vp_bunny.out" 2>&1 && grep -q skipped "$BUILD/vp_bunny.out"; then
    pass vp-bunny-skip
else
    fail vp-bunny-skip
fi
if build walk $CC -std=c99 $WARN -O2 $OMP -I. examples/walk.c -o "$BUILD/walk" -lm &&
   "$BUILD/walk" --grid 2 --m 256 --frames 2 --size 64x36 -o "$BUILD/walk-small" >"$BUILD/walk.out" 2>&1 &&
   [ -s "$BUILD/walk-small_001.png" ]; then
    pass walk-small
else
    fail walk-small
fi
# temporal radiosity under a moving light: frames 0 and 3 written, different, 4 error rows
if build moving-light $CC -std=c99 $WARN -O2 $OMP -I. examples/moving_light.c -o "$BUILD/moving_light" -lm &&
   "$BUILD/moving_light" --patches 150 --frames 4 --every 3 --size 32x32 -o "$BUILD/moving-small" >"$BUILD/moving-light.out" 2>&1 &&
   [ -s "$BUILD/moving-small_0000.png" ] && [ -s "$BUILD/moving-small_0003.png" ] && [ ! -e "$BUILD/moving-small_0001.png" ] &&
   ! cmp -s "$BUILD/moving-small_0000.png" "$BUILD/moving-small_0003.png" &&
   [ "$(awk -F, 'NR > 1 && $5 >= 0 && $5 < 10' "$BUILD/moving-small.csv" | cut -d, -f2-4 | sort -u | wc -l)" -eq 4 ]; then
    pass moving-light-small
else
    fail moving-light-small
fi
# ---- GLSL: the header holds the current glsl/ sources --------------------------------------
if build glsl-embed $CC -std=c99 $WARN -O2 glsl/embed.c -o "$BUILD/glsl_embed" &&
   "$BUILD/glsl_embed" --check radiosity.h >"$BUILD/glsl-embed.out" 2>&1; then
    pass glsl-embed-current
else
    cat "$BUILD/glsl-embed.out" 2>/dev/null | sed "s/^/    /"
    fail glsl-embed-current
fi
# ---- Vulkan: every GLSL kernel against the CPU path (lavapipe is enough; installed when we can)
vk_ready() { [ -f /usr/include/vulkan/vulkan.h ] && have glslangValidator && ls /usr/share/vulkan/icd.d/*.json >/dev/null 2>&1; }
vk_ready || try_install mesa-vulkan-drivers libvulkan-dev glslang-tools
# the Khronos validation layer: test_vulkan turns it on when installed and fails on its messages
[ -f /usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json ] || try_install vulkan-validationlayers
if vk_ready; then
    echo "== GLSL sources compile on their own"
    have spirv-val || try_install spirv-tools
    for f in glsl/*.comp; do
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
else
    skip vulkan "no Vulkan headers, Vulkan driver or glslangValidator (packages mesa-vulkan-drivers libvulkan-dev glslang-tools)"
fi
# ---- GLSL lighting models against C on a Vulkan device (lavapipe is enough) ----------------
{ have glslangValidator && [ -f /usr/include/vulkan/vulkan.h ]; } || try_install glslang-tools libvulkan-dev mesa-vulkan-drivers
if have glslangValidator && [ -f /usr/include/vulkan/vulkan.h ]; then
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
else
    skip shading-vulkan "glslangValidator or the Vulkan headers are missing (packages glslang-tools libvulkan-dev mesa-vulkan-drivers)"
fi
# ---- the rad tool (needs assimp and stb: installed when we can) --------------------------
{ [ -f /usr/include/assimp/cimport.h ] && [ -f /usr/include/stb/stb_image.h ]; } || try_install libassimp-dev libstb-dev
if [ -f /usr/include/assimp/cimport.h ] && [ -f /usr/include/stb/stb_image.h ]; then
    if build tool-rad $CC -std=c99 $WARN -O2 $OMP -I. tools/*.c -o "$BUILD/rad" -lassimp -lm; then
        pass tool-build
        echo "== tool tests"
        out=$(RAD_DATA_DIR="${RAD_DATA_DIR:-../shared/data}" bash tests/tool_tests.sh "$BUILD/rad" 2>&1)
        echo "$out" | grep -E '^(ok|FAIL|SKIP)' | sed 's/^/  /'
        PASSED=$((PASSED + $(echo "$out" | grep -c '^ok')))
        nf=$(echo "$out" | grep -c '^FAIL')
        FAILED=$((FAILED + nf))
        [ "$nf" = 0 ] || FAILED_NAMES="$FAILED_NAMES tool-tests"
        echo "$out" | grep -E '^skip' | while read -r line; do echo "  $line"; done
        ns=$(echo "$out" | grep -c '^skip')
        if [ "$ns" -gt 0 ]; then
            if [ "${RAD_TEST_REQUIRE_ALL:-0}" = 1 ]; then FAILED=$((FAILED + ns)); FAILED_NAMES="$FAILED_NAMES tool-tests(skipped)"
            else SKIPPED=$((SKIPPED + ns)); SKIPPED_NAMES="$SKIPPED_NAMES tool-tests"; fi
        fi
        # the evaluation report at quick quality (make report-quick): every table cell filled,
        # every image written (tools/report.sh --check)
        if build report-temporal $CC -std=c99 $WARN -O2 $OMP -I. bench/temporal.c -o "$BUILD/temporal" -lm &&
            RAD_DATA_DIR="${RAD_DATA_DIR:-../shared/data}" bash tools/report.sh --quick --out "$BUILD/report-quick" \
                --rad "$BUILD/rad" --temporal-bench "$BUILD/temporal" >"$BUILD/report-quick.log" 2>&1; then
            pass "report-quick ($(tail -n 1 "$BUILD/report-quick.log" | sed 's/.*: \([0-9]* table rows, [0-9]* images\).*/\1/'))"
        else
            fail report-quick; tail -n 20 "$BUILD/report-quick.log" | sed 's/^/    /'
        fi
    else
        fail tool-build
    fi
    if [ -f tests/test_tool.c ]; then
        unit test-tool $CC -std=c99 $WARN -O2 $OMP -I. tests/test_tool.c tools/image.c tools/metrics.c tools/trace.c
    fi
else
    skip tool-suites "assimp or stb is not installed (packages libassimp-dev libstb-dev)"
fi
if build link-a $CC -std=c99 $WARN -I. -c tests/link_a.c -o "$BUILD/link_a.o" &&
   build link-b $CXX -std=c++11 -Wall -Wextra -Wpedantic -Werror -I. -c tests/link_b.cpp -o "$BUILD/link_b.o" &&
   build link-main $CC -std=c99 $WARN -I. -c tests/link_main.c -o "$BUILD/link_main.o" &&
   build link-exe $CXX "$BUILD/link_a.o" "$BUILD/link_b.o" "$BUILD/link_main.o" -o "$BUILD/link-c-cpp" -lm &&
   "$BUILD/link-c-cpp" >"$BUILD/link-c-cpp.out" 2>&1; then
    pass link-c-and-cpp
else
    fail link-c-and-cpp
fi

# ---- clang (optional: installed when we can) ---------------------------------------------
have clang || try_install clang libclang-rt-14-dev
if have clang && have clang++; then
    unit unit-clang-O2 clang -std=c99 $WARN -O2 -I. tests/test_main.c
    compile_run compile-clang-c99 clang -std=c99 $WARN -I. tests/compile_c99.c -o "$BUILD/compile-clang-c99" -lm
    compile_run compile-clang-cpp11 clang++ -std=c++11 -Wall -Wextra -Wpedantic -Werror -I. tests/compile_cpp.cpp -o "$BUILD/compile-clang-cpp11" -lm
    if printf 'int main(void){return 0;}' | clang -fsanitize=address,undefined -x c - -o /dev/null 2>/dev/null; then
        RAD_TEST_QUICK=1 unit unit-clang-asan-ubsan-O2 clang -std=c99 $WARN -O2 $SAN -I. tests/test_main.c
        RAD_TEST_QUICK=1 unit unit-clang-asan-ubsan-O0-scalar clang -std=c99 $WARN -O0 -DRAD_NO_SIMD $SAN -I. tests/test_main.c
    else
        skip unit-clang-asan-ubsan "clang's sanitizer runtime is missing (package libclang-rt-14-dev)"
    fi
    # libFuzzer smoke runs (the long runs are `make fuzz`, recorded in FUZZING.md)
    if printf 'int LLVMFuzzerTestOneInput(const unsigned char *d, unsigned long n){(void)d;(void)n;return 0;}' |
        clang -fsanitize=fuzzer -x c - -o /dev/null 2>/dev/null; then
        echo "== fuzz smoke"
        # one harness per loader; the builds (about 45 s each) run two at a time; TMPDIR: where
        # fuzz_stream writes its input file (left behind when it crashes)
        FUZZERS="container scene stream multibounce temporal"
        for f in $FUZZERS; do mkdir -p "$BUILD/fuzz/$f"; done
        if build make-corpus $CC -std=c99 -O2 -I. fuzz/make_corpus.c -o "$BUILD/make_corpus" -lm &&
           "$BUILD/make_corpus" "$BUILD/fuzz"; then
            running=0
            for f in $FUZZERS; do
                rm -f "$BUILD/fuzz_$f"
                build "fuzz-$f" clang -std=c99 -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -I. "fuzz/fuzz_$f.c" -o "$BUILD/fuzz_$f" -lm &
                running=$((running + 1))
                if [ "$running" -ge 2 ]; then wait -n; running=$((running - 1)); fi
            done
            wait
            for f in $FUZZERS; do
                if [ -x "$BUILD/fuzz_$f" ] &&
                   { ! ls fuzz/crashes/"$f"-* >/dev/null 2>&1 || TMPDIR="$BUILD" "$BUILD/fuzz_$f" fuzz/crashes/"$f"-* >"$BUILD/fuzz-$f.log" 2>&1; } &&
                   TMPDIR="$BUILD" "$BUILD/fuzz_$f" -max_total_time="${RAD_FUZZ_SECONDS:-15}" -rss_limit_mb=2048 -artifact_prefix="$BUILD/fuzz-$f-" \
                       "$BUILD/fuzz/$f" >"$BUILD/fuzz-$f.log" 2>&1; then
                    pass "fuzz-$f ($(grep -o 'Done [0-9]* runs' "$BUILD/fuzz-$f.log"))"
                else
                    tail -20 "$BUILD/fuzz-$f.log" 2>/dev/null | sed 's/^/    /'
                    fail "fuzz-$f"
                fi
            done
        else
            fail fuzz-corpus
        fi
    else
        skip fuzz-smoke "clang has no libFuzzer runtime (package libclang-rt-14-dev)"
    fi
else
    skip clang-suites "clang is not installed (package clang)"
fi

# ---- valgrind memcheck (optional: installed when we can) ---------------------------------
have valgrind || try_install valgrind
if have valgrind; then
    echo "== valgrind memcheck"
    if build unit-valgrind $CC -std=c99 $WARN -O2 -g -I. tests/test_main.c -o "$BUILD/unit-valgrind" -lm &&
       RAD_TEST_QUICK=1 valgrind --error-exitcode=99 --leak-check=full --errors-for-leak-kinds=definite,indirect,possible \
           --quiet "$BUILD/unit-valgrind" >"$BUILD/valgrind.out" 2>&1; then
        pass "valgrind-memcheck ($(tail -n 1 "$BUILD/valgrind.out"))"
    else
        grep -E '==[0-9]+==' "$BUILD/valgrind.out" | head -30 | sed 's/^/    /'
        fail valgrind-memcheck
    fi
else
    skip valgrind-memcheck "valgrind is not installed (package valgrind)"
fi

echo
[ -z "$SKIPPED_NAMES" ] || echo "skipped suites:$SKIPPED_NAMES"
[ -z "$FAILED_NAMES" ] || echo "failed:$FAILED_NAMES"
if [ "$SKIPPED" -gt 0 ]; then
    echo "$PASSED passed, $FAILED failed, $SKIPPED skipped"
else
    echo "$PASSED passed, $FAILED failed"
fi
[ "$FAILED" = 0 ]
