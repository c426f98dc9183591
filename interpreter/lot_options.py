"""``--front`` and ``--map``: the options that say how a GeoJSON lot file becomes lots.

:class:`LotOptions` holds which edge of each footprint is its front and which feature properties
give which attrs (:class:`PropertyMap`); :func:`parse_map` and :func:`parse_front` read the
command line's spelling of them.  :func:`coerce` and :func:`map_properties` turn a feature's
property values into the attr values ``--map`` asks for, when the file is read.  Kept apart from
the reading of the file itself (lots.py), which applies them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from bgr.grammar.errors import BgrError, Diagnostic, HeldWarnings, Warnings

from .values import is_number, number_of, number_problem

FRONTS = ("first", "longest", "street")
MAP_TYPES = ("int", "float", "str", "bool")


@dataclass(frozen=True)
class PropertyMap:
    """``--map ATTR=PROP[:TYPE]``: the feature property ``prop`` gives the attr ``attr``.

    ``type`` coerces the value when the file is read (:func:`coerce`): ``int`` (a number or a
    string that is one, rounded to the nearest whole number, halves away from zero: "3.5" is 4),
    ``float``, ``bool`` (true/false, yes/no, 1/0) or ``str`` (any single value); None passes the
    value as it is, for the attr's own type to judge, as a property of the attr's name is."""

    attr: str
    prop: str
    type: str | None = None

    def __str__(self) -> str:
        return f"{self.attr}={self.prop}" + (f":{self.type}" if self.type else "")


@dataclass(frozen=True)
class LotOptions:
    """How a GeoJSON lot file becomes lots (``bgr derive --front``, ``--map``).

    ``front``: ``first`` (the outline's first edge, the default), ``longest`` (its longest edge
    once cleaned) or ``street`` (the edge whose midpoint is nearest to a line of the GeoJSON file
    ``streets``; on a tie within a millimetre, the longer edge).  ``mapping``: the properties that
    give attrs, applied over the properties of the attrs' own names."""

    front: str = "first"
    streets: str | None = None
    mapping: tuple[PropertyMap, ...] = ()

    def __post_init__(self) -> None:
        if self.front not in FRONTS:
            raise BgrError(f"front must be one of {', '.join(FRONTS)}, got {_shown(self.front)}")
        if (self.front == "street") != (self.streets is not None):
            raise BgrError("front 'street' needs a street file (streets=...), and only it does")
        if not all(isinstance(m, PropertyMap) for m in self.mapping):
            raise BgrError("mapping must be a tuple of PropertyMap (see parse_map)")


def parse_map(text: str) -> PropertyMap:
    """``NAME=PROPERTY[:TYPE]`` as ``--map`` takes it.  A property name may hold colons
    (``building:levels``): the last ``:``-segment is the TYPE only when it is one of int, float,
    str, bool (``floors=building:levels:int``)."""
    name, sep, prop = text.partition("=")
    name, prop = name.strip(), prop.strip()
    kind = None
    head, colon, tail = prop.rpartition(":")
    if colon and tail in MAP_TYPES:
        prop, kind = head, tail
    if not sep or not name or not prop:
        raise BgrError(
            Diagnostic(
                "",
                0,
                0,
                f"--map {text[:60]}: write NAME=PROPERTY[:TYPE]",
                "NAME is an attr of the grammar, PROPERTY a property of the lot file's "
                "features, TYPE int, float, str or bool: --map floors=building:levels:int",
            )
        )
    return PropertyMap(name, prop, kind)


def parse_front(text: str) -> tuple[str, str | None]:
    """``first``, ``longest`` or ``street:LINES.geojson`` as ``--front`` takes it: the front
    and the street file (None but for ``street``)."""
    if text in ("first", "longest"):
        return text, None
    kind, colon, path = text.partition(":")
    if kind == "street" and colon and path:
        return "street", path
    raise BgrError(
        Diagnostic(
            "",
            0,
            0,
            f"--front {text[:60]}: write first, longest or street:LINES.geojson",
            "street:FILE takes the edge nearest to a LineString of FILE (same CRS as the lots)",
        )
    )


def check_mapping(options: LotOptions | None, attrs, path: str = "") -> None:
    """A BgrError, as ``--set`` gives, when ``--map`` names an attr the grammar does not have."""
    from bgr.grammar.errors import suggest

    for item in options.mapping if options is not None else ():
        if item.attr not in attrs:
            hint = suggest(item.attr, attrs) or (
                "attrs: " + ", ".join(attrs) if attrs else "the grammar declares no attrs"
            )
            raise BgrError(
                Diagnostic(
                    path, 0, 0, f"--map {item}: the grammar has no attr '{item.attr}' to set", hint
                )
            )


def coerce(value, kind: str | None) -> tuple[object, str | None]:
    """``(value, None)`` coerced to a --map TYPE, or ``(None, why)`` when it cannot be (why
    follows "is <value>, ")."""
    if isinstance(value, (dict, list)):
        return None, "not a single value"
    if kind is None:
        return value, None
    if kind in ("int", "float"):
        number = number_of(value) if isinstance(value, str) else value
        if not is_number(number):
            return None, "not a number"
        problem = number_problem(number)
        if problem:
            return None, problem
        if kind == "float":
            return float(number), None
        whole = math.floor(abs(number) + 0.5)  # halves away from zero, as round() in .bgr
        return int(whole if number >= 0 else -whole), None
    if kind == "bool":
        if isinstance(value, bool):
            return value, None
        text = value.strip().lower() if isinstance(value, str) else value
        if text in ("true", "yes", "1", 1):
            return True, None
        if text in ("false", "no", "0", 0):
            return False, None
        return None, "not true/false, yes/no or 1/0"
    if isinstance(value, str):
        return value, None
    if isinstance(value, bool):
        return ("true" if value else "false"), None
    return _shown(value), None


def map_properties(
    properties: dict, mapping: tuple, name: str, shown: str, warnings: Warnings | HeldWarnings
) -> dict:
    """The attrs ``mapping`` (PropertyMap items) gives a feature of ``properties``: each value
    coerced (:func:`coerce`); a property that is missing or null gives nothing, silently; one
    that cannot be coerced gives nothing, with a warning naming the feature."""
    out = {}
    for item in mapping:
        value = properties.get(item.prop)
        if value is None:
            continue
        fitted, why = coerce(value, item.type)
        if why is None:
            out[item.attr] = fitted
            continue
        warnings.warn(
            Diagnostic(
                shown,
                0,
                0,
                f"{name}: property '{item.prop}' is {_shown(value)}, {why} (--map {item}); "
                f"the attr '{item.attr}' keeps its value",
                "without --strict the property is ignored with a warning",
            )
        )
    return out


def _shown(value) -> str:
    import json

    try:
        return json.dumps(value, ensure_ascii=False, allow_nan=True)[:60]
    except (TypeError, ValueError):  # not JSON; or an int of more digits than str() converts
        try:
            return repr(value)[:60]
        except ValueError:
            return "a number of thousands of digits"
