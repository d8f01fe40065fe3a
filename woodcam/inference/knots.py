"""Knot strands fitted from a block's knot masks into its stem field (issue 12 part 3).

Each connected region of a face's ``extras["knot_mask"]`` is a knot's exit through that face: its
centroid (block frame) and equivalent radius ``sqrt(area / pi)``. A branch runs across the stem
(seed 003: from the pith outward, nearly perpendicular to it), so two exits on different faces
whose joining line makes more than :data:`~woodcam.tolerances.KNOT_PAIR_MIN_ANGLE_DEG` with the
stem's axis are one knot, the nearest pairs first (H11: faces C and F). A strand is the line
through its exits, extended across the block but not past the pith (the least stem years along
the line: a branch starts there; two exits with the pith between them are two branches), with
the radius linear between the exits' radii.
An unpaired exit gets a strand into the block down the stem's year gradient (toward the pith,
where a branch starts), ending at the pith, with its own radius; where that gradient does not
enter the block through the face, along the face's inward normal made perpendicular to the
stem axis. Its place is a guess (``pinned=False``): it keeps the stem's ring spacing inside
(:class:`~woodcam.fields.knot_strands.StemWithKnots`). The strands join the stem field through
:class:`woodcam.fields.knot_strands.StemWithKnots`.

Alive or dead (seed 003) is read from the face photo at each exit (:func:`exit_is_dead`): a dead
knot is ringed by bark, a dark line along its whole boundary; an alive knot's rings run on into
the stem's, so its boundary is no darker than its surroundings except where a ring happens to
cross it. A strand is dead when every exit of it is (the part of a branch past its death is
dead; a strand alive at one exit and dead at the other is kept alive: one flag per strand).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from .._types import ArrayLike
from ..fields.base import central_gradient
from ..fields.knot_strands import KnotStrand, StemWithKnots
from ..fields.knots import KnotParams
from ..frames import FACE_NORMAL, pixel_to_block
from ..tolerances import (DEAD_KNOT_BANDS_MM, DEAD_KNOT_MIN_OUTLINED, DEAD_KNOT_SECTORS, KNOT_MIN_AREA_PX,
                          KNOT_BEND_MAX_BEFORE_PITH, KNOT_BEND_ROUNDS, KNOT_MIN_AREA_SHARE, KNOT_MIN_ENTRY_COS,
                          KNOT_PAIR_MIN_ANGLE_DEG, KNOT_PITH_YEARS)

if TYPE_CHECKING:
    from .observations import RingObservations
    from .stem import StemField


def exit_is_dead(photo, region, pixel_mm: float) -> tuple[bool, float]:
    """Does a knot exit show a dead knot's bark ring? ``(dead, outlined share)``.

    photo : (h, w, 3) or (h, w) image of the face; region : (h, w) bool, the exit's mask;
    pixel_mm : pixel size. Around the region's centroid the boundary is cut into
    :data:`~woodcam.tolerances.DEAD_KNOT_SECTORS` sectors; a sector is outlined when the band
    just inside the boundary is darker than both the knot wood further in and the wood just
    outside (bands :data:`~woodcam.tolerances.DEAD_KNOT_BANDS_MM`) by 1 % of the photo's range.
    Dead when at least :data:`~woodcam.tolerances.DEAD_KNOT_MIN_OUTLINED` of the sectors are
    outlined (alive knots: a ring crossing the boundary darkens 0-20 % of them, measured on
    synthetic knots and H11).
    """
    from scipy import ndimage

    m = np.asarray(region, bool)
    lum = np.asarray(photo, float)
    lum = lum.mean(axis=2) if lum.ndim == 3 else lum
    if lum.shape != m.shape or not m.any() or m.all():
        return False, 0.0
    sd = (ndimage.distance_transform_edt(~m) - ndimage.distance_transform_edt(m)) * pixel_mm
    rr, cc = np.indices(m.shape)
    r0, c0 = np.argwhere(m).mean(axis=0)
    n = DEAD_KNOT_SECTORS
    sector = ((np.arctan2(rr - r0, cc - c0) + np.pi) / (2 * np.pi) * n).astype(int) % n
    (e0, e1), (i0, i1), (o0, o1) = DEAD_KNOT_BANDS_MM
    bands = [(sd > e0) & (sd <= e1), (sd > i0) & (sd <= i1), (sd > o0) & (sd <= o1)]
    margin = 0.01 * float(np.ptp(lum))
    outlined = []
    for k in range(n):
        sel = sector == k
        e, i, o = (lum[b & sel] for b in bands)
        if min(len(e), len(i), len(o)) >= 3:
            outlined.append(e.mean() < min(i.mean(), o.mean()) - margin)
    share = float(np.mean(outlined)) if outlined else 0.0
    return bool(share >= DEAD_KNOT_MIN_OUTLINED), share


def knot_exits(block, faces=None) -> list[dict]:
    """Knot exits on ``faces`` (default all): ``{"face", "centre_mm" (3,), "radius_mm", "dead",
    "outlined"}`` (:func:`exit_is_dead` on the face photo; alive without a photo)."""
    from scipy import ndimage

    out = []
    for name in (list(block.faces) if faces is None else faces):
        f = block.faces.get(name)
        mask = None if f is None else f.extras.get("knot_mask")
        if mask is None or not np.any(mask):
            continue
        px = min(block.face_pixel_size_mm(name))
        lab, n = ndimage.label(np.asarray(mask, bool))
        areas = np.bincount(lab.ravel())[1:]
        for i in range(1, n + 1):
            # speckle beside a knot (a detector's, or H11's grown mask) is not another knot
            if areas[i - 1] < max(KNOT_MIN_AREA_PX, KNOT_MIN_AREA_SHARE * areas.max()):
                continue
            region = lab == i
            rr, cc = np.nonzero(region)
            c = pixel_to_block(name, np.array([rr.mean()]), np.array([cc.mean()]), f.shape, block.size_mm)[0]
            dead, share = exit_is_dead(f.photo, region, px) if f.photo is not None else (False, 0.0)
            out.append({"face": name, "centre_mm": c, "radius_mm": float(np.sqrt(len(rr) / np.pi) * px),
                        "dead": dead, "outlined": share})
    return out


#: Samples along a paired strand's line where the stem's years are looked at.
_LINE_SAMPLES = 256


def _toward_pith(stem, point_mm, inward, length: float):
    """``(direction (3,), reach mm)`` of a branch seen at one exit: it grew from the pith out
    along the stem's radial direction, so into the block it runs down the stem's year gradient,
    ``-grad g`` (finite differences, 0.5 mm), and ends at the pith, ``g / |grad g|`` away
    (at most ``length``). ``(None, length)`` where that direction does not enter the block
    through the face (``inward`` (3,), its inward normal) or the gradient vanishes."""
    g0, grads = central_gradient(stem, point_mm, 0.5)
    g, grad = float(g0[0]), grads[0]
    norm = float(np.linalg.norm(grad))
    if not np.isfinite(norm) or norm < 1e-6 or -(grad @ inward) / norm < KNOT_MIN_ENTRY_COS:
        return None, length
    return -grad / norm, float(np.clip(g / norm + 1.0, 5.0, length)) if np.isfinite(g) else length


def fit_knot_strands(block, stem, faces=None) -> list[KnotStrand]:
    """Strands of the knots whose exits the masks show (module docstring)."""
    return strands_from_exits(knot_exits(block, faces), stem, block.size_mm)


def strands_from_exits(exits: list[dict], stem: Callable, size_mm: ArrayLike) -> list[KnotStrand]:
    """Strands of the knot ``exits`` (:func:`knot_exits`) in ``stem``, a block of ``size_mm``
    (module docstring)."""
    if not exits:
        return []
    axis = np.asarray(getattr(stem, "axis", (0.0, 0.0, 1.0)), float)
    axis /= np.linalg.norm(axis)
    length = float(np.linalg.norm(size_mm))
    pairs = []
    for i in range(len(exits)):
        for j in range(i + 1, len(exits)):
            if exits[i]["face"] == exits[j]["face"]:
                continue
            v = exits[j]["centre_mm"] - exits[i]["centre_mm"]
            dist = float(np.linalg.norm(v))
            if dist > 0 and abs(v @ axis) / dist < np.cos(np.deg2rad(KNOT_PAIR_MIN_ANGLE_DEG)):
                pairs.append((dist, i, j))
    used, strands = set(), []
    for dist, i, j in sorted(pairs):
        if i in used or j in used:
            continue
        a, b = exits[i], exits[j]
        u = (b["centre_mm"] - a["centre_mm"]) / dist
        # the line's stem years: a branch grows out of the pith, so it ends where they are least
        t = np.linspace(-length, dist + length, _LINE_SAMPLES)
        g = np.asarray(stem(a["centre_mm"] + t[:, None] * u), float)
        between = (t >= 0) & (t <= dist)
        if not np.all(np.isfinite(g)) or \
                g[between].min() < min(g[between][0], g[between][-1]) - KNOT_PITH_YEARS:
            continue  # the pith lies between the exits: two branches, not one
        used |= {i, j}
        lo_t, hi_t = -length, dist + length
        if g[between][0] <= g[between][-1]:  # the pith is beyond exit a: start there
            lo_t = float(t[t <= 0][np.argmin(g[t <= 0])]) - 1.0
        else:
            hi_t = float(t[t >= dist][np.argmin(g[t >= dist])]) + 1.0
        # an oblique strand cuts a face in an ellipse of area pi R^2 / |cos(incidence)|
        ra, rb = (e["radius_mm"] * np.sqrt(max(abs(u @ np.asarray(FACE_NORMAL[e["face"]], float)), 0.2))
                  for e in (a, b))
        slope = (rb - ra) / dist
        lo, hi = 0.5 * min(ra, rb), 2.0 * max(ra, rb)
        strands.append(KnotStrand(tuple(a["centre_mm"] + u * lo_t), tuple(a["centre_mm"] + u * hi_t),
                                  float(np.clip(ra + slope * lo_t, lo, hi)),
                                  float(np.clip(ra + slope * hi_t, lo, hi)), dead=a["dead"] and b["dead"]))
    for k, e in enumerate(exits):
        if k in used:
            continue
        n = -np.asarray(FACE_NORMAL[e["face"]], float)  # into the block
        d, reach = _toward_pith(stem, e["centre_mm"] + n, n, length)
        if d is None:  # the stem gives no usable direction here: the face normal, across the stem
            d = n - axis * (n @ axis)
            d = d / np.linalg.norm(d) if np.linalg.norm(d) > 0.3 else n
        # the exit's area is an ellipse of pi R^2 / |cos(incidence)| on an oblique face
        r = e["radius_mm"] * np.sqrt(max(abs(d @ n), 0.2))
        strands.append(KnotStrand(tuple(e["centre_mm"] - 2.0 * d), tuple(e["centre_mm"] + reach * d),
                                  r, r, dead=e["dead"], pinned=False))
    return strands


def fit_knotted_stem(obs: RingObservations, size_mm: ArrayLike, exits: list[dict],
                     rounds: int = KNOT_BEND_ROUNDS, seed: int = 0, guessed: bool = False,
                     stem: StemField | None = None) -> StemWithKnots | StemField:
    """The stem model with the rings bent round its knots (seed 003's join), fitted jointly:
    ``StemWithKnots(stem, strands, bend=KnotParams())``, or the plain stem when no strand bends.

    obs : labelled ring observations (block frame, mm); size_mm : (3,) block size; exits : the
    block's knot exits (:func:`knot_exits`, from the masks); guessed : also bend round strands
    guessed from one exit (``pinned=False``); stem : the plain :func:`~.stem.fit_stem` of
    ``obs`` when already fitted.

    A knot lowers the growth time of the stem round it far beyond its surface (seed 003's power
    smooth minimum with its distance ranges: about a year at twice the knot radius, 15 years
    from the pith), so the faces' rings near an exit are bent and a stem fitted to them is
    bent too. Fixed point: fit the stem, place the strands in it, and refit the stem to the
    years minus the bend the knots put there (``fit_stem(offset_years=..., init=...)``),
    ``rounds`` times (dev seed 21, six noisy faces, within 1 mm: 0 rounds 40 / 29 / 36 %, 1
    round 97 / 53 / 97 %, 2 rounds 99 / 68 / 98 %, 4 rounds 99 / 74 / 98 % on blocks 1 / 9 / 10).

    By default only strands pinned by two exits bend the rings: a one-exit strand is a guess a
    few mm off its knot, and its bend then writes wrong years over a wide region (dev seed 21,
    three faces: block 10 45 -> 25 %, block 5 86 -> 43 % within 1 mm; but block 7 63 -> 66 %):
    ``guessed=True`` is a separate hypothesis the held-out faces judge. Strands that do not
    bend are kept for the knot's look (:meth:`StemWithKnots.knot_features`). A dead strand bends
    as an alive one: the branch was alive from the pith to its death, which the exits do not
    show, and the bend comes from that inner part (its inversion past death is left out).
    """
    return _fit_knotted_stem(obs, size_mm, exits, rounds, seed, guessed, stem)[0]


def _fit_knotted_stem(obs, size_mm, exits, rounds, seed, guessed, stem):
    """:func:`fit_knotted_stem` and whether every round placed pinned strands only (then the
    fit with ``guessed=True`` would make the very same steps)."""
    from .stem import fit_stem

    stem = fit_stem(obs, size_mm, seed=seed) if stem is None else stem
    plain, field, only_pinned = stem, stem, True
    for r in range(rounds + 1):
        g = stem(obs.points_mm)  # once per round: the check here and the bend's offset below
        if np.mean(g <= stem.pith_years()) > KNOT_BEND_MAX_BEFORE_PITH:
            return plain, False  # times are not "from the pith" in this stem: no bend to speak of
        strands = strands_from_exits(exits, stem, size_mm)
        only_pinned &= all(s.pinned for s in strands)
        if not any(s.pinned or guessed for s in strands):
            return plain, False
        field = StemWithKnots(stem, strands, bend=KnotParams(), bend_guessed=guessed)
        if r == rounds:
            break
        off = field(obs.points_mm) - g
        stem = fit_stem(obs, size_mm, seed=seed, offset_years=off, init=stem)
    return field, only_pinned


def knot_bend_recipes(size_mm: ArrayLike, exits: list[dict], seed: int = 0,
                      guessed: bool = False) -> tuple[Callable, dict[str, Callable]]:
    """Evidence hypotheses of the knots' bend: ``(stem, recipes)``.

    ``recipes``, name -> ``RingObservations -> field``, is :func:`fit_knotted_stem` from scratch
    on the given rings (the exits come from the masks, not from the rings a fold holds out):
    ``"stem + knot bend"`` (pinned strands; exits on two faces needed) and, with ``guessed``,
    ``"stem + guessed knot bend"`` (every strand). The guessed one is left out by default
    (:func:`~.fit.fit_block` does not offer it): a strand guessed from one exit is a few mm to
    cm off its knot, and with three faces, where most knots show one exit, its bend lost more
    than it gained (seed 61297, three noisy faces, knotted: 52.4 -> 50.0 % within 1 mm; dev seed
    9101 block 0: 60.9 -> 51.3); with six faces it was never needed (dev seeds 9101 and 21: the
    same choices and scores without it). ``stem`` is the plain stem's recipe (:func:`~.stem.fit_stem`)
    remembering its last fit: passed as the evidence fit's stem hypothesis
    (:func:`~.evidence.fit_evidence`'s ``stem``), each fold's stem is fitted once for all of them.
    """
    from .evidence import stem_recipe

    plain = stem_recipe(size_mm, seed)  # remembers its last fit: one stem per fold for all

    bent: dict = {}

    def pinned(obs):
        if bent.get("obs") is not obs:
            field, same = _fit_knotted_stem(obs, size_mm, exits, KNOT_BEND_ROUNDS, seed, False, plain(obs))
            bent.update(obs=obs, field=field, same=same)
        return bent["field"]

    def bent_guessed(obs):
        if bent.get("obs") is obs and bent["same"]:  # no strand was a guess: the same fit
            return bent["field"]
        return fit_knotted_stem(obs, size_mm, exits, seed=seed, guessed=True, stem=plain(obs))

    out = {}
    if len({e["face"] for e in exits}) >= 2:  # a strand is pinned by exits on two faces
        out["stem + knot bend"] = pinned
    if exits and guessed:
        out["stem + guessed knot bend"] = bent_guessed
    return plain, out


def with_knots(block, stem, faces=None):
    """``(field, strands)``: ``stem`` with the masked knots joined in, or ``stem`` unchanged."""
    strands = fit_knot_strands(block, stem, faces)
    return (StemWithKnots(stem, strands) if strands else stem), strands


__all__ = ["exit_is_dead", "fit_knot_strands", "fit_knotted_stem", "knot_bend_recipes", "knot_exits",
           "strands_from_exits", "with_knots"]
