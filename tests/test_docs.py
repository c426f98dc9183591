"""The documentation stays true: every ```bgr example checks and is canonical, the generated
operation reference is current, and the language reference mentions every operation and function.
"""

from __future__ import annotations

import ast
import io
import os
import re
import shlex
import subprocess
import sys
import tokenize
from dataclasses import dataclass, field
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


# --- The commands of README.md and docs/cli.md run and print what the docs say (issue 24) ---
#
# Every `bgr ...` line of a ```sh block is run (status 0 expected); every `$ ...` line of a
# ```console or ```text transcript is run and what it prints is compared with the lines the
# doc shows under it (a command with no lines under it must print nothing). `$ echo $?` gives
# the status of the command before it; otherwise a transcript whose output shows `error:`
# expects 1, and 0 elsewhere. `$ cat FILE` shows a file: it is compared when an earlier command
# wrote FILE and written from the doc when none did (a file the reader is asked to create). A
# ```text or ```json block after a line ending "`NAME.ext`:" ("Given this `bad.bgr`:") is such a
# file too. Each block runs in its own temporary folder, where `examples/` and `tests/` are
# links to the repository's, so that the doc's paths work and its outputs land there.

COMMAND_DOCS = [ROOT / "README.md", DOCS / "cli.md"]

_ANY_FENCE = re.compile(r"^```([\w-]*)[^\n]*\n(.*?)^```[ \t]*$", re.S | re.M)
_GIVEN = re.compile(r"`([\w.-]+\.\w+)`:\s*$")
_SHELL = {"sh", "shell", "bash"}
_TRANSCRIPT = {"console", "text"}

# Files the docs name but show only in part (the error message quotes their one line).
PARTIAL_FILES = {
    "syn.bgr": "Lot --> extrude(3 Mass\n",  # docs/cli.md, "A syntax error stops ..."
    "deep.bgr": "Lot --> t(0, 1, 0) Lot\n",  # docs/cli.md, "a `deep.bgr` whose one rule ..."
}

# Commands on the 481 Helsinki footprints take 20 s to minutes on two cores: marked slow (CI
# runs them in a step of their own; `pytest -m slow tests/test_docs.py` here).
SLOW = ("helsinki_osm_buildings.geojson",)

# Commands not run, each with why; keep it short. (None today: every command of the two files
# names shipped files or files an earlier command or block of the same doc makes.)
SKIP: dict[str, str] = {}

_NO_GL = "no OpenGL context through EGL"


@dataclass
class Step:
    line: int  # of the Markdown file
    command: str
    output: list[str] | None  # the lines the doc shows under it; None in a ```sh block
    status: int | None = None  # from a `$ echo $?` after it


@dataclass
class Block:
    doc: Path
    line: int
    steps: list[Step]
    given: dict[str, str] = field(default_factory=dict)


def _shell_steps(body: str, first: int) -> list[Step]:
    steps: list[Step] = []
    lines = body.split("\n")
    i = 0
    while i < len(lines):
        start, text = first + i, lines[i]
        while text.endswith("\\") and i + 1 < len(lines):
            i += 1
            text = text[:-1] + " " + lines[i].strip()
        i += 1
        text = re.sub(r"\s+#\s.*$", "", text.strip())
        found = re.search(r"(?:^|&&\s*)(bgr\s.*)$", text)  # `pip install -e . && bgr ...`
        if found:
            steps.append(Step(start, found.group(1), None))
    return steps


def _transcript_steps(body: str, first: int) -> list[Step]:
    steps: list[Step] = []
    lines = body.rstrip("\n").split("\n")
    i = 0
    while i < len(lines):
        text = lines[i]
        if text.startswith("$ "):
            start, command = first + i, text[2:]
            while command.endswith("\\") and i + 1 < len(lines):
                i += 1
                command = command[:-1] + " " + lines[i].strip()
            if command.strip() == "echo $?" and steps:
                steps[-1].status = int(lines[i + 1])
                i += 2
                continue
            steps.append(Step(start, command.strip(), []))
        elif steps and steps[-1].output is not None:
            steps[-1].output.append(text.rstrip())
        i += 1
    return steps


def command_blocks(md: Path) -> list[Block]:
    """Every block of ``md`` that runs a ``bgr`` command, with the files shown before it."""
    text = md.read_text(encoding="utf-8")
    given = dict(PARTIAL_FILES)
    blocks = []
    for m in _ANY_FENCE.finditer(text):
        lang, body = m.group(1), m.group(2)
        first = text.count("\n", 0, m.start()) + 2  # the line of the block's first line
        steps: list[Step] = []
        if lang in _SHELL:
            steps = _shell_steps(body, first)
        elif lang in _TRANSCRIPT:
            steps = _transcript_steps(body, first)
        if any(s.command.startswith("bgr ") for s in steps):
            blocks.append(Block(md, first - 1, steps, dict(given)))
        elif not steps and lang in _TRANSCRIPT | {"json"}:
            before = text[: m.start()].rstrip("\n").rsplit("\n", 1)[-1]
            if name := _GIVEN.search(before):
                given[name.group(1)] = body
    # a table whose last column is a command (the README's examples): run, status 0 expected
    rows = [
        Step(text.count("\n", 0, m.start()) + 1, m.group(1), None)
        for m in re.finditer(r"^\|.*\| `(bgr [^`|]*)` \|[ \t]*$", text, re.M)
    ]
    if rows:
        blocks.append(Block(md, rows[0].line, rows, dict(given)))
    return blocks


def _block_params():
    for md in COMMAND_DOCS:
        for block in command_blocks(md):
            where = f"{md.relative_to(ROOT)}:{block.line}"
            marks = []
            if any(s in step.command for step in block.steps for s in SLOW):
                marks.append(pytest.mark.slow)
            reasons = [r for step in block.steps for c, r in SKIP.items() if c in step.command]
            if reasons:
                marks.append(pytest.mark.skip(reason=reasons[0]))
            yield pytest.param(block, id=where, marks=marks)


def _workdir(tmp: Path, given: dict[str, str]) -> None:
    for name in ("examples", "tests"):
        (tmp / name).symlink_to(ROOT / name, target_is_directory=True)
    for name, body in given.items():
        (tmp / name).write_text(body, encoding="utf-8")


def _shell(command: str, tmp: Path, timeout: float) -> tuple[int, str]:
    """Run a command line with bash in ``tmp``, bgr from this interpreter's environment."""
    env = dict(os.environ, PYTHONUNBUFFERED="1", LC_ALL="C")
    env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
    env.pop("BGR_DEBUG", None)
    done = subprocess.run(
        ["bash", "-c", command],
        cwd=tmp,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        timeout=timeout,
    )
    return done.returncode, done.stdout


def _bgr(command: str, tmp: Path, no_gl: bool, monkeypatch: pytest.MonkeyPatch) -> tuple[int, str]:
    """``bgr.cli.main`` (the entry point of the ``bgr`` script) in this process, which saves
    a Python start and bgr's imports per command; standard output and error are gathered in
    order, as a terminal shows them, except what ``> FILE`` sends to a file."""
    from bgr import cli
    from bgr.render import raster_gl

    argv = shlex.split(command)[1:]
    to_file = None
    if ">" in argv:
        to_file, argv = argv[argv.index(">") + 1], argv[: argv.index(">")]
    both = io.TextIOWrapper(io.BytesIO(), encoding="utf-8", write_through=True)
    out = io.TextIOWrapper(io.BytesIO(), encoding="utf-8", write_through=True) if to_file else both
    with monkeypatch.context() as m:
        m.chdir(tmp)
        m.setattr(sys, "stdout", out)
        m.setattr(sys, "stderr", both)
        if no_gl:  # the doc's example of the numpy fallback: as if no context could be made
            m.setattr(raster_gl, "_state", {"error": f"{_NO_GL} (the docs test hides it)"})
        try:
            status = cli.main(argv)
        except SystemExit as e:  # argparse: --help, bad usage
            status = e.code if isinstance(e.code, int) else int(e.code is not None)
    if to_file:
        (tmp / to_file).write_bytes(out.buffer.getvalue())  # type: ignore[attr-defined]
    return status, both.buffer.getvalue().decode("utf-8")  # type: ignore[attr-defined]


def _matches(shown: str, printed: str) -> bool:
    """A shown line matches a printed one; ``(...)`` in the doc stands for any text."""
    parts = [re.escape(p) for p in shown.split("(...)")]
    return re.fullmatch(r"\(.*\)".join(parts), printed) is not None


def _lines_match(shown: list[str], printed: list[str]) -> bool:
    """The doc's lines match the printed ones; a line ``...`` stands for any lines (warnings)."""
    if not shown:
        return not printed
    if shown[0] == "...":
        return any(_lines_match(shown[1:], printed[i:]) for i in range(len(printed) + 1))
    return bool(printed) and _matches(shown[0], printed[0]) and _lines_match(shown[1:], printed[1:])


def _counts(line: str) -> dict[str, str]:
    return {unit: n for n, unit in re.findall(r"(\d[\d,]*) ([a-z]+)", line)}


def _difference(where: str, step: Step, shown: list[str], printed: list[str]) -> str:
    message = [f"{where}: `{step.command}` prints other lines than the doc shows"]
    doc, out = shown, printed
    if "..." in doc:  # compare what follows the last `...` with the end of the output
        doc = doc[len(doc) - doc[::-1].index("...") :]
        out = out[max(len(out) - len(doc), 0) :]
    for i in range(max(len(doc), len(out))):
        a = doc[i] if i < len(doc) else "(nothing)"
        b = out[i] if i < len(out) else "(nothing)"
        if i >= len(doc) or i >= len(out) or not _matches(a, b):
            quoted, got = _counts(a), _counts(b)
            for unit in quoted.keys() & got.keys():
                if quoted[unit] != got[unit]:
                    message.append(f"  quoted {quoted[unit]} {unit}, printed {got[unit]} {unit}")
            message += [f"  doc: {a}", f"  printed: {b}"]
            break
    return "\n".join(message + ["doc:", *shown, "printed:", *printed[-40:]])


def _run_step(block: Block, step: Step, tmp: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    where = f"{block.doc.relative_to(ROOT)}:{step.line}"
    words = step.command.split()
    if words[0] == "cat" and len(words) == 2 and not (tmp / words[1]).exists():
        (tmp / words[1]).write_text("\n".join(step.output or []) + "\n", encoding="utf-8")
        return
    shown = list(step.output) if step.output is not None else None
    no_gl = shown is not None and any(_NO_GL in line for line in shown)
    if any(s in step.command for s in SLOW):
        status, text = _shell(step.command, tmp, timeout=1800)  # --workers forks: its own process
    elif words[0] == "bgr":
        status, text = _bgr(step.command, tmp, no_gl, monkeypatch)
    else:
        status, text = _shell(step.command, tmp, timeout=60)
    printed = [line.rstrip() for line in text.rstrip("\n").split("\n")]
    printed = [] if printed == [""] else printed
    if words[0] == "bgr":
        expected = step.status
        if expected is None:
            expected = 1 if shown and any("error:" in line for line in shown) else 0
        assert status == expected, (
            f"{where}: `{step.command}` exits {status}, the doc expects {expected}\n" + text[-3000:]
        )
    if shown is None:
        return
    while shown and not shown[-1]:
        shown.pop()
    if not no_gl and any(_NO_GL in line for line in printed):  # no GL on this machine
        printed = [re.sub(r"\(numpy\)$", "(gl)", x) for x in printed if _NO_GL not in x]
    assert _lines_match(shown, printed), _difference(where, step, shown, printed)


@pytest.mark.parametrize("block", list(_block_params()))
def test_documented_commands(block: Block, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    _workdir(tmp_path, block.given)
    for step in block.steps:
        _run_step(block, step, tmp_path, monkeypatch)


def test_command_blocks_are_found() -> None:
    # the parser above finds what it should: a regression here would silently test nothing
    readme, cli = (command_blocks(md) for md in COMMAND_DOCS)
    commands = [s.command for b in readme + cli for s in b.steps if s.command.startswith("bgr")]
    assert len(readme) >= 4 and len(cli) >= 15 and len(commands) >= 35
    assert "bgr check typo.bgr" in commands
    assert {"bad.bgr", "box.bgr", "div.bgr", "street.json"} <= set(cli[-1].given)


# --- Counts quoted in Python examples: `len(result)  # 634 terminals` ---

_COUNT = re.compile(r"#\s*(?:numpy \((\d[\d, ]*)\)|(\d[\d,]*) [a-z]+)")


def _count_comments(text: str) -> dict[int, re.Match[str]]:
    """Line (1-based, in the block) -> the count its comment quotes."""
    found = {}
    for tok in tokenize.generate_tokens(io.StringIO(text).readline):
        if tok.type == tokenize.COMMENT and (m := _COUNT.match(tok.string)):
            found[tok.start[0]] = m
    return found


def _python_count_blocks():
    for md in COMMAND_DOCS:
        text = md.read_text(encoding="utf-8")
        for m in re.finditer(r"^```python[ \t]*\n(.*?)^```[ \t]*$", text, re.S | re.M):
            if _count_comments(m.group(1)):
                line = text.count("\n", 0, m.start()) + 1
                yield pytest.param(md, line, m.group(1), id=f"{md.relative_to(ROOT)}:{line}")


@pytest.mark.parametrize("md, line, text", list(_python_count_blocks()))
def test_python_example_counts(
    md: Path, line: int, text: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Runs the block's statements in a folder like the commands' (examples/ linked), up to the
    # last one with a quoted count, and compares each quoted count with the value.
    _workdir(tmp_path, {})
    monkeypatch.chdir(tmp_path)
    counts = _count_comments(text)
    namespace: dict = {}
    for stmt in ast.parse(text).body:
        if stmt.lineno > max(counts):
            break
        quoted = next(
            (counts[n] for n in range(stmt.lineno, stmt.end_lineno + 1) if n in counts), None
        )
        if quoted is None or not isinstance(stmt, ast.Expr):
            exec(compile(ast.Module([stmt], []), str(md), "exec"), namespace)
            continue
        value = eval(compile(ast.Expression(stmt.value), str(md), "eval"), namespace)
        where = f"{md.relative_to(ROOT)}:{line + stmt.lineno}: {ast.unparse(stmt)}"
        if quoted.group(1):  # numpy (634, 3)
            want = tuple(int(n.replace(",", "")) for n in quoted.group(1).split(", "))
            assert tuple(value.shape) == want, f"{where}: quoted shape {want}, it is {value.shape}"
        else:
            want_n = int(quoted.group(2).replace(",", ""))
            assert value == want_n, f"{where}: quoted '{quoted.group(0)}', it is {value:,}"


# --- Every synopsis of docs/cli.md names the options of its command's --help, and no others ---


def _parser_options() -> dict[str, list[tuple[str, ...]]]:
    """Command -> the option strings of each option of its parser (what --help lists), less -h."""
    import argparse

    from bgr.cli import build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return {
        name: [tuple(a.option_strings) for a in p._actions if a.option_strings]
        for name, p in sub.choices.items()
    }


def _synopses() -> dict[tuple[int, str], set[str]]:
    """(line of the ```text block, command) -> the options its `bgr COMMAND ...` lines name."""
    text = (DOCS / "cli.md").read_text(encoding="utf-8")
    found: dict[tuple[int, str], set[str]] = {}
    for m in re.finditer(r"^```text[ \t]*\n(.*?)^```[ \t]*$", text, re.S | re.M):
        line = text.count("\n", 0, m.start()) + 1
        command = None
        for row in m.group(1).split("\n"):
            if start := re.match(r"bgr ([a-z-]+) ", row):
                command = start.group(1)
            elif not row.startswith(" "):
                command = None
            if command:
                options = set(re.findall(r"(?<![\w-])(--?[a-z][\w-]*)", row))
                found.setdefault((line, command), set()).update(options)
    return found


def test_synopses_match_help() -> None:
    options = _parser_options()
    synopses = _synopses()
    assert {c for _, c in synopses} == set(options), "a command without a synopsis in docs/cli.md"
    problems = []
    for (line, command), shown in sorted(synopses.items()):
        known = {o for strings in options[command] for o in strings}
        unknown = shown - known
        # each option but --help, by any of its names (-o or --output)
        missing = [s[-1] for s in options[command] if "--help" not in s and not shown & set(s)]
        if unknown or missing:
            problems.append(
                f"docs/cli.md:{line}: bgr {command}: {sorted(unknown)} not in its --help, "
                f"{missing} of its --help not shown"
            )
    assert not problems, "\n".join(problems)


# --- Links between the docs point at files and headings that exist ---


def _slug(heading: str) -> str:
    """GitHub's anchor for a heading: lower case, punctuation dropped, spaces to hyphens."""
    text = re.sub(r"[`*_]|\[|\]\([^)]*\)", "", heading.strip().lower())
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def _anchors(md: Path) -> set[str]:
    text = re.sub(r"^```.*?^```", "", md.read_text(encoding="utf-8"), flags=re.S | re.M)
    seen: dict[str, int] = {}
    anchors = set()
    for heading in re.findall(r"^#{1,6} (.+)$", text, re.M):
        slug = _slug(heading)
        anchors.add(slug if slug not in seen else f"{slug}-{seen[slug]}")
        seen[slug] = seen.get(slug, 0) + 1
    return anchors


@pytest.mark.parametrize(
    "md",
    [*_markdown_files(), ROOT / "examples" / "helsinki" / "README.md"],
    ids=lambda p: str(p.relative_to(ROOT)),
)
def test_links_resolve(md: Path) -> None:
    text = re.sub(r"^```.*?^```", "", md.read_text(encoding="utf-8"), flags=re.S | re.M)
    broken = []
    for target in re.findall(r"\]\(([^)\s]+)\)", text):
        if re.match(r"[a-z]+:", target):  # https:, mailto:
            continue
        path, _, anchor = target.partition("#")
        file = (md.parent / path).resolve() if path else md
        if not file.exists():
            broken.append(f"{target}: no such file")
        elif anchor and file.suffix == ".md" and anchor not in _anchors(file):
            broken.append(f"{target}: no heading #{anchor} in {file.relative_to(ROOT)}")
    assert not broken, f"{md.relative_to(ROOT)}: " + "; ".join(broken)
