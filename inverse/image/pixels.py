"""Window pixels of a rectified façade: per-pixel features and a small perceptron over them.

The paper (section 5.2) detects windows per tile with two CNNs trained on CMP tiles.  bgr has no
deep-learning framework among its dependencies (issue 28: the package stays small and CPU-only),
so the window evidence is a per-pixel classifier instead: a one-hidden-layer perceptron of a few
hundred weights, in numpy, over features that say what a window looks like at three scales —
its colour and darkness against the wall round it, the edges of its frame, and how much its
row and its column look like window rows and columns of this façade.  Trained by
``bench/train_facade.py`` on the CMP façades (five folds, measured in docs/benchmarks.md); its
weights are :data:`WEIGHTS`.  The grid and the boxes of :mod:`.facade` are read off its map.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy import ndimage

WEIGHTS = Path(__file__).with_name("window_pixels.npz")
FEATURES = 12


def features(rgb: np.ndarray) -> np.ndarray:
    """(h, w, FEATURES) float32 per-pixel features of an (h, w, 3) uint8 façade image."""
    lab = lab_image(rgb)
    lum = lab[..., 0] / 100.0
    gx = ndimage.sobel(lum, axis=1)
    gy = ndimage.sobel(lum, axis=0)
    energy = np.hypot(gx, gy)
    h, w = lum.shape
    scale = max(h, w) / 100.0  # a façade's window is a few hundredths of it
    out = [
        lum,
        lab[..., 1] / 50.0,
        lab[..., 2] / 50.0,
        lum - ndimage.gaussian_filter(lum, 4 * scale),  # darker than the wall round it
        lum - ndimage.gaussian_filter(lum, 1.5 * scale),
        ndimage.gaussian_filter(energy, 0.5 * scale),
        ndimage.gaussian_filter(energy, 1.5 * scale),
        ndimage.gaussian_filter(np.abs(gx), 1.0 * scale),  # vertical frame edges
        ndimage.gaussian_filter(np.abs(gy), 1.0 * scale),  # horizontal frame edges
    ]
    rows = _zscore(np.abs(gx).mean(axis=1))  # section 5.2's V(y): a window row's edges
    cols = _zscore(np.abs(gy).mean(axis=0))  # H(x)
    out.append(np.broadcast_to(rows[:, None], (h, w)))
    out.append(np.broadcast_to(cols[None, :], (h, w)))
    ys = np.broadcast_to(np.linspace(0, 1, h)[:, None], (h, w))
    out.append(ys)  # shops and doors keep to the ground floor
    return np.stack(out, axis=-1).astype(np.float32)


def window_probability(rgb: np.ndarray, weights: dict[str, np.ndarray] | None = None) -> np.ndarray:
    """(h, w) probability that each pixel of the façade is a window (or door or shop)."""
    net = weights if weights is not None else load_weights()
    x = features(rgb).reshape(-1, FEATURES)
    return forward(net, x).reshape(rgb.shape[:2])


def forward(net: dict[str, np.ndarray], x: np.ndarray) -> np.ndarray:
    """The perceptron: standardised features, one tanh layer, a logistic output."""
    z = (x - net["mean"]) / net["std"]
    hidden = np.tanh(z @ net["w1"] + net["b1"])
    return 1.0 / (1.0 + np.exp(-(hidden @ net["w2"] + net["b2"])[:, 0]))


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


RGB_TO_XYZ = np.array(
    [[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]]
)
WHITE = np.array([0.95047, 1.0, 1.08883])
