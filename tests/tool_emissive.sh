# tool_emissive.sh - emission through the importer (sourced by tool_tests.sh, which defines RAD,
# TMP, ok, fail and close): the glTF Cornell box of tests/data (radiance 17 12 4 written as
# emissiveFactor (1, 12/17, 4/17) x KHR_materials_emissive_strength 17, which assimp 5.2 does
# not read) renders like the OBJ box, a 2 x 2 checker emissiveTexture (mean one half) halves
# all the light in rad render and rad trace, and rad info reports each material.
EM_DIR=$(dirname "${BASH_SOURCE[0]}")/data
"$RAD" export cornell -o "$TMP/em_box.obj" > /dev/null 2>&1
em_mean() { "$RAD" compare "$1" "$2" 2> /dev/null | awk '/^mean:/ { print $2, $3 }'; }
if "$RAD" render "$TMP/em_box.obj" -o "$TMP/em_obj.pfm" --size 48x48 --aa 4 --patches 150 > /dev/null 2>&1 &&
    "$RAD" render "$EM_DIR/cornell.gltf" -o "$TMP/em_gltf.pfm" --size 48x48 --aa 4 --patches 150 > /dev/null 2> "$TMP/em_err.txt" &&
    "$RAD" render "$EM_DIR/cornell_textured.gltf" -o "$TMP/em_tex.pfm" --size 48x48 --aa 4 --patches 150 > /dev/null 2>&1; then
    set -- $(em_mean "$TMP/em_gltf.pfm" "$TMP/em_obj.pfm") "" ""
    close "$1" "$2" 0.01 && ok "glTF Cornell box (emissive strength 17) renders the OBJ box's energy ($1 vs $2)" ||
        fail "glTF Cornell box (emissive strength 17) renders the OBJ box's energy" "mean $1 vs $2"
    set -- $(em_mean "$TMP/em_tex.pfm" "$TMP/em_obj.pfm") "" ""
    close "$1" "$(awk -v b="$2" 'BEGIN { print b / 2 }')" 0.01 &&
        ok "a checker emissiveTexture halves the rendered light ($1 vs $2)" ||
        fail "a checker emissiveTexture halves the rendered light" "mean $1 vs $2"
else
    fail "render of the glTF Cornell box" "$(head -c 300 "$TMP/em_err.txt")"
fi
if "$RAD" trace "$EM_DIR/cornell.gltf" -o "$TMP/em_tr.pfm" --size 32x32 --spp 16 > /dev/null 2>&1 &&
    "$RAD" trace "$EM_DIR/cornell_textured.gltf" -o "$TMP/em_trt.pfm" --size 32x32 --spp 16 > /dev/null 2>&1; then
    set -- $(em_mean "$TMP/em_trt.pfm" "$TMP/em_tr.pfm") "" ""
    close "$1" "$(awk -v b="$2" 'BEGIN { print b / 2 }')" 0.03 &&
        ok "rad trace: a checker emissiveTexture halves the light ($1 vs $2)" ||
        fail "rad trace: a checker emissiveTexture halves the light" "mean $1 vs $2"
else
    fail "rad trace of the glTF Cornell box" ""
fi
# rad info SCENE: per material what was used and what was ignored, by name
sed 's/"name": "m0_white",/"name": "m0_white", "normalTexture": {"index": 0}, "doubleSided": true, "alphaMode": "MASK", "alphaCutoff": 0.25, "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1}},/' \
    "$EM_DIR/cornell_textured.gltf" > "$TMP/em_info.gltf"
if "$RAD" info "$TMP/em_info.gltf" > "$TMP/em_info.txt" 2> "$TMP/em_err.txt"; then
    awk '/^material .*m3_light/ { on = 1; next } /^material/ { on = 0 } on' "$TMP/em_info.txt" > "$TMP/em_light.txt"
    grep -q "emission (radiance): texture '.*' x 17 12 4 (emissiveFactor 1 0.705882 0.235294 x KHR_materials_emissive_strength 17)" \
        "$TMP/em_light.txt" && ok "rad info: the lamp's emission factor, strength and texture" ||
        fail "rad info: the lamp's emission factor, strength and texture" "$(head -c 400 "$TMP/em_light.txt")"
    awk '/^material .*m0_white/ { on = 1; next } /^material/ { on = 0 } on' "$TMP/em_info.txt" > "$TMP/em_white.txt"
    grep -q "doubleSided: true (used" "$TMP/em_white.txt" && grep -q "sides: two"  "$TMP/em_white.txt" && grep -q "alphaMode: MASK, alphaCutoff 0.25 (used" "$TMP/em_white.txt" &&
        grep -q "cutout: none (opaque)" "$TMP/em_white.txt" &&
        grep -q "ignored: .*normalTexture (not diffuse)" "$TMP/em_white.txt" &&
        grep -q "ignored: .*KHR_materials_transmission (extension)" "$TMP/em_white.txt" &&
        grep -q "ignored: .*metallicFactor (not diffuse)" "$TMP/em_white.txt" &&
        ok "rad info: doubleSided, alphaMode read; normalTexture, metallicFactor, KHR_materials_transmission named as ignored" ||
        fail "rad info: what a material read and ignored" "$(head -c 600 "$TMP/em_white.txt")"
else
    fail "rad info of a glTF scene" "$(head -c 300 "$TMP/em_err.txt")"
fi
if "$RAD" info cornell > "$TMP/em_ci.txt" 2>&1 && grep -q "emission (radiance): 17 12 4" "$TMP/em_ci.txt"; then
    ok "rad info cornell lists the built-in materials"
else
    fail "rad info cornell lists the built-in materials" "$(head -c 300 "$TMP/em_ci.txt")"
fi
# a negative emissive strength is refused naming the material, not dropped
sed 's/"emissiveStrength": 17.0/"emissiveStrength": -17.0/' "$EM_DIR/cornell.gltf" > "$TMP/em_neg.gltf"
"$RAD" info "$TMP/em_neg.gltf" > /dev/null 2> "$TMP/em_err.txt"
rc=$?
[ $rc -eq 1 ] && grep -q "material .* 'm3_light': emissive strength -17 is out of range" "$TMP/em_err.txt" &&
    ok "a negative KHR_materials_emissive_strength is refused naming the material" ||
    fail "a negative KHR_materials_emissive_strength is refused naming the material" "exit $rc: $(head -c 300 "$TMP/em_err.txt")"
# OBJ: Ke x map_Ke, the glTF's checker written out as a PNG, uvs 0..1 across the lamp
grep -o 'data:image/png;base64,[^"]*' "$EM_DIR/cornell_textured.gltf" | cut -d, -f2 | base64 -d > "$TMP/em_checker.png"
awk 'BEGIN { print "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1" }
     /^o / { lamp = ($2 == "light") }
     /^v / { nv++; if (lamp && !first) first = nv }
     lamp && /^f / { printf "f"; for (i = 2; i <= 4; ++i) printf " %d/%d", $i, $i - first + 1; print ""; next }
     { print }' "$TMP/em_box.obj" | sed 's/^mtllib .*/mtllib em_tex.mtl/' > "$TMP/em_tex.obj"
sed 's/^Ke 17 12 4$/Ke 17 12 4\nmap_Ke em_checker.png/' "$TMP/em_box.mtl" > "$TMP/em_tex.mtl"
if "$RAD" render "$TMP/em_tex.obj" -o "$TMP/em_objtex.pfm" --size 48x48 --aa 4 --patches 150 > /dev/null 2> "$TMP/em_err.txt" &&
    [ -f "$TMP/em_obj.pfm" ]; then
    set -- $(em_mean "$TMP/em_objtex.pfm" "$TMP/em_obj.pfm") "" ""
    close "$1" "$(awk -v b="$2" 'BEGIN { print b / 2 }')" 0.01 && ok "OBJ map_Ke (checker) x Ke halves the rendered light ($1 vs $2)" ||
        fail "OBJ map_Ke (checker) x Ke halves the rendered light" "mean $1 vs $2"
else
    fail "render of an OBJ with map_Ke" "$(head -c 300 "$TMP/em_err.txt")"
fi
# the other methods follow the texture: the hierarchical elements' mean, AAVP's samples
for em_m in hierarchical aavp; do
    if "$RAD" render "$EM_DIR/cornell.gltf" -o "$TMP/em_a.pfm" --size 24x24 --aa 1 --method $em_m > /dev/null 2>&1 &&
        "$RAD" render "$EM_DIR/cornell_textured.gltf" -o "$TMP/em_b.pfm" --size 24x24 --aa 1 --method $em_m > /dev/null 2> "$TMP/em_err.txt"; then
        set -- $(em_mean "$TMP/em_b.pfm" "$TMP/em_a.pfm") "" ""
        close "$1" "$(awk -v b="$2" 'BEGIN { print b / 2 }')" 0.01 &&
            ok "--method $em_m: a checker emissiveTexture halves the light ($1 vs $2)" ||
            fail "--method $em_m: a checker emissiveTexture halves the light" "mean $1 vs $2"
    else
        fail "--method $em_m render of the textured glTF box" "$(head -c 300 "$TMP/em_err.txt")"
    fi
done
# unnamed materials, the lamp's mesh first: assimp numbers materials by first use, not in the
# file's order, so the strength is matched by base colour and emissive factor, not by index
if "$RAD" render "$EM_DIR/cornell_unnamed.gltf" -o "$TMP/em_un.pfm" --size 48x48 --aa 4 --patches 150 > /dev/null 2> "$TMP/em_err.txt" &&
    [ -f "$TMP/em_gltf.pfm" ]; then
    set -- $(em_mean "$TMP/em_un.pfm" "$TMP/em_gltf.pfm") "" ""
    close "$1" "$2" 0.01 && ok "unnamed glTF materials in another order keep the lamp's strength ($1 vs $2)" ||
        fail "unnamed glTF materials in another order keep the lamp's strength" "mean $1 vs $2"
else
    fail "render of the unnamed glTF Cornell box" "$(head -c 300 "$TMP/em_err.txt")"
fi
