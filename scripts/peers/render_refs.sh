#!/usr/bin/env bash
# Mitsuba reference renders of lumen's bunny scenes: several seeds each, for
# scripts/peers/compare.py.
#
#   scripts/peers/render_refs.sh [OUT_DIR] [SPP] [SEEDS...]
#
# Defaults: OUT_DIR /work/peer-refs, 256 spp, seeds 0 1 2 3. Meshes are taken
# from $ASSETS (default: assets/ of the repo). Writes
# OUT_DIR/mitsuba-bunny-SPPspp-seedS.exr and OUT_DIR/mitsuba-bunny_235k-SPPspp-seedS.exr
# and a log of the exact commands and timings in OUT_DIR/mitsuba-refs.log.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
out=${1:-/work/peer-refs}
spp=${2:-256}
shift $(( $# > 2 ? 2 : $# ))
seeds=("$@")
[[ ${#seeds[@]} -eq 0 ]] && seeds=(0 1 2 3)
assets=${ASSETS:-$root/assets}
eval "$("$here/setup.sh" --env)"
mkdir -p "$out"
log="$out/mitsuba-refs.log"
for mesh in bunny bunny_235k; do
    for s in "${seeds[@]}"; do
        f="$out/mitsuba-$mesh-${spp}spp-seed$s.exr"
        [[ -e "$f" ]] && { echo "exists: $f"; continue; }
        cmd=("$LUMEN_PEERS_PYTHON" "$here/mitsuba_bunny.py" "$assets/$mesh.glb" --spp "$spp" --seed "$s" --out "$f")
        echo "$(date -Is) load $(cut -d' ' -f1-3 /proc/loadavg): ${cmd[*]}" | tee -a "$log"
        "${cmd[@]}" 2>>"$log" | tee -a "$log"
    done
done
