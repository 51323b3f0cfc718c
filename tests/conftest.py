"""Shared pytest fixtures: seeded random generators and paths to reference data."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parent.parent
ASSETS = REPO / "assets"
REFERENCE = REPO.parent / "shared" / "reference"


@pytest.fixture
def rng() -> np.random.Generator:
    """A fixed-seed generator: every test run draws the same numbers."""
    return np.random.default_rng(20131023)


@pytest.fixture
def reference_dir() -> Path:
    """``../shared/reference`` (vendor URDFs, real parts); skips when it is absent."""
    if not REFERENCE.is_dir():
        pytest.skip(f"reference data not found at {REFERENCE}")
    return REFERENCE
