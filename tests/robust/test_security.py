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


#: The one unpickling allowed, as (file, code): the bytes a forked worker of this process sent
#: back through the pool's pipe (``_parallel._run_forked``), which the pool would otherwise
#: unpickle itself; nothing read from a file or from anyone else.
_OWN_FORK_RESULT = ("woodcam/_parallel.py", "pickle.loads(got[1])")


def test_no_unsafe_torch_load_anywhere():
    """Issue 15: `woodcam train gtf` resumed with torch.load(weights_only=False). No pickle
    load anywhere but of this process' own forked workers' results (``_OWN_FORK_RESULT``)."""
    offenders = []
    for p in (REPO / "woodcam").rglob("*.py"):
        rel = str(p.relative_to(REPO))
        for i, line in enumerate(p.read_text().splitlines(), 1):
            if "torch.load(" in line and "weights_only=True" not in line:
                offenders.append(f"{rel}:{i}")
            if re.search(r"weights_only\s*=\s*False|pickle\.loads?\(|allow_pickle\s*=\s*True",
                         line.replace(_OWN_FORK_RESULT[1], "") if rel == _OWN_FORK_RESULT[0] else line):
                offenders.append(f"{rel}:{i}")
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


@pytest.mark.parametrize("meta, match", [
    ({"block": "builtin:rift", "appearance": {"kind": "neural", "params": {"cache_dir": "/tmp/x"}}},
     "params.cache_dir .* is not an accepted appearance parameter"),
    ({"block": "builtin:rift", "appearance": {"kind": "neural", "params": {"epochs": 10**9}}},
     "params.epochs .* out of range"),
    ({"block": "builtin:rift", "appearance": {"params": ["x"]}}, "params must be an object"),
    ({"block": ["builtin:rift"]}, "must be a string"),
])
def test_glb_metadata_cannot_choose_where_or_how_much(tmp_path, meta, match, glb_with):
    """Issue 15: a crafted GLB made `preview` fit and write a cache into a folder it names. A
    GLB's metadata may name its block and appearance, never a cache folder or unbounded work."""
    from woodcam.cli.options import stock_of_glb

    with pytest.raises(WoodcamError, match=match):
        stock_of_glb(glb_with(meta, tmp_path / "x.glb"))


def test_glb_naming_a_folder_never_writes_into_it(tmp_path, monkeypatch, glb_with):
    from woodcam.block.io import write_block
    from woodcam.cli.options import stock_of_glb
    from woodcam.fields.builtin import builtin_block
    from woodcam.synth import synth_block

    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    block = synth_block(builtin_block("flat-sawn").field, (30, 20, 10), face_px=32, seed=0)
    block.true_field = None
    victim = tmp_path / "victim"
    write_block(block, victim)
    before = {p: p.stat().st_mtime_ns for p in victim.rglob("*")}
    stock = stock_of_glb(glb_with({"block": str(victim)}, tmp_path / "x.glb"))
    assert stock.size_mm == (30.0, 20.0, 10.0)
    assert {p: p.stat().st_mtime_ns for p in victim.rglob("*")} == before
    assert list((tmp_path / "cache" / "fields").glob("*.npz"))


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
    # the file named, not the function (a command-line user read "read_glb_metadata: ..." of the
    # file they typed; sweep h9)
    with pytest.raises(WoodcamError, match=r"^GLB file '.*bad.glb' (is \d+ bytes, too short|is not a glTF 2.0 binary|has a malformed glTF JSON chunk)"):
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
