"""Benchmark: the Helsinki example (486 real footprints) against an earlier commit, in turn.

    python bench/helsinki.py --baseline 106d831 [--pairs 7] [--one-process] [--workers N]

Extracts the ``--baseline`` commit with ``git archive`` into a temporary folder, lays it out as
the installed package (``pyproject.toml``'s package-dir mapping) and runs its ``bgr derive`` of
the Helsinki command alternately with this checkout's, in fresh processes: wall seconds of each
pair, their ratio, the medians, and the md5 of both GLBs (they must be the same bytes).
``--one-process`` sets ``BGR_BACKGROUND=0`` for both sides (no writer process beside the
derivation, where the baseline has one: the derivation's own speed-up).
"""

from __future__ import annotations

import argparse
import hashlib
import io
import os
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
COMMAND = [
    "derive",
    "examples/helsinki/helsinki.bgr",
    "--lot",
    "examples/helsinki/helsinki_osm_buildings.geojson",
    "--map",
    "floors=building:levels:int",
]
# the old package first on the path, and the editable install's finder out of the way
RUNNER = """
import sys
sys.meta_path[:] = [f for f in sys.meta_path if "editable" not in type(f).__name__.lower()
                    and "editable" not in getattr(f, "__module__", "")]
sys.path.insert(0, sys.argv.pop(1))
import bgr
assert bgr.__file__.startswith(sys.path[0]), bgr.__file__
from bgr.cli import main
sys.exit(main(sys.argv[1:]))
"""


def extract(rev: str, into: Path) -> Path:
    """The commit ``rev`` laid out as an importable ``bgr`` package under ``into``."""
    data = subprocess.run(
        ["git", "-C", str(ROOT), "archive", "--format=tar", rev],
        capture_output=True,
        check=True,
    ).stdout
    tree = into / "tree"
    with tarfile.open(fileobj=io.BytesIO(data)) as tar:
        tar.extractall(tree, filter="data")
    mapping = tomllib.loads((tree / "pyproject.toml").read_text())["tool"]["setuptools"]
    package = into / "pkg"
    for name, folder in mapping["package-dir"].items():
        target = package.joinpath(*name.split("."))
        target.parent.mkdir(parents=True, exist_ok=True)
        (tree / folder).rename(target)
    return package


def timed(argv: list[str], env: dict) -> float:
    start = time.perf_counter()
    done = subprocess.run(argv, cwd=ROOT, env=env, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if done.returncode:
        sys.exit(f"{' '.join(argv[:4])} failed:\n{done.stderr[-2000:]}")
    return seconds


def md5(path: Path) -> str:
    return hashlib.md5(path.read_bytes()).hexdigest()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", required=True, help="the commit to compare against")
    ap.add_argument("--pairs", type=int, default=7)
    ap.add_argument("--one-process", action="store_true", help="BGR_BACKGROUND=0 for both sides")
    ap.add_argument("--workers", default="1", help="--workers for both sides")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        package = extract(args.baseline, folder)
        old_glb, new_glb = folder / "old.glb", folder / "new.glb"
        old = [sys.executable, "-c", RUNNER, str(package), *COMMAND, "--workers", args.workers]
        new = [sys.executable, "-m", "bgr", *COMMAND, "--workers", args.workers]
        env = dict(os.environ)
        new_env = dict(env, BGR_BACKGROUND="0") if args.one_process else env
        before, after = [], []
        print(f"baseline {args.baseline} vs {ROOT} (one process: {args.one_process})")
        for k in range(args.pairs):
            before.append(timed([*old, "-o", str(old_glb)], new_env))
            after.append(timed([*new, "-o", str(new_glb)], new_env))
            print(f"pair {k + 1}: {before[-1]:6.2f} s  {after[-1]:6.2f} s  "
                  f"{before[-1] / after[-1]:5.2f}x", flush=True)  # fmt: skip
        ratios = sorted(b / a for b, a in zip(before, after, strict=True))
        print(
            f"medians: {statistics.median(before):.2f} s before, {statistics.median(after):.2f} s "
            f"now: {statistics.median(before) / statistics.median(after):.2f}x; pair by pair "
            f"{ratios[0]:.2f}x to {ratios[-1]:.2f}x, median {statistics.median(ratios):.2f}x"
        )
        same = md5(old_glb) == md5(new_glb)
        print(f"md5 {md5(old_glb)} before, {md5(new_glb)} now: {'same' if same else 'DIFFERENT'}")


if __name__ == "__main__":
    main()
