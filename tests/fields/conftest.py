"""Shared fixtures for the field tests: the real CT log (skipped when the data is absent)."""

import pytest

from woodcam.fields.tree_data import shared_data_dir


@pytest.fixture(scope="session")
def gran1():
    base = shared_data_dir()
    if base is None or not (base / "trees" / "Gran_1_knots.json").is_file():
        pytest.skip("shared/data/trees (the CT-measured spruce log) is not available; "
                    "set WOODCAM_SHARED_DATA")
    from woodcam.fields.tree_data import read_gran1

    return read_gran1(base / "trees")
