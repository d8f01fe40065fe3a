"""Part sources -> manifold in the block frame (mm), and carving the part out of the block.

``load_part(source)`` accepts build123d/cadquery solids, trimesh meshes, manifold3d manifolds
and STEP/STL/OBJ/GLB files or ``.py`` scripts defining ``part``; ``carve(part, size_mm)``
intersects it with the block ``[0, W] x [0, D] x [0, H]``.
"""

from .carve import CarveResult, carve
from .parts import SUPPORTED_SUFFIXES, auto_tolerance_mm, load_part

__all__ = ["CarveResult", "SUPPORTED_SUFFIXES", "auto_tolerance_mm", "carve", "load_part"]
