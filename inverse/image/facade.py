"""A rectified façade photograph parsed into floors, window columns and windows (section 5 of
"Procedural building from a single image"), with numpy and scipy only.

The paper's stages, and what stands in for its CNNs here (each a documented deviation,
measured on the CMP façades by ``bench/facade_cmp.py`` and ``bench/train_facade.py``):

1. **Window evidence.**  The paper's window existence and window box CNNs run on each tile of a
   grid its floor / column CNN proposes.  Here two small per-pixel perceptrons
   (:mod:`.pixels`, trained on CMP; the second sees the first's map round the pixel) give each
   pixel's window probability, the gradient projections of section 5.2
   (``V(y) = sum_x |dI/dx|``, ``H(x) = sum_y |dI/dy|``) among the features; pixels above the
   threshold are window.
2. **Grid** (:func:`window_grid`), read off that window map as section 5.2 reads the gradient
   projections: floors are the runs of rows with many window pixels, and in each floor the
   windows are the runs of columns with window pixels in most of its rows; so every window is a
   box and the boxes make the label map (the paper's simplified façade image).  Then section
   5.2's refinement, as the paper states it (:func:`refine_grid`): the grid's floor count and
   storey height, column count and window pitch stand for the CNN's estimates, and the
   boundaries between floors and between columns move to the minima of V and H, each storey
   and tile kept within 75 %-140 % of the estimate; each window belongs to the floor and tile
   its centre is in, one window a tile.  (The paper's boundaries then cut the tiles its window
   CNNs look into; here the windows are found first, so the refined boundaries regroup them and
   are the floor boundaries of the parse.)  Not yet: the regularisation of window sizes per
   floor.  (The window and façade styles: :mod:`.windows`, :mod:`.facade_style`.)
3. **Façade colour** (section 5.4, as stated): k-means with k = 10 in L*a*b* on the pixels
   outside the windows; the largest cluster's centre.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from PIL import Image
from scipy import ndimage

from .pixels import RGB_TO_XYZ, WHITE, lab_image, load_weights, window_probability

WORK_HEIGHT = 256
"""Rows the photograph is resampled to for the window classifier (its aspect kept): features and
weights are at one scale whatever the photograph's size."""

ROW_LEVEL = 0.35
"""A row belongs to a floor's window band when its share of window pixels is at least this
fraction of the highest row's (the default: trained weights carry their own, chosen on the
training façades by ``bench/train_facade.py``)."""

SLIVER = 0.35
"""A floor band (a window) lower (narrower) than this fraction of the median of its façade's
(its floor's) is dropped: the edge of a ledge, a pipe, a shadow."""

COLUMN_LEVEL = 0.5
"""In a floor's band, a column is a window's when at least this share of the band's rows are
window pixels there (likewise a default)."""

SPACING = (0.75, 1.40)
"""Section 5.2: the refined floor heights and tile widths stay within 75 % and 140 % of the
estimated ones."""

REFINE = True
"""Whether :func:`parse_facade` refines the grid on the gradient projections (section 5.2);
``bench/facade_cmp.py --no-refine`` measures the parse without."""

COLOR_CLUSTERS = 10  # section 5.4: "k = 10 clusters for all our results"


@dataclass
class FacadeParse:
    """A façade's parse in the input photograph's pixels: ``window`` the (h, w) window mask,
    ``windows`` (k, 4) window boxes (top, left, bottom, right), ``floors`` the window rows' box
    index lists top to bottom, ``floor_bounds`` the floor boundaries (floors + 1 rows, top to
    bottom), ``color`` the façade's sRGB colour."""

    window: np.ndarray
    windows: np.ndarray
    floors: list[list[int]]
    floor_bounds: np.ndarray
    color: tuple[int, int, int]

    @property
    def height(self) -> int:
        return int(self.window.shape[0])

    @property
    def width(self) -> int:
        return int(self.window.shape[1])

    def label_map(self) -> np.ndarray:
        """(height, width) uint8 of CMP label ids: 2 façade, 3 window (the window boxes: the
        paper's simplified façade image; on CMP they score a little above the raw mask)."""
        labels = np.full((self.height, self.width), 2, dtype=np.uint8)
        for top, left, bottom, right in np.rint(self.windows).astype(np.int64):
            labels[top:bottom, left:right] = 3
        return labels

    def windows_per_floor(self) -> list[int]:
        """Windows in each floor, top to bottom."""
        return [len(f) for f in self.floors]


def working_image(rgb: np.ndarray) -> np.ndarray:
    """The photograph resampled to :data:`WORK_HEIGHT` rows (uint8, aspect kept)."""
    height, width = rgb.shape[:2]
    size = (max(1, round(width * WORK_HEIGHT / height)), WORK_HEIGHT)
    return np.asarray(Image.fromarray(rgb[..., :3]).resize(size, Image.Resampling.BILINEAR))


def gradient_projections(gray: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Section 5.2: V(y) = sum over x of |dI/dx| (a row's vertical edges) and H(x) = sum over y
    of |dI/dy| (a column's horizontal edges), each divided by its length."""
    gx = np.abs(ndimage.sobel(gray, axis=1))
    gy = np.abs(ndimage.sobel(gray, axis=0))
    return gx.mean(axis=1), gy.mean(axis=0)


def rows_of(extents: list[tuple[float, float]]) -> list[list[int]]:
    """Indices of ``extents`` (start, end) grouped into rows, in order of their centres: an
    extent joins the last row when it overlaps that row's median extent by more than half of
    the shorter of the two.  How ``bench/facade_cmp.py`` counts the floors of a labelled façade
    from its window boxes (the truth the parse's floors are scored against)."""
    order = sorted(range(len(extents)), key=lambda i: sum(extents[i]) / 2)
    rows: list[list[int]] = []
    for i in order:
        start, end = extents[i]
        if rows:
            row_start = float(np.median([extents[j][0] for j in rows[-1]]))
            row_end = float(np.median([extents[j][1] for j in rows[-1]]))
            overlap = min(end, row_end) - max(start, row_start)
            if overlap > 0.5 * min(end - start, row_end - row_start):
                rows[-1].append(i)
                continue
        rows.append([i])
    return rows


def facade_color(rgb: np.ndarray, wall: np.ndarray, seed: int = 0) -> tuple[int, int, int]:
    """Section 5.4: the centre of the largest of :data:`COLOR_CLUSTERS` k-means clusters in
    L*a*b* of the wall pixels, as sRGB 0..255."""
    from scipy.cluster.vq import kmeans2

    pixels = rgb[wall].reshape(-1, 3).astype(np.float64) / 255.0
    if len(pixels) == 0:
        pixels = rgb.reshape(-1, 3).astype(np.float64) / 255.0
    step = max(1, len(pixels) // 20_000)  # a sample: the colour of a wall needs no more
    lab = _lab(pixels[::step])
    k = min(COLOR_CLUSTERS, len(np.unique(lab, axis=0)))  # a plain wall has fewer colours
    if k <= 1:
        centre = lab[0]
    else:
        with warnings.catch_warnings():  # a cluster emptied on the way is no failure here
            warnings.simplefilter("ignore")
            centres, label = kmeans2(lab, k, seed=np.random.default_rng(seed), minit="++")
        centre = centres[np.bincount(label, minlength=k).argmax()]
    r, g, b = (int(v) for v in np.clip(np.rint(_srgb(centre) * 255), 0, 255))
    return r, g, b


def runs(profile: np.ndarray, level: float, shortest: int) -> list[tuple[int, int]]:
    """(start, end) of the runs of ``profile`` at or above ``level``, ``shortest`` samples
    long or more."""
    above = np.concatenate([[False], profile >= level, [False]])
    edges = np.flatnonzero(np.diff(above.astype(np.int8)))
    return [
        (int(a), int(b)) for a, b in zip(edges[::2], edges[1::2], strict=True) if b - a >= shortest
    ]


def window_grid(
    mask: np.ndarray, row_level: float = ROW_LEVEL, column_level: float = COLUMN_LEVEL
) -> list[list[tuple[int, int, int, int]]]:
    """Windows floor by floor, (top, left, bottom, right) each, read off a window mask as the
    grid of section 5.2 reads the gradient projections: floors are the runs of rows whose share
    of window pixels is high (:data:`ROW_LEVEL` of the highest), and in each floor the windows
    are the runs of columns with window pixels in most of the floor's rows."""
    height, width = mask.shape
    share = ndimage.uniform_filter1d(mask.mean(axis=1), 3)
    bands = runs(share, row_level * share.max(), max(2, height // 100))
    if bands:  # a band much lower than the others is a ledge or a shadow's edge, not a floor
        tall = np.median([b - a for a, b in bands])
        bands = [(a, b) for a, b in bands if b - a >= SLIVER * tall]
    floors = []
    for top, bottom in bands:
        across = mask[top:bottom].mean(axis=0)
        cells = runs(across, column_level, max(2, width // 200))
        if cells:  # likewise a window much narrower than its floor's others
            wide = np.median([b - a for a, b in cells])
            cells = [(a, b) for a, b in cells if b - a >= SLIVER * wide]
        floors.append([(top, left, bottom, right) for left, right in cells])
    return [f for f in floors if f]


def refine_boundaries(
    profile: np.ndarray, bounds: list[int], spacing: float, within: tuple[float, float] = SPACING
) -> np.ndarray:
    """Section 5.2's refinement: the boundaries ``bounds`` (increasing indices into
    ``profile``) each displaced by at most half of (1 - 0.75) of ``spacing`` to where the sum of
    ``profile`` over them is least, every gap between neighbours kept within ``within`` of
    ``spacing``: exactly, by dynamic programming along the chain.  Where two neighbours cannot
    be kept within it (the estimate is off there) that gap is left free."""
    n = len(profile)
    if not bounds or spacing <= 0:
        return np.asarray(bounds, dtype=np.float64)
    low, high = within[0] * spacing, within[1] * spacing
    reach = max(1, round((1 - within[0]) * spacing / 2))
    cands = [np.arange(max(1, b - reach), min(n - 1, b + reach) + 1) for b in bounds]
    cost = profile[cands[0]].astype(np.float64)
    back = []
    for j in range(1, len(cands)):
        gap = cands[j][:, None] - cands[j - 1][None, :]
        total = np.where((gap >= low) & (gap <= high), cost[None, :], np.inf)
        if not np.isfinite(total).any():
            total = np.where(gap > 0, cost[None, :], np.inf)
        best = total.argmin(axis=1)
        back.append(best)
        cost = profile[cands[j]] + total[np.arange(len(cands[j])), best]
    k = int(np.argmin(cost))
    out = [int(cands[-1][k])]
    for j in range(len(cands) - 1, 0, -1):
        k = int(back[j - 1][k])
        out.append(int(cands[j - 1][k]))
    return np.array(out[::-1], dtype=np.float64)


def refine_grid(
    grid: list[list[tuple[int, int, int, int]]], v: np.ndarray, h: np.ndarray
) -> tuple[list[list[tuple[int, int, int, int]]], np.ndarray]:
    """The grid of :func:`window_grid` refined as section 5.2 refines its CNN's: the floor
    count and storey height, the column count and window pitch, are the grid's (the paper's
    estimates), the boundaries between floors (columns) start midway between the window rows
    (columns of windows across the floors, grouped by :func:`rows_of`) and move to minima of
    ``v`` = V(y) (``h`` = H(x)) by :func:`refine_boundaries`.  Each window then belongs to the
    floor its centre lies in, and the windows of one floor whose centres share a column tile
    become one (the paper's one window a tile: a mullion no longer splits a window in two).
    Where this deviates from the paper's words: the estimates are medians of the grid's
    spacings, not a CNN's; only the inner boundaries move, so the top and bottom storeys (to the
    photograph's edges: roof, ground floor) are not held to the estimate; how far a boundary
    may move, which the paper leaves open, is :func:`refine_boundaries`'s.  Returns the grid
    and the inner floor boundaries (rows)."""
    if not grid:
        return grid, np.zeros(0)
    tops = [float(np.median([w[0] for w in f])) for f in grid]
    bottoms = [float(np.median([w[2] for w in f])) for f in grid]
    inner = [round((b + t) / 2) for b, t in zip(bottoms[:-1], tops[1:], strict=True)]
    centres = np.add(tops, bottoms) / 2
    storey = float(np.median(np.diff(centres))) if len(grid) > 1 else 0.0
    ys = refine_boundaries(v, inner, storey)
    windows = [w for f in grid for w in f]
    floor_of = np.searchsorted(ys, [(w[0] + w[2]) / 2 for w in windows])
    extents = [(float(w[1]), float(w[3])) for w in windows]
    columns = rows_of(extents)
    tile_of = np.zeros(len(windows), dtype=np.int64)
    if len(columns) > 1:
        lefts = [float(np.median([extents[i][0] for i in c])) for c in columns]
        rights = [float(np.median([extents[i][1] for i in c])) for c in columns]
        mids = [round((r + left) / 2) for r, left in zip(rights[:-1], lefts[1:], strict=True)]
        pitch = float(np.median(np.diff(np.add(lefts, rights) / 2)))
        xs = refine_boundaries(h, sorted(mids), pitch)
        tile_of = np.searchsorted(xs, [(w[1] + w[3]) / 2 for w in windows])
    tiles: dict[tuple[int, int], tuple[int, int, int, int]] = {}
    for w, f, c in zip(windows, floor_of, tile_of, strict=True):
        key = (int(f), int(c))
        a = tiles.get(key, w)
        tiles[key] = (min(a[0], w[0]), min(a[1], w[1]), max(a[2], w[2]), max(a[3], w[3]))
    kept = sorted({f for f, _ in tiles})
    floors = [[tiles[f, c] for f, c in sorted(tiles) if f == k] for k in kept]
    return floors, np.array([ys[k - 1] for k in kept[1:]])


def parse_facade(rgb: np.ndarray, net: dict[str, np.ndarray] | None = None) -> FacadeParse:
    """The parse of a rectified façade photograph (h, w, 3) uint8 (``net``: the window
    classifier's weights, by default the shipped ones)."""
    net = net if net is not None else load_weights()
    work = working_image(rgb)
    return parse_probability(rgb, work, window_probability(work, net), net)


def parse_probability(
    rgb: np.ndarray,
    work: np.ndarray,
    prob: np.ndarray,
    net: dict[str, np.ndarray],
    refine: bool = REFINE,
    color: bool = True,
) -> FacadeParse:
    """The parse of ``rgb`` from the window probability ``prob`` of its working image ``work``
    (apart from :func:`parse_facade` so that the training and the benchmark can try grid levels
    and the refinement on one probability map; ``color=False`` skips the colour's k-means)."""
    height, width = rgb.shape[:2]
    small = prob >= float(net["threshold"])
    levels = {k: float(net[k]) for k in ("row_level", "column_level") if k in net}
    grid = window_grid(small, **levels)
    sy, sx = height / work.shape[0], width / work.shape[1]
    if refine:
        v, h = gradient_projections(lab_image(work)[..., 0] / 100.0)
        grid, inner = refine_grid(grid, v, h)
    windows = np.array(
        [(t * sy, x0 * sx, b * sy, x1 * sx) for floor in grid for t, x0, b, x1 in floor]
    ).reshape(-1, 4)
    full = np.asarray(
        Image.fromarray(prob.astype(np.float32)).resize((width, height), Image.Resampling.BILINEAR)
    )
    window = full >= float(net["threshold"])
    floors, k = [], 0
    for floor in grid:
        floors.append(list(range(k, k + len(floor))))
        k += len(floor)
    if not refine:  # floor boundaries midway between the window rows
        tops = [float(np.median(windows[f, 0])) / sy for f in floors]
        bottoms = [float(np.median(windows[f, 2])) / sy for f in floors]
        inner = np.array([(b + t) / 2 for b, t in zip(bottoms[:-1], tops[1:], strict=True)])
    bounds = np.array([0.0, *(inner * sy), float(height)])
    rgb_color = facade_color(rgb, ~window) if color else (0, 0, 0)
    return FacadeParse(window, windows, floors, bounds, rgb_color)


def _lab(rgb: np.ndarray) -> np.ndarray:
    """sRGB 0..1 (n, 3) to CIE L*a*b* (D65)."""
    return lab_image(np.clip(np.rint(rgb * 255), 0, 255).astype(np.uint8)[None])[0]


def _srgb(lab: np.ndarray) -> np.ndarray:
    """CIE L*a*b* (3,) to sRGB 0..1."""
    fy = (lab[0] + 16) / 116
    f = np.array([fy + lab[1] / 500, fy, fy - lab[2] / 200])
    xyz = np.where(f > 6 / 29, f**3, 3 * (6 / 29) ** 2 * (f - 4 / 29)) * WHITE
    linear = np.linalg.solve(RGB_TO_XYZ, xyz)
    linear = np.clip(linear, 0, 1)
    return np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * linear ** (1 / 2.4) - 0.055)
