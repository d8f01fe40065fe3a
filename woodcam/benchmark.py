"""Synthetic work at scale: seed 000's Table 1 on thousands of blocks and its report, block sets
and the neural model's training set, each as many independent tasks of :mod:`woodcam.scale`.

One block is one task, keyed ``b000042`` (index 42), and :func:`bench_block` computes it from
``(seed, index, settings)`` alone: the block is drawn from ``np.random.default_rng([seed,
index])``, fitted by every method on every face set, and scored on the interior cut planes of
:mod:`woodcam.inference.evaluate` against its true growth field. A record keeps the seed, the
index, the block's parameters and the metrics (percentages), never the face images: a block is
regenerated from its seed when a picture is wanted (:func:`bench_gallery`).

Blocks (50 mm cubes by default) are of two kinds, half each by default:

- ``clear``: a knot-free analytic log (eccentric, lobed, ring width log-uniform in the range)
  sawn flat, quarter, rift or through the pith (:func:`woodcam.synth.random_log_placement`);
- ``knotted``: a log of the log generator (seed 001) through the knot field (seed 003), the
  block's front face cut through a knot that reaches past the block's depth (the setting of
  ``tests/inference/test_inference_bench.py``), each face's knots marked in
  ``extras["knot_mask"]`` as a tracer would.

Faces are rendered by :func:`woodcam.synth.synth_block` (traces on the integer iso-lines, optional
jitter / dropout). Face sets: ``full`` (six faces) and ``partial`` (front, top, left: three faces
meeting at a corner). :func:`run_bench` runs many blocks through :func:`woodcam.scale.run_many`;
:func:`bench_report` turns the records into Table-1 figures with bootstrap confidence intervals
over blocks and paired Wilcoxon signed-rank tests between methods.
"""

from __future__ import annotations

import json
import math
import time
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ._atomic import all_or_nothing, atomic_folder, atomic_path, output_folder, remove_stale, write_figure, write_text
from ._checks import as_floats, check_bool, check_number, check_path, received
from ._readers import read_json_file
from .errors import WoodcamError

if TYPE_CHECKING:
    from .scale import RunSummary

#: Methods of :func:`woodcam.inference.fit.fit_block` a bench runs by default.
DEFAULT_METHODS = ("rbf", "radial", "neural")

#: Three faces meeting at a corner: half the surface (the partial annotation of Table 1).
PARTIAL_FACES = ("front", "top", "left")

#: Settings of a bench run (JSON); every record of a run folder was made with the same ones.
DEFAULT_SETTINGS: dict[str, Any] = {
    "methods": list(DEFAULT_METHODS),
    "face_sets": {"full": None, "partial": list(PARTIAL_FACES)},
    "knotted_fraction": 0.5,
    "size_mm": [50.0, 50.0, 50.0],
    "ring_width_range_mm": [2.0, 5.0],
    "face_px": 256,            # 5.12 px/mm on a 50 mm cube, as the Table-1 bench test's 5 px/mm
    "trace_jitter_mm": 0.0,
    "trace_dropout": 0.0,
}

#: Metric names of a record (percent; see :func:`woodcam.inference.evaluate.summarise`):
#: same-year ("matched") and any-year ("unmatched") hits within 1 and 2 mm, and coverage.
METRICS = ("matched_1", "matched_2", "unmatched_1", "unmatched_2", "coverage_1")

#: Bootstrap resamples for the confidence intervals (95 %, percentile method): with 2000 the
#: Monte-Carlo error of a 2.5 % quantile is ~0.3 % of the interval's width.
BOOTSTRAP_RESAMPLES = 2000

RUN_MANIFEST = "run.json"


def bench_key(index: int) -> str:
    return f"b{int(index):06d}"


def key_index(key: str) -> int:
    return int(key[1:])


def bench_settings(**overrides) -> dict:
    """:data:`DEFAULT_SETTINGS` with ``overrides`` checked: unknown names and bad values raise."""
    from .inference.fit import METHODS
    from .frames import check_face, check_size

    unknown = set(overrides) - set(DEFAULT_SETTINGS)
    if unknown:
        raise WoodcamError(f"bench settings: unknown {sorted(unknown)}; known: {sorted(DEFAULT_SETTINGS)}")
    s = json.loads(json.dumps({**DEFAULT_SETTINGS, **{k: v for k, v in overrides.items() if v is not None}}))
    if isinstance(s["methods"], str):
        s["methods"] = [m.strip() for m in s["methods"].split(",") if m.strip()]
    bad = [m for m in s["methods"] if m not in METHODS]
    if bad or not s["methods"]:
        raise WoodcamError(f"methods must be a comma-separated subset of {', '.join(METHODS)}; got "
                           f"{','.join(s['methods'])!r}")
    # a list of face sets was an AttributeError, knotted_fraction='a' a TypeError; a NaN, zero or
    # text size_mm and a NaN or reversed ring-width range were taken, and every block of the run
    # then failed in its task
    if not isinstance(s["face_sets"], dict):
        raise WoodcamError(f"face_sets must be a dict label -> list of faces (or None for all); got "
                           f"{s['face_sets']!r:.60}; e.g. {{'full': None, 'partial': ['front', 'top', 'left']}}")
    for faces in s["face_sets"].values():
        for f in faces or ():
            check_face(f)
    check_number(s["knotted_fraction"], "knotted_fraction", lo=0, hi=1, fix="the share of knotted blocks")
    check_size(s["size_mm"])
    widths = as_floats(s["ring_width_range_mm"])
    if widths is None or widths.shape != (2,) or not np.all(np.isfinite(widths)) or not 0 < widths[0] <= widths[1]:
        raise WoodcamError(f"ring_width_range_mm must be two ring widths 0 < min <= max in mm; got "
                           f"{s['ring_width_range_mm']!r:.60}; e.g. [2.0, 5.0]")
    if not (isinstance(s["face_px"], int) and s["face_px"] >= 32):
        raise WoodcamError(f"face_px must be an integer >= 32 pixels; got {s['face_px']!r}")
    check_number(s["trace_jitter_mm"], "trace_jitter_mm", lo=0, fix="the traces' noise in mm, e.g. 0.1")
    check_number(s["trace_dropout"], "trace_dropout", lo=0, hi=1, fix="the share of trace points dropped")
    return s


# -- one block ------------------------------------------------------------------------------------

def _knotted_field(rng: np.random.Generator, size_mm, ring_width_range_mm):
    """A knotted log and a block whose front face is cut through one of its knots."""
    from .fields import block_at_knot, place_block_in_log
    from .synth import knotted_log_field

    for _ in range(20):  # a generated log nearly always has a long knot; draw again if not
        log_field = knotted_log_field(rng, tuple(ring_width_range_mm), length_mm=1200.0)
        log = log_field.log
        long_enough = [k for k, kn in enumerate(log.knots)
                       if kn.r_end_mm > size_mm[1] + 15.0 and 150.0 < kn.z0_mm < 1050.0]
        if long_enough:
            k = int(rng.choice(long_enough))
            field = place_block_in_log(log_field, *block_at_knot(log, k, size_mm))
            return field, {"knot_index": k, "ring_width_mm": float(log_field.ring_width_mm)}
    raise WoodcamError("no generated log had a knot reaching past the block's depth in 20 draws; "
                       f"use a smaller block than {tuple(size_mm)} mm")


def make_bench_block(seed: int, index: int, settings: dict):
    """Block ``index`` of bench ``seed``: ``(Block with true_field, kind, params)``."""
    from .frames import face_pixel_points
    from .synth import PATTERNS, cut_block, random_log_placement, synth_block

    rng = np.random.default_rng([int(seed), int(index)])
    size = tuple(float(v) for v in settings["size_mm"])
    knotted = bool(rng.uniform() < settings["knotted_fraction"])
    if knotted:
        field, params = _knotted_field(rng, size, settings["ring_width_range_mm"])
    else:
        pattern = PATTERNS[int(rng.integers(len(PATTERNS)))]
        log, placement = random_log_placement(rng, pattern, size, tuple(settings["ring_width_range_mm"]))
        field = cut_block(log, size, **placement)
        params = {**placement, "log": log.to_dict(),
                  "ring_width_mm": log.ring_width_at(placement["distance_mm"])}
    block = synth_block(field, size, face_px=settings["face_px"], rng=rng, seed=None,
                        name=bench_key(index), trace_jitter_mm=settings["trace_jitter_mm"],
                        trace_dropout=settings["trace_dropout"])
    if knotted:  # the tracer marks knots; the fitters leave them out (KNOT_MASK_MARGIN_MM)
        for name, face in block.faces.items():
            pts = face_pixel_points(name, face.shape, size).reshape(-1, 3)
            face.extras["knot_mask"] = (field.knot_features(pts)["knot"] > 0.5).reshape(face.shape)
    params = {k: (float(v) if isinstance(v, (np.floating, float)) else v) for k, v in params.items()}
    return block, ("knotted" if knotted else "clear"), params


def _fit_all(block, settings, keep_lines: bool = False):
    from .inference.evaluate import evaluate_fits
    from .inference.fit import fit_block

    metrics, timing, scores = {}, {}, {}
    for label, faces in settings["face_sets"].items():
        fields, metrics[label], timing[label] = {}, {}, {}
        for m in settings["methods"]:
            t0 = time.perf_counter()
            try:
                fields[m] = fit_block(block, m, faces=faces)
            except WoodcamError as err:  # the method cannot fit this block: a result, not a crash
                metrics[label][m] = {"error": str(err)}
            timing[label][m] = time.perf_counter() - t0
        t0 = time.perf_counter()
        scored = evaluate_fits(block.true_field, fields, block.size_mm, keep_lines=keep_lines)
        timing[label]["score"] = time.perf_counter() - t0
        for m, (summary, sc) in scored.items():
            metrics[label][m] = {k: float(v) for k, v in summary.items()}
            scores.setdefault(label, {})[m] = sc
    return metrics, timing, scores


def bench_block(seed: int, index: int, settings: dict) -> dict:
    """Table-1 metrics of every method on block ``index`` of bench ``seed`` (the task of a run).

    Depends on ``(seed, index, settings)`` only. Returns a JSON-able dict: ``seed``, ``index``,
    ``kind`` ("clear" | "knotted"), ``params`` (the block's log and placement), ``metrics``
    (face set -> method -> :data:`METRICS` percentages and ``n_points``, or ``{"error": msg}``
    when the method refused the block) and ``timing`` (seconds; not deterministic).
    """
    # seed='a' was int()'s ValueError, index=-1 numpy's, settings=None a TypeError
    seed, index = _check_seed_index(seed, index)
    if not isinstance(settings, dict) or set(DEFAULT_SETTINGS) - set(settings):
        raise WoodcamError(f"settings must be the dict of every bench setting (bench_settings(...)); got "
                           f"{settings!r:.60}; pass bench_settings() or bench_settings(face_px=64)")
    t0 = time.perf_counter()
    block, kind, params = make_bench_block(seed, index, settings)
    synth_s = time.perf_counter() - t0
    metrics, timing, _ = _fit_all(block, settings)
    return {"seed": int(seed), "index": int(index), "kind": kind, "params": params,
            "metrics": metrics, "timing": {"synth_s": synth_s, **timing}}


def _check_seed_index(seed, index) -> tuple[int, int]:
    """The bench seed and a block index (or the first one, ``start``), each an integer >= 0
    (numpy's generator refuses a negative one)."""
    return (int(check_number(seed, "seed", lo=0, integer=True, fix="the bench's seed, e.g. 1")),
            int(check_number(index, "index", lo=0, integer=True, fix="the block's number in the bench, from 0")))


def _bench_task(key: str, seed: int, settings: dict) -> dict:
    return bench_block(seed, key_index(key), settings)


def run_bench(out_dir: str | Path, blocks: int, seed: int, settings: dict | None = None, *,
              start: int = 0, **run_options: Any) -> "RunSummary":
    """Bench blocks ``start .. start + blocks - 1`` of ``seed`` into ``out_dir`` (resumable).

    ``settings`` override :data:`DEFAULT_SETTINGS` (see :func:`bench_settings`);
    ``run_options`` go to :func:`woodcam.scale.run_many` (``engine``, ``address``, ``workers``,
    ``retries``, ``memory_limit_mb``, ``progress``, ``connect_timeout_s``).

    ``out_dir/run.json`` holds the seed and settings; running again into the same folder with the
    same seed and settings computes only the blocks without a record, and a different seed or
    settings is refused (a run folder holds one experiment). The order of ``methods`` is not a
    setting: the same methods in another order resume the run in its recorded order. Returns
    the :class:`woodcam.scale.RunSummary`.
    """
    from .scale import check_run_manifest, run_many

    # seed='a' was int()'s ValueError and start=-1 a run of failed blocks (numpy refuses a negative
    # index), settings=[1] a TypeError, blocks=True a run of one block, a file as out_dir mkdir's error
    blocks = int(check_number(blocks, "blocks", lo=1, integer=True, fix="how many blocks to bench, e.g. 10"))
    seed = _check_seed_index(seed, 0)[0]
    start = int(check_number(start, "start", lo=0, integer=True, fix="the first block's number, from 0"))
    if settings is not None and not isinstance(settings, dict):
        raise WoodcamError(f"settings must be a dict of bench settings to override, or None; got {settings!r:.60}; "
                           "e.g. {'face_px': 64}")
    settings = bench_settings() if settings is None else bench_settings(**settings)
    out = output_folder(check_path(out_dir, "run_bench: out_dir", fix="the run folder, e.g. 'runs/bench'"),
                        "run_bench: out_dir")
    settings = _recorded_method_order(out / RUN_MANIFEST, settings)
    check_run_manifest(out / RUN_MANIFEST, {"format": "woodcam-bench-run", "version": 1,
                                            "seed": int(seed), "settings": settings})
    keys = [bench_key(i) for i in range(start, start + blocks)]
    return run_many(partial(_bench_task, seed=int(seed), settings=settings), keys, out,
                    desc="bench blocks", unit="block", **run_options)


def _recorded_method_order(manifest: Path, settings: dict) -> dict:
    """``settings`` with its methods in the order ``manifest`` (a run's run.json) records, when
    they are the same methods: every method is fitted and scored on its own, so the order
    changes no result, and ``--methods rbf,radial`` into a run of ``radial,rbf`` was refused as
    other settings. Anything else (no manifest, other methods) is left to check_run_manifest."""
    try:
        recorded = json.loads(manifest.read_text())["settings"]["methods"]
    except (OSError, ValueError, KeyError, TypeError):
        return settings
    if isinstance(recorded, list) and sorted(map(str, recorded)) == sorted(settings["methods"]):
        return {**settings, "methods": list(recorded)}
    return settings


def bench_gallery(seed: int, index: int, settings: dict, out_dir, *, planes: bool = True,
                  thumbnail: bool = True) -> list[Path]:
    """Regenerate block ``index`` from its seed; with ``planes`` refit it and draw its cut planes
    (true rings in black, each method's in colour) to ``out_dir/b000042_<face set>.png``; with
    ``thumbnail`` draw its faces as an unfolded cross ``b000042_faces.png``. Returns the files."""
    from .block.render import save_cross_png
    from .inference.evaluate import plot_planes

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    block, kind, _ = make_bench_block(seed, index, settings)
    _, _, scores = _fit_all(block, settings, keep_lines=True) if planes else (None, None, {})
    files = []
    for label, by_method in scores.items():
        p = out / f"{bench_key(index)}_{label}.png"
        plot_planes(p, by_method, title=f"{bench_key(index)} ({kind}, {label}): black = true rings, "
                    "colour = fitted")
        files.append(p)
    if thumbnail:
        p = out / f"{bench_key(index)}_faces.png"
        save_cross_png(block, p, "photo", traces=True)
        files.append(p)
    return files


# -- the report -----------------------------------------------------------------------------------

def _ci(values: np.ndarray, rng_seed: int = 0) -> tuple[float, float, float]:
    """Mean and 95 % percentile-bootstrap interval of the mean over blocks."""
    from scipy.stats import bootstrap

    v = np.asarray(values, float)
    if len(v) == 0:
        return math.nan, math.nan, math.nan
    if len(v) < 2 or np.ptp(v) == 0:
        return float(v.mean()), float(v.mean()), float(v.mean())
    r = bootstrap((v,), np.mean, n_resamples=BOOTSTRAP_RESAMPLES, method="percentile",
                  confidence_level=0.95, random_state=np.random.default_rng(rng_seed))
    return float(v.mean()), float(r.confidence_interval.low), float(r.confidence_interval.high)


def _paired(a: np.ndarray, b: np.ndarray) -> dict:
    """Wilcoxon signed-rank test of paired per-block values (two-sided), mean difference a - b."""
    from scipy.stats import wilcoxon

    d = np.asarray(a, float) - np.asarray(b, float)
    if len(d) == 0:
        return {"n": 0, "mean_diff": math.nan, "p": math.nan}
    if not np.any(d != 0):
        return {"n": int(len(d)), "mean_diff": 0.0, "p": 1.0}
    return {"n": int(len(d)), "mean_diff": float(d.mean()), "p": float(wilcoxon(a, b).pvalue)}


def summarise_bench(records: dict) -> dict:
    """Table-1 statistics of a run's records (see :func:`bench_report`), as a JSON-able dict."""
    ok = [r["result"] for r in records.values() if r["status"] == "ok"]
    failed = [{"key": r["key"], "error": r.get("error", "")} for r in records.values() if r["status"] != "ok"]
    if not ok:
        raise WoodcamError("the run folder has no finished block records; run `woodcam bench run` first")
    face_sets = list(ok[0]["metrics"])
    methods = list(ok[0]["metrics"][face_sets[0]])
    table, tests, worst, refused = {}, {}, {}, []
    for label in face_sets:
        for kind in ("all", "clear", "knotted"):
            rows = [r for r in ok if kind == "all" or r["kind"] == kind]
            # paired statistics use the blocks every method fitted
            rows_all = [r for r in rows if all("error" not in r["metrics"][label][m] for m in methods)]
            for m in methods:
                vals = {k: np.array([r["metrics"][label][m][k] for r in rows_all]) for k in METRICS}
                table.setdefault(label, {}).setdefault(kind, {})[m] = {
                    "n": len(rows_all), **{k: _ci(v, rng_seed=i) for i, (k, v) in enumerate(vals.items())}}
            for i, a in enumerate(methods):
                for b in methods[i + 1:]:
                    tests.setdefault(label, {}).setdefault(kind, {})[f"{a} vs {b}"] = {
                        k: _paired([r["metrics"][label][a][k] for r in rows_all],
                                   [r["metrics"][label][b][k] for r in rows_all])
                        for k in ("matched_1", "matched_2", "unmatched_1", "unmatched_2")}
        for m in methods:
            scored = [(r["metrics"][label][m]["matched_1"], r["index"], r["kind"]) for r in ok
                      if "error" not in r["metrics"][label][m]]
            worst.setdefault(label, {})[m] = [{"index": i, "kind": k, "matched_1": v}
                                              for v, i, k in sorted(scored)[:5]]
            refused += [{"index": r["index"], "face_set": label, "method": m,
                         "error": r["metrics"][label][m]["error"]} for r in ok
                        if "error" in r["metrics"][label][m]]
    # CPU seconds of the task in its worker (wall seconds on a shared machine overstate it)
    seconds = np.array([rec.get("cpu_s", rec["seconds"]) for rec in records.values() if rec["status"] == "ok"])
    return {"blocks": len(ok), "clear": sum(r["kind"] == "clear" for r in ok),
            "knotted": sum(r["kind"] == "knotted" for r in ok), "failed": failed, "refused": refused,
            "methods": methods, "face_sets": face_sets, "table": table, "tests": tests, "worst": worst,
            "task_s_mean": float(seconds.mean()), "task_s_median": float(np.median(seconds)),
            "cpu_hours_per_1e5": float(seconds.mean() * 1e5 / 3600.0)}


def _fmt(ci) -> str:
    m, lo, hi = ci
    return "n/a" if math.isnan(m) else f"{m:.1f} [{lo:.1f}, {hi:.1f}]"


def _markdown(s: dict, run: dict) -> str:
    lines = [f"# woodcam bench report: seed {run['seed']}, {s['blocks']} blocks "
             f"({s['clear']} clear, {s['knotted']} knotted)", "",
             "Per-block percentages of ring-line points on seven interior cut planes (seed 000, "
             "Table 1): *same year* counts a predicted ring point within the threshold of the true "
             "ring of the same year, *any year* of any true ring. Each cell is the mean over blocks "
             f"with its 95 % bootstrap interval ({BOOTSTRAP_RESAMPLES} resamples, percentile).", ""]
    for label in s["face_sets"]:
        faces = run["settings"]["face_sets"][label]
        lines += [f"## {label} ({'all six faces' if faces is None else ', '.join(faces)})", ""]
        for kind in ("all", "clear", "knotted"):
            rows = s["table"][label][kind]
            n = next(iter(rows.values()))["n"]
            lines += [f"### {kind} blocks (n = {n})", "",
                      "| method | same year <= 1 mm | same year <= 2 mm | any year <= 1 mm | "
                      "any year <= 2 mm | coverage 1 mm |", "|---|---|---|---|---|---|"]
            for m, r in rows.items():
                lines.append(f"| {m} | " + " | ".join(_fmt(r[k]) for k in METRICS) + " |")
            pairs = s["tests"].get(label, {}).get(kind, {})  # none with a single method
            if pairs:
                lines += ["", "Paired Wilcoxon signed-rank tests (two-sided p; mean difference in "
                          "percentage points):", "",
                          "| pair | same year 1 mm | same year 2 mm | any year 1 mm | any year 2 mm |",
                          "|---|---|---|---|---|"]
            for pair, t in pairs.items():
                lines.append(f"| {pair} | " + " | ".join(
                    "n/a" if math.isnan(t[k]["p"]) else f"{t[k]['mean_diff']:+.1f}, p = {t[k]['p']:.2g}"
                    for k in ("matched_1", "matched_2", "unmatched_1", "unmatched_2")) + " |")
            lines.append("")
        lines += ["### worst blocks (same year <= 1 mm)", ""]
        for m, rows in s["worst"][label].items():
            lines.append(f"- {m}: " + ", ".join(f"{bench_key(w['index'])} ({w['kind']}) "
                                               f"{w['matched_1']:.1f} %" for w in rows))
        lines.append("")
    lines += ["## cost", "", f"Task CPU time: mean {s['task_s_mean']:.1f} s, median "
              f"{s['task_s_median']:.1f} s per block (one worker, one thread); 10^5 blocks = "
              f"{s['cpu_hours_per_1e5']:.0f} CPU-hours, about {s['cpu_hours_per_1e5'] / 100:.1f} h "
              f"on 100 cores, {s['cpu_hours_per_1e5'] / 1000:.2f} h on 1000.", ""]
    if s.get("gallery") or s.get("thumbnails"):
        lines += ["## gallery", ""]
        lines += [f"- {bench_key(i)}: cut planes `gallery/{bench_key(i)}_<face set>.png` (refitted from "
                  f"its seed), faces `gallery/{bench_key(i)}_faces.png`" for i in s.get("gallery", [])]
        lines += [f"- {bench_key(i)}: faces `gallery/{bench_key(i)}_faces.png`" for i in s.get("thumbnails", [])]
        lines.append("")
    if s["failed"]:
        lines += [f"## failed tasks ({len(s['failed'])})", ""]
        lines += [f"- {f['key']}: {f['error']}" for f in s["failed"][:50]]
        lines.append("")
    if s["refused"]:
        lines += [f"## blocks a method refused ({len(s['refused'])}; left out of that face set's "
                  "paired statistics)", ""]
        lines += [f"- {bench_key(r['index'])} {r['face_set']} {r['method']}: {r['error']}"
                  for r in s["refused"][:50]]
        lines.append("")
    return "\n".join(lines)


def _plot(s: dict, path: Path) -> Path:
    from .errors import require

    matplotlib = require("matplotlib", "view", "drawing the bench report")
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(s["face_sets"]), figsize=(6 * len(s["face_sets"]), 4.6), squeeze=False)
    methods = s["methods"]
    kinds = ("clear", "knotted")
    for ax, label in zip(axes[0], s["face_sets"]):
        labelled = set()
        for j, (metric, hatch) in enumerate((("matched_1", ""), ("matched_2", "//"))):
            for i, m in enumerate(methods):
                for k, kind in enumerate(kinds):
                    mean, lo, hi = s["table"][label][kind][m][metric]
                    if math.isnan(mean):
                        continue
                    x = k * (len(methods) + 1) + i + 0.4 * j
                    name = f"{m} {'1' if j == 0 else '2'} mm"
                    ax.bar(x, mean, 0.4, color=f"C{i}", hatch=hatch, edgecolor="k", linewidth=0.3,
                           label=None if name in labelled else name)
                    labelled.add(name)
                    ax.errorbar(x, mean, [[mean - lo], [hi - mean]], color="k", capsize=2, lw=0.8)
        ax.set_xticks([k * (len(methods) + 1) + (len(methods) - 1) / 2 + 0.2 for k in range(len(kinds))])
        ax.set_xticklabels(kinds)
        ax.set_ylim(0, 100)
        ax.set_ylabel("% ring points within 1 / 2 mm (same year)")
        ax.set_title(f"{label}: mean over blocks, 95 % bootstrap CI")
        ax.legend(fontsize=7, ncol=3, loc="upper center", bbox_to_anchor=(0.5, -0.08))
    fig.tight_layout()
    write_figure(fig, path, dpi=110)
    plt.close(fig)
    return path


def _check_bench_result(path: Path, rec: dict, shape: list) -> None:
    """A finished record's result as :func:`summarise_bench` reads it (a record is a file, from
    anywhere: one whose result lacked 'metrics' or held a number where a score goes was an
    internal error, KeyError or TypeError): ``kind`` clear or knotted, ``metrics`` face set ->
    method -> either ``error`` or every :data:`METRICS` score a finite number, the same face sets
    and methods as the first record checked (``shape``, filled by it), and the record's
    ``seconds``. Else a WoodcamError naming the file and the fix."""
    res = rec["result"]
    metrics = res.get("metrics")

    def fail(why: str) -> WoodcamError:
        return WoodcamError(f"record {path} is not a bench block result as `woodcam bench run` writes it: {why}; "
                            "delete it and re-run `woodcam bench run` to recompute it")

    if res.get("kind") not in ("clear", "knotted"):
        raise fail(f"its kind must be 'clear' or 'knotted', got {received(res.get('kind'), 40)}")
    if not (isinstance(metrics, dict) and metrics and all(isinstance(v, dict) and v for v in metrics.values())):
        raise fail("its metrics must map each face set to its methods' scores")
    got = [(label, sorted(cells)) for label, cells in metrics.items()]
    if not shape:
        shape += got
    elif got != shape:
        raise fail(f"it scores {got}, the run's first record {shape} (face sets, methods)")
    for label, cells in metrics.items():
        for m, cell in cells.items():
            ok = isinstance(cell, dict) and ("error" in cell or all(
                isinstance(cell.get(k), (int, float)) and not isinstance(cell.get(k), bool)
                and math.isfinite(cell[k]) for k in METRICS))
            if not ok:
                raise fail(f"{label}/{m} must hold an error or the finite scores {', '.join(METRICS)}; got "
                           f"{received(cell, 60)}")
    t = rec.get("cpu_s", rec.get("seconds"))
    if isinstance(t, bool) or not isinstance(t, (int, float)) or not math.isfinite(t):
        raise fail(f"its seconds (or cpu_s) must be a number; got {received(t, 40)}")


def bench_report(run_dir: str | Path, out_dir: str | Path, *, gallery: int = 3, thumbnails: int = 2,
                 progress: bool = True) -> dict:
    """Write ``report.md``, ``report.json`` and ``table1.png`` for a bench run folder into
    ``out_dir``, plus a failure gallery: the cut planes of the ``gallery`` worst blocks (same
    year within 1 mm, over all methods and face sets) and face thumbnails of ``thumbnails``
    blocks of each kind, all regenerated from the seed. The files are one set
    (:func:`woodcam._atomic.all_or_nothing`): an interrupted report leaves the folder's previous
    one as it was; once they are in place, the gallery pictures an earlier report left there
    (of other blocks) are removed. Returns the summary dict.

    ``run_dir``: the folder ``woodcam bench run`` wrote (its run manifest and ``records/``);
    ``progress``: a bar on stderr while the gallery's blocks are refitted and drawn."""
    from .scale import read_records, record_path, write_json_atomic

    progress = check_bool(progress, "bench_report: progress")
    run_dir, out = Path(run_dir), Path(out_dir)
    mpath = run_dir / RUN_MANIFEST
    if not mpath.is_file():
        # the folder as given ('bench report RUN'), not the parameter's name the user never typed
        raise WoodcamError(f"run folder {str(run_dir)!r} has no {RUN_MANIFEST}, so no bench run wrote it; "
                           "make one with `woodcam bench run --out DIR` and give that DIR")
    # strict, and a run's manifest: '{' or a list was an internal error (JSONDecodeError, TypeError)
    again = f"delete the run folder {str(run_dir)!r} and run `woodcam bench run` again"
    try:
        run = read_json_file(mpath, "bench run manifest")
    except WoodcamError as err:
        raise WoodcamError(f"{err}; {again}") from err
    if not (isinstance(run, dict) and isinstance(run.get("seed"), int) and isinstance(run.get("settings"), dict)):
        raise WoodcamError(f"bench run manifest {str(mpath)!r} must be a JSON object with the run's seed (an "
                           f"integer) and settings, as `woodcam bench run` writes it; got {received(run)}; {again}")
    records = read_records(run_dir)
    shape: list = []  # the face sets and methods of the first finished record: every other's too
    for key, rec in records.items():  # a record copied in from another run would be counted
        if rec["status"] != "ok":
            continue
        res = rec.get("result")
        index = res.get("index") if isinstance(res, dict) else None
        if not isinstance(res, dict) or res.get("seed") != run["seed"] or not isinstance(index, int) \
                or key != bench_key(index):
            what = (f"block {index} of seed {res.get('seed')}" if isinstance(res, dict)
                    else f"no block result (a JSON object; got {received(res, 40)})")
            raise WoodcamError(f"record {record_path(run_dir, key)} is {what}, not block {key} of this run's seed "
                               f"{run['seed']} ({mpath}); delete it and re-run `woodcam bench run` to recompute it")
        _check_bench_result(record_path(run_dir, key), rec, shape)
    s = summarise_bench(records)
    # the gallery: worst distinct blocks first, then a sample of each kind as thumbnails; chosen
    # before the report is written, so report.json and report.md say which blocks it draws (they
    # did not: the picks were only returned)
    worst = sorted({(w["matched_1"], w["index"]) for label in s["worst"] for rows in s["worst"][label].values()
                    for w in rows})
    picks = []
    for _, i in worst:
        if i not in picks and len(picks) < gallery:
            picks.append(i)
    sample = []
    for kind in ("clear", "knotted"):
        sample += [r["result"]["index"] for r in records.values()
                   if r["status"] == "ok" and r["result"]["kind"] == kind][:thumbnails]
    s["gallery"] = picks
    s["thumbnails"] = [i for i in sample if i not in picks]
    out.mkdir(parents=True, exist_ok=True)
    from ._progress import progress_bar

    # one set: an interrupted gallery (minutes of refits) left a new report.md beside the
    # previous report's pictures
    with all_or_nothing():
        files = [write_json_atomic(out / "report.json", {"seed": run["seed"], "settings": run["settings"], **s}),
                 write_text(out / "report.md", _markdown(s, run)), _plot(s, out / "table1.png")]
        for i in progress_bar(picks + s["thumbnails"], desc="gallery", unit="block",
                              enabled=progress):  # the worst are refitted; the sample only drawn
            files += bench_gallery(run["seed"], i, run["settings"], out / "gallery", planes=i in picks)
    # an earlier report's gallery drew other blocks: beside this one's, a reader took them for
    # this report's worst blocks
    remove_stale(out / "gallery", ["b*_*.png"], files, kind="benchmark-gallery")
    return s


# -- synthetic block sets at scale ----------------------------------------------------------------

def _synth_set_task(key: str, seed: int, out_dir: str, face_px: int, knotted: bool,
                    block_options: dict | None = None) -> dict:
    """Write block ``key`` (``block_0042``) of set ``seed`` to ``out_dir/key`` atomically;
    ``block_options`` go to :func:`woodcam.synth.benchmark_set_block` (sizes, knotted share,
    trace noise)."""
    from .block.io import write_block
    from .synth import benchmark_set_block, knotted_log_field

    index = int(key.split("_")[1])
    opts = dict(block_options or {})
    if "size_range_mm" in opts:
        opts["size_range_mm"] = tuple(opts["size_range_mm"])
    block, info = benchmark_set_block(seed, index, face_px=face_px,
                                      log_fields=knotted_log_field if knotted else None, **opts)
    # a folder from an earlier run without its record is replaced whole; a stopped write leaves
    # nothing (a Ctrl-C left an empty .block_0000.<pid>.tmp, a kill a half one, for good)
    with atomic_folder(Path(out_dir) / key) as tmp:
        write_block(block, tmp)
    return info


#: Options of :func:`write_benchmark_set`'s ``block_options`` (those of
#: :func:`woodcam.synth.benchmark_set_block` and :func:`woodcam.synth.synth_block` that the
#: benchmark varies: ``woodcam block synth``'s flags).
BLOCK_OPTIONS = ("size_range_mm", "knotted_fraction", "trace_jitter_mm", "trace_dropout",
                 "trace_dropout_chunk_mm", "mislabel_fraction", "trace_faces")


def _block_option_defaults() -> dict:
    """The default of every :data:`BLOCK_OPTIONS` name: those of
    :func:`woodcam.synth.benchmark_set_block`, else of :class:`woodcam.synth.SynthSpec` (flat)."""
    import inspect

    from .synth import benchmark_set_block
    from .synth.spec import SynthSpec

    own = inspect.signature(benchmark_set_block).parameters
    flat = SynthSpec().flat()
    return {k: own[k].default if k in own else flat[k] for k in BLOCK_OPTIONS}


def _benchmark_set_manifest(seed: int, face_px: int, knotted: bool, block_options: dict | None) -> dict:
    """The settings a block set's ``.synth/run.json`` records (:func:`write_benchmark_set`,
    :func:`check_benchmark_set_out`): ``block_options`` checked, every default filled in."""
    opts = dict(block_options or {})
    bad = sorted(set(opts) - set(BLOCK_OPTIONS))
    if bad:
        raise WoodcamError(f"block_options must be among {', '.join(BLOCK_OPTIONS)}; got {bad}")
    from .synth.degradation import _check_fraction

    for name in ("knotted_fraction", "trace_dropout", "mislabel_fraction"):
        if name in opts:  # at the door, not once per failing task
            _check_fraction(name, opts[name])
    # every option, defaults filled in: a rerun that spells out a default (size_range_mm
    # [30, 80], as the CLI does) is the same set, not one of other settings
    opts = {**_block_option_defaults(), **opts}
    opts["size_range_mm"] = [float(v) for v in opts["size_range_mm"]]  # JSON-friendly in the task
    if opts["trace_faces"] is not None:
        opts["trace_faces"] = list(opts["trace_faces"])
    return {"format": "woodcam-benchmark-set", "seed": int(seed), "face_px": int(face_px),
            "knotted": bool(knotted), "block_options": opts}


def check_benchmark_set_out(out_dir, seed: int, *, face_px: int = 512, knotted: bool = True,
                            block_options: dict | None = None) -> None:
    """Refuse, before any work, to write the set ``seed`` (settings as
    :func:`write_benchmark_set` takes them) without an engine into ``out_dir`` when an engine
    run left a set of another seed or settings there (``out_dir/.synth/run.json``): the serial
    writer (:func:`woodcam.synth.synth_benchmark_set`) replaced its blocks and ``index.json``
    and left its records, so a later engine run of the old seed kept the new seed's blocks as
    done. The rule is :func:`woodcam.scale.check_run_manifest`'s (a
    :class:`~woodcam.errors.UsageError`); a folder without one is left as it is."""
    from .scale import check_run_manifest

    path = Path(out_dir) / ".synth" / RUN_MANIFEST
    if path.is_file():
        check_run_manifest(path, _benchmark_set_manifest(seed, face_px, knotted, block_options), out_dir)


def write_benchmark_set(out_dir, count: int, seed: int, *, face_px: int = 512, knotted: bool = True,
                        block_options: dict | None = None, **run_options):
    """:func:`woodcam.synth.synth_benchmark_set` with the knotted generator, one task per block on
    an engine (the same blocks, bit for bit), resumable; writes ``index.json`` at the end.
    ``block_options`` (names in :data:`BLOCK_OPTIONS`: sizes, knotted share, trace noise as
    ``woodcam block synth`` takes them) are passed to every block, so a noisy set is the same
    on every engine as without one. With a Dask ``address`` the workers write the block folders,
    so they need ``out_dir`` on a shared disk. ``run_options`` go to
    :func:`woodcam.scale.run_many`. Returns ``(RunSummary, index dict)``."""
    from .scale import check_run_manifest, read_records, run_many, write_json_atomic
    from .synth.dataset import check_no_stale_blocks

    if not isinstance(count, int) or count < 1:
        raise WoodcamError(f"count must be an integer >= 1; got {count!r}")
    manifest = _benchmark_set_manifest(seed, face_px, knotted, block_options)
    opts = manifest["block_options"]
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    # the records say which blocks are done, not of which set: a rerun with another seed kept the
    # old seed's blocks under an index.json of the new one
    check_run_manifest(out / ".synth" / RUN_MANIFEST, manifest, out)
    # the serial writer's rule: a smaller set left the larger one's last blocks there, unlisted
    check_no_stale_blocks(out, count, int(seed))
    keys = [f"block_{i:04d}" for i in range(count)]
    summary = run_many(partial(_synth_set_task, seed=int(seed), out_dir=str(out.resolve()),
                               face_px=int(face_px), knotted=bool(knotted), block_options=opts),
                       keys, out / ".synth", desc="synthesising blocks", unit="block", **run_options)
    recs = read_records(out / ".synth")
    index = {"format": "woodcam-benchmark", "version": 1, "seed": int(seed), "count": int(count),
             "face_px": int(face_px), "size_range_mm": opts["size_range_mm"],
             "ring_width_range_mm": [1.5, 6.0], "knotted_available": bool(knotted),
             "blocks": [recs[k]["result"] for k in keys if k in recs and recs[k]["status"] == "ok"]}
    write_json_atomic(out / "index.json", index)
    return summary, index


# -- training sets at scale -----------------------------------------------------------------------

#: Fields per shard of a training set: 256 x 1600 points is ~5 MB of float32, a few seconds.
TRAINING_SHARD_FIELDS = 256


def _training_shard_task(key: str, spec: dict, shard_fields: int, out_dir: str) -> dict:
    """Write shard ``key`` (``shard_0003``) of the training set of ``spec`` as an npz."""
    from .fields.neural import GTFSpec, make_training_shard

    sp = GTFSpec.from_dict(spec)
    start = int(key.split("_")[1]) * shard_fields
    stop = min(start + shard_fields, sp.n_fields)
    pts, vals = make_training_shard(sp, start, stop)
    with atomic_path(Path(out_dir) / f"{key}.npz") as tmp:
        np.savez(tmp, points=pts, values=vals)
    return {"start": start, "stop": stop}


def make_training_set_many(spec, out_dir, *, shard_fields: int = TRAINING_SHARD_FIELDS,
                           **run_options) -> tuple[np.ndarray, np.ndarray]:
    """:func:`woodcam.fields.neural.make_training_set` of ``spec`` made in shards of
    ``shard_fields`` fields, one task each (:func:`woodcam.scale.run_many`; ``run_options`` go
    there), written to ``out_dir/shard_NNNN.npz`` and concatenated: the same arrays, bit for bit,
    resumable. With a Dask ``address`` the workers write the shards (a shared disk is needed).

    Returns
    -------
    points : (N, M, 3) float32, values : (N, M) float32
    """
    from .fields.neural import TRAINING_SET_FIELDS
    from .scale import check_run_manifest, read_records, run_many

    if not isinstance(shard_fields, int) or shard_fields < 1:
        raise WoodcamError(f"shard_fields must be an integer >= 1; got {shard_fields!r}")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    # the shards of another spec's training set (another seed ...) were reused without a word
    check_run_manifest(out / ".records" / RUN_MANIFEST, {
        "format": "woodcam-training-set", "shard_fields": shard_fields,
        "spec": {k: spec.to_dict()[k] for k in TRAINING_SET_FIELDS}}, out)
    n_shards = -(-spec.n_fields // shard_fields)
    keys = [f"shard_{i:04d}" for i in range(n_shards)]
    s = run_many(partial(_training_shard_task, spec=spec.to_dict(), shard_fields=shard_fields,
                         out_dir=str(out.resolve())), keys, out / ".records",
                 desc="training set shards", unit="shard", **run_options)
    if s.failed:
        bad = {k: r.get("error") for k, r in read_records(out / ".records").items() if r["status"] != "ok"}
        raise WoodcamError(f"{s.failed} training-set shard(s) failed: {bad}; run again to retry them")
    parts = [_read_training_shard(out, k, spec, shard_fields) for k in keys]
    return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


def _read_training_shard(out: Path, key: str, spec, shard_fields: int) -> tuple[np.ndarray, np.ndarray]:
    """Shard ``key`` of ``out`` (points, values), made again where its file is missing, cut or
    of other shapes (a disk, a copy, a hand): its record said "ok", and numpy's BadZipFile or
    FileNotFoundError ended the run as an internal error. A shard is a function of the spec
    alone, so the one made again is the same."""
    import warnings

    from ._cache import CacheWarning
    from ._readers import read_npz

    start = int(key.split("_")[1]) * shard_fields
    want = (min(start + shard_fields, spec.n_fields) - start, spec.points_per_field)

    def read() -> tuple[np.ndarray, np.ndarray]:
        with read_npz(out / f"{key}.npz", "a training-set shard") as z:
            pts, vals = np.asarray(z["points"], np.float32), np.asarray(z["values"], np.float32)
        if pts.shape != want + (3,) or vals.shape != want:
            raise WoodcamError(f"{out / key}.npz: holds points {pts.shape} and values {vals.shape}, not "
                               f"{want + (3,)} and {want}")
        return pts, vals

    try:
        return read()
    except WoodcamError as err:
        warnings.warn(CacheWarning(f"{err}; made the shard again (shards depend on the spec alone)"), stacklevel=3)
    _training_shard_task(key, spec.to_dict(), shard_fields, str(out.resolve()))
    return read()


__all__ = ["DEFAULT_METHODS", "DEFAULT_SETTINGS", "METRICS", "PARTIAL_FACES", "bench_block",
           "bench_gallery", "bench_report", "bench_settings", "check_benchmark_set_out", "make_bench_block",
           "run_bench", "make_training_set_many", "summarise_bench", "write_benchmark_set"]
