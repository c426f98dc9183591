"""Cut planes and components: a building cut into slabs where its cross-section changes.

The paper (section IV.A) renders the building between a near and a far plane moving up, and puts
a cut plane where the pixel difference between consecutive contours has a non-zero second
derivative.  Here the same criterion is computed from the geometry, with no window system:

* the cross-section's outline only changes course at the heights of vertices, so those are the
  candidate heights;
* the pixel difference between two contours dz apart is the area the contour sweeps, which is
  ``R(z) dz`` with ``R(z) = sum over sloped faces crossing z of (section length) x |n_up| / |n_h|``
  (a vertical wall sweeps nothing, a 45 degree roof face sweeps its own section length per metre);
* a **step** (a terrace or an overhang: flat faces at z) is an infinite first derivative,
  and a **kink** (R jumps: walls end and a roof begins, one wing's roof ends) a non-zero second
  derivative.  A cut is made at either.  Inside a hip roof R shrinks smoothly and no cut is made,
  so a roof is one component, as in the paper's Figure 3.

Measured data is not exact: faces within 3 degrees of vertical count as walls and within 5.7
degrees of horizontal as flat, and no slab is thinner than MIN_SLAB (a candidate closer than that
to the last cut, the bottom or the top is passed over), where the rendered contours of the paper
would not show a difference either.

Each slab between consecutive cuts is a component: the triangles inside it, with those that cross
a cut clipped at the plane (trimesh's ``slice_faces_plane``; the pieces of one plane then merged
back into fewer triangles, :mod:`.remesh`), so the components together cover
exactly the building's surface.  A horizontal face lying on a cut goes to the slab it closes: an
upward-facing terrace to the slab below, a downward-facing overhang to the slab above.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from trimesh.intersections import slice_faces_plane

from .remesh import merge_pieces, plane_keys

HEIGHT_TOL = 1e-4  # metres: vertex heights closer than this are one height
HORIZONTAL = 0.995  # |n_up| above this (under 5.7 degrees): a flat face (a step, not a slope)
VERTICAL = 0.05  # |n_up| below this (within 3 degrees of vertical): a wall, sweeping nothing
MIN_SLAB = 0.5  # metres: no component is thinner (measured walls and terrain are not exact)
STEP_AREA = 0.05  # m2, and STEP_SHARE of the footprint: a smaller terrace is noise, not a step
STEP_SHARE = 0.002
KINK_RATE = 0.05  # m2 per m, and KINK_SHARE of the contour length: a smaller jump of R is noise
KINK_SHARE = 0.02


@dataclass
class Slab:
    """One component's triangles: a slab of a building between two cut heights."""

    bottom: float
    top: float
    vertices: np.ndarray  # (V, 3) float64, bgr frame
    faces: np.ndarray  # (F, 3) int64
    source_faces: np.ndarray  # (F,) int64: the building face each triangle was cut from


def _face_geometry(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit normals (zero for degenerate triangles) and areas of the faces."""
    tri = vertices[faces]
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    double_area = np.linalg.norm(cross, axis=1)
    normals = np.divide(
        cross, double_area[:, None], out=np.zeros_like(cross), where=double_area[:, None] > 0
    )
    return normals, double_area / 2


def section_lengths(tri_heights: np.ndarray, tri: np.ndarray, z: float) -> np.ndarray:
    """The length of each triangle's intersection with the horizontal plane at height ``z``.

    ``tri`` is (F, 3, 3) corners, ``tri_heights`` their heights (F, 3).  Zero for triangles the
    plane misses; computed from the two edges whose ends lie on either side of the plane."""
    side = tri_heights - z
    points = []
    for a, b in ((0, 1), (1, 2), (2, 0)):
        ha, hb = side[:, a], side[:, b]
        crosses = (ha * hb < 0) | ((ha == 0) & (hb != 0))
        t = np.divide(ha, ha - hb, out=np.zeros_like(ha), where=crosses)
        p = tri[:, a] + t[:, None] * (tri[:, b] - tri[:, a])
        points.append(np.where(crosses[:, None], p, np.nan))
    stacked = np.stack(points, axis=1)  # (F, 3 edges, 3)
    found = ~np.isnan(stacked[:, :, 0])
    lengths = np.zeros(len(tri))
    two = found.sum(axis=1) >= 2
    if two.any():
        order = np.argsort(~found[two], axis=1, kind="stable")[:, :2]
        pts = np.take_along_axis(stacked[two], order[:, :, None], axis=1)
        lengths[two] = np.linalg.norm(pts[:, 0] - pts[:, 1], axis=1)
    return lengths


def cut_heights(vertices: np.ndarray, faces: np.ndarray) -> list[float]:
    """The heights (bgr's y) where a building is cut into components, lowest first; the
    building's own bottom and top are not cuts.  See the module docstring for the criterion."""
    if len(faces) == 0:
        return []
    normals, areas = _face_geometry(vertices, faces)
    up = normals[:, 1]
    tri = vertices[faces]
    heights = tri[:, :, 1]
    lo, hi = heights.min(axis=1), heights.max(axis=1)
    candidates = np.unique(np.round(vertices[:, 1] / HEIGHT_TOL).astype(np.int64)) * HEIGHT_TOL
    bottom, top = float(vertices[:, 1].min()), float(vertices[:, 1].max())
    candidates = candidates[(candidates > bottom + HEIGHT_TOL) & (candidates < top - HEIGHT_TOL)]
    if len(candidates) == 0:
        return []
    footprint = float(np.sum(areas[up > 0] * up[up > 0]))
    flat = np.abs(up) > HORIZONTAL
    sloped = ~flat & (np.abs(up) > VERTICAL)
    horizontal = np.sqrt(np.maximum(1.0 - up**2, 0.0))
    speed = np.divide(np.abs(up), horizontal, out=np.zeros_like(up), where=horizontal > 0)
    walls = ~flat
    flat_height = (lo + hi) / 2
    gaps = np.diff(np.concatenate([[bottom], candidates, [top]]))
    cuts: list[float] = []
    for k, z in enumerate(candidates):
        if z < (cuts[-1] if cuts else bottom) + MIN_SLAB or z > top - MIN_SLAB:
            continue
        step = float(areas[flat & (np.abs(flat_height - z) < HEIGHT_TOL)].sum())
        if step > max(STEP_AREA, STEP_SHARE * footprint):
            cuts.append(float(z))
            continue
        delta = min(1e-3, gaps[k] / 2, gaps[k + 1] / 2)
        rate, length = [], []
        for zz in (z - delta, z + delta):
            near = walls & (lo < zz) & (hi > zz)
            lengths = section_lengths(heights[near], tri[near], zz)
            rate.append(float(np.sum(lengths * speed[near] * sloped[near])))
            length.append(float(lengths.sum()))
        if abs(rate[1] - rate[0]) > max(KINK_RATE, KINK_SHARE * max(length)):
            cuts.append(float(z))
    return cuts


def slabs(
    vertices: np.ndarray,
    faces: np.ndarray,
    cuts: list[float],
    colors: np.ndarray | None = None,
) -> list[Slab]:
    """The building's triangles cut into one slab per interval between its cuts (see the module
    docstring); slabs that get no triangles are left out.  The clipped pieces of each slab are
    merged back plane by plane (:mod:`.remesh`; ``colors``, one per face: pieces of different
    colours are not merged)."""
    if len(faces) == 0:
        return []
    bottom, top = float(vertices[:, 1].min()), float(vertices[:, 1].max())
    levels = [bottom, *cuts, top]
    heights = vertices[faces][:, :, 1]
    lo, hi = heights.min(axis=1), heights.max(axis=1)
    normals, _ = _face_geometry(vertices, faces)
    keys = None  # each face's plane (and colour), the first time a face is clipped
    out = []
    for i in range(len(levels) - 1):
        z0, z1 = levels[i], levels[i + 1]
        first, last = i == 0, i == len(levels) - 2
        on_bottom = (np.abs(hi - z0) < HEIGHT_TOL) & (np.abs(lo - z0) < HEIGHT_TOL)
        on_top = (np.abs(hi - z1) < HEIGHT_TOL) & (np.abs(lo - z1) < HEIGHT_TOL)
        inside = (lo >= z0 - HEIGHT_TOL) & (hi <= z1 + HEIGHT_TOL) & ~on_bottom & ~on_top
        # a flat face on a cut closes the slab it faces away from (see the module docstring)
        keep_bottom = on_bottom & ((normals[:, 1] < 0) | first)
        keep_top = on_top & ((normals[:, 1] >= 0) | last)
        whole = np.flatnonzero(inside | keep_bottom | keep_top)
        crossing = np.flatnonzero((lo < z1 - HEIGHT_TOL) & (hi > z0 + HEIGHT_TOL) & ~inside)
        parts_v, parts_f, parts_s = [vertices], [faces[whole]], [whole]
        if len(crossing):
            v, f, tag = _clip(vertices, faces, crossing, z0, z1)
            if keys is None:
                keys = plane_keys(vertices, faces, colors)
            v, f, tag = merge_pieces(v, f, tag, keys[tag])
            parts_v.append(v)
            parts_f.append(f + len(vertices))
            parts_s.append(tag)
        all_v = np.concatenate(parts_v)
        all_f = np.concatenate(parts_f).astype(np.int64)
        if len(all_f) == 0:
            continue
        used, remap = np.unique(all_f, return_inverse=True)
        out.append(
            Slab(
                z0, z1, all_v[used], remap.reshape(-1, 3).astype(np.int64), np.concatenate(parts_s)
            )
        )
    return out


def _clip(
    vertices: np.ndarray, faces: np.ndarray, index: np.ndarray, z0: float, z1: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The parts of faces ``index`` between heights z0 and z1, and the face each part came from.

    The faces are given their own corners, and each corner carries its face's index as a
    texture coordinate, which slicing interpolates along the triangle's own edges, so every
    piece still carries the index of the face it was cut from."""
    corners = vertices[faces[index]].reshape(-1, 3)
    own = np.arange(len(corners)).reshape(-1, 3)
    tag = np.column_stack([np.repeat(index, 3).astype(float), np.zeros(len(corners))])
    for normal, height in (((0.0, 1.0, 0.0), z0), ((0.0, -1.0, 0.0), z1)):
        if len(own) == 0:
            break
        with np.errstate(all="ignore"):  # a sliver's barycentric weights: see _sources
            corners, own, tag = slice_faces_plane(
                corners, own, np.array(normal), np.array([0.0, height, 0.0]), uv=tag
            )
    own = np.asarray(own, dtype=np.int64).reshape(-1, 3)
    source, keep = _sources(tag, own)
    return corners, own[keep], source


def _sources(tag: np.ndarray, own: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(the face each piece was cut from, which pieces have one).  trimesh interpolates a cut
    corner's tag by barycentric weights, which a face of no area (a sliver of the first cut, a
    collapsed input face) turns into NaN: such a corner is skipped for a sibling's tag, and a
    piece with none is dropped (it has no area either) rather than cast to a wild index."""
    if not len(own):
        return np.zeros(0, np.int64), np.zeros(0, dtype=bool)
    tags = tag[own, 0]  # (P, 3)
    finite = np.isfinite(tags)
    pick = tags[np.arange(len(own)), np.argmax(finite, axis=1)]
    keep = finite.any(axis=1)
    return np.rint(pick[keep]).astype(np.int64), keep
