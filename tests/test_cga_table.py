"""docs/cga.md, CGA's words beside bgr's, is generated from grammar/cga_table.py and the
operation registry, and stays true to both."""

from conftest import ROOT

from bgr.grammar.cga_table import BGR_ONLY, CGA, NOT_YET, SAME, table, usage
from bgr.grammar.registry import BUILTINS, OPERATIONS


def test_docs_cga_md_is_the_generated_table():
    assert (ROOT / "docs" / "cga.md").read_text() == table(), (
        "run: python -m bgr.grammar.cga_table > docs/cga.md"
    )


def test_what_bgr_has_comes_from_the_registry():
    names = [name for name, *_ in CGA]
    assert len(names) == len(set(names))
    for name, status, written, _ in CGA:
        if status == NOT_YET:
            assert not written and not usage(name), f"{name} is in the registry: update its status"
        elif not written:
            assert usage(name), f"{name}: bgr has no operation or function of that name"
        if status == SAME and not written:
            assert name in OPERATIONS or name in BUILTINS


def test_every_operation_and_function_of_bgr_is_placed():
    listed = {name for name, *_ in CGA}
    for name in [*OPERATIONS, *BUILTINS]:
        assert name in listed or name in BGR_ONLY, f"{name}: list it in CGA or in BGR_ONLY"
