#!/bin/sh
# Renders every built-in scene (as it is, and with the path integrator) and
# the example scenes with two lumen binaries, small and with few samples, to
# linear .pfm files, and compares them byte for byte: a change meant to
# leave the images alone must pass it.
#
# usage: scripts/same-images.sh BINARY_A BINARY_B [WIDTH] [SPP]
#   A's images are kept in $LUMEN_SAME_DIR/a (default: a temporary directory)
set -eu
a=$1
b=$2
width=${3:-128}
spp=${4:-16}
root=$(cd "$(dirname "$0")/.." && pwd)
out=${LUMEN_SAME_DIR:-$(mktemp -d)}
mkdir -p "$out/a" "$out/b"

render() { # binary dir name scene args...
    bin=$1 dir=$2 name=$3 scene=$4
    shift 4
    "$bin" render "$scene" --width "$width" --spp "$spp" --threads 2 -o "$dir/$name.pfm" "$@" >/dev/null 2>&1 ||
        echo "render failed: $bin $scene $*" >&2
}

jobs=$(mktemp)
"$a" scenes | awk '{print $1}' | while read -r s; do
    echo "$s $s"
    echo "$s-path $s --integrator path"
done >"$jobs"
for f in bunny.toml bunny-sky.toml gltf-bunnies.toml shapes.toml still-life.toml ring.json bunny-field.toml; do
    echo "${f%.*} $root/examples/$f" >>"$jobs"
done
for f in "$root"/examples/materials*.toml; do
    [ -e "$f" ] && echo "$(basename "${f%.*}") $f" >>"$jobs"
done

differ=0
total=0
while read -r name scene rest; do
    # shellcheck disable=SC2086
    [ -e "$out/a/$name.pfm" ] || render "$a" "$out/a" "$name" "$scene" $rest
    # shellcheck disable=SC2086
    render "$b" "$out/b" "$name" "$scene" $rest
    total=$((total + 1))
    if ! cmp -s "$out/a/$name.pfm" "$out/b/$name.pfm"; then
        echo "differs: $name"
        differ=$((differ + 1))
    fi
done <"$jobs"
rm -f "$jobs"
echo "$differ of $total images differ"
[ "$differ" -eq 0 ]
