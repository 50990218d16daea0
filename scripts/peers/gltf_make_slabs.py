#!/usr/bin/env python3
"""Write a small glTF file of slabs (boxes 0.8 x 0.8 x 0.1, 1 apart, facing
+z) with transmissive materials, for a white-furnace check of the
transmission lobe in lumen and in Cycles (docs/validation-gltf.md,
scripts/peers/gltf_slabs.toml). Plain Python, no dependencies.

    gltf_make_slabs.py OUT.gltf

Columns (x = 0, 1, 2, 3), all KHR_materials_transmission 1, metallic 0:
  0: ior 1.5, roughness 0,   KHR_materials_volume thickness 0.1 (refracting)
  1: ior 1.5, roughness 0.5, volume (refracting)
  2: ior 1.0, roughness 0.5, volume (refracting, index-matched)
  3: ior 1.5, roughness 0.5, no volume extension (thin-walled)
Rows (y = 0, 1): base colour white; base colour (0.5, 0.7, 0.9).
In a white furnace a slab that loses no energy looks exactly white (row 0).
"""

import base64
import json
import struct
import sys


def box(cx, cy, hx=0.4, hy=0.4, hz=0.05):
    """24 vertices (flat normals), 36 indices, outward counter-clockwise."""
    pos, nrm, idx = [], [], []
    faces = [((1, 0, 0), (0, 1, 0), (0, 0, 1)), ((-1, 0, 0), (0, 0, 1), (0, 1, 0)),
             ((0, 1, 0), (0, 0, 1), (1, 0, 0)), ((0, -1, 0), (1, 0, 0), (0, 0, 1)),
             ((0, 0, 1), (1, 0, 0), (0, 1, 0)), ((0, 0, -1), (0, 1, 0), (1, 0, 0))]
    h = (hx, hy, hz)
    c = (cx, cy, 0.0)
    for n, u, v in faces:
        base = len(pos)
        for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            p = [c[k] + h[k] * (n[k] + su * u[k] + sv * v[k]) for k in range(3)]
            pos.append(p)
            nrm.append(list(n))
        idx += [base, base + 1, base + 2, base, base + 2, base + 3]
    return pos, nrm, idx


COLUMNS = [
    {"ior": 1.5, "rough": 0.0, "volume": True},
    {"ior": 1.5, "rough": 0.5, "volume": True},
    {"ior": 1.0, "rough": 0.5, "volume": True},
    {"ior": 1.5, "rough": 0.5, "volume": False},
]
ROWS = [[1.0, 1.0, 1.0, 1.0], [0.5, 0.7, 0.9, 1.0]]


def main(out):
    buf = bytearray()
    views, accessors, meshes, nodes, materials = [], [], [], [], []
    for r, colour in enumerate(ROWS):
        for c, col in enumerate(COLUMNS):
            ext = {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                   "KHR_materials_ior": {"ior": col["ior"]}}
            if col["volume"]:
                ext["KHR_materials_volume"] = {"thicknessFactor": 0.1}
            materials.append({"name": f"slab_r{r}_c{c}",
                              "pbrMetallicRoughness": {"baseColorFactor": colour, "metallicFactor": 0.0,
                                                       "roughnessFactor": col["rough"]},
                              "extensions": ext})
            pos, nrm, idx = box(float(c), float(r))
            acc = []
            for data, fmt, typ, comp, target in ((pos, "<3f", "VEC3", 5126, 34962),
                                                 (nrm, "<3f", "VEC3", 5126, 34962),
                                                 (idx, "<H", "SCALAR", 5123, 34963)):
                while len(buf) % 4:
                    buf.append(0)
                start = len(buf)
                for d in data:
                    buf += struct.pack(fmt, *(d if isinstance(d, list) else [d]))
                views.append({"buffer": 0, "byteOffset": start, "byteLength": len(buf) - start,
                              "target": target})
                a = {"bufferView": len(views) - 1, "componentType": comp, "count": len(data), "type": typ}
                if typ == "VEC3" and data is pos:
                    a["min"] = [min(p[k] for p in pos) for k in range(3)]
                    a["max"] = [max(p[k] for p in pos) for k in range(3)]
                accessors.append(a)
                acc.append(len(accessors) - 1)
            meshes.append({"primitives": [{"attributes": {"POSITION": acc[0], "NORMAL": acc[1]},
                                           "indices": acc[2], "material": len(materials) - 1}]})
            nodes.append({"mesh": len(meshes) - 1, "name": f"slab_r{r}_c{c}"})
    doc = {
        "asset": {"version": "2.0", "generator": "lumen scripts/peers/gltf_make_slabs.py"},
        "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume"],
        "scene": 0, "scenes": [{"nodes": list(range(len(nodes)))}], "nodes": nodes, "meshes": meshes,
        "materials": materials, "accessors": accessors, "bufferViews": views,
        "buffers": [{"byteLength": len(buf),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(buf)).decode()}],
    }
    with open(out, "w") as f:
        json.dump(doc, f, indent=1)
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1]))
