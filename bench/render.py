"""Benchmark: render a 200,000-triangle model at 1024 x 1024 with both rasterisers.

    python bench/render.py [--n 9] [--size 1024] [--repeats 5]
                           [--grammar ../shared/bench/grid_city.bgr]

The model is the grid-city stress grammar (bench/grid_city.py) with n = 9: 81 buildings, 200,086
triangles.  For each backend (GL through EGL, numpy) and each view it times, over several
repeats, the rasterisation alone (depth + triangle-index buffers) and a whole ``render()`` of a
prepared scene in shaded mode (rasterise + image); it gives the median and the best.  Then one
fresh process per backend runs the command line on the model's GLB (``bgr render city.glb -o
x.png``): Python start, imports, reading the GLB, making the GL context, rendering, PNG writing.
Target: under 2 s per 1024 x 1024 image.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_GRAMMAR = ROOT.parent / "shared" / "bench" / "grid_city.bgr"
VIEWS = ("iso", "front", "top")


def timed(fn, repeats: int) -> tuple[float, float]:
    runs = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        runs.append(time.perf_counter() - t)
    return statistics.median(runs), min(runs)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=9, help="grid size of the city (9: 200,086 triangles)")
    ap.add_argument("--size", type=int, default=1024, help="square image size in pixels")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--grammar", type=Path, default=DEFAULT_GRAMMAR)
    args = ap.parse_args()
    if not args.grammar.is_file():
        sys.exit(f"{args.grammar}: not found (the benchmark grammar lives in ../shared/bench/)")

    import bgr
    from bgr.render import Camera, images, load_scene, raster_gl, raster_numpy

    t = time.perf_counter()
    result = bgr.derive(bgr.load(args.grammar), seed=1, attrs={"n": args.n})
    derive_s = time.perf_counter() - t
    t = time.perf_counter()
    scene = load_scene(result)
    scene_s = time.perf_counter() - t
    size = (args.size, args.size)
    print(
        f"model: {args.grammar.name} n = {args.n}: {len(result):,} terminals, {len(scene):,} "
        "triangles "
        f"(derive {derive_s:.2f} s, scene {scene_s:.2f} s); image {size[0]}x{size[1]}; cores: "
        f"{os.cpu_count()}"
    )

    t = time.perf_counter()
    gl = raster_gl.available()
    context_s = time.perf_counter() - t
    if gl:
        info = raster_gl._context()["ctx"].info
        print(
            f"GL: {info['GL_RENDERER']}, {info['GL_VERSION']}; context made in {context_s:.2f} s "
            "(once per process)"
        )
    else:
        print(f"GL: not available ({raster_gl._state.get('error')}); numpy only")

    backends = [("gl", raster_gl.rasterise)] if gl else []
    backends.append(("numpy", raster_numpy.rasterise))
    print(
        f"\n{'backend':<8} {'view':<6} {'covered':>8} {'raster med s':>13} {'best s':>7} "
        f"{'render med s':>13} {'best s':>7}"
    )
    for name, rasterise in backends:
        for view in VIEWS:
            cam = Camera.preset(view, *scene.bounds(), size=size)
            frame = rasterise(scene.triangles, cam)  # warm up (and the GL framebuffer)
            raster = timed(lambda r=rasterise, c=cam: r(scene.triangles, c), args.repeats)
            whole = timed(
                lambda r=rasterise, c=cam: images.shaded(r(scene.triangles, c), scene), args.repeats
            )
            print(
                f"{name:<8} {view:<6} {frame.mask.mean():>7.1%} {raster[0]:>13.3f} "
                f"{raster[1]:>7.3f} "
                f"{whole[0]:>13.3f} {whole[1]:>7.3f}"
            )

    with tempfile.TemporaryDirectory() as tmp:
        glb = Path(tmp) / "city.glb"
        result.save(glb)
        print(
            "\ncommand line, fresh process each: bgr render city.glb -o x.png --size "
            f"{size[0]}x{size[1]}"
        )
        for name, _ in backends:
            cmd = [
                sys.executable,
                "-m",
                "bgr",
                "render",
                str(glb),
                "-o",
                str(Path(tmp) / "x.png"),
                "--size",
                f"{size[0]}x{size[1]}",
                "--backend",
                name,
            ]
            runs = []
            for _ in range(3):
                t = time.perf_counter()
                proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
                runs.append(time.perf_counter() - t)
                if proc.returncode != 0:
                    sys.exit(proc.stderr)
            print(
                f"  --backend {name:<6} median {statistics.median(runs):.2f} s, best "
                f"{min(runs):.2f} s"
            )


if __name__ == "__main__":
    main()
