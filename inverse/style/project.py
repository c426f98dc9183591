"""Texture of the remeshed faces (section 4.1, last paragraph): "We project faces in the original
model to the remeshed model with their textures.  Each face is projected along its own normal
direction.  The texture on the remeshed model is then interpolated from the projections. ...
multiple textures might project onto the same face ... we select the projection that covers the
largest area of the face."

For every remeshed :class:`~bgr.inverse.style.model.Face` (a vertical rectangle), the source
triangles that reach it are those that are textured, roughly parallel to it (:data:`MAX_ANGLE`),
near its plane (:data:`PLANE_TOLERANCE`) and overlapping its rectangle.  Each is projected along
its own normal onto the face's plane (the paper's words), into face coordinates ``u`` (distance
from the face's left end seen from outside) and ``y`` (height).  They are grouped by source image
(material); the image whose projections cover the largest area of the rectangle wins (exact
polygon areas, overlaps counted once).  Its triangles are rasterised onto a pixel grid of the face
and each pixel centre samples the image at its barycentric UV: the face's rectified texture.

The paper does not say how to rasterise, how fine, or what a pixel no projection covers shows.
Chosen here, each documented where it is made: the grid keeps the winning source's own texel
density (capped at ``max_size`` a side); "interpolated" is barycentric UVs a pixel and bilinear
texels, from a box-filtered reduction of the image when a pixel spans two or more texels; where
projections of the winning image overlap, the one in front shows; pixels none covers take the
mean colour of the covered ones (the remeshed face is a bounding shape, so a stepped wall leaves
corners uncovered).  The paper's models carry one photograph a wall; PLATEAU's one atlas a
building, which is one "texture" here, so its walls never compete.
"""

from __future__ import annotations

import math
import os
import threading
from dataclasses import dataclass

import numpy as np
import shapely

from bgr.formats.textured_model import TexturedMesh, wrapped
from bgr.grammar.errors import BgrError, Diagnostic
from bgr.inverse.style.model import Face

MAX_ANGLE = 30.0
"""Degrees: a source triangle whose normal is further than this from the face's outward normal
does not project onto it.  Not in the paper (its models are Manhattan-world, so walls are either
parallel or perpendicular); 30 degrees keeps slightly tilted or sloppily modelled walls (a batter,
a misplaced vertex) and drops the perpendicular neighbour walls and roofs, which are 90 degrees
away, and a wall facing the other way (180)."""

MAX_THREADS = 4  # faces drawn at once (threads), at most one a core
THREADED_PIXELS = 16_384
"""Faces of at least this many pixels (128 x 128) are drawn in threads, smaller ones in the
calling thread: measured on PLATEAU (median 200 pixels a face) and the tessellated synthetic
building (median 100,000), threads pay only on the large."""
PLANE_TOLERANCE = 0.02
"""Units of the unit-height frame (2 % of the building's height): a source triangle projects onto
a face only if some part of it lies within this distance of the face's plane, in front or behind.
Not in the paper, which relies on remeshing having moved the misaligned vertices; the remeshed
faces come from floor contours cut through the model, so walls lie on them up to such errors
(the paper's own vertex threshold is 0.0005).  2 % of the height is 0.2 m on a 10 m house: a
wall behind it (a setback, a recess deeper than that) is another wall."""

MIN_COVER = 0.02
"""Fraction of a face's area the winning projection must cover for the face to be textured; less
(a neighbour's sliver reaching over a misaligned edge) leaves the face untextured."""


def face_axes(face: Face) -> tuple[np.ndarray, np.ndarray]:
    """(d, n): the face's left-to-right direction seen from outside and its outward normal, unit
    (x, z) vectors.  Standing outside, looking along -n with y up, the viewer's right is
    (-n) x y = (n_z, 0, -n_x); so d = (n_z, -n_x) and n = (-d_z, d_x).  For the front wall
    (n = -z) d is -x: its left seen from outside is at +x."""
    edge = np.asarray(face.end, dtype=np.float64) - np.asarray(face.start, dtype=np.float64)
    length = float(np.hypot(edge[0], edge[1]))
    if length == 0.0:
        return np.zeros(2), np.zeros(2)
    d = edge / length
    return d, np.array([-d[1], d[0]])


def face_textures(
    mesh: TexturedMesh,
    vertices: np.ndarray,
    select: np.ndarray,
    faces: list[Face],
    texels_per_unit: float | None = None,
    max_size: int = 1024,
    *,
    tolerance: float = PLANE_TOLERANCE,
    max_angle: float = MAX_ANGLE,
) -> None:
    """Fill ``texture`` and ``color`` of each face in ``faces`` from the triangles of ``mesh``
    that ``select`` (F,) keeps, whose vertices in the standard frame are ``vertices`` (V, 3).

    A textured face gets an (h, w, 3) uint8 image, row 0 its top, column 0 its left seen from
    outside; its resolution is ``texels_per_unit`` pixels a unit or, by default, the winning
    source's own texel density, each side at most ``max_size`` and at least 1 pixel.  Its pixels
    no projection covers get the mean colour of those it covers, and ``color`` is the image's
    mean colour.  A face no textured triangle reaches keeps ``texture`` None and gets the colour
    of the nearest parallel untextured triangle's material, or keeps its own (grey) if none.
    Each image is decoded once a call; one that cannot be read is a :class:`BgrError`."""
    tris = _Triangles(mesh, np.asarray(vertices, dtype=np.float64), np.asarray(select, dtype=bool))
    images = _Images(mesh)
    cos_max = math.cos(math.radians(max_angle))
    # Which triangles reach a face, which image wins it and its grid: small shapely and numpy
    # steps that hold the GIL, so one thread.  Then the pixels: a large face's are numpy on
    # whole arrays, which releases the GIL, so they go to threads; a small face's cost the
    # per-call overhead of a thread hand-off and are drawn here (PLATEAU's 500 faces have a
    # median of 200 pixels: threads made its capture slower).
    plans = [
        _plan_face(tris, images, face, texels_per_unit, max_size, tolerance, cos_max)
        for face in faces
    ]
    large = [plan for plan in plans if plan is not None and plan.pixels >= THREADED_PIXELS]
    for plan in plans:
        if plan is not None and plan.pixels < THREADED_PIXELS:
            _paint_face(tris, images, plan)
    # each face's result is the same whichever thread computes it: output byte-identical
    workers = min(MAX_THREADS, os.cpu_count() or 1, len(large))
    if workers <= 1:
        for plan in large:
            _paint_face(tris, images, plan)
        return
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(workers) as pool:
        for _ in pool.map(lambda plan: _paint_face(tris, images, plan), large):
            pass  # re-raises a face's error (an unreadable image)


class _Triangles:
    """The selected triangles with a material, as arrays: corners, unit normals, UVs."""

    def __init__(self, mesh: TexturedMesh, vertices: np.ndarray, select: np.ndarray) -> None:
        keep = np.flatnonzero(select & (mesh.material >= 0))
        self.corners = vertices[mesh.faces[keep]]  # (K, 3, 3)
        self.plan = self.corners[:, :, [0, 2]]  # (K, 3, 2): x, z, what a face's plane sees
        cross = np.cross(
            self.corners[:, 1] - self.corners[:, 0], self.corners[:, 2] - self.corners[:, 0]
        )
        length = np.linalg.norm(cross, axis=1)
        self.normal = cross / np.where(length > 0, length, 1.0)[:, None]  # zero for degenerate
        self.uv = mesh.uv[keep]
        self.material = mesh.material[keep]
        self.textured = mesh.textured()[keep]
        self.colors = [m.color for m in mesh.materials]

    def reaching(
        self, face: Face, tolerance: float, cos_max: float, textured: bool
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(index, projected (k, 3, 2) in (u, y), signed distance of the centroid in front of the
        plane (k,)) of the triangles, textured
        or not, that are parallel to ``face`` within ``cos_max``, reach within ``tolerance`` of
        its plane and whose projections' bounding boxes overlap its rectangle."""
        d, n = face_axes(face)
        n3 = np.array([n[0], 0.0, n[1]])
        facing = self.normal @ n3  # cosine of the angle between the normals
        parallel = np.flatnonzero((self.textured == textured) & (facing >= cos_max))
        start = np.asarray(face.start, dtype=np.float64)
        rel = self.plan[parallel] - start  # (k, 3, 2) from the face's left end
        dist = rel @ n  # (k, 3) signed distance of each corner in front of the plane
        near = (dist.min(axis=1) <= tolerance) & (dist.max(axis=1) >= -tolerance)
        index, dist = parallel[near], dist[near]
        # along the triangle's own normal (section 4.1): p - n_s * dist / (n_s . n_f)
        shift = dist / facing[index][:, None]  # (k, 3)
        moved = self.corners[index] - shift[:, :, None] * self.normal[index][:, None, :]
        proj = np.stack([(moved[:, :, [0, 2]] - start) @ d, moved[:, :, 1]], axis=-1)
        lo, hi = proj.min(axis=1), proj.max(axis=1)
        eps = 1e-9
        overlap = (
            (lo[:, 0] < face.width - eps)
            & (hi[:, 0] > eps)
            & (lo[:, 1] < face.top - eps)
            & (hi[:, 1] > face.bottom + eps)
        )
        front = dist.mean(axis=1)
        return index[overlap], proj[overlap], front[overlap]


class _Images:
    """Each material's image, decoded on first use, and its box-filtered reductions by powers of
    two: a face sampled more coarsely than its source would otherwise alias (every third window
    mullion, stripes of a fine brick pattern), as a texture read without mipmaps does."""

    def __init__(self, mesh: TexturedMesh) -> None:
        self.mesh = mesh
        self.cache: dict[tuple[int, int], np.ndarray] = {}
        self.lock = threading.Lock()  # faces are projected in threads: decode each image once

    def __call__(self, material: int, factor: int = 1) -> np.ndarray:
        """(h, w, 3) float32: the image, reduced ``factor`` times in each direction."""
        with self.lock:
            return self._get(material, factor)

    def _get(self, material: int, factor: int) -> np.ndarray:
        if (material, 1) not in self.cache:
            self.cache[material, 1] = self._decode(material)
        if (material, factor) not in self.cache:
            from PIL import Image

            full = self.cache[material, 1]
            size = (max(1, round(full.shape[1] / factor)), max(1, round(full.shape[0] / factor)))
            small = Image.fromarray(full.astype(np.uint8)).resize(size, Image.Resampling.BOX)
            self.cache[material, factor] = np.asarray(small, dtype=np.float32)
        return self.cache[material, factor]

    def _decode(self, material: int) -> np.ndarray:
        from bgr.grammar.textures import open_image

        mat = self.mesh.materials[material]
        try:
            with open_image(mat.image_bytes()) as im:
                return np.asarray(im.convert("RGB"), dtype=np.float32)
        except BgrError:
            raise
        except Exception as exc:  # Pillow raises many kinds for bytes that are no image
            from PIL import UnidentifiedImageError

            why = (
                "it is not a PNG or JPEG image" if isinstance(exc, UnidentifiedImageError) else exc
            )
            where = str(mat.image) if mat.image is not None else f"material {mat.name!r}"
            raise BgrError(
                Diagnostic(
                    self.mesh.source,
                    0,
                    0,
                    f"texture image {where} cannot be read: {why}",
                    "replace the image with a readable PNG or JPEG, or remove it from the model",
                )
            ) from None


@dataclass
class _Plan:
    """A textured face's projection before its pixels are drawn: the winning image's triangles
    (indices, projections in (u, y), distances in front of the plane), the grid and the image
    reduction to sample."""

    face: Face
    winner: int
    index: np.ndarray
    proj: np.ndarray
    front: np.ndarray
    cols: int
    rows: int
    factor: int

    @property
    def pixels(self) -> int:
        return self.cols * self.rows


def _plan_face(
    tris: _Triangles,
    images: _Images,
    face: Face,
    texels_per_unit: float | None,
    max_size: int,
    tolerance: float,
    cos_max: float,
) -> _Plan | None:
    """The face's projection (section 4.1: the image covering the largest area wins), or None
    for a face no image covers enough, which gets its plain colour here."""
    width, height = face.width, face.height
    index, proj, front = tris.reaching(face, tolerance, cos_max, textured=True)
    winner, cover = _largest_cover(proj, tris.material[index], face)
    if width <= 0 or height <= 0 or cover < MIN_COVER * width * height:
        face.texture = None
        color = _plain_color(tris, face, tolerance, cos_max)
        if color is not None:
            face.color = color
        return None
    mine = tris.material[index] == winner
    index, proj, front = index[mine], proj[mine], front[mine]
    source = _density(proj, tris.uv[index], images(winner).shape)
    cols, rows = _grid(width, height, texels_per_unit or source, max_size)
    step = source * width / cols  # source texels a face pixel spans
    factor = 2 ** int(np.log2(step)) if step >= 2 else 1
    return _Plan(face, winner, index, proj, front, cols, rows, factor)


def _paint_face(tris: _Triangles, images: _Images, plan: _Plan) -> None:
    """Draw a planned face's rectified texture and its mean colour."""
    face, index, cols, rows = plan.face, plan.index, plan.cols, plan.rows
    image = images(plan.winner, plan.factor)
    order = np.argsort(plan.front, kind="stable")
    uv, covered = _raster(plan.proj, tris.uv[index], order, face, cols, rows)
    wrap = images.mesh.materials[plan.winner].wrap
    texture = np.empty((rows, cols, 3), dtype=np.float32)
    if covered.all():  # the usual case: no mask to gather through or scatter back
        texture.reshape(-1, 3)[:] = _bilinear(image, wrapped(uv.reshape(-1, 2), wrap))
    elif covered.any():
        texture[covered] = _bilinear(image, wrapped(uv[covered], wrap))
        texture[~covered] = texture[covered].mean(axis=0)
    else:  # a grid too coarse for any pixel centre to fall in: the triangles' mean colour
        centres = wrapped(tris.uv[index].mean(axis=1), wrap)
        texture[:] = _bilinear(image, centres).mean(axis=0)
    np.rint(texture, out=texture)
    face.texture = np.clip(texture, 0, 255, out=texture).astype(np.uint8)
    face.color = _rgb(face.texture.reshape(-1, 3).mean(axis=0))


def _largest_cover(proj: np.ndarray, material: np.ndarray, face: Face) -> tuple[int, float]:
    """(material, area): the source image whose projections cover the largest area of the face's
    rectangle (section 4.1), overlaps counted once; ties go to the lower material index.  With a
    single image (PLATEAU: one atlas a building) there is nothing to compare and its area only
    meets :data:`MIN_COVER`: the clipped triangles' areas are summed instead of united, which
    counts an overlap twice but costs a third of the time."""
    if len(proj) == 0:
        return -1, 0.0
    rect = shapely.box(0.0, face.bottom, face.width, face.top)
    kinds = np.unique(material)  # ascending: the first of equal areas wins
    if len(kinds) == 1:  # the triangles inside the rectangle need no clipping
        lo, hi = proj.min(axis=1), proj.max(axis=1)
        inside = (lo[:, 0] >= 0) & (hi[:, 0] <= face.width)
        inside &= (lo[:, 1] >= face.bottom) & (hi[:, 1] <= face.top)
        crossing = shapely.polygons(proj[~inside])
        clipped = float(_areas(proj[inside]).sum())
        clipped += float(shapely.area(shapely.intersection(crossing, rect)).sum())
        return int(kinds[0]), min(clipped, face.width * face.height)
    polys = shapely.polygons(proj)
    best, area = -1, 0.0
    for m in kinds:
        covered = shapely.intersection(shapely.union_all(polys[material == m]), rect).area
        if covered > area:
            best, area = int(m), float(covered)
    return best, area


def _density(proj: np.ndarray, uv: np.ndarray, shape: tuple[int, ...]) -> float:
    """Texels a unit of the source: sqrt(UV area in pixels / projected area) over the winning
    triangles, so the face keeps the detail its photograph has."""
    rows, cols = shape[0], shape[1]
    pix = uv * np.array([cols, rows])
    uv_area = _areas(pix).sum()
    area = _areas(proj).sum()
    return float(np.sqrt(uv_area / area)) if area > 0 and uv_area > 0 else 1.0


def _areas(tri: np.ndarray) -> np.ndarray:
    """(k,) areas of 2D triangles (k, 3, 2)."""
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    return np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]) / 2


def _grid(width: float, height: float, density: float, max_size: int) -> tuple[int, int]:
    """(columns, rows): ``density`` pixels a unit, scaled down as one (keeping the aspect) until
    the longer side is at most ``max_size``; each side at least 1."""
    cols, rows = width * density, height * density
    scale = min(1.0, max_size / max(cols, rows, 1e-12))
    cols_i = min(max_size, max(1, round(cols * scale)))
    rows_i = min(max_size, max(1, round(rows * scale)))
    return cols_i, rows_i


def _raster(
    proj: np.ndarray, uv: np.ndarray, order: np.ndarray, face: Face, cols: int, rows: int
) -> tuple[np.ndarray, np.ndarray]:
    """(uv (rows, cols, 2), covered (rows, cols) bool): each pixel centre's barycentric UV in the
    projected triangle that covers it.  Pixel (i, j) has its centre at u = (j + 0.5) / cols of
    the width and y = (i + 0.5) / rows of the height below the top.  Triangles are drawn in
    ``order`` (the rearmost first), so where two overlap the one in front shows, as it would to
    a viewer outside looking along the normal (the paper does not say).
    Each fills only its bounding box of pixels: one numpy pass a triangle, none a pixel."""
    # pixel space: x right (columns), y down (rows), pixel centres at half integers
    px = np.stack(
        [proj[:, :, 0] * (cols / face.width), (face.top - proj[:, :, 1]) * (rows / face.height)],
        axis=-1,
    )
    lo = np.clip(np.ceil(px.min(axis=1) - 0.5), 0, [cols, rows]).astype(np.int64)
    hi = np.clip(np.floor(px.max(axis=1) - 0.5) + 1, 0, [cols, rows]).astype(np.int64)
    out = np.zeros((rows, cols, 2))
    covered = np.zeros((rows, cols), dtype=bool)
    for t in order:
        (j0, i0), (j1, i1) = lo[t], hi[t]
        if j1 <= j0 or i1 <= i0:
            continue
        a, b, c = px[t]
        det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])
        if abs(det) < 1e-12:
            continue
        x = np.arange(j0, j1) + 0.5
        y = np.arange(i0, i1)[:, None] + 0.5
        # the same arithmetic as ((x - a0) * (c1 - a1) - (c0 - a0) * (y - a1)) / det, each
        # factor on a row or a column and only the last two steps on the whole box, in place
        w1 = np.subtract((x - a[0]) * (c[1] - a[1]), (c[0] - a[0]) * (y - a[1]))
        w1 /= det
        w2 = np.subtract((b[0] - a[0]) * (y - a[1]), (x - a[0]) * (b[1] - a[1]))
        w2 /= det
        w0 = np.subtract(1.0, w1)
        w0 -= w2
        eps = -1e-9  # a pixel centre on an edge two triangles share belongs to both
        inside = w0 >= eps
        inside &= w1 >= eps
        inside &= w2 >= eps
        if not inside.any():
            continue
        bary = np.stack([w0[inside], w1[inside], w2[inside]], axis=-1)  # (p, 3)
        block = out[i0:i1, j0:j1]
        block[inside] = bary @ uv[t]
        covered[i0:i1, j0:j1] |= inside
    return out, covered


def _bilinear(image: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """(p, 3) colours of the image at UVs (p, 2) in 0..1, v up (row (1 - v) * h from the top),
    bilinear between the four nearest texel centres.  Neighbours past an edge clamp to it rather
    than wrap: at a repeating texture's seam that is at most half a texel of difference."""
    rows, cols = image.shape[0], image.shape[1]
    x = np.clip(uv[:, 0] * cols - 0.5, 0.0, cols - 1.0)
    y = np.clip((1.0 - uv[:, 1]) * rows - 0.5, 0.0, rows - 1.0)
    x0, y0 = np.floor(x).astype(np.int64), np.floor(y).astype(np.int64)
    x1, y1 = np.minimum(x0 + 1, cols - 1), np.minimum(y0 + 1, rows - 1)
    # the weights in the image's float32: a texel's colour needs no more, and the products of
    # a million-pixel face move half the bytes
    fx = (x - x0).astype(image.dtype)[:, None]
    fy = (y - y0).astype(image.dtype)[:, None]
    flat = image.reshape(rows * cols, image.shape[2])  # one row-major index a texel: np.take
    r0, r1 = y0 * cols, y1 * cols  # gathers whole texels faster than image[y, x] does
    gx = 1 - fx
    top = np.take(flat, r0 + x0, axis=0) * gx + np.take(flat, r0 + x1, axis=0) * fx
    bottom = np.take(flat, r1 + x0, axis=0) * gx + np.take(flat, r1 + x1, axis=0) * fx
    return top * (1 - fy) + bottom * fy


def _plain_color(
    tris: _Triangles, face: Face, tolerance: float, cos_max: float
) -> tuple[int, int, int] | None:
    """The colour of the untextured parallel triangle nearest the face's plane among those that
    reach its rectangle (its material's sRGB colour, 0..255), or None when none does."""
    index, _, front = tris.reaching(face, tolerance, cos_max, textured=False)
    if len(index) == 0:
        return None
    nearest = index[int(np.argmin(np.abs(front)))]
    return _rgb(np.array(tris.colors[int(tris.material[nearest])][:3]) * 255.0)


ROOF_UP = 0.9
"""A triangle is a roof when its unit normal's up component is above this (within about 26
degrees of level): flat roofs and the gentle pitches of most Manhattan-world blocks."""


def roof_color(
    mesh: TexturedMesh, vertices: np.ndarray, select: np.ndarray
) -> tuple[int, int, int] | None:
    """The area-weighted mean sRGB colour (0..255) of the untextured roof triangles that
    ``select`` keeps (``vertices`` in the standard frame, y up), or None when there are none.

    The paper's style sheet holds the walls only; the roof is the shape layer's, and a style
    sheet that paints it a fixed grey makes every derived building's roof another colour than
    its source's.  Textured roofs are not sampled (None): their photographs are for the walls'
    crops to carry, and the emitter keeps its grey."""
    tris = _Triangles(mesh, np.asarray(vertices, dtype=np.float64), np.asarray(select, dtype=bool))
    corners = tris.corners
    area = 0.5 * np.linalg.norm(
        np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1
    )
    roof = (tris.normal[:, 1] > ROOF_UP) & ~tris.textured & (area > 0)
    if not roof.any():
        return None
    colors = np.array([c[:3] for c in tris.colors], dtype=np.float64).reshape(-1, 3)
    mean = (colors[tris.material[roof]] * area[roof, None]).sum(axis=0) / area[roof].sum()
    return _rgb(mean * 255.0)


def _rgb(color: np.ndarray) -> tuple[int, int, int]:
    r, g, b = (int(v) for v in np.clip(np.rint(color), 0, 255))
    return (r, g, b)
