"""The photograph's camera of Nishida et al. 2018, section 4.2: a pinhole ``M = K [R | t]`` with
eight parameters ``(phi_x, phi_y, phi_z, fov, C_x, C_y, t_x, t_y)``.

The building stands on the origin of its own frame (x along the street, y up, z into the lot, as
every bgr mass; its street face looks at -z).  The camera looks at it from the street: it is
turned ``phi_y`` degrees about the vertical (so that it sees the street face and the right-hand
side), tilted up ``phi_x`` degrees and rolled ``phi_z`` degrees.  ``t_x, t_y`` place the building's
origin off the optical axis, in metres; the depth ``t_z = L / (2 tan(fov / 2))`` fixes the scale
(the paper's dolly zoom, ``L`` the width of the scene at the building), and the
focal length is ``f = image width / (2 tan(fov / 2))``.  ``C_x, C_y`` move the principal point
from the image centre, as fractions of half the image's width and height.

This is the renderer's camera (bgr.render.camera, whose ``Camera.from_paper`` also takes the
eight numbers) with two conventions of its own, because the fit works on street photographs:
``phi_x`` > 0 looks up (the renderer's pitch > 0 looks down) and ``t`` places the building in the
camera's frame (``M = K [R | t]`` as written), not the camera in the rotated one.
:meth:`~bgr.inverse.image.photo.render_camera` turns a fit into the renderer's camera.

The ranges are the paper's (section 4.3), within which the model is trained, with one change: the
paper's ``L`` = 25 m and ``t_x, t_y`` within +-15 m are doubled (50 m, +-30 m), the same views of
buildings twice as large, because the stdlib's masses are metric rules (parapets, eaves and
sills of fixed size) whose plausible sizes would not fit in the paper's 25 m scene.  A
silhouette fixes a building only up to scale: the photograph stage sets the scale afterwards
from the façade's floor count.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bgr.render.camera import rot_x as _rot_x
from bgr.render.camera import rot_y as _rot_y
from bgr.render.camera import rot_z as _rot_z

SCENE_WIDTH = 50.0  # L, metres: twice the paper's 25 m, see the module docstring
NAMES = ("phi_x", "phi_y", "phi_z", "fov", "c_x", "c_y", "t_x", "t_y")
# the paper's ranges, section 4.3 (degrees, fractions of half the image, metres)
LOW = np.array([0.0, 20.0, -10.0, 20.0, -0.8, -0.8, -30.0, -30.0])
HIGH = np.array([40.0, 70.0, 10.0, 90.0, 0.8, 0.8, 30.0, 30.0])
NEAR = 0.5  # metres: a vertex closer to the camera than this cannot be projected


@dataclass(frozen=True)
class PhotoCamera:
    """The eight camera parameters (degrees, fractions, metres), see the module's docstring."""

    phi_x: float
    phi_y: float
    phi_z: float
    fov: float
    c_x: float
    c_y: float
    t_x: float
    t_y: float

    @classmethod
    def from_vector(cls, values) -> PhotoCamera:
        return cls(*(float(v) for v in values))

    def vector(self) -> np.ndarray:
        return np.array([getattr(self, name) for name in NAMES])

    @property
    def t_z(self) -> float:
        return SCENE_WIDTH / (2 * np.tan(np.radians(self.fov) / 2))

    def rotation(self) -> np.ndarray:
        """World (y up) to camera (x right, y down, z forward) rotation."""
        # a half turn about z: bgr's +x is on the left of someone facing the street face (its
        # frame is right-handed), the camera's x runs to the right and its y down
        flip = np.diag([-1.0, -1.0, 1.0])
        return _rot_z(self.phi_z) @ _rot_x(-self.phi_x) @ _rot_y(self.phi_y) @ flip

    def intrinsics(self, width: int, height: int) -> np.ndarray:
        f = width / (2 * np.tan(np.radians(self.fov) / 2))
        cx = width / 2 * (1 + self.c_x)
        cy = height / 2 * (1 + self.c_y)
        return np.array([[f, 0, cx], [0, f, cy], [0, 0, 1.0]])

    def to_camera(self, points: np.ndarray) -> np.ndarray:
        """(n, 3) world points in the camera's frame."""
        t = np.array([self.t_x, self.t_y, self.t_z])
        return points @ self.rotation().T + t

    def project(self, points: np.ndarray, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
        """(pixels (n, 2), in front (n,) bool): where world points land in a width x height
        image, pixel centres at half-integers, y down."""
        cam = self.to_camera(np.asarray(points, dtype=float))
        front = cam[:, 2] > NEAR
        depth = np.where(front, cam[:, 2], NEAR)
        k = self.intrinsics(width, height)
        u = k[0, 0] * cam[:, 0] / depth + k[0, 2]
        v = k[1, 1] * cam[:, 1] / depth + k[1, 2]
        return np.stack([u, v], axis=1), front

    def position(self) -> np.ndarray:
        """The camera's centre in the building's frame (metres, y up)."""
        t = np.array([self.t_x, self.t_y, self.t_z])
        return -self.rotation().T @ t

    def as_dict(self, width: int, height: int) -> dict:
        """What the sidecar JSON holds: the parameters and the matrices they make."""
        k = self.intrinsics(width, height)
        rt = np.hstack([self.rotation(), np.array([[self.t_x], [self.t_y], [self.t_z]])])
        return {
            "model": f"pinhole, Nishida et al. 2018 section 4.2 (L = {SCENE_WIDTH:g} m)",
            "image_size": [width, height],
            **{name: round(float(v), 6) for name, v in zip(NAMES, self.vector(), strict=True)},
            "t_z": round(self.t_z, 6),
            "K": np.round(k, 6).tolist(),
            "Rt": np.round(rt, 6).tolist(),
            "position": np.round(self.position(), 4).tolist(),
        }


def normalise(vector: np.ndarray) -> np.ndarray:
    """Camera parameters mapped to [0, 1] over the paper's ranges."""
    return (np.asarray(vector, dtype=float) - LOW) / (HIGH - LOW)


def denormalise(unit: np.ndarray) -> np.ndarray:
    return LOW + np.asarray(unit, dtype=float) * (HIGH - LOW)
