"""The geometry of a captured model's blocks: frames, outlines and face names.

A block's frame (:class:`_Frame`: a rotation about the vertical and a translation) places it in
its parent's; :func:`_outline` lists its vertical faces in its own frame, in ring order, for a
box, a cylinder or a prism; :func:`_face_names` are the names the file gives those faces.  Pure
geometry of the parsed JSON, with no checks and no diagnostics.
"""

from __future__ import annotations

import math

from .captured_schema import BOX_FACES, BOX_RING

# ---- geometry ---------------------------------------------------------------------------------


def _normal(x_axis) -> tuple[float, float, float]:
    """The outward normal of a vertical face whose x axis (left to right from outside) is given:
    x × y, the face frame being right-handed (x along the face, y up, z out)."""
    return (0.0 - x_axis[2], 0.0, x_axis[0] + 0.0)


def _snap(v: float) -> float:
    """Rounding noise of sin and cos (1e-16) off, and no -0.0: coordinates read as written."""
    return round(v, 12) + 0.0


class _Frame:
    """A rotation about y (radians) followed by a translation: local -> parent coordinates."""

    def __init__(self, angle: float = 0.0, t=(0.0, 0.0, 0.0)) -> None:
        self.angle, self.t = angle, tuple(t)
        self.c, self.s = math.cos(angle), math.sin(angle)

    def direction(self, v):
        x, y, z = v
        return (_snap(x * self.c + z * self.s), _snap(y), _snap(-x * self.s + z * self.c))

    def point(self, p):
        d = self.direction(p)
        return (_snap(d[0] + self.t[0]), _snap(d[1] + self.t[1]), _snap(d[2] + self.t[2]))

    def then(self, parent: _Frame) -> _Frame:
        """This frame, placed in ``parent``'s: the composition parent ∘ self."""
        return _Frame(self.angle + parent.angle, parent.point(self.t))


def _outline(block: dict) -> list[tuple[str, tuple, tuple, float]]:
    """The vertical faces of a block in its own frame, in ring order (each face's right end is
    the next one's left end, seen from outside): (name, bottom-left origin, x axis, width)."""
    w, _, d = (float(v) for v in block["size"])
    shape = block["shape"]
    if shape == "box":
        local = {
            "front": ((w, 0.0, 0.0), (-1.0, 0.0, 0.0), w),
            "left": ((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), d),
            "back": ((0.0, 0.0, d), (1.0, 0.0, 0.0), w),
            "right": ((w, 0.0, d), (0.0, 0.0, -1.0), d),
        }
        return [(name, *local[name]) for name in BOX_RING]
    if shape == "cylinder":
        n = int(block["sides"])
        a, b = w / 2, d / 2
        step = 2 * math.pi / n

        def at(angle):
            return (a + a * math.cos(angle), 0.0, b + b * math.sin(angle))

        # facet 0 faces the front (-z); the ring runs -z, -x, +z, +x as a box's does
        points = [at(-math.pi / 2 + step / 2 - i * step) for i in range(n)]
        edges = [(str(i), points[i], points[(i + 1) % n]) for i in range(n)]
    else:
        pts = [(float(x), 0.0, float(z)) for x, z in block["footprint"]]
        n = len(pts)
        edges = [(str(i), pts[i], pts[(i + 1) % n]) for i in range(n)]
        if _signed_area(block["footprint"]) > 0:  # the other winding: every face runs backwards
            edges = [(name, q, p) for name, p, q in edges]
            edges = edges[:1] + edges[1:][::-1]
    out = []
    for name, p, q in edges:
        dx, dz = q[0] - p[0], q[2] - p[2]
        length = math.hypot(dx, dz)
        axis = (dx / length, 0.0, dz / length) if length > 0 else (1.0, 0.0, 0.0)
        out.append((name, p, axis, length))
    return out


def _signed_area(points) -> float:
    """Shoelace area in (x, z); negative for the ring order of a box (front, left, back, right)."""
    n = len(points)
    return 0.5 * sum(
        points[i][0] * points[(i + 1) % n][1] - points[(i + 1) % n][0] * points[i][1]
        for i in range(n)
    )


def _side_of(normal) -> str:
    x, _, z = normal
    if abs(x) >= abs(z) - 1e-9:
        return "right" if x > 0 else "left"
    return "back" if z > 0 else "front"


def _face_names(block: dict) -> list[str]:
    if block["shape"] == "box":
        return list(BOX_FACES)
    if block["shape"] == "cylinder":
        return [str(i) for i in range(int(block["sides"]))]
    return [str(i) for i in range(len(block["footprint"]))]


def _names_hint(block: dict) -> str:
    names = _face_names(block)
    shown = ", ".join(names if len(names) <= 8 else names[:3] + ["...", names[-1]])
    return f"a {block['shape']}'s faces are {shown}"
