"""Texture colours per pixel, from a frame's triangle buffer: the same for both rasterisers.

The rasterisers say which triangle each pixel sees (``Frame.triangle``); that is all texturing
needs.  For every pixel on a textured triangle, the ray through the pixel's centre is cut with
the triangle's plane (Moller-Trumbore, its vectors once per triangle, then three affine
functions of the pixel and two divisions per pixel, numpy in bulk), which gives the point's
barycentric coordinates on the triangle in the world, hence its texture coordinates
*perspective-correct* by construction (no interpolation in screen space).  The image
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


def _coefficients(frame: Frame, scene: Scene, tris: np.ndarray) -> np.ndarray:
    """(U, 3, 3) per triangle of ``tris``: the Moller-Trumbore determinant and the numerators of
    the barycentric s and t as affine functions of the pixel, ``c[k] @ (1, column, row)``.

    The ray through pixel (column, row) has the world direction ``D = D0 + column Dx + row Dy``
    and starts at the camera, ``T = eye - a`` from the triangle's first corner, so with edges
    e1, e2: det = D . (e2 x e1), s det = D . (e2 x T), t det = D . (T x e1), each a dot product
    with a vector of the triangle alone: per pixel, three affine functions and two divisions."""
    camera = frame.camera
    corners = scene.triangles[tris]
    a = corners[:, 0]
    e1, e2 = corners[:, 1] - a, corners[:, 2] - a
    to_eye = camera.position - a
    cx, cy = camera.center
    f = camera.focal
    rot = camera.rotation  # world -> camera; its rows are the camera's axes in the world
    along = np.stack(
        [np.array([(0.5 - cx) / f, -(0.5 - cy) / f, -1.0]) @ rot, rot[0] / f, -rot[1] / f]
    )
    vectors = np.stack([np.cross(e2, e1), np.cross(e2, to_eye), np.cross(to_eye, e1)], axis=1)
    return vectors @ along.T


def pixel_uv(
    frame: Frame, scene: Scene, pixels: np.ndarray, tri: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """((N, 2) texture coordinates, (N, 2, 2) their change per pixel) seen at the flat
    ``pixels`` (indices into the H x W image), each on scene triangle ``tri``.

    The ray through the pixel's centre meets the triangle's plane at barycentric
    (1 - s - t, s, t), clamped into the triangle (a pixel centre on an edge, or a triangle seen
    edge-on, must not reach past its corners into a neighbour's part of an atlas).  The change
    is to the rays through the right and lower neighbours, on the same plane, unclamped:
    ``[[du, dv] per column, [du, dv] per row]``."""
    row, col = np.divmod(pixels, frame.camera.size[0])
    tris, index = np.unique(tri, return_inverse=True)
    c = _coefficients(frame, scene, tris)[index.reshape(-1)]  # (N, 3, 3)
    here = c[:, :, 0] + c[:, :, 1] * col[:, None] + c[:, :, 2] * row[:, None]  # (N, 3)
    corner_uv = scene.uv[tri]  # type: ignore[index]

    def at(value: np.ndarray, clamp: bool) -> np.ndarray:
        with np.errstate(divide="ignore", invalid="ignore"):
            s, t = value[:, 1] / value[:, 0], value[:, 2] / value[:, 0]
        if clamp:
            bad = ~(np.isfinite(s) & np.isfinite(t))
            s[bad], t[bad] = 1.0 / 3.0, 1.0 / 3.0
            s, t = np.clip(s, 0.0, 1.0), np.clip(t, 0.0, 1.0)
            over = s + t > 1.0
            total = s[over] + t[over]
            s[over], t[over] = s[over] / total, t[over] / total
        return (
            corner_uv[:, 0] * (1.0 - s - t)[:, None]
            + corner_uv[:, 1] * s[:, None]
            + corner_uv[:, 2] * t[:, None]
        )

    uv = at(here, clamp=True)
    centre = at(here, clamp=False)
    step = np.stack([at(here + c[:, :, 1], False) - centre, at(here + c[:, :, 2], False) - centre])
    return uv, step.transpose(1, 0, 2)


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


def _texels(t: np.ndarray, n: int, wrap: str) -> np.ndarray:
    """Texel coordinates ``t`` brought into a range whose floor fits int64 and names the same
    texels after :func:`_wrap`: NaN and infinities to 0, then one period (n, or 2n mirrored) or
    clamped to -1..n.  A model's UVs may be 1e30 (a glTF buffer holds any float): cast as
    they were, they overflowed int64 (numpy's "invalid value encountered in cast")."""
    t = np.nan_to_num(t, nan=0.0, posinf=0.0, neginf=0.0)
    if wrap == "wrap":
        return np.mod(t, n)
    if wrap == "mirror":
        return np.mod(t, 2 * n)
    return np.clip(t, -1.0, float(n))


def _bilinear(rgb: np.ndarray, uv: np.ndarray, wrap: str) -> np.ndarray:
    h, w = rgb.shape[:2]
    # texel centres at (k + 0.5) / size; rows counted from the top
    with np.errstate(over="ignore", invalid="ignore"):  # 1e308 * w: inf, made 0 by _texels
        x = _texels(uv[:, 0] * w - 0.5, w, wrap)
        y = _texels((1.0 - uv[:, 1]) * h - 0.5, h, wrap)
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
    :func:`pixel_uv`, picks each pixel's mipmap level for ``bilinear``."""
    rgb = texture.rgb
    h, w = rgb.shape[:2]
    if filter == "nearest":
        with np.errstate(over="ignore", invalid="ignore"):
            x = _texels(uv[:, 0] * w, w, texture.wrap)
            y = _texels((1.0 - uv[:, 1]) * h, h, texture.wrap)
        i = _wrap(np.floor(x).astype(np.int64), w, texture.wrap)
        j = _wrap(np.floor(y).astype(np.int64), h, texture.wrap)
        return _LINEAR[rgb[j, i]]
    if footprint is None:
        return _bilinear(rgb, uv, texture.wrap)
    # texels per pixel: the longer of the two steps, measured in level-0 texels
    with np.errstate(over="ignore", invalid="ignore"):  # inf and nan: level 0 below
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
    # UVs of 1e308 (any float a model holds) overflow to inf and nan here: sample() takes them
    with np.errstate(over="ignore", invalid="ignore"):
        uv, footprint = pixel_uv(frame, scene, pixels, tri)
    colour = np.empty((len(pixels), 3))
    order = np.argsort(which, kind="stable")
    cuts = np.flatnonzero(np.diff(which[order])) + 1
    for group in np.split(order, cuts):  # one per image
        colour[group] = sample(
            scene.textures[int(which[group[0]])],
            uv[group],
            filter,
            footprint[group],
        )
    return pixels, colour
