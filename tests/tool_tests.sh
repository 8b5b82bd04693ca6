#!/usr/bin/env bash
# tool_tests.sh - checks of the rad command-line tool.
# Run from the repository root:  bash tests/tool_tests.sh build/rad
# Prints "ok NAME" / "FAIL NAME" (and "skip NAME: why") per check; exits 1 if any failed.
set -u
RAD=${1:-build/rad}
case "$RAD" in /*) ;; *) RAD="$PWD/$RAD" ;; esac
DATA=${RAD_DATA_DIR:-../shared/data}
if [ ! -x "$RAD" ]; then
    echo "FAIL tool: '$RAD' is not an executable (build it first)"
    exit 1
fi
TMP=$(mktemp -d "${TMPDIR:-/tmp}/rad_tool_tests.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
failures=0
passes=0
ok() { echo "ok $1"; passes=$((passes + 1)); }
fail() { echo "FAIL $1${2:+: $2}"; failures=$((failures + 1)); }
skip() { echo "skip $1: $2"; }
# within REL relative: close VALUE EXPECTED REL
close() { awk -v v="$1" -v e="$2" -v r="$3" 'BEGIN { d = v - e; if (d < 0) d = -d; exit !(v != "" && d <= r * (e < 0 ? -e : e)) }'; }
# value of "FROM TO VALUE" for a pair
pair() { awk -v a="$2" -v b="$3" '$1 == a && $2 == b { print $3 }' "$1"; }

# ---- the program ----------------------------------------------------------------------
"$RAD" help > "$TMP/help.txt" 2>&1 && grep -q formfactors "$TMP/help.txt" && ok "help exits 0" || fail "help exits 0"
"$RAD" no-such-command > /dev/null 2> "$TMP/err.txt"
rc=$?
[ $rc -eq 2 ] && grep -q "unknown command" "$TMP/err.txt" && ok "unknown command exits 2" || fail "unknown command exits 2" "exit $rc"
"$RAD" render --help > /dev/null 2>&1 && ok "render --help exits 0" || fail "render --help exits 0"
"$RAD" render cornell --bogus-option 1 -o "$TMP/x.pfm" > /dev/null 2>&1
[ $? -eq 2 ] && ok "unknown option exits 2" || fail "unknown option exits 2"
"$RAD" formfactors "$TMP/missing.obj" > /dev/null 2> "$TMP/err.txt"
rc=$?
[ $rc -eq 1 ] && [ -s "$TMP/err.txt" ] && ok "missing scene file exits 1 with a message" || fail "missing scene file exits 1 with a message" "exit $rc"

# ---- form factors on generated scenes (REFERENCE.md §1) --------------------------------
# two parallel opposed unit squares at gap 1, facing each other (C-11)
cat > "$TMP/parallel.obj" <<'EOF'
o a
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
f 1 2 3 4
o b
v 0 0 1
v 0 1 1
v 1 1 1
v 1 0 1
f 5 6 7 8
EOF
if "$RAD" formfactors "$TMP/parallel.obj" > "$TMP/par.txt" 2> "$TMP/err.txt"; then
    v=$(pair "$TMP/par.txt" a b)
    close "$v" 0.19982489569838746 1e-3 && ok "formfactors C-11 parallel squares ($v)" ||
        fail "formfactors C-11 parallel squares" "got '$v', want 0.19982489569838746"
    w=$(pair "$TMP/par.txt" b a)
    close "$w" 0.19982489569838746 1e-3 && ok "formfactors C-11 reverse pair ($w)" || fail "formfactors C-11 reverse pair" "got '$w'"
else
    fail "formfactors C-11 parallel squares" "$(head -c 300 "$TMP/err.txt")"
fi

# perpendicular unit squares sharing an edge, both facing into the quarter space (C-14)
cat > "$TMP/perpendicular.obj" <<'EOF'
o a
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
f 1 2 3 4
o b
v 0 0 0
v 0 1 0
v 0 1 1
v 0 0 1
f 5 6 7 8
EOF
if "$RAD" formfactors "$TMP/perpendicular.obj" > "$TMP/perp.txt" 2> "$TMP/err.txt"; then
    v=$(pair "$TMP/perp.txt" a b)
    close "$v" 0.20004377607540316 1e-3 && ok "formfactors C-14 perpendicular squares ($v)" ||
        fail "formfactors C-14 perpendicular squares" "got '$v', want 0.20004377607540316"
else
    fail "formfactors C-14 perpendicular squares" "$(head -c 300 "$TMP/err.txt")"
fi

# two coaxial 64-gons of circumradius 1 at gap 1 facing each other (C-41 for the disks of the
# polygons' area: r = sqrt(n sin(2 pi / n) / (2 pi)))
awk 'BEGIN {
    n = 64; pi = atan2(0, -1);
    print "o a";
    for (i = 0; i < n; ++i) printf "v %.9f %.9f 0\n", cos(2 * pi * i / n), sin(2 * pi * i / n);
    printf "f"; for (i = 1; i <= n; ++i) printf " %d", i; printf "\n";
    print "o b";
    for (i = 0; i < n; ++i) printf "v %.9f %.9f 1\n", cos(2 * pi * i / n), sin(2 * pi * i / n);
    printf "f"; for (i = n; i >= 1; --i) printf " %d", n + i; printf "\n";
}' > "$TMP/disks.obj"
expect=$(awk 'BEGIN {
    n = 64; pi = atan2(0, -1); h = 1;
    r = sqrt(n * sin(2 * pi / n) / (2 * pi));      # equal-area radius
    R1 = r / h; R2 = r / h;
    X = 1 + (1 + R2 * R2) / (R1 * R1);
    printf "%.12f\n", 0.5 * (X - sqrt(X * X - 4 * (R2 / R1) * (R2 / R1)));
}')
if "$RAD" formfactors "$TMP/disks.obj" > "$TMP/disks.txt" 2> "$TMP/err.txt"; then
    v=$(pair "$TMP/disks.txt" a b)
    close "$v" "$expect" 1e-3 && ok "formfactors C-41 coaxial disks ($v, want $expect)" ||
        fail "formfactors C-41 coaxial disks" "got '$v', want $expect"
else
    fail "formfactors C-41 coaxial disks" "$(head -c 300 "$TMP/err.txt")"
fi

# ---- bake and info ----------------------------------------------------------------------
if "$RAD" bake cornell --patches 500 -o "$TMP/x.radb" > /dev/null 2> "$TMP/err.txt" && [ -s "$TMP/x.radb" ]; then
    ok "bake cornell"
    if "$RAD" info "$TMP/x.radb" > "$TMP/info.txt" 2>&1; then
        missing=""
        for s in PATCHES PATCH_VERTICES TRIANGLES FF_DENSE "VECTOR *E " "VECTOR *B "; do
            grep -q "$s" "$TMP/info.txt" || missing="$missing '$s'"
        done
        [ -z "$missing" ] && grep -q "patches: " "$TMP/info.txt" && ok "info lists the sections" ||
            fail "info lists the sections" "missing$missing"
    else
        fail "info lists the sections" "$(head -c 300 "$TMP/info.txt")"
    fi
    size=$(wc -c < "$TMP/x.radb")
    head -c $((size / 2)) "$TMP/x.radb" > "$TMP/truncated.radb"
    "$RAD" info "$TMP/truncated.radb" > /dev/null 2> "$TMP/err.txt"
    rc=$?
    [ $rc -ne 0 ] && grep -q "RAD_ERROR" "$TMP/err.txt" && ok "info rejects a truncated bake (exit $rc)" ||
        fail "info rejects a truncated bake" "exit $rc: $(head -c 200 "$TMP/err.txt")"
    # one flipped byte in the form factors: a checksum error
    cp "$TMP/x.radb" "$TMP/flipped.radb"
    printf '\377' | dd of="$TMP/flipped.radb" bs=1 seek=$((size / 2)) conv=notrunc 2> /dev/null
    "$RAD" info "$TMP/flipped.radb" > /dev/null 2> "$TMP/err.txt"
    rc=$?
    [ $rc -ne 0 ] && grep -q "RAD_ERROR" "$TMP/err.txt" && ok "info rejects a corrupted bake (exit $rc)" ||
        fail "info rejects a corrupted bake" "exit $rc: $(head -c 200 "$TMP/err.txt")"
    # render with the bake = render solving in memory with the same options
    if "$RAD" render cornell --bake "$TMP/x.radb" --size 32x32 --aa 4 -o "$TMP/baked.pfm" > /dev/null 2> "$TMP/err.txt" &&
        "$RAD" render cornell --patches 500 --size 32x32 --aa 4 -o "$TMP/solved.pfm" > /dev/null 2>> "$TMP/err.txt" &&
        cmp -s "$TMP/baked.pfm" "$TMP/solved.pfm"; then
        ok "render --bake equals the in-memory solution"
    else
        fail "render --bake equals the in-memory solution" "$(head -c 300 "$TMP/err.txt")"
    fi
    "$RAD" render "$TMP/parallel.obj" --bake "$TMP/x.radb" --size 8x8 -o "$TMP/wrong.pfm" > /dev/null 2>&1
    [ $? -eq 1 ] && ok "render --bake rejects another scene's bake" || fail "render --bake rejects another scene's bake"
else
    fail "bake cornell" "$(head -c 300 "$TMP/err.txt")"
fi

# ---- render -----------------------------------------------------------------------------
if "$RAD" render cornell --method classic --size 64x64 --aa 4 -o "$TMP/x.pfm" > /dev/null 2> "$TMP/err.txt"; then
    hdr=$(head -c 64 "$TMP/x.pfm" | head -n 2 | tr '\n' ' ')
    bytes=$(wc -c < "$TMP/x.pfm")
    if [ "$hdr" = "PF 64 64 " ] && [ "$bytes" -ge $((64 * 64 * 12)) ]; then
        ok "render classic writes a 64x64 PFM"
    else
        fail "render classic writes a 64x64 PFM" "header '$hdr', $bytes bytes"
    fi
else
    fail "render classic writes a 64x64 PFM" "$(head -c 300 "$TMP/err.txt")"
fi
if "$RAD" render cornell --method classic --patches 500 --size 48x32 --aa 1 -o "$TMP/x.png" > /dev/null 2> "$TMP/err.txt" &&
    [ "$(head -c 8 "$TMP/x.png" | od -An -tx1 | tr -d ' \n')" = "89504e470d0a1a0a" ]; then
    ok "render classic writes a PNG"
else
    fail "render classic writes a PNG" "$(head -c 300 "$TMP/err.txt")"
fi

if [ -f "$DATA/cornell.obj" ]; then
    CAM="0.278,0.273,-0.8:0.278,0.273,0:0,1,0"
    if "$RAD" render cornell --patches 1000 --size 64x64 --aa 4 -o "$TMP/builtin.pfm" > /dev/null 2> "$TMP/err.txt" &&
        "$RAD" render "$DATA/cornell.obj" --camera "$CAM" --fov 39.3077 --patches 1000 --size 64x64 --aa 4 \
            -o "$TMP/file.pfm" > /dev/null 2>> "$TMP/err.txt"; then
        if "$RAD" help 2> /dev/null | grep -q "^  compare"; then
            "$RAD" compare "$TMP/builtin.pfm" "$TMP/file.pfm" > "$TMP/cmp.txt" 2>&1
            psnr=$(awk '/^PSNR/ { print $2 }' "$TMP/cmp.txt")
            if [ "$psnr" = "inf" ] || awk -v p="$psnr" 'BEGIN { exit !(p != "" && p + 0 > 30) }'; then
                ok "cornell and cornell.obj render alike (PSNR $psnr dB)"
            else
                fail "cornell and cornell.obj render alike" "PSNR '$psnr': $(head -c 300 "$TMP/cmp.txt")"
            fi
        else
            skip "cornell and cornell.obj render alike" "no 'rad compare' in this build"
        fi
    else
        fail "cornell and cornell.obj render alike" "$(head -c 300 "$TMP/err.txt")"
    fi
else
    skip "cornell and cornell.obj render alike" "$DATA/cornell.obj not found (set RAD_DATA_DIR)"
fi

if "$RAD" render cornell --method pathtrace --size 32x32 --spp 4 -o "$TMP/pt.pfm" > /dev/null 2> "$TMP/err.txt" &&
    [ "$(head -c 64 "$TMP/pt.pfm" | head -n 2 | tr '\n' ' ')" = "PF 32 32 " ]; then
    ok "render pathtrace writes a PFM"
else
    fail "render pathtrace writes a PFM" "$(head -c 300 "$TMP/err.txt")"
fi

# --shading: the built-in box has only an area light, which stays Lambertian whatever the
# model, so a microfacet render equals the default one up to float rounding
if "$RAD" render cornell --patches 300 --size 32x32 --aa 1 -o "$TMP/sh-none.pfm" > /dev/null 2> "$TMP/err.txt" &&
    "$RAD" render cornell --patches 300 --size 32x32 --aa 1 --shading microfacet -o "$TMP/sh-mf.pfm" > /dev/null 2>> "$TMP/err.txt" &&
    "$RAD" compare "$TMP/sh-none.pfm" "$TMP/sh-mf.pfm" > "$TMP/cmp.txt" 2>&1 &&
    psnr=$(awk '/^PSNR/ { print $2 }' "$TMP/cmp.txt") &&
    { [ "$psnr" = "inf" ] || awk -v p="$psnr" 'BEGIN { exit !(p + 0 > 100) }'; }; then
    ok "render --shading leaves area lights Lambertian (PSNR $psnr dB: float rounding only)"
else
    fail "render --shading leaves area lights Lambertian" "$(head -c 300 "$TMP/err.txt")"
fi
"$RAD" render cornell -o "$TMP/x.png" --shading gouraud > /dev/null 2>&1; rc=$?
[ $rc = 2 ] && ok "render --shading rejects an unknown model" || fail "render --shading rejects an unknown model" "exit $rc"
"$RAD" render cornell -o "$TMP/x.png" --method pathtrace --shading phong > /dev/null 2>&1; rc=$?
[ $rc = 2 ] && ok "render --shading is refused with pathtrace" || fail "render --shading is refused with pathtrace" "exit $rc"

echo "$passes passed, $failures failed"
[ $failures -eq 0 ]
