"""Values that enter a run from outside the grammar: attr overrides (``--set``, ``attrs=``, GeoJSON
properties), lot sizes and seeds.

A grammar's own numbers are checked where they are used; these are checked where they enter, so
that a typo or a broken data file is reported at its source (the option, the feature) rather than
as an overflow or a NaN deep inside a derivation.  The ranges are stated in docs/cli.md ("Values
from outside").
"""

from __future__ import annotations

import math
import re

# |v| of a number attr set from outside: far beyond any size in metres, or any count a grammar
# splits by, yet small enough that products of a few of them stay finite
MAX_NUMBER = 1e9
# |x|, |y| of a footprint coordinate in metres (a projected CRS: Web Mercator reaches 2e7 m),
# and the largest lot side; squares and cross products of these stay far from overflow
MAX_COORDINATE = 1e8
# a seed is a 64-bit number: negative seeds count down from 2**64 (-1 is 2**64 - 1)
SEED_RANGE = (-(2**63), 2**64 - 1)

# the number syntax of the .bgr language (grammar/bgr.lark, NUMBER) with an optional sign, in
# ASCII only: Python's float() also takes "1_000", "inf", "nan" and non-ASCII digits ("١٠")
NUMBER_SYNTAX = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?", re.ASCII)
_INTEGER = re.compile(r"[+-]?[0-9]+", re.ASCII)


def number_of(text: str) -> int | float | None:
    """The number a string spells — ``"6"`` is 6, ``"12.5"`` is 12.5, surrounding spaces
    allowed — or None: no digit separators (``"1_000"``), no non-ASCII digits, no ``inf`` or
    ``nan``, nothing that overflows (``"1e400"``)."""
    text = text.strip()
    if not NUMBER_SYNTAX.fullmatch(text):
        return None
    value = float(text)  # before int(): int() of 5,000 digits is an error, float() is inf
    if not math.isfinite(value):
        return None
    return int(text) if _INTEGER.fullmatch(text) and abs(value) < 2**63 else value


def is_number(value: object) -> bool:
    """A Python number as a grammar sees one (a bool is not one)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def number_problem(value: int | float, limit: float = MAX_NUMBER) -> str | None:
    """Why a number cannot be used — ``"not finite"``, ``"out of range (...)"`` — or None."""
    try:
        x = float(value)
    except OverflowError:  # an int of more than about 309 digits
        x = math.inf
    if math.isnan(x) or (math.isinf(x) and not isinstance(value, int)):
        return "not a finite number"
    if not abs(x) <= limit:
        return f"out of range (at most {limit:.0e} in size)".replace("e+0", "e")
    return None
