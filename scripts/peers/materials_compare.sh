#!/usr/bin/env bash
# lumen's conductor, rough-dielectric and plastic materials against Mitsuba 3
# on scripts/peers/materials-scene.toml (gold GGX roughness 0.2 and 0.5, a
# smooth silver mirror, frosted glass ior 1.5 roughness 0.3, red plastic
# under a GGX coat of roughness 0.3, a diffuse control ball, a grey floor, a
# white sky): docs/validation-materials.md.
#
#   scripts/peers/materials_compare.sh [OUT_DIR]        # default /tmp/lumen-materials
#
# First the point checks (no rendering):
#   - Mitsuba's RGB eta/k of Au and Ag against lumen's table (metals.rs);
#   - Mitsuba's roughconductor / roughdielectric / roughplastic, stock and
#     wrapped (hcsmith / hcplastic), against float64 reference formulas at
#     random direction pairs, and lumen's own lobes at the same directions
#     (scripts/peers/materials_probe.rs, built against $LUMEN_SRC);
#   - the plastic's coat (materials_coat.py): T(mu) and Ri by each recipe;
#   - a diagnosis (materials_probe trace): each sphere's pixels by lumen's
#     own loop as it is and with every sampled direction made unit length.
# Then it renders the scene NSEEDS times with lumen (seeds 100, 101, ...) and
# NSEEDS times with Mitsuba 3 in each of two shadowing models (seeds 0, 1, ...):
#   separable   Mitsuba's own roughconductor / roughdielectric / roughplastic
#               (Smith G = G1 G1)
#   correlated  the same BSDFs wrapped in mitsuba_materials.py's `hcsmith`
#               (height-correlated Smith G = 1 / (1 + Lambda_i + Lambda_o),
#               lumen's) and, for the plastic, `hcplastic` (also the coat's
#               T and Ri of the height-correlated interface, Ri integrated
#               exactly)
#   lumencoat   correlated, but the plastic's coat T(mu) and Ri are the ones
#               lumen's tables give (materials_coat.lumen_coat): Mitsuba
#               rendering lumen's model exactly, tabulation included
# all at the scene's resolution, SPP samples per pixel and max_depth, both
# renderers with their independent samplers and Russian roulette from the
# fifth bounce. Then, for each Mitsuba mode against lumen:
#   - per-channel means of the whole image and of each object's region
#     (pixels whose 4 x 4 sub-pixel rays all hit the same object, from
#     materials_regions.py), the difference in standard errors (Welch's t over
#     the per-seed means, and the equivalent normal score z);
#   - per pixel: Welch's z of the two sets' means, the fraction of pixel
#     values within 3 (expected 99.73% if the two renderers have the same
#     expected image), RMS z (expected 1), per region and overall;
#   - compare.py's verdict (image mean, pixels and 8 x 8 blocks);
# and the Mitsuba modes against each other, paired (they share their seeds and
# so most of their paths: the difference of each seed's images is the model
# change's effect with most of the noise cancelled).
#
# Environment:
#   SCENE=scripts/peers/materials-scene.toml   the scene
#   SPP=512 NSEEDS=8                           samples per pixel, renders per set
#   LSEED0=100 MSEED0=0                        first seed of lumen's, Mitsuba's renders
#   LUMEN=...                                  lumen binary (default: cargo build --release,
#                                              $CARGO_TARGET_DIR/release/lumen)
#   LUMEN_SRC=<repo root>                      lumen's source, for the probe and the metals table
#   PROBE=...                                  materials_probe binary (default: built in
#                                              $PROBE_TARGET, default /tmp/lumen-probe-target);
#                                              PROBE=off skips lumen's point checks
#   LUMEN_PEERS_PYTHON, DRJIT_LIBLLVM_PATH     Mitsuba's venv (default: from
#                                              scripts/peers/setup.sh --env)
#   VARIANT=llvm_ad_rgb                        Mitsuba variant (scalar_rgb works, slowly)
#   THREADS=0                                  worker threads of both (0: all cores)
#   MODES="separable correlated lumencoat"     which Mitsuba modes to render
#   REUSE=0                                    1: keep images already in OUT_DIR
# Writes OUT_DIR/{lumen,mitsuba-separable,mitsuba-correlated}-SEED.pfm, the
# renderers' logs, zmap-MODE.pfm (|z| per pixel, max over channels),
# checks.txt, check-bsdfs.json, coat.txt, trace.txt, report.json and report.md (the
# tables of docs/validation-materials.md), env.txt (machine, versions,
# commands, times).
set -euo pipefail

HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../.." && pwd)
LUMEN_SRC=${LUMEN_SRC:-$ROOT}
OUT=${1:-/tmp/lumen-materials}
SCENE=${SCENE:-$HERE/materials-scene.toml}
SPP=${SPP:-512}
NSEEDS=${NSEEDS:-8}
LSEED0=${LSEED0:-100}
MSEED0=${MSEED0:-0}
VARIANT=${VARIANT:-llvm_ad_rgb}
THREADS=${THREADS:-0}
MODES=${MODES:-separable correlated lumencoat}
REUSE=${REUSE:-0}
mkdir -p "$OUT"
log() { echo "materials_compare.sh: $*" >&2; }

if [[ -z "${LUMEN:-}" ]]; then
    log "building lumen (cargo build --release)"
    (cd "$LUMEN_SRC" && cargo build --release --quiet)
    LUMEN=${CARGO_TARGET_DIR:-$LUMEN_SRC/target}/release/lumen
fi
if [[ -z "${LUMEN_PEERS_PYTHON:-}" ]]; then
    eval "$("$HERE/setup.sh" --env)"
fi
PY=$LUMEN_PEERS_PYTHON

LSEEDS=() MSEEDS=()
for ((i = 0; i < NSEEDS; i++)); do LSEEDS+=($((LSEED0 + i))); MSEEDS+=($((MSEED0 + i))); done
read -r DEPTH < <("$PY" -c 'import sys, tomllib; print(tomllib.load(open(sys.argv[1], "rb")).get("render", {}).get("max_depth", 50))' "$SCENE")
log "scene $SCENE, $SPP spp, max_depth $DEPTH, $NSEEDS seeds a set, out $OUT"
"$LUMEN" --version >"$OUT/lumen-version.txt" 2>&1 || true
T_START=$(date +%s)
{
    echo "date: $(date -u +%Y-%m-%dT%H:%M:%SZ)"
    echo "cpu: $(lscpu | sed -n 's/^Model name: *//p' | head -n1), $(nproc) logical CPUs"
    echo "loadavg at start: $(cut -d' ' -f1-3 /proc/loadavg)"
    echo "lumen: $LUMEN ($(cat "$OUT/lumen-version.txt")), source $LUMEN_SRC at" \
        "$(git -C "$LUMEN_SRC" rev-parse --short HEAD 2>/dev/null || echo '?')" \
        "($(git -C "$LUMEN_SRC" status --short -- src 2>/dev/null | wc -l) files changed under src/)"
    echo "rustc: $(rustc --version 2>/dev/null || echo '?')"
    echo "mitsuba: $("$PY" -c 'import mitsuba as mi, drjit as dr; print(mi.__version__, "drjit", dr.__version__)'), variant $VARIANT"
    echo "python: $("$PY" -c 'import sys, numpy; print(sys.version.split()[0], "numpy", numpy.__version__)')"
    echo "scene: $SCENE (sha256 $(sha256sum "$SCENE" | cut -c1-16)), $SPP spp, max_depth $DEPTH," \
        "seeds lumen ${LSEEDS[*]}, mitsuba ${MSEEDS[*]}"
} >"$OUT/env.txt"

# --- point checks ----------------------------------------------------------
t0=$(date +%s)
{
    echo "## Mitsuba's eta/k against lumen's metals.rs"
    "$PY" "$HERE/mitsuba_materials.py" --variant "$VARIANT" --check-metals "$LUMEN_SRC/src/material/metals.rs"
} >"$OUT/checks.txt" 2>&1 || { cat "$OUT/checks.txt" >&2; log "metals differ"; exit 1; }
PROBE=${PROBE:-}
if [[ -z $PROBE ]]; then
    PROBE_TARGET=${PROBE_TARGET:-/tmp/lumen-probe-target}
    pdir=$(mktemp -d /tmp/lumen-probe.XXXXXX)
    printf '%s\n' '[package]' 'name = "materials_probe"' 'version = "0.0.0"' 'edition = "2021"' '' \
        '[[bin]]' 'name = "materials_probe"' "path = \"$HERE/materials_probe.rs\"" '' \
        '[dependencies]' "lumen = { path = \"$LUMEN_SRC\" }" '' '[workspace]' >"$pdir/Cargo.toml"
    cp "$LUMEN_SRC/Cargo.lock" "$pdir/" 2>/dev/null || true
    log "building materials_probe against $LUMEN_SRC (target $PROBE_TARGET)"
    (cd "$pdir" && CARGO_TARGET_DIR=$PROBE_TARGET cargo build --release --quiet) \
        || { log "materials_probe did not build"; exit 1; }
    PROBE=$PROBE_TARGET/release/materials_probe
    rm -rf "$pdir"
fi
probe=()
[[ $PROBE != off ]] && probe=(--probe "$PROBE")
set +e
{
    echo
    echo "## Rough BSDFs at random direction pairs (Mitsuba, wrappers, lumen)"
    "$PY" "$HERE/mitsuba_materials.py" --variant "$VARIANT" --check-bsdfs "${probe[@]}" \
        --json "$OUT/check-bsdfs.json"
} >>"$OUT/checks.txt" 2>&1
rc=$?
set -e
"$PY" "$HERE/materials_coat.py" >"$OUT/coat.txt" 2>&1
cat "$OUT/checks.txt" "$OUT/coat.txt" >&2
[[ $rc == 0 ]] || { log "point checks FAILED (see $OUT/checks.txt)"; exit 1; }
log "point checks: $(($(date +%s) - t0)) s"
echo "point checks: $(($(date +%s) - t0)) s (probe $PROBE)" >>"$OUT/env.txt"

# --- diagnosis: lumen's own loop with and without unit directions ----------
# (materials_probe trace: each sphere's pixels by lumen's scene, camera,
# BSDFs and ray spawning, BSDF sampling only; `normalize` makes each sampled
# direction unit length before the ray leaves, which lumen does not do)
if [[ $PROBE != off ]]; then
    t0=$(date +%s)
    : >"$OUT/trace.txt"
    for i in $("$PY" -c 'import sys, tomllib
for i, o in enumerate(tomllib.load(open(sys.argv[1], "rb"))["objects"]):
    if o["type"] == "sphere": print(i)' "$SCENE"); do
        for how in asis normalize; do
            "$PROBE" trace "$SCENE" "$i" "${TRACE_SPP:-1024}" $how >>"$OUT/trace.txt"
        done
    done
    cat "$OUT/trace.txt" >&2
    echo "trace diagnosis: $(($(date +%s) - t0)) s" >>"$OUT/env.txt"
fi

# --- lumen ---------------------------------------------------------------
t0=$(date +%s)
threads=()
[[ $THREADS != 0 ]] && threads=(--threads "$THREADS")
for s in "${LSEEDS[@]}"; do
    img="$OUT/lumen-$s.pfm"
    [[ $REUSE == 1 && -s $img ]] && continue
    "$LUMEN" render "$SCENE" -o "$img" --spp "$SPP" --depth "$DEPTH" --seed "$s" \
        --sampler independent --integrator path --checkpoint-interval 100h "${threads[@]}" \
        >"$OUT/lumen-$s.log" 2>&1 || { cat "$OUT/lumen-$s.log" >&2; exit 1; }
    log "lumen seed $s: $(grep -E '^time ' "$OUT/lumen-$s.log" || tail -n1 "$OUT/lumen-$s.log")"
done
log "lumen: $(($(date +%s) - t0)) s"
{
    echo "lumen renders: $(($(date +%s) - t0)) s wall for ${#LSEEDS[@]} renders; lumen's own time line per render (s):" \
        "$(for s in "${LSEEDS[@]}"; do grep -ohE '^time [0-9.]+ s' "$OUT/lumen-$s.log" | cut -d' ' -f2; done | tr '\n' ' ')"
    echo "lumen command: $LUMEN render $SCENE -o OUT/lumen-SEED.pfm --spp $SPP --depth $DEPTH --seed SEED" \
        "--sampler independent --integrator path --checkpoint-interval 100h ${threads[*]}"
} >>"$OUT/env.txt"

# --- Mitsuba -------------------------------------------------------------
for mode in $MODES; do
    t0=$(date +%s)
    have=1
    for s in "${MSEEDS[@]}"; do [[ -s "$OUT/mitsuba-$mode-$s.pfm" ]] || have=0; done
    if [[ $REUSE == 1 && $have == 1 ]]; then
        echo "mitsuba $mode renders: reused; $(tail -n1 "$OUT/mitsuba-$mode.json" 2>/dev/null)" >>"$OUT/env.txt"
        continue
    fi
    "$PY" "$HERE/mitsuba_materials.py" "$SCENE" --spp "$SPP" --max-depth "$DEPTH" --smith "$mode" \
        --variant "$VARIANT" --threads "$THREADS" --seeds "${MSEEDS[@]}" \
        --out-template "$OUT/mitsuba-$mode-{seed}.pfm" >"$OUT/mitsuba-$mode.json" 2>"$OUT/mitsuba-$mode.log" \
        || { cat "$OUT/mitsuba-$mode.log" >&2; exit 1; }
    log "mitsuba $mode: $(($(date +%s) - t0)) s ($(tail -n1 "$OUT/mitsuba-$mode.json" | cut -c1-160)...)"
    {
        echo "mitsuba $mode renders: $(($(date +%s) - t0)) s wall (with start-up and one warm-up render): $(tail -n1 "$OUT/mitsuba-$mode.json")"
        echo "mitsuba $mode command: $PY $HERE/mitsuba_materials.py $SCENE --spp $SPP --max-depth $DEPTH" \
            "--smith $mode --variant $VARIANT --threads $THREADS --seeds ${MSEEDS[*]} --out-template OUT/mitsuba-$mode-{seed}.pfm"
    } >>"$OUT/env.txt"
done

# --- compare.py: image, pixels, 8 x 8 blocks -------------------------------
for mode in $MODES; do
    a=() b=()
    for s in "${LSEEDS[@]}"; do a+=("$OUT/lumen-$s.pfm"); done
    for s in "${MSEEDS[@]}"; do b+=("$OUT/mitsuba-$mode-$s.pfm"); done
    "$PY" "$HERE/compare.py" --a "${a[@]}" --b "${b[@]}" --z-map "$OUT/zmap-$mode.pfm" \
        >"$OUT/compare-$mode.txt" || true
    log "compare.py lumen vs mitsuba $mode: $(grep -E '^(AGREE|DISAGREE)' "$OUT/compare-$mode.txt")"
done

# --- per-region and per-pixel tables ---------------------------------------
PEERS_DIR=$HERE "$PY" - "$SCENE" "$OUT" "$SPP" "$DEPTH" "${LSEEDS[*]}" "${MSEEDS[*]}" "$MODES" <<'PYEOF'
import json, math, os, sys, tomllib
from pathlib import Path
from statistics import NormalDist

import numpy as np

sys.path.insert(0, os.environ["PEERS_DIR"])
import peerlib  # noqa: E402
from compare import read_image, welch, t_to_z  # noqa: E402
from materials_regions import region_ids  # noqa: E402

scene_path, out, spp, depth, lseeds, mseeds, modes = sys.argv[1:8]
out = Path(out)
lseeds, mseeds, modes = lseeds.split(), mseeds.split(), modes.split()
scene = peerlib.fill_defaults(tomllib.loads(Path(scene_path).read_text()))
ids = region_ids(scene)
np.save(out / "regions.npy", ids)
L = np.stack([read_image(str(out / f"lumen-{s}.pfm")) for s in lseeds])
M = {m: np.stack([read_image(str(out / f"mitsuba-{m}-{s}.pfm")) for s in mseeds]) for m in modes}
for k, a in [("lumen", L), *M.items()]:
    if not np.isfinite(a).all():
        sys.exit(f"{k}: non-finite pixel values")

regions = [("image", np.ones(ids.shape, bool))]
for i, o in enumerate(scene["objects"]):
    if (ids == i).any():
        regions.append((o["material"], ids == i))
regions.append(("sky", ids == -1))
regions.append(("edges", ids == -2))
# edge pixels next to (3 x 3) a dielectric's region, and the others: glass
# is where lumen's rays leave the unit length (docs/validation-materials.md)
glass = np.zeros(ids.shape, bool)
for i, o in enumerate(scene["objects"]):
    if scene["materials"][o["material"]]["type"] == "dielectric":
        glass |= ids == i
if glass.any():
    near = np.zeros_like(glass)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            near |= np.roll(np.roll(glass, dy, 0), dx, 1)
    regions.append(("edges by glass", (ids == -2) & near))
    regions.append(("other edges", (ids == -2) & ~near))
P3 = 2 * (1 - NormalDist().cdf(3.0))


def region_stats(a, b, mask):
    """Per-seed means of the region in sets a, b -> means, Welch diff, se, t, z."""
    pa, pb = a[:, mask].mean(1), b[:, mask].mean(1)  # (n, 3)
    d, se, z, zero = welch(pa, pb)
    t = np.where(se > 0, d / np.where(se > 0, se, 1), 0.0)
    base = np.where(pb.mean(0) != 0, pb.mean(0), 1)
    return dict(mean_a=pa.mean(0), mean_b=pb.mean(0), diff=d, se=se, t=t, z=z,
                rel=d / base, rel_se=se / np.abs(base),
                se_a=pa.std(0, ddof=1) / math.sqrt(len(pa)), se_b=pb.std(0, ddof=1) / math.sqrt(len(pb)))


def pixel_stats(a, b, masks):
    """Per-pixel Welch z. Values with no variance, or a relative standard
    error below 1e-5 (a mirror reflecting the sky: every sample the same up
    to the Fresnel factor's change across the pixel), are set apart and
    must agree to a relative 1e-4: their z measures float rounding (1e-6),
    not light transport."""
    d, se, z, zero = welch(a, b)
    ref = np.abs(b.mean(0))
    zero = zero | (se <= 1e-5 * ref)
    res = {}
    for name, mask in masks:
        zz, zr = z[mask], zero[mask]
        noisy = zz[~zr]
        const_bad = int((zr & (np.abs(d[mask]) > 1e-4 * ref[mask] + 1e-7)).sum())
        n = noisy.size
        res[name] = dict(values=int(n), constant=int(zr.sum()), constant_mismatch=const_bad,
                         within3=float((np.abs(noisy) <= 3).mean()) if n else float("nan"),
                         over3=int((np.abs(noisy) > 3).sum()),
                         rms_z=float(np.sqrt((noisy ** 2).mean())) if n else float("nan"),
                         mean_z=float(noisy.mean()) if n else float("nan"),
                         max_abs_z=float(np.abs(noisy).max()) if n else float("nan"))
    return res


report = {"scene": Path(scene_path).name, "size": list(L.shape[1:3]), "spp": int(spp), "max_depth": int(depth),
          "lumen_seeds": lseeds, "mitsuba_seeds": mseeds, "regions": {}, "pixels": {}, "paired": {}}
for name, mask in regions:
    report["regions"][name] = {"pixels": int(mask.sum())}
md = []
f4 = lambda v: " / ".join(f"{x:.4f}" for x in v)  # noqa: E731
TITLE = {"separable": "stock Mitsuba (separable Smith G)",
         "correlated": "Mitsuba with height-correlated G (hcsmith, hcplastic)",
         "lumencoat": "Mitsuba with height-correlated G and lumen's coat tables"}
for m in modes:
    md.append(f"\n### lumen against {TITLE.get(m, m)}\n")
    md.append(f"Per-object means over {len(lseeds)} + {len(mseeds)} renders; relative difference "
              "(lumen − Mitsuba)/Mitsuba ± its standard error; z = Welch's t over the per-seed means "
              "mapped to a normal score.\n")
    md.append("| region | pixels | lumen R / G / B | Mitsuba R / G / B | (lumen − Mitsuba)/Mitsuba R / G / B | "
              "z R / G / B |")
    md.append("| --- | ---: | --- | --- | --- | --- |")
    for name, mask in regions:
        if name in ("sky",):
            continue
        r = region_stats(L, M[m], mask)
        report["regions"][name][m] = {k: np.asarray(v).tolist() for k, v in r.items()}
        md.append(f"| {name} | {int(mask.sum())} | {f4(r['mean_a'])} | {f4(r['mean_b'])} | "
                  + " / ".join(f"{100 * x:+.3f} ± {100 * e:.3f}%" for x, e in zip(r["rel"], r["rel_se"])) + " | "
                  + " / ".join(f"{x:+.2f}" for x in r["z"]) + " |")
    px = pixel_stats(L, M[m], regions)
    report["pixels"][m] = px
    md.append(f"\nPer pixel (Welch z of lumen's {len(lseeds)} renders against Mitsuba's {len(mseeds)}, "
              f"each pixel value R, G, B; pure noise: {100 * (1 - P3):.2f}% within 3, RMS z 1, mean z 0; "
              "values without noise (relative s.e. < 1e-5) set apart, mismatched when they differ by more "
              "than 1e-4):\n")
    md.append("| region | noisy values | within \\|z\\| ≤ 3 | RMS z | mean z | max \\|z\\| | noiseless values (mismatched) |")
    md.append("| --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    for name, _ in regions:
        p = px[name]
        md.append(f"| {name} | {p['values']} | {100 * p['within3']:.2f}% | {p['rms_z']:.3f} | {p['mean_z']:+.3f} | "
                  f"{p['max_abs_z']:.1f} | {p['constant']} ({p['constant_mismatch']}) |")

# Mitsuba's modes share seeds: paired differences.
for new, old in (("correlated", "separable"), ("lumencoat", "correlated")):
    if new not in M or old not in M:
        continue
    md.append(f"\n### Mitsuba, {new} minus {old} (paired by seed)\n")
    md.append(f"| region | {old} R / G / B | {new} R / G / B | ({new} − {old})/{old} R / G / B | "
              "t R / G / B |")
    md.append("| --- | --- | --- | --- | --- |")
    S, C = M[old], M[new]
    report["paired"][f"{new}-{old}"] = {}
    for name, mask in regions:
        if name == "sky":
            continue
        ps, pc = S[:, mask].mean(1), C[:, mask].mean(1)
        dd = pc - ps
        dm, dse = dd.mean(0), dd.std(0, ddof=1) / math.sqrt(len(dd))
        base = ps.mean(0)
        rel, rse = dm / base, dse / base
        t = np.where(dse > 0, dm / np.where(dse > 0, dse, 1), 0)
        report["paired"][f"{new}-{old}"][name] = dict(separable=ps.mean(0).tolist(), correlated=pc.mean(0).tolist(),
                                      diff=dm.tolist(), se=dse.tolist(), rel=rel.tolist(), rel_se=rse.tolist(),
                                      t=t.tolist())
        md.append(f"| {name} | {f4(ps.mean(0))} | {f4(pc.mean(0))} | "
                  + " / ".join(f"{100 * x:+.3f} ± {100 * e:.3f}%" for x, e in zip(rel, rse)) + " | "
                  + " / ".join(f"{x:+.1f}" for x in t) + " |")

# The diagnosis of materials_probe trace (if run): lumen's loop as it is and
# with unit directions, per sphere.
trace = out / "trace.txt"
if trace.exists() and trace.stat().st_size:
    import re
    rows = {}
    for line in trace.read_text().splitlines():
        m = re.match(r"object (\d+): (\d+) pixels, (\d+) paths each(, directions normalised)?: mean (\S+) (\S+) (\S+); "
                     r"hits on a sphere computed off its surface \(> 1e-4\): (\d+) of (\d+)", line)
        if m:
            rows.setdefault(int(m[1]), {})["unit" if m[4] else "asis"] = (
                np.array([float(m[5]), float(m[6]), float(m[7])]), int(m[8]), int(m[9]))
    md.append("\n### lumen's own loop with and without unit directions (materials_probe trace)\n")
    md.append("| object | as lumen renders R / G / B | directions made unit R / G / B | change R / G / B | "
              "hits on a sphere off its surface (as is) |")
    md.append("| --- | --- | --- | --- | ---: |")
    report["trace"] = {}
    for i, r in sorted(rows.items()):
        if "asis" not in r or "unit" not in r:
            continue
        a, u = r["asis"][0], r["unit"][0]
        name = scene["objects"][i]["material"]
        report["trace"][name] = dict(asis=a.tolist(), unit=u.tolist(), off_surface=r["asis"][1], sphere_hits=r["asis"][2])
        md.append(f"| {name} | {f4(a)} | {f4(u)} | " + " / ".join(f"{100 * x:+.3f}%" for x in u / a - 1)
                  + f" | {r['asis'][1]} of {r['asis'][2]} |")

(out / "report.json").write_text(json.dumps(report, indent=1))
(out / "report.md").write_text("\n".join(md) + "\n")
print("\n".join(md))
PYEOF
for mode in $MODES; do
    echo
    echo "compare.py, lumen (A) against Mitsuba $mode (B):"
    sed '$d' "$OUT/compare-$mode.txt"
done
echo "total: $(($(date +%s) - T_START)) s; loadavg at end: $(cut -d' ' -f1-3 /proc/loadavg)" >>"$OUT/env.txt"
log "total $(($(date +%s) - T_START)) s; report in $OUT/report.md, environment in $OUT/env.txt"
