"""Make the README pictures of woodcam.logs: a generated log (translucent surface + knots) and
its heightmap detail. Run from the repo root: ``python docs/img/make_logs_pictures.py``."""

import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pyvista as pv

from woodcam.logs import generate_log
from woodcam.logs.export import LIVE_KNOT_RGBA, DEAD_KNOT_RGBA, heightmap_image, knot_mesh, surface_mesh

out = sys.argv[1] if len(sys.argv) > 1 else "docs/img"
seed = int(sys.argv[2]) if len(sys.argv) > 2 else 7
log = generate_log(seed, length_mm=2000.0)

# 3-D view: lying log, translucent surface, live knots brown, dead parts dark
pv.OFF_SCREEN = True
pl = pv.Plotter(off_screen=True, window_size=(1400, 420))
s = surface_mesh(log, max_rows=200, max_cols=120)
rot = np.array([[0, 0, 1], [0, 1, 0], [-1, 0, 0]], float)  # log axis z -> view x
pl.add_mesh(pv.wrap(s.vertices @ rot.T).cast_to_unstructured_grid() if False else
            pv.PolyData(s.vertices @ rot.T, np.c_[np.full(len(s.faces), 3), s.faces]),
            color=(0.87, 0.75, 0.55), opacity=0.25, smooth_shading=True)
for k in log.knots:
    m, rgba = knot_mesh(k)
    poly = pv.PolyData(m.vertices @ rot.T, np.c_[np.full(len(m.faces), 3), m.faces])
    poly.cell_data["rgba"] = rgba
    pl.add_mesh(poly, scalars="rgba", rgb=True)
pl.set_background("white")
pl.camera_position = "xz"
pl.camera.elevation = 20
pl.camera.zoom(2.3)
pl.screenshot(f"{out}/log_knots.png")

img, (lo, hi) = heightmap_image(log, "detail")
fig, ax = plt.subplots(figsize=(7, 3.2), dpi=90)
im = ax.imshow((lo + img * (hi - lo)).T[::-1], cmap="RdBu_r", vmin=lo, vmax=hi, aspect="auto",
               extent=[0, log.length_mm, 0, 360])
ax.set_xlabel("l along the log (mm)")
ax.set_ylabel("azimuth (deg)")
ax.set_title(f"heightmap detail (knot bumps + grain), seed {seed}")
fig.colorbar(im, ax=ax, label="mm")
fig.tight_layout()
fig.savefig(f"{out}/log_heightmap.png")
print("wrote", out)
