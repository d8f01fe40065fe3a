"""block.json, images and true-field files are checked at the door: WoodcamError, never a traceback."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from woodcam.block import Block, Face, RingTrace
from woodcam.block.io import read_block, write_block
from woodcam.errors import WoodcamError


def _block() -> Block:
    rng = np.random.default_rng(1)
    face = Face("top", (16, 20), photo=rng.integers(0, 256, (16, 20, 3), dtype=np.uint8),
                ring_map=rng.uniform(0, 1, (16, 20)).astype(np.float32),
                traces=[RingTrace(np.array([[1.0, 1.0], [5.0, 9.0], [8.0, 15.0]]), year=3)],
                extras={"knot_mask": rng.uniform(size=(16, 20)) > 0.8})
    return Block((30.0, 20.0, 10.0), faces={"top": face}, name="small")


@pytest.fixture
def folder(tmp_path) -> Path:
    write_block(_block(), tmp_path / "blk")
    return tmp_path / "blk"


def _edit(folder: Path, fn) -> None:
    p = folder / "block.json"
    m = json.loads(p.read_text())
    fn(m)
    p.write_text(json.dumps(m))


def test_valid_folder_round_trips(folder):
    b = read_block(folder)
    assert b.size_mm == (30.0, 20.0, 10.0)
    np.testing.assert_array_equal(b.faces["top"].photo, _block().faces["top"].photo)


@pytest.mark.parametrize("edit, match", [
    (lambda m: m.update(size_mm=[30, "20", 10]), r"size_mm\[1\] must be a number"),
    (lambda m: m.update(size_mm=[30, 20]), r'"size_mm" must be \[W, D, H\]'),
    (lambda m: m.pop("size_mm"), r'"size_mm" is required'),
    (lambda m: m.update(size_mm=[30, 20, -1]), r"size_mm\[2\] must be in \(0"),
    (lambda m: m.update(size_mm=[30, 20, 1e9]), r"size_mm\[2\] must be in \(0, 10000\]"),
    (lambda m: m.update(faces=[]), r'"faces" must be a JSON object'),
    (lambda m: m["faces"].update(sideways={"shape": [2, 2]}), r"must be one of"),
    (lambda m: m["faces"]["top"].update(shape=[16]), r"faces.top.shape must be \[n_rows, n_cols\]"),
    (lambda m: m["faces"]["top"].update(shape=[16, 0]), r"shape\[1\] must be an integer in \[1,"),
    (lambda m: m["faces"]["top"].update(shape=[16, 1e12]), r"shape\[1\] must be an integer in"),
    (lambda m: m["faces"]["top"].update(ring_map_bits=0), r"ring_map_bits must be 8 or 16"),
    (lambda m: m["faces"]["top"].update(ring_map_bits=True), r"ring_map_bits must be 8 or 16"),
    (lambda m: m["faces"]["top"]["traces"][0].update(year=1e12), r"traces\[0\].year must be an integer in"),
    (lambda m: m["faces"]["top"]["traces"][0].update(year="3"), r"traces\[0\].year must be an integer"),
    (lambda m: m["faces"]["top"]["traces"][0].update(year=2.5), r"year must be an integer"),
    (lambda m: m["faces"]["top"]["traces"][0]["points_px"][1].__setitem__(0, 1e9), r"points_px\[1\]\[0\] \(row\) must be in"),
    (lambda m: m["faces"]["top"]["traces"][0].update(points_px=[[1, 2]]), r"at least 2 points"),
    (lambda m: m["faces"]["top"]["traces"][0].update(points_px=[[1, 2], [3]]), r"must be \[row, col\]"),
    (lambda m: m["faces"]["top"]["traces"][0].pop("points_px"), r"points_px is required"),
    (lambda m: m["faces"]["top"].update(traces={}), r"traces must be a JSON list"),
    (lambda m: m["faces"]["top"].update(photo=3), r"photo must be a string or null"),
    (lambda m: m["faces"]["top"]["extras"]["knot_mask"].update(dtype="float64"), r"dtype must be bool, uint8"),
    (lambda m: m["faces"]["top"]["extras"].update(note=5), r"extras.note must be a JSON object"),
    (lambda m: m.update(true_field={"saved": True, "type": "os:system", "file": "x.json"}), r"must name a woodcam class"),
    (lambda m: m.update(format="other"), r'"format" must be "woodcam-block"'),
    (lambda m: m.update(version=99), r'"version" must be an integer in \[1, 1\]'),
])
def test_bad_manifest_is_a_woodcam_error(folder, edit, match):
    _edit(folder, edit)
    with pytest.raises(WoodcamError, match=match):
        read_block(folder)


@pytest.mark.parametrize("text, match", [
    ('{"format": "woodcam-block", "size_mm": [NaN, 1, 1]}', "finite numbers"),
    ('{"format": "woodcam-block", "size_mm": [Infinity, 1, 1]}', "finite numbers"),
    ('{"format": "woodcam-block", "size_mm": [1e999, 1, 1]}', "must be a finite number"),
    ('[' * 100000, "valid JSON"),
    ('{"format": ', "valid JSON"),
    ('"just a string"', "must be a JSON object"),
])
def test_bad_json_is_a_woodcam_error(tmp_path, text, match):
    (tmp_path / "block.json").write_text(text)
    with pytest.raises(WoodcamError, match=match):
        read_block(tmp_path)


def test_non_utf8_manifest(tmp_path):
    (tmp_path / "block.json").write_bytes(b'{"format": "\xff"}')
    with pytest.raises(WoodcamError, match="not UTF-8"):
        read_block(tmp_path)


# -- file references stay inside the folder --------------------------------------------------------

def test_absolute_and_parent_paths_are_refused_unless_trusted(folder, tmp_path, monkeypatch):
    """Issue 15: block.json accepted absolute paths and '../' (a PNG outside the folder was baked
    into a texture)."""
    outside = tmp_path / "secret.png"
    Image.fromarray(np.full((16, 20, 3), 7, np.uint8)).save(outside)
    for ref in (str(outside), "../secret.png"):
        _edit(folder, lambda m, ref=ref: m["faces"]["top"].update(photo=ref))
        with pytest.raises(WoodcamError, match="points outside the block folder"):
            read_block(folder)
    assert read_block(folder, allow_outside=True).faces["top"].photo.max() == 7
    for off in ("0", "false", "no"):  # the variable set to say no trusts nothing
        monkeypatch.setenv("WOODCAM_ALLOW_OUTSIDE_PATHS", off)
        with pytest.raises(WoodcamError, match="points outside the block folder"):
            read_block(folder)
    monkeypatch.setenv("WOODCAM_ALLOW_OUTSIDE_PATHS", "1")
    assert read_block(folder).faces["top"].photo.max() == 7


@pytest.mark.parametrize("regenerated, said", [
    (None, "got None"), (5, "got 5"), ([3], r"got \[3\]"),
    ("top_ring_map.png", "got the string 'top_ring_map.png'; pass \\['top_ring_map.png'\\]"),
])
def test_read_block_checks_its_regenerated_names(folder, regenerated, said):
    """regenerated=None or 5 was "argument of type 'NoneType' is not iterable" at the first
    face's file, and a string was searched as text (each file name a substring of it): the
    names are checked at the door, an empty collection (the default) still allowed."""
    (folder / "top_ring_map.png").unlink()
    with pytest.raises(WoodcamError, match="read_block: regenerated must be a list of file names; " + said):
        read_block(folder, regenerated=regenerated)
    assert read_block(folder, regenerated=["top_ring_map.png"]).faces["top"].ring_map is None
    with pytest.raises(WoodcamError, match="ring map of face 'top'.*listed but missing"):
        read_block(folder, regenerated=[])


def test_symlink_leading_out_is_refused(folder, tmp_path):
    outside = tmp_path / "secret.png"
    Image.fromarray(np.zeros((16, 20, 3), np.uint8)).save(outside)
    os.symlink(outside, folder / "link.png")
    _edit(folder, lambda m: m["faces"]["top"].update(photo="link.png"))
    with pytest.raises(WoodcamError, match="link leading outside"):
        read_block(folder)


def test_true_field_file_outside_is_refused(folder):
    _edit(folder, lambda m: m.update(true_field={"saved": True, "type": "woodcam.fields:X",
                                                 "file": "/etc/passwd"}))
    with pytest.raises(WoodcamError, match="points outside"):
        read_block(folder)


def test_bad_true_field_state_is_a_woodcam_error(folder):
    (folder / "tf.json").write_text('{"nonsense": 1}')
    _edit(folder, lambda m: m.update(true_field={
        "saved": True, "type": "woodcam.fields.radial:RadialScalingField", "file": "tf.json"}))
    with pytest.raises(WoodcamError, match="true field"):
        read_block(folder)


# -- images ------------------------------------------------------------------------------------

@pytest.mark.parametrize("damage", ["empty", "truncated", "text", "missing"])
def test_damaged_images_are_a_woodcam_error(folder, damage):
    png = folder / "top_photo.png"
    data = png.read_bytes()
    if damage == "missing":
        png.unlink()
    else:
        png.write_bytes({"empty": b"", "truncated": data[: len(data) // 2],
                         "text": b"not an image at all"}[damage])
    with pytest.raises(WoodcamError, match="cannot decode the image|listed but missing"):
        read_block(folder)


def test_sixteen_bit_photo_is_scaled_not_wrapped(folder):
    """Issue 15: 16-bit photos wrapped to 8 bits (value % 256)."""
    grey = np.full((16, 20), 32896, np.uint16)  # 128 * 257: mid grey
    grey[0, 0], grey[0, 1] = 65535, 256         # white; and a dark value that wraps to 0
    Image.fromarray(grey).save(folder / "top_photo.png")
    photo = read_block(folder).faces["top"].photo
    assert photo.dtype == np.uint8 and photo.shape == (16, 20, 3)
    assert photo[5, 5, 0] == 128 and photo[0, 0, 0] == 255 and photo[0, 1, 0] == 1


def test_sixteen_bit_ring_map_with_8_bit_label_is_read_at_its_own_depth(folder):
    """It was refused ('more than ring_map_bits = 8 allows'): the PNG's own depth is read now
    (tests/block/test_block_io.py, test_a_ring_map_saved_at_another_depth_is_read_at_its_own)."""
    before = read_block(folder).faces["top"].ring_map
    _edit(folder, lambda m: m["faces"]["top"].update(ring_map_bits=8))
    assert np.array_equal(read_block(folder).faces["top"].ring_map, before)


def test_oversized_image_is_refused_before_decoding(folder, monkeypatch):
    monkeypatch.setenv("WOODCAM_MAX_IMAGE_PIXELS", "100")
    with pytest.raises(WoodcamError, match="WOODCAM_MAX_IMAGE_PIXELS"):
        read_block(folder)


def test_mokume_damaged_image(tmp_path):
    from woodcam.block.io import read_mokume

    (tmp_path / "A_col.png").write_bytes(b"")
    with pytest.raises(WoodcamError, match="cannot decode"):
        read_mokume(tmp_path)


@pytest.mark.parametrize("side", range(6))
def test_stl_missing_a_side_is_capped_flat_and_said(tmp_path, side):
    """Issue 15: an STL box missing one side came back as an 833 mm^3 solid, silently."""
    import trimesh

    from woodcam.cad import load_part
    from woodcam.errors import WoodcamWarning

    box = trimesh.creation.box(extents=(10, 10, 10))
    normal = np.eye(3)[side // 2] * (1 if side % 2 else -1)
    on_side = np.flatnonzero(np.all(np.isclose(box.face_normals, normal), axis=1))
    assert len(on_side) == 2
    holey = trimesh.Trimesh(box.vertices, np.delete(box.faces, on_side, axis=0))
    holey.export(tmp_path / "holey.stl")
    with pytest.warns(WoodcamWarning, match="was not closed: 4 open edges in 1 hole"):
        solid = load_part(tmp_path / "holey.stl")
    assert solid.volume() == pytest.approx(1000.0, rel=1e-9)


def test_stl_with_a_hole_that_is_not_flat_is_refused(tmp_path):
    """Two triangles of two different sides missing: a cap is a guess (917 or 1000 mm^3)."""
    import trimesh

    from woodcam.cad import load_part

    box = trimesh.creation.box(extents=(10, 10, 10))
    n = box.face_normals
    a = np.flatnonzero(np.isclose(n[:, 0], -1))[0]
    b = np.flatnonzero(np.isclose(n[:, 1], -1) & np.isin(box.faces, box.faces[a]).sum(1).astype(bool))
    b = b[np.isin(box.faces[b], box.faces[a]).sum(1) == 2][0]  # shares an edge with a
    trimesh.Trimesh(box.vertices, np.delete(box.faces, [a, b], axis=0)).export(tmp_path / "h.stl")
    with pytest.raises(WoodcamError, match="is not flat"):
        load_part(tmp_path / "h.stl")


@pytest.mark.parametrize("points, year, match", [
    ([[0, 0], [1, float("nan")]], 1, "must be finite"),
    ([[0, 0], [1, 1]], 10**12, "year of a ring trace must be an integer"),
    ([[0, 0], [1, 1]], 2.5, "year of a ring trace must be an integer"),
    ([[0, 0], [1, 1]], True, "year of a ring trace must be an integer"),
])
def test_ring_trace_checks_its_numbers(points, year, match):
    with pytest.raises(WoodcamError, match=match):
        RingTrace(np.array(points, float), year)
    assert RingTrace(np.zeros((2, 2)), 3.0).year == 3


@pytest.mark.parametrize("toml, match", [
    ('[tools.1]\ntype = "flat"\ndiameter_mm = "6"\n', r"diameter_mm must be a number"),
    ('[tools.1]\ntype = "flat"\ndiameter_mm = [6]\n', r"diameter_mm must be a number"),
    ('[tools]\n1 = 5\n', r"tools.1 must be a table"),
    ('[tools.1]\ntype = 3\ndiameter_mm = 6\n', r"needs type"),
    ('[tools.1]\ntype = "flat"\ndiameter_mm = 1e300\n', r"diameter_mm must be a positive number in \(0, 1000\]"),
    ('[tools.1]\ntype = "flat"\ndiameter_mm = nan\n', r"diameter_mm must be a positive number"),
    ('[tools.1]\ntype = "vbit"\ndiameter_mm = 6\nangle_deg = true\n', r"angle_deg must be a number"),
    ('[tools.-3]\ntype = "flat"\ndiameter_mm = 6\n', r"tool number .* must be in \[0, 99999\]"),
])
def test_tool_table_types_are_checked(tmp_path, toml, match):
    from woodcam.toolpath.tools import load_tool_table

    (tmp_path / "t.toml").write_text(toml)
    with pytest.raises(WoodcamError, match=match):
        load_tool_table(tmp_path / "t.toml")


def test_tool_table_bytes_that_are_not_utf8(tmp_path):
    from woodcam.toolpath.tools import load_tool_table

    (tmp_path / "t.toml").write_bytes(b'[tools.1]\ntype = "\xff"\n')
    with pytest.raises(WoodcamError, match="not valid TOML"):
        load_tool_table(tmp_path / "t.toml")


@pytest.mark.parametrize("edit, match", [
    (lambda d: d.update(pith_z_mm="abc"), r"pith_z_mm must be \(h,\) heights in mm \(numbers\); got 'abc'"),
    (lambda d: d.update(radii_mm=[[1, 2]]), r"radii_mm"),
    (lambda d: d["radii_mm"][0].__setitem__(0, 1e400), r"finite numbers|must be finite"),
    (lambda d: d["pith_xy_mm"][0].__setitem__(0, None),
     r"pith_xy_mm must be \(h, 2\) pith points in mm \(numbers\); got \[\[None, 0\.0\]"),
    (lambda d: d.update(knots=[{"z0_mm": 1}]), r"missing the key"),
    (lambda d: d.update(knots=[5]), r"wrong type"),
    (lambda d: d.clear(), r"format must be 'woodcam-log'"),
])
def test_log_file_types_are_checked(tmp_path, edit, match):
    from woodcam.fields.skeleton import simple_log
    from woodcam.logs.io import read_log

    d = simple_log(100.0, 30.0, z_step_mm=20.0, azimuths=6).to_json()
    edit(d)
    (tmp_path / "log.json").write_text(json.dumps(d))
    with pytest.raises(WoodcamError, match=match) as err:
        read_log(tmp_path / "log.json")
    # the file is named (sweep h6: "log file format must be 'woodcam-log'; got None" left the
    # user of 'woodcam log render a.json b.json'-style scripts guessing which file)
    assert repr(str(tmp_path / "log.json")) in str(err.value), str(err.value)
    # and the fix is a command (sweep h4: 'woodcam log render' was told to "write the file with
    # woodcam.logs.write_log", a Python function)
    if match in (r"wrong type", r"format must be 'woodcam-log'"):
        assert "'woodcam log export'" in str(err.value), str(err.value)


@pytest.mark.parametrize("content", [b"", b"\x89PNG\r\n\x1a\n\xff", b"{"])
def test_a_log_file_that_is_no_json_says_what_to_give(tmp_path, content):
    """'woodcam log render photo.png' said "log file: 'photo.png' is not UTF-8 text (invalid
    start byte)" and an empty file "must be valid JSON ...: Expecting value", with no fix (sweep h4)."""
    from woodcam.logs.io import read_log

    (tmp_path / "log.json").write_bytes(content)
    with pytest.raises(WoodcamError, match=r"; give a woodcam log file \(JSON, as 'woodcam log export' writes\), "
                       r"or --real for the measured log$"):
        read_log(tmp_path / "log.json")
