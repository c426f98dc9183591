"""color, material, label: what the terminals carry to the output files."""

from __future__ import annotations

from ..expressions import runtime_error
from ..occlusion import note
from ..shapes import DEFAULT_COLOR
from ..surfaces import renamed


def _channel(app, step, value) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 <= value <= 1.0:
        raise runtime_error(
            app.module, step.pos, f"a colour channel must be a number in 0..1, got {value!r}"
        )
    return float(value)


_PARSED: dict[str, tuple] = {}


def color(app, shape, step, args) -> bool:
    values = args[:-1]
    if len(values) == 1:
        text = values[0]
        if text in _PARSED:
            shape.color = _PARSED[text]
            return False
        if not (isinstance(text, str) and len(text) == 7 and text[0] == "#"):
            raise runtime_error(
                app.module, step.pos, f"{text!r} is not a colour", 'write "#rrggbb"'
            )
        try:
            shape.color = _PARSED[text] = tuple(int(text[i : i + 2], 16) / 255.0 for i in (1, 3, 5))
        except ValueError:
            raise runtime_error(
                app.module, step.pos, f"{text!r} is not a colour", 'write "#rrggbb"'
            ) from None
    else:
        shape.color = tuple(_channel(app, step, v) for v in values)
    return False


def material(app, shape, step, args) -> bool:
    shape.material = renamed(shape.material, str(args[0]))  # set(material.*) values stay
    return False


def reset_material(app, shape, step, args) -> bool:
    """CGA's resetMaterial(): the shape's material as a new shape's (interpreter/shapes.py)."""
    shape.color, shape.material, shape.tex = DEFAULT_COLOR, None, None
    return False


def label(app, shape, step, args) -> bool:
    shape.label = str(args[0])
    note(app, shape, shape.label)  # a labelled occluder, for inside(all, "name") and the rest
    return False
