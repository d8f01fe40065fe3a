"""Growth-time fields: ``field(points_mm (n, 3)) -> years (n,)`` in the block frame.

Only fields and their input data live here (``LogSkeleton``/``BranchStrand`` for the knot
field); reading, writing, generating and rendering logs is :mod:`woodcam.logs`.
"""

from .analytic import AnalyticLogField
from .base import GrowthField, LogFrame, arf, check_points, evaluate, grain_direction
from .builtin import BUILTIN_NAMES, builtin_block
from .grid import GridField
from .knots import KnotParams, KnottedLogField, block_at_knot
from .placement import PlacedField, place_block_in_log
from .radial import RadialScalingField, RadiusFunction
from .residual import FaceResidual, ResidualField
from .skeleton import BranchStrand, LogSkeleton, simple_log
from .state import field_from_state, field_to_state

__all__ = [
    "AnalyticLogField", "BUILTIN_NAMES", "BranchStrand", "FaceResidual", "GridField", "GrowthField", "KnotParams",
    "KnottedLogField", "LogFrame", "LogSkeleton", "PlacedField", "RadialScalingField",
    "RadiusFunction", "ResidualField", "arf", "block_at_knot", "builtin_block", "check_points", "evaluate",
    "field_from_state", "field_to_state", "grain_direction", "place_block_in_log", "simple_log",
]
