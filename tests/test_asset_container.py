"""Assets as meshes of one glTF file: ``asset a = "meshes.glb#name"`` (issue 29, item 4).

``bgr infer --kind city`` writes every type's mesh into one ``meshes.glb``, a node each; a
grammar inserts one of them by its node name.
"""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

import bgr
from bgr.grammar.errors import BgrError


def _container(path, sizes: dict[str, float]) -> None:
    scene = trimesh.Scene()
    for name, width in sizes.items():
        scene.add_geometry(trimesh.creation.box(extents=[width, 1, 1]), name, name)
    path.write_bytes(scene.export(file_type="glb"))


def _grammar(folder, assets: str, body: str) -> bgr.Grammar:
    source = folder / "g.bgr"
    source.write_text(f"{assets}\nLot --> {body}\n")
    return bgr.load(source)


def test_each_asset_is_its_own_mesh(tmp_path):
    _container(tmp_path / "meshes.glb", {"narrow": 1.0, "wide": 3.0})
    grammar = _grammar(
        tmp_path,
        'asset a = "meshes.glb#narrow"\nasset b = "meshes.glb#wide"',
        "s(0, 0, 0) [ A ] t(10, 0, 0) B\nA --> i(a)\nB --> s(0, 0, 0) i(b)",
    )
    table = bgr.derive(grammar).terminals
    assert len(table) == 2
    assert np.allclose(sorted(table.size[:, 0]), [1.0, 3.0])


def test_an_unknown_mesh_is_a_located_error(tmp_path):
    _container(tmp_path / "meshes.glb", {"narrow": 1.0, "wide": 3.0})
    grammar = _grammar(tmp_path, 'asset a = "meshes.glb#wdie"', "i(a)")
    with pytest.raises(BgrError) as caught:
        bgr.derive(grammar)
    text = str(caught.value)
    assert "meshes.glb has no mesh named 'wdie'" in text
    assert "g.bgr:1:" in text


def test_a_file_named_with_a_hash_is_that_file(tmp_path):
    box = trimesh.creation.box(extents=[2, 1, 1])
    (tmp_path / "a#b.glb").write_bytes(box.export(file_type="glb"))
    grammar = _grammar(tmp_path, 'asset a = "a#b.glb"', "s(0, 0, 0) i(a)")
    assert bgr.derive(grammar).terminals.size[0, 0] == pytest.approx(2.0)
