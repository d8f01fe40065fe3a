"""Figures of the task runner: speed-up of 2 workers over serial, per-task overhead per engine.

Run: ``python -m pytest tests/scale/test_scale_bench.py -m bench -s`` (prints a table). The
machine is shared, so every figure is a ratio against a baseline measured in the same run, and
the load average is printed with it. Besides wall time it prints the cores actually used (task
CPU seconds / wall seconds): with the kernel's ``sched_autogroup`` on, all processes of one
session share one fair slice of the CPUs, so on a loaded machine two workers get no more CPU
than one and the wall speed-up says more about the neighbours than about the engine.
"""

from __future__ import annotations

import os
import time
from functools import partial

import pytest

import _scale_tasks as tasks
from pathlib import Path

from woodcam.scale import read_records, run_many

#: Pure-Python iterations of one CPU-bound task (~1 s on an idle core of this machine).
SPIN = 3_000_000
N_TASKS = 12
N_TRIVIAL = 200


def _timed(tmp_path, name, fn, keys, **kw) -> float:
    t0 = time.perf_counter()
    s = run_many(fn, keys, tmp_path / name, progress=False, **kw)
    assert s.failed == 0 and s.done == len(keys)
    return time.perf_counter() - t0


def _cpu(tmp_path, name) -> float:
    """Task CPU seconds summed over a run's records."""
    return sum(r["cpu_s"] for r in read_records(tmp_path / name).values())


def _autogroup() -> str:
    try:
        return Path("/proc/self/autogroup").read_text().strip() + (
            ", sched_autogroup_enabled=" + Path("/proc/sys/kernel/sched_autogroup_enabled").read_text().strip())
    except OSError:
        return "no autogroup information"


@pytest.mark.bench
@pytest.mark.slow
def test_speedup_and_overhead(tmp_path):
    load0 = os.getloadavg()
    keys = [f"k{i}" for i in range(N_TASKS)]
    spin = partial(tasks.spin, n=SPIN)
    trivial = partial(tasks.spin, n=0)
    # start-up: the loky pool is reused between calls (warm it once); a LocalCluster is started
    # by every dask call, so its start-up is the time of a one-trivial-task run, subtracted below
    local_start = _timed(tmp_path, "warm", trivial, ["k0", "k1"], engine="local", workers=2)
    dask_start = _timed(tmp_path, "dask-start", trivial, ["k0"], engine="dask", workers=2)
    serial = _timed(tmp_path, "serial", spin, keys, engine="local", workers=1)
    local2 = _timed(tmp_path, "local2", spin, keys, engine="local", workers=2)
    dask2 = _timed(tmp_path, "dask2", spin, keys, engine="dask", workers=2) - dask_start
    # per-task overhead: trivial tasks, N of them minus 1 of them (start-up cancels)
    over = {}
    for name, kw in {"local serial": dict(engine="local", workers=1),
                     "local 2 workers": dict(engine="local", workers=2),
                     "dask 2 workers": dict(engine="dask", workers=2)}.items():
        one = _timed(tmp_path, f"{name}-1", trivial, ["k0"], **kw)
        many = _timed(tmp_path, f"{name}-n", trivial, [f"k{i}" for i in range(N_TRIVIAL)], **kw)
        over[name] = (many - one) / (N_TRIVIAL - 1)
    load1 = os.getloadavg()
    print(f"\nload average (1, 5, 15 min) before {load0}, after {load1}; {os.cpu_count()} CPUs")
    print(f"start-up: loky pool {local_start:.1f} s (first call), dask LocalCluster {dask_start:.1f} s")
    print(f"{N_TASKS} tasks of {SPIN} sin() each: serial {serial:.1f} s, local 2 workers "
          f"{local2:.1f} s (speed-up {serial / local2:.2f}x), dask 2 workers {dask2:.1f} s "
          f"without start-up (speed-up {serial / dask2:.2f}x)")
    cpu = {n: _cpu(tmp_path, n) for n in ("serial", "local2", "dask2")}
    print(f"cores used (task CPU s / wall s): serial {cpu['serial'] / serial:.2f}, local 2 workers "
          f"{cpu['local2'] / local2:.2f}, dask 2 workers {cpu['dask2'] / dask2:.2f}; {_autogroup()}")
    for name, v in over.items():
        print(f"per-task overhead, {name}: {1000 * v:.1f} ms (incl. one fsynced JSON record)")
    # what the engine controls: a task costs the same CPU on a worker as in the serial loop
    assert cpu["local2"] < 1.3 * cpu["serial"] and cpu["dask2"] < 1.3 * cpu["serial"], cpu
