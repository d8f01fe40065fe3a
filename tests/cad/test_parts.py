"""load_part: every accepted source type, file round trips, tessellation tolerance, errors.

Known answers: analytic volumes of boxes/cylinders/spheres (within CARVE_VOLUME_RTOL, set by the
tessellation), exact volumes for polyhedral parts, and lossless round trips of a mesh through
STL/OBJ/GLB/glTF (float32 files: relative 1e-6).
"""

from __future__ import annotations

import contextlib
import math

import manifold3d
import numpy as np
import pytest
import trimesh

from woodcam.cad import load_part
from woodcam.errors import WoodcamError, WoodcamWarning
from woodcam.tolerances import CARVE_VOLUME_RTOL

#: Relative volume error of a mesh that went through a float32 file format (STL, GLB): vertex
#: round-off ~6e-8 relative per coordinate, summed over the surface: 1e-6 is ample.
FILE_ROUND_TRIP_RTOL = 1e-6


def _tri_count(solid) -> int:
    return solid.num_tri()


# ----------------------------------------------------------------------------- source types


def test_build123d_box_volume_is_exact(bd):
    part = bd.Pos(10, 20, 30) * bd.Box(40, 30, 20)
    solid = load_part(part)
    assert isinstance(solid, manifold3d.Manifold)
    assert solid.volume() == pytest.approx(40 * 30 * 20, rel=1e-12)
    np.testing.assert_allclose(solid.bounding_box(), (-10, 5, 20, 30, 35, 40), atol=1e-9)


def test_build123d_cylinder_volume_within_tessellation_tolerance(bd):
    solid = load_part(bd.Cylinder(radius=20, height=30))
    assert solid.volume() == pytest.approx(math.pi * 20**2 * 30, rel=CARVE_VOLUME_RTOL)
    # the polygonal cylinder is inscribed: it can only lose volume
    assert solid.volume() < math.pi * 20**2 * 30


def test_build123d_builder_and_compound_of_overlapping_solids(bd):
    with bd.BuildPart() as builder:
        bd.Box(10, 10, 10, align=bd.Align.MIN)
    assert load_part(builder).volume() == pytest.approx(1000, rel=1e-12)
    # two boxes overlapping in a 5 x 10 x 10 slab, as separate solids of one compound:
    # each solid is meshed on its own and the pieces are unioned, so the overlap counts once
    a = bd.Box(10, 10, 10, align=bd.Align.MIN)
    b = bd.Pos(5, 0, 0) * bd.Box(10, 10, 10, align=bd.Align.MIN)
    compound = bd.Compound([a, b])
    assert load_part(compound).volume() == pytest.approx(1500, rel=1e-9)


def test_sphere_poles_weld_into_closed_mesh(bd):
    """Regression: OCC meshes a sphere's degenerate pole edges as fans of coincident nodes;
    welding turned them into repeated-vertex triangles and left 4 open edges."""
    solid = load_part(bd.Sphere(radius=8))
    assert solid.volume() == pytest.approx(4 / 3 * math.pi * 8**3, rel=CARVE_VOLUME_RTOL)


def test_cadquery_workplane_and_shape(cq):
    # 40 x 30 x 20 box centred on the origin with a 10 mm hole through its top face centre
    wp = cq.Workplane("XY").box(40, 30, 20).faces(">Z").workplane().hole(10)
    expected = 40 * 30 * 20 - math.pi * 5**2 * 20
    assert load_part(wp).volume() == pytest.approx(expected, rel=CARVE_VOLUME_RTOL)
    assert load_part(wp.val()).volume() == pytest.approx(expected, rel=CARVE_VOLUME_RTOL)
    # the hole is where the model says: a 6 x 6 column on the z axis is empty
    column = manifold3d.Manifold.cube((6, 6, 30), center=True)
    assert (load_part(wp) ^ column).volume() == pytest.approx(0, abs=1e-9)


def test_cadquery_workplane_with_several_solids_is_unioned(cq):
    # two solids overlapping by 5 x 10 x 10 left uncombined on the stack
    wp = cq.Workplane("XY").pushPoints([(0, 0), (5, 0)]).box(10, 10, 10, combine=False)
    assert len(wp.vals()) == 2
    assert load_part(wp).volume() == pytest.approx(1500, rel=1e-9)


def test_cadquery_empty_workplane_raises(cq):
    with pytest.raises(WoodcamError, match="holds no shape"):
        load_part(cq.Workplane("XY"))


def test_trimesh_input_and_inside_out_mesh():
    box = trimesh.creation.box(extents=(10, 20, 30))
    assert load_part(box).volume() == pytest.approx(6000, rel=1e-12)
    inverted = box.copy()
    inverted.invert()
    assert inverted.volume < 0
    assert load_part(inverted).volume() == pytest.approx(6000, rel=1e-12)


def test_trimesh_scene_meshes_are_unioned():
    a = trimesh.creation.box(extents=(10, 10, 10))
    b = trimesh.creation.box(extents=(10, 10, 10))
    b.apply_translation((5, 0, 0))  # overlaps a by 5 x 10 x 10
    scene = trimesh.Scene([a, b])
    assert load_part(scene).volume() == pytest.approx(1500, rel=1e-9)


def test_shells_of_one_mesh_overlap_nest_and_flip():
    """An assembly exported as one STL holds overlapping bodies: their union, not the sum
    (10000 mm^3, not 16000 carved as two stacked surfaces); an inward shell inside a body is a
    cavity, a body inside that cavity counts again, and a body with flipped normals beside
    another is a body."""
    def box(size, centre, inward=False):
        b = trimesh.creation.box(extents=(size,) * 3)
        b.apply_translation(centre)
        if inward:
            b.invert()
        return b

    overlap = trimesh.util.concatenate([box(20, (50, 40, 25)), box(20, (45, 40, 25))])
    solid = load_part(overlap)
    assert solid.volume() == pytest.approx(20 * 20 * 25, rel=1e-12)
    assert len(solid.decompose()) == 1
    nested = trimesh.util.concatenate([box(30, (0, 0, 0)), box(20, (0, 0, 0), inward=True),
                                       box(10, (0, 0, 0))])
    assert load_part(nested).volume() == pytest.approx(27000 - 8000 + 1000, rel=1e-12)
    flipped = trimesh.util.concatenate([box(10, (0, 0, 0)), box(10, (50, 0, 0), inward=True)])
    assert load_part(flipped).volume() == pytest.approx(2000, rel=1e-12)


def test_mesh_with_holes_is_repaired():
    box = trimesh.creation.box(extents=(10, 10, 10))
    one_missing = trimesh.Trimesh(box.vertices, box.faces[:-1])
    two_missing = trimesh.Trimesh(box.vertices, box.faces[:-2])  # a whole square face gone
    assert not one_missing.is_watertight and not two_missing.is_watertight
    with pytest.warns(WoodcamWarning, match="1 hole.*capped each hole flat.*1000 mm"):
        assert load_part(one_missing).volume() == pytest.approx(1000, rel=1e-12)
    with pytest.warns(WoodcamWarning, match="1 hole.*1000 mm"):
        assert load_part(two_missing).volume() == pytest.approx(1000, rel=1e-12)


def test_duplicate_triangles_are_dropped_and_said():
    """A triangle written twice (some STL exporters) was refused as '8 open or non-manifold
    edges', a message that did not say why."""
    box = trimesh.creation.box(extents=(10, 10, 10))
    doubled = trimesh.Trimesh(box.vertices, np.vstack([box.faces, box.faces[:4]]), process=False)
    with pytest.warns(WoodcamWarning, match="has 4 duplicate triangles.*dropped the copies"):
        assert load_part(doubled).volume() == pytest.approx(1000, rel=1e-12)


def test_open_surface_raises():
    square = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2], [0, 2, 3]])
    with pytest.raises(WoodcamError, match="not a closed .watertight. mesh.*4 open"):
        load_part(square)
    sphere = trimesh.creation.icosphere()
    cup = trimesh.Trimesh(sphere.vertices, sphere.faces[:160])
    with pytest.raises(WoodcamError, match="not a closed"):
        load_part(cup)


def test_bodies_touching_along_an_edge_are_said_as_such():
    """Two boxes sharing one edge (4 triangles on it) were refused as '1 open or non-manifold
    edges' with 'export a solid, not surfaces': advice for a surface, not for touching bodies."""
    a = trimesh.creation.box((20, 20, 20))
    b = a.copy()
    b.apply_translation((20, 20, 0))
    with pytest.raises(WoodcamError, match=r"is not a 2-manifold mesh: 1 edge is shared by more than two triangles "
                       r"\(bodies touching along an edge, or a surface inside the solid\), 0 open; make the "
                       r"bodies overlap or move them apart"):
        load_part(trimesh.util.concatenate([a, b]))


def test_manifold_input_is_returned_as_is():
    cube = manifold3d.Manifold.cube((3, 4, 5))
    assert load_part(cube) is cube


def test_empty_and_errored_manifolds_raise():
    with pytest.raises(WoodcamError, match="empty"):
        load_part(manifold3d.Manifold())
    bad = manifold3d.Manifold(manifold3d.Mesh(
        np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32), np.array([[0, 1, 2]], np.uint32)))
    with pytest.raises(WoodcamError, match="NotManifold"):
        load_part(bad)


def test_unsupported_object_raises():
    with pytest.raises(WoodcamError, match="cannot use an object of type builtins.int"):
        load_part(42)


def test_build123d_sketch_without_solid_raises(bd):
    with pytest.raises(WoodcamError, match="contains no solid nor shell .only faces"):
        load_part(bd.Rectangle(10, 10))


def test_non_shape_cad_objects_raise(bd, cq):
    with pytest.raises(WoodcamError, match="cannot use an object of type build123d.*Vector"):
        load_part(bd.Vector(1, 2, 3))
    with pytest.raises(WoodcamError, match="holds no shape"):
        load_part(cq.Workplane("XY").center(1, 2))
    with pytest.raises(WoodcamError, match="is None; the script or builder produced no shape"):
        load_part(None)


def test_list_of_sources_is_unioned(bd):
    a = bd.Box(10, 10, 10, align=bd.Align.MIN)
    b = trimesh.creation.box(extents=(10, 10, 10))
    b.apply_translation((10, 5, 5))  # overlaps a by 5 x 10 x 10
    assert load_part([a, b]).volume() == pytest.approx(1500, rel=1e-9)
    assert load_part(bd.ShapeList([a])).volume() == pytest.approx(1000, rel=1e-12)
    with pytest.raises(WoodcamError, match="empty list"):
        load_part([])


@pytest.mark.parametrize(("kwargs", "pattern"), [
    ({"tolerance_mm": 0.0}, "tolerance_mm must be a finite number > 0"),
    ({"tolerance_mm": float("nan")}, "tolerance_mm must be a finite number > 0"),
    ({"angular_tolerance_deg": 120}, r"angular_tolerance_deg must be in \(0, 90\]"),
])
def test_bad_tolerances_raise(kwargs, pattern):
    with pytest.raises(WoodcamError, match=pattern):
        load_part(manifold3d.Manifold.cube((1, 1, 1)), **kwargs)


# ----------------------------------------------------------------------------- tolerance


def test_tolerance_changes_triangle_count_and_accuracy(bd):
    cylinder = bd.Cylinder(radius=20, height=30)
    exact = math.pi * 20**2 * 30
    # coarse after fine and fine after coarse on the same shape object: OCC caches a
    # triangulation on the shape; load_part must mesh a fresh copy each time
    fine = load_part(cylinder, tolerance_mm=0.01, angular_tolerance_deg=1.0)
    coarse = load_part(cylinder, tolerance_mm=1.0, angular_tolerance_deg=45.0)
    fine_again = load_part(cylinder, tolerance_mm=0.01, angular_tolerance_deg=1.0)
    assert _tri_count(coarse) < _tri_count(fine) / 10
    assert _tri_count(fine_again) == _tri_count(fine)
    assert abs(fine.volume() - exact) < abs(coarse.volume() - exact) / 100
    # chord tolerance alone also matters (angular tolerance loose)
    chord_fine = load_part(cylinder, tolerance_mm=0.01, angular_tolerance_deg=45.0)
    chord_coarse = load_part(cylinder, tolerance_mm=1.0, angular_tolerance_deg=45.0)
    assert _tri_count(chord_fine) > 2 * _tri_count(chord_coarse)


# ----------------------------------------------------------------------------- files


@pytest.fixture
def block_minus_cylinder_mesh():
    """A polyhedral part (64-gon hole) with an exact, tessellation-free volume."""
    block = manifold3d.Manifold.cube((40, 30, 20))
    hole = manifold3d.Manifold.cylinder(20, 8, circular_segments=64).translate((20, 15, 0))
    solid = block - hole
    mesh = solid.to_mesh()
    return trimesh.Trimesh(mesh.vert_properties[:, :3], mesh.tri_verts), solid.volume()


@pytest.mark.parametrize("suffix", [".stl", ".obj", ".ply", ".off", ".glb", ".gltf"])
def test_mesh_file_round_trip(tmp_path, block_minus_cylinder_mesh, suffix):
    mesh, volume = block_minus_cylinder_mesh
    path = tmp_path / f"part{suffix}"
    # export to memory and write ourselves: trimesh's own .gltf file export leaves a file
    # handle open (a ResourceWarning that the strict pytest config turns into an error)
    data = mesh.export(file_type=suffix.lstrip("."))
    files = data if isinstance(data, dict) else {path.name: data}  # .gltf: json + .bin buffers
    for name, blob in files.items():
        target = tmp_path / (path.name if name == "model.gltf" else name)
        target.write_bytes(blob if isinstance(blob, bytes) else blob.encode())
    solid = load_part(path)
    assert solid.volume() == pytest.approx(volume, rel=FILE_ROUND_TRIP_RTOL)
    np.testing.assert_allclose(solid.bounding_box(), (0, 0, 0, 40, 30, 20), atol=1e-5)
    assert load_part(str(path)).volume() == pytest.approx(volume, rel=FILE_ROUND_TRIP_RTOL)


def test_another_programs_gltf_in_metres_is_read_as_metres_y_up(tmp_path):
    """glTF is metres with +Y up by its spec: a 0.05 m box from trimesh was a 0.05 mm speck ("too
    small to carve", an empty preview). A part under 1 unit is now read so, with a warning; the
    woodcam view reads it the same way."""
    from woodcam.export import load_textured

    box = trimesh.creation.box((0.04, 0.02, 0.03))  # metres: x 40 mm, y (up) 20 mm, z (toward the viewer) 30 mm
    box.apply_translation((0.1, 0.01, -0.05))
    path = tmp_path / "box_m.glb"
    path.write_bytes(box.export(file_type="glb"))
    with pytest.warns(WoodcamWarning, match="read as metres with \\+Y up, as glTF specifies"):
        solid = load_part(path)
    assert solid.volume() == pytest.approx(40 * 20 * 30, rel=1e-6)
    # block x = glTF x, block y = -glTF z, block z = glTF y; mm
    np.testing.assert_allclose(solid.bounding_box(), (80, 35, 0, 120, 65, 20), atol=1e-4)
    with pytest.warns(WoodcamWarning, match="read as metres"):
        mesh = load_textured(path)
    np.testing.assert_allclose(mesh.bounds, [(80, 35, 0), (120, 65, 20)], atol=1e-4)


def test_step_round_trip(tmp_path, bd):
    part = bd.Pos(50, 40, 25) * (bd.Box(40, 30, 20) - bd.Cylinder(radius=8, height=20))
    path = tmp_path / "part.step"
    bd.export_step(part, str(path))
    expected = 40 * 30 * 20 - math.pi * 8**2 * 20
    solid = load_part(path)
    assert solid.volume() == pytest.approx(expected, rel=CARVE_VOLUME_RTOL)
    assert solid.volume() == pytest.approx(load_part(part).volume(), rel=1e-9)
    np.testing.assert_allclose(solid.bounding_box(), (30, 25, 15, 70, 55, 35), atol=1e-6)


def test_a_cut_short_step_file_says_where_in_one_line(tmp_path, bd, capfd):
    """OpenCascade's parser printed its reason to stdout, in red, after woodcam's error line,
    which gave only the reader's status (IFSelect_ReturnStatus.IFSelect_RetFail); the reason is
    now in the error, and nothing else is printed."""
    whole = tmp_path / "whole.step"
    bd.export_step(bd.Box(10, 10, 10), str(whole))
    path = tmp_path / "cut.step"
    path.write_bytes(whole.read_bytes()[:1500])
    capfd.readouterr()
    with pytest.raises(WoodcamError, match=r"'.*cut\.step' is not a readable STEP file \(OpenCascade: "
                       r"Undefined Parsing: Line \d+: Incorrect syntax: .*\); "
                       r"re-export it"):
        load_part(path)
    out, err = capfd.readouterr()
    assert out == "" and err == ""
    assert load_part(whole).volume() == pytest.approx(1000)  # and the messenger is back as it was


def test_two_threads_reading_step_at_once_leave_occts_printers_as_they_were():
    """OpenCascade's message printers are global; _occt_messages swapped them with no lock, so
    a second thread reading STEP meanwhile saved the first's temporary printer as 'the old ones'
    and put it back for good. Thread A holds the swap until thread B has entered or 0.5 s
    passed; B leaves after A: with the lock B enters only after A left."""
    import threading

    pytest.importorskip("OCP")
    from OCP.Message import Message

    from woodcam.cad import parts

    messenger = Message.DefaultMessenger_s()
    before = len(list(messenger.Printers()))
    a_in, a_out = threading.Event(), threading.Event()
    both_in = threading.Barrier(2, timeout=0.5)

    def a():
        with parts._occt_messages():
            a_in.set()
            with contextlib.suppress(threading.BrokenBarrierError):
                both_in.wait()
        a_out.set()

    def b():
        with parts._occt_messages():
            with contextlib.suppress(threading.BrokenBarrierError):
                both_in.wait()
            a_out.wait(5)

    ta = threading.Thread(target=a)
    ta.start()
    assert a_in.wait(5)
    tb = threading.Thread(target=b)
    tb.start()
    ta.join(10)
    tb.join(10)
    assert len(list(messenger.Printers())) == before


def test_step_surface_model_of_shells_is_a_part(tmp_path, bd):
    """A STEP surface model (SHELL_BASED_SURFACE_MODEL: SketchUp, Blender, mesh tools) bounds
    the part with a closed shell and no solid: it was refused as 'contains no solid ...
    extrude, revolve or thicken it'."""
    box = bd.Pos(50, 40, 25) * bd.Box(20, 20, 20)
    path = tmp_path / "shell.step"
    bd.export_step(bd.Shell(box.faces()), str(path))
    assert "SHELL_BASED_SURFACE_MODEL" in path.read_text()
    solid = load_part(path)
    assert solid.volume() == pytest.approx(8000, rel=1e-9)
    np.testing.assert_allclose(solid.bounding_box(), (40, 30, 15, 60, 50, 35), atol=1e-6)
    bd.export_step(bd.Shell(box.faces()[:-1]), str(path))  # one side missing: capped, and said
    with pytest.warns(WoodcamWarning, match="was not closed.*capped each hole flat"):
        assert load_part(path).volume() == pytest.approx(8000, rel=1e-9)


def test_python_script_defining_part(tmp_path, bd):
    script = tmp_path / "my_part.py"
    script.write_text(
        "from build123d import Box, Align, Pos\n"
        "part = Pos(1, 2, 3) * Box(10, 20, 30, align=Align.MIN)\n"
        "if __name__ == '__main__':\n"
        "    raise SystemExit('the command-line block must not run when woodcam loads a part')\n"
    )
    solid = load_part(script)
    assert solid.volume() == pytest.approx(6000, rel=1e-12)
    np.testing.assert_allclose(solid.bounding_box(), (1, 2, 3, 11, 22, 33), atol=1e-9)


def test_python_script_imports_helpers_next_to_it(tmp_path):
    (tmp_path / "my_dimensions.py").write_text("SIDE = 7.0\n")
    script = tmp_path / "uses_helper.py"
    script.write_text("import manifold3d\nfrom my_dimensions import SIDE\n"
                      "part = manifold3d.Manifold.cube((SIDE, SIDE, SIDE))\n")
    assert load_part(script).volume() == pytest.approx(343, rel=1e-12)


def test_cadquery_scripts_showing_result_and_assemblies(tmp_path, cq):
    """CQ-editor scripts end with `show_object(result)` (a NameError before) and assemble
    parts with cq.Assembly (refused before): the shown objects, the assembly's parts where it
    puts them."""
    shown = tmp_path / "shown.py"
    shown.write_text("import cadquery as cq\n"
                     "result = cq.Workplane().box(10, 10, 10).translate((20, 20, 20))\n"
                     "show_object(result, name='body', options={'color': 'red'})\n"
                     "show_object(cq.Workplane().box(10, 10, 10).translate((40, 20, 20)))\n")
    solid = load_part(shown)
    assert solid.volume() == pytest.approx(2000, rel=1e-9)
    np.testing.assert_allclose(solid.bounding_box(), (15, 15, 15, 45, 25, 25), atol=1e-6)
    unshown = tmp_path / "unshown.py"
    unshown.write_text("import cadquery as cq\nresult = cq.Workplane().box(10, 10, 10)\n")
    with pytest.raises(WoodcamError, match="defines `result`.*add `part = result`"):
        load_part(unshown)
    assembly = cq.Assembly()
    assembly.add(cq.Workplane().box(20, 20, 20), name="a", loc=cq.Location((30, 40, 25)))
    assembly.add(cq.Workplane().box(20, 20, 20), name="b", loc=cq.Location((70, 40, 25)))
    solid = load_part(assembly)
    assert solid.volume() == pytest.approx(16000, rel=1e-9)
    np.testing.assert_allclose(solid.bounding_box(), (20, 30, 15, 80, 50, 35), atol=1e-6)


def test_a_script_showing_objects_in_a_loop_loads_them_all(tmp_path):
    """`for part in parts: show_object(part)` loaded only the last (`part` won, 1000 mm^3 of
    2000, no word): the shown objects win; a `part` not among them is named in a warning."""
    import warnings

    from woodcam.errors import WoodcamWarning

    loop = tmp_path / "loop.py"
    loop.write_text("import manifold3d\n"
                    "parts = [manifold3d.Manifold.cube((10, 10, 10)).translate((x, 0, 0)) for x in (0, 20)]\n"
                    "for part in parts:\n    show_object(part)\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert load_part(loop).volume() == pytest.approx(2000, rel=1e-12)
    other = tmp_path / "other.py"
    other.write_text("import manifold3d\npart = manifold3d.Manifold.cube((10, 10, 10))\n"
                     "show_object(manifold3d.Manifold.cube((2, 2, 2)))\n")
    with pytest.warns(WoodcamWarning, match=r"defines `part` and passes 1 other object to show_object: "
                                            r"loaded what it shows.*pass it to show_object too"):
        assert load_part(other).volume() == pytest.approx(8, rel=1e-12)


def test_python_script_with_trimesh_part(tmp_path):
    script = tmp_path / "mesh_part.py"
    script.write_text("import trimesh\npart = trimesh.creation.box(extents=(2, 3, 4))\n")
    assert load_part(script).volume() == pytest.approx(24, rel=1e-12)


_UNREADABLE = r"(not a valid mesh|could not be read)"


@pytest.mark.parametrize(("name", "content", "pattern"), [
    ("garbage.stl", "this is not a mesh\n", r"mesh file '.*garbage\.stl'.*" + _UNREADABLE),
    ("empty.stl", "", r"part file '.*empty\.stl' is empty \(0 bytes\): the export was cut short"),
    ("empty.step", "", r"part file '.*empty\.step' is empty \(0 bytes\).*export the part"),
    ("garbage.obj", "hello\nworld\n", r"mesh file '.*garbage\.obj'.*" + _UNREADABLE),
    ("garbage.glb", "not a glb", r"mesh file '.*garbage\.glb'.*could not be read"),
    ("garbage.step", "ISO-10303-21; nonsense", r"'.*garbage\.step' is not a readable STEP file"),
    ("no_part.py", "x = 1\n",
     r"script '.*no_part\.py' does not define a module-level variable `part`"),
    ("broken.py", "x = 1\n\nraise RuntimeError('boom')\n",
     r"script '.*broken\.py' failed at line 3 with RuntimeError: boom"),
    ("helper_fails.py", "import json\n\npart = json.loads('{')\n",
     r"script '.*helper_fails\.py' failed at line 3 with JSONDecodeError"),
    ("exits.py", "import sys\nsys.exit(3)\n", r"script '.*exits\.py' called sys\.exit\(3\)"),
    ("wrong_type.py", "part = 3.5\n",
     r"`part` of script '.*wrong_type\.py'.*cannot use an object of type builtins\.float"),
    ("path_part.py", "part = 'other.stl'\n", r"`part` of script '.*path_part\.py' is a path"),
    ("part.txt", "10 10 10", r"unsupported suffix '\.txt'; use one of \.step"),
])
def test_bad_files_raise_clear_errors(tmp_path, name, content, pattern):
    path = tmp_path / name
    path.write_text(content)
    with pytest.raises(WoodcamError, match=pattern):
        load_part(path)


@pytest.mark.parametrize("stated", [0, 5, 999])
def test_a_binary_stl_whose_header_miscounts_its_triangles_is_read_by_its_size(tmp_path, stated):
    """A binary STL whose header's count disagrees with its size (0 from some exporters) was
    refused as 'contains no triangles' (trimesh read it as nothing); it is read by its size, said."""
    box = trimesh.creation.box(extents=(10, 20, 30))
    data = bytearray(box.export(file_type="stl"))
    data[80:84] = stated.to_bytes(4, "little")
    path = tmp_path / "box.stl"
    path.write_bytes(bytes(data))
    with pytest.warns(WoodcamWarning, match=rf"'.*box\.stl' is a binary STL whose header says {stated} "
                      r"triangles but whose size holds 12; woodcam read the 12"):
        solid = load_part(path)
    assert solid.volume() == pytest.approx(6000, rel=1e-9)


@pytest.mark.parametrize(("body", "fix"), [
    ("import trimesh\nbox = trimesh.creation.box((10, 10, 10))\n", r"it defines trimesh Trimesh `box`: add `part = box`"),
    ("import trimesh\nimport math\nbox = trimesh.creation.box((10, 10, 10))\nlid = box.copy()\nn = 3\n",
     r"it defines trimesh Trimesh `box`, trimesh Trimesh `lid`: add `part = \[box, lid\]` \(their union\) or pass "
     r"the one you mean to show_object"),
    ("import math\nx = math.pi\n", r"add e\.g\. `part = Box\(10, 10, 10\)`"),
    ("import manifold3d\n\nif __name__ == '__main__':\n    part = manifold3d.Manifold.cube((1, 1, 1))\n",
     r"its `if __name__ == \"__main__\":` block does not run when woodcam loads the script \(as when it is "
     r"imported\): build `part` at module level, outside that block$"),
])
def test_a_script_without_part_is_told_which_of_its_shapes_to_name(tmp_path, body, fix):
    """A script of `box = ...` and `lid = ...` but no `part` was told to add `part = Box(10, 10,
    10)`, as if it built nothing; the fix names the shapes it built."""
    path = tmp_path / "shapes.py"
    path.write_text(body)
    with pytest.raises(WoodcamError, match=r"does not define a module-level variable `part` nor call show_object; "
                       + fix):
        load_part(path)


def test_a_timeout_a_library_turned_into_its_own_error_is_still_the_timeout(tmp_path):
    """The alarm of --timeout landing in build123d's import (OCP, pybind11) came back as
    'ImportError: initialization failed', and bake said 'part script ... failed at line 2 with
    ImportError: initialization failed; ... fix the script'. It is the timeout."""
    path = tmp_path / "slow.py"
    path.write_text("import time\ntry:\n    time.sleep(5)\nexcept BaseException as err:  # as pybind11 does\n"
                    "    raise ImportError('initialization failed') from err\n")
    with pytest.raises(WoodcamError, match=r"loading the part '.*slow\.py' took longer than the timeout of 0\.5 s; "
                       r"raise --timeout"):
        load_part(path, timeout_s=0.5)


def test_a_scripts_prints_go_to_stderr_named_apart_from_the_commands_output(tmp_path, capsys):
    """A part script's print() shared stdout with woodcam's own output ('woodcam bake box.py ...
    | tail -1' read the script's last print, not the summary). CQ-editor shows a script's prints
    in its log, apart from the part: here each line goes to stderr after the script's name,
    a print without its newline too, and stdout is woodcam's alone."""
    from woodcam.cli import main

    path = tmp_path / "box.py"
    path.write_text("import sys, trimesh\nprint('wall', 4, 'mm')\nprint('two\\nlines')\n"
                    "part = trimesh.creation.box((10, 10, 10))\npart.apply_translation((50, 40, 25))\n"
                    "print('no newline', end='')\n")
    capsys.readouterr()
    assert load_part(path).volume() == pytest.approx(1000)
    assert capsys.readouterr() == ("", "box.py: wall 4 mm\nbox.py: two\nbox.py: lines\nbox.py: no newline\n")
    print("after")  # stdout is the stream's own again
    assert capsys.readouterr().out == "after\n"
    assert main(["bake", str(path), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "b.glb"), "--no-obj",
                 "--texels-per-mm", "1"]) == 0
    out, err = capsys.readouterr()
    assert "wall 4" not in out and out.startswith("b: 12 triangles"), out
    assert err.startswith("box.py: wall 4 mm\nbox.py: two\n"), err


def test_a_scripts_prints_pass_a_progress_bar_being_drawn(tmp_path, monkeypatch):
    """A script's line written straight to stderr landed inside a progress bar's line (the
    bake's stage bar is drawn on stderr while the script runs): each goes through tqdm.write,
    which clears the bar and draws it again below."""
    import woodcam._progress as progress

    said = []
    monkeypatch.setattr(progress, "write", lambda line, file=None: said.append(line))
    path = tmp_path / "box.py"
    path.write_text("import trimesh\nprint('wall 4 mm')\npart = trimesh.creation.box((10, 10, 10))\n")
    load_part(path)
    assert said == ["box.py: wall 4 mm"]


def test_a_cq_editor_script_calling_debug_and_log_loads_what_it_shows(tmp_path, capsys):
    """CQ-editor gives its scripts debug() (a helper shape drawn red, not the part) and log();
    a script calling them failed with NameError, and one relying on its `cq` was not told why."""
    path = tmp_path / "cqed.py"
    path.write_text("import trimesh\nbox = trimesh.creation.box((10, 10, 10))\nhelper = trimesh.creation.box((99, 1, 1))\n"
                    "debug(helper)\nlog('built the box')\nshow_object(box)\n")
    capsys.readouterr()
    assert load_part(path).volume() == pytest.approx(1000)
    assert capsys.readouterr().err == "cqed.py: built the box\n"  # as the script's prints: named, on stderr
    path.write_text("r = cq.Workplane('XY').box(1, 1, 1)\nshow_object(r)\n")
    with pytest.raises(WoodcamError, match=r"failed at line 1 with NameError: name 'cq' is not defined \(CQ-editor "
                       r"imports cadquery as `cq` for its scripts: add `import cadquery as cq`\)"):
        load_part(path)


def test_a_sketch_shown_beside_the_solid_is_left_out_and_said(tmp_path, cq, bd):
    """CQ-editor scripts show the profile beside the solid made from it; the union of what is
    shown refused the script ('cannot use an object of type cadquery.sketch.Sketch', or 'contains
    no solid nor shell'). What holds no volume is left out, named; a script showing nothing with
    volume is still refused."""
    path = tmp_path / "profile.py"
    path.write_text("import cadquery as cq\ns = cq.Sketch().rect(20, 20)\n"
                    "show_object(s, name='profile')\nshow_object(cq.Workplane().box(10, 10, 10))\n"
                    "show_object(cq.Workplane().rect(5, 5))\n")
    with pytest.warns(WoodcamWarning, match=r"'.*profile\.py' shows 2 objects with no volume \(show_object\[0\] "
                      r"\('profile'\), a cadquery Sketch; show_object\[2\], a cadquery Workplane\): left out of the part"):
        assert load_part(path).volume() == pytest.approx(1000)
    path.write_text("from build123d import Box, Rectangle\nshow_object(Rectangle(5, 5))\nshow_object(Box(10, 10, 10))\n")
    with pytest.warns(WoodcamWarning, match=r"show_object\[0\], a build123d Rectangle\): left out"):
        assert load_part(path).volume() == pytest.approx(1000)
    path.write_text("from build123d import Rectangle\nshow_object(Rectangle(5, 5))\nshow_object(Rectangle(6, 6))\n")
    with pytest.raises(WoodcamError, match="contains no solid nor shell"):
        load_part(path)


def test_a_script_showing_its_part_in_the_ocp_cad_viewer_loads_what_it_shows(tmp_path):
    """build123d's docs show parts with ocp_vscode's show(); a script importing it failed with
    ModuleNotFoundError (or, with the viewer installed, sent its part there and woodcam got none).
    While the script runs, ocp_vscode is woodcam's: show() and show_object() give the part, the
    rest does nothing; the real module (or its absence) is back after."""
    import sys

    path = tmp_path / "viewed.py"
    path.write_text("import manifold3d\nfrom ocp_vscode import show, set_port, Camera\nset_port(3939)\n"
                    "a = manifold3d.Manifold.cube((10, 10, 10))\nb = a.translate((20, 0, 0))\n"
                    "show(a, b, names=['a', 'b'], reset_camera=Camera.ISO)\n")
    before = sys.modules.get("ocp_vscode")
    assert load_part(path).volume() == pytest.approx(2000)
    assert sys.modules.get("ocp_vscode") is before
    path.write_text("import manifold3d\nfrom ocp_vscode import *\nset_defaults(ortho=True)\n"
                    "show_object(manifold3d.Manifold.cube((10, 10, 10)))\n")
    assert load_part(path).volume() == pytest.approx(1000)


def test_missing_file_raises(tmp_path):
    with pytest.raises(WoodcamError, match="does not exist"):
        load_part(tmp_path / "nowhere.stl")


def test_triangle_budget_remeshes_looser_and_says_so(bd):
    """A finely meshed torus (46k triangles at 0.01 mm) is re-meshed under a 20k budget; the
    volume stays within the looser chord tolerance of the exact 2 pi^2 R r^2."""
    torus = bd.Pos(30, 30, 30) * bd.Torus(20, 6)
    exact = 2 * math.pi ** 2 * 20 * 6 ** 2
    free: dict = {}
    load_part(torus, tolerance_mm=0.01, max_triangles=None, report=free)
    assert free["triangles"] > 40_000 and free["notes"] == []
    budget: dict = {}
    solid = load_part(torus, tolerance_mm=0.01, max_triangles=20_000, report=budget)
    assert budget["triangles"] <= 20_000
    assert budget["tolerance_mm"] > 0.01
    assert "exceeded max_triangles=20000; re-meshed to" in budget["notes"][0]
    # chord error shrinks the inscribed mesh: at most area x tolerance below the exact volume
    area = 4 * math.pi ** 2 * 20 * 6
    assert exact - area * budget["tolerance_mm"] <= solid.volume() <= exact
    tight: dict = {}
    load_part(torus, tolerance_mm=0.01, max_triangles=500, report=tight)
    assert "still over" in tight["notes"][0]
    with pytest.raises(WoodcamError, match="max_triangles must be an integer >= 100"):
        load_part(torus, max_triangles=5)


def _chord_depth(solid, radius):
    """Largest depth (mm) of a triangle edge's midpoint below the surface of a sphere of
    ``radius`` centred at the origin: the mesh's chord error, sampled."""
    mesh = solid.to_mesh()
    tri = np.asarray(mesh.vert_properties)[:, :3][np.asarray(mesh.tri_verts)]
    mids = np.concatenate([(tri[:, i] + tri[:, (i + 1) % 3]) / 2 for i in range(3)])
    return float((radius - np.linalg.norm(mids, axis=1)).max())


def test_default_tolerance_scales_with_part_size_and_texel_size(bd):
    """Issue 16: the chord tolerance follows the part (0.1 % of its diagonal) and the texel (a
    quarter of it), and the mesh keeps well under a texel: edge midpoints of a sphere lie within
    half a texel of its surface (OpenCascade overshoots its nominal deflection up to ~2 x)."""
    from woodcam.cad.parts import auto_tolerance_mm

    cases = [  # radius mm, texels/mm, expected tolerance
        (5.0, 10.0, 1e-3 * math.sqrt(3) * 10.0),      # small part: size-bound, 0.017 mm
        (100.0, 10.0, 0.025),                          # large part: texel-bound
        (100.0, 2.0, 0.125),                           # coarser texels: looser
    ]
    depths = []
    for radius, tpm, expected in cases:
        report: dict = {}
        solid = load_part(bd.Sphere(radius=radius), texels_per_mm=tpm, report=report)
        assert report["tolerance_mm"] == pytest.approx(expected, rel=1e-6)
        assert report["tolerance_mm"] == pytest.approx(
            auto_tolerance_mm(2 * math.sqrt(3) * radius, tpm), rel=1e-6)
        assert report["tolerance_rule"].startswith("auto: min(")
        depth = _chord_depth(solid, radius)
        assert 0 < depth <= 0.55 / tpm  # well under one texel
        assert depth <= 2.2 * report["tolerance_mm"]
        depths.append(depth)
    # on the large sphere the chord, not the 5-degree angle, bounds the facets: 5 x coarser
    # texels give facets at least 2.5 x deeper
    assert depths[2] > 2.5 * depths[1]
    given: dict = {}
    load_part(bd.Sphere(radius=5.0), tolerance_mm=0.2, report=given)
    assert given["tolerance_mm"] == 0.2 and given["tolerance_rule"] == "given"
    with pytest.raises(WoodcamError, match="texels_per_mm must be a finite number > 0"):
        load_part(bd.Sphere(radius=5.0), texels_per_mm=0)


def test_a_large_part_stays_under_the_triangle_budget(bd):
    """A 200 mm sphere at 10 texels/mm meshes to 40k triangles at the texel-bound 0.025 mm:
    re-meshed under a 12k budget, and the report says so; at 1 texel/mm (0.25 mm) it fits.
    (The default budget of 120k triangles is reached by a ~0.6 m sphere: 8 s to mesh.)"""
    sphere = bd.Sphere(radius=100.0)
    fine: dict = {}
    load_part(sphere, max_triangles=12_000, report=fine)
    assert fine["triangles"] <= 12_000 and fine["max_triangles"] == 12_000
    assert "exceeded max_triangles=12000; re-meshed to" in fine["notes"][0]
    assert fine["tolerance_mm"] > 0.025
    coarse: dict = {}
    load_part(sphere, texels_per_mm=1.0, max_triangles=12_000, report=coarse)
    assert coarse["notes"] == [] and coarse["triangles"] <= 12_000
    assert coarse["tolerance_mm"] == pytest.approx(0.25)


def test_shells_beside_a_solid_are_named_not_dropped_silently(tmp_path, bd):
    """Shells were used only when there was no solid: a STEP (or compound) with a solid and a
    separate shell body lost the shell without a word."""
    solid = bd.Pos(20, 20, 20) * bd.Box(10, 10, 10)
    shell = bd.Shell((bd.Pos(60, 20, 20) * bd.Box(10, 10, 10)).faces())
    path = tmp_path / "mixed.step"
    bd.export_step(bd.Compound([solid, shell]), str(path))
    with pytest.warns(WoodcamWarning, match=r"mixed.step' holds 1 solid and 1 shell \(surface body\) outside any "
                                            r"solid: carved the solids only, the 1 shell left out; if it belongs"):
        assert load_part(path).volume() == pytest.approx(1000, rel=1e-9)
