"""Text from input data made safe to write into a .bgr grammar.

The inverse modules (``bgr infer``) put words from their input into the grammar they write: a
file name, a CRS string and object names in header comments, box ids, mesh stems and labels in
rule and asset names.  Such input comes from anywhere (a city file from the internet), so it must
never be able to add a line to the grammar: a file named ``n\\nattr evil = 1\\n#.obj`` would
otherwise write ``attr evil = 1`` as code.  Every inverse module goes through these functions:

* :func:`comment_text` makes any string one line of printable text for a comment (line breaks,
  NUL, other control and invisible characters escaped as ``\\n``, ``\\x00``, ``\\u2028``; bounded);
* :func:`identifier` makes any string a legal rule or asset name (ASCII letters, digits and
  ``_``, starting with a letter, not a keyword or built-in, bounded);
* :func:`unwritable` says why a string (a mesh path, a label) cannot be a string literal;
* :func:`comment_line` is what the formatter itself applies to a comment a module built: a line
  that cannot end early or open with code (parsed comments pass through unchanged).

String literals need no more: the formatter escapes quotes, backslashes and line ends
(:func:`bgr.grammar.formatter.format_string`).
"""

from __future__ import annotations

import re

from .registry import BUILTIN_NAMES, KEYWORDS, OPERATIONS

COMMENT_LENGTH = 200  # input text kept in a comment, in characters (then "...")
NAME_LENGTH = 64  # a rule or asset name made from input keeps this many characters
RESERVED = frozenset(
    set(OPERATIONS)
    | set(KEYWORDS)
    | set(BUILTIN_NAMES)
    | {"NIL", "true", "false", "and", "or", "not", "case", "else"}
)
_NOT_NAME = re.compile(r"[^A-Za-z0-9_]")
_LINE_ENDS = re.compile(r"[\r\n\x00]")  # what ends a line for the parser (and NUL, refused)


def comment_text(text: object, most: int = COMMENT_LENGTH) -> str:
    """``text`` as one line of printable characters: every character Python does not call
    printable (line and paragraph separators, NEL, NUL, tabs, bidi controls, lone surrogates
    from undecodable file names) written as its escape; a text longer than ``most`` characters
    is cut to ``most`` (escapes counted) and ends in ``...``.  Why: an editor breaks lines at
    more characters than the parser does, and a grammar must read the same to a person as to bgr."""
    text = str(text)
    safe = "".join(c if c.isprintable() else repr(c)[1:-1] for c in text[: most + 1])
    return safe[:most] + "..." if len(text) > most else safe


def comment_line(text: str) -> str:
    """A comment as the formatter writes it: starts with ``#`` (or ``//``), and no line end or
    NUL inside, so that it stays one comment.  Text the parser read is returned as it is."""
    if _LINE_ENDS.search(text):
        text = _LINE_ENDS.sub(lambda m: repr(m.group())[1:-1], text)
    if not text.startswith(("#", "//")):
        text = "# " + text
    return text


def identifier(
    text: object,
    default: str = "Part",
    *,
    prefix: str = "",
    capital: bool = False,
    most: int = NAME_LENGTH,
    sep: str = "",
    taken: set[str] | frozenset[str] = frozenset(),
) -> str:
    """A legal, unused rule or asset name made from ``text``: every other character becomes
    ``_`` (``_`` at the ends dropped), a name not starting with a letter gets ``prefix`` (or
    ``default``'s first letter) in front, an empty one is ``default``; ``capital``: its first
    letter upper case; at most ``most`` characters of ``text``, then ``sep`` and a number when
    the name is a keyword, a built-in or in ``taken`` (the caller adds the result to its set)."""
    name = _NOT_NAME.sub("_", str(text)).strip("_")[:most] or default
    if not name[0].isalpha() or not name[0].isascii():
        name = (prefix or default[:1] or "P") + name
    if capital:
        name = name[0].upper() + name[1:]
    out, i = name, 2
    while out in RESERVED or out in taken:
        out, i = f"{name}{sep}{i}", i + 1
    return out


def unwritable(text: str) -> str | None:
    """What in ``text`` no .bgr string literal can hold (a NUL, a lone surrogate such as an
    undecodable byte of a file name), said for a message; None when it can be written."""
    if "\x00" in text:
        return "a NUL character"
    try:
        text.encode("utf-8")
    except UnicodeEncodeError as e:
        return f"the character {comment_text(text[e.start])} (not Unicode text)"
    return None
