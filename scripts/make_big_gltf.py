#!/usr/bin/env python3
"""Writes a large textured glTF model for measuring how fast lumen loads
one: a grid of N x N quads (2 N^2 triangles) bent into a wave, with
positions, normals, texture coordinates and tangents, and one material
with 4096 x 4096 base colour, metallic-roughness, normal and emissive
textures (PNG, in the GLB). N = 708 gives 1,002,528 triangles.

    python3 scripts/make_big_gltf.py OUT.glb [N] [TEXTURE_SIZE]

Needs numpy and Pillow. The textures are smooth patterns (they compress
as real textures do, unlike noise)."""
import io
import json
import struct
import sys

import numpy as np
from PIL import Image


def png(array):
    out = io.BytesIO()
    Image.fromarray(array).save(out, format="PNG", compress_level=1)
    return out.getvalue()


def main():
    out = sys.argv[1]
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 708
    size = int(sys.argv[3]) if len(sys.argv) > 3 else 4096
    u = np.linspace(0.0, 1.0, n + 1, dtype=np.float32)
    uu, vv = np.meshgrid(u, u, indexing="xy")
    x, z = uu * 2 - 1, vv * 2 - 1
    y = 0.1 * np.sin(6 * x) * np.cos(6 * z)
    pos = np.stack([x, y, z], -1).reshape(-1, 3).astype(np.float32)
    dydx = 0.6 * np.cos(6 * x) * np.cos(6 * z)
    dydz = -0.6 * np.sin(6 * x) * np.sin(6 * z)
    nrm = np.stack([-dydx, np.ones_like(x), -dydz], -1)
    nrm /= np.linalg.norm(nrm, axis=-1, keepdims=True)
    nrm = nrm.reshape(-1, 3).astype(np.float32)
    tan = np.stack([np.ones_like(x), dydx, np.zeros_like(x)], -1)
    tan /= np.linalg.norm(tan, axis=-1, keepdims=True)
    tan = np.concatenate([tan, np.ones_like(x)[..., None]], -1).reshape(-1, 4).astype(np.float32)
    uv = np.stack([uu, vv], -1).reshape(-1, 2).astype(np.float32)
    i = np.arange(n)
    a = (i[None, :] + (n + 1) * i[:, None]).reshape(-1)
    b, c, d = a + 1, a + n + 1, a + n + 2
    idx = np.stack([np.stack([a, c, b], -1), np.stack([b, c, d], -1)], 1).reshape(-1).astype(np.uint32)

    t = np.linspace(0, 8 * np.pi, size, dtype=np.float32)
    tx, ty = np.meshgrid(t, t)
    wave = (0.5 + 0.5 * np.sin(tx) * np.cos(ty))
    rgb = lambda r, g, b: np.stack([r, g, b], -1).clip(0, 1).__mul__(255).astype(np.uint8)  # noqa: E731
    images = [
        png(rgb(wave, 0.5 * wave + 0.2, 1 - wave)),  # base colour
        png(rgb(np.zeros_like(wave), 0.3 + 0.5 * wave, (wave > 0.7).astype(np.float32))),  # occlusion, roughness, metal
        png(rgb(0.5 + 0.2 * np.cos(tx), 0.5 + 0.2 * np.sin(ty), np.ones_like(wave))),  # normal
        png(rgb((wave > 0.95) * 1.0, (wave > 0.95) * 0.5, np.zeros_like(wave))),  # emissive
    ]
    blobs = [pos.tobytes(), nrm.tobytes(), tan.tobytes(), uv.tobytes(), idx.tobytes()] + images
    views, offset, body = [], 0, b""
    for blob in blobs:
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(blob)})
        pad = (-len(blob)) % 4
        body += blob + b"\0" * pad
        offset += len(blob) + pad
    nv = len(pos)
    gltf = {
        "asset": {"version": "2.0", "generator": "lumen scripts/make_big_gltf.py"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TANGENT": 2, "TEXCOORD_0": 3},
                                    "indices": 4, "material": 0}]}],
        "materials": [{
            "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicRoughnessTexture": {"index": 1}},
            "normalTexture": {"index": 2}, "emissiveTexture": {"index": 3}, "emissiveFactor": [1, 1, 1]}],
        "textures": [{"source": k} for k in range(4)],
        "images": [{"bufferView": 5 + k, "mimeType": "image/png"} for k in range(4)],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": nv, "type": "VEC3",
             "min": pos.min(0).tolist(), "max": pos.max(0).tolist()},
            {"bufferView": 1, "componentType": 5126, "count": nv, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": nv, "type": "VEC4"},
            {"bufferView": 3, "componentType": 5126, "count": nv, "type": "VEC2"},
            {"bufferView": 4, "componentType": 5125, "count": len(idx), "type": "SCALAR"},
        ],
        "bufferViews": views,
        "buffers": [{"byteLength": len(body)}],
    }
    js = json.dumps(gltf).encode()
    js += b" " * ((-len(js)) % 4)
    glb = struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(js) + 8 + len(body))
    glb += struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(body), 0x004E4942) + body
    with open(out, "wb") as f:
        f.write(glb)
    print(f"{out}: {len(idx) // 3} triangles, {nv} vertices, 4 textures {size}x{size}, {len(glb) / 1e6:.1f} MB")


if __name__ == "__main__":
    main()
