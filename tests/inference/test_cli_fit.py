"""``woodcam fit`` / ``woodcam eval rings`` through the CLI's parser (woodcam.cli.fit)."""

import re

import numpy as np
import pytest

from _eq79_blocks import make_block, random_field
from woodcam.cli import build_parser, main
from woodcam.block.io import write_block
from woodcam.errors import WoodcamError
from woodcam.fields import GridField
from woodcam.inference import bake


def _parse(argv):
    return build_parser().parse_args(argv)


def run(args):
    return args.func(args)


@pytest.fixture(scope="module")
def block_dir(tmp_path_factory):
    field = random_field(np.random.default_rng(104))
    block = make_block(field, px_per_mm=3)
    folder = tmp_path_factory.mktemp("blk") / "b0"
    write_block(block, folder)
    truth = bake(field, block.size_mm).save(folder.parent / "truth.npz")
    return folder, truth, field


def test_fit_writes_a_grid_field_close_to_the_truth(block_dir, tmp_path, capsys):
    folder, _, field = block_dir
    out = tmp_path / "f.npz"
    assert run(_parse(["fit", str(folder), "--method", "radial", "--out", str(out)])) == 0
    assert "wrote" in capsys.readouterr().out
    fit = GridField.load(out)
    p = np.random.default_rng(0).uniform(3, 47, (2000, 3))
    assert np.percentile(np.abs(fit(p) - field(p)), 99) < 0.1


def test_fit_makes_a_missing_out_folder(block_dir, tmp_path, capsys):
    """Every other FILE --out makes its missing folder; 'fit --out fits/f.npz' fitted, then failed
    with 'No such file or directory (fits/f.npz)'."""
    folder, _, _ = block_dir
    out = tmp_path / "fits" / "new" / "f.npz"
    assert main(["fit", str(folder), "--method", "radial", "--out", str(out)]) == 0
    assert GridField.load(out).years.size


def test_fit_writes_the_out_file_it_was_given_whatever_the_suffix_case(block_dir, tmp_path, capsys):
    """--out takes .npz in any case (check_out); the field was then written to 'f.NPZ.npz' (numpy's
    rule, case-sensitive) and the named file never appeared."""
    folder, _, _ = block_dir
    out = tmp_path / "f.NPZ"
    assert main(["fit", str(folder), "--method", "radial", "--out", str(out)]) == 0
    assert f"wrote {out} " in capsys.readouterr().out
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.NPZ"]
    assert GridField.load(out).years.size


def test_eval_writes_table_and_images(block_dir, tmp_path):
    folder, truth, _ = block_dir
    out = tmp_path / "ev"
    args = _parse(["eval", "rings", str(folder), "--truth", str(truth), "--methods", "radial",
                   "--partial-faces", "none", "--out", str(out)])
    assert run(args) == 0
    table = (out / "table.md").read_text()
    assert "radial matched 1 mm" in table
    assert len(list(out.glob("*.png"))) == 1


def test_eval_seed_on_blocks_with_a_truth_is_said_to_change_nothing(block_dir, tmp_path, capsys):
    """--seed seeds the held-out scoring of real blocks; on blocks with a true field it was
    accepted and ignored without a word."""
    folder, truth, _ = block_dir
    assert main(["eval", "rings", str(folder), "--truth", str(truth), "--methods", "radial",
                 "--partial-faces", "none", "--seed", "3", "--out", str(tmp_path / "ev")]) == 0
    assert "--seed 3 seeds the held-out scoring of real blocks only; eq79 have a true field" in capsys.readouterr().err


def test_eval_seed_without_the_evidence_method_is_said_to_change_nothing(tmp_path, capsys):
    """--seed seeds only the evidence fit (fit_block: other methods ignore it); with the default
    --methods rbf,radial a real block's scores were the same for every seed, without a word."""
    block = make_block(random_field(np.random.default_rng(104)), px_per_mm=3, traces=False, ring_map=True,
                       faces=("front", "top", "left"))
    block.true_field = None  # a real block: held-out scoring, where --seed is meant
    folder = tmp_path / "real"
    write_block(block, folder)
    assert main(["eval", "rings", str(folder), "--methods", "radial", "--seed", "4294967295",
                 "--out", str(tmp_path / "ev")]) == 0
    err = capsys.readouterr().err
    assert ("--seed 4294967295 acts on the evidence fit only, and --methods radial has none: it changes "
            "nothing; add evidence to --methods (e.g. --methods evidence,radial) or drop it") in err
    # --confidence draws the evidence fit's per-point confidence: no other fit carries one
    assert main(["eval", "rings", str(folder), "--methods", "radial", "--seed", "2", "--confidence",
                 "--out", str(tmp_path / "ev2")]) == 0
    assert ("--seed 2 and --confidence act on the evidence fit only, and --methods radial has none: they "
            "change nothing; add evidence to --methods (e.g. --methods evidence,radial) or drop them") in \
        capsys.readouterr().err


@pytest.mark.slow
def test_eval_confidence_overlay_and_summary(block_dir, tmp_path):
    """`eval rings --confidence` (issue 12 part 5): the evidence fit's confidence drawn under its
    lines, and the table summarises it for the evidence fit only (three faces traced: the
    unseen half of the block is less sure than the seen one)."""
    from PIL import Image

    folder, truth, _ = block_dir
    out = tmp_path / "conf"
    assert main(["eval", "rings", str(folder), "--truth", str(truth), "--methods", "radial,evidence",
                 "--partial-faces", "front,top,left", "--confidence", "--out", str(out)]) == 0
    table = (out / "table.md").read_text()
    assert "Confidence on the predicted ring lines" in table
    rows = [r for r in table.splitlines() if "| evidence |" in r and not r.startswith("| **mean**")]
    assert len(rows) == 2 and not any("| radial |" in r for r in table.splitlines() if "confiden" in r)
    full, partial = ([float(c) for c in r.strip("|").split("|")[2:4]] for r in rows)
    assert 0 <= partial[0] < full[0] <= 1  # mean confidence: three faces leave more unsure
    (png,) = out.glob("*_partial.png")
    img = np.asarray(Image.open(png).convert("RGB"), float) / 255
    # the red-yellow-green confidence image is under the evidence row: strongly red or green pixels
    assert np.mean((np.abs(img[..., 0] - img[..., 1]) > 0.4) & (img[..., 2] < 0.4)) > 0.01


def test_cli_errors(block_dir, tmp_path, capsys):
    folder, truth, _ = block_dir
    with pytest.raises(SystemExit):  # argparse's choices, before the block is read
        _parse(["fit", str(folder), "--method", "magic", "--out", str(tmp_path / "x.npz")])
    assert "--method: invalid choice: 'magic' (choose from 'evidence', 'rbf', 'radial', 'neural')" \
        in capsys.readouterr().err
    with pytest.raises(WoodcamError, match="--truth needs one field file per block"):
        run(_parse(["eval", "rings", str(folder), str(folder), "--truth", str(truth), "--out", str(tmp_path)]))
    with pytest.raises(WoodcamError, match="nor an existing folder"):
        run(_parse(["fit", str(tmp_path / "nowhere"), "--out", str(tmp_path / "x.npz")]))
    with pytest.raises(WoodcamError, match="--methods must be from"):
        run(_parse(["eval", "rings", str(folder), "--methods", "radial,magic", "--out", str(tmp_path)]))


def test_eval_without_truth_scores_faces_held_out(tmp_path, capsys):
    block = make_block(random_field(np.random.default_rng(104)), px_per_mm=3, traces=False, ring_map=True,
                       faces=("front", "top", "left"))
    block.true_field = None  # a real block: only its faces are known
    folder = tmp_path / "real"
    write_block(block, folder)
    out = tmp_path / "ev"
    assert main(["eval", str(folder), "--methods", "radial", "--out", str(out)]) == 0  # old form
    said = capsys.readouterr().out
    assert "no true field; scoring each face predicted from the others" in said
    # sweep h5 item 13: it printed the pattern '<block>_holdout.md and <block>_<method>.png'
    assert f"wrote {out / 'eq79_holdout.md'}, {out / 'eq79_radial.png'}" in said and "<block>" not in said
    table = (out / "eq79_holdout.md").read_text()
    assert "radial ridge ≤ 2 px" in table and "mean, held out" in table
    assert (out / "eq79_radial.png").exists()


def test_fit_workers_option_sets_the_fit_processes_and_keeps_the_field(block_dir, tmp_path, monkeypatch):
    """``woodcam fit --workers N``: the evidence fit on N processes (``$WOODCAM_WORKERS``) gives
    the field it gives on one, bit for bit; 0 is refused with one line."""
    from woodcam._parallel import WORKERS_ENV, fit_workers

    folder, _, _ = block_dir
    monkeypatch.delenv(WORKERS_ENV, raising=False)
    fields = []
    for n in ("1", "2"):
        out = tmp_path / f"w{n}.npz"
        assert main(["fit", str(folder), "--workers", n, "--out", str(out)]) == 0
        assert fit_workers() == int(n)
        fields.append(GridField.load(out))
    assert np.array_equal(fields[0].years, fields[1].years)
    assert fields[0].meta["chosen"] == fields[1].meta["chosen"]
    assert main(["fit", str(folder), "--workers", "0", "--out", str(tmp_path / "w0.npz")]) != 0


@pytest.mark.parametrize("method", ["radial", "rbf"])
def test_fit_workers_act_on_the_radial_and_rbf_fits(block_dir, tmp_path, monkeypatch, method):
    """``woodcam fit --method radial --workers N`` ran the pith search's descents and the grid
    bake on one process whatever N was (only the evidence fit read it): they now run on the fit's
    workers, and the field is the one-worker field bit for bit."""
    import woodcam._parallel as parallel

    folder, _, _ = block_dir
    asked: list = []
    share = parallel.share
    monkeypatch.setattr(parallel, "share", lambda tasks, here, workers: asked.append(workers) or share(tasks, here, workers))
    fields = []
    for n in ("1", "2"):
        monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / f"cache{n}"))  # each fits afresh
        asked.clear()
        assert main(["fit", str(folder), "--method", method, "--workers", n, "--out", str(tmp_path / f"{n}.npz")]) == 0
        assert set(asked) <= {int(n)} and (asked or n == "1"), (n, asked)  # one worker may fork nothing
        fields.append(GridField.load(tmp_path / f"{n}.npz"))
    assert np.array_equal(fields[0].years, fields[1].years)


def test_fit_workers_with_the_neural_method_is_said_to_change_nothing(block_dir, tmp_path, monkeypatch, capsys):
    """``fit --method neural --workers 4`` was accepted and changed nothing without a word (the
    net runs in one process: torch's thread pool is not safe to fork)."""
    import woodcam.stock

    def fitted_field(*args, **kwargs):
        raise SystemExit(0)  # the warning comes before the work: no fit (nor torch) is needed

    monkeypatch.setattr(woodcam.stock, "fitted_field", fitted_field)
    folder, _, _ = block_dir
    with pytest.raises(SystemExit):
        main(["fit", str(folder), "--method", "neural", "--workers", "4", "--out", str(tmp_path / "n.npz")])
    assert ("woodcam: warning: --workers 4 acts on the evidence, radial and rbf fits only, and --method neural "
            "runs in one process: it changes nothing; drop it or use another --method (e.g. --method radial)"
            ) in capsys.readouterr().err
    for method in ("neural", "radial"):  # without --workers, or with a method that uses them: no word
        with pytest.raises(SystemExit):
            main(["fit", str(folder), "--method", method, *(["--workers", "2"] if method == "radial" else []),
                  "--out", str(tmp_path / "n.npz")])
        assert "--workers" not in capsys.readouterr().err


def test_eval_methods_all_is_every_method(block_dir, tmp_path, monkeypatch):
    """``--methods all`` ran the default rbf,radial."""
    import woodcam.inference.evaluate as evaluate
    from woodcam.cli.fit import METHODS

    folder, truth, _ = block_dir
    asked = []

    def fake(blocks, methods, sets, **kw):
        asked.append(list(methods))
        return {"table": ""}

    monkeypatch.setattr(evaluate, "benchmark", fake)
    assert main(["eval", "rings", str(folder), "--truth", str(truth), "--methods", "all",
                 "--out", str(tmp_path)]) == 0
    assert main(["eval", "rings", str(folder), "--truth", str(truth), "--out", str(tmp_path)]) == 0
    assert asked == [list(METHODS), ["rbf", "radial"]]


def test_eval_outputs_land_as_one_set_and_a_rerun_removes_the_earlier_runs(block_dir, tmp_path,
                                                                            monkeypatch, capsys):
    """A Ctrl-C at 7 s left block_0000_full.png alone (the table is written last), and a rerun
    with fewer blocks left the earlier run's pictures beside the new table.md. Now the run's
    files land together (or none do) and the earlier run's files it does not write again go,
    named in a warning; only files a run listed (.woodcam-eval-files.json)."""
    import json
    import shutil

    import woodcam.inference.fit as fit

    folder, truth, _ = block_dir
    other = tmp_path / "b1"
    shutil.copytree(folder, other)
    meta = json.loads((other / "block.json").read_text())
    (other / "block.json").write_text(json.dumps({**meta, "name": "eq79b"}))
    out = tmp_path / "ev"
    out.mkdir()
    (out / "notes_full.png").write_bytes(b"mine")  # named like an output; no run wrote it
    ev = ["eval", "rings", "--methods", "radial", "--partial-faces", "none", "--out", str(out)]
    assert main([*ev, str(folder), str(other), "--truth", str(truth), str(truth)]) == 0
    both = {p.name: (p.stat().st_ino, p.read_bytes()) for p in out.iterdir()}
    assert {"eq79_full.png", "eq79b_full.png", "table.md", "notes_full.png"} <= set(both)
    real_fit, calls = fit.fit_block, []

    def interrupted_at_the_second_block(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real_fit(*args, **kwargs)

    monkeypatch.setattr(fit, "fit_block", interrupted_at_the_second_block)
    capsys.readouterr()
    assert main([*ev, str(other), str(folder), "--truth", str(truth), str(truth)]) == 130
    assert capsys.readouterr().err == "woodcam: interrupted\n"
    # eq79b_full.png was drawn before the Ctrl-C: nothing of the run landed (not even the same
    # bytes again: the same files, inode for inode), no temporary is left
    assert {p.name: (p.stat().st_ino, p.read_bytes()) for p in out.iterdir()} == both
    monkeypatch.setattr(fit, "fit_block", real_fit)
    assert main([*ev, str(folder), "--truth", str(truth)]) == 0
    assert re.search(r"warning: removed 1 file\(s\) of an earlier run .*: eq79b_full.png$",
                     capsys.readouterr().err, re.M)
    assert sorted(p.name for p in out.iterdir()) == [".woodcam-eval-files.json", "eq79_full.png",
                                                     "notes_full.png", "table.md"]
    assert "eq79b" not in (out / "table.md").read_text()


def test_eval_says_what_it_wrote_once_the_set_has_landed(block_dir, tmp_path, monkeypatch, capsys):
    """eval rings printed 'wrote DIR/table.md and cut-plane images' (and, per real block, its
    files) inside its set, before any of them was in place, and named the pictures by kind; eval
    appearance and eval realistic say it after the set has landed. Now one 'wrote' line after
    the set, naming each file it wrote (not the set's list file)."""
    import woodcam._atomic as atomic

    folder, truth, _ = block_dir
    out = tmp_path / "ev"
    said_before, real_remove = [], atomic.remove_stale

    def landing(*args, **kwargs):  # called once the set's files are renamed into place
        said_before.append(capsys.readouterr().out)
        return real_remove(*args, **kwargs)

    monkeypatch.setattr(atomic, "remove_stale", landing)
    assert main(["eval", "rings", str(folder), "--truth", str(truth), "--methods", "radial",
                 "--out", str(out)]) == 0
    assert len(said_before) == 1 and "wrote" not in said_before[0]
    wrote = [line for line in capsys.readouterr().out.splitlines() if line.startswith("wrote")]
    files = [out / "eq79_full.png", out / "eq79_partial.png", out / "table.md"]
    assert wrote == ["wrote " + ", ".join(map(str, files))]
    assert all(f.is_file() for f in files) and (out / ".woodcam-eval-files.json").is_file()


_SLOW_SHARE = """
import pathlib, sys, time
import woodcam.inference.evidence as evidence
from woodcam._parallel import share
from woodcam.cli import main

def slow_share(tasks, here, workers):
    # the held-out refits, each made 60 s long; this process' own piece says it started
    def mine():
        pathlib.Path(sys.argv[1]).write_text('sharing')
        time.sleep(60)
    return share([lambda: time.sleep(60) for _ in tasks], mine, 2)

evidence.share = slow_share
sys.exit(main(['fit', sys.argv[2], '--out', sys.argv[3]]))
"""


def test_ctrl_c_during_the_forked_refits_ends_the_fit_at_once(block_dir, tmp_path):
    """Sweep h3 item 3: a Ctrl-C while the fit's held-out refits ran in forks (woodcam._parallel.
    share) was seen, then the pool's shutdown waited for the forks to finish their refits (5-8 s
    on a real fit; here 60 s refits). Now the forks are killed: exit 130 within a fraction of the
    refits' time, one line, no file written. SIGINT goes to the woodcam process only, so its
    forks never see it."""
    import os
    import signal
    import subprocess
    import sys
    import time

    folder, _, _ = block_dir
    mark, out = tmp_path / "mark", tmp_path / "out"
    out.mkdir()
    # a cache of its own: fit reads the fitted-field cache, where an earlier run's fit of the
    # same block (the same content) would answer without any refit
    env = dict(os.environ, WOODCAM_WORKERS="2", WOODCAM_CACHE_DIR=str(tmp_path / "cache"))
    proc = subprocess.Popen([sys.executable, "-c", _SLOW_SHARE, str(mark), str(folder), str(out / "f.npz")],
                            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        t0 = time.perf_counter()
        while not mark.exists():
            assert proc.poll() is None and time.perf_counter() - t0 < 120, proc.stderr.read()
            time.sleep(0.05)
        time.sleep(0.5)  # the forks are at work
        os.kill(proc.pid, signal.SIGINT)
        t1 = time.perf_counter()
        err = proc.communicate(timeout=120)[1]
        waited = time.perf_counter() - t1
    finally:
        if proc.poll() is None:
            proc.kill()
    assert (proc.returncode, err) == (130, "woodcam: interrupted\n"), err[-2000:]
    assert waited < 0.25 * 60, waited  # not the forks' 60 s
    assert sorted(p.name for p in out.iterdir()) == []


def test_fit_draws_one_stage_bar_over_the_block_and_the_fit(block_dir, tmp_path, bars):
    """'woodcam fit' of H11 from its photos lasts 20-30 s (2 cores) and drew no bar, where 'bake'
    of the same block draws one over the same fit: it draws a stage bar naming the fit now."""
    folder, _, _ = block_dir
    assert main(["fit", str(folder), "--method", "radial", "--out", str(tmp_path / "f.npz")]) == 0
    [bar] = [b for b in bars if b.desc == "fit"]
    assert bar.enabled and bar.unit == "stage" and bar.total == 3
    assert bar.shown[1:4] == ["fit: open block", "fit: fit", "fit: write"]
    assert bar.n == 3 and bar.closed


def test_fit_reads_and_fills_the_fitted_field_cache_bake_uses(block_dir, tmp_path, monkeypatch, capsys):
    """``woodcam fit`` fitted on every run (a photographed block's evidence fit: ~30 s each time)
    and never filled the content-keyed cache bake and preview fit through
    (woodcam.stock.fitted_field), so bake then fitted the same block again. Now one fit for
    both, the same field; --faces is part of the key (another fit, cached too)."""
    import woodcam.inference as inference
    import woodcam.inference.fit as inference_fit
    from woodcam.block.io import read_block_folder
    from woodcam.stock import fitted_field

    folder, _, _ = block_dir
    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    real_fit, calls = inference_fit.fit_block, []

    def counted(*args, **kwargs):
        calls.append(kwargs.get("faces"))
        return real_fit(*args, **kwargs)

    monkeypatch.setattr(inference_fit, "fit_block", counted)  # where each caller finds it
    monkeypatch.setattr(inference, "fit_block", counted)
    fits = []
    for k in range(2):
        out = tmp_path / f"f{k}.npz"
        assert main(["fit", str(folder), "--method", "radial", "--out", str(out)]) == 0
        fits.append(GridField.load(out))
    assert calls == [None]  # the second run read the first one's fit
    np.testing.assert_array_equal(fits[0].years, fits[1].years)
    field = fitted_field(read_block_folder(folder), folder, "radial")  # what bake and preview open
    assert calls == [None]
    np.testing.assert_array_equal(field.years, fits[0].years)
    for k in range(2):
        assert main(["fit", str(folder), "--method", "radial", "--faces", "front,top",
                     "--out", str(tmp_path / f"p{k}.npz")]) == 0
    assert calls == [None, ["front", "top"]]
    assert not np.array_equal(GridField.load(tmp_path / "p0.npz").years, fits[0].years)
