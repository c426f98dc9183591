"""Run inside Blender: import a glTF/GLB and write, as JSON, what Blender made of it.

    blender -b --factory-startup --python-exit-code 1 \\
        --python tests/blender_gltf_report.py -- IN.glb OUT.json

tests/test_blender_import.py runs it to check that a textured bgr GLB arrives in Blender (the
tool most people open a GLB in) with its texture coordinates, its images' pixels and the
material wiring a user expects: the colour map feeding the Principled BSDF's Base Color and the
normal map a Normal Map node feeding its Normal. It reports what Blender built rather than
judging it, so the expectations stay in the test. It is not collected by pytest (no ``test_``
prefix) and needs ``bpy``, which only exists inside Blender.

Exit status 3 (and a line on standard error) when this Blender has no glTF importer, or its
Python no numpy (the importer needs it; Debian's ``blender`` package does not pull in
``python3-numpy``): the test skips then, since that is the Blender install's gap, not bgr's.
"""

from __future__ import annotations

import json
import sys

import bpy

MAX_PIXELS = 64 * 64  # report every pixel of an image this small (the test's images are)


def upstream(socket, seen: set | None = None) -> list:
    """Every node that feeds ``socket``, directly or through other nodes (a Mix multiplying the
    colour factor in, a UV Map node, ...), nearest first."""
    seen = set() if seen is None else seen
    found = []
    for link in socket.links:
        node = link.from_node
        if node.name in seen:
            continue
        seen.add(node.name)
        found.append(node)
        for inp in node.inputs:
            found += upstream(inp, seen)
    return found


def texture_node(node) -> dict:
    """An Image Texture node: its image's name and the UV map it samples ('' = the default)."""
    uv = [n.uv_map for n in upstream(node.inputs["Vector"]) if n.type == "UVMAP"]
    return {"image": node.image.name if node.image else None, "uv_map": uv[0] if uv else ""}


def material_report(mat) -> dict:
    out: dict = {"name": mat.name, "base_color": [], "normal_map": None}
    out["blend_method"] = mat.blend_method
    if not mat.use_nodes:
        return out
    bsdfs = [n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED"]
    if not bsdfs:
        return out
    bsdf = bsdfs[0]
    feeding = upstream(bsdf.inputs["Base Color"])
    out["base_color"] = [texture_node(n) for n in feeding if n.type == "TEX_IMAGE"]
    for n in upstream(bsdf.inputs["Normal"]):
        if n.type == "NORMAL_MAP":
            images = [m for m in upstream(n.inputs["Color"]) if m.type == "TEX_IMAGE"]
            out["normal_map"] = {
                "uv_map": n.uv_map,
                "images": [texture_node(m) for m in images],
            }
            break
    return out


def image_report(image) -> dict:
    pixels = list(image.pixels[:])  # reading them loads the image: has_data is then meaningful
    w, h = image.size
    out = {
        "name": image.name,
        "size": [w, h],
        "channels": image.channels,
        "has_data": bool(image.has_data),
        "colorspace": image.colorspace_settings.name,
        "packed": image.packed_file is not None,
    }
    if 0 < w * h <= MAX_PIXELS:
        out["pixels"] = pixels  # RGBA floats, bottom row first (Blender's image origin)
    return out


def object_report(obj) -> dict:
    mesh = obj.data
    world = obj.matrix_world
    names = [slot.material.name if slot.material else None for slot in obj.material_slots]
    layers = []
    for layer in mesh.uv_layers:
        loops = []
        for poly in mesh.polygons:
            mat = names[poly.material_index] if poly.material_index < len(names) else None
            for li in poly.loop_indices:
                co = world @ mesh.vertices[mesh.loops[li].vertex_index].co
                u, v = layer.data[li].uv
                loops.append([co.x, co.y, co.z, u, v, mat])
        layers.append({"name": layer.name, "loops": loops})  # [x, y, z, u, v, material]
    return {
        "name": obj.name,
        "polygons": len(mesh.polygons),
        "materials": names,
        "uv_layers": layers,
    }


def main() -> None:
    args = sys.argv[sys.argv.index("--") + 1 :]
    source, target = args[0], args[1]
    bpy.ops.wm.read_factory_settings(use_empty=True)  # no default cube, camera or light
    if not hasattr(bpy.types, "IMPORT_SCENE_OT_gltf"):  # the add-on is missing or disabled
        print("this Blender has no glTF importer (io_scene_gltf2)", file=sys.stderr)
        sys.exit(3)
    try:  # the importer needs numpy, which Debian's blender package does not depend on
        import numpy
    except ImportError:
        print(
            "this Blender's Python has no numpy (Debian: apt-get install python3-numpy)",
            file=sys.stderr,
        )
        sys.exit(3)
    if not hasattr(numpy, "bool"):
        # Blender 3.4's importer writes np.bool, an alias of bool that numpy 1.24 removed; Debian
        # pairs it with numpy 1.24 (KhronosGroup/glTF-Blender-IO#1844, fixed in Blender 3.5 by
        # #1831, which wrote bool instead): give it back the alias, what the fix amounts to
        numpy.bool = bool
    bpy.ops.import_scene.gltf(filepath=source)
    objects = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    used = {s.material.name for o in objects for s in o.material_slots if s.material}
    report = {
        "blender": bpy.app.version_string,
        "objects": [object_report(o) for o in objects],
        "materials": [material_report(m) for m in bpy.data.materials if m.name in used],
        "images": [image_report(i) for i in bpy.data.images if i.type == "IMAGE"],
    }
    with open(target, "w", encoding="utf-8") as f:
        json.dump(report, f)


main()
