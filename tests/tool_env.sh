# tool_env.sh - checks of the environment light in the rad tool (--env), sourced by
# tool_tests.sh (its RAD, TMP, ok, fail, close, bad and pfm_mean).

# env_hdr FILE W H: a flat (not run-length encoded) Radiance .hdr of W x H pixels whose
# radiance is the awk expression in $4 of the row y (0 = zenith) and column x (0 = +X)
env_hdr() {
    {
        printf '#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n' "$3" "$2"
        LC_ALL=C awk -v W="$2" -v H="$3" "
            function rgbe(r, g, b,   m, e, f) {
                m = r; if (g > m) m = g; if (b > m) m = b
                if (m < 1e-32) { printf \"%c%c%c%c\", 0, 0, 0, 0; return }
                e = 0; f = m
                while (f >= 1) { f /= 2; e++ }
                while (f < 0.5) { f *= 2; e-- }
                f = 256 / 2 ^ e
                printf \"%c%c%c%c\", int(r * f), int(g * f), int(b * f), e + 128
            }
            BEGIN { for (y = 0; y < H; ++y) for (x = 0; x < W; ++x) { $4; rgbe(R, G, B) } }"
    } > "$1"
}

# The direction convention: a camera far outside the box, fov 4 degrees, sees only the map:
# along +X the columns u < 1/8 (red), along +Z those around u = 1/4 (green), straight up
# the top rows (white 3); turned 90 degrees (+X towards +Z), the red columns move to +Z and
# the green ones to -X.
env_hdr "$TMP/env-dirs.hdr" 32 16 'R = G = B = 0.5
    if (x < 4) { R = 1; G = B = 0 } else if (x >= 6 && x < 10) { G = 1; R = B = 0 }
    if (y < 2) R = G = B = 3'
while read -r name cam rot want; do
    for cmd in render trace; do
        opts="--aa 1 --patches 20"
        [ $cmd = trace ] && opts="--spp 1"
        if "$RAD" $cmd cornell --env "$TMP/env-dirs.hdr:1:$rot" --camera "$cam" --fov 4 --size 4x4 $opts \
            -o "$TMP/env-dir.pfm" > /dev/null 2> "$TMP/err.txt"; then
            v=$(pfm_mean "$TMP/env-dir.pfm")
            close "$v" "$want" 1e-3 && ok "$cmd --env: $name sees mean radiance $v" ||
                fail "$cmd --env: $name" "mean radiance $v, want $want"
        else
            fail "$cmd --env: $name" "$(head -c 300 "$TMP/err.txt")"
        fi
    done
done <<'EOF2'
+X 10,0.3,0.3:11,0.3,0.4:0,1,0 0 0.333333
+Z 0.3,0.3,10:0.3,0.3,11:0,1,0 0 0.333333
up 0.3,10,0.3:0.3,11,0.3:1,0,0 0 3
+Z-turned-90 0.3,0.3,10:0.1,0.3,11:0,1,0 90 0.333333
-X-turned-90 -10,0.3,0.3:-11,0.3,0.3:0,1,0 90 0.333333
-X -10,0.3,0.3:-11,0.3,0.3:0,1,0 0 0.5
EOF2

# A constant map of radiance (0.5, 1, 2) is the sky of that radiance: rad render of the dark
# box agrees with its --sky 0.5,1,2 image within 2% (the library's direct light for both:
# the map's estimator, half its rays drawn below the horizon here, is the noisier).
"$RAD" export cornell -o "$TMP/envbox.obj" > /dev/null 2>&1
sed 's/^Ke .*/Ke 0 0 0/' "$TMP/envbox.mtl" > "$TMP/envbox.tmp" && mv "$TMP/envbox.tmp" "$TMP/envbox.mtl"
env_hdr "$TMP/env-const.hdr" 16 8 'R = 0.5; G = 1; B = 2'
if "$RAD" render "$TMP/envbox.obj" --env "$TMP/env-const.hdr" --fov 25 --size 16x16 --patches 200 --aa 4 \
    --light-samples 256 -o "$TMP/env-c.pfm" > /dev/null 2> "$TMP/err.txt" &&
    "$RAD" render "$TMP/envbox.obj" --sky 0.5,1,2 --fov 25 --size 16x16 --patches 200 --aa 4 --light-samples 256 \
        -o "$TMP/env-s.pfm" > /dev/null 2>> "$TMP/err.txt"; then
    me=$(pfm_mean "$TMP/env-c.pfm"); ms=$(pfm_mean "$TMP/env-s.pfm")
    close "$me" "$ms" 0.02 && grep -q "1 environment" "$TMP/err.txt" &&
        ok "render --env constant map = --sky of its radiance (mean $me and $ms)" ||
        fail "render --env constant map = --sky of its radiance" "mean $me and $ms"
else
    fail "render --env constant map = --sky of its radiance" "$(head -c 300 "$TMP/err.txt")"
fi

# The room with a window: the dark box lit through its open side by a map of a sky (0.6, 0.8,
# 1.2), a ground (0.2) and a sun of two texels (radiance 400, about 0.01 sr) that shines in.
# rad render (classic radiosity, 300 patches, the library's importance-sampled direct light)
# and rad trace (its own path tracer, next-event estimation from the same distribution with
# MIS) agree on the mean radiance within 3% (measured: 1.2%).
env_hdr "$TMP/env-sun.hdr" 32 16 'if (y < 8) { R = 0.6; G = 0.8; B = 1.2 } else { R = G = B = 0.2 }
    if (y == 5 && (x == 24 || x == 25)) { R = 400; G = 380; B = 340 }'
if "$RAD" render "$TMP/envbox.obj" --env "$TMP/env-sun.hdr" --fov 25 --size 24x24 --patches 300 --aa 64 \
    -o "$TMP/env-r.pfm" > /dev/null 2> "$TMP/err.txt" &&
    "$RAD" trace "$TMP/envbox.obj" --env "$TMP/env-sun.hdr" --fov 25 --size 24x24 --spp 256 \
        -o "$TMP/env-t.pfm" > /dev/null 2>> "$TMP/err.txt"; then
    mr=$(pfm_mean "$TMP/env-r.pfm"); mt=$(pfm_mean "$TMP/env-t.pfm")
    awk -v t="$mt" 'BEGIN { exit !(t + 0 > 1.0) }' && close "$mr" "$mt" 0.03 &&
        ok "room with a window under an environment map: render and trace agree (mean $mr and $mt)" ||
        fail "room with a window under an environment map: render and trace agree" "mean $mr and $mt"
else
    fail "room with a window under an environment map: render and trace agree" "$(head -c 300 "$TMP/err.txt")"
fi

# bad maps: exit 2 naming the problem
bad "--env of a missing file" "cannot read HDR\|not a Radiance" render cornell --env "$TMP/no-such.hdr" -o "$TMP/y.pfm"
bad "--env of a PNG" "must be a Radiance .hdr or an OpenEXR" trace cornell --env "$TMP/y.png:2" -o "$TMP/y.pfm"
bad "--env with a negative scale" "SCALE must be a number >= 0" render cornell --env "$TMP/env-const.hdr:-1" -o "$TMP/y.pfm"

# Preetham's sky and its sun from the date and time (16 h on 21 June at 45 N: 37.3 degrees up,
# 93 degrees west of north) light the box through its open side: render and trace agree on
# the mean radiance within 3% (measured: 0.2%)
if "$RAD" render "$TMP/envbox.obj" --sky-model preetham:3 --sun-time 45:172:16 --fov 25 --size 24x24 --patches 300 \
    --aa 16 -o "$TMP/sky-r.pfm" > /dev/null 2> "$TMP/err.txt" &&
    "$RAD" trace "$TMP/envbox.obj" --sun-time 45:172:16 --sky-model preetham:3 --fov 25 --size 24x24 --spp 64 \
        -o "$TMP/sky-t.pfm" > /dev/null 2>> "$TMP/err.txt"; then
    mr=$(pfm_mean "$TMP/sky-r.pfm"); mt=$(pfm_mean "$TMP/sky-t.pfm")
    grep -q "sun 37.3 degrees up at azimuth -93" "$TMP/err.txt" && grep -q "1 sun, 0 sky, 1 environment" "$TMP/err.txt" &&
        awk -v t="$mt" 'BEGIN { exit !(t + 0 > 0.5) }' && close "$mr" "$mt" 0.03 &&
        ok "--sky-model preetham:3 --sun-time 45:172:16: render and trace agree (mean $mr and $mt)" ||
        fail "--sky-model preetham:3 --sun-time 45:172:16: render and trace agree" "mean $mr and $mt; $(grep 'sky model' "$TMP/err.txt")"
else
    fail "--sky-model preetham:3 --sun-time 45:172:16: render and trace agree" "$(head -c 300 "$TMP/err.txt")"
fi
bad "--sky-model turbidity 12" "turbidity T in \[1.7, 10\]" render cornell --sky-model preetham:12 --sun-time 45:172:12 -o "$TMP/y.pfm"
bad "--sun-time at night" "below the horizon" trace cornell --sky-model preetham:3 --sun-time 45:172:23 -o "$TMP/y.pfm"
bad "--sun-time 45:400:12" "LAT in \[-90, 90\], DAY in \[1, 366\]" render cornell --sun-time 45:400:12 --sky-model preetham:3 -o "$TMP/y.pfm"
"$RAD" render cornell --sky-model preetham:3 -o "$TMP/y.pfm" > /dev/null 2> "$TMP/err.txt"
rc=$?
[ $rc -eq 1 ] && grep -q -- "--sky-model needs --sun-time" "$TMP/err.txt" && ok "rejects --sky-model without --sun-time" ||
    fail "rejects --sky-model without --sun-time" "exit $rc: $(head -c 200 "$TMP/err.txt")"

# An OpenEXR map (tinyexr): rad render writes a constant image of the sky (0.5, 1, 2) as
# .exr; read back as --env it shows that radiance to a camera looking away from the box
if "$RAD" render cornell --sky 0.5,1,2 --size 8x4 --patches 20 --aa 1 --camera 0,0,-1:0,0,-2:0,1,0 \
    -o "$TMP/env-c.exr" > /dev/null 2> "$TMP/err.txt"; then
    if "$RAD" render cornell --env "$TMP/env-c.exr" --size 4x4 --patches 20 --aa 1 --camera 0,0,-1:0,0,-2:0,1,0 \
        -o "$TMP/env-exr.pfm" > /dev/null 2> "$TMP/err.txt"; then
        v=$(pfm_mean "$TMP/env-exr.pfm")
        close "$v" 1.166667 1e-4 && ok "--env reads an OpenEXR map (mean radiance $v)" ||
            fail "--env reads an OpenEXR map" "mean $v, want 1.166667"
    else
        grep -q "without tinyexr" "$TMP/err.txt" && skip_data "--env reads an OpenEXR map" "rad built without tinyexr" ||
            fail "--env reads an OpenEXR map" "$(head -c 300 "$TMP/err.txt")"
    fi
else
    grep -q "without tinyexr" "$TMP/err.txt" && skip_data "--env reads an OpenEXR map" "rad built without tinyexr" ||
        fail "--env reads an OpenEXR map (writing it)" "$(head -c 300 "$TMP/err.txt")"
fi
