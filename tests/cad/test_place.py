"""Placing foreign parts (--place) and sized / turned blocks (issue 16 part 5)."""

from __future__ import annotations

import manifold3d
import numpy as np
import pytest

from woodcam.cad.place import place_part
from woodcam.errors import WoodcamError
from woodcam.stock import open_stock


def _bounds(solid):
    return np.asarray(solid.bounding_box()).reshape(2, 3)


def test_rotate_center_drop_place_a_box_exactly():
    box = manifold3d.Manifold.cube([10.0, 20.0, 30.0]).translate([-50.0, 7.0, 3.0])
    placed, matrix = place_part(box, ["rotate:x:90", "center", "drop"], (100.0, 80.0, 50.0))
    lo, hi = _bounds(placed)
    np.testing.assert_allclose(hi - lo, [10.0, 30.0, 20.0], atol=1e-9)  # y and z swapped
    np.testing.assert_allclose((lo + hi)[:2] / 2, [50.0, 40.0], atol=1e-9)  # centred in x, y
    assert lo[2] == pytest.approx(0.0, abs=1e-9)  # resting on the bottom face
    assert placed.volume() == pytest.approx(6000.0)
    np.testing.assert_allclose(np.linalg.det(matrix[:3, :3]), 1.0)


def _nubbed_box(axis: int):
    """A 30 mm cube centred at the origin with a 4 mm nub on the middle of its +``axis`` face."""
    nub = np.zeros(3)
    nub[axis] = 17.0
    return (manifold3d.Manifold.cube([30.0] * 3, center=True)
            + manifold3d.Manifold.cube([4.0] * 3, center=True).translate(nub))


@pytest.mark.parametrize("axis", ["x", "y", "z"])
def test_a_quarter_turn_follows_the_right_hand_rule(axis):
    """rotate:AXIS:90 turns by the right hand rule: about x, +y goes to +z; about y, +z goes to
    +x; about z, +x goes to +y. The box's extents alone cannot tell +90 from -90; its nub on one
    face can. rotate:y turned the other way (left-handed) before this test."""
    i = {"x": 1, "y": 2, "z": 0}[axis]  # the face the nub starts on
    j = {"x": 2, "y": 0, "z": 1}[axis]  # where the right hand sends it
    placed, matrix = place_part(_nubbed_box(i), [f"rotate:{axis}:90"], (100.0, 80.0, 50.0))
    want = np.zeros(3)
    want[j] = 1.0
    np.testing.assert_allclose(matrix[:3, :3] @ np.eye(3)[i], want, atol=1e-12)
    lo, hi = _bounds(placed)
    # the nub sticks out 4 mm on the +j side of the turned cube (about the bounding box's centre,
    # which is 2 mm towards the nub: the cube spans [-17, 13] there and the nub reaches 17)
    assert hi[j] - lo[j] == pytest.approx(34.0, abs=1e-9)
    top = placed.trim_by_plane(list(want), float(hi[j]) - 3.0)  # the part beyond the cube's face
    assert top.volume() == pytest.approx(3 * 16.0, rel=1e-9)


def test_fit_scales_into_the_block_with_the_margin():
    big = manifold3d.Manifold.cube([400.0, 100.0, 100.0])
    placed, matrix = place_part(big, ["fit:5"], (100.0, 80.0, 50.0))
    lo, hi = _bounds(placed)
    np.testing.assert_allclose(lo[0], 5.0, atol=1e-9)
    np.testing.assert_allclose(hi[0], 95.0, atol=1e-9)  # the long side sets the scale: 90/400
    assert np.all(lo >= 5.0 - 1e-9) and np.all(hi <= np.array([95.0, 75.0, 45.0]) + 1e-9)
    assert matrix[0, 0] == pytest.approx(90.0 / 400.0)


@pytest.mark.parametrize(("ops", "match"), [
    (["rotate:w:90"], "rotate:AXIS:DEG"), (["translate:1,2"], "translate:X,Y,Z"),
    (["scale:-1"], r"scale must be in \(0, 1000\]"), (["spin"], "is not a placement operation"),
    # these overflowed: the part's volume became NaN (its warnings vanished) or 0 ("inside-out?")
    (["scale:1e300"], r"scale must be in \(0, 1000\]"), (["translate:1e300,0,0"], "within 100 m"),
    (["translate:1,nan,2"], "not a finite number"), (["fit:60"], "leaves no room")])
def test_bad_placements_are_clear_errors(ops, match):
    with pytest.raises(WoodcamError, match=match):
        place_part(manifold3d.Manifold.cube([1.0, 1.0, 1.0]), ops, (100.0, 80.0, 50.0))


def test_a_near_miss_of_an_operation_is_named():
    """'--place centre' (British, as woodcam's own help writes 'the block centre') was told only
    the list of operations; a near spelling is named first, a far one is not guessed at."""
    from woodcam.cad.place import parse_place

    with pytest.raises(WoodcamError, match=r"^--place 'centre' is not a placement operation; did you mean "
                       r"'center'\? use rotate:AXIS:DEG, "):
        parse_place(["centre"])
    with pytest.raises(WoodcamError, match=r"^--place 'Rotat:z:90' is not a placement operation; did you mean "
                       r"'rotate'\? "):
        parse_place(["Rotat:z:90"])
    with pytest.raises(WoodcamError, match=r"^--place 'spin' is not a placement operation; use rotate"):
        parse_place(["spin"])


def test_a_sized_builtin_block_is_the_same_wood_round_the_same_centre():
    small = open_stock("builtin:flat-sawn")
    big = open_stock("builtin:flat-sawn:300x120x40")
    assert big.size_mm == (300.0, 120.0, 40.0)
    rng = np.random.default_rng(0)
    offsets = rng.uniform(-20.0, 20.0, (200, 3))
    a = small.wood.years(np.asarray(small.size_mm) / 2 + offsets)
    b = big.wood.years(np.asarray(big.size_mm) / 2 + offsets)
    np.testing.assert_allclose(a, b, atol=1e-9)
    with pytest.raises(WoodcamError, match="the size must be WxDxH"):
        open_stock("builtin:flat-sawn:300x0x40")


def test_turning_the_block_turns_its_wood():
    plain = open_stock("builtin:flat-sawn")
    turned = open_stock("builtin:flat-sawn~z90")
    W, D, H = plain.size_mm
    assert turned.size_mm == (D, W, H)
    # a quarter turn about z (right hand): old (x, y, z) sits at new (D - y, x, z)
    rng = np.random.default_rng(1)
    p = rng.uniform([0, 0, 0], plain.size_mm, (300, 3))
    q = np.column_stack([D - p[:, 1], p[:, 0], p[:, 2]])
    np.testing.assert_allclose(turned.wood.years(q), plain.wood.years(p), atol=1e-9)
    n = np.tile([1.0, 0.0, 0.0], (len(p), 1))  # +x in the old block is +y in the turned one
    np.testing.assert_allclose(turned.wood.color(q, n[:, [1, 0, 2]]), plain.wood.color(p, n),
                               atol=1e-6)
    # about x (+y to +z) and y (+z to +x), right hand: a left-handed turn would give the same
    # sizes and mirror the wood
    for turn, size, moved in (
            ("x", (W, H, D), lambda p: np.column_stack([p[:, 0], H - p[:, 2], p[:, 1]])),
            ("y", (H, D, W), lambda p: np.column_stack([p[:, 2], p[:, 1], W - p[:, 0]]))):
        other = open_stock(f"builtin:flat-sawn~{turn}90")
        assert other.size_mm == size, turn
        np.testing.assert_allclose(other.wood.years(moved(p)), plain.wood.years(p), atol=1e-9,
                                   err_msg=turn)
    full = open_stock("builtin:flat-sawn~z90~z90~z90~z90")
    np.testing.assert_allclose(full.wood.years(p), plain.wood.years(p), atol=1e-9)
    with pytest.raises(WoodcamError, match="multiple of 90 degrees"):
        open_stock("builtin:flat-sawn~z45")


def test_ops_as_typed_must_match_the_ops_one_for_one():
    """placement_matrix quotes each op as the user typed it; a list of another length raised a
    bare ValueError from zip: it is refused naming as_typed, and --place's translate rule names
    the units of both doors."""
    from woodcam.cad.place import placement_matrix

    box = ((0, 0, 0), (10, 10, 10))
    with pytest.raises(WoodcamError, match=r"as_typed must hold one text per operation \(2\); got 1"):
        placement_matrix(["center", "rotate:z:90"], box, (50, 50, 50), as_typed=["center"])
    with pytest.raises(WoodcamError, match=r"--place 'translate:1,2': expected translate:X,Y,Z "
                                           r"\(in --units on the command line, mm in the library\)"):
        placement_matrix(["translate:1,2"], box, (50, 50, 50))


def test_a_negative_fit_margin_is_refused_with_the_fix():
    """Review of f41a6cd: parse_place said 'a margin must be >= 0; got -0.1 mm' and no fix; it
    names the two that work (no margin, the default one)."""
    from woodcam.cad.place import parse_place

    with pytest.raises(WoodcamError, match=r"--place 'fit:-0.1': a margin must be >= 0; got -0.1 mm; "
                                           r"write fit:0 for none, or fit for 2 mm"):
        parse_place(["center", "fit:-0.1"])
    assert parse_place(["fit:0", "fit"]) == [("fit", 0.0, "fit:0"), ("fit", 2.0, "fit")]


def test_an_absurd_angle_is_refused_and_a_too_wide_fit_margin_says_the_largest():
    """Walkthrough: 'rotate:z:1e308' was taken (the part turned by float noise: a typo, surely),
    and 'fit:1000' said the margin 'leaves no room' without the margin that does."""
    from woodcam.cad.place import parse_place

    for deg in ("1e308", "-361", "720"):
        with pytest.raises(WoodcamError, match=rf"--place 'rotate:z:{deg}': an angle must be within a full "
                                               r"turn, -360 to 360 degrees; got .*; write it modulo 360"):
            parse_place([f"rotate:z:{deg}"])
    assert parse_place(["rotate:z:-360", "rotate:x:360"])[0][1] == (2, -360.0)
    with pytest.raises(WoodcamError, match=r"--place 'fit:1000': a margin of 1000 mm leaves no room in the "
                                           r"100x80x50 mm block; a margin must be less than half its smallest "
                                           r"side: write fit:MARGIN with MARGIN below 25 mm, or fit for 2 mm$"):
        place_part(manifold3d.Manifold.cube([1.0, 1.0, 1.0]), ["fit:1000"], (100.0, 80.0, 50.0))
    placed, _ = place_part(manifold3d.Manifold.cube([1.0, 1.0, 1.0]), ["fit:24.9"], (100.0, 80.0, 50.0))
    assert _bounds(placed)[1][2] == pytest.approx(25.1)
