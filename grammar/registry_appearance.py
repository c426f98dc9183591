"""The roof, insert, appearance, attribute and report operations of the registry: ``roof``,
``i``, ``trim``, ``color``, ``material``, ``label``, ``set``, ``report`` and ``print``.
:mod:`registry` gathers them into ``OPERATIONS`` in the order given here.
"""

from __future__ import annotations

from .registry_kinds import (
    ATTR_NAME,
    COLOR,
    GEOMETRY,
    NUMBER,
    ROOF_KIND,
    STRING,
    VALUE,
    Op,
    Param,
    _sig,
)

ROOFS_INSERTS_APPEARANCE: list[Op] = [
    # -- roofs -------------------------------------------------------------------------
    Op(
        "roof",
        "roofs",
        _sig(
            Param("kind", ROOF_KIND),
            Param("pitch", NUMBER, 30.0),
            Param("overhang", NUMBER, 0.0),
        ),
        "Build a roof of the given kind on a 2D footprint: pitch in degrees, overhang in metres.",
        "roof(hip, 30, 0.5)",
    ),
    # -- inserts -----------------------------------------------------------------------
    Op(
        "i",
        "inserts",
        _sig(Param("geometry", GEOMETRY)),
        "Insert a primitive (cube, cylinder, sphere, quad, wedge) or a declared asset, fitted "
        "to "
        "the scope.",
        "i(cube)",
    ),
    Op(
        "trim",
        "inserts",
        _sig(),
        "Cut the shape's geometry by its trim planes now, as CGA's trim() (`i()` cuts what "
        "it inserts by itself); nothing happens while trimming is off or no plane crosses "
        "the shape, and a shape wholly cut away is gone.",
        "trim()",
    ),
    # -- appearance --------------------------------------------------------------------
    Op(
        "color",
        "appearance",
        (
            (Param("color", COLOR),),
            (Param("r", NUMBER), Param("g", NUMBER), Param("b", NUMBER)),
        ),
        'Set the colour of the shape and its descendants: a "#rrggbb" string or r, g, b in 0..1.',
        'color("#c8b89a")',
    ),
    Op(
        "material",
        "appearance",
        _sig(Param("name", STRING)),
        "Set a named material; the name reaches the output file.",
        'material("brick")',
    ),
    Op(
        "resetMaterial",
        "appearance",
        _sig(),
        "Reset the material, as CGA's resetMaterial: the colour a shape never coloured has "
        "(`#cccccc`), no material name, no set(material.*) values, no texture projections or "
        "maps.",
        "resetMaterial()",
    ),
    Op(
        "label",
        "appearance",
        _sig(Param("name", STRING)),
        "Set the semantic label written to outputs (default: the terminal rule's name).",
        'label("Window")',
    ),
    # -- attributes ----------------------------------------------------------------------
    Op(
        "set",
        "attributes",
        _sig(Param("attribute", ATTR_NAME), Param("value", VALUE)),
        "Set an attr of this file (or `alias.attr` of an imported one) for the shape and "
        "every shape derived from it, as CGA's "
        "set(): rules below read the new value, the rest of the lot the old one (attrs "
        "computed from it keep theirs). `set(trim.vertical, true)` turns CGA's trim planes "
        "on for the shape's subtree (`false` off).",
        "set(floors, floors - 1)",
    ),
    # -- reports -------------------------------------------------------------------------
    Op(
        "report",
        "reports",
        _sig(Param("key", STRING), Param("value", VALUE)),
        "Report a value (a number, a string or true/false) under a key, as CGA's report(): "
        "the shape is unchanged; each lot's reports, summed, counted and averaged per key, "
        "are in the derive result and in `bgr derive --reports FILE.json`.",
        'report("floor area", geometry.area())',
    ),
    Op(
        "print",
        "reports",
        _sig(Param("value", VALUE)),
        "Print a value (as str() writes it) on the console, as CGA's print(): `bgr derive` "
        "writes each lot's prints on standard error, in derivation order; the shape is "
        "unchanged.",
        'print("floors: " + floors)',
    ),
]
