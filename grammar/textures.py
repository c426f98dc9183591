"""Texture files: where a grammar's ``texture("...")`` path points, and what the file holds.

A texture path resolves as an asset path does (grammar/paths.py): relative to the folder of the
grammar that names it, and only inside the load's roots (that folder, the stdlib, --allow-path).
The file must be a PNG or a JPEG, the two image types every glTF reader takes; it is checked when
the grammar is checked (a literal path) and again when a derivation first uses it (a computed
one), so a missing or broken image is a located error, never a traceback or a black surface.
"""

from __future__ import annotations

import io
import os
import re
import stat
import threading
from collections import OrderedDict
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from .errors import BgrError
from .paths import ALLOW_HINT, SPECIAL_DIRS, check_input, inside, read_input, resolved

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


def locate(
    module_path: str,
    roots: Iterable[Path],
    text: str,
    folder: Path | None = None,
    folders: dict[str, str] | None = None,
) -> Path:
    """The file a texture path names, resolved (from ``folder``, the module's real folder, when
    given); :class:`TextureError` when it is out of reach.

    ``folders``: resolved folders already seen by the caller (a derivation's, which reads a
    style sheet's 1,300 crops from one folder): a file there that is no symlink itself is the
    resolved folder plus its name, one ``lstat`` instead of ``realpath``'s one per component
    (in os.path's strings: pathlib's objects took as long again)."""
    if not isinstance(text, str) or not text or "\0" in text:
        raise TextureError(f"{text!r} is not a texture file name", 'write texture("file.png")')
    joined = os.path.join(folder or base_folder(module_path), text)
    path = None
    head, name = os.path.split(joined)
    if folders is not None and name not in ("", ".", ".."):
        parent = folders.get(head)
        if parent is None:
            parent = folders[head] = str(resolved(head))
        candidate = os.path.join(parent, name)
        try:
            if not stat.S_ISLNK(os.lstat(candidate).st_mode):
                path = Path(candidate)
        except OSError:
            pass  # missing or unreadable: realpath and the reader say what it is
    if path is None:
        path = resolved(joined)
    roots = tuple(roots)
    if roots and not inside(path, roots):  # resolved once: within() would resolve it again
        raise TextureError(
            f"texture file '{text[:200]}' is outside the folders this grammar may read",
            ALLOW_HINT,
        )
    return path


def read_image(path: Path, shown: str, real: bool = False) -> Image:
    """Read and identify a PNG or JPEG file; :class:`TextureError` says what is wrong.
    ``real``: ``path`` is resolved already (:func:`locate`'s), so not resolved again."""
    try:
        if not real or inside(path, SPECIAL_DIRS):  # /proc, /sys, /dev, FIFOs: before stat
            check_input(path, "texture file", real=real)
        if os.stat(path).st_size > MAX_IMAGE_BYTES:
            raise TextureError(
                f"texture file '{shown[:200]}' is larger than {MAX_IMAGE_BYTES >> 20} MB"
            )
        data = read_input(path, "texture file", real=real)
    except BgrError as e:
        raise TextureError(e.message, e.hint) from None
    except FileNotFoundError:
        raise TextureError(
            f"texture file '{shown[:200]}' not found", f"looked for {path}"
        ) from None
    except (OSError, ValueError) as e:
        reason = getattr(e, "strerror", None) or str(e)
        raise TextureError(f"texture file '{shown[:200]}' cannot be read: {reason}") from None
    return _decoded(data, str(path), shown)


# the images read_image decoded in this process, by resolved path, least recently used first;
# at most DECODED_BYTES of file bytes (a style sheet's crops are a few KB each)
_DECODED: OrderedDict[str, Image] = OrderedDict()
_DECODED_SIZE = [0]
_DECODED_LOCK = threading.Lock()
DECODED_BYTES = 64 << 20


def _decoded(data: bytes, key: str, shown: str) -> Image:
    """:func:`decode_image`, remembered across derivations and loads in this process.

    Why: a style sheet names 1,000-3,000 crop files, and checking the sheet, then each
    derivation with it (``bgr restyle``: one per mass), decoded every one again, 0.5 ms each,
    most of a retargeted generation's time.  The file is still read every time and the cached
    image is used only when its bytes are the same (a file changed on disk, even within one
    mtime tick, is decoded anew); only the decoding, which depends on nothing but the bytes,
    is skipped.  A failure is not remembered."""
    with _DECODED_LOCK:
        known = _DECODED.get(key)
        if known is not None and known.data == data:
            _DECODED.move_to_end(key)
            return known
    image = decode_image(data, key, shown)
    if len(data) > DECODED_BYTES // 16:
        return image
    with _DECODED_LOCK:
        old = _DECODED.pop(key, None)
        if old is not None:
            _DECODED_SIZE[0] -= len(old.data)
        _DECODED[key] = image
        _DECODED_SIZE[0] += len(data)
        while _DECODED_SIZE[0] > DECODED_BYTES:
            _, dropped = _DECODED.popitem(last=False)
            _DECODED_SIZE[0] -= len(dropped.data)
    return image


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


def load(
    module_path: str,
    roots: Iterable[Path],
    text: str,
    folder: Path | None = None,
    folders: dict[str, str] | None = None,
) -> Image:
    """:func:`locate` then :func:`read_image`."""
    return read_image(locate(module_path, roots, text, folder, folders), text, real=True)
