"""Cameras of the preview: named view directions and tight framing of a box.

Pure numpy apart from the plotter handed to :func:`set_camera` (any object with
``window_size``, ``camera.view_angle``, ``camera_position`` and ``reset_camera_clipping_range``).
"""

from __future__ import annotations

import numpy as np

from .._types import CAMERAS, Camera
from ..errors import WoodcamError

__all__ = ["CAMERAS", "UNCUT_CAMERAS", "Camera", "check_camera", "default_cut_normal", "frame_camera", "set_camera"]

#: Direction from the focal point to the camera and the camera's up vector, block frame.
#: "iso" looks from front-right-above (the viewer stands at -Y, conventions.md). "top" has +Y
#: up in the picture and "bottom" has -Y up, so both show their face as its face image does.
_CAMERA_VIEW: dict[str, tuple[tuple[float, float, float], tuple[float, float, float]]] = {
    "iso": ((1.0, -1.0, 1.0), (0.0, 0.0, 1.0)),
    "top": ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0)),
    "bottom": ((0.0, 0.0, -1.0), (0.0, -1.0, 0.0)),
    "front": ((0.0, -1.0, 0.0), (0.0, 0.0, 1.0)),
    "back": ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),
    "left": ((-1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
    "right": ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
}

def check_camera(camera: str) -> str:
    if camera not in _CAMERA_VIEW:
        raise WoodcamError(
            f"camera must be one of {', '.join(CAMERAS)}; got {camera!r}"
        )
    return camera



#: Cameras whose picture is uncut unless a cut is asked for (a cut origin or normal given, the
#: interactive plane dragged). Looking straight down or up, the only axis facing the camera is
#: Z, so the default cut was a horizontal one at mid-height: ``--camera bottom`` showed a ring
#: at the middle of a bowl with its foot cut away, ``--camera top`` a flat slab with a pocket
#: tray's pockets cut away; the user who asks for the top or the underside wants to see it.
UNCUT_CAMERAS: tuple[str, ...] = ("top", "bottom")


def default_cut_normal(camera: str, size: np.ndarray) -> np.ndarray:
    """The block's longest axis, among those facing the camera, signed toward the camera: the
    cut a view gets when one is shown (for :data:`UNCUT_CAMERAS` only when asked for)."""
    view = np.asarray(_CAMERA_VIEW[camera][0])
    facing = np.abs(view) > 1e-9
    k = int(np.argmax(np.where(facing, size, -np.inf)))
    n = np.zeros(3)
    n[k] = np.sign(view[k])
    return n


#: Fraction of the picture's half-width and half-height the framed block may fill.
_FRAME_FILL = 0.92


def frame_camera(camera: str, bounds, window_size=(1280, 960), view_angle_deg: float = 30.0):
    """Camera that looks along ``camera``'s direction and frames the box ``bounds`` tightly:
    ``(position (3,), focal point (3,), view up (3,))``, block frame, mm.

    pyvista's ``reset_camera`` frames the bounding sphere, which leaves a flat block small in
    the picture; here the eight corners are projected and the distance and focal point chosen
    so that they fill :data:`_FRAME_FILL` of the picture (perspective, vertical view angle
    ``view_angle_deg``, the window's aspect ratio ``window_size = (width, height)`` px).
    """
    check_camera(camera)
    direction, up = (np.asarray(a, dtype=float) for a in _CAMERA_VIEW[camera])
    b = np.asarray(bounds, dtype=float).reshape(3, 2)
    direction = direction / np.linalg.norm(direction)
    right = np.cross(up, direction)
    right /= np.linalg.norm(right)
    up = np.cross(direction, right)
    bits = (np.arange(8)[:, None] >> np.arange(3)[None, :]) & 1
    corners = b[:, 0] + bits * (b[:, 1] - b[:, 0])               # (8, 3) mm
    width, height = window_size
    tan_y = np.tan(np.radians(view_angle_deg) / 2.0) * _FRAME_FILL
    tan_x = tan_y * width / height
    focal = b.mean(axis=1)
    for _ in range(4):  # distance from the extents, then recentre; converges in a few steps
        q = corners - focal
        along = q @ direction                                    # towards the camera, mm
        x, y = q @ right, q @ up
        dist = float(np.max(along + np.maximum(np.abs(x) / tan_x, np.abs(y) / tan_y)))
        depth = dist - along                                     # (8,) > 0
        sx, sy = x / depth, y / depth                            # tangents on the picture
        shift_x = 0.5 * (sx.max() + sx.min()) * dist
        shift_y = 0.5 * (sy.max() + sy.min()) * dist
        focal = focal + shift_x * right + shift_y * up
    return focal + dist * direction, focal, up


def set_camera(plotter, camera: str, bounds) -> None:
    """Look along the camera's direction and frame the box ``bounds`` tightly
    (:func:`frame_camera` with the plotter's window size and view angle)."""
    position, focal, up = frame_camera(camera, bounds, plotter.window_size,
                                       plotter.camera.view_angle)
    plotter.camera_position = [tuple(position), tuple(focal), tuple(up)]
    plotter.reset_camera_clipping_range()
