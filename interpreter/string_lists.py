"""CGA's string functions (``len``, ``count``, ``find``, ``substring``, ``str``) and its string
lists: several strings in one, each followed by a semicolon (``"a;b;c;"``), with the functions of
CGA's utility library that read and build them (``listItem``, ``listSize``, ``listRandom``...).
A string list is a string, not an array (arrays.py), so it travels through attrs, parameters
and ``+`` like any other string.  A last item without its semicolon is read as an item, as the
functions CityEngine ships do.
"""

from __future__ import annotations

import math


def items(text: str) -> list[str]:
    """The items of a string list (the empty piece after the last semicolon is no item)."""
    parts = text.split(";")
    return parts[:-1] if parts and parts[-1] == "" else parts


def joined(parts: list[str]) -> str:
    """A string list of ``parts``, each followed by its semicolon."""
    return "".join(f"{p};" for p in parts)


def list_item(text: str, index: float) -> str:
    """The item at ``index`` (0-based); "" past either end."""
    found = items(text)
    i = int(index)
    return found[i] if 0 <= i < len(found) else ""


def list_index(text: str, item: str) -> float:
    """Where ``item`` first stands in the list (0-based), or -1."""
    found = items(text)
    return float(found.index(item)) if item in found else -1.0


def list_range(text: str, start: float, end: float) -> str:
    """The items from ``start`` up to, not including, ``end``, as a string list."""
    found = items(text)
    lo = max(0, int(start))
    return joined(found[lo : max(lo, int(end))])


# name: (function, the types of its arguments), as expressions.py's string functions
FUNCTIONS = {
    "listSize": (lambda s: float(len(items(s))), (str,)),
    "listItem": (list_item, (str, float)),
    "listIndex": (list_index, (str, str)),
    "listCount": (lambda s, item: float(items(s).count(item)), (str, str)),
    "listFirst": (lambda s: list_item(s, 0), (str,)),
    "listLast": (lambda s: (items(s) or [""])[-1], (str,)),
    "listAdd": (lambda s, item: joined([*items(s), item]), (str, str)),
    "listRange": (list_range, (str, float, float)),
    "listTerminate": (lambda s: joined(items(s)), (str,)),
}


def _find(text: str, match: str, n: float) -> float:
    """CGA's find(): where the n-th (0-based) occurrence of ``match`` starts, or -1."""
    at, start = -1, 0
    for _ in range(int(n) + 1):
        at = text.find(match, start)
        if at < 0 or not match:
            return float(at)
        start = at + len(match)
    return float(at)


def _substring(text: str, start: float, end: float) -> str:
    """CGA's substring(): the characters from ``start`` up to, not including, ``end``."""
    lo = max(0, int(start))
    hi = max(lo, min(len(text), int(end)))
    return text[lo:hi]


# name: (function, the types of its arguments), every string function expressions.py compiles
TEXT = {
    "len": (lambda s: float(len(s)), (str,)),
    "count": (lambda s, m: float(s.count(m)) if m else 0.0, (str, str)),
    "find": (_find, (str, str, float)),
    "substring": (_substring, (str, float, float)),
    **FUNCTIONS,  # listItem, listSize ...: the string lists
}


def number_text(text: str) -> float | None:
    """A string that spells a finite number, as that number; None otherwise."""
    try:
        value = float(text)
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def as_text(value) -> str | None:
    """CGA's str(): a string as it is, true/false, a number to 10 significant digits without a
    trailing ".0" (str(1.69) is "1.69", str(2.0) "2"), an array as ``(3)[1,2,3]``; None for
    what has no text (a rule)."""
    if isinstance(value, str):
        return value
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return format(value, ".10g")
    if isinstance(value, tuple):  # an array, as CityEngine prints one: (3)[1,2,3]
        return f"({len(value)})[{','.join(str(as_text(v)) for v in value)}]"
    return None
