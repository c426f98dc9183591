"""report(key, value) and print(value): what a grammar hands out about what it builds.

CityEngine collects each initial shape's ``report()`` calls and shows them per key (count, sum,
average, minimum, maximum); bgr keeps each lot's in derivation order (``Engine.reports``, then
the lot's entry ``reports`` in the terminal table) and sums them up in :mod:`..reports`.  The
shape is not changed.  ``print`` keeps its text with the lot, for ``bgr derive`` to write on
standard error as CGA writes to its console.  A reusable subtree that reports or prints is
derived each time, not replayed (reuse.py keeps no record of it), so every call is counted.
"""

from __future__ import annotations

from ..expressions import as_text, runtime_error


def report(app, shape, step, args) -> bool:
    key, value = args[0], args[1]
    if not isinstance(key, str):
        raise runtime_error(app.module, step.pos, f"report()'s key must be a string, got {key!r}")
    if isinstance(value, (bool, str)):
        app.engine.reports.append((key, value))
    elif isinstance(value, (int, float)):
        app.engine.reports.append((key, float(value)))
    else:
        raise runtime_error(
            app.module,
            step.pos,
            f"report('{key}', ...) takes a number, a string or true/false, got {value!r:.40}",
        )
    return False


def print_value(app, shape, step, args) -> bool:
    """print(value): its text kept with the lot (``Engine.prints``); ``bgr derive`` writes it."""
    text = as_text(args[0])
    if text is None:
        raise runtime_error(
            app.module,
            step.pos,
            f"print() takes a number, a string or true/false, got {args[0]!r:.40}",
        )
    app.engine.prints.append(text)
    return False
