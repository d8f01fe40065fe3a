"""The files of a parquetry run (see :func:`write_parquetry`) and its printed summary."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np

from .._atomic import all_or_nothing, manifest_path, output_folder, remove_stale, write_text
from .._checks import check_bool, check_path
from ._io import atomic_write_png
from .cutpaths import (
    Piece,
    check_piece,
    panel_outlines,
    svg_document,
    transform_outline,
    write_dxf,
)
from .engine import Parquetry, ParquetryRun, _check_run, _native, feature_cost, ssim_vs_matched
from ..units import message_unit, say_length
from .job import ParquetryJob, write_job

#: Thickness (mm) of the board in panel.glb: 0.6 mm veneer on a 1.5 mm birch ply substrate,
#: the build-up of seed 002 sec. 3.1.
PANEL_THICKNESS_MM = 2.1


def run_pieces(run: ParquetryRun) -> list[Piece]:
    """Every placed patch as a :class:`Piece` with outlines and fabricability problems."""
    ppm = run.params.px_per_mm
    pieces = []
    for p in run.panels:
        outlines = panel_outlines(p, ppm)
        for q in p.patches:
            segs = outlines[q.id]
            sheet = transform_outline(segs, panel_to_sheet_mm(run, q))
            pc = Piece(q.id, q.match.sheet, segs, sheet)
            pc.problems = check_piece(segs, run.params.min_piece_mm, run.params.tool_diameter_mm / 2)
            pieces.append(pc)
    return pieces


def panel_to_sheet_mm(run: ParquetryRun, q) -> np.ndarray:
    """``(2, 3)`` affine taking patch ``q``'s panel mm to real mm on its sheet: the match's
    rigid motion on the working grid, then the sheet's :meth:`~woodcam.parquetry.veneers.Veneer.pixel_scale`
    (the grid's pixel count is rounded: a 50 dpi scan's 520 px stand for 130.048 mm, not 130)."""
    sx, sy = run.veneers[q.match.sheet].pixel_scale()
    return q.target_to_sheet(run.bank, run.params.px_per_mm) * np.array([[sx], [sy]])


def _suffix(run: ParquetryRun, k: int) -> str:
    return "" if len(run.panels) == 1 else f"_{run.panels[k].name}"


def panel_mesh(render: np.ndarray, px_per_mm: float, thickness_mm: float = PANEL_THICKNESS_MM):
    """The panel as a thin textured board (trimesh): top face (z = thickness) shows ``render``;
    x right, y away (the panel's top edge at y = height), z up, mm."""
    import trimesh
    from PIL import Image

    h, w = render.shape[:2]
    W, H, T = w / px_per_mm, h / px_per_mm, thickness_mm
    # Six faces with their own vertices, so the top carries the image and the sides the
    # colour of the nearest edge pixel column (u, v clamped to the image border).
    quads = {
        "top": ([(0, 0, T), (W, 0, T), (W, H, T), (0, H, T)], [(0, 0), (1, 0), (1, 1), (0, 1)]),
        "bottom": ([(0, 0, 0), (0, H, 0), (W, H, 0), (W, 0, 0)], [(0, 0), (0, 1), (1, 1), (1, 0)]),
        "front": ([(0, 0, 0), (W, 0, 0), (W, 0, T), (0, 0, T)], [(0, 0), (1, 0), (1, 0), (0, 0)]),
        "back": ([(W, H, 0), (0, H, 0), (0, H, T), (W, H, T)], [(1, 1), (0, 1), (0, 1), (1, 1)]),
        "left": ([(0, H, 0), (0, 0, 0), (0, 0, T), (0, H, T)], [(0, 1), (0, 0), (0, 0), (0, 1)]),
        "right": ([(W, 0, 0), (W, H, 0), (W, H, T), (W, 0, T)], [(1, 0), (1, 1), (1, 1), (1, 0)]),
    }
    verts, uvs, faces = [], [], []
    for corners, uv in quads.values():
        b = len(verts)
        verts += corners
        uvs += uv
        faces += [(b, b + 1, b + 2), (b, b + 2, b + 3)]
    img = Image.fromarray((np.clip(render, 0, 1) * 255 + 0.5).astype(np.uint8))
    mat = trimesh.visual.material.PBRMaterial(baseColorTexture=img, metallicFactor=0.0,
                                              roughnessFactor=0.8)
    vis = trimesh.visual.TextureVisuals(uv=np.array(uvs, float), material=mat)
    return trimesh.Trimesh(np.array(verts, float), np.array(faces), visual=vis, process=False)


def native_grid(p: Parquetry) -> dict:
    """Which grid a panel's 'native' figures (``feature_cost(..., "native")``,
    ``ssim_vs_matched(..., grid="native")``) are measured on: ``native_px`` its ``[h, w]`` (the
    target's own pixels, or the working grid where those are finer), ``native_grid`` "target" or
    "working", ``target_px`` the target's own ``[h, w]``. The one convention of result.json and
    the benches (the summary called a working grid the target's own)."""
    own = tuple(p.native_shape or p.matched.shape)
    measured = _native(p, "native") or p.matched.shape
    grid = "target" if _native(p, "native") or own[0] <= measured[0] else "working"
    return {"native_px": list(measured), "native_grid": grid, "target_px": list(own)}


def summary(run: ParquetryRun) -> dict:
    """The figures printed and stored in result.json."""
    prm = run.params
    out = {"placed_cells": run.placed, "planned_cells": run.planned, "patches": len(run.patches),
           "complete": run.complete, "message": run.message, "repaired_pieces": len(run.repaired),
           "single_use": prm.single_use,
           "match_seconds": round(run.match_seconds, 3), "match_cpu_seconds": round(run.cpu_seconds, 3),
           "seconds_per_patch": round(run.match_seconds / max(1, len(run.patches)), 4),
           # the README's and the bench's speed figures are CPU seconds: wall seconds on a loaded
           # machine are several times them
           "cpu_seconds_per_patch": round(run.cpu_seconds / max(1, len(run.patches)), 4),
           "panels": []}
    for p in run.panels:
        ok = p.labels >= 0
        # the size its cut files have (pixels over px_per_mm), not cells x patch_mm: a patch is
        # a whole number of pixels (ParquetryParams.patch_px, rounded)
        d = {"name": p.name, "size_mm": list(p.size_mm),
             "cells": list(p.cells.shape), "patches": len(p.patches)}
        if ok.all():
            d.update(feature_cost=feature_cost(p, p.render, prm),
                     feature_cost_baseline=feature_cost(p, p.baseline, prm),
                     ssim=ssim_vs_matched(p, p.render), ssim_baseline=ssim_vs_matched(p, p.baseline),
                     ssim_1mm=ssim_vs_matched(p, p.render, round(prm.px_per_mm)),
                     ssim_1mm_baseline=ssim_vs_matched(p, p.baseline, round(prm.px_per_mm)),
                     **native_grid(p),
                     feature_cost_native=feature_cost(p, p.render, prm, "native"),
                     feature_cost_native_baseline=feature_cost(p, p.baseline, prm, "native"),
                     ssim_native=ssim_vs_matched(p, p.render, grid="native"),
                     ssim_native_baseline=ssim_vs_matched(p, p.baseline, grid="native"),
                     mean_patch_cost_px=float(np.mean([q.cost_px for q in p.patches])))
        out["panels"].append(d)
    return out


def write_parquetry(run: ParquetryRun, out_dir: str | Path, *,
                    glb_writer: Callable[..., Path] | None = None, progress: bool = False,
                    job: ParquetryJob | None = None) -> dict:
    """Write every file of a run into ``out_dir``; returns ``{"files": [...], "summary": {...},
    "problems": {...}}``.

    Files: ``render.png`` (the panel in wood), ``baseline.png`` (each piece's mean colour, the
    paper's Fig. 8 baseline), ``target_matched.png`` (the histogram-matched target, eq. 2),
    ``assembly.svg`` (outlines and ids on the panel), ``veneer_<id>.svg`` / ``.dxf`` per sheet
    that gives a piece (cut paths in sheet mm, tool paths, engraved ids), ``result.json``
    (every patch: region, sheet, rotation, anchor, cost; parameters; figures; fabricability),
    ``panel.glb`` (the panel as a textured board, when ``glb_writer`` is given: pass
    ``woodcam.export_glb``, which sits in a sibling layer), ``job.json`` (the run as a job
    file, when ``job`` is given). Several targets get ``_<name>`` suffixes. The files are one
    set (:func:`woodcam._atomic.all_or_nothing`): an interrupted or failed write leaves the
    folder's previous files as they were, never new ones beside old ones; once they are in
    place, the files an earlier run wrote there and this one does not (sheets not cut this
    time, a ``job.json`` without ``job``) are removed, with a WoodcamWarning naming them; the
    run lists its files in ``.woodcam-parquetry-files.json`` for the next
    (:func:`woodcam._atomic.remove_stale`). In ``result.json`` a sheet no piece is cut from
    has ``file_svg`` null. ``progress``: a bar on stderr while the sheets' cut files are
    written (more than one sheet; off by default).
    """
    import base64
    import io

    from PIL import Image

    _check_run(run, "write_parquetry")
    progress = check_bool(progress, "write_parquetry: progress")
    out = check_path(out_dir, "write_parquetry: out_dir", fix="the folder to write the panels and cut files to")
    output_folder(out, "write_parquetry: out_dir")
    prm = run.params
    ppm = prm.px_per_mm
    files = []
    pieces = run_pieces(run)
    by_id = {pc.id: pc for pc in pieces}
    # one set: a Ctrl-C while the cut files are written left a new render.png and assembly.svg
    # beside the previous run's result.json and sheets
    with all_or_nothing():
        for k, p in enumerate(run.panels):
            sfx = _suffix(run, k)
            files.append(atomic_write_png(out / f"render{sfx}.png", p.render))
            files.append(atomic_write_png(out / f"baseline{sfx}.png", p.baseline))
            files.append(atomic_write_png(out / f"target_matched{sfx}.png", np.repeat(p.matched[..., None], 3, 2)))
            W, H = p.size_mm
            buf = io.BytesIO()
            Image.fromarray((np.clip(p.render, 0, 1) * 255 + 0.5).astype(np.uint8)).save(buf, format="PNG")
            uri = "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode()
            # xlink:href, not SVG 2's plain href: SVG 1.1 readers (Inkscape before 1.3) see only the
            # former, and every browser and SVG 2 reader still reads it
            bg = (f'<image x="0" y="0" width="{W:.3f}" height="{H:.3f}" preserveAspectRatio="none" '
                  f'xlink:href="{uri}"/>')
            doc = svg_document(W, H, [(q.id, by_id[q.id].outline_panel) for q in p.patches],
                               background=bg, title=f"woodcam parquetry assembly {p.name}")
            files.append(write_text(out / f"assembly{sfx}.svg", doc, mkdir=True))
            if glb_writer is not None:
                files.append(glb_writer(panel_mesh(p.render, ppm), out / f"panel{sfx}.glb",
                                        metadata={"kind": "parquetry panel", "units": "mm",
                                                  "size_mm": [W, H, PANEL_THICKNESS_MM]}))
        sheets_used = sorted({pc.sheet for pc in pieces})
        it = sheets_used
        if progress and len(sheets_used) > 1:
            from .._progress import progress_bar

            it = progress_bar(sheets_used, desc="writing cut files", unit="sheet")
        for i in it:
            v = run.veneers[i]
            W, H = v.size_mm
            mine = [(pc.id, pc.outline_sheet) for pc in pieces if pc.sheet == i]
            files.append(write_text(out / f"veneer_{v.id}.svg",
                                    svg_document(W, H, mine, prm.tool_diameter_mm / 2, title=f"woodcam veneer {v.id}"),
                                    mkdir=True))
            files.append(write_dxf(out / f"veneer_{v.id}.dxf", H, mine, prm.tool_diameter_mm / 2))
        summ = summary(run)
        problems = {pc.id: pc.problems for pc in pieces if pc.problems}
        result = {
            "params": {**prm.__dict__, "overlap_mm_used": prm.overlap, "kerf_mm_used": prm.kerf},
            "summary": summ,
            "veneers": [{"id": v.id, "source": v.source, "size_mm": list(v.size_mm),
                         "px_per_mm": v.px_per_mm,
                         # a sheet no piece is cut from has no cut file (null, not a name)
                         "file_svg": f"veneer_{v.id}.svg" if i in sheets_used else None}
                        for i, v in enumerate(run.veneers)],
            "patches": [{"id": q.id, "target": q.target, "row": q.row, "col": q.col, "cells": q.cells,
                         "region_mm": [q.col * prm.patch_mm, q.row * prm.patch_mm, q.cells * prm.patch_mm],
                         "sheet": run.veneers[q.match.sheet].id, "rotation_deg": run.bank.angles_deg[q.match.rot],
                         "anchor_px": [q.match.x, q.match.y], "cost": q.match.cost, "cost_px": q.cost_px,
                         "panel_to_sheet_mm": panel_to_sheet_mm(run, q).tolist()}
                        for q in run.patches],
            "fabricability": {"pieces": len(pieces), "problems": problems,
                              "repaired": {str(k): v for k, v in run.repaired.items()}},
        }
        files.append(write_text(out / "result.json", json.dumps(result, indent=1, default=float), mkdir=True))
        if job is not None:
            files.append(write_job(job, out / "job.json"))
    # an earlier run's sheets (and panels of other targets, a panel.glb under --no-glb, a
    # job.json a run without a job does not describe) are not this run's: sent to the router
    # with the rest, they would be cut for nothing
    remove_stale(out, [f"{stem}{s}" for stem in ("render", "baseline", "target_matched")
                       for s in (".png", "_*.png")]
                 + ["assembly.svg", "assembly_*.svg", "panel.glb", "panel_*.glb", "veneer_*.svg",
                    "veneer_*.dxf", "job.json"], files, kind="parquetry")
    files.append(manifest_path(out, "parquetry"))  # the list of them, for the next run (as woodify's)
    return {"files": [str(f) for f in files], "summary": summ, "problems": problems}


def format_summary(summ: dict, problems: dict) -> str:
    """The lines ``woodcam parquetry`` prints."""
    lines = []
    for d in summ["panels"]:
        # in the message units (--units) too: the panel's size is the one length of the summary
        inch = f" ({say_length(d['size_mm'], sep=' x ')})" if message_unit() != "mm" else ""
        line = (f"{d['name']}: {d['cells'][1]} x {d['cells'][0]} cells, {d['size_mm'][0]:g} x "
                f"{d['size_mm'][1]:g} mm{inch}, {d['patches']} patch{'' if d['patches'] == 1 else 'es'}")
        if "feature_cost" in d:
            def ssim(key):  # None: the grid is narrower than SSIM's 7 x 7 window
                return ("n/a (fewer pixels than its 7 x 7 window)" if d[key] is None
                        else f"{d[key]:.3f} (baseline {d[key + '_baseline']:.3f})")
            line += (f"; feature cost/px {d['feature_cost']:.5f} (mean-colour baseline "
                     f"{d['feature_cost_baseline']:.5f}), SSIM {ssim('ssim')}, at 1 mm pixels "
                     f"{ssim('ssim_1mm')}")
            if d.get("native_grid", "target") == "target":
                line += (f"; on the target's own {d['native_px'][1]} x {d['native_px'][0]} pixels feature "
                         f"cost {d['feature_cost_native']:.5f} (baseline {d['feature_cost_native_baseline']:.5f}), "
                         f"SSIM {ssim('ssim_native')}")
            else:  # no grid coarser than the working one: its figures above are the finest measured
                line += (f"; the target's own {d['target_px'][1]} x {d['target_px'][0]} pixels are finer than "
                         f"the {d['native_px'][1]} x {d['native_px'][0]} px working grid, so the working "
                         f"grid's figures stand for them (raise --px-per-mm to measure finer)")
        lines.append(line)
    lines.append(f"matching: {summ['match_seconds']:.1f} s wall, {summ['match_cpu_seconds']:.1f} CPU-s; per patch "
                 f"{summ['seconds_per_patch']:.3f} s wall, {summ['cpu_seconds_per_patch']:.3f} CPU-s")
    lines.append(f"fabricability: {summ.get('repaired_pieces', 0)} pieces repaired (seams "
                 f"straightened), {len(problems)} pieces with problems left"
                 + ("" if not problems else " (listed in result.json)"))
    if not summ.get("single_use", True):
        # the fabricability line above counts each piece's own shape only: say what it misses
        lines.append("wood reused (--reuse-wood): pieces overlap on the veneer sheets, so the cut files "
                     "cannot be cut as they are (a bound on quality, not a job for the router)")
    if summ["message"]:
        lines.append(summ["message"])
    return "\n".join(lines)
