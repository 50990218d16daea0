#!/bin/sh
# Renders the bench's bunny scene with lumen at several seeds and compares
# the images with Mitsuba 3's (made by render_refs.sh) pixel by pixel:
# compare.py says whether the difference is what the two sets' noise explains.
#
# usage: scripts/peers/compare_lumen.sh REFS_DIR [SPP] [SEEDS...]
#   REFS_DIR holds mitsuba-bunny-SPPspp-seed{0..3}.exr (render_refs.sh);
#   lumen's images go to REFS_DIR/lumen/. Seeds default to 10 11 12 13, so
#   that no seed is shared with Mitsuba's set (shared noise would hide a bias).
set -eu
cd "$(dirname "$0")/../.."
refs=$1
spp=${2:-256}
shift $(($# < 2 ? $# : 2))
seeds=${*:-10 11 12 13}
mkdir -p "$refs/lumen"
cargo build --profile dist --quiet
b=""
for s in $seeds; do
    out="$refs/lumen/bunny-${spp}spp-seed$s.pfm"
    ./target/dist/lumen render scripts/peers/bunny-scene.toml -o "$out" --spp "$spp" --seed "$s"
    b="$b $out"
done
eval "$(scripts/peers/setup.sh --env)"
# shellcheck disable=SC2086
"$LUMEN_PEERS_PYTHON" scripts/peers/compare.py --a "$refs"/mitsuba-bunny-"$spp"spp-seed[0-3].exr --b $b
