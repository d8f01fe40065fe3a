"""Deviation of a simulated stock from the design part: leftover and overcut per cell, in mm.

Both surfaces are height fields on the simulation grid (block frame, mm): the simulated stock's
``SimResult.heightmap`` and the part's top (:func:`woodcam.toolpath.reference.manifold_heightmap`
of the part solid, the highest upward-facing triangle over each cell centre; 0 where the part
is absent). ``difference_mm = stock - part``: > 0 is material left on the part (leftover), < 0
material cut from the part (overcut, a gouge). A 3-axis program can only reach the part from
above, so the part's top is what it is compared with.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import WoodcamError
from ..tolerances import SIM_CONTACT_TOL_MM
from ..units import Units, say_length, say_volume


@dataclass
class Deviation:
    """Leftover/overcut of a simulation against a part (module docstring).

    ``difference_mm : (ny, nx)`` stock minus part (mm); ``leftover_mm3`` and ``overcut_mm3``
    the volumes of the positive and negative parts; ``gouges`` ``[(line, depth_mm)]``: the
    source lines that last cut cells below the part by more than ``tol_mm``, deepest first.
    """

    difference_mm: np.ndarray
    cell_mm: tuple[float, float]
    leftover_mm3: float
    overcut_mm3: float
    gouges: list[tuple[int, float]] = field(default_factory=list)

    def summary(self, gouges: bool = True, units: Units = "mm") -> str:
        """One line: leftover and overcut volumes with their deepest points and, with
        ``gouges``, the five deepest gouging lines; lengths and volumes in ``units``."""
        worst = ", ".join(f"line {ln} ({fmt_depth(d, units)})" for ln, d in self.gouges[:5])
        # the overcut to 0.1 mm^3: a 0.6 mm^3 overcut must not print as 1
        return (f"leftover {say_volume(self.leftover_mm3, '.0f', units=units)} (max "
                f"{fmt_depth(max(self.difference_mm.max(), 0), units)}), overcut "
                f"{say_volume(self.overcut_mm3, '.1f', units=units)} (max "
                f"{fmt_depth(max(-self.difference_mm.min(), 0), units)})"
                + (f"; gouges at {worst}" + (" ..." if len(self.gouges) > 5 else "")
                   if self.gouges and gouges else ""))


def fmt_depth(mm: float, units: Units = "mm") -> str:
    """Depths to the micrometre in mm (``0.085 mm``), four significant digits in inches."""
    return say_length(mm, ".3f", units=units)


def deviation(result, part, *, tol_mm: float = SIM_CONTACT_TOL_MM * 100) -> Deviation:
    """Compare ``result`` (:class:`~woodcam.toolpath.simulate.SimResult`, ideally run with
    ``track_lines=True``) with ``part`` (a ``manifold3d.Manifold`` in the block frame, mm, e.g.
    :func:`woodcam.cad.load_part`). Overcuts deeper than ``tol_mm`` (default 0.01 mm) are
    listed as gouges by line."""
    from .reference import manifold_heightmap

    hm = np.asarray(result.heightmap, float)
    part_hm = manifold_heightmap(part, result.size_mm, hm.shape)
    diff = hm - part_hm
    area = result.cell_mm[0] * result.cell_mm[1]
    gouges: list[tuple[int, float]] = []
    deep = diff < -tol_mm
    if deep.any() and result.line_map is not None:
        lines = result.line_map[deep]
        depth = -diff[deep]
        order = np.argsort(-depth)
        seen: dict[int, float] = {}
        for ln, d in zip(lines[order].tolist(), depth[order].tolist()):
            if ln > 0 and ln not in seen:
                seen[ln] = d
        gouges = list(seen.items())
    return Deviation(diff, tuple(result.cell_mm), float(np.clip(diff, 0, None).sum() * area),
                     float(np.clip(-diff, 0, None).sum() * area), gouges)


def deviation_png(dev: Deviation, path, *, range_mm: float | None = None, title: str = ""):
    """Write the deviation map as a PNG: red overcut, blue leftover, white on the part, with a
    colour bar in mm (symmetric, ``range_mm`` or the 99th percentile of ``|difference|``).
    Top view, X right, Y up (block frame). Written atomically."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .._atomic import atomic_path

    d = dev.difference_mm
    r = range_mm or float(max(np.percentile(np.abs(d), 99), 1e-3))
    if not (np.isfinite(r) and r > 0):
        raise WoodcamError(f"deviation_png: range_mm must be > 0, got {range_mm!r}")
    ny, nx = d.shape
    W, D = nx * dev.cell_mm[0], ny * dev.cell_mm[1]
    fig, ax = plt.subplots(figsize=(8, 8 * D / W * 0.9 + 1.2), dpi=110)
    im = ax.imshow(-d, origin="lower", extent=(0, W, 0, D), cmap="RdBu_r", vmin=-r, vmax=r,
                   interpolation="nearest")
    cb = fig.colorbar(im, ax=ax, shrink=0.85)
    cb.set_label("overcut (+, red) / leftover (-, blue), mm")
    ax.set_xlabel("X (mm)")
    ax.set_ylabel("Y (mm)")
    ax.set_title(title or dev.summary(gouges=False), fontsize=9)
    with atomic_path(path, mkdir=True) as tmp:
        fig.savefig(tmp, format="png", bbox_inches="tight")
    plt.close(fig)
    return path
