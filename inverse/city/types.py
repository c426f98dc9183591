"""Component types: dissimilarity clustering of components (paper, section IV.D).

Level 0 is lossless within the tolerance: components whose meshes are equal on the key grid
(same key, see :mod:`.components`) are one type, so deriving the grammar gives every input
triangle back within it.  Above it, the paper's k-means
hierarchy: k-means on the level-0 types' feature vectors with k = n/2, then on the cluster
centres with k halved again, until k = 1; level l is the l-th cut through that tree.  The
dissimilarity is d_ij = ||W (F_i - F_j)|| (equation 1), W a unit-length weight vector.  The
representative of a cluster (its terminal) is the member closest to the cluster's mean, or the one
with the fewest triangles.  ``--threshold t_d`` picks the coarsest level at which every member is
within t_d of its representative.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.cluster.vq import kmeans2

from .components import FEATURES, Component, features


@dataclass
class Level:
    """One de-instancing result: a type per level-0 type, and each type's representative."""

    index: int
    of_base: np.ndarray  # (n0,) type of each level-0 type at this level
    representative: np.ndarray  # (n,) the level-0 type whose mesh stands for each type
    error: float  # the largest dissimilarity of a level-0 type to its representative


@dataclass
class Types:
    """All levels for one set of components."""

    base_of: np.ndarray  # (nc,) the level-0 type of each component
    base_first: np.ndarray  # (n0,) a component of each level-0 type (its mesh is the type's)
    base_count: np.ndarray  # (n0,) instances of each level-0 type
    vectors: np.ndarray  # (n0, len(FEATURES)) weighted feature vectors
    levels: list[Level]


def weights(given: dict[str, float] | None = None) -> np.ndarray:
    """The unit-length weight vector W: 1 for every feature unless ``given`` says otherwise."""
    w = np.ones(len(FEATURES))
    for name, value in (given or {}).items():
        w[FEATURES.index(name)] = value
    norm = np.linalg.norm(w)
    return w / norm if norm > 0 else w


def cluster(
    components: list[Component],
    *,
    feature_weights: dict[str, float] | None = None,
    representative: str = "mean",
    seed: int = 0,
    progress=None,
) -> Types:
    """Level 0 by equal meshes, then the k-means hierarchy on the level-0 types; ``progress``
    (a tqdm bar) counts the level-0 types as their feature vectors are made."""
    base_of, first, count = _equal_meshes(components)
    w = weights(feature_weights)
    vectors = np.array([_counted(features(components[i]), progress) for i in first]) * w
    triangles = np.array([len(components[i].faces) for i in first])
    n0 = len(first)
    levels = [Level(0, np.arange(n0), np.arange(n0), 0.0)]
    rng = np.random.default_rng(seed)
    labels = np.arange(n0)
    points = vectors
    k = n0
    while k > 1:
        k = max(1, k // 2)
        if len(points) <= k:
            continue
        if k == 1:
            step = np.zeros(len(points), dtype=np.int64)
        else:
            _, step = kmeans2(points, k, minit="++", seed=rng, missing="warn")
        used, step = np.unique(step, return_inverse=True)  # drop empty clusters
        labels = step[labels]
        points = np.array([vectors[labels == j].mean(axis=0) for j in range(len(used))])
        reps = _representatives(labels, vectors, points, triangles, representative)
        error = float(np.max(np.linalg.norm(vectors - vectors[reps[labels]], axis=1)))
        levels.append(Level(len(levels), labels.copy(), reps, error))
    return Types(base_of, first, count, vectors, levels)


def _equal_meshes(components: list[Component]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Level 0: (the type of each component, a component of each type, instances of each type),
    components of one key being one type, types numbered by first appearance."""
    keys = [c.key for c in components]
    unique, first, base_of, count = np.unique(
        np.array(keys), return_index=True, return_inverse=True, return_counts=True
    )
    order = np.argsort(first, kind="stable")
    renumber = np.empty(len(order), dtype=np.int64)
    renumber[order] = np.arange(len(order))
    return renumber[base_of.reshape(-1)], first[order], count[order]


def base_types(components: list[Component]) -> Types:
    """Level 0 alone (no feature vectors, no hierarchy above it): what a level-0 grammar needs."""
    base_of, first, count = _equal_meshes(components)
    n0 = len(first)
    level0 = Level(0, np.arange(n0), np.arange(n0), 0.0)
    return Types(base_of, first, count, np.zeros((n0, len(FEATURES))), [level0])


def _counted(value, progress):
    """``value``, after telling ``progress`` (a tqdm bar, or None) that one more is done."""
    if progress is not None:
        progress.update()
    return value


def _representatives(
    labels: np.ndarray, vectors: np.ndarray, means: np.ndarray, triangles: np.ndarray, how: str
) -> np.ndarray:
    reps = np.empty(len(means), dtype=np.int64)
    for j in range(len(means)):
        members = np.flatnonzero(labels == j)
        if how == "fewest":
            reps[j] = members[np.argmin(triangles[members])]
        else:
            reps[j] = members[np.argmin(np.linalg.norm(vectors[members] - means[j], axis=1))]
    return reps


def level_for(types: Types, *, level: int | None = None, threshold: float | None = None) -> Level:
    """The level asked for: by number (clamped to the coarsest), or the coarsest whose error is
    within ``threshold``; level 0 when neither is given."""
    if threshold is not None:
        fitting = [lv for lv in types.levels if lv.error <= threshold]
        return fitting[-1]
    if level is None:
        return types.levels[0]
    return types.levels[min(max(level, 0), len(types.levels) - 1)]
