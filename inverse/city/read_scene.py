"""What every city reader hands on, and how that becomes a :class:`CityScene`.

Each format's reader (:mod:`.read_obj`, :mod:`.read_ply`, :mod:`.read_gltf`,
:mod:`.read_cityjson`) returns a :class:`Found`: the file's triangles in its own frame and the
objects they belong to.  :func:`_scene` then does what is the same for every format: drops
triangles that repeat a vertex or an earlier face, checks the coordinates
(:mod:`.coordinates`), finds the up axis (:func:`up_axis`) and an offset of whole metres
(:func:`offset_of`), turns the triangles into bgr's y-up frame and splits them into objects
(connected components where the file has none).  The file reading and error wording that the
readers share (:func:`_read_bytes`, :func:`_reason`) are here too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from bgr.grammar.errors import BgrError, Diagnostic
from bgr.grammar.paths import read_input

from .coordinates import Locate, check_coordinates
from .model import CityObject, CityScene
from .objects import components, mark_surfaces, separate

RECENTRE_FROM = 1000.0  # metres: a horizontal centre farther than this from 0 is re-centred
LIFT_FROM = 100.0  # metres: a lowest point farther than this from 0 is brought to about 0


def _read_bytes(path: str | Path, shown: str) -> bytes:
    try:
        return read_input(path, "city file")
    except FileNotFoundError:
        raise BgrError(Diagnostic(shown, 0, 0, "no such city file")) from None
    except OSError as exc:
        raise BgrError(Diagnostic(shown, 0, 0, f"cannot read the city file: {exc}")) from None


def _reason(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0][:200] if text else type(exc).__name__


# --------------------------------------------------------------------------------------------
# what every reader hands on


@dataclass
class Found:
    """A file's triangles in its own frame, and the objects they belong to.

    ``owner`` is each face's index into ``objects`` (templates: name, kind, proceduralize and
    attributes; their vertices and faces are filled in by :func:`_scene`), or None when the file
    has no objects and connected components make them."""

    vertices: np.ndarray  # (V, 3) float64, the input's frame
    faces: np.ndarray  # (F, 3) int64
    colors: np.ndarray | None  # (F, 4) uint8
    owner: np.ndarray | None  # (F,) int64
    objects: list[CityObject] = field(default_factory=list)
    crs: str | None = None
    hint: str | None = None  # what to say when no triangles are left
    locate: Locate | None = None  # a bad vertex's error at its place in the file (OBJ: line)


def _template(name: str, kind: str = "object", **more) -> CityObject:
    return CityObject(name, kind, np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), **more)


def _scene(shown: str, found: Found, up: str) -> CityScene:
    """Checks, up axis, offset and bgr's frame; the objects filled in (see the module)."""
    faces = np.asarray(found.faces, dtype=np.int64).reshape(-1, 3)
    vertices = np.asarray(found.vertices, dtype=np.float64).reshape(-1, 3)
    has_area = (
        (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])
    )
    keep = np.flatnonzero(has_area)
    keep = keep[_first_of_each(faces[keep], None if found.owner is None else found.owner[keep])]
    faces = faces[keep]
    colors = None if found.colors is None else found.colors[keep]
    owner = None if found.owner is None else found.owner[keep]
    if not len(faces):
        hint = found.hint
        if hint is None and len(has_area):
            hint = f"each of its {len(has_area)} faces repeats a vertex: none has an area"
        raise BgrError(Diagnostic(shown, 0, 0, f"no triangles in {shown}", hint))
    check_coordinates(shown, vertices, faces, owner, found.objects, found.locate)
    mark = np.zeros(len(vertices), dtype=bool)
    mark[faces] = True
    used = vertices[mark]
    up = up_axis(used) if up == "auto" else up
    scene = CityScene([], shown, up, offset_of(used, up), found.crs)
    local = scene.from_input(vertices)
    objects = found.objects
    if owner is None:
        owner, count = components(local, faces)
        objects = [_template(f"object-{k}") for k in range(1, count + 1)]
    else:
        mark_surfaces(local, faces, owner, objects)  # roads and terrain of a typeless format
        owner, objects = separate(local, faces, owner, objects)
    scene.objects = _split(local, faces, colors, owner, objects)
    return scene


def _first_of_each(faces: np.ndarray, owner: np.ndarray | None) -> np.ndarray:
    """Positions (ascending) of the faces to keep when a face that repeats an earlier one of its
    object (the same three vertices in the same turning order) is dropped.

    A repeated face adds no surface, but each copy would be cut, fitted and hashed: a CityJSON
    surface listed 3,000 times took 10 s to infer.  A face and its reverse are both kept (a
    two-sided wall)."""
    if not len(faces):
        return np.zeros(0, dtype=np.int64)
    turn = np.argmin(faces, axis=1)  # rotate each face to start at its smallest index
    rows = np.take_along_axis(faces, (turn[:, None] + np.arange(3)) % 3, axis=1)
    key = np.column_stack([np.zeros(len(faces), np.int64) if owner is None else owner, rows])
    _, first = np.unique(key, axis=0, return_index=True)
    return np.sort(first)


def up_axis(points: np.ndarray) -> str:
    """ "z" when the points' z extent is less than half of both horizontal extents (x and y: a
    z-up city is wider than it is tall), else "y", OBJ's and glTF's convention."""
    extent = points.max(axis=0) - points.min(axis=0)
    return "z" if extent[2] < 0.5 * min(extent[0], extent[1]) else "y"


def offset_of(points: np.ndarray, up: str) -> np.ndarray:
    """The offset (input frame) that brings projected coordinates near 0: the bounding box's
    horizontal centre in whole metres when it is more than RECENTRE_FROM from 0, and the lowest
    point rounded down to a whole metre when it is more than LIFT_FROM from 0.  Whole metres
    keep the subtraction exact, so outputs land where the input was to the last digit."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    vertical = 2 if up == "z" else 1
    plan = [a for a in range(3) if a != vertical]
    offset = np.zeros(3)
    centre = (lo + hi) / 2
    if math.hypot(centre[plan[0]], centre[plan[1]]) > RECENTRE_FROM:
        offset[plan] = np.round(centre[plan])
    if abs(lo[vertical]) > LIFT_FROM:
        offset[vertical] = math.floor(lo[vertical])
    return offset


def _split(
    vertices: np.ndarray,
    faces: np.ndarray,
    colors: np.ndarray | None,
    owner: np.ndarray,
    objects: list[CityObject],
) -> list[CityObject]:
    """The objects with their own triangles and only the vertices those use (renumbered), in
    the order of ``objects``; objects left without triangles are dropped."""
    order = np.argsort(owner, kind="stable")
    faces, owner = faces[order], owner[order]
    # a vertex of object k is the pair (k, vertex): numbered within its object by rank
    pairs = owner[:, None] * len(vertices) + faces
    used, inverse = np.unique(pairs.reshape(-1), return_inverse=True)
    inverse = inverse.reshape(-1, 3)
    first_pair = np.searchsorted(used, np.arange(len(objects) + 1) * len(vertices))
    starts = np.searchsorted(owner, np.arange(len(objects) + 1))
    out = []
    for k, obj in enumerate(objects):
        lo, hi = starts[k], starts[k + 1]
        if lo == hi:
            continue
        mine = used[first_pair[k] : first_pair[k + 1]]
        obj.vertices = vertices[mine - k * len(vertices)]
        obj.faces = (inverse[lo:hi] - first_pair[k]).astype(np.int64)
        obj.colors = None if colors is None else colors[order[lo:hi]]
        out.append(obj)
    return out
