"""Buildings that are a footprint extruded and roofed, written as the operations that make them.

A house of walls standing on a footprint under a hip, gable, pyramid or shed roof (the kinds of
``roof(kind, pitch, overhang)``, docs/language.md) is, in the grammar,

    polygon(x1, z1, ...) extrude(h) comp(f) { top: roof(gable, 35, 0.4) Roof | side: Wall }

a line of text instead of a mesh, whose height, pitch and eaves a user can change.  The fit
works on the whole building (its walls and roof together: with eaves, a roof's slab and its
walls' overlap, and no cut between them makes either a shape of its own):

1. the footprint is where the walls stand (the walls' ground lines, as :mod:`.prisms` finds
   them); the walls' height ``h`` is the lowest of the heights the walls reach along each edge of
   it (a gable wall rises above, an eave-side wall ends there);
2. the roof's pitch follows from its height above ``h``: a roof of this kind over this footprint
   at 45 degrees is ``top`` high, and every roof kind here grows with ``tan(pitch)``; the overhang
   is how far the roof reaches beyond the footprint's edges (the farthest edge midpoint);
3. each kind (and, for a shed or a square's gable, each edge as the front) is built by the
   interpreter's own roof geometry and kept when the house it makes and the building are within
   three quarters of the tolerance of each other both ways (trimesh's point-to-surface distance
   on vertices and points spread over both surfaces, as :mod:`.prisms` checks).

The walls, the roof and the floor each have one colour or none.  A building that fails any of it
keeps its components.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import shapely
import trimesh

from bgr.interpreter.geometry.meshes import clip_below
from bgr.interpreter.geometry.roofs import roof_mesh

from .batch import _whole, fit_all
from .components import Component, digits_for
from .model import CityObject
from .prisms import (
    LEVEL,
    MIN_HEIGHT,
    UPRIGHT,
    PrismFit,
    _close_meshes,
    _colors,
    facing,
    fit_prism,
    footprint,
    prism_mesh,
)
from .types import Types
from .uncut import whole_instead

KINDS = ("gable", "hip", "pyramid", "shed")
PITCH_DIGITS = 3  # degrees: a thousandth moves a 10 m roof's ridge by under a millimetre


@dataclass(frozen=True)
class HouseFit:
    """A building as walls on a footprint under a roof, in its box frame."""

    ring: tuple[tuple[float, float], ...]  # (x, z) corners, the first edge the roof's front
    height: float  # of the walls
    bottom: bool  # the floor is part of the building
    kind: str  # gable | hip | pyramid | shed
    pitch: float  # degrees
    overhang: float  # metres
    colors: dict[str, str]  # "side", "bottom", "roof" -> "#rrggbb", where the input has colours


def roofed(
    objects: list[CityObject], comps: list[Component], types: Types, tolerance: float, grid: float
) -> tuple[list[Component], Types]:
    """Level 0's components with every building that is a house (see the module docstring) one
    component carrying its :class:`HouseFit` (``Component.house``), where its lowest component
    was; ``comps`` and ``types`` as they are when none is.  Equal buildings (one key) are
    fitted once."""
    members: dict[int, list[int]] = {}
    for i, comp in enumerate(comps):
        members.setdefault(comp.building, []).append(i)
    roofs = {b for b, own in members.items() if any(_has_slopes(comps[i]) for i in own)}
    several = [b for b in sorted(roofs) if len(members[b]) > 1]
    slabs = _whole([objects[b] for b in several])
    whole = {
        c.building: c
        for c in fit_all(
            [(b, s) for b, s in zip(several, slabs, strict=True) if s is not None], objects, grid
        )
    }
    fits: dict[str, tuple] = {}
    instead: dict[int, Component] = {}
    for b in sorted(roofs):
        comp = whole.get(b) if b in whole else comps[members[b][0]]
        if comp is None or fit_prism(comp, tolerance) is not None:
            continue
        if comp.key not in fits:
            house = fit_house(comp, tolerance)
            # equal buildings (one key) take the same fit and the same turn of their frame
            turn = None if house is None else np.linalg.solve(comp.frame, house.frame)
            fits[comp.key] = (house, turn)
        house, turn = fits[comp.key]
        if house is not None:
            instead[b] = replace(house, building=b, frame=comp.frame @ turn)
    if not instead:
        return comps, types
    return whole_instead(comps, members, instead)


def _has_slopes(comp: Component) -> bool:
    """Whether some face of the component is neither upright nor level (a roof's slope)."""
    _, _, up = facing(comp.vertices[comp.faces])
    up = np.abs(up)
    return bool(np.any((up >= UPRIGHT) & (up <= LEVEL)))


def fit_house(comp: Component, tolerance: float) -> Component | None:
    """The component carrying the house it is within ``tolerance`` (metres) of, or None (see
    the module docstring).  A rectangle's house may come back in its box turned by quarter
    turns: ``polygon()`` of a rectangle starts it at its lowest corner, so its first edge, the
    front a shed rises from and a square's gable runs along, is the frame's x axis."""
    try:
        return _fit(comp, tolerance)
    except (shapely.errors.GEOSException, ValueError, IndexError, ZeroDivisionError):
        return None


def house_mesh(fit: HouseFit) -> trimesh.Trimesh:
    """The triangles the fit's operations make, in the component's frame (y up)."""
    walls = prism_mesh(PrismFit(fit.ring, fit.height, fit.bottom, False, {}))
    made = roof_mesh(np.array(fit.ring), fit.kind, fit.pitch, fit.overhang)
    # gable and shed walls end at the walls' top, as the roof operation cuts them
    upright = np.array([made.planes[i].kind in ("gable", "wall") for i in made.face_plane])
    points, faces = (made.vertices, made.faces)
    if upright.any():
        points, faces = clip_below(points, faces, upright)
    # (x, z, up) -> (x, up, z) turns the triangles inside out: their corners go the other way
    lifted = np.asarray(points)[:, [0, 2, 1]] + [0.0, fit.height, 0.0]
    roof = trimesh.Trimesh(lifted, np.asarray(faces)[:, ::-1], process=False)
    return trimesh.util.concatenate([walls, roof])


def _fit(comp: Component, tolerance: float) -> Component | None:
    v, f = comp.vertices, comp.faces
    if len(f) == 0 or comp.size[1] < MIN_HEIGHT:
        return None
    tri = v[f]
    _, real, up = facing(tri)
    half = tolerance / 2
    wall = real & (np.abs(up) < UPRIGHT)
    floor = real & (up < -LEVEL) & (np.abs(tri[:, :, 1]).max(axis=1) <= half)
    sloped = real & (up >= UPRIGHT)
    if not wall.any() or not sloped.any() or np.any(real & ~(wall | floor | sloped)):
        return None  # no roof, or a face looking down that is not the floor (a soffit)
    digits = digits_for(tolerance)
    ring = footprint(tri[wall], tolerance)
    if ring is None:
        return None
    height = _wall_height(tri[wall], np.array(ring), half)
    top = float(comp.size[1]) - height
    if height < MIN_HEIGHT or top < MIN_HEIGHT:
        return None
    height = round(height, digits)
    roof = sloped | (wall & (tri[:, :, 1].min(axis=1) >= height - half))  # gable walls too
    colors = _colors(comp.colors, {"side": wall & ~roof, "bottom": floor, "roof": roof})
    if colors is None:
        return None
    overhang = round(_overhang(tri[sloped], ring), digits)
    for kind in KINDS:
        for variant, turned in _fronts(comp, kind, ring, digits):
            pitch = _pitch(turned, kind, top)
            if pitch is None:
                continue
            fit = HouseFit(turned, height, bool(floor.any()), kind, pitch, overhang, colors)
            try:
                made = house_mesh(fit)
            except ValueError:  # a pitch or an overhang the roof refuses
                continue
            given = trimesh.Trimesh(variant.vertices, variant.faces, process=False)
            # far off: not worth the distances (the areas differ a little where a gable wall
            # overlaps the walls' top under eaves: its surface is theirs)
            if abs(made.area - given.area) > 0.05 * given.area:
                continue
            if _close_meshes(given, made, tolerance):
                return replace(variant, house=fit)
    return None


def _fronts(comp: Component, kind: str, ring: tuple, digits: int):
    """(the component, its footprint with the front first) for each front to try: every edge
    for a shed (it rises from its front), two for a gable (a square's ridge runs along its
    front), one for the others.  A rectangle's front is its first edge as ``polygon()`` writes
    it (from its lowest corner along x): the other fronts are the component turned."""
    count = len(ring) if kind == "shed" else 2 if kind == "gable" else 1
    if not _is_box(ring, comp.size, 10.0**-digits):
        for front in range(count):
            yield comp, ring[front:] + ring[:front]
        return
    for quarter in range(min(count, 4)):
        turned = _quarter_turned(comp, quarter)
        w, d = (round(float(x), digits) for x in turned.size[[0, 2]])
        yield turned, ((0.0, 0.0), (w, 0.0), (w, d), (0.0, d))


def _is_box(ring: tuple, size: np.ndarray, step: float) -> bool:
    """Whether the footprint is the box's own rectangle."""
    corners = {(0.0, 0.0), (float(size[0]), 0.0), (float(size[0]), float(size[2])),
               (0.0, float(size[2]))}  # fmt: skip
    return len(ring) == 4 and all(
        any(abs(x - a) <= step and abs(z - b) <= step for a, b in corners) for x, z in ring
    )


def _quarter_turned(comp: Component, quarter: int) -> Component:
    """The component in its box turned ``quarter`` times by 90 degrees about the vertical: the
    same triangles in the world, their frame's x now along what was its z, and so on."""
    out = comp
    for _ in range(quarter):
        width = float(out.size[0])
        frame = out.frame.copy()
        x_axis, z_axis = out.frame[:3, 0].copy(), out.frame[:3, 2].copy()
        frame[:3, 0], frame[:3, 2] = z_axis, -x_axis
        frame[:3, 3] = out.frame[:3, 3] + width * x_axis
        v = out.vertices
        vertices = np.column_stack([v[:, 2], v[:, 1], width - v[:, 0]])
        size = np.array([out.size[2], out.size[1], out.size[0]])
        out = replace(out, frame=frame, vertices=vertices, size=size)
    return out


def _wall_height(walls: np.ndarray, ring: np.ndarray, half: float) -> float:
    """The lowest, over the footprint's edges, of the highest wall corner on that edge."""
    corners = walls.reshape(-1, 3)
    ground = corners[:, [0, 2]]
    lowest = math.inf
    for a, b in zip(ring, np.roll(ring, -1, axis=0), strict=True):
        edge = b - a
        length = float(np.hypot(*edge))
        if length <= 2 * half:
            continue
        along = (ground - a) @ edge / length
        off = np.abs((ground - a) @ np.array([-edge[1], edge[0]]) / length)
        on = (off <= half) & (along >= -half) & (along <= length + half)
        if on.any():
            lowest = min(lowest, float(corners[on, 1].max()))
    return lowest if math.isfinite(lowest) else 0.0


def _overhang(roof: np.ndarray, ring: tuple) -> float:
    """How far the roof reaches beyond the footprint: the farthest of the footprint's edge
    midpoints from the roof's outline seen from above (0 where the roof ends at the walls)."""
    cover = shapely.union_all(shapely.polygons(roof[:, :, [0, 2]]))
    footprint = shapely.Polygon(ring)
    if cover.area <= footprint.area * (1 + 1e-9):
        return 0.0
    points = np.array(ring)
    mids = shapely.points((points + np.roll(points, -1, axis=0)) / 2)
    return float(shapely.distance(mids, cover.boundary).max())


def _pitch(ring: tuple, kind: str, top: float) -> float | None:
    """The pitch at which the roof of ``kind`` over ``ring`` is ``top`` metres high (every kind
    here grows with tan(pitch)), rounded; None when it cannot be built or stays flat."""
    try:
        at45 = float(roof_mesh(np.array(ring), kind, 45.0).vertices[:, 2].max())
    except ValueError:
        return None
    if at45 <= 1e-9:
        return None
    pitch = round(math.degrees(math.atan(top / at45)), PITCH_DIGITS)
    return pitch if 0.0 < pitch < 90.0 else None
