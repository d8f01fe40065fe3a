"""Woodify benchmarks (``-m bench``): the issue's figures with a same-run baseline.

Times are CPU seconds of this process (``time.process_time``), which the shared machine's load
inflates less than wall clock; the baseline is scikit-fmm's ``travel_time`` alone on the same
grid in the same run. Printed as one JSON line per figure. The CPU ratios to the same-run
baselines are asserted (:data:`MAX_FIELD_OVER_SKFMM`, :data:`MAX_CRACKS_OVER_FRONT`).
"""

from __future__ import annotations

import json
import os
import time

import numpy as np
import pytest
import trimesh

from woodcam.woodify import woodify
from woodcam.woodify.cracks import simulate_cracks

pytestmark = pytest.mark.bench

#: Bars on CPU(woodify's 40-year field) / CPU(scikit-fmm's travel_time alone on its grid), per
#: case. No target is stated: measured 1.46-1.91 (isotropic), 3.06-3.8 (eccentric) and
#: 6.96-8.55 (obstacle) in three runs on the shared 2-core machine at load ~5 (Dec 2026),
#: times a 1.5x margin, so a field markedly slower than today fails.
MAX_FIELD_OVER_SKFMM = {"isotropic": 2.9, "eccentric": 5.7, "eccentric + obstacle": 13.0}
#: Bar on CPU(crack stage, 5 years) / CPU(growth stage) at resolution 200. The README reports
#: the figure (2.3x, then 10.9 s); measured 1.68-1.95 in four runs (same machine), times 1.5.
MAX_CRACKS_OVER_FRONT = 2.9


def _tree_mesh(target_faces: int = 20_000):
    """A trunk with two branches (manifold union), refined to about ``target_faces`` triangles."""
    import manifold3d as m3

    trunk = m3.Manifold.cylinder(80.0, 9.0, 7.0, 48).translate((0, 0, -40))
    b1 = m3.Manifold.cylinder(40.0, 4.0, 2.5, 32).rotate((0, 50, 0)).translate((0, 0, -5))
    b2 = m3.Manifold.cylinder(35.0, 3.5, 2.0, 32).rotate((-45, 0, 30)).translate((0, 0, 15))
    solid = trunk + b1 + b2
    mesh = solid.to_mesh()
    tm = trimesh.Trimesh(mesh.vert_properties[:, :3], mesh.tri_verts)
    while len(tm.faces) < target_faces:
        tm = tm.subdivide()
    return tm


def _report(name, **values):
    load = os.getloadavg()[0]
    print(json.dumps({"figure": name, "load_1min": round(load, 2), **values}))


def test_field_of_a_20k_triangle_mesh_at_128():
    import skfmm

    mesh = _tree_mesh()
    nf = len(mesh.faces)
    post = trimesh.creation.cylinder(radius=3.0, height=200.0, sections=32)
    post.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, (1, 0, 0)))
    post.apply_translation((20.0, 0.0, 0.0))
    # warm-up of each method on a coarse grid: numba compiles (or loads its cache) on the
    # first call, which cost the first figure ~3 CPU-s with a cold cache (ratio 4.7, warm 1.5-1.9)
    for kw in ({}, {"eccentricity": 0.3}, {"eccentricity": 0.3, "obstacles": [post]}):
        woodify(mesh, 40, growth_mm=20.0, resolution=24, **kw)
    t = time.process_time()
    res = woodify(mesh, 40, growth_mm=20.0, resolution=128)
    t_woodify = time.process_time() - t
    g = res.front.grid
    # baseline: scikit-fmm alone on the same grid (a sphere's level set as input)
    phi = np.linalg.norm(g.nodes() - mesh.centroid, axis=1).reshape(g.shape) - 10.0
    t_skfmm = np.inf
    for _ in range(3):  # best of three: the baseline's CPU time varied 0.5-0.9 s under load
        t = time.process_time()
        skfmm.travel_time(phi, np.ones_like(phi), dx=float(g.spacing_mm))
        t_skfmm = min(t_skfmm, time.process_time() - t)
    _report("field 40 years, isotropic", triangles=nf, grid=list(g.shape), method=res.front.method,
            woodify_cpu_s=round(t_woodify, 2), skfmm_alone_cpu_s=round(t_skfmm, 2),
            ratio=round(t_woodify / t_skfmm, 2))
    t = time.process_time()
    ecc = woodify(mesh, 40, growth_mm=20.0, resolution=128, eccentricity=0.3)
    t_ecc = time.process_time() - t
    _report("field 40 years, eccentric", method=ecc.front.method, cpu_s=round(t_ecc, 2),
            ratio_to_skfmm=round(t_ecc / t_skfmm, 2))
    t = time.process_time()
    obs = woodify(mesh, 40, growth_mm=20.0, resolution=128, eccentricity=0.3, obstacles=[post])
    t_obs = time.process_time() - t
    _report("field 40 years, eccentric + obstacle", method=obs.front.method, cpu_s=round(t_obs, 2),
            ratio_to_skfmm=round(t_obs / t_skfmm, 2))
    # field evaluation: 1M random points in the grown object's box
    rng = np.random.default_rng(0)
    lo = np.asarray(g.origin_mm)
    pts = lo + rng.random((1_000_000, 3)) * (np.asarray(g.shape) - 1) * g.spacing_mm
    res.field(pts[:1000])
    t, tw = time.process_time(), time.perf_counter()
    res.field(pts)
    dt, dw = time.process_time() - t, time.perf_counter() - tw
    _report("field evaluation", points=len(pts), points_per_cpu_s=round(len(pts) / dt),
            points_per_wall_s=round(len(pts) / dw), cpu_s=round(dt, 3))
    ratios = {"isotropic": t_woodify / t_skfmm, "eccentric": t_ecc / t_skfmm,
              "eccentric + obstacle": t_obs / t_skfmm}
    _report("field CPU over scikit-fmm alone", **{k: round(v, 2) for k, v in ratios.items()},
            bars=MAX_FIELD_OVER_SKFMM)
    for case, ratio in ratios.items():
        assert ratio < MAX_FIELD_OVER_SKFMM[case], (
            f"the 40-year field ({case}) costs {ratio:.2f}x scikit-fmm's CPU time on its grid; bar "
            f"{MAX_FIELD_OVER_SKFMM[case]} (measured 1.46-8.55 by case, times 1.5)")
    assert len(pts) / dt > 1e6


def test_whole_run_with_cracks_and_surfaces_at_5_years():
    mesh = _tree_mesh()
    t = time.process_time()
    res = woodify(mesh, 5, growth_mm=6.0, resolution=128)
    cs = simulate_cracks(res, [0, 1, 2, 3, 4, 5])
    surfaces = [res.surface(y) for y in (1.0, 2.0, 3.0, 4.0)]
    dt = time.process_time() - t
    _report("whole run 5 years with cracks and surfaces", triangles=len(mesh.faces),
            grid=list(res.front.grid.shape), final_vertices=len(cs.mesh.vertices),
            cracks=int(sum(x["cracks"] for x in cs.log)), cpu_s=round(dt, 2),
            timings=res.timings)
    assert all(s.is_watertight for s in surfaces)


def test_crack_stage_against_the_growth_stage_at_200(monkeypatch):
    """The crack stage at a fine grid, as ratios in the same run: to the growth (front) stage,
    and to the same cracks with the back-trace grids rebuilt on every call (the old code path:
    two full-grid float64 gradients a crack year)."""
    from woodcam.woodify import surfaces

    mesh = _tree_mesh()
    years = 10
    t = time.process_time()
    res = woodify(mesh, years, resolution=200, eccentricity=0.2)
    t_front = time.process_time() - t
    ys = [years - 5 + k for k in range(6)]
    t = time.process_time()
    cs = simulate_cracks(res, ys)
    t_cracks = time.process_time() - t
    cached = surfaces.trace_grids

    def rebuilt(front):
        front._trace_cache = None
        return cached(front)

    monkeypatch.setattr(surfaces, "trace_grids", rebuilt)
    t = time.process_time()
    old = simulate_cracks(res, ys)
    t_rebuilt = time.process_time() - t
    _report("crack stage, 5 years", grid=list(res.front.grid.shape), cracks=len(cs.crack_directions),
            vertices=len(cs.mesh.vertices), front_cpu_s=round(t_front, 2),
            cracks_cpu_s=round(t_cracks, 2), ratio_to_front=round(t_cracks / t_front, 2),
            grids_rebuilt_per_call_cpu_s=round(t_rebuilt, 2),
            ratio_to_rebuilt=round(t_cracks / t_rebuilt, 2), bar_ratio_to_front=MAX_CRACKS_OVER_FRONT)
    assert t_cracks / t_front < MAX_CRACKS_OVER_FRONT, (
        f"the crack stage costs {t_cracks / t_front:.2f}x the growth stage's CPU time; bar "
        f"{MAX_CRACKS_OVER_FRONT} (measured 1.68-1.95, times 1.5)")
    assert np.array_equal(cs.crack_edges, old.crack_edges)
    assert np.array_equal(cs.crack_width, old.crack_width)
