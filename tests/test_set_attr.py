"""set(attribute, value), as CGA's set(): a shape and every shape derived from it read the new
value of the attr, the rest of the lot the old one (operations/attributes.py)."""

import pytest

import bgr


def sizes(source: str, lot=(20, 10)) -> list[tuple[str, list[float]]]:
    table = bgr.derive(source, lot=lot).terminals.freeze()
    return [(table.label[i], [float(v) for v in table.size[i]]) for i in range(len(table))]


def test_a_set_value_reaches_the_shapes_derived_after_it_and_no_others():
    got = sizes(
        "attr floors = 4\n"
        "attr storeys = floors * 2\n"
        "Lot --> split(x) { ~1: Left | ~1: Right }\n"
        "Left --> set(floors, 2) Mass\n"
        "Right --> Mass\n"
        "Mass --> s('1, floors * 3, '1) [ s(storeys, 1, 1) Storeys ] Box\n"
        "terminal Box, Storeys\n"
    )
    # the left half was given 2 floors; an attr computed from floors keeps its value (as CGA)
    assert got == [
        ("Storeys", [8.0, 1.0, 1.0]),
        ("Box", [10.0, 6.0, 10.0]),
        ("Storeys", [8.0, 1.0, 1.0]),
        ("Box", [10.0, 12.0, 10.0]),
    ]


def test_inside_brackets_a_set_stays_with_the_copy():
    got = sizes(
        "attr h = 1\n"
        "Lot --> [ set(h, 5) A ] B\n"
        "A --> s(h, 1, 1) X\n"
        "B --> s(h, 1, 1) Y\n"
        "terminal X, Y\n"
    )
    assert got == [("X", [5.0, 1.0, 1.0]), ("Y", [1.0, 1.0, 1.0])]


def test_the_candler_pattern_a_flag_per_face():
    """Candler's rule sets onStreet per comp face; the façade below reads it."""
    got = sizes(
        "attr onStreet = false\n"
        "Lot --> extrude(6) comp(f) { front: set(onStreet, true) Facade "
        "| side: Facade | top: NIL | bottom: NIL }\n"
        "Facade --> case onStreet: Shop | else: Wall\n"
        "terminal Shop, Wall\n"
    )
    assert [label for label, _ in got] == ["Shop", "Wall", "Wall", "Wall"]


def test_a_set_inside_a_repeated_subtree_is_the_same_derived_or_replayed(monkeypatch):
    source = (
        "attr w = 2\n"
        "Lot --> extrude(12) comp(f) { side: Facade }\n"
        "Facade --> split(y) { 3: Floor }*\n"
        "Floor --> set(w, split.index + 1) split(x) { ~w: Tile }*\n"
        "Tile --> s(w, '1, '1) T\n"
        "terminal T\n"
    )
    with_reuse = bgr.derive(source, lot=(20, 10)).terminals.freeze()
    monkeypatch.setattr("bgr.interpreter.engine.REUSE", False)
    without = bgr.derive(source, lot=(20, 10)).terminals.freeze()
    assert len(with_reuse) == len(without)
    assert (with_reuse.size == without.size).all() and (with_reuse.origin == without.origin).all()
    assert sorted({float(v) for v in with_reuse.size[:, 0]}) == [1.0, 2.0, 3.0, 4.0]


@pytest.mark.parametrize(
    ("source", "message"),
    [
        ("attr height = 1\nLot --> set(heigt, 2) A\nterminal A\n", "unknown attr 'heigt'"),
        ("const k = 1\nLot --> set(k, 2) A\nterminal A\n", "'k' is a const"),
        ('attr a = 1\nLot --> set("a", 2) A\nterminal A\n', "name it bare"),
        ("attr a = 1\nLot --> set(a) A\nterminal A\n", "'set' takes"),
    ],
)
def test_a_wrong_set_is_a_check_error(source, message):
    with pytest.raises(bgr.BgrCheckError, match=message) as info:
        bgr.load(source)
    assert info.value.diagnostics[0].line == 2 or "const" in message


def test_a_rule_is_not_a_value_to_set():
    source = "attr a = 1\nLot --> P(x = A)\nP(x) --> set(a, x) A\nterminal A\n"
    with pytest.raises(bgr.BgrError, match="not the rule 'A'"):
        bgr.derive(source)
