"""Train the photograph stage's mass-and-camera network (bgr.inverse.image.mass_fit) on
silhouettes the project renders itself (bench/mass_views.py), and write its weights.

    pip install torch   # training only: bgr runs the network in numpy
    python bench/train_mass.py [--masses 200] [--views 16] [--epochs 12] [--out PATH]

The training set is ``--masses`` random masses of each of the 30 families, ``--views`` accepted
camera views of each, from seed :data:`TRAIN_SEED`; 10 % of it is held out to report the
network's own accuracy while training.  The synthetic test set of bench/mass_synthetic.py is
drawn from another seed and is never seen here.

The network (see ``bgr.inverse.image.mass_fit.forward``, which runs it): the silhouette cropped
round its box at 64 x 64 pixels, a 5 x 5 convolution of stride 2 and three 3 x 3 convolutions
of :data:`WIDTHS` channels with ReLU and 2 x 2 max pooling, the box's four numbers joined, one
ReLU layer of :data:`HIDDEN` units and three heads (family logits, 8 camera parameters, every
family's mass parameters), fitted by Adam (cosine-decayed rate) on cross-entropy plus the
squared error of the camera and of the true family's parameters (``REGRESSION`` weights the
two).  Seeded; PyTorch on the CPU (two threads) is deterministic enough that the same command
writes weights that score the same to three digits.
"""

from __future__ import annotations

import argparse
import math
import pickle
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))

TRAIN_SEED = 2801
WIDTHS = (16, 32, 64, 64)
HIDDEN = 512
BATCH = 256
RATE = 1e-3
REGRESSION = 4.0


def dataset(masses: int, views: int, seed: int, cache: Path | None = None):
    """(inputs (n, mass_fit.FEATURES) float32, family (n,), camera (n, 8), mass
    (n, MAX_PARAMS), mask (n, MAX_PARAMS)) of the rendered training views."""
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


def _network(n_out: int):
    """The torch module whose state dict ``mass_fit.forward`` reads (names matter)."""
    import torch
    from torch import nn
    from torch.nn import functional as F

    from bgr.inverse.image.mass_fit import CROP

    a, b, c, d = WIDTHS
    side = CROP // 16  # a stride-2 convolution and three poolings

    class Net(nn.Module):
        def __init__(self) -> None:
            super().__init__()
            self.c1 = nn.Conv2d(1, a, 5, 2, 2)
            self.c2 = nn.Conv2d(a, b, 3, 1, 1)
            self.c3 = nn.Conv2d(b, c, 3, 1, 1)
            self.c4 = nn.Conv2d(c, d, 3, 1, 1)
            self.f1 = nn.Linear(d * side * side + 4, HIDDEN)
            self.f2 = nn.Linear(HIDDEN, n_out)

        def forward(self, image, box):
            h = F.relu(self.c1(image))
            h = F.max_pool2d(F.relu(self.c2(h)), 2)
            h = F.max_pool2d(F.relu(self.c3(h)), 2)
            h = F.max_pool2d(F.relu(self.c4(h)), 2)
            return self.f2(F.relu(self.f1(torch.cat([h.flatten(1), box], 1))))

    return Net()


def train(data, epochs: int, seed: int = TRAIN_SEED, log=print) -> dict[str, np.ndarray]:
    """The trained network's weights, as ``mass_fit.forward`` reads them."""
    import torch
    from torch.nn import functional as F

    from bgr.inverse.image.mass_fit import CROP
    from bgr.inverse.image.masses import FAMILIES, MAX_PARAMS

    x, family, camera, mass, mask = data
    torch.set_num_threads(2)
    torch.manual_seed(seed)
    n_fam = len(FAMILIES)
    net = _network(n_fam + 8 + n_fam * MAX_PARAMS)
    box_mean = x[:, CROP * CROP :].mean(axis=0)
    box_std = x[:, CROP * CROP :].std(axis=0) + 1e-3

    def batch(rows):
        image = torch.from_numpy(x[rows, : CROP * CROP].reshape(-1, 1, CROP, CROP) - 0.5)
        box = torch.from_numpy((x[rows, CROP * CROP :] - box_mean) / box_std)
        return image.float(), box.float()

    optimiser = torch.optim.Adam(net.parameters(), RATE)
    rng = np.random.default_rng(seed)
    size = min(BATCH, len(x))  # a smoke test's few views make one batch
    steps = epochs * (len(x) // size)
    step = 0
    for epoch in range(epochs):
        order = rng.permutation(len(x))
        for first in range(0, len(order) - size + 1, size):
            for group in optimiser.param_groups:  # cosine decay
                group["lr"] = RATE * 0.5 * (1 + math.cos(math.pi * step / steps))
            rows = order[first : first + size]
            out = net(*batch(rows))
            truth = torch.from_numpy(family[rows]).long()
            loss = F.cross_entropy(out[:, :n_fam], truth)
            cam_err = out[:, n_fam : n_fam + 8] - torch.from_numpy(camera[rows]).float()
            heads = out[:, n_fam + 8 :].reshape(len(rows), n_fam, MAX_PARAMS)
            mass_err = heads[torch.arange(len(rows)), truth] - torch.from_numpy(mass[rows]).float()
            mass_err = mass_err * torch.from_numpy(mask[rows]).float()
            regression = (cam_err.square().sum() + mass_err.square().sum()) / (2 * len(rows))
            loss = loss + REGRESSION * regression
            optimiser.zero_grad()
            loss.backward()
            optimiser.step()
            step += 1
        log(f"epoch {epoch + 1}: loss {loss.item():.3f}")
    weights = {k.replace(".", "_"): v.detach().numpy() for k, v in net.state_dict().items()}
    box = {"box_mean": box_mean.astype(np.float32), "box_std": box_std.astype(np.float32)}
    return {**weights, **box}


def scores(net: dict, data) -> dict[str, float]:
    """Family accuracy and RMSE of the [0, 1] camera and (true family's) mass parameters."""
    from bgr.inverse.image.mass_fit import forward

    x, family, camera, mass, mask = data
    parts = [forward(net, x[i : i + 500]) for i in range(0, len(x), 500)]
    logits, cam_out, mass_out = (np.concatenate(p) for p in zip(*parts, strict=True))
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
    parser.add_argument("--epochs", type=int, default=12)
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
