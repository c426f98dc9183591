"""EXT_meshopt_compression: buffer views stored as meshoptimizer's codes, decoded before reading.

gltfpack's output, and the assets file of ``bgr infer --kind city`` (inverse/city/container.py),
keep each buffer view's bytes compressed in one buffer and give the view itself a place in
another, a *fallback* buffer that may hold no data at all.  :func:`decoded` fills those places
by decoding every compressed view (meshoptimizer's ``meshopt`` binding), so the rest of the
reader sees plain buffers.  Nothing in the file is believed first: the extension's buffer, range,
stride, count, mode and filter are checked against the specification and the buffers' real sizes,
the decoded bytes are bounded before any is allocated (MAX_DECODED in all, MOST_RATIO times a
view's codes, a fallback buffer no larger than its views), and a code the decoder refuses is a
located error, not a crash.
"""

from __future__ import annotations

from typing import Any

from .gltf_checks import fail, quoted, view_span, whole

MESHOPT = "EXT_meshopt_compression"
MODES = ("ATTRIBUTES", "TRIANGLES", "INDICES")
FILTERS = ("NONE", "OCTAHEDRAL", "QUATERNION", "EXPONENTIAL")
MAX_DECODED = 1 << 30  # bytes of decoded views one file may ask for
MOST_RATIO = 1024  # decoded bytes a byte of meshopt's codes may stand for (real files: 2 to 20)
SLACK = 1 << 16  # bytes any view may decode to, however short its codes


def compressed(gltf: dict) -> bool:
    """Whether any buffer view of the file is EXT_meshopt_compression's."""
    views = gltf.get("bufferViews")
    return isinstance(views, list) and any(
        isinstance(v, dict) and isinstance(v.get("extensions"), dict) and MESHOPT in v["extensions"]
        for v in views
    )


def decoded(gltf: dict, blobs: list[bytes]) -> list[bytes]:
    """``blobs`` (the bytes of each buffer) with every compressed view decoded into its place in
    its own buffer; a buffer that holds such places and no data gets its byteLength of zeros
    first.  The JSON is left as it is: the views now hold what they say."""
    sizes = [
        whole(b.get("byteLength") if isinstance(b, dict) else None, f"buffer {k}", "byteLength", 1)
        for k, b in enumerate(gltf["buffers"])
    ]
    jobs = []
    total = 0
    for v, view in enumerate(gltf["bufferViews"]):
        if not isinstance(view, dict):
            fail(f"bufferView {v}", "is not a JSON object")
        extensions = view.get("extensions")
        if not isinstance(extensions, dict) or MESHOPT not in extensions:
            continue
        job = _checked(view, v, extensions[MESHOPT], sizes, blobs)
        total += job[2] * job[3]
        if total > MAX_DECODED:
            fail(
                f"bufferView {v}",
                f"its compressed views decode to more than {MAX_DECODED >> 20} MB",
                "bgr reads compressed models of up to that size",
            )
        jobs.append(job)
    out = [bytearray(b) for b in blobs]
    for k in {job[0] for job in jobs}:
        if len(out[k]) < sizes[k]:  # a fallback buffer: room for the decoded views
            needed = max(job[1] + job[2] * job[3] for job in jobs if job[0] == k)
            if sizes[k] > needed + 64:  # 64: alignment padding; not gigabytes of nothing
                fail(
                    f"buffer {k}",
                    f"byteLength {sizes[k]} is more than its compressed views fill ({needed})",
                )
            out[k] += bytes(sizes[k] - len(out[k]))
    for target, start, count, stride, mode, filt, code, v in jobs:
        out[target][start : start + count * stride] = _decode(code, count, stride, mode, filt, v)
    return [bytes(b) for b in out]


def _checked(
    view: dict, v: int, ext: Any, sizes: list[int], blobs: list[bytes]
) -> tuple[int, int, int, int, str, str, bytes, int]:
    """(target buffer, start, count, stride, mode, filter, code, view) of compressed view ``v``,
    every field checked as the specification states it."""
    name = f"bufferView {v} {MESHOPT}"
    if not isinstance(ext, dict):
        fail(name, "is not a JSON object")
    target, start, length = view_span(view, v, sizes)
    source, offset, code_length = view_span(ext, v, [len(b) for b in blobs])
    stride = whole(ext.get("byteStride"), name, "byteStride", 1, 256)
    count = whole(ext.get("count"), name, "count")
    mode, filt = ext.get("mode"), ext.get("filter", "NONE")
    if mode not in MODES:
        fail(name, f"mode {_shown(mode)} is not one of {', '.join(MODES)}")
    if filt not in FILTERS:
        fail(name, f"filter {_shown(filt)} is not one of {', '.join(FILTERS)}")
    if count * stride != length:
        fail(name, f"count {count} x byteStride {stride} is not its view's byteLength {length}")
    if length > MOST_RATIO * code_length + SLACK:  # refused before anything is allocated
        fail(name, f"{code_length} bytes of codes cannot hold the {length} bytes it claims")
    if "byteStride" in view and view["byteStride"] != stride:
        fail(name, f"byteStride {stride} is not its view's {view['byteStride']!r:.40}")
    if mode == "ATTRIBUTES" and stride % 4:
        fail(name, f"byteStride {stride} of ATTRIBUTES is not a multiple of 4")
    if mode != "ATTRIBUTES" and (stride not in (2, 4) or filt != "NONE"):
        fail(name, f"{mode} needs byteStride 2 or 4 and no filter")
    if mode == "TRIANGLES" and count % 3:
        fail(name, f"count {count} of TRIANGLES is not a multiple of 3")
    if (filt == "OCTAHEDRAL" and stride not in (4, 8)) or (filt == "QUATERNION" and stride != 8):
        fail(name, f"filter {filt} cannot have byteStride {stride}")
    code = bytes(blobs[source][offset : offset + code_length])
    return target, start, count, stride, mode, filt, code, v


def _decode(code: bytes, count: int, stride: int, mode: str, filt: str, v: int) -> bytes:
    """The decoded bytes of one view (count x stride), or a located error."""
    if count == 0:
        return b""
    import meshopt

    try:
        rows = meshopt.decode_gltf_buffer(code, count, stride, mode, filt)
    except (ValueError, RuntimeError, MemoryError) as e:
        fail(f"bufferView {v} {MESHOPT}", f"its data does not decode: {str(e)[:160]}")
    data = rows.tobytes()
    if len(data) != count * stride:
        fail(f"bufferView {v} {MESHOPT}", "its data decodes to the wrong length")
    return data


def _shown(value: Any) -> str:
    return quoted(value) if isinstance(value, str) else repr(value)[:40]
