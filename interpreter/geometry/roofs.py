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

Modules
-------
This module holds :func:`roof_mesh` and the straight-skeleton kinds (hip, gable, mansard,
gambrel); :mod:`.roof_pyramid` and :mod:`.roof_shed_flat` build the others.  All of them start
from the cleaned footprint and its eave polygon (:mod:`.roof_footprint`) and assemble their
mesh with the builder of :mod:`.roof_model`, which also holds :class:`RoofPlane` and
:class:`RoofMesh`.
"""

from __future__ import annotations

import math

import numpy as np

from .roof_footprint import MITRE_LIMIT as MITRE_LIMIT
from .roof_footprint import _eave_ring, _Footprint, _sharp_corners, _slope_plane, _wall_plane
from .roof_model import RoofMesh as RoofMesh
from .roof_model import RoofPlane as RoofPlane
from .roof_model import _cross, _MeshBuilder
from .roof_pyramid import _pyramid_apex, _pyramid_roof
from .roof_shed_flat import _flat_roof, _shed_roof
from .skeleton import Skeleton, SkeletonError, edge_lines, straight_skeleton

KINDS = ("flat", "gable", "hip", "pyramid", "shed", "mansard", "gambrel")
MANSARD_BREAK = 1.0 / 3.0  # the steep lower band covers this fraction of the largest inset


def mansard_lower_pitch(pitch: float) -> float:
    """Pitch (degrees) of the steep lower band of a mansard or gambrel roof of ``pitch``."""
    return 45.0 + pitch / 2.0


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
