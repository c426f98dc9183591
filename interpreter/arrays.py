"""CGA's arrays: ``[1, 2, 3]``, ``["a", "b"]``, ``[true, false]``, an item ``a[i]`` (0-based),
and the functions that read and make them (``size``, ``index``, ``splitString``).

An array is a Python tuple of one kind of value (numbers, strings or booleans), as CGA's
``float[]``, ``string[]`` and ``bool[]``; a tuple is hashable, so an array in an attr or a
rule's argument is part of a repeated subtree's key like any other value.  What is wrong
with one raises :class:`ArrayError`, which the expression compiler reports at its place.
"""

from __future__ import annotations

_KINDS = (("numbers", (int, float)), ("strings", (str,)), ("booleans", (bool,)))


class ArrayError(ValueError):
    """An array that cannot be made or read: the message says why."""


def kind_of(value) -> str | None:
    """``numbers``, ``strings`` or ``booleans`` for a value an array can hold; None else."""
    if isinstance(value, bool):
        return "booleans"
    for name, types in _KINDS:
        if isinstance(value, types):
            return name
    return None


def array_of(values: list) -> tuple:
    """The array of ``values``, all of one kind (CGA's arrays are typed)."""
    kinds = {kind_of(v) for v in values}
    if None in kinds:
        raise ArrayError("an array holds numbers, strings or booleans, not arrays or rules")
    if len(kinds) > 1:
        raise ArrayError(f"an array holds one kind of value, not {' and '.join(sorted(kinds))}")
    return tuple(float(v) if kind_of(v) == "numbers" else v for v in values)


def item(array, index) -> object:
    """``array[index]``: 0-based; an index past either end is an error, as in CGA."""
    if not isinstance(array, tuple):
        raise ArrayError(f"only an array has items, not {_shown(array)}")
    if isinstance(index, bool) or not isinstance(index, (int, float)):
        raise ArrayError(f"an array's index is a number, not {_shown(index)}")
    i = int(index)
    if i != index or not 0 <= i < len(array):
        raise ArrayError(f"index {index:g} is outside the array's {len(array)} items")
    return array[i]


def size(array) -> float:
    """CGA's size(): the number of items of an array (or characters of a string)."""
    if isinstance(array, (tuple, str)):
        return float(len(array))
    raise ArrayError(f"size() takes an array or a string, not {_shown(array)}")


def index_of(array, value) -> float:
    """CGA's index(): where ``value`` first stands in the array, or -1."""
    if not isinstance(array, tuple):
        raise ArrayError(f"index() takes an array, not {_shown(array)}")
    return float(array.index(value)) if value in array else -1.0


def split_string(text, separator) -> tuple:
    """CGA's splitString(): the pieces of ``text`` between the separators, as a string array
    (a separator at the end leaves no empty last piece)."""
    if not isinstance(text, str) or not isinstance(separator, str) or not separator:
        raise ArrayError("splitString() takes a string and a non-empty separator")
    pieces = text.split(separator)
    return tuple(pieces[:-1] if pieces and pieces[-1] == "" else pieces)


def _shown(value) -> str:
    if isinstance(value, tuple):
        return "an array"
    if isinstance(value, str):
        return f'the string "{value[:40]}"'
    return repr(value)


# builtin name: (function, its number of arguments)
FUNCTIONS = {"size": (size, 1), "index": (index_of, 2), "splitString": (split_string, 2)}
