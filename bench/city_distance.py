"""Benchmark: bgr.inverse.city.distance.surface_distances on whole cities.

    python bench/make_city.py --buildings 16000 -o /tmp/city16k.obj     # about 1 M triangles
    python bench/city_distance.py /tmp/city16k.obj                     # vs itself moved 0.5 mm
    python bench/city_distance.py /tmp/city16k.obj --jitter 0.05       # every vertex moved
    python bench/city_distance.py /tmp/city16k.obj --other B.obj       # vs another mesh

Compares a mesh with a copy of itself moved ``--shift`` metres along x (the level-0 case of
``bgr infer --kind city``: every sample lies within a millimetre of the other surface), with a
copy whose vertices are moved at random (``--jitter``, metres, normal per coordinate), or with
another mesh (``--other``: samples far from the other surface take the slow path; see the
module's docstring).  Prints the wall time of the call, the samples, the distances, and the
process's peak resident memory before and after it.
"""

from __future__ import annotations

import argparse
import os
import resource
import time
from pathlib import Path

import numpy as np
import trimesh

from bgr.inverse.city.distance import surface_distances


def load(path: Path) -> tuple[np.ndarray, np.ndarray]:
    mesh = trimesh.load(path, force="mesh", process=False)
    assert isinstance(mesh, trimesh.Trimesh)
    return np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64)


def peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mesh", type=Path)
    ap.add_argument("--other", type=Path, default=None)
    ap.add_argument("--shift", type=float, default=0.0005)
    ap.add_argument("--jitter", type=float, default=0.0)
    ap.add_argument("--samples-per-m2", type=float, default=4.0)
    ap.add_argument("--max-samples", type=int, default=1_000_000)
    args = ap.parse_args()
    start = time.perf_counter()
    av, af = load(args.mesh)
    if args.other is not None:
        bv, bf = load(args.other)
        what = str(args.other)
    elif args.jitter:
        bv, bf = av + np.random.default_rng(1).normal(0.0, args.jitter, av.shape), af
        what = f"itself, every vertex moved by N(0, {args.jitter} m) per coordinate"
    else:
        bv, bf = av + [args.shift, 0.0, 0.0], af
        what = f"itself moved {args.shift} m along x"
    print(f"{args.mesh}: {len(af):,} triangles vs {what}: {len(bf):,} triangles")
    print(
        f"loaded in {time.perf_counter() - start:.1f} s; {os.cpu_count()} cpus, load average "
        f"{os.getloadavg()[0]:.2f}; peak {peak_mb():.0f} MB before the call",
        flush=True,
    )
    start = time.perf_counter()
    d = surface_distances(
        av, af, bv, bf, samples_per_m2=args.samples_per_m2, max_samples=args.max_samples
    )
    took = time.perf_counter() - start
    print(f"surface_distances: {took:.1f} s, {d.samples:,} samples, peak {peak_mb():.0f} MB")
    print(
        f"hausdorff {d.hausdorff:.9g} (A->B {d.a_to_b_max:.9g}, B->A {d.b_to_a_max:.9g}), "
        f"chamfer {d.chamfer:.9g} (means {d.a_to_b_mean:.9g}, {d.b_to_a_mean:.9g}); "
        f"worst at {np.round(d.worst, 3).tolist() if d.worst is not None else None}"
    )


if __name__ == "__main__":
    main()
