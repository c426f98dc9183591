"""The selectors of CGA's blocks (offset, innerRectangle, setback, comp) in bgr's words, for the
translator (translate.py): a selector bgr has is kept, one it lacks is reported and left out."""

from __future__ import annotations

from lark import Tree

from ..grammar import nodes as n
from ..grammar.registry import (
    COMP_INDEX_CALLS,
    COMP_SELECTORS,
    EDGE_SELECTORS,
    INNER_SELECTORS,
    SETBACK_SELECTORS,
    VERTEX_SELECTORS,
)
from .expressions import bare_word


def selectors(tr, t, kind: str, meta, named: set[str]) -> list:
    """The bgr selector words (or index calls) a CGA block's selector ``t`` stands for in a
    block of ``kind`` (offset, innerRectangle, setback, comp:f/e/v); what bgr lacks is reported
    and left out.  ``named``: the offset words taken so far."""
    word = bare_word(t)
    if kind == "offset":
        words = ["inside", "border"] if word == "all" else [word]
        if word not in ("inside", "border", "all"):
            tr.warn(meta, f"selector '{word}' after offset() is not in bgr; left out")
            return []
        keys = [w for w in words if w is not None and w not in named]
        named.update(keys)
        return [n.Name(w) for w in keys]
    if kind == "innerRectangle":
        if word in INNER_SELECTORS:
            return [n.Name(word)]
        tr.warn(meta, f"innerRectangle selector '{word or 'this'}' is not in bgr; left out")
        return []
    if kind == "setback":
        if word in SETBACK_SELECTORS:
            return [n.Name(word)]
        tr.warn(meta, f"setback selector '{word or 'this'}' is not in bgr yet; left out")
        return []
    comp_kind = kind.partition(":")[2] or "f"  # "comp:e": the block of a comp(e)
    allowed = {"e": EDGE_SELECTORS, "v": VERTEX_SELECTORS}.get(comp_kind, COMP_SELECTORS)
    if word in allowed:
        return [n.Name(word)]
    if isinstance(t, Tree) and t.data == "number":
        index = n.Number(float(str(t.children[0])))
        return [n.Call(COMP_INDEX_CALLS[comp_kind], [index])]
    parts = {"f": "faces", "e": "edges", "v": "vertices"}[comp_kind]
    tr.warn(
        meta,
        f"comp({comp_kind}) selector '{word or 'this'}' is not in bgr yet; its {parts} are "
        "left out",
    )
    return []
