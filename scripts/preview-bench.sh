#!/bin/sh
# What watching a render costs it: in each round, the same `lumen render`
# runs without --preview, then with --preview and its page open in a
# running headless Chromium for the whole render (the page fetches every
# pass's image and draws it), one after the other; prints each round's speed
# ratio (time without over time with; 1 = no cost) and their median.
# Rounds alternate which run goes first, so that drift slows both alike.
#
# usage: scripts/preview-bench.sh LUMEN [ROUNDS] [RENDER ARGS...]
#   default render: cover --width 640 --spp 256 --seed 1 (all cores)
#   needs /usr/bin/chromium (Debian's chromium package) and curl
set -eu
lumen=$1
rounds=${2:-6}
shift
[ $# -gt 0 ] && shift
[ $# -gt 0 ] || set -- cover --width 640 --spp 256 --seed 1
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
. "$(dirname "$0")/lib/timing.sh"


plain() {
    "$lumen" render "$@" -o "$out/plain.png" >"$out/plain.txt" 2>&1
}

# One browser for every round, started (and warmed up) before them: its
# own start-up is not the page's cost. The page is opened in a new tab
# through Chromium's DevTools HTTP endpoint once the render prints its
# address, and closed when the render ends.
debug_port=${LUMEN_BENCH_DEVTOOLS_PORT:-9333}
/usr/bin/chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
    --disable-background-networking --disable-component-update --disable-sync \
    --user-data-dir="$out/profile" --remote-debugging-port="$debug_port" about:blank \
    >"$out/browser.txt" 2>&1 &
browser=$!
trap 'kill "$browser" 2>/dev/null; rm -rf "$out"' EXIT
until curl -sf "http://127.0.0.1:$debug_port/json/version" >/dev/null; do sleep 0.1; done

watched() {
    "$lumen" render "$@" --preview -o "$out/watched.png" >"$out/watched.txt" 2>&1 &
    pid=$!
    url=
    while [ -z "$url" ]; do
        sleep 0.05
        url=$(sed -n 's/^preview: //p' "$out/watched.txt")
    done
    tab=$(curl -sf -X PUT "http://127.0.0.1:$debug_port/json/new?$url" |
        sed -n 's/^ *"id": "\(.*\)",$/\1/p')
    [ -n "$tab" ] || {
        echo "the browser did not open the page" >&2
        exit 1
    }
    wait "$pid"
    curl -sf "http://127.0.0.1:$debug_port/json/close/$tab" >/dev/null
}

ratios=
i=1
while [ "$i" -le "$rounds" ]; do
    if [ $((i % 2)) -eq 1 ]; then
        plain "$@"
        watched "$@"
    else
        watched "$@"
        plain "$@"
    fi
    ta=$(seconds "$out/plain.txt")
    tb=$(seconds "$out/watched.txt")
    r=$(ratio "$ta" "$tb")
    echo "round $i: without $ta s  with the page $tb s  speed $r"
    ratios="$ratios $r"
    i=$((i + 1))
done
report "speed with the page / without:" "$ratios"
