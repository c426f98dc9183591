"""The OpenGL rasteriser: the same two buffers as :mod:`.raster_numpy`, from a headless context.

moderngl makes a standalone context through EGL (``backend="egl"``), which needs no display: on
a machine without a GPU, Mesa's llvmpipe rasterises on the CPU, still far faster than numpy.
One draw call writes, per pixel, ``gl_PrimitiveID`` (the triangle's index, since the triangles
are drawn in order without an index buffer) into an integer target and the linear depth into a
float target.  The depth test runs on ``gl_FragDepth`` set to the depth scaled between the
near and far planes, so its 24 bits are spread evenly over the scene instead of crowding at
the near plane as the usual projective depth does.

Everything is imported and created lazily: importing this module needs no moderngl.  When a
context cannot be made, :class:`GLUnavailable` says why, and the caller falls back to numpy.
The context (about half a second to make) is kept for the life of the process.
"""

from __future__ import annotations

import os
import threading
from typing import Any

import numpy as np

from .camera import Camera
from .frame import Frame, GLUnavailable, empty_frame, prepare

VERTEX = """
#version 330
uniform vec4 proj;      // 2f/W, 2f/H, Cx, Cy
uniform vec2 range;     // near, far
in vec3 position;       // camera space: x right, y up, looking down -z
out float depth;
void main() {
    float d = -position.z;
    float n = range.x, f = range.y;
    depth = d;
    gl_Position = vec4(proj.x * position.x + proj.z * d, proj.y * position.y + proj.w * d,
                       (f + n) / (f - n) * d - 2.0 * f * n / (f - n), d);
}
"""

FRAGMENT = """
#version 330
uniform vec2 range;
in float depth;
layout(location = 0) out int triangle;
layout(location = 1) out float linear_depth;
void main() {
    triangle = gl_PrimitiveID + 1;
    linear_depth = depth;
    gl_FragDepth = clamp((depth - range.x) / (range.y - range.x), 0.0, 1.0);
}
"""

_lock = threading.Lock()
_state: dict[str, Any] = {}


def _context() -> Any:
    """The process's moderngl context and program, made on first use (GLUnavailable if it can't)."""
    with _lock:
        if "error" in _state:
            raise GLUnavailable(_state["error"])
        if "ctx" not in _state:
            try:
                import moderngl
            except ImportError as exc:
                _state["error"] = f"moderngl is not installed ({exc})"
                raise GLUnavailable(_state["error"]) from None
            try:
                ctx = moderngl.create_standalone_context(backend="egl", require=330)
                prog = ctx.program(vertex_shader=VERTEX, fragment_shader=FRAGMENT)
            except Exception as exc:  # noqa: BLE001 - no libEGL, no device, no GL 3.3: all mean "no GL"
                _state["error"] = (
                    f"no OpenGL context through EGL ({type(exc).__name__}: {exc})".strip()
                )
                raise GLUnavailable(_state["error"]) from None
            _state.update(ctx=ctx, prog=prog, targets={})
        return _state


def available() -> bool:
    """True when a GL context can be made (making it on first call)."""
    try:
        _context()
    except GLUnavailable:
        return False
    return True


def _targets(state: dict, size: tuple[int, int]) -> Any:
    """A framebuffer of the given size (id, depth, z-buffer), kept for reuse."""
    fbo = state["targets"].get(size)
    if fbo is None:
        ctx = state["ctx"]
        if max(size) > ctx.info.get("GL_MAX_RENDERBUFFER_SIZE", 16384):
            raise GLUnavailable(f"{size[0]}x{size[1]} is larger than this GL renderer allows")
        for old in state[
            "targets"
        ].values():  # keep one size only: a run of sizes would fill memory
            for attachment in (*old.color_attachments, old.depth_attachment):
                attachment.release()
            old.release()
        ids = ctx.texture(size, 1, dtype="i4")
        depth = ctx.texture(size, 1, dtype="f4")
        fbo = ctx.framebuffer(
            color_attachments=[ids, depth], depth_attachment=ctx.depth_renderbuffer(size)
        )
        state["targets"] = {size: fbo}
    return fbo


def rasterise(triangles: np.ndarray, camera: Camera) -> Frame:
    """Depth and triangle-index buffers of world ``triangles`` (T, 3, 3) seen by ``camera``."""
    state = _context()
    frame = empty_frame(camera, "gl")
    if len(triangles) == 0:
        return frame
    W, H = camera.size
    cam, near, far = prepare(np.asarray(triangles, dtype=np.float64), camera)
    with _lock:
        ctx, prog = state["ctx"], state["prog"]
        fbo = _targets(state, (W, H))
        f = camera.focal
        prog["proj"].value = (2.0 * f / W, 2.0 * f / H, *camera.principal_point)
        prog["range"].value = (near, far)
        vbo = ctx.buffer(np.ascontiguousarray(cam, dtype="f4").tobytes())
        try:
            vao = ctx.vertex_array(prog, [(vbo, "3f", "position")])
            try:
                fbo.use()
                ctx.viewport = (0, 0, W, H)
                ctx.disable(ctx.CULL_FACE | ctx.BLEND)
                ctx.enable(ctx.DEPTH_TEST)
                ctx.depth_func = "<"
                fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
                vao.render(mode=ctx.TRIANGLES, vertices=3 * len(cam))
                ids = np.frombuffer(
                    fbo.read(components=1, attachment=0, dtype="i4"), dtype=np.int32
                )
                depth = np.frombuffer(
                    fbo.read(components=1, attachment=1, dtype="f4"), dtype=np.float32
                )
            finally:
                vao.release()
        finally:
            vbo.release()
    ids = ids.reshape(H, W)[::-1] - 1  # GL's row 0 is the bottom of the image
    depth = depth.reshape(H, W)[::-1]
    frame.triangle[:] = ids
    covered = ids >= 0
    frame.depth[covered] = depth[covered]
    return frame


def reset() -> None:
    """Forget the context (and a remembered failure): for tests, and after a fork."""
    with _lock:
        ctx = _state.get("ctx")
        _state.clear()
        if ctx is not None:
            ctx.release()


def _after_fork() -> None:
    """A GL context does not survive fork(), and with Mesa a forked child that makes a new one
    after its parent made one hangs.  So such a child has no GL (auto falls back to numpy); a
    child forked before any context was made may make its own.  The lock is new, in case another
    thread held it at the fork."""
    global _lock
    _lock = threading.Lock()
    had_context = "ctx" in _state
    _state.clear()
    if had_context:
        _state["error"] = (
            "this process was forked after its parent made a GL context, which cannot "
            "be shared; use the 'spawn' start method for worker processes"
        )


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_after_fork)
