"""The PLY reader of ``bgr infer --kind city``: one mesh, read by trimesh after
:mod:`.ply_checks` has checked its header; its objects are its connected components."""

from __future__ import annotations

import io
from typing import TYPE_CHECKING

import numpy as np

from bgr.grammar.errors import BgrError, Diagnostic

from .read_scene import Found, _reason

if TYPE_CHECKING:
    import trimesh


def _read_ply(shown: str, data: bytes) -> Found:
    """A PLY read by trimesh: one mesh, whose objects are its connected components."""
    import warnings

    import trimesh

    from .ply_checks import check_header, check_mesh

    check_header(shown, data)  # counts the file can hold, before trimesh allocates them
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")  # a NaN cast: check_coordinates names the vertex
            mesh = trimesh.load(io.BytesIO(data), file_type="ply", process=False)
    except Exception as exc:  # trimesh raises whatever its parsers meet
        raise BgrError(
            Diagnostic(shown, 0, 0, f"not a PLY file bgr can read: {_reason(exc)}")
        ) from None
    faces = getattr(mesh, "faces", None)
    if isinstance(mesh, trimesh.Trimesh) and faces is not None:
        check_mesh(shown, np.asarray(mesh.vertices), np.asarray(faces))
    if not isinstance(mesh, trimesh.Trimesh) or faces is None or not len(faces):
        hint = "it holds points only" if isinstance(mesh, trimesh.PointCloud) else None
        raise BgrError(Diagnostic(shown, 0, 0, f"no triangles in {shown}", hint))
    colors = (
        _mesh_colors(mesh) if getattr(mesh.visual, "kind", None) in ("face", "vertex") else None
    )
    return Found(np.asarray(mesh.vertices, dtype=np.float64), np.asarray(faces), colors, None)


def _mesh_colors(mesh: trimesh.Trimesh) -> np.ndarray:
    """(F, 4) sRGB bytes of a trimesh's faces (its vertex colours averaged, where it has those;
    white where it has none)."""
    colors = getattr(mesh.visual, "face_colors", None)
    if colors is None:
        return np.full((len(mesh.faces), 4), 255, dtype=np.uint8)
    return np.asarray(colors, dtype=np.uint8)
