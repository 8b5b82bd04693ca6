#!/usr/bin/env bash
# dist_tests.sh - checks of the distributed bake (docs/distributed.md): rad bake --shard/--rows,
# rad merge, and the MPI driver tools/rad-mpi.
#     bash tests/dist_tests.sh RAD PART_EDIT [RAD_MPI]
# RAD: the rad tool; PART_EDIT: tests/dist_part_edit.c built; RAD_MPI: rad-mpi (empty or absent:
# its checks print "skip"). Prints "ok NAME", "FAIL NAME: why" or "skip NAME: why" per check;
# exits 1 when a check failed. Every bake is the built-in Cornell box at --patches 300 (378
# patches), a few seconds each.
set -u
RAD=$1
EDIT=$2
MPI=${3:-}
TMP=$(mktemp -d "${TMPDIR:-/tmp}/rad_dist_tests.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
failures=0
ok() { echo "ok $1"; }
fail() { echo "FAIL $1${2:+: $2}"; failures=$((failures + 1)); }
skip() { echo "skip $1: $2"; }
B="--patches 300"
# merge_refuses NAME PATTERN PARTS...: rad merge exits 1, says PATTERN, and writes nothing
merge_refuses() {
    local name=$1 pattern=$2
    shift 2
    rm -f "$TMP/refused.radb"
    "$RAD" merge "$@" -o "$TMP/refused.radb" > /dev/null 2> "$TMP/err.txt"
    local rc=$?
    if [ $rc -eq 1 ] && grep -q -- "$pattern" "$TMP/err.txt" && [ ! -e "$TMP/refused.radb" ]; then
        ok "$name"
    else
        fail "$name" "exit $rc: $(head -c 300 "$TMP/err.txt")"
    fi
}

# ---- the single bake and its 3 shards --------------------------------------------------
if ! "$RAD" bake cornell $B -o "$TMP/full.radb" > /dev/null 2> "$TMP/err.txt"; then
    fail "single bake" "$(head -c 300 "$TMP/err.txt")"
    exit 1
fi
for i in 0 1 2; do
    "$RAD" bake cornell $B --shard $i/3 -o "$TMP/p$i.radb" > /dev/null 2> "$TMP/shard$i.txt" ||
        fail "bake --shard $i/3" "$(head -c 300 "$TMP/shard$i.txt")"
done
# each unordered pair in exactly one shard: the shards' pairs add up to N (N - 1) / 2, and
# none holds more than 36% of them (balanced by pairs, not rows)
cat "$TMP"/shard?.txt | awk '/ of [0-9]+ pairs/ { for (k = 1; k <= NF; ++k) if ($k == "of") { s += $(k - 1); t = $(k + 1); m = $(k - 1) > m ? $(k - 1) : m } }
    END { exit !(t == 378 * 377 / 2 && s == t && m <= 0.36 * t) }' &&
    ok "3 shards hold each of the 71253 pairs once, balanced" ||
    fail "3 shards hold each pair once, balanced" "$(grep -h ' pairs' "$TMP"/shard?.txt)"
if "$RAD" merge "$TMP/p2.radb" "$TMP/p0.radb" "$TMP/p1.radb" -o "$TMP/merged.radb" > /dev/null 2> "$TMP/err.txt" &&
    cmp -s "$TMP/full.radb" "$TMP/merged.radb"; then
    ok "merge of 3 shards (any order) equals the single bake byte for byte"
else
    fail "merge of 3 shards equals the single bake" "$(head -c 300 "$TMP/err.txt")"
fi
"$RAD" info "$TMP/merged.radb" > /dev/null 2>&1 && ok "info reads the merged bake" || fail "info reads the merged bake"
# --rows parts of uneven sizes, with one thread, merge to the same bytes too
"$RAD" bake cornell $B --rows 0:40 --threads 1 -o "$TMP/r0.radb" > /dev/null 2>&1 &&
    "$RAD" bake cornell $B --rows 40:378 -o "$TMP/r1.radb" > /dev/null 2>&1 &&
    "$RAD" merge "$TMP/r0.radb" "$TMP/r1.radb" -o "$TMP/rows.radb" > /dev/null 2>&1 &&
    cmp -s "$TMP/full.radb" "$TMP/rows.radb" && ok "merge of --rows parts equals the single bake" ||
    fail "merge of --rows parts equals the single bake"

# ---- refusals: each names the reason ---------------------------------------------------
merge_refuses "merge names a missing shard" "shard 1 of 3 is missing" "$TMP/p0.radb" "$TMP/p2.radb"
merge_refuses "merge refuses a shard given twice" "shard 2/3 is given twice" "$TMP/p0.radb" "$TMP/p1.radb" "$TMP/p2.radb" "$TMP/p2.radb"
merge_refuses "merge refuses overlapping rows" "overlap" "$TMP/r0.radb" "$TMP/r1.radb" "$TMP/p1.radb"
merge_refuses "merge names missing rows" "rows 40:378 are in no part" "$TMP/r0.radb"
merge_refuses "merge refuses a bake that is no part" "not a part of a sharded bake" "$TMP/full.radb" "$TMP/p1.radb"
"$RAD" bake cornell $B --samples 9 --rows 40:378 -o "$TMP/s9.radb" > /dev/null 2>&1 ||
    fail "bake --samples 9 --rows 40:378"
merge_refuses "merge refuses parts baked with other options (names the option)" "different options (--samples 16 vs 9)" \
    "$TMP/r0.radb" "$TMP/s9.radb"
cat > "$TMP/box.obj" << 'EOF'
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
f 1 2 3 4
f 8 7 6 5
f 1 5 6 2
f 2 6 7 3
f 3 7 8 4
f 5 1 4 8
EOF
"$RAD" bake "$TMP/box.obj" $B --rows 0:1 -o "$TMP/other.radb" > /dev/null 2>&1 || fail "bake of another scene's part"
merge_refuses "merge refuses parts of another scene" "different scenes" "$TMP/r0.radb" "$TMP/other.radb"
if "$EDIT" "$TMP/r1.radb" "$TMP/v.radb" 0.0.9; then
    merge_refuses "merge refuses parts of another library version" "by 0.0.9: the parts of one bake come from one version" "$TMP/r0.radb" "$TMP/v.radb"
    merge_refuses "merge refuses parts of a version other than its own" "this rad is" "$TMP/v.radb" "$TMP/r0.radb"
else
    fail "dist_part_edit rewrites a part"
fi
"$RAD" bake cornell $B --shard 1/3 --method multibounce -o "$TMP/mb.radb" > /dev/null 2> "$TMP/err.txt"
[ $? -eq 2 ] && grep -q "classic" "$TMP/err.txt" && ok "bake --shard refuses --method multibounce" ||
    fail "bake --shard refuses --method multibounce" "$(head -c 200 "$TMP/err.txt")"
for bad in 3/3 1/0 x/2 1; do
    "$RAD" bake cornell $B --shard "$bad" -o "$TMP/bad.radb" > /dev/null 2>&1
    [ $? -eq 2 ] || fail "bake --shard $bad is a usage error"
done
"$RAD" bake cornell $B --rows 0:999 -o "$TMP/bad.radb" > /dev/null 2> "$TMP/err.txt"
[ $? -eq 1 ] && grep -q "beyond the 378 patches" "$TMP/err.txt" && [ ! -e "$TMP/bad.radb" ] &&
    ok "bake --rows beyond the patches fails and writes nothing" || fail "bake --rows beyond the patches" "$(head -c 200 "$TMP/err.txt")"

# ---- MPI ---------------------------------------------------------------------------------
if [ -z "$MPI" ] || ! command -v mpirun > /dev/null 2>&1; then
    skip mpi "OpenMPI is not installed (packages libopenmpi-dev openmpi-bin)"
else
    RUN="mpirun"
    [ "$(id -u)" = 0 ] && RUN="$RUN --allow-run-as-root"
    OVER=""
    [ "$(nproc 2> /dev/null || echo 1)" -ge 2 ] || OVER="--oversubscribe"
    if $RUN -np 2 $OVER "$MPI" bake cornell $B -o "$TMP/mpi2.radb" > /dev/null 2> "$TMP/err.txt" &&
        cmp -s "$TMP/full.radb" "$TMP/mpi2.radb"; then
        ok "mpirun -np 2 rad-mpi bake equals the single bake byte for byte"
    else
        fail "mpirun -np 2 rad-mpi bake equals the single bake" "$(tail -c 400 "$TMP/err.txt")"
    fi
    if $RUN -np 3 --oversubscribe "$MPI" bake cornell $B -o "$TMP/mpi3.radb" > /dev/null 2> "$TMP/err.txt" &&
        cmp -s "$TMP/full.radb" "$TMP/mpi3.radb"; then
        ok "mpirun -np 3 --oversubscribe rad-mpi bake equals the single bake byte for byte"
    else
        fail "mpirun -np 3 rad-mpi bake equals the single bake" "$(tail -c 400 "$TMP/err.txt")"
    fi
    # rank 1 gets a scene that does not exist (MPMD): the run fails with rank 1's message and
    # leaves no output, not even a temporary
    mkdir -p "$TMP/out"
    $RUN -np 1 $OVER "$MPI" bake cornell $B -o "$TMP/out/failed.radb" : -np 1 "$MPI" bake "$TMP/missing.obj" $B \
        -o "$TMP/out/failed.radb" > /dev/null 2> "$TMP/err.txt" < /dev/null
    rc=$?
    [ $rc -ne 0 ] && grep -q "rank 1/2.*missing.obj" "$TMP/err.txt" && grep -q "nothing written" "$TMP/err.txt" &&
        [ -z "$(ls -A "$TMP/out")" ] && ok "a failing rank fails the run with its message and no output" ||
        fail "a failing rank fails the run" "exit $rc: $(head -c 400 "$TMP/err.txt")"
    $RUN -np 2 $OVER "$MPI" bake cornell $B --shard 0/2 -o "$TMP/x.radb" > /dev/null 2> "$TMP/err.txt"
    [ $? -ne 0 ] && grep -q "leave them out" "$TMP/err.txt" && ok "rad-mpi refuses --shard" || fail "rad-mpi refuses --shard"
fi
[ $failures -eq 0 ]
