"""Tools: exact profiles, specs, tool tables, and the closed-form sweep kernels vs brute force."""

from __future__ import annotations

import math

import numpy as np
import pytest

from woodcam.errors import WoodcamError, WoodcamWarning
from woodcam.toolpath import (BallEndMill, BullNoseMill, ChamferMill, FlatEndMill,
                              SnubNoseVBit, TaperedBallMill, VBit, load_camotics_tools,
                              load_tool_table,
                              parse_tool_spec)


def test_profiles_are_the_analytic_shapes():
    r = np.array([0.0, 0.5, 1.0, 1.5, 2.0, 2.5])
    assert np.all(FlatEndMill(4).profile(r[:5]) == 0) and FlatEndMill(4).profile(2.5) == np.inf
    np.testing.assert_allclose(BallEndMill(4).profile(r[:5]), 2 - np.sqrt(4 - r[:5] ** 2))
    np.testing.assert_allclose(VBit(4, angle_deg=90).profile(r[:5]), r[:5])  # 45 deg flanks
    np.testing.assert_allclose(VBit(4, angle_deg=60).profile(1.0), math.sqrt(3))
    bull = BullNoseMill(4, corner_radius_mm=1)
    np.testing.assert_allclose(bull.profile([0, 1, 1.5, 2]),
                               [0, 0, 1 - math.sqrt(0.75), 1])
    assert BallEndMill(4).profile_height_mm == pytest.approx(2)


@pytest.mark.parametrize("spec, tool", [
    ("flat:6.35", FlatEndMill(6.35)), ("ball:3", BallEndMill(3)),
    ("bull:6:1", BullNoseMill(6, corner_radius_mm=1)), ("VBit:60:12", VBit(12, angle_deg=60)),
])
def test_parse_tool_spec(spec, tool):
    assert parse_tool_spec(spec) == tool
    assert parse_tool_spec(tool.spec()) == tool


@pytest.mark.parametrize("spec, match", [
    ("drill:3", "type must be one of"), ("ball", "takes 1 number"), ("vbit:60", "takes 2"),
    ("flat:x", "numbers expected"), ("flat:-1", "diameter_mm must be a positive"),
    ("bull:6:4", "corner_radius_mm must be in"), ("vbit:180:6", "angle_deg"),
])
def test_parse_tool_spec_errors(spec, match):
    with pytest.raises(WoodcamError, match=match):
        parse_tool_spec(spec)


def test_load_tool_table(tmp_path):
    p = tmp_path / "tools.toml"
    p.write_text('[tools.1]\ntype = "flat"\ndiameter_mm = 6.35\n'
                 '[tools.2]\ntype = "vbit"\ndiameter_mm = 12\nangle_deg = 60\n'
                 '[tools.5]\ntype = "bull"\ndiameter_mm = 6\ncorner_radius_mm = 1\n')
    assert load_tool_table(p) == {1: FlatEndMill(6.35), 2: VBit(12, angle_deg=60),
                                  5: BullNoseMill(6, corner_radius_mm=1)}
    p.write_text('[tools.1]\ntype = "vbit"\ndiameter_mm = 12\n')
    with pytest.raises(WoodcamError, match="angle_deg"):
        load_tool_table(p)
    p.write_text('[tools.one]\ntype = "flat"\ndiameter_mm = 3\n')
    with pytest.raises(WoodcamError, match="must be the tool number"):
        load_tool_table(p)
    with pytest.raises(WoodcamError, match="does not exist"):
        load_tool_table(tmp_path / "missing.toml")
    # a typo was ignored: flute_length (for flute_length_mm) silently turned the reach checks off
    p.write_text('[tools.5]\ntype = "flat"\ndiameter_mm = 3\nflute_length = 2\n')
    with pytest.raises(WoodcamError, match=r"\[tools.5\] \(type 'flat'\) has unknown key\(s\) \['flute_length'\]"):
        load_tool_table(p)
    p.write_text('[tools.5]\ntype = "flat"\ndiameter_mm = 3\nangle_deg = 60\n')  # not a flat's
    with pytest.raises(WoodcamError, match=r"unknown key\(s\) \['angle_deg'\]"):
        load_tool_table(p)
    p.write_text('[tools.5]\ntype = "flat"\ndiameter_mm = 3\nflute_length_mm = 2\ndescription = "1/8 in"\n')
    assert load_tool_table(p)[5].flute_length_mm == 2


TOOLS = [FlatEndMill(6), BallEndMill(6), BullNoseMill(6, corner_radius_mm=1.5),
         VBit(8, angle_deg=60), VBit(8, angle_deg=150),
         SnubNoseVBit(6, angle_deg=60, tip_diameter_mm=1.0),
         ChamferMill(6, angle_deg=90, tip_diameter_mm=2.0),
         TaperedBallMill(6, tip_diameter_mm=1.5, taper_deg=10)]


@pytest.mark.parametrize("tool", TOOLS, ids=lambda t: t.spec())
@pytest.mark.parametrize("slope", [0.0, 0.3, -0.8, 2.5, -6.0])
def test_sweep_kernel_matches_brute_force_minimum(tool, slope, rng):
    """Closed-form lower envelope == min over 20,001 samples of the move (same cells)."""
    L, z0 = 5.0, 1.0
    along = rng.uniform(-4, 9, 200).astype(np.float32)
    d = rng.uniform(0, 3.3, 200).astype(np.float32)
    env = tool._sweep(along[None, None], (d * d)[None, None], np.float32(slope),
                      np.float32(L), np.float32(z0))[0, 0]
    t = np.linspace(0, L, 20_001)
    rho = np.hypot(along[:, None] - t[None, :], d[:, None])
    brute = (z0 + slope * t[None, :] + tool.profile(rho)).min(axis=1)
    covered = np.isfinite(brute)
    assert np.array_equal(np.isfinite(env), covered)
    # sampling step 2.5e-4 mm: the sampled minimum is above the true one by at most
    # step * (|slope| + max profile slope on the way); float32 kernel ~1e-6 relative
    np.testing.assert_allclose(env[covered], brute[covered], atol=1e-3 + 3e-4 * abs(slope))
    assert np.all(env[covered] <= brute[covered] + 1e-5)


def test_new_profiles_specs_and_tables(tmp_path):
    snub = parse_tool_spec("snub:60:6:1")
    assert snub == SnubNoseVBit(6, angle_deg=60, tip_diameter_mm=1)
    np.testing.assert_allclose(snub.profile([0.0, 0.5, 1.5]), [0, 0, math.sqrt(3)])
    assert parse_tool_spec("chamfer:90:12:2").profile(4.0) == pytest.approx(3.0)
    tb = parse_tool_spec("taperball:6:1:10")
    rt = 0.5 * math.cos(math.radians(10))
    h = tb.profile(np.array([0.0, rt, 2.0]))
    assert h[0] == 0 and h[1] == pytest.approx(0.5 - math.sqrt(0.25 - rt * rt))
    assert h[2] == pytest.approx(h[1] + (2.0 - rt) / math.tan(math.radians(10)))
    for spec in ("snub:60:6:1", "chamfer:90:12:2", "taperball:6:1:10"):
        assert parse_tool_spec(spec).spec() == spec
    with pytest.raises(WoodcamError, match="tip_diameter_mm"):
        parse_tool_spec("snub:60:6:7")
    p = tmp_path / "t.toml"
    p.write_text('[tools.4]\ntype = "taperball"\ndiameter_mm = 6\ntip_diameter_mm = 1\n'
                 'taper_deg = 10\n[tools.5]\ntype = "snub"\ndiameter_mm = 6\nangle_deg = 60\n'
                 'tip_diameter_mm = "x"\n')
    with pytest.raises(WoodcamError, match="must be a number"):
        load_tool_table(p)
    # CAMotics: a cone is its diameter and the length of its conical part
    j = tmp_path / "tools.json"
    j.write_text('{"tools": {"1": {"units": "imperial", "shape": "cylindrical", '
                 '"diameter": 0.25, "length": 1}, "2": {"units": "metric", "shape": "conical",'
                 ' "diameter": 10, "length": 5}, "3": {"shape": "snubnose", "diameter": 6, '
                 '"snub_diameter": 2, "length": 2}, "4": {"shape": "ballnose", "diameter": 3}}}')
    with pytest.warns(WoodcamWarning, match=r"tool 4 \(ballnose\) gives no \"length\""):
        tools = load_tool_table(j)
    # a cylindrical tool's length is its cutting (flute) length: 1 inch; none: CAMotics' 10 mm
    assert tools[1] == FlatEndMill(6.35, flute_length_mm=25.4)
    assert tools[4] == BallEndMill(3, flute_length_mm=10)
    assert tools[2] == VBit(10, angle_deg=90, flute_length_mm=5)
    assert tools[3] == SnubNoseVBit(6, angle_deg=90, tip_diameter_mm=2, flute_length_mm=2)
    j.write_text('{"tools": {"1": {"shape": "spheroid", "diameter": 3}}}')
    with pytest.raises(WoodcamError, match="shape"):
        load_camotics_tools(j)


def test_a_camotics_table_reads_as_camotics_reads_it(tmp_path):
    """CAMotics' Tool::read takes units and shapes in any case, with its aliases (units mm and
    inch, shapes cylinder and cone): woodcam refused 'Imperial', 'inch' and 'Cylinder'. Its
    'length' is the whole cutter from the tip, a cone's too: a V-bit cutting past its cone was
    simulated with no word, where a cylindrical tool's length already warned (the shank rubs).
    A spheroid, which woodcam has no tool for, is refused naming the fix."""
    j = tmp_path / "tools.json"
    j.write_text('{"1": {"units": "Imperial", "shape": "Cylinder", "diameter": 0.25, "length": 1},'
                 ' "2": {"units": "inch", "shape": "Cone", "diameter": 0.5, "length": 0.25},'
                 ' "3": {"units": "MM", "shape": "BallNose", "diameter": 6, "length": 20}}')
    tools = load_camotics_tools(j)
    assert tools[1] == FlatEndMill(6.35, flute_length_mm=25.4)
    assert tools[2] == VBit(12.7, angle_deg=90, flute_length_mm=6.35)
    assert tools[3] == BallEndMill(6, flute_length_mm=20)
    for units in ('"furlong"', "3"):
        j.write_text('{"1": {"units": %s, "shape": "cylindrical", "diameter": 6}}' % units)
        with pytest.raises(WoodcamError, match="units must be metric or imperial"):
            load_camotics_tools(j)
    j.write_text('{"1": {"shape": "Sphere", "diameter": 6}}')
    with pytest.raises(WoodcamError, match="shape 'sphere' .*has no woodcam tool"):
        load_camotics_tools(j)


def test_a_camotics_entry_number_names_its_tool(tmp_path):
    """CAMotics' Tool::read takes an entry's "number" over its key (ToolTable::set files the
    tool under it): woodcam filed {"1": {"number": 3, ...}} as tool 1, so the program's T3 had
    no tool and T1 cut with it. Two entries on one number (CAMotics keeps the later one, no
    word) are refused, naming both keys; a number not a tool number is refused."""
    j = tmp_path / "tools.json"
    j.write_text('{"1": {"number": 3, "shape": "ballnose", "diameter": 6, "length": 20},'
                 ' "2": {"shape": "cylindrical", "diameter": 3, "length": 12}}')
    assert load_camotics_tools(j) == {3: BallEndMill(6, flute_length_mm=20),
                                      2: FlatEndMill(3, flute_length_mm=12)}
    j.write_text('{"1": {"number": 2, "shape": "ballnose", "diameter": 6, "length": 20},'
                 ' "2": {"shape": "cylindrical", "diameter": 3, "length": 12}}')
    with pytest.raises(WoodcamError, match="tool 2 and tool 1 are both tool 2 .*own number"):
        load_camotics_tools(j)
    for bad in ('"3"', "-1", "2.5", "true"):
        j.write_text('{"1": {"number": %s, "shape": "ballnose", "diameter": 6, "length": 20}}' % bad)
        with pytest.raises(WoodcamError, match='tool 1: "number" must be a tool number'):
            load_camotics_tools(j)


def test_a_camotics_tool_without_length_is_said(tmp_path):
    """Without "length" CAMotics takes 10 mm (Tool's constructor: ToolTable::read builds a metric
    Tool, then Tool::read leaves its length alone): woodcam gave a cylindrical or ball-nose tool
    no flute length (no limit: cuts past its flutes went unwarned) and refused a cone, so the
    tool it simulated was not the one CAMotics cuts with. It now takes 10 mm for every shape,
    in mm for an imperial entry too (not 10 in, not 1 in), a cone's angle from it, and one
    warning names the tools and the length taken."""
    j = tmp_path / "tools.json"
    j.write_text('{"1": {"shape": "cylindrical", "diameter": 3}, "2": {"shape": "ballnose",'
                 ' "diameter": 6, "units": "imperial"}, "5": {"shape": "ballnose", "diameter": 6,'
                 ' "length": 20}, "7": {"number": 8, "shape": "cone", "diameter": 20}}')
    with pytest.warns(WoodcamWarning, match=r'tools 1 \(cylindrical\), 2 \(ballnose\), 8 \(conical, '
                      r"key '7'\) give no \"length\": each is taken as 10 mm long, as CAMotics takes "
                      r"it .*in mm whatever the entry's units") as caught:
        tools = load_camotics_tools(j)
    assert len(caught) == 1
    assert tools[1] == FlatEndMill(3, flute_length_mm=10)
    assert tools[2] == BallEndMill(6 * 25.4, flute_length_mm=10)  # the 10 mm is not scaled
    assert tools[5] == BallEndMill(6, flute_length_mm=20)
    # CAMotics' cone of diameter 20 and length 10: 2 atan(10 / 10) = 90 degrees
    assert tools[8] == VBit(20, angle_deg=90, flute_length_mm=10)
    j.write_text('{"1": {"shape": "snubnose", "diameter": 12, "snub_diameter": 2}}')
    with pytest.warns(WoodcamWarning, match=r'tool 1 \(snubnose\) gives no "length": it is taken as 10 mm'):
        assert load_camotics_tools(j)[1] == SnubNoseVBit(12, angle_deg=2 * math.degrees(math.atan(0.5)),
                                                         tip_diameter_mm=2, flute_length_mm=10)
    j.write_text('{"1": {"shape": "cylindrical", "diameter": 3, "length": 12}}')
    load_camotics_tools(j)  # a length given: no word (filterwarnings = error)


def test_a_v_bit_cutting_past_its_camotics_cone_is_warned(tmp_path):
    """A CAMotics V-bit 10 mm across with a 5 mm cone (90 degrees) plunged 7 mm: the shank rubs
    the top 2 mm; warned as a cylindrical tool's short length is (deeper_than_flute)."""
    from woodcam.toolpath import read_gcode, simulate

    j = tmp_path / "tools.json"
    j.write_text('{"1": {"shape": "conical", "diameter": 10, "length": 5}}')
    prog = read_gcode("G21 G90\nT1 M6\nG0 X10 Y10 Z5\nG1 Z-7 F300\nG1 X30\nG0 Z5\nM30\n")
    res = simulate(prog, load_camotics_tools(j), (40.0, 20.0, 10.0), resolution_mm=0.5)
    assert any("deeper_than_flute" in str(i) for i in res.report), res.report
