"""Rules that can never end in a terminal: a warning of ``bgr check`` (and ``bgr.load``).

A derivation emits a shape when a successor names a declared ``terminal``, or when a sequence (a
rule's body, a split piece, a face, an inset) ends with its shape neither consumed (by a
successor, ``NIL``, ``split``, ``comp`` or ``offset``) nor having made a child.  A rule is
*productive* when some alternative of it can emit, by itself or through a productive rule it
hands a shape to; the rest are found as a fixed point.  The analysis over-estimates what can
emit (every branch of a ``case``, every split entry, a rule held in a parameter and a rule of an
imported module count as able to), so it warns only about rules that surely emit nothing.

Rules that emit nothing are fine on their own (``Mass --> NIL``); rules that hand shapes only to
each other in a cycle (``A --> B``, ``B --> A``; ``Lot --> split(x) { ~1: Lot | ~1: Lot }``) run
until a limit stops them, or end having made nothing: each such cycle is one warning, at its
first rule.
"""

from __future__ import annotations

from . import nodes as n
from .errors import Diagnostic, source_line

_CYCLE_SHOWN = 6  # rules of a cycle named in the message


def unproductive_cycles(grammar) -> list[Diagnostic]:
    """One warning per cycle of rules from which no derivation can reach a terminal; each rule
    of such a cycle is put in ``grammar.barren``, with the cycle (the engine stops a derivation
    that hands them too many shapes)."""
    rules: dict[str, n.Rule] = grammar.rules
    deps: dict[str, list[str]] = {}
    productive: set[str] = set()
    for name, rule in rules.items():
        found: list[str] = []
        if _rule_emits(rule, grammar, found):
            productive.add(name)
        deps[name] = found
    # productive = the rules that can reach one that emits by itself (reverse reachability)
    callers: dict[str, list[str]] = {name: [] for name in rules}
    for name, targets in deps.items():
        for target in targets:
            callers[target].append(name)
    todo = list(productive)
    while todo:
        for caller in callers[todo.pop()]:
            if caller not in productive:
                productive.add(caller)
                todo.append(caller)
    barren = {name: [t for t in deps[name] if t not in productive] for name in rules}
    barren = {name: targets for name, targets in barren.items() if name not in productive}
    out = []
    for component in _cycles(barren):
        first = min(component, key=lambda r: (rules[r].pos.line, rules[r].pos.column))
        cycle = _cycle_from(first, component, barren)
        shown = cycle if len(cycle) <= _CYCLE_SHOWN else cycle[:_CYCLE_SHOWN] + ["..."]
        chain = " -> ".join(shown + [first])
        grammar.barren.update(dict.fromkeys(component, chain))
        out.append(_warning(grammar, first, component, chain, barren))
    return sorted(out, key=lambda d: (d.line, d.column))


def _warning(grammar, first: str, component: list[str], chain: str, barren) -> Diagnostic:
    rule = grammar.rules[first]
    names = sorted(component)
    listed = ", ".join(repr(r) for r in names[:_CYCLE_SHOWN])
    if len(names) > _CYCLE_SHOWN:
        listed += f" and {len(names) - _CYCLE_SHOWN} more"
    if len(names) == 1:
        message = f"no terminal is reachable from rule {listed}: it hands shapes only to itself"
    else:
        message = (
            f"no terminal is reachable from rules {listed}: they hand shapes only to each other"
        )
    message += f" ({chain})"
    start = grammar.start
    if start in component:
        message += f"; '{start}' is the start rule"
    elif start in barren and _reaches(start, first, barren):
        message += f"; the start rule '{start}' reaches no terminal either"
    return Diagnostic(
        grammar.path,
        rule.pos.line,
        rule.pos.column,
        message,
        f"give {'it' if len(names) == 1 else 'one of them'} an alternative that ends in a "
        "terminal: a successor declared with 'terminal', or steps that end without a successor, "
        "NIL, split, comp or offset",
        source_line(grammar.module.source, rule.pos.line),
        len(first),
        severity="warning",
    )


def _rule_emits(rule: n.Rule, grammar, deps: list[str]) -> bool:
    """True when the rule can emit by itself; ``deps`` gets the rules of this module it may hand
    a shape to (whose productivity would make it productive)."""
    body = rule.body
    if isinstance(body, n.Sequence):
        bodies = [body]
    elif isinstance(body, n.Stochastic):
        bodies = [c.body for c in body.choices]
    else:
        bodies = [c.body for c in body.cases]
    local = set(rule.params)
    emits = False
    for seq in bodies:
        emits = _sequence(seq.steps, grammar, local, deps, True) or emits
    return emits


def _sequence(steps, grammar, local: set[str], deps: list[str], emits_at_end: bool) -> bool:
    """Whether the steps can emit (the end counts when ``emits_at_end``: not inside ``[ ]``)."""
    consumed = spawned = emits = False
    for step in steps:
        if isinstance(step, n.Nil):
            consumed = True
            break
        if isinstance(step, n.Successor):
            consumed = spawned = True
            emits = _target(step, grammar, local, deps) or emits
        elif isinstance(step, n.Operation):
            if step.block is not None:  # split, comp, offset: each piece ends its own sequence
                consumed = True
                for entry in _entries(step.block.entries):
                    emits = _sequence(entry.body.steps, grammar, local, deps, True) or emits
        elif isinstance(step, n.Push):
            emits = _sequence(step.steps, grammar, local, deps, False) or emits
            spawned = spawned or _spawns(step.steps)
    return emits or (emits_at_end and not consumed and not spawned)


def _spawns(steps) -> bool:
    """Whether ``[ steps ]`` surely hands a shape to a successor (then the end emits nothing)."""
    for step in steps:
        if isinstance(step, n.Nil):
            return False
        if isinstance(step, n.Successor) or (isinstance(step, n.Push) and _spawns(step.steps)):
            return True
    return False


def _entries(entries):
    for entry in entries:
        if isinstance(entry, n.Group):
            yield from _entries(entry.entries)
        else:
            yield entry


def _target(step: n.Successor, grammar, local: set[str], deps: list[str]) -> bool:
    """Whether a successor surely reaches a terminal or may (a rule held in a parameter, a rule of
    another module); a rule of this module is left to the fixed point."""
    name = step.name
    if name in local or "." in name:
        return True
    if name in grammar.terminals:
        return True
    if name in grammar.rules:
        deps.append(name)
        return False
    return True  # unknown: reported by the checker


def _cycles(graph: dict[str, list[str]]) -> list[list[str]]:
    """The strongly connected components of ``graph`` that hold a cycle (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    out = []
    for root in graph:
        if root in index:
            continue
        work = [(root, 0)]
        while work:
            node, i = work.pop()
            if i == 0:
                index[node] = low[node] = len(index)
                stack.append(node)
                on_stack.add(node)
            targets = graph[node]
            if i < len(targets):
                work.append((node, i + 1))
                target = targets[i]
                if target not in index:
                    work.append((target, 0))
                elif target in on_stack:
                    low[node] = min(low[node], index[target])
                continue
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1 or node in graph[node]:
                    out.append(component)
    return out


def _cycle_from(first: str, component: list[str], graph: dict[str, list[str]]) -> list[str]:
    """A shortest cycle through ``first`` inside its component: the rules in call order."""
    members = set(component)
    came: dict[str, str] = {}
    frontier = [first]
    while frontier:
        following = []
        for node in frontier:
            for target in graph[node]:
                if target == first and (node != first or len(members) == 1):
                    path = [node]
                    while path[-1] != first:
                        path.append(came[path[-1]])
                    return path[::-1]
                if target in members and target not in came:
                    came[target] = node
                    following.append(target)
        frontier = following
    return [first]  # not reached: a component with a cycle has one through each member


def _reaches(source: str, goal: str, graph: dict[str, list[str]]) -> bool:
    seen = {source}
    todo = [source]
    while todo:
        node = todo.pop()
        if node == goal:
            return True
        for target in graph[node]:
            if target not in seen:
                seen.add(target)
                todo.append(target)
    return False
