"""Issue 12, fit speed: the optimised hot paths of the evidence fit compute what the
straightforward code computed.

Each optimisation (designs written in place, frames without ``np.cross``, Cholesky by LAPACK
directly, a fixed axis' design built once for the smoothing and growth-history rounds, the stem's
design cached per centreline, thin-plate RBFs evaluated by one distance product) is checked
against the code it replaced, and the whole default fit of a small knotted block against the
same fit with every replaced piece put back: the same choice, the same held-out scores to the
last digit, the same baked field to 1e-9 years. The speed itself is a ratio in the ``bench``
test (not in the default run).
"""

from __future__ import annotations

import contextlib
import time
import warnings

import numpy as np
import pytest
from scipy.interpolate import RBFInterpolator
from scipy.linalg import cho_factor, cho_solve

from woodcam.errors import WoodcamWarning
from woodcam.inference import radial, rbf, stem
from woodcam.inference.fit import fit_block

# -- the code the optimisations replaced (main at c729fb9) ---------------------------------------


def _frame_ref(direction):
    d = np.asarray(direction, float)
    d = d / np.linalg.norm(d)
    helper = np.eye(3)[int(np.argmin(np.abs(d)))]
    e1 = np.cross(d, helper)
    e1 /= np.linalg.norm(e1)
    return d, e1, np.cross(d, e1)


def _radial_design_ref(points, pith, d, e1, e2, z_scale, K, M):
    q = points - pith
    a1, a2, z = q @ e1, q @ e2, (q @ d) / z_scale
    rho = np.hypot(a1, a2)
    phi = np.arctan2(a2, a1)
    k = np.arange(1, K + 1)
    trig = np.concatenate([np.ones((len(q), 1)), np.cos(np.outer(phi, k)), np.sin(np.outer(phi, k))], axis=1)
    zp = z[:, None] ** np.arange(M + 1)
    return rho, (trig[:, :, None] * zp[:, None, :]).reshape(len(q), -1)


def _stem_design_ref(points, centre, frame, L, curve, K, M, P, rho0):
    d, b1, b2 = frame
    q = points - centre
    tau = (q @ d) / L
    pw = tau[:, None] ** np.arange(3)
    x1 = q @ b1 - pw @ curve[0]
    x2 = q @ b2 - pw @ curve[1]
    rho, phi = np.hypot(x1, x2), np.arctan2(x2, x1)
    k = np.arange(1, K + 1)
    trig = np.concatenate([np.ones((len(rho), 1)), np.cos(np.outer(phi, k)), np.sin(np.outer(phi, k))], axis=1)
    B = (trig[:, :, None] * (tau[:, None] ** np.arange(M + 1))[:, None, :]).reshape(len(rho), -1)
    pows = (rho / rho0)[:, None] ** np.arange(2, P + 1)
    return np.concatenate([np.ones((len(rho), 1)), pows, rho[:, None] * B], axis=1)


def _lstsq_ref(lhs, rhs):
    AtA = lhs.T @ lhs
    AtA[np.diag_indices_from(AtA)] += 1e-10 * (np.trace(AtA) / len(AtA) + 1e-30)
    try:
        return cho_solve(cho_factor(AtA), lhs.T @ rhs)
    except np.linalg.LinAlgError:
        return np.linalg.lstsq(lhs, rhs, rcond=None)[0]


def _solve_ref(self, pith, d):
    if self.years is None:  # the unlabelled branch was not changed
        return _solve_now(self, pith, d)
    dd, e1, e2 = radial._frame(d)
    rho, B = radial._design(self.points, pith, dd, e1, e2, self.z_scale, self.K, self.M)
    A = rho[:, None] * B
    pen = np.sqrt(self.ridge * len(A)) * radial._penalty_weights(self.K, self.M) * np.median(rho)
    X = np.concatenate([np.ones((len(A), 1)), A], axis=1)
    P = np.concatenate([np.zeros((len(pen), 1)), np.diag(pen)], axis=1)
    lhs = np.concatenate([X, P])
    rhs = np.concatenate([self.years, np.zeros(len(pen))])
    sol = radial._lstsq(lhs, rhs)
    return lhs @ sol - rhs, sol[1:], sol[0], None


_solve_now = radial._Problem.solve


def _ring_spacing_ref(obs):
    from scipy.spatial import cKDTree

    dists = []
    for f in np.unique(obs.face):
        on = obs.face == f
        pts, grp = obs.points_mm[on], obs.group[on]
        for g in np.unique(grp):
            mine = grp == g
            if mine.all():
                continue
            dd, _ = cKDTree(pts[~mine]).query(pts[mine][:: max(1, mine.sum() // 20)])
            dists.append(dd)
    return float(np.median(np.concatenate(dists)))


@contextlib.contextmanager
def straightforward(monkeypatch):
    """Every optimised piece replaced by the code it replaced (caches never hit)."""
    with monkeypatch.context() as m:
        m.setattr(radial, "_frame", _frame_ref)
        m.setattr(stem, "_frame", _frame_ref)
        m.setattr(radial, "_design", _radial_design_ref)
        m.setattr(stem, "_design", _stem_design_ref)
        m.setattr(radial, "_lstsq", _lstsq_ref)
        m.setattr(stem, "_lstsq", _lstsq_ref)
        m.setattr(radial._Problem, "solve", _solve_ref)
        m.setattr(radial._AxisDesign, "fits", lambda self, obs, field: False)
        m.setattr(radial._AxisDesign, "linear", lambda self, field: field.linear(self.obs.points_mm))
        m.setattr(stem._StemProblem, "design", lambda self, curve: _stem_design_ref(
            self.points, self.centre, self.frame, self.L, curve, self.K, self.M, self.P, self.rho0))
        m.setattr(rbf, "_thin_plate_field", lambda r: r)
        m.setattr(radial, "_ring_spacing", _ring_spacing_ref)
        yield


# -- piece by piece ---------------------------------------------------------------------------

def test_frames_and_designs_are_the_replaced_code_bit_for_bit():
    rng = np.random.default_rng(3)
    for K, M in [(12, 1), (2, 1), (4, 0), (3, 2), (0, 1)]:
        pts = rng.uniform(-40, 90, (500, 3))
        pith = pts[7].copy()  # a point on the pith: rho = 0, phi = arctan2(0, 0) = 0
        v = rng.normal(size=3)
        d, e1, e2 = _frame_ref(v)
        assert all(np.array_equal(a, b) for a, b in zip(radial._frame(v), (d, e1, e2)))
        want, got = _radial_design_ref(pts, pith, d, e1, e2, 40.0, K, M), radial._design(pts, pith, d, e1, e2, 40.0, K, M)
        assert np.array_equal(want[0], got[0]) and np.array_equal(want[1], got[1]), (K, M)
        curve = rng.normal(0, 5, (2, 3))
        args = (pts, np.full(3, 25.0), (d, e1, e2), 60.0, curve, K, M, 3, 80.0)
        assert np.array_equal(_stem_design_ref(*args), stem._design(*args)), (K, M)


def test_normal_equations_are_scipys_cholesky_bit_for_bit():
    rng = np.random.default_rng(4)
    lhs, rhs = rng.normal(size=(800, 51)), rng.normal(size=800)
    assert np.array_equal(radial._lstsq(lhs, rhs), _lstsq_ref(lhs, rhs))
    flat = np.zeros((50, 4))  # singular (the ridge makes it semi-definite at best): lstsq's answer
    flat[:, 0] = 1.0
    assert np.array_equal(radial._lstsq(flat, np.ones(50)), _lstsq_ref(flat, np.ones(50)))
    lhs[3, 2] = np.nan
    with pytest.raises(ValueError, match="infs or NaNs"):  # as scipy's check_finite
        radial._lstsq(lhs, rhs)
    prob = radial._Problem(rng.uniform(0, 50, (600, 3)), rng.uniform(0, 20, 600), None, np.full(3, 25.0), 40.0,
                           12, 1, 1e-8)
    pith, d = np.array([-20.0, 70.0, 3.0]), np.array([0.1, 0.2, 1.0])
    assert all(np.array_equal(a, b) for a, b in zip(_solve_ref(prob, pith, d)[:3], prob.solve(pith, d)[:3]))


def test_thin_plate_field_matches_scipys_evaluation():
    rng = np.random.default_rng(5)
    centres = rng.uniform(0, 60, (400, 3))
    values = np.sin(centres[:, 0] / 7) + centres[:, 2] / 10
    scipy_rbf = RBFInterpolator(centres, values, kernel="thin_plate_spline", smoothing=0.3)
    fast = rbf._thin_plate_field(scipy_rbf)
    assert isinstance(fast, rbf._ThinPlate)
    x = np.concatenate([rng.uniform(-5, 65, (3000, 3)), centres[:50]])  # incl. the centres (r = 0)
    np.testing.assert_allclose(fast(x), scipy_rbf(x), rtol=0, atol=1e-9)
    other = RBFInterpolator(centres, values, kernel="cubic")
    assert rbf._thin_plate_field(other) is other  # only the thin-plate spline has the fast path


def test_a_face_spline_is_baked_exactly_near_the_faces_and_smoothly_deep_inside():
    """A thin-plate spline of face points (the evidence fit's residual, the RBF hypothesis) is
    baked exactly within ``BAKE_SMOOTH_DEPTH_MM`` of a face and from a coarser grid deeper
    (:mod:`woodcam.inference.baked`); on a residual of a few years that bends sharply near its
    centres the deep nodes stay within 0.02 years. A spline with a centre inside the block is
    baked exactly everywhere. Checked by breaking it: interpolating every node from the coarse
    grid, the nodes near the faces are 0.2 years off and this fails."""
    from woodcam.fields.grid import GridField
    from woodcam.fields.residual import ResidualField
    from woodcam.inference.baked import _depth_mm, bake
    from woodcam.tolerances import BAKE_SMOOTH_DEPTH_MM

    rng = np.random.default_rng(11)
    size = np.array([40.0, 34.0, 46.0])
    pts = rng.uniform(0, 1, (600, 3)) * size
    face = rng.integers(0, 3, len(pts))
    pts[np.arange(len(pts)), face] = np.where(rng.random(len(pts)) < 0.5, 0.0, size[face])  # on the faces
    wavy = 2.0 * np.sin(pts[:, 0] / 3.0) * np.cos(pts[:, 2] / 4.0) + rng.normal(0, 0.3, len(pts))
    spline = rbf._thin_plate_field(RBFInterpolator(pts, wavy, kernel="thin_plate_spline", smoothing=1.0))
    stem = lambda p: np.asarray(p, float)[:, 2] / 2.5 + 3.0  # noqa: E731
    nodes_ok = []
    for field in (ResidualField(stem, spline), spline):
        exact = GridField.bake(field, (0, 0, 0), tuple(size), 1.0, margin_nodes=2)
        fast = bake(field, size)
        shape = exact.years.shape
        nodes = exact.nodes_mm()
        deep = (_depth_mm(nodes, size) >= BAKE_SMOOTH_DEPTH_MM).reshape(shape)
        diff = np.abs(fast.years - exact.years)
        assert deep.mean() > 0.3 and np.ptp(exact.years[deep]) > 2.0  # a deep field that varies
        np.testing.assert_allclose(fast.years[~deep], exact.years[~deep], rtol=0, atol=1e-9)
        assert diff[deep].max() < 0.02
        nodes_ok.append(diff[deep].max() > 0)  # deep nodes interpolated, not evaluated
    assert all(nodes_ok)
    inside = pts.copy()
    inside[0] = size / 2  # one centre deep inside: no smooth interior
    spline = rbf._thin_plate_field(RBFInterpolator(inside, wavy, kernel="thin_plate_spline", smoothing=1.0))
    assert np.array_equal(bake(spline, size).years, GridField.bake(spline, (0, 0, 0), tuple(size), 1.0,
                                                                    margin_nodes=2).years)


def _labelled_problem(K, M, ridge, seed=6):
    """Rings of a tilted, eccentric radial field sampled on three faces of a 50 mm block."""
    rng = np.random.default_rng(seed)
    faces = [np.c_[rng.uniform(0, 50, 700), np.zeros(700), rng.uniform(0, 50, 700)],
             np.c_[rng.uniform(0, 50, 700), rng.uniform(0, 50, 700), np.full(700, 50.0)],
             np.c_[np.zeros(700), rng.uniform(0, 50, 700), rng.uniform(0, 50, 700)]]
    pts = np.concatenate(faces)
    axis = np.array([0.15, -0.1, 1.0]) / np.linalg.norm([0.15, -0.1, 1.0])
    q = pts - np.array([-30.0, 20.0, 0.0])
    radial_q = q - np.outer(q @ axis, axis)
    phi = np.arctan2(radial_q[:, 1], radial_q[:, 0])
    years = np.linalg.norm(radial_q, axis=1) / (2.5 + 0.4 * np.cos(phi)) + rng.normal(0, 0.05, len(pts))
    return radial._Problem(pts, years, None, np.full(3, 25.0), 43.3, K, M, ridge)


@pytest.mark.parametrize("K, M, ridge", [(12, 1, 1e-3), (4, 1, 1e-4), (6, 2, 1e-2)])
def test_radial_jacobian_is_the_derivative(K, M, ridge):
    """The exact variable-projection Jacobian of the radial axis search against central
    differences of the residual: the data rows (the frame's spin about the axis turns only the
    ridge rows' coefficients, not the cost), and the cost's gradient ``J' r`` over all rows.
    Ridges where the differences are accurate (at the fits' 1e-8 they agree to ~1e-4 only,
    the differences' own noise); without the jitter's change the data rows miss by 5e-5."""
    prob = _labelled_problem(K, M, ridge)
    base = radial._frame(np.array([0.1, 0.2, 1.0]))
    theta = np.array([0.03, -0.02, -40.0, 25.0])  # some way from the optimum: residuals are large
    r, jac = prob.residual_and_jacobian(theta, base)
    J = jac()
    n = len(prob.points)
    assert np.array_equal(r, prob.solve(*prob.axis_of(theta, base))[0])
    for j, h in enumerate([1e-7, 1e-7, 1e-5, 1e-5]):
        step = np.zeros(4)
        step[j] = h
        plus, minus = (prob.solve(*prob.axis_of(theta + s, base))[0] for s in (step, -step))
        fd = (plus - minus) / (2 * h)
        assert np.abs(fd[:n] - J[:n, j]).max() < 1e-5 * np.abs(fd[:n]).max(), j
        grad_fd = (plus @ plus - minus @ minus) / (4 * h)  # d(|r|^2 / 2)
        assert abs(grad_fd - J[:, j] @ r) < 1e-6 * abs(grad_fd), j


def test_radial_search_with_the_jacobian_ends_where_differences_end():
    """The axis descent with the exact Jacobian reaches the optimum the forward-difference
    descent (FIT_VERSION <= 13) reached: the same cost, axis and pith."""
    from scipy.optimize import least_squares

    prob = _labelled_problem(12, 1, 1e-8)
    start_pith, start_d = np.array([-10.0, 30.0, 0.0]), np.array([0.0, 0.1, 1.0])
    pith, d, cost = radial._refine(prob, start_pith, start_d, max_nfev=60)
    d0, b1, b2 = base = radial._frame(start_d)
    off = start_pith - prob.centre
    theta0 = np.array([0.0, 0.0, off @ b1, off @ b2])
    fd = least_squares(lambda th: prob.solve(*prob.axis_of(th, base))[0], theta0, x_scale=[0.05, 0.05, 5.0, 5.0],
                       diff_step=1e-4, max_nfev=60, method="trf", ftol=1e-6, xtol=1e-6)
    pith_fd, d_fd = prob.axis_of(fd.x, base)
    assert cost == pytest.approx(fd.cost * 2, rel=1e-5)
    assert np.degrees(np.arccos(min(1.0, abs(d @ d_fd)))) < 0.01
    at = lambda p, dd: p + dd * ((prob.centre - p) @ dd)  # noqa: E731  the pith line's point nearest the centre
    assert np.linalg.norm(at(pith, d) - at(pith_fd, d_fd)) < 0.01
    true_axis = np.array([0.15, -0.1, 1.0]) / np.linalg.norm([0.15, -0.1, 1.0])
    assert np.degrees(np.arccos(abs(d @ true_axis))) < 1.0  # and that optimum is the field's axis


@pytest.mark.parametrize("step_mm", [0.3, 0.004])  # traced as usual; so dense that 32 neighbours are one ring
def test_ring_spacing_is_the_per_ring_trees(step_mm):
    """One tree per face asked for 32 neighbours gives the per-ring trees' median bit for bit,
    also where every neighbour of a point is its own ring and it must ask the other rings."""
    from woodcam.inference.observations import RingObservations

    rng = np.random.default_rng(3)
    pts, grp, face = [], [], []
    for f in range(2):  # two faces of arcs 2.5 mm apart, each ring in two pieces, one lone ring
        for r in range(4 if f == 0 else 1):
            for piece in range(2):
                a = np.arange(piece * 0.8, piece * 0.8 + 0.7, step_mm / (20.0 + 2.5 * r))
                xy = (20.0 + 2.5 * r) * np.c_[np.cos(a), np.sin(a)] + rng.normal(0, 0.05, (len(a), 2))
                pts.append(np.c_[xy, np.full(len(a), 10.0 * f)])
                grp.append(np.full(len(a), len(grp)))
                face.append(np.full(len(a), f))
    p = np.concatenate(pts)
    obs = RingObservations(p, np.full(len(p), np.nan), np.concatenate(grp), np.concatenate(face))
    assert radial._ring_spacing(obs) == _ring_spacing_ref(obs)


# -- the whole fit ----------------------------------------------------------------------------

@pytest.fixture(scope="module")
def small_knotted_block():
    from woodcam.bench_realistic import make_block

    block, info = make_block(9101, 0, "noisy", face_px=96)  # dev seed; every hypothesis family
    assert info["knotted"]
    return block


def _fit(block):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", WoodcamWarning)
        return fit_block(block, "evidence")


def test_optimised_fit_is_the_straightforward_fit(small_knotted_block, monkeypatch):
    """The default fit (hypotheses, knot bend) of a small knotted block with the optimised hot
    paths and with every replaced piece put back: same choice, same held-out scores, baked
    field equal to 1e-9 years (broken once: ``_trig_powers`` as powers of exp(i phi), 1e-15
    from the cosines, moved the baked field by more than that)."""
    fast = _fit(small_knotted_block)
    with straightforward(monkeypatch):
        slow = _fit(small_knotted_block)
    assert "stem + knot bend" in fast.meta["scores"]  # the bend was offered, so it was timed too
    assert fast.meta["chosen"] == slow.meta["chosen"]
    assert fast.meta["accepted"] == slow.meta["accepted"]
    assert fast.meta["scores"] == slow.meta["scores"]
    np.testing.assert_allclose(fast.years, slow.years, rtol=0, atol=1e-9)
    np.testing.assert_allclose(fast.layers["uncertainty"], slow.layers["uncertainty"], rtol=0, atol=1e-9)


@pytest.mark.bench
def test_optimised_fit_cpu_ratio(small_knotted_block, monkeypatch):
    """CPU seconds of the optimised default fit against the straightforward one, same process,
    interleaved (the machine is shared). Prints the ratio; asserts only that it is a gain."""
    times = {"fast": [], "slow": []}
    for _ in range(2):
        for name in ("slow", "fast"):
            with straightforward(monkeypatch) if name == "slow" else contextlib.nullcontext():
                c0 = time.process_time()
                _fit(small_knotted_block)
                times[name].append(time.process_time() - c0)
    ratio = min(times["fast"]) / min(times["slow"])
    print(f"optimised / straightforward CPU: {ratio:.2f} ({min(times['fast']):.2f} / {min(times['slow']):.2f} s)")
    assert ratio < 0.9
