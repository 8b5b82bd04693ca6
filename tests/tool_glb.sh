# tool_glb.sh - rad lightmap -o OUT.glb|OUT.gltf, the scene for engines (sourced by
# tool_tests.sh, which defines RAD, TMP, ok, fail, close, pfm_mean and psnr_of). The browser
# check (three.js in Chromium) is the web suite: tests/web/run.sh.

# the GLB container: magic "glTF", version 2, the length in the header is the file's, the
# first chunk is JSON naming the lightmap on TEXCOORD_1 and the camera; the HDR copy beside it
le32() { od -An -t u4 -j "$2" -N 4 "$1" | tr -d ' '; }
if "$RAD" lightmap cornell --patches 200 --size 64 -o "$TMP/lm.glb" > /dev/null 2> "$TMP/err.txt"; then
    hdr=$(ls "$TMP"/lm.lightmap.exr "$TMP"/lm.lightmap.pfm 2> /dev/null | head -n 1)
    json_len=$(le32 "$TMP/lm.glb" 12)
    head -c $((20 + json_len)) "$TMP/lm.glb" | tail -c "$json_len" > "$TMP/lm.json"
    if [ "$(head -c 4 "$TMP/lm.glb")" = glTF ] && [ "$(le32 "$TMP/lm.glb" 4)" = 2 ] &&
        [ "$(le32 "$TMP/lm.glb" 8)" = "$(wc -c < "$TMP/lm.glb" | tr -d ' ')" ] &&
        [ "$(head -c 20 "$TMP/lm.glb" | tail -c 4)" = JSON ] && [ $((json_len % 4)) = 0 ] &&
        grep -q '"TEXCOORD_1"' "$TMP/lm.json" && grep -q '"RAD_lightmap":{"texture":0,"texCoord":1,"encoding":"srgb","scale":' "$TMP/lm.json" &&
        grep -q '"cameras":\[{"name":"rad view","type":"perspective"' "$TMP/lm.json" && grep -q '"mimeType":"image/png"' "$TMP/lm.json" &&
        [ -n "$hdr" ] && grep -q "\"hdr\":\"$(basename "$hdr")\"" "$TMP/lm.json"; then
        ok "lightmap -o x.glb: a GLB 2.0 whose materials name the PNG lightmap on TEXCOORD_1, a camera, the HDR copy beside it"
    else
        fail "lightmap -o x.glb: a GLB 2.0 whose materials name the PNG lightmap on TEXCOORD_1, a camera, the HDR copy beside it" \
            "$(head -c 300 "$TMP/lm.json")"
    fi
else
    fail "lightmap -o x.glb" "$(tail -n 3 "$TMP/err.txt")"
fi

# glb in: assimp reads it back (the box's 8 meshes by name, 32 triangles), and a lightmap baked
# over its own TEXCOORD_1 (no unwrap) is the one written beside it, within the bake's noise
if "$RAD" info "$TMP/lm.glb" > "$TMP/info.txt" 2>&1 && grep -q "8 meshes, 32 triangles" "$TMP/info.txt" &&
    grep -q "'red'" "$TMP/info.txt"; then
    ok "a written glb reads back: 8 meshes, 32 triangles, the material names"
else
    fail "a written glb reads back: 8 meshes, 32 triangles, the material names" "$(head -n 3 "$TMP/info.txt")"
fi
if [ -n "${hdr:-}" ] && "$RAD" lightmap "$TMP/lm.glb" --patches 200 --size 64 -o "$TMP/again.gltf" > /dev/null 2> "$TMP/err.txt" &&
    grep -q "using the file's second uv set" "$TMP/err.txt" && [ -s "$TMP/again.bin" ] &&
    grep -q '"uri":"again.bin"' "$TMP/again.gltf"; then
    again=$(ls "$TMP"/again.lightmap.exr "$TMP"/again.lightmap.pfm 2> /dev/null | head -n 1)
    p=$(psnr_of "$hdr" "$again")
    if at_least "$p" 40; then ok "glb in, gltf out: the file's TEXCOORD_1 gives the same lightmap (PSNR $p dB)"
    else fail "glb in, gltf out: the file's TEXCOORD_1 gives the same lightmap" "PSNR $p dB"; fi
else
    fail "glb in, gltf out: the file's TEXCOORD_1 gives the same lightmap" "$(tail -n 3 "$TMP/err.txt")"
fi

# what a glb cannot carry is refused before the work
"$RAD" lightmap cornell --sh -o "$TMP/sh.glb" > /dev/null 2> "$TMP/err.txt"
rc=$?
[ $rc = 2 ] && grep -q "leave out --sh" "$TMP/err.txt" && [ ! -e "$TMP/sh.glb" ] && ok "lightmap --sh -o x.glb is refused (exit 2)" ||
    fail "lightmap --sh -o x.glb is refused (exit 2)" "exit $rc"

# names: the .bin's uri percent-encoded (a space in the file name), a material name that is not
# UTF-8 (Latin-1 in an MTL) written with '?' so the JSON stays valid UTF-8
printf 'newmtl caf\351\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 0 0 0\nKe 5 5 5\n' > "$TMP/names.mtl"
printf 'mtllib names.mtl\nv 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nv 0 1 0\nv 0 1 1\nv 1 1 1\nv 1 1 0\nusemtl caf\351\nf 1 4 3 2\nusemtl lamp\nf 5 8 7 6\n' > "$TMP/names.obj"
if "$RAD" lightmap "$TMP/names.obj" --patches 20 --size 32 -o "$TMP/my scene.gltf" > /dev/null 2> "$TMP/err.txt" &&
    grep -q '"uri":"my%20scene.bin"' "$TMP/my scene.gltf" && grep -q '"name":"caf?"' "$TMP/my scene.gltf" &&
    [ -s "$TMP/my scene.bin" ]; then
    ok "gltf names: the buffer's uri percent-encoded, a non-UTF-8 material name made valid"
else
    fail "gltf names: the buffer's uri percent-encoded, a non-UTF-8 material name made valid" "$(tail -n 2 "$TMP/err.txt")"
fi
