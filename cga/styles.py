"""CGA's ``style`` blocks as grammars of their own.

A CGA style redefines some of the file's attrs (``style Red`` then ``attr color = "#ff0000"``)
and rules; CityEngine derives the file with the style's.  bgr has no styles, so each becomes a
small grammar beside the translation, ``FILE.Red.bgr``: it imports the translation, sets the
attrs the style redefines (``set(base.color, "#ff0000")``), overrides the rules it redefines
(``base.Roof --> ...``, bgr's rule overriding) and hands the lot to its start rule.  What a
style defines that the file does not have, and its functions and consts, are reported and left
out.
"""

from __future__ import annotations

import copy
import dataclasses

from lark import Tree

from ..grammar import nodes as n
from .expressions import pos

BASE = "base"


def style_blocks(tree: Tree) -> list[tuple[Tree, list[Tree]]]:
    """Each ``style`` declaration with the items that follow it, up to the next one."""
    out: list[tuple[Tree, list[Tree]]] = []
    for item in tree.children:
        if item.data == "style_decl":
            out.append((item, []))
        elif out:
            out[-1][1].append(item)
    return out


def style_module(tr, decl: Tree, items: list[Tree], base_path: str, start: str) -> n.Module:
    """The grammar of one style: the base file imported, its attrs set, the rules it redefines
    overridden, its start rule run."""
    sets: list = []
    rules: list = []
    for item in items:
        if item.data == "annotation":
            continue
        name = str(item.children[0])
        if item.data == "rule" and "." not in name:
            rules += _override(tr, decl, item)
            continue
        if item.data != "attr_decl" or name not in tr.attrs:
            tr.warn(
                item.meta,
                f"style '{decl.children[0]}' redefines '{name}', which is not an "
                "attr of the file: left out (a style changes attrs only in bgr)",
            )
            continue
        value = _based(tr.expr(item.children[1]), tr)
        target = n.Name(f"{BASE}.{tr.attrs[name]}")
        sets.append(n.Operation("set", [target, value], pos=pos(item.meta)))
    rule = n.Rule(
        start, [], n.Sequence([*sets, n.Successor(f"{BASE}.{start}")]), pos=pos(decl.meta)
    )
    where = pos(decl.meta)
    return n.Module(
        [n.Version(1.0, pos=where), n.Import(BASE, path=base_path, pos=where), rule, *rules],
        path=f"{tr.path} (style {decl.children[0]})",
    )


def _override(tr, decl: Tree, item: Tree) -> list:
    """A rule the style redefines: ``base.Name --> ...`` with its body read in the base file's
    names (and the helper rules its nested cases need, kept in the style's grammar)."""
    name = str(item.children[0])
    arity = len(item.children[1].children) if item.children[1] is not None else 0
    if (name, arity) not in tr.rules:
        tr.warn(
            item.meta,
            f"style '{decl.children[0]}' defines rule '{name}', which the file does not have: "
            "left out (a style redefines the file's rules in bgr)",
        )
        return []
    extra, tr.extra = tr.extra, []
    leaves = dict(tr.terminals)
    rule = tr.rule(item, [])
    helpers, tr.extra = tr.extra, extra
    # leaves and helper rules the style's rule made are the style grammar's own
    own_leaves = sorted(set(tr.terminals.values()) - set(leaves.values()))
    tr.terminals = leaves
    own = {h.name for h in helpers} | set(own_leaves)
    base_rules = set(tr.rules.values()) | set(tr.terminals.values()) | set(tr.undefined.values())
    out: list = [rule, *helpers]
    for r in out:
        _rebase(r, tr, base_rules - own)
    rule.name = f"{BASE}.{rule.name}"
    return out + ([n.TerminalDecl(own_leaves)] if own_leaves else [])


def _rebase(rule: n.Rule, tr, base_rules: set[str]) -> None:
    """Point a style rule's successors and values at the base file's, through the import."""
    rule.body = _based_steps(rule.body, tr, base_rules)


def _based_steps(node, tr, base_rules: set[str]):
    node = copy.deepcopy(node)
    values = set(tr.attrs.values()) | set(tr.consts.values())
    funcs = {bgr for bgr, _ in tr.funcs.values()}
    for x in _nodes(node):
        successor = isinstance(x, n.Successor) and x.name in base_rules
        value = isinstance(x, n.Name) and x.name in values
        if successor or value or (isinstance(x, n.Call) and x.name in funcs):
            x.name = f"{BASE}.{x.name}"
    return node


def _nodes(node):
    """Every syntax node under ``node`` (its dataclass fields and lists), itself first."""
    stack = [node]
    while stack:
        x = stack.pop()
        if isinstance(x, list):
            stack.extend(x)
        elif dataclasses.is_dataclass(x) and not isinstance(x, (n.Pos, type)):
            yield x
            stack.extend(getattr(x, f.name) for f in dataclasses.fields(x))


def _based(e: n.Expr, tr) -> n.Expr:
    """An expression of the base file, read from the style's grammar: its attrs, consts and
    functions through the import."""
    e = copy.deepcopy(e)
    own_values = set(tr.attrs.values()) | set(tr.consts.values())
    own_funcs = {bgr for bgr, _ in tr.funcs.values()}
    for x in n.walk(e):
        own = own_values if isinstance(x, n.Name) else own_funcs if isinstance(x, n.Call) else ()
        if getattr(x, "name", None) in own:
            x.name = f"{BASE}.{x.name}"
    return e
