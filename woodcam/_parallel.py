"""Both cores for one fit: the evidence fit's independent pieces on a small pool.

A user fitting one block waits for its wall time, and the goal (issue 12) is a fit within
10 s on a 2-core machine; the fit's CPU time alone is 7-17 s on the benchmark's knotted
blocks. Its independent pieces run in forked processes, which inherit the parent's data
without pickling it (only results travel back); threads would not do: the fits are many
small numpy and least-squares steps that hold the GIL between them (a threaded grid bake
gained 1.7x where a fork gains ~2x), and several recipes keep per-fold caches.

- :func:`map_processes`: independent items (the radial axis refinements);
- :func:`share`: independent tasks in forks while this process does a piece that must stay
  here, then helps with the tasks (the held-out refits, one task per fold: those of the
  hypotheses that keep no state beside the all-faces fit of the knots' bend, then the others);
- :func:`beside`: one piece in a fork while this process does another (half of a grid bake).

A piece this process runs may share its own pieces with new forks (the cone starts of a knot
inside the knots' bend, while a fork refits the hypotheses that keep no state); a piece running
in a fork runs its pieces one after the other (its core is taken: no pools of pools).

Each piece runs the same code on the same inputs as in a serial run, so the results are the
same bit for bit (``tests/inference/test_parallel_fit.py``). :func:`fit_workers` says how
many cores a fit may use: ``$WOODCAM_WORKERS`` when set (``woodcam.scale``'s workers set it
to 1, since there the tasks are the unit of parallelism), else ``min(2, cpu count)``. Off
Linux (:data:`_CAN_FORK`) the pieces run one after the other.
"""

from __future__ import annotations

import os
import pickle
import sys
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from .errors import WoodcamError

if TYPE_CHECKING:
    from concurrent.futures import ProcessPoolExecutor

#: The environment variable that caps the cores one fit uses.
WORKERS_ENV = "WOODCAM_WORKERS"

#: Cores a fit uses by default: the 2 of the machine the goal is set on; more would only add
#: pool overhead to pieces that come in twos and threes.
DEFAULT_WORKERS = 2


def fit_workers() -> int:
    """Cores one fit may use: ``$WOODCAM_WORKERS`` (an integer >= 1) or ``min(2, cpu count)``."""
    raw = os.environ.get(WORKERS_ENV)
    if raw is None or raw.strip() == "":
        return max(1, min(DEFAULT_WORKERS, os.cpu_count() or 1))
    try:
        n = int(raw)
    except ValueError:
        n = 0
    if n < 1:
        raise WoodcamError(f"{WORKERS_ENV} must be an integer >= 1 (cores one fit may use); got {raw!r}; "
                           f"unset it for the default ({DEFAULT_WORKERS})")
    return n


#: Fork only on Linux: Windows has no fork, and on macOS a forked child of a process that has
#: used the system's frameworks (Accelerate's BLAS among them) may crash, which is why Python
#: no longer forks there by default; elsewhere the pieces run one after the other.
_CAN_FORK = sys.platform.startswith("linux")

#: What forked workers run: ``"away"`` (the tasks) and ``"claim"`` (where the next task from
#: the first is counted) are set in the parent just before the fork, so that the children find
#: the functions and their data without pickling them (only an index and the results travel);
#: ``"child"`` is set in a forked worker, whose own pieces run serially (no pools of pools: a
#: fork's core is taken). A piece run in the parent may fork its own pieces.
_FORKED: dict = {}


def _claim(counts, lock, from_first: bool) -> int | None:
    """The next task not yet taken, from the first (a fork) or the last (this process), or None
    when the two ends have met. ``counts``: shared ``[next from the first, next from the last]``."""
    with lock:
        first, last = counts[0], counts[1]
        if first > last:
            return None
        if from_first:
            counts[0] = first + 1
            return first
        counts[1] = last - 1
        return last


def _run_forked() -> tuple[int, bytes] | None:
    """In a fork: the next task from the first, run, and its index with its result; None when
    none is left. The task is claimed when the job starts, not when it is queued: the pool
    queues a job ahead of each worker, and a task named in a queued job could no longer be
    taken by this process, which then waited for it (a fork's last two folds of the knots'
    bend, 1.6 s idle)."""
    _FORKED["child"] = True
    i = _claim(*_FORKED["claim"], from_first=True)
    if i is None:
        return None
    # The result travels pickled by hand and is unpickled by this process' main thread
    # (share): the pool's own result thread would unpickle it, importing the modules its
    # classes live in (scipy.interpolate for an RBF) while the main thread may be importing
    # the same package for a task it took, and Python then fails the main thread's import of
    # the half-initialised package ("cannot import name 'RBFInterpolator'": the first fit of
    # a process, one run in three; tests/inference/test_parallel_fit.py).
    return i, pickle.dumps(_FORKED["away"][i](), protocol=pickle.HIGHEST_PROTOCOL)


def share(tasks: list[Callable[[], Any]], here: Callable[[], Any], workers: int) -> tuple[list, Any]:
    """``([t() for t in tasks], here())``: ``workers - 1`` forked processes work through
    ``tasks`` from the first while this process runs ``here``, then takes the tasks none has
    started, from the last (their costs are not known ahead: each side keeps busy until they
    meet). All here, one after the other, with one worker, off Linux (:data:`_CAN_FORK`) or
    inside a forked piece: ``here`` first, as with forks, so that ``here`` sees no task's side
    effects either way. Each task's result must be picklable and must not depend on where it
    ran (a task done here keeps its side effects, one done in a fork loses them)."""
    if not _CAN_FORK or _FORKED.get("child") or not tasks or workers <= 1:
        mine = here()
        return [t() for t in tasks], mine
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    ctx = mp.get_context("fork")
    claim = (ctx.RawArray("l", [0, len(tasks) - 1]), ctx.Lock())
    _FORKED.update(away=tasks, claim=claim)  # the children's copies are read
    try:
        with ProcessPoolExecutor(min(workers - 1, len(tasks)), mp_context=ctx) as ex:
            try:
                # the first submit forks every worker: each sees the state as it is here and now
                jobs = [ex.submit(_run_forked) for _ in tasks]
                mine = here()
                done: dict = {}
                while (i := _claim(*claim, from_first=False)) is not None:
                    done[i] = tasks[i]()
                for job in jobs:  # what the forks did (a job that found none left returns None)
                    if (got := job.result()) is not None:
                        done[got[0]] = pickle.loads(got[1])
                return [done[i] for i in range(len(tasks))], mine
            except BaseException:
                # Ctrl-C (or an error) here: leaving the with-block waited for the forks to
                # finish their tasks (a fit's held-out refits: 5-8 s after the Ctrl-C)
                kill_workers(ex)
                raise
    finally:
        _FORKED.pop("away", None)
        _FORKED.pop("claim", None)


def kill_workers(pool: ProcessPoolExecutor) -> None:
    """Kill the worker processes of ``pool`` (a ``ProcessPoolExecutor``) and drop its queued
    jobs, so that its shutdown does not wait for their work: on a Ctrl-C or an error, whose
    run's results are never used."""
    for proc in list((getattr(pool, "_processes", None) or {}).values()):
        proc.kill()
    manager = getattr(pool, "_executor_manager_thread", None)
    pool.shutdown(wait=False, cancel_futures=True)
    # its manager thread ends as it sees the killed workers, closing its wake-up pipe; left to end
    # on its own, it raced CPython 3.11's exit hook (concurrent.futures.process._python_exit), which
    # wrote to that pipe as it closed: 'Exception ignored ... OSError: [Errno 9] Bad file
    # descriptor' after the interrupt's one line. Joined here (bounded), the pipe is closed first.
    if manager is not None:
        manager.join(timeout=5.0)


def map_processes(fn: Callable[[Any], Any], items: Sequence, workers: int) -> list:
    """``[fn(item) for item in items]``: forked processes take the items from the first, this
    one from the last (:func:`share`). ``fn``'s results must be picklable; the side effects of
    the items done in a fork are lost."""
    items = list(items)
    if len(items) <= 1:  # nothing to share: no fork
        return [fn(x) for x in items]
    return share([lambda x=x: fn(x) for x in items], lambda: None, workers)[0]


def beside(away: Callable[[], Any], here: Callable[[], Any], workers: int = 2) -> tuple[Any, Any]:
    """``(away(), here())``: ``away`` in a forked process while ``here`` runs in this one (one
    after the other with one worker, :func:`share`; here too when ``here`` is done before the
    fork has started it). ``away``'s result must be picklable and must not depend on where it
    ran; ``here``'s side effects stay."""
    done, mine = share([away], here, workers)
    return done[0], mine


__all__: list[str] = []
