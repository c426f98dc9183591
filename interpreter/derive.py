"""The public derivation API: ``bgr.derive(grammar, seed=, attrs=, lot=)``."""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from numbers import Integral, Real
from pathlib import Path

from bgr.grammar.checker import Grammar
from bgr.grammar.errors import BgrError, Diagnostic, Warnings
from bgr.grammar.loader import load
from bgr.grammar.site import table_site

from .batch import Job, derive_lots
from .engine import Engine
from .limits import (
    DEFAULT_MAX_DEPTH,
    DEFAULT_MAX_SHAPES,
    DEFAULT_MAX_TRIANGLES,
    default_max_memory,
)
from .lots import DEFAULT_LOT, Lot, LotOptions, parse_lot_option, rectangle
from .randomness import child_hash, name_hash, root_hash
from .terminals import TerminalTable, concat
from .values import SEED_RANGE, number_problem


@dataclass
class Result:
    """What a derivation made: the terminal table, and ways to turn it into meshes and files."""

    terminals: TerminalTable
    seed: int
    attrs: dict
    # what the run worked around: footprints skipped or repaired, properties ignored, roofs
    # built as another kind; one-line diagnostics (``d.render()``), in the lot file's feature
    # order (interpreter.derive.FeatureOrder), each once
    warnings: list[Diagnostic] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.terminals)

    @property
    def mesh(self):
        """One ``trimesh.Trimesh`` of every terminal, with face colours."""
        from bgr.formats import to_trimesh

        return to_trimesh(self.terminals)

    @property
    def reports(self) -> list[dict]:
        """Each lot's ``report(key, value)`` calls summed up per key: its name, id and
        {key: {"count", "sum", "mean", "min", "max"}} (strings: {"count", "values"}), in lot
        order (interpreter/reports.py)."""
        from .reports import reports_of

        return reports_of(self.terminals.lots)

    @property
    def prints(self) -> list[str]:
        """What the grammar's print() calls wrote, lot after lot, in derivation order."""
        return [text for lot in self.terminals.lots for text in lot.get("prints", ())]

    def save(self, path: str | os.PathLike, fmt: str | None = None) -> None:
        """Write by extension (.glb .gltf .obj .ply .stl .json .city.json .city.jsonl),
        atomically."""
        from bgr.formats import write

        write(self.terminals, Path(path), seed=self.seed, attrs=self.attrs, fmt=fmt)


def derive(
    grammar: Grammar | str | os.PathLike,
    seed: int = 0,
    attrs: dict | None = None,
    lot: str | tuple[float, float] | list[Lot] | None = None,
    *,
    max_depth: int = DEFAULT_MAX_DEPTH,
    max_shapes: int = DEFAULT_MAX_SHAPES,
    max_triangles: int = DEFAULT_MAX_TRIANGLES,
    max_memory: int | None = None,
    start: str | None = None,
    strict: bool = False,
    allow_paths: Iterable[str | os.PathLike] = (),
    lot_options: LotOptions | None = None,
) -> Result:
    """Derive a grammar on one lot or several.

    ``grammar`` is a checked :class:`bgr.Grammar` or anything :func:`bgr.load` takes.  ``lot`` is
    ``(width, depth)``, ``"W,D"`` (or ``"WxD"``), a GeoJSON path, or a list of lots; the default
    is 20 x 20 m.
    Each GeoJSON feature's properties override attrs of the same name for its building.

    What the run works around — a footprint it cannot use (skipped), a property that does not
    fit its attr (ignored), a roof built as another kind — is in ``Result.warnings``; with
    ``strict=True`` the first of them is a :class:`bgr.BgrError` instead.  An error raised while
    deriving one of several lots names the lot ("feature 12 (id 4253124): ...").

    The budgets hold for the whole run, all lots together: ``max_depth`` nested rules,
    ``max_shapes`` shapes, ``max_triangles`` triangles of terminals, and ``max_memory`` bytes
    allocated by the run from its start, whatever the process held before (None: 80 % of the
    memory the machine has available when the run starts).  Passing one of them raises a
    located :class:`bgr.BgrError`; see docs/limits.md.

    ``allow_paths`` is passed to :func:`bgr.load` when ``grammar`` is not loaded yet.
    ``lot_options`` (:class:`~bgr.interpreter.lots.LotOptions`: the front edge, ``--map``) apply
    when ``lot`` is a GeoJSON path.

    Every argument is checked before anything is derived (docs/cli.md, "Values from outside"):
    a seed outside -2**63 .. 2**64 - 1, limits under 1, attrs that are not finite numbers of at
    most 1e9, booleans or strings, or a lot of any other form is a :class:`bgr.BgrError`.
    """
    job, lots, warnings = prepare(
        grammar,
        seed,
        attrs,
        lot,
        max_depth=max_depth,
        max_shapes=max_shapes,
        max_triangles=max_triangles,
        max_memory=max_memory,
        start=start,
        strict=strict,
        allow_paths=allow_paths,
        lot_options=lot_options,
    )
    parts, read, shown = [], FeatureOrder(warnings), []
    for result in derive_lots(job, lots):
        shown += read.before(lots[result.index]) + result.warnings
        parts.append(result.table)
    table = concat(parts, site=site_of(lots, job.grammar), grammar=str(job.grammar.path or ""))
    return Result(table, seed, job.values, _once(shown + read.before(None)))


def prepare(
    grammar: Grammar | str | os.PathLike,
    seed: int = 0,
    attrs: dict | None = None,
    lot: str | tuple[float, float] | list[Lot] | None = None,
    *,
    max_depth: int = DEFAULT_MAX_DEPTH,
    max_shapes: int = DEFAULT_MAX_SHAPES,
    max_triangles: int = DEFAULT_MAX_TRIANGLES,
    max_memory: int | None = None,
    start: str | None = None,
    strict: bool = False,
    allow_paths: Iterable[str | os.PathLike] = (),
    lot_options: LotOptions | None = None,
    per_lot: bool = False,
) -> tuple[Job, list[Lot], Warnings]:
    """The checks of :func:`derive`, and what deriving its lots one by one needs: the run's
    :class:`Job`, its lots, and the warnings reading the lots raised.  ``bgr derive`` uses it
    to derive lots on workers and write them as they come (:mod:`bgr.interpreter.batch`);
    ``per_lot``: the shape and triangle budgets hold for each lot on its own (see Job)."""
    if not isinstance(grammar, Grammar):
        grammar = load(grammar, allow_paths=allow_paths)
    _check_seed(seed)
    _check_limits(max_depth=max_depth, max_shapes=max_shapes, max_triangles=max_triangles)
    attrs = _checked_attrs(attrs)
    warnings = Warnings(strict)
    lots = _lots(lot, warnings, lot_options)
    site_of(lots, grammar)
    probe = Engine(grammar, seed, attrs, max_depth, max_shapes)
    values = probe.attrs  # the run's attrs
    probe.release()
    if max_memory is None:
        max_memory = default_max_memory()
    job = Job(
        grammar,
        seed,
        attrs,
        values,
        start=start,
        strict=strict,
        several=len(lots) > 1,
        max_depth=max_depth,
        max_shapes=max_shapes,
        max_triangles=max_triangles,
        max_memory=max_memory,
        per_lot=per_lot,
    )
    return job, lots, warnings


class FeatureOrder:
    """The warnings of reading the lots, handed out among the lots' own in feature order: before
    a lot, those about its feature and the features before it (one skipped between two lots
    comes between them; one about no feature, a street file's, first); the rest at the end."""

    def __init__(self, warnings: Warnings) -> None:
        self.items = list(zip(warnings.features, warnings.items, strict=True))
        self.at = 0

    def before(self, lot: Lot | None) -> list[Diagnostic]:
        """The warnings to give before ``lot``'s own; with None, all that are left."""
        last = None if lot is None else lot.feature
        out = []
        while self.at < len(self.items):
            feature, diagnostic = self.items[self.at]
            if last is not None and feature is not None and feature > last:
                break
            out.append(diagnostic)
            self.at += 1
        return out


def _once(items: list[Diagnostic]) -> list[Diagnostic]:
    """Warnings in order, each once (lots derived apart may warn alike)."""
    seen, out = set(), []
    for d in items:
        key = (d.path, d.line, d.column, d.message)
        if key not in seen:
            seen.add(key)
            out.append(d)
    return out


def site_of(lots: list[Lot], grammar: Grammar | None = None) -> dict | None:
    """Where the run's local metres are on Earth (TerminalTable.site): the lots' common site
    (read_geojson gives every lot of a file the same one), else the grammar's ``site``
    declaration (grammar/site.py), None for plain metres.  Lots placed in different CRSs or
    about different origins cannot share one output file, nor lots placed on Earth and a
    grammar that declares another place."""
    site = lots[0].site
    if any(each.site != site for each in lots):
        raise BgrError(
            "the lots are placed in different coordinate systems (their site differs); derive "
            "lots of one GeoJSON file, or lots in plain metres, together"
        )
    declaration = grammar.site if grammar is not None else None
    if declaration is None:
        return None if site is None else {**site, "origin": list(site["origin"]), "up": "z"}
    if site is not None:
        raise BgrError(
            Diagnostic(
                str(grammar.path if grammar is not None else ""),
                declaration.pos.line,
                declaration.pos.column,
                "the grammar declares a site, and the lots are placed on Earth by their own "
                "file: only one can say where the output lies",
                "derive the grammar on plain lots, or remove its 'site' line",
            )
        )
    return table_site(declaration)


def _shown(value: object) -> str:
    """``repr`` for a message, cut short (an int of 5,000 digits has no repr at all)."""
    try:
        text = repr(value)
    except ValueError:
        return f"a {type(value).__name__} too large to show"
    return text if len(text) <= 60 else text[:57] + "..."


def _check_seed(seed: object) -> None:
    low, high = SEED_RANGE
    if isinstance(seed, bool) or not isinstance(seed, int) or not low <= seed <= high:
        raise BgrError(
            f"the seed must be a whole number from -2**63 to 2**64 - 1, got {_shown(seed)}"
        )


def _check_limits(**limits: object) -> None:
    for name, value in limits.items():
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise BgrError(f"{name} must be a positive whole number, got {_shown(value)}")


def _checked_attrs(attrs: object) -> dict:
    """A copy of ``attrs=``: names are strings; values numbers (finite, |v| <= MAX_NUMBER),
    booleans or strings, so that a bad value is refused here, naming the attr, rather than
    failing deep in a derivation (or as an OverflowError)."""
    if attrs is None:
        return {}
    if not isinstance(attrs, Mapping):
        raise BgrError(f"attrs must be a dict of attr names to values, got {_shown(attrs)}")
    out = {}
    for name, value in attrs.items():
        if not isinstance(name, str):
            raise BgrError(f"attr names must be strings, got {_shown(name)}")
        if isinstance(value, Real) and not isinstance(value, bool):
            problem = number_problem(value)
            if problem:
                raise BgrError(f"attr '{name}': {_shown(value)} is {problem}")
            value = int(value) if isinstance(value, Integral) else float(value)
        elif not isinstance(value, (bool, str)):
            raise BgrError(
                f"attr '{name}': {_shown(value)} is not a number, true/false or a string"
            )
        out[name] = value
    return out


def _lots(lot: object, warnings: Warnings, options: LotOptions | None = None) -> list[Lot]:
    """The lots ``derive(lot=)`` names: see its docstring; anything else is a BgrError."""
    if lot is None:
        return [rectangle(*DEFAULT_LOT)]
    if isinstance(lot, (str, os.PathLike)):
        return parse_lot_option(os.fspath(lot), warnings, options)
    if isinstance(lot, Lot):
        return [lot]
    if (
        isinstance(lot, (tuple, list))
        and len(lot) == 2
        and all(isinstance(v, Real) and not isinstance(v, bool) for v in lot)
    ):
        return [rectangle(*lot)]
    try:
        lots = list(lot)  # any iterable of lots
    except TypeError:
        lots = None
    if lots is not None and all(isinstance(v, Lot) for v in lots):
        if not lots:
            raise BgrError("lot is an empty list: there is no lot to derive on")
        return lots
    raise BgrError(
        f'lot must be (width, depth), a "W,D" string, a GeoJSON path or a list of lots, '
        f"got {_shown(lot)}"
    )


__all__ = ["derive", "Result", "child_hash", "name_hash", "root_hash"]
