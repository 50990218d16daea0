#!/usr/bin/env python3
"""Writes a scene file of N small spheres on a floor (default 1,000,000):
the large scene file that docs/performance.md loads, converts and renders
to measure how the scene reader scales.

    python3 scripts/make_field.py OUT.toml [N]
    python3 scripts/make_field.py OUT.json [N]

The extension chooses the format. The spheres sit on a square grid, with
radius and material drawn from a fixed-seed generator, so that the file is
the same on every run and the TOML and JSON forms describe the same scene.
Every sphere is its own [[objects]] table, as a person or a simple program
would write it.
"""
import json
import math
import random
import sys

MATERIALS = {
    "floor": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]},
    "matte": {"type": "diffuse", "albedo": [0.7, 0.3, 0.2]},
    "metal": {"type": "metal", "albedo": [0.8, 0.8, 0.9], "fuzz": 0.1},
    "glass": {"type": "dielectric", "ior": 1.5},
}
NAMES = ["matte", "metal", "glass"]


def toml_inline(table):
    """A flat table as a TOML inline table (its values written as in JSON)."""
    return "{ %s }" % ", ".join("%s = %s" % (k, json.dumps(v)) for k, v in table.items())


def spheres(n):
    """(x, y, z, radius, material) of the floor, then of n spheres on a grid
    around the origin."""
    yield 0, -10000, 0, 10000, "floor"
    rng = random.Random(1)
    side = max(1, math.ceil(math.sqrt(n)))
    spacing = 0.5
    half = side * spacing / 2
    for i in range(n):
        r = round(0.05 + 0.15 * rng.random(), 4)
        x = round(-half + (i % side) * spacing + 0.1 * rng.random(), 4)
        z = round(-half + (i // side) * spacing + 0.1 * rng.random(), 4)
        yield x, r, z, r, NAMES[rng.randrange(3)]


def write_toml(out, n):
    out.write('caption = "A field of %d small spheres"\n\n' % n)
    out.write("[render]\nwidth = 400\nsamples_per_pixel = 16\nmax_depth = 8\n\n")
    out.write("[camera]\nvfov = 40\nlookfrom = [0, 40, 120]\nlookat = [0, 0, 0]\n\n")
    out.write("[materials]\n")
    for name, body in MATERIALS.items():
        out.write("%s = %s\n" % (name, toml_inline(body)))
    for x, y, z, r, m in spheres(n):
        out.write('\n[[objects]]\ntype = "sphere"\ncenter = [%s, %s, %s]\n'
                  'radius = %s\nmaterial = "%s"\n' % (x, y, z, r, m))


def write_json(out, n):
    out.write('{\n  "caption": "A field of %d small spheres",\n' % n)
    out.write('  "render": {"width": 400, "samples_per_pixel": 16, "max_depth": 8},\n')
    out.write('  "camera": {"vfov": 40, "lookfrom": [0, 40, 120], "lookat": [0, 0, 0]},\n')
    out.write('  "materials": {\n')
    out.write(",\n".join('    "%s": %s' % (name, json.dumps(body))
                          for name, body in MATERIALS.items()))
    out.write('\n  },\n  "objects": [')
    for i, (x, y, z, r, m) in enumerate(spheres(n)):
        out.write('%s\n    {"type": "sphere", "center": [%s, %s, %s], "radius": %s, '
                  '"material": "%s"}' % ("," if i else "", x, y, z, r, m))
    out.write("\n  ]\n}\n")


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    path = sys.argv[1]
    n = int(sys.argv[2]) if len(sys.argv) == 3 else 1_000_000
    with open(path, "w") as out:
        if path.endswith(".toml"):
            write_toml(out, n)
        elif path.endswith(".json"):
            write_json(out, n)
        else:
            sys.exit("the output must end in .toml or .json")


if __name__ == "__main__":
    main()
