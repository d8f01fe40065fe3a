"""``woodcam train gtf`` (woodcam.cli.train) through the CLI's parser."""

from __future__ import annotations

import csv

import pytest

pytest.importorskip("torch")

from woodcam.cli import build_parser  # noqa: E402
from woodcam.fields.neural import GTFSpec  # noqa: E402


def _parse(argv):
    return build_parser().parse_args(argv)


def test_train_gtf_cli_writes_spec_weights_log_and_resumes(tmp_path, capsys):
    spec = GTFSpec(n_fields=6, points_per_field=32, latent_dim=4, hidden=8, layers=2, n_harmonics=2,
                   batch_fields=3, batch_points=8, steps=30, checkpoint_every=10, log_every=10)
    spec_path = spec.save(tmp_path / "spec.json")
    out = tmp_path / "model"
    args = _parse(["train", "gtf", "--spec", str(spec_path), "--out", str(out), "--steps", "10"])
    assert args.func(args) == 0
    assert "trained 10 steps" in capsys.readouterr().out
    args = _parse(["train", "gtf", "--spec", str(spec_path), "--out", str(out)])
    assert args.func(args) == 0  # resumes from step 10 to the spec's 30
    assert "trained 30 steps" in capsys.readouterr().out
    assert GTFSpec.load(out / "gtf_spec.json") == spec
    assert (out / "gtf.pt").is_file()
    with open(out / "gtf_train_log.csv", newline="") as fh:
        assert [int(r["step"]) for r in csv.DictReader(fh)] == [10, 20, 30]


def test_train_rejects_unknown_model(tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        _parse(["train", "sdf", "--out", str(tmp_path)])
    assert exc.value.code == 2  # argparse's usage error, naming the bad choice and the good one
    assert "invalid choice: 'sdf'" in capsys.readouterr().err


def test_train_gtf_engine_checks_the_checkpoint_before_building_the_training_set(tmp_path, capsys):
    """With --engine the training shards (minutes) were built into OUT/trainset/ before the
    checkpoint of another spec refused the run."""
    from dataclasses import replace

    from woodcam.cli import EXIT_ERROR, main

    spec = GTFSpec(n_fields=6, points_per_field=32, latent_dim=4, hidden=8, layers=2, n_harmonics=2,
                   batch_fields=3, batch_points=8, steps=10, checkpoint_every=10, log_every=10)
    out = tmp_path / "model"
    assert main(["train", "gtf", "--spec", str(spec.save(tmp_path / "a.json")), "--out", str(out)]) == 0
    other = replace(spec, seed=3).save(tmp_path / "b.json")
    assert main(["train", "gtf", "--spec", str(other), "--out", str(out), "--engine", "local",
                 "--workers", "1"]) == EXIT_ERROR
    assert "was written for another spec" in capsys.readouterr().err
    assert not (out / "trainset").exists()
