"""Growth-time fields: ``field(points_mm (n, 3)) -> years (n,)`` in the block frame."""

from .base import GrowthField, LogFrame, arf, check_points, evaluate, grain_direction

__all__ = ["GrowthField", "LogFrame", "arf", "check_points", "evaluate", "grain_direction"]
