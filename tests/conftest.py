import os
from pathlib import Path

import pytest
from hypothesis import settings

# no per-example deadline anywhere: the suite runs two processes on two cores beside whatever
# else the machine does, and a slow example is not a failure (what a case may cost is bounded
# by the timing tests that say so)
settings.register_profile("bgr", deadline=None)
settings.load_profile("bgr")

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


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption(
        "--fuzz-cases",
        type=int,
        default=None,
        help="examples per fuzz test in tests/test_fuzz.py, tests/test_fuzz_geojson.py and "
        "tests/test_fuzz_inverse.py (nightly: 100000); default: each test's own small count",
    )


def pytest_configure(config: pytest.Config) -> None:
    # test_fuzz.py reads it when it is imported, to size its hypothesis settings
    cases = config.getoption("--fuzz-cases")
    if cases:
        os.environ["BGR_FUZZ_CASES"] = str(cases)
