#!/usr/bin/env bash
# tests/web/run.sh RAD WORKDIR - the web suite: a scene baked by `rad lightmap -o OUT.glb`, shown
# by three.js (an engine this project did not write) in headless Chromium, agrees with the rad
# tool's own views of the same camera. Run from the repository root (tests/run.sh's stage web).
#
# Needs chromium and node/npm (Debian: chromium npm). three.js comes from npm once, pinned, into
# build/web/node_modules (the page's import map points there); later runs, and machines without
# the registry, use that copy. Prints "ok ..." / "FAIL ..." lines; exit 0 pass, 1 fail, 77 skip
# with the reason on the last line as "skip: ...".
#
# The measure: the canvas three.js drew, read back by the page (drawn without MSAA: WebGL
# resolves it in sRGB, which darkens edges, while the tool averages linear radiance) and each view decoded from sRGB to linear,
# luminance (Rec. 709) averaged over a 4x4 grid of regions (tests/web/check.mjs):
#   - `rad lightmap --render`: the same lightmap texels shaded by the tool (radiance = emission +
#     albedo x bilinear lightmap / pi), so the difference is the glb's encoding and three.js:
#     every region within 5%, their mean within 2%;
#   - `rad render --method lightmap`: the tool's lightmap renderer, as a user would compare. It
#     adds the direct light per pixel (the lightmap holds only the indirect light there), and
#     the two tool views themselves differ by ~5% on the ceiling beside the light: every region
#     within 8%, their mean within 2%.
set -u
RAD=${1:?usage: tests/web/run.sh RAD WORKDIR}
WORK=${2:?usage: tests/web/run.sh RAD WORKDIR}
THREE_VERSION=0.187.0 # material.lightMap adds irradiance (no pi factor) since r155; Texture.channel since r151
THREE_DIR=build/web/node_modules/three
SIZE=256
mkdir -p "$WORK"
have() { command -v "$1" >/dev/null 2>&1; }
skip() { echo "skip: $1"; exit 77; }
have chromium || skip "chromium is not installed (package chromium)"
have node || skip "node is not installed (package npm brings nodejs)"
if ! grep -q "\"version\": \"$THREE_VERSION\"" "$THREE_DIR/package.json" 2>/dev/null; then
    have npm || skip "three.js $THREE_VERSION is not in $THREE_DIR and npm is not installed (package npm)"
    mkdir -p build/web
    echo "installing three@$THREE_VERSION from npm into build/web (once)"
    if ! npm install --prefix build/web --no-audit --no-fund --no-save "three@$THREE_VERSION" >"$WORK/npm.log" 2>&1 ||
        ! grep -q "\"version\": \"$THREE_VERSION\"" "$THREE_DIR/package.json" 2>/dev/null; then
        tail -n 5 "$WORK/npm.log" | sed 's/^/    /'
        skip "three.js $THREE_VERSION is not in $THREE_DIR and 'npm install three@$THREE_VERSION' failed (can npm reach its registry? the log: $WORK/npm.log)"
    fi
fi
failed=0
# the Cornell box: 400 patches and a 256x256 atlas keep the two bakes to ~15 s of CPU
if "$RAD" lightmap cornell --patches 400 --size 256 -o "$WORK/cornell.glb" --render "$WORK/lightmap-view.png" \
        --render-size ${SIZE}x${SIZE} >"$WORK/lightmap.log" 2>&1 &&
    "$RAD" render cornell --method lightmap --patches 400 --lightmap-size 256 --size ${SIZE}x${SIZE} \
        -o "$WORK/render-view.png" >"$WORK/render.log" 2>&1; then
    echo "ok    bake cornell.glb and the tool's two views"
else
    tail -n 5 "$WORK/lightmap.log" "$WORK/render.log" 2>/dev/null | sed 's/^/    /'
    echo "FAIL  bake cornell.glb and the tool's two views"
    exit 1
fi
out=$(node tests/web/check.mjs --glb "$WORK/cornell.glb" --out "$WORK/three-view.png" --size ${SIZE}x${SIZE} \
    --aa 0 --tol 0.05 --mean-tol 0.02 --ref "$WORK/lightmap-view.png" --tol 0.08 --ref "$WORK/render-view.png" 2>&1)
rc=$?
echo "$out" | sed -E 's/^(ok|FAIL) +/\1    three.js vs /; s/^page:/      page:/'
[ $rc = 0 ] || failed=1
echo "      three.js view: $WORK/three-view.png"
exit $failed
