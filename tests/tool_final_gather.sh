# tool_final_gather.sh - the traced first bounce of rad render (sourced by tool_tests.sh: uses
# $RAD, $TMP, ok, fail and close). (1) --final-gather on the engine tier's path (the default
# classic of the Cornell box) looks the solution up at its hits: the image keeps the light of
# the later bounces. (2) vp and aavp trace the first bounce by default: a voxel's patch averages
# every sample in it (on a stack of shelves the exposed top, the shelves under it and the wall
# behind them), so the points a camera sees got that average: 8% over the trace here.
fg_box() { # x0 y0 z0 x1 y1 z1: a box with outward faces, appended to $FG_OBJ
    local b
    b=$(grep -c '^v ' "$FG_OBJ")
    awk -v x0="$1" -v y0="$2" -v z0="$3" -v x1="$4" -v y1="$5" -v z1="$6" -v b="$b" 'BEGIN {
        for (i = 0; i < 8; ++i) printf "v %g %g %g\n", (i % 2) ? x1 : x0, (int(i / 2) % 2) ? y1 : y0, (i >= 4) ? z1 : z0
        printf "f %d %d %d %d\n", b + 1, b + 5, b + 7, b + 3    # -x
        printf "f %d %d %d %d\n", b + 2, b + 4, b + 8, b + 6    # +x
        printf "f %d %d %d %d\n", b + 1, b + 2, b + 6, b + 5    # -y
        printf "f %d %d %d %d\n", b + 3, b + 7, b + 8, b + 4    # +y
        printf "f %d %d %d %d\n", b + 1, b + 3, b + 4, b + 2    # -z
        printf "f %d %d %d %d\n", b + 5, b + 6, b + 8, b + 7    # +z
    }' >> "$FG_OBJ"
}
# (1)
if "$RAD" render cornell --patches 100 --size 16x16 --aa 4 -o "$TMP/fg_c0.pfm" > /dev/null 2>&1 &&
    "$RAD" render cornell --patches 100 --size 16x16 --aa 4 --final-gather 64 -o "$TMP/fg_c1.pfm" > /dev/null 2> "$TMP/fg_err.txt"; then
    r=$("$RAD" compare "$TMP/fg_c1.pfm" "$TMP/fg_c0.pfm" 2> /dev/null | sed -n 's/.*A \/ B = //p')
    close "$r" 1 0.03 && grep -q "timing: method=classic" "$TMP/fg_err.txt" &&
        ok "render --final-gather on the default classic path keeps the later bounces ($r of the image without)" ||
        fail "render --final-gather on the default classic path keeps the later bounces" "$r of the image without"
else
    fail "render --final-gather on the default classic path" "$(tail -c 300 "$TMP/fg_err.txt")"
fi
# (2) an open-roofed room 6 x 4 x 4 (floor and walls facing in) under a sun, five thin shelves
# 0.2 apart on its -x wall, seen from above
FG_OBJ="$TMP/fg_shelf.obj"
cat > "$FG_OBJ" <<'OBJ'
v 0 0 0
v 6 0 0
v 6 4 0
v 0 4 0
v 0 0 4
v 6 0 4
v 6 4 4
v 0 4 4
f 1 5 6 2
f 1 4 8 5
f 2 6 7 3
f 1 2 3 4
f 5 8 7 6
OBJ
for k in 0 1 2 3 4; do
    y=$(awk -v k=$k 'BEGIN { print 1.5 + 0.2 * k }')
    fg_box 0 "$y" 0 1.2 "$(awk -v y="$y" 'BEGIN { print y + 0.05 }')" 4
done
FG_VIEW="--camera 5,3.5,2:0.4,2,2:0,1,0 --fov 60 --size 32x24 --sun 0.3,-1,0.2:3"
if "$RAD" trace "$FG_OBJ" $FG_VIEW --spp 512 -o "$TMP/fg_ref.pfm" > /dev/null 2>&1 &&
    "$RAD" render "$FG_OBJ" $FG_VIEW --method aavp --vp-resolution 8 -o "$TMP/fg_a.pfm" > /dev/null 2> "$TMP/fg_err.txt" &&
    "$RAD" render "$FG_OBJ" $FG_VIEW --method aavp --vp-resolution 8 --final-gather 0 -o "$TMP/fg_a0.pfm" > /dev/null 2>&1; then
    r=$("$RAD" compare "$TMP/fg_a.pfm" "$TMP/fg_ref.pfm" 2> /dev/null | sed -n 's/.*A \/ B = //p')
    r0=$("$RAD" compare "$TMP/fg_a0.pfm" "$TMP/fg_ref.pfm" 2> /dev/null | sed -n 's/.*A \/ B = //p')
    close "$r" 1 0.05 && ! close "$r0" 1 0.05 && grep -q -- "--final-gather 16 (the virtual patches' default" "$TMP/fg_err.txt" &&
        ok "render --method aavp traces the first bounce by default: shelves $r of the trace (without: $r0)" ||
        fail "render --method aavp traces the first bounce by default" "shelves $r of the trace (without: $r0)"
else
    fail "render --method aavp on a stack of shelves" "$(tail -c 300 "$TMP/fg_err.txt")"
fi
