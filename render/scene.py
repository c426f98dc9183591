"""What the renderer draws: world triangles with a colour, a part and a label each.

Every source (a derivation ``Result``, a ``.bgr`` file, a ``.glb``/``.gltf``/``.obj``/``.ply``
or CityGML ``.gml`` file, a trimesh) is turned into one :class:`Scene` (render/scene_model.py)
so that the rasterisers and the image modes never care where the triangles came from.  A
textured source (a grammar's ``texture()``, a glTF or OBJ material with an image, a CityGML
file) also gives each triangle its image and texture coordinates (render/textured.py); a model
with textures is read by the textured-model readers (formats/textured_model.py), one without by
the readers below.

* ``part`` says where a triangle came from: the row of its terminal in the derivation's terminal
  table (so a pixel's triangle leads to the terminal's path, rule and scope), or its material's
  index for a glTF file, which keeps no terminals (-1: no material), or its colour's index for
  a bare trimesh.
* ``label`` is what the ``labels`` mode colours by.  For a derivation it is the terminal's label
  (``label()`` in the grammar, else its rule name).  A glTF file written by bgr keeps materials
  but not terminal labels, so its triangles are labelled by material: the ``material()`` name
  when the grammar gave one, else the colour as ``#rrggbb``.  A foreign glTF file is labelled the
  same way, by its materials' names (or colours, for unnamed materials); triangles without any
  material get the label ``(none)``.  An ``.obj`` is labelled by material too (bgr's colour
  materials ``c_rrggbb`` as ``#rrggbb``), a ``.ply`` by colour.  For exact terminal labels,
  render the ``.bgr`` itself.
"""

from __future__ import annotations

import contextlib
import math
import os
from collections.abc import Iterable, Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from ..grammar.errors import BgrError, Diagnostic
from .scene_model import NO_LABEL as NO_LABEL
from .scene_model import Scene as Scene
from .scene_model import labels_index as labels_index


def lots_front(lots: list) -> np.ndarray | None:
    """The way a derivation's lots face, for the views: each lot's front faces against its
    scope's z (its front edge's outward normal), weighted by the front edge's length (the
    scope's x size).  The result is the weighted mean over the lots facing within 90 degrees of
    the direction the most front length faces (a sum of ``w max(0, cos)`` over whole degrees), so
    that the two sides of a street, facing each other, do not cancel out; None without lots."""
    normals, weights = [], []
    for lot in lots:
        try:
            z = np.asarray(lot["axes"], dtype=np.float64).reshape(3, 3)[2]
            width = float(np.asarray(lot.get("size", (1.0,)), dtype=np.float64).reshape(-1)[0])
        except (AttributeError, KeyError, TypeError, ValueError):
            continue
        n = np.array([-z[0], -z[2]])
        length = float(np.hypot(*n))
        if not (np.isfinite(n).all() and length > 1e-9):
            continue
        normals.append(n / length)
        weights.append(width if math.isfinite(width) and width > 0 else 1.0)
    if not normals:
        return None
    n, w = np.array(normals), np.array(weights)
    # the weights in 360 one-degree bins, then the best of 360 directions by sum w max(0, cos)
    bins = np.rint(np.degrees(np.arctan2(n[:, 1], n[:, 0]))).astype(np.int64) % 360
    mass = np.bincount(bins, weights=w, minlength=360)
    angle = np.radians(np.arange(360))
    score = np.maximum(np.cos(angle[:, None] - angle[None, :]), 0.0) @ mass
    best = angle[int(np.argmax(score))]
    side = n @ np.array([math.cos(best), math.sin(best)]) > 1e-9
    mean = (w[side, None] * n[side]).sum(axis=0)
    length = float(np.linalg.norm(mean))
    if not length > 1e-9:  # cannot happen with lots in that half-plane; be safe
        return None
    return np.array([mean[0] / length, 0.0, mean[1] / length])


_labels_index = labels_index


def from_result(result: Any) -> Scene:
    """A derivation's terminals: part = terminal row, label = terminal label; the colour maps
    of textured terminals with their coordinates (render/textured.py)."""
    from ..formats.meshes import MeshPool, bake, srgb8

    table = result.terminals if hasattr(result, "terminals") else result
    table.freeze()
    pool = MeshPool.of(table)
    baked = bake(table, pool=pool)
    row = np.repeat(np.arange(len(table), dtype=np.int64), np.diff(baked.fstart))
    label_of_row, labels = _labels_index(table.label) if len(table) else (np.zeros(0, np.int64), [])
    texture = uv = None
    textures: list = []
    if len(getattr(table, "tex_rows", ())):
        from .textured import table_textures

        texture, uv, textures = table_textures(table, pool, baked.fstart)
    return Scene(
        texture=texture,
        uv=uv,
        textures=textures,
        triangles=baked.vertices[baked.faces],
        colors=srgb8(table)[row],
        part=row,
        label=label_of_row[row],
        labels=labels,
        warnings=list(getattr(result, "warnings", [])),
        front=lots_front(table.lots),
    )


def _finite(scene: Scene, shown: str) -> Scene:
    """``scene`` when every corner of a model read from ``shown`` is finite and within
    MAX_INPUT_COORDINATE of the origin, as bgr's model readers require; else a located error.
    An OBJ without a readable MTL is read by trimesh, which takes ``v 0 1e400 0`` as inf: the
    camera and the clipping made NaN of it (numpy's warnings on the terminal)."""
    from ..interpreter.limits import MAX_INPUT_COORDINATE

    if scene.triangles.ndim != 3 or scene.triangles.shape[1:] != (3, 3):
        # trimesh reads an OBJ whose vertices are all 2 numbers as 2D points
        raise BgrError(
            Diagnostic(shown, 0, 0, "its vertices are not 3D points (x y z)", "write v x y z")
        )
    corners = scene.triangles.reshape(-1, 3)
    bad = ~(np.abs(corners) <= MAX_INPUT_COORDINATE).all(axis=1)
    if bad.any():
        point = ", ".join(f"{c:.6g}" for c in corners[int(np.argmax(bad))])
        raise BgrError(
            Diagnostic(
                shown,
                0,
                0,
                f"a vertex ({point}) is not finite or lies beyond {MAX_INPUT_COORDINATE:.0e}",
                "bgr draws models in metres about their centre",
            )
        )
    return scene


def _distinct(scene: Scene) -> Scene:
    """``scene`` with each triangle that repeats an earlier one exactly (its corners, colour,
    part, label, image and texture coordinates) kept once: it would cover the same pixels
    with the same colour.  100,000 copies of one OBJ face drawn through trimesh made 200,000
    triangles for the numpy rasteriser (5 s).  A weighted sum of each row, sorted, shows
    first whether any row can repeat (distinct sums: none does), so a model without copies
    pays one sort of T numbers."""
    T = len(scene)
    if T < 2:
        return scene
    cols = [
        scene.triangles.reshape(T, 9),
        scene.colors.astype(np.float64),
        scene.part[:, None].astype(np.float64),
        scene.label[:, None].astype(np.float64),
    ]
    if scene.texture is not None and scene.uv is not None:
        cols += [scene.texture[:, None].astype(np.float64), scene.uv.reshape(T, 6)]
    rows = np.ascontiguousarray(np.hstack(cols))
    weights = np.random.default_rng(0).uniform(1.0, 2.0, rows.shape[1])
    with np.errstate(over="ignore", invalid="ignore"):
        sums = rows @ weights
    if len(np.unique(sums)) == T:
        return scene
    _, first = np.unique(rows, axis=0, return_index=True)
    if len(first) == T:
        return scene
    keep = np.sort(first)
    return replace(
        scene,
        triangles=scene.triangles[keep],
        colors=scene.colors[keep],
        part=scene.part[keep],
        label=scene.label[keep],
        texture=None if scene.texture is None else scene.texture[keep],
        uv=None if scene.uv is None else scene.uv[keep],
    )


def from_trimesh(
    mesh: Any, material_names: list[str] | None = None, material_of_face: np.ndarray | None = None
) -> Scene:
    """A trimesh: colours from its face colours; parts and labels by material when known, else
    by colour."""
    faces = np.asarray(mesh.faces, dtype=np.int64).reshape(-1, 3)
    triangles = (
        np.asarray(mesh.vertices, dtype=np.float64)[faces] if len(faces) else np.zeros((0, 3, 3))
    )
    try:
        rgb = np.asarray(mesh.visual.face_colors, dtype=np.uint8)[:, :3]
    except Exception:  # noqa: BLE001  # pragma: no cover - a visual that has no face colours
        rgb = np.full((len(faces), 3), 200, dtype=np.uint8)
    if len(rgb) != len(faces):
        rgb = np.full((len(faces), 3), 200, dtype=np.uint8)
    if (
        material_of_face is not None
        and material_names is not None
        and len(material_of_face) == len(faces)
    ):
        names = [NO_LABEL if m < 0 else material_names[m] for m in range(-1, len(material_names))]
        label, labels = _labels_index(names[m + 1] for m in material_of_face)
        part = material_of_face.astype(np.int64)
    else:
        packed = (rgb[:, 0].astype(np.int64) << 16) | (rgb[:, 1].astype(np.int64) << 8) | rgb[:, 2]
        _, part = np.unique(packed, return_inverse=True)
        label, labels = _labels_index(f"#{p:06x}" for p in packed)
        part = part.reshape(-1).astype(np.int64)
    return Scene(triangles=triangles, colors=rgb.copy(), part=part, label=label, labels=labels)


def _glb_materials(gltf: dict, blob: bytes) -> tuple[list[str], np.ndarray]:
    """(material names, material index of each face) in the order ``world_mesh`` emits faces.

    ``world_mesh`` keeps no material per face, so this walks the same nodes, instances and
    primitives in the same order (``mesh_nodes``), counting faces from the accessors' ``count``
    alone.  It runs after ``world_mesh``, which has checked all of them.
    """
    from ..formats.glb_read import instance_count, mesh_nodes, scene_roots, triangle_primitives

    names = []
    materials = gltf.get("materials")
    for k, mat in enumerate(materials if isinstance(materials, list) else []):
        mat = mat if isinstance(mat, dict) else {}
        extras = mat.get("extras") if isinstance(mat.get("extras"), dict) else {}
        name = extras.get("material") or mat.get("name") or extras.get("color")
        names.append(name if isinstance(name, str) else f"material {k}")
    out: list[np.ndarray] = []
    for i, node, _ in mesh_nodes(gltf, scene_roots(gltf)):
        copies = instance_count(gltf, blob, node, i) or 1
        for _, prim in triangle_primitives(gltf, node, i):
            source = prim["indices"] if "indices" in prim else prim["attributes"]["POSITION"]
            n = gltf["accessors"][source]["count"] // 3 * copies
            out.append(np.full(n, prim.get("material", -1), dtype=np.int64))
    return names, (np.concatenate(out) if out else np.zeros(0, dtype=np.int64))


@contextlib.contextmanager
def _model_errors(shown: str, what: str, hint: str, caught: tuple = (Exception,)) -> Iterator[None]:
    """Every failure reading the model file ``shown`` as one located BgrError: a missing or
    unreadable file, or one the reader cannot parse (``caught``: what it raises on bad input)."""
    try:
        yield
    except FileNotFoundError:
        raise BgrError(Diagnostic(shown, 0, 0, "no such file", "check the path")) from None
    except BgrError as exc:
        if exc.path:  # located already (the model at its line, or its MTL file): keep it
            raise
        raise BgrError(Diagnostic(shown, 0, 0, exc.message, exc.hint)) from None
    except OSError as exc:
        raise BgrError(
            Diagnostic(shown, 0, 0, f"cannot read the file: {exc.strerror or exc}")
        ) from None
    except caught as exc:
        message = f"not {what} bgr can read ({type(exc).__name__}: {exc})"[:300]
        raise BgrError(Diagnostic(shown, 0, 0, message, hint)) from None


def _gltf_textured(gltf: dict) -> bool:
    """Whether a glTF file's materials show images (then its textured reader draws it)."""
    materials = gltf.get("materials")
    if not gltf.get("images") or not isinstance(materials, list):
        return False
    for mat in materials:
        pbr = mat.get("pbrMetallicRoughness") if isinstance(mat, dict) else None
        if isinstance(pbr, dict) and isinstance(pbr.get("baseColorTexture"), dict):
            return True
    return False


def from_citygml(path: str | os.PathLike) -> Scene:
    """A CityGML 2.0 file with its textures (formats/citygml_read.py), z up turned to y up in a
    local metric frame (render/textured.py: a geographic CRS on a local transverse Mercator);
    labels by semantic surface type."""
    from ..formats.citygml_read import read_citygml
    from .textured import from_textured_mesh

    return from_textured_mesh(read_citygml(path), str(path))


def from_gltf(path: str | os.PathLike) -> Scene:
    """A .glb or .gltf file, instances expanded (``read_glb``); parts and labels by material."""
    from ..formats.glb_read import load, scene_roots, world_mesh

    shown = str(path)
    with _model_errors(
        shown,
        "a glTF 2.0 file",
        "bgr reads triangle meshes with float positions",
        (ValueError, KeyError, IndexError, TypeError, AttributeError, StopIteration),
    ):
        gltf, blob = load(path)
        if _gltf_textured(gltf):
            from ..formats.gltf_textured import read_gltf_textured
            from .textured import from_textured_mesh

            return from_textured_mesh(read_gltf_textured(path), shown)
        mesh = world_mesh(gltf, blob, scene_roots(gltf))
        names, material = _glb_materials(gltf, blob)
    return from_trimesh(mesh, names, material)


def _mtl_libraries(path: Path, data: bytes) -> tuple[dict[str, bytes], list[Diagnostic]]:
    """The material libraries an OBJ names (``mtllib``), read from its own folder only, and a
    warning for each that cannot be read (its faces are drawn grey)."""
    from ..grammar.paths import read_input

    shown, folder = str(path), path.resolve().parent
    found: dict[str, bytes] = {}
    warnings: list[Diagnostic] = []
    seen: set[str] = set()
    for line in data.splitlines():
        if not line.startswith(b"mtllib"):
            continue
        name = line[len(b"mtllib") :].decode("utf-8", "replace").strip()
        if not name or name in seen:
            continue
        seen.add(name)
        where = (folder / name).resolve()
        problem = None
        if not where.is_relative_to(folder):
            problem = "it is outside the OBJ's folder"
        else:
            try:
                found[name] = read_input(where, "material library")
            except FileNotFoundError:
                problem = "no such file beside the OBJ"
            except BgrError as exc:
                problem = exc.message
            except OSError as exc:
                problem = exc.strerror or "unreadable"
        if problem:
            warnings.append(
                Diagnostic(
                    shown,
                    0,
                    0,
                    f"material library '{name}' not read ({problem}): its faces are drawn grey",
                    "keep the .mtl that bgr derive wrote next to the .obj",
                    severity="warning",
                )
            )
    return found, warnings


def _material_label(name: str | None) -> str:
    """An OBJ material's label: bgr names a colour material c_rrggbb, shown as #rrggbb."""
    if not name:
        return NO_LABEL
    if len(name) == 8 and name.startswith("c_"):
        with contextlib.suppress(ValueError):
            int(name[2:], 16)
            return "#" + name[2:]
    return name


def _has_colour_map(mtl: bytes) -> bool:
    """Whether a material library names a colour map (``map_Kd``) on some line."""
    return any(line.strip().lower().startswith(b"map_kd") for line in mtl.splitlines())


def from_mesh_file(path: str | os.PathLike) -> Scene:
    """A .obj (colours from the .mtl files it names, labels and parts by material) or a .ply
    (vertex or face colours, labels and parts by colour), read with trimesh."""
    import io
    import logging

    import trimesh

    from ..grammar.paths import read_input

    shown, path = str(path), Path(path)
    fmt = path.suffix.lower().lstrip(".")
    quiet = logging.getLogger("trimesh")
    level = quiet.level
    try:
        with _model_errors(
            shown,
            f"a .{fmt} file",
            "bgr reads triangle meshes (OBJ with its .mtl, PLY with vertex or face colours)",
        ):  # trimesh's parsers raise many kinds of exception
            data = read_input(path, "model file")
            libraries, warnings = _mtl_libraries(path, data) if fmt == "obj" else ({}, [])
            if any(_has_colour_map(mtl) for mtl in libraries.values()):
                from ..formats.obj_textured import read_obj_textured
                from .textured import from_textured_mesh

                return from_textured_mesh(read_obj_textured(path), shown)
            stream: io.IOBase = io.BytesIO(data)
            if fmt == "obj":  # a text file: bytes that are not text are no OBJ
                if b"\0" in data:
                    hint = "bgr renders .bgr, .glb, .gltf, .obj (with its .mtl) and .ply files"
                    message = "a binary file, not a Wavefront OBJ (a text file)"
                    raise BgrError(Diagnostic(shown, 0, 0, message, hint))
                stream = io.StringIO(data.decode("utf-8", "replace"))
            # a missing material is said once, by the warning above
            quiet.setLevel(logging.CRITICAL)
            loaded = trimesh.load(
                stream, file_type=fmt, resolver=libraries, process=False, force="scene"
            )
            meshes = [m for m in loaded.dump(concatenate=False) if len(getattr(m, "faces", ()))]
    finally:
        quiet.setLevel(level)
    if not meshes:
        raise BgrError(
            Diagnostic(shown, 0, 0, "no triangles to draw", f"the .{fmt} file has no faces")
        )
    triangles, colors, names = [], [], []
    for mesh in meshes:
        faces = np.asarray(mesh.faces, dtype=np.int64).reshape(-1, 3)
        triangles.append(np.asarray(mesh.vertices, dtype=np.float64)[faces])
        material = getattr(mesh.visual, "material", None)
        if material is not None:  # an OBJ: one material per mesh
            rgb = np.asarray(material.main_color, dtype=np.uint8)[:3]
            colors.append(np.tile(rgb, (len(faces), 1)))
            names += [_material_label(getattr(material, "name", None))] * len(faces)
        else:  # a PLY: vertex colours (averaged over a face) or face colours
            rgb = np.asarray(mesh.visual.face_colors, dtype=np.uint8)[:, :3]
            colors.append(rgb)
            names += [f"#{r:02x}{g:02x}{b:02x}" for r, g, b in rgb.tolist()]
    label, labels = _labels_index(names)
    return Scene(
        triangles=np.concatenate(triangles),
        colors=np.concatenate(colors),
        part=label.copy(),
        label=label,
        labels=labels,
        warnings=warnings,
    )


def load_scene(
    source: Any,
    *,
    seed: int = 0,
    attrs: dict | None = None,
    lot: Any = None,
    max_depth: int | None = None,
    max_shapes: int | None = None,
    strict: bool = False,
    max_triangles: int | None = None,
    max_memory: int | None = None,
    allow_paths: Iterable[str | os.PathLike] = (),
    lot_options: Any = None,
) -> Scene:
    """A :class:`Scene` from a Scene, a ``bgr.Result``, a terminal table, a trimesh, or a path to
    a ``.bgr`` (loaded with ``allow_paths`` as :func:`bgr.load`, derived with ``seed``,
    ``attrs``, ``lot`` and ``strict``, its warnings kept in ``Scene.warnings``), ``.glb``,
    ``.gltf``, ``.obj``, ``.ply`` or CityGML 2.0 ``.gml`` file.  ``lot_options`` (a LotOptions:
    --front, --map) go to the derivation."""
    if isinstance(source, Scene):
        return source
    if isinstance(source, (str, os.PathLike)):
        path = Path(source)
        suffix = path.suffix.lower()
        if suffix == ".bgr":
            from ..grammar.loader import load
            from ..interpreter.derive import derive

            limits = {
                k: v
                for k, v in (
                    ("max_depth", max_depth),
                    ("max_shapes", max_shapes),
                    ("max_triangles", max_triangles),
                    ("max_memory", max_memory),
                )
                if v is not None
            }
            from ..interpreter.lots import check_mapping

            grammar = load(path, path=str(source), allow_paths=allow_paths)
            check_mapping(lot_options, grammar.attrs, str(source))
            result = derive(
                grammar,
                seed=seed,
                attrs=attrs,
                lot=lot,
                strict=strict,
                lot_options=lot_options,
                **limits,
            )
            return from_result(result)
        if suffix in (".glb", ".gltf"):
            return _distinct(_finite(from_gltf(path), str(source)))
        if suffix in (".obj", ".ply"):
            return _distinct(_finite(from_mesh_file(path), str(source)))
        if suffix == ".gml":
            return _distinct(_finite(from_citygml(path), str(source)))
        raise BgrError(
            Diagnostic(
                str(source),
                0,
                0,
                f"cannot render a '{suffix or 'extensionless'}' file",
                "give a .bgr grammar or a .glb, .gltf, .obj, .ply or CityGML .gml model",
            )
        )
    if hasattr(source, "terminals") or hasattr(source, "library"):
        return from_result(source)
    if hasattr(source, "vertices") and hasattr(source, "faces"):
        return from_trimesh(source)
    raise BgrError(
        f"cannot render a {type(source).__name__}; give a bgr Result, a trimesh or a file path"
    )
