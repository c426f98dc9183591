"""Rule overriding across CGA imports, and the rules a file calls without defining them.

CGA lets a file replace a rule of a file it imports (``volume.Glazing(dist) --> ...``): the
imported file's own calls to ``Glazing`` run the importer's rule.  bgr has the same
(``alias.Name --> ...``, language.md), so the override is translated as a rule of that dotted
name, named after the imported translation's own rule (``rules_of``: an imported rule
overloaded by arity has another bgr name for each).

An imported file often calls such a rule without defining it, with arguments
(``Glazing(1.4)``): CGA leaves the shape as a leaf unless an importer supplies the rule.  The
translation defines it (``placeholder``) as a rule of those parameters that leaves the shape as
a terminal labelled with the rule's name, so that an override has a rule to replace.
"""

from __future__ import annotations

from ..grammar import nodes as n
from ..grammar.registry import OPERATIONS
from .expressions import pos


def placeholder(tr, name: str, args: list, meta) -> n.Step:
    """A call of a rule the file does not define: a rule of that many parameters, made once,
    whose shape stays a leaf labelled ``name``."""
    key = (name, len(args))
    found = tr.undefined.get(key)
    if found is None:
        found = tr.undefined[key] = tr.fresh(name, OPERATIONS)
        leaf = tr.fresh(name + "Leaf", OPERATIONS)
        tr.terminals[f"{name}/{len(args)}"] = leaf
        steps = [n.Operation("label", [n.String(name)]), n.Successor(leaf, [])]
        params = [f"arg{i + 1}" for i in range(len(args))]
        tr.extra.append(n.Rule(found, params, n.Sequence(steps), pos=pos(meta)))
        tr.warn(
            meta,
            f"rule '{name}' is not defined in this file; it is written as a rule whose shape "
            "stays a leaf, for an importer to override",
        )
    return n.Successor(found, [tr.expr(a) for a in args], pos=pos(meta))


def rules_of(tr) -> dict[tuple[str, int], str]:
    """(CGA rule name, arity) -> the bgr rule or terminal an importer's override replaces."""
    table = dict(tr.rules)
    table.update(tr.undefined)
    for name, terminal in tr.terminals.items():
        if "/" not in name:
            table.setdefault((name, 0), terminal)
    return table


def override(tr, t, notes) -> n.Rule | None:
    """``alias.Name(params) --> body``: the importer's rule that replaces the imported one."""
    name, params = (
        str(t.children[0]),
        [str(c) for c in (t.children[1].children if t.children[1] else [])],
    )
    alias, _, member = name.partition(".")
    bgr_alias = tr.imports.get(alias)
    if bgr_alias is None:
        why = "is not an import" if alias not in tr.imports else "was not translated"
        tr.warn(t.meta, f"overriding rule '{name}': '{alias}' {why}; the override is left out")
        return None
    target = tr.import_rules.get(alias, {}).get((member, len(params)))
    if target is None:
        tr.warn(
            t.meta,
            f"overriding rule '{name}': the imported file has no rule '{member}' of "
            f"{len(params)} parameters; the override is left out",
        )
        return None
    tr.rules[(name, len(params))] = f"{bgr_alias}.{target}"
    return tr.rule(t, notes)
