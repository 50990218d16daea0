#!/usr/bin/env bash
# Checks compare.py on Mitsuba-only renders of the small bunny scene:
# two independent sets (different seeds) must agree, and a set with the
# floor's reflectance at 0.52 instead of 0.5 must be told apart.
#
#   scripts/peers/selftest_compare.sh [WORK_DIR] [SPP]     (defaults: a temp dir, 64)
#
# Needs the mesh at $ASSETS/bunny.glb (default: assets/ of the repo).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
dir=${1:-$(mktemp -d)}
spp=${2:-64}
assets=${ASSETS:-$root/assets}
eval "$("$here/setup.sh" --env)"
mkdir -p "$dir"
render() {  # NAME FLOOR SEED...
    local name=$1 floor=$2; shift 2
    for s in "$@"; do
        f="$dir/$name-seed$s.exr"
        [[ -e "$f" ]] || "$LUMEN_PEERS_PYTHON" "$here/mitsuba_bunny.py" "$assets/bunny.glb" \
            --spp "$spp" --seed "$s" --floor-albedo "$floor" --out "$f" >/dev/null
    done
}
render a 0.5 100 101 102 103
render b 0.5 200 201 202 203
render floor052 0.52 300 301 302 303
status=0
echo "== two independent sets of the same scene (must agree)"
if "$LUMEN_PEERS_PYTHON" "$here/compare.py" --a "$dir"/a-seed*.exr --b "$dir"/b-seed*.exr | grep -v '^{'; then
    echo "ok: agree"
else
    echo "FAILED: the sets should agree"; status=1
fi
echo "== floor reflectance 0.52 against 0.5 (must disagree)"
if "$LUMEN_PEERS_PYTHON" "$here/compare.py" --a "$dir"/a-seed*.exr --b "$dir"/floor052-seed*.exr | grep -v '^{'; then
    echo "FAILED: the 4% floor bias was not detected"; status=1
else
    [[ ${PIPESTATUS[0]} -eq 1 ]] && echo "ok: disagree" || { echo "FAILED: compare.py error"; status=1; }
fi
exit $status
