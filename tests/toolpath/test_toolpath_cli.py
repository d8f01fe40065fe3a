"""``woodcam gcode`` glue: argument handling up to the pipeline (the bake stage is stubbed)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import woodcam.pipeline
from woodcam.errors import WoodcamError
from woodcam.toolpath import BallEndMill, FlatEndMill, read_gcode
from woodcam.cli import build_parser, main
from woodcam.cli.gcode import _tools_from_args

REPO = Path(__file__).resolve().parents[2]


def _parse(argv):
    return build_parser().parse_args(["gcode", *argv])


def test_tool_arguments():
    prog = read_gcode("T1 M6\nG0 X1 Y1 Z1\nG1 Z-1 F10\nT2 M6\nG1 X2\n")
    args = _parse(["p.nc", "--block", "builtin:rift", "--out", "o.glb", "--tool", "flat:6",
                   "--tool", "ball:3"])
    assert _tools_from_args(args, prog) == {1: FlatEndMill(6), 2: BallEndMill(3)}
    args = _parse(["p.nc", "--block", "b", "--out", "o.glb", "--tool", "2=ball:3",
                   "--tools", str(REPO / "toolpaths" / "tools.toml")])
    tools = _tools_from_args(args, prog)
    assert tools[2] == BallEndMill(3) and tools[1] == FlatEndMill(6.35)
    args = _parse(["p.nc", "--block", "b", "--out", "o.glb", "--tool", "x=ball:3"])
    with pytest.raises(WoodcamError, match="must be a tool number"):
        _tools_from_args(args, prog)
    args = _parse(["p.nc", "--block", "b", "--out", "o.glb"])
    with pytest.raises(WoodcamError, match="no tools given"):
        _tools_from_args(args, prog)


def test_rapids_before_the_first_tool_change_need_no_tool(tmp_path, monkeypatch):
    """Carbide Create starts every file with "G53G0Z-5.000" before "M6T1": the rapid ran as
    T0, so "--tool flat:3.175" went to T0 and the run stopped with "the program uses tool 1 but
    tools has [0]"; with two tools, T0 needed a --tool 0=SPEC of its own."""
    from woodcam.toolpath import simulate

    _stub_preview(monkeypatch, {})
    text = "G90 G21\nG0 Z5\nM6 T1\nM3 S18000\nG0 X10 Y10\nG1 Z-1 F300\nG1 X50\nG0 Z5\n" \
        "M6 T2\nG0 X10 Y30\nG1 Z-1\nG1 X50\nG0 Z5\nM2\n"
    prog = read_gcode(text, start_mm=(0, 0, 10))
    assert prog.tool.tolist()[0] == 0
    base = ["p.nc", "--block", "b", "--out", "o.glb", "--tool", "flat:3.175"]
    assert _tools_from_args(_parse(base + ["--tool", "ball:3"]), prog) == {
        1: FlatEndMill(3.175), 2: BallEndMill(3)}
    res = simulate(prog, {1: FlatEndMill(3.175), 2: BallEndMill(3)}, (100, 80, 50))
    assert res.removed_volume_mm3 > 0
    one = read_gcode(text.split("M6 T2")[0] + "M2\n", start_mm=(0, 0, 10))
    assert _tools_from_args(_parse(base), one) == {1: FlatEndMill(3.175)}
    path = tmp_path / "cc.nc"
    path.write_text(text.split("M6 T2")[0] + "M2\n")
    args = _parse([str(path), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "o.glb"),
                   "--tool", "flat:3.175", "--cell-size", "0.5"])
    assert args.func(args) == 0


def test_run_simulates_and_hands_a_watertight_mesh_to_the_pipeline(tmp_path, monkeypatch,
                                                                   capsys):
    seen = {}

    def fake_preview(heightmap, stock, out_glb, **kw):
        seen.update(heightmap=heightmap, stock=stock, meta=kw["metadata"])
        return woodcam.pipeline.PartPreview("x", files={"glb": Path(out_glb)}, triangles=1)

    monkeypatch.setattr(woodcam.pipeline, "preview_heightfield", fake_preview)
    prog = tmp_path / "slot.nc"
    prog.write_text("G0 X20 Y40 Z2\nG1 Z-3 F300\nX80\nG0 Z2\n")
    args = _parse([str(prog), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "o.glb"),
                   "--tool", "flat:6", "--cell-size", "0.25"])
    assert args.func(args) == 0
    W, D, H = seen["stock"].size_mm
    hm = seen["heightmap"]
    assert (H - hm).sum() * W * D / hm.size == pytest.approx(3 * (60 * 6 + 3.14159265 * 9),
                                                             rel=5e-3)
    assert seen["meta"]["tools"] == {"0": "flat:6"}
    assert "slot.nc: 4 moves" in capsys.readouterr().out


def test_negative_and_invalid_triples():
    args = _parse(["p.nc", "--block", "b", "--out", "o.glb", "--work-offset", "-14,5,3",
                   "--start", "-1.5,-2,30"])
    assert args.work_offset == (-14.0, 5.0, 3.0) and args.start == (-1.5, -2.0, 30.0)
    for bad in ("nan,nan,nan", "1,2", "1,inf,3", "a,b,c"):
        with pytest.raises(SystemExit):
            _parse(["p.nc", "--block", "b", "--out", "o.glb", "--work-offset", bad])


def test_program_without_cuts_is_an_error(tmp_path):
    prog = tmp_path / "rapids.nc"
    prog.write_text("G0 X20 Y40 Z2\nG0 X30\nM2\n")
    args = _parse([str(prog), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "o.glb"),
                   "--tool", "flat:6"])
    with pytest.raises(WoodcamError, match="no cutting move"):
        args.func(args)


@pytest.mark.slow
def test_gcode_end_to_end_writes_a_baked_glb(tmp_path):
    from woodcam.export import read_glb_metadata

    prog = tmp_path / "slot.nc"
    prog.write_text("G0 X20 Y40 Z2\nG1 Z-3 F300\nX80\nG0 Z2\n")
    out = tmp_path / "slot.glb"
    args = _parse([str(prog), "--block", "builtin:flat-sawn", "--out", str(out), "--tool",
                   "ball:6", "--cell-size", "0.25", "--texels-per-mm", "2", "--no-obj"])
    assert args.func(args) == 0
    meta = read_glb_metadata(out)
    assert meta["block"] == "builtin:flat-sawn" and meta["tools"] == {"0": "ball:6"}


def _stub_preview(monkeypatch, seen):
    def fake_preview(heightmap, stock, out_glb, **kw):
        seen.update(heightmap=heightmap, stock=stock, meta=kw["metadata"])
        return woodcam.pipeline.PartPreview("x", files={"glb": Path(out_glb)}, triangles=1)

    monkeypatch.setattr(woodcam.pipeline, "preview_heightfield", fake_preview)


def test_machine_zero_option_places_carbide_create_retracts(tmp_path, monkeypatch, capsys):
    """Carbide Create's "G53G0Z-5.000" went 5 mm into the stock (machine zero taken at G-code
    zero): rapid_through_stock on every such file. Without --machine-zero it is a retract to the
    --start height, warned with its lines; --machine-zero (in --units) places it."""
    _stub_preview(monkeypatch, {})
    path = tmp_path / "cc.nc"
    path.write_text("G90\nG21\nG53G0Z-5.000\nM6T1\nM03S18000\nG0X10.000Y10.000\nG0Z5.000\n"
                    "G1Z-1.000F254.0\nG1X50.000F1016.0\nG0Z5.000\nG53G0Z-5.000\nM02\n")
    base = [str(path), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "o.glb"),
            "--tool", "flat:3.175", "--cell-size", "0.5"]
    assert main(["gcode", *base]) == 0
    err = capsys.readouterr().err
    assert "rapid_through_stock" not in err
    assert "cc.nc line 3: G53 (machine coordinates) on line(s) 3, 11:" in err
    assert main(["gcode", *base, "--strict"]) == 3  # the assumption is a warning
    capsys.readouterr()
    inch = [str(path), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "o.glb"),
            "--tool", "flat:0.125", "--cell-size", "0.02", "--units", "inch"]
    assert main(["gcode", *inch, "--strict", "--machine-zero", "0,0,3"]) == 0  # Z home 76.2 mm up
    assert "warning" not in capsys.readouterr().err
    assert main(["gcode", *base, "--machine-zero", "0,0,1e9"]) == 2
    assert "--machine-zero must be in [-100000, 100000]" in capsys.readouterr().err


def test_programs_in_sequence_until_line_stock_and_strict(tmp_path, monkeypatch, capsys):
    seen = {}
    _stub_preview(monkeypatch, seen)
    rough = tmp_path / "rough.nc"
    rough.write_text("G0 X20 Y20 Z2 M3 S9000\nG1 Z-3 F600\nX40\nG0 Z2\nM2\n")
    finish = tmp_path / "finish.nc"
    finish.write_text("G0 X20 Y30 Z2 M3 S9000\nG1 Z-3 F600\nX40\nG0 Z2\nM2\n")
    base = ["--block", "builtin:flat-sawn", "--out", str(tmp_path / "o.glb"), "--tool", "flat:6",
            "--cell-size", "0.5", "--stock", "60x50x20", "--stock-origin", "5,5,0"]
    args = _parse([str(rough), str(finish), *base])
    assert args.func(args) == 0
    hm = seen["heightmap"]
    assert seen["stock"].size_mm == (60.0, 50.0, 20.0) and hm.shape == (100, 120)
    both = (20 - hm).sum() * 0.25
    assert both == pytest.approx(2 * 3 * (20 * 6 + 3.14159265 * 9), rel=0.02)
    out = capsys.readouterr().out
    assert "rough.nc: 4 moves" in out and "finish.nc: 4 moves" in out
    assert "machining time T0: 0:00:" in out
    # scrubbed to line 2 of the last program: its slot is only plunged
    args = _parse([str(rough), str(finish), *base, "--until-line", "2"])
    assert args.func(args) == 0
    part = (20 - seen["heightmap"]).sum() * 0.25
    assert part == pytest.approx(3 * (20 * 6 + 3.14159265 * 9) + 3 * 3.14159265 * 9, rel=0.03)
    # --strict: a warning (a cut with the spindle off) gives exit status 3
    off = tmp_path / "off.nc"
    off.write_text("G0 X20 Y20 Z2\nG1 Z-3 F600\nX40\nG0 Z2\nM2\n")
    args = _parse([str(off), *base, "--strict"])
    assert args.func(args) == 3
    assert "spindle_off" in capsys.readouterr().err


@pytest.mark.parametrize("extra, said, fix, fixed", [
    (["--stock", "167x208x25"], "runs from (0, 0, 0) mm to (167, 208, 25) mm",
     "give --stock 100x80x25 or smaller, or a block that holds it: --block builtin:flat-sawn:167x208x50",
     ["--block", "builtin:flat-sawn:167x208x50", "--stock", "167x208x25"]),
    (["--stock", "60x50x20", "--stock-origin", "50,5,0"], "to (110, 55, 20) mm",
     "give --stock 50x50x20 or smaller at that corner, or a block that holds it: "
     "--block builtin:flat-sawn:110x80x50", ["--stock", "50x50x20", "--stock-origin", "50,5,0"]),
    (["--stock", "60x50x20", "--stock-origin=-5,-5,0"], "runs from (-5, -5, 0) mm",
     "give --stock-origin 0,0,0 (in the block) and --stock 60x50x20 or smaller",
     ["--stock", "60x50x20", "--stock-origin", "0,0,0"]),
    (["--units", "inch", "--stock", "5x2x1"], "past the 3.937x3.15x1.969 in block",
     "or a block that holds it: --block builtin:flat-sawn:5x3.15x1.969",
     ["--units", "inch", "--stock", "5x2x1", "--block", "builtin:flat-sawn:5x3.15x1.969"]),
])
def test_a_stock_past_its_block_is_a_usage_error_naming_the_sizes(tmp_path, monkeypatch, capsys,
                                                                   extra, said, fix, fixed):
    """'gcode --stock 167x208x25 --block builtin:flat-sawn' (a 100 x 80 x 50 mm block), or a
    --stock-origin putting the stock partly outside the block, simulated wood of the field
    outside the block without a word (for a fitted block an extrapolation, wood the user does
    not have): a usage error, one line, naming both sizes and the fix, before any simulation;
    the fix it gives runs."""
    seen: dict = {}
    _stub_preview(monkeypatch, seen)
    prog = tmp_path / "p.nc"
    prog.write_text("G0 X20 Y20 Z2 M3 S9000\nG1 Z-0.1 F600\nX40\nG0 Z2\nM2\n")
    cell = "0.08" if "--units" in extra else "2"  # in --units
    base = [str(prog), "--out", str(tmp_path / "o.glb"), "--tool", "flat:6", "--cell-size", cell]
    assert main(["gcode", *base, "--block", "builtin:flat-sawn", *extra]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and not seen, err
    assert "the stock must be wood of the block, not of the field outside it" in err, err
    assert said in err and err.rstrip().endswith(fix), err
    assert main(["gcode", *base, "--block", "builtin:flat-sawn", *fixed]) == 0, capsys.readouterr().err
    k = 25.4 if "inch" in fixed else 1.0
    assert seen["stock"].size_mm == pytest.approx([float(v) * k for v in fixed[fixed.index("--stock") + 1].split("x")])


@pytest.mark.parametrize("tool", ["-1=flat:6", "-25=ball:3"])
def test_a_negative_tool_number_is_refused_naming_the_range(tool, capsys):
    """'gcode --tool -1=flat:6' was argparse's 'argument --tool: expected one argument' (it took
    '-1=flat:6' for an option): the tool number's own rule, one line, exit 2 (as --tool=-1=flat:6)."""
    for argv in (["--tool", tool], [f"--tool={tool}"]):
        assert main(["gcode", "p.nc", "--block", "builtin:flat-sawn", "--out", "o.glb", *argv]) == 2
        err = capsys.readouterr().err
        assert err == (f"woodcam: error: --tool {tool!r}: the tool number must be in [0, 99999]; "
                       f"got {tool.split('=')[0]}; e.g. --tool 1={tool.split('=')[1]}\n"), err


def test_more_unnumbered_tools_than_the_program_has_numbers_says_how_to_number_them(capsys, tmp_path):
    """Two --tool SPEC without numbers for a program of one tool (T1) said 'give numbers as
    N=SPEC' with no example; now the numbers the tools would take, the rule and the fix."""
    assert main(["gcode", str(REPO / "toolpaths" / "pocket_islands.nc"), "--block", "builtin:flat-sawn",
                 "--out", str(tmp_path / "o.glb"), "--tool", "flat:6", "--tool", "ball:3", "--quiet"]) == 1
    err = capsys.readouterr().err
    assert err == ("woodcam: error: --tool: 2 tools without numbers but the program uses 1 tool number(s) "
                   "without a tool ([1]); each tool without a number takes the next of those; give numbers as "
                   "N=SPEC, e.g. --tool 1=flat:6 --tool 2=ball:3, or leave out the tools it does not use\n"), err


def test_a_glbs_appearance_params_not_an_object_say_the_fix():
    """A GLB whose metadata's appearance.params is no object was refused without a fix."""
    from woodcam.cli.options import _trusted_appearance_params

    with pytest.raises(WoodcamError, match=r"^'p.glb': metadata appearance.params must be an object; got list; "
                       r"re-bake it, or pass --block SPEC \(and the bake options\) yourself$"):
        _trusted_appearance_params([1], "p.glb")


def test_machining_time_estimate():
    prog = read_gcode("G0 X0 Y0 Z10\nG1 X100 F600\nG0 X0\nT2 M6\nG1 Y60 F1200\nM2\n",
                      start_mm=(0, 0, 10))
    t = prog.machining_time_s(rapid_mm_min=6000)
    assert t[0] == pytest.approx((10.0, 1.0))   # 100 mm at 600 mm/min, 100 mm rapid at 6000
    assert t[2] == pytest.approx((3.0, 0.0))
    with pytest.raises(WoodcamError, match="rapid_mm_min"):
        prog.machining_time_s(0)


def test_the_rapids_before_the_first_tool_change_count_to_its_tool(tmp_path, monkeypatch, capsys):
    """A post's safe moves before 'T1 M6' (tool 0: no tool loaded) were timed as a tool of their
    own, 'T0: 0:00:01 (0:00:00 feeding), T1: 0:00:04 ...', though simulate moves them with T1
    and the GLB's tools list T1 alone. They count to T1; a program whose tool 0 feeds keeps
    its T0 (test_machining_time_estimate)."""
    prog = read_gcode("G21 G90\nG0 Z20\nG0 X50 Y40\nT1 M6\nG0 X10 Y10 Z5\nG1 Z-1 F300\n"
                      "G1 X50 F1200\nG0 Z5\nM30\n")
    t = prog.machining_time_s(rapid_mm_min=6000)
    assert list(t) == [1] and t[1][0] == pytest.approx(60 * (6 / 300 + 40 / 1200))
    assert t[1][1] == pytest.approx(60 * (10 + np.hypot(50, 40) + np.sqrt(40**2 + 30**2 + 15**2) + 6) / 6000)
    _stub_preview(monkeypatch, {})
    path = tmp_path / "t0.nc"
    path.write_text("G21 G90\nG0 Z20\nT1 M6\nM3 S9000\nG0 X10 Y10 Z5\nG1 Z-1 F300\n"
                    "G1 X50 F1200\nG0 Z5\nM30\n")
    assert main(["gcode", str(path), "--block", "builtin:flat-sawn", "--out",
                 str(tmp_path / "o.glb"), "--tool", "flat:3", "--cell-size", "0.5"]) == 0
    assert "; machining time T1: 0:00:04 (0:00:03 feeding)\n" in capsys.readouterr().out


def test_grid_coarser_than_half_the_stepover_warns(tmp_path, monkeypatch, capsys):
    _stub_preview(monkeypatch, {})
    prog = REPO / "toolpaths" / "corpus" / "gen_raster_fine.ngc"  # 0.5 mm step-over
    assert read_gcode(prog).stepover_mm(0.1) == pytest.approx(0.5, abs=0.01)
    base = [str(prog), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "o.glb"),
            "--tool", "1=ball:6", "--strict"]
    args = _parse([*base, "--cell-size", "0.4"])
    assert args.func(args) == 3
    assert "coarser than half the step-over (0.5 mm)" in capsys.readouterr().err
    args = _parse([*base, "--cell-size", "0.2"])
    args.func(args)
    assert "step-over" not in capsys.readouterr().err


def _raster(step: float, levels: int, passes: int, length: float = 30.0) -> str:
    """A zig-zag raster written as CAM posts do ("G1 Y..." then "G1 X..." per pass), cut in
    ``levels`` stacked depth levels."""
    text = ["G21 G90 G17 F1000", "G0 X0 Y0 Z5"]
    for lev in range(1, levels + 1):
        text.append(f"G1 X0 Y0 Z{-lev}")
        for k in range(passes):
            text += [f"G1 Y{k * step:.3f}", f"G1 X{length if k % 2 == 0 else 0}"]
    return "\n".join(text + ["M2", ""])


def test_the_simulation_shows_a_progress_bar_over_its_moves(tmp_path, monkeypatch, bars):
    """woodcam gcode ran simulate with progress=False (no bar on a 200,000-line raster), and
    simulate's bar counted runs: a raster is one run, its bar stood at 0/1 to the end."""
    _stub_preview(monkeypatch, {})
    prog = tmp_path / "raster.nc"
    prog.write_text("G0 X0 Y0 Z2 M3 S9000\nG1 Z-1 F600\n" + "".join(
        f"G1 X{60 * (k % 2)} Y{k}\n" for k in range(40)) + "G0 Z2\nM2\n")
    args = _parse([str(prog), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "o.glb"),
                   "--tool", "flat:6", "--cell-size", "0.5"])
    assert args.func(args) == 0
    sim = [b for b in bars if b.desc == "simulate"]
    assert len(sim) == 1 and sim[0].enabled and sim[0].unit == "move"
    assert sim[0].n == sim[0].total == 41


def test_one_stage_bar_runs_over_the_whole_job(tmp_path, monkeypatch, bars):
    """Opening a photographed block (its fit: 20-30 s once), meshing, baking and the screenshot
    ran without a bar (the simulation's own is drawn only while it simulates): 'woodcam gcode' of
    a pocket on the H11 cube took 10-25 s with none. One stage bar, as bake's, names each step."""
    _stub_preview(monkeypatch, {})
    rough, finish = tmp_path / "rough.nc", tmp_path / "finish.nc"
    rough.write_text("G0 X20 Y20 Z2 M3 S9000\nG1 Z-3 F600\nX40\nG0 Z2\nM2\n")
    finish.write_text("G0 X20 Y20 Z2 M3 S9000\nG1 Z-4 F600\nX40\nG0 Z2\nM2\n")
    assert main(["gcode", str(rough), str(finish), "--block", "builtin:flat-sawn", "--out",
                 str(tmp_path / "job.glb"), "--tool", "flat:6", "--cell-size", "0.5"]) == 0
    [bar] = [b for b in bars if b.desc == "gcode job"]
    assert bar.enabled and bar.unit == "stage"
    assert bar.shown[1:] == ["gcode job: open block", "gcode job: simulate rough.nc",
                             "gcode job: simulate finish.nc", "gcode job: mesh and bake", "gcode job"]
    assert bar.n == bar.total == 4 and bar.closed


def test_programs_and_tools_are_refused_before_the_block_is_opened(tmp_path, capsys, monkeypatch):
    """A missing program, a bad --tool or a missing --tools table was refused only after the
    block was opened (a photographed block's fit: 20-30 s the first time), and two of the
    errors named Python parameters ("read_gcode: text_or_path='x.nc' is not a file",
    "load_tool_table: path='t.toml' does not exist"). Each is refused first now, naming what
    was typed."""
    import woodcam.stock

    opened = []
    monkeypatch.setattr(woodcam.stock, "open_stock", lambda *a, **k: opened.append(a))
    prog = tmp_path / "p.nc"
    prog.write_text("G0 X20 Y20 Z2 M3 S9000\nG1 Z-3 F600\nX40\nG0 Z2\nM2\n")
    base = ["--block", "builtin:flat-sawn", "--out", str(tmp_path / "o.glb")]
    for argv, said, rc in (
            # a missing program or table: a wrong command line, refused at the input door (exit 2, was 1)
            ([str(tmp_path / "nope.nc"), "--tool", "flat:6"],
             f"PROGRAM of 'woodcam gcode': {str(tmp_path / 'nope.nc')!r} does not exist", 2),
            ([str(prog), "--tools", str(tmp_path / "t.toml")],
             f"--tools of 'woodcam gcode': {str(tmp_path / 't.toml')!r} does not exist", 2),
            # a malformed --tool is a wrong command line (exit 2, at the door)
            ([str(prog), "--tool", "1=flat:abc"], "--tool '1=flat:abc': tool spec 'flat:abc'", 2),
            ([str(prog)], "no tools given; pass --tool SPEC", 2)):  # a missing option: usage
        assert main(["gcode", *argv, *base]) == rc
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and said in err, err
        assert "text_or_path" not in err and "path=" not in err
    assert opened == []


def test_a_refused_line_names_its_program(tmp_path, monkeypatch):
    """With several programs of one job, "G-code line 5: 'G41': ..." did not say which."""
    from woodcam.toolpath import GcodeError

    _stub_preview(monkeypatch, {})
    rough, finish = tmp_path / "rough.nc", tmp_path / "finish.nc"
    rough.write_text("G0 X20 Y20 Z2 M3 S9000\nG1 Z-3 F600\nX40\nG0 Z2\nM2\n")
    finish.write_text("G0 X20 Y20 Z2 M3 S9000\nG41 G1 Z-3 F600\nM2\n")
    args = _parse([str(rough), str(finish), "--block", "builtin:flat-sawn", "--out",
                   str(tmp_path / "o.glb"), "--tool", "flat:6", "--cell-size", "0.5"])
    # the path as typed: two finish.nc in different folders read the same by name alone
    with pytest.raises(GcodeError, match=rf"^{re.escape(str(finish))}: G-code line 2: 'G41': cutter radius") as e:
        args.func(args)
    assert e.value.line == 2


def test_stepover_of_stacked_levels_helices_and_crossings():
    """The step-over read 0.05 mm for a 2.4 mm pocket in six depth levels (the stacked copies
    filled the nearest neighbours), 0.15 mm for a helical bore and 0.1 mm for two crossing
    slots, each with a warning to use a grid 4-16x finer; a raster written "G1 Y / G1 X" read
    twice its step-over (the next pass is two source lines on)."""
    assert read_gcode(_raster(2.4, 6, 17, 60)).stepover_mm(0.1) == pytest.approx(2.4)
    # 3 mm passes are farther than the 48 nearest points reach: not known, as for one level
    # (the return diagonal between levels, crossing the passes at a slant, read 0.75 mm)
    assert read_gcode(_raster(3.0, 1, 17, 60)).stepover_mm(0.1) is None
    assert read_gcode(_raster(3.0, 6, 17, 60)).stepover_mm(0.1) is None
    assert read_gcode(_raster(0.15, 3, 100)).stepover_mm(0.1) == pytest.approx(0.15)
    assert read_gcode(_raster(0.15, 1, 100)).stepover_mm(0.1) == pytest.approx(0.15)
    helix = "G21 G90 F500\nG0 X57 Y40 Z1\n" + "".join(
        f"G3 X57 Y40 Z{-z} I-7 J0\n" for z in range(6)) + "M2\n"
    assert read_gcode(helix).stepover_mm(0.1) is None
    crossing = "G21 G90 F500\nG0 X-20 Y40 Z5\nG1 Z-5\nG1 X130\nG0 Z5\nG0 X50 Y-20\n" \
        "G1 Z-5\nG1 Y100\nG0 Z5\nM2\n"
    assert read_gcode(crossing).stepover_mm(0.1) is None


def test_the_corpus_pocket_steps_over_5_mm():
    """lcnc_params_pocket.ngc (a zig-zag at 5 mm) went from the end of each leftward pass
    diagonally to the start of the next rightward one, across the passes: its step-over read
    1.09 mm and the pocket was cut on a slant. Each feed now runs along X or Y."""
    prog = read_gcode(REPO / "toolpaths" / "corpus" / "lcnc_params_pocket.ngc")
    d = prog.end_mm - prog.start_mm
    feed = (prog.kind == 1) & (np.abs(d[:, :2]).max(axis=1) > 0)
    assert (np.abs(d[feed, :2]).min(axis=1) < 1e-9).all()
    assert prog.stepover_mm(0.5) == pytest.approx(5.0)


def test_the_simulations_issues_reach_the_review_page_as_hotspots(tmp_path, capsys):
    """gcode printed its issues but stored none in the GLB, so the review page, which reads them
    from there, never showed a G-code hotspot."""
    from woodcam.cli import main
    from woodcam.export import read_glb_metadata

    glb = tmp_path / "p.glb"
    assert main(["gcode", str(REPO / "toolpaths" / "profile_tabs.nc"), "--tool", "flat:6.35", "--block",
                 "builtin:flat-sawn", "--out", str(glb), "--no-obj", "--cell-size", "0.5"]) == 0
    spots = read_glb_metadata(glb)["warnings"]
    assert len(spots) == 5 and all("below_stock_bottom" in s["message"] for s in spots)
    # where the tip goes through the 50 mm block's bottom (block frame Z0; the moves end 0.5 mm
    # under it)
    assert all(s["at_mm"][2] == pytest.approx(0.0) for s in spots)
    assert main(["review", str(glb), "--out", str(tmp_path / "p.html"), "--voxels", "20000"]) == 0
    page = (tmp_path / "p.html").read_text()
    assert page.count("below_stock_bottom") >= 5


def test_the_review_page_of_a_gcode_glb_shows_its_tools_and_machining_time(tmp_path, capsys):
    """The GLB records the run's tools and machining time, but the page (and its printed shop
    sheet) showed neither."""
    from woodcam.cli import main
    from woodcam.cli.gcode import fmt_hms
    from woodcam.export import read_glb_metadata

    glb = tmp_path / "p.glb"
    assert main(["gcode", str(REPO / "toolpaths" / "profile_tabs.nc"), "--tool", "1=flat:6.35",
                 "--block", "builtin:flat-sawn", "--out", str(glb), "--no-obj", "--cell-size", "1"]) == 0
    meta = read_glb_metadata(glb)
    assert meta["tools"] == {"1": "flat:6.35"} and meta["machining_time_s"] > 60
    assert main(["review", str(glb), "--out", str(tmp_path / "p.html"), "--voxels", "20000"]) == 0
    page = (tmp_path / "p.html").read_text()
    assert "<tr><th>tools (--tool specs, mm)</th><td>T1 flat:6.35</td></tr>" in page
    assert f"<tr><th>machining time</th><td>{fmt_hms(meta['machining_time_s'])} (estimate" in page


def test_review_with_another_block_than_the_baked_one_says_so(tmp_path, capsys):
    """review/preview --block of another block (another size, an edited folder) was taken without a
    word, so the section cap showed other wood than the part's surface."""
    from woodcam.cli import main

    glb = tmp_path / "p.glb"
    assert main(["gcode", str(REPO / "toolpaths" / "profile_tabs.nc"), "--tool", "flat:6.35", "--block",
                 "builtin:flat-sawn", "--out", str(glb), "--no-obj", "--cell-size", "0.5"]) == 0
    capsys.readouterr()
    assert main(["review", str(glb), "--block", "builtin:flat-sawn:200x80x50", "--out", str(tmp_path / "a.html"),
                 "--voxels", "20000"]) == 0
    assert "is not the block p.glb was baked from (builtin:flat-sawn, 100x80x50 mm)" in capsys.readouterr().err
    assert main(["review", str(glb), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "b.html"),
                 "--voxels", "20000"]) == 0
    assert "is not the block" not in capsys.readouterr().err  # the same block: no word


# a missing part, or a part of a suffix no reader takes, is a wrong command line (the input
# door, exit 2; they were 1)
@pytest.mark.parametrize("part,says,code", [("nope.stl", "woodcam: error: --part of 'woodcam gcode': ", 2),
                                            ("design.jpg", "woodcam: error: --part of 'woodcam gcode': ", 2)])
def test_a_bad_design_part_is_refused_before_the_simulation(part, says, code, tmp_path, capsys):
    """``--part nope.stl`` simulated the whole program (minutes on a real job), then failed
    naming 'part file', not the option."""
    (tmp_path / "design.jpg").write_bytes(b"\xff\xd8")
    capsys.readouterr()
    assert main(["gcode", str(REPO / "toolpaths" / "drilling.nc"), "--tool", "flat:6", "--block",
                 "builtin:flat-sawn", "--cell-size", "0.5", "--out", str(tmp_path / "g.glb"),
                 "--part", str(tmp_path / part)]) == code
    out = capsys.readouterr()
    assert "moves read" not in out.out  # nothing was simulated
    err = out.err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(says) and part in err[0], err
    assert not (tmp_path / "g.glb").exists()


def test_the_glb_records_the_programs_resolved(tmp_path, monkeypatch):
    """Sweep h13 item 4: the GLB recorded the G-code path as typed ('job/slot.nc'), relative to
    a working folder it does not record, so its review page, made from another folder, named
    no file there; now resolved, as the block spec is (stock.absolute_spec)."""
    seen = []
    monkeypatch.setattr(woodcam.pipeline, "preview_heightfield",
                        lambda hm, stock, out, **kw: seen.append(kw["metadata"])
                        or woodcam.pipeline.PartPreview("x", files={"glb": out}))
    (tmp_path / "job").mkdir()
    for name in ("rough.nc", "finish.nc"):
        (tmp_path / "job" / name).write_text("G21\nG0 X20 Y40 Z2\nG1 Z-3 F300\nX80\nG0 Z2\n")
    monkeypatch.chdir(tmp_path)
    common = ["--block", "builtin:flat-sawn", "--tool", "flat:6", "--cell-size", "1", "--out", "o.glb"]
    assert main(["gcode", "job/rough.nc", *common]) == 0
    assert main(["gcode", "job/rough.nc", "job/finish.nc", *common]) == 0
    one, two = seen
    assert one["gcode"] == str(tmp_path.resolve() / "job" / "rough.nc")
    assert two["gcode"] == [str(tmp_path.resolve() / "job" / n) for n in ("rough.nc", "finish.nc")]
    monkeypatch.chdir(REPO)  # another folder: the recorded paths still name the files
    assert all(Path(p).is_file() for p in [one["gcode"], *two["gcode"]])


def test_a_no_obj_rerun_removes_the_earlier_runs_obj(tmp_path, capsys):
    """gcode --no-obj into a folder left the earlier run's OBJ + MTL + PNG beside the new GLB."""
    from woodcam.cli import main

    argv = ["gcode", str(REPO / "toolpaths" / "drilling.nc"), "--tool", "flat:6", "--block",
            "builtin:flat-sawn", "--out", str(tmp_path / "g.glb"), "--cell-size", "1", "--texels-per-mm", "1"]
    assert main(argv) == 0
    assert (tmp_path / "g.obj").is_file()
    capsys.readouterr()
    assert main([*argv, "--no-obj"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == [".woodcam-g.glb-files.json", "g.glb"]
    assert "removed 3 file(s) of an earlier run" in capsys.readouterr().err


def _drilling_with_part(tmp_path) -> list[str]:
    """The gcode command line of drilling.nc on builtin:flat-sawn with a 20 mm box as --part
    (a deviation map), written to tmp_path/g.glb."""
    import trimesh

    box = trimesh.creation.box((20, 20, 20))
    box.apply_translation((50, 40, 25))
    box.export(tmp_path / "box.stl")
    return ["gcode", str(REPO / "toolpaths" / "drilling.nc"), "--tool", "flat:6", "--block",
            "builtin:flat-sawn", "--cell-size", "1", "--out", str(tmp_path / "g.glb"), "--no-obj",
            "--part", str(tmp_path / "box.stl")]


def test_a_rerun_removes_the_deviation_map_and_the_bakes_report_it_does_not_write(tmp_path, capsys):
    """gcode without --part left the earlier run's NAME_deviation.png (a map of another cut),
    and gcode into a GLB bake wrote left bake's NAME_report.* (a part's volume and yield) beside
    the simulated stock: both passed for this run's. Only files an earlier run listed go."""
    with_part = _drilling_with_part(tmp_path)
    gcode = with_part[:with_part.index("--part")]  # the same run without the part
    assert main(with_part) == 0
    assert (tmp_path / "g_deviation.png").is_file()
    capsys.readouterr()
    assert main(gcode) == 0
    assert re.search(r"warning: removed 1 file\(s\) .*: g_deviation.png$", capsys.readouterr().err, re.M)
    assert sorted(p.name for p in tmp_path.iterdir()) == [".woodcam-g.glb-files.json", "box.stl", "g.glb"]
    assert main(["bake", str(tmp_path / "box.stl"), "--block", "builtin:flat-sawn", "--out",
                 str(tmp_path / "g.glb"), "--texels-per-mm", "1", "--no-obj"]) == 0
    assert (tmp_path / "g_report.txt").is_file()
    capsys.readouterr()
    assert main(gcode) == 0
    assert re.search(r"warning: removed 2 file\(s\) .*: g_report.txt, g_report.json$",
                     capsys.readouterr().err, re.M)
    assert sorted(p.name for p in tmp_path.iterdir()) == [".woodcam-g.glb-files.json", "box.stl", "g.glb"]


def test_a_ctrl_c_while_baking_leaves_the_earlier_deviation_map_with_its_glb(tmp_path, capsys, monkeypatch):
    """The deviation map was written before the stock was meshed and baked: a Ctrl-C there left
    the new cut's map beside the earlier run's GLB (a map of another cut). It is drawn once the
    GLB set is in place: interrupted, the folder is the earlier run's."""
    gcode = _drilling_with_part(tmp_path)
    assert main(gcode) == 0
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}

    def interrupted(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(woodcam.pipeline, "preview_heightfield", interrupted)
    assert main([*gcode[:-1], str(tmp_path / "box.stl"), "--until-line", "12"]) == 130
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_a_ctrl_c_while_the_deviation_map_is_drawn_leaves_no_earlier_map_beside_the_new_glb(
        tmp_path, capsys, monkeypatch):
    """Review of 8b54610: the map is drawn once the new GLB set is in place, so a Ctrl-C while
    it was drawn left the earlier run's NAME_deviation.png (another cut's) beside the new GLB,
    passing for its map until the next run, the fault 6825aa1 fixed for NAME_view.png. The
    earlier map is gone once the new GLB has landed."""
    import woodcam.toolpath.deviation as deviation_module
    from woodcam.export import read_glb_metadata

    gcode = _drilling_with_part(tmp_path)
    assert main(gcode) == 0
    dev = tmp_path / "g_deviation.png"
    assert dev.is_file() and "until_line" not in read_glb_metadata(tmp_path / "g.glb")

    def interrupted(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(deviation_module, "deviation_png", interrupted)
    assert main([*gcode, "--until-line", "12"]) == 130
    assert read_glb_metadata(tmp_path / "g.glb")["until_line"] == 12  # the new cut's GLB landed
    assert not dev.exists()  # and no earlier cut's map beside it


def test_the_programs_messages_are_shown_as_the_machine_would_show_them(tmp_path, monkeypatch,
                                                                         capsys):
    """A program's (MSG,...) and (DEBUG,...) messages, which LinuxCNC shows its operator as the
    program runs (DEBUG with the parameters' values at that point), were read into the
    interpreter and shown nowhere: read_gcode's Program had no place for them and woodcam
    gcode said nothing. They are Program.messages now, printed one a line; not warnings
    (--strict passes). A (PRINT,...), which LinuxCNC writes to its terminal and never shows
    the operator, was printed as a 'message' too; it is labelled 'print' now."""
    _stub_preview(monkeypatch, {})
    text = ("G21 G90\nT1 M6\nG0 X10 Y10 Z5 M3 S9000\n(MSG, roughing)\n#1=0\no1 while [#1 lt 2]\n"
            "G1 Z[-1-#1] F600\n(DEBUG, pass #1 at z=#<_z>)\nG1 X30\nG0 Z5\nG0 X10\n#1=[#1+1]\n"
            "o1 endwhile\n(PRINT, done #1)\nM2\n")
    said = ["line 4: roughing", "line 8: pass 0.000000 at z=-1.000000",
            "line 8: pass 1.000000 at z=-2.000000"]
    prog = read_gcode(text)
    assert prog.messages == said and prog.warnings == []
    assert prog.until_line(8).messages == said  # as its warnings: the whole program's
    path = tmp_path / "msg.nc"
    path.write_text(text)
    args = _parse([str(path), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "o.glb"),
                   "--tool", "flat:6", "--cell-size", "0.5", "--strict"])
    assert args.func(args) == 0
    err = capsys.readouterr().err
    assert [ln for ln in err.splitlines() if "message" in ln] == [
        f"woodcam: message: msg.nc {m}" for m in said]
    assert prog.printed == ["line 14: done 2.000000"]
    assert [ln for ln in err.splitlines() if "done" in ln] == [
        "woodcam: print: msg.nc line 14: done 2.000000"]


def test_a_message_shows_the_diameter_of_the_users_tool_table(tmp_path, monkeypatch, capsys):
    """A (DEBUG,...) of #5410, the loaded tool's diameter in the machine's tool table, showed
    '#5410?' though --tools (or --tool N=SPEC) gives that tool; it shows its diameter now."""
    _stub_preview(monkeypatch, {})
    path = tmp_path / "dia.nc"
    path.write_text("G21 G90\nT1 M6\n(DEBUG, dia #5410)\nG0 X10 Y10 Z5 M3 S9000\nG1 Z-1 F600\n"
                    "G1 X30\nG0 Z5\nT7 M6\n(DEBUG, dia #5410)\nG1 Z-1\nM2\n")
    args = _parse([str(path), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "o.glb"),
                   "--tools", str(REPO / "toolpaths" / "tools.toml"), "--tool", "7=ball:3.5",
                   "--cell-size", "0.5"])
    assert args.func(args) == 0
    err = capsys.readouterr().err
    assert [ln for ln in err.splitlines() if "message" in ln] == [
        "woodcam: message: dia.nc line 3: dia 6.350000",
        "woodcam: message: dia.nc line 9: dia 3.500000"]


def test_a_message_shows_the_diameter_of_a_tool_without_a_number(tmp_path, monkeypatch, capsys):
    """A --tool SPEC without a number cuts the program's tool numbers no other --tool gives,
    in the order it uses them (one alone: also a program without a T word), but a (DEBUG,...)
    or (PRINT,...) of #5410 said '[#5410: T1's diameter, from the machine's tool table]' with a
    warning to give the tool it was given. It shows that tool's diameter now. A program without
    a T word (the one tool cuts it) has no tool loaded, so #5410 shows 0, as LinuxCNC shows it
    (rs274 -t; woodcam showed the tool's diameter there)."""
    _stub_preview(monkeypatch, {})
    two = tmp_path / "two.nc"
    two.write_text("G21 G90\nT1 M6\n(DEBUG, dia #5410)\nG0 X10 Y10 Z5 M3 S9000\nG1 Z-1 F600\n"
                   "G1 X30\nG0 Z5\nT7 M6\n(PRINT, dia #5410)\nG1 Z-1\nT9 M6\n"
                   "(DEBUG, dia #5410)\nG1 X40\nM2\n")
    none = tmp_path / "none.nc"
    none.write_text("G21 G90\n(DEBUG, dia #5410)\nG0 X10 Y10 Z5 M3 S9000\nG1 Z-1 F600\nG1 X30\n"
                    "M2\n")
    for path, tools, said in (
            (two, ["flat:4", "7=ball:3.5", "flat:2"], ["line 3: dia 4.000000",
                                                       "line 12: dia 2.000000"]),
            (none, ["flat:6.35"], ["line 2: dia 0.000000"])):
        args = _parse([str(path), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "o.glb"),
                       *[w for t in tools for w in ("--tool", t)], "--cell-size", "0.5"])
        assert args.func(args) == 0
        err = capsys.readouterr().err
        assert [ln for ln in err.splitlines() if "message" in ln] == [
            f"woodcam: message: {path.name} {m}" for m in said], err
        assert "#5410" not in err
        if path == two:
            assert f"woodcam: print: {path.name} line 9: dia 3.500000" in err


def test_a_program_is_read_once_though_its_tools_without_numbers_read_it_twice(tmp_path, monkeypatch,
                                                                               capsys):
    """With a --tool SPEC without a number and a (DEBUG,...) of #5410 the program is read a
    second time with that tool's diameter; it opened the file again for it, so a program
    saved between the two reads was simulated as the new file with the old one's messages. It
    is read once now: the second reading reads the same text, and the messages and moves are
    the first file's."""
    import pathlib

    _stub_preview(monkeypatch, {})
    prog = tmp_path / "p.nc"
    prog.write_text("G21 G90\nT1 M6\n(DEBUG, dia #5410)\nG0 X10 Y10 Z5 M3 S9000\nG1 Z-1 F600\n"
                    "G1 X30\nM2\n")
    opened = []
    real_open = pathlib.Path.open

    def counting_open(self, *a, **kw):
        if self.name == prog.name:
            opened.append(self)
            if len(opened) == 2:  # saved again while woodcam reads it: a longer program
                with open(prog, "w") as f:
                    f.write("G21 G90\nT1 M6\n(DEBUG, changed #5410)\nG0 X10 Y10 Z5 M3 S9000\n"
                            "G1 Z-2 F600\nG1 X80\nG1 Y20\nM2\n")
        return real_open(self, *a, **kw)

    monkeypatch.setattr(pathlib.Path, "open", counting_open)
    args = _parse([str(prog), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "o.glb"),
                   "--tool", "flat:4", "--cell-size", "0.5"])
    assert args.func(args) == 0
    captured = capsys.readouterr()
    assert len(opened) == 1, opened
    assert "woodcam: message: p.nc line 3: dia 4.000000" in captured.err, captured.err
    assert "changed" not in captured.err
    assert "p.nc: 3 moves read" in captured.out, captured.out


def test_linuxcnc_cutter_compensation_offsets_by_a_tool_without_a_number(tmp_path, monkeypatch,
                                                                         capsys):
    """--interpreter linuxcnc runs G41/G42 as LinuxCNC does, offsetting the path by the radius
    of its tool table's diameter. A --tool SPEC without a number gave the table no diameter
    (the program was read again with it only where it said or printed something), so the
    profile was cut on the programmed line, 3 mm off, where --tool 1=SPEC cut it offset: the
    same tool cut two parts. Both cut the offset profile now."""
    from woodcam.toolpath.linuxcnc import linuxcnc_missing

    if linuxcnc_missing():
        pytest.skip(f"LinuxCNC's interpreter is not available: {linuxcnc_missing()}")
    _stub_preview(monkeypatch, {})
    prog = tmp_path / "comp.ngc"
    prog.write_text("G21 G90\nT1 M6\nS10000 M3\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG41\nG1 X20 Y10\n"
                    "G1 X40\nG1 Y40\nG1 X20\nG1 Y10\nG40\nG0 Z5\nM2\n")
    removed = []
    for tool in ("flat:6", "1=flat:6"):
        args = _parse([str(prog), "--block", "builtin:flat-sawn", "--out",
                       str(tmp_path / "o.glb"), "--tool", tool, "--cell-size", "0.5",
                       "--interpreter", "linuxcnc"])
        assert args.func(args) == 0
        out = capsys.readouterr().out
        removed.append(re.search(r"removed ([0-9.]+ mm\^3)", out).group(1))
    assert removed[0] == removed[1], removed


def test_linuxcnc_reads_a_program_once_unless_its_tool_table_can_change_it(tmp_path, monkeypatch,
                                                                          capsys):
    """With --interpreter linuxcnc and a --tool SPEC without a number every program was read
    twice by LinuxCNC (the second time with that tool's diameter in its table: +1.2 s on the
    16,434-line raster), though only a parameter or G41/G42 reads the table. A program with
    neither is read once now and reads the same moves, warnings and messages with any table
    (the samples, read with and without diameters); one with G41 or a #5410 is still read
    again (test_linuxcnc_cutter_compensation_offsets_by_a_tool_without_a_number)."""
    import woodcam.toolpath.linuxcnc as lcnc

    assert not lcnc.may_read_tool_diameters("G21 G90\nT1 M6\nG4 P1\nG1 X41 Y42 F300\nG40\n"
                                            "(MSG, cut)\nG2 X1 Y1 R4.2\nM2\n")
    for text in ("G1 X#1", "G1 X[1+2]", "G41", "G42 D1", "g 4 1", "G041", "G+42", "G41.1 D3",
                 "(G41 in a comment)", "(DEBUG, #5410)", "O100 sub\nG1 X##2\nO100 endsub"):
        assert lcnc.may_read_tool_diameters(text), text
    if lcnc.linuxcnc_missing():
        pytest.skip(f"LinuxCNC's interpreter is not available: {lcnc.linuxcnc_missing()}")
    for name in ("drilling.nc", "pocket_islands.nc", "profile_tabs.nc", "vcarve_text.nc"):
        text = (REPO / "toolpaths" / name).read_text()
        assert not lcnc.may_read_tool_diameters(text), name
        a, b = (read_gcode(text, interpreter="linuxcnc", tool_diameters_mm=d)
                for d in ({}, {1: 6.35, 2: 3.0, 3: 12.0, 4: 25.0}))
        assert (a.warnings, a.messages, a.printed) == (b.warnings, b.messages, b.printed)
        for field in ("start_mm", "end_mm", "kind", "tool", "line", "feed_mm_min", "spindle_rpm"):
            assert np.array_equal(getattr(a, field), getattr(b, field)), (name, field)
    _stub_preview(monkeypatch, {})
    runs = []
    real = lcnc.run_batch
    monkeypatch.setattr(lcnc, "run_batch", lambda *a, **k: runs.append(k) or real(*a, **k))
    plain, comp = tmp_path / "plain.ngc", tmp_path / "comp.ngc"
    plain.write_text("G21 G90\nT1 M6\nS10000 M3\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40\nG0 Z5\n"
                     "M2\n")
    comp.write_text("G21 G90\nT1 M6\nS10000 M3\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG42\nG1 X20\n"
                    "G1 X40\nG40\nG0 Z5\nM2\n")
    for prog, reads in ((plain, 1), (comp, 2)):
        runs.clear()
        args = _parse([str(prog), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "o.glb"),
                       "--tool", "flat:6", "--cell-size", "0.5", "--interpreter", "linuxcnc"])
        assert args.func(args) == 0
        assert f"{prog.name}: " in capsys.readouterr().out
        assert len(runs) == reads, (prog.name, runs)
    assert runs[-1]["tool_diameters_mm"] == {1: 6.0}


def test_a_tool_number_without_a_tool_is_refused_before_the_block_naming_its_file(tmp_path,
                                                                                monkeypatch,
                                                                                capsys):
    """A program using a tool number no --tool/--tools gives (a Fusion post's T2 M6 with only
    --tool 1=SPEC) was refused by the simulation: after the block was opened (20-30 s for a
    photographed one) and every program before it simulated, with a message naming no file.
    It is refused with the programs' other checks now, naming the file and the line."""
    import woodcam.stock

    _stub_preview(monkeypatch, {})
    opened = []
    real = woodcam.stock.open_stock
    monkeypatch.setattr(woodcam.stock, "open_stock", lambda *a, **k: opened.append(a) or real(*a, **k))
    one, two = tmp_path / "one.nc", tmp_path / "two.nc"
    one.write_text("G21 G90\nT1 M6\nM3 S9000\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X30\nM30\n")
    two.write_text("G21 G90\nT1 M6\nM3 S9000\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG0 Z5\nT2 M6\n"
                   "M3 S9000\nG1 Z-1 F300\nG1 X30\nM30\n")
    base = ["--block", "builtin:flat-sawn", "--out", str(tmp_path / "o.glb"), "--cell-size", "0.5"]
    assert main(["gcode", str(one), str(two), *base, "--tool", "1=flat:6"]) == 1
    out, err = capsys.readouterr()
    assert err.strip() == ("woodcam: error: woodcam gcode two.nc: the program uses tool 2 (first "
                           "at line 9) but tools has [1]; add T2 to the tool table or pass --tool "
                           "2=SPEC"), err
    assert opened == [] and "moves read" not in out, out
    assert main(["gcode", str(one), str(two), *base, "--tool", "1=flat:6", "--until-line",
                 "6"]) == 0  # two.nc simulated up to before its T2: no tool 2 needed
    assert main(["gcode", str(two), *base, "--tool", "flat:6", "--tool", "ball:3"]) == 0
    assert len(opened) == 2


def test_a_grid_coarser_than_half_a_tool_is_warned(tmp_path, monkeypatch, capsys):
    """A 0.4 mm slot on a 0.5 mm grid ran along a row of cell edges: it removed 0 mm^3 with no
    word. A grid coarser than half a used tool's diameter is warned now (the fix named in
    --units), and fails --strict; a fine enough grid, or a small tool the program does not
    use, is not."""
    _stub_preview(monkeypatch, {})
    prog = tmp_path / "slot.nc"
    prog.write_text("G21 G90\nT1 M6\nM3 S9000\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X50\nG0 Z5\nM30\n")
    base = [str(prog), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "o.glb")]
    assert main(["gcode", *base, "--tool", "flat:0.4", "--cell-size", "0.5"]) == 0
    out, err = capsys.readouterr()
    assert "removed 0 mm^3" in out  # what the warning is about
    assert err == ("woodcam: warning: slot.nc: the grid (0.5 mm) is coarser than half the "
                   "diameter of T1 (0.4 mm): its cuts can fall between the cell centres and "
                   "vanish; use --cell-size 0.2 or finer\n"), err
    assert main(["gcode", *base, "--tool", "flat:0.4", "--cell-size", "0.5", "--strict"]) == 3
    capsys.readouterr()
    assert main(["gcode", *base, "--tool", "flat:0.4", "--cell-size", "0.2", "--strict"]) == 0
    assert main(["gcode", *base, "--tool", "1=flat:3", "--tool", "2=flat:0.4", "--cell-size",
                 "0.5"]) == 0
    assert "the grid" not in capsys.readouterr().err  # (the unused T2 has its own warning)
    assert main(["gcode", *base, "--units", "inch", "--tool", "flat:0.015", "--cell-size",
                 "0.02"]) == 0
    assert "the grid (0.02 in) is coarser than half the diameter of T1 (0.015 in)" in \
        capsys.readouterr().err


def test_a_g20_program_given_tool_sizes_that_look_like_inches_is_warned(tmp_path, monkeypatch, capsys):
    """A G20 (inch) program given --tool flat:0.25 (the user meant a quarter inch, read as
    0.25 mm) cut a hair-thin slot with no word. It is warned, with --units inch as the fix, and
    fails --strict; a tool of 1.6 mm or more, --units inch and a G21 program are not warned."""
    _stub_preview(monkeypatch, {})
    prog = tmp_path / "inch.nc"
    prog.write_text("G20 G90\nM3 S9000\nG0 X0.5 Y0.5 Z0.1\nG1 Z-0.05 F20\nG1 X2\nG0 Z0.1\nM2\n")
    base = [str(prog), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "o.glb")]
    assert main(["gcode", *base, "--tool", "flat:0.25", "--cell-size", "0.1"]) == 0
    assert capsys.readouterr().err == (
        "woodcam: warning: inch.nc: the program moves in inches (G20, from line 3) but every "
        "--tool is under 1.6 mm (1/16 in) across, read as mm (flat:0.25); if its sizes are "
        "inches, pass --units inch (it reads the --tool sizes and the other lengths typed in "
        "inches)\n")
    assert main(["gcode", *base, "--tool", "flat:0.25", "--strict"]) == 3
    capsys.readouterr()
    for more in (["--tool", "flat:1.6"], ["--units", "inch", "--tool", "flat:0.25"]):
        assert main(["gcode", *base, *more, "--cell-size", "0.1", "--strict"]) == 0, more
    # one tool of 3 mm: not all typed in inches (T1 is unused, warned as such, not as inches)
    assert main(["gcode", *base, "--tool", "1=flat:0.5", "--tool", "0=flat:3", "--cell-size", "0.1"]) == 0
    assert "inches" not in capsys.readouterr().err
    prog.write_text(prog.read_text().replace("G20", "G21"))
    assert main(["gcode", *base, "--tool", "flat:0.25", "--cell-size", "0.1", "--strict"]) == 0
    assert capsys.readouterr().err == ""


def test_a_run_scrubbed_before_the_first_move_says_its_machining_time(tmp_path, monkeypatch, capsys):
    """--until-line before the program's first move simulates no move, and the report ended in
    a dangling 'machining time ' with nothing after it. It says 0:00:00 (no moves) now."""
    _stub_preview(monkeypatch, {})
    prog = tmp_path / "p.nc"
    prog.write_text("G21 G90\nT1 M6\nG0 X10 Y10 Z5\nG1 Z-1 F600\nG1 X30\nM2\n")
    args = _parse([str(prog), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "o.glb"),
                   "--tool", "flat:4", "--cell-size", "0.5", "--until-line", "2"])
    assert args.func(args) == 0
    out = capsys.readouterr().out
    assert "p.nc: 0 moves read" in out and "issue(s); machining time 0:00:00 (no moves)\n" in out, out


def test_until_line_keeps_the_tools_of_the_whole_program(tmp_path, monkeypatch, capsys):
    """A two-tool program run with '--tool flat:6 --tool ball:3' failed when --until-line was
    added to scrub it before its T2 M6: the tools without numbers went to the cut-short
    program's tool numbers ('2 tools without numbers but the program uses 1 tool number(s)'),
    so the run's own command line was refused. They go to the whole program's numbers now."""
    _stub_preview(monkeypatch, {})
    prog = tmp_path / "p.nc"
    prog.write_text("G21 G90\nT1 M6\nM3 S12000\nG0 X10 Y10 Z5\nG1 Z-3 F300\nG1 X40 Y20\nG0 Z5\n"
                    "T2 M6\nM3 S12000\nG0 X20 Y30 Z5\nG1 Z-2 F300\nG1 X45\nG0 Z5\nM30\n")
    base = [str(prog), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "o.glb"),
            "--tool", "flat:6", "--tool", "ball:3", "--cell-size", "0.5"]
    for line, moves, times in (("3", 0, "0:00:00 (no moves)"), ("6", 3, "T1: 0:00:08"),
                               ("12", 7, "T2: 0:00:07")):
        args = _parse([*base, "--until-line", line])
        assert args.func(args) == 0
        out = capsys.readouterr().out
        assert f"p.nc: {moves} moves read" in out and times in out, out


def test_tools_without_numbers_go_to_the_jobs_tool_numbers_across_its_files(tmp_path, monkeypatch,
                                                                           capsys):
    """A roughing file on T1 and a finishing file on T2 (the --help's 'several files of one
    job') with '--tool flat:6 --tool ball:3' failed: each file matched the tools to its own
    numbers ('2 tools without numbers but the program uses 1'); and '--tool flat:6' alone cut
    the finishing T2 with the flat mill, without a word. The tools go to the job's numbers in
    order of first use now; a T2 without a tool is refused naming the file."""
    _stub_preview(monkeypatch, {})
    rough, finish = tmp_path / "rough.nc", tmp_path / "finish.nc"
    rough.write_text("G21 G90\nT1 M6\nM3 S12000\nG0 X10 Y10 Z5\nG1 Z-3 F300\nG1 X40 Y20\n"
                     "G0 Z5\nM30\n")
    finish.write_text("G21 G90\nT2 M6\nM3 S12000\nG0 X20 Y30 Z5\nG1 Z-2 F300\nG1 X45\nG0 Z5\n"
                      "M30\n")
    base = [str(rough), str(finish), "--block", "builtin:flat-sawn", "--out",
            str(tmp_path / "o.glb"), "--cell-size", "0.5"]
    args = _parse([*base, "--tool", "flat:6", "--tool", "ball:3"])
    assert _tools_from_args(args, [read_gcode(rough), read_gcode(finish)]) == {
        1: FlatEndMill(6), 2: BallEndMill(3)}
    assert args.func(args) == 0
    out = capsys.readouterr().out
    assert "rough.nc: 4 moves" in out and "finish.nc: 4 moves" in out and "T2: 0:00:07" in out
    args = _parse([*base, "--tool", "flat:6"])
    with pytest.raises(WoodcamError, match=r"woodcam gcode finish.nc: the program uses tool 2 "
                       r"\(first at line 4\) but tools has \[1\]"):
        args.func(args)
    args = _parse([*base, "--tool", "flat:6", "--tool", "ball:3", "--tool", "vbit:60:6"])
    with pytest.raises(WoodcamError, match=r"3 tools without numbers but the programs use 2 "
                       r"tool number\(s\) without a tool \(\[1, 2\]\).*they do not use"):
        args.func(args)

def test_a_numbered_tool_the_job_never_calls_is_warned(tmp_path, monkeypatch, capsys):
    """'--tool 3=ball:3' for a program that calls T1 and T2 (T2 from --tools) was taken
    without a word: the user who typed the wrong number cut with the table's T2. It is warned
    now, one line naming the number, the numbers the job calls and the fix, and fails --strict;
    a number the job calls, a program without a T word and its one tool, and --tools entries
    the job does not call are not warned."""
    _stub_preview(monkeypatch, {})
    prog = tmp_path / "p.nc"
    prog.write_text("G21 G90\nT1 M6\nM3 S12000\nG0 X10 Y10 Z5\nG1 Z-3 F300\nG1 X40 Y20\nG0 Z5\n"
                    "T2 M6\nM3 S12000\nG0 X20 Y30 Z5\nG1 Z-2 F300\nG1 X45\nG0 Z5\nM30\n")
    base = [str(prog), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "o.glb"),
            "--cell-size", "0.5", "--tools", str(REPO / "toolpaths" / "tools.toml")]
    assert main(["gcode", *base, "--tool", "3=ball:3"]) == 0
    assert capsys.readouterr().err == (
        "woodcam: warning: --tool 3=ball:3: the job never calls tool 3 (it uses T1, T2), so this "
        "tool cuts nothing; if it is meant for one of those, give it that number (e.g. --tool "
        "1=ball:3), else leave it out\n")
    assert main(["gcode", *base, "--tool", "3=ball:3", "--strict"]) == 3
    capsys.readouterr()
    assert main(["gcode", *base, "--tool", "2=ball:3", "--strict"]) == 0
    # --until-line scrubs the job; the tools are still the whole job's
    assert main(["gcode", *base, "--tool", "2=ball:3", "--until-line", "6", "--strict"]) == 0
    assert capsys.readouterr().err == ""
    one = tmp_path / "one.nc"  # no T word: tool 0, cut by the one tool given, whatever its number
    one.write_text("G21 G90\nM3 S9000\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X30\nM30\n")
    base = [str(one), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "o.glb"), "--cell-size", "0.5"]
    assert main(["gcode", *base, "--tool", "3=flat:6", "--strict"]) == 0
    assert capsys.readouterr().err == ""
