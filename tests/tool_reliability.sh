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
rel_refused "lightmap --point with intensity 1e25" "$RAD" lightmap cornell --patches 20 --size 32 -o "$REL/q.pfm" --point 0,1,0:1e25
# bounded counts and a positive exposure
rel_refused "render --aa 4294967295" "$RAD" render cornell --patches 20 --size 8x8 -o "$REL/q.png" --aa 4294967295
rel_refused "render --pixel-light-samples 100000000" "$RAD" render cornell --patches 20 --size 8x8 -o "$REL/q.png" --pixel-light-samples 100000000
rel_refused "bake --light-samples 100000000" "$RAD" bake cornell --patches 20 -o "$REL/q.radb" --light-samples 100000000
rel_refused "bake --samples 100000" "$RAD" bake cornell --patches 20 -o "$REL/q.radb" --samples 100000
rel_refused "lightmap --exposure 0" "$RAD" lightmap cornell --patches 20 --size 32 -o "$REL/q.png" --exposure 0
rel_refused "lightmap --exposure -1" "$RAD" lightmap cornell --patches 20 --size 32 -o "$REL/q.png" --exposure -1
rel_refused "compare --diff-scale inf" "$RAD" compare "$REL/sig/a.pfm" "$REL/sig/a.pfm" --diff "$REL/d.png" --diff-scale inf
"$RAD" render --help 2>&1 | grep -q -- "--aa N.*1 to 65536" && ok "render --help states the --aa limit" || fail "render --help states the --aa limit"

# ---- rad info refuses what the loaders refuse ------------------------------------------------
# rel_edit IN OUT INDEX WORD TYPE VALUE: word WORD (4 bytes) of section INDEX (its row in
# rad info's table) set to VALUE (f32 or u32), every CRC-32 recomputed (each section's bytes,
# the table of 64-byte entries at 64, the header's first 60 bytes), so only the loaders'
# checks of the values themselves can find it
rel_edit() {
    python3 - "$@" <<'PY'
import struct, sys, zlib
src, dst, sec, word, typ, val = sys.argv[1:7]
b = bytearray(open(src, 'rb').read())
n = struct.unpack_from('<I', b, 8)[0]
e = 64 + 64 * int(sec)
off = struct.unpack_from('<Q', b, e + 16)[0]
struct.pack_into('<f' if typ == 'f32' else '<I', b, off + 4 * int(word), float(val) if typ == 'f32' else int(val))
c = lambda x: zlib.crc32(bytes(x)) & 0xffffffff
for i in range(n):
    e = 64 + 64 * i
    o, nb = struct.unpack_from('<QQ', b, e + 16)
    struct.pack_into('<I', b, e + 32, c(b[o:o + nb]))
struct.pack_into('<I', b, 36, c(b[64:64 + 64 * n]))
struct.pack_into('<I', b, 60, c(b[0:60]))
open(dst, 'wb').write(b)
PY
}
# rel_section FILE TYPE [NAME]: the row of the first section of that type (and name)
rel_section() { "$RAD" info "$1" 2> /dev/null | awk -v t="$2" -v n="${3:-}" '$2 == t && (n == "" || $3 == n) { print $1; exit }'; }
# rel_damaged LABEL FILE SECTION-TYPE SECTION-NAME WORD TYPE VALUE RENDER-ARGS...: rad info and rad render both refuse
rel_damaged() {
    label=$1 src=$2 st=$3 sn=$4 wd=$5 ty=$6 va=$7
    shift 7
    idx=$(rel_section "$src" "$st" "$sn")
    if [ -z "$idx" ] || ! rel_edit "$src" "$REL/bad.radb" "$idx" "$wd" "$ty" "$va" 2> /dev/null; then
        fail "info refuses $label" "no section $st $sn in $src"
        return
    fi
    "$RAD" info "$REL/bad.radb" > "$REL/info.txt" 2> "$REL/err.txt"
    rc=$?
    "$RAD" render cornell --patches 40 --size 8x8 -o "$REL/bad.pfm" --bake "$REL/bad.radb" "$@" > /dev/null 2>&1
    rr=$?
    [ $rc -eq 1 ] && [ $rr -ne 0 ] && ! grep -q "all OK" "$REL/info.txt" && [ -s "$REL/err.txt" ] &&
        ok "info refuses $label, as render does" ||
        fail "info refuses $label, as render does" "info exit $rc, render exit $rr: $(head -c 300 "$REL/err.txt")"
}
"$RAD" bake cornell --method aavp --vp-resolution 2 --face-points 4 -o "$REL/aavp.radb" > /dev/null 2>&1
"$RAD" bake cornell --patches 40 --method temporal -o "$REL/tp.radb" > /dev/null 2>&1
"$RAD" bake cornell --patches 40 --method stochastic -o "$REL/st.radb" > /dev/null 2>&1
for f in aavp tp st; do
    "$RAD" info "$REL/$f.radb" > "$REL/info.txt" 2>&1 && grep -q "all OK" "$REL/info.txt" && ok "info passes the intact $f bake" ||
        fail "info passes the intact $f bake" "$(head -c 300 "$REL/info.txt")"
done
rel_damaged "a NaN virtual-patch form factor" "$REL/aavp.radb" FF_VALUES vp 5 f32 nan --method aavp
rel_damaged "a virtual-patch form-factor column out of range" "$REL/aavp.radb" FF_COLUMNS vp 3 u32 100000 --method aavp
rel_damaged "a virtual patch of albedo 1.5" "$REL/aavp.radb" VP_ALBEDO vp 0 f32 1.5 --method aavp
rel_damaged "a NaN row sum (stochastic)" "$REL/st.radb" "USER(row" "" 3 f32 nan --method stochastic
rel_damaged "a negative L (stochastic)" "$REL/st.radb" VECTOR L 0 f32 -1 --method stochastic
rel_damaged "a temporal bake with k = 0" "$REL/tp.radb" "USER(rad" "method)" 9 u32 0 --method temporal
rel_damaged "a temporal bake with mode 7" "$REL/tp.radb" "USER(rad" "method)" 8 u32 7 --method temporal
# a damaged virtual-patch bake is called damaged; an intact one given to another method is
# called what it is
idx=$(rel_section "$REL/aavp.radb" FF_VALUES vp)
rel_edit "$REL/aavp.radb" "$REL/bad.radb" "$idx" 5 f32 nan 2> /dev/null
"$RAD" render cornell --method aavp --bake "$REL/bad.radb" -o "$REL/q.pfm" --size 8x8 > /dev/null 2> "$REL/err.txt"
[ $? -eq 1 ] && grep -q "damaged virtual patches" "$REL/err.txt" && ! grep -q "holds no virtual" "$REL/err.txt" &&
    ok "render calls a damaged virtual-patch bake damaged" ||
    fail "render calls a damaged virtual-patch bake damaged" "$(tail -c 300 "$REL/err.txt")"
"$RAD" render cornell --method temporal --bake "$REL/aavp.radb" -o "$REL/q.pfm" --size 8x8 > /dev/null 2> "$REL/err.txt"
[ $? -eq 1 ] && tail -n 1 "$REL/err.txt" | grep -q "holds virtual patches.*--method aavp or vp" &&
    ok "render names an intact virtual-patch bake given to --method temporal" ||
    fail "render names an intact virtual-patch bake given to --method temporal" "$(tail -c 300 "$REL/err.txt")"
# a file that cannot be read: the system's reason, not "truncated"
if [ -r /proc/self/mem ]; then
    "$RAD" info /proc/self/mem > /dev/null 2> "$REL/err.txt"
    [ $? -eq 1 ] && grep -q "cannot read bake '/proc/self/mem': Input/output error" "$REL/err.txt" &&
        ok "info on an unreadable file gives the system's error" ||
        fail "info on an unreadable file gives the system's error" "$(head -c 300 "$REL/err.txt")"
fi
mkdir -p "$REL/adir"
"$RAD" info "$REL/adir" > /dev/null 2> "$REL/err.txt"
[ $? -eq 1 ] && grep -q "Is a directory" "$REL/err.txt" && ok "info on a folder says it is one" ||
    fail "info on a folder says it is one" "$(head -c 300 "$REL/err.txt")"

# ---- no output is an input of the same command, and no two outputs are one file ---------------
# an OBJ whose floor takes its albedo from tex.png (map_Kd), lit by an emissive quad
mkdir -p "$REL/tex"
python3 - "$REL/tex" <<'PY'
import struct, sys, zlib
d = sys.argv[1]
def chunk(t, b): return struct.pack('>I', len(b)) + t + b + struct.pack('>I', zlib.crc32(t + b) & 0xffffffff)
raw = b''.join(b'\x00' + bytes((200, 30, 30)) * 8 for _ in range(8))
open(d + '/tex.png', 'wb').write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', 8, 8, 8, 2, 0, 0, 0)) +
                                 chunk(b'IDAT', zlib.compress(raw)) + chunk(b'IEND', b''))
open(d + '/scene.mtl', 'w').write('newmtl floor\nKd 1 1 1\nmap_Kd tex.png\nnewmtl lamp\nKd 0 0 0\nKe 10 10 10\n')
open(d + '/scene.obj', 'w').write('mtllib scene.mtl\no floor\nusemtl floor\nv 0 0 0\nv 0 0 1\nv 1 0 1\nv 1 0 0\n'
                                  'vt 0 0\nvt 0 1\nvt 1 1\nvt 1 0\nf 1/1 2/2 3/3 4/4\no lamp\nusemtl lamp\n'
                                  'v 0.3 1 0.3\nv 0.7 1 0.3\nv 0.7 1 0.7\nv 0.3 1 0.7\nf 5 6 7 8\n')
PY
m0=$(cksum < "$REL/tex/tex.png")
for c in "render --patches 20 --size 8x8" "trace --spp 1 --size 8x8" "lightmap --patches 20 --size 16"; do
    "$RAD" ${c%% *} "$REL/tex/scene.obj" ${c#* } -o "$REL/tex/tex.png" > /dev/null 2> "$REL/err.txt"
    rc=$?
    [ $rc -eq 1 ] && [ "$(cksum < "$REL/tex/tex.png")" = "$m0" ] && grep -q "tex.png.*read from" "$REL/err.txt" &&
        ok "${c%% *} -o the scene's own texture refused" ||
        fail "${c%% *} -o the scene's own texture refused" "exit $rc $(tail -c 300 "$REL/err.txt")"
done
(cd "$REL/tex" && "$RAD" lightmap scene.obj --patches 20 --size 16 -o out.png --render ./tex.png) > /dev/null 2> "$REL/err.txt"
[ $? -eq 1 ] && [ "$(cksum < "$REL/tex/tex.png")" = "$m0" ] && ok "lightmap --render onto the texture (another spelling) refused" ||
    fail "lightmap --render onto the texture (another spelling) refused" "$(tail -c 300 "$REL/err.txt")"
"$RAD" export "$REL/tex/scene.obj" -o "$REL/tex/scene.obj" > /dev/null 2>&1
[ $? -eq 1 ] && ok "export onto its own scene refused" || fail "export onto its own scene refused"
# two outputs of one command naming one file (existing or not, spelled differently)
rm -f "$REL/lm.pfm"
"$RAD" lightmap cornell --patches 20 --size 32 -o "$REL/lm.pfm" --render "$REL/./lm.pfm" > /dev/null 2> "$REL/err.txt"
[ $? -eq 1 ] && grep -q "same file" "$REL/err.txt" && [ ! -e "$REL/lm.pfm" ] && ok "lightmap -o X --render X refused" ||
    fail "lightmap -o X --render X refused" "$(tail -c 300 "$REL/err.txt")"
"$RAD" compare "$REL/sig/a.pfm" "$REL/sig/a.pfm" --diff "$REL/d.png" --png "$REL/d.png" > /dev/null 2> "$REL/err.txt"
[ $? -eq 1 ] && grep -q "same file" "$REL/err.txt" && ok "compare --diff X --png X refused" ||
    fail "compare --diff X --png X refused" "$(tail -c 300 "$REL/err.txt")"
# the SH layers' own names are checked before the bake
mkdir -p "$REL/shf"
mkdir "$REL/shf/lm.L11.pfm"
"$RAD" lightmap cornell --sh --patches 20 --size 32 -o "$REL/shf/lm.pfm" > "$REL/out.txt" 2> "$REL/err.txt"
[ $? -eq 1 ] && grep -q "lm.L11.pfm' is a directory" "$REL/err.txt" && ! grep -q "direct light" "$REL/err.txt" &&
    ok "lightmap --sh checks its layers' names before the bake" ||
    fail "lightmap --sh checks its layers' names before the bake" "$(tail -c 300 "$REL/err.txt")"

# ---- inputs the tool reads ---------------------------------------------------------------------
# a glTF quad whose second uv set is one point: no texel is covered, so no all-zero lightmap
python3 - "$REL/deg.gltf" <<'PY'
import base64, json, struct, sys
pos = struct.pack('<12f', 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0)
uv0 = struct.pack('<8f', 0, 0, 1, 0, 1, 1, 0, 1)
uv1 = struct.pack('<8f', *([0.5] * 8))
idx = struct.pack('<6I', 0, 1, 2, 0, 2, 3)
buf = pos + uv0 + uv1 + idx
views, off = [], 0
for part in (pos, uv0, uv1, idx):
    views.append({'buffer': 0, 'byteOffset': off, 'byteLength': len(part)})
    off += len(part)
doc = {'asset': {'version': '2.0'}, 'scene': 0, 'scenes': [{'nodes': [0]}], 'nodes': [{'mesh': 0}],
       'meshes': [{'primitives': [{'attributes': {'POSITION': 0, 'TEXCOORD_0': 1, 'TEXCOORD_1': 2}, 'indices': 3}]}],
       'buffers': [{'byteLength': len(buf), 'uri': 'data:application/octet-stream;base64,' + base64.b64encode(buf).decode()}],
       'bufferViews': views,
       'accessors': [{'bufferView': 0, 'componentType': 5126, 'count': 4, 'type': 'VEC3', 'min': [0, 0, 0], 'max': [1, 1, 0]},
                     {'bufferView': 1, 'componentType': 5126, 'count': 4, 'type': 'VEC2'},
                     {'bufferView': 2, 'componentType': 5126, 'count': 4, 'type': 'VEC2'},
                     {'bufferView': 3, 'componentType': 5125, 'count': 6, 'type': 'SCALAR'}]}
open(sys.argv[1], 'w').write(json.dumps(doc))
PY
"$RAD" lightmap "$REL/deg.gltf" -o "$REL/deg.pfm" --size 32 --patches 2 --sun 0,0,-1:1 > /dev/null 2> "$REL/err.txt"
[ $? -eq 1 ] && grep -q "covers no texel" "$REL/err.txt" && [ ! -e "$REL/deg.pfm" ] &&
    ok "lightmap refuses a second uv set that covers no texel" ||
    fail "lightmap refuses a second uv set that covers no texel" "$(tail -c 300 "$REL/err.txt")"
# a PFM header whose width wraps to 16 as a 32-bit int is refused, not read as 16 wide
python3 -c "import array;open('$REL/w.pfm','wb').write(b'PF\n4294967312 16\n-1.0\n'+array.array('f',[0.5]*768).tobytes())"
python3 -c "import array;open('$REL/s.pfm','wb').write(b'PF\n16 16\n-1.0\n'+array.array('f',[0.5]*768).tobytes())"
"$RAD" compare "$REL/w.pfm" "$REL/s.pfm" > /dev/null 2> "$REL/err.txt"
[ $? -eq 1 ] && grep -q "bad PFM header" "$REL/err.txt" && ok "a PFM width of 4294967312 is refused" ||
    fail "a PFM width of 4294967312 is refused" "$(tail -c 300 "$REL/err.txt")"
