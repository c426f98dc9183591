"""What ``bgr infer`` reads, and one clear error for a file it does not (a photo, a binary file, a
file whose extension names no input it knows).

:func:`check_input` looks at a file's extension and its first bytes before any reader opens it,
so that a JPEG given to ``bgr infer`` is called a JPEG, and the kinds and their file types are
named, rather than a reader failing to decode it.  The readers call :func:`not_text` when the
bytes they were given do not decode, for the same message from the Python API.
"""

from __future__ import annotations

import codecs
import os

from bgr.grammar.errors import BgrError, Diagnostic

# what each --kind reads, by extension (auto picks the kind from them: cli._infer_kind)
CITY_EXTENSIONS = (".obj", ".ply", ".glb", ".gltf", ".city.json", ".city.jsonl", ".jsonl")
TEXT_EXTENSIONS = (".json", ".bgr")
READS = (
    "bgr infer reads --kind schema: a terminal list (.json, from bgr derive -o x.json), a "
    "captured model (.json) or a grammar (.bgr); --kind city: a 3D city (.obj, .ply, .glb, "
    '.gltf, .city.json, .city.jsonl); --kind boxes: a box hierarchy (.json with a "root" box); '
    "--kind style: a textured building (.gml, .xml, .obj, .glb, .gltf); --kind facade: a "
    "rectified façade photograph (.jpg, .png); --kind image: a photograph of a building with "
    "--silhouette"
)

# magic numbers of the files people give by mistake: (prefix, what it is)
_MAGIC = (
    (b"\xff\xd8\xff", "a JPEG image"),
    (b"\x89PNG\r\n\x1a\n", "a PNG image"),
    (b"GIF87a", "a GIF image"),
    (b"GIF89a", "a GIF image"),
    (b"II*\x00", "a TIFF image"),
    (b"MM\x00*", "a TIFF image"),
    (b"BM", "a BMP image"),
    (b"%PDF", "a PDF document"),
    (b"PK\x03\x04", "a ZIP archive (or an office document)"),
    (b"\x1f\x8b", "a gzip-compressed file"),
    (b"glTF", "a binary glTF model"),
)
_HEAD = 1 << 16  # bytes looked at


def describe(head: bytes) -> str | None:
    """What ``head``, a file's first bytes, is when it is not UTF-8 text: an image or another
    known binary format by its magic number, else "a binary file"; None for text."""
    if head[:4] == b"RIFF" and head[8:12] == b"WEBP":
        return "a WebP image"
    for magic, what in _MAGIC:
        if head.startswith(magic) and (magic != b"BM" or b"\x00" in head[:64]):
            return what
    if b"\x00" in head:
        return "a binary file"
    try:  # not final: a character cut at the end of the head is no error
        codecs.getincrementaldecoder("utf-8")().decode(head, final=False)
    except UnicodeDecodeError:
        return "a binary file (not UTF-8 text)"
    return None


def not_text(shown: str, head: bytes, kind: str = "schema") -> BgrError:
    """The error for an input of ``kind`` that is not text."""
    what = describe(head) or "a binary file (not UTF-8 text)"
    wanted = {
        "schema": "a terminal list, a captured model or a grammar",
        "boxes": "a box hierarchy",
    }.get(kind, "an input bgr infer reads")
    return BgrError(Diagnostic(shown, 0, 0, f"{what}, not {wanted}", READS))


def check_input(path: str | os.PathLike, kind: str | None) -> None:
    """Refuse, before any reader opens it, an input of ``bgr infer`` that is binary where text
    is read (--kind schema or boxes, or a .json or .bgr) or, with no --kind, whose extension
    names no input.  A missing file, a folder or a FIFO is left to the readers' own messages;
    --kind city names its formats itself."""
    shown = str(path)
    lower = shown.lower()
    if kind == "city" or (kind is None and lower.endswith(CITY_EXTENSIONS)):
        return
    head = b""
    if os.path.isfile(path):  # follows links; never opens a FIFO or a device
        try:
            with open(path, "rb") as f:
                head = f.read(_HEAD)
        except OSError:
            return
    what = describe(head)
    if kind is None and not lower.endswith(TEXT_EXTENSIONS) and os.path.isfile(path):
        ext = os.path.splitext(shown)[1]
        shape = what or (f"a '{ext}' file" if ext else "a file without an extension")
        raise BgrError(
            Diagnostic(
                shown,
                0,
                0,
                f"{shape}, not an input bgr infer reads",
                READS + "; give --kind to read another file as one of them",
            )
        )
    if what is not None:
        raise not_text(shown, head, kind or "schema")
