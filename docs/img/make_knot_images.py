"""Regenerate the knot pictures of docs/knots.md (needs the shared data; pyvista for the part).

    WOODCAM_SHARED_DATA=/path/to/shared/data python docs/img/make_knot_images.py
"""

from pathlib import Path

import numpy as np
from PIL import Image

from woodcam.logs import render as lr
from woodcam.fields.knots import KnottedLogField, block_at_knot, place_block_in_log
from woodcam.logs.io import read_gran1

OUT = Path(__file__).parent


def _small(path, colours=96):
    Image.open(path).convert("RGB").quantize(colours).save(path, optimize=True)


def main():
    log = read_gran1()
    f = KnottedLogField(log)
    board, disc = lr.default_sections(log, px_per_mm=2.0)
    zc, az, _ = lr.busiest_board(log, length_mm=500, width_mm=140)
    board = lr.tangential_board(log, zc, az, 60.0, length_mm=500, width_mm=140, px_per_mm=2)
    disc = lr.end_grain_disc(log, disc.origin_mm[2], px_per_mm=1.5)
    radial = lr.radial_section(log, 1500.0, 0.4887, length_mm=600, px_per_mm=1.5)
    for name, s in (("gran1_board", board), ("gran1_disc", disc), ("gran1_radial", radial)):
        _small(lr.save_png(lr.render_section(f, s, supersample=2), OUT / f"{name}.png"))
    tiles = []
    for i in (52, 10):                      # a big alive knot, a dead knot with its outline
        p = log.knot_point(i, [100.0])[0]
        c = log.pith_at([p[2]])[0]
        a = np.arctan2(p[1] - c[1], p[0] - c[0])
        s = lr.tangential_board(log, p[2] + 5, a, 100.0, length_mm=64, width_mm=64,
                                px_per_mm=3)
        tiles += [lr.render_section(f, s, supersample=3), np.full((192, 6, 3), 255, np.uint8)]
    _small(lr.save_png(np.concatenate(tiles[:-1], 1), OUT / "gran1_knot_closeups.png"))
    _part(log, f)


def _part(log, f):
    import manifold3d as m3
    import pyvista as pv

    origin, R = block_at_knot(log, 52, (60, 50, 100))
    pf = place_block_in_log(f, origin, R)
    box = m3.Manifold.cube((56, 46, 96)).translate((2, 2, 2))
    part = box - m3.Manifold.cylinder(100, 10, circular_segments=64).rotate((0, 90, 0)) \
        .translate((-20, 25, 82))
    part = part - m3.Manifold.cube((20, 60, 20)).translate((46, -5, -5))
    mesh = part.refine(90).to_mesh()
    v = np.asarray(mesh.vert_properties)[:, :3]
    t = np.asarray(mesh.tri_verts)
    ev = pf.evaluate(v)
    rgb = lr.colour_years(ev["years"], ev)
    pm = pv.PolyData(v, np.hstack([np.full((len(t), 1), 3), t]).ravel())
    pm.point_data["rgb"] = (rgb * 255).astype(np.uint8)
    pl = pv.Plotter(off_screen=True, window_size=(420, 480))
    pl.add_mesh(pm, scalars="rgb", rgb=True)
    pl.camera_position = [(-80, -160, 140), (30, 25, 48), (0, 0, 1)]
    pl.screenshot(str(OUT / "knotty_part.png"))
    _small(OUT / "knotty_part.png", 128)


if __name__ == "__main__":
    main()
