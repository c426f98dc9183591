"""Checks of operations: a signature that fits, each argument of the kind it takes, blocks.

An operation's arguments are checked against its signature in :mod:`bgr.grammar.registry`:
bare words from a fixed set (axes, kinds, modes), primitives and assets, attrs for ``set()``,
numbers, strings, colours, relative and floating sizes, and literal texture paths.  Its block
must be one it takes (split sizes, comp, setback and offset selectors).
"""

from __future__ import annotations

import re
from collections.abc import Callable

from . import nodes as n
from .check_expressions import ExpressionChecks
from .errors import suggest
from .registry import (
    ATTR_NAME,
    AXES,
    AXIS,
    AXIS_NAMES,
    CLEANUP_KIND,
    CLEANUP_KINDS,
    COLOR,
    COMP_INDEX_CALLS,
    COMP_KIND,
    COMP_KINDS,
    COMP_SELECTORS,
    COORD_SYSTEM,
    COORD_SYSTEMS,
    EDGE_SELECTORS,
    EXTRUDE_KIND,
    EXTRUDE_KINDS,
    FOOTPRINT_KIND,
    FOOTPRINT_KINDS,
    GEOMETRY,
    INNER_ALIGNMENT,
    INNER_ALIGNMENTS,
    INNER_SELECTORS,
    MANY,
    NORMALIZE_MODE,
    NORMALIZE_MODES,
    NORMALIZE_TYPE,
    NORMALIZE_TYPES,
    NUMBER,
    NUMBER_OR_WORD,
    OFFSET_SELECTORS,
    OPERATIONS,
    PER_EDGE,
    PRIMITIVES,
    PROJECTION_AXES,
    PROJECTION_AXES_NAMES,
    ROOF_KIND,
    ROOF_KINDS,
    ROTATION_PIVOT,
    ROTATION_PIVOTS,
    SETBACK_SELECTORS,
    SHAPE_ATTRIBUTES,
    SIZE,
    SPLIT_ADJUST,
    SPLIT_ADJUSTS,
    STRING,
    TEX_SIZE,
    TRANSFORM_MODE,
    TRANSFORM_MODES,
    UP_AXES,
    UP_AXIS,
    VERTEX_SELECTORS,
    Op,
)
from .textures import TextureError, load

_COLOR_RE = re.compile(r"#[0-9a-fA-F]{6}\Z")
_SYMBOL_KINDS = {
    AXIS: AXIS_NAMES,
    COMP_KIND: COMP_KINDS,
    ROOF_KIND: ROOF_KINDS,
    FOOTPRINT_KIND: FOOTPRINT_KINDS,
    EXTRUDE_KIND: EXTRUDE_KINDS,
    PROJECTION_AXES: PROJECTION_AXES_NAMES,
    NORMALIZE_MODE: NORMALIZE_MODES,
    NORMALIZE_TYPE: NORMALIZE_TYPES,
    UP_AXIS: UP_AXES,
    CLEANUP_KIND: CLEANUP_KINDS,
    INNER_ALIGNMENT: INNER_ALIGNMENTS,
    SPLIT_ADJUST: SPLIT_ADJUSTS,
    TRANSFORM_MODE: TRANSFORM_MODES,
    COORD_SYSTEM: COORD_SYSTEMS,
    ROTATION_PIVOT: ROTATION_PIVOTS,
}
_TEXTURE_OPS = ("texture", "normalMap")


class OperationChecks(ExpressionChecks):
    """Checks an operation's arguments and block; the steps of a block are walked by
    ``sequence`` (:class:`bgr.grammar.check_rules.RuleChecks`)."""

    sequence: Callable[[n.Sequence, set[str]], None]

    def operation(self, step: n.Operation, local: set[str]) -> None:
        op = OPERATIONS[step.name]
        signature = self.pick_signature(op, step)
        if signature is not None:
            for i, arg in enumerate(step.args):
                param = op.param(signature, i)
                self.op_arg(arg, param.kind, param.name, op, local)
        else:
            # no signature fits (reported): check the expressions, but not a bare word that one
            # of the operation's signatures takes (extrude(world.up, 1, 2) is one mistake)
            words = {
                word
                for sig in op.signatures
                for p in sig
                if p.kind in _SYMBOL_KINDS
                for word in _SYMBOL_KINDS[p.kind]
            }
            for arg in step.args:
                if not (isinstance(arg, n.Name) and arg.name in words):
                    self.arg(arg, local, relative_ok=True)
        if op.block is None:
            if step.block is not None:  # the grammar lets any call carry a block
                self.error(step.block.pos, f"'{op.name}' takes no {{ }} block")
            return
        if step.block is None:
            self.error(
                step.pos,
                f"'{op.name}' needs a {{ ... }} block",
                f"for example: {op.example}",
                len(op.name),
            )
            return
        if step.block.repeat and op.block != "split":
            end = step.block.pos
            star = n.Pos(end.end_line, end.end_column - 1, end.end_line, end.end_column)
            self.error(
                star,
                f"only split blocks repeat; '{op.name}' {{ ... }} cannot take a '*'",
                "remove the '*'",
            )
        outer = self.comp_kind
        if op.block == "comp":
            kind = step.args[0] if step.args else None
            self.comp_kind = kind.name if isinstance(kind, n.Name) else "f"
        self.block_entries(step.block.entries, op, local, in_group=False)
        self.comp_kind = outer

    def pick_signature(self, op: Op, step: n.Operation):
        count = len(step.args)
        for sig, (least, most) in zip(op.signatures, op.arities(), strict=True):
            if least <= count <= most:
                return sig
        counts = " or ".join(
            str(a) if a == b else f"{a} or more" if b == MANY else f"{a} to {b}"
            for a, b in op.arities()
        )
        noun = "argument" if counts == "1" else "arguments"
        self.error(
            step.pos,
            f"'{op.name}' takes {counts} {noun}, given {count}",
            f"write {op.usage()}",
            len(op.name),
        )
        return None

    def set_target(self, arg, op: Op) -> None:
        """set()'s first argument: a bare word naming an attr of this file."""
        if not isinstance(arg, n.Name):
            self.error(arg.pos, "set() changes an attr: name it bare", f"for example: {op.example}")
        elif arg.name in SHAPE_ATTRIBUTES:
            return
        elif "." in arg.name and arg.name.split(".", 1)[0] in self.g.imports:
            module, member = self.g.lookup_module(arg.name)
            if member in module.attrs:
                module.settable.add(member)  # its rules read the value set() gave
            else:
                self.error(
                    arg.pos,
                    f"unknown attr '{arg.name}'",
                    suggest(member, list(module.attrs)) or "set() changes attrs of that file",
                )
        elif "." in arg.name and arg.name.split(".", 1)[0] in self.broken_aliases:
            return
        elif arg.name in self.g.consts:
            self.error(arg.pos, f"'{arg.name}' is a const: set() changes attrs only")
        elif arg.name in self.g.attrs:
            self.g.settable.add(arg.name)
        else:
            hint = "set() changes this file's attrs (declare it: attr NAME = value) or an import's"
            self.error(
                arg.pos,
                f"unknown attr '{arg.name}'",
                suggest(arg.name, list(self.g.attrs)) or hint,
            )

    def op_arg(self, arg, kind: str, pname: str, op: Op, local: set[str]) -> None:
        if kind in NUMBER_OR_WORD:
            if isinstance(arg, n.Name) and arg.name in NUMBER_OR_WORD[kind]:
                return
            kind = NUMBER
        if kind == ATTR_NAME:
            self.set_target(arg, op)
            return
        if kind in _SYMBOL_KINDS or kind in (AXES, GEOMETRY):
            if not isinstance(arg, n.Name):
                allowed = self.allowed_symbols(kind)
                self.error(
                    arg.pos,
                    f"the {pname} of '{op.name}' is a bare word, one of {allowed}",
                    f"for example: {op.example}",
                )
                return
            word = arg.name
            if kind in _SYMBOL_KINDS:
                if word not in _SYMBOL_KINDS[kind]:
                    self.error(
                        arg.pos,
                        f"unknown {kind} '{word}'",
                        suggest(word, _SYMBOL_KINDS[kind])
                        or f"use one of {self.allowed_symbols(kind)}",
                    )
            elif kind == AXES:
                if not word or set(word) - set("xyz") or len(set(word)) != len(word):
                    self.error(
                        arg.pos,
                        f"'{word}' is not a set of axes",
                        "write the axes as one word of x, y and z, e.g. center(xz)",
                    )
            else:  # GEOMETRY
                module, member = self.g.lookup_module(word)
                if member in PRIMITIVES and module is self.g:
                    return
                if "." in word and word.split(".", 1)[0] in self.broken_aliases:
                    return
                if member not in module.assets:
                    known = list(PRIMITIVES) + list(self.g.assets)
                    self.error(
                        arg.pos,
                        f"unknown primitive or asset '{word}'",
                        suggest(word, known) or 'declare it: asset NAME = "path/to/mesh.glb"',
                    )
            return
        if isinstance(arg, n.Relative) and arg.floating and kind != TEX_SIZE:
            self.error(
                arg.pos,
                f"a floating size (~w) is not allowed as the {pname} of '{op.name}'",
                "floating sizes go in split sizes, setupProjection() and tileUV()",
            )
            return
        if isinstance(arg, n.Relative) and kind not in (SIZE, TEX_SIZE):
            self.error(
                arg.pos,
                f"a relative size ('f) is not allowed as the {pname} of '{op.name}'",
                "relative sizes go in s(), t(), split sizes, setupProjection() and tileUV()",
            )
            return
        self.arg(arg, local, relative_ok=True)
        expr = arg.expr if isinstance(arg, n.Relative) else arg
        if op.name in _TEXTURE_OPS and isinstance(expr, n.String):
            self.texture_file(expr)
        if kind in (NUMBER, SIZE, TEX_SIZE, PER_EDGE) and isinstance(expr, (n.String, n.Bool)):
            self.error(expr.pos, f"the {pname} of '{op.name}' must be a number")
        elif kind == STRING and isinstance(expr, (n.Number, n.Bool)):
            self.error(
                expr.pos,
                f"the {pname} of '{op.name}' must be a string",
                f"for example: {op.example}",
            )
        elif kind == COLOR:
            if isinstance(expr, n.String) and not _COLOR_RE.match(expr.value):
                self.error(
                    expr.pos,
                    f"'{expr.value}' is not a colour",
                    'write "#rrggbb" with six hexadecimal digits, or three numbers in 0..1',
                )
            elif isinstance(expr, (n.Number, n.Bool)):
                self.error(
                    expr.pos,
                    'a single colour argument is a "#rrggbb" string',
                    "or give three numbers: color(r, g, b)",
                )

    def texture_file(self, expr: n.String) -> None:
        """A literal texture path must name a readable PNG or JPEG within the grammar's roots
        (a computed one is checked when the derivation first uses it)."""
        if not self.g.roots or expr.value == "":  # by hand: not checked; "": no map
            return
        try:
            load(self.g.path, self.g.roots, expr.value, self.g.folder)
        except TextureError as e:
            self.error(expr.pos, e.message, e.hint)

    def allowed_symbols(self, kind: str) -> str:
        if kind == AXES:
            return "x, y, z, xy, xz, yz, xyz"
        if kind == GEOMETRY:
            return ", ".join(list(PRIMITIVES) + list(self.g.assets))
        return ", ".join(_SYMBOL_KINDS[kind])

    def block_entries(self, entries, op: Op, local: set[str], in_group: bool) -> None:
        for entry in entries:
            if isinstance(entry, n.Group):
                if op.block != "split":
                    self.error(
                        entry.pos,
                        f"repeat groups {{ ... }}* belong in split blocks, not in '{op.name}'",
                    )
                else:
                    self.block_entries(entry.entries, op, local, in_group=True)
                continue
            if entry.combine and not (op.block == "comp" and self.comp_kind == "f"):
                self.error(
                    entry.pos,
                    f"'=' (the parts taken as one shape) belongs in comp(f) blocks, not in "
                    f"'{op.name}'",
                    "write ':' to take them one by one",
                )
            if op.block == "split":
                self.expr(entry.key, local, in_rule=True)
                if isinstance(entry.key, (n.String, n.Bool)):
                    self.error(entry.key.pos, "a split size must be a number")
            else:
                self.selector(entry, op, local)
            self.sequence(entry.body, local)

    def selector(self, entry: n.Entry, op: Op, local: set[str]) -> None:
        comp_selectors = {"e": EDGE_SELECTORS, "v": VERTEX_SELECTORS}
        allowed = {
            "comp": comp_selectors.get(self.comp_kind, COMP_SELECTORS),
            "setback": SETBACK_SELECTORS,
            "innerRectangle": INNER_SELECTORS,
        }.get(op.block or "", OFFSET_SELECTORS)
        key = entry.key
        if entry.kind != "abs":
            self.error(
                entry.pos,
                f"'{op.name}' selectors have no size prefix",
                f"write e.g. '{allowed[0]}: A'",
            )
            return
        if isinstance(key, n.Name) and key.name in allowed:
            return
        index_call = COMP_INDEX_CALLS.get(self.comp_kind, "face")
        if op.block == "comp" and isinstance(key, n.Call) and key.name == index_call:
            if len(key.args) != 1:
                self.error(key.pos, f"{index_call}() takes one argument, the {index_call} index")
            else:
                self.expr(key.args[0], local, in_rule=True)
            return
        word = key.name if isinstance(key, (n.Name, n.Call)) else None
        extra = f", {index_call}(i)" if op.block == "comp" else ""
        hint = suggest(word, allowed) if word else None
        self.error(
            key.pos,
            f"unknown {op.name} selector" + (f" '{word}'" if word else ""),
            hint or f"use one of {', '.join(allowed)}{extra}",
        )
