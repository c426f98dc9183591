"""Time the README's test command several times in a row, as a contributor would run it.

    python bench/suite.py                 # `pytest` five times in a row
    python bench/suite.py --runs 1 --slow # and `pytest -m slow` once after it

Each run is a fresh `pytest` process in the repository root; the script prints one line per run
(wall seconds, pytest's closing line) and exits 1 if any run failed, so "five passes in a row,
each under ten minutes" (docs/benchmarks.md, "The test suite") is one command to check.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CLOSING = re.compile(r"^=*\s*(\d+ (passed|failed).*?)\s*=*$")


def run(args: list[str]) -> tuple[float, int, str]:
    """One pytest process: its wall seconds, exit status and closing line."""
    start = time.perf_counter()
    proc = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    seconds = time.perf_counter() - start
    lines = [m.group(1) for m in map(CLOSING.match, proc.stdout.splitlines()) if m]
    if proc.returncode != 0:
        sys.stdout.write(proc.stdout[-4000:])
    return seconds, proc.returncode, lines[-1] if lines else f"exit {proc.returncode}"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--runs", type=int, default=5, help="runs of `pytest` (default 5)")
    parser.add_argument("--slow", action="store_true", help="then run `pytest -m slow` once")
    options = parser.parse_args()
    failed = 0
    plan = [("pytest", [])] * options.runs + (
        [("pytest -m slow", ["-m", "slow"])] if options.slow else []
    )
    for i, (name, args) in enumerate(plan, 1):
        seconds, status, closing = run(args)
        failed += status != 0
        print(f"run {i} ({name}): {seconds:7.1f} s  {closing}", flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
