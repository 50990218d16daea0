#!/bin/sh
# What feature buffers cost a render: in each round the same `lumen render
# ... --threads 1` runs twice at the same time, one per core (swapping cores
# every round, so that a machine's drift slows both alike), once without
# and once with `--aov $AOVS` (default albedo,normal: what --denoise keeps);
# prints each round's speed ratio (process time without over time with;
# 1 = no cost) and their median. The time is the whole process, from start
# to the last file written, saves included.
#
# usage: scripts/aov-bench.sh LUMEN [ROUNDS] [RENDER ARGS...]
#   default render: cover --width 640 --spp 64 --seed 1   (needs taskset, two cores)
#   AOVS=albedo,normal,depth scripts/aov-bench.sh ...   other layers
set -eu
lumen=$1
rounds=${2:-8}
shift
[ $# -gt 0 ] && shift
[ $# -gt 0 ] || set -- cover --width 640 --spp 64 --seed 1
aovs=${AOVS:-albedo,normal}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
. "$(dirname "$0")/lib/timing.sh"

# Runs lumen pinned to core $1 with the rest of the arguments; writes its
# wall-clock seconds to $out/$2.s and its output to $out/$2.txt.
timed() {
    core=$1
    name=$2
    shift 2
    /usr/bin/time -f %e -o "$out/$name.s" taskset -c "$core" "$lumen" render "$@" --threads 1 \
        -o "$out/$name.exr" >"$out/$name.txt" 2>&1 || {
        cat "$out/$name.txt" >&2
        exit 1
    }
}

ratios=
i=1
while [ "$i" -le "$rounds" ]; do
    ca=$((i % 2))
    cb=$((1 - ca))
    timed "$ca" off "$@" &
    pa=$!
    timed "$cb" on "$@" --aov "$aovs" &
    pb=$!
    wait "$pa" "$pb"
    ta=$(cat "$out/off.s")
    tb=$(cat "$out/on.s")
    r=$(ratio "$ta" "$tb")
    echo "round $i: without $ta s  with $tb s  speed with/without $r"
    ratios="$ratios $r"
    i=$((i + 1))
done
report "with/without" "$ratios"
