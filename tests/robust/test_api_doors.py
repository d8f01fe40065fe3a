"""The doors of the public API: what an entry point cannot use is refused with a WoodcamError that
names it (found by a sweep of bad inputs: these raised AttributeError or a 1.5 TiB MemoryError)."""

from __future__ import annotations

import pytest

from woodcam.errors import WoodcamError


def test_fit_block_refuses_what_is_not_a_block():
    from woodcam import fit_block

    with pytest.raises(WoodcamError, match="block must be a woodcam.block.Block.*got NoneType"):
        fit_block(None, "radial")


def test_a_log_too_long_to_hold_is_refused_before_allocating():
    from woodcam import generate_log

    with pytest.raises(WoodcamError, match="surface height map .*MAX_GRID_CELLS.*WOODCAM_MAX_GRID_CELLS"):
        generate_log(seed=1, length_mm=1e12)


def test_crease_normals_refuses_what_is_not_a_mesh():
    from woodcam import crease_normals

    with pytest.raises(WoodcamError, match="mesh must be a trimesh.Trimesh; got NoneType"):
        crease_normals(None)


def test_grain_direction_refuses_what_is_not_a_field():
    import numpy as np

    from woodcam import grain_direction

    with pytest.raises(WoodcamError, match="field must be a growth field.*got NoneType"):
        grain_direction(None, np.zeros((2, 3)))
