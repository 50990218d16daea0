#!/bin/sh
# What feature buffers cost a render: in each round the same `lumen render
# ... --threads 1` runs twice at the same time, one per core (swapping cores
# every round, so that a machine's drift slows both alike), once without
# and once with `--aov $AOVS` (default albedo,normal: what --denoise keeps);
# prints each round's speed ratio (process time without over time with;
# 1 = no cost) and their median. The time is the whole process, from start
# to the last file written, saves included.
#
#
# SEQUENTIAL=1: each round runs the two one after the other instead, on all
# threads (the order swapped every round), and compares the render time
# lumen reports (its passes and saves, without start-up and loading). The
# two runs then share no memory bandwidth, which at the same time weighs
# against the larger film with layers.
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

# Runs lumen on all threads with the rest of the arguments; writes the
# render time it reports to $out/$1.s.
whole() {
    name=$1
    shift
    "$lumen" render "$@" -o "$out/$name.exr" >"$out/$name.txt" 2>&1 || {
        cat "$out/$name.txt" >&2
        exit 1
    }
    seconds "$out/$name.txt" >"$out/$name.s"
}

# Runs round $1's two renders (the rest of the arguments, without and
# with the layers): one after the other with SEQUENTIAL=1, the order
# swapped every round; otherwise at once, a core each, the cores swapped.
run_round() {
    round=$1
    shift
    if [ "${SEQUENTIAL:-0}" = 1 ] && [ $((round % 2)) = 1 ]; then
        whole off "$@"
        whole on "$@" --aov "$aovs"
    elif [ "${SEQUENTIAL:-0}" = 1 ]; then
        whole on "$@" --aov "$aovs"
        whole off "$@"
    else
        ca=$((round % 2))
        timed "$ca" off "$@" &
        pa=$!
        timed $((1 - ca)) on "$@" --aov "$aovs" &
        pb=$!
        wait "$pa" "$pb"
    fi
}

ratios=
i=1
while [ "$i" -le "$rounds" ]; do
    run_round "$i" "$@"
    ta=$(cat "$out/off.s")
    tb=$(cat "$out/on.s")
    r=$(ratio "$ta" "$tb")
    echo "round $i: without $ta s  with $tb s  speed with/without $r"
    ratios="$ratios $r"
    i=$((i + 1))
done
report "with/without" "$ratios"
