"""Headless previews of grammars and models: ``bgr render`` and its Python API.

    from bgr.render import render, render_labels, save_png
    image = render("examples/house.bgr", mode="shaded", view="iso", size=(800, 600), seed=3)
    save_png(image, "house.png")                     # atomically: a temporary file, then a rename
    image, legend = render_labels(result, view="front")   # legend: label -> "#rrggbb"

The pieces, one concern each: :mod:`.scene` turns a source into triangles with colours, parts
and labels; :mod:`.camera` is the pinhole camera of Nishida et al. 2018 (section 4.2) with the
``front``/``iso``/``top`` views fitted to the model; :mod:`.raster_gl` (OpenGL through EGL,
fast) and :mod:`.raster_numpy` (numpy, the fallback) make the depth and triangle-index buffers;
:mod:`.images` turns them into the four modes; :mod:`.texturing` draws the textures of a
textured scene (:mod:`.textured`: a textured grammar, glTF, OBJ+MTL or CityGML model) in the
shaded mode from the triangle buffer alone, so both rasterisers draw them alike.
"""

from __future__ import annotations

import json
import os
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from ..grammar.errors import BgrError, Diagnostic
from . import images
from .camera import PRESETS, Camera
from .frame import Frame, GLUnavailable
from .scene import Scene, load_scene

MODES = ("shaded", "silhouette", "lines", "labels")
VIEWS = tuple(PRESETS)
BACKENDS = ("auto", "gl", "numpy")
DEFAULT_SIZE = (1024, 768)

__all__ = [
    "BACKENDS",
    "MODES",
    "VIEWS",
    "Camera",
    "Frame",
    "GLUnavailable",
    "Scene",
    "image_of",
    "legend_path",
    "load_scene",
    "make_camera",
    "rasterise",
    "render",
    "render_labels",
    "save_legend",
    "save_png",
]


def make_camera(
    view: str | os.PathLike | Camera, scene: Scene, size: tuple[int, int] | None = None
) -> Camera:
    """The camera for ``view``: a preset name (fitted to the scene's triangles and turned to the
    way its lots face, ``scene.front``), a Camera, or a camera .json path.  ``size`` replaces
    the camera's image size when given."""
    if isinstance(view, Camera):
        return view if size is None else view.with_size(size)
    if isinstance(view, str) and view in PRESETS:
        lo, hi = scene.bounds()
        return Camera.preset(
            view,
            lo,
            hi,
            size or DEFAULT_SIZE,
            front=scene.front,
            points=scene.triangles.reshape(-1, 3) if len(scene) else None,
        )
    if isinstance(view, (str, os.PathLike)) and str(view).lower().endswith(".json"):
        return Camera.from_json(view, size)
    raise BgrError(
        f"unknown view '{view}'; give {', '.join(PRESETS)}, a Camera or a camera .json file"
    )


def _warn(reason: str) -> None:
    warnings.warn(f"bgr.render: {reason}; using the numpy rasteriser", RuntimeWarning, stacklevel=3)


def rasterise(
    scene: Scene,
    camera: Camera,
    backend: str = "auto",
    on_fallback: Callable[[str], None] | None = _warn,
) -> Frame:
    """The depth and triangle-index buffers of ``scene`` seen by ``camera``.

    ``backend``: ``"gl"`` (an error if no GL context can be made), ``"numpy"``, or ``"auto"``: GL
    when it can, else numpy, calling ``on_fallback(reason)`` (by default a RuntimeWarning).
    """
    if backend not in BACKENDS:
        raise BgrError(f"unknown backend '{backend}'; known backends: {', '.join(BACKENDS)}")
    if backend in ("auto", "gl"):
        from . import raster_gl

        try:
            return raster_gl.rasterise(scene.triangles, camera)
        except GLUnavailable as exc:
            if backend == "gl":
                raise BgrError(
                    Diagnostic(
                        "",
                        0,
                        0,
                        f"the GL renderer is not available: {exc}",
                        "install the EGL libraries (see README.md) or use --backend numpy",
                    )
                ) from None
            if on_fallback is not None:
                on_fallback(str(exc))
    from . import raster_numpy

    return raster_numpy.rasterise(scene.triangles, camera)


def image_of(frame: Frame, scene: Scene, mode: str) -> tuple[np.ndarray, dict | None]:
    """(image, legend or None) of one mode; shaded and labels are RGB, the others greyscale."""
    if mode == "shaded":
        return images.shaded(frame, scene), None
    if mode == "silhouette":
        return images.silhouette(frame), None
    if mode == "lines":
        return images.lines(frame, scene), None
    if mode == "labels":
        return images.labels(frame, scene)
    raise BgrError(f"unknown mode '{mode}'; known modes: {', '.join(MODES)}")


def _render(
    source: Any,
    mode: str,
    view: Any,
    size: tuple[int, int] | None,
    backend: str,
    seed: int,
    attrs: dict | None,
    lot: Any,
) -> tuple[np.ndarray, dict | None]:
    if mode not in MODES:
        raise BgrError(f"unknown mode '{mode}'; known modes: {', '.join(MODES)}")
    scene = load_scene(source, seed=seed, attrs=attrs, lot=lot)
    camera = make_camera(view, scene, size)
    return image_of(rasterise(scene, camera, backend), scene, mode)


def render(
    source: Any,
    mode: str = "shaded",
    view: str | os.PathLike | Camera = "iso",
    size: tuple[int, int] | None = None,
    backend: str = "auto",
    *,
    seed: int = 0,
    attrs: dict | None = None,
    lot: Any = None,
) -> np.ndarray:
    """An image of ``source``: a ``bgr.Result``, a :class:`Scene`, a trimesh, or the path of a
    ``.bgr`` file (derived with ``seed``, ``attrs`` and ``lot``, as ``bgr.derive`` takes them) or
    of a ``.glb``/``.gltf``, ``.obj``, ``.ply`` or CityGML ``.gml`` file; textures are drawn.

    ``mode``: ``shaded`` (H, W, 3), ``silhouette`` (H, W; 255 on the model), ``lines`` (H, W;
    black lines on white) or ``labels`` (H, W, 3; see :func:`render_labels` for the legend).
    ``view``: ``front``, ``iso`` or ``top`` (fitted to the model), a :class:`Camera`, or a camera
    .json file.  ``size``: (width, height), default the camera's or 1024 x 768.  Errors are
    ``bgr.BgrError``.
    """
    return _render(source, mode, view, size, backend, seed, attrs, lot)[0]


def render_labels(
    source: Any,
    view: str | os.PathLike | Camera = "iso",
    size: tuple[int, int] | None = None,
    backend: str = "auto",
    *,
    seed: int = 0,
    attrs: dict | None = None,
    lot: Any = None,
) -> tuple[np.ndarray, dict]:
    """The ``labels`` image and its legend ``{"background": "#000000", "labels": {label: rgb}}``."""
    image, legend = _render(source, "labels", view, size, backend, seed, attrs, lot)
    assert legend is not None
    return image, legend


def _check_suffix(path: Path, suffix: str) -> None:
    if path.suffix.lower() != suffix:
        shown = (
            f"unknown output extension '{path.suffix}'"
            if path.suffix
            else "the output file name has no extension"
        )
        raise BgrError(Diagnostic(str(path), 0, 0, shown, f"bgr render writes {suffix} files"))


def save_png(image: np.ndarray, path: str | os.PathLike) -> None:
    """Write an (H, W) or (H, W, 3) uint8 image as PNG, atomically: nothing is left behind on
    failure, and an existing file is replaced whole or not at all."""
    from PIL import Image

    from ..formats.atomic import atomic_files

    path = Path(path)
    _check_suffix(path, ".png")
    array = np.ascontiguousarray(image, dtype=np.uint8)
    if not (array.ndim == 2 or (array.ndim == 3 and array.shape[2] in (3, 4))):
        raise BgrError(f"cannot write an image of shape {array.shape} as PNG")
    picture = Image.fromarray(array)  # (H, W): greyscale; (H, W, 3): RGB
    with atomic_files([path]) as (f,):
        picture.save(f, format="PNG")


def save_legend(legend: dict, path: str | os.PathLike) -> None:
    """Write a labels legend as JSON, atomically."""
    from ..formats.atomic import atomic_files

    path = Path(path)
    with atomic_files([path]) as (f,):
        f.write((json.dumps(legend, indent=1, ensure_ascii=False) + "\n").encode("utf-8"))


def legend_path(png: str | os.PathLike) -> Path:
    """Where ``bgr render --legend`` puts the legend: ``OUT.png`` -> ``OUT.legend.json``."""
    return Path(png).with_suffix(".legend.json")
