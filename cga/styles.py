"""CGA's ``style`` blocks as grammars of their own.

A CGA style redefines some of the file's attrs (``style Red`` then ``attr color = "#ff0000"``);
CityEngine derives the rules with the style's values.  bgr has no styles, so each becomes a
small grammar beside the translation, ``FILE.Red.bgr``: it imports the translation, sets the
attrs the style redefines (``set(base.color, "#ff0000")``) and hands the lot to its start rule.
What a style redefines other than attrs (a rule, a function, a const) is reported and left out.
"""

from __future__ import annotations

import copy

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
    """The grammar of one style: the base file imported, its attrs set, its start rule run."""
    sets = []
    for item in items:
        if item.data == "annotation":
            continue
        name = str(item.children[0])
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
        [n.Version(1.0, pos=where), n.Import(BASE, path=base_path, pos=where), rule],
        path=f"{tr.path} (style {decl.children[0]})",
    )


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
