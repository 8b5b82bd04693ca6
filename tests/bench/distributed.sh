#!/usr/bin/env bash
# distributed.sh - the distributed bake (docs/distributed.md) measured on this machine:
# the work of the shards against one bake (CPU seconds, one thread), and rad-mpi with 1 and 2
# ranks of one thread each (wall seconds).
#     bash tests/bench/distributed.sh RAD RAD_MPI [PATCHES] [REPEATS] >> section.md
# Prints a markdown section. Times: the best of REPEATS runs (default 3).
set -eu
RAD=$1
MPI=$2
PATCHES=${3:-1000}
REPEATS=${4:-3}
TMP=$(mktemp -d "${TMPDIR:-/tmp}/rad_dist_bench.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
RUN="mpirun"
[ "$(id -u)" = 0 ] && RUN="$RUN --allow-run-as-root"
best() { sort -g | head -n 1; }
# CPU seconds of the form factors: "in X s (Y s CPU)" of a bake's or a shard's line (one
# thread: the work, whatever else the machine runs)
ff_secs() { sed -n 's/.* pairs.* in [0-9.]* s (\([0-9.]*\) s CPU)$/\1/p' "$1"; }
done_secs() { sed -n 's/.*done in \([0-9.]*\) s$/\1/p' "$1" | tail -n 1; }

single_ff=""; single_all=""
for r in $(seq "$REPEATS"); do
    "$RAD" bake cornell --patches "$PATCHES" --threads 1 -o "$TMP/full.radb" > /dev/null 2> "$TMP/single.txt"
    single_ff="$single_ff $(ff_secs "$TMP/single.txt")"
    single_all="$single_all $(done_secs "$TMP/single.txt")"
done
N=$(sed -n 's/.*triangles, \([0-9]*\) patches/\1/p' "$TMP/single.txt" | head -n 1)
shard_ff=""; shard_pairs=""
for i in 0 1; do
    t=""
    for r in $(seq "$REPEATS"); do
        "$RAD" bake cornell --patches "$PATCHES" --threads 1 --shard $i/2 -o "$TMP/p$i.radb" > /dev/null 2> "$TMP/shard$i.txt"
        t="$t $(ff_secs "$TMP/shard$i.txt")"
    done
    shard_ff="$shard_ff $(echo $t | tr ' ' '\n' | best)"
    shard_pairs="$shard_pairs $(sed -n 's/.*: \([0-9]*\) of [0-9]* pairs.*/\1/p' "$TMP/shard$i.txt")"
done
"$RAD" merge "$TMP/p0.radb" "$TMP/p1.radb" -o "$TMP/merged.radb" > /dev/null 2> "$TMP/merge.txt"
cmp -s "$TMP/full.radb" "$TMP/merged.radb" && same=yes || same=NO
evaluated=$(sed -n 's/.* \([0-9]*\) pairs evaluated.*/\1/p' "$TMP/merge.txt")
mpi1=""; mpi2=""
for r in $(seq "$REPEATS"); do
    $RUN -np 1 "$MPI" bake cornell --patches "$PATCHES" --threads 1 -o "$TMP/m1.radb" > /dev/null 2> "$TMP/m1.txt"
    $RUN -np 2 "$MPI" bake cornell --patches "$PATCHES" --threads 1 -o "$TMP/m2.radb" > /dev/null 2> "$TMP/m2.txt"
    mpi1="$mpi1 $(sed -n 's/.*ranks, done in \([0-9.]*\) s$/\1/p' "$TMP/m1.txt")"
    mpi2="$mpi2 $(sed -n 's/.*ranks, done in \([0-9.]*\) s$/\1/p' "$TMP/m2.txt")"
done
cmp -s "$TMP/full.radb" "$TMP/m2.radb" && same2=yes || same2=NO
sf=$(echo $single_ff | tr ' ' '\n' | best)
sa=$(echo $single_all | tr ' ' '\n' | best)
m1=$(echo $mpi1 | tr ' ' '\n' | best)
m2=$(echo $mpi2 | tr ' ' '\n' | best)
set -- $shard_ff; s0=$1; s1=$2
set -- $shard_pairs; q0=$1; q1=$2
full_bytes=$(stat -c %s "$TMP/full.radb")
part_bytes=$(( $(stat -c %s "$TMP/p0.radb") + $(stat -c %s "$TMP/p1.radb") ))
awk -v N="$N" -v sf="$sf" -v sa="$sa" -v s0="$s0" -v s1="$s1" -v q0="$q0" -v q1="$q1" -v ev="$evaluated" \
    -v m1="$m1" -v m2="$m2" -v fb="$full_bytes" -v pb="$part_bytes" -v same="$same" -v same2="$same2" -v rep="$REPEATS" \
    -v load="$(cut -d' ' -f1-3 /proc/loadavg)" 'BEGIN {
    pairs = N * (N - 1) / 2
    printf "Cornell box, N = %d patches (%d pairs), 16 samples, one thread per process, best of %d runs; load average %s on 2 cores while it ran (other work on the machine).\n\n", N, pairs, rep, load
    printf "| form factors | CPU seconds | pairs | pairs evaluated |\n|---|---:|---:|---:|\n"
    printf "| single bake | %.2f | %d | %d |\n", sf, pairs, ev
    printf "| shard 0/2 | %.2f | %d | |\n", s0, q0
    printf "| shard 1/2 | %.2f | %d | |\n", s1, q1
    printf "| shards together | %.2f (%.1f%% of the single bake) | %d (%+.2f%%) | %d (the same pairs) |\n\n", s0 + s1, 100 * (s0 + s1) / sf, q0 + q1, 100 * (q0 + q1 - pairs) / pairs, ev
    printf "Pair balance: the larger shard holds %.1f%% of the pairs and took %.1f%% of the shards'"'"' CPU time. Merge of the two parts equals the single bake byte for byte: %s.\n\n", 100 * (q0 > q1 ? q0 : q1) / pairs, 100 * (s0 > s1 ? s0 : s1) / (s0 + s1), same
    printf "| rad-mpi bake (whole run: patches, direct light, form factors, gather, merge, solve, write) | wall seconds |\n|---|---:|\n"
    printf "| 1 rank | %.2f |\n| 2 ranks | %.2f |\n| parallel efficiency T1 / (2 T2) | %.0f%% |\n\n", m1, m2, 100 * m1 / (2 * m2)
    printf "Single bake (1 thread, whole run): %.2f s wall; 2 ranks equal it byte for byte: %s. Per evaluated pair: %.2f us of one core (the single bake'"'"'s form-factor CPU time / pairs evaluated). Container: %d bytes; the 2 parts: %d bytes (%.2fx).\n", sa, same2, 1e6 * sf / ev, fb, pb, pb / fb
}'
