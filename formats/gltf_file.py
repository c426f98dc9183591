"""A glTF file's JSON and its buffers, each checked to be what it says before it is used.

A ``.glb`` holds its JSON and (usually) buffer 0 in chunks whose lengths it states; a ``.gltf``
names its buffers by URI: base64 ``data:`` URIs, or files beside it, which exporters (trimesh,
Blender's "glTF separate") often split into one file per buffer.  Chunk lengths are checked
against the file, a data URI's length against its ``byteLength`` before it is decoded, and a
file URI is read only inside the model's own folder (symlinks and ``..`` resolved, no URL or
absolute path), like the ``mtllib`` of an OBJ.  Several buffers are joined into one, each
bufferView checked to lie inside its own buffer first, so the rest of the reader
(:mod:`.glb_read`) sees buffer 0 only.  Views compressed by EXT_meshopt_compression are decoded
into their places first (:mod:`.gltf_meshopt`).
"""

from __future__ import annotations

import base64
import json
import re
import struct
from pathlib import Path
from urllib.parse import unquote

from bgr.grammar.paths import read_input, resolved

from .gltf_checks import data_uri_payload, fail, quoted, view_span, whole
from .gltf_meshopt import compressed, decoded

JSON_CHUNK, BIN_CHUNK = 0x4E4F534A, 0x004E4942
_SCHEME = re.compile(r"[A-Za-z][A-Za-z0-9+.-]*:")  # http:, file:, ... (not a relative path)
_BUFFER_HINT = "bgr reads buffers embedded in the file (data: URIs) or in files in its folder"


def parse(data: bytes, folder: Path | None = None) -> tuple[dict, bytes]:
    """(glTF JSON, buffer 0) of a .glb or .gltf file's bytes.  A buffer is the GLB's BIN chunk,
    a base64 ``data:`` URI, or a file named by a relative URI inside ``folder`` (the model's own
    folder: :func:`load` passes it; without one such a file is an error).  A file of several
    buffers comes back with them joined as buffer 0, its bufferViews moved to match."""
    if data[:4] == b"glTF":
        gltf, chunk = _glb_chunks(data)
    else:
        gltf, chunk = _json(data), None
    buffers = gltf.get("buffers")
    if not isinstance(buffers, list) or not buffers:
        return gltf, chunk or b""
    blobs = [_buffer(buffers, k, chunk, folder) for k in range(len(buffers))]
    if compressed(gltf):  # EXT_meshopt_compression: the views decoded into their places
        blobs = decoded(gltf, blobs)
    if len(blobs) == 1:
        return gltf, blobs[0]
    return gltf, _joined(gltf, blobs)


def load(path: Path | str) -> tuple[dict, bytes]:
    """(glTF JSON, buffer 0) of a .glb or .gltf file, its buffers read from beside it if need be."""
    return parse(read_input(path, "model file"), resolved(path).parent)


def _glb_chunks(data: bytes) -> tuple[dict, bytes | None]:
    """The JSON chunk and the BIN chunk (None if none) of a GLB, each checked to fit the file."""
    if len(data) < 20:
        fail("", f"not a glTF 2.0 binary: its {len(data)} bytes are fewer than a GLB header")
    _, version, length = struct.unpack_from("<4sII", data)
    if version != 2 or length != len(data):
        fail("", f"not a glTF 2.0 binary (version {version}, length {length} of {len(data)})")
    json_len, kind = struct.unpack_from("<II", data, 12)
    if kind != JSON_CHUNK or 20 + json_len > len(data):
        fail("", f"its first chunk is not JSON of {json_len} bytes inside the file")
    gltf = _json(data[20 : 20 + json_len])
    at, blob = 20 + json_len, None
    if at + 8 <= len(data):
        bin_len, kind = struct.unpack_from("<II", data, at)
        if kind == BIN_CHUNK:
            if at + 8 + bin_len > len(data):
                fail("", f"its BIN chunk of {bin_len} bytes runs past the end of the file")
            blob = data[at + 8 : at + 8 + bin_len]
    return gltf, blob


def _json(text: bytes) -> dict:
    """A glTF's JSON object, or a located error (not a Python one) for text that is not one."""
    try:
        gltf = json.loads(text)
    except RecursionError:
        fail("", "its JSON nests too deeply")
    except ValueError as exc:
        fail("", f"its JSON does not parse: {str(exc)[:160]}")
    if not isinstance(gltf, dict):
        fail("", "its JSON is not an object")
    return gltf


def _buffer(buffers: list, k: int, chunk: bytes | None, folder: Path | None) -> bytes:
    """Buffer ``k``: from its URI, else (buffer 0 of a GLB) the BIN chunk.  A buffer without
    either is left empty: the accessors that need it say so."""
    buffer = buffers[k]
    if not isinstance(buffer, dict):
        fail(f"buffer {k}", "is not a JSON object")
    if "uri" not in buffer:
        return chunk if k == 0 and chunk is not None else b""
    uri = buffer["uri"]
    if not isinstance(uri, str):
        fail(f"buffer {k}", "uri must be a string")
    size = whole(buffer.get("byteLength"), f"buffer {k}", "byteLength", 1)
    return _uri_buffer(uri, size, folder, f"buffer {k}")


def _uri_buffer(uri: str, size: int, folder: Path | None, where: str) -> bytes:
    """A buffer of ``size`` bytes named by ``uri``: a base64 data: URI (its length checked
    before decoding) or a relative path that stays inside ``folder`` once symlinks and ``..``
    are resolved."""
    if uri.startswith("data:"):
        payload = data_uri_payload(uri, size, where)
        try:
            return base64.b64decode(payload, validate=True)
        except ValueError:
            fail(where, "its data: URI is not valid base64")
    if _SCHEME.match(uri):
        fail(where, f"uri {quoted(uri)} is not a file in the model's folder", _BUFFER_HINT)
    if folder is None:
        fail(where, f"its data is in the file {quoted(uri)}: read the model from its path")
    root = resolved(folder)
    try:
        target = resolved(root / unquote(uri))
        if not target.is_relative_to(root):
            fail(where, f"its file {quoted(uri)} lies outside the model's folder", _BUFFER_HINT)
        return read_input(target, "glTF buffer")
    except (OSError, ValueError) as exc:  # ValueError: a NUL in the name
        reason = getattr(exc, "strerror", None) or str(exc)
        fail(where, f"cannot read its buffer {quoted(uri)}: {reason}")


def _joined(gltf: dict, blobs: list[bytes]) -> bytes:
    """Several buffers as one (each from a 4-byte boundary), every bufferView checked to lie
    inside its own buffer, then moved to the joined one; ``gltf`` is changed to match."""
    sizes = [
        whole(b.get("byteLength"), f"buffer {k}", "byteLength", 1)
        for k, b in enumerate(gltf["buffers"])
    ]
    for k, (size, blob) in enumerate(zip(sizes, blobs, strict=True)):
        if size > len(blob):
            fail(f"buffer {k}", f"byteLength {size} is more than the {len(blob)} bytes of its data")
    starts = [0]
    for size in sizes:
        starts.append(starts[-1] + size + (-size % 4))
    views = gltf.get("bufferViews", [])
    if not isinstance(views, list):
        fail("", "bufferViews must be a list")
    for v, view in enumerate(views):
        if not isinstance(view, dict):
            fail(f"bufferView {v}", "is not a JSON object")
        k, start, _ = view_span(view, v, sizes)
        view["buffer"], view["byteOffset"] = 0, starts[k] + start
    gltf["buffers"] = [{"byteLength": starts[-1]}]
    return b"".join(
        blob[:size] + b"\0" * (-size % 4) for size, blob in zip(sizes, blobs, strict=True)
    )
