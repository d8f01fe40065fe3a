"""The parquetry pipeline of seed 002 (sec. 3.2-3.4): targets cut into patches, each matched on
the veneer sheets under single use, seams cut, the panel rendered.

Target images are resampled to the working resolution ``px_per_mm``; panel pixel ``(r, c)``
covers ``[c, c + 1] x [r, r + 1] / px_per_mm`` mm (x right, y down, origin top-left, as SVG).
The panel is an integer number of the finest cells (``patch_mm``): its short side is rounded
to whole cells (Table 1: 360 mm -> 26 x 14 = 364 mm), the long side cropped centrally.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from .._checks import check_bool
from .._repr import summary_repr
from ..errors import WoodcamError
from ..units import say_length
from .features import edge, features, intensity, match_histogram
from .job import ParquetryParams
from .matching import Match, SheetBank, edge_margin_px
from .veneers import Veneer, check_veneer_id


@dataclass
class Patch:
    """One placed patch.

    id : unique over all targets of a run (engraved on the pieces)
    target : index of its target
    row, col, cells : its square in finest cells (top-left cell, side in cells)
    grown : ``(y0, x0, y1, x1)`` panel pixels of the matched window (square + overlap, clipped)
    match : sheet, rotation, anchor and SSD of eq. 4
    cost_px : ``match.cost`` per pixel of the window
    """

    id: int
    target: int
    row: int
    col: int
    cells: int
    grown: tuple[int, int, int, int]
    match: Match
    cost_px: float

    def target_to_sheet(self, bank: SheetBank, px_per_mm: float) -> np.ndarray:
        """``(2, 3)`` affine taking panel mm (x, y) to mm (x, y) on the sheet's working grid
        for this patch: sheet pixels over ``px_per_mm``, not yet the sheet's real mm (its pixel
        count is rounded; :func:`woodcam.parquetry.output.panel_to_sheet_mm` gives those)."""
        mat, _ = bank.rotation(self.match.sheet, self.match.rot)
        ainv = np.linalg.inv(mat[:, :2])
        y0, x0 = self.grown[:2]
        # panel px p -> canvas px p - (x0, y0) + (mx, my) -> sheet px ainv (q - t)
        off = np.array([self.match.x - x0, self.match.y - y0], float)
        lin = ainv
        # mm: p = m ppm - 0.5 ; sheet_mm = (sheet_px + 0.5) / ppm
        tr = ainv @ (off - 0.5 - mat[:, 2]) + 0.5
        out = np.empty((2, 3))
        out[:, :2] = lin
        out[:, 2] = tr / px_per_mm
        return out


@dataclass
class Parquetry:
    """One assembled target.

    target_rgb : (H, W, 3) float32 the target cropped and resampled to the panel
    matched : (H, W) float32 the histogram-matched target intensity (eq. 2)
    target_feats : (H, W, 2) float32 its features (eq. 1 with eq. 2's intensity)
    cells : (rows, cols) int: patch id of every finest cell, -1 where none was placed
    labels : (H, W) int: patch id of every panel pixel after the seams, -1 where none
    render, baseline : (H, W, 3) float32 the panel in wood, and each piece's mean colour
    seams_v, seams_h : seam curves (see :mod:`woodcam.parquetry.seams`) or None
    native_shape : (h, w) the panel in the target image's own pixels (what it was resampled
        from): the finest grid on which the target carries information
    px_per_mm : the working resolution the panel's pixels are at (``params.px_per_mm``)
    """

    index: int
    name: str
    target_rgb: np.ndarray
    matched: np.ndarray
    target_feats: np.ndarray
    cell_px: int
    cells: np.ndarray
    px_per_mm: float
    patches: list[Patch] = field(default_factory=list)
    labels: np.ndarray | None = None
    render: np.ndarray | None = None
    baseline: np.ndarray | None = None
    seams_v: list | None = None
    seams_h: list | None = None
    native_shape: tuple[int, int] | None = None
    # The target side of the metrics on another grid, ``{key: array}``, computed once per
    # panel (the summary asks for the render's and the baseline's figures on the same grid).
    _metric_targets: dict = field(default_factory=dict, repr=False, compare=False)

    def metric_target(self, what: Literal["matched", "features"], shape: tuple[int, int] | None,
                      w_intens: float = 0.5, w_edge: float = 0.5) -> np.ndarray:
        """The matched target ``(h, w)`` or its eq. 1 features ``(h, w, 2)``, area-averaged to
        ``shape`` (None: the working grid, as matched); cached per panel."""
        key = (what, shape, w_intens, w_edge) if what == "features" else (what, shape)
        if key not in self._metric_targets:
            if what == "matched":
                val = _area(self.matched, shape)
            elif shape is None:
                val = self.target_feats
            else:
                val = np.stack([w_intens * _area(self.matched, shape),
                                w_edge * edge(_area(intensity(self.target_rgb), shape))], axis=-1)
            self._metric_targets[key] = val
        return self._metric_targets[key]

    @property
    def size_mm(self) -> tuple[float, float]:
        """The panel's ``(width, height)`` in mm: its pixels over ``px_per_mm``, the size its
        cut files have."""
        return self.cells.shape[1] * self.cell_px / self.px_per_mm, self.cells.shape[0] * self.cell_px / self.px_per_mm

    @property
    def complete(self) -> bool:
        return bool((self.cells >= 0).all())


@dataclass
class ParquetryRun:
    """Everything a run made: the targets' panels, the sheets, the bank (consumed wood), timing.

    ``placed`` / ``planned``: patches placed of those planned; ``message``: why a run stopped
    short ("the veneers ran out of free wood: ..." with a fix), ``""`` for a complete one;
    ``match_seconds`` (wall clock)
    and ``cpu_seconds``, s; ``repaired``: piece (patch) id -> what :func:`repair_fabricability`
    changed. Panel images and patch windows are in panel pixels at ``params.px_per_mm``
    (:class:`Patch`), veneers in their own pixels (:class:`Veneer`).
    """

    __repr__ = summary_repr  # arrays as shapes: a notebook shows one line

    params: ParquetryParams
    veneers: list[Veneer]
    bank: SheetBank
    panels: list[Parquetry]
    patches: list[Patch]
    placed: int
    planned: int
    message: str
    match_seconds: float
    cpu_seconds: float
    repaired: dict[int, str] = field(default_factory=dict)

    @property
    def complete(self) -> bool:
        return self.placed == self.planned


def saliency(grey: np.ndarray) -> np.ndarray:
    """Fine-grained centre-surround saliency ``(h, w)`` (after Montabone & Soto 2010, the
    paper's choice): the sum over scales of |I - Gaussian_sigma(I)|."""
    import cv2

    g = np.asarray(grey, np.float32)
    s = np.zeros_like(g)
    for sigma in (1.0, 2.0, 4.0, 8.0):
        s += np.abs(g - cv2.GaussianBlur(g, (0, 0), sigma))
    return s


def prepare_target(rgb: np.ndarray, params: ParquetryParams, source_values: np.ndarray,
                   index: int = 0, name: str = "target") -> Parquetry:
    """Crop/resample a target to whole cells, histogram-match it (eq. 2), compute eq. 1."""
    import cv2

    rgb = np.asarray(rgb, np.float32)
    if rgb.ndim == 2:
        rgb = np.repeat(rgb[..., None], 3, axis=2)
    cell = params.patch_px
    h, w = rgb.shape[:2]
    short_cells = params.short_cells
    scale = short_cells * cell / min(h, w)
    if h <= w:
        rows, cols = short_cells, max(1, int(w * scale + 1e-6) // cell)
    else:
        rows, cols = max(1, int(h * scale + 1e-6) // cell), short_cells
    nh, nw = round(h * scale), round(w * scale)
    nh, nw = max(nh, rows * cell), max(nw, cols * cell)
    img = cv2.resize(rgb, (nw, nh), interpolation=cv2.INTER_AREA if scale < 1 else cv2.INTER_CUBIC)
    y0, x0 = (nh - rows * cell) // 2, (nw - cols * cell) // 2
    img = np.clip(img[y0:y0 + rows * cell, x0:x0 + cols * cell], 0, 1).astype(np.float32)
    grey = intensity(img)
    matched = match_histogram(grey, source_values, params.w_hist)
    f = np.stack([params.w_intens * matched, params.w_edge * edge(grey)], axis=-1).astype(np.float32)
    native = (max(1, round(rows * cell / scale)), max(1, round(cols * cell / scale)))
    return Parquetry(index, name, img, matched, f, cell, np.full((rows, cols), -1, np.int64),
                     px_per_mm=params.px_per_mm, native_shape=native)


def _check_target(t, k: int) -> np.ndarray:
    """Target ``k`` as float RGB/grey in [0, 1]: uint8 is scaled by 1/255. A float image in
    0..255 or a NaN was clipped to white/garbage silently, a 1-D or empty array a bare
    ValueError/ZeroDivisionError in the resampling."""
    a = np.asarray(t)
    if a.dtype == np.uint8:
        a = a.astype(np.float32) / 255.0
    elif a.dtype == bool or not np.issubdtype(a.dtype, np.number):
        raise WoodcamError(f"target {k} must be an image of numbers (uint8, or float in [0, 1]); got dtype "
                           f"{a.dtype}; read it with woodcam.parquetry.veneers.read_image")
    if a.ndim not in (2, 3) or (a.ndim == 3 and a.shape[2] != 3) or min(a.shape[:2], default=0) < 1:
        raise WoodcamError(f"target {k} must be an (h, w, 3) RGB or (h, w) grey image; got shape {a.shape}")
    finite = np.isfinite(a)
    if not finite.all() or a.min() < 0 or a.max() > 1:
        lo, hi = (a[finite].min(), a[finite].max()) if finite.any() else (np.nan, np.nan)
        raise WoodcamError(f"target {k} must hold finite values in [0, 1]; got range [{lo:g}, {hi:g}] with "
                           f"{int(np.sum(~finite))} non-finite; divide a 0..255 image by 255 (or pass it as uint8)")
    return a


def _check_run(run, where: str) -> None:
    """``run`` must be what :func:`build_parquetry` returned (None was an AttributeError)."""
    if not isinstance(run, ParquetryRun):
        raise WoodcamError(f"{where}: run must be a ParquetryRun; got {type(run).__name__}; pass what "
                           "build_parquetry(...) returned")


class SheetTooSmallError(WoodcamError):
    """A veneer sheet smaller than one patch with its overlap and the kerf round it
    (:func:`build_parquetry`): ``veneer_id``, its ``size_mm`` (W, H) and the ``need_mm`` a side
    must reach, so a caller can name its own settings of the patch, overlap and kerf (the
    command line's options, not these parameters' names)."""

    def __init__(self, message: str, veneer_id: str, size_mm: tuple[float, float], need_mm: float):
        super().__init__(message)
        self.veneer_id, self.size_mm, self.need_mm = veneer_id, size_mm, need_mm


class _OutOfWood(Exception):
    pass


def build_parquetry(targets: np.ndarray | list[np.ndarray], veneers: list[Veneer],
                    params: ParquetryParams | None = None, *,
                    names: list[str] | None = None, progress: bool = False,
                    seams: bool = True, repair: bool = True) -> ParquetryRun:
    """Rebuild each target from the veneers (seed 002, sec. 3).

    Parameters
    ----------
    targets : list of (h, w, 3) float RGB in [0, 1] (or one array); (h, w) grey and uint8 0..255
        images are taken too (uint8 scaled by 1/255)
    veneers : list of :class:`Veneer` (any resolution; resampled to ``params.px_per_mm``)
    params : :class:`ParquetryParams` (Table 1 defaults)
    names : list of str, optional
        One name per target, for its messages and files (default ``target0``, ``target1``, ...)
    progress : progress bars over the sheets' rotations and the patches (stderr, a terminal only;
        off by default)
    seams : cut optimal seams in the overlaps (eq. 8-9); False keeps square patches, matched
        and placed with their overlap all the same (the matching of a seamed run, as the bench
        times it); ``overlap_mm=0`` matches and places them square, spending no wood round
        them, as ``woodcam parquetry --no-seams`` does
    repair : straighten the seams round pieces a router cannot cut (see
        :func:`repair_fabricability`); False leaves them to be reported

    Returns
    -------
    ParquetryRun ; when the wood runs out, ``complete`` is False, ``message`` says how many
    patches were placed, and the panels hold what was made (unplaced cells are -1).
    """
    if params is not None and not isinstance(params, ParquetryParams):  # a dict: AttributeError 'check'
        raise WoodcamError(f"params must be a ParquetryParams or None; got {type(params).__name__}; "
                           "pass ParquetryParams(**settings)")
    params = (params or ParquetryParams()).check()
    progress, seams, repair = (check_bool(v, f"build_parquetry: {n}") for n, v in
                               (("progress", progress), ("seams", seams), ("repair", repair)))
    if isinstance(targets, np.ndarray):
        targets = [targets]
    if not targets:
        raise WoodcamError("targets must hold at least one image; got none")
    if isinstance(targets, str):
        raise WoodcamError(f"targets must be images (arrays), not a path; got {targets!r:.60}; read it first "
                           "with woodcam.parquetry.veneers.read_image(path, 'target')")
    targets = [_check_target(t, k) for k, t in enumerate(targets)]
    if not veneers:
        raise WoodcamError("veneers must hold at least one sheet; got none (pass --veneer or --veneer-from)")
    for i, v in enumerate(veneers):  # an image array was an AttributeError ('id')
        if not isinstance(v, Veneer):
            raise WoodcamError(f"veneers[{i}] must be a Veneer; got {type(v).__name__}; make one with "
                               "load_scan(path, dpi=...) or slice_veneers(stock, ...)")
    if names is not None and (isinstance(names, str) or len(names) != len(targets)):  # an IndexError
        raise WoodcamError(f"names must be one name per target ({len(targets)}); got {names!r:.80}")
    ids = [check_veneer_id(v.id, f"veneers[{i}].id") for i, v in enumerate(veneers)]
    # unique up to case: 'A' and 'a' name one veneer_A.svg on a case-insensitive file system
    folded = [i.casefold() for i in ids]
    if len(set(folded)) != len(folded):
        twice = sorted({i for i in ids if folded.count(i.casefold()) > 1})
        raise WoodcamError(f"veneer ids must be unique, letter case aside (each names its cut files "
                           f"veneer_<id>.svg/.dxf); "
                           f"got {twice} more than once; give the sheets their own ids (a job file's "
                           "source_textures 'id'), and slice a block once, with more --sheets")
    sheets = [v.resampled(params.px_per_mm) for v in veneers]
    top_cells = 2 ** params.n_adaptive
    # a piece keeps the kerf clear of the sheet's edges (SheetBank.clears_edges): the search
    # uses whole pixels, edge_margin_px of them lost at each edge (a 13 px sheet passed for a
    # 10 px patch at a 1.2 px kerf and placed nothing)
    kerf_px = params.kerf * params.px_per_mm
    need_px = params.patch_px + 2 * params.overlap_px + 2 * edge_margin_px(kerf_px)
    for v in sheets:
        h, w = v.rgb.shape[:2]
        if min(h, w) < need_px:
            size = (w / params.px_per_mm, h / params.px_per_mm)
            raise SheetTooSmallError(
                f"veneer {v.id!r} is {say_length(size, '.1f', ' x ')}, smaller than one patch with its "
                f"overlap and the kerf round it ({say_length(need_px / params.px_per_mm, 'g')}); "
                "use larger sheets, a smaller patch_mm or overlap_mm, or a smaller kerf_mm",
                v.id, size, need_px / params.px_per_mm)
    grey = [intensity(v.rgb) for v in sheets]
    src_vals = np.concatenate([g[v.mask] for g, v in zip(grey, sheets)])
    if src_vals.size > 2_000_000:   # the CDF needs no more samples than this
        src_vals = src_vals[np.random.default_rng(0).choice(src_vals.size, 2_000_000, replace=False)]
    bank = SheetBank(grey, [v.mask for v in sheets], params.w_intens, params.w_edge, params.n_rot,
                     kerf_px=kerf_px, mode=params.mode,
                     coarse_factor=params.coarse_factor_for(sum(g.size for g in grey)),
                     top_k=params.top_k,
                     single_use=params.single_use, w_struct=params.w_struct,
                     rerank=params.rerank, flat_detail=params.flat_detail,
                     flat_rerank=params.flat_rerank, progress=progress)
    names = names or [f"target{k}" for k in range(len(targets))]
    panels = [prepare_target(t, params, src_vals, k, names[k]) for k, t in enumerate(targets)]

    # Priority queue (sec. 3.3, Fig. 6): top-level squares of 2**n_adaptive cells; where the
    # panel's last rows or columns leave a rectangle narrower than that, squares tile it
    # (_squares: one square of its short side left the rest of it uncovered)
    queue = []
    for p in panels:
        rows, cols = p.cells.shape
        sal = saliency(p.matched)
        cy, cx = rows * p.cell_px / 2.0, cols * p.cell_px / 2.0
        tops = [sq for r in range(0, rows, top_cells) for c in range(0, cols, top_cells)
                for sq in _squares(r, c, min(top_cells, rows - r), min(top_cells, cols - c))]
        for r, c, n in tops:
            y0, x0 = r * p.cell_px, c * p.cell_px
            y1, x1 = y0 + n * p.cell_px, x0 + n * p.cell_px
            if params.priority == "saliency":
                key = -float(sal[y0:y1, x0:x1].mean())
            else:
                key = float(np.hypot((y0 + y1) / 2 - cy, (x0 + x1) / 2 - cx))
            queue.append(((p.index, key) if params.queue == "sequential" else (key, p.index),
                          p.index, r, c, n))
    queue.sort(key=lambda q: q[0])
    planned_cells = sum(p.cells.size for p in panels)

    o = params.overlap_px
    patches: list[Patch] = []
    contexts = [bank.target_context(p.target_feats) for p in panels]
    # working pixels per target-image pixel, for the structural re-rank (SheetBank.best)
    struct_px = [max(1.0, p.matched.shape[0] / p.native_shape[0]) if p.native_shape else 1.0
                 for p in panels]

    def window(p: Parquetry, r: int, c: int, n: int):
        H, W = p.matched.shape
        y0, x0 = r * p.cell_px - o, c * p.cell_px - o
        y1, x1 = (r + n) * p.cell_px + o, (c + n) * p.cell_px + o
        return max(0, y0), max(0, x0), min(H, y1), min(W, x1)

    if params.single_use:
        _say_too_little_wood(panels, sheets, params,
                             [(y1 - y0, x1 - x0) for _, k, r, c, n in queue
                              for y0, x0, y1, x1 in [window(panels[k], r, c, n)]])
    def place(p: Parquetry, r: int, c: int, n: int) -> None:
        g = window(p, r, c, n)
        tmpl = np.ascontiguousarray(p.target_feats[g[0]:g[2], g[1]:g[3]])
        ctx = contexts[p.index]
        m = bank.best(tmpl, None if ctx is None else (ctx, g[0], g[1]), struct_px[p.index])
        if n > 1 and n % 2 == 0:
            h2 = n // 2
            kids = [(r + dr, c + dc) for dr in (0, h2) for dc in (0, h2)]
            tot = area = 0.0
            ok = True
            for kr, kc in kids:
                kg = window(p, kr, kc, h2)
                km = bank.best(np.ascontiguousarray(p.target_feats[kg[0]:kg[2], kg[1]:kg[3]]),
                               None if ctx is None else (ctx, kg[0], kg[1]), struct_px[p.index])
                if km is None:
                    ok = False
                    break
                a = (kg[2] - kg[0]) * (kg[3] - kg[1])
                tot += km.cost
                area += a
            parent_px = (g[2] - g[0]) * (g[3] - g[1])
            # Split when the four are better by more than w_adaptive (sec. 3.3, Fig. 11).
            if ok and (m is None or params.w_adaptive * tot / area < m.cost / parent_px):
                for kr, kc in kids:
                    place(p, kr, kc, h2)
                return
        if m is None:
            raise _OutOfWood
        th, tw = tmpl.shape[:2]
        bank.take(m, th, tw)
        pid = len(patches)
        patches.append(Patch(pid, p.index, r, c, n, g, m, m.cost / (th * tw)))
        p.patches.append(patches[-1])
        p.cells[r:r + n, c:c + n] = pid

    bar = None
    if progress:
        from .._progress import progress_bar

        bar = progress_bar(total=planned_cells, desc="matching patches", unit="cell")
    t0, c0 = time.perf_counter(), time.process_time()
    message = ""
    try:
        for _, t, r, c, n in queue:
            before = len(patches)
            place(panels[t], r, c, n)
            if bar is not None:
                bar.update(sum(q.cells ** 2 for q in patches[before:]))
    except _OutOfWood:
        placed = sum(int((p.cells >= 0).sum()) for p in panels)
        n = len(patches)  # 'placed 1 patches covering 1 of 16 cells' of a run that made one
        message = (f"the veneers ran out of free wood: placed {n} patch{'' if n == 1 else 'es'} covering "
                   f"{placed} of {planned_cells} cells; the rest of the "
                   f"{'panel is' if len(panels) == 1 else 'panels are'} left empty. "
                   "Add veneer sheets, make the panel smaller (image_size_mm, --image-size-mm) or use "
                   "larger patches")
    finally:
        if bar is not None:
            bar.close()
    match_s, cpu_s = time.perf_counter() - t0, time.process_time() - c0
    placed_cells = sum(int((p.cells >= 0).sum()) for p in panels)
    for p in panels:
        finish_panel(p, patches, bank, sheets, params, seams=seams)
    run = ParquetryRun(params, sheets, bank, panels, patches, placed_cells, planned_cells,
                       message, match_s, cpu_s)
    if repair:
        repair_fabricability(run)
    return run


def _say_too_little_wood(panels: list[Parquetry], sheets: list[Veneer], params: ParquetryParams,
                         windows: list[tuple[int, int]]) -> None:
    """A WoodcamWarning, before any matching, when the sheets' usable wood is less than the
    panels' top-level patches take: ``windows`` their ``(h, w)`` working pixels with the
    overlap, each the least wood its square takes (its four children's windows cover its own),
    every piece of wood used once. The run went on to 'ran out of free wood' with no word of
    why: a default 364 mm panel from a 51 mm scan placed 2 of 676 cells.

    The kerf counts (a job that passed without it ran out: two 10 mm pieces of four on a 14 x
    30 mm sheet at a 2 mm kerf): two pieces stay ``kerf`` apart and a piece that far from the
    sheet's edge and unusable wood (``SheetBank.clears_edges``), so each piece grown by half
    the kerf (``h w + k (h + w) + pi k^2 / 4``) is wood no other piece's takes, and it lies on
    the usable wood shrunk by half the kerf (pixels whose centres lie that far inside it). A
    lower bound still: the wood between rotated pieces and round the sheets' corners is not
    counted."""
    from scipy.ndimage import distance_transform_edt

    from ..errors import WoodcamWarning
    from ..units import say_area

    k = params.kerf * params.px_per_mm
    if k > 0:  # centre to the nearest off-wood pixel's centre: its side is half a pixel nearer
        wood_px = float(sum(int(np.count_nonzero(
            distance_transform_edt(np.pad(v.mask, 1, constant_values=False))[1:-1, 1:-1] >= k / 2 + 0.5))
            for v in sheets))
    else:
        wood_px = float(sum(int(np.count_nonzero(v.mask)) for v in sheets))
    hw = np.asarray(windows, float).reshape(-1, 2)
    need_px = float((hw[:, 0] * hw[:, 1] + k * hw.sum(1) + np.pi * k * k / 4).sum())
    if wood_px >= 0.98 * need_px:  # a rotated footprint's pixels may fall a little short of its area
        return
    import warnings

    px2 = params.px_per_mm ** 2
    sizes = ", ".join(f"{p.name} {say_length(p.size_mm, 'g', ' x ')}" for p in panels)
    kerf = f" and the {say_length(params.kerf, 'g')} kerf round it" if k > 0 else ""
    warnings.warn(
        f"the veneers cannot cover the panel{'s' if len(panels) > 1 else ''} ({sizes}): they hold "
        f"{say_area(wood_px / px2, '.0f')} of usable wood"
        f"{' half the kerf in from its edges' if k > 0 else ''}, and the "
        f"{sum(p.cells.size for p in panels)} patches of "
        f"{say_length(params.patch_mm, 'g')}, each piece with its {say_length(params.overlap, 'g')} overlap{kerf}, "
        f"every piece of wood used once, take at least {say_area(need_px / px2, '.0f')}, so at most "
        f"{100 * wood_px / need_px:.2g}% of it can be made; add at least "
        f"{say_area((need_px - wood_px) / px2, '.0f')} of veneer, or make the panel smaller (image_size_mm, "
        "--image-size-mm)",
        WoodcamWarning, stacklevel=3)


def _squares(r: int, c: int, h: int, w: int) -> list[tuple[int, int, int]]:
    """Squares ``(row, col, side)`` (cells) that tile the ``h x w`` rectangle of cells whose
    corner is cell ``(r, c)`` exactly once: squares of the short side along the long one, then
    the rest the same way."""
    out: list[tuple[int, int, int]] = []
    while h > 0 and w > 0:
        s = min(h, w)
        if h <= w:
            out += [(r, c + k * s, s) for k in range(w // s)]
            c, w = c + (w // s) * s, w % s
        else:
            out += [(r + k * s, c, s) for k in range(h // s)]
            r, h = r + (h // s) * s, h % s
    return out


def finish_panel(p: Parquetry, patches: list[Patch], bank: SheetBank, sheets: list[Veneer],
                 params: ParquetryParams, seams: bool = True) -> None:
    """Seams (eq. 8-9) when the panel is complete, then labels, render and baseline."""
    from .seams import cut_seams, straight_labels

    H, W = p.matched.shape
    windows = {q.id: (q.grown, bank.patch_pixels(q.match, q.grown[2] - q.grown[0], q.grown[3] - q.grown[1]))
               for q in p.patches}
    if seams and p.complete and params.overlap_px > 0:
        p.labels, p.seams_v, p.seams_h = cut_seams(p, windows, params)
    else:
        p.labels = straight_labels(p)
    _render_panel(p, bank, sheets)


def _render_panel(p: Parquetry, bank: SheetBank, sheets: list[Veneer]) -> None:
    """``p.render`` (each pixel the wood of its label's patch) and ``p.baseline`` (each piece
    its mean colour, the paper's Fig. 8 baseline) from ``p.labels``."""
    H, W = p.matched.shape
    render = np.zeros((H, W, 3), np.float32)
    for q in p.patches:
        (y0, x0, y1, x1) = q.grown
        col = bank.warp_window(sheets[q.match.sheet].rgb, q.match, y1 - y0, x1 - x0)
        sel = p.labels[y0:y1, x0:x1] == q.id
        render[y0:y1, x0:x1][sel] = col[sel]
    p.render = render
    base = np.zeros_like(render)
    lab = p.labels.ravel()
    ok = lab >= 0
    if ok.any():
        n = int(lab.max()) + 1
        cnt = np.bincount(lab[ok], minlength=n)
        flat = render.reshape(-1, 3)
        means = np.stack([np.bincount(lab[ok], weights=flat[ok, k], minlength=n) for k in range(3)], 1)
        means /= np.maximum(cnt, 1)[:, None]
        base.reshape(-1, 3)[ok] = means[lab[ok]]
    p.baseline = base


def repair_fabricability(run: ParquetryRun, max_rounds: int = 4) -> dict[int, str]:
    """Repair the pieces that fail the router checks (:func:`~.cutpaths.check_piece`).

    A seam bounding a failing piece (a bend tighter than the tool radius, a part narrower than
    ``min_piece_mm``) is replaced by the straight grid line it was cut in; a piece bounded by
    straight lines is its patch's square (at least ``patch_mm >= min_piece_mm`` wide, convex
    right-angle corners), so the repair always ends. The straight line lies in every grown
    window it crosses, so the wood under it was matched and is consumed already (single use
    is unchanged); labels, render and baseline are redone. Returns ``{piece id: what was
    done}`` (also merged into ``run.repaired``); the files written afterwards are checked again
    by :func:`write_parquetry`. ``max_rounds`` (default 4): check-and-straighten rounds per
    panel; a panel's pieces are checked again after each round (its neighbours' outlines
    change too) until none fails or the rounds are spent.
    """
    from .cutpaths import check_piece, panel_outlines
    from .seams import labels_from_lines, straight_line

    _check_run(run, "repair_fabricability")
    prm = run.params
    done: dict[int, str] = {}
    for p in run.panels:
        if p.seams_v is None or p.seams_h is None:
            continue            # square pieces: fabricable by construction
        H, W = p.matched.shape
        for _ in range(max_rounds):
            outlines = panel_outlines(p, prm.px_per_mm)
            bad = {q.id: check_piece(outlines[q.id], prm.min_piece_mm, prm.tool_diameter_mm / 2)
                   for q in p.patches}
            bad = {k: v for k, v in bad.items() if v}
            if not bad:
                break
            rows, cols = p.cells.shape
            for q in (q for q in p.patches if q.id in bad):
                for k in (q.col, q.col + q.cells):
                    if 0 < k < cols:
                        p.seams_v[k - 1] = straight_line(k * p.cell_px, "v", k, H)
                for m in (q.row, q.row + q.cells):
                    if 0 < m < rows:
                        p.seams_h[m - 1] = straight_line(m * p.cell_px, "h", m, W)
                done[q.id] = "seams straightened (" + "; ".join(bad[q.id]) + ")"
        p.labels = labels_from_lines(p, p.seams_v, p.seams_h)
        _render_panel(p, run.bank, run.veneers)
    run.repaired.update(done)
    return done


#: Where the metrics below compare: at the working resolution (``px_per_mm``) or on the
#: target image's own pixel grid (``Parquetry.native_shape``).
MetricGrid = Literal["working", "native"]


def _native(p: Parquetry, grid: MetricGrid) -> tuple[int, int] | None:
    """The ``(h, w)`` to area-average to for ``grid``, or None to stay at the working
    resolution (also when the target is as fine as the working grid or finer)."""
    if grid not in ("working", "native"):
        raise WoodcamError(f"grid must be one of ['working', 'native']; got {grid!r}")
    H, W = p.matched.shape
    if grid == "working" or p.native_shape is None or p.native_shape[0] >= H:
        return None
    return p.native_shape


def _area(a: np.ndarray, shape: tuple[int, int] | None) -> np.ndarray:
    import cv2

    if shape is None:
        return np.asarray(a, np.float32)
    return cv2.resize(np.asarray(a, np.float32), (shape[1], shape[0]), interpolation=cv2.INTER_AREA)


def feature_cost(p: Parquetry, image: np.ndarray, params: ParquetryParams,
                 grid: MetricGrid = "working") -> float:
    """Eq. 8 per pixel: mean over the panel of ``|F(R) - F(I_T)|^2`` with ``F`` of eq. 1 (the
    target's intensity histogram-matched, eq. 2). ``image (H, W, 3)`` is a render or baseline
    of the panel ``p`` (:class:`Parquetry`, panel pixels at ``params.px_per_mm``); ``params``
    gives eq. 1's weights ``w_intens`` and ``w_edge``.

    grid : "working" compares at ``px_per_mm`` with the target's features of the matching;
        "native" area-averages image and target to the target image's own pixels first (the
        target says nothing finer than those; wood detail below them is neither asked for
        nor forbidden) and takes eq. 1 there.
    """
    shape = _native(p, grid)
    g = _area(intensity(image), shape)
    f = features(g, params.w_intens, params.w_edge)
    t = p.metric_target("features", shape, params.w_intens, params.w_edge)
    return float(((f - t) ** 2).sum(axis=2).mean())


def ssim_vs_matched(p: Parquetry, image: np.ndarray, downsample: int = 1,
                    grid: MetricGrid = "working") -> float | None:
    """SSIM (scikit-image: 7 x 7 windows, grey, data range 1) between an image's intensity and
    the matched target (eq. 2), both ``(H, W)`` at the working resolution, or first
    area-averaged by ``downsample`` (``round(px_per_mm)`` gives 1 mm pixels, 7 mm windows:
    structure at half a patch rather than the wood's sub-millimetre grain), or with
    ``grid="native"`` to the target image's own pixels (``downsample`` then unused). None
    where that grid, or the working one, is narrower than the 7 x 7 window (a 4 x 4 px
    target's own pixels): SSIM has no value there. ``p``: the panel (:class:`Parquetry`) whose
    matched target ``image`` (a render or baseline, ``(H, W, 3)`` panel pixels) is compared to."""
    from skimage.metrics import structural_similarity

    a, b = intensity(image), p.matched
    shape = _native(p, grid)
    if shape is None and downsample > 1:
        h, w = b.shape
        shape = (max(7, h // downsample), max(7, w // downsample))
    if min(b.shape) < 7 or (shape is not None and min(shape) < 7):
        return None  # skimage raised ValueError: an internal error at the end of a whole run
    a, b = _area(a, shape), p.metric_target("matched", shape)
    return float(structural_similarity(a, b, data_range=1.0))
