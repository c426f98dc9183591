"""polygon(x1, z1, ...): a footprint written as its corners (how inferred cities write theirs)."""

import numpy as np
import pytest
import trimesh

import bgr
from bgr.formats.meshes import bake
from bgr.grammar.errors import BgrError

L_SHAPE = "0, 0, 12, 0, 12, 8, 5, 8, 5, 14, 0, 14"  # 12 x 8 + 5 x 6 = 126 m2
L_AREA = 126.0


def derived(src: str) -> trimesh.Trimesh:
    baked = bake(bgr.derive(bgr.load(src)).terminals)
    mesh = trimesh.Trimesh(baked.vertices, baked.faces, process=False)
    mesh.merge_vertices()  # a terminal a face: shared corners are written once a face
    return mesh


def test_an_extruded_polygon_is_a_closed_prism_of_its_outline():
    mesh = derived(f"Lot --> polygon({L_SHAPE}) extrude(9)")
    assert mesh.is_watertight
    assert mesh.volume == pytest.approx(L_AREA * 9)
    assert mesh.bounds.ravel().tolist() == pytest.approx([0, 0, 0, 12, 9, 14])


def test_a_clockwise_polygon_makes_the_same_prism_facing_out():
    corners = np.array([float(c) for c in L_SHAPE.split(",")]).reshape(-1, 2)[::-1].ravel()
    mesh = derived(f"Lot --> polygon({', '.join(f'{c:g}' for c in corners)}) extrude(9)")
    assert mesh.volume == pytest.approx(L_AREA * 9)  # positive: the faces point outwards
    top = mesh.face_normals[:, 1] > 0.99
    assert mesh.area_faces[top].sum() == pytest.approx(L_AREA)


def test_the_corners_are_in_the_scope_frame_and_the_scope_fits_them():
    src = "Lot --> t(3, 0, 2) r(0, 90, 0) polygon(1, 1, 5, 1, 5, 3, 1, 3) extrude(2)"
    result = bgr.derive(bgr.load(src)).terminals
    assert result.size[0].tolist() == pytest.approx([4, 2, 2])
    # r(0, 90, 0): the scope's x runs along world -z, its z along world +x
    assert result.origin[0].tolist() == pytest.approx([3 + 1, 0, 2 - 1])
    mesh = derived(src)
    assert mesh.bounds.ravel().tolist() == pytest.approx([4, 0, -3, 6, 2, 1])


def test_comp_finds_the_walls_and_caps_of_an_extruded_polygon():
    src = (
        f"Lot --> polygon({L_SHAPE}) extrude(9) comp(f) {{ side: Wall | bottom: Floor }}\n"
        "terminal Wall, Floor"
    )
    table = bgr.derive(bgr.load(src)).terminals
    labels = [table.label[i] for i in range(len(table))]
    assert labels.count("Wall") == 6 and labels.count("Floor") == 1


@pytest.mark.parametrize(
    ("call", "message"),
    [
        ("polygon(0, 0, 1, 0, 1, 1, 0)", "x, z pairs"),
        ("polygon(0, 0, 1, 1, 2, 2)", "non-zero area"),
        ("polygon(0, 0, 4, 0, 1, 3, 3, 3)", "cross"),
        ('polygon(0, 0, 1, 0, "a", 1)', "must be a number"),
    ],
)
def test_a_bad_polygon_is_a_located_error(call, message):
    with pytest.raises(BgrError) as caught:
        bgr.derive(bgr.load(f"Lot --> {call} extrude(3)"))
    assert message in str(caught.value)
    assert str(caught.value).startswith("<text>:1:")  # file, line and column


def test_a_polygon_on_an_upright_face_is_refused():
    with pytest.raises(BgrError, match="horizontal 2D shape"):
        bgr.derive(bgr.load("Lot --> extrude(5) comp(f) { front: polygon(0, 0, 1, 0, 1, 1) }"))


def test_the_checker_counts_a_polygon_s_corners():
    with pytest.raises(BgrError, match="'polygon' takes 6 or more arguments, given 4"):
        bgr.load("Lot --> polygon(0, 0, 1, 1) extrude(3)")
