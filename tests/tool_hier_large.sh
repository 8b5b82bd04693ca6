# tool_hier_large.sh - rad render --method hierarchical on coincident layers (sourced by
# tool_tests.sh: uses $RAD, $TMP, ok and fail). A floor stored three times over under a ceiling
# (albedo 0.85, lit by a sky): the sweeps grew B to infinity and the run failed blaming the
# lights; now it renders, reports its progress and its memory, and its image is finite.
{
    echo "newmtl white"; echo "Kd 0.85 0.85 0.85"
} > "$TMP/hl_layers.mtl"
{
    echo "mtllib hl_layers.mtl"; echo "usemtl white"
    for c in 1 2 3; do echo "v 0 0 0"; echo "v 0 0 1"; echo "v 1 0 1"; echo "v 1 0 0"; done
    echo "v 0 0.1 0"; echo "v 1 0.1 0"; echo "v 1 0.1 1"; echo "v 0 0.1 1"
    for c in 0 1 2 3; do b=$((4 * c)); echo "f $((b + 1)) $((b + 2)) $((b + 3))"; echo "f $((b + 1)) $((b + 3)) $((b + 4))"; done
} > "$TMP/hl_layers.obj"
if "$RAD" render "$TMP/hl_layers.obj" --method hierarchical --hr-eps 1e-3 --sky 3 --camera 0.5,0.05,-1:0.5,0.05,0.5:0,1,0 \
        --size 16x12 -o "$TMP/hl_layers.pfm" > /dev/null 2> "$TMP/hl_err.txt" &&
        grep -q "MiB of elements and links" "$TMP/hl_err.txt" && ! grep -q "nan\|inf " "$TMP/hl_err.txt"; then
    ok "render --method hierarchical: three coincident floors under a ceiling solve (no inf from the sweeps)"
else
    fail "render --method hierarchical: three coincident floors under a ceiling" "$(tail -c 400 "$TMP/hl_err.txt")"
fi
