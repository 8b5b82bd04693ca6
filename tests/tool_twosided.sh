# tool_twosided.sh - two-sided surfaces in the rad tool (sourced by tool_tests.sh, which
# defines RAD, TMP, ok, fail, close and pfm_mean).

# A unit square sheet (albedo 0.6, wound facing +z) at z = 0 between two black unit-square
# emitters: below at z = -0.5 facing up (radiance 2), above at z = 0.5 facing down (0.5). Each
# side of the sheet sees only its emitter, so at the centre its radiance is rho L F with F the
# form factor from a point to a parallel square centred 0.5 below it (four corner rectangles
# X = Y = 1: F = 4 / (2 pi) * 2 X / sqrt(1 + X^2) * atan(X / sqrt(1 + X^2))). A 10-degree view of
# the centre from each side: rad trace and rad render (classic) within 1% of it with
# --two-sided all; one-sided (the default for OBJ) the back is black.
cat > "$TMP/sheet.mtl" <<'EOF2'
newmtl sheet
Kd 0.6 0.6 0.6
newmtl below
Kd 0 0 0
Ke 2 2 2
newmtl above
Kd 0 0 0
Ke 0.5 0.5 0.5
EOF2
cat > "$TMP/sheet.obj" <<'EOF2'
mtllib sheet.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 -0.5
v 1 0 -0.5
v 1 1 -0.5
v 0 1 -0.5
v 0 0 0.5
v 1 0 0.5
v 1 1 0.5
v 0 1 0.5
o sheet
usemtl sheet
f 1 2 3 4
o below
usemtl below
f 5 6 7 8
o above
usemtl above
f 9 12 11 10
EOF2
ts_F=$(awk 'BEGIN { x = 1; s = sqrt(1 + x * x); printf "%.9g\n", 4 / (2 * 3.14159265358979) * 2 * x / s * atan2(x / s, 1) }')
ts_view_below="--camera 0.5,0.5,-0.25:0.5,0.5,0:0,1,0 --fov 10 --size 8x8"
ts_view_above="--camera 0.5,0.5,0.25:0.5,0.5,0:0,1,0 --fov 10 --size 8x8"
for ts_side in below:2 above:0.5; do
    ts_name=${ts_side%%:*}
    ts_expect=$(awk -v f="$ts_F" -v l="${ts_side##*:}" 'BEGIN { printf "%.9g\n", 0.6 * l * f }')
    eval "ts_view=\$ts_view_$ts_name"
    # shellcheck disable=SC2086
    if "$RAD" trace "$TMP/sheet.obj" --two-sided all $ts_view --spp 1024 -o "$TMP/ts-t.pfm" > /dev/null 2> "$TMP/err.txt" &&
        "$RAD" render "$TMP/sheet.obj" --two-sided all $ts_view --patches 200 -o "$TMP/ts-r.pfm" > /dev/null 2>> "$TMP/err.txt"; then
        ts_t=$(pfm_mean "$TMP/ts-t.pfm")
        ts_r=$(pfm_mean "$TMP/ts-r.pfm")
        close "$ts_t" "$ts_expect" 0.01 && close "$ts_r" "$ts_expect" 0.01 &&
            ok "two-sided sheet, side seen from $ts_name: trace $ts_t, render $ts_r, closed form $ts_expect" ||
            fail "two-sided sheet, side seen from $ts_name" "trace $ts_t, render $ts_r, closed form $ts_expect"
    else
        fail "two-sided sheet, side seen from $ts_name" "$(head -c 300 "$TMP/err.txt")"
    fi
done
# shellcheck disable=SC2086
"$RAD" trace "$TMP/sheet.obj" $ts_view_below --spp 16 -o "$TMP/ts-1.pfm" > /dev/null 2>&1
ts_b=$(pfm_mean "$TMP/ts-1.pfm")
[ "$ts_b" = "0" ] && ok "one-sided (the OBJ default), the sheet's back is black" ||
    fail "one-sided (the OBJ default), the sheet's back is black" "mean radiance $ts_b"

# glTF doubleSided sets the flag (the unit square: 2 mesh triangles, 4 scene triangles);
# --two-sided none and all override the file; a bad mode is a usage error.
ts_gltf() { # ts_gltf DOUBLESIDED > FILE
    printf '{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0, "name": "n"}],
 "materials": [{"name": "leaf", "doubleSided": %s, "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}}],
 "meshes": [{"name": "m", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
 "buffers": [{"byteLength": 72, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAACAPwAAgD8AAAAAAAAAAAAAgD8AAAAAAAAAAAEAAAACAAAAAAAAAAIAAAADAAAA"}],
 "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 24}],
 "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
  {"bufferView": 1, "componentType": 5125, "count": 6, "type": "SCALAR"}]}\n' "$1"
}
ts_gltf true > "$TMP/ds.gltf"
ts_gltf false > "$TMP/ss.gltf"
ts_tris() { "$RAD" formfactors "$@" --patches 4 2>&1 > /dev/null | sed -n 's/.*: \([0-9]*\) triangles.*/\1/p' | head -n 1; }
ts_a=$(ts_tris "$TMP/ds.gltf"); ts_b=$(ts_tris "$TMP/ss.gltf")
ts_c=$(ts_tris "$TMP/ds.gltf" --two-sided none); ts_d=$(ts_tris --two-sided "$TMP/ss.gltf")
[ "$ts_a" = 4 ] && [ "$ts_b" = 2 ] && [ "$ts_c" = 2 ] && [ "$ts_d" = 4 ] &&
    ok "glTF doubleSided is two-sided; --two-sided none / all override the file" ||
    fail "glTF doubleSided is two-sided; --two-sided none / all override the file" "scene triangles $ts_a $ts_b $ts_c $ts_d (want 4 2 2 4)"
"$RAD" formfactors "$TMP/ds.gltf" --two-sided sometimes > /dev/null 2> "$TMP/err.txt"
ts_rc=$?
[ $ts_rc -eq 2 ] && grep -q "two-sided wants auto, all or none" "$TMP/err.txt" &&
    ok "--two-sided with an unknown mode is a usage error" || fail "--two-sided with an unknown mode is a usage error" "exit $ts_rc"
"$RAD" help | grep -q -- "--two-sided \[auto|all|none\]" && ok "rad help documents --two-sided" ||
    fail "rad help documents --two-sided"

# One-sided triangles wound against their own normals draw a warning naming --two-sided.
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 -1\nf 1//1 2//1 3//1\nf 1//1 3//1 4//1\n' > "$TMP/mixed.obj"
"$RAD" formfactors "$TMP/mixed.obj" --patches 4 > /dev/null 2> "$TMP/err.txt"
grep -q "wound against their normals.*--two-sided all" "$TMP/err.txt" && ok "mixed windings draw a warning" ||
    fail "mixed windings draw a warning" "$(head -c 300 "$TMP/err.txt")"
"$RAD" formfactors "$TMP/mixed.obj" --two-sided all --patches 4 > /dev/null 2> "$TMP/err.txt"
! grep -q "wound against" "$TMP/err.txt" && ok "no winding warning for two-sided surfaces" ||
    fail "no winding warning for two-sided surfaces" "$(head -c 300 "$TMP/err.txt")"
