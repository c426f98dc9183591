"""bgr render draws textures (issue 26): a textured grammar, textured glTF / OBJ+MTL models and
CityGML buildings, with both rasterisers.

The expectations are measured without the renderer's texturing: the light on a surface is read
from an untextured white twin of the same scene (its pixels are the intensity itself), and where
a pixel lands on the façade is computed here from the camera, a ray and the façade's plane.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest
from conftest import SHARED
from PIL import Image
from test_render import BACKENDS, gl_or_skip

import bgr
from bgr.cli import main
from bgr.render import Camera, images, load_scene, make_camera, rasterise, render
from bgr.render.scene import Scene

PLATEAU = SHARED / "data" / "textured" / "plateau_tokyo" / "53392633_bldg_6697_2_op.gml"

# the texture: four quadrants, rows from the image's top: red | green over blue | yellow
QUADRANTS = {
    "top-left": (230, 30, 30),
    "top-right": (30, 200, 60),
    "bottom-left": (40, 60, 220),
    "bottom-right": (240, 220, 40),
}
# the façade: 3 m x 2 m, the back face of a box; where it lies and which way its scope x runs
# are read from the derived terminal (:class:`Face`), so the cameras look at its outside with
# its scope x to the right and its scope y up
FACADE = (
    "version 1\nstart Lot\nterminal Tile\n"
    "Lot --> s(3, 0, 2) r(0, 0, 0) extrude(2) comp(f) { back: Facade }\n"
)
SIZE = (320, 240)


@dataclass
class Face:
    """A quad: its corner at scope (0, 0) and its scope x and y edges, in world metres."""

    origin: np.ndarray
    ex: np.ndarray
    ey: np.ndarray

    @classmethod
    def of(cls, path) -> Face:
        table = bgr.derive(path).terminals.freeze()
        assert len(table) == 1
        axes, size = table.axes[0], table.size[0]
        return cls(table.origin[0].copy(), axes[0] * size[0], axes[1] * size[1])

    def camera(self, right: float, up: float, out: float) -> Camera:
        """A camera ``out`` metres in front of the face's centre, moved ``right`` and ``up``
        along its scope x and y, looking at its centre with its scope y up."""
        ux, uy = self.ex / np.linalg.norm(self.ex), self.ey / np.linalg.norm(self.ey)
        n = np.cross(ux, uy)
        centre = self.origin + (self.ex + self.ey) / 2
        return Camera.look_at(centre + right * ux + up * uy + out * n, centre, uy, size=SIZE)

    def box(self, camera) -> tuple[int, int, int, int]:
        """(left, top, right, bottom) pixel columns and rows of the face seen straight on."""
        o, x, y = self.origin, self.ex, self.ey
        px, _ = camera.project(np.array([o, o + x, o + x + y, o + y]))
        return int(px[:, 0].min()), int(px[:, 1].min()), int(px[:, 0].max()), int(px[:, 1].max())

    def scope_x(self, camera, rows, cols) -> np.ndarray:
        """The scope x (0..1) of the point where the ray through each pixel's centre meets
        the face's plane: the ray and the plane written out afresh, not the renderer's."""
        cx, cy = camera.center
        f = camera.focal
        ray = np.stack([(cols + 0.5 - cx) / f, -(rows + 0.5 - cy) / f, -np.ones(len(rows))], axis=1)
        ray = ray @ camera.rotation
        n = np.cross(self.ex, self.ey)
        t = ((self.origin - camera.position) @ n) / (ray @ n)
        hit = camera.position + t[:, None] * ray
        return (hit - self.origin) @ self.ex / (self.ex @ self.ex)


def linear(srgb) -> np.ndarray:
    c = np.asarray(srgb, dtype=np.float64) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def quadrant_png(path, size: int = 8) -> None:
    pixels = np.zeros((size, size, 3), np.uint8)
    h = size // 2
    pixels[:h, :h], pixels[:h, h:] = QUADRANTS["top-left"], QUADRANTS["top-right"]
    pixels[h:, :h], pixels[h:, h:] = QUADRANTS["bottom-left"], QUADRANTS["bottom-right"]
    Image.fromarray(pixels).save(path)


def facade(tmp_path, body: str, name: str = "f.bgr"):
    path = tmp_path / name
    path.write_text(FACADE + "Facade --> " + body + " Tile\n")
    return path


@pytest.fixture
def grammars(tmp_path):
    """(textured façade, its untextured white twin, its untextured default-grey twin)."""
    quadrant_png(tmp_path / "img.png")
    textured = facade(
        tmp_path,
        'color("#ffffff") setupProjection(0, scope.xy, \'1, \'1) projectUV(0) texture("img.png")',
    )
    white = facade(tmp_path, 'color("#ffffff")', "white.bgr")
    grey = facade(tmp_path, "setupProjection(0, scope.xy, '1, '1) projectUV(0)", "grey.bgr")
    return textured, white, grey


@pytest.fixture
def face(grammars):
    return Face.of(grammars[1])


def region(image, box, fx0, fy0, fx1, fy1) -> np.ndarray:
    """The pixels of the part (fx0..fx1, fy0..fy1 as fractions, y from the top) of ``box``."""
    left, top, right, bottom = box
    w, h = right - left, bottom - top
    rows = slice(top + int(fy0 * h), top + int(fy1 * h))
    cols = slice(left + int(fx0 * w), left + int(fx1 * w))
    return image[rows, cols].reshape(-1, 3)


# --- a textured grammar ----------------------------------------------------------------------


@pytest.mark.parametrize("backend", BACKENDS)
def test_textured_facade_shows_its_image_under_the_light(grammars, face, backend):
    if backend == "gl":
        gl_or_skip()
    textured, white, grey = grammars
    camera = face.camera(0, 0, 6)
    shot = render(textured, view=camera, backend=backend)
    light = render(white, view=camera, backend=backend)
    plain = render(grey, view=camera, backend=backend)
    box = face.box(camera)
    intensity = linear(region(light, box, 0.1, 0.1, 0.9, 0.9)).mean(axis=0)
    assert np.allclose(intensity, intensity[0]) and 0.3 < intensity[0] <= 1.0
    # each quadrant of the façade shows that quadrant of the image (v up: the image's top row at
    # the façade's top; u along scope x, left to right seen from outside), lit like the twin
    for name, (fx, fy) in {
        "top-left": (0.0, 0.0),
        "top-right": (0.5, 0.0),
        "bottom-left": (0.0, 0.5),
        "bottom-right": (0.5, 0.5),
    }.items():
        seen = linear(region(shot, box, fx + 0.1, fy + 0.1, fx + 0.4, fy + 0.4)).mean(axis=0)
        expected = linear(QUADRANTS[name]) * intensity[0]
        assert np.allclose(seen, expected, atol=0.01), (name, seen, expected)
    # the whole façade's mean is the texture's mean colour (in linear light), times the light
    texture_mean = np.mean([linear(c) for c in QUADRANTS.values()], axis=0) * intensity[0]
    whole = linear(region(shot, box, 0.02, 0.02, 0.98, 0.98)).mean(axis=0)
    assert np.allclose(whole, texture_mean, atol=0.02)
    # ... which an untextured twin is not
    untextured = linear(region(plain, box, 0.02, 0.02, 0.98, 0.98)).mean(axis=0)
    assert np.abs(untextured - texture_mean).max() > 0.1


def test_colour_multiplies_the_image(grammars, face, tmp_path):
    """As glTF's baseColorFactor times baseColorTexture: the default grey darkens the image."""
    quadrant_png(tmp_path / "img.png")
    tinted = facade(
        tmp_path,
        "color(0.5, 1, 1) setupProjection(0, scope.xy, '1, '1) projectUV(0) texture(\"img.png\")",
        "tinted.bgr",
    )
    camera = face.camera(0, 0, 6)
    light = render(grammars[1], view=camera, backend="numpy")
    shot = render(tinted, view=camera, backend="numpy")
    box = face.box(camera)
    intensity = linear(region(light, box, 0.1, 0.1, 0.9, 0.9)).mean()
    seen = linear(region(shot, box, 0.1, 0.6, 0.4, 0.9)).mean(axis=0)  # bottom-left: blue
    expected = linear(QUADRANTS["bottom-left"]) * linear((128, 255, 255)) * intensity
    assert np.allclose(seen, expected, atol=0.01)


STRIPES = np.array(
    [
        (230, 25, 25),
        (25, 200, 25),
        (25, 25, 230),
        (230, 230, 25),
        (25, 220, 220),
        (220, 25, 220),
        (250, 250, 250),
        (60, 60, 60),
    ],
    dtype=np.uint8,
)


@pytest.mark.parametrize("backend", BACKENDS)
def test_oblique_view_is_perspective_correct(tmp_path, face, backend):
    """Eight vertical stripes seen at a slant: each pixel shows the stripe of the façade point
    its ray hits (an affine interpolation in the image would be off by up to a stripe)."""
    if backend == "gl":
        gl_or_skip()
    Image.fromarray(np.repeat(STRIPES[None], 2, axis=0)).save(tmp_path / "stripes.png")
    textured = facade(
        tmp_path,
        "color(\"#ffffff\") setupProjection(0, scope.xy, '1, '1) projectUV(0) "
        'texture("stripes.png")',
    )
    white = facade(tmp_path, 'color("#ffffff")', "white.bgr")
    camera = face.camera(-4, 0.7, 3)
    scene = load_scene(textured)
    shot = images.shaded(rasterise(scene, camera, backend), scene, filter="nearest")
    plain = load_scene(white)
    frame = rasterise(plain, camera, backend)
    light = images.shaded(frame, plain)
    rows, cols = np.nonzero(frame.triangle >= 0)
    assert len(rows) > 5000
    x = face.scope_x(camera, rows, cols) * 8
    expected = np.clip(np.floor(x), 0, 7).astype(int)
    # the texel's colour: the pixel divided by the light on it, matched to the nearest stripe
    texel = linear(shot[rows, cols]) / linear(light[rows, cols])
    seen = np.argmin(((texel[:, None, :] - linear(STRIPES)[None]) ** 2).sum(axis=2), axis=1)
    near_edge = np.abs(x - np.rint(x)) < 0.05
    assert (seen == expected)[~near_edge].mean() > 0.995
    # an affine (screen-space) interpolation would disagree on many of them
    mid = face.origin + face.ey / 2
    px, _ = camera.project(np.array([mid, mid + face.ex]))
    affine = np.clip(np.floor((cols - px[0, 0]) / (px[1, 0] - px[0, 0]) * 8), 0, 7)
    assert (affine != expected).mean() > 0.1


def test_untextured_scene_is_drawn_as_before(grammars, face):
    """The texturing pass touches nothing without textures: the same image, pixel for pixel,
    as the flat-shaded lookup table alone."""
    _, white, _ = grammars
    scene = load_scene(white)
    assert not scene.textured()
    frame = rasterise(scene, face.camera(0, 0, 6), "numpy")
    image = images.shaded(frame, scene)
    stripped = Scene(scene.triangles, scene.colors, scene.part, scene.label, scene.labels)
    assert np.array_equal(image, images.shaded(frame, stripped))


def test_wrapping_repeats_the_image(tmp_path, grammars, face):
    """``setupProjection(0, scope.xy, 1.5, 1)``: the 3 m x 2 m façade shows the image 2 x 2
    times, so each quarter of it shows the whole image (its top-left corner red ...)."""
    quadrant_png(tmp_path / "img.png")
    tiled = facade(
        tmp_path,
        'color("#ffffff") setupProjection(0, scope.xy, 1.5, 1) projectUV(0) texture("img.png")',
        "tiled.bgr",
    )
    camera = face.camera(0, 0, 6)
    shot = render(tiled, view=camera, backend="numpy")
    light = render(grammars[1], view=camera, backend="numpy")
    box = face.box(camera)
    intensity = linear(region(light, box, 0.1, 0.1, 0.9, 0.9)).mean()
    for fx in (0.0, 0.5):
        for fy in (0.0, 0.5):
            seen = linear(region(shot, box, fx + 0.05, fy + 0.05, fx + 0.2, fy + 0.2))
            expected = linear(QUADRANTS["top-left"]) * intensity
            assert np.allclose(seen.mean(axis=0), expected, atol=0.01)


# --- textured models -------------------------------------------------------------------------


def test_textured_glb_renders_like_its_grammar(grammars, face, tmp_path):
    textured, white, _ = grammars
    glb = tmp_path / "f.glb"
    bgr.derive(textured).save(glb)
    camera = face.camera(0, 0, 6)
    shot = render(glb, view=camera, backend="numpy")
    light = render(white, view=camera, backend="numpy")
    box = face.box(camera)
    intensity = linear(region(light, box, 0.1, 0.1, 0.9, 0.9)).mean()
    seen = linear(region(shot, box, 0.6, 0.1, 0.9, 0.4)).mean(axis=0)  # top-right: green
    assert np.allclose(seen, linear(QUADRANTS["top-right"]) * intensity, atol=0.01)


def test_obj_with_map_kd_renders_its_image(tmp_path):
    """A hand-written OBJ quad (the façade, 3 x 2 m in z = 0) with ``vt`` and an MTL's
    ``map_Kd``."""
    quadrant_png(tmp_path / "img.png")
    (tmp_path / "m.mtl").write_text("newmtl skin\nKd 1 1 1\nmap_Kd img.png\n")
    (tmp_path / "q.obj").write_text(
        "mtllib m.mtl\nv 0 0 0\nv 3 0 0\nv 3 2 0\nv 0 2 0\n"
        "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl skin\nf 1/1 2/2 3/3 4/4\n"
    )
    (tmp_path / "w.obj").write_text("v 0 0 0\nv 3 0 0\nv 3 2 0\nv 0 2 0\nf 1 2 3 4\n")
    scene = load_scene(tmp_path / "q.obj")
    assert scene.textured() and scene.labels == ["skin"]
    face = Face(np.zeros(3), np.array([3.0, 0, 0]), np.array([0, 2.0, 0]))
    camera = face.camera(0, 0, 6)
    shot = render(scene, view=camera, backend="numpy")
    box = face.box(camera)
    # the light, from an untextured white quad in the same place
    plain = load_scene(tmp_path / "w.obj")
    plain.colors[:] = 255
    light = render(plain, view=camera, backend="numpy")
    intensity = linear(region(light, box, 0.1, 0.1, 0.9, 0.9))
    for name, (fx, fy) in {"top-left": (0.0, 0.0), "bottom-right": (0.5, 0.5)}.items():
        seen = linear(region(shot, box, fx + 0.1, fy + 0.1, fx + 0.4, fy + 0.4)).mean(axis=0)
        assert np.allclose(seen, linear(QUADRANTS[name]) * intensity.mean(), atol=0.01), name


def test_gl_and_numpy_draw_the_same_textures(grammars, face):
    gl_or_skip()
    scene = load_scene(grammars[0])
    camera = face.camera(-4, 0.7, 3)
    gl = images.shaded(rasterise(scene, camera, "gl"), scene)
    cpu = images.shaded(rasterise(scene, camera, "numpy"), scene)
    assert (np.abs(gl.astype(int) - cpu.astype(int)).max(axis=2) <= 1).mean() > 0.999


# --- CityGML ---------------------------------------------------------------------------------


def test_citygml_wall_shows_its_image_in_a_y_up_frame(tmp_path):
    """test_textured_read's wall (4 m x 3 m in the plane y = 0 of EPSG:6677, z up, u = x / 4)
    beside a 4 x 2 image, left half red, right half blue: drawn y up about its centre, the
    wall seen from +y (north) shows the red half on the right (x grows to the viewer's left)."""
    from test_textured_read import WALL

    (tmp_path / "tex").mkdir()
    pixels = np.zeros((2, 4, 3), dtype=np.uint8)
    pixels[:, :2], pixels[:, 2:] = (230, 30, 30), (40, 60, 220)
    Image.fromarray(pixels).save(tmp_path / "tex" / "wall.png")
    path = tmp_path / "wall.gml"
    path.write_text(WALL.format(hole="", hole_uv="", image="tex/wall.png"), encoding="utf-8")
    scene = load_scene(path)
    assert scene.textured() and set(scene.labels) == {"WallSurface", "RoofSurface"}
    # x 0..4 -> east -2..2; z 0..3 -> up; y -2..0 -> -north -1..1 (centred on the box)
    lo, hi = scene.bounds()
    np.testing.assert_allclose(lo, [-2, 0, -1], atol=1e-12)
    np.testing.assert_allclose(hi, [2, 3, 1], atol=1e-12)
    wall = Face(np.array([2.0, 0, -1]), np.array([-4.0, 0, 0]), np.array([0, 3.0, 0]))
    camera = wall.camera(0, 0, 6)  # on the +y (north, render -z) side of the wall
    assert camera.position[2] < -1
    shot = render(scene, view=camera, backend="numpy")
    white = Scene(
        scene.triangles, np.full_like(scene.colors, 255), scene.part, scene.label, scene.labels
    )
    box = wall.box(camera)
    intensity = linear(region(render(white, view=camera, backend="numpy"), box, 0.1, 0.1, 0.9, 0.9))
    left = linear(region(shot, box, 0.1, 0.2, 0.35, 0.8)).mean(axis=0)
    right = linear(region(shot, box, 0.65, 0.2, 0.9, 0.8)).mean(axis=0)
    assert np.allclose(left, linear((40, 60, 220)) * intensity.mean(), atol=0.01)
    assert np.allclose(right, linear((230, 30, 30)) * intensity.mean(), atol=0.01)


# --- CityGML: the PLATEAU buildings -------------------------------------------------------------


@pytest.fixture(scope="module")
def plateau():
    if not PLATEAU.is_file():
        pytest.skip(f"the PLATEAU buildings are not here ({PLATEAU})")
    return load_scene(PLATEAU)


def test_plateau_is_drawn_in_a_local_metric_frame(plateau):
    """Distances between the file's points (latitude, longitude, height) measured on the
    ellipsoid by pyproj's geodesic agree with the scene's horizontal distances."""
    from pyproj import Geod

    from bgr.formats.citygml_read import read_citygml

    mesh = read_citygml(PLATEAU)
    geod = Geod(ellps="GRS80")
    rng = np.random.default_rng(5)
    a, b = rng.choice(len(mesh.faces), 2, replace=False)
    for i, j in ((a, b), (0, len(mesh.faces) - 1)):
        p, q = mesh.vertices[mesh.faces[i, 0]], mesh.vertices[mesh.faces[j, 0]]
        _, _, metres = geod.inv(p[1], p[0], q[1], q[0])
        s, t = plateau.triangles[i, 0], plateau.triangles[j, 0]
        assert np.hypot(s[0] - t[0], s[2] - t[2]) == pytest.approx(metres, rel=1e-5)
        assert s[1] == p[2] and t[1] == q[2]  # heights kept, y up
    lo, hi = plateau.bounds()
    assert 100 < hi[0] - lo[0] < 1000 and 3 < lo[1] < hi[1] < 60


def test_plateau_renders_with_its_textures(plateau, tmp_path):
    assert plateau.textured()
    assert {"WallSurface", "RoofSurface"} <= set(plateau.labels)
    camera = make_camera("iso", plateau, (400, 300))
    frame = rasterise(plateau, camera, "numpy")
    shot = images.shaded(frame, plateau)
    flat = images.shaded(
        frame, Scene(plateau.triangles, plateau.colors, plateau.part, plateau.label, plateau.labels)
    )
    tri = frame.triangle
    on_texture = (tri >= 0) & (plateau.texture[np.maximum(tri, 0)] >= 0)
    assert on_texture.sum() > 0.2 * (tri >= 0).sum()  # most of what is seen is photographed
    # textured pixels are photographs, not flat colours: they differ from the untextured render
    # and take many colours on a single triangle's pixels
    differ = np.abs(shot.astype(int) - flat.astype(int)).max(axis=2) > 10
    assert differ[on_texture].mean() > 0.5
    colours = np.unique(shot[on_texture].reshape(-1, 3), axis=0)
    assert len(colours) > 1000
    assert (differ & ~on_texture & (tri >= 0)).sum() == 0  # untextured surfaces unchanged


def test_bgr_render_draws_a_citygml_file(tmp_path, capsys):
    if not PLATEAU.is_file():
        pytest.skip(f"the PLATEAU buildings are not here ({PLATEAU})")
    out = tmp_path / "plateau.png"
    args = ["render", str(PLATEAU), "-o", str(out), "--size", "320x240", "--backend", "numpy"]
    assert main(args) == 0
    assert "320x240 shaded" in capsys.readouterr().err
    with Image.open(out) as im:
        assert im.size == (320, 240)


def test_render_help_names_citygml(capsys):
    with pytest.raises(SystemExit):
        main(["render", "--help"])
    assert ".gml" in capsys.readouterr().out


def test_bad_citygml_is_one_located_error(tmp_path, capsys):
    bad = tmp_path / "bad.gml"
    bad.write_text("<CityModel><nothing/></CityModel>")
    assert main(["render", str(bad), "-o", str(tmp_path / "x.png"), "--backend", "numpy"]) == 1
    err = capsys.readouterr().err
    assert "bad.gml" in err and "Traceback" not in err
    assert not (tmp_path / "x.png").exists()


def test_far_away_fine_pattern_shows_its_mean(tmp_path, grammars, face):
    """A checkerboard of single black and white texels, 60 x 40 times over the façade (some 16
    texels per pixel): mipmapping draws its mean, half the white in linear light, where the
    nearest texel alone sparkles between black and white."""
    checker = (np.indices((64, 64)).sum(axis=0) % 2 * 255).astype(np.uint8)
    Image.fromarray(np.repeat(checker[:, :, None], 3, axis=2)).save(tmp_path / "checker.png")
    fine = facade(
        tmp_path,
        'color("#ffffff") setupProjection(0, scope.xy, 0.05, 0.05) projectUV(0) '
        'texture("checker.png")',
        "fine.bgr",
    )
    scene = load_scene(fine)
    camera = face.camera(0, 0, 6)
    frame = rasterise(scene, camera, "numpy")
    box = face.box(camera)
    light = render(grammars[1], view=camera, backend="numpy")
    intensity = linear(region(light, box, 0.1, 0.1, 0.9, 0.9)).mean()
    smooth = linear(region(images.shaded(frame, scene), box, 0.1, 0.1, 0.9, 0.9)) / intensity
    assert np.allclose(smooth.mean(), 0.5, atol=0.02) and smooth.std() < 0.05
    sparkle = linear(region(images.shaded(frame, scene, filter="nearest"), box, 0.1, 0.1, 0.9, 0.9))
    assert (sparkle / intensity).std() > 0.3
