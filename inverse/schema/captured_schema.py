"""The captured-model format's constants and its JSON Schema.

:data:`SCHEMA` is the JSON Schema (2020-12) a captured-model JSON is validated against;
``docs/captured-model.schema.json`` is :func:`schema_text` written out.  The constants here are
the format's version, the bounds on its lengths and on the size of a document, the tolerances the
sums and the attachments are checked with, and the names of a box's faces.  They are apart from
the reader so that the format's definition reads on its own.
"""

from __future__ import annotations

import json

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
