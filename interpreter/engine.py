"""The derivation: applying rules to shapes until only terminals are left.

The loop is iterative (an explicit stack, depth first, children in order), so deep grammars
cannot overflow Python's stack, and terminals come out in the order LANGUAGE.md section 11 fixes.
A rule application runs its sequence of steps on one shape (:class:`Application`, in
application.py); operations are looked up by name in :mod:`bgr.interpreter.operations`, one
function each.  The engine holds what a derivation keeps across its shapes: the attrs' values,
the compiled expressions and plans, the budgets (depth, shapes, triangles, memory), the repeated
subtrees derived once (reuse.py) and the terminal table it emits into, with its unit meshes.
"""

from __future__ import annotations

import gc
import math
import os
from dataclasses import replace
from typing import Any

import numpy as np

from bgr.grammar import nodes as n
from bgr.grammar.checker import bind_problem
from bgr.grammar.errors import BgrError, Diagnostic, Warnings, suggest

from .application import EMIT, Application
from .context import RuleRef
from .expressions import Compiler, evaluate_values, runtime_error
from .geometry import meshes
from .geometry.polygons import RECT
from .limits import (
    BYTES_PER_SHAPE,
    DEFAULT_MAX_DEPTH,
    DEFAULT_MAX_SHAPES,
    DEFAULT_MAX_TRIANGLES,
    MAX_COORDINATE,
    MEMORY_CHECK_EVERY,
    format_bytes,
    memory_in_use,
)
from .operations.trims import kept as kept_trims
from .operations.trims import moved_trims
from .randomness import child_hash, name_hash, root_hash
from .reuse import Reuse
from .shapes import Flat, Shape, Solid
from .terminals import MeshLibrary, TerminalTable, UnitMesh

RECORDED = object()  # marks the end of a reusable subtree on the stack (reuse.py)
# derive each repeated subtree once (reuse.py); BGR_REUSE=0 derives every one in full (the
# same numbers, slower: for tests and measurements)
REUSE = os.environ.get("BGR_REUSE", "1") != "0"
# a flat or prism geometry's key (Engine.mesh_id) -> its unit mesh and MeshLibrary key, kept
# across the lots one process derives: each lot has its own table and library, but a window
# frame's ring, or a storey's slab, is the same mesh in every building (Helsinki: 4,176 prism
# meshes built, 2,271 of them distinct)
_UNIT_MESHES: dict[tuple, tuple] = {}
UNIT_MESHES_MOST = 10_000  # entries kept, at most: the cache is emptied when it grows past this
SHARED_MESH_VERTICES = 64  # meshes of more vertices (a building's mass) rarely repeat: not kept


class Engine:
    """Derives one grammar with one seed and one set of attrs; reusable for several lots."""

    def __init__(
        self,
        grammar,
        seed: int = 0,
        attrs: dict | None = None,
        max_depth: int = DEFAULT_MAX_DEPTH,
        max_shapes: int = DEFAULT_MAX_SHAPES,
        lot_index: int = 0,
        warnings: Warnings | None = None,
        lot_name: str = "",
        max_triangles: int = DEFAULT_MAX_TRIANGLES,
        max_memory: int | None = None,
        memory_base: int | None = None,
    ) -> None:
        self.grammar, self.seed, self.lot_index = grammar, seed, lot_index
        self.warnings = warnings if warnings is not None else Warnings()
        self.lot_name = lot_name  # put before warnings' messages: "feature 12 (id 4253124): ..."
        self.max_depth, self.max_shapes = max_depth, max_shapes
        self.max_triangles, self.max_memory = max_triangles, max_memory
        self.triangles = 0
        # the ceiling budgets what the run allocates, not what the process held before it (a
        # notebook's arrays, a test session): growth is measured from the run's resident memory
        # at its start, ``memory_base`` (this engine's start when not given)
        self.memory_base = 0
        # the shape count at which memory is expected to reach the ceiling (see check_memory)
        self.memory_full_at: float = math.inf
        if max_memory is not None:
            now = memory_in_use()
            self.memory_base = now if memory_base is None else memory_base
            self.memory_full_at = (max_memory - (now - self.memory_base)) / BYTES_PER_SHAPE
        self._mesh_triangles: list[int] = []  # triangles per library mesh id
        self._mesh_images: list[int] = []  # per library mesh id: its own image's index, or -1
        self.compilers: dict[int, Compiler] = {}
        self.attrs = self._prepare_values(grammar, dict(attrs or {}))
        self.table = TerminalTable()
        self.reuse = Reuse(replay=REUSE)
        self.shapes = 0
        self.barren_shapes = 0  # handed to rules that can never end in a terminal (.barren)
        self.reports: list[tuple[str, object]] = []  # report(key, value) calls, in order
        self.prints: list[str] = []  # print(value) texts, in order
        self._bindings: dict = {}
        self._exprs: dict[int, object] = {}
        self._flat_ids: dict[tuple, int] = {}
        self._bare_ids: set[int] = set()  # the meshes of bare shapes (comp(e), comp(v))
        self.solid_slabs: dict[tuple, object] = {}  # (mesh, axis, lo, hi) -> a split's piece
        self.occlusion: Any = None  # occlusion.Recorder or .Occluders when the grammar asks them
        # CGA's object coordinate system (rotate, translate): the lot's scope as the start rule
        # receives it, set by derive()
        self.object_frame: tuple = (
            (0.0, 0.0, 0.0),
            ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),
        )
        self.split_cache: dict = {}  # (block id, sizes, length) -> placed pieces
        self.constant_sizes: dict[int, tuple | None] = {}  # id(entries) -> literal sizes
        # id(operation node) -> its signature (the grammar outlives us)
        self.signatures: dict[int, tuple] = {}
        self.uses_center: dict[int, bool] = {}  # id(step list) -> does it call center()?
        # id(successor) -> (module, member, member's name hash, its rule or None if a terminal,
        # Application.binder's plan)
        self.targets: dict[int, tuple] = {}
        self.rule_locals: dict[int, frozenset] = {}  # id(rule) -> its parameter names
        self.defaults: dict[int, tuple] = {}  # id(rule) -> Application.fill_defaults' plan
        # (id(successor), id(target module), target rule) -> Application.binder's plan
        self.binders: dict[tuple, tuple] = {}
        # the compilers and plans above are the run's, kept for its other lots (shared.py)
        self.shared = False

    def _prepare_values(self, grammar, overrides: dict) -> dict:
        unknown = [k for k in overrides if k not in grammar.attrs]
        if unknown:
            hint = suggest(unknown[0], grammar.attrs) or (
                "attrs: " + ", ".join(grammar.attrs)
                if grammar.attrs
                else "the grammar declares no attrs"
            )
            raise BgrError(
                Diagnostic(
                    grammar.path, 0, 0, f"the grammar has no attr '{unknown[0]}' to set", hint
                )
            )
        seen = set()

        # ``again``: itself, passed in; a closure naming itself is a reference cycle that
        # would hold the engine (and its compiled expressions) until a cyclic collection
        def prepare(g, over, again):
            if id(g) in seen:
                return
            seen.add(id(g))
            for sub in g.imports.values():
                again(sub, {}, again)
            values = evaluate_values(g, over, self.compilers, self.seed, self.lot_index)
            for name, value in values.items():
                if isinstance(value, float) and not math.isfinite(value):
                    item = g.attrs.get(name) or g.consts[name]
                    raise runtime_error(
                        g,
                        item.pos,
                        f"'{name}' is {value!r}: numbers must be finite",
                        "a product or power overflowed? Keep values below 1e308",
                    )

        prepare(grammar, overrides, prepare)
        values = self.compilers[id(grammar)].values
        return {k: values[k] for k in grammar.attrs}

    # ---- expressions -------------------------------------------------------------------------
    def compiled(self, compiler: Compiler, node, local: frozenset):
        key = id(node)
        fn = self._exprs.get(key)
        if fn is None:
            fn = self._exprs[key] = compiler.expr(node, local)
        return fn

    # ---- the loop ------------------------------------------------------------------------------
    def derive(
        self, lot: Shape, rule: str | None = None, index: int = 0, several: bool = False
    ) -> TerminalTable:
        """Derive the start rule (or ``rule``) on a lot; ``index`` numbers lots of one run."""
        grammar = self.grammar
        start = rule or grammar.start
        if start is None or start not in grammar.rules:
            what = f"no rule '{start}'" if start else "no rules to derive"
            raise BgrError(Diagnostic(grammar.path, 0, 0, f"the grammar has {what}"))
        head = grammar.rules[start]
        required = [p for i, p in enumerate(head.params) if head.default(i) is None]
        if required:
            raise runtime_error(
                grammar,
                head.pos,
                f"the start rule '{start}' needs a value for {', '.join(required)}, "
                "but the lot comes with none",
                "give the parameters defaults ('w = 10'), or start from a rule that calls this one",
            )
        lot.path = f"{start}.{index}" if several else start
        self.object_frame = (tuple(lot.origin), lot.axes)
        lot.hash = child_hash(root_hash(self.seed), name_hash(start), index)
        stack = [(lot, grammar, grammar.rules[start], {}, (0, 1, 0, 1, 0.0, 0.0, ""))]
        reuse, table = self.reuse, self.table
        gc_was_on = gc.isenabled()
        # hundreds of thousands of short-lived shapes and no cycles: measured 15% faster
        gc.disable()
        try:
            while stack:
                item = stack.pop()
                first = item[0]
                if first is EMIT:
                    self.emit(*item[1:])
                    continue
                if first is RECORDED:  # a reusable subtree is done: keep what it emitted
                    reuse.record(self, *item[1:])
                    continue
                shape, module, rule_node, args, indices = item
                if shape.trims:  # planes too far to matter are dropped before the key is made
                    shape.trims = kept_trims(shape)
                known = reuse.lookup(shape, module, rule_node, args)
                if known is not None:
                    key, found = known
                    if found is not None and reuse.replay(
                        self, key, found, shape, module, rule_node.pos
                    ):
                        continue
                    marks = (
                        self.shapes,
                        self.barren_shapes,
                        self.triangles,
                        len(table.tex_rows),
                        len(self.warnings),
                        len(self.reports) + len(self.prints),
                    )
                    # derived at the world's origin and moved when done (reuse.py), so that
                    # a replay and a derivation make the same numbers
                    where = (tuple(shape.origin), shape.path)
                    if shape.trims:  # the trim planes move with it
                        shape.trims = moved_trims(shape.trims, shape.origin)
                    shape.origin = [0.0, 0.0, 0.0]
                    stack.append((RECORDED, key, where, len(table.label), marks))
                app = Application(self, shape, module, rule_node, args, indices)
                app.run()
                children = app.children
                done = 0
                for child in children:  # terminals before the first rule: emitted now, in order
                    if child[0] is not EMIT:
                        break
                    self.emit(*child[1:])
                    done += 1
                if done < len(children):
                    stack.extend(reversed(children[done:] if done else children))
        finally:
            if gc_was_on:
                gc.enable()
        return self.table

    def release(self) -> None:
        """Drop the derivation's compiled expressions and plans: they hold the engine and its
        compilers in reference cycles, which otherwise wait for the cyclic collector (55,000
        objects after a style sheet's derivation, 0.1 s to collect).  Shared ones are left to
        the run's other lots (shared.forget drops them)."""
        if self.shared:
            return
        for compiler in self.compilers.values():
            compiler.funcs.clear()
        self.compilers.clear()
        for cache in (
            self._exprs,
            self.signatures,
            self.binders,
            self.targets,
            self._bindings,
            self.defaults,
        ):
            cache.clear()

    def binding_problem(self, ref: RuleRef, step: n.Successor):
        """bind_problem() for a rule held in a parameter, cached per (successor, rule)."""
        key = (id(step), id(ref.module), ref.member)
        if key not in self._bindings:
            if ref.member in ref.module.rules:
                found = bind_problem(ref.module.rules[ref.member], step.args, ref.member)
            else:
                found = (None, f"terminal '{ref.member}' takes no arguments", None)
            self._bindings[key] = found
        return self._bindings[key]

    def warn(self, module, pos, message: str, hint: str | None = None) -> None:
        """A located warning (the grammar's place and the lot's name); an error when strict."""
        error = runtime_error(module, pos, message, hint)
        if self.warnings.strict:
            raise error
        if self.lot_name:
            error.diagnostics[0] = replace(
                error.diagnostics[0], message=f"{self.lot_name}: {message}"
            )
        self.warnings.add(error.diagnostics[0])

    def count_shape(self, module, pos) -> None:
        self.shapes += 1
        if self.shapes > self.max_shapes:
            raise runtime_error(
                module,
                pos,
                f"the derivation made more than {self.max_shapes:,} shapes",
                "a rule multiplies shapes without end? Raise the budget with --max-shapes N",
            )
        if self.shapes % MEMORY_CHECK_EVERY == 0 and self.max_memory is not None:
            self.check_memory(module, pos)

    def check_memory(self, module, pos) -> None:
        """A located error once the run has allocated more than the memory ceiling since it
        started (the process's resident memory less ``memory_base``)."""
        used = memory_in_use() - self.memory_base
        self.memory_full_at = self.shapes + (self.max_memory - used) / BYTES_PER_SHAPE
        if used > self.max_memory:
            raise runtime_error(
                module,
                pos,
                f"the derivation needs more than {format_bytes(self.max_memory)} of memory "
                f"(after {self.shapes:,} shapes)",
                "make fewer or larger pieces, derive fewer lots at once, or raise the ceiling "
                "with --max-memory SIZE",
            )

    def check_scope(self, module, step, shape: Shape) -> None:
        """Sizes and places stay finite and below MAX_COORDINATE (an s('1e308) is caught where
        it is written, not as NaN vertices in a file)."""
        for v in (*shape.size, *shape.origin):
            if not -MAX_COORDINATE <= v <= MAX_COORDINATE:  # also false for NaN
                raise runtime_error(
                    module,
                    step.pos,
                    f"'{step.name}' makes a scope of {v:g} m, beyond the "
                    f"{MAX_COORDINATE:,.0f} m any shape may reach",
                    "check the numbers: sizes and positions are metres",
                )

    # ---- terminals -------------------------------------------------------------------------------
    def emit(self, shape: Shape, label: str, rule: str, module, pos: n.Pos) -> None:
        """Append a terminal row; ``module`` and ``pos`` (where it was made) locate a budget
        error."""
        geom = shape.geom
        if isinstance(geom, Solid) and geom.mesh in self._bare_ids:
            return  # an edge or a vertex left as it is: nothing to show, as in CityEngine
        t = self.table
        t.label.append(shape.label or label)
        t.rule.append(rule)
        t.path.append(shape.path)
        t.origin.append(shape.origin)
        t.axes.append(shape.axes)
        t.size.append(shape.size)
        t.color.append(shape.color)
        t.material.append(shape.material)
        mesh = self.mesh_id(shape.geom)
        t.mesh.append(mesh)
        counts, own = self._mesh_triangles, self._mesh_images
        while len(counts) < len(t.library.meshes):
            unit = t.library.meshes[len(counts)]
            counts.append(len(unit.faces))
            # an inserted asset's own texture: its image in the table, once per unit mesh
            textured = unit.image is not None and unit.uv is not None
            own.append(t.add_image(unit.image) if textured else -1)
        if shape.tex is not None or own[mesh] >= 0:
            t.add_texturing(len(t.label) - 1, shape.tex, own[mesh])
        self.triangles += counts[mesh]
        if self.triangles > self.max_triangles:
            raise runtime_error(
                module,
                pos,
                f"the terminals make more than {self.max_triangles:,} triangles "
                f"(at '{rule}', terminal {len(t.label):,})",
                "make fewer or simpler terminals, or raise the budget with --max-triangles N",
            )

    def mesh_id(self, geom) -> int:
        if isinstance(geom, Solid):
            return geom.mesh
        # equal outlines share one unit mesh: a window's frame ring, cut to the same size on
        # every floor, is built once and instanced
        polys = geom.polys if geom.polys == RECT else tuple(geom.polys)
        key = (type(geom).__name__, geom.k, geom.name, polys)
        found = self._flat_ids.get(key)
        if found is not None:
            return found
        built = _UNIT_MESHES.get(key)
        if built is None:
            if isinstance(geom, Flat):
                verts, faces = meshes.flat_mesh(geom.polys, geom.k)
            else:
                verts, faces = meshes.prism_mesh(geom.polys, geom.k)
            mesh = UnitMesh(geom.name, verts, faces)
            built = (mesh, MeshLibrary.key(mesh))
            if len(verts) <= SHARED_MESH_VERTICES:  # a building's own outline is not kept
                if len(_UNIT_MESHES) >= UNIT_MESHES_MOST:
                    _UNIT_MESHES.clear()
                _UNIT_MESHES[key] = built
        found = self._flat_ids[key] = self.table.library.add(*built)
        return found

    def bare_id(self, name: str) -> int:
        """The empty unit mesh of comp(e)'s edges and comp(v)'s vertices (``name``)."""
        key = ("bare", name)
        found = self._flat_ids.get(key)
        if found is None:
            empty = UnitMesh(name, np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int32))
            found = self._flat_ids[key] = self.table.library.add(empty)
            self._bare_ids.add(found)
        return found

    def primitive_id(self, name: str) -> int:
        key = ("primitive", name)
        found = self._flat_ids.get(key)
        if found is None:
            verts, faces = meshes.primitive(name)
            found = self._flat_ids[key] = self.table.library.add(UnitMesh(name, verts, faces))
        return found
