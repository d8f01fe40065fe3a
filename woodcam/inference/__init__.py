"""Fitting a growth field to a block's ring annotations, and measuring it (seed 000, Table 1).

- :func:`fit_block` ``(block, method, faces) -> field``: ``"rbf"`` is the seed's baseline,
  ``"radial"`` our least-squares fit of a pith axis and a smooth inverse ring width.
- :func:`evaluate_fit` / :func:`benchmark`: share of predicted ring-line points within 1 / 2 mm
  of the true ring line (same year, or any year) on interior cut planes.
"""

from .baked import bake
from .evaluate import DEFAULT_PLANES, CutPlane, benchmark, evaluate_fit, evaluate_fits
from .fit import METHODS, Method, fit_block
from .observations import RingObservations, gather_observations
from .radial import RadialField, fit_radial
from .rbf import fit_rbf

__all__ = [
    "CutPlane", "DEFAULT_PLANES", "METHODS", "Method", "RadialField",
    "RingObservations", "bake", "benchmark", "evaluate_fit", "evaluate_fits", "fit_block",
    "fit_radial", "fit_rbf", "gather_observations",
]
