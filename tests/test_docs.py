"""The documentation stays true: every ```bgr example checks and is canonical, the generated
operation reference is current, and the language reference mentions every operation and function.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

import bgr
from bgr.grammar.reference import reference_markdown
from bgr.grammar.registry import (
    BUILTIN_NAMES,
    BUILTINS,
    COMP_SELECTORS,
    OFFSET_SELECTORS,
    OPERATIONS,
    PRIMITIVES,
    ROOF_KINDS,
)

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
LANGUAGE = DOCS / "language.md"

_FENCE = re.compile(r"^```bgr[ \t]*\n(.*?)^```[ \t]*$", re.S | re.M)


def _markdown_files() -> list[Path]:
    files = sorted(DOCS.glob("*.md"))
    readme = ROOT / "README.md"
    if readme.is_file():
        files.insert(0, readme)
    return files


def bgr_blocks(path: Path) -> list[tuple[int, str]]:
    """(line of the opening fence, text) of every ```bgr block in a Markdown file."""
    text = path.read_text(encoding="utf-8")
    return [(text.count("\n", 0, m.start()) + 1, m.group(1)) for m in _FENCE.finditer(text)]


def _all_blocks():
    for md in _markdown_files():
        for line, text in bgr_blocks(md):
            yield pytest.param(md, line, text, id=f"{md.relative_to(ROOT)}:{line}")


ALL_BLOCKS = list(_all_blocks())


@pytest.mark.parametrize("md, line, text", ALL_BLOCKS)
def test_example_checks(md: Path, line: int, text: str) -> None:
    # Each example is checked as if it were a file beside the Markdown file, so that relative
    # imports (import "../examples/house.bgr") resolve from there.
    # The repository is allowed as a root, since the examples reach ../examples from docs/.
    shown = md.parent / f"{md.stem}-line{line}.bgr"
    try:
        bgr.load(text, path=str(shown), allow_paths=[ROOT])
    except bgr.BgrError as e:
        pytest.fail(f"the example at {md.name}:{line} does not check:\n{e.render()}")


@pytest.mark.parametrize("md, line, text", ALL_BLOCKS)
def test_example_is_canonical(md: Path, line: int, text: str) -> None:
    formatted = bgr.format_source(text)
    assert formatted == text, f"the example at {md.name}:{line} is not in canonical layout"


def test_language_reference_has_enough_examples() -> None:
    assert len(bgr_blocks(LANGUAGE)) >= 30


def test_operations_reference_is_generated() -> None:
    expected = reference_markdown()
    actual = (DOCS / "operations.md").read_text(encoding="utf-8")
    assert actual == expected, "regenerate it: python -m bgr.grammar.reference > docs/operations.md"


def _mentions_call(text: str, name: str) -> bool:
    """``name(`` inside a code span or a code block: `t(x, y, z)`, ``rand()``."""
    return re.search(rf"(?<![\w.]){re.escape(name)}\(", text) is not None


@pytest.mark.parametrize("name", sorted(OPERATIONS))
def test_language_reference_mentions_operation(name: str) -> None:
    text = LANGUAGE.read_text(encoding="utf-8")
    assert _mentions_call(text, name), f"docs/language.md never shows the operation {name}(...)"


@pytest.mark.parametrize("name", sorted(BUILTINS))
def test_language_reference_mentions_builtin_function(name: str) -> None:
    text = LANGUAGE.read_text(encoding="utf-8")
    assert _mentions_call(text, name), f"docs/language.md never shows the function {name}(...)"


@pytest.mark.parametrize(
    "word",
    sorted(
        set(BUILTIN_NAMES)
        | set(ROOF_KINDS)
        | set(PRIMITIVES)
        | set(COMP_SELECTORS)
        | set(OFFSET_SELECTORS)
    ),
)
def test_language_reference_mentions_symbol(word: str) -> None:
    text = LANGUAGE.read_text(encoding="utf-8")
    assert f"`{word}`" in text or re.search(
        rf"`[^`\n]*(?<![\w.]){re.escape(word)}(?![\w])[^`\n]*`", text
    ), f"docs/language.md never mentions `{word}`"
