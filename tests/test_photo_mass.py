"""The photograph stage's camera, masses, silhouettes and fit (issue 28, section 4 of Nishida et
al. 2018): what ``bgr infer --kind image`` relies on before it looks at a façade."""

from __future__ import annotations

import numpy as np
import pytest

from bgr.inverse.image import camera as cam
from bgr.inverse.image.camera import PhotoCamera
from bgr.inverse.image.mass_fit import MassFit, _conv, _pool, estimate, refine
from bgr.inverse.image.masses import BY_RULE, FAMILIES, side_faces, triangles
from bgr.inverse.image.outline import Target, boundary, iou

VIEW = [15.0, 40.0, 3.0, 60.0, 0.1, 0.2, 2.0, 5.0]  # a street-level view inside the ranges


def test_camera_is_a_proper_rotation_and_sees_the_street_face_and_the_right_side():
    camera = PhotoCamera(10, 45, 5, 60, 0, 0, 0, 0)
    r = camera.rotation()
    assert np.allclose(r @ r.T, np.eye(3)) and np.isclose(np.linalg.det(r), 1.0)
    front = camera.to_camera(np.array([[0.0, 5.0, -5.0]]))[0, 2]
    back = camera.to_camera(np.array([[0.0, 5.0, 5.0]]))[0, 2]
    assert front < back  # the street face (-z) is nearer
    # bgr's -x is on the right of someone facing the street face: that side is the near one
    right = camera.to_camera(np.array([[-5.0, 5.0, 0.0]]))[0, 2]
    left = camera.to_camera(np.array([[5.0, 5.0, 0.0]]))[0, 2]
    assert right < left
    straight = PhotoCamera(0, 0, 0, 60, 0, 0, 0, 0)
    (u_left, _), (u_right, _) = straight.project(np.array([[5.0, 0, 0], [-5.0, 0, 0]]), 400, 300)[0]
    assert u_left < 200 < u_right


def test_camera_origin_lands_on_the_principal_point_and_scale_follows_the_dolly_zoom():
    camera = PhotoCamera(0, 0, 0, 60, 0.2, -0.4, 0, 0)
    pixels, _ = camera.project(np.zeros((1, 3)), 400, 300)
    assert np.allclose(pixels[0], [200 * 1.2, 150 * 0.6])
    # L metres at the origin's depth fill the image's width
    half = cam.SCENE_WIDTH / 2
    pixels, _ = PhotoCamera(0, 0, 0, 60, 0, 0, 0, 0).project(
        np.array([[half, 0, 0], [-half, 0, 0]]), 400, 300
    )
    assert np.isclose(abs(pixels[1, 0] - pixels[0, 0]), 400)


@pytest.mark.parametrize("family", FAMILIES, ids=lambda f: f.rule)
def test_every_family_derives_at_the_corners_of_its_ranges(family):
    """The fit may move any parameter to either end of its range: each family still derives,
    with side faces to read a façade from."""
    k = len(family.params)
    rng = np.random.default_rng(len(family.rule))
    for unit in (np.ones(k), rng.integers(0, 2, k).astype(float)):
        tris = triangles(family, family.values(unit))
        assert len(tris) and np.isfinite(tris).all()
        lo, hi = tris.reshape(-1, 3).min(axis=0), tris.reshape(-1, 3).max(axis=0)
        assert lo[1] == pytest.approx(0, abs=0.05)  # standing on the ground
        assert abs(lo[0] + hi[0]) < 0.5 * (hi[0] - lo[0])  # about centred
    # the lowest and smallest: still side faces that take the façade (not all plain Wall)
    assert side_faces(family, family.values(np.zeros(k)))


def test_the_chamfer_distance_is_zero_on_the_outline_and_grows_with_a_shift():
    family = BY_RULE["Block"]
    fit = MassFit(family, np.full(3, 0.5), cam.normalise(VIEW))
    mask = fit.mask(160, 120)
    target = Target(mask)
    assert target.chamfer(mask) == 0
    shifted = [target.chamfer(np.roll(mask, k, axis=1)) for k in (2, 6)]
    assert 0 < shifted[0] < shifted[1]
    assert iou(mask, mask) == 1.0 and iou(mask, np.roll(mask, 6, axis=1)) < 1
    assert boundary(mask).sum() < mask.sum()


def test_refinement_moves_a_perturbed_fit_back_onto_the_silhouette():
    family = BY_RULE["LBlock"]
    rng = np.random.default_rng(28)
    truth = MassFit(family, rng.uniform(0.3, 0.7, len(family.params)), cam.normalise(VIEW))
    mask = truth.mask(160, 120)
    target = Target(mask)
    start = MassFit(
        family,
        np.clip(truth.mass + rng.normal(0, 0.05, truth.mass.shape), 0, 1),
        np.clip(truth.camera + rng.normal(0, 0.05, 8), 0, 1),
    )
    before = target.chamfer(start.mask(160, 120))
    fit = refine(start, target, evaluations=160)
    assert fit.distance < before / 2
    assert iou(fit.mask(160, 120), mask) > 0.9
    assert ((fit.mass >= 0) & (fit.mass <= 1)).all() and (
        (fit.camera >= 0) & (fit.camera <= 1)
    ).all()


def test_the_network_ranks_the_true_family_high_on_clear_silhouettes():
    """The shipped weights on views it was not trained on (another seed): the true family among
    the three likeliest for most of them."""
    rng = np.random.default_rng(2899)
    hits = 0
    rules = ["Block", "GableHouse", "PodiumTower", "Steeple", "WeddingCake", "RoundTower"]
    for rule in rules:
        family = BY_RULE[rule]
        view = cam.normalise(VIEW)
        truth = MassFit(family, rng.uniform(0.3, 0.7, len(family.params)), view)
        guesses = estimate(truth.mask(160, 120), top=3)
        hits += rule in [g.family.rule for g in guesses]
        assert all(0 <= g.probability <= 1 for g in guesses)
    assert hits >= 4


@pytest.mark.parametrize(("k", "stride"), [(5, 2), (3, 1)])
def test_the_numpy_convolution_is_torchs_same_padded_convolution(k, stride):
    """The shipped network was trained in PyTorch and runs in numpy: each output pixel is the
    sum over channels and the k x k window round ``stride``-th input pixels, zeros outside."""
    rng = np.random.default_rng(5)
    x = rng.normal(size=(2, 3, 8, 8)).astype(np.float32)
    w = rng.normal(size=(4, 3, k, k)).astype(np.float32)
    b = rng.normal(size=4).astype(np.float32)
    out = _conv(x, w, b, stride)
    pad = k // 2
    padded = np.pad(x, ((0, 0), (0, 0), (pad, pad), (pad, pad)))
    side = -(-8 // stride)
    assert out.shape == (2, 4, side, side)
    for n, o, i, j in [(0, 0, 0, 0), (1, 3, side - 1, side - 1), (0, 2, 1, side - 2)]:
        window = padded[n, :, i * stride : i * stride + k, j * stride : j * stride + k]
        assert out[n, o, i, j] == pytest.approx(float((window * w[o]).sum() + b[o]), abs=1e-4)
    pooled = _pool(out)
    assert pooled[1, 3, 0, 0] == out[1, 3, :2, :2].max()
