"""Check-time errors (names, arities, duplicates, symbols, imports) and the `bgr check` command.

Each test feeds one grammar that parses but is wrong to ``bgr.load`` and checks the first
diagnostic: a meaningful message, its exact 1-based line and column, and the hint when there is
one.  Tests marked xfail(strict=True) describe the right behaviour where the implementation is
wrong.
"""

from __future__ import annotations

import re
import subprocess
import sys

import pytest
from errors_helpers import check, first_error

# (source, line, column, message substring, hint substring or None)
CASES = [
    # ---- unknown names ----------------------------------------------------------------------
    pytest.param(
        "Lot --> extrude(3) Facde\nFacade --> NIL\n",
        1,
        20,
        "unknown rule 'Facde'",
        "did you mean 'Facade'?",
        id="unknown-rule-did-you-mean",
    ),
    pytest.param(
        "Lot --> extrude(3) Zzyzx\n",
        1,
        20,
        "unknown rule 'Zzyzx'",
        "define it with 'Zzyzx --> ...' or declare it with 'terminal Zzyzx'",
        id="unknown-rule-no-close-name",
    ),
    pytest.param(
        "attr height = 3\nLot --> extrude(heigth)\n",
        2,
        17,
        "unknown name 'heigth'",
        "did you mean 'height'?",
        id="unknown-attr-did-you-mean",
    ),
    pytest.param(
        "Lot --> extrude(Height)\nattr height = 3\n",
        1,
        17,
        "unknown name 'Height'",
        "did you mean 'height'?",
        id="unknown-attr-differs-in-case",
    ),
    pytest.param("Lot --> extrude(qqqq)\n", 1, 17, "unknown name 'qqqq'", None, id="unknown-name"),
    pytest.param(
        "A --> extrude(scope.sw)\n",
        1,
        15,
        "unknown name 'scope.sw'",
        "did you mean 'scope.s",
        id="unknown-scope-member",
    ),
    pytest.param(
        "A --> extrude(B)\nB --> NIL\n",
        1,
        15,
        "'B' is a rule, not a value",
        "handed whole to a rule parameter",
        id="rule-used-as-value",
    ),
    pytest.param(
        "func storeys(h) = h / 3\nLot --> extrude(storys(9))\n",
        2,
        17,
        "unknown function 'storys'",
        "did you mean 'storeys'?",
        id="unknown-function",
    ),
    pytest.param(
        "A --> extrude(extrude(1))\n",
        1,
        15,
        "'extrude' is an operation, not a function",
        None,
        id="operation-used-as-function",
    ),
    # ---- argument counts --------------------------------------------------------------------
    pytest.param(
        "Lot --> Floor(1, 2)\nFloor(i) --> NIL\n",
        1,
        9,
        "rule 'Floor' takes 1 argument, given 2",
        "it is declared as Floor(i)",
        id="rule-too-many-args",
    ),
    pytest.param(
        "Lot --> Floor\nFloor(i) --> NIL\n",
        1,
        9,
        "rule 'Floor' takes 1 argument, given 0",
        "Floor(i)",
        id="rule-missing-args",
    ),
    pytest.param(
        "terminal Wall\nA --> Wall(1)\n",
        2,
        7,
        "terminal 'Wall' takes no arguments",
        None,
        id="terminal-with-args",
    ),
    pytest.param(
        "func f(a, b) = a + b\nLot --> extrude(f(1))\n",
        2,
        17,
        "function 'f' takes 2 arguments, given 1",
        "it is declared as f(a, b)",
        id="func-wrong-arg-count",
    ),
    pytest.param(
        "Lot --> extrude(world.up, 1, 2)\n",
        1,
        9,
        "'extrude' takes 1 or 2 arguments, given 3",
        "write extrude(height) or extrude(direction, height)",
        id="operation-too-many-args",
    ),
    pytest.param(
        "Lot --> t(1, 2)\n",
        1,
        9,
        "'t' takes 3 arguments, given 2",
        "write t(x, y, z)",
        id="operation-too-few-args",
    ),
    pytest.param(
        "A --> t()\n",
        1,
        7,
        "'t' takes 3 arguments, given 0",
        "t(x, y, z)",
        id="operation-empty-parens",
    ),
    pytest.param(
        "Lot --> extrude(floor(1, 2))\n",
        1,
        17,
        "'floor' takes 1 argument",
        None,
        id="builtin-too-many-args",
    ),
    pytest.param(
        "Lot --> extrude(clamp(1))\n",
        1,
        17,
        "'clamp' takes 3 arguments, given 1",
        "clamp(x, lo, hi)",
        id="builtin-too-few-args",
    ),
    pytest.param(
        "A --> comp(f) { face(1, 2): B }\nB --> NIL\n",
        1,
        17,
        "face() takes one argument",
        None,
        id="face-selector-wrong-args",
    ),
    # ---- duplicates -------------------------------------------------------------------------
    pytest.param(
        "A --> NIL\nB --> NIL\nA --> B\n",
        3,
        1,
        "duplicate rule 'A'",
        "'A' is already defined on line 1",
        id="duplicate-rule",
    ),
    pytest.param(
        "terminal A\nA --> NIL\n",
        2,
        1,
        "duplicate rule 'A'",
        "line 1",
        id="rule-duplicates-terminal",
    ),
    pytest.param(
        "attr h = 1\nattr h = 2\nA --> NIL\n",
        2,
        6,
        "duplicate attr or const 'h'",
        "'h' is already defined on line 1",
        id="duplicate-attr",
    ),
    pytest.param(
        "attr h = 1\nconst h = 2\nA --> NIL\n",
        2,
        7,
        "duplicate attr or const 'h'",
        "line 1",
        id="const-duplicates-attr",
    ),
    pytest.param(
        "func f(x) = x\nfunc f(y) = y\nA --> NIL\n",
        2,
        6,
        "duplicate func 'f'",
        "'f' is already defined on line 1",
        id="duplicate-func",
    ),
    pytest.param(
        'asset col = "a.glb"\nasset col = "b.glb"\nA --> NIL\n',
        2,
        7,
        "duplicate asset 'col'",
        "'col' is already defined on line 1",
        id="duplicate-asset",
    ),
    pytest.param(
        "import stdlib.palette as p\nimport stdlib.palette as p\nA --> NIL\n",
        2,
        26,
        "duplicate import alias 'p'",
        "line 1",
        id="duplicate-alias",
    ),
    pytest.param(
        "import stdlib.palette as scope\nA --> NIL\n",
        1,
        26,
        "'scope' is reserved and cannot be an import alias",
        None,
        id="reserved-alias",
    ),
    pytest.param(
        "A(x, x) --> NIL\n", 1, 6, "parameter 'x' appears twice", None, id="duplicate-parameter"
    ),
    pytest.param(
        "version 1\nversion 1\nA --> NIL\n",
        2,
        9,
        "more than one 'version'",
        None,
        id="two-versions",
    ),
    pytest.param(
        "start A\nstart A\nA --> NIL\n", 2, 7, "more than one 'start'", None, id="two-starts"
    ),
    # ---- operations -------------------------------------------------------------------------
    pytest.param(
        "Lot --> extrud(3)\n", 1, 9, "'extrud'", "did you mean 'extrude'?", id="unknown-operation"
    ),
    pytest.param(
        "Lot --> extrude\n",
        1,
        9,
        "operation 'extrude' needs its arguments",
        "write extrude(height)",
        id="operation-without-args",
    ),
    pytest.param(
        "Lot --> split\n",
        1,
        9,
        "operation 'split' needs its arguments",
        "split(axis, adjustment)",
        id="split-without-args",
    ),
    pytest.param(
        "A --> split(x)\n",
        1,
        7,
        "'split' needs a { ... } block",
        "for example: split(x) {",
        id="split-without-block",
    ),
    pytest.param(
        "A --> extrude(1) { 1: B }\nB --> NIL\n",
        1,
        18,
        "'extrude' takes no { } block",
        None,
        id="block-on-blockless-operation",
    ),
    pytest.param(
        "extrude --> NIL\n",
        1,
        1,
        "'extrude' is an operation and cannot name a rule",
        "choose another name",
        id="rule-named-like-operation",
    ),
    pytest.param(
        "A --> NIL\nsplit(x) --> NIL\n",
        2,
        1,
        "'split' is an operation and cannot name a rule",
        "choose another name",
        id="rule-with-params-named-like-operation",
    ),
    # ---- percentages ------------------------------------------------------------------------
    pytest.param(
        "A --> 60%: B | 50%: C\nB --> NIL\nC --> NIL\n",
        1,
        16,
        "the percentages add up to 110%, over 100%",
        "'else' takes what is left",
        id="percentages-over-100",
    ),
    pytest.param(
        "A --> 50%: B | 50%: C | 10%: D | else: NIL\nB --> NIL\nC --> NIL\nD --> NIL\n",
        1,
        25,
        "add up to 110%",
        None,
        id="percentages-over-100-at-third-choice",
    ),
    pytest.param(
        "A --> (-10)%: B | else: C\nB --> NIL\nC --> NIL\n",
        1,
        8,
        "a probability cannot be negative",
        None,
        id="negative-percentage",
    ),
    pytest.param(
        "A --> -10%: B | else: C\nB --> NIL\nC --> NIL\n",
        1,
        7,
        "a probability cannot be negative",
        None,
        id="negative-percent-literal",
    ),
    # ---- declarations -----------------------------------------------------------------------
    pytest.param(
        "version 2\nA --> NIL\n",
        1,
        9,
        "unknown language version 2",
        "this bgr reads version 1",
        id="unknown-version",
    ),
    pytest.param(
        "start Lott\nLot --> NIL\n",
        1,
        7,
        "start rule 'Lott' is not defined",
        "did you mean 'Lot'?",
        id="start-names-missing-rule",
    ),
    pytest.param(
        "attr a = b + 1\nattr b = a\nA --> NIL\n",
        1,
        6,
        "attrs and consts define each other in a cycle: a -> b -> a",
        None,
        id="attr-cycle",
    ),
    pytest.param(
        "attr a = a\nA --> NIL\n", 1, 6, "cycle: a -> a", None, id="attr-defined-by-itself"
    ),
    pytest.param(
        "attr w = scope.sx\nA --> NIL\n",
        1,
        10,
        "'scope.sx' is only known while deriving a shape",
        "use it in a rule or a func",
        id="scope-in-attr",
    ),
    # ---- bare-word arguments ----------------------------------------------------------------
    pytest.param(
        "A --> split(w) { 1: B }\nB --> NIL\n",
        1,
        13,
        "unknown axis 'w'",
        "x, y, z",
        id="unknown-axis",
    ),
    pytest.param(
        "A --> center(xw)\n", 1, 14, "'xw' is not a set of axes", "center(xz)", id="bad-axes"
    ),
    pytest.param(
        "A --> roof(hipp, 30)\n",
        1,
        12,
        "unknown roof kind 'hipp'",
        "did you mean 'hip'?",
        id="unknown-roof-kind",
    ),
    pytest.param(
        "A --> i(cub)\n",
        1,
        9,
        "unknown primitive or asset 'cub'",
        "did you mean 'cube'?",
        id="unknown-primitive",
    ),
    pytest.param(
        'asset col = "c.glb"\nA --> i(colm)\n',
        2,
        9,
        "unknown primitive or asset 'colm'",
        "did you mean 'col'?",
        id="unknown-asset",
    ),
    pytest.param(
        "A --> comp(f) { fron: B }\nB --> NIL\n",
        1,
        17,
        "unknown comp selector 'fron'",
        "did you mean 'front'?",
        id="unknown-comp-selector",
    ),
    pytest.param(
        "A --> offset(1) { insde: B }\nB --> NIL\n",
        1,
        19,
        "unknown offset selector 'insde'",
        "did you mean 'inside'?",
        id="unknown-offset-selector",
    ),
    # ---- argument types ---------------------------------------------------------------------
    pytest.param(
        'A --> color("#12345")\n',
        1,
        13,
        "'#12345' is not a colour",
        '"#rrggbb"',
        id="colour-five-digits",
    ),
    pytest.param(
        'A --> color("red")\n',
        1,
        13,
        "'red' is not a colour",
        "six hexadecimal digits",
        id="colour-by-name",
    ),
    pytest.param(
        "A --> color(3)\n",
        1,
        13,
        'a single colour argument is a "#rrggbb" string',
        "color(r, g, b)",
        id="colour-one-number",
    ),
    pytest.param(
        "A --> material(3)\n",
        1,
        16,
        "the name of 'material' must be a string",
        'material("brick")',
        id="material-number",
    ),
    pytest.param(
        'A --> extrude("3")\n',
        1,
        15,
        "the height of 'extrude' must be a number",
        None,
        id="extrude-string",
    ),
    pytest.param(
        'A --> split(x) { "a": B }\nB --> NIL\n',
        1,
        18,
        "a split size must be a number",
        None,
        id="split-size-string",
    ),
    # ---- relative sizes and repeat stars in the wrong place ---------------------------------
    pytest.param(
        "A --> extrude('0.5)\n",
        1,
        15,
        "a relative size ('f) is not allowed as the height of 'extrude'",
        "relative sizes go in s(), t(), split sizes, setupProjection() and tileUV()",
        id="relative-size-in-extrude",
    ),
    # ~w parses as an argument since textures (issue 26); only texture sizes take it
    pytest.param(
        "A --> extrude(~2)\n",
        1,
        15,
        "a floating size (~w) is not allowed as the height of 'extrude'",
        "floating sizes go in split sizes, setupProjection() and tileUV()",
        id="floating-size-in-extrude",
    ),
    pytest.param(
        "A --> t(~1, 0, 0)\n",
        1,
        9,
        "a floating size (~w) is not allowed as the x of 't'",
        "floating sizes go in split sizes, setupProjection() and tileUV()",
        id="floating-size-in-t",
    ),
    pytest.param(
        "A --> B('0.5)\nB(x) --> NIL\n",
        1,
        9,
        "a relative size ('f) is not allowed here",
        "relative sizes go in",
        id="relative-size-in-successor-args",
    ),
    pytest.param(
        "A --> comp(f) { '0.5: B }\nB --> NIL\n",
        1,
        17,
        "'comp' selectors have no size prefix",
        "front: A",
        id="size-prefix-on-comp-selector",
    ),
    pytest.param(
        "A --> comp(f) { top: B }*\nB --> NIL\n",
        1,
        25,
        "only split blocks repeat",
        None,
        id="comp-block-with-star",
    ),
    pytest.param(
        "A --> comp(f) { { top: B }* }\nB --> NIL\n",
        1,
        17,
        "repeat groups { ... }* belong in split blocks, not in 'comp'",
        None,
        id="repeat-group-in-comp",
    ),
    # ---- imported names ---------------------------------------------------------------------
    pytest.param(
        "A --> win.Window\n",
        1,
        7,
        "unknown module 'win'",
        "import it first",
        id="dotted-successor-unknown-alias",
    ),
    pytest.param(
        "A --> extrude(pal.brick)\n",
        1,
        15,
        "unknown module 'pal'",
        "import",
        id="dotted-name-unknown-alias",
    ),
    pytest.param(
        "import stdlib.palette as pal\nA --> color(pl.brick)\n",
        2,
        13,
        "unknown module 'pl'",
        "did you mean 'pal'?",
        id="dotted-name-misspelt-alias",
    ),
    pytest.param(
        "import stdlib.palette as pal\nA --> color(pal.brik)\n",
        2,
        13,
        "module 'pal' has no attr or const 'brik'",
        "did you mean 'brick'?",
        id="module-has-no-const",
    ),
    pytest.param(
        "import stdlib.palette as pal\nA --> pal.Brick\n",
        2,
        7,
        "module 'pal' has no rule 'Brick'",
        None,
        id="module-has-no-rule",
    ),
    pytest.param(
        "import stdlib.pallete as p\nA --> NIL\n",
        1,
        8,
        "there is no stdlib module 'pallete'",
        "did you mean 'palette'?",
        id="stdlib-module-misspelt",
    ),
    pytest.param(
        "import stdlib.zzzz as p\nA --> NIL\n",
        1,
        8,
        "there is no stdlib module 'zzzz'",
        "palette",
        id="stdlib-module-unknown",
    ),
    pytest.param(
        "import foo.bar as x\nA --> NIL\n",
        1,
        8,
        "cannot import 'foo.bar' by name",
        'import "foo/bar.bgr" as x',
        id="import-dotted-non-stdlib",
    ),
]


@pytest.mark.parametrize("src, line, column, message, hint", CASES)
def test_check_error(src, line, column, message, hint):
    err = check(src, line, column, message, hint)
    assert "Traceback" not in err.render()


# ---- several errors at once -----------------------------------------------------------------


def test_checker_reports_every_error_in_line_order():
    src = (
        "attr h = 3\n"
        "A --> extrude(hh) B\n"  # unknown name 'hh', unknown rule 'B'
        "C --> extrud(1)\n"  # unknown operation
        "D --> i(cub)\n"  # unknown primitive
        "attr h = 4\n"
    )  # duplicate attr
    err = first_error(src)
    where = [(d.line, d.column) for d in err.diagnostics]
    assert where == [(2, 15), (2, 19), (3, 7), (4, 9), (5, 6)]
    messages = [d.message for d in err.diagnostics]
    assert "unknown name 'hh'" in messages[0]
    assert "unknown rule 'B'" in messages[1]
    assert "'extrud'" in messages[2]
    assert "'cub'" in messages[3]
    assert "duplicate attr or const 'h'" in messages[4]
    assert (err.line, err.column, err.message) == (2, 15, messages[0])
    assert err.render().endswith("5 errors")


def test_errors_in_declarations_and_rules_are_all_reported():
    src = "version 3\nfunc f(a) = a + zz\nLot --> roof(hipp) Mass(1)\nMass --> NIL\n"
    err = first_error(src)
    assert [(d.line, d.column) for d in err.diagnostics] == [(1, 9), (2, 17), (3, 14), (3, 20)]


# ---- imports (real files) -------------------------------------------------------------------


def test_import_missing_file(tmp_path):
    main = tmp_path / "main.bgr"
    main.write_text('import "lib/windows.bgr" as win\nA --> NIL\n')
    err = check(main, 1, 8, "cannot find the imported file 'lib/windows.bgr'", "looked for")
    assert err.path == str(main)
    assert str(tmp_path / "lib" / "windows.bgr") in err.hint


def test_import_cycle_between_two_files(tmp_path):
    (tmp_path / "a.bgr").write_text('import "b.bgr" as b\nA --> b.B\n')
    (tmp_path / "b.bgr").write_text('# b imports a back\nimport "a.bgr" as a\nB --> NIL\n')
    err = first_error(tmp_path / "a.bgr")
    assert "import cycle" in err.message
    assert "a.bgr -> b.bgr -> a.bgr" in err.message
    assert err.hint and "cannot import itself" in err.hint
    assert (err.line, err.column) == (2, 8)  # the import that closes the cycle, in b.bgr
    assert err.path.endswith("b.bgr")


def test_module_importing_itself(tmp_path):
    path = tmp_path / "self.bgr"
    path.write_text('A --> NIL\nimport "self.bgr" as me\n')
    err = check(path, 2, 8, "import cycle: self.bgr -> self.bgr", "cannot import itself")
    assert err.path == str(path)


def test_error_inside_imported_file_names_that_file(tmp_path):
    (tmp_path / "main.bgr").write_text('import "lib.bgr" as lib\nA --> lib.Window\n')
    (tmp_path / "lib.bgr").write_text("# windows\nWindow --> extrude(hieght)\nattr height = 2\n")
    err = check(tmp_path / "main.bgr", 2, 20, "unknown name 'hieght'", "did you mean 'height'?")
    assert err.path.endswith("lib.bgr") and not err.path.endswith("main.bgr")
    assert err.render().startswith(f"{err.path}:2:20: error: ")
    assert "Window --> extrude(hieght)" in err.render()


def test_syntax_error_inside_imported_file_names_that_file(tmp_path):
    (tmp_path / "main.bgr").write_text('import "sub/lib.bgr" as lib\nA --> lib.Window\n')
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "lib.bgr").write_text("Window --> extrude(3\n")
    err = check(tmp_path / "main.bgr", 1, 21, "unexpected end of file", "not closed")
    assert err.path.replace("\\", "/").endswith("sub/lib.bgr")


def test_missing_rule_of_imported_file(tmp_path):
    (tmp_path / "main.bgr").write_text('import "lib.bgr" as lib\nA --> lib.Windw\n')
    (tmp_path / "lib.bgr").write_text("Window --> NIL\n")
    err = check(
        tmp_path / "main.bgr", 2, 7, "module 'lib' has no rule 'Windw'", "did you mean 'Window'?"
    )
    assert err.path == str(tmp_path / "main.bgr")


def test_load_of_missing_path():
    err = first_error("/nonexistent/dir/house.bgr")
    assert "no such file" in err.message
    assert err.path == "/nonexistent/dir/house.bgr"


# ---- the `bgr check` command ----------------------------------------------------------------


def run_bgr(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "bgr", *args], capture_output=True, text=True, cwd=cwd, timeout=60
    )


def test_acceptance_check_reports_misspelt_rule(tmp_path):
    path = tmp_path / "house.bgr"
    line2 = "Lot --> extrude(10) Facde"
    path.write_text("# a house\n" + line2 + '\nFacade --> color("#c8b89a")\n')
    col = line2.index("Facde") + 1  # 21

    proc = run_bgr("check", str(path))

    assert proc.returncode == 1
    assert "Traceback" not in proc.stderr and "Traceback" not in proc.stdout
    lines = proc.stderr.splitlines()
    head = [
        i
        for i, text in enumerate(lines)
        if re.match(rf"^{re.escape(str(path))}:2:{col}: error: .*'Facde'", text)
    ]
    assert head, proc.stderr
    i = head[0]
    source, caret = lines[i + 1], lines[i + 2]
    assert source.endswith(line2)
    assert caret.index("^") == source.index("Facde")  # the caret is under the 'F' of 'Facde'
    assert any("did you mean 'Facade'?" in text for text in lines[i + 3 :])


def test_check_clean_file_exits_0(tmp_path):
    path = tmp_path / "ok.bgr"
    path.write_text(
        "attr height = 12\nLot --> extrude(height) comp(f) { top: Roof | side: Wall }\n"
        "terminal Roof, Wall\n"
    )
    proc = run_bgr("check", str(path))
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr == ""
    assert f"{path}: ok" in proc.stdout


def test_check_without_file_is_a_usage_error():
    proc = run_bgr("check")
    assert proc.returncode == 2
    assert "usage:" in proc.stderr and "Traceback" not in proc.stderr


def test_unknown_subcommand_is_a_usage_error():
    proc = run_bgr("frobnicate", "x.bgr")
    assert proc.returncode == 2
    assert "frobnicate" in proc.stderr and "Traceback" not in proc.stderr


def test_no_subcommand_is_a_usage_error():
    proc = run_bgr()
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr


def test_check_missing_file_exits_1(tmp_path):
    missing = tmp_path / "nope.bgr"
    proc = run_bgr("check", str(missing))
    assert proc.returncode == 1
    assert f"{missing}: error: no such file" in proc.stderr
    assert "Traceback" not in proc.stderr


def test_check_syntax_error_exits_1_with_position(tmp_path):
    path = tmp_path / "bad.bgr"
    path.write_text("A --> NIL\nB --> split(x) { 1: C\n")
    proc = run_bgr("check", str(path))
    assert proc.returncode == 1
    assert proc.stderr.startswith(f"{path}:2:22: error: unexpected end of file")
    assert "Traceback" not in proc.stderr


@pytest.mark.parametrize(
    "data, where, message",
    [
        (b"A --> B\x00\n", ":1:8:", "NUL character"),
        (b"A --> NIL\n# caf\xe9\n", ":2:6:", "not UTF-8"),
    ],
    ids=["nul", "latin-1"],
)
def test_check_binary_file_exits_1(tmp_path, data, where, message):
    path = tmp_path / "binary.bgr"
    path.write_bytes(data)
    proc = run_bgr("check", str(path))
    assert proc.returncode == 1
    assert proc.stderr.startswith(f"{path}{where} error: ")
    assert message in proc.stderr.splitlines()[0]
    assert "Traceback" not in proc.stderr


def test_check_several_files_reports_each(tmp_path):
    good, bad = tmp_path / "good.bgr", tmp_path / "bad.bgr"
    good.write_text("A --> NIL\n")
    bad.write_text("A --> Bb\nB --> NIL\n")
    proc = run_bgr("check", str(bad), str(good))
    assert proc.returncode == 1
    assert f"{bad}:1:7: error: unknown rule 'Bb'" in proc.stderr
    assert f"{good}: ok" in proc.stdout
