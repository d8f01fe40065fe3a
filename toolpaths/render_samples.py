"""Render the sample programs carved in a built-in block into ``img/`` (README pictures).

    PYTHONPATH=. python toolpaths/render_samples.py [--block builtin:flat-sawn]

Simulates each program with ``tools.toml``, meshes the stock, colours the mesh vertices with the
block's :class:`~woodcam.appearance.Wood` (vertex colours: a quick stand-in for the baked
texture of ``woodcam gcode``) and renders it off-screen with pyvista.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
SAMPLES = ["pocket_islands", "profile_tabs", "relief_raster", "vcarve_text", "drilling"]


def _render_mesh(mesh, size_mm):
    """Vertex colours need vertices where the colour changes: keep the top at full grid
    resolution and subdivide the four walls (one strip of quads each) to 1 mm triangles."""
    import trimesh
    from trimesh.remesh import subdivide_to_size

    W, D, _ = size_mm
    v = np.asarray(mesh.vertices)
    f = np.asarray(mesh.faces)
    tri = v[f]
    on = lambda axis, val: np.all(np.abs(tri[:, :, axis] - val) < 1e-9, axis=1)  # noqa: E731
    wall = on(0, 0) | on(0, W) | on(1, 0) | on(1, D)
    wv, wf = subdivide_to_size(v, f[wall], max_edge=1.0)
    top = trimesh.Trimesh(v, f[~wall], process=False)
    return trimesh.util.concatenate([top, trimesh.Trimesh(wv, wf, process=False)])


def _depth_inset(heightmap, size_mm, height_px):
    """Top view of the height field (cell depth below the top face, viridis), ``height_px`` high."""
    from matplotlib import colormaps
    from PIL import Image

    depth = size_mm[2] - heightmap[::-1]  # row 0 of an image is the back (+Y) edge
    rgb = colormaps["viridis"](depth / max(depth.max(), 1e-9))[..., :3]
    img = Image.fromarray((rgb * 255).astype(np.uint8))
    w = round(height_px * heightmap.shape[1] / heightmap.shape[0])
    return img.resize((w, height_px), Image.Resampling.LANCZOS)


def render(mesh, wood, png, size_mm, window=(640, 440), heightmap=None):
    import pyvista as pv
    from PIL import Image

    mesh = _render_mesh(mesh, size_mm)
    colors = wood.color(np.asarray(mesh.vertices), np.asarray(mesh.vertex_normals))
    faces = np.hstack([np.full((len(mesh.faces), 1), 3), mesh.faces]).ravel()
    poly = pv.PolyData(np.asarray(mesh.vertices), faces)
    poly.point_data["rgb"] = (np.clip(colors, 0, 1) * 255).astype(np.uint8)
    pl = pv.Plotter(off_screen=True, window_size=window)
    pl.add_mesh(poly, scalars="rgb", rgb=True, smooth_shading=True, specular=0.15)
    pl.set_background("white")
    W, D, H = size_mm
    pl.camera.focal_point = (W / 2, D / 2, H / 2)
    pl.camera.position = (W / 2 + 0.25 * W, -1.25 * D, H + 1.6 * D)
    pl.camera.up = (0, 0, 1)
    pl.camera.zoom(1.05)
    pl.enable_anti_aliasing("ssaa")
    img = Image.fromarray(pl.screenshot(return_img=True))
    pl.close()
    if heightmap is not None:  # side panel: the height field seen from above
        inset = _depth_inset(heightmap, size_mm, window[1] - 40)
        canvas = Image.new("RGB", (window[0] + inset.width + 20, window[1]), "white")
        canvas.paste(img, (0, 0))
        canvas.paste(inset, (window[0], 20))
        img = canvas
    img.quantize(colors=192, method=Image.Quantize.MEDIANCUT).save(
        png, optimize=True)


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--block", default="builtin:flat-sawn")
    ap.add_argument("--only", nargs="*", default=SAMPLES)
    args = ap.parse_args(argv)
    from woodcam.stock import open_stock
    from woodcam.toolpath import load_tool_table, read_gcode, simulate

    stock = open_stock(args.block)
    tools = load_tool_table(HERE / "tools.toml")
    (HERE / "img").mkdir(exist_ok=True)
    for name in args.only:
        t0 = time.perf_counter()
        prog = read_gcode(HERE / f"{name}.nc")
        res = simulate(prog, tools, stock.size_mm)
        mesh = res.to_mesh(flat_tol_mm=-1.0)  # full grid: vertex colours need it
        png = HERE / "img" / f"{name}.png"
        render(mesh, stock.wood, png, stock.size_mm, heightmap=res.heightmap)
        print(f"{name}: {len(prog)} moves, {len(mesh.faces)} triangles, watertight "
              f"{mesh.is_watertight}, {png.stat().st_size // 1024} KB, "
              f"{time.perf_counter() - t0:.1f} s; report: {len(res.report)} entries",
              file=sys.stderr)


if __name__ == "__main__":
    main()
