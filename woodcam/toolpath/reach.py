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
are checked one by one. The scan for the next such move and each part's excess are compiled
(:mod:`woodcam.toolpath._reach_kernel`). It runs only for tools with reach data (20,000-move
raster: +0.05 CPU-s when nothing comes near, +0.3 CPU-s with 5 mm of flute that touches often).
"""

from __future__ import annotations

import numpy as np

from ..tolerances import REACH_GRID_MM, REACH_TOL_MM
from ..units import said, say_length

#: Issue kinds of this check (see :class:`woodcam.toolpath.simulate.Issue`).
REACH_KINDS = ("deeper_than_flute", "shank_collision", "holder_collision")


def reach_issues(p0, p1, tool_of, lookup, lines, size_mm, initial_heightmap=None) -> list:
    """Replay the moves ``p0 -> p1 : (n, 3)`` (tool tip, block frame, mm, program order) with
    tools ``lookup[tool_of[k]]`` on a coarse height field of the ``size_mm`` stock (starting
    from ``initial_heightmap`` resampled, or the full block) and return
    ``[(kind, line, message, excess)]`` for every move whose shank or holder meets stock
    (``excess``: how far, mm, above the part's bottom; a line of several moves, an arc's
    chords or a cycle's pecks, has an entry for each move that meets it)."""
    parts_of = {t: tool.reach_parts() for t, tool in lookup.items()}
    if not any(parts_of.values()):
        return []
    from ._reach_kernel import first_tall, part_excess  # numba: imported when needed
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
    n = len(p0)
    lowest = np.minimum(p0[:, 2], p1[:, 2])
    # each move's window of cells within its tool's widest part (+ one cell), its cut window
    # (within its cutter's radius) and the height its lowest part sinks to, all at once
    reach, R_of, low = np.zeros(n), np.zeros(n), np.zeros(n)
    for t, tool in lookup.items():
        on = tool_of == t
        reach[on] = max([tool.radius_mm] + [r for _, r, _ in parts_of[t]]) + max(dx, dy)
        R_of[on] = tool.radius_mm
        # all(lowest + bottom >= top - tol) over the parts is this for the lowest part
        # (rounding is monotone)
        low[on] = lowest[on] + min([bottom for _, _, bottom in parts_of[t]], default=np.inf)
    wi0, wi1, wj0, wj1 = _clipped(_cell_window(p0, p1, reach, dx, dy), nx, ny)
    ci0, ci1, cj0, cj1 = _clipped(_cell_window(p0, p1, R_of, dx, dy), nx, ny)
    cuts = (ci1 >= ci0) & (cj1 >= cj0)
    # above the stock, a straight retract (its start ended the last move) or a window that
    # misses the stock: neither checked nor cut
    retract = (p1[:, 2] > p0[:, 2]) & (p0[:, 0] == p1[:, 0]) & (p0[:, 1] == p1[:, 1])
    moves = np.flatnonzero(~((lowest >= H) | retract | (wi1 < wi0) | (wj1 < wj0)))
    cut = _Cutter(hm, p0, p1, tool_of, lookup, dx, dy, (ci0, ci1, cj0, cj1))
    # moves whose cut is not applied yet (applied in batches, one flush before each move
    # near tall stock): positions in `moves` from `done`
    done = 0
    c = 0
    while True:
        # the stock only ever goes down: a move with nothing in its window above its lowest
        # part even before the pending cuts has nothing there after them (no check needed)
        c = int(first_tall(hm, moves, wj0, wj1, wi0, wi1, low, REACH_TOL_MM, c))
        if c == len(moves):
            break
        batch = moves[done:c]
        cut(batch[cuts[batch]])
        done = c
        k = int(moves[c])
        c += 1
        R = lookup[int(tool_of[k])].radius_mm
        j0, j1, i0, i1 = int(wj0[k]), int(wj1[k]), int(wi0[k]), int(wi1[k])
        top = float(hm[j0:j1 + 1, i0:i1 + 1].max())
        for name, r, bottom in parts_of[int(tool_of[k])]:
            if lowest[k] + bottom >= top - REACH_TOL_MM:
                continue  # nothing in the window stands that high
            # a shank as wide as the cutter runs along the wall the flutes just cut: one
            # coarse cell wider sees that wall (a slot deeper than the flutes)
            e, d2 = part_excess(hm, j0, j1, i0, i1, dx, dy, p0[k], p1[k],
                                max(r, R) + max(dx, dy) if name == "shank" else r, bottom)
            if e <= REACH_TOL_MM:
                continue
            # said(): the message keeps its mm text for the files (the GLB's issue spots, which
            # the review page shows): it was filed in inches under --units inch, beside the
            # other issues' mm
            if name == "holder":
                out.append(("holder_collision", int(lines[k]), said(lambda: (
                    f"the {say_length(2 * r, 'g')} holder ({say_length(bottom, 'g')} above the tip) "
                    f"meets the stock {say_length(e, '.2f')} deep")), e))
            elif d2 <= (R + max(dx, dy)) ** 2:
                out.append(("deeper_than_flute", int(lines[k]), said(lambda: (
                    f"cuts {say_length(e + bottom, '.2f')} deep with {say_length(bottom, 'g')} of "
                    f"flute: the shank rubs {say_length(e, '.2f')} of stock above the flutes")), e))
            else:
                out.append(("shank_collision", int(lines[k]), said(lambda: (
                    f"the {say_length(2 * r, 'g')} shank meets the stock {say_length(e, '.2f')} "
                    f"above the flutes ({say_length(bottom, 'g')})")), e))
    return out


def _clipped(window, nx, ny):
    """A float cell window ``(i0, i1, j0, j1)`` clipped to the ``ny x nx`` grid, as ints
    (empty: ``i1 < i0``)."""
    fi0, fi1, fj0, fj1 = window
    return (np.clip(fi0, 0, nx).astype(np.int64), np.clip(fi1, -1, nx - 1).astype(np.int64),
            np.clip(fj0, 0, ny).astype(np.int64), np.clip(fj1, -1, ny - 1).astype(np.int64))


class _Cutter:
    """Cuts moves (indices into ``p0``, ``p1``; any order: the stock is a minimum over moves)
    from the coarse ``hm`` with the simulation's own kernels, one tool at a time; ``windows =
    (i0, i1, j0, j1)``: each move's cut window, inside the grid."""

    def __init__(self, hm, p0, p1, tool_of, lookup, dx, dy, windows):
        from ._sweep import sweep_update
        from .simulate import _BATCH_CELLS, _compiled_profile, _sweep_batch

        self.hm, self.p0, self.p1, self.tool_of, self.lookup = hm, p0, p1, tool_of, lookup
        self.dx, self.dy, self.windows = dx, dy, windows
        self.sweep_update, self.sweep_batch, self.batch_cells = (sweep_update, _sweep_batch,
                                                                 _BATCH_CELLS)
        self.compiled = {t: _compiled_profile(tool) for t, tool in lookup.items()}
        self.no_map = np.zeros((1, 1), np.int64)

    def __call__(self, idx) -> None:
        from .gcode import FEED

        if not len(idx):
            return
        hm, p0, p1, dx, dy = self.hm, self.p0, self.p1, self.dx, self.dy
        ny, nx = hm.shape
        ci0, ci1, cj0, cj1 = self.windows
        tools = self.tool_of[idx]
        for t in (tools[:1] if len(self.lookup) == 1 else np.unique(tools)):
            sel = idx if len(self.lookup) == 1 else idx[tools == t]
            tool = self.lookup[int(t)]
            i0, i1, j0, j1 = ci0[sel], ci1[sel], cj0[sel], cj1[sel]
            wy = int((j1 - j0).max()) + 1
            wx = int((i1 - i0).max()) + 1
            compiled = self.compiled[int(t)]
            if compiled is not None:  # the compiled kernel, all at once
                self.sweep_update(hm, self.no_map, False, *compiled, float(tool.radius_mm),
                                  np.ascontiguousarray(p0[sel], float),
                                  np.ascontiguousarray(p1[sel], float), np.minimum(j0, ny - wy),
                                  np.minimum(i0, nx - wx), wy, wx, dx, dy, sel,
                                  np.empty(len(sel)))
                continue
            per = max(1, self.batch_cells // (wy * wx))
            kinds = np.full(len(sel), FEED, np.uint8)  # rapids cut too; simulate reports them
            for st in range(0, len(sel), per):
                q = slice(st, st + per)
                self.sweep_batch(hm, None, tool, p0[sel[q]], p1[sel[q]], i0[q], j0[q], i1[q],
                                 j1[q], wy, wx, dx, dy, kinds[q], sel[q], {})


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
