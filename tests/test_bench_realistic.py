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
