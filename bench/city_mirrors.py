"""How many of an inferred city's level-0 types have a mirror image among the others.

    python bench/city_mirrors.py ../shared/data/cities/zurich_lod2.obj [more cities...]

Issue 29 asks that two components be one type when a mirror maps one onto the other.  Before
building it this counts what it would merge: each type's representative mesh mirrored across
its box (x -> width - x, the triangles turned back outward), in each of its box's four quarter
turns, keyed on the same grid as the types (``components.mesh_key``), looked up among the
other types' keys.
"""

from __future__ import annotations

import sys
import warnings

import numpy as np

from bgr.inverse.city.components import key_grid, mesh_key
from bgr.inverse.city.pipeline import Options, decompose, place
from bgr.inverse.city.read import read_city
from bgr.inverse.city.types import cluster, level_for


def mirrored_keys(vertices: np.ndarray, faces: np.ndarray, grid: float) -> list[str]:
    """The keys of the mesh mirrored across x in its box, in the box's four quarter turns."""
    width = vertices[:, 0].max()
    turned = np.column_stack([width - vertices[:, 0], vertices[:, 1], vertices[:, 2]])
    flipped = faces[:, ::-1]
    keys = []
    for _ in range(4):
        low = turned.min(axis=0) * [1.0, 0.0, 1.0]
        keys.append(mesh_key(turned - low, flipped, grid))
        extent = turned[:, 0].max()
        turned = np.column_stack([turned[:, 2], turned[:, 1], extent - turned[:, 0]])
    return keys


def main() -> None:
    options = Options(progress=False)
    grid = key_grid(options.tolerance)
    for path in sys.argv[1:]:
        scene = read_city(path, up=options.up, lod=options.lod)
        comps = decompose(scene, options)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            types = cluster(comps, seed=options.seed)
        placed = place(scene, comps, types, level_for(types, level=0), options)
        reps = placed.term_mesh
        own = {c.key for c in reps}
        paired = sum(
            any(k in own and k != c.key for k in mirrored_keys(c.vertices, c.faces, grid))
            for c in reps
        )
        print(f"{path}: {len(reps)} types at level 0, {paired} with a mirror image among them")


if __name__ == "__main__":
    main()
