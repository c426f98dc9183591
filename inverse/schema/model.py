"""The subdivided, labelled building that face, floor and model schemas are inferred from.

Both inputs — a terminal list written by ``bgr derive -o x.json`` and a captured-model JSON — are
read into these classes, and everything after that (schemas, the emitted grammar) works on them
alone.  A :class:`Cell` is Build-by-Number's subface: a labelled leaf, or a subdivision of its
rectangle into parts along one axis (columns along x, rows along y).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

# Labels whose size is fixed when the input does not say (the documented default):
# openings keep their size on a novel face, walls and everything else stretch.
FIXED_PATTERN = re.compile(r"window|door|entrance|entry|portal|gate", re.IGNORECASE)
KEY_DIGITS = 4  # sizes in equality keys are rounded to 0.1 mm


def default_fixed(label: str) -> bool:
    return bool(FIXED_PATTERN.search(label))


@dataclass
class Cell:
    """A subface: ``label`` for a leaf; ``axis`` and ``parts`` for a subdivided one.

    ``size`` is the cell's extent along its parent's axis (a face's root cell: its width);
    ``label`` of a subdivided cell is the name of the rule that made it, if known, and only
    names the rewrite rule in the output.  An empty leaf (``label`` None, no parts) is a gap that
    the source left empty (an absolute split shorter than its scope, or a NIL piece).
    """

    size: float
    label: str | None = None
    axis: str | None = None  # "x" | "y" when subdivided
    parts: list[Cell] = field(default_factory=list)
    fixed: bool = False
    occluded: bool = False

    @property
    def is_leaf(self) -> bool:
        return self.axis is None

    def key(self) -> str:
        """The equality relation of Build-by-Number: a leaf is its label, a subdivided cell its
        rewrite string (the keys of its parts, with their sizes — see ``docs/inverse-schema.md``).
        """
        if self.is_leaf:
            return self.label or "_"
        inner = ",".join(
            f"{p.key()}@{round(p.size, KEY_DIGITS)}{'!' if p.fixed else ''}" for p in self.parts
        )
        return f"{self.axis}[{inner}]"

    def leaves(self) -> list[Cell]:
        if self.is_leaf:
            return [self]
        return [leaf for p in self.parts for leaf in p.leaves()]

    def count(self) -> int:
        """Leaves, the subfaces a user sees."""
        return 1 if self.is_leaf else sum(p.count() for p in self.parts)


@dataclass
class Face:
    """One face of a block: its subdivision and where it sits among its neighbours.

    ``left``/``right`` are the corners at its two vertical edges, seen from outside:
    ``"outer"`` (a convex corner), ``"inner"`` (a reflex one), ``"flat"`` (the wall goes on) or
    ``"free"`` (no neighbour known).  ``side`` is the comp selector of the source (front, left...).
    """

    width: float
    height: float
    root: Cell
    left: str = "free"
    right: str = "free"
    side: str = "side"
    name: str = "Face"
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)
    x_axis: tuple[float, float, float] = (1.0, 0.0, 0.0)
    y_axis: tuple[float, float, float] = (
        0.0,
        1.0,
        0.0,
    )  # up the face (of a flat face: the lot's z)
    normal: tuple[float, float, float] = (0.0, 0.0, -1.0)
    order: int = 0  # position in the source's derivation order (the order its terminals came out)
    lot: str = ""  # the lot (building) it belongs to: faces of different lots never link

    @property
    def category(self) -> tuple[str, str]:
        """One of Build-by-Number's nine orientation categories (left corner, right corner)."""
        return (self.left, self.right)

    def occluded(self) -> int:
        return sum(1 for leaf in self.root.leaves() if leaf.occluded)


@dataclass
class Block:
    """A building block: its faces in order round it (each from the ground to the top), and its
    size.  A face's floors are the parts of its root cell when that is split along y: the
    captured-model reader builds them from the block's floors, the terminal-list reader finds
    them in the façade's own subdivision."""

    name: str
    faces: list[Face]
    width: float
    depth: float
    height: float
    shape: str = "box"  # box | cylinder | prism
    footprint: list[tuple[float, float]] = field(default_factory=list)  # world (x, z), ring order


@dataclass
class Model:
    """A captured or derived building: its blocks, tallest first after :meth:`sorted_blocks`."""

    blocks: list[Block]
    source: str = ""
    labels_fixed: dict[str, bool] = field(default_factory=dict)
    roof_labels: list[str] = field(default_factory=list)  # labels found on horizontal faces
    label_colors: dict[str, str] = field(default_factory=dict)  # "#rrggbb" per label, when known
    dropped: int = 0  # faces on no mass (parts at odd angles) left out of the schemas
    skipped: int = 0  # parts without area (a line, a face of zero height) left out
    # A flat model: its faces lie flat on their lots (a façade derived on the lot rectangle, with
    # no extrude), and the grammar splits the lot itself.  The names of the lot's scope axes
    # that a face's x (its width) and y (its height) run along, e.g. ("x", "z"); None for a
    # model of masses, whose faces come from comp(f).
    flat_axes: tuple[str, str] | None = None

    def faces(self) -> list[Face]:
        return [f for b in self.blocks for f in b.faces]

    def sorted_blocks(self) -> list[Block]:
        return sorted(self.blocks, key=lambda b: -b.height)
