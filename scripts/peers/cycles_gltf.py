#!/usr/bin/env python3
"""A lumen scene placing glTF files, rendered with Blender Cycles, the glTF
files read by Blender's own importer (io_scene_gltf2, bundled with bpy).

    eval "$(scripts/peers/setup_cycles.sh --env)"
    $LUMEN_CYCLES_PYTHON scripts/peers/cycles_gltf.py scripts/peers/gltf_spheres.toml \
        --spp 256 --seed 1 --out spheres-cycles.pfm
    $LUMEN_CYCLES_PYTHON scripts/peers/cycles_gltf.py SCENE.toml --spp 256 \
        --seeds 0 1 2 3 --out-template /tmp/c-{seed}.pfm
    $LUMEN_CYCLES_PYTHON scripts/peers/cycles_gltf.py SCENE.toml --dump-materials

What is read from the lumen scene (docs/scene-format.md), in lumen's Y-up
coordinates, each point and direction mapped to Blender's Z-up by
(x, y, z) -> (x, -z, y) (cycles_common.to_blender; the glTF importer maps
glTF's Y-up the same way):

- [render] width, height, max_depth; [camera] lookfrom, lookat, vup, vfov
  (vertical, degrees; sensor fit vertical), pinhole only.
- [background] `solid` (World Background of that colour, strength 1) or
  `image` (equirectangular; an Environment Texture, Linear interpolation,
  behind a Mapping node turning it about Blender's +Z by -(90 + rotation)
  degrees, strength = intensity). Cycles' equirectangular map has its
  centre (u = 0.5) along +X and +Y at u = 0.25; lumen's has its centre
  straight ahead of the default camera (-z, Blender +Y) and +x (Blender
  +X) to its right, and `rotation` turns the sky counter-clockwise seen
  from above, i.e. about Blender +Z by +rotation. Checked by --sky-only.
- [[objects]] of type `mesh` whose file is .glb/.gltf, with no `material`
  override: imported by bpy.ops.import_scene.gltf (default options: the
  file's normals, Principled BSDF materials), the file's root objects then
  placed by the object's `transform` (translate, rotate, scale, matrix,
  in the order written, as lumen applies them).

Cycles settings: cycles_common.configure (box filter 1 px, no clamping,
no denoising, filter glossy 0, caustics on, adaptive sampling off), with
max_bounces = diffuse = glossy = transmission = max_depth - 2 (Cycles'
0 bounces is 2 segments: the exact match of lumen's max_depth, see
cycles_common.py), transparent bounces 64 (alpha MASK/BLEND cut-outs;
lumen's rays pass through cut-out surfaces without counting a segment).

--distribution GGX|MULTI_GGX sets every Principled BSDF's microfacet
distribution (the importer leaves Cycles' default, MULTI_GGX: multiple
scattering / energy compensation; GGX is single scattering as glTF).
--linear-textures replaces each 8-bit sRGB texture by a float copy of its
texels decoded to linear: Cycles interpolates 8-bit sRGB textures before
decoding them (kernel/svm/image.h), lumen decodes each texel first.
--tint-per-interface squares the constant Base Color of transmitting
Principled BSDFs: Cycles tints refraction by sqrt(Base Color) at each
interface (svm closure setup, transmission_tint = sqrt(base colour)),
glTF by the base colour at each interface.
--dump-materials prints each imported material's Principled inputs (value
or what is linked) and exits: the importer's mapping.
"""

import argparse
import json
import math
import sys
import time
import tomllib
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import cycles_common as cc  # noqa: E402
import peerlib  # noqa: E402

import bpy  # noqa: E402
from mathutils import Matrix, Vector  # noqa: E402

# lumen (Y-up) -> Blender (Z-up): (x, y, z) -> (x, -z, y).
C = Matrix(((1, 0, 0, 0), (0, 0, -1, 0), (0, 1, 0, 0), (0, 0, 0, 1)))


def step_matrix(step):
    """One lumen transform step as a 4x4 matrix in lumen coordinates."""
    if "translate" in step:
        return Matrix.Translation(Vector(step["translate"]))
    if "rotate" in step:
        r = step["rotate"]
        return Matrix.Rotation(math.radians(r["degrees"]), 4, Vector(r["axis"]).normalized())
    if "scale" in step:
        s = step["scale"]
        s = [s] * 3 if isinstance(s, (int, float)) else s
        return Matrix.Diagonal((*[float(x) for x in s], 1.0))
    if "matrix" in step:
        return Matrix(step["matrix"])
    raise SystemExit(f"transform step {step} not supported")


def lumen_transform(steps):
    """The object's transform in Blender coordinates: C T C^-1, T composed
    in the order written (the first step applied first)."""
    t = Matrix.Identity(4)
    for s in steps or []:
        t = step_matrix(s) @ t
    return C @ t @ C.inverted()


def world_image(scene, path, rotation_deg, intensity):
    w = bpy.data.worlds.new("sky") if scene.world is None else scene.world
    scene.world = w
    w.use_nodes = True
    nt = w.node_tree
    nt.nodes.clear()
    coord = nt.nodes.new("ShaderNodeTexCoord")
    mapping = nt.nodes.new("ShaderNodeMapping")
    mapping.vector_type = "POINT"
    mapping.inputs["Rotation"].default_value = (0.0, 0.0, math.radians(-(90.0 + rotation_deg)))
    env = nt.nodes.new("ShaderNodeTexEnvironment")
    env.image = bpy.data.images.load(str(path), check_existing=True)
    env.interpolation = "Linear"
    env.projection = "EQUIRECTANGULAR"
    bg = nt.nodes.new("ShaderNodeBackground")
    bg.inputs["Strength"].default_value = intensity
    out = nt.nodes.new("ShaderNodeOutputWorld")
    nt.links.new(coord.outputs["Generated"], mapping.inputs["Vector"])
    nt.links.new(mapping.outputs["Vector"], env.inputs["Vector"])
    nt.links.new(env.outputs["Color"], bg.inputs["Color"])
    nt.links.new(bg.outputs["Background"], out.inputs["Surface"])
    return env.image


# Seconds spent in Blender's glTF importer so far (denoise_cycles.py reports
# them beside the render call's).
IMPORT_SECONDS = 0.0


def import_gltf(path, matrix):
    """Import a glTF file; place its root objects by `matrix` (Blender
    coordinates). Returns the new objects."""
    global IMPORT_SECONDS
    before = set(bpy.data.objects)
    t0 = time.perf_counter()
    bpy.ops.import_scene.gltf(filepath=str(path))
    IMPORT_SECONDS += time.perf_counter() - t0
    new = [ob for ob in bpy.data.objects if ob not in before]
    for ob in new:
        if ob.parent is None:
            ob.matrix_world = matrix @ ob.matrix_world
    return new


def linearize_textures():
    """Replace every 8-bit sRGB image of the imported materials by a float
    image of its texels decoded to linear (alpha kept), so that Cycles
    interpolates linear values as lumen does. (Cycles keeps 8-bit sRGB
    images as bytes, interpolates the encoded values and decodes the result:
    kernel/svm/image.h, svm_image_texture, NODE_IMAGE_COMPRESS_AS_SRGB.)
    Returns the names of the images replaced."""
    import numpy as np
    done = {}
    for mat in bpy.data.materials:
        if mat.node_tree is None:
            continue
        for node in mat.node_tree.nodes:
            img = getattr(node, "image", None)
            if node.type != "TEX_IMAGE" or img is None or img.is_float:
                continue
            if img.colorspace_settings.name != "sRGB":
                continue
            if img.name not in done:
                w, h = img.size
                px = np.empty(w * h * 4, np.float32)
                img.pixels.foreach_get(px)            # the stored (encoded) values / 255
                px = px.reshape(-1, 4)
                c = px[:, :3]
                px[:, :3] = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
                new = bpy.data.images.new(img.name + ".linear", w, h, alpha=True, float_buffer=True)
                new.colorspace_settings.name = "Linear Rec.709"
                new.alpha_mode = img.alpha_mode
                new.pixels.foreach_set(px.ravel())
                done[img.name] = new
            node.image = done[img.name]
    return sorted(done)


def square_transmission_tint():
    """Square the (constant) Base Color of every Principled BSDF that
    transmits (Transmission Weight linked or > 0) and is not metallic by a
    constant: Cycles tints refraction by sqrt(Base Color) at each interface
    (once per closed object), glTF by the base colour at each interface.
    Returns the materials changed."""
    changed = []
    for mat, node in principled_nodes():
        t = node.inputs["Transmission Weight"]
        bc = node.inputs["Base Color"]
        if bc.is_linked or not (t.is_linked or t.default_value > 0):
            continue
        c = list(bc.default_value)
        bc.default_value = (c[0] ** 2, c[1] ** 2, c[2] ** 2, c[3])
        changed.append(mat.name)
    return changed


def principled_nodes():
    for mat in bpy.data.materials:
        if mat.node_tree is None:
            continue
        for node in mat.node_tree.nodes:
            if node.type == "BSDF_PRINCIPLED":
                yield mat, node


def socket_desc(sock):
    if sock.is_linked:
        link = sock.links[0]
        n = link.from_node
        what = n.type
        if n.type == "TEX_IMAGE" and n.image is not None:
            what += f"({n.image.name}, {n.image.colorspace_settings.name}, {n.interpolation})"
        elif n.type in ("MATH", "MIX"):
            what += f"({getattr(n, 'operation', getattr(n, 'blend_type', ''))})"
        elif n.type == "SEPARATE_COLOR":
            pass
        elif n.type == "NORMAL_MAP":
            what += f"(space {n.space}, uv {n.uv_map}, strength {n.inputs['Strength'].default_value})"
        return f"<- {what}.{link.from_socket.name}"
    v = getattr(sock, "default_value", None)
    try:
        v = [round(x, 4) for x in v]
    except TypeError:
        v = round(v, 4) if isinstance(v, float) else v
    return v


INPUTS = ["Base Color", "Metallic", "Roughness", "IOR", "Alpha", "Normal", "Specular IOR Level",
          "Specular Tint", "Transmission Weight", "Coat Weight", "Sheen Weight", "Emission Color",
          "Emission Strength", "Diffuse Roughness"]


def dump_materials():
    out = []
    for mat, node in principled_nodes():
        d = {"material": mat.name, "distribution": node.distribution,
             "subsurface_method": node.subsurface_method}
        for name in INPUTS:
            if name in node.inputs:
                d[name] = socket_desc(node.inputs[name])
        outn = [n for n in mat.node_tree.nodes if n.type == "OUTPUT_MATERIAL"]
        if outn and outn[0].inputs["Volume"].is_linked:
            v = outn[0].inputs["Volume"].links[0].from_node
            d["Volume"] = f"{v.type} color {list(v.inputs[0].default_value)[:3]} density {v.inputs[1].default_value}"
        out.append(d)
    return out


def build(args):
    lscene = peerlib.fill_defaults(tomllib.loads(Path(args.scene).read_text()))
    base = Path(args.scene).resolve().parent
    r, cam = lscene["render"], lscene["camera"]
    if cam.get("defocus_angle", 0.0) != 0.0:
        raise SystemExit("only a pinhole camera (defocus_angle 0)")
    width = args.width or r["width"]
    height = max(1, r["height"] * width // r["width"])
    depth = args.max_depth or r["max_depth"]
    spp = args.spp or r["samples_per_pixel"]
    seed0 = args.seeds[0] if args.seeds else args.seed
    scene = cc.empty_scene()
    for w in list(bpy.data.worlds):
        bpy.data.worlds.remove(w)
    scene.world = None
    cc.configure(scene, width, height, spp, depth, seed0, args.threads, args.rr == "on",
                 None if args.pattern == "startup" else args.pattern, bounces=depth - 2)
    scene.cycles.transparent_max_bounces = 64
    bg = lscene.get("background", {"type": "gradient"})
    if bg["type"] == "solid":
        cc.world_color(scene, bg["color"], 1.0)
    elif bg["type"] == "image":
        img = Path(bg["file"])
        img = img if img.is_absolute() else base / img
        world_image(scene, img, float(bg.get("rotation", 0.0)), float(bg.get("intensity", 1.0)))
    else:
        raise SystemExit(f"background {bg['type']} not supported (solid or image)")
    cc.camera(scene, cam["lookfrom"], cam["lookat"], cam["vup"], float(cam["vfov"]))
    files = []
    if not args.sky_only:
        for i, o in enumerate(lscene.get("objects", [])):
            if o["type"] != "mesh" or "material" in o:
                raise SystemExit(f"objects[{i}]: only glTF meshes with their own materials")
            f = Path(o["file"])
            f = f if f.is_absolute() else base / f
            if f.suffix.lower() not in (".glb", ".gltf"):
                raise SystemExit(f"objects[{i}]: {f} is not glTF")
            if o.get("smooth", True) is False:
                raise SystemExit(f"objects[{i}]: smooth = false not supported")
            import_gltf(f, lumen_transform(o.get("transform")))
            files.append(f.name)
    # the importer may add cameras and lights: keep ours, drop its lights
    for ob in list(bpy.data.objects):
        if ob.type == "LIGHT":
            bpy.data.objects.remove(ob, do_unlink=True)
    scene.camera = bpy.data.objects["cam"]
    linear = linearize_textures() if args.linear_textures else []
    squared = square_transmission_tint() if args.tint_per_interface else []
    if args.distribution != "import":
        for _, node in principled_nodes():
            node.distribution = args.distribution
    ntri = 0
    for ob in scene.objects:
        if ob.type == "MESH":
            ntri += sum(len(p.vertices) - 2 for p in ob.data.polygons)
    info = {"scene": Path(args.scene).name, "files": files, "triangles": ntri, "width": width,
            "height": height, "spp": spp, "max_depth": depth, "bounces": depth - 2,
            "rr": args.rr, "pattern": args.pattern, "distribution": args.distribution,
            "background": bg["type"], "linearized_textures": linear,
            "squared_tint": squared}
    return scene, info


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene", help="lumen scene file (.toml) placing glTF meshes")
    cc.add_common_args(ap)
    ap.add_argument("--width", type=int, help="image width (height follows the scene's aspect)")
    ap.add_argument("--distribution", choices=["import", "GGX", "MULTI_GGX"], default="import",
                    help="Principled BSDF distribution: as imported (MULTI_GGX), or forced")
    ap.add_argument("--linear-textures", action="store_true",
                    help="decode 8-bit sRGB textures to float before rendering (Cycles then "
                         "interpolates linear values, as lumen does)")
    ap.add_argument("--tint-per-interface", action="store_true",
                    help="square the constant Base Color of transmitting Principled BSDFs "
                         "(glTF tints by the base colour at every interface, Cycles by its square root)")
    ap.add_argument("--sky-only", action="store_true", help="leave the meshes out (sky orientation check)")
    ap.add_argument("--dump-materials", action="store_true", help="print the imported materials and exit")
    args = ap.parse_args(cc.argv_after_dashdash() if argv is None else argv)
    if not (args.out or args.seeds or args.dump_materials):
        ap.error("give --out (one render), --seeds (timed renders) or --dump-materials")
    scene, info = build(args)
    if args.dump_materials:
        for d in dump_materials():
            print(json.dumps(d))
        return 0
    cc.run(scene, args, info)
    return 0


if __name__ == "__main__":
    sys.exit(main())
