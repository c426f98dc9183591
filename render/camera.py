"""The pinhole camera of the renderer, parameterised as in Nishida et al. 2018, section 4.2.

The paper writes the projection as ``M = K [R | t]`` with ``K`` holding the focal length ``f``
and the principal point ``(C_x, C_y)``, and estimates eight numbers: the rotation angles
``phi_x, phi_y, phi_z`` about the x, y and z axes, the horizontal field of view ``fov`` (with
``f = image width / (2 tan(fov / 2))``), the principal point and the camera's ``t_x, t_y``; ``t_z``
comes from the "dolly zoom" ``t_z = L / (2 tan(fov / 2))`` with the scene width ``L = 25`` m.
We keep that parameterisation and name the angles as a photographer would:

* ``pitch`` = ``phi_x`` (positive: the camera looks down, the top of the model tilts towards it),
* ``yaw`` = ``phi_y`` (0: straight at the front; positive: the camera swings round to the left, as
  seen by someone in the street facing the front, so the façade's left-hand end (+x) comes into
  view),
* ``roll`` = ``phi_z`` (positive: the image turns counter-clockwise).

Conventions (those of the paper's OpenGL renderer): the camera looks down its own -z axis with +y
up and +x to the right; world points go to camera coordinates by ``R (X - position)``, where
``R = Rx(pitch) Ry(yaw) Rz(roll) FRONT``.  bgr's world has y up and the lot in the x-z plane with
its front edge (the street side) along +x and the lot reaching into +z, so façades built by
``comp(f) { front: ... }`` face -z.  The paper's model frame has the front facing the camera
(+z), so ``FRONT`` (a half turn about y) takes bgr's world into it: yaw = pitch = roll = 0 then
looks straight at the front façade, as "phi_y = 0 means that the photograph is a front-view".

The principal point is in normalised image coordinates as the paper's ranges (``C_x, C_y`` in
[-0.8, 0.8]) imply: (0, 0) is the image centre, (1, 1) its top-right corner.  Pixels have (0, 0)
at the top-left corner of the image and pixel (i, j)'s centre at (i + 0.5, j + 0.5).
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..grammar.errors import BgrError, Diagnostic, suggest
from ..grammar.paths import read_json

# A half turn about y: bgr's world (front facing -z) into the paper's model frame (front facing +z).
FRONT = np.diag([-1.0, 1.0, -1.0])
SCENE_WIDTH = 25.0  # the paper's L: assumed width of the scene at the building's depth, metres
PRESETS = {  # view name -> (yaw, pitch, roll, fov) in degrees
    "front": (0.0, 0.0, 0.0, 35.0),
    "iso": (35.0, 30.0, 0.0, 35.0),
    "top": (0.0, 90.0, 0.0, 35.0),
}
MARGIN = 0.05  # presets leave this fraction of the image free on each side
# image size: each side at most MAX_SIDE pixels, and at most MAX_PIXELS in all (4096 x 4096):
# the numpy rasteriser keeps about 50 bytes a pixel, so the largest image needs under 1 GB
MAX_SIDE = 8192
MAX_PIXELS = 4096 * 4096
MAX_NUMBER = 1e8  # |v| of a camera file's numbers: positions in metres, angles in degrees


def size_problem(width: int, height: int) -> str | None:
    """Why an image size cannot be rendered, or None."""
    if not (1 <= width <= MAX_SIDE and 1 <= height <= MAX_SIDE):
        return f"each side must be 1 to {MAX_SIDE} pixels"
    if width * height > MAX_PIXELS:
        return f"at most {MAX_PIXELS:,} pixels in all (e.g. 4096x4096)"
    return None


def _finite(value: object) -> bool:
    """A JSON number usable as a camera value: finite and |v| <= MAX_NUMBER (not a bool)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    try:
        return math.isfinite(value) and abs(value) <= MAX_NUMBER
    except OverflowError:  # an int of more than about 309 digits
        return False


def rot_x(deg: float) -> np.ndarray:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(deg: float) -> np.ndarray:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(deg: float) -> np.ndarray:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rotation_from_angles(yaw: float = 0.0, pitch: float = 0.0, roll: float = 0.0) -> np.ndarray:
    """World-to-camera rotation ``Rx(pitch) Ry(yaw) Rz(roll) FRONT`` (degrees; see the module)."""
    return rot_x(pitch) @ rot_y(yaw) @ rot_z(roll) @ FRONT


def facing_yaw(front) -> float:
    """The yaw in degrees that turns bgr's default front (facing -z) to face ``front`` (a world
    vector; its y is ignored): 0 for -z, 90 for -x, 180 for +z; 0 for None or a vertical one."""
    if front is None:
        return 0.0
    fx, _, fz = (float(v) for v in np.asarray(front, dtype=np.float64).reshape(3))
    if not (math.isfinite(fx) and math.isfinite(fz)) or math.hypot(fx, fz) < 1e-9:
        return 0.0
    return math.degrees(math.atan2(-fx, -fz))


@dataclass(eq=False)
class Camera:
    """A pinhole camera: ``project`` maps world points to pixels and depths.

    ``rotation`` is the 3x3 world-to-camera matrix (its rows are the camera's right, up and
    backward directions in world coordinates), ``position`` the camera centre in the world,
    ``fov`` the horizontal field of view in degrees, ``principal_point`` normalised (see the
    module), ``size`` the image (width, height) in pixels.
    """

    fov: float
    rotation: np.ndarray
    position: np.ndarray
    principal_point: tuple[float, float] = (0.0, 0.0)
    size: tuple[int, int] = (1024, 768)

    def __post_init__(self) -> None:
        self.rotation = np.asarray(self.rotation, dtype=np.float64).reshape(3, 3)
        self.position = np.asarray(self.position, dtype=np.float64).reshape(3)
        self.principal_point = (float(self.principal_point[0]), float(self.principal_point[1]))
        self.size = (int(self.size[0]), int(self.size[1]))
        if not 0.0 < float(self.fov) < 180.0:
            raise BgrError(f"the field of view must be between 0 and 180 degrees, got {self.fov}")
        problem = size_problem(*self.size)
        if problem:
            raise BgrError(f"the image size {self.size[0]}x{self.size[1]} is too large: {problem}")
        if not (np.isfinite(self.position).all() and np.isfinite(self.principal_point).all()):
            raise BgrError("the camera position and principal point must be finite numbers")
        if (
            not np.allclose(self.rotation @ self.rotation.T, np.eye(3), atol=1e-6)
            or np.linalg.det(self.rotation) < 0
        ):
            raise BgrError(
                "the camera rotation must be a proper rotation matrix (orthonormal rows, "
                "determinant +1)"
            )

    # --- constructors -----------------------------------------------------------------------

    @classmethod
    def from_angles(
        cls,
        yaw: float,
        pitch: float,
        roll: float,
        position,
        fov: float = 35.0,
        principal_point=(0.0, 0.0),
        size=(1024, 768),
    ) -> Camera:
        """A camera at ``position`` (world) turned by yaw, pitch and roll in degrees."""
        return cls(fov, rotation_from_angles(yaw, pitch, roll), position, principal_point, size)

    @classmethod
    def look_at(
        cls,
        position,
        target,
        up=(0.0, 1.0, 0.0),
        fov: float = 35.0,
        principal_point=(0.0, 0.0),
        size=(1024, 768),
    ) -> Camera:
        """A camera at ``position`` looking at ``target``, with ``up`` pointing up in the image."""
        position = np.asarray(position, dtype=np.float64)
        back = position - np.asarray(target, dtype=np.float64)
        if not np.linalg.norm(back) > 0:
            raise BgrError("the camera target must differ from its position")
        back /= np.linalg.norm(back)
        right = np.cross(np.asarray(up, dtype=np.float64), back)
        if not np.linalg.norm(right) > 1e-9:
            raise BgrError("the camera's up direction is parallel to its viewing direction")
        right /= np.linalg.norm(right)
        return cls(
            fov, np.stack([right, np.cross(back, right), back]), position, principal_point, size
        )

    @classmethod
    def from_paper(
        cls,
        phi_x: float,
        phi_y: float,
        phi_z: float,
        fov: float,
        c_x: float,
        c_y: float,
        t_x: float,
        t_y: float,
        size=(1024, 768),
        scene_width: float = SCENE_WIDTH,
    ) -> Camera:
        """The paper's eight parameters theta^C = (phi_x, phi_y, phi_z, fov, C_x, C_y, t_x, t_y).

        ``t = (t_x, t_y, t_z)`` is the camera position in the rotated frame, ``t_z`` from the dolly
        zoom ``scene_width / (2 tan(fov / 2))``; angles in degrees.
        """
        rotation = rotation_from_angles(phi_y, phi_x, phi_z)
        t_z = scene_width / (2.0 * math.tan(math.radians(fov) / 2.0))
        return cls(fov, rotation, rotation.T @ np.array([t_x, t_y, t_z]), (c_x, c_y), size)

    @classmethod
    def preset(cls, name: str, lo, hi, size=(1024, 768), *, front=None, points=None) -> Camera:
        """View ``front``, ``iso`` or ``top``, placed so the box ``lo``..``hi`` (or the
        ``points`` in it, see :func:`fit`) fills the frame.

        ``front`` is the direction the model's front faces, a world vector in the x-z plane
        (see :func:`facing_yaw`); by default -z, bgr's front on a W x D lot.  The view's yaw
        is counted from it, so ``front`` looks straight at that front whichever way it faces.
        """
        if name not in PRESETS:
            raise BgrError(
                f"unknown view '{name}'; known views: {', '.join(PRESETS)}, or a camera .json file"
            )
        yaw, pitch, roll, fov = PRESETS[name]
        rotation = rotation_from_angles(yaw, pitch, roll) @ rot_y(-facing_yaw(front))
        return fit(cls(fov, rotation, np.zeros(3), (0.0, 0.0), size), lo, hi, points=points)

    @classmethod
    def from_json(cls, path: str | os.PathLike, size=None) -> Camera:
        """Read a camera file (format in docs/cli.md); ``size`` overrides the file's."""
        shown = str(path)
        data = read_json(path, "camera file", "check the path")
        return cls.from_dict(data, shown, size)

    @classmethod
    def from_dict(cls, data: Any, shown: str = "<camera>", size=None) -> Camera:
        """A camera from the JSON object of :meth:`from_json`; errors name the bad key."""
        return _from_dict(cls, data, shown, size)

    def to_dict(self) -> dict:
        """The JSON form (with ``rotation`` as a matrix), for saving a view to tweak later."""
        return {
            "fov": self.fov,
            "position": [round(float(v), 6) for v in self.position],
            "rotation": [[round(float(v), 9) for v in row] for row in self.rotation],
            "principal_point": list(self.principal_point),
            "size": list(self.size),
        }

    # --- projection --------------------------------------------------------------------------

    @property
    def focal(self) -> float:
        """The focal length in pixels, ``width / (2 tan(fov / 2))``."""
        return self.size[0] / (2.0 * math.tan(math.radians(self.fov) / 2.0))

    @property
    def center(self) -> tuple[float, float]:
        """The principal point in pixels."""
        w, h = self.size
        return (1.0 + self.principal_point[0]) * w / 2.0, (1.0 - self.principal_point[1]) * h / 2.0

    @property
    def K(self) -> np.ndarray:
        """The 3x3 intrinsic matrix in pixels (v grows downwards, so its y focal is negative)."""
        cx, cy = self.center
        return np.array([[self.focal, 0.0, cx], [0.0, -self.focal, cy], [0.0, 0.0, 1.0]])

    def with_size(self, size) -> Camera:
        return Camera(self.fov, self.rotation, self.position, self.principal_point, size)

    def to_camera(self, points) -> np.ndarray:
        """(n, 3) points in camera coordinates: x right, y up, looking down -z."""
        return (
            np.asarray(points, dtype=np.float64).reshape(-1, 3) - self.position
        ) @ self.rotation.T

    def project(self, points) -> tuple[np.ndarray, np.ndarray]:
        """(pixels (n, 2), depth (n,)): image positions and distances along the viewing axis.

        Points behind the camera (depth <= 0) get pixels of NaN.
        """
        cam = self.to_camera(points)
        depth = -cam[:, 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = np.where(depth > 0, 1.0 / depth, np.nan)
        cx, cy = self.center
        f = self.focal
        pixels = np.stack([cx + f * cam[:, 0] * inv, cy - f * cam[:, 1] * inv], axis=1)
        return pixels, depth


def fit(camera: Camera, lo, hi, margin: float = MARGIN, points=None) -> Camera:
    """The camera moved (not turned) so that the box ``lo``..``hi`` (or, when given, the
    ``points`` (n, 3) inside it: the model's corners) just fits in its image.

    Everything is measured from the box centre, so a model far from the origin (projected
    coordinates of some 10^6 m) is framed as well as one at it.  In the rotated frame the camera
    sits at ``(ox, oy, d)`` from that centre; each point ``q`` is inside the frustum when
    ``|q_x - ox| <= (d - q_z) tan_x`` (and the same in y), so the smallest ``d`` is found in
    closed form for each axis; then the image is centred by bisection.  Fitting the points
    rather than the box's eight corners frames a sparse or irregular model (a city, an L) tightly
    in an oblique view, where the box's empty corners would stick out.
    """
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    if not (np.isfinite(lo).all() and np.isfinite(hi).all()) or (hi < lo).any():
        lo, hi, points = np.full(3, -0.5), np.full(3, 0.5), None
    extent = float(np.linalg.norm(hi - lo)) or 1.0
    centre = (lo + hi) / 2.0
    if points is not None and len(points):
        sides = _depth_bins(
            np.asarray(points, dtype=np.float64).reshape(-1, 3) - centre, camera.rotation
        )
    else:
        corners = np.array(
            [[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
        )
        q = (corners - centre) @ camera.rotation.T
        sides = [(q[:, 0], q[:, 2]), (q[:, 1], q[:, 2])]
    w, h = camera.size
    tan = np.array([w / 2.0, h / 2.0]) * (1.0 - 2.0 * margin) / camera.focal
    d = -np.inf
    for k, (across, depth) in enumerate(sides):
        a = np.max(depth + across / tan[k])
        b = np.max(depth - across / tan[k])
        d = max(d, (a + b) / 2.0)
    d = max(d, max(depth.max() for _, depth in sides) + 1e-3 * extent)
    offset = np.zeros(2)
    for k, (across, depth) in enumerate(sides):  # centre: the extreme coordinates cancel
        lo_o, hi_o = across.min(), across.max()
        for _ in range(60):
            mid = (lo_o + hi_o) / 2.0
            u = (across - mid) / (d - depth)
            if u.max() + u.min() > 0:
                lo_o = mid
            else:
                hi_o = mid
        offset[k] = (lo_o + hi_o) / 2.0
    position = centre + camera.rotation.T @ np.array([offset[0], offset[1], d])
    return Camera(camera.fov, camera.rotation, position, camera.principal_point, camera.size)


DEPTH_BINS = 1024  # slices of the model's depth that fit() keeps the outermost points of


def _depth_bins(points: np.ndarray, rotation: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """For the camera's x and y: (across, depth) of a few points that enclose ``points`` in the
    view, for :func:`fit`: the model's depth (its rotated z) cut into DEPTH_BINS slices, each
    giving the largest and smallest coordinate of its points at the slice's near side.  They
    lie at most 1/1024 of the depth beyond the model (a hair more margin), and a million points
    take a few elementwise passes (a convex hull took seconds)."""
    # row by row rather than a matrix product: on a busy machine BLAS threads are slower
    q = [sum(points[:, c] * rotation[j, c] for c in range(3)) for j in range(3)]
    z = q[2]
    near, far = float(z.max()), float(z.min())
    bins = DEPTH_BINS if near > far else 1
    step = (near - far) / bins
    index = (
        np.minimum(((z - far) / step).astype(np.int64), bins - 1)
        if step > 0
        else np.zeros(len(z), dtype=np.int64)
    )
    front = far + step * np.arange(1, bins + 1)
    front[-1] = near
    used = np.bincount(index, minlength=bins) > 0
    sides = []
    for k in range(2):
        most, least = np.full(bins, -np.inf), np.full(bins, np.inf)
        np.maximum.at(most, index, q[k])
        np.minimum.at(least, index, q[k])
        depth = front[used]
        sides.append((np.concatenate([most[used], least[used]]), np.concatenate([depth, depth])))
    return sides


# --- the camera file ----------------------------------------------------------------------------

KEYS = (
    "fov",
    "position",
    "yaw",
    "pitch",
    "roll",
    "rotation",
    "target",
    "up",
    "principal_point",
    "size",
)


def _json(value: object) -> str:
    """A value as a message shows it: JSON, cut short."""
    text = json.dumps(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _from_dict(cls, data: Any, shown: str, size) -> Camera:
    def bad(message: str, hint: str | None = None) -> BgrError:
        return BgrError(Diagnostic(shown, 0, 0, message, hint))

    if not isinstance(data, dict):
        raise bad(
            "a camera file holds one JSON object",
            'e.g. {"fov": 40, "position": [10, 5, -30], "yaw": 20}',
        )
    for key in data:
        if key not in KEYS:
            raise bad(
                f"unknown camera key '{key}'",
                suggest(key, KEYS) or f"known keys: {', '.join(KEYS)}",
            )

    def number(key: str, default: float | None = None) -> float:
        value = data.get(key, default)
        if value is None:
            raise bad(f"the camera needs '{key}'")
        if not _finite(value):
            raise bad(
                f"camera key '{key}' must be a number (at most {MAX_NUMBER:,.0f} in size), "
                f"got {_json(value)}"
            )
        return float(value)

    def vector(key: str, n: int, default=None) -> np.ndarray:
        value = data.get(key, default)
        if value is None:
            raise bad(f"the camera needs '{key}'", f"'{key}': a list of {n} numbers")
        flat = (
            value
            if key != "rotation"
            else (
                [v for row in value for v in row]
                if isinstance(value, list) and all(isinstance(r, list) for r in value)
                else None
            )
        )
        if not isinstance(flat, list) or len(flat) != n or not all(_finite(v) for v in flat):
            shape = (
                "a 3x3 matrix (a list of three rows of three numbers)"
                if key == "rotation"
                else f"a list of {n} numbers"
            )
            raise bad(
                f"camera key '{key}' must be {shape} (each at most {MAX_NUMBER:,.0f} in size), "
                f"got {_json(value)}"
            )
        return np.array(flat, dtype=np.float64)

    fov = number("fov", 40.0)
    if not 0.0 < fov < 180.0:
        raise bad(f"camera key 'fov' must be between 0 and 180 degrees, got {fov:g}")
    position = vector("position", 3)
    principal = tuple(vector("principal_point", 2, [0.0, 0.0]))
    if size is None:
        size = (1024, 768)
        if "size" in data:
            sz = vector("size", 2)
            whole = all(float(v).is_integer() for v in sz)
            if not whole or size_problem(int(sz[0]), int(sz[1])):
                raise bad(
                    f"camera key 'size' must be two positive whole numbers, 1 to {MAX_SIDE} "
                    f"each and at most {MAX_PIXELS:,} pixels in all; got {_json(data['size'])}",
                    "--size WxH overrides it",
                )
            size = (int(sz[0]), int(sz[1]))
    angles = [k for k in ("yaw", "pitch", "roll") if k in data]
    ways = [
        k
        for k, there in (
            ("rotation", "rotation" in data),
            ("target", "target" in data),
            ("yaw/pitch/roll", bool(angles)),
        )
        if there
    ]
    if len(ways) > 1:
        raise bad(f"the camera gives both '{ways[0]}' and '{ways[1]}'; give one way of turning it")
    if "up" in data and "target" not in data:
        raise bad("camera key 'up' needs 'target'")
    if "rotation" in data:
        rotation = vector("rotation", 9).reshape(3, 3)
        if (
            not np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-4)
            or np.linalg.det(rotation) < 0
        ):
            raise bad(
                "camera key 'rotation' is not a rotation matrix (orthonormal rows, determinant +1)"
            )
        u, _, vt = np.linalg.svd(rotation)  # remove the rounding of a hand-written matrix
        return cls(fov, u @ vt, position, principal, size)
    if "target" in data:
        try:
            return cls.look_at(
                position,
                vector("target", 3),
                vector("up", 3, [0.0, 1.0, 0.0]),
                fov,
                principal,
                size,
            )
        except BgrError as exc:
            raise bad(f"camera key 'target': {exc.message}") from None
    return cls(
        fov,
        rotation_from_angles(number("yaw", 0.0), number("pitch", 0.0), number("roll", 0.0)),
        position,
        principal,
        size,
    )
