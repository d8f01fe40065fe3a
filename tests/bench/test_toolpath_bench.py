"""Benchmark: the 20,100-move ball-end 3D raster over a 100 x 100 mm stock at 0.1 mm.

Run with ``pytest -m bench -s tests/bench/test_toolpath_bench.py``. Reports wall and CPU time,
moves/s and cell updates/s (cells covered by a swept tool and min-updated), and the
speed ratio against the exact manifold3d reference (hulls of the tool at both ends of every move,
unioned, subtracted from the box) on the same moves. The reference costs ~25 ms of CPU per
move, so by default it runs on the program's first ``WOODCAM_BENCH_REF_MOVES`` = 2,000 moves
(and the simulation is timed on the same prefix for the ratio); set it to ``all`` for the full
program (measured ~41 ms CPU per move at 2,000 and 4,000 moves, so ~14 minutes of CPU, and the
union held >11 GB of memory part-way through).
"""

from __future__ import annotations

import importlib.util
import os
import time
from pathlib import Path

import numpy as np
import pytest

from woodcam.toolpath import BallEndMill, Program, read_gcode, simulate
from woodcam.toolpath.reference import reference_stock

pytestmark = pytest.mark.bench
REPO = Path(__file__).resolve().parents[2]
SIZE = (100.0, 100.0, 30.0)

#: Bar on CPU(manifold3d reference) / CPU(height-field simulation) on the raster's first 2,000
#: moves. No target is stated; the bar was 5: measured 1028-1109x in three runs on the shared
#: 2-core machine at load ~5 (Dec 2026), divided by a 1.5x margin, so a simulation markedly
#: slower than today fails.
MIN_SIM_SPEEDUP_OVER_MANIFOLD = 680
#: Bar on woodcam's interpreter speed over LinuxCNC's (lines per CPU-s, same raster, same
#: run). No target is stated (DEVELOPERS.md reports the figure): measured 0.53-0.68 in
#: three runs on the shared 2-core machine at load ~5 (Dec 2026), divided by a 1.5x margin,
#: so an interpreter markedly slower than today (e.g. without its short path for plain
#: ``X.. Z.. F..`` lines) fails.
MIN_INTERPRETER_OVER_LINUXCNC = 0.35


def _raster_program() -> Program:
    spec = importlib.util.spec_from_file_location("make_samples",
                                                  REPO / "toolpaths" / "make_samples.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return read_gcode(mod.relief_raster(100.0, 100.0, stepover=0.5, n_seg=100))


def _prefix(prog: Program, n: int) -> Program:
    s = slice(0, n)
    return Program(prog.start_mm[s], prog.end_mm[s], prog.kind[s], prog.tool[s], prog.line[s],
                   prog.feed_mm_min[s], prog.spindle_rpm[s])


def _timed(fn):
    w, c = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - w, time.process_time() - c


def test_raster_20k_moves_throughput_and_ratio_to_manifold():
    t0 = time.perf_counter()
    prog = _raster_program()
    t_read = time.perf_counter() - t0
    tool = BallEndMill(6)
    assert len(prog) >= 20_000
    simulate(_prefix(prog, 200), tool, SIZE)  # warm-up
    res, wall, cpu = _timed(lambda: simulate(prog, tool, SIZE, resolution_mm=0.1))
    cells = res.stats["cell_updates"]
    print(f"\nraster: {len(prog)} moves, grid {res.stats['grid']}, read {t_read:.2f} s")
    print(f"simulate: wall {wall:.2f} s, cpu {cpu:.2f} s, {len(prog) / wall:.0f} moves/s, "
          f"{cells / wall / 1e6:.1f} M cell updates/s ({cells / 1e6:.1f} M cells)")
    _, mwall, _ = _timed(lambda: res.to_mesh(flat_tol_mm=0.01))
    print(f"mesh (flat_tol 0.01 mm): {mwall:.2f} s")

    n_ref = os.environ.get("WOODCAM_BENCH_REF_MOVES", "2000")
    sub = prog if n_ref == "all" else _prefix(prog, int(n_ref))
    # best of three: the height field takes ~0.04 CPU-s on the 2,000-move prefix
    runs = [_timed(lambda: simulate(sub, tool, SIZE, resolution_mm=0.1)) for _ in range(3)]
    sim_sub, swall, scpu = runs[0][0], min(r[1] for r in runs), min(r[2] for r in runs)
    # manifold3d evaluates booleans lazily: volume() inside the timing forces the result
    vol, rwall, rcpu = _timed(lambda: reference_stock(sub, tool, SIZE, segments=96).volume())
    v_ref = np.prod(SIZE) - vol
    rel = sim_sub.removed_volume_mm3 / v_ref - 1
    print(f"reference on {len(sub)} moves: manifold3d wall {rwall:.1f} s cpu {rcpu:.1f} s; "
          f"height field wall {swall:.3f} s cpu {scpu:.3f} s; ratio (cpu) {rcpu / scpu:.0f}x, "
          f"(wall) {rwall / swall:.0f}x (bar {MIN_SIM_SPEEDUP_OVER_MANIFOLD}); removed volume differs by "
          f"{100 * rel:+.3f} %")
    assert abs(rel) < 5e-3
    assert rcpu / scpu > MIN_SIM_SPEEDUP_OVER_MANIFOLD, (
        f"the height field is {rcpu / scpu:.0f}x faster than manifold3d in CPU time; bar "
        f"{MIN_SIM_SPEEDUP_OVER_MANIFOLD} (measured 1028-1109, divided by 1.5)")


def _cli_run(tmp_path, src_root, label, extra=()):
    """``woodcam gcode`` of the raster in a fresh process: (CPU s, peak RSS GB, stdout)."""
    import subprocess
    import sys

    prog = tmp_path / "raster.nc"
    if not prog.exists():
        spec = importlib.util.spec_from_file_location("make_samples",
                                                      REPO / "toolpaths" / "make_samples.py")
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        prog.write_text(mod.relief_raster(100.0, 100.0, stepover=0.5, n_seg=100))
    code = ("import sys, resource, time; t = time.process_time(); "
            "from woodcam.cli import main; rc = main(sys.argv[1:]); "
            "r = resource.getrusage(resource.RUSAGE_SELF); "
            "print('CPU', r.ru_utime + r.ru_stime, 'RSS', r.ru_maxrss); sys.exit(rc)")
    run = subprocess.run([sys.executable, "-c", code, "gcode", str(prog), "--block",
                          "builtin:flat-sawn", "--out", str(tmp_path / f"{label}.glb"), "--tool",
                          "2=ball:6", "--screenshot", *extra], capture_output=True, text=True,
                         # cwd: "python -c" puts the working folder first on sys.path, which
                         # would shadow src_root with the checkout pytest runs in
                         cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(src_root)})
    assert run.returncode in (0, 3), run.stderr[-3000:]
    out = run.stdout
    line = [ln for ln in out.splitlines() if ln.startswith("CPU ")][-1].split()
    return float(line[1]), float(line[3]) / 1e6, out


def test_whole_gcode_preview_of_the_raster(tmp_path):
    """The whole ``woodcam gcode`` run (read, simulate, mesh, bake, GLB + OBJ, screenshot) of
    the 20,000-move raster: CPU seconds and peak memory in a fresh process, with the default
    iso screenshot (numba z-buffer, :mod:`woodcam.view.stockview`) and ``--camera top``. Set
    ``WOODCAM_BENCH_BASELINE_SRC`` to the root of an older checkout to run it in the same
    session and report the ratios (the time goal, 5 CPU-s, is reported, not asserted: the
    machine's load moves it; issue 18's xatlas baseline measured 106 CPU-s and 4.0 GB)."""
    cpu, rss, out = _cli_run(tmp_path, REPO, "now")
    print(f"\nwoodcam gcode raster (this checkout): {cpu:.1f} CPU-s, peak {rss:.2f} GB; load "
          f"average {os.getloadavg()[0]:.1f}")
    tcpu, trss, _ = _cli_run(tmp_path, REPO, "top", ("--camera", "top"))
    print(f"the same with --camera top: {tcpu:.1f} CPU-s, peak {trss:.2f} GB")
    base = os.environ.get("WOODCAM_BENCH_BASELINE_SRC")
    if base:
        bcpu, brss, _ = _cli_run(tmp_path, Path(base), "base")
        btcpu, btrss, _ = _cli_run(tmp_path, Path(base), "base_top", ("--camera", "top"))
        print(f"baseline {base}: iso {bcpu:.1f} CPU-s, peak {brss:.2f} GB (ratio {bcpu / cpu:.1f}x "
              f"CPU, {brss / rss:.1f}x memory); top {btcpu:.1f} CPU-s, peak {btrss:.2f} GB "
              f"(ratio {btcpu / tcpu:.1f}x CPU, {btrss / trss:.1f}x memory)")
    assert max(rss, trss) * 1e6 < 2**20  # ru_maxrss KiB: under 1 GiB


def test_interpreter_lines_per_cpu_second_vs_linuxcnc(tmp_path):
    """Reading speed (source lines per CPU second) of woodcam's interpreter and of LinuxCNC's
    own (Debian ``linuxcnc-uspace``, its ``gcode`` module with a canon that records moves, as
    the oracle test runs it) on the same 20,500-line raster, in the same run, best of three
    each. Asserted: woodcam's speed over LinuxCNC's (their CPU-s over ours) above
    :data:`MIN_INTERPRETER_OVER_LINUXCNC`."""
    from woodcam.toolpath.interpreter import Interpreter
    from woodcam.toolpath.linuxcnc import linuxcnc_missing, run_batch

    why = linuxcnc_missing()
    if why:
        pytest.skip(why)
    spec = importlib.util.spec_from_file_location("make_samples",
                                                  REPO / "toolpaths" / "make_samples.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    text = mod.relief_raster(100.0, 100.0, stepover=0.5, n_seg=100)
    path = tmp_path / "raster.ngc"
    path.write_text(text)
    n = len(text.splitlines())
    ours = float("inf")
    for _ in range(3):
        c = time.process_time()
        moves, _ = Interpreter(text, start_mm=(0.0, 0.0, 10.0)).run()
        ours = min(ours, time.process_time() - c)
    runs = run_batch([path] * 3)
    for res in runs:
        assert res["error"] is None and len(res["moves"]) - len(moves) in (0, 1)  # + its start
    theirs = min(res["cpu_seconds"] for res in runs)
    print(f"\ninterpreter on {n} lines: woodcam {n / ours:,.0f} lines/CPU-s, LinuxCNC "
          f"{n / theirs:,.0f} lines/CPU-s; woodcam/LinuxCNC = {theirs / ours:.2f}x (bar "
          f"{MIN_INTERPRETER_OVER_LINUXCNC}); load {os.getloadavg()[0]:.1f}")
    assert theirs / ours > MIN_INTERPRETER_OVER_LINUXCNC, (
        f"woodcam's interpreter reads at {theirs / ours:.2f}x LinuxCNC's speed; bar "
        f"{MIN_INTERPRETER_OVER_LINUXCNC} (measured 0.53-0.68, divided by 1.5)")


def test_relief_job_167x208_end_to_end(tmp_path):
    """A real-sized job: the 167 x 208 mm relief panel finished by a 70,000-move OpenCAMLib
    raster (``toolpaths/make_relief_job.py``; generating it takes OpenCAMLib ~2 minutes), read,
    simulated at 0.1 mm, meshed, baked at 10 texels/mm (the walls and bottom at lower density
    keep the atlas within 4096 px), exported and drawn from the top and iso, in a fresh
    process: CPU seconds and peak memory (under 1 GiB)."""
    import subprocess
    import sys

    pytest.importorskip("opencamlib", reason="opencamlib (dev extra) is not installed")
    gen = subprocess.run([sys.executable, str(REPO / "toolpaths" / "make_relief_job.py"),
                          str(tmp_path)], capture_output=True, text=True,
                         env={**os.environ, "PYTHONPATH": str(REPO)})
    assert gen.returncode == 0, gen.stderr[-2000:]
    code = ("import sys, resource; from woodcam.cli import main; rc = main(sys.argv[1:]); "
            "r = resource.getrusage(resource.RUSAGE_SELF); "
            "print('CPU', r.ru_utime + r.ru_stime, 'RSS', r.ru_maxrss); sys.exit(rc)")
    for camera in ("top", "iso"):
        run = subprocess.run([sys.executable, "-c", code, "gcode",
                              str(tmp_path / "relief_panel.ngc"), "--block", "builtin:flat-sawn:167x208x50",
                              "--stock", "167x208x25", "--tool", "1=ball:3", "--out",
                              str(tmp_path / f"panel_{camera}.glb"), "--screenshot", "--camera",
                              camera], capture_output=True, text=True,
                             env={**os.environ, "PYTHONPATH": str(REPO)})
        assert run.returncode == 0, run.stderr[-3000:]
        assert "texels_per_mm lowered" not in run.stderr  # 10 texels/mm fit in 4096 px
        line = [ln for ln in run.stdout.splitlines() if ln.startswith("CPU ")][-1].split()
        moves = [ln for ln in run.stdout.splitlines() if "moves read" in ln][0]
        print(f"\n--camera {camera}: {moves}\n  {float(line[1]):.1f} CPU-s, peak "
              f"{float(line[3]) / 1e6:.2f} GB; load {os.getloadavg()[0]:.1f}")
        assert float(line[3]) * 1024 < 2**30  # ru_maxrss is in KiB: under 1 GiB
