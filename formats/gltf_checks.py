"""Checks of a glTF file's JSON against its own rules and its buffer, made before a byte is read.

A glTF file is offsets, lengths, strides and indices into a buffer, written by whoever made the
file, and numpy believes what it is told: a negative ``byteStride`` handed to ``as_strided``
reads process memory (or crashes the process), a node that lists its child twice doubles the
walk at every level.  So every number :mod:`.glb_read` uses is checked here first, against the
glTF 2.0 specification and the buffer's real size, and a file that breaks a rule is a
:class:`BgrError` naming what breaks it ("accessor 3: byteStride -64 of bufferView 0 ...", "node
7: ...") -- never a crash, a hang or values read from outside the file.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NoReturn

import numpy as np

from bgr.grammar.errors import BgrError, Diagnostic

COMPONENTS = {5120: "i1", 5121: "u1", 5122: "<i2", 5123: "<u2", 5125: "<u4", 5126: "<f4"}
COMPONENT_NAMES = {
    5120: "int8",
    5121: "uint8",
    5122: "int16",
    5123: "uint16",
    5125: "uint32",
    5126: "float32",
}
WIDTHS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
FLOAT = (5126,)
UNSIGNED = (5121, 5123, 5125)  # what indices may be (glTF 2.0, 3.7.2.1)

MAX_NODE_VISITS = 1_000_000
"""Nodes placed when reading one file, a node reached along several paths of the tree counted
once per path.  glTF wants a tree (a node has at most one parent), which places each node once;
bgr also reads a node shared by several parents, but a chain of shared nodes doubles at each
step (41 nodes: 2^40 placements), so the count is taken before the walk and a file past the cap
is refused at once.  A million placements take about five seconds to walk; bgr's own files
place a node per lot and label."""

SINGULAR = {
    "accessors": "accessor",
    "bufferViews": "bufferView",
    "buffers": "buffer",
    "materials": "material",
    "meshes": "mesh",
    "nodes": "node",
    "scenes": "scene",
}
STORED = "Draco-compressed and sparse data is not read"


def fail(where: str, message: str, hint: str | None = None) -> NoReturn:
    """Stop reading: ``where`` (an accessor, node, ...) breaks a rule; the caller adds the file."""
    raise BgrError(Diagnostic("", 0, 0, f"{where}: {message}" if where else message, hint))


def quoted(text: str, limit: int = 80) -> str:
    """``text`` as a message may show it: cut to ``limit`` characters, control characters
    escaped (a file's strings reach the terminal)."""
    cut = text[:limit] + ("..." if len(text) > limit else "")
    return "'" + cut.encode("unicode_escape").decode("ascii") + "'"


def whole(value: Any, where: str, name: str, low: int = 0, high: int | None = None) -> int:
    """``value`` as an int from ``low`` to ``high``: JSON floats (3.0, 1e20) and booleans are
    refused, as the glTF schema refuses them."""
    ok = isinstance(value, int) and not isinstance(value, bool)
    if not ok or value < low or (high is not None and value > high):
        shown = quoted(value) if isinstance(value, str) else repr(value)[:40]
        span = f"from {low}" + (f" to {high}" if high is not None else "")
        fail(where, f"{name} {shown} is not a whole number {span}")
    return value


def entry(gltf: dict, key: str, index: Any, where: str) -> dict:
    """``gltf[key][index]``, an object, or a located error naming ``where`` refers to it."""
    items = gltf.get(key)
    one = SINGULAR.get(key, key)
    if not isinstance(items, list):
        fail(where, f"refers to {one} {index!r:.40}, but the file has no {key} list")
    index = whole(index, where, f"its {one} index")
    if index >= len(items):
        fail(where, f"{one} {index} does not exist (the file has {len(items)})")
    item = items[index]
    if not isinstance(item, dict):
        fail(f"{one} {index}", "is not a JSON object")
    return item


def numbers(value: Any, n: int, where: str, name: str) -> np.ndarray:
    """``value`` as ``n`` finite float64s (a node's translation, a material's colour...)."""
    ok = isinstance(value, list) and len(value) == n
    ok = ok and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
    try:
        array = np.array(value, dtype=np.float64) if ok else None
    except OverflowError:  # an int of hundreds of digits
        array = None
    if array is None or not np.isfinite(array).all():
        fail(where, f"{name} must be {n} finite numbers")
    return array


# --------------------------------------------------------------------------------------------
# accessors


@dataclass(frozen=True)
class Layout:
    """Where an accessor's elements lie in buffer 0, checked to lie inside it."""

    start: int  # byte of the first element
    stride: int  # bytes from one element to the next
    count: int
    width: int  # components per element
    dtype: np.dtype

    @property
    def element(self) -> int:
        return self.width * self.dtype.itemsize


def buffer_size(gltf: dict, blob: bytes) -> int:
    """Buffer 0's byteLength, checked against the bytes the file really holds for it."""
    buffer = entry(gltf, "buffers", 0, "the file's data")
    size = whole(buffer.get("byteLength"), "buffer 0", "byteLength", 1)
    if size > len(blob):
        fail("buffer 0", f"byteLength {size} is more than the {len(blob)} bytes of its data")
    return size


def layout(gltf: dict, size: int, index: Any, where: str = "") -> Layout:
    """The checked :class:`Layout` of accessor ``index`` in a buffer of ``size`` bytes: known
    component type and type, offsets, length and stride within the glTF rules, and the last
    element's end inside its bufferView and the buffer (so no view can reach past them)."""
    acc = entry(gltf, "accessors", index, where)
    name = f"accessor {index}"
    if "sparse" in acc:
        fail(name, "sparse accessors are not supported", STORED)
    if "bufferView" not in acc:
        fail(name, "has no bufferView (its values would all be zero)", STORED)
    ctype = acc.get("componentType")
    if not isinstance(ctype, int) or isinstance(ctype, bool) or ctype not in COMPONENTS:
        fail(name, f"componentType {ctype!r:.40} is not one of {sorted(COMPONENTS)}")
    kind = acc.get("type")
    if not isinstance(kind, str) or kind not in WIDTHS:
        shown = quoted(kind) if isinstance(kind, str) else repr(kind)[:40]
        fail(name, f"type {shown} is not one bgr reads ({', '.join(WIDTHS)})")
    dtype, width = np.dtype(COMPONENTS[ctype]), WIDTHS[kind]
    count = whole(acc.get("count"), name, "count")
    offset = whole(acc.get("byteOffset", 0), name, "byteOffset")
    v = acc["bufferView"]
    view = entry(gltf, "bufferViews", v, name)
    _, start, length = view_span(view, v, [size])
    element = width * dtype.itemsize
    stride = element
    if "byteStride" in view:
        stride = view["byteStride"]
        if not isinstance(stride, int) or isinstance(stride, bool) or not 4 <= stride <= 252:
            fail(name, f"byteStride {stride!r:.40} of bufferView {v} is not from 4 to 252")
        if stride % 4 or stride < element:
            fail(
                name,
                f"byteStride {stride} of bufferView {v} is not a multiple of 4 at least "
                f"{element} (one {kind} of {COMPONENT_NAMES[ctype]})",
            )
    end = offset + stride * (count - 1) + element if count else offset
    if end > length:
        fail(
            name,
            f"its {count} elements from byte {offset} end at byte {end} of bufferView {v}, "
            f"which holds {length} bytes",
            "the file is cut short or its counts are wrong",
        )
    return Layout(start + offset, stride, count, width, dtype)


def view_span(view: dict, v: int, sizes: list[int]) -> tuple[int, int, int]:
    """(buffer, byteOffset, byteLength) of bufferView ``v``, checked to lie inside its buffer
    (``sizes``: the byteLength of each buffer)."""
    name = f"bufferView {v}"
    buffer = whole(view.get("buffer"), name, "buffer")
    if buffer >= len(sizes):
        fail(name, f"buffer {buffer} does not exist (the file has {len(sizes)})")
    start = whole(view.get("byteOffset", 0), name, "byteOffset")
    length = whole(view.get("byteLength"), name, "byteLength", 1)
    if start + length > sizes[buffer]:
        fail(
            name,
            f"bytes {start} to {start + length} lie outside buffer {buffer} of "
            f"{sizes[buffer]} bytes",
        )
    return buffer, start, length


def values(blob: bytes, at: Layout) -> np.ndarray:
    """The (count, width) elements of a checked layout: the bytes from the first element's start
    to the last one's end, cut into rows of ``stride`` with a plain reshape (no strided view)."""
    if at.count == 0:
        return np.zeros((0, at.width), dtype=at.dtype)
    span = at.stride * (at.count - 1) + at.element
    raw = np.frombuffer(blob, dtype=np.uint8, count=span, offset=at.start)
    if at.stride != at.element:  # interleaved: pad the last row, then keep each row's element
        rows = np.concatenate([raw, np.zeros(at.stride - at.element, dtype=np.uint8)])
        raw = np.ascontiguousarray(rows.reshape(at.count, at.stride)[:, : at.element])
    return raw.view(at.dtype).reshape(at.count, at.width)


def check_finite(data: np.ndarray, index: int) -> None:
    """Refuse a float accessor holding NaN or an infinity (no later step can place it)."""
    bad = ~np.isfinite(data)
    if bad.any():
        row = int(np.argmax(bad.any(axis=1)))
        fail(f"accessor {index}", f"element {row} holds {data[row].tolist()}, not finite numbers")


def check_kind(gltf: dict, index: int, use: str, components: tuple, types: tuple) -> None:
    """Refuse accessor ``index`` (checked by :func:`layout`) unless its component type and type
    are among those ``use`` (e.g. "POSITION of mesh 0 primitive 0") allows."""
    acc = gltf["accessors"][index]
    ctype, kind = acc["componentType"], acc["type"]
    if ctype not in components or kind not in types:
        allowed = " or ".join(f"{COMPONENT_NAMES[c]} ({c})" for c in components)
        hint = None
        if use.startswith("POSITION") and ctype != 5126:
            hint = "integer positions need KHR_mesh_quantization in the file's extensionsUsed"
        fail(
            f"accessor {index}",
            f"{kind} of {COMPONENT_NAMES[ctype]} ({ctype}), but {use} must be "
            f"{' or '.join(types)} of {allowed}",
            hint,
        )


# --------------------------------------------------------------------------------------------
# the node graph


def children(nodes: list, i: int) -> list[int]:
    """Node ``i``'s children, checked: a list of existing nodes, none twice."""
    node = nodes[i]
    if not isinstance(node, dict):
        fail(f"node {i}", "is not a JSON object")
    kids = node.get("children", [])
    if not isinstance(kids, list):
        fail(f"node {i}", "children must be a list of node indices")
    if not kids:
        return kids
    if not all(type(k) is int for k in kids) or min(kids) < 0 or max(kids) >= len(nodes):
        for k in kids:  # the slow way, to name the child
            whole(k, f"node {i}", "child", 0)
            if k >= len(nodes):
                fail(f"node {i}", f"child {k} does not exist (the file has {len(nodes)} nodes)")
    if len(set(kids)) != len(kids):
        seen: set[int] = set()
        for k in kids:
            if k in seen:
                fail(f"node {i}", f"lists node {k} twice among its children")
            seen.add(k)
    return kids


def node_paths(gltf: dict, roots: list[int], cap: int = MAX_NODE_VISITS) -> dict[int, int]:
    """How many times a walk from ``roots`` places each node it reaches (once per path to it),
    every node on the way checked and the counts taken from the graph's shape, without walking:
    a cycle, or more than ``cap`` placements in all, is a located error at once."""
    nodes = gltf.get("nodes", [])
    if not isinstance(nodes, list):
        fail("", "nodes must be a list")
    for r in roots:
        whole(r, "the scene", "root node", 0)
        if r >= len(nodes):
            fail("the scene", f"root node {r} does not exist (the file has {len(nodes)} nodes)")
    kids: dict[int, list[int]] = {}
    stack = list(roots)
    while stack:  # the reachable nodes, each checked once
        i = stack.pop()
        if i not in kids:
            kids[i] = children(nodes, i)
            stack.extend(kids[i])
    waiting = dict.fromkeys(kids, 0)  # parents not yet counted
    for listed in kids.values():
        for k in listed:
            waiting[k] += 1
    tops = set(roots)
    forest = len(tops) == len(roots) and len(kids) <= cap
    if forest and all(n == (0 if i in tops else 1) for i, n in waiting.items()):
        return dict.fromkeys(kids, 1)  # a tree per root: each node placed once, no cycle
    paths = dict.fromkeys(kids, 0)
    for r in roots:
        paths[r] += 1
    ready = [i for i, n in waiting.items() if n == 0]
    total = done = 0
    while ready:  # Kahn's order: a node's count is final once all its parents are counted
        i = ready.pop()
        done += 1
        total += paths[i]
        if total > cap:
            fail(
                f"node {i}",
                f"the node tree places more than {cap:,} nodes (node {i} is reached "
                f"along {'more than ' if paths[i] > cap else ''}{min(paths[i], cap):,} paths)",
                "glTF wants each node to have at most one parent",
            )
        for k in kids[i]:
            paths[k] = min(paths[k] + paths[i], cap + 1)
            waiting[k] -= 1
            if not waiting[k]:
                ready.append(k)
    if done < len(kids):
        _cycle(kids, waiting)
    return paths


def _cycle(kids: dict[int, list[int]], waiting: dict[int, int]) -> NoReturn:
    """Name a cycle among the nodes Kahn's order could not reach (each has a parent among them,
    so following parents must come round)."""
    parent: dict[int, int] = {}
    for i, listed in kids.items():
        if waiting[i]:
            for k in listed:
                if waiting[k]:
                    parent.setdefault(k, i)
    at = next(iter(parent))
    trail: list[int] = []
    while at not in trail:
        trail.append(at)
        at = parent[at]
    loop = trail[trail.index(at) :][::-1]
    shown = " -> ".join(str(i) for i in (loop + loop[:1])[:12])
    fail(f"node {at}", f"is its own descendant (nodes {shown})", "glTF wants a tree of nodes")


def check_roots(gltf: dict) -> list[int]:
    """The default scene's root nodes, checked (without scenes: every node nobody lists as a
    child), and the whole tree under them checked by :func:`node_paths`."""
    nodes = gltf.get("nodes", [])
    if not isinstance(nodes, list):
        fail("", "nodes must be a list")
    if gltf.get("scenes"):
        scene = entry(gltf, "scenes", gltf.get("scene", 0), "the default scene")
        roots = scene.get("nodes", [])
        where = f"scene {gltf.get('scene', 0)}"
        if not isinstance(roots, list):
            fail(where, "nodes must be a list of node indices")
        for r in roots:
            whole(r, where, "node", 0)
            if r >= len(nodes):
                fail(where, f"node {r} does not exist (the file has {len(nodes)} nodes)")
        if len(set(roots)) != len(roots):
            fail(where, "lists a node twice")
    else:
        listed = {k for i in range(len(nodes)) for k in children(nodes, i)}
        roots = [i for i in range(len(nodes)) if i not in listed]
    node_paths(gltf, roots)
    return list(roots)


def data_uri_payload(uri: str, size: int, where: str = "buffer 0") -> str:
    """The base64 text of a ``data:`` URI holding a buffer of ``size`` bytes, its length
    checked before it is decoded."""
    head, comma, payload = uri.partition(",")
    if not comma or not head.endswith(";base64"):
        fail(where, "its data: URI is not base64 (data:...;base64,...)")
    most = 4 * math.ceil(size / 3)
    if len(payload.rstrip("=")) > most:
        fail(where, f"its data: URI holds more than its byteLength of {size} bytes")
    return payload
