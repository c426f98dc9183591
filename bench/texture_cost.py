"""Benchmark: what texturing every façade of grid_city costs (issue 26: at most 25 % more
derive + GLB time for n = 20, and each image stored once).

    python bench/texture_cost.py [--n 20] [--runs 5] [--grammar ../shared/bench/grid_city.bgr]

Two grammars are written to a temporary folder: grid_city as it is (plain) and the same with
its façades textured the CGA way (``Facade --> setupProjection(0, scope.xy, ~1.5, ~1)
projectUV(0) texture("brick.png") split(y) ...``: every tile, wall and window of every façade
carries texture coordinates and the colour map; brick.png is the one bgr ships).  Each run
derives one of them to GLB in a fresh process (``bgr derive G -o out.glb --set n=N``), plain
and textured in turn so that a drift of the machine's speed hits both; the ratio is taken pair
by pair and its median printed, for wall-clock and for CPU (user + system) seconds, with the
textured GLB's image count.
"""

from __future__ import annotations

import argparse
import json
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_GRAMMAR = ROOT.parent / "shared" / "bench" / "grid_city.bgr"
BRICK = ROOT / "stdlib" / "textures" / "brick.png"
PLAIN_FACADE = "Facade --> split(y)"
TEXTURED_FACADE = (
    'Facade --> setupProjection(0, scope.xy, ~1.5, ~1) projectUV(0) texture("brick.png") split(y)'
)


def textured(text: str) -> str:
    """grid_city with every façade textured (its Facade rule given a projection and a map)."""
    if text.count(PLAIN_FACADE) != 1:
        sys.exit(f"the grammar has no single '{PLAIN_FACADE}' rule to texture")
    return text.replace(PLAIN_FACADE, TEXTURED_FACADE)


def timed(grammar: Path, n: int, out: Path) -> tuple[float, float]:
    """Wall and CPU (user + system) seconds of one `bgr derive` to GLB in a fresh process: the
    CPU time is what a loaded machine disturbs least."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    proc = subprocess.run(
        [sys.executable, "-m", "bgr", "derive", str(grammar), "-o", str(out), "--set", f"n={n}"],
        capture_output=True,
        text=True,
    )
    seconds = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        sys.exit(f"{grammar.name} failed:\n{proc.stderr}")
    cpu = after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime
    return seconds, cpu


def glb_images(path: Path) -> int:
    """The number of images a GLB's JSON chunk lists."""
    data = path.read_bytes()
    length = int.from_bytes(data[12:16], "little")
    return len(json.loads(data[20 : 20 + length]).get("images", []))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--n", type=int, default=20, help="grid size (default 20)")
    parser.add_argument("--runs", type=int, default=5, help="pairs of runs (default 5)")
    parser.add_argument("--grammar", type=Path, default=DEFAULT_GRAMMAR)
    args = parser.parse_args(argv)
    if not args.grammar.is_file():
        sys.exit(f"{args.grammar}: no such grammar (the benchmark inputs live in ../shared/bench)")
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        plain, tex = folder / "plain.bgr", folder / "textured.bgr"
        text = args.grammar.read_text()
        plain.write_text(text)
        tex.write_text(textured(text))
        shutil.copy(BRICK, folder / "brick.png")
        timed(plain, args.n, folder / "warm.glb")  # warm-up: imports and the disk cache
        pairs = []
        for k in range(args.runs):
            a = timed(tex, args.n, folder / "textured.glb")
            b = timed(plain, args.n, folder / "plain.glb")
            pairs.append((a, b))
            print(
                f"run {k + 1}: textured {a[0]:.2f} s ({a[1]:.2f} s CPU), "
                f"plain {b[0]:.2f} s ({b[1]:.2f} s CPU), "
                f"ratio {a[0] / b[0]:.3f} ({a[1] / b[1]:.3f} CPU)"
            )
        images = glb_images(folder / "textured.glb")
        sizes = [(folder / f).stat().st_size / 1e6 for f in ("textured.glb", "plain.glb")]
    for k, what in ((0, "wall"), (1, "CPU")):
        ratio = statistics.median(a[k] / b[k] for a, b in pairs)
        print(
            f"n = {args.n}, {what}: textured median "
            f"{statistics.median(a[k] for a, _ in pairs):.2f} s, plain "
            f"{statistics.median(b[k] for _, b in pairs):.2f} s; median ratio {ratio:.3f} "
            f"({(ratio - 1) * 100:+.1f} %)"
        )
    print(f"textured GLB {sizes[0]:.1f} MB with {images} image(s), plain {sizes[1]:.1f} MB")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
