"""Fit the generic neural growth field to a block's rings: eq. 5 of seed 000, with or without years.

    argmin_{c, T, a}  sum_k | f_theta(c, gamma(T(x_k))) - (g_k - a) |_1 + w_reg |c|^2     (eq. 5)

``x_k`` are traced ring points on the block faces (block frame, mm) with years ``g_k``; ``f_theta``
is the generic model of :mod:`woodcam.fields.neural`, whose output is in normalised growth units
(radius units of its ``[-1, 1]^3`` trunk domain). The cut-out transform ``T`` here is

    q = exp([w]) R0 (x - P0) / L + t          (normalised trunk coordinates, pith on z)

with the coarse pith line ``(P0, R0)`` and domain length ``L`` (mm per unit, chosen so the block
sits inside the domain) from the grid search, and ``t`` (3,), ``w`` (axis-angle, 3,) refined by
Adam. The seed's relative scale ``s`` appears as the output scale ``K`` (years per normalised
unit): years = ``a + K f``. Scaling the input by ``s`` and the output by ``K`` are the same for the
family's fields (``rho / r'`` is homogeneous in ``rho``); scaling the output keeps the block inside
the trained domain whatever its ring width.

Two steps, as in §3.2.3: (1) ``c = 0``, grid search over the pith direction (3 block axes, 6 face
diagonals, 4 body diagonals) and the pith position in the cross-section (a square grid of
offsets out to several block radii), with ``K`` and the integer ``a`` solved in closed form per
candidate; (2) ``a`` fixed, Adam over ``c, t, w, log K``.

Unlabelled rings (traces without years, Mokume-style ring maps; ``labels="none"`` or ``"auto"``
without enough years) are fitted in three steps:

1. *Numbering.* The ring points of :func:`woodcam.inference.gather_observations` (traces, else
   ring-map components) are fitted by the radial fitter, which numbers unlabelled rings from their
   spacing (:func:`woodcam.inference.radial.number_rings`); its field rounded at each point is
   that point's year. Per point rather than per group, so a ring-map component that merges two
   rings gets both; points the radial field leaves more than ``_NUMBER_CONFIDENCE`` from an
   integer sit out this step.
2. *Labelled start.* Eq. 5 as above on the numbered points, with the radial fitter's pith line
   in place of the grid search (Adam).
3. *Year-free refinement.* L-BFGS over ``c, t, w, log K`` and a phase ``b`` (``years = a + b + K f``;
   ``b`` lets a real pith sit between rings) on a loss that needs no year numbers::

       L = mean_ring sin^2(pi y) + w_gap mean_gap cos^(2p)(pi y) + w_K (log K - log K_0)^2 + w_reg |c|^2

   ``sin^2(pi y)`` pulls ring points to *some* integer (smooth, ~ (pi d)^2 for a distance ``d``
   to the nearest integer, and bounded, so a spurious ring pixel costs at most 1). The gap term
   pushes points *between* rings away from integers; ``cos^(2p)`` with ``p = _GAP_POWER`` is
   peaked (0.06 at a quarter year from an integer), so it acts only on gap points that drift
   close to a ring and leaves the ring positions to the ring term. Gap points are the midpoints
   from each ring point to the nearest point of another ring group on the same face (for traces
   and ring maps alike, so knots masked out of the ring points are masked here too), kept where
   the numbered start is at least ``_GAP_MIN_PHASE`` from an integer: that drops midpoints
   between two pieces of one ring and those on a ring missing from the map.

   Degenerate solutions and the guards. A periodic ring loss alone is minimised by (i) a field
   flattened or stretched so that every point sits near one integer (``K -> 0``), and (ii) a
   field with ``n`` times the ring density (``K -> n K``: the rings land on every n-th integer,
   extra rings appear between them). Both put the gap points on integers, which the gap term
   charges (up to ``w_gap`` per point against the ring term's gain of at most 1, so with
   ``w_gap >= 1`` neither is a minimum). The start comes from the numbered labelled fit, so the
   refinement is local; the weak penalty ``w_K (log K - log K_0)^2`` keeps ``K`` from drifting
   where few rings pin it (a 10 % drift costs 0.01, the ring term of a 0.03-year misfit).
   Without any gap point (a single ring group per face) the numbered start is kept unrefined.
   Measured on an eq. 7-9 block (tests): started from a field of twice the ring density (every
   ring on an even integer) the ring term alone stays there (a minimum: rings fit as well as
   the truth), with the gap term it leaves (the refinement is local: it does not reach the
   right density from there, the numbering has to); from the numbered fit the ring density
   stays within 5 % of the truth.

Measured (eq. 7-9 blocks 100-107 of ``tests/inference/_eq79_blocks.py``, 50 mm cubes at 5 px/mm;
Table-1 share of predicted ring-line points within 1 mm of a true ring line, any year, mean over
the 8 blocks): year-labelled traces 76.6 % with the seed's grid start, 98.0 % with
``start="radial"``; the same traces without years 98.8 %; ring maps only 98.6 %. CPU time of an
unlabelled fit (one torch thread) 6.5-7.0 s mean, 8.4 s at most; the Mokume cubes CN03 / H11
(256 px ring maps) 9.0 / 8.4 s. The radial numbering takes 2.5-5 s of that.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Literal, get_args

import numpy as np

from ..errors import WoodcamError, require
from ..fields.grid import GridField

#: Grid-search pith offsets, in block cross-section radii (both in-plane directions).
_OFFSETS = np.array([0.0, 0.5, 1.2, 2.5, 5.0])
_OFFSETS = np.concatenate([-_OFFSETS[:0:-1], _OFFSETS])
#: Share of the domain half-width the block may fill (the net was trained on [-1, 1]^3).
_DOMAIN_FILL = 0.95
#: Trace points used in the grid search / the Adam refinement (random subsets, fixed seed).
_GRID_POINTS = 128
_ADAM_POINTS = 1000
#: Adam learning rates (code: latent units; pose: normalised units and radians; scale: log K),
#: decayed by a cosine to 5 %.
_LR_CODE, _LR_POSE, _LR_SCALE = 3e-2, 1e-2, 1e-2
#: Grid placements refined by a trial Adam run of steps // _TRIAL_SHARE steps; the best trial
#: gets the full run (see _fit_labelled).
_STARTS = 4
_TRIAL_SHARE = 4

Labels = Literal["auto", "years", "none"]
Start = Literal["grid", "radial"]

#: Year-free refinement (module docstring): L-BFGS iterations, gap-term weight and sharpness,
#: log-K drift weight. The labelled start of an unlabelled fit runs this share of ``steps``
#: (the year-free refinement finishes it; 150 vs 300 start steps gave the same final misfit).
_YEAR_FREE_STEPS = 60
_W_GAP = 1.0
_GAP_POWER = 4
_W_SCALE = 1.0
_START_STEPS_SHARE = 0.5
#: Numbered ring points farther than this (years) from an integer of the radial field are left
#: out of the labelled start; gap points nearer than _GAP_MIN_PHASE to an integer of the start
#: are dropped (a ring missing from the map or the tracing runs there).
_NUMBER_CONFIDENCE = 0.35
_GAP_MIN_PHASE = 0.2


@dataclass
class NeuralBlockField:
    """A decoded generic field placed in a block: ``(n, 3) block mm -> (n,) years``.

    ``years = age_offset + scale * f_theta(code, rotation @ (x - origin_mm) / length_mm + shift)``.
    """

    net: object
    code: np.ndarray          # (latent_dim,)
    rotation: np.ndarray      # (3, 3), rows: trunk x, y, z (pith) axes in the block frame
    origin_mm: np.ndarray     # (3,) block-frame point mapped to the trunk origin (before shift)
    length_mm: float          # mm per normalised unit
    shift: np.ndarray         # (3,) normalised units
    scale: float              # years per normalised unit (K)
    age_offset: float         # a, integer-valued years at the pith

    @property
    def axis(self) -> np.ndarray:
        """Pith direction in the block frame, (3,) unit."""
        return np.asarray(self.rotation[2], float)

    @property
    def pith_point_mm(self) -> np.ndarray:
        """A block-frame point on the pith line (where the trunk ``x = y = 0``, ``z = 0``)."""
        return self.origin_mm - self.length_mm * (self.rotation.T @ self.shift)

    def to_trunk(self, points_mm) -> np.ndarray:
        p = np.asarray(points_mm, float)
        return np.einsum("ij,nj->ni", self.rotation, p - self.origin_mm) / self.length_mm + self.shift

    def __call__(self, points_mm) -> np.ndarray:
        torch = require("torch", "learn", "the neural growth field")
        q = self.to_trunk(points_mm).astype(np.float32)
        code = torch.as_tensor(np.asarray(self.code, np.float32))
        out = np.empty(len(q))
        with torch.no_grad():
            for i in range(0, len(q), 65536):
                out[i:i + 65536] = self.net(code, torch.from_numpy(q[i:i + 65536])).double().numpy()
        return self.age_offset + self.scale * out


@dataclass
class NeuralFit:
    """Everything :func:`fit_neural_details` found.

    ``loss_years``: labelled fits, the final mean ``|field - year|`` at the traced points;
    year-free fits, the final mean distance of the field to the nearest integer at the ring
    points (``labelled_loss_years`` holds that before the year-free refinement).
    """

    field: NeuralBlockField
    grid: GridField
    loss_years: float          # see above, years
    grid_loss_years: float     # mean |residual| after the grid search (c = 0), years
    n_points: int              # ring points used
    time_s: float
    mode: str = "years"        # "years" (eq. 5) or "year-free"
    labelled_loss_years: float | None = None   # year-free: phase loss of the numbered start
    ring_points_mm: np.ndarray | None = None   # year-free: (n, 3) ring points, block frame
    gap_points_mm: np.ndarray | None = None    # year-free: (m, 3) points between rings used


def _rotation_to(axis: np.ndarray) -> np.ndarray:
    """(3, 3) rotation whose last row is ``axis`` (unit), first row a fixed perpendicular."""
    z = axis / np.linalg.norm(axis)
    ref = np.array([1.0, 0, 0]) if abs(z[0]) < 0.9 else np.array([0, 1.0, 0])
    x = ref - z * (ref @ z)
    x /= np.linalg.norm(x)
    return np.stack([x, np.cross(z, x), z])


def _directions() -> np.ndarray:
    """13 pith directions: block axes, face diagonals, body diagonals (sign is irrelevant).
    (48 more spread over the hemisphere doubled the fit time and changed no benchmark block.)"""
    d = [(1, 0, 0), (0, 1, 0), (0, 0, 1),
         (1, 1, 0), (1, -1, 0), (1, 0, 1), (1, 0, -1), (0, 1, 1), (0, 1, -1),
         (1, 1, 1), (1, 1, -1), (1, -1, 1), (-1, 1, 1)]
    d = np.array(d, float)
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def _corners(size) -> np.ndarray:
    return np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], float) * size


def _resolve_model(model):
    from ..fields.neural import load_model

    if model is None:
        return load_model()
    if isinstance(model, (str, Path)):
        return load_model(model)
    if isinstance(model, tuple) and len(model) == 2:
        return model
    raise WoodcamError(f"model must be None (the packaged model), a model folder or a (net, spec) "
                       f"tuple from woodcam.fields.neural.load_model; got {type(model).__name__}")


def _solve_scale_offset(f: np.ndarray, g: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per candidate row: ``g ~ a + K f`` with integer ``a`` and ``K > 0``, L1 score.

    Least squares for ``(K, a)``, ``a`` rounded, ``K`` refitted with ``a`` fixed; candidates with
    ``K <= 0`` (years decreasing outward) score ``inf``. f : (m, n), g : (n,) -> (K, a, score) (m,).
    """
    fm = f.mean(axis=1, keepdims=True)
    gm = g.mean()
    var = ((f - fm) ** 2).sum(axis=1)
    k = ((f - fm) * (g - gm)).sum(axis=1) / np.maximum(var, 1e-12)
    a = np.round(gm - k * fm[:, 0])
    k = (f * (g - a[:, None])).sum(axis=1) / np.maximum((f * f).sum(axis=1), 1e-12)
    score = np.abs(a[:, None] + k[:, None] * f - g).mean(axis=1)
    score[~(k > 0)] = np.inf
    return k, a, score


def _rodrigues(torch, w):
    """Rotation matrix of the axis-angle vector ``w`` (3,), differentiable at 0."""
    theta2 = (w * w).sum()
    theta = torch.sqrt(theta2 + 1e-20)
    kx = torch.zeros(3, 3, dtype=w.dtype)
    kx = torch.stack([torch.stack([kx[0, 0], -w[2], w[1]]),
                      torch.stack([w[2], kx[0, 0], -w[0]]),
                      torch.stack([-w[1], w[0], kx[0, 0]])])
    # sin(t)/t and (1 - cos t)/t^2 with their Taylor limits near 0
    a = torch.where(theta < 1e-4, 1 - theta2 / 6, torch.sin(theta) / theta)
    b = torch.where(theta < 1e-4, 0.5 - theta2 / 24, (1 - torch.cos(theta)) / (theta2 + 1e-20))
    return torch.eye(3, dtype=w.dtype) + a * kx + b * (kx @ kx)


def fit_neural_details(block, *, model=None, faces=None, steps: int = 300, seed: int = 0,
                       progress: bool = False, spacing_mm: float | None = None,
                       threads: int = 1, labels: Labels = "auto",
                       year_free_steps: int = _YEAR_FREE_STEPS, start: Start = "grid") -> NeuralFit:
    """Fit eq. 5 (labelled) or the year-free loss (unlabelled) to ``block``; see :func:`fit_neural`
    (this returns more)."""
    torch = require("torch", "learn", "fitting the neural growth field")
    from .._threads import torch_threads

    with torch_threads(torch, threads):
        return _fit(torch, block, model, faces, steps, seed, progress, spacing_mm, labels,
                    year_free_steps, start)


def _check_steps(name: str, steps) -> int:
    if not isinstance(steps, (int, np.integer)) or isinstance(steps, bool) or steps < 0:
        raise WoodcamError(f"{name} must be an integer >= 0; got {steps!r}")
    return int(steps)


def _fit(torch, block, model, faces, steps, seed, progress, spacing_mm, labels,
         year_free_steps, start) -> NeuralFit:
    t_start = time.perf_counter()
    steps = _check_steps("steps", steps)
    year_free_steps = _check_steps("year_free_steps", year_free_steps)
    if labels not in get_args(Labels):
        raise WoodcamError(f"labels must be one of {', '.join(get_args(Labels))}; got {labels!r}")
    if start not in get_args(Start):
        raise WoodcamError(f"start must be one of {', '.join(get_args(Start))}; got {start!r}")
    name = getattr(block, "name", "?")
    pts, yrs = block.trace_points_mm(faces)
    ok = np.isfinite(yrs)
    pts, yrs = pts[ok], yrs[ok]
    enough = len(pts) >= 10 and len(np.unique(yrs)) >= 2
    if labels == "years" and not enough:
        raise WoodcamError(
            f"block {name!r}: fitting with labels='years' needs year-labelled ring traces with "
            f"at least 2 different years and 10 points; got {len(pts)} labelled points with "
            f"{len(np.unique(yrs))} distinct years (faces={faces!r}); trace and label the rings "
            f"on more faces, or pass labels='auto' to fit unlabelled traces and ring maps")
    net, spec = _resolve_model(model)
    rng = np.random.default_rng(seed)
    size = np.asarray(block.size_mm, float)
    if labels == "years" or (labels == "auto" and enough):
        pith = _radial_pith(block, faces, size, seed) if start == "radial" else None
        field, grid_loss = _fit_labelled(torch, net, spec, pts, yrs, size, steps, rng, progress, name,
                                         pith=pith)
        loss = float(np.mean(np.abs(field(pts) - yrs))) if steps else grid_loss
        return _finish(field, size, spacing_mm, loss, grid_loss, len(pts), "years", None, None,
                       None, t_start)

    # --- unlabelled: number the rings, fit as labelled, then refine without years -------------
    ring, numbered, pith = _number_rings(block, faces, size, seed, name)
    keep = np.abs(numbered - np.round(numbered)) < _NUMBER_CONFIDENCE
    if keep.sum() < 10 or len(np.unique(np.round(numbered[keep]))) < 2:
        keep = np.ones(len(numbered), bool)
    field, grid_loss = _fit_labelled(torch, net, spec, ring.points_mm[keep], np.round(numbered[keep]),
                                     size, int(steps * _START_STEPS_SHARE), rng, progress, name,
                                     pith=pith)
    gaps = _gap_points(ring.points_mm, ring.group, ring.face, field, block)
    start_loss = _phase_loss(field, ring.points_mm)
    if year_free_steps and len(gaps):
        field = _refine_year_free(torch, net, spec, field, ring.points_mm, gaps, year_free_steps,
                                  rng)
    loss = _phase_loss(field, ring.points_mm)
    return _finish(field, size, spacing_mm, loss, grid_loss, len(ring.points_mm), "year-free",
                   start_loss, ring.points_mm, gaps, t_start)


def _finish(field, size, spacing_mm, loss, grid_loss, n, mode, start_loss, ring, gaps, t_start):
    sp = float(spacing_mm) if spacing_mm is not None else float(max(size.max() / 48.0, 0.5))
    grid = GridField.bake(field, (0.0, 0.0, 0.0), tuple(size), sp)
    return NeuralFit(field, grid, float(loss), float(grid_loss), n, time.perf_counter() - t_start,
                     mode=mode, labelled_loss_years=start_loss, ring_points_mm=ring,
                     gap_points_mm=gaps)


def _phase_loss(field, points_mm) -> float:
    """Mean distance (years) of the field at ``points_mm`` to the nearest integer."""
    y = field(points_mm)
    return float(np.mean(np.abs(y - np.round(y))))


def _radial_pith(block, faces, size, seed):
    """The radial fitter's pith line ``(point, direction)`` from the labelled observations."""
    from .observations import gather_observations
    from .radial import fit_radial

    radial = fit_radial(gather_observations(block, faces), size, seed=seed)
    return radial.pith_mm, radial.axis


def _number_rings(block, faces, size, seed, name):
    """Ring points of ``block`` (years stripped) and the radial fitter's growth time at them.

    The radial fitter (:func:`woodcam.inference.radial.fit_radial`) numbers unlabelled rings by
    their spacing; its field rounded at each point is the point's year (per point, not per
    group: a ring-map component that merges two rings gets both years).
    """
    from .observations import RingObservations, gather_observations
    from .radial import fit_radial

    obs = gather_observations(block, faces)
    obs = RingObservations(obs.points_mm, np.full(len(obs.points_mm), np.nan), obs.group, obs.face)
    if obs.n_groups < 2:
        raise WoodcamError(
            f"block {name!r}: fitting without year labels needs at least two rings (traces or "
            f"ring-map components) on the faces {faces!r}; found {obs.n_groups}; trace more rings "
            f"or label their years")
    radial = fit_radial(obs, size, seed=seed)
    return obs, radial(obs.points_mm), (radial.pith_mm, radial.axis)


def _gap_points(points, group, face, field, block=None, max_points: int = 4 * _ADAM_POINTS
                ) -> np.ndarray:
    """Points between rings: midpoints from each ring point to the nearest point of another ring
    group on the same face, kept where ``field`` (the numbered start) is at least
    :data:`_GAP_MIN_PHASE` from an integer. That drops midpoints between two pieces of one ring
    and those on a ring missing from the map or the tracing. Midpoints on a face's
    knot exclusion (:func:`~woodcam.inference.observations.knot_exclusion`) are dropped too:
    rings bend round a knot. points (n, 3) block mm, group (n,), face (n,) indices of
    :data:`woodcam.frames.FACES` -> (m, 3) block mm."""
    from scipy.spatial import cKDTree

    from ..frames import FACES, block_to_pixel
    from .observations import _pixel_index, knot_exclusion

    out = []
    for f in np.unique(face):
        on = np.flatnonzero(face == f)
        if len(np.unique(group[on])) < 2:
            continue
        p, g = points[on], group[on]
        k = min(64, len(p))
        _, idx = cKDTree(p).query(p, k=k)
        other = g[idx] != g[:, None]
        has = other.any(axis=1)
        j = idx[np.arange(len(p)), np.argmax(other, axis=1)]
        mid = 0.5 * (p[has] + p[j[has]])
        fc = block.faces.get(FACES[int(f)]) if block is not None else None
        knot = None if fc is None else knot_exclusion(fc, min(block.face_pixel_size_mm(fc.name)))
        if knot is not None:
            r, c = block_to_pixel(fc.name, mid, fc.shape, block.size_mm)
            mid = mid[~knot[_pixel_index(r, fc.shape[0]), _pixel_index(c, fc.shape[1])]]
        out.append(mid)
    if not out:
        return np.empty((0, 3))
    mid = np.concatenate(out)
    if len(mid) > max_points:
        mid = mid[np.random.default_rng(0).choice(len(mid), max_points, replace=False)]
    y = field(mid)
    return mid[np.abs(y - np.round(y)) >= _GAP_MIN_PHASE]


def _fit_labelled(torch, net, spec, pts, yrs, size, steps, rng, progress, name, pith=None):
    """Eq. 5 in two steps (grid search with ``c = 0``, then Adam with ``a`` fixed).

    pts (n, 3) block mm, yrs (n,) years -> (NeuralBlockField, grid-search L1 loss in years).
    ``pith``: an optional pith line ``(point (3,), direction (3,))`` in the block frame (the radial
    fitter's) used instead of the grid search; when its point lies beyond the grid's reach
    (:data:`_OFFSETS`), the grid's offsets along its direction are searched. Why not add it to
    the grid as one more candidate: the grid ranks candidates by their ``c = 0`` misfit, and on
    eq. 7-9 block 103 of the benchmark set a wrong offset beat the right pith there (0.90 vs
    1.00 years) but not after Adam (unmatched 1 mm 77 % vs 99.9 %).
    """
    center = size / 2
    corners = _corners(size)

    # --- step 1: coarse grid search with c = 0 ------------------------------------------------
    sub = rng.choice(len(pts), min(_GRID_POINTS, len(pts)), replace=False)
    ps, gs = pts[sub], yrs[sub]
    dirs = _directions() if pith is None else np.asarray(pith[1], float)[None]
    cands, dir_of = [], []  # (rotation, origin, length), direction index
    for di, d in enumerate(dirs):
        rot = _rotation_to(d)
        cc = (corners - center) @ rot.T
        radius = np.max(np.hypot(cc[:, 0], cc[:, 1]))
        half_len = np.max(np.abs(cc[:, 2]))
        offs = [np.array([u, v, 0.0]) * radius for u in _OFFSETS for v in _OFFSETS]
        if pith is not None:
            off = rot @ (np.asarray(pith[0], float) - center)
            off[2] = 0.0
            if np.hypot(off[0], off[1]) <= _OFFSETS.max() * radius:
                offs = [off]
        for off in offs:
            rho_max = np.max(np.hypot(cc[:, 0] - off[0], cc[:, 1] - off[1]))
            length = max(rho_max, half_len) / _DOMAIN_FILL
            cands.append((rot, center + rot.T @ off, length))
            dir_of.append(di)
    rots = np.stack([c[0] for c in cands])
    origins = np.stack([c[1] for c in cands])
    lengths = np.array([c[2] for c in cands])
    q = np.einsum("mij,mnj->mni", rots, ps[None] - origins[:, None]) / lengths[:, None, None]
    zero = torch.zeros(spec.latent_dim)
    with torch.no_grad():
        f = net(zero, torch.from_numpy(q.astype(np.float32))).double().numpy()
    k, a, score = _solve_scale_offset(f, gs)
    if not np.isfinite(score).any():
        # the years may be the user's labels or the fit's own numbering of unlabelled rings: say
        # both (it blamed "the trace year labels" on blocks that had none)
        raise WoodcamError(f"block {name!r}: no pith placement makes the rings' years (their labels, or "
                           f"the numbering of unlabelled rings) grow away from a pith; check the year labels "
                           f"if any, or use method 'radial' or 'evidence'")
    sub = rng.choice(len(pts), min(_ADAM_POINTS, len(pts)), replace=False)
    # the best placement of each pith direction, best first: distinct starts
    order = np.argsort(score)
    _, first = np.unique(np.asarray(dir_of)[order], return_index=True)
    tops = order[np.sort(first)][:_STARTS]
    starts = []
    for best in tops:
        if not np.isfinite(score[best]):
            break
        rot0, origin0, length0 = rots[best], origins[best], float(lengths[best])
        # re-solve K and a on all points for this placement
        q_all = ((pts - origin0) @ rot0.T / length0).astype(np.float32)
        with torch.no_grad():
            f_all = net(zero, torch.from_numpy(q_all)).double().numpy()
        k_all, a_all, s_all = _solve_scale_offset(f_all[None], yrs)
        if np.isfinite(s_all[0]):
            start = (rot0, origin0, length0, float(k_all[0]), float(a_all[0]), float(s_all[0]))
        else:
            start = (rot0, origin0, length0, float(k[best]), float(a[best]), float(score[best]))
        starts.append(start)

    # --- step 2: Adam over c, t, w, log K with a fixed ----------------------------------------
    # Multi-start: the grid ranks placements by their c = 0 misfit, which a wrong placement can
    # win (eq. 7-9 benchmark blocks 101 and 103: 7 % and 62 % within 1 mm from the top
    # placement). A short Adam run from the best placement of each of the _STARTS best pith
    # directions, then the full run from the one whose misfit fell lowest.
    if len(starts) > 1 and steps:
        trial = max(steps // _TRIAL_SHARE, 1)
        losses = [_adam_from(torch, net, spec, pts[sub], yrs[sub], st, trial, False)[1] for st in starts]
        starts = [starts[int(np.argmin(losses))]]
    field, _ = _adam_from(torch, net, spec, pts[sub], yrs[sub], starts[0], steps, progress)
    return field, starts[0][5]


def _adam_from(torch, net, spec, pts, yrs, start, steps, progress):
    """Adam over ``c, t, w, log K`` (``a`` fixed) from a grid placement ``start`` = (rotation,
    origin, length, K, a, grid loss) on points ``pts`` (n, 3) block mm with years ``yrs`` (n,).
    Returns ``(NeuralBlockField, final L1 misfit in years)``."""
    rot0, origin0, length0, k0, a_fix, _ = start
    p_t = torch.from_numpy(((pts - origin0) @ rot0.T / length0))  # float64, trunk frame
    g_t = torch.from_numpy(yrs - a_fix)
    code = torch.zeros(spec.latent_dim, dtype=torch.float64, requires_grad=True)
    shift = torch.zeros(3, dtype=torch.float64, requires_grad=True)
    w = torch.zeros(3, dtype=torch.float64, requires_grad=True)
    log_k = torch.tensor(np.log(k0), dtype=torch.float64, requires_grad=True)
    opt = torch.optim.Adam([{"params": [code], "lr": _LR_CODE},
                            {"params": [shift, w], "lr": _LR_POSE},
                            {"params": [log_k], "lr": _LR_SCALE}])

    def loss_fn(rmat):
        pred = torch.exp(log_k) * net(code.float(), (p_t @ rmat.T + shift).float()).double()
        return (pred - g_t).abs().mean() + spec.w_reg * (code * code).sum()

    _adam(torch, opt, w, loss_fn, steps, progress, "fit neural")
    with torch.no_grad():
        rmat = _rodrigues(torch, w)
        l1 = float((torch.exp(log_k) * net(code.float(), (p_t @ rmat.T + shift).float()).double()
                    - g_t).abs().mean())
    field = NeuralBlockField(net=net, code=code.detach().numpy().astype(np.float32),
                             rotation=rmat.numpy() @ rot0, origin_mm=origin0, length_mm=length0,
                             shift=shift.detach().numpy().copy(), scale=float(np.exp(log_k.item())),
                             age_offset=a_fix)
    return field, l1


def _adam(torch, opt, w, loss_fn, steps, progress, desc):
    """``steps`` Adam steps of ``loss_fn(rotation(w))``, learning rates cosine-decayed to 5 %."""
    base_lrs = [g["lr"] for g in opt.param_groups]
    it = range(steps)
    if progress:
        from .._progress import progress_bar
        it = progress_bar(it, desc=desc, unit="step")
    for i in it:
        scale = 0.5 * (1 + np.cos(np.pi * i / max(steps, 1)))
        for grp, lr in zip(opt.param_groups, base_lrs):
            grp["lr"] = lr * (0.05 + 0.95 * scale)
        loss = loss_fn(_rodrigues(torch, w))
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()


def _periodic_terms(y_ring, y_gap, sin):
    """The year-free loss's ring and gap terms (module docstring) of growth times (years) on and
    between rings; ``sin`` is ``np.sin`` or ``torch.sin``. Returns ``(ring, gap)``, each in [0, 1]."""
    ring = (sin(np.pi * y_ring) ** 2).mean()
    gap = ((1 - sin(np.pi * y_gap) ** 2) ** _GAP_POWER).mean() if len(y_gap) else 0.0
    return ring, gap


def year_free_loss(field, ring_mm, gap_mm) -> tuple[float, float]:
    """Ring and gap terms of the year-free loss of ``field`` at block points ``ring_mm`` (n, 3)
    on rings and ``gap_mm`` (m, 3) between rings: ``(mean sin^2(pi y), mean cos^(2p)(pi y))``."""
    ring, gap = _periodic_terms(field(ring_mm), field(gap_mm) if len(gap_mm) else np.empty(0), np.sin)
    return float(ring), float(gap)


def _refine_year_free(torch, net, spec, start: NeuralBlockField, ring_mm, gap_mm, steps, rng,
                      w_gap: float = _W_GAP, w_scale: float = _W_SCALE) -> NeuralBlockField:
    """L-BFGS on the year-free loss (module docstring) from ``start``, ``steps`` iterations.

    ring_mm (n, 3), gap_mm (m, 3): block-frame points on and between rings. Free: code ``c``,
    pose ``(t, w)``, ``log K`` and a phase ``b``: ``years = a + b + K f``. ``w_gap = 0`` and
    ``w_scale = 0`` switch the guards off (tests show what they prevent).
    """
    def to_trunk(p):
        sub = p if len(p) <= _ADAM_POINTS else p[rng.choice(len(p), _ADAM_POINTS, replace=False)]
        return torch.from_numpy(np.einsum("ij,nj->ni", start.rotation, sub - start.origin_mm)
                                / start.length_mm)

    p_ring, p_gap = to_trunk(ring_mm), to_trunk(gap_mm)
    n_ring = len(p_ring)
    p_all = torch.cat([p_ring, p_gap])
    code = torch.tensor(np.asarray(start.code, np.float64), requires_grad=True)
    shift = torch.tensor(np.asarray(start.shift, np.float64), requires_grad=True)
    w = torch.zeros(3, dtype=torch.float64, requires_grad=True)
    log_k0 = float(np.log(start.scale))
    log_k = torch.tensor(log_k0, dtype=torch.float64, requires_grad=True)
    phase = torch.zeros((), dtype=torch.float64, requires_grad=True)
    a0 = float(start.age_offset)
    params = [code, shift, w, log_k, phase]
    # L-BFGS with a strong-Wolfe line search, not Adam: the periodic loss is sharp in the pose
    # (K ~ 15-60 years per normalised unit, so 0.01 units of shift move the rings by a year) and
    # Adam's first full-size steps threw the rings off by half a period on a real cube (CN03:
    # loss 0.29 -> 0.82 in 10 steps); the line search only accepts steps that lower the loss.
    opt = torch.optim.LBFGS(params, lr=1.0, max_iter=steps, history_size=20,
                            line_search_fn="strong_wolfe", tolerance_grad=1e-9,
                            tolerance_change=1e-12)

    def closure():
        opt.zero_grad(set_to_none=True)
        rmat = _rodrigues(torch, w)
        y = a0 + phase + torch.exp(log_k) * net(code.float(), (p_all @ rmat.T + shift).float()).double()
        ring, gap = _periodic_terms(y[:n_ring], y[n_ring:], torch.sin)
        total = (ring + w_gap * gap + w_scale * (log_k - log_k0) ** 2
                 + spec.w_reg * (code * code).sum())
        total.backward()
        return total

    if steps:
        opt.step(closure)
    with torch.no_grad():
        rmat = _rodrigues(torch, w).numpy()
    return NeuralBlockField(net=net, code=code.detach().numpy().astype(np.float32),
                            rotation=rmat @ start.rotation, origin_mm=start.origin_mm,
                            length_mm=start.length_mm, shift=shift.detach().numpy().copy(),
                            scale=float(np.exp(log_k.item())),
                            age_offset=start.age_offset + float(phase.item()))


def fit_neural(block, *, model=None, faces=None, steps: int = 300, seed: int = 0,
               progress: bool = False, spacing_mm: float | None = None, threads: int = 1,
               labels: Labels = "auto", year_free_steps: int = _YEAR_FREE_STEPS,
               start: Start = "grid") -> GridField:
    """Growth field of ``block`` from its ring traces or ring maps with the generic neural model.

    Parameters
    ----------
    block : woodcam.block.Block
        Labelled: ``block.trace_points_mm(faces)`` (unlabelled trace points are then ignored).
        Unlabelled: the ring points of :func:`woodcam.inference.gather_observations` (traces,
        else ring maps).
    model : None, folder or ``(net, spec)``
        The generic model; None loads the packaged ``woodcam/models`` weights.
    faces : list of face names, optional
        Faces whose rings are fitted (default: all).
    steps : int
        Adam iterations of the labelled refinement (0: grid search only).
    seed : int
        Seeds the random point subsets; the same inputs give the same field.
    spacing_mm : float, optional
        Bake grid spacing (default: the longest block side / 48, at least 0.5 mm).
    threads : int
        torch CPU threads during the fit (restored after); 1 is fastest on a busy machine.
    labels : "auto", "years" or "none"
        "years": eq. 5 on year-labelled traces (error without them); "none": ignore any years
        and fit the rings year-free (module docstring); "auto": "years" when the traces carry
        at least 10 labelled points of 2 different years, else "none".
    year_free_steps : int
        L-BFGS iterations of the year-free refinement (unlabelled fits only; 0: numbering only).
    start : "grid" or "radial"
        Labelled fits: "grid" is the seed's coarse grid search (13 pith directions x 81 pith
        offsets); "radial" starts from the pith line of the radial fitter
        (:func:`woodcam.inference.fit_radial`, ~1-2 s more) instead, which rescues blocks where
        no grid direction is close enough to the pith for Adam to recover. Unlabelled fits
        always start from the radial fitter's line.

    Returns
    -------
    GridField
        Growth time (years) in the block frame, baked over the block; ``.axis`` is the fitted
        pith direction. Unlabelled fits give the rings up to the age offset (the pith is put
        near year 0 by the numbering; the year-free phase may make the offset fractional).

    Raises
    ------
    WoodcamError
        No rings on the faces (no traces and no ring-map ring pixels), a single ring without a
        year, ``labels="years"`` without labelled traces, or bad ``steps`` / ``labels`` /
        ``model``.
    """
    return fit_neural_details(block, model=model, faces=faces, steps=steps, seed=seed,
                              progress=progress, spacing_mm=spacing_mm, threads=threads,
                              labels=labels, year_free_steps=year_free_steps, start=start).grid
