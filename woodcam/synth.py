"""Synthetic blocks: cut a block out of a log, render its six faces, trace its rings.

Everything is in the block frame of ``docs/conventions.md`` (mm, origin bottom-front-left, X
width, Y depth, Z up) unless a name says ``log``: the log frame has ``z`` on the pith.

- :func:`cut_block` places a log-frame growth field (any callable ``(n, 3) mm -> years``, pith
  on the log's ``z`` axis) in a block frame for a sawing pattern, giving a block-frame field.
- :func:`synth_block` renders a :class:`~woodcam.block.Block` from a block-frame field: face
  photos (an appearance's ``color(points, normals)`` plus camera noise), ring traces on the
  integer iso-lines of the field (refined onto them with Newton steps on the field itself),
  Mokume-like ring maps, and the true field. Knobs degrade the annotation like a human would.
- :func:`synth_benchmark_set` writes a reproducible set of such blocks to disk.

The growth-time field (GTF) gives years since the pith; ring boundaries are its integer
iso-surfaces and ``ARF = (GTF mod 1)^2`` (eq. 6 of seed 000).
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Literal, get_args

import numpy as np

from .block import Block, Face, RingTrace
from .block.io import write_block
from .errors import WoodcamError
from .fields.base import LogFrame, arf, check_points, evaluate, grain_direction
from .fields.placement import PlacedField
from .fields.state import field_from_state, field_to_state
from .frames import FACE_NORMAL, FACES, CrossLayout, check_face, check_size, face_image_size_mm, pixel_to_block
from .tolerances import TRACE_FD_STEP_PX, TRACE_ISO_TOL_YEARS

SawPattern = Literal["flat-sawn", "quarter-sawn", "rift", "pith-inside"]
PATTERNS: tuple[SawPattern, ...] = get_args(SawPattern)

#: Angle (deg) in the block's XY plane, from +Y towards +X, of the outward radial direction at
#: the block centre for each pattern: flat-sawn puts the rings parallel to the front/back faces,
#: quarter-sawn perpendicular to them, rift at 45 degrees.
_PATTERN_ANGLE_DEG = {"flat-sawn": 0.0, "quarter-sawn": 90.0, "rift": 45.0, "pith-inside": 0.0}


# -- fields ---------------------------------------------------------------------------------------

@dataclass(frozen=True)
class AnalyticLogField:
    """A knot-free log in its own frame (mm; ``z`` on the pith), as a growth-time field.

    Rings are slightly eccentric, slightly lobed and have a ring width that varies slowly with
    the distance from the pith::

        r_eff = r (1 - e cos(theta - theta_e)) (1 + a cos(k theta + phi))
        w(r)  = w0 (1 + s r_eff)                      ring width (mm) at radius r_eff
        years = ln(1 + s r_eff) / (w0 s)   (= r_eff / w0 when s = 0)

    so ``d years / d r_eff = 1 / w(r_eff)``. Years are 0 on the pith.

    Parameters
    ----------
    ring_width_mm : float
        ``w0``, ring width at the pith (mm).
    width_slope_per_mm : float
        ``s``: relative change of ring width per mm of radius; ``1 + s r`` is clamped at 0.05
        for negative ``s`` far from the pith.
    eccentricity, eccentric_azimuth_deg : float
        ``e`` in [0, 0.5): rings are wider towards ``theta_e``.
    lobe_amplitude, lobes, lobe_phase_deg : float, int, float
        ``a``, ``k``, ``phi``: non-circular rings.
    """

    ring_width_mm: float = 3.0
    width_slope_per_mm: float = 0.0
    eccentricity: float = 0.0
    eccentric_azimuth_deg: float = 0.0
    lobe_amplitude: float = 0.0
    lobes: int = 3
    lobe_phase_deg: float = 0.0

    #: Fibre direction in the log frame (straight stem).
    axis = (0.0, 0.0, 1.0)

    def __post_init__(self):
        if not self.ring_width_mm > 0:
            raise WoodcamError(f"ring_width_mm must be > 0 mm; got {self.ring_width_mm!r}")
        if not 0 <= self.eccentricity < 0.5:
            raise WoodcamError(f"eccentricity must be in [0, 0.5); got {self.eccentricity!r}")
        if not 0 <= self.lobe_amplitude < 0.5:
            raise WoodcamError(f"lobe_amplitude must be in [0, 0.5); got {self.lobe_amplitude!r}")

    def __call__(self, points_log_mm) -> np.ndarray:
        """Growth time ``(n,)`` in years at log-frame points ``(n, 3)`` mm."""
        p = check_points(points_log_mm, "points_log_mm")
        x, y = p[:, 0], p[:, 1]
        r = np.hypot(x, y)
        th = np.arctan2(y, x)
        r_eff = r * (1.0 - self.eccentricity * np.cos(th - math.radians(self.eccentric_azimuth_deg)))
        r_eff *= 1.0 + self.lobe_amplitude * np.cos(self.lobes * th + math.radians(self.lobe_phase_deg))
        s = self.width_slope_per_mm
        if abs(s) < 1e-12:
            return r_eff / self.ring_width_mm
        return np.log(np.maximum(1.0 + s * r_eff, 0.05)) / (self.ring_width_mm * s)

    def ring_width_at(self, radius_mm: float) -> float:
        """Ring width (mm) at ``radius_mm`` from the pith (ignoring eccentricity and lobes)."""
        return self.ring_width_mm * max(1.0 + self.width_slope_per_mm * radius_mm, 0.05)

    def to_dict(self) -> dict:
        return {k: getattr(self, k) for k in self.__dataclass_fields__}

    @classmethod
    def from_dict(cls, d: dict) -> "AnalyticLogField":
        return cls(**d)


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


def cut_block(log_field, size_mm, pattern: SawPattern = "flat-sawn", *, distance_mm: float | None = None,
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
        return PlacedField.from_log_frame(log_field, log_frame)
    W, D, _ = size
    if distance_mm is None:
        distance_mm = 0.0 if pattern == "pith-inside" else 1.5 * max(W, D)
    if distance_mm < 0:
        raise WoodcamError(f"distance_mm must be >= 0; got {distance_mm!r}")
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


#: Line width (mm) of the Mokume U-Net ring maps as ``sigma`` of ``exp(-(d / sigma)^2)``:
#: their lines are 5.1-5.9 px wide at half maximum on 256 px faces of ~50 mm cubes
#: (measured on H11 and CN03 face E), and FWHM = 1.665 sigma -> sigma ~ 3.2 px ~ 0.62 mm.
MOKUME_RING_SIGMA_MM = 0.62


# -- rendering ------------------------------------------------------------------------------------

_EARLYWOOD = np.array([0.88, 0.73, 0.56])
_LATEWOOD = np.array([0.66, 0.45, 0.27])


class _BuiltinWood:
    """Built-in appearance (used when no ``wood`` is given): ``color(points_mm, normals)``.

    Earlywood -> latewood by the field's ARF (eq. 6 of seed 000) with a smooth latewood band
    over about the last 30 % of each ring, a per-ring tone, end grain (|fibre . normal| near 1)
    a little darker, and a fibre texture: smooth 3-D noise stretched along the fibres
    (``_FIBRE_SCALES_MM``: streaks on side grain, pores on end grain). All random parts are
    drawn once per block, so the six faces agree where they meet.
    """

    #: (across-fibre, along-fibre) noise scales (mm) and weights of the fibre texture octaves.
    _FIBRE_SCALES_MM = ((0.22, 6.0, 0.6), (0.9, 25.0, 0.4))
    _FIBRE_AMPLITUDE = 0.05

    def __init__(self, field, rng: np.random.Generator, lattice: int = 64):
        self.field = field
        self.phase = rng.uniform(0, 2 * np.pi)
        self.lattice = [rng.standard_normal((lattice,) * 3).astype(np.float32) for _ in self._FIBRE_SCALES_MM]
        self.offsets = rng.uniform(0, lattice, (len(self._FIBRE_SCALES_MM), 3))

    def _fibre_texture(self, p: np.ndarray, fib: np.ndarray) -> np.ndarray:
        from scipy.ndimage import map_coordinates

        along = (p * fib).sum(1, keepdims=True)
        tex = np.zeros(len(p))
        for (l_across, l_along, w), grid, off in zip(self._FIBRE_SCALES_MM, self.lattice, self.offsets):
            # stretched coordinates: 1 cell = l_across across the fibres, l_along along them
            q = p / l_across - (1.0 / l_across - 1.0 / l_along) * along * fib + off
            tex += w * map_coordinates(grid, q.T, order=1, mode="grid-wrap")
        return tex

    def color(self, points_mm, normals, years=None, years_per_px=None) -> np.ndarray:
        """rgb ``(n, 3)`` in [0, 1] at ``points_mm (n, 3)`` with outward ``normals (n, 3)``.

        ``years (n,)`` may be passed when already evaluated; ``years_per_px (n,)``, the growth
        time spanned by one pixel, anti-aliases the latewood -> earlywood step at each ring
        boundary (a box filter: the step becomes a one-pixel ramp).
        """
        p = check_points(points_mm)
        years = evaluate(self.field, p) if years is None else years
        fib = np.asarray(grain_direction(self.field, p), dtype=float)
        end_grain = np.abs((fib * np.asarray(normals, float)).sum(1))
        a = arf(years)                                  # (years mod 1)^2
        x = np.clip((a - 0.3) / 0.5, 0.0, 1.0)         # latewood band: about the last 30 % of a ring
        late = x * x * (3.0 - 2.0 * x)                  # smoothstep
        if years_per_px is not None:
            frac = years - np.floor(years)
            w = np.maximum(np.asarray(years_per_px, float), 1e-6)
            # box filter of the pixel [frac - w/2, frac + w/2] across the step at the boundary:
            # the part past it is earlywood (late = 0), the part before a ring's start is the
            # previous ring's latewood (late ~ 1)
            before = np.clip((1.0 - frac) / w + 0.5, 0.0, 1.0)
            prev = np.clip(0.5 - frac / w, 0.0, 1.0)
            late = late * before * (1.0 - prev) + prev
        ring = np.floor(years)
        tone = 1.0 + 0.04 * np.sin(ring * 2.399 + self.phase)   # per-ring brightness
        tex = 1.0 + self._FIBRE_AMPLITUDE * self._fibre_texture(p, fib)
        rgb = _EARLYWOOD + late[:, None] * (_LATEWOOD - _EARLYWOOD)
        rgb = rgb * (tone * tex * (1.0 - 0.15 * end_grain))[:, None]
        return np.clip(rgb, 0.0, 1.0)


def _camera(rgb: np.ndarray, rng: np.random.Generator, noise: float, variation: float,
            blur_px: float = 0.0) -> np.ndarray:
    """Photograph an ``(h, w, 3)`` float image: lens blur (Gaussian, ``blur_px``), exposure and
    white balance, vignetting, sensor noise; returns uint8."""
    from scipy.ndimage import gaussian_filter

    h, w, _ = rgb.shape
    out = gaussian_filter(rgb, (blur_px, blur_px, 0), mode="nearest") if blur_px > 0 else rgb
    if variation > 0:
        gain = 1.0 + variation * rng.standard_normal() + variation * 0.3 * rng.standard_normal(3)
        rr, cc = np.meshgrid(np.linspace(-1, 1, h), np.linspace(-1, 1, w), indexing="ij")
        centre = rng.uniform(-0.3, 0.3, 2)
        vignette = 1.0 - 2.0 * variation * rng.uniform(0.5, 1.5) * ((rr - centre[0]) ** 2 + (cc - centre[1]) ** 2) / 2
        out = out * gain * vignette[..., None]
    if noise > 0:
        out = out + noise * rng.standard_normal(out.shape)
    return np.clip(np.round(out * 255.0), 0, 255).astype(np.uint8)


def _ring_map(g: np.ndarray, sigma_px: float, noise: float, rng: np.random.Generator) -> np.ndarray:
    """Mokume-like ring map ``(h, w)`` float32 in [0, 1]: ``exp(-(d / sigma)^2)`` plus noise.

    ``d = |g - round(g)| / |grad g|`` is the pixel distance to the nearest integer iso-line
    (first-order estimate from the growth-time image ``g`` sampled at pixel centres).
    """
    gr, gc = np.gradient(g)
    grad = np.hypot(gr, gc)
    d = np.abs(g - np.round(g)) / np.maximum(grad, 1e-9)
    m = np.exp(-((d / sigma_px) ** 2))
    if noise > 0:
        m = m + noise * rng.standard_normal(m.shape)
    return np.clip(m, 0.0, 1.0).astype(np.float32)


def _face_points(face, shape, size) -> np.ndarray:
    """Block points ``(rows * cols, 3)`` of a face's pixel centres, row-major.

    Same as :func:`woodcam.frames.face_pixel_points` (the map is affine in ``(row, col)``),
    built by broadcasting to avoid a slow BLAS matmul on (n, 2) x (2, 3).
    """
    p0 = pixel_to_block(face, 0.0, 0.0, shape, size)
    dr = pixel_to_block(face, 1.0, 0.0, shape, size) - p0
    dc = pixel_to_block(face, 0.0, 1.0, shape, size) - p0
    r = np.arange(shape[0], dtype=float)[:, None, None]
    c = np.arange(shape[1], dtype=float)[None, :, None]
    return (p0 + r * dr + c * dc).reshape(-1, 3)


def _refine(field, face, shape, size, rc: np.ndarray, level: np.ndarray, iters: int = 4):
    """Move pixel points ``rc (n, 2)`` onto the iso-lines ``field = level (n,)`` of the face.

    Newton steps along the in-face gradient of the field itself (central differences of
    :data:`TRACE_FD_STEP_PX` px), each step clamped to 1 px. Returns ``(rc, residual_years)``.
    """
    h = TRACE_FD_STEP_PX
    n = len(rc)
    offs = np.array([[0, 0], [h, 0], [-h, 0], [0, h], [0, -h]], float)
    for it in range(iters + 1):
        q = (rc[None, :, :] + offs[:, None, :]).reshape(-1, 2)
        v = evaluate(field, pixel_to_block(face, q[:, 0], q[:, 1], shape, size)).reshape(5, n)
        res = v[0] - level
        if it == iters:
            break
        grad = np.stack([(v[1] - v[2]) / (2 * h), (v[3] - v[4]) / (2 * h)], axis=1)
        g2 = np.maximum((grad ** 2).sum(1), 1e-18)
        step = -(res / g2)[:, None] * grad
        norm = np.linalg.norm(step, axis=1, keepdims=True)
        rc = rc + step * np.minimum(1.0, 1.0 / np.maximum(norm, 1e-18))
    return rc, res


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Half-open index ranges of the True runs of a 1-D bool mask."""
    d = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)))


def _trace_face(field, face, shape, size, g: np.ndarray) -> list[RingTrace]:
    """Clean traces of the integer iso-lines of ``field`` on one face (pixel coordinates).

    Marching squares (contourpy) on ``g``, the field sampled at pixel centres, gives polylines
    within ``[0, n - 1]`` px (half a pixel short of the face edges); :func:`_refine` then moves
    every vertex onto the true iso-line. Vertices that do not converge (a kink of the field,
    e.g. where a knot meets the stem, or a vanishing gradient) or leave the face are dropped and
    the polyline is split there.
    """
    import contourpy  # marching squares: maintained, C++, a core dependency

    # Ring boundaries are the iso-lines years = 1, 2, ...; years = 0 is the pith itself.
    lo, hi = max(1, math.ceil(np.nanmin(g))), math.floor(np.nanmax(g))
    if hi < lo:
        return []
    gen = contourpy.contour_generator(z=g, line_type=contourpy.LineType.Separate)
    lines, levels = [], []
    for year in range(lo, hi + 1):
        for xy in gen.lines(year):
            if len(xy) >= 2:
                lines.append(xy[:, ::-1].astype(float))   # contourpy gives (x=col, y=row)
                levels.append(year)
    if not lines:
        return []
    counts = np.array([len(a) for a in lines])
    rc = np.concatenate(lines)
    lev = np.repeat(np.array(levels, float), counts)
    rc, res = _refine(field, face, shape, size, rc, lev)
    inside = ((rc[:, 0] >= -0.5) & (rc[:, 0] <= shape[0] - 0.5)
              & (rc[:, 1] >= -0.5) & (rc[:, 1] <= shape[1] - 0.5))
    ok = inside & (np.abs(res) < TRACE_ISO_TOL_YEARS)
    traces = []
    start = 0
    for k, year in zip(counts, levels):
        seg, good = rc[start:start + k], ok[start:start + k]
        start += k
        for a, b in _runs(good):
            if b - a >= 2:
                traces.append(RingTrace(seg[a:b].copy(), int(year)))
    return traces


def _arc_mm(p: np.ndarray, px_mm: tuple[float, float]) -> np.ndarray:
    """Cumulative arc length (mm) along a pixel polyline ``p (k, 2)``."""
    d = np.diff(p, axis=0) * np.asarray(px_mm)
    return np.concatenate([[0.0], np.cumsum(np.hypot(d[:, 0], d[:, 1]))])


def _dropout(traces, px_mm, fraction: float, chunk_mm: float, rng) -> list[RingTrace]:
    """Remove random pieces of ``chunk_mm`` arc length, each with probability ``fraction``."""
    out = []
    for t in traces:
        s = _arc_mm(t.points_px, px_mm)
        chunk = np.floor(s / chunk_mm + rng.uniform()).astype(int)
        keep = rng.uniform(size=chunk.max() + 1) >= fraction
        for a, b in _runs(keep[chunk]):
            if b - a >= 2:
                out.append(RingTrace(t.points_px[a:b], t.year))
    return out


def _jitter(traces, px_mm, sigma_mm: float, corr_mm: float, rng) -> list[RingTrace]:
    """Move every vertex along the trace's normal by Gaussian noise of std ``sigma_mm``.

    The noise is smoothed along the trace with a Gaussian of ``corr_mm`` (a hand wobbles, it
    does not shake) and rescaled so its marginal std stays ``sigma_mm``.
    """
    from scipy.ndimage import gaussian_filter1d

    scale = np.asarray(px_mm)
    out = []
    for t in traces:
        p_mm = t.points_px * scale
        tan = np.gradient(p_mm, axis=0)
        nrm = np.stack([-tan[:, 1], tan[:, 0]], axis=1)
        nrm /= np.maximum(np.linalg.norm(nrm, axis=1, keepdims=True), 1e-12)
        e = rng.standard_normal(len(p_mm))
        if corr_mm > 0 and len(p_mm) > 2:
            step = max(_arc_mm(t.points_px, px_mm)[-1] / (len(p_mm) - 1), 1e-9)
            s = corr_mm / step
            imp = np.zeros(int(8 * s) | 1)
            imp[len(imp) // 2] = 1.0
            kern = gaussian_filter1d(imp, s, mode="constant")
            e = gaussian_filter1d(e, s, mode="reflect") / math.sqrt(max((kern ** 2).sum(), 1e-12))
        out.append(RingTrace((p_mm + (sigma_mm * e)[:, None] * nrm) / scale, t.year))
    return out


def _check_fraction(name: str, value: float) -> float:
    if not 0.0 <= value <= 1.0:
        raise WoodcamError(f"{name} must be a fraction in [0, 1]; got {value!r}")
    return float(value)


def synth_block(field, size_mm, *, wood=None, px_per_mm: float | None = None, face_px: int = 512,
                faces=FACES, trace_faces=None, ring_map_faces=None,
                trace_dropout: float = 0.0, trace_dropout_chunk_mm: float = 3.0,
                trace_jitter_mm: float = 0.0, trace_jitter_corr_mm: float = 1.0,
                mislabel_fraction: float = 0.0, unlabelled_fraction: float = 0.0,
                photo_noise: float = 0.012, photo_variation: float = 0.03, photo_blur_px: float = 0.6,
                ring_map_sigma_px: float | None = None, ring_map_noise: float = 0.02,
                knot_masks: bool = True, seed: int = 0, rng: np.random.Generator | None = None,
                name: str = "synthetic", meta: dict | None = None) -> Block:
    """Render a synthetic :class:`Block` from a growth field placed in the block frame.

    Parameters
    ----------
    field : callable ``(n, 3) block mm -> (n,) years``
        The true growth-time field (e.g. from :func:`cut_block`); kept as ``block.true_field``.
    size_mm : (W, D, H)
    wood : object with ``color(points_mm (n, 3), normals (n, 3)) -> (n, 3) float [0, 1]``, optional
        The appearance (``woodcam.appearance.Wood``); it should wrap the same ``field``. None
        uses a built-in earlywood/latewood colour map of the field's ARF.
    px_per_mm : float, optional
        Image density; default ``face_px / max(size_mm)`` (the largest face side gets
        ``face_px`` pixels). Face image shapes follow :class:`woodcam.frames.CrossLayout`, so
        the faces unfold into one cross.
    faces : faces to render (photo). ``trace_faces`` / ``ring_map_faces`` (default: ``faces``)
        choose which of them carry traces / ring maps (partial annotation, e.g. three faces).
    trace_dropout : fraction in [0, 1]
        Expected fraction of trace length removed, in random pieces of ``trace_dropout_chunk_mm``.
    trace_jitter_mm : float
        Std (mm) of the perpendicular displacement of trace vertices, smoothed along the trace
        over ``trace_jitter_corr_mm`` (0 = independent per vertex).
    mislabel_fraction : fraction
        Traces whose year is off by +-1.
    unlabelled_fraction : fraction
        Traces with ``year=None``.
    photo_noise : float
        Sensor noise std (fraction of full scale); ``photo_variation`` the std of the per-face
        exposure (and ~ the vignetting strength); ``photo_blur_px`` the Gaussian lens blur
        (px), which also anti-aliases the sharp latewood -> earlywood step. All 0 gives the
        clean rendering: exactly ``round(255 * color)``.
    ring_map_sigma_px, ring_map_noise : float
        Ring-map line width ``sigma`` (px) of ``exp(-(d / sigma)^2)`` and additive noise std.
        Default sigma: :data:`MOKUME_RING_SIGMA_MM` times ``px_per_mm``, the width of the
        Mokume U-Net maps.
    knot_masks : for a field with ``knot_features`` (knotted logs), mark each face's knot wood
        (weight > 0.5) in ``extras["knot_mask"]``, as the knot masks of Mokume's H11.
    seed, rng
        ``rng`` if given, else ``np.random.default_rng(seed)``; the same seed gives the same block.

    Returns
    -------
    Block
        With ``true_field=field`` and ``meta`` holding the generator settings. Clean traces
        (no jitter, no mislabelling) lie on the integer iso-lines within
        :data:`woodcam.tolerances.TRACE_ISO_TOL_YEARS` years.
    """
    size = check_size(size_mm)
    if not callable(field):
        raise WoodcamError(f"field must be callable (n, 3) mm -> years; got {type(field).__name__}")
    if wood is not None and not callable(getattr(wood, "color", None)):
        raise WoodcamError(
            f"wood must have a color(points_mm, normals) method; got {type(wood).__name__}"
        )
    faces = [check_face(f) for f in faces]
    trace_faces = set(faces if trace_faces is None else [check_face(f) for f in trace_faces])
    ring_map_faces = set(faces if ring_map_faces is None else [check_face(f) for f in ring_map_faces])
    for knob in ("trace_dropout", "mislabel_fraction", "unlabelled_fraction"):
        _check_fraction(knob, locals()[knob])
    if trace_jitter_mm < 0 or photo_noise < 0 or photo_variation < 0 or ring_map_noise < 0:
        raise WoodcamError("trace_jitter_mm, photo_noise, photo_variation and ring_map_noise must be >= 0")
    if px_per_mm is None:
        if face_px < 2:
            raise WoodcamError(f"face_px must be >= 2 pixels; got {face_px!r}")
        px_per_mm = face_px / float(size.max())
    if not px_per_mm > 0:
        raise WoodcamError(f"px_per_mm must be > 0; got {px_per_mm!r}")
    rng = np.random.default_rng(seed) if rng is None else rng
    # A whole number of pixels across W: unfold_cross infers the density from the front face's
    # width, so this keeps all six face shapes consistent with it.
    px_per_mm = max(1, round(size[0] * float(px_per_mm))) / size[0]
    layout = CrossLayout(tuple(size), px_per_mm)
    if ring_map_sigma_px is None:
        ring_map_sigma_px = MOKUME_RING_SIGMA_MM * px_per_mm

    appearance = "builtin" if wood is None else type(wood).__name__
    wood = _BuiltinWood(field, rng) if wood is None else wood
    out = {}
    for face in faces:
        shape = layout.face_shape(face)
        hmm, wmm = face_image_size_mm(face, size)
        px_mm = (hmm / shape[0], wmm / shape[1])
        pts = _face_points(face, shape, size)
        g = evaluate(field, pts)
        normals = np.broadcast_to(np.asarray(FACE_NORMAL[face], float), pts.shape)
        if isinstance(wood, _BuiltinWood):
            gr, gc = np.gradient(g.reshape(shape))
            rgb = wood.color(pts, normals, years=g, years_per_px=np.hypot(gr, gc).ravel())
        else:
            rgb = np.asarray(wood.color(pts, normals), dtype=float)
        photo = _camera(rgb.reshape(shape + (3,)), rng, photo_noise, photo_variation, photo_blur_px)
        g = g.reshape(shape)
        ring_map = _ring_map(g, ring_map_sigma_px, ring_map_noise, rng) if face in ring_map_faces else None
        traces = []
        if face in trace_faces:
            traces = _trace_face(field, face, shape, size, g)
            if trace_dropout > 0:
                traces = _dropout(traces, px_mm, trace_dropout, trace_dropout_chunk_mm, rng)
            if trace_jitter_mm > 0:
                traces = _jitter(traces, px_mm, trace_jitter_mm, trace_jitter_corr_mm, rng)
            if mislabel_fraction > 0 or unlabelled_fraction > 0:
                u = rng.uniform(size=(len(traces), 2))
                sign = rng.choice([-1, 1], size=len(traces))
                traces = [RingTrace(t.points_px, None if u[i, 1] < unlabelled_fraction
                                    else t.year + int(sign[i]) if u[i, 0] < mislabel_fraction else t.year)
                          for i, t in enumerate(traces)]
        extras = {}
        if knot_masks and hasattr(field, "knot_features"):
            # as a tracer (or the knot detector) marks the knots on a photo: knot wood
            extras["knot_mask"] = (np.asarray(field.knot_features(pts)["knot"]) > 0.5).reshape(shape)
        out[face] = Face(face, shape, photo=photo, traces=traces, ring_map=ring_map, extras=extras)

    settings = {
        "generator": "woodcam.synth.synth_block", "seed": seed,
        "px_per_mm": float(px_per_mm), "appearance": appearance,
        "trace_faces": sorted(trace_faces), "ring_map_faces": sorted(ring_map_faces),
        "trace_dropout": trace_dropout, "trace_dropout_chunk_mm": trace_dropout_chunk_mm,
        "trace_jitter_mm": trace_jitter_mm, "trace_jitter_corr_mm": trace_jitter_corr_mm,
        "mislabel_fraction": mislabel_fraction, "unlabelled_fraction": unlabelled_fraction,
        "photo_noise": photo_noise, "photo_variation": photo_variation, "photo_blur_px": photo_blur_px,
        "ring_map_sigma_px": ring_map_sigma_px, "ring_map_noise": ring_map_noise,
        "knot_masks": bool(knot_masks),
    }
    return Block(tuple(size), faces=out, true_field=field, name=name, meta={**settings, **(meta or {})})


# -- benchmark set --------------------------------------------------------------------------------

def random_log_placement(rng: np.random.Generator, pattern: SawPattern, size_mm,
                         ring_width_range_mm=(1.5, 6.0)) -> tuple[AnalyticLogField, dict]:
    """Draw a knot-free eccentric analytic log and a placement (kwargs of :func:`cut_block`).

    The ring width at the block centre is log-uniform in ``ring_width_range_mm``; it varies
    slowly with radius (``width_slope_per_mm`` within +-0.003 / mm).
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


def benchmark_set_block(seed: int, index: int, *, face_px: int = 512, size_range_mm=(30.0, 80.0),
                        ring_width_range_mm=(1.5, 6.0),
                        log_fields: Callable[[np.random.Generator], object] | None = None,
                        knotted_fraction: float = 0.5,
                        wood_factory: Callable[[object], object] | None = None,
                        **synth_kwargs) -> tuple[Block, dict]:
    """Block ``index`` of the set :func:`synth_benchmark_set` writes for ``seed``, alone.

    Drawn from ``np.random.default_rng([seed, index])`` only, so it is the same block whichever
    process makes it and whatever else is made. Returns the block and its index entry (name,
    size, knotted, ring width, placement).
    """
    i = int(index)
    rng = np.random.default_rng([int(seed), i])
    pattern = PATTERNS[i % len(PATTERNS)]
    size = tuple(float(v) for v in np.round(rng.uniform(*size_range_mm, size=3) * 2) / 2)
    log, placement = random_log_placement(rng, pattern, size, ring_width_range_mm)
    knotted = log_fields is not None and rng.uniform() < knotted_fraction
    if knotted:
        log = log_fields(rng)
        field, placement = _place_through_knot(rng, log, placement, size)
    else:
        field = cut_block(log, size, **placement)
    name = f"block_{i:04d}"
    info = {"name": name, "index": i, "size_mm": list(size), "knotted": bool(knotted),
            "ring_width_mm": log.ring_width_at(placement["distance_mm"]) if not knotted else None,
            **{k: (float(v) if isinstance(v, (float, np.floating)) else v) for k, v in placement.items()}}
    wood = None if wood_factory is None else wood_factory(field)
    block = synth_block(field, size, wood=wood, face_px=face_px, rng=rng, seed=None, name=name,
                        meta={"benchmark_seed": int(seed), **info}, **synth_kwargs)
    return block, info


def synth_benchmark_set(out_dir, count: int, seed: int, *, face_px: int = 512,
                        size_range_mm=(30.0, 80.0), ring_width_range_mm=(1.5, 6.0),
                        log_fields: Callable[[np.random.Generator], object] | None = None,
                        knotted_fraction: float = 0.5, wood_factory: Callable[[object], object] | None = None,
                        progress: bool = True, **synth_kwargs) -> list[Path]:
    """Write ``count`` synthetic blocks to ``out_dir/block_0000`` ... plus ``out_dir/index.json``.

    Block ``i`` is drawn from ``np.random.default_rng([seed, i])`` alone, so any block of a set
    can be regenerated without the others and the set is reproducible. Sawing patterns cycle
    through :data:`PATTERNS`; each side is uniform in ``size_range_mm`` (0.5 mm steps); ring
    width at the block is log-uniform in ``ring_width_range_mm``.

    Parameters
    ----------
    log_fields : callable ``rng -> log-frame field``, optional
        Factory of knotted log fields (pith on log ``z``, e.g. :func:`knotted_log_field`). When
        given, a block is knotted with probability ``knotted_fraction``, and a knotted block is
        cut with a knot crossing it (:func:`knot_crosses` on the true field, asserted).
    wood_factory : callable ``block-frame field -> wood``, optional
        Appearance for each block (e.g. ``lambda f: woodcam.appearance.Wood(f, ...)``); default
        the built-in colour map.
    synth_kwargs
        Passed to :func:`synth_block` (e.g. ``trace_dropout``); default clean full annotation.

    Returns
    -------
    list of Path
        The block folders, in order.
    """
    from tqdm.auto import tqdm

    if count < 1:
        raise WoodcamError(f"count must be >= 1; got {count!r}")
    _check_fraction("knotted_fraction", knotted_fraction)
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    index = {"format": "woodcam-benchmark", "version": 1, "seed": int(seed), "count": int(count),
             "face_px": int(face_px), "size_range_mm": list(size_range_mm),
             "ring_width_range_mm": list(ring_width_range_mm),
             "knotted_available": log_fields is not None, "blocks": []}
    folders = []
    # tqdm's delay keeps the bar hidden for runs shorter than ~2 s.
    for i in tqdm(range(count), desc="synthesising blocks", unit="block", delay=2.0, disable=not progress):
        block, info = benchmark_set_block(
            seed, i, face_px=face_px, size_range_mm=size_range_mm,
            ring_width_range_mm=ring_width_range_mm, log_fields=log_fields,
            knotted_fraction=knotted_fraction, wood_factory=wood_factory, **synth_kwargs)
        folder = out_dir / info["name"]
        write_block(block, folder)
        folders.append(folder)
        index["blocks"].append(info)
    (out_dir / "index.json").write_text(json.dumps(index, indent=1))
    return folders


def knot_crosses(field, size_mm, n: int = 12) -> bool:
    """True when a knot of ``field`` (block frame, with ``knot_features``) crosses the block:
    some point of an ``n^3`` grid over it has knot weight > 0.5 (inside the knot wood)."""
    if not hasattr(field, "knot_features"):
        return False
    size = check_size(size_mm)
    axes = [np.linspace(0.0, s, n) for s in size]
    pts = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    return bool(np.any(np.asarray(field.knot_features(pts)["knot"]) > 0.5))


def _place_through_knot(rng: np.random.Generator, log_field, placement: dict, size, tries: int = 60):
    """Move ``placement`` (kwargs of :func:`cut_block`) so that a knot of ``log_field`` crosses
    the block: its centre on a random knot's strand, at a random pith distance between the
    block's half diagonal and the knot's end (pith-inside: at the knot's base on the pith).

    Returns ``(block-frame field, placement)``; checked with :func:`knot_crosses` (asserted from
    the true field), raising :class:`WoodcamError` when no knot of the log reaches a block.
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
    raise WoodcamError(f"no knot of this log crosses a {W:g} x {D:g} mm block after {tries} tries; "
                       f"use a smaller block or a log with longer knots")


def knotted_log_field(rng: np.random.Generator, ring_width_range_mm=(1.5, 6.0), *,
                      length_mm: float = 1200.0):
    """A knotted log field (log frame) from the log generator of seed 001 (``woodcam.logs``),
    turned into the stem + knot field of seed 003; ring width log-uniform in the range.
    The factory :func:`synth_benchmark_set` takes as ``log_fields``."""
    from .fields import KnottedLogField, log_from_generated
    from .logs import generate_log

    gen = generate_log(int(rng.integers(1 << 31)), length_mm=length_mm)
    width = math.exp(rng.uniform(*np.log(ring_width_range_mm)))
    return KnottedLogField(log_from_generated(gen), ring_width_mm=width)


def time_synth_block(face_px: int = 512, repeats: int = 1) -> float:
    """Seconds to synthesise one cube block with six ``face_px``-square faces (built-in colour)."""
    log = AnalyticLogField(ring_width_mm=3.0, width_slope_per_mm=0.001, eccentricity=0.1, lobe_amplitude=0.02)
    field = cut_block(log, (50, 50, 50), "rift")
    best = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        synth_block(field, (50, 50, 50), face_px=face_px, seed=0)
        best = min(best, time.perf_counter() - t0)
    return best
