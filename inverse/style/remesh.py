"""Capture geometry (Zhang et al., sections 4.1-4.3.1): a building in the standard view
(:mod:`.frame`) remeshed into floors and the outlines between them, cut into blocks, and each
block's outline broken into four walls of vertical faces.  Textures are another stage's work
(``Face.texture`` stays None here).

* :func:`floors` - section 4.1: vertex heights within 0.0005 of the height are one floor.
* :func:`contours` - section 4.1: the model's outline between each two successive floors.
* :func:`blocks` - section 4.2: cuts at the local maxima of the floor-area ratio.
* :func:`walls` - section 4.3.1: four pieces per outline, broken at the bounding-box corners.
* :func:`capture_geometry` - all of it for one building of a textured model.
"""

from __future__ import annotations

import numpy as np
import shapely
from shapely.geometry.polygon import orient

from bgr.formats.textured_model import TexturedMesh
from bgr.grammar.errors import BgrError, Diagnostic

from .frame import Frame, standard_frame
from .model import Block, Capture, Face

FLOOR_GAP = 0.0005
"""Section 4.1: two vertex heights closer than this (of the building's height) share a floor."""

NEIGHBOURHOOD = 0.001
"""The "minimum neighborhood distance" of section 4.1, in units of the building's height (the
paper names the check, not its distance; ours: 2 cm on a 20 m building).  An outline vertex
closer than this to its neighbour, or to the line through its neighbours, is removed."""

WELD = 1e-7
"""Vertices closer than this (unit-height frame) are one vertex: CityGML polygons are
triangulated one by one, so a corner shared by a wall and a roof appears once per polygon."""

RATIO_EPS = 1e-6
"""Two floor-area ratios closer than this (relative) are equal when local maxima are found
(section 4.2)."""

RATIO_NOISE = 0.01
"""A floor-area ratio below 1 + this is 1: no change of shape.  Deviation from section 4.2,
whose local maxima need no threshold on clean models: a real model's walls lean and its outlines
are simplified (NEIGHBOURHOOD), so successive areas of one straight block differ by parts in
10,000, and among such ratios every local maximum would be a cut.  1 % is above that noise
(the simplification moves an outline's area by about 0.3 %) and far below a setback's change."""

SETBACK = 1.25
"""A floor-area ratio of at least this (a fifth of the area gone) is a cut whether or not it is
a local maximum.  Deviation from section 4.2, whose cuts are the local maxima of the ratio
alone: that rule picks one floor of a gradual taper, but on a model whose floors are its
setbacks only (an untextured mass, one face a wall: bgr restyle's input; an LoD2 model without
storey lines) every floor is a real change, and successive growing ratios (a four-step tower:
1.61, 1.87, 2.5) would make one cut of three.  Floor-to-floor ratios of a taper stay well
below 1.25 (tests/test_style_capture.py: 1.1 and 1.2 beside a 3 are not cuts)."""


MIN_LEVEL = 2.0
"""Metres: the thinnest level (interval between two floors) a capture keeps.  Deviation from
section 4.1, which makes a floor of every vertex height: a real model's pitched roofs, leaning
walls and ledges put vertices at dozens of heights centimetres apart (PLATEAU: 84 floors on a
49 m building, most intervals under 0.2 m), and each interval would become a row of faces with
rules and texture crops of its own.  Nothing thinner than the lowest storey people build
(2.2-2.5 m) is a storey; a thinner interval joins the neighbour whose outline it resembles."""


def thin_levels_merged(floors: np.ndarray, rings: list[np.ndarray], least: float) -> np.ndarray:
    """The floors with every interval under ``least`` (unit height) merged into a neighbour:
    the thinnest first, into the neighbour whose outline area is nearer its own (the merged
    interval takes the taller part's area), until none is thinner or one interval is left."""
    kept = [float(f) for f in floors]
    areas = [_area(r) if len(r) >= 3 else 0.0 for r in rings]

    def like(a: float, b: float) -> float:
        return max(a, b) / min(a, b) if min(a, b) > 0 else float("inf")

    while len(kept) > 2:
        height = np.diff(kept)
        i = int(np.argmin(height))
        if height[i] >= least:
            break
        options = []
        if i > 0:
            options.append((like(areas[i - 1], areas[i]), i))  # drop floor i: join the one below
        if i + 1 < len(height):
            options.append((like(areas[i], areas[i + 1]), i + 1))  # join the one above
        _, floor = min(options)
        below, above = floor - 1, floor
        areas[below] = areas[below] if height[below] >= height[above] else areas[above]
        del areas[above]
        del kept[floor]
    return np.array(kept)


def floor_groups(heights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(group of each height (N,), each group's floor height (m,) ascending): the connected
    components of the paper's adjacency matrix (section 4.1: heights joined when they differ by
    less than 0.0005 of the building's height), which for scalars are the runs of sorted heights
    with gaps below the threshold; each floor is its group's average height, but the lowest and
    highest are the building's own extremes (so that the floors run from 0 to 1 exactly)."""
    y = np.asarray(heights, dtype=np.float64).ravel()
    if len(y) == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0)
    order = np.argsort(y, kind="stable")
    ys = y[order]
    span = float(ys[-1] - ys[0])
    new = np.concatenate([[True], np.diff(ys) >= FLOOR_GAP * span])
    sorted_group = np.cumsum(new) - 1
    count = int(sorted_group[-1]) + 1
    mean = np.bincount(sorted_group, weights=ys, minlength=count) / np.bincount(sorted_group)
    mean[0], mean[-1] = ys[0], ys[-1]
    group = np.empty(len(y), dtype=np.int64)
    group[order] = sorted_group
    return group, mean


def floors(vertices_std: np.ndarray) -> np.ndarray:
    """Section 4.1: the floor heights (m,) of a building in the standard view, ascending, from
    0 to 1: vertex heights that differ by less than 0.0005 of the building's height are one floor
    at their average height (the first and last at the building's lowest and highest point)."""
    v = np.asarray(vertices_std, dtype=np.float64)
    return floor_groups(v[:, 1] if v.ndim == 2 else v)[1]


def _section(vertices: np.ndarray, faces: np.ndarray, height: float) -> np.ndarray:
    """(S, 2, 2) x, z segments where the plane y = height cuts the triangles; no vertex may lie
    on the plane (the caller cuts between floors).  Each crossing point is computed from its edge
    in one canonical direction (lower vertex index first), so the two triangles sharing a welded
    edge give bit-identical points and the segments join exactly."""
    y = vertices[faces, 1]  # (F, 3)
    above = y > height
    crossing = above.any(axis=1) & ~above.all(axis=1)
    tri = faces[crossing]
    up = above[crossing]
    a = tri[:, [0, 1, 2]]
    b = tri[:, [1, 2, 0]]
    cut = up[:, [0, 1, 2]] != up[:, [1, 2, 0]]  # (S, 3): exactly two per triangle
    lo, hi = np.minimum(a, b)[cut], np.maximum(a, b)[cut]
    t = (height - vertices[lo, 1]) / (vertices[hi, 1] - vertices[lo, 1])
    points = vertices[lo] + t[:, None] * (vertices[hi] - vertices[lo])
    return points[:, [0, 2]].reshape(-1, 2, 2)


def _outline(segments: np.ndarray) -> shapely.Polygon | None:
    """The largest polygon the segments enclose (holes filled: the outer ring is what section
    4.3.1 breaks into walls).  A section of a model with gaps (not watertight) leaves open chains
    that enclose nothing; those are closed by a thin buffer that is taken off again."""
    if len(segments) == 0:
        return None
    snapped = np.round(segments / WELD) * WELD  # near-equal ends made equal
    snapped = snapped[np.any(snapped[:, 0] != snapped[:, 1], axis=1)]
    if len(snapped) == 0:
        return None
    lines = shapely.linestrings(snapped)
    ends = np.round(snapped / WELD).reshape(-1, 2)
    # the ends' degrees: unique over complex numbers sorts (x, z) pairs as unique(axis=0) does,
    # at a third of its time (it views rows as structured records)
    _, degree = np.unique(ends[:, 0] + 1j * ends[:, 1], return_counts=True)
    polygons: list = []
    if np.all(degree == 2):  # closed chains meeting end to end: polygonize as they are
        merged = shapely.multilinestrings(lines)
        found, cuts, dangles, invalid = shapely.polygonize_full([merged])
        if cuts.is_empty and dangles.is_empty and invalid.is_empty:
            polygons = [p for p in shapely.get_parts(found) if p.area > 0]
    # chains that touch or cross themselves (or ends that meet three ways: T-junctions, a wall
    # two parts share) are noded first, the slower path
    if not polygons:
        merged = shapely.union_all(lines)
        polygons = [p for p in shapely.get_parts(shapely.polygonize([merged])) if p.area > 0]
    if not polygons:
        grown = shapely.get_parts(merged.buffer(NEIGHBOURHOOD, join_style="mitre"))
        grown = [shapely.Polygon(g.exterior) for g in grown if isinstance(g, shapely.Polygon)]
        polygons = [
            p
            for g in grown
            for p in shapely.get_parts(g.buffer(-NEIGHBOURHOOD, join_style="mitre"))
            if p.area > 0
        ]
        if not polygons:
            return None
    return shapely.Polygon(_largest(np.array(polygons, dtype=object)).exterior)


def _largest(polygons: np.ndarray) -> shapely.Polygon:
    """The largest part of the union of ``polygons`` (an object array), unioning only the
    polygons of that part: a model of many buildings has many far-apart polygons in one
    section.  The parts are the connected components of "intersects" (an STRtree query); the sum
    of a component's areas bounds its union's (polygons that overlap count twice), so components
    are unioned largest bound first until no bound left can beat the best union."""
    if len(polygons) <= 16:  # a few: one union costs less than finding the parts
        union = shapely.union_all(polygons) if len(polygons) > 1 else polygons[0]
        return max(shapely.get_parts(union), key=lambda p: p.area)
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    pairs = shapely.STRtree(polygons).query(polygons, predicate="intersects")
    n = len(polygons)
    graph = coo_matrix((np.ones(pairs.shape[1]), (pairs[0], pairs[1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    bound = np.bincount(label, weights=shapely.area(polygons))  # >= the part's area
    best: shapely.Polygon | None = None
    for component in np.argsort(-bound, kind="stable"):
        if best is not None and bound[component] <= best.area:
            break
        members = polygons[label == component]
        union = shapely.union_all(members) if len(members) > 1 else members[0]
        part = max(shapely.get_parts(union), key=lambda p: p.area)
        if best is None or part.area > best.area:
            best = part
    assert best is not None
    return best


def _clean(polygon: shapely.Polygon) -> np.ndarray:
    """(k, 2) the outer ring counter-clockwise in (x, z), without the repeated closing vertex,
    collinear vertices and vertices closer than NEIGHBOURHOOD to a neighbour removed."""
    simple = polygon.simplify(NEIGHBOURHOOD, preserve_topology=True)
    if simple.is_empty or simple.area <= 0:
        simple = polygon
    ring = np.asarray(orient(simple, sign=1.0).exterior.coords)[:-1]  # shapely 2.0 has orient
    keep = np.ones(len(ring), dtype=bool)
    for _ in range(len(ring)):  # short edges: drop the later end, until none is left (rare)
        pts = ring[keep]
        if len(pts) <= 3:
            break
        short = np.hypot(*(np.roll(pts, -1, axis=0) - pts).T) < NEIGHBOURHOOD
        if not short.any():
            break
        index = np.flatnonzero(keep)[(np.argmax(short) + 1) % len(pts)]
        keep[index] = False
    return ring[keep]


def contours(
    mesh_std_vertices: np.ndarray, faces: np.ndarray, floors: np.ndarray
) -> list[np.ndarray]:
    """Section 4.1: the outline (k, 2) of the model between each two successive floors, an outer
    ring counter-clockwise in (x, z) (shapely's orientation sign 1); (0, 2) where the section is
    empty.

    The paper intersects the model with the plane of each floor.  We cut at the middle of each
    interval instead, with every vertex snapped to its floor first (the paper's "vertical
    alignment"): then no vertex lies on the cutting plane, the cut crosses only the faces that
    span the interval (a floor's own plane also holds the horizontal roofs and ledges that end
    there, whose outline belongs to the interval below or above, ambiguously), and for the
    vertical walls of a Manhattan-world building the section is the same at every height of the
    interval, so the middle is no loss.  Where a section gives several polygons (two towers on
    one podium), the largest is kept: section 4.3.1 breaks one outline per floor into walls.
    Heights within 0.0005 of a floor are moved onto it here (vertices need not be snapped)."""
    v = np.array(mesh_std_vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    levels = np.asarray(floors, dtype=np.float64)
    v[:, 1] = _snap(v[:, 1], levels)
    out = []
    for lo, hi in zip(levels[:-1], levels[1:], strict=True):
        polygon = _outline(_section(v, f, (lo + hi) / 2.0))
        out.append(np.zeros((0, 2)) if polygon is None else _clean(polygon))
    return out


def _snap(heights: np.ndarray, levels: np.ndarray) -> np.ndarray:
    """Each height moved onto the nearest floor when it is within FLOOR_GAP of the span (the
    vertical alignment of section 4.1); others are kept."""
    if len(levels) == 0:
        return heights
    at = np.clip(np.searchsorted(levels, heights), 1, max(len(levels) - 1, 1))
    below, above = levels[at - 1], levels[np.minimum(at, len(levels) - 1)]
    nearest = np.where(np.abs(heights - below) <= np.abs(above - heights), below, above)
    span = float(levels[-1] - levels[0])
    return np.where(np.abs(heights - nearest) < FLOOR_GAP * max(span, 1e-300), nearest, heights)


def _area(ring: np.ndarray) -> float:
    """The shoelace area of a ring (k, 2)."""
    if len(ring) < 3:
        return 0.0
    x, z = ring[:, 0], ring[:, 1]
    return float(abs(np.dot(x, np.roll(z, -1)) - np.dot(z, np.roll(x, -1))) / 2.0)


def cut_floors(areas: np.ndarray) -> np.ndarray:
    """Section 4.2: the floors (indices 1..n-1 into the floors of n intervals) that cut the
    building, from the intervals' outline areas.

    r_i = max(a_i, a_{i-1}) / min(a_i, a_{i-1}) at floor i; a cut is a local maximum,
    r_i > r_{i-1} and r_i > r_{i+1}.  Decisions the paper leaves open, ours:

    * the ends: r_0 and r_n (the ground and the roof, no interval beyond) are 1, the smallest a
      ratio can be, so the first and last inner floors are cuts when they rise above their one
      neighbour;
    * a plateau (r equal over several successive floors, within RATIO_EPS) that rises above both
      its neighbours cuts at each of its floors.  Deviation: read strictly, the paper's rule finds
      no cut in a ziggurat of equal steps (every r the same), which is several blocks plainly;
    * an empty interval (area 0) gives r = inf at its floors;
    * a ratio below 1 + RATIO_NOISE is 1 (deviation: see RATIO_NOISE);
    * a ratio of SETBACK (1.25) or more is a cut, a local maximum or not (deviation: see
      SETBACK).
    """
    a = np.asarray(areas, dtype=np.float64)
    if len(a) < 2:
        return np.zeros(0, dtype=np.int64)
    big, small = np.maximum(a[1:], a[:-1]), np.minimum(a[1:], a[:-1])
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(small > 0, big / np.where(small > 0, small, 1.0), np.inf)
    r = np.where(big > 0, r, 1.0)  # two empty intervals: no change
    r = np.where(r < 1.0 + RATIO_NOISE, 1.0, r)
    padded = np.concatenate([[1.0], r, [1.0]])
    # runs of equal ratios (plateaus), then each run compared with the runs beside it
    finite = np.where(np.isfinite(padded), padded, np.finfo(float).max)
    step = np.abs(np.diff(finite)) > RATIO_EPS * np.maximum(finite[1:], finite[:-1])
    run = np.concatenate([[0], np.cumsum(step)])
    value = finite[np.concatenate([[0], np.flatnonzero(step) + 1])]
    higher = np.zeros(len(value), dtype=bool)
    higher[1:-1] = (value[1:-1] > value[:-2]) & (value[1:-1] > value[2:])
    return np.flatnonzero(higher[run[1:-1]] | (r >= SETBACK)) + 1


def blocks(floors: np.ndarray, contours: list[np.ndarray]) -> list[Block]:
    """Section 4.2: the building cut into blocks at the local maxima of the floor-area ratio
    (:func:`cut_floors`).  A block is a run of intervals from one cut (the ground is the first)
    to the next, extruded from the bounding box of its first interval's outline ("blocks are
    generated by vertically extruding the bounding boxes of the cuts"); its walls are empty
    until :func:`walls` fills them."""
    levels = np.asarray(floors, dtype=np.float64)
    n = len(levels) - 1
    cuts = cut_floors(np.array([_area(c) for c in contours[:n]]))
    starts = np.concatenate([[0], cuts]).astype(int)
    ends = np.concatenate([cuts, [n]]).astype(int)
    out = []
    for start, end in zip(starts, ends, strict=True):
        ring = contours[start]
        if len(ring) == 0:  # an empty cut interval: the first outline of the block that has one
            ring = next((contours[i] for i in range(start, end) if len(contours[i])), ring)
        if len(ring):
            lo, hi = ring.min(axis=0), ring.max(axis=0)
            box = (float(lo[0]), float(hi[0]), float(lo[1]), float(hi[1]))
        else:
            box = (0.0, 0.0, 0.0, 0.0)
        levels_in = list(range(int(start), int(end)))
        out.append(Block(float(levels[start]), float(levels[end]), box, levels_in))
    return out


def _break_points(ring: np.ndarray) -> tuple[int, np.ndarray]:
    """(the ring's vertex nearest the (xmin, zmin) corner of its bounding box, (4,) offsets from
    it counter-clockwise of the vertices nearest the four corners): the starts of the front,
    right, back and left pieces (section 4.3.1).  A vertex nearest two corners ends an empty
    piece; one that would run backwards (a ring folding past a corner) is held at the previous,
    so the four pieces always cover the ring once, in order."""
    lo, hi = ring.min(axis=0), ring.max(axis=0)
    corners = np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]])
    d = np.linalg.norm(ring[None, :, :] - corners[:, None, :], axis=2)  # (4, k)
    nearest = np.argmin(d, axis=1)
    k = len(ring)
    offset = np.maximum.accumulate((nearest - nearest[0]) % k)
    return int(nearest[0]), offset


def walls(block: Block, contours: list[np.ndarray], floors: np.ndarray) -> None:
    """Section 4.3.1: fill ``block.walls`` with the vertical faces of each of its intervals.

    Each interval's outline is broken into four pieces at its vertices nearest the four corners
    of the interval's own bounding box (:func:`_break_points`); the piece from the (xmin, zmin)
    corner to the (xmax, zmin) one, counter-clockwise, is the front (min z, outward -z), then
    right (max x), back (max z), left (min x).  Each edge of a piece is one Face spanning the
    interval (section 4.1: "each edge on a floor generates one vertical face").  Seen from
    outside a wall runs clockwise in (x, z), so each face's start is its edge's later vertex and
    the faces of a level are in the reverse of the ring's order."""
    levels = np.asarray(floors, dtype=np.float64)
    block.walls = [[], [], [], []]
    for level in block.levels:
        ring = contours[level]
        if len(ring) < 3:
            continue
        start, offset = _break_points(ring)
        k = len(ring)
        bounds = np.concatenate([offset, [k]])  # edge j runs from ring[j] to ring[j + 1]
        bottom, top = float(levels[level]), float(levels[level + 1])
        for w in range(4):
            edges = (start + np.arange(bounds[w], bounds[w + 1])) % k
            for j in edges[::-1]:
                a, b = ring[j], ring[(j + 1) % k]
                block.walls[w].append(Face(w, level, b.copy(), a.copy(), bottom, top))


def selection(mesh: TexturedMesh, building: str | None) -> np.ndarray:
    """(F,) bool: the building's triangles (all of them for None).  A CityGML reader already
    gives each building its highest level of detail, with every semantic surface (walls, roofs,
    ground) of it: all of them are the building's shape."""
    if building is None:
        keep = np.ones(len(mesh.faces), dtype=bool)
    elif building not in mesh.object_ids:
        some = ", ".join(mesh.object_ids[:5]) + (", ..." if len(mesh.object_ids) > 5 else "")
        raise BgrError(
            Diagnostic(
                mesh.source,
                0,
                0,
                f"no building {building[:200]!r} in the model",
                f"its buildings are: {some}" if some else "the model names no buildings",
            )
        )
    else:
        keep = mesh.mask(object_id=building)
    if not keep.any():
        raise BgrError(
            Diagnostic(mesh.source, 0, 0, "the model has no triangles to capture", "give a mesh")
        )
    return keep


def capture_geometry(mesh: TexturedMesh, building: str | None) -> tuple[Capture, Frame]:
    """Sections 4.1-4.3.1 for one building of a textured model (``building``: an id of
    ``mesh.object_ids``; None: the whole mesh): its standard view, floors, outlines, blocks and
    walls.  Faces carry no texture yet.  Raises :class:`BgrError` located at ``mesh.source`` for
    an unknown building, an empty selection, no vertical faces or zero height."""
    keep = selection(mesh, building)
    frame = standard_frame(mesh, keep)
    tris = mesh.faces[keep]
    used, local = np.unique(tris, return_inverse=True)
    std = frame.apply(mesh.vertices[used])
    # weld by position (section 4.1's "redundant vertices")
    _, first, weld = np.unique(
        np.round(std / WELD).astype(np.int64), axis=0, return_index=True, return_inverse=True
    )
    std = std[first]
    faces = weld.ravel()[local.reshape(-1, 3)]
    faces = faces[(faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2])]
    faces = faces[faces[:, 0] != faces[:, 2]]
    group, levels = floor_groups(std[:, 1])
    std[:, 1] = levels[group]  # the paper's vertical alignment: each vertex onto its floor
    rings = contours(std, faces, levels)
    storeys = thin_levels_merged(levels, rings, MIN_LEVEL / frame.scale)
    if len(storeys) < len(levels):
        levels = storeys
        rings = contours(std, faces, levels)
    warnings = []
    for i in range(len(rings)):
        if len(rings[i]) == 0:
            near = [j for j in sorted(range(len(rings)), key=lambda j: abs(j - i)) if len(rings[j])]
            warnings.append(
                f"nothing of the building between heights {levels[i] * frame.scale:.2f} and "
                f"{levels[i + 1] * frame.scale:.2f} m: the outline of the nearest floor is used"
            )
            if near:
                rings[i] = rings[near[0]].copy()
    parts = blocks(levels, rings)
    for block in parts:
        walls(block, rings, levels)
    if building is None:
        ids = mesh.object_ids
        building = ids[0] if len(ids) == 1 else ""
    capture = Capture(building, frame.scale, levels, rings, parts, mesh.source, warnings)
    return capture, frame
