"""One textured-mesh model that the readers of textured files (CityGML, OBJ+MTL, glTF) all fill.

The inverse modules that learn façades from real textured buildings want the same thing from
every format: triangles, the image each one shows and where in that image each corner lies, and
what the surface is (a wall, a roof) and whose it is (a building's id).  So each reader turns its
file into a :class:`TexturedMesh` and nothing downstream knows which format it came from.

Conventions, chosen once for all formats:

* **Frame.** Vertices are in the file's own frame and units: CityGML and CityJSON are z up (a
  PLATEAU file is latitude, longitude, height in EPSG:6697), OBJ and glTF are as written (glTF y
  up).  ``up`` says which axis is up; ``crs`` is the CRS the file names (a CityGML
  ``gml:Envelope``'s ``srsName``), or None.  Nothing is reprojected: the caller owns that choice.
* **UVs per corner**, (F, 3, 2): a CityGML vertex shared by a wall and a roof has a different
  texture coordinate on each, and OBJ's ``vt`` are per corner too; per-vertex UVs (glTF) are
  spread to corners.  Like CGA's uv set 0 (the colormap) and OpenGL, OBJ and CityGML, (0, 0) is
  the image's **lower**-left corner and v grows upwards; the glTF reader flips its top-left v.
  Coordinates outside 0..1 are kept: they mean the image repeats (``Material.wrap``).
* **Materials** are a table; ``material`` (F,) indexes it (-1: none).  A material's colour is
  RGBA in 0..1 as displayed (sRGB; glTF's linear factors are converted).  Its image is a
  resolved path inside the model's folder, read only when asked for (:meth:`Material.image_bytes`).
* **Semantics and objects** are tables too (``semantic_names``, ``object_ids``), indexed per face,
  so selecting the roofs of a building is a numpy mask (:meth:`TexturedMesh.mask`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from bgr.grammar.errors import Diagnostic

_SCHEME = re.compile(r"[A-Za-z][A-Za-z0-9+.-]*:")  # http:, file:, data: ...
_DRIVE = re.compile(r"[A-Za-z]:[\\/]")  # C:\ : an absolute Windows path

WRAPS = ("wrap", "mirror", "clamp", "border", "none")
"""How UVs outside 0..1 reach the image (CityGML 2.0 ``app:wrapMode``; OBJ and glTF repeat)."""


@dataclass
class Material:
    """What a face looks like: a colour, and maybe an image mapped by the face's UVs."""

    name: str
    color: tuple[float, float, float, float] = (1.0, 1.0, 1.0, 1.0)  # sRGB and alpha, 0..1
    image: Path | None = None  # resolved, inside the model's folder; None: colour only
    wrap: str = "wrap"  # one of WRAPS
    data: bytes | None = None  # an image stored in the model file itself (a GLB's bufferView)
    _size: tuple[int, int] | None = field(default=None, repr=False, compare=False)

    def image_bytes(self) -> bytes:
        """The image file's bytes (read now, not when the model was read)."""
        from bgr.grammar.paths import read_input

        if self.data is not None:
            return self.data
        if self.image is None:
            raise ValueError(f"material {self.name!r} has no image")
        return read_input(self.image, "texture image")

    def has_image(self) -> bool:
        return self.image is not None or self.data is not None

    def image_size(self) -> tuple[int, int]:
        """(width, height) of the image in pixels, from its header (Pillow; read once);
        ValueError for one of more than ``bgr.grammar.textures.MAX_IMAGE_PIXELS``."""
        if self._size is None:
            from bgr.grammar.textures import open_image

            with open_image(self.image_bytes()) as im:
                self._size = (int(im.width), int(im.height))
        return self._size


@dataclass
class TexturedMesh:
    """Triangles with per-corner UVs, a material, a semantic type and an owning object each."""

    vertices: np.ndarray  # (V, 3) float64, the file's frame
    faces: np.ndarray  # (F, 3) int64 into vertices
    uv: np.ndarray  # (F, 3, 2) float64; meaningful where the face's material has an image
    material: np.ndarray  # (F,) int64 into materials, -1: none
    materials: list[Material]
    semantic: np.ndarray  # (F,) int64 into semantic_names ("" : no semantic surface)
    semantic_names: list[str]
    object: np.ndarray  # (F,) int64 into object_ids
    object_ids: list[str]
    surface: np.ndarray  # (F,) int64 into surface_ids: the polygon / primitive a face is from
    surface_ids: list[str]  # a CityGML polygon's gml:id ("" without one), "mesh 0 primitive 1"
    up: str = "z"
    crs: str | None = None
    source: str = ""  # the file read, as given
    warnings: list[Diagnostic] = field(default_factory=list)

    def mask(self, semantic: str | None = None, object_id: str | None = None) -> np.ndarray:
        """(F,) bool: the faces of one semantic type and/or one object (an unknown name: none)."""
        keep = np.ones(len(self.faces), dtype=bool)
        if semantic is not None:
            code = self.semantic_names.index(semantic) if semantic in self.semantic_names else -2
            keep &= self.semantic == code
        if object_id is not None:
            code = self.object_ids.index(object_id) if object_id in self.object_ids else -2
            keep &= self.object == code
        return keep

    def textured(self) -> np.ndarray:
        """(F,) bool: faces whose material has an image."""
        has = np.array([m.has_image() for m in self.materials] + [False], dtype=bool)
        return has[self.material]  # -1 picks the trailing False


def image_path(folder: Path, uri: str) -> Path:
    """The file a texture's relative URI names inside ``folder`` (the model's own folder),
    symlinks and ``..`` resolved; ValueError saying why for a URL, an absolute path or a file
    outside the folder (a model read from anywhere may not make bgr read anything else).
    Whether the file exists is the caller's question: a missing image is a warning."""
    from urllib.parse import unquote

    from bgr.grammar.paths import resolved

    if _SCHEME.match(uri) and not _DRIVE.match(uri):
        raise ValueError("is a URL, not a file in the model's folder")
    name = unquote(uri).replace("\\", "/")
    if not name or name.startswith("/") or _DRIVE.match(name) or "\0" in name:
        raise ValueError("is not a relative path inside the model's folder")
    if len(name.encode("utf-8", "surrogatepass")) > 4096 or any(
        len(part.encode("utf-8", "surrogatepass")) > 255 for part in name.split("/")
    ):  # past PATH_MAX or NAME_MAX: stat() would raise ENAMETOOLONG
        raise ValueError("cannot be a file name (File name too long)")
    root = resolved(folder)
    try:
        target = resolved(root / name)
    except OSError as exc:  # a name of 100,000 characters: ENAMETOOLONG
        raise ValueError(f"cannot be a file name ({exc.strerror or exc})") from None
    if not target.is_relative_to(root):
        raise ValueError("lies outside the model's folder")
    return target


def wrapped(uv: np.ndarray, wrap: str) -> np.ndarray:
    """UVs brought into 0..1 as a renderer samples them: repeated (``wrap``), mirrored, or
    clamped (``clamp``, ``border`` and ``none``, whose outside is a border colour or nothing,
    clamp to the edge that a sampler would reach)."""
    if wrap == "wrap":
        out = uv - np.floor(uv)
        return np.where((uv != 0) & (out == 0) & (uv == np.rint(uv)), 1.0, out)  # 1 stays 1
    if wrap == "mirror":
        period = np.mod(uv, 2.0)
        return np.where(period > 1.0, 2.0 - period, period)
    return np.clip(uv, 0.0, 1.0)


def pixels(uv: np.ndarray, size: tuple[int, int], wrap: str = "wrap") -> np.ndarray:
    """(..., 2) int64 (column, row) of the image pixels that UVs (..., 2) sample, rows counted
    from the image's top (as Pillow and numpy store it) while v counts from its bottom."""
    width, height = size
    w = wrapped(np.asarray(uv, dtype=np.float64), wrap)
    col = np.minimum(np.floor(w[..., 0] * width), width - 1)
    row = np.minimum(np.floor((1.0 - w[..., 1]) * height), height - 1)
    return np.stack([col, row], axis=-1).astype(np.int64)
