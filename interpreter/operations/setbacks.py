"""setback(distance) { selector: ... | remainder: ... }: CGA's setback of a 2D shape's edges
(interpreter/geometry/setbacks.py holds the geometry), and setbackPerEdge(distance), its
distance evaluated once per edge with the edge as the current shape; innerRectangle, and
shapeL, shapeU and shapeO, CGA's L, U and O (ring) shapes cut from a 2D shape's scope."""

from __future__ import annotations

import math

from bgr.grammar import nodes as n

from ..expressions import runtime_error
from ..geometry.meshes import PLANE_AXES
from ..geometry.polygons import RECT, UNIT_SQUARE, is_unit_square
from ..geometry.polygons import normalise as normalise_polys
from ..geometry.setbacks import edge_kinds, strips
from ..shapes import Flat, cross

_SIDES = ("left", "right", "front", "back")


def setback(app, shape, step, args) -> bool:
    """setback(distance) and setbackPerEdge(distance): see the module docstring."""
    geom = shape.geom
    if not isinstance(geom, Flat):
        raise runtime_error(
            app.module,
            step.pos,
            f"{step.name}() needs a 2D shape",
            "set back the edges of a lot, or of a face from comp(f)",
        )
    p, q = PLANE_AXES[geom.k]
    su, sv = shape.size[p], shape.size[q]
    polys = [(UNIT_SQUARE, ())] if geom.polys == RECT else geom.polys
    edges = edge_kinds(polys, su, sv, p, q)
    if step.name == "setbackPerEdge":
        each = _per_edge(app, shape, step, args[0], edges, p, q)
    else:
        each = [float(args[0])] * len(edges)
    for d in each:
        if d < 0:
            raise runtime_error(
                app.module,
                step.pos,
                f"{step.name}() distance {d:g} is negative",
                "grow with offset",
            )
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
    distance = [each[i] for i in order] if step.name == "setbackPerEdge" else (each or [0.0])[0]
    parts, rest = strips(polys, su, sv, [edges[i][0] for i in order], distance)
    part_of = dict(zip(order, parts, strict=True))
    for entry, picked in chosen:
        for i in picked:
            _piece(app, shape, step, entry, part_of[i], p, q, geom.k)
    for entry in step.block.entries:
        if entry.key.name == "remainder":
            _piece(app, shape, step, entry, rest, p, q, geom.k)
    return True


def _per_edge(app, shape, step, distance, edges, p: int, q: int) -> list[float]:
    """setbackPerEdge's distance evaluated once per edge, as CGA's: the current shape is then
    the edge (its scope's x along it, from its start, a size of (length, 0, 0)), comp.sel its
    selector word and comp.index its number round the outline.  An array as the value gives
    edge i its item i (none past its end), as CGA's setback(distances)."""
    ctx = app.ctx
    saved = (ctx.shape, ctx.comp_index, ctx.comp_total, ctx.comp_sel)
    normal = [0.0, 0.0, 0.0]
    normal[3 - p - q] = 1.0
    out = []
    try:
        for i, ((a, b), kind) in enumerate(edges):
            start, along = [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
            start[p], start[q] = a
            along[p], along[q] = b[0] - a[0], b[1] - a[1]
            length = math.hypot(*along)
            x = [c / length for c in along]
            edge = shape.copy().cut_from(shape)
            edge.origin = shape.world(start)
            edge.axes = tuple(tuple(shape.direction(v)) for v in (x, normal, cross(x, normal)))
            edge.size = [length, 0.0, 0.0]
            ctx.shape, ctx.comp_index, ctx.comp_total, ctx.comp_sel = edge, i, len(edges), kind
            value = distance(ctx)
            if isinstance(value, tuple):  # CGA's setback(distances): edge i takes item i
                value = value[i] if i < len(value) else 0.0
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise runtime_error(
                    app.module, step.pos, f"{step.name}()'s distance is a number, got {value!r:.40}"
                )
            out.append(float(value))
    finally:
        ctx.shape, ctx.comp_index, ctx.comp_total, ctx.comp_sel = saved
    return out


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
