"""Random streams seeded by the global seed and a shape's derivation path (LANGUAGE.md section 9).

A shape's stream depends only on the seed and on the chain of (rule, child index) from the
axiom, so derivation order does not matter and editing one subtree leaves every other subtree's
draws unchanged.  The path hash is built incrementally with the splitmix64 finaliser; draws are
splitmix64 steps.  Pure Python integers: one draw costs well under a microsecond.
"""

from __future__ import annotations

import zlib

MASK = (1 << 64) - 1
GOLDEN = 0x9E3779B97F4A7C15


def mix(z: int) -> int:
    """The splitmix64 finaliser: a 64-bit bijection with good avalanche."""
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9 & MASK
    z = (z ^ (z >> 27)) * 0x94D049BB133111EB & MASK
    return z ^ (z >> 31)


def name_hash(name: str) -> int:
    """A stable 64-bit hash of a rule name (Python's hash() is salted per process)."""
    data = name.encode("utf-8")
    return (zlib.crc32(data) << 32) | zlib.adler32(data)


def root_hash(seed: int) -> int:
    return mix((seed * GOLDEN + 0x632BE59BD9B4E019) & MASK)


def child_hash(parent: int, rule_hash: int, index: int) -> int:
    # mix() written out: this runs once per shape derived
    z = (parent ^ rule_hash) + (index + 1) * GOLDEN & MASK
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9 & MASK
    z = (z ^ (z >> 27)) * 0x94D049BB133111EB & MASK
    return z ^ (z >> 31)


class Stream:
    """The draws of one shape: a splitmix64 sequence started from its path hash."""

    __slots__ = ("state",)

    def __init__(self, path_hash: int) -> None:
        self.state = path_hash

    def uniform(self) -> float:
        """A float in [0, 1)."""
        self.state = (self.state + GOLDEN) & MASK
        return (mix(self.state) >> 11) * (1.0 / (1 << 53))
