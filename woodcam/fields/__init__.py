"""Growth-time fields: ``field(points_mm (n, 3)) -> years (n,)`` in the block frame."""

from .analytic import AnalyticLogField
from .base import GrowthField, LogFrame, arf, check_points, evaluate, grain_direction
from .builtin import BUILTIN_NAMES, builtin_block
from .grid import GridField
from .knot_maps import read_maps, write_maps
from .knots import KnotParams, KnottedLogField, block_at_knot
from .placement import PlacedField, place_block_in_log
from .state import field_from_state, field_to_state
from .radial import RadialScalingField, RadiusFunction
from .tree_data import Knot, Log, log_from_generated, read_gran1, read_log, simple_log, write_log

__all__ = [
    "AnalyticLogField", "BUILTIN_NAMES", "GridField", "GrowthField", "Knot", "KnotParams", "KnottedLogField", "Log",
    "LogFrame", "PlacedField", "RadialScalingField", "RadiusFunction", "arf", "block_at_knot",
    "builtin_block", "check_points", "evaluate", "field_from_state", "field_to_state", "grain_direction",
    "log_from_generated", "place_block_in_log", "read_gran1", "read_log", "read_maps",
    "simple_log", "write_log", "write_maps",
]
