"""``--units inch``: every length of a command line read in inches gives what the same lengths in
millimetres give (2 in == 50.8 mm); defaults stay mm; summaries print in the unit."""

from __future__ import annotations

import re

import pytest

import woodcam.pipeline
from woodcam.cli import build_parser, main
from woodcam.cli.options import LENGTH_OPTIONS, lengths_to_mm, place_op_in
from woodcam.units import MM_PER_UNIT, fmt_length, fmt_volume

#: The same command line twice: lengths in inches, and the very same lengths in mm.
PAIRS = {
    "bake": (["p.py", "--block", "builtin:flat-sawn:4x3x1~z90", "--out", "x.glb", "--tolerance",
              "0.002", "--place", "rotate:z:90", "--place", "translate:1,-0.5,0", "--place",
              "fit:0.1"],
             ["p.py", "--block", "builtin:flat-sawn:101.6x76.2x25.4~z90", "--out", "x.glb",
              "--tolerance", "0.0508", "--place", "rotate:z:90", "--place",
              "translate:25.4,-12.7,0", "--place", "fit:2.54"]),
    "place": (["p.py", "--block", "log:gran1@52:6x2x1.5", "--out", "d", "--margin", "0.125"],
              ["p.py", "--block", "log:gran1@52:152.4x50.8x38.1", "--out", "d", "--margin",
               "3.175"]),
    "preview": (["x.glb", "--block", "builtin:knotty:2x2x2", "--cut-origin", "1,-0.5,0.25"],
                ["x.glb", "--block", "builtin:knotty:50.8x50.8x50.8", "--cut-origin",
                 "25.4,-12.7,6.35"]),
    "review": (["x.glb", "--block", "builtin:rift:2x2x1~z90[1x1x0.5@0.5,0,0.25]", "--out", "r.html"],
               ["x.glb", "--block", "builtin:rift:50.8x50.8x25.4~z90[25.4x25.4x12.7@12.7,0,6.35]",
                "--out", "r.html"]),  # a resize in a spec (what gcode --stock records) in units too
    "woodify": (["p.stl", "--years", "5", "--out", "d", "--growth", "0.5", "--block-size",
                 "4x3x2", "--block-centre=-1,0,0.5", "--crack-region", "0,0,1,0.25"],
                ["p.stl", "--years", "5", "--out", "d", "--growth", "12.7", "--block-size",
                 "101.6x76.2x50.8", "--block-centre=-25.4,0,12.7", "--crack-region",
                 "0,0,25.4,6.35"]),
    "parquetry": (["eye.png", "--out", "d", "--sheet-size", "24x16", "--leaf-thickness",
                   "0.025", "--saw-kerf", "0.015", "--tool-diameter", "0.125"],
                  ["eye.png", "--out", "d", "--sheet-size", "609.6x406.4", "--leaf-thickness",
                   "0.635", "--saw-kerf", "0.381", "--tool-diameter", "3.175"]),
    "gcode": (["p.nc", "--block", "builtin:flat-sawn:4x3x1", "--out", "x.glb", "--tool",
               "2=vbit:60:0.5", "--tool", "bull:0.25:0.05", "--tool", "snub:90:0.5:0.1",
               "--tool", "3=flat:0.25:flute=1:stickout=1.5:holder=1",
               "--work-offset", "-1,0,0.5", "--start", "0,0,0.4", "--machine-zero=-2,0,3",
               "--stock", "2x2x1",
               "--stock-origin", "0.5,0.5,0", "--cell-size", "0.004", "--rapid-rate", "200",
               "--mesh-tol", "0.001"],
              ["p.nc", "--block", "builtin:flat-sawn:101.6x76.2x25.4", "--out", "x.glb", "--tool",
               "2=vbit:60:12.7", "--tool", "bull:6.35:1.27", "--tool", "snub:90:12.7:2.54",
               "--tool", "3=flat:6.35:flute=25.4:stickout=38.1:holder=25.4",
               "--work-offset", "-25.4,0,12.7", "--start", "0,0,10.16",
               "--machine-zero=-50.8,0,76.2", "--stock",
               "50.8x50.8x25.4", "--stock-origin", "12.7,12.7,0", "--cell-size", "0.1016",
               "--rapid-rate", "5080", "--mesh-tol", "0.0254"]),
}


def _parsed(command, argv, units):
    parser = build_parser()
    args = parser.parse_args([command, *argv, "--units", units])
    lengths_to_mm(args, parser)
    return args


def _same(a, b):
    if isinstance(a, (tuple, list)) and a and isinstance(a[0], float):
        return a == pytest.approx(b, rel=1e-12)
    if isinstance(a, float):
        return a == pytest.approx(b, rel=1e-12)
    return a == b


@pytest.mark.parametrize("command", sorted(PAIRS))
def test_inch_command_line_equals_the_mm_one(command):
    inch, mm = PAIRS[command]
    a, b = _parsed(command, inch, "inch"), _parsed(command, mm, "mm")
    dests = [d for (c, d) in LENGTH_OPTIONS if c == command]
    assert dests and all(getattr(a, d) is not None for d in dests), "every length is exercised"
    for dest in dests:
        assert _same(getattr(a, dest), getattr(b, dest)), (dest, getattr(a, dest), getattr(b, dest))


def test_every_length_option_exists_and_its_command_has_units():
    parser = build_parser()
    commands = parser.get_default("_commands").choices
    for command, dest in LENGTH_OPTIONS:
        dests = {a.dest for a in commands[command]._actions}
        assert {dest, "units"} <= dests, (command, dest)


def test_every_length_option_says_it_is_read_in_units():
    """gcode --work-offset, --start, --stock, --stock-origin (and woodify's, parquetry's ...) said
    "mm" in their help while --units inch read them in inches."""
    commands = build_parser().get_default("_commands").choices
    wrong = []
    for (command, dest), kind in LENGTH_OPTIONS.items():
        if kind == "spec":  # a block spec: the --units help names its WxDxH
            continue
        action = next(a for a in commands[command]._actions if a.dest == dest)
        if "--units" not in (action.help or "") or "MM" in str(action.metavar or ""):
            wrong.append(f"{command} {action.option_strings[-1]} {action.metavar}: {action.help}")
    assert not wrong, wrong


def test_defaults_stay_millimetres():
    a = _parsed("gcode", ["p.nc", "--block", "b", "--out", "x.glb"], "inch")
    assert (a.cell_size, a.mesh_tol, a.rapid_rate) == (0.1, 0.05, 5000.0)
    a = _parsed("place", ["p.py", "--block", "b", "--out", "d"], "inch")
    assert a.margin == 1.0 and a.block == "b"  # a folder spec has no size to convert


def test_place_ops_round_trip_and_printing():
    k = MM_PER_UNIT["inch"]
    for op in ("translate:25.4,-12.7,0", "fit:2.54", "rotate:x:90", "scale:2", "center", "drop"):
        assert place_op_in(place_op_in(op, 1 / k), k) == op
    assert place_op_in("translate:25.4,-12.7,0", 1 / k) == "translate:1,-0.5,0"
    assert place_op_in("rotate:z:25.4", 1 / k) == "rotate:z:25.4"  # degrees are no length
    # printed for the user: rounded for the unit (TYPED_DECIMALS), no -0; read back: 12 digits
    assert place_op_in("translate:50,-23.7,-0.001", 1 / k, 4) == "translate:1.9685,-0.9331,0.0000"
    assert place_op_in("fit:1", 1 / k, 4) == "fit:0.0394"
    assert place_op_in("translate:50,-23.7,0", 1 / k) == "translate:1.96850393701,-0.933070866142,0"
    assert fmt_length(50.8, "inch") == "2 in" and fmt_length(50.8) == "50.8 mm"
    assert fmt_volume(25.4 ** 3 * 2, "inch") == "2 in^3" and fmt_volume(1234.4) == "1234 mm^3"
    # (the leftover of a 60x50x20 in block with --part said '6e+04 in^3')
    assert fmt_volume(25.4 ** 3 * 60000, "inch") == "60000 in^3"
    assert fmt_volume(25.4 ** 3 * 123456.7, "inch") == "123500 in^3"


def test_gcode_in_inches_cuts_what_the_mm_run_cuts(tmp_path, monkeypatch, capsys):
    """End to end through main(): the simulated stock of the inch command line is the mm one's."""
    seen = []

    def fake_preview(heightmap, stock, out_glb, **kw):
        seen.append((heightmap.copy(), tuple(stock.size_mm)))
        return woodcam.pipeline.PartPreview("x", files={"glb": out_glb}, triangles=1)

    monkeypatch.setattr(woodcam.pipeline, "preview_heightfield", fake_preview)
    prog = tmp_path / "slot.nc"
    prog.write_text("G21\nG0 X20 Y40 Z2\nG1 Z-3 F300\nX80\nG0 Z2\n")  # the program itself in mm
    common = [str(prog), "--out", str(tmp_path / "o.glb")]
    assert main(["gcode", *common, "--units", "inch", "--block", "builtin:flat-sawn:4x3x1",
                 "--tool", "flat:0.25", "--cell-size", "0.01", "--work-offset", "0,0,1"]) == 0
    out_inch = capsys.readouterr().out
    assert main(["gcode", *common, "--block", "builtin:flat-sawn:101.6x76.2x25.4",
                 "--tool", "flat:6.35", "--cell-size", "0.254", "--work-offset", "0,0,25.4"]) == 0
    out_mm = capsys.readouterr().out
    (hm_in, size_in), (hm_mm, size_mm) = seen
    assert size_in == pytest.approx(size_mm) and size_mm == pytest.approx((101.6, 76.2, 25.4))
    assert hm_in.shape == hm_mm.shape and (hm_in == hm_mm).all()
    assert (hm_mm < 25.4 - 2.9).any()  # the slot was cut, 3 mm deep
    removed_mm3 = float(out_mm.split("removed ")[1].split(" mm^3")[0])
    removed_in3 = float(out_inch.split("removed ")[1].split(" in^3")[0])
    assert removed_in3 == pytest.approx(removed_mm3 / 25.4 ** 3, rel=1e-3)


def test_place_in_inches_ranks_what_the_mm_run_ranks_and_prints_inches(tmp_path, capsys, bars):
    """End to end: the same placements, their JSON in mm, the printed --place in inches."""
    import json

    import trimesh

    part = tmp_path / "block.stl"
    trimesh.creation.box((24.0, 18.0, 10.0)).apply_translation((12, 9, 5)).export(part)
    common = ["place", str(part), "--candidates", "60", "--top", "2"]
    assert main([*common, "--units", "inch", "--block", "builtin:knotty:4x3x2", "--margin",
                 "0.05", "--out", str(tmp_path / "in")]) == 0
    out_inch = capsys.readouterr().out
    # sweep h5 item 7: a bar over the whole run (opening the block, loading the part: seconds)
    (run,) = [b for b in bars if b.desc == "place"]
    assert run.total == run.n == 4 and run.closed and run.enabled
    assert [d.split(": ")[-1] for d in run.shown[1:-1]] == ["load part", "open block", "score placements",
                                                            "render"]  # the part first (c58d41e)
    assert main([*common, "--block", "builtin:knotty:101.6x76.2x50.8", "--margin", "1.27",
                 "--out", str(tmp_path / "mm")]) == 0
    out_mm = capsys.readouterr().out
    rec = {u: json.loads((tmp_path / u / "placements.json").read_text()) for u in ("in", "mm")}
    assert [r["ops"] for r in rec["in"]["ranked"]] == [r["ops"] for r in rec["mm"]["ranked"]]
    best = rec["mm"]["ranked"][0]["ops"]
    move = next(op for op in best if op.startswith("translate:"))
    mm = [float(v) for v in move.split(":")[1].split(",")]
    assert f"--place {move}" in out_mm
    printed = out_inch.split("--place translate:")[1].split()[0]
    assert [float(v) for v in printed.split(",")] == pytest.approx([v / 25.4 for v in mm], abs=5e-5)
    # sweep h2 item 3: printed to 0.0001 in (it was 12 significant digits: 1.96850393701), the
    # JSON's ops in mm as they were
    assert printed == ",".join(f"{v / 25.4:.4f}" for v in mm), printed
    assert all(len(op.split(":")[1].split(",")[0].split(".")[1]) == 3
               for r in rec["in"]["ranked"] for op in r["ops"] if op.startswith("translate:"))
    # the inch numbers say their unit and how bake reads them: typed into 'woodcam bake' without
    # --units inch they moved the part that many mm (the column said only "place")
    assert out_inch.splitlines()[0].endswith("  place (lengths in inches: woodcam bake --units inch)")
    assert out_mm.splitlines()[0].endswith("runout  place")


def test_gcode_deviation_and_gouges_print_in_inches(tmp_path, monkeypatch, capsys):
    """With ``--part`` and ``--units inch`` the deviation line and the gouge warnings are in
    inches (the map file stays in mm); the same run in mm prints the same amounts in mm."""
    import trimesh

    monkeypatch.setattr(woodcam.pipeline, "preview_heightfield",
                        lambda hm, stock, out, **kw: woodcam.pipeline.PartPreview(
                            "x", files={"glb": out}, triangles=1))
    part = tmp_path / "part.stl"  # the whole 101.6 x 76.2 x 25.4 mm block: every cut gouges
    trimesh.creation.box(extents=(101.6, 76.2, 25.4)).apply_translation(
        (50.8, 38.1, 12.7)).export(part)
    prog = tmp_path / "slot.nc"
    prog.write_text("G21\nG0 X20 Y40 Z2\nG1 Z-2.54 F300\nX80\nG0 Z2\n")
    common = [str(prog), "--out", str(tmp_path / "o.glb"), "--part", str(part)]
    main(["gcode", *common, "--units", "inch", "--block", "builtin:flat-sawn:4x3x1",
          "--tool", "flat:0.25", "--cell-size", "0.01", "--work-offset", "0,0,1"])
    inch = capsys.readouterr()
    main(["gcode", *common, "--block", "builtin:flat-sawn:101.6x76.2x25.4",
          "--tool", "flat:6.35", "--cell-size", "0.254", "--work-offset", "0,0,25.4"])
    mm = capsys.readouterr()
    overcut_in = float(inch.out.split("overcut ")[1].split(" in^3")[0])
    overcut_mm = float(mm.out.split("overcut ")[1].split(" mm^3")[0])
    assert overcut_mm > 1000 and overcut_in == pytest.approx(overcut_mm / 25.4 ** 3, rel=1e-2)
    depth_in = float(inch.err.split("gouge: cuts ")[1].split(" in ")[0])
    depth_mm = float(mm.err.split("gouge: cuts ")[1].split(" mm ")[0])
    assert depth_mm == pytest.approx(2.54, abs=0.01) and depth_in == pytest.approx(0.1, abs=1e-3)
    assert " mm" not in inch.out.split("deviation from")[1].split("; map")[0]


def test_messages_of_an_inch_run_quote_what_was_typed_and_speak_inches(tmp_path, monkeypatch, capsys, glb_with):
    """Sweep h13 item 1: with --units inch the preview block-mismatch warning named the spec as
    converted (builtin:flat-sawn:101.6x81.28x50.8) and the baked size in mm, a block spec too big
    was refused as '25400x25.4x25.4 ... in mm', and the bake report said '1-3 mm under it'."""

    import woodcam.view as view
    from woodcam.advise import SUBSURFACE_MM, report_text
    from woodcam.stock import spec_digest
    from woodcam.units import fmt_size, fmt_span, say_length

    assert fmt_span(*SUBSURFACE_MM) == "1-3 mm" and fmt_span(*SUBSURFACE_MM, "inch") == "0.039-0.12 in"
    assert fmt_size((101.6, 81.28, 50.8), "inch") == "4x3.2x2 in" and fmt_size((100, 80, 50)) == "100x80x50 mm"
    meta = {"block": "builtin:flat-sawn", "block_digest": spec_digest("builtin:flat-sawn"),
            "size_mm": [100.0, 80.0, 50.0]}
    glb = glb_with(meta, tmp_path / "tray.glb")
    seen = {}
    # the scene's messages (a cut plane missing the block) speak the message units, set for the run
    monkeypatch.setattr(view, "preview", lambda mesh, **kw: seen.update(kw, inch=say_length(25.4)))
    assert main(["preview", str(glb), "--screenshot", "--units", "inch",
                 "--block", "builtin:flat-sawn:4x3.2x2"]) == 0
    assert seen["inch"] == "1 in"
    err = capsys.readouterr().err
    assert ("--block builtin:flat-sawn:4x3.2x2 is not the block tray.glb was baked from "
            "(builtin:flat-sawn, 3.937x3.15x1.969 in)") in err
    assert main(["bake", "p.stl", "--units", "inch", "--block", "builtin:knotty:1000x1x1",
                 "--out", str(tmp_path / "x.glb")]) == 2  # at the door: a usage error
    err = capsys.readouterr().err
    assert "--block builtin:knotty:1000x1x1: the size must be WxDxH in --units inch" in err
    assert ("<= 393.7 in (raise it with WOODCAM_MAX_BLOCK_SIZE_MM=N); got '1000x1x1', e.g. 11.8x4.72x1.57 in"
            in err) and "25400" not in err
    # the same rule, at the door, in mm (it was the stock's error there: exit 1, other words)
    for units in ([], ["--units", "mm"]):
        assert main(["bake", "p.stl", *units, "--block", "builtin:knotty:20000x1x1",
                     "--out", str(tmp_path / "x.glb")]) == 2
        assert capsys.readouterr().err == (
            "woodcam: error: --block builtin:knotty:20000x1x1: the size must be WxDxH in mm, each "
            "> 0 and <= 10000 mm (raise it with WOODCAM_MAX_BLOCK_SIZE_MM=N); got '20000x1x1', e.g. 300x120x40 mm\n")
    report = {"volume_mm3": 16387.064, "yield": 0.1, "knots": 0.02, "knots_surface": 0.0, "pith": 0.0,
              "end_grain": 0.2, "elongation": 0.3, "warnings": [
                  "a knot lies 1-3 mm under the surface (it may show after sanding)"],
              "regions": [{"region": "first third", "grain": [1, 0, 0], "runout_deg": 1, "knots": 0.0}]}
    text = report_text(report, "tray", "inch")
    assert " mm" not in text and text.count("0.039-0.12 in under") == 4, text
    assert "tray: 1 in^3" in text
    assert report_text(report, "tray").count("1-3 mm under") == 4


def test_library_messages_of_an_inch_run_speak_inches(tmp_path, monkeypatch, capsys):
    """Sweep h3 item 1: with --units inch the library's own messages said mm: place's no-fit
    error ('a 1 mm margin'), the carve hint of a part in inches ('only 1x1x1 mm in the 50.8x...
    mm block') and the G-code simulation issues ('cuts up to 1.000 mm into the stock'). They
    follow --units now (woodcam.units.message_units); a library caller still reads mm."""
    import trimesh

    from woodcam.advise import advise_placement
    from woodcam.errors import WoodcamError
    from woodcam.stock import open_stock

    big, tiny = tmp_path / "big.stl", tmp_path / "tiny.stl"
    trimesh.creation.box((240.0, 18.0, 10.0)).apply_translation((120, 9, 5)).export(big)
    trimesh.creation.box((1.0, 1.0, 1.0)).apply_translation((20, 20, 20)).export(tiny)
    assert main(["place", str(big), "--units", "inch", "--block", "builtin:knotty:4x3x2",
                 "--out", str(tmp_path / "pl")]) == 1
    err = capsys.readouterr().err
    assert f"part {str(big)!r} (9.449x0.7087x0.3937 in) fits the 4x3x2 in block" in err, err
    assert "with a 0.03937 in margin" in err and " mm" not in err, err
    with pytest.raises(WoodcamError, match=r"\(240.0x18.0x10.0 mm\) fits the 101.6x76.2x50.8 mm "
                       r"block .* with a 1 mm margin"):  # the library's callers: mm, as before
        advise_placement(big, open_stock("builtin:knotty:101.6x76.2x50.8"), candidates=4)
    assert main(["place", str(tiny), "--units", "inch", "--block", "builtin:knotty:2x2x2",
                 "--candidates", "4", "--top", "1", "--out", str(tmp_path / "pt")]) == 0
    err = capsys.readouterr().err
    # the hint of a part modelled in inches is about the file's own numbers: mm (sweep h13 item 7)
    assert "the part is only 1x1x1 mm in the 50.8x50.8x50.8 mm block" in err, err

    meta = {}
    monkeypatch.setattr(woodcam.pipeline, "preview_heightfield",
                        lambda hm, stock, out, **kw: meta.update(kw["metadata"]) or woodcam.pipeline.PartPreview(
                            "x", files={"glb": out}, triangles=1))
    prog = tmp_path / "p.nc"
    prog.write_text("G21\nM3 S1000\nG0 X20 Y40 Z2\nG1 Z-30 F300\nX80\nG0 Z-1\nX10\nG0 Z2\nM5\nM2\n")
    assert main(["gcode", str(prog), "--units", "inch", "--block", "builtin:flat-sawn:4x3x1",
                 "--tool", "flat:0.25", "--cell-size", "0.04", "--work-offset", "0,0,1",
                 "--out", str(tmp_path / "g.glb")]) == 0
    err = capsys.readouterr().err
    assert "below_stock_bottom: tool tip at z = -1.181 in (G-code frame), 0.1811 in below" in err, err
    assert "rapid_through_stock: rapid move (G0) cuts up to 0.03937 in into the stock" in err, err
    assert " mm" not in err, err
    # review h15 item 7: the GLB's metadata copy of the issues was in inches too: files stay mm
    filed = " ".join(w["message"] for w in meta["warnings"])
    assert "below_stock_bottom: tool tip at z = -30.000 mm (G-code frame), 4.600 mm below" in filed, filed
    assert "rapid move (G0) cuts up to 1.000 mm into the stock" in filed and " in " not in filed, filed



def test_an_inch_bake_files_its_report_in_mm_and_prints_its_warnings_in_inches(tmp_path, capsys):
    """Sweep h13 item 1: under --units inch the part report's files (_report.txt, _report.json,
    the GLB's metadata) held the carve's "part sticks out" warning in inches beside their mm
    numbers. Files stay in mm (woodcam.units.said / filed); the warning printed follows --units."""
    import json

    import trimesh

    from woodcam.export import read_glb_metadata

    part = tmp_path / "out.stl"
    trimesh.creation.box((30.0, 20.0, 10.0)).apply_translation((10, 10, 5)).export(part)
    out = tmp_path / "b.glb"
    assert main(["bake", str(part), "--units", "inch", "--block", "builtin:knotty:2x2x2",
                 "--texels-per-mm", "2", "--no-obj", "--out", str(out)]) == 0
    captured = capsys.readouterr()
    said = ("part sticks out of the block: 0.06102 in^3 (16.7 % of the part's 0.3661 in^3) lies outside "
            "and is not carved; part bounding box [-0.1969, 0.9843] x [0, 0.7874] x [0, 0.3937] in, "
            "block [0, 2] x [0, 2] x [0, 2] in")
    # said once, on stderr in --units: the printed report left it out (it was on stdout too)
    assert captured.err.count(said) == 1 and f"woodcam: warning: {said}" in captured.err
    assert "sticks out" not in captured.out, captured.out
    filed = ("part sticks out of the block: 1000 mm^3 (16.7 % of the part's 6000 mm^3) lies outside "
             "and is not carved; part bounding box [-5, 25] x [0, 20] x [0, 10] mm, "
             "block [0, 50.8] x [0, 50.8] x [0, 50.8] mm")
    text = (tmp_path / "b_report.txt").read_text()
    assert f"  warning: {filed}" in text and " in^3" not in text and "] in" not in text, text
    assert json.loads((tmp_path / "b_report.json").read_text())["warnings"][0].startswith(filed)
    assert read_glb_metadata(out)["report"]["warnings"][0].startswith(filed)


def test_an_inch_place_error_quotes_the_op_as_typed(tmp_path, capsys):
    """Sweep h13 item 2: a --place error of an inch run quoted the op converted to mm beside a
    margin in inches ("--place 'fit:38.1': a margin of 1.5 in"); it quotes the op as typed."""
    import trimesh

    part = tmp_path / "p.stl"
    trimesh.creation.box((10.0, 10.0, 10.0)).apply_translation((20, 20, 20)).export(part)
    # a margin too wide for this block is failed work (exit 1); a move out of range, a malformed
    # command line (exit 2, at the door)
    for op, said, rc in (("fit:1.5", "--place 'fit:1.5': a margin of 1.5 in leaves no room in the 2x2x2 in block; "
                                     "a margin must be less than half its smallest side: write fit:MARGIN with "
                                     "MARGIN below 1 in, or fit for 0.07874 in", 1),
                         ("translate:1e5,0,0", "--place 'translate:1e5,0,0': a move must stay within 100 m", 2)):
        assert main(["bake", str(part), "--units", "inch", "--block", "builtin:knotty:2x2x2",
                     "--place", "center", "--place", op, "--out", str(tmp_path / "b.glb")]) == rc
        err = capsys.readouterr().err
        assert said in err and "38.1" not in err and "2540000" not in err, err


def test_areas_and_limits_in_library_messages_speak_the_message_units():
    """Sweep h13 items 5, 6, 12: under --units inch the bake's atlas warning still said "(texel
    X mm) ... N mm^2 surface", parquetry's cut check "N mm^2 of it is narrower" and the G-code
    zero-radius arc error "radius 3.937e-05 in is below LinuxCNC's 0.00127 mm"."""
    from woodcam.toolpath import GcodeError, read_gcode
    from woodcam.units import message_units, say_area

    assert say_area(645.16) == "645.2 mm^2" and say_area(1234.4, ".0f") == "1234 mm^2"
    arc = "G21 G0 X0 Y0\nG2 X0.002 Y0 I0.001 J0 F100\nM2\n"
    with pytest.raises(GcodeError, match=r"radius 0.001 mm is below LinuxCNC's 0.00127 mm;"):
        read_gcode(arc)
    with message_units("inch"):
        assert say_area(645.16) == "1 in^2" and say_area(1234.4, ".0f") == "1.913 in^2"
        with pytest.raises(GcodeError, match=r"radius 3.937e-05 in is below LinuxCNC's 5e-05 in;"):
            read_gcode(arc)


def test_say_length_takes_a_0d_array():
    """Sweep h13 item 9: say_length(np.array(2.0)) raised TypeError (iteration over a 0-d array)."""
    import numpy as np

    from woodcam.units import message_units, say_length

    assert say_length(np.array(2.0)) == "2 mm" and say_length(np.float64(2.5), ".2f") == "2.50 mm"
    assert say_length(np.array([1.0, 2.0])) == "1x2 mm" and say_length(3) == "3 mm"
    with message_units("inch"):
        assert say_length(np.array(25.4)) == "1 in"


def test_the_units_hint_speaks_the_files_millimetres_under_every_units():
    """Sweep h13 item 7: the hint of a part modelled in inches said "0.03937x... in in the 2x2x2
    in block" under --units inch from carve and advise_placement, while woodify said mm: the
    hint is about the file's own numbers, read as mm whatever --units says, so mm for all."""
    import trimesh

    from woodcam.cad import carve
    from woodcam.errors import WoodcamWarning
    from woodcam.units import message_units

    tiny = trimesh.creation.box((1.0, 2.0, 1.0)).apply_translation((20, 20, 20))
    for units in ("mm", "inch"):
        with message_units(units), pytest.warns(WoodcamWarning) as caught:
            carve(tiny, (50.8, 50.8, 50.8))
        assert [str(w.message) for w in caught if "only" in str(w.message)][0].startswith(
            "the part is only 1x2x1 mm in the 50.8x50.8x50.8 mm block: 25.4 times larger"), units


def test_say_length_and_say_volume_take_a_summarys_units():
    """Sweep h13 item 8: the deviation summary's depths and volumes had their own formatting
    (fmt_depth, _volume) beside say_length / say_volume; these take ``units=`` now (a summary's
    unit, not the run's message units) and the summary goes through them, its text unchanged."""
    from woodcam.toolpath.deviation import fmt_depth
    from woodcam.units import message_units, say_length, say_volume

    with message_units("inch"):  # an explicit unit wins over the message units
        assert say_length(0.085, ".3f", units="mm") == "0.085 mm" == fmt_depth(0.085)
        assert say_volume(0.6, ".1f", units="mm") == "0.6 mm^3"
    assert say_length(25.4, ".3f", units="inch") == "1 in" == fmt_depth(25.4, "inch")
    assert say_volume(16387.064, ".0f", units="inch") == "1 in^3"


def test_a_large_volume_or_area_is_said_without_an_exponent():
    """A part of 120000 mm^3 sticking 110000 mm^3 out of its block was warned of as
    '1.1e+05 mm^3 (91.7 % of the part's 120000 mm^3)': a message's volumes and areas are
    written out, rounded to the spec's significant digits, in one form."""
    import trimesh

    from woodcam.cad.carve import carve
    from woodcam.errors import WoodcamWarning
    from woodcam.units import say_area, say_volume

    assert say_volume(110000.0) == "110000 mm^3" and say_volume(123456.7) == "123500 mm^3"
    assert say_area(2.5e6) == "2500000 mm^2" and say_volume(1.518) == "1.518 mm^3"
    with pytest.warns(WoodcamWarning) as caught:
        carve(trimesh.creation.box((300.0, 20.0, 20.0)), (100.0, 80.0, 50.0))
    said = [str(w.message) for w in caught if "sticks out" in str(w.message)]
    assert said and said[0].startswith("part sticks out of the block: 110000 mm^3 (91.7 % of the part's "
                                       "120000 mm^3) lies outside"), said


@pytest.mark.parametrize("units, spec", [
    (["--units", "inch"], "builtin:knotty[4x3]"),          # three sides wanted
    (["--units", "inch"], "builtin:knotty[1000x1x1]"),     # over the cap once in inches
    (["--units", "inch"], "builtin:knotty:4x3x2[4x3x0@1,1,1]"),
    ([], "builtin:knotty[40x30x20@a,1,2]"),
])
def test_a_spec_resize_is_checked_as_typed_at_the_door(units, spec, tmp_path, capsys):
    """Sweep h16 item A: only a spec's :WxDxH was checked at the door; a resize [WxDxH@X,Y,Z]
    reached the stock's check converted: --units inch 'builtin:knotty[1000x1x1]' said
    "block spec 'builtin:knotty[25400x25.4x25.4]': the size must be WxDxH in mm" (exit 1)."""
    assert main(["bake", "p.stl", *units, "--block", spec, "--out", str(tmp_path / "x.glb")]) == 2
    err = capsys.readouterr().err
    said = "--units inch" if units else "mm"
    assert err.startswith(f"woodcam: error: --block {spec}: a resize must be [WxDxH] or "
                          f"[WxDxH@X,Y,Z] in {said}"), err
    assert "25.4" not in err and "101.6" not in err and err.count("\n") == 1


@pytest.mark.parametrize("spec, stock_says, door_says", [
    ("builtin:knotty:4x3x2:", "the size must be WxDxH in mm", "the size must be WxDxH in mm"),  # a trailing ':'
    ("builtin:knotty[40 x30x20]", "'[40 x30x20]' is neither a turn", "a resize must be [WxDxH]"),
    ("builtin:knotty~q90", "turn '~q90' must be ~AXIS", "turn '~q90' must be ~AXIS"),
    ("builtin:knotty~z90 ", "'~z90 ' is neither a turn", "'~z90 ' is neither a turn"),
    ("log:gran1@x:60x40x30", "a log block must read 'log:LOG@KNOT'", "a log block must read 'log:LOG@KNOT'"),
])
def test_the_door_refuses_what_the_stock_refuses(spec, stock_says, door_says, tmp_path, capsys):
    """Sweep H1: the --block door check had a grammar of its own (a pattern for the :WxDxH, the
    resizes by the ops' text), so it let through specs the stock refused once the command ran
    (exit 1): a trailing ':', a space in a resize, a bad turn, a log block without a knot. It
    now reads the spec with the stock's own reader (woodcam._specs.parse_spec)."""
    from woodcam.errors import WoodcamError
    from woodcam.stock import open_stock

    with pytest.raises(WoodcamError, match=re.escape(stock_says)):
        open_stock(spec)
    assert main(["bake", "p.stl", "--block", spec, "--out", str(tmp_path / "x.glb")]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"woodcam: error: --block {spec}: ") and door_says in err, err
    assert err.count("\n") == 1


@pytest.mark.parametrize("inch, mm", [
    ("log:/data/~scan/l.json@2:4x3x2~z90[1x1x1@0.5,0,0]",
     "log:/data/~scan/l.json@2:101.6x76.2x50.8~z90[25.4x25.4x25.4@12.7,0,0]"),
    ("log:/data/logs[2]/l.json@2:4x3x2", "log:/data/logs[2]/l.json@2:101.6x76.2x50.8"),
    ("builtin:knotty:4X3X2~Z90.0[2X1X1]", "builtin:knotty:101.6x76.2x50.8~z90[50.8x25.4x25.4]"),
])
def test_an_inch_spec_is_the_block_its_mm_spelling_is(inch, mm, tmp_path, capsys):
    """Sweep H1: --units inch scaled a log block's :WxDxH only when its path had no '~' or '['
    (a pattern of its own): 'log:/data/~scan/l.json@2:4x3x2' stayed a 4x3x2 mm block, and was
    not checked at the door either. The spec is read once and written back in mm."""
    from woodcam.stock import spec_digest

    from woodcam._specs import parse_spec

    got = _parsed("place", ["p.py", "--block", inch, "--out", "d"], "inch").block
    assert spec_digest(got) == spec_digest(mm), got  # the same block, turns and resizes included
    assert parse_spec(got).size_mm == pytest.approx(parse_spec(mm).size_mm, rel=1e-12)
    big = inch.replace("4x3x2", "1000x1x1").replace("4X3X2", "1000x1x1")  # 25.4 m: refused as typed
    assert main(["place", "p.stl", "--units", "inch", "--block", big, "--out", str(tmp_path / "d")]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"woodcam: error: --block {big}: the size must be WxDxH in --units inch"), err


def test_a_malformed_place_is_refused_before_the_block_is_opened(tmp_path, capsys, monkeypatch):
    """'bake --place fit:abc' (or rotate:q:90, or a negative fit margin) was refused only when the
    part was placed: after the block was opened (a photographed block's fit, 20-30 s the first
    time) and the part loaded. It is refused first now, quoting the op as typed, as a usage error
    (exit 2: a wrong command line; it exited 1)."""
    import trimesh

    import woodcam.stock

    opened = []
    real = woodcam.stock.open_stock
    monkeypatch.setattr(woodcam.stock, "open_stock", lambda *a, **k: opened.append(a) or real(*a, **k))
    part = tmp_path / "p.stl"
    trimesh.creation.box((10.0, 10.0, 10.0)).apply_translation((20, 20, 20)).export(part)
    for op, said in (("fit:abc", "--place 'fit:abc': 'abc' is not a finite number"),
                     ("rotate:q:90", "--place 'rotate:q:90': expected rotate:AXIS:DEG"),
                     ("fit:-0.1", "--place 'fit:-0.1': a margin must be >= 0; got -0.1 in"),
                     ("rotate:z:1e308", "--place 'rotate:z:1e308': an angle must be within a full turn")):
        assert main(["bake", str(part), "--units", "inch", "--block", "builtin:knotty:2x2x2",
                     "--place", "center", "--place", op, "--out", str(tmp_path / "b.glb")]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and said in err, err
    assert opened == []
    assert main(["bake", str(part), "--block", "builtin:flat-sawn", "--place", "center", "--place", "fit:1",
                 "--out", str(tmp_path / "b.glb"), "--no-obj", "--texels-per-mm", "1"]) == 0
    assert len(opened) == 1


@pytest.mark.parametrize("tool, says", [
    ("flat:2000", "FlatEndMill: the diameter must be a positive number in (0, 39.37] in, got 2000 in; give the "
                  "cutting diameter in inches"),
    ("ball:-0.5", "BallEndMill: the diameter must be a positive number in (0, 39.37] in, got -0.5 in; give the "
                  "cutting diameter in inches"),
    ("bull:0.25:0.2", "BullNoseMill: the corner radius must be in (0, diameter/2 = 0.125] in, got 0.2 in; use "
                      "ball for rc = R or flat for rc = 0"),
    ("snub:60:0.5:0.6", "SnubNoseVBit: the tip diameter must be in [0, diameter = 0.5) in, got 0.6 in"),
    ("chamfer:90:0.5:0.5", "ChamferMill: the tip diameter must be in [0, diameter = 0.5) in, got 0.5 in"),
    ("taperball:0.1:0.2:3", "TaperedBallMill: the tip diameter must be in (0, diameter = 0.1] in, got 0.2 in"),
    ("flat:0.25:shank=-1", "FlatEndMill: shank= must be a positive length in (0, 393.7] in, got -1 in"),
    ("vbit:60:0.5:flute=0.1:stickout=0.05:holder=1",
     "VBit: stickout=0.05 in (tip to holder) is shorter than flute=0.1 in; the holder would cover the flutes"),
    ("flat:0.25:holder=1", "FlatEndMill: holder= and stickout= go together (the holder's size and where it "
                           "starts above the tip); got 1 in and None"),
])
def test_a_tools_rule_under_units_inch_speaks_inches(tool, says, tmp_path, capsys):
    """Tool-building errors spoke mm under --units inch: "--tool 'flat:2000' (read as 'flat:50800'
    in mm): FlatEndMill: diameter_mm must be a positive number in (0, 1000] mm, got 50800", of a
    spec typed in inches; a bull's corner, a tip, the reach likewise."""
    argv = ["gcode", "toolpaths/drilling.nc", "--block", "builtin:flat-sawn", "--out", str(tmp_path / "g.glb"),
            "--units", "inch", "--tool", tool]
    capsys.readouterr()
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"woodcam: error: --tool {tool!r}: {says}"], err
    assert not re.search(r"\bmm\b|_mm", err[0]), err


def test_a_tool_tables_rule_stays_mm_under_units_inch_and_names_its_entry(tmp_path, capsys):
    """A tool table's keys and numbers are mm whatever --units says (files stay mm): its refusal
    speaks mm and its keys, and names the table and the entry (it named neither)."""
    table = tmp_path / "tools.toml"
    table.write_text('[tools.3]\ntype = "bull"\ndiameter_mm = 6\ncorner_radius_mm = 4\n')
    argv = ["gcode", "toolpaths/drilling.nc", "--block", "builtin:flat-sawn", "--out", str(tmp_path / "g.glb"),
            "--units", "inch", "--tools", str(table)]
    capsys.readouterr()
    assert main(argv) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"woodcam: error: load_tool_table: {table}: [tools.3]: BullNoseMill: corner_radius_mm must be "
                   "in (0, diameter/2 = 3] mm, got 4 mm; use ball for rc = R or flat for rc = 0"], err


def test_the_units_help_says_the_messages_speak_it():
    """With no length typed, 'review PART --block FOLDER --units inch' changed only its warnings'
    lengths ('45 mm past its right face' -> '1.772 in past ...'; the page byte for byte the same),
    and every command's --units help named only the options it reads and what stays mm. The help
    now says the warnings and errors speak it, and review's that its page measures in mm."""
    commands = build_parser().get_default("_commands").choices
    with_units = sorted({c for c, _ in LENGTH_OPTIONS})
    for command in with_units:
        action = next(a for a in commands[command]._actions if a.dest == "units")
        assert "the lengths in warnings and errors" in action.help, (command, action.help)
    review = next(a for a in commands["review"]._actions if a.dest == "units")
    assert "files written (the page's measurements too) stay mm" in review.help


@pytest.mark.parametrize("units, option, value, says", [
    # a rate: --rapid-rate 0.001 (inch/min) was refused as '[0.1, 1e+06] mm; got 0.001 inch =
    # 0.0254 mm', a length where the option reads a length per minute
    ("inch", "--rapid-rate", "0.001", "--rapid-rate must be in [0.1, 1e+06] mm/min; got 0.001 "
                                      "inch/min = 0.0254 mm/min;"),
    ("mm", "--rapid-rate", "0.001", "--rapid-rate must be in [0.1, 1e+06] mm/min; got 0.001 mm/min;"),
    ("inch", "--rapid-rate", "nan", "--rapid-rate must be a finite number in [0.1, 1e+06] mm/min; "
                                    "got nan inch/min;"),
    # a length under --units mm said no unit at all: '[0.005, 10]; got 20.0'
    ("mm", "--cell-size", "20", "--cell-size must be in [0.005, 10] mm; got 20.0 mm;"),
    ("inch", "--cell-size", "0.5", "--cell-size must be in [0.005, 10] mm; got 0.5 inch = 12.7 mm;"),
    ("mm", "--start", "0,0,1e9", "--start must be in [-100000, 100000] mm; got 1000000000.0 mm;"),
])
def test_a_range_error_says_the_unit_of_the_range_and_the_value(units, option, value, says, tmp_path,
                                                               capsys):
    prog = tmp_path / "p.nc"
    prog.write_text("G21\nG0 X1 Z2\nM2\n")
    assert main(["gcode", str(prog), "--block", "builtin:flat-sawn", "--tool", "flat:3", "--out",
                 str(tmp_path / "o.glb"), "--units", units, option, value]) == 2
    assert says in capsys.readouterr().err


def test_a_small_volume_or_area_is_said_without_an_exponent():
    """A 1 mm^3 part baked under --units inch was summed up as '6.102e-05 in^3' (fmt_volume:
    'never in exponent form' held for large volumes only); small volumes and areas are written
    out to their four significant digits, in every unit."""
    from woodcam.units import say_area, say_volume

    assert fmt_volume(1.0, "inch") == "0.00006102 in^3"
    assert fmt_volume(1e-5) == "0.00001 mm^3" and say_volume(2.5e-6) == "0.0000025 mm^3"
    assert say_area(1e-3, units="inch") == "0.00000155 in^2"
    assert fmt_volume(25.4 ** 3 * 2, "inch") == "2 in^3" and fmt_volume(1.518) == "1.518 mm^3"
    assert "e" not in fmt_volume(-1e-9, "inch")


def test_the_reach_issues_of_an_inch_run_are_filed_in_mm(tmp_path, monkeypatch, capsys):
    """The GLB's metadata copy of the simulation issues (the review page's hotspots) stays mm
    under --units inch, as the other issues' (review h15 item 7): the reach checks' messages
    (deeper_than_flute, shank and holder) were built with say_length alone, so the file said
    'cuts 1.18 in deep with 0.5 in of flute' beside 'cuts up to 1.000 mm into the stock'."""
    meta = {}
    monkeypatch.setattr(woodcam.pipeline, "preview_heightfield",
                        lambda hm, stock, out, **kw: meta.update(kw["metadata"]) or woodcam.pipeline.PartPreview(
                            "x", files={"glb": out}, triangles=1))
    prog = tmp_path / "p.nc"
    prog.write_text("G20\nM3 S1000\nG0 X1 Y1 Z0.1\nG1 Z-0.9 F30\nX3\nG0 Z0.1\nM5\nM2\n")
    assert main(["gcode", str(prog), "--units", "inch", "--block", "builtin:flat-sawn:4x3x1",
                 "--tool", "flat:0.25:flute=0.5:holder=1:stickout=0.7", "--cell-size", "0.04",
                 "--out", str(tmp_path / "g.glb")]) == 0
    err = capsys.readouterr().err
    said = [ln for ln in err.splitlines() if "deeper_than_flute" in ln or "holder_collision" in ln]
    assert len(said) == 2 and all(" mm" not in ln and " in " in ln for ln in said), err
    filed = [w["message"] for w in meta["warnings"]
             if "deeper_than_flute" in w["message"] or "holder_collision" in w["message"]]
    assert len(filed) == 2 and all(" mm" in m and " in " not in m for m in filed), filed
    assert any("deep with 12.7 mm of flute" in m for m in filed), filed
