"""The faces of a captured model's blocks, built in world coordinates and checked.

:func:`_faces_of` turns each face of a block, floor by floor, into a :class:`.model.Face` whose
cell tree is the file's subfaces (:func:`_build_cell`), checking that sizes sum to their cell;
:func:`_attachments` checks that attached faces are coplanar, face each other and overlap, and
says which faces an attachment hides.
"""

from __future__ import annotations

import math
import re

from bgr.grammar.errors import suggest

from .captured_checks import _join, _num
from .captured_geometry import (
    _face_names,
    _Frame,
    _names_hint,
    _normal,
    _outline,
    _side_of,
)
from .captured_reader import _Reader
from .captured_schema import GEOM_TOL, PLAIN, TOL
from .model import Cell, Face
from .terminal_cells import _set_fixed


def _build_cell(
    reader: _Reader,
    sub: dict,
    width: float,
    height: float,
    where: str,
    size: float,
    floor_name: str | None = None,
) -> Cell:
    """The Cell of one subface whose rectangle is width x height; ``size`` is its extent along its
    parent's axis.  Sums are checked on the way."""
    label = sub.get("label")
    if "split" not in sub:
        reader.use_label(label, f"{where}.label")
        cell = Cell(size, label, fixed=reader.is_fixed(label))
    else:
        axis, parts = sub["split"], sub["parts"]
        full = width if axis == "x" else height
        total = math.fsum(p["size"] for p in parts)
        if not abs(total - full) <= TOL:
            what = "wide" if axis == "x" else "tall"
            reader.fail(
                where,
                f"the parts (split {axis}) sum to {_num(total)} m but the subface is "
                f"{_num(full)} m {what}",
                f"difference {_num(full - total)} m; sizes: "
                + " + ".join(_num(p["size"]) for p in parts),
            )
        cells = []
        for k, p in enumerate(parts):
            s = float(p["size"])
            w, h = (s, height) if axis == "x" else (width, s)
            cells.append(_build_cell(reader, p, w, h, f"{where}.parts[{k}]", s))
        cell = Cell(size, label or floor_name, axis=axis, parts=cells)
    if sub.get("occluded"):
        cell.occluded = True
        for leaf in cell.leaves():
            leaf.occluded = True
    return cell


def _camel(*parts: str) -> str:
    words = [w for p in parts for w in re.split(r"[^A-Za-z0-9]+", p) if w]
    return "".join(w[:1].upper() + w[1:] for w in words) or "Face"


def _faces_of(reader: _Reader, b: dict, i: int, frame: _Frame) -> list[tuple[str, Face]]:
    where = f"blocks[{i}]"
    floors = reader.floors(b, where)
    height = float(b["size"][1])
    names = _face_names(b)
    given = b.get("faces", {})
    for name in given:
        if name not in names:
            reader.fail(
                _join(f"{where}.faces", name),
                f"not a face of this {b['shape']}",
                suggest(name, names) or _names_hint(b),
            )
    plain = b.get("plain", PLAIN)
    reader.use_label(plain, f"{where}.plain" if "plain" in b else where)
    out = []
    for name, origin, x_axis, width in _outline(b):
        fwhere = _join(f"{where}.faces", name)
        if not width > TOL:
            reader.fail(
                fwhere,
                f"the face is {_num(width)} m wide: too narrow to check its subfaces",
                "faces are at least 1e-6 m wide: check the block's size",
            )
            continue
        subs = given.get(name)
        if subs is not None and len(subs) != len(floors):
            reader.fail(
                fwhere,
                f"{len(subs)} subface{'s' * (len(subs) != 1)} for {len(floors)} "
                f"floor{'s' * (len(floors) != 1)}",
                "one subface per floor, bottom to top: "
                + ", ".join(n or f"floor {k}" for k, (n, _) in enumerate(floors)),
            )
            subs = None
        cells = []
        for k, (floor_name, fh) in enumerate(floors):
            if subs is None:
                cells.append(Cell(fh, plain, fixed=reader.is_fixed(plain)))
                continue
            sub = subs[k]
            swhere = f"{fwhere}[{k}]"
            if "size" in sub and not abs(sub["size"] - fh) <= TOL:
                reader.fail(
                    f"{swhere}.size",
                    f"{_num(sub['size'])} m, but floor {k}"
                    f"{' (' + repr(floor_name) + ')' if floor_name else ''} is {_num(fh)} m tall",
                    "a floor's subface may leave size out: it is the floor's height",
                )
            cells.append(_build_cell(reader, sub, width, fh, swhere, fh, floor_name))
        root = Cell(width, axis="y", parts=cells)
        _set_fixed(root, None)
        world_x = frame.direction(x_axis)
        normal = _normal(world_x)
        face = Face(
            width,
            height,
            root,
            side=_side_of(_normal(x_axis)),
            name=_camel(b["id"], name),
            origin=frame.point(origin),
            x_axis=world_x,
            normal=normal,
        )
        out.append((name, face))
    return out


def _attachments(
    reader: _Reader, blocks: list[dict], faces: list[dict[str, Face]], ids: dict[str, int]
) -> tuple[set[int], set[int]]:
    """(the faces an attachment covers completely, the faces whose left end it covers), as ids
    of Face objects; checks that attached faces are coplanar, face each other and overlap."""
    hidden: set[int] = set()
    start_covered: set[int] = set()
    for i, b in enumerate(blocks):
        for k, att in enumerate(b.get("attach", [])):
            where = f"blocks[{i}].attach[{k}]"
            a = faces[i][att["face"]]
            other = faces[ids[att["to"]]][att["to_face"]]
            pair = (
                f"face {att['face']!r} of {b['id']!r} and face {att['to_face']!r} of {att['to']!r}"
            )
            facing = sum(a.normal[j] * other.normal[j] for j in range(3))
            gap = sum((other.origin[j] - a.origin[j]) * a.normal[j] for j in range(3))
            if not facing <= -1 + 1e-9:
                reader.fail(
                    where,
                    f"{pair} do not face each other",
                    "attached faces are coplanar with "
                    "opposite normals: check the blocks' transforms",
                )
                continue
            if not abs(gap) <= GEOM_TOL:
                reader.fail(
                    where,
                    f"{pair} are {_num(abs(gap))} m apart",
                    "attached faces are coplanar: check the blocks' sizes and transforms",
                )
                continue
            for face, cover in ((a, other), (other, a)):
                covered, touch, start = _covers(cover, face)
                if not touch:
                    reader.fail(
                        where,
                        f"{pair} are in one plane but do not overlap",
                        "check the blocks' sizes and transforms",
                    )
                    break
                if covered:
                    hidden.add(id(face))
                if start:
                    start_covered.add(id(face))
    return hidden, start_covered


def _covers(cover: Face, face: Face) -> tuple[bool, bool, bool]:
    """Whether ``cover`` (in the same plane) hides all of ``face``, overlaps it at all, and
    hides the bottom of its left end."""
    u0 = sum((cover.origin[j] - face.origin[j]) * face.x_axis[j] for j in range(3))
    u1 = u0 + cover.width * sum(cover.x_axis[j] * face.x_axis[j] for j in range(3))
    lo, hi = min(u0, u1), max(u0, u1)
    y_lo, y_hi = cover.origin[1], cover.origin[1] + cover.height
    f_lo, f_hi = face.origin[1], face.origin[1] + face.height
    touch = (
        min(hi, face.width) - max(lo, 0.0) > GEOM_TOL
        and min(y_hi, f_hi) - max(y_lo, f_lo) > GEOM_TOL
    )
    across = y_lo <= f_lo + GEOM_TOL and y_hi >= f_hi - GEOM_TOL
    covered = touch and across and lo <= GEOM_TOL and hi >= face.width - GEOM_TOL
    start = touch and lo <= GEOM_TOL and y_lo <= f_lo + GEOM_TOL
    return covered, touch, start
