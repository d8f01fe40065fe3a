"""Both cores for one fit: the evidence fit's independent pieces on a small pool.

A user fitting one block waits for its wall time, and the goal (issue 12) is a fit within
10 s on a 2-core machine; the fit's CPU time alone is 7-17 s on the benchmark's knotted
blocks. Its independent pieces run in forked processes, which inherit the parent's data
without pickling it (only results travel back); threads would not do: the fits are many
small numpy and least-squares steps that hold the GIL between them (a threaded grid bake
gained 1.7x where a fork gains ~2x), and several recipes keep per-fold caches.

- :func:`map_processes`: independent items on a pool (the radial axis refinements);
- :func:`beside`: one piece in a child while this process does another (the held-out refits
  of the hypotheses that share no state beside those that do; half of a grid bake).

Each piece runs the same code on the same inputs as in a serial run, so the results are the
same bit for bit (``tests/inference/test_parallel_fit.py``). :func:`fit_workers` says how
many cores a fit may use: ``$WOODCAM_WORKERS`` when set (``woodcam.scale``'s workers set it
to 1, since there the tasks are the unit of parallelism), else ``min(2, cpu count)``. Off
Linux (:data:`_CAN_FORK`) the pieces run one after the other.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable, Sequence
from typing import Any

from .errors import WoodcamError

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

#: What forked workers run: set in the parent just before the fork, so that the children find
#: the functions and their data without pickling them (only an index and the results travel).
#: Not empty inside a forked piece, where further pieces run serially (no nested pools).
_FORKED: dict = {}


def _run_forked(i: int):
    return _FORKED["away"][i]()


def _fork_beside(away: list[Callable[[], Any]], here: Callable[[], Any]) -> tuple[list, Any]:
    """``([f() for f in away], here())`` with each ``away`` call in a forked process while
    ``here`` runs in this one; all here, one after the other, off Linux (:data:`_CAN_FORK`)
    or inside a forked piece."""
    if not _CAN_FORK or _FORKED or not away:
        return [f() for f in away], here()
    import multiprocessing as mp

    ctx = mp.get_context("fork")
    from concurrent.futures import ProcessPoolExecutor

    _FORKED["away"] = away
    try:
        with ProcessPoolExecutor(len(away), mp_context=ctx) as ex:
            # the first submit forks every worker: each sees the state as it is here and now
            jobs = [ex.submit(_run_forked, i) for i in range(len(away))]
            _FORKED.clear()
            mine = here()
            return [j.result() for j in jobs], mine
    finally:
        _FORKED.clear()


def map_processes(fn: Callable[[Any], Any], items: Sequence, workers: int) -> list:
    """``[fn(item) for item in items]`` in ``workers`` contiguous shares: the first here, the
    others each in a forked process. ``fn``'s results must be picklable; the side effects of
    the forked shares are lost."""
    items = list(items)
    if workers <= 1 or len(items) <= 1:
        return [fn(x) for x in items]
    bounds = [len(items) * k // min(workers, len(items)) for k in range(min(workers, len(items)) + 1)]
    shares = [items[bounds[k]:bounds[k + 1]] for k in range(len(bounds) - 1)]
    away, mine = _fork_beside([lambda share=share: [fn(x) for x in share] for share in shares[1:]],
                              lambda: [fn(x) for x in shares[0]])
    return mine + [y for share in away for y in share]


def beside(away: Callable[[], Any], here: Callable[[], Any]) -> tuple[Any, Any]:
    """``(away(), here())``: ``away`` in a forked process while ``here`` runs in this one.
    ``away``'s result must be picklable and its side effects are lost; ``here``'s stay."""
    done, mine = _fork_beside([away], here)
    return done[0], mine


__all__: list[str] = []
