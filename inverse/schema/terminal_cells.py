"""One face of a terminal list as a Cell tree, and the fixed flags of cell trees.

:class:`_Frame` projects terminals onto a face's plane; :class:`_Builder` turns the face's rule
subtree into nested splits: a rule's pieces side by side along x or y, or, where one rule body
nests splits, cut apart geometrically (guillotine cuts).  :func:`_set_fixed` fills in whether
each part of a cell tree can stretch along its parent's axis; the captured-model reader uses it
too.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .model import Cell, default_fixed
from .terminal_list import TOL, _dot, _Node, _Terminal


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
