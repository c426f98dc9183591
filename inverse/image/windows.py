"""Window style recognition (section 6 of "Procedural building from a single image"): each
window box of a rectified façade is classified as one of the stdlib's window rules, and the
façade's window rule is the majority vote over its boxes.

The paper trains a CNN (AlexNet at 227 x 227) on CMP tiles it annotated by hand.  Here, with
numpy only at run time and no annotated windows, the classifier is trained on renders of the
stdlib's own window rules (``bench/train_windows.py``: random sizes, proportions and colours,
degraded to look like photo crops, the paper's "simplify the input to match the synthetic
data" read in reverse), and is small enough to ship as an .npz:

* **Features** (:func:`features`): the crop of the box with :data:`MARGIN` of its size on
  every side, resized to :data:`CROP` grey; histograms of gradient orientation on a grid of
  cells (HOG-like: the bars, arches, slats and railings that tell the rules apart are edges of a
  given direction in a given place), a coarse contrast-normalised thumbnail (where the dark
  glass is: a round head, a disc), a few colour statistics (shutters and frames in a colour
  other than the wall's) and the box's log aspect ratio, which the resize would lose.
* **Model** (:func:`predict_proba`): a perceptron with one hidden layer of 256 tanh units and a
  softmax over :data:`RULES`, after standardising the features; measured against a plain
  multinomial logistic regression on the same features by the training script.

The crops are classified in one batch: a façade of 60 windows takes about 0.1 s (measured on
a loaded two-core machine), most of it numpy's elementwise work on the 60 crops.

Measured by ``bench/train_windows.py`` on the 20 % of renders not trained on (350 renders a
rule, 3 crops each): the perceptron (256 units) 0.83 of the crops, logistic regression on the
same features 0.80 (the paper's CNN: 0.91 on its held-out augmented CMP tiles).  The rules
confused most differ only in glazing bars (Plain, Transom, Sash, Georgian), which a 48-row crop
of a 30-100 pixel window blurs together, or in how far a railing reaches (FrenchBalcony,
Balcony); the vote over a façade's windows absorbs much of it.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np
from PIL import Image

WEIGHTS = Path(__file__).with_name("window_styles.npz")

RULES = (
    "Plain",
    "TwoPane",
    "ThreePane",
    "Cross",
    "Transom",
    "Sash",
    "Georgian",
    "Arched",
    "Segmental",
    "Oculus",
    "Shutters",
    "FrenchBalcony",
    "Balcony",
    "Louvre",
)
"""The stdlib window rules told apart (``stdlib/window.bgr``), in the classifier's output
order, plainer rules first; the weights file carries its own list, which wins.  Chosen as the
ones that look different in a front-on crop of the opening: the glazing patterns (one pane, two,
a Chicago window, a cross, a transom light, sashes, small Georgian panes), the heads (round,
segmental, a disc), what stands in front of or beside the opening (shutters, a railing across
it, a balcony slab) and a louvre.  Left out: Mullioned (at façade scale TwoPane or ThreePane in
stone), Casement (an open leaf, rare in photographs), Bay (front-on, a Plain window on a
panel), the stone dressings Sill ... Hood (they go round any window, mostly outside the box: a
decision of their own), Awning, Shop and the entrances (ground-floor openings)."""

DEFAULT_RULE = "Plain"
"""The rule of a façade with no windows to vote: the stdlib façades' own default."""

MARGIN = 0.2
"""Wall kept round a box on every side, as a fraction of its height (width): a sill, a lintel,
a keystone, the shutters beside the opening and a balcony's slab are part of the style."""

CROP = (48, 32)
"""(rows, columns) of the grey crop the features are computed on."""

CELL = 8
"""Side of a gradient-histogram cell, crop pixels: 6 x 4 cells."""

BINS = 9
"""Unsigned orientation bins of the gradient histograms (0-180 degrees, as HOG)."""

THUMB = (12, 8)
"""(rows, columns) of the contrast-normalised thumbnail."""


def crops(rgb: np.ndarray, boxes: np.ndarray, margin: float = MARGIN) -> np.ndarray:
    """(k, rows, cols, 3) float32 crops in [0, 1] of ``boxes`` (top, left, bottom, right) with
    ``margin`` round each, resized to :data:`CROP`; a box reaching past the image is clamped to
    it (a window at the façade's edge keeps what there is)."""
    rgb = np.asarray(rgb)
    if rgb.ndim == 2:
        rgb = np.repeat(rgb[:, :, None], 3, axis=2)
    rgb = rgb[:, :, :3]
    if rgb.dtype != np.uint8:
        rgb = np.clip(
            np.asarray(rgb, dtype=np.float64) * (255.0 if rgb.max() <= 1.0 else 1.0), 0, 255
        )
        rgb = rgb.astype(np.uint8)
    height, width = rgb.shape[:2]
    image = Image.fromarray(rgb)
    rows, cols = CROP
    out = np.zeros((len(boxes), rows, cols, 3), dtype=np.float32)
    for k, (top, left, bottom, right) in enumerate(np.asarray(boxes, dtype=np.float64)):
        h = max(bottom - top, 1.0)
        w = max(right - left, 1.0)
        t = int(np.clip(np.floor(top - margin * h), 0, height - 1))
        b = int(np.clip(np.ceil(bottom + margin * h), t + 1, height))
        le = int(np.clip(np.floor(left - margin * w), 0, width - 1))
        r = int(np.clip(np.ceil(right + margin * w), le + 1, width))
        piece = image.crop((le, t, r, b)).resize((cols, rows), Image.Resampling.BILINEAR)
        out[k] = np.asarray(piece, dtype=np.float32) / 255.0
    return out


def _soften(x: np.ndarray) -> np.ndarray:
    """(k, rows, cols, 3) crops blurred by a [1, 2, 1] / 4 kernel down and across (edges
    repeated): a crisp render or a sharp photo then looks like the blurred, resampled crops the
    classifier was trained on (the paper's "simplify the input", at the crop's scale)."""
    p = np.pad(x, ((0, 0), (1, 1), (1, 1), (0, 0)), mode="edge")
    v = 0.25 * p[:, :-2] + 0.5 * p[:, 1:-1] + 0.25 * p[:, 2:]
    return np.asarray(0.25 * v[:, :, :-2] + 0.5 * v[:, :, 1:-1] + 0.25 * v[:, :, 2:])


def features(crop_batch: np.ndarray, aspect: np.ndarray) -> np.ndarray:
    """(k, F) float32 features of (k, rows, cols, 3) crops in [0, 1] and their boxes' aspect
    ratios (height / width)."""
    x = _soften(np.asarray(crop_batch, dtype=np.float32))
    k = len(x)
    rows, cols = CROP
    grey = x @ np.array([0.299, 0.587, 0.114], dtype=np.float32)
    # gradient-orientation histograms, soft-binned by magnitude, each cell normalised by the
    # crop's overall gradient energy (so a faint photo and a crisp render compare)
    gy = np.zeros_like(grey)
    gx = np.zeros_like(grey)
    gy[:, 1:-1] = grey[:, 2:] - grey[:, :-2]
    gx[:, :, 1:-1] = grey[:, :, 2:] - grey[:, :, :-2]
    mag = np.sqrt(gx * gx + gy * gy)
    ang = np.mod(np.arctan2(gy, gx), np.pi) / np.pi * BINS
    lo = np.floor(ang).astype(np.int64)
    frac = ang - lo
    lo %= BINS
    hi = (lo + 1) % BINS
    # summed straight into bands of 4 rows (one bincount: no (k, rows, cols, bins) array)
    band = (np.arange(k)[:, None, None] * (rows // 4) + np.arange(rows)[None, :, None] // 4) * cols
    where = (band + np.arange(cols)[None, None, :]) * BINS
    bands = np.bincount(
        np.concatenate([(where + lo).ravel(), (where + hi).ravel()]),
        weights=np.concatenate([(mag * (1 - frac)).ravel(), (mag * frac).ravel()]),
        minlength=k * rows // 4 * cols * BINS,
    ).reshape(k, rows // 4, cols, BINS)
    cells = bands.reshape(k, rows // CELL, CELL // 4, cols // CELL, CELL, BINS).sum(axis=(2, 4))
    cells = cells.reshape(k, -1)
    cells = np.sqrt(cells / (cells.sum(axis=1, keepdims=True) + 1e-3))
    # a finer view of the orientations along rows and columns: bars and slats
    rows_h = bands.sum(axis=2).reshape(k, -1)
    cols_h = bands.sum(axis=1).reshape(k, cols // 4, 4, BINS).sum(axis=2).reshape(k, -1)
    rows_h = np.sqrt(rows_h / (rows_h.sum(axis=1, keepdims=True) + 1e-3))
    cols_h = np.sqrt(cols_h / (cols_h.sum(axis=1, keepdims=True) + 1e-3))
    # a thumbnail, zero mean and unit contrast: where the dark glass lies
    tr, tc = THUMB
    thumb = grey.reshape(k, tr, rows // tr, tc, cols // tc).mean(axis=(2, 4)).reshape(k, -1)
    thumb = (thumb - thumb.mean(axis=1, keepdims=True)) / (thumb.std(axis=1, keepdims=True) + 0.03)
    # colour: chroma of the middle and of the sides against the whole crop's
    chroma = x - x.mean(axis=3, keepdims=True)
    mid = chroma[:, rows // 6 : -rows // 6, cols // 4 : -cols // 4].mean(axis=(1, 2))
    sides = np.concatenate([chroma[:, :, : cols // 5], chroma[:, :, -cols // 5 :]], axis=2)
    side = sides.mean(axis=(1, 2))
    whole = chroma.mean(axis=(1, 2))
    sat = np.abs(chroma).mean(axis=3)
    colour = np.concatenate(
        [
            (mid - whole) * 4,
            (side - whole) * 4,
            sat.mean(axis=(1, 2))[:, None] * 4,
            sat[:, :, : cols // 5].mean(axis=(1, 2))[:, None] * 4,
        ],
        axis=1,
    )
    shape = np.log(np.clip(np.asarray(aspect, dtype=np.float32), 0.1, 10.0))[:, None]
    return np.concatenate([cells, rows_h, cols_h, thumb, colour, shape], axis=1).astype(np.float32)


def box_features(rgb: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """Features of the crops of ``boxes`` in ``rgb``."""
    boxes = np.asarray(boxes, dtype=np.float64).reshape(-1, 4)
    aspect = (boxes[:, 2] - boxes[:, 0]) / np.maximum(boxes[:, 3] - boxes[:, 1], 1.0)
    return features(crops(rgb, boxes), aspect)


def predict_proba(feats: np.ndarray, net: dict[str, np.ndarray]) -> np.ndarray:
    """(k, rules) class probabilities of features under ``net`` (``mean``, ``std``, ``w1``,
    ``b1`` and, for the perceptron, ``w2``, ``b2``; without them ``w1`` is a linear model)."""
    z = (np.asarray(feats, dtype=np.float64) - net["mean"]) / net["std"]
    logits = z @ net["w1"] + net["b1"]
    if "w2" in net:
        logits = np.tanh(logits) @ net["w2"] + net["b2"]
    logits -= logits.max(axis=1, keepdims=True)
    p = np.exp(logits)
    return np.asarray(p / p.sum(axis=1, keepdims=True))


@lru_cache(maxsize=2)
def _load(path: str) -> tuple[dict[str, np.ndarray], tuple[str, ...]]:
    with np.load(path, allow_pickle=False) as data:
        net = {key: np.asarray(data[key], dtype=np.float64) for key in data.files if key != "rules"}
        rules = tuple(str(r) for r in data["rules"])
    return net, rules


def load_weights(
    path: str | Path = WEIGHTS,
) -> tuple[dict[str, np.ndarray], tuple[str, ...]]:
    """(net, rule names) from a weights file written by ``bench/train_windows.py`` (or
    ``bench/train_facade_style.py``: the same perceptron)."""
    return _load(str(path))


def classify(rgb: np.ndarray, boxes: np.ndarray, weights: str | Path = WEIGHTS) -> list[str]:
    """The window rule of each box, in order."""
    boxes = np.asarray(boxes, dtype=np.float64).reshape(-1, 4)
    if len(boxes) == 0:
        return []
    net, rules = load_weights(weights)
    proba = predict_proba(box_features(rgb, boxes), net)
    return [rules[i] for i in np.argmax(proba, axis=1)]


def window_style(
    rgb: np.ndarray, boxes: np.ndarray, weights: str | Path = WEIGHTS
) -> tuple[str, dict[str, int]]:
    """(rule, votes): the stdlib window rule (``"Plain"``, ``"Arched"``, ...) most of the boxes
    (top, left, bottom, right) of the rectified façade ``rgb`` are classified as, and each
    rule's count of boxes (rules with none left out).  A tie goes to the rule earlier in the
    classifier's order (plainer rules first), so the answer is deterministic; no boxes give
    :data:`DEFAULT_RULE` and no votes."""
    labels = classify(rgb, boxes, weights)
    if not labels:
        return DEFAULT_RULE, {}
    _, rules = load_weights(weights)
    votes: dict[str, int] = {}
    for label in labels:
        votes[label] = votes.get(label, 0) + 1
    best = max(votes, key=lambda r: (votes[r], -rules.index(r)))
    return best, {r: votes[r] for r in rules if r in votes}
