"""Reach checks (issue 18 part 6): cuts deeper than the flutes, shank and holder against the
stock the earlier moves left, warned with their lines (woodcam.toolpath.reach)."""

from __future__ import annotations

import json

import pytest

from woodcam.errors import WoodcamError
from woodcam.toolpath import FlatEndMill, parse_tool_spec, read_gcode, simulate
from woodcam.toolpath.tools import load_tool_table

# a 20 mm slot cut in three 4 mm passes to 12 mm deep (lines 3, 5, 7 plunge; 4, 6, 8 cut)
SLOT = ("M3 S10000\nG0 X20 Y20 Z5\nG1 Z-4 F300\nG1 X40\nG1 Z-8\nG1 X20\nG1 Z-12\nG1 X40\n"
        "G0 Z5\nM2\n")
SIZE = (60.0, 40.0, 20.0)


def _issues(spec, program=SLOT):
    res = simulate(read_gcode(program), parse_tool_spec(spec), SIZE, resolution_mm=0.2)
    return [(i.kind, i.line, i.last_line, i.message) for i in res.report]


def test_a_slot_deeper_than_the_flutes_is_found_on_its_lines_with_its_depth():
    assert _issues("flat:6") == []             # no reach data: nothing to check
    assert _issues("flat:6:flute=15") == []    # 12 mm slot, 15 mm of flute
    # 10 mm of flute: the 8 mm pass is fine (the stock it meets was cut to 4 mm by the pass
    # before, and the walls are 8 mm high); the 12 mm pass rubs 2 mm of wall
    (kind, line, last, msg), = _issues("flat:6:flute=10")
    assert (kind, line, last) == ("deeper_than_flute", 7, 8)
    assert "cuts 12.00 mm deep with 10 mm of flute" in msg and "rubs 2.00 mm" in msg
    # the same 12 mm cut in one plunge is too deep from its first line
    deep = "M3 S10000\nG0 X20 Y20 Z5\nG1 Z-12 F300\nG1 X40\nG0 Z5\nM2\n"
    (kind, line, last, msg), = _issues("flat:6:flute=10", deep)
    assert (kind, line, last) == ("deeper_than_flute", 3, 4)


def test_holder_and_wide_shank_collisions():
    got = _issues("flat:6:flute=11:stickout=11.5:holder=30")
    assert [(k, ln, last) for k, ln, last, _ in got] == [("deeper_than_flute", 7, 8),
                                                         ("holder_collision", 7, 8)]
    assert "30 mm holder (11.5 mm above the tip) meets the stock 0.50 mm deep" in got[1][3]
    # a 3 mm V-bit on a 6 mm shank with 3 mm of flute: the shank rubs the slot's walls from
    # the first 4 mm plunge (1 mm above the flutes)
    (kind, line, last, msg), = _issues("vbit:60:3:flute=3:shank=6")
    assert (kind, line, last) == ("shank_collision", 3, 8)
    assert "6 mm shank meets the stock 1.00 mm above the flutes" in msg
    assert _issues("flat:6:flute=11:stickout=30:holder=30") == [
        ("deeper_than_flute", 7, 8, _issues("flat:6:flute=11")[0][3])]


def test_reach_in_specs_tool_tables_and_errors(tmp_path):
    t = parse_tool_spec("flat:6:flute=22:shank=6:stickout=30:holder=35")
    assert t == FlatEndMill(6, flute_length_mm=22, shank_diameter_mm=6, stickout_mm=30,
                            holder_diameter_mm=35)
    assert parse_tool_spec(t.spec()) == t
    assert t.reach_parts() == [("shank", 3.0, 22.0), ("holder", 17.5, 30.0)]
    toml = tmp_path / "t.toml"
    toml.write_text('[tools.4]\ntype = "ball"\ndiameter_mm = 3\nflute_length_mm = 9\n'
                    'stickout_mm = 20\nholder_diameter_mm = 22\n')
    assert load_tool_table(toml)[4].reach_parts() == [("shank", 1.5, 9.0),
                                                      ("holder", 11.0, 20.0)]
    cam = tmp_path / "t.json"
    cam.write_text(json.dumps({"tools": {"1": {"units": "imperial", "shape": "cylindrical",
                                               "diameter": 0.25, "length": 0.5}}}))
    assert load_tool_table(cam)[1].flute_length_mm == pytest.approx(12.7)
    with pytest.raises(WoodcamError, match="stickout_mm=10 .* shorter than flute_length_mm"):
        parse_tool_spec("flat:6:flute=22:stickout=10:holder=30")
    with pytest.raises(WoodcamError, match="holder_diameter_mm and stickout_mm go together"):
        parse_tool_spec("flat:6:holder=30")
    with pytest.raises(WoodcamError, match="'reach' is not one of"):
        parse_tool_spec("flat:6:reach=3")
    with pytest.raises(WoodcamError, match="flute_length_mm must be None or a positive"):
        FlatEndMill(6, flute_length_mm=-1)


def test_strict_fails_on_a_reach_warning(tmp_path, monkeypatch, capsys):
    from tests.toolpath.test_toolpath_cli import _parse, _stub_preview

    _stub_preview(monkeypatch, {})
    prog = tmp_path / "slot.nc"
    prog.write_text(SLOT)
    base = [str(prog), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "o.glb"),
            "--cell-size", "0.5", "--stock", "60x40x20", "--strict"]
    args = _parse([*base, "--tool", "flat:6:flute=15"])
    assert args.func(args) == 0
    args = _parse([*base, "--tool", "flat:6:flute=10"])
    assert args.func(args) == 3
    assert "lines 7-8: deeper_than_flute" in capsys.readouterr().err


def test_each_move_meets_the_stock_the_earlier_moves_left():
    """A 10 mm facing, then a 12 mm slot inside it: the slot engages only 2 mm, so 11 mm of
    flute is enough; the same slot in the uncut block is too deep (the check replays the
    program in order, and starts from an earlier program's stock)."""
    face = ["M3 S10000", "G0 X10 Y10 Z5", "G1 Z-10 F300"]
    y = 10.0
    while y < 30:
        face += ["G1 X50", f"G1 Y{y + 3:g}", "G1 X10", f"G1 Y{y + 6:g}"]
        y += 6
    slot = ["G0 Z5", "G0 X15 Y20", "G1 Z-12", "G1 X45", "G0 Z5", "M2"]
    assert _issues("flat:6:flute=11", "\n".join(face + slot) + "\n") == []
    alone = "\n".join(["M3 S10000 F300"] + slot[1:]) + "\n"
    (kind, line, _, msg), = _issues("flat:6:flute=11", alone)
    assert kind == "deeper_than_flute" and line == 3 and "12.00 mm deep" in msg
    tool = parse_tool_spec("flat:6:flute=11")
    faced = simulate(read_gcode("\n".join(face + ["G0 Z5", "M2"]) + "\n"), tool, SIZE,
                     resolution_mm=0.2)
    assert faced.report == []
    again = simulate(read_gcode(alone), tool, SIZE, resolution_mm=0.2,
                     initial_heightmap=faced.heightmap)
    assert again.report == []
