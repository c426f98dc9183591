"""The photograph stage's building mass and camera (Nishida et al. 2018, section 4): a network
recognises the mass family among the 30 stdlib masses and estimates the camera's and the mass's
parameters jointly from the silhouette; a bound-constrained derivative-free search then refines
them on the paper's distance between silhouettes.

The network is a small convolutional network over the silhouette cropped round its box at
:data:`CROP` pixels, plus the box itself (the paper's AlexNets read 227 x 227 images; see
docs/inverse-image.md for what was measured): four 3 x 3 / 5 x 5 convolutions with ReLU and max
pooling, one fully connected layer, and three heads: the family (softmax), the camera's eight
parameters, and every family's mass parameters (only the true family's head is trained on a
sample).  Its weights are ``mass_net.npz``, trained by ``bench/train_mass.py`` (PyTorch, a
training-only extra) on silhouettes the project renders itself; it runs here in numpy.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
from PIL import Image

from . import camera as cam
from .camera import PhotoCamera
from .masses import FAMILIES, MAX_PARAMS, Family, triangles
from .outline import AREA_WEIGHT, Target, centre, silhouette

CROP = 64  # side of the square crop round the silhouette the network reads, pixels
CANVAS = (320, 240)  # a photograph is first stretched to 4:3, as the synthetic ones are
FEATURES = CROP * CROP + 4
WEIGHTS = Path(__file__).with_name("mass_net.npz")


def network_input(mask: np.ndarray) -> np.ndarray:
    """(FEATURES,) float32: the silhouette's coverage in a square crop round its bounding box
    (so that a small building keeps its shape's detail), then the box's centre and size as
    fractions of the photograph (what the camera's position needs).  The photograph is
    stretched to 4:3 first, as the paper stretches photographs to its square input."""
    image = Image.fromarray(mask.astype(np.uint8) * 255).resize(CANVAS, Image.Resampling.NEAREST)
    rows = np.flatnonzero(np.asarray(image).any(axis=1))
    cols = np.flatnonzero(np.asarray(image).any(axis=0))
    if len(rows) == 0:
        return np.zeros(FEATURES, np.float32)
    x0, x1, y0, y1 = cols[0], cols[-1] + 1, rows[0], rows[-1] + 1
    side = max(x1 - x0, y1 - y0)
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    box = (cx - side / 2, cy - side / 2, cx + side / 2, cy + side / 2)
    crop = image.transform((CROP, CROP), Image.Transform.EXTENT, box, Image.Resampling.BILINEAR)
    cover = np.asarray(crop, dtype=np.float32).reshape(-1) / 255.0
    w, h = CANVAS
    where = np.array([cx / w, cy / h, (x1 - x0) / w, (y1 - y0) / h], np.float32)
    return np.concatenate([cover, where])


@lru_cache(maxsize=1)
def load_weights() -> dict[str, np.ndarray]:
    with np.load(WEIGHTS) as data:
        return {k: data[k] for k in data.files}


def _conv(x: np.ndarray, weight: np.ndarray, bias: np.ndarray, stride: int) -> np.ndarray:
    """A 'same'-padded 2-D convolution of (n, c, h, w) by (o, c, k, k) weights, as
    ``torch.nn.Conv2d(padding=k // 2, stride=stride)`` computes it."""
    k = weight.shape[-1]
    pad = k // 2
    padded = np.pad(x, ((0, 0), (0, 0), (pad, pad), (pad, pad)))
    windows = np.lib.stride_tricks.sliding_window_view(padded, (k, k), axis=(2, 3))
    windows = windows[:, :, : x.shape[2] : stride, : x.shape[3] : stride]
    out = np.tensordot(windows, weight, axes=([1, 4, 5], [1, 2, 3]))  # (n, h, w, o)
    return out.transpose(0, 3, 1, 2) + bias[None, :, None, None]


def _relu(x: np.ndarray) -> np.ndarray:
    return np.maximum(x, 0)


def _pool(x: np.ndarray) -> np.ndarray:
    """2 x 2 max pooling of (n, c, h, w), h and w even."""
    n, c, h, w = x.shape
    return x.reshape(n, c, h // 2, 2, w // 2, 2).max(axis=(3, 5))


def forward(net: dict[str, np.ndarray], x: np.ndarray) -> tuple[np.ndarray, ...]:
    """(family logits (n, F), camera (n, 8), mass (n, F, MAX_PARAMS)) in [0, 1] units, of
    (n, FEATURES) network inputs."""
    image = x[:, : CROP * CROP].reshape(-1, 1, CROP, CROP).astype(np.float32) - 0.5
    box = (x[:, CROP * CROP :] - net["box_mean"]) / net["box_std"]
    h = _relu(_conv(image, net["c1_weight"], net["c1_bias"], 2))
    h = _pool(_relu(_conv(h, net["c2_weight"], net["c2_bias"], 1)))
    h = _pool(_relu(_conv(h, net["c3_weight"], net["c3_bias"], 1)))
    h = _pool(_relu(_conv(h, net["c4_weight"], net["c4_bias"], 1)))
    flat = np.concatenate([h.reshape(len(x), -1), box], axis=1)
    hidden = _relu(flat @ net["f1_weight"].T + net["f1_bias"])
    out = hidden @ net["f2_weight"].T + net["f2_bias"]
    n = len(FAMILIES)
    logits = out[:, :n]
    camera = out[:, n : n + 8]
    mass = out[:, n + 8 :].reshape(len(x), n, MAX_PARAMS)
    return logits, camera, mass


@dataclass
class MassFit:
    """A family, its parameters and the camera, with how well they match the silhouette."""

    family: Family
    mass: np.ndarray  # [0, 1] units
    camera: np.ndarray  # [0, 1] units
    distance: float = float("inf")  # the paper's dist(S, S^), pixels of the fitting scale
    evaluations: int = 0
    probability: float = 0.0  # the network's belief in the family

    @property
    def values(self) -> dict[str, float]:
        return self.family.values(self.mass)

    @property
    def photo_camera(self) -> PhotoCamera:
        return PhotoCamera.from_vector(cam.denormalise(self.camera))

    def mask(self, width: int, height: int) -> np.ndarray:
        shown = silhouette(triangles(self.family, self.values), self.photo_camera, width, height)
        return np.zeros((height, width), bool) if shown is None else shown


def estimate(mask: np.ndarray, top: int = 3, net: dict | None = None) -> list[MassFit]:
    """The network's ``top`` most likely families for a silhouette, best first, each with its
    estimated camera and mass parameters."""
    net = net or load_weights()
    logits, camera, mass = forward(net, network_input(mask)[None, :])
    belief = np.exp(logits[0] - logits[0].max())
    belief /= belief.sum()
    order = np.argsort(-logits[0])[:top]
    return [
        MassFit(
            FAMILIES[i],
            np.clip(mass[0, i, : len(FAMILIES[i].params)], 0, 1),
            np.clip(camera[0], 0, 1),
            probability=float(belief[i]),
        )
        for i in order
    ]


class _Objective:
    """dist(S, S^) of a parameter vector (camera then mass, [0, 1] units), the mass's triangles
    kept for the last mass seen: a search that moves the camera alone derives nothing."""

    def __init__(self, family: Family, target: Target) -> None:
        self.family = family
        self.target = target
        self.height, self.width = target.mask.shape
        self.key: bytes | None = None
        self.tris = np.zeros((0, 3, 3))
        self.calls = 0

    def __call__(self, x: np.ndarray) -> float:
        self.calls += 1
        x = np.clip(x, 0, 1)
        mass = x[8:]
        key = np.round(mass, 5).tobytes()
        if key != self.key:
            self.tris = triangles(self.family, self.family.values(mass))
            self.key = key
        camera = PhotoCamera.from_vector(cam.denormalise(x[:8]))
        shown = silhouette(self.tris, camera, self.width, self.height)
        if shown is None:  # a corner behind the camera: as bad as no silhouette
            return float(np.hypot(self.width, self.height)) + AREA_WEIGHT
        return self.target.score(shown)


def _search(objective, x0: np.ndarray, evaluations: int, method: str) -> tuple[np.ndarray, float]:
    from scipy.optimize import minimize

    options: dict[str, float] = {"maxfev": evaluations}
    if method == "Powell":
        options.update(xtol=1e-3, ftol=1e-3)
    else:  # COBYQA: start with steps of a tenth of each range
        options.update(initial_tr_radius=0.1, final_tr_radius=1e-3)
    found = minimize(objective, x0, method=method, bounds=[(0.0, 1.0)] * len(x0), options=options)
    return np.clip(found.x, 0, 1), float(found.fun)


def centred(fit: MassFit, target: Target) -> MassFit:
    """The fit with its principal point moved so that its silhouette's box has the target's
    centre (a shift of the principal point moves the image): a start the searches cannot
    miss by a whole building."""
    mine = centre(fit.mask(target.mask.shape[1], target.mask.shape[0]))
    theirs = centre(target.mask)
    if mine is None or theirs is None:
        return fit
    height, width = target.mask.shape
    shift = (theirs - mine) / (np.array([width, height]) / 2)  # in principal-point units
    camera = cam.denormalise(fit.camera)
    camera[4:6] += shift
    moved = np.clip(cam.normalise(camera), 0, 1)
    return MassFit(fit.family, fit.mass, moved, fit.distance, fit.evaluations, fit.probability)


def refine_camera(fit: MassFit, target: Target, evaluations: int = 120) -> MassFit:
    """The camera alone moved to a local minimum of the distance (Powell: no derivation per
    step, a few milliseconds each), from the network's camera centred on the target."""
    fit = centred(fit, target)
    objective = _Objective(fit.family, target)

    def camera_only(c: np.ndarray) -> float:
        return objective(np.concatenate([c, fit.mass]))

    camera, distance = _search(camera_only, fit.camera, evaluations, "Powell")
    return MassFit(fit.family, fit.mass, camera, distance, objective.calls, fit.probability)


def refine(fit: MassFit, target: Target, evaluations: int = 300, method: str = "COBYQA") -> MassFit:
    """The fit moved to a local minimum of dist(S, S^) within the parameters' ranges: the
    camera alone first (:func:`refine_camera`, a fifth of the evaluations), then camera and
    mass together by a bound-constrained derivative-free search.  The paper uses BOBYQA (its
    Python port is GPL-3); scipy's COBYQA, Powell's successor to it, is the default, Powell's
    conjugate directions the alternative (docs/inverse-image.md has both measured)."""
    first = refine_camera(fit, target, evaluations // 5)
    objective = _Objective(fit.family, target)
    x, distance = _search(
        objective,
        np.concatenate([first.camera, first.mass]),
        evaluations - first.evaluations,
        method,
    )
    if distance > first.distance:  # the search may end on a worse point than it started
        return MassFit(
            fit.family,
            first.mass,
            first.camera,
            first.distance,
            first.evaluations + objective.calls,
            fit.probability,
        )
    return MassFit(
        fit.family, x[8:], x[:8], distance, first.evaluations + objective.calls, fit.probability
    )
