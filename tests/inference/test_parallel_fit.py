"""One evidence fit on two cores (woodcam._parallel): the same fit bit for bit as on one."""

from __future__ import annotations

import os
import time
import warnings

import numpy as np
import pytest

from woodcam import _parallel
from woodcam.errors import WoodcamError, WoodcamWarning
from woodcam.fields.base import evaluate
from woodcam.fields.knot_strands import StemWithKnots
from woodcam.inference.fit import fit_block

pytestmark = pytest.mark.skipif(not _parallel._CAN_FORK, reason="a fit forks its pieces on Linux only (woodcam._parallel)")


def test_fit_workers_reads_the_environment(monkeypatch):
    monkeypatch.delenv(_parallel.WORKERS_ENV, raising=False)
    assert _parallel.fit_workers() == max(1, min(2, os.cpu_count() or 1))
    monkeypatch.setenv(_parallel.WORKERS_ENV, "3")
    assert _parallel.fit_workers() == 3
    for bad in ("0", "two", "-1"):
        monkeypatch.setenv(_parallel.WORKERS_ENV, bad)
        with pytest.raises(WoodcamError, match="WOODCAM_WORKERS must be an integer >= 1"):
            _parallel.fit_workers()


def test_map_processes_keeps_the_order_forks_take_the_first_items_and_this_process_the_last():
    pids = _parallel.map_processes(lambda x: (x, os.getpid()), range(7), 3)
    assert [x for x, _ in pids] == list(range(7))
    here = [p == os.getpid() for _, p in pids]
    assert here == sorted(here)  # a prefix in forks, the rest (a suffix, maybe empty) here
    assert _parallel.map_processes(lambda x: (x, os.getpid()), range(4), 1) == [(x, os.getpid()) for x in range(4)]


def test_share_evens_out_tasks_between_the_fork_and_this_process():
    """While this process is busy, the fork works from the first task; then this process takes
    the tasks not yet started, from the last, and both meet."""
    def task(i):
        time.sleep(0.1)
        return i, os.getpid()

    done, mine = _parallel.share([lambda i=i: task(i) for i in range(10)], lambda: time.sleep(0.25) or "here", 2)
    assert mine == "here" and [i for i, _ in done] == list(range(10))
    in_fork = [p != os.getpid() for _, p in done]
    assert in_fork[0] and not in_fork[-1]  # both took part
    assert in_fork == sorted(in_fork, reverse=True)


def test_a_task_the_busy_fork_has_not_started_is_taken_here():
    """A fork claims a task when it starts it: while it is busy with the first, the second is
    still free for this process. Checked by breaking it: with the tasks named when the pool
    queues them (it queues one ahead of each worker), the second ran in the fork after the first."""
    def task(s):
        time.sleep(s)
        return os.getpid()

    done, _ = _parallel.share([lambda: task(1.0), lambda: task(0.0)], lambda: time.sleep(0.3), 2)
    assert done[0] != os.getpid() and done[1] == os.getpid()


def test_beside_keeps_only_its_own_side_effects():
    seen: list = []

    def away():
        seen.append("away")
        return os.getpid()

    def here():
        time.sleep(0.5)  # the fork starts meanwhile (else this process would take ``away`` too)
        seen.append("here")
        return os.getpid()

    pid_away, pid_here = _parallel.beside(away, here)
    assert pid_here == os.getpid() != pid_away
    assert seen == ["here"]  # the forked side's changes stay in the fork


def test_a_forked_piece_inside_another_runs_serially():
    inner = _parallel.beside(lambda: _parallel.map_processes(lambda x: os.getpid(), range(3), 2),
                             lambda: time.sleep(0.5))[0]  # the fork takes the piece meanwhile
    assert len(set(inner)) == 1 and inner[0] != os.getpid()


def test_a_piece_run_here_shares_its_own_pieces_with_a_new_fork():
    """This process' side of a share may fork its own pieces (a knot's cone starts inside the
    knots' bend, while a fork refits other hypotheses): they run in a fork of their own and here."""
    def slow(x):
        time.sleep(0.2)
        return os.getpid()

    away, inner = _parallel.beside(os.getpid, lambda: _parallel.map_processes(slow, range(4), 2))
    assert inner[-1] == os.getpid() and inner[0] not in (os.getpid(), away)


_IMPORT_RACE = """
import time
import numpy as np
from woodcam._parallel import share

def away():
    from scipy.interpolate import RBFInterpolator
    x = np.random.default_rng(0).random((50, 3))
    return RBFInterpolator(x, x[:, 0])

def here():
    time.sleep(0.05)  # the forks' results arrive while this process imports the same package
    from scipy.interpolate import RBFInterpolator
    return RBFInterpolator.__name__

done, mine = share([away, away], here, 3)
print(type(done[0]).__name__, mine)
"""


def test_forked_results_never_race_this_process_imports():
    """A fresh process (nothing of scipy.interpolate imported yet) whose forks return RBFs while
    it imports scipy.interpolate itself: the pool's result thread must not unpickle them (and so
    import the package) beside the main thread. Checked by breaking it: with the results
    returned unpickled by the pool, this fails with "cannot import name 'RBFInterpolator'" (12
    runs of 12; the first real fit of a process failed so once in three)."""
    import subprocess
    import sys

    for _ in range(3):
        run = subprocess.run([sys.executable, "-c", _IMPORT_RACE], capture_output=True, text=True, timeout=120)
        assert run.returncode == 0 and run.stdout.split() == ["RBFInterpolator", "RBFInterpolator"], run.stderr[-800:]


def test_forked_grid_evaluation_is_the_serial_one_bit_for_bit():
    """A thin-plate RBF on a grid whose size is no multiple of anything: the forked share starts
    on an aligned point (broken once: cut at half the points, the matrix-vector kernels' row
    blocks moved and the RBF's values changed by rounding)."""
    from scipy.interpolate import RBFInterpolator

    from woodcam.inference.rbf import _thin_plate_field

    rng = np.random.default_rng(3)
    centres = rng.uniform(0, 40, (700, 3))
    field = _thin_plate_field(RBFInterpolator(centres, np.sin(centres[:, 0] / 7) + centres[:, 2] / 3,
                                              kernel="thin_plate_spline", smoothing=1.0))
    pts = rng.uniform(-2, 42, (3 * (1 << 16) + 12347, 3))  # half of it is odd
    serial = evaluate(field, pts)
    forked = evaluate(field, pts, workers=2)
    assert np.array_equal(serial, forked)


@pytest.fixture(scope="module")
def small_knotted_block():
    from woodcam.bench_realistic import make_block

    block, info = make_block(9101, 0, "noisy", face_px=96)  # dev seed; every hypothesis family
    assert info["knotted"]
    return block


def _fit(block, workers, monkeypatch, **kw):
    monkeypatch.setenv(_parallel.WORKERS_ENV, str(workers))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", WoodcamWarning)
        return fit_block(block, "evidence", **kw)


@pytest.mark.parametrize("residual", [False, True])
def test_two_workers_give_the_one_worker_fit_bit_for_bit(small_knotted_block, monkeypatch, residual):
    """The default evidence fit of a small knotted block (radial basins, stem, RBF, residual,
    knot bend with cones; ``residual``: the small-scale residual, refitted on every fold's
    fields) on one core and on two: the same choice, held-out scores, baked years and layers."""
    one = _fit(small_knotted_block, 1, monkeypatch, residual=residual)
    two = _fit(small_knotted_block, 2, monkeypatch, residual=residual)
    assert "stem + knot bend" in one.meta["scores"] and "rbf" in one.meta["scores"]
    assert one.meta == two.meta
    assert np.array_equal(one.years, two.years)
    assert one.layers.keys() == two.layers.keys()
    for k in one.layers:
        assert np.array_equal(one.layers[k], two.layers[k])


def test_hypotheses_that_share_a_folds_fit_are_refitted_together(small_knotted_block):
    """``holdout_evidence`` refits the hypotheses not marked ``alone`` one fold per task, in their
    order, wherever the task runs: one that reads another's fit of the same fold (the knots'
    bend reads the stem's, remembered by the stem's recipe) finds it, on one worker and on two,
    and every score is the serial one. Checked by breaking it: with one task per hypothesis
    and fold, the later hypothesis finds another fold's fit and has no prediction."""
    from woodcam.inference.evidence import Hypothesis, holdout_evidence
    from woodcam.inference.observations import gather_observations

    obs = gather_observations(small_knotted_block)
    last: dict = {}

    def base(o):
        last["obs"] = o
        return lambda p: np.asarray(p, float) @ np.array([0.0, 0.0, 0.4])

    def on_base(o):
        if last.get("obs") is not o:  # this fold's base fit must have been made just before
            raise WoodcamError("the base was fitted on other rings")
        return lambda p: np.asarray(p, float) @ np.array([0.0, 0.0, 0.4]) + 0.2

    hyps = [Hypothesis("base", None, base), Hypothesis("on base", None, on_base),
            Hypothesis("alone", None, lambda o: (lambda p: np.asarray(p, float) @ np.array([0.0, 0.3, 0.0])),
                       alone=True)]
    runs = []
    for workers in (1, 2):
        predictions: dict = {}
        runs.append(holdout_evidence(hyps, obs, workers=workers, predictions=predictions))
        faces = set(runs[-1]["base"])
        assert len(faces) >= 2 and {f for n, f in predictions if n == "on base"} == faces
    assert runs[0] == runs[1]


def test_a_fold_keeps_its_own_cone_fits(monkeypatch):
    """The knots' bend of a fold starts from the cone fits of the all-faces bend only: what a
    fold fits stays in it (the folds run in forks, in any order), so no fold depends on another.
    Every start is fitted afresh here (no reuse of a start a few degrees off), so that the folds
    fit cones of their own (the start down the stem's years of a knot cut by a block edge).
    Checked by breaking it: with the folds writing to the shared fits, the memo grows by four."""
    from woodcam.bench_realistic import make_block
    from woodcam.inference import knots as K
    from woodcam.inference.observations import gather_observations

    monkeypatch.setattr(K, "KNOT_CONE_START_REUSE_DEG", 0.0)
    block, info = make_block(7777, 7, "noisy", face_px=96)  # dev seed: knots cut by block edges
    obs = gather_observations(block)
    exits = K.knot_exits(block)
    pinned = K.knot_bend_recipes(block.size_mm, exits, cones=True, workers=1)[1]["stem + knot bend"]
    pinned(obs)
    after_all = {k: len(v) for k, v in exits[0]["cone_memo"].items()}
    assert sum(after_all.values()) >= 4
    fold = pinned(obs.subset(obs.face != np.unique(obs.face)[0]))
    assert isinstance(fold, StemWithKnots)
    assert {k: len(v) for k, v in exits[0]["cone_memo"].items()} == after_all
