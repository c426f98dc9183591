"""The mutations of bench/fuzz_inverse.py (and tests/test_fuzz_inverse.py): what a hostile
file does to a city model, a box hierarchy or a captured model.

Each mutator takes a ``random.Random`` and the file's bytes and returns new bytes: truncation,
byte flips, NUL bytes, blocks repeated; hostile numbers (NaN, inf, 1e400, 2**63, -1) put in
for numbers of the text; JSON values replaced by hostile or wrongly typed ones, deleted,
repeated, nested thousands deep; OBJ lines repeated 100,000 times or given hostile fields;
lying PLY headers (counts, types, formats), lying GLB chunk lengths, glTF buffer URIs that
point out of the folder, at devices or at huge data: URIs.
"""

from __future__ import annotations

import json
import random
import re
import struct

import fuzz_structure

HOSTILE_NUMBERS = (
    "nan", "NaN", "inf", "-inf", "Infinity", "-Infinity", "1e308", "-1e308", "1e400", "-1e400",
    "1e-320", "0", "-0", "-1", "-2", "2147483647", "2147483648", "4294967296",
    "9223372036854775807", "9223372036854775808", "-9223372036854775809", "1e18", "1e9",
    "123456789012345678901234567890", "3.5", "1e8", "-1e8", "100000001",
)  # fmt: skip
HOSTILE_JSON = (
    float("nan"), float("inf"), -float("inf"), 1e308, -1e308, 10**400, 2**63, -(2**63), -1, 0,
    1e-320, 10**9, 2**31, True, False, None, "", "x\x00y", "a" * 100_000, "\n#-->\"'", "1e400",
    [], {}, [[]], [None], {"": None}, [1e308, float("nan"), -1], "../../../etc/passwd",
)  # fmt: skip


# what a mutator raises on a document an earlier mutation reshaped ("buffers": [3], 10**400)
SHAPE_ERRORS = (TypeError, LookupError, AttributeError, ValueError, ArithmeticError, RecursionError)


def _json_paths(node, path=()):
    """Every (path, value) of a JSON document, depth first."""
    yield path, node
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _json_paths(v, (*path, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _json_paths(v, (*path, i))


def _set(doc, path, value):
    if not path:
        return value
    parent = doc
    for key in path[:-1]:
        parent = parent[key]
    parent[path[-1]] = value
    return doc


def _hostile_value(rng: random.Random, old):
    """A hostile replacement for a JSON value: non-finite, huge, wrong type, deep, long."""
    roll = rng.random()
    if roll < 0.5:
        return rng.choice(HOSTILE_JSON)
    if roll < 0.6:
        return [old] * rng.choice((2, 50, 5000))
    if roll < 0.7:
        deep = old
        for _ in range(rng.choice((5, 100, 990, 5000))):
            deep = [deep]
        return deep
    if roll < 0.8 and isinstance(old, (int, float)) and not isinstance(old, bool):
        return old * rng.choice((-1, 1e6, 1e12, 1e300, 0.5)) + rng.choice((0, 1, -1))
    if roll < 0.9 and isinstance(old, str):
        return old + rng.choice(("\x00", "\n", "/../../x", "é" * 3, "💥", "\ud800"[:0]))
    return rng.uniform(-1e9, 1e9) if rng.random() < 0.5 else rng.randint(-(2**40), 2**40)


def _dumps(doc) -> bytes:
    try:
        return json.dumps(doc, allow_nan=True).encode("utf-8", "surrogatepass")
    except (RecursionError, ValueError):
        return b"[" * 100_000 + b"]" * 100_000


def mutate_json(rng: random.Random, data: bytes) -> bytes:
    """A structural mutation of a JSON document: a value replaced, deleted or duplicated."""
    try:
        doc = json.loads(data)
    except (ValueError, RecursionError):
        return mutate_bytes(rng, data)
    paths = list(_json_paths(doc))
    path, value = rng.choice(paths)
    roll = rng.random()
    if roll < 0.7 or not path:
        doc = _set(doc, path, _hostile_value(rng, value))
    elif roll < 0.85:
        parent = doc
        for key in path[:-1]:
            parent = parent[key]
        del parent[path[-1]]
    else:  # a sibling key or item made a copy of this one
        parent = doc
        for key in path[:-1]:
            parent = parent[key]
        if isinstance(parent, list):
            parent.extend([value] * rng.choice((1, 100, 3000)))
        else:
            parent[rng.choice(("name", "type", "id", "uri", "count", "x" * 200))] = value
    return _dumps(doc)


_NUMBER = re.compile(rb"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")


def mutate_numbers(rng: random.Random, data: bytes) -> bytes:
    """A number of the text replaced by a hostile one (NaN, inf, huge, negative, index-like)."""
    matches = list(_NUMBER.finditer(data[:2_000_000]))
    if not matches:
        return mutate_bytes(rng, data)
    m = rng.choice(matches)
    new = rng.choice(HOSTILE_NUMBERS).encode()
    return data[: m.start()] + new + data[m.end() :]


def mutate_bytes(rng: random.Random, data: bytes) -> bytes:
    """Truncation, byte flips, a NUL, a block repeated or deleted."""
    if not data:
        return b"\x00"
    roll = rng.random()
    b = bytearray(data)
    if roll < 0.3:
        return bytes(b[: rng.randrange(len(b))])
    if roll < 0.65:
        for _ in range(rng.choice((1, 2, 8, 64))):
            b[rng.randrange(len(b))] = rng.randrange(256)
        return bytes(b)
    if roll < 0.75:
        b.insert(rng.randrange(len(b)), 0)
        return bytes(b)
    i = rng.randrange(len(b))
    j = min(len(b), i + rng.choice((1, 16, 200, 5000)))
    if roll < 0.88:
        return bytes(b[:j] + b[i:j] * rng.choice((2, 30, 1000)) + b[j:])
    return bytes(b[:i] + b[j:])


def mutate_lines(rng: random.Random, data: bytes) -> bytes:
    """OBJ/ASCII lines: one duplicated many times, dropped, or given a hostile field."""
    lines = data.split(b"\n")
    i = rng.randrange(len(lines))
    roll = rng.random()
    if roll < 0.25:
        lines[i:i] = [lines[i]] * rng.choice((10, 1000, 100_000))
    elif roll < 0.4:
        del lines[i]
    elif roll < 0.6:
        word = rng.choice(
            (b"o ", b"g ", b"usemtl ", b"f ", b"v ", b"vn ", b"mtllib ", b"s ", b"l ")
        )
        tail = rng.choice((b"", b"a" * 100_000, b"\x00", b"x\ny", b"1 2", b"-1 -2 -3", b"0 0 0"))
        lines.insert(i, word + tail)
    else:
        fields = lines[i].split(b" ")
        k = rng.randrange(len(fields))
        fields[k] = rng.choice(HOSTILE_NUMBERS).encode() + rng.choice((b"", b"/1", b"//", b"/x"))
        lines[i] = b" ".join(fields)
    return b"\n".join(lines)


def mutate_ply_header(rng: random.Random, data: bytes) -> bytes:
    """A lying PLY header: an element count, a property type or the format changed."""
    end = data.find(b"end_header")
    if end < 0:
        return mutate_bytes(rng, data)
    head, body = data[:end], data[end:]
    lines = head.split(b"\n")
    counts = [i for i, line in enumerate(lines) if line.startswith(b"element")]
    roll = rng.random()
    if counts and roll < 0.6:
        i = rng.choice(counts)
        parts = lines[i].split(b" ")
        counts = (*HOSTILE_NUMBERS[:4], "0", "-1", "1000000000", "4294967295", "9" * 20)
        parts[-1] = rng.choice(counts).encode()
        lines[i] = b" ".join(parts)
    elif roll < 0.8:
        i = rng.randrange(len(lines))
        lines[i] = lines[i].replace(b"float", rng.choice((b"double", b"uchar", b"list", b"int")))
        lines[i] = lines[i].replace(b"uchar", rng.choice((b"int", b"double", b"uint")))
    else:
        lines = [
            line.replace(b"ascii", b"binary_little_endian").replace(
                b"binary_little_endian", rng.choice((b"ascii", b"binary_big_endian"))
            )
            for line in lines
        ]
    return b"\n".join(lines) + body


def mutate_glb(rng: random.Random, data: bytes) -> bytes:
    """GLB: the JSON chunk mutated structurally (lengths kept right), or lying lengths."""
    if len(data) < 20 or data[:4] != b"glTF":
        return mutate_bytes(rng, data)
    json_len = struct.unpack_from("<I", data, 12)[0]
    roll = rng.random()
    if roll < 0.6:
        doc = data[20 : 20 + json_len]
        new = mutate_json(rng, doc)
        new += b" " * (-len(new) % 4)
        rest = data[20 + json_len :]
        body = struct.pack("<II", len(new), 0x4E4F534A) + new + rest
        return b"glTF" + struct.pack("<II", 2, 12 + len(body)) + body
    b = bytearray(data)
    offsets = [8, 12]
    if 20 + json_len + 8 <= len(data):
        offsets.append(20 + json_len)
    where = rng.choice(offsets)
    value = rng.choice((0, 1, 3, 0xFFFFFFFF, 0x7FFFFFFF, len(data) * 2, len(data) - 1))
    struct.pack_into("<I", b, where, value)
    return bytes(b)


def mutate_gltf_uri(rng: random.Random, data: bytes) -> bytes:
    """glTF: a buffer or image URI pointed elsewhere (outside, a device, a huge data: URI)."""
    try:
        doc = json.loads(data)
        buffers = doc["buffers"]
    except (ValueError, KeyError, TypeError, RecursionError):
        return mutate_json(rng, data)
    if not buffers:
        return mutate_json(rng, data)
    buf = rng.choice(buffers)
    buf["uri"] = rng.choice(
        (
            "../../../../etc/passwd", "/etc/passwd", "/dev/zero", "/proc/self/mem", "missing.bin",
            "data:application/octet-stream;base64," + "A" * 4_000_000,
            "data:application/octet-stream;base64,@@@", "data:,", "file:///etc/passwd",
            "http://example.com/x.bin", "%2e%2e/%2e%2e/etc/passwd", "model.bin\x00.txt", "",
        )
    )  # fmt: skip
    if rng.random() < 0.3:
        buf["byteLength"] = rng.choice((0, -1, 2**62, 10**12, 1.5))
    return _dumps(doc)


def mutate_mild(rng: random.Random, data: bytes) -> bytes:
    """Up to eight numbers of the text scaled or shifted a little: a file that still reads,
    so that the cases reach the analysis after the reader (box overlaps, schemas, clusters)."""
    matches = list(_NUMBER.finditer(data[:2_000_000]))
    if not matches:
        return mutate_bytes(rng, data)
    out = data
    for m in sorted(
        rng.sample(matches, min(len(matches), rng.randint(1, 8))), key=lambda m: -m.start()
    ):
        value = float(m.group()) * rng.choice((0.5, 0.99, 1.01, 2, -1, 0)) + rng.choice((0, 1, -1))
        text = str(int(value)) if b"." not in m.group() and value.is_integer() else repr(value)
        out = out[: m.start()] + text.encode() + out[m.end() :]
    return out


def mutate_box_tree(rng: random.Random, data: bytes) -> bytes:
    """A box hierarchy changed so that it stays valid (bench/fuzz_structure.py)."""
    return fuzz_structure.mutate_boxes(rng, data, mutate_json)


def mutate_parts(rng: random.Random, data: bytes) -> bytes:
    """A captured model changed so that it stays valid (bench/fuzz_structure.py)."""
    return fuzz_structure.mutate_captured(rng, data, mutate_json)


MUTATORS = {
    "obj": (mutate_mild, mutate_lines, mutate_numbers, mutate_bytes),
    "ply": (mutate_mild, mutate_ply_header, mutate_numbers, mutate_bytes),
    "gltf": (mutate_mild, mutate_json, mutate_gltf_uri, mutate_numbers, mutate_bytes),
    "glb": (mutate_glb, mutate_bytes),
    "cityjson": (mutate_mild, mutate_json, mutate_numbers, mutate_bytes),
    "boxes": (mutate_box_tree, mutate_mild, mutate_json, mutate_numbers, mutate_bytes),
    "captured": (mutate_parts, mutate_mild, mutate_json, mutate_numbers, mutate_bytes),
}
WEIGHTS = {
    "mutate_bytes": 1,
    "mutate_numbers": 2,
    "mutate_mild": 2,
    "mutate_box_tree": 6,
    "mutate_parts": 6,
}  # the structural mutators get 3


def mutant(rng: random.Random, surface: str, data: bytes) -> bytes:
    """One to three mutations of a seed file of ``surface``."""
    mutators = MUTATORS[surface]
    weights = [WEIGHTS.get(m.__name__, 3) for m in mutators]
    for _ in range(rng.choice((1, 1, 1, 2, 3))):
        mutator = rng.choices(mutators, weights)[0]
        try:
            data = mutator(rng, data)
        except SHAPE_ERRORS:  # an earlier mutation left a shape this one does not expect
            data = mutate_bytes(rng, data)
        if len(data) > 50_000_000:
            data = data[:50_000_000]
    return data
