"""The OBJ reader of ``bgr infer --kind city``: ``v`` and ``f`` lines, in objects.

An OBJ is read in bulk by numpy where its lines are plain (:func:`_bulk`), and line by line
where they are not, so that an error names its line and column (:class:`ObjText`).  Objects are
its ``o`` objects, else its ``g`` groups, else none (the connected components make them);
polygons are fanned where convex and cut by earcut where not (:func:`triangulate`).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from bgr.grammar.errors import BgrError, Diagnostic

from .coordinates import check_coordinates
from .model import CityObject
from .read_scene import Found, _template

_TOKEN = re.compile(r"\S+")
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?", re.ASCII)
_NOT_FINITE = re.compile(r"[+-]?(?:nan|inf|infinity)", re.IGNORECASE)
_INDEX = re.compile(r"([+-]?\d+)(?:/\S*)?", re.ASCII)  # i, i/t, i//n, i/t/n: only i is read
_COMMENT = re.compile(rb"#[^\n]*")
VERTEX_WIDTHS = (3, 4, 6)  # x y z, x y z w, x y z r g b
OBJ_VERTEX = "`v x y z`, optionally followed by `r g b`"
NEWLINE, BLANKS = 10, (32, 9)


class ObjText:
    """An OBJ file as bytes, and where each line starts (after any leading blanks) and ends:
    the bulk parsers read whole kinds of lines at once from it, the line-by-line parsers and
    messages decode single lines."""

    def __init__(self, shown: str, data: bytes) -> None:
        if b"\r" in data:  # CRLF and lone CR end lines too (as errors.source_lines counts them)
            data = data.replace(b"\r\n", b"\n").replace(b"\r", b"\n")
        self.shown, self.data = shown, data
        self.buf = np.frombuffer(data + b"\n\n", dtype=np.uint8)  # two bytes past every line
        ends = np.flatnonzero(self.buf == NEWLINE)[:-1]
        self.ends = ends  # (lines,) the newline ending each line (the last: padding)
        self.starts = np.concatenate([[0], ends[:-1] + 1]).astype(np.int64)
        lead = np.isin(self.buf[self.starts], BLANKS)
        for i in np.flatnonzero(lead).tolist():  # rare: indented lines
            s = int(self.starts[i])
            while self.buf[s] in BLANKS:
                s += 1
            self.starts[i] = s

    def lines_of(self, keyword: str) -> np.ndarray:
        """The (0-based) lines whose first word is ``keyword`` (one character)."""
        first, second = self.buf[self.starts], self.buf[self.starts + 1]
        return np.flatnonzero(
            (first == ord(keyword)) & ((second == NEWLINE) | np.isin(second, BLANKS))
        )

    def line(self, i: int) -> str:
        """Line ``i`` as text, as the file has it (leading blanks too)."""
        start = int(self.ends[i - 1]) + 1 if i else 0
        return self.data[start : int(self.ends[i])].decode("utf-8", errors="replace")

    def rests(self, rows: np.ndarray) -> np.ndarray:
        """The bytes of the lines ``rows`` after their one-character keyword, each with its
        newline: every line is two runs of bytes, (blanks and) keyword, then the rest, kept
        or not."""
        begins = np.concatenate([[0], self.ends[:-1] + 1])
        runs = np.stack([self.starts + 1 - begins, self.ends + 1 - self.starts - 1], axis=1)
        keep = np.zeros(runs.shape, dtype=bool)
        keep[rows, 1] = True
        mask = np.repeat(keep.reshape(-1), runs.reshape(-1))
        return self.buf[: len(mask)][mask]

    def error(self, line: int, token: int | None, message: str, hint: str | None = None):
        """A BgrError at a line (0-based) and token (0 the keyword; None: after the last)."""
        return BgrError(Diagnostic(self.shown, line + 1, self.column(line, token), message, hint))

    def column(self, line: int, token: int | None) -> int:
        text = self.line(line).split("#", 1)[0]
        starts = [m.start() + 1 for m in _TOKEN.finditer(text)]
        if token is None or token >= len(starts):
            return len(text.rstrip()) + 1 if text.strip() else 1
        return starts[token]

    def tokens(self, i: int) -> list[str]:
        """The words of line ``i`` after its keyword, its comment left out."""
        return self.line(i).split("#", 1)[0].split()[1:]


@dataclass
class ObjParse:
    """The numbers of an OBJ's ``v`` and ``f`` lines: what the bulk and the line-by-line
    parsers both produce."""

    numbers: np.ndarray  # float64, every number of every v line
    widths: np.ndarray  # (V,) how many numbers each v line has
    indices: np.ndarray  # int64, every vertex index of every f line, as written
    sizes: np.ndarray  # (P,) how many vertices each f line has


def _read_obj(shown: str, data: bytes) -> Found:
    """An OBJ's faces, in objects (``o``), else groups (``g``), else none (components)."""
    obj = ObjText(shown, data)
    v_lines, f_lines = obj.lines_of("v"), obj.lines_of("f")
    parsed = _obj_numbers(obj, v_lines, f_lines)
    vertices, rgb = _obj_vertices(parsed)
    if not len(f_lines):
        hint = f"it has {len(v_lines)} vertices and no `f` lines" if len(v_lines) else None
        hint = hint or ("the file is empty" if not data.strip() else "it has no `v` or `f` lines")
        raise BgrError(Diagnostic(shown, 0, 0, f"no triangles in {shown}", hint))
    corners = _obj_corners(obj, parsed, v_lines, f_lines)

    def locate(vertex: int, axis: int, message: str, hint: str) -> BgrError:
        return obj.error(int(v_lines[vertex]), axis + 1, message, hint)

    check_coordinates(shown, vertices, corners, None, [], locate)  # before any arithmetic
    faces, polygon = triangulate(vertices, parsed.sizes, corners)
    colors = None if rgb is None else _face_colors(rgb, faces)
    owner, objects = _obj_objects(obj, f_lines[polygon])

    return Found(vertices, faces, colors, owner, objects, locate=locate)


def _obj_numbers(obj: ObjText, v_lines: np.ndarray, f_lines: np.ndarray) -> ObjParse:
    """The numbers of the v and f lines, in bulk; a line-by-line pass where the bulk one meets
    anything unusual, which either finds the error (and its column) or reads what bulk could
    not."""
    numbers, widths = _bulk(obj.rests(v_lines), len(v_lines), float)
    if (
        numbers is None
        or not np.isin(widths, VERTEX_WIDTHS).all()
        or not np.isfinite(numbers).all()
    ):
        numbers, widths = _vertex_lines(obj, v_lines)
    indices, sizes = _bulk(obj.rests(f_lines), len(f_lines), int)
    if indices is None or (sizes < 3).any():
        indices, sizes = _face_lines(obj, f_lines)
    return ObjParse(numbers, widths, indices, sizes)


def _bulk(raw: np.ndarray, n: int, kind: type) -> tuple[np.ndarray | None, np.ndarray]:
    """(every number of ``n`` lines (bytes, ``raw``), how many words each line has), read at
    once by numpy; None for the numbers when they are not all plain numbers (then the
    line-by-line parser decides).  Of a vertex index ``i/t/n`` only ``i`` is kept."""
    if (raw == ord("#")).any():
        raw = np.frombuffer(_COMMENT.sub(b"", raw.tobytes()), dtype=np.uint8)
    blank = raw <= 32
    word = ~blank
    word[1:] &= blank[:-1]  # the first byte of each word
    counts = np.bincount(
        np.searchsorted(np.flatnonzero(raw == NEWLINE), np.flatnonzero(word)), minlength=n
    ).astype(np.int64)
    total = int(counts.sum())
    dtype = np.int64 if kind is int else np.float64
    if total == 0:  # numpy reads a blank string as one number
        return np.zeros(0, dtype=dtype), counts
    if raw.max() > 127:  # numpy would read some non-ASCII digits; the line parser refuses them
        return None, counts
    pick = None
    if kind is int:
        # every field between blanks and slashes is a number; a word's first field is its index
        slash = raw == ord("/")
        cut = blank | slash
        field = ~cut
        field[1:] &= cut[:-1]
        if (word & slash).any():  # a word starting with "/" has no vertex index
            return None, counts
        # numpy reads a lone sign as 0, and "- 1" as -1: a sign must start a field, a digit next
        sign = np.flatnonzero((raw == ord("-")) | (raw == ord("+")))
        after = raw[np.minimum(sign + 1, len(raw) - 1)]
        if not (field[sign] & (after >= ord("0")) & (after <= ord("9"))).all():
            return None, counts
        if slash.any():
            pick = np.flatnonzero(word[field])
            raw = np.where(slash, np.uint8(32), raw)
            total = int(field.sum())
    try:
        values = np.fromstring(raw.tobytes(), dtype=dtype, sep=" ")
    except ValueError:
        return None, counts
    if len(values) != total:
        return None, counts
    return (values if pick is None else values[pick]), counts


def _last_line(obj: ObjText) -> int:
    """The last line that is not blank (where a file cut short ends)."""
    filled = np.flatnonzero(obj.buf[obj.starts] != NEWLINE)
    return int(filled[-1]) if len(filled) else 0


def _vertex_lines(obj: ObjText, v_lines: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The v lines one at a time: the first one that is not 3, 4 or 6 finite numbers is an
    error at its line and column."""
    numbers: list[float] = []
    widths = []
    last = _last_line(obj)
    for i in v_lines.tolist():
        tokens = obj.tokens(i)
        for j, token in enumerate(tokens, start=1):
            number = _NUMBER.fullmatch(token) is not None
            if _NOT_FINITE.fullmatch(token) or (number and not math.isfinite(float(token))):
                raise obj.error(
                    i,
                    j,
                    "a vertex coordinate is not a finite number",
                    "NaN and infinity place nothing: the exporter wrote a point it could not place",
                )
            if not number:
                raise obj.error(i, j, "a vertex coordinate is not a number", OBJ_VERTEX)
        if len(tokens) < 3:
            cut = " (the file may be cut short)" if i == last else ""
            raise obj.error(
                i,
                None,
                f"a vertex needs three coordinates, this one has {len(tokens)}{cut}",
                OBJ_VERTEX,
            )
        if len(tokens) not in VERTEX_WIDTHS:
            raise obj.error(
                i,
                5 if len(tokens) == 5 else 7,
                f"a vertex of {len(tokens)} numbers: 3, 4 (x y z w) or 6 (x y z r g b) expected",
                OBJ_VERTEX,
            )
        numbers += map(float, tokens)
        widths.append(len(tokens))
    return np.array(numbers, dtype=np.float64), np.array(widths, dtype=np.int64)


def _face_lines(obj: ObjText, f_lines: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The f lines one at a time: the first one that is not three or more vertex indices
    (``i``, ``i/t``, ``i//n``, ``i/t/n``) is an error at its line and column."""
    indices: list[int] = []
    sizes = []
    for i in f_lines.tolist():
        tokens = obj.tokens(i)
        for j, token in enumerate(tokens, start=1):
            match = _INDEX.fullmatch(token)
            if match is None:
                raise obj.error(
                    i, j, "not a vertex index", "a face corner is `i`, `i/t`, `i//n` or `i/t/n`"
                )
            index = int(match.group(1))
            indices.append(max(min(index, 2**62), -(2**62)))  # beyond any file: out of range
        if len(tokens) < 3:
            raise obj.error(
                i,
                None,
                f"a face needs at least three vertices, this one has {len(tokens)}",
                "`f i j k ...`: a line cut short, or a line (`l`) written as a face",
            )
        sizes.append(len(tokens))
    return np.array(indices, dtype=np.int64), np.array(sizes, dtype=np.int64)


def _obj_vertices(parsed: ObjParse) -> tuple[np.ndarray, np.ndarray | None]:
    """(V, 3) positions, and (V, 3) colours in 0..1 when every v line has ``r g b``."""
    widths = parsed.widths
    if len(widths) and (widths == widths[0]).all():
        rows = parsed.numbers.reshape(len(widths), int(widths[0]))
    else:
        starts = np.cumsum(widths) - widths
        rows = parsed.numbers[starts[:, None] + np.arange(3)]
    vertices = np.ascontiguousarray(rows[:, :3], dtype=np.float64)
    if not len(widths) or not (widths == 6).all():
        return vertices, None
    rgb = rows[:, 3:6]
    return vertices, rgb / 255.0 if rgb.max(initial=0.0) > 1.0 else rgb


def _obj_corners(
    obj: ObjText, parsed: ObjParse, v_lines: np.ndarray, f_lines: np.ndarray
) -> np.ndarray:
    """Every face corner as a 0-based vertex number.  Negative indices count back from the
    last vertex above the face; positive ones may name vertices further down (readers allow
    it); 0 and numbers beyond the file's vertices are errors at their line and column."""
    raw = parsed.indices
    above = np.repeat(np.searchsorted(v_lines, f_lines), parsed.sizes)
    corners = np.where(raw < 0, above + raw, raw - 1)
    bad = (raw == 0) | (corners < 0) | (corners >= len(v_lines))
    if not bad.any():
        return corners
    k = int(np.argmax(bad))
    ends = np.cumsum(parsed.sizes)
    polygon = int(np.searchsorted(ends, k, side="right"))
    token = k - int(ends[polygon] - parsed.sizes[polygon]) + 1
    line, value = int(f_lines[polygon]), int(raw[k])
    if value == 0:
        raise obj.error(line, token, "a vertex index is 0", "OBJ counts vertices from 1")
    if value < 0:
        raise obj.error(
            line,
            token,
            f"vertex index {value} reaches before the first vertex",
            f"a negative index counts back from the last vertex above the face: "
            f"{int(above[k])} are above this line",
        )
    raise obj.error(
        line,
        token,
        f"vertex index {value} is out of range"
        if value < 2**62
        else "a vertex index far out of range",
        f"the file has {len(v_lines)} vertices (`v` lines)",
    )


def _face_colors(rgb: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F, 4) sRGB bytes: each triangle the mean of its corners' colours, opaque."""
    mean = np.clip(rgb[faces].mean(axis=1), 0.0, 1.0)
    out = np.full((len(faces), 4), 255, dtype=np.uint8)
    out[:, :3] = np.rint(mean * 255).astype(np.uint8)
    return out


def _obj_objects(obj: ObjText, face_line: np.ndarray) -> tuple[np.ndarray | None, list[CityObject]]:
    """(object of each triangle, objects) from ``o`` lines, else ``g`` lines; (None, []) when
    the file has neither.  A name used twice is one object (bgr writes ``g Wall`` under every
    object); faces above the first name are in ``default``.  Objects in order of first face."""
    named = obj.lines_of("o")
    if not len(named):
        named = obj.lines_of("g")
    if not len(named):
        return None, []
    event = np.searchsorted(named, face_line, side="right")  # 0: above the first name
    used, first, inverse = np.unique(event, return_index=True, return_inverse=True)
    ids: dict[str, int] = {}
    of_event = np.empty(len(used), dtype=np.int64)
    for k in np.argsort(first, kind="stable").tolist():
        e = int(used[k])
        name = " ".join(obj.tokens(int(named[e - 1]))) if e else ""
        of_event[k] = ids.setdefault(name or "default", len(ids))
    return of_event[inverse.reshape(-1)], [_template(name) for name in ids]


# --------------------------------------------------------------------------------------------
# polygons


def triangulate(
    vertices: np.ndarray, sizes: np.ndarray, corners: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(triangles (T, 3), the polygon each comes from (T,)) of polygons given by their sizes
    and flat corner list, in polygon order.  Convex polygons are fanned (in bulk, by size);
    the others are cut by earcut in their plane (one at a time: they are rare), facing as the
    polygon does."""
    starts = np.cumsum(sizes) - sizes
    parts, owners = [], []
    for size in np.unique(sizes).tolist():
        which = np.flatnonzero(sizes == size)
        ring = corners[starts[which, None] + np.arange(size)]  # (n, size)
        if size == 3:
            parts.append(ring)
            owners.append(which)
            continue
        convex = _convex(vertices[ring])
        fan = np.arange(1, size - 1)
        tris = np.stack(
            [
                np.repeat(ring[convex, :1], size - 2, axis=1),
                ring[convex][:, fan],
                ring[convex][:, fan + 1],
            ],
            axis=2,
        )
        parts.append(tris.reshape(-1, 3))
        owners.append(np.repeat(which[convex], size - 2))
        for p in np.flatnonzero(~convex).tolist():
            tri = _earcut(vertices, ring[p])
            parts.append(tri)
            owners.append(np.full(len(tri), which[p], dtype=np.int64))
    faces = np.concatenate(parts).astype(np.int64)
    owner = np.concatenate(owners).astype(np.int64)
    order = np.argsort(owner, kind="stable")
    return faces[order], owner[order]


def _convex(points: np.ndarray) -> np.ndarray:
    """(n,) whether each polygon (n, k, 3) turns the same way at every corner, seen along its
    Newell normal: then a fan from its first corner covers it exactly."""
    normal = np.cross(points, np.roll(points, -1, axis=1)).sum(axis=1)
    edges = np.roll(points, -1, axis=1) - points
    turns = np.cross(edges, np.roll(edges, -1, axis=1))
    return (np.einsum("nkc,nc->nk", turns, normal) >= 0).all(axis=1)


def _earcut(vertices: np.ndarray, ring: np.ndarray) -> np.ndarray:
    from bgr.formats.cityjson_read import _triangulate

    return _triangulate(vertices, [ring.tolist()])
