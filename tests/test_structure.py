"""The package's shape stays walkable: no module over 650 lines, no import circle.

The import graph is built from the source with the standard library's ``ast``: every
``import`` and ``from ... import`` of one of the package's own modules is an edge, wherever it
stands (an import inside a function is still a dependency, and a circle hidden that way is still
a circle).  Only imports under ``if TYPE_CHECKING:`` are left out: they name a type for the
checker and are never run.  The folders map onto the one import namespace ``bgr`` as
pyproject.toml's ``package-dir`` says.
"""

from __future__ import annotations

import ast
import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MAX_LINES = 650


def package_files() -> dict[str, Path]:
    """Every module of the package by its dotted name (``bgr.grammar.parser``)."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())
    folders = config["tool"]["setuptools"]["package-dir"]
    modules: dict[str, Path] = {}
    for package, folder in folders.items():
        for path in sorted((ROOT / folder).rglob("*.py")):
            parts = list(path.relative_to(ROOT / folder).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            modules[".".join([package, *parts])] = path
    return modules


def imports_of(name: str, path: Path, modules: dict[str, Path]) -> set[str]:
    """The package's modules that module ``name`` imports (anywhere in its body)."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found: set[str] = set()
    for node in _run_time_nodes(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - (node.level - 1)]
                prefix = ".".join(base + ([node.module] if node.module else []))
            else:
                prefix = node.module or ""
            # `from x import y` imports the module x.y when there is one, else names from x
            targets = [
                f"{prefix}.{alias.name}" if f"{prefix}.{alias.name}" in modules else prefix
                for alias in node.names
            ]
        else:
            continue
        for target in targets:
            while target and target not in modules:
                target = target.rpartition(".")[0]
            if target and target != name:
                found.add(target)
    return found


def _run_time_nodes(tree: ast.AST):
    """Every node of ``tree`` except what stands under ``if TYPE_CHECKING:``."""
    for node in ast.iter_child_nodes(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for child in node.orelse:
                yield child
                yield from _run_time_nodes(child)
            continue
        yield node
        yield from _run_time_nodes(node)


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One import circle in ``graph`` as the list of its modules, or None (depth-first)."""
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    path: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        path.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                return path[path.index(nxt) :] + [nxt]
            if nxt not in state and (cycle := visit(nxt)):
                return cycle
        path.pop()
        state[node] = 2
        return None

    for node in sorted(graph):
        if node not in state and (cycle := visit(node)):
            return cycle
    return None


def test_no_module_is_over_650_lines():
    long = {
        str(path.relative_to(ROOT)): lines
        for path in package_files().values()
        if (lines := len(path.read_text().splitlines())) > MAX_LINES
    }
    assert not long, f"split these by concern (at most {MAX_LINES} lines): {long}"


def test_no_import_circle_among_the_packages_modules():
    modules = package_files()
    graph = {name: imports_of(name, path, modules) for name, path in modules.items()}
    cycle = find_cycle(graph)
    assert cycle is None, "import circle: " + " -> ".join(cycle or [])


def test_the_cycle_finder_finds_a_circle_and_passes_a_tree():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b", "c"}, "b": {"c"}, "c": set()}) is None


def test_the_readme_layout_names_what_is_there():
    """Each row of README.md's Layout table names a folder that exists, and every file it names
    (``x.py``, ``x.lark``) is in that folder; every package folder has a row."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    table = text[text.index("| folder | what it holds |") :].split("\n\n")[0]
    rows = [line for line in table.splitlines()[2:] if line.startswith("| `")]
    folders = set()
    for row in rows:
        first, rest = row.split("|")[1], "|".join(row.split("|")[2:])
        for folder in re.findall(r"`([\w/]+)/`", first):
            folders.add(folder)
            assert (ROOT / folder).is_dir(), f"README layout: no folder {folder}/"
            for name in re.findall(r"`([\w/]+\.(?:py|lark))`", rest):
                found = list((ROOT / folder).rglob(Path(name).name))
                assert found, f"README layout: {folder}/ holds no {name}"
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())
    packages = set(config["tool"]["setuptools"]["package-dir"].values())
    assert packages <= folders, f"README layout misses {sorted(packages - folders)}"
