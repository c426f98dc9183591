"""Each lot's ``report(key, value)`` calls summed up, as CityEngine's Reports pane shows them.

For every key: how many values were reported (``count``); for numbers also their ``sum``,
``mean``, ``min`` and ``max``; for strings and true/false how often each was reported
(``values``).  :func:`reports_of` reads a derived table's lots (the engine keeps each lot's calls
in ``lots[i]["reports"]``), :func:`document` is what ``bgr derive --reports FILE.json`` writes:
every lot's summary and the run's over all lots.
"""

from __future__ import annotations

from collections.abc import Iterable


def summary(calls: Iterable[tuple[str, object]]) -> dict[str, dict]:
    """{key: {"count", "sum", "mean", "min", "max"} or {"count", "values"}}, keys in the order
    they were first reported."""
    numbers: dict[str, list[float]] = {}
    others: dict[str, dict[str, int]] = {}
    order: dict[str, None] = {}
    for key, value in calls:
        order.setdefault(key, None)
        if isinstance(value, float) and not isinstance(value, bool):
            numbers.setdefault(key, []).append(value)
        else:
            shown = ("true" if value else "false") if isinstance(value, bool) else str(value)
            counts = others.setdefault(key, {})
            counts[shown] = counts.get(shown, 0) + 1
    out: dict[str, dict] = {}
    for key in order:
        entry: dict = {"count": len(numbers.get(key, ())) + sum(others.get(key, {}).values())}
        values = numbers.get(key)
        if values:
            total = sum(values)
            entry.update(sum=total, mean=total / len(values), min=min(values), max=max(values))
        if key in others:
            entry["values"] = others[key]
        out[key] = entry
    return out


def reports_of(lots: list[dict]) -> list[dict]:
    """Each lot's name, id and summary, in lot order."""
    return [
        {"name": lot.get("name"), "id": lot.get("id"), "reports": summary(lot.get("reports", ()))}
        for lot in lots
    ]


def document(lots: list[dict], grammar: str, seed: int) -> dict:
    """What ``--reports FILE.json`` holds: the run, each lot's summary and the total's."""
    calls = [call for lot in lots for call in lot.get("reports", ())]
    return {
        "bgr": 1,
        "grammar": grammar,
        "seed": seed,
        "lots": reports_of(lots),
        "total": summary(calls),
    }
