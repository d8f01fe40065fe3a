"""The log-centric log model of seed 001: knots, centreline, surface, generation, fitting.

Frames and units: log frame in mm with ``z`` (= log-centric ``l``) along the log; log-centric
coordinates ``(theta_rad, l_mm, rho_mm)`` around the centreline (see :mod:`.knot`).
"""

from .centreline import Centreline, fit_centreline
from .export import export_log_glb, heightmap_png, read_heightmap_png
from .fit import KnotFit, fit_gran_knots, fit_knot
from .generate import SPRUCE, CompoundGaussian, GeneratedKnot, GeneratedLog, LogStats, generate_log
from .knot import Knot, KnotParams
from .surface import SurfaceBase, SurfaceKnot, Thickness, fit_surface_base, fit_surface_knot, fit_thickness, gabor_noise

__all__ = [
    "Centreline", "CompoundGaussian", "GeneratedKnot", "GeneratedLog", "Knot", "KnotFit", "KnotParams",
    "LogStats", "SPRUCE", "SurfaceBase", "SurfaceKnot", "Thickness", "export_log_glb", "fit_centreline",
    "fit_gran_knots", "fit_knot", "fit_surface_base", "fit_surface_knot", "fit_thickness", "gabor_noise",
    "generate_log", "heightmap_png", "read_heightmap_png",
]
