#!/bin/sh
# The book's own C++ (Ray Tracing in One Weekend, the final scene) against
# lumen's `cover` at the same size, samples and depth: docs/peers.md, "The
# book's C++".
#
# usage: scripts/peers/book_cover.sh BOOK_DIR [WIDTH] [SPP] [DEPTH]
#   BOOK_DIR: a checkout of github.com/RayTracing/raytracing.github.io
#   (its src/InOneWeekend is built here with g++ -O3; nothing of it is kept
#   in this repository). Defaults: 400 wide, 100 spp, depth 50.
#   LUMEN: the lumen binary (default target/release/lumen).
#
# The book's program is single-threaded: it runs on core 0 while lumen
# renders the same image with one thread on core 1 (both slowed alike by
# the host), then lumen renders it again with every core. Prints the times
# and the ratios; the book's rays per second are lumen's ray count over the
# book's time (the scene is the same random field in distribution: the
# same number of rays within a fraction of a percent).
set -eu
book=$1
width=${2:-400}
spp=${3:-100}
depth=${4:-50}
root=$(cd "$(dirname "$0")/../.." && pwd)
lumen=${LUMEN:-$root/target/release/lumen}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
src="$book/src/InOneWeekend"
[ -f "$src/main.cc" ] || { echo "no $src/main.cc" >&2; exit 1; }
cp "$src"/*.h "$work"/
sed -e "s/cam.image_width *= *[0-9]*;/cam.image_width = $width;/" \
    -e "s/cam.samples_per_pixel *= *[0-9]*;/cam.samples_per_pixel = $spp;/" \
    -e "s/cam.max_depth *= *[0-9]*;/cam.max_depth = $depth;/" \
    "$src/main.cc" >"$work/main.cc"
for field in "image_width = $width" "samples_per_pixel = $spp" "max_depth = $depth"; do
    grep -q "cam.$field;" "$work/main.cc" || { echo "could not set $field in main.cc" >&2; exit 1; }
done
g++ -O3 -std=c++17 -o "$work/book" "$work/main.cc"

seconds() { awk '/^time /{print $2; exit}' "$1"; }
taskset -c 0 sh -c 'start=$(date +%s%N); "$1" >"$2" 2>/dev/null; end=$(date +%s%N); echo $(((end - start) / 1000000))' \
    sh "$work/book" "$work/book.ppm" >"$work/book.ms" &
book_pid=$!
taskset -c 1 "$lumen" render cover --width "$width" --spp "$spp" --depth "$depth" --threads 1 \
    -o "$work/lumen1.png" >"$work/lumen1.txt" 2>&1
wait "$book_pid"
"$lumen" render cover --width "$width" --spp "$spp" --depth "$depth" -o "$work/lumen.png" >"$work/lumen.txt" 2>&1
book_s=$(awk '{print $1 / 1000}' "$work/book.ms")
one=$(seconds "$work/lumen1.txt")
all=$(seconds "$work/lumen.txt")
rays=$(awk '/^time /{for (i = 1; i <= NF; i++) if ($i == "rays,") {print $(i - 1); exit}}' "$work/lumen.txt")
awk -v b="$book_s" -v one="$one" -v all="$all" -v rays="$rays" -v w="$width" -v s="$spp" -v d="$depth" 'BEGIN {
    printf "cover %s wide, %s spp, depth %s (%s rays)\n", w, s, d, rays
    printf "book C++, 1 core      %8.2f s  %6.2f M rays/s\n", b, rays / b / 1e6
    printf "lumen, 1 thread       %8.2f s  %6.2f M rays/s  %5.1fx the book\n", one, rays / one / 1e6, b / one
    printf "lumen, every core     %8.2f s  %6.2f M rays/s  %5.1fx the book\n", all, rays / all / 1e6, b / all
}'
