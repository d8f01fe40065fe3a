"""A field defined in a log's own frame, seen from a block placed anywhere in that log.

``PlacedField(log_field, origin_mm, rotation)`` answers block-frame points: a block point ``p``
sits at ``origin_mm + rotation @ p`` in the log frame (mm). ``rotation (3, 3)`` is proper
(orthonormal, det +1); its columns are the block's X, Y, Z axes in the log frame. Fibre
directions, knot features and the one-pass ``evaluate`` of knotted fields are forwarded, with
directions rotated back into the block frame.

The placement itself is a :class:`~woodcam.fields.base.LogFrame`, the one rigid-placement type
(the radial family places its log the same way): ``PlacedField`` is a log-frame field plus a
``LogFrame``, and only keeps ``(origin_mm, rotation)`` as a second way to state it.
"""

from __future__ import annotations

import numpy as np

from .._checks import as_floats, check_rotation
from .._repr import attrs_repr
from .._types import ArrayLike, GrowthFieldLike
from ..errors import WoodcamError
from .base import LogFrame, check_points, grain_direction
from .state import field_from_state, field_to_state


class PlacedField:
    """A log-frame growth field in block coordinates (see module docstring).

    Parameters
    ----------
    log_field : growth field
        ``(n, 3)`` log-frame points (mm) -> ``years (n,)``.
    origin_mm : (3,) float
        Where the block origin (its bottom-front-left corner) sits in the log frame, mm.
    rotation : (3, 3) float, optional
        Proper rotation whose columns are the block's X, Y, Z axes in the log frame: block
        point ``p`` sits at ``origin_mm + rotation @ p`` in the log; default the identity.

    Calling it with block-frame points ``(n, 3)`` mm gives ``years (n,)``; ``grain_direction``
    answers unit ``(n, 3)`` directions in the block frame.
    """

    def __init__(self, log_field: GrowthFieldLike, origin_mm: ArrayLike = (0.0, 0.0, 0.0),
                 rotation: ArrayLike | None = None):
        if not callable(log_field):
            raise WoodcamError(
                f"log_field must be callable (n, 3) mm -> years; got {type(log_field).__name__}")
        # a string was numpy's bare ValueError
        R = np.eye(3) if rotation is None else check_rotation(rotation, "rotation")
        o = as_floats(origin_mm)
        if o is None or o.shape != (3,):
            raise WoodcamError(f"origin_mm must be a 3-vector (mm, log frame); got {origin_mm!r:.80}")
        self.log_field = log_field
        # rows of R are the log's axes in block coordinates; the pith passes through the block
        # point that maps to the log origin: origin + R p = 0
        self.frame = LogFrame(tuple(-(R.T @ o)), tuple(R[2]), tuple(R[0]))

    def __repr__(self) -> str:  # arrays as shapes: a notebook shows one line
        return attrs_repr(self, ('log_field', 'frame'))

    @classmethod
    def from_log_frame(cls, log_field, frame: LogFrame) -> "PlacedField":
        """Place with a :class:`LogFrame` (the log's frame given in the block frame)."""
        if not callable(log_field):
            raise WoodcamError(
                f"log_field must be callable (n, 3) mm -> years; got {type(log_field).__name__}")
        out = cls.__new__(cls)
        out.log_field, out.frame = log_field, frame
        return out

    @property
    def rotation(self) -> np.ndarray:
        """(3, 3): block point ``p`` sits at ``origin_mm + rotation @ p`` in the log frame."""
        return self.frame.rotation

    @property
    def origin_mm(self) -> np.ndarray:
        """(3,) mm: where the block origin sits in the log frame."""
        return -(self.frame.rotation @ np.asarray(self.frame.pith_point_mm, float))

    @property
    def axis(self) -> np.ndarray:
        """The log's z axis (the pith direction of a straight log) in the block frame, (3,)."""
        return self.rotation[2].copy()

    def to_log(self, points_mm: ArrayLike) -> np.ndarray:
        """Block-frame points ``(n, 3)`` -> log-frame points ``(n, 3)`` (mm)."""
        return self.frame.to_log(points_mm)

    def _to_block_dirs(self, d) -> np.ndarray:
        return self.frame.direction_to_block(d)

    def __call__(self, points_mm: ArrayLike) -> np.ndarray:
        return np.asarray(self.log_field(self.to_log(points_mm)), dtype=float)

    def grain_direction(self, points_mm: ArrayLike) -> np.ndarray:
        """Unit fibre directions ``(n, 3)`` in the block frame."""
        p = check_points(points_mm)
        if not callable(getattr(self.log_field, "grain_direction", None)):
            return np.broadcast_to(self._to_block_dirs(grain_direction(self.log_field, p[:1]))[0], p.shape)
        return self._to_block_dirs(self.log_field.grain_direction(self.to_log(p)))

    def __getattr__(self, name):
        # Forward the optional knotted-field API only when the wrapped field has it, so
        # ``hasattr(placed, "knot_features")`` tells the truth to appearances.
        if name in ("knot_features", "evaluate") and "log_field" in self.__dict__:
            inner = getattr(self.log_field, name)  # AttributeError when absent
            if name == "knot_features":
                return lambda points_mm: inner(self.to_log(points_mm))

            def evaluate(points_mm, *, directions: bool = False):
                out = inner(self.to_log(points_mm), directions=directions)
                if directions:
                    out["direction"] = self._to_block_dirs(out["direction"])
                return out
            return evaluate
        raise AttributeError(name)

    def to_dict(self) -> dict:
        f = self.frame
        return {"log_field": field_to_state(self.log_field),
                "frame": {"pith_point_mm": [float(v) for v in f.pith_point_mm],
                          "axis": [float(v) for v in f.axis],
                          "reference": None if f.reference is None else [float(v) for v in f.reference]}}

    @classmethod
    def from_dict(cls, d: dict) -> "PlacedField":
        log_field = field_from_state(d["log_field"])
        if "frame" not in d:  # written before the placement became a LogFrame
            return cls(log_field, d["origin_mm"], d["rotation"])
        f = d["frame"]
        ref = f.get("reference")
        return cls.from_log_frame(log_field, LogFrame(tuple(f["pith_point_mm"]), tuple(f["axis"]),
                                                      None if ref is None else tuple(ref)))


def place_block_in_log(log_field: GrowthFieldLike, origin_mm: ArrayLike,
                       rotation: ArrayLike | None = None) -> PlacedField:
    """Place a block in a log: block point ``p`` sits at ``origin_mm + rotation @ p`` (log
    frame, mm). ``log_field``: the log's growth field, called with log-frame points
    (``(n, 3) mm -> (n,) years``); ``rotation``: ``(3, 3)``, default the identity. See
    :class:`PlacedField`."""
    return PlacedField(log_field, origin_mm, rotation)
