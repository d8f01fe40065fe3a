"""A growth field baked to a regular grid in the block frame and read back by cubic splines.

Grid samples sit on cell *corners*: sample ``(i, j, k)`` is the block point
``origin_mm + (i, j, k) * spacing_mm``. ``years : (nx, ny, nz) float32`` holds growth time (years
since the pith). Evaluation uses cubic B-spline interpolation (``scipy.ndimage.map_coordinates``
on prefiltered coefficients), so a smooth growth-time field keeps sub-millimetre ring positions
from a 1 mm grid; points outside the grid are clamped to its border (``mode="nearest"``).

This is a stop-gap for ``woodcam.fields.grid.GridField``, which the lead is writing; when it
lands, :func:`bake` should return that class instead (same idea, same ``save``/``load``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import WoodcamError
from ..fields.base import check_points, evaluate
from ..frames import check_size
from ..tolerances import BAKE_MARGIN_MM, BAKE_SPACING_MM


@dataclass
class BakedField:
    """Growth time on a corner-aligned grid, evaluated with cubic splines.

    Attributes
    ----------
    years : (nx, ny, nz) float32
        Growth time (years) at the grid corners.
    origin_mm : (3,) float
        Block-frame position of sample ``(0, 0, 0)``.
    spacing_mm : float
        Grid step (mm), the same on all three axes.
    """

    years: np.ndarray
    origin_mm: np.ndarray
    spacing_mm: float

    def __post_init__(self):
        from scipy import ndimage

        self.years = np.asarray(self.years, dtype=np.float32)
        if self.years.ndim != 3 or min(self.years.shape) < 4:
            raise WoodcamError(
                f"years of a baked field must be a 3-D grid at least 4 samples a side; got {self.years.shape}"
            )
        self.origin_mm = np.asarray(self.origin_mm, dtype=float).reshape(3)
        self.spacing_mm = float(self.spacing_mm)
        self._coef = ndimage.spline_filter(self.years.astype(np.float64), order=3, mode="nearest")

    def __call__(self, points_mm) -> np.ndarray:
        """Growth time ``(n,)`` in years at block points ``(n, 3)`` mm."""
        from scipy import ndimage

        p = check_points(points_mm)
        idx = ((p - self.origin_mm) / self.spacing_mm).T
        return ndimage.map_coordinates(self._coef, idx, order=3, mode="nearest", prefilter=False)

    def save(self, path) -> Path:
        """Write the grid to an ``.npz`` file; returns the path written."""
        path = Path(path)
        np.savez_compressed(path, years=self.years, origin_mm=self.origin_mm,
                            spacing_mm=np.float64(self.spacing_mm), kind=np.str_("woodcam.baked_field"))
        return path if path.suffix == ".npz" else path.with_suffix(path.suffix + ".npz")

    @classmethod
    def load(cls, path) -> "BakedField":
        """Read a grid written by :meth:`save`."""
        try:
            with np.load(path) as z:
                return cls(z["years"], z["origin_mm"], float(z["spacing_mm"]))
        except (OSError, KeyError, ValueError) as err:
            raise WoodcamError(
                f"field file {str(path)!r} is not a baked growth field (.npz with years, origin_mm, "
                f"spacing_mm): {err}; write one with `woodcam fit`"
            ) from err


def bake(field, size_mm, spacing_mm: float = BAKE_SPACING_MM, margin_mm: float = BAKE_MARGIN_MM) -> BakedField:
    """Sample ``field`` on a grid covering the block plus ``margin_mm`` on every side.

    Parameters
    ----------
    field : callable ``(n, 3) mm -> (n,) years``
    size_mm : (W, D, H)
    spacing_mm : grid step in mm
    margin_mm : extra border so spline evaluation at the faces is not a boundary case
    """
    size = check_size(size_mm)
    if not spacing_mm > 0:
        raise WoodcamError(f"spacing_mm must be > 0; got {spacing_mm!r}")
    origin = -float(margin_mm) * np.ones(3)
    n = np.ceil((size + 2 * margin_mm) / spacing_mm).astype(int) + 1
    axes = [origin[i] + spacing_mm * np.arange(n[i]) for i in range(3)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    return BakedField(evaluate(field, grid).reshape(tuple(n)), origin, spacing_mm)
