"""What a roof is made of: its planes (:class:`RoofPlane`), its mesh (:class:`RoofMesh`), and
the builder every roof kind assembles its mesh with (:class:`_MeshBuilder`).

The kinds themselves are built in :mod:`.roofs` (the straight-skeleton kinds),
:mod:`.roof_pyramid` and :mod:`.roof_shed_flat`, on the footprint of :mod:`.roof_footprint`;
the module docstring of :mod:`.roofs` says what each kind is.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .earclip import triangulate


@dataclass(frozen=True)
class RoofPlane:
    """One plane of a roof: the points p with ``normal . p == offset``.

    ``kind`` is ``slope`` (rising from an edge), ``corner`` (rising from a sharp corner whose
    eave is bevelled), ``gable`` (a vertical gable wall), ``wall`` (a shed's vertical side) or
    ``flat``.  ``edge`` is the index i of the footprint edge ``polygon[i] -> polygon[i+1]`` the
    plane rises from or stands on (None for a flat roof and a corner); ``edges`` all the input
    edges on that line (collinear runs and repeated points are merged), for a corner the two
    edges that meet there.
    ``normal`` points outward (up for a slope); ``pitch`` is in degrees from horizontal.
    """

    kind: str
    edge: int | None
    edges: tuple[int, ...]
    normal: np.ndarray
    offset: float
    pitch: float


@dataclass
class RoofMesh:
    """A roof's triangle mesh; see the module docstring of :mod:`.roofs`."""

    vertices: np.ndarray  # (V, 3) float64
    faces: np.ndarray  # (F, 3) int32, counter-clockwise seen from outside / above
    face_plane: np.ndarray  # (F,) int: index into planes
    planes: list[RoofPlane]
    eave: np.ndarray  # (E, 3): the outline of the open bottom, counter-clockwise from above
    overhang: float
    kind: str  # the kind built (a pyramid that cannot be built is a hip)
    fallback: str = ""  # why the kind built is not the kind asked for, when that is a surprise


class _MeshBuilder:
    """Collects triangles over a vertex table, one plane per key, and compacts at the end."""

    def __init__(self, vertices: np.ndarray):
        self.vertices = np.asarray(vertices, dtype=np.float64)
        self.triangles: list[np.ndarray] = []
        self.owner: list[np.ndarray] = []
        self.planes: list[RoofPlane] = []
        self.keys: dict = {}

    def plane(self, key, make, *args) -> int:
        """The index of the plane under ``key``, made by ``make(*args)`` the first time.

        The arguments are passed, not captured by a closure, so a plane made inside a loop
        reads that iteration's values whenever it is made.
        """
        if key not in self.keys:
            self.keys[key] = len(self.planes)
            self.planes.append(make(*args))
        return self.keys[key]

    def add(self, tris, plane: int) -> None:
        """Add triangles (vertex ids), already counter-clockwise seen from outside."""
        tris = np.asarray(tris, dtype=np.int64).reshape(-1, 3)
        self.triangles.append(tris)
        self.owner.append(np.full(len(tris), plane, dtype=np.int64))

    def add_polygon(self, ids, flat: np.ndarray, plane: int) -> None:
        """Triangulate the polygon of vertex ids ``ids`` drawn in 2D as ``flat`` (counter-clockwise
        when seen from outside) and add it."""
        ids = np.asarray(ids, dtype=np.int64)
        self.add(ids[triangulate(flat)], plane)

    def finish(self, eave: np.ndarray, overhang: float, kind: str) -> RoofMesh:
        tris = np.concatenate(self.triangles) if self.triangles else np.zeros((0, 3), np.int64)
        owner = np.concatenate(self.owner) if self.owner else np.zeros(0, np.int64)
        used, inverse = np.unique(tris, return_inverse=True)
        vertices = self.vertices[used]
        if not np.isfinite(vertices).all():
            raise ArithmeticError("roof mesh has non-finite vertices")
        return RoofMesh(
            vertices=vertices,
            faces=inverse.reshape(-1, 3).astype(np.int32),
            face_plane=owner,
            planes=self.planes,
            eave=np.asarray(eave, dtype=np.float64),
            overhang=overhang,
            kind=kind,
        )


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v)


def _cross(u, v):
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]
