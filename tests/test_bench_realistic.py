"""woodcam.bench_realistic: the per-block scoring task of the ring benchmark and its summary."""

import json

import pytest

from woodcam.bench_realistic import bootstrap_ci, make_block, markdown, score_block, summarise
from woodcam.errors import WoodcamError
from woodcam.inference.evaluate import DEFAULT_PLANES


def test_score_block_is_plain_json_and_scores_the_sanity_row():
    row = score_block(3, 0, ("radial",), "clean", "full", kind="eq79", face_px=64,
                      planes=DEFAULT_PLANES[:2], pixel_mm=0.25)
    json.dumps(row)  # records must be plain JSON for a runner
    assert row["kind"] == "eq79" and row["faces"] == "full" and row["scenario"] == "clean"
    # an eq. 7-9 block with clean traces on six faces is the radial model's own family
    assert row["radial"]["matched_1"] > 95 and row["radial"]["fit_s"] > 0
    # the task is a pure function of (seed, index): the block is regenerated identically
    (a, _), (b, _) = make_block(3, 0, "clean", "eq79", 32), make_block(3, 0, "clean", "eq79", 32)
    assert a.faces["front"].traces[0].year == b.faces["front"].traces[0].year
    assert (a.faces["front"].traces[0].points_px == b.faces["front"].traces[0].points_px).all()
    rows = [row, dict(row, name="other", radial=dict(row["radial"], matched_2=50.0))]
    (g,) = summarise(rows, ["radial"])
    assert g["n"] == 2 and g["radial"]["matched_2_worst"] == 50.0
    assert g["radial"]["matched_2_worst_block"] == "other"
    assert "| clean | full | eq79 | 2 |" in markdown([g], ["radial"])


def test_worst_cell_names_the_block_of_each_value():
    """Block a is the worst within 1 mm, block b within 2 mm: the cell said '50.0 / 80.0 (b)',
    giving b a 1 mm score that is a's."""
    def row(name, m1, m2):
        return {"scenario": "noisy", "faces": "full", "kind": "clear", "name": name,
                "radial": {"matched_1": m1, "matched_2": m2, "fit_s": 1.0, "fit_cpu_s": 1.0}}

    md = markdown(summarise([row("a", 50.0, 90.0), row("b", 60.0, 80.0)], ["radial"]), ["radial"])
    assert "50.0 (a) / 80.0 (b)" in md
    md = markdown(summarise([row("a", 50.0, 70.0), row("b", 60.0, 80.0)], ["radial"]), ["radial"])
    assert "50.0 / 70.0 (a)" in md


def test_the_interval_is_printed_at_the_means_precision():
    """A mean of 95.7 was printed beside '[96–96]': the interval had no decimals."""
    def row(name, m):
        return {"scenario": "noisy", "faces": "full", "kind": "clear", "name": name,
                "radial": {"matched_1": m, "matched_2": m, "fit_s": 1.0, "fit_cpu_s": 1.0}}

    md = markdown(summarise([row("a", 95.6), row("b", 95.8)], ["radial"]), ["radial"])
    assert "| 95.7 [95.6–95.8] | 95.7 [95.6–95.8] |" in md


def test_bootstrap_interval_brackets_the_mean():
    lo, hi = bootstrap_ci([80.0, 90.0, 100.0, 70.0])
    assert lo < 85.0 < hi and 70 <= lo and hi <= 100


def test_bad_options_are_named():
    with pytest.raises(WoodcamError, match="scenario must be one of"):
        score_block(1, 0, ("radial",), "foggy")
    with pytest.raises(WoodcamError, match="methods must be from"):
        score_block(1, 0, ("magic",))
    with pytest.raises(WoodcamError, match="face_set must be one of"):
        score_block(1, 0, ("radial",), "clean", "two")


@pytest.mark.parametrize("seed, index", [(-1, 0), (3, -2), (1.5, 0), (True, 0)])
def test_a_benchmark_block_needs_a_seed_and_index_that_name_one(seed, index):
    with pytest.raises(WoodcamError, match="must be an integer >= 0"):
        make_block(seed, index)


def test_eval_realistic_takes_methods_all_as_eval_rings_does(tmp_path, monkeypatch):
    """'eval rings --methods all' ran every method; 'eval realistic --methods all' was refused
    ('--methods must be from ...; got ['all']')."""
    import woodcam.bench_realistic
    from woodcam.cli import main
    from woodcam.cli.fit import METHODS

    asked = []

    def score_block(seed, index, methods, *args, **kwargs):
        asked.append(list(methods))
        raise SystemExit(0)  # the methods are all this test needs

    monkeypatch.setattr(woodcam.bench_realistic, "score_block", score_block)
    with pytest.raises(SystemExit):
        main(["eval", "realistic", "--seed", "1", "--count", "1", "--methods", "all", "--out",
              str(tmp_path / "out")])
    assert asked == [list(METHODS)]


def test_eval_realistic_says_the_evidence_only_options_change_nothing_without_evidence(tmp_path, monkeypatch,
                                                                                     capsys):
    """--no-knot-bend, --no-knot-cones and --residual act on the evidence fit only (fit_block);
    'eval realistic --methods radial --residual --no-knot-bend' ran and said nothing of them."""
    import woodcam.bench_realistic
    from woodcam.cli import main

    def score_block(seed, index, methods, *args, **kwargs):
        raise SystemExit(0)  # the warning comes before the work: no block is needed

    monkeypatch.setattr(woodcam.bench_realistic, "score_block", score_block)
    with pytest.raises(SystemExit):
        main(["eval", "realistic", "--seed", "1", "--count", "1", "--methods", "rbf,radial", "--residual",
              "--no-knot-bend", "--out", str(tmp_path / "out")])
    assert ("woodcam: warning: --no-knot-bend and --residual act on the evidence fit only, and --methods "
            "rbf,radial has none: they change nothing; add evidence to --methods (e.g. --methods "
            "evidence,rbf,radial) or drop them") in capsys.readouterr().err
    with pytest.raises(SystemExit):  # with evidence they act: no word
        main(["eval", "realistic", "--seed", "1", "--count", "1", "--methods", "evidence", "--residual",
              "--out", str(tmp_path / "out2")])
    assert "evidence fit only" not in capsys.readouterr().err


def test_eval_realistic_outputs_land_as_one_set_and_a_rerun_removes_the_earlier_runs(tmp_path, monkeypatch,
                                                                                     capsys):
    """records.json was rewritten after every block and the PNGs drawn as they came, table.md at
    the end: a Ctrl-C left new records and pictures beside an earlier run's table, and a rerun
    with fewer blocks kept the earlier run's pictures. Now the run's files land together (or
    none do) and the earlier run's it does not write again go, with a warning."""
    import re

    import woodcam.bench_realistic
    import woodcam.inference.evaluate
    from woodcam._atomic import write_text
    from woodcam.cli import main

    def score_block(seed, index, methods, scenario, faces, kind, **kwargs):
        if index == stop_at[0]:
            raise KeyboardInterrupt
        return {"name": f"b{index}", "kind": kind, "scenario": scenario, "faces": faces, "planes": [],
                **{m: {"matched_1": 90.0 + index, "matched_2": 95.0, "fit_s": 0.1} for m in methods}}

    stop_at = [None]
    monkeypatch.setattr(woodcam.bench_realistic, "score_block", score_block)
    monkeypatch.setattr(woodcam.inference.evaluate, "plot_planes",
                        lambda path, planes, **kw: write_text(path, "a picture"))
    out = tmp_path / "out"
    run = ["eval", "realistic", "--seed", "1", "--methods", "radial", "--faces", "full", "--eq79", "0",
           "--plots", "--out", str(out)]
    assert main([*run, "--count", "3"]) == 0
    first = {p.name: (p.stat().st_ino, p.read_bytes()) for p in out.iterdir()}
    assert {"b0_noisy_full.png", "b2_noisy_full.png", "records.json", "table.md"} <= set(first)
    stop_at[0] = 1  # a Ctrl-C at the second block
    assert main([*run, "--count", "2"]) == 130
    assert {p.name: (p.stat().st_ino, p.read_bytes()) for p in out.iterdir()} == first
    stop_at[0] = None
    capsys.readouterr()
    assert main([*run, "--count", "2"]) == 0
    assert re.search(r"warning: removed 1 file\(s\) of an earlier run .*: b2_noisy_full.png$",
                     capsys.readouterr().err, re.M)
    assert sorted(p.name for p in out.iterdir()) == [".woodcam-eval-files.json", "b0_noisy_full.png",
                                                     "b1_noisy_full.png", "records.json", "table.md"]
    assert [r["name"] for r in json.loads((out / "records.json").read_text())] == ["b0", "b1"]
