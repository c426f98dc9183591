"""Train the photograph stage's mass-and-camera network (bgr.inverse.image.mass_fit, issue 28) on
silhouettes the project renders itself (bench/mass_views.py), and write its weights.

    python bench/train_mass.py [--masses 200] [--views 16] [--epochs 30] [--out PATH]

The training set is ``--masses`` random masses of each of the 30 families, ``--views`` accepted
camera views of each, from seed :data:`TRAIN_SEED`; 10 % of it is held out to report the
network's own accuracy while training.  The synthetic test set of bench/mass_synthetic.py is
drawn from another seed and is never seen here.

The network: the silhouette cropped round its box at 48 x 48 pixels and the box (see
``network_input``), two ReLU layers of :data:`HIDDEN` units, and three
heads (family logits, 8 camera parameters, every family's mass parameters), fitted by Adam on
cross-entropy plus the squared error of the camera and of the true family's parameters
(``REGRESSION`` weights the two).  Everything is seeded: the same command writes the same file.
"""

from __future__ import annotations

import argparse
import pickle
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))

TRAIN_SEED = 2801
HIDDEN = 384
BATCH = 256
RATE = 1e-3
REGRESSION = 4.0


def dataset(masses: int, views: int, seed: int, cache: Path | None = None):
    """(inputs (n, 1728) float32, family (n,), camera (n, 8), mass (n, MAX_PARAMS), mask
    (n, MAX_PARAMS)) of the rendered training views."""
    from mass_views import ASPECT, draw_view, sample

    from bgr.inverse.image.mass_fit import CANVAS, network_input
    from bgr.inverse.image.masses import MAX_PARAMS

    if cache is not None and cache.exists():
        with open(cache, "rb") as f:
            found = pickle.load(f)
    else:
        start = time.perf_counter()
        found = sample(seed, masses, views)
        print(f"{len(found)} views in {time.perf_counter() - start:.0f} s", flush=True)
        if cache is not None:
            with open(cache, "wb") as f:
                pickle.dump(found, f)
    assert CANVAS[0] * ASPECT[1] == CANVAS[1] * ASPECT[0]
    x = np.stack([network_input(draw_view(v, *CANVAS)) for v in found])
    family = np.array([v.family for v in found])
    camera = np.stack([v.camera for v in found])
    mass = np.zeros((len(found), MAX_PARAMS))
    mask = np.zeros((len(found), MAX_PARAMS))
    for i, v in enumerate(found):
        mass[i, : len(v.mass)] = v.mass
        mask[i, : len(v.mass)] = 1
    return x, family, camera, mass, mask


def train(data, epochs: int, seed: int = TRAIN_SEED, log=print) -> dict[str, np.ndarray]:
    from bgr.inverse.image.mass_fit import forward
    from bgr.inverse.image.masses import FAMILIES, MAX_PARAMS

    x, family, camera, mass, mask = data
    n_fam = len(FAMILIES)
    rng = np.random.default_rng(seed)
    mean = x.mean(axis=0)
    std = x.std(axis=0) + 0.05
    f = x.shape[1]
    outs = n_fam + 8 + n_fam * MAX_PARAMS
    params = {
        "w1": rng.normal(0, np.sqrt(2 / f), (f, HIDDEN)).astype(np.float32),
        "b1": np.zeros(HIDDEN, np.float32),
        "w2": rng.normal(0, np.sqrt(2 / HIDDEN), (HIDDEN, HIDDEN)).astype(np.float32),
        "b2": np.zeros(HIDDEN, np.float32),
        "w3": rng.normal(0, np.sqrt(1 / HIDDEN), (HIDDEN, outs)).astype(np.float32),
        "b3": np.zeros(outs, np.float32),
    }
    params["b3"][n_fam:] = 0.5
    adam_m = {k: np.zeros_like(v) for k, v in params.items()}
    adam_v = {k: np.zeros_like(v) for k, v in params.items()}
    z_all = ((x - mean) / std).astype(np.float32)
    step = 0
    for epoch in range(epochs):
        order = rng.permutation(len(x))
        rate = RATE * (0.5 * (1 + np.cos(np.pi * epoch / epochs)))  # cosine decay
        for first in range(0, len(order) - BATCH + 1, BATCH):
            b = order[first : first + BATCH]
            z = z_all[b]
            a1 = z @ params["w1"] + params["b1"]
            h1 = np.maximum(a1, 0)
            a2 = h1 @ params["w2"] + params["b2"]
            h2 = np.maximum(a2, 0)
            out = h2 @ params["w3"] + params["b3"]
            # family: softmax cross-entropy
            logits = out[:, :n_fam]
            p = np.exp(logits - logits.max(axis=1, keepdims=True))
            p /= p.sum(axis=1, keepdims=True)
            d_out = np.zeros_like(out)
            d_out[:, :n_fam] = p
            d_out[np.arange(len(b)), family[b]] -= 1
            # camera and the true family's mass parameters: squared error
            d_out[:, n_fam : n_fam + 8] = REGRESSION * (out[:, n_fam : n_fam + 8] - camera[b])
            heads = out[:, n_fam + 8 :].reshape(len(b), n_fam, MAX_PARAMS)
            d_heads = np.zeros_like(heads)
            rows = np.arange(len(b))
            d_heads[rows, family[b]] = REGRESSION * (heads[rows, family[b]] - mass[b]) * mask[b]
            d_out[:, n_fam + 8 :] = d_heads.reshape(len(b), -1)
            d_out /= len(b)
            grads = {"w3": h2.T @ d_out, "b3": d_out.sum(axis=0)}
            d2 = (d_out @ params["w3"].T) * (a2 > 0)
            grads["w2"], grads["b2"] = h1.T @ d2, d2.sum(axis=0)
            d1 = (d2 @ params["w2"].T) * (a1 > 0)
            grads["w1"], grads["b1"] = z.T @ d1, d1.sum(axis=0)
            step += 1
            for k, g in grads.items():
                adam_m[k] = 0.9 * adam_m[k] + 0.1 * g
                adam_v[k] = 0.999 * adam_v[k] + 0.001 * g * g
                m_hat = adam_m[k] / (1 - 0.9**step)
                v_hat = adam_v[k] / (1 - 0.999**step)
                params[k] -= (rate * m_hat / (np.sqrt(v_hat) + 1e-8)).astype(np.float32)
        net = {**params, "mean": mean.astype(np.float32), "std": std.astype(np.float32)}
        logits, _, _ = forward(net, x[:2000])
        log(
            f"epoch {epoch + 1}: training accuracy {np.mean(logits.argmax(1) == family[:2000]):.3f}"
        )
    return {**params, "mean": mean.astype(np.float32), "std": std.astype(np.float32)}


def scores(net: dict, data) -> dict[str, float]:
    """Family accuracy and RMSE of the [0, 1] camera and (true family's) mass parameters."""
    from bgr.inverse.image.mass_fit import forward

    x, family, camera, mass, mask = data
    logits, cam_out, mass_out = forward(net, x)
    rows = np.arange(len(x))
    mass_err = (mass_out[rows, family] - mass) * mask
    return {
        "accuracy": float(np.mean(logits.argmax(1) == family)),
        "camera_rmse": float(np.sqrt(np.mean((np.clip(cam_out, 0, 1) - camera) ** 2))),
        "mass_rmse": float(np.sqrt((mass_err**2).sum() / mask.sum())),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--masses", type=int, default=200, help="masses per family")
    parser.add_argument("--views", type=int, default=16, help="views per mass")
    parser.add_argument("--epochs", type=int, default=30)
    parser.add_argument("--cache", help="a file to keep the sampled views in (pickle)")
    parser.add_argument("--out", default=str(ROOT / "inverse" / "image" / "mass_net.npz"))
    args = parser.parse_args()
    data = dataset(args.masses, args.views, TRAIN_SEED, Path(args.cache) if args.cache else None)
    n = len(data[0])
    held = np.arange(n) % 10 == 9
    train_part = tuple(d[~held] for d in data)
    held_part = tuple(d[held] for d in data)
    start = time.perf_counter()
    net = train(train_part, args.epochs)
    print(
        f"trained in {time.perf_counter() - start:.0f} s; held-out views: {scores(net, held_part)}"
    )
    np.savez_compressed(args.out, **net)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
