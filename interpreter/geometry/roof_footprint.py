"""The footprint a roof stands on, and its eave polygon: what every roof kind starts from.

:class:`_Footprint` is the input polygon cleaned for the geometry (counter-clockwise, no
repeated points or collinear corners, each edge remembering the input edges it stands for);
:func:`_eave_ring` grows it outward by the overhang, bevelling corners too sharp to mitre
(see "Overhang" in :mod:`.roofs`); :func:`_slope_plane` and :func:`_wall_plane` are the planes
that rise from or stand on its lines.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from shapely.geometry import Polygon

from .earclip import signed_area
from .roof_model import RoofPlane, _cross, _unit
from .skeleton import edge_lines, offset_outward

_CLEAN_TOL = 2e-6  # relative: corners closer than this, or this close to straight, are dropped
MITRE_LIMIT = 2.0  # an eave corner reaches at most this many overhangs from its footprint corner


@dataclass
class _Footprint:
    """The footprint cleaned for the geometry: counter-clockwise, no repeated points, no
    collinear corners; each of its edges remembers the input edges it stands for."""

    points: np.ndarray  # (n, 2)
    edges: list[tuple[int, ...]]  # input edge indices on each edge
    label: list[int]  # the input edge that names each edge (the longest of them)
    front: int  # the edge that carries input edge 0
    scale: float

    @classmethod
    def of(cls, polygon) -> _Footprint:
        pts = np.asarray(polygon, dtype=np.float64)
        if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 3:
            raise ValueError("a roof footprint is a (K, 2) array of K >= 3 points")
        if not np.isfinite(pts).all():
            raise ValueError("a roof footprint has non-finite coordinates")
        count = len(pts)
        scale = float(np.ptp(pts, axis=0).max())
        keep, runs = _essential_corners(pts, [(i,) for i in range(count)], _CLEAN_TOL * scale)
        if len(keep) < 3 or not Polygon(pts[keep]).is_valid or Polygon(pts[keep]).area <= 0:
            raise ValueError("a roof footprint must be a simple polygon of non-zero area")
        if signed_area(pts[keep]) < 0:  # clockwise: reverse, edge j now runs keep[j] -> keep[j+1]
            keep = keep[::-1]
            runs = [runs[j - 1] for j in range(len(runs) - 1, -1, -1)]
        label = [
            max(run, key=lambda i: np.linalg.norm(pts[(i + 1) % count] - pts[i])) for run in runs
        ]
        front = next(j for j, run in enumerate(runs) if 0 in run)
        return cls(
            points=pts[keep],
            edges=[tuple(sorted(r)) for r in runs],
            label=label,
            front=front,
            scale=scale,
        )

    def line(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """The inward unit normal of line k and a point on it: edge k, or for ``k >= n`` the
        bevel of corner ``k - n`` (see :func:`_eave_ring`): through the corner, its normal
        halfway between those of the corner's two edges."""
        _, nrm, _ = edge_lines(self.points)
        n = len(self.points)
        if k < n:
            return nrm[k], self.points[k]
        j = k - n
        return _unit(nrm[j - 1] + nrm[j]), self.points[j]

    def naming(self, k: int, kind: str = "slope") -> tuple[str, int | None, tuple[int, ...]]:
        """``(kind, edge, edges)`` of a RoofPlane on line k (see :meth:`line`)."""
        n = len(self.points)
        if k < n:
            return kind, self.label[k], self.edges[k]
        j = k - n
        return "corner", None, (self.label[j - 1], self.label[j])


def _essential_corners(pts: np.ndarray, runs: list, tol: float):
    """Drop the corners of a ring that are within ``tol`` of the previous one or of the straight
    line through their neighbours.  Returns the kept indices and, for each kept edge (from kept
    corner j to j+1), the merged ``runs`` of the edges it replaces (``runs[i]`` belongs to the
    input edge from point i to i+1)."""
    keep, runs = list(range(len(pts))), list(runs)
    changed = True
    while changed and len(keep) >= 3:
        changed = False
        m = len(keep)
        for q in range(m):
            a, b, c = pts[keep[q - 1]], pts[keep[q]], pts[keep[(q + 1) % m]]
            ac = np.linalg.norm(c - a)
            straight = ac > tol and abs(_cross(b - a, c - a)) <= tol * ac and (b - a) @ (c - b) > 0
            if np.linalg.norm(b - a) <= tol or straight:
                runs[q - 1] = runs[q - 1] + runs[q]  # edge q-1 now reaches keep[q+1]
                del keep[q], runs[q]
                changed = True
                break
    return keep, runs


def _sharp_corners(pts: np.ndarray, weights: np.ndarray) -> list[int]:
    """The convex corners between two moving edges whose mitre would reach more than
    MITRE_LIMIT overhangs: interior angle theta with sin(theta / 2) < 1 / MITRE_LIMIT."""
    d, _, _ = edge_lines(pts)
    before = np.roll(d, 1, axis=0)  # the edge into corner j
    convex = _cross(before, d) > 0
    sharp = np.einsum("ij,ij->i", before, d) < 2.0 / MITRE_LIMIT**2 - 1.0
    moving = (weights > 0) & (np.roll(weights, 1) > 0)
    return [int(j) for j in np.flatnonzero(convex & sharp & moving)]


def _bevelled(pts: np.ndarray, weights: np.ndarray, sharp: list[int], overhang: float):
    """The polygon whose outward offset by ``overhang`` is the bevelled eave of ``pts``: each
    sharp corner cut by a short chamfer that moves out fast enough (its speed) to end at distance
    ``overhang`` beyond the corner.  Returns the points, the edges' speeds and, per edge, its
    line (footprint edge k, or ``n + j`` for the chamfer of corner j)."""
    n = len(pts)
    if not sharp:
        return pts, weights, np.arange(n)
    lengths = np.linalg.norm(np.roll(pts, -1, axis=0) - pts, axis=1)
    d, _, _ = edge_lines(pts)
    cuts = np.minimum(overhang, 0.25 * np.minimum(lengths, np.roll(lengths, 1)))
    for _ in range(8):  # cuts small enough that the chamfered polygon stays simple
        points, speed, lines = [], [], []
        for j in range(n):
            if j in sharp:
                cut = float(cuts[j])
                a, b = pts[j] - cut * d[j - 1], pts[j] + cut * d[j]
                inset = float(np.linalg.norm(d[j] - d[j - 1])) * cut / 2.0  # corner to chamfer
                points += [a, b]
                speed += [1.0 + inset / overhang, weights[j]]
                lines += [n + j, j]
            else:
                points.append(pts[j])
                speed.append(weights[j])
                lines.append(j)
        points = np.array(points)
        if Polygon(points).is_valid:
            return points, np.array(speed), np.array(lines, dtype=np.int64)
        cuts /= 8.0
    raise ValueError("a roof footprint with corners too sharp to bevel")


def _eave_ring(fp: _Footprint, overhang: float, weights: np.ndarray):
    """The eave polygon (see the module docstring) and, for each of its edges, the line whose
    plane it carries: footprint edge k, or ``n + j`` for the bevel of corner j.

    A mitred corner reaches ``overhang / sin(angle / 2)`` from its footprint corner: without a
    limit, a corner of a few degrees (a needle that a digitising slip left on a footprint) sends
    the eave hundreds of metres away.  So a convex corner whose mitre would reach more than
    MITRE_LIMIT overhangs (one sharper than 60 degrees) is bevelled: the eave gets an edge at
    distance ``overhang`` from the corner, square to the corner's bisector, and the roof a
    *corner* plane rising from it at the roof's pitch through the corner itself, so the roof
    still sits on the corner.  (Without an overhang a corner needs no bevel.)
    """
    sharp = _sharp_corners(fp.points, weights) if overhang > 0 else []
    poly, speed, lines = _bevelled(fp.points, weights, sharp, overhang)
    ring, source = offset_outward(poly, overhang, speed)
    source = lines[source]
    keep, runs = _essential_corners(ring, [(q,) for q in range(len(ring))], _CLEAN_TOL * fp.scale)
    if len(keep) < 3:
        raise ValueError("the roof's eave polygon collapsed")
    m = len(ring)
    longest = [max(run, key=lambda q: np.linalg.norm(ring[(q + 1) % m] - ring[q])) for run in runs]
    return ring[keep], source[longest]


def _slope_plane(
    fp: _Footprint, k: int, tan: float, start: float = 0.0, base: float = 0.0
) -> RoofPlane:
    """The plane over line k (an edge, or a bevelled corner: :meth:`_Footprint.line`) that is at
    height ``base`` at inset ``start`` and rises at ``tan``."""
    nrm, origin = fp.line(k)
    normal = _unit([-tan * nrm[0], -tan * nrm[1], 1.0])
    point = np.append(origin + start * nrm, base)
    kind, edge, edges = fp.naming(k)
    return RoofPlane(kind, edge, edges, normal, float(normal @ point), math.degrees(math.atan(tan)))


def _wall_plane(fp: _Footprint, k: int, kind: str, through) -> RoofPlane:
    """The vertical plane along line k through the point ``through`` (2D), facing outward."""
    nrm, _ = fp.line(k)
    normal = np.array([-nrm[0], -nrm[1], 0.0])
    _, edge, edges = fp.naming(k, kind)
    return RoofPlane(kind, edge, edges, normal, float(normal[:2] @ through), 90.0)
