"""Window pixels of a rectified façade: per-pixel features and two small perceptrons over them.

The paper (section 5.2) detects windows per tile with two CNNs trained on CMP tiles.  bgr has no
deep-learning framework among its dependencies (the package stays small and CPU-only),
so the window evidence is a per-pixel classifier instead, in numpy, of two passes (auto-context,
Tu 2008: the second pass sees what the first one made of the pixel's neighbourhood, which is
what a CNN's receptive field gives it):

1. a one-hidden-layer perceptron over :data:`FEATURES` features that say what a window looks
   like at a few scales — its colour and darkness against the wall round it and against the
   façade as a whole, the edges of its frame, and how much its row and its column look like
   window rows and columns of this façade (section 5.2's projections V and H among them);
2. a second perceptron over those features and :data:`CONTEXT` more read off the first pass's
   probability map: smoothed, its row and column profiles, its value a few window sizes above,
   below and to each side, and one storey and one window pitch away (the pitches from the
   profiles' autocorrelation: windows repeat, and a pixel whose neighbours one pitch away are
   window is likely one too).

Trained by ``bench/train_facade.py`` on the CMP façades (five folds, measured in
docs/benchmarks.md), the second pass on the first pass's out-of-fold maps (so that it learns
how far the first pass is to be trusted on façades it has not seen); the weights are
:data:`WEIGHTS`.  The grid and the boxes of :mod:`.facade` are read off the second pass's map.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy import ndimage

WEIGHTS = Path(__file__).with_name("window_pixels.npz")
FEATURES = 23
CONTEXT = 19
SECOND = "ctx_"
"""Prefix of the second pass's weights in :data:`WEIGHTS` (the first pass's have none)."""


def features(rgb: np.ndarray) -> np.ndarray:
    """(h, w, FEATURES) float32 per-pixel features of an (h, w, 3) uint8 façade image."""
    lab = lab_image(rgb)
    lum, a, b = lab[..., 0] / 100.0, lab[..., 1] / 50.0, lab[..., 2] / 50.0
    h, w = lum.shape
    scale = max(h, w) / 100.0  # a façade's window is a few hundredths of it
    blur = ndimage.gaussian_filter
    gx = ndimage.sobel(lum, axis=1)
    gy = ndimage.sobel(lum, axis=0)
    energy = np.hypot(gx, gy)
    sat = np.hypot(a, b)
    dark = lum - blur(lum, 4 * scale)
    out = [lum, a, b]
    out += [lum - blur(lum, k * scale) for k in (1.5, 10)] + [dark]  # darker than the wall round
    out += [a - blur(a, 4 * scale), b - blur(b, 4 * scale), sat - blur(sat, 4 * scale)]
    out += [blur(energy, k * scale) for k in (0.5, 1.5, 4)]  # a frame's edges, and a window's
    out += [blur(np.abs(gx), scale), blur(np.abs(gy), scale)]  # vertical, horizontal edges
    spread = blur(lum**2, 1.5 * scale) - blur(lum, 1.5 * scale) ** 2
    out.append(np.sqrt(np.maximum(spread, 0)))  # texture: glazing bars, curtains
    out.append(_rows(_zscore(np.abs(gx).mean(axis=1)), w))  # section 5.2's V(y)
    out.append(_columns(_zscore(np.abs(gy).mean(axis=0)), h))  # H(x)
    out.append(_rows(_zscore(dark.mean(axis=1)), w))  # rows and columns of dark openings
    out.append(_columns(_zscore(dark.mean(axis=0)), h))
    out.append(_zscore(ndimage.uniform_filter1d(np.abs(gx), max(3, w // 4), axis=1)))  # V nearby
    out.append(_zscore(ndimage.uniform_filter1d(np.abs(gy), max(3, h // 4), axis=0)))  # H nearby
    out.append(_rows(np.linspace(0, 1, h), w))  # shops and doors keep to the ground floor
    out.append(_columns(np.abs(np.linspace(-1, 1, w)), h))  # and the façade's edges to the wall
    return np.stack(out, axis=-1).astype(np.float32)


def context(prob: np.ndarray) -> np.ndarray:
    """(h, w, CONTEXT) float32 features of the first pass's (h, w) probability map."""
    h, w = prob.shape
    scale = max(h, w) / 100.0
    smooth = ndimage.gaussian_filter(prob, scale)
    out = [prob, smooth, ndimage.gaussian_filter(prob, 3 * scale)]
    out += [_rows(prob.mean(axis=1), w), _columns(prob.mean(axis=0), h)]
    out.append(ndimage.uniform_filter1d(prob, max(3, w // 4), axis=1))
    out.append(ndimage.uniform_filter1d(prob, max(3, h // 4), axis=0))
    for k in (3, 8):  # a window's size or two away
        d = int(round(k * scale))
        out += [_shift(smooth, d, 0), _shift(smooth, -d, 0), _shift(smooth, 0, d)]
        out.append(_shift(smooth, 0, -d))
    storey = pitch(prob.mean(axis=1), max(3, h // 20), h // 2)
    bay = pitch(prob.mean(axis=0), max(3, w // 30), w // 2)
    for dy, dx in ((storey, 0), (0, bay)):  # one storey, one window pitch away
        before, after = _shift(smooth, dy, dx), _shift(smooth, -dy, -dx)
        out += [np.maximum(before, after), np.minimum(before, after)]
    return np.stack(out, axis=-1).astype(np.float32)


def pitch(profile: np.ndarray, shortest: int, longest: int) -> int:
    """The lag in [shortest, longest) at which ``profile`` best matches itself shifted (its
    autocorrelation's highest there): the pitch of a row of windows or of the storeys."""
    v = profile - profile.mean()
    corr = np.correlate(v, v, "full")[len(v) - 1 :]
    longest = min(longest, len(v) - 1)
    if longest <= shortest or corr[0] <= 0:
        return shortest
    return int(shortest + np.argmax(corr[shortest:longest]))


def window_probability(rgb: np.ndarray, weights: dict[str, np.ndarray] | None = None) -> np.ndarray:
    """(h, w) probability that each pixel of the façade is a window (or door or shop)."""
    net = weights if weights is not None else load_weights()
    x = features(rgb)
    prob = forward(net, x.reshape(-1, FEATURES)).reshape(rgb.shape[:2])
    if SECOND + "w1" not in net:  # one pass only
        return prob
    both = np.concatenate([x, context(prob)], axis=-1).reshape(-1, FEATURES + CONTEXT)
    return forward(net, both, SECOND).reshape(rgb.shape[:2])


def forward(net: dict[str, np.ndarray], x: np.ndarray, prefix: str = "") -> np.ndarray:
    """A perceptron (the weights named ``prefix`` + mean, std, w1, b1, w2, b2): standardised
    features, one tanh layer, a logistic output."""
    z = (x - net[prefix + "mean"]) / net[prefix + "std"]
    hidden = np.tanh(z @ net[prefix + "w1"] + net[prefix + "b1"])
    return 1.0 / (1.0 + np.exp(-(hidden @ net[prefix + "w2"] + net[prefix + "b2"])[:, 0]))


def load_weights() -> dict[str, np.ndarray]:
    with np.load(WEIGHTS) as data:
        return {k: data[k] for k in data.files}


def lab_image(rgb: np.ndarray) -> np.ndarray:
    """(h, w, 3) CIE L*a*b* (D65) of an sRGB uint8 image."""
    c = rgb[..., :3].astype(np.float64) / 255.0
    linear = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    xyz = linear @ RGB_TO_XYZ.T / WHITE
    f = np.where(xyz > (6 / 29) ** 3, np.cbrt(xyz), xyz / (3 * (6 / 29) ** 2) + 4 / 29)
    return np.stack(
        [116 * f[..., 1] - 16, 500 * (f[..., 0] - f[..., 1]), 200 * (f[..., 1] - f[..., 2])],
        axis=-1,
    )


def _zscore(v: np.ndarray) -> np.ndarray:
    return (v - v.mean()) / (v.std() + 1e-9)


def _rows(v: np.ndarray, width: int) -> np.ndarray:
    """A per-row value spread over the row's ``width`` pixels."""
    return np.broadcast_to(v[:, None], (len(v), width))


def _columns(v: np.ndarray, height: int) -> np.ndarray:
    return np.broadcast_to(v[None, :], (height, len(v)))


def _shift(a: np.ndarray, dy: int, dx: int) -> np.ndarray:
    """``a`` moved down ``dy`` and right ``dx`` pixels, its edge rows and columns repeated."""
    h, w = a.shape
    rows = np.clip(np.arange(h) - dy, 0, h - 1)
    cols = np.clip(np.arange(w) - dx, 0, w - 1)
    return a[rows][:, cols]


RGB_TO_XYZ = np.array(
    [[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]]
)
WHITE = np.array([0.95047, 1.0, 1.08883])
