"""Components that are footprints extruded to a height, written as grammar operations.

A slab whose faces are all upright walls, plus (or not) a flat floor at its bottom and a flat
cap at its top, is a prism: ``polygon(x1, z1, ...) extrude(h)`` reproduces it, with
``comp(f) { side: ... | bottom: ... }`` where a cap is missing (the floor of a wall slab under
a roof, say).  Written that way it is a few hundred bytes of editable text instead of a mesh in
the assets file, and a user can change a building's height or outline in the grammar.

The fit is checked, not assumed: the walls' vertices lie within half the tolerance of the
outline, the walls' area and each cap's area equal the prism's to within a strip of the
tolerance along the outline, and last the two surfaces are within three quarters of the
tolerance of each other both ways (vertices and points spread over each, measured by trimesh's
point-to-surface distance).  A component that fails any check keeps its mesh.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely
import trimesh
from shapely.ops import polygonize, unary_union
from trimesh.creation import extrude_polygon

from .components import Component, digits_for

UPRIGHT = 0.05  # |n_up| below this: a wall (the corner checks bound how far it may lean)
LEVEL = 1 - 1e-8  # |n_up| above this: a floor or a cap
MIN_HEIGHT = 0.05  # metres: a thinner slab is a surface, not a prism
SPACING = 0.4  # metres: the checks' points on a surface are about this far apart ...
SAMPLES = 1500  # ... or this many, where the surface is large


@dataclass(frozen=True)
class PrismFit:
    """A component as a prism: its outline in its box frame, height, caps and colours."""

    ring: tuple[tuple[float, float], ...]  # (x, z) corners in metres, on the grammar's grid
    height: float
    bottom: bool  # the floor is part of the component
    top: bool  # the cap is part of the component
    colors: dict[str, str]  # "side", "bottom", "top" -> "#rrggbb", where the input has colours


def fit_prism(comp: Component, tolerance: float) -> PrismFit | None:
    """The prism a component is within ``tolerance`` (metres), or None when it is none (or
    when GEOS or the triangulator cannot make sense of its outline: it keeps its mesh)."""
    try:
        return _fit(comp, tolerance)
    except (shapely.errors.GEOSException, ValueError, IndexError):
        return None


def _fit(comp: Component, tolerance: float) -> PrismFit | None:
    v, f = comp.vertices, comp.faces
    height = float(comp.size[1])
    if len(f) == 0 or height < MIN_HEIGHT:
        return None
    tri = v[f]
    double, real, up = facing(tri)
    ys = tri[:, :, 1]
    half = tolerance / 2
    wall = real & (np.abs(up) < UPRIGHT)
    bottom = real & (up < -LEVEL) & (np.abs(ys).max(axis=1) <= half)
    top = real & (up > LEVEL) & (np.abs(ys - height).max(axis=1) <= half)
    if not np.all(wall | bottom | top | ~real) or not wall.any():
        return None
    digits = digits_for(tolerance)
    ring = footprint(tri[wall], tolerance)
    if ring is None:
        return None
    polygon = shapely.Polygon(ring)
    boundary = polygon.exterior
    # seen from above: the walls lie on the outline and the caps fill it, to half the tolerance
    # (shapely's Hausdorff distance, on edges cut into a hundred pieces)
    seen = shapely.linestrings(_segment_ends(tri[wall][:, :, [0, 2]]))
    if shapely.hausdorff_distance(shapely.multilinestrings(seen), boundary, densify=0.01) > half:
        return None
    for chosen in (bottom, top):
        if chosen.any():
            try:
                cap = shapely.union_all(shapely.polygons(tri[chosen][:, :, [0, 2]]))
            except shapely.errors.GEOSException:  # slivers GEOS cannot merge: keep the mesh
                return None
            if shapely.hausdorff_distance(cap, polygon, densify=0.01) > half:
                return None
    perimeter, area = boundary.length, polygon.area
    slack = tolerance * perimeter
    if abs(double[wall].sum() / 2 - perimeter * height) > slack * height:
        return None
    caps = {}
    for name, chosen in (("bottom", bottom), ("top", top)):
        covered = double[chosen].sum() / 2
        if chosen.any() and abs(covered - area) > slack:
            return None  # a partial floor or cap: not an extrusion's
        caps[name] = bool(chosen.any())
    colors = _colors(comp.colors, {"side": wall, "bottom": bottom, "top": top})
    if colors is None:
        return None
    fit = PrismFit(ring, round(height, digits), caps["bottom"], caps["top"], colors)
    return fit if _close(comp, fit, tolerance) else None


def facing(tri: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(twice each triangle's area, whether it has any, the upward part of its unit normal)."""
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    double = np.linalg.norm(cross, axis=1)
    real = double > 1e-12
    up = np.divide(cross[:, 1], double, out=np.zeros(len(tri)), where=real)
    return double, real, up


def footprint(walls: np.ndarray, tolerance: float) -> tuple[tuple[float, float], ...] | None:
    """Where the walls stand seen from above, as one ring on the grammar's grid, or None when
    they enclose no single polygon without a courtyard."""
    outline = _outline(_ground_lines(walls, tolerance / 2), tolerance)
    return None if outline is None else _rounded(outline, digits_for(tolerance))


def prism_mesh(fit: PrismFit) -> trimesh.Trimesh:
    """The triangles ``polygon() extrude()`` makes of a fit (its missing caps left out), in the
    component's frame (y up)."""
    made = extrude_polygon(shapely.Polygon(fit.ring), fit.height)  # z up
    vertices = made.vertices[:, [0, 2, 1]]  # (x, z, up) -> (x, up, z)
    faces = made.faces[:, ::-1]  # the axes' swap turned them inside out
    up = made.face_normals[:, 2]
    keep = (np.abs(up) < 0.5) | ((up > 0.5) & fit.top) | ((up < -0.5) & fit.bottom)
    return trimesh.Trimesh(vertices, faces[keep], process=False)


def _close(comp: Component, fit: PrismFit, tolerance: float) -> bool:
    """Whether the prism and the component are within ``tolerance`` of each other both ways
    (:func:`_close_meshes`)."""
    given = trimesh.Trimesh(comp.vertices, comp.faces, process=False)
    return _close_meshes(given, prism_mesh(fit), tolerance)


def _close_meshes(given: trimesh.Trimesh, made: trimesh.Trimesh, tolerance: float) -> bool:
    """Whether two meshes are within three quarters of ``tolerance`` of each other both ways,
    on their vertices and on points spread over their surfaces (at most SPACING apart where
    SAMPLES allow) — trimesh's point-to-surface distance."""
    for a, b in ((given, made), (made, given)):
        count = int(min(SAMPLES, max(64, a.area / SPACING**2)))
        points, _ = trimesh.sample.sample_surface(a, count, seed=0)
        points = np.vstack([points, a.vertices])
        _, distance, _ = trimesh.proximity.closest_point(b, points)
        if distance.max() > 0.75 * tolerance:
            return False
    return True


def _ground_lines(walls: np.ndarray, half: float) -> np.ndarray:
    """(L, 2, 2): where the walls stand, seen from above: the edges of wall triangles that lie
    on the slab's bottom (exact even where a wall leans a little), or, where no wall edge is
    there, each wall triangle's two corners farthest apart."""
    edges = np.concatenate([walls[:, [0, 1]], walls[:, [1, 2]], walls[:, [2, 0]]])
    low = np.all(np.abs(edges[:, :, 1]) <= half, axis=1)
    if low.sum() >= 3:
        return edges[low][:, :, [0, 2]]
    return _segment_ends(walls[:, :, [0, 2]])


def _outline(ends: np.ndarray, tolerance: float):
    """The one polygon the ground lines enclose, or None when they enclose several or a
    courtyard (a hole ``polygon()`` cannot write)."""
    grid = tolerance / 4
    snapped = np.round(ends / grid) * grid
    lines = shapely.linestrings(snapped)
    lines = lines[shapely.length(lines) > 0]
    if len(lines) < 3:
        return None
    found = list(polygonize(unary_union(lines)))
    if len(found) != 1 or len(found[0].interiors):
        return None
    simple = found[0].simplify(tolerance / 4, preserve_topology=True)
    if simple.is_empty or simple.geom_type != "Polygon" or not simple.is_valid:
        return None
    return simple


def _segment_ends(walls: np.ndarray) -> np.ndarray:
    """(W, 2, 2): the two corners farthest apart of each wall triangle seen from above."""
    pairs = np.array([(0, 1), (1, 2), (0, 2)])
    gaps = np.linalg.norm(walls[:, pairs[:, 0]] - walls[:, pairs[:, 1]], axis=2)
    best = pairs[np.argmax(gaps, axis=1)]
    rows = np.arange(len(walls))
    return np.stack([walls[rows, best[:, 0]], walls[rows, best[:, 1]]], axis=1)


def _rounded(polygon, digits: int) -> tuple[tuple[float, float], ...] | None:
    """The exterior counter-clockwise in (x, z), to ``digits`` decimals (millimetres for the
    default tolerance), without repeated corners; None when rounding spoils it."""
    coords = np.round(np.asarray(polygon.exterior.coords)[:-1], digits)
    keep = np.any(coords != np.roll(coords, 1, axis=0), axis=1)
    coords = coords[keep]
    if len(coords) < 3:
        return None
    ring = shapely.Polygon(coords)
    if not ring.is_valid or ring.area <= 0:
        return None
    if not shapely.Polygon(coords).exterior.is_ccw:
        coords = coords[::-1]
    return tuple((float(x) + 0.0, float(z) + 0.0) for x, z in coords)


def _colors(colors: np.ndarray | None, parts: dict[str, np.ndarray]) -> dict[str, str] | None:
    """One colour for each part present, or None when a part has several (the mesh keeps them);
    {} without colours."""
    if colors is None or len(colors) == 0:
        return {}
    out = {}
    for name, chosen in parts.items():
        if not chosen.any():
            continue
        found = np.unique(np.asarray(colors)[chosen][:, :3], axis=0)
        if len(found) != 1:
            return None
        r, g, b = (int(c) for c in found[0])
        out[name] = f"#{r:02x}{g:02x}{b:02x}"
    return out
