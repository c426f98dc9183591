"""The face schema of Build-by-Number (section 3.2.1), as pure functions on symbols and widths.

A face is a row of columns.  :func:`symbols` names equal columns alike, :func:`rewrite` turns the
column string into a growth rule (``ABCBCBCBA`` -> ``A(BC)*BA``), and :func:`retarget` applies
that rule to a face of another width: how many repetitions each starred pair gets and the scale
of the variable-width columns.  Nothing here knows about geometry or grammar syntax, so the
paper's rules can be tested on their own and against ``interpreter/split_solver.py``, which
implements the same application rule as LANGUAGE.md section 6, rule 3.
"""

from __future__ import annotations

import itertools
import math
import string
from collections import Counter
from collections.abc import Hashable, Sequence
from dataclasses import dataclass

EPS = 1e-9  # slack when flooring the common multiplier (rounding must not lose a repetition)
TIE = 1e-12  # scales closer than this are equally close to 1: rounding is not a preference


@dataclass(frozen=True)
class Sym:
    """One column, standing for itself: ``index`` is its position in the face."""

    index: int


@dataclass(frozen=True)
class Star:
    """A repeated pair ``(XY)*``: the positions of its first instance, and how many adjacent
    instances of the original it replaced (``count`` may be 1, as in derivation 2)."""

    first_index: int
    second_index: int
    count: int


Item = Sym | Star


# ---- the symbolic rule (steps 2-5) -------------------------------------------------------------


def symbols(keys: Sequence[Hashable]) -> list[str]:
    """Step 2: a symbol per column, equal iff the columns' keys are equal.

    Symbols are given in order of first appearance, ``A`` ... ``Z``, then ``A1`` ... ``Z1``,
    ``A2`` ..., so the paper's strings read the same here.  The caller builds the keys from the
    labels of a column's subfaces (recursively, from their own rewrite rules): that is the
    paper's equality relation, and this function only applies it.
    """
    named: dict[Hashable, str] = {}
    for key in keys:
        if key not in named:
            n = len(named)
            named[key] = string.ascii_uppercase[n % 26] + (str(n // 26) if n >= 26 else "")
    return [named[key] for key in keys]


def rewrite(symbols: Sequence[str]) -> list[Item]:
    """Steps 3-5: mark reoccurring pairs ``XY`` (never ``XX``), merge adjacent ones, star them.

    A pair *reoccurs* when it occurs at least twice anywhere in the whole string, counting every
    position, including occurrences that share a symbol with an occurrence of another pair (the
    ``BA`` inside ``ABAB`` counts for ``BA``).  A pair of two different symbols cannot overlap
    itself, so there is no self-overlap to decide.  The scan then goes left to right: a
    reoccurring pair at the scan position is marked and consumes both symbols, anything else
    is a plain symbol.  Because the counts are taken on the whole string, a pair may be marked
    where the scan reaches only one of its occurrences; its star then has count 1, as the
    stars of derivation 2 (``AABAABAA`` -> ``A(AB)*A(AB)*AA``) do.
    """
    n = len(symbols)
    occurs = Counter(
        (symbols[i], symbols[i + 1]) for i in range(n - 1) if symbols[i] != symbols[i + 1]
    )
    items: list[Item] = []
    i = 0
    while i < n:
        pair = (symbols[i], symbols[i + 1]) if i + 1 < n else None
        if pair is None or occurs[pair] < 2:
            items.append(Sym(i))
            i += 1
            continue
        last = items[-1] if items else None
        if (
            isinstance(last, Star)
            and (symbols[last.first_index], symbols[last.second_index]) == pair
        ):
            items[-1] = Star(last.first_index, last.second_index, last.count + 1)  # step 4
        else:
            items.append(Star(i, i + 1, 1))
        i += 2
    return items


def to_text(items: Sequence[Item], symbols: Sequence[str]) -> str:
    """The rule as the paper writes it, e.g. ``A(BC)*BA``."""
    return "".join(
        symbols[it.index]
        if isinstance(it, Sym)
        else f"({symbols[it.first_index]}{symbols[it.second_index]})*"
        for it in items
    )


def stars(items: Sequence[Item]) -> list[Star]:
    """The repeating groups of a rule, in order: the order of every ``counts`` tuple here."""
    return [it for it in items if isinstance(it, Star)]


def expand(items: Sequence[Item], counts: Sequence[int] | None = None) -> list[int]:
    """The column positions a rule lays out, each star repeated ``counts`` times (default: its
    original count).  Mapped through the symbols, the default gives back the rewritten string."""
    reps = iter(counts if counts is not None else [s.count for s in stars(items)])
    out: list[int] = []
    for item in items:
        if isinstance(item, Sym):
            out.append(item.index)
        else:
            out += [item.first_index, item.second_index] * next(reps)
    return out


# ---- applying the rule to a novel face ---------------------------------------------------------


def counts_expressible(counts: Sequence[int]) -> bool:
    """Whether the application rule can produce these counts at all: all are k or k + 1."""
    return not counts or max(counts) - min(counts) <= 1


def unroll(
    items: Sequence[Item],
    counts: Sequence[int] | None = None,
    widths: Sequence[float] | None = None,
) -> list[Item]:
    """Pull repetitions out of stars as plain columns until the star counts are all k or k + 1.

    ``counts`` are the repetitions each star stands for (default: the original ones).  The
    application rule only ever gives counts in {k, k + 1}, so a face with, say, 4 and 2 could
    not come back at its own size.  Every star is kept (each group can still grow), which makes
    k the smallest count; a larger star keeps k + 1 and its other instances follow it as plain
    columns.  Those refer to the first instance's columns, as the star's repetitions do, so
    :func:`expand` is unchanged.

    {k, k + 1} is necessary, not sufficient: at the original size every combination of the same
    nominal width fits exactly (scale 1), whatever its fixed and variable parts, so two stars of
    equal width (typically the same pair either side of a door, with 3 and 2) tie, and the tie
    is broken by order (or by rounding) into (2, 3).  Given the ``widths``, such a tie brings
    every star down to k: all at k is the one combination nothing else can match.
    """
    counts = [s.count for s in stars(items)] if counts is None else list(counts)
    k = min(counts, default=0)
    keep = [min(n, k + 1) for n in counts]
    if widths is not None:
        pair = [widths[s.first_index] + widths[s.second_index] for s in stars(items)]
        width = sum(n * p for n, p in zip(keep, pair, strict=True))
        for extra in itertools.product((0, 1), repeat=len(keep)):
            other = [k + e for e in extra]
            if other != keep and abs(
                sum(n * p for n, p in zip(other, pair, strict=True)) - width
            ) <= EPS * max(1.0, width):
                keep = [k] * len(counts)
                break
    return _pull(items, counts, keep)


def _pull(items: Sequence[Item], counts: Sequence[int], keep: Sequence[int]) -> list[Item]:
    """Each star with ``keep`` repetitions, followed by the rest of its ``counts`` as columns."""
    reps = iter(zip(counts, keep, strict=True))
    out: list[Item] = []
    for item in items:
        if isinstance(item, Sym):
            out.append(item)
            continue
        n, kept = next(reps)
        out.append(Star(item.first_index, item.second_index, kept))
        out += [Sym(item.first_index), Sym(item.second_index)] * (n - kept)
    return out


def retarget(
    items: Sequence[Item],
    widths: Sequence[float],
    fixed: Sequence[bool],
    length: float,
    minimum: int = 0,
) -> tuple[tuple[int, ...], float]:
    """The paper's application rule: repetitions per star (in order) and the variable scale.

    ``widths``/``fixed`` are per column position; a star's repetition has the widths of its
    first instance.  Non-repeating columns count 1.  The common multiplier k is the largest
    that fills the remaining width (at nominal widths) without overflowing, possibly 0; then
    every combination of at most one extra repetition per star is searched and the one whose
    scale s for the variable columns is closest to 1 wins (fixed columns keep their width).
    Ties, which the paper leaves open, go to more repetitions (LANGUAGE.md section 6), then to
    the first combination in enumeration order (extras on later stars first), split_solver's
    order too.

    ``minimum`` raises the floor of k: the paper lets a group vanish (k = 0) where one
    repetition of every group does not fit; the interpreter does too where a variable column
    outside the groups takes the length (as CGA), and keeps at least one otherwise
    (LANGUAGE.md section 6), which ``minimum=1`` computes.

    Where the paper is silent: with no variable column anywhere the scale means nothing, so the
    combination that fills most without overflowing wins (scale 1); when fixed columns alone
    leave no room for variable ones, the counts are k each and the scale is 0.
    """

    def nominal(columns: Sequence[int]) -> tuple[float, float]:
        return (
            sum(widths[c] for c in columns if fixed[c]),
            sum(widths[c] for c in columns if not fixed[c]),
        )

    out_fixed, out_var = nominal([it.index for it in items if isinstance(it, Sym)])
    groups = [nominal((s.first_index, s.second_index)) for s in stars(items)]
    per_rep = sum(a + f for a, f in groups)
    remaining = length - out_fixed - out_var
    k = max(minimum, math.floor(remaining / per_rep + EPS)) if per_rep > 0 else 0
    stretchy = out_var > 0 or any(f > 0 for _, f in groups)

    best: tuple[tuple[int, ...], float, float] | None = None  # counts, scale, distance
    for extra in itertools.product((0, 1), repeat=len(groups)):
        counts = tuple(k + e for e in extra)
        fixed_width = out_fixed + sum(c * a for c, (a, _) in zip(counts, groups, strict=True))
        var_width = out_var + sum(c * f for c, (_, f) in zip(counts, groups, strict=True))
        if stretchy:
            if var_width <= 0 or length - fixed_width <= 0:
                continue  # no variable column to scale, or no room left for them
            scale = (length - fixed_width) / var_width
            distance = abs(scale - 1.0)
        else:
            if fixed_width > length + EPS:
                continue  # overflows
            scale, distance = 1.0, length - fixed_width
        if (
            best is None
            or distance < best[2] - TIE
            or (distance <= best[2] + TIE and sum(counts) > sum(best[0]))
        ):
            best = (counts, scale, distance)
    if best is None:
        return (k,) * len(groups), 0.0 if stretchy else 1.0
    return best[0], best[1]
