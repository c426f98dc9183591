"""set(attribute, value): CGA's set() of a user attribute, for a shape and what it derives.

In CGA an attribute's value belongs to the shape: ``set`` changes it for the current shape, and
the shapes derived from it afterwards inherit the new value; the rest of the lot keeps the old.
bgr keeps the values set so far on the shape (``Shape.attrs``: a sorted tuple of
((module id, name), value), shared by copies until the next ``set``), and a rule reads an attr
that some ``set`` of its file changes from there first (expressions.Compiler.name).  Attrs
computed from the changed one keep the values they had when the lot began, as in CGA.
"""

from __future__ import annotations

from bgr.grammar.registry import SHAPE_ATTRIBUTES

from ..expressions import RuleRef, runtime_error
from ..surfaces import LARGEST, with_value
from .trims import switched


def set_attr(app, shape, step, args) -> bool:
    name, value = args[0], args[1]
    if isinstance(value, RuleRef):
        raise runtime_error(
            app.module,
            step.pos,
            f"set({name}, ...) takes a number, a string or true/false, not the rule "
            f"'{value.member}'",
        )
    if name.startswith("material.color."):  # one channel of color(): r, g or b, 0..1
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 <= value <= 1:
            raise runtime_error(
                app.module, step.pos, f"set({name}, ...) takes a number from 0 to 1, got {value!r}"
            )
        channels = list(shape.color)
        channels["rgb".index(name[-1])] = float(value)
        shape.color = tuple(channels)
        return False
    if name.startswith("material."):  # 0..1, shininess 0..128 (interpreter/surfaces.py)
        attribute = name.split(".", 1)[1]
        largest = LARGEST.get(attribute, 1.0)
        whole = isinstance(value, (int, float)) and not isinstance(value, bool)
        if not whole or not 0.0 <= value <= largest:
            raise runtime_error(
                app.module,
                step.pos,
                f"set({name}, ...) takes a number from 0 to {largest:g}, got {value!r}",
            )
        shape.material = with_value(shape.material, attribute, float(value))
        return False
    if name in SHAPE_ATTRIBUTES:
        if not isinstance(value, bool):
            raise runtime_error(app.module, step.pos, f"set({name}, ...) takes true or false")
        # on: the next comp(f) of a solid makes planes; both off: none carried any more
        shape.trims = switched(shape.trims, name.split(".", 1)[1], value)
        return False
    module, member = app.module.lookup_module(name)  # an imported file's attr: alias.name
    key = (id(module), member)
    values = dict(shape.attrs or ())
    values[key] = value
    shape.attrs = tuple(sorted(values.items()))
    return False
