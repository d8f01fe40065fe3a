"""carve: part ∩ block against analytic volumes; warnings for parts sticking out; miss errors.

Known answers: block minus a cylinder (W D H - pi r^2 H), a box fully inside (its own volume,
exact), a sphere centred on the top face (half inside, half outside), all within
CARVE_VOLUME_RTOL (set by the tessellation of curved faces).
"""

from __future__ import annotations

import math

import manifold3d
import numpy as np
import pytest
import trimesh

from woodcam.cad import CarveResult, carve
from woodcam.errors import WoodcamError, WoodcamWarning
from woodcam.tolerances import CARVE_VOLUME_RTOL, ON_FACE_TOL_MM

from .conftest import DEMO_BLOCK_MM

W, D, H = DEMO_BLOCK_MM


def _check_result(result: CarveResult) -> None:
    """Invariants of every carve: closed mesh in the block, consistent volumes."""
    assert isinstance(result, CarveResult)
    assert result.mesh.is_watertight and result.mesh.is_winding_consistent
    assert result.mesh.volume == pytest.approx(result.volume_mm3, rel=1e-9)
    assert result.manifold.volume() == pytest.approx(result.volume_mm3, rel=1e-12)
    lo, hi = result.mesh.bounds
    assert np.all(lo >= -ON_FACE_TOL_MM) and np.all(hi <= np.array(result.size_mm) + ON_FACE_TOL_MM)
    assert result.volume_mm3 + result.outside_volume_mm3 == pytest.approx(
        result.part_volume_mm3, rel=1e-9)


def test_block_minus_cylinder_matches_analytic_volume(bd):
    r = 20.0
    part = bd.Box(W, D, H, align=bd.Align.MIN) - bd.Pos(W / 2, D / 2, 0) * bd.Cylinder(
        radius=r, height=H, align=(bd.Align.CENTER, bd.Align.CENTER, bd.Align.MIN))
    result = carve(part, DEMO_BLOCK_MM)
    _check_result(result)
    assert result.volume_mm3 == pytest.approx(W * D * H - math.pi * r**2 * H, rel=CARVE_VOLUME_RTOL)
    assert result.outside_volume_mm3 == pytest.approx(0, abs=1e-6)
    assert result.warnings == []


def test_box_fully_inside_keeps_its_volume_exactly():
    part = manifold3d.Manifold.cube((30, 20, 10)).translate((5, 6, 7))
    result = carve(part, DEMO_BLOCK_MM)
    _check_result(result)
    assert result.volume_mm3 == pytest.approx(6000, rel=1e-12)
    assert result.part_volume_mm3 == pytest.approx(6000, rel=1e-12)
    assert result.outside_volume_mm3 == 0.0
    np.testing.assert_allclose(result.mesh.bounds, [[5, 6, 7], [35, 26, 17]], atol=1e-9)


def test_a_part_too_small_to_carve_says_so():
    """A 0.02 mm part inside the block was said not to intersect it, with the advice to move it by
    (0, 0, 0) mm."""
    part = manifold3d.Manifold.cube((0.02, 0.02, 0.02)).translate((50, 40, 25))
    with pytest.raises(WoodcamError, match=r"the part's volume is 0.000008 mm\^3 \(it measures 0.02x0.02x0.02 mm\), too small to carve; "
                       r"check its units"):
        carve(part, DEMO_BLOCK_MM)


def test_a_part_in_metres_too_small_to_carve_says_its_size_and_how_to_scale_it():
    """A 0.2 m part exported in metres is read as 0.2 mm: refused with 'check its units' alone,
    no size, no fix; now with what it measures, in metres and inches, and the caller's fix."""
    part = manifold3d.Manifold.cube((0.2, 0.05, 0.03)).translate((0.01, 0.04, 0.025))
    with pytest.raises(WoodcamError, match=r"it measures 0.2x0.05x0.03 mm\), too small to carve; check its "
                       r"units: .*modelled in metres would be 200x50x30 mm, in inches 5.08x1.27x0.762 mm: "
                       r"add scale:1000"):
        carve(part, DEMO_BLOCK_MM, units_fix="add scale:1000")


@pytest.mark.parametrize("source, says", [
    ("tray.step", "A STEP file names its units and is converted from them to millimetres, so it was saved "
     "this small"),
    ("tray.py", "Lengths in a part script or a build123d/cadquery shape carry no units and are read as "
     "millimetres"),
    ("tray.stl", "Part files are read as millimetres (STL, OBJ and PLY carry no units)"),
    (None, "Part files are read as millimetres (STL, OBJ and PLY carry no units)"),
])
def test_the_inch_warning_says_what_the_parts_source_carries(source, says):
    """The warning of a part in inches said '(STL, OBJ and PLY carry no units)' of a STEP part
    (which carries its units) and of a .py script too: its note is true of the part's source."""
    tray = manifold3d.Manifold.cube((90, 70, 18)).translate((5, 5, 2)).scale([1 / 25.4] * 3)
    with pytest.warns(WoodcamWarning, match="25.4 times larger it would still fit") as caught:
        carve(tray, DEMO_BLOCK_MM, source=source)
    (message,) = [str(w.message) for w in caught]
    assert says in message, message
    assert ("carry no units" in message) == (source != "tray.step"), message


def test_a_part_in_inches_read_as_mm_says_how_to_scale_it():
    """An STL carries no units: a 90 x 70 x 18 mm tray exported in inches is read as a
    3.5 x 2.8 x 0.7 mm speck, which was carved and reported ('0 mm^3') without a word."""
    tray = manifold3d.Manifold.cube((90, 70, 18)).translate((5, 5, 2)).scale([1 / 25.4] * 3)
    with pytest.warns(WoodcamWarning, match=r"only 3.54x2.76x0.709 mm in the 100x80x50 mm block: "
                      r"25.4 times larger it would still fit.*in inches scale it before carving: "
                      r"woodcam.cad.place.place_part\(part, \['scale:25.4', 'center'\], size_mm\)"):
        result = carve(tray, DEMO_BLOCK_MM)
    assert any("25.4 times larger" in w for w in result.warnings)
    # a small part that would not fit 25.4 x larger is taken as meant
    carve(manifold3d.Manifold.cube((5, 4, 3)), DEMO_BLOCK_MM)


def test_part_filling_the_block_exactly_has_no_warning():
    result = carve(manifold3d.Manifold.cube(DEMO_BLOCK_MM), DEMO_BLOCK_MM)
    _check_result(result)
    assert result.volume_mm3 == pytest.approx(W * D * H, rel=1e-12)
    assert result.warnings == []


def test_sphere_half_out_of_the_top_warns_with_outside_volume(bd):
    r = 15.0
    part = bd.Pos(W / 2, D / 2, H) * bd.Sphere(radius=r)
    half = 2 / 3 * math.pi * r**3
    with pytest.warns(WoodcamWarning, match=r"sticks out of the block: .* mm\^3 \(50(\.\d+)? %"):
        result = carve(part, DEMO_BLOCK_MM)
    _check_result(result)
    assert result.volume_mm3 == pytest.approx(half, rel=CARVE_VOLUME_RTOL)
    assert result.outside_volume_mm3 == pytest.approx(half, rel=CARVE_VOLUME_RTOL)
    assert len(result.warnings) == 1
    assert f"{result.outside_volume_mm3:.4g} mm^3" in result.warnings[0]
    # the cut face is the block's top face: the highest vertices lie on z = H
    assert result.mesh.bounds[1, 2] == pytest.approx(H, abs=ON_FACE_TOL_MM)


def test_part_bigger_than_block_is_clipped_to_the_block():
    part = manifold3d.Manifold.cube((W + 20, D + 20, H + 20)).translate((-10, -10, -10))
    outside = (W + 20) * (D + 20) * (H + 20) - W * D * H
    with pytest.warns(WoodcamWarning, match="sticks out") as record:
        result = carve(part, DEMO_BLOCK_MM)
    assert len(record) == 1
    _check_result(result)
    assert result.volume_mm3 == pytest.approx(W * D * H, rel=1e-12)
    assert result.outside_volume_mm3 == pytest.approx(outside, rel=1e-9)
    np.testing.assert_allclose(result.mesh.bounds, [[0, 0, 0], [W, D, H]], atol=1e-9)


def test_part_missing_the_block_raises_with_both_bounding_boxes():
    part = manifold3d.Manifold.cube((10, 10, 10)).translate((200, 0, 0))
    with pytest.raises(WoodcamError, match=(
            r"does not intersect the block: the part's bounding box is \[200, 210\] x \[0, 10\] "
            r"x \[0, 10\] mm but the block is \[0, 100\] x \[0, 80\] x \[0, 50\] mm")):
        carve(part, DEMO_BLOCK_MM)


def test_part_only_touching_the_block_raises():
    part = manifold3d.Manifold.cube((10, 10, 10)).translate((W, 0, 0))  # shares the right face
    with pytest.raises(WoodcamError, match="does not intersect the block"):
        carve(part, DEMO_BLOCK_MM)


def test_part_modelled_around_the_origin_gets_a_hint(cq):
    # a common mistake: a part centred on the origin instead of in the block frame
    part = cq.Workplane("XY").box(20, 20, 20).translate((0, 0, -30))
    with pytest.raises(WoodcamError, match=r"move it by \(50, 40, 55\) mm to centre it"):
        carve(part, DEMO_BLOCK_MM)


def test_carve_accepts_any_load_part_source(tmp_path):
    mesh = trimesh.creation.box(extents=(10, 10, 10))
    mesh.apply_translation((50, 40, 25))
    path = tmp_path / "cube.stl"
    mesh.export(path)
    for source in (mesh, path, str(path)):
        result = carve(source, DEMO_BLOCK_MM)
        assert result.volume_mm3 == pytest.approx(1000, rel=1e-6)


@pytest.mark.parametrize("size", [(100, 80), (100, 0, 50), (100, -1, 50), (100, float("inf"), 50),
                                  "100x80x50", None])
def test_bad_block_size_raises(size):
    with pytest.raises(WoodcamError, match="size_mm must be three"):
        carve(manifold3d.Manifold.cube((1, 1, 1)), size)


def test_result_figures_agree_with_its_mesh():
    """A 20 mm cube half outside the block: the carved half's mesh, manifold and figures agree
    (replaces a test of the standard library's frozen dataclass)."""
    cube = manifold3d.Manifold.cube((20, 20, 20)).translate((-10, 5, 5))
    with pytest.warns(WoodcamWarning, match="sticks out of the block"):
        result = carve(cube, DEMO_BLOCK_MM)
    assert result.volume_mm3 == pytest.approx(4000, rel=1e-6)
    assert result.mesh.volume == pytest.approx(result.volume_mm3, rel=1e-9)
    assert result.manifold.volume() == pytest.approx(result.volume_mm3, rel=1e-9)
    assert result.part_volume_mm3 == pytest.approx(8000, rel=1e-6)
    assert result.outside_volume_mm3 == pytest.approx(4000, rel=1e-6)
    assert result.mesh.bounds[0][0] == pytest.approx(0.0) and result.size_mm == tuple(DEMO_BLOCK_MM)
    assert len(result.warnings) == 1 and "sticks out" in result.warnings[0]


def test_every_manifold_to_mesh_conversion_keeps_manifold3ds_double_vertices(tmp_path):
    """A manifold3d Manifold was turned into triangles in five places, carve and write_stl in
    float64 (to_mesh64), placement advice, woodify's parts and the toolpath reference in float32
    (to_mesh: a 10.7 mm top read as 10.6999998 mm). Now one conversion (woodcam._manifold), in
    float64: the same solid is the same vertices, to the last bit, wherever it is read."""
    from woodcam.advise import _part_mesh
    from woodcam.cli.woodify import _load_mesh
    from woodcam.toolpath.reference import manifold_heightmap

    size = (30.1, 20.3, 10.7)  # none of them a float32
    solid = manifold3d.Manifold.cube(size)
    exact = np.asarray(solid.to_mesh64().vert_properties)[:, :3]
    script = tmp_path / "box.py"
    script.write_text(f"import manifold3d\npart = manifold3d.Manifold.cube({size})\n")
    for what, mesh in (("carve", carve(solid, (40.0, 30.0, 20.0)).mesh), ("advise", _part_mesh(solid)),
                       ("woodify", _load_mesh(str(script))[0])):
        assert np.array_equal(np.sort(mesh.vertices, axis=0), np.sort(exact, axis=0)), what
    assert np.array_equal(manifold_heightmap(solid, size, (4, 4)), np.full((4, 4), 10.7))
