"""Roof meshes over a footprint: the geometry of ``roof(kind, pitch, overhang)`` (LANGUAGE.md §5).

Everything here works in a face-local frame: the footprint is a simple polygon (K, 2) in metres
in the xy plane (either orientation, convex or not — L, T, U shapes —, no holes) and the roof
rises along +z from the footprint's edges at z = 0.  The interpreter maps that frame onto the
shape's scope (where y is up).

Kinds
-----
``hip``
    The straight-skeleton roof: every footprint edge carries one plane at ``pitch``; planes meet
    along hips, valleys and ridges; a node at offset ``t`` from the footprint is at height
    ``t * tan(pitch)``, so the top is at ``tan(pitch)`` times the largest inset distance.
``gable``
    A hip roof whose wing ends are vertical gable walls: an edge gets a gable when its hip face is
    a triangle over two convex corners whose apex starts a ridge between the two neighbouring
    slopes (the short ends of a rectangle, the ends of every wing of an L, T or U).  The skeleton
    is then recomputed with those edges not moving (weight 0), so the neighbouring slopes run on
    until they meet the wall: the wall's face is a vertical triangle in the wall's plane.  A convex
    quadrilateral whose hip roof has no ridge (a square) gets gables on the two edges beside its
    front edge (``polygon[0] -> polygon[1]``), so the ridge runs parallel to the front.  Shapes
    with no wing end (a regular hexagon, a triangle) keep their hip roof.  A gable whose wall
    would not stay a wall in the eave polygon (next to a reflex corner there, once an overhang
    has closed a notch) is made a slope again, rising from the eave.
``pyramid``
    One apex, one triangle per edge.  The apex is above the centroid or the pole of
    inaccessibility, whichever is farther from the boundary (the centroid on a tie), among those
    that see every edge from the inside (the polygon's kernel), otherwise above the kernel's own
    pole of inaccessibility; its height is ``tan(pitch)`` times its distance to the
    footprint's boundary, so the faces of the nearest edges have exactly ``pitch`` and the others
    are shallower.  A footprint with an empty kernel (a U) cannot carry a pyramid and gets a hip.
``shed``
    One plane rising at ``pitch`` from the first edge (``polygon[0] -> polygon[1]``) across the
    footprint (``z = tan(pitch) * distance to that edge's line``, raised if some corner lies
    behind that line so that nothing is below the eave), plus vertical walls down to the eave.
``flat``
    The footprint itself at z = 0, triangulated (pitch is ignored), with its holes (courtyards)
    left open: each hole shrinks by the overhang, as the eaves reach into the courtyard.
``mansard``
    Two hip slopes: a steep lower band at ``mansard_lower_pitch(pitch) = 45 + pitch / 2`` degrees
    over the first third (``MANSARD_BREAK``) of the largest inset distance, then a shallow hip at
    ``pitch`` on the inset polygon.  It is one straight skeleton cut at the break offset, so the
    two bands share their break line exactly.
``gambrel``
    The mansard's two slopes with the gable's ends (the gable walls are vertical pentagons).

Overhang
--------
``overhang`` moves the eaves outward horizontally by that distance while every roof plane stays
the plane of the roof without overhang: a plane at pitch ``p`` still passes through its wall-top
edge at z = 0, and the eave ends ``overhang * tan(p)`` lower (for a mansard or gambrel, ``p`` is
the lower band's pitch); gable walls do not move, so a gable end has no overhang.  For the
skeleton kinds the roof is the skeleton of the *eave polygon* — the footprint grown outward by the
overhang (mitred corners; gable walls stay in their plane) — lowered by that amount; a shed and a
flat roof cover the same eave polygon.  The eave polygon is grown by the outward wavefront with
its events, so an overhang wider than a small indent closes it, and one that would make opposite
eaves meet across a narrow courtyard covers it; there the eave polygon has lost edges and the roof
near them is the roof of the grown shape rather than an extension of the roof without overhang.

A mitre reaches ``overhang / sin(angle / 2)`` from a corner of that angle: a corner of a few
degrees (a needle left on a footprint by a digitising slip) would send the eave hundreds of metres
away.  So a convex corner sharper than 60 degrees, whose mitre would reach more than
``MITRE_LIMIT`` (2) overhangs, is *bevelled*: the eave polygon gets an edge ``overhang`` beyond the
corner, square to its bisector, from which a ``corner`` plane rises at the roof's pitch through
the corner itself (a small hip facet; without an overhang it has no size and no corner is
bevelled).  A gable wall next to such a corner becomes a slope when there is an overhang.  So no
eave corner is more than ``MITRE_LIMIT * overhang`` from its footprint corner.

A pyramid keeps its planes too: each hip (from the apex through a corner) is carried on past its
corner until the eave is ``overhang`` beyond the nearer of the corner's two walls, but not more than
``MITRE_LIMIT * overhang`` from the corner; each eave corner is as low as its hip takes it.  On a
regular footprint every corner goes the same way (the eave is level at ``-overhang * tan(pitch)``,
every eave ``overhang`` out); on a long one the limit holds the far corners back, so the walls
nearest the apex get less than ``overhang`` and the eave slopes.  (Carrying every hip on by
``overhang`` over the apex's clearance, as before, gave a 6 m x 70 m footprint 5.8 m eaves at its
ends for a 0.5 m overhang, and a needle eaves of two kilometres.)

Holes
-----
A footprint's holes (``holes=``: the courtyards of a block) are kept by a ``flat`` roof only.  The
straight skeleton here is that of a simple polygon, so the other kinds are built on the outline
alone and roof a courtyard over (as a hip roof over the whole block would); a grammar that meets
courtyard blocks can give them flat roofs.

Output
------
A :class:`RoofMesh`: vertices (V, 3), triangles (F, 3) counter-clockwise seen from outside,
``face_plane`` (F,) the plane of each triangle, ``planes`` (:class:`RoofPlane`: the edge a plane
rises from, its unit normal, its offset and pitch), and ``eave``, the outline of the open bottom.
Every kind but ``flat`` is a closed surface once a cap on ``eave`` (facing down) is added.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry import Point, Polygon
from shapely.ops import polylabel

from .earclip import signed_area, triangulate
from .skeleton import Skeleton, SkeletonError, edge_lines, offset_outward, straight_skeleton

KINDS = ("flat", "gable", "hip", "pyramid", "shed", "mansard", "gambrel")
MANSARD_BREAK = 1.0 / 3.0  # the steep lower band covers this fraction of the largest inset
_CLEAN_TOL = 2e-6  # relative: corners closer than this, or this close to straight, are dropped
MITRE_LIMIT = 2.0  # an eave corner reaches at most this many overhangs from its footprint corner


def mansard_lower_pitch(pitch: float) -> float:
    """Pitch (degrees) of the steep lower band of a mansard or gambrel roof of ``pitch``."""
    return 45.0 + pitch / 2.0


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
    """A roof's triangle mesh; see the module docstring."""

    vertices: np.ndarray  # (V, 3) float64
    faces: np.ndarray  # (F, 3) int32, counter-clockwise seen from outside / above
    face_plane: np.ndarray  # (F,) int: index into planes
    planes: list[RoofPlane]
    eave: np.ndarray  # (E, 3): the outline of the open bottom, counter-clockwise from above
    overhang: float
    kind: str  # the kind built (a pyramid that cannot be built is a hip)
    fallback: str = ""  # why the kind built is not the kind asked for, when that is a surprise


def roof_mesh(polygon, kind: str, pitch: float, overhang: float = 0.0, holes=()) -> RoofMesh:
    """The roof of ``kind`` over ``polygon`` (K, 2); see the module docstring for each kind.
    ``holes`` (rings (H, 2) inside the polygon) are left open by a flat roof (see "Holes")."""
    if kind not in KINDS:
        raise ValueError(f"unknown roof kind {kind!r}; expected one of {', '.join(KINDS)}")
    overhang = float(overhang)
    if not math.isfinite(overhang) or overhang < 0:
        raise ValueError(f"roof overhang must be >= 0, got {overhang}")
    pitch = float(pitch)
    if kind != "flat" and not (0.0 < pitch < 90.0):
        raise ValueError(f"roof pitch must be between 0 and 90 degrees, got {pitch}")
    fp = _Footprint.of(polygon)
    if kind == "flat":
        return _flat_roof(fp, overhang, holes)
    if kind == "shed":
        return _shed_roof(fp, pitch, overhang)
    if kind == "pyramid":
        apex = _pyramid_apex(fp)
        if apex is not None:
            return _pyramid_roof(fp, pitch, overhang, apex)
        kind = "hip"
    return _skeleton_roof(fp, kind, pitch, overhang)


# --------------------------------------------------------------------------------------------
# the footprint


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


def _cross(u, v):
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


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


# --------------------------------------------------------------------------------------------
# assembling a mesh


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


# --------------------------------------------------------------------------------------------
# hip, gable, mansard, gambrel: straight skeletons


def _skeleton_roof(fp: _Footprint, kind: str, pitch: float, overhang: float) -> RoofMesh:
    """Lift the (weighted, possibly staged) straight skeleton of the eave polygon."""
    pts = fp.points
    n = len(pts)
    hip = straight_skeleton(pts)
    weights = np.ones(n)
    if kind in ("gable", "gambrel"):
        weights[_gable_edges(fp, hip)] = 0.0
        if overhang > 0:  # a sharp corner is bevelled (see _eave_ring): no gable wall beside it
            for j in _sharp_corners(pts, np.ones(n)):
                weights[[j - 1, j]] = 1.0
    line_weights = np.concatenate([weights, np.ones(n)])  # a bevelled corner is a slope
    two_slopes = kind in ("mansard", "gambrel")
    pitches = (mansard_lower_pitch(pitch), pitch) if two_slopes else (pitch,)
    tans = [math.tan(math.radians(p)) for p in pitches]
    inset = MANSARD_BREAK * hip.t_max  # where the lower band of a two-slope roof ends
    breaks = (overhang + inset,) if two_slopes else ()

    try:
        if overhang == 0 and not breaks and weights.all():
            eave, source, speed, sk = pts, np.arange(len(pts)), weights, hip
        else:
            eave, source = _eave_ring(fp, overhang, weights)
            speed, sk = _gabled_skeleton(eave, line_weights[source], breaks)
    except SkeletonError as exc:
        if weights.all():
            raise
        mesh = _skeleton_roof(fp, "mansard" if two_slopes else "hip", pitch, overhang)
        mesh.fallback = f"its gable ends could not be built ({exc})"
        return mesh

    t = sk.nodes[:, 2]
    z = tans[0] * (t - overhang)
    if two_slopes:
        z = np.where(t > overhang + inset, tans[0] * inset + tans[1] * (t - overhang - inset), z)
    builder = _MeshBuilder(np.column_stack([sk.nodes[:, :2], z]))
    d, _, _ = edge_lines(eave)
    for stage, faces in enumerate(sk.faces):
        for k, cycles in enumerate(faces):
            edge = int(source[k])
            if not cycles:
                continue
            if speed[k] > 0:
                # an eave edge grown by the overhang rises from its wall top at z = 0; a gable
                # that had to become a slope rises from the eave height instead
                lower = overhang - overhang * line_weights[edge]
                plane = builder.plane(
                    ("slope", edge, stage, lower),
                    _slope_plane,
                    fp,
                    edge,
                    tans[stage],
                    inset * stage + lower,
                    tans[0] * inset * stage,
                )
                flat = sk.nodes[:, :2]
            else:
                plane = builder.plane(("gable", edge), _wall_plane, fp, edge, "gable", pts[edge])
                flat = np.column_stack([sk.nodes[:, :2] @ d[k], sk.nodes[:, 2]])
            for cycle in cycles:
                builder.add_polygon(cycle, flat[cycle], plane)
    return builder.finish(builder.vertices[: len(eave)], overhang, kind)


def _gabled_skeleton(eave: np.ndarray, speed: np.ndarray, breaks) -> tuple[np.ndarray, Skeleton]:
    """The skeleton of the eave polygon with its gable edges (speed 0) held still.

    A gable keeps its wall only where the wall stays a wall: an edge next to a reflex corner of
    the eave polygon (possible once an overhang has closed a notch) would have its wall pushed
    into the roof, and any gable whose face leaves its own line is likewise made a slope again.
    """
    speed = speed.copy()
    d, nrm, c = edge_lines(eave)
    convex = _cross(np.roll(d, 1, axis=0), d) > 0
    speed[~(convex & np.roll(convex, -1))] = 1.0
    tol = 1e-6 * float(np.ptp(eave, axis=0).max())
    while True:
        sk = straight_skeleton(eave, speed, breaks)
        astray = [
            k
            for k in np.flatnonzero(speed == 0)
            if any(
                np.abs(sk.nodes[cycle, :2] @ nrm[k] - c[k]).max() > tol
                for faces in sk.faces
                for cycle in faces[k]
            )
        ]
        if not astray:
            return speed, sk
        speed[astray] = 1.0


def _gable_edges(fp: _Footprint, hip: Skeleton) -> list[int]:
    """The edges that get a gable wall: see ``gable`` in the module docstring."""
    pts = fp.points
    n = len(pts)
    d, _, _ = edge_lines(pts)
    convex = _cross(np.roll(d, 1, axis=0), d) > 0  # at vertex i, between edges i-1 and i
    faces = hip.faces[0]
    xy = hip.nodes[:, :2]
    sides = [
        {frozenset((c[i], c[(i + 1) % len(c)])) for c in cycles for i in range(len(c))}
        for cycles in faces
    ]
    min_ridge = 1e-6 * fp.scale
    chosen = []
    for k in range(n):
        if len(faces[k]) != 1 or not (convex[k] and convex[(k + 1) % n]):
            continue
        corners = _corners(faces[k][0], xy)
        apex = [v for v in corners if v not in (k, (k + 1) % n)]
        if len(corners) != 3 or len(apex) != 1:
            continue
        # a ridge: a segment between two skeleton nodes that both neighbouring slopes share;
        # in a triangle those slopes also share the hip from their common corner (node < n),
        # which is no ridge
        shared = sides[k - 1] & sides[(k + 1) % n]
        if any(
            apex[0] in s and min(s) >= n and np.linalg.norm(np.subtract(*xy[list(s)])) > min_ridge
            for s in shared
        ):
            chosen.append(k)
    if not chosen and n == 4 and convex.all():
        chosen = [(fp.front + 1) % 4, (fp.front + 3) % 4]
    return chosen


def _corners(cycle: list[int], xy: np.ndarray) -> list[int]:
    """The nodes of a face cycle where it turns (straight-through nodes left out)."""
    out = []
    m = len(cycle)
    for i in range(m):
        a, b, c = xy[cycle[i - 1]], xy[cycle[i]], xy[cycle[(i + 1) % m]]
        u, v = b - a, c - b
        if abs(_cross(u, v)) > 1e-9 * np.linalg.norm(u) * np.linalg.norm(v) or u @ v < 0:
            out.append(cycle[i])
    return out


# --------------------------------------------------------------------------------------------
# pyramid


def _pyramid_apex(fp: _Footprint):
    """Where the apex goes (see ``pyramid`` in the module docstring), or None (empty kernel)."""
    _, nrm, c = edge_lines(fp.points)
    margin = 1e-6 * fp.scale
    shape = Polygon(fp.points)

    def sees_all(p) -> bool:
        return bool(np.all(nrm @ p - c > margin))

    candidates = [
        np.array(shape.centroid.coords[0]),
        np.array(polylabel(shape, 1e-4 * fp.scale).coords[0]),
    ]
    seeing = [p for p in candidates if sees_all(p)]
    if seeing:  # the one farther from the boundary; the centroid on a tie (a rectangle)
        clearance = [shape.exterior.distance(Point(p)) for p in seeing]
        return seeing[int(np.argmax(np.round(clearance, 9)))]
    kernel = _kernel(fp.points, nrm, c, margin)
    if kernel is None:
        return None
    p = np.array(polylabel(Polygon(kernel), 1e-4 * fp.scale).coords[0])
    return p if sees_all(p) else None


def _kernel(pts: np.ndarray, nrm: np.ndarray, c: np.ndarray, margin: float):
    """The polygon's kernel (where every edge is seen from inside), shrunk by ``margin``."""
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    box = ((lo[0], lo[1]), (hi[0], lo[1]), hi, (lo[0], hi[1]))
    poly = [np.array(p, dtype=np.float64) for p in box]
    for k in range(len(pts)):
        poly = _clip_half_plane(poly, nrm[k], c[k] + margin)
        if len(poly) < 3:
            return None
    poly = np.array(poly)
    return poly if signed_area(poly) > margin * margin else None


def _clip_half_plane(poly, normal, level):
    """Sutherland–Hodgman: the part of a convex polygon where normal . x >= level."""
    out = []
    for i, p in enumerate(poly):
        q = poly[(i + 1) % len(poly)]
        sp, sq = normal @ p - level, normal @ q - level
        if sp >= 0:
            out.append(p)
        if (sp >= 0) != (sq >= 0):
            out.append(p + (q - p) * (sp / (sp - sq)))
    return out


def _pyramid_growth(pts: np.ndarray, apex: np.ndarray, run: np.ndarray, overhang: float):
    """How far each corner's hip is carried on past the corner, as a fraction of the corner's
    distance from the apex: until the eave is ``overhang`` beyond the nearer of the corner's two
    walls (``run``: the apex's distance from each edge's line), but no more than MITRE_LIMIT
    overhangs from the corner.  The old single fraction, ``overhang`` over the apex's clearance,
    gave a 6 m x 70 m footprint 5.8 m eaves at its ends for 0.5 m, and a needle kilometres."""
    if overhang == 0:
        return np.zeros(len(pts))
    nearer = np.minimum(run, np.roll(run, 1))  # corner j is between edges j-1 and j
    reach = np.linalg.norm(pts - apex, axis=1)
    return np.minimum(overhang / nearer, MITRE_LIMIT * overhang / reach)


def _pyramid_roof(fp: _Footprint, pitch: float, overhang: float, apex: np.ndarray) -> RoofMesh:
    """One triangle per edge up to the apex; with overhang, each hip carried on past its corner
    (see ``pyramid`` in the module docstring), so that every face keeps its plane."""
    pts = fp.points
    n = len(pts)
    radius = Polygon(pts).exterior.distance(Point(apex))
    tan = math.tan(math.radians(pitch))
    height = tan * radius
    _, nrm, c = edge_lines(pts)
    grow = _pyramid_growth(pts, apex, nrm @ apex - c, overhang)
    eave = np.column_stack([pts + grow[:, None] * (pts - apex), -grow * height])
    builder = _MeshBuilder(np.vstack([eave, [[apex[0], apex[1], height]]]))
    for k in range(n):
        a, b = np.append(pts[k], 0.0), np.append(pts[(k + 1) % n], 0.0)
        normal = _unit(np.cross(b - a, np.append(apex, height) - a))
        run = float(nrm[k] @ apex - c[k])  # horizontal distance from the edge to the apex
        slope = math.degrees(math.atan2(height, run))
        plane = builder.plane(
            k, RoofPlane, "slope", fp.label[k], fp.edges[k], normal, float(normal @ a), slope
        )
        builder.add([[k, (k + 1) % n, n]], plane)
    return builder.finish(eave, overhang, "pyramid")


# --------------------------------------------------------------------------------------------
# shed and flat


def _shed_roof(fp: _Footprint, pitch: float, overhang: float) -> RoofMesh:
    """One plane rising from the front edge over the eave polygon, and walls below it."""
    pts = fp.points
    ring, source = _eave_ring(fp, overhang, np.ones(len(pts)))
    n = len(ring)
    _, nrm, c = edge_lines(pts)
    f = fp.front
    tan = math.tan(math.radians(pitch))
    behind = min(0.0, float((pts @ nrm[f] - c[f]).min()))  # corners behind the front line
    top = tan * (ring @ nrm[f] - c[f] - behind)
    bottom = float(top.min())
    low = top - bottom <= _CLEAN_TOL * fp.scale  # corners on the eave: one vertex, at the eave
    top[low] = bottom
    vertices = np.vstack(
        [np.column_stack([ring, top]), np.column_stack([ring, np.full(n, bottom)])]
    )
    below = np.where(low, np.arange(n), np.arange(n) + n)
    builder = _MeshBuilder(vertices)
    roof = builder.plane("roof", _slope_plane, fp, f, tan, behind, 0.0)
    builder.add_polygon(np.arange(n), ring, roof)
    for i in range(n):
        j = (i + 1) % n
        if low[i] and low[j]:
            continue
        edge = int(source[i])
        wall = builder.plane(("wall", edge), _wall_plane, fp, edge, "wall", ring[i])
        quad = [tri for tri in ([below[i], below[j], j], [below[i], j, i]) if len(set(tri)) == 3]
        builder.add(quad, wall)
    return builder.finish(vertices[below], overhang, "shed")


def _flat_roof(fp: _Footprint, overhang: float, holes=()) -> RoofMesh:
    """The eave polygon at z = 0, without the holes (each shrunk by the overhang)."""
    ring, _ = _eave_ring(fp, overhang, np.ones(len(fp.points)))
    vertices = np.column_stack([ring, np.zeros(len(ring))])
    builder = _MeshBuilder(vertices)
    plane = builder.plane("flat", RoofPlane, "flat", None, (), np.array([0.0, 0.0, 1.0]), 0.0, 0.0)
    open_holes = [
        h.buffer(-overhang, join_style="mitre", mitre_limit=MITRE_LIMIT) if overhang > 0 else h
        for h in (Polygon(np.asarray(hole, dtype=np.float64)) for hole in holes)
        if h.is_valid and h.area > 0
    ]
    if not open_holes:
        builder.add_polygon(np.arange(len(ring)), ring, plane)
        return builder.finish(vertices, overhang, "flat")
    from .polygons import from_shapely
    from .polygons import triangulate as earcut

    shape = Polygon(ring).difference(shapely.union_all(open_holes))
    points, tris = earcut(from_shapely(shape))
    if len(tris):  # counter-clockwise seen from above
        a, b, c = points[tris[:, 0]], points[tris[:, 1]], points[tris[:, 2]]
        flip = _cross(b - a, c - a) < 0
        tris[flip] = tris[flip][:, ::-1]
    builder = _MeshBuilder(np.column_stack([points, np.zeros(len(points))]))
    plane = builder.plane("flat", RoofPlane, "flat", None, (), np.array([0.0, 0.0, 1.0]), 0.0, 0.0)
    builder.add(tris, plane)
    return builder.finish(vertices, overhang, "flat")
