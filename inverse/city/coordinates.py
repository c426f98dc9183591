"""The one check every city reader's vertices pass: finite, and within ``MAX_INPUT_COORDINATE``.

A vertex at 1e308 is a number, so the readers take it; further on it hangs GEOS ``simplify``
(past SIGTERM), crashes scipy's ``kmeans2`` and overflows the integer keys of the component
meshes.  Cities are bounded as lots are (1e8 m; docs/limits.md), once, right after reading
(:func:`bgr.inverse.city.read._scene`), whatever the format.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from bgr.grammar.errors import BgrError, Diagnostic
from bgr.interpreter.limits import MAX_INPUT_COORDINATE

from .model import CityObject

Locate = Callable[[int, int, str, str], BgrError]
"""(vertex, axis, message, hint) -> the error at the vertex's place in the file (OBJ: its line
and column)."""

HINT = (
    f"a city's coordinates are metres within ±{MAX_INPUT_COORDINATE:.0e} (a projected CRS "
    "reaches 2e7): the exporter wrote a point it could not place, or other units"
).replace("e+0", "e")


def check_coordinates(
    shown: str,
    vertices: np.ndarray,
    faces: np.ndarray,
    owner: np.ndarray | None,
    objects: list[CityObject],
    locate: Locate | None = None,
) -> None:
    """A BgrError naming the first vertex a face uses that is not finite or lies beyond
    MAX_INPUT_COORDINATE (vertices no face uses may be anything: exporters leave such)."""
    used = np.zeros(len(vertices), dtype=bool)
    used[faces] = True
    bad = used & ~(np.abs(vertices) <= MAX_INPUT_COORDINATE).all(axis=1)  # NaN compares false
    if not bad.any():
        return
    k = int(np.argmax(bad))
    axis = int(np.argmax(~(np.abs(vertices[k]) <= MAX_INPUT_COORDINATE)))
    value = float(vertices[k, axis])
    what = (
        "is not a finite number (NaN or infinity)"
        if not np.isfinite(value)
        else f"is beyond {MAX_INPUT_COORDINATE:,.0f} m"
    )
    more = int(bad.sum()) - 1
    others = f" ({more:,} more {'vertex' if more == 1 else 'vertices'} like it)" if more else ""
    message = f"{'xyz'[axis]} = {value:g} {what}{others}"
    if locate is not None:
        raise locate(k, axis, f"vertex {k + 1}: {message}", HINT)
    where = _object_of(k, faces, owner, objects)
    raise BgrError(Diagnostic(shown, 0, 0, f"{where}: {message}", HINT))


def _object_of(
    vertex: int, faces: np.ndarray, owner: np.ndarray | None, objects: list[CityObject]
) -> str:
    """How the message names a vertex: by the object whose face uses it when the file names
    objects (a CityJSON id, a glTF node), else by its number among the file's vertices."""
    if owner is not None and objects:
        face = int(np.argmax((faces == vertex).any(axis=1)))
        return f"a vertex of {objects[int(owner[face])].kind} '{objects[int(owner[face])].name}'"
    return f"vertex {vertex + 1} (counted from 1)"
