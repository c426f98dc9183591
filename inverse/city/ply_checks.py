"""What a PLY file must hold before trimesh reads it, and what trimesh's mesh must hold after.

trimesh believes a PLY header: an ``element vertex 1000000000`` in a 1 KB file makes it size
arrays by the count, and face indices beyond the vertices or vertices of NaN reach numpy's
integer casts and bgr's welding as they are.  :func:`check_header` refuses counts the
file's size cannot hold, before any allocation; :func:`check_mesh` refuses faces naming
vertices the file does not have, each with a message that says where.
"""

from __future__ import annotations

import re

import numpy as np

from bgr.grammar.errors import BgrError, Diagnostic

# bytes of each PLY scalar type in a binary body
SIZES = {
    "char": 1, "uchar": 1, "int8": 1, "uint8": 1, "short": 2, "ushort": 2, "int16": 2,
    "uint16": 2, "int": 4, "uint": 4, "int32": 4, "uint32": 4, "float": 4, "float32": 4,
    "double": 8, "float64": 8,
}  # fmt: skip
MAX_HEADER = 1 << 20  # bytes looked at for end_header
_ELEMENT = re.compile(rb"element\s+(\S+)\s+(\S+)")


def check_header(shown: str, data: bytes) -> None:
    """Refuse a header whose element counts are not whole numbers from 0, or which claim more
    elements than the body's bytes can hold (each element takes at least one byte per
    property in binary, two characters per property in ASCII)."""
    end = data.find(b"end_header", 0, MAX_HEADER)
    if not data.startswith(b"ply") or end < 0:
        return  # trimesh's own message says it is no PLY
    body = len(data) - end - len(b"end_header")
    binary = b"binary" in data[:end]
    lines = data[:end].splitlines()
    elements: list[tuple[int, str, int, int]] = []  # (line, name, count, bytes each at least)
    for number, line in enumerate(lines, start=1):
        words = line.split()
        match = _ELEMENT.match(line.strip())
        if match:
            count = _count(shown, number, match[1].decode("ascii", "replace"), match[2])
            elements.append((number, match[1].decode("ascii", "replace"), count, 0))
        elif words[:1] == [b"property"] and elements and len(words) >= 3:
            each = _property_bytes(words, binary)
            line_no, name, count, size = elements[-1]
            elements[-1] = (line_no, name, count, size + each)
    need = 0
    for line_no, name, count, size in elements:
        need += count * size
        if need > body:
            raise BgrError(
                Diagnostic(
                    shown,
                    line_no,
                    1,
                    f"the header claims {count:,} '{name}' elements, more than the file's "
                    f"{body:,} bytes after the header can hold",
                    "the file is cut short or its header is wrong: export it again",
                )
            )


def _count(shown: str, line: int, name: str, raw: bytes) -> int:
    """An element count: ASCII digits, below 2**40."""
    if not re.fullmatch(rb"[0-9]{1,13}", raw):
        raise BgrError(
            Diagnostic(
                shown,
                line,
                1,
                f"element '{name}': its count "
                f"'{raw[:20].decode('ascii', 'replace')}' is not a whole number from 0",
                "a PLY header says `element vertex N` with N the number of vertices",
            )
        )
    return int(raw)


def _property_bytes(words: list[bytes], binary: bool) -> int:
    """The fewest bytes a property takes in the body: its type's size (a list: its count's),
    or two characters in ASCII."""
    if not binary:
        return 2
    kind = words[2] if words[1] == b"list" else words[1]
    return SIZES.get(kind.decode("ascii", "replace"), 1)


def check_mesh(shown: str, vertices: np.ndarray, faces: np.ndarray) -> None:
    """Refuse faces that name vertices the file does not have (trimesh reads them as they
    are), naming the first."""
    if not len(faces):
        return
    bad = (faces < 0) | (faces >= len(vertices))
    if not bad.any():
        return
    k = int(np.argmax(bad.any(axis=1)))
    value = int(faces[k][bad[k]][0])
    raise BgrError(
        Diagnostic(
            shown,
            0,
            0,
            f"face {k + 1} (counted from 1) names vertex {value}, which the file does not have",
            f"PLY counts vertices from 0; this file has {len(vertices):,}",
        )
    )
