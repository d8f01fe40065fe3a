"""Parts made by other people, as a new user brings them: meshes shipped by the Debian package
linuxcnc-uspace (its vismach machine models, STL and OBJ). Each is placed into the demo block with
``fit`` and baked at 10 texels/mm: the atlas must be at least half full and the density kept.

No public STEP file is installed on this machine (searched / for *.step, *.stp, *.brep and the
build123d, cadquery, OCP and trimesh packages); the tessellation tests use analytic B-reps
(tests/cad/test_parts.py). Skipped with a reason where linuxcnc's examples are absent.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from woodcam.cad import carve, load_part
from woodcam.cad.place import place_part

from .conftest import DEMO_BLOCK_MM

_VISMACH = Path("/usr/share/doc/linuxcnc/examples/sample-configs/sim/axis/vismach")

#: (file, triangles as loaded): a 4.8k-triangle tool carousel (xatlas charts it: the projected
#: charts of its faceted rims fragment) and a 3k-triangle robot link (projected charts).
PUBLIC_PARTS = [("VMC_toolchange/carousel.stl", 4756), ("puma/puma_link4.obj", 3026)]


class _GreyWood:
    def color(self, points_mm, normals):
        return np.full(points_mm.shape, 0.5)


@pytest.mark.slow  # ~2 CPU-s per part
@pytest.mark.parametrize("name, triangles", PUBLIC_PARTS, ids=[p[0] for p in PUBLIC_PARTS])
def test_a_public_part_fits_the_block_and_bakes_half_full(name, triangles):
    from woodcam.bake import bake

    path = _VISMACH / name
    if not path.is_file():
        pytest.skip(f"{path} is not installed (Debian package linuxcnc-uspace ships it)")
    solid = load_part(path)
    assert solid.num_tri() == triangles
    placed, matrix = place_part(solid, ["fit"], DEMO_BLOCK_MM)
    lo, hi = np.asarray(placed.bounding_box()).reshape(2, 3)
    assert np.all(lo >= -1e-6) and np.all(hi <= np.asarray(DEMO_BLOCK_MM) + 1e-6)
    result = carve(placed, DEMO_BLOCK_MM)
    assert result.volume_mm3 == pytest.approx(placed.volume(), rel=1e-6)  # fits: nothing cut off
    baked = bake(result.mesh, _GreyWood(), texels_per_mm=10.0)
    assert baked.uv_fill >= 0.5, baked.summary()
    assert baked.texels_per_mm == pytest.approx(10.0), baked.summary()
