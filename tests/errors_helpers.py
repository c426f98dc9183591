"""Shared helpers of the bad-input tests: the first error of a source and its checks."""

from __future__ import annotations

import pytest

import bgr


def first_error(src) -> bgr.BgrError:
    with pytest.raises(bgr.BgrError) as e:
        bgr.load(src)
    return e.value


def check(src, line: int, column: int, message: str, hint: str | None = None) -> bgr.BgrError:
    """The first diagnostic is at (line, column), says ``message`` and hints ``hint``."""
    err = first_error(src)
    assert (err.line, err.column) == (line, column), err.render()
    assert message in err.message, err.render()
    if hint is not None:
        assert err.hint is not None and hint in err.hint, err.render()
    # the error's own fields are those of its first diagnostic
    first = err.diagnostics[0]
    assert (first.line, first.column, first.message) == (err.line, err.column, err.message)
    return err


def bug(reason: str):
    return pytest.mark.xfail(reason=reason, strict=True)
