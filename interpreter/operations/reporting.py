"""report(key, value): CGA's reports, values a grammar hands out about what it builds.

CityEngine collects each initial shape's ``report()`` calls and shows them per key (count, sum,
average, minimum, maximum); bgr keeps each lot's in derivation order (``Engine.reports``, then
the lot's entry ``reports`` in the terminal table) and sums them up in :mod:`..reports`.  The
shape is not changed.  A reusable subtree that reports is derived each time, not replayed
(reuse.py keeps no record of a subtree that reported), so every call is counted.
"""

from __future__ import annotations

from ..expressions import runtime_error


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
