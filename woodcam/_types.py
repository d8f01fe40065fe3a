"""Type aliases and protocols of the public API (annotations only; nothing heavy at import).

- :data:`ArrayLike`: anything numpy turns into an array (``points_mm (n, 3)``, ``size_mm (3,)``...).
- :data:`PathLike`: a file system path.
- :class:`GrowthFieldLike`: ``field(points_mm (n, 3)) -> years (n,)``, the fields' one protocol.
- :data:`Mesh`: a ``trimesh.Trimesh`` (block frame, mm).
- :class:`AppearanceLike`: ``appearance.color(field, points_mm, normals) -> rgb (n, 3)``.
- :class:`WoodLike`: ``wood.color(points_mm (n, 3), normals (n, 3)) -> rgb (n, 3)``, the seam.
- :data:`Camera` / :data:`CAMERAS`: the named views (``woodcam.view.camera``; here so that the
  command line's ``--camera`` offers them without importing the viewer).
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any, Literal, Protocol, Union, get_args

if TYPE_CHECKING:
    import numpy as np
    import trimesh
    from numpy.typing import ArrayLike

    Mesh = trimesh.Trimesh
else:  # numpy and trimesh stay unimported until a function needs them
    ArrayLike = Any
    Mesh = Any

PathLike = Union[str, "os.PathLike[str]"]

Camera = Literal["iso", "top", "front", "back", "left", "right", "bottom"]
CAMERAS: tuple[str, ...] = get_args(Camera)


class GrowthFieldLike(Protocol):
    """A growth-time field: years ``(n,)`` at block-frame points ``(n, 3)`` mm."""

    def __call__(self, points_mm: np.ndarray, /) -> np.ndarray: ...


class AppearanceLike(Protocol):
    """Colours ``(n, 3)`` of a field's wood at points with normals (``Wood``'s appearance)."""

    def color(self, field: GrowthFieldLike, points_mm: np.ndarray, normals: np.ndarray, /) -> np.ndarray: ...


class WoodLike(Protocol):
    """What every consumer of the seam calls: colours ``(n, 3)`` in [0, 1]."""

    def color(self, points_mm: np.ndarray, normals: np.ndarray, /) -> np.ndarray: ...


__all__ = ["AppearanceLike", "ArrayLike", "GrowthFieldLike", "Mesh", "PathLike", "WoodLike"]
