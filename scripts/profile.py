#!/usr/bin/env python3
"""Where a lumen render's time goes, by lumen source file and by stage.

The render loop is one function into which nearly everything is inlined,
so `perf report` by symbol says little and by source line credits glam's
and the standard library's inlined helpers. This script records a run with
`perf`, and credits each sample to the innermost frame of its inline stack
that lies in lumen's own `src/` (found with `llvm-addr2line -i`), then sums
the files into stages: traversal, primitive tests, hit record, shading,
lights, sampler, camera, film, path loop.

usage: scripts/profile.py [--top N] [--core C] -- LUMEN_BINARY ARGS...
  e.g. scripts/profile.py -- target/release/lumen bench --threads 1 \
           --runs 3 --spp 64 --workload cover-400x225
--core pins the run to core C (taskset). Needs perf and llvm-addr2line (or addr2line), and a binary with debug
information (the release profile keeps line tables).
"""
import collections
import os
import re
import shutil
import subprocess
import sys
import tempfile

# Stage of each lumen source file, by the first pattern its path matches.
STAGES = [
    (r"geometry/(bvh|bvh_bundle|bvh_build|instance|aabb)\.rs$|/lanes\.rs$|/simd\.rs$", "traversal"),
    (r"geometry/(sphere|triangle|quad|moving)\.rs$", "primitive tests"),
    (r"geometry/|scene/world\.rs$|scene/mod\.rs$|/hit\.rs$", "hit record"),
    (r"bsdf/|material/|texture/|/sampling\.rs$|/frame\.rs$", "shading"),
    (r"light/|/distribution\.rs$", "lights"),
    (r"sampler/|/sampler\.rs$|/rng\.rs$|/sobol", "sampler"),
    (r"/camera\.rs$|/ray\.rs$", "camera"),
    (r"/film\.rs$|/render\.rs$|/halt\.rs$", "film and rows"),
    (r"/integrator\.rs$|medium/|/medium\.rs$", "path loop"),
]


def stage_of(path):
    for pattern, stage in STAGES:
        if re.search(pattern, path):
            return stage
    return "other"


def main():
    args = sys.argv[1:]
    top, pin = 25, []
    while args[:1] in (["--top"], ["--core"]):
        if args[0] == "--top":
            top = int(args[1])
        else:
            pin = ["taskset", "-c", args[1]]
        args = args[2:]
    if args[:1] == ["--"]:
        args = args[1:]
    if not args:
        sys.exit(__doc__)
    binary = os.path.realpath(args[0])
    addr2line = shutil.which("llvm-addr2line") or shutil.which("addr2line")
    with tempfile.TemporaryDirectory() as tmp:
        data = os.path.join(tmp, "perf.data")
        subprocess.run(
            ["perf", "record", "-q", "-F", "4000", "-o", data, "--"] + pin + args,
            check=True,
            stdout=sys.stderr,
        )
        script = subprocess.run(
            ["perf", "script", "-i", data, "-F", "ip,sym,symoff,dso"],
            check=True,
            capture_output=True,
            text=True,
        ).stdout
    # Symbol addresses in the binary, to turn sym+offset into an address.
    nm = subprocess.run(["nm", "-C", binary], check=True, capture_output=True, text=True).stdout
    symbols = {}
    for line in nm.splitlines():
        parts = line.split(" ", 2)
        if len(parts) == 3 and parts[0] and parts[1] in "tTwW":
            symbols.setdefault(parts[2], int(parts[0], 16))
    counts = collections.Counter()
    outside = 0
    base = os.path.basename(binary)
    for line in script.splitlines():
        m = re.match(r"\s*[0-9a-f]+ (.*)\+0x([0-9a-f]+) \((.*)\)\s*$", line)
        if not m or os.path.basename(m.group(3)) != base or m.group(1) not in symbols:
            outside += 1
            continue
        counts[symbols[m.group(1)] + int(m.group(2), 16)] += 1
    addresses = sorted(counts)
    out = subprocess.run(
        [addr2line, "-e", binary, "-i", "-a"] + [hex(a) for a in addresses],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    # Output: an address line, then file:line for each inline frame,
    # innermost first.
    frames = collections.defaultdict(list)
    current = None
    for line in out.splitlines():
        if line.startswith("0x"):
            current = int(line, 16)
        elif current is not None:
            frames[current].append(line.strip())
    by_file = collections.Counter()
    total = sum(counts.values()) + outside
    for address, n in counts.items():
        own = next((f for f in frames[address] if "/src/" in f and "/rustc/" not in f
                    and "/.cargo/" not in f), None)
        path = own.rsplit(":", 1)[0] if own else "(no lumen frame)"
        path = re.sub(r".*?/src/", "src/", path, count=1)
        by_file[path] += n
    by_stage = collections.Counter()
    for path, n in by_file.items():
        by_stage[stage_of(path) if path.startswith("src/") else "other"] += n
    by_stage["outside the binary"] = outside
    print(f"{total} samples")
    print("\nstage                 share")
    for stage, n in by_stage.most_common():
        print(f"{stage:20} {100 * n / total:6.1f}%")
    print("\nfile                                  share")
    for path, n in by_file.most_common(top):
        print(f"{path:36} {100 * n / total:6.1f}%")


if __name__ == "__main__":
    main()
