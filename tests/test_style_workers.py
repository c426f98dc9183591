"""A model of several buildings is captured on every core (issue 27: PLATEAU's 10 buildings in
0.7 of the time on 2): forked workers, one building each, the sheet the same as one building
after another, and a worker's failure the located error the loop would have raised.

Workers are forked only from a process with no other thread, and a pytest worker runs threads
(execnet's, tqdm's, dask's), so these tests run their captures in a fresh Python process."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import threading
from pathlib import Path

import pytest

from bgr.inverse.style import capture as capture_module

ROOT = Path(__file__).resolve().parent.parent
PLATEAU = ROOT.parent / "shared/data/textured/plateau_tokyo/53392633_bldg_6697_2_op.gml"
linux_only = pytest.mark.skipif(
    not sys.platform.startswith("linux") or len(os.sched_getaffinity(0)) < 2,
    reason="workers are forked on Linux with two cores or more",
)


def _run(script: str) -> subprocess.CompletedProcess:
    """``script`` in a fresh Python process (no thread but its main one), after a prelude that
    replaces capture_building with a fake: building "fail-located" raises a located error,
    "fail-bug" a RuntimeError, "fail-killed" kills its process (only a forked worker's)."""
    prelude = """
        import os, signal
        from bgr.grammar.errors import BgrError, Diagnostic
        from bgr.inverse.style import capture as C
        PARENT = os.getpid()

        def fake(mesh, building):
            if building == "fail-located":
                raise BgrError(Diagnostic("city.gml", 7, 3, "texture x.png cannot be read", "h"))
            if building == "fail-bug":
                raise RuntimeError("a bug")
            if building == "fail-killed" and os.getpid() != PARENT:
                os.kill(os.getpid(), signal.SIGKILL)
            return (building, os.getpid() != PARENT)

        C.capture_building = fake
        assert C._capture_workers(4) >= 2, C._capture_workers(4)
    """
    code = textwrap.dedent(prelude) + textwrap.dedent(script)
    return subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, cwd=ROOT
    )


@linux_only
def test_results_come_back_in_order_from_the_workers():
    done = _run("""
        ids = [f"b{k}" for k in range(7)]
        got = C.capture_buildings(object(), ids)
        assert [g[0] for g in got] == ids, got
        assert all(in_worker for _, in_worker in got), got
        print("ok")
    """)
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr


@linux_only
@pytest.mark.parametrize(
    ("building", "words"),
    [
        ("fail-located", ["city.gml:7:3: error: texture x.png cannot be read"]),
        ("fail-bug", ["internal error in a worker process while capturing building fail-bug"]),
        ("fail-killed", ["killed by signal 9", "capturing building fail-killed", "--building"]),
    ],
)
def test_a_worker_that_fails_or_dies_is_a_named_error(building, words):
    done = _run(f"""
        try:
            C.capture_buildings(object(), ["b0", "{building}", "b2"])
        except BgrError as error:
            print(error)
    """)
    assert done.returncode == 0, done.stderr
    for word in words:
        assert word in done.stdout, done.stdout


@linux_only
def test_workers_give_the_sheet_of_one_building_after_another():
    if not PLATEAU.exists():
        pytest.skip("the shared PLATEAU data is not here")
    script = f"""
        import threading
        from bgr.inverse.style import capture as C
        from bgr.inverse.style.emit import Crops, style_text

        mesh = C.read_model({str(PLATEAU)!r})
        ids = mesh.object_ids[-4:]  # the four smallest: a tenth of a second each
        assert threading.active_count() == 1 and C._capture_workers(len(ids)) >= 2

        def sheet(captured):
            crops = Crops("style.assets", 512)
            return style_text([(c.capture, c.groups) for c in captured], crops), crops.files

        parallel = C.capture_buildings(mesh, ids)
        one_by_one = [C.capture_building(mesh, b) for b in ids]
        assert [c.capture.building for c in parallel] == ids
        assert sheet(parallel) == sheet(one_by_one)
        print("same")
    """
    done = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(script)],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=ROOT,
    )
    assert done.returncode == 0 and done.stdout.strip() == "same", done.stderr


def test_one_building_or_another_thread_means_no_workers():
    assert capture_module._capture_workers(1) == 1
    stop = threading.Event()
    other = threading.Thread(target=stop.wait)
    other.start()
    try:  # forking now would copy whatever lock the other thread holds
        assert capture_module._capture_workers(10) == 1
    finally:
        stop.set()
        other.join()
