"""Redraw docs/img/h11_knot_bake.png: H11's photos above the evidence fit's colour-map bake of the
same faces (the knot fitted from the knot masks of faces C and F), and the fitted field's ring
lines (integer growth times) drawn on the photos: what the colour map has to show.

Run from the repository root: ``python docs/img/make_h11_knot.py`` (needs ../shared/data or
``$WOODCAM_SHARED_DATA``). It also prints, per face, how the bake compares with the photo:
the correlation of their ring-scale luminance (Gaussian band 1.5-8 px: where the rings fall),
the bake's ring-scale contrast over the photo's, the mean colour difference, and on the knot's
faces the knot's luminance difference and ring-scale contrast ratio (mask eroded by 8 px).
"""

import os
import warnings
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from scipy import ndimage  # noqa: E402

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

LUMA = np.array([0.299, 0.587, 0.114])


def _band(im, lo=1.5, hi=8.0):
    return ndimage.gaussian_filter(im, lo) - ndimage.gaussian_filter(im, hi)


for f, face in block.faces.items():
    pts = face_pixel_points(f, face.shape, block.size_mm).reshape(-1, 3)
    n = np.broadcast_to(np.asarray(FACE_NORMAL[f], float), pts.shape)
    rgb = np.clip(stock.wood.color(pts, n), 0, 1).reshape(face.shape + (3,))
    photo = face.photo / 255.0
    lb, lp = rgb @ LUMA, photo @ LUMA
    bb, bp = _band(lb), _band(lp)
    line = (f"{f:6s} ring corr {np.corrcoef(bb.ravel(), bp.ravel())[0, 1]:5.2f}  contrast {bb.std() / bp.std():4.2f}"
            f"  mean colour diff {np.round(rgb.reshape(-1, 3).mean(0) - photo.reshape(-1, 3).mean(0), 3)}")
    if "knot_mask" in face.extras:
        core = ndimage.binary_erosion(np.asarray(face.extras["knot_mask"], bool), iterations=8)
        kb, kp = _band(lb, 1.0, 6.0), _band(lp, 1.0, 6.0)
        line += (f"  knot: luminance diff {lb[core].mean() - lp[core].mean():+.3f}"
                 f" ring contrast {kb[core].std() / kp[core].std():4.2f}")
    print(line)
