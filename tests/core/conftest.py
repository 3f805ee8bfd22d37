from pathlib import Path

import pytest

import modalviewer as mv

ASSETS = Path(__file__).resolve().parents[2] / "assets"


@pytest.fixture(scope="session")
def spot():
    """A real scanned-style mesh shipped in assets/ (about 3k vertices)."""
    return mv.load_mesh(ASSETS / "spot.obj")
