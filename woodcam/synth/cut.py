"""Cut a block out of a log: a log-frame field placed in the block frame by a sawing pattern."""

from __future__ import annotations

import math
from typing import Literal, get_args

import numpy as np

from .._checks import check_number
from .._types import ArrayLike, GrowthFieldLike
from ..errors import WoodcamError
from ..fields.analytic import AnalyticLogField
from ..fields.base import LogFrame
from ..fields.placement import PlacedField
from ..frames import check_size

SawPattern = Literal["flat-sawn", "quarter-sawn", "rift", "pith-inside"]
PATTERNS: tuple[SawPattern, ...] = get_args(SawPattern)

#: Angle (deg) in the block's XY plane, from +Y towards +X, of the outward radial direction at
#: the block centre for each pattern: flat-sawn puts the rings parallel to the front/back faces,
#: quarter-sawn perpendicular to them, rift at 45 degrees.
_PATTERN_ANGLE_DEG = {"flat-sawn": 0.0, "quarter-sawn": 90.0, "rift": 45.0, "pith-inside": 0.0}


def _rotate(v: np.ndarray, axis: np.ndarray, angle_rad: float) -> np.ndarray:
    """Rodrigues rotation of vector ``v`` about unit ``axis``."""
    return (v * math.cos(angle_rad) + np.cross(axis, v) * math.sin(angle_rad)
            + axis * (axis @ v) * (1 - math.cos(angle_rad)))


def _pith_hits_box(point, direction, size) -> bool:
    """Whether the line ``point + t direction`` passes through the box ``[0, size]``."""
    lo, hi = -np.inf, np.inf
    for i in range(3):
        if abs(direction[i]) < 1e-12:
            if not 0.0 <= point[i] <= size[i]:
                return False
            continue
        a, b = (0.0 - point[i]) / direction[i], (size[i] - point[i]) / direction[i]
        lo, hi = max(lo, min(a, b)), min(hi, max(a, b))
    return lo <= hi


def cut_block(log_field: GrowthFieldLike, size_mm: ArrayLike, pattern: SawPattern = "flat-sawn", *,
              distance_mm: float | None = None,
              azimuth_deg: float = 0.0, height_mm: float = 0.0, angle_deg: float | None = None,
              tilt_deg: float = 0.0, log_frame: LogFrame | None = None) -> PlacedField:
    """Cut a block of ``size_mm`` out of a log: return the log's field in the block frame.

    The pith (log ``z``) runs along block ``+Z`` (top and bottom faces are end grain), tilted
    by ``tilt_deg`` (slope of grain). The block centre sits at distance ``distance_mm`` from
    the pith, at log azimuth ``azimuth_deg`` and log height ``height_mm``; the outward radial
    direction at the block centre points at ``angle_deg`` in the block's XY plane, measured
    from ``+Y`` towards ``+X``, which is what the sawing pattern sets.

    Parameters
    ----------
    log_field : callable ``(n, 3) log-frame mm -> (n,) years``
        Any log-frame field with the pith on its ``z`` axis (knot-free or knotted).
    size_mm : (W, D, H)
    pattern : "flat-sawn" | "quarter-sawn" | "rift" | "pith-inside"
        flat-sawn: rings run along the front/back faces (radial direction +-Y, angle 0);
        quarter-sawn: rings cross the front/back faces at right angles (angle 90);
        rift: at 45 degrees; pith-inside: the pith passes through the block.
    distance_mm : float, optional
        Distance from the pith to the block centre (mm). Default ``1.5 * max(W, D)`` (pith
        outside), 0 for pith-inside. Outside patterns require the pith line to miss the block,
        pith-inside requires it to cross it.
    azimuth_deg, height_mm : float
        Where in the log the block is cut (matters for eccentric or knotted logs).
    angle_deg : float, optional
        Override of the pattern's radial direction angle.
    tilt_deg : float
        Rotation of the pith axis away from +Z about the tangential direction (slope of grain);
        positive leans its upper end along the outward radial direction.
    log_frame : LogFrame, optional
        Give the placement directly instead (any orientation); the other placement arguments
        are then ignored.

    Returns
    -------
    PlacedField
        ``field(points_mm (n, 3) block frame) -> years (n,)``.
    """
    size = check_size(size_mm)
    if pattern not in PATTERNS:
        raise WoodcamError(f"pattern must be one of {', '.join(PATTERNS)}; got {pattern!r}")
    if log_frame is not None:
        if not isinstance(log_frame, LogFrame):  # a tuple was taken and failed at the first call
            raise WoodcamError(f"log_frame must be a woodcam.fields.LogFrame or None; got "
                               f"{type(log_frame).__name__}; pass e.g. LogFrame((50, -60, 0), (0, 0, 1))")
        return PlacedField.from_log_frame(log_field, log_frame)
    W, D, _ = size
    # each number by name: a NaN was refused as the LogFrame's 'pith_point_mm'/'reference'
    # (or, for angle_deg and tilt_deg, as 'the pith inside the block'), a string was math's TypeError
    if distance_mm is None:
        distance_mm = 0.0 if pattern == "pith-inside" else 1.5 * max(W, D)
    distance_mm = check_number(distance_mm, "distance_mm", lo=0, fix="mm from the pith to the block centre")
    azimuth_deg, height_mm, tilt_deg = (check_number(v, name, fix="a finite number, in degrees or mm")
                                        for v, name in ((azimuth_deg, "azimuth_deg"), (height_mm, "height_mm"),
                                                        (tilt_deg, "tilt_deg")))
    if angle_deg is not None:
        angle_deg = check_number(angle_deg, "angle_deg", fix="degrees from +Y towards +X, or None for the pattern's")
    ang = math.radians(_PATTERN_ANGLE_DEG[pattern] if angle_deg is None else angle_deg)
    b_r = np.array([math.sin(ang), math.cos(ang), 0.0])        # outward radial at the centre
    z = np.array([0.0, 0.0, 1.0])
    t = np.cross(z, b_r)                                       # tangential direction
    tilt = math.radians(tilt_deg)
    z, b_r = _rotate(z, t, tilt), _rotate(b_r, t, tilt)
    t = np.cross(z, b_r)
    phi = math.radians(azimuth_deg)
    x_axis = math.cos(phi) * b_r - math.sin(phi) * t           # so that cos(phi) x + sin(phi) y = b_r
    centre = size / 2.0
    pith_point = centre - distance_mm * b_r - height_mm * z
    hits = _pith_hits_box(pith_point, z, size)
    if pattern == "pith-inside" and not hits:
        raise WoodcamError(
            f"pattern 'pith-inside' needs the pith to cross the block; distance_mm={distance_mm:g} "
            f"puts it outside a {W:g} x {D:g} mm section; use distance_mm < {min(W, D) / 2:g}"
        )
    if pattern != "pith-inside" and hits:
        raise WoodcamError(
            f"pattern {pattern!r} needs the pith outside the block; distance_mm={distance_mm:g} puts it "
            f"inside; use distance_mm > {0.5 * math.hypot(W, D):g} or pattern='pith-inside'"
        )
    frame = LogFrame(tuple(pith_point), tuple(z), tuple(x_axis))
    return PlacedField.from_log_frame(log_field, frame)


def random_log_placement(rng: np.random.Generator, pattern: SawPattern, size_mm: ArrayLike,
                         ring_width_range_mm: tuple[float, float] = (1.5, 6.0)) -> tuple[AnalyticLogField, dict]:
    """Draw a knot-free eccentric analytic log and a placement (kwargs of :func:`cut_block`).

    The ring width at the block centre is log-uniform in ``ring_width_range_mm``; it varies
    slowly with radius (``width_slope_per_mm`` within +-0.003 / mm). ``rng``: the generator
    every draw comes from; ``pattern``: the sawing pattern (one of :data:`PATTERNS`);
    ``size_mm``: the block's ``(W, D, H)`` mm.
    """
    W, D, _ = check_size(size_mm)
    half_diag = 0.5 * math.hypot(W, D)
    if pattern == "pith-inside":
        distance = rng.uniform(0.0, 0.3) * min(W, D)
    else:
        distance = half_diag + rng.uniform(5.0, 150.0)
    width = math.exp(rng.uniform(*np.log(ring_width_range_mm)))
    slope = rng.uniform(-0.003, 0.003)
    # width at the block centre: w0 (1 + s d) = width (radius ~ distance; eccentricity ignored)
    slope = max(slope, -0.5 / max(distance + half_diag, 1.0))
    log = AnalyticLogField(
        ring_width_mm=width / (1.0 + slope * distance), width_slope_per_mm=slope,
        eccentricity=rng.uniform(0.0, 0.15), eccentric_azimuth_deg=rng.uniform(0, 360),
        lobe_amplitude=rng.uniform(0.0, 0.025), lobes=int(rng.integers(3, 7)),
        lobe_phase_deg=rng.uniform(0, 360),
    )
    placement = {
        "pattern": pattern, "distance_mm": distance, "azimuth_deg": rng.uniform(0, 360),
        "height_mm": rng.uniform(0, 1000), "tilt_deg": float(np.clip(rng.normal(0, 2.0), -6, 6)),
        "angle_deg": _PATTERN_ANGLE_DEG[pattern] + (rng.uniform(0, 360) if pattern == "pith-inside"
                                                    else rng.uniform(-10, 10)),
    }
    return log, placement


def knot_crosses(field: GrowthFieldLike, size_mm: ArrayLike, n: int = 12) -> bool:
    """True when a knot of ``field`` (block frame, with ``knot_features``) crosses the block
    ``size_mm`` (``(W, D, H)`` mm): some point of an ``n^3`` grid over it has knot weight > 0.5
    (inside the knot wood)."""
    if not hasattr(field, "knot_features"):
        return False
    size = check_size(size_mm)
    axes = [np.linspace(0.0, s, n) for s in size]
    pts = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    return bool(np.any(np.asarray(field.knot_features(pts)["knot"]) > 0.5))


def _place_through_knot(rng: np.random.Generator, log_field, placement: dict, size, fix: str,
                        tries: int = 60):
    """Move ``placement`` (kwargs of :func:`cut_block`) so that a knot of ``log_field`` crosses
    the block: its centre on a random knot's strand, at a random pith distance between the
    block's half diagonal and the knot's end (pith-inside: at the knot's base on the pith).

    Returns ``(block-frame field, placement)``; checked with :func:`knot_crosses` (asserted from
    the true field), raising :class:`WoodcamError` when no knot of the log reaches a block, its
    fix ``fix`` (the caller's own parameters: a set's sizes and knotted share).
    """
    log = getattr(log_field, "log", None)
    if log is None or not getattr(log, "knots", None):
        raise WoodcamError(f"log_fields must return a knotted log field with knots (a .log with "
                           f".knots, e.g. knotted_log_field); got {type(log_field).__name__}")
    W, D, _ = size
    half_diag = 0.5 * math.hypot(W, D)
    # the whole block inside the log where it is thick enough; a log too thin for the block
    # (a big block from a small generated log) keeps its field beyond the bark
    r_out = max(float(log.r_min_mm) - half_diag - 5.0, half_diag + 12.0)
    inside = placement["pattern"] == "pith-inside"
    for _ in range(tries):
        k = int(rng.integers(len(log.knots)))
        kn = log.knots[k]
        if inside:
            r = float(placement["distance_mm"])
            p = log.knot_point(k, [max(r, 2.0)])[0]
        else:
            # block centre at pith distance r_c; the knot reaches its inner half when it ends
            # beyond the block's innermost side (r_c - min(W, D) / 2)
            lo, hi = half_diag + 2.0, min(float(kn.r_end_mm) + 0.5 * min(W, D) - 3.0, r_out)
            if hi <= lo:
                continue
            r_c = rng.uniform(lo, hi)
            p = log.knot_point(k, [min(r_c, float(kn.r_end_mm) - 2.0)])[0]
            r = max(r_c, half_diag + 1.0)  # cut_block measures from the log's z axis
        moved = dict(placement, distance_mm=r, height_mm=float(p[2]),
                     azimuth_deg=math.degrees(math.atan2(p[1], p[0])))
        try:
            field = cut_block(log_field, size, **moved)
        except WoodcamError:  # the curved pith put the block on the wrong side of it
            continue
        if knot_crosses(field, size):
            return field, moved
    raise WoodcamError(f"no knot of this log crosses a {W:g} x {D:g} mm block after {tries} tries; {fix}")
