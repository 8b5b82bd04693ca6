# tool_assets.sh - the small real assets of tests/data through the importer (sourced by
# tool_tests.sh, which defines RAD, TMP, ok, fail and close): what `rad info` reports for the
# showcase scene (.gltf with base64 buffers and images, and the same scene as .glb) and for the
# glTF scenes exported by Blender (tests/data/gltf-blender-io), the emission of the emissive
# strength scene against its closed form, and quick renders against rad trace.
AS_DIR=$(dirname "${BASH_SOURCE[0]}")/data
AS_BIO=$AS_DIR/gltf-blender-io
# the lines of material NAME in a `rad info` listing
as_mat() { awk -v n="'$2':" '/^material / { on = ($3 == n); next } on' "$1"; }
as_mean() { "$RAD" compare "$1" "$2" 2> /dev/null | awk '/^mean:/ { print $2, $3 }'; }

# showcase: .gltf and .glb report the same materials
for as_f in showcase.gltf showcase.glb; do
    if "$RAD" info "$AS_DIR/$as_f" > "$TMP/as_info.txt" 2> "$TMP/as_err.txt"; then
        as_mat "$TMP/as_info.txt" screen > "$TMP/as_m.txt"
        grep -q "emission (radiance): texture '.*' x 6 6 6 (emissiveFactor 1 1 1 x KHR_materials_emissive_strength 6)" "$TMP/as_m.txt" &&
            ok "rad info $as_f: the screen's emissive texture x factor x strength 6" ||
            fail "rad info $as_f: the screen's emissive texture x factor x strength 6" "$(head -c 400 "$TMP/as_m.txt")"
        as_mat "$TMP/as_info.txt" leaf_cards > "$TMP/as_m.txt"
        grep -q "albedo: texture '" "$TMP/as_m.txt" && grep -q "alphaMode: MASK, alphaCutoff 0.5" "$TMP/as_m.txt" &&
            grep -q "sides: two" "$TMP/as_m.txt" &&
            ok "rad info $as_f: the leaf cards' base-colour texture, alphaMode MASK 0.5, two-sided" ||
            fail "rad info $as_f: the leaf cards' texture, alpha mode and sides" "$(head -c 400 "$TMP/as_m.txt")"
        as_c=$(as_mat "$TMP/as_info.txt" curtain | grep -c "sides: two")
        as_p=$(as_mat "$TMP/as_info.txt" plaster | grep -c "sides: two")
        as_o=$(as_mat "$TMP/as_info.txt" floor_wood | grep -c "sides: one")
        [ "$as_c$as_p$as_o" = 111 ] && ok "rad info $as_f: curtain and walls two-sided (doubleSided), the floor one-sided" ||
            fail "rad info $as_f: sides of curtain, walls, floor" "$as_c$as_p$as_o"
        head -1 "$TMP/as_info.txt" | grep -q ": 12 meshes, 88 triangles, 10 materials" &&
            ok "rad info $as_f: 12 meshes, 88 triangles" || fail "rad info $as_f: counts" "$(head -1 "$TMP/as_info.txt")"
    else
        fail "rad info $as_f" "$(head -c 300 "$TMP/as_err.txt")"
    fi
done

# Blender's export: doubleSided on one sphere only, alphaMode MASK with its cutoff, the
# emissive strength extension with and without an emissive texture, under both PBR models
if "$RAD" info "$AS_BIO/14_emission_strength/14_emission_strength.gltf" > "$TMP/as_info.txt" 2> "$TMP/as_err.txt"; then
    as_good=0
    for as_m in pbrEmissiveStrength SpecGlossEmissiveStrength; do
        as_mat "$TMP/as_info.txt" $as_m | grep -q "emission (radiance): 4.5 4 3.5 (emissiveFactor 0.9 0.8 0.7 x KHR_materials_emissive_strength 5)" &&
            as_good=$((as_good + 1))
    done
    for as_m in pbrEmissiveStrengthTexture SpecGlossEmissiveStrengthTexture; do
        as_mat "$TMP/as_info.txt" $as_m | grep -q "emission (radiance): texture '14_emission_strength.png' x 4.5 4 3.5 (emissiveFactor" &&
            as_good=$((as_good + 1))
    done
    as_mat "$TMP/as_info.txt" pbrEmissiveTexture | grep -q "emission (radiance): texture '14_emission_strength.png' x 0.9 0.8 0.7$" &&
        as_good=$((as_good + 1))
    as_mat "$TMP/as_info.txt" pbrEmissive | grep -q "emission (radiance): 0.9 0.8 0.7$" && as_good=$((as_good + 1))
    [ $as_good -eq 6 ] && ok "rad info: Blender's emissive strength scene, factor x strength x texture per material" ||
        fail "rad info: Blender's emissive strength scene" "$as_good of 6 materials as expected"
else
    fail "rad info of Blender's emissive strength scene" "$(head -c 300 "$TMP/as_err.txt")"
fi
if "$RAD" info "$AS_BIO/01_single_vs_double_sided/01_single_vs_double_sided.gltf" > "$TMP/as_info.txt" 2> "$TMP/as_err.txt" &&
    as_mat "$TMP/as_info.txt" mat_double | grep -q "doubleSided: true" && as_mat "$TMP/as_info.txt" mat_double | grep -q "sides: two" &&
    as_mat "$TMP/as_info.txt" mat_single | grep -q "sides: one"; then
    ok "rad info: Blender's doubleSided sphere two-sided, the other one-sided"
else
    fail "rad info: Blender's single and double-sided spheres" "$(head -c 400 "$TMP/as_info.txt") $(head -c 200 "$TMP/as_err.txt")"
fi
if "$RAD" info "$AS_BIO/01_alpha_mask/01_alpha_mask.gltf" > "$TMP/as_info.txt" 2> "$TMP/as_err.txt" &&
    as_mat "$TMP/as_info.txt" Alpha_Mask | grep -q "alphaMode: MASK, alphaCutoff 0.42" &&
    as_mat "$TMP/as_info.txt" Alpha_Mask | grep -q "albedo: texture '01_alpha_mask.png"; then
    ok "rad info: Blender's alpha mask quad (MASK, cutoff 0.42, its texture)"
else
    fail "rad info: Blender's alpha mask quad" "$(head -c 400 "$TMP/as_info.txt") $(head -c 200 "$TMP/as_err.txt")"
fi

# The emissive spheres (radius 1, centres 2 apart along x) seen head-on through a 2-degree
# view: the patch of sphere in view faces the camera and its neighbours lie behind its tangent
# plane, so the radiance is the emission alone: 0.9 0.8 0.7 (mean 0.8) for pbrEmissive at
# x = 12, times the strength 5 (mean 4) for pbrEmissiveStrength at x = 18.
as_ok=1
for as_x in 12:0.8 18:4; do
    as_c=${as_x%%:*}
    "$RAD" trace "$AS_BIO/14_emission_strength/14_emission_strength.gltf" --camera $as_c,0,-4:$as_c,0,0:0,1,0 --fov 2 \
        --size 4x4 --spp 4 -o "$TMP/as_e$as_c.pfm" > /dev/null 2> "$TMP/as_err.txt" || as_ok=0
done
if [ $as_ok = 1 ]; then
    set -- $(as_mean "$TMP/as_e12.pfm" "$TMP/as_e18.pfm") "" ""
    close "$1" 0.8 0.01 && close "$2" 4 0.01 &&
        ok "rad trace: Blender's emissive spheres radiate factor (mean $1) and factor x strength 5 (mean $2)" ||
        fail "rad trace: Blender's emissive spheres radiate factor and factor x strength" "mean $1 (want 0.8), $2 (want 4)"
else
    fail "rad trace of Blender's emissive spheres" "$(head -c 300 "$TMP/as_err.txt")"
fi

# Quick renders against rad trace (the same importer, lights and camera): the showcase lit
# by its sky through the window, and Blender's spheres (one two-sided, seen inside through
# their holes) under a uniform sky. Energy within 5% at these low counts.
as_pair() { # NAME TOL SCENE ARGS...: rad render (--patches 300) and rad trace (64 spp), 40x40
    local n=$1 tol=$2 s=$3
    shift 3
    if "$RAD" render "$s" "$@" --size 40x40 --aa 4 --patches 300 -o "$TMP/as_r.pfm" > /dev/null 2> "$TMP/as_err.txt" &&
        "$RAD" trace "$s" "$@" --size 40x40 --spp 64 -o "$TMP/as_t.pfm" > /dev/null 2>> "$TMP/as_err.txt"; then
        set -- $(as_mean "$TMP/as_r.pfm" "$TMP/as_t.pfm") "" ""
        close "$1" "$2" "$tol" && ok "$n: rad render's energy within $tol of rad trace's ($1 vs $2)" ||
            fail "$n: rad render's energy within $tol of rad trace's" "mean $1 vs $2"
    else
        fail "$n: rad render and rad trace" "$(head -c 300 "$TMP/as_err.txt")"
    fi
}
as_pair "showcase under its sky" 0.05 "$AS_DIR/showcase.glb" --env "$AS_DIR/showcase_sky.hdr"
as_pair "Blender's single and double-sided spheres" 0.05 "$AS_BIO/01_single_vs_double_sided/01_single_vs_double_sided.gltf" --sky 1

# A glTF camera sits at its node's origin with the file's yfov: the showcase's camera node
# (translation 1.6 1.55 -2.3, turned to look at -0.5 0.95 1.2, yfov 62 degrees) gives the
# image of the same camera given on the command line.
if "$RAD" trace "$AS_DIR/showcase.gltf" --env "$AS_DIR/showcase_sky.hdr" --size 24x24 --spp 4 -o "$TMP/as_c1.pfm" > /dev/null 2> "$TMP/as_err.txt" &&
    "$RAD" trace "$AS_DIR/showcase.gltf" --env "$AS_DIR/showcase_sky.hdr" --size 24x24 --spp 4 -o "$TMP/as_c2.pfm" \
        --camera 1.6,1.55,-2.3:-0.5,0.95,1.2:0,1,0 --fov 62 > /dev/null 2>> "$TMP/as_err.txt"; then
    as_s=$("$RAD" compare "$TMP/as_c1.pfm" "$TMP/as_c2.pfm" 2> /dev/null | awk '/^SSIM/ { print $2 }')
    at_least "$as_s" 0.99 && ok "a glTF camera node: position, direction and yfov as in the file (SSIM $as_s)" ||
        fail "a glTF camera node: position, direction and yfov as in the file" "SSIM $as_s against the explicit camera"
else
    fail "rad trace with a glTF camera" "$(head -c 300 "$TMP/as_err.txt")"
fi

# KHR_texture_transform: two quads (an emissive texture, a base-colour texture under a white
# sky) with the transform on their texture references render as the same quads with the
# transform applied to their uvs instead; rad info says it was used.
if "$RAD" trace "$AS_DIR/texture_transform.gltf" --sky 1 --camera 0,0.5,-3:0,0.5,0:0,1,0 --fov 40 --size 32x32 --spp 4 \
        -o "$TMP/as_x1.pfm" > /dev/null 2> "$TMP/as_err.txt" &&
    "$RAD" trace "$AS_DIR/texture_transform_baked.gltf" --sky 1 --camera 0,0.5,-3:0,0.5,0:0,1,0 --fov 40 --size 32x32 --spp 4 \
        -o "$TMP/as_x2.pfm" > /dev/null 2>> "$TMP/as_err.txt" &&
    "$RAD" info "$AS_DIR/texture_transform.gltf" > "$TMP/as_info.txt" 2>> "$TMP/as_err.txt"; then
    as_s=$("$RAD" compare "$TMP/as_x1.pfm" "$TMP/as_x2.pfm" 2> /dev/null | awk '/^SSIM/ { print $2 }')
    at_least "$as_s" 0.999 && [ "$(grep -c "KHR_texture_transform: used" "$TMP/as_info.txt")" = 2 ] &&
        ok "KHR_texture_transform on emissive and base-colour textures: as the transformed uvs (SSIM $as_s)" ||
        fail "KHR_texture_transform on emissive and base-colour textures" "SSIM $as_s; $(grep -c "KHR_texture_transform" "$TMP/as_info.txt") report lines"
else
    fail "rad trace of the texture transform quads" "$(head -c 300 "$TMP/as_err.txt")"
fi

# The lightmap of a scene with two-sided materials: the unwrapped copy takes one side of each
# pair (pairing them again made every sheet four coincident triangles, and the form factors
# between coincident patches multiplied the light by about 1000). The showcase's lightmap
# render within 10% of rad trace's energy (one lightmap layer: the leaf cards show one side's
# indirect light on both).
if "$RAD" render "$AS_DIR/showcase.glb" --env "$AS_DIR/showcase_sky.hdr" --method lightmap --patches 300 --size 32x32 --aa 1 \
        -o "$TMP/as_lm.pfm" > /dev/null 2> "$TMP/as_err.txt" &&
    "$RAD" trace "$AS_DIR/showcase.glb" --env "$AS_DIR/showcase_sky.hdr" --size 32x32 --spp 64 -o "$TMP/as_lt.pfm" > /dev/null 2>> "$TMP/as_err.txt"; then
    set -- $(as_mean "$TMP/as_lm.pfm" "$TMP/as_lt.pfm") "" ""
    close "$1" "$2" 0.1 && ok "lightmap of two-sided sheets: energy within 10% of rad trace ($1 vs $2)" ||
        fail "lightmap of two-sided sheets: energy within 10% of rad trace" "mean $1 vs $2"
else
    fail "rad render --method lightmap of the showcase" "$(head -c 300 "$TMP/as_err.txt")"
fi
