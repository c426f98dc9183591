"""Train the window-pixel perceptrons of bgr.inverse.image.pixels on the CMP façades (issue 28),
with five-fold cross-validation, and write their weights.

    python bench/train_facade.py [--cmp DIR] [--out inverse/image/window_pixels.npz]

Each façade is resampled to :data:`bgr.inverse.image.facade.WORK_HEIGHT` rows, its features
computed there, and :data:`SAMPLES` pixels drawn from it (a fixed seed); the label of a pixel is
"window" for CMP window (3), door (4) and shop (12), as the paper's Table 4 counts them.  Each
perceptron (:data:`HIDDEN` tanh units, logistic output) is fitted by Adam on the cross-entropy.
The first pass is fitted on the features; the second (auto-context) on the features and the
context of the first pass's probability map, that map being, for each training façade, the one
of a first pass fitted without it (:data:`INNER` folds inside the training façades: the second
pass learns from maps like those it will see).  The decision threshold is the one that
maximises window F1 on the training pixels, and the grid's two levels the pair of
:data:`LEVELS` that maximises it on the training façades.  Five folds of 20 façades in file
order: each fold's model is trained on the other 80 and scored on its 20 by
``bench/facade_cmp.py``'s measures, with and without section 5.2's boundary refinement; the
shipped weights are trained on all 100.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from PIL import Image

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))

SAMPLES = 8000  # pixels drawn from each façade
HIDDEN = 16
STEPS = 3000
BATCH = 4096
SEED = 28
INNER = 4  # folds inside the training façades for the second pass's first-pass maps

Facade = tuple[np.ndarray, np.ndarray, np.ndarray]
"""A façade's features (h, w, F) at the working scale, window truth (h, w), sampled pixels."""


def load(photo: Path) -> Facade:
    """The features, truth and :data:`SAMPLES` sampled pixel indices of a façade."""
    from bgr.inverse.image.facade import working_image
    from bgr.inverse.image.pixels import features

    rgb = np.asarray(Image.open(photo).convert("RGB"))
    labels = np.asarray(Image.open(photo.with_suffix(".png")))
    work = working_image(rgb)
    small = np.asarray(
        Image.fromarray(labels).resize((work.shape[1], work.shape[0]), Image.Resampling.NEAREST)
    )
    x = features(work)
    y = np.isin(small, (3, 4, 12))
    rng = np.random.default_rng([SEED, int(photo.stem[-4:])])
    pick = rng.choice(y.size, min(SAMPLES, y.size), replace=False)
    return x, y, pick


def samples(data: list[Facade], members: list[int], maps: dict[int, np.ndarray] | None = None):
    """(x, y) of the sampled pixels of ``members``: their features, and with ``maps`` (first-pass
    probability maps) their context features too."""
    from bgr.inverse.image.pixels import context

    xs, ys = [], []
    for i in members:
        x, y, pick = data[i]
        if maps is not None:
            x = np.concatenate([x, context(maps[i])], axis=-1)
        xs.append(x.reshape(-1, x.shape[-1])[pick])
        ys.append(y.reshape(-1)[pick])
    return np.concatenate(xs).astype(np.float64), np.concatenate(ys)


def first_pass_map(net: dict[str, np.ndarray], facade: Facade) -> np.ndarray:
    from bgr.inverse.image.pixels import forward

    x = facade[0]
    return forward(net, x.reshape(-1, x.shape[-1]).astype(np.float64)).reshape(x.shape[:2])


def fit(data: list[Facade], members: list[int], seed: int = SEED) -> dict[str, np.ndarray]:
    """Both passes fitted on the façades ``members``; the threshold is the second pass's."""
    from bgr.inverse.image.pixels import SECOND

    first = train(*samples(data, members), seed)
    maps = {}
    for j in range(INNER):  # each member's first-pass map from a first pass fitted without it
        held = members[j::INNER]
        rest = [i for i in members if i not in held]
        inner = train(*samples(data, rest), seed + 1 + j)
        maps.update({i: first_pass_map(inner, data[i]) for i in held})
    if not INNER:
        maps = {i: first_pass_map(first, data[i]) for i in members}
    second = train(*samples(data, members, maps), seed)
    net = {k: v for k, v in first.items() if k != "threshold"}
    net.update({SECOND + k: v for k, v in second.items() if k != "threshold"})
    net["threshold"] = second["threshold"]
    return net


def train(x: np.ndarray, y: np.ndarray, seed: int = SEED) -> dict[str, np.ndarray]:
    """The perceptron fitted to (x, y) by Adam, and its F1-best threshold."""
    from bgr.inverse.image.pixels import forward

    rng = np.random.default_rng(seed)
    mean, std = x.mean(axis=0), x.std(axis=0) + 1e-6
    z = (x - mean) / std
    f = x.shape[1]
    params = {
        "w1": rng.normal(0, 1 / np.sqrt(f), (f, HIDDEN)),
        "b1": np.zeros(HIDDEN),
        "w2": rng.normal(0, 1 / np.sqrt(HIDDEN), (HIDDEN, 1)),
        "b2": np.zeros(1),
    }
    m = {k: np.zeros_like(v) for k, v in params.items()}
    v = {k: np.zeros_like(p) for k, p in params.items()}
    target = y.astype(np.float64)
    for step in range(1, STEPS + 1):
        batch = rng.integers(0, len(z), BATCH)
        zb, tb = z[batch], target[batch]
        hidden = np.tanh(zb @ params["w1"] + params["b1"])
        p = 1 / (1 + np.exp(-(hidden @ params["w2"] + params["b2"])[:, 0]))
        d_out = (p - tb)[:, None] / BATCH
        grads = {
            "w2": hidden.T @ d_out,
            "b2": d_out.sum(axis=0),
        }
        d_hidden = (d_out @ params["w2"].T) * (1 - hidden**2)
        grads["w1"] = zb.T @ d_hidden
        grads["b1"] = d_hidden.sum(axis=0)
        rate = 0.01 if step < 0.7 * STEPS else 0.002
        for k in params:
            m[k] = 0.9 * m[k] + 0.1 * grads[k]
            v[k] = 0.999 * v[k] + 0.001 * grads[k] ** 2
            mhat = m[k] / (1 - 0.9**step)
            vhat = v[k] / (1 - 0.999**step)
            params[k] -= rate * mhat / (np.sqrt(vhat) + 1e-8)
    net = {"mean": mean, "std": std, **params}
    prob = forward(net, x)
    best, best_f1 = 0.5, -1.0
    for t in np.linspace(0.2, 0.8, 25):
        guess = prob >= t
        tp = (guess & y).sum()
        f1 = 2 * tp / max(1, 2 * tp + (guess & ~y).sum() + (~guess & y).sum())
        if f1 > best_f1:
            best, best_f1 = float(t), float(f1)
    net["threshold"] = np.array(best)
    return {k: np.asarray(val, dtype=np.float64) for k, val in net.items()}


LEVELS = [
    (0.35, 0.5),
    (0.35, 0.4),
    (0.3, 0.45),
    (0.3, 0.4),
    (0.3, 0.35),
    (0.25, 0.4),
    (0.25, 0.35),
    (0.2, 0.3),
]
"""(row, column) levels of the grid (bgr.inverse.image.facade.window_grid) tried on the
training façades; the one with the best window F1 there goes with the weights."""


def choose_levels(net: dict[str, np.ndarray], photos: list[Path]) -> dict[str, np.ndarray]:
    """``net`` with the grid levels of :data:`LEVELS` that score best on ``photos`` (each
    photograph's probability map computed once, parsed at each pair of levels)."""
    import facade_cmp

    from bgr.inverse.image import facade

    maps = []
    for photo in photos:
        rgb = np.asarray(Image.open(photo).convert("RGB"))
        work = facade.working_image(rgb)
        maps.append((rgb, work, facade.window_probability(work, net)))
    best, best_f1 = LEVELS[0], -1.0
    for row, column in LEVELS:
        trial = {**net, "row_level": np.array(row), "column_level": np.array(column)}
        rows = [
            facade_cmp.measure(facade.parse_probability(*m, trial, color=False), photo)
            for m, photo in zip(maps, photos, strict=True)
        ]
        tp, fp, fn = (sum(r[k] for r in rows) for k in (1, 2, 3))
        f1 = 2 * tp / max(1, 2 * tp + fp + fn)
        if f1 > best_f1:
            best, best_f1 = (row, column), f1
    return {**net, "row_level": np.array(best[0]), "column_level": np.array(best[1])}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cmp", type=Path, default=ROOT.parent / "shared/data/facades/cmp")
    ap.add_argument("--out", type=Path, default=ROOT / "inverse/image/window_pixels.npz")
    ap.add_argument("--folds", type=int, default=5)
    args = ap.parse_args()
    import facade_cmp

    photos = sorted(args.cmp.glob("cmp_b*.jpg"))
    if not photos:
        sys.exit(f"{args.cmp}: no CMP façades here")
    start = time.perf_counter()
    data = [load(p) for p in photos]
    print(f"features of {len(photos)} façades in {time.perf_counter() - start:.1f} s")
    size = len(photos) // args.folds
    rows, plain = [], []
    for k in range(args.folds):
        test = set(range(k * size, (k + 1) * size if k < args.folds - 1 else len(photos)))
        members = [i for i in range(len(photos)) if i not in test]
        t0 = time.perf_counter()
        net = choose_levels(fit(data, members), [photos[i] for i in members])
        fold = facade_cmp.evaluate([photos[i] for i in sorted(test)], net)
        unrefined = facade_cmp.evaluate([photos[i] for i in sorted(test)], net, refine=False)
        rows += fold
        plain += unrefined
        print(
            f"fold {k + 1}: trained in {time.perf_counter() - t0:.1f} s, threshold "
            f"{float(net['threshold']):.2f}, levels {float(net['row_level'])}/"
            f"{float(net['column_level'])}, {facade_cmp.summary(fold)}; without the "
            f"refinement {facade_cmp.summary(unrefined)}",
            flush=True,
        )
    print(f"cross-validated, all {len(rows)}: {facade_cmp.summary(rows)}")
    print(f"  without the refinement: {facade_cmp.summary(plain)}")
    net = choose_levels(fit(data, list(range(len(photos)))), photos)
    np.savez(args.out, **net)
    print(f"wrote {args.out} ({args.out.stat().st_size} bytes)")


if __name__ == "__main__":
    main()
