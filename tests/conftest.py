"""Shared pytest fixtures: real-data location and small synthetic blocks."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[1]


def shared_data_dir() -> Path:
    """``$WOODCAM_SHARED_DATA`` or ``<repo>/../shared/data``."""
    return Path(os.environ.get("WOODCAM_SHARED_DATA", REPO.parent / "shared" / "data"))


@pytest.fixture
def shared_data() -> Path:
    d = shared_data_dir()
    if not d.is_dir():
        pytest.skip(f"real reference data not found at {d} (set WOODCAM_SHARED_DATA)")
    return d


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)
