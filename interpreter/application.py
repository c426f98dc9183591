"""One rule applied to one shape (:class:`Application`): its body's steps run in order.

The engine (engine.py) pops a shape and its rule off its stack and hands them here; the
application runs the rule's operations (looked up by name in
:mod:`bgr.interpreter.operations`, one function each) with their arguments evaluated by the
registry's signatures, binds the arguments of each successor, and collects the children: the
shapes handed to rules, and finished terminals in their place (marked :data:`EMIT`), which the
engine then derives or emits depth first, in order.
"""

from __future__ import annotations

from bgr.grammar import nodes as n
from bgr.grammar.registry import (
    ATTR_NAME,
    AXES,
    AXIS,
    CLEANUP_KIND,
    COMP_KIND,
    COORD_SYSTEM,
    EXTRUDE_KIND,
    FOOTPRINT_KIND,
    GEOMETRY,
    INNER_ALIGNMENT,
    NORMALIZE_MODE,
    NORMALIZE_TYPE,
    NUMBER,
    NUMBER_OR_WORD,
    OPERATIONS,
    PER_EDGE,
    PROJECTION_AXES,
    ROOF_KIND,
    ROTATION_PIVOT,
    SIZE,
    SPLIT_ADJUST,
    TEX_SIZE,
    TRANSFORM_MODE,
    UP_AXIS,
)

from .barren import handed
from .context import Context, RuleRef
from .expressions import runtime_error
from .limits import MAX_COORDINATE
from .operations import IMPLEMENTATIONS
from .operations.texturing import follow
from .operations.trims import DELETED
from .randomness import Stream, child_hash, name_hash
from .shapes import Shape

SYMBOL_KINDS = {
    ATTR_NAME,
    AXIS,
    AXES,
    COMP_KIND,
    ROOF_KIND,
    FOOTPRINT_KIND,
    EXTRUDE_KIND,
    GEOMETRY,
    PROJECTION_AXES,
    NORMALIZE_MODE,
    NORMALIZE_TYPE,
    UP_AXIS,
    CLEANUP_KIND,
    INNER_ALIGNMENT,
    SPLIT_ADJUST,
    TRANSFORM_MODE,
    COORD_SYSTEM,
    ROTATION_PIVOT,
}
_NUMERIC_KINDS = {
    NUMBER,
    SIZE,
    TEX_SIZE,
    *NUMBER_OR_WORD,
}  # parameters whose value must be a number
# operations that move or stretch a shape's geometry with its scope: its texture projections and
# coordinates follow (texturing.follow).  reverseNormals keeps the outline where it is.
_MOVERS = frozenset({"t", "r", "s", "center", "matrix", "translate", "rotate"})
_ARRAYS = frozenset({"set", "print"})  # operations that take an array as a value
_NUMBER = (float, int)  # bool is neither: True.__class__ is bool
EMIT = object()  # marks a children-list entry that is a finished terminal, kept in order
_NAME_HASHES: dict[str, int] = {}


def _name_hash(name: str) -> int:
    found = _NAME_HASHES.get(name)
    if found is None:
        found = _NAME_HASHES[name] = name_hash(name)
    return found


def _rule_of(module, member: str):
    """The rule a successor applies; None for a terminal (which makes no new shape)."""
    return None if member in module.terminals else module.rules[member]


# operations after which the scope's size or place may have grown past MAX_COORDINATE
_SCOPE_CHANGERS = frozenset(
    name for name, op in OPERATIONS.items() if op.family in ("transforms", "roofs", "inserts")
) | {"extrude", "taper", "footprint"}


class Application:
    """One rule applied to one shape: runs the body's steps and collects the children."""

    # one is made per shape derived: slots make that, and every attribute read, cheaper
    __slots__ = (
        "engine",
        "shape",
        "module",
        "rule",
        "compiler",
        "local",
        "ctx",
        "children",
        "counter",
    )

    def __init__(
        self,
        engine,  # the Engine deriving the lot (engine.py)
        shape: Shape,
        module,
        rule: n.Rule,
        args: dict,
        indices=(0, 1, 0, 1, 0.0, 0.0, ""),
    ) -> None:
        self.engine, self.shape, self.module, self.rule = engine, shape, module, rule
        self.compiler = engine.compilers[id(module)]
        local = engine.rule_locals.get(id(rule))
        if local is None:
            local = engine.rule_locals[id(rule)] = frozenset(rule.params)
        self.local = local
        # split.index/total and comp.index/total of the piece this shape came from stay visible
        self.ctx = Context(
            shape,
            args,
            Stream(shape.hash),
            engine.seed,
            indices,
            engine.table.library,
            engine.occlusion,
        )
        self.children: list = []
        self.counter = 0
        if len(args) != len(rule.params):
            self.fill_defaults(args)

    def fill_defaults(self, args: dict) -> None:
        """Parameters the caller left out take their defaults, evaluated in order in the rule's
        own module on the shape it received (a default may use the parameters before it)."""
        rule, engine = self.rule, self.engine
        plan = engine.defaults.get(id(rule))
        if plan is None:  # (parameter, compiled default) of each parameter that has one, once
            plan = engine.defaults[id(rule)] = tuple(
                (p, engine.compiled(self.compiler, rule.default(i), frozenset(rule.params[:i])))
                for i, p in enumerate(rule.params)
                if rule.default(i) is not None
            )
        ctx = self.ctx
        for p, fn in plan:
            if p not in args:
                args[p] = fn(ctx)

    def value(self, node):
        return self.engine.compiled(self.compiler, node, self.local)(self.ctx)

    def run(self) -> None:
        body = self.rule.body
        if isinstance(body, n.Sequence):
            self.sequence(self.shape, body.steps)
        elif isinstance(body, n.Stochastic):
            draw = self.ctx.stream.uniform() * 100.0
            acc = 0.0
            chosen = None
            for choice in body.choices:  # every percentage is checked, whichever branch is taken
                if choice.prob is None:
                    chosen = chosen or choice
                    continue
                p = self.value(choice.prob)
                # "not p >= 0" also refuses nan, which compares false with everything
                if isinstance(p, bool) or not isinstance(p, (int, float)) or not p >= 0:
                    raise runtime_error(
                        self.module,
                        choice.pos,
                        f"a percentage must be a number from 0 to 100, got {p!r}",
                    )
                acc += p
                if acc > 100 + 1e-9:
                    raise runtime_error(
                        self.module, choice.pos, f"the percentages add up to {acc:g}%, over 100%"
                    )
                if chosen is None and draw < acc:
                    chosen = choice
            if chosen is not None:  # no else and a draw past the percentages: deleted, as NIL
                self.sequence(self.shape, chosen.body.steps)
        else:
            for case in body.cases:
                if case.cond is None or self.value(case.cond):
                    self.sequence(self.shape, case.body.steps)
                    return

    def sequence(self, shape: Shape, steps) -> None:
        """Run steps on ``shape``; a shape that no successor took and nothing consumed or deleted
        becomes a terminal, in its place among the children (depth first, children in order)."""
        spawned = self.counter
        if not self.steps(shape, steps, self.snapshot(shape, steps)) and self.counter == spawned:
            self.children.append(
                (EMIT, shape, self.rule.name, self.rule.name, self.module, self.rule.pos)
            )

    def steps(self, shape: Shape, steps, received: Shape) -> bool:
        """Run steps; True when the shape was consumed (by a successor, NIL, split, comp...).

        ``received`` is the scope ``center()`` aligns to: the one saved by the last ``[``, or the
        shape the rule received.  What happens inside ``[ ... ]`` works on a copy, and a copy
        that no successor takes is dropped.
        """
        consumed = False
        last = steps[-1] if steps else None
        for step in steps:
            self.ctx.shape = shape
            if isinstance(step, n.Operation):
                moved = (
                    (shape.origin[:], shape.axes, shape.size[:])
                    if shape.tex is not None and step.name in _MOVERS
                    else None
                )
                done = IMPLEMENTATIONS[step.name](self, shape, step, self.arguments(step, received))
                if done:
                    if done is DELETED:  # nothing is left of it (an insert trimmed away)
                        self.ctx.shape = shape
                        return True
                    consumed = True
                if moved is not None:
                    follow(shape, *moved)
                if step.name in _SCOPE_CHANGERS:
                    self.engine.check_scope(self.module, step, shape)
            elif isinstance(step, n.Successor):
                # the last step may hand the shape itself over: nothing uses it afterwards
                self.successor(shape, step, handover=step is last)
                consumed = True
            elif isinstance(step, n.Nil):  # the shape is deleted: later steps have nothing
                self.ctx.shape = shape
                return True
            elif isinstance(step, n.Push):
                self.steps(shape.copy(), step.steps, self.snapshot(shape, step.steps))
        self.ctx.shape = shape
        return consumed

    def snapshot(self, shape: Shape, steps) -> Shape | None:
        """The scope center() aligns to, copied only for step lists that call center()."""
        uses = self.engine.uses_center
        key = id(steps)
        found = uses.get(key)
        if found is None:
            found = uses[key] = any(
                isinstance(s, n.Operation) and s.name == "center" for s in steps
            )
        return shape.copy() if found else None

    def arguments(self, step: n.Operation, received: Shape) -> list:
        """Evaluated arguments by the registry's signature: bare words stay words, a relative
        size becomes ("rel", f), missing optional ones take their defaults; last, ``received``.
        The plan (what each position is) is worked out once per operation node."""
        plan = self.engine.signatures.get(id(step))
        if plan is None:
            plan = self.engine.signatures[id(step)] = self.plan(step)
        ctx = self.ctx
        out = [
            value
            if kind == 0
            else fn(ctx)
            if kind == 1
            else (value, fn(ctx))
            if kind == 2
            else fn  # 3: evaluated by the operation, once per part (setbackPerEdge)
            for kind, value, fn, _ in plan
        ]
        for i, value in enumerate(out):
            # a relative size is ("rel", f); any other tuple is an array
            number = value[1] if plan[i][0] == 2 else value
            if number.__class__ in _NUMBER:
                if not -MAX_COORDINATE <= number <= MAX_COORDINATE:
                    self.out_of_range(step, i, number)
            elif number.__class__ in (str, tuple) and plan[i][3]:
                # the checker types most arguments; a value it cannot type, such as
                # `c ? "a" : 1`, is known only now
                what = "an array" if number.__class__ is tuple else f"{number!r:.40}"
                raise runtime_error(
                    self.module,
                    step.pos,
                    f"{step.name}() needs a finite number, got {what} (argument {i + 1})",
                    "a string or an array where a number goes: an attr set to one, or a "
                    "conditional whose branches give one?",
                )
            elif number.__class__ is tuple and plan[i][0] == 1 and step.name not in _ARRAYS:
                raise runtime_error(
                    self.module,
                    step.pos,
                    f"{step.name}() takes one value, got an array (argument {i + 1})",
                    "pick an item with a[i]",
                )
        out.append(received)
        return out

    def out_of_range(self, step: n.Operation, index: int, number: float) -> None:
        """An operation's number that is not finite, or larger than any building needs."""
        raise runtime_error(
            self.module,
            step.pos,
            f"'{step.name}' argument {index + 1} is {number:g}: an operation's numbers must be "
            f"finite and within ±{MAX_COORDINATE:,.0f}",
            "a product or power overflowed? Sizes and positions are metres",
        )

    def plan(self, step: n.Operation) -> tuple:
        """(kind, constant, compiled, numeric) per parameter: kind 0 a word or default, 1 a
        value, 2 relative, 3 an expression the operation evaluates itself (once per edge);
        numeric: the parameter takes a number (or a size)."""
        spec, count = OPERATIONS[step.name], len(step.args)
        sig = next(
            s
            for s, (least, most) in zip(spec.signatures, spec.arities(), strict=True)
            if least <= count <= most
        )
        plan = []
        for i in range(max(len(sig), count)):
            param = spec.param(sig, i)
            numeric = param.kind in _NUMERIC_KINDS
            if i >= count:
                plan.append((0, param.default, None, numeric))
                continue
            arg = step.args[i]
            if param.kind in SYMBOL_KINDS or (
                param.kind in NUMBER_OR_WORD
                and isinstance(arg, n.Name)
                and arg.name in NUMBER_OR_WORD[param.kind]
            ):
                plan.append((0, arg.name, None, False))
            elif param.kind == PER_EDGE:
                compiled = self.engine.compiled(self.compiler, arg, self.local)
                plan.append((3, None, compiled, False))
            elif isinstance(arg, n.Relative):
                tag = "float" if arg.floating else "rel"
                compiled = self.engine.compiled(self.compiler, arg.expr, self.local)
                plan.append((2, tag, compiled, numeric))
            else:
                compiled = self.engine.compiled(self.compiler, arg, self.local)
                plan.append((1, None, compiled, numeric))
        return tuple(plan)

    def successor(self, shape: Shape, step: n.Successor, handover: bool = False) -> None:
        engine = self.engine
        if step.name in self.local:  # a rule handed over in a parameter
            module, member = self.target(step)
            member_hash, rule, plan = _name_hash(member), _rule_of(module, member), None
        else:
            found = engine.targets.get(id(step))
            if found is None:  # the target and binder's plan, worked out once per successor
                module, member = self.module.lookup_module(step.name)
                plan = self.binder(module, member, step) if step.args else ()
                found = (module, member, _name_hash(member), _rule_of(module, member), plan)
                engine.targets[id(step)] = found
            module, member, member_hash, rule, plan = found
        if member in module.barren:  # a rule that can never end in a terminal
            handed(engine, self.module, step, module.barren[member])
        if plan is None:
            args = self.bind(module, member, step) if step.args else {}
        else:
            ctx = self.ctx
            args = {name: fn(ctx) for name, fn in plan} if plan else {}
        child = shape if handover else shape.copy()
        index = self.counter
        self.counter += 1
        child.path = f"{shape.path}/{member}.{index}"
        child.hash = child_hash(shape.hash, member_hash, index)
        child.depth = shape.depth + 1
        engine.count_shape(self.module, step.pos)
        if child.depth > engine.max_depth:
            raise runtime_error(
                self.module,
                step.pos,
                f"the derivation is deeper than {engine.max_depth} rules (at '{step.name}')",
                "a rule calls itself without end? Raise the limit with --max-depth N",
            )
        if rule is None:  # a terminal
            child.label = child.label or member
            self.children.append((EMIT, child, member, member, self.module, step.pos))
            return
        ctx = self.ctx
        self.children.append(
            (
                child,
                module,
                rule,
                args,
                (
                    ctx.split_index,
                    ctx.split_total,
                    ctx.comp_index,
                    ctx.comp_total,
                    ctx.comp_left,
                    ctx.comp_right,
                    ctx.comp_sel,
                ),
            )
        )

    def target(self, step: n.Successor):
        """The (module, rule name) a parameter used as a successor holds."""
        ref = self.ctx.args[step.name]
        if not isinstance(ref, RuleRef):
            shown = repr(ref)
            if isinstance(ref, (str, float)):
                shown = f'the string "{ref}"' if isinstance(ref, str) else f"the value {ref:g}"
            raise runtime_error(
                self.module,
                step.pos,
                f"parameter '{step.name}' is applied as a rule but holds {shown}",
                f"pass a rule: {self.rule.name}({step.name} = SomeRule)",
            )
        if step.args or ref.member in ref.module.rules:
            problem = self.engine.binding_problem(ref, step)
            if problem is not None:
                raise runtime_error(
                    self.module,
                    step.pos,
                    problem[1] + f" (held by parameter '{step.name}')",
                    problem[2],
                )
        return ref.module, ref.member

    def bind(self, module, member: str, step: n.Successor) -> dict:
        """Argument values by parameter name: positions first, then keywords (the checker, or
        target() for a rule held in a parameter, has made sure they fit)."""
        binders = self.engine.binders
        key = (id(step), id(module), member)
        plan = binders.get(key)
        if plan is None:  # (parameter name, compiled argument) per argument, once per target
            plan = binders[key] = self.binder(module, member, step)
        ctx = self.ctx
        return {name: fn(ctx) for name, fn in plan}

    def binder(self, module, member: str, step: n.Successor) -> tuple:
        """What :meth:`bind` evaluates, worked out once per (successor, target) in a
        derivation: a style sheet's split rules pass 20-30 arguments at every call."""
        if member not in module.rules:
            return ()
        params = module.rules[member].params
        engine, compiler, local = self.engine, self.compiler, self.local
        plan = []
        for i, arg in enumerate(step.args):
            if isinstance(arg, n.Keyword):
                name, node = arg.name, arg.value
            else:
                name, node = params[i], arg.expr if isinstance(arg, n.Relative) else arg
            plan.append((name, engine.compiled(compiler, node, local)))
        return tuple(plan)

    def piece(self, shape: Shape, body: n.Sequence, split=None, comp=None) -> None:
        """Run a block entry's steps on one piece (a split piece, a face, an inset)."""
        ctx = self.ctx
        if comp is None:  # a split piece: only split.index and split.total change
            saved_split = ctx.split_index, ctx.split_total
            if split is not None:
                ctx.split_index, ctx.split_total = split
            self.sequence(shape, body.steps)
            ctx.split_index, ctx.split_total = saved_split
            return
        saved = (
            ctx.split_index,
            ctx.split_total,
            ctx.comp_index,
            ctx.comp_total,
            ctx.comp_left,
            ctx.comp_right,
            ctx.comp_sel,
        )
        if split is not None:
            ctx.split_index, ctx.split_total = split
        ctx.comp_index, ctx.comp_total, ctx.comp_left, ctx.comp_right, ctx.comp_sel = comp
        self.sequence(shape, body.steps)
        (
            ctx.split_index,
            ctx.split_total,
            ctx.comp_index,
            ctx.comp_total,
            ctx.comp_left,
            ctx.comp_right,
            ctx.comp_sel,
        ) = saved
