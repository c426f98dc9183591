"""Texture files: where a grammar's ``texture("...")`` path points, and what the file holds.

A texture path resolves as an asset path does (grammar/paths.py): relative to the folder of the
grammar that names it, and only inside the load's roots (that folder, the stdlib, --allow-path).
The file must be a PNG or a JPEG, the two image types every glTF reader takes; it is checked when
the grammar is checked (a literal path) and again when a derivation first uses it (a computed
one), so a missing or broken image is a located error, never a traceback or a black surface.
"""

from __future__ import annotations

import io
import re
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from .errors import BgrError
from .paths import ALLOW_HINT, check_input, read_input, within

MIME = {"PNG": "image/png", "JPEG": "image/jpeg"}
MAX_IMAGE_BYTES = 64 << 20  # a texture larger than this is a mistake, not a façade
# pixels of one texture image, read from its header before it is decoded: 8192 x 4096.  A PNG
# of 18 KB may claim 12,000 x 12,000 pixels (432 MB as RGB, and the renderer's mipmaps in
# linear light eight bytes a channel on top); below Pillow's own decompression-bomb limit
# (89,478,485, a warning; twice that, an error), so that limit never speaks first
MAX_IMAGE_PIXELS = 8192 * 4096


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
        with open_image(data) as img:
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


def open_image(data: bytes):
    """The Pillow image of ``data``, opened (its header read) but not decoded; ValueError saying
    why when it claims more than MAX_IMAGE_PIXELS pixels.  What Pillow raises for bytes that
    are no image reaches the caller.  Pillow's decompression-bomb warning is silenced here:
    this limit, lower, is the one that holds."""
    import warnings

    from PIL import Image as PILImage

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PILImage.DecompressionBombWarning)
        try:
            img = PILImage.open(io.BytesIO(data))
        except PILImage.DecompressionBombError as exc:  # twice Pillow's limit: its own error
            claimed = re.search(r"\((\d+) pixels\)", str(exc))
            count = f"{int(claimed[1]):,}" if claimed else "more"
            raise ValueError(
                f"it claims {count} pixels, more than {MAX_IMAGE_PIXELS:,} (8192 x 4096)"
            ) from None
    width, height = img.size
    if width * height > MAX_IMAGE_PIXELS:
        img.close()
        raise ValueError(
            f"it claims {width:,} x {height:,} pixels, more than {MAX_IMAGE_PIXELS:,} (8192 x 4096)"
        )
    return img


def load(module_path: str, roots: Iterable[Path], text: str, folder: Path | None = None) -> Image:
    """:func:`locate` then :func:`read_image`."""
    return read_image(locate(module_path, roots, text, folder), text)
