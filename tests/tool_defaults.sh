# tool_defaults.sh - rad render with no --method (sourced by tool_tests.sh: uses $RAD, $TMP,
# ok and fail): on a generated 11 000-triangle room, too large for a dense matrix within the
# default budget, the library's plan (rad_baker_plan) chooses AAVP and its resolution, says so
# before the build, and the render runs; the Cornell box stays classic.
bash "$(dirname "${BASH_SOURCE[0]}")/data/open_room.sh" "$TMP/td_room" 20
if "$RAD" render "$TMP/td_room.obj" --camera 0.3,1.6,3.7:2.6,0.6,1.2:0,1,0 --fov 70 --size 16x12 --aa 1 \
        --pixel-light-samples 2 -o "$TMP/td_room.pfm" > /dev/null 2> "$TMP/td_err.txt"; then
    plan_line=$(grep -n "rad_baker_plan: virtual patches: classic would need [0-9]* patches" "$TMP/td_err.txt" | head -n 1 | cut -d: -f1)
    build_line=$(grep -n "aavp virtual patches at resolution" "$TMP/td_err.txt" | head -n 1 | cut -d: -f1)
    res=$(sed -n 's/.*no --method given: chose aavp at --vp-resolution \([0-9]*\).*/\1/p' "$TMP/td_err.txt")
    if [ -n "$plan_line" ] && [ -n "$build_line" ] && [ "$plan_line" -lt "$build_line" ] && [ -n "$res" ] &&
        grep -q "mean free path .* asks for resolution" "$TMP/td_err.txt" &&
        grep -q "aavp virtual patches at resolution $res:" "$TMP/td_err.txt" &&
        grep -q "timing: method=aavp patches=" "$TMP/td_err.txt"; then
        ok "render with no --method: an 11 000-triangle room gets AAVP at resolution $res, said before the build"
    else
        fail "render with no --method says and runs its choice on an 11 000-triangle room" "$(head -c 600 "$TMP/td_err.txt")"
    fi
else
    fail "render with no --method on an 11 000-triangle room" "$(tail -c 400 "$TMP/td_err.txt")"
fi
if "$RAD" render cornell --patches 100 --size 8x8 --aa 1 -o "$TMP/td_c.pfm" > /dev/null 2> "$TMP/td_err.txt" &&
    grep -q "no --method given: chose classic" "$TMP/td_err.txt" && grep -q "timing: method=classic" "$TMP/td_err.txt"; then
    ok "render with no --method: the Cornell box stays classic"
else
    fail "render with no --method: the Cornell box stays classic" "$(head -c 400 "$TMP/td_err.txt")"
fi
