"""Texture colours per pixel, from a frame's triangle buffer: the same for both rasterisers.

The rasterisers say which triangle each pixel sees (``Frame.triangle``); that is all texturing
needs.  For every pixel on a textured triangle, the ray through the pixel's centre is cut with
the triangle's plane (Moller-Trumbore, in bulk: one numpy expression over all such pixels), which
gives the point's barycentric coordinates on the triangle in the world, hence its texture
coordinates *perspective-correct* by construction (no interpolation in screen space).  The image
is sampled there in linear light, coordinates outside 0..1 wrapped as the texture says (REPEAT by
default, as glTF samplers and CGA do):

* ``nearest``: the texel the point falls in (GL's NEAREST);
* ``bilinear`` (the default): between the four nearest texels of the mipmap level whose texels
  are about a pixel apart there (GL's LINEAR_MIPMAP_NEAREST): the rays through the pixel's right
  and lower neighbours, cut with the same plane, say how far the coordinates move per pixel, so a
  façade far away shows its texture averaged rather than a sparkle of single texels.

So the GL and numpy renderers draw the same textures, and only pixels that show a textured
triangle cost anything: an untextured scene is drawn exactly as before.
"""

from __future__ import annotations

import numpy as np

from .frame import Frame
from .scene import Scene

FILTERS = ("bilinear", "nearest")

# sRGB byte -> linear light, once
_LINEAR = np.where(
    np.arange(256) / 255.0 <= 0.04045,
    np.arange(256) / 255.0 / 12.92,
    ((np.arange(256) / 255.0 + 0.055) / 1.055) ** 2.4,
)


def _rays(frame: Frame, row: np.ndarray, col: np.ndarray) -> np.ndarray:
    """(N, 3) world directions of the rays through the centres of pixels (row, col)."""
    camera = frame.camera
    cx, cy = camera.center
    f = camera.focal
    ray = np.empty((len(row), 3))
    ray[:, 0] = (col + 0.5 - cx) / f
    ray[:, 1] = -(row + 0.5 - cy) / f
    ray[:, 2] = -1.0
    return ray @ camera.rotation  # camera -> world: the rotation's transpose, on row vectors


def _plane_uv(frame: Frame, scene: Scene, ray: np.ndarray, tri: np.ndarray, clamp: bool):
    """(N, 2) texture coordinates where each ray from the camera meets triangle ``tri``'s plane:
    barycentric (1 - s - t, s, t), clamped into the triangle when ``clamp`` (a pixel centre on
    an edge, or a triangle seen edge-on, must not reach past its corners into a neighbour's part
    of an atlas); NaN where a ray runs along the plane (unclamped)."""
    corners = scene.triangles[tri]
    a = corners[:, 0]
    e1, e2 = corners[:, 1] - a, corners[:, 2] - a
    to_eye = frame.camera.position - a
    p = np.cross(ray, e2)
    q = np.cross(to_eye, e1)
    with np.errstate(divide="ignore", invalid="ignore"):
        det = np.einsum("ij,ij->i", e1, p)
        s = np.einsum("ij,ij->i", to_eye, p) / det
        t = np.einsum("ij,ij->i", ray, q) / det
    if clamp:
        bad = ~(np.isfinite(s) & np.isfinite(t))
        s[bad], t[bad] = 1.0 / 3.0, 1.0 / 3.0
        s, t = np.clip(s, 0.0, 1.0), np.clip(t, 0.0, 1.0)
        over = s + t > 1.0
        total = s[over] + t[over]
        s[over], t[over] = s[over] / total, t[over] / total
    uv = scene.uv[tri]  # type: ignore[index]
    return uv[:, 0] * (1.0 - s - t)[:, None] + uv[:, 1] * s[:, None] + uv[:, 2] * t[:, None]


def pixel_uv(frame: Frame, scene: Scene, pixels: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """(N, 2) texture coordinates seen at the flat ``pixels`` (indices into the H x W image),
    each on scene triangle ``tri``."""
    row, col = np.divmod(pixels, frame.camera.size[0])
    return _plane_uv(frame, scene, _rays(frame, row, col), tri, clamp=True)


def pixel_footprint(frame: Frame, scene: Scene, pixels: np.ndarray, tri: np.ndarray):
    """(N, 2, 2) how the texture coordinates change from each pixel to its right and lower
    neighbours ([[du, dv] per column, [du, dv] per row]), on the pixel's triangle's plane."""
    row, col = np.divmod(pixels, frame.camera.size[0])
    here = _plane_uv(frame, scene, _rays(frame, row, col), tri, clamp=False)
    right = _plane_uv(frame, scene, _rays(frame, row, col + 1), tri, clamp=False)
    down = _plane_uv(frame, scene, _rays(frame, row + 1, col), tri, clamp=False)
    return np.stack([right - here, down - here], axis=1)


def _wrap(index: np.ndarray, n: int, wrap: str) -> np.ndarray:
    """Texel indices brought inside 0..n-1: repeated, mirrored, or clamped to the edge."""
    if wrap == "wrap":
        return np.mod(index, n)
    if wrap == "mirror":
        k = np.mod(index, 2 * n)
        return np.where(k >= n, 2 * n - 1 - k, k)
    return np.clip(index, 0, n - 1)


def mipmaps(texture) -> list[np.ndarray]:
    """The texture's mipmap levels, (H, W, 3) uint8 sRGB each: level 0 the image, each next one
    half its size (rounded down, at least 1), every texel the mean of 2 x 2 (in linear light;
    an odd last row or column is left out), down to 1 x 1.  Made once per texture."""
    levels = texture._mipmaps
    if levels is None:
        levels = [texture.rgb]
        while max(levels[-1].shape[:2]) > 1:
            top = levels[-1]
            h, w = top.shape[:2]
            h2, w2 = max(h // 2, 1), max(w // 2, 1)
            lin = _LINEAR[top[: 2 * h2 if h > 1 else 1, : 2 * w2 if w > 1 else 1]]
            lin = lin.reshape(h2, -1, w2, lin.shape[1] // w2, 3).mean(axis=(1, 3))
            levels.append(_to_srgb8(lin))
        texture._mipmaps = levels
    return levels


def _to_srgb8(c: np.ndarray) -> np.ndarray:
    c = np.clip(c, 0.0, 1.0)
    s = np.where(c <= 0.0031308, c * 12.92, 1.055 * c ** (1 / 2.4) - 0.055)
    return np.rint(s * 255.0).astype(np.uint8)


def _bilinear(rgb: np.ndarray, uv: np.ndarray, wrap: str) -> np.ndarray:
    h, w = rgb.shape[:2]
    # texel centres at (k + 0.5) / size; rows counted from the top
    x = np.nan_to_num(uv[:, 0] * w - 0.5, nan=0.0, posinf=0.0, neginf=0.0)
    y = np.nan_to_num((1.0 - uv[:, 1]) * h - 0.5, nan=0.0, posinf=0.0, neginf=0.0)
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0)[:, None], (y - y0)[:, None]
    i0, j0 = x0.astype(np.int64), y0.astype(np.int64)
    left, right = _wrap(i0, w, wrap), _wrap(i0 + 1, w, wrap)
    up, down = _wrap(j0, h, wrap), _wrap(j0 + 1, h, wrap)
    top = _LINEAR[rgb[up, left]] * (1.0 - fx) + _LINEAR[rgb[up, right]] * fx
    bottom = _LINEAR[rgb[down, left]] * (1.0 - fx) + _LINEAR[rgb[down, right]] * fx
    return top * (1.0 - fy) + bottom * fy


def sample(
    texture, uv: np.ndarray, filter: str = "bilinear", footprint: np.ndarray | None = None
) -> np.ndarray:
    """(N, 3) linear-light colours of a :class:`~.textured.Texture` at texture coordinates
    ``uv`` (N, 2), v up (row 0 of the image is v = 1).  ``footprint`` (N, 2, 2), from
    :func:`pixel_footprint`, picks each pixel's mipmap level for ``bilinear``."""
    rgb = texture.rgb
    h, w = rgb.shape[:2]
    if filter == "nearest":
        x = np.nan_to_num(uv[:, 0] * w, nan=0.0, posinf=0.0, neginf=0.0)
        y = np.nan_to_num((1.0 - uv[:, 1]) * h, nan=0.0, posinf=0.0, neginf=0.0)
        i = _wrap(np.floor(x).astype(np.int64), w, texture.wrap)
        j = _wrap(np.floor(y).astype(np.int64), h, texture.wrap)
        return _LINEAR[rgb[j, i]]
    if footprint is None:
        return _bilinear(rgb, uv, texture.wrap)
    # texels per pixel: the longer of the two steps, measured in level-0 texels
    steps = footprint * np.array([w, h], dtype=np.float64)
    rho = np.sqrt(np.maximum((steps[:, 0] ** 2).sum(axis=1), (steps[:, 1] ** 2).sum(axis=1)))
    levels = mipmaps(texture)
    with np.errstate(divide="ignore", invalid="ignore"):
        level = np.floor(np.log2(rho) + 0.5)
    level = np.clip(np.nan_to_num(level, nan=0.0, posinf=0.0, neginf=0.0), 0, len(levels) - 1)
    level = level.astype(np.int64)
    out = np.empty((len(uv), 3))
    for k in np.unique(level):
        sel = level == k
        out[sel] = _bilinear(levels[int(k)], uv[sel], texture.wrap)
    return out


def textured_pixels(
    frame: Frame, scene: Scene, filter: str = "bilinear"
) -> tuple[np.ndarray, np.ndarray]:
    """(flat pixel indices, (N, 3) linear-light texture colours) of every pixel that shows a
    textured triangle; one pass per image, every pixel of it at once."""
    if filter not in FILTERS:
        raise ValueError(f"unknown texture filter {filter!r}; known: {', '.join(FILTERS)}")
    empty = np.zeros(0, dtype=np.int64), np.zeros((0, 3))
    if not scene.textured():
        return empty
    assert scene.texture is not None
    flat = frame.triangle.reshape(-1)
    pixels = np.flatnonzero(flat >= 0)
    which = scene.texture[flat[pixels]]
    pixels, which = pixels[which >= 0], which[which >= 0]
    if not len(pixels):
        return empty
    tri = flat[pixels].astype(np.int64)
    uv = pixel_uv(frame, scene, pixels, tri)
    footprint = pixel_footprint(frame, scene, pixels, tri) if filter == "bilinear" else None
    colour = np.empty((len(pixels), 3))
    order = np.argsort(which, kind="stable")
    cuts = np.flatnonzero(np.diff(which[order])) + 1
    for group in np.split(order, cuts):  # one per image
        colour[group] = sample(
            scene.textures[int(which[group[0]])],
            uv[group],
            filter,
            None if footprint is None else footprint[group],
        )
    return pixels, colour
