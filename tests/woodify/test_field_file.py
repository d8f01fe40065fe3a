"""``field.npz`` of a woodified object: the file's suffix rule and refusing a broken file."""

from __future__ import annotations

import re

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from woodcam.cli import main
from woodcam.errors import WoodcamError
from woodcam.fields.grid import GridField
from woodcam.woodify import WoodifiedField
from woodcam.woodify.speed import GrowthSpeed

FIX = "write it again with 'woodcam woodify MESH --out DIR' (it writes DIR/field.npz)"


def _field() -> WoodifiedField:
    return WoodifiedField(np.arange(27.0).reshape(3, 3, 3), (0, 0, 0), 1.0, GrowthSpeed(10, 5), 3.0)


@pytest.mark.parametrize("name, written", [("F.NPZ", "F.NPZ"), ("f.npz", "f.npz"), ("f", "f.npz"),
                                           ("f.bin", "f.bin.npz")])
def test_save_takes_the_npz_suffix_rule_of_every_npz_writer(tmp_path, name, written):
    """'.NPZ' was refused ('path must end in .npz'); the grid field's writer keeps it as named."""
    f = _field()
    out = f.save(tmp_path / "sub" / name)
    assert out == tmp_path / "sub" / written
    assert sorted(p.name for p in (tmp_path / "sub").iterdir()) == [written]
    back = WoodifiedField.load(out)
    np.testing.assert_array_equal(back.arrival_mm, f.arrival_mm)
    assert back.years_final == f.years_final


@pytest.mark.parametrize("kind, why", [
    ("truncated", "not a zip \\(.npz\\) archive: truncated"),
    ("garbage", "not a zip \\(.npz\\) archive: truncated"),
    ("another npz", "'format is not a file in the archive'"),
])
def test_a_broken_field_file_is_one_error_naming_it_the_rule_and_the_fix(tmp_path, kind, why):
    """A truncated field.npz was numpy's BadZipFile (an internal error), a text file its
    'pickled data' message."""
    path = _field().save(tmp_path / "field.npz")
    if kind == "truncated":
        data = path.read_bytes()
        path.write_bytes(data[: len(data) // 2])
    elif kind == "garbage":
        path.write_text("not a field")
    else:
        np.savez(path, a=np.zeros(3))
    with pytest.raises(WoodcamError) as err:
        WoodifiedField.load(path)
    msg = str(err.value)
    assert msg.startswith(f"{path}: not a woodcam woodify field (woodcam-woodify-field-1 .npz")
    assert msg.endswith(FIX)
    assert re.search(why, msg)


def test_bake_from_a_truncated_field_is_one_line(tmp_path, capsys):
    path = _field().save(tmp_path / "field.npz")
    path.write_bytes(path.read_bytes()[:100])
    trimesh.creation.box((1, 1, 1)).export(tmp_path / "part.stl")
    rc = main(["bake", str(tmp_path / "part.stl"), "--block", f"woodify:{path}", "--out", str(tmp_path / "o.glb")])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc != 0
    assert len(err) == 1 and "internal error" not in err[0]
    assert err[0].startswith(f"woodcam: error: {path}: not a woodcam woodify field") and err[0].endswith(FIX)


def test_to_block_is_the_inverse_of_to_object_for_a_turned_block():
    """to_block (object frame -> block frame: where the grown input lies in the block) undoes
    to_object, also for a block placed turned (WoodifiedField.placed(rotation=))."""
    from scipy.spatial.transform import Rotation

    R = Rotation.from_euler("xyz", [20.0, -35.0, 70.0], degrees=True).as_matrix()
    f = _field().placed((1.5, 1.0, 0.5), (1.0, 1.2, 0.8), R)
    p = np.random.default_rng(0).uniform(-2.0, 3.0, (50, 3))
    np.testing.assert_allclose(f.to_object(f.to_block(p)), p, atol=1e-12)
    np.testing.assert_allclose(f.to_block(f.to_object(p)), p, atol=1e-12)
    np.testing.assert_allclose(f.to_block(f.block_origin_mm[None]), 0.0, atol=1e-12)


@pytest.mark.parametrize("load", [WoodifiedField.load, GridField.load],
                         ids=["woodify field", "grid field"])
@pytest.mark.parametrize("path", [None, 3])
def test_load_refuses_a_path_that_is_not_one_naming_the_argument(load, path):
    """GridField.load(None) was "None: not a woodcam grid field ...: expected str, bytes or
    os.PathLike object, not NoneType" (None taken as a file name), WoodifiedField.load(None)
    Path()'s bare TypeError."""
    with pytest.raises(WoodcamError, match=rf"^path must be a file path \(str or pathlib\.Path\); got {path}; "
                                           r"pass the path of .*\.npz"):
        load(path)


@pytest.mark.parametrize("d, match", [
    (None, r"got None"), ([1, 2], r"got \[1, 2\]"),
    ({"velocity_mm": 10}, r"got a dict without time_scale_years, shape, eccentricity, up"),
])
def test_growth_speed_from_dict_refuses_anything_but_its_dict(d, match):
    """GrowthSpeed.from_dict(None) was a bare TypeError ("'NoneType' object is not
    subscriptable"), a missing key a bare KeyError; '10' was read as 10.0 by float()."""
    with pytest.raises(WoodcamError, match=r"^d must be a growth speed dict with keys velocity_mm, time_scale_years, "
                                           r"shape, eccentricity, up \(GrowthSpeed\.to_dict\(\)\); " + match + "; e.g. {"):
        GrowthSpeed.from_dict(d)
    good = GrowthSpeed(10, 5, 1.5, 0.2).to_dict()
    with pytest.raises(WoodcamError, match=r"velocity_mm must be a number; got '10'"):
        GrowthSpeed.from_dict({**good, "velocity_mm": "10"})
    assert GrowthSpeed.from_dict(good) == GrowthSpeed(10, 5, 1.5, 0.2)


_UP = st.tuples(*[st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False)] * 3).filter(
    lambda v: float(np.linalg.norm(v)) > 1e-6)


@settings(max_examples=300, derandomize=True, deadline=None)
@given(up=_UP, eccentricity=st.floats(-0.9, 0.9))
def test_a_growth_speed_round_trips_its_dict_exactly(up, eccentricity):
    """GrowthSpeed.from_dict(g.to_dict()) differed from g in the last bit of ``up`` for a
    non-axis direction (692 of 2000 random ones): the constructor normalised the ``up`` it was
    given, and normalised the stored, already normalised one again. A direction of length 1 to
    rounding is now kept as given (woodcam._checks.check_vector), so the round trip is exact,
    through JSON too (as field.npz and woodify.json keep it)."""
    import json

    g = GrowthSpeed(12.5, 30.0, 2.0, eccentricity, up)
    assert abs(float(np.linalg.norm(g.up)) - 1.0) < 1e-15  # still normalised once
    for d in (g.to_dict(), json.loads(json.dumps(g.to_dict()))):
        back = GrowthSpeed.from_dict(d)
        assert back == g and back.up == g.up and back.to_dict() == g.to_dict()
