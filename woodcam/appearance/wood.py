"""``Wood``: a growth field plus an appearance; the one seam everything downstream uses."""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from ..errors import WoodcamError
from ..fields.base import arf, check_points, evaluate
from .colormap import ColorMapAppearance

#: Points per work item when colouring in parallel: big enough to amortise numpy's call
#: overhead, small enough that two threads stay busy and memory stays ~50 MB per item.
_CHUNK = 1 << 16


class Wood:
    """Wood with a growth field and an appearance.

    Parameters
    ----------
    field : growth field
        ``field(points_mm (n, 3)) -> years (n,)`` in the block frame.
    appearance : object with ``color(field, points_mm, normals) -> (n, 3)``
        Default: :class:`ColorMapAppearance` with the oak preset.
    threads : int or None
        Worker threads for :meth:`color` (numpy releases the GIL in its kernels);
        default: the number of CPU cores.
    """

    def __init__(self, field, appearance=None, *, threads: int | None = None):
        if not callable(field):
            raise WoodcamError(f"field must be callable as field(points_mm) -> years; got {type(field).__name__}")
        self.field = field
        self.appearance = appearance if appearance is not None else ColorMapAppearance()
        self.threads = max(1, threads or os.cpu_count() or 1)

    def years(self, points_mm) -> np.ndarray:
        """Growth time ``(n,)`` in years at ``points_mm : (n, 3)``."""
        return evaluate(self.field, points_mm)

    def arf(self, points_mm) -> np.ndarray:
        """Annual-ring field ``(n,)`` in [0, 1) at ``points_mm`` (eq. 6 of seed 000)."""
        return arf(self.years(points_mm))

    def color(self, points_mm, normals) -> np.ndarray:
        """Surface colour ``rgb : (n, 3)`` float32 in [0, 1].

        Parameters
        ----------
        points_mm : (n, 3) float
            Surface points, block frame, mm.
        normals : (n, 3) float
            Unit outward surface normals at those points (block frame).
        """
        p = check_points(points_mm)
        n = np.asarray(normals, dtype=np.float32)
        if n.shape != p.shape:
            raise WoodcamError(f"normals must have the shape of points_mm {p.shape}; got {n.shape}")
        out = np.empty((len(p), 3), np.float32)
        starts = range(0, len(p), _CHUNK)

        def work(i):
            out[i:i + _CHUNK] = self.appearance.color(self.field, p[i:i + _CHUNK], n[i:i + _CHUNK])

        if self.threads == 1 or len(p) <= _CHUNK:
            for i in starts:
                work(i)
        else:
            with ThreadPoolExecutor(self.threads) as pool:
                list(pool.map(work, starts))
        return out
