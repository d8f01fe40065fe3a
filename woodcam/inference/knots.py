"""Knot strands fitted from a block's knot masks into its stem field (issue 12 part 3).

Each connected region of a face's ``extras["knot_mask"]`` is a knot's exit through that face: its
centroid (block frame) and equivalent radius ``sqrt(area / pi)``. Exits on two faces that touch
across the edge between them are one knot *end* (a knot cut by a block edge or corner). A branch
runs across the stem (seed 003: from the pith outward, nearly perpendicular to it), so two ends
on different faces whose joining line makes more than
:data:`~woodcam.tolerances.KNOT_PAIR_MIN_ANGLE_DEG` with the stem's axis are one knot (H11: faces
C and F). A branch starts on the pith, so the pairs whose line passes the stem's pith beyond
one of them (:data:`~woodcam.tolerances.KNOT_PAIR_MAX_MISS_SHARE`) are taken first, the line
nearest it first, then the others, the nearest ends first (FIT_VERSION 17: in distance order
alone a knot's exit paired with a knot cutting a block corner on dev seed 21 block 22 and seed
50287 block 1). Another pairing (two pairs exchanging partners, or a pair taking an end left
over) is kept where its cones cut the masks better and the bend fits the rings better
(:func:`_pairings`, FIT_VERSION 26: dev seed 9101 block 5's two knots were crossed). An
unpaired end over two faces is a knot of its own. An end still unpaired then pairs
with an end already taken that lies nearer the pith when their line passes the pith
(:data:`~woodcam.tolerances.KNOT_SHARE_MAX_MISS_MM`): a whorl's branches leave the pith
together, so near it one exit can be two knots'.
A knot is a cone round its strand (its radius grows along it), and its strand and radius are
the cone that cuts the faces as every face's mask shows (:func:`_fit_cone`: inside its exits,
outside on the knot-free samples), extended across the block but not past the pith (the least
stem years along the line: a branch starts there; two exits with the pith between them are two
branches). Before (``strands_from_exits(cones=False)``): the line through two exits' centroids
with the radius linear between their areas' radii, which on dev seed 7777 block 2 paired the two
exits of each end and bent the rings round two wrong strands (35 % within 1 mm; the cone 97 %).
An unpaired exit in a stem with a pith (:class:`~.stem.StemField`) is the branch it is: the ray
from the pith in its cross-section out through the exit and on across the block
(:func:`_pith_ray`; FIT_VERSION 18). Its rise, which one exit does not show, is read from the
rings by :func:`fit_knotted_stem` (:func:`_ray_rises`); with a rise it is placed
(``pinned=True``) and bends the rings, without one it is a guess (``pinned=False``) that marks
its knot (the knot layer a bake colours) and leaves the field's years as they are (FIT_VERSION
16). In a stem without a pith the strand runs into the block down the stem's year gradient
(toward the pith, where a branch starts), ending at the pith, with its own radius; where that
gradient does not enter the block through the face, along the face's inward normal made
perpendicular to the stem axis. The strands join the stem field through
:class:`woodcam.fields.knot_strands.StemWithKnots`.

Alive or dead (seed 003) is read from the face photo at each exit (:func:`exit_is_dead`): a dead
knot is ringed by bark, a dark line along its whole boundary; an alive knot's rings run on into
the stem's, so its boundary is no darker than its surroundings except where a ring happens to
cross it. A strand is dead when every exit of it is (the part of a branch past its death is
dead; a strand alive at one exit and dead at the other is kept alive: one flag per strand).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from .._parallel import map_processes
from .._types import ArrayLike
from ..fields.base import central_gradient
from ..fields.knot_strands import KnotStrand, StemWithKnots
from ..fields.knots import KnotParams
from ..frames import FACE_NORMAL, pixel_to_block
from ..tolerances import (DEAD_KNOT_BANDS_MM, DEAD_KNOT_MIN_OUTLINED, DEAD_KNOT_SECTORS, KNOT_BEND_MAX_BEFORE_PITH,
                          KNOT_BEND_ROUNDS, KNOT_CONE_EDGE_MM, KNOT_CONE_MAX_NFEV, KNOT_CONE_MIN_RADIUS_MM,
                          KNOT_CONE_REACH_MM, KNOT_CONE_SAMPLE_MM, KNOT_CONE_START_REUSE_DEG, KNOT_END_MIN_SPAN_RADII,
                          KNOT_END_TOUCH_MM, KNOT_MIN_AREA_PX, KNOT_MIN_AREA_SHARE,
                          KNOT_MIN_ENTRY_COS, KNOT_PAIR_MIN_ANGLE_DEG, KNOT_PAIR_MISS_FLOOR_MM, KNOT_PITH_YEARS,
                          KNOT_PAIR_MAX_MISS_SHARE, KNOT_PAIRING_MIN_IOU_GAIN, KNOT_PAIRING_MIN_MISFIT_GAIN,
                          KNOT_RAY_MIN_PITH_MM, KNOT_RAY_MISFIT_CAP_MM, KNOT_RAY_REFIT_POINTS,
                          KNOT_RAY_RISES_DEG, KNOT_SHARE_MAX_MISS_MM, KNOT_SHARE_MAX_MISS_SHARE)

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
    "outlined", "surface", "pixels", "cone_memo"}`` (:func:`exit_is_dead` on the face photo;
    alive without a photo). ``surface`` is shared by all exits: ``(points_mm (n, 3), knot (n,)
    bool)``, the masks of every face given one (knot-free faces too), sampled every
    :data:`~woodcam.tolerances.KNOT_CONE_SAMPLE_MM`; ``pixels`` (m,) int indexes the exit's own
    samples in it (:func:`_fit_cone` fits a strand's cone to them); ``cone_memo`` (shared dict)
    keeps those fits, which depend on the masks and their start only."""
    from scipy import ndimage

    out = []
    pts, flags, regions = [], [], []  # the sampled surface and, per exit, its sampled region
    for name in (list(block.faces) if faces is None else faces):
        f = block.faces.get(name)
        mask = None if f is None else f.extras.get("knot_mask")
        if mask is None:
            continue
        m = np.asarray(mask, bool)
        px = min(block.face_pixel_size_mm(name))
        step = max(1, int(round(KNOT_CONE_SAMPLE_MM / px)))
        rows, cols = np.mgrid[step // 2:m.shape[0]:step, step // 2:m.shape[1]:step]
        base = sum(len(q) for q in pts)
        pts.append(pixel_to_block(name, rows.ravel(), cols.ravel(), f.shape, block.size_mm))
        flags.append(m[rows, cols].ravel())
        if not m.any():
            continue
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
            regions.append(base + np.flatnonzero(region[rows, cols].ravel()))
    surface = (np.concatenate(pts), np.concatenate(flags)) if pts else (np.zeros((0, 3)), np.zeros(0, bool))
    memo: dict = {}  # cone fits of these masks: the bend refits its strands every round and fold
    for e, idx in zip(out, regions):
        e.update(surface=surface, pixels=idx, cone_memo=memo)
    return out


#: Samples along a paired strand's line where the stem's years are looked at.
_LINE_SAMPLES = 256


def _fit_cone(surface, positive, ignore, c0, u0, r0, memo: dict | None = None,
              workers: int = 1):
    """A knot's cone fitted to the knot masks of every face: ``(c (3,), u (3,), rc, slope,
    cost)``; ``u0`` (3,) or (k, 3) starting directions, the fit of least cost kept (the first of
    equal costs); ``memo``: a dict remembering each start's fit by the other arguments; a
    start within :data:`~woodcam.tolerances.KNOT_CONE_START_REUSE_DEG` of one already fitted
    takes that fit (the first such). Per start because a knot end cut by a block edge starts
    from three directions of its own samples and one down the stem's years, and only that one
    changes from fold to fold and round to round, by a few degrees (seed 91841 block 7, six
    faces: 101 cone fits of four starts each were 132 of the fit's 147 CPU-s; then 29 starts
    down the stem's years within 5.6 degrees of each other were 9 of its 21 CPU-s).

    A branch is a cone round its strand (seed 001/003: its diameter grows along it), so its
    exits are where that cone cuts the block's faces. The cone is fitted to the sampled face
    masks ``surface = (points (n, 3), knot (n,) bool)`` (:func:`knot_exits`): its ``positive``
    samples (the exits of this knot, index array) inside, every knot-free sample of every
    masked face outside (a face without a mask says nothing), other knots' samples (``ignore``)
    left out; least squares of a logistic inside-ness (width
    :data:`~woodcam.tolerances.KNOT_CONE_EDGE_MM`), every sample weighted alike (balancing the
    few knot samples against the many clear ones widened the cone by 1-3 mm).
    Starts from the line through ``c0`` along ``u0`` with radius ``r0`` (the exits' centres and
    mean radius). Why: the exits' centroids and areas alone misplace a strand whose exits are
    cut by a block edge or split over two faces, and its bend and rings then land off the knot
    (dev seed 7777 block 2: the true strand takes the bend's cut planes from 26 to 94 % within
    1 mm; scipy has no cone fit, so it is written here).

    ``workers``: processes the starts not yet fitted are shared among
    (:func:`woodcam._parallel.map_processes`; the same fits, bit for bit); a start that would
    take an earlier start's fit of this call waits for it, as one after the other."""
    head = (np.asarray(positive).tobytes(), np.asarray(ignore).tobytes(), np.asarray(c0, float).tobytes(),
            float(r0))
    done = [] if memo is None else memo.setdefault(head, [])  # (start (3,), fit) of this problem
    cos_near = np.cos(np.radians(KNOT_CONE_START_REUSE_DEG))
    fits = [f for _, f in done]  # every fit this call may take, by index: the memo's, then its own
    known = [(u, i) for i, (u, _) in enumerate(done)]
    fresh, picks = [], []  # the starts to fit; the fit each start takes
    for u_start in np.atleast_2d(np.asarray(u0, float)):  # several starting directions
        pick = next((i for u, i in known if u @ u_start >= cos_near * np.linalg.norm(u) * np.linalg.norm(u_start)),
                    None)
        if pick is None:
            pick = len(fits) + len(fresh)
            fresh.append(u_start.copy())
            if memo is not None:  # a later start near this one takes its fit
                known.append((u_start.copy(), pick))
        picks.append(pick)
    if fresh:
        problem = _cone_problem(surface, positive, ignore, c0, r0)
        new = map_processes(lambda u: _fit_cone_start(problem, c0, u, r0), fresh, workers)
        fits += new
        if memo is not None:
            done.extend(zip(fresh, new))
    best = None
    for fit in (fits[i] for i in picks):
        if best is None or fit[4] < best[4]:  # the least misfit wins
            best = fit
    return best


def _cone_problem(surface, positive, ignore, c0, r0):
    """``(P (m, 3), y (m,), w)``: the samples a cone started at ``c0`` with radius ``r0`` is
    fitted to (:func:`_fit_cone`), their inside labels and their common weight."""
    pts, knot = surface
    keep = np.ones(len(pts), bool)
    keep[ignore] = False
    keep[positive] = True
    label = np.zeros(len(pts))
    label[positive] = 1.0
    # only samples near the starting cone can move it (speed: faces are ~10^4 samples each)
    near = keep & (np.linalg.norm(pts - c0, axis=1) < np.ptp(pts[positive], axis=0).max() + 2.0 * r0
                   + KNOT_CONE_REACH_MM)
    near &= label.astype(bool) | ~knot
    P, y = pts[near], label[near]
    return P, y, 1.0 / np.sqrt(max(len(y), 1))  # every sample alike: the misfit is the area misclassified


def _cone_iou(problem, cone) -> float:
    """Intersection over union of the samples inside ``cone`` (:func:`_fit_cone`'s ``(c, u, rc,
    slope, cost)``) and the knot samples of ``problem`` (:func:`_cone_problem`): how well one
    cone explains the masks it was fitted to (1: every knot sample inside, no clear one)."""
    inside = _cone_terms(np.concatenate([cone[0], cone[1], [cone[2], cone[3]]]), problem[0])[-1] > 0
    knot = problem[1] > 0.5
    return float((inside & knot).sum() / max((inside | knot).sum(), 1))


def _fit_cone_start(problem, c0, u_start, r0):
    """One start of :func:`_fit_cone`: ``(c, u, rc, slope, cost)`` from the line through ``c0``
    along ``u_start (3,)`` with radius ``r0``, ``u`` in the starting sense. Residuals
    :func:`_cone_residuals`, Jacobian :func:`_cone_jacobian` (analytic: 2-point differences
    spent 8 more residual evaluations per step; seed 91841 block 7 33.9 -> 21.6 CPU-s)."""
    from scipy.optimize import least_squares

    x0 = np.concatenate([c0, u_start, [r0, 0.0]])
    last: dict = {}

    def terms(x):  # least_squares asks for the Jacobian where it just took the residuals
        if "x" not in last or not np.array_equal(last["x"], x):
            last.update(x=x.copy(), terms=_cone_terms(x, problem[0]))
        return last["terms"]

    fit = least_squares(_cone_residuals, x0, jac=_cone_jacobian, args=(problem, c0, terms),
                        x_scale=np.array([5, 5, 5, 0.2, 0.2, 0.2, 1.0, 0.05]),
                        max_nfev=KNOT_CONE_MAX_NFEV)
    x = fit.x
    u = x[3:6] / np.linalg.norm(x[3:6])
    sign = np.sign(u @ u_start) or 1.0  # keep the starting sense (exit to exit)
    return x[:3], u * sign, float(x[6]), float(x[7]) * sign, float(fit.cost)


def _cone_terms(x, P):
    """What the cone fit's residuals and Jacobian share at ``x = (c (3,), v (3,), rc, slope)``
    (``u = v / |v|``): ``u, |v|, t (m,), d (m,), n (m, 3)`` (unit from the axis to each sample,
    0 on it), ``active (m,)`` (the radius ``rc + slope t`` is above its floor
    :data:`~woodcam.tolerances.KNOT_CONE_MIN_RADIUS_MM`) and the margin ``m (m,)``: that radius
    less ``d``, in edge widths (> 0 inside)."""
    nv = float(np.linalg.norm(x[3:6]))
    u = x[3:6] / nv
    q = P - x[:3]
    t = q @ u
    perp = q - t[:, None] * u
    d = np.linalg.norm(perp, axis=1)
    n = perp / np.where(d > 0, d, 1.0)[:, None]
    radius = x[6] + x[7] * t
    active = radius > KNOT_CONE_MIN_RADIUS_MM
    m = (np.where(active, radius, KNOT_CONE_MIN_RADIUS_MM) - d) / KNOT_CONE_EDGE_MM
    return u, nv, t, d, n, active, m


def _cone_residuals(x, problem, c0, terms=None):
    """Residuals (m + 2,) of the cone fit (:func:`_fit_cone`): each sample's logistic
    inside-ness minus its label, weighted, and two gauges (``c`` slides along ``u``; ``|v|`` = 1).
    ``terms``: ``x -> _cone_terms(x, P)``, remembered by the caller (default: computed)."""
    P, y, w = problem
    u, nv, *_, m = _cone_terms(x, P) if terms is None else terms(x)
    inside = 0.5 * (1.0 + np.tanh(0.5 * m))  # logistic, overflow-free
    return np.concatenate([w * (inside - y), [(x[:3] - c0) @ u, nv - 1.0]])


def _cone_jacobian(x, problem, c0, terms=None):
    """Jacobian (m + 2, 8) of :func:`_cone_residuals`. With ``q = p - c``, ``t = q.u`` and
    ``d = |q - t u|`` along the unit ``n``: ``dd/dc = -n``, ``dd/dv = -t n / |v|``,
    ``dt/dc = -u``, ``dt/dv = d n / |v|`` (``n`` is normal to ``u``), so the margin
    ``(rc + slope t - d) / edge`` moves by ``(n - a slope u) / edge`` with ``c``, by
    ``n (t + a slope d) / (|v| edge)`` with ``v``, by ``a / edge`` with ``rc`` and ``a t / edge``
    with ``slope`` (``a``: the radius is above its floor). ``terms`` as :func:`_cone_residuals`."""
    P, y, w = problem
    u, nv, t, d, n, active, m = _cone_terms(x, P) if terms is None else terms(x)
    a = active.astype(float)
    dm = np.empty((len(P), 8))
    dm[:, :3] = n - (a * x[7])[:, None] * u
    dm[:, 3:6] = n * ((t + a * x[7] * d) / nv)[:, None]
    dm[:, 6] = a
    dm[:, 7] = a * t
    th = np.tanh(0.5 * m)
    J = np.zeros((len(P) + 2, 8))
    J[:-2] = dm * (w * 0.25 * (1.0 - th * th) / KNOT_CONE_EDGE_MM)[:, None]
    proj = (np.eye(3) - np.outer(u, u)) / nv  # du/dv
    J[-2, :3] = u
    J[-2, 3:6] = (x[:3] - c0) @ proj
    J[-1, 3:6] = u
    return J


def _pith_miss(stem, points_mm, u, dist, length: float) -> tuple[np.ndarray, np.ndarray]:
    """``(miss (m,) mm, beyond (m,) bool)`` of the ``m`` lines through ``points_mm (m, 3)`` along
    the unit ``u (m, 3)``: how near each passes the pith of ``stem`` (a
    :class:`~.stem.StemField`: its least ``pith_distance_mm``, sampled from ``2 length`` mm behind
    its point to as far beyond the other exit, ``dist (m,)`` mm on, then finely round the least),
    and whether that nearest point lies beyond the exits (not between them, where the pith would
    part two branches). All lines in one call of the stem per stage."""
    p, u, dist = np.asarray(points_mm, float), np.asarray(u, float), np.asarray(dist, float)
    rows = np.arange(len(dist))

    def least(t):  # (m, n) positions along the lines -> the least pith distance and where
        rho = stem.pith_distance_mm((p[:, None] + t[..., None] * u[:, None]).reshape(-1, 3)).reshape(t.shape)
        k = np.argmin(rho, axis=1)
        return rho[rows, k], t[rows, k]

    reach = 2.0 * length + dist
    t = np.linspace(-reach, dist + reach, _LINE_SAMPLES, axis=1)
    step = t[:, 1] - t[:, 0]
    _, tk = least(t)
    miss, tk = least(np.linspace(tk - step, tk + step, 41, axis=1))
    return miss, ~((0.0 < tk) & (tk < dist))


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


def fit_knot_strands(block, stem, faces=None, cones: bool = False) -> list[KnotStrand]:
    """Strands of the knots whose exits the masks show (module docstring; ``cones``:
    :func:`strands_from_exits`)."""
    return strands_from_exits(knot_exits(block, faces), stem, block.size_mm, cones)


def _ends(exits, cones: bool) -> list[list[int]]:
    """Exits grouped into knot ends: exits on two faces whose mask samples touch across the
    block edge between them are one cross-section of a knot cut by that edge (one end, not two
    knots: dev seed 7777 block 2 enters by its front and left faces at one corner and leaves by
    its right and back faces at the opposite one). Without ``cones`` (or mask samples) every
    exit is its own end."""
    parent = list(range(len(exits)))

    def root(k):
        while parent[k] != k:
            k = parent[k]
        return k

    if cones and exits and "surface" in exits[0]:
        from scipy.spatial import cKDTree

        pts = exits[0]["surface"][0]
        trees = [cKDTree(pts[e["pixels"]]) if len(e["pixels"]) else None for e in exits]
        for i in range(len(exits)):
            for j in range(i + 1, len(exits)):
                if exits[i]["face"] == exits[j]["face"] or trees[i] is None or trees[j] is None:
                    continue
                if trees[i].sparse_distance_matrix(trees[j], KNOT_END_TOUCH_MM).nnz:
                    parent[root(j)] = root(i)
    groups: dict[int, list[int]] = {}
    for k in range(len(exits)):
        groups.setdefault(root(k), []).append(k)
    return list(groups.values())


def _end_centre(exits, end, cones: bool) -> np.ndarray:
    """(3,) mm: the middle of a knot end's mask samples (``cones``), else (or when it has none)
    its exits' centre."""
    if cones and "surface" in exits[end[0]]:
        idx = np.concatenate([exits[k]["pixels"] for k in end])
        if len(idx):
            return exits[end[0]]["surface"][0][idx].mean(axis=0)
    return np.mean([exits[k]["centre_mm"] for k in end], axis=0)


def strands_from_exits(exits: list[dict], stem: Callable, size_mm: ArrayLike,
                       cones: bool = False, workers: int = 1,
                       rises: dict[int, float] | None = None, prefer: frozenset = frozenset()) -> list[KnotStrand]:
    """Strands of the knot ``exits`` (:func:`knot_exits`) in ``stem``, a block of ``size_mm``
    (module docstring). ``cones``: exits touching across a block edge are one knot end
    (:func:`_ends`), and a paired strand's line and radius are its cone fitted to the face masks
    (:func:`_fit_cone`; exits from :func:`knot_exits` carry the samples); False: the line
    through two exits' centroids with radii from their areas (what
    :func:`~.fit.fit_block` ``(knot_cones=False)`` uses; the fit's default is the cones since
    FIT_VERSION 10). ``workers``: processes each cone's starts may use (:func:`_fit_cone`).
    ``rises``: exit index -> rise (rad) of the knots seen at one exit whose ray from the pith
    the rings placed (:func:`_ray_rises`): those strands bend the rings (``pinned``). ``prefer``:
    pairs of knot ends taken first, as the rings and masks chose them (:func:`_pairings`, :func:`_fit_knotted_stem`)."""
    return _strands(exits, stem, size_mm, cones, workers, rises, prefer)[0]


def _strands(exits, stem, size_mm, cones=False, workers=1, rises=None,
             prefer: frozenset = frozenset(), iou: bool = False) -> tuple[list[KnotStrand], dict]:
    """:func:`strands_from_exits` and what :func:`_ray_rises` and :func:`_pairings` need of it:
    ``{"lone": exit index -> index of its strand, for each knot seen at one exit only (its
    strand a guess, or a ray whose rise ``rises`` gives), "ends": the knot ends (exit index
    tuples, :func:`_ends`), "pairs": [(end, end, IoU)] the ends paired, in order, each with its
    cone's agreement with their masks (:func:`_cone_iou`, with ``iou`` and cones; else None)}``.
    ``prefer``: pairs of ends (frozensets of two exit index tuples) taken before every other
    pair (:func:`_pairings`)."""
    if not exits:
        return [], {"lone": {}, "ends": [], "pairs": []}
    rises = rises or {}
    size = np.asarray(size_mm, float)
    axis = np.asarray(getattr(stem, "axis", (0.0, 0.0, 1.0)), float)
    axis /= np.linalg.norm(axis)
    length = float(np.linalg.norm(size_mm))
    ends = _ends(exits, cones)
    centres = [_end_centre(exits, e, cones) for e in ends]
    candidates = []  # (distance, end, end): ends on different faces whose line crosses the stem
    for i in range(len(ends)):
        for j in range(i + 1, len(ends)):
            if {exits[k]["face"] for k in ends[i]} & {exits[k]["face"] for k in ends[j]}:
                continue
            v = centres[j] - centres[i]
            dist = float(np.linalg.norm(v))
            if dist > 0 and abs(v @ axis) / dist < np.cos(np.deg2rad(KNOT_PAIR_MIN_ANGLE_DEG)):
                candidates.append((dist, i, j))
    # a branch grows out of the pith, so the line of two exits of one knot passes it beyond one of
    # them: such pairs first, the line nearest the pith first; the others after them, the nearest
    # exits first (a line with the pith between its exits is two branches' and comes last too)
    rho = np.asarray(stem.pith_distance_mm(np.array(centres)), float) if hasattr(stem, "pith_distance_mm") else None
    miss = np.full(len(candidates), np.inf)  # floored, mm; inf where the pith lies between or is unknown
    if rho is not None and candidates:
        dists, first, second = (np.array(q) for q in zip(*candidates))
        at = np.array(centres)
        least, beyond = _pith_miss(stem, at[first], (at[second] - at[first]) / dists[:, None], dists, length)
        miss = np.where(beyond, np.maximum(least, KNOT_PAIR_MISS_FLOOR_MM), np.inf)
    pairs = [((0, mi) if rho is not None and mi <= KNOT_PAIR_MAX_MISS_SHARE * min(rho[i], rho[j]) else (1, dist),
              dist, i, j, mi) for (dist, i, j), mi in zip(candidates, miss)]  # (order, distance, end, end, miss)
    if prefer:  # the pairs the rings and masks chose over the order above (:func:`_pairings`)
        pairs = [((-1, 0) if frozenset((tuple(ends[i]), tuple(ends[j]))) in prefer else order, dist, i, j, mi)
                 for order, dist, i, j, mi in pairs]
    pairs.sort(key=lambda q: q[:4])
    surface = exits[0].get("surface") if cones else None
    agree: dict[tuple, float] = {}  # paired group -> its cone's IoU with the masks (``iou``)
    memo = exits[0].get("cone_memo")

    def place(group, anchors, starts, single=False):
        """The strand of exits ``group``: its line starts along each of ``starts (k, 3)``
        through the middle of ``anchors (m, 3)`` (mm), whose extent along it is where the exits
        lie; None where the pith lies between them, or (``single``: the exits of one end) where
        the line is not long across the end or runs along the stem."""
        c0 = anchors.mean(axis=0)
        u, cone = starts[0], None
        if surface is not None:  # the strand of the cone the masks show
            others = [k for k in range(len(exits)) if k not in group]
            positive = np.concatenate([exits[k]["pixels"] for k in group])
            ignore = np.concatenate([exits[k]["pixels"] for k in others]) if others else np.zeros(0, int)
            r0 = float(np.mean([exits[k]["radius_mm"] for k in group]))
            cone = _fit_cone(surface, positive, ignore, c0, starts, r0, memo=memo, workers=workers)
            if iou and not single:  # only :func:`_pairings` asks (each fit once, not every round)
                agree[tuple(group)] = _cone_iou(_cone_problem(surface, positive, ignore, c0, r0), cone)
            # the radius along it as the masks show it, even thinning away from the pith: a branch
            # thickens outward (seed 003), but the masks pin the slope poorly and bounding it
            # moved the axis (FIT_VERSION 25, README "A knot seen at one corner")
            c0, u = cone[0], cone[1]
        tt = (anchors - c0) @ u
        start, dist = c0 + tt.min() * u, float(np.ptp(tt))
        if dist <= 0 or (single and (cone is None or
                                     dist < KNOT_END_MIN_SPAN_RADII * max(cone[2], KNOT_CONE_MIN_RADIUS_MM) or
                                     abs(u @ axis) > np.cos(np.deg2rad(KNOT_PAIR_MIN_ANGLE_DEG)))):
            return None
        # the line's stem years: a branch grows out of the pith, so it ends where they are least
        t = np.linspace(-length, dist + length, _LINE_SAMPLES)
        g = np.asarray(stem(start + t[:, None] * u), float)
        between = (t >= 0) & (t <= dist)
        if not between.any():  # the exits lie within one sample along the cone's axis: it runs
            return None  # across the line joining them, so they are not two ends of one knot
        if not np.all(np.isfinite(g)) or \
                g[between].min() < min(g[between][0], g[between][-1]) - KNOT_PITH_YEARS:
            return None  # the pith lies between the exits: two branches, not one
        lo_t, hi_t = -length, dist + length
        pith_first = bool(g[between][0] <= g[between][-1])
        if pith_first:  # the pith is beyond the first end: start there
            lo_t = float(t[t <= 0][np.argmin(g[t <= 0])]) - 1.0
        else:
            hi_t = float(t[t >= dist][np.argmin(g[t >= dist])]) + 1.0
        if cone is not None:  # the fitted cone's radius along the strand
            # kept exact in the middle of the exits; its slope only as far as keeps both far
            # ends within [lo, hi] (clipping each end alone would tilt the radius in the block)
            lo, hi = KNOT_CONE_MIN_RADIUS_MM, 2.0 * max(exits[k]["radius_mm"] for k in group)
            tm = 0.5 * dist
            r_mid = float(np.clip(cone[2] + cone[3] * ((start + tm * u - cone[0]) @ u), lo, hi))
            back, ahead = tm - lo_t, hi_t - tm  # > 0: the strand's ends behind and ahead
            slope = float(np.clip(cone[3], -min((hi - r_mid) / back, (r_mid - lo) / ahead),
                                  min((r_mid - lo) / back, (hi - r_mid) / ahead)))
            ra = r_mid - slope * tm
        else:
            # an oblique strand cuts a face in an ellipse of area pi R^2 / |cos(incidence)|
            ra, rb = (exits[k]["radius_mm"] * np.sqrt(max(abs(u @ np.asarray(FACE_NORMAL[exits[k]["face"]], float)),
                                                          0.2)) for k in (group[0], group[-1]))
            slope = (rb - ra) / dist
            lo, hi = 0.5 * min(ra, rb), 2.0 * max(ra, rb)

        def radius(at):  # the strand's radius at ``at`` mm along u from start
            return float(np.clip(ra + slope * at, lo, hi))

        if single and surface is not None:
            # seen at one end only: where the line comes out of the block away from the pith on a
            # photographed face whose mask shows no knot, the knot ends before that face (the
            # stem grew over it), as a one-exit ray does (:func:`_pith_ray`)
            near, far = (start + u * lo_t, start + u * hi_t) if pith_first else (start + u * hi_t, start + u * lo_t)
            stop = _clear_face_stop(near, far, lambda q: radius((q - start) @ u), size, surface)
            if stop is not None and (stop - c0) @ (far - near) > 0:  # beyond its own exits
                at = float((stop - start) @ u)
                lo_t, hi_t = (lo_t, at) if pith_first else (at, hi_t)
        return KnotStrand(tuple(start + u * lo_t), tuple(start + u * hi_t), radius(lo_t), radius(hi_t),
                          dead=all(exits[k]["dead"] for k in group))

    def pair(i, j, dist):
        return place(ends[i] + ends[j], np.stack([centres[i], centres[j]]), ((centres[j] - centres[i]) / dist)[None])

    used_ends, strands, paired = set(), [], []
    for _, dist, i, j, _ in pairs:
        if i in used_ends or j in used_ends:
            continue
        strand = pair(i, j, dist)
        if strand is not None:
            used_ends |= {i, j}
            strands.append(strand)
            paired.append((tuple(ends[i]), tuple(ends[j]), agree.get(tuple(ends[i] + ends[j]))))
    for i, end in enumerate(ends):
        # an unpaired end over two or more faces is a knot cut by a block edge or corner: the
        # cone that cuts both faces as the masks show is its strand, started along the samples'
        # principal axes and down the stem's year gradient (toward the pith)
        if i in used_ends or surface is None or len({exits[k]["face"] for k in end}) < 2:
            continue
        samples = surface[0][np.concatenate([exits[k]["pixels"] for k in end])]
        starts = list(np.linalg.svd(samples - samples.mean(axis=0), full_matrices=False)[2])
        n = -np.asarray(FACE_NORMAL[exits[end[0]]["face"]], float)
        d, _ = _toward_pith(stem, exits[end[0]]["centre_mm"] + n, n, length)
        if d is not None:
            starts.append(d)
        strand = place(end, samples, np.array(starts), single=True)
        if strand is not None:
            used_ends.add(i)
            strands.append(strand)
    # an exit near the pith may be two knots' of a whorl: an end left over pairs with a taken end
    # nearer the pith where their line passes it (module docstring)
    for _, dist, i, j, miss in pairs if rho is not None else ():
        if (i in used_ends) != (j in used_ends):
            near, far = (i, j) if i in used_ends else (j, i)
            if rho[near] < rho[far] and miss <= min(KNOT_SHARE_MAX_MISS_MM, KNOT_SHARE_MAX_MISS_SHARE * rho[near]) \
                    and (strand := pair(i, j, dist)) is not None:
                used_ends.add(far)
                strands.append(strand)
    used = {k for e in used_ends for k in ends[e]}
    lone = {}
    for k, e in enumerate(exits):
        if k in used:
            continue
        lone[k] = len(strands)
        if hasattr(stem, "pith_in_section_mm"):  # a branch from the pith through its exit (:func:`_pith_ray`)
            ray = _pith_ray(e, stem, size_mm, rises.get(k, 0.0), pinned=k in rises)
            if ray is not None:
                strands.append(ray)
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
    return strands, {"lone": lone, "ends": [tuple(e) for e in ends], "pairs": paired}


def _pith_ray(exit_: dict, stem, size_mm: ArrayLike, rise: float = 0.0, pinned: bool = False) -> KnotStrand | None:
    """The strand of a knot seen at one exit as the branch it is: from the pith (a
    :class:`~.stem.StemField`'s, in the exit's cross-section) out through the exit and on across
    the block of ``size_mm``, turned ``rise`` (rad) from the cross-section toward the pith's
    tangent (a branch rises or droops: seed 001's spruce ends its knots at -11 degrees, and a
    block may lie either way up). Its radius is the exit's, made round (an oblique strand cuts
    the face in an ellipse of area ``pi R^2 / |cos(incidence)|``). Where it would cross the
    block to a photographed face whose mask shows no knot where it comes out, the knot ends
    before that face (the stem grew over it): the strand stops where its surface would reach
    the face, the longest knot the photos allow. None where the exit lies within
    :data:`~woodcam.tolerances.KNOT_RAY_MIN_PITH_MM` of the pith (no direction to speak of),
    the ray would run along the face (:data:`~woodcam.tolerances.KNOT_MIN_ENTRY_COS`), or it
    would stop before it has crossed its exit.

    Why stop it rather than draw no ray (FIT_VERSION 18-21): the knot was then a guess along
    the exit face's normal that bends nothing, up to 40 degrees off a knot that runs most of the
    way across the block (dev seed 7777 block 6). Three noisy faces, dev seeds 7777, 63311, 9101
    and 21: 3 of 48 knotted blocks up by 7-28 points within 2 mm, none down; the knot ending
    half way there instead: one of them down (README).

    Why not down the stem's year gradient from the exit (the strand before): where the pith lies
    outside the block beyond the exit's face, that gradient leaves the block, and the face
    normal made across the stem stood in for it, up to 40 degrees off the knot (seed 64151
    block 22, three faces: 46 % within 2 mm; the ray through the exit 95 %)."""
    size = np.asarray(size_mm, float)
    c = np.asarray(exit_["centre_mm"], float)
    q = stem.pith_in_section_mm(c[None])[0]
    a = stem.grain_direction(q[None])[0]
    v = c - q
    v = v - (v @ a) * a
    rho = float(np.linalg.norm(v))
    if rho < KNOT_RAY_MIN_PITH_MM:
        return None
    w = np.cos(rise) * v / rho + np.sin(rise) * a
    n = -np.asarray(FACE_NORMAL[exit_["face"]], float)
    if abs(w @ n) < KNOT_MIN_ENTRY_COS:
        return None
    r = exit_["radius_mm"] * np.sqrt(abs(w @ n))
    start, end = c - rho / np.cos(rise) * w, c + float(np.linalg.norm(size)) * w
    if "surface" in exit_:
        stop = _clear_face_stop(start, end, lambda q: r, size, exit_["surface"], exit_mm=c)
        if stop is not None:
            end = stop
            if (end - c) @ w <= 0.0:
                return None
    return KnotStrand(tuple(start), tuple(end), r, r, dead=exit_["dead"], pinned=pinned)


def _clear_face_stop(start, end, radius, size, surface, exit_mm=None) -> np.ndarray | None:
    """(3,) where a knot on the line ``start`` -> ``end`` (mm, ``start`` the pith's side) ends
    because the block face it would come out of away from ``exit_mm`` (default: the end of its
    part inside the block) is photographed and its mask shows no knot there: one mask sample
    short of where the knot's surface, of radius ``radius(point (3,))`` mm, would reach that
    face (the mask shows a knot only to within a sample); None where it comes out on a face
    without a mask, or where the mask shows a knot, or it does not come out. ``surface``: the
    faces' mask samples ``(points (n, 3), knot (n,) bool)`` (:func:`knot_exits`)."""
    other = _far_end(start, end, start if exit_mm is None else exit_mm, size)
    if other is None:
        return None
    gap = np.minimum(np.abs(other), np.abs(size - other))  # mm from each pair of opposite faces
    if gap.min() > 1e-6:
        return None  # it ends inside the block
    pts, knot = surface
    r = radius(other)
    w = (end - start) / np.linalg.norm(end - start)
    ax = int(np.argmin(gap))  # the face it leaves by
    face = np.flatnonzero(np.abs(pts[:, ax] - other[ax]) < 1e-6)  # (not a neighbour's samples by the edge)
    seen = face[np.linalg.norm(pts[face] - other, axis=1) < max(r, 2.0 * KNOT_CONE_SAMPLE_MM)]
    if not len(seen) or knot[seen].any():
        return None
    cos_far = max(abs(w[ax]), KNOT_MIN_ENTRY_COS)
    return other - (r / cos_far + KNOT_CONE_SAMPLE_MM) * w


def _far_end(start, end, exit_mm, size) -> np.ndarray | None:
    """(3,) where the segment ``start`` -> ``end`` crosses the surface of the block ``[0, size]``
    away from ``exit_mm`` (the other end of its part inside), or None where that part ends
    inside the block (the pith is in it) or the segment misses the block."""
    d = end - start
    with np.errstate(divide="ignore", invalid="ignore"):
        t0, t1 = (0.0 - start) / d, (size - start) / d
    lo = np.nanmax(np.where(d != 0, np.minimum(t0, t1), -np.inf))
    hi = np.nanmin(np.where(d != 0, np.maximum(t0, t1), np.inf))
    lo, hi = max(lo, 0.0), min(hi, 1.0)
    if lo >= hi:
        return None
    a, b = start + lo * d, start + hi * d
    far = a if np.linalg.norm(a - exit_mm) > np.linalg.norm(b - exit_mm) else b
    return None if (far is a and lo == 0.0) else far


def _ray_misfit(field, obs, density) -> float:
    """Mean squared distance (mm², each capped at :data:`~woodcam.tolerances.KNOT_RAY_MISFIT_CAP_MM`)
    of ``obs``'s ring points from ``field``'s ring of their year; ``density (n,)``: the ring
    density (years/mm) there, the stem's (a bend changes it little; 7x cheaper than the field's)."""
    err = np.abs(np.asarray(field(obs.points_mm), float) - obs.years) / density
    return float(np.mean(np.minimum(err, KNOT_RAY_MISFIT_CAP_MM) ** 2))


def _pairings(exits, stem, size_mm, near: frozenset | None = None, workers: int = 1) -> list[frozenset]:
    """Other pairings of the knot ends than the order of :func:`_strands` whose cones cut the
    masks better: each the pairs to take first (``prefer``), the least :func:`_cone_iou` of
    its pairs' cones higher than the order's by :data:`~woodcam.tolerances.KNOT_PAIRING_MIN_IOU_GAIN`
    (a pairing is as good as its worst pair: one that makes a pair better by making another
    worse is no better). :func:`_fit_knotted_stem` keeps one where the rings say so too.

    Why: that order (pairs whose line passes the pith first, then the nearest ends) knows
    nothing of which ends look like one knot, and it can cross two knots. Dev seed 9101 block 5
    (six noisy faces, the pith 13-16 cm away, so every pair is ordered by distance): two knots
    from the left face, one out by the right face, one by the bottom-right edge; the nearest
    ends first paired each left exit with the other's far end, and the bend round the two
    crossed strands scored 60.9 % within 2 mm, the pairs exchanged 93.9 % (cone IoU 0.80 / 0.96
    against 0.97 / 0.90).

    The pairings tried: two pairs of the order exchanging partners (either way), or one end of
    a pair taking an end the order left unpaired. ``near``: the pairing the all-faces fit chose
    (a fold: :func:`knot_bend_recipes`), the only one tried, as a fold's rises are searched
    near the all-faces fit's."""
    if near is not None and not near:  # a fold of a fit that kept the order: nothing to try
        return []
    _, info = _strands(exits, stem, size_mm, True, workers, iou=True)
    base = info["pairs"]
    if near is not None:
        alts = [near]
    else:
        alts = []
        for (a, b, _), (c, d, _) in itertools.combinations(base, 2):
            alts += [frozenset({frozenset((a, c)), frozenset((b, d))}),
                     frozenset({frozenset((a, d)), frozenset((b, c))})]
        paired = {e for q in base for e in q[:2]}
        for a, b, _ in base:
            alts += [frozenset({frozenset((x, e))}) for x in (a, b) for e in info["ends"] if e not in paired]

    def worst(pairs):  # the least IoU of the pairs' cones with their masks
        return min((q[2] for q in pairs), default=0.0)

    seen, least, better = [{frozenset(q[:2]) for q in base}], worst(base) + KNOT_PAIRING_MIN_IOU_GAIN, []
    for alt in alts:
        got = _strands(exits, stem, size_mm, True, workers, prefer=alt, iou=True)[1]["pairs"]
        if (pairs := {frozenset(q[:2]) for q in got}) not in seen:  # another pairing, tried once
            seen.append(pairs)
            if worst(got) >= least:
                better.append(alt)
    return better


def _ray_rises(exits, stem, obs, size_mm, cones: bool, seed: int,
               near: dict[int, float] | None = None, workers: int = 1,
               prefer: frozenset = frozenset()) -> dict[int, float]:
    """exit index -> rise (rad) of each knot seen at one exit whose ray from the pith
    (:func:`_pith_ray`) bends the rings: per such knot in turn, of the rises
    :data:`~woodcam.tolerances.KNOT_RAY_RISES_DEG` (then the vertex of the parabola through the
    best and its neighbours) and no bend at all, the one whose bend, with the stem refitted to
    it once, leaves the least misfit on the rings (:func:`_ray_misfit`).

    Why: the exit shows where a knot crosses the face and the pith where it starts, but not
    its rise, and 10-20 degrees off puts its bend 1-2 cm off across a block (dev seeds 7777 and
    63311, three noisy faces, knotted blocks within 2 mm: the ray across the stem 63.7 %, the
    true knot's direction through the exit 76.5 %); the rings round the exit, on its face and
    the others, are bent by where the knot really runs. The stem's fit absorbs a knot's bend
    into itself, so each rise is judged after the stem is refitted to it (without that, no bend
    always won), by a quick refit (:data:`~woodcam.tolerances.KNOT_RAY_REFIT_POINTS`).

    ``near``: rises found on more rings (a fold's fit starts from the all-faces fit's, as its
    stem does: :func:`knot_bend_recipes`): only those knots are tried, each at its rise and one
    step of the grid either side. Why: every fold searching afresh took seed 31337 block 15 (six
    faces, five knots seen at one exit) from 7.3 to 20.4 s wall. ``workers``: processes each
    knot's cone starts may use (:func:`_fit_cone`). ``prefer``: the ends' pairing
    (:func:`_pairings`)."""
    from .stem import fit_stem

    rises: dict[int, float] = {}
    full = np.deg2rad(KNOT_RAY_RISES_DEG)
    strands, info = _strands(exits, stem, size_mm, cones, workers, prefer=prefer)
    lone = info["lone"]
    made: dict = {}

    def ray(k, rise):  # knot k's pinned ray at ``rise``, made once (the check below, then its cost)
        if (k, rise) not in made:
            made[(k, rise)] = _pith_ray(exits[k], stem, size_mm, rise, pinned=True)
        return made[(k, rise)]

    # a knot with a ray at any rise of the grid: one drooping 20 degrees may have none across the
    # stem (it would run along its exit face)
    lone = {k: i for k, i in lone.items() if (near is None or k in near)
            and any(ray(k, float(r)) is not None for r in full)}
    if not lone:
        return rises
    g0, grad = central_gradient(stem, obs.points_mm, 0.25)
    density = np.maximum(np.linalg.norm(grad, axis=1), 1e-6)

    def cost(k=None, rise=0.0):  # the misfit with knot k's ray at ``rise`` (None: as they are)
        trial = list(strands)
        if k is not None:
            trial[lone[k]] = ray(k, rise)
            if trial[lone[k]] is None:  # no ray at that rise (along the face, or out by a face showing none)
                return np.inf
        bent = StemWithKnots(stem, trial, bend=KnotParams())
        # every arm refitted alike, no bend too (the stem given was fitted in full: the quick
        # refit would start behind it); the quick refit: what the comparison needs, not a fit
        refit = fit_stem(obs, size_mm, seed=seed, offset_years=bent(obs.points_mm) - g0, init=stem, history=False,
                         n_fit=KNOT_RAY_REFIT_POINTS)
        return _ray_misfit(StemWithKnots(refit, trial, bend=KnotParams()), obs, density)

    now = cost()
    for k in lone:
        grid = full if near is None else near[k] + np.array([-1.0, 0.0, 1.0]) * (full[1] - full[0])
        costs = np.array([cost(k, float(rise)) for rise in grid])
        i = int(np.argmin(costs))
        best, rise = costs[i], float(grid[i])
        if 0 < i < len(grid) - 1:  # the parabola's vertex through the best and its neighbours
            c0, c1, c2 = costs[i - 1:i + 2]
            h = 0.5 * (grid[i + 1] - grid[i - 1])
            if np.isfinite(c0 + c2) and c0 + c2 - 2.0 * c1 > 0:
                step = float(np.clip(0.5 * h * (c0 - c2) / (c0 + c2 - 2.0 * c1), -0.5 * h, 0.5 * h))
                if step and (c := cost(k, rise + step)) < best:
                    best, rise = c, rise + step
        if best < now:  # this knot's bend fits the rings better than without it
            rises[k], now = rise, best
            strands[lone[k]] = ray(k, rise)
    return rises


def fit_knotted_stem(obs: RingObservations, size_mm: ArrayLike, exits: list[dict],
                     rounds: int = KNOT_BEND_ROUNDS, seed: int = 0, guessed: bool = False,
                     stem: StemField | None = None, cones: bool = False) -> StemWithKnots | StemField:
    """The stem model with the rings bent round its knots (seed 003's join), fitted jointly:
    ``StemWithKnots(stem, strands, bend=KnotParams())``, or the plain stem when no strand bends.

    obs : labelled ring observations (block frame, mm); size_mm : (3,) block size; exits : the
    block's knot exits (:func:`knot_exits`, from the masks); guessed : also bend round strands
    guessed from one exit (``pinned=False``); stem : the plain :func:`~.stem.fit_stem` of
    ``obs`` when already fitted; cones : strands from the cones fitted to the masks
    (:func:`strands_from_exits`).

    A knot lowers the growth time of the stem round it far beyond its surface (seed 003's power
    smooth minimum with its distance ranges: about a year at twice the knot radius, 15 years
    from the pith), so the faces' rings near an exit are bent and a stem fitted to them is
    bent too. Fixed point: fit the stem, place the strands in it, and refit the stem to the
    years minus the bend the knots put there (``fit_stem(offset_years=..., init=...)``),
    ``rounds`` times (dev seed 21, six noisy faces, within 1 mm: 0 rounds 40 / 29 / 36 %, 1
    round 97 / 53 / 97 %, 2 rounds 99 / 68 / 98 %, 4 rounds 99 / 74 / 98 % on blocks 1 / 9 / 10).
    The bend is a share of the time since the pith, so where the given stem's growth time falls
    away from its pith the fixed point starts from ``fit_stem(outward=True)`` (FIT_VERSION 23;
    dev seed 9101 block 5, six faces: the bend had been left out, 59.3 -> 64.7 % within 2 mm).

    The strands that bend the rings: those pinned by two exits, and each knot seen at one exit
    whose ray from the pith, at the rise the rings choose, fits them better than no bend at all
    (:func:`_ray_rises`, in the first round's stem; FIT_VERSION 18). Before, a one-exit strand
    ran down the stem's years from its exit, a few mm to cm off its knot, and its bend wrote
    wrong years over a wide region (dev seed 21, three faces: block 10 45 -> 25 %, block 5 86
    -> 43 % within 1 mm), so only pinned strands bent the rings; the ray with its rise read
    from the rings bends them where the rings say so (dev seeds 7777 and 63311, three noisy
    faces, the default fit within 2 mm: 62.8 -> 67.7 %, README "A knot seen at one exit").
    Knot ends are paired in the order of :func:`strands_from_exits`, or (FIT_VERSION 26) as
    another pairing whose cones cut the masks better (:func:`_pairings`) where the fixed point
    with it leaves less misfit on the rings, by the share
    :data:`~woodcam.tolerances.KNOT_PAIRING_MIN_MISFIT_GAIN` (:func:`_ray_misfit`, each
    pairing's bend fitted in full: a quick refit from the first round's stem, as the rises are
    judged, preferred the crossed pairs of dev seed 9101 block 5, 2.98 against 3.51 mm², where
    the fixed point gives 0.83 against 0.57). Both are asked because either alone chose wrong
    pairs on the development blocks: the rings alone were worse in 4 of the 7 blocks where they
    preferred another pairing (24683/16 83.7 -> 38.1 % within 2 mm, whose other cone cut its
    masks at IoU 0.72 against 0.92); the masks alone by a hair (57131/19).
    ``guessed=True`` (a separate hypothesis the held-out faces judge) bends round every strand. Strands that do not
    bend are kept for the knot's look (:meth:`StemWithKnots.knot_features`). A dead strand bends
    as an alive one: the branch was alive from the pith to its death, which the exits do not
    show, and the bend comes from that inner part (its inversion past death is left out).
    """
    return _fit_knotted_stem(obs, size_mm, exits, rounds, seed, guessed, stem, cones)[0]


def _fit_knotted_stem(obs, size_mm, exits, rounds, seed, guessed, stem, cones=False, near=None, workers=1,
                      near_pairing=None):
    """:func:`fit_knotted_stem`, whether every round placed pinned strands only (then the fit
    with ``guessed=True`` would make the very same steps), the rises of the rays that bend
    (:func:`_ray_rises`, ``near`` passed on) and the pairing of the knot ends it kept (the
    ``prefer`` of :func:`strands_from_exits`; ``near_pairing`` is :func:`_pairings`' ``near``);
    ``workers``: processes each cone's starts may use."""
    from .stem import fit_stem

    def falls(s, g):  # times are not "from the pith" in stem s (g: its years at the rings)
        return np.mean(g <= s.pith_years()) > KNOT_BEND_MAX_BEFORE_PITH

    stem = fit_stem(obs, size_mm, seed=seed) if stem is None else stem
    plain, g = stem, stem(obs.points_mm)
    if falls(stem, g):
        # the pith beyond the rings' side of most years (a far pith's straight rings fit
        # either way): the bend starts from the stem whose growth time rises away from it
        stem = fit_stem(obs, size_mm, seed=seed, outward=True, workers=workers)
        g = stem(obs.points_mm)
    if falls(stem, g):
        return plain, False, {}, frozenset()  # no bend to speak of

    def bend(pairing):  # the fixed point with the knot ends paired as ``pairing`` prefers
        s, field, only_pinned, rises = stem, plain, True, None
        for r in range(rounds + 1):
            g = s(obs.points_mm)  # once per round: the check here and the bend's offset below
            if r and falls(s, g):
                return plain, False, {}
            if rises is None:  # the rises of the knots seen at one exit, in the first round's stem
                rises = _ray_rises(exits, s, obs, size_mm, cones, seed, near, workers, pairing)
            strands = strands_from_exits(exits, s, size_mm, cones, workers, rises=rises, prefer=pairing)
            only_pinned &= all(x.pinned for x in strands)
            if not any(x.pinned or guessed for x in strands):
                return plain, False, rises
            field = StemWithKnots(s, strands, bend=KnotParams(), bend_guessed=guessed)
            if r == rounds:
                break
            s = fit_stem(obs, size_mm, seed=seed, offset_years=field(obs.points_mm) - g, init=s)
        return field, only_pinned, rises

    field, only_pinned, rises = bend(frozenset())
    pairing: frozenset = frozenset()
    alts = _pairings(exits, stem, size_mm, near_pairing, workers) \
        if cones and exits and "surface" in exits[0] and isinstance(field, StemWithKnots) else []
    if alts:  # another pairing whose cones cut the masks better: kept where the rings fit it better too
        density = np.maximum(np.linalg.norm(central_gradient(stem, obs.points_mm, 0.25)[1], axis=1), 1e-6)
        limit = (1.0 - KNOT_PAIRING_MIN_MISFIT_GAIN) * _ray_misfit(field, obs, density)
        for alt in alts:
            got = bend(alt)
            if isinstance(got[0], StemWithKnots) and (cost := _ray_misfit(got[0], obs, density)) < limit:
                limit, (field, only_pinned, rises), pairing = cost, got, alt
    return field, only_pinned, rises, pairing


def _memo_copy(memo: dict) -> dict:
    """A copy of a cone memo (:func:`_fit_cone`) that fits added to it leave the original as it
    was: its lists copied, the fits they hold shared (never changed)."""
    return {k: list(v) for k, v in memo.items()}


def knot_bend_recipes(size_mm: ArrayLike, exits: list[dict], seed: int = 0, guessed: bool = False,
                      cones: bool = False, residual: bool = True,
                      workers: int | None = None) -> tuple[Callable, dict[str, Callable], dict[str, str]]:
    """Evidence hypotheses of the knots' bend: ``(stem, recipes, refines)``.

    ``recipes``, name -> ``RingObservations -> field``, is :func:`fit_knotted_stem` on the given
    rings (the exits come from the masks, not from the rings a fold holds out):
    ``"stem + knot bend"`` (strands pinned by two exits or rays whose rise the rings chose), with ``residual``
    ``"stem + knot bend + residual"`` (the same with a smoothed thin-plate RBF of what it leaves
    on the faces, as ``"radial + residual"`` on the radial fit; :func:`~.fit.fit_block` offers
    it where :data:`~woodcam.tolerances.KNOT_BEND_RESIDUAL_MIN_FACES` faces carry rings) and,
    with ``guessed``, ``"stem + guessed knot bend"`` (every strand). ``refines``, name -> base,
    marks the bends as refinements of ``"stem"`` (:attr:`~.evidence.Hypothesis.refines`); the
    bend with its residual competes as a plain hypothesis.

    Why the residual: the stem model bent by the cones cannot follow the rings within a knot
    radius or two of an exit, where the generator's curved strand, its growing radius and its
    death bend them (seed 35089, six noisy faces, block 18: the bend fits its own faces' ring
    points at 47 % where the truth's own field reaches 93 %), so its held-out faces score low
    (50 %, 39 % from cold fold starts, below) although its inside is the best of all (81 % within
    2 mm against the chosen 62 %). The residual takes the faces' misfit and leaves the bend's
    inside; on 35089's blocks 2, 6, 14 and 18 its held-out evidence was the best and its inside
    98 / 85 / 78 / 90 % against the chosen 63 / 77 / 59 / 62 % (README, "The knots' bend with a
    residual").

    Fold fits: the first rings a recipe is given are all the faces' (:func:`~.evidence.
    fit_evidence` fits every hypothesis on them before the folds), and each fold's bend starts
    from that fit's stem, placed by the fold's faces (``fit_stem(init=, offset_years=)`` with
    the first fit's bend), as a radial basin's fold descends from its own axis; from the fold's
    plain stem instead, a knot-distorted stem in another basin, the bend's held-out faces fell
    (35089/18: 49.9 -> 39.3 %). Its rays likewise start from the all-faces fit's rises
    (:func:`_ray_rises` ``near``): the fold's rings choose among each such rise and one grid step
    either side, or no bend; and its cones from the all-faces fit's (a fold's own cone fits are
    its own), so that no fold depends on which folds came before it or where they ran: the folds
    are refitted in forks (:func:`~.evidence.holdout_evidence`). The guessed one is left out by default
    (:func:`~.fit.fit_block` does not offer it): a strand guessed from one exit is a few mm to
    cm off its knot, and with three faces, where most knots show one exit, its bend lost more
    than it gained (seed 61297, three noisy faces, knotted: 52.4 -> 50.0 % within 1 mm; dev seed
    9101 block 0: 60.9 -> 51.3); with six faces it was never needed (dev seeds 9101 and 21: the
    same choices and scores without it). ``stem`` is the plain stem's recipe (:func:`~.stem.fit_stem`)
    remembering its last fit: passed as the evidence fit's stem hypothesis
    (:func:`~.evidence.fit_evidence`'s ``stem``), each fold's stem is fitted once for all of them.
    ``workers``: processes the stem's start search and each cone's starts may use (default
    :func:`woodcam._parallel.fit_workers`; inside a forked fold they run serially).
    """
    from .._parallel import fit_workers
    from ..tolerances import EVIDENCE_RBF_POINTS
    from .evidence import _residual_recipe, stem_recipe

    cores = fit_workers() if workers is None else int(workers)
    plain = stem_recipe(size_mm, seed, cores)  # remembers its last fit: one stem per fold for all

    bent: dict = {}

    def fold_exits():
        """The exits with the cone fits of the all-faces fit only (a copy of them per fold): a
        fold's cones never depend on which folds were fitted before it, nor where (the folds
        run in forks, :func:`~.evidence.holdout_evidence`)."""
        if "memo" not in bent:  # the first, all-faces fit: its cones are remembered for all
            return exits
        memo = _memo_copy(bent["memo"])
        return [{**e, "cone_memo": memo} for e in exits]

    def pinned(obs):
        if bent.get("obs") is not obs:
            first = bent.get("first")
            warm = isinstance(first, StemWithKnots)  # a fold: start in the all-faces bend's basin
            if warm:
                from .stem import fit_stem

                off = first(obs.points_mm) - first.stem(obs.points_mm)
                start = fit_stem(obs, size_mm, seed=seed, offset_years=off, init=first.stem)
            field, same, rises, pairing = _fit_knotted_stem(obs, size_mm, fold_exits(), KNOT_BEND_ROUNDS, seed, False,
                                                            start if warm else plain(obs), cones, bent.get("rises"),
                                                            cores, bent.get("pairing"))
            if warm:
                same = False  # the guessed bend starts from the plain stem: not the same steps
                if not isinstance(field, StemWithKnots):  # no bend in this fold: the plain stem's
                    field = plain(obs)
            bent.update(obs=obs, field=field, same=same)
            if "first" not in bent:  # the all-faces fit: what every fold starts from (its stem,
                # the rises of its rays and its cones)
                bent.update(first=field, rises=rises, pairing=pairing,
                            memo=_memo_copy(exits[0].get("cone_memo") or {}))
        return bent["field"]

    def bent_guessed(obs):
        if bent.get("obs") is obs and bent["same"]:  # no strand was a guess: the same fit
            return bent["field"]
        return fit_knotted_stem(obs, size_mm, fold_exits(), seed=seed, guessed=True, stem=plain(obs), cones=cones)

    out, refines = {}, {}
    if exits:  # a strand pinned by exits on two faces, or a ray from the pith the rings place
        out["stem + knot bend"], refines["stem + knot bend"] = pinned, "stem"
        if residual:
            out["stem + knot bend + residual"] = _residual_recipe(pinned, EVIDENCE_RBF_POINTS)
    if exits and guessed:
        out["stem + guessed knot bend"], refines["stem + guessed knot bend"] = bent_guessed, "stem"
    return plain, out, refines


def with_knots(block, stem, faces=None, cones: bool = False, exits: list[dict] | None = None,
               workers: int | None = None):
    """``(field, strands)``: ``stem`` with the masked knots joined in, or ``stem`` unchanged.
    ``exits``: the block's :func:`knot_exits` where already found (their cone fits are
    remembered with them: the strands of a chosen field reuse the folds' cones). ``workers``:
    processes a cone's starts may use (default :func:`woodcam._parallel.fit_workers`; where
    no fold fitted the cones, e.g. no knot is pinned by two faces, they are fitted here)."""
    from .._parallel import fit_workers
    from .._threads import one_blas_thread

    exits = knot_exits(block, faces) if exits is None else exits
    with one_blas_thread():  # as inside the evidence fit, whose folds fitted the cones it reuses
        strands = strands_from_exits(exits, stem, block.size_mm, cones,
                                     fit_workers() if workers is None else int(workers))
    return (StemWithKnots(stem, strands) if strands else stem), strands


__all__ = ["exit_is_dead", "fit_knot_strands", "fit_knotted_stem", "knot_bend_recipes", "knot_exits",
           "strands_from_exits", "with_knots"]
