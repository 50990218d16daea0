#!/bin/sh
# Compares the throughput of two lumen binaries on a machine whose
# speed drifts: in each round both run `lumen bench --threads 1` at the same
# time, one per core (swapping cores every round), so that drift slows both
# alike; prints each round's B/A ratio and their median.
#
# usage: scripts/ab-pair.sh BINARY_A BINARY_B [ROUNDS]   (needs taskset, two cores)
# LUMEN_BENCH_ARGS adds arguments to both benches, e.g. "--workload
# cover-400x225" when both binaries know it (it skips the other workloads).
set -eu
workload=${LUMEN_BENCH_ARGS:-}
a=$1
b=$2
rounds=${3:-8}
out=$(mktemp -d)
pa=
pb=
trap 'kill $pa $pb 2>/dev/null; rm -rf "$out"' EXIT
trap 'kill $pa $pb 2>/dev/null; rm -rf "$out"; exit 130' INT TERM
. "$(dirname "$0")/lib/timing.sh"

# Runs binary $1 on core $2, its output to $3, in the background.
bench() {
    taskset -c "$2" "$1" bench --threads 1 --runs 3 --spp 64 $workload >"$3" 2>&1 &
}

# The first workload's M rays/s in output file $1 (the cover unless
# LUMEN_BENCH_ARGS names another), or the output and exit 1.
rays() {
    r=$(awk 'seen && NF >= 3 {print $3; exit} /^workload/ {seen = 1}' "$1")
    if [ -z "$r" ]; then
        cat "$1" >&2
        exit 1
    fi
    echo "$r"
}

ratios=
i=0
while [ "$i" -lt "$rounds" ]; do
    core_a=$((i % 2))
    bench "$a" "$core_a" "$out/a"
    pa=$!
    bench "$b" $((1 - core_a)) "$out/b"
    pb=$!
    wait "$pa" || { cat "$out/a" >&2; exit 1; }
    wait "$pb" || { cat "$out/b" >&2; exit 1; }
    ra=$(rays "$out/a")
    rb=$(rays "$out/b")
    # Rays per second: B's over A's.
    r=$(ratio "$rb" "$ra")
    echo "round $((i + 1)): A $ra  B $rb M rays/s  B/A $r"
    ratios="$ratios $r"
    i=$((i + 1))
done
report "B/A" "$ratios"
