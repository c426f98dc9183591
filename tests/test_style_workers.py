"""A model of several buildings is captured on every core (issue 27: PLATEAU's 10 buildings in
0.7 of the time on 2): forked workers, one building each, the sheet the same as one building
after another, and a worker's failure the located error the loop would have raised."""

from __future__ import annotations

import os
import signal
import threading
from pathlib import Path

import pytest

from bgr.grammar.errors import BgrError, Diagnostic
from bgr.inverse.style import capture as capture_module
from bgr.inverse.style.capture import capture_buildings

ROOT = Path(__file__).resolve().parent.parent
PLATEAU = ROOT.parent / "shared/data/textured/plateau_tokyo/53392633_bldg_6697_2_op.gml"
MESH = object()  # the fake captures below never look at it
forking = pytest.mark.skipif(
    capture_module._capture_workers(2) < 2, reason="one core, no fork, or threads here"
)


@forking
def test_workers_give_the_sheet_of_one_building_after_another():
    if not PLATEAU.exists():
        pytest.skip("the shared PLATEAU data is not here")
    from bgr.inverse.style.emit import Crops, style_text

    mesh = capture_module.read_model(str(PLATEAU))
    ids = mesh.object_ids[-4:]  # the four smallest: a tenth of a second each

    def sheet(captured):
        crops = Crops("style.assets", 512)
        return style_text([(c.capture, c.groups) for c in captured], crops), crops.files

    parallel = capture_buildings(mesh, ids)
    one_by_one = [capture_module.capture_building(mesh, b) for b in ids]
    assert [c.capture.building for c in parallel] == ids
    assert sheet(parallel) == sheet(one_by_one)


def _fake(fail: str, how: str):
    def capture_building(mesh, building):
        if building == fail:
            if how == "located":
                raise BgrError(Diagnostic("city.gml", 7, 3, "texture x.png cannot be read", "h"))
            if how == "bug":
                raise RuntimeError("a bug")
            os.kill(os.getpid(), signal.SIGKILL)
        return f"captured {building}"

    return capture_building


@forking
def test_results_come_back_in_the_buildings_order(monkeypatch):
    monkeypatch.setattr(capture_module, "capture_building", _fake("none", "located"))
    ids = [f"b{k}" for k in range(7)]
    assert capture_buildings(MESH, ids) == [f"captured {b}" for b in ids]


@forking
def test_a_located_error_in_a_worker_is_raised_as_it_is(monkeypatch):
    monkeypatch.setattr(capture_module, "capture_building", _fake("b2", "located"))
    with pytest.raises(BgrError) as info:
        capture_buildings(MESH, ["b0", "b1", "b2", "b3"])
    (diagnostic,) = info.value.diagnostics
    assert (diagnostic.path, diagnostic.line, diagnostic.column) == ("city.gml", 7, 3)
    assert diagnostic.message == "texture x.png cannot be read"


@forking
@pytest.mark.parametrize(
    ("how", "words"),
    [
        ("bug", ["internal error in a worker process while capturing building b1", "a bug"]),
        ("killed", ["killed by signal 9", "while capturing building b1", "--building ID"]),
    ],
)
def test_a_worker_that_fails_or_dies_is_named(monkeypatch, how, words):
    monkeypatch.setattr(capture_module, "capture_building", _fake("b1", how))
    with pytest.raises(BgrError) as info:
        capture_buildings(MESH, ["b0", "b1", "b2"])
    for word in words:
        assert word in str(info.value)


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
