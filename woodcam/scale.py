"""Running many independent tasks: local processes by default, a Dask cluster when asked.

:func:`run_many` calls ``fn(key)`` once for every key and keeps one small JSON record per key in
``out_dir/records/<key>.json``::

    {"key": "b000042", "status": "ok", "attempts": 1, "seconds": 9.81, "cpu_s": 9.6,
     "result": {...}}
    {"key": "b000043", "status": "failed", "attempts": 3, "seconds": 0.02,
     "error": "ValueError: the message"}

A record is written atomically (a temp file in the same folder, then ``os.replace``), by the
process that drives the run, as each task finishes; so after a ``kill -9`` every record on disk
is whole, and running the same call again skips every key that has an ``ok`` record (failed keys
are tried again). ``fn`` must be picklable (a module-level function or a ``functools.partial``
of one) and its result JSON-serialisable; its result must depend on the key alone (and the
settings bound into ``fn``), never on the engine, the worker or the order, so that a run is
reproducible and resumable: that is the caller's contract, which :mod:`woodcam.benchmark` keeps
by drawing everything from ``np.random.default_rng([seed, index])``.

Engines (:data:`ENGINES`):

- ``"local"`` (default): joblib's loky process pool on this machine, no services; ``workers=1``
  runs in this process (the serial baseline).
- ``"dask"``: Dask ``distributed``. With ``address`` (``tcp://host:8786``) the run goes to that
  scheduler, as on a real cluster (start it with ``dask scheduler`` and ``dask worker ADDRESS``);
  records are still written here, so the workers need no shared disk. Without ``address`` a
  ``LocalCluster`` of ``workers`` (default 2) single-threaded worker processes on 127.0.0.1 is
  started for the run and closed after it.

Every worker runs one task at a time with one BLAS / OpenMP / torch / numba thread: tasks are the
unit of parallelism, and on a shared machine nested threads only contend. Each local worker is
bounded to ``memory_limit_mb`` of address space (a task going past it gets a ``MemoryError``,
which is retried and then recorded as a failure); Dask workers get the same number as their
``memory_limit`` (the nanny restarts a worker beyond it).
"""

from __future__ import annotations

import json
import logging
import os
import re
import shutil
import sys
import tempfile
import time
import traceback
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterable, Literal, get_args

from ._checks import check_bool, check_number, check_path
from ._repr import summary_repr
from .errors import UsageError, WoodcamError
from .limits import WORKER_MEMORY_MB_RANGE

Engine = Literal["local", "dask"]
ENGINES: tuple[str, ...] = get_args(Engine)

#: Sub-folder of a run folder holding one ``<key>.json`` record per task.
RECORDS_DIR = "records"

#: A key becomes a file name: letters, digits, ``_ . -``, not starting with a dot.
_KEY_RE = re.compile(r"^[A-Za-z0-9_-][A-Za-z0-9_.-]{0,199}$")

#: Address space (MiB) a local worker may map by default: a woodcam bench task peaks near 1 GiB
#: (torch + numba + a fitted grid), and 8 engineers share 24 GB here, 3 GiB each at most.
DEFAULT_MEMORY_LIMIT_MB = 3072

#: Seconds to wait for a Dask scheduler before calling its address unreachable.
CONNECT_TIMEOUT_S = 10.0

#: Environment variables that cap the thread pools of BLAS, OpenMP (torch), numba and numexpr;
#: set in each worker before those libraries load, and enforced at run time by threadpoolctl.
_THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS",
                "VECLIB_MAXIMUM_THREADS", "NUMBA_NUM_THREADS", "NUMEXPR_NUM_THREADS",
                "WOODCAM_WORKERS")  # the last: an evidence fit's forked pieces (woodcam._parallel)


@dataclass(frozen=True)
class RunSummary:
    """What :func:`run_many` did: counts of keys and the wall time (s) of this call;
    ``first_failure`` is ``"KEY failed: ERROR"`` of the first key that failed in it ('' if none);
    ``unit`` what one key is, singular ("block", "shard"), for :meth:`line`.

    ``out_dir``: the run folder (records under its ``records/``); ``engine``: ``"local"`` or
    ``"dask"``; ``workers``: the processes (local) or the cluster's workers (dask) that ran the
    keys, 0 when none was left to compute; ``total``: the keys asked for, of which ``skipped``
    had a record already (earlier runs), ``done`` were computed now and ``failed`` raised;
    ``wall_s``: seconds this call took to compute them (``time.perf_counter``)."""

    __repr__ = summary_repr  # arrays as shapes: a notebook shows one line

    out_dir: Path
    engine: str
    workers: int
    total: int
    skipped: int
    done: int
    failed: int
    wall_s: float
    first_failure: str = ""
    unit: str = "task"

    def line(self) -> str:
        """One line for a command to print; with failures, the first one's error (a run whose
        every key failed said '1 failed' and no why: the error was in a hidden record only).
        It counts in :attr:`unit` ("2 blocks: ..."): 'bench run --blocks 2' said "2 keys: ...",
        the record's file name, a word of this module and no user's."""
        why = ""
        if self.failed and self.first_failure:
            more = self.failed - 1
            why = (f"; {self.first_failure}" + (f" ({more} more failed: each error is in its record)"
                                                 if more else ""))
        return (f"{_count(self.total, self.unit)}: {self.skipped} already done, {self.done} computed, "
                f"{self.failed} failed; {self.wall_s:.1f} s on {self.engine} with "
                f"{_count(self.workers, 'worker')}; records in {self.out_dir / RECORDS_DIR}{why}")


def _count(n: int, noun: str) -> str:
    """``"1 block"``, ``"2 blocks"``."""
    return f"{n} {noun}" + ("" if n == 1 else "s")


# -- records --------------------------------------------------------------------------------------

def write_json_atomic(path, obj) -> Path:
    """Write ``obj`` as JSON to ``path`` atomically (:func:`woodcam._atomic.write_text`: a hidden
    temp file in the same folder, fsync, ``os.replace``), so a reader, or a run killed half-way,
    sees the old file or the whole new one, never a part."""
    from ._atomic import write_text

    path = Path(path)
    write_text(path, json.dumps(obj, separators=(",", ":")))
    return path


def check_run_manifest(path: str | Path, manifest: dict, out_dir: str | Path | None = None) -> None:
    """Tie a run folder to the settings its records were made with: write ``manifest`` (a
    JSON-able dict: seed, settings ...) to ``path`` when there is none, else refuse another one.

    :func:`run_many` skips every key with an ``ok`` record whatever made it, so a rerun into the
    same folder with another seed or settings would keep the old results under the new
    settings' name; callers whose task results depend on settings call this first. ``out_dir``
    is the folder the user gave (``--out``), named in the errors where ``path`` lies in a hidden
    folder of it (``OUT/.synth/run.json``); default ``path``'s folder. Raises
    :class:`~woodcam.errors.UsageError` (a :class:`WoodcamError`; the CLI's exit 2) naming the
    folder, each setting that differs (one level into nested dicts) and the fixes.
    """
    path = Path(path)
    folder = str(path.parent if out_dir is None else Path(out_dir))
    want = json.loads(json.dumps(manifest))  # tuples -> lists, as the file holds them
    if not path.is_file():
        path.parent.mkdir(parents=True, exist_ok=True)
        write_json_atomic(path, want)
        return
    try:
        old = json.loads(path.read_text())
    except ValueError as err:
        raise WoodcamError(f"{path} is not valid JSON ({err}); delete the run folder {folder!r} "
                           f"or pick a new --out") from err
    old = old if isinstance(old, dict) else {}
    diffs = []
    for k, v in want.items():
        o = old.get(k)
        if isinstance(v, dict) and isinstance(o, dict):
            diffs += [f"{k}.{j} {o.get(j)!r} there, {v.get(j)!r} now"
                      for j in sorted(set(v) | set(o)) if o.get(j) != v.get(j)]
        elif o != v:
            diffs.append(f"{k} {o!r} there, {v!r} now")
    if diffs:
        # a wrong command line (an --out that holds another set), found before any work: exit 2
        seed = f" (--seed {old['seed']!r})" if "seed" in want and old.get("seed") != want["seed"] else ""
        raise UsageError(f"{folder!r} holds a run with another seed or settings ({'; '.join(diffs)}); "
                         f"pick another --out, run again with its options{seed} to resume it, or "
                         f"delete {folder!r} to start over")


def record_path(out_dir, key: str) -> Path:
    return Path(out_dir) / RECORDS_DIR / f"{key}.json"


def read_records(out_dir: str | Path) -> dict[str, dict]:
    """Every record of the run folder ``out_dir`` (the one given to :func:`run_many`; its
    ``records/``): ``key -> record`` (see the module docstring), sorted by key.

    Temp files left by a killed run start with a dot and are not records.
    """
    folder = check_path(out_dir, "read_records: out_dir", fix="the run folder given to run_many") / RECORDS_DIR
    if not folder.is_dir():
        # the folder as given ('bench report RUN'), not the parameter's name the user never typed
        raise WoodcamError(f"run folder {str(out_dir)!r} has no {RECORDS_DIR}/ sub-folder, so no bench run "
                           "wrote it; run `woodcam bench run --out DIR` first and give that DIR")
    out = {}
    for p in sorted(folder.glob("[!.]*.json")):
        try:
            rec = json.loads(p.read_text())
        except ValueError as err:  # never happens with atomic writes; say so if it does
            raise WoodcamError(f"record {p} is not valid JSON ({err}); delete it and re-run "
                               f"to recompute that key") from err
        # a record's file is named by its key: a copy ("b000001 (copy).json") or a renamed file
        # holding another key was silently merged into that key, and one without a key or status
        # was a KeyError
        if not isinstance(rec, dict) or not isinstance(rec.get("key"), str) or "status" not in rec:
            raise WoodcamError(f"record {p} is not a run record (a JSON object with 'key' and "
                               f"'status'); delete it and re-run to recompute that key")
        if rec["key"] != p.stem:
            raise WoodcamError(f"record {p} holds key {rec['key']!r}, not its file's name "
                               f"{p.stem!r} (a copied or renamed record?); one record per key, "
                               f"named <key>.json: delete it and re-run to recompute that key")
        out[rec["key"]] = rec
    return out


def _finished_keys(out_dir: Path) -> set[str]:
    folder = out_dir / RECORDS_DIR
    done = set()
    for p in folder.glob("[!.]*.json"):
        try:
            rec = json.loads(p.read_text())
        except ValueError:
            continue  # treat as not done; it is overwritten
        # done only when it is that key's own record (read_records' rule): a copied, renamed or
        # key-less one is recomputed, and so overwritten
        if isinstance(rec, dict) and rec.get("key") == p.stem and rec.get("status") == "ok":
            done.add(p.stem)
    return done


# -- the worker side ------------------------------------------------------------------------------

_original_soft_as: int | None = None


def _limit_worker(memory_limit_mb: int | None) -> None:
    """In a worker process, before each task: one thread per library, and the address-space
    cap of this run (set every time: a reused loky worker may have served another run)."""
    global _original_soft_as
    import resource

    for var in _THREAD_VARS:
        os.environ[var] = "1"
    if "torch" in sys.modules:
        sys.modules["torch"].set_num_threads(1)
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    if _original_soft_as is None:
        _original_soft_as = soft
    want = _original_soft_as
    if memory_limit_mb:
        want = int(memory_limit_mb) * 1024 * 1024
        if hard != resource.RLIM_INFINITY:
            want = min(want, hard)
    if want != soft:
        resource.setrlimit(resource.RLIMIT_AS, (want, hard))


def _attempt(fn: Callable[[str], Any], key: str, retries: int, memory_limit_mb: int | None,
             limit_process: bool) -> dict:
    """Run ``fn(key)`` up to ``1 + retries`` times; return the record (never raises)."""
    from threadpoolctl import threadpool_limits

    if limit_process:
        _limit_worker(memory_limit_mb)
    t0, c0 = time.perf_counter(), time.process_time()
    error = ""
    for attempt in range(1, retries + 2):
        try:
            with threadpool_limits(1):
                result = fn(key)
            return {"key": key, "status": "ok", "attempts": attempt,
                    "seconds": time.perf_counter() - t0, "cpu_s": time.process_time() - c0,
                    "result": result}
        except Exception as err:  # noqa: BLE001 - any task error becomes a failed record
            tb = traceback.extract_tb(err.__traceback__)
            where = f" (at {Path(tb[-1].filename).name}:{tb[-1].lineno})" if tb else ""
            error = f"{type(err).__name__}: {err}{where}"
    return {"key": key, "status": "failed", "attempts": retries + 1,
            "seconds": time.perf_counter() - t0, "cpu_s": time.process_time() - c0, "error": error}


# -- the driver -----------------------------------------------------------------------------------

def _check_keys(keys: Iterable) -> list[str]:
    # a string was run as one key per letter, None was a bare "'NoneType' object is not iterable"
    if isinstance(keys, (str, bytes)) or not isinstance(keys, Iterable):
        raise WoodcamError(f"keys must be an iterable of keys (a list of str); got {keys!r:.60}"
                           + (f"; pass [{keys!r}]" if isinstance(keys, str) else ""))
    keys = [str(k) for k in keys]
    bad = [k for k in keys if not _KEY_RE.match(k)]
    if bad:
        raise WoodcamError(f"keys must be file-name safe (letters, digits, '_', '.', '-', not "
                           f"starting with '.', at most 200 characters); got {bad[0]!r}")
    if len(set(keys)) != len(keys):
        dup = next(k for k in keys if keys.count(k) > 1)
        raise WoodcamError(f"keys must be unique; {dup!r} appears more than once")
    return keys


def check_address(address: str, name: str = "address") -> str:
    """``address`` if it is a Dask scheduler address (``tcp://HOST:PORT``, or another of Dask's
    protocols), else a WoodcamError naming ``name`` (the CLI's ``--address``)."""
    if not isinstance(address, str) or not re.match(r"^(tcp|tls|inproc|ucx|ws|wss)://[^\s/]+$", address):
        raise WoodcamError(f"{name} must be a Dask scheduler address like tcp://HOST:8786; got "
                           f"{address!r}")
    return address


def run_many(fn: Callable[[str], Any], keys: Iterable, out_dir: str | Path, engine: Engine = "local",
             address: str | None = None, workers: int | None = None, retries: int = 2, *,
             memory_limit_mb: int | None = DEFAULT_MEMORY_LIMIT_MB, progress: bool = True,
             connect_timeout_s: float = CONNECT_TIMEOUT_S, desc: str = "tasks",
             unit: str = "task") -> RunSummary:
    """Run ``fn(key)`` for every key not already done, writing one record per key.

    Parameters
    ----------
    fn : callable ``key (str) -> JSON-serialisable``
        Picklable; deterministic in its key (see the module docstring).
    keys : iterable of str
        File-name safe, unique; records are ``out_dir/records/<key>.json``.
    out_dir : folder (created)
    engine : "local" | "dask"
    address : str, optional
        ``engine="dask"`` only: a running scheduler (``tcp://host:port``); unreachable within
        ``connect_timeout_s`` (default :data:`CONNECT_TIMEOUT_S`) seconds gives a
        :class:`WoodcamError`.
    workers : int, optional
        Worker processes (local: default 2, 1 = serial in this process; dask without address:
        default 2). With an address the cluster sets it; passing it is an error.
    retries : int
        Extra attempts of a task that raises, before its failed record is written.
    memory_limit_mb : int or None
        Per worker (MiB): an address-space cap of each local worker process, the
        ``memory_limit`` of each LocalCluster worker. None: no cap.
    progress : bool
        A tqdm bar with rate and ETA on stderr (on a terminal: woodcam._progress).
    desc, unit : str
        The bar's description, and what one key is to the user, singular ("block"): the bar's
        unit and :meth:`RunSummary.line`'s count ("2 blocks: ...").

    Returns
    -------
    RunSummary
    """
    if not callable(fn):  # None ran and wrote a 'failed' record ("'NoneType' object is not callable") per key
        raise WoodcamError(f"fn must be a callable key (str) -> JSON-serialisable; got {type(fn).__name__}")
    if engine not in ENGINES:
        raise WoodcamError(f"engine must be one of {', '.join(ENGINES)}; got {engine!r}")
    # retries=True and workers=True were taken as 1, memory_limit_mb='1e3' was a bare TypeError
    retries = int(check_number(retries, "retries", lo=0, integer=True, fix="tries after a failure, e.g. 2"))
    if workers is not None:
        workers = int(check_number(workers, "workers", lo=1, integer=True, fix="worker processes, or None"))
    if memory_limit_mb is not None:
        check_number(memory_limit_mb, "memory_limit_mb", lo=WORKER_MEMORY_MB_RANGE[0],
                     fix="MiB per worker (a Python worker alone needs ~100 MiB), or None")
    progress = check_bool(progress, "run_many: progress")
    if not isinstance(unit, str) or not unit.strip():  # the summary line would count in it
        raise WoodcamError(f"unit must be a word naming one key, e.g. 'block'; got {unit!r}")
    # NaN or -1 was taken, and handed to Dask's Client(timeout=...) as it was
    connect_timeout_s = check_number(connect_timeout_s, "connect_timeout_s", lo=0, lo_open=True,
                                     fix=f"seconds to wait for a Dask scheduler, e.g. {CONNECT_TIMEOUT_S:g}")
    if address is not None:
        if engine != "dask":
            raise WoodcamError(f"address applies to engine='dask' only; got engine={engine!r} "
                               f"with address={address!r}")
        check_address(address)
        if workers is not None:
            raise WoodcamError(f"workers cannot be set with an address: the cluster at {address} "
                               f"has its own workers; got workers={workers!r}")
    keys = _check_keys(keys)
    from ._atomic import output_folder

    out_dir = check_path(out_dir, "run_many: out_dir", fix="the run folder, e.g. 'runs/bench'")
    output_folder(out_dir / RECORDS_DIR, "run_many: out_dir")
    for stale in (out_dir / RECORDS_DIR).glob(".*.tmp*"):  # temp files of a killed run
        stale.unlink(missing_ok=True)
    done_before = _finished_keys(out_dir)
    todo = [k for k in keys if k not in done_before]
    skipped = len(keys) - len(todo)

    client = cluster = scratch = None
    if todo and engine == "dask":  # connect first: a bad address fails before any progress bar
        client, cluster, scratch = _dask_client(address, workers, memory_limit_mb, connect_timeout_s)

    from ._progress import progress_bar

    bar = progress_bar(total=len(keys), initial=skipped, desc=desc, unit=unit, smoothing=0.1,
                       enabled=progress, dynamic_ncols=True)
    counts = {"ok": 0, "failed": 0}
    first_failure: list[str] = []

    def finish(rec: dict) -> None:
        write_json_atomic(record_path(out_dir, rec["key"]), rec)
        counts[rec["status"]] += 1
        if rec["status"] == "failed" and not first_failure:
            first_failure.append(f"{rec['key']} failed: {rec.get('error', 'no error recorded')}")
        bar.update(1)
        if counts["failed"]:
            bar.set_postfix(failed=counts["failed"], refresh=False)

    t0 = time.perf_counter()
    n_workers = 0
    try:
        if not todo:
            n_workers = 0
        elif engine == "local":
            n_workers = 2 if workers is None else workers
            _run_local(fn, todo, n_workers, retries, memory_limit_mb, finish)
        else:
            n_workers = _run_dask(client, fn, todo, retries, finish)
    finally:
        bar.close()
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
        if scratch is not None:
            shutil.rmtree(scratch, ignore_errors=True)
    return RunSummary(out_dir, engine, n_workers, len(keys), skipped, counts["ok"],
                      counts["failed"], time.perf_counter() - t0, "".join(first_failure), unit)


def _run_local(fn, todo, n_workers, retries, memory_limit_mb, finish) -> None:
    if n_workers == 1:  # the serial baseline: this process, no pool, no cap on the caller
        from threadpoolctl import threadpool_limits

        with threadpool_limits(1):
            for key in todo:
                finish(_attempt(fn, key, retries, None, False))
        return
    from joblib import Parallel, delayed, parallel_config
    from joblib.externals.loky.process_executor import TerminatedWorkerError

    # inner_max_num_threads=1 sets the thread variables (BLAS, OpenMP, numba) in each worker
    # before it imports anything; generator_unordered hands results back as they finish.
    try:
        with parallel_config(backend="loky", inner_max_num_threads=1):
            for rec in Parallel(n_jobs=n_workers, return_as="generator_unordered", batch_size=1,
                                pre_dispatch=f"{2 * n_workers}")(
                    delayed(_attempt)(fn, key, retries, memory_limit_mb, True) for key in todo):
                finish(rec)
    except TerminatedWorkerError as err:
        raise WoodcamError(
            f"a local worker process died ({str(err).splitlines()[0]}); the records written so "
            f"far are kept: run the same command again to resume, or lower the worker count "
            f"or raise the memory limit") from err


def _dask_client(address, workers, memory_limit_mb, connect_timeout_s):
    """``(client, cluster or None, scratch directory or None)``: a client of the scheduler at
    ``address``, or of a new loopback LocalCluster of ``workers`` single-threaded processes."""
    from .errors import require

    require("distributed", "scale", "running tasks on Dask")
    import dask
    from distributed import Client, LocalCluster

    if address is None:
        # the workers' spill and lock files in a directory of this run, removed with the cluster:
        # dask's default, dask-scratch-space in the shared temp directory, outlived every run
        scratch = tempfile.mkdtemp(prefix="woodcam-dask-")
        cluster = None
        try:
            with dask.config.set({"temporary-directory": scratch}):  # the scheduler's, made in this process
                cluster = LocalCluster(
                    n_workers=2 if workers is None else workers, threads_per_worker=1, processes=True,
                    host="127.0.0.1", dashboard_address=None, local_directory=scratch,
                    memory_limit=f"{memory_limit_mb}MiB" if memory_limit_mb else 0,
                    # the cluster's own log lines (and its shutdown races) would bury the progress bar;
                    # a task's errors come back in its record, a lost worker as a failed record
                    silence_logs=logging.CRITICAL)
            return Client(cluster), cluster, scratch
        except BaseException:  # a cluster or client that failed to start leaves no process or file behind
            if cluster is not None:
                cluster.close()
            shutil.rmtree(scratch, ignore_errors=True)
            raise
    try:
        return Client(address, timeout=connect_timeout_s), None, None
    except (OSError, TimeoutError) as err:
        raise WoodcamError(
            f"address: no Dask scheduler answered at {address} within {connect_timeout_s:g} s "
            f"({type(err).__name__}); start one with `dask scheduler` and `dask worker "
            f"{address}`, or leave --address out to run a local 2-worker cluster") from err


def _run_dask(client, fn, todo, retries, finish) -> int:
    """Submit ``todo`` to ``client`` with a bounded window of futures; returns the worker count."""
    from distributed import as_completed

    n = len(client.nthreads())
    window = max(4 * max(n, 1), 16)  # bounded in-flight futures, so 1e5 keys stay cheap
    it = iter(todo)
    pending = as_completed()
    key_of = {}

    def submit(key):
        # limit_process: one torch thread (the nanny already sets OMP/BLAS variables to 1); the
        # memory cap is the nanny's memory_limit, not an rlimit on someone else's worker.
        fut = client.submit(_attempt, fn, key, retries, None, True, pure=False,
                            key=f"woodcam-{key}-{os.getpid()}-{time.time_ns()}")
        key_of[fut.key] = key
        pending.add(fut)

    for key in [k for _, k in zip(range(window), it)]:
        submit(key)
    for fut in pending:
        key = key_of.pop(fut.key)
        try:
            rec = fut.result()
        except Exception as err:  # noqa: BLE001 - a worker lost (KilledWorker), cancelled
            rec = {"key": key, "status": "failed", "attempts": 1, "seconds": 0.0, "cpu_s": 0.0,
                   "error": f"{type(err).__name__}: {err}"}
        fut.release()
        finish(rec)
        nxt = next(it, None)
        if nxt is not None:
            submit(nxt)
    return n


__all__ = ["DEFAULT_MEMORY_LIMIT_MB", "ENGINES", "Engine", "RECORDS_DIR", "RunSummary",
           "check_address", "check_run_manifest", "read_records", "record_path", "run_many", "write_json_atomic"]
