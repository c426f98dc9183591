"""CityGML 2.0 text to raw records: polygons with their context, textures, materials, the CRS.

CityGML files in the wild are not always namespace-correct XML: exporters write prefixes they
never declare (``xAL:``, ``uro:``, ``gen:``) and a namespace-aware parser refuses the whole file
("unbound prefix").  So the file is parsed by expat **without** namespace processing and every
element and attribute is matched by its local name (``bldg:WallSurface`` -> ``WallSurface``):
what a CityGML user means, whatever prefix or namespace the exporter wrote.

Files come from anywhere, so the parse refuses a DOCTYPE (CityGML has no use for one, and it is
what entity expansion -- "billion laughs", external entities -- needs), elements nested deeper
than MAX_DEPTH and files larger than MAX_BYTES, and every problem is a :class:`BgrError` at the
file's line and column.  Coordinates are checked here, once per posList in bulk: whole 3D points,
finite, within MAX_INPUT_COORDINATE.  :mod:`.citygml_read` assembles the records into a model.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import NoReturn
from xml.parsers import expat

import numpy as np

from bgr.grammar.errors import BgrError, Diagnostic
from bgr.interpreter.limits import DEFAULT_MAX_TRIANGLES, MAX_INPUT_COORDINATE

MAX_DEPTH = 256  # elements nested; PLATEAU's deepest is 14
MAX_BYTES = 2**30  # a 1 GiB CityGML file is read; a larger one is refused before parsing
MAX_POINTS = 3 * DEFAULT_MAX_TRIANGLES  # ring points in one file

POLYGONS = {"Polygon", "Triangle", "Rectangle"}
OBJECTS = {"Building", "BuildingPart", "BuildingInstallation", "IntBuildingInstallation", "Room"}
SURFACE_PARENTS = {"boundedBy", "opening"}  # their child is a thematic surface (WallSurface ...)
TEXT = {
    "posList",
    "pos",
    "coordinates",
    "textureCoordinates",
    "imageURI",
    "theme",
    "diffuseColor",
    "transparency",
    "target",
    "wrapMode",
}
_LOD = re.compile(r"lod([0-4])")


@dataclass
class RawPolygon:
    """One gml:Polygon as the file has it: rings of points (closing point dropped) and context."""

    id: str | None
    line: int
    lod: int  # from the nearest lodN... property above it; -1: none
    semantic: str  # the thematic surface it bounds (WallSurface ...), "" if none
    object: str  # gml:id of the nearest Building / BuildingPart ..., "" if none
    owners: list[str]  # gml:ids of itself and the elements above it, nearest first
    rings: list[np.ndarray] = field(default_factory=list)  # (n, 3) each, exterior first
    ring_ids: list[str | None] = field(default_factory=list)


@dataclass
class RawTexture:
    """An app:ParameterizedTexture: its image, the surfaces it targets and their rings' UVs."""

    theme: str
    line: int
    image_uri: str = ""
    image_at: tuple[int, int] = (0, 0)  # where the app:imageURI is
    wrap: str = "none"  # CityGML 2.0: wrapMode defaults to none
    targets: list[str] = field(default_factory=list)  # surface ids, '#' removed
    coords: dict[str, np.ndarray] = field(default_factory=dict)  # ring id -> (n, 2)


@dataclass
class RawMaterial:
    """An app:X3DMaterial: a colour for the surfaces it targets."""

    theme: str
    line: int
    id: str | None
    diffuse: tuple[float, float, float] = (0.8, 0.8, 0.8)  # X3D's default diffuseColor
    transparency: float = 0.0
    targets: list[str] = field(default_factory=list)


@dataclass
class RawCity:
    polygons: list[RawPolygon] = field(default_factory=list)
    textures: list[RawTexture] = field(default_factory=list)
    materials: list[RawMaterial] = field(default_factory=list)
    crs: str | None = None
    warnings: list[Diagnostic] = field(default_factory=list)


def local(name: str) -> str:
    """``bldg:WallSurface`` -> ``WallSurface`` (any prefix, declared or not)."""
    return name.rpartition(":")[2]


class _Parse:
    """expat handlers that keep a stack of open elements and fill a :class:`RawCity`."""

    def __init__(self, shown: str) -> None:
        self.shown = shown
        self.city = RawCity()
        self.stack: list[tuple[str, dict[str, str]]] = []  # (local name, attributes by local)
        self.lines: list[tuple[int, int]] = []  # where each open element starts
        self.text: list[str] | None = None
        self.polygon: RawPolygon | None = None
        self.ring: list[np.ndarray] | None = None
        self.texture: RawTexture | None = None
        self.material: RawMaterial | None = None
        self.theme = ""
        self.points = 0
        self.envelope_crs: str | None = None
        self.parser = expat.ParserCreate()  # no namespace processing: undeclared prefixes read
        p = self.parser
        p.StartElementHandler = self.start
        p.EndElementHandler = self.end
        p.CharacterDataHandler = self.chars
        p.StartDoctypeDeclHandler = self.doctype
        p.EntityDeclHandler = self.entity
        p.buffer_text = True

    # ----------------------------------------------------------------------------------------

    def fail(
        self, message: str, hint: str | None = None, at: tuple[int, int] | None = None
    ) -> NoReturn:
        line, column = at or (self.parser.CurrentLineNumber, self.parser.CurrentColumnNumber + 1)
        raise BgrError(Diagnostic(self.shown, line, column, message, hint))

    def warn(self, message: str, at: tuple[int, int]) -> None:
        self.city.warnings.append(Diagnostic(self.shown, at[0], at[1], message, severity="warning"))

    def doctype(self, *_) -> NoReturn:
        self.fail(
            "a DOCTYPE is refused: CityGML needs none, and its entities could expand without end",
            "remove the <!DOCTYPE ...> declaration",
        )

    def entity(self, *_) -> NoReturn:
        self.doctype()

    # ----------------------------------------------------------------------------------------

    def start(self, name: str, attributes: dict[str, str]) -> None:
        tag = local(name)
        attrs = {local(k): v for k, v in attributes.items()}
        if len(self.stack) >= MAX_DEPTH:
            self.fail(f"elements nest deeper than {MAX_DEPTH}", "no CityGML file nests this deep")
        at = (self.parser.CurrentLineNumber, self.parser.CurrentColumnNumber + 1)
        self.stack.append((tag, attrs))
        self.lines.append(at)
        if tag in TEXT:
            self.text = []
        if tag in POLYGONS and self.texture is None and self.material is None:
            self.polygon = self._polygon(attrs.get("id"), at[0])
        elif tag == "LinearRing" and self.polygon is not None:
            self.ring = []
            self.polygon.ring_ids.append(attrs.get("id"))
        elif tag == "Envelope" and self.envelope_crs is None and "srsName" in attrs:
            self.envelope_crs = attrs["srsName"]
        elif tag == "Appearance":
            self.theme = ""
        elif tag == "ParameterizedTexture":
            self.texture = RawTexture(self.theme, at[0])
            self.city.textures.append(self.texture)
        elif tag == "X3DMaterial":
            self.material = RawMaterial(self.theme, at[0], attrs.get("id"))
            self.city.materials.append(self.material)
        elif tag == "target" and self.texture is not None and "uri" in attrs:
            self.texture.targets.append(attrs["uri"].lstrip("#"))
        elif tag in ("TexCoordGen", "GeoreferencedTexture"):
            self.warn(f"app:{tag} is not read: its surfaces are left untextured", at)
        if self.city.crs is None and "srsName" in attrs:
            self.city.crs = attrs["srsName"]  # the first named CRS, until an Envelope names one

    def chars(self, data: str) -> None:
        if self.text is not None:
            self.text.append(data)

    def end(self, name: str) -> None:
        tag, attrs = self.stack.pop()
        at = self.lines.pop()
        text = "".join(self.text) if self.text is not None and tag in TEXT else ""
        if tag in TEXT:
            self.text = None
            self._text(tag, attrs, text, at)
        elif tag == "LinearRing" and self.ring is not None and self.polygon is not None:
            if not self.ring:
                self.fail("a gml:LinearRing has no gml:posList (or gml:pos)", at=at)
            self.polygon.rings.append(_open(np.concatenate(self.ring)))
            self.ring = None
        elif tag in POLYGONS and self.polygon is not None:
            if self.polygon.rings and len(self.polygon.rings[0]) >= 3:
                self.city.polygons.append(self.polygon)
            else:
                self.warn("a polygon without an exterior ring of 3 points or more is skipped", at)
            self.polygon = None
        elif tag == "ParameterizedTexture":
            self.texture = None
        elif tag == "X3DMaterial":
            self.material = None

    def _text(self, tag: str, attrs: dict[str, str], text: str, at: tuple[int, int]) -> None:
        """What an element of TEXT says, now that it is closed."""
        if tag in ("posList", "pos") and self.ring is not None:
            self.ring.append(self._points(text, attrs, at))
        elif tag == "coordinates" and self.ring is not None:
            self.fail("gml:coordinates (GML 2) is not read", "write rings as gml:posList", at)
        elif tag == "theme":
            self.theme = text.strip()
            if self.texture is not None:
                self.texture.theme = self.theme
        elif self.texture is not None:
            if tag == "imageURI":
                self.texture.image_uri, self.texture.image_at = text.strip(), at
            elif tag == "wrapMode":
                self.texture.wrap = text.strip()
            elif tag == "textureCoordinates":
                ring = attrs.get("ring", "").lstrip("#")
                if ring not in self.texture.coords:  # PLATEAU writes each ring's list twice
                    self.texture.coords[ring] = self._numbers(text, 2, "texture coordinate", at)
        elif self.material is not None:
            if tag == "diffuseColor":
                rgb = self._numbers(text, 3, "colour", at)
                if len(rgb) != 1:
                    self.fail("diffuseColor must be 3 numbers", at=at)
                self.material.diffuse = (float(rgb[0, 0]), float(rgb[0, 1]), float(rgb[0, 2]))
            elif tag == "transparency":
                self.material.transparency = float(self._numbers(text, 1, "number", at)[0, 0])
            elif tag == "target":
                self.material.targets.append(text.strip().lstrip("#"))

    # ----------------------------------------------------------------------------------------

    def _polygon(self, pid: str | None, line: int) -> RawPolygon:
        """A polygon starting here, its LoD, semantic surface and object read off the stack."""
        lod, semantic, obj = -1, "", ""
        owners = [pid] if pid else []
        for k in range(len(self.stack) - 2, -1, -1):
            tag, attrs = self.stack[k]
            if "id" in attrs:
                owners.append(attrs["id"])
            if lod < 0 and (m := _LOD.match(tag)):
                lod = int(m.group(1))
            parent = self.stack[k - 1][0] if k else ""
            if not semantic and parent in SURFACE_PARENTS:
                semantic = tag
            if not obj and (tag in OBJECTS or parent == "cityObjectMember"):
                obj = attrs.get("id", tag)
        return RawPolygon(pid, line, lod, semantic, obj, owners)

    def _points(self, text: str, attrs: dict[str, str], at: tuple[int, int]) -> np.ndarray:
        """(n, 3) points of a posList or pos, checked: 3D, whole points, finite, in range."""
        dims = attrs.get("srsDimension") or next(
            (a["srsDimension"] for _, a in reversed(self.stack) if "srsDimension" in a), "3"
        )
        if dims.strip() != "3":
            self.fail(f"srsDimension {dims[:20]!r}: bgr reads 3D coordinates only", at=at)
        points = self._numbers(text, 3, "coordinate", at)
        bad = ~(np.abs(points) <= MAX_INPUT_COORDINATE).all(axis=1)
        if bad.any():
            k = int(np.argmax(bad))
            self.fail(
                f"point {k + 1} ({', '.join(f'{v:g}' for v in points[k])}) is not finite or "
                f"lies beyond {MAX_INPUT_COORDINATE:.0e}",
                "the exporter wrote a point it could not place",
                at,
            )
        self.points += len(points)
        if self.points > MAX_POINTS:
            self.fail(f"the file has more than {MAX_POINTS:,} ring points, past what bgr reads")
        return points

    def _numbers(self, text: str, width: int, what: str, at: tuple[int, int]) -> np.ndarray:
        """(n, width) float64 of whitespace-separated numbers, or a located error."""
        tokens = text.split()
        try:
            values = np.array(tokens, dtype=np.float64)
        except ValueError:
            bad = next(t for t in tokens if not _is_number(t))
            self.fail(f"{bad[:40]!r} is not a number", at=at)
        if len(values) % width:
            self.fail(f"{len(values)} numbers do not make whole {what}s of {width}", at=at)
        if not np.isfinite(values).all():
            self.fail(f"a {what} is not a finite number", at=at)
        return values.reshape(-1, width)


def _is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


def _open(points: np.ndarray) -> np.ndarray:
    """A closed ring's points without the closing point (GML repeats the first at the end)."""
    if len(points) > 1 and np.array_equal(points[0], points[-1]):
        return points[:-1]
    return points


def parse_citygml(data: bytes, shown: str) -> RawCity:
    """The raw records of a CityGML file's bytes (``shown`` names it in messages)."""
    if len(data) > MAX_BYTES:
        raise BgrError(
            Diagnostic(shown, 0, 0, f"the file is larger than {MAX_BYTES:,} bytes, past bgr's cap")
        )
    state = _Parse(shown)
    try:
        state.parser.Parse(data, True)
    except expat.ExpatError as exc:
        message = expat.ErrorString(exc.code) if exc.code is not None else str(exc)
        raise BgrError(
            Diagnostic(shown, exc.lineno, exc.offset + 1, f"not well-formed XML: {message}")
        ) from None
    except (LookupError, ValueError) as exc:  # an encoding expat cannot use ("UTF-3", Shift_JIS)
        p = state.parser
        reason = str(exc)[:100].encode("unicode_escape").decode("ascii")
        raise BgrError(
            Diagnostic(
                shown,
                p.CurrentLineNumber,
                p.CurrentColumnNumber + 1,
                f"the XML declaration's encoding cannot be read: {reason}",
                "save the file as UTF-8 (CityGML files are UTF-8 in practice)",
            )
        ) from None
    if state.envelope_crs is not None:
        state.city.crs = state.envelope_crs
    return state.city
