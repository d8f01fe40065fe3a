"""The task runner (woodcam.scale) and the bench at scale (woodcam.benchmark): determinism across
engines and worker counts, resuming after kill -9, a separate Dask scheduler, failures, reports.

Worker processes are started by the code under test (loky, LocalCluster) or by these tests
(``dask scheduler`` / ``dask worker``), always on 127.0.0.1, and killed by their process group.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from functools import partial
from pathlib import Path

import numpy as np
import pytest

import _scale_tasks as tasks
from woodcam.errors import WoodcamError, WoodcamWarning
from woodcam.scale import RECORDS_DIR, read_records, run_many

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]

#: A bench small enough for the default run (~5 CPU-s a pass): 30 mm cubes, the radial fit from
#: six faces; with seed 1 block 0 is clear and block 1 knotted.
TINY = {"methods": ["radial"], "face_sets": {"full": None}, "size_mm": [30.0, 30.0, 30.0], "face_px": 96}


def _env() -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(REPO), str(HERE), env.get("PYTHONPATH", "")])
    return env


def _kill_group(proc: subprocess.Popen) -> None:
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGKILL)
    proc.wait(timeout=30)


# -- determinism ----------------------------------------------------------------------------------

def test_bench_metrics_identical_on_every_engine_and_worker_count(tmp_path):
    from woodcam.benchmark import bench_block, bench_settings, run_bench

    runs = {}
    for name, kw in {"local-1": dict(engine="local", workers=1),
                     "local-2": dict(engine="local", workers=2),
                     "dask-2": dict(engine="dask", workers=2)}.items():
        s = run_bench(tmp_path / name, 2, seed=1, settings=TINY, progress=False, **kw)
        assert (s.done, s.failed, s.skipped) == (2, 0, 0), name
        recs = read_records(tmp_path / name)
        runs[name] = {k: (r["result"]["kind"], r["result"]["metrics"]) for k, r in recs.items()}
    assert [runs["local-1"][k][0] for k in sorted(runs["local-1"])] == ["clear", "knotted"]
    assert runs["local-1"] == runs["local-2"] == runs["dask-2"]  # exact floats, not approx
    # and equal to the task computed directly in this process
    direct = bench_block(1, 1, bench_settings(**TINY))
    assert direct["metrics"] == runs["dask-2"]["b000001"][1]
    # the metrics are real: the clear block is fitted perfectly, the knotted one is not
    assert runs["local-1"]["b000000"][1]["full"]["radial"]["matched_1"] > 95.0
    assert runs["local-1"]["b000001"][1]["full"]["radial"]["matched_1"] < 80.0


def test_rerun_with_other_settings_is_refused(tmp_path):
    from woodcam.benchmark import run_bench

    tiny = {**TINY, "knotted_fraction": 0.0}
    run_bench(tmp_path, 1, seed=4, settings=tiny, engine="local", workers=1, progress=False)
    with pytest.raises(WoodcamError, match="another seed or settings"):
        run_bench(tmp_path, 1, seed=5, settings=tiny, engine="local", workers=1, progress=False)


def test_the_same_methods_in_another_order_resume_the_run(tmp_path):
    """``--methods rbf,radial`` into a run made with ``radial,rbf`` was refused as other
    settings; the order is no setting: the run resumes in its recorded order."""
    from woodcam.benchmark import RUN_MANIFEST, run_bench

    tiny = {**TINY, "knotted_fraction": 0.0, "face_px": 32}
    kw = dict(engine="local", workers=1, progress=False)
    run_bench(tmp_path, 1, seed=4, settings={**tiny, "methods": ["radial", "rbf"]}, **kw)
    s = run_bench(tmp_path, 1, seed=4, settings={**tiny, "methods": ["rbf", "radial"]}, **kw)
    assert (s.skipped, s.done) == (1, 0)
    assert json.loads((tmp_path / RUN_MANIFEST).read_text())["settings"]["methods"] == ["radial", "rbf"]
    with pytest.raises(WoodcamError, match=r"settings.methods \['radial', 'rbf'\] there, \['rbf'\] now"):
        run_bench(tmp_path, 1, seed=4, settings={**tiny, "methods": ["rbf"]}, **kw)


# -- resuming after kill -9 -----------------------------------------------------------------------

def test_kill9_mid_run_then_rerun_recomputes_nothing_and_loses_nothing(tmp_path):
    out, log = tmp_path / "run", tmp_path / "log"
    log.mkdir()
    keys = [f"k{i}" for i in range(16)]
    script = (f"from functools import partial; from woodcam.scale import run_many; import _scale_tasks as t; "
              f"run_many(partial(t.slow, log_dir={str(log)!r}, sleep_s=0.4), {keys!r}, {str(out)!r}, "
              f"workers=2, progress=False)")
    proc = subprocess.Popen([sys.executable, "-c", script], env=_env(), start_new_session=True)
    try:
        deadline = time.monotonic() + 240
        while time.monotonic() < deadline:
            n = len(list((out / RECORDS_DIR).glob("[!.]*.json"))) if (out / RECORDS_DIR).is_dir() else 0
            if n >= 4 or proc.poll() is not None:
                break
            time.sleep(0.05)
    finally:
        _kill_group(proc)  # SIGKILL to the driver and its worker processes
    assert proc.returncode == -signal.SIGKILL, "the run finished before it could be killed"
    before = read_records(out)  # every record parses: none is partial
    assert 4 <= len(before) < len(keys)
    for k, r in before.items():
        assert r["status"] == "ok" and r["result"]["value"] == tasks.value_of(k)
    markers_before = set(p.name for p in log.iterdir())

    s = run_many(partial(tasks.slow, log_dir=str(log), sleep_s=0.0), keys, out, workers=2, progress=False)
    assert (s.skipped, s.done, s.failed) == (len(before), len(keys) - len(before), 0)
    new = [p.name.split(".")[0] for p in log.iterdir() if p.name not in markers_before]
    assert not set(new) & set(before), "finished keys were computed again"
    assert sorted(new) == sorted(set(keys) - set(before))
    after = read_records(out)
    assert sorted(after) == sorted(keys)
    assert all(after[k]["result"]["value"] == tasks.value_of(k) for k in keys)
    assert {k: after[k] for k in before} == before  # old records untouched
    assert not [p for p in (out / RECORDS_DIR).iterdir() if p.name.startswith(".")]


# -- failures -------------------------------------------------------------------------------------

#: The line of _scale_tasks.py whose raise a failed record names.
_FLAKY_RAISES_AT = next(i for i, line in enumerate(Path(tasks.__file__).read_text().splitlines(), 1)
                        if "refuses on purpose" in line)

@pytest.mark.parametrize("engine,workers", [("local", 1), ("local", 2)])
def test_raising_task_is_retried_then_recorded_failed_and_the_run_goes_on(tmp_path, engine, workers):
    log = tmp_path / "log"
    log.mkdir()
    keys = [f"k{i}" for i in range(6)]
    s = run_many(partial(tasks.flaky, log_dir=str(log)), keys, tmp_path / "run", engine=engine,
                 workers=workers, retries=2, progress=False)
    assert (s.done, s.failed) == (5, 1)
    recs = read_records(tmp_path / "run")
    bad = recs["k3"]
    assert bad["status"] == "failed" and bad["attempts"] == 3
    assert bad["key"] == "k3" and "ValueError: task k3 refuses on purpose" in bad["error"]
    assert len([p for p in log.iterdir() if p.name.startswith("k3.")]) == 3  # really tried 3 times
    assert all(recs[k]["status"] == "ok" for k in keys if k != "k3")
    # a failed key is tried again on the next run; the finished ones are not
    s2 = run_many(partial(tasks.flaky, log_dir=str(log)), keys, tmp_path / "run", engine=engine,
                  workers=workers, retries=0, progress=False)
    assert (s2.skipped, s2.done, s2.failed) == (5, 0, 1)
    # the summary line says why, not only how many: the error was in the hidden record only
    assert s.line().endswith(f"records in {tmp_path / 'run' / RECORDS_DIR}; k3 failed: ValueError: task k3 "
                             f"refuses on purpose (at _scale_tasks.py:{_FLAKY_RAISES_AT})"), s.line()


def test_memory_limit_per_local_worker(tmp_path):
    s = run_many(partial(tasks.hog, mb=1500), ["k0"], tmp_path / "big", workers=2, retries=0,
                 memory_limit_mb=1024, progress=False)
    assert s.failed == 1
    assert read_records(tmp_path / "big")["k0"]["error"].startswith("MemoryError")
    s = run_many(partial(tasks.hog, mb=50), ["k0"], tmp_path / "small", workers=2, retries=0,
                 memory_limit_mb=1024, progress=False)
    assert s.done == 1
    # the same (reused) worker processes, a larger limit: the big task fits now
    s = run_many(partial(tasks.hog, mb=1500), ["k0"], tmp_path / "big2", workers=2, retries=0,
                 memory_limit_mb=4096, progress=False)
    assert s.done == 1


def test_local_dask_cluster_leaves_nothing_in_the_temp_directory(tmp_path, monkeypatch):
    # dask's default scratch space (dask-scratch-space with its lock files) outlived every run
    import tempfile

    temp = tmp_path / "temp"
    temp.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(temp))
    s = run_many(tasks.value_of, ["k1", "k2", "k3"], tmp_path / "run", engine="dask", workers=2, progress=False)
    assert (s.done, s.failed) == (3, 0)
    assert [r["result"] for r in read_records(tmp_path / "run").values()] == [tasks.value_of(k) for k in ("k1", "k2", "k3")]
    assert list(temp.iterdir()) == []


def test_unreachable_address_is_one_clear_error(tmp_path):
    with pytest.raises(WoodcamError, match=r"address: no Dask scheduler answered at tcp://127\.0\.0\.1:9"):
        run_many(tasks.value_of, ["k1"], tmp_path, engine="dask", address="tcp://127.0.0.1:9",
                 connect_timeout_s=2.0, progress=False)


def test_cli_bad_address_prints_one_line(tmp_path):
    r = subprocess.run([sys.executable, "-m", "woodcam.cli", "block", "synth", "--count", "1", "--out",
                        str(tmp_path), "--engine", "dask", "--address", "tcp://127.0.0.1:9",
                        "--connect-timeout-s", "2"],
                       env=_env(), capture_output=True, text=True, timeout=120)
    from woodcam.cli import EXIT_ERROR

    assert r.returncode == EXIT_ERROR
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("woodcam: error: address: no Dask scheduler"), r.stderr


@pytest.mark.parametrize("kwargs,match", [
    (dict(engine="spark"), "engine must be one of local, dask; got 'spark'"),
    (dict(address="tcp://127.0.0.1:8786"), "address applies to engine='dask' only"),
    (dict(engine="dask", address="127.0.0.1:8786"), "address must be a Dask scheduler address"),
    (dict(engine="dask", address="tcp://127.0.0.1:8786", workers=2), "workers cannot be set"),
    (dict(workers=0), "workers must be an integer >= 1; got 0"),
    (dict(retries=-1), "retries must be an integer >= 0"),
    (dict(keys=["../x"]), "keys must be file-name safe"),
    (dict(keys=["a", "a"]), "keys must be unique"),
])
def test_bad_arguments(tmp_path, kwargs, match):
    keys = kwargs.pop("keys", ["k1"])
    with pytest.raises(WoodcamError, match=match):
        run_many(tasks.value_of, keys, tmp_path, progress=False, **kwargs)


# -- a real cluster: scheduler and worker as separate processes -----------------------------------

def test_separate_dask_scheduler_and_worker_serve_a_run(tmp_path):
    dask = Path(sys.executable).with_name("dask")
    if not dask.exists():
        pytest.skip(f"the dask command is not installed next to {sys.executable}")
    sched_file = tmp_path / "scheduler.json"
    procs = []
    try:
        procs.append(subprocess.Popen(
            [str(dask), "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
             "--scheduler-file", str(sched_file)], env=_env(), start_new_session=True,
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        deadline = time.monotonic() + 120
        while not sched_file.exists() and time.monotonic() < deadline:
            time.sleep(0.1)
        address = json.loads(sched_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        procs.append(subprocess.Popen(
            [str(dask), "worker", address, "--nworkers", "1", "--nthreads", "1", "--host", "127.0.0.1",
             "--no-dashboard", "--memory-limit", "2GiB"], env=_env(), start_new_session=True,
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        from distributed import Client

        with Client(address, timeout=60) as c:
            c.wait_for_workers(1, timeout=120)
        s = run_many(tasks.where, [f"k{i}" for i in range(4)], tmp_path / "run", engine="dask",
                     address=address, progress=False)
        assert (s.done, s.failed, s.workers) == (4, 0, 1)
        recs = read_records(tmp_path / "run")
        pids = {r["result"]["pid"] for r in recs.values()}
        assert len(pids) == 1 and os.getpid() not in pids  # ran on the separate worker
        assert all(recs[k]["result"]["value"] == tasks.value_of(k) for k in recs)

        # the CLI with --address: a block set, the same blocks as the serial generator
        from woodcam.cli import main
        from woodcam.synth import synth_benchmark_set

        assert main(["block", "synth", "--count", "2", "--seed", "7", "--face-px", "48", "--out",
                     str(tmp_path / "set"), "--engine", "dask", "--address", address, "--quiet"]) == 0
        synth_benchmark_set(tmp_path / "ref", 2, 7, face_px=48, progress=False,
                            log_fields=__import__("woodcam.synth", fromlist=["x"]).knotted_log_field)
        got, ref = (json.loads((tmp_path / d / "index.json").read_text()) for d in ("set", "ref"))
        assert got["blocks"] == ref["blocks"]
        from woodcam.block.io import read_block

        for name in ("block_0000", "block_0001"):
            a, b = read_block(tmp_path / "set" / name), read_block(tmp_path / "ref" / name)
            for f in a.faces:
                np.testing.assert_array_equal(a.faces[f].photo, b.faces[f].photo)
                assert [t.year for t in a.faces[f].traces] == [t.year for t in b.faces[f].traces]
    finally:
        for p in reversed(procs):
            _kill_group(p)


# -- the report -----------------------------------------------------------------------------------

def _fake_records(tmp_path, n=10):
    """Records of a run where rbf beats radial on every block, by 1 + 0.1 i points (no ties)."""
    from woodcam.benchmark import DEFAULT_SETTINGS, RUN_MANIFEST
    from woodcam.scale import record_path, write_json_atomic

    (tmp_path / RECORDS_DIR).mkdir(parents=True)
    write_json_atomic(tmp_path / RUN_MANIFEST, {"seed": 0, "settings": {**DEFAULT_SETTINGS,
                                                                        "methods": ["radial", "rbf"]}})
    rng = np.random.default_rng(0)
    for i in range(n):
        base = {k: float(rng.uniform(50, 90)) for k in ("matched_1", "matched_2", "unmatched_1",
                                                          "unmatched_2", "coverage_1")}
        met = {label: {"radial": dict(base), "rbf": {k: v + 1.0 + 0.1 * i for k, v in base.items()}}
               for label in ("full", "partial")}
        write_json_atomic(record_path(tmp_path, f"b{i:06d}"), {
            "key": f"b{i:06d}", "status": "ok", "attempts": 1, "seconds": 2.0, "cpu_s": 1.5,
            "result": {"seed": 0, "index": i, "kind": "clear" if i % 2 else "knotted", "params": {},
                       "metrics": met, "timing": {}}})
    return tmp_path


def test_report_statistics_known_answers(tmp_path):
    from woodcam.benchmark import summarise_bench

    s = summarise_bench(read_records(_fake_records(tmp_path)))
    t = s["tests"]["full"]["all"]["radial vs rbf"]["matched_1"]
    # 10 paired differences, all negative: the exact two-sided signed-rank p is 2 / 2**10
    assert t["n"] == 10 and t["mean_diff"] == pytest.approx(-1.45)
    assert t["p"] == pytest.approx(2 / 2 ** 10)
    m, lo, hi = s["table"]["full"]["all"]["radial"]["matched_1"]
    vals = [r["result"]["metrics"]["full"]["radial"]["matched_1"] for r in read_records(tmp_path).values()]
    assert m == pytest.approx(np.mean(vals)) and lo < m < hi
    # a 95 % interval: for these ten near-uniform values the percentile bootstrap is the normal
    # interval mean +- 1.96 sd / sqrt(n) to 2 % (a 90 % or 99 % interval is 16 % or 31 % off)
    for k in ("matched_1", "matched_2", "unmatched_1", "coverage_1"):
        vals = [r["result"]["metrics"]["full"]["radial"][k] for r in read_records(tmp_path).values()]
        m, lo, hi = s["table"]["full"]["all"]["radial"][k]
        assert (hi - lo) / (2 * 1.96 * np.std(vals) / np.sqrt(len(vals))) == pytest.approx(1.0, abs=0.08), k
    vals = [r["result"]["metrics"]["full"]["radial"]["matched_1"] for r in read_records(tmp_path).values()]
    assert s["table"]["full"]["clear"]["rbf"]["n"] == 5
    assert s["worst"]["full"]["radial"][0]["matched_1"] == pytest.approx(min(vals))
    assert s["cpu_hours_per_1e5"] == pytest.approx(1.5 * 1e5 / 3600)


def test_a_copied_renamed_or_foreign_record_is_named_not_merged(tmp_path):
    """A record file copied beside its original, renamed to another key, without a key, or
    from another seed's run: the report names the file (it was silently merged into its key,
    counted as the wrong block, or a KeyError)."""
    import shutil

    from woodcam.benchmark import bench_report

    rec = lambda run, name: run / RECORDS_DIR / name  # noqa: E731
    cases = {
        "copy": lambda run: shutil.copy(rec(run, "b000001.json"), rec(run, "b000001 (copy).json")),
        "renamed": lambda run: shutil.copy(rec(run, "b000001.json"), rec(run, "b000011.json")),
        "no key": lambda run: rec(run, "b000002.json").write_text('{"status": "ok"}'),
        "other seed": lambda run: rec(run, "b000003.json").write_text(
            rec(run, "b000003.json").read_text().replace('"seed":0', '"seed":7')),
    }
    named = {"copy": "b000001 (copy).json", "renamed": "b000011.json", "no key": "b000002.json",
             "other seed": "b000003.json"}
    for case, spoil in cases.items():
        run = _fake_records(tmp_path / case.replace(" ", "_"))
        spoil(run)
        with pytest.raises(WoodcamError, match="delete it and re-run") as err:
            bench_report(run, tmp_path / "rep", gallery=0, thumbnails=0, progress=False)
        assert named[case] in str(err.value), case
    # and a run does not take the key-less record for a finished block: re-running recomputes it
    from woodcam.scale import _finished_keys

    assert "b000002" not in _finished_keys(tmp_path / "no_key")
    assert "b000001" in _finished_keys(tmp_path / "no_key")


def _spoil_record(run, key, edit):
    path = run / RECORDS_DIR / f"{key}.json"
    rec = json.loads(path.read_text())
    edit(rec)
    path.write_text(json.dumps(rec))


@pytest.mark.parametrize("spoil, said", [
    (lambda run: (run / "run.json").write_text("{"), r"bench run manifest '.*run.json' must be valid JSON"),
    (lambda run: (run / "run.json").write_text("[1]"), r"must be a JSON object with the run's seed"),
    (lambda run: _spoil_record(run, "b000001", lambda r: r.update(result=5)), r"b000001.json is no block result"),
    (lambda run: _spoil_record(run, "b000001", lambda r: r["result"].pop("metrics")), r"its metrics must map"),
    (lambda run: _spoil_record(run, "b000001", lambda r: r["result"]["metrics"]["full"]["rbf"].update(matched_1="x")),
     r"full/rbf must hold an error or the finite scores matched_1, "),
    (lambda run: _spoil_record(run, "b000001", lambda r: r["result"]["metrics"].pop("partial")),
     r"it scores \[\('full', \['radial', 'rbf'\]\)\], the run's first record"),
    (lambda run: _spoil_record(run, "b000001", lambda r: r["result"].update(kind="burl")), r"kind must be 'clear' or"),
])
def test_a_malformed_run_manifest_or_record_is_named_not_an_internal_error(tmp_path, spoil, said):
    """'woodcam bench report' of a run whose run.json was '{' or a list, or whose record held a
    number for its result, lacked metrics or a face set, or a word for a score: JSONDecodeError,
    TypeError, AttributeError or KeyError, "internal error ... this is a woodcam bug" (sweep h4)."""
    from woodcam.benchmark import bench_report

    run = _fake_records(tmp_path / "run")
    spoil(run)
    with pytest.raises(WoodcamError, match=said) as err:
        bench_report(run, tmp_path / "rep", gallery=0, thumbnails=0, progress=False)
    assert "woodcam bench run" in str(err.value), err.value


def test_report_on_a_real_run_writes_tables_and_gallery(tmp_path):
    from woodcam.benchmark import bench_report, run_bench

    run_bench(tmp_path / "run", 2, seed=1, settings=TINY, engine="local", workers=1, progress=False)
    s = bench_report(tmp_path / "run", tmp_path / "rep", gallery=1, thumbnails=0, progress=False)
    md = (tmp_path / "rep" / "report.md").read_text()
    assert "seed 1, 2 blocks (1 clear, 1 knotted)" in md and "| radial |" in md
    assert s["gallery"] == [1]  # the knotted block is the worst
    # the report files say which blocks the gallery draws (only the returned dict did)
    assert json.loads((tmp_path / "rep" / "report.json").read_text())["gallery"] == [1]
    assert "- b000001: cut planes `gallery/b000001_<face set>.png`" in md
    for f in ("report.json", "table1.png", "gallery/b000001_full.png", "gallery/b000001_faces.png"):
        assert (tmp_path / "rep" / f).stat().st_size > 1000, f


def test_a_report_into_an_earlier_reports_folder_leaves_one_set(tmp_path, monkeypatch):
    """A report written where an earlier one lies kept the earlier gallery's pictures beside
    its own (a reader took them for this report's blocks); a report that fails half-way leaves
    the earlier one whole."""
    import importlib

    bm = importlib.import_module("woodcam.benchmark")  # woodcam.benchmark is also a function
    from woodcam.scale import record_path, write_json_atomic

    run, rep = tmp_path / "run", tmp_path / "rep"
    (run / RECORDS_DIR).mkdir(parents=True)
    write_json_atomic(run / bm.RUN_MANIFEST, {"seed": 0, "settings": bm.bench_settings(
        **{**TINY, "face_px": 32, "knotted_fraction": 0.0})})
    for i in range(2):
        met = {"full": {"radial": {k: 50.0 + i for k in bm.METRICS}}}
        write_json_atomic(record_path(run, f"b{i:06d}"), {
            "key": f"b{i:06d}", "status": "ok", "attempts": 1, "seconds": 2.0, "cpu_s": 1.5,
            "result": {"seed": 0, "index": i, "kind": "clear", "params": {}, "metrics": met,
                       "timing": {}}})
    bm.bench_report(run, rep, gallery=0, thumbnails=2, progress=False)
    assert sorted(p.name for p in (rep / "gallery").iterdir()) == [
        ".woodcam-benchmark-gallery-files.json", "b000000_faces.png", "b000001_faces.png"]
    with pytest.warns(WoodcamWarning, match=r"removed 1 file\(s\) of an earlier run .*: b000001_faces\.png$"):
        bm.bench_report(run, rep, gallery=0, thumbnails=1, progress=False)  # says what it removed
    assert sorted(p.name for p in (rep / "gallery").iterdir()) == [
        ".woodcam-benchmark-gallery-files.json", "b000000_faces.png"]
    md = (rep / "report.md").read_text()

    def broken(*a, **k):
        raise WoodcamError("interrupted")

    monkeypatch.setattr(bm, "bench_gallery", broken)
    monkeypatch.setattr(bm, "_markdown", lambda *a: "another report")
    with pytest.raises(WoodcamError, match="interrupted"):
        bm.bench_report(run, rep, gallery=0, thumbnails=1, progress=False)
    assert (rep / "report.md").read_text() == md
    assert sorted(p.name for p in rep.rglob("*") if p.is_file()) == [
        ".woodcam-benchmark-gallery-files.json", "b000000_faces.png", "report.json", "report.md",
        "table1.png"]


# -- training sets --------------------------------------------------------------------------------

def test_training_set_in_shards_is_bit_identical_and_trains_the_same(tmp_path):
    import torch

    from woodcam.benchmark import make_training_set_many
    from woodcam.cli import main
    from woodcam.fields.neural import GTFSpec, make_training_set

    spec = GTFSpec(n_fields=40, points_per_field=50, steps=3, batch_fields=8, checkpoint_every=10,
                   log_every=1)
    pts, vals = make_training_set_many(spec, tmp_path / "shards", shard_fields=16, engine="local",
                                       workers=2, progress=False)
    ref = make_training_set(spec)
    assert len(list((tmp_path / "shards").glob("shard_*.npz"))) == 3
    np.testing.assert_array_equal(pts, ref[0])
    np.testing.assert_array_equal(vals, ref[1])
    # `woodcam train gtf --engine` trains the same weights as the plain command
    spec.save(tmp_path / "spec.json")
    for name, extra in (("plain", []), ("engine", ["--engine", "local", "--workers", "1"])):
        assert main(["train", "gtf", "--spec", str(tmp_path / "spec.json"), "--out",
                     str(tmp_path / name), *extra]) == 0
    a, b = (torch.load(tmp_path / n / "gtf.pt", weights_only=True) for n in ("plain", "engine"))
    assert all(torch.equal(a[k], b[k]) for k in a)
    assert (tmp_path / "engine" / "trainset" / "shard_0000.npz").exists()


def test_training_set_of_another_spec_is_refused_not_reused(tmp_path):
    """The shards of a training set were reused for a spec with another seed (another training
    set), silently; a spec that differs in the network only keeps them."""
    from dataclasses import replace

    from woodcam.benchmark import make_training_set_many
    from woodcam.fields.neural import GTFSpec, make_training_set

    spec = GTFSpec(n_fields=8, points_per_field=20, batch_fields=4)
    kw = dict(shard_fields=4, engine="local", workers=1, progress=False)
    make_training_set_many(spec, tmp_path / "ts", **kw)
    with pytest.raises(WoodcamError, match=r"another seed or settings \(spec.seed 0 there, 5 now\)"):
        make_training_set_many(replace(spec, seed=5), tmp_path / "ts", **kw)
    pts, vals = make_training_set_many(replace(spec, hidden=16), tmp_path / "ts", **kw)
    np.testing.assert_array_equal(vals, make_training_set(spec)[1])


@pytest.mark.parametrize("damage", ["truncated", "missing", "another shape"])
def test_a_broken_training_shard_is_made_again(tmp_path, damage):
    """A shard file cut, deleted or replaced after its record said "ok" ended 'woodcam train gtf
    --engine' as an internal error (numpy's BadZipFile, FileNotFoundError) on every rerun."""
    from woodcam._cache import CacheWarning
    from woodcam.benchmark import make_training_set_many
    from woodcam.fields.neural import GTFSpec, make_training_set

    spec = GTFSpec(n_fields=8, points_per_field=20, batch_fields=4)
    kw = dict(shard_fields=4, engine="local", workers=1, progress=False)
    make_training_set_many(spec, tmp_path / "ts", **kw)
    shard = tmp_path / "ts" / "shard_0001.npz"
    if damage == "truncated":
        shard.write_bytes(shard.read_bytes()[: shard.stat().st_size // 2])
    elif damage == "missing":
        shard.unlink()
    else:
        np.savez(shard, points=np.zeros((2, 20, 3), np.float32), values=np.zeros((2, 20), np.float32))
    with pytest.warns(CacheWarning, match=r"shard_0001.npz.*made the shard again"):
        pts, vals = make_training_set_many(spec, tmp_path / "ts", **kw)
    ref = make_training_set(spec)
    np.testing.assert_array_equal(pts, ref[0])
    np.testing.assert_array_equal(vals, ref[1])



def test_the_summary_counts_in_the_users_word(tmp_path):
    """'bench run --blocks 2' said "2 keys: ... with 2 worker(s)": keys are the records' file
    names, no word of the user's; the line counts in the run's unit, singular or plural."""
    from woodcam.scale import RunSummary

    def line(total, workers, **unit):
        return RunSummary(tmp_path, "local", workers, total, 0, total, 0, 1.0, **unit).line()

    assert line(2, 2, unit="block").startswith("2 blocks: 0 already done, 2 computed, 0 failed; "
                                               "1.0 s on local with 2 workers; ")
    assert line(1, 1, unit="shard").startswith("1 shard: 0 already done, 1 computed, 0 failed; "
                                               "1.0 s on local with 1 worker; ")
    assert line(3, 1).startswith("3 tasks: ")  # run_many's own default
    with pytest.raises(WoodcamError, match="unit must be a word naming one key"):
        run_many(str, ["a"], tmp_path / "run", unit="", progress=False)

def test_cli_bench_run_and_report(tmp_path, capsys):
    from woodcam.cli import main

    run, rep = str(tmp_path / "run"), str(tmp_path / "rep")
    assert main(["bench", "run", "--blocks", "1", "--seed", "4", "--methods", "radial", "--knotted-fraction",
                 "0", "--face-px", "64", "--workers", "1", "--quiet", "--out", run]) == 0
    # counted in blocks, the user's word (it said "1 keys", the records' file names)
    assert "1 block: 0 already done, 1 computed, 0 failed; " in capsys.readouterr().out
    assert main(["bench", "run", "--blocks", "1", "--seed", "4", "--methods", "radial", "--knotted-fraction",
                 "0", "--face-px", "64", "--workers", "1", "--quiet", "--out", run]) == 0
    assert "1 block: 1 already done, 0 computed" in capsys.readouterr().out
    assert main(["bench", "report", run, "--out", rep, "--gallery", "0", "--thumbnails", "0", "--quiet"]) == 0
    assert "1 blocks (1 clear, 0 knotted); full same year <= 1 mm: radial" in capsys.readouterr().out
    from woodcam.cli import EXIT_USAGE

    # a usage error naming the option, as fit's and eval's --methods (it was the library's
    # 'methods must be a comma-separated subset ...', exit 1)
    assert main(["bench", "run", "--blocks", "1", "--methods", "radial,splines", "--out", run]) == EXIT_USAGE
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["woodcam: error: --methods must be from evidence, rbf, radial, neural; got 'radial,splines', "
                   "in which 'splines' is none of them; e.g. --methods evidence,rbf"]
