#!/bin/sh
# Compares the cover throughput of two lumen binaries on a machine whose
# speed drifts: in each round both run `lumen bench --threads 1` at the same
# time, one per core (swapping cores every round), so that drift slows both
# alike; prints each round's B/A ratio and their median.
#
# usage: scripts/ab-pair.sh BINARY_A BINARY_B [ROUNDS]   (needs taskset, two cores)
set -eu
a=$1
b=$2
rounds=${3:-8}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
ratios=""
i=0
while [ "$i" -lt "$rounds" ]; do
    core_a=$((i % 2))
    core_b=$((1 - core_a))
    taskset -c "$core_a" "$a" bench --threads 1 --runs 3 --spp 64 >"$out/a" 2>&1 &
    taskset -c "$core_b" "$b" bench --threads 1 --runs 3 --spp 64 >"$out/b" 2>&1 &
    wait
    ra=$(awk '/^cover/ {print $3}' "$out/a")
    rb=$(awk '/^cover/ {print $3}' "$out/b")
    ratio=$(awk -v a="$ra" -v b="$rb" 'BEGIN {printf "%.3f", b / a}')
    echo "round $((i + 1)): A $ra  B $rb M rays/s  B/A $ratio"
    ratios="$ratios $ratio"
    i=$((i + 1))
done
echo "$ratios" | tr ' ' '\n' | grep . | sort -n | awk '
    { v[NR] = $1 }
    END { m = (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2;
          printf "B/A median %.3f (range %s to %s, %d rounds)\n", m, v[1], v[NR], NR }'
