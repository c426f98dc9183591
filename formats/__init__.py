"""File formats (LANGUAGE.md section 11): a module per format, its writer and (where the inverse
modules or the renderer read it) its reader side by side.  The interpreter only makes the terminal
table; every module that touches a file goes through this package.

    from bgr.formats import write, write_json, to_trimesh
    write(table, Path("out.glb"), seed=3, attrs={"height": 18})     # format from the extension
    write(table, Path("-"), seed=3, attrs={}, fmt="json")            # the terminal list on stdout

Every file is written atomically (:mod:`.atomic`): a failure leaves no output and no temporary
file behind.  Failures a user can act on (unknown format, unwritable folder) are ``BgrError``.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np

from bgr.grammar.errors import BgrError, Diagnostic
from bgr.interpreter.limits import MAX_COORDINATE
from bgr.interpreter.terminals import TerminalTable

from .cityjson import write_cityjson, write_cityjsonseq
from .cityjson_read import read_cityjson
from .glb import write_glb, write_gltf
from .glb_read import read_glb
from .meshes import bake, to_trimesh
from .obj import write_obj
from .ply import write_ply
from .stl import write_stl
from .terminal_json import write_json, write_json_bytes
from .texture_files import Copies, atomic_with_images, texture_folder

# format name -> writer(table, binary stream, *, seed, attrs); obj is special (two files)
# the writer of each format: (table, binary stream, seed=, attrs=) -> None
FORMATS: dict[str, Callable[..., None]] = {
    "glb": write_glb,
    "gltf": write_gltf,
    "obj": write_obj,
    "ply": write_ply,
    "stl": write_stl,
    "json": write_json_bytes,
    "city.json": write_cityjson,
    "city.jsonl": write_cityjsonseq,
}
EXTENSIONS = {f".{name}": name for name in FORMATS}
GLTF = ("glb", "gltf")  # the formats that take the ``gltf`` options of write()
COPIES = ("obj", "city.json")  # the formats whose images are copied beside them

__all__ = [
    "write",
    "write_json",
    "to_trimesh",
    "read_glb",
    "read_cityjson",
    "bake",
    "format_of",
    "check_writable",
    "FORMATS",
    "EXTENSIONS",
]


def check_writable(table: TerminalTable, attrs: dict) -> None:
    """Refuse a table no file can hold: a terminal placed at a non-finite or absurd coordinate
    (JSON has no NaN, a GLB reader would drop the scene), or a non-finite attr value.  The
    engine stops such shapes where they are made; this guards tables built another way."""
    table.freeze()
    for name, value in attrs.items():
        if isinstance(value, float) and not math.isfinite(value):
            raise BgrError(f"cannot write attr '{name}' = {value!r}: numbers must be finite")
    if not len(table):
        return
    for mesh in table.library.meshes:
        if not np.isfinite(mesh.vertices).all():
            raise BgrError(f"cannot write the mesh '{mesh.name}': its vertices are not finite")
    columns = (table.origin, table.size, table.axes.reshape(len(table), 9))
    bad = np.zeros(len(table), dtype=bool)
    for column in columns:
        bad |= ~(np.abs(column) <= MAX_COORDINATE).all(axis=1)  # NaN compares false
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        raise BgrError(
            f"cannot write terminal {row} ('{table.label[row]}', made by rule "
            f"'{table.rule[row]}' at {table.path[row]}): its scope is not finite or lies "
            f"beyond {MAX_COORDINATE:,.0f} m ({int(bad.sum()):,} terminals like it)"
        )


def _known() -> str:
    return "known extensions: " + ", ".join(EXTENSIONS)


def format_of(path: Path, fmt: str | None = None) -> str:
    """The format name for an output path (or the explicit ``fmt``); BgrError when unknown."""
    if fmt is not None:
        name = fmt.lower().lstrip(".")
        if name not in FORMATS:
            raise BgrError(f"unknown output format '{fmt}'; known formats: {', '.join(FORMATS)}")
        return name
    name = Path(str(path).lower()).name
    # the longest extension first, so that .city.json is CityJSON and not the terminal list
    for ext in sorted(EXTENSIONS, key=len, reverse=True):
        if name.endswith(ext) and len(name) > len(ext):
            return EXTENSIONS[ext]
    suffix = Path(name).suffix
    shown = (
        f"unknown output extension '{suffix}'"
        if suffix
        else "the output file name has no extension"
    )
    raise BgrError(Diagnostic(str(path), 0, 0, shown, _known()))


def write(
    table: TerminalTable,
    path: Path,
    *,
    seed: int,
    attrs: dict,
    fmt: str | None = None,
    gltf: dict | None = None,
) -> None:
    """Write ``table`` to ``path`` in the format of its extension, or ``fmt`` when given.

    ``path`` ``"-"`` writes to standard output and needs ``fmt`` (not ``obj``, which is two files).
    For ``.obj`` the ``.mtl`` is written beside it, with the same stem; the images of a textured
    ``.obj`` or ``.city.json`` are copied into ``{stem}_textures/`` beside it
    (:mod:`.texture_files`).  ``gltf``: options of the glTF writers (``group_by``,
    ``instancing``; see :func:`.glb.build`), ignored by others.
    """
    check_writable(table, attrs)
    options = gltf or {}
    path = Path(path)
    if str(path) == "-":
        if fmt is None:
            raise BgrError("writing to standard output ('-') needs a format, e.g. --format json")
        name = format_of(path, fmt)
        if name == "json":
            write_json(table, sys.stdout, seed=seed, attrs=attrs)
        elif name == "obj":
            raise BgrError(
                "obj cannot go to standard output (it comes with a .mtl file); give a file name"
            )
        elif name in COPIES and table.textured():
            raise BgrError(
                f"a textured {name} cannot go to standard output (its images are copied beside "
                "it); give a file name"
            )
        else:
            sys.stdout.flush()
            extra = options if name in GLTF else {}
            FORMATS[name](table, sys.stdout.buffer, seed=seed, attrs=attrs, **extra)
            sys.stdout.buffer.flush()
        return

    name = format_of(path, fmt)
    # OBJ and CityJSON name their images: copied into a folder beside the file (texture_files)
    copies = None
    if name in COPIES and table.textured():  # CityJSON has no normal maps
        copies = Copies.of(table, texture_folder(path), (0, 1) if name == "obj" else (0,))
    if name == "obj":
        mtl = path.with_suffix(".mtl")
        with atomic_with_images([path, mtl], copies) as (f_obj, f_mtl):
            write_obj(
                table, f_obj, f_mtl, mtl_name=mtl.name, seed=seed, attrs=attrs, textures=copies
            )
    else:
        with atomic_with_images([path], copies) as (f,):
            extra = options if name in GLTF else {"textures": copies} if copies else {}
            FORMATS[name](table, f, seed=seed, attrs=attrs, **extra)
