"""Fit the generic neural growth field to a block's year-labelled ring traces (eq. 5 of seed 000).

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
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

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
    """Everything :func:`fit_neural_details` found."""

    field: NeuralBlockField
    grid: GridField
    loss_years: float          # final mean |residual| at the fitted trace points, years
    grid_loss_years: float     # the same after the grid search (c = 0)
    n_points: int
    time_s: float


def _rotation_to(axis: np.ndarray) -> np.ndarray:
    """(3, 3) rotation whose last row is ``axis`` (unit), first row a fixed perpendicular."""
    z = axis / np.linalg.norm(axis)
    ref = np.array([1.0, 0, 0]) if abs(z[0]) < 0.9 else np.array([0, 1.0, 0])
    x = ref - z * (ref @ z)
    x /= np.linalg.norm(x)
    return np.stack([x, np.cross(z, x), z])


def _directions() -> np.ndarray:
    """13 pith directions: block axes, face diagonals, body diagonals (sign is irrelevant)."""
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
                       threads: int = 1) -> NeuralFit:
    """Fit eq. 5 to ``block``'s labelled traces; see :func:`fit_neural` (this returns more)."""
    torch = require("torch", "learn", "fitting the neural growth field")
    old_threads = torch.get_num_threads()
    torch.set_num_threads(int(threads))
    try:
        return _fit(torch, block, model, faces, steps, seed, progress, spacing_mm)
    finally:
        torch.set_num_threads(old_threads)


def _fit(torch, block, model, faces, steps, seed, progress, spacing_mm) -> NeuralFit:
    t_start = time.perf_counter()
    if not isinstance(steps, (int, np.integer)) or steps < 0:
        raise WoodcamError(f"steps must be an integer >= 0; got {steps!r}")
    pts, yrs = block.trace_points_mm(faces)
    ok = np.isfinite(yrs)
    pts, yrs = pts[ok], yrs[ok]
    if len(pts) < 10 or len(np.unique(yrs)) < 2:
        raise WoodcamError(
            f"block {getattr(block, 'name', '?')!r}: fitting needs year-labelled ring traces with "
            f"at least 2 different years and 10 points; got {len(pts)} labelled points with "
            f"{len(np.unique(yrs))} distinct years (faces={faces!r}); trace and label the rings "
            f"on more faces")
    net, spec = _resolve_model(model)
    rng = np.random.default_rng(seed)
    size = np.asarray(block.size_mm, float)
    center = size / 2
    corners = _corners(size)

    # --- step 1: coarse grid search with c = 0 ------------------------------------------------
    sub = rng.choice(len(pts), min(_GRID_POINTS, len(pts)), replace=False)
    ps, gs = pts[sub], yrs[sub]
    dirs = _directions()
    cands = []  # (rotation, origin, length)
    for d in dirs:
        rot = _rotation_to(d)
        cc = (corners - center) @ rot.T
        radius = np.max(np.hypot(cc[:, 0], cc[:, 1]))
        half_len = np.max(np.abs(cc[:, 2]))
        for u in _OFFSETS:
            for v in _OFFSETS:
                off = np.array([u, v, 0.0]) * radius
                rho_max = np.max(np.hypot(cc[:, 0] - off[0], cc[:, 1] - off[1]))
                length = max(rho_max, half_len) / _DOMAIN_FILL
                cands.append((rot, center + rot.T @ off, length))
    rots = np.stack([c[0] for c in cands])
    origins = np.stack([c[1] for c in cands])
    lengths = np.array([c[2] for c in cands])
    q = np.einsum("mij,mnj->mni", rots, ps[None] - origins[:, None]) / lengths[:, None, None]
    zero = torch.zeros(spec.latent_dim)
    with torch.no_grad():
        f = net(zero, torch.from_numpy(q.astype(np.float32))).double().numpy()
    k, a, score = _solve_scale_offset(f, gs)
    best = int(np.argmin(score))
    if not np.isfinite(score[best]):
        raise WoodcamError(f"block {getattr(block, 'name', '?')!r}: no pith placement makes the "
                           f"labelled years grow away from a pith; check the trace year labels")
    rot0, origin0, length0 = rots[best], origins[best], float(lengths[best])
    a_fix = float(a[best])
    # re-solve K and a on all points for the chosen placement
    q_all = ((pts - origin0) @ rot0.T / length0).astype(np.float32)
    with torch.no_grad():
        f_all = net(zero, torch.from_numpy(q_all)).double().numpy()
    k_all, a_all, s_all = _solve_scale_offset(f_all[None], yrs)
    if np.isfinite(s_all[0]):
        k0, a_fix, grid_loss = float(k_all[0]), float(a_all[0]), float(s_all[0])
    else:
        k0, grid_loss = float(k[best]), float(score[best])

    # --- step 2: Adam over c, t, w, log K with a fixed ----------------------------------------
    sub = rng.choice(len(pts), min(_ADAM_POINTS, len(pts)), replace=False)
    p_t = torch.from_numpy(((pts[sub] - origin0) @ rot0.T / length0))  # float64, trunk frame
    g_t = torch.from_numpy(yrs[sub] - a_fix)
    code = torch.zeros(spec.latent_dim, dtype=torch.float64, requires_grad=True)
    shift = torch.zeros(3, dtype=torch.float64, requires_grad=True)
    w = torch.zeros(3, dtype=torch.float64, requires_grad=True)
    log_k = torch.tensor(np.log(k0), dtype=torch.float64, requires_grad=True)
    opt = torch.optim.Adam([{"params": [code], "lr": _LR_CODE},
                            {"params": [shift, w], "lr": _LR_POSE},
                            {"params": [log_k], "lr": _LR_SCALE}])
    base_lrs = [g["lr"] for g in opt.param_groups]
    it = range(steps)
    if progress:
        from tqdm import tqdm
        it = tqdm(it, desc="fit neural", unit="step")
    loss_v = grid_loss
    for i in it:
        scale = 0.5 * (1 + np.cos(np.pi * i / max(steps, 1)))
        for grp, lr in zip(opt.param_groups, base_lrs):
            grp["lr"] = lr * (0.05 + 0.95 * scale)
        rmat = _rodrigues(torch, w)
        q_i = (p_t @ rmat.T + shift).float()
        pred = torch.exp(log_k) * net(code.float(), q_i).double()
        l1 = (pred - g_t).abs().mean()
        loss = l1 + spec.w_reg * (code * code).sum()
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()
        loss_v = float(l1.detach())

    with torch.no_grad():
        rmat = _rodrigues(torch, w).numpy()
    field = NeuralBlockField(net=net, code=code.detach().numpy().astype(np.float32),
                             rotation=rmat @ rot0, origin_mm=origin0, length_mm=length0,
                             shift=shift.detach().numpy().copy(), scale=float(np.exp(log_k.item())),
                             age_offset=a_fix)
    # final loss on all labelled points with the final parameters
    loss_all = float(np.mean(np.abs(field(pts) - yrs)))
    sp = float(spacing_mm) if spacing_mm is not None else float(max(size.max() / 48.0, 0.5))
    grid = GridField.bake(field, (0.0, 0.0, 0.0), tuple(size), sp)
    return NeuralFit(field, grid, loss_all if steps else grid_loss, grid_loss, len(pts),
                     time.perf_counter() - t_start)


def fit_neural(block, *, model=None, faces=None, steps: int = 300, seed: int = 0,
               progress: bool = False, spacing_mm: float | None = None, threads: int = 1) -> GridField:
    """Growth field of ``block`` from its year-labelled traces with the generic neural model.

    Parameters
    ----------
    block : woodcam.block.Block
        Uses ``block.trace_points_mm(faces)``; unlabelled (NaN-year) trace points are ignored.
    model : None, folder or ``(net, spec)``
        The generic model; None loads the packaged ``woodcam/models`` weights.
    faces : list of face names, optional
        Faces whose traces are fitted (default: all).
    steps : int
        Adam iterations of the refinement (0: grid search only).
    seed : int
        Seeds the random point subsets; the same inputs give the same field.
    spacing_mm : float, optional
        Bake grid spacing (default: the longest block side / 48, at least 0.5 mm).
    threads : int
        torch CPU threads during the fit (restored after); 1 is fastest on a busy machine.

    Returns
    -------
    GridField
        Growth time (years) in the block frame, baked over the block; ``.axis`` is the fitted
        pith direction.
    """
    return fit_neural_details(block, model=model, faces=faces, steps=steps, seed=seed,
                              progress=progress, spacing_mm=spacing_mm, threads=threads).grid
