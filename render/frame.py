"""What a rasteriser returns, and the set-up both rasterisers share.

Both backends start from the same camera-space triangles and the same near and far distances
(:func:`prepare`), so that their buffers agree pixel for pixel up to rounding: the numpy one
clips at ``near`` itself, the GL one lets the GPU clip at the same plane.  Textures need no
more than these buffers (render/texturing.py: a pixel's triangle and the camera give its
texture coordinates), so both rasterisers draw them alike.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .camera import Camera


class GLUnavailable(RuntimeError):
    """No OpenGL context could be made (no moderngl, no EGL library, no device): use numpy."""


@dataclass(eq=False)
class Frame:
    """The two buffers of a rendering, row 0 at the top of the image.

    ``depth`` is the distance along the viewing axis (``inf`` where nothing is drawn);
    ``triangle`` the index of the scene triangle seen at each pixel (-1 for the background).
    """

    depth: np.ndarray  # (H, W) float32
    triangle: np.ndarray  # (H, W) int32
    camera: Camera
    backend: str  # "gl" or "numpy"

    @property
    def mask(self) -> np.ndarray:
        return self.triangle >= 0


def empty_frame(camera: Camera, backend: str) -> Frame:
    w, h = camera.size
    return Frame(
        np.full((h, w), np.inf, dtype=np.float32),
        np.full((h, w), -1, dtype=np.int32),
        camera,
        backend,
    )


def prepare(triangles: np.ndarray, camera: Camera) -> tuple[np.ndarray, float, float]:
    """(camera-space triangles (T, 3, 3), near, far).

    ``far`` lies just beyond the farthest corner.  When every corner is in front of the camera,
    ``near`` lies just before the nearest one (no triangle comes closer than its corners), so
    nothing is clipped; otherwise some triangle reaches behind the camera and ``near`` is
    far / 10^4: what is nearer than that is clipped away.
    """
    cam = camera.to_camera(triangles.reshape(-1, 3)).reshape(-1, 3, 3)
    depth = -cam[:, :, 2]
    ahead = depth[depth > 0]
    if ahead.size == 0:
        return cam, 1.0, 2.0
    far = float(ahead.max()) * 1.01 + 1e-6
    near = float(ahead.min()) * 0.99 if ahead.size == depth.size else 0.0
    return cam, max(near, far * 1e-4), far
