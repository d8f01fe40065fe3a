"""Shared pytest fixtures: real-data location and small synthetic blocks."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[1]


def pytest_configure(config) -> None:
    """A suite started in the background of a script (``pytest ... &``) inherits SIGINT ignored,
    and woodcam keeps an ignored SIGINT ignored (as ``nohup`` asks): every Ctrl-C test then saw the
    command run on to exit 0 and failed, though a terminal's Ctrl-C works. The Ctrl-C tests stand
    for a terminal user, so the suite and the commands it starts get SIGINT back (a Python handler
    becomes the default action across exec); the ignored case has its own test in test_cli_doors."""
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


def shared_data_dir() -> Path:
    """``$WOODCAM_SHARED_DATA`` or ``<repo>/../shared/data``."""
    return Path(os.environ.get("WOODCAM_SHARED_DATA", REPO.parent / "shared" / "data"))


@pytest.fixture
def shared_data() -> Path:
    d = shared_data_dir()
    if not d.is_dir():
        pytest.skip(f"real reference data not found at {d} (set WOODCAM_SHARED_DATA)")
    return d


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)


@pytest.fixture(scope="session")
def gran1():
    """The CT-measured spruce log Gran_1 (skipped when the shared data is absent)."""
    from woodcam.logs.io import read_gran1
    from woodcam.logs.io import shared_data_dir as woodcam_shared_data_dir

    base = woodcam_shared_data_dir()
    if base is None or not (base / "trees" / "Gran_1_knots.json").is_file():
        pytest.skip("shared/data/trees (the CT-measured spruce log) is not available; "
                    "set WOODCAM_SHARED_DATA")
    return read_gran1(base / "trees")


class RecordedBar:
    """A stand-in for a tqdm bar: what :func:`woodcam._progress.progress_bar` was asked to draw
    (``desc``, ``total``, the descriptions it showed), whether it may be drawn at all
    (``enabled``: a bar made with ``enabled=False`` never shows, so a test of a bar asserts it)
    and how far it went (``n``)."""

    def __init__(self, iterable=None, *, desc, unit, enabled=True, **kwargs):
        self.iterable, self.desc, self.unit, self.enabled = iterable, desc, unit, enabled
        self.total = kwargs.get("total", len(iterable) if hasattr(iterable, "__len__") else None)
        self.n, self.shown, self.closed, self.disable = 0, [desc], False, not enabled

    def __iter__(self):
        for x in self.iterable:
            yield x
            self.n += 1

    def update(self, k=1):
        self.n += k

    def set_description_str(self, desc, refresh=True):
        self.shown.append(desc)

    def set_postfix(self, refresh=True, **values):
        pass

    def refresh(self):
        pass

    def close(self):
        self.closed = True


@pytest.fixture
def bars(monkeypatch) -> list[RecordedBar]:
    """Every progress bar the package makes in the test, recorded (:class:`RecordedBar`)."""
    import woodcam._progress

    made: list[RecordedBar] = []

    def record(iterable=None, **kwargs):
        made.append(RecordedBar(iterable, **kwargs))
        return made[-1]

    monkeypatch.setattr(woodcam._progress, "progress_bar", record)
    return made


def _glb_with(meta: dict, path: Path) -> Path:
    """A minimal GLB (no mesh) whose JSON chunk holds ``meta`` as woodcam's scene extras."""
    import json
    import struct

    body = json.dumps({"asset": {"version": "2.0"}, "scenes": [{"extras": {"woodcam": meta}}]})
    body = body.encode() + b" " * (-len(body) % 4)
    path.write_bytes(struct.pack("<III", 0x46546C67, 2, 20 + len(body))
                     + struct.pack("<II", len(body), 0x4E4F534A) + body)
    return path


@pytest.fixture
def glb_with():
    """``glb_with(meta, path) -> path``: a minimal GLB carrying only woodcam's metadata ``meta``
    (what ``stock_of_glb`` and ``preview`` read), for tests of the block a GLB names."""
    return _glb_with


def _glb_placed_twice(path: Path) -> Path:
    """A GLB of one 10 mm box (mesh "a") placed by two nodes, at x = 30 ("moved") and at the
    origin ("at_zero"): one mesh, two placements, as an exporter writes an instanced part."""
    import trimesh

    box = trimesh.creation.box((10.0, 10.0, 10.0))
    moved = np.eye(4)
    moved[0, 3] = 30.0
    scene = trimesh.Scene()
    scene.add_geometry(box, geom_name="a", node_name="moved", transform=moved)
    scene.graph.update(frame_to="at_zero", frame_from=scene.graph.base_frame, geometry="a",
                       matrix=np.eye(4))
    scene.export(path)
    return path


@pytest.fixture
def glb_placed_twice():
    """``glb_placed_twice(path) -> path``: writes :func:`_glb_placed_twice` (one box mesh placed
    at x = 0 and x = 30), for the readers that must take or refuse both placements."""
    return _glb_placed_twice


#: The Khronos glTF validator (npm package gltf-validator, which make test installs) and the
#: node script that runs it on one file.
_VALIDATOR_JS = REPO / "tests" / "_gltf_validate.js"
_NODE_MODULES = Path(os.environ.get("WOODCAM_NODE_MODULES", REPO / ".cache" / "node" / "node_modules"))


def _gltf_validate(path: Path) -> dict:
    node = shutil.which("node")
    if node is None:
        pytest.skip("node is not installed; the Khronos glTF validator runs on node")
    if not (_NODE_MODULES / "gltf-validator").is_dir():
        pytest.skip(
            f"npm package gltf-validator missing under {_NODE_MODULES}; install with "
            "npm install --prefix .cache/node gltf-validator (make test does)"
        )
    run = subprocess.run(
        [node, str(_VALIDATOR_JS), str(path)],
        capture_output=True, text=True, timeout=120,
        env={**os.environ, "NODE_PATH": str(_NODE_MODULES)},
    )
    assert run.returncode == 0, run.stderr
    return json.loads(run.stdout)


@pytest.fixture
def gltf_validate():
    """``gltf_validate(path) -> report``: the Khronos validator's JSON report of a glTF/GLB file
    (skips where node or the validator is missing)."""
    return _gltf_validate
