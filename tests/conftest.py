from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
SHARED = ROOT.parent / "shared"


def shipped_grammars() -> list[Path]:
    """Every .bgr file the repository ships (examples, stdlib, tests' own data)."""
    return sorted(
        p for p in ROOT.rglob("*.bgr") if ".venv" not in p.parts and "build" not in p.parts
    )


@pytest.fixture
def root() -> Path:
    return ROOT
