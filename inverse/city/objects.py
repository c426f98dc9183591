"""Objects of a city mesh by geometry: connected components on the ground plane.

A mesh that names no objects (a PLY, an OBJ without ``o`` or ``g``) is cut into connected
components (:func:`components`); a named object whose faces fall into parts apart on the ground
is split into them (:func:`separate`: a street exported as one object gives a building each).
"""

from __future__ import annotations

import numpy as np

from .model import CityObject

WELD = 1e-6  # of the scene's size: positions this close are one vertex (connected components)
PLAN_GAP = 0.2  # metres: components whose ground-plane boxes come this close are one object


def components(
    vertices: np.ndarray, faces: np.ndarray, owner: np.ndarray | None = None
) -> tuple[np.ndarray, int]:
    """(object of each face, number of objects) for a mesh that names none; with ``owner`` (the
    object each face belongs to), the parts of each object, never joining two objects.

    Faces sharing a vertex (positions equal to WELD of the scene's size) are one component;
    components whose boxes in the ground plane (bgr's x and z) come within PLAN_GAP are then
    one object, until no two do (a window modelled as a loose quad in front of its façade joins
    its building; a building in a courtyard its block).  Objects are numbered by their first
    face."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    used, local = np.unique(faces, return_inverse=True)  # unused vertices may be anything
    weld = _weld(vertices[used])[local.reshape(-1, 3)]  # (F, 3) welded vertex ids
    if owner is not None:  # a welded vertex of each object its own: (owner, vertex) pairs
        pairs = owner[:, None] * (int(weld.max()) + 1) + weld
        weld = np.unique(pairs, return_inverse=True)[1].reshape(-1, 3)
    n = int(weld.max()) + 1
    edges = np.concatenate([weld[:, [0, 1]], weld[:, [1, 2]]])
    graph = coo_matrix((np.ones(len(edges), dtype=np.int32), (edges[:, 0], edges[:, 1])), (n, n))
    _, of_vertex = connected_components(graph, directed=False)
    label = of_vertex[weld[:, 0]].astype(np.int64)
    label = _merge_plan_overlaps(vertices, faces, label, owner)
    _, first = np.unique(label, return_index=True)
    rank = np.empty(len(first), dtype=np.int64)
    rank[np.argsort(first, kind="stable")] = np.arange(len(first))
    return rank[np.searchsorted(np.unique(label), label)], len(first)


def _weld(vertices: np.ndarray) -> np.ndarray:
    """Each vertex's id, equal for positions that round to the same point of a grid of WELD
    times the scene's size (the ids of one 64-bit key per point: sorting rows is slower)."""
    lo = vertices.min(axis=0)
    size = float((vertices.max(axis=0) - lo).max()) or 1.0
    q = np.rint((vertices - lo) / (size * WELD)).astype(np.int64)  # 0 .. 1e6 < 2**20 per axis
    key = (q[:, 0] << 42) | (q[:, 1] << 21) | q[:, 2]
    return np.unique(key, return_inverse=True)[1].reshape(-1)


def _merge_plan_overlaps(
    vertices: np.ndarray, faces: np.ndarray, label: np.ndarray, owner: np.ndarray | None = None
) -> np.ndarray:
    """Labels of components merged while their ground-plane boxes overlap (within PLAN_GAP),
    only within one owner when faces have owners: merging makes boxes larger, so it repeats
    until the number of objects stays the same."""
    import shapely
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    corners = vertices[faces][:, :, [0, 2]]  # (F, 3, 2): bgr's ground plane
    face_lo, face_hi = corners.min(axis=1), corners.max(axis=1)
    _, label = np.unique(label, return_inverse=True)
    while True:
        n = int(label.max()) + 1
        lo = np.full((n, 2), np.inf)
        hi = np.full((n, 2), -np.inf)
        np.minimum.at(lo, label, face_lo)
        np.maximum.at(hi, label, face_hi)
        half = PLAN_GAP / 2
        boxes = shapely.box(lo[:, 0] - half, lo[:, 1] - half, hi[:, 0] + half, hi[:, 1] + half)
        a, b = shapely.STRtree(boxes).query(boxes, predicate="intersects")
        if owner is not None:
            of_label = np.zeros(n, dtype=np.int64)
            of_label[label] = owner
            a, b = a[of_label[a] == of_label[b]], b[of_label[a] == of_label[b]]
        graph = coo_matrix((np.ones(len(a), dtype=np.int32), (a, b)), (n, n))
        count, merged = connected_components(graph, directed=False)
        label = merged[label].astype(np.int64)
        if count == n:
            return label


def separate(
    vertices: np.ndarray, faces: np.ndarray, owner: np.ndarray, objects: list[CityObject]
) -> tuple[np.ndarray, list[CityObject]]:
    """Objects holding several buildings apart on the ground (the parts :func:`components`
    finds within one object) split into one object each, named ``NAME/1``, ``NAME/2``... in
    the order of their first faces; carried objects (roads, terrain) stay whole, and objects
    keep their order."""
    label, _ = components(vertices, faces, owner)
    first = np.unique(label, return_index=True)[1]  # each part's first face
    order = np.lexsort((first, owner[first]))  # by object, then by first face
    part_owner = owner[first[order]]
    parts_of = np.bincount(part_owner, minlength=len(objects))
    split = np.array([parts_of[k] > 1 and obj.proceduralize for k, obj in enumerate(objects)])
    if not split.any():
        return owner, objects
    new_index = np.empty(len(order), dtype=np.int64)  # by part label
    out: list[CityObject] = []
    seen: dict[int, int] = {}  # object -> its index in out (objects kept whole)
    counter = np.zeros(len(objects), dtype=np.int64)
    for part, k in zip(order.tolist(), part_owner.tolist(), strict=True):
        obj = objects[k]
        if not split[k]:
            if k not in seen:
                seen[k] = len(out)
                out.append(obj)
            new_index[part] = seen[k]
            continue
        counter[k] += 1
        piece = CityObject(
            f"{obj.name}/{counter[k]}",
            obj.kind,
            np.zeros((0, 3)),
            np.zeros((0, 3), dtype=np.int64),  # filled in by the reader's split
            attributes=dict(obj.attributes),
        )
        new_index[part] = len(out)
        out.append(piece)
    return new_index[label], out


STEEP = 0.5  # |normal . up| below this (steeper than 60 degrees): a face is a wall
WALL_SHARE = 0.05  # an object with walls on less than this share of its area is a surface


def mark_surfaces(
    vertices: np.ndarray, faces: np.ndarray, owner: np.ndarray, objects: list[CityObject]
) -> None:
    """Objects of a format without types (OBJ, PLY, glTF) that have next to no walls — roads,
    terrain, water, land use, a roof without its walls — are surfaces: carried through as they
    are (kind ``surface``, one mesh for all of them), not proceduralized as buildings, as
    CityJSON's roads and land use are by their type.  Walls are faces steeper than 60 degrees;
    under WALL_SHARE of an object's area, it has none to speak of.  When every object would be a
    surface, none is: the file is then what there is to proceduralize."""
    tri = vertices[faces]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area = np.linalg.norm(normal, axis=1)
    steep = np.abs(normal[:, 1]) < STEEP * area  # bgr's frame: y is up
    total = np.bincount(owner, area, minlength=len(objects))
    walls = np.bincount(owner, np.where(steep, area, 0.0), minlength=len(objects))
    flat = [
        k
        for k, obj in enumerate(objects)
        if obj.kind == "object" and obj.proceduralize and walls[k] < WALL_SHARE * total[k]
    ]
    if len(flat) == sum(obj.proceduralize for obj in objects):
        return
    for k in flat:
        objects[k].kind = "surface"
        objects[k].proceduralize = False
