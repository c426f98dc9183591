"""One section of a style sheet, loaded without the others: ``bgr restyle --section N``.

A sheet of several buildings (emit.style_text) is a header (attrs, the buildings' heights
``const S<k>height``, ``Lot`` choosing ``S<k>Lot`` by ``attr style``, the ``S<k>Lot`` rules,
Wall/Window/Bay, the ``SplitX<m>`` / ``SplitY<m>`` rules of equations 8-9 that any section
uses) and one ``# ---- `` section per building whose consts and rules all start with
``S<k>``.  Loading and checking the whole PLATEAU sheet (10 buildings, 5,500 lines) took 3 s,
Lark reading about 200 KB a second, of which a restyle uses one section.

:func:`section_text` keeps the header and section N, and blanks every other line (line numbers
and columns stay those of the file, so a message points into the file as it is): the other
sections, the other ``S<k>Lot`` rules, the Split rules section N never names, and ``Lot``'s
cases, ``Lot --> S<N>Lot`` in their place (the same successor the case took, so the derivation
and its output are the same).  Only a sheet laid out exactly as emit writes it is cut: anything
else (a sheet edited by hand, one building, a section that names another's rules) gives None,
and :func:`load_section` loads the whole sheet, as does a cut text that fails to check.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable
from pathlib import Path

from bgr.grammar.checker import Grammar
from bgr.grammar.errors import BgrError

MARKER = "# ---- "
_HEAD = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")  # a line starting at column 0 with a name
_SPLIT = re.compile(r"(Split[XY]\d+)(?:Fit|Y|Run|Scaled)?")
_SPLIT_USE = re.compile(r"\b(Split[XY]\d+)\(")
_SECTION_NAME = re.compile(r"\bS(\d+)[A-Za-z_]")
_HEIGHT = re.compile(r"const S(\d+)height = ")  # a building's height, in the header


def _extents(lines: list[str], first: int, end: int) -> list[tuple[str, int, int]]:
    """(name, first line, end line) of each line in [first, end) that starts with a name at
    column 0, reaching to the next such line (continuation lines are indented, or start with
    ``)`` or ``}``; comments between rules go with the rule before)."""
    heads = [(i, m[0]) for i in range(first, end) if (m := _HEAD.match(lines[i]))]
    return [
        (name, i, heads[j + 1][0] if j + 1 < len(heads) else end)
        for j, (i, name) in enumerate(heads)
    ]


def section_text(text: str, section: int) -> str | None:
    """The sheet's text with only section ``section`` (and what it uses of the header) left,
    every other line blank; None when the text is not laid out as emit writes a sheet of
    several buildings."""
    if "\r" in text:
        return None
    lines = text.split("\n")
    marks = [i for i, line in enumerate(lines) if line.startswith(MARKER)]
    count = len(marks)
    if count < 2 or not 0 <= section < count:
        return None
    header = _extents(lines, 0, marks[0])
    lot = [(i, end) for name, i, end in header if name == "Lot"]
    cases = [f"case style == {k}: S{k}Lot" for k in range(count - 1)]
    cases.append(f"else: S{count - 1}Lot")
    if len(lot) != 1:
        return None
    at, end = lot[0]
    # bgr fmt's two layouts of a case rule: on one line when it fits, else a case a line
    if lines[at] == "Lot --> " + " | ".join(cases):
        span = 1
    elif lines[at] == "Lot -->" and lines[at + 1 : at + 1 + count] == [
        ("    | " if k else "    ") + case for k, case in enumerate(cases)
    ]:
        span = 1 + count
    else:
        return None
    if any(lines[at + span : end]):
        return None
    stop = marks[section + 1] if section + 1 < count else len(lines)
    mine = lines[marks[section] : stop]
    for line in mine:  # every const and rule of the section is its own
        if _HEAD.match(line) and not re.match(rf"(const )?S{section}(?![0-9])[A-Za-z_]", line):
            return None
    text_of_section = "\n".join(mine)
    if any(int(k) != section for k in _SECTION_NAME.findall(text_of_section)):
        return None
    used = set(_SPLIT_USE.findall(text_of_section))
    out = [""] * len(lines)
    out[marks[section] : stop] = mine
    for name, first, end in header:
        split = _SPLIT.fullmatch(name)
        if name == "Lot":
            out[first] = f"Lot --> S{section}Lot"
        elif re.fullmatch(r"S\d+Lot", name):
            if name == f"S{section}Lot":
                out[first:end] = lines[first:end]
        elif name == "const" and (height := _HEIGHT.match(lines[first])):
            if int(height[1]) == section:  # the buildings' heights: this one's only
                out[first:end] = lines[first:end]
        elif split is None or split[1] in used:
            out[first:end] = lines[first:end]
    kept = "\n".join(out[: marks[0]])
    if any(int(k) != section for k in _SECTION_NAME.findall(kept)):
        return None  # the header names some other section's rules outside Lot and S<k>Lot
    # comments and blank lines before the first name stay (the file's opening comment)
    first_head = header[0][1] if header else marks[0]
    out[:first_head] = lines[:first_head]
    return "\n".join(out)


def load_section(
    style: str | os.PathLike, section: int, allow_paths: Iterable[str | os.PathLike] = ()
) -> tuple[Grammar, bool]:
    """The sheet at ``style`` loaded for one section: (grammar, whether it is that section
    alone).  Falls back to the whole sheet whenever the cut is not possible or fails to
    check, so errors are always the whole sheet's."""
    from bgr.grammar.loader import load, read_source

    allow = list(allow_paths)
    if Path(style).suffix == ".bgr" and section >= 0:
        text = read_source(style)
        cut = section_text(text, section)
        if cut is not None:
            try:
                return load(cut, str(style), allow_paths=allow), True
            except BgrError:
                pass
    return load(style, allow_paths=allow), False
