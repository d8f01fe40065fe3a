"""``woodcam gcode`` glue: argument handling up to the pipeline (the bake stage is stubbed)."""

from __future__ import annotations

from pathlib import Path

import pytest

import woodcam.pipeline
from woodcam.errors import WoodcamError
from woodcam.toolpath import BallEndMill, FlatEndMill, read_gcode
from woodcam.cli import build_parser
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


def test_run_simulates_and_hands_a_watertight_mesh_to_the_pipeline(tmp_path, monkeypatch,
                                                                   capsys):
    seen = {}

    def fake_preview_mesh(mesh, stock, out_glb, **kw):
        seen.update(mesh=mesh, stock=stock, meta=kw["metadata"])
        return woodcam.pipeline.PartPreview("x", files={"glb": Path(out_glb)})

    monkeypatch.setattr(woodcam.pipeline, "preview_mesh", fake_preview_mesh)
    prog = tmp_path / "slot.nc"
    prog.write_text("G0 X20 Y40 Z2\nG1 Z-3 F300\nX80\nG0 Z2\n")
    args = _parse([str(prog), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "o.glb"),
                   "--tool", "flat:6", "--resolution", "0.25"])
    assert args.func(args) == 0
    mesh = seen["mesh"]
    assert mesh.is_watertight
    W, D, H = seen["stock"].size_mm
    assert mesh.volume == pytest.approx(W * D * H - 3 * (60 * 6 + 3.14159265 * 9), rel=5e-3)
    assert seen["meta"]["tools"] == {"0": "flat:6"}
    assert "slot.nc: 3 moves" in capsys.readouterr().out


@pytest.mark.slow
def test_gcode_end_to_end_writes_a_baked_glb(tmp_path):
    from woodcam.export import read_glb_metadata

    prog = tmp_path / "slot.nc"
    prog.write_text("G0 X20 Y40 Z2\nG1 Z-3 F300\nX80\nG0 Z2\n")
    out = tmp_path / "slot.glb"
    args = _parse([str(prog), "--block", "builtin:flat-sawn", "--out", str(out), "--tool",
                   "ball:6", "--resolution", "0.25", "--texels-per-mm", "2", "--no-obj"])
    assert args.func(args) == 0
    meta = read_glb_metadata(out)
    assert meta["block"] == "builtin:flat-sawn" and meta["tools"] == {"0": "ball:6"}
