"""The four images made from a frame's buffers: shaded, silhouette, lines and labels.

Each is a pure function of the buffers and the scene, computed per triangle where it can be
(a flat-shaded colour is one lookup per pixel), so that every mode costs about the same
whichever rasteriser made the frame.
"""

from __future__ import annotations

import colorsys
import zlib

import numpy as np

from .frame import Frame
from .scene import Scene

BACKGROUND = (242, 242, 242)  # shaded: a light grey, so that white walls still show their outline
LIGHT = np.array([-0.45, 0.6, 0.66])  # camera space: from the upper left, towards the viewer
AMBIENT = 0.35
PALETTE_SIZE = 64


def _srgb_to_linear(c: np.ndarray) -> np.ndarray:
    c = c / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def _linear_to_srgb8(c: np.ndarray) -> np.ndarray:
    c = np.clip(c, 0.0, 1.0)
    s = np.where(c <= 0.0031308, c * 12.92, 1.055 * c ** (1 / 2.4) - 0.055)
    return np.rint(s * 255.0).astype(np.uint8)


def facing_normals(frame: Frame, scene: Scene) -> np.ndarray:
    """(T, 3) unit normals in camera space, each turned towards the camera (faces are two-sided)."""
    cam = frame.camera
    n = scene.normals()
    to_camera = cam.position - scene.triangles[:, 0] if len(scene) else np.zeros((0, 3))
    flip = np.einsum("ij,ij->i", n, to_camera) < 0
    n[flip] *= -1
    return n @ cam.rotation.T


def shaded(
    frame: Frame, scene: Scene, background=BACKGROUND, filter: str = "bilinear"
) -> np.ndarray:
    """(H, W, 3) uint8: each triangle's colour under one light from the camera's upper left
    (Lambert, in linear light, plus an ambient term), on a light background.  A textured
    triangle's pixels show its image sampled there (render/texturing.py, ``filter`` bilinear or
    nearest) times its colour, under the same light."""
    light = LIGHT / np.linalg.norm(LIGHT)
    intensity = AMBIENT + (1.0 - AMBIENT) * np.clip(facing_normals(frame, scene) @ light, 0.0, 1.0)
    lit = _srgb_to_linear(scene.colors.astype(np.float64)) * intensity[:, None]
    table = np.concatenate(
        [_linear_to_srgb8(lit), np.array([background], dtype=np.uint8)]
    )  # index -1: background
    image = table[frame.triangle]
    if scene.textured():
        from .texturing import textured_pixels

        pixels, texel = textured_pixels(frame, scene, filter)
        tri = frame.triangle.reshape(-1)[pixels]
        image.reshape(-1, 3)[pixels] = _linear_to_srgb8(texel * lit[tri])
    return image


def silhouette(frame: Frame) -> np.ndarray:
    """(H, W) uint8 mask: 255 where the model is, 0 elsewhere."""
    return np.where(frame.mask, 255, 0).astype(np.uint8)


def face_ids(scene: Scene, normal_tol: float = 1e-3, offset_tol: float = 1e-3) -> np.ndarray:
    """(T,) int64: triangles of one label and colour lying in one plane share an id.

    So the diagonal of a wall quad, the fan of a polygon, and the seam between two wall tiles
    side by side in one façade are not edges; a window in that wall (another label or colour)
    is outlined, and so is every crease and step.
    """
    if len(scene) == 0:
        return np.zeros(0, dtype=np.int64)
    n = scene.normals()
    # each plane's offset from the model's centre, not the origin: at projected coordinates
    # (10^6 m) the normals' rounding times the distance would split one wall into many planes
    lo, hi = scene.bounds()
    offset = np.einsum("ij,ij->i", n, scene.triangles[:, 0] - (lo + hi) / 2.0)
    rgb = scene.colors.astype(np.int64)
    look = scene.label * (1 << 24) + (rgb[:, 0] << 16) + (rgb[:, 1] << 8) + rgb[:, 2]
    key = np.column_stack([look, np.rint(n / normal_tol), np.rint(offset / offset_tol)]).astype(
        np.int64
    )
    order = np.lexsort(
        key.T[::-1]
    )  # rows sorted; equal rows are neighbours (np.unique(axis=0) is slower)
    starts = np.empty(len(key), dtype=bool)
    starts[0] = True
    starts[1:] = (key[order[1:]] != key[order[:-1]]).any(axis=1)
    ids = np.empty(len(key), dtype=np.int64)
    ids[order] = np.cumsum(starts) - 1
    return ids


def lines(frame: Frame, scene: Scene, width: int = 1) -> np.ndarray:
    """(H, W) uint8 line drawing, black on white: the visible edges.

    An edge lies between two neighbouring pixels that show different faces (:func:`face_ids`),
    or the model and the background: a change of label or colour, of plane (a crease: a change
    of normal; a step: a change of depth) or the outline.  It is drawn on the nearer of the two
    pixels, so lines are one pixel wide and sit on the surface in front; ``width`` > 1 thickens
    them.
    """
    fid = np.concatenate([face_ids(scene), [-1]])[frame.triangle]
    depth = frame.depth
    edge = np.zeros(fid.shape, dtype=bool)
    for axis in (0, 1):
        a = (slice(None, -1), slice(None)) if axis == 0 else (slice(None), slice(None, -1))
        b = (slice(1, None), slice(None)) if axis == 0 else (slice(None), slice(1, None))
        differ = fid[a] != fid[b]
        a_nearer = depth[a] <= depth[b]
        edge[a] |= differ & a_nearer
        edge[b] |= differ & ~a_nearer
    for _ in range(max(width, 1) - 1):  # grow by one pixel right and down per step
        grown = edge.copy()
        grown[1:, :] |= edge[:-1, :]
        grown[:, 1:] |= edge[:, :-1]
        edge = grown
    return np.where(edge, 0, 255).astype(np.uint8)


def palette(size: int = PALETTE_SIZE) -> np.ndarray:
    """(size, 3) uint8 distinct, saturated colours, none near black: hues a golden angle apart,
    in three levels of saturation and brightness."""
    levels = [(0.80, 0.95), (0.55, 0.85), (0.95, 0.70)]
    out = []
    for k in range(size):
        s, v = levels[k % 3]
        r, g, b = colorsys.hsv_to_rgb((k * 0.6180339887498949) % 1.0, s, v)
        out.append((round(r * 255), round(g * 255), round(b * 255)))
    return np.array(out, dtype=np.uint8)


def label_colours(labels: list[str]) -> dict[str, tuple[int, int, int]]:
    """A fixed colour per label: the CRC-32 of its name picks one of :func:`palette`; when two
    labels of the set pick the same colour, the later one (in sorted order) takes the next free
    colour.  A label keeps its colour from image to image unless such a clash moves it."""
    names = sorted(set(labels))
    size = PALETTE_SIZE
    while size < len(names):
        size *= 2
    colours = palette(size)
    taken: set[int] = set()
    out = {}
    for name in names:
        k = zlib.crc32(name.encode("utf-8")) % size
        while k in taken:
            k = (k + 1) % size
        taken.add(k)
        out[name] = tuple(int(c) for c in colours[k])
    return out


def hex_colour(rgb) -> str:
    r, g, b = (int(c) for c in rgb)
    return f"#{r:02x}{g:02x}{b:02x}"


def labels(frame: Frame, scene: Scene) -> tuple[np.ndarray, dict]:
    """(H, W, 3) uint8 with each terminal label in its colour on black, and the legend:
    ``{"background": "#000000", "labels": {label: "#rrggbb", ...}}`` for every label of the scene
    (see :mod:`.scene` for what a label is when the source is a glTF file)."""
    colours = label_colours(scene.labels)
    table = np.array(
        [colours[name] for name in scene.labels] + [(0, 0, 0)], dtype=np.uint8
    ).reshape(-1, 3)
    per_triangle = np.concatenate([scene.label, [len(scene.labels)]])
    image = table[per_triangle[frame.triangle]]
    legend = {
        "background": "#000000",
        "labels": {name: hex_colour(colours[name]) for name in sorted(colours)},
    }
    return image, legend
