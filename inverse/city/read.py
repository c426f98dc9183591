"""The readers of ``bgr infer --kind city``: a 3D city file in, a :class:`CityScene` of objects out.

One public function, :func:`read_city`.  Every format goes through the same steps:

1. **Read** the file's triangles in its own frame, and which object each belongs to: CityJSON
   city objects, OBJ ``o`` objects (else ``g`` groups), the nodes of a glTF scene.  Inputs
   without objects (a PLY, an OBJ of bare faces, a glTF of one node) are cut into connected
   components, merged where their ground-plane boxes overlap (:func:`components`).
2. **Check** what no later step can use: coordinates that are not finite numbers or lie
   beyond 1e8 m (:mod:`.coordinates`), an empty scene.  Triangles that repeat a vertex are
   dropped without a word: exporters write them.
3. **Orient and re-centre**: the up axis (:func:`up_axis`), an offset of whole metres so that
   projected coordinates (hundreds of kilometres) become small (:func:`offset_of`), then the turn
   into bgr's y-up frame (:meth:`CityScene.from_input`), in float64.

Every failure is a :class:`BgrError` naming the file (and, for OBJ, the line and column).
"""

from __future__ import annotations

import io
import math
import re
import struct
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from bgr.grammar.errors import BgrError, Diagnostic
from bgr.grammar.paths import read_input

from .coordinates import Locate, check_coordinates
from .model import CityObject, CityScene
from .objects import components, mark_surfaces, separate

if TYPE_CHECKING:
    import trimesh

__all__ = ["read_city"]  # the helpers below are the module's own (tests reach into some)

# extension (lower case) -> format; the longest matching extension wins
EXTENSIONS = {
    ".obj": "obj",
    ".ply": "ply",
    ".glb": "gltf",
    ".gltf": "gltf",
    ".city.json": "cityjson",
    ".json": "cityjson",
    ".city.jsonl": "cityjsonl",
    ".jsonl": "cityjsonl",
}
ACCEPTED = ".obj, .ply, .glb, .gltf, .city.json (.json) and .city.jsonl (.jsonl)"
UPS = ("auto", "y", "z")
PROCEDURAL_TYPES = ("Building", "BuildingPart")  # CityJSON types that are proceduralized

RECENTRE_FROM = 1000.0  # metres: a horizontal centre farther than this from 0 is re-centred
LIFT_FROM = 100.0  # metres: a lowest point farther than this from 0 is brought to about 0


# --------------------------------------------------------------------------------------------
# the public function


def read_city(path: str | Path, *, up: str = "auto", lod: str | None = None) -> CityScene:
    """Read a 3D city (OBJ, PLY, glTF/GLB, CityJSON or CityJSON Text Sequences) as objects of
    triangles in bgr's frame: y up, metres, re-centred (the scene's ``offset`` puts it back).

    ``up``: the input's up axis, "y", "z", or "auto" (CityJSON is z up, glTF y up; OBJ and PLY
    are z up when their z extent is less than half their horizontal ones, else y up).
    ``lod``: the CityJSON level of detail to read (default: each object's highest); other
    formats have one geometry and refuse it.  Raises :class:`BgrError` naming the file."""
    shown = str(path)
    fmt = format_of(shown)
    if up not in UPS:
        raise BgrError(
            Diagnostic(shown, 0, 0, f"unknown up axis '{up}'", f"use one of {', '.join(UPS)}")
        )
    if lod is not None and not fmt.startswith("cityjson"):
        raise BgrError(
            Diagnostic(
                shown,
                0,
                0,
                "a level of detail only selects among CityJSON geometries",
                "leave out the lod: this file has one geometry per object",
            )
        )
    if fmt.startswith("cityjson") and up == "y":
        raise BgrError(
            Diagnostic(shown, 0, 0, "CityJSON is z up", "leave the up axis on auto, or z")
        )
    try:
        if fmt.startswith("cityjson"):
            found, up = _read_cityjson(path, lod), "z"
        elif fmt == "gltf":
            found, up = _read_gltf(path), "y" if up == "auto" else up
        else:
            data = _read_bytes(path, shown)
            found = _read_obj(shown, data) if fmt == "obj" else _read_ply(shown, data)
        return _scene(shown, found, up)
    except (
        ValueError,
        TypeError,
        IndexError,
        KeyError,
        AttributeError,
        OverflowError,
        RecursionError,
    ) as exc:
        # the readers turn what they expect into messages; this is what they did not foresee
        raise BgrError(
            Diagnostic(shown, 0, 0, f"cannot read the city file: {_reason(exc)}")
        ) from None


def format_of(shown: str) -> str:
    """The format of a path, from its extension; BgrError for one this module does not read."""
    lower = shown.lower()
    for ext in sorted(EXTENSIONS, key=len, reverse=True):
        if lower.endswith(ext):
            return EXTENSIONS[ext]
    raise BgrError(
        Diagnostic(
            shown,
            0,
            0,
            "cannot read this file as a city: its extension names no format bgr reads",
            f"bgr reads cities from {ACCEPTED}",
        )
    )


def _read_bytes(path: str | Path, shown: str) -> bytes:
    try:
        return read_input(path, "city file")
    except FileNotFoundError:
        raise BgrError(Diagnostic(shown, 0, 0, "no such city file")) from None
    except OSError as exc:
        raise BgrError(Diagnostic(shown, 0, 0, f"cannot read the city file: {exc}")) from None


# --------------------------------------------------------------------------------------------
# what every reader hands on


@dataclass
class Found:
    """A file's triangles in its own frame, and the objects they belong to.

    ``owner`` is each face's index into ``objects`` (templates: name, kind, proceduralize and
    attributes; their vertices and faces are filled in by :func:`_scene`), or None when the file
    has no objects and connected components make them."""

    vertices: np.ndarray  # (V, 3) float64, the input's frame
    faces: np.ndarray  # (F, 3) int64
    colors: np.ndarray | None  # (F, 4) uint8
    owner: np.ndarray | None  # (F,) int64
    objects: list[CityObject] = field(default_factory=list)
    crs: str | None = None
    hint: str | None = None  # what to say when no triangles are left
    locate: Locate | None = None  # a bad vertex's error at its place in the file (OBJ: line)


def _template(name: str, kind: str = "object", **more) -> CityObject:
    return CityObject(name, kind, np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), **more)


def _scene(shown: str, found: Found, up: str) -> CityScene:
    """Checks, up axis, offset and bgr's frame; the objects filled in (see the module)."""
    faces = np.asarray(found.faces, dtype=np.int64).reshape(-1, 3)
    vertices = np.asarray(found.vertices, dtype=np.float64).reshape(-1, 3)
    has_area = (
        (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])
    )
    keep = np.flatnonzero(has_area)
    keep = keep[_first_of_each(faces[keep], None if found.owner is None else found.owner[keep])]
    faces = faces[keep]
    colors = None if found.colors is None else found.colors[keep]
    owner = None if found.owner is None else found.owner[keep]
    if not len(faces):
        hint = found.hint
        if hint is None and len(has_area):
            hint = f"each of its {len(has_area)} faces repeats a vertex: none has an area"
        raise BgrError(Diagnostic(shown, 0, 0, f"no triangles in {shown}", hint))
    check_coordinates(shown, vertices, faces, owner, found.objects, found.locate)
    mark = np.zeros(len(vertices), dtype=bool)
    mark[faces] = True
    used = vertices[mark]
    up = up_axis(used) if up == "auto" else up
    scene = CityScene([], shown, up, offset_of(used, up), found.crs)
    local = scene.from_input(vertices)
    objects = found.objects
    if owner is None:
        owner, count = components(local, faces)
        objects = [_template(f"object-{k}") for k in range(1, count + 1)]
    else:
        mark_surfaces(local, faces, owner, objects)  # roads and terrain of a typeless format
        owner, objects = separate(local, faces, owner, objects)
    scene.objects = _split(local, faces, colors, owner, objects)
    return scene


def _first_of_each(faces: np.ndarray, owner: np.ndarray | None) -> np.ndarray:
    """Positions (ascending) of the faces to keep when a face that repeats an earlier one of its
    object (the same three vertices in the same turning order) is dropped.

    A repeated face adds no surface, but each copy would be cut, fitted and hashed: a CityJSON
    surface listed 3,000 times took 10 s to infer.  A face and its reverse are both kept (a
    two-sided wall)."""
    if not len(faces):
        return np.zeros(0, dtype=np.int64)
    turn = np.argmin(faces, axis=1)  # rotate each face to start at its smallest index
    rows = np.take_along_axis(faces, (turn[:, None] + np.arange(3)) % 3, axis=1)
    key = np.column_stack([np.zeros(len(faces), np.int64) if owner is None else owner, rows])
    _, first = np.unique(key, axis=0, return_index=True)
    return np.sort(first)


def up_axis(points: np.ndarray) -> str:
    """ "z" when the points' z extent is less than half of both horizontal extents (x and y: a
    z-up city is wider than it is tall), else "y", OBJ's and glTF's convention."""
    extent = points.max(axis=0) - points.min(axis=0)
    return "z" if extent[2] < 0.5 * min(extent[0], extent[1]) else "y"


def offset_of(points: np.ndarray, up: str) -> np.ndarray:
    """The offset (input frame) that brings projected coordinates near 0: the bounding box's
    horizontal centre in whole metres when it is more than RECENTRE_FROM from 0, and the lowest
    point rounded down to a whole metre when it is more than LIFT_FROM from 0.  Whole metres
    keep the subtraction exact, so outputs land where the input was to the last digit."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    vertical = 2 if up == "z" else 1
    plan = [a for a in range(3) if a != vertical]
    offset = np.zeros(3)
    centre = (lo + hi) / 2
    if math.hypot(centre[plan[0]], centre[plan[1]]) > RECENTRE_FROM:
        offset[plan] = np.round(centre[plan])
    if abs(lo[vertical]) > LIFT_FROM:
        offset[vertical] = math.floor(lo[vertical])
    return offset


def _split(
    vertices: np.ndarray,
    faces: np.ndarray,
    colors: np.ndarray | None,
    owner: np.ndarray,
    objects: list[CityObject],
) -> list[CityObject]:
    """The objects with their own triangles and only the vertices those use (renumbered), in
    the order of ``objects``; objects left without triangles are dropped."""
    order = np.argsort(owner, kind="stable")
    faces, owner = faces[order], owner[order]
    # a vertex of object k is the pair (k, vertex): numbered within its object by rank
    pairs = owner[:, None] * len(vertices) + faces
    used, inverse = np.unique(pairs.reshape(-1), return_inverse=True)
    inverse = inverse.reshape(-1, 3)
    first_pair = np.searchsorted(used, np.arange(len(objects) + 1) * len(vertices))
    starts = np.searchsorted(owner, np.arange(len(objects) + 1))
    out = []
    for k, obj in enumerate(objects):
        lo, hi = starts[k], starts[k + 1]
        if lo == hi:
            continue
        mine = used[first_pair[k] : first_pair[k + 1]]
        obj.vertices = vertices[mine - k * len(vertices)]
        obj.faces = (inverse[lo:hi] - first_pair[k]).astype(np.int64)
        obj.colors = None if colors is None else colors[order[lo:hi]]
        out.append(obj)
    return out


# --------------------------------------------------------------------------------------------
# OBJ


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


# --------------------------------------------------------------------------------------------
# PLY


def _read_ply(shown: str, data: bytes) -> Found:
    """A PLY read by trimesh: one mesh, whose objects are its connected components."""
    import warnings

    import trimesh

    from .ply_checks import check_header, check_mesh

    check_header(shown, data)  # counts the file can hold, before trimesh allocates them
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")  # a NaN cast: check_coordinates names the vertex
            mesh = trimesh.load(io.BytesIO(data), file_type="ply", process=False)
    except Exception as exc:  # trimesh raises whatever its parsers meet
        raise BgrError(
            Diagnostic(shown, 0, 0, f"not a PLY file bgr can read: {_reason(exc)}")
        ) from None
    faces = getattr(mesh, "faces", None)
    if isinstance(mesh, trimesh.Trimesh) and faces is not None:
        check_mesh(shown, np.asarray(mesh.vertices), np.asarray(faces))
    if not isinstance(mesh, trimesh.Trimesh) or faces is None or not len(faces):
        hint = "it holds points only" if isinstance(mesh, trimesh.PointCloud) else None
        raise BgrError(Diagnostic(shown, 0, 0, f"no triangles in {shown}", hint))
    colors = (
        _mesh_colors(mesh) if getattr(mesh.visual, "kind", None) in ("face", "vertex") else None
    )
    return Found(np.asarray(mesh.vertices, dtype=np.float64), np.asarray(faces), colors, None)


def _mesh_colors(mesh: trimesh.Trimesh) -> np.ndarray:
    """(F, 4) sRGB bytes of a trimesh's faces (its vertex colours averaged, where it has those;
    white where it has none)."""
    colors = getattr(mesh.visual, "face_colors", None)
    if colors is None:
        return np.full((len(mesh.faces), 4), 255, dtype=np.uint8)
    return np.asarray(colors, dtype=np.uint8)


def _reason(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0][:200] if text else type(exc).__name__


# --------------------------------------------------------------------------------------------
# glTF


def _read_gltf(path: str | Path) -> Found:
    """A .glb/.gltf's triangles, an object per node under the scene's one root node (bgr's
    tree: root, then a node per lot), else per root node; when that makes one object, its
    connected components are the objects instead.  The file is checked as it is read
    (formats/gltf_checks.py), its triangles counted for the whole scene before any is made."""
    from bgr.formats.glb_read import check_scene, node_matrix, parse, scene_roots, world_mesh
    from bgr.grammar.paths import resolved

    shown = str(path)
    data = _read_bytes(path, shown)
    parts: list[tuple[str, trimesh.Trimesh, dict]] = []
    try:
        gltf, blob = parse(data, resolved(path).parent)
        nodes = gltf.get("nodes", [])
        roots = scene_roots(gltf)
        check_scene(gltf, blob, roots)
        if len(roots) == 1 and nodes[roots[0]].get("children"):
            root = nodes[roots[0]]
            alone = {key: value for key, value in root.items() if key != "children"}
            own = world_mesh({**gltf, "nodes": [alone]}, blob, [0], checked=True)
            parts.append((_node_name(root, roots[0]), own, {}))
            world = node_matrix(root, roots[0])
            for child in root["children"]:
                mesh = world_mesh(gltf, blob, [child], world, checked=True)
                parts.append((_node_name(nodes[child], child), mesh, _extras(nodes[child])))
        else:
            for r in roots:
                mesh = world_mesh(gltf, blob, [r], checked=True)
                parts.append((_node_name(nodes[r], r), mesh, _extras(nodes[r])))
    except BgrError as exc:
        raise BgrError(
            Diagnostic(shown, 0, 0, f"not a glTF file bgr can read: {exc.message}", exc.hint)
        ) from None
    except (
        ValueError,
        KeyError,
        TypeError,
        IndexError,
        AttributeError,
        RecursionError,
        struct.error,
    ) as exc:
        raise BgrError(
            Diagnostic(shown, 0, 0, f"not a glTF file bgr can read: {_reason(exc)}")
        ) from None
    return _gathered(parts)


def _node_name(node: dict, index: int) -> str:
    name = node.get("name")
    return name if isinstance(name, str) and name else f"node-{index}"


def _extras(node: dict) -> dict:
    extras = node.get("extras")
    return dict(extras) if isinstance(extras, dict) else {}


def _gathered(parts: list[tuple[str, trimesh.Trimesh, dict]]) -> Found:
    """One Found of several meshes, an object each (names made unique, meshes without
    triangles left out); a single object is left to connected components."""
    vertices, faces, colors, owner = [], [], [], []
    objects: list[CityObject] = []
    taken: set[str] = set()
    count = 0
    for name, mesh, attrs in parts:
        if not len(mesh.faces):
            continue
        shown, n = name, 1
        while shown in taken:
            n += 1
            shown = f"{name}-{n}"
        taken.add(shown)
        vertices.append(np.asarray(mesh.vertices, dtype=np.float64))
        faces.append(np.asarray(mesh.faces, dtype=np.int64) + count)
        colors.append(_mesh_colors(mesh))
        owner.append(np.full(len(mesh.faces), len(objects), dtype=np.int64))
        objects.append(_template(shown, attributes=attrs))
        count += len(vertices[-1])
    if not faces:
        return Found(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), None, None)
    found = Found(
        np.concatenate(vertices),
        np.concatenate(faces),
        np.concatenate(colors),
        np.concatenate(owner),
        objects,
    )
    if len(objects) == 1:
        found.owner, found.objects = None, []
    return found


# --------------------------------------------------------------------------------------------
# CityJSON


def _lod_order(lod: str) -> tuple[float, str]:
    try:
        return float(lod), lod
    except ValueError:
        return float("inf"), lod


def _read_cityjson(path: str | Path, lod: str | None) -> Found:
    """Every city object with triangles: Buildings and BuildingParts to proceduralize, the
    rest (roads, land use, water, terrain...) carried.  A Building whose geometry is all in
    its BuildingParts has no triangles of its own, so only its parts are objects."""
    from bgr.formats.cityjson_read import read_cityjson

    model = read_cityjson(path, lod)
    vertices, faces, owner = [], [], []
    objects: list[CityObject] = []
    count = 0
    for ident, mesh in model.objects.items():
        if not len(mesh.faces):
            continue
        vertices.append(mesh.vertices)
        faces.append(mesh.faces + count)
        owner.append(np.full(len(mesh.faces), len(objects), dtype=np.int64))
        objects.append(
            _template(
                ident,
                mesh.type,
                proceduralize=mesh.type in PROCEDURAL_TYPES,
                attributes=dict(mesh.attributes),
            )
        )
        count += len(mesh.vertices)
    crs = model.reference_system
    hint = None
    if lod is not None:
        has = ", ".join(sorted(model.lods, key=_lod_order)[:12]) or "none"
        hint = f"no city object has geometry of lod {lod[:40]}; the file has lods {has}"
    if not faces:
        return Found(
            np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), None, None, crs=crs, hint=hint
        )
    return Found(
        np.concatenate(vertices),
        np.concatenate(faces),
        None,
        np.concatenate(owner),
        objects,
        crs=None if crs is None else str(crs),
        hint=hint,
    )
