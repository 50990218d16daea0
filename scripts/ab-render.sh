#!/bin/sh
# Compares two lumen binaries on one render, on a machine whose speed
# drifts: in each round both run the same `lumen render ... --threads 1` at
# the same time, one per core (swapping cores every round), so that drift
# slows both alike; prints each round's speed ratio B/A (time of A over time
# of B) and their median. Faster than scripts/ab-pair.sh, and works with
# binaries whose `lumen bench` knows different workloads.
#
# usage: scripts/ab-render.sh BINARY_A BINARY_B [ROUNDS] [RENDER ARGS...]
#   default render: cover --width 400 --spp 64 --seed 1   (needs taskset, two cores)
set -eu
a=$1
b=$2
rounds=${3:-10}
shift 2
[ $# -gt 0 ] && shift
[ $# -gt 0 ] || set -- cover --width 400 --spp 64 --seed 1
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
. "$(dirname "$0")/lib/timing.sh"


ratios=
i=1
while [ "$i" -le "$rounds" ]; do
    ca=$((i % 2))
    cb=$((1 - ca))
    taskset -c "$ca" "$a" render "$@" --threads 1 -o "$out/a.pfm" >"$out/a.txt" 2>&1 &
    pa=$!
    taskset -c "$cb" "$b" render "$@" --threads 1 -o "$out/b.pfm" >"$out/b.txt" 2>&1 &
    pb=$!
    wait "$pa" "$pb"
    ta=$(seconds "$out/a.txt")
    tb=$(seconds "$out/b.txt")
    r=$(ratio "$ta" "$tb")
    echo "round $i: A $ta s  B $tb s  speed B/A $r"
    ratios="$ratios $r"
    i=$((i + 1))
done
report "B/A" "$ratios"
