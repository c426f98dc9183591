"""Read a captured-model JSON (a building written by hand) into a :class:`Model`.

A captured model is Build-by-Number's model specification (section 3.1) as a file: a scene graph
of blocks (box, cylinder, prism) with transforms and attachments, each block cut into floors, and
each face of each floor subdivided into rows and columns of labelled subfaces.  The format is
documented in ``docs/inverse-schema.md`` ("Captured-model JSON"); its JSON Schema is
:data:`SCHEMA` here, and ``docs/captured-model.schema.json`` is that schema written out
(``python -m bgr.inverse.schema.captured > docs/captured-model.schema.json``; a test keeps them
equal).

Reading goes in three stages, each reporting every problem it finds as a :class:`BgrError` whose
diagnostics name the offending element by its JSON path (``blocks[0].faces.front[1].size``):

1. the JSON itself: finite numbers, no key given twice, not nested absurdly deep;
2. the JSON Schema (:data:`SCHEMA`): keys, types, ranges;
3. the meaning: ids unique, parents known and acyclic, floors summing to the block's height,
   subface sizes summing to their cell, attachments naming real faces that touch.

Then the faces are built in world coordinates and :func:`link_faces` sets their corners, as the
terminal-list reader (:mod:`.terminals`) does.
"""

from __future__ import annotations

import json
import math
import re
import sys
from pathlib import Path

from bgr.grammar.errors import BgrError, Diagnostic, suggest
from bgr.grammar.paths import read_input

from .model import Block, Cell, Face, Model, default_fixed
from .terminals import _set_fixed, link_faces

FORMAT_VERSION = 1
TOL = 1e-6  # metres: sizes that sum to within this of their cell fit it
GEOM_TOL = 1e-4  # metres: attached faces this close are coplanar (0.1 mm)
MAX_LENGTH = 1e6  # metres: bound on every length and coordinate, so TOL stays meaningful
MAX_NESTING = 100  # JSON levels: deeper documents are refused before anything recurses into them
# JSON values (numbers, strings, lists, objects...): the schema validator takes 70 us a value, and
# up to 300 where it has errors to explain (100,000 values: 36 s); 20,000 is some 18 blocks of
# corner_shop.json's size, checked within a few seconds
MAX_VALUES = 20_000
PLAIN = "wall"  # the label of a face the file does not subdivide
BOX_FACES = ("front", "right", "back", "left")  # as listed in the file and the docs
BOX_RING = ("front", "left", "back", "right")  # left to right seen from outside (see the docs)
IDENTIFIER = r"^[A-Za-z_][A-Za-z0-9_]*$"

# ---- the JSON Schema --------------------------------------------------------------------------

_LENGTH = {"$ref": "#/$defs/length"}
_COORD = {"$ref": "#/$defs/coordinate"}

SCHEMA: dict = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "bgr captured model",
    "description": "A building captured by hand, Build-by-Number style: blocks (box, cylinder, "
    "prism) in a scene graph, cut into floors, each face of each floor subdivided into labelled "
    "subfaces. "
    "See docs/inverse-schema.md, section 'Captured-model JSON'.",
    "type": "object",
    "required": ["bgr_captured", "blocks"],
    "additionalProperties": False,
    "properties": {
        "bgr_captured": {
            "const": FORMAT_VERSION,
            "description": "the format version: 1 (the only one)",
        },
        "name": {"type": "string", "description": "the building's name, free text"},
        "labels": {
            "type": "object",
            "description": "per label, whether its size is fixed (windows, doors) or stretches "
            "(brick); labels not listed are fixed when they contain window, door, entrance, entry, "
            "portal or gate",
            "propertyNames": {"$ref": "#/$defs/label"},
            "additionalProperties": {"$ref": "#/$defs/labelInfo"},
        },
        "blocks": {
            "type": "array",
            "minItems": 1,
            "items": {"$ref": "#/$defs/block"},
            "description": "the building blocks, at least one",
        },
    },
    "$defs": {
        "length": {
            "type": "number",
            "exclusiveMinimum": 0,
            "maximum": MAX_LENGTH,
            "description": "a length in metres, greater than 0 (and at most 1e6)",
        },
        "coordinate": {
            "type": "number",
            "minimum": -MAX_LENGTH,
            "maximum": MAX_LENGTH,
            "description": "a coordinate in metres (between -1e6 and 1e6)",
        },
        "label": {
            "type": "string",
            "pattern": IDENTIFIER,
            "description": "a label: an identifier (letters, digits and _, not starting with a "
            "digit), as it names a terminal of the inferred grammar",
        },
        "labelInfo": {
            "type": "object",
            "required": ["fixed"],
            "additionalProperties": False,
            "properties": {
                "fixed": {
                    "type": "boolean",
                    "description": "true: keeps its size on a novel face; false: stretches",
                }
            },
            "description": 'a label\'s properties: {"fixed": true|false}',
        },
        "block": {
            "type": "object",
            "description": 'a block: {"id", "shape", "size": [width, height, depth], ...}',
            "required": ["id", "shape", "size"],
            "additionalProperties": False,
            "properties": {
                "id": {
                    "type": "string",
                    "minLength": 1,
                    "description": "the block's id, unique in the file",
                },
                "shape": {
                    "enum": ["box", "cylinder", "prism"],
                    "description": "the block's solid: box, cylinder or prism",
                },
                "size": {
                    "type": "array",
                    "items": _LENGTH,
                    "minItems": 3,
                    "maxItems": 3,
                    "description": "[width, height, depth] in metres: the block's extent along its "
                    "local x, y (up) and z",
                },
                "sides": {
                    "type": "integer",
                    "minimum": 3,
                    "maximum": 360,
                    "description": "a cylinder's number of facets, 3 to 360",
                },
                "footprint": {
                    "type": "array",
                    "minItems": 3,
                    "maxItems": 1000,
                    "items": {
                        "type": "array",
                        "items": _COORD,
                        "minItems": 2,
                        "maxItems": 2,
                        "description": "a footprint point [x, z] in metres",
                    },
                    "description": "a prism's plan: [[x, z], ...] in metres in the block's frame, "
                    "at least 3 points, not closed (the last is not the first again)",
                },
                "transform": {
                    "type": "object",
                    "additionalProperties": False,
                    "description": '{"translate": [x, y, z], "rotate": degrees about y}, '
                    "relative to the parent",
                    "properties": {
                        "translate": {
                            "type": "array",
                            "items": _COORD,
                            "minItems": 3,
                            "maxItems": 3,
                            "description": "[x, y, z] in metres, in the parent's frame",
                        },
                        "rotate": {
                            "type": "number",
                            "minimum": -360,
                            "maximum": 360,
                            "description": "degrees about the vertical (y) axis, -360 to 360; "
                            "positive turns +x toward -z",
                        },
                    },
                },
                "parent": {
                    "type": ["string", "null"],
                    "description": "the id of the block this one's transform is relative to, "
                    "or null",
                },
                "attach": {
                    "type": "array",
                    "items": {"$ref": "#/$defs/attach"},
                    "description": "the faces of this block that touch faces of other blocks",
                },
                "floors": {
                    "type": "array",
                    "minItems": 1,
                    "items": {"$ref": "#/$defs/floor"},
                    "description": "the block's floors, bottom to top; their heights sum to the "
                    "block's height",
                },
                "faces": {
                    "type": "object",
                    "additionalProperties": {
                        "type": "array",
                        "minItems": 1,
                        "items": {"$ref": "#/$defs/subface"},
                        "description": "one subface per floor, bottom to top",
                    },
                    "description": "per face name (box: front, right, back, left; cylinder and "
                    'prism: "0", "1", ...), one subface per floor',
                },
                "plain": {"$ref": "#/$defs/label"},
                "roof": {"$ref": "#/$defs/label"},
            },
            "allOf": [
                {
                    "if": {"properties": {"shape": {"const": "cylinder"}}, "required": ["shape"]},
                    "then": {"required": ["sides"]},
                },
                {
                    "if": {"properties": {"shape": {"const": "prism"}}, "required": ["shape"]},
                    "then": {"required": ["footprint"]},
                },
            ],
        },
        "attach": {
            "type": "object",
            "required": ["face", "to", "to_face"],
            "additionalProperties": False,
            "description": 'an attachment: {"face": this block\'s face, "to": another block\'s id, '
            '"to_face": that block\'s face}',
            "properties": {
                "face": {"type": "string", "description": "a face of this block"},
                "to": {"type": "string", "description": "the id of another block"},
                "to_face": {"type": "string", "description": "a face of that block"},
            },
        },
        "floor": {
            "type": "object",
            "required": ["height"],
            "additionalProperties": False,
            "description": 'a floor: {"name": ..., "height": metres}',
            "properties": {
                "name": {
                    "type": "string",
                    "minLength": 1,
                    "description": "the floor's name (base, ground, ...)",
                },
                "height": _LENGTH,
            },
        },
        "subface": {
            "type": "object",
            "additionalProperties": False,
            "description": 'a subface: a leaf {"label", "size", "occluded"} or a subdivision '
            '{"label" (optional), "size", "split": "x"|"y", "parts": [...]}',
            "properties": {
                "label": {"$ref": "#/$defs/label"},
                "size": _LENGTH,
                "occluded": {
                    "type": "boolean",
                    "description": "true when the photographs do not show this subface",
                },
                "split": {
                    "enum": ["x", "y"],
                    "description": "the axis of the subdivision: x (columns, left to right) or "
                    "y (rows, bottom to top)",
                },
                "parts": {
                    "type": "array",
                    "minItems": 1,
                    "items": {"$ref": "#/$defs/part"},
                    "description": "the parts of the subdivision, left to right or bottom to top",
                },
            },
            "dependentRequired": {"split": ["parts"], "parts": ["split"]},
            "if": {"not": {"required": ["split"]}},
            "then": {"required": ["label"]},
        },
        "part": {
            "$ref": "#/$defs/subface",
            "required": ["size"],
            "description": "a part of a subdivision: a subface with its size along the split axis",
        },
    },
}


def schema_text() -> str:
    """The schema as ``docs/captured-model.schema.json`` holds it."""
    return json.dumps(SCHEMA, indent=2, ensure_ascii=False) + "\n"


# ---- errors -----------------------------------------------------------------------------------


def _diag(path: str, where: str, message: str, hint: str | None = None) -> Diagnostic:
    text = f"{where}: {message}" if where else message
    return Diagnostic(path, 0, 0, text, hint)


def _error(path: str, where: str, message: str, hint: str | None = None) -> BgrError:
    return BgrError(_diag(path, where, message, hint))


def _where(parts) -> str:
    """``blocks[0].faces.front[1]`` from a JSON path (keys and indices)."""
    out = ""
    for p in parts:
        if isinstance(p, int):
            out += f"[{p}]"
        elif re.match(r"^[A-Za-z_][A-Za-z0-9_]*$", p):
            out += f".{p}" if out else p
        else:
            out += f"[{_show(p)}]"  # a 10,000-character key is cut
    return out


def _join(where: str, key) -> str:
    return _where([key]) if not where else where + _where(["_", key])[1:]


def _show(value) -> str:
    try:
        text = json.dumps(value, ensure_ascii=False)
    except (TypeError, ValueError):
        text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _num(x: float) -> str:
    return format(x, ".12g")


_KIND = {
    dict: "an object",
    list: "an array",
    str: "a string",
    bool: "a boolean",
    type(None): "null",
    int: "a number",
    float: "a number",
}


def _kind(value) -> str:
    return _KIND.get(type(value), type(value).__name__)


# ---- stage 1: the JSON itself -------------------------------------------------------------------


class _Object(dict):
    """A JSON object that remembers the keys given more than once."""

    duplicates: tuple = ()


def _pairs(pairs):
    obj = _Object(pairs)
    if len(obj) != len(pairs):
        seen, dups = set(), []
        for k, _ in pairs:
            if k in seen and k not in dups:
                dups.append(k)
            seen.add(k)
        obj.duplicates = tuple(dups)
    return obj


def _constant(name: str):
    raise ValueError(f"{name} is not a JSON number")


def parse(text: str, path: str = "<captured>"):
    """The JSON value of a captured-model text; syntax errors point at their line and column."""
    try:
        return json.loads(text, object_pairs_hook=_pairs, parse_constant=_constant)
    except json.JSONDecodeError as exc:
        lines = text.split("\n")
        line = lines[exc.lineno - 1] if 0 < exc.lineno <= len(lines) else None
        raise BgrError(
            Diagnostic(
                path,
                exc.lineno,
                exc.colno,
                f"not valid JSON: {exc.msg}",
                'a captured model is a JSON object: {"bgr_captured": 1, "blocks": [...]}',
                source_line=line,
            )
        ) from None
    except ValueError as exc:  # NaN, Infinity; integers too long to convert
        raise _error(path, "", f"not valid JSON: {exc}") from None
    except RecursionError:
        raise _error(
            path, "", f"the JSON is nested too deeply (more than {MAX_NESTING} levels)"
        ) from None


def _check_json(data, path: str) -> list[Diagnostic]:
    """Stage 1, without recursion: JSON types only, finite numbers, no duplicate keys, bounded
    nesting (so that the schema validator and the builder cannot run out of stack)."""
    out: list[Diagnostic] = []
    stack = [(data, "", 1)]
    count = 0
    while stack:
        value, where, depth = stack.pop()
        count += 1
        if count > MAX_VALUES:  # before the schema validator's time grows with it
            return [_too_many(path)]
        if depth > MAX_NESTING:
            out.append(_diag(path, where, f"nested too deeply (more than {MAX_NESTING} levels)"))
            continue
        if isinstance(value, dict):
            for key in getattr(value, "duplicates", ()):
                out.append(
                    _diag(
                        path,
                        _join(where, key),
                        "given twice in one object",
                        "JSON keeps only the last one; remove the other",
                    )
                )
            items = []
            for key, item in value.items():
                if not isinstance(key, str):
                    out.append(_diag(path, where, f"has a key that is not a string: {key!r}"))
                    continue
                items.append((item, _join(where, key), depth + 1))
            stack.extend(reversed(items))
        elif isinstance(value, list):
            stack.extend(
                reversed([(item, _join(where, i), depth + 1) for i, item in enumerate(value)])
            )
        elif isinstance(value, float):
            if not math.isfinite(value):
                out.append(_diag(path, where, f"{value} is not a JSON number"))
        elif isinstance(value, int) and not isinstance(value, bool):
            if abs(value) > 10**300:
                out.append(_diag(path, where, "a number too large to be a length or a coordinate"))
        elif not isinstance(value, (str, bool)) and value is not None:
            out.append(_diag(path, where, f"{type(value).__name__} is not a JSON value"))
    return out


def _too_many(path: str) -> Diagnostic:
    return _diag(
        path,
        "",
        f"the captured model holds more than {MAX_VALUES:,} JSON values",
        "infer each building from a file of its own (docs/limits.md)",
    )


# ---- stage 2: the JSON Schema -------------------------------------------------------------------

_VALIDATOR = None


def _validator():
    global _VALIDATOR
    if _VALIDATOR is None:
        try:
            from jsonschema import Draft202012Validator
        except ImportError:  # pragma: no cover - a declared dependency
            raise BgrError(
                Diagnostic(
                    "",
                    0,
                    0,
                    "reading a captured model needs the jsonschema package",
                    "pip install jsonschema",
                )
            ) from None
        _VALIDATOR = Draft202012Validator(SCHEMA)
    return _VALIDATOR


def _resolve(schema: dict) -> dict:
    ref = schema.get("$ref", "")
    return SCHEMA["$defs"].get(ref.rsplit("/", 1)[-1], schema) if ref else schema


def _expected(schema: dict) -> str:
    """What a schema asks for, in words."""
    if "description" in schema:
        return schema["description"]
    return "a valid value"


def _schema_diagnostics(error, path: str) -> list[Diagnostic]:
    """One jsonschema error as diagnostics that name the offending element and what is expected."""
    parts = list(error.absolute_path)
    where = _where(parts)
    schema = error.schema if isinstance(error.schema, dict) else {}
    kind, value, instance = error.validator, error.validator_value, error.instance
    hint = schema.get("description")
    if "propertyNames" in error.relative_schema_path:
        return [_diag(path, _join(where, instance), "not a valid label", hint)]
    if kind == "required":
        out = []
        for key in value:
            if not isinstance(instance, dict) or key in instance:
                continue
            if key == "label" and "description" not in schema:  # the subface's if/then
                what = "a leaf subface (one without split and parts) needs a label"
            elif key in schema.get("properties", {}):
                what = _expected(_resolve(schema["properties"][key]))
            elif "description" in schema:  # a part of a split: its size
                what = schema["description"]
            else:  # a shape's own key (sides, footprint)
                what = _expected(SCHEMA["$defs"]["block"]["properties"].get(key, {}))
            out.append(_diag(path, _join(where, key), "missing", what))
        return out
    if kind == "additionalProperties" and isinstance(instance, dict):
        known = list(schema.get("properties", {}))
        out = []
        for key in instance:
            if key not in known:
                hint = suggest(key, known) or (
                    "expected one of: " + ", ".join(known) if known else None
                )
                out.append(_diag(path, _join(where, key), "unknown key", hint))
        return out
    if kind == "dependentRequired" and isinstance(instance, dict):
        out = []
        for key, needs in value.items():
            if key in instance:
                for other in needs:
                    if other not in instance:
                        out.append(
                            _diag(
                                path,
                                _join(where, other),
                                f'missing: a subface with "{key}" needs "{other}"',
                                _expected(SCHEMA["$defs"]["subface"]),
                            )
                        )
        return out
    if kind == "type":
        types = value if isinstance(value, list) else [value]
        words = " or ".join(
            {
                "object": "an object",
                "array": "an array",
                "string": "a string",
                "number": "a number",
                "integer": "an integer",
                "boolean": "true or false",
                "null": "null",
            }.get(t, t)
            for t in types
        )
        return [
            _diag(path, where, f"expected {words}, got {_kind(instance)} {_show(instance)}", hint)
        ]
    if kind == "enum":
        return [
            _diag(
                path, where, f"{_show(instance)} is not one of {', '.join(map(str, value))}", hint
            )
        ]
    if kind == "const":
        return [_diag(path, where, f"expected {_show(value)}, got {_show(instance)}", hint)]
    if kind in ("exclusiveMinimum", "minimum", "maximum", "exclusiveMaximum"):
        word = {
            "exclusiveMinimum": "greater than",
            "minimum": "at least",
            "maximum": "at most",
            "exclusiveMaximum": "less than",
        }[kind]
        return [_diag(path, where, f"must be {word} {_num(value)}, got {_show(instance)}", hint)]
    if kind in ("minItems", "maxItems"):
        n = len(instance) if isinstance(instance, list) else 0
        if schema.get("minItems") == schema.get("maxItems"):
            need = f"exactly {value}"
        else:
            need = f"at least {value}" if kind == "minItems" else f"at most {value}"
        return [_diag(path, where, f"has {n} item{'s' * (n != 1)}, expected {need}", hint)]
    if kind == "minLength":
        return [_diag(path, where, "must not be empty", hint)]
    if kind == "pattern":
        return [_diag(path, where, f"{_show(instance)} is not an identifier", hint)]
    return [_diag(path, where, error.message, hint)]  # pragma: no cover - every keyword above


def _check_schema(data, path: str) -> list[Diagnostic]:
    errors = sorted(
        _validator().iter_errors(data),
        key=lambda e: (
            [(0, p) if isinstance(p, int) else (1, p) for p in e.absolute_path],
            str(e.validator),
        ),
    )
    out: list[Diagnostic] = []
    seen = set()
    for error in errors:
        for d in _schema_diagnostics(error, path):
            if d.message not in seen:
                seen.add(d.message)
                out.append(d)
    return out


# ---- geometry ---------------------------------------------------------------------------------


def _normal(x_axis) -> tuple[float, float, float]:
    """The outward normal of a vertical face whose x axis (left to right from outside) is given:
    x × y, the face frame being right-handed (x along the face, y up, z out)."""
    return (0.0 - x_axis[2], 0.0, x_axis[0] + 0.0)


def _snap(v: float) -> float:
    """Rounding noise of sin and cos (1e-16) off, and no -0.0: coordinates read as written."""
    return round(v, 12) + 0.0


class _Frame:
    """A rotation about y (radians) followed by a translation: local -> parent coordinates."""

    def __init__(self, angle: float = 0.0, t=(0.0, 0.0, 0.0)) -> None:
        self.angle, self.t = angle, tuple(t)
        self.c, self.s = math.cos(angle), math.sin(angle)

    def direction(self, v):
        x, y, z = v
        return (_snap(x * self.c + z * self.s), _snap(y), _snap(-x * self.s + z * self.c))

    def point(self, p):
        d = self.direction(p)
        return (_snap(d[0] + self.t[0]), _snap(d[1] + self.t[1]), _snap(d[2] + self.t[2]))

    def then(self, parent: _Frame) -> _Frame:
        """This frame, placed in ``parent``'s: the composition parent ∘ self."""
        return _Frame(self.angle + parent.angle, parent.point(self.t))


def _outline(block: dict) -> list[tuple[str, tuple, tuple, float]]:
    """The vertical faces of a block in its own frame, in ring order (each face's right end is
    the next one's left end, seen from outside): (name, bottom-left origin, x axis, width)."""
    w, _, d = (float(v) for v in block["size"])
    shape = block["shape"]
    if shape == "box":
        local = {
            "front": ((w, 0.0, 0.0), (-1.0, 0.0, 0.0), w),
            "left": ((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), d),
            "back": ((0.0, 0.0, d), (1.0, 0.0, 0.0), w),
            "right": ((w, 0.0, d), (0.0, 0.0, -1.0), d),
        }
        return [(name, *local[name]) for name in BOX_RING]
    if shape == "cylinder":
        n = int(block["sides"])
        a, b = w / 2, d / 2
        step = 2 * math.pi / n

        def at(angle):
            return (a + a * math.cos(angle), 0.0, b + b * math.sin(angle))

        # facet 0 faces the front (-z); the ring runs -z, -x, +z, +x as a box's does
        points = [at(-math.pi / 2 + step / 2 - i * step) for i in range(n)]
        edges = [(str(i), points[i], points[(i + 1) % n]) for i in range(n)]
    else:
        pts = [(float(x), 0.0, float(z)) for x, z in block["footprint"]]
        n = len(pts)
        edges = [(str(i), pts[i], pts[(i + 1) % n]) for i in range(n)]
        if _signed_area(block["footprint"]) > 0:  # the other winding: every face runs backwards
            edges = [(name, q, p) for name, p, q in edges]
            edges = edges[:1] + edges[1:][::-1]
    out = []
    for name, p, q in edges:
        dx, dz = q[0] - p[0], q[2] - p[2]
        length = math.hypot(dx, dz)
        axis = (dx / length, 0.0, dz / length) if length > 0 else (1.0, 0.0, 0.0)
        out.append((name, p, axis, length))
    return out


def _signed_area(points) -> float:
    """Shoelace area in (x, z); negative for the ring order of a box (front, left, back, right)."""
    n = len(points)
    return 0.5 * sum(
        points[i][0] * points[(i + 1) % n][1] - points[(i + 1) % n][0] * points[i][1]
        for i in range(n)
    )


def _side_of(normal) -> str:
    x, _, z = normal
    if abs(x) >= abs(z) - 1e-9:
        return "right" if x > 0 else "left"
    return "back" if z > 0 else "front"


def _face_names(block: dict) -> list[str]:
    if block["shape"] == "box":
        return list(BOX_FACES)
    if block["shape"] == "cylinder":
        return [str(i) for i in range(int(block["sides"]))]
    return [str(i) for i in range(len(block["footprint"]))]


def _names_hint(block: dict) -> str:
    names = _face_names(block)
    shown = ", ".join(names if len(names) <= 8 else names[:3] + ["...", names[-1]])
    return f"a {block['shape']}'s faces are {shown}"


# ---- stage 3: meaning, and the model ------------------------------------------------------------


class _Reader:
    def __init__(self, data: dict, path: str, fixed: dict[str, bool] | None) -> None:
        from bgr.grammar.registry import KEYWORDS

        self.data, self.path = data, path
        self.keywords = set(KEYWORDS)
        self.diags: list[Diagnostic] = []
        declared = {k: v["fixed"] for k, v in data.get("labels", {}).items()}
        self.fixed = {**declared, **(fixed or {})}
        self.used: list[str] = []

    def fail(self, where: str, message: str, hint: str | None = None) -> None:
        self.diags.append(_diag(self.path, where, message, hint))

    def raise_if_failed(self) -> None:
        if self.diags:
            raise BgrError(self.diags)

    def is_fixed(self, label: str) -> bool:
        return self.fixed.get(label, default_fixed(label))

    def use_label(self, label: str, where: str) -> None:
        if label in self.keywords:
            self.fail(
                where,
                f"{label!r} is a keyword of the bgr language, so it cannot name a terminal",
                f"rename it, e.g. {label}_",
            )
        elif label not in self.used:
            self.used.append(label)

    # ---- the scene graph --------------------------------------------------------------------
    def check_blocks(self) -> dict[str, int]:
        blocks = self.data["blocks"]
        ids: dict[str, int] = {}
        for i, b in enumerate(blocks):
            if b["id"] in ids:
                self.fail(
                    f"blocks[{i}].id",
                    f"{b['id']!r} is also the id of blocks[{ids[b['id']]}]",
                    "block ids are unique",
                )
            else:
                ids[b["id"]] = i
        for i, b in enumerate(blocks):
            where = f"blocks[{i}]"
            if "sides" in b and b["shape"] != "cylinder":
                self.fail(
                    f"{where}.sides", f"only a cylinder has sides, and this block is a {b['shape']}"
                )
            if "footprint" in b and b["shape"] != "prism":
                self.fail(
                    f"{where}.footprint",
                    f"only a prism has a footprint, and this block is a {b['shape']}",
                )
            parent = b.get("parent")
            if parent is not None and parent not in ids:
                self.fail(
                    f"{where}.parent",
                    f"no block has the id {parent!r}",
                    suggest(parent, ids) or "parent is the id of another block, or null",
                )
            if b["shape"] == "prism" and "footprint" in b:
                self.check_footprint(b, where)
        # cycles: follow each chain of parents
        reported: set[int] = set()
        for i in range(len(blocks)):
            chain, j = [], i
            while j is not None and j not in chain:
                chain.append(j)
                parent = blocks[j].get("parent")
                j = ids.get(parent) if parent is not None else None
            if j is not None and j == i and i not in reported:
                cycle = chain[chain.index(j) :]
                reported.update(cycle)
                names = " -> ".join(repr(blocks[k]["id"]) for k in cycle + [j])
                self.fail(
                    f"blocks[{i}].parent",
                    f"the parents form a cycle: {names}",
                    "the scene graph is a tree: one block at its root has parent null",
                )
        for i, b in enumerate(blocks):
            for k, att in enumerate(b.get("attach", [])):
                where = f"blocks[{i}].attach[{k}]"
                if att["face"] not in _face_names(b):
                    self.fail(
                        f"{where}.face",
                        f"{att['face']!r} is not a face of this {b['shape']}",
                        suggest(att["face"], _face_names(b)) or _names_hint(b),
                    )
                target = ids.get(att["to"])
                if target is None:
                    self.fail(
                        f"{where}.to",
                        f"no block has the id {att['to']!r}",
                        suggest(att["to"], ids) or "to is the id of another block",
                    )
                elif target == i:
                    self.fail(f"{where}.to", "a block cannot be attached to itself")
                elif att["to_face"] not in _face_names(blocks[target]):
                    other = blocks[target]
                    self.fail(
                        f"{where}.to_face",
                        f"{att['to_face']!r} is not a face of block {att['to']!r} (a "
                        f"{other['shape']})",
                        suggest(att["to_face"], _face_names(other)) or _names_hint(other),
                    )
        return ids

    def check_footprint(self, b: dict, where: str) -> None:
        w, _, d = b["size"]
        pts = b["footprint"]
        ok = True
        for k, (x, z) in enumerate(pts):
            if not (-TOL <= x <= w + TOL and -TOL <= z <= d + TOL):
                self.fail(
                    f"{where}.footprint[{k}]",
                    f"[{_num(x)}, {_num(z)}] lies outside the block's "
                    f"plan [0, {_num(w)}] x [0, {_num(d)}]",
                    "size is [width, height, depth]: the "
                    "footprint lies within x in [0, width], z in [0, depth]",
                )
                ok = False
        n = len(pts)
        for k in range(n):
            p, q = pts[k], pts[(k + 1) % n]
            if math.hypot(q[0] - p[0], q[1] - p[1]) <= TOL:
                hint = (
                    "do not close the ring: the last point is joined to the first"
                    if k == n - 1
                    else "each edge of the footprint is a face: it needs a length"
                )
                self.fail(f"{where}.footprint[{(k + 1) % n}]", "repeats the point before it", hint)
                ok = False
        if ok:
            from shapely.geometry import Polygon
            from shapely.validation import explain_validity

            poly = Polygon([(x, z) for x, z in pts])
            if not poly.is_valid or poly.area <= TOL:
                reason = explain_validity(poly) if not poly.is_valid else "it has no area"
                self.fail(
                    f"{where}.footprint",
                    f"not a simple polygon: {reason}",
                    "the points go once round the plan, edges not crossing",
                )

    def frames(self, ids: dict[str, int]) -> list[_Frame]:
        """Each block's frame in world coordinates: its transform composed with its parents'."""
        blocks = self.data["blocks"]
        done: dict[int, _Frame] = {}
        for i in range(len(blocks)):
            chain, j = [], i
            while j not in done:  # up to a root or a block already placed (no cycles by now)
                chain.append(j)
                parent = blocks[j].get("parent")
                if parent is None:
                    break
                j = ids[parent]
            for k in reversed(chain):
                t = blocks[k].get("transform", {})
                local = _Frame(
                    math.radians(t.get("rotate", 0.0)),
                    [float(v) for v in t.get("translate", (0.0, 0.0, 0.0))],
                )
                parent = blocks[k].get("parent")
                done[k] = local.then(done[ids[parent]]) if parent is not None else local
        return [done[i] for i in range(len(blocks))]

    # ---- floors and subfaces ----------------------------------------------------------------
    def floors(self, b: dict, where: str) -> list[tuple[str | None, float]]:
        height = float(b["size"][1])
        floors = b.get("floors") or [{"height": height}]
        total = math.fsum(f["height"] for f in floors)
        if not abs(total - height) <= TOL:
            self.fail(
                f"{where}.floors",
                f"the floor heights sum to {_num(total)} m but the block is "
                f"{_num(height)} m tall (size[1])",
                f"difference {_num(height - total)} m",
            )
        return [(f.get("name"), float(f["height"])) for f in floors]


def _build_cell(
    reader: _Reader,
    sub: dict,
    width: float,
    height: float,
    where: str,
    size: float,
    floor_name: str | None = None,
) -> Cell:
    """The Cell of one subface whose rectangle is width x height; ``size`` is its extent along its
    parent's axis.  Sums are checked on the way."""
    label = sub.get("label")
    if "split" not in sub:
        reader.use_label(label, f"{where}.label")
        cell = Cell(size, label, fixed=reader.is_fixed(label))
    else:
        axis, parts = sub["split"], sub["parts"]
        full = width if axis == "x" else height
        total = math.fsum(p["size"] for p in parts)
        if not abs(total - full) <= TOL:
            what = "wide" if axis == "x" else "tall"
            reader.fail(
                where,
                f"the parts (split {axis}) sum to {_num(total)} m but the subface is "
                f"{_num(full)} m {what}",
                f"difference {_num(full - total)} m; sizes: "
                + " + ".join(_num(p["size"]) for p in parts),
            )
        cells = []
        for k, p in enumerate(parts):
            s = float(p["size"])
            w, h = (s, height) if axis == "x" else (width, s)
            cells.append(_build_cell(reader, p, w, h, f"{where}.parts[{k}]", s))
        cell = Cell(size, label or floor_name, axis=axis, parts=cells)
    if sub.get("occluded"):
        cell.occluded = True
        for leaf in cell.leaves():
            leaf.occluded = True
    return cell


def _camel(*parts: str) -> str:
    words = [w for p in parts for w in re.split(r"[^A-Za-z0-9]+", p) if w]
    return "".join(w[:1].upper() + w[1:] for w in words) or "Face"


def _faces_of(reader: _Reader, b: dict, i: int, frame: _Frame) -> list[tuple[str, Face]]:
    where = f"blocks[{i}]"
    floors = reader.floors(b, where)
    height = float(b["size"][1])
    names = _face_names(b)
    given = b.get("faces", {})
    for name in given:
        if name not in names:
            reader.fail(
                _join(f"{where}.faces", name),
                f"not a face of this {b['shape']}",
                suggest(name, names) or _names_hint(b),
            )
    plain = b.get("plain", PLAIN)
    reader.use_label(plain, f"{where}.plain" if "plain" in b else where)
    out = []
    for name, origin, x_axis, width in _outline(b):
        fwhere = _join(f"{where}.faces", name)
        if not width > TOL:
            reader.fail(
                fwhere,
                f"the face is {_num(width)} m wide: too narrow to check its subfaces",
                "faces are at least 1e-6 m wide: check the block's size",
            )
            continue
        subs = given.get(name)
        if subs is not None and len(subs) != len(floors):
            reader.fail(
                fwhere,
                f"{len(subs)} subface{'s' * (len(subs) != 1)} for {len(floors)} "
                f"floor{'s' * (len(floors) != 1)}",
                "one subface per floor, bottom to top: "
                + ", ".join(n or f"floor {k}" for k, (n, _) in enumerate(floors)),
            )
            subs = None
        cells = []
        for k, (floor_name, fh) in enumerate(floors):
            if subs is None:
                cells.append(Cell(fh, plain, fixed=reader.is_fixed(plain)))
                continue
            sub = subs[k]
            swhere = f"{fwhere}[{k}]"
            if "size" in sub and not abs(sub["size"] - fh) <= TOL:
                reader.fail(
                    f"{swhere}.size",
                    f"{_num(sub['size'])} m, but floor {k}"
                    f"{' (' + repr(floor_name) + ')' if floor_name else ''} is {_num(fh)} m tall",
                    "a floor's subface may leave size out: it is the floor's height",
                )
            cells.append(_build_cell(reader, sub, width, fh, swhere, fh, floor_name))
        root = Cell(width, axis="y", parts=cells)
        _set_fixed(root, None)
        world_x = frame.direction(x_axis)
        normal = _normal(world_x)
        face = Face(
            width,
            height,
            root,
            side=_side_of(_normal(x_axis)),
            name=_camel(b["id"], name),
            origin=frame.point(origin),
            x_axis=world_x,
            normal=normal,
        )
        out.append((name, face))
    return out


def _attachments(
    reader: _Reader, blocks: list[dict], faces: list[dict[str, Face]], ids: dict[str, int]
) -> tuple[set[int], set[int]]:
    """(the faces an attachment covers completely, the faces whose left end it covers), as ids
    of Face objects; checks that attached faces are coplanar, face each other and overlap."""
    hidden: set[int] = set()
    start_covered: set[int] = set()
    for i, b in enumerate(blocks):
        for k, att in enumerate(b.get("attach", [])):
            where = f"blocks[{i}].attach[{k}]"
            a = faces[i][att["face"]]
            other = faces[ids[att["to"]]][att["to_face"]]
            pair = (
                f"face {att['face']!r} of {b['id']!r} and face {att['to_face']!r} of {att['to']!r}"
            )
            facing = sum(a.normal[j] * other.normal[j] for j in range(3))
            gap = sum((other.origin[j] - a.origin[j]) * a.normal[j] for j in range(3))
            if not facing <= -1 + 1e-9:
                reader.fail(
                    where,
                    f"{pair} do not face each other",
                    "attached faces are coplanar with "
                    "opposite normals: check the blocks' transforms",
                )
                continue
            if not abs(gap) <= GEOM_TOL:
                reader.fail(
                    where,
                    f"{pair} are {_num(abs(gap))} m apart",
                    "attached faces are coplanar: check the blocks' sizes and transforms",
                )
                continue
            for face, cover in ((a, other), (other, a)):
                covered, touch, start = _covers(cover, face)
                if not touch:
                    reader.fail(
                        where,
                        f"{pair} are in one plane but do not overlap",
                        "check the blocks' sizes and transforms",
                    )
                    break
                if covered:
                    hidden.add(id(face))
                if start:
                    start_covered.add(id(face))
    return hidden, start_covered


def _covers(cover: Face, face: Face) -> tuple[bool, bool, bool]:
    """Whether ``cover`` (in the same plane) hides all of ``face``, overlaps it at all, and
    hides the bottom of its left end."""
    u0 = sum((cover.origin[j] - face.origin[j]) * face.x_axis[j] for j in range(3))
    u1 = u0 + cover.width * sum(cover.x_axis[j] * face.x_axis[j] for j in range(3))
    lo, hi = min(u0, u1), max(u0, u1)
    y_lo, y_hi = cover.origin[1], cover.origin[1] + cover.height
    f_lo, f_hi = face.origin[1], face.origin[1] + face.height
    touch = (
        min(hi, face.width) - max(lo, 0.0) > GEOM_TOL
        and min(y_hi, f_hi) - max(y_lo, f_lo) > GEOM_TOL
    )
    across = y_lo <= f_lo + GEOM_TOL and y_hi >= f_hi - GEOM_TOL
    covered = touch and across and lo <= GEOM_TOL and hi >= face.width - GEOM_TOL
    start = touch and lo <= GEOM_TOL and y_lo <= f_lo + GEOM_TOL
    return covered, touch, start


def model_from_captured(
    data, path: str = "<captured>", fixed: dict[str, bool] | None = None
) -> Model:
    """The Model of a parsed captured-model JSON.  ``fixed`` overrides the file's ``labels``.

    Every problem raises :class:`BgrError`, its diagnostics naming the element by JSON path."""
    diags = _check_json(data, path)
    if diags:
        raise BgrError(diags)
    try:
        diags = _check_schema(data, path)
    except RecursionError:  # pragma: no cover - MAX_NESTING keeps the validator shallow
        raise _error(path, "", "the captured model is nested too deeply to validate") from None
    if diags:
        raise BgrError(diags)
    reader = _Reader(data, path, fixed)
    ids = reader.check_blocks()
    reader.raise_if_failed()
    blocks = data["blocks"]
    frames = reader.frames(ids)
    built = [_faces_of(reader, b, i, frames[i]) for i, b in enumerate(blocks)]
    roofs = []
    for i, b in enumerate(blocks):
        if "roof" in b:
            reader.use_label(b["roof"], f"blocks[{i}].roof")
            if b["roof"] not in roofs:
                roofs.append(b["roof"])
    reader.raise_if_failed()
    by_name = [dict(faces) for faces in built]
    hidden, start_covered = _attachments(reader, blocks, by_name, ids)
    reader.raise_if_failed()
    kept = [[f for _, f in faces if id(f) not in hidden] for faces in built]
    all_faces = [f for faces in kept for f in faces]
    if not all_faces:
        raise _error(path, "blocks", "every face is hidden by an attachment: nothing to infer from")
    # link_faces joins a face to the first face that starts where it ends: one whose start an
    # attached block hides goes last, so that a wall running on past the attachment wins
    link_faces(
        [f for f in all_faces if id(f) not in start_covered]
        + [f for f in all_faces if id(f) in start_covered]
    )
    model_blocks = []
    for b, faces, ring in zip(blocks, kept, built, strict=True):
        w, h, d = (float(v) for v in b["size"])
        plan = [(f.origin[0], f.origin[2]) for _, f in ring]  # every face, hidden ones too
        model_blocks.append(Block(b["id"], faces, w, d, h, b["shape"], footprint=plan))
    labels = list(reader.used) + [lbl for lbl in reader.fixed if lbl not in reader.used]
    labels_fixed = {lbl: reader.is_fixed(lbl) for lbl in labels}
    return Model(model_blocks, source=path, labels_fixed=labels_fixed, roof_labels=roofs)


def load_captured(path: str | Path, fixed: dict[str, bool] | None = None) -> Model:
    """Read and check a captured-model JSON file: see :func:`model_from_captured`."""
    shown = str(path)
    try:
        text = read_input(path, "captured model").decode("utf-8")
    except FileNotFoundError:
        raise _error(shown, "", "no such file") from None
    except IsADirectoryError:
        raise _error(shown, "", "is a directory, not a captured-model JSON file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise _error(shown, "", f"cannot read the captured model: {exc}") from None
    return model_from_captured(parse(text, shown), shown, fixed)


def main(argv: list[str] | None = None) -> int:
    """``python -m bgr.inverse.schema.captured``: print the JSON Schema (the docs' copy)."""
    sys.stdout.write(schema_text())
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
