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

    A wood made by :meth:`turned` maps its points and normals back to the source block's frame
    before the field and the appearance see them.
    """

    def __init__(self, field, appearance=None, *, threads: int | None = None):
        if not callable(field):
            raise WoodcamError(f"field must be callable as field(points_mm) -> years; got {type(field).__name__}")
        self.field = field
        self.appearance = appearance if appearance is not None else ColorMapAppearance()
        self.threads = max(1, threads or os.cpu_count() or 1)
        #: (R (3, 3), t (3,)) with source point = R^T (p - t), or None (this block's own frame)
        self._turn: tuple[np.ndarray, np.ndarray] | None = None

    def turned(self, axis: str, quarter_turns: int, size_mm) -> tuple["Wood", tuple]:
        """The same wood with the block turned ``quarter_turns`` x 90 degrees about the block
        axis ``axis`` (``"x"``, ``"y"`` or ``"z"``, right hand rule), e.g. to run the grain along
        another axis under a part that stays put.

        Parameters
        ----------
        axis : {"x", "y", "z"}
        quarter_turns : int
        size_mm : (3,) float
            The block's size (W, D, H) before turning.

        Returns
        -------
        (Wood, (W', D', H'))
            The turned wood, in the turned block's frame (origin at its bottom-front-left
            corner), and the turned block's size.
        """
        if axis not in ("x", "y", "z") or int(quarter_turns) != quarter_turns:
            raise WoodcamError(
                f"turned: axis must be 'x', 'y' or 'z' and quarter_turns an integer; got "
                f"axis={axis!r}, quarter_turns={quarter_turns!r}; e.g. turned('z', 1, size)")
        k = int(quarter_turns) % 4
        i, j = {"x": (1, 2), "y": (2, 0), "z": (0, 1)}[axis]  # cyclic: e_i -> e_j
        rot = np.eye(3)
        for _ in range(k):  # exact integer quarter turns: (e_i, e_j) -> (e_j, -e_i)
            step = np.eye(3)
            step[i, i] = step[j, j] = 0.0
            step[j, i], step[i, j] = 1.0, -1.0
            rot = step @ rot
        size = np.asarray(size_mm, dtype=float)
        corners = np.array(np.meshgrid(*[(0.0, v) for v in size], indexing="ij")).reshape(3, -1).T
        moved = corners @ rot.T
        shift = -moved.min(axis=0)
        out = Wood(self.field, self.appearance, threads=self.threads)
        inner = self._turn
        if inner is None:
            out._turn = (rot, shift)
        else:  # compose: new -> this wood's frame -> its source
            r0, t0 = inner
            out._turn = (rot @ r0, rot @ t0 + shift)
        new_size = tuple(float(v) for v in np.abs(rot) @ size)
        return out, new_size

    def _to_source(self, points, normals=None):
        if self._turn is None:
            return points, normals
        rot, shift = self._turn
        p = ((points - shift) @ rot).astype(points.dtype, copy=False)
        n = None if normals is None else (normals @ rot).astype(normals.dtype, copy=False)
        return p, n

    def years(self, points_mm) -> np.ndarray:
        """Growth time ``(n,)`` in years at ``points_mm : (n, 3)``."""
        p, _ = self._to_source(check_points(points_mm))
        return evaluate(self.field, p)

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
        p, n = self._to_source(p, n)
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
