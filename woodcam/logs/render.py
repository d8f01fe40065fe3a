"""Planar sections through a knotted log, as images (arrays), for `woodcam log render`.

A section is a rectangle in the log frame (mm): ``origin`` (its corner at pixel row 0, column 0),
``u`` (unit, along columns) and ``v`` (unit, along rows, downward in the image), ``size_mm =
(width, height)`` and a resolution in pixels per mm. Pixel ``(row i, col j)`` samples the point
``origin + (j + 0.5) / ppm * u + (i + 0.5) / ppm * v`` (pixel centres).

Colours: the colour map's species ramp (:meth:`woodcam.appearance.ColorMapAppearance.ramp` of
``ARF = (years mod 1)^2``, eq. 6 of seed 000; spruce by default, the species of the real log)
with :class:`woodcam.appearance.knots.KnotShading`, the shading every renderer uses; points
outside the log's outer surface get ``background``. Functions return ``(rows, cols, 3) uint8``
arrays; only :func:`save_png` writes.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..appearance.colormap import ColorMapAppearance, Species
from ..appearance.knots import KnotShading
from ..errors import WoodcamError, WoodcamWarning
from ..fields.base import arf
from ..fields.knots import KnottedLogField
from ..fields.skeleton import LogSkeleton

BACKGROUND_RGB = (0.16, 0.16, 0.16)


@dataclass(frozen=True)
class Section:
    """A planar rectangle in the log frame (see the module docstring)."""

    origin_mm: tuple
    u: tuple
    v: tuple
    size_mm: tuple
    px_per_mm: float = 4.0
    name: str = "section"

    def shape(self) -> tuple[int, int]:
        return (max(1, int(round(self.size_mm[1] * self.px_per_mm))),
                max(1, int(round(self.size_mm[0] * self.px_per_mm))))

    def check_size(self, supersample: int = 1) -> None:
        """Refuse, before any allocation, a section whose points at ``supersample`` x
        ``supersample`` samples a pixel pass :data:`woodcam.limits.MAX_GRID_CELLS`, naming the
        ``--px-per-mm`` and ``--supersample`` given (a 4 m board at 1000 px/mm asked for 1.57 TiB,
        3 floats a point; ``--px-per-mm 50 --supersample 4`` was said as '200 px/mm')."""
        from ..limits import check_grid

        s = int(supersample)
        what = f"the section {self.name!r} at {self.px_per_mm:g} px/mm"
        if s > 1:
            what += f" with {s}x{s} samples a pixel (--supersample {s})"
        check_grid((self.size_mm[1] * self.px_per_mm * s, self.size_mm[0] * self.px_per_mm * s, 3),
                   what, fix="lower --px-per-mm" + (" or --supersample" if s > 1 else ""))

    def points(self) -> np.ndarray:
        """Pixel-centre points ``(rows, cols, 3)`` in the log frame, mm."""
        self.check_size()
        rows, cols = self.shape()
        o, u, v = (np.asarray(a, float) for a in (self.origin_mm, self.u, self.v))
        j = (np.arange(cols) + 0.5) / self.px_per_mm
        i = (np.arange(rows) + 0.5) / self.px_per_mm
        return o + j[None, :, None] * u + i[:, None, None] * v


def _check_height(log: LogSkeleton, z_mm: float, what: str) -> None:
    """``z_mm`` lies along the log (a section elsewhere shows only air, and 1e300 overflowed)."""
    if not (log.pith_z_mm[0] <= z_mm <= log.pith_z_mm[-1]):
        raise WoodcamError(f"{what} must lie in the log, [{log.pith_z_mm[0]:g}, {log.pith_z_mm[-1]:g}] "
                           f"mm along it; got {z_mm:g}")


def _warn_past_ends(log: LogSkeleton, z_lo: float, z_hi: float, what: str) -> None:
    """Warn when the z range ``[z_lo, z_hi]`` of a section whose columns run along the log (``+z``
    to the right) passes one of its ends: that part is drawn as background (it was, silently)."""
    lo, hi = float(log.pith_z_mm[0]), float(log.pith_z_mm[-1])
    parts = []
    if z_lo < lo:
        parts.append(f"its left {lo - z_lo:.0f} mm (z < {lo:g} mm)")
    if z_hi > hi:
        parts.append(f"its right {z_hi - hi:.0f} mm (z > {hi:g} mm)")
    if parts:
        fits = (f"a centre height in [{lo + (z_hi - z_lo) / 2:g}, {hi - (z_hi - z_lo) / 2:g}] mm keeps "
                "it inside" if z_hi - z_lo <= hi - lo else f"the log is only {hi - lo:g} mm long")
        warnings.warn(f"{what} spans z {z_lo:g}..{z_hi:g} mm, past the log's end ([{lo:g}, {hi:g}] mm "
                      f"along it): {' and '.join(parts)} is drawn as background; {fits}",
                      WoodcamWarning, stacklevel=3)


def _deg(azimuth_rad: float) -> str:
    """An azimuth for a file name: whole degrees in [0, 360) (1e300 degrees made a name longer
    than the file system allows)."""
    return f"{np.degrees(azimuth_rad) % 360.0:.0f}"


def end_grain_disc(log: LogSkeleton, z_mm: float, *, px_per_mm: float = 2.0, margin_mm: float = 5.0
                   ) -> Section:
    """Horizontal section at height ``z_mm`` covering the whole log cross-section, seen from
    above (``+x`` to the right, ``+y`` up in the image)."""
    _check_height(log, z_mm, "the disc's height z_mm (--disc)")
    c = log.pith_at(np.array([z_mm]))[0]
    h = log.r_max_mm + margin_mm
    return Section((c[0] - h, c[1] + h, z_mm), (1, 0, 0), (0, -1, 0), (2 * h, 2 * h), px_per_mm,
                   f"disc_z{z_mm:.0f}")


def tangential_board(log: LogSkeleton, z_center_mm: float, azimuth_rad: float, offset_mm: float, *,
                     length_mm: float = 600.0, width_mm: float = 120.0,
                     px_per_mm: float = 2.0) -> Section:
    """Face of a flat-sawn board: a plane parallel to the log axis at ``offset_mm`` from the
    pith (at ``z_center_mm``), facing azimuth ``azimuth_rad``. Image columns run along the log
    (``+z`` to the right), rows across it."""
    _check_height(log, z_center_mm, "the board's centre height z_center_mm (--board Z AZ OFF)")
    if not abs(offset_mm) < log.r_max_mm:
        raise WoodcamError(f"the board's offset from the pith offset_mm (--board Z AZ OFF) must be within "
                           f"the log's radius, |offset| < {log.r_max_mm:g} mm; got {offset_mm:g}")
    c = log.pith_at(np.array([z_center_mm]))[0]
    n = np.array([np.cos(azimuth_rad), np.sin(azimuth_rad), 0.0])
    t = np.array([-np.sin(azimuth_rad), np.cos(azimuth_rad), 0.0])
    centre = np.array([c[0], c[1], z_center_mm]) + offset_mm * n
    origin = centre - 0.5 * length_mm * np.array([0, 0, 1.0]) + 0.5 * width_mm * t
    _warn_past_ends(log, z_center_mm - length_mm / 2, z_center_mm + length_mm / 2,
                    f"the board (--board Z AZ OFF, {length_mm:g} mm long)")
    return Section(tuple(origin), (0, 0, 1), tuple(-t), (length_mm, width_mm), px_per_mm,
                   f"board_z{z_center_mm:.0f}_az{_deg(azimuth_rad)}_off{offset_mm:.0f}")


def radial_section(log: LogSkeleton, z_center_mm: float, azimuth_rad: float, *,
                   length_mm: float = 300.0, px_per_mm: float = 2.0,
                   margin_mm: float = 5.0) -> Section:
    """Quarter-sawn face: the plane through the pith (at ``z_center_mm``) containing the
    azimuth ``azimuth_rad``, from the far bark to the near bark. Columns run along the log
    (``+z`` to the right); rows from ``azimuth_rad`` (top) through the pith to the opposite
    side. Knots show as spikes growing out of the pith."""
    _check_height(log, z_center_mm, "the section's centre height z_center_mm (--radial Z AZ)")
    c = log.pith_at(np.array([z_center_mm]))[0]
    n = np.array([np.cos(azimuth_rad), np.sin(azimuth_rad), 0.0])
    h = log.r_max_mm + margin_mm
    origin = np.array([c[0], c[1], z_center_mm - 0.5 * length_mm]) + h * n
    _warn_past_ends(log, z_center_mm - length_mm / 2, z_center_mm + length_mm / 2,
                    f"the radial section (--radial Z AZ, {length_mm:g} mm long)")
    return Section(tuple(origin), (0, 0, 1), tuple(-n), (length_mm, 2 * h), px_per_mm,
                   f"radial_z{z_center_mm:.0f}_az{_deg(azimuth_rad)}")


def busiest_board(log: LogSkeleton, *, offset_mm: float = 60.0, length_mm: float = 600.0,
                  width_mm: float = 120.0, step_deg: float = 10.0, step_mm: float = 50.0):
    """The (z_center, azimuth) of the tangential board that cuts the most knots (knot axes
    crossing the board plane inside its rectangle), found by a coarse scan; returns
    ``(z_center_mm, azimuth_rad, n_knots)``."""
    best = (log.pith_z_mm[0] + length_mm / 2, 0.0, -1)
    if not log.knots:
        return best[0], best[1], 0
    zs = np.arange(log.pith_z_mm[0] + length_mm / 2, log.pith_z_mm[-1] - length_mm / 2 + 1,
                   step_mm)
    r = np.linspace(0, log.r_max_mm, 200)
    pts = [(k, log.knot_point(i, r)) for i, k in enumerate(log.knots)]
    for az in np.radians(np.arange(0, 360, step_deg)):
        n = np.array([np.cos(az), np.sin(az)])
        t = np.array([-np.sin(az), np.cos(az)])
        cross = []
        for k, p in pts:
            c = log.pith_at(p[:, 2])
            rel = p[:, :2] - c
            s = rel @ n - offset_mm
            idx = np.nonzero((np.sign(s[:-1]) != np.sign(s[1:])) & (r[1:] <= k.r_end_mm))[0]
            if len(idx):
                i = idx[0]
                cross.append((p[i, 2], rel[i] @ t))
        if not cross:
            continue
        cz, ct = np.array(cross).T
        for zc in zs:
            inside = (np.abs(cz - zc) < length_mm / 2 - 20) & (np.abs(ct) < width_mm / 2 - 10)
            cnt = int(np.sum(inside))
            if cnt > best[2]:
                best = (float(zc), float(az), cnt)
    return best


def colour_years(years, features=None, *, species: Species | str = "spruce",
                 knots: KnotShading = KnotShading()) -> np.ndarray:
    """Colour ``(n,) years -> (n, 3)`` float RGB: the species ramp of the ARF, knots shaded."""
    rgb = ColorMapAppearance(species).ramp(arf(np.asarray(years, float))).astype(float)
    if features is not None:
        rgb = knots.apply(rgb, features)
    return rgb


def render_section(field: KnottedLogField, section: Section, *, background=BACKGROUND_RGB,
                   species: Species | str = "spruce", knots: KnotShading = KnotShading(),
                   supersample: int = 1) -> np.ndarray:
    """Colour image ``(rows, cols, 3) uint8`` of ``field`` on ``section``.

    ``supersample = s`` evaluates ``s x s`` points per pixel and averages their colours (knot
    rings are ~0.2 mm apart and alias into speckle at 2-4 px/mm).
    """
    s = int(supersample)
    if s > 1:
        section.check_size(s)  # in the numbers typed: the fine section's own check said ppm * s
        rows, cols = section.shape()
        ppm = section.px_per_mm
        fine = Section(section.origin_mm, section.u, section.v, (cols / ppm, rows / ppm),
                       ppm * s, section.name)
        img = render_section(field, fine, background=background, species=species,
                             knots=knots).astype(float)
        img = img.reshape(rows, s, cols, s, 3).mean(axis=(1, 3))
        return (img + 0.5).astype(np.uint8)
    pts = section.points()
    shp = pts.shape[:2]
    p = pts.reshape(-1, 3)
    out = field.evaluate(p)
    rgb = colour_years(out["years"], out, species=species, knots=knots)
    rel = p[:, :2] - field.log.pith_at(p[:, 2])
    outside = np.hypot(rel[:, 0], rel[:, 1]) > field.log.radius_at(
        p[:, 2], np.arctan2(rel[:, 1], rel[:, 0]))
    outside |= (p[:, 2] < field.log.pith_z_mm[0]) | (p[:, 2] > field.log.pith_z_mm[-1])
    rgb[outside] = background
    return (np.clip(rgb, 0, 1) * 255 + 0.5).astype(np.uint8).reshape(*shp, 3)


def save_png(image: np.ndarray, path) -> Path:
    """Write a ``(rows, cols, 3) uint8`` image as PNG (atomically: a complete file or none)."""
    from PIL import Image

    from .._atomic import atomic_path

    path = Path(path)
    with atomic_path(path, mkdir=True) as tmp:
        Image.fromarray(np.asarray(image, np.uint8)).save(tmp, format="PNG")
    return path


#: The default board's distance from the pith (mm), for a log thicker than 100 mm; a thinner
#: log's is 0.6 of its smallest radius (:func:`default_sections`).
DEFAULT_BOARD_OFFSET_MM = 60.0


def default_sections(log: LogSkeleton, *, px_per_mm: float = 2.0) -> list[Section]:
    """A tangential board through the most knots (:data:`DEFAULT_BOARD_OFFSET_MM` from the pith,
    or 0.6 of a thinner log's smallest radius; 600 mm long, or the log's length) and an
    end-grain disc through the log's biggest whorl (the height where most knot axes pass 50 mm
    from the pith, +-12 mm)."""
    # 60 mm from the pith, or 0.6 of a thinner log's smallest radius (a board of a log 40 mm in
    # radius was refused as '--board ... |offset| < 40 mm; got 60', a --board nobody typed)
    # and 600 mm long, or a shorter log's length (one 300 mm long was drawn half background,
    # warned of as a '--board' past its end)
    offset = min(DEFAULT_BOARD_OFFSET_MM, 0.6 * log.r_min_mm)
    length = min(600.0, log.length_mm)
    zc, az, _ = busiest_board(log, offset_mm=offset, length_mm=length)
    secs = [tangential_board(log, zc, az, offset, length_mm=length, px_per_mm=px_per_mm)]
    if log.knots:
        zk = np.array([log.knot_point(i, [50.0])[0, 2] for i in range(len(log.knots))])
        cands = np.arange(log.pith_z_mm[0], log.pith_z_mm[-1], 5.0)
        counts = np.array([np.sum(np.abs(zk - z) < 12.0) for z in cands])
        z_best = cands[int(np.argmax(counts))]
        zd = float(np.median(zk[np.abs(zk - z_best) < 12.0]))
    else:
        zd = float(log.pith_z_mm[len(log.pith_z_mm) // 2])
    zd = float(np.clip(zd, log.pith_z_mm[0], log.pith_z_mm[-1]))
    secs.append(end_grain_disc(log, zd, px_per_mm=px_per_mm))
    return secs
