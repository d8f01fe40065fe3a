"""The README's quick start runs as written, in order, and its outputs reload (issue 17)."""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


def _quick_start() -> list[str]:
    """The ``woodcam ...`` lines of the code block under '## Using it', comments removed."""
    text = (REPO / "README.md").read_text()
    section = text.split("## Using it", 1)[1].split("\n## ", 1)[0]
    block = re.search(r"```\n(.*?)```", section, re.S).group(1)
    return [line.split("  #")[0].strip() for line in block.splitlines()
            if line.startswith("woodcam ")]


def test_the_quick_start_lists_the_main_commands():
    commands = _quick_start()
    assert [c.split()[1] for c in commands][:3] == ["demo", "blocks", "bake"]


@pytest.mark.slow  # runs the demo and every quick-start command (~3-5 min)
def test_the_quick_start_runs_as_written(tmp_path):
    for name in ("cad_examples", "toolpaths"):
        (tmp_path / name).symlink_to(REPO / name)
    env = {**os.environ, "WOODCAM_CACHE_DIR": str(tmp_path / "cache")}
    for command in _quick_start():
        argv = shlex.split(command)
        if argv[1] == "preview" and "--screenshot" not in argv:
            continue  # opens a window: the next line renders the same view off screen
        run = subprocess.run([sys.executable, "-m", "woodcam.cli", *argv[1:]], cwd=tmp_path,
                             env=env, capture_output=True, text=True, timeout=1800)
        assert run.returncode == 0, f"{command}\n{run.stderr[-2000:]}"
    from woodcam.export import load_textured, read_glb_metadata

    glb = tmp_path / "out" / "bowl.glb"
    assert len(load_textured(glb).faces) > 1000
    assert read_glb_metadata(glb)["block"] == "builtin:flat-sawn"
    assert load_textured(tmp_path / "out" / "bowl.obj").visual.uv is not None
    assert (tmp_path / "out" / "bowl.png").is_file() and (tmp_path / "out" / "bowl_texture.png").is_file()
    assert (tmp_path / "out" / "bowl.html").stat().st_size > 1e6
    assert (tmp_path / "out" / "place" / "placements.png").is_file()
