"""Straight line segments of a photograph: a small detector after LSD, with numpy and scipy.

:func:`line_segments` finds the straight edges of windows and ledges from which
:mod:`.rectify` finds a façade's vanishing points; :func:`to_gray` is the luma it reads.  It is
written here rather than taken from OpenCV's LSD so that bgr needs no OpenCV and no GPL code.
Points are ``(x, y)`` pixels, x to the right and y down, as in :mod:`.rectify`.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage, sparse
from scipy.sparse import csgraph

Array = np.ndarray


def to_gray(rgb: Array) -> Array:
    """(h, w) float32 luma (Rec. 601) of an (h, w, 3) image; a 2-D image is returned as float."""
    a = np.asarray(rgb, dtype=np.float32)
    return a if a.ndim == 2 else a[..., :3] @ np.array([0.299, 0.587, 0.114], dtype=np.float32)


def line_segments(
    gray: Array,
    min_length: float = 15.0,
    min_gradient: float = 5.2,
    bins: int = 32,
    max_width: float = 4.0,
    aspect: float = 0.08,
    mask: Array | None = None,
) -> Array:
    """(n, 4) segments ``x1, y1, x2, y2`` of a grey image (0-255), longest first.

    A small detector after LSD (von Gioi et al.): the image is smoothed a little (sigma 0.8)
    and its gradient taken by Sobel; pixels with a gradient of at least ``min_gradient`` grey
    levels a pixel (LSD's 5.2; ``mask``: only where True) are grouped into 8-connected regions
    of like level-line direction.  Directions keep their polarity (360 degrees), so the two
    edges of a dark band are two lines, not one wide blur.  ``bins`` (even) windows two bins
    wide make two staggered partitions of the circle: each pixel is in one window of each, and
    a region is kept only by the window whose central half holds its mean direction, so a line
    is found once, whatever its angle (``ndimage.label`` on quantised bins splits lines that
    lie on a bin's border).  Each region gets its line by PCA of its pixels (gradient-
    weighted) and is kept when at least ``min_length`` long, at most ``max_width`` wide (or
    ``aspect`` of its length: a soft shadow edge is wide) and with its axis along its pixels'
    level lines (blobs and corners fail that).  Unlike LSD there is no a-contrario test: the
    thresholds stand in for it.  The regions come from ``csgraph.connected_components`` on
    the strong pixels alone: one pass per partition, not one ``ndimage.label`` per bin.
    """
    g = ndimage.gaussian_filter(np.asarray(gray, dtype=np.float32), 0.8)
    gx = ndimage.sobel(g, axis=1) / 8.0
    gy = ndimage.sobel(g, axis=0) / 8.0
    mag = np.hypot(gx, gy)
    strong = mag >= min_gradient
    if mask is not None:
        strong &= np.asarray(mask, dtype=bool)
    ys, xs = np.nonzero(strong)
    if len(ys) == 0:
        return np.zeros((0, 4))
    # level-line direction in [0, 360): along the edge, the brighter side on its left
    theta = np.degrees(np.arctan2(gx[ys, xs], -gy[ys, xs])) % 360.0
    w = mag[ys, xs]
    step = 360.0 / bins
    out: list[Array] = []
    for shift in (0.0, step):  # the two staggered partitions into windows two half-bins wide
        k = np.floor((theta - shift + step) / (2 * step)).astype(np.int64) % (bins // 2)
        centre = shift + 2 * step * k
        n, lab = _regions(ys, xs, k, strong.shape)
        count = np.bincount(lab, minlength=n)
        keep = count[lab] >= 0.8 * min_length
        seg = _fit_regions(xs[keep], ys[keep], lab[keep], w[keep], theta[keep], centre[keep], n)
        thin = seg[:, 5] <= np.maximum(max_width, aspect * seg[:, 4])
        good = (seg[:, 4] >= min_length) & thin & (np.abs(seg[:, 6]) <= step / 2)
        out.append(seg[good, :4])
    segs = np.concatenate(out)
    length = np.hypot(segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1])
    return np.asarray(segs[np.argsort(-length)])


def _regions(ys: Array, xs: Array, k: Array, shape: tuple[int, int]) -> tuple[int, Array]:
    """8-connected components of the pixels ``ys, xs`` (raster order) joining only neighbours
    in the same orientation window ``k``.

    The graph goes to ``csgraph`` as a CSR matrix built directly, four forward neighbours a
    pixel (itself where the neighbour is not joined): no COO sorting, the slow part."""
    rows, cols = shape
    n = len(ys)
    stride = cols + 2  # a column of -1 either side and a row below: no bounds checks
    pad = np.full((rows + 1) * stride, -1, dtype=np.int8)
    at = ys * stride + xs + 1
    pad[at] = own = k.astype(np.int8)
    node = np.zeros((rows + 1) * stride, dtype=np.int32)
    node[at] = me = np.arange(n, dtype=np.int32)
    nbr = np.empty((n, 4), dtype=np.int32)
    for d, step in enumerate((1, stride, stride + 1, stride - 1)):
        nbr[:, d] = np.where(pad[at + step] == own, node[at + step], me)
    graph = sparse.csr_matrix(
        (np.ones(4 * n, dtype=np.int8), nbr.ravel(), np.arange(0, 4 * n + 1, 4)), shape=(n, n)
    )
    count, labels = csgraph.connected_components(graph, directed=False)
    return int(count), np.asarray(labels)


def _fit_regions(
    xs: Array, ys: Array, lab: Array, w: Array, theta: Array, centre: Array, n: int
) -> Array:
    """Per region present in ``lab``: x1, y1, x2, y2, length, width, mean orientation (of
    ``theta``, degrees) less its window's ``centre``; a region whose PCA axis disagrees with
    its level lines by more than 10 degrees gets an offset of 90, so the caller drops it.

    The axis is fitted twice, the second time without the pixels of the region's last tenth
    at either end: at a window's corner the gradient turns, and the corner's pixels that still
    fall in the orientation window would pull the axis round by a few tenths of a degree."""
    m = np.unique(lab)
    xs, ys = xs.astype(float), ys.astype(float)
    cx, cy, c, s, _ = _pca(xs, ys, w, lab, n)
    t = (xs - cx[lab]) * c[lab] + (ys - cy[lab]) * s[lab]
    tmin, tmax = _extent(t, lab, n)
    lo, hi = (0.9 * tmin[lab] + 0.1 * tmax[lab]), (0.1 * tmin[lab] + 0.9 * tmax[lab])
    inner = (t >= lo) & (t <= hi)
    cx2, cy2, c2, s2, minor = _pca(xs[inner], ys[inner], w[inner], lab[inner], n)
    ok = np.bincount(lab[inner], minlength=n) >= 3
    cx, cy, c, s = (np.where(ok, new, old) for new, old in ((cx2, cx), (cy2, cy), (c2, c), (s2, s)))
    t = (xs - cx[lab]) * c[lab] + (ys - cy[lab]) * s[lab]
    tmin, tmax = _extent(t, lab, n)
    ang = np.radians(theta)
    sin, cos = np.bincount(lab, w * np.sin(ang), n), np.bincount(lab, w * np.cos(ang), n)
    mean = np.degrees(np.arctan2(sin, cos))
    window = np.zeros(n)
    window[lab] = centre  # one window per region
    mean_off = (mean - window + 180.0) % 360.0 - 180.0
    # the level-line angle atan2(gx, -gy) of an edge is its axis angle atan2(dy, dx) mod 180
    disagree = np.abs((np.degrees(np.arctan2(s, c)) - mean + 90.0) % 180.0 - 90.0)
    seg = np.empty((len(m), 7))
    seg[:, 0] = cx[m] + tmin[m] * c[m]
    seg[:, 1] = cy[m] + tmin[m] * s[m]
    seg[:, 2] = cx[m] + tmax[m] * c[m]
    seg[:, 3] = cy[m] + tmax[m] * s[m]
    seg[:, 4] = tmax[m] - tmin[m] + 1.0
    seg[:, 5] = np.sqrt(12.0 * minor[m])  # the width of a uniform band with that variance
    seg[:, 6] = np.where(disagree[m] <= 10.0, mean_off[m], 90.0)
    return seg


def _pca(xs: Array, ys: Array, w: Array, lab: Array, n: int) -> tuple[Array, ...]:
    """Weighted centroid, principal axis (cos, sin; y down) and minor variance per label."""
    sw = np.maximum(np.bincount(lab, w, n), 1e-12)
    cx = np.bincount(lab, w * xs, n) / sw
    cy = np.bincount(lab, w * ys, n) / sw
    dx, dy = xs - cx[lab], ys - cy[lab]
    sxx = np.bincount(lab, w * dx * dx, n) / sw
    syy = np.bincount(lab, w * dy * dy, n) / sw
    sxy = np.bincount(lab, w * dx * dy, n) / sw
    phi = 0.5 * np.arctan2(2 * sxy, sxx - syy)
    minor = np.maximum(0.5 * (sxx + syy) - np.sqrt(0.25 * (sxx - syy) ** 2 + sxy**2), 0.0)
    return cx, cy, np.cos(phi), np.sin(phi), minor


def _extent(t: Array, lab: Array, n: int) -> tuple[Array, Array]:
    """Least and greatest ``t`` per label."""
    tmin = np.full(n, np.inf)
    tmax = np.full(n, -np.inf)
    np.minimum.at(tmin, lab, t)
    np.maximum.at(tmax, lab, t)
    return tmin, tmax
