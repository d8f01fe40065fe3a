"""The woodcam command end to end: demo, bake, preview, and clean one-line errors."""

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import trimesh
from PIL import Image

from woodcam.cli import main
from woodcam.export import read_glb_metadata

REPO = __import__("pathlib").Path(__file__).resolve().parents[1]


def test_demo_quick_writes_every_output(tmp_path, capsys, bars):
    assert main(["demo", "--out", str(tmp_path), "--quick"]) == 0
    # sweep h5 item 7: 20 s with no bar; now one over the parts and one of each part's stages
    demo = [b for b in bars if b.desc == "demo"]
    assert len(demo) == 1 and demo[0].total == demo[0].n == 4 and demo[0].closed and demo[0].enabled
    for part in ("bowl", "tray", "lid"):
        own = [b for b in bars if b.desc == part]
        assert len(own) == 1 and own[0].total == own[0].n == 6 and own[0].closed  # render too
        assert own[0].enabled
    out = capsys.readouterr().out
    for part in ("bowl", "tray", "lid"):
        for suffix in (".glb", ".obj", ".mtl", "_texture.png", "_view.png"):
            f = tmp_path / f"{part}{suffix}"
            assert f.is_file() and f.stat().st_size > 0, f
        assert part in out
        view = np.asarray(Image.open(tmp_path / f"{part}_view.png").convert("RGB"))
        assert (np.abs(view.astype(int) - 255).sum(-1) > 30).mean() > 0.05  # not blank
    assert (tmp_path / "demo.png").is_file()
    for stage in ("load", "carve", "bake", "export", "render"):
        assert stage in out
    # the summary's "files:" list names every file written (it left out the MTL, the texture
    # and the JSON report)
    listed = set(re.findall(r"\S+", out.split("files:", 1)[1].replace(",", " ")))
    written = {str(f) for f in tmp_path.iterdir() if f.name != "demo.png"}
    assert written <= listed, written - listed


def test_bake_and_preview_from_the_command_line(tmp_path, capsys):
    glb = tmp_path / "tray.glb"
    rc = main(["bake", str(REPO / "cad_examples" / "tray.py"), "--block", "builtin:quarter-sawn",
               "--out", str(glb), "--texels-per-mm", "3"])
    assert rc == 0
    assert read_glb_metadata(glb)["block"] == "builtin:quarter-sawn"
    mesh = trimesh.load(glb, force="mesh")
    assert mesh.visual.uv is not None and len(mesh.faces) > 1000
    png = tmp_path / "tray.png"
    assert main(["preview", str(glb), "--screenshot", str(png)]) == 0
    assert png.is_file()
    assert "wrote" in capsys.readouterr().out


@pytest.mark.parametrize("argv, message, code", [
    # a part or block folder that is not there, or a built-in block no one has, is a wrong command
    # line (exit 2, was 1)
    (["bake", "missing.py", "--block", "builtin:flat-sawn", "--out", "x.glb"], "missing.py", 2),
    (["bake", "cad_examples/tray.py", "--block", "builtin:oak-burl", "--out", "x.glb"],
     "unknown built-in block 'oak-burl'", 2),
    (["bake", "cad_examples/tray.py", "--block", "nowhere/", "--out", "x.glb"],
     "(block spec 'nowhere/'): 'nowhere' does not exist; it must be an existing FOLDER (a block spec is", 2),
])
def test_errors_are_one_clean_line(argv, message, code, tmp_path):
    res = subprocess.run([sys.executable, "-m", "woodcam.cli", *argv], cwd=REPO,
                         capture_output=True, text=True)
    assert res.returncode == code
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("woodcam: error:") and message in lines[0]
    assert "Traceback" not in res.stderr


@pytest.mark.parametrize("argv, message", [
    (["--knot-darkening", "0.3"], "--knot-darkening takes 2 comma-separated numbers in [0, 1]; got '0.3'; "
     "e.g. 0.25,0.45"),
    (["--knot-outline", "0.1,0.1,2"], "--knot-outline takes 3 comma-separated numbers in [0, 1]; got "
     "'0.1,0.1,2'; e.g. 0.16,0.10,0.06"),
    # argparse took "-0.1,0.3" for an option: "expected one argument", not the rule
    (["--knot-darkening", "-0.1,0.3"], "--knot-darkening takes 2 comma-separated numbers in [0, 1]; "
     "got '-0.1,0.3'"),
    (["--knot-outline", "-1,0,0"], "--knot-outline takes 3 comma-separated numbers in [0, 1]; got '-1,0,0'"),
    (["--appearance", "neural", "--knot-darkening", "0.3,0.4"], "apply to --appearance colormap only (the neural "
     "appearance learns knot colours from the photos); got --knot-darkening with --appearance neural; leave them "
     "out, or use --appearance colormap"),
    (["--quality", "draft"], "--quality and --epochs apply to --appearance neural only; got --quality draft with "
     "--appearance colormap; add --appearance neural, or leave them out"),
])
def test_appearance_options_out_of_range_or_contradicting_are_usage_errors(argv, message):
    """A knot darkening or outline colour out of [0, 1], or a knot option beside the neural
    appearance, exited 1 (a runtime error) where every other range error exits 2."""
    res = subprocess.run([sys.executable, "-m", "woodcam.cli", "bake", "cad_examples/tray.py", "--block",
                          "builtin:knotty", "--out", "x.glb", *argv], cwd=REPO, capture_output=True, text=True)
    assert res.returncode == 2, res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("woodcam: error:") and message in lines[0]
    assert "Traceback" not in res.stderr



def test_a_line_number_or_candidate_count_out_of_range_is_a_usage_error(tmp_path, capsys):
    """Sweep h6: ``gcode --until-line -3`` exited 1 (a runtime error) and ``place --candidates
    5000000`` passed the range check (up to 1e7), loaded the part, then exited 1 naming the Python
    parameter ('candidates must be an integer in [1, 1e6]'); every other range error exits 2,
    before any work, naming the option."""
    from woodcam.cli import main

    out = tmp_path / "o.glb"
    assert main(["gcode", str(REPO / "toolpaths/vcarve_text.nc"), "--tool", "vbit:60:12", "--block", "builtin:flat-sawn",
                 "--until-line", "-3", "--out", str(out)]) == 2
    assert "--until-line must be in [1, 1e+08]; got -3" in capsys.readouterr().err
    assert main(["place", str(REPO / "cad_examples/lid.py"), "--block", "builtin:flat-sawn", "--candidates", "5000000",
                 "--out", str(tmp_path / "place")]) == 2
    assert "--candidates must be in [1, 1e+06]; got 5000000" in capsys.readouterr().err
    assert not out.exists() and not (tmp_path / "place").exists()

def test_knot_flags_reach_the_colour_map(tmp_path):
    """--knot-darkening 0,0 leaves knot wood as light as the stem's; 0.9,0.9 makes it dark."""
    from woodcam.appearance.knots import KnotShading
    from woodcam.cli import build_parser
    from woodcam.cli.options import appearance_params as _appearance_params
    from woodcam.stock import open_stock

    base = ["bake", "x.py", "--block", "builtin:knotty", "--out", "x.glb"]
    args = build_parser().parse_args(base + ["--knot-darkening", "0.9,0.8", "--knot-outline", "0,0.5,1"])
    params = _appearance_params(args)
    # (and a colour map fitted to photos of a knot keeps this darkening, not the photos' knot)
    assert params == {"knots": KnotShading(0.9, 0.8, (0.0, 0.5, 1.0)), "knot_lut": None}
    wood_light = open_stock("builtin:knotty", knots=KnotShading(0.0, 0.0)).wood
    stock = open_stock("builtin:knotty", **params)
    wood_dark, field = stock.wood, stock.wood.field
    pts = np.random.default_rng(0).uniform((0, 0, 0), stock.size_mm, (20000, 3))
    knot = field.knot_features(pts)["knot"] > 0.9
    assert knot.sum() > 50
    n = np.tile([0.0, 1.0, 0.0], (int(knot.sum()), 1))
    light = wood_light.appearance.color(field, pts[knot], n).mean()
    dark = wood_dark.appearance.color(field, pts[knot], n).mean()
    assert dark < 0.5 * light, (dark, light)


def test_help_explains_block_frame():
    res = subprocess.run([sys.executable, "-m", "woodcam.cli", "--help"], capture_output=True, text=True)
    assert res.returncode == 0 and "bottom-front-left" in res.stdout and "builtin:NAME" in res.stdout


def test_blocks_lists_builtins(capsys):
    assert main(["blocks"]) == 0
    out = capsys.readouterr().out
    assert "builtin:flat-sawn" in out and "builtin:knotty" in out


def test_a_closed_output_pipe_ends_quietly_but_write_errors_are_said(tmp_path, capsys, monkeypatch):
    """``woodcam blocks | head``: the reader went away; the command stops as git and ls do
    (exit 141, not a word) -- it printed 'woodcam: error: Broken pipe; check the path, its
    permissions and the free space', exit 1."""
    import os

    read_end, write_end = os.pipe()
    os.close(read_end)  # the reader is gone before the first line: every write is EPIPE
    try:
        res = subprocess.run([sys.executable, "-m", "woodcam.cli", "blocks"], cwd=REPO,
                             stdout=write_end, stderr=subprocess.PIPE, text=True, timeout=120)
    finally:
        os.close(write_end)
    assert (res.returncode, res.stderr) == (141, ""), res.stderr  # 128 + SIGPIPE, as git and ls
    # a real write error on stdout is still one line and exit 1
    if os.path.exists("/dev/full"):
        with open("/dev/full", "w") as full:
            res = subprocess.run([sys.executable, "-m", "woodcam.cli", "blocks"], cwd=REPO,
                                 stdout=full, stderr=subprocess.PIPE, text=True, timeout=120)
        assert res.returncode == 1 and "No space left on device" in res.stderr, res.stderr
    # a broken pipe that is not stdout's (a worker process that died) is an error, not quiet
    import woodcam.cli.bake as bake_cli

    def worker_died(args):
        raise BrokenPipeError(32, "Broken pipe")

    monkeypatch.setattr(bake_cli, "run_blocks", worker_died)
    assert main(["blocks"]) == 1
    assert "woodcam: error: Broken pipe" in capsys.readouterr().err


def test_a_part_sticking_out_is_said_in_the_report_files(tmp_path, capsys):
    """'part sticks out of the block' went to stderr only: the report files kept no trace of it."""
    import json

    import trimesh

    from woodcam.cli import main

    box = trimesh.creation.box((40, 40, 40))
    box.apply_translation((95, 40, 20))  # the flat-sawn block is 100 mm wide: 15 mm stick out
    box.export(tmp_path / "box.stl")
    assert main(["bake", str(tmp_path / "box.stl"), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "b.glb"),
                 "--no-obj", "--texels-per-mm", "1"]) == 0
    said = json.loads((tmp_path / "b_report.json").read_text())["warnings"]
    assert any(w.startswith("part sticks out of the block") for w in said)
    assert "warning: part sticks out of the block" in (tmp_path / "b_report.txt").read_text()
    # sweep h5 item 9: the review page had block, spec, species and texels only
    assert main(["review", str(tmp_path / "b.glb"), "--out", str(tmp_path / "b.html"), "--voxels", "1000"]) == 0
    page = (tmp_path / "b.html").read_text()
    assert "<th>warning 1</th><td>part sticks out of the block" in page
    assert re.search(r"<th>part</th><td>\d+ mm\^3, yield [\d.]+ % of the block", page)


def test_a_rerun_removes_the_earlier_runs_outputs_it_does_not_write_again(tmp_path, capsys):
    """A rerun without --screenshot left NAME_view.png of the earlier run beside the new GLB,
    passing for a view of it. Now each run lists the files it wrote for the GLB
    (.woodcam-NAME.glb-files.json) and a rerun removes the listed ones it does not write again,
    naming each; never a file no run listed, nor an input of the run."""
    box = trimesh.creation.box((20, 20, 20))
    box.apply_translation((50, 40, 25))
    box.export(tmp_path / "box.stl")
    mine = tmp_path / "b_deviation.png"  # the user's, named like an output: no run wrote it
    mine.write_bytes(b"not woodcam's")
    bake = ["bake", "--block", "builtin:flat-sawn", "--out", str(tmp_path / "b.glb"), "--texels-per-mm", "1"]
    assert main([*bake, str(tmp_path / "box.stl"), "--screenshot"]) == 0
    first = {p.name for p in tmp_path.iterdir()}
    assert {"b.glb", "b.obj", "b.mtl", "b_texture.png", "b_report.txt", "b_view.png"} <= first
    capsys.readouterr()
    # the earlier run's OBJ is this run's part: it and its MTL and texture stay; the view goes
    assert main([*bake, str(tmp_path / "b.obj"), "--no-obj"]) == 0
    err = capsys.readouterr().err
    assert re.search(r"warning: removed 1 file\(s\) of an earlier run .*: b_view.png$", err, re.M), err
    assert {p.name for p in tmp_path.iterdir()} == first - {"b_view.png"}
    # a run that neither writes nor reads the OBJ set removes it: it is still the first run's
    assert main([*bake, str(tmp_path / "box.stl"), "--no-obj"]) == 0
    assert re.search(r"removed 3 file\(s\) .*: b.obj, b.mtl, b_texture.png$", capsys.readouterr().err, re.M)
    assert {p.name for p in tmp_path.iterdir()} == first - {"b_view.png", "b.obj", "b.mtl", "b_texture.png"}
    assert mine.read_bytes() == b"not woodcam's"


def test_bake_draws_one_stage_bar_over_the_whole_run(tmp_path, bars, capsys):
    """Sweep h5 item 7: 20 s of bake drew nothing (only the rasterise chunks had a bar, each
    shorter than its 2 s delay); opening the block (a fit: minutes) had none either."""
    box = trimesh.creation.box((20, 20, 20))
    box.apply_translation((50, 40, 25))
    box.export(tmp_path / "box.stl")
    assert main(["bake", str(tmp_path / "box.stl"), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "b.glb"),
                 "--no-obj", "--texels-per-mm", "1", "--screenshot"]) == 0
    stage = [b for b in bars if b.unit == "stage"]
    assert len(stage) == 1 and stage[0].desc == "bake b" and stage[0].enabled
    plan = ["load", "open block", "carve", "bake", "report", "export", "render"]  # the part before the block
    assert stage[0].total == len(plan) and stage[0].n == len(plan) and stage[0].closed
    assert [d.split(": ")[-1] for d in stage[0].shown[1:-1]] == plan


def test_meshing_options_on_a_mesh_part_are_said_to_be_ignored(tmp_path, capsys):
    """--tolerance only meshes B-rep parts; on an STL it did nothing, without a word.
    --max-triangles bounds a mesh too: under it, nothing is said."""
    import trimesh

    from woodcam.cli import main

    box = trimesh.creation.box((20, 20, 20))
    box.apply_translation((50, 40, 25))
    box.export(tmp_path / "box.stl")
    argv = ["bake", str(tmp_path / "box.stl"), "--block", "builtin:flat-sawn", "--no-obj",
            "--texels-per-mm", "1"]
    assert main([*argv, "--out", str(tmp_path / "a.glb"), "--max-triangles", "1000",
                 "--tolerance", "0.5"]) == 0
    err = capsys.readouterr().err
    assert "--tolerance sets how B-rep parts" in err and "--max-triangles" not in err.split("ignored")[0]
    assert "box.stl is a triangle mesh, baked as it is: ignored" in err and "simplified" not in err
    assert main([*argv, "--out", str(tmp_path / "b.glb")]) == 0
    assert "ignored" not in capsys.readouterr().err


def test_max_triangles_simplifies_a_mesh_part_over_it(tmp_path, capsys):
    """A 1.3 M-triangle STL baked in ~100 s and 3.5 GB: --max-triangles bounded B-rep parts
    only. A mesh over it is simplified (manifold3d), a warning giving both counts and the
    tolerance; a mesh within it is baked as it is. (An icosphere of 5120 triangles against a
    budget of 1000 stands for the big one.)"""
    import json

    sphere = trimesh.creation.icosphere(subdivisions=4, radius=15.0)
    sphere.apply_translation((50, 40, 25))
    part = tmp_path / "ball.stl"
    sphere.export(part)
    argv = ["bake", str(part), "--block", "builtin:flat-sawn", "--no-obj", "--texels-per-mm", "1"]
    assert main([*argv, "--out", str(tmp_path / "a.glb"), "--max-triangles", "1000"]) == 0
    out, err = capsys.readouterr()
    said = re.search(r"ball\.stl': 5120 triangles exceeded max_triangles=1000 \(--max-triangles\); simplified to "
                     r"(\d+) triangles, surfaces moved by less than ([\d.]+) mm \(raise --max-triangles to keep more\)",
                     err)
    assert said and err.count("\n") == 1, err
    made = int(said.group(1))
    assert 100 < made <= 1000 and float(said.group(2)) < 1.0, err
    # the summary says it beside the count, as it says how a B-rep part was meshed
    assert out.startswith(f"a: {made} triangles (simplified from 5120 within {said.group(2)} mm; budget 1000 "
                          "triangles), "), out
    report = json.loads((tmp_path / "a_report.json").read_text())
    assert any("simplified to" in w for w in report["warnings"])
    from woodcam.cad import load_part
    from woodcam.errors import WoodcamWarning

    report: dict = {}
    solid = load_part(sphere, max_triangles=1000, report=report)  # the part baked: its shape kept
    assert solid.num_tri() == report["simplified"]["to"] <= 1000 and report["simplified"]["from"] == 5120
    assert abs(solid.volume() / sphere.volume - 1) < 0.035  # 2.8 %: 1000 triangles of a 30 mm ball
    with pytest.warns(WoodcamWarning, match="5120 triangles exceeded max_triangles=1000 .* simplified to"):
        load_part(sphere, max_triangles=1000)  # no report to fill (woodcam place, woodify): a warning
    assert main([*argv, "--out", str(tmp_path / "b.glb"), "--max-triangles", "6000"]) == 0
    assert "simplified" not in capsys.readouterr().err


def test_place_takes_the_triangle_budget_its_warning_names(tmp_path, capsys):
    """'woodcam place' loaded a mesh over the default budget simplified, with a warning saying
    'raise --max-triangles', an option place did not have: it has bake's now, the same help."""
    from woodcam.cli import build_parser

    commands = {name: p for a in build_parser()._actions if hasattr(a, "choices") and isinstance(a.choices, dict)
                for name, p in a.choices.items()}
    helps = {name: next(a.help for a in commands[name]._actions if a.dest == "max_triangles")
             for name in ("bake", "place")}
    assert helps["bake"] == helps["place"] and "mesh part" in helps["place"]
    sphere = trimesh.creation.icosphere(subdivisions=4, radius=15.0)
    sphere.apply_translation((50, 40, 25))
    part = tmp_path / "ball.stl"
    sphere.export(part)
    argv = ["place", str(part), "--block", "builtin:flat-sawn", "--candidates", "1", "--rotations", "none", "--quiet"]
    assert main([*argv, "--out", str(tmp_path / "a"), "--max-triangles", "1000"]) == 0
    assert "5120 triangles exceeded max_triangles=1000 (--max-triangles); simplified to" in capsys.readouterr().err
    assert main([*argv, "--out", str(tmp_path / "b")]) == 0
    assert "simplified" not in capsys.readouterr().err


def test_gcode_passes_its_budget_to_the_design_part(tmp_path, monkeypatch, capsys):
    """'woodcam gcode --part design.stl' loads the design with load_part's budget, whose warning
    says 'raise --max-triangles': gcode takes it for --part now, and passes it on."""
    import woodcam.cad as cad
    from woodcam.errors import WoodcamError

    seen = []

    def load_part(path, **kw):
        seen.append(kw)
        raise WoodcamError("stop here")

    monkeypatch.setattr(cad, "load_part", load_part)
    part = tmp_path / "design.stl"
    trimesh.creation.box((10.0, 10.0, 10.0)).export(part)
    argv = ["gcode", "toolpaths/drilling.nc", "--block", "builtin:flat-sawn", "--tool", "1=flat:6",
            "--part", str(part), "--out", str(tmp_path / "g.glb")]
    monkeypatch.chdir(Path(__file__).resolve().parents[1])
    assert main([*argv, "--max-triangles", "5000"]) == 1
    assert main(argv) == 1
    assert seen == [{"max_triangles": 5000}, {}]
    assert "--part: stop here" in capsys.readouterr().err


def test_a_mesh_part_that_cannot_be_simplified_to_the_budget_is_refused(capsys):
    """Forty separate 1 mm boxes (480 triangles) cannot be simplified to 100 triangles: within 1 %
    of the diagonal they vanish. One line names --max-triangles, the counts and the fix."""
    from woodcam.cad import load_part
    from woodcam.errors import WoodcamError

    boxes = trimesh.util.concatenate([trimesh.creation.box((1, 1, 1)).apply_translation((3 * i, 0, 0))
                                      for i in range(40)])
    with pytest.raises(WoodcamError, match=r"the part has 480 triangles, over max_triangles \(--max-triangles\) = "
                       r"100, and simplifying it by up to 1.18 mm \(1 % of its diagonal at most\) left 0 and lost 40 of its 40 "
                       r"bodies; raise --max-triangles to 480 to bake it whole, or simplify it in your CAD program$"):
        load_part(boxes, max_triangles=100)
    report: dict = {}
    assert load_part(boxes, max_triangles=480, report=report).num_tri() == 480 and report["simplified"] is None


def test_a_part_in_inches_gets_each_commands_own_fix(tmp_path, capsys, monkeypatch):
    """The warning of a part in inches told `woodcam place` (no --place option) and library
    callers of carve() to 'add --place scale:25.4 --place center': each caller says its own."""
    part = tmp_path / "tray_inches.stl"
    trimesh.creation.box((3.0, 2.0, 0.5)).apply_translation((50, 40, 25)).export(part)
    assert main(["bake", str(part), "--block", "builtin:knotty", "--out", str(tmp_path / "t.glb"),
                 "--texels-per-mm", "2", "--no-obj"]) == 0
    err = capsys.readouterr().err
    assert "25.4 times larger it would still fit" in err
    assert "if it was modelled in inches add --place scale:25.4 --place center (in metres: scale:1000)" in err
    assert main(["place", str(part), "--block", "builtin:knotty", "--candidates", "8", "--top", "1",
                 "--out", str(tmp_path / "place")]) == 0
    err = capsys.readouterr().err
    assert "if it was modelled in inches scale the part file by 25.4 in your CAD program" in err
    assert "--place" not in err
    # a script's lengths, and a STEP file's, are not 'STL, OBJ and PLY': each says its own
    script = tmp_path / "tray_inches.py"
    script.write_text("import trimesh\npart = trimesh.creation.box((3.0, 2.0, 0.5))"
                      ".apply_translation((50, 40, 25))\n")
    assert main(["place", str(script), "--block", "builtin:knotty", "--candidates", "8", "--top", "1",
                 "--out", str(tmp_path / "place")]) == 0
    err = capsys.readouterr().err
    assert "Lengths in a part script or a build123d/cadquery shape carry no units" in err, err
    assert "STL" not in err and "or write its lengths in mm" in err, err
    assert main(["bake", str(script), "--block", "builtin:knotty", "--out", str(tmp_path / "t.glb"),
                 "--texels-per-mm", "2", "--no-obj"]) == 0
    err = capsys.readouterr().err
    assert "Lengths in a part script" in err and "STL" not in err, err


@pytest.mark.parametrize("command, out", [("place", "place"), ("bake", "t.glb")])
def test_a_broken_part_is_said_before_the_block_opens(command, out, tmp_path, capsys, monkeypatch):
    """`woodcam place` and `woodcam bake` opened the block (a Mokume sample's or a photographed
    block's ring fit: minutes) before they ran the part script, so a typo in it was said after
    the wait. The part is loaded first."""
    import woodcam.stock

    def no_block(*args, **kwargs):
        raise AssertionError("the block was opened before the part was loaded")

    monkeypatch.setattr(woodcam.stock, "open_stock", no_block)
    part = tmp_path / "typo.py"
    part.write_text("part = Bx(10, 10, 10)\n")
    assert main([command, str(part), "--block", "builtin:knotty", "--out", str(tmp_path / out)]) == 1
    err = capsys.readouterr().err
    assert err.startswith("woodcam: error: part script") and "NameError: name 'Bx' is not defined" in err, err


def test_place_names_the_part_that_fits_nowhere_and_the_fix(tmp_path, capsys):
    """`woodcam place`'s error of a part that fits the block in no orientation began
    'advise_placement:' (a Python function) and did not name the part file. It names PART as
    typed and says the fix; the library's message keeps its function name."""
    from woodcam import open_stock
    from woodcam.advise import advise_placement
    from woodcam.errors import WoodcamError

    long = trimesh.creation.box((300, 20, 20)).apply_translation((50, 40, 25))
    part = tmp_path / "long.stl"
    long.export(part)
    assert main(["place", str(part), "--block", "builtin:knotty", "--out", str(tmp_path / "place")]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"woodcam: error: part {str(part)!r} (300.0x20.0x20.0 mm) fits the 100x80x50 mm "
                          "block in none of the 'z90' orientations"), err
    assert "advise_placement" not in err and "a bigger block (at least 302x80x50 mm" in err, err
    with pytest.raises(WoodcamError, match=r"^advise_placement: the part \(300"):
        advise_placement(long, open_stock("builtin:knotty"))


def test_bake_loads_its_part_once(tmp_path, monkeypatch):
    """Loaded before the block opens (test_a_broken_part_is_said_before_the_block_opens), the
    part is not loaded again to be carved."""
    import woodcam.cad

    loads = []
    load_part = woodcam.cad.load_part

    def counted(*args, **kwargs):
        loads.append(args[0])
        return load_part(*args, **kwargs)

    monkeypatch.setattr(woodcam.cad, "load_part", counted)
    box = tmp_path / "box.stl"
    trimesh.creation.box((20, 20, 20)).apply_translation((50, 40, 25)).export(box)
    assert main(["bake", str(box), "--block", "builtin:knotty", "--out", str(tmp_path / "b.glb"),
                 "--texels-per-mm", "1", "--no-obj", "--place", "center"]) == 0
    assert loads == [str(box)]  # loaded once, then carved as a manifold


def test_place_bounds_a_part_script_with_timeout_as_bake_does(tmp_path, capsys):
    """`woodcam place` runs the same trusted part scripts as bake but had no --timeout: a
    script stuck in a loop hung it."""
    part = tmp_path / "loops.py"
    part.write_text("while True:\n    pass\n")
    assert main(["place", str(part), "--block", "builtin:flat-sawn", "--timeout", "0.5",
                 "--out", str(tmp_path / "place")]) == 1
    err = capsys.readouterr().err
    assert err.startswith("woodcam: error: loading the part") and "took longer than the timeout of 0.5 s" in err, err


def test_a_no_obj_rerun_removes_the_earlier_runs_obj_but_never_an_input_or_a_foreign_obj(tmp_path, capsys):
    """Rerunning `bake --no-obj` into a folder left the earlier run's OBJ + MTL + PNG beside the
    new GLB, where they passed for the new part. They go (named in a warning); a baked OBJ
    given as the part, or an OBJ another program wrote, stays."""
    box = trimesh.creation.box((20, 20, 20))
    box.apply_translation((50, 40, 25))
    box.export(tmp_path / "box.stl")
    out = tmp_path / "a.glb"
    bake = ["bake", str(tmp_path / "box.stl"), "--block", "builtin:flat-sawn", "--out", str(out),
            "--texels-per-mm", "1"]
    assert main(bake) == 0
    trio = [tmp_path / n for n in ("a.obj", "a.mtl", "a_texture.png")]
    assert all(p.is_file() for p in trio)
    capsys.readouterr()
    # the earlier OBJ is this run's part: kept whole
    assert main(["bake", str(trio[0]), *bake[2:], "--no-obj"]) == 0
    assert all(p.is_file() for p in trio) and "removed" not in capsys.readouterr().err
    assert main([*bake, "--no-obj"]) == 0
    assert not any(p.exists() for p in trio)
    assert "removed 3 file(s) of an earlier run" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == [".woodcam-a.glb-files.json", "a.glb", "a_report.json",
                                                          "a_report.txt", "box.stl"]
    box.export(trio[0])  # trimesh's OBJ, not woodcam's: not ours to remove
    assert main([*bake, "--no-obj"]) == 0
    assert trio[0].is_file() and "removed" not in capsys.readouterr().err


def test_an_interrupted_export_leaves_the_earlier_runs_report_with_its_glb(tmp_path, capsys, monkeypatch):
    """The part report was written before the GLB, on its own: Ctrl-C during the export left
    this run's report (another block's yield, grain, knots) beside the previous run's GLB. The
    report is now part of the export's set."""
    import woodcam.export as export

    trimesh.creation.box((20, 20, 20)).apply_translation((50, 40, 25)).export(tmp_path / "box.stl")
    out = tmp_path / "out"
    argv = ["bake", str(tmp_path / "box.stl"), "--out", str(out / "p.glb"), "--texels-per-mm", "1"]
    assert main([*argv, "--block", "builtin:flat-sawn"]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(export, "export_glb", interrupted)
    assert main([*argv, "--block", "builtin:rift"]) == 130
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before


def test_bake_refuses_a_missing_or_unreadable_part_before_the_block_is_opened(tmp_path, capsys, monkeypatch):
    """'bake nope.stl --block B' said the part was missing only after the block was opened (a
    photographed block's fit: 20-30 s the first time); a part of a suffix no reader takes, too."""
    import woodcam.stock

    opened = []
    monkeypatch.setattr(woodcam.stock, "open_stock", lambda *a, **k: opened.append(a))
    (tmp_path / "part.dwg").write_text("x")
    # a missing part, or one of a suffix no reader takes, is a wrong command line, refused at the
    # input door (exit 2; the suffix was the work failing, exit 1)
    for part, said, code in ((tmp_path / "nope.stl", f"PART of 'woodcam bake': {str(tmp_path / 'nope.stl')!r} "
                              "does not exist", 2),
                             (tmp_path / "part.dwg", f"PART of 'woodcam bake': {str(tmp_path / 'part.dwg')!r} "
                              "has suffix '.dwg', which it cannot read; it must end in .step", 2)):
        assert main(["bake", str(part), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "b.glb")]) == code
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and said in err, err
    assert opened == []


def test_a_ctrl_c_while_the_view_is_drawn_leaves_no_earlier_view_beside_the_new_glb(tmp_path, capsys, monkeypatch):
    """The GLB set lands before the view is drawn: a Ctrl-C while drawing (seconds) left the
    earlier run's NAME_view.png beside the new part's GLB, passing for its view. The earlier
    view is gone once the new GLB is in place; a PNG no run listed (the user's) is kept."""
    import woodcam.view as view

    def drawn(mesh, screenshot=None, **kw):
        screenshot.write_bytes(b"view of " + read_glb_metadata(mesh)["placement"]["ops"][0].encode())

    part = tmp_path / "p.stl"
    trimesh.creation.box((10.0, 10.0, 10.0)).apply_translation((20, 20, 20)).export(part)
    out, png = tmp_path / "b.glb", tmp_path / "b_view.png"
    base = ["bake", str(part), "--block", "builtin:flat-sawn", "--out", str(out), "--no-obj",
            "--texels-per-mm", "1", "--screenshot"]
    monkeypatch.setattr(view, "preview", drawn)
    assert main([*base, "--place", "drop"]) == 0 and png.read_bytes() == b"view of drop"

    def interrupted(mesh, **kw):
        raise KeyboardInterrupt

    monkeypatch.setattr(view, "preview", interrupted)
    assert main([*base, "--place", "center"]) == 130
    assert read_glb_metadata(out)["placement"]["ops"] == ["center"]  # the new part landed
    assert not png.exists()
    mine = tmp_path / "mine.png"
    mine.write_bytes(b"mine")
    assert main([*base[:-1], "--screenshot", str(mine), "--place", "center"]) == 130
    assert mine.read_bytes() == b"mine"


def test_a_failed_run_says_its_warnings_first_and_its_error_last(tmp_path, capsys):
    """A run that warned and then failed printed its warnings after the error line (a finally in
    woodcam.cli), so the last line a user saw, or a script read from standard error, was a
    warning, not why it failed. Now: the warnings in the order raised, then the one error line."""
    (tmp_path / "bad.stl").write_text("solid x\nendsolid x\n")
    argv = ["bake", str(tmp_path / "bad.stl"), "--block", "builtin:flat-sawn", "--out",
            str(tmp_path / "x.glb"), "--camera", "front", "--quiet"]
    assert main(argv) == 1
    lines = capsys.readouterr().err.strip().splitlines()
    assert [line.split(":")[1] for line in lines] == [" warning", " error"], lines
    assert lines[0].startswith("woodcam: warning: --camera front chooses the view of --screenshot")
    assert lines[-1].startswith("woodcam: error: mesh file ") and "contains no triangles" in lines[-1]


def test_confidence_of_a_block_with_no_fit_names_the_block_and_the_fix(tmp_path, capsys):
    """'preview --confidence' of a GLB baked from a built-in block said '--confidence needs a block
    whose field was fitted (...); pass --block', naming neither the block it got nor one to pass."""
    box = trimesh.creation.box((20, 20, 20))
    box.apply_translation((50, 40, 25))
    box.export(tmp_path / "box.stl")
    glb = tmp_path / "b.glb"
    assert main(["bake", str(tmp_path / "box.stl"), "--block", "builtin:flat-sawn", "--no-obj",
                 "--texels-per-mm", "1", "--quiet", "--out", str(glb)]) == 0
    capsys.readouterr()
    assert main(["preview", str(glb), "--confidence", "--screenshot", str(tmp_path / "b.png"), "--quiet"]) == 1
    err = capsys.readouterr().err
    assert err == ("woodcam: error: --confidence needs a block whose field was fitted (a block folder without a "
                   "true field, or a Mokume folder); got the block 'builtin:flat-sawn', whose field has no fit and "
                   "so no uncertainty; pass --block with such a block (e.g. --block ../shared/data/mokume/H11), "
                   "or leave --confidence out\n"), err


def test_screenshot_before_the_input_leaves_the_input_to_the_command(tmp_path, monkeypatch, capsys):
    """'woodcam preview --screenshot bowl.glb' (bake's part, gcode's program alike): --screenshot's
    optional PNG took the input, and the command said 'the following arguments are required:
    mesh' of a mesh typed. An existing file not named .png after --screenshot is the input, the
    PNG its default name; a name that is no file is still refused as no .png."""
    from pathlib import Path

    import woodcam.view as view
    from woodcam.cli import EXIT_USAGE

    shots = []
    monkeypatch.setattr(view, "preview", lambda mesh, screenshot=None, **kw: (
        shots.append(Path(screenshot).name), Path(screenshot).write_bytes(b"png")))
    part = tmp_path / "p.stl"
    trimesh.creation.box((10.0, 10.0, 10.0)).apply_translation((20, 20, 20)).export(part)
    assert main(["bake", "--screenshot", str(part), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "b.glb"),
                 "--no-obj", "--texels-per-mm", "1", "--quiet"]) == 0
    assert main(["preview", "--screenshot", str(tmp_path / "b.glb"), "--quiet"]) == 0
    assert shots == ["b_view.png", "b_view.png"] and (tmp_path / "b_view.png").is_file()
    capsys.readouterr()
    assert main(["preview", "--screenshot", str(tmp_path / "v.png"), str(tmp_path / "b.glb"), "--quiet"]) == 0
    assert shots[-1] == "v.png"
    assert main(["preview", "--screenshot", "view", str(tmp_path / "b.glb")]) == EXIT_USAGE
    assert "--screenshot of 'woodcam preview' is a FILE ending in .png; got 'view'" in capsys.readouterr().err


@pytest.mark.parametrize("argv, said", [
    (["logs", "render", "--real", "--out", "x"], "invalid choice: 'logs' (choose from "),
    (["log", "rendr", "--real", "--out", "x"], "invalid choice: 'rendr' (choose from 'render', 'maps', 'export')"),
    (["preview", "p.glb", "--camera", "isso"], "invalid choice: 'isso' (choose from 'iso', "),
])
def test_a_mistyped_command_or_choice_is_offered_the_nearest(argv, said, capsys):
    """'woodcam logs render ...' (the package is woodcam.logs) listed the eighteen commands and
    left 'log' to be found, though a mistyped option gets 'did you mean --out?' (sweep h4)."""
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    near = {"logs": "'log'", "rendr": "'render'", "isso": "'iso'"}[said.split("'")[1]]
    assert err.count("\n") == 1 and said in err and err.rstrip().endswith(f"; did you mean {near}? (see "
                                                                         f"'{err.split(':')[0]} --help')"), err


@pytest.mark.parametrize("blob, said", [
    (b"", "'{}' is empty (0 bytes)"),
    (b"glT", "'{}' is 3 bytes, too short to be a GLB file"),
    (b"PK\x03\x04" + b"\0" * 40, "'{}' is no glTF 2.0 binary (it starts b'PK\\x03\\x04', not b'glTF' version 2)"),
])
@pytest.mark.parametrize("argv", [["preview", "{}", "--screenshot", "{}.png"], ["review", "{}", "--out", "{}.html"]])
def test_a_glb_that_is_no_glb_is_named_at_the_door(tmp_path, capsys, blob, said, argv):
    """'woodcam preview notglb.glb' (3 bytes) said "read_glb_metadata: 'notglb.glb' is 3 bytes, ..."
    (a function's name the user never typed) and exited 1, after the work began: a file of
    another kind under the .glb suffix is refused at the door, naming the argument (exit 2, as
    a wrong suffix is); a GLB whose JSON is bad is still the reader's (exit 1)."""
    from woodcam.cli import EXIT_USAGE

    path = tmp_path / "part.glb"
    path.write_bytes(blob)
    assert main([a.format(path) for a in argv]) == EXIT_USAGE
    err = capsys.readouterr().err
    arg = "MESH of 'woodcam preview'" if argv[0] == "preview" else "PART of 'woodcam review'"
    assert err.count("\n") == 1 and err.startswith(f"woodcam: error: {arg}: {said.format(path)}; give a .glb "
                                                   "written by woodcam bake"), err
    assert "read_glb_metadata" not in err


def test_errors_name_what_the_user_typed_not_internal_names(tmp_path, capsys):
    """'woodcam log' said "required: log_command", 'woodcam bench report DIR' of a folder no run
    wrote "run_dir must be ..." (or out_dir), 'preview empty.stl' "mesh_or_path: the mesh has no
    faces": names of the code, not of what was typed."""
    from woodcam.cli import EXIT_ERROR

    with pytest.raises(SystemExit):
        main(["log"])
    assert "the following arguments are required: {render,maps,export}" in capsys.readouterr().err
    empty = tmp_path / "norun"
    empty.mkdir()
    assert main(["bench", "report", str(empty), "--out", str(tmp_path / "rep")]) == EXIT_ERROR
    err = capsys.readouterr().err
    assert f"run folder {str(empty)!r} has no run.json, so no bench run wrote it" in err and "run_dir" not in err
    from woodcam.errors import WoodcamError
    from woodcam.scale import read_records

    with pytest.raises(WoodcamError, match=r"^run folder '.*norun' has no records/ sub-folder, so no bench run"):
        read_records(empty)
    stl = tmp_path / "empty.stl"
    stl.write_bytes(b"solid x\nendsolid x\n")
    assert main(["preview", str(stl), "--screenshot", str(tmp_path / "v.png")]) == EXIT_ERROR
    err = capsys.readouterr().err
    assert f"mesh file {str(stl)!r} has no faces" in err and "mesh_or_path" not in err
