"""The fast colour-map appearance: colour from the ARF, fibre streaks, pores and end grain.

Each point's growth time gives its ARF (eq. 6 of seed 000); a ramp maps the ARF to a colour
between earlywood and latewood. Three per-axis colourings (for surfaces normal to X, Y and Z,
eq. 10 of seed 000) differ in how much end grain they show: a surface whose normal runs along
the fibres cuts them across, and end grain is darker (open cell ends trap light) and rougher
than side grain. Pores and fibre streaks come from one solid noise stretched along the grain,
so a side-grain surface shows them as streaks and an end-grain surface as dots, as in real
wood. When a block has face photos, the colour ramps are fitted to them per block axis
(:meth:`ColorMapAppearance.fit_to_block`), so end-grain darkening comes from the photos.

Colours are linear floats in [0, 1] (sRGB values, no gamma handling: photos and textures are
both sRGB and the model only interpolates between observed colours).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..errors import WoodcamError
from ..fields.base import arf, check_points, grain_direction
from ..fields.knots import knot_shading
from ..frames import FACE_AXIS, face_pixel_points
from .noise import grain_noise, value_noise
from .orientation import blend_axis_colors

#: Number of ARF bins of a fitted colour ramp.
LUT_BINS = 32


@dataclass(frozen=True)
class Species:
    """Colour and texture parameters of a wood species (colours are sRGB floats in [0, 1]).

    Attributes
    ----------
    earlywood_rgb, latewood_rgb : (3,) float
    latewood_start : float
        ARF value where the ramp to latewood starts (ARF = (GTF mod 1)^2, latewood near 1).
    pore_contrast : float
        Darkening of pores (0 = none); ``ring_porous`` puts them in the earlywood only.
    pore_across_mm, pore_along_mm : float
        Pore/fibre cell size across and along the grain.
    streak_contrast : float
        Amplitude of fibre streaks (relative brightness).
    endgrain_darkening : float
        Relative darkening of pure end grain.
    endgrain_roughness : float
        Amplitude of the fine isotropic mottling added on end grain.
    """

    name: str
    earlywood_rgb: tuple[float, float, float]
    latewood_rgb: tuple[float, float, float]
    latewood_start: float = 0.55
    pore_contrast: float = 0.15
    ring_porous: bool = False
    pore_across_mm: float = 0.25
    pore_along_mm: float = 6.0
    streak_contrast: float = 0.06
    endgrain_darkening: float = 0.3
    endgrain_roughness: float = 0.15


#: Species presets; colours read off photographs of planed boards.
SPECIES: dict[str, Species] = {
    "oak": Species("oak", (0.80, 0.64, 0.44), (0.56, 0.40, 0.24), 0.5, 0.35, True, 0.3, 5.0, 0.07),
    "maple": Species("maple", (0.93, 0.84, 0.70), (0.82, 0.68, 0.50), 0.7, 0.06, False, 0.15, 4.0, 0.05),
    "walnut": Species("walnut", (0.52, 0.36, 0.25), (0.33, 0.21, 0.14), 0.55, 0.15, False, 0.25, 6.0, 0.08),
    "cherry": Species("cherry", (0.82, 0.56, 0.40), (0.66, 0.40, 0.26), 0.6, 0.06, False, 0.15, 5.0, 0.05),
    "pine": Species("pine", (0.93, 0.80, 0.58), (0.72, 0.48, 0.25), 0.45, 0.04, False, 0.2, 8.0, 0.05, 0.25),
    "spruce": Species("spruce", (0.94, 0.86, 0.70), (0.78, 0.60, 0.40), 0.5, 0.03, False, 0.2, 8.0, 0.04, 0.25),
}


def get_species(species) -> Species:
    """Return a :class:`Species` from a preset name or a Species."""
    if isinstance(species, Species):
        return species
    if species not in SPECIES:
        raise WoodcamError(f"species must be one of {', '.join(SPECIES)}; got {species!r}")
    return SPECIES[species]


def _smoothstep(e0, e1, x):
    t = np.clip((x - e0) / (e1 - e0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


@dataclass(frozen=True)
class ColorMapAppearance:
    """Colour-map appearance (see module docstring).

    Parameters
    ----------
    species : Species or preset name
    axis_luts : (3, LUT_BINS, 3) float or None
        Fitted colour over ARF for surfaces normal to X, Y, Z (block frame); ``None`` uses the
        species ramp with end-grain darkening. Rows with NaN fall back to the species ramp.
    knot_darkening_alive, knot_darkening_dead : float
        Relative darkening of alive and dead knot wood (fields that report ``knot_features``).
    dead_outline_rgb : (3,) float
        Colour of the bark ring around dead knots.
    seed : int
        Noise seed.
    """

    species: Species | str = "oak"
    axis_luts: np.ndarray | None = None
    knot_darkening_alive: float = 0.25
    knot_darkening_dead: float = 0.45
    dead_outline_rgb: tuple[float, float, float] = (0.16, 0.10, 0.06)
    seed: int = 0

    def __post_init__(self):
        object.__setattr__(self, "species", get_species(self.species))
        if self.axis_luts is not None:
            luts = np.asarray(self.axis_luts, dtype=np.float32)
            if luts.shape != (3, LUT_BINS, 3):
                raise WoodcamError(f"axis_luts must have shape (3, {LUT_BINS}, 3); got {luts.shape}")
            object.__setattr__(self, "axis_luts", luts)

    # -- the ramp -------------------------------------------------------------------------------

    def ramp(self, arf_values) -> np.ndarray:
        """Species colour at ARF values ``(n,)`` -> ``(n, 3)`` float32 (side grain, no noise)."""
        s = self.species
        t = _smoothstep(s.latewood_start, 1.0, np.asarray(arf_values, np.float32))[:, None]
        early = np.asarray(s.earlywood_rgb, np.float32)
        late = np.asarray(s.latewood_rgb, np.float32)
        return early + t * (late - early)

    # -- per-axis colourings ----------------------------------------------------------------------

    def axis_colors(self, field, points_mm) -> np.ndarray:
        """The three per-axis colourings of eq. 10, shape ``(3, n, 3)``: normals X, Y, Z."""
        p = check_points(points_mm)
        s = self.species
        years, grain, knots = _field_sample(field, p)
        a = arf(years).astype(np.float32)
        latewood = _smoothstep(s.latewood_start, 1.0, a)
        base = self.ramp(a)

        # One solid pore/fibre noise, stretched along the grain: streaks on side grain,
        # dots on end grain (a cut across the stretched cells).
        fibre = grain_noise(p, grain, s.pore_across_mm, s.pore_along_mm, self.seed)
        pores = np.maximum(fibre - 0.35, 0.0) * (1.0 / 0.65)
        if s.ring_porous:
            pores *= 1.0 - latewood
        streaks = grain_noise(p, grain, 4 * s.pore_across_mm, 4 * s.pore_along_mm, self.seed + 1)
        shade = (1.0 + s.streak_contrast * streaks) * (1.0 - s.pore_contrast * pores)
        rough = value_noise(p * np.float32(1.0 / (0.5 * s.pore_across_mm)), self.seed + 2)

        out = np.empty((3,) + base.shape, np.float32)
        for k in range(3):
            end = np.abs(grain[:, k])  # 1 where a plane normal to axis k cuts the fibres across
            if self.axis_luts is not None and np.all(np.isfinite(self.axis_luts[k])):
                col = _lut_lookup(self.axis_luts[k], a)
            else:
                col = base * (1.0 - s.endgrain_darkening * end * end)[:, None]
            col = col * (shade * (1.0 + s.endgrain_roughness * end * rough))[:, None]
            if knots is not None:
                col = knot_shading(col, knots, alive_darkening=self.knot_darkening_alive,
                                   dead_darkening=self.knot_darkening_dead,
                                   outline_rgb=self.dead_outline_rgb)
            out[k] = col
        return np.clip(out, 0.0, 1.0)

    def color(self, field, points_mm, normals) -> np.ndarray:
        """Colour ``(n, 3)`` in [0, 1] of surfaces at ``points_mm`` with unit ``normals``."""
        yz, zx, xy = self.axis_colors(field, points_mm)
        return blend_axis_colors(yz, zx, xy, normals)

    # -- fitting to photos ------------------------------------------------------------------------

    @classmethod
    def fit_to_block(cls, block, field, species="oak", **kwargs) -> "ColorMapAppearance":
        """Fit per-axis colour ramps (colour as a function of ARF) to a block's face photos.

        For every face with a photo, the ARF of ``field`` at each pixel centre is binned into
        :data:`LUT_BINS` bins and the mean photo colour per bin is taken; both faces of an axis
        are pooled. Bins no pixel falls in are filled by linear interpolation along the ARF.
        Axes without photos keep the species ramp. Raises if no face has a photo.
        """
        sums = np.zeros((3, LUT_BINS, 3))
        counts = np.zeros((3, LUT_BINS))
        for face in block.faces.values():
            if face.photo is None:
                continue
            pts = face_pixel_points(face.name, face.shape, block.size_mm).reshape(-1, 3)
            a = arf(field(pts))
            b = np.minimum((a * LUT_BINS).astype(int), LUT_BINS - 1)
            k = FACE_AXIS[face.name]
            rgb = face.photo.reshape(-1, 3).astype(float) / 255.0
            np.add.at(counts[k], b, 1)
            for c in range(3):
                sums[k, :, c] += np.bincount(b, rgb[:, c], minlength=LUT_BINS)
        if not counts.any():
            raise WoodcamError(
                f"block {block.name!r} has no face photos to fit a colour map to; "
                "use a species preset instead (ColorMapAppearance(species=...))"
            )
        luts = np.full((3, LUT_BINS, 3), np.nan)
        centres = (np.arange(LUT_BINS) + 0.5) / LUT_BINS
        for k in range(3):
            ok = counts[k] > 0
            if not ok.any():
                continue
            mean = sums[k][ok] / counts[k][ok, None]
            for c in range(3):
                luts[k, :, c] = np.interp(centres, centres[ok], mean[:, c])
        return cls(species=species, axis_luts=luts, **kwargs)

    def with_params(self, **changes) -> "ColorMapAppearance":
        """Copy with some parameters changed."""
        return replace(self, **changes)


def _field_sample(field, points_mm):
    """Growth time, fibre directions and (for knotted fields) knot features in one pass.

    Knotted fields answer ``evaluate(points, directions=True)`` with everything at once, which
    is several times cheaper than calling the field, ``grain_direction`` and ``knot_features``
    separately. Returns ``(years (n,), grain (n, 3) float32, knots dict or None)``.
    """
    evaluate_all = getattr(field, "evaluate", None)
    if callable(evaluate_all):
        out = evaluate_all(points_mm, directions=True)
        return out["years"], np.asarray(out["direction"], np.float32), out
    return field(points_mm), np.asarray(grain_direction(field, points_mm), np.float32), None


def _lut_lookup(lut: np.ndarray, a: np.ndarray) -> np.ndarray:
    """Linear interpolation of a ``(LUT_BINS, 3)`` ramp at ARF values ``a`` (bin centres)."""
    t = np.clip(a * LUT_BINS - 0.5, 0.0, LUT_BINS - 1.0)
    i0 = np.minimum(t.astype(np.int64), LUT_BINS - 2)
    f = (t - i0)[:, None]
    return lut[i0] * (1 - f) + lut[i0 + 1] * f
