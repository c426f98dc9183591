"""Syntax tree -> canonical .bgr text, comments kept.  The only way the project writes .bgr.

Layout rules (docs/language.md, "Formatting"):

* one declaration or rule per line; blank lines between top-level items are kept (at most one);
* a rule is one line when it fits in 100 columns; otherwise, or when a comment sits inside it,
  its stochastic or conditional branches go one per line, and its split / comp / offset blocks
  open with ``{`` and put one entry per line, each after a leading ``|``;
* a rule head longer than 60 columns puts one parameter per line, then ``) -->`` and the body;
* spacing is fixed: ``a + b``, ``f(a, b)``, ``{ 3: A | ~1: B }``, ``[ t(0, 0, 1) A ]``;
* expressions get the parentheses their meaning needs and no more.

Comments are anchored to output lines: a comment on its own line goes before the first line that
comes after it in the source; a comment after code goes at the end of that code's line.  The
result is idempotent and ``parse(format(x)) == parse(x)``.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence
from dataclasses import dataclass

from . import nodes as n
from .errors import BgrError, Diagnostic, source_lines
from .safe_text import comment_line

WIDTH = 100
HEAD_WIDTH = (
    60  # a rule head (name, parameters, arrow) longer than this lists one parameter per line
)
INDENT = "    "

# Precedence levels, loosest first; they mirror the tree builder's binding powers.
_LEVEL = {
    "or": 1,
    "and": 2,
    "==": 4,
    "!=": 4,
    "<": 4,
    "<=": 4,
    ">": 4,
    ">=": 4,
    "+": 5,
    "-": 5,
    "*": 6,
    "/": 6,
    "%": 6,
    "**": 8,
}
_UNARY_LEVEL = {"not": 3, "-": 7, "+": 7}
_ATOM = 9


# ---- expressions --------------------------------------------------------------------------------


def format_number(value: float) -> str:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"cannot write {value!r} as a .bgr number")
    if float(value).is_integer() and abs(value) < 1e16:
        return str(int(value))
    return repr(float(value))


def format_string(value: str) -> str:
    if "\x00" in value:
        raise ValueError("a .bgr string cannot hold a NUL character")
    escaped = (
        value.replace("\\", "\\\\")
        .replace('"', '\\"')
        .replace("\n", "\\n")
        .replace("\r", "\\r")
        .replace("\t", "\\t")
    )
    return f'"{escaped}"'


def _level(e) -> int:
    if isinstance(e, n.Binary):
        return _LEVEL[e.op]
    if isinstance(e, n.Unary):
        return _UNARY_LEVEL[e.op]
    if isinstance(e, n.Ternary):
        return 0
    if isinstance(e, n.Number) and e.value < 0:
        return _UNARY_LEVEL["-"]  # -2 prints like a prefix minus (and -0.0 prints as 0)
    return _ATOM


def format_expr(e) -> str:
    """An expression with the fewest parentheses that keep its meaning."""
    if isinstance(e, n.Number):
        return format_number(e.value)
    if isinstance(e, n.String):
        return format_string(e.value)
    if isinstance(e, n.Bool):
        return "true" if e.value else "false"
    if isinstance(e, n.Name):
        return e.name
    if isinstance(e, n.Call):
        return f"{e.name}({', '.join(format_arg(a) for a in e.args)})"
    if isinstance(e, n.Array):
        return f"[{', '.join(format_expr(a) for a in e.items)}]"
    if isinstance(e, n.Index):
        target = format_expr(e.target)
        if _level(e.target) < _ATOM:
            target = f"({target})"
        return f"{target}[{format_expr(e.index)}]"
    if isinstance(e, n.Relative):
        return ("~" if e.floating else "'") + format_expr(e.expr)
    if isinstance(e, n.Unary):
        inner = format_expr(e.operand)
        # `not` takes everything down to comparisons; `-` and `+` take only `**`
        if _level(e.operand) < (3 if e.op == "not" else 8):
            inner = f"({inner})"
        return f"not {inner}" if e.op == "not" else f"{e.op}{inner}"
    if isinstance(e, n.Binary):
        return _format_chain(e)
    if isinstance(e, n.Ternary):
        parts = []
        while isinstance(e, n.Ternary):  # the else spine in a loop: it can be long
            cond = format_expr(e.cond)
            if _level(e.cond) == 0:
                cond = f"({cond})"
            parts.append(f"{cond} ? {format_expr(e.then)} : ")
            e = e.otherwise
        return "".join(parts) + format_expr(e)
    raise TypeError(f"not an expression: {e!r}")


def _format_chain(e: n.Expr) -> str:
    """A binary operator with the fewest parentheses; the left spine of a chain
    (``1 + 2 + ... + n``) in a loop, so that its length costs no stack.  A parenthesis around a
    left operand always opens at the very start of the text, so only their count is kept."""
    spine = []
    while isinstance(e, n.Binary):
        spine.append(e)
        e = e.left
    parts, opens = [format_expr(e)], 0
    for node in reversed(spine):
        p = _LEVEL[node.op]
        ll, rl = _level(node.left), _level(node.right)
        if ll <= p if (node.op == "**" or p == 4) else ll < p:
            opens += 1
            parts.append(")")
        right = format_expr(node.right)
        if _is_signed(node.right):  # a prefix minus opens a term of its own: a * -b, a ** -b
            right_paren = False
        elif isinstance(node.right, n.Unary):  # `not`: only `and` and `or` can take it bare
            right_paren = p > 2
        else:
            right_paren = rl < p if node.op == "**" else rl <= p
        parts.append(f" {node.op} ({right})" if right_paren else f" {node.op} {right}")
    return "(" * opens + "".join(parts)


def _is_signed(e) -> bool:
    """A prefix ``-``/``+`` term or a negative number: it binds only ``**`` to its right."""
    return (isinstance(e, n.Unary) and e.op in ("-", "+")) or (
        isinstance(e, n.Number) and _level(e) == 7
    )


def format_annotation(note: n.Annotation) -> str:
    """``@Name`` or ``@Name(args)``, arguments as a call's (``min = 1``)."""
    if not note.args:
        return f"@{note.name}"
    return f"@{note.name}({', '.join(format_arg(a) for a in note.args)})"


def format_arg(a) -> str:
    if isinstance(a, n.Keyword):
        return f"{a.name} = {format_expr(a.value)}"
    return format_expr(a)


def format_params(rule: n.Rule) -> str:
    """``(w, d = 10)``, or nothing for a rule without parameters."""
    if not rule.params:
        return ""
    parts = []
    for i, p in enumerate(rule.params):
        d = rule.default(i)
        parts.append(p if d is None else f"{p} = {format_expr(d)}")
    return f"({', '.join(parts)})"


def _guarded(e) -> str:
    """An expression in front of ':' (a split size, a case): a ternary there gets parentheses."""
    text = format_expr(e)
    return f"({text})" if isinstance(e, n.Ternary) else text


# ---- layout -------------------------------------------------------------------------------------


@dataclass
class Line:
    text: str
    anchor: int  # the source line this output line starts from
    indent: int
    top: bool = False  # the first line of a top-level item, or a comment before one


class _Writer:
    def __init__(self) -> None:
        self.lines: list[Line] = []
        self.parts: list[str] = []
        self.anchor, self.indent, self.top = 0, 0, False

    def start(self, anchor: int, indent: int, top: bool = False) -> None:
        self.flush()
        self.anchor, self.indent, self.top = anchor, indent, top

    def write(self, text: str) -> None:
        self.parts.append(text)

    def column(self) -> int:
        return len(INDENT) * self.indent + sum(len(p) for p in self.parts)

    def flush(self) -> None:
        if self.parts:
            self.lines.append(
                Line("".join(self.parts).rstrip(), self.anchor, self.indent, self.top)
            )
        self.parts = []


class Formatter:
    def __init__(self, module: n.Module, width: int = WIDTH) -> None:
        self.module = module
        self.width = width
        # a comment a module built (bgr infer) stays one comment, whatever its text holds
        self.comments = [
            c
            if c.text == (safe := comment_line(c.text))
            else n.Comment(safe, c.line, c.column, c.own_line)
            for c in sorted(module.comments, key=lambda c: (c.line, c.column))
        ]
        self.comment_keys = [(c.line, c.column) for c in self.comments]
        self.source_lines = source_lines(module.source) if module.source else []

    # ---- comments inside a span decide between one line and several -------------------
    def has_comment_inside(self, pos: n.Pos) -> bool:
        if not pos.line or not self.comments:
            return False
        i = bisect.bisect_left(self.comment_keys, (pos.line, 0))
        return i < len(self.comment_keys) and self.comment_keys[i] < (pos.end_line, pos.end_column)

    def has_comment_on_line(self, line: int) -> bool:
        i = bisect.bisect_left(self.comment_keys, (line, 0))
        return i < len(self.comment_keys) and self.comment_keys[i][0] == line

    def can_inline(self, node) -> bool:
        if self.has_comment_inside(node.pos):
            return False
        return all(self.can_inline(b) for b in _blocks_in(node))

    # ---- items --------------------------------------------------------------------------
    def format(self) -> str:
        out = _Writer()
        for item in self.module.items:
            notes = getattr(item, "annotations", None) or []
            out.start(notes[0].pos.line if notes else item.pos.line, 0, top=True)
            for k, note in enumerate(notes):  # one a line, above what they annotate
                out.write(format_annotation(note))
                out.start(notes[k + 1].pos.line if k + 1 < len(notes) else item.pos.line, 0)
            if isinstance(item, n.Rule):
                self.rule(item, out)
            else:
                out.write(self.declaration(item))
        out.flush()
        return self.render(self.place_comments(out.lines))

    def declaration(self, item) -> str:
        if isinstance(item, n.Version):
            return f"version {format_number(item.number)}"
        if isinstance(item, n.Import):
            target = item.module if item.module is not None else format_string(item.path or "")
            return f"import {target} as {item.alias}"
        if isinstance(item, n.Attr):
            return f"attr {item.name} = {format_expr(item.value)}"
        if isinstance(item, n.Const):
            return f"const {item.name} = {format_expr(item.value)}"
        if isinstance(item, n.Func):
            return f"func {item.name}({', '.join(item.params)}) = {format_expr(item.body)}"
        if isinstance(item, n.Asset):
            return f"asset {item.name} = {format_string(item.path)}"
        if isinstance(item, n.TerminalDecl):
            return f"terminal {', '.join(item.names)}"
        if isinstance(item, n.Start):
            return f"start {item.name}"
        if isinstance(item, n.Site):
            crs = "" if item.crs is None else f" {format_string(item.crs)}"
            origin = ", ".join(format_number(v) for v in item.origin)
            return f"site{crs} origin ({origin}) up {item.up}"
        raise TypeError(f"not a top-level item: {item!r}")

    def rule(self, rule: n.Rule, out: _Writer) -> None:
        head = rule.name + format_params(rule) + " -->"
        if len(head) > HEAD_WIDTH and rule.params:  # a long parameter list: one a line
            out.write(rule.name + "(")
            for i, p in enumerate(rule.params):
                out.start(rule.pos.line, 1)
                d = rule.default(i)
                out.write(
                    (p if d is None else f"{p} = {format_expr(d)}")
                    + ("," if i < len(rule.params) - 1 else "")
                )
            out.start(rule.pos.line, 0)
            head = ") -->"
        body = rule.body
        if isinstance(body, n.Sequence):
            if self.one_push_a_line(head, body):
                out.write(head)
                for step in body.steps:
                    out.start(step.pos.line or rule.pos.line, 1)
                    self.steps([step], out)
                return
            out.write(head + " ")
            self.steps(body.steps, out)
            return
        alts: Sequence[n.Choice | n.Case] = (
            body.choices if isinstance(body, n.Stochastic) else body.cases
        )
        heads = [self.alt_head(a) for a in alts]
        inline = (
            head
            + " "
            + " | ".join(
                h + self.inline_steps(a.body.steps) for h, a in zip(heads, alts, strict=True)
            )
        )
        # Branches have no closing bracket, so a comment after the last one also keeps them
        # one per line once they already start below the head (that is how fmt wrote them).
        trailing_below = body.pos.line > rule.pos.line and self.has_comment_on_line(
            body.pos.end_line
        )
        if (
            all(self.can_inline(a.body) for a in alts)
            and not self.has_comment_inside(body.pos)
            and not trailing_below
            and len(inline) <= self.width
        ):
            out.write(inline)
            return
        out.write(head)
        for i, (h, alt) in enumerate(zip(heads, alts, strict=True)):
            out.start(alt.pos.line or rule.pos.line, 1)
            out.write(("| " if i else "") + h)
            self.steps(alt.body.steps, out)

    def one_push_a_line(self, head: str, body: n.Sequence) -> bool:
        """A rule that only places children (``[ ... A ] [ ... B ] ...``, as the city grammars
        of bgr infer write) and is too long for a line gets one placement per line."""
        steps = body.steps
        if len(steps) < 2 or not all(isinstance(s, n.Push) for s in steps):
            return False
        if self.has_comment_inside(body.pos) or self.has_comment_on_line(body.pos.end_line):
            return False  # comments keep the rule on one line, so that fmt(fmt(x)) == fmt(x)
        if len(head) + 4 * len(steps) > self.width:  # each `[ ]` and a space: too long, unwritten
            return True
        return len(head) + 1 + len(self.inline_steps(steps)) > self.width

    def alt_head(self, alt) -> str:
        if isinstance(alt, n.Choice):
            if alt.prob is None:
                return "else: "
            if isinstance(alt.prob, n.Number) and alt.prob.value >= 0:
                return f"{format_number(alt.prob.value)}%: "
            return f"({format_expr(alt.prob)})%: "
        return "else: " if alt.cond is None else f"case {_guarded(alt.cond)}: "

    # ---- steps and blocks ------------------------------------------------------------------
    def inline_steps(self, steps) -> str:
        w = _Writer()
        self.steps(steps, w, force_inline=True)
        w.flush()
        return w.lines[0].text if w.lines else ""

    def steps(self, steps, out: _Writer, force_inline: bool = False) -> None:
        for i, step in enumerate(steps):
            if i:
                out.write(" ")
            if isinstance(step, n.Nil):
                out.write("NIL")
            elif isinstance(step, n.Successor):
                out.write(
                    step.name
                    + (f"({', '.join(format_arg(a) for a in step.args)})" if step.args else "")
                )
            elif isinstance(step, n.Push):
                out.write("[ " if step.steps else "[")
                self.steps(step.steps, out, force_inline)
                out.write(" ]")
            elif isinstance(step, n.Operation):
                out.write(f"{step.name}({', '.join(format_arg(a) for a in step.args)})")
                if step.block is not None:
                    out.write(" ")
                    self.block(
                        step.block.entries, step.block.repeat, step.block.pos, out, force_inline
                    )
            else:
                raise TypeError(f"not a step: {step!r}")

    def inline_block(self, entries, star: bool) -> str:
        return (
            "{ " + " | ".join(self.inline_entry(e) for e in entries) + " }" + ("*" if star else "")
        )

    def inline_entry(self, entry) -> str:
        if isinstance(entry, n.Group):
            return self.inline_block(entry.entries, True)
        return self.key(entry) + self.inline_steps(entry.body.steps)

    def key(self, entry: n.Entry) -> str:
        prefix = {"abs": "", "rel": "'", "float": "~"}[entry.kind]
        return f"{prefix}{_guarded(entry.key)}{' = ' if entry.combine else ': '}"

    def block(self, entries, star: bool, pos: n.Pos, out: _Writer, force_inline: bool) -> None:
        inline = self.inline_block(entries, star)
        fits = out.column() + len(inline) <= self.width
        if force_inline or (
            fits and not self.has_comment_inside(pos) and all(self.can_inline(e) for e in entries)
        ):
            out.write(inline)
            return
        indent = out.indent
        out.write("{")
        for i, entry in enumerate(entries):
            out.start(entry.pos.line or out.anchor, indent + 1)
            out.write("| " if i else "")
            if isinstance(entry, n.Group):
                self.block(entry.entries, True, entry.pos, out, False)
            else:
                out.write(self.key(entry))
                self.steps(entry.body.steps, out)
        out.start(pos.end_line or out.anchor, indent)
        out.write("}" + ("*" if star else ""))

    # ---- comments and blank lines ----------------------------------------------------------
    def place_comments(self, lines: list[Line]) -> list[Line]:
        leading: dict[int, list[Line]] = {}
        trailing: dict[int, list[str]] = {}
        tail: list[Line] = []
        anchors = [ln.anchor for ln in lines]
        for c in self.comments:
            if c.own_line:
                i = bisect.bisect_right(anchors, c.line)
                if i < len(lines):
                    target = lines[i]
                    leading.setdefault(i, []).append(
                        Line(c.text, c.line, target.indent, target.top)
                    )
                else:
                    tail.append(Line(c.text, c.line, 0, True))
            else:
                i = bisect.bisect_right(anchors, c.line) - 1
                if i >= 0:
                    trailing.setdefault(i, []).append(c.text)
                else:  # cannot happen for parsed text; keep the comment all the same
                    leading.setdefault(0, []).append(Line(c.text, c.line, 0, True))
        placed: list[Line] = []
        for i, line in enumerate(lines):
            placed += leading.get(i, [])
            if i in trailing:
                line = Line(
                    line.text + "  " + "  ".join(trailing[i]), line.anchor, line.indent, line.top
                )
            placed.append(line)
        return placed + tail

    def render(self, lines: list[Line]) -> str:
        text: list[str] = []
        for line in lines:
            if line.top and text and text[-1] != "" and self.blank_before(line.anchor):
                text.append("")
            text.append(INDENT * line.indent + line.text)
        return "\n".join(text) + "\n" if text else ""

    def blank_before(self, line: int) -> bool:
        return 1 < line <= len(self.source_lines) + 1 and not self.source_lines[line - 2].strip()


def _blocks_in(node):
    """The blocks and groups directly or indirectly inside a node (not the node itself)."""
    if isinstance(node, (n.Block, n.Group)):
        for e in node.entries:
            if isinstance(e, n.Group):
                yield e
            else:
                yield from _blocks_in(e.body)
    elif isinstance(node, n.Entry):
        yield from _blocks_in(node.body)
    elif isinstance(node, (n.Sequence, n.Push)):
        for step in node.steps:
            if isinstance(step, n.Operation) and step.block is not None:
                yield step.block
            elif isinstance(step, n.Push):
                yield from _blocks_in(step)


def format_module(module: n.Module, width: int = WIDTH) -> str:
    """Canonical text of a syntax tree (parsed, or built by an inverse module)."""
    try:
        return Formatter(module, width).format()
    except RecursionError:
        raise BgrError(
            Diagnostic(
                module.path,
                0,
                0,
                "the grammar nests expressions or blocks too deeply to format",
                "split deep nesting into separate rules",
            )
        ) from None


def format_source(text: str, path: str = "<text>") -> str:
    """Canonical text of .bgr source; raises BgrSyntaxError on text that does not parse, and
    TypeError when ``text`` is not a ``str`` (a programmer's error)."""
    if not isinstance(text, str):
        raise TypeError(
            f"bgr.format_source takes the text of a grammar (str), not {type(text).__name__}"
        )
    from .parser import parse

    return format_module(parse(text, path))
