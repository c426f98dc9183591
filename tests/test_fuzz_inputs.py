"""Fuzzing what the command line takes besides grammars: option values, and the terminal lists
and captured models that ``bgr infer`` reads.  Whatever comes in, ``bgr`` answers with a status
of 0, 1 or 2 and a message, never a traceback or an "internal error" (issue 10).

The number of cases grows with ``BGR_FUZZ_CASES`` (default: a CI-sized sample).
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import random
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from bgr.cli import main

ROOT = Path(__file__).resolve().parent.parent
CASES = int(os.environ.get("BGR_FUZZ_CASES", "0")) or None
CAPTURED = ROOT / "examples/captured/corner_shop.json"


def fuzz(default: int):
    return settings(
        max_examples=CASES or default,
        deadline=None,
        database=None,
        suppress_health_check=list(HealthCheck),
    )


def run(argv: list[str]) -> tuple[int, str]:
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            code = main(argv)
        except SystemExit as e:  # argparse's usage errors
            code = e.code if isinstance(e.code, int) else 2
    return code, err.getvalue()


def assert_answered(code: int, err: str) -> None:
    assert code in (0, 1, 2), err
    assert "internal error" not in err and "Traceback" not in err, err


HOSTILE_NUMBERS = [
    "nan", "inf", "-inf", "1e400", "-1e400", "1e308", "1e-320", "0", "-0", "-1", "1_000",
    "١٠", "0x10", "1e", "", " ", "3,", ",3", "3,,3", "1e9,1e9", "99999999999999999999999",
    "true", '"a"', "NaN", "+5", "5.", ".5", "1/0",
]  # fmt: skip
OPTIONS = {
    "--seed": HOSTILE_NUMBERS + ["3", str(2**64), str(-(2**63))],
    "--lot": HOSTILE_NUMBERS + ["10,10", "1e308,1e308", "nan,3", "0,5", "-3,5", "missing.geojson"],
    "--set": [f"h={v}" for v in HOSTILE_NUMBERS] + ["=3", "h", "nope=3", "h=="],
    "--max-depth": HOSTILE_NUMBERS + ["1", "2"],
    "--max-shapes": HOSTILE_NUMBERS + ["1", "5"],
    "--max-triangles": HOSTILE_NUMBERS + ["1", "12"],
    "--max-memory": HOSTILE_NUMBERS + ["1K", "64M", "4G", "1T", "9999T"],
    "--format": ["glb", "gltf", "obj", "ply", "stl", "json", "city.json", "", "GLB"],
}


@fuzz(120)
@given(
    st.lists(st.sampled_from(sorted(OPTIONS)), max_size=4),
    st.randoms(use_true_random=False),
    st.sampled_from(["out.glb", "out.obj", "out.json", "out.city.json", "out", "-"]),
)
def test_derive_options(tmp_path_factory, names, rng, output):
    folder = tmp_path_factory.mktemp("opts")
    grammar = folder / "box.bgr"
    grammar.write_text("attr h = 3\nterminal Box\nLot --> extrude(h) Box\n")
    argv = ["derive", str(grammar), "-o", output if output == "-" else str(folder / output)]
    for name in names:
        argv += [name, rng.choice(OPTIONS[name])]
    assert_answered(*run(argv))


def _mutate(value, rng: random.Random, depth: int = 0):
    """One random change somewhere inside a JSON value."""
    hostile = [None, True, "x", "", -1, 0, 1e308, -1e308, 1e-320, 2**70, [], {}, [[]], "NaN"]
    if isinstance(value, dict) and value and rng.random() < 0.8:
        key = rng.choice(sorted(value, key=str))
        roll = rng.random()
        if roll < 0.15:
            del value[key]
        elif roll < 0.3:
            value[key] = rng.choice(hostile)
        else:
            value[key] = _mutate(value[key], rng, depth + 1)
        return value
    if isinstance(value, list) and value and rng.random() < 0.8:
        i = rng.randrange(len(value))
        roll = rng.random()
        if roll < 0.15:
            del value[i]
        elif roll < 0.25:
            value.insert(i, value[i])
        elif roll < 0.35:
            value[i] = rng.choice(hostile)
        else:
            value[i] = _mutate(value[i], rng, depth + 1)
        return value
    if isinstance(value, float | int) and not isinstance(value, bool):
        return rng.choice([value * 1e300, -value, 0, float("nan"), float("inf"), value + 0.5])
    return rng.choice(hostile)


@pytest.fixture(scope="module")
def terminal_list(tmp_path_factory) -> dict:
    out = tmp_path_factory.mktemp("tl") / "facade.json"
    code, err = run(["derive", str(ROOT / "examples/house.bgr"), "-o", str(out)])
    assert code == 0, err
    return json.loads(out.read_text())


@fuzz(60)
@given(st.randoms(use_true_random=False), st.integers(1, 4), st.sampled_from(["terms", "model"]))
def test_infer_reads_mutated_inputs(tmp_path_factory, terminal_list, rng, changes, which):
    data = json.loads(
        json.dumps(terminal_list) if which == "terms" else CAPTURED.read_text(encoding="utf-8")
    )
    for _ in range(changes):
        data = _mutate(data, rng)
    path = tmp_path_factory.mktemp("infer") / "input.json"
    path.write_text(json.dumps(data, allow_nan=True))
    assert_answered(*run(["infer", str(path), "-o", str(path.with_suffix(".bgr"))]))


@pytest.mark.parametrize(
    "text",
    ["", "{", "[]", "null", "1e400", '{"terminals": 5}', "[" * 100_000 + "]" * 100_000, "\x00"],
)
def test_infer_reads_broken_json(tmp_path, text):
    path = tmp_path / "input.json"
    path.write_text(text)
    assert_answered(*run(["infer", str(path)]))
