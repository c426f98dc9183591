"""CGA shape operations -> bgr steps, one small function per family.

Each function takes the translator (for names, expressions, assets and warnings), the CGA call
(its name, argument trees, block and meta) and the rest of the sequence after it, and returns the
bgr steps plus whether it took the rest of the sequence in (``offset(-1, inside) A B`` becomes
``offset(1) { inside: A B }``).  An operation bgr has no counterpart for is dropped with a warning
when it only changes the shape (``alignScopeToGeometry``), or stands as ``NIL`` when it would
have consumed it (``comp(e) { ... }``), so that what follows still derives.
"""

from __future__ import annotations

import copy
from typing import TYPE_CHECKING

from lark import Tree

from ..grammar import nodes as n
from ..grammar.cga_table import OPERATION_NAMES as CGA_OPERATIONS
from ..grammar.registry import (
    CLEANUP_KINDS,
    COORD_SYSTEMS,
    NUMBER_OR_WORD,
    OPERATIONS,
    PROJECTION_AXES_NAMES,
    ROTATION_PIVOTS,
    SHAPE_ATTRIBUTES,
    SIZE,
    TEX_SIZE,
    TRANSFORM_MODES,
    UP_AXES,
)
from . import media, overrides
from .expressions import bare_word, dotted, pos
from .media import PRIMITIVES

if TYPE_CHECKING:
    from .translate import Translator

Steps = tuple[list, bool]

# bgr operations with CGA's name and arguments (their arguments are translated one by one)
SAME = {
    "t",
    "s",
    "r",
    "center",
    "extrude",
    "envelope",
    "trim",
    "taper",
    "color",
    "label",
    "report",
    "print",
    "setupProjection",
    "projectUV",
    "tileUV",
    "scaleUV",
    "translateUV",
    "rotateUV",
    "normalizeUV",
    "deleteUV",
    "reverseNormals",
    "texture",
    "rotateScope",
    "alignScopeToAxes",
    "alignScopeToGeometry",
    "mirror",
    "cleanupGeometry",
    "convexify",
    "rotate",
    "translate",
    "deleteHoles",
    "resetMaterial",
}
# operations some of whose arguments are bare words
WORDS_TAKEN = (
    "center", "setupProjection", "normalizeUV", "alignScopeToAxes", "alignScopeToGeometry",
    "cleanupGeometry", "rotate", "translate", "r",
)  # fmt: skip
ROOFS = {"roofGable": "gable", "roofHip": "hip", "roofPyramid": "pyramid", "roofShed": "shed"}
BUILTIN_ASSETS = {"cube": "cube", "cylinder": "cylinder", "sphere": "sphere", "quad": "quad"}
# operations that change the shape in a way bgr cannot yet: dropped, the shape goes on as it was
DROPPED = {
    "mirrorScope",
    "setPivot",
    "setNormals",
    "softenNormals",
    "modifyVertex",
    "resetGeometry",
    "splitAndSetbackPerimeter",
    "insertAlongUV",
    "scatter",
    "splitArea",
    "roofRamp",
    "texture3D",
    "primitiveDisk",
    "primitiveTorus",
    "tileUV3D",
    "setMaterial",
    "alignScopeToAxes3D",
    "inline",
    "comp",
    "split",
}
SYMBOLS = {"x", "y", "z", "xy", "xz", "yz", "xyz"}
TEXTURE_MAPS = {"material.colormap": "texture", "material.normalmap": "normalMap"}


def operation(tr: Translator, name: str, args: list, block, meta, rest: list) -> Steps:
    """The bgr steps for one CGA operation call."""
    where = pos(meta)
    if name in ("split", "comp") and block is not None:
        return (
            split(tr, args, block, meta) if name == "split" else comp(tr, args, block, meta)
        ), False
    if name == "offset":
        return offset(tr, args, meta, rest)
    if name == "setback" and block is not None and len(args) == 1 and not _is_fcall_block(args[0]):
        # setback(distances) with an array: a distance per edge, setbackPerEdge's array form
        op = "setbackPerEdge" if _array_valued(tr, args[0]) else "setback"
        return _with_block(tr, op, [tr.expr(args[0])], tr.block(block, "setback"), meta), True
    if name in ("shapeL", "shapeU", "shapeO") and block is not None:
        body = tr.block(block, "innerRectangle")
        return _with_block(tr, name, [tr.expr(a) for a in args], body, meta), True
    if name == "setback" and block is not None and len(args) == 1 and _same_distance(args[0]):
        # setback(comp(fe) { all: d }): setback(d), or setbackPerEdge(d) where d reads the edge
        distance = tr.expr(_same_distance(args[0]))
        op = "setbackPerEdge" if _per_component(distance) else "setback"
        return _with_block(tr, op, [distance], tr.block(block, "setback"), meta), True
    if name in ("innerRectangle", "innerRect") and block is not None:
        alignment = bare_word(args[0]) if args else "scope"
        if alignment not in ("scope", "edge"):
            tr.warn(meta, f"innerRectangle({alignment}) is read as innerRectangle(scope)")
            alignment = "scope"
        body = tr.block(block, "innerRectangle")
        return _with_block(tr, "innerRectangle", [n.Name(alignment)], body, meta), True
    if name in ("setback", "setbackPerEdge") and block is not None and len(args) == 1:
        # setback(comp(fe) { front = 5 | all = 2 }): a distance per edge, as setbackPerEdge
        distance = _per_edge(tr, args[0], meta) if name == "setback" else tr.expr(args[0])
        if distance is not None:
            body = tr.block(block, "setback")
            return _with_block(tr, "setbackPerEdge", [distance], body, meta), True
    if name in ("setback", "setbackPerEdge"):
        tr.warn(meta, f"{name}() of this form is not in bgr yet; its shape is dropped (NIL)")
        return [n.Nil(pos=where)], True
    if name in ROOFS:
        return roof(tr, name, args, meta), False
    if name in PRIMITIVES:
        steps: list = []
        if name == "primitiveCylinder" and len(args) == 3:  # (sides, radius, height)
            radius, height = tr.expr(args[1]), tr.expr(args[2])
            steps = _centred_scope(_twice(radius), height, _twice(copy.deepcopy(radius)), where)
        elif name == "primitiveCube" and len(args) == 3:  # (width, height, depth)
            width, height, depth = (tr.expr(a) for a in args)
            steps = _centred_scope(width, height, depth, where)
        return steps + [n.Operation("i", [n.Name(PRIMITIVES[name])], pos=where)], False
    if name == "i":
        return insert(tr, args, meta, rest)
    if name == "set":
        return set_value(tr, args, meta), False
    if name == "texture":
        return texture(tr, "texture", args, meta), False
    if name in SAME:
        return same(tr, name, args, meta), False
    if name in DROPPED or name in ("split", "comp"):
        if block is not None:
            tr.warn(
                meta,
                f"{name}() is not in bgr yet; its shape is dropped (NIL)",
                "the parts it would make are missing from the translation",
            )
            return [n.Nil(pos=where)], True
        tr.warn(meta, f"{name}() is not in bgr yet; it is left out and the shape goes on as it was")
        return [], False
    if name not in CGA_OPERATIONS:  # a rule the file calls but does not define
        return [overrides.placeholder(tr, name, args, meta)], False
    tr.warn(meta, f"unknown operation '{name}'; it is left out")
    return [], False


def _centred_scope(width: n.Expr, height: n.Expr, depth: n.Expr, where) -> list:
    """Steps that give a primitive of the sizes CGA names its scope, as CGA places it: in the
    xz centre of the current scope, on its y = 0 (a negative height reaching down)."""

    def folded(name: str, e: n.Expr, scale: float = 1.0) -> n.Expr:
        if isinstance(e, n.Number):
            value = {"abs": abs, "min": lambda v: min(v, 0.0)}[name](e.value)
            return n.Number(value * scale)
        args = [copy.deepcopy(e)] + ([n.Number(0.0)] if name == "min" else [])
        call = n.Call(name, args)
        return call if scale == 1.0 else n.Binary("*", n.Number(scale), call)

    centre = [n.Relative(n.Number(0.5)), n.Number(0.0), n.Relative(n.Number(0.5))]
    corner = [folded("abs", width, -0.5), folded("min", height), folded("abs", depth, -0.5)]
    sizes = [folded("abs", width), folded("abs", height), folded("abs", depth)]
    return [
        n.Operation("t", centre, pos=where),
        n.Operation("t", corner, pos=where),
        n.Operation("s", sizes, pos=where),
    ]


def _twice(e: n.Expr) -> n.Expr:
    return n.Number(2 * e.value) if isinstance(e, n.Number) else n.Binary("*", n.Number(2.0), e)


def same(tr: Translator, name: str, args: list, meta) -> list:
    op = OPERATIONS[name]
    out: list = []
    least, most = op.arities()[0][0], max(m for _, m in op.arities())
    if (
        name == "color"
        and len(args) == 1
        and isinstance(args[0], Tree)
        and args[0].data == "number"
    ):
        tr.warn(meta, "color() of one number is read as a grey: color(v, v, v)")
        args = args * 3
    if name == "color" and len(args) == 4:
        tr.warn(meta, "color()'s alpha is left out (set material.opacity is not in bgr yet)")
        args = args[:3]
    word = bare_word(args[0]) if args else None
    if name == "envelope" and word == "normal":  # CGA's word for the face's normal
        out.append(n.Name("face.normal"))
        args = args[1:]
    elif (
        name in ("extrude", "envelope")
        and word is not None
        and word.startswith(("world.", "face.", "vertex."))
    ):
        if word not in ("world.up", "world.y", "face.normal"):  # world.y is up, as bgr's
            tr.warn(meta, f"{name}({word}, ...) is erected along world.up")
        out.append(n.Name("world.up" if word != "face.normal" else "face.normal"))
        args = args[1:]
    if len(args) + len(out) > most:
        tr.warn(meta, f"{name}() takes at most {most} arguments in bgr; the others are left out")
        args = args[: most - len(out)]
    sig = next((g for g in op.signatures if len(g) >= len(args) + len(out)), op.signatures[-1])
    for a in args:
        arg = tr.op_arg(a, symbols=name in WORDS_TAKEN)
        kind = op.param(sig, len(out)).kind
        if isinstance(arg, n.Relative) and kind not in (SIZE, TEX_SIZE):
            arg = _absolute(tr, name, arg, out, a)
        out.append(arg)
    if len(out) < least:
        tr.warn(meta, f"{name}() needs {least} arguments in bgr; it is left out")
        return []
    return [n.Operation(name, out, pos=pos(meta))]


def _absolute(tr: Translator, name: str, arg: n.Relative, before: list, t) -> n.Expr:
    """A ``'f`` where bgr takes metres: setupProjection's offsets are fractions of the scope
    along the projection's axes (``'8`` on ``scope.xz``'s v is 8 * scope.sz); elsewhere the
    ``'`` is dropped."""
    if name == "setupProjection" and len(before) in (4, 5) and isinstance(before[1], n.Name):
        axes = before[1].name.split(".")[-1]
        axis = axes[len(before) - 4]
        return n.Binary("*", arg.expr, n.Name(f"scope.s{axis}"))
    tr.warn(
        getattr(t, "meta", None),
        f"a relative ' size is not allowed there in {name}(); it is read as metres",
    )
    return arg.expr


def split(tr: Translator, args: list, block: Tree, meta) -> list:
    axis = bare_word(args[0]) if args else None
    if axis not in ("x", "y", "z"):
        tr.warn(meta, "split() of this kind is not in bgr yet; its shape is dropped (NIL)")
        return [n.Nil(pos=pos(meta))]
    # CGA fits each piece's scope to its geometry unless told noAdjust; bgr's split keeps the
    # slab's unless told adjust
    mode = bare_word(args[1]) if len(args) > 1 else "adjust"
    if mode not in ("adjust", "noAdjust") or len(args) > 2:
        tr.warn(meta, "split()'s unitSpace/uvSpace arguments are left out")
        mode = "adjust" if mode not in ("adjust", "noAdjust") else mode
    words = [n.Name(axis)] + ([n.Name("adjust")] if mode == "adjust" else [])
    return _with_block(tr, "split", words, tr.block(block, "split"), meta)


def comp(tr: Translator, args: list, block: Tree, meta) -> list:
    kind = bare_word(args[0]) if args else None
    if kind not in ("f", "e", "v"):
        tr.warn(
            meta,
            f"comp({kind}) is not in bgr yet (faces, edges and vertices only); its shape is "
            "dropped (NIL)",
            "the parts it would make are missing from the translation",
        )
        return [n.Nil(pos=pos(meta))]
    if len(args) > 1:
        tr.warn(meta, "comp()'s scope alignment (noAlign) is not in bgr; it is left out")
    return _with_block(tr, "comp", [n.Name(kind)], tr.block(block, f"comp:{kind}"), meta)


def _same_distance(t):
    """The distance of ``comp(fe) { all: d }`` (one entry, every edge), else None."""
    calls = [c for c in t.iter_subtrees() if c.data == "fcall_block"] if isinstance(t, Tree) else []
    if len(calls) != 1 or dotted(calls[0].children[0]) != "comp":
        return None
    call = calls[0]
    entries = [c for c in call.children if isinstance(c, Tree) and c.data == "value_entry"]
    if calls[0] is not t or len(entries) != 1:
        return None
    key, value = entries[0].children
    return value if bare_word(key) == "all" else None


def _array_valued(tr: Translator, t) -> bool:
    """An array literal, or the name of an attr or const the file sets to one."""
    if isinstance(t, Tree) and t.data == "array":
        return True
    return bare_word(t) in tr.arrays


def _per_component(e) -> bool:
    """Whether an expression can differ from one component to the next: it reads the
    component's scope, comp.*, geometry or draws a random number."""
    for x in n.walk(e):
        if isinstance(x, n.Name) and x.name.startswith(("comp.", "scope.", "geometry.")):
            return True
        if isinstance(x, n.Call) and (
            x.name in ("rand", "randint", "p", "listRandom") or x.name.startswith("geometry.")
        ):
            return True
    return False


# the comp(fe) selectors a distance per edge can name, as the scope's (bgr's setback words)
_EDGE_WORDS = ("front", "back", "left", "right", "top", "bottom")


def _per_edge(tr: Translator, t, meta) -> n.Expr | None:
    """``comp(fe) { front = 5 | side = 3 | all = 1 }`` as one expression of comp.sel and
    comp.index for setbackPerEdge: each edge takes the value of the first entry that selects
    it, and no setback (0) when none does, as CGA's comp function gives; None for any other
    argument.  ``object.`` and ``street.`` selectors are read as the scope's (CGA reads street
    selectors as object ones where the lot has no street widths)."""
    if not (isinstance(t, Tree) and t.data == "fcall_block" and dotted(t.children[0]) == "comp"):
        return None
    entries = [c for c in t.children if isinstance(c, Tree) and c.data == "value_entry"]
    chain: list[tuple[n.Expr | None, n.Expr]] = []
    for key, value in (e.children for e in entries):
        word = bare_word(key) or ""
        plain = word.split(".", 1)[1] if word.startswith(("object.", "street.")) else word
        if plain != word:
            tr.warn(meta, f"setback selector '{word}' is read as '{plain}'")
        sel = n.Name("comp.sel")
        if plain == "all":
            condition = None
        elif plain in _EDGE_WORDS:
            condition = n.Binary("==", sel, n.String(plain))
        elif plain == "side":
            condition = n.Binary(
                "or",
                n.Binary("==", sel, n.String("left")),
                n.Binary("==", copy.deepcopy(sel), n.String("right")),
            )
        elif isinstance(key, Tree) and key.data == "number":
            condition = n.Binary("==", n.Name("comp.index"), tr.expr(key))
        else:
            tr.warn(meta, f"setback selector '{word or 'this'}' is not in bgr yet; left out")
            continue
        chain.append((condition, tr.expr(value)))
        if condition is None:
            break
    out: n.Expr = n.Number(0.0)
    for condition, value in reversed(chain):
        out = value if condition is None else n.Ternary(condition, value, out)
    return out


def _is_fcall_block(t) -> bool:
    """``comp(fe) { front = 3 | ... }``: distances per edge, which bgr's setback does not take."""
    return isinstance(t, Tree) and any(
        isinstance(c, Tree) and c.data == "fcall_block" for c in t.iter_subtrees()
    )


def _with_block(tr: Translator, name: str, args: list, block: n.Block | None, meta) -> list:
    if block is None:  # each entry was left out (and reported): nothing is made of the shape
        return [n.Nil(pos=pos(meta))]
    return [n.Operation(name, args, block, pos=pos(meta))]


def offset(tr: Translator, args: list, meta, rest: list) -> Steps:
    """CGA's ``offset(d)`` keeps the face with an inner and a border part that a later
    ``comp(f) { inside: .. | border: .. }`` selects; ``offset(d, inside)`` keeps only one part.
    bgr's offset takes the block at once, with the opposite sign (a positive distance shrinks)."""
    where = pos(meta)
    if not args:
        tr.warn(meta, "offset() needs a distance; it is left out")
        return [], False
    distance = negated(tr.expr(args[0]))
    part = bare_word(args[1]) if len(args) > 1 else "all"
    if part in ("inside", "border"):
        body = tr.sequence_of(rest)
        block = n.Block([n.Entry("abs", n.Name(part), body)])
        return [n.Operation("offset", [distance], block, pos=where)], True
    follow = rest[0] if rest else None
    if follow is not None and _is_comp_f(follow):
        block = tr.block(follow.children[-1], "offset")
        return _with_block(tr, "offset", [distance], block, meta), True
    tr.warn(
        meta,
        "offset() without a comp(f) after it: the rest of the rule runs on the inside "
        "and the border apart",
    )
    body = tr.sequence_of(rest)
    block = n.Block(
        [
            n.Entry("abs", n.Name("inside"), body),
            n.Entry("abs", n.Name("border"), copy.deepcopy(body)),
        ]
    )
    return [n.Operation("offset", [distance], block, pos=where)], True


def negated(e: n.Expr) -> n.Expr:
    """``-e``, written simply: ``-0.8`` is ``0.8``, ``-(-d)`` is ``d``."""
    if isinstance(e, n.Number):
        return n.Number(-e.value)
    if isinstance(e, n.Unary) and e.op == "-":
        return e.operand
    return n.Unary("-", e)


def _is_comp_f(t) -> bool:
    if not (isinstance(t, Tree) and t.data == "call"):
        return False
    name = dotted(t.children[0])
    args = [] if t.children[1] is None else t.children[1].children
    return name == "comp" and t.children[2] is not None and bool(args) and bare_word(args[0]) == "f"


def roof(tr: Translator, name: str, args: list, meta) -> list:
    out: list = [n.Name(ROOFS[name])]
    if args:
        out.append(tr.expr(args[0]))
    if name in ("roofGable", "roofHip") and len(args) > 1:
        out.append(tr.expr(args[1]))
    extra = args[3:] if name == "roofGable" else args[2:] if name == "roofHip" else args[1:]
    if name == "roofGable" and len(args) > 2 and not _zero(args[2]):
        tr.warn(meta, "roofGable()'s second overhang is not in bgr: the first is used for both")
    if any(not _zero(a) and bare_word(a) != "false" for a in extra):
        tr.warn(meta, f"{name}()'s further arguments are left out")
    return [n.Operation("roof", out, pos=pos(meta))]


def insert(tr: Translator, args: list, meta, rest: list) -> Steps:
    where = pos(meta)
    if not args:
        tr.warn(meta, "i() needs a geometry; it is left out")
        return [], False
    geometry = media.asset_of(tr, args[0], meta)
    if geometry is not None:
        return [n.Operation("i", [geometry], pos=where)], False
    # a path computed at derive time (a rule parameter): one branch per asset the file names
    return media.dispatch_insert(tr, args[0], meta, rest), True


def texture(tr: Translator, op: str, args: list, meta) -> list:
    if not args:
        return []
    path = media.texture_path(tr, args[0], meta)
    return [] if path is None else [n.Operation(op, [path], pos=pos(meta))]


def set_value(tr: Translator, args: list, meta) -> list:
    if len(args) != 2:
        tr.warn(meta, "set() takes a name and a value; it is left out")
        return []
    target = bare_word(args[0])
    if target == "material.name":
        return [n.Operation("material", [tr.expr(args[1])], pos=pos(meta))]
    if target in TEXTURE_MAPS:
        return texture(tr, TEXTURE_MAPS[target], args[1:], meta)
    if target == "material.color.rgb" or target == "material.color":
        return [n.Operation("color", [tr.expr(args[1])], pos=pos(meta))]
    if target in SHAPE_ATTRIBUTES:
        return [n.Operation("set", [n.Name(target), tr.expr(args[1])], pos=pos(meta))]
    attr = tr.attr_name(target) if target else None
    if attr is None:
        tr.warn(
            meta, f"set({target}, ...) is not in bgr yet (attrs of this file only); it is left out"
        )
        return []
    return [n.Operation("set", [n.Name(attr), tr.expr(args[1])], pos=pos(meta))]


def _zero(t) -> bool:
    return isinstance(t, Tree) and t.data == "number" and float(str(t.children[0])) == 0.0


def is_symbol_arg(t, projection: bool) -> str | None:
    """A bare word bgr takes as a symbol: an axis set, or a projection's axes (``scope.xy``)."""
    word = bare_word(t)
    if word in SYMBOLS or (projection and word in PROJECTION_AXES_NAMES):
        return word
    if word in ("uv", "uvUniform", "u", "v", "separatePerFace", "collectiveAllFaces"):
        return word
    if word in UP_AXES or word in CLEANUP_KINDS or any(word in w for w in NUMBER_OR_WORD.values()):
        return word
    if word in TRANSFORM_MODES or word in COORD_SYSTEMS or word in ROTATION_PIVOTS:
        return word  # rotate's and translate's, r's pivot
    return None
