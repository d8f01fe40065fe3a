"""3-axis stock-removal simulation on a height field.

Data form
---------
The stock is the box ``[0, W] x [0, D] x [0, H]`` of the block frame (mm). It is sampled on a
grid of ``ny x nx`` cells, ``nx = round(W / resolution_mm)`` (so the cell size
``dx = W / nx`` is within half a cell of the asked resolution and the grid ends on the stock's
faces). ``heightmap[j, i]`` is the top of the remaining stock (block-frame Z, mm, clamped to
``[0, H]``) above the cell centre ``(X, Y) = ((i + 0.5) dx, (j + 0.5) dy)``: row ``j`` runs along
+Y (depth), column ``i`` along +X (width).

Machine frame: ``G-code (x, y, z) = block (X, Y, Z) - work_offset_mm``; the default offset
``(0, 0, H)`` puts work zero on the stock's top-front-left corner (``docs/conventions.md``).

Sweep kernel
------------
For a straight move from ``p0`` to ``p1`` (tool tip, block frame) the lower envelope of the swept
tool above a cell is ``min over the move of z(l) + profile(|cell - p(l)|)``. With ``a`` the
cell's coordinate along the move's XY direction, ``d`` its distance from the move's XY line and
``s = dz / dl`` the slope, write ``w = l - a``: the envelope is
``z0 + s a + min_w [ s w + h(sqrt(w^2 + d^2)) ]`` over ``w`` in
``[-a, L - a] ∩ [-sqrt(R^2 - d^2), sqrt(R^2 - d^2)]``. The bracket is convex in ``w`` (``h``
convex and non-decreasing, the distance convex), so the constrained minimiser is the
unconstrained one clipped to the interval; each tool solves it in closed form
(:meth:`Tool._sweep`; for the bull nose on ramps a bisection in the numpy path, a bracketed
Newton solve of its contact quartic in the compiled one). The result is exact at every cell
centre, so the only error of the height field is sampling (one cell) and arc chords.

Every tool type of :mod:`woodcam.toolpath.tools` is swept by the compiled kernel of
:mod:`woodcam.toolpath._sweep` (the same formulas, in float64, one pass per cell). A tool of
another type (a subclass) takes the numpy path: moves whose bounding boxes (in cells) fit the same
padded window are stacked into ``(batch, wy, wx)`` float32 arrays and evaluated at once; each
move's window is then min-merged into the height field as one slice (``np.minimum(view, env,
out=view)``: windows of consecutive moves overlap, so a fancy-indexed assignment would lose
updates, and a slice per move avoids the slower unbuffered ``np.minimum.at``). There is no
per-cell Python loop; the per-move Python work is that one slice. Batches are formed within runs
of the program that share a tool and contain no rapid below the stock top, so the rapid check
sees the stock as cut by every earlier move.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Literal, Mapping

import numpy as np

from .._checks import as_floats, check_bool, check_number
from .._repr import summary_repr
from .._types import ArrayLike, Mesh
from ..errors import WoodcamError
from ..tolerances import SIM_CONTACT_TOL_MM
from ..units import said, say_length
from .gcode import FEED, RAPID, Program
from .reach import REACH_KINDS, _cell_window, reach_issues
from .tools import (BallEndMill, BullNoseMill, ChamferMill, FlatEndMill, SnubNoseVBit,
                    TaperedBallMill, Tool, VBit)

#: Most cells of a height field (1 GiB of float64, the same again for a line map).
_MAX_CELLS = 1 << 27
#: Cells evaluated per vectorised batch: ~20 float32 temporaries of 64k cells stay in L2/L3
#: cache (measured 1.4x faster than 1M-cell batches on the raster benchmark).
_BATCH_CELLS = 1 << 16
#: Tools whose swept envelope :mod:`woodcam.toolpath._sweep` computes (exact types: a subclass
#: may change the profile): each type's profile there, ``(kind, params)`` (see that module).
_COMPILED = {BallEndMill: lambda t: (0, ()), FlatEndMill: lambda t: (1, ()),
             VBit: lambda t: (2, (t._k,)),
             BullNoseMill: lambda t: (3, (t.corner_radius_mm,)),
             SnubNoseVBit: lambda t: (4, (0.5 * t.tip_diameter_mm, t._k)),
             ChamferMill: lambda t: (4, (0.5 * t.tip_diameter_mm, t._k)),
             TaperedBallMill: lambda t: (5, t._parts())}


def _compiled_profile(tool: Tool) -> tuple[int, np.ndarray] | None:
    """``(kind, prm (4,) float64)`` of ``tool`` for :func:`woodcam.toolpath._sweep.sweep_update`,
    or ``None`` for a tool it does not know (the numpy :meth:`Tool._sweep` path)."""
    make = _COMPILED.get(type(tool))
    if make is None:
        return None
    kind, prm = make(tool)
    return kind, np.array([float(v) for v in prm] + [0.0] * (4 - len(prm)))


IssueKind = Literal["rapid_through_stock", "below_stock_bottom", "cut_outside_stock",
                    "spindle_off", "deeper_than_flute", "shank_collision", "holder_collision"]

#: Issues of one kind listed one by one before the rest are summarised in one entry.
MAX_ISSUES_PER_KIND = 12


@dataclass(frozen=True)
class Issue:
    """A problem the simulation found on G-code lines ``line .. last_line`` (1-based).
    ``at_mm``: where it first happens (tool tip, block frame, mm): a rapid's first point that
    cuts the stock, where a move goes below the stock bottom, else the middle of the offending
    move; ``None`` where the simulation does not say (the reach checks)."""

    kind: IssueKind
    line: int
    message: str
    last_line: int | None = None
    at_mm: tuple[float, float, float] | None = None

    def __str__(self):
        where = f"line {self.line}" if not self.last_line or self.last_line == self.line \
            else f"lines {self.line}-{self.last_line}"
        return f"{where}: {self.kind}: {self.message}"


def _summarise(issues: dict, move_lines: np.ndarray, excess: dict | None = None) -> list[Issue]:
    """Merge runs of one kind on consecutive moving lines (lines without a move in between,
    such as a lone ``F`` word, do not break a run); cap each kind at MAX_ISSUES_PER_KIND. A
    run says its first line's message, or with ``excess`` (``{(kind, line): mm}``, the reach
    kinds) the message of its worst line (the first of equals)."""
    excess = excess or {}
    ranks = {int(v): k for k, v in enumerate(np.unique(move_lines))}
    out = []
    for kind in ("rapid_through_stock", "below_stock_bottom", "cut_outside_stock", "spindle_off",
                 *REACH_KINDS):
        items = sorted((i for (k, _), i in issues.items() if k == kind), key=lambda i: i.line)
        runs: list[list[Issue]] = []
        for it in items:
            if runs and ranks[it.line] <= ranks[runs[-1][-1].line] + 1:
                runs[-1].append(it)
            else:
                runs.append([it])
        said = [max(r, key=lambda i: excess.get((kind, i.line), -np.inf)) for r in runs]
        merged = [Issue(kind, r[0].line, w.message, r[-1].line, r[0].at_mm)
                  for r, w in zip(runs, said)]
        if len(merged) > MAX_ISSUES_PER_KIND:
            rest = merged[MAX_ISSUES_PER_KIND:]
            n_lines = sum(len(r) for r in runs[MAX_ISSUES_PER_KIND:])
            merged = merged[:MAX_ISSUES_PER_KIND] + [Issue(
                kind, rest[0].line, f"and {n_lines} more lines like this, the last at line "
                f"{rest[-1].last_line}", rest[-1].last_line, rest[0].at_mm)]
        out += merged
    return sorted(out, key=lambda i: (i.line, i.kind))


@dataclass
class SimResult:
    """Result of :func:`simulate` (see the module docstring for the height-field form).

    ``heightmap (ny, nx)`` float: top of the remaining stock over each cell centre, block-frame
    Z in mm (row ``j`` along +Y, column ``i`` along +X); ``size_mm (3,)`` the stock's W, D, H
    mm; ``cell_mm (2,)`` the cell size ``(dx, dy)`` mm; ``report``: the issues found (rapids
    into stock, ...); ``stats``: counts and timings; ``line_map (ny, nx)`` int: the source
    line that cut each cell last (0: not cut), with ``simulate(..., track_lines=True)``, else
    None.
    """

    __repr__ = summary_repr  # arrays as shapes: a notebook shows one line

    heightmap: np.ndarray
    size_mm: tuple[float, float, float]
    cell_mm: tuple[float, float]
    report: list[Issue] = field(default_factory=list)
    stats: dict = field(default_factory=dict)
    line_map: np.ndarray | None = None  # (ny, nx) source line that cut each cell last

    @property
    def cell_centres_mm(self) -> tuple[np.ndarray, np.ndarray]:
        """``(x (nx,), y (ny,))`` block-frame coordinates of the cell centres, mm."""
        ny, nx = self.heightmap.shape
        return ((np.arange(nx) + 0.5) * self.cell_mm[0], (np.arange(ny) + 0.5) * self.cell_mm[1])

    @property
    def removed_volume_mm3(self) -> float:
        """Removed volume (mm^3), midpoint rule over the cells."""
        return float((self.size_mm[2] - self.heightmap).sum() * self.cell_mm[0] * self.cell_mm[1])

    def to_mesh(self, *, flat_tol_mm: float = 1e-9) -> Mesh:
        """Watertight ``trimesh.Trimesh`` of the remaining stock in the block frame (mm).

        See :func:`woodcam.toolpath.mesh.heightfield_mesh`; ``flat_tol_mm`` is how far from
        planar a region may be and still be merged into one fan (1e-9: exactly planar only).
        """
        from .mesh import heightfield_mesh

        return heightfield_mesh(self.heightmap, self.size_mm, flat_tol_mm=flat_tol_mm)


def tool_lookup(program: Program, tools, who: str = "simulate") -> dict[int, Tool]:
    """The tool of each tool number ``program`` uses, from ``tools`` (one :class:`Tool` for all,
    or ``{number: Tool}``: the only one for a program that loads none, the first loaded for
    the rapids before the first M6); a number without a tool is refused, naming its first line
    (``who``: what the message says refused it)."""
    if not isinstance(program, Program):  # G-code text or None was an AttributeError ('tool')
        raise WoodcamError(f"simulate: program must be a Program; got {type(program).__name__}; "
                           "read it first: simulate(read_gcode(text_or_path), tools, size_mm)")
    used = sorted(set(np.unique(program.tool).tolist()))
    if isinstance(tools, Tool):
        return {t: tools for t in used}
    if not isinstance(tools, Mapping) or not all(isinstance(v, Tool) for v in tools.values()):
        raise WoodcamError(f"simulate: tools must be a Tool or a mapping {{number: Tool}}, got "
                           f"{type(tools).__name__}; e.g. {{1: parse_tool_spec('flat:6')}}")
    out = {}
    for t in used:
        if t in tools:
            out[t] = tools[t]
        elif t == 0 and len(tools) == 1:  # program never loads a tool (no M6): the only one
            out[t] = next(iter(tools.values()))
        elif t == 0 and program.tool_of_leading_rapids() in tools:
            # rapids before the first M6 (a safe-Z move): the first tool the program loads
            out[t] = tools[program.tool_of_leading_rapids()]
        else:
            line = int(program.line[np.argmax(program.tool == t)])
            raise WoodcamError(f"{who}: the program uses tool {t} (first at line {line}) "
                               f"but tools has {sorted(tools)}; add T{t} to the tool table or "
                               f"pass --tool {t}=SPEC")
    return out


def _reuse_freed_memory() -> None:
    """Keep freed blocks in the heap (glibc ``mallopt``): the batch temporaries (~0.25 MB
    each) are otherwise handed back to the OS and faulted in again on every batch, which made
    the first simulation of a process 2x slower (raster benchmark: 2.2 s -> 1.1 s CPU, page
    faults 1.6 M -> 1.5 k). A no-op where the C library is not glibc."""
    global _MALLOC_SET
    if _MALLOC_SET:
        return
    _MALLOC_SET = True
    try:
        import ctypes

        libc = ctypes.CDLL("libc.so.6")
        libc.mallopt(-3, 256 << 20)  # M_MMAP_THRESHOLD: blocks below 256 MB from the heap
        libc.mallopt(-1, 512 << 20)  # M_TRIM_THRESHOLD: keep up to 512 MB of freed heap
    except (OSError, AttributeError):
        pass


_MALLOC_SET = False


def simulate(program: Program, tools: Mapping[int, Tool] | Tool, size_mm: ArrayLike, *,
             resolution_mm: float = 0.1, work_offset_mm: ArrayLike | None = None,
             progress: bool = False, initial_heightmap: ArrayLike | None = None,
             track_lines: bool = False) -> SimResult:
    """Remove the swept tools of ``program`` from a ``W x D x H`` stock on a height field.

    Parameters
    ----------
    program : Program
        Straight moves from :func:`woodcam.toolpath.read_gcode` (G-code frame, mm; placed
        in the block by ``work_offset_mm``).
    tools : Tool | Mapping[int, Tool]
        One tool for every move, or the tool table by tool number.
    size_mm : (3,) float
        Stock size ``(W, D, H)``, mm.
    resolution_mm : float
        Cell size (mm), default 0.1.
    work_offset_mm : (3,) float | None
        Block-frame position of G-code zero; ``None`` means ``(0, 0, H)``.
    progress : bool
        Show a tqdm progress bar over the batches.
    initial_heightmap : (ny, nx) float | None
        The stock as an earlier program left it (``SimResult.heightmap`` of the same size and
        resolution): programs of one job (roughing, then finishing) run in sequence.
    track_lines : bool
        Also record in ``SimResult.line_map (ny, nx) int`` the source line that cut each cell
        last (0: not cut), for the deviation map's gouge list (a little slower).

    Returns
    -------
    SimResult
        ``heightmap (ny, nx)``, ``report`` (issues with line numbers), ``stats`` (timings).
    """
    # resolution_mm=True or '0.5' was float()'s 1.0 and 0.5 without a word
    check_number(resolution_mm, "simulate: resolution_mm", lo=0, lo_open=True, fix="use e.g. 0.1")
    # strings and short vectors were bare ValueError/TypeError; complex numbers were taken as
    # their real parts under numpy's ComplexWarning
    size, off_in = (None if v is None else v.reshape(-1) for v in (as_floats(size_mm), as_floats(work_offset_mm)))
    res_mm = float(resolution_mm)
    if size is None or size.shape != (3,) or not np.all(np.isfinite(size) & (size > 0)):
        raise WoodcamError(f"simulate: size_mm must be (W, D, H) finite and > 0 in mm, got {size_mm!r}")
    if work_offset_mm is not None and (off_in is None or off_in.shape != (3,) or not np.isfinite(off_in).all()):
        raise WoodcamError(f"simulate: work_offset_mm must be three finite numbers (X, Y, Z) in mm; "
                           f"got {work_offset_mm!r}")
    resolution_mm = res_mm
    progress = check_bool(progress, "simulate: progress")
    track_lines = check_bool(track_lines, "simulate: track_lines")
    _reuse_freed_memory()
    W, D, H = size
    off = np.array([0.0, 0.0, H]) if off_in is None else off_in
    nx, ny = max(1, round(W / resolution_mm)), max(1, round(D / resolution_mm))
    if nx * ny > _MAX_CELLS:
        # the finest cell that fits (two significant digits, rounded up; checked, since the
        # cell counts round): the message said only 'use a coarser resolution'
        fine = float(f"{math.sqrt(W * D / _MAX_CELLS):.2g}")
        while max(1, round(W / fine)) * max(1, round(D / fine)) > _MAX_CELLS:
            fine = float(f"{fine + 10 ** (math.floor(math.log10(fine)) - 1):.2g}")
        raise WoodcamError(f"simulate: resolution_mm (--cell-size) {say_length(resolution_mm, 'g')} "
                           f"makes {nx} x {ny} = {nx * ny:,} cells of the "
                           f"{say_length((W, D), 'g')} stock, more than the {_MAX_CELLS:,} the "
                           f"height field holds (1 GiB of float64); use {say_length(fine, 'g')} "
                           "or coarser")
    dx, dy = W / nx, D / ny
    lookup = tool_lookup(program, tools)
    t0 = time.perf_counter()
    line_map = np.zeros((ny, nx), np.int64) if track_lines else None
    if initial_heightmap is None:
        hm = np.full((ny, nx), H, float)
    else:
        hm = as_floats(initial_heightmap)  # 'a' was numpy's bare ValueError
        if hm is None or hm.shape != (ny, nx) or not np.isfinite(hm).all():
            got = f"{initial_heightmap!r:.40}" if hm is None else hm.shape
            raise WoodcamError(f"simulate: initial_heightmap must be a finite ({ny}, {nx}) "
                               f"array for this stock and resolution, got {got}; pass the "
                               "heightmap of an earlier simulate() with the same size_mm and "
                               "resolution_mm")
        hm = hm.copy()  # cut in place below: the caller's array stays as it was
    p0 = program.start_mm + off
    p1 = program.end_mm + off
    if not (np.isfinite(p0).all() and np.isfinite(p1).all()):
        bad = int(program.line[np.flatnonzero(~(np.isfinite(p0) & np.isfinite(p1)).all(1))[0]])
        raise WoodcamError(f"simulate: a move of line {bad} has a non-finite coordinate; "
                           "every move must have finite start_mm and end_mm")
    issues: dict[tuple[str, int], Issue] = {}
    tool_of = program.tool
    R = np.zeros(len(program))
    for tnum, tool in lookup.items():
        R[tool_of == tnum] = tool.radius_mm
    zmin = np.minimum(p0[:, 2], p1[:, 2])
    # cell index windows of the swept footprints, in float first (a move to X1e20 must not
    # overflow the int64 cast), then clipped to the grid
    fi0, fi1, fj0, fj1 = _cell_window(p0, p1, R, dx, dy)
    outside = (fi0 < 0) | (fj0 < 0) | (fi1 >= nx) | (fj1 >= ny)
    # Moves reaching far outside the stock are cut to the part that can touch it, so the
    # float32 kernel works on short coordinates (exact: the rest of the move is outside).
    far = outside & ((fi0 < -nx) | (fj0 < -ny) | (fi1 >= 2 * nx) | (fj1 >= 2 * ny))
    inside = np.ones(len(p0), bool)
    if far.any():
        pad = R[far] + max(dx, dy)
        p0[far], p1[far], inside[far] = _clip_segments(
            p0[far], p1[far], np.stack([-pad, -pad], 1), np.stack([W + pad, D + pad], 1))
        fi0, fi1, fj0, fj1 = _cell_window(p0, p1, R, dx, dy)
    i0 = np.clip(fi0, 0, nx).astype(np.int64)
    j0 = np.clip(fj0, 0, ny).astype(np.int64)
    i1 = np.clip(fi1, -1, nx - 1).astype(np.int64)
    j1 = np.clip(fj1, -1, ny - 1).astype(np.int64)
    over = (i1 >= i0) & (j1 >= j0) & inside
    below_top = zmin < H - SIM_CONTACT_TOL_MM
    kind, lines = program.kind, program.line
    # a move ending below the bottom (the retract out of it is not reported again)
    mid = 0.5 * (p0 + p1)
    # (each line and run of lines says its worst: the first said 0.016 mm below the bottom of a
    # helix going 2 mm below it; see _add_worst)
    excess: dict[tuple[str, int], float] = {}
    for k in np.flatnonzero((p1[:, 2] < -SIM_CONTACT_TOL_MM) & over):
        # where the tip goes through the bottom (z = 0), or the start if it is below already
        t = p0[k, 2] / (p0[k, 2] - p1[k, 2]) if p0[k, 2] > 0 else 0.0
        _add_worst(issues, excess, "below_stock_bottom", lines[k], -p1[k, 2],
                   lambda: said(lambda: f"tool tip at z = {say_length(p1[k, 2] - off[2], '.3f')} "
                                f"(G-code frame), {say_length(-p1[k, 2], '.3f')} below the stock "
                                "bottom"), p0[k] + t * (p1[k] - p0[k]))
    for k in np.flatnonzero(below_top & outside & (kind == FEED)):  # its worst: the lowest
        _add_worst(issues, excess, "cut_outside_stock", lines[k], -zmin[k],
                   lambda: said(lambda: f"tool T{tool_of[k]} is below the stock top (z = "
                                f"{say_length(zmin[k] - off[2], '.3f')}) with its footprint "
                                "outside the stock"), mid[k])
    for k in np.flatnonzero(below_top & over & (kind == FEED) & ~(program.spindle_rpm > 0)):
        _add(issues, "spindle_off", lines[k], "feed move into the stock with the spindle off "
             "(no M3/M4 with S > 0 before it, or none since a tool change, which stops it "
             "in LinuxCNC): the controller would cut with a still tool",
             mid[k])
    # tools with reach data: the stock each move meets must not reach the shank or holder
    # (each line and run of lines says its worst hit: the first said 'cuts 10.10 mm deep' of a
    # helix going 15 mm deep with 10 mm of flute)
    for rkind, rline, message, e in reach_issues(p0, p1, tool_of, lookup, lines, size,
                                                 initial_heightmap):
        _add_worst(issues, excess, rkind, rline, e, lambda m=message: m)
    act = np.flatnonzero(below_top & over)  # program order
    # Runs in program order, broken at tool changes and before/after every rapid that reaches
    # below the stock top: the rapid check must see the stock as cut by all earlier moves.
    # Within a run the order does not matter (the height field is a minimum over moves).
    brk = np.zeros(len(act), bool)
    if len(act):
        rap = kind[act] == RAPID
        brk[1:] = (tool_of[act][1:] != tool_of[act][:-1]) | rap[1:] | rap[:-1]
    runs = np.split(np.arange(len(act)), np.flatnonzero(brk))
    cells = 0
    from .._progress import progress_bar

    # over the moves, not the runs: a raster is one run, and its bar stood at 0/1 to the end
    bar = progress_bar(desc="simulate", unit="move", total=len(act), enabled=progress)
    for run in runs:
        if not len(run):
            continue
        idx_run = act[run]
        tool = lookup[int(tool_of[idx_run[0]])]
        # Group moves by window size (rounded up to multiples of 8 cells) so each group is a
        # dense (batch, wy, wx) array of bounded size (small enough to stay in cache).
        wy = (j1[idx_run] - j0[idx_run] + 1 + 7) // 8 * 8
        wx = (i1[idx_run] - i0[idx_run] + 1 + 7) // 8 * 8
        order = np.lexsort((wx, wy))
        idx_run, wy, wx = idx_run[order], wy[order], wx[order]
        breaks = np.flatnonzero((np.diff(wy) != 0) | (np.diff(wx) != 0)) + 1
        for g in np.split(np.arange(len(idx_run)), breaks):
            per = max(1, _BATCH_CELLS // int(wy[g[0]] * wx[g[0]]))
            for st in range(0, len(g), per):
                idx = idx_run[g[st:st + per]]
                cells += _sweep_batch(hm, line_map, tool, p0[idx], p1[idx], i0[idx], j0[idx],
                                      i1[idx],
                                      j1[idx], int(wy[g[0]]), int(wx[g[0]]), dx, dy, kind[idx],
                                      lines[idx], issues, excess)
                bar.update(len(idx))
    bar.close()
    n_active = len(act)
    np.clip(hm, 0.0, H, out=hm)
    wall = time.perf_counter() - t0
    report = _summarise(issues, program.line, excess)
    stats = {"moves": len(program), "moves_cutting_window": n_active, "cell_updates": cells,
             "wall_s": wall, "moves_per_s": len(program) / max(wall, 1e-12),
             "cell_updates_per_s": cells / max(wall, 1e-12), "grid": (ny, nx)}
    return SimResult(hm, (float(W), float(D), float(H)), (float(dx), float(dy)), report, stats, line_map)


def _clip_segments(a, b, lo, hi):
    """Liang-Barsky: the parts of segments ``a -> b`` ``(n, 3)`` whose XY lies in the boxes
    ``lo, hi : (n, 2)``; Z follows the segment (clamped to +/-1e9 mm for the float32 kernel).
    Returns ``(a', b', inside (n,) bool)``.

    Exact rational arithmetic (``fractions``): a move from X-1e20 to X1e20 crosses a 100 mm
    stock at a parameter 0.5 +/- 1e-18 that floats cannot hold. Only moves reaching far outside
    the stock come here (absurd programs), so the per-move Python loop is not a hot path.
    """
    from fractions import Fraction as F

    na, nb = a.copy(), b.copy()
    ok = np.ones(len(a), bool)
    for k in range(len(a)):
        p = [F(float(v)) for v in a[k]]
        d = [F(float(v)) - q for v, q in zip(b[k], p)]
        t0, t1 = F(0), F(1)
        for ax in (0, 1):
            for num, den in ((p[ax] - F(float(lo[k, ax])), -d[ax]),
                             (F(float(hi[k, ax])) - p[ax], d[ax])):
                if den == 0:
                    if num < 0:
                        ok[k] = False
                    continue
                r = num / den
                if den < 0:
                    t0 = max(t0, r)
                else:
                    t1 = min(t1, r)
        if not ok[k] or t0 > t1:
            ok[k] = False
            continue
        na[k] = [float(q + t0 * e) for q, e in zip(p, d)]
        nb[k] = [float(q + t1 * e) for q, e in zip(p, d)]
    np.clip(na[:, 2], -1e9, 1e9, out=na[:, 2])
    np.clip(nb[:, 2], -1e9, 1e9, out=nb[:, 2])
    return na, nb, ok


def _add(issues, kind, line, message, at=None):
    key = (kind, int(line))
    if key not in issues:
        issues[key] = Issue(kind, int(line), message,
                            at_mm=None if at is None else tuple(float(v) for v in at))


def _add_worst(issues, excess, kind, line, e, message, at=None):
    """Keep the worst ``e`` (mm: how deep, how far) of ``(kind, line)``: its ``message()``
    (made only when it is kept), with the first one's ``at`` (where it first happened);
    ``excess`` keeps the ``e`` of each, for :func:`_summarise` to say a run's worst line."""
    key = (kind, int(line))
    if e <= excess.get(key, -np.inf):
        return
    excess[key] = float(e)
    first = issues.get(key)
    issues[key] = Issue(kind, int(line), message(), at_mm=first.at_mm if first else (
        None if at is None else tuple(float(v) for v in at)))


def _rapid_cut(issues, excess, line, depth, first_contact) -> None:
    """A rapid of ``line`` cuts ``depth`` mm into the stock: the line keeps its deepest
    (:func:`_add_worst`; a drilling cycle's rapids, a G28's two legs) at its first rapid's
    first contact (``first_contact()``, sampled only for that rapid)."""
    key = ("rapid_through_stock", int(line))
    _add_worst(issues, excess, *key, depth,
               lambda: said(lambda: f"rapid move (G0) cuts up to {say_length(depth, '.3f')} "
                            "into the stock"), None if key in issues else first_contact())


def _first_contact(tool, a, b, window, j0, i0, dx, dy):
    """The first tip position (block frame, mm, (3,)) along the move ``a -> b`` where ``tool``
    reaches more than SIM_CONTACT_TOL_MM below the stock before the move, sampled every quarter
    cell, at most 16,385 samples (a longer move more coarsely); the middle of the move when no
    sample does (a graze between samples). ``window``: the height field's cells
    ``[j0:j0 + wy, i0:i0 + wx]`` before the move (they hold the move's footprint). Only for the
    few moves reported as issues."""
    R = float(tool.radius_mm)
    wy, wx = window.shape
    di = np.arange(-int(np.ceil(R / dx)) - 1, int(np.ceil(R / dx)) + 2)
    dj = np.arange(-int(np.ceil(R / dy)) - 1, int(np.ceil(R / dy)) + 2)
    n = int(min(1 << 14, max(2, np.ceil(np.linalg.norm(b - a) / (0.25 * min(dx, dy)))))) + 1
    for t in np.array_split(np.linspace(0.0, 1.0, n), max(1, n // 256)):
        p = a + t[:, None] * (b - a)
        i = np.floor(p[:, 0] / dx).astype(np.int64)[:, None, None] + di[None, None, :]
        j = np.floor(p[:, 1] / dy).astype(np.int64)[:, None, None] + dj[None, :, None]
        r = np.hypot((i + 0.5) * dx - p[:, 0, None, None], (j + 0.5) * dy - p[:, 1, None, None])
        li, lj = i - i0, j - j0
        inside = (li >= 0) & (li < wx) & (lj >= 0) & (lj < wy)  # off the grid: no stock
        top = np.where(inside, window[np.clip(lj, 0, wy - 1), np.clip(li, 0, wx - 1)], -np.inf)
        depth = (top - p[:, 2, None, None] - tool.profile(r)).max(axis=(1, 2))
        hit = np.flatnonzero(depth > SIM_CONTACT_TOL_MM)
        if len(hit):
            return p[hit[0]]
    return 0.5 * (a + b)


def _sweep_batch(hm, line_map, tool, a, b, i0, j0, i1, j1, wy, wx, dx, dy, kind, lines,
                 issues, excess=None):
    """Lower envelope of ``len(a)`` straight moves over their windows; min-update ``hm``.

    ``a, b : (n, 3)`` block-frame tip positions (mm); each window is the ``wy x wx`` cells from
    ``(j0, i0)``, shifted to lie inside the grid. Cells of a window that the swept tool does not
    cover come back from the kernel as ``+inf`` (the footprint test is part of the kernel), so
    padding needs no mask. Float32 inside the kernel: coordinates are relative to the move start
    (|x| < ~50 mm, round-off < 1e-5 mm). Returns the number of covered cells. A rapid that
    cuts the stock goes into ``issues`` with its line's deepest cut (:func:`_rapid_cut`; ``excess``
    keeps the depths, ``None`` where no rapid is passed: the reach replay).
    """
    excess = {} if excess is None else excess
    n = len(a)
    ny, nx = hm.shape
    wy, wx = min(wy, ny), min(wx, nx)
    js = np.clip(j0, 0, ny - wy)
    is_ = np.clip(i0, 0, nx - wx)
    compiled = _compiled_profile(tool)
    if compiled is not None:  # one compiled pass, no window temporaries
        from ._sweep import sweep_update

        depth = np.empty(n)
        track = line_map is not None
        # the stock under each rapid before it (its first contact, if it cuts)
        before = {k: hm[js[k]:js[k] + wy, is_[k]:is_[k] + wx].copy()
                  for k in np.flatnonzero(kind == RAPID)}
        cells = sweep_update(hm, line_map if track else np.zeros((1, 1), np.int64), track,
                             *compiled, float(tool.radius_mm), np.ascontiguousarray(a, float),
                             np.ascontiguousarray(b, float), js, is_, wy, wx, dx, dy,
                             np.asarray(lines, np.int64), depth)
        for k in np.flatnonzero((kind == RAPID) & (depth > SIM_CONTACT_TOL_MM)):
            _rapid_cut(issues, excess, lines[k], float(depth[k]), lambda k=k: _first_contact(
                tool, a[k], b[k], before[k], js[k], is_[k], dx, dy))
        return int(cells)
    f32 = np.float32
    cx = ((is_[:, None] + np.arange(wx)[None, :] + 0.5) * dx - a[:, 0, None]).astype(f32)
    cy = ((js[:, None] + np.arange(wy)[None, :] + 0.5) * dy - a[:, 1, None]).astype(f32)
    ex, ey, ez = (b - a).T
    L = np.hypot(ex, ey)
    plunge = L < 1e-9  # vertical move: along = x, clipped to t = 0 below, so rho = |cell - p|
    Ls = np.where(plunge, 1.0, L)
    ux, uy = np.where(plunge, 1.0, ex / Ls), np.where(plunge, 0.0, ey / Ls)
    s = np.where(plunge, 0.0, ez / Ls)
    z0 = np.where(plunge, np.minimum(a[:, 2], b[:, 2]), a[:, 2])
    L = np.where(plunge, 0.0, L)
    col = lambda v: np.asarray(np.clip(v, -1e30, 1e30), f32)[:, None, None]  # noqa: E731
    along = (cx * ux[:, None].astype(f32))[:, None, :] + (cy * uy[:, None].astype(f32))[:, :, None]
    # perpendicular distance directly (rr - along^2 would cancel catastrophically in float32)
    perp = (cx * uy[:, None].astype(f32))[:, None, :] - (cy * ux[:, None].astype(f32))[:, :, None]
    d2 = perp * perp
    env = tool._sweep(along, d2, col(s), col(L), col(z0))
    rap = kind == RAPID
    if rap.any():
        # a rapid cuts stock if its envelope is below the stock as cut by all earlier moves
        for k in np.flatnonzero(rap):
            cur = hm[js[k]:js[k] + wy, is_[k]:is_[k] + wx]
            depth = float((cur - env[k]).max())
            if depth > SIM_CONTACT_TOL_MM:
                _rapid_cut(issues, excess, lines[k], depth, lambda k=k, cur=cur: _first_contact(
                    tool, a[k], b[k], cur, js[k], is_[k], dx, dy))
    for k in range(n):  # scatter: one slice per move (windows overlap, so no fancy indexing)
        view = hm[js[k]:js[k] + wy, is_[k]:is_[k] + wx]
        if line_map is not None:  # remember which line cut each cell last (deviation map)
            lower = env[k] < view
            line_map[js[k]:js[k] + wy, is_[k]:is_[k] + wx][lower] = lines[k]
        np.minimum(view, env[k], out=view)
    return int(np.isfinite(env).sum())
