"""``--preview PNG``: the grammar ``bgr infer --kind image`` wrote, derived, rendered with the
fitted camera and laid over the photograph, with the user's outline drawn on top — the picture
that shows at a glance whether the fit holds."""

from __future__ import annotations

from pathlib import Path

import numpy as np

OPACITY = 0.7  # of the rendering over the photograph
OUTLINE = (255, 40, 200)  # the user's outline


def rendered(text: str, camera) -> tuple[np.ndarray, np.ndarray]:
    """(shaded RGB, coverage mask) of a grammar's derivation seen by ``camera``."""
    import bgr
    from bgr.render import images, rasterise
    from bgr.render.scene import load_scene

    scene = load_scene(bgr.derive(bgr.load(text)))
    frame = rasterise(scene, camera, "auto", on_fallback=None)
    return images.shaded(frame, scene), frame.mask


def overlay(photo: np.ndarray, shaded: np.ndarray, covered: np.ndarray, outline: np.ndarray):
    """The rendering blended over the photograph, the outline's boundary on top."""
    from .outline import boundary

    out = photo.astype(np.float32)
    out[covered] = (1 - OPACITY) * out[covered] + OPACITY * shaded[covered]
    edge = boundary(outline)
    thick = edge | np.roll(edge, 1, 0) | np.roll(edge, 1, 1)
    out[thick] = OUTLINE
    return np.clip(out + 0.5, 0, 255).astype(np.uint8)


def save_preview(text: str, camera, photo: np.ndarray, outline: np.ndarray, path: Path) -> float:
    """Write the preview PNG (atomically) and return the rendered model's silhouette IoU with
    the outline."""
    from bgr.render import save_png

    from .outline import iou

    shaded, covered = rendered(text, camera)
    save_png(overlay(photo, shaded, covered, outline), path)
    return iou(covered, outline)
