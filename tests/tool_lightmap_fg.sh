# tool_lightmap_fg.sh - the lightmap's final gather per texel (sourced by tool_tests.sh: uses
# $RAD, $TMP, ok, fail and close). (1) In a room lit through a ceiling opening by an emitter
# larger than the opening (tests/data/open_room.sh), the voxels of the walls and ceiling next
# to the opening average in light the texels under them do not see: the lightmap over aavp
# that reads those averages is 4.5% over the path tracer, one that traces the first bounce
# from each texel (the default with --proxy aavp|vp) within 3%, as the aavp render. (2) rad
# lightmap takes --final-gather, and refuses it where it cannot be honoured.
bash "$(dirname "${BASH_SOURCE[0]}")/data/open_room.sh" "$TMP/lfg_room" 2
LFG_VIEW="--camera 0.3,1.6,3.7:2.6,0.6,1.2:0,1,0 --fov 70 --size 32x24"
LFG_LM="--method lightmap --proxy aavp --lightmap-size 128 --vp-resolution 8"
# shellcheck disable=SC2086
if "$RAD" trace "$TMP/lfg_room.obj" $LFG_VIEW --spp 256 -o "$TMP/lfg_ref.pfm" > /dev/null 2>&1 &&
    "$RAD" render "$TMP/lfg_room.obj" $LFG_VIEW $LFG_LM -o "$TMP/lfg_d.pfm" > /dev/null 2> "$TMP/lfg_err.txt" &&
    "$RAD" render "$TMP/lfg_room.obj" $LFG_VIEW $LFG_LM --final-gather 0 -o "$TMP/lfg_0.pfm" > /dev/null 2>&1; then
    r=$("$RAD" compare "$TMP/lfg_d.pfm" "$TMP/lfg_ref.pfm" 2> /dev/null | sed -n 's/.*A \/ B = //p')
    r0=$("$RAD" compare "$TMP/lfg_0.pfm" "$TMP/lfg_ref.pfm" 2> /dev/null | sed -n 's/.*A \/ B = //p')
    close "$r" 1 0.03 && ! close "$r0" 1 0.04 && grep -q "final gather of the first bounce, 32 rays a texel" "$TMP/lfg_err.txt" &&
        ok "render --method lightmap --proxy aavp traces the first bounce per texel: room under an opening $r of the trace (without: $r0)" ||
        fail "render --method lightmap --proxy aavp traces the first bounce per texel" "room under an opening $r of the trace (without: $r0)"
else
    fail "render --method lightmap on the room under an opening" "$(tail -c 300 "$TMP/lfg_err.txt")"
fi
# (2)
if "$RAD" lightmap "$TMP/lfg_room.obj" --proxy aavp --vp-resolution 8 --size 64 --final-gather 8 -o "$TMP/lfg_a.pfm" > /dev/null 2> "$TMP/lfg_err.txt" &&
    grep -q "final gather of the first bounce, 8 rays a texel$" "$TMP/lfg_err.txt"; then
    ok "lightmap --final-gather 8 reaches the engine tier's bake"
else
    fail "lightmap --final-gather 8 reaches the engine tier's bake" "$(tail -c 300 "$TMP/lfg_err.txt")"
fi
"$RAD" lightmap cornell --patches 40 --size 16 --sh --final-gather 8 -o "$TMP/lfg_sh.pfm" > /dev/null 2> "$TMP/lfg_err.txt"
rc=$?
[ $rc -eq 2 ] && grep -q -- "--final-gather gathers RGB irradiance" "$TMP/lfg_err.txt" &&
    ok "lightmap --sh --final-gather is refused, naming why" ||
    fail "lightmap --sh --final-gather is refused, naming why" "rc $rc: $(tail -c 200 "$TMP/lfg_err.txt")"
"$RAD" lightmap cornell --size 64 --proxy hierarchical --final-gather 8 -o "$TMP/lfg_h.pfm" > /dev/null 2> "$TMP/lfg_err.txt"
rc=$?
[ $rc -eq 1 ] && grep -q -- "--final-gather is for the engine tier's bakes" "$TMP/lfg_err.txt" &&
    ok "lightmap --proxy hierarchical --final-gather is refused, naming why" ||
    fail "lightmap --proxy hierarchical --final-gather is refused, naming why" "rc $rc: $(tail -c 200 "$TMP/lfg_err.txt")"
