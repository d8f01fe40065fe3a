"""Knot strands inside a fitted stem field (issue 12 part 3; seed 003's knot model, simplified).

A fitted stem field (any ``(n, 3) mm -> years`` in the block frame: a radial fit, an RBF, a baked
grid) has no pith distance or age origin one can trust, so seed 003's times "from the pith" are
replaced by the stem's own growth time:

- the strand point of a point ``p`` is its nearest point ``S`` on the strand, at distance ``d``;
  ``R`` is the knot radius there and ``G`` the stem's ring density (years/mm) at ``S``;
- inside the knot (``d < R``) its time is ``b = g(S) + (d / R) (g(p) - g(S)) - (R - d) G``:
  concentric rings round the strand at its core with the stem's ring spacing, turning into the
  stem's time on the knot surface ``d = R`` (seed 003: ``t_b = t_s`` at the measured diameter);
  ``b <= g(p)`` inside for any stem (``|g(p) - g(S)| <= d G``), so the knot is exactly the
  cylinder ``d < R``; outside, ``b = g(p) + (d - R) G`` leaves the stem in charge.
  (Seed 003 takes the strand point "at the same pith distance", which needs a fitted pith a
  knot strand is radial to; a fitted stem of a real block is not that exact.)
- stem and knot join by a smooth minimum. Seed 003's power smooth minimum (its eq. 2) needs
  times from the pith; this one is the polynomial smooth minimum
  ``min(a, b) - h^2 k / 4, h = max(k - |a - b|, 0) / k`` with ``k`` in years, which bends the
  stem's rings round the knot within about ``k`` rings of its surface.

The bend (``bend=`` a :class:`~woodcam.fields.knots.KnotParams`, a stem with a pith such as
:class:`woodcam.inference.stem.StemField`): seed 003's own join instead, as the log generator
(:class:`~woodcam.fields.knots.KnottedLogField`) has it, with times counted from the stem's pith
``t_s = g(p) - g(pith)`` (years; the power smooth minimum is homogeneous, so years serve as well
as the seed's mm): ``t_b = t_s d / R`` (eq. 1 with ``rho = R / r``: the knot holds every ring
since the pith), ``delta = smin(t_s, t_b, k) - min(t_s, t_b)`` (eqs. 2-3) with the adaptive
``k`` over ``t_s - t_b = rho_s (1 - d / R)`` mm (``rho_s`` the pith distance), faded over the
distance range ``range_d0 + range_k0 rho_s .. range_d1 + range_k1 rho_s`` and joined as eq. 6.
The power smooth minimum lowers the stem's time by a share of itself (18 % at ``d = 2R``, 5 %
at ``5R`` for ``k = 1.5``), so the rings bend round a knot over many rings, not one. Only
:attr:`KnotStrand.pinned` strands bend the rings (the others only mark their knot), and a
dead strand bends as an alive one (the exits show a branch dead at the surface, not where
it died; the bend comes from its alive inner part). Fitted jointly with the stem by
:func:`woodcam.inference.knots.fit_knotted_stem`.

Dead knots (seed 003, Sec. 4.2.2): past its death a branch stops growing and the stem grows
round it without ring continuity, leaving a bark ring (dark outline) at the knot surface. Seed
003 scales the amount of smoothing ``delta = smin - min`` by a factor ``f`` that turns negative
past the death (eq. 5: ``delta' = f delta``); a dead strand here takes
``f =`` :data:`DEAD_KNOT_SMOOTHING_FACTOR` everywhere along it (the stem's rings are pushed
away from the knot instead of bending into it, so they break at its surface), and its
:meth:`StemWithKnots.knot_features` report ``dead`` inside and an ``outline`` shell of
:data:`DEAD_KNOT_OUTLINE_MM` at the surface. Which strands are dead is read from the photos
(:func:`woodcam.inference.knots.exit_is_dead`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ..errors import WoodcamError
from .base import central_gradient, check_points
from .knots import _T_EPS, KnotParams, smoothing_amount

#: Smoothing ``k`` (years) of the stem-knot smooth minimum: rings bend round a knot within about
#: one ring of its surface, as on H11's faces C and F (looked at).
KNOT_SMOOTH_YEARS = 1.0

#: Width (mm) over which the knot darkening weight falls from 1 to 0 across the knot surface.
KNOT_EDGE_MM = 0.3

#: Seed 003's smoothing factor ``f`` (eq. 5) of a dead knot: negative inverts the smooth
#: minimum, so the stem's rings break at the knot surface instead of flowing into it.
DEAD_KNOT_SMOOTHING_FACTOR = -1.0

#: Thickness (mm) of a dead knot's bark ring (``outline``) inside its surface: seed 003's
#: outline parameter; woodcam's log generator draws 1 mm across the knot, 0.5 mm a side.
DEAD_KNOT_OUTLINE_MM = 0.5

_SAMPLES = 256


@dataclass(frozen=True)
class KnotStrand:
    """A straight branch strand through a block, block frame mm.

    start_mm, end_mm : (3,) its ends (beyond the block); radius_start_mm, radius_end_mm : knot
    radius at the ends, linear in between; dead : True for a dead knot (seed 003: no ring
    continuity with the stem, a bark ring at its surface; module docstring); pinned : True when
    two face exits pin the line (its place is measured), False for a strand guessed from one
    exit (its direction is the stem's, toward the pith: :func:`woodcam.inference.knots.
    fit_knot_strands`).
    """

    start_mm: tuple
    end_mm: tuple
    radius_start_mm: float
    radius_end_mm: float
    dead: bool = False
    pinned: bool = True

    def __post_init__(self):
        if min(self.radius_start_mm, self.radius_end_mm) <= 0:
            raise WoodcamError(f"knot radii must be > 0 mm; got {self.radius_start_mm}, {self.radius_end_mm}")
        if np.allclose(self.start_mm, self.end_mm):
            raise WoodcamError("a knot strand needs two different ends")

    def samples(self, n: int = _SAMPLES):
        """Points ``(n, 3)`` and radii ``(n,)`` along the strand."""
        t = np.linspace(0.0, 1.0, n)[:, None]
        a, b = np.asarray(self.start_mm, float), np.asarray(self.end_mm, float)
        return a + t * (b - a), self.radius_start_mm + t[:, 0] * (self.radius_end_mm - self.radius_start_mm)


def _smin(a, b, k, f: float = 1.0):
    """Polynomial smooth minimum with its amount of smoothing scaled by ``f`` (seed 003 eq. 5:
    ``min + f delta``; ``f = 1`` the plain smooth minimum, negative inverts it)."""
    h = np.maximum(k - np.abs(a - b), 0.0) / k
    return np.minimum(a, b) - f * h * h * k / 4.0


class StemWithKnots:
    """``years(p)``: a stem field with knot strands joined in (module docstring).

    stem : ``(n, 3) mm -> (n,) years``; strands : list of :class:`KnotStrand`.
    dense : the knot's ring density ``G`` is ``max(G, g(S) / R)`` where ``g(S) > 0``: with growth
        time counted from the pith (woodcam's convention) the knot then holds every ring since
        the pith and its time is ``b = (d / R) g(p)``, seed 003's ``t_b = d t_s / R``. Only for
        :attr:`KnotStrand.pinned` strands: a strand guessed from one exit is a few mm off its
        knot, and dense rings a few mm off write wrong years over the whole cylinder (dev seed
        21: fitted one-exit strands lowered the cut-plane score, keeping the stem's spacing
        did not), so it keeps the stem's spacing. False keeps it for every strand.
    bend_guessed : also let strands guessed from one exit (``pinned=False``) change the years:
        bend the stem round them (with ``bend``) or join their knot's rings in (without). By
        default a guessed strand marks its knot only (:meth:`knot_features`): even with the
        stem's spacing, its rings a few mm to cm off the knot cost the fits' insides (FIT_VERSION
        16: fresh seed 50287, six noisy faces, knotted blocks within 2 mm 85.4 -> 88.2 %, block
        20 36.6 -> 60.3; README, "A guessed knot marks, it does not write years").
    """

    def __init__(self, stem, strands, smoothing_years: float = KNOT_SMOOTH_YEARS, dense: bool = True,
                 bend: KnotParams | None = None, bend_guessed: bool = False):
        self.stem = stem
        self.dense = bool(dense)
        self.strands = list(strands)
        self.k = float(smoothing_years)
        self.axis = getattr(stem, "axis", (0.0, 0.0, 1.0))
        self._tables = [self._table(s) for s in self.strands]
        # the stem's years and ring density along each strand, for the join without a bend only:
        # made when first needed (the bend never reads them, and the knot-rise search builds ~200
        # bent fields a block: 2.5 of its 13.7 profiled s were these tables, never read)
        self._along: list = [None] * len(self.strands)
        self.bend, self.bend_guessed = bend, bool(bend_guessed)
        if bend is not None:
            if not hasattr(stem, "pith_distance_mm"):
                raise WoodcamError("bend needs a stem with a pith (pith_distance_mm), e.g. a "
                                   f"woodcam.inference.stem.StemField; got {type(stem).__name__}")
            self._pith_years = float(stem.pith_years())

    @staticmethod
    def _table(strand: KnotStrand):
        """The strand's line ``a`` (3,), ``v`` (3,) (start, end - start) and its sample radii ``(n,)``."""
        _, rad = strand.samples()
        a, b = np.asarray(strand.start_mm, float), np.asarray(strand.end_mm, float)
        return a, b - a, rad

    def _stem_along(self, i: int):
        """The stem's years ``(n,)`` and ring density ``(n,)`` (years/mm, at least 1e-3) at strand
        ``i``'s samples, made once."""
        if self._along[i] is None:
            gs, grad = central_gradient(self.stem, self.strands[i].samples()[0], 0.25)
            self._along[i] = gs, np.maximum(np.linalg.norm(grad, axis=1), 1e-3)
        return self._along[i]

    @staticmethod
    def _distance(p: np.ndarray, table):
        """``d``, ``R`` and the strand sample position ``s`` of each point's strand point: all
        that :meth:`knot_features` and :meth:`knot_halo` need (the two interpolations more of
        :meth:`_geometry` were ~45 % of its cost)."""
        a, v, rad = table
        t = np.clip((p - a) @ v / (v @ v), 0.0, 1.0)
        d = np.linalg.norm(p - (a + t[:, None] * v), axis=1)
        s = t * (len(rad) - 1)
        return d, np.interp(s, np.arange(len(rad)), rad), s

    def _geometry(self, p: np.ndarray, i: int):
        """``d``, ``R``, ``G`` and the stem time at strand ``i``'s point of each point."""
        d, R, s = self._distance(p, self._tables[i])
        gs, dens = self._stem_along(i)
        at = np.arange(len(gs))
        return d, R, np.interp(s, at, dens), np.interp(s, at, gs)

    def _knot_time(self, p, g, i: int, dense: bool):
        d, R, G, gS = self._geometry(p, i)
        if dense:  # seed 003: the knot holds every ring since the pith
            G = np.where(gS > 0, np.maximum(G, gS / R), G)
        inside = gS + (d / R) * (g - gS) - (R - d) * G
        return np.where(d < R, inside, g + (d - R) * G)

    def _bent(self, p, gs):
        """Seed 003's join (module docstring, "bend"): ``min(t_s, t_b..) + sum delta_i`` with
        times counted from the stem's pith, each knot's ``delta`` faded over its distance range."""
        P = self.bend
        ds = np.asarray(self.stem.pith_distance_mm(p), float)
        ts = np.maximum(gs - self._pith_years, _T_EPS)  # before the pith's time: no bend (below)
        tbm = np.full(len(p), np.inf)
        inv2 = np.zeros(len(p))
        total = np.zeros(len(p))
        for strand, table in zip(self.strands, self._tables):
            if not (strand.pinned or self.bend_guessed):  # a guessed strand marks its knot only
                continue
            d, R, _ = self._distance(p, table)
            q = d / R
            tb = ts * q  # seed 003: t_b = |P - S| / (rho v_s), rho = R / r: the knot's rings scaled
            tD = ds * (1.0 - q)  # t_s - t_b in mm of stem radius
            kk = 0.5 * (P.k_knot - P.k_stem) * tD / (P.k_transition_mm + np.abs(tD)) + 0.5 * (P.k_knot + P.k_stem)
            delta = smoothing_amount(ts, tb, kk)
            r0, r1 = P.range_d0_mm + P.range_k0 * ds, P.range_d1_mm + P.range_k1 * ds
            inr = d < r1
            delta = np.where(inr, delta * (1.0 - np.clip((d - r0) / (r1 - r0), 0.0, 1.0)), 0.0)
            tb = np.where(inr, tb, np.inf)
            tbm = np.minimum(tbm, tb)
            inv2 += 1.0 / np.maximum(tb, _T_EPS) ** 2
            total += delta
        with np.errstate(divide="ignore"):
            soft = np.where(inv2 > 0, 1.0 / np.sqrt(inv2), np.inf)
        w = np.clip((ts - soft) / ts, 0.0, 1.0)  # inside a knot its own rings, unsmoothed
        w = w * w * (3.0 - 2.0 * w)
        return gs + (np.minimum(ts, tbm) + (1.0 - w) * total - ts)

    def __call__(self, points_mm) -> np.ndarray:
        p = check_points(points_mm)
        gs = np.asarray(self.stem(p), float)
        if self.bend is not None:
            return self._bent(p, gs)
        out = gs.copy()
        for i, strand in enumerate(self.strands):
            if not (strand.pinned or self.bend_guessed):  # a guessed strand marks its knot only
                continue
            out = _smin(out, self._knot_time(p, gs, i, self.dense and strand.pinned), self.k,
                        DEAD_KNOT_SMOOTHING_FACTOR if strand.dead else 1.0)
        return out

    def knot_features(self, points_mm) -> dict:
        """``knot`` (0..1 darkening weight: 1 inside a knot), ``dead`` (the knot weight of dead
        strands) and ``outline`` (1 in a dead knot's bark ring, the :data:`DEAD_KNOT_OUTLINE_MM`
        shell inside its surface), each ``(n,)``, as
        :meth:`woodcam.fields.KnottedLogField.knot_features`."""
        layers = self.knot_layers(points_mm)
        del layers["halo"]
        return layers

    def knot_halo(self, points_mm) -> np.ndarray:
        """``(n,)`` in 0..1: 1 inside a knot, falling linearly to 0 one knot radius beyond its
        surface (where a fitted knot's rings and the stem's bend round it are guessed)."""
        return self.knot_layers(points_mm)["halo"]

    def knot_layers(self, points_mm) -> dict:
        """:meth:`knot_features` and ``halo`` (:meth:`knot_halo`), each ``(n,)``, from one pass
        over the strands (a bake needs all four at every node; each is cheap once the distance
        to the strand is known, which is most of the cost)."""
        p = check_points(points_mm)
        knot, dead, outline, halo = (np.zeros(len(p)) for _ in range(4))
        for strand, table in zip(self.strands, self._tables):
            d, R, _ = self._distance(p, table)
            k = np.clip((R - d) / KNOT_EDGE_MM + 0.5, 0.0, 1.0)
            knot = np.maximum(knot, k)
            halo = np.maximum(halo, np.clip(2.0 - d / R, 0.0, 1.0))
            if strand.dead:
                dead = np.maximum(dead, k)
                outline = np.maximum(outline, ((d < R) & (d > R - DEAD_KNOT_OUTLINE_MM)).astype(float))
        return {"knot": knot, "dead": dead, "outline": outline, "halo": halo}

    def grain_direction(self, points_mm) -> np.ndarray:
        p = check_points(points_mm)
        a = np.asarray(self.axis, float)
        return np.broadcast_to(a / np.linalg.norm(a), p.shape).copy()


def strands_to_meta(strands) -> list[dict]:
    """Plain-JSON list of strands (kept in a baked grid's ``meta["knots"]``)."""
    return [{k: (list(map(float, v)) if isinstance(v, (tuple, list, np.ndarray)) else v)
             for k, v in asdict(s).items()} for s in strands]


def strands_from_meta(items) -> list[KnotStrand]:
    return [KnotStrand(tuple(d["start_mm"]), tuple(d["end_mm"]), float(d["radius_start_mm"]),
                       float(d["radius_end_mm"]), bool(d.get("dead", False)), bool(d.get("pinned", True)))
            for d in items]


__all__ = ["DEAD_KNOT_OUTLINE_MM", "DEAD_KNOT_SMOOTHING_FACTOR", "KNOT_SMOOTH_YEARS", "KnotStrand", "StemWithKnots",
           "strands_from_meta", "strands_to_meta"]
