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
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

from bgr.grammar.errors import BgrError, Diagnostic, read_json
from bgr.grammar.safe_text import unwritable
from bgr.interpreter.limits import MAX_INPUT_COORDINATE

from .model import Block, Cell, Face, Model, default_fixed

TOL = 1e-6  # metres: coordinates that agree this closely are the same
_HEX = re.compile(r"#[0-9a-fA-F]{6}")


@dataclass
class _Terminal:
    """One terminal of the list, with the plane it lies in read from its own frame.

    ``k`` is the scope axis the terminal is flat along (its size there is 0), so its plane is
    spanned by the other two axes in index order: a face from comp(f) is flat along z (plane x,
    y), a piece of a lot along y (plane x, z).  Nothing assumes which axis is up.  A solid (no
    size 0) has ``k`` 2 for when it stands alone, but beside flat terminals it joins the face
    one of its axes is normal to (:func:`_same_plane`).  ``k`` is None when two or three sizes
    are 0 (a line or a point, which has no area to subdivide).
    """

    index: int
    label: str
    path: str
    origin: tuple[float, float, float]
    axes: tuple[tuple[float, float, float], ...]
    size: tuple[float, float, float]
    color: str | None = None
    k: int | None = field(init=False, default=2)
    flat: bool = field(init=False, default=False)

    def __post_init__(self) -> None:
        zeros = [i for i in range(3) if self.size[i] < TOL]
        self.flat = len(zeros) == 1
        self.k = zeros[0] if self.flat else (2 if not zeros else None)

    @property
    def normal(self) -> tuple[float, float, float]:
        return self.axes[self.k]

    @property
    def plane(self) -> tuple[int, int]:
        """The indices of the two scope axes the terminal's plane is spanned by, in order."""
        return _PLANES[self.k]


_PLANES = {0: (1, 2), 1: (0, 2), 2: (0, 1)}


@dataclass
class _Node:
    path: str
    items: list = field(default_factory=list)  # child _Node or _Terminal, in derivation order
    terminals: list = field(default_factory=list)  # every terminal below, in order
    gathered: bool = False  # a face gathered from a rule's children, not a rule of its own

    @property
    def name(self) -> str:
        last = self.path.rsplit("/", 1)[-1]
        return last.rsplit(".", 1)[0]


def _error(path: str, message: str, hint: str | None = None) -> BgrError:
    return BgrError(Diagnostic(path, 0, 0, message, hint))


def _vector(value, n: int, where: str, path: str) -> tuple:
    """``n`` numbers, each finite and within MAX_INPUT_COORDINATE (a terminal at 1e308 is no
    place: it made a lot of 1e308 that the check of the inferred grammar blamed on bgr)."""
    if (
        not isinstance(value, list)
        or len(value) != n
        or not all(
            isinstance(v, (int, float))
            and not isinstance(v, bool)
            and abs(v) <= MAX_INPUT_COORDINATE  # NaN compares false
            for v in value
        )
    ):
        raise _error(
            path,
            f"{where} must be a list of {n} finite numbers within ±{MAX_INPUT_COORDINATE:.0e} m, "
            f"got {json.dumps(value)[:60]}".replace("e+0", "e"),
        )
    return tuple(float(v) for v in value)


def read_terminals(data: dict, path: str = "<terminals>") -> list[_Terminal]:
    """The terminals of a parsed terminal-list JSON, checked: each error names the element."""
    if not isinstance(data, dict) or not isinstance(data.get("terminals"), list):
        raise _error(
            path,
            "not a bgr terminal list: expected an object with a 'terminals' list",
            "write one with: bgr derive FILE.bgr -o terminals.json",
        )
    out = []
    for i, t in enumerate(data["terminals"]):
        where = f"terminals[{i}]"
        if not isinstance(t, dict):
            raise _error(path, f"{where} is not an object")
        for key in ("label", "path"):
            if not isinstance(t.get(key), str) or not t.get(key):
                raise _error(path, f"{where}.{key} must be a non-empty string")
            if unwritable(t[key]):  # the inferred grammar writes it as a label string
                raise _error(path, f"{where}.{key} holds {unwritable(t[key])}, which no label has")
        origin = _vector(t.get("origin"), 3, f"{where}.origin", path)
        axes_raw = t.get("axes")
        if not isinstance(axes_raw, list) or len(axes_raw) != 3:
            raise _error(path, f"{where}.axes must be three 3-vectors")
        axes = tuple(_vector(a, 3, f"{where}.axes[{j}]", path) for j, a in enumerate(axes_raw))
        size = _vector(t.get("size"), 3, f"{where}.size", path)
        if min(size) < 0:
            raise _error(path, f"{where}.size has a negative entry")
        color = t.get("color")
        color = color if isinstance(color, str) and _HEX.fullmatch(color) else None
        out.append(_Terminal(i, t["label"], t["path"], origin, axes, size, color))
    return out


def _tree(terminals: list[_Terminal]) -> _Node:
    """The rule tree of the paths; children in derivation (first appearance) order."""
    nodes: dict[str, _Node] = {}
    root = _Node("")

    def node(path: str) -> _Node:
        found = nodes.get(path)
        if found is None:
            found = nodes[path] = _Node(path)
            parent = node(path.rsplit("/", 1)[0]) if "/" in path else root
            parent.items.append(found)
        return found

    for t in terminals:
        node(t.path).items.append(t)

    def fill(n: _Node) -> None:
        for item in n.items:
            if isinstance(item, _Node):
                fill(item)
                n.terminals += item.terminals
            else:
                n.terminals.append(item)

    fill(root)
    return root


# ---- faces ------------------------------------------------------------------------------------


def _dot(a, b) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _same_axes(a, b) -> bool:
    return all(abs(a[i][j] - b[i][j]) < 1e-6 for i in range(3) for j in range(3))


DEPTH = 1.0  # metres: recessed glass and extruded frames within this of the wall belong to its face


def _same_plane(t: _Terminal, ref: _Terminal) -> bool:
    """Whether ``t`` lies in ``ref``'s face, within DEPTH of its plane (a recess or a frame is
    projected onto the face; its depth is not part of the schema).

    Two flat terminals (or two solids) must have the same axes and be flat along the same one.
    A solid beside a flat terminal only needs one of its axes along the face's normal, whichever
    it is: a frame extruded from a wall has its depth along z or along y depending on how
    extrude() sets the scope, and it belongs to the wall either way."""
    if t.flat == ref.flat:
        if t.k != ref.k or not _same_axes(t.axes, ref.axes):
            return False
        normal = ref.normal
    else:
        normal = (ref if ref.flat else t).normal
        solid = t if ref.flat else ref
        if not any(abs(abs(_dot(a, normal)) - 1.0) < 1e-6 for a in solid.axes):
            return False
    return abs(_dot(t.origin, normal) - _dot(ref.origin, normal)) < DEPTH


def _reference(terminals: list[_Terminal]) -> _Terminal:
    """The terminal whose plane a group of terminals is read in: the first flat one (a face's
    own surface), else the first."""
    return next((t for t in terminals if t.flat), terminals[0])


def _coplanar(terminals: list[_Terminal]) -> bool:
    """One face: every terminal in the reference's plane."""
    ref = _reference(terminals)
    return all(_same_plane(t, ref) for t in terminals)


def _area(t: _Terminal) -> float:
    p, q = t.plane
    return t.size[p] * t.size[q]


LINK = 0.6  # metres: face corners this close are one corner
MINOR = 0.35  # parts off the main plane (reveals, sill tops) up to this share of its area


def _main_plane(terminals: list[_Terminal]) -> set[int] | None:
    """The terminals of a subtree's main plane, if the rest are minor parts of it.

    A window with 3D parts puts small terminals at right angles to the wall (the sides of its
    reveal, the top of its sill); they belong to the face they are set in, not to faces of
    their own.  The subtree is one face when the terminals in its largest plane (same axes,
    within DEPTH) outweigh all the others by area; the others are left out of the schema.
    Planes are set by flat terminals; a solid joins the first plane it stands in (it could
    stand in three: a box has an axis along each), else solids group among themselves."""
    groups: list[tuple[_Terminal, list[_Terminal]]] = []
    ordered = [t for t in terminals if t.flat] + [t for t in terminals if not t.flat]
    for t in ordered:
        for first, members in groups:
            if _same_plane(t, first):
                members.append(t)
                break
        else:
            groups.append((t, [t]))
        if len(groups) > 64:  # many orientations: a whole mass, not one face
            return None
    areas = [sum(_area(t) for t in members) for _, members in groups]
    best = max(range(len(groups)), key=lambda i: areas[i])
    if sum(areas) - areas[best] > MINOR * areas[best]:
        return None
    return {t.index for t in groups[best][1]}


def _face_nodes(node: _Node, out: list) -> None:
    """Collect (node, kept terminal indices) per face: the highest subtrees that lie in one
    plane, up to minor parts at other angles.  Where a rule's children are the pieces of a face
    with no rule of its own (``comp(f) { front: split(x) { ... } }``), the children in one plane
    are gathered into one face.  Lots are never gathered: two flat lots side by side lie in one
    plane, but each is a façade of its own."""
    if not node.path:  # the root: one subtree per lot
        for item in node.items:
            _face_nodes(item, out)
        return
    if node.terminals:
        kept = (
            {t.index for t in node.terminals}
            if _coplanar(node.terminals)
            else _main_plane(node.terminals)
        )
        if kept:
            out.append((node, kept))
            return
    planes: dict[tuple, _Node] = {}
    for item in node.items:
        terms = item.terminals if isinstance(item, _Node) else [item]
        if isinstance(item, _Node) and not (terms and _coplanar(terms)):
            _face_nodes(item, out)
            continue
        if not terms or not any(t.flat for t in terms):  # a solid (a roof, a box), no face
            continue
        first = _reference(terms)
        key = tuple(round(v, 5) for v in first.normal) + (
            round(_dot(first.origin, first.normal), 5),
        )
        if key not in planes:
            planes[key] = _Node(node.path, gathered=True)
            out.append(planes[key])  # keeps derivation order among faces
        planes[key].items.append(item)
        planes[key].terminals += terms
    for i, entry in enumerate(out):  # a plane of one child rule is that rule's own face
        if isinstance(entry, _Node):
            only = (
                entry.items[0]
                if len(entry.items) == 1 and isinstance(entry.items[0], _Node)
                else entry
            )
            out[i] = (only, {t.index for t in entry.terminals})


@dataclass
class _Frame:
    """A face's frame: its bottom left corner and the directions of its width (x) and height (y)
    in the world, from the terminals' own frames (never from a guess at which axis is up)."""

    origin: tuple[float, float, float]
    x: tuple[float, float, float]
    y: tuple[float, float, float]
    cache: dict[int, tuple[float, float, float, float]] = field(default_factory=dict)

    def rect(self, t: _Terminal) -> tuple[float, float, float, float]:
        """The terminal's extent in the face, (u0, v0, u1, v1): its scope box projected onto the
        face's x and y.  Remembered per terminal: every level of the rule tree asks again."""
        found = self.cache.get(t.index)
        if found is None:
            found = self.cache[t.index] = self._project(t)
        return found

    def _project(self, t: _Terminal) -> tuple[float, float, float, float]:
        d = (
            t.origin[0] - self.origin[0],
            t.origin[1] - self.origin[1],
            t.origin[2] - self.origin[2],
        )
        u, v = _dot(d, self.x), _dot(d, self.y)
        p, q = t.plane
        if t.axes[p] == self.x and t.axes[q] == self.y:  # the face's own axes: exact sizes
            return (u, v, u + t.size[p], v + t.size[q])
        u0, u1, v0, v1 = u, u, v, v
        for axis, length in zip(t.axes, t.size, strict=True):
            du, dv = _dot(axis, self.x) * length, _dot(axis, self.y) * length
            u0, u1 = u0 + min(du, 0.0), u1 + max(du, 0.0)
            v0, v1 = v0 + min(dv, 0.0), v1 + max(dv, 0.0)
        return (u0, v0, u1, v1)


def _union(rects) -> tuple[float, float, float, float]:
    return (
        min(r[0] for r in rects),
        min(r[1] for r in rects),
        max(r[2] for r in rects),
        max(r[3] for r in rects),
    )


class _Builder:
    """Turns one face's rule subtree into a Cell tree."""

    def __init__(self, frame: _Frame, fixed: dict[str, bool], kept: set[int] | None = None) -> None:
        self.frame, self.fixed, self.kept = frame, fixed, kept

    def children(self, node: _Node) -> list:
        """A node's items that hold kept terminals, in derivation order."""
        if self.kept is None:
            return node.items
        return [
            item
            for item in node.items
            if (
                any(t.index in self.kept for t in item.terminals)
                if isinstance(item, _Node)
                else item.index in self.kept
            )
        ]

    def terms(self, node: _Node) -> list[_Terminal]:
        return (
            node.terminals
            if self.kept is None
            else [t for t in node.terminals if t.index in self.kept]
        )

    def is_fixed(self, label: str) -> bool:
        return self.fixed.get(label, default_fixed(label))

    def leaf(self, t: _Terminal, size: float) -> Cell:
        return Cell(size, t.label, fixed=self.is_fixed(t.label))

    def items_of(self, node: _Node):
        """(rect, item) of a node's children, in derivation order."""
        out = []
        for item in self.children(node):
            terms = self.terms(item) if isinstance(item, _Node) else [item]
            out.append((_union([self.frame.rect(t) for t in terms]), item))
        return out

    def cell(self, item, rect, size: float) -> Cell:
        if not isinstance(item, _Node):
            return self.leaf(item, size)
        kids = self.children(item)
        if len(kids) == 1 and not isinstance(kids[0], _Node):
            return self.leaf(kids[0], size)
        if len(kids) == 1:  # a rule that only hands its shape on
            inner = self.cell(kids[0], rect, size)
            if not inner.is_leaf:
                inner.label = inner.label or item.name
            return inner
        children = self.items_of(item)
        cell = self.partition(children, rect, size) or self.guillotine(
            [(self.frame.rect(t), t) for t in self.terms(item)], rect, size
        )
        cell.label = item.name
        return cell

    def fitted(self, item, slot, size: float) -> Cell:
        """A terminal in a slot it does not fill (a door shorter than its column): the leaf with
        empty parts beside it, so that the gap keeps its size instead of the leaf growing."""
        (r, t) = item
        w, h = r[2] - r[0], r[3] - r[1]
        short_x = w < slot[2] - slot[0] - TOL
        short_y = h < slot[3] - slot[1] - TOL
        cell = self.leaf(t, size if not short_x else h if short_y else w)
        if short_y:
            parts = (
                ([Cell(r[1] - slot[1])] if r[1] > slot[1] + TOL else [])
                + [Cell(h, t.label, fixed=cell.fixed)]
                + ([Cell(slot[3] - r[3])] if slot[3] > r[3] + TOL else [])
            )
            cell = _split("y", parts, w if short_x else size)
        if short_x:
            inner = cell if short_y else Cell(w, t.label, fixed=cell.fixed)
            inner.size = w
            parts = (
                ([Cell(r[0] - slot[0])] if r[0] > slot[0] + TOL else [])
                + [inner]
                + ([Cell(slot[2] - r[2])] if slot[2] > r[2] + TOL else [])
            )
            cell = _split("x", parts, size)
        return cell

    def partition(self, children, rect, size: float) -> Cell | None:
        """The children as one split: they lie side by side along x (or y) in derivation order
        and each spans the whole rectangle across.  Gaps become empty cells."""
        for axis, lo, hi, a0, a1 in (("x", 0, 2, 1, 3), ("y", 1, 3, 0, 2)):
            pos = rect[lo]
            parts = []
            ok = True
            for r, item in children:
                if abs(r[a0] - rect[a0]) > TOL or abs(r[a1] - rect[a1]) > TOL or r[lo] < pos - TOL:
                    ok = False
                    break
                if r[lo] > pos + TOL:
                    parts.append(Cell(r[lo] - pos))  # a gap the source left empty
                parts.append(self.cell(item, r, r[hi] - r[lo]))
                pos = r[hi]
            if ok and len(parts) > 1:
                if rect[hi] > pos + TOL:
                    parts.append(Cell(rect[hi] - pos))
                return _split(axis, parts, size)
        return None

    def guillotine(self, items, rect, size: float) -> Cell:
        """Cut a set of terminal rectangles apart by full cuts (y first, then x): the pieces of
        splits nested inside one rule body, which no path element separates."""
        if len(items) == 1:
            return self.fitted(items[0], rect, size)
        for axis, lo, hi in (("y", 1, 3), ("x", 0, 2)):
            ordered = sorted(items, key=lambda it: (it[0][lo], it[1].index))
            groups, end = [], None
            for r, t in ordered:
                if end is None or r[lo] >= end - TOL:
                    groups.append([])
                    end = r[hi]
                groups[-1].append((r, t))
                end = max(end, r[hi])
            if len(groups) > 1:
                parts, pos = [], rect[lo]
                for g in groups:
                    gr = _union([r for r, _ in g])
                    if gr[lo] > pos + TOL:
                        parts.append(Cell(gr[lo] - pos))
                    sub = list(rect)
                    sub[lo], sub[hi] = gr[lo], gr[hi]
                    parts.append(self.guillotine(g, tuple(sub), gr[hi] - gr[lo]))
                    pos = gr[hi]
                if rect[hi] > pos + TOL:
                    parts.append(Cell(rect[hi] - pos))
                return _split(axis, parts, size)
        # overlapping pieces: keep the first, the rest cannot be a subdivision
        return self.leaf(items[0][1], size)


def _split(axis: str, parts: list[Cell], size: float) -> Cell:
    """A subdivided cell; fixed along its parent's axis when nothing in it can stretch."""
    cell = Cell(size, axis=axis, parts=parts)
    cell.fixed = _fixed_along(cell, axis)
    return cell


def _fixed_along(cell: Cell, axis: str) -> bool:
    """Can the cell not stretch along ``axis``?  A leaf by its label; a split along the same axis
    when all its parts are fixed; a split across it when any part is (a window column cannot be
    made wider)."""
    if cell.is_leaf:
        return cell.fixed
    if cell.axis == axis:
        return all(_fixed_along(p, axis) for p in cell.parts)
    return any(_fixed_along(p, axis) for p in cell.parts)


def _set_fixed(cell: Cell, axis: str | None) -> None:
    """Fill in ``fixed`` of every part along its own parent's axis."""
    if cell.is_leaf:
        return
    for p in cell.parts:
        _set_fixed(p, cell.axis)
        p.fixed = _fixed_along(p, cell.axis)


# ---- lots, sides, corners and blocks --------------------------------------------------------


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


def side_of(normal, axes=None) -> str:
    """The comp selector of a face by its outward normal in its lot's frame (section 7: front is
    -z, back +z, left -x, right +x); the world's frame when the lot is not known."""
    if axes is not None:
        normal = tuple(_dot(normal, a) for a in axes)
    x, _, z = normal
    if abs(x) >= abs(z):
        return "right" if x > 0 else "left"
    return "back" if z > 0 else "front"


def _corner(x_left, x_right) -> str:
    """The corner between a face (x axis x_left) and its right neighbour (x_right), from outside."""
    turn = x_left[2] * x_right[0] - x_left[0] * x_right[2]  # y of x_left cross x_right
    along = x_left[0] * x_right[0] + x_left[2] * x_right[2]
    if abs(turn) < 1e-6 and along > 0:
        return "flat"
    return "outer" if turn > 0 else "inner"


def link_faces(faces: list[Face]) -> list[list[Face]]:
    """Set each vertical face's left/right corner from the face whose bottom corner it shares
    (``origin``, ``width``, ``x_axis`` in world coordinates); faces linked this way form one
    block, returned as rings in order.  Used by both readers."""
    # corners match within LINK: a cornice or a quoin that stands a little past the wall's
    # edge widens a face's outline by a few centimetres
    cell = LINK * 2

    def bucket(p):
        return (math.floor(p[0] / cell), math.floor(p[2] / cell))

    starts: dict[tuple, list[Face]] = {}
    for f in faces:
        starts.setdefault(bucket(f.origin), []).append(f)
    right_of: dict[int, Face] = {}
    taken: set[int] = set()
    for f in faces:
        end = tuple(f.origin[i] + f.width * f.x_axis[i] for i in range(3))
        bx, bz = bucket(end)
        near = [
            g for dx in (-1, 0, 1) for dz in (-1, 0, 1) for g in starts.get((bx + dx, bz + dz), [])
        ]
        best, rank = None, (LINK, 0.0)
        for g in near:
            d = math.dist((end[0], end[1], end[2]), g.origin)
            # the nearest start; at a shared corner the wall that runs straight on (a block
            # attached flush) before one that turns
            r = (round(d, 6), -_dot(f.x_axis, g.x_axis))
            if g is not f and id(g) not in taken and d <= LINK and (best is None or r < rank):
                best, rank = g, r
        if best is not None:
            taken.add(id(best))
            right_of[id(f)] = best
            kind = _corner(f.x_axis, best.x_axis)
            f.right, best.left = kind, kind
    # blocks: follow the links
    seen, blocks = set(), []
    for f in faces:
        if id(f) in seen:
            continue
        ring, g = [], f
        while g is not None and id(g) not in seen:
            seen.add(id(g))
            ring.append(g)
            g = right_of.get(id(g))
        blocks.append(ring)
    return blocks


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
