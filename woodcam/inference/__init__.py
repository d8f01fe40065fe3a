"""Fitting a growth field to a block's ring annotations, and measuring it (seed 000, Table 1).

- :func:`fit_block` ``(block, method, faces) -> field``: ``"evidence"`` (the default) fits
  several hypotheses and keeps the one the held-out faces support (:mod:`.evidence`, with knots
  from the knot masks, :mod:`.knots`); ``"rbf"`` is the seed's baseline,
  ``"radial"`` our least-squares fit of a pith axis and a smooth inverse ring width;
  :func:`fit_stem` the stem model (curved pith near a block axis, ring density by direction,
  height and year: :mod:`.stem`), one of the evidence fit's hypotheses.
  ``"neural"`` the seed's eq. 5 fit of the generic neural field (labelled traces, or ring maps
  with a year-free loss).
- :func:`evaluate_fit` / :func:`benchmark`: share of predicted ring-line points within 1 / 2 mm
  of the true ring line (same year, or any year) on interior cut planes.
- :func:`leave_one_face_out`: for real blocks (no true field), each face predicted from the
  others and scored against its ring map.
"""

from .baked import bake
from .evidence import EvidenceFit, fit_evidence
from .evaluate import DEFAULT_PLANES, CutPlane, benchmark, evaluate_fit, evaluate_fits
from .fit import METHODS, Method, fit_block
from .holdout import leave_one_face_out, score_face
from .observations import RingObservations, gather_observations
from .radial import RadialField, fit_radial, number_observations
from .rbf import fit_rbf
from .residual import fit_face_residual
from .stem import StemField, fit_stem

__all__ = [
    "CutPlane", "DEFAULT_PLANES", "EvidenceFit", "METHODS", "Method", "RadialField",
    "RingObservations", "StemField", "bake", "benchmark", "evaluate_fit", "evaluate_fits", "fit_block", "fit_evidence",
    "fit_face_residual", "fit_radial", "fit_rbf", "fit_stem", "gather_observations", "leave_one_face_out",
    "number_observations", "score_face",
]
