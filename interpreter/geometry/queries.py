"""CGA's geometry functions: what the current shape's geometry measures, in metres.

``geometry.area()``, ``geometry.volume()``, ``geometry.nVertices()``, ``geometry.nFaces()`` and
``geometry.height()`` read the shape's own geometry (its outline, its extruded prism, its roof or
inserted mesh) scaled to its scope, as CityEngine's functions of those names do: the area is the
sum of all its faces, the volume the one its closed surface encloses (0 for a 2D shape), the
vertices and faces those of its polygons (a box has 8 and 6, not its triangles' 24 and 12), and
the height its extent along the world's vertical.  All are pure functions of the geometry, the
scope's size and its axes, which the reuse keys hold (interpreter/reuse.py), so a subtree that
asks them is still derived once and replayed.
"""

from __future__ import annotations

import numpy as np

from ..shapes import Flat, Prism, Solid
from .frames import planar_faces
from .meshes import flat_mesh, prism_mesh


def scope_mesh(shape, library) -> tuple[np.ndarray, np.ndarray]:
    """The shape's triangles in its scope's metres: (V, 3) vertices and (F, 3) faces."""
    geom = shape.geom
    size = np.asarray(shape.size, dtype=np.float64)
    if isinstance(geom, Solid):
        unit = library.meshes[geom.mesh]
        return np.asarray(unit.vertices, dtype=np.float64) * size, np.asarray(unit.faces)
    if isinstance(geom, Flat):
        verts, faces = flat_mesh(geom.polys, geom.k)
    elif isinstance(geom, Prism):
        verts, faces = prism_mesh(geom.polys, geom.k)
    else:  # pragma: no cover - every shape has one of the three
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    return verts * size, faces


def _corners(shape, library) -> np.ndarray:
    verts, faces = scope_mesh(shape, library)
    return verts[faces] if len(faces) else np.zeros((0, 3, 3))


def area(shape, library, selector: str = "all") -> float:
    """The sum of the areas of the geometry's faces, in square metres: all of them, or those a
    comp(f) selector would take (``top``, ``side``, ``front``...: by their normal in the scope)."""
    tri = _corners(shape, library)
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    sizes = np.linalg.norm(cross, axis=1)
    if selector != "all" and len(tri):
        normals = cross / np.maximum(sizes, 1e-300)[:, None]
        sizes = sizes[_selected(normals, selector)]
    return float(0.5 * sizes.sum())


def _selected(normals: np.ndarray, selector: str) -> np.ndarray:
    """Which faces (by unit normal in the scope) a comp(f) selector takes."""
    x, y, z = normals[:, 0], normals[:, 1], normals[:, 2]
    level = np.abs(y) <= 0.7071
    sideways = np.abs(x) >= np.abs(z)
    slope = np.degrees(np.arcsin(np.clip(np.abs(y), 0.0, 1.0)))
    chosen = {
        "top": y > 0.7071,
        "bottom": y < -0.7071,
        "side": level,
        "left": level & sideways & (x < 0),
        "right": level & sideways & (x > 0),
        "front": level & ~sideways & (z < 0),
        "back": level & ~sideways & (z > 0),
        "vertical": slope < 1.0,
        "horizontal": slope > 89.0,
        "aslant": (slope >= 1.0) & (slope <= 89.0) & (y > 0),
        "nutant": (slope >= 1.0) & (slope <= 89.0) & (y < 0),
    }
    return chosen[selector]


def angle(shape, library, kind: str) -> float:
    """CGA's geometry.angle: ``maxSlope`` the steepest face against the world's horizontal
    plane, in degrees; ``zenith`` 90 minus that; ``azimuth`` the compass direction that face
    looks to, clockwise from north (-z in bgr's world, as in CityEngine's; east, +x, is 90).
    A shape without faces has a slope of 0."""
    tri = _corners(shape, library)
    if not len(tri):
        return 90.0 if kind == "zenith" else 0.0
    axes = np.asarray(shape.axes, dtype=np.float64)
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]) @ axes  # in world axes
    sizes = np.linalg.norm(cross, axis=1)
    keep = sizes > 1e-12 * max(float(sizes.max()), 1e-300)
    normals = cross[keep] / sizes[keep, None]
    slopes = np.degrees(np.arccos(np.clip(np.abs(normals[:, 1]), 0.0, 1.0)))
    steepest = int(np.argmax(slopes))
    if kind == "maxSlope":
        return float(slopes[steepest])
    if kind == "zenith":
        return float(90.0 - slopes[steepest])
    east, north = normals[steepest, 0], -normals[steepest, 2]
    if abs(east) < 1e-12 and abs(north) < 1e-12:
        return 0.0
    return float(np.degrees(np.arctan2(east, north)) % 360.0)


def volume(shape, library) -> float:
    """The volume the geometry's surface encloses (the divergence theorem over its triangles),
    in cubic metres; 0 for a 2D shape."""
    if isinstance(shape.geom, Flat):
        return 0.0
    tri = _corners(shape, library)
    signed = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6.0
    return float(abs(signed))


def n_vertices(shape, library) -> int:
    """The geometry's distinct corners (its triangles' shared and repeated ones counted once)."""
    verts, faces = scope_mesh(shape, library)
    used = verts[np.unique(faces)] if len(faces) else verts[:0]
    return int(len(np.unique(np.round(used, 9), axis=0)))


def n_faces(shape, library) -> int:
    """The geometry's faces: its coplanar, connected triangles counted as one polygon."""
    verts, faces = scope_mesh(shape, library)
    return len(planar_faces(verts, faces)) if len(faces) else 0


def height(shape, library) -> float:
    """The geometry's extent along the world's vertical, in metres."""
    verts, faces = scope_mesh(shape, library)
    if not len(faces):
        return 0.0
    world_y = verts[np.unique(faces)] @ np.asarray(shape.axes, dtype=np.float64)[:, 1]
    return float(world_y.max() - world_y.min())


QUERIES = {
    "geometry.area": area,
    "geometry.volume": volume,
    "geometry.nVertices": n_vertices,
    "geometry.nFaces": n_faces,
    "geometry.height": height,
}


def _face_rings(shape, library) -> list:
    """The geometry's planar faces: (rings in scope metres, outer first; normal)."""
    verts, faces = scope_mesh(shape, library)
    return planar_faces(verts, faces) if len(faces) else []


def _edges(shape, library) -> dict:
    """Each undirected edge of the faces' outlines (rounded end points) and how many faces
    share it."""
    seen: dict = {}
    for rings, _ in _face_rings(shape, library):
        for ring in rings:
            pts = [tuple(round(float(c), 6) for c in p) for p in ring]
            for a, b in zip(pts, pts[1:] + pts[:1], strict=True):
                key = (a, b) if a <= b else (b, a)
                seen[key] = seen.get(key, 0) + 1
    return seen


def n_edges(shape, library) -> int:
    """The geometry's distinct edges (a box: 12)."""
    return len(_edges(shape, library))


def n_holes(shape, library) -> int:
    """The holes in the geometry's faces (a courtyard footprint: 1; extruded, 2: top and
    bottom)."""
    return sum(len(rings) - 1 for rings, _ in _face_rings(shape, library))


def boundary_length(shape, library) -> float:
    """The length of the edges that only one face has: a 2D shape's outline (with its holes'),
    0 for a closed solid."""
    total = 0.0
    for (a, b), used in _edges(shape, library).items():
        if used == 1:
            total += float(np.linalg.norm(np.subtract(a, b)))
    return total


def is_concave(shape, library) -> bool:
    """Whether a face of the geometry is concave (a hole makes it so), as CGA's."""
    for rings, normal in _face_rings(shape, library):
        if len(rings) > 1:
            return True
        ring = np.asarray(rings[0], dtype=np.float64)
        edges = np.roll(ring, -1, axis=0) - ring
        turns = np.cross(edges, np.roll(edges, -1, axis=0)) @ np.asarray(normal, dtype=np.float64)
        if bool((turns > 1e-9).any() and (turns < -1e-9).any()):
            return True
    return False


def is_planar(shape, library, tolerance: float = 0.0) -> bool:
    """Whether all the geometry's faces lie in one plane, normals within ``tolerance``
    degrees of each other (and their points on one plane)."""
    faces = _face_rings(shape, library)
    if not faces:
        return True
    first = np.asarray(faces[0][1], dtype=np.float64)
    limit = np.cos(np.radians(max(float(tolerance), 0.0))) - 1e-9
    points = np.asarray([p for rings, _ in faces for ring in rings for p in ring])
    offsets = (points - points[0]) @ first
    span = float(np.ptp(points, axis=0).max()) or 1.0
    parallel = all(float(np.dot(first, n)) >= limit for _, n in faces)
    slack = span * float(np.sin(np.radians(max(float(tolerance), 0.0)))) + 1e-6
    return bool(parallel and float(np.abs(offsets).max()) <= slack)


QUERIES.update(
    {
        "geometry.nEdges": n_edges,
        "geometry.nHoles": n_holes,
        "geometry.boundaryLength": boundary_length,
        "geometry.isConcave": is_concave,
    }
)
