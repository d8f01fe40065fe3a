"""cad_examples: every example (bowl, tray, lid, spoon_blank) loads, carves into the demo block with nothing outside, keeps a
>= 2 mm margin, matches its B-rep volume, and runs standalone."""

from __future__ import annotations

import runpy
import subprocess
import sys

import numpy as np
import pytest

from woodcam.cad import carve, load_part
from woodcam.tolerances import CARVE_VOLUME_RTOL, OUTSIDE_VOLUME_EPS_MM3

from .conftest import DEMO_BLOCK_MM, REPO_ROOT

EXAMPLES_DIR = REPO_ROOT / "cad_examples"
EXAMPLES = ["bowl", "tray", "lid", "spoon_blank"]
#: Margin the examples keep to every block face (mm), so a demo block of the same size never
#: clips them.
MIN_MARGIN_MM = 2.0
#: Relative volume difference allowed between a script's own STL export and its B-rep.
STANDALONE_STL_RTOL = 1e-2


def _brep_volume(part) -> float:
    """Exact B-rep volume of a build123d Part or cadquery Workplane (mm^3)."""
    return float(part.volume) if hasattr(part, "volume") and not callable(part.volume) \
        else float(part.val().Volume())


@pytest.fixture(scope="module", params=EXAMPLES)
def example(request, bd, cq):
    """(name, module namespace, carve result) for each example, built once per module."""
    path = EXAMPLES_DIR / f"{request.param}.py"
    namespace = runpy.run_path(str(path), run_name="__test__")
    result = carve(load_part(path), DEMO_BLOCK_MM)
    return request.param, namespace, result


def test_example_carves_inside_the_demo_block(example):
    name, namespace, result = example
    assert tuple(namespace["BLOCK_MM"]) == DEMO_BLOCK_MM
    assert result.warnings == []
    assert result.outside_volume_mm3 < OUTSIDE_VOLUME_EPS_MM3
    assert result.mesh.is_watertight and result.mesh.is_winding_consistent
    lo, hi = result.mesh.bounds
    assert np.all(lo >= MIN_MARGIN_MM), f"{name}: lower bounds {lo} closer than {MIN_MARGIN_MM}"
    assert np.all(hi <= np.array(DEMO_BLOCK_MM) - MIN_MARGIN_MM), f"{name}: upper bounds {hi}"


def test_example_mesh_volume_matches_brep(example):
    _, namespace, result = example
    expected = _brep_volume(namespace["part"])
    assert result.volume_mm3 == pytest.approx(expected, rel=CARVE_VOLUME_RTOL)


def test_bowl_dimensions(bd):
    namespace = runpy.run_path(str(EXAMPLES_DIR / "bowl.py"), run_name="__test__")
    bb = namespace["part"].bounding_box()
    assert bb.size.X == pytest.approx(2 * namespace["RIM_RADIUS"], abs=1e-6)   # Ø74
    assert bb.size.Z == pytest.approx(namespace["HEIGHT"], abs=1e-6)          # 42 high
    assert (bb.min.X + bb.max.X) / 2 == pytest.approx(50.0, abs=1e-6)
    assert (bb.min.Y + bb.max.Y) / 2 == pytest.approx(40.0, abs=1e-6)
    # it is hollow: much less than the solid of revolution's envelope cylinder
    envelope = np.pi * namespace["RIM_RADIUS"] ** 2 * namespace["HEIGHT"]
    assert namespace["part"].volume < 0.5 * envelope


def test_lid_bevels_are_30_degrees(bd):
    """The lid's panel faces that are neither horizontal nor vertical slope at BEVEL_ANGLE_DEG."""
    namespace = runpy.run_path(str(EXAMPLES_DIR / "lid.py"), run_name="__test__")
    mesh = carve(namespace["part"], DEMO_BLOCK_MM).mesh
    tilt_deg = np.degrees(np.arccos(np.clip(np.abs(mesh.face_normals[:, 2]), 0, 1)))
    planar_bevel = (tilt_deg > 10) & (tilt_deg < 80)
    area = mesh.area_faces[planar_bevel]
    # most sloped area (the four bevels) sits at 30°; the rest is the plate's round-over
    at_30 = np.abs(tilt_deg[planar_bevel] - namespace["BEVEL_ANGLE_DEG"]) < 0.01
    assert area[at_30].sum() > 0.8 * area.sum()


def test_spoon_handle_is_tilted(bd):
    """The handle's top and bottom faces are planes tilted by HANDLE_ANGLE_DEG about Y."""
    namespace = runpy.run_path(str(EXAMPLES_DIR / "spoon_blank.py"), run_name="__test__")
    mesh = carve(namespace["part"], DEMO_BLOCK_MM).mesh
    angle = np.radians(namespace["HANDLE_ANGLE_DEG"])
    up = np.array([-np.sin(angle), 0.0, np.cos(angle)])  # normal of the handle's top face
    top = mesh.face_normals @ up > 1 - 1e-6
    bottom = mesh.face_normals @ -up > 1 - 1e-6
    # both faces span most of the handle: > 40 mm long, >= 10 mm wide
    assert mesh.area_faces[top].sum() > 400
    assert mesh.area_faces[bottom].sum() > 400


@pytest.mark.slow
@pytest.mark.parametrize("name", EXAMPLES)
def test_example_runs_standalone_and_its_stl_loads(tmp_path, name, bd, cq):
    out = tmp_path / f"{name}.stl"
    proc = subprocess.run([sys.executable, str(EXAMPLES_DIR / f"{name}.py"), str(out)],
                          capture_output=True, text=True, timeout=300, check=False)
    assert proc.returncode == 0, proc.stderr
    assert out.is_file() and f"wrote {out}" in proc.stdout
    namespace = runpy.run_path(str(EXAMPLES_DIR / f"{name}.py"), run_name="__test__")
    _assert_stl_says_mm(out, name)
    # the script's STL is meshed by woodcam's load_part (0.05 mm chords), as woodcam carves it
    assert load_part(out).volume() == pytest.approx(
        _brep_volume(namespace["part"]), rel=STANDALONE_STL_RTOL)


def _assert_stl_says_mm(path, name: str) -> None:
    """A binary STL written by woodcam.export.write_stl: its 80-byte header states units=mm and
    what it is (the CAD kernels' exporters wrote 'STL Exported by Open CASCADE Technology', no
    unit), not 'solid' (ASCII STL), and its triangle count matches its length."""
    import struct

    from woodcam.export import STL_HEADER

    data = path.read_bytes()
    assert data[:80] == f"woodcam: units=mm {name}.py part, block frame, Z up".encode().ljust(80), data[:80]
    assert data.startswith(STL_HEADER) and not data.startswith(b"solid")
    (n,) = struct.unpack_from("<I", data, 80)
    assert n > 100 and len(data) == 84 + 50 * n


def test_tray_runs_standalone_into_the_current_directory(tmp_path, cq):
    """One subprocess run in the default suite (each costs a cadquery import, seconds); its STL
    says its unit in its header (sweep h2: 'STL Exported by Open CASCADE Technology', no unit)."""
    proc = subprocess.run([sys.executable, str(EXAMPLES_DIR / "tray.py")], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300, check=False)
    assert proc.returncode == 0, proc.stderr
    out = tmp_path / "tray.stl"
    assert out.is_file()
    _assert_stl_says_mm(out, "tray")
    namespace = runpy.run_path(str(EXAMPLES_DIR / "tray.py"), run_name="__test__")
    assert load_part(out).volume() == pytest.approx(
        _brep_volume(namespace["part"]), rel=CARVE_VOLUME_RTOL)


class _FlatWood:
    def color(self, points_mm, normals):
        return np.full(points_mm.shape, 0.5)


@pytest.mark.slow  # bakes every example at the default 10 texels/mm (~10 CPU-s)
def test_example_bakes_with_half_the_atlas_filled(example):
    """Issue 16: charts capped at 256 x the median face filled 7-15 % of the atlas on curved CAD
    parts (a 90 mm cup silently dropped from 10 to 3.7 texels/mm); the bar is 50 %."""
    from woodcam.bake import bake

    name, _, result = example
    baked = bake(result.mesh, _FlatWood(), texels_per_mm=10.0)
    assert baked.uv_fill >= 0.5, f"{name}: {baked.summary()}"
    assert baked.texels_per_mm == pytest.approx(10.0), f"{name}: density lowered"
