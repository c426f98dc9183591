"""Rectification of a façade seen in a photograph (section 5.1 of "Procedural building from a
single image"), with numpy, scipy and Pillow only.

The camera / mass stage gives, for the largest visible façade of the fitted mass, the four
image corners of that façade and its size in metres.  This module

1. maps the quad to a fronto-parallel image by its homography (:func:`homography`, a
   normalised DLT, and :func:`warp`, bilinear sampling), at a resolution of about what the
   photograph offers and with a valid-pixel mask where the façade leaves the photograph
   (:func:`rectify_facade`);
2. corrects the quad first, because a mass fitted to a silhouette is often a few degrees off
   (the paper's figure 11): a small LSD-like detector (:func:`line_segments`, in
   :mod:`.segments`) finds the straight edges of windows and ledges, :func:`vanishing_point`
   finds where the façade's horizontal (vertical) ones meet by RANSAC and least squares on their
   angles, and :func:`refine_quad` turns the quad's edges to point at those vanishing points
   (:class:`RefinedQuad`).

No OpenCV and no GPL code: the detector is bgr's own.

Conventions.  Points are ``(x, y)`` pixels, x to the right and y down, the centre of pixel
``[row, col]`` at ``(col, row)``.  A quad's corners run top-left, top-right, bottom-right,
bottom-left of the façade as seen from outside (clockwise on screen).  Vanishing points are
homogeneous 3-vectors of unit norm (``w == 0``: at infinity), so parallel image lines are no
special case.  A homography ``H`` maps ``[x, y, 1]`` of its source to its destination.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from PIL import Image, ImageDraw
from scipy import ndimage, optimize

from .segments import line_segments as line_segments
from .segments import to_gray as to_gray

Array = np.ndarray


# --- homographies --------------------------------------------------------------------------


def _normaliser(points: Array) -> Array:
    """Hartley's conditioning: centroid to the origin, mean distance sqrt(2), so that the DLT's
    matrix does not mix pixel-sized and unit-sized entries."""
    centre = points.mean(axis=0)
    spread = np.sqrt(((points - centre) ** 2).sum(axis=1)).mean()
    s = np.sqrt(2.0) / spread if spread > 0 else 1.0
    return np.array([[s, 0, -s * centre[0]], [0, s, -s * centre[1]], [0, 0, 1.0]])


def homography(src: Array, dst: Array) -> Array:
    """(3, 3) ``H`` with ``dst ~ H @ [src, 1]``: the normalised DLT, least squares for n > 4.

    Raises ValueError for fewer than four finite pairs or a degenerate configuration (three of
    four points on a line: the solution is a singular matrix, no homography).
    """
    src = np.asarray(src, dtype=float)
    dst = np.asarray(dst, dtype=float)
    if src.ndim != 2 or src.shape[1] != 2 or src.shape != dst.shape or len(src) < 4:
        raise ValueError(
            f"homography needs two (n >= 4, 2) point arrays, got {src.shape} and {dst.shape}"
        )
    if not (np.isfinite(src).all() and np.isfinite(dst).all()):
        raise ValueError("homography points must be finite")
    ts, td = _normaliser(src), _normaliser(dst)
    s = src @ ts[:2, :2].T + ts[:2, 2]
    d = dst @ td[:2, :2].T + td[:2, 2]
    n = len(s)
    a = np.zeros((2 * n, 9))
    a[0::2, 0:2], a[0::2, 2] = s, 1
    a[0::2, 6:8], a[0::2, 8] = -d[:, :1] * s, -d[:, 0]
    a[1::2, 3:5], a[1::2, 5] = s, 1
    a[1::2, 6:8], a[1::2, 8] = -d[:, 1:] * s, -d[:, 1]
    _, sv, vt = np.linalg.svd(a)
    hn = vt[-1].reshape(3, 3)
    rank = np.linalg.svd(hn, compute_uv=False)
    if (n == 4 and sv[-2] < 1e-9 * sv[0]) or rank[-1] < 1e-8 * rank[0]:
        # three points on a line map to a singular matrix: no homography does what is asked
        raise ValueError("homography: degenerate points (three of them on one line?)")
    h = np.linalg.inv(td) @ hn @ ts
    return h / (h[2, 2] if abs(h[2, 2]) > 1e-12 else np.linalg.norm(h))


def _cross2(u: Array, v: Array) -> Array:
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def apply_homography(h: Array, points: Array) -> Array:
    """(n, 2) images of (n, 2) points under ``h`` (points mapped to infinity come back inf)."""
    p = np.asarray(points, dtype=float)
    q = p @ h[:, :2].T + h[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        return q[:, :2] / q[:, 2:]


def warp(
    rgb: Array, h_out_to_in: Array, size: tuple[int, int], fill: int = 0, engine: str = "pillow"
) -> tuple[Array, Array]:
    """Resample an (h, w, 3) (or (h, w)) uint8 image to ``size = (width, height)``.

    ``h_out_to_in`` maps an output pixel ``(x, y)`` to the input pixel it shows (the inverse
    direction leaves no holes).  Bilinear sampling, as ``map_coordinates`` order 1 per channel
    (``engine="scipy"``, the reference); the default ``"pillow"`` is the same interpolation in
    Pillow's C ``Image.transform`` (PERSPECTIVE, BILINEAR), three to four times faster on a
    512-row façade and within one grey level of the reference (tests check it): Pillow puts
    pixel centres at +0.5, hence the conjugation by half-pixel shifts.  Returns the image and
    a bool mask, True where the sample lies on the input (within half a pixel of its border)
    and on the same side of the horizon as the output's centre (``w`` of that sign: a point
    beyond the horizon is behind the camera); elsewhere the image holds ``fill``.
    """
    width, height = int(size[0]), int(size[1])
    if width < 1 or height < 1:
        raise ValueError(f"warp: output size must be positive, got {size}")
    if engine not in ("pillow", "scipy"):
        raise ValueError(f"warp: engine is 'pillow' or 'scipy', got {engine!r}")
    img = np.asarray(rgb)
    if img.dtype != np.uint8 or img.ndim not in (2, 3) or (img.ndim == 3 and img.shape[2] != 3):
        raise ValueError(
            f"warp: needs an (h, w, 3) or (h, w) uint8 image, got {img.dtype} {img.shape}"
        )
    h = np.asarray(h_out_to_in, dtype=float)
    # w is affine in (x, y): its sign at the corners says whether the horizon crosses the output
    corners = np.array(
        [[0, 0, 1], [width - 1, 0, 1], [0, height - 1, 1], [width - 1, height - 1, 1.0]]
    )
    w_centre = h[2] @ [0.5 * (width - 1), 0.5 * (height - 1), 1.0]
    sign = 1.0 if w_centre >= 0 else -1.0
    split = bool(((corners @ h[2]) * sign <= 0).any())
    shift = np.array([[1, 0, 0.5], [0, 1, 0.5], [0, 0, 1.0]])
    hc = shift @ h @ np.linalg.inv(shift)  # the same map with pixel centres at +0.5
    if engine == "pillow" and abs(hc[2, 2]) > 1e-9 * np.abs(hc).max():
        coeffs = tuple(float(c) for c in (hc / hc[2, 2]).ravel()[:8])
        src = Image.fromarray(img)
        persp, bil = Image.Transform.PERSPECTIVE, Image.Resampling.BILINEAR
        ink = fill if img.ndim == 2 else (fill, fill, fill)
        out = np.array(src.transform((width, height), persp, coeffs, bil, fillcolor=ink))
        ones = Image.new("L", src.size, 255)
        near = Image.Resampling.NEAREST
        valid = np.asarray(ones.transform((width, height), persp, coeffs, near, fillcolor=0)) > 0
        if split:
            ys, xs = np.mgrid[0:height, 0:width]
            valid &= (h[2, 0] * xs + h[2, 1] * ys + h[2, 2]) * sign > 0
            out[~valid] = fill
        return out, valid
    ys, xs = np.mgrid[0:height, 0:width].astype(float)
    q = h[:, 0, None, None] * xs + h[:, 1, None, None] * ys + h[:, 2, None, None]
    w = q[2] * sign
    with np.errstate(divide="ignore", invalid="ignore"):
        u, v = q[0] / q[2], q[1] / q[2]
    rows, cols = img.shape[:2]
    valid = (w > 0) & (u >= -0.5) & (u < cols - 0.5) & (v >= -0.5) & (v < rows - 0.5)
    coords = np.stack([np.where(valid, v, -1.0), np.where(valid, u, -1.0)])
    chans = img[..., None] if img.ndim == 2 else img
    res = np.empty((height, width, chans.shape[2]), dtype=np.uint8)
    for c in range(chans.shape[2]):
        band = ndimage.map_coordinates(
            chans[..., c].astype(np.float32), coords, order=1, mode="nearest"
        )
        res[..., c] = np.where(valid, np.clip(np.rint(band), 0, 255), fill)
    return (res[..., 0] if img.ndim == 2 else res), valid


# --- quads and rectification ---------------------------------------------------------------


def check_quad(quad: Array) -> Array:
    """The quad as a (4, 2) float array, or ValueError saying what is wrong with it: not four
    finite points, corners (nearly) coinciding or collinear, self-crossing, not convex, or
    corners not in the order top-left, top-right, bottom-right, bottom-left."""
    q = np.asarray(quad, dtype=float)
    if q.shape != (4, 2):
        raise ValueError(f"façade quad must be 4 corners (x, y), got shape {q.shape}")
    if not np.isfinite(q).all():
        raise ValueError("façade quad has a corner that is not a finite number")
    size = float(np.ptp(q, axis=0).max())
    if size < 2.0:
        raise ValueError("façade quad is smaller than two pixels")
    edges = np.roll(q, -1, axis=0) - q
    turns = _cross2(edges, np.roll(edges, -1, axis=0))  # at corners 1, 2, 3, 0
    if (np.abs(turns) < 1e-3 * size * size).any():
        raise ValueError("façade quad is degenerate: three corners on a line (or two coincide)")
    d1, d2 = q[2] - q[0], q[3] - q[1]
    denom = _cross2(d1, d2)  # the diagonals of a proper quad cross inside both
    t = _cross2(q[1] - q[0], d2) / denom if denom else -1.0
    s = _cross2(q[1] - q[0], d1) / denom if denom else -1.0
    if not (0 < t < 1 and 0 < s < 1):
        raise ValueError(
            "façade quad crosses itself or is not convex: corners must run top-left, "
            "top-right, bottom-right, bottom-left"
        )
    if (turns < 0).any():
        raise ValueError(
            "façade quad runs anticlockwise: corners must be top-left, top-right, "
            "bottom-right, bottom-left (the façade seen from outside)"
        )
    return q


@dataclass(frozen=True)
class Rectified:
    """A façade made fronto-parallel.  ``image`` (h, w, 3) uint8, ``valid`` (h, w) bool (False:
    the façade left the photograph there, the pixel holds 0), ``H`` maps a rectified pixel
    ``(x, y)`` to the photograph's, ``pixels_per_metre`` the same along x and y: the façade's
    top-left corner is at (-0.5, -0.5), its bottom-right at (width_m, height_m) * scale - 0.5."""

    image: Array
    valid: Array
    H: Array
    pixels_per_metre: float

    def to_photo(self, points: Array) -> Array:
        """(n, 2) photograph pixels of (n, 2) rectified pixels."""
        return apply_homography(self.H, points)


def rectify_facade(
    rgb: Array,
    quad: Array,
    metres: tuple[float, float],
    pixels_per_metre: float | None = None,
    max_height: int = 512,
    max_width: int = 4096,
) -> Rectified:
    """The façade inside ``quad`` (top-left, top-right, bottom-right, bottom-left) of the photo
    ``rgb``, ``metres = (width_m, height_m)`` wide and high, warped to a rectangle.

    The scale is the same along both axes, so the output's aspect ratio is the façade's.  By
    default it is the finest the photograph offers along the quad's sides (the largest of each
    side's length in pixels over its length in metres: nothing is lost on the near side, the
    far side is interpolated), then capped so the image is at most ``max_height`` rows and
    ``max_width`` columns.
    Raises ValueError for a degenerate quad or sizes that are not positive.
    """
    q = check_quad(quad)
    width_m, height_m = (float(m) for m in metres)
    if not (np.isfinite(width_m) and np.isfinite(height_m) and width_m > 0 and height_m > 0):
        raise ValueError(f"façade size must be two positive numbers of metres, got {metres}")
    if pixels_per_metre is None:
        sides = np.linalg.norm(np.roll(q, -1, axis=0) - q, axis=1)  # top, right, bottom, left
        ppm = max(sides[0] / width_m, sides[2] / width_m, sides[1] / height_m, sides[3] / height_m)
    else:
        ppm = float(pixels_per_metre)
        if not (np.isfinite(ppm) and ppm > 0):
            raise ValueError(f"pixels_per_metre must be positive, got {pixels_per_metre}")
    ppm = min(ppm, max_height / height_m, max_width / width_m)
    wx, hy = width_m * ppm, height_m * ppm
    size = (max(1, int(round(wx))), max(1, int(round(hy))))
    rect = np.array([[-0.5, -0.5], [wx - 0.5, -0.5], [wx - 0.5, hy - 0.5], [-0.5, hy - 0.5]])
    h = homography(rect, q)
    image, valid = warp(rgb, h, size)
    if image.ndim == 2:
        image = np.repeat(image[..., None], 3, axis=2)
    return Rectified(image=image, valid=valid, H=h, pixels_per_metre=ppm)


# --- vanishing points ----------------------------------------------------------------------


@dataclass(frozen=True)
class VanishingPoint:
    """Where a family of image lines meets.  ``point`` is homogeneous ``(x, y, w)`` of unit norm
    in pixels (``w == 0``: the lines are parallel in the image); ``inliers`` marks the segments
    (of those given) that pass through it within ``inlier_deg``; ``error_deg`` is their
    length-weighted RMS angle to it."""

    point: Array
    inliers: Array
    error_deg: float

    @property
    def support(self) -> int:
        return int(self.inliers.sum())


def _homogeneous(p: Array) -> Array:
    p = np.asarray(p, dtype=float).ravel()
    if p.shape == (2,):
        p = np.array([p[0], p[1], 1.0])
    if p.shape != (3,) or not np.isfinite(p).all() or not np.linalg.norm(p) > 0:
        raise ValueError(f"a vanishing point guess is (x, y) or homogeneous (x, y, w), got {p}")
    return p / np.linalg.norm(p)


def _angle_errors(v: Array, mids: Array, dirs: Array) -> Array:
    """(k, n) sine of the angle between each segment (midpoint, unit direction) and the line
    from its midpoint to each of k homogeneous points ``v`` (k, 3); 1 where the point is the
    midpoint itself.  Homogeneous, so a point at infinity needs no special case."""
    u = v[:, None, :2] - v[:, None, 2:] * mids[None]
    norm = np.linalg.norm(u, axis=2)
    cross = np.abs(dirs[None, :, 0] * u[..., 1] - dirs[None, :, 1] * u[..., 0])
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(norm > 1e-12, cross / norm, 1.0)


def vanishing_point(
    segments: Array,
    guess: Array,
    tolerance_deg: float = 8.0,
    inlier_deg: float = 1.0,
    min_support: int = 5,
    hypotheses: int = 300,
    seed: int = 0,
) -> VanishingPoint | None:
    """The vanishing point of the segments (n, 4) that point within ``tolerance_deg`` of the
    homogeneous (or (x, y)) ``guess``, or None when fewer than ``min_support`` agree on one.

    RANSAC over pairs of those segments (each pair's lines meet in a hypothesis, the guess is
    one more), scored by the total length of the segments within ``inlier_deg`` of it: the
    façade's windows and ledges outvote the odd tree branch.  The best is then polished by least
    squares of the inliers' angles (``scipy.optimize.least_squares`` on a local chart of the
    sphere of homogeneous points, so it may converge to or through infinity), each weighted by
    its length cubed: the angle of a line fitted to L pixels has a variance of about 1 / L^3
    (on the test photos that halves the error of the length-weighted fit).
    Coordinates are centred and scaled first, which keeps the homogeneous products well
    conditioned; angles are unchanged by that.
    """
    segs = np.asarray(segments, dtype=float).reshape(-1, 4)
    g = _homogeneous(guess)
    if len(segs) < min_support:
        return None
    p1, p2 = segs[:, :2], segs[:, 2:]
    centre = 0.5 * (p1 + p2).mean(axis=0)
    scale = max(float(np.abs(np.concatenate([p1, p2]) - centre).max()), 1.0)
    t = np.array([[1, 0, -centre[0]], [0, 1, -centre[1]], [0, 0, scale]]) / scale
    a, b = (p1 - centre) / scale, (p2 - centre) / scale
    mids, length = 0.5 * (a + b), np.linalg.norm(b - a, axis=1)
    dirs = (b - a) / np.maximum(length, 1e-12)[:, None]
    gn = t @ g
    gn /= np.linalg.norm(gn)
    near = _angle_errors(gn[None], mids, dirs)[0] <= np.sin(np.radians(tolerance_deg))
    cand = np.nonzero(near)[0]
    if len(cand) < min_support:
        return None
    lines = np.cross(np.c_[a[cand], np.ones(len(cand))], np.c_[b[cand], np.ones(len(cand))])
    rng = np.random.default_rng(seed)
    if len(cand) * (len(cand) - 1) // 2 <= hypotheses:  # few: every pair
        pairs = np.stack(np.triu_indices(len(cand), 1), axis=1)
    else:  # long segments are likelier façade lines: drawn more often
        p = length[cand] / length[cand].sum()
        pairs = np.sort(rng.choice(len(cand), size=(hypotheses, 2), p=p), axis=1)
        pairs = pairs[pairs[:, 0] != pairs[:, 1]]
    hyp = np.cross(lines[pairs[:, 0]], lines[pairs[:, 1]]) if len(pairs) else np.zeros((0, 3))
    norms = np.linalg.norm(hyp, axis=1)
    hyp = np.vstack([gn, hyp[norms > 1e-12] / norms[norms > 1e-12, None]])
    sin_in = np.sin(np.radians(inlier_deg))
    err = _angle_errors(hyp, mids[cand], dirs[cand])
    score = ((err <= sin_in) * length[cand]).sum(axis=1)
    best = hyp[int(np.argmax(score))]
    inl = cand[err[int(np.argmax(score))] <= sin_in]
    for _ in range(2):  # polish on the inliers, take the inliers again, polish again
        if len(inl) < 2:
            break
        best = _polish(best, mids[inl], dirs[inl], length[inl] ** 3)
        inl = cand[_angle_errors(best[None], mids[cand], dirs[cand])[0] <= sin_in]
    if len(inl) < min_support:
        return None
    e = np.arcsin(np.clip(_angle_errors(best[None], mids[inl], dirs[inl])[0], 0, 1))
    rms = float(np.degrees(np.sqrt((length[inl] * e**2).sum() / length[inl].sum())))
    point = np.linalg.solve(t, best)
    point /= np.linalg.norm(point)
    if point[2] < 0 or (point[2] == 0 and point[0] < 0):  # one sign for one point
        point = -point
    mask = np.zeros(len(segs), dtype=bool)
    mask[inl] = True
    return VanishingPoint(point=point, inliers=mask, error_deg=rms)


def _polish(v: Array, mids: Array, dirs: Array, weight: Array) -> Array:
    """Least-squares homogeneous point minimising the weighted sines of the segments' angles to
    it, moved in the tangent plane of the unit sphere at ``v``."""
    basis = np.linalg.svd(v[None])[2][1:]  # two unit vectors orthogonal to v
    sw = np.sqrt(weight)

    def point(c: Array) -> Array:
        p = v + c @ basis
        return np.asarray(p / np.linalg.norm(p))

    def residual(c: Array) -> Array:
        p = point(c)
        u = p[:2] - p[2] * mids
        n = np.maximum(np.linalg.norm(u, axis=1), 1e-12)
        return np.asarray(sw * (dirs[:, 0] * u[:, 1] - dirs[:, 1] * u[:, 0]) / n)

    res = optimize.least_squares(residual, np.zeros(2), method="lm" if len(mids) >= 2 else "trf")
    return point(res.x)


# --- the quad refined ----------------------------------------------------------------------


@dataclass(frozen=True)
class RefinedQuad:
    """The quad after :func:`refine_quad` (the given one where a vanishing point was missing),
    the two vanishing points found (None: too little support), the segments they were sought
    among (n, 4), and a sentence saying what was done, for logs and user messages."""

    quad: Array
    horizontal: VanishingPoint | None
    vertical: VanishingPoint | None
    segments: Array
    note: str

    @property
    def refined(self) -> bool:
        return self.horizontal is not None or self.vertical is not None


def _line(p: Array, q: Array) -> Array:
    return np.cross(np.r_[p, 1.0], np.r_[q, 1.0])


def _meet(l1: Array, l2: Array) -> Array:
    p = np.cross(l1, l2)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.asarray(p[:2] / p[2])


def facade_segments(
    gray: Array, quad: Array, margin: float = 0.1, detect_size: int = 1000
) -> Array:
    """Segments (n, 4) of the photo (grey or RGB) made of pixels inside the quad grown by
    ``margin`` about its centre (the trees and street round a façade only add outliers and
    time); the crop round it is shrunk to at most ``detect_size`` pixels a side (a phone
    photo's 4000 pixels would take seconds and add nothing to a vanishing point)."""
    q = check_quad(quad)
    img = np.asarray(gray, dtype=np.float32)
    if img.ndim == 3:
        img = to_gray(img)
    centre = q.mean(axis=0)
    grown = centre + (q - centre) * (1 + margin)
    rows, cols = img.shape
    x0, y0 = (max(0, int(np.floor(v))) for v in grown.min(axis=0))
    x1, y1 = (
        min(cols, int(np.ceil(grown[:, 0].max())) + 1),
        min(rows, int(np.ceil(grown[:, 1].max())) + 1),
    )
    if x1 - x0 < 8 or y1 - y0 < 8:
        return np.zeros((0, 4))
    crop = img[y0:y1, x0:x1]
    f = min(1.0, detect_size / max(crop.shape))
    if f < 1.0:
        size = (max(8, round(crop.shape[1] * f)), max(8, round(crop.shape[0] * f)))
        small = Image.fromarray(np.ascontiguousarray(crop)).resize(size, Image.Resampling.BILINEAR)
        crop = np.asarray(small)
    sx, sy = (x1 - x0) / crop.shape[1], (y1 - y0) / crop.shape[0]
    # the grown quad in the (shrunk) crop's pixels: full-size x is (x_small + 0.5) * sx - 0.5
    poly = (grown - [x0, y0] + 0.5) / [sx, sy] - 0.5
    inside = Image.new("1", (crop.shape[1], crop.shape[0]), 0)
    ImageDraw.Draw(inside).polygon([(float(x), float(y)) for x, y in poly], fill=1)
    segs = line_segments(
        crop, min_length=max(10.0, 0.02 * max(crop.shape)), mask=np.asarray(inside)
    )
    segs = (segs + 0.5) * np.array([sx, sy, sx, sy]) - 0.5
    return np.asarray(segs + np.array([x0, y0, x0, y0], dtype=float))


def refine_quad(
    gray: Array,
    quad: Array,
    min_support: int = 5,
    tolerance_deg: float = 8.0,
    max_shift: float = 0.15,
    detect_size: int = 1000,
) -> RefinedQuad:
    """The quad with its top and bottom edges turned to pass through the horizontal vanishing
    point of the façade's segments and its left and right edges through the vertical one.

    Each edge turns about its midpoint, so the quad keeps its centre and extent: the vanishing
    points fix the edges' directions (what a mass fitted to a silhouette gets wrong by a few
    degrees), not where the façade ends (which the segments cannot tell from a window's edge).
    The guesses are where the quad's own opposite edges meet (homogeneous: parallel edges meet
    at infinity).  A direction with fewer than ``min_support`` agreeing segments keeps the
    given edges; so does a result that is no proper quad or moves a corner by more than
    ``max_shift`` of the quad's size.  ``note`` says which.  Raises ValueError only for a
    degenerate ``quad`` (see :func:`check_quad`).
    """
    q = check_quad(quad)
    segs = facade_segments(gray, q, detect_size=detect_size)
    ends = {"top": (0, 1), "right": (1, 2), "bottom": (3, 2), "left": (0, 3)}
    edges = {e: _line(q[i], q[j]) for e, (i, j) in ends.items()}
    found: dict[str, VanishingPoint | None] = {}
    notes = []
    for name, (e1, e2) in (("horizontal", ("top", "bottom")), ("vertical", ("left", "right"))):
        guess = np.cross(edges[e1], edges[e2])  # homogeneous: parallel edges meet at infinity
        vp = found[name] = vanishing_point(segs, guess, tolerance_deg, min_support=min_support)
        if vp is None:
            few = f"too few segments (under {min_support}) agree on a vanishing point"
            notes.append(f"{name} edges kept: {few}")
            continue
        for e in (e1, e2):  # the edge through its midpoint and the vanishing point
            i, j = ends[e]
            edges[e] = np.cross(np.r_[0.5 * (q[i] + q[j]), 1.0], vp.point)
        fit = f"{vp.support} segments (RMS {vp.error_deg:.2f} deg)"
        notes.append(f"{name} edges through the vanishing point of {fit}")
    corners = (("top", "left"), ("top", "right"), ("bottom", "right"), ("bottom", "left"))
    new = np.array([_meet(edges[a], edges[b]) for a, b in corners])
    size = float(np.ptp(q, axis=0).max())
    try:
        new = check_quad(new)
        if np.linalg.norm(new - q, axis=1).max() > max_shift * size:
            raise ValueError(f"a corner would move more than {max_shift:.0%} of the quad's size")
    except ValueError as err:
        return RefinedQuad(
            q, None, None, segs, f"quad kept: the vanishing points give no usable quad ({err})"
        )
    return RefinedQuad(new, found["horizontal"], found["vertical"], segs, "; ".join(notes))
