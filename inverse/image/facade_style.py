"""Façade style recognition (section 5.3 of "Procedural building from a single image"): which
of the stdlib's sixteen façades (``stdlib/facade.bgr``) a parsed façade is, and that rule's
parameters fitted from the parse.

The paper classifies the façade image with a CNN trained on façades its grammars render.  Here,
as for the window styles (:mod:`.windows`), the classifier is trained on renders of the stdlib's
own façade rules with random parameters, sizes and colours, lightly degraded, *run through
the parse* (``bench/train_facade_style.py``): it learns the parse's quirks on each family (quoins
read as narrow windows, a shop front's two boxes) rather than an idealised layout, and is small
enough to ship as an .npz used by numpy alone:

* **Features** (:func:`features`): what the families differ in (the groups of stdlib/facade.bgr:
  floors, edge columns, middle column), measured relative to the façade's own middle floors so
  that they do not depend on its scale: the floor count, the bottom and top storeys' heights and
  their windows' sizes, counts and sills against the middle floors'; the end and the middle
  columns' window widths, heights, spacing and how many of their windows are missing; the window
  mask's share along the height and (folded about the middle) across the width; and from the
  photograph, the wall's brightness and colour along the height and across the width (a stone
  ground floor, quoins, accent columns) and where the horizontal edges are (bands, cornices);
  and 8 x 12 thumbnails of the mask, the brightness and the colour, folded about the middle.
  (Measured on the held-out renders of a first, smaller run: the profiles and thumbnails carry
  most of it, the box features alone reach 0.38; the colour thumbnails added 0.13.)
* **Model** (:func:`predict_proba`): :mod:`.windows`' perceptron (one hidden tanh layer, a
  softmax over :data:`RULES`) on standardised features.

**Fallback.**  Where the classifier is unsure (the likeliest family below :data:`THRESHOLD`,
or less than :data:`RATIO` times as likely as Grid), where the parse has fewer than two floors
of windows, where the family needs a storey of its own the parse lacks, or where it has
distinct end or middle columns and the parse's floors have fewer than three windows (no plain
column for them to differ from), the façade is ``Grid``, the plainest one: a wrong family adds
a shop front or a portal the photograph has not, a wrong Grid only leaves out a difference.

Measured by ``bench/train_facade_style.py`` (45 renders a family, two degraded versions each,
1,440 parses, 14 minutes on one loaded core): on the 20 % of renders not trained on, the
perceptron picks the right family for 0.81 of the parses (logistic regression 0.77); with the
probability fallback (threshold and ratio) 0.80 keep a family, 0.91 of those right, and the
family written is right for 0.82.
On 784 further renders drawn apart (the script's sampler, one degraded version a render,
another seed's draws) 0.80, and with the fallback 0.83 keep a family, 0.86 of those right.
Confused most: the families that differ in depth (Attic, Pavilions, Risalit, Manor: what
stands forward of the wall, which a front-on photograph barely shows), Quoined with Grid and
Symmetric.  Half the renders (25 a family, 9 minutes) gave 0.72 on those 784.  On the 100 CMP
façades (no truth: only the spread) the families written are Grid 48, Tripartite 12,
Shopfront 10, Portal 8, and four or fewer each of ten others.
"""

from __future__ import annotations

import statistics
from pathlib import Path

import numpy as np
from PIL import Image

from .facade import FacadeParse, rows_of
from .facade_grid import grid_values
from .windows import load_weights, predict_proba

WEIGHTS = Path(__file__).with_name("facade_styles.npz")

THRESHOLD = 0.5
"""The likeliest family's probability below which the façade is written as ``Grid``."""

RATIO = 2.0
"""A family other than ``Grid`` is written only when it is at least this many times as likely
as ``Grid``: a plain grid of windows whose middle or end column the parse finds no different
is a Grid, whatever its column count suggests."""

DEFAULT_RULE = "Grid"

RULES = (
    "Grid",
    "Shopfront",
    "Attic",
    "Tripartite",
    "Quoined",
    "CornerShop",
    "Pavilions",
    "EndBays",
    "CentralBalconies",
    "CentralEntrance",
    "Risalit",
    "Portal",
    "Symmetric",
    "Arcade",
    "Manor",
    "Palazzo",
)
"""The stdlib façades, in the classifier's output order (the weights file carries its own)."""

GROUND = {"Shopfront", "Tripartite", "CornerShop", "EndBays", "CentralEntrance", "Portal"}
GROUND |= {"Arcade", "Palazzo"}
"""Families with a ground floor of their own (``ground_h``)."""
TOP = {"Attic", "Tripartite", "Pavilions", "EndBays", "Risalit", "Portal", "Manor", "Palazzo"}
"""Families with a top floor of their own (``top_h``)."""
CENTRE = {"CentralBalconies", "CentralEntrance", "Risalit", "Portal", "Symmetric", "Arcade"}
CENTRE |= {"Manor", "Palazzo"}
"""Families with a middle column (an odd number of tiles)."""
EDGES = {"Quoined", "CornerShop", "Pavilions", "EndBays", "Symmetric", "Arcade", "Manor"}
EDGES |= {"Palazzo"}
"""Families with distinct end columns."""
DOOR = {"CornerShop", "EndBays", "CentralEntrance", "Portal", "Arcade", "Palazzo"}
"""Families with entrances (``door_w``, ``door_h``): in the middle column, or else the end ones."""
BANDS = {
    "Grid": 0.0,
    "Shopfront": 0.55,
    "Attic": 1.05,
    "Tripartite": 1.05,
    "Quoined": 0.3,
    "CornerShop": 0.65,
    "Pavilions": 1.05,
    "EndBays": 0.6,
    "CentralBalconies": 0.0,
    "CentralEntrance": 0.65,
    "Risalit": 1.05,
    "Portal": 0.6,
    "Symmetric": 0.0,
    "Arcade": 0.55,
    "Manor": 1.05,
    "Palazzo": 1.1,
}
"""Metres of fixed bands (plinth, fascia, cornice, coping) in each rule's height."""

BINS_Y = 16  # bins of the profiles along the height
BINS_X = 8  # bins of the profiles across half the width (folded about the middle)
SMALL = (48, 48)  # (rows, columns) the photograph is reduced to for the colour profiles
THUMB = (8, 12)  # (rows, columns) of the thumbnails (folded: 8 x 6 values each)


def _log(a: float, b: float) -> float:
    return float(np.log(np.clip(a / b, 0.1, 10.0))) if a > 0 and b > 0 else 0.0


def _bin(profile: np.ndarray, bins: int) -> np.ndarray:
    """``profile`` averaged into ``bins`` equal stretches."""
    edges = np.linspace(0, len(profile), bins + 1)
    idx = np.minimum(np.floor(np.arange(len(profile)) * bins / len(profile)), bins - 1)
    sums = np.bincount(idx.astype(np.int64), weights=profile, minlength=bins)
    return sums / np.maximum(np.diff(edges), 1e-9)


def _fold(profile: np.ndarray) -> np.ndarray:
    """A profile across the width folded about the middle: the half from an end to the middle."""
    both = (profile + profile[::-1]) / 2
    return both[: max(1, len(both) // 2)]


def _floor_stats(boxes: np.ndarray, storey: tuple[float, float]) -> np.ndarray:
    """(median width, median height, count, sill as a share of the storey) of one floor."""
    if len(boxes) == 0:
        return np.zeros(4)
    width = float(np.median(boxes[:, 3] - boxes[:, 1]))
    height = float(np.median(boxes[:, 2] - boxes[:, 0]))
    sill = (storey[1] - float(np.median(boxes[:, 2]))) / max(storey[1] - storey[0], 1.0)
    return np.array([width, height, float(len(boxes)), sill])


def _columns(boxes: np.ndarray) -> list[list[int]]:
    return rows_of([(float(b[1]), float(b[3])) for b in boxes])


def layout_features(parse: FacadeParse) -> np.ndarray:
    """The box features: floors, bottom and top storeys, end and middle columns."""
    out = np.zeros(32)
    n = len(parse.floors)
    if n == 0 or len(parse.windows) == 0:
        return out
    boxes = parse.windows
    bounds = parse.floor_bounds
    storeys = np.diff(bounds)
    inner = storeys[1:-1] if n >= 3 else storeys
    mid = float(np.median(inner))
    middle = [i for f in (parse.floors[1:-1] if n >= 3 else parse.floors) for i in f]
    ref = _floor_stats(boxes[middle], (0.0, mid))
    counts = [len(f) for f in (parse.floors[1:-1] if n >= 3 else parse.floors)]
    out[0] = min(n, 8) / 4
    out[1] = float(np.median(counts)) / 5
    out[2] = _log(parse.width, parse.height)
    out[3] = _log(storeys[-1], mid)
    out[4] = _log(storeys[0], mid)
    for k, floor in enumerate((parse.floors[-1], parse.floors[0])):
        idx = n - 1 if k == 0 else 0
        s = _floor_stats(boxes[floor], (bounds[idx], bounds[idx + 1]))
        out[5 + 5 * k : 10 + 5 * k] = [
            _log(s[0], ref[0]),
            _log(s[1], ref[1]),
            _log(s[2], float(np.median(counts))),
            s[3] - ref[3],
            float(parse.window[int(bounds[idx]) : int(bounds[idx + 1])].mean()),
        ]
    # the columns of the middle floors (all floors when there are fewer than three)
    sel = np.array(middle)
    cols = _columns(boxes[sel])
    out[15] = min(len(cols), 12) / 6
    if len(cols) >= 3:
        centres = [float(np.median((boxes[sel[c], 1] + boxes[sel[c], 3]) / 2)) for c in cols]
        widths = [float(np.median(boxes[sel[c], 3] - boxes[sel[c], 1])) for c in cols]
        heights = [float(np.median(boxes[sel[c], 2] - boxes[sel[c], 0])) for c in cols]
        present = [len(c) / max(1, len(counts)) for c in cols]
        pitch = float(np.median(np.diff(centres)))
        plain = float(np.median(widths[1:-1]))
        plain_h = float(np.median(heights[1:-1]))
        for k, e in enumerate((0, -1)):
            gap = abs(centres[e] - centres[1 if e == 0 else -2])
            edge = centres[e] if e == 0 else parse.width - centres[e]
            out[16 + 4 * k : 20 + 4 * k] = [
                _log(widths[e], plain),
                _log(heights[e], plain_h),
                _log(gap, pitch),
                min(present[e], 1.5) + _log(edge, pitch),
            ]
        c = int(np.argmin([abs(x - parse.width / 2) for x in centres]))
        off = abs(centres[c] - parse.width / 2) / max(pitch, 1.0)
        out[24:29] = [
            _log(widths[c], plain),
            _log(heights[c], plain_h),
            min(present[c], 1.5),
            off,
            float(len(cols) % 2),
        ]
    # the ground floor's window nearest the middle against its others (an entrance)
    ground = boxes[parse.floors[-1]]
    if len(ground) >= 3:
        x = (ground[:, 1] + ground[:, 3]) / 2
        c = int(np.argmin(np.abs(x - parse.width / 2)))
        others = np.delete(ground, c, axis=0)
        out[29] = _log(ground[c, 3] - ground[c, 1], float(np.median(others[:, 3] - others[:, 1])))
        out[30] = _log(ground[c, 2] - ground[c, 0], float(np.median(others[:, 2] - others[:, 0])))
        out[31] = (ground[c, 2] - float(np.median(others[:, 2]))) / max(mid, 1.0)
    return out


def image_features(parse: FacadeParse, rgb: np.ndarray) -> np.ndarray:
    """The mask and photograph profiles: window share, wall brightness and colour, horizontal
    edges, along the height (:data:`BINS_Y`) and folded across the width (:data:`BINS_X`)."""
    mask = parse.window.astype(np.float64)
    out = [_bin(mask.mean(axis=1), BINS_Y), _bin(_fold(mask.mean(axis=0)), BINS_X)]
    small = np.asarray(
        Image.fromarray(np.ascontiguousarray(rgb[..., :3])).resize(
            (SMALL[1], SMALL[0]), Image.Resampling.BILINEAR
        ),
        dtype=np.float64,
    )
    wall = ~np.asarray(Image.fromarray(parse.window).resize((SMALL[1], SMALL[0])), dtype=bool)
    grey = small.mean(axis=2)
    chroma = small - grey[..., None]
    spread = float(grey[wall].std()) + 10.0 if wall.any() else 10.0
    base = float(np.median(grey[wall])) if wall.any() else float(np.median(grey))
    weight = wall.astype(np.float64) + 1e-3
    for plane, centre in ((grey, base), (chroma[..., 0], 0.0), (chroma[..., 2], 0.0)):
        rows = (plane * weight).sum(axis=1) / weight.sum(axis=1)
        cols = (plane * weight).sum(axis=0) / weight.sum(axis=0)
        out.append(_bin((rows - centre) / spread, BINS_Y))
        out.append(_bin(_fold((cols - centre) / spread), BINS_X))
    edges = np.abs(np.diff(grey, axis=0)).mean(axis=1)
    out.append(_bin(edges / (edges.mean() + 1.0), BINS_Y - 1))
    # thumbnails folded about the middle: the window mask, and the photograph's brightness and
    # red and blue against it (where a stone storey, accent columns, a shop front are)
    rows, cols = THUMB
    half = cols // 2
    m = Image.fromarray(parse.window.astype(np.uint8) * 255)
    m_small = np.asarray(m.resize((cols, rows), Image.Resampling.BILINEAR), dtype=np.float64)
    thumb = np.asarray(
        Image.fromarray(np.ascontiguousarray(rgb[..., :3])).resize(
            (cols, rows), Image.Resampling.BILINEAR
        ),
        dtype=np.float64,
    )
    g = thumb.mean(axis=2)
    scale = g.std() + 5.0
    planes = [m_small / 255.0, (g - np.median(g)) / scale]
    planes += [(thumb[..., k] - g) / scale for k in (0, 2)]
    out += [((p + p[:, ::-1]) / 2)[:, :half].ravel() for p in planes]
    return np.concatenate(out)


def features(parse: FacadeParse, rgb: np.ndarray) -> np.ndarray:
    """(F,) float32 features of a parse and its photograph (any size: the profiles resample)."""
    return np.concatenate([layout_features(parse), image_features(parse, rgb)]).astype(np.float32)


def classify(
    parse: FacadeParse, rgb: np.ndarray, weights: str | Path = WEIGHTS
) -> dict[str, float]:
    """Each family's probability, likeliest first."""
    net, rules = load_weights(weights)  # the windows' perceptron file format
    p = predict_proba(features(parse, rgb)[None], net)[0]
    order = np.argsort(-p, kind="stable")
    return {rules[i]: float(p[i]) for i in order}


def fit_params(parse: FacadeParse, rule: str, floor_height: float) -> dict[str, float]:
    """The parameters of ``rule`` read off the parse (metres; ``width`` and ``height`` are the
    façade's): :func:`~.facade_grid.grid_values`' floor, tile and window sizes, and for the
    families with their own ground and top floors those storeys' heights (the middle floors
    then share what is left, less the rule's bands), an odd tile count where the rule has a
    middle column, and the entrance's size where it has one."""
    values = grid_values(parse, floor_height)
    n = len(parse.floors)
    if rule == DEFAULT_RULE or n == 0:
        return values
    scale = values["height"] / max(parse.height, 1)
    storeys = np.diff(parse.floor_bounds) * scale
    ground = float(np.clip(storeys[-1], 2.5, 7.0)) if rule in GROUND else 0.0
    top = float(np.clip(storeys[0], 1.6, 4.0)) if rule in TOP else 0.0
    mids = n - (rule in GROUND) - (rule in TOP)
    room = values["height"] - BANDS[rule] - ground - top
    values["floor_h"] = room / mids if mids > 0 and room > 2.0 * mids else floor_height
    # the window sizes and sill of the middle floors alone
    middle = range(1 if top else 0, n - 1 if ground else n)
    if len(middle):
        boxes = parse.windows[[i for k in middle for i in parse.floors[k]]]
        values["win_w"] = float(np.median(boxes[:, 3] - boxes[:, 1])) * scale
        values["win_h"] = float(np.median(boxes[:, 2] - boxes[:, 0])) * scale
        sills = [
            parse.floor_bounds[k + 1] - float(np.median(parse.windows[parse.floors[k], 2]))
            for k in middle
        ]
        values["sill_h"] = max(0.0, float(np.median(sills))) * scale
    if ground:
        values["ground_h"] = ground
    if top:
        values["top_h"] = top
    if rule in CENTRE:
        counts = parse.windows_per_floor()
        columns = int(statistics.median(counts)) if counts else 1
        odd = columns if columns % 2 else columns + 1
        values["tile_w"] = (values["width"] - 2 * values["margin"]) / odd
    if rule in DOOR and len(parse.floors[-1]):
        boxes = parse.windows[parse.floors[-1]]
        x = (boxes[:, 1] + boxes[:, 3]) / 2
        at = parse.width / 2 if rule in CENTRE else 0.0
        door = boxes[int(np.argmin(np.abs(x - at)))]
        values["door_w"] = float(np.clip((door[3] - door[1]) * scale, 0.9, 3.0))
        values["door_h"] = float(np.clip((door[2] - door[0]) * scale, 2.0, max(2.0, ground - 0.3)))
    return values


def facade_style(
    parse: FacadeParse,
    rgb: np.ndarray,
    floor_height: float = 3.2,
    weights: str | Path = WEIGHTS,
    threshold: float = THRESHOLD,
    ratio: float = RATIO,
) -> tuple[str, dict[str, float], dict[str, float]]:
    """(rule, parameters, probabilities): the stdlib façade the parse of the rectified
    photograph ``rgb`` is likeliest to be and its parameters (:func:`fit_params`, metres, with
    the façade's ``width`` and ``height``), or ``Grid`` (:data:`DEFAULT_RULE`, see the module's
    Fallback) and its own; and each family's probability, likeliest first (empty when the
    parse is too thin to ask the classifier)."""
    if len(parse.floors) < 2 or len(parse.windows) == 0:
        return DEFAULT_RULE, fit_params(parse, DEFAULT_RULE, floor_height), {}
    proba = classify(parse, rgb, weights)
    rule, p = next(iter(proba.items()))
    floors = (rule in GROUND) + (rule in TOP) + 1
    columns = 3 if rule in EDGES or rule in CENTRE else 1
    counts = parse.windows_per_floor()
    unsure = p < threshold or p < ratio * proba[DEFAULT_RULE]
    if unsure or len(counts) < floors or statistics.median(counts) < columns:
        rule = DEFAULT_RULE
    return rule, fit_params(parse, rule, floor_height), proba


def describe(rule: str, proba: dict[str, float]) -> str:
    """``fac.Rule (p 0.91)``, or for a fallback what the classifier's likeliest was."""
    if not proba:
        return f"fac.{rule} (too few floors to classify)"
    best, p = next(iter(proba.items()))
    if best == rule:
        return f"fac.{rule} (p {p:.2f})"
    return f"fac.{rule} (fallback: likeliest {best}, p {p:.2f})"


def facade_call(
    rule: str, values: dict[str, float], color: tuple[int, int, int], window: str = "Plain"
) -> tuple[list[str], str]:
    """(attr lines, rule call) of a façade in a written grammar: an ``attr`` for each fitted
    parameter but the façade's ``width`` and ``height``, and ``wall_color``, and the call of
    ``fac.<rule>`` with them and the ``window`` rule of stdlib.window."""
    names = [k for k in values if k not in ("width", "height")]
    lines = [f"attr {k} = {values[k]:.3f}".rstrip("0").rstrip(".") for k in names]
    lines.append('attr wall_color = "#{:02x}{:02x}{:02x}"'.format(*color))
    args = ", ".join(f"{k} = {k}" for k in [*names, "wall_color"])
    return lines, f"fac.{rule}({args}, window = win.{window})"
