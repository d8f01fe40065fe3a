"""Ring traces of a synthetic face: the integer iso-lines of the true field, in pixels.

Marching squares on the sampled field, then Newton steps on the field itself put every vertex
on its iso-line (:data:`woodcam.tolerances.TRACE_ISO_TOL_YEARS`).
"""

from __future__ import annotations


import numpy as np

from ..block import RingTrace
from ..fields.base import evaluate
from ..fields.rings import iso_lines
from ..frames import pixel_to_block
from ..tolerances import TRACE_FD_STEP_PX, TRACE_ISO_TOL_YEARS


def _refine(field, face, shape, size, rc: np.ndarray, level: np.ndarray, iters: int = 4):
    """Move pixel points ``rc (n, 2)`` onto the iso-lines ``field = level (n,)`` of the face.

    Newton steps along the in-face gradient of the field itself (central differences of
    :data:`TRACE_FD_STEP_PX` px), each step clamped to 1 px. Returns ``(rc, residual_years)``.
    """
    h = TRACE_FD_STEP_PX
    n = len(rc)
    offs = np.array([[0, 0], [h, 0], [-h, 0], [0, h], [0, -h]], float)
    for it in range(iters + 1):
        q = (rc[None, :, :] + offs[:, None, :]).reshape(-1, 2)
        v = evaluate(field, pixel_to_block(face, q[:, 0], q[:, 1], shape, size)).reshape(5, n)
        res = v[0] - level
        if it == iters:
            break
        grad = np.stack([(v[1] - v[2]) / (2 * h), (v[3] - v[4]) / (2 * h)], axis=1)
        g2 = np.maximum((grad ** 2).sum(1), 1e-18)
        step = -(res / g2)[:, None] * grad
        norm = np.linalg.norm(step, axis=1, keepdims=True)
        rc = rc + step * np.minimum(1.0, 1.0 / np.maximum(norm, 1e-18))
    return rc, res


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Half-open index ranges of the True runs of a 1-D bool mask."""
    d = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)))


def _trace_face(field, face, shape, size, g: np.ndarray) -> list[RingTrace]:
    """Clean traces of the integer iso-lines of ``field`` on one face (pixel coordinates).

    Marching squares (:func:`woodcam.fields.rings.iso_lines`) on ``g``, the field sampled at
    pixel centres, gives polylines
    within ``[0, n - 1]`` px (half a pixel short of the face edges); :func:`_refine` then moves
    every vertex onto the true iso-line. Vertices that do not converge (a kink of the field,
    e.g. where a knot meets the stem, or a vanishing gradient) or leave the face are dropped and
    the polyline is split there.
    """
    found = iso_lines(g, first_year=1)  # ring boundaries: years = 1, 2, ...; 0 is the pith
    if not found:
        return []
    levels = [year for year, _ in found]
    lines = [xy for _, xy in found]
    counts = np.array([len(a) for a in lines])
    rc = np.concatenate(lines)
    lev = np.repeat(np.array(levels, float), counts)
    rc, res = _refine(field, face, shape, size, rc, lev)
    inside = ((rc[:, 0] >= -0.5) & (rc[:, 0] <= shape[0] - 0.5)
              & (rc[:, 1] >= -0.5) & (rc[:, 1] <= shape[1] - 0.5))
    ok = inside & (np.abs(res) < TRACE_ISO_TOL_YEARS)
    traces = []
    start = 0
    for k, year in zip(counts, levels):
        seg, good = rc[start:start + k], ok[start:start + k]
        start += k
        for a, b in _runs(good):
            if b - a >= 2:
                traces.append(RingTrace(seg[a:b].copy(), int(year)))
    return traces
