"""Derive each repeated subtree once: a façade repeats the same floor, a floor the
same tile, thousands of times, and a rule whose subtree draws no randomness and reads nothing
of where its shape is gives the same terminals, moved, every time.

:func:`reusable` is the static analysis: a rule may be reused when nothing it can reach (its
body, the rules it hands shapes to, the functions and defaults it evaluates) draws randomness
(``rand``, ``randint``, a stochastic body), reads its shape's place or context (``scope.x``,
``split.index``, ``comp.*``, ``depth``, ``seed``) or texture-projects; a rule held in a
parameter is checked when the rule is applied, with its arguments.  :class:`Reuse` keeps, per
(rule, arguments, the shape's size, axes, geometry, colour, material, label and depth), what
the first such subtree emitted, relative to its shape's origin; the engine replays it for
every later shape with the same key.  The axes are part of the key, so a replay only moves
rows: their axes, sizes, meshes, colours and labels are the recorded ones, and their origins
are the recorded offsets plus the new origin.
Paths are the new shape's path plus the recorded suffixes, so the terminal list is the one a
full derivation gives, row for row, in the same order.
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass

from bgr.grammar import nodes as n
from bgr.grammar.registry import OCCLUSION, OPERATIONS

from .context import RuleRef
from .geometry.polygons import RECT
from .limits import MEMORY_CHECK_EVERY
from .operations.trims import relative
from .shapes import Flat, Prism, Solid

# names whose value depends on where the shape is, or on its place among its siblings
PLACED = {
    "scope.x",
    "scope.y",
    "scope.z",
    "split.index",
    "split.total",
    "comp.index",
    "comp.total",
    "comp.left",
    "comp.right",
    "comp.sel",
    "depth",
    "seed",
}
RANDOM = {"rand", "randint", "p", "listRandom"}
OCCLUDED = set(OCCLUSION)  # occlusion queries: their answer depends on the lot around the shape
# a subtree of up to this many terminals is kept the first time it is derived (a tile, a floor);
# a larger one the second time (grid_city at n = 20: 1.34 s and 374 MB keeping all the first
# time, 1.65 s and 281 MB keeping all the second time)
FIRST_MOST = 256
# rows all records hold together, at most: the least recently replayed are forgotten first, so
# memory stays flat however large the city (a façade's floors are replayed right after they
# are recorded, and then never again)
KEEP_MOST = 50_000
# the key under which Reuse.share keeps the analysis in a shared cache
ANALYSIS = "reuse.analysis"
# a rule whose first this many lookups all found nothing is not looked up any more (Helsinki:
# a façade row's end margins, 19,494 lookups, and its first tile, 15,204, never find a record,
# for the replayed floor holds them); its subtrees are still derived at the origin and moved
GIVE_UP = 256
MOVED = "moved only"  # Reuse.worth's mark of such a rule
UNSOUGHT = (None, None)  # Reuse.lookup's answer for it: no key, no record
TEXTURING = {name for name, op in OPERATIONS.items() if op.family == "texturing"}


def reusable(module, name: str, known: dict) -> bool:
    """Whether rule ``name`` of ``module`` may be derived once and replayed (see the module
    docstring); ``known`` caches the answers, by (id(module), name).  A chain of rules deeper
    than Python's recursion allows is answered no, for every rule the search had reached."""
    key = (id(module), name)
    if key in known:
        return known[key]
    before = set(known)
    try:
        return _reusable(module, name, known)
    except RecursionError:
        for reached in set(known) - before:
            known[reached] = False
        return False


def _reusable(module, name: str, known: dict) -> bool:
    key = (id(module), name)
    if key in known:
        return known[key]
    known[key] = True  # a rule that reaches itself: decided by the rest of its body
    rule = module.rules.get(name)
    ok = rule is not None and _body_ok(module, rule, known)
    known[key] = ok
    return ok


def _body_ok(module, rule: n.Rule, known: dict) -> bool:
    local = set(rule.params)
    if not all(_expr_ok(module, d, known, local) for d in rule.defaults if d is not None):
        return False
    body = rule.body
    if isinstance(body, n.Stochastic):
        return False
    if isinstance(body, n.Conditional):
        return all(
            (case.cond is None or _expr_ok(module, case.cond, known, local))
            and _steps_ok(module, case.body.steps, local, known)
            for case in body.cases
        )
    return _steps_ok(module, body.steps, local, known)


def _steps_ok(module, steps, local: set, known: dict) -> bool:
    for step in steps:
        if isinstance(step, n.Push):
            if not _steps_ok(module, step.steps, local, known):
                return False
        elif isinstance(step, n.Successor):
            if not all(_expr_ok(module, _value(a), known, local) for a in step.args):
                return False
            if step.name in local:  # a rule held in a parameter: checked with the arguments
                continue
            target, member = module.lookup_module(step.name)
            if member in target.rules and not _reusable(target, member, known):
                return False
        elif isinstance(step, n.Operation):
            if step.name in TEXTURING or _placed_transform(step):
                return False
            if not all(_expr_ok(module, _value(a), known, local) for a in step.args):
                return False
            if step.block is not None and not _block_ok(module, step.block.entries, local, known):
                return False
    return True


def _placed_transform(step: n.Operation) -> bool:
    """translate() to an absolute place, or rotate() or translate() in the lot's own (object)
    system: what they make depends on where the shape is, or on its lot."""
    if step.name not in ("translate", "rotate") or len(step.args) < 2:
        return False
    mode, system = (a.name if isinstance(a, n.Name) else None for a in step.args[:2])
    return system in ("object", "pivot") or (step.name == "translate" and mode == "abs")


def _block_ok(module, entries, local: set, known: dict) -> bool:
    for entry in entries:
        if isinstance(entry, n.Group):
            if not _block_ok(module, entry.entries, local, known):
                return False
        elif not (
            _expr_ok(module, entry.key, known, local)
            and _steps_ok(module, entry.body.steps, local, known)
        ):
            return False
    return True


def inserts(module, name: str, known: dict) -> bool:
    """Whether rule ``name`` can reach an ``i()`` (its subtree is what trim planes cut: their
    place is then part of its reuse key); a rule held in a parameter counts as one that can.
    ``known`` caches the answers; too deep a chain is answered yes."""
    key = ("i", id(module), name)
    if key in known:
        return known[key]
    try:
        return _inserts(module, name, known)
    except RecursionError:
        return True


def _inserts(module, name: str, known: dict) -> bool:
    key = ("i", id(module), name)
    if key in known:
        return known[key]
    known[key] = False  # a rule that reaches itself: decided by the rest of its body
    rule = module.rules.get(name)
    if rule is None:
        return False
    body = rule.body
    sequences = (
        [body.steps]
        if isinstance(body, n.Sequence)
        else [c.body.steps for c in getattr(body, "cases", getattr(body, "choices", []))]
    )
    found = any(_steps_insert(module, steps, set(rule.params), known) for steps in sequences)
    known[key] = found
    return found


def _steps_insert(module, steps, local: set, known: dict) -> bool:
    for step in steps:
        if isinstance(step, n.Push):
            if _steps_insert(module, step.steps, local, known):
                return True
        elif isinstance(step, n.Successor):
            if step.name in local:
                return True
            target, member = module.lookup_module(step.name)
            if _inserts(target, member, known):
                return True
        elif isinstance(step, n.Operation):
            if step.name == "i":
                return True
            if step.block is not None and _entries_insert(module, step.block.entries, local, known):
                return True
    return False


def _entries_insert(module, entries, local: set, known: dict) -> bool:
    for entry in entries:
        if isinstance(entry, n.Group):
            if _entries_insert(module, entry.entries, local, known):
                return True
        elif _steps_insert(module, entry.body.steps, local, known):
            return True
    return False


def _spawns(rule: n.Rule) -> bool:
    """Whether a rule hands shapes on (a successor, a split, a component split): a rule that
    only paints or inserts makes one terminal, as quick to derive as to replay."""
    bodies = (
        [rule.body.steps]
        if isinstance(rule.body, n.Sequence)
        else [c.body.steps for c in getattr(rule.body, "cases", getattr(rule.body, "choices", []))]
    )
    return any(_spawning(steps) for steps in bodies)


def _spawning(steps) -> bool:
    for step in steps:
        if isinstance(step, n.Successor) or (isinstance(step, n.Operation) and step.block):
            return True
        if isinstance(step, n.Push) and _spawning(step.steps):
            return True
    return False


def _value(arg):
    return (
        arg.value
        if isinstance(arg, n.Keyword)
        else arg.expr
        if isinstance(arg, n.Relative)
        else arg
    )


def _expr_ok(
    module, node, known: dict, local: set | frozenset = frozenset(), seen: frozenset = frozenset()
) -> bool:
    """Whether an expression draws no randomness and reads nothing of its shape's place; a
    name in ``local`` is a parameter (its value is part of the key), even if it is called
    ``depth``."""
    if isinstance(node, n.Name):
        if node.name in local:
            return True
        if node.name in PLACED:
            return False
        target, member = module.lookup_module(node.name)  # a rule handed on as a value
        return member not in target.rules or _reusable(target, member, known)
    if isinstance(node, n.Call):
        if node.name in RANDOM or node.name in OCCLUDED:
            return False
        if not all(_expr_ok(module, a, known, local, seen) for a in node.args):
            return False
        target, member = module.lookup_module(node.name)
        func = target.funcs.get(member) if hasattr(target, "funcs") else None
        if func is not None and (id(target), member) not in seen:
            inner = frozenset(func.params)  # a function sees its parameters, not the rule's
            return _expr_ok(target, func.body, known, inner, seen | {(id(target), member)})
        return True
    if isinstance(node, n.Unary):
        return _expr_ok(module, node.operand, known, local, seen)
    if isinstance(node, n.Binary):
        return _expr_ok(module, node.left, known, local, seen) and _expr_ok(
            module, node.right, known, local, seen
        )
    if isinstance(node, n.Ternary):
        return all(
            _expr_ok(module, e, known, local, seen) for e in (node.cond, node.then, node.otherwise)
        )
    if isinstance(node, (n.Array, n.Index)):
        parts = node.items if isinstance(node, n.Array) else [node.target, node.index]
        return all(_expr_ok(module, e, known, local, seen) for e in parts)
    return True  # a number, a string, a boolean


@dataclass(slots=True)
class Record:
    """What one subtree emitted: its rows' origins relative to its shape's origin, and where
    the rows are in the table.  The other columns (axes, sizes, colours, meshes, labels,
    rules, paths) are never changed once a row is appended, so a replay copies them from the
    table itself: recording costs nothing beyond the origins, which matters because most
    records are never replayed (Helsinki: 140,842 recorded, 51,856 replays)."""

    offsets: list  # per row: origin minus the shape's origin
    start: int  # the rows are the table's start .. start + len(offsets)
    prefix: int  # the length of the recorded shape's path
    shapes: int  # shapes the subtree made
    barren: int
    triangles: int
    suffixes: list | None = None  # per row: its path after the shape's; made at the first replay


class Reuse:
    """The records of one derivation, by key (see the module docstring).

    A reusable rule's subtree is always derived with its shape moved to the world's origin and
    its rows moved back when it is done, whether or not it is replayed, so that a replayed row
    (recorded offset plus origin) and a derived one are the same float64 numbers: with
    ``replay`` off (BGR_REUSE=0) every output is the same, byte for byte.  A small subtree is
    kept the first time it is derived; a large one (a whole façade, which rarely repeats) the
    second time.
    """

    def __init__(self, replay: bool = True) -> None:
        self.replaying = replay
        self.known: dict = {}  # (id(module), rule name) -> reusable?
        # id(rule) -> reusable and making more than one shape? (MOVED: given up looking up)
        self.worth: dict = {}
        self.tries: dict = {}  # id(rule) -> lookups that found nothing; -1 once one found one
        self.seen: set = set()
        self.records: OrderedDict = OrderedDict()  # least recently replayed first
        self.rows = 0  # rows the records hold, at most KEEP_MOST
        self.hits = 0

    def share(self, cache: dict) -> None:
        """Keep the static analysis (which rules may be reused) in ``cache``, a dict that the
        lots of one run share (batch.derive_lot's split cache, whose keys are ids of one
        grammar's nodes too): it depends on the grammar alone, and working it out again for
        every lot was 2 % of Helsinki's time."""
        self.known, self.worth, self.tries = cache.setdefault(
            ANALYSIS, (self.known, self.worth, self.tries)
        )

    def lookup(self, shape, module, rule: n.Rule, args: dict) -> tuple | None:
        """(key, its record or None) of a rule applied to a shape, or None when its subtree is
        not reusable (or is one terminal, which costs no more to derive than to replay).

        The key is made of plain tuples, ids and values, so that hashing it, as every lookup
        does, runs no Python ``__hash__`` (a geometry's or a rule reference's: 1.1 million
        calls on Helsinki)."""
        worth = self.worth.get(id(rule))
        if worth is None:
            worth = self.worth[id(rule)] = _spawns(rule) and reusable(module, rule.name, self.known)
        if not worth or shape.tex is not None:
            return None
        if worth is MOVED:  # derived at the origin wherever a lookup would have been made
            for value in args.values():
                if isinstance(value, RuleRef) and not self._handed_ok(value):
                    return None
            return UNSOUGHT
        geom = shape.geom
        kind = geom.__class__
        if kind is Flat or kind is Prism:
            polys = geom.polys
            geom = (kind, geom.k, geom.name, polys if polys == RECT else tuple(polys))
        elif kind is Solid:
            geom = (kind, geom.mesh, geom.name)
        named: tuple = ()
        if args:
            items = []
            for name, value in sorted(args.items()):
                if isinstance(value, RuleRef):
                    if not self._handed_ok(value):
                        return None
                    value = (RuleRef, id(value.module), value.member)
                items.append((name, value))
            named = tuple(items)
        key = (
            id(module),
            id(rule),
            named,
            tuple(shape.size),
            shape.axes,
            geom,
            shape.color,
            shape.material,
            shape.label,
            shape.depth,
            shape.attrs,  # values set() gave attrs for this shape and what it derives
            # trim planes cut what the subtree inserts: whether they are on and where they
            # stand matters only then
            (relative(shape) if shape.trims else shape.trims is not None)
            if inserts(module, rule.name, self.known)
            else (),
        )
        try:
            found = self.records.get(key)
        except TypeError:  # an argument or a geometry that cannot be a key
            return None
        tries = self.tries.get(id(rule), 0)
        if found is not None:
            if tries >= 0:
                self.tries[id(rule)] = -1  # looked up from now on, however often it misses
        elif tries >= 0:
            self.tries[id(rule)] = tries + 1
            if tries + 1 >= GIVE_UP:
                self.worth[id(rule)] = MOVED
        return key, found

    def _handed_ok(self, ref: RuleRef) -> bool:
        """Whether a rule handed over in an argument keeps its receiver reusable: a terminal,
        or a rule whose own subtree is reusable."""
        return ref.member not in ref.module.rules or reusable(ref.module, ref.member, self.known)

    def record(self, engine, key, where: tuple, start: int, marks: tuple) -> None:
        """Move the rows a subtree emitted (``start`` on, derived at the world's origin) to
        ``where``, its shape's (origin, path) when the rule was applied; keep them for replays
        the second time the key is seen, unless the subtree made textured rows, warnings,
        reports or prints, which are not replayed."""
        t = engine.table
        (ox, oy, oz), path = where
        local = t.origin[start:]
        if ox or oy or oz:  # a piece at its parent's corner (the first of a split) stays put
            t.origin[start:] = [(x + ox, y + oy, z + oz) for x, y, z in local]
        if key is None or not self.replaying:  # UNSOUGHT: moved, not kept
            return
        if key not in self.seen and len(local) > FIRST_MOST:
            self.seen.add(key)  # a large subtree is kept once it repeats (a façade rarely does)
            return
        shapes, barren, triangles, textured, warned, reported = marks
        if (
            len(t.tex_rows) != textured
            or len(engine.warnings) != warned
            or len(engine.reports) + len(engine.prints) != reported  # nor report nor print
        ):
            return
        self.rows += len(local)
        while self.rows > KEEP_MOST and self.records:  # forget the least recently replayed
            self.rows -= len(self.records.popitem(last=False)[1].offsets)
        self.records[key] = Record(
            local,
            start,
            len(path),
            engine.shapes - shapes,
            engine.barren_shapes - barren,
            engine.triangles - triangles,
        )

    def replay(self, engine, key, record: Record, shape, module, pos) -> bool:
        """Emit a record's rows for ``shape``; False (nothing done) when that would pass a
        budget, so that the full derivation reports it where it happens.  ``module`` and
        ``pos`` (the rule's) locate a memory-ceiling error."""
        if (
            engine.shapes + record.shapes > engine.max_shapes
            or engine.triangles + record.triangles > engine.max_triangles
        ):
            return False
        t = engine.table
        ox, oy, oz = shape.origin
        if ox or oy or oz:  # as record() moves them: not at all to the origin itself
            t.origin.extend([(x + ox, y + oy, z + oz) for x, y, z in record.offsets])
        else:
            t.origin.extend(record.offsets)
        start, end = record.start, record.start + len(record.offsets)
        t.axes += t.axes[start:end]
        t.size += t.size[start:end]
        t.color += t.color[start:end]
        t.material += t.material[start:end]
        t.mesh += t.mesh[start:end]
        t.label += t.label[start:end]
        t.rule += t.rule[start:end]
        suffixes = record.suffixes
        if suffixes is None:
            prefix = record.prefix
            suffixes = record.suffixes = [p[prefix:] for p in t.path[start:end]]
        path = shape.path
        t.path += [path + s for s in suffixes]
        before = engine.shapes
        engine.shapes += record.shapes
        engine.barren_shapes += record.barren
        engine.triangles += record.triangles
        self.hits += 1
        self.records.move_to_end(key)
        if engine.max_memory is not None and (
            engine.shapes // MEMORY_CHECK_EVERY != before // MEMORY_CHECK_EVERY
        ):
            engine.check_memory(module, pos)
        return True
