"""Rings and knots found on face photos: the classical quadrature-filter detector, knot masks,
and scores against reference ring maps. Uses :mod:`woodcam.block`; :mod:`woodcam.inference`
uses it."""

from .rings import RingDetection, detect_rings
from .score import RidgeScore, reference_ridge, ridge_scores

__all__ = ["RidgeScore", "RingDetection", "detect_rings", "reference_ridge", "ridge_scores"]
