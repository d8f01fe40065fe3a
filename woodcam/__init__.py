"""woodcam: CNC cut preview for solid wood.

Photograph a block, infer its growth rings, carve a part out of it and see the wood on every
surface before a single cut. Lengths are millimetres, growth time is years, points are in the
block frame of ``docs/conventions.md`` (origin bottom-front-left, X width, Y depth, Z up).
"""

from .errors import MissingDependencyError, WoodcamError
from .fields import GrowthField, LogFrame, arf, evaluate, grain_direction
from .frames import FACES, FACE_NORMAL, MOKUME_LETTER, block_to_pixel, pixel_to_block, unfold_cross

__version__ = "0.1.0"

__all__ = [
    "FACES", "FACE_NORMAL", "GrowthField", "LogFrame", "MOKUME_LETTER", "MissingDependencyError",
    "WoodcamError", "arf", "block_to_pixel", "evaluate", "grain_direction", "pixel_to_block",
    "unfold_cross",
]
