"""bgr.load: paths, text, bytes, imports and the checked Grammar it returns."""

from pathlib import Path

import pytest

import bgr


def test_load_a_path_text_or_bytes(tmp_path):
    f = tmp_path / "a.bgr"
    f.write_text("Lot --> extrude(3) Mass\nterminal Mass\n")
    for source in (f, str(f), f.read_text(), f.read_bytes()):
        g = bgr.load(source)
        assert g.start == "Lot" and set(g.rules) == {"Lot"} and set(g.terminals) == {"Mass"}


def test_grammar_exposes_its_declarations():
    g = bgr.load(
        'version 1\nattr h = 3\nconst c = 2\nfunc f(x) = x * c\nasset col = "c.glb"\n'
        "start B\nA --> NIL\nB --> A\n"
    )
    assert (g.version, g.start) == (1, "B")
    assert (
        set(g.attrs) == {"h"}
        and set(g.consts) == {"c"}
        and set(g.funcs) == {"f"}
        and set(g.assets) == {"col"}
    )


def test_without_start_the_first_rule_is_the_axiom():
    assert bgr.load("First --> Second\nSecond --> NIL\n").start == "First"


def test_relative_imports_resolve_from_the_importing_file(tmp_path):
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib" / "win.bgr").write_text(
        'import "../parts.bgr" as parts\nWindow --> parts.Glass\n'
    )
    (tmp_path / "parts.bgr").write_text("attr inset = 0.2\nGlass --> t(0, 0, -inset) NIL\n")
    main = tmp_path / "main.bgr"
    main.write_text('import "lib/win.bgr" as win\nLot --> split(x) { ~2: win.Window }*\n')
    g = bgr.load(main)
    assert set(g.imports) == {"win"}
    assert set(g.imports["win"].imports["parts"].rules) == {"Glass"}


def test_a_module_imported_twice_is_loaded_once(tmp_path):
    (tmp_path / "common.bgr").write_text("C --> NIL\n")
    (tmp_path / "a.bgr").write_text('import "common.bgr" as c\nA --> c.C\n')
    (tmp_path / "b.bgr").write_text('import "common.bgr" as c\nB --> c.C\n')
    (tmp_path / "main.bgr").write_text('import "a.bgr" as a\nimport "b.bgr" as b\nM --> a.A b.B\n')
    g = bgr.load(tmp_path / "main.bgr")
    assert g.imports["a"].imports["c"] is g.imports["b"].imports["c"]


def test_stdlib_modules_import_by_name():
    g = bgr.load("import stdlib.palette as pal\nLot --> color(pal.brick)\n")
    assert "brick" in g.imports["pal"].consts


def test_text_imports_resolve_from_the_given_path(tmp_path):
    (tmp_path / "lib.bgr").write_text("W --> NIL\n")
    g = bgr.load('import "lib.bgr" as lib\nA --> lib.W\n', path=str(tmp_path / "virtual.bgr"))
    assert "lib" in g.imports


def test_every_error_is_reported_not_only_the_first():
    with pytest.raises(bgr.BgrError) as e:
        bgr.load("A --> B1\nB --> C1\nC --> extrude(world.up, 1, 2)\n")
    assert [(d.line, d.column) for d in e.value.diagnostics] == [(1, 7), (2, 7), (3, 7)]
    assert (e.value.line, e.value.column) == (1, 7)


def test_missing_file_is_a_bgr_error(tmp_path):
    with pytest.raises(bgr.BgrError, match="no such file"):
        bgr.load(tmp_path / "nope.bgr")


def test_installed_namespace_is_bgr_only():
    """Nothing generic such as a top-level `grammar` module lands in site-packages."""
    import importlib.util

    assert importlib.util.find_spec("bgr.grammar") is not None
    spec = importlib.util.find_spec("grammar")
    assert spec is None or Path(spec.origin or "").parent.parent == Path(bgr.__file__).parent.parent
