"""inverse/style/project.py: the source model's textures projected onto remeshed faces (section
4.1 of the style-sheets paper).  Expectations are worked out by hand from boxes whose walls are
mapped to images drawn here; the PLATEAU test checks each face pixel against the source image at
the UV the source triangle gives that point."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest
from conftest import SHARED
from PIL import Image

from bgr.formats.textured_model import Material, TexturedMesh
from bgr.grammar.errors import BgrError
from bgr.inverse.style.model import OUTWARD, Face
from bgr.inverse.style.project import face_axes, face_textures

RED, GREEN, BLUE = (255, 0, 0), (0, 255, 0), (0, 0, 255)

# The box 4 wide (x 0..4), 3 high (y 0..3), 2 deep (z 0..2).  Each wall's (start, end): its
# left and right ends seen from outside, worked out by standing in front of it: facing the front
# wall (outward -z) from -z, looking +z with y up, +x is on the viewer's left; facing the right
# wall (+x) from +x, +z is on the left; the back wall (+z) from +z, -x on the left; the left wall
# (-x) from -x, -z on the left.
WALL_ENDS = {
    "front": ((4.0, 0.0), (0.0, 0.0)),
    "right": ((4.0, 2.0), (4.0, 0.0)),
    "back": ((0.0, 2.0), (4.0, 2.0)),
    "left": ((0.0, 0.0), (0.0, 2.0)),
}
WALL_NORMALS = {"front": (0, 0, -1), "right": (1, 0, 0), "back": (0, 0, 1), "left": (-1, 0, 0)}


def three_part(width: int, height: int, left=RED, top_right=BLUE, bottom_right=GREEN) -> np.ndarray:
    """A red left half, a blue top-right quarter and a green bottom-right quarter: any mirror or
    flip of it is another image."""
    img = np.zeros((height, width, 3), dtype=np.uint8)
    img[:, : width // 2] = left
    img[: height // 2, width // 2 :] = top_right
    img[height // 2 :, width // 2 :] = bottom_right
    return img


def save(img: np.ndarray, path: Path) -> Path:
    Image.fromarray(img).save(path)
    return path


def quad_mesh(quads: list[tuple], materials: list[Material]) -> TexturedMesh:
    """Triangles from quads (start (x, z), end (x, z), bottom, top, material, uv rectangle
    (u0, v0, u1, v1) or None): corners bottom-left, bottom-right, top-right, top-left as seen
    from outside, so each triangle's winding makes its normal point outward."""
    verts, faces, uvs, mats = [], [], [], []
    for start, end, bottom, top, material, box in quads:
        base = len(verts)
        (sx, sz), (ex, ez) = start, end
        verts += [(sx, bottom, sz), (ex, bottom, ez), (ex, top, ez), (sx, top, sz)]
        u0, v0, u1, v1 = box or (0.0, 0.0, 1.0, 1.0)
        corner_uv = [(u0, v0), (u1, v0), (u1, v1), (u0, v1)]
        for tri in ((0, 1, 2), (0, 2, 3)):
            faces.append([base + k for k in tri])
            uvs.append([corner_uv[k] for k in tri])
            mats.append(material)
    n = len(faces)
    return TexturedMesh(
        vertices=np.array(verts, dtype=np.float64),
        faces=np.array(faces, dtype=np.int64),
        uv=np.array(uvs, dtype=np.float64),
        material=np.array(mats, dtype=np.int64),
        materials=materials,
        semantic=np.zeros(n, dtype=np.int64),
        semantic_names=["WallSurface"],
        object=np.zeros(n, dtype=np.int64),
        object_ids=["box"],
        surface=np.arange(n, dtype=np.int64) // 2,
        surface_ids=[str(k) for k in range(len(quads))],
        up="y",
    )


def run(mesh: TexturedMesh, faces: list[Face], **kw) -> list[Face]:
    face_textures(mesh, mesh.vertices, np.ones(len(mesh.faces), dtype=bool), faces, **kw)
    return faces


def face(start, end, bottom=0.0, top=3.0, wall=0) -> Face:
    return Face(wall, 0, np.array(start, float), np.array(end, float), bottom, top)


def near_match(got: np.ndarray, want: np.ndarray) -> np.ndarray:
    """(h, w) bool: pixels whose colour equals the expected one at the same place or one pixel
    away (a colour boundary may move by a pixel)."""
    ok = np.zeros(got.shape[:2], dtype=bool)
    pad = np.pad(want.astype(int), ((1, 1), (1, 1), (0, 0)), mode="edge")
    h, w = got.shape[:2]
    for di in (0, 1, 2):
        for dj in (0, 1, 2):
            ok |= np.abs(got.astype(int) - pad[di : di + h, dj : dj + w]).max(axis=2) <= 2
    return ok


def test_face_axes_match_the_walls_outward_normals() -> None:
    for w, name in enumerate(("front", "right", "back", "left")):
        d, n = face_axes(face(*WALL_ENDS[name]))
        assert n == pytest.approx(OUTWARD[w])
        assert n == pytest.approx(np.array(WALL_NORMALS[name])[[0, 2]])
        # d is the viewer's right: (outward x up) . d > 0 is the right-handed check
        assert np.cross(np.array([n[0], 0, n[1]]), [0, 1, 0]) @ [d[0], 0, d[1]] < 0


def test_each_wall_of_a_box_gets_its_image_the_right_way_round(tmp_path: Path) -> None:
    widths = {"front": 4, "right": 2, "back": 4, "left": 2}
    palettes = {
        "front": (RED, BLUE, GREEN),
        "right": (BLUE, GREEN, RED),
        "back": (GREEN, RED, BLUE),
        "left": ((255, 255, 0), (0, 255, 255), (255, 0, 255)),
    }
    images, materials, quads = {}, [], []
    for k, name in enumerate(WALL_ENDS):
        images[name] = three_part(10 * widths[name], 30, *palettes[name])  # 10 texels a unit
        materials.append(Material(name, image=save(images[name], tmp_path / f"{name}.png")))
        quads.append((*WALL_ENDS[name], 0.0, 3.0, k, None))
    mesh = quad_mesh(quads, materials)
    v = mesh.vertices[mesh.faces]
    normals = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    for k, name in enumerate(WALL_ENDS):  # the source walls face outward
        assert np.sign(normals[2 * k]) == pytest.approx(WALL_NORMALS[name])
    faces = run(mesh, [face(*WALL_ENDS[name], wall=w) for w, name in enumerate(WALL_ENDS)])
    for f, name in zip(faces, WALL_ENDS, strict=True):
        assert f.texture is not None
        assert f.texture.shape == (30, 10 * widths[name], 3)  # the source's texel density
        assert near_match(f.texture, images[name]).all(), name
        assert tuple(f.texture[0, 0]) == palettes[name][0]  # top-left seen from outside
        assert tuple(f.texture[0, -1]) == palettes[name][1]
        assert tuple(f.texture[-1, -1]) == palettes[name][2]
        # half the face one colour, a quarter each of the others
        want = np.array(palettes[name]).T @ [0.5, 0.25, 0.25]
        assert f.color == pytest.approx(tuple(want), abs=1)


def test_the_projection_covering_the_largest_area_wins(tmp_path: Path) -> None:
    # image A: red left half, white right half; B: solid blue, twice as fine
    a = np.zeros((30, 28, 3), dtype=np.uint8)
    a[:, :14] = RED
    a[:, 14:] = 255
    b = np.full((60, 24, 3), BLUE, dtype=np.uint8)
    mats = [
        Material("A", image=save(a, tmp_path / "a.png")),
        Material("B", image=save(b, tmp_path / "b.png")),
    ]
    # front wall: its left 70 % (x 4 .. 1.2) shows A, its right 30 % (x 1.2 .. 0) shows B
    for left, right in ((0, 1), (1, 0)):
        mesh = quad_mesh(
            [
                ((4.0, 0.0), (1.2, 0.0), 0.0, 3.0, left, None),
                ((1.2, 0.0), (0.0, 0.0), 0.0, 3.0, right, None),
            ],
            mats,
        )
        (f,) = run(mesh, [face((4.0, 0.0), (0.0, 0.0))])
        assert f.texture is not None
        if left == 0:  # A covers 70 %: 10 texels a unit, 40 x 30
            assert f.texture.shape == (30, 40, 3)
            assert (f.texture[:, :13] == RED).all()
            assert (f.texture[:, 15:27] == 255).all()
            # the 30 % A does not cover: the mean of what it covers, half red half white
            assert np.abs(f.texture[:, 29:].astype(int) - [255, 128, 128]).max() <= 1
            assert f.color == pytest.approx((255, 128, 128), abs=1)
        else:  # B covers 70 %: its 24 x 60 texels over 2.8 x 3 units, sqrt(1440 / 8.4) =
            # 13.09 texels a unit, 52.4 x 39.3 pixels; blue everywhere
            assert f.texture.shape == (39, 52, 3)
            assert (f.texture == BLUE).all()


def test_a_face_cut_from_a_wall_gets_the_matching_part_of_its_image(tmp_path: Path) -> None:
    img = three_part(40, 30)
    mesh = quad_mesh(
        [((4.0, 0.0), (0.0, 0.0), 0.0, 3.0, 0, None)],
        [Material("m", image=save(img, tmp_path / "f.png"))],
    )
    left, right, upper = run(
        mesh,
        [
            face((4.0, 0.0), (2.0, 0.0)),
            face((2.0, 0.0), (0.0, 0.0)),
            face((4.0, 0.0), (0.0, 0.0), 1.5, 3.0),
        ],
    )
    assert left.texture is not None and right.texture is not None and upper.texture is not None
    assert left.texture.shape == (30, 20, 3) and (left.texture == RED).all()
    assert right.texture.shape == (30, 20, 3)
    assert (right.texture[:15] == BLUE).all() and (right.texture[15:] == GREEN).all()
    assert upper.texture.shape == (15, 40, 3)
    assert (upper.texture[:, :20] == RED).all() and (upper.texture[:, 20:] == BLUE).all()


@pytest.mark.parametrize(
    ("z", "flipped", "reaches"),
    [
        (-0.003, False, True),
        (0.003, False, True),
        (0.0, True, False),
        (0.2, False, False),
        (-0.2, False, False),
    ],
)
def test_only_near_walls_facing_the_same_way_project(
    tmp_path: Path, z: float, flipped: bool, reaches: bool
) -> None:
    img = three_part(40, 30)
    start, end = (4.0, z), (0.0, z)
    if flipped:
        start, end = end, start
    mesh = quad_mesh(
        [(start, end, 0.0, 3.0, 0, None)], [Material("m", image=save(img, tmp_path / "f.png"))]
    )
    (f,) = run(mesh, [face((4.0, 0.0), (0.0, 0.0))])
    if reaches:
        assert f.texture is not None and near_match(f.texture, img).all()
    else:
        assert f.texture is None and f.color == (200, 200, 200)


def test_an_untextured_face_takes_its_walls_material_colour(tmp_path: Path) -> None:
    mats = [
        Material("paint", color=(0.5, 0.25, 1.0, 1.0)),
        Material("far", color=(0.0, 0.0, 0.0, 1.0)),
    ]
    mesh = quad_mesh(
        [
            ((4.0, 0.0), (0.0, 0.0), 0.0, 3.0, 0, None),
            ((4.0, 0.01), (0.0, 0.01), 0.0, 3.0, 1, None),
        ],
        mats,
    )
    (f,) = run(mesh, [face((4.0, 0.0), (0.0, 0.0))])
    assert f.texture is None
    assert f.color == (128, 64, 255)  # the nearer one, 0..1 sRGB to 0..255


def test_resolution_options_and_one_decode_per_image(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import bgr.grammar.textures as textures

    img = three_part(40, 30)
    mesh = quad_mesh(
        [((4.0, 0.0), (0.0, 0.0), 0.0, 3.0, 0, None)],
        [Material("m", image=save(img, tmp_path / "f.png"))],
    )
    opened = []
    real = textures.open_image
    monkeypatch.setattr(textures, "open_image", lambda data: opened.append(1) or real(data))
    faces = [face((4.0, 0.0), (0.0, 0.0)) for _ in range(3)]
    run(mesh, faces[:1], max_size=20)
    run(mesh, faces[1:2], texels_per_unit=5)
    run(mesh, faces[2:], texels_per_unit=1000, max_size=64)
    assert [f.texture.shape for f in faces] == [(15, 20, 3), (15, 20, 3), (48, 64, 3)]
    assert len(opened) == 3  # once a call
    opened.clear()
    run(mesh, [face((4.0, 0.0), (2.0, 0.0)), face((2.0, 0.0), (0.0, 0.0))])
    assert len(opened) == 1


def test_an_image_that_cannot_be_read_is_a_located_error(tmp_path: Path) -> None:
    bad = tmp_path / "bad.png"
    bad.write_bytes(b"not an image")
    mesh = quad_mesh([((4.0, 0.0), (0.0, 0.0), 0.0, 3.0, 0, None)], [Material("m", image=bad)])
    with pytest.raises(BgrError, match="bad.png"):
        run(mesh, [face((4.0, 0.0), (0.0, 0.0))])


PLATEAU = SHARED / "data" / "textured" / "plateau_tokyo" / "53392633_bldg_6697_2_op.gml"


def plateau_walls(mesh: TexturedMesh) -> tuple[np.ndarray, list[tuple[int, Face, np.ndarray]]]:
    """The PLATEAU vertices in a local frame (x east, y up, z south, metres: latitude and
    longitude by the equirectangular approximation, exact enough over a block of a few hundred
    metres) and, per WallSurface polygon, (building, Face, its triangles): the Face is the
    polygon's bounding rectangle in its own plane, its outward normal the polygon's area-weighted
    normal made horizontal, its ends ordered left to right seen from outside (d = (n_z, -n_x))."""
    lat, lon, h = mesh.vertices.T
    lat0, lon0 = lat.mean(), lon.mean()
    metres = 6_371_000.0 * np.pi / 180.0
    x = (lon - lon0) * metres * np.cos(np.radians(lat0))
    verts = np.stack([x, h, -(lat - lat0) * metres], axis=1)  # (E, U, -N): a rotation
    walls = mesh.mask(semantic="WallSurface")
    tri = verts[mesh.faces]
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    out = []
    for s in np.unique(mesh.surface[walls]):
        mine = np.flatnonzero(walls & (mesh.surface == s))
        normal = cross[mine].sum(axis=0)
        flat = np.array([normal[0], normal[2]])
        if np.hypot(*flat) < 0.9 * np.linalg.norm(normal):  # not vertical
            continue
        n = flat / np.hypot(*flat)
        d = np.array([n[1], -n[0]])
        pts = tri[mine].reshape(-1, 3)
        centre = pts[:, [0, 2]].mean(axis=0)
        u = (pts[:, [0, 2]] - centre) @ d
        if u.max() - u.min() < 0.5 or np.ptp(pts[:, 1]) < 0.5:  # a sliver: nothing to see
            continue
        f = Face(0, 0, centre + u.min() * d, centre + u.max() * d, pts[:, 1].min(), pts[:, 1].max())
        out.append((int(mesh.object[mine[0]]), f, mine))
    return verts, out


def texel(texture: np.ndarray, u: np.ndarray, t: np.ndarray) -> np.ndarray:
    """(p, 3) the texture's pixels at fractions u across (from the left) and t down."""
    rows, cols = texture.shape[:2]
    j = np.clip((u * cols).astype(int), 0, cols - 1)
    i = np.clip((t * rows).astype(int), 0, rows - 1)
    return texture[i, j].astype(np.float32)


def test_plateau_walls_get_their_photographs(tmp_path: Path) -> None:
    """Each wall polygon's bounding rectangle, textured by projection, shows at each of the
    polygon's triangle centroids the pixel the source image has at that centroid's UV; mirrored
    left to right or upside down it would not.  All 10 buildings' walls, one call each."""
    if not PLATEAU.exists():
        pytest.skip("PLATEAU data absent (../shared/data/textured/plateau_tokyo)")
    from bgr.formats.citygml_read import read_citygml
    from bgr.inverse.style.project import _bilinear

    mesh = read_citygml(PLATEAU)
    verts, walls = plateau_walls(mesh)
    assert len(walls) > 100
    began = time.perf_counter()
    for b in range(len(mesh.object_ids)):
        faces = [f for owner, f, _ in walls if owner == b]
        face_textures(mesh, verts, mesh.mask(object_id=mesh.object_ids[b]), faces)
    spent = time.perf_counter() - began
    print(f"{len(walls)} PLATEAU wall faces projected in {spent:.2f} s")
    textured = [f.texture is not None for _, f, _ in walls]
    print(f"{sum(textured)} of {len(walls)} textured")
    assert np.mean(textured) > 0.9

    images: dict[int, np.ndarray] = {}
    right, mirrored, flipped = [], [], []
    for _, f, mine in walls:
        if f.texture is None:
            continue
        m = int(mesh.material[mine[0]])
        if m not in images:
            images[m] = np.asarray(Image.open(mesh.materials[m].image).convert("RGB"), np.float32)
        want = _bilinear(images[m], mesh.uv[mine].mean(axis=1))  # source colour at centroids
        c = verts[mesh.faces[mine]].mean(axis=1)
        d = (f.end - f.start) / f.width
        u = (c[:, [0, 2]] - f.start) @ d / f.width  # 0..1 across, left seen from outside
        t = (f.top - c[:, 1]) / f.height  # 0..1 down from the top
        right.append(np.abs(texel(f.texture, u, t) - want).mean(axis=1))
        mirrored.append(np.abs(texel(f.texture, 1 - u, t) - want).mean(axis=1))
        flipped.append(np.abs(texel(f.texture, u, 1 - t) - want).mean(axis=1))
    right_err = float(np.median(np.concatenate(right)))
    mirror_err = float(np.median(np.concatenate(mirrored)))
    flip_err = float(np.median(np.concatenate(flipped)))
    print(
        f"|face - source| at centroids: {right_err:.1f}, "
        f"mirrored {mirror_err:.1f}, flipped {flip_err:.1f}"
    )
    assert right_err < 6  # of 255 (measured 1.8): half a pixel's shift on a photograph
    assert mirror_err > 2 * right_err and flip_err > 2 * right_err  # measured 10.8 and 13.4


def test_a_face_whose_one_pixel_no_projection_covers_takes_the_sources_colour(
    tmp_path: Path,
) -> None:
    img = np.full((30, 40, 3), (10, 200, 30), dtype=np.uint8)
    mesh = quad_mesh(
        [((4.0, 0.0), (2.4, 0.0), 0.0, 3.0, 0, None)],  # the left 40 % of the front wall
        [Material("m", image=save(img, tmp_path / "f.png"))],
    )
    (f,) = run(mesh, [face((4.0, 0.0), (0.0, 0.0))], texels_per_unit=0.1)  # 1 x 1: its centre
    assert f.texture is not None and f.texture.shape == (1, 1, 3)  # is at 50 %, uncovered
    assert tuple(f.texture[0, 0]) == (10, 200, 30) and f.color == (10, 200, 30)


def test_where_two_projections_of_one_image_overlap_the_one_in_front_shows(tmp_path: Path) -> None:
    img = np.zeros((30, 40, 3), dtype=np.uint8)
    img[:, :20], img[:, 20:] = RED, BLUE
    png = save(img, tmp_path / "f.png")
    on_plane = ((4.0, 0.0), (0.0, 0.0), 0.0, 3.0, 0, (0.0, 0.0, 0.5, 1.0))  # the red half
    in_front = ((4.0, -0.01), (0.0, -0.01), 0.0, 3.0, 0, (0.5, 0.0, 1.0, 1.0))  # the blue half
    for quads in ([on_plane, in_front], [in_front, on_plane]):  # whatever the file's order
        (f,) = run(quad_mesh(quads, [Material("m", image=png)]), [face((4.0, 0.0), (0.0, 0.0))])
        assert f.texture is not None and (f.texture[:, 1:] == BLUE).all()
        # the first column samples within half a texel of the red half: bilinear blends it in
        assert (f.texture[:, 0, 2] > 200).all()


@pytest.mark.parametrize(("share", "textured"), [(0.01, False), (0.03, True)])
def test_a_sliver_below_min_cover_leaves_a_face_untextured(
    tmp_path: Path, share: float, textured: bool
) -> None:
    img = np.full((30, 40, 3), RED, dtype=np.uint8)
    edge = 4.0 - 4.0 * share  # the source covers the face's left `share` seen from outside
    mesh = quad_mesh(
        [((4.0, 0.0), (edge, 0.0), 0.0, 3.0, 0, None)],
        [Material("m", image=save(img, tmp_path / "f.png"))],
    )
    (f,) = run(mesh, [face((4.0, 0.0), (0.0, 0.0))], texels_per_unit=10)
    assert (f.texture is not None) == textured


def test_a_face_coarser_than_its_source_averages_rather_than_aliases(tmp_path: Path) -> None:
    img = np.zeros((30, 40, 3), dtype=np.uint8)
    img[:, 1::2] = 255  # one-texel black and white stripes: 10 texels a unit
    mesh = quad_mesh(
        [((4.0, 0.0), (0.0, 0.0), 0.0, 3.0, 0, None)],
        [Material("m", image=save(img, tmp_path / "f.png"))],
    )
    # 3 pixels a unit: a pixel spans 3.3 texels; point or bilinear samples would show stripes
    # of varying grey, the area they cover averages 127.5
    (f,) = run(mesh, [face((4.0, 0.0), (0.0, 0.0))], texels_per_unit=3)
    assert f.texture is not None and f.texture.shape == (9, 12, 3)
    assert np.abs(f.texture.astype(int) - 127.5).max() <= 1


def test_only_the_selected_triangles_project(tmp_path: Path) -> None:
    red = np.full((30, 40, 3), RED, dtype=np.uint8)
    blue = np.full((60, 80, 3), BLUE, dtype=np.uint8)
    mats = [
        Material("ours", image=save(red, tmp_path / "r.png")),
        Material("theirs", image=save(blue, tmp_path / "b.png")),
    ]
    # the neighbour's wall is coplanar, finer and covers the whole face; ours only 60 %
    mesh = quad_mesh(
        [
            ((4.0, 0.0), (1.6, 0.0), 0.0, 3.0, 0, None),
            ((4.0, 0.0), (0.0, 0.0), 0.0, 3.0, 1, None),
        ],
        mats,
    )
    (f,) = [face((4.0, 0.0), (0.0, 0.0))]
    face_textures(mesh, mesh.vertices, np.array([True, True, False, False]), [f])
    assert f.texture is not None and (f.texture == RED).all()
