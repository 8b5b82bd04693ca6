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
