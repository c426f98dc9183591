"""Read a terminal list (``bgr derive -o x.json``) into a :class:`Model` of subdivided faces.

A terminal list has no faces or floors, only labelled rectangles with derivation paths.  The
structure comes back from both:

* **paths** give the rule tree: every terminal under ``Lot/Mass.0/Front.1/`` was made by the
  rule application ``Front.1``, and the children of one application, in derivation order, are
  the pieces of its split;
* **geometry** says which subtree is one face (all its terminals flat, in one plane, with the
  same axes) and along which axis a rule's pieces lie (they tile its rectangle along x or y).

Where one rule body nests splits (no path element between them), the pieces are cut apart
geometrically (guillotine cuts).  Corners come from where faces meet: a face's right bottom
corner is its neighbour's left one.

The reader is in parts: :mod:`.terminal_list` reads and checks the list and rebuilds the rule
tree, :mod:`.terminal_planes` finds the subtrees that are faces, :mod:`.terminal_cells` turns
each into a cell tree and :mod:`.corners` links the faces at their corners.  This module puts
them together: :func:`model_from_terminals` reads the faces in their lots' frames and makes
blocks of them (rings of vertical faces, or the faces of a flat model).
"""

from __future__ import annotations

from pathlib import Path

from bgr.grammar.paths import read_json

from .corners import LINK, link_faces, side_of
from .model import Block, Face, Model
from .terminal_cells import _Builder, _Frame, _set_fixed, _union
from .terminal_list import TOL, _dot, _error, _Node, _Terminal, _tree, _vector, read_terminals
from .terminal_planes import DEPTH, MINOR, _face_nodes, _reference

__all__ = [
    "DEPTH",
    "LINK",
    "MINOR",
    "TOL",
    "link_faces",
    "load_terminal_list",
    "model_from_terminals",
    "read_terminals",
    "side_of",
]


def _lot_frames(data: dict, path: str) -> dict[str, tuple]:
    """The axes of each lot (``lots`` of the terminal list, written since this reader exists):
    a face's side is read in its lot's frame, as comp(f) reads it, not in the world's."""
    frames = {}
    lots = data.get("lots", [])
    if not isinstance(lots, list):
        raise _error(path, "'lots' must be a list")
    for i, lot in enumerate(lots):
        if not isinstance(lot, dict) or not isinstance(lot.get("path"), str):
            raise _error(path, f"lots[{i}] must be an object with a 'path'")
        axes = lot.get("axes")
        if not isinstance(axes, list) or len(axes) != 3:
            raise _error(path, f"lots[{i}].axes must be three 3-vectors")
        frames[lot["path"]] = tuple(
            _vector(a, 3, f"lots[{i}].axes[{j}]", path) for j, a in enumerate(axes)
        )
    return frames


def _read_face(
    group: _Node, kept: set[int], fixed: dict[str, bool], frames: dict
) -> tuple[Face, _Terminal] | None:
    """One face of the rule tree as a Face (and its first terminal), in the frame its terminals
    give: x and y along the two axes of their plane.  None for a face without area (zero width
    or height): nothing to subdivide, and a grammar cannot re-create it."""
    terms = [t for t in group.terminals if t.index in kept]
    first = _reference(terms)
    p, q = first.plane
    x, y = first.axes[p], first.axes[q]
    u0, v0, u1, v1 = _union([_Frame(first.origin, x, y).rect(t) for t in terms])
    if u1 - u0 < TOL or v1 - v0 < TOL:
        return None
    origin = tuple(first.origin[i] + u0 * x[i] + v0 * y[i] for i in range(3))
    rect = (0.0, 0.0, u1 - u0, v1 - v0)
    root = _Builder(_Frame(origin, x, y), fixed, kept).cell(group, rect, rect[2])
    _set_fixed(root, None)
    lot = first.path.split("/", 1)[0]
    side = side_of(first.normal, frames.get(lot))
    if abs(first.normal[1]) > 0.7071 and (group.gathered or "/" not in group.path):
        name = "Facade"  # lying on the lot: the lot (or the pieces it was cut into) is the façade
    else:
        name = side.capitalize() + "Face" if group.gathered else group.name
    face = Face(
        rect[2],
        rect[3],
        root,
        name=name,
        origin=origin,
        x_axis=x,
        y_axis=y,
        normal=first.normal,
        lot=lot,
        side=side,
    )
    return face, first


def model_from_terminals(
    data: dict, path: str = "<terminals>", fixed: dict[str, bool] | None = None
) -> Model:
    """The Model of a terminal list: its vertical faces, subdivided, in derivation order, with
    their corners; horizontal faces' labels are kept for the roof.  A list with no vertical face
    is a flat model: its faces lie on their lots (a façade derived on the lot rectangle) and are
    the façades themselves.  Parts without area (lines, points, faces of zero height) are
    skipped and counted."""
    every = read_terminals(data, path)
    frames = _lot_frames(data, path)
    if not every:
        raise _error(path, "the terminal list is empty: nothing to infer from")
    terminals = [t for t in every if t.k is not None]
    skipped = len(every) - len(terminals)
    fixed = dict(fixed or {})
    found: list = []
    _face_nodes(_tree(terminals), found)
    vertical, horizontal = [], []
    for group, kept in found:
        read = _read_face(group, kept, fixed, frames)
        if read is None:
            skipped += 1
            continue
        kind = horizontal if abs(read[0].normal[1]) > 0.7071 else vertical
        read[0].order = len(kind)  # derivation order among the faces of its kind
        kind.append(read)
    colors: dict[str, str] = {}
    for t in terminals:  # a label's colour: the first one it comes in
        if t.color is not None:
            colors.setdefault(t.label, t.color)
    if vertical:
        faces = [face for face, _ in vertical]
        blocks, dropped = _masses(faces)
        roofs = [first.label for _, first in horizontal]  # a roof or a floor slab
        model = Model(blocks, source=path, roof_labels=roofs, label_colors=colors, dropped=dropped)
    elif horizontal:
        blocks, axes = _flats(horizontal, frames)
        model = Model(blocks, source=path, label_colors=colors, flat_axes=axes)
    else:
        raise _error(
            path,
            "no face with an area in the terminal list"
            + (f" ({skipped} parts of zero size)" if skipped else ""),
            "face schemas are inferred from façades: flat terminals on the sides of a mass, "
            "or on the lot itself",
        )
    model.skipped = skipped
    return model


def _masses(faces: list[Face]) -> tuple[list[Block], int]:
    """The blocks of vertical faces: each a ring of faces linked at their corners, within one
    lot; and how many small faces on no mass were left out."""
    by_lot: dict[str, list[Face]] = {}
    for f in faces:
        by_lot.setdefault(f.lot, []).append(f)
    rings = [ring for lot_faces in by_lot.values() for ring in link_faces(lot_faces)]

    # a mass is a closed ring of faces, or faces as large as one; small faces on no ring (the
    # sides of a dormer, a balcony's front...) are parts of something else and are left out
    def area(ring):
        return sum(f.width * f.height for f in ring)

    largest = max(area(r) for r in rings)
    closed = [
        ring
        for ring in rings
        if all(f.left != "free" and f.right != "free" for f in ring) or area(ring) >= 0.25 * largest
    ]
    dropped = sum(len(r) for r in rings) - sum(len(r) for r in closed)
    blocks = []
    for i, ring in enumerate(closed or rings):
        xs = [c for f in ring for c in (f.origin[0], f.origin[0] + f.width * f.x_axis[0])]
        zs = [c for f in ring for c in (f.origin[2], f.origin[2] + f.width * f.x_axis[2])]
        blocks.append(
            Block(
                f"Block{i}",
                ring,
                max(xs) - min(xs),
                max(zs) - min(zs),
                max(f.height for f in ring),
                footprint=[(f.origin[0], f.origin[2]) for f in ring],
            )
        )
    return blocks, dropped


def _flats(read: list[tuple[Face, _Terminal]], frames: dict) -> tuple[list[Block], tuple[str, str]]:
    """The blocks of a flat model, a face each (nothing to link: a flat façade has no corners),
    and the lot's scope axes its faces run along, which the grammar's splits will name."""
    first_face, first = read[0]
    axes = _scope_axes(first_face, first, frames.get(first_face.lot))
    blocks = []
    for i, (face, _) in enumerate(read):
        extent = {axes[0]: face.width, axes[1]: face.height}
        corners = [(0.0, 0.0), (face.width, 0.0), (face.width, face.height), (0.0, face.height)]
        footprint = [
            tuple(face.origin[j] + a * face.x_axis[j] + b * face.y_axis[j] for j in (0, 2))
            for a, b in corners
        ]
        blocks.append(
            Block(
                f"Block{i}",
                [face],
                extent.get("x", 0.0),
                extent.get("z", 0.0),
                0.0,
                shape="flat",
                footprint=footprint,
            )
        )
    return blocks, axes


def _scope_axes(face: Face, first: _Terminal, lot_axes) -> tuple[str, str]:
    """The names of the lot's scope axes that the face's x and y run along: the lot axis each
    is parallel to when the lot's frame is known, else the terminal's own scope axes (a piece
    of a lot split in x and z has the lot's axes)."""
    names = []
    for vector, own in zip((face.x_axis, face.y_axis), first.plane, strict=True):
        name = "xyz"[own]
        if lot_axes is not None:
            dots = [_dot(vector, a) for a in lot_axes]
            best = max(range(3), key=lambda i: abs(dots[i]))
            if dots[best] > 1.0 - 1e-6:
                name = "xyz"[best]
        names.append(name)
    return names[0], names[1]


def load_terminal_list(path: str | Path, fixed: dict[str, bool] | None = None) -> Model:
    data = read_json(path, "terminal list", "write one with: bgr derive FILE.bgr -o terminals.json")
    return model_from_terminals(data, str(path), fixed)
