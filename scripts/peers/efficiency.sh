#!/usr/bin/env bash
# Efficiency (1 / (variance x seconds per render)) of lumen and its peer
# renderers on one scene at one sample count: docs/peers.md, "Efficiency".
#
#   scripts/peers/efficiency.sh bunny|spheres|cornell|materials SPP [CONFIG...]
#
# materials: scripts/peers/materials-scene.toml (gold at two roughnesses, a
# silver mirror, frosted glass, plastic and a diffuse ball on a floor; the
# `materials-320x180` workload of `lumen bench`), Mitsuba's stock BSDFs
# (mitsuba_materials.py).
#
# cornell: `lumen scenes export cornell-box` with its light one-sided, the
# `path` integrator and width CORNELL_WIDTH (mitsuba_cornell.py,
# cycles_cornell.py; docs/peers.md, "Lights").
#
# CONFIG (default: all of them):
#   lumen:SAMPLER[:RR]             lumen with --sampler SAMPLER (zsobol, sobol, independent,
#                                  stratified; plain "lumen" is independent); RR off
#                                  (the default: --integrator bsdf, no Russian
#                                  roulette) or rr5 (--integrator path: roulette
#                                  from the fifth bounce)
#   mitsuba:SAMPLER:RR             SAMPLER independent|multijitter|ldsampler|stratified,
#                                  RR rr5 (Mitsuba's default rr_depth 5) or off
#   cycles:PATTERN:RR[:LT]         PATTERN startup (the bpy startup scene's, Tabulated
#                                  Sobol) or AUTOMATIC (a new scene's default: blue noise)
#                                  or another Cycles sampling_pattern; RR on (default) or off;
#                                  LT (cornell only) light tree on (default) or off
#
# Each configuration renders the scene once to warm up (JIT compilation, scene
# upload), then once per seed (SEEDS, default "1 2"), timing each render
# alone (scene loading excluded), and prints one line:
#   renderer sampler rr scene spp s/render variance efficiency cpu-s eff/cpu-s load0 load1 busy0 other
# (load0/load1: 1-minute load average at the start and end; busy0: cores busy
# over the 3 s before the start; other: cores used by other processes during
# the configuration; see below)
# where variance = mean over pixels and channels of (A - B)^2 / 2 of the two
# seeds' images (linear RGB) and s/render the mean of the two timed renders;
# cpu-s is the renderer's CPU time per render (all threads) and eff/cpu-s =
# 1 / (variance x cpu-s), which depends much less on other work sharing the
# machine than the wall time does.
#
# Environment:
#   OUT=/tmp/lumen-peers-eff   images and results.jsonl
#   SEEDS="1 2"                the two seeds
#   MESH=assets/bunny_235k.glb the bunny mesh (bunny scene)
#   LUMEN=target/dist/lumen the lumen binary
#   THREADS=2                  worker threads of every renderer
#   CORNELL_WIDTH=300          image width of the cornell scene
#   MAX_LOAD=1.5 WAIT=600      wait up to WAIT s before each configuration for the
#   BUSY_MAX=0.3               1-minute load average to fall below MAX_LOAD (or, as
#                              it decays slowly after the previous measurement, for
#                              fewer than BUSY_MAX cores busy over 3 s with the load
#                              average below MAX_LOAD + 1); a line whose start saw
#                              other work (busy >= BUSY_MAX)
#   OTHER_MAX=0.15 RETRIES=2   "other": cores used by other processes during the
#                              configuration (machine CPU time from /proc/stat minus
#                              this script's children's); a configuration with
#                              other > OTHER_MAX or busy0 >= BUSY_MAX is measured
#                              again (up to RETRIES times), else marked "loaded"
# Needs scripts/peers/setup.sh (Mitsuba) and scripts/peers/setup_cycles.sh (Cycles);
# they are run here if their venvs are missing.
set -euo pipefail

HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../.." && pwd)
SCENE=${1:?usage: efficiency.sh bunny|spheres|cornell|materials SPP [CONFIG...]}
SPP=${2:?usage: efficiency.sh bunny|spheres|cornell|materials SPP [CONFIG...]}
shift 2
CONFIGS=("$@")
if [[ ${#CONFIGS[@]} -eq 0 && $SCENE == materials ]]; then
    CONFIGS=(lumen:sobol:rr5 lumen:independent:rr5
             mitsuba:independent:rr5 mitsuba:multijitter:rr5 mitsuba:ldsampler:rr5 mitsuba:stratified:rr5)
elif [[ ${#CONFIGS[@]} -eq 0 && $SCENE == cornell ]]; then
    CONFIGS=(lumen:sobol:rr5 mitsuba:multijitter:rr5 cycles:startup:on cycles:AUTOMATIC:on
             cycles:SOBOL_BURLEY:on cycles:startup:on:off)
elif [[ ${#CONFIGS[@]} -eq 0 ]]; then
    CONFIGS=(lumen:independent lumen:sobol
             mitsuba:independent:rr5 mitsuba:multijitter:rr5 mitsuba:ldsampler:rr5
             mitsuba:independent:off mitsuba:multijitter:off mitsuba:ldsampler:off
             cycles:startup:on cycles:AUTOMATIC:on cycles:startup:off cycles:AUTOMATIC:off)
fi
OUT=${OUT:-/tmp/lumen-peers-eff}
read -r SEED_A SEED_B <<<"${SEEDS:-1 2}"
MESH=${MESH:-$ROOT/assets/bunny_235k.glb}
MESH=$(cd "$(dirname "$MESH")" && pwd)/$(basename "$MESH")
LUMEN=${LUMEN:-$ROOT/target/dist/lumen}
MAX_LOAD=${MAX_LOAD:-1.5}
BUSY_MAX=${BUSY_MAX:-0.3}
OTHER_MAX=${OTHER_MAX:-0.15}
RETRIES=${RETRIES:-2}
WAIT=${WAIT:-600}
THREADS=${THREADS:-2}
CORNELL_WIDTH=${CORNELL_WIDTH:-300}
mkdir -p "$OUT"

case $SCENE in bunny|spheres|cornell|materials) ;; *) echo "efficiency.sh: scene must be bunny, spheres, cornell or materials" >&2; exit 2 ;; esac

need_mitsuba=0; need_cycles=0
for c in "${CONFIGS[@]}"; do
    case $c in mitsuba:*) need_mitsuba=1 ;; cycles:*) need_cycles=1 ;; esac
done
if [[ $need_mitsuba == 1 ]]; then
    eval "$("$HERE/setup.sh" --env 2>/dev/null || "$HERE/setup.sh")"
fi
if [[ $need_cycles == 1 ]]; then
    eval "$("$HERE/setup_cycles.sh" --env 2>/dev/null || "$HERE/setup_cycles.sh")"
fi
# A Python with numpy for efficiency.py: a peer venv, else python3.
PY=${LUMEN_PEERS_PYTHON:-${LUMEN_CYCLES_PYTHON:-}}
if [[ -z "$PY" ]]; then
    PY=$("$HERE/setup.sh" --env 2>/dev/null | sed -n 's/^export LUMEN_PEERS_PYTHON=//p' || true)
    [[ -n "$PY" ]] || PY=$("$HERE/setup_cycles.sh" --env 2>/dev/null | sed -n 's/^export LUMEN_CYCLES_PYTHON=//p' || true)
    [[ -n "$PY" ]] || PY=python3
fi

# The lumen scene: for the bunny, bunny-scene.toml with MESH's absolute path.
if [[ $SCENE == bunny ]]; then
    LUMEN_SCENE=$OUT/bunny-scene-$(basename "$MESH" .glb).toml
    sed "s|^file = .*|file = \"$MESH\"|" "$HERE/bunny-scene.toml" >"$LUMEN_SCENE"
elif [[ $SCENE == cornell ]]; then
    LUMEN_SCENE=$OUT/cornell-scene-$CORNELL_WIDTH.toml
    "$LUMEN" scenes export cornell-box -o "$OUT/cornell-export.toml" >/dev/null
    sed 's/two_sided = true/two_sided = false/; s/integrator = "bsdf"/integrator = "path"/;'" s/^width = .*/width = $CORNELL_WIDTH/" \
        "$OUT/cornell-export.toml" >"$LUMEN_SCENE"
    rm -f "$OUT/cornell-export.toml"
elif [[ $SCENE == materials ]]; then
    LUMEN_SCENE=$HERE/materials-scene.toml
else
    LUMEN_SCENE=$HERE/spheres-scene.toml
fi

load1() { cut -d' ' -f1 /proc/loadavg; }
below() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a < b) }'; }
# Cores busy right now: CPU time of all processes over 3 s (/proc/stat), in cores.
busy_cores() {
    local a b
    a=$(awk '/^cpu /{print $2+$3+$4+$7+$8, $2+$3+$4+$5+$6+$7+$8}' /proc/stat)
    sleep 3
    b=$(awk '/^cpu /{print $2+$3+$4+$7+$8, $2+$3+$4+$5+$6+$7+$8}' /proc/stat)
    awk -v a="$a" -v b="$b" -v n="$(nproc)" 'BEGIN { split(a, x, " "); split(b, y, " ");
        d = y[2] - x[2]; printf "%.2f", (d > 0 ? n * (y[1] - x[1]) / d : 0) }'
}
# Wait (up to WAIT s) until the machine is idle: nothing else running now
# (under BUSY_MAX cores busy over 3 s) and the 1-minute load average below
# MAX_LOAD + 1 (it still carries the previous measurement's own two busy cores
# for a minute, so MAX_LOAD alone would cost a minute's wait each time).
wait_for_low_load() {
    local t=0
    while [[ $t -lt $WAIT ]]; do
        BUSY=$(busy_cores)
        below "$BUSY" "$BUSY_MAX" && below "$(load1)" "$(awk -v m="$MAX_LOAD" 'BEGIN{print m + 1}')" && return 0
        sleep 5; t=$((t + 8))
    done
}

# CPU-seconds used by the whole machine so far (/proc/stat) and by this
# script's finished children (bash `times`).
machine_cpu_s() { awk -v hz="$(getconf CLK_TCK)" '/^cpu /{printf "%.2f", ($2+$3+$4+$7+$8) / hz}' /proc/stat; }
# (`times` must run in this shell, not in a $(...) subshell: it writes to a file.)
children_cpu_s() {
    times >"$OUT/.times"
    tail -n1 "$OUT/.times" | awk '{ t = 0; for (i = 1; i <= 2; i++) { split($i, p, "m"); sub("s", "", p[2]); t += p[1] * 60 + p[2] } printf "%.2f", t }'
}

# Runs one configuration; sets SECS_A SECS_B (wall), CPU_A CPU_B (CPU seconds
# of the renderer process, all threads), IMG_A IMG_B.
run_config() {
    local c=$1 tag=$2 log="$OUT/$2.log"
    IMG_A="$OUT/$tag-s$SEED_A.pfm"; IMG_B="$OUT/$tag-s$SEED_B.pfm"
    local tmpl="$OUT/$tag-s{seed}.pfm" r s rr
    local lt
    IFS=: read -r r s rr lt <<<"$c"
    case $r in
    lumen)
        # lumen's own "time" line: the render passes, without scene loading;
        # CPU seconds: the whole process (scene loading included, so a bound).
        local times=() cpus=() c0 integrator=bsdf
        rr=${rr:-off}
        [ "$rr" = rr5 ] && integrator=path
        "$LUMEN" render "$LUMEN_SCENE" -o "$OUT/$tag-warmup.pfm" --spp "$SPP" --seed "$SEED_A" \
            --sampler "${s:-independent}" --integrator "$integrator" --checkpoint-interval 100h \
            --threads "$THREADS" >"$log" 2>&1
        for seed in "$SEED_A" "$SEED_B"; do
            children_cpu_s >"$OUT/.c"; c0=$(cat "$OUT/.c")
            "$LUMEN" render "$LUMEN_SCENE" -o "$OUT/$tag-s$seed.pfm" --spp "$SPP" --seed "$seed" \
                --sampler "${s:-independent}" --integrator "$integrator" --checkpoint-interval 100h \
                --threads "$THREADS" >>"$log" 2>&1
            children_cpu_s >"$OUT/.c"
            cpus+=("$(awk -v a="$c0" -v b="$(cat "$OUT/.c")" 'BEGIN { printf "%.2f", b - a }')")
            times+=("$(grep -o '^time [0-9.]* s' "$log" | tail -n1 | awk '{print $2}')")
        done
        rm -f "$OUT/$tag-warmup.pfm"
        SECS_A=${times[0]}; SECS_B=${times[1]}; CPU_A=${cpus[0]}; CPU_B=${cpus[1]}
        ;;
    mitsuba)
        local rrarg=off; [[ $rr == rr5 ]] && rrarg=5
        if [[ $SCENE == bunny ]]; then
            "$LUMEN_PEERS_PYTHON" "$HERE/mitsuba_bunny.py" "$MESH" --spp "$SPP" --sampler "$s" \
                --rr-depth "$rrarg" --seeds "$SEED_A" "$SEED_B" --out-template "$tmpl" \
                --threads "$THREADS" >"$log" 2>&1
        elif [[ $SCENE == materials ]]; then
            "$LUMEN_PEERS_PYTHON" "$HERE/mitsuba_materials.py" "$LUMEN_SCENE" --spp "$SPP" --sampler "$s" \
                --rr-depth "$rrarg" --seeds "$SEED_A" "$SEED_B" --out-template "$tmpl" \
                --threads "$THREADS" >"$log" 2>&1
        elif [[ $SCENE == cornell ]]; then
            "$LUMEN_PEERS_PYTHON" "$HERE/mitsuba_cornell.py" "$LUMEN_SCENE" --spp "$SPP" --sampler "$s" \
                --rr-depth "$rrarg" --timed --seeds "$SEED_A" "$SEED_B" --out-template "$tmpl" \
                --threads "$THREADS" >"$log" 2>&1
        else
            "$LUMEN_PEERS_PYTHON" "$HERE/mitsuba_spheres.py" "$HERE/spheres-scene.toml" --spp "$SPP" \
                --sampler "$s" --rr-depth "$rrarg" --seeds "$SEED_A" "$SEED_B" --out-template "$tmpl" \
                --threads "$THREADS" >"$log" 2>&1
        fi
        read -r SECS_A SECS_B CPU_A CPU_B < <(tail -n1 "$log" | "$PY" -c 'import json,sys; d=json.load(sys.stdin); print(*d["times_s"], *d["cpu_s"])')
        ;;
    cycles)
        local script=cycles_spheres.py arg=$HERE/spheres-scene.toml extra=()
        [[ $SCENE == bunny ]] && { script=cycles_bunny.py; arg=$MESH; }
        [[ $SCENE == cornell ]] && { script=cycles_cornell.py; arg=$LUMEN_SCENE; extra=(--timed); }
        [[ -n $lt ]] && extra+=(--light-tree "$lt")
        "$LUMEN_CYCLES_PYTHON" "$HERE/$script" "$arg" --spp "$SPP" --pattern "$s" --rr "$rr" \
            --threads "$THREADS" --seeds "$SEED_A" "$SEED_B" --out-template "$tmpl" "${extra[@]}" >"$log" 2>&1
        read -r SECS_A SECS_B CPU_A CPU_B < <(grep '^{' "$log" | tail -n1 | "$PY" -c 'import json,sys; d=json.load(sys.stdin); print(*d["times_s"], *d["cpu_s"])')
        ;;
    *) echo "efficiency.sh: unknown configuration $c" >&2; return 2 ;;
    esac
}

printf '%-8s %-15s %-4s %-8s %5s %9s %12s %11s %8s %9s %6s %6s %5s %5s\n' \
    renderer sampler rr scene spp s/render variance efficiency cpu-s eff/cpu-s load0 load1 busy0 other
for c in "${CONFIGS[@]}"; do
    IFS=: read -r r s rr lt <<<"$c"
    [[ $r == lumen ]] && { s=${s:-independent}; rr=${rr:-off}; }
    tag="$SCENE-$SPP-$r-$s-$rr${lt:+-lt$lt}"
    [[ -n $lt ]] && s="$s:lt-$lt"
    for try in $(seq 0 "$RETRIES"); do
        wait_for_low_load
        LOAD_START=$(load1)
        m0=$(machine_cpu_s); children_cpu_s >"$OUT/.c"; c0=$(cat "$OUT/.c"); t0=$(date +%s.%N)
        run_config "$c" "$tag" || { echo "efficiency.sh: $c failed, see $OUT/$tag.log" >&2; continue 2; }
        m1=$(machine_cpu_s); children_cpu_s >"$OUT/.c"; c1=$(cat "$OUT/.c"); t1=$(date +%s.%N)
        LOAD_END=$(load1)
        # cores used by other processes during this configuration (warm-up included)
        OTHER=$(awk -v m0="$m0" -v m1="$m1" -v c0="$c0" -v c1="$c1" -v t0="$t0" -v t1="$t1" \
            'BEGIN { o = ((m1 - m0) - (c1 - c0)) / (t1 - t0); printf "%.2f", (o < 0 ? 0 : o) }')
        mark=""
        below "$BUSY" "$BUSY_MAX" && below "$OTHER" "$OTHER_MAX" || mark=" loaded"
        [[ -z $mark || $try -ge $RETRIES ]] && break
        echo "efficiency.sh: $c: other work ran (busy0 $BUSY, other $OTHER cores): measuring again" >&2
    done
    J=$("$PY" "$HERE/efficiency.py" "$IMG_A" "$IMG_B" --seconds "$SECS_A" --seconds "$SECS_B" --json \
        --label "$c")
    read -r SECS VAR EFF < <(echo "$J" | "$PY" -c 'import json,sys; d=json.load(sys.stdin); print(d["seconds"], d["variance"], d["efficiency"])')
    CPU=$(awk -v a="$CPU_A" -v b="$CPU_B" 'BEGIN { printf "%.3f", (a + b) / 2 }')
    EFFCPU=$(awk -v v="$VAR" -v c="$CPU" 'BEGIN { printf "%.5g", 1 / (v * c) }')
    printf '%-8s %-15s %-4s %-8s %5s %9.3f %12.5g %11.5g %8s %9s %6s %6s %5s %5s%s\n' \
        "$r" "$s" "$rr" "$SCENE" "$SPP" "$SECS" "$VAR" "$EFF" "$CPU" "$EFFCPU" "$LOAD_START" "$LOAD_END" "$BUSY" "$OTHER" "$mark"
    echo "$J" | "$PY" -c 'import json,sys; d=json.load(sys.stdin); d.update(zip(("renderer","sampler","rr","scene","spp","times_s","cpu_s","load_start","load_end","busy_cores_start","other_cores","host_cores"), sys.argv[1:])); print(json.dumps(d))' \
        "$r" "$s" "$rr" "$SCENE" "$SPP" "$SECS_A $SECS_B" "$CPU_A $CPU_B" "$LOAD_START" "$LOAD_END" "$BUSY" "$OTHER" "$(nproc)" >>"$OUT/results.jsonl"
done
