"""A z-buffer rasteriser in numpy alone: the renderer's fallback when no GL context can be made.

How it stays watertight: corners are snapped to 1/256 pixel (as GPUs do), so the edge functions
``E(p) = dx (p_y - a_y) - dy (p_x - a_x)`` are whole numbers held exactly in float64; the two
triangles sharing an edge compute exactly opposite values, and a pixel centre lying exactly on an
edge goes to one of them by the top-left rule (the sign ``E`` would take if the centre moved by
an infinitesimal ``(eps, eps^2)``).  So adjacent triangles leave no holes and no pixel twice.

How it stays fast: a Python loop per triangle would take minutes for 200,000 triangles.  Instead
triangles are grouped by the size of their pixel bounding box, rounded up to a few size classes;
each group is one ``(n, h, w)`` array of candidate pixels whose edge functions are plain
broadcasts (no gathers).  The covered pixels of every group then meet in one z-test:
``np.maximum.at`` keeps the largest inverse depth per pixel (the nearest surface; inverse depth is
affine in screen space, so it interpolates exactly), and ties go to the lowest triangle index, as
they do in GL with ``LESS`` and the triangles drawn in order.
"""

from __future__ import annotations

import numpy as np

from .camera import Camera
from .frame import Frame, empty_frame, prepare

SUB = 256  # sub-pixel steps per pixel
HALF = SUB // 2
CHUNK = 1 << 21  # candidate pixels per block: bounds memory to some 50 MB
SIZES = np.array(
    [
        1,
        2,
        3,
        4,
        5,
        6,
        8,
        10,
        12,
        16,
        20,
        24,
        32,
        40,
        48,
        64,
        80,
        96,
        128,
        160,
        192,
        256,
        320,
        384,
        512,
        640,
        768,
        1024,
        1280,
        1536,
        2048,
        2560,
        3072,
        4096,
        5120,
        6144,
        8192,
        10240,
        12288,
        16384,
        1 << 62,
    ]
)


def clip_near(cam: np.ndarray, near: float) -> tuple[np.ndarray, np.ndarray]:
    """Camera-space triangles clipped to depth >= ``near``: (triangles, index of their source).

    A triangle with one corner behind the plane becomes two, with two corners behind one; the
    corners keep their cyclic order.
    """
    depth = -cam[:, :, 2]
    behind = depth < near
    count = behind.sum(axis=1)
    keep = np.flatnonzero(count == 0)
    out, source = [cam[keep]], [keep]
    for n_behind in (1, 2):
        sel = np.flatnonzero(count == n_behind)
        if not len(sel):
            continue
        tri, b = cam[sel], behind[sel]
        odd = np.argmax(b if n_behind == 1 else ~b, axis=1)  # the corner on its own side
        roll = (odd[:, None] + np.arange(3)) % 3
        tri = np.take_along_axis(tri, roll[:, :, None], axis=1)  # the odd corner first
        d = -tri[:, :, 2] - near  # signed distance to the plane
        a, b1, c = tri[:, 0], tri[:, 1], tri[:, 2]
        ab = a + (b1 - a) * (d[:, 0] / (d[:, 0] - d[:, 1]))[:, None]
        ac = a + (c - a) * (d[:, 0] / (d[:, 0] - d[:, 2]))[:, None]
        if n_behind == 1:  # a behind: the quad ab, b, c, ac
            out += [np.stack([ab, b1, c], axis=1), np.stack([ab, c, ac], axis=1)]
            source += [sel, sel]
        else:  # only a in front: the triangle a, ab, ac
            out.append(np.stack([a, ab, ac], axis=1))
            source.append(sel)
    return np.concatenate(out), np.concatenate(source)


def _merge(zbuf: np.ndarray, ids: np.ndarray, pix: np.ndarray, inv: np.ndarray, tri: np.ndarray):
    """The z-test of one block of fragments folded into the buffers: per pixel the largest
    inverse depth, and of the fragments at it the lowest triangle index -- what one test of all
    fragments at once gives, whatever the blocks.  Fragments were once kept until the end:
    100,000 copies of one face over a 64 x 48 image made 10^8 of them, 1.6 GB."""
    touched = np.unique(pix)
    before = zbuf[touched]
    np.maximum.at(zbuf, pix, inv)
    ids[touched[zbuf[touched] > before]] = np.iinfo(np.int64).max  # nearer now: earlier lose
    win = inv == zbuf[pix]
    np.minimum.at(ids, pix[win], tri[win])


def rasterise(triangles: np.ndarray, camera: Camera) -> Frame:
    """Depth and triangle-index buffers of world ``triangles`` (T, 3, 3) seen by ``camera``."""
    W, H = camera.size
    frame = empty_frame(camera, "numpy")
    if len(triangles) == 0:
        return frame
    cam, near, _ = prepare(np.asarray(triangles, dtype=np.float64), camera)
    cam, source = clip_near(cam, near)
    depth = -cam[:, :, 2]
    f, (cx, cy) = camera.focal, camera.center
    with np.errstate(divide="ignore", invalid="ignore"):
        U = np.rint((cx + f * cam[:, :, 0] / depth) * SUB)
        V = np.rint((cy - f * cam[:, :, 1] / depth) * SUB)
        iz = 1.0 / depth

    # counter-clockwise on screen (y down: positive area), degenerate and off-screen ones dropped
    area = (U[:, 1] - U[:, 0]) * (V[:, 2] - V[:, 0]) - (V[:, 1] - V[:, 0]) * (U[:, 2] - U[:, 0])
    flip = area < 0
    for arr in (U, V, iz):
        arr[flip, 1], arr[flip, 2] = arr[flip, 2].copy(), arr[flip, 1].copy()
    area = np.abs(area)
    i0 = np.maximum(np.ceil((U.min(axis=1) - HALF) / SUB), 0)
    i1 = np.minimum(np.floor((U.max(axis=1) - HALF) / SUB), W - 1)
    j0 = np.maximum(np.ceil((V.min(axis=1) - HALF) / SUB), 0)
    j1 = np.minimum(np.floor((V.max(axis=1) - HALF) / SUB), H - 1)
    ok = (area > 0) & np.isfinite(area) & (i1 >= i0) & (j1 >= j0)
    if not ok.any():
        return frame
    U, V, iz, area, source = U[ok], V[ok], iz[ok], area[ok], source[ok]
    i0, i1, j0, j1 = (
        i0[ok].astype(np.int64),
        i1[ok].astype(np.int64),
        j0[ok].astype(np.int64),
        j1[ok].astype(np.int64),
    )

    # size classes; a box padded to its class is shifted back inside the image
    wc = np.minimum(SIZES[np.searchsorted(SIZES, i1 - i0 + 1)], W)
    hc = np.minimum(SIZES[np.searchsorted(SIZES, j1 - j0 + 1)], H)
    i0 = np.minimum(i0, W - wc)
    j0 = np.minimum(j0, H - hc)

    # edge k runs from corner k to corner k + 1: E = A px + B py + C, in sub-pixel units
    px0, py0 = i0 * SUB + HALF, j0 * SUB + HALF
    E0, SX, SY, THR = [], [], [], []
    for k in range(3):
        ax, ay, bx, by = U[:, k], V[:, k], U[:, (k + 1) % 3], V[:, (k + 1) % 3]
        dx, dy = bx - ax, by - ay
        E0.append(dx * (py0 - ay) - dy * (px0 - ax))
        SX.append(-dy * SUB)
        SY.append(dx * SUB)
        THR.append(np.where((dy < 0) | ((dy == 0) & (dx > 0)), 0.0, 1.0))  # top-left rule
    # inverse depth is affine in the pixel: iz = (E1 iz0 + E2 iz1 + E0 iz2) / area
    ZA = (E0[1] * iz[:, 0] + E0[2] * iz[:, 1] + E0[0] * iz[:, 2]) / area
    ZX = (SX[1] * iz[:, 0] + SX[2] * iz[:, 1] + SX[0] * iz[:, 2]) / area
    ZY = (SY[1] * iz[:, 0] + SY[2] * iz[:, 1] + SY[0] * iz[:, 2]) / area

    key = wc * (H + 1) + hc
    order = np.argsort(key, kind="stable")
    cuts = np.flatnonzero(np.diff(key[order])) + 1
    zbuf = np.zeros(W * H)
    ids = np.full(W * H, np.iinfo(np.int64).max)
    for group in np.split(order, cuts):
        wb, hb = int(wc[group[0]]), int(hc[group[0]])
        step = max(1, CHUNK // (wb * hb))
        di = np.arange(wb, dtype=np.float64)
        dj = np.arange(hb, dtype=np.float64)
        for lo in range(0, len(group), step):
            sel = group[lo : lo + step]
            inside = None
            for k in range(3):
                row = (E0[k][sel] - THR[k][sel])[:, None] + SY[k][sel][:, None] * dj  # (n, hb)
                col = SX[k][sel][:, None] * di  # (n, wb)
                test = (row[:, :, None] + col[:, None, :]) >= 0
                inside = test if inside is None else np.logical_and(inside, test, out=inside)
            n, jj, ii = np.nonzero(inside)
            if not len(n):
                continue
            t = sel[n]
            _merge(
                zbuf,
                ids,
                (j0[t] + jj) * W + (i0[t] + ii),
                ZA[t] + ZX[t] * ii + ZY[t] * jj,
                source[t].astype(np.int64),
            )
    covered = zbuf > 0
    frame.triangle.reshape(-1)[covered] = ids[covered]
    frame.depth.reshape(-1)[covered] = 1.0 / zbuf[covered]
    return frame
