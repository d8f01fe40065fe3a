"""Installed like a library: the wheel carries the example parts and the review viewer, and
``woodcam demo`` runs from it outside the checkout (issue 17)."""

from __future__ import annotations

import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


def test_the_demo_finds_its_examples_inside_the_package():
    import woodcam
    from woodcam.demo import examples_dir

    d = examples_dir()
    assert d.parent == Path(woodcam.__file__).resolve().parent
    assert {"bowl.py", "tray.py", "lid.py"} <= {p.name for p in d.iterdir()}


@pytest.mark.slow  # builds a wheel and runs the demo from it (~2-3 min)
def test_the_wheel_runs_the_demo_outside_the_checkout(tmp_path):
    build = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps",
                            "--no-build-isolation", "-w", str(tmp_path / "dist"), str(REPO)],
                           capture_output=True, text=True, timeout=600)
    assert build.returncode == 0, build.stderr[-2000:]
    assert "deprecated" not in build.stderr.lower()
    (wheel,) = (tmp_path / "dist").glob("woodcam-*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    assert {"woodcam/examples/bowl.py", "woodcam/review/viewer.bundle.js", "woodcam/py.typed"} <= names
    target = tmp_path / "site"
    inst = subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "--target",
                           str(target), str(wheel)], capture_output=True, text=True, timeout=600)
    assert inst.returncode == 0, inst.stderr[-2000:]
    work = tmp_path / "elsewhere"
    work.mkdir()
    env = {**os.environ, "PYTHONPATH": str(target)}
    where = subprocess.run([sys.executable, "-c", "import woodcam; print(woodcam.__file__)"],
                           cwd=work, env=env, capture_output=True, text=True)
    assert where.stdout.startswith(str(target)), where.stdout  # the wheel, not the checkout
    demo = subprocess.run([sys.executable, "-m", "woodcam.cli", "demo", "--quick", "--out", "out"],
                          cwd=work, env=env, capture_output=True, text=True, timeout=1200)
    assert demo.returncode == 0, demo.stderr[-2000:]
    assert (work / "out" / "bowl.glb").is_file() and (work / "out" / "demo.png").is_file()
