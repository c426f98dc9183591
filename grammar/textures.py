"""Texture files: where a grammar's ``texture("...")`` path points, and what the file holds.

A texture path resolves as an asset path does (grammar/paths.py): relative to the folder of the
grammar that names it, and only inside the load's roots (that folder, the stdlib, --allow-path).
The file must be a PNG or a JPEG, the two image types every glTF reader takes; it is checked when
the grammar is checked (a literal path) and again when a derivation first uses it (a computed
one), so a missing or broken image is a located error, never a traceback or a black surface.
"""

from __future__ import annotations

import io
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from .errors import BgrError
from .paths import ALLOW_HINT, check_input, read_input, within

MIME = {"PNG": "image/png", "JPEG": "image/jpeg"}
MAX_IMAGE_BYTES = 64 << 20  # a texture larger than this is a mistake, not a façade


class TextureError(ValueError):
    """Why a texture path cannot be used: ``message`` and ``hint`` for a located Diagnostic."""

    def __init__(self, message: str, hint: str | None = None) -> None:
        super().__init__(message)
        self.message, self.hint = message, hint


@dataclass(frozen=True)
class Image:
    """One texture file, read once: its bytes go into the output as they are."""

    path: str  # resolved, the key that makes each distinct file one image
    data: bytes
    mime: str  # image/png or image/jpeg
    width: int
    height: int
    alpha: bool  # whether it has an alpha channel (then it is the opacity)


def base_folder(module_path: str) -> Path:
    """The folder a module's relative paths start from (the working folder for text)."""
    if module_path in ("<text>", "<stdin>", "<string>") or not module_path:
        return Path.cwd()
    return Path(module_path).parent


def locate(module_path: str, roots: Iterable[Path], text: str, folder: Path | None = None) -> Path:
    """The file a texture path names, resolved (from ``folder``, the module's real folder, when
    given); :class:`TextureError` when it is out of reach."""
    if not isinstance(text, str) or not text or "\0" in text:
        raise TextureError(f"{text!r} is not a texture file name", 'write texture("file.png")')
    path = ((folder or base_folder(module_path)) / text).resolve()
    roots = tuple(roots)
    if roots and not within(path, roots):
        raise TextureError(
            f"texture file '{text[:200]}' is outside the folders this grammar may read",
            ALLOW_HINT,
        )
    return path


def read_image(path: Path, shown: str) -> Image:
    """Read and identify a PNG or JPEG file; :class:`TextureError` says what is wrong."""
    try:
        check_input(path, "texture file")
        if path.stat().st_size > MAX_IMAGE_BYTES:
            raise TextureError(
                f"texture file '{shown[:200]}' is larger than {MAX_IMAGE_BYTES >> 20} MB"
            )
        data = read_input(path, "texture file")
    except BgrError as e:
        raise TextureError(e.message, e.hint) from None
    except FileNotFoundError:
        raise TextureError(
            f"texture file '{shown[:200]}' not found", f"looked for {path}"
        ) from None
    except (OSError, ValueError) as e:
        reason = getattr(e, "strerror", None) or str(e)
        raise TextureError(f"texture file '{shown[:200]}' cannot be read: {reason}") from None
    return decode_image(data, str(path), shown)


def decode_image(data: bytes, key: str, shown: str) -> Image:
    """An :class:`Image` of PNG or JPEG bytes (``key``: what makes it distinct, a resolved path
    or a path and a name inside a model file); :class:`TextureError` for anything else."""
    try:
        from PIL import Image as PILImage

        with PILImage.open(io.BytesIO(data)) as img:
            kind = img.format or ""
            img.load()  # decodes it: a truncated or corrupt file fails here, not in a viewer
            width, height = img.size
            alpha = "A" in img.getbands() or "transparency" in img.info
    except Exception as e:  # any decoder failure is the file's fault
        raise TextureError(
            f"texture file '{shown[:200]}' is not a readable image: {e}",
            "textures are PNG or JPEG files",
        ) from None
    if kind not in MIME:
        raise TextureError(
            f"texture file '{shown[:200]}' is a {kind or 'unknown'} image",
            "textures are PNG or JPEG files (what glTF readers take); convert it",
        )
    return Image(key, data, MIME[kind], int(width), int(height), bool(alpha))


def load(module_path: str, roots: Iterable[Path], text: str, folder: Path | None = None) -> Image:
    """:func:`locate` then :func:`read_image`."""
    return read_image(locate(module_path, roots, text, folder), text)
