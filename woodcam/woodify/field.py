"""The grown object's growth field: years at any point of a block cut out of it.

:class:`WoodifiedField` stores the front's arrival time ``T`` (mm of pseudo-time) on the
woodify grid and maps it to years by the separation of time (:mod:`woodcam.woodify.speed`):
``years = lambda W^-1(T / v)``. It interpolates ``T``, not years: ``T`` is a distance-like,
Lipschitz function, while years have an infinite slope where ``W`` saturates, and the
integer-year iso-surfaces (the rings) then coincide with the grown surfaces of those years.
Years are 0 inside the input object (the "core", which the seed does not grow) and are capped
at the last year the march reached beyond the final surface.

Placement: block-frame points ``p`` (mm, docs/conventions.md) sit at
``block_origin_mm + rotation @ p`` in the object frame (the input mesh's frame, mm), so a block
of ``block_size_mm`` is cut anywhere out of the grown object (:meth:`WoodifiedField.to_object`;
its inverse :meth:`WoodifiedField.to_block` moves the input, modelled in the object frame, to
where it grew in the block).

Engulfed obstacles are no wood: :meth:`WoodifiedField.no_wood` is true inside them, and
:meth:`WoodifiedField.evaluate` reports them as ``dead`` (darkened like dead-knot wood by the
colour map) with an ``outline`` on the scar round them, so a baked part shows the post.
Fibres run along ``stem_axis`` (object frame; by default the input's longest principal axis,
:func:`woodcam.woodify.bark.stem_axis`).

File ``field.npz`` (written atomically): ``arrival_mm`` float32 (nx, ny, nz), ``origin_mm``,
``spacing_mm``, ``speed`` (JSON of :class:`GrowthSpeed`), ``years_final``, ``stem_axis``,
optional ``obstacle_sdf_mm`` float32, ``block_origin_mm``, ``block_rotation``,
``block_size_mm``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike
from scipy import ndimage

from .._atomic import atomic_write
from .._checks import (as_floats, check_bool, check_number, check_path, check_rotation, check_vector, npz_path,
                       received)
from .._readers import read_npz
from .._repr import attrs_repr
from ..errors import WoodcamError
from ..fields.base import LogFrame, check_points
from ..fields.grid import grid_coords
from .speed import GrowthSpeed

Interpolation = Literal["linear", "cubic"]
_ORDER = {"linear": 1, "cubic": 3}
FORMAT = "woodcam-woodify-field-1"

#: Width (mm) of the scar line drawn round an engulfed obstacle in ``evaluate``'s ``outline``.
_SCAR_MM = 0.8


def _block_size(value) -> np.ndarray:
    """A woodified block's ``block_size_mm`` (W, D, H) as floats: three finite sizes > 0. The one
    rule of the constructor and :meth:`WoodifiedField.placed`."""
    size = as_floats(value)
    if size is None or size.shape != (3,) or not np.all(np.isfinite(size)) or np.any(size <= 0):
        raise WoodcamError(f"block_size_mm must be three finite sizes > 0 (W, D, H mm); got {received(value)}")
    return size


class WoodifiedField:
    """Growth time (years) of a grown object at block-frame points (see module docstring).

    Parameters
    ----------
    arrival_mm : (nx, ny, nz) float
        Front arrival time on grid nodes (mm); non-finite entries (never reached) are capped.
    origin_mm : (3,) float
        Object-frame position of node (0, 0, 0).
    spacing_mm : float
        Node spacing (mm).
    speed : GrowthSpeed
    years_final : float
        The last simulated year (for reports; the field answers beyond it).
    obstacle_sdf_mm : (nx, ny, nz) float, optional
        Signed distance to obstacles (negative inside) on the same nodes.
    block_origin_mm, rotation, block_size_mm :
        Placement of the block in the object frame (see module docstring); default: the
        identity (block frame = object frame) and the grid's extent.
    interpolation : "linear" (trilinear, default) or "cubic" (C2 B-spline)
    stem_axis : (3,) float, optional
        Fibre direction in the object frame; default ``speed.up``.
    """

    #: Year 0 is the surface of the mesh the object grew from, not a pith: a part cut next to it
    #: is not warned of checks (:func:`woodcam.fields.base.has_pith`).
    has_pith = False

    def __init__(self, arrival_mm: ArrayLike, origin_mm: ArrayLike, spacing_mm: float,
                 speed: GrowthSpeed, years_final: float, obstacle_sdf_mm: ArrayLike | None = None,
                 block_origin_mm: ArrayLike = (0.0, 0.0, 0.0), rotation: ArrayLike | None = None,
                 block_size_mm: ArrayLike | None = None, interpolation: Interpolation = "linear",
                 stem_axis: ArrayLike | None = None) -> None:
        T = as_floats(arrival_mm)  # 'a' was numpy's bare ValueError, complex its ComplexWarning
        if T is None or T.ndim != 3 or min(T.shape) < 2:
            got = received(arrival_mm) if T is None else T.shape
            raise WoodcamError(f"arrival_mm must be an (nx, ny, nz) grid of real numbers, each >= 2; got {got}")
        if interpolation not in _ORDER:
            raise WoodcamError(f"interpolation must be one of {list(_ORDER)}; got {interpolation!r}")
        finite = np.isfinite(T)
        if not finite.any():
            raise WoodcamError("arrival_mm has no finite value; the front never started")
        self.t_cap_mm = float(T[finite].max())
        self.arrival_mm = np.where(finite, T, self.t_cap_mm).astype(np.float32)
        if not isinstance(speed, GrowthSpeed):  # None was an AttributeError ('years')
            raise WoodcamError(f"speed must be a GrowthSpeed; got {type(speed).__name__}")
        self.origin_mm = check_vector(origin_mm, "origin_mm", fix="the mm position of node (0, 0, 0)")
        # 0 was refused as 'block_size_mm ... got None', a string was float()'s ValueError
        self.spacing_mm = check_number(spacing_mm, "spacing_mm", lo=0, lo_open=True, fix="the grid's node spacing, mm")
        self.speed = speed
        # NaN was kept (a report of 'nan years'), a string float()'s ValueError; a NaN block
        # origin made every year NaN, a zero stem axis numpy's divide warning and a NaN axis
        self.years_final = check_number(years_final, "years_final", lo=0, fix="the last simulated year")
        # beyond the velocity scale the front never arrives (W < 1): cap where W = 1 - 1e-6
        self.years_cap = float(speed.years(min(self.t_cap_mm, speed.velocity_mm * (1 - 1e-6))))
        sdf = None if obstacle_sdf_mm is None else as_floats(obstacle_sdf_mm)
        if obstacle_sdf_mm is not None and (sdf is None or sdf.shape != T.shape):
            raise WoodcamError(f"obstacle_sdf_mm must be the signed distances on the arrival grid's nodes, shape "
                               f"{T.shape}; got "
                               f"{'shape ' + str(sdf.shape) if sdf is not None else repr(obstacle_sdf_mm)[:60]}")
        self.obstacle_sdf_mm = None if sdf is None else sdf.astype(np.float32)
        self.interpolation = interpolation
        self.stem_axis = check_vector(speed.up if stem_axis is None else stem_axis, "stem_axis", unit=True,
                                      fix="the fibre direction in the object frame, or None for speed.up")
        R = np.eye(3) if rotation is None else check_rotation(rotation, "rotation")
        self.rotation = R
        self.block_origin_mm = check_vector(block_origin_mm, "block_origin_mm",
                                            fix="the object-frame position of the block's origin corner")
        extent = (np.asarray(self.arrival_mm.shape) - 1) * self.spacing_mm
        self.block_size_mm = tuple(float(v) for v in _block_size(extent if block_size_mm is None else block_size_mm))
        order = _ORDER[interpolation]
        self._coeffs = (ndimage.spline_filter(self.arrival_mm, order=order, mode="nearest",
                                              output=np.float32) if order > 1 else self.arrival_mm)

    def __repr__(self) -> str:  # arrays as shapes: a notebook shows one line
        return attrs_repr(self, ('arrival_mm', 'origin_mm', 'spacing_mm', 'years_final', 'block_origin_mm',
                                 'block_size_mm', 'interpolation'))

    @property
    def axis(self) -> np.ndarray:
        """Fibre direction (the stem axis) in the block frame, (3,)."""
        return self.rotation.T @ self.stem_axis

    @property
    def object_frame(self) -> LogFrame:
        """The grown object's frame placed in the block frame: its ``to_log`` is
        :meth:`to_object`. Blocks cut anywhere out of the object draw the colour map's texture
        in it (``ColorMapAppearance.texture_frame``), so the same wood has the same colours
        however the block is placed."""
        R = self.rotation
        return LogFrame(tuple(-(R.T @ self.block_origin_mm)), tuple(R[2]), tuple(R[0]))

    def to_object(self, points_mm: ArrayLike) -> np.ndarray:
        """Block-frame points ``(n, 3)`` -> object-frame points ``(n, 3)`` (mm)."""
        p = check_points(points_mm)
        return self.block_origin_mm + np.einsum("ij,kj->ik", p, self.rotation)

    def to_block(self, points_mm: ArrayLike) -> np.ndarray:
        """Object-frame points ``(n, 3)`` -> block-frame points ``(n, 3)`` (mm), the inverse of
        :meth:`to_object`: where the grown input (a part modelled in the object frame) lies in
        the block, so a part baked into its own woodify block sits where it grew."""
        q = check_points(points_mm)
        return (q - self.block_origin_mm) @ self.rotation

    def _sample(self, grid, q, order) -> np.ndarray:
        if order == 1:
            from ._voxel import trilinear

            return trilinear(grid, self.origin_mm, self.spacing_mm, np.ascontiguousarray(q, float))
        idx = grid_coords(q, self.origin_mm, self.spacing_mm, grid.shape)
        return ndimage.map_coordinates(grid, idx, order=order, mode="nearest", prefilter=False)

    def arrival(self, points_mm: ArrayLike) -> np.ndarray:
        """Interpolated arrival time ``T (n,)`` (mm) at block-frame points."""
        return self._sample(self._coeffs, self.to_object(points_mm), _ORDER[self.interpolation])

    def __call__(self, points_mm: ArrayLike) -> np.ndarray:
        """Growth time ``years (n,)`` at ``points_mm (n, 3)`` (block frame, mm)."""
        T = self.arrival(points_mm).astype(float)
        return np.minimum(self.speed.years(T), self.years_cap)

    def no_wood(self, points_mm: ArrayLike) -> np.ndarray:
        """``(n,) bool``: inside an engulfed obstacle (no wood there)."""
        if self.obstacle_sdf_mm is None:
            return np.zeros(len(check_points(points_mm)), bool)
        return self._sample(self.obstacle_sdf_mm, self.to_object(points_mm), 1) < 0

    def evaluate(self, points_mm: ArrayLike, *, directions: bool = False) -> dict:
        """Years with the colour map's knot channels in one pass (see module docstring)."""
        p = check_points(points_mm)
        directions = check_bool(directions, "directions")
        out = {"years": self(p)}
        n = len(p)
        zero = np.zeros(n, np.float32)
        if self.obstacle_sdf_mm is None:
            out["knot"] = out["dead"] = out["outline"] = zero
        else:
            sd = self._sample(self.obstacle_sdf_mm, self.to_object(p), 1)
            # both knot channels: the colour map darkens the obstacle twice, so it reads as
            # foreign matter, not as a knot
            out["knot"] = out["dead"] = (sd < 0).astype(np.float32)
            out["outline"] = ((sd >= 0) & (sd < _SCAR_MM)).astype(np.float32)
        if directions:
            out["direction"] = np.broadcast_to(self.axis, p.shape).astype(np.float32)
        return out

    def grain_direction(self, points_mm: ArrayLike) -> np.ndarray:
        """Unit fibre directions ``(n, 3)``: the stem axis everywhere (block frame)."""
        return np.broadcast_to(self.axis, check_points(points_mm).shape)

    def placed(self, block_size_mm: ArrayLike, block_centre_mm: ArrayLike | None = None,
               rotation: ArrayLike | None = None) -> WoodifiedField:
        """The same grown object with a block of ``block_size_mm`` (W, D, H) centred at
        ``block_centre_mm`` (object frame; default the grid's centre)."""
        # 'abc' and a 2-vector centre were numpy's bare errors, complex its ComplexWarning, an
        # infinite size a NaN origin: the constructor's rules, checked before they are used
        size = _block_size(block_size_mm)
        R = np.eye(3) if rotation is None else check_rotation(rotation, "rotation")
        extent = (np.asarray(self.arrival_mm.shape) - 1) * self.spacing_mm
        c = self.origin_mm + extent / 2 if block_centre_mm is None else check_vector(
            block_centre_mm, "block_centre_mm", fix="the object-frame centre of the block, mm, or None for the grid's")
        return WoodifiedField(self.arrival_mm, self.origin_mm, self.spacing_mm, self.speed,
                              self.years_final, self.obstacle_sdf_mm, c - R @ size / 2, R,
                              tuple(size), self.interpolation, self.stem_axis)

    def save(self, path: str | Path) -> Path:
        """Write ``field.npz`` atomically (temp file in the same folder, then ``os.replace``).
        A ``path`` without the suffix gets ``.npz`` appended; one ending in it in any case
        (``F.NPZ``) is written as named (:func:`woodcam._checks.npz_path`, the rule of every
        ``.npz`` writer). Returns the path written."""
        path = npz_path(path)
        arrays = {"format": FORMAT, "arrival_mm": self.arrival_mm, "origin_mm": self.origin_mm,
                  "spacing_mm": self.spacing_mm, "speed": json.dumps(self.speed.to_dict()),
                  "years_final": self.years_final, "block_origin_mm": self.block_origin_mm,
                  "block_rotation": self.rotation, "block_size_mm": np.asarray(self.block_size_mm),
                  "stem_axis": self.stem_axis}
        if self.obstacle_sdf_mm is not None:
            arrays["obstacle_sdf_mm"] = self.obstacle_sdf_mm
        with atomic_write(path, mkdir=True) as fh:  # a handle: numpy appends .npz to a path not ending in it
            np.savez_compressed(fh, **arrays)
        return path

    @classmethod
    def load(cls, path, interpolation: Interpolation = "linear") -> WoodifiedField:
        """Read a ``field.npz`` written by :meth:`save`."""
        path = check_path(path, "path", fix="pass the path of the field.npz 'woodcam woodify MESH --out DIR' wrote")
        if not path.is_file():
            raise WoodcamError(f"woodify field {str(path)!r} does not exist; write one with "
                               "'woodcam woodify MESH --out DIR' (it writes DIR/field.npz)")
        with read_npz(path, f"a woodcam woodify field ({FORMAT} .npz, written by 'woodcam woodify')",
                      "write it again with 'woodcam woodify MESH --out DIR' (it writes DIR/field.npz)") as z:
            if str(z["format"]) != FORMAT:
                raise ValueError(f"its format is {z['format']!s}")
            return cls(z["arrival_mm"], z["origin_mm"], float(z["spacing_mm"]),
                       GrowthSpeed.from_dict(json.loads(str(z["speed"]))),
                       float(z["years_final"]),
                       z["obstacle_sdf_mm"] if "obstacle_sdf_mm" in z.files else None,
                       z["block_origin_mm"], z["block_rotation"], tuple(z["block_size_mm"]),
                       interpolation, z["stem_axis"])
