"""Consistent face groups (section 4.3.3) and the splitting rules detected on their averaged
textures (section 4.3.4).

A rule detected on one face alone generalises badly (the paper's figure 7a): windows of faces
stacked one above the other drift apart, faces with a poor photograph get no rule.  So faces
are grouped, and each group's members are averaged into one texture before detection:

* a **horizontally consistent group** is every face between the same two floors (one level):
  its windows share storey rows, so the level gets one **vertical** rule (C, D: rows);
* a **vertically consistent group** links each face to the face of the floor above that it
  overlaps most, when their widths agree (equation 1, phi_shape > 0.9) and so do their column
  signals (equation 2, phi_texture > 0.5): a stack of faces sharing window columns, which gets
  one **horizontal** rule (A, B: columns).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .model import Capture, Face
from .rules import Rule, detect_rule

SHAPE_LINK = 0.9  # phi_shape above which two stacked faces can share columns (section 4.3.3)
TEXTURE_LINK = 0.5  # phi_texture above which they do
SIGNAL_SAMPLES = 64  # points at which two column signals are compared over their overlap


@dataclass
class Groups:
    """Which group each face of ``Capture.faces`` belongs to, and each group's rule.

    Rule lengths are in metres (the capture's unit height times ``Capture.scale``), so that a
    window keeps its size on a target of any size; ``Rule.sections`` are fractions of the
    averaged texture, top to bottom and left to right as the textures are stored."""

    faces: list[Face]
    horizontal: list[int]  # per face: its level's group (index into rows)
    vertical: list[int]  # per face: its stack's group (index into columns)
    rows: list[Rule]  # per horizontal group: the vertical rule C, D (storey rows)
    columns: list[Rule]  # per vertical group: the horizontal rule A, B (window columns)
    row_cuts: list[list[tuple[str, float, float]]]  # per rows[g]: its sections as fractions
    # of the texture's height, top to bottom ("scalable" or "insertable", first, end)
    column_cuts: list[list[tuple[str, float, float]]]  # per columns[g]: fractions of the
    # width, left to right


RIGHTWARD = np.array([(-1.0, 0.0), (0.0, -1.0), (1.0, 0.0), (0.0, 1.0)])
"""(x, z) direction of each wall's left to right seen from outside (a comp(f) face's x axis:
y up crossed with the outward normal)."""


def along(face: Face) -> tuple[float, float]:
    """The interval a face covers along its wall's left-to-right axis: a jog square to the wall
    covers none."""
    axis = RIGHTWARD[face.wall]
    a, b = float(face.start @ axis), float(face.end @ axis)
    return (min(a, b), max(a, b))


def direction(face: Face) -> np.ndarray:
    """The face's own left-to-right unit direction seen from outside, (x, z)."""
    edge = np.asarray(face.end, dtype=np.float64) - np.asarray(face.start, dtype=np.float64)
    length = float(np.hypot(edge[0], edge[1]))
    return edge / length if length > 0 else np.zeros(2)


def spans(lower: Face, upper: Face) -> tuple[tuple[float, float], tuple[float, float]]:
    """The intervals two faces cover along the lower face's own left-to-right direction, or two
    empty ones when they do not look the same way.

    The face's own direction, not its wall's (``along``): a jog of an outline (the wing side of
    an L) is filed under the wall whose bounding-box corners enclose it (section 4.3.1) and runs
    square to it, so along that wall it covers nothing, and neither equation 1 nor 2 could link
    it to the jog above it."""
    axis = direction(lower)
    if float(axis @ direction(upper)) < 0.99:
        return (0.0, 0.0), (0.0, 0.0)

    def span(f: Face) -> tuple[float, float]:
        a, b = float(f.start @ axis), float(f.end @ axis)
        return (min(a, b), max(a, b))

    return span(lower), span(upper)


def shape_similarity(lower: Face, upper: Face) -> float:
    """Equation 1: the width of the two faces' overlap over the narrower face's width."""
    (a0, a1), (b0, b1) = spans(lower, upper)
    overlap = max(0.0, min(a1, b1) - max(a0, b0))
    narrower = min(a1 - a0, b1 - b0)
    return overlap / narrower if narrower > 0 else 0.0


def column_means(face: Face) -> np.ndarray | None:
    """The face's pixel columns averaged (grey, 0..1), left to right; None when untextured.
    A mean over the whole texture: ``vertical_links`` computes it once a face, not once for
    every pair that face is compared in (that was the capture's largest single cost)."""
    if face.texture is None:
        return None
    return face.texture.astype(np.float64).mean(axis=2).mean(axis=0) / 255.0


def column_signal(
    face: Face,
    lo: float,
    hi: float,
    span: tuple[float, float],
    grey: np.ndarray | None = None,
) -> np.ndarray | None:
    """omega of equation 2: the face's pixel columns averaged (grey, 0..1), sampled at
    SIGNAL_SAMPLES points of the stretch lo..hi of the axis along which the face covers
    ``span``; None when untextured.  ``grey``: the face's ``column_means`` when already known."""
    if grey is None:
        grey = column_means(face)
    if grey is None:
        return None
    a0, a1 = span
    at = (np.linspace(lo, hi, SIGNAL_SAMPLES) - a0) / max(a1 - a0, 1e-12)
    cols = np.clip((at * len(grey)).astype(np.int64), 0, len(grey) - 1)
    return grey[cols]


def texture_similarity(
    lower: Face,
    upper: Face,
    means: tuple[np.ndarray | None, np.ndarray | None] | None = None,
) -> float:
    """Equation 2: the correlation of the two faces' column signals over their overlap.  Two
    untextured faces are alike (1); a textured and an untextured face are not (0); a flat
    signal correlates with another flat one only.  ``means``: the two faces' ``column_means``
    when already known."""
    (a0, a1), (b0, b1) = spans(lower, upper)
    lo, hi = max(a0, b0), min(a1, b1)
    if means is None:
        means = (column_means(lower), column_means(upper))
    if means[0] is None or means[1] is None:
        return 1.0 if means[0] is None and means[1] is None else 0.0
    s = column_signal(lower, lo, hi, (a0, a1), means[0])
    t = column_signal(upper, lo, hi, (b0, b1), means[1])
    assert s is not None and t is not None
    ds, dt = s - s.mean(), t - t.mean()
    ns, nt = float(np.sqrt(ds @ ds)), float(np.sqrt(dt @ dt))
    if ns < 1e-9 or nt < 1e-9:
        return 1.0 if ns < 1e-9 and nt < 1e-9 else 0.0
    return float(ds @ dt) / (ns * nt)


def vertical_links(faces: list[Face]) -> list[int]:
    """Union-find of the bottom-to-top traversal: each face is linked to the face of the next
    level on the same wall side that overlaps it most, when equations 1 and 2 agree."""
    parent = list(range(len(faces)))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    means: dict[int, np.ndarray | None] = {}

    def grey(i: int) -> np.ndarray | None:
        if i not in means:
            means[i] = column_means(faces[i])
        return means[i]

    by_level: dict[tuple[int, int], list[int]] = {}
    for i, f in enumerate(faces):
        by_level.setdefault((f.wall, f.level), []).append(i)
    for i, f in enumerate(faces):
        above = by_level.get((f.wall, f.level + 1), [])
        if not above:
            continue
        shapes = [shape_similarity(f, faces[j]) for j in above]
        k = max(range(len(above)), key=lambda n: (shapes[n], -above[n]))
        best = above[k]
        if shapes[k] > SHAPE_LINK and (
            texture_similarity(f, faces[best], (grey(i), grey(best))) > TEXTURE_LINK
        ):
            parent[root(best)] = root(i)
    roots = [root(i) for i in range(len(faces))]
    order = {r: k for k, r in enumerate(dict.fromkeys(roots))}
    return [order[r] for r in roots]


def averaged(faces: list[Face]) -> np.ndarray | None:
    """The members' textures resampled to the median size and averaged (section 4.3.4: "we
    average texture maps of all group members for the detection of the rules")."""
    textures = [f.texture for f in faces if f.texture is not None]
    if not textures:
        return None
    if len(textures) == 1:  # its own average, at its own size (a group of one: most stacks)
        return np.array(textures[0], dtype=np.uint8)
    h = int(np.median([t.shape[0] for t in textures]))
    w = int(np.median([t.shape[1] for t in textures]))
    total = np.zeros((h, w, 3))
    for t in textures:
        if t.shape[:2] == (h, w):  # the resampling below would be the identity
            total += t
            continue
        rows = np.minimum((np.arange(h) + 0.5) * t.shape[0] // h, t.shape[0] - 1).astype(int)
        cols = np.minimum((np.arange(w) + 0.5) * t.shape[1] // w, t.shape[1] - 1).astype(int)
        total += t[np.ix_(rows, cols)]  # one gather, not a copy of whole rows first
    return (total / len(textures)).astype(np.uint8)


def _rule(
    members: list[Face], axis: str, length: float
) -> tuple[Rule, list[tuple[str, float, float]]]:
    image = averaged(members)
    if image is None:  # untextured: one scalable piece, no window
        return Rule(axis, (length,), ()), [("scalable", 0.0, 1.0)]
    rule = detect_rule(image, axis, length)
    n = image.shape[0 if axis == "y" else 1]
    return rule, [(kind, first / n, end / n) for kind, first, end in rule.sections]


def face_groups(capture: Capture) -> Groups:
    """Both kinds of group of every face, and their rules in metres."""
    faces = capture.faces
    levels = sorted({f.level for f in faces})
    horizontal = [levels.index(f.level) for f in faces]
    vertical = vertical_links(faces)
    rows = []
    for g, level in enumerate(levels):
        members = [f for f, h in zip(faces, horizontal, strict=True) if h == g]
        height = (capture.floors[level + 1] - capture.floors[level]) * capture.scale
        rows.append(_rule(members, "y", float(height)))
    columns = []
    for g in range(max(vertical, default=-1) + 1):
        members = [f for f, v in zip(faces, vertical, strict=True) if v == g]
        width = float(np.mean([f.width for f in members])) * capture.scale
        columns.append(_rule(members, "x", width))
    return Groups(
        faces,
        horizontal,
        vertical,
        [r for r, _ in rows],
        [r for r, _ in columns],
        [c for _, c in rows],
        [c for _, c in columns],
    )
