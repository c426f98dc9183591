"""Texture files read across derivations (issue 27: a retargeted generation under 1 s).

A process decodes each texture file once (grammar/textures.py ``_decoded``), a derivation
resolves a folder of crops once (``locate``'s ``folders``), the terminal table finds an image by
its path in a dict (``TerminalTable.add_image``) and the GLB writer embeds each image once.
What a user relies on: none of that ever shows a file as it was, lets a symlink out of the
grammar's folders, or changes what is written.
"""

from __future__ import annotations

import io
import os
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import bgr
from bgr.grammar import textures
from bgr.interpreter.terminals import TerminalTable

# two pieces, each textured by a file name passed in a parameter: computed paths, read while
# deriving (a literal one is also read when the grammar is checked)
GRAMMAR = """version 1
start Lot
terminal Tile
Lot --> s(2, 0, 1) r(0, 0, 0) extrude(1) comp(f) {{ back: Facade }}
Facade --> split(x) {{ '0.5: Piece("{a}") | '0.5: Piece("{b}") }}
Piece(file) --> setupProjection(0, scope.xy, '1, '1) projectUV(0) texture(file) Tile
"""


def png(path: Path, rgb: tuple[int, int, int], size: tuple[int, int] = (4, 4)) -> bytes:
    """An uncompressed PNG of one colour: its byte size depends on its size only."""
    buffer = io.BytesIO()
    Image.new("RGB", size, rgb).save(buffer, format="PNG", compress_level=0)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(buffer.getvalue())
    return buffer.getvalue()


def derive(folder: Path, a: str, b: str):
    grammar = folder / "t.bgr"
    grammar.write_text(GRAMMAR.format(a=a, b=b))
    return bgr.derive(grammar).terminals.freeze()


def colours(table) -> list[tuple[int, ...]]:
    """The colour of each image of the table, as decoded from the bytes it holds."""
    out = []
    for image in table.images:
        with Image.open(io.BytesIO(image.data)) as img:
            out.append(img.convert("RGB").getpixel((0, 0)))
    return out


def test_a_file_rewritten_with_the_same_size_and_time_is_read_anew(tmp_path):
    crop = tmp_path / "assets" / "crop.png"
    first = png(crop, (255, 0, 0))
    stamp = crop.stat()
    table = derive(tmp_path, "assets/crop.png", "assets/crop.png")
    assert colours(table) == [(255, 0, 0)]
    second = png(crop, (0, 0, 255))
    assert len(second) == len(first) and second != first
    os.utime(crop, ns=(stamp.st_atime_ns, stamp.st_mtime_ns))  # as if within one mtime tick
    assert crop.stat().st_mtime_ns == stamp.st_mtime_ns and crop.stat().st_size == stamp.st_size
    table = derive(tmp_path, "assets/crop.png", "assets/crop.png")
    assert colours(table) == [(0, 0, 255)]
    assert table.images[0].data == second


def test_a_file_broken_after_a_good_read_is_a_located_error(tmp_path):
    crop = tmp_path / "assets" / "crop.png"
    png(crop, (255, 0, 0))
    derive(tmp_path, "assets/crop.png", "assets/crop.png")
    crop.write_bytes(b"\x89PNG\r\n\x1a\n" + b"\0" * 40)
    with pytest.raises(bgr.BgrError) as e:
        derive(tmp_path, "assets/crop.png", "assets/crop.png")
    assert "is not a readable image" in e.value.render()
    assert e.value.line == 6


def test_a_symlink_beside_files_already_read_is_held_to_the_roots(tmp_path):
    outside = tmp_path / "outside"
    png(outside / "secret.png", (0, 255, 0))
    project = tmp_path / "project"
    png(project / "assets" / "crop.png", (255, 0, 0))
    (project / "assets" / "link.png").symlink_to(outside / "secret.png")
    # crop.png first: its folder is resolved and remembered before the link is met
    with pytest.raises(bgr.BgrError) as e:
        derive(project, "assets/crop.png", "assets/link.png")
    assert "outside the folders this grammar may read" in e.value.render()
    # a link inside the roots is the file it points to: one image, stored once
    (project / "assets" / "same.png").symlink_to(project / "assets" / "crop.png")
    table = derive(project, "assets/crop.png", "assets/same.png")
    assert [image.path for image in table.images] == [
        str((project / "assets" / "crop.png").resolve())
    ]
    assert np.array_equal(table.tex_maps[:, 0], [0, 0])


def test_the_cache_keeps_at_most_its_bound(tmp_path, monkeypatch):
    files = [png(tmp_path / f"c{k}.png", (k, 0, 0)) for k in range(45)]
    bound = 40 * len(files[0]) + 1  # 40 files (none over a sixteenth of it, the most one takes)
    monkeypatch.setattr(textures, "DECODED_BYTES", bound)
    monkeypatch.setattr(textures, "_DECODED", type(textures._DECODED)())
    monkeypatch.setattr(textures, "_DECODED_SIZE", [0])
    for k in range(45):
        image = textures.load(str(tmp_path / "t.bgr"), (tmp_path,), f"c{k}.png")
        assert image.width == 4 and image.data == files[k]
    held = textures._DECODED
    assert textures._DECODED_SIZE[0] == sum(len(image.data) for image in held.values()) < bound
    assert list(held) == [str((tmp_path / f"c{k}.png").resolve()) for k in range(5, 45)]
    big = png(tmp_path / "big.png", (9, 9, 9), (64, 64))  # over a sixteenth: decoded, not kept
    assert textures.load(str(tmp_path / "t.bgr"), (tmp_path,), "big.png").data == big
    assert str((tmp_path / "big.png").resolve()) not in held


def test_add_image_numbers_each_path_once_and_follows_a_replaced_list():
    def image(path: str):
        return textures.Image(path, path.encode(), "image/png", 1, 1, False)

    table = TerminalTable()
    assert [table.add_image(image(p)) for p in ("a", "b", "a", "c", "b")] == [0, 1, 0, 2, 1]
    assert [im.path for im in table.images] == ["a", "b", "c"]
    table.images = [image("c"), image("a")]  # shared or replaced by another hand
    assert table.add_image(image("a")) == 1
    table.images.append(image("d"))
    assert table.add_image(image("d")) == 2
    assert table.add_image(image("e")) == 3


def test_two_lots_share_one_embedded_image(tmp_path):
    import json
    import struct

    from bgr.interpreter.lots import footprint

    png(tmp_path / "crop.png", (255, 0, 0))
    grammar = tmp_path / "t.bgr"
    grammar.write_text(GRAMMAR.format(a="crop.png", b="crop.png"))
    out = tmp_path / "t.glb"
    lots = [footprint([(0, 0), (2, 0), (2, -1), (0, -1)]), footprint([(4, 0), (6, 0), (6, -1)])]
    bgr.derive(grammar, lot=lots).save(out)
    data = out.read_bytes()
    (length,) = struct.unpack("<I", data[12:16])
    document = json.loads(data[20 : 20 + length])
    assert len(document["images"]) == 1
    assert len(document["meshes"]) >= 2
