"""Template matching of target patches on rotated veneer sheets, with single use (seed 002,
sec. 3.2-3.3, eq. 3-4).

The :class:`SheetBank` holds every sheet's feature map (eq. 1) at the working resolution in
the sheet's own, unrotated pixel frame (x = column, y = row, pixel centres at integers), the
sheet's usable-wood mask, and its *taken* mask: wood consumed by placed patches, grown by the
kerf. A patch is a rectangle of ``(th, tw)`` pixels in the frame of sheet ``i`` rotated by
``angle_j`` (the rotated canvas of :func:`~woodcam.parquetry.features.rotate`), anchored at its
top-left pixel ``(x, y)``; its *footprint* is that rectangle mapped back to the sheet frame, a
rotated rectangle. A candidate may be used only when every sheet pixel whose centre lies in
its footprint is usable and untaken; single use is checked there, in the sheet frame, so it
is exact whatever frame the search ran in. The footprint grown by the kerf must also lie on
the sheet and off unusable wood (checked on the polygon itself, not its pixel centres): the
router cuts round a piece, so a piece on the sheet's edge or on the mask's edge would be cut
off the sheet or into unusable wood. The search sees usable wood shrunk by the kerf.

Search (eq. 4, SSD over all sheets, rotations and positions) runs on an *atlas*: all rotated
sheets of one pyramid level packed into one image, separated by blocked pixels, so one
``cv2.matchTemplate`` call scores every sheet, rotation and position, and an integral image of
the blocked pixels rules out anchors whose window touches used or unusable wood.

- ``"exhaustive"``: the atlas at full resolution; the best valid anchor is exact.
- ``"fast"``: the atlas at 1/f resolution finds the ``k`` best coarse anchors; each is
  re-ranked by exact SSD at full resolution over +-f pixels around it (coarse-to-fine with
  exact re-ranking). The rotated full-resolution features are warped only for those windows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..errors import WoodcamError
from .features import features, rotate, rotation_matrix

MatchMode = Literal["exhaustive", "fast"]


@dataclass
class Match:
    """Where a target patch was found.

    sheet : index into the bank's sheets
    rot : rotation index (angle ``bank.angles_deg[rot]``)
    x, y : anchor (top-left pixel) in the rotated canvas, full resolution
    cost : SSD of eq. 4 over the template (sum over pixels and both feature channels)
    """

    sheet: int
    rot: int
    x: int
    y: int
    cost: float


class _Atlas:
    """All rotated sheets of one pyramid level in one image (see module docstring)."""

    def __init__(self, bank: SheetBank, f: int, progress: bool = False):
        import itertools

        import cv2

        from .._progress import progress_bar

        self.f = f
        tiles = []                      # (sheet, rot, feats, usable, affine)
        # seconds to minutes before the first patch is matched (every sheet rotated n_rot times)
        every = progress_bar(list(itertools.product(range(len(bank.grey)), range(len(bank.angles_deg)))),
                             desc="rotating sheets", unit="rotation", enabled=progress)
        for i, j in every:
            # eq. 3: the features of the rotated sheet (not the rotated features)
            Gr, Ur, m = rotate(bank.grey[i], bank.usable[i], bank.angles_deg[j])
            Fr = bank.features(Gr)
            if f > 1:
                Fr = _coarse(Fr, f)
                hc, wc = Fr.shape[:2]
                Ur = cv2.resize(Ur[:hc * f, :wc * f].astype(np.float32), (wc, hc),
                                interpolation=cv2.INTER_AREA) > 1 - 1e-4
            tiles.append((i, j, Fr, Ur, m))
        # Shelf packing, rows about as wide as the square root of the total area.
        pad = 1
        width = int(max(max(t[2].shape[1] for t in tiles) + pad,
                        np.sqrt(sum(t[2].shape[0] * t[2].shape[1] for t in tiles)) * 1.3))
        x = y = row_h = 0
        places = []
        for t in tiles:
            h, w = t[2].shape[:2]
            if x + w + pad > width:
                x, y, row_h = 0, y + row_h + pad, 0
            places.append((y + pad, x + pad))
            x += w + pad
            row_h = max(row_h, h)
        H, W = y + row_h + 2 * pad, width + pad
        self.F = np.zeros((H, W, tiles[0][2].shape[2]), np.float32)
        self.blocked = np.ones((H, W), np.uint8)
        self.tile_id = np.full((H, W), -1, np.int32)
        self.tiles = []                 # (sheet, rot, y0, x0, h, w, affine sheet->tile)
        for k, ((i, j, Fr, Ur, m), (y0, x0)) in enumerate(zip(tiles, places)):
            h, w = Fr.shape[:2]
            self.F[y0:y0 + h, x0:x0 + w] = Fr
            self.blocked[y0:y0 + h, x0:x0 + w] = ~Ur
            self.tile_id[y0:y0 + h, x0:x0 + w] = k
            self.tiles.append((i, j, y0, x0, h, w, m))
        self._origins = np.array([t[2:4] for t in self.tiles], np.int64).reshape(-1, 2)
        # One contiguous plane per channel (what matchTemplate wants), the stacked copy freed.
        self._chan = [np.ascontiguousarray(self.F[..., c]) for c in range(self.F.shape[2])]
        self._f2 = (self.F * self.F).sum(axis=2)
        self.shape = self.F.shape
        del self.F
        self._base_cache: dict[tuple[int, int], np.ndarray] = {}
        self._dsum_cache: dict[tuple[int, int], np.ndarray] = {}
        # Cached anchor maps (float32, one per template size: interior, edge and corner
        # patches, and their trimmed coarse templates) held to ~200 MB, 2 to 8 copies.
        self._max_cached = int(np.clip(200_000_000 // (4 * H * W), 2, 8))
        self._by_sheet: dict[int, list[int]] = {}
        for k, t in enumerate(self.tiles):
            self._by_sheet.setdefault(t[0], []).append(k)

    @property
    def nbytes(self) -> int:
        return (sum(c.nbytes for c in self._chan) + self._f2.nbytes + self.blocked.nbytes + self.tile_id.nbytes
                + sum(b.nbytes for b in self._base_cache.values())
                + sum(b.nbytes for b in self._dsum_cache.values()))

    def search(self, template: np.ndarray, k: int,
               trim: tuple[int, int, int, int] = (0, 0, 0, 0),
               exclude: tuple[np.ndarray, np.ndarray] | None = None,
               detail_weight: float = 1.0) -> list[tuple[int, int, int, float]]:
        """The ``k`` best valid anchors: ``[(tile, x_in_tile, y_in_tile, cost), ...]`` sorted.
        ``template (th, tw, c)`` has the atlas' channels (at a coarse level: :func:`_coarse`).

        trim : ``(top, left, bottom, right)`` pixels cut off a window of ``(th + top + bottom,
            tw + left + right)``: the cost is the trimmed template's, the anchors and the
            free-wood test are the whole window's.
        exclude : ``(rows, cols)`` atlas anchors (of the whole window) left out, e.g. those
            known to hold no free window (see :meth:`SheetBank.best`).
        detail_weight : weight of the coarse level's detail-amplitude channel (the last one,
            see :func:`_downsample`) in the SSD; above 1 a textured window costs more against
            a calm template (see :meth:`SheetBank.best`)."""
        import cv2

        th, tw = template.shape[:2]
        ty, tx, by, bx = trim
        thf, twf = th + ty + by, tw + tx + bx
        if thf > self.shape[0] or twf > self.shape[1]:
            return []
        base = self._base(th, tw)
        cc = None
        oh, ow = self.shape[0] - th + 1, self.shape[1] - tw + 1
        wd = float(detail_weight) if self.f > 1 else 1.0
        for ch in range(self.shape[2]):
            t = np.ascontiguousarray(template[..., ch], np.float32)
            if ch == self.shape[2] - 1 and wd != 1.0:
                t = t * np.float32(wd)
            if max(th, tw) <= _DIRECT_MAX:
                # filter2D correlates directly (anchored top-left it is TM_CCORR on the valid
                # part); for the coarse search's few-pixel templates that is ~2.7 times quicker
                # than matchTemplate's DFT path.
                r = cv2.filter2D(self._chan[ch], cv2.CV_32F, t, anchor=(0, 0),
                                 borderType=cv2.BORDER_CONSTANT)[:oh, :ow]
            else:
                r = cv2.matchTemplate(self._chan[ch], t, cv2.TM_CCORR)
            # the first output is a fresh array (a view of one), so it is summed into in place
            cc = r if cc is None else cv2.add(cc, r, dst=cc)
        # SSD = sum S^2 - 2 sum S T + sum T^2 (eq. 4); base carries sum S^2 and +inf where the
        # window touches used or unusable wood, so no mask has to be applied per search.
        cost = cv2.scaleAdd(cc, -2.0, base)
        if wd != 1.0:
            # sum_c w_c (S_c - T_c)^2: base holds the detail channel's S^2 once
            cost = cv2.scaleAdd(self._detail_sums(th, tw), wd - 1.0, cost)
        if thf != th or twf != tw:
            # whole-window anchor a scores the trimmed template at a + (ty, tx); it is valid
            # only where the whole window is free
            ohf, owf = self.shape[0] - thf + 1, self.shape[1] - twf + 1
            cost = cost[ty:ty + ohf, tx:tx + owf].copy()
            cost[np.isinf(self._base(thf, twf))] = np.inf
        if exclude is not None and exclude[0].size:
            cost[exclude] = np.inf
        flat = cost.ravel()
        sel = _smallest(flat, k)
        if sel.size == 0:
            return []
        t2 = (template.astype(np.float64) ** 2).sum(axis=(0, 1))
        if wd != 1.0:
            t2[-1] *= wd
        tsum = float(t2.sum())
        sel = sel[np.argsort(flat[sel], kind="stable")]
        ya, xa = np.divmod(sel, cost.shape[1])
        t = self.tile_id[ya, xa]
        org = self._origins[t]
        return list(zip(t.tolist(), (xa - org[:, 1]).tolist(), (ya - org[:, 0]).tolist(),
                        np.maximum(flat[sel].astype(np.float64) + tsum, 0.0).tolist()))

    def _detail_sums(self, th: int, tw: int) -> np.ndarray:
        """Windowed sum of the detail channel's square per anchor for a ``(th, tw)``
        template (no blocking: :meth:`_base` carries that); cached per size."""
        key = (th, tw)
        if key not in self._dsum_cache:
            while len(self._dsum_cache) >= self._max_cached:
                self._dsum_cache.pop(next(iter(self._dsum_cache)))
            d = self._chan[-1]
            self._dsum_cache[key] = _window_sums(d * d, th, tw)
        return self._dsum_cache[key]

    def _base(self, th: int, tw: int) -> np.ndarray:
        """Windowed sum of S^2 per anchor for a ``(th, tw)`` template, +inf where the window
        touches a blocked pixel; cached per template size (few occur: interior patches and the
        clipped ones along the panel's edges) and kept current by :meth:`block_polygon`."""
        import cv2

        key = (th, tw)
        if key in self._base_cache:
            self._base_cache[key] = self._base_cache.pop(key)      # most recently used last
            return self._base_cache[key]
        while len(self._base_cache) >= self._max_cached:
            self._base_cache.pop(next(iter(self._base_cache)))
        base = _window_sums(self._f2, th, tw)
        ii = cv2.integral(self.blocked, sdepth=cv2.CV_32S)
        win = ii[th:, tw:] - ii[:-th, tw:] - ii[th:, :-tw] + ii[:-th, :-tw]
        base[win > 0] = np.inf
        self._base_cache[key] = base
        return base

    def block_polygon(self, sheet: int, poly_sheet_px: np.ndarray) -> None:
        """Mark the pixels of every tile of ``sheet`` whose centres lie in the polygon."""
        for k in self._by_sheet.get(sheet, []):
            _, _, y0, x0, h, w, m = self.tiles[k]
            # Rotated full-resolution frame, then coarse: full pixel x sits in coarse pixel
            # (x - (f - 1) / 2) / f.
            q = poly_sheet_px @ m[:, :2].T + m[:, 2]
            q = (q - (self.f - 1) / 2.0) / self.f
            rr, cc = _polygon_pixels(q, (h, w))
            if rr.size == 0:
                continue
            self.blocked[y0 + rr, x0 + cc] = 1
            self._update_bases(y0 + int(rr.min()), y0 + int(rr.max()), x0 + int(cc.min()), x0 + int(cc.max()))

    def _update_bases(self, r0: int, r1: int, c0: int, c1: int) -> None:
        """Rule out the cached anchors whose window reaches the newly blocked box
        ``[r0, r1] x [c0, c1]`` (atlas pixels): only that neighbourhood is recomputed."""
        import cv2

        for (th, tw), base in self._base_cache.items():
            ay0, ax0 = max(0, r0 - th + 1), max(0, c0 - tw + 1)
            ay1, ax1 = min(base.shape[0] - 1, r1), min(base.shape[1] - 1, c1)
            if ay1 < ay0 or ax1 < ax0:
                continue
            blk = self.blocked[ay0:ay1 + th, ax0:ax1 + tw]
            ii = cv2.integral(blk, sdepth=cv2.CV_32S)
            win = ii[th:, tw:] - ii[:-th, tw:] - ii[th:, :-tw] + ii[:-th, :-tw]
            sub = base[ay0:ay1 + 1, ax0:ax1 + 1]
            sub[win > 0] = np.inf


#: Largest template side (px) correlated directly by filter2D rather than matchTemplate
#: (measured on a 1261 x 1598 atlas: 5 px 5.5 vs 14.9 ms, 10 px on par, 21 px 2 times slower).
_DIRECT_MAX = 7


def _lowpass(F: np.ndarray, f: int) -> np.ndarray:
    """Gaussian low-pass (sigma f / 2) before downsampling by f: the coarse search compares
    what survives a misalignment of up to half a coarse pixel, so a texture's fine, periodic
    detail (latewood lines) does not make the true place look bad at the wrong phase."""
    import cv2

    return cv2.GaussianBlur(F, (0, 0), f / 2.0, borderType=cv2.BORDER_REPLICATE)


def _smallest(flat: np.ndarray, k: int) -> np.ndarray:
    """Indices of the ``k`` smallest finite values of ``flat`` (unordered; fewer when fewer are
    finite). Exact: a threshold from a strided sample (every 64th value) selects a superset of
    about 4 k values, and only those are partitioned; argpartition of the whole coarse map
    (a million values and more) was a fifth of the time per patch."""
    k = min(k, flat.size)
    step = 64
    if flat.size > 64 * step * k // 16:
        sample = flat[::step]
        q = min(sample.size - 1, max(1, 4 * k // step))
        thr = np.partition(sample, q)[q]
        if np.isfinite(thr):
            cand = np.flatnonzero(flat <= thr)
            if cand.size >= k:
                sub = flat[cand]
                return cand[np.argpartition(sub, k - 1)[:k]] if cand.size > k else cand
    sel = np.argpartition(flat, k - 1)[:k] if k < flat.size else np.arange(flat.size)
    return sel[np.isfinite(flat[sel])]


def _distinct(cands: list[tuple[int, int, int, float]]) -> list[tuple[int, int, int, float]]:
    """Coarse candidates ``[(tile, x, y, cost)]`` (sorted) less those next to a better one in
    the same tile (Chebyshev distance 1): the exact re-ranking round a coarse anchor already
    covers half a coarse pixel and more either side, so a neighbour adds nothing, and in
    periodic grain a few minima's neighbours would otherwise fill the whole batch."""
    kept: list[tuple[int, int, int, float]] = []
    seen: set[tuple[int, int, int]] = set()
    for c in cands:
        t, x, y, _ = c
        if (t, x, y) in seen:
            continue
        kept.append(c)
        seen.update((t, x + dx, y + dy) for dx in (-1, 0, 1) for dy in (-1, 0, 1))
    return kept


def _coarse(F: np.ndarray, f: int) -> np.ndarray:
    """Features ``F (h, w, c)`` low-passed and downsampled by ``f`` (see :func:`_lowpass`),
    with one more channel, the *detail amplitude* per coarse pixel: ``(h // f, w // f, c + 1)``.
    See :func:`_lowpass_energy` and :func:`_downsample`."""
    return _downsample(_lowpass_energy(F, f), f)


def _lowpass_energy(F: np.ndarray, f: int) -> np.ndarray:
    """``[G(F), G(|F|^2)]`` as ``(h, w, c + 1)`` float32: the Gaussian low-pass of
    :func:`_lowpass` of the features and of their energy, at full resolution (one blur)."""
    import cv2

    F = F if F.ndim == 3 else F[..., None]
    chans = [np.ascontiguousarray(F[..., k], np.float32) for k in range(F.shape[2])]
    energy = chans[0] * chans[0]
    for ch in chans[1:]:
        energy += ch * ch
    out = _lowpass(cv2.merge([*chans, energy]), f)
    return out.reshape(*F.shape[:2], F.shape[2] + 1)


def _downsample(L: np.ndarray, f: int) -> np.ndarray:
    """Coarse features from :func:`_lowpass_energy`'s ``L (h, w, c + 1)``: the low-passed
    channels and the detail amplitude ``sqrt(G(|F|^2) - |G(F)|^2)`` (the RMS of what the
    low-pass removes), area-averaged over whole ``f x f`` blocks: ``(h // f, w // f, c + 1)``.

    SSD splits into the coarse images' SSD and the detail's, and by Cauchy-Schwarz the
    detail's is at least ``f^2 (a_S - a_T)^2`` per coarse pixel, with equality where wood and
    target carry the same detail in phase (a crop of the wood itself). Leaving it out ranks a
    finely grained piece of wood as good as a calm one of the same mean tone, so a flat target
    region got grain wherever calm wood was not among the few candidates re-ranked exactly.
    The local variance under the Gaussian is as phase-robust as the coarse features (a box
    over each coarse pixel would depend on where the grid falls).
    """
    import cv2

    h, w, c1 = L.shape
    hc, wc = max(1, h // f), max(1, w // f)
    # Cropped to whole coarse pixels first, so coarse pixel X covers exactly full pixels
    # f X .. f X + f - 1 (a plain resize to w // f stretches the grid by up to f pixels over
    # the width, a phase error that grows across the sheet).
    both = cv2.resize(np.ascontiguousarray(L[:hc * f, :wc * f]), (wc, hc),
                      interpolation=cv2.INTER_AREA).reshape(hc, wc, c1)
    lo = both[..., :c1 - 1]
    var = both[..., c1 - 1] - (lo * lo).sum(axis=2)
    both[..., c1 - 1] = np.sqrt(np.maximum(var, 0.0))
    return both


def _ssd(image: np.ndarray, template: np.ndarray, sq_sums: np.ndarray | None = None) -> np.ndarray:
    """SSD of eq. 4 for every anchor: ``sum S^2 - 2 sum S T + sum T^2`` over both channels.

    OpenCV's multi-channel ``matchTemplate`` is several times slower than its single-channel
    cross-correlation, so the channels are correlated one by one; ``sq_sums`` (the windowed
    sum of S^2, which does not depend on the template's values) may be passed in from a cache.
    """
    import cv2

    th, tw = template.shape[:2]
    cc = None
    for ch in range(image.shape[2]):
        r = cv2.matchTemplate(np.ascontiguousarray(image[..., ch]),
                              np.ascontiguousarray(template[..., ch]), cv2.TM_CCORR)
        cc = r if cc is None else cc + r
    if sq_sums is None:
        sq_sums = _window_sums((image * image).sum(axis=2), th, tw)
    out = sq_sums - 2.0 * cc + float((template.astype(np.float64) ** 2).sum())
    return np.maximum(out, 0.0, out=out)


def _window_sums(a: np.ndarray, th: int, tw: int) -> np.ndarray:
    """Sum of ``a`` over every ``(th, tw)`` window (anchor = top-left), via an integral image."""
    import cv2

    ii = cv2.integral(np.asarray(a, np.float64), sdepth=cv2.CV_64F)
    return (ii[th:, tw:] - ii[:-th, tw:] - ii[th:, :-tw] + ii[:-th, :-tw]).astype(np.float32)


def _polygon_pixels(poly_xy: np.ndarray, shape) -> tuple[np.ndarray, np.ndarray]:
    """Rows and columns of the pixels whose centres lie inside ``poly_xy (n, 2)`` (x, y)."""
    from skimage.draw import polygon

    return polygon(poly_xy[:, 1], poly_xy[:, 0], shape)


class _Anchors:
    """A growing set of atlas anchors ``(row, col)`` with its ``(rows, cols)`` index arrays,
    extended rather than rebuilt (thousands may pile up late in a run)."""

    def __init__(self) -> None:
        self._new: list[tuple[int, int]] = []
        self._arr = (np.zeros(0, np.intp), np.zeros(0, np.intp))

    def append(self, rc: tuple[int, int]) -> None:
        self._new.append(rc)

    def __len__(self) -> int:
        return self._arr[0].size + len(self._new)

    def arrays(self) -> tuple[np.ndarray, np.ndarray]:
        if self._new:
            add = np.array(self._new, np.intp).reshape(-1, 2)
            self._arr = (np.concatenate([self._arr[0], add[:, 0]]), np.concatenate([self._arr[1], add[:, 1]]))
            self._new = []
        return self._arr


class SheetBank:
    """Veneer features, rotations and the consumed-wood state (see module docstring).

    Parameters
    ----------
    grey : list of (h, w) float32 sheet intensities, working resolution
    usable : list of (h, w) bool
    w_intens, w_edge : feature weights of eq. 1
    n_rot : number of rotations, angles ``360 k / n_rot`` degrees (eq. 3)
    kerf_px : wood lost round every footprint (pixels): two footprints stay this far apart
    mode : "exhaustive" or "fast"
    coarse_factor : pyramid factor f of the fast mode
    top_k : coarse candidates re-ranked exactly in the fast mode
    single_use : False gives the unconstrained matcher (wood may be reused; an upper bound)
    w_struct, rerank : structural re-ranking of the ``rerank`` cheapest free candidates (see
        :meth:`_choose`); 0 picks by eq. 4 alone
    flat_detail, flat_rerank : where the template's target is flat (:func:`_flat_fraction`),
        the coarse detail channel's weight and the number re-ranked rise towards these
        (1.0 and ``rerank``: off; see :meth:`best`)
    progress : a bar over the rotated sheets while they are prepared (woodcam._progress)
    """

    def __init__(self, grey, usable, w_intens: float = 0.5, w_edge: float = 0.5,
                 n_rot: int = 15, kerf_px: float = 0.0,
                 mode: MatchMode = "fast", coarse_factor: int = 4, top_k: int = 12,
                 single_use: bool = True, max_atlas_bytes: int = 2_500_000_000,
                 w_struct: float = 0.0, rerank: int = 4, flat_detail: float = 1.0,
                 flat_rerank: int | None = None, progress: bool = False):
        if mode not in ("exhaustive", "fast"):
            raise WoodcamError(f"mode must be one of ['exhaustive', 'fast']; got {mode!r}")
        if n_rot < 1:
            raise WoodcamError(f"n_rot must be >= 1; got {n_rot}")
        self.grey = [np.ascontiguousarray(g, np.float32) for g in grey]
        self.w_intens, self.w_edge = float(w_intens), float(w_edge)
        self.kerf_px = float(kerf_px)
        # the wood as given (is_free's exact test), and what the search may use: pixels whose
        # centres keep the kerf clear of unusable wood and the sheet's edge
        self._off_wood = [~np.asarray(u, bool) for u in usable]
        self.usable = [_clear_of(~off, self.kerf_px) for off in self._off_wood]
        self.taken = [~u for u in self.usable]
        self._unusable = [~u for u in self.usable]
        self.angles_deg = [360.0 * k / n_rot for k in range(n_rot)]
        self.mode = mode
        self.f = 1 if mode == "exhaustive" else max(1, int(coarse_factor))
        # Exact re-ranking radius round a coarse anchor X (full px f X): the area-averaged
        # coarse pixel hides a phase of up to half a coarse pixel, plus one for rounding.
        self.radius = self.f // 2 + 1
        self.top_k = top_k
        self.single_use = single_use
        self.w_struct, self.rerank = float(w_struct), max(1, int(rerank))
        self.flat_detail = float(flat_detail)
        self.flat_rerank = max(self.rerank, int(flat_rerank or 0))
        est = sum(g.shape[0] * g.shape[1] for g in self.grey) * n_rot * 2.0 * 13 / self.f ** 2
        if est > max_atlas_bytes:
            raise WoodcamError(
                f"the {mode} search would hold ~{est / 1e9:.1f} GB of rotated sheets (limit "
                f"{max_atlas_bytes / 1e9:.1f} GB); use mode 'fast', fewer rotations, or a lower "
                "working resolution (px_per_mm)")
        self.atlas = _Atlas(self, self.f, progress)
        # Coarse anchors known to hold no free window, per full template size (see best());
        # how many were found, how many coarse anchors were re-ranked exactly, and how often
        # the exact scan of every rotation ran (the slow path: tests count it).
        self._dead: dict[tuple[int, int], _Anchors] = {}
        self.dead_anchors = 0
        self.fallback_scans = 0
        self.exact_reranks = 0
        self._rot = [[rotation_matrix(g.shape[:2], a) for a in self.angles_deg] for g in self.grey]

    def rotation(self, sheet: int, rot: int) -> tuple[np.ndarray, tuple[int, int]]:
        """``(affine (2, 3) sheet px -> rotated canvas px, canvas (h, w))`` of a rotation."""
        return self._rot[sheet][rot]

    def features(self, grey: np.ndarray) -> np.ndarray:
        """Eq. 1 on a (rotated) sheet intensity: ``(h, w, 2)``."""
        return features(grey, self.w_intens, self.w_edge)

    # -- geometry ---------------------------------------------------------------------------
    def footprint(self, sheet: int, rot: int, x: float, y: float, th: int, tw: int) -> np.ndarray:
        """The patch rectangle anchored at (x, y) of rotation ``rot`` in the sheet frame:
        ``(4, 2)`` float (x, y) pixel coordinates, corners in order."""
        m, _ = self._rot[sheet][rot]
        corners = np.array([[x - 0.5, y - 0.5], [x + tw - 0.5, y - 0.5],
                            [x + tw - 0.5, y + th - 0.5], [x - 0.5, y + th - 0.5]])
        a, t = m[:, :2], m[:, 2]
        return (corners - t) @ np.linalg.inv(a).T

    def is_free(self, sheet: int, poly: np.ndarray) -> bool:
        """True when every sheet pixel centred in ``poly`` is usable and not taken, and
        ``poly`` grown by the kerf lies on the sheet and off unusable wood (:meth:`clears_edges`).
        The cheap pixel test runs first: the exact one (shapely, ~2 ms where a rotated
        footprint's box holds hundreds of unusable pixels) only for a footprint that passed it."""
        lo, hi = poly.min(0), poly.max(0)
        taken = self.taken[sheet]
        # Quick accept (the same answer, without rasterising): every pixel centred in the
        # polygon lies in its bounding box, so a free box means a free footprint, and a
        # rectangle whose sides are both >= sqrt(2) px holds a disc of radius >= sqrt(2)/2,
        # hence at least one pixel centre. Early in a run, and for the structural re-rank's
        # many candidates, the box is nearly always free.
        side = np.hypot(*(poly[1] - poly[0])), np.hypot(*(poly[3] - poly[0]))
        if min(side) >= 1.5:
            box = taken[max(0, int(np.ceil(lo[1]))):int(np.floor(hi[1])) + 1,
                        max(0, int(np.ceil(lo[0]))):int(np.floor(hi[0])) + 1]
            if not box.any():
                return self.clears_edges(sheet, poly)
        rr, cc = _polygon_pixels(poly, taken.shape)
        if rr.size == 0 or taken[rr, cc].any():
            return False
        return self.clears_edges(sheet, poly)

    def clears_edges(self, sheet: int, poly: np.ndarray) -> bool:
        """True when the footprint ``poly (4, 2)`` sheet px grown by ``kerf_px`` (the wood the
        router takes round the piece cut in it) lies on the sheet and no unusable pixel's square
        reaches into it: exact on the polygon, where the pixel-centre test of :meth:`is_free`
        lets a rotated footprint's edge stray up to a pixel past its centres."""
        import shapely

        k = self.kerf_px
        off = self._off_wood[sheet]
        h, w = off.shape
        # the sheet spans [-0.5, w - 0.5] x [-0.5, h - 0.5] px; the bounding box of the polygon
        # grown by a disc of radius k is its own bounding box grown by k
        lo, hi = poly.min(0) - k, poly.max(0) + k
        if lo[0] < -0.5 - 1e-6 or lo[1] < -0.5 - 1e-6 or hi[0] > w - 0.5 + 1e-6 or hi[1] > h - 0.5 + 1e-6:
            return False
        # unusable pixels whose squares reach the grown bounding box
        r0, c0 = max(0, int(np.ceil(lo[1] - 0.5))), max(0, int(np.ceil(lo[0] - 0.5)))
        r1, c1 = int(np.floor(hi[1] + 0.5)) + 1, int(np.floor(hi[0] + 0.5)) + 1
        rr, cc = np.nonzero(off[r0:r1, c0:c1])
        if rr.size == 0:
            return True
        rr, cc = rr + r0, cc + c0
        # only squares that may come within the kerf: the footprint is convex, so a centre's
        # largest distance past its sides is at most its distance to it, and a square reaches
        # sqrt(1/2) px from its centre; the box's corners of a rotated footprint hold many more
        edge = np.roll(poly, -1, axis=0) - poly
        turn = np.sign(np.sum(poly[:, 0] * np.roll(poly[:, 1], -1) - np.roll(poly[:, 0], -1) * poly[:, 1]))
        out = np.column_stack([edge[:, 1], -edge[:, 0]]) * turn
        out /= np.maximum(np.linalg.norm(out, axis=1, keepdims=True), 1e-12)
        past = (((np.column_stack([cc, rr])[:, None, :] - poly[None]) * out[None]).sum(2)).max(1)
        near = past <= k + np.sqrt(0.5) + 1e-6
        if not near.any():
            return True
        rr, cc = rr[near], cc[near]
        squares = shapely.box(cc - 0.5, rr - 0.5, cc + 0.5, rr + 0.5)
        fp = shapely.Polygon(poly)
        if k > 0:
            return bool((shapely.distance(fp, squares) >= k - 1e-6).all())
        return bool((shapely.area(shapely.intersection(fp, squares)) <= 1e-9).all())

    def consume(self, sheet: int, poly: np.ndarray) -> None:
        """Mark the footprint, grown by the kerf, as used wood (no-op when not single use)."""
        if not self.single_use:
            return
        grown = _grow(poly, self.kerf_px)
        rr, cc = _polygon_pixels(grown, self.taken[sheet].shape)
        self.taken[sheet][rr, cc] = True
        self.atlas.block_polygon(sheet, grown)

    # -- search -----------------------------------------------------------------------------
    def exact_costs(self, sheet: int, rot: int, x0: int, y0: int, radius: int,
                    template: np.ndarray, keep: int = 0) -> list[tuple[float, int, int]]:
        """Exact SSD (eq. 4) of ``template`` at anchors ``x0 +- radius, y0 +- radius`` of a
        rotation, warping only that window of the rotated sheet; ``[(cost, x, y)]`` sorted,
        only anchors whose window lies in rotated usable wood; the ``keep`` best (0: all)."""
        import cv2

        th, tw = template.shape[:2]
        m, (H, W) = self._rot[sheet][rot]
        xa, ya = max(0, x0 - radius), max(0, y0 - radius)
        xb, yb = min(W - tw, x0 + radius), min(H - th, y0 + radius)
        if xb < xa or yb < ya:
            return []
        ww, hh = xb - xa + tw, yb - ya + th
        roi = self._rotated_features(sheet, rot, xa, ya, ww, hh)
        mr = m.copy()
        mr[:, 2] -= (xa, ya)
        # Blocked = taken (which includes unusable wood) or, for the reuse matcher, unusable;
        # only the window is touched, never the whole sheet.
        blocked = self.taken[sheet] if self.single_use else self._unusable[sheet]
        if self.angles_deg[rot] % 360.0 == 0.0:
            u = ~blocked[ya:ya + hh, xa:xa + ww]
        else:
            # Nearest-neighbour: a rotated pixel is free when the sheet pixel it sits on is;
            # off the sheet counts as blocked. The final word is is_free() in the sheet frame.
            u = cv2.warpAffine(blocked.view(np.uint8), mr, (ww, hh), flags=cv2.INTER_NEAREST,
                               borderMode=cv2.BORDER_CONSTANT, borderValue=1) == 0
        cost = _ssd(np.ascontiguousarray(roi), template)
        ii = cv2.integral((~u).astype(np.uint8), sdepth=cv2.CV_32S)
        win = ii[th:, tw:] - ii[:-th, tw:] - ii[th:, :-tw] + ii[:-th, :-tw]
        cost[win != 0] = np.inf
        flat = cost.ravel()
        sel = _smallest(flat, keep or flat.size)
        sel = sel[np.argsort(flat[sel], kind="stable")]
        ys, xs = np.divmod(sel, cost.shape[1])
        return [(float(c), int(x), int(y)) for c, x, y in
                zip(flat[sel].tolist(), (xs + xa).tolist(), (ys + ya).tolist())]

    def target_context(self, feats: np.ndarray) -> np.ndarray | None:
        """The fast search's low-pass of a whole target's features ``(H, W, 2)`` (None in the
        exhaustive mode), for :meth:`best`'s ``context``."""
        return None if self.f == 1 else _lowpass_energy(feats, self.f)

    def best(self, template: np.ndarray,
             context: tuple[np.ndarray, int, int] | None = None,
             struct_px: float = 1.0) -> Match | None:
        """The best valid placement of ``template (th, tw, 2)`` (eq. 4), or None when no free
        wood holds it. Does not consume; call :meth:`take` to commit.

        context : ``(target_context(target feats), y0, x0)`` where the template was cut from
            the target (fast mode): its coarse version is then low-passed with the target
            round it, as every sheet is, rather than with its border replicated, which made
            the outer ring of coarse pixels (a third to a half of a template) disagree even
            with the very wood the target was cut from.
        struct_px : working pixels per pixel of the target image (> 1 when the target was
            enlarged to the working grid): the structural re-rank (:meth:`_choose`) looks at
            the wood on the target's own pixels, the finest grid on which the target says
            whether it is flat.
        """
        th, tw = template.shape[:2]
        f = self.f
        if f == 1:
            cands = self.atlas.search(template, self.top_k * 8)
            m = self._choose(template, [(c, *self.atlas.tiles[t][:2], x, y) for t, x, y, c in cands],
                             struct_px)
            if m is not None:
                return m
            return self._fallback(template) if cands else None
        trim = (0, 0, 0, 0)
        if context is not None:
            L, y0, x0 = context
            tc = _downsample(L[y0:y0 + th, x0:x0 + tw], f)
            # Where the window meets the target's own edge there is no context: the outer
            # coarse pixels there (the Gaussian reaches 0.75 f past the edge, less than one
            # coarse pixel) are left out of the coarse cost (not of the free-wood test).
            H, W = L.shape[:2]
            t = (int(y0 == 0), int(x0 == 0), int(y0 + th >= H), int(x0 + tw >= W))
            if tc.shape[0] > t[0] + t[2] and tc.shape[1] > t[1] + t[3]:
                trim = t
                tc = np.ascontiguousarray(tc[t[0]:tc.shape[0] - t[2], t[1]:tc.shape[1] - t[3]])
        else:
            tc = _coarse(template, f)
        # A coarse search ranks 16 top_k distinct anchors (of its 32 top_k best); they are
        # re-ranked exactly top_k at a time, and the next batch is looked at only when every
        # candidate of this one collides with used wood (late in a run, where the cheapest wood
        # is gone). The coarse map's used wood is optimistic (a coarse pixel is blocked when its
        # centre is), so slivers between used pieces look free there: an anchor whose exact
        # windows are all taken is remembered as dead for this template size (wood is only ever
        # consumed, so it stays dead) and left out of every later search, and the search is
        # run again until a free window turns up or no coarse anchor is left. Without that
        # memory, a target with wide flat areas (coffee) drew the same dead slivers patch after
        # patch and fell through to the exact scan of every rotation (minutes per patch).
        # Where the target is flat, grain of any visible amplitude costs SSIM its contrast-
        # structure term, which eq. 4 weighs no more than a slightly wrong tone: the coarse
        # search weighs the wood's detail amplitude more there and more candidates are
        # re-ranked structurally (both in proportion to the share of flat windows; off in a bare
        # SheetBank, on in ParquetryParams's defaults).
        wd, nr = 1.0, self.rerank
        if (self.flat_detail != 1.0 or self.flat_rerank > self.rerank) and self.w_intens > 0:
            flat = _flat_fraction(template[..., 0] / self.w_intens, struct_px)
            wd = 1.0 + (self.flat_detail - 1.0) * flat
            nr = round(self.rerank + max(0, self.flat_rerank - self.rerank) * flat)
        dead = self._dead.setdefault((th, tw), _Anchors())
        searched = False
        while True:
            cands = _distinct(self.atlas.search(tc, self.top_k * 32, trim, dead.arrays(), wd))[:self.top_k * 16]
            if not cands:
                break
            searched = True
            for b in range(0, len(cands), self.top_k):
                m = self._rerank_batch(template, cands[b:b + self.top_k], dead, struct_px, nr)
                if m is not None:
                    return m
        return self._fallback(template) if searched or len(dead) else None

    def _rerank_batch(self, template: np.ndarray, batch: list[tuple[int, int, int, float]],
                      dead: _Anchors, struct_px: float, rerank: int | None = None) -> Match | None:
        """Exact re-ranking of coarse anchors ``batch = [(tile, x, y, cost)]`` (see
        :meth:`best`); anchors with no free window are appended to ``dead`` (atlas rows, cols)."""
        th, tw = template.shape[:2]
        f = self.f
        found: list[tuple[float, int, int, int, int]] = []
        live = []
        for t, xc, yc, _ in batch:
            i, j, y0, x0 = self.atlas.tiles[t][:4]
            # Coarse tiles are the full rotated canvases downsampled: coarse pixel X covers
            # full pixels f X .. f X + f - 1.
            ex = self.exact_costs(i, j, xc * f, yc * f, self.radius, template, keep=3)
            self.exact_reranks += 1
            if not ex:
                dead.append((y0 + yc, x0 + xc))
                self.dead_anchors += 1
                continue
            live.append((t, xc, yc, i, j, y0, x0))
            found += [(c, i, j, x, y) for c, x, y in ex]
        found.sort()
        m = self._choose(template, found, struct_px, rerank)
        if m is not None or not self.single_use:
            return m
        # Every anchor's three best windows collide: its other windows may not, and an anchor
        # is dead only when none of them is free.
        more = []
        for t, xc, yc, i, j, y0, x0 in live:
            ex = self.exact_costs(i, j, xc * f, yc * f, self.radius, template)
            hit = next(((c, i, j, x, y) for c, x, y in ex[3:]
                        if self.is_free(i, self.footprint(i, j, x, y, th, tw))), None)
            if hit is None:
                dead.append((y0 + yc, x0 + xc))
                self.dead_anchors += 1
            else:
                more.append(hit)
        return self._choose(template, sorted(more), struct_px, rerank)

    def _choose(self, template: np.ndarray, found: list, struct_px: float = 1.0,
                rerank: int | None = None) -> Match | None:
        """The candidate to take from ``found = [(cost, sheet, rot, x, y)]`` (sorted by cost).

        With ``w_struct == 0`` the cheapest free one (eq. 4). Otherwise the first
        ``rerank`` free candidates are re-ranked by ``cost / n_px + w_struct * S``, where ``S``
        is the mean of ``1 - cs`` over 7 x 7 windows and ``cs`` the contrast-structure term of
        SSIM (Wang et al. 2004) between the wood's intensity and the target's (eq. 2): SSD
        weighs a tone error and a grain of the same amplitude alike, whereas the eye (and SSIM)
        forgives a slightly wrong tone far sooner than grain running where the target is flat.
        Both intensities are first area-averaged by ``struct_px`` (see :meth:`best`).
        """
        th, tw = template.shape[:2]
        free = []
        near = max(2, min(th, tw) // 4)
        for c, i, j, x, y in found:
            if self.w_struct > 0 and any(m.sheet == i and m.rot == j and abs(m.x - x) <= near
                                         and abs(m.y - y) <= near for m in free):
                continue    # the same bit of wood shifted a pixel or two: nothing new to rank
            # nothing is taken without single use: is_free's pixel test then passes and its
            # exact test (the kerf clear of the sheet's edge and of unusable wood) decides
            if self.is_free(i, self.footprint(i, j, x, y, th, tw)):
                free.append(Match(i, j, x, y, c))
                if self.w_struct <= 0 or self.w_intens <= 0 or len(free) >= (rerank or self.rerank):
                    break
        if len(free) <= 1:
            return free[0] if free else None
        gt = template[..., 0] / self.w_intens
        score = [m.cost / (th * tw) + self.w_struct * _structure_penalty(
            self._rotated_grey(m.sheet, m.rot, m.x, m.y, tw, th), gt, struct_px) for m in free]
        return free[int(np.argmin(score))]

    def _fallback(self, template: np.ndarray) -> Match | None:
        """Exact scan of every rotation for the cheapest free anchor, when no coarse anchor is
        left (the coarse map's usable wood is conservative: a window at the very edge of the
        usable wood may only be seen here); complete. Counted in ``fallback_scans``.

        Per rotation, only anchors whose window is free in the rotated used-wood mask are
        costed, cheapest first, and only as many as it takes to find one that
        :meth:`is_free` accepts."""
        self.fallback_scans += 1
        th, tw = template.shape[:2]
        best = None
        for i in range(len(self.grey)):
            for j in range(len(self.angles_deg)):
                _, (H, W) = self._rot[i][j]
                r = max(H, W)
                keep = 8
                while True:
                    ex = self.exact_costs(i, j, r, r, r, template, keep=keep)
                    hit = next(((c, x, y) for c, x, y in ex
                                if (best is None or c < best.cost)
                                and self.is_free(i, self.footprint(i, j, x, y, th, tw))), None)
                    if hit is not None:
                        best = Match(i, j, hit[1], hit[2], hit[0])
                    if hit is not None or len(ex) < keep or (best is not None and ex[-1][0] >= best.cost):
                        break
                    keep *= 8
        return best

    def take(self, m: Match, th: int, tw: int) -> np.ndarray:
        """Commit a match: consume its footprint; returns the footprint ``(4, 2)`` sheet px."""
        poly = self.footprint(m.sheet, m.rot, m.x, m.y, th, tw)
        self.consume(m.sheet, poly)
        return poly

    def patch_pixels(self, m: Match, th: int, tw: int) -> np.ndarray:
        """The rotated sheet's features under a match, ``(th, tw, 2)`` (for the seams)."""
        return self._rotated_features(m.sheet, m.rot, m.x, m.y, tw, th)

    def _rotated_features(self, sheet: int, rot: int, x0: int, y0: int, w: int, h: int) -> np.ndarray:
        """Features (eq. 1) of the window ``[x0, x0 + w) x [y0, y0 + h)`` of the rotated sheet,
        computed from the rotated intensity with a 1 px margin, so they equal the features of
        the whole rotated sheet there (the Sobel filter is 3 x 3)."""
        import cv2

        m, _ = self._rot[sheet][rot]
        mr = m.copy()
        mr[:, 2] -= (x0 - 1, y0 - 1)
        G = self.grey[sheet]
        if self.angles_deg[rot] % 360.0 == 0.0:
            # the window with a 1 px margin, replicated at the sheet's border as the
            # whole-sheet Sobel sees it (only the window is copied, never the sheet)
            H, W = G.shape
            ys = np.clip(np.arange(y0 - 1, y0 + h + 1), 0, H - 1)
            xs = np.clip(np.arange(x0 - 1, x0 + w + 1), 0, W - 1)
            g = G[np.ix_(ys, xs)]
        else:
            g = cv2.warpAffine(G, mr, (w + 2, h + 2), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT)
        return np.ascontiguousarray(self.features(g)[1:-1, 1:-1])

    def _rotated_grey(self, sheet: int, rot: int, x0: int, y0: int, w: int, h: int) -> np.ndarray:
        """Intensity of the window ``[x0, x0 + w) x [y0, y0 + h)`` of the rotated sheet."""
        import cv2

        if self.angles_deg[rot] % 360.0 == 0.0:
            return self.grey[sheet][y0:y0 + h, x0:x0 + w]
        mr = self._rot[sheet][rot][0].copy()
        mr[:, 2] -= (x0, y0)
        return cv2.warpAffine(self.grey[sheet], mr, (w, h), flags=cv2.INTER_LINEAR,
                              borderMode=cv2.BORDER_CONSTANT)

    def warp_window(self, image: np.ndarray, m: Match, th: int, tw: int) -> np.ndarray:
        """Any per-sheet image (features, colour) of sheet ``m.sheet`` seen through the
        rotated window of a match: ``(th, tw, c)``."""
        import cv2

        mat, _ = self._rot[m.sheet][m.rot]
        if self.angles_deg[m.rot] % 360.0 == 0.0:
            return image[m.y:m.y + th, m.x:m.x + tw].copy()
        mr = mat.copy()
        mr[:, 2] -= (m.x, m.y)
        return cv2.warpAffine(np.asarray(image, np.float32), mr, (tw, th), flags=cv2.INTER_LINEAR,
                              borderMode=cv2.BORDER_CONSTANT)


#: SSIM's window and its C2 = (0.03 L)^2 for intensities in [0, 1] (Wang et al. 2004).
_SSIM_WIN = 7
_SSIM_C2 = (0.03 * 1.0) ** 2


def _native_grey(g: np.ndarray, scale: float) -> np.ndarray:
    """An intensity ``(h, w)`` area-averaged by ``scale`` (the target image's own pixels; at
    least 7 x 7 of them kept), float32; unchanged for ``scale <= 1``."""
    import cv2

    a = np.asarray(g, np.float32)
    if scale > 1.0:
        h, w = a.shape
        size = (max(_SSIM_WIN, round(w / scale)), max(_SSIM_WIN, round(h / scale)))
        a = cv2.resize(a, size, interpolation=cv2.INTER_AREA)
    return a


def _flat_fraction(gt: np.ndarray, scale: float = 1.0) -> float:
    """Share of the 7 x 7 windows of a target intensity ``gt (h, w)`` (on the target image's
    own pixels, see :func:`_native_grey`) whose variance is below SSIM's C2: where grain of
    any visible amplitude costs SSIM its contrast-structure term."""
    import cv2

    k = (_SSIM_WIN, _SSIM_WIN)
    b = _native_grey(gt, scale)
    mb = cv2.blur(b, k)
    vb = cv2.blur(b * b, k) - mb * mb
    return float(np.mean(vb < _SSIM_C2))


def _structure_penalty(gs: np.ndarray, gt: np.ndarray, scale: float = 1.0) -> float:
    """Mean of ``1 - cs`` over 7 x 7 box windows of two ``(h, w)`` intensities, where
    ``cs = (2 cov + C2) / (var_s + var_t + C2)`` is SSIM's contrast-structure term: 0 when the
    wood's grain follows the target's structure, up to 1 (2 for anti-correlation) when the wood
    is textured where the target is flat. ``scale > 1`` area-averages both by that factor
    first (the target image's own pixels; at least 7 x 7 of them are kept)."""
    import cv2

    k = (_SSIM_WIN, _SSIM_WIN)
    a, b = _native_grey(gs, scale), _native_grey(gt, scale)
    ma, mb = cv2.blur(a, k), cv2.blur(b, k)
    va = cv2.blur(a * a, k) - ma * ma
    vb = cv2.blur(b * b, k) - mb * mb
    cv = cv2.blur(a * b, k) - ma * mb
    cs = (2 * cv + _SSIM_C2) / (np.maximum(va, 0) + np.maximum(vb, 0) + _SSIM_C2)
    return float(np.mean(1.0 - cs))


def _clear_distance_px(kerf_px: float) -> float:
    """The search's kerf rule, its one home: the least distance (px, centre to centre,
    Euclidean) from a pixel a piece may cover to the nearest unusable pixel or pixel off the
    sheet: ``kerf_px``, plus the half pixel from a footprint's edge to its centres, plus the half
    pixel from an unusable pixel's side to its centre; less 1e-9, so a kerf of whole pixels (a
    distance met exactly) leaves exactly that many."""
    return kerf_px + 1.0 - 1e-9


def edge_margin_px(kerf_px: float) -> int:
    """Whole pixels the search loses along each straight edge of a sheet at ``kerf_px``
    (:func:`_clear_of` along a row: the pixel ``c`` px in from the edge lies ``c + 1`` px from
    the first pixel off the sheet): ``ceil(kerf_px)``, 0 without a kerf. A sheet smaller than a
    patch with this at both sides holds no piece (the engine's size check)."""
    if kerf_px <= 0:
        return 0
    return math.ceil(_clear_distance_px(kerf_px)) - 1


def _clear_of(usable: np.ndarray, kerf_px: float) -> np.ndarray:
    """The pixels of ``usable (h, w)`` bool whose centres lie at least ``kerf_px`` plus half a
    pixel from every unusable pixel's square and from the sheet's edge (off the sheet counts as
    unusable; :func:`_clear_distance_px`): an axis-aligned footprint on them, whose edge lies
    half a pixel past its centres, keeps the kerf clear. Measured centre to centre (Euclidean)
    less the half pixel to a square's side, so a pixel diagonal to unusable wood is kept up to
    0.2 px nearer; the exact test is :meth:`SheetBank.clears_edges`. ``kerf_px <= 0`` keeps
    ``usable`` as it is."""
    from scipy.ndimage import distance_transform_edt

    if kerf_px <= 0:
        return usable.copy()
    d = distance_transform_edt(np.pad(usable, 1, constant_values=False))[1:-1, 1:-1]
    return d >= _clear_distance_px(kerf_px)


def _grow(poly: np.ndarray, d: float) -> np.ndarray:
    """A convex polygon offset outward by ``d`` pixels (mitred corners; no-op for d <= 0)."""
    if d <= 0:
        return poly
    from shapely.geometry import Polygon

    g = Polygon(poly).buffer(d, join_style="mitre")
    return np.asarray(g.exterior.coords)[:-1]
