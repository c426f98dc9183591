"""setback(distance) { selector: ... | remainder: ... }: CGA's setback of a 2D shape's edges
(interpreter/geometry/setbacks.py holds the geometry); innerRectangle, and shapeL, shapeU and
shapeO, CGA's L, U and O (ring) shapes cut from a 2D shape's scope."""

from __future__ import annotations

from bgr.grammar import nodes as n

from ..expressions import runtime_error
from ..geometry.meshes import PLANE_AXES
from ..geometry.polygons import RECT, UNIT_SQUARE, is_unit_square
from ..geometry.polygons import normalise as normalise_polys
from ..geometry.setbacks import edge_kinds, strips
from ..shapes import Flat

_SIDES = ("left", "right", "front", "back")


def setback(app, shape, step, args) -> bool:
    distance = float(args[0])
    geom = shape.geom
    if not isinstance(geom, Flat):
        raise runtime_error(
            app.module,
            step.pos,
            "setback() needs a 2D shape",
            "set back the edges of a lot, or of a face from comp(f)",
        )
    if distance < 0:
        raise runtime_error(
            app.module, step.pos, f"setback() distance {distance:g} is negative", "grow with offset"
        )
    p, q = PLANE_AXES[geom.k]
    su, sv = shape.size[p], shape.size[q]
    polys = [(UNIT_SQUARE, ())] if geom.polys == RECT else geom.polys
    edges = edge_kinds(polys, su, sv, p, q)
    taken = [False] * len(edges)
    chosen: list[tuple[n.Entry, list[int]]] = []
    for entry in step.block.entries:
        word = entry.key.name
        if word == "remainder":
            continue
        picked = [
            i
            for i, (_, kind) in enumerate(edges)
            if not taken[i]
            and (word == "all" or word == kind or (word == "side" and kind in _SIDES))
        ]
        for i in picked:
            taken[i] = True
        chosen.append((entry, picked))
    order = sorted(i for _, picked in chosen for i in picked)
    parts, rest = strips(polys, su, sv, [edges[i][0] for i in order], distance)
    part_of = dict(zip(order, parts, strict=True))
    for entry, picked in chosen:
        for i in picked:
            _piece(app, shape, step, entry, part_of[i], p, q, geom.k)
    for entry in step.block.entries:
        if entry.key.name == "remainder":
            _piece(app, shape, step, entry, rest, p, q, geom.k)
    return True


def _piece(app, shape, step, entry, metric_polys, p: int, q: int, k: int) -> None:
    if not metric_polys:
        return
    unit, (x0, y0, w, h) = normalise_polys(metric_polys)
    piece = shape.copy().cut_from(shape)
    move = [0.0, 0.0, 0.0]
    move[p], move[q] = x0, y0
    piece.origin = shape.world(move)
    piece.size[p], piece.size[q] = w, h
    piece.geom = Flat(k, RECT if is_unit_square(unit) else unit)
    app.engine.count_shape(app.module, entry.pos)
    app.piece(piece, entry.body)


def inner_rectangle(app, shape, step, args) -> bool:
    """innerRectangle(scope | edge) { shape: A | remainder: B }: the largest rectangle inside a
    2D shape along the scope's axes or one of its edges, and the rest
    (interpreter/geometry/inner_rectangle.py)."""
    from ..geometry.inner_rectangle import inner_rectangle, inner_rectangle_edge

    largest = inner_rectangle_edge if args[0] == "edge" else inner_rectangle

    geom = shape.geom
    if not isinstance(geom, Flat):
        raise runtime_error(
            app.module, step.pos, "innerRectangle() needs a 2D shape", "use it on a lot or a face"
        )
    p, q = PLANE_AXES[geom.k]
    polys = [(UNIT_SQUARE, ())] if geom.polys == RECT else geom.polys
    rect, rest = largest(polys, shape.size[p], shape.size[q])
    for entry in step.block.entries:
        part = rect if entry.key.name == "shape" else rest
        _piece(app, shape, step, entry, part, p, q, geom.k)
    return True


# the sides each of CGA's shape operations takes a width for, in its arguments' order
LUO_SIDES = {
    "shapeL": ("front", "left"),
    "shapeU": ("front", "right", "left"),
    "shapeO": ("front", "right", "back", "left"),
}


def shape_luo(app, shape, step, args) -> bool:
    """shapeL(front, left), shapeU(front, right, left), shapeO(front, right, back, left)
    { shape: A | remainder: B }: as CGA's, the strips of those widths along the scope's sides
    (front at its low z, or low y on a face; left at its low x), joined into an L, a U or a
    ring and cut to the shape's outline; ``remainder`` is the rest."""
    import shapely
    from shapely.geometry import box

    from ..geometry.polygons import from_shapely, metric, to_shapely

    geom = shape.geom
    if not isinstance(geom, Flat):
        raise runtime_error(
            app.module, step.pos, f"{step.name}() needs a 2D shape", "use it on a lot or a face"
        )
    p, q = PLANE_AXES[geom.k]
    su, sv = shape.size[p], shape.size[q]
    polys = [(UNIT_SQUARE, ())] if geom.polys == RECT else geom.polys
    whole = to_shapely(metric(polys, su, sv))
    strips_of = {
        "front": lambda d: box(0.0, 0.0, su, d),
        "back": lambda d: box(0.0, sv - d, su, sv),
        "left": lambda d: box(0.0, 0.0, d, sv),
        "right": lambda d: box(su - d, 0.0, su, sv),
    }
    widths = [float(v) for v in args[: len(step.args)]]
    pieces = [
        strips_of[side](min(width, max(su, sv)))
        for side, width in zip(LUO_SIDES[step.name], widths, strict=True)
        if width > 0
    ]
    part = whole.intersection(shapely.union_all(pieces)) if pieces else shapely.Polygon()
    parts = {"shape": from_shapely(part), "remainder": from_shapely(whole.difference(part))}
    for entry in step.block.entries:
        _piece(app, shape, step, entry, parts[entry.key.name], p, q, geom.k)
    return True
