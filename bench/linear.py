"""Work that used to grow with the square of the input (issue 34), timed through the CLI.

A round footprint of N corners derived with a flat-roofed grammar (outline cleaning,
interpreter/outline.py), and ``bgr infer`` on an OBJ of N one-triangle objects (the per-object
cost of inverse/city).  Each case is a fresh ``bgr`` process; the figure is its wall time, the
best of ``--repeat`` runs.  The inputs are made by the generators of tests/test_linear.py.

    python bench/linear.py               # 10,000 and 100,000 of each
    python bench/linear.py --repeat 3
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
from test_linear import FLAT, one_triangle_city, round_lot  # noqa: E402


def timed(args: list[str], cwd: Path, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "bgr", *args], cwd=cwd, check=True,
                       capture_output=True)  # fmt: skip
        best = min(best, time.perf_counter() - start)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=1)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        (folder / "flat.bgr").write_text(FLAT)
        print("| case | N | wall (s) |\n|---|---:|---:|")
        for n in (10_000, 100_000):
            lot = round_lot(folder / f"round{n}.geojson", n)
            took = timed(["derive", "flat.bgr", "--lot", lot.name, "-o", "out.glb"], folder,
                         args.repeat)  # fmt: skip
            print(f"| round footprint, `bgr derive` | {n:,} corners | {took:.2f} |", flush=True)
        for n in (10_000, 100_000):
            city = one_triangle_city(folder / f"city{n}.obj", n, flat=True)
            took = timed(["infer", city.name, "-o", f"city{n}.bgr"], folder, args.repeat)
            print(f"| one-triangle objects, `bgr infer` | {n:,} objects | {took:.2f} |", flush=True)


if __name__ == "__main__":
    main()
