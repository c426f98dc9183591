"""The edges and vertices of a shape's faces, with what comp(e) and comp(v) select them by.

The faces come from ``comp(f)``'s face list (rings of 3D points in scope-local metres and an
outward unit normal each), so an edge is a side of a face's polygon, never a triangulation
diagonal.  Two faces share an edge when its two end points agree to a micrometre.

CGA's roof selectors are read from the geometry alone, so they hold for any roof-like solid:

* ``eave``: a horizontal edge whose faces (but a downward one) lie above it, one of them a
  slope;
* ``ridge``: a horizontal edge whose faces lie below it, two of them slopes;
* ``hip`` / ``valley``: an inclined edge between two sloped faces, convex / concave.

An edge's normal, the y axis of its scope, is the mean of its faces' normals; a vertex's the
mean of the normals of the faces around it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# a direction within 1 degree of the scope's horizontal plane is horizontal (as comp(f)'s
# vertical and horizontal faces)
_SIN_1_DEGREE = math.sin(math.radians(1.0))


@dataclass(frozen=True)
class Edge:
    start: tuple[float, float, float]  # scope-local metres, in the first face's ring order
    end: tuple[float, float, float]
    normal: tuple[float, float, float]  # mean of its faces' outward normals, unit length
    faces: tuple[int, ...]  # the faces it belongs to, in face order
    roof: str  # eave, ridge, hip, valley or ""


@dataclass(frozen=True)
class Vertex:
    point: tuple[float, float, float]
    normal: tuple[float, float, float]  # mean of its faces' normals, unit length
    toward: tuple[float, float, float]  # the next corner of the first face's ring that has it
    border: bool  # on an edge that only one face has


def _key(p) -> tuple[int, int, int]:
    return (round(p[0] * 1e6), round(p[1] * 1e6), round(p[2] * 1e6))


def _unit(v: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    length = float(np.linalg.norm(v))
    return v / length if length > 1e-12 else fallback


def _sides(faces):
    """(face index, start, end) of every side of every ring of every face, in order."""
    for index, (rings, _nrm, *_rest) in enumerate(faces):
        for ring in rings:
            count = len(ring)
            for i in range(count):
                a, b = ring[i], ring[(i + 1) % count]
                if _key(a) != _key(b):
                    yield index, a, b


def _gathered(faces, key_of) -> dict[tuple, list]:
    """[first side's start, its end, the faces that have it] by ``key_of(start, end)``, in the
    order the faces first use each key (dicts keep it)."""
    found: dict[tuple, list] = {}
    for index, a, b in _sides(faces):
        entry = found.setdefault(key_of(a, b), [a, b, []])
        if index not in entry[2]:
            entry[2].append(index)
    return found


def edges(faces) -> list[Edge]:
    """The distinct edges of the faces, in the order the faces first use them."""
    found = _gathered(faces, lambda a, b: tuple(sorted((_key(a), _key(b)))))
    normals = [np.asarray(nrm, dtype=float) for _rings, nrm, *_ in faces]
    centres = [np.mean(np.asarray(rings[0], dtype=float), axis=0) for rings, *_ in faces]
    out = []
    for a, b, owners in found.values():
        mean = _unit(sum(normals[i] for i in owners), normals[owners[0]])
        roof = _roof_kind(np.asarray(a, float), np.asarray(b, float), owners, normals, centres)
        out.append(Edge(tuple(a), tuple(b), tuple(mean.tolist()), tuple(owners), roof))
    return out


def _roof_kind(a, b, owners, normals, centres) -> str:
    direction = _unit(b - a, np.array([1.0, 0.0, 0.0]))
    middle = (a + b) / 2
    if abs(direction[1]) <= _SIN_1_DEGREE:
        # faces that are not undersides: above the edge, it is an eave; below, a ridge
        upper = [i for i in owners if normals[i][1] >= -_SIN_1_DEGREE]
        heights = [centres[i][1] - middle[1] for i in upper]
        slopes = [i for i in upper if _SIN_1_DEGREE < normals[i][1] < 1 - 1e-9]
        if slopes and all(h > 1e-9 for h in heights):
            return "eave"  # the low edge of a slope (a gable end's or a wall's foot is not)
        if len(slopes) >= 2 and all(h < -1e-9 for h in heights):
            return "ridge"  # where two slopes meet at the top (a shed's high edge is not)
        return ""
    sloped = [i for i in owners if _SIN_1_DEGREE < abs(normals[i][1]) < 1 - 1e-9]
    if len(owners) != 2 or len(sloped) != 2:
        return ""
    first, second = owners
    # convex when the second face lies behind the first one's plane
    behind = float(np.dot(normals[first], centres[second] - middle))
    return "hip" if behind < 0 else "valley"


def vertices(faces) -> list[Vertex]:
    """The distinct corners of the faces, in the order the faces first use them."""
    border_keys: set[tuple] = set()
    for edge in edges(faces):
        if len(edge.faces) == 1:
            border_keys.update((_key(edge.start), _key(edge.end)))
    found = _gathered(faces, lambda a, b: _key(a))
    normals = [np.asarray(nrm, dtype=float) for _rings, nrm, *_ in faces]
    out = []
    for key, (point, toward, owners) in found.items():
        mean = _unit(sum(normals[i] for i in owners), normals[owners[0]])
        out.append(Vertex(tuple(point), tuple(mean.tolist()), tuple(toward), key in border_keys))
    return out
