"""CGA's trim planes: what is inserted on a façade is cut where the façade meets the next one.

``comp(f)`` of a solid gives each wall face a plane at each of its vertical edges, the one that
halves the corner with the neighbouring wall (CGA's trim planes).  Every shape derived from the
face keeps them, and ``i()`` cuts the inserted mesh by them, so that a ledge or a cornice made
longer than its façade meets its neighbour's in a mitre at the corner instead of running past
it.  Splits do not cut (their pieces never leave the face).

Trimming is off in a bgr grammar until ``set(trim.vertical, true)`` (``Shape.trims`` is None);
CGA has it on from the start, so ``bgr import-cga`` writes that first in the start rule.  Off by
default, grammars written for bgr keep their outputs, and their repeated subtrees replay as
before.

A plane is (normal, c): the kept side is where normal . point >= c, in world coordinates.  A
shape farther from a plane than its own largest size (a tile in the middle of a façade) drops
it (:func:`kept`): what it inserts would have to be more than twice its size to reach the plane,
and the reuse of repeated subtrees, which keys on the planes a shape keeps (relative to its
origin), then replays such tiles as before.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..geometry.meshes import PLANE_AXES
from ..geometry.polygons import RECT, from_shapely, is_unit_square, normalise
from ..shapes import Flat, Prism, Shape, Solid
from ..terminals import UnitMesh

_EPS = 1e-9
# what an operation returns when nothing of the shape is left: the engine takes it as NIL
DELETED = "deleted"
# a plane whose generating edge rises less than this from the world's horizontal plane is a
# horizontal one (CGA's trim attribute: 40 degrees)
HORIZONTAL_BELOW = math.sin(math.radians(40.0))


@dataclass(frozen=True, slots=True)
class Trims:
    """What a shape knows of trimming: whether vertical and horizontal planes cut (CGA's
    trim.vertical, on by default there, and trim.horizontal, off), and the planes it carries,
    each (normal, c, horizontal) in world coordinates, kept where normal . point >= c."""

    vertical: bool
    horizontal: bool
    planes: tuple = ()

    def __bool__(self) -> bool:  # "has planes": what the engine asks before moving them
        return bool(self.planes)

    def cutting(self) -> tuple:
        """The planes that cut: those of a kind that is on."""
        return tuple(
            p for p in self.planes if (self.horizontal if p[2] else self.vertical)
        )  # fmt: skip


def switched(trims: Trims | None, which: str, on: bool) -> Trims | None:
    """set(trim.vertical | trim.horizontal, on).  The planes stay with the shape while both
    are off, as CGA's do (its Parthenon turns trimming off for a column's box and on again for
    the capital, which the corner's plane then cuts); None once both are off and no plane is
    left."""
    now = trims if trims is not None else Trims(False, False)
    now = replace(now, **{which: on})
    return now if now.vertical or now.horizontal or now.planes else None


def corner_planes(face: Shape, left: float, right: float) -> tuple:
    """The two vertical trim planes of a wall face whose corners turn ``left`` and ``right``
    degrees (comp.left, comp.right: 90 at a box's corners): through its left and right edges,
    halving each corner, kept on the face's side."""
    half_l, half_r = math.radians(left) / 2, math.radians(right) / 2
    at_left = face.origin
    at_right = face.world((face.size[0], 0.0, 0.0))
    n_left = tuple(face.direction((math.cos(half_l), 0.0, math.sin(half_l))))
    n_right = tuple(face.direction((-math.cos(half_r), 0.0, math.sin(half_r))))
    return ((n_left, _dot(n_left, at_left), False), (n_right, _dot(n_right, at_right), False))


def edge_planes(shape: Shape, faces: list, shared: list, index: int, skip_upright: bool) -> tuple:
    """The trim planes of face ``index`` of a solid (``faces``: comp(f)'s list, in scope
    metres; ``shared``: geometry.edges.edges of them) at each edge it shares with another face:
    the plane through the edge halving the angle between the two, kept on this face's side;
    horizontal when the edge rises less than 40 degrees from the world's horizontal plane.
    ``skip_upright``: leave out upright edges (a box's walls have corner_planes there)."""
    out = []
    normals = [np.asarray(nrm, dtype=np.float64) for _r, nrm, *_ in faces]
    centre = np.mean(np.asarray(faces[index][0][0], dtype=np.float64), axis=0)
    for edge in shared:
        if index not in edge.faces or len(edge.faces) != 2:
            continue
        other = edge.faces[1] if edge.faces[0] == index else edge.faces[0]
        a, b = np.asarray(edge.start), np.asarray(edge.end)
        along = np.asarray(shape.direction(tuple((b - a).tolist())))
        rise = abs(along[1]) / (float(np.linalg.norm(along)) or 1.0)
        if skip_upright and rise > math.cos(math.radians(1.0)):
            continue
        halving = normals[index] - normals[other]
        if float(np.linalg.norm(halving)) < 1e-9:
            continue  # two faces in one plane: nothing to cut between them
        if float(np.dot(halving, centre - a)) < 0:
            halving = -halving
        normal = np.asarray(shape.direction(tuple(halving.tolist())))
        normal /= np.linalg.norm(normal)
        point = shape.world(tuple(a.tolist()))
        n = tuple(float(v) for v in normal)
        out.append((n, _dot(n, point), rise < HORIZONTAL_BELOW))
    return tuple(out)


def _dot(a, b) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def kept(shape: Shape) -> Trims:
    """The shape's trims without the planes it lies farther from than its own largest size."""
    reach = max(shape.size)
    trims = shape.trims
    near = tuple(p for p in trims.planes if _least(shape, p[0], p[1]) <= reach)
    return trims if len(near) == len(trims.planes) else replace(trims, planes=near)


def _least(shape: Shape, normal, c: float) -> float:
    """The least signed distance of the shape's scope box from a plane (negative: it crosses
    or lies behind it)."""
    least = _dot(normal, shape.origin) - c
    for axis, size in zip(shape.axes, shape.size, strict=True):
        least += min(0.0, size * _dot(normal, axis))
    return least


def moved_trims(trims: Trims, origin) -> Trims:
    """Trim planes as seen from ``origin``: a subtree derived at the world's origin (reuse)."""
    planes = tuple((n, c - _dot(n, origin), h) for n, c, h in trims.planes)
    return replace(trims, planes=planes)


def relative(shape: Shape) -> tuple:
    """Which planes cut and where they stand relative to the shape's origin, rounded: part of a
    reuse key."""
    o, trims = shape.origin, shape.trims
    return (trims.vertical, trims.horizontal) + tuple(
        (round(n[0], 9), round(n[1], 9), round(n[2], 9), round(c - _dot(n, o), 9), h)
        for n, c, h in trims.planes
    )


def trim(app, shape: Shape, step, args):
    """CGA's trim(): the shape's geometry cut by its trim planes now; a 2D shape or a prism
    becomes the mesh of what is left (only when a plane crosses it)."""
    planes = shape.trims.cutting() if shape.trims else ()
    if not planes or all(_least(shape, n, c) >= 0 for n, c, _ in planes):
        return False
    geom = shape.geom
    if not isinstance(geom, Solid):  # cut as a mesh, and a prism stays a solid comp(f) opens
        name = "extrusion" if isinstance(geom, Prism) else geom.name
        shape.geom = Solid(app.engine.mesh_id(geom), name)
    if not trim_insert(app, shape):
        return DELETED
    if isinstance(geom, Flat):  # what is left of a 2D shape is a 2D shape again
        _flat_again(app, shape, geom.k)
    return False


def _flat_again(app, shape: Shape, k: int) -> None:
    """A trimmed 2D shape's mesh back to its outline (Flat), its scope fitted to it."""
    import shapely
    from shapely.geometry import Polygon

    mesh = app.engine.table.library.meshes[shape.geom.mesh]
    p, q = PLANE_AXES[k]
    metres = mesh.vertices * np.asarray(shape.size, dtype=np.float64)
    flat = metres[:, [p, q]]
    merged = shapely.union_all([Polygon(flat[f]) for f in mesh.faces if len(set(f)) == 3])
    unit, (x0, y0, w, h) = normalise(from_shapely(merged))
    axes = shape.axes
    shape.origin = [shape.origin[i] + x0 * axes[p][i] + y0 * axes[q][i] for i in range(3)]
    shape.size[p], shape.size[q] = w, h
    shape.geom = Flat(k, RECT if is_unit_square(unit) else unit)


def trim_insert(app, shape: Shape) -> bool:
    """Cut the shape's inserted mesh by its trim planes; False when nothing of it is left."""
    planes = shape.trims.cutting() if shape.trims else ()
    if not planes or all(_least(shape, n, c) >= 0 for n, c, _ in planes):
        return True  # the scope's box (which holds the fitted mesh) is wholly on the kept side
    library = app.engine.table.library
    mesh = library.meshes[shape.geom.mesh]
    axes = np.asarray(shape.axes, dtype=np.float64)
    size = np.asarray(shape.size, dtype=np.float64)
    origin = np.asarray(shape.origin, dtype=np.float64)
    verts, faces, uv = mesh.vertices, mesh.faces, mesh.uv
    changed = False
    for normal, c, _ in planes:
        # a vertex's signed distance in the mesh's unit coordinates: its world point is
        # origin + (u * size) @ axes (no division by a size, which is 0 across a face)
        n = (axes @ np.asarray(normal)) * size
        side = verts @ n + (float(origin @ np.asarray(normal)) - c)
        scale = float(np.abs(n).max()) or 1.0
        if (side >= -_EPS * scale).all():
            continue
        if (side <= _EPS * scale).all():
            return False
        verts, faces, uv = _clip(verts, faces, uv, side, _EPS * scale)
        changed = True
        if not len(faces):
            return False
    if changed:
        trimmed = UnitMesh(mesh.name, verts, faces, uv, mesh.image)
        shape.geom = type(shape.geom)(library.add(trimmed), shape.geom.name)
    return True


def _clip(verts, faces, uv, side, eps):
    """Triangles cut to the side >= 0 of a plane (``side``: each vertex's signed distance);
    texture coordinates interpolated along the cut edges, winding kept."""
    inside = side >= -eps
    keep = inside[faces].all(axis=1)
    drop = (~inside[faces]).all(axis=1)
    out_f = [faces[keep]]
    out_uv = [uv[keep]] if uv is not None else None
    extra: list = []
    base = len(verts)
    for t in np.nonzero(~keep & ~drop)[0]:
        tri = faces[t]
        pts, d = verts[tri], side[tri]
        corners = uv[t] if uv is not None else None
        poly, poly_uv = [], []
        for i in range(3):
            j = (i + 1) % 3
            if d[i] >= -eps:
                poly.append(pts[i])
                if corners is not None:
                    poly_uv.append(corners[i])
            if (d[i] >= -eps) != (d[j] >= -eps):
                f = d[i] / (d[i] - d[j])
                poly.append(pts[i] + (pts[j] - pts[i]) * f)
                if corners is not None:
                    poly_uv.append(corners[i] + (corners[j] - corners[i]) * f)
        if len(poly) < 3:
            continue
        ids = np.arange(base, base + len(poly))
        base += len(poly)
        extra.append(np.asarray(poly))
        fan = [(ids[0], ids[k], ids[k + 1]) for k in range(1, len(poly) - 1)]
        out_f.append(np.asarray(fan, dtype=faces.dtype))
        if out_uv is not None:
            out_uv.append(
                np.asarray(
                    [(poly_uv[0], poly_uv[k], poly_uv[k + 1]) for k in range(1, len(poly) - 1)]
                )
            )
    new_verts = np.vstack([verts, *extra]) if extra else verts
    new_faces = np.vstack(out_f) if out_f else np.zeros((0, 3), dtype=faces.dtype)
    new_uv = np.concatenate(out_uv) if out_uv is not None else None
    return new_verts, new_faces, new_uv
