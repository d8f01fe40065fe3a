"""Parquetry figures (seed 002): seconds per patch (exhaustive vs fast), mean feature cost and
SSIM (parquetry vs mean-colour baseline vs a matcher that may reuse wood), and the Fig. 14
degradation (sequential vs interleaved) on one sheet.

Run as a benchmark (``pytest -m bench tests/bench/test_parquetry_bench.py``) or as a script
that prints and stores the figures::

    python tests/bench/test_parquetry_bench.py quality|speed|fig14|exhaustive|exhaustive4|full|calm|calm-flat|calm-noflat OUT.json [COARSE_FACTOR | IMAGES | OUT_DIR] [OUT_DIR]

Timings are CPU seconds of the matching (``time.process_time``), so they are comparable under
the shared machine's load; wall seconds are stored too. ``speed``, ``exhaustive_vs_fast`` and
``exhaustive_vs_fast_4ppm`` take ``params`` (ParquetryParams fields changed, e.g. ``FLAT``) so
the flat-window options can be compared against the defaults in one run (README, "flat windows").
"""

from __future__ import annotations

import functools
import json
import os
import sys
import time
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.bench

MOKUME = Path("/work/shared/data/mokume")


def _leaves(spec, sp, leaves, size_mm, ppm, prefix=None):
    """``leaves`` leaves of ``size_mm = (width, height)`` mm sliced normal to y (the CLI's
    default --slice-axis) from the built-in block ``spec`` grown to hold them: its face normal
    to y (width x height) at least the leaf, its depth its own (``builtin:flat-sawn`` for
    600 x 400 mm leaves: ``builtin:flat-sawn:600x80x400``, the same wood round the same
    centre). The leaves pass the CLI's door (``check_leaves_in_block``): every sheet is wood of
    the block (the 100 x 80 x 50 mm blocks were sliced 600 x 400 mm, wood of the field beyond
    them)."""
    from woodcam._specs import parse_spec
    from woodcam.parquetry import slice_veneers
    from woodcam.parquetry.job import check_leaves_in_block
    from woodcam.stock import open_stock

    parsed = parse_spec(spec)
    assert parsed.kind == "builtin" and not parsed.ops, spec
    w, d, h = open_stock(spec).size_mm
    name = f"builtin:{parsed.source}:{max(w, size_mm[0]):g}x{d:g}x{max(h, size_mm[1]):g}"
    stock = open_stock(name, species=sp)
    size = check_leaves_in_block(stock, leaves, *size_mm, 0.6, 0.4, "y")
    return slice_veneers(stock, leaves, size, px_per_mm=ppm, axis="y", id_prefix=prefix)


def _sheets(size_mm, ppm, leaves=2, mokume=True, n_species=6, blocks=None):
    from woodcam.parquetry import mokume_veneers

    out = []
    if mokume:
        import os

        root = Path(os.environ.get("WOODCAM_SHARED_DATA", "/work/shared/data")) / "mokume"
        for name in ("CN03", "H11"):
            if (root / name).is_dir():
                out += mokume_veneers(root / name)
    for spec, sp in (blocks or SPECIES_BLOCKS[:n_species]):
        # the fast-grown leaves get their own ids (the same species also comes from SPECIES_BLOCKS)
        prefix = f"{sp}-fast" if spec == FAST_GROWN else sp
        out += _leaves(spec, sp, leaves, size_mm, ppm, prefix)
    return out


#: Leaves of a fast-grown flitch (woodcam's ``builtin:fast-grown``: 10 mm rings, the leaves
#: flat-sawn 500 mm from the pith, bands of even earlywood tens of mm wide), 600 x 400 mm: the
#: calm wood a parquetry maker keeps for plain areas. The block holds them: its 600 x 400 mm
#: front face (normal to y, the slicing axis), as the README's --veneer-from example.
FAST_GROWN = "builtin:fast-grown:600x80x400"


#: Six colour presets on four grain layouts: a continuum of tones from walnut to maple (two
#: species only leave a gap in the middle tones that no matcher can fill).
SPECIES_BLOCKS = (("builtin:flat-sawn", "walnut"), ("builtin:quarter-sawn", "maple"),
                  ("builtin:rift", "oak"), ("builtin:flat-sawn", "cherry"),
                  ("builtin:pith-inside", "pine"), ("builtin:knotty", "spruce"))


#: The full workload's four leaves: the quarter-sawn face of each species, the calmest of the
#: built-in blocks' planes at the target's 0.7 mm pixels (README: the SSIM gap is the grain
#: where the target is flat); flat-sawn walnut and cherry and rift oak scored SSIM 0.024 lower.
FULL_BLOCKS = tuple(("builtin:quarter-sawn", sp) for sp in ("walnut", "maple", "oak", "cherry"))


def _figures(run, prm):
    from woodcam.parquetry.engine import feature_cost, ssim_vs_matched
    from woodcam.parquetry.output import native_grid

    p = run.panels[0]
    d = {"patches": len(run.patches), "complete": run.complete,
         "cpu_s": run.cpu_seconds, "wall_s": run.match_seconds,
         "cpu_s_per_patch": run.cpu_seconds / max(1, len(run.patches)),
         "mean_patch_cost_px": float(np.mean([q.cost_px for q in run.patches])),
         "dead_anchors": run.bank.dead_anchors, "fallback_scans": run.bank.fallback_scans,
         "load_avg_1min": os.getloadavg()[0]}
    if run.complete:
        k = round(prm.px_per_mm)
        # Two baselines: the paper's (Fig. 8: each piece of the *result* in its mean colour,
        # p.baseline) and an oracle that no wood gives, each piece in the *target's* mean
        # (matched) intensity: it shows how much of the error is tone rather than structure.
        lab = p.labels.ravel()
        tmean = np.bincount(lab, p.matched.ravel()) / np.maximum(np.bincount(lab), 1)
        oracle = np.repeat(tmean[lab].reshape(p.labels.shape)[..., None], 3, axis=2).astype(np.float32)
        for key, im in (("", p.render), ("_baseline", p.baseline), ("_oracle_target_mean", oracle)):
            d["feature_cost" + key] = feature_cost(p, im, prm)
            d["ssim" + key] = ssim_vs_matched(p, im)
            d["ssim_1mm" + key] = ssim_vs_matched(p, im, k)
            d["feature_cost_native" + key] = feature_cost(p, im, prm, "native")
            d["ssim_native" + key] = ssim_vs_matched(p, im, grid="native")
        # the grid the native figures were measured on (the target's own pixels, or the working
        # grid where those are finer), as result.json says it; it was always the target's own
        d.update(native_grid(p))
        # SSIM with both area-averaged to coarser pixels (the render's grain fades, its
        # pieces' inner structure stays): where wood starts to beat flat colour
        for mm in (2, 3):
            d[f"ssim_{mm}mm"] = ssim_vs_matched(p, p.render, mm * k)
            d[f"ssim_{mm}mm_baseline"] = ssim_vs_matched(p, p.baseline, mm * k)
    return d


def quality(images=("camera", "astronaut", "coffee", "chelsea"), size_mm=112.0, ppm=2.0,
            exhaustive=(), variants=("fast", "fast_eq4_only", "reuse")):
    """Parquetry (fast, and exhaustive for ``exhaustive``) vs baseline vs reuse, per image."""
    import dataclasses

    from skimage import data

    from woodcam.parquetry import ParquetryParams, build_parquetry

    sheets = _sheets((300, 200), ppm)
    out = {"workload": f"skimage targets at {size_mm:g} mm short side, 14 mm patches, {ppm:g} px/mm, "
           f"{len(sheets)} sheets (12 Mokume face photos 50 mm + 2 leaves 300x200 mm of each of 6 "
           "species sliced from builtin blocks), 15 rotations", "images": {}}
    for name in images:
        img = getattr(data, name)().astype(np.float32) / 255
        base = ParquetryParams(image_size_mm=size_mm, px_per_mm=ppm)
        res = {}
        runs = [("fast", base), ("fast_eq4_only", dataclasses.replace(base, w_struct=0.0)),
                ("reuse", dataclasses.replace(base, single_use=False))]
        if name in exhaustive:
            runs.insert(1, ("exhaustive", dataclasses.replace(base, mode="exhaustive")))
        runs = [r for r in runs if r[0] in variants or r[0] == "exhaustive"]
        for label, prm in runs:
            run = build_parquetry([img], sheets, prm)
            res[label] = _figures(run, prm)
            print(name, label, json.dumps(res[label]), flush=True)
        out["images"][name] = res
    return out


def speed(size_mm=70.0, ppm=4.0, sheet=(600, 400), coarse_factor=None, top_k=12, params=None):
    """The issue's sheets (four 600 x 400 mm at 4 px/mm, 15 rotations), fast mode, square
    patches (seams are not part of the per-patch matching time). The time per patch depends on
    the wood searched, not on the target's size, so a 70 mm crop of the target (25 patches)
    stands in for the 360 mm panel (676 patches, ~45 min of wall time on this loaded machine).
    The exhaustive mode's rotated sheets would need ~2.8 GB here, over this shared machine's
    budget: it is compared on quality()'s workload instead."""
    from skimage import data

    from woodcam.parquetry import ParquetryParams, build_parquetry

    sheets = _sheets(sheet, ppm, leaves=2, mokume=False, n_species=2)
    img = data.camera()[40:300, 120:380].astype(np.float32) / 255
    prm = ParquetryParams(image_size_mm=size_mm, px_per_mm=ppm, coarse_factor=coarse_factor, top_k=top_k,
                          **(params or {}))
    t = time.process_time()
    run = build_parquetry([img], sheets, prm, seams=False, progress=True)
    out = {"workload": f"camera crop at {size_mm:g} mm, 14 mm patches, {len(sheets)} sheets {sheet[0]}x{sheet[1]} mm "
           f"at {ppm:g} px/mm (2 walnut + 2 maple leaves sliced from builtin blocks), 15 rotations, "
           f"coarse factor {run.bank.f}, top_k {top_k}",
           "params": dict(params or {}), "atlas_px": int(run.bank.atlas.blocked.size),
           "coarse_factor": run.bank.f,
           "fast": _figures(run, prm), "fast_total_cpu_s": time.process_time() - t}
    print(json.dumps(out), flush=True)
    return out


def fig14(size_mm=70.0, ppm=2.0, copies=7):
    """The same target built ``copies`` times from one sheet: sequential (centre-out, one
    after the other) vs interleaved (all at once by saliency), Fig. 14."""
    from skimage import data

    from woodcam.parquetry import ParquetryParams, build_parquetry

    sheet = _leaves("builtin:knotty", "walnut", 1, (400, 300), ppm)
    img = data.camera()[30:330, 100:400].astype(np.float32) / 255
    out = {"workload": f"camera crop at {size_mm:g} mm (5 x 5 patches of 14 mm), {copies} copies, one "
           f"400x300 mm walnut leaf (builtin:knotty:400x80x300) at {ppm:g} px/mm", "runs": {}}
    for label, prm in (("sequential", ParquetryParams(image_size_mm=size_mm, px_per_mm=ppm, queue="sequential",
                                                      priority="center")),
                       ("interleaved", ParquetryParams(image_size_mm=size_mm, px_per_mm=ppm,
                                                       queue="interleaved", priority="saliency"))):
        run = build_parquetry([img] * copies, sheet, prm, seams=False)
        per = [float(np.mean([q.cost_px for q in p.patches])) if p.patches else None for p in run.panels]
        placed = [len(p.patches) for p in run.panels]
        out["runs"][label] = {"cost_px_per_copy": per, "patches_per_copy": placed, "message": run.message}
        print(label, per, placed, flush=True)
    return out


def exhaustive_vs_fast(size_mm=70.0, ppm=2.0, params=None):
    """Fast vs exhaustive on one workload small enough for the exhaustive search here: a
    5 x 5-patch camera crop, one 200 x 150 mm leaf of each of six species + 12 Mokume faces."""
    import dataclasses

    from skimage import data

    from woodcam.parquetry import ParquetryParams, build_parquetry

    sheets = _sheets((200, 150), ppm, leaves=1)
    img = data.camera()[40:300, 120:380].astype(np.float32) / 255
    base = ParquetryParams(image_size_mm=size_mm, px_per_mm=ppm, **(params or {}))
    out = {"workload": f"camera crop at {size_mm:g} mm, {len(sheets)} sheets (12 Mokume faces + one "
           f"200x150 mm leaf of six species), {ppm:g} px/mm, 15 rotations", "runs": {}}
    for label, prm in (("fast", base), ("exhaustive", dataclasses.replace(base, mode="exhaustive"))):
        run = build_parquetry([img], sheets, prm, seams=False)
        out["runs"][label] = _figures(run, prm)
        print(label, json.dumps(out["runs"][label]), flush=True)
    return out


def exhaustive_vs_fast_4ppm(size_mm=70.0, ppm=4.0, factors=(4, 8, 16), params=None):
    """Fast (several coarse factors) vs exhaustive at the issue's resolution (4 px/mm, 14 mm
    patches, 15 rotations) on wood the exhaustive atlas can hold on this machine: one
    300 x 200 mm leaf each of walnut and maple (the issue's four 600 x 400 mm sheets would
    need ~6 GB for it)."""
    import dataclasses

    from skimage import data

    from woodcam.parquetry import ParquetryParams, build_parquetry

    sheets = _sheets((300, 200), ppm, leaves=1, mokume=False, n_species=2)
    img = data.camera()[40:300, 120:380].astype(np.float32) / 255
    base = ParquetryParams(image_size_mm=size_mm, px_per_mm=ppm, **(params or {}))
    out = {"workload": f"camera crop at {size_mm:g} mm (25 patches of 14 mm), one 300x200 mm leaf "
           f"each of walnut and maple at {ppm:g} px/mm, 15 rotations, square patches", "runs": {}}
    runs = [("exhaustive", dataclasses.replace(base, mode="exhaustive"))]
    runs += [(f"fast_f{f}", dataclasses.replace(base, coarse_factor=f)) for f in factors]
    for label, prm in runs:
        run = build_parquetry([img], sheets, prm, seams=False)
        out["runs"][label] = _figures(run, prm)
        print(label, json.dumps(out["runs"][label]), flush=True)
    return out


def full_workload(out_dir=None, runs=("fast", "eq4_only", "reuse")):
    """The issue's workload: ``camera`` at 360 mm (676 patches of 14 mm), one 600 x 400 mm leaf
    each of walnut, maple, oak and cherry sliced from quarter-sawn blocks + the 12 Mokume face
    photos, 4 px/mm, 15 rotations, seams; the fast run's files are written to ``out_dir``."""
    import dataclasses

    from skimage import data

    from woodcam.parquetry import ParquetryParams, build_parquetry, write_parquetry

    sheets = _sheets((600, 400), 4.0, leaves=1, mokume=True, blocks=FULL_BLOCKS)
    img = data.camera().astype(np.float32) / 255
    base = ParquetryParams()
    variants = {"fast": base, "eq4_only": dataclasses.replace(base, w_struct=0.0),
                "reuse": dataclasses.replace(base, single_use=False)}
    out = {"workload": "camera at 360 mm, 14 mm patches, four 600x400 mm quarter-sawn leaves "
           "(walnut, maple, oak, cherry) + 12 Mokume face photos, 4 px/mm, 15 rotations, seams",
           "runs": {}}
    for label in runs:
        prm = variants[label]
        t = time.process_time()
        run = build_parquetry([img], sheets, prm)
        d = _figures(run, prm)
        d.update(total_cpu_s=time.process_time() - t, coarse_factor=run.bank.f,
                 repaired=len(run.repaired))
        if label == "fast" and out_dir is not None:
            d["problems_left"] = len(write_parquetry(run, out_dir)["problems"])
        out["runs"][label] = d
        print(label, json.dumps(d), flush=True)
    return out


#: The flat-window settings measured by ``calm-flat`` (tuned on crops of moon and clock only);
#: the defaults since they were re-measured on the speed and fast-vs-exhaustive benches.
FLAT = {"flat_detail": 3.0, "flat_rerank": 12}
#: The flat-window weighting turned off (the defaults before; ``calm-noflat``).
NO_FLAT = {"flat_detail": 1.0, "flat_rerank": 4}


def calm_wood(images=("moon", "immunohistochemistry"), out_dir=None, params=None):
    """The SSIM attempt with calm wood (README, "calm wood"): the full workload's settings on
    a pool of the six SPECIES_BLOCKS leaves + four fast-grown leaves (walnut, maple, oak,
    cherry; ``builtin:fast-grown``, 10 mm rings) + the 12 Mokume photos, 600 x 400 mm leaves at 4 px/mm.
    Developed on targets outside the bar's four (skimage ``moon``, ``immunohistochemistry``,
    ``clock``); pass ``camera,astronaut,coffee,chelsea`` to measure the bar's targets.
    ``params``: ParquetryParams fields changed from the defaults (``calm-flat``: FLAT)."""
    from skimage import data

    from woodcam.parquetry import ParquetryParams, build_parquetry, write_parquetry

    blocks = SPECIES_BLOCKS + tuple((FAST_GROWN, sp) for sp in ("walnut", "maple", "oak", "cherry"))
    sheets = _sheets((600, 400), 4.0, leaves=1, mokume=True, blocks=blocks)
    out = {"workload": "skimage targets at 360 mm, 14 mm patches, one 600x400 mm leaf of each of the six "
           "SPECIES_BLOCKS + four fast-grown leaves (10 mm rings) + 12 Mokume face photos, "
           "4 px/mm, 15 rotations, seams", "params": dict(params or {}), "images": {}}
    for name in images:
        img = getattr(data, name)().astype(np.float32) / 255
        prm = ParquetryParams(**(params or {}))
        run = build_parquetry([img], sheets, prm)
        out["images"][name] = d = _figures(run, prm)
        if out_dir is not None:
            write_parquetry(run, Path(out_dir) / name)
        print(name, json.dumps(d), flush=True)
    return out


@functools.lru_cache(maxsize=1)
def _full_fast():
    return full_workload(runs=("fast",))["runs"]["fast"]


def test_quality_bar_on_the_skimage_targets():
    """The issue's bar on real targets nobody here made (112 mm panels at 2 px/mm, where the
    512 px images carry 4.6 px/mm, finer than the working grid): the render beats the paper's
    mean-colour baseline on eq. 8 and on SSIM at 1 mm pixels, on all four."""
    r = quality(variants=("fast",))["images"]
    for name, res in r.items():
        f = res["fast"]
        assert f["feature_cost"] < f["feature_cost_baseline"], name
        assert f["ssim_1mm"] > f["ssim_1mm_baseline"], name


def test_quality_on_the_full_workload_on_the_targets_own_pixels():
    """The issue's workload (camera at 360 mm: 512 px over 364 mm, 1.4 px/mm): on the target's
    own 512 x 512 pixels the render beats the mean-colour baseline on eq. 8 (at the working
    0.25 mm pixels it does not: see the README)."""
    f = _full_fast()
    assert f["complete"] and f["native_grid"] == "target" and f["native_px"] == [512, 512]
    assert f["feature_cost_native"] < f["feature_cost_native_baseline"]


@pytest.mark.xfail(strict=True, reason="not met: at 1.4 px/mm of target every veneer here has "
                   "grain (std 0.02-0.05 in 5 mm windows, far above SSIM's C2 = 0.03^2) where "
                   "the camera is flat (41 % of cells), which a flat colour does not; even the "
                   "same wood blurred at 1 mm only ties on the native grid, and calm fast-grown "
                   "leaves (calm_wood) only halve the gap (0.564 vs 0.606 on the target's grid), "
                   "0.578 vs 0.603 with the flat-window options (calm-flat); see README")
def test_full_workload_beats_the_baseline_on_ssim():
    f = _full_fast()
    assert f["ssim"] > f["ssim_baseline"] and f["ssim_native"] > f["ssim_native_baseline"]


def test_fast_mode_within_5_percent_of_exhaustive_on_camera():
    r = exhaustive_vs_fast()["runs"]
    assert r["fast"]["mean_patch_cost_px"] <= 1.05 * r["exhaustive"]["mean_patch_cost_px"]
    assert r["fast"]["cpu_s_per_patch"] < r["exhaustive"]["cpu_s_per_patch"]


if __name__ == "__main__":
    what, dest = sys.argv[1], Path(sys.argv[2])
    fn = {"quality": quality, "speed": speed, "fig14": fig14, "exhaustive": exhaustive_vs_fast,
          "exhaustive4": exhaustive_vs_fast_4ppm, "full": full_workload, "calm": calm_wood,
          "calm-flat": functools.partial(calm_wood, params=FLAT),
          "calm-noflat": functools.partial(calm_wood, params=NO_FLAT)}[what]
    extra = {}
    if len(sys.argv) > 3:
        extra = ({"coarse_factor": int(sys.argv[3])} if what == "speed"
                 else {"out_dir": sys.argv[3]} if what == "full"
                 else {"images": tuple(sys.argv[3].split(",")), "out_dir": (sys.argv[4:] or [None])[0]}
                 if what in ("calm", "calm-flat", "calm-noflat")
                 else {"images": tuple(sys.argv[3].split(","))})
    res = fn(**extra)
    dest.write_text(json.dumps(res, indent=1))
    print(f"wrote {dest}")


def test_fast_mode_within_5_percent_of_exhaustive_at_4_px_per_mm():
    """The issue's resolution; the coarse factor the issue's sheets get automatically (16)."""
    r = exhaustive_vs_fast_4ppm(factors=(16,))["runs"]
    assert r["fast_f16"]["mean_patch_cost_px"] <= 1.05 * r["exhaustive"]["mean_patch_cost_px"]
    assert r["fast_f16"]["cpu_s_per_patch"] < 0.1 * r["exhaustive"]["cpu_s_per_patch"]
