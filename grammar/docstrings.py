"""Doc comments: the comment block directly above a rule, read as its documentation.

The standard library documents every public rule this way, and ``docs/stdlib.md`` is generated
from it::

    # Arched: a round-arched window, the glass recessed behind a frame.
    #   frame: frame width, metres
    #   recess: how far the glass sits behind the wall face, metres
    Arched(frame = 0.08, recess = 0.15) --> ...

The first line is ``Name: summary``; each later line of the form ``  param: text`` documents a
parameter; any other line continues the summary.  A module's header is the comment block at the
top of the file.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from . import nodes as n

_PARAM = re.compile(r"^\s{2,}([A-Za-z_][A-Za-z0-9_]*)\s*:\s*(.*)$")


@dataclass
class RuleDoc:
    name: str
    summary: str  # the text after "Name:" on the first line, with continuation lines
    params: dict[str, str] = field(default_factory=dict)  # parameter -> its line
    named: bool = False  # the first line starts with "Name:"


def _text(comment: n.Comment) -> str:
    text = comment.text
    for mark in ("#", "//"):
        if text.startswith(mark):
            return text[len(mark) :].rstrip()
    return text.rstrip()


def rule_docs(module: n.Module) -> dict[str, RuleDoc]:
    """The doc comment of every rule that has one (own-line comments directly above its head)."""
    by_line = {c.line: c for c in module.comments if c.own_line}
    docs: dict[str, RuleDoc] = {}
    for rule in module.rules():
        lines = []
        line = rule.pos.line - 1
        while line in by_line:
            lines.append(_text(by_line[line]))
            line -= 1
        if lines:
            docs[rule.name] = parse_doc(rule.name, list(reversed(lines)))
    return docs


def parse_doc(name: str, lines: list[str]) -> RuleDoc:
    first = lines[0].strip()
    named = first.startswith(name + ":")
    summary = [first[len(name) + 1 :].strip() if named else first]
    params: dict[str, str] = {}
    for raw in lines[1:]:
        m = _PARAM.match(raw)
        if m:
            params[m.group(1)] = m.group(2).strip()
        elif raw.strip():
            summary.append(raw.strip())
    return RuleDoc(name, " ".join(summary), params, named)


def module_header(module: n.Module) -> str:
    """The comment block at the top of a file, before its first declaration or rule."""
    first_item = min(
        (item.pos.line for item in module.items if getattr(item, "pos", None)), default=10**9
    )
    out: list[tuple[int, str]] = []
    for c in sorted(module.comments, key=lambda c: c.line):
        if c.line >= first_item or not c.own_line:
            break
        if out and c.line != out[-1][0] + 1:
            break
        out.append((c.line, _text(c).strip()))
    return " ".join(text for _, text in out).strip()
