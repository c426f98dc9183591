"""Every shape operation and built-in function, declared once.

The checker reads the signatures to validate calls, ``docs/operations.md`` is generated from the
docs here (``python -m bgr.grammar.reference > docs/operations.md``), and the interpreter looks up
the implementation of each operation by its name.

Each operation is declared once, in the module of its family: :mod:`registry_transforms`,
:mod:`registry_components` (splits and components), :mod:`registry_appearance` (roofs, inserts,
appearance, attributes, reports) and :mod:`registry_texturing`; the built-in functions and the
names the interpreter provides in :mod:`registry_functions`; the argument kinds and the
:class:`Op` record in :mod:`registry_kinds`.  This module gathers them into ``OPERATIONS`` in the
order the reference lists them, holds the language's keywords, and is where the rest of bgr
imports all of them from.  Adding an operation means adding one :class:`Op` entry to the module
of its family and one function in the interpreter family that ``family`` names.
"""

from __future__ import annotations

from .registry_appearance import ROOFS_INSERTS_APPEARANCE
from .registry_components import SPLITS_AND_COMPONENTS
from .registry_functions import BUILTIN_NAMES, BUILTINS, WORD_ARGUMENTS, Builtin
from .registry_kinds import (
    ANGLE_KINDS,
    ATTR_NAME,
    AXES,
    AXIS,
    AXIS_NAMES,
    CLEANUP_KIND,
    CLEANUP_KINDS,
    COLOR,
    COMP_INDEX_CALLS,
    COMP_KIND,
    COMP_KINDS,
    COMP_SELECTORS,
    COORD_SYSTEM,
    COORD_SYSTEMS,
    EDGE_PICK,
    EDGE_SELECTORS,
    EXTRUDE_KIND,
    EXTRUDE_KINDS,
    FACE_PICK,
    FOOTPRINT_KIND,
    FOOTPRINT_KINDS,
    GEOMETRY,
    INNER_ALIGNMENT,
    INNER_ALIGNMENTS,
    INNER_SELECTORS,
    MANY,
    NORMALIZE_MODE,
    NORMALIZE_MODES,
    NORMALIZE_TYPE,
    NORMALIZE_TYPES,
    NUMBER,
    NUMBER_OR_WORD,
    OCCLUSION,
    OCCLUSION_TARGETS,
    OFFSET_SELECTORS,
    PRIMITIVES,
    PROJECTION_AXES,
    PROJECTION_AXES_NAMES,
    REQUIRED,
    ROOF_KIND,
    ROOF_KINDS,
    SETBACK_SELECTORS,
    SHAPE_ATTRIBUTES,
    SIZE,
    SPLIT_ADJUST,
    SPLIT_ADJUSTS,
    STRING,
    TEX_SIZE,
    TRANSFORM_MODE,
    TRANSFORM_MODES,
    UP_AXES,
    UP_AXIS,
    UV_SETS,
    VALUE,
    VERTEX_SELECTORS,
    Op,
    Param,
)
from .registry_texturing import TEXTURING
from .registry_transforms import TRANSFORMS

__all__ = [
    "ANGLE_KINDS",
    "ATTR_NAME",
    "AXES",
    "AXIS",
    "AXIS_NAMES",
    "BUILTINS",
    "BUILTIN_NAMES",
    "Builtin",
    "CLEANUP_KIND",
    "CLEANUP_KINDS",
    "COLOR",
    "COORD_SYSTEM",
    "COORD_SYSTEMS",
    "COMP_INDEX_CALLS",
    "COMP_KIND",
    "COMP_KINDS",
    "COMP_SELECTORS",
    "EDGE_PICK",
    "EDGE_SELECTORS",
    "EXTRUDE_KIND",
    "EXTRUDE_KINDS",
    "FACE_PICK",
    "FOOTPRINT_KIND",
    "FOOTPRINT_KINDS",
    "GEOMETRY",
    "INNER_ALIGNMENT",
    "INNER_ALIGNMENTS",
    "INNER_SELECTORS",
    "KEYWORDS",
    "MANY",
    "NORMALIZE_MODE",
    "NORMALIZE_MODES",
    "NORMALIZE_TYPE",
    "NORMALIZE_TYPES",
    "NUMBER",
    "NUMBER_OR_WORD",
    "OCCLUSION",
    "OCCLUSION_TARGETS",
    "OFFSET_SELECTORS",
    "OPERATIONS",
    "Op",
    "PRIMITIVES",
    "PROJECTION_AXES",
    "PROJECTION_AXES_NAMES",
    "Param",
    "REQUIRED",
    "ROOF_KIND",
    "ROOF_KINDS",
    "SETBACK_SELECTORS",
    "SHAPE_ATTRIBUTES",
    "SIZE",
    "SPLIT_ADJUST",
    "SPLIT_ADJUSTS",
    "TRANSFORM_MODE",
    "TRANSFORM_MODES",
    "STRING",
    "TEX_SIZE",
    "UP_AXES",
    "UP_AXIS",
    "UV_SETS",
    "VALUE",
    "VERTEX_SELECTORS",
    "WORD_ARGUMENTS",
]

OPERATIONS: dict[str, Op] = {
    op.name: op
    for op in [*TRANSFORMS, *SPLITS_AND_COMPONENTS, *ROOFS_INSERTS_APPEARANCE, *TEXTURING]
}

KEYWORDS = (
    "version",
    "import",
    "as",
    "attr",
    "const",
    "func",
    "start",
    "asset",
    "terminal",
    "site",
    "case",
    "else",
    "NIL",
    "true",
    "false",
    "and",
    "or",
    "not",
)
