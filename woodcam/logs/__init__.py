"""Logs: the log-centric model of seed 001 (knots, centreline, surface, generation, fitting),
reading and writing logs (the CT-measured spruce log, log files, the seed-003 image maps) and
section renders. A log becomes the knot field's input through ``GeneratedLog.to_skeleton`` or
the readers, which return :class:`woodcam.fields.skeleton.LogSkeleton`.

Frames and units: log frame in mm with ``z`` (= log-centric ``l``) along the log; log-centric
coordinates ``(theta_rad, l_mm, rho_mm)`` around the centreline (see :mod:`.knot`).
"""

from .centreline import Centreline, fit_centreline
from .export import export_log_glb, heightmap_png, read_heightmap_png
from .fit import KnotFit, fit_gran_knots, fit_knot
from .generate import SPRUCE, CompoundGaussian, GeneratedKnot, GeneratedLog, LogStats, generate_log
from .io import read_gran1, read_log, write_log
from .knot import Knot, KnotShape
from .maps import read_maps, write_maps
from .surface import SurfaceBase, SurfaceKnot, Thickness, fit_surface_base, fit_surface_knot, fit_thickness, gabor_noise

__all__ = [
    "Centreline", "CompoundGaussian", "GeneratedKnot", "GeneratedLog", "Knot", "KnotFit", "KnotShape",
    "LogStats", "SPRUCE", "SurfaceBase", "SurfaceKnot", "Thickness", "export_log_glb", "fit_centreline",
    "fit_gran_knots", "fit_knot", "fit_surface_base", "fit_surface_knot", "fit_thickness", "gabor_noise",
    "generate_log", "heightmap_png", "read_gran1", "read_heightmap_png", "read_log", "read_maps",
    "write_log", "write_maps",
]
