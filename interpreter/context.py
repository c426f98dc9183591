"""What an expression sees while a shape is derived, and a rule passed as a value.

:class:`Context` is the one object every compiled expression (expressions.py) reads: the shape,
its rule's arguments, its random stream, the split and comp indices of the piece it came from.
:class:`RuleRef` is a rule or terminal handed to a rule parameter.  They are apart from the
compiler (which imports them, and from which they stay importable) so that modules that only
meet these values at run time, such as the analysis of repeated subtrees in reuse.py, need not
import the compiler.
"""

from __future__ import annotations


class Context:
    """What an expression can see while a shape is being derived."""

    __slots__ = (
        "shape",
        "args",
        "stream",
        "seed",
        "split_index",
        "split_total",
        "comp_index",
        "comp_total",
        "comp_left",
        "comp_right",
        "comp_sel",
        "library",
        "occlusion",
    )

    def __init__(
        self,
        shape,
        args: dict,
        stream,
        seed: int,
        indices=(0, 1, 0, 1, 0.0, 0.0, ""),
        library=None,
        occlusion=None,
    ) -> None:
        """``indices``: split.index, split.total, comp.index, comp.total, the comp face's left
        and right neighbour angles and its selector, of the piece the shape came from;
        ``library``: the derivation's unit meshes, which the geometry functions measure a mesh
        shape by; ``occlusion``: the lot's occluders (occlusion.py), None when the grammar asks
        no occlusion query."""
        self.shape, self.args, self.stream, self.seed = shape, args, stream, seed
        self.library, self.occlusion = library, occlusion
        (
            self.split_index,
            self.split_total,
            self.comp_index,
            self.comp_total,
            self.comp_left,
            self.comp_right,
            self.comp_sel,
        ) = indices


class RuleRef:
    """A rule or terminal handed to a rule parameter as a value (``Facade(window = win.Arched)``).

    It names the module that defines the rule, so a stdlib façade applies the caller's window.
    """

    __slots__ = ("module", "member")

    def __init__(self, module, member: str) -> None:
        self.module, self.member = module, member

    def __eq__(self, other) -> bool:
        return (
            isinstance(other, RuleRef)
            and other.module is self.module
            and other.member == self.member
        )

    def __hash__(self) -> int:
        return hash((id(self.module), self.member))

    def __repr__(self) -> str:
        return f"the rule '{self.member}'"
