"""Issue 12 part 4: a regularised residual on top of the smooth stem, kept per region only where
leave-one-face-out among the fit's faces says it predicts (woodcam.inference.residual)."""

import numpy as np
import pytest

from _eq79_blocks import make_block
from test_stem import CurvedStem
from woodcam.frames import FACES
from woodcam.inference import gather_observations
from woodcam.inference.evidence import _years_error_mm, face_score, fit_evidence
from woodcam.inference.residual import FieldPlusResidual, fit_regional_residual
from woodcam.inference.stem import fit_stem

SIZE = (50.0, 45.0, 60.0)


def _wave(p):
    """The known distortion: a 0.3-year plane wave 45 mm long across the grain (every face
    shows it, so neighbouring faces can vouch for it)."""
    p = np.asarray(p, float)
    return 0.3 * np.sin(2 * np.pi * (p[:, 0] + 0.7 * p[:, 1] + 0.5 * p[:, 2]) / 45.0)


class _Wavy:
    def __init__(self):
        self.stem = CurvedStem()
        self.axis = self.stem.axis

    def __call__(self, p):
        return self.stem(p) + _wave(p)


@pytest.fixture(scope="module")
def wavy():
    truth = _Wavy()
    block = make_block(truth, SIZE, px_per_mm=3.0, rng=np.random.default_rng(3), jitter_mm=0.1)
    return truth, gather_observations(block)


def test_residual_recovered_and_predicts_held_out_face(wavy):
    truth, obs = wavy
    held = obs.face == FACES.index("right")
    rest = obs.subset(~held)
    stem = fit_stem(rest, SIZE)
    res = fit_regional_residual(rest, stem, SIZE)
    assert res.kept >= 8, res.kept  # of 64 regions: most of them have no ring point near
    p, y = obs.points_mm[held], obs.years[held]
    before = face_score(_years_error_mm(stem, p, y))
    after = face_score(_years_error_mm(FieldPlusResidual(stem, res), p, y))
    # measured 87.1 -> 97.4 % (mean of the shares within 1 and 2 mm) on the face no fit saw
    assert after > before + 5.0, (before, after)
    # what it adds is the stem's miss of the true field there, not noise
    miss = truth(p) - stem(p)
    assert np.corrcoef(miss, res(p))[0, 1] > 0.5
    assert np.sqrt(np.mean((miss - res(p)) ** 2)) < 0.8 * np.sqrt(np.mean(miss ** 2))


def test_residual_rejected_on_clear_block():
    clear = CurvedStem(ecc=0.0, curv=(0.0, 0.0))  # the stem model's own family: nothing to add
    obs = gather_observations(make_block(clear, SIZE, px_per_mm=3.0, rng=np.random.default_rng(3),
                                         jitter_mm=0.1))
    stem = fit_stem(obs, SIZE)
    res = fit_regional_residual(obs, stem, SIZE)
    # the gate keeps at most a stray region (measured 1 of 64, 0.07 year at most) ...
    assert res.kept <= 2, res.kept
    assert np.abs(res(obs.points_mm)).max() < 0.1
    # ... where, without the gate, every region with points would correct the jitter
    open_gate = fit_regional_residual(obs, stem, SIZE, min_gain_mm=-np.inf)
    assert open_gate.kept > 20 * max(res.kept, 1)


def test_evidence_offers_regional_residual(wavy):
    """The evidence fit judges "stem + regional residual" like any other hypothesis."""
    _, obs = wavy
    ev = fit_evidence(obs, SIZE, candidates=("radial", "stem", "regional"), warn=False)
    assert "stem + regional residual" in ev.scores and "radial + regional residual" in ev.scores
    assert ev.scores["stem + regional residual"]["mean"] > ev.scores["stem"]["mean"] + 2.0, ev.scores
