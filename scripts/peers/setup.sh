#!/usr/bin/env bash
# Install Mitsuba 3 (the peer renderer lumen is compared with) into a venv.
#
#   scripts/peers/setup.sh                 # venv in $HOME/.cache/lumen-peers/venv
#   LUMEN_PEERS_VENV=/some/dir scripts/peers/setup.sh
#   eval "$(scripts/peers/setup.sh --env)" # also export the variables in this shell
#
# Idempotent: an existing venv with the pinned versions is left alone.
#
# Mitsuba's fast CPU variant, llvm_ad_rgb, JIT-compiles its kernels with
# LLVM (and traces rays with Embree, built into the wheel). Dr.Jit loads
# libLLVM at run time; it finds it through DRJIT_LIBLLVM_PATH. We install
# Debian's libllvm19 if missing and point DRJIT_LIBLLVM_PATH at it.
# The last lines printed are the `export` lines for the caller to eval.
set -euo pipefail

MITSUBA_VERSION=3.9.1
DRJIT_VERSION=1.5.0
NUMPY_VERSION=2.4.6
# HDR-FLIP, for the denoising benchmarks (scripts/denoise-bench.py and
# scripts/peers/denoise_cycles.py).
FLIP_VERSION=1.7

VENV="${LUMEN_PEERS_VENV:-$HOME/.cache/lumen-peers/venv}"
ENV_ONLY=0
[[ "${1:-}" == "--env" ]] && ENV_ONLY=1

log() { echo "setup.sh: $*" >&2; }

# --- libLLVM -------------------------------------------------------------
find_libllvm() {
    local f
    for f in /usr/lib/llvm-19/lib/libLLVM.so.1 /usr/lib/llvm-19/lib/libLLVM-19.so \
             /usr/lib/x86_64-linux-gnu/libLLVM-19.so.1 /usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 \
             /usr/lib/aarch64-linux-gnu/libLLVM-19.so.1 /usr/lib/x86_64-linux-gnu/libLLVM-19.so; do
        [[ -e "$f" ]] && { readlink -f "$f"; return 0; }
    done
    # any libLLVM shipped by the libllvm19 package
    if dpkg -L libllvm19 >/dev/null 2>&1; then
        f=$(dpkg -L libllvm19 | grep -E '/libLLVM[^/]*\.so[^/]*$' | head -n1 || true)
        [[ -n "$f" && -e "$f" ]] && { readlink -f "$f"; return 0; }
    fi
    return 1
}

if [[ -n "${DRJIT_LIBLLVM_PATH:-}" && -e "${DRJIT_LIBLLVM_PATH}" ]]; then
    LIBLLVM="$DRJIT_LIBLLVM_PATH"
elif LIBLLVM=$(find_libllvm); then
    :
else
    [[ $ENV_ONLY == 1 ]] && { log "libLLVM 19 not installed; run without --env first"; exit 1; }
    log "installing libllvm19 (apt-get)"
    if [[ $(id -u) -ne 0 ]]; then SUDO=sudo; else SUDO=; fi
    $SUDO apt-get install -y --no-install-recommends libllvm19 >&2 || {
        $SUDO apt-get update >&2 && $SUDO apt-get install -y --no-install-recommends libllvm19 >&2; }
    LIBLLVM=$(find_libllvm) || { log "libllvm19 installed but libLLVM*.so not found"; exit 1; }
fi
export DRJIT_LIBLLVM_PATH="$LIBLLVM"

# --- venv with mitsuba ---------------------------------------------------
PY="$VENV/bin/python"
have_pins() {
    [[ -x "$PY" ]] && "$PY" - "$MITSUBA_VERSION" "$DRJIT_VERSION" "$NUMPY_VERSION" "$FLIP_VERSION" <<'PYEOF' 2>/dev/null
import sys, importlib.metadata as md
want = dict(zip(("mitsuba", "drjit", "numpy", "flip-evaluator"), sys.argv[1:]))
sys.exit(0 if all(md.version(k) == v for k, v in want.items()) else 1)
PYEOF
}

if [[ $ENV_ONLY == 0 ]]; then
    if have_pins; then
        log "venv $VENV already has mitsuba $MITSUBA_VERSION, drjit $DRJIT_VERSION, numpy $NUMPY_VERSION, flip-evaluator $FLIP_VERSION"
    else
        log "creating venv $VENV"
        python3 -m venv "$VENV" >&2
        "$PY" -m pip install --quiet --upgrade pip >&2
        "$PY" -m pip install --quiet "mitsuba==$MITSUBA_VERSION" "drjit==$DRJIT_VERSION" "numpy==$NUMPY_VERSION" \
            "flip-evaluator==$FLIP_VERSION" >&2
    fi

    # --- check: llvm_ad_rgb really runs, with several threads -------------
    log "checking the llvm_ad_rgb variant"
    "$PY" - <<'PYEOF' >&2
import mitsuba as mi, drjit as dr
mi.set_variant("llvm_ad_rgb")
scene = mi.load_dict({"type": "scene", "integrator": {"type": "path"},
    "sensor": {"type": "perspective",
               "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0, 5], target=[0, 0, 0], up=[0, 1, 0]),
               "film": {"type": "hdrfilm", "width": 16, "height": 16}},
    "emitter": {"type": "constant"}, "s": {"type": "sphere"}})
img = mi.render(scene, spp=4)
import numpy as np
v = float(np.asarray(img).mean())
assert np.isfinite(v) and v > 0, v
maps = open("/proc/self/maps").read().split("\n")
libs = sorted({l.split()[-1] for l in maps if "libLLVM" in l or "libembree" in l})
assert any("libLLVM" in l for l in libs), "libLLVM not loaded"
assert any("libembree" in l for l in libs), "Embree not loaded"
assert dr.thread_count() >= 1
print(f"setup.sh: ok: mitsuba {mi.__version__}, drjit {dr.__version__}, variant {mi.variant()}, "
      f"{dr.thread_count()} threads, test image mean {v:.3f}; loaded {', '.join(libs)}")
PYEOF
fi

[[ -x "$PY" ]] || { log "no venv at $VENV: run scripts/peers/setup.sh without --env first"; exit 1; }
echo "export DRJIT_LIBLLVM_PATH=$DRJIT_LIBLLVM_PATH"
echo "export LUMEN_PEERS_PYTHON=$PY"
