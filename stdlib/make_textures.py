"""The textures bgr ships (stdlib/textures/*.png), drawn with numpy alone, deterministically.

    python -m bgr.stdlib.make_textures          # rewrites stdlib/textures/*.png

Examples and the standard library need images they may redistribute; photographs of real
buildings come with licences that forbid it, so bgr draws its own: brick with mortar (and its
normal map), render (plaster), a window (frame, mullion, transom and glass) and clay roof tiles.

**Tileable by construction.** Every image is a function of integer pixel coordinates that
repeats exactly with the image's width and height: bricks, courses, tiles and noise cells are
whole numbers of pixels that divide the image, and the noise lattice wraps.  So a projection
that repeats the image (``setupProjection(0, scope.xy, ~2, ~1.2)``) shows no seam, and drawing
the image one half-width further on (:func:`draw` with an offset) gives the same image rolled:
tests/test_shipped_textures.py checks that, and that the committed files are what this script
draws.  Structural lines (mortar joints, tile gaps) sit away from the image's edges, so an edge
pair of pixels looks like any other neighbouring pair.

**Deterministic.** Noise comes from an integer hash, not a random generator whose stream may
change between numpy releases, and only + - * / and sqrt touch floats (exactly rounded in IEEE
754), so every machine draws the same pixels.  The tests compare pixels, not PNG bytes (zlib
versions may compress differently).

Sizes: 256 x 256 pixels each.  The brick image is one 2.0 m x 1.2 m tile of stretcher bond
(8 bricks of 250 mm across, 16 courses of 75 mm up); the stdlib projects it that size.
"""

from __future__ import annotations

import io
from collections.abc import Callable
from pathlib import Path

import numpy as np

SIZE = 256
FOLDER = Path(__file__).resolve().parent / "textures"
_M32 = 0xFFFFFFFF


def _hash(a: np.ndarray, b: np.ndarray, seed: int) -> np.ndarray:
    """A float in [0, 1) per integer pair (a, b): a 32-bit integer mix, the same everywhere."""
    h = (
        a.astype(np.int64) * 0x9E3779B1 + b.astype(np.int64) * 0x85EBCA77 + seed * 0xC2B2AE3D
    ) & _M32
    h ^= h >> 15
    h = (h * 0x2C1B3C6D) & _M32
    h ^= h >> 12
    h = (h * 0x297A2D39) & _M32
    h ^= h >> 15
    return h.astype(np.float64) / 4294967296.0


def _smooth(t: np.ndarray) -> np.ndarray:
    return t * t * (3.0 - 2.0 * t)


def _noise(x: np.ndarray, y: np.ndarray, cell: int, seed: int) -> np.ndarray:
    """Value noise in [0, 1) on a lattice of ``cell``-pixel squares that wraps every SIZE pixels
    (``cell`` divides SIZE), smoothly interpolated between the lattice values."""
    n = SIZE // cell
    i, j = x // cell, y // cell
    fx = _smooth((x % cell + 0.5) / cell)
    fy = _smooth((y % cell + 0.5) / cell)

    def at(di: int, dj: int) -> np.ndarray:
        return _hash((i + di) % n, (j + dj) % n, seed)

    top = at(0, 0) + (at(1, 0) - at(0, 0)) * fx
    bottom = at(0, 1) + (at(1, 1) - at(0, 1)) * fx
    return top + (bottom - top) * fy


def _fbm(x: np.ndarray, y: np.ndarray, seed: int, cells=(64, 32, 16, 8, 4)) -> np.ndarray:
    """Octaves of :func:`_noise`, each half the cell and half the weight: in about -0.5..0.5."""
    total, weight, norm = np.zeros(x.shape), 1.0, 0.0
    for k, cell in enumerate(cells):
        total += weight * (_noise(x, y, cell, seed + 101 * k) - 0.5)
        norm += weight
        weight *= 0.5
    return total / norm


def _mix(a, b, t: np.ndarray) -> np.ndarray:
    """Colour a where t is 0, b where t is 1: (..., 3)."""
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return a + (b - a) * t[..., None]


def _ramp(d: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """0 below lo, 1 above hi, linear between."""
    return np.clip((d - lo) / (hi - lo), 0.0, 1.0)


# ---- brick ------------------------------------------------------------------------------------

BRICKS, COURSES = 8, 16  # per image: bricks of 32 x 16 pixels
_BW, _CH = SIZE // BRICKS, SIZE // COURSES


def _brick_layout(x: np.ndarray, y: np.ndarray):
    """Stretcher bond: per pixel the brick's (column, course) and the distance in pixels to the
    nearest joint across (dx) and up (dy).  Head joints fall 8 pixels in from the image's edge
    (24 in odd courses), bed joints 7 pixels down, so no joint lies on an edge of the image."""
    course = (y + _CH // 2 - 1) // _CH  # bed joint between rows 7 and 8 of every course
    shift = np.where(course % 2 == 0, _BW // 4, 3 * _BW // 4)
    xs = x - shift
    col = xs // _BW
    lx = xs % _BW + 0.5  # 0.5 .. 31.5 across the brick
    ly = (y + _CH // 2 - 1) % _CH + 0.5
    dx = np.minimum(lx, _BW - lx)  # pixels to the head joint (at lx = 0)
    dy = np.minimum(ly, _CH - ly)
    return col % BRICKS, course % COURSES, dx, dy


def _brick_height(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """0 in the mortar, 1 on a brick's face, a bevel of about 2 pixels between; a little grain."""
    _, _, dx, dy = _brick_layout(x, y)
    face = np.minimum(_ramp(dx, 0.6, 2.2), _ramp(dy, 1.1, 2.6))
    return face + 0.06 * _fbm(x, y, 7, cells=(8, 4, 2))


def brick(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Red-brown bricks of varied firing in light grey mortar."""
    col, course, dx, dy = _brick_layout(x, y)
    tone = _hash(col, course, 1)  # one tone per brick
    base = _mix((164, 70, 48), (120, 52, 38), tone)
    burnt = _hash(col, course, 2) > 0.86  # a few dark, over-fired bricks
    base = np.where(burnt[..., None], base * 0.72, base)
    grain = 1.0 + 0.16 * _fbm(x, y, 3) + 0.05 * (_hash(x % SIZE, y % SIZE, 4) - 0.5)
    face = base * grain[..., None]
    mortar = np.array((196.0, 190.0, 178.0)) * (1.0 + 0.1 * _fbm(x, y, 5))[..., None]
    edge = np.minimum(_ramp(dx, 0.6, 1.4), _ramp(dy, 1.1, 1.9))
    return face * edge[..., None] + mortar * (1.0 - edge[..., None])


def brick_normal(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The tangent-space normal map of :func:`brick` (glTF: x right, y up the image, z out;
    stored (n + 1) / 2): the mortar lies back, the bricks' edges are bevelled."""
    h = _brick_height(x, y) * 2.5  # pixels of relief per unit of height
    # central differences that wrap: the image repeats, so the slope at its edge is continuous
    right = (np.roll(h, -1, axis=1) - np.roll(h, 1, axis=1)) / 2.0
    down = (np.roll(h, -1, axis=0) - np.roll(h, 1, axis=0)) / 2.0
    n = np.stack([-right, down, np.ones_like(h)], axis=-1)  # up the image is -down
    n /= np.sqrt((n * n).sum(axis=-1))[..., None]
    return (n + 1.0) * 127.5


# ---- render -----------------------------------------------------------------------------------


def render(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Warm off-white render (plaster): soft blotches and a fine trowelled grain."""
    blotch = _fbm(x, y, 11, cells=(128, 64, 32))
    grain = _fbm(x, y, 12, cells=(8, 4, 2))
    shade = 1.0 + 0.07 * blotch + 0.035 * grain
    return np.array((226.0, 214.0, 190.0)) * shade[..., None]


# ---- window -----------------------------------------------------------------------------------


def window(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """A casement window filling the image: a white frame 16 pixels wide, a mullion down the
    middle and a transom a third down, four panes of glass reflecting a pale sky.  Stretched
    once over an opening (``setupProjection(0, scope.xy, '1, '1)``); repeated, the frames of
    neighbours meet edge to edge."""
    xs, ys = x % SIZE, y % SIZE
    frame_w, bar = 16, 5  # pixels: outer frame, half the mullion and transom
    transom = SIZE // 3
    border = np.minimum(np.minimum(xs, SIZE - 1 - xs), np.minimum(ys, SIZE - 1 - ys))
    in_frame = border < frame_w
    in_bar = (np.abs(xs - (SIZE - 1) / 2.0) < bar) | (np.abs(ys - transom) < bar)
    # glass: a sky gradient, lighter towards the top, with a diagonal sheen and the room's dark
    t = ys / (SIZE - 1.0)
    glass = _mix((150, 178, 196), (58, 74, 88), t)
    sheen = _ramp(np.abs(((xs + ys) % 96) - 48.0), 30.0, 44.0) * 0.12
    glass = glass * (1.0 + sheen)[..., None]
    frame = np.array((236.0, 234.0, 226.0)) * (1.0 + 0.03 * _fbm(x, y, 21, cells=(8, 4)))[..., None]
    # a shadow line where the glass meets the frame (the frame stands proud of the glass)
    edge = np.minimum(
        border - frame_w, np.minimum(np.abs(xs - (SIZE - 1) / 2.0), np.abs(ys - transom)) - bar
    )
    glass = glass * (0.7 + 0.3 * _ramp(edge, 0.0, 3.0))[..., None]
    solid = in_frame | in_bar
    return np.where(solid[..., None], frame, glass)


# ---- roof tiles -------------------------------------------------------------------------------

TILE_ROWS, TILES = 8, 8  # per image: tiles of 32 x 32 pixels, rows overlapping downwards


def roof_tiles(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Clay plain tiles in staggered rows, up the image towards the ridge: each row's lower edge
    laps over the row below and shades its top; thin dark gaps between neighbours."""
    th, tw = SIZE // TILE_ROWS, SIZE // TILES
    row = (y + th // 2) // th  # rows end 16 pixels from the image's edge
    ly = (y + th // 2) % th + 0.5  # 0.5 at a row's top .. 31.5 at its lower edge
    xs = x - np.where(row % 2 == 0, tw // 4, 3 * tw // 4)
    col = xs // tw
    lx = xs % tw + 0.5
    tone = _hash(col % TILES, row % TILE_ROWS, 31)
    base = _mix((176, 84, 52), (132, 60, 40), tone)
    # lighter towards the lower edge (it catches the light), shaded under the row above
    light = 0.78 + 0.3 * (ly / th) - 0.3 * (1.0 - _ramp(ly, 0.0, 5.0))
    gap = 1.0 - 0.55 * (1.0 - _ramp(np.minimum(lx, tw - lx), 0.5, 1.6))
    grain = 1.0 + 0.1 * _fbm(x, y, 33, cells=(32, 16, 8, 4))
    return base * (light * gap * grain)[..., None]


# ---- drawing and writing ----------------------------------------------------------------------

TEXTURES: dict[str, Callable[[np.ndarray, np.ndarray], np.ndarray]] = {
    "brick": brick,
    "brick_normal": brick_normal,
    "render": render,
    "window": window,
    "roof_tiles": roof_tiles,
}


def draw(name: str, x0: int = 0, y0: int = 0) -> np.ndarray:
    """(SIZE, SIZE, 3) uint8 pixels of texture ``name``, rows from the image's top, drawn from
    pixel (x0, y0) on (an offset of a whole image draws the same pixels: it repeats)."""
    y, x = np.mgrid[y0 : y0 + SIZE, x0 : x0 + SIZE]
    rgb = TEXTURES[name](x.astype(np.int64), y.astype(np.int64))
    return np.clip(np.rint(rgb), 0, 255).astype(np.uint8)


def png_bytes(pixels: np.ndarray) -> bytes:
    from PIL import Image

    out = io.BytesIO()
    Image.fromarray(pixels, "RGB").save(out, format="PNG", optimize=True)
    return out.getvalue()


def write_all(folder: Path = FOLDER) -> list[Path]:
    """Draw every texture into ``folder`` as NAME.png (written atomically); the paths."""
    from bgr.formats.atomic import atomic_files

    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for name in TEXTURES:
        path = folder / f"{name}.png"
        with atomic_files([path]) as (f,):
            f.write(png_bytes(draw(name)))
        paths.append(path)
    return paths


if __name__ == "__main__":
    for written in write_all():
        print(f"{written}  {written.stat().st_size:,} bytes")
