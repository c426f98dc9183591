"""CGA's occlusion queries: ``inside()``, ``overlaps()`` and ``touches()``.

A query asks whether the current shape's geometry lies inside, overlaps or touches the closed
geometry of another shape of the lot.  Its answer steers the derivation that makes those shapes,
so a lot that asks one is derived twice, as CityEngine does:

1. every query answers false, and the occluders are noted (:class:`Recorder`): the lot's
   closed leaves, the closed shapes ``comp()`` or ``offset()`` took apart (where a mass turns
   into surfaces), and a copy of each shape ``label(name)`` named, under that name;
2. the lot is derived again, and each query is tested against those occluders
   (:class:`Occluders`), leaving out the shape's own ancestors and descendants (whose geometry
   holds it or lies in it by construction).

Only closed geometry occludes (every edge between exactly two faces).  A query with a label
tests the shapes that ``label()`` gave that name; one without, every occluder.  The tests sample
the query's geometry (its corners, edge midpoints and triangle centres) against each occluder:

* inside: every sample in or on the occluder;
* overlaps: a sample strictly inside the occluder, or (the query's geometry closed) one of the
  occluder's strictly inside it;
* touches: overlaps, or a triangle centre of either lies on the other's surface.

``intra`` tests the lot's own shapes, ``inter`` those of the lots around it, ``all`` (the
default) both.  The lots around a lot are those whose bounding boxes come within
:data:`NEIGHBOURHOOD` (1 m, CityEngine's default) of its own; their occluders are the closed
shapes of *their* first passes, so a run of several lots whose grammar asks a query first
derives every lot once with every query false, then each again against its own first pass
and its neighbours' (:func:`bgr.interpreter.batch.derive_lots`): what a lot makes never
depends on which process derived it, or on the order of the lots.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .geometry.queries import scope_mesh

_RAY = np.array([0.8732, 0.3912, 0.2907])  # a direction no axis-aligned face lies along
_RAY /= np.linalg.norm(_RAY)


@dataclass
class Occluder:
    path: str  # the shape's place in the derivation tree (Shape.path)
    label: str | None  # the name label() gave it; None for a leaf or a comp'd shape
    triangles: np.ndarray  # (T, 3, 3) world coordinates
    low: np.ndarray
    high: np.ndarray
    # a shape noted inside its rule (comp, offset, label): the successors of that rule it
    # stands for, by their index (what the shape became); None for a leaf
    span: tuple[int, int] | None = None


def _world(shape, library) -> np.ndarray:
    """The shape's triangles in world coordinates, (T, 3, 3)."""
    verts, faces = scope_mesh(shape, library)
    if not len(faces):
        return np.zeros((0, 3, 3))
    world = np.asarray(shape.origin, float) + verts @ np.asarray(shape.axes, float)
    return world[np.asarray(faces)]


def _closed(triangles: np.ndarray) -> bool:
    """Every edge between exactly two triangles (corners merged to a micrometre)."""
    if not len(triangles):
        return False
    keys = np.round(triangles.reshape(-1, 3) * 1e6).astype(np.int64)
    _, ids = np.unique(keys, axis=0, return_inverse=True)
    ids = ids.reshape(-1, 3)
    edges = np.sort(np.concatenate([ids[:, [0, 1]], ids[:, [1, 2]], ids[:, [2, 0]]]), axis=1)
    edges = edges[edges[:, 0] != edges[:, 1]]
    if not len(edges):
        return False
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return bool((counts == 2).all())


def _occluder(path: str, label, triangles: np.ndarray, span=None) -> Occluder | None:
    if not _closed(triangles):
        return None
    points = triangles.reshape(-1, 3)
    return Occluder(path, label, triangles, points.min(axis=0), points.max(axis=0), span)


class Recorder:
    """The first pass: every query answers false, and the occluders are noted."""

    testing = False

    def __init__(self) -> None:
        self.items: list[Occluder] = []

    def note(self, shape, library, label: str | None, span: tuple[int, int]) -> None:
        found = _occluder(shape.path, label, _world(shape, library), span)
        if found is not None:
            self.items.append(found)

    def finish(self, table) -> Occluders:
        """The occluders: those noted, and the closed leaves of the first pass's table."""
        items = list(self.items)
        library, closed = table.library, {}
        for i, mesh in enumerate(table.mesh):
            unit = library.meshes[mesh]
            if mesh not in closed:
                closed[mesh] = _closed(unit.vertices[unit.faces]) if len(unit.faces) else False
            if not closed[mesh]:
                continue
            verts = unit.vertices * np.asarray(table.size[i], float)
            world = np.asarray(table.origin[i], float) + verts @ np.asarray(table.axes[i], float)
            found = _occluder(table.path[i], None, world[unit.faces])
            if found is not None:
                items.append(found)
        return Occluders(items)


class Occluders:
    """The second pass: each query tested against the first pass's occluders, the lot's own
    (``items``, for ``intra``) and those of the lots around it (``neighbours``, ``inter``)."""

    testing = True

    def __init__(self, items: list[Occluder], neighbours: list[Occluder] | None = None) -> None:
        self.items = items
        self.neighbours = neighbours or []

    def of(self, target: str) -> list[Occluder]:
        """The occluders a query with this target tests."""
        if target == "intra":
            return self.items
        if target == "inter":
            return self.neighbours
        return self.items + self.neighbours


def note(app, shape, label: str | None = None, first: int | None = None) -> None:
    """Note ``shape`` as an occluder when this is a lot's first pass: a shape comp() or
    offset() took apart (``first``: the index its first part's successor got), or a shape
    label() named (it goes on as the rule's next successor)."""
    occlusion = app.engine.occlusion
    if occlusion is not None and not occlusion.testing:
        span = (
            app.counter if first is None else first,
            app.counter if first is None else app.counter - 1,
        )
        occlusion.note(shape, app.engine.table.library, label, span)


def uses_occlusion(grammar, seen: set | None = None) -> bool:
    """Whether the grammar or a module it imports asks an occlusion query (the checker marks
    them)."""
    seen = set() if seen is None else seen
    if id(grammar) in seen:
        return False
    seen.add(id(grammar))
    return getattr(grammar, "occlusion", False) or any(
        uses_occlusion(sub, seen) for sub in grammar.imports.values()
    )


def _related(other: Occluder, path: str) -> bool:
    """Whether the shape at ``path`` is the occluder, an ancestor of it or a descendant, by
    their paths (``Lot/Mass.0/Facade.3``: each successor's rule and index in its parent's)."""
    own = other.path
    if path == own or own.startswith(path + "/"):
        return True
    if not path.startswith(own + "/"):
        return False
    if other.span is None:  # a leaf: all below it is its own
        return True
    # noted inside its rule: only the successors that shape went on as are its descendants
    head = path[len(own) + 1 :].split("/", 1)[0]
    index = int(head.rsplit(".", 1)[1])
    return other.span[0] <= index <= other.span[1]


def _samples(triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(corners, edge midpoints and centres; the centres) of some triangles."""
    corners = np.unique(np.round(triangles.reshape(-1, 3), 9), axis=0)
    mids = (triangles + np.roll(triangles, -1, axis=1)) / 2
    centres = triangles.mean(axis=1)
    return np.concatenate([corners, mids.reshape(-1, 3), centres]), centres


def _where(points: np.ndarray, triangles: np.ndarray, eps: float) -> np.ndarray:
    """For each point: 1 strictly inside the closed triangles, 0 on them, -1 outside."""
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    e1, e2 = b - a, c - a
    normal = np.cross(e1, e2)
    area2 = np.linalg.norm(normal, axis=1)
    keep = area2 > 1e-18
    a, e1, e2, normal, area2 = a[keep], e1[keep], e2[keep], normal[keep], area2[keep]
    unit = normal / area2[:, None]
    rel = points[:, None, :] - a[None, :, :]  # (P, T, 3)
    height = np.einsum("ptk,tk->pt", rel, unit)
    foot = rel - height[..., None] * unit[None]
    # barycentric coordinates of the foot, with a tolerance of eps along the edges
    u = np.einsum("ptk,tk->pt", np.cross(foot, e2[None]), unit) / area2
    v = np.einsum("ptk,tk->pt", np.cross(e1[None], foot), unit) / area2
    slack = eps / np.sqrt(area2)
    on = (np.abs(height) <= eps) & (u >= -slack) & (v >= -slack) & (u + v <= 1 + slack)
    # parity of the crossings of a ray from each point (Moller-Trumbore)
    pvec = np.cross(_RAY, e2)
    det = np.einsum("tk,tk->t", e1, pvec)
    ok = np.abs(det) > 1e-18
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    su = np.einsum("ptk,tk->pt", rel, pvec) * inv
    qvec = np.cross(rel, e1[None])
    sv = np.einsum("ptk,k->pt", qvec, _RAY) * inv
    t = np.einsum("ptk,tk->pt", qvec, e2) * inv
    hits = ok & (su >= 0) & (sv >= 0) & (su + sv <= 1) & (t > eps)
    inside = hits.sum(axis=1) % 2 == 1
    return np.where(on.any(axis=1), 0, np.where(inside, 1, -1))


def query(ctx, name: str, target: str, label) -> bool:
    """inside, overlaps or touches (``name``) of the context's shape (see the docstring)."""
    occlusion = ctx.occlusion
    if occlusion is None or not occlusion.testing:
        return False
    shape = ctx.shape
    mine = _world(shape, ctx.library)
    if not len(mine):
        return False
    wanted = None if label is None or str(label) == "" else str(label)
    points, centres = _samples(mine)
    low, high = points.min(axis=0), points.max(axis=0)
    scale = max(float(np.ptp(points, axis=0).max()), 1.0)
    eps = 1e-6 * scale
    closed = None
    for other in occlusion.of(target):
        if wanted is not None and other.label != wanted:
            continue
        if _related(other, shape.path):
            continue
        if (low > other.high + eps).any() or (high < other.low - eps).any():
            continue
        status = _where(points, other.triangles, eps)
        if name == "inside":
            if (status >= 0).all():
                return True
            continue
        if (status > 0).any():
            return True
        if closed is None:
            closed = _closed(mine)
        theirs, their_centres = _samples(other.triangles)
        if closed and (_where(theirs, mine, eps) > 0).any():
            return True
        if name == "touches":
            if (_where(centres, other.triangles, eps) == 0).any():
                return True
            if (_where(their_centres, mine, eps) == 0).any():
                return True
    return False


def first_pass(make_engine, lot_shape, start, index: int, several: bool) -> Occluders:
    """Derive the lot once with every query false (an engine from ``make_engine()``, whose
    terminals, prints and reports are dropped) and return what occludes in it."""
    from .reuse import Reuse

    engine = make_engine()
    engine.reuse = Reuse(replay=False)  # every comp and label noted, none replayed past
    recorder = engine.occlusion = Recorder()
    try:
        engine.derive(lot_shape, start, index=index, several=several)
        return recorder.finish(engine.table)
    finally:
        engine.release()


# --------------------------------------------------------------------------------------------
# the lots around a lot (inter)

NEIGHBOURHOOD = 1.0  # metres between two lots' bounding boxes (CityEngine's default)


def lot_bounds(shape) -> np.ndarray:
    """(2, 3): the lowest and highest world corner of a lot's scope, the box its initial
    shape lies in."""
    corners = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], float)
    world = np.asarray(shape.origin, float) + (corners * np.asarray(shape.size, float)) @ (
        np.asarray(shape.axes, float)
    )
    return np.stack([world.min(axis=0), world.max(axis=0)])


def neighbourhoods(bounds: np.ndarray, distance: float = NEIGHBOURHOOD) -> list[list[int]]:
    """For each box of ``bounds`` (N, 2, 3), the other boxes within ``distance`` of it, in
    index order.  Candidates come from an R-tree of the ground-plane boxes (shapely's
    STRtree), then the 3-D gap between the boxes decides."""
    from shapely import STRtree, box

    count = len(bounds)
    if count < 2:
        return [[] for _ in range(count)]
    low, high = bounds[:, 0], bounds[:, 1]
    tree = STRtree([box(lo[0], lo[2], hi[0], hi[2]) for lo, hi in zip(low, high, strict=True)])
    near = [
        box(lo[0] - distance, lo[2] - distance, hi[0] + distance, hi[2] + distance)
        for lo, hi in zip(low, high, strict=True)
    ]
    mine, theirs = tree.query(near, predicate="intersects")
    keep = mine != theirs
    mine, theirs = mine[keep], theirs[keep]
    gap = np.maximum(0.0, np.maximum(low[theirs] - high[mine], low[mine] - high[theirs]))
    close = np.linalg.norm(gap, axis=1) <= distance
    found: list[list[int]] = [[] for _ in range(count)]
    for i, j in sorted(zip(mine[close].tolist(), theirs[close].tolist(), strict=True)):
        found[i].append(j)
    return found
