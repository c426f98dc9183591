"""Where vertical faces meet: their comp sides, the corners between them, and their rings.

:func:`side_of` names a face by its outward normal as comp(f) does; :func:`link_faces` joins
faces whose bottom corners meet, sets each face's left and right corner (flat, outer or inner)
and returns the rings they form, one per block.  Both readers (:mod:`.terminals` and
:mod:`.captured`) link their faces with it, and the emitter names sides with :func:`side_of`.
"""

from __future__ import annotations

import math

from .model import Face
from .terminal_list import _dot

LINK = 0.6  # metres: face corners this close are one corner


def side_of(normal, axes=None) -> str:
    """The comp selector of a face by its outward normal in its lot's frame (section 7: front is
    -z, back +z, left -x, right +x); the world's frame when the lot is not known."""
    if axes is not None:
        normal = tuple(_dot(normal, a) for a in axes)
    x, _, z = normal
    if abs(x) >= abs(z):
        return "right" if x > 0 else "left"
    return "back" if z > 0 else "front"


def _corner(x_left, x_right) -> str:
    """The corner between a face (x axis x_left) and its right neighbour (x_right), from outside."""
    turn = x_left[2] * x_right[0] - x_left[0] * x_right[2]  # y of x_left cross x_right
    along = x_left[0] * x_right[0] + x_left[2] * x_right[2]
    if abs(turn) < 1e-6 and along > 0:
        return "flat"
    return "outer" if turn > 0 else "inner"


def link_faces(faces: list[Face]) -> list[list[Face]]:
    """Set each vertical face's left/right corner from the face whose bottom corner it shares
    (``origin``, ``width``, ``x_axis`` in world coordinates); faces linked this way form one
    block, returned as rings in order.  Used by both readers."""
    # corners match within LINK: a cornice or a quoin that stands a little past the wall's
    # edge widens a face's outline by a few centimetres
    cell = LINK * 2

    def bucket(p):
        return (math.floor(p[0] / cell), math.floor(p[2] / cell))

    starts: dict[tuple, list[Face]] = {}
    for f in faces:
        starts.setdefault(bucket(f.origin), []).append(f)
    right_of: dict[int, Face] = {}
    taken: set[int] = set()
    for f in faces:
        end = tuple(f.origin[i] + f.width * f.x_axis[i] for i in range(3))
        bx, bz = bucket(end)
        near = [
            g for dx in (-1, 0, 1) for dz in (-1, 0, 1) for g in starts.get((bx + dx, bz + dz), [])
        ]
        best, rank = None, (LINK, 0.0)
        for g in near:
            d = math.dist((end[0], end[1], end[2]), g.origin)
            # the nearest start; at a shared corner the wall that runs straight on (a block
            # attached flush) before one that turns
            r = (round(d, 6), -_dot(f.x_axis, g.x_axis))
            if g is not f and id(g) not in taken and d <= LINK and (best is None or r < rank):
                best, rank = g, r
        if best is not None:
            taken.add(id(best))
            right_of[id(f)] = best
            kind = _corner(f.x_axis, best.x_axis)
            f.right, best.left = kind, kind
    # blocks: follow the links
    seen, blocks = set(), []
    for f in faces:
        if id(f) in seen:
            continue
        ring, g = [], f
        while g is not None and id(g) not in seen:
            seen.add(id(g))
            ring.append(g)
            g = right_of.get(id(g))
        blocks.append(ring)
    return blocks
