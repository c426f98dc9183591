"""How fast the default limits stop a runaway, and that the largest benchmark still runs.

Runs each runaway grammar of issue 10 with the *default* budgets (no --max-shapes), each in a
fresh ``bgr derive`` process whose address space is capped at 2 GB, and reports its exit status,
wall time and peak memory; then derives ``grid_city`` n = 40 (about 1 M terminals) with the
defaults and no cap, which must succeed.  Results go in docs/limits.md.

    python bench/hostile.py              # all
    python bench/hostile.py --no-city    # the runaways only (a minute less)
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
GRID_CITY = ROOT.parent / "shared/bench/grid_city.bgr"
CAP = 2 * 2**30

RUNAWAYS = {
    # in rules that can never end in a terminal: stopped after 20,000 shapes handed to them
    "binary split explosion": ("Lot --> A\nA --> split(x) { ~1: A | ~1: A }", []),
    # one that makes a terminal at every step has to make the whole shape budget
    "binary explosion with terminals": ("Lot --> A\nA --> split(x) { ~1: A | ~1: A T }", []),
    "1 mm repeat on 10 km": ("Lot --> split(x) { 0.001: T }*", ["--lot", "10000,10"]),
    "floating 1 mm repeat on 10 km": ("Lot --> split(x) { ~0.001: T }*", ["--lot", "10000,10"]),
    "1 cm repeat on 30 km": ("Lot --> split(x) { 0.01: T }*", ["--lot", "30000,10"]),
    "3 M terminals of 2 triangles": ("Lot --> split(x) { 0.01: T }*", ["--lot", "29000,10"]),
    "house, height 1e9": (None, ["--set", "height=1e9"]),
    "scale by 1e308": ("Lot --> extrude(3) s('1e308, 0, 1)", []),
    # the slowest per shape: every other piece is extruded and its top face taken, a mesh each
    "explosion through extrude, comp": (
        "Lot --> A\nA --> split(x) { ~1: extrude(1) comp(f) { top: B } | ~1: A }\n"
        "B --> split(y) { ~1: A | ~1: A }",
        [],
    ),
}


def run(args: list[str], cwd: str, cap: bool) -> tuple[int, float, float, str]:
    """(exit status, seconds, peak MB, last stderr line) of one bgr process."""
    start = time.perf_counter()
    proc = subprocess.Popen(
        [sys.executable, "-m", "bgr", *args],
        cwd=cwd,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=(lambda: resource.setrlimit(resource.RLIMIT_AS, (CAP, CAP))) if cap else None,
    )
    assert proc.stderr is not None
    err = proc.stderr.read()
    _, status, usage = os.wait4(proc.pid, 0)
    seconds = time.perf_counter() - start
    lines = [line for line in err.splitlines() if "error" in line] or err.splitlines() or [""]
    return os.waitstatus_to_exitcode(status), seconds, usage.ru_maxrss / 1024, lines[0][:90]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-city", action="store_true", help="skip grid_city n = 40")
    options = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        print(f"{'case':32} {'exit':>4} {'seconds':>8} {'peak MB':>8}  message")
        for name, (source, extra) in RUNAWAYS.items():
            if source is None:
                path = str(ROOT / "examples/house.bgr")
            else:
                path = os.path.join(tmp, "case.bgr")
                Path(path).write_text("terminal T\n" + source + "\n")
            code, seconds, peak, message = run(
                ["derive", path, "-o", os.path.join(tmp, "out.glb"), *extra], tmp, cap=True
            )
            print(f"{name:32} {code:>4} {seconds:>8.1f} {peak:>8.0f}  {message}")
        if not options.no_city and GRID_CITY.exists():
            code, seconds, peak, message = run(
                ["derive", str(GRID_CITY), "--set", "n=40", "-o", os.path.join(tmp, "city.glb")],
                tmp,
                cap=False,
            )
            print(
                f"{'grid_city n = 40, no cap':32} {code:>4} {seconds:>8.1f} {peak:>8.0f}  {message}"
            )


if __name__ == "__main__":
    main()
