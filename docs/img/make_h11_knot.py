"""Redraw docs/img/h11_knot_bake.png: H11's photos above the evidence fit's colour-map bake of the
same faces (the knot fitted from the knot masks of faces C and F), and the fitted field's ring
lines (integer growth times) drawn on the photos: what the colour map has to show.

Run from the repository root: ``python docs/img/make_h11_knot.py`` (needs ../shared/data or
``$WOODCAM_SHARED_DATA``).
"""

import os
import warnings
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from woodcam.block.io import read_mokume  # noqa: E402
from woodcam.frames import FACE_NORMAL, face_pixel_points  # noqa: E402
from woodcam.inference.holdout import face_years  # noqa: E402
from woodcam.stock import open_stock  # noqa: E402

FOLDER = Path(os.environ.get("WOODCAM_SHARED_DATA",
                             Path(__file__).resolve().parents[3] / "shared" / "data")) / "mokume" / "H11"
warnings.simplefilter("ignore")
# H11 is a softwood (shared data README; spruce): the Mokume files name no species, and the
# default preset (oak) would lay oak's ring-porous pores and streaks over the fitted rings.
stock = open_stock(str(FOLDER), species="spruce")
block = read_mokume(FOLDER)
faces = ("left", "back", "front", "top")
field = stock.wood.field
fig, ax = plt.subplots(3, len(faces), figsize=(3 * len(faces), 9))
for c, f in enumerate(faces):
    face = block.faces[f]
    pts = face_pixel_points(f, face.shape, block.size_mm).reshape(-1, 3)
    n = np.broadcast_to(np.asarray(FACE_NORMAL[f], float), pts.shape)
    rgb = np.clip(stock.wood.color(pts, n), 0, 1).reshape(face.shape + (3,))
    ax[0, c].imshow(face.photo)
    ax[0, c].set_title(f"{f} photo")
    ax[1, c].imshow(rgb)
    ax[1, c].set_title(f"{f} baked (evidence fit)")
    years = face_years(field, f, face.shape, block.size_mm)
    ax[2, c].imshow(face.photo)
    ax[2, c].contour(years, levels=np.arange(np.floor(years.min()), np.ceil(years.max()) + 1),
                     colors="red", linewidths=0.6)
    ax[2, c].set_title(f"{f}: fitted ring lines")
    for a in ax[:, c]:
        a.axis("off")
plt.tight_layout()
plt.savefig(Path(__file__).with_name("h11_knot_bake.png"), dpi=60)
