"""The ``woodcam`` command as a package: one registration convention, a light ``--help``."""

import pkgutil
import subprocess
import sys
from pathlib import Path

import pytest

import woodcam.cli as cli
from woodcam.appearance.knots import KnotShading

REPO = Path(__file__).resolve().parents[1]
HEAVY = ("numpy", "scipy", "numba", "torch", "trimesh", "PIL", "pyvista", "cv2", "skimage")

#: A GLB's 12-byte header (magic, version 2, length): enough for the input door, which refuses a
#: .glb that is no glTF binary (an empty placeholder was let through before)
_GLB_HEADER = b"glTF\x02\x00\x00\x00\x0c\x00\x00\x00"


def test_help_imports_nothing_heavy():
    """``woodcam --help`` (every command registered) loads no numeric or CAD library."""
    code = ("import sys\nfrom woodcam.cli import main\ntry:\n    main(['--help'])\n"
            "except SystemExit:\n    pass\n"
            f"print(sorted({{m.split('.')[0] for m in sys.modules}} & set({HEAVY!r})))")
    res = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True,
                         env={"PYTHONPATH": str(REPO), "PATH": "/usr/bin:/bin"})
    assert res.returncode == 0, res.stderr
    assert "eval" in res.stdout and "gcode" in res.stdout
    assert res.stdout.strip().splitlines()[-1] == "[]"


def test_every_command_module_is_registered_once_and_lives_in_the_package():
    here = {m.name for m in pkgutil.iter_modules(cli.__path__) if m.name not in ("options", "__main__")}
    assert sorted(f"woodcam.cli.{n}" for n in here) == sorted(cli.COMMANDS)
    for name in cli.COMMANDS:
        assert callable(getattr(__import__(name, fromlist=["register"]), "register")), name


def test_fit_methods_match_the_fitters():
    from woodcam.cli.fit import METHODS
    from woodcam.inference.fit import METHODS as FITTERS

    assert tuple(METHODS) == tuple(FITTERS)


@pytest.mark.parametrize("argv, command, sub", [
    (["eval-appearance", "builtin:rift", "--out", "x"], "eval", "appearance"),
    (["eval", "some/folder", "--out", "x"], "eval", "rings"),
    (["eval", "rings", "some/folder", "--out", "x"], "eval", "rings"),
    (["eval", "appearance", "builtin:rift", "--out", "x"], "eval", "appearance"),
])
def test_old_spellings_reach_the_new_commands(argv, command, sub):
    parser = cli.build_parser()
    args = parser.parse_args(cli._apply_aliases(argv, parser))
    assert args.command == command and args.eval_command == sub


def test_bake_demo_and_gcode_share_the_bake_options():
    parser = cli.build_parser()
    common = ["--species", "walnut", "--knot-darkening", "0.2,0.4", "--no-obj"]
    runs = {"bake": ["bake", "p.py", "--block", "builtin:rift", "--out", "o.glb", *common],
            "demo": ["demo", *common],
            "gcode": ["gcode", "p.nc", "--block", "builtin:rift", "--out", "o.glb", *common]}
    for name, argv in runs.items():
        args = parser.parse_args(argv)
        assert cli.options.stock_options(args) == {
            "species": "walnut", "appearance": "colormap",
            "knots": KnotShading(alive_darkening=0.2, dead_darkening=0.4), "knot_lut": None}, name
        assert args.no_obj, name


def test_version_prints_the_package_version(capsys):
    from woodcam import __version__
    from woodcam.cli import main

    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out.strip() == f"woodcam {__version__}"


@pytest.mark.parametrize("module", ["woodcam", "woodcam.cli"])
def test_python_dash_m_runs_the_command(module):
    """``python -m woodcam`` said 'No module named woodcam.__main__'."""
    from woodcam import __version__

    res = subprocess.run([sys.executable, "-m", module, "--version"], cwd=REPO, capture_output=True,
                         text=True, timeout=120)
    assert res.returncode == 0 and res.stdout.strip() == f"woodcam {__version__}", res.stderr


def test_preview_takes_negative_vectors_and_view_flags():
    from woodcam.cli import build_parser

    args = build_parser().parse_args(["preview", "x.glb", "--cut-normal", "-1,0,0",
                                      "--cut-origin", "-14,5.5,3", "--camera", "top", "--no-cut"])
    assert args.cut_normal == (-1.0, 0.0, 0.0) and args.cut_origin == (-14.0, 5.5, 3.0)
    assert args.camera == "top" and args.no_cut
    with pytest.raises(SystemExit) as exc:
        build_parser().parse_args(["preview", "x.glb", "--cut-normal", "1,nan,0"])
    assert exc.value.code == 2


def test_preview_names_its_own_arguments_and_ignores_nothing_silently(tmp_path, monkeypatch, capsys):
    """preview of a missing file said 'mesh_or_path: no file at ...' and --cut-normal 0,0,0
    'cut_normal must be ...' (the viewer's parameters); --no-cut dropped --cut-origin and
    --cut-normal without a word."""
    import woodcam.view as view

    got = []
    monkeypatch.setattr(view, "preview", lambda mesh, **kw: got.append(kw))
    monkeypatch.setattr("woodcam.cli.options.stock_of_glb", lambda mesh, block, **kw: None)
    monkeypatch.setattr("woodcam.cli.options.recorded_block_size", lambda mesh: None)
    assert cli.main(["preview", str(tmp_path / "nope.glb"), "--screenshot"]) == 2  # the input door's
    assert f"MESH of 'woodcam preview': {str(tmp_path / 'nope.glb')!r} does not exist" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exc:
        cli.main(["preview", "x.glb", "--cut-normal", "0,0,0"])
    assert exc.value.code == 2
    assert "--cut-normal '0,0,0': a direction must not be zero" in capsys.readouterr().err
    glb = tmp_path / "part.glb"
    glb.write_bytes(_GLB_HEADER)  # the input door reads the GLB magic; preview is stubbed
    assert cli.main(["preview", str(glb), "--screenshot", "--no-cut", "--cut-origin", "1,2,3",
                     "--cut-normal", "0,0,1"]) == 0
    assert ("woodcam: warning: --cut-origin and --cut-normal place the cut plane, which --no-cut "
            "leaves out: ignored") in capsys.readouterr().err
    assert got[-1]["cut_plane"] is False
    assert cli.main(["preview", str(glb), "--screenshot", "--cut-origin", "1,2,3"]) == 0
    assert "warning" not in capsys.readouterr().err


def _commands():
    """{command: its argparse parser} for every sub-command (nested ones included)."""
    import argparse

    out, todo = {}, [("", cli.build_parser())]
    while todo:
        name, parser = todo.pop()
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                todo += [(f"{name} {sub}".strip(), p) for sub, p in action.choices.items()]
        out[name] = parser
    return out


def test_one_option_name_means_one_thing_across_commands():
    """Issue 17: '--resolution is mm in one command and a cell count in another'. Every
    --resolution is now a cell count (int); gcode's stock grid is --cell-size, a length (the old
    spelling still parses to it)."""
    seen = {}
    for name, parser in _commands().items():
        for action in parser._actions:
            if "--resolution" in action.option_strings and action.dest == "resolution":
                seen[name] = action.type
    assert seen and set(seen.values()) == {int}, seen
    gcode = _commands()["gcode"]
    base = ["p.nc", "--block", "builtin:flat-sawn", "--out", "o.glb"]
    assert gcode.parse_args([*base, "--resolution", "0.25"]).cell_size == 0.25
    assert gcode.parse_args([*base, "--cell-size", "0.5"]).cell_size == 0.5


def test_preview_screenshot_takes_an_optional_name_like_bake_and_gcode(tmp_path, monkeypatch):
    """``--screenshot`` alone names the PNG after the input (MESH_view.png), as in bake/gcode."""
    import woodcam.view as view

    got = []
    monkeypatch.setattr(view, "preview", lambda mesh, **kw: got.append(kw["screenshot"]))
    glb = tmp_path / "bowl.glb"
    glb.write_bytes(_GLB_HEADER)  # the input door reads the GLB magic; preview is stubbed
    monkeypatch.setattr("woodcam.cli.options.stock_of_glb", lambda mesh, block, **kw: None)
    assert cli.main(["preview", str(glb), "--screenshot"]) == 0
    assert cli.main(["preview", str(glb), "--screenshot", str(tmp_path / "x.png")]) == 0
    assert got == [tmp_path / "bowl_view.png", tmp_path / "x.png"]
    for name, parser in _commands().items():
        for action in parser._actions:
            if "--screenshot" in action.option_strings:
                assert action.nargs == "?", name


def test_a_second_run_in_one_process_prints_its_warnings_too(tmp_path, monkeypatch, capsys):
    """The record of printed warnings lived as long as the process: a second cli.main() (a
    notebook, a test, a script driving woodcam) printed none that the first had printed."""
    import woodcam.view as view

    monkeypatch.setattr(view, "preview", lambda mesh, **kw: None)
    monkeypatch.setattr("woodcam.cli.options.stock_of_glb", lambda mesh, block, **kw: None)
    monkeypatch.setattr("woodcam.cli.options.recorded_block_size", lambda mesh: None)
    glb = tmp_path / "part.glb"
    glb.write_bytes(_GLB_HEADER)  # the input door reads the GLB magic; preview is stubbed
    argv = ["preview", str(glb), "--screenshot", "--no-cut", "--cut-origin", "1,2,3"]
    for _ in range(2):
        assert cli.main(argv) == 0
        assert "woodcam: warning: --cut-origin places the cut plane" in capsys.readouterr().err


def test_camera_is_one_shared_option_and_bake_draws_the_one_asked(tmp_path, monkeypatch, capsys):
    """Sweep h13 item 3: preview offered bottom, gcode not (without a word why), bake had no
    --camera at all (its --screenshot always iso), and gcode's --camera without --screenshot was
    dropped silently. Now one option (options.add_camera_option, the views of woodcam._types):
    gcode's help says why it has no bottom; a --camera with nothing to draw warns."""
    import argparse

    import woodcam.pipeline
    import woodcam.view as view
    from woodcam._types import CAMERAS
    from woodcam.cli.options import write_screenshot

    choices, helps = {}, {}
    for name in ("bake", "preview", "gcode"):
        (action,) = [a for a in _commands()[name]._actions if "--camera" in a.option_strings]
        choices[name], helps[name] = tuple(action.choices), action.help
    assert choices["bake"] == choices["preview"] == CAMERAS
    assert choices["gcode"] == tuple(c for c in CAMERAS if c != "bottom")
    assert "No bottom: the simulated stock is a height field" in helps["gcode"]
    got = []
    monkeypatch.setattr(view, "preview", lambda mesh, **kw: got.append(kw["camera"]))
    for camera, drawn in (("bottom", "bottom"), (None, "iso")):
        args = argparse.Namespace(screenshot=True, out=str(tmp_path / "p.glb"), camera=camera)
        write_screenshot(args, {"glb": tmp_path / "p.glb"}, argparse.Namespace(wood=None, size_mm=(1, 1, 1)))
        assert got[-1] == drawn
    monkeypatch.setattr(woodcam.pipeline, "preview_heightfield",
                        lambda hm, stock, out, **kw: woodcam.pipeline.PartPreview("x", files={"glb": out}))
    prog = tmp_path / "slot.nc"
    prog.write_text("G21\nG0 X20 Y40 Z2\nG1 Z-3 F300\nX80\nG0 Z2\n")
    assert cli.main(["gcode", str(prog), "--block", "builtin:flat-sawn", "--tool", "flat:6", "--cell-size",
                     "1", "--out", str(tmp_path / "o.glb"), "--camera", "top"]) == 0
    assert ("woodcam: warning: --camera top chooses the view of --screenshot, which was not asked for: "
            "ignored; add --screenshot") in capsys.readouterr().err


def test_every_command_takes_quiet_and_it_stops_every_bar(monkeypatch):
    """'--quiet' (no progress bars) was an option of six commands; 'bake', 'gcode', 'woodify',
    'fit', 'review', 'place' and the others drew their bars with no way to turn them off on a
    terminal. Every command takes it, and it stops any bar its work draws."""
    import argparse
    import io

    import woodcam.cli.bake as bake_cli
    from woodcam._progress import progress_bar
    from woodcam.cli import _commands, build_parser, main

    lacking = [" ".join(path) for path, _help, sp in _commands(build_parser())
               if not any(isinstance(a, argparse._SubParsersAction) for a in sp._actions)
               and "--quiet" not in sp._option_string_actions]
    assert not lacking, lacking

    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    drawn = {}

    def command(args):  # work that draws a bar at once, as a long bake's does after 2 s
        drawn[args.quiet] = out = Terminal()
        for _ in progress_bar(range(3), desc="baking", unit="step", file=out, delay=0):
            pass
        return 0

    monkeypatch.setattr(bake_cli, "run_blocks", command)
    assert main(["blocks"]) == 0 and main(["blocks", "--quiet"]) == 0
    assert "baking" in drawn[False].getvalue() and drawn[True].getvalue() == ""


def test_faces_names_faces_and_eval_realistics_face_sets_say_so():
    """'fit --faces front,top' takes faces, 'eval realistic --faces full,three' took face sets:
    one option name, two meanings. eval realistic's is --face-sets (--faces still parses)."""
    by_faces = sorted(name for name, parser in _commands().items() for a in parser._actions
                      if a.option_strings[:1] == ["--faces"])
    assert by_faces == ["fit"], by_faces
    realistic = cli.build_parser().parse_args(["eval", "realistic", "--seed", "1", "--faces", "three",
                                               "--out", "o"])
    assert realistic.faces == "three"
    help_ = next(a.help for a in _commands()["eval realistic"]._actions if "--face-sets" in a.option_strings)
    assert "full (six faces), three (front, top, left)" in help_
