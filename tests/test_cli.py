"""The woodcam command end to end: demo, bake, preview, and clean one-line errors."""

import subprocess
import sys

import numpy as np
import pytest
import trimesh
from PIL import Image

from woodcam.cli import main
from woodcam.export import read_glb_metadata

REPO = __import__("pathlib").Path(__file__).resolve().parents[1]


def test_demo_quick_writes_every_output(tmp_path, capsys):
    assert main(["demo", "--out", str(tmp_path), "--quick"]) == 0
    out = capsys.readouterr().out
    for part in ("bowl", "tray", "lid"):
        for suffix in (".glb", ".obj", ".mtl", ".png", "_view.png"):
            f = tmp_path / f"{part}{suffix}"
            assert f.is_file() and f.stat().st_size > 0, f
        assert part in out
        view = np.asarray(Image.open(tmp_path / f"{part}_view.png").convert("RGB"))
        assert (np.abs(view.astype(int) - 255).sum(-1) > 30).mean() > 0.05  # not blank
    assert (tmp_path / "demo.png").is_file()
    for stage in ("load", "carve", "bake", "export", "render"):
        assert stage in out


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


@pytest.mark.parametrize("argv, message", [
    (["bake", "missing.py", "--block", "builtin:flat-sawn", "--out", "x.glb"], "missing.py"),
    (["bake", "cad_examples/tray.py", "--block", "builtin:oak-burl", "--out", "x.glb"],
     "unknown built-in block 'oak-burl'"),
    (["bake", "cad_examples/tray.py", "--block", "nowhere/", "--out", "x.glb"],
     "neither 'builtin:NAME'"),
])
def test_errors_are_one_clean_line(argv, message, tmp_path):
    res = subprocess.run([sys.executable, "-m", "woodcam.cli", *argv], cwd=REPO,
                         capture_output=True, text=True)
    assert res.returncode == 2
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("woodcam: error:") and message in lines[0]
    assert "Traceback" not in res.stderr


def test_help_explains_block_frame():
    res = subprocess.run([sys.executable, "-m", "woodcam.cli", "--help"], capture_output=True, text=True)
    assert res.returncode == 0 and "bottom-front-left" in res.stdout and "builtin:NAME" in res.stdout


def test_blocks_lists_builtins(capsys):
    assert main(["blocks"]) == 0
    out = capsys.readouterr().out
    assert "builtin:flat-sawn" in out and "builtin:knotty" in out
