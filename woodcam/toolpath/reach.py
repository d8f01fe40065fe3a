"""Reach checks: where the stock is deeper than a tool's flutes or touches its shank or holder.

A tool that carries reach data (:class:`woodcam.toolpath.tools.Tool`: ``flute_length_mm``,
``shank_diameter_mm``, ``stickout_mm``, ``holder_diameter_mm``) is, above its cutting part, a
stack of non-cutting cylinders (:meth:`Tool.reach_parts`): the shank of radius ``Rs`` from the
flute length up, the holder of radius ``Rh`` from the stick-out up. During a move the part of
bottom height ``b`` above the tip covers every cell within its radius of the move's XY path; a
cell whose remaining stock (before the move) stands above the lowest tip height over the
stretch of the move that covers it, plus ``b``, is hit:

    excess(cell) = stock(cell) - (min over covering t of z_tip(t) + b) > REACH_TOL_MM

The shank's radius is widened by one coarse cell so a shank as wide as the cutter sees the wall
the flutes just cut. Within the cutter's radius (and that cell) a shank hit is a cut deeper than
the flutes (``deeper_than_flute``, depth = stock - tip); beyond it, a shank wider than the
cutter rubbing a wall (``shank_collision``); the holder gives ``holder_collision``.

The stock a move meets is the stock every earlier move left, so the check replays the program
in order on its own coarse grid (:data:`woodcam.tolerances.REACH_GRID_MM`), cutting each move's
swept tool with the same batched kernel as the simulation. Cuts are applied in batches: a move
whose window holds nothing as high as its shank or holder even before the pending cuts (the
stock only goes down) needs no check, so only the moves near tall stock flush the batch and
are checked one by one. It runs only for tools with reach data (20,000-move raster: +0.3 CPU-s
when nothing comes near, +2.4 CPU-s with 5 mm of flute that touches often).
"""

from __future__ import annotations

import numpy as np

from ..tolerances import REACH_GRID_MM, REACH_TOL_MM
from ..units import say_length

#: Issue kinds of this check (see :class:`woodcam.toolpath.simulate.Issue`).
REACH_KINDS = ("deeper_than_flute", "shank_collision", "holder_collision")


def reach_issues(p0, p1, tool_of, lookup, lines, size_mm, initial_heightmap=None) -> list:
    """Replay the moves ``p0 -> p1 : (n, 3)`` (tool tip, block frame, mm, program order) with
    tools ``lookup[tool_of[k]]`` on a coarse height field of the ``size_mm`` stock (starting
    from ``initial_heightmap`` resampled, or the full block) and return
    ``[(kind, line, message)]`` for every move whose shank or holder meets stock."""
    parts_of = {t: tool.reach_parts() for t, tool in lookup.items()}
    if not any(parts_of.values()):
        return []
    W, D, H = (float(v) for v in size_mm)
    nx, ny = max(1, round(W / REACH_GRID_MM)), max(1, round(D / REACH_GRID_MM))
    dx, dy = W / nx, D / ny
    xc, yc = (np.arange(nx) + 0.5) * dx, (np.arange(ny) + 0.5) * dy
    if initial_heightmap is None:
        hm = np.full((ny, nx), H)
    else:  # the earlier program's stock at the coarse cell centres (nearest fine cell)
        fine = np.asarray(initial_heightmap, float)
        fi = np.minimum((xc / W * fine.shape[1]).astype(int), fine.shape[1] - 1)
        fj = np.minimum((yc / D * fine.shape[0]).astype(int), fine.shape[0] - 1)
        hm = fine[np.ix_(fj, fi)].copy()
    out = []
    pending: list[int] = []  # moves whose cut is not applied yet (applied in batches)

    def flush():
        _cut_batch(hm, pending, p0, p1, tool_of, lookup, dx, dy)
        pending.clear()

    # every move's window of cells within its tool's widest part (+ one cell), all at once
    reach = np.zeros(len(p0))
    for t, tool in lookup.items():
        reach[tool_of == t] = max([tool.radius_mm] + [r for _, r, _ in parts_of[t]]) + max(dx, dy)
    fi0, fi1, fj0, fj1 = _cell_window(p0, p1, reach, dx, dy)
    wi0, wi1 = np.clip(fi0, 0, nx).astype(int), np.clip(fi1, -1, nx - 1).astype(int)
    wj0, wj1 = np.clip(fj0, 0, ny).astype(int), np.clip(fj1, -1, ny - 1).astype(int)
    for k in range(len(p0)):
        a, b = p0[k], p1[k]
        if min(a[2], b[2]) >= H or (b[2] > a[2] and a[0] == b[0] and a[1] == b[1]):
            continue  # above the stock, or a straight retract (its start ended the last move)
        if wi1[k] < wi0[k] or wj1[k] < wj0[k]:
            continue  # the move's window misses the stock
        R = lookup[int(tool_of[k])].radius_mm
        parts = parts_of[int(tool_of[k])]
        js, is_ = slice(wj0[k], wj1[k] + 1), slice(wi0[k], wi1[k] + 1)
        lowest = min(a[2], b[2])
        # the stock only ever goes down: if nothing in the window stands above the lowest
        # part even before the pending cuts, nothing does after them (no check needed)
        if all(lowest + bottom >= float(hm[js, is_].max()) - REACH_TOL_MM
               for _, _, bottom in parts):
            pending.append(k)
            continue
        flush()
        cur = hm[js, is_]
        along, d2, L, s, z0 = _frame(a, b, xc[is_], yc[js])
        top = float(cur.max())
        for name, r, bottom in parts:
            if lowest + bottom >= top - REACH_TOL_MM:
                continue  # nothing in the window stands that high
            # a shank as wide as the cutter runs along the wall the flutes just cut: one
            # coarse cell wider sees that wall (a slot deeper than the flutes)
            zlow = _lowest_tip(along, d2, L, s, z0,
                               max(r, R) + max(dx, dy) if name == "shank" else r)
            excess = np.where(np.isfinite(zlow), cur - (zlow + bottom), -np.inf)
            worst = np.unravel_index(int(np.argmax(excess)), excess.shape)
            e = float(excess[worst])
            if e <= REACH_TOL_MM:
                continue
            if name == "holder":
                out.append(("holder_collision", int(lines[k]),
                            f"the {say_length(2 * r, 'g')} holder ({say_length(bottom, 'g')} above the tip) "
                            f"meets the stock {say_length(e, '.2f')} deep"))
            elif d2[worst] <= (R + max(dx, dy)) ** 2:
                out.append(("deeper_than_flute", int(lines[k]),
                            f"cuts {say_length(e + bottom, '.2f')} deep with {say_length(bottom, 'g')} of "
                            f"flute: the shank rubs {say_length(e, '.2f')} of stock above the flutes"))
            else:
                out.append(("shank_collision", int(lines[k]),
                            f"the {say_length(2 * r, 'g')} shank meets the stock {say_length(e, '.2f')} "
                            f"above the flutes ({say_length(bottom, 'g')})"))
        pending.append(k)  # then this move cuts the coarse stock
    flush()
    return out


def _cut_batch(hm, moves, p0, p1, tool_of, lookup, dx, dy) -> None:
    """Cut ``moves`` (indices, any order: the stock is a minimum over moves) from the coarse
    ``hm`` with the simulation's own batched kernel, one tool at a time."""
    from .gcode import FEED
    from .simulate import _BATCH_CELLS, _sweep_batch

    if not moves:
        return
    ny, nx = hm.shape
    idx = np.asarray(moves)
    for t in np.unique(tool_of[idx]):
        sel = idx[tool_of[idx] == t]
        tool = lookup[int(t)]
        R = tool.radius_mm
        a, b = p0[sel], p1[sel]
        fi0, fi1, fj0, fj1 = _cell_window(a, b, R, dx, dy)
        i0, i1 = np.clip(fi0, 0, nx).astype(int), np.clip(fi1, -1, nx - 1).astype(int)
        j0, j1 = np.clip(fj0, 0, ny).astype(int), np.clip(fj1, -1, ny - 1).astype(int)
        ok = (i1 >= i0) & (j1 >= j0)
        sel, a, b, i0, i1, j0, j1 = sel[ok], a[ok], b[ok], i0[ok], i1[ok], j0[ok], j1[ok]
        if not len(sel):
            continue
        wy = int((j1 - j0).max()) + 1
        wx = int((i1 - i0).max()) + 1
        per = max(1, _BATCH_CELLS // (wy * wx))
        kinds = np.full(len(sel), FEED, np.uint8)  # rapids cut too; their report is simulate's
        for st in range(0, len(sel), per):
            q = slice(st, st + per)
            _sweep_batch(hm, None, tool, a[q], b[q], i0[q], j0[q], i1[q], j1[q], wy, wx, dx,
                         dy, kinds[q], sel[q], {})


def _cell_window(p0, p1, r, dx, dy):
    """Cell-index window ``(i0, i1, j0, j1)`` (floats, unclipped: a move to X1e20 must not
    overflow an int cast) of the cells of a ``dx x dy`` mm grid (centres at ``((i + 0.5) dx,
    (j + 0.5) dy)``) that lie within ``r`` mm of the XY bounding box of each move
    ``p0 -> p1 : (n, 3)`` or ``(3,)`` mm (``r`` a number or ``(n,)``):
    ``i0 = ceil((min x - r) / dx - 0.5)``, ``i1 = floor((max x + r) / dx - 0.5)``, and so on in
    y. The one formula of the simulation's and the reach check's windows."""
    x0, x1, y0, y1 = p0[..., 0], p1[..., 0], p0[..., 1], p1[..., 1]
    return (np.ceil((np.minimum(x0, x1) - r) / dx - 0.5),
            np.floor((np.maximum(x0, x1) + r) / dx - 0.5),
            np.ceil((np.minimum(y0, y1) - r) / dy - 0.5),
            np.floor((np.maximum(y0, y1) + r) / dy - 0.5))


def _frame(a, b, x, y):
    """The move's frame at cells ``x (wx,)``, ``y (wy,)``: ``along, d2 (wy, wx)`` and the
    move's XY length, slope dz/dl and start height (a plunge: length 0 at its lower end)."""
    ex, ey = b[0] - a[0], b[1] - a[1]
    L = float(np.hypot(ex, ey))
    cx = (x - a[0])[None, :]
    cy = (y - a[1])[:, None]
    if L < 1e-9:
        return cx + 0 * cy, cx * cx + cy * cy, 0.0, 0.0, float(min(a[2], b[2]))
    ux, uy = ex / L, ey / L
    along = cx * ux + cy * uy
    perp = cx * uy - cy * ux
    return along, perp * perp, L, float((b[2] - a[2]) / L), float(a[2])


def _lowest_tip(along, d2, L, s, z0, r):
    """Lowest tip height over the stretch of the move during which a cylinder of radius ``r``
    about the tool axis covers each cell (``+inf`` where it never does)."""
    re = np.sqrt(np.maximum(r * r - d2, 0.0))
    lo = np.maximum(along - re, 0.0)
    hi = np.minimum(along + re, L)
    z = z0 + s * np.where(s > 0, lo, hi)  # linear in t: the lower end of the stretch
    return np.where((d2 <= r * r) & (lo <= hi), z, np.inf)
