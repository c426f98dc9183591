"""The stdlib's plainest façade, ``fac.Grid``, fitted to a façade parse: its floor, tile and
window sizes in metres (:func:`grid_values`).

Both the grammar writer of ``bgr infer --kind facade`` (:mod:`.command`) and the style
recognition (:mod:`.facade_style`, whose families start from these values) use it; it stays
apart from both so that neither has to import the other, and so that it costs no more than
numpy to import (the parser's scipy is named for types only).
"""

from __future__ import annotations

import statistics
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .facade import FacadeParse


def grid_values(parse: FacadeParse, floor_height: float) -> dict[str, float]:
    """The parse as the parameters of the stdlib's ``fac.Grid`` (and the façade's ``width`` and
    ``height``), in metres: the photograph scaled so that the floors are ``floor_height``
    metres apart."""
    boxes = parse.windows
    floors = [boxes[f] for f in parse.floors]
    centres = [float(np.median((f[:, 0] + f[:, 2]) / 2)) for f in floors]
    pitch = (
        float(np.median(np.diff(centres)))
        if len(centres) > 1
        else parse.height / max(1, len(floors))
    )
    scale = floor_height / pitch  # metres a pixel
    width, height = parse.width * scale, parse.height * scale
    counts = parse.windows_per_floor()
    columns = int(statistics.median(counts)) if counts else 1
    win_w = float(np.median(boxes[:, 3] - boxes[:, 1])) * scale if len(boxes) else 0.0
    win_h = float(np.median(boxes[:, 2] - boxes[:, 0])) * scale if len(boxes) else 0.0
    bottoms = [parse.floor_bounds[k + 1] - float(np.median(f[:, 2])) for k, f in enumerate(floors)]
    sill = max(0.0, statistics.median(bottoms)) * scale if bottoms else 0.0
    left = float(boxes[:, 1].min()) * scale if len(boxes) else 0.0
    right = width - float(boxes[:, 3].max()) * scale if len(boxes) else 0.0
    tile = (width - left - right + win_w) / max(1, columns)  # the windows' pitch
    margin = max(0.0, min(left, right) - (tile - win_w) / 2)
    # fac.Grid fits round(height / floor_h) floors and round(room / tile_w) tiles: the parse's
    # counts, exactly, with these
    return {
        "width": width,
        "height": height,
        "floor_h": height / max(1, len(floors)),
        "tile_w": (width - 2 * margin) / max(1, columns),
        "win_w": win_w,
        "win_h": win_h,
        "sill_h": sill,
        "margin": margin,
    }
