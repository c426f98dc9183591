"""The readers of ``bgr infer --kind city``: a 3D city file in, a :class:`CityScene` of objects out.

One public function, :func:`read_city`, which picks the reader by the file's extension
(:func:`format_of`).  Every format goes through the same steps:

1. **Read** the file's triangles in its own frame, and which object each belongs to: CityJSON
   city objects (:mod:`.read_cityjson`), OBJ ``o`` objects, else ``g`` groups
   (:mod:`.read_obj`), the nodes of a glTF scene (:mod:`.read_gltf`).  Inputs without objects
   (a PLY, :mod:`.read_ply`; an OBJ of bare faces; a glTF of one node) are cut into connected
   components, merged where their ground-plane boxes overlap (:func:`components`).
2. **Check** what no later step can use: coordinates that are not finite numbers or lie
   beyond 1e8 m (:mod:`.coordinates`), an empty scene.  Triangles that repeat a vertex are
   dropped without a word: exporters write them.
3. **Orient and re-centre**: the up axis (:func:`up_axis`), an offset of whole metres so that
   projected coordinates (hundreds of kilometres) become small (:func:`offset_of`), then the turn
   into bgr's y-up frame (:meth:`CityScene.from_input`), in float64.  Steps 2 and 3 are the same
   for every format (:mod:`.read_scene`).

Every failure is a :class:`BgrError` naming the file (and, for OBJ, the line and column).
"""

from __future__ import annotations

from pathlib import Path

from bgr.grammar.errors import BgrError, Diagnostic

from .model import CityScene
from .read_cityjson import PROCEDURAL_TYPES as PROCEDURAL_TYPES
from .read_cityjson import _read_cityjson
from .read_gltf import _read_gltf
from .read_obj import OBJ_VERTEX as OBJ_VERTEX
from .read_obj import VERTEX_WIDTHS as VERTEX_WIDTHS
from .read_obj import ObjParse as ObjParse
from .read_obj import ObjText as ObjText
from .read_obj import _bulk as _bulk
from .read_obj import _face_lines as _face_lines
from .read_obj import _read_obj
from .read_obj import _vertex_lines as _vertex_lines
from .read_obj import triangulate as triangulate
from .read_ply import _read_ply
from .read_scene import LIFT_FROM as LIFT_FROM
from .read_scene import RECENTRE_FROM as RECENTRE_FROM
from .read_scene import Found as Found
from .read_scene import _read_bytes, _reason, _scene
from .read_scene import offset_of as offset_of
from .read_scene import up_axis as up_axis

__all__ = ["read_city"]  # the readers are in the modules above (tests reach into some here)

# extension (lower case) -> format; the longest matching extension wins
EXTENSIONS = {
    ".obj": "obj",
    ".ply": "ply",
    ".glb": "gltf",
    ".gltf": "gltf",
    ".city.json": "cityjson",
    ".json": "cityjson",
    ".city.jsonl": "cityjsonl",
    ".jsonl": "cityjsonl",
}
ACCEPTED = ".obj, .ply, .glb, .gltf, .city.json (.json) and .city.jsonl (.jsonl)"
UPS = ("auto", "y", "z")


# --------------------------------------------------------------------------------------------
# the public function


def read_city(path: str | Path, *, up: str = "auto", lod: str | None = None) -> CityScene:
    """Read a 3D city (OBJ, PLY, glTF/GLB, CityJSON or CityJSON Text Sequences) as objects of
    triangles in bgr's frame: y up, metres, re-centred (the scene's ``offset`` puts it back).

    ``up``: the input's up axis, "y", "z", or "auto" (CityJSON is z up, glTF y up; OBJ and PLY
    are z up when their z extent is less than half their horizontal ones, else y up).
    ``lod``: the CityJSON level of detail to read (default: each object's highest); other
    formats have one geometry and refuse it.  Raises :class:`BgrError` naming the file."""
    shown = str(path)
    fmt = format_of(shown)
    if up not in UPS:
        raise BgrError(
            Diagnostic(shown, 0, 0, f"unknown up axis '{up}'", f"use one of {', '.join(UPS)}")
        )
    if lod is not None and not fmt.startswith("cityjson"):
        raise BgrError(
            Diagnostic(
                shown,
                0,
                0,
                "a level of detail only selects among CityJSON geometries",
                "leave out the lod: this file has one geometry per object",
            )
        )
    if fmt.startswith("cityjson") and up == "y":
        raise BgrError(
            Diagnostic(shown, 0, 0, "CityJSON is z up", "leave the up axis on auto, or z")
        )
    try:
        if fmt.startswith("cityjson"):
            found, up = _read_cityjson(path, lod), "z"
        elif fmt == "gltf":
            found, up = _read_gltf(path), "y" if up == "auto" else up
        else:
            data = _read_bytes(path, shown)
            found = _read_obj(shown, data) if fmt == "obj" else _read_ply(shown, data)
        return _scene(shown, found, up)
    except (
        ValueError,
        TypeError,
        IndexError,
        KeyError,
        AttributeError,
        OverflowError,
        RecursionError,
    ) as exc:
        # the readers turn what they expect into messages; this is what they did not foresee
        raise BgrError(
            Diagnostic(shown, 0, 0, f"cannot read the city file: {_reason(exc)}")
        ) from None


def format_of(shown: str) -> str:
    """The format of a path, from its extension; BgrError for one this module does not read."""
    lower = shown.lower()
    for ext in sorted(EXTENSIONS, key=len, reverse=True):
        if lower.endswith(ext):
            return EXTENSIONS[ext]
    raise BgrError(
        Diagnostic(
            shown,
            0,
            0,
            "cannot read this file as a city: its extension names no format bgr reads",
            f"bgr reads cities from {ACCEPTED}",
        )
    )
