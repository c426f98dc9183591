"""Repeated subtrees derived once (interpreter/reuse.py, issue 30): the outputs are the bytes a
full derivation writes, and what draws randomness or reads its place is never reused."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest
from test_gltf_validator import CASES, GRID_CITY

import bgr
from bgr.grammar.stdlib_reference import public_rules
from bgr.interpreter import engine as engine_module
from bgr.interpreter import reuse as reuse_module

ROOT = Path(__file__).resolve().parent.parent
FORMATS = ("glb", "obj", "ply", "city.json")  # and the terminal list


def written(result, folder: Path) -> dict[str, bytes]:
    folder.mkdir(parents=True, exist_ok=True)
    out = {}
    for ext in FORMATS:
        path = folder / f"out.{ext}"
        result.save(path)
        out[ext] = path.read_bytes()
    return out


def derived_both_ways(monkeypatch, tmp_path: Path, derive) -> tuple[dict, dict, list, list]:
    """The outputs and terminal lists of ``derive()`` without reuse and with it."""
    found = []
    tmp_path.mkdir(parents=True, exist_ok=True)
    for reuse in (False, True):
        monkeypatch.setattr(engine_module, "REUSE", reuse)
        result = derive()
        path = tmp_path / f"terminals-{reuse}.json"
        result.save(path)
        out = written(result, tmp_path / str(reuse))
        out["json"] = path.read_bytes()
        found.append((out, json.loads(out["json"])))
    (full, full_list), (reused, reused_list) = found
    return full, reused, full_list["terminals"], reused_list["terminals"]


def assert_same(full, reused, full_list, reused_list) -> None:
    for ext in (*FORMATS, "json"):
        assert full[ext] == reused[ext], f".{ext} differs"
    assert full_list == reused_list  # every digit of every float64


@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize(("name", "grammar", "lot", "attrs"), [c[:3] + c[4:] for c in CASES])
def test_every_example_derives_to_the_same_bytes(
    monkeypatch, tmp_path, name, grammar, lot, attrs, seed
):
    assert_same(
        *derived_both_ways(
            monkeypatch, tmp_path, lambda: bgr.derive(grammar, seed=seed, lot=lot, attrs=attrs)
        )
    )


@pytest.mark.parametrize("seed", [1, 7])
def test_the_grid_city_derives_to_the_same_bytes_and_reuses(monkeypatch, tmp_path, seed):
    if not GRID_CITY.is_file():
        pytest.skip("../shared/bench is not here")
    hits = []
    replay = reuse_module.Reuse.replay

    def counted(self, *args):
        done = replay(self, *args)
        hits.append(done)
        return done

    monkeypatch.setattr(reuse_module.Reuse, "replay", counted)
    grammar = bgr.load(GRID_CITY)
    assert_same(
        *derived_both_ways(
            monkeypatch, tmp_path, lambda: bgr.derive(grammar, seed=seed, attrs={"n": 3})
        )
    )
    assert sum(hits) > 100  # floors and tiles replayed, not derived again


def _gallery():
    spec = importlib.util.spec_from_file_location("make_gallery", ROOT / "docs" / "make_gallery.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_stdlib_contact_sheet_derives_to_the_same_bytes(monkeypatch, tmp_path):
    gallery = _gallery()
    for module in gallery.MODULES:
        if module not in gallery.WRAPPERS:
            continue
        for rule, _doc in public_rules(module)[1]:
            template, _ = gallery.WRAPPERS[module]
            if module == "textured" and rule.name in gallery.TEXTURED:
                template = gallery.TEXTURED[rule.name][0]
            if module == "window" and rule.name.endswith("Entrance"):
                template = gallery.ENTRANCE
            body = (
                f"Lot --> lib.{rule.name}" if template is None else template.format(name=rule.name)
            )
            src = f"import stdlib.{module} as lib\n{body}\n"
            lot = (20, 15) if template is None else None

            def derive(src=src, lot=lot):
                return bgr.derive(bgr.load(src, path=ROOT / "_gallery.bgr"), seed=1, lot=lot)

            assert_same(*derived_both_ways(monkeypatch, tmp_path / f"{module}-{rule.name}", derive))


TILES = """
Lot --> s(30, 0, 10) extrude(12) comp(f) { front: Facade | all: NIL }
Facade --> split(y) { ~3: Floor }*
Floor --> split(x) { ~2: Tile }*
"""


@pytest.mark.parametrize(
    ("tile", "varies"),
    [
        ("Tile --> color(rand(0, 1), 0.5, 0.5)", "color"),  # randomness: drawn anew each time
        ("Tile --> case scope.x < 10: color(1, 0, 0) | else: color(0, 0, 1)", "color"),
        (
            "Tile --> case split.index % 2 == 0: s('1, '0.5, '1) Tile2 | else: Tile2\n"
            "Tile2 --> color(0, 1, 0)",
            "size",
        ),
        (
            "Tile --> Bay(part = Pane)\nBay(part) --> split(x) { ~1: part | ~1: part }\n"
            "Pane --> color(rand(0, 1), 0, 0)",
            "color",
        ),
    ],
    ids=["rand", "scope.x", "split.index", "random rule held in a parameter"],
)
def test_what_draws_randomness_or_reads_its_place_is_derived_each_time(
    monkeypatch, tmp_path, tile, varies
):
    grammar = bgr.load(TILES + tile)
    full, reused, full_list, reused_list = derived_both_ways(
        monkeypatch, tmp_path, lambda: bgr.derive(grammar, seed=4)
    )
    assert_same(full, reused, full_list, reused_list)
    values = {json.dumps(t[varies]) for t in reused_list}
    assert len(values) > 1  # the tiles differ, as in a full derivation


def test_reusable_rules_are_found_by_what_they_reach():
    grammar = bgr.load(
        TILES
        + "Tile --> split(x) { ~1: Wall | 1: Window | ~1: Wall }\n"
        + "Window --> Pane\nPane --> color(rand(0, 1), 0, 0)\nWall --> color(1, 1, 1)\n"
    )
    known: dict = {}
    ok = {name: reuse_module.reusable(grammar, name, known) for name in grammar.rules}
    assert ok["Wall"] and not ok["Pane"]
    assert not ok["Window"] and not ok["Tile"] and not ok["Floor"]  # they reach Pane
    assert not np.all(list(ok.values()))
