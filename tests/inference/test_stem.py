"""Issue 12 part 2: the stem model (curved, tilted pith; ring widths by year and direction) and
the honesty of the leave-one-face-out choice (part 1)."""

import numpy as np
import pytest

from _eq79_blocks import make_block, random_field
from woodcam.errors import WoodcamError
from woodcam.inference import evaluate_fit, gather_observations
from woodcam.inference.evidence import radial_recipe
from woodcam.inference.radial import RadialField, _smoothest_coefficients, fit_radial
from woodcam.inference.stem import fit_stem

SIZE = (50.0, 45.0, 60.0)


class CurvedStem:
    """A log of the generator's family in the block frame: the pith a parabola in z
    ``pith(z) = p0 + u (z - zc) + k (z - zc)^2`` (x and y), cross-sections perpendicular to z
    (as ``Centreline.to_log_centric``), eccentric rings whose width grows with the radius
    (``AnalyticLogField``: ``years = ln(1 + s r_eff) / (w0 s)``)."""

    def __init__(self, p0=(-22.0, 18.0), slope=(0.06, -0.03), curv=(0.0022, 0.0015), zc=30.0,
                 w0=2.5, s=0.004, ecc=0.1, ecc_az=0.7):
        self.p0, self.slope, self.curv, self.zc = np.array(p0), np.array(slope), np.array(curv), zc
        self.w0, self.s, self.ecc, self.ecc_az = w0, s, ecc, ecc_az
        self.axis = np.array([0.0, 0.0, 1.0])

    def pith(self, z):
        t = np.asarray(z, float) - self.zc
        return self.p0 + np.outer(t, self.slope) + np.outer(t ** 2, self.curv)

    def __call__(self, points_mm):
        p = np.asarray(points_mm, float)
        q = p[:, :2] - self.pith(p[:, 2])
        r = np.hypot(q[:, 0], q[:, 1])
        th = np.arctan2(q[:, 1], q[:, 0])
        r_eff = r * (1 - self.ecc * np.cos(th - self.ecc_az))
        return np.log1p(self.s * r_eff) / (self.w0 * self.s)


@pytest.fixture(scope="module")
def curved():
    field = CurvedStem()
    block = make_block(field, SIZE, px_per_mm=3.0, rng=np.random.default_rng(3), jitter_mm=0.1)
    return field, block


def _pith_at(stem, z):
    """The fitted centreline's (x, y) where it crosses the plane at height z (base axis +z)."""
    p = stem.pith_mm([z - stem.centre_mm[2]])[0]
    assert abs(p[2] - z) < 1e-9
    return p[:2]


def test_curved_pith_recovered_from_three_faces(curved):
    field, block = curved
    obs = gather_observations(block, ["front", "top", "left"])
    stem = fit_stem(obs, SIZE)
    assert abs(stem.base_axis @ [0, 0, 1]) == 1.0  # the grain runs along z: the z axis is the base
    # The pith runs 16-22 mm outside the block, tilted 3.8 degrees, and bends: its middle sits
    # (1.98, 1.35) mm off the chord between its ends. From three jittered faces the centreline is
    # found within 2.5 mm at the bottom, middle and top (eccentric rings trade ~1-2 mm of pith
    # position against eccentricity), and the bend towards the block within 0.75 mm.
    heights = (0.0, 30.0, 60.0)
    fit = np.array([_pith_at(stem, z) for z in heights])
    true = field.pith(heights)
    assert np.linalg.norm(fit - true, axis=1).max() < 2.5, (fit, true)
    sag = lambda p: (p[0] + p[2]) / 2 - p[1]  # noqa: E731
    assert abs(sag(fit)[0] - sag(true)[0]) < 0.75, (sag(fit), sag(true))
    # the rings inside, on planes no face shows
    acc = evaluate_fit(field, stem, SIZE, pixel_mm=0.3)[0]
    assert acc["matched_1"] > 95.0 and acc["matched_2"] > 99.0, acc
    # the bend is what gets them: the same stem forced straight misses the rings by ~1 mm
    straight = fit_stem(obs, SIZE, curve_prior_mm=1e-3)
    assert abs(sag(np.array([_pith_at(straight, z) for z in heights]))[0]) < 0.01
    acc_straight = evaluate_fit(field, straight, SIZE, pixel_mm=0.3)[0]
    assert acc_straight["matched_1"] < acc["matched_1"] - 20.0, (acc, acc_straight)


def test_stem_needs_labelled_rings(curved):
    _, block = curved
    obs = gather_observations(block, ["front"])
    unl = type(obs)(obs.points_mm, np.full(len(obs.years), np.nan), obs.group, obs.face)
    with pytest.raises(WoodcamError, match="year-labelled"):
        fit_stem(unl, SIZE)
    with pytest.raises(WoodcamError, match="tilt_prior_deg"):
        fit_stem(obs, SIZE, tilt_prior_deg=0.0)


def test_radial_recipe_refits_the_pith_per_fold():
    """Leave-one-face-out must not leak the held-out face into the fit that predicts it.

    A radial hypothesis fitted on every face carries the held-out face in its axis. Simulated
    here by a hypothesis whose axis is 25 degrees off (its shape least-squares fitted to every
    face): the fold's fit on the other five faces must forget where the hypothesis' axis came
    from, so it matches the fold fit of the good hypothesis. The first version kept each radial
    hypothesis' axis (``radial_recipe(field)`` without ``size_mm``): there the fold fits differ
    by 0.24-0.34 year (median over the block), 40x more than with the axis refitted."""
    rng = np.random.default_rng(7)
    block = make_block(random_field(rng), px_per_mm=3.0, rng=rng)
    obs = gather_observations(block)
    good = fit_radial(obs, block.size_mm)
    d = good.axis / np.linalg.norm(good.axis)
    perp = np.cross(d, [0.3, 0.5, 0.8])
    perp /= np.linalg.norm(perp)
    t = np.deg2rad(25.0)
    off = _smoothest_coefficients(obs, RadialField(good.pith_mm + 3 * perp, np.cos(t) * d + np.sin(t) * perp,
                                                   good.z_scale_mm, good.K, good.M, good.coef, good.offset), 0)
    rest = obs.subset(obs.face != 0)
    pts = np.random.default_rng(1).uniform(0, 1, (2000, 3)) * np.asarray(block.size_mm)
    spread = lambda a, b: float(np.median(np.abs(a(pts) - b(pts))))  # noqa: E731
    leaky = spread(radial_recipe(good)(rest), radial_recipe(off)(rest))
    assert leaky > 0.15, leaky  # the leak is visible in this setting
    honest = spread(radial_recipe(good, size_mm=block.size_mm)(rest), radial_recipe(off, size_mm=block.size_mm)(rest))
    assert honest < 0.03, (honest, leaky)


def test_stem_recipe_folds_descend_from_the_all_faces_stem(curved, monkeypatch):
    """The evidence fit's stem recipe fits its first observations (all faces) from scratch and
    each fold by a local descent from that stem (``fit_stem(init=)``, about a quarter of the CPU
    of a fold fitted from scratch: README): the fold's prediction is the from-scratch fold fit's
    (median 0.0 year apart here). Checked by breaking it: without the warm start the fold's
    ``init`` is None."""
    import woodcam.inference.stem as stem_module
    from woodcam.inference.evidence import stem_recipe

    field, block = curved
    obs = gather_observations(block)
    cold_fit = stem_module.fit_stem
    inits = []

    def spy(*args, **kwargs):
        inits.append(kwargs.get("init"))
        return cold_fit(*args, **kwargs)

    monkeypatch.setattr(stem_module, "fit_stem", spy)
    rec = stem_recipe(block.size_mm)
    first = rec(obs)  # all faces: the start of every fold
    rest = obs.subset(obs.face != 0)
    warm = rec(rest)
    assert rec(rest) is warm  # remembered: the bend hypothesis refines this very stem
    assert len(inits) == 2 and inits[0] is None and inits[1] is first, inits
    cold = cold_fit(rest, block.size_mm)
    pts = np.random.default_rng(1).uniform(0, 1, (2000, 3)) * np.asarray(block.size_mm)
    assert float(np.median(np.abs(warm(pts) - cold(pts)))) < 0.05


def test_the_knots_bend_starts_from_a_stem_whose_growth_time_rises_away_from_its_pith():
    """Growth time counts from the pith, and seed 003's bend is a share of the time since it.
    Known answer: the realistic generator's dev seed 9101 block 5 (six noisy faces, knotted),
    whose true pith runs 60.0 mm from the block's centre. Its cheapest stem has a negative mean
    ring density, its pith 140 mm off: every ring point lies "before" that pith, and the bend
    was left out. The bend now starts from the cheapest stem whose growth time rises away from
    its pith (``fit_stem(outward=True)``, ``stem._outward``), which finds the pith within 10 mm
    and bends the rings round the knots (60.9 % within 2 mm on the cut planes, the cheapest stem
    29.5). Checked by breaking it: with ``outward`` ignored the stem's asserts fail (density
    -0.43 rings/mm); with the bend starting from the cheapest stem it is left out (a plain
    StemField comes back)."""
    from woodcam.bench_realistic import FACE_SETS, make_block as bench_block
    from woodcam.fields.knot_strands import StemWithKnots
    from woodcam.inference.knots import fit_knotted_stem, knot_exits
    from woodcam.tolerances import KNOT_BEND_MAX_BEFORE_PITH

    block, _ = bench_block(9101, 5, "noisy", "realistic", 256)
    obs = gather_observations(block, FACE_SETS["full"])
    centre = np.asarray(block.size_mm)[None] / 2
    cheapest = fit_stem(obs, block.size_mm)
    assert cheapest.coef[0] < 0.0  # the situation: c_00, rings per mm at the middle height
    stem = fit_stem(obs, block.size_mm, outward=True)
    assert stem.coef[0] > 0.0, stem.coef[0]
    assert np.mean(stem(obs.points_mm) <= stem.pith_years()) <= KNOT_BEND_MAX_BEFORE_PITH
    assert abs(stem.pith_distance_mm(centre)[0] - 60.0) < 10.0, stem.pith_distance_mm(centre)  # 50.4
    bent = fit_knotted_stem(obs, block.size_mm, knot_exits(block, FACE_SETS["full"]), stem=cheapest, cones=True)
    assert isinstance(bent, StemWithKnots) and any(s.pinned for s in bent.strands)
    acc = {name: evaluate_fit(block.true_field, f, block.size_mm, pixel_mm=0.5)[0]["matched_2"]
           for name, f in (("cheapest", cheapest), ("bent", bent))}
    assert acc["bent"] > acc["cheapest"] + 20.0, acc


def test_fit_stem_refuses_what_is_not_ring_observations():
    with pytest.raises(WoodcamError, match="obs must be RingObservations.*got NoneType"):
        fit_stem(None, (50, 50, 50))
