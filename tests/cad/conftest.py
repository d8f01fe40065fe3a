"""Shared fixtures for the woodcam.cad tests."""

from __future__ import annotations

from pathlib import Path

import pytest

#: Demo block of the examples and most tests: (W, D, H) mm.
DEMO_BLOCK_MM = (100.0, 80.0, 50.0)

#: Repository root (tests/cad/ -> repo).
REPO_ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def bd():
    """build123d, skipping when the ``cad`` extra is not installed."""
    return pytest.importorskip("build123d")


@pytest.fixture(scope="session")
def cq():
    """cadquery, skipping when the ``cad`` extra is not installed."""
    return pytest.importorskip("cadquery")
