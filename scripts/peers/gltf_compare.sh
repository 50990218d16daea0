#!/usr/bin/env bash
# Khronos glTF sample models rendered by lumen and by Blender Cycles (bpy,
# Blender's own glTF importer), same camera, sky, film and path length:
# docs/validation-gltf.md.
#
#   scripts/peers/gltf_compare.sh [OUT_DIR]          # default /tmp/gltf-compare
#
# Scenes (lumen scene files; cycles_gltf.py reads the same files):
#   spheres                 gltf_spheres.toml                MetalRoughSpheresNoTextures, white sky
#   helmet                  gltf_helmet.toml                 DamagedHelmet, assets/sky.hdr
#   normals                 gltf_normals.toml                NormalTangentMirrorTest, assets/sky.hdr
#   transmission            gltf_transmission.toml           TransmissionTest, white sky
#   transmission_roughness  gltf_transmission_roughness.toml TransmissionRoughnessTest, white sky
#   slabs                   gltf_slabs.toml                  gltf_make_slabs.py's slabs, white furnace
# For each: NSEEDS lumen renders (seeds 100, 101, ...) and NSEEDS Cycles
# renders (seeds 0, 1, ...) per Cycles variant:
#   import      the materials as Blender's importer makes them (Principled
#               BSDF, Cycles' default multiple-scattering GGX)
#   GGX         the same, every Principled BSDF switched to single-scattering GGX
#   lintex      8-bit sRGB textures decoded to linear floats before rendering
#               (cycles_gltf.py --linear-textures: Cycles then interpolates
#               linear values, as lumen does)
#   GGX-lintex  both
#   GGX-tint2   GGX, and the constant base colour of transmitting materials
#               squared (--tint-per-interface: Cycles tints by its square
#               root at each interface, glTF by the base colour)
# then gltf_analyze.py: per-channel means with standard errors, per-region
# differences, NAME-VARIANT.png (lumen | Cycles | relative difference) and
# NAME-VARIANT.json / .txt (scenes under an image sky: also the means over
# the object's pixels, told from a lumen render of the sky alone); each other
# variant against import (NAME-VARIANT-vs-import.*: what that change alone
# does in Cycles); and gltf_tables.py's tables of all of it, OUT_DIR/report.md.
#
# Environment:
#   SCENES="spheres helmet normals transmission transmission_roughness slabs"
#   SPP=256 NSEEDS=4          samples per pixel, renders per set
#   VARIANTS_<scene>="import ..."   Cycles variants of a scene (defaults below)
#   KHRONOS=/work/khronos     where the sample models lumen does not ship are (DamagedHelmet,
#                             TransmissionTest, TransmissionRoughnessTest, in folders of their
#                             names as in KhronosGroup/glTF-Sample-Assets/Models; the scene files
#                             name /work/khronos); the others are read from assets/khronos
#   LUMEN=...                 lumen binary (default: cargo build --release in the repo)
#   LUMEN_CYCLES_PYTHON       bpy's venv (default: from scripts/peers/setup_cycles.sh --env)
#   THREADS=2                 worker threads of both
#   REUSE=0                   1: keep images already in OUT_DIR
set -euo pipefail

HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../.." && pwd)
OUT=${1:-/tmp/gltf-compare}
SCENES=${SCENES:-spheres helmet normals transmission transmission_roughness slabs}
: "${VARIANTS_spheres:=import GGX}"
: "${VARIANTS_helmet:=import GGX-lintex}"
: "${VARIANTS_normals:=import GGX-lintex}"
: "${VARIANTS_transmission:=import lintex}"
: "${VARIANTS_transmission_roughness:=import GGX GGX-tint2}"
: "${VARIANTS_slabs:=import GGX GGX-tint2}"
SPP=${SPP:-256}
NSEEDS=${NSEEDS:-4}
KHRONOS=${KHRONOS:-/work/khronos}
THREADS=${THREADS:-2}
REUSE=${REUSE:-0}
mkdir -p "$OUT"
log() { echo "gltf_compare.sh: $*" >&2; }

if [[ -z "${LUMEN:-}" ]]; then
    log "building lumen (cargo build --release)"
    (cd "$ROOT" && cargo build --release --quiet)
    LUMEN=${CARGO_TARGET_DIR:-$ROOT/target}/release/lumen
fi
if [[ -z "${LUMEN_CYCLES_PYTHON:-}" ]]; then
    eval "$("$HERE/setup_cycles.sh" --env)"
fi
CPY=$LUMEN_CYCLES_PYTHON

{
    echo "date: $(date -u +%FT%TZ)"
    echo "cpu: $(lscpu | sed -n 's/^Model name: *//p') ($(nproc) cores)"
    echo "lumen: $("$LUMEN" --version 2>&1 | head -1) ($LUMEN)"
    echo "blender: $("$CPY" -c 'import bpy; print(bpy.app.version_string)' 2>/dev/null | tail -1)"
    echo "spp: $SPP, seeds per set: $NSEEDS, threads: $THREADS"
} >"$OUT/versions.txt"
cat "$OUT/versions.txt" >&2

python3 "$HERE/gltf_make_slabs.py" "$OUT/slabs.gltf"

LSEEDS=() CSEEDS=()
for ((i = 0; i < NSEEDS; i++)); do LSEEDS+=($((100 + i))); CSEEDS+=("$i"); done

region_kind() {
    case $1 in
        spheres) echo spheres ;; transmission) echo transmission ;;
        transmission_roughness) echo tiles ;; slabs) echo slabs ;; *) echo grid:8 ;;
    esac
}

for name in $SCENES; do
    src="$HERE/gltf_$name.toml"
    scene="$OUT/scene-$name.toml"
    # absolute paths: the models, the sky, the slabs written above
    sed -e "s#/work/khronos#$KHRONOS#g" -e "s#\"../../assets/#\"$ROOT/assets/#" \
        -e "s#/tmp/gltf-compare/slabs.gltf#$OUT/slabs.gltf#" "$src" >"$scene"
    log "== $name: $SPP spp, $NSEEDS seeds"
    [[ $REUSE == 1 ]] || : >"$OUT/$name-lumen-times.txt"
    for s in "${LSEEDS[@]}"; do
        img="$OUT/$name-lumen-$s.pfm"
        [[ $REUSE == 1 && -s $img ]] && continue
        "$LUMEN" render "$scene" -o "$img" --spp "$SPP" --seed "$s" --threads "$THREADS" \
            --checkpoint-interval 100h >"$OUT/$name-lumen-$s.log" 2>&1
        grep '^time' "$OUT/$name-lumen-$s.log" | sed "s/^/seed $s: /" | tee -a "$OUT/$name-lumen-times.txt" >&2
        rm -f "$img.lumen-ckpt"
    done
    vname="VARIANTS_$name"
    read -r -a variants <<<"${!vname:-import}"
    for v in "${variants[@]}"; do
        first="$OUT/$name-cycles-$v-${CSEEDS[0]}.pfm"
        if [[ $REUSE == 1 && -s $first ]]; then continue; fi
        opts=(--distribution import)
        [[ $v == *GGX* ]] && opts=(--distribution GGX)
        [[ $v == *lintex* ]] && opts+=(--linear-textures)
        [[ $v == *tint2* ]] && opts+=(--tint-per-interface)
        "$CPY" "$HERE/cycles_gltf.py" "$scene" --spp "$SPP" --threads "$THREADS" "${opts[@]}" \
            --seeds "${CSEEDS[@]}" --out-template "$OUT/$name-cycles-$v-{seed}.pfm" \
            >"$OUT/$name-cycles-$v.json" 2>"$OUT/$name-cycles-$v.log"
        "$CPY" -c 'import json,sys; d=json.loads(open(sys.argv[1]).read().splitlines()[-1]); print("cycles", sys.argv[2], "times_s", d["times_s"], "cpu_s", d["cpu_s"])' \
            "$OUT/$name-cycles-$v.json" "$v" >&2
    done
    "$CPY" "$HERE/cycles_gltf.py" "$scene" --dump-materials 2>/dev/null | grep '^{' >"$OUT/$name-cycles-materials.jsonl" || true
    kind=$(region_kind "$name")
    exp=0
    mask=()
    if grep -q '^type = "image"' "$scene"; then
        # the sky alone (the scene up to its first object), to tell object pixels from sky
        sed '/^\[\[objects\]\]/,$d' "$scene" >"$OUT/scene-$name-sky.toml"
        "$LUMEN" render "$OUT/scene-$name-sky.toml" -o "$OUT/$name-sky.pfm" --spp 64 --seed 1 \
            --threads "$THREADS" >/dev/null 2>&1 && mask=(--object-mask "$OUT/$name-sky.pfm")
    fi
    la=() ; for s in "${LSEEDS[@]}"; do la+=("$OUT/$name-lumen-$s.pfm"); done
    cset() { local v=$1 s; for s in "${CSEEDS[@]}"; do echo "$OUT/$name-cycles-$v-$s.pfm"; done; }
    for v in "${variants[@]}"; do
        mapfile -t cb < <(cset "$v")
        python3 "$HERE/gltf_analyze.py" --a "${la[@]}" --b "${cb[@]}" \
            --label-a lumen --label-b "Cycles ($v)" --scene "$scene" --regions "$kind" \
            --png "$OUT/$name-$v.png" --json "$OUT/$name-$v.json" --exposure "$exp" "${mask[@]}" \
            | tee "$OUT/$name-$v.txt" >&2 || true
    done
    for v in "${variants[@]}"; do
        [[ $v == import ]] && continue
        mapfile -t ca < <(cset "$v")
        mapfile -t cb < <(cset import)
        python3 "$HERE/gltf_analyze.py" --a "${ca[@]}" --b "${cb[@]}" \
            --label-a "Cycles $v" --label-b "Cycles import" --scene "$scene" --regions "$kind" \
            --png "$OUT/$name-$v-vs-import.png" --json "$OUT/$name-$v-vs-import.json" "${mask[@]}" \
            | tee "$OUT/$name-$v-vs-import.txt" >&2 || true
    done
done
python3 "$HERE/gltf_tables.py" "$OUT" >"$OUT/report.md"
log "done: $OUT (tables: $OUT/report.md)"
