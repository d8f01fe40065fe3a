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
is exact whatever frame the search ran in.

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

    def __init__(self, bank: SheetBank, f: int):
        import cv2

        self.f = f
        tiles = []                      # (sheet, rot, feats, usable, affine)
        for i, (G, U) in enumerate(zip(bank.grey, bank.usable)):
            for j, a in enumerate(bank.angles_deg):
                # eq. 3: the features of the rotated sheet (not the rotated features)
                Gr, Ur, m = rotate(G, U, a)
                Fr = bank.features(Gr)
                if f > 1:
                    h, w = Fr.shape[:2]
                    hc, wc = max(1, h // f), max(1, w // f)
                    Fr = cv2.resize(_lowpass(Fr, f), (wc, hc), interpolation=cv2.INTER_AREA)
                    Ur = cv2.resize(Ur.astype(np.float32), (wc, hc), interpolation=cv2.INTER_AREA) > 1 - 1e-4
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
        self.F = np.zeros((H, W, 2), np.float32)
        self.blocked = np.ones((H, W), np.uint8)
        self.tile_id = np.full((H, W), -1, np.int32)
        self.tiles = []                 # (sheet, rot, y0, x0, h, w, affine sheet->tile)
        for k, ((i, j, Fr, Ur, m), (y0, x0)) in enumerate(zip(tiles, places)):
            h, w = Fr.shape[:2]
            self.F[y0:y0 + h, x0:x0 + w] = Fr
            self.blocked[y0:y0 + h, x0:x0 + w] = ~Ur
            self.tile_id[y0:y0 + h, x0:x0 + w] = k
            self.tiles.append((i, j, y0, x0, h, w, m))
        self._sq: dict[tuple[int, int], np.ndarray] = {}
        self._by_sheet: dict[int, list[int]] = {}
        for k, t in enumerate(self.tiles):
            self._by_sheet.setdefault(t[0], []).append(k)

    @property
    def nbytes(self) -> int:
        return self.F.nbytes + self.blocked.nbytes + self.tile_id.nbytes

    def search(self, template: np.ndarray, k: int) -> list[tuple[int, int, int, float]]:
        """The ``k`` best valid anchors: ``[(tile, x_in_tile, y_in_tile, cost), ...]`` sorted."""
        import cv2

        th, tw = template.shape[:2]
        if th > self.F.shape[0] or tw > self.F.shape[1]:
            return []
        key = (th, tw)
        if key not in self._sq:
            # Few template sizes occur (interior patches, clipped ones at the panel's edges);
            # keep the last two so a large atlas holds at most two extra float32 copies.
            if len(self._sq) >= 2:
                self._sq.pop(next(iter(self._sq)))
            self._sq[key] = _window_sums((self.F * self.F).sum(axis=2), th, tw)
        cost = _ssd(self.F, template, self._sq[key])
        ii = cv2.integral(self.blocked, sdepth=cv2.CV_32S)
        win = ii[th:, tw:] - ii[:-th, tw:] - ii[th:, :-tw] + ii[:-th, :-tw]
        valid = np.flatnonzero(win.ravel() == 0)
        if valid.size == 0:
            return []
        vals = cost.ravel()[valid]
        k = min(k, valid.size)
        sel = np.argpartition(vals, k - 1)[:k] if k < valid.size else np.arange(valid.size)
        sel = sel[np.argsort(vals[sel])]
        out = []
        for n, c in zip(valid[sel].tolist(), vals[sel].tolist()):
            ya, xa = divmod(int(n), cost.shape[1])
            t = int(self.tile_id[ya, xa])
            _, _, y0, x0, *_ = self.tiles[t]
            out.append((t, xa - x0, ya - y0, c))
        return out

    def block_polygon(self, sheet: int, poly_sheet_px: np.ndarray) -> None:
        """Mark the pixels of every tile of ``sheet`` whose centres lie in the polygon."""
        for k in self._by_sheet.get(sheet, []):
            _, _, y0, x0, h, w, m = self.tiles[k]
            # Rotated full-resolution frame, then coarse: full pixel x sits in coarse pixel
            # (x - (f - 1) / 2) / f.
            q = poly_sheet_px @ m[:, :2].T + m[:, 2]
            q = (q - (self.f - 1) / 2.0) / self.f
            rr, cc = _polygon_pixels(q, (h, w))
            self.blocked[y0 + rr, x0 + cc] = 1


def _lowpass(F: np.ndarray, f: int) -> np.ndarray:
    """Gaussian low-pass (sigma f / 2) before downsampling by f: the coarse search compares
    what survives a misalignment of up to half a coarse pixel, so a texture's fine, periodic
    detail (latewood lines) does not make the true place look bad at the wrong phase."""
    import cv2

    return cv2.GaussianBlur(F, (0, 0), f / 2.0, borderType=cv2.BORDER_REPLICATE)


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
    """

    def __init__(self, grey, usable, w_intens: float = 0.5, w_edge: float = 0.5,
                 n_rot: int = 15, kerf_px: float = 0.0,
                 mode: MatchMode = "fast", coarse_factor: int = 4, top_k: int = 12,
                 single_use: bool = True, max_atlas_bytes: int = 2_500_000_000):
        if mode not in ("exhaustive", "fast"):
            raise WoodcamError(f"mode must be one of ['exhaustive', 'fast']; got {mode!r}")
        if n_rot < 1:
            raise WoodcamError(f"n_rot must be >= 1; got {n_rot}")
        self.grey = [np.ascontiguousarray(g, np.float32) for g in grey]
        self.w_intens, self.w_edge = float(w_intens), float(w_edge)
        self.usable = [np.asarray(u, bool) for u in usable]
        self.taken = [~u for u in self.usable]
        self._unusable = [~u for u in self.usable]
        self.angles_deg = [360.0 * k / n_rot for k in range(n_rot)]
        self.kerf_px = float(kerf_px)
        self.mode = mode
        self.f = 1 if mode == "exhaustive" else max(1, int(coarse_factor))
        self.top_k = top_k
        self.single_use = single_use
        est = sum(g.shape[0] * g.shape[1] for g in self.grey) * n_rot * 2.0 * 13 / self.f ** 2
        if est > max_atlas_bytes:
            raise WoodcamError(
                f"the {mode} search would hold ~{est / 1e9:.1f} GB of rotated sheets (limit "
                f"{max_atlas_bytes / 1e9:.1f} GB); use mode 'fast', fewer rotations, or a lower "
                "working resolution (px_per_mm)")
        self.atlas = _Atlas(self, self.f)
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
        """True when every sheet pixel centred in ``poly`` is usable and not taken."""
        rr, cc = _polygon_pixels(poly, self.taken[sheet].shape)
        if rr.size == 0:
            return False
        # The polygon must lie on the sheet: pixels clipped away would be outside the wood.
        lo, hi = poly.min(0), poly.max(0)
        h, w = self.taken[sheet].shape
        if lo[0] < -0.5 - 1e-6 or lo[1] < -0.5 - 1e-6 or hi[0] > w - 0.5 + 1e-6 or hi[1] > h - 0.5 + 1e-6:
            return False
        return not self.taken[sheet][rr, cc].any()

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
                    template: np.ndarray) -> list[tuple[float, int, int]]:
        """Exact SSD (eq. 4) of ``template`` at anchors ``x0 +- radius, y0 +- radius`` of a
        rotation, warping only that window of the rotated sheet; ``[(cost, x, y)]`` sorted,
        only anchors whose window lies in rotated usable wood."""
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
        ys, xs = np.nonzero(win == 0)
        out = sorted(zip(cost[ys, xs].tolist(), (xs + xa).tolist(), (ys + ya).tolist()))
        return [(float(c), int(x), int(y)) for c, x, y in out]

    def best(self, template: np.ndarray) -> Match | None:
        """The best valid placement of ``template (th, tw, 2)`` (eq. 4), or None when no free
        wood holds it. Does not consume; call :meth:`take` to commit."""
        import cv2

        th, tw = template.shape[:2]
        f = self.f
        if f == 1:
            cands = self.atlas.search(template, self.top_k * 8)
            for t, x, y, c in cands:
                i, j = self.atlas.tiles[t][:2]
                if not self.single_use or self.is_free(i, self.footprint(i, j, x, y, th, tw)):
                    return Match(i, j, x, y, c)
            return self._fallback(template) if cands else None
        tc = cv2.resize(_lowpass(template, f), (max(1, tw // f), max(1, th // f)),
                        interpolation=cv2.INTER_AREA)
        any_cands = False
        for k in (self.top_k, self.top_k * 16):
            cands = self.atlas.search(tc, k)
            any_cands = any_cands or bool(cands)
            found: list[tuple[float, int, int, int, int]] = []
            for t, xc, yc, _ in cands:
                i, j = self.atlas.tiles[t][:2]
                # Coarse tiles are the full rotated canvases downsampled: coarse pixel X
                # covers full pixels f X .. f X + f - 1.
                xf, yf = xc * f, yc * f
                for c, x, y in self.exact_costs(i, j, xf, yf, f + 1, template)[:3]:
                    found.append((c, i, j, x, y))
            found.sort()
            for c, i, j, x, y in found:
                if not self.single_use or self.is_free(i, self.footprint(i, j, x, y, th, tw)):
                    return Match(i, j, x, y, c)
            if not cands:
                break
        return self._fallback(template) if any_cands else None

    def _fallback(self, template: np.ndarray) -> Match | None:
        """Exact scan of every rotation for a free anchor when the ranked candidates all
        collide with used wood (rare: only when the atlas' blocked pixels are optimistic at a
        boundary); slow but complete."""
        th, tw = template.shape[:2]
        best = None
        for i in range(len(self.grey)):
            for j in range(len(self.angles_deg)):
                _, (H, W) = self._rot[i][j]
                r = max(H, W)
                for c, x, y in self.exact_costs(i, j, r, r, r, template):
                    if best is not None and c >= best.cost:
                        break
                    if self.is_free(i, self.footprint(i, j, x, y, th, tw)):
                        best = Match(i, j, x, y, c)
                        break
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
            # copy with the same replicated border the whole-sheet Sobel would see
            pad = np.pad(G, 1, mode="edge")
            g = pad[y0:y0 + h + 2, x0:x0 + w + 2]
        else:
            g = cv2.warpAffine(G, mr, (w + 2, h + 2), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT)
        return np.ascontiguousarray(self.features(g)[1:-1, 1:-1])

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


def _grow(poly: np.ndarray, d: float) -> np.ndarray:
    """A convex polygon offset outward by ``d`` pixels (mitred corners; no-op for d <= 0)."""
    if d <= 0:
        return poly
    from shapely.geometry import Polygon

    g = Polygon(poly).buffer(d, join_style="mitre")
    return np.asarray(g.exterior.coords)[:-1]
