"""bgr render: camera maths, both rasterisers, the four image modes, the command line."""

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest
import shapely
import trimesh
from conftest import ROOT
from PIL import Image

import bgr
from bgr.cli import main
from bgr.render import (
    Camera,
    images,
    load_scene,
    make_camera,
    raster_gl,
    raster_numpy,
    rasterise,
    render,
    render_labels,
    save_png,
)
from bgr.render.scene import Scene, from_trimesh

HOUSE = ROOT / "examples" / "house.bgr"


# --- helpers ------------------------------------------------------------------------------------


def gl_or_skip():
    """Skip a GL test only when a context truly cannot be made, saying why."""
    try:
        raster_gl._context()
    except raster_gl.GLUnavailable as exc:
        pytest.skip(f"no GL context on this machine: {exc}")


BACKENDS = [pytest.param("numpy", id="numpy"), pytest.param("gl", id="gl")]


def frame_of(scene, camera, backend):
    if backend == "gl":
        gl_or_skip()
        return raster_gl.rasterise(scene.triangles, camera)
    return raster_numpy.rasterise(scene.triangles, camera)


def reference_projection(points, yaw, pitch, roll, position, fov, principal, size):
    """The paper's camera written out afresh: x_cam = Rx(pitch) Ry(yaw) Rz(roll) F (X - C), with F
    the half turn about y that makes bgr's front (facing -z) face the camera; f = W / 2 tan(fov/2);
    the principal point in normalised image coordinates."""

    def r(axis, deg):
        c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
        return {
            "x": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
            "y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
            "z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]),
        }[axis]

    R = r("x", pitch) @ r("y", yaw) @ r("z", roll) @ np.diag([-1.0, 1.0, -1.0])
    cam = (np.asarray(points, float) - position) @ R.T
    w, h = size
    f = w / (2 * math.tan(math.radians(fov) / 2))
    u = w / 2 * (1 + principal[0]) + f * cam[:, 0] / -cam[:, 2]
    v = h / 2 * (1 - principal[1]) - f * cam[:, 1] / -cam[:, 2]
    return np.column_stack([u, v])


def box_scene(lo=(0, 0, 0), hi=(8, 5, 6)):
    lo, hi = np.array(lo, float), np.array(hi, float)
    box = trimesh.creation.box(extents=hi - lo)
    box.apply_translation((lo + hi) / 2)
    box.visual.face_colors = [200, 180, 150, 255]
    return from_trimesh(box)


def mask_of_polygon(polygon, size):
    w, h = size
    xs, ys = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)
    return shapely.contains_xy(polygon, xs, ys)


@pytest.fixture(scope="module")
def house():
    return load_scene(HOUSE, seed=3)


# --- camera -------------------------------------------------------------------------------------


def test_projection_matches_the_paper_model():
    pts = np.random.default_rng(1).uniform(-5, 5, (50, 3))
    args = {
        "yaw": 30,
        "pitch": 15,
        "roll": -5,
        "position": np.array([20.0, 12.0, -40.0]),
        "fov": 50,
        "principal": (0.1, -0.2),
        "size": (640, 480),
    }
    cam = Camera.from_angles(
        args["yaw"],
        args["pitch"],
        args["roll"],
        args["position"],
        args["fov"],
        args["principal"],
        args["size"],
    )
    pixels, depth = cam.project(pts)
    assert np.allclose(pixels, reference_projection(pts, **args))
    assert (depth > 0).all()


def test_from_paper_uses_the_dolly_zoom():
    cam = Camera.from_paper(10, 40, 0, 60, 0.0, 0.0, 2.0, -3.0, size=(400, 300))
    t = cam.rotation @ cam.position  # the camera position in the rotated frame
    assert np.allclose(t, [2.0, -3.0, 25 / (2 * math.tan(math.radians(30)))])
    assert math.isclose(cam.focal, 400 / (2 * math.tan(math.radians(30))))


def test_front_camera_faces_the_front_facade(house):
    cam = Camera.preset("front", *house.bounds(), size=(320, 240))
    # bgr's front faces -z: the camera sits in front of it (z < 0), looking towards +z
    assert cam.position[2] < 0 and np.allclose(cam.rotation[2], [0, 0, -1])
    frame = raster_numpy.rasterise(house.triangles, cam)
    seen = np.unique(frame.triangle[frame.mask])
    normals = images.facing_normals(frame, house)[seen]
    assert np.median(house.normals()[seen][:, 2]) < -0.9  # mostly façade triangles facing -z
    assert (normals[:, 2] >= 0).all()  # every visible face turned towards the camera


@pytest.mark.parametrize("view", ["front", "iso", "top"])
def test_presets_frame_the_whole_model(house, view):
    cam = Camera.preset(view, *house.bounds(), size=(400, 300))
    pixels, depth = cam.project(house.triangles.reshape(-1, 3))
    assert (depth > 0).all()
    assert (pixels >= 0).all() and (pixels[:, 0] <= 400).all() and (pixels[:, 1] <= 300).all()
    span = pixels.max(axis=0) - pixels.min(axis=0)
    assert span[0] > 0.8 * 400 or span[1] > 0.8 * 300  # and fills it


@pytest.mark.parametrize(
    "content, words",
    [
        ("{", "not valid JSON"),
        ("[1, 2]", "one JSON object"),
        ('{"position": [0, 0, -10], "fvo": 40}', "unknown camera key 'fvo'"),
        ('{"fov": 40}', "needs 'position'"),
        ('{"position": [0, 0], "fov": 40}', "'position' must be a list of 3 numbers"),
        ('{"position": [0, 0, -9], "fov": "wide"}', "'fov' must be a number"),
        ('{"position": [0, 0, -9], "fov": 200}', "'fov' must be between 0 and 180"),
        (
            '{"position": [0, 0, -9], "rotation": [[1, 0, 0], [0, 2, 0], [0, 0, 1]]}',
            "'rotation' is not a rotation",
        ),
        ('{"position": [0, 0, -9], "yaw": 10, "target": [0, 0, 0]}', "give one way of turning it"),
        ('{"position": [0, 0, -9], "size": [0, 10]}', "'size' must be two positive whole numbers"),
        ('{"position": [0, 0, -9], "target": [0, 0, -9]}', "'target'"),
    ],
)
def test_camera_file_errors_name_the_problem(tmp_path, content, words):
    path = tmp_path / "cam.json"
    path.write_text(content)
    with pytest.raises(bgr.BgrError) as info:
        Camera.from_json(path)
    assert words in info.value.message and info.value.path == str(path)


def test_camera_file_forms(tmp_path):
    path = tmp_path / "cam.json"
    path.write_text(
        '{"fov": 50, "position": [4, 3, -20], "yaw": 20, "pitch": 10, "principal_point": [0.1, 0], '
        '"size": [320, 200]}'
    )
    cam = Camera.from_json(path)
    assert cam.size == (320, 200) and cam.principal_point == (0.1, 0.0)
    ref = Camera.from_angles(20, 10, 0, [4, 3, -20], 50, (0.1, 0.0), (320, 200))
    assert np.allclose(cam.rotation, ref.rotation)
    path.write_text(json.dumps(cam.to_dict()))
    again = Camera.from_json(path, size=(64, 40))
    assert np.allclose(again.rotation, cam.rotation) and again.size == (64, 40)
    path.write_text('{"position": [10, 5, -30], "target": [10, 5, 0]}')
    look = Camera.from_json(path)
    assert np.allclose(look.rotation, Camera.from_angles(0, 0, 0, [0, 0, 0]).rotation)
    with pytest.raises(bgr.BgrError, match="no such camera file"):
        Camera.from_json(tmp_path / "missing.json")


# --- rasterisers --------------------------------------------------------------------------------


@pytest.mark.parametrize("backend", BACKENDS)
def test_box_silhouette_matches_the_projected_hull(backend):
    lo, hi = np.array([1.0, 0.0, 2.0]), np.array([9.0, 5.0, 8.0])
    scene = box_scene(lo, hi)
    args = {
        "yaw": 25,
        "pitch": 20,
        "roll": 4,
        "position": np.array([18.0, 14.0, -16.0]),
        "fov": 45,
        "principal": (0.05, -0.1),
        "size": (400, 300),
    }
    cam = Camera.from_angles(
        args["yaw"],
        args["pitch"],
        args["roll"],
        args["position"],
        args["fov"],
        args["principal"],
        args["size"],
    )
    corners = np.array(
        [[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
    )
    hull = shapely.MultiPoint(reference_projection(corners, **args)).convex_hull
    expected = mask_of_polygon(hull, args["size"])
    got = frame_of(scene, cam, backend).mask
    iou = (got & expected).sum() / (got | expected).sum()
    assert iou > 0.98, iou
    assert abs(got.sum() - hull.area) < 0.01 * hull.area


def grid_square(n, jitter, rng):
    """The square 0..10 x 0..10 at z = 0 as (n - 1)^2 quads cut in two, inner corners jittered."""
    g = np.linspace(0.0, 10.0, n)
    xs, ys = np.meshgrid(g, g)
    shift = rng.uniform(-jitter, jitter, (2, n, n))
    shift[:, [0, -1], :] = 0.0
    shift[:, :, [0, -1]] = 0.0
    verts = np.stack([xs + shift[0], ys + shift[1], np.zeros_like(xs)], axis=-1).reshape(-1, 3)
    quads = [
        (i * n + j, i * n + j + 1, (i + 1) * n + j + 1, (i + 1) * n + j)
        for i in range(n - 1)
        for j in range(n - 1)
    ]
    faces = np.array([(a, b, c) for a, b, c, _ in quads] + [(a, c, d) for a, _, c, d in quads])
    k = len(faces)
    return Scene(
        verts[faces],
        np.full((k, 3), 200, np.uint8),
        np.zeros(k, np.int64),
        np.zeros(k, np.int64),
        ["x"],
    )


@pytest.mark.parametrize("backend", BACKENDS)
def test_adjacent_triangles_leave_no_holes(backend):
    """A square cut into ~2,000 triangles covers exactly the pixels of the same square in two
    triangles: nothing missing (or added) along shared edges or at shared corners, even when
    corners and edges pass exactly through pixel centres."""
    rng = np.random.default_rng(7)
    coarse = grid_square(2, 0.0, rng)
    # corners on pixel centres: 257 px wide (centre 128.5), 19.2 px per metre, 6 px per grid cell
    fov = 60.0
    distance = 257 / (2 * math.tan(math.radians(fov / 2))) / 19.2
    exact = Camera.from_angles(0, 0, 0, [5, 5, -distance], fov, size=(257, 257))
    cases = [(grid_square(33, 0.0, rng), exact), (grid_square(33, 0.12, rng), exact)]
    for yaw in (160.0, 23.0, -40.0):
        eye = np.array([5, 5, 0]) - 20 * np.array(
            [math.sin(math.radians(yaw)), -0.2, math.cos(math.radians(yaw))]
        )
        cases.append((grid_square(33, 0.12, rng), Camera.look_at(eye, [5, 5, 0], size=(256, 256))))
    for k, (fine, cam) in enumerate(cases):
        a, b = frame_of(fine, cam, backend).mask, frame_of(coarse, cam, backend).mask
        assert a.sum() > 10_000
        if k < 2:  # straight outline: the same pixels exactly
            assert (a == b).all(), (k, (a != b).sum())
        else:  # in perspective the outline's inner corners snap to 1/256 px off the straight edge
            inner = b.copy()
            inner[1:-1, 1:-1] = (
                b[1:-1, 1:-1] & b[:-2, 1:-1] & b[2:, 1:-1] & b[1:-1, :-2] & b[1:-1, 2:]
            )
            assert a[inner].all(), (k, (inner & ~a).sum())  # no hole inside
            assert (a != b).sum() <= 4, (k, (a != b).sum())


def test_numpy_and_gl_agree(house):
    gl_or_skip()
    for view in ("front", "iso", "top"):
        cam = Camera.preset(view, *house.bounds(), size=(320, 240))
        a = raster_numpy.rasterise(house.triangles, cam)
        b = raster_gl.rasterise(house.triangles, cam)
        assert (a.mask == b.mask).mean() > 0.999
        same = a.triangle == b.triangle
        assert same.mean() > 0.995, (view, same.mean())
        both = same & a.mask
        assert np.allclose(a.depth[both], b.depth[both], rtol=1e-4)


def test_near_plane_clipping_agrees():
    """A camera standing inside the model: triangles cross the near plane and are clipped."""
    gl_or_skip()
    scene = box_scene((0, 0, 0), (20, 10, 20))
    cam = Camera.look_at([3, 4, 3], [15, 3, 17], size=(200, 150), fov=90)
    a = raster_numpy.rasterise(scene.triangles, cam)
    b = raster_gl.rasterise(scene.triangles, cam)
    assert a.mask.all() and b.mask.all()  # the walls all round
    assert (a.triangle == b.triangle).mean() > 0.99
    assert np.allclose(a.depth, b.depth, rtol=1e-4)


def test_auto_falls_back_to_numpy_once_gl_fails(house, monkeypatch):
    monkeypatch.setitem(raster_gl._state, "error", "pretend: no EGL")
    cam = Camera.preset("iso", *house.bounds(), size=(64, 48))
    reasons = []
    frame = rasterise(house, cam, "auto", on_fallback=reasons.append)
    assert frame.backend == "numpy" and reasons == ["pretend: no EGL"]
    with pytest.raises(bgr.BgrError, match="GL renderer is not available"):
        rasterise(house, cam, "gl")
    with pytest.warns(RuntimeWarning, match="numpy"):
        render(house, size=(64, 48))


def test_forked_child_falls_back_instead_of_hanging():
    """Mesa hangs a forked child making a context after its parent did: the child must not try."""
    gl_or_skip()
    code = (
        "import os\n"
        "from bgr.render import Camera, load_scene, rasterise\n"
        "s = load_scene(os.environ['HOUSE'])\n"
        "cam = Camera.preset('iso', *s.bounds(), size=(64, 48))\n"
        "assert rasterise(s, cam, 'gl').backend == 'gl'\n"
        "pid = os.fork()\n"
        "if pid == 0:\n"
        "    os._exit(0 if rasterise(s, cam, on_fallback=None).backend == 'numpy' else 3)\n"
        "_, status = os.waitpid(pid, 0)\n"
        "raise SystemExit(os.waitstatus_to_exitcode(status))\n"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "HOUSE": str(HOUSE)},
        check=False,
    )
    assert proc.returncode == 0, proc.stderr


# --- images -------------------------------------------------------------------------------------


@pytest.mark.parametrize("view", ["front", "iso", "top"])
def test_shaded_house_is_not_blank(house, view):
    image = render(house, "shaded", view, size=(320, 240))
    assert image.shape == (240, 320, 3) and image.dtype == np.uint8
    colours = np.unique(image.reshape(-1, 3), axis=0)
    assert len(colours) >= (3 if view == "top" else 5)
    foreground = (image != images.BACKGROUND).any(axis=2).mean()
    assert 0.2 < foreground < 0.95
    assert tuple(image[0, 0]) == images.BACKGROUND


def test_labels_give_one_colour_per_label(house):
    image, legend = render_labels(house, "iso", size=(320, 240), backend="numpy")
    assert (
        set(legend["labels"])
        == set(house.labels)
        == {"Door", "Frame", "Glass", "Roof", "Sill", "Wall"}
    )
    colours = list(legend["labels"].values())
    assert len(set(colours)) == len(colours) and "#000000" not in colours
    frame = rasterise(house, make_camera("iso", house, (320, 240)), "numpy")  # render's camera
    label_at = np.array(house.labels + ["(background)"])[
        np.concatenate([house.label, [-1]])[frame.triangle]
    ]
    hexes = np.array([images.hex_colour(p) for p in image.reshape(-1, 3)]).reshape(240, 320)
    for name in np.unique(label_at):
        seen = set(hexes[label_at == name])
        assert seen == {legend["labels"].get(name, "#000000")}, name
    assert (
        images.label_colours(["Wall"])["Wall"] == images.label_colours(house.labels)["Wall"]
    )  # fixed colours


def test_lines_draw_the_box_outline_but_no_face_diagonal():
    lo, hi = np.array([0.0, 0.0, 0.0]), np.array([8.0, 5.0, 6.0])
    scene = box_scene(lo, hi)
    size = (400, 300)
    cam = Camera.preset("iso", lo, hi, size)
    line = images.lines(raster_numpy.rasterise(scene.triangles, cam), scene) == 0
    assert line.mean() < 0.05
    pixels, _ = cam.project(np.array([[x, y, z] for x in (0, 8) for y in (0, 5) for z in (0, 6)]))
    hull = shapely.MultiPoint(pixels).convex_hull
    near_line = np.zeros_like(
        line
    )  # lines grown by one pixel: the outline may sit half a pixel off
    near_line[1:-1, 1:-1] = (
        line[1:-1, 1:-1] | line[:-2, 1:-1] | line[2:, 1:-1] | line[1:-1, :-2] | line[1:-1, 2:]
    )
    outline = hull.exterior
    for t in np.linspace(0, 1, 200, endpoint=False):
        x, y = outline.interpolate(t, normalized=True).coords[0]
        assert near_line[int(y), int(x)] or near_line[int(y + 0.5), int(x + 0.5)], (x, y)
    # every box face is two triangles: the middle of each diagonal of a visible face stays white
    tri = scene.triangles
    normals = scene.normals()
    checked = 0
    for axis in range(3):
        for side in (lo[axis], hi[axis]):
            on = np.flatnonzero(np.isclose(tri[:, :, axis], side).all(axis=1))
            quad = tri[on].reshape(-1, 3)
            face_centre = (quad.min(axis=0) + quad.max(axis=0)) / 2
            if (cam.position - face_centre) @ normals[on[0]] <= 0:
                continue  # not visible
            # the diagonal is the edge shared by the face's two triangles
            shared = [p for p in tri[on[0]] if any(np.allclose(p, q) for q in tri[on[1]])]
            for t in np.linspace(0.3, 0.7, 9):
                ((u, v),) = cam.project([shared[0] + t * (shared[1] - shared[0])])[0]
                assert not line[int(v), int(u)], (axis, side, t)
            checked += 1
    assert checked == 3


def test_silhouette_is_binary(house):
    image = render(house, "silhouette", "front", size=(160, 120))
    assert image.shape == (120, 160) and set(np.unique(image)) == {0, 255}


def test_glb_scene_labels_by_material(tmp_path):
    result = bgr.derive(HOUSE, seed=3)
    path = tmp_path / "house.glb"
    result.save(path)
    scene = load_scene(path)
    assert len(scene) == result.terminals.triangle_count()
    assert set(scene.labels) == {"#5a6a7a", "#7a3b2e", "#cccccc", "#d8c8a8"}
    a = render(scene, "shaded", "front", size=(200, 150), backend="numpy")
    b = render(result, "shaded", "front", size=(200, 150), backend="numpy")
    assert (np.abs(a.astype(int) - b.astype(int)).max(axis=2) > 2).mean() < 0.01


@pytest.mark.parametrize("ext", ["obj", "ply"])
def test_obj_and_ply_that_derive_writes_render_in_their_colours(tmp_path, capsys, ext):
    """`bgr derive examples/house.bgr -o h.obj && bgr render h.obj -o h.png` (issue 24): the OBJ
    is read with its .mtl, the PLY with its vertex colours; the picture is the grammar's."""
    result = bgr.derive(HOUSE, seed=3)
    path = tmp_path / f"house.{ext}"
    assert main(["derive", str(HOUSE), "--seed", "3", "-o", str(path)]) == 0
    scene = load_scene(path)
    assert len(scene) == result.terminals.triangle_count() and scene.warnings == []
    assert set(scene.labels) == {"#5a6a7a", "#7a3b2e", "#cccccc", "#d8c8a8"}
    a = render(scene, "shaded", "front", size=(200, 150), backend="numpy")
    b = render(result, "shaded", "front", size=(200, 150), backend="numpy")
    assert (np.abs(a.astype(int) - b.astype(int)).max(axis=2) > 2).mean() < 0.01
    out = tmp_path / "h.png"
    assert main(["render", str(path), "-o", str(out), "--size", "80x60"]) == 0
    assert out.is_file() and "80x60 shaded" in capsys.readouterr().err


def test_obj_without_its_mtl_is_drawn_grey_with_a_warning(tmp_path, capsys):
    path = tmp_path / "house.obj"
    bgr.derive(HOUSE, seed=3).save(path)
    (tmp_path / "house.mtl").unlink()
    assert main(["render", str(path), "-o", str(tmp_path / "h.png"), "--size", "80x60"]) == 0
    err = capsys.readouterr().err
    assert "warning: material library 'house.mtl' not read" in err and "Traceback" not in err
    # an mtllib outside the OBJ's folder is not read
    (tmp_path / "sub").mkdir()
    text = path.read_text().replace("mtllib house.mtl", "mtllib ../secret.mtl")
    (tmp_path / "sub" / "x.obj").write_text(text)
    (tmp_path / "secret.mtl").write_text("newmtl c_d8c8a8\nKd 1 0 0\n")
    scene = load_scene(tmp_path / "sub" / "x.obj")
    assert "outside the OBJ's folder" in scene.warnings[0].message
    assert not (scene.colors == [255, 0, 0]).all(axis=1).any()


@pytest.mark.parametrize(
    "name, data, words",
    [
        ("x.obj", bytes(range(256)) * 4, "a binary file, not a Wavefront OBJ"),
        ("x.ply", b"\x89PNG\r\n\x1a\n" + bytes(200), "not a .ply file bgr can read"),
        ("x.obj", b"# nothing\nv 0 0 0\n", "no triangles to draw"),
        ("x.ply", b"", "not a .ply file bgr can read"),
    ],
)
def test_bad_obj_and_ply_are_one_error(tmp_path, capsys, name, data, words):
    (tmp_path / name).write_bytes(data)
    assert main(["render", str(tmp_path / name), "-o", str(tmp_path / "x.png")]) == 1
    err = capsys.readouterr().err
    assert words in err and "Traceback" not in err and not (tmp_path / "x.png").exists()


# --- files and the command line ----------------------------------------------------------------


def test_save_png_is_atomic(tmp_path):
    image = np.zeros((10, 20, 3), np.uint8)
    with pytest.raises(bgr.BgrError, match="does not exist"):
        save_png(image, tmp_path / "no" / "x.png")
    with pytest.raises(bgr.BgrError, match="extension"):
        save_png(image, tmp_path / "x.jpg")
    with pytest.raises(bgr.BgrError, match="shape"):
        save_png(np.zeros((4, 4, 7), np.uint8), tmp_path / "x.png")
    assert list(tmp_path.iterdir()) == []
    save_png(image, tmp_path / "x.png")
    assert Image.open(tmp_path / "x.png").size == (20, 10)


def test_cli_writes_pngs(tmp_path, capsys):
    out = tmp_path / "p.png"
    assert (
        main(
            [
                "render",
                str(HOUSE),
                "-o",
                str(out),
                "--size",
                "160x120",
                "--seed",
                "3",
                "--set",
                "height=14",
                "--lot",
                "24,16",
            ]
        )
        == 0
    )
    with Image.open(out) as im:
        assert im.format == "PNG" and im.size == (160, 120) and im.mode == "RGB"
    assert "160x120 shaded" in capsys.readouterr().err
    out2 = tmp_path / "l.png"
    assert (
        main(
            [
                "render",
                str(HOUSE),
                "-o",
                str(out2),
                "--size",
                "160x120",
                "--mode",
                "labels",
                "--legend",
                "--view",
                "front",
                "--backend",
                "numpy",
            ]
        )
        == 0
    )
    legend = json.loads((tmp_path / "l.legend.json").read_text())
    assert legend["background"] == "#000000" and "Wall" in legend["labels"]
    cam = tmp_path / "cam.json"
    cam.write_text('{"fov": 40, "position": [10, 6, -40], "target": [10, 5, 6], "size": [90, 60]}')
    out3 = tmp_path / "c.png"
    assert main(["render", str(HOUSE), "-o", str(out3), "--view", str(cam), "--mode", "lines"]) == 0
    with Image.open(out3) as im:
        assert im.size == (90, 60) and im.mode == "L"


def test_cli_failures_leave_no_file(tmp_path, capsys):
    out = tmp_path / "p.png"
    assert main(["render", str(tmp_path / "missing.bgr"), "-o", str(out)]) == 1
    assert "no such file" in capsys.readouterr().err
    assert main(["render", str(tmp_path / "missing.glb"), "-o", str(out)]) == 1
    bad = tmp_path / "cam.json"
    bad.write_text('{"fov": 40, "positon": [0, 0, -5]}')
    assert main(["render", str(HOUSE), "-o", str(out), "--view", str(bad)]) == 1
    assert "unknown camera key 'positon'" in capsys.readouterr().err
    div = tmp_path / "div.bgr"
    div.write_text("attr n = 0\nLot --> extrude(1 / n)\n")
    assert main(["render", str(div), "-o", str(out)]) == 1
    assert "division by zero" in capsys.readouterr().err
    assert main(["render", str(HOUSE), "-o", str(tmp_path / "p.jpg")]) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cam.json", "div.bgr"]


@pytest.mark.parametrize(
    "args",
    [
        [],  # no -o
        ["-o", "x.png", "--size", "big"],
        ["-o", "x.png", "--view", "side"],
        ["-o", "x.png", "--mode", "wire"],
        ["-o", "x.png", "--legend"],
        ["-o", "x.png", "--set", "novalue"],
    ],
)
def test_cli_usage_errors(args, capsys):
    with pytest.raises(SystemExit) as info:
        raise SystemExit(main(["render", str(HOUSE), *args]))
    assert info.value.code == 2


def test_cli_model_options_only_for_grammars(tmp_path):
    glb = tmp_path / "h.glb"
    bgr.derive(HOUSE).save(glb)
    assert main(["render", str(glb), "-o", str(tmp_path / "x.png"), "--seed", "2"]) == 2
    assert main(["render", str(glb), "-o", str(tmp_path / "x.png"), "--size", "80x60"]) == 0


def test_cli_subprocess_no_traceback(tmp_path):
    out = tmp_path / "p.png"
    proc = subprocess.run(
        [sys.executable, "-m", "bgr", "render", str(tmp_path / "nope.bgr"), "-o", str(out)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 1 and "Traceback" not in proc.stderr and "no such file" in proc.stderr
    assert not out.exists()


@pytest.mark.parametrize("backend", BACKENDS)
def test_same_inputs_same_bytes(tmp_path, backend):
    if backend == "gl":
        gl_or_skip()
    for name in ("a.png", "b.png"):
        assert (
            main(
                [
                    "render",
                    str(HOUSE),
                    "-o",
                    str(tmp_path / name),
                    "--size",
                    "200x150",
                    "--seed",
                    "3",
                    "--backend",
                    backend,
                ]
            )
            == 0
        )
    assert (tmp_path / "a.png").read_bytes() == (tmp_path / "b.png").read_bytes()
