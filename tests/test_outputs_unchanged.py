"""Every command's output from the bundled examples, byte for byte, against recorded hashes.

Moving code between modules (the package's layout) must not change what bgr writes. Each case
below runs one command line on an example and hashes what it wrote; the hashes are recorded in
``tests/data/output_hashes.json``.  A change that is meant to alter outputs rewrites that file
with ``python tests/test_outputs_unchanged.py`` and says why in its commit.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
import os
import shutil
import sys
from pathlib import Path

import pytest

from bgr.cli import main

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
RECORD = Path(__file__).resolve().parent / "data" / "output_hashes.json"

# (case name, output file name, command line with {out} for the output path and {dir} for its
# folder; or a list of command lines run in turn, the last one's output hashed)
CASES = [
    ("derive-house-glb", "out.glb", ["derive", "house.bgr", "--seed", "3", "-o", "{out}"]),
    ("derive-house-json", "out.json", ["derive", "house.bgr", "--seed", "3", "-o", "{out}"]),
    ("derive-house-obj", "out.obj", ["derive", "house.bgr", "--seed", "3", "-o", "{out}"]),
    ("derive-house-ply", "out.ply", ["derive", "house.bgr", "--seed", "3", "-o", "{out}"]),
    (
        "derive-house-cityjson",
        "out.city.json",
        ["derive", "house.bgr", "--seed", "3", "-o", "{out}"],
    ),
    ("derive-tower-glb", "out.glb", ["derive", "tower.bgr", "--seed", "3", "-o", "{out}"]),
    ("derive-city-block-glb", "out.glb", ["derive", "city_block.bgr", "-o", "{out}"]),
    ("derive-textured-house-glb", "out.glb", ["derive", "textured_house.bgr", "-o", "{out}"]),
    ("derive-stdlib-street-json", "out.json", ["derive", "stdlib_street.bgr", "-o", "{out}"]),
    (
        "derive-l-building-lot-glb",
        "out.glb",
        ["derive", "l_building.bgr", "--lot", "l_lot.geojson", "-o", "{out}"],
    ),
    (
        "derive-house-block-json",
        "out.json",
        ["derive", "house.bgr", "--lot", "block.geojson", "--seed", "5", "-o", "{out}"],
    ),
    (
        "derive-house-set-lot-json",
        "out.json",
        ["derive", "house.bgr", "--set", "height=14", "--lot", "12,9", "-o", "{out}"],
    ),
    (
        "derive-house-reports",
        "reports.json",
        ["derive", "house.bgr", "-o", "{dir}/x.json", "--reports", "{out}"],
    ),
    ("fmt-house", "stdout", ["fmt", "house.bgr"]),
    ("fmt-city-block", "stdout", ["fmt", "city_block.bgr"]),
    ("import-cga-townhouse", "out.bgr", ["import-cga", "cga/townhouse.cga", "-o", "{out}"]),
    ("infer-schema-corner-shop", "out.bgr", ["infer", "captured/corner_shop.json", "-o", "{out}"]),
    ("infer-boxes-building", "out.bgr", ["infer", "boxes/building.json", "-o", "{out}"]),
    (
        "retarget-building-json",
        "out.json",
        ["retarget", "boxes/building.json", "--size", "30,14,12", "-o", "{out}"],
    ),
    (
        "infer-city-block-bgr",
        "out.bgr",
        [
            ["derive", "city_block.bgr", "-o", "{dir}/block.obj"],
            ["infer", "{dir}/block.obj", "--no-progress", "-o", "{out}"],
        ],
    ),
    (
        "render-house-numpy",
        "out.png",
        ["render", "house.bgr", "--backend", "numpy", "--size", "160x120", "-o", "{out}"],
    ),
]


def run_case(argv: list, out_name: str, folder: Path) -> bytes:
    """Run a case's command lines in-process in a copy of the examples folder; return what
    the last one wrote."""
    # the examples are copied beside the output, so paths written relative to it (assets) are
    # the same wherever the test runs
    work = folder / "examples"
    shutil.copytree(EXAMPLES, work, dirs_exist_ok=True)
    out = folder / out_name
    stdout = io.StringIO()
    for line in argv if isinstance(argv[0], list) else [argv]:
        args = [a.replace("{out}", str(out)).replace("{dir}", str(folder)) for a in line]
        stdout = io.StringIO()
        here = os.getcwd()
        os.chdir(work)
        try:
            with contextlib.redirect_stdout(stdout):
                code = main(args)
        finally:
            os.chdir(here)
        assert code == 0, f"bgr {' '.join(args)} exited {code}"
    return stdout.getvalue().encode() if out_name == "stdout" else out.read_bytes()


def _sha(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


@pytest.mark.parametrize("name, out_name, argv", CASES, ids=[c[0] for c in CASES])
def test_output_is_byte_identical_to_the_recorded_one(tmp_path, name, out_name, argv):
    recorded = json.loads(RECORD.read_text())
    assert name in recorded, f"no hash recorded for {name}: run python {__file__}"
    assert _sha(run_case(argv, out_name, tmp_path)) == recorded[name]


if __name__ == "__main__":  # rewrite the record (say why in the commit)
    import tempfile

    hashes = {}
    for name, out_name, argv in CASES:
        with tempfile.TemporaryDirectory() as folder:
            hashes[name] = _sha(run_case(argv, out_name, Path(folder)))
            print(name, hashes[name][:12], file=sys.stderr)
    RECORD.write_text(json.dumps(hashes, indent=1, sort_keys=True) + "\n")
