"""``bgr infer PHOTO --kind image --silhouette SIL -o b.bgr``: a building from one photograph and
its outline (Nishida et al. 2018): the mass and the camera fitted to the outline
(:mod:`.mass_fit`), the largest visible façade rectified (:mod:`.rectify`) and parsed
(:mod:`.facade`), and all of it written as one grammar of the stdlib's vocabulary.

The masses see the street face and the right-hand side (the camera's ``phi_y`` is positive), so
an outline is fitted as given and mirrored, and the better of the two kept: a mirrored fit is a
photograph that shows the left-hand side, whose façade is read from the mirrored photograph.
A silhouette fixes a building only up to scale; the scale comes from the façade's floors, each
``--floor-height`` metres high.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from bgr.grammar.errors import BgrError, Diagnostic, terminal_text

from .camera import PhotoCamera
from .facade import FacadeParse, parse_facade
from .mass_fit import MassFit, estimate, refine, refine_camera
from .masses import METRIC, Family, attr_lines
from .outline import Target

FIT_SIDE = 160  # the longer side of the image the mass is fitted in, pixels
CANDIDATES = 3  # (family, orientation) pairs refined, the network's likeliest
EVALUATIONS = 300  # distance evaluations of the whole refinement
ROUNDS = 2  # whole refinements of the winner: a restart leaves the first's pixel plateaus
CLEARLY = 0.8  # the other family replaces the likeliest when its distance is below this share


@dataclass
class PhotoFit:
    """What the photograph stage found: the mass and camera, whether the photograph was
    mirrored to fit it, the metres per model unit, and the façade's parse."""

    mass: MassFit
    mirrored: bool
    scale: float
    parse: FacadeParse | None
    facade_size: tuple[float, float]  # the rectified façade's width and height, model units
    window: str = "Plain"  # the stdlib window rule voted on the façade's windows
    style: tuple[str, dict[str, float]] | None = None  # the façade rule and its fitted values


def fitting_size(width: int, height: int) -> tuple[int, int]:
    k = FIT_SIDE / max(width, height)
    return max(8, round(width * k)), max(8, round(height * k))


def fit_mass(
    mask: np.ndarray, progress=None, network_mask: np.ndarray | None = None
) -> tuple[MassFit, bool]:
    """The best mass and camera for a silhouette mask (already at the fitting size), and
    whether it was found on the mirrored silhouette.  ``network_mask`` is the same silhouette
    at a finer size for the network, which was trained on silhouettes drawn at
    ``mass_fit.CANVAS`` (on the fitting size's coarser ones its family top-1 falls from 0.75
    to 0.67: docs/inverse-image.md)."""
    network_mask = mask if network_mask is None else network_mask
    options = []
    for mirrored in (False, True):
        seen = network_mask[:, ::-1] if mirrored else network_mask
        for guess in estimate(seen, top=CANDIDATES):
            options.append((guess, mirrored))
    # the network's likeliest guesses of both orientations, their cameras refined
    targets = {m: Target(mask[:, ::-1] if m else mask) for m in (False, True)}
    ranked = sorted(options, key=lambda o: -o[0].probability)[:CANDIDATES]
    tried = []
    for guess, mirrored in ranked:
        fit = refine_camera(guess, targets[mirrored])
        tried.append((fit, mirrored))
        if progress:
            side = "mirrored" if mirrored else "as given"
            progress(
                f"  {guess.family.rule} ({side}, p {guess.probability:.2f}): camera fitted, "
                f"distance {fit.distance:.2f} px"
            )
    # the likeliest and the closest other (by its camera alone) both refined whole; the
    # likeliest kept unless the other ends clearly closer (a flexible wrong family fits better
    # than the right one with the network's rough parameters: the closer alone loses family
    # accuracy), then refined again from where it stopped: COBYQA's fresh trust region leaves
    # the rasterised distance's plateaus (docs/inverse-image.md has each step measured)
    others = sorted(tried[1:], key=lambda t: t[0].distance)[:1]
    done = [(refine(fit, targets[m], EVALUATIONS), m) for fit, m in [tried[0], *others]]
    best, mirrored = done[0]
    if len(done) > 1 and done[1][0].distance < CLEARLY * best.distance:
        best, mirrored = done[1]
    for _ in range(ROUNDS - 1):
        again = refine(best, targets[mirrored], EVALUATIONS)
        spent = best.evaluations + again.evaluations
        best = replace(again if again.distance < best.distance else best, evaluations=spent)
    return best, mirrored


def facade_quads(fit: MassFit, width: int, height: int) -> list[tuple[float, np.ndarray, tuple]]:
    """(projected area, quad (top-left, top-right, bottom-right, bottom-left) in pixels, (width,
    height) in model units) of each side face of the mass that faces the camera, largest
    first."""
    from .masses import side_faces

    camera = fit.photo_camera
    eye = camera.position()
    out = []
    for origin, axes, size in side_faces(fit.family, fit.values):
        x, y, normal = axes
        corners = np.array(
            [origin + y * size[1], origin + x * size[0] + y * size[1], origin + x * size[0], origin]
        )
        centre = corners.mean(axis=0)
        if np.dot(normal, eye - centre) <= 0:
            continue
        pixels, front = camera.project(corners, width, height)
        if not front.all():
            continue
        px, py = pixels[:, 0], pixels[:, 1]
        area = 0.5 * (np.dot(px, np.roll(py, -1)) - np.dot(py, np.roll(px, -1)))
        if area < 0:  # the face's x runs leftwards in the photograph: read it left to right
            pixels = pixels[[1, 0, 3, 2]]
        out.append((float(abs(area)), pixels, (float(size[0]), float(size[1]))))
    return sorted(out, key=lambda item: -item[0])


def read_facade(rgb: np.ndarray, fit: MassFit, mirrored: bool, progress=None):
    """The largest visible façade rectified and parsed: (parse or None, its size in model
    units, the rectified image or None).  None when no face is visible or the rectification
    fails (the grammar then keeps the stdlib's default façade)."""
    from .rectify import rectify_facade, refine_quad

    height, width = rgb.shape[:2]
    photo = rgb[:, ::-1] if mirrored else rgb
    for _area, quad, size in facade_quads(fit, width, height)[:1]:
        try:
            # the quad's edges turned onto the façade's vanishing points (section 5.1)
            refined = refine_quad(photo, quad)
            if progress:
                progress(f"  façade quad: {refined.note}")
            rect = rectify_facade(photo, refined.quad, size)
        except ValueError as exc:
            if progress:
                progress(f"  façade not rectified: {exc}")
            return None, size, None
        image = rect.image[:, ::-1] if mirrored else rect.image
        if progress:
            progress(
                f"  rectified {size[0]:.1f} x {size[1]:.1f} units to "
                f"{image.shape[1]}x{image.shape[0]} px"
            )
        return parse_facade(image), size, image
    return None, (0.0, 0.0), None


def fit_photo(
    rgb: np.ndarray, mask_full: np.ndarray, floor_height: float, progress=None
) -> PhotoFit:
    """Every stage on one photograph (``rgb``) and its outline mask at the photo's size."""
    height, width = rgb.shape[:2]
    small = fitting_size(width, height)
    from PIL import Image

    mask = np.asarray(Image.fromarray(mask_full).resize(small, Image.Resampling.NEAREST))
    start = time.perf_counter()
    fit, mirrored = fit_mass(mask, progress, network_mask=mask_full)
    if progress:
        progress(
            f"mass: {fit.family.rule}{' (mirrored)' if mirrored else ''}, distance "
            f"{fit.distance:.2f} px, {time.perf_counter() - start:.1f} s"
        )
    start = time.perf_counter()
    parse, size, image = read_facade(rgb, fit, mirrored, progress)
    window = "Plain"
    votes: dict[str, int] = {}
    if parse is not None and image is not None and len(parse.windows):
        from .windows import window_style

        window, votes = window_style(image, parse.windows)
    scale = 1.0
    if parse is not None and len(parse.floors) >= 1 and size[1] > 0:
        # the façade's floors are floor_height metres apart
        units_per_floor = size[1] / max(1, len(parse.floors))
        scale = floor_height / units_per_floor
    from .facade_style import describe, facade_style

    style = None
    rule = "Grid"
    proba: dict[str, float] = {}
    if parse is not None and image is not None and len(parse.windows):
        rule, values, proba = facade_style(parse, image, floor_height)
        style = (rule, values)
    if progress:
        floors = len(parse.floors) if parse is not None else 0
        progress(
            f"façade: {floors} floors, {describe(rule, proba)}, windows win.{window} "
            f"({votes.get(window, 0)} of {sum(votes.values())} votes), scale {scale:.2f} m per "
            f"unit, {time.perf_counter() - start:.1f} s"
        )
    return PhotoFit(fit, mirrored, scale, parse, size, window, style)


def photo_grammar(result: PhotoFit, source: str, floor_height: float) -> str:
    """The fit as one grammar: the mass's parameters and the façade's as attrs, the mass rule
    of stdlib.mass with the stdlib façade recognised on the photograph (:mod:`.facade_style`,
    fac.Grid when unsure or without a parse) on every side."""
    from bgr.grammar.formatter import format_source

    from .command import grid_values

    family: Family = result.mass.family
    values = dict(result.mass.values)
    for name in values:
        if name in METRIC:
            values[name] *= result.scale
    lines = [
        f"# {_comment(Path(source).name)}: a building fitted by bgr infer --kind image:",
        f"# mass {family.rule}{' (seen mirrored)' if result.mirrored else ''}, "
        f"silhouette distance {result.mass.distance:.2f} px",
        "version 1",
        "",
        "import stdlib.mass as mass",
        "import stdlib.facade as fac",
        "import stdlib.window as win",
        "",
        *attr_lines(family, values),
    ]
    facade = "fac.Grid"
    if result.parse is not None and len(result.parse.windows):
        from .facade_style import facade_call

        rule, values = result.style or ("Grid", grid_values(result.parse, floor_height))
        attrs, call = facade_call(rule, values, result.parse.color, result.window)
        lines += attrs
        facade = "Facade"
    lines += ["", f"Lot --> {family.call(facade)}"]
    if facade == "Facade":
        lines.append(f"Facade --> {call}")
    return format_source("\n".join(lines) + "\n")


def render_camera(result: PhotoFit, width: int, height: int, lot: tuple[float, float]):
    """The fitted camera as the renderer's :class:`~bgr.render.camera.Camera` in the frame of
    ``bgr derive``'s output (the mass centred on a ``lot``, scaled to metres), so that
    ``bgr render b.bgr --view b.camera.json`` shows the photograph's view."""
    from bgr.render.camera import Camera

    camera: PhotoCamera = result.mass.photo_camera
    rotation = camera.rotation()
    if result.mirrored:  # the view of the mirrored building, mirrored back
        rotation = np.diag([-1.0, 1.0, 1.0]) @ rotation @ np.diag([-1.0, 1.0, 1.0])
    position = camera.position() * result.scale
    if result.mirrored:
        position[0] = -position[0]
    position = position + np.array([lot[0] / 2, 0.0, lot[1] / 2])
    # bgr's renderer looks down its -z with y up: flip the paper's y-down, z-forward frame
    flip = np.diag([1.0, -1.0, -1.0])
    c_x = -camera.c_x if result.mirrored else camera.c_x
    return Camera(camera.fov, flip @ rotation, position, (c_x, -camera.c_y), (width, height))


def _comment(text: str) -> str:
    return terminal_text(text, keep="").replace("\n", " ")


def _need(path: str | None, what: str) -> str:
    if not path:
        raise BgrError(
            Diagnostic(
                "", 0, 0, f"--kind image needs {what}", "give --silhouette SIL.json or a mask PNG"
            )
        )
    return path


def run_image(args) -> int:
    """The command: read, fit, write the grammar, its camera and (with --preview) a picture."""
    import json

    from bgr.formats.atomic import write_text
    from bgr.grammar.paths import check_output

    from .command import read_photo
    from .silhouette import read_silhouette

    if not args.floor_height > 0 or not np.isfinite(args.floor_height):
        print("bgr infer: --floor-height must be a positive number of metres", file=sys.stderr)
        return 2
    for target in (args.output, args.preview):
        if target not in (None, "-"):
            check_output(target)
    sil_path = _need(args.silhouette, "the building's outline")
    rgb = read_photo(args.input)
    height, width = rgb.shape[:2]
    outline = read_silhouette(sil_path, (width, height))

    def progress(line: str) -> None:
        print(f"bgr infer: {line}", file=sys.stderr, flush=True)

    progress(f"{terminal_text(args.input, keep='')}: {width}x{height}, fitting the mass")
    result = fit_photo(rgb, outline.mask(width, height), args.floor_height, progress)
    text = photo_grammar(result, args.input, args.floor_height)
    lot = _lot(result)
    camera = render_camera(result, width, height, lot)
    if args.output in (None, "-"):
        sys.stdout.write(text)
    else:
        write_text(Path(args.output), text)
        sidecar = Path(args.output).with_suffix(".camera.json")
        write_text(sidecar, json.dumps(camera.to_dict(), indent=1) + "\n")
        progress(f"wrote {args.output} and its camera {sidecar}")
    if args.preview:
        from .preview import save_preview

        score = save_preview(text, camera, rgb, outline.mask(width, height), Path(args.preview))
        progress(f"preview {args.preview}: silhouette IoU {score:.3f} with the outline")
    return 0


def _lot(result: PhotoFit) -> tuple[float, float]:
    """The lot ``bgr derive`` gives a grammar without --lot (20 x 20 m): the mass is centred
    on it."""
    return (20.0, 20.0)
