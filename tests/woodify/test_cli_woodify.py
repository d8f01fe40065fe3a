"""``woodcam woodify`` writes its products, and ``bake --block woodify:...`` carves from them."""

from __future__ import annotations

import json
import re
import time
from pathlib import Path

import numpy as np
import pytest
import trimesh

from woodcam.cli import main
from woodcam.errors import WoodcamError
from woodcam.stock import open_stock
from woodcam.woodify import WoodifiedField

REPO = Path(__file__).resolve().parents[2]


def _rc(argv) -> int:
    """``main``'s exit status, also for argparse's usage errors (a SystemExit)."""
    try:
        return main(argv)
    except SystemExit as exit_:
        return exit_.code


@pytest.fixture(scope="module")
def grown_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("woodify")
    trunk = trimesh.creation.cylinder(radius=6.0, height=30.0, sections=32)
    trunk.export(d / "trunk.stl")
    out = d / "tree"
    rc = main(["woodify", str(d / "trunk.stl"), "--years", "8", "--growth", "30",
               "--eccentricity", "0.2", "--up", "1,0,0", "--resolution", "48", "--crack-years", "2",
               "--block-size", "100x80x50", "--block-centre", "5,0,0", "--out", str(out)])
    assert rc == 0
    return out


def test_woodify_writes_field_surfaces_sections_and_bark(grown_dir):
    for name in ("field.npz", "grown.glb", "section_xz.png", "section_xy.png", "woodify.json",
                 "surface_y2.stl", "surface_y4.stl", "surface_y6.stl"):
        assert (grown_dir / name).is_file(), name
    assert not list(grown_dir.glob("tmp*")), "temporary files left behind"
    s = trimesh.load(grown_dir / "surface_y4.stl")
    assert s.is_watertight
    # STL has no unit field: the header states it (it was 80 zero bytes)
    header = (grown_dir / "surface_y4.stl").read_bytes()[:80]
    assert header.startswith(b"woodcam: units=mm woodify surface at year 4, in the input mesh's frame"), header
    # ... and the input's frame it is: the grown trunk straddles the input's origin (its centre)
    # on every axis, where the block frame's coordinates are all >= 0
    assert (s.bounds[0] < 0).all() and (s.bounds[1] > 0).all(), s.bounds
    f = WoodifiedField.load(grown_dir / "field.npz")
    assert f.block_size_mm == (100.0, 80.0, 50.0)
    # block centre (5, 0, 0) in the object: the block's centre point is 5 mm off the trunk axis
    # inside the input (year 0); a block corner lies beyond the final bark (> 8 years)
    assert f(np.array([[50.0, 40.0, 25.0]]))[0] == 0.0
    assert f(np.array([[0.0, 0.0, 0.0]]))[0] > 8.0
    from woodcam.export import load_textured

    glb = load_textured(grown_dir / "grown.glb")
    assert glb.visual.uv is not None and len(glb.faces) > 100
    # the GLB says it is in the block frame, and is: the grown trunk (axis along the input's x)
    # is the object frame moved by -block_origin, not the input mesh's frame (review placed its
    # section colours 25 mm off the mesh)
    meta = __import__("woodcam.export", fromlist=["x"]).read_glb_metadata(grown_dir / "grown.glb")
    assert meta["frame"] == "block"
    origin = np.asarray(meta["woodify"]["block_origin_mm"])
    np.testing.assert_allclose(origin, f.block_origin_mm)
    # the bark is the surface of the last year: the block's field reads 8 years on its vertices
    assert np.percentile(np.abs(f(glb.vertices) - 8.0), 95) < 0.2
    summary = json.loads((grown_dir / "woodify.json").read_text())
    assert summary["method"] == "offset" and summary["cracks"]["count"] >= 0


def test_bake_carves_a_bowl_from_the_grown_wood(grown_dir, tmp_path):
    spec = f"woodify:{grown_dir / 'field.npz'}"
    stock = open_stock(spec)
    assert stock.size_mm == (100.0, 80.0, 50.0)
    out = tmp_path / "bowl.glb"
    rc = main(["bake", str(REPO / "cad_examples" / "bowl.py"), "--block", spec, "--out", str(out),
               "--texels-per-mm", "1.5", "--no-obj"])
    assert rc == 0 and out.stat().st_size > 10_000


def test_a_glb_baked_from_a_grown_block_reopens_its_wood(grown_dir, tmp_path, monkeypatch):
    """A part baked from 'woodify:DIR/field.npz' recorded the block as the folder
    '<cwd>/woodify:DIR/field.npz': preview and review of it failed ('not there any more'), and
    its digest was of the spec's text, blind to a changed field.npz."""
    import shutil

    from woodcam.cli.options import stock_of_glb
    from woodcam.errors import WoodcamWarning
    from woodcam.export import read_glb_metadata
    from woodcam.pipeline import preview_mesh

    shutil.copy(grown_dir / "field.npz", tmp_path / "field.npz")
    monkeypatch.chdir(tmp_path)
    stock = open_stock("woodify:field.npz")
    box = trimesh.creation.box((20.0, 16.0, 10.0))
    box.apply_translation([50.0, 40.0, 25.0])
    glb = preview_mesh(box, stock, tmp_path / "part.glb", texels_per_mm=1.0, obj=False,
                       screenshot=False).files["glb"]
    assert read_glb_metadata(glb)["block"] == f"woodify:{tmp_path / 'field.npz'}"
    monkeypatch.chdir(grown_dir)
    again = stock_of_glb(glb)
    p = np.random.default_rng(0).uniform(5.0, 45.0, (200, 3))
    n = np.tile([0.0, 0.0, 1.0], (len(p), 1))
    np.testing.assert_allclose(again.wood.color(p, n), stock.wood.color(p, n), atol=1e-6)
    # another grown field under the same name: a warning; none: an error naming the file
    f = WoodifiedField.load(tmp_path / "field.npz")
    f.placed((90.0, 80.0, 50.0), tuple(f.block_origin_mm + (45.0, 40.0, 25.0))).save(tmp_path / "field.npz")
    with pytest.warns(WoodcamWarning, match="changed since part.glb was baked"):
        stock_of_glb(glb)
    (tmp_path / "field.npz").unlink()
    with pytest.raises(WoodcamError, match="field.npz', which is not there any more; pass --block"):
        stock_of_glb(glb)


def test_cli_errors_are_one_line(tmp_path, capsys):
    m = trimesh.creation.icosphere(subdivisions=2, radius=5.0)
    m.export(tmp_path / "ball.stl")
    assert main(["woodify", str(tmp_path / "ball.stl"), "--years", "0", "--out", str(tmp_path / "o")]) == 2
    assert "--years must be in (0, 10000]" in capsys.readouterr().err
    # each was accepted (exit 0, silently clamped) or a ZeroDivisionError traceback after the growth
    for opt, value, said in (("--growth", "1e20", "--growth must be in (0, 10000]"),
                             ("--crack-years", "0", "--crack-years must be in [1, 1000]"),
                             ("--crack-threshold", "-1", "--crack-threshold must be in (0,"),
                             ("--crack-region", "0,0,0,-5", "--crack-region X,Y,Z,R needs a radius R > 0"),
                             ("--block-size", "1e300x10x10", "--block-size takes WxDxH in mm"),
                             ("--block-centre", "1e300,0,0", "--block-centre must be in [-100000, 100000]"),
                             ("--shape", "1e300", "--shape must be in (0, 100]")):
        t0 = time.perf_counter()
        assert _rc(["woodify", str(tmp_path / "ball.stl"), "--years", "3", "--resolution", "256",
                     "--out", str(tmp_path / "o"), f"{opt}={value}"]) in (1, 2), opt  # 2: a range (usage)
        assert time.perf_counter() - t0 < 10.0, f"{opt}: refused only after the growth (a minute at 256)"
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and said in err, err
    # an open mesh is named with its option and file (the growth said 'obstacles[0] must be
    # watertight' of an --obstacle, and 'mesh must be ...' of the part)
    trimesh.Trimesh(m.vertices, m.faces[:-4]).export(tmp_path / "open.stl")
    assert main(["woodify", str(tmp_path / "open.stl"), "--years", "3", "--out", str(tmp_path / "o")]) == 1
    assert f"part {str(tmp_path / 'open.stl')!r} must be watertight" in capsys.readouterr().err
    assert main(["woodify", str(tmp_path / "ball.stl"), "--obstacle", str(tmp_path / "open.stl"), "--years", "3",
                 "--out", str(tmp_path / "o")]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"--obstacle {str(tmp_path / 'open.stl')!r} must be watertight" in err, err
    with pytest.raises(WoodcamError, match="does not exist"):
        open_stock(f"woodify:{tmp_path / 'missing.npz'}")


def test_an_empty_or_nan_mesh_is_one_error_naming_the_file(tmp_path, capsys):
    """An empty STL was an internal error (TypeError unpacking its bounds); a NaN vertex in an
    OBJ or STL was welded away with its triangles and the rest refused as not watertight
    ('1 triangles'), naming neither the NaN nor the file; the library grew on a NaN box."""
    import struct

    from woodcam.woodify import woodify

    (tmp_path / "empty.stl").write_text("solid e\nendsolid e\n")
    (tmp_path / "nan.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 nan\n"
                                      "f 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n")
    tris = [(0, 0, 0, 1, 0, 0, 0, 1, 0), (0, 0, 0, 1, 0, 0, 0, 0, np.nan),
            (0, 0, 0, 0, 1, 0, 0, 0, np.nan), (1, 0, 0, 0, 1, 0, 0, 0, np.nan)]
    (tmp_path / "nan.stl").write_bytes(b"\0" * 80 + struct.pack("<I", 4) + b"".join(
        struct.pack("<12fH", 0, 0, 0, *t, 0) for t in tris))
    for name, said in (("empty.stl", "holds no triangles"), ("nan.obj", "1 of 4 vertices that are not finite"),
                       ("nan.stl", "vertices that are not finite numbers (NaN or inf)")):
        assert main(["woodify", str(tmp_path / name), "--years", "2", "--resolution", "16",
                     "--out", str(tmp_path / "o")]) == 1, name
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and f"part {str(tmp_path / name)!r} " in err and said in err, err
    assert not (tmp_path / "o").exists()
    box = trimesh.creation.box((10.0, 10.0, 10.0))
    v = box.vertices.copy()
    v[0, 2] = np.inf
    with pytest.raises(WoodcamError, match="mesh has 1 of 8 vertices that are not finite"):
        woodify(trimesh.Trimesh(v, box.faces, process=False), 2.0, resolution=16)


def _two_box_scenes(tmp_path, glb_placed_twice):
    """A GLB of two boxes (centres x = 0 and 30) and a GLB of one box placed at both."""
    a, b = trimesh.creation.box((10.0, 10.0, 10.0)), trimesh.creation.box((10.0, 10.0, 10.0))
    b.apply_translation((30.0, 0.0, 0.0))
    two = trimesh.Scene()
    two.add_geometry(a, geom_name="a")
    two.add_geometry(b, geom_name="b")
    two.export(tmp_path / "two.glb")
    return tmp_path / "two.glb", glb_placed_twice(tmp_path / "twice.glb")


def test_a_file_of_several_meshes_grows_all_of_them(tmp_path, capsys, glb_placed_twice):
    """A GLB of two meshes was refused by load_textured ('holds 2 meshes'), and a GLB of one mesh
    placed twice grew its first placement alone, the other dropped without a word: both boxes
    grow now (their union, as a part file's meshes), year 0 inside each."""
    for path in _two_box_scenes(tmp_path, glb_placed_twice):
        out = tmp_path / f"o_{path.stem}"
        assert main(["woodify", str(path), "--years", "2", "--resolution", "24", "--cracks", "none",
                     "--out", str(out)]) == 0, capsys.readouterr().err
        f = WoodifiedField.load(out / "field.npz")
        centres = np.array([[0.0, 0.0, 0.0], [30.0, 0.0, 0.0]]) - f.block_origin_mm
        np.testing.assert_array_equal(f(centres), [0.0, 0.0])
        assert f.block_size_mm[0] > 40.0, "the grown object spans both boxes"


def test_an_open_mesh_in_a_file_of_several_is_named_with_its_option_and_file(tmp_path, capsys):
    """A file of several meshes skipped the open-mesh check of a one-mesh file: two boxes
    touching along an edge were refused by the growth as 'mesh must be watertight' (an
    --obstacle: 'obstacles[0] ...'), naming neither the option nor the file; a box missing a
    side was capped flat with a warning (a one-mesh file is refused) and a sphere missing
    triangles refused as 'mesh file ...', without the option. Now each mesh and their union go
    through the same check, naming the option, the file and the mesh; the touching union says
    why and its fix (it suggested trimesh.repair.fill_holes, for meshes each closed); an open
    mesh is told how to close it in a CAD or mesh program."""
    a = trimesh.creation.box((10.0, 10.0, 10.0))
    ball = trimesh.creation.icosphere(subdivisions=2, radius=5.0)
    ball.export(tmp_path / "ball.stl")
    touching, lidless, holed = a.copy(), trimesh.Trimesh(a.vertices, a.faces[:-2]), \
        trimesh.Trimesh(ball.vertices, ball.faces[:-4])
    touching.apply_translation((10.0, 10.0, 0.0))
    for m in (lidless, holed):
        m.apply_translation((30.0, 0.0, 0.0))
    for name, b, said in (("touching", touching, "(the union of its 2 meshes)"),
                          ("lidless", lidless, "(its mesh 'b')"), ("holed", holed, "(its mesh 'b')")):
        scene = trimesh.Scene()
        scene.add_geometry(a, geom_name="a")
        scene.add_geometry(b, geom_name="b")
        path = str(tmp_path / f"{name}.glb")
        scene.export(path)
        for what, args in (("part", [path]), ("--obstacle", [str(tmp_path / "ball.stl"), "--obstacle", path])):
            assert main(["woodify", *args, "--years", "2", "--resolution", "16", "--cracks", "none",
                         "--out", str(tmp_path / "o")]) == 1, (name, what)
            err = capsys.readouterr().err
            assert err.count("\n") == 1 and f"error: {what} {path!r} {said} must be watertight" in err, err
            touch = "touch along an edge or at a vertex" in err and "non-manifold union" in err
            assert touch == (name == "touching") and ("Close Holes" in err) == (name != "touching"), err
            assert "fill_holes" not in err, err
    assert not (tmp_path / "o").exists()


def _longest_black_run(rows) -> int:
    """Longest run of black pixels along any row of ``rows`` (r, c, 3) uint8."""
    black = np.pad(rows.max(axis=-1) < 60, ((0, 0), (1, 1)))
    edges = np.diff(black.astype(np.int8), axis=1)
    return max(int((np.flatnonzero(e == -1) - np.flatnonzero(e == 1)).max(initial=0)) for e in edges)


def test_scale_bar_is_a_round_length_in_the_units_drawn_under_the_picture():
    from woodcam.woodify.surfaces import scale_bar_mm, with_scale_bar

    # the longest 1-2-5 length at most a fifth of the width, in the units asked for
    assert scale_bar_mm(72.0) == 10.0 and scale_bar_mm(100.0) == 20.0 and scale_bar_mm(30.0) == 5.0
    assert scale_bar_mm(72.0, "inch") == pytest.approx(12.7)  # 0.5 in of a 2.83 in picture
    assert scale_bar_mm(254.0, "inch") == pytest.approx(50.8)  # 2 in of 10 in
    with pytest.raises(WoodcamError, match="width_mm must be a length > 0"):
        scale_bar_mm(0.0)
    picture = np.full((50, 640, 3), 200, np.uint8)
    out, length = with_scale_bar(picture, 0.1)  # 64 mm wide: a 10 mm bar, 100 px
    assert length == 10.0 and out.shape[0] > 50 and out.shape[1:] == (640, 3)
    np.testing.assert_array_equal(out[:50], picture)  # the picture itself is untouched
    assert _longest_black_run(out[50:]) == 100


def test_section_pictures_carry_a_scale_bar_in_the_runs_units(tmp_path):
    """section_xz.png / section_xy.png had no scale: nothing in them told their size. Now a strip
    under each holds a bar of a round length in --units (its label says it), as long as that
    length at the picture's scale: the grid's width (32.1 mm here) over the 640 columns."""
    from PIL import Image

    ball = tmp_path / "ball.stl"
    trimesh.creation.icosphere(subdivisions=1, radius=5.0).export(ball)
    for units, bar_mm in (("mm", 5.0), ("inch", 5.08)):  # 5 mm, 0.2 in
        out = tmp_path / units
        assert main(["woodify", str(ball), "--years", "2", "--resolution", "16", "--cracks", "none",
                     "--units", units, "--out", str(out)]) == 0
        grid = json.loads((out / "woodify.json").read_text())["grid"]
        mm_per_px = (grid["shape"][0] - 1) * grid["spacing_mm"] / 640
        for name, axis in (("section_xz.png", 2), ("section_xy.png", 1)):
            img = np.asarray(Image.open(out / name).convert("RGB"))
            rows = max(int(640 * (grid["shape"][axis] - 1) / (grid["shape"][0] - 1)), 16)
            assert img.shape[0] > rows and img.shape[1] == 640, (name, img.shape)
            assert abs(_longest_black_run(img[rows:]) - bar_mm / mm_per_px) <= 1, (units, name)


def test_meshes_touching_at_a_single_vertex_are_refused_as_a_non_manifold_union(tmp_path, capsys):
    """Two closed tetrahedra in one GLB sharing exactly one corner (no edge): their welded union
    has every edge shared by two triangles, so trimesh calls it watertight, and it grew without
    a word, while the union's refusal says 'they touch along an edge or at a vertex'. Now the
    pinched vertex is found (the triangles round it form two fans) and refused with that
    refusal's fix, as an --obstacle too; one mesh (an STL) pinched the same way is refused with
    its own fix, naming the point."""
    tet = trimesh.Trimesh([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [0.0, 10.0, 0.0], [0.0, 0.0, 10.0]],
                          [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    other = trimesh.Trimesh(-tet.vertices, tet.faces[:, ::-1])  # mirrored through the shared corner
    assert tet.is_watertight and other.is_watertight and tet.volume > 0 and other.volume > 0
    scene = trimesh.Scene()
    scene.add_geometry(tet, geom_name="a")
    scene.add_geometry(other, geom_name="b")
    path = str(tmp_path / "corner.glb")
    scene.export(path)
    trimesh.creation.icosphere(subdivisions=2, radius=5.0).export(tmp_path / "ball.stl")
    for what, args in (("part", [path]), ("--obstacle", [str(tmp_path / "ball.stl"), "--obstacle", path])):
        assert main(["woodify", *args, "--years", "2", "--resolution", "16", "--cracks", "none",
                     "--out", str(tmp_path / "o")]) == 1, what
        err = capsys.readouterr().err
        assert err.count("\n") == 1, err
        assert f"error: {what} {path!r} (the union of its 2 meshes) must be a manifold solid" in err, err
        assert "1 vertex (the first at (0, 0, 0) mm)" in err and "non-manifold vertex" in err, err
        assert "touch along an edge or at a vertex" in err and "non-manifold union" in err, err
        assert "fill_holes" not in err, err
    one = str(tmp_path / "corner.stl")
    trimesh.util.concatenate([tet, other]).export(one)
    assert main(["woodify", one, "--years", "2", "--resolution", "16", "--cracks", "none",
                 "--out", str(tmp_path / "o")]) == 1
    err = capsys.readouterr().err
    assert f"error: part {one!r} must be a manifold solid" in err and "(0, 0, 0) mm" in err, err
    assert "move those parts apart" in err and "fill_holes" not in err, err
    assert not (tmp_path / "o").exists()


def test_surface_and_crack_years_are_usage_errors_before_the_growth(tmp_path, capsys, monkeypatch):
    """--surface-years out of range or not numbers exited 1 (a failed run, not a wrong command
    line); a year given twice was grown, written and listed twice; --crack-years beyond --years
    was clamped to year 0 without a word (8 crack years of a 3-year growth)."""
    import woodcam.woodify as wf

    grown = []
    monkeypatch.setattr(wf, "woodify", lambda *a, **k: grown.append(a) or pytest.fail("grew"))
    ball = tmp_path / "ball.stl"
    trimesh.creation.icosphere(subdivisions=1, radius=5.0).export(ball)
    for extra, said in ((["--surface-years", "1,abc"], "--surface-years takes comma-separated years in [0, 3] (--years); "
                                                    "got '1,abc'; e.g. --surface-years 1.5,3"),
                        (["--surface-years", "1,4"], "got '1,4'"),
                        (["--surface-years", "1,1.0000001"], "would both be written as surface_y1.stl"),
                        (["--crack-years", "8"], "--crack-years must be at most --years (3): it simulates the "
                                                 "last years of the growth; got 8; give --crack-years 3 or fewer")):
        assert _rc(["woodify", str(ball), "--years", "3", "--out", str(tmp_path / "o"), *extra]) == 2, extra
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and said in err, err
    assert grown == []
    # under a year: no --crack-years fits, and the default grows the cracks from the input on
    assert _rc(["woodify", str(ball), "--years", "0.5", "--crack-years", "1", "--out", str(tmp_path / "o")]) == 2
    assert "leave --crack-years out" in capsys.readouterr().err
    assert grown == []
    monkeypatch.undo()
    out = tmp_path / "twice"
    assert main(["woodify", str(ball), "--years", "3", "--resolution", "16", "--cracks", "none",
                 "--surface-years", "1,1,2", "--out", str(out)]) == 0
    summary = capsys.readouterr().out
    assert summary.count("surface_y1.stl") == 1 and sorted(p.name for p in out.glob("surface_y*.stl")) == [
        "surface_y1.stl", "surface_y2.stl"]


def test_vectors_and_sizes_are_refused_at_the_door_as_typed(tmp_path, capsys):
    """woodify parsed --up, --block-centre and --crack-region with its own _vec (exit 1, after
    --units had converted them: --block-size 1000x10x10 --units inch said '25400x254x254'); --up
    0,0,0 reached the library, which named its parameter 'up'. They are the shared vector_type /
    sizes_type and RANGES now: exit 2, the option and the value as typed; a size read in the
    units typed (--block-size 0x1x1 --units inch said 'in mm')."""
    ball = tmp_path / "ball.stl"
    trimesh.creation.icosphere(subdivisions=1, radius=5.0).export(ball)
    for extra, said in (
            (["--up", "0,0,0"], "--up '0,0,0': a direction must not be zero; e.g. 0,0,1"),
            (["--crack-region", "0,0,0"], "--crack-region '0,0,0': give 4 finite numbers X,Y,Z,R"),
            (["--crack-region=1,2,3,0"], "--crack-region X,Y,Z,R needs a radius R > 0; got R = 0 mm; "
              "e.g. --crack-region 0,0,50,10, or leave it out for cracks anywhere on the bark"),
            (["--block-size", "1000x10x10", "--units", "inch"],
             "--block-size takes WxDxH in inches (--units inch), 3 numbers in (0, 393.701] (raise it with WOODCAM_MAX_BLOCK_SIZE_MM=N), e.g. 2x2x2; "
             "got '1000x10x10'"),
            # read in the units typed: it said 'takes WxDxH in mm', read before --units was known
            (["--block-size", "0x1x1", "--units", "inch"],
             "--block-size takes WxDxH in inches (--units inch), 3 numbers in (0, 393.701] (raise it with WOODCAM_MAX_BLOCK_SIZE_MM=N), e.g. 2x2x2; "
             "got '0x1x1'"),
            (["--block-centre=5000,0,0", "--units", "inch"],
             "--block-centre must be in [-100000, 100000] mm; got 5000.0 inch = 127000 mm")):
        assert _rc(["woodify", str(ball), "--years", "3", "--out", str(tmp_path / "o"), *extra]) == 2, extra
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and said in err, err


def test_eccentricity_is_refused_by_its_option_name(tmp_path, capsys):
    """--eccentricity 1 was refused by the library as 'eccentricity must lie in (-1, 1)', exit 1."""
    for value in ("1", "-1", "2"):
        assert _rc(["woodify", str(tmp_path / "p.stl"), "--years", "3", "--out", str(tmp_path / "o"),
                    f"--eccentricity={value}"]) == 2
        assert f"--eccentricity must be in (-1, 1); got {float(value)!r}" in capsys.readouterr().err
    assert _rc(["woodify", str(tmp_path / "p.stl"), "--years", "3", "--out", str(tmp_path / "o"),
                "--eccentricity=0.999"]) == 2  # in range: on to the missing part file, a wrong command line
    assert "p.stl" in capsys.readouterr().err


def test_an_interrupted_run_leaves_the_last_runs_products(tmp_path, monkeypatch, capsys):
    """A Ctrl-C while writing left the new grown.glb and field.npz beside the old woodify.json and
    sections; and each run at other --surface-years left its surfaces beside the last run's."""
    import woodcam.cli.woodify as wcli

    trimesh.creation.icosphere(subdivisions=2, radius=5.0).export(tmp_path / "ball.stl")
    out = tmp_path / "o"

    def grow(years, surfaces):
        return main(["woodify", str(tmp_path / "ball.stl"), "--years", years, "--resolution", "24",
                     "--cracks", "none", "--surface-years", surfaces, "--out", str(out)])

    assert grow("4", "1,2") == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    real = wcli.json.dumps

    def interrupted(doc, **kw):  # Ctrl-C as the summary, the last file, is written
        if isinstance(doc, dict) and "total_s" in doc:
            raise KeyboardInterrupt
        return real(doc, **kw)

    monkeypatch.setattr(wcli.json, "dumps", interrupted)
    assert grow("6", "3") == 130
    monkeypatch.setattr(wcli.json, "dumps", real)
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before  # nothing new, no temporaries
    assert grow("6", "3") == 0
    assert sorted(p.name for p in out.glob("surface_y*.stl")) == ["surface_y3.stl"]
    assert json.loads((out / "woodify.json").read_text())["years"] == 6.0
    capsys.readouterr()


def test_the_summary_names_every_file_written(tmp_path, capsys):
    """The printed 'wrote ...' list left out woodify.json, which the README lists in out/tree/."""
    trimesh.creation.icosphere(subdivisions=2, radius=5.0).export(tmp_path / "ball.stl")
    out = tmp_path / "o"
    assert main(["woodify", str(tmp_path / "ball.stl"), "--years", "3", "--resolution", "24",
                 "--cracks", "none", "--out", str(out)]) == 0
    wrote = capsys.readouterr().out.split("; wrote ", 1)[1].splitlines()[0].split(", ")
    assert sorted(Path(f).name for f in wrote) == sorted(p.name for p in out.iterdir())


def test_input_texture_is_carried_to_the_grown_bark(tmp_path):
    """A textured input (UV = longitude, latitude) keeps its picture in place: every grown
    vertex's UV is the UV of the input point straight below it (radial growth of a sphere)."""
    from PIL import Image

    m = trimesh.creation.icosphere(subdivisions=3, radius=8.0)
    v = m.vertices / 8.0
    uv = np.c_[0.5 + np.arctan2(v[:, 1], v[:, 0]) / (2 * np.pi), 0.5 + np.arcsin(v[:, 2]) / np.pi]
    img = Image.fromarray((np.random.default_rng(0).random((64, 64, 3)) * 255).astype(np.uint8))
    m.visual = trimesh.visual.TextureVisuals(uv=uv, image=img)
    m.export(tmp_path / "ball.glb")
    out = tmp_path / "grown"
    assert main(["woodify", str(tmp_path / "ball.glb"), "--years", "5", "--growth", "6",
                 "--resolution", "40", "--cracks", "none", "--out", str(out)]) == 0
    from woodcam.export import load_textured, read_glb_metadata

    g = load_textured(out / "grown.glb")
    w = read_glb_metadata(out / "grown.glb")["woodify"]  # block frame -> the input's frame
    q = g.vertices @ np.asarray(w["block_rotation"]).T + np.asarray(w["block_origin_mm"])
    p = q / np.linalg.norm(q, axis=1, keepdims=True)
    lat = 0.5 + np.arcsin(p[:, 2]) / np.pi
    # latitude is smooth everywhere (longitude wraps at the seam): compare it
    assert np.percentile(np.abs(g.visual.uv[:, 1] - lat), 95) < 0.03


def test_ply_vertex_properties_paint_the_growth(tmp_path):
    """A PLY's per-vertex 'gain' speeds the growth where it is painted (seed sec. 4.2.2)."""
    m = trimesh.creation.icosphere(subdivisions=3, radius=8.0)
    m.vertex_attributes["gain"] = np.where(m.vertices[:, 2] > 0, 1.6, 1.0).astype(np.float32)
    (tmp_path / "ball.ply").write_bytes(trimesh.exchange.ply.export_ply(m, include_attributes=True))
    out = tmp_path / "grown"
    assert main(["woodify", str(tmp_path / "ball.ply"), "--years", "5", "--growth", "6",
                 "--resolution", "40", "--cracks", "none", "--out", str(out)]) == 0
    f = WoodifiedField.load(out / "field.npz")
    # block point = object point - block origin (no rotation); 6 mm grown where gain is 1
    top = f.arrival(np.array([[0, 0, 8 + 6 * 1.6]]) - f.block_origin_mm)
    bottom = f.arrival(np.array([[0, 0, -8 - 6.0]]) - f.block_origin_mm)
    assert top[0] == pytest.approx(6.0, abs=1.5) and bottom[0] == pytest.approx(6.0, abs=0.6)


def test_resolution_has_the_librarys_range_on_the_command_line(tmp_path, capsys):
    """--resolution went through the colour-volume cells' range [8, 256]: 512 (which the library
    grows) was refused at 256, and 12 passed the door to fail in the library (exit 1)."""
    from woodcam.cli import build_parser
    from woodcam.cli.options import check_numbers
    from woodcam.limits import WOODIFY_RESOLUTION_RANGE
    from woodcam.woodify.front import VoxelGrid

    def args(value):
        return build_parser().parse_args(["woodify", "ball.stl", "--years", "3", "--resolution", value,
                                          "--out", str(tmp_path / "o")])

    lo, hi = WOODIFY_RESOLUTION_RANGE
    check_numbers(args(str(hi)))  # accepted at the door, as by the library
    VoxelGrid.around((0, 0, 0), (1, 1, 1), hi)
    trimesh.creation.icosphere(subdivisions=1, radius=5.0).export(tmp_path / "ball.stl")
    assert _rc(["woodify", str(tmp_path / "ball.stl"), "--years", "3", "--resolution", str(lo - 4),
                "--out", str(tmp_path / "o")]) == 2
    assert f"--resolution must be in [{lo}, {hi}]; got {lo - 4}" in capsys.readouterr().err
    with pytest.raises(WoodcamError, match=f"resolution must be an integer in \\[{lo}, {hi}\\]"):
        VoxelGrid.around((0, 0, 0), (1, 1, 1), hi + 1)


def _crack_share(glb: Path, n: int = 40000) -> float:
    """Share of the bark's area (points sampled evenly over the surface of a written GLB) that
    shows the crack colour of woodcam.woodify.bark."""
    scene = trimesh.load(glb)
    m = next(iter(scene.geometry.values()))
    img = np.asarray(m.visual.material.baseColorTexture.convert("RGB"), float)
    h, w = img.shape[:2]
    pts, fi = trimesh.sample.sample_surface(m, n, seed=0)
    bary = trimesh.triangles.points_to_barycentric(m.triangles[fi], pts)
    uv = (m.visual.uv[m.faces[fi]] * bary[:, :, None]).sum(1)
    c = np.clip((uv[:, 0] % 1) * w, 0, w - 1).astype(int)
    r = np.clip((1 - uv[:, 1] % 1) * h, 0, h - 1).astype(int)
    return float((np.abs(img[r, c] - [28, 20, 14]).max(1) < 10).mean())


def test_crack_density_per_bark_area_does_not_depend_on_flatness(tmp_path):
    """The bark of a flat shape (the lid) was mostly dark: cylindrical coordinates squeeze its
    flat faces and rims into a sliver of the picture, and every crack there was drawn into that
    band (a flat disc showed 0.54 of its bark as crack, a tall cylinder with as many cracks per
    mm^2 0.20). Read back from grown.glb: the two agree."""
    shares = {}
    for name, mesh in (("disc", trimesh.creation.cylinder(radius=40.0, height=8.0, sections=64)),
                       ("stem", trimesh.creation.cylinder(radius=15.0, height=80.0, sections=64))):
        mesh.export(tmp_path / f"{name}.stl")
        assert main(["woodify", str(tmp_path / f"{name}.stl"), "--years", "6", "--resolution", "40",
                     "--cracks", "random", "--crack-years", "3", "--out", str(tmp_path / name)]) == 0
        shares[name] = _crack_share(tmp_path / name / "grown.glb")
    assert 0.05 < shares["stem"] < 0.4, shares
    assert 0.6 < shares["disc"] / shares["stem"] < 1.6, shares


def test_cracks_on_a_textured_input_cover_as_much_bark_as_untextured(tmp_path):
    """The same trunk with a picture (cylindrical UVs, its vertices split per face as many
    exporters write them) cracks as often as without one, but its cracks were drawn into the
    picture at the picture's scale (2 px of a 256 px picture: 1.3 mm wide) and piled onto its lid
    (one row of the picture): 0.35 of the bark showed as crack against 0.19 untextured. Drawn into
    an atlas of even texel density, as the untextured bark's, the two agree (0.16 here)."""
    from PIL import Image

    trunk = trimesh.creation.cylinder(radius=12.0, height=60.0, sections=48)
    trunk.export(tmp_path / "trunk.stl")
    split = trimesh.Trimesh(trunk.triangles.reshape(-1, 3), np.arange(3 * len(trunk.faces)).reshape(-1, 3),
                            process=False)
    v = split.vertices
    uv = np.c_[(np.arctan2(v[:, 1], v[:, 0]) / (2 * np.pi)) % 1, (v[:, 2] + 30) / 60]
    grey = (np.random.default_rng(0).random((256, 256, 3)) * 80 + 120).astype(np.uint8)
    split.visual = trimesh.visual.TextureVisuals(uv=uv, image=Image.fromarray(grey))
    split.export(tmp_path / "trunk.glb")
    shares, counts = {}, {}
    for name in ("trunk.stl", "trunk.glb"):
        out = tmp_path / name.replace(".", "_")
        assert main(["woodify", str(tmp_path / name), "--years", "6", "--resolution", "40",
                     "--crack-years", "3", "--out", str(out)]) == 0
        shares[name] = _crack_share(out / "grown.glb")
        counts[name] = json.loads((out / "woodify.json").read_text())["cracks"]["count"]
    assert counts["trunk.glb"] == counts["trunk.stl"] > 10, counts
    assert 0.05 < shares["trunk.stl"] < 0.4, shares
    assert 0.7 < shares["trunk.glb"] / shares["trunk.stl"] < 1.4, shares


def _bark_feature_mm(glb: Path, region: str, along: str, n_lines: int = 120) -> float:
    """Feature size (mm) of the bark of a written GLB along surface lines: the lag where the
    luminance autocorrelation first drops below 0.25. Lines through random points of the lid
    (normal . z > 0.98) run ``radial`` (from the axis) or ``tangential``; on the sides (|normal .
    z| < 0.1) ``tangential`` (across the fibres, the stem is z) or ``axial``."""
    from scipy.spatial import cKDTree

    scene = trimesh.load(glb)
    m = next(iter(scene.geometry.values()))
    img = np.asarray(m.visual.material.baseColorTexture.convert("L"), float)
    h, w = img.shape
    pts, fi = trimesh.sample.sample_surface(m, 1_500_000, seed=1)
    bary = trimesh.triangles.points_to_barycentric(m.triangles[fi], pts)
    uv = (m.visual.uv[m.faces[fi]] * bary[:, :, None]).sum(1)
    lum = img[np.clip((1 - uv[:, 1] % 1) * h, 0, h - 1).astype(int), np.clip((uv[:, 0] % 1) * w, 0, w - 1).astype(int)]
    z = np.array([0.0, 0.0, 1.0])
    nz = m.face_normals @ z
    sel = np.nonzero(nz > 0.98 if region == "lid" else np.abs(nz) < 0.1)[0]
    rng = np.random.default_rng(0)
    f = rng.choice(sel, n_lines, p=m.area_faces[sel] / m.area_faces[sel].sum())
    p = m.triangles[f].mean(1)
    rad = p - m.vertices.mean(0)
    rad[:, 2] = 0.0
    rad /= np.linalg.norm(rad, axis=1, keepdims=True)
    t = {"radial": rad, "tangential": np.cross(z, rad if region == "lid" else m.face_normals[f]),
         "axial": np.broadcast_to(z, p.shape)}[along]
    t = t / np.linalg.norm(t, axis=1, keepdims=True)
    step, s = 0.1, np.arange(-8.0, 8.0, 0.1)
    L = lum[cKDTree(pts).query((p[:, None] + s[None, :, None] * t[:, None]).reshape(-1, 3))[1]]
    L = L.reshape(n_lines, len(s))
    L = L - L.mean(1, keepdims=True)
    L = L[L.std(1) > 0] / L[L.std(1) > 0].std(1, keepdims=True)
    ac = np.array([np.mean(L[:, :len(s) - k] * L[:, k:]) for k in range(len(s) // 2)])
    return float(np.argmax(ac < 0.25) * step) if (ac < 0.25).any() else float(len(ac) * step)


def test_bark_is_not_stretched_on_flat_faces(tmp_path):
    """The procedural bark was a picture laid on by cylindrical coordinates round the stem,
    which squeeze a flat lid to a line: its plates ran as radial streaks (on a grown box, features
    2.3x longer along the radius than across it, 1.5x those across the fibres on the sides). A
    solid texture has the same features per mm on every face: the lid's radial and tangential
    feature sizes agree, and match the sides' across the fibres."""
    trimesh.creation.box(extents=(30.0, 30.0, 60.0)).export(tmp_path / "box.stl")
    assert main(["woodify", str(tmp_path / "box.stl"), "--years", "6", "--resolution", "48",
                 "--cracks", "none", "--out", str(tmp_path / "box")]) == 0
    glb = tmp_path / "box" / "grown.glb"
    radial, tangential = _bark_feature_mm(glb, "lid", "radial"), _bark_feature_mm(glb, "lid", "tangential")
    across = _bark_feature_mm(glb, "side", "tangential")
    assert 0.75 < radial / tangential < 1.33, (radial, tangential)
    assert 0.75 < radial / across < 1.33, (radial, across)


def test_max_atlas_bounds_the_bark_atlas_and_is_named_as_typed(tmp_path, capsys):
    """woodify bakes its bark into an atlas, and a surface too large for it got a lower density
    with a warning that said 'raise max_atlas_px', an option woodify did not have: --max-atlas
    bounds the atlas as bake's does, the warning names it as typed; where no atlas is baked (the
    input's own picture kept) the option is said to have no effect."""
    from PIL import Image

    trimesh.creation.box(extents=(30.0, 30.0, 60.0)).export(tmp_path / "box.stl")
    assert main(["woodify", str(tmp_path / "box.stl"), "--years", "4", "--resolution", "32",
                 "--cracks", "none", "--max-atlas", "128", "--out", str(tmp_path / "o")]) == 0
    (grown,) = trimesh.load(tmp_path / "o" / "grown.glb").geometry.values()
    assert max(grown.visual.material.baseColorTexture.size) <= 128
    (msg,) = [line for line in capsys.readouterr().err.splitlines() if "lowered" in line]
    assert "max_atlas_px=128" in msg and "--max-atlas" in msg
    # a textured input keeps its picture without cracks drawn into it: no atlas to bound
    m = trimesh.creation.icosphere(subdivisions=2, radius=8.0)
    uv = np.c_[0.5 + 0.5 * m.vertices[:, 0] / 8.0, 0.5 + 0.5 * m.vertices[:, 2] / 8.0]
    img = Image.fromarray(np.full((32, 32, 3), 120, np.uint8))
    m.visual = trimesh.visual.TextureVisuals(uv=uv, image=img)
    m.export(tmp_path / "ball.glb")
    assert main(["woodify", str(tmp_path / "ball.glb"), "--years", "3", "--resolution", "24",
                 "--cracks", "none", "--max-atlas", "256", "--out", str(tmp_path / "b")]) == 0
    (msg,) = [line for line in capsys.readouterr().err.splitlines() if "max-atlas" in line]
    assert "--max-atlas 256 has no effect" in msg
    # given as the default's value it is given all the same (4096 was taken for "not given"),
    # and not given it says nothing
    for extra, said in ((["--max-atlas", "4096"], 1), ([], 0)):
        assert main(["woodify", str(tmp_path / "ball.glb"), "--years", "3", "--resolution", "24",
                     "--cracks", "none", *extra, "--out", str(tmp_path / "b")]) == 0
        err = [line for line in capsys.readouterr().err.splitlines() if "max-atlas" in line]
        assert len(err) == said and all("--max-atlas 4096 has no effect" in e for e in err), (extra, err)


def test_a_mesh_saved_in_metres_is_named_as_such(tmp_path, capsys):
    """A 40 mm box saved as 0.04 units grew, silently, into a 0.06 mm speck (mesh files carry no
    units and are read as mm, whatever --units says): it is warned about, with the unit it looks
    saved in and the fix; the same box in mm grows silently."""
    trimesh.creation.box((0.04, 0.04, 0.03)).export(tmp_path / "m.stl")
    for units in ("mm", "inch"):
        assert main(["woodify", str(tmp_path / "m.stl"), "--years", "5", "--resolution", "16",
                     "--cracks", "none", "--units", units, "--out", str(tmp_path / "o")]) == 0
        (msg,) = [line for line in capsys.readouterr().err.splitlines() if "metres" in line]
        assert msg.startswith("woodcam: warning: part '" + str(tmp_path / "m.stl") + "'")
        assert "0.04x0.04x0.03 mm" in msg and "40x40x30 mm" in msg
        assert "scale it by 1000" in msg and "--units" in msg
    trimesh.creation.box((40.0, 40.0, 30.0)).export(tmp_path / "mm.stl")
    assert main(["woodify", str(tmp_path / "mm.stl"), "--years", "5", "--resolution", "16",
                 "--cracks", "none", "--out", str(tmp_path / "o2")]) == 0
    assert "warning" not in capsys.readouterr().err
    # an obstacle file in metres is named as the obstacle it is, not as the part
    assert main(["woodify", str(tmp_path / "mm.stl"), "--years", "5", "--resolution", "16", "--cracks",
                 "none", "--obstacle", str(tmp_path / "m.stl"), "--out", str(tmp_path / "o3")]) == 0
    (msg,) = [line for line in capsys.readouterr().err.splitlines() if "metres" in line]
    assert msg.startswith("woodcam: warning: --obstacle '" + str(tmp_path / "m.stl") + "': the obstacle is only "), msg
    assert "never the obstacle's own" in msg and "the part's own" not in msg, msg
    # and in an obstacle's words: it said "part files are read as millimetres ... nothing that
    # small is carved" of a file that is grown around, not carved
    assert "obstacle files are read as millimetres" in msg and "nothing that small bends the rings" in msg, msg
    assert "part files" not in msg and "carved" not in msg, msg


def test_a_mesh_saved_in_inches_is_named_as_such(tmp_path, capsys):
    """A 4 x 3 x 2 inch box saved in inches is read as a 4 x 3 x 2 mm speck, and grew so
    without a word (only a part under 1 mm, as if in metres, was warned of): it is warned about
    from its size alone (no block to compare with), in bake's words of a mesh's units
    (woodcam.cad.carve.units_note) with the size it would have and the fix; a 10 mm ball (a
    real knob) grows silently."""
    trimesh.creation.box((4.0, 3.0, 2.0)).export(tmp_path / "in.stl")
    assert main(["woodify", str(tmp_path / "in.stl"), "--years", "5", "--resolution", "16",
                 "--cracks", "none", "--out", str(tmp_path / "o")]) == 0
    (msg,) = [line for line in capsys.readouterr().err.splitlines() if "warning" in line]
    assert msg.startswith("woodcam: warning: part '" + str(tmp_path / "in.stl") + "'"), msg
    assert "modelled in inches" in msg and "4x3x2 mm" in msg and "102x76.2x50.8 mm" in msg, msg
    assert "STL, OBJ and PLY carry no units" in msg and "scale it by 25.4" in msg and "--units" in msg, msg
    trimesh.creation.icosphere(subdivisions=1, radius=5.0).export(tmp_path / "ball.stl")
    assert main(["woodify", str(tmp_path / "ball.stl"), "--years", "5", "--resolution", "16",
                 "--cracks", "none", "--out", str(tmp_path / "o2")]) == 0
    assert "warning" not in capsys.readouterr().err


def test_a_bar_is_drawn_while_the_growth_runs(tmp_path, monkeypatch):
    """woodify's bar of plain updates drew nothing until a stage ended: a 13 s growth on a 160^3
    grid (a 1.3M-triangle mesh: 7 s to read, 25 s to grow at the default 128) showed no bar at
    all. Its stage bar's timer draws it, naming the stage, once the delay is past."""
    import io
    import sys
    import time

    import woodcam._progress
    import woodcam.woodify

    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    term = Terminal()
    monkeypatch.setattr(sys, "stderr", term)
    monkeypatch.setattr(woodcam._progress, "PROGRESS_DELAY_S", 0.05)
    grow = woodcam.woodify.woodify
    seen = []

    def slow_growth(*args, **kwargs):  # the growth of a big grid: the bar shows meanwhile
        deadline = time.monotonic() + 5
        while "woodify: grow" not in term.getvalue() and time.monotonic() < deadline:
            time.sleep(0.01)
        seen.append(term.getvalue())
        return grow(*args, **kwargs)

    monkeypatch.setattr(woodcam.woodify, "woodify", slow_growth)
    trimesh.creation.icosphere(subdivisions=2, radius=5.0).export(tmp_path / "ball.stl")
    assert main(["woodify", str(tmp_path / "ball.stl"), "--years", "3", "--resolution", "16",
                 "--cracks", "none", "--out", str(tmp_path / "o")]) == 0
    assert "woodify: grow" in seen[0] and "1/5" in seen[0]


def test_seed_help_names_what_it_seeds(capsys):
    """--seed seeds the procedural bark (SolidBark) and random cracks; its help said 'the bark
    picture', which an input's own picture is (and --seed never changes)."""
    with pytest.raises(SystemExit):
        main(["woodify", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "random seed of the procedural bark and random cracks" in text and "bark picture" not in text


def test_wood_that_shows_no_ring_is_said_so(tmp_path):
    """Wood grown under a year (a 5 mm ball grown 0.5 years), a block cut inside one growth
    layer (here the ungrown core, year 0), and a veneer leaf lying in one layer were each one
    flat colour without a word. Now each warns, naming why and what to change; wood with rings
    (the ball grown 3 years, a block across them) says nothing."""
    import warnings

    from woodcam.errors import WoodcamWarning
    from woodcam.parquetry import slice_veneers
    from woodcam.woodify import woodify

    ball = trimesh.creation.icosphere(subdivisions=2, radius=5.0)
    with pytest.warns(WoodcamWarning, match=r"years \(--years\) = 0.5: .* has none inside its bark: .* one flat "
                                            r"colour; grow more than one year \(e.g. --years 5"):
        woodify(ball, 0.5, resolution=16)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        grown = woodify(ball, 3.0, growth_mm=3.0, resolution=24)
        grown.field.placed(grown.field.block_size_mm).save(tmp_path / "ringed.npz")  # the grown box
        ringed = open_stock(f"woodify:{tmp_path / 'ringed.npz'}")
        W, _, H = ringed.size_mm
        slice_veneers(ringed, 1, (W, H), px_per_mm=1.0)  # the block's middle plane: across the rings
    grown.field.placed((4.0, 4.0, 4.0), (0.0, 0.0, 0.0)).save(tmp_path / "core.npz")
    with pytest.warns(WoodcamWarning, match=r"block woodify:.*core.npz: its 4 x 4 x 4 mm of wood lie in one growth "
                                            r"layer \(years 0 to 0 of the 3 grown\), so it shows no ring, one flat colour; "
                                            r"cut a block that reaches across a ring"):
        core = open_stock(f"woodify:{tmp_path / 'core.npz'}")
    with pytest.warns(WoodcamWarning, match=r"veneers of woodify:.*core.npz: 2 of 2 leaves lie in one growth layer "
                                            r"and show no ring, one flat colour: leaf 0 at y=2 mm \(years 0 to 0\); "
                                            r"leaf 1 .*slice across the rings"):
        slice_veneers(core, 2, (4.0, 4.0), px_per_mm=2.0)


def test_a_block_centred_outside_the_grown_object_is_refused(tmp_path, capsys):
    """--block-centre=1000,0,0 (or 0,40,0 by a 40 mm box grown 5 mm) was taken without a word: the
    block was cut from the air round the object (a bake from its field.npz: "years 18.6 to 18.6
    of the 5 grown"), and section_xz.png through that centre was a blank white picture. Now a
    usage error after the growth, before anything is written, naming the value as typed, the
    grown box in --units and a centre inside it."""
    box = tmp_path / "box.stl"
    trimesh.creation.box((40, 30, 20)).export(box)
    out = tmp_path / "o"
    base = ["woodify", str(box), "--years", "3", "--resolution", "24", "--cracks", "none", "--out", str(out)]
    for centre, units, said in (("1000,0,0", "mm", "--block-centre 1000,0,0: the block's centre lies outside"),
                                ("0,40,0", "mm", "its block would be cut from the air round the object"),
                                ("0,1.6,0", "inch", "--block-centre 0,1.6,0: the block's centre lies outside")):
        growth = "0.2" if units == "inch" else "5"  # 5 mm, 5.08 mm
        assert _rc([*base, "--growth", growth, f"--block-centre={centre}", "--units", units]) == 2, centre
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and said in err, err
        unit = "in" if units == "inch" else "mm"
        assert "z [" in err and f"] {unit})" in err and "--block-centre=0," in err, err
        assert not out.exists() or not any(out.iterdir()), list(out.iterdir())
    # a centre inside the grown box, even off the input (its bark), is a block of the grown wood
    assert _rc([*base, "--growth", "5", "--block-centre=0,0,12"]) == 0
    capsys.readouterr()
    from PIL import Image

    section = np.asarray(Image.open(out / "section_xz.png").convert("RGB"))
    assert (section.min(axis=-1) < 200).mean() > 0.2  # wood, not a white page


def test_crack_options_with_no_cracks_are_said_to_do_nothing(tmp_path, capsys):
    """--cracks none dropped --crack-years, --crack-region, --crack-render, --crack-threshold and
    --relief without a word (exit 0, the same files as without them): a warning names those
    typed; with cracks, or with none typed, there is none."""
    ball = tmp_path / "ball.stl"
    trimesh.creation.icosphere(subdivisions=1, radius=5.0).export(ball)
    base = ["woodify", str(ball), "--years", "2", "--resolution", "16", "--out", str(tmp_path / "o")]
    assert main([*base, "--cracks", "none", "--crack-years", "1", "--relief", "0.5",
                 "--crack-render", "groove", "--crack-region=0,0,0,3", "--crack-threshold", "2"]) == 0
    err = capsys.readouterr().err
    assert ("woodcam: warning: --crack-years, --crack-region, --crack-render, --crack-threshold, --relief shape "
            "the bark's cracks, and --cracks none draws none, so they change nothing here; drop them, or give a "
            "crack pattern (--cracks stress, the default)") in err, err
    for extra in (["--cracks", "none"], ["--crack-years", "1", "--relief", "0.5"]):
        assert main([*base, *extra]) == 0
        assert "change nothing" not in capsys.readouterr().err, extra
    assert _rc([*base, "--cracks", "none", "--relief", "2"]) == 2  # its range still checked
    assert "--relief must be in [0, 1]" in capsys.readouterr().err


def test_a_block_reaching_past_the_grown_object_is_warned_of(tmp_path, capsys):
    """--block-size 1000x1000x1000 of a ball grown to 30 mm was taken without a word: the block
    was air round the object, wood never grown, which field.npz fills with years past those
    grown, so a part carved out there baked as plain wood. Now a block more than a grid step
    past the grown object's box is warned of, with the box and the largest block about that
    centre; the default block (the grown box) and one within it say nothing."""
    trimesh.creation.icosphere(subdivisions=2, radius=5.0).export(tmp_path / "ball.stl")
    base = ["woodify", str(tmp_path / "ball.stl"), "--years", "4", "--growth", "3", "--resolution", "24",
            "--cracks", "none", "--out", str(tmp_path / "out")]
    assert main([*base, "--block-size", "100x16x16"]) == 0
    err = capsys.readouterr().err
    # the ball grown 3 mm: 7.87 mm, the surface's facets a little inside the sphere; 16 mm
    # across reaches 0.13 mm past it, within a grid step: no word of it
    assert err == ("woodcam: warning: the block cut from the grown object (100 x 16 x 16 mm about 0,0,0 mm, "
                   "--block-size) reaches 42.13 mm past the grown object's box (x [-7.874, 7.874], y [-7.874, "
                   "7.874], z [-7.874, 7.874] mm): that part of it is air round the object, wood never grown, which "
                   "field.npz fills with years past the 4 grown (a bake shows wood there); keep the block within "
                   "that box (--block-size at most 15.75x15.75x15.75 mm about that centre), or leave --block-size "
                   "out for the grown object's own box\n"), err
    for within in ([], ["--block-size", "10x10x10"]):
        assert main([*base, *within]) == 0
        assert "past the grown object's box" not in capsys.readouterr().err


def test_degenerate_and_twice_written_triangles_are_dropped_as_bake_drops_them(tmp_path, capsys):
    """A closed box STL with a zero-length sliver (a corner written twice, which welding
    collapses to a triangle with a repeated vertex) or with one triangle written twice was
    refused as 'must be watertight ... open or non-manifold edges; repair it first (e.g.
    trimesh.repair.fill_holes ...)', while ``woodcam bake`` carves both (it drops those
    triangles): woodify drops them too, the copy with bake's warning, and grows the box."""
    box = trimesh.creation.box((40.0, 30.0, 20.0))
    sliver = trimesh.Trimesh(np.vstack([box.vertices, box.vertices[:1]]),
                             np.vstack([box.faces, [[0, 8, 1]]]), process=False)
    twice = trimesh.Trimesh(box.vertices, np.vstack([box.faces, box.faces[:1]]), process=False)
    fields = {}
    for name, mesh in (("box", box), ("sliver", sliver), ("twice", twice)):
        mesh.export(tmp_path / f"{name}.stl")
        assert main(["woodify", str(tmp_path / f"{name}.stl"), "--years", "3", "--resolution", "16",
                     "--cracks", "none", "--out", str(tmp_path / name)]) == 0, capsys.readouterr().err
        err = capsys.readouterr().err
        dup = [line for line in err.splitlines() if "duplicate triangles" in line]
        assert dup == ([f"woodcam: warning: part {str(tmp_path / 'twice.stl')!r} has 1 duplicate triangles "
                        "(the same three corners twice); woodcam dropped the copies (the solid is unchanged)"]
                       if name == "twice" else []), err
        with np.load(tmp_path / name / "field.npz") as z:
            fields[name] = z["arrival_mm"].copy()
    # the same solid grows the same wood, to the last bit
    assert np.array_equal(fields["sliver"], fields["box"]) and np.array_equal(fields["twice"], fields["box"])


def test_a_part_baked_into_its_own_woodify_block_with_the_printed_translate_sits_where_it_grew(tmp_path, capsys):
    """Sweep h10 item 1: 'woodcam bake PART --block woodify:F' reads PART in the block frame (as
    every block does), the grown input's frame moved by the block's corner, so the input baked
    into its own field sat that corner away from where it grew (the lid example: a median of 3.2
    years at its surface, rings across its top). woodify prints the translate that bakes it where
    it grew: there its surface is the year-0 ring, arrival ~0 within a grid step."""
    import re

    from woodcam.export import load_textured

    part = tmp_path / "part.stl"
    trimesh.creation.box((24.0, 16.0, 10.0)).apply_translation((7.0, -3.0, 12.0)).export(part)
    assert main(["woodify", str(part), "--years", "3", "--resolution", "32", "--cracks", "none",
                 "--surface-years", "1", "--out", str(tmp_path / "w")]) == 0
    said = capsys.readouterr().out
    shift = re.search(r"add --place translate:(\S+)\)", said)
    assert shift, said
    f = WoodifiedField.load(tmp_path / "w" / "field.npz")
    np.testing.assert_allclose([float(v) for v in shift[1].split(",")], -f.block_origin_mm, atol=1e-3)
    bake = ["bake", str(part), "--block", f"woodify:{tmp_path / 'w' / 'field.npz'}", "--texels-per-mm", "1",
            "--no-obj"]
    assert main([*bake, "--place", f"translate:{shift[1]}", "--out", str(tmp_path / "at.glb")]) == 0
    surface = load_textured(tmp_path / "at.glb").sample(3000, seed=0)
    arrival = f.arrival(surface)
    assert np.median(arrival) < 0.1 * f.spacing_mm and arrival.max() < f.spacing_mm, (np.median(arrival), arrival.max())
    assert f(surface).max() < 1.0  # no whole ring on its surface
    # without it: the part in the block frame, the block's corner away from where it grew
    assert main([*bake, "--out", str(tmp_path / "as_is.glb")]) == 0
    assert np.median(f.arrival(load_textured(tmp_path / "as_is.glb").sample(3000, seed=0))) > f.spacing_mm
    assert json.loads((tmp_path / "w" / "woodify.json").read_text())["block"]["input_translate_mm"] == \
        pytest.approx(-f.block_origin_mm)
    # under --units inch: the translate in inches, and the bake command printed reads it so
    assert main(["woodify", str(part), "--years", "3", "--resolution", "32", "--cracks", "none", "--units", "inch",
                 "--out", str(tmp_path / "wi")]) == 0
    said = capsys.readouterr().out
    shift = re.search(r"woodcam bake PART --units inch --block .* add --place translate:(\S+)\)", said)
    assert shift, said
    np.testing.assert_allclose([float(v) for v in shift[1].split(",")], -f.block_origin_mm / 25.4, atol=1e-4)


def test_a_grid_past_a_limit_says_what_its_numbers_count(tmp_path, capsys, monkeypatch):
    """'needs 1.074e+09, more than the limit MAX_GRID_CELLS = 2e+08' said no unit: nodes, bytes,
    pixels? Each number now carries what it counts, bytes also in GiB, and the fix follows."""
    trimesh.creation.box((40.0, 40.0, 40.0)).export(tmp_path / "box.stl")
    argv = ["woodify", str(tmp_path / "box.stl"), "--years", "5", "--resolution", "1024", "--quiet",
            "--out", str(tmp_path / "tree")]
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    assert "(a 1024x1024x1024 grid) needs 1.074e+09 grid cells, more than the limit MAX_GRID_CELLS = 2e+08 grid cells; " \
           "lower the resolution to " in err, err
    monkeypatch.setenv("WOODCAM_MAX_GRID_CELLS", "2e9")
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert "resolution 1024 (memory) needs 1.933e+11 bytes (180 GiB), more than the limit MAX_ALLOC_BYTES = " \
           "4.295e+09 bytes (4 GiB); lower the resolution to " in err, err


def test_every_limit_says_its_unit():
    """Every MAX_ limit's refusal says what its numbers count (woodcam.limits.UNITS)."""
    from woodcam import limits

    for name, top in limits._DEFAULTS.items():
        with pytest.raises(WoodcamError) as e:
            limits.check_limit(name, 3 * top, "this")
        unit = limits.UNITS[name]
        assert re.search(rf"needs [0-9.e+]+ {unit}( \(12 GiB\))?, more than the limit {name} = [0-9.e+]+ {unit}[ ;]",
                         str(e.value)), str(e.value)


def test_an_obstacle_round_the_whole_part_is_named_as_its_option(tmp_path, capsys):
    """An --obstacle holding the whole part was refused as 'obstacles must leave part of the
    input outside them; the obstacle(s) contain ...': the library's keyword, not the option
    typed, and no file. The CLI names '--obstacle FILE'; the library keeps 'obstacles[i]'."""
    from woodcam.woodify import woodify

    trimesh.creation.box((10.0, 10.0, 10.0)).export(tmp_path / "part.stl")
    trimesh.creation.box((30.0, 30.0, 30.0)).export(tmp_path / "cage.stl")
    cage = str(tmp_path / "cage.stl")
    assert main(["woodify", str(tmp_path / "part.stl"), "--years", "5", "--resolution", "24", "--quiet",
                 "--obstacle", cage, "--out", str(tmp_path / "tree")]) == 1
    err = capsys.readouterr().err
    assert err == (f"woodcam: error: --obstacle {cage!r} must leave part of the input mesh outside it; it "
                   "contains the whole input mesh (12 triangles), so nothing can grow; move or shrink it, "
                   "or leave it out\n"), err
    with pytest.raises(WoodcamError, match=r"^obstacles\[0\], obstacles\[1\] must leave part of the input mesh "
                       "outside them; together they contain"):
        woodify(trimesh.creation.box((10.0, 10.0, 10.0)), 5, resolution=24,
                obstacles=[trimesh.creation.box((30.0, 30.0, 30.0)), trimesh.creation.box((2.0, 2.0, 2.0))])


def test_woodify_takes_the_triangle_budget_its_warning_names(tmp_path, capsys):
    """load_part simplifies a union of meshes (a script, a STEP) over its triangle budget with a
    warning saying 'raise --max-triangles', an option woodify did not have (exit 2, unrecognized):
    woodify takes bake's --max-triangles, and the union of a GLB of two 1280-triangle balls is
    simplified within 1000 triangles, said with both counts; under the default budget it is not.
    A file of one mesh keeps every triangle (its picture, painted growth), which a warning says
    where the budget given is below its count."""
    scene = trimesh.Scene()
    for name, x in (("a", 0.0), ("b", 30.0)):
        ball = trimesh.creation.icosphere(subdivisions=3, radius=8.0)
        ball.apply_translation((x, 0.0, 0.0))
        scene.add_geometry(ball, geom_name=name)
    scene.export(tmp_path / "two.glb")
    base = ["woodify", str(tmp_path / "two.glb"), "--years", "2", "--resolution", "24", "--cracks", "none"]
    assert main([*base, "--max-triangles", "1000", "--out", str(tmp_path / "o")]) == 0
    (msg,) = [line for line in capsys.readouterr().err.splitlines() if "--max-triangles" in line]
    assert "2560 triangles" in msg and "max_triangles=1000" in msg and "simplified to" in msg, msg
    assert main([*base, "--out", str(tmp_path / "o2")]) == 0
    assert "--max-triangles" not in capsys.readouterr().err
    trimesh.creation.icosphere(subdivisions=3, radius=8.0).export(tmp_path / "ball.stl")
    assert main(["woodify", str(tmp_path / "ball.stl"), "--years", "2", "--resolution", "24", "--cracks", "none",
                 "--max-triangles", "1000", "--out", str(tmp_path / "o3")]) == 0
    (msg,) = [line for line in capsys.readouterr().err.splitlines() if "--max-triangles" in line]
    assert "1280 triangles, over --max-triangles 1000, and grows with every one" in msg, msg


def test_a_script_or_step_part_saved_in_inches_is_named_in_its_kinds_words(tmp_path, capsys):
    """woodify warned of a mesh file under 6.35 mm (looks saved in inches) or 1 mm (in metres),
    and grew a part script or STEP of that size without a word: they get the same check, in
    the words of their kind (woodcam.cad.carve.units_note: a script's lengths carry no units, a
    STEP names its units, to be re-exported in the unit it was drawn in), an STL its own."""
    import build123d as bd

    (tmp_path / "box.py").write_text("import trimesh\npart = trimesh.creation.box((4.0, 3.0, 2.0))\n")
    bd.export_step(bd.Box(0.04, 0.03, 0.02), str(tmp_path / "box.step"))
    trimesh.creation.box((4.0, 3.0, 2.0)).export(tmp_path / "box.stl")
    says = {"box.py": ("modelled in inches", "lengths in a part script", "or write its lengths in mm"),
            "box.step": ("modelled in metres", "a STEP file names its units",
                         "drawn in metres under a millimetre setting", "or re-export it with its units set to metres"),
            "box.stl": ("modelled in inches", "STL, OBJ and PLY carry no units", "or export it in mm")}
    for name, words in says.items():
        assert main(["woodify", str(tmp_path / name), "--years", "3", "--resolution", "16", "--cracks", "none",
                     "--out", str(tmp_path / ("o_" + name.replace(".", "_")))]) == 0
        (msg,) = [line for line in capsys.readouterr().err.splitlines() if "warning" in line]
        assert msg.startswith(f"woodcam: warning: part '{tmp_path / name}'"), msg
        assert all(w in msg for w in words) and "--units" in msg, (name, msg)
        assert ("STL, OBJ and PLY" in msg) == (name == "box.stl"), msg


def test_a_small_obstacle_is_judged_beside_the_part(tmp_path, capsys):
    """The inch check (a part under 6.35 mm looks saved in inches) fired on --obstacle meshes
    too: a 3 x 3 x 5 mm pin beside a 40 mm box, a real obstacle, was said to look modelled in
    inches. An obstacle gets it only where the part does (the scene looks saved in inches); the
    metres check (under 1 mm) stays (test_a_mesh_saved_in_metres_is_named_as_such)."""
    def grow(part, obstacle, out):
        assert main(["woodify", str(part), "--obstacle", str(obstacle), "--years", "3", "--resolution", "16",
                     "--cracks", "none", "--out", str(tmp_path / out)]) == 0
        return [line for line in capsys.readouterr().err.splitlines() if "warning" in line]

    trimesh.creation.box((40.0, 40.0, 30.0)).export(tmp_path / "part.stl")
    pin = trimesh.creation.cylinder(radius=1.5, height=5.0)
    pin.apply_translation((30.0, 0.0, 0.0))
    pin.export(tmp_path / "pin.stl")
    assert grow(tmp_path / "part.stl", tmp_path / "pin.stl", "o") == []
    # a 150 x 150 x 100 mm part and a 30 x 30 x 60 mm post saved in inches: both look so
    trimesh.creation.box((150 / 25.4, 150 / 25.4, 100 / 25.4)).export(tmp_path / "part_in.stl")
    post = trimesh.creation.cylinder(radius=15.0, height=60.0)
    post.apply_translation((110.0, 0.0, 0.0))
    post.apply_scale(1 / 25.4)
    post.export(tmp_path / "pin_in.stl")
    said = grow(tmp_path / "part_in.stl", tmp_path / "pin_in.stl", "o2")
    assert len(said) == 2 and all("modelled in inches" in m for m in said), said
    assert said[1].startswith("woodcam: warning: --obstacle '" + str(tmp_path / "pin_in.stl") + "'"), said
    # each named as what it is: "--obstacle 'pin_in.stl': the part is only ..." named the part
    assert ": the part is only " in said[0] and "the obstacle" not in said[0], said
    assert ": the obstacle is only " in said[1] and "the part is only" not in said[1], said
    # and its fix too: it said "--units converts only the lengths typed as options, never the part's own"
    assert "never the part's own" in said[0] and "never the obstacle's own" not in said[0], said
    assert "never the obstacle's own" in said[1] and "the part's own" not in said[1], said
    # a router bit's width is the part's reason (it is carved), the obstacle's the part's size
    assert "router bit is wider" in said[0] and "part files are read" in said[0], said
    assert "router bit" not in said[1] and "as the part's, is under 6.35 mm" in said[1], said
    assert "obstacle files are read" in said[1], said


def test_units_note_words_each_kind_of_obstacle_file():
    """woodcam.cad.carve.units_note/units_hint in an obstacle's words for each kind of file (a
    mesh, a script, a STEP file): "part files" / "a part script" and "nothing that small is
    carved" were said of --obstacle files; the part's words, which bake and place share, stay."""
    from woodcam.cad.carve import units_hint, units_note

    assert units_note("p.stl")[0] == "part files are read as millimetres (STL, OBJ and PLY carry no units)"
    assert units_note("o.stl", noun="obstacle")[0].startswith("obstacle files are read as millimetres")
    assert units_note("p.py")[0].startswith("lengths in a part script or a build123d/cadquery shape")
    assert units_note("o.py", noun="obstacle")[0].startswith("lengths in the obstacle's script or")
    assert units_note("o.step", "metres", "obstacle") == units_note("p.step", "metres")  # no noun in it
    tiny = ((0, 0, 0), (0.04, 0.04, 0.03))
    part, obstacle = (units_hint(*tiny, None, "FIX", source="x.stl", noun=n) for n in ("part", "obstacle"))
    assert part is not None and obstacle is not None
    assert "nothing that small is carved" in part and "part files" in part, part
    assert "nothing that small bends the rings" in obstacle and "carved" not in obstacle, obstacle
