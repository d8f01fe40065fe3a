import os
from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def gran_knots_json() -> Path:
    """``Gran_1_knots.json`` of the shared data (skips when absent, as on a user's machine)."""
    root = os.environ.get("WOODCAM_SHARED_DATA") or str(Path(__file__).resolve().parents[3] / "shared" / "data")
    p = Path(root) / "trees" / "Gran_1_knots.json"
    if not p.is_file():
        pytest.skip(f"shared data not found at {p}; set WOODCAM_SHARED_DATA")
    return p
