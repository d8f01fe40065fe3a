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


@pytest.fixture(scope="session")
def gran1():
    """The CT-measured spruce log Gran_1 (skipped when the shared data is absent)."""
    from woodcam.logs.io import read_gran1
    from woodcam.logs.io import shared_data_dir as woodcam_shared_data_dir

    base = woodcam_shared_data_dir()
    if base is None or not (base / "trees" / "Gran_1_knots.json").is_file():
        pytest.skip("shared/data/trees (the CT-measured spruce log) is not available; "
                    "set WOODCAM_SHARED_DATA")
    return read_gran1(base / "trees")
