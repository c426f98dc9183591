"""The pieces of a slab's clipped triangles merged back, plane by plane, into fewer triangles.

Clipping a triangle at a cut plane leaves a triangle on one side and a quad (two triangles) on
the other, so a wall rectangle (two triangles) crossing one cut becomes six triangles where its
two strips need four, and every cut a wall crosses adds more (Zurich's LoD2 tile went from
5,141 triangles to 10,271).  Here the pieces of one slab that lie in one plane (their
source faces' planes equal to 1e-6, and the same colour) are united in that plane (shapely, on a
grid of a micrometre, so that the two triangles' cuts of a shared edge meet) and triangulated
again by earcut.  Triangles no cut crosses are not touched, and a group is kept as it was when
merging would not make it smaller.
"""

from __future__ import annotations

import numpy as np

GRID = 1e-6  # metres: pieces are united on this grid (the cuts of a shared edge meet there)
PLANE = 1e-6  # unit normals and plane offsets (metres) equal to this are one plane


def merge_pieces(
    corners: np.ndarray, faces: np.ndarray, source: np.ndarray, plane_key: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(vertices, faces, source face of each) for the pieces ``faces`` into ``corners`` (one
    slab's clipped triangles), those of one ``plane_key`` row merged where that makes fewer."""
    if len(faces) < 2:
        return corners, faces, source
    keys, group = np.unique(plane_key, axis=0, return_inverse=True)
    group = group.reshape(-1)
    out_v, out_f, out_s, count = [], [], [], 0
    for g in range(len(keys)):
        mine = np.flatnonzero(group == g)
        merged = _merged(corners, faces[mine]) if len(mine) > 1 else None
        if merged is None or len(merged[1]) >= len(mine):
            used, remap = np.unique(faces[mine], return_inverse=True)
            v, f = corners[used], remap.reshape(-1, 3)
            s = source[mine]
        else:
            v, f = merged
            s = np.full(len(f), source[mine[0]])
        out_v.append(v)
        out_f.append(f + count)
        out_s.append(s)
        count += len(v)
    return np.concatenate(out_v), np.concatenate(out_f).astype(np.int64), np.concatenate(out_s)


def _merged(corners: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """Coplanar triangles united and triangulated again, facing as they did; None when shapely
    or earcut cannot (the pieces then stay as they are)."""
    import shapely
    from trimesh.creation import triangulate_polygon

    tri = corners[faces]
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normal = cross.sum(axis=0)
    length = np.linalg.norm(normal)
    if length < 1e-12:
        return None
    normal /= length
    u = np.cross(normal, [0.0, 1.0, 0.0] if abs(normal[1]) < 0.9 else [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    w = np.cross(normal, u)  # (u, w, normal) right-handed: counter-clockwise in 2D faces +normal
    origin = tri[0, 0]
    flat = np.stack([(tri - origin) @ u, (tri - origin) @ w], axis=-1)  # (n, 3, 2)
    try:
        union = shapely.union_all(shapely.polygons(flat), grid_size=GRID)
        # corners on a straight edge (where a neighbour's cut ended) go: they hold no shape
        union = shapely.simplify(union, GRID)
        parts = list(getattr(union, "geoms", [union]))
        out_v, out_f, count = [], [], 0
        for part in parts:
            if part.is_empty or part.geom_type != "Polygon" or part.area <= 0:
                continue
            v2, f = triangulate_polygon(part, engine="earcut")
            v3 = origin + v2[:, :1] * u + v2[:, 1:2] * w
            # earcut's winding follows the ring's; turn each to face +normal
            t = v3[f]
            facing = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]) @ normal
            f = np.where((facing < 0)[:, None], f[:, ::-1], f)
            out_v.append(v3)
            out_f.append(f + count)
            count += len(v3)
    except Exception:  # GEOS or earcut on degenerate pieces: keep them as they were
        return None
    if not out_f:
        return None
    return np.concatenate(out_v), np.concatenate(out_f)


def plane_keys(vertices: np.ndarray, faces: np.ndarray, colors: np.ndarray | None) -> np.ndarray:
    """(F, 4 or 8) integer rows equal for faces in one plane (unit normal and offset to
    :data:`PLANE`) and, where the input has colours, of one colour."""
    tri = vertices[faces]
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    norm = np.linalg.norm(cross, axis=1, keepdims=True)
    unit = np.divide(cross, norm, out=np.zeros_like(cross), where=norm > 0)
    offset = np.einsum("ij,ij->i", unit, tri[:, 0])
    key = np.rint(np.column_stack([unit, offset]) / PLANE).astype(np.int64)
    if colors is not None and len(colors) == len(faces):
        key = np.column_stack([key, np.asarray(colors, dtype=np.int64)])
    return key
