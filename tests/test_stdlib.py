"""The standard library (issue 4): the family counts of the single-image paper (30 masses,
16 façades, 31 windows and entrances), a doc comment for every public rule, and every public rule
derived with 5 seeds on 3 sizes to a non-empty, finite mesh."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT

import bgr
from bgr.grammar.docstrings import rule_docs

STDLIB = ROOT / "stdlib"
SEEDS = range(5)


def module(name: str):
    path = STDLIB / f"{name}.bgr"
    return bgr.load(path.read_text(encoding="utf-8"), path=path)


def public(grammar) -> list[str]:
    return [name for name in grammar.rules if not name.startswith("_")]


@pytest.fixture(scope="module")
def modules():
    return {name: module(name) for name in ("mass", "facade", "window", "roof")}


# ---- counts and documentation ----------------------------------------------------------------


def test_family_counts_follow_the_paper(modules):
    """Figure 3: 30 masses; Figure 5: 16 façades; Figure 6: 31 windows, 6 of them entrances."""
    assert len(public(modules["mass"])) == 30
    assert len(public(modules["facade"])) == 16
    windows = public(modules["window"])
    assert len(windows) == 31
    assert len([w for w in windows if w.endswith("Entrance")]) == 6
    assert len(public(modules["roof"])) >= 6


@pytest.mark.parametrize("name", ["mass", "facade", "window", "roof", "palette", "textured"])
def test_every_public_rule_is_documented_with_every_parameter(name):
    grammar = module(name)
    docs = rule_docs(grammar.module)
    for rule_name in public(grammar):
        rule = grammar.rules[rule_name]
        assert rule_name in docs, f"{name}.bgr: rule {rule_name} has no doc comment"
        doc = docs[rule_name]
        assert doc.named and doc.summary, (
            f"{name}.bgr: {rule_name}'s doc must start '# {rule_name}: ...'"
        )
        assert list(doc.params) == rule.params, (
            f"{name}.bgr: {rule_name} documents {list(doc.params)}"
        )
        missing = [p for i, p in enumerate(rule.params) if rule.default(i) is None]
        assert not missing, f"{name}.bgr: {rule_name} has parameters without defaults: {missing}"


# ---- every rule derives ----------------------------------------------------------------------


def _wrapper(mod: str, names: list[str]) -> bgr.Grammar:
    """One start rule per public rule of ``mod``, applying it to the front face of a W x H wall."""
    lines = [f"import stdlib.{mod} as lib", "attr W = 1", "attr H = 1"]
    lines += [
        f"T_{n} --> s(W, 0, 1) extrude(H) comp(f) {{ front: lib.{n} | all: NIL }}" for n in names
    ]
    return bgr.load("\n".join(lines) + "\n", path=ROOT / "tests" / f"_{mod}_wrapper.bgr")


def _assert_mesh(result, what: str) -> None:
    mesh = result.mesh
    assert len(result.terminals) > 0 and len(mesh.faces) > 0, f"{what}: empty"
    assert np.isfinite(mesh.vertices).all(), f"{what}: non-finite vertices"
    assert (np.ptp(mesh.vertices, axis=0) < 1e4).all(), f"{what}: geometry flies off"


WALLS = {"facade": [(5, 4), (14, 11), (32, 30)], "window": [(0.6, 0.9), (1.2, 1.6), (2.5, 3.2)]}


@pytest.mark.parametrize(
    "seeds_on_largest",
    [pytest.param([0], id="some"), pytest.param(list(SEEDS), id="all", marks=pytest.mark.slow)],
)
@pytest.mark.parametrize("mod", ["facade", "window"])
def test_every_facade_and_window_derives_on_three_sizes_and_five_seeds(
    modules, mod, seeds_on_largest
):
    """Five seeds on the two smaller walls; on the largest one seed in the default run, five
    with `pytest -m slow`."""
    names = public(modules[mod])
    grammar = _wrapper(mod, names)
    for name in names:
        for w, h in WALLS[mod]:
            for seed in seeds_on_largest if (w, h) == WALLS[mod][-1] else SEEDS:
                result = bgr.derive(grammar, seed=seed, attrs={"W": w, "H": h}, start=f"T_{name}")
                _assert_mesh(result, f"{mod}.{name} on {w} x {h} m, seed {seed}")


def _chunks(names: list[str], size: int) -> list[list[str]]:
    return [names[i : i + size] for i in range(0, len(names), size)]


# the 30 masses in six tests of five, so that the suite's processes share them out
MASS_CHUNKS = _chunks(public(module("mass")), 5)


# the default run derives each mass with five seeds on the middle lot and one on the others;
# `pytest -m slow` every seed on every lot
SWEEPS = [
    pytest.param({(8, 6): [0], (20, 15): list(SEEDS), (45, 30): [0]}, id="some"),
    pytest.param(
        {lot: list(SEEDS) for lot in [(8, 6), (20, 15), (45, 30)]}, id="all", marks=pytest.mark.slow
    ),
]


@pytest.mark.parametrize("sweep", SWEEPS)
@pytest.mark.parametrize("names", MASS_CHUNKS, ids=[c[0] for c in MASS_CHUNKS])
def test_every_mass_derives_on_three_lots_and_five_seeds(modules, names, sweep):
    grammar = modules["mass"]
    for name in names:
        for lot, seeds in sweep.items():
            for seed in seeds:
                result = bgr.derive(grammar, seed=seed, lot=lot, start=name)
                _assert_mesh(result, f"mass.{name} on a {lot} lot, seed {seed}")
                lo, hi = result.mesh.bounds
                assert hi[1] > 2.5, f"mass.{name} on {lot}: lower than a storey"


def test_every_roof_assembly_derives_on_three_tops_and_five_seeds(modules):
    names = public(modules["roof"])
    lines = ["import stdlib.roof as rf"]
    lines += [f"T_{n} --> extrude(6) comp(f) {{ top: rf.{n} | all: NIL }}" for n in names]
    grammar = bgr.load("\n".join(lines) + "\n", path=ROOT / "tests" / "_roof_wrapper.bgr")
    for name in names:
        for lot in [(8, 6), (20, 15), (45, 30)]:
            for seed in SEEDS:
                result = bgr.derive(grammar, seed=seed, lot=lot, start=f"T_{name}")
                _assert_mesh(result, f"roof.{name} on a {lot} top, seed {seed}")
                assert result.mesh.bounds[1][1] >= 6 - 1e-6, f"roof.{name} is not on the top face"


# ---- composing the parts ---------------------------------------------------------------------

COMPOSED = """\
# An L-shaped block with hip roof, arched windows above shops, in eight lines.
import stdlib.mass as mass
import stdlib.facade as fac
import stdlib.window as win

Lot --> mass.LHip(facade = Upper, front = Street)
Upper --> fac.Grid(window = win.Arched, tile_w = 3.5)
Street --> fac.Shopfront(window = win.Arched, ground = win.Shop)
"""


def test_mass_facade_and_window_compose_in_under_fifteen_lines(tmp_path):
    assert len(COMPOSED.splitlines()) < 15
    path = tmp_path / "composed.bgr"
    path.write_text(COMPOSED)
    grammar = bgr.load(COMPOSED, path=path)
    result = bgr.derive(grammar, seed=1, lot=(24, 18))
    _assert_mesh(result, "composed")
    labels = set(result.terminals.label)
    assert {"Wall", "Glass"} <= labels
    paths = result.terminals.path
    # the arched window the composition asked for is applied on the façades
    assert any("Arched" in p for p in paths)
    # the same grammar through the CLI
    out = tmp_path / "composed.glb"
    from bgr.cli import main

    assert main(["derive", str(path), "--seed", "1", "-o", str(out)]) == 0
    assert out.stat().st_size > 1000


# ---- bands and cornices at the corners ---------------------------------------------------------


def _corner_overruns(result, footprint, prefix: str = "") -> list[str]:
    """Façade bands and cornices of a building on a convex ``footprint`` ((x, z) world points)
    that go past a corner further than the corner's bisector: out of a side wall by more than out
    of their own wall.  A bar's wall is the footprint edge it stands furthest out of."""
    from bgr.interpreter.terminals import world_vertices

    pts = np.asarray(footprint, dtype=float)
    nxt = np.roll(pts, -1, axis=0)
    if (pts[:, 0] * nxt[:, 1] - nxt[:, 0] * pts[:, 1]).sum() < 0:  # counter-clockwise in (x, z)
        pts = pts[::-1]
    edges = np.roll(pts, -1, axis=0) - pts
    normals = np.stack([edges[:, 1], -edges[:, 0]], axis=1)  # outward
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    t = result.terminals
    bad = []
    for row, (label, path) in enumerate(zip(t.label, t.path, strict=True)):
        if label not in ("Cornice", "Trim") or "/_Face." not in path or not path.startswith(prefix):
            continue
        mesh = t.library.meshes[t.mesh[row]]
        xz = world_vertices(t, np.array([row]), mesh)[0][:, [0, 2]]
        out = np.einsum("ej,vj->ve", normals, xz) - np.einsum("ej,ej->e", normals, pts)
        own = int(np.argmax(out.mean(axis=0)))
        past = (out - out[:, [own]]).max()
        if past > 1e-6 or out[:, own].max() > 0.6:
            bad.append(f"{path}: {past:.2f} m past a corner, {out[:, own].max():.2f} m out")
    return bad


def test_street_gable_cornice_ends_at_the_corners():
    """The red gable house of examples/stdlib_street.bgr (lot 3 of block.geojson, seed 5): its
    street façade's cornice stood 0.45 m out past the gable walls, which have none."""
    import json

    lots = json.loads((ROOT / "examples" / "block.geojson").read_text(encoding="utf-8"))
    ring = lots["features"][2]["geometry"]["coordinates"][0][:-1]
    result = bgr.derive(
        bgr.load(ROOT / "examples" / "stdlib_street.bgr"),
        seed=5,
        lot=str(ROOT / "examples" / "block.geojson"),
    )
    house = "Lot.2/GableHouse."
    t = result.terminals
    cornices = [
        p
        for p, lab in zip(t.path, t.label, strict=True)
        if p.startswith(house) and lab == "Cornice"
    ]
    assert len(cornices) >= 2, "the street façade has no cornice any more"
    assert _corner_overruns(result, [(x, -y) for x, y in ring], house) == []


@pytest.mark.parametrize("facade", ["Attic", "Tripartite", "Palazzo"])
def test_bands_meet_round_every_corner_of_a_block(tmp_path, facade):
    """The same façade all round a five-sided block: each band is mitred at every corner."""
    ring = [(0, 0), (14, 0), (17, 8), (9, 13), (0, 10)]
    lot = tmp_path / "lot.geojson"
    lot.write_text(
        '{"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", '
        f'"coordinates": [{[list(p) for p in ring + ring[:1]]}]}}}}'
    )
    src = (
        "import stdlib.mass as mass\nimport stdlib.facade as fac\n"
        f"Lot --> mass.Block(h = 12, facade = fac.{facade})\n"
    )
    result = bgr.derive(bgr.load(src, path=tmp_path / "b.bgr"), seed=1, lot=str(lot))
    assert "Cornice" in result.terminals.label or "Trim" in result.terminals.label
    assert _corner_overruns(result, [(x, -y) for x, y in ring]) == []


# ---- the generated reference -----------------------------------------------------------------


def test_stdlib_reference_is_current_and_every_thumbnail_exists():
    """docs/stdlib.md is generated (python -m bgr.grammar.stdlib_reference); thumbnails by
    docs/make_gallery.py.  Rerun both after changing a stdlib rule or its doc comment."""
    import re

    from bgr.grammar.stdlib_reference import stdlib_markdown

    text = (ROOT / "docs" / "stdlib.md").read_text(encoding="utf-8")
    assert text == stdlib_markdown(), "docs/stdlib.md is stale: run python docs/make_gallery.py"
    images = re.findall(r"\]\((img/[^)]+\.png)\)", text)
    assert len(images) >= 30 + 16 + 31 + 6 + 1
    missing = [i for i in images if not (ROOT / "docs" / i).is_file()]
    assert not missing, f"thumbnails missing (run python docs/make_gallery.py): {missing[:5]}"


def test_reference_example_derives():
    """The composition example at the top of docs/stdlib.md is a working grammar."""
    import re

    text = (ROOT / "docs" / "stdlib.md").read_text(encoding="utf-8")
    src = re.search(r"```bgr\n(.*?)```", text, re.S).group(1)
    result = bgr.derive(bgr.load(src), seed=0, lot=(20, 14))
    _assert_mesh(result, "the docs/stdlib.md example")
