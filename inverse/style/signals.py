"""The signals that section 4.3.4 labels: one value per column (axis "x") or row (axis "y") of
a rectified face texture, high where a window is.  ``variance_signal`` is the paper's; the
others are documented deviations for textures where its assumption fails.

Pure numpy: no I/O; images are (h, w, 3) uint8 arrays, row 0 the top (inverse/style/model.py).
"""

from __future__ import annotations

import numpy as np

AXES = ("x", "y")


def _image(image: np.ndarray, axis: str) -> np.ndarray:
    """The texture as an (h, w, 3) uint8 array, checked; ``axis`` checked too."""
    if axis not in AXES:
        raise ValueError(f"axis must be 'x' or 'y', not {axis!r}")
    img = np.asarray(image)
    if img.ndim == 2:
        img = np.repeat(img[:, :, None], 3, axis=2)
    if img.ndim != 3 or img.shape[0] == 0 or img.shape[1] == 0 or img.shape[2] < 3:
        raise ValueError(f"a texture must be an (h, w, 3) image, not shape {np.shape(image)}")
    if img.dtype != np.uint8:
        raise ValueError(f"a texture must hold uint8 values, not {img.dtype}")
    return img[:, :, :3]


def _channel_sums(img: np.ndarray, axis: str) -> tuple[np.ndarray, np.ndarray, int]:
    """Per position along ``axis`` and per channel: the sum of the values and of their squares
    over the other axis, as (n, 3) float64, and how many values each sums.  Exact integer
    sums (uint32 while 255^2 times the count fits, uint64 beyond), each over a contiguous or
    evenly strided last axis, so a 2000 x 256 texture takes a few milliseconds."""
    h, w, _ = img.shape
    count = h if axis == "x" else w
    total = np.uint32 if count * 255**2 < 2**32 else np.uint64
    if axis == "x":
        wide = img.astype(np.uint16)  # 255^2 fits
        first = wide.sum(axis=0, dtype=total)
        second = (wide * wide).sum(axis=0, dtype=total)
    else:
        flat = img.reshape(h, w * 3).astype(np.uint16)  # a row's values, channel by channel
        squares = flat * flat
        first = np.stack([flat[:, c::3].sum(axis=1, dtype=total) for c in range(3)], axis=1)
        second = np.stack([squares[:, c::3].sum(axis=1, dtype=total) for c in range(3)], axis=1)
    return first.astype(np.float64), second.astype(np.float64), count


def unit_range(values: np.ndarray) -> np.ndarray:
    """Min-max normalisation to 0..1 (a constant signal becomes all 0): lambda = 0.025 is then
    2.5 % of the signal's own range on every texture, whatever its contrast or size."""
    lo, hi = float(values.min()), float(values.max())
    if hi - lo <= 1e-12:
        return np.zeros(values.shape, dtype=np.float64)
    return (values.astype(np.float64) - lo) / (hi - lo)


def colour_variance(image: np.ndarray, axis: str) -> np.ndarray:
    """The raw colour variance of each column (axis "x") or row (axis "y", top first): the sum
    over R, G, B of the variance of that channel's values, in 0..1 units (0 for one colour, at
    most 0.75).  ``variance_signal`` is this stretched to 0..1."""
    img = _image(image, axis)
    first, second, count = _channel_sums(img, axis)
    variance = second / count - (first / count) ** 2  # E[v^2] - E[v]^2, per channel
    return np.maximum(variance, 0.0).sum(axis=-1) / 255.0**2


def variance_signal(image: np.ndarray, axis: str) -> np.ndarray:
    """The discrete colour-variance signal var(i) of section 4.3.4 (Figure 9, top).

    Axis "x" gives one value per image column (for a horizontal splitting rule: widths along
    x), axis "y" one per row, top first (a vertical rule).  The colour variance of a column is
    the sum over R, G, B of the variance of that channel's values down the column, in 0..1
    units (``colour_variance``); a column that crosses both wall and window varies, a column of
    plain wall does not (the paper's key assumption).  The signal is then stretched to 0..1
    (``unit_range``) so the paper's lambda means the same on every texture."""
    return unit_range(colour_variance(image, axis))


def edge_signal(image: np.ndarray, axis: str) -> np.ndarray:
    """A homogeneity signal for curtain walls, where section 4.3.4's assumption is reversed:
    the glass is the plain part and the framing between bays the busy one.

    Deviation from the paper (it has only ``variance_signal``): on a texture such as Candler's
    window tiles, a bay of dark drawn blinds has a column variance as low as the mullions'
    (measured: 0.013 against 0.017-0.03), so no labelling of var(i) finds it.  Here the value
    of a column is the mean over rows of the colour step across it (sum over R, G, B of
    |I(r, i+1) - I(r, i)|, 0..1 units, each column the mean of its two sides), averaged over a
    box of 2 * round(n / 400) + 1 columns (11 on a 2000-pixel texture, about a mullion's
    width) so that a mullion's edges make one section, then turned over (1 - the unit-range
    value) so that label 1, the high cluster, is still the window.  Along y a window's blinds
    and transoms make horizontal edges, so this signal suits axis "x" only."""
    img = _image(image, axis)
    h, w, _ = img.shape
    flat = img.reshape(h, w * 3).astype(np.int16)
    if axis == "x":  # steps between neighbouring columns: 3 values apart in a flattened row
        steps = np.abs(flat[:, 3:] - flat[:, :-3]).sum(axis=0).reshape(w - 1, 3).sum(axis=1)
        steps = steps / (255.0 * h)
    else:
        steps = np.abs(flat[1:] - flat[:-1]).sum(axis=1) / (255.0 * w)
    if steps.size == 0:
        return np.zeros(w if axis == "x" else h, dtype=np.float64)
    per = np.r_[steps[0], (steps[:-1] + steps[1:]) / 2.0, steps[-1]]
    box = 2 * round(per.size / 400) + 1
    if box > 1:
        padded = np.pad(per, box // 2, mode="edge")
        per = np.convolve(padded, np.full(box, 1.0 / box), mode="valid")
    return 1.0 - unit_range(per)


SIGNALS = {"variance": variance_signal, "edges": edge_signal}
"""The signals ``detect_rule`` can label: "variance" is the paper's."""
