"""Woodification (seed 004): grow any watertight mesh like a tree, and carve from the result.

Growth speed (Weibull, eccentricity, brushes) -> front arrival time on a grid (scikit-fmm, an
exact offset, or woodcam's anisotropic fast marching, with obstacles) -> the grown object's
growth field (:class:`WoodifiedField`, the woodcam field protocol), grown surfaces at any
year with texture carried from the input, ring sections, and bark cracks.
"""

from .brushes import Brush, load_brushes
from .field import WoodifiedField
from .front import Front, VoxelGrid, propagate, sphere_arrival
from .grow import Woodification, woodify
from .speed import GrowthSpeed, weibull_cdf, weibull_cdf_inv, weibull_speed

__all__ = [
    "Brush", "Front", "GrowthSpeed", "VoxelGrid", "Woodification", "WoodifiedField",
    "load_brushes", "propagate", "sphere_arrival", "weibull_cdf", "weibull_cdf_inv",
    "weibull_speed", "woodify",
]
