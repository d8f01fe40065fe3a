"""Nothing run that should not be: checkpoints are data, manifests stay in their folder, GLB
metadata never makes woodcam write anywhere, part scripts are documented as trusted code."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from woodcam.errors import WoodcamError

REPO = Path(__file__).resolve().parents[2]
TINY = {"n_fields": 8, "points_per_field": 64, "latent_dim": 4, "hidden": 16, "layers": 2,
        "n_harmonics": 3, "batch_fields": 4, "batch_points": 16, "steps": 20,
        "checkpoint_every": 10, "log_every": 10}


def test_no_unsafe_torch_load_anywhere():
    """Issue 15: `woodcam train gtf` resumed with torch.load(weights_only=False)."""
    offenders = []
    for p in (REPO / "woodcam").rglob("*.py"):
        for i, line in enumerate(p.read_text().splitlines(), 1):
            if "torch.load(" in line and "weights_only=True" not in line:
                offenders.append(f"{p.relative_to(REPO)}:{i}")
            if re.search(r"weights_only\s*=\s*False|pickle\.loads?\(|allow_pickle\s*=\s*True", line):
                offenders.append(f"{p.relative_to(REPO)}:{i}")
    assert offenders == []


class _Payload:
    """A pickle that runs a command when loaded with weights_only=False."""

    def __init__(self, marker: Path):
        self.marker = marker

    def __reduce__(self):
        return (subprocess.call, ([sys.executable, "-c", f"open({str(self.marker)!r}, 'w')"],))


def test_crafted_checkpoint_is_refused_and_not_run(tmp_path):
    torch = pytest.importorskip("torch")
    from woodcam.fields.neural import GTFSpec, train_gtf

    marker = tmp_path / "pwned"
    out = tmp_path / "run"
    out.mkdir()
    torch.save({"spec": GTFSpec(**TINY).to_dict(), "evil": _Payload(marker)},
               out / "gtf_checkpoint.pt")
    with pytest.raises(WoodcamError, match="refused, nothing in it was run"):
        train_gtf(GTFSpec(**TINY), out, progress=False)
    assert not marker.exists()


def test_checkpoint_of_plain_data_resumes(tmp_path):
    pytest.importorskip("torch")
    from woodcam.fields.neural import GTFSpec, train_gtf

    spec = GTFSpec(**TINY)
    train_gtf(spec, tmp_path, steps=10, progress=False)
    assert sorted(p.name for p in tmp_path.iterdir() if ".tmp" in p.name) == []
    res = train_gtf(spec, tmp_path, progress=False)  # resumes from step 10 with weights_only
    assert list(res["step"]) == [10, 20]


def test_glb_metadata_never_makes_preview_write(tmp_path, monkeypatch):
    """Issue 15: a crafted GLB named a folder in its metadata and `preview` fitted a field and
    wrote a cache into it. A GLB's block spec may only name a built-in or log block."""
    from woodcam.cli.bake import stock_from_glb_metadata

    victim = tmp_path / "victim"
    victim.mkdir()
    (victim / "block.json").write_text('{"format": "woodcam-block", "size_mm": [1, 1, 1]}')
    with pytest.raises(WoodcamError, match="names a folder"):
        stock_from_glb_metadata({"block": str(victim)}, "part.glb")
    assert sorted(p.name for p in victim.iterdir()) == ["block.json"]
    for bad in ({"block": 5}, {"block": ["builtin:flat-sawn"]}, {"block": "x" * 5000}):
        with pytest.raises(WoodcamError, match="metadata"):
            stock_from_glb_metadata(bad, "part.glb")
    assert stock_from_glb_metadata({}, "part.glb") is None
    assert stock_from_glb_metadata({"block": "builtin:flat-sawn"}, "part.glb").size_mm


@pytest.mark.parametrize("blob", [
    b"", b"glTF", b"glTF\x02\x00\x00\x00" + b"\x00" * 12,
    b"glTF\x02\x00\x00\x00\x20\x00\x00\x00\xff\xff\xff\x7fJSON",             # chunk longer than file
    b"glTF\x02\x00\x00\x00\x20\x00\x00\x00\x04\x00\x00\x00JSON\xff\xfe\x00\x01",  # not UTF-8
    b"glTF\x02\x00\x00\x00\x20\x00\x00\x00\x04\x00\x00\x00JSON[1,2",          # bad JSON
    b"glTF\x02\x00\x00\x00\x20\x00\x00\x00\x02\x00\x00\x00JSON[]",            # not an object
    b'glTF\x02\x00\x00\x00\x20\x00\x00\x00\x0e\x00\x00\x00JSON{"scenes": 5}',
    b'glTF\x02\x00\x00\x00\x20\x00\x00\x00\x17\x00\x00\x00JSON{"scenes":[],"scene":9}',
    b'glTF\x02\x00\x00\x00\x20\x00\x00\x00\x1b\x00\x00\x00JSON{"scenes":[{"extras":7}]}',
])
def test_malformed_glb_metadata_is_a_woodcam_error(tmp_path, blob):
    from woodcam.export import read_glb_metadata

    p = tmp_path / "bad.glb"
    p.write_bytes(blob)
    with pytest.raises(WoodcamError, match="read_glb_metadata"):
        read_glb_metadata(p)


def test_part_scripts_are_documented_as_trusted_code():
    readme = (REPO / "README.md").read_text()
    assert re.search(r"part scripts?.{0,200}trusted", readme, re.IGNORECASE | re.DOTALL)
    out = subprocess.run([sys.executable, "-m", "woodcam.cli", "bake", "--help"], check=True,
                         capture_output=True,
                         text=True, cwd=REPO, env={"PYTHONPATH": str(REPO), "PATH": "/usr/bin"})
    assert "trusted" in out.stdout and "--timeout" in out.stdout


def test_part_script_timeout(tmp_path):
    from woodcam.cad import load_part

    script = tmp_path / "endless.py"
    script.write_text("while True:\n    try:\n        pass\n    except Exception:\n        pass\n")
    with pytest.raises(WoodcamError, match="longer than the timeout of 0.3 s"):
        load_part(script, timeout_s=0.3)
    with pytest.raises(WoodcamError, match="timeout_s must be a finite number"):
        load_part(script, timeout_s=float("nan"))
