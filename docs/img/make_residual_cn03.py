"""Regenerate docs/img/residual_cn03.png: CN03's six faces, photo and ring map next to the
default evidence fit's rings and the same fit with the small-scale residual (issue 12 part 4)
forced on, and the residual itself. On CN03 leave-one-face-out does not keep the residual
(``fit_evidence(residual=True)``), so the default is what ``fit_block(residual=True)`` returns;
the forced column shows what it would have added.

    WOODCAM_SHARED_DATA=/work/shared/data python docs/img/make_residual_cn03.py
"""

import os
import warnings
from pathlib import Path

import numpy as np

from woodcam.block.io import read_mokume
from woodcam.fields.base import arf
from woodcam.fields.residual import ResidualField
from woodcam.frames import MOKUME_LETTER
from woodcam.inference.evidence import fit_evidence
from woodcam.inference.holdout import face_years
from woodcam.inference.observations import gather_observations
from woodcam.inference.radial import fit_radial_hypotheses
from woodcam.inference.residual import fit_face_residual

OUT = Path(__file__).parent / "residual_cn03.png"


def main():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    warnings.simplefilter("ignore")
    data = Path(os.environ.get("WOODCAM_SHARED_DATA", "../shared/data"))
    block = read_mokume(data / "mokume" / "CN03")
    obs = gather_observations(block)
    ev = fit_evidence(obs, block.size_mm, residual=True, warn=False)
    base = ev.hypotheses[ev.chosen]
    numbered = fit_radial_hypotheses(obs, block.size_mm)[1]  # the ring maps' rings, numbered as fit_evidence does
    res = fit_face_residual(numbered, base, block.size_mm)
    forced = ResidualField(base, res)
    faces = list(block.faces)
    fig, axes = plt.subplots(len(faces), 5, figsize=(15, 3 * len(faces)))
    titles = ["photo", "ring map (Mokume U-Net)", f"default fit ({ev.chosen})",
              "with the residual, forced", "residual (years)"]
    for row, face in zip(axes, faces):
        f = block.faces[face]
        y0 = face_years(base, face, f.shape, block.size_mm)
        y1 = face_years(forced, face, f.shape, block.size_mm)
        row[0].imshow(f.photo)
        row[1].imshow(f.ring_map, cmap="gray")
        row[2].imshow(arf(y0), cmap="copper")
        row[3].imshow(arf(y1), cmap="copper")
        im = row[4].imshow(y1 - y0, cmap="RdBu", vmin=-0.5, vmax=0.5)
        row[0].set_ylabel(f"{face} ({MOKUME_LETTER[face]})")
        for ax in row:
            ax.set_xticks([])
            ax.set_yticks([])
    for ax, t in zip(axes[0], titles):
        ax.set_title(t)
    fig.colorbar(im, ax=axes[:, 4], shrink=0.3)
    fig.suptitle(f"CN03: {ev.residual['why']}; residual kept: {ev.residual['kept']} "
                 f"(max |r| on the faces {np.abs(res.amplitude_years()):.2f} years)")
    fig.savefig(OUT, dpi=55, bbox_inches="tight")
    print(f"wrote {OUT}; {ev.message}")


if __name__ == "__main__":
    main()
