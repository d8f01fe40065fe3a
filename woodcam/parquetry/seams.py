"""Seams between overlapping patches (seed 002, sec. 3.4, eq. 8-9), smoothed for a router.

The panel's finest cells form a grid of ``rows x cols`` cells of ``c`` pixels. Every patch was
matched on its square grown by ``o`` pixels, so across each grid line two patches overlap in a
band of ``2 o`` pixels. A *vertical line* ``k`` (1 <= k < cols, nominally at x = k c) is a
path ``X_k(y)``: for every pixel row y the boundary position (pixel-corner coordinate) with
column ``k - 1`` on its left; *horizontal lines* ``Y_m(x)`` likewise. Each line is found by
dynamic programming over the whole panel (eq. 9: the cost of a boundary at b is the error of
the left patch left of b plus the error of the right patch right of b), with the path moving at
most one pixel per row (the paper's 6-connected cut). Where four patches overlap the two
directions are alternated with the other fixed (the paper: two repetitions suffice); there the
cuts run straight across, so crossings are near-right-angle corners (woodcam's addition for
fabricability).

For a router each path is then smoothed (Gaussian, which keeps it inside its band) until its
radius of curvature is at least the tool radius and half of ``min_piece_mm`` everywhere, and
represented by a cubic spline through knots every ``_KNOT_PX`` pixels, i.e. exactly by cubic
Bézier segments (C1, hence G1). Labels are taken from the smooth curves at pixel centres, so the
render, the cut files and the piece outlines agree.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Spline knot spacing along a seam (pixels at the working resolution): each knot interval
#: becomes one cubic Bézier segment. 8 px = 2 mm at 4 px/mm: well below the 3.5 mm overlap
#: band, so a cubic per interval follows the smoothed cut closely.
_KNOT_PX = 8

#: The DP path keeps this many pixels off its band's edges, so the spline (which may swing
#: slightly past its samples) stays inside the grown windows the patches were matched on.
_BAND_MARGIN_PX = 1


@dataclass
class SeamLine:
    """One grid line as a smooth curve.

    axis : "v" (x as a function of y) or "h" (y as a function of x)
    index : k of the line (nominal position k * cell)
    raw : (n,) int the DP boundary positions per pixel row/column (6-connected: steps <= 1)
    knots : (m,) float knot positions along the line's parameter (pixels, corner coordinates)
    spline : scipy CubicSpline of the offset, parameter -> position (pixels)
    """

    axis: str
    index: int
    raw: np.ndarray
    knots: np.ndarray
    spline: object

    def __call__(self, t):
        return self.spline(t)


def _line_from(values: np.ndarray, axis: str, index: int, length: int, raw: np.ndarray) -> SeamLine:
    from scipy.interpolate import CubicSpline

    centres = np.arange(length) + 0.5
    knots = np.unique(np.concatenate([np.arange(0, length, _KNOT_PX, dtype=float), [float(length)]]))
    v = np.interp(knots, centres, values)
    return SeamLine(axis, index, raw, knots, CubicSpline(knots, v, bc_type="natural"))


def _max_curvature(line: SeamLine) -> float:
    t = np.linspace(line.knots[0], line.knots[-1], 8 * len(line.knots))
    d1, d2 = line.spline(t, 1), line.spline(t, 2)
    return float(np.max(np.abs(d2) / (1 + d1 * d1) ** 1.5))


def smooth_line(raw: np.ndarray, axis: str, index: int, min_radius_px: float) -> SeamLine:
    """Smooth a DP path until its curvature radius is >= ``min_radius_px`` everywhere."""
    from scipy.ndimage import gaussian_filter1d

    vals = raw.astype(float)
    length = len(raw)
    sigma = max(1.0, 0.5 * np.sqrt(max(min_radius_px, 1.0)))
    for _ in range(20):
        s = gaussian_filter1d(vals, sigma, mode="nearest")
        line = _line_from(s, axis, index, length, raw)
        if min_radius_px <= 0 or _max_curvature(line) * min_radius_px <= 1.0:
            return line
        sigma *= 1.5
    # A straight line at the rounded mean always satisfies the bound and stays in the band;
    # an integer sits on pixel edges, never on the pixel centres the labels are taken at.
    return _line_from(np.full(length, float(np.round(vals.mean()))), axis, index, length, raw)


def straight_line(pos: float, axis: str, index: int, length: int) -> SeamLine:
    return _line_from(np.full(length, float(pos)), axis, index, length, np.full(length, round(pos)))


def _dp(cost: np.ndarray, frozen: np.ndarray | None = None) -> np.ndarray:
    """Minimum path through ``cost (K, n, B)`` for K lines at once, moving <= 1 per step
    (not at all into a step where ``frozen (n,)`` is True): returns ``(K, n)`` indices into B."""
    K, n, B = cost.shape
    acc = cost[:, 0].copy()
    back = np.zeros((K, n, B), np.int8)
    big = np.inf
    for i in range(1, n):
        left = np.concatenate([np.full((K, 1), big), acc[:, :-1]], axis=1)
        right = np.concatenate([acc[:, 1:], np.full((K, 1), big)], axis=1)
        if frozen is not None and frozen[i]:
            left = right = np.full_like(acc, big)
        stack = np.stack([left, acc, right], axis=0)
        arg = np.argmin(stack, axis=0)
        back[:, i] = arg.astype(np.int8) - 1
        acc = np.take_along_axis(stack, arg[None], axis=0)[0] + cost[:, i]
    path = np.empty((K, n), np.int64)
    path[:, -1] = np.argmin(acc, axis=1)
    for i in range(n - 1, 0, -1):
        path[:, i - 1] = path[:, i] + back[np.arange(K), i, path[:, i]]
    return path


def _index_map(lines: list[SeamLine], coords_across: np.ndarray, coords_along: np.ndarray) -> np.ndarray:
    """For points (along, across) the number of lines whose position at ``along`` is <= across."""
    n = np.zeros(coords_across.shape, np.int64)
    for ln in lines:
        n += (ln(coords_along) <= coords_across)
    return n


def cut_seams(p, windows: dict, params, repetitions: int = 2):
    """Seams of a complete panel (see module docstring).

    Parameters
    ----------
    p : :class:`~woodcam.parquetry.engine.Parquetry` with ``cells`` all placed
    windows : ``{patch_id: ((y0, x0, y1, x1), feats (h, w, 2))}`` the rotated sheet features
        under each patch's grown window
    params : ParquetryParams

    Returns ``(labels (H, W) int, vertical lines, horizontal lines)``.
    """
    H, W = p.matched.shape
    rows, cols = p.cells.shape
    c, o = p.cell_px, params.overlap_px
    T = p.target_feats
    err = {}
    for pid, ((y0, x0, y1, x1), F) in windows.items():
        err[pid] = (((F - T[y0:y1, x0:x1]) ** 2).sum(axis=2), y0, x0)
    lo, hi = -o + _BAND_MARGIN_PX, o - _BAND_MARGIN_PX     # boundary offsets allowed
    B = hi - lo + 1
    # Curvature bound: the tool radius (concave side of either piece) and half the smallest
    # piece (a convex bump tighter than that is a feature narrower than min_piece_mm).
    min_r = 0.5 * max(params.tool_diameter_mm, params.min_piece_mm) * params.px_per_mm
    v_lines = [straight_line(k * c, "v", k, H) for k in range(1, cols)]
    h_lines = [straight_line(m * c, "h", m, W) for m in range(1, rows)]

    def solve(axis: str, across_lines: list[SeamLine]) -> list[SeamLine]:
        n_lines = (cols if axis == "v" else rows) - 1
        length = H if axis == "v" else W
        if n_lines <= 0:
            return []
        band = np.arange(lo, hi)               # pixel offsets in the band (left of boundary 0 is -1)
        along = np.arange(length) + 0.5
        cost = np.zeros((n_lines, length, B))
        for li in range(n_lines):
            k = li + 1
            pos = k * c + band                 # pixel index across the line
            # cell index along the line for each (along, band pixel), from the other lines
            A, P = np.meshgrid(along, pos + 0.5, indexing="ij")
            idx = _index_map(across_lines, A, P)           # (length, band) row (or col) index
            if axis == "v":
                left = p.cells[idx, k - 1]
                right = p.cells[idx, k]
            else:
                left = p.cells[k - 1, idx]
                right = p.cells[k, idx]
            eL = np.zeros(A.shape)
            eR = np.zeros(A.shape)
            ai = np.arange(length)[:, None].repeat(len(band), 1)
            pi = np.broadcast_to(pos[None, :], A.shape)
            ys, xs = (ai, pi) if axis == "v" else (pi, ai)
            for pid in np.unique(np.concatenate([left.ravel(), right.ravel()])):
                e, y0, x0 = err[int(pid)]
                for ids, out in ((left, eL), (right, eR)):
                    sel = ids == pid
                    if sel.any():
                        out[sel] = e[ys[sel] - y0, xs[sel] - x0]
            # boundary b (offset lo..hi): band pixels < b go left, >= b go right (eq. 9)
            cl = np.concatenate([np.zeros((length, 1)), np.cumsum(eL, axis=1)], axis=1)
            cr = np.concatenate([np.cumsum(eR[:, ::-1], axis=1)[:, ::-1], np.zeros((length, 1))], axis=1)
            cost[li] = cl + cr
        # Across the four-patch zones round the crossings the cut runs straight, so every
        # crossing is a near-right-angle corner (a sharp one would leave a spike narrower than
        # min_piece_mm); the alternation still chooses where along the band it crosses.
        frozen = np.zeros(length, bool)
        n_across = (rows if axis == "v" else cols)
        for m in range(1, n_across):
            frozen[max(0, m * c - o - 1):min(length, m * c + o + 1)] = True
        paths = _dp(cost, frozen) + lo
        return [smooth_line((li + 1) * c + paths[li], axis, li + 1, min_r) for li in range(n_lines)]

    for _ in range(repetitions):
        v_lines = solve("v", h_lines)
        h_lines = solve("h", v_lines)
    return labels_from_lines(p, v_lines, h_lines), v_lines, h_lines


def labels_from_lines(p, v_lines: list[SeamLine], h_lines: list[SeamLine]) -> np.ndarray:
    """Patch id of every panel pixel from the smooth seam curves (pixel-centre rule)."""
    H, W = p.matched.shape
    yy, xx = np.mgrid[0:H, 0:W] + 0.5
    col = _index_map(v_lines, xx, yy)
    row = _index_map(h_lines, yy, xx)
    return p.cells[row, col]


def straight_labels(p) -> np.ndarray:
    """Patch id of every pixel for square patches (no seams); -1 where no patch was placed."""
    return np.repeat(np.repeat(p.cells, p.cell_px, axis=0), p.cell_px, axis=1)


def grid_lines(p) -> tuple[list[SeamLine], list[SeamLine]]:
    """The panel's seam curves, or straight lines at the cell edges when it has none."""
    H, W = p.matched.shape
    rows, cols = p.cells.shape
    if p.seams_v is not None:
        return p.seams_v, p.seams_h
    return ([straight_line(k * p.cell_px, "v", k, H) for k in range(1, cols)],
            [straight_line(m * p.cell_px, "h", m, W) for m in range(1, rows)])
