"""Capture (section 4): a textured model in, one style sheet section per building out.

The stages, each in its own module: the standard view and the remeshed floors, blocks and
walls (frame.py, remesh.py), the faces' textures (project.py), the consistent face groups and
their splitting rules (groups.py, rules.py), and the grammar (emit.py).
"""

from __future__ import annotations

import multiprocessing
import os
import sys
import threading
import time
from contextlib import closing
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from bgr.formats.textured_model import TexturedMesh
from bgr.grammar.errors import BgrError, Diagnostic

from .emit import Crops, style_text
from .groups import Groups, face_groups
from .model import Capture
from .project import face_textures, roof_color
from .remesh import capture_geometry, selection
from .snap import snap_faces

READERS = {
    ".gml": "citygml",
    ".xml": "citygml",
    ".obj": "obj",
    ".glb": "gltf",
    ".gltf": "gltf",
}


def read_model(path: str) -> TexturedMesh:
    """The textured model in ``path``, by its extension (CityGML, OBJ + MTL, glTF / GLB)."""
    kind = READERS.get(Path(path).suffix.lower())
    if kind == "citygml":
        from bgr.formats.citygml_read import read_citygml

        return read_citygml(path)
    if kind == "obj":
        from bgr.formats.obj_textured import read_obj_textured

        return read_obj_textured(path)
    if kind == "gltf":
        from bgr.formats.gltf_textured import read_gltf_textured

        return read_gltf_textured(path)
    raise BgrError(
        Diagnostic(
            path,
            0,
            0,
            "bgr infer --kind style reads a textured model: CityGML (.gml, .xml), OBJ with its "
            "MTL (.obj) or glTF (.glb, .gltf)",
            "export the building as one of these with its textures",
        )
    )


def building_ids(mesh: TexturedMesh, building: str | None) -> list[str | None]:
    """The buildings to capture: ``building`` alone; else, in a CityGML file, every building
    (object) with a textured face, in the file's order; else the whole model as one building
    (an OBJ's groups and a glTF's nodes are parts, not buildings).  A located error when no
    face is textured."""
    textured = mesh.textured()
    if not textured.any():
        raise BgrError(
            Diagnostic(
                mesh.source,
                0,
                0,
                "the model has no textured face: a style sheet is captured from a building's "
                "photographic textures",
                "give a model whose walls carry texture images (CityGML appearances, OBJ "
                "map_Kd, glTF baseColorTexture), with the images beside it",
            )
        )
    if building is not None:
        if not textured[selection(mesh, building)].any():  # an unknown id: a located error
            raise BgrError(
                Diagnostic(
                    mesh.source,
                    0,
                    0,
                    f"--building {building}: no face of that building is textured",
                    "pick a building whose walls carry texture images",
                )
            )
        return [building]
    if Path(mesh.source).suffix.lower() not in (".gml", ".xml"):
        return [None]
    used = np.unique(mesh.object[textured])
    return [mesh.object_ids[i] for i in used]


@dataclass
class Captured:
    """One building's capture: its remeshed structure, groups and rules, and the frame that
    maps the input into the standard view."""

    capture: Capture
    groups: Groups
    frame: object  # remesh.Frame
    seconds: float = 0.0
    notes: list[str] = field(default_factory=list)


def capture_building(
    mesh: TexturedMesh, building: str | None, texels_per_unit: float | None = None
) -> Captured:
    """Sections 4.1-4.3 for one building of ``mesh`` (None: the whole mesh as one)."""
    start = time.perf_counter()
    capture, frame = capture_geometry(mesh, building)
    select = (
        mesh.mask(object_id=building) if building is not None else np.ones(len(mesh.faces), bool)
    )
    vertices = frame.apply(mesh.vertices)
    face_textures(mesh, vertices, select, capture.faces, texels_per_unit)
    capture.roof = roof_color(mesh, vertices, select)
    snap_faces(capture)  # section 5.2.1 on the textured faces (snap.py says why)
    groups = face_groups(capture)
    return Captured(capture, groups, frame, time.perf_counter() - start)


def capture_buildings(mesh: TexturedMesh, ids: list[str | None]) -> list[Captured]:
    """:func:`capture_building` of each of ``ids``, in their order, on every core when there
    are several buildings: a building's capture is Python-bound (hundreds of small faces), so
    threads would queue on the GIL, and PLATEAU's 10 take 0.7 of the time on 2 cores.

    The workers are forked (they start at once, sharing the read model; a forkserver or a spawn
    would import bgr and receive the model again, which costs what they save), and only from a
    process with no other thread: a fork copies the locks other threads hold.  Elsewhere, and
    where fork is unavailable or unsafe (macOS, Windows), one building after another.  The
    sheet is the same either way."""
    workers = _capture_workers(len(ids))
    if workers <= 1:
        return [capture_building(mesh, b) for b in ids]
    from bgr.interpreter.workers import Pool

    pool = Pool(
        workers,
        multiprocessing.get_context("fork"),
        _adopt,
        (mesh,),
        doing="capturing",
        memory_hint="capture one building at a time with --building ID",
    )
    captured = []
    # closed on any exit: a raised error kills the workers still capturing
    with closing(pool.ordered(_capture_in_worker, iter(ids), 2 * workers, _building)) as results:
        for result in results:
            if isinstance(result, BgrError):  # the worker's located error, as the loop raises
                raise result
            captured.append(result)
    return captured


def _capture_workers(buildings: int) -> int:
    if buildings < 2 or not sys.platform.startswith("linux"):
        return 1
    if "fork" not in multiprocessing.get_all_start_methods() or threading.active_count() > 1:
        return 1
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return min(buildings, cores or 1)


_MESH: TexturedMesh | None = None  # a capture worker's model, set once when it starts


def _adopt(mesh: TexturedMesh) -> None:
    global _MESH
    _MESH = mesh


def _capture_in_worker(building: str | None) -> Captured | BgrError:
    assert _MESH is not None
    try:
        return capture_building(_MESH, building)
    except BgrError as error:  # sent back whole: the parent raises it as a located error
        return error


def _building(building: str | None) -> str:
    return "the model" if building is None else f"building {building}"


def infer_style(
    path: str,
    building: str | None = None,
    assets: str = "style.assets",
    max_texture_size: int = 512,
    mesh: TexturedMesh | None = None,
) -> tuple[str, dict[str, bytes], list[Captured]]:
    """The style sheet of the model in ``path``: its ``.bgr`` text, its crops (file name ->
    PNG bytes, for the folder the grammar names ``assets``) and each building's capture."""
    mesh = mesh if mesh is not None else read_model(path)
    captured = capture_buildings(mesh, building_ids(mesh, building))
    crops = Crops(assets, max_texture_size)
    text = style_text([(c.capture, c.groups) for c in captured], crops)
    return text, crops.files, captured
