"""Files outside a grammar's reach: the import/asset root, regular files only in and out, SIGTERM
and killed runs leave no temporaries (grammar/paths.py, formats/atomic.py)."""

import os
import signal
import subprocess
import sys
import time

import pytest

import bgr
from bgr.formats.atomic import is_stale, write_text

SECRET = "TOP-SECRET-4242"
needs_fifo = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this system")


def run(*args, cwd=None, timeout=60):
    return subprocess.run(
        [sys.executable, "-m", "bgr", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=timeout,
    )


def dead_pid() -> int:
    """The PID of a process that has exited (and been reaped)."""
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


@pytest.fixture
def layout(tmp_path):
    """tmp/outside/secret.bgr (a secret in a comment and a syntax error) and tmp/proj/."""
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "secret.bgr").write_text(f"# {SECRET}\n{SECRET} -->\n")
    (outside / "lib.bgr").write_text("Part --> NIL\n")
    proj = tmp_path / "proj"
    proj.mkdir()
    return proj, outside


# --- the root: imports ----------------------------------------------------------------------


def test_proc_import_is_refused_without_its_content(tmp_path, monkeypatch):
    monkeypatch.setenv("BGR_TEST_SECRET", SECRET)
    main_bgr = tmp_path / "main.bgr"
    main_bgr.write_text('import "/proc/self/environ" as e\nLot --> NIL\n')
    out = run("check", str(main_bgr))
    assert out.returncode == 1
    assert SECRET not in out.stderr + out.stdout
    assert f"{main_bgr}:1:8: error: cannot import '/proc/self/environ'" in out.stderr
    assert "outside the folders" in out.stderr and "--allow-path" in out.stderr


def test_proc_import_is_refused_even_when_allowed(tmp_path):
    main_bgr = tmp_path / "main.bgr"
    main_bgr.write_text('import "/proc/self/environ" as e\nLot --> NIL\n')
    with pytest.raises(bgr.BgrError) as info:
        bgr.load(main_bgr, allow_paths=["/proc"])
    assert "only .bgr files can be imported" in info.value.render()


def test_parent_import_outside_the_root_is_refused_unread(layout):
    proj, outside = layout
    (proj / "main.bgr").write_text('import "../outside/secret.bgr" as s\nLot --> NIL\n')
    out = run("check", "main.bgr", cwd=proj)
    assert out.returncode == 1
    assert SECRET not in out.stderr
    assert "main.bgr:1:8: error: cannot import '../outside/secret.bgr'" in out.stderr
    assert "hint: widen the allowed folders with --allow-path DIR" in out.stderr


def test_non_bgr_import_is_refused_before_it_is_read(tmp_path):
    (tmp_path / "notes.txt").write_text(f"{SECRET} -->\n")
    (tmp_path / "main.bgr").write_text('import "notes.txt" as n\nLot --> NIL\n')
    with pytest.raises(bgr.BgrError) as info:
        bgr.load(tmp_path / "main.bgr")
    text = info.value.render()
    assert "only .bgr files can be imported" in text and SECRET not in text


def test_a_grammar_argument_that_is_not_bgr_is_never_quoted(tmp_path):
    (tmp_path / "passwd").write_text(f"root:{SECRET}:0:0\n")
    for command in ("check", "fmt", "derive"):
        extra = ["-o", str(tmp_path / "x.glb")] if command == "derive" else []
        out = run(command, str(tmp_path / "passwd"), *extra)
        assert out.returncode == 1, command
        assert SECRET not in out.stderr + out.stdout
        assert "not a .bgr file" in out.stderr


def test_allow_path_widens_the_root(layout):
    proj, outside = layout
    (proj / "main.bgr").write_text('import "../outside/lib.bgr" as lib\nLot --> lib.Part\n')
    assert run("check", "main.bgr", cwd=proj).returncode == 1
    out = run("check", "--allow-path", str(outside), "main.bgr", cwd=proj)
    assert out.returncode == 0, out.stderr
    out = run("derive", "main.bgr", "-o", "x.json", "--allow-path", "../outside", cwd=proj)
    assert out.returncode == 0, out.stderr
    assert "Part" in bgr.load(proj / "main.bgr", allow_paths=[outside]).imports["lib"].rules


def test_subfolders_and_stdlib_stay_reachable(tmp_path):
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib" / "a.bgr").write_text('import "../b.bgr" as b\nA --> b.B\n')
    (tmp_path / "b.bgr").write_text("import stdlib.palette as pal\nB --> color(pal.brick)\n")
    (tmp_path / "main.bgr").write_text('import "lib/a.bgr" as a\nLot --> a.A\n')
    assert set(bgr.load(tmp_path / "main.bgr").imports) == {"a"}
    assert "pal" in bgr.load("import stdlib.palette as pal\nLot --> NIL\n").imports


def test_text_has_the_working_folder_as_root(layout, monkeypatch):
    proj, outside = layout
    (proj / "near.bgr").write_text("Near --> NIL\n")
    monkeypatch.chdir(proj)
    assert "n" in bgr.load('import "near.bgr" as n\nLot --> n.Near\n').imports
    with pytest.raises(bgr.BgrError, match="outside the folders"):
        bgr.load('import "../outside/lib.bgr" as l\nLot --> l.Part\n')


def test_symlink_escape_is_refused(layout):
    proj, outside = layout
    try:
        (proj / "link.bgr").symlink_to(outside / "secret.bgr")
        (proj / "dir").symlink_to(outside, target_is_directory=True)
    except OSError:
        pytest.skip("cannot make symlinks here")
    for target in ("link.bgr", "dir/secret.bgr"):
        (proj / "main.bgr").write_text(f'import "{target}" as s\nLot --> NIL\n')
        with pytest.raises(bgr.BgrError) as info:
            bgr.load(proj / "main.bgr")
        assert "outside the folders" in info.value.render()
        assert SECRET not in info.value.render()


def test_asset_outside_the_root_is_refused(layout):
    proj, outside = layout
    (outside / "box.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    (proj / "main.bgr").write_text('asset box = "../outside/box.obj"\nLot --> i(box)\n')
    with pytest.raises(bgr.BgrError) as info:
        bgr.derive(proj / "main.bgr")
    assert info.value.line == 1 and "outside the folders" in info.value.message
    assert len(bgr.derive(proj / "main.bgr", allow_paths=[outside])) == 1
    out = run("derive", "main.bgr", "-o", "x.json", cwd=proj)
    assert out.returncode == 1 and "outside the folders" in out.stderr


# --- special files as inputs ----------------------------------------------------------------


@needs_fifo
def test_check_and_fmt_on_a_fifo_return_promptly(tmp_path):
    fifo = tmp_path / "pipe.bgr"
    os.mkfifo(fifo)
    for command in ("check", "fmt"):
        out = run(command, str(fifo), timeout=20)
        assert out.returncode == 1, command
        assert "FIFO" in out.stderr and "regular file" in out.stderr
        assert "Traceback" not in out.stderr


@needs_fifo
def test_fifo_import_asset_and_lot_are_refused(tmp_path):
    os.mkfifo(tmp_path / "pipe.bgr")
    os.mkfifo(tmp_path / "pipe.obj")
    os.mkfifo(tmp_path / "lots.geojson")
    (tmp_path / "a.bgr").write_text('import "pipe.bgr" as p\nLot --> NIL\n')
    with pytest.raises(bgr.BgrError, match="FIFO"):
        bgr.load(tmp_path / "a.bgr")
    (tmp_path / "b.bgr").write_text('asset x = "pipe.obj"\nLot --> i(x)\n')
    with pytest.raises(bgr.BgrError, match="FIFO") as info:
        bgr.derive(tmp_path / "b.bgr")
    assert info.value.line == 1
    with pytest.raises(bgr.BgrError, match="FIFO"):
        bgr.derive("Lot --> NIL\n", lot=str(tmp_path / "lots.geojson"))


def test_device_and_proc_inputs_are_refused(tmp_path):
    with pytest.raises(bgr.BgrError, match="/proc, /sys or /dev"):
        bgr.derive("Lot --> NIL\n", lot="/dev/null")
    from bgr.render.camera import Camera

    with pytest.raises(bgr.BgrError, match="/proc, /sys or /dev"):
        Camera.from_json("/proc/self/status")


# --- special files as outputs ---------------------------------------------------------------


@needs_fifo
def test_output_onto_a_fifo_is_refused_and_the_fifo_stays(tmp_path):
    import stat

    fifo = tmp_path / "out.glb"
    os.mkfifo(fifo)
    (tmp_path / "link.glb").symlink_to(fifo)
    (tmp_path / "g.bgr").write_text("Lot --> extrude(3)\n")
    for target in ("out.glb", "link.glb"):
        out = run("derive", str(tmp_path / "g.bgr"), "-o", str(tmp_path / target), timeout=20)
        assert out.returncode == 1 and "FIFO" in out.stderr, out.stderr
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["g.bgr", "link.glb", "out.glb"]


def test_output_onto_a_device_is_refused():
    with pytest.raises(bgr.BgrError, match="/proc, /sys or /dev"):
        write_text("/dev/null", "x")


@needs_fifo
def test_infer_and_write_text_refuse_a_fifo_output(tmp_path, root):
    import stat

    os.mkfifo(tmp_path / "out.bgr")
    with pytest.raises(bgr.BgrError, match="FIFO"):
        write_text(tmp_path / "out.bgr", "Lot --> NIL\n")
    source = root / "examples" / "captured" / "corner_shop.json"
    out = run("infer", str(source), "-o", str(tmp_path / "out.bgr"), timeout=30)
    assert out.returncode == 1 and "FIFO" in out.stderr, out.stderr
    assert stat.S_ISFIFO(os.lstat(tmp_path / "out.bgr").st_mode)


# --- SIGTERM and killed runs ----------------------------------------------------------------

SLOW_WRITE = """
import sys, time
import bgr.formats.glb as glb
def slow(self, stream):
    stream.write(b"partial")
    stream.flush()
    time.sleep(30)
glb.Scene.write_glb = slow  # bgr derive streams a GLB through Scene (formats/sinks.py)
from bgr.cli import main
sys.exit(main(sys.argv[1:]))
"""


def _wait_for(predicate, seconds=20.0):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(0.05)
    return False


@pytest.mark.skipif(not hasattr(signal, "SIGKILL"), reason="POSIX signals")
def test_sigterm_during_a_write_leaves_no_temporary(tmp_path):
    (tmp_path / "g.bgr").write_text("Lot --> extrude(3)\n")
    child = subprocess.Popen(
        [sys.executable, "-c", SLOW_WRITE, "derive", str(tmp_path / "g.bgr"), "-o", "out.glb"],
        cwd=tmp_path,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert _wait_for(lambda: any(p.suffix == ".tmp" for p in tmp_path.iterdir()))
        child.send_signal(signal.SIGTERM)
        _, err = child.communicate(timeout=20)
    finally:
        child.kill()
    assert child.returncode == 143, err
    assert "bgr: terminated" in err and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["g.bgr"]


# the real derivation, announced on standard error so that the signal lands inside it
ANNOUNCED_DERIVE = """
import sys
import bgr.interpreter.engine as engine
real = engine.Engine.derive
def derive(self, *args, **kwargs):
    print("deriving", file=sys.stderr, flush=True)
    return real(self, *args, **kwargs)
engine.Engine.derive = derive
from bgr.cli import main
sys.exit(main(sys.argv[1:]))
"""


@pytest.mark.skipif(not hasattr(signal, "SIGKILL"), reason="POSIX signals")
def test_sigterm_during_a_slow_derive_exits_143(tmp_path):
    # 160,000 cubes: seconds to derive and write
    (tmp_path / "g.bgr").write_text(
        "Lot --> split(x) { { ~0.05: Row }* }\nRow --> split(z) { { ~0.05: i(cube) }* }\n"
    )
    child = subprocess.Popen(
        [sys.executable, "-c", ANNOUNCED_DERIVE, "derive", "g.bgr", "-o", "out.glb"],
        cwd=tmp_path,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert child.stderr is not None and child.stderr.readline() == "deriving\n"
        time.sleep(0.2)
        child.send_signal(signal.SIGTERM)
        _, err = child.communicate(timeout=20)
    finally:
        child.kill()
    assert child.returncode == 143, err
    assert "bgr: terminated" in err and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["g.bgr"]


def test_a_killed_writers_temporary_is_removed_by_the_next_write(tmp_path):
    (tmp_path / "g.bgr").write_text("Lot --> extrude(3)\n")
    stale = tmp_path / f".out.glb.{dead_pid()}.0badcafe.tmp"
    live = tmp_path / f".out.glb.{os.getpid()}.00c0ffee.tmp"  # this test process is alive
    other = tmp_path / f".other.glb.{dead_pid()}.0badcafe.tmp"  # another target's
    for p in (stale, live, other):
        p.write_bytes(b"partial")
    out = run("derive", "g.bgr", "-o", "out.glb", cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert not stale.exists() and live.exists() and other.exists()


def test_stale_rule(tmp_path):
    old = tmp_path / ".out.glb.1a2b3c4d.tmp"  # no PID: an earlier bgr's, judged by age
    old.write_bytes(b"")
    assert not is_stale(old, "out.glb")
    os.utime(old, (time.time() - 7200, time.time() - 7200))
    assert is_stale(old, "out.glb")
    assert not is_stale(tmp_path / f".out.glb.{os.getpid()}.ab.tmp", "out.glb")
    assert is_stale(tmp_path / f".out.glb.{dead_pid()}.ab.tmp", "out.glb")
    assert not is_stale(tmp_path / f".x.glb.{dead_pid()}.ab.tmp", "out.glb")


def test_an_asset_name_the_system_refuses_is_a_located_error(tmp_path):
    """A 300-character file name (ENAMETOOLONG from the OS) was an internal error."""
    (tmp_path / "g.bgr").write_text(f'asset M = "{"a" * 300}.obj"\nLot --> extrude(2) i(M)\n')
    out = run("derive", "g.bgr", "-o", "x.glb", cwd=tmp_path)
    assert out.returncode == 1, out.stderr
    assert "g.bgr:1:7: error: asset file" in out.stderr and "cannot be opened" in out.stderr
    assert "internal error" not in out.stderr
    assert not (tmp_path / "x.glb").exists()
