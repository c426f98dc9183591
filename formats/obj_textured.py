"""Read a Wavefront OBJ with its MTL materials and their images into a :class:`TexturedMesh`.

bgr reads OBJ itself rather than through trimesh: trimesh re-welds vertices (a corner's ``vt``
is per corner, so a vertex shared by two faces with different UVs must not be merged), keeps
no path to a material's image, and resolves ``mtllib`` and ``map_Kd`` names anywhere on disk.
Here every ``f`` corner keeps its own ``vt``; polygons are fanned from their first corner (OBJ
faces are convex in practice, and OBJ has no holes); ``usemtl`` names a material of the
``mtllib`` files, whose ``Kd``, ``d`` / ``Tr`` and ``map_Kd`` are read.  ``o`` (else ``g``)
names the object each face belongs to.

Files come from anywhere: an index that names no vertex, a number that does not parse, a
vertex that is not finite or lies beyond MAX_INPUT_COORDINATE are errors at their line; an
``mtllib`` or image outside the OBJ's folder (URL, absolute path, ``..``) is an error; a missing
MTL file or image is a warning, and the faces keep their UVs with no image.  Numbers are
converted in bulk (numpy), the lines classified in one pass.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from bgr.grammar.errors import BgrError, Diagnostic
from bgr.grammar.paths import read_input, resolved
from bgr.interpreter.limits import DEFAULT_MAX_TRIANGLES, MAX_INPUT_COORDINATE

from .gltf_checks import quoted
from .textured_model import Material, TexturedMesh, image_path

__all__ = ["read_obj_textured"]


class _Obj:
    """One pass over an OBJ's lines, collecting what the model needs."""

    def __init__(self, shown: str, folder: Path) -> None:
        self.shown, self.folder = shown, folder
        self.v: list[str] = []
        self.v_lines: list[int] = []
        self.vt: list[str] = []
        self.corners: list[tuple[int, int]] = []  # (v, vt) 1-based, resolved; vt 0: none
        self.sizes: list[int] = []
        self.face_lines: list[int] = []
        self.face_material: list[str] = []
        self.face_object: list[str] = []
        self.libraries: list[tuple[str, int]] = []
        self.warnings: list[Diagnostic] = []

    def fail(self, line: int, message: str, hint: str | None = None) -> BgrError:
        return BgrError(Diagnostic(self.shown, line, 1, message, hint))

    def read(self, text: str) -> None:
        material, obj, group = "", "", ""
        seen: set[tuple[str, str, str, int, int]] = set()
        for n, raw in enumerate(text.splitlines(), start=1):
            key, _, rest = raw.strip().partition(" ")
            if key == "v":
                self.v.append(" ".join(rest.split()[:3]))
                self.v_lines.append(n)
            elif key == "vt":
                self.vt.append(" ".join((rest.split() + ["0"])[:2]))
            elif key == "f":
                # a face that repeats an earlier one (its corners naming the same vertices,
                # the same material and object) is read once: 100,000 copies of one line
                # drew 200,000 triangles on the same pixels for 12 s
                same = (rest.strip(), material, obj or group, len(self.v), len(self.vt))
                if same in seen:
                    continue
                seen.add(same)
                self._face(rest.split(), n)
                self.face_material.append(material)
                self.face_object.append(obj or group)
            elif key == "usemtl":
                material = rest.strip()
            elif key == "o":
                obj = rest.strip()
            elif key == "g":
                group = rest.strip()
            elif key == "mtllib":
                self.libraries.extend((name, n) for name in rest.split())

    def _face(self, tokens: list[str], line: int) -> None:
        if len(tokens) < 3:
            raise self.fail(line, f"a face needs 3 corners or more, not {len(tokens)}")
        for token in tokens:
            parts = token.split("/")
            v = self._index(parts[0], len(self.v), "vertex", line)
            t = (
                self._index(parts[1], len(self.vt), "texture coordinate", line)
                if (len(parts) > 1 and parts[1])
                else 0
            )
            self.corners.append((v, t))
        self.sizes.append(len(tokens))
        self.face_lines.append(line)
        if len(self.corners) > 3 * DEFAULT_MAX_TRIANGLES:
            raise self.fail(line, f"more than {DEFAULT_MAX_TRIANGLES:,} triangles, past bgr's cap")

    def _index(self, token: str, count: int, what: str, line: int) -> int:
        """A 1-based index (negative: counted back from the last one so far), checked."""
        try:
            k = int(token)
        except ValueError:
            raise self.fail(line, f"{quoted(token, 40)} is not a {what} index") from None
        k = count + k + 1 if k < 0 else k
        if not 1 <= k <= count:
            raise self.fail(
                line, f"{what} {token[:20]} does not exist (the file has {count} so far)"
            )
        return k


def read_obj_textured(path: str | Path) -> TexturedMesh:
    """The textured triangles of an OBJ and its MTL files (the file's frame; ``up`` "y", as OBJ
    exporters write); BgrError at the line for what it cannot read."""
    shown = str(path)
    text = _text(path, shown, "OBJ file")
    obj = _Obj(shown, resolved(path).parent)
    obj.read(text)
    vertices = _numbers(obj.v, 3, obj, obj.v_lines)
    uv_table = _numbers(obj.vt, 2, obj, None) if obj.vt else np.zeros((0, 2))
    materials, index = _libraries(obj)
    if not obj.sizes:
        raise BgrError(Diagnostic(shown, 0, 0, "the OBJ file has no faces"))
    corners = np.array(obj.corners, dtype=np.int64)
    sizes = np.array(obj.sizes, dtype=np.int64)
    starts = np.cumsum(sizes) - sizes
    owner = np.repeat(np.arange(len(sizes)), sizes - 2)  # a fan of size - 2 per face
    step = np.arange(len(owner)) - np.repeat(np.cumsum(sizes - 2) - (sizes - 2), sizes - 2)
    first = starts[owner]
    pick = np.stack([first, first + step + 1, first + step + 2], axis=1)  # (T, 3) corners
    faces = corners[pick, 0] - 1
    uv_rows = np.vstack([np.zeros((1, 2)), uv_table])  # row 0: a corner without vt
    objects = sorted(set(obj.face_object), key=obj.face_object.index)
    names = np.array([index.get(m, -1) for m in obj.face_material], dtype=np.int64)
    face_object = np.array([objects.index(o) for o in obj.face_object], dtype=np.int64)
    return TexturedMesh(
        vertices=vertices,
        faces=faces,
        uv=uv_rows[corners[pick, 1]],
        material=names[owner],
        materials=materials,
        semantic=np.zeros(len(owner), dtype=np.int64),
        semantic_names=[""],
        object=face_object[owner],
        object_ids=objects,
        surface=owner,
        surface_ids=[f"line {n}" for n in obj.face_lines],
        up="y",
        source=shown,
        warnings=obj.warnings,
    )


def _text(path: str | Path, shown: str, what: str) -> str:
    try:
        return read_input(path, what).decode("utf-8", errors="replace")
    except FileNotFoundError:
        raise BgrError(Diagnostic(shown, 0, 0, f"no such {what}")) from None
    except OSError as exc:
        raise BgrError(Diagnostic(shown, 0, 0, f"cannot read the {what}: {exc}")) from None


def _numbers(rows: list[str], width: int, obj: _Obj, lines: list[int] | None) -> np.ndarray:
    """(n, width) float64 of the rows, converted together; a located error for a bad one."""
    try:
        values = np.array(" ".join(rows).split(), dtype=np.float64)
    except ValueError:
        values = None
    if values is None or len(values) != width * len(rows):
        k = next(i for i, r in enumerate(rows) if not _row_ok(r, width))
        line = lines[k] if lines else 0
        raise obj.fail(line, f"{quoted(rows[k], 40)} is not {width} numbers")
    out = values.reshape(-1, width)
    bad = ~(np.abs(out) <= MAX_INPUT_COORDINATE).all(axis=1)
    if bad.any():
        k = int(np.argmax(bad))
        line = lines[k] if lines else 0
        raise obj.fail(
            line, f"{quoted(rows[k], 40)} is not finite or beyond {MAX_INPUT_COORDINATE:.0e}"
        )
    return out


def _row_ok(row: str, width: int) -> bool:
    try:
        return len([float(t) for t in row.split()]) == width
    except ValueError:
        return False


def _libraries(obj: _Obj) -> tuple[list[Material], dict[str, int]]:
    """The materials of the ``mtllib`` files (first definition of a name wins) and their index."""
    materials: list[Material] = []
    index: dict[str, int] = {}
    first: dict[str, int] = {}  # each library read once: 100,000 mtllib lines took 100 s
    for name, line in obj.libraries:
        first.setdefault(name, line)
    for name, line in first.items():
        try:
            path = image_path(obj.folder, name)
        except ValueError as exc:
            raise obj.fail(
                line, f"mtllib {quoted(name)} {exc}", "keep the MTL beside the OBJ"
            ) from None
        if not path.is_file():
            obj.warnings.append(
                Diagnostic(
                    obj.shown, line, 1, f"mtllib {quoted(name)} is missing", severity="warning"
                )
            )
            continue
        # shown as the user named it: beside the OBJ as given, not the resolved absolute path
        shown = str(Path(obj.shown).parent / name)
        for material in _mtl(_text(path, shown, "MTL file"), path, shown, obj):
            if material.name not in index:
                index[material.name] = len(materials)
                materials.append(material)
    return materials, index


def _mtl(text: str, path: Path, shown: str, obj: _Obj) -> list[Material]:
    """The materials of one MTL file (``shown`` names it in messages): Kd, d (or Tr) and map_Kd
    (its last token: options such as ``-s`` come before the file name).  Each distinct image
    name is resolved, and a missing one warned of, once: an MTL that repeats a ``map_Kd`` line
    100,000 times spent 10 s resolving the same path."""
    out: list[Material] = []
    images: dict[str, Path | None] = {}
    for n, raw in enumerate(text.splitlines(), start=1):
        key, _, rest = raw.strip().partition(" ")
        if key == "newmtl":
            out.append(Material(rest.strip()))
        elif not out:
            continue
        elif key == "Kd" or key in ("d", "Tr"):
            try:
                values = [float(t) for t in rest.split()]
            except ValueError:
                raise BgrError(Diagnostic(shown, n, 1, f"{key} must be numbers")) from None
            if not all(math.isfinite(v) for v in values):  # NaN was a NaN colour, cast to uint8
                raise BgrError(Diagnostic(shown, n, 1, f"{key} must be finite numbers"))
            r, g, b, a = out[-1].color
            if key == "Kd" and len(values) >= 3:
                r, g, b = (min(max(c, 0.0), 1.0) for c in values[:3])
            elif values:
                a = min(max(values[0] if key == "d" else 1.0 - values[0], 0.0), 1.0)
            out[-1].color = (r, g, b, a)
        elif key == "map_Kd" and rest.split():
            name = rest.split()[-1]
            if name not in images:
                images[name] = _image(path, shown, name, n, obj)
            if images[name] is not None:
                out[-1].image = images[name]
    return out


def _image(path: Path, shown: str, name: str, line: int, obj: _Obj) -> Path | None:
    """The image a ``map_Kd`` of the MTL ``path`` names; None, with a warning, when missing."""
    try:
        image = image_path(path.parent, name)
    except ValueError as exc:
        raise BgrError(Diagnostic(shown, line, 1, f"map_Kd {quoted(name)} {exc}")) from None
    if image.is_file():
        return image
    obj.warnings.append(
        Diagnostic(
            shown,
            line,
            1,
            f"map_Kd {quoted(name)} is missing: its faces are left untextured",
            severity="warning",
        )
    )
    return None
