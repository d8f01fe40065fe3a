"""Programs nobody here wrote: OpenCAMLib (PyPI ``opencamlib``) drop-cutter rasters and
waterlines over an STL part, read and simulated by woodcam: the simulated surface never lies
below the part by more than one cell (no gouge), and the finish reaches the part."""

from __future__ import annotations

import numpy as np
import pytest

from woodcam.toolpath import parse_tool_spec, read_gcode, simulate

ocl = pytest.importorskip("opencamlib", reason="opencamlib (dev extra) is not installed")

W, D, H = 60.0, 40.0, 20.0
NX, NY = 31, 21  # part vertices: a 2 mm triangulated height field


def _dome(x, y):
    return 10 + 8 * np.exp(-((x - 30) ** 2 + (y - 20) ** 2) / 150) + 0.8 * np.sin(x / 4)


def _part_stl(tmp_path):
    """The part's top surface as an STL (block frame, mm): a dome with ripples."""
    import trimesh

    xs, ys = np.linspace(0, W, NX), np.linspace(0, D, NY)
    X, Y = np.meshgrid(xs, ys)
    Z = _dome(X, Y)
    a = (np.arange(NY - 1)[:, None] * NX + np.arange(NX - 1)[None, :]).ravel()
    faces = np.concatenate([np.c_[a, a + 1, a + NX + 1], np.c_[a, a + NX + 1, a + NX]])
    path = tmp_path / "part.stl"
    trimesh.Trimesh(np.c_[X.ravel(), Y.ravel(), Z.ravel()], faces).export(path)
    return path, Z


def _part_height(Z, x, y):
    """The triangulated part's height at ``x, y`` (same diagonal split as the STL)."""
    h = W / (NX - 1)
    i = np.clip((x / h).astype(int), 0, NX - 2)
    j = np.clip((y / h).astype(int), 0, NY - 2)
    u, v = x / h - i, y / h - j
    z00, z10, z01, z11 = Z[j, i], Z[j, i + 1], Z[j + 1, i], Z[j + 1, i + 1]
    return np.where(u >= v, z00 + u * (z10 - z00) + v * (z11 - z10),
                    z00 + v * (z01 - z00) + u * (z11 - z01))


def _surface(path):
    s = ocl.STLSurf()
    ocl.STLReader(str(path), s)
    return s


def _gcode(paths, feed=1500):
    """G-code of CL point lists (tool tip, block frame = machine frame with zero offset)."""
    out = ["(OpenCAMLib program)", "G21 G90 G17", "T1 M6", "S18000 M3", f"G0 Z{H + 5:.3f}"]
    for pts in paths:
        out.append(f"G0 X{pts[0][0]:.4f} Y{pts[0][1]:.4f}")
        out.append(f"G1 Z{pts[0][2]:.4f} F{feed}")
        out += [f"G1 X{x:.4f} Y{y:.4f} Z{z:.4f}" for x, y, z in pts[1:]]
        out.append(f"G0 Z{H + 5:.3f}")
    return "\n".join(out + ["M5", "M30"]) + "\n"


def _drop_cutter_raster(surf, diameter, step):
    cutter = ocl.BallCutter(diameter, 30)
    pdc = ocl.PathDropCutter()
    pdc.setSTL(surf)
    pdc.setCutter(cutter)
    pdc.setSampling(0.25)
    pdc.setZ(0)
    rows = []
    for y in np.arange(0, D + 1e-9, step):
        path = ocl.Path()
        path.append(ocl.Line(ocl.Point(0, float(y), 0), ocl.Point(W, float(y), 0)))
        pdc.setPath(path)
        pdc.run()
        rows.append([(p.x, p.y, p.z) for p in pdc.getCLPoints()])
    return rows


def _waterlines(surf, diameter, levels):
    loops = []
    for z in levels:
        wl = ocl.Waterline()
        wl.setSTL(surf)
        wl.setCutter(ocl.CylCutter(diameter, 30))
        wl.setZ(float(z))
        wl.setSampling(0.5)
        wl.run()
        for loop in wl.getLoops():
            pts = [(p.x, p.y, p.z) for p in loop]
            loops.append(pts + pts[:1])
    return loops


def _check_no_gouge(text, tool, Z, resolution=0.25):
    prog = read_gcode(text, start_mm=(0, 0, H + 5))  # work zero is the stock bottom here
    res = simulate(prog, parse_tool_spec(tool), (W, D, H), resolution_mm=resolution,
                   work_offset_mm=(0, 0, 0))
    x, y = res.cell_centres_mm
    part = _part_height(Z, x[None, :], y[:, None])
    over = part - res.heightmap          # > 0: the simulated surface is below the part
    return res, part, over


def test_drop_cutter_raster_has_no_gouge_and_reaches_the_part(tmp_path):
    path, Z = _part_stl(tmp_path)
    text = _gcode(_drop_cutter_raster(_surface(path), 6.0, 1.0))
    res, part, over = _check_no_gouge(text, "ball:6", Z)
    cell = max(res.cell_mm)
    assert over.max() <= cell, f"gouge of {over.max():.3f} mm"
    # a 1 mm step-over with a 6 mm ball leaves scallops of ~0.04 mm: the finish reaches the
    # part everywhere inside the raster
    inner = (slice(8, -8), slice(8, -8))
    assert np.median(-over[inner]) < 0.1 and (-over[inner]).max() < 1.0


def test_waterline_has_no_gouge(tmp_path):
    path, Z = _part_stl(tmp_path)
    loops = _waterlines(_surface(path), 6.0, np.arange(11.0, 18.0, 1.0))
    assert len(loops) >= 5
    res, part, over = _check_no_gouge(_gcode(loops), "flat:6", Z)
    assert over.max() <= max(res.cell_mm), f"gouge of {over.max():.3f} mm"
    assert res.removed_volume_mm3 > 1000  # the levels really cut around the dome


def _part_solid(Z):
    """The dome part as a closed solid (the STL's top triangles, walls and a bottom)."""
    import trimesh

    xs, ys = np.linspace(0, W, NX), np.linspace(0, D, NY)
    X, Y = np.meshgrid(xs, ys)
    top = np.c_[X.ravel(), Y.ravel(), Z.ravel()]
    bot = np.c_[X.ravel(), Y.ravel(), np.zeros(NX * NY)]
    n = NX * NY
    a = (np.arange(NY - 1)[:, None] * NX + np.arange(NX - 1)[None, :]).ravel()
    faces = [np.c_[a, a + 1, a + NX + 1], np.c_[a, a + NX + 1, a + NX],       # top, up
             np.c_[a, a + NX + 1, a + 1] + n, np.c_[a, a + NX, a + NX + 1] + n]  # bottom
    ring = np.concatenate([np.arange(NX - 1), (NX - 1) + NX * np.arange(NY - 1),
                           NX * NY - 1 - np.arange(NX - 1), NX * (NY - 1) - NX * np.arange(NY - 1)])
    nxt = np.roll(ring, -1)
    faces += [np.c_[ring, ring + n, nxt + n], np.c_[ring, nxt + n, nxt]]
    mesh = trimesh.Trimesh(np.vstack([top, bot]), np.vstack(faces), process=False)
    if mesh.volume < 0:
        mesh.invert()
    return mesh


def test_deviation_map_is_zero_on_the_machined_part_and_lists_gouges(tmp_path):
    from woodcam.cad import load_part
    from woodcam.toolpath.deviation import deviation, deviation_png

    path, Z = _part_stl(tmp_path)
    solid = load_part(_part_solid(Z))
    text = _gcode(_drop_cutter_raster(_surface(path), 6.0, 1.0))
    prog = read_gcode(text, start_mm=(0, 0, H + 5))
    good = deviation(simulate(prog, parse_tool_spec("ball:6"), (W, D, H), resolution_mm=0.25,
                              work_offset_mm=(0, 0, 0), track_lines=True), solid)
    inner = good.difference_mm[8:-8, 8:-8]
    assert np.median(np.abs(inner)) < 0.05 and good.overcut_mm3 < 0.5 and not good.gouges
    bad = deviation(simulate(prog, parse_tool_spec("ball:8"), (W, D, H), resolution_mm=0.25,
                             work_offset_mm=(0, 0, 0), track_lines=True), solid)
    assert bad.overcut_mm3 > 10 * max(good.overcut_mm3, 0.1) and bad.gouges
    feed_lines = set(prog.line[prog.kind == 1].tolist())
    assert {ln for ln, _ in bad.gouges} <= feed_lines
    png = deviation_png(bad, tmp_path / "dev.png")
    assert png.stat().st_size > 10_000
