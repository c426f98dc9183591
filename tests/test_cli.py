"""The command line: check, fmt, version, exit statuses, atomic writes."""

import os
import random
import subprocess
import sys

import pytest

from bgr.cli import main

MESSY = "A-->extrude(3)B\nB-->NIL\n"
CLEAN = "A --> extrude(3) B\nB --> NIL\n"


def run(*args, stdin=None):
    return subprocess.run(
        [sys.executable, "-m", "bgr", *args], capture_output=True, text=True, input=stdin
    )


def test_version_and_help():
    out = run("--version")
    assert out.returncode == 0 and out.stdout.startswith("bgr ")
    out = run("--help")
    assert out.returncode == 0 and "check" in out.stdout and "fmt" in out.stdout


def test_allow_path_is_an_option_of_every_command_that_loads_a_grammar():
    for command in ("check", "derive", "render", "infer"):
        out = run(command, "--help")
        assert out.returncode == 0 and "--allow-path DIR" in out.stdout, command


def test_no_command_is_bad_usage():
    assert run().returncode == 2


def test_check_every_shipped_grammar(root):
    files = [
        str(p) for p in sorted(root.glob("examples/*.bgr")) + sorted(root.glob("stdlib/*.bgr"))
    ]
    out = run("check", *files)
    assert out.returncode == 0, out.stderr
    assert out.stdout.count(": ok") == len(files)


def test_check_reports_every_file(tmp_path, capsys):
    good, bad = tmp_path / "good.bgr", tmp_path / "bad.bgr"
    good.write_text(CLEAN)
    bad.write_text("A --> Nope\n")
    assert main(["check", str(bad), str(good)]) == 1
    captured = capsys.readouterr()
    assert "bad.bgr:1:7: error: unknown rule 'Nope'" in captured.err
    assert "good.bgr: ok" in captured.out


def test_fmt_prints_checks_and_writes(tmp_path, capsys):
    f = tmp_path / "m.bgr"
    f.write_text(MESSY)
    assert main(["fmt", str(f)]) == 0
    assert capsys.readouterr().out == CLEAN
    assert main(["fmt", "--check", str(f)]) == 1
    assert "not formatted" in capsys.readouterr().err
    os.chmod(f, 0o640)
    assert main(["fmt", "-w", str(f)]) == 0
    assert f.read_text() == CLEAN and (f.stat().st_mode & 0o777) == 0o640
    assert main(["fmt", "--check", str(f)]) == 0
    assert [p.name for p in tmp_path.iterdir()] == ["m.bgr"]  # no temporary file left behind


def test_fmt_of_a_broken_file_changes_nothing(tmp_path, capsys):
    f = tmp_path / "broken.bgr"
    f.write_text("A --> extrude(\n")
    assert main(["fmt", "-w", str(f)]) == 1
    assert f.read_text() == "A --> extrude(\n"
    assert "broken.bgr:1:" in capsys.readouterr().err


def test_fmt_reads_standard_input():
    out = run("fmt", "-", stdin=MESSY)
    assert out.returncode == 0 and out.stdout == CLEAN


def test_fmt_usage_errors(tmp_path):
    a, b = tmp_path / "a.bgr", tmp_path / "b.bgr"
    a.write_text(CLEAN)
    b.write_text(CLEAN)
    assert run("fmt", str(a), str(b)).returncode == 2
    assert run("fmt", "--check", "-w", str(a)).returncode == 2


@pytest.mark.parametrize("args", [["check", "/no/such/file.bgr"], ["fmt", "/no/such/file.bgr"]])
def test_missing_files_are_bad_input_not_tracebacks(args):
    out = run(*args)
    assert out.returncode == 1 and "no such file" in out.stderr and "Traceback" not in out.stderr


@pytest.mark.parametrize(
    "name, data, what",
    [
        ("photo.jpg", b"\xff\xd8\xff\xe0\x00\x10JFIF\x00\x01" + bytes(range(256)), "a JPEG image"),
        ("plan.png", b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR" + bytes(64), "a PNG image"),
        ("noise", random.Random(24).randbytes(4096), "a binary file"),
        ("notes.txt", b"width 12 m\n", "a '.txt' file"),
    ],
)
def test_infer_names_what_a_file_is_not_and_what_it_reads(tmp_path, name, data, what):
    """`bgr infer photo.jpg` said "'utf-8' codec can't decode byte 0xff" (issue 24)."""
    path = tmp_path / name
    path.write_bytes(data)
    out = run("infer", str(path))
    assert out.returncode == 1 and "Traceback" not in out.stderr and "codec" not in out.stderr
    first, hint = out.stderr.splitlines()
    assert first == f"{path}: error: {what}" + first.split(what, 1)[1]
    assert first.endswith(", not an input bgr infer reads")
    for kind in ("--kind schema", "--kind city", "--kind boxes", ".bgr", ".obj", ".city.json"):
        assert kind in hint
    # the same bytes as a .json, or with --kind schema or boxes: still what it is, not a codec
    if what != "a '.txt' file":
        for args in (["--kind", "schema"], ["--kind", "boxes"]):
            out = run("infer", str(path), *args)
            assert out.returncode == 1 and out.stderr.startswith(f"{path}: error: {what}")
        (tmp_path / "x.json").write_bytes(data)
        out = run("infer", str(tmp_path / "x.json"))
        assert out.returncode == 1 and f"error: {what}" in out.stderr


def test_version_answers_without_importing_the_toolkit():
    """``bgr --version`` starts in a few hundredths of a second: it imports neither the
    parser nor numpy (issue 30; it took 0.6 s when the package imported everything)."""
    import subprocess
    import sys

    code = (
        "import sys; from bgr.entry import main; main(['--version']); "
        "print(sorted(m for m in ('numpy', 'lark', 'trimesh', 'bgr.cli') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    version_line, imported = out.stdout.splitlines()
    assert version_line.startswith("bgr ")
    assert imported == "[]"
