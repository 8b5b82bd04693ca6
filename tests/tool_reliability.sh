# tool_reliability.sh - the rad tool's reliability checks: every output written as a
# temporary renamed into place (alone or as a set), nothing left behind by a signal, outputs
# that are inputs or each other refused, option values checked before the work, and rad info
# refusing what the loaders refuse. Sourced from tests/tool_tests.sh (RAD, TMP, ok, fail);
# run alone with:  bash tests/tool_reliability.sh build/rad
if ! command -v ok > /dev/null 2>&1; then
    RAD=${1:-build/rad}
    case "$RAD" in /*) ;; *) RAD="$PWD/$RAD" ;; esac
    TMP=$(mktemp -d "${TMPDIR:-/tmp}/rad_rel_tests.XXXXXX")
    trap 'rm -rf "$TMP"' EXIT
    failures=0
    passes=0
    ok() { echo "ok $1"; passes=$((passes + 1)); }
    fail() { echo "FAIL $1${2:+: $2}"; failures=$((failures + 1)); }
    REL_ALONE=1
fi
REL="$TMP/rel"
mkdir -p "$REL"
# rel_clean: a folder with no hidden file (a temporary) left in it
rel_clean() { [ -z "$(find "$1" -mindepth 1 -maxdepth 1 -name '.*' -print -quit)" ]; }

# ---- outputs as sets ---------------------------------------------------------------------
# rad export: the .obj and .mtl replace the old pair together; a file-size limit (EFBIG,
# as a full disk gives ENOSPC) on the larger .obj leaves both old files and names the .obj
mkdir -p "$REL/exp"
"$RAD" export cornell -o "$REL/exp/s.obj" > /dev/null 2>&1
printf 'o q\nv 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n' > "$REL/exp/tri.obj"
"$RAD" export "$REL/exp/tri.obj" -o "$REL/exp/s.obj" > /dev/null 2>&1
m0=$(cat "$REL/exp/s.obj" "$REL/exp/s.mtl" | cksum)
(ulimit -f 2; trap '' XFSZ; "$RAD" export cornell -o "$REL/exp/s.obj") > /dev/null 2> "$REL/err.txt"
rc=$?
[ $rc -eq 1 ] && [ "$(cat "$REL/exp/s.obj" "$REL/exp/s.mtl" | cksum)" = "$m0" ] && rel_clean "$REL/exp" &&
    ok "export: a failed .obj leaves the old .obj and .mtl pair" ||
    fail "export: a failed .obj leaves the old .obj and .mtl pair" "exit $rc $(head -c 300 "$REL/err.txt")"
grep -q "s\.obj'.*File too large" "$REL/err.txt" && ! grep -q "s\.mtl'" "$REL/err.txt" &&
    ok "export: the error names the file that hit the limit" ||
    fail "export: the error names the file that hit the limit" "$(head -c 300 "$REL/err.txt")"

# rad lightmap --sh: the four layers replace the old set together; a layer that cannot be
# written leaves every old layer
mkdir -p "$REL/sh"
"$RAD" lightmap cornell -o "$REL/sh/lm.pfm" --sh --size 32 --patches 40 > /dev/null 2>&1
m0=$(cat "$REL/sh/lm.L00.pfm" "$REL/sh/lm.L1m1.pfm" "$REL/sh/lm.L11.pfm" 2> /dev/null | cksum)
rm -f "$REL/sh/lm.L10.pfm"
mkdir "$REL/sh/lm.L10.pfm"
"$RAD" lightmap cornell -o "$REL/sh/lm.pfm" --sh --size 32 --patches 40 --sun 0,-0.3,1:5 > /dev/null 2> "$REL/err.txt"
rc=$?
[ $rc -ne 0 ] && [ "$(cat "$REL/sh/lm.L00.pfm" "$REL/sh/lm.L1m1.pfm" "$REL/sh/lm.L11.pfm" 2> /dev/null | cksum)" = "$m0" ] &&
    rel_clean "$REL/sh" && grep -q "lm.L10.pfm" "$REL/err.txt" &&
    ok "lightmap --sh: a layer that cannot be written leaves the old layers" ||
    fail "lightmap --sh: a layer that cannot be written leaves the old layers" "exit $rc $(head -c 300 "$REL/err.txt")"

# ---- temporaries ---------------------------------------------------------------------------
# SIGXFSZ in the middle of a write (a 1 KiB file-size limit): rad dies of the signal as
# before, and its temporary is gone
mkdir -p "$REL/sig"
rc=$(cd "$REL/sig" && ulimit -f 2 && sh -c '"$1" render cornell -o x.pfm --size 128x128 --patches 30 > /dev/null 2>&1; echo $?' sh "$RAD" 2> /dev/null)
[ $rc -gt 128 ] && rel_clean "$REL/sig" && [ ! -e "$REL/sig/x.pfm" ] &&
    ok "a SIGXFSZ during a write leaves no temporary (exit $rc)" ||
    fail "a SIGXFSZ during a write leaves no temporary" "exit $rc: $(ls -A "$REL/sig")"
# SIGTERM while rad compare encodes a large PNG: no temporary left (the window is found by
# polling; when it is missed the check says so and passes on the finished file)
python3 -c "
import array; w=h=1500; hd=b'PF\n%d %d\n-1.0\n'%(w,h); a=array.array('f',[0.5]*(w*h*3))
open('$REL/sig/a.pfm','wb').write(hd+a.tobytes())" 2> /dev/null
if [ -s "$REL/sig/a.pfm" ]; then
    "$RAD" compare "$REL/sig/a.pfm" "$REL/sig/a.pfm" --png "$REL/sig/o.png" > /dev/null 2>&1 &
    pid=$!
    seen=0
    for _ in $(seq 1 2000); do
        if [ -n "$(find "$REL/sig" -maxdepth 1 -name '.radtmp-*' -print -quit)" ]; then
            kill -TERM $pid 2> /dev/null && seen=1
            break
        fi
        kill -0 $pid 2> /dev/null || break
    done
    wait $pid
    rc=$?
    if [ $seen -eq 1 ] && [ $rc -eq 143 ]; then
        rel_clean "$REL/sig" && ok "a SIGTERM during a write leaves no temporary" ||
            fail "a SIGTERM during a write leaves no temporary" "$(ls -A "$REL/sig")"
    else
        rel_clean "$REL/sig" && ok "a SIGTERM during a write leaves no temporary (the write finished first)" ||
            fail "a SIGTERM during a write leaves no temporary" "exit $rc $(ls -A "$REL/sig")"
    fi
fi
# a valid name of 250 characters: the temporary's name does not grow with it
long=$(printf 'a%.0s' $(seq 1 246)).png
(cd "$REL/sig" && "$RAD" render cornell -o "$long" --size 8x8 --patches 20) > /dev/null 2> "$REL/err.txt" &&
    [ -s "$REL/sig/$long" ] && ok "an output name of 250 characters is written" ||
    fail "an output name of 250 characters is written" "$(head -c 300 "$REL/err.txt")"

# ---- option values checked before the work --------------------------------------------------
# rel_refused NAME ARGS...: exit 2 with a message naming the option (the first -- word of NAME)
rel_refused() {
    name=$1
    shift
    opt=$(printf '%s\n' "$name" | grep -o -- '--[a-z-]*' | head -n 1)
    timeout 60 "$@" > /dev/null 2> "$REL/err.txt"
    rc=$?
    [ $rc -eq 2 ] && grep -q -- "$opt" "$REL/err.txt" && ok "$name refused (exit 2, names $opt)" ||
        fail "$name refused" "exit $rc $(head -c 300 "$REL/err.txt")"
}
# a direction whose squared length overflows a float would be normalised to zero: no light
rel_refused "render --sun 0,-0.3e20,1e20:5" "$RAD" render cornell --patches 20 --size 8x8 -o "$REL/q.pfm" --sun 0,-0.3e20,1e20:5
rel_refused "render --sun 0,0,1e-30:5 (too short)" "$RAD" render cornell --patches 20 --size 8x8 -o "$REL/q.pfm" --sun 0,0,1e-30:5
rel_refused "bake --spot with DIR 0,-1e20,0" "$RAD" bake cornell --patches 20 -o "$REL/q.radb" --spot 0,1,0:0,-1e20,0:30:5
rel_refused "trace --sun 1e20,1e20,0:1" "$RAD" trace cornell --spp 1 --size 8x8 -o "$REL/q.pfm" --sun 1e20,1e20,0:1
rel_refused "render --camera looking 1e20 away" "$RAD" render cornell --patches 20 --size 8x8 -o "$REL/q.pfm" --camera 0.278,0.274,-1.1:0.278,0.274,1e20:0,1,0
rel_refused "trace --camera with up along the view" "$RAD" trace cornell --spp 1 --size 8x8 -o "$REL/q.pfm" --camera 0,0,0:0,0,1:0,0,2
rel_refused "render --area whose U x V overflows" "$RAD" render cornell --patches 20 --size 8x8 -o "$REL/q.pfm" --area 0,1,0:3e19,0,0:0,0,3e19:1
rel_refused "render --light-path beyond 1e30" "$RAD" render cornell --method temporal --patches 20 --size 8x8 -o "$REL/q.pfm" --light-path line:0,0,0:1e31,0,0
# a light that overflows the transport is refused up front, not at the save after the bake
rel_refused "bake --sky 1e30" "$RAD" bake cornell --patches 20 -o "$REL/q.radb" --sky 1e30
rel_refused "lightmap --point with intensity 1e25" "$RAD" lightmap cornell --patches 20 --size 16 -o "$REL/q.pfm" --point 0,1,0:1e25
# bounded counts and a positive exposure
rel_refused "render --aa 4294967295" "$RAD" render cornell --patches 20 --size 8x8 -o "$REL/q.png" --aa 4294967295
rel_refused "render --pixel-light-samples 100000000" "$RAD" render cornell --patches 20 --size 8x8 -o "$REL/q.png" --pixel-light-samples 100000000
rel_refused "bake --light-samples 100000000" "$RAD" bake cornell --patches 20 -o "$REL/q.radb" --light-samples 100000000
rel_refused "bake --samples 100000" "$RAD" bake cornell --patches 20 -o "$REL/q.radb" --samples 100000
rel_refused "lightmap --exposure 0" "$RAD" lightmap cornell --patches 20 --size 16 -o "$REL/q.png" --exposure 0
rel_refused "lightmap --exposure -1" "$RAD" lightmap cornell --patches 20 --size 16 -o "$REL/q.png" --exposure -1
rel_refused "compare --diff-scale inf" "$RAD" compare "$REL/sig/a.pfm" "$REL/sig/a.pfm" --diff "$REL/d.png" --diff-scale inf
"$RAD" render --help 2>&1 | grep -q -- "--aa N.*1 to 65536" && ok "render --help states the --aa limit" || fail "render --help states the --aa limit"
