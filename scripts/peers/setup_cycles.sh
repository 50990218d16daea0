#!/usr/bin/env bash
# Install Blender Cycles (the `bpy` module from PyPI, Blender as a Python
# module) into a venv, for the peer-renderer comparisons (docs/peers.md).
#
#   scripts/peers/setup_cycles.sh                 # venv in $HOME/.cache/lumen-peers/venv-cycles
#   LUMEN_CYCLES_VENV=/some/dir scripts/peers/setup_cycles.sh
#   eval "$(scripts/peers/setup_cycles.sh --env)" # export LUMEN_CYCLES_PYTHON in this shell
#
# Idempotent: an existing venv with the pinned versions is left alone.
#
# bpy wheels are built for one CPython minor version each: bpy 4.2-5.0 need
# CPython 3.11 (cp311 manylinux x86-64 wheels). A python3.11 on PATH (pyenv
# or Debian's) is used; without one, Debian's python3.11 and python3.11-venv
# are installed with apt-get. bpy links a few X11/GL client libraries (not
# used when rendering in the background); missing ones are installed too.
# The last line printed is the `export` line for the caller to eval.
set -euo pipefail

BPY_VERSION=5.0.1
NUMPY_VERSION=1.26.4   # what bpy 5.0.1 requires (numpy 1.x ABI)

VENV="${LUMEN_CYCLES_VENV:-$HOME/.cache/lumen-peers/venv-cycles}"
ENV_ONLY=0
[[ "${1:-}" == "--env" ]] && ENV_ONLY=1
PY="$VENV/bin/python"

log() { echo "setup_cycles.sh: $*" >&2; }
if [[ $(id -u) -ne 0 ]]; then SUDO=sudo; else SUDO=; fi
apt_install() {
    $SUDO apt-get install -y --no-install-recommends "$@" >&2 || {
        $SUDO apt-get update >&2 && $SUDO apt-get install -y --no-install-recommends "$@" >&2; }
}

have_pins() {
    [[ -x "$PY" ]] && "$PY" - "$BPY_VERSION" "$NUMPY_VERSION" <<'PYEOF' 2>/dev/null
import sys, importlib.metadata as md
want = dict(zip(("bpy", "numpy"), sys.argv[1:]))
sys.exit(0 if all(md.version(k) == v for k, v in want.items()) else 1)
PYEOF
}

find_python311() {
    local p
    for p in python3.11 /usr/bin/python3.11 /usr/local/bin/python3.11; do
        if command -v "$p" >/dev/null 2>&1 && "$p" -c 'import sys, venv; assert sys.version_info[:2] == (3, 11)' 2>/dev/null; then
            command -v "$p"; return 0
        fi
    done
    return 1
}

if [[ $ENV_ONLY == 0 ]]; then
    if have_pins; then
        log "venv $VENV already has bpy $BPY_VERSION, numpy $NUMPY_VERSION"
    else
        if ! PY311=$(find_python311); then
            log "no CPython 3.11 found: installing Debian's python3.11 (apt-get)"
            apt_install python3.11 python3.11-venv
            PY311=$(find_python311) || { log "python3.11 still not usable"; exit 1; }
        fi
        log "creating venv $VENV with $PY311 ($("$PY311" --version 2>&1))"
        rm -rf "$VENV"
        "$PY311" -m venv "$VENV" >&2 || { apt_install python3.11-venv; "$PY311" -m venv "$VENV" >&2; }
        "$PY" -m pip install --quiet --upgrade pip >&2
        "$PY" -m pip install --quiet "bpy==$BPY_VERSION" "numpy==$NUMPY_VERSION" >&2
    fi

    # --- shared libraries bpy links (X11 client, GL): install the missing ones
    SO=$(ls "$VENV"/lib/python3.11/site-packages/bpy/__init__*.so 2>/dev/null | head -n1 || true)
    if [[ -n "$SO" ]] && ldd "$SO" | grep -q "not found"; then
        log "bpy needs: $(ldd "$SO" | grep 'not found' | awk '{print $1}' | tr '\n' ' ')"
        apt_install libx11-6 libxrender1 libxfixes3 libxi6 libxkbcommon0 libsm6 libice6 libgl1 libxext6 libxxf86vm1
    fi

    # --- check: Cycles renders on the CPU ---------------------------------
    log "checking Cycles"
    "$PY" - <<'PYEOF' >&2
import bpy, numpy as np, os, tempfile
s = bpy.context.scene
s.render.engine = "CYCLES"
s.cycles.device = "CPU"
s.cycles.samples = 4
s.cycles.use_denoising = False
s.render.resolution_x = s.render.resolution_y = 16
s.render.image_settings.file_format = "OPEN_EXR"
s.render.image_settings.color_depth = "32"
bpy.ops.render.render(write_still=False)
with tempfile.TemporaryDirectory() as d:
    p = os.path.join(d, "t.exr")
    bpy.data.images["Render Result"].save_render(filepath=p, scene=s)
    img = bpy.data.images.load(p)
    a = np.empty(len(img.pixels), np.float32)
    img.pixels.foreach_get(a)
v = float(a.mean())
assert np.isfinite(v) and v > 0, v
print(f"setup_cycles.sh: ok: Blender {bpy.app.version_string} (bpy), Cycles on the CPU, "
      f"test image mean {v:.3f}")
PYEOF
fi

[[ -x "$PY" ]] || { log "no venv at $VENV: run scripts/peers/setup_cycles.sh without --env first"; exit 1; }
echo "export LUMEN_CYCLES_PYTHON=$PY"
