"""The user's outline of the target building in a photograph (``--silhouette SIL``).

Single-photo inverse modelling (Nishida et al. 2018) fits a building's mass to its silhouette,
so the silhouette is the one thing the user must give: a JSON polygon of pixel points or a mask
image.  This module reads either into a :class:`Silhouette` that the fitter rasterises at the
scale it works at, and refuses, with a located message, every input that would make the fit
meaningless (too few points, a self-crossing outline, a mask of several buildings, a mask of
the whole photograph) instead of fitting nonsense or failing with a traceback.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field
from json.decoder import JSONDecodeError
from typing import Any

import numpy as np

from bgr.grammar.errors import BgrError, Diagnostic

# Points outside the photograph by at most this share of its width (height) are the user's
# slack when clicking the border, clipped onto it; farther ones are a wrong photo or wrong units.
OUTSIDE_TOLERANCE = 0.02
# A mask's other parts smaller than this share of the largest are specks of a brush, dropped.
SPECK_SHARE = 0.02
# A silhouette covering this share of the photograph leaves no background to fit against.
WHOLE_SHARE = 0.98
# A mask of another size is resized when its aspect ratio is within this share of the photo's.
ASPECT_TOLERANCE = 0.01
MAX_POINTS = 100_000  # an outline drawn by a person has tens of points; more is no outline
MAX_JSON_BYTES = 32 * 2**20

_POINT_HINT = "give a JSON list of [x, y] pixel points, e.g. [[10, 5], [90, 5], [90, 60]]"


@dataclass(frozen=True)
class Silhouette:
    """The building's outline in photo pixels (origin top-left, x right, y down).

    ``polygon`` is the (n, 2) float outline a JSON file gave (closed implicitly), or None when
    a mask image gave it; then ``_mask`` holds the mask at the photograph's size.  Both kinds
    answer :meth:`mask` and :meth:`outline` at any scale, so that the fitter may work on a
    reduced photograph without caring which kind the user drew.
    """

    size: tuple[int, int]  # (width, height) of the photograph
    polygon: np.ndarray | None = None
    _mask: np.ndarray | None = field(default=None, repr=False)

    def mask(self, width: int | None = None, height: int | None = None) -> np.ndarray:
        """(height, width) bool: True inside the building, the photograph scaled to that size
        (its own size by default; one of the two gives the other by the photo's aspect)."""
        from PIL import Image

        width, height = _scale_size(self.size, width, height)
        if self.polygon is not None:
            scale = np.array([width / self.size[0], height / self.size[1]])
            return _fill(self.polygon * scale, width, height)
        assert self._mask is not None
        if (width, height) == self.size:
            return self._mask.copy()
        image = Image.fromarray(self._mask.astype(np.uint8) * 255)
        return np.asarray(image.resize((width, height), Image.Resampling.NEAREST)) > 0

    def outline(self, width: int | None = None, height: int | None = None) -> np.ndarray:
        """(height, width) bool: the 1-pixel inner boundary of :meth:`mask` at that size (the
        mask less its erosion), what an edge-based fit compares with the model's contour."""
        from scipy import ndimage

        inside = self.mask(width, height)
        # pixels on the photograph's border count as boundary: the erosion treats the outside
        # of the image as background
        return inside & ~ndimage.binary_erosion(inside, border_value=0)

    @property
    def bbox(self) -> tuple[float, float, float, float]:
        """(x0, y0, x1, y1) in photo pixels: the outline's extent (a mask's, as pixel edges)."""
        if self.polygon is not None:
            (x0, y0), (x1, y1) = self.polygon.min(axis=0), self.polygon.max(axis=0)
            return float(x0), float(y0), float(x1), float(y1)
        assert self._mask is not None
        rows, cols = np.nonzero(self._mask)
        return float(cols.min()), float(rows.min()), float(cols.max() + 1), float(rows.max() + 1)

    @property
    def area(self) -> float:
        """The building's area in photo pixels²."""
        if self.polygon is not None:
            x, y = self.polygon[:, 0], self.polygon[:, 1]
            return float(abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))) / 2)
        assert self._mask is not None
        return float(self._mask.sum())


def _fill(ring: np.ndarray, width: int, height: int) -> np.ndarray:
    """The polygon ``ring`` (pixel positions, pixel i spanning [i, i + 1)) drawn filled by
    Pillow, its outline included: the convention the fit draws a model's silhouette with
    (``outline.draw``), so that a model matching the outline exactly matches its mask too."""
    from PIL import Image, ImageDraw

    canvas = Image.new("1", (width, height), 0)
    # ImageDraw puts coordinate i at pixel i's centre, hence the half pixel
    points = [(x, y) for x, y in np.round(ring - 0.5, 2).tolist()]
    ImageDraw.Draw(canvas).polygon(points, fill=1, outline=1)
    return np.asarray(canvas, dtype=bool)


def _scale_size(size: tuple[int, int], width: int | None, height: int | None) -> tuple[int, int]:
    if width is None and height is None:
        return size
    if width is None:
        assert height is not None
        width = max(1, round(size[0] * height / size[1]))
    if height is None:
        height = max(1, round(size[1] * width / size[0]))
    if width < 1 or height < 1:
        raise ValueError(f"a mask of {width} x {height} pixels")
    return int(width), int(height)


def read_silhouette(path: str, size: tuple[int, int]) -> Silhouette:
    """The silhouette in ``path`` for a photograph of ``size`` = (width, height) pixels.

    A JSON list of [x, y] points (or ``{"points": [...]}``), or a mask image of the
    photograph's size (or its aspect ratio, resized) whose white/nonzero pixels are the
    building.  Which one is decided by the bytes, not the name: a mask saved as ``.json`` or
    points saved as ``.txt`` still read.  Anything else is a located :class:`BgrError`.
    """
    from bgr.grammar.paths import read_input

    path = str(path)  # a pathlib.Path too
    try:
        data = read_input(path, "silhouette")
    except FileNotFoundError:
        raise BgrError(Diagnostic(path, 0, 0, "no such file", "check the path")) from None
    except OSError as exc:
        raise BgrError(
            Diagnostic(path, 0, 0, f"cannot read the silhouette: {exc.strerror or exc}", "")
        ) from None
    width, height = int(size[0]), int(size[1])
    if width < 1 or height < 1:
        raise ValueError(f"a photograph of {width} x {height} pixels")
    head = data.lstrip(b"\xef\xbb\xbf \t\r\n")[:1]
    if head in (b"[", b"{"):
        return _read_points(path, data, (width, height))
    image_error = _image_error(data)
    if image_error is None:
        return _read_mask(path, data, (width, height))
    if path.lower().endswith(".json") or (data and _is_text(data)):
        return _read_points(path, data, (width, height))  # its JSON error says where
    raise BgrError(
        Diagnostic(
            path,
            0,
            0,
            f"the silhouette is neither JSON points nor an image ({image_error})",
            _POINT_HINT + ", or a mask PNG of the photograph's size, white on the building",
        )
    )


def _is_text(data: bytes) -> bool:
    try:
        text = data[:4096].decode("utf-8")
    except UnicodeDecodeError as exc:
        return exc.start > 4000  # a character cut at the end of the sample
    return all(c.isprintable() or c in "\t\r\n" for c in text)


def _image_error(data: bytes) -> str | None:
    """None when Pillow recognises ``data`` as an image (it is decoded later), else why not."""
    from PIL import UnidentifiedImageError

    from bgr.grammar.textures import open_image

    try:
        with open_image(data):
            return None
    except UnidentifiedImageError:
        return "Pillow reads no image from it"
    except Exception as exc:  # Pillow raises many kinds for broken headers
        return str(exc) or type(exc).__name__


# --- JSON points -------------------------------------------------------------------------


class _Located(list):
    """A JSON array with the string offset of itself and of each of its elements."""

    start: int = 0
    starts: list[int]


def _located_array(s_and_end: tuple[str, int], scan_once: Any) -> tuple[_Located, int]:
    """json.decoder.JSONArray that also records where each element starts: the standard
    decoder keeps no positions, and a message about point 317 should point at it."""
    s, end = s_and_end
    values = _Located()
    values.start = end - 1
    values.starts = []
    end = _skip(s, end)
    if s[end : end + 1] == "]":
        return values, end + 1
    while True:
        values.starts.append(end)
        try:
            value, end = scan_once(s, end)
        except StopIteration as err:
            raise JSONDecodeError("Expecting value", s, err.value) from None
        values.append(value)
        if len(values) > MAX_POINTS:
            raise JSONDecodeError(f"more than {MAX_POINTS:,} values in one list", s, end)
        end = _skip(s, end)
        nextchar = s[end : end + 1]
        end += 1
        if nextchar == "]":
            return values, end
        if nextchar != ",":
            raise JSONDecodeError("Expecting ',' delimiter", s, end - 1)
        end = _skip(s, end)
        if s[end : end + 1] == "]":
            raise JSONDecodeError("Illegal trailing comma before end of array", s, end)


_WHITESPACE = re.compile(r"[ \t\n\r]*")


def _skip(text: str, offset: int) -> int:
    """The offset of the first character at or after ``offset`` that is not JSON whitespace."""
    found = _WHITESPACE.match(text, offset)
    return found.end() if found else offset


def _decode(path: str, text: str) -> Any:
    from json.scanner import py_make_scanner  # type: ignore[attr-defined]

    decoder = json.JSONDecoder(parse_int=float)  # no int-digits limit: "1" * 5000 is inf
    decoder.parse_array = _located_array  # type: ignore[attr-defined]
    # the C scanner parses arrays itself, ignoring parse_array: the Python one calls it
    decoder.scan_once = py_make_scanner(decoder)  # type: ignore[attr-defined]
    try:
        value, end = decoder.raw_decode(text, _skip(text, 0))
        rest = _skip(text, end)
        if rest != len(text):
            raise JSONDecodeError("Extra data after the points", text, rest)
    except JSONDecodeError as exc:
        raise BgrError(
            Diagnostic(
                path,
                exc.lineno,
                exc.colno,
                f"the silhouette is not valid JSON: {exc.msg}",
                _POINT_HINT,
                source_line=_line(text, exc.lineno),
            )
        ) from None
    except RecursionError:
        raise BgrError(
            Diagnostic(path, 0, 0, "the silhouette's JSON is nested too deeply", _POINT_HINT)
        ) from None
    return value


def _line(text: str, lineno: int) -> str:
    lines = text.splitlines()
    return lines[lineno - 1] if 0 < lineno <= len(lines) else ""


def _where(text: str, offset: int) -> tuple[int, int]:
    line = text.count("\n", 0, offset) + 1
    return line, offset - text.rfind("\n", 0, offset)


def _read_points(path: str, data: bytes, size: tuple[int, int]) -> Silhouette:
    if len(data) > MAX_JSON_BYTES:
        raise BgrError(
            Diagnostic(
                path,
                0,
                0,
                f"the silhouette is {len(data):,} bytes: more than {MAX_JSON_BYTES:,} of points",
                "an outline needs tens of points",
            )
        )
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        column = exc.start - data.rfind(b"\n", 0, exc.start)
        raise BgrError(
            Diagnostic(path, line, column, "the silhouette is not UTF-8 text", _POINT_HINT)
        ) from None

    def fail(offset: int, message: str, hint: str = _POINT_HINT) -> BgrError:
        line, column = _where(text, offset)
        return BgrError(Diagnostic(path, line, column, message, hint, _line(text, line)))

    value = _decode(path, text)
    if isinstance(value, dict):
        if "points" not in value:
            raise fail(0, 'the silhouette\'s JSON object has no "points"')
        value = value["points"]
        if not isinstance(value, _Located):
            raise fail(0, 'the silhouette\'s "points" is not a list of [x, y] points')
    if not isinstance(value, _Located):
        raise fail(0, f"the silhouette's JSON is {_kind(value)}, not a list of [x, y] points")
    points: list[tuple[float, float]] = []
    offsets: list[int] = []
    for i, (point, start) in enumerate(zip(value, value.starts, strict=True)):
        if not isinstance(point, _Located) or len(point) != 2:
            what = f"{len(point)} values" if isinstance(point, list) else _kind(point)
            raise fail(start, f"point {i + 1} is {what}, not [x, y]")
        xy = []
        for coordinate, at, axis in zip(point, point.starts, "xy", strict=True):
            if isinstance(coordinate, bool) or not isinstance(coordinate, (int, float)):
                raise fail(at, f"point {i + 1}'s {axis} is {_kind(coordinate)}, not a number")
            if not math.isfinite(coordinate):
                raise fail(at, f"point {i + 1}'s {axis} is {coordinate}: not a finite number")
            xy.append(float(coordinate))
        points.append((xy[0], xy[1]))
        offsets.append(start)
    return _polygon(path, points, offsets, value.start, size, fail)


def _kind(value: Any) -> str:
    """What a JSON value is, as a message names it: "true", "a string", "an object"."""
    if isinstance(value, bool) or value is None:
        return json.dumps(value)
    if isinstance(value, list):
        return "a list"
    if isinstance(value, dict):
        return "an object"
    if isinstance(value, str):
        return "a string"
    return "a number"


def _polygon(
    path: str,
    points: list[tuple[float, float]],
    offsets: list[int],
    list_start: int,
    size: tuple[int, int],
    fail: Any,
) -> Silhouette:
    """The checked, clipped polygon of the points: each check the fit's geometry needs."""
    import shapely

    width, height = size
    tol_x, tol_y = OUTSIDE_TOLERANCE * width, OUTSIDE_TOLERANCE * height
    for i, ((x, y), at) in enumerate(zip(points, offsets, strict=True)):
        if not (-tol_x <= x <= width + tol_x and -tol_y <= y <= height + tol_y):
            raise fail(
                at,
                f"point {i + 1} ({x:g}, {y:g}) is outside the {width} x {height} photograph",
                "points are pixels of the photograph, origin top-left, x right, y down; "
                "a point may be off its border by 2 % (clipped onto it), no more",
            )
    clipped = [(min(max(x, 0.0), width), min(max(y, 0.0), height)) for x, y in points]
    # a repeated point (the first given again as the last, a double click) adds no corner
    kept: list[tuple[float, float]] = []
    kept_at: list[int] = []
    for point, at in zip(clipped, offsets, strict=True):
        if not kept or point != kept[-1]:
            kept.append(point)
            kept_at.append(at)
    if len(kept) > 1 and kept[0] == kept[-1]:
        kept.pop()
        kept_at.pop()
    if len(kept) < 3:
        raise fail(
            list_start,
            f"the silhouette has {len(kept)} distinct point{'s' * (len(kept) != 1)}: "
            "an outline needs at least 3",
        )
    ring = np.array(kept, dtype=float)
    polygon = shapely.Polygon(ring)
    area = float(polygon.area)
    if float(polygon.convex_hull.area) < 1.0:
        raise fail(
            list_start,
            f"the silhouette's polygon encloses {area:g} pixels²: no area",
            "the points lie on one line (or within a pixel); outline the building's corners",
        )
    reason = str(shapely.is_valid_reason(polygon))
    if reason != "Valid Geometry":
        at = list_start
        number = r"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)"
        found = re.search(rf"\[\s*{number}\s+{number}\s*\]", reason)
        where = ""
        if found:
            cx, cy = float(found[1]), float(found[2])
            where = f" at ({cx:.1f}, {cy:.1f})"
            # point at the edge that crosses there: the nearest segment's first point
            segments = [
                shapely.LineString([ring[k], ring[(k + 1) % len(ring)]]) for k in range(len(ring))
            ]
            cross = shapely.Point(cx, cy)
            nearest = min(range(len(ring)), key=lambda k: segments[k].distance(cross))
            at = kept_at[nearest]
        what = (
            "crosses itself"
            if reason.startswith(("Self-intersection", "Ring Self"))
            else "is invalid"
        )
        raise fail(
            at,
            f"the silhouette's polygon {what}{where} ({reason.split('[')[0].strip()})",
            "give the points in order around the building, each corner once",
        )
    if area < 1.0:
        raise fail(list_start, f"the silhouette's polygon encloses {area:g} pixels²: no area")
    if area >= WHOLE_SHARE * width * height:
        raise fail(
            list_start,
            f"the silhouette covers {area / (width * height):.0%} of the photograph",
            "outline the building only: the fit needs background around it",
        )
    return Silhouette((width, height), polygon=ring)


# --- mask images -------------------------------------------------------------------------


def _read_mask(path: str, data: bytes, size: tuple[int, int]) -> Silhouette:
    from PIL import Image

    from bgr.grammar.textures import open_image

    width, height = size

    def fail(message: str, hint: str) -> BgrError:
        return BgrError(Diagnostic(path, 0, 0, message, hint))

    try:
        with open_image(data) as image:
            image.load()
            inside = _mask_pixels(image)
    except Exception as exc:  # a truncated or corrupt image fails only when decoded
        raise fail(
            f"cannot read the silhouette mask: {exc or type(exc).__name__}",
            "give a PNG of the photograph's size, white on the building, black elsewhere",
        ) from None
    mh, mw = inside.shape
    if (mw, mh) != (width, height):
        aspect, photo = mw / mh, width / height
        if abs(aspect / photo - 1) > ASPECT_TOLERANCE:
            raise fail(
                f"the silhouette mask is {mw} x {mh} pixels, the photograph {width} x {height}",
                "draw the mask over the photograph itself, at its size or scaled with it",
            )
        resized = Image.fromarray(inside.astype(np.uint8) * 255).resize(
            (width, height), Image.Resampling.NEAREST
        )
        inside = np.asarray(resized) > 0
    return Silhouette((width, height), _mask=_one_part(inside, fail))


def _mask_pixels(image: Any) -> np.ndarray:
    """True where the mask marks the building.  An alpha channel that varies is the mask (a
    building painted on a transparent layer, whatever its colour); otherwise the brightest
    pixels are: above half the brightest value, so that 0/1, 0/255 and 0/65535 masks and a
    JPEG's noisy white all read the same."""
    has_alpha = image.mode in ("RGBA", "LA", "PA", "La", "RGBa") or (
        image.mode == "P" and "transparency" in image.info
    )
    if has_alpha:
        alpha = np.asarray(image.convert("RGBA"))[..., 3]
        if alpha.min() != alpha.max():
            return alpha > 127
    if image.mode in ("1", "L", "I", "I;16", "I;16B", "I;16L", "F"):
        values = np.asarray(image).astype(np.float64)
    else:
        values = np.asarray(image.convert("RGB")).max(axis=2).astype(np.float64)
    values = np.nan_to_num(values, nan=0.0)
    top = float(values.max())
    if values.ndim != 2 or top <= 0:
        return np.zeros(values.shape[:2], dtype=bool)
    return values > top / 2


def _one_part(inside: np.ndarray, fail: Any) -> np.ndarray:
    """The mask's one building: its holes filled (a silhouette has none), specks dropped; a
    located refusal for an empty mask, several buildings, or the whole photograph."""
    from scipy import ndimage

    hint = "paint the one target building white on black"
    if not inside.any():
        raise fail("the silhouette mask is empty: no pixel marks the building", hint)
    labels, count = ndimage.label(inside, structure=np.ones((3, 3), dtype=bool))
    sizes = np.bincount(labels.ravel())[1:]
    largest = int(np.argmax(sizes))
    big = [k for k in range(count) if k != largest and sizes[k] >= SPECK_SHARE * sizes[largest]]
    if big:
        boxes = ndimage.find_objects(labels)
        parts = []
        for k in [largest, *big][:5]:
            ys, xs = boxes[k]
            x_range, y_range = f"{xs.start}-{xs.stop - 1}", f"{ys.start}-{ys.stop - 1}"
            parts.append(f"{int(sizes[k]):,} pixels at x {x_range}, y {y_range}")
        more = f" and {len(big) + 1 - len(parts)} more" if len(big) + 1 > len(parts) else ""
        raise fail(
            f"the silhouette mask has {len(big) + 1} separate parts: {'; '.join(parts)}{more}",
            "a silhouette is one building: join its parts or erase the others "
            f"(parts under {SPECK_SHARE:.0%} of the largest are ignored)",
        )
    kept = ndimage.binary_fill_holes(labels == largest + 1)
    share = float(kept.mean())
    if share >= WHOLE_SHARE:
        raise fail(
            f"the silhouette mask covers {share:.0%} of the photograph",
            "outline the building only (white on black): the fit needs background around it; "
            "an inverted mask reads as the whole photograph",
        )
    return np.asarray(kept, dtype=bool)
