"""What i() and texture() name in a CGA file, as the translation writes it: assets declared
where they are found, a path computed at derive time chosen among the file's own, textures
relative to the output.  Functions of the translator (``tr``), kept apart from its rules."""

from __future__ import annotations

import copy

from lark import Token

from ..grammar import nodes as n
from .expressions import bare_word, dotted, literal_string, pos, unquote
from .lookup import like

# CGA's primitive insertions and the built-in asset each is
PRIMITIVES = {
    "primitiveCube": "cube",
    "primitiveCylinder": "cylinder",
    "primitiveSphere": "sphere",
    "primitiveQuad": "quad",
}

GEOMETRY_FILES = (".obj", ".glb", ".gltf", ".fbx", ".dae", ".ply", ".stl", ".3ds")
IMAGE_FILES = (".jpg", ".jpeg", ".png", ".tif", ".tiff", ".tga", ".bmp")


def asset_of(tr, t, meta) -> n.Expr | None:
    text = literal_string(t)
    if text is None and bare_word(t) in tr.consts:
        text = _const_text(tr, bare_word(t))
    if text is None:
        return None
    return tr.assets.geometry(text, meta, tr.warn)


def _const_text(tr, name: str | None) -> str | None:
    for item in tr.tree.children:
        if item.data == "const_decl" and str(item.children[0]) == name:
            return literal_string(item.children[2])
    return None


def dispatch_insert(tr, t, meta, rest: list) -> list:
    value = tr.expr(t)
    tail = tr.steps(rest)
    choices: dict[str, n.Expr] = {}
    named = file_strings(tr, GEOMETRY_FILES, builtin=True) | set(_computed_files(tr, t))
    for text in sorted(named):
        choices[text] = tr.assets.geometry(text, meta, tr.warn)
    kinds = {ops_key(g) for g in choices.values()} | {"cube"}
    if len(kinds) == 1:
        return [n.Operation("i", [n.Name("cube")], pos=pos(meta))] + tail
    cases = [
        n.Case(
            n.Binary("==", value, n.String(text)),
            n.Sequence([n.Operation("i", [g])] + copy.deepcopy(tail)),
        )
        for text, g in choices.items()
    ]
    cases.append(n.Case(None, n.Sequence([n.Operation("i", [n.Name("cube")])] + tail)))
    return [tr.helper(n.Conditional(cases), pos(meta))]


def texture_path(tr, t, meta) -> n.Expr | None:
    text = literal_string(t)
    if text is None and bare_word(t) in tr.consts:
        text = _const_text(tr, bare_word(t))
    if text is not None:
        return tr.assets.texture(text, meta, tr.warn)
    images = file_strings(tr, IMAGE_FILES)
    prefix = tr.assets.texture_prefix(images)
    if prefix is None:
        tr.warn(
            meta,
            "texture() of a computed path: not every image the file names was "
            "found beside it (as PNG or JPEG), so it is left out",
        )
        return None
    value = tr.expr(t)
    return n.Binary("+", n.String(prefix), value) if prefix else value


def inserts(tr) -> bool:
    """Whether the file inserts anything (i(), primitiveCube()...): trim planes cut that."""
    names = {"i", *PRIMITIVES}
    return any(
        dotted(t.children[0]) in names
        for t in tr.tree.find_pred(lambda t: t.data in ("call", "successor"))
    )


def file_strings(tr, suffixes: tuple, builtin: bool = False) -> set[str]:
    out = set()
    for tok in tr.tree.scan_values(lambda v: isinstance(v, Token) and v.type == "STRING"):
        text = unquote(tok)
        if not text.rsplit("/", 1)[-1].rsplit(".", 1)[0]:
            continue  # ".obj": the end of a computed path, no file of its own
        if text.lower().endswith(suffixes) or (builtin and text.startswith("builtin:")):
            out.add(text)
    return out


def ops_key(e: n.Expr) -> str:
    return e.name if isinstance(e, n.Name) else repr(e)


def _computed_files(tr, t) -> list[str]:
    """The asset files a path written ``"prefix" + x + ".obj"`` can name: those beside the
    CGA file that start and end so (a name built from an attr or a random choice)."""
    if not (hasattr(t, "data") and t.data == "sum"):
        return []
    first, last = t.children[0], t.children[-1]
    prefix, suffix = literal_string(first), literal_string(last)
    if prefix is None or suffix is None or not suffix.lower().endswith(GEOMETRY_FILES):
        return []
    return like(prefix, suffix, tr.assets.folder)
