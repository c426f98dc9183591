"""comp(e) and comp(v): a shape's edges and vertices as shapes of their own, and comp()
itself, which hands faces to components.comp_faces.

CGA's edge shape has its scope's x along the edge (from its first face's ring order), y the
mean of its faces' normals, z = x × y, its origin at the edge's start and a size of
(length, 0, 0).  A vertex shape sits at the corner with y its faces' mean normal, x toward the
next corner of its first face, and a size of 0.  Both are bare: their geometry has no faces, so
one left as a leaf makes no terminal, as in CityEngine; a rule gives them a size and inserts
something (``s('1, 0.2, 0.2) center(yz) i(cube)`` puts a bar along an edge).
"""

from __future__ import annotations

import math
from dataclasses import replace

from ..geometry.edges import edges, vertices
from ..occlusion import note
from ..shapes import Solid, cross, dot, normalise
from .components import comp_faces, faces_of
from .selection import check_budget, select, words


def comp(app, shape, step, args) -> bool:
    kind = args[0]
    if kind == "f":
        return comp_faces(app, shape, step)
    first = app.counter
    done = comp_edges(app, shape, step) if kind == "e" else comp_vertices(app, shape, step)
    note(app, shape, first=first)  # as comp_faces' shape, an occluder (occlusion.py)
    return done


def _frame(x, y_hint) -> tuple[list[float], list[float], list[float]]:
    """Orthonormal (x, y, z) with x as given and y as near ``y_hint`` as x allows."""
    x = normalise(list(x))
    y = [y_hint[i] - dot(y_hint, x) * x[i] for i in range(3)]
    if math.sqrt(dot(y, y)) < 1e-9:  # the hint runs along x: any perpendicular
        other = [0.0, 1.0, 0.0] if abs(x[1]) < 0.9 else [1.0, 0.0, 0.0]
        y = [other[i] - dot(other, x) * x[i] for i in range(3)]
    y = normalise(y)
    return x, y, cross(x, y)


def _bare(app, shape, point, axes, size, name: str):
    piece = shape.copy().cut_from(shape)
    piece.origin = shape.world(point)
    piece.axes = tuple(tuple(shape.direction(a)) for a in axes)
    piece.size = size
    piece.geom = Solid(app.engine.bare_id(name), name)
    if piece.trims is not None:
        piece.trims = replace(piece.trims, planes=())
    return piece


def comp_edges(app, shape, step) -> bool:
    found = edges(faces_of(app, step, shape))
    check_budget(app, step, len(found), "edges")
    answers = [
        words(e.normal, "border" if len(e.faces) == 1 else "inside", *([e.roof] if e.roof else []))
        for e in found
    ]
    for entry, selector, chosen in select(app, step, answers):
        for j, i in enumerate(chosen):
            edge = found[i]
            along = [edge.end[k] - edge.start[k] for k in range(3)]
            axes = _frame(along, edge.normal)
            length = math.sqrt(dot(along, along))
            piece = _bare(app, shape, edge.start, axes, [length, 0.0, 0.0], "edge")
            app.engine.count_shape(app.module, entry.pos)
            app.piece(piece, entry.body, comp=(j, len(chosen), 0.0, 0.0, selector))
    return True


def comp_vertices(app, shape, step) -> bool:
    found = vertices(faces_of(app, step, shape))
    check_budget(app, step, len(found), "vertices")
    answers = [words(v.normal, "border" if v.border else "inside") for v in found]
    for entry, selector, chosen in select(app, step, answers):
        for j, i in enumerate(chosen):
            vertex = found[i]
            toward = [vertex.toward[k] - vertex.point[k] for k in range(3)]
            y = normalise(list(vertex.normal))
            axes = _vertex_axes(toward, y)
            piece = _bare(app, shape, vertex.point, axes, [0.0, 0.0, 0.0], "vertex")
            app.engine.count_shape(app.module, entry.pos)
            app.piece(piece, entry.body, comp=(j, len(chosen), 0.0, 0.0, selector))
    return True


def _vertex_axes(toward, y) -> tuple[list[float], list[float], list[float]]:
    """y the vertex normal; x toward the next corner, made perpendicular to y."""
    x = [toward[i] - dot(toward, y) * y[i] for i in range(3)]
    if math.sqrt(dot(x, x)) < 1e-9:
        other = [1.0, 0.0, 0.0] if abs(y[0]) < 0.9 else [0.0, 0.0, 1.0]
        x = [other[i] - dot(other, y) * y[i] for i in range(3)]
    x = normalise(x)
    return x, y, cross(x, y)
