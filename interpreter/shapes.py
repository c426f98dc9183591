"""Shapes: a scope (origin, three orthonormal axes, size) plus geometry and appearance.

Scopes use plain Python floats: a shape's 3-vectors are too small for numpy to pay off, and the
derivation creates hundreds of thousands of them.  Geometry lives in unit scope coordinates, so
``s()`` rescales a shape without touching its geometry.

Geometry kinds (LANGUAGE.md sections 4-5):

* :class:`Flat` — a 2D shape: polygons in the plane of two scope axes, flat along axis ``k``
  (a lot: k = 1, y; a face from ``comp``: k = 2, z).
* :class:`Prism` — the base polygons extruded from 0 to 1 along axis ``k``.
* :class:`Solid` — any other mesh (primitives, roofs, assets, tapers), by unit-mesh id.
"""

from __future__ import annotations

from dataclasses import dataclass

Vec = tuple[float, float, float]
IDENTITY: tuple[Vec, Vec, Vec] = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


@dataclass(frozen=True, slots=True)
class Flat:
    k: int
    polys: object  # polygons.RECT or a list of (exterior, holes) in unit coordinates
    name: str = "polygon"


@dataclass(frozen=True, slots=True)
class Prism:
    k: int
    polys: object
    name: str = "prism"
    # convexify(maxLength) of the solid: comp(f) cuts its concave faces into convex parts,
    # with cuts up to this length (math.inf: all); 0: not convexified
    convex: float = 0.0


@dataclass(frozen=True, slots=True)
class Solid:
    mesh: int  # id in the derivation's MeshLibrary
    name: str  # what the terminal list's "geometry" says: cube, roof, an asset's name...
    convex: float = 0.0  # as Prism's


_new_shape = object.__new__
DEFAULT_COLOR = (0.8, 0.8, 0.8)  # a shape never coloured: #cccccc


class Shape:
    """One shape of the derivation.  Copied, never shared, between parent and children."""

    __slots__ = (
        "origin",
        "axes",
        "size",
        "geom",
        "color",
        "material",
        "label",
        "path",
        "hash",
        "depth",
        "frame",
        "tex",
        "attrs",
        "trims",
    )

    def __init__(
        self,
        origin,
        axes,
        size,
        geom,
        color=DEFAULT_COLOR,
        material=None,
        label=None,
        path="",
        hash_=0,
        depth=0,
    ) -> None:
        self.origin: list[float] = list(origin)
        self.axes: tuple[Vec, Vec, Vec] = axes
        self.size: list[float] = list(size)
        self.geom = geom
        self.color = color
        self.material = material
        self.label = label
        self.path = path
        self.hash = hash_
        self.depth = depth
        self.frame = None  # (origin, axes) of the shape this one was cut from; None: the world
        self.tex = None  # texturing.Texturing (projections, coordinates, maps), None: plain
        # attrs set() on this shape or an ancestor: ((id(module), name), value) pairs sorted by
        # key, a tuple so that it can be part of a reuse key; None: none (operations/attributes)
        self.attrs: tuple | None = None
        # CGA's trim planes and whether its vertical and horizontal ones cut (operations/trims:
        # a Trims); None: trimming is off (the default; set(trim.vertical, true) turns it on)
        self.trims = None

    def copy(self) -> Shape:
        # slot by slot, not through __init__: a derivation copies shapes millions of times
        twin = _new_shape(Shape)
        twin.origin = self.origin[:]
        twin.axes = self.axes
        twin.size = self.size[:]
        twin.geom = self.geom
        twin.color = self.color
        twin.material = self.material
        twin.label = self.label
        twin.path = self.path
        twin.hash = self.hash
        twin.depth = self.depth
        twin.frame = self.frame
        twin.tex = self.tex  # immutable: shared until an operation replaces it
        twin.attrs = self.attrs  # immutable too
        twin.trims = self.trims  # immutable too
        return twin

    def cut_from(self, parent: Shape) -> Shape:
        """Mark this shape as a piece of ``parent`` (a split piece, a face, an inset)."""
        self.frame = (tuple(parent.origin), parent.axes)
        return self

    @property
    def local_origin(self) -> list[float]:
        """scope.x/y/z: the origin in the frame of the shape this one was cut from."""
        if self.frame is None:
            return self.origin
        (ox, oy, oz), axes = self.frame
        d = (self.origin[0] - ox, self.origin[1] - oy, self.origin[2] - oz)
        return [d[0] * a[0] + d[1] * a[1] + d[2] * a[2] for a in axes]

    def world(self, local: Vec) -> list[float]:
        """A point in scope-local metres -> world."""
        o, (ax, ay, az) = self.origin, self.axes
        x, y, z = local
        return [o[i] + x * ax[i] + y * ay[i] + z * az[i] for i in range(3)]

    def direction(self, local: Vec) -> list[float]:
        (ax, ay, az) = self.axes
        x, y, z = local
        return [x * ax[i] + y * ay[i] + z * az[i] for i in range(3)]


def cross(a, b) -> list[float]:
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def dot(a, b) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def normalise(a) -> list[float]:
    length = dot(a, a) ** 0.5
    return [a[0] / length, a[1] / length, a[2] / length] if length > 1e-15 else [0.0, 0.0, 0.0]
