"""One evidence fit on two cores (woodcam._parallel): the same fit bit for bit as on one."""

from __future__ import annotations

import os
import warnings

import numpy as np
import pytest

from woodcam import _parallel
from woodcam.errors import WoodcamError, WoodcamWarning
from woodcam.fields.base import evaluate
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
    import time

    def task(i):
        time.sleep(0.1)
        return i, os.getpid()

    done, mine = _parallel.share([lambda i=i: task(i) for i in range(10)], lambda: time.sleep(0.25) or "here", 2)
    assert mine == "here" and [i for i, _ in done] == list(range(10))
    in_fork = [p != os.getpid() for _, p in done]
    assert in_fork[0] and not in_fork[-1]  # both took part
    assert in_fork == sorted(in_fork, reverse=True)


def test_beside_keeps_only_its_own_side_effects():
    seen: list = []

    def away():
        seen.append("away")
        return os.getpid()

    def here():
        seen.append("here")
        return os.getpid()

    pid_away, pid_here = _parallel.beside(away, here)
    assert pid_here == os.getpid() != pid_away
    assert seen == ["here"]  # the forked side's changes stay in the fork


def test_a_forked_piece_inside_another_runs_serially():
    inner = _parallel.beside(lambda: _parallel.map_processes(lambda x: os.getpid(), range(3), 2), lambda: None)[0]
    assert len(set(inner)) == 1 and inner[0] != os.getpid()


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


def test_hypotheses_that_share_state_are_refitted_here(small_knotted_block):
    """``holdout_evidence(workers=2)`` refits only hypotheses marked ``alone`` in a fork: the
    others (the stem and its knots' bend, whose cone fits later steps read) keep their side
    effects here, fold by fold in the serial order, and every score is the serial one."""
    from woodcam.inference.evidence import Hypothesis, holdout_evidence
    from woodcam.inference.observations import gather_observations

    obs = gather_observations(small_knotted_block)
    log: list = []

    def recipe(name, scale):
        def refit(o):
            log.append((name, len(o.points_mm), os.getpid()))
            return lambda p: np.asarray(p, float) @ np.array([0.0, 0.0, scale])
        return refit

    hyps = [Hypothesis("shared", None, recipe("shared", 0.4)), Hypothesis("alone", None, recipe("alone", 0.3), alone=True)]
    serial = holdout_evidence(hyps, obs, workers=1)
    serial_log = list(log)
    log.clear()
    forked = holdout_evidence(hyps, obs, workers=2)
    assert forked == serial and len(serial["shared"]) >= 2
    shared = [e for e in log if e[0] == "shared"]  # ("alone" folds may be taken here too)
    assert shared == [e for e in serial_log if e[0] == "shared"]  # here, in the same order
