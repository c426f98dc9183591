"""Components: a box about the vertical axis for each slab, its mesh in the box's frame, a key
that equal meshes share, and the feature vector that clusters components into types.

The box (paper, section IV.B) is the minimum-area rectangle of the slab's vertices seen from
above, extruded from the slab's bottom to its top.  A rectangle has four frames (it looks the same
turned by 90 degrees); the one chosen is the one whose mesh, in that frame, has the smallest key,
so that two copies of a component turned by any multiple of 90 degrees get the same frame
relative to their geometry, and the same key.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from typing import Any

import numpy as np
import shapely
from trimesh.bounds import oriented_bounds_2D

from .cuts import Slab

TOLERANCE = 0.01  # metres: level 0's default bound (bgr infer --tolerance)


def key_grid(tolerance: float) -> float:
    """The grid meshes are compared on: two meshes equal on it differ by at most ``tolerance``
    at any corner (a corner moves at most one cell along each axis: sqrt(3) cells in all)."""
    return tolerance / np.sqrt(3.0)


def digits_for(tolerance: float) -> int:
    """Decimals of the grammar's lengths: a tenth of the tolerance (millimetres for 1 cm), so
    that rounding them adds at most a few per cent of it."""
    return int(min(9, max(3, np.ceil(-np.log10(tolerance / 10)))))


def grid_mesh(
    vertices: np.ndarray, faces: np.ndarray, digits: int
) -> tuple[np.ndarray, np.ndarray]:
    """A mesh on the grammar's grid (``digits`` decimals: the lengths written are as short as
    the grammar's), its equal vertices shared and the ones no triangle uses dropped."""
    import trimesh

    points = np.round(np.asarray(vertices, dtype=np.float64), digits)
    mesh = trimesh.Trimesh(points, np.asarray(faces), process=False)
    mesh.merge_vertices()
    mesh.update_faces(mesh.nondegenerate_faces())  # a corner merged into another
    mesh.remove_unreferenced_vertices()
    return np.asarray(mesh.vertices), np.asarray(mesh.faces)


KEY_GRID = key_grid(TOLERANCE)

# the feature vector (paper, section IV.C), in units where 1 is a noticeable difference
FEATURES = (
    "front shape",  # vertices of the Douglas-Peucker outline seen from the front
    "side shape",  # ... and from the side
    "width",  # metres
    "height",
    "depth",
    "rotation",  # tens of degrees, of the box about the vertical, in [0, 90)
    "roof slope",  # tens of degrees: area-weighted slope of the upward faces that are not flat
    "intensity",  # tenths of grey (0..10) of the faces' colours, where the input has colours
)


@dataclass
class Component:
    """One slab of one building, in the frame of its box."""

    building: int  # index of the object it was cut from
    frame: np.ndarray  # (4, 4): box frame -> bgr world (columns: x, y up, z, origin)
    size: np.ndarray  # (3,) box size along the frame's x, y, z
    vertices: np.ndarray  # (V, 3) in the box frame: within [0, size]
    faces: np.ndarray  # (F, 3)
    colors: np.ndarray | None  # (F, 4) uint8 or None
    key: str  # equal for meshes equal on the key grid (in their chosen frame)
    angle: float  # degrees, the rectangle's rotation about the vertical, in [0, 90)
    # the walls and roof that make it (houses.HouseFit), for a building that is a house
    house: Any = None


def _turn(angle_deg: float) -> np.ndarray:
    """The frame axes for a box turned by ``angle`` about bgr's y (up): x, y, z as columns."""
    a = np.radians(angle_deg)
    x = np.array([np.cos(a), 0.0, -np.sin(a)])
    y = np.array([0.0, 1.0, 0.0])
    return np.column_stack([x, y, np.cross(x, y)])


def mesh_key(vertices: np.ndarray, faces: np.ndarray, grid: float = KEY_GRID) -> str:
    """A digest of a mesh that does not depend on vertex or triangle order (nor on where each
    triangle's corner list starts), only on the triangles' corners on the KEY_GRID."""
    grid = np.rint(vertices / grid).astype(np.int64)
    tri = grid[faces]  # (F, 3, 3)
    # start each triangle at its smallest corner, keeping the winding
    order = np.argmin(_corner_rank(tri), axis=1)
    turn = (np.arange(3)[None, :] + order[:, None]) % 3
    rolled = np.take_along_axis(tri, turn[:, :, None], axis=1)
    flat = rolled.reshape(len(tri), 9)
    flat = flat[np.lexsort(flat.T[::-1])]
    return hashlib.sha1(flat.tobytes()).hexdigest()


def _corner_rank(tri: np.ndarray) -> np.ndarray:
    """(F, 3) rank of each corner among all corners (lexicographic on x, y, z)."""
    corners = tri.reshape(-1, 3)
    rank = np.empty(len(corners), dtype=np.int64)
    rank[np.lexsort(corners.T[::-1])] = np.arange(len(corners))
    return rank.reshape(-1, 3)


def fit(slab: Slab, building: int, colors: np.ndarray | None, grid: float = KEY_GRID) -> Component:
    """The component of a slab: its box, its mesh in the box's frame, its key."""
    ground = slab.vertices[:, [0, 2]]
    angle = 0.0
    if len(np.unique(np.round(ground, 6), axis=0)) >= 3:
        try:
            transform, _ = oriented_bounds_2D(ground)
            angle = float(np.degrees(np.arctan2(transform[1, 0], transform[0, 0])))
        except Exception:  # collinear points: qhull cannot make a hull; keep the world axes
            angle = 0.0
    angle = angle % 90.0
    bottom = float(slab.vertices[:, 1].min())
    best = None
    for quarter in range(4):
        axes = _turn(angle + 90.0 * quarter)
        local = slab.vertices @ axes  # coordinates along the frame's axes
        low = local.min(axis=0)
        low[1] = bottom
        local = local - low
        key = mesh_key(local, slab.faces, grid)
        if best is None or key < best[0]:
            origin = axes @ low
            frame = np.eye(4)
            frame[:3, :3], frame[:3, 3] = axes, origin
            best = (key, frame, local)
    assert best is not None
    key, frame, local = best
    size = local.max(axis=0)
    return Component(building, frame, size, local, slab.faces, colors, key, angle)


def features(comp: Component) -> np.ndarray:
    """The feature vector of a component (see FEATURES), from its mesh in its own frame."""
    v, f = comp.vertices, comp.faces
    tri = v[f]
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area = np.linalg.norm(cross, axis=1) / 2
    keep = area > 1e-9
    up = np.divide(cross[:, 1], 2 * area, out=np.zeros(len(f)), where=keep)
    roofish = keep & (up > 0.05) & (up < 0.999)
    slope = (
        float(np.average(np.degrees(np.arccos(up[roofish])), weights=area[roofish]))
        if roofish.any()
        else 0.0
    )
    intensity = 0.0
    if comp.colors is not None and len(comp.colors) == len(f) and keep.any():
        grey = comp.colors[:, :3].astype(float) @ np.array([0.299, 0.587, 0.114]) / 255
        intensity = float(np.average(grey[keep], weights=area[keep])) * 10
    return np.array(
        [
            _outline_vertices(tri[keep][:, :, [0, 1]], comp.size),
            _outline_vertices(tri[keep][:, :, [2, 1]], comp.size),
            comp.size[0],
            comp.size[1],
            comp.size[2],
            comp.angle / 10,
            slope / 10,
            intensity,
        ]
    )


def _outline_vertices(flat: np.ndarray, size: np.ndarray) -> float:
    """Vertices of the Douglas-Peucker simplified outline of triangles seen from one side (the
    paper renders the component and simplifies the foreground's outline).

    ``flat`` is the triangles projected on the view plane.  Of a closed mesh the faces turned
    towards the viewer cover the whole silhouette, so only they are merged (half the work);
    an open surface that has none turned this way is merged from the other side."""
    if len(flat) == 0:
        return 0.0
    e1, e2 = flat[:, 1] - flat[:, 0], flat[:, 2] - flat[:, 0]
    facing = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    chosen = flat[facing > 1e-9] if np.any(facing > 1e-9) else flat[facing < -1e-9]
    if len(chosen) == 0:  # seen edge on: a line
        return 2.0
    # the same triangle twice adds nothing to the union but its time (a face repeated 100,000
    # times took 4 s; a million, 40): merge each distinct one once
    chosen = np.unique(chosen.reshape(len(chosen), 6), axis=0).reshape(-1, 3, 2)
    polygons = shapely.polygons(np.concatenate([chosen, chosen[:, :1]], axis=1))
    try:
        outline = shapely.union_all(polygons)
    except shapely.errors.GEOSException:  # nearly coincident edges: merge on a 0.1 mm grid
        outline = shapely.union_all(polygons, grid_size=1e-4)
    simple = shapely.simplify(outline, 0.02 * float(max(size.max(), 1e-3)))
    rings = shapely.get_parts(simple)
    return float(sum(len(p.exterior.coords) - 1 for p in rings if p.geom_type == "Polygon"))
