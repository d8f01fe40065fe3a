"""The fast colour-map appearance: colour from the ARF, fibre streaks, pores and end grain.

Each point's growth time gives its ARF (eq. 6 of seed 000); a ramp maps the ARF to a colour
between earlywood and latewood. Three per-axis colourings (for surfaces normal to X, Y and Z,
eq. 10 of seed 000) differ in how much end grain they show: a surface whose normal runs along
the fibres cuts them across, and end grain is darker (open cell ends trap light) and rougher
than side grain. Pores and fibre streaks come from one solid noise stretched along the grain,
so a side-grain surface shows them as streaks and an end-grain surface as dots, as in real
wood. When a block has face photos, the colour ramps are fitted to them per block axis
(:meth:`ColorMapAppearance.fit_to_block`), so end-grain darkening comes from the photos; a
fitted ramp is looked up by the ring phase ``years mod 1`` (= sqrt(ARF), :data:`LUT_BINS`) and
learned from clear wood only (knots would darken every ring position).

Colours are linear floats in [0, 1] (sRGB values, no gamma handling: photos and textures are
both sRGB and the model only interpolates between observed colours).
"""

from __future__ import annotations

from dataclasses import InitVar, dataclass, replace
from typing import Literal

import numba
import numpy as np

from .._checks import as_floats, check_number, numbers_fix, real_numbers, received
from .._repr import summary_repr
from .._types import ArrayLike, GrowthFieldLike
from ..errors import WoodcamError
from ..fields.base import LogFrame, arf, check_points, check_texture_frame, grain_direction
from ..frames import FACE_AXIS, face_pixel_points
from .knots import KnotShading
from .noise import TABLE, noise_at
from .orientation import eq10_weights

#: Number of ring-phase bins of a fitted colour ramp (equal steps of ``years mod 1``, i.e. of
#: ``sqrt(ARF)``). Binned by phase, not by the ARF: the ARF squares the phase, so its first bin
#: would span 0.18 of a ring, and a photo's latewood band that straddles the whole year (as it
#: does once the phase is registered on a ring map, whose lines sit on the dark band) would be
#: averaged with earlywood there: H11's baked latewood lines came out a third fainter.
LUT_BINS = 32

#: Window (Gaussian sigma, pixels of a 256-pixel face side) over which the offset between a
#: fitted field's rings and a face's ring map is averaged: about one ring spacing on the Mokume
#: cubes (rings 15-30 px apart), so each ring is registered mostly by itself and its neighbours.
RING_REGISTRATION_BLUR_PX_PER_SIDE = 12.0

#: Knot feature (0 = stem wood, 1 = inside a knot) below which a photo pixel counts as clear
#: stem wood when a colour ramp is fitted: the knot's smooth-minimum blend reaches a few
#: per cent a little outside its surface, where the stem's rings are already bent round it.
KNOT_FREE_BELOW = 0.05

#: Knot feature above which a photo pixel counts as knot wood when the knot's own colour ramp
#: is fitted (:func:`_field_lut`): the core of the knot, away from the smooth-minimum blend
#: where stem and knot rings mix.
KNOT_CORE_ABOVE = 0.5

#: Ring scale of a face photo (Gaussian sigmas, pixels of a 256-pixel face side): the photo
#: blurred by the first minus blurred by the second is its ring-scale part (H11's rings are
#: 6-30 px apart; the first removes pixel noise, the second the slow shading of a face or a
#: knot). Used for a fitted field's knot ramp (:func:`_knot_lut`).
RING_BAND_PX_PER_SIDE = (1.0, 6.0)

#: Ring-phase harmonics of the stem ramp that give a fitted field's knot ramp its profile
#: (:func:`_knot_lut`): the shape of a ring (where the latewood is), not the ramp's bin noise.
KNOT_PROFILE_HARMONICS = 2

RampAnchor = Literal["auto", "field", "ring_map"]


def _lut_array(value, name: str, shape: tuple[int, ...]) -> np.ndarray:
    """A fitted table of :class:`ColorMapAppearance` (``axis_luts``, ``knot_lut``,
    ``axis_exposure``, ``exposure_span_mm``) as float32 of ``shape``, or the error naming it."""
    a = as_floats(value)
    if a is None:
        fix = numbers_fix(value, name) or "ColorMapAppearance.fit_to_block fits it"
        raise WoodcamError(f"{name} must be real numbers of shape {shape}; got {received(value)}; {fix}")
    if a.shape != shape:
        raise WoodcamError(f"{name} must have shape {shape}; got {a.shape}")
    return a.astype(np.float32)


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
    source: str = ""


#: sRGB centroids (0-255) of the ISCC-NBS colour names the cited presets use, as tabulated by
#: P. Centore, "sRGB centroids for the ISCC-NBS colour system" (2016),
#: https://munsellcolourscienceforpainters.com/ISCCNBS/ISCCNBSSystem.html (Illuminant C, the
#: ISCC-NBS standard). Quoted, not fitted: a written colour name becomes one of these numbers.
ISCC_NBS_SRGB: dict[str, tuple[int, int, int]] = {
    "light reddish brown": (172, 122, 115), "moderate reddish brown": (125, 66, 59),
    "dark reddish brown": (70, 29, 30), "light brown": (173, 124, 99),
    "moderate brown": (114, 74, 56), "dark brown": (68, 33, 18),
    "grayish brown": (103, 79, 72), "dark grayish brown": (62, 44, 40),
    "moderate yellowish brown": (136, 102, 72), "dark yellowish brown": (80, 52, 26),
    "yellowish white": (238, 223, 218), "yellowish gray": (198, 185, 177),
    "pinkish white": (239, 221, 229), "pinkish gray": (199, 182, 189),
    "moderate reddish orange": (205, 105, 82), "moderate red": (177, 73, 85),
}

#: The quotes below were read in the 2010 edition's chapter 2 as reproduced page by page at
#: https://issuhub.com/view/index/5801 (pages 20-29); the black cherry and white ash sentences
#: as reproduced at woodworkdetails.com and cocolumber.com (the same Handbook wording).
_HANDBOOK = ("Forest Products Laboratory (2010), Wood Handbook - Wood as an Engineering Material, "
             "FPL-GTR-190, ch. 2 (Wiemann), https://www.fpl.fs.usda.gov/documnts/fplgtr/fplgtr190/"
             "chapter_02.pdf")


def _cited(name: str, early: str, late: str, like: str, source: str) -> Species:
    """A preset whose earlywood and latewood colours are the ISCC-NBS centroids of the colour
    names its ``source`` gives (the lighter named colour for earlywood, the darker for latewood;
    a single named colour gets the ISCC-NBS name one lightness step darker for latewood). The
    texture parameters (pores, streaks, end grain) are those of the legacy preset ``like`` of the
    same anatomical group (ring-porous, diffuse-porous, softwood): no source gives them."""
    rgb = {k: tuple(v / 255.0 for v in ISCC_NBS_SRGB[k]) for k in (early, late)}
    return replace(_LEGACY[like], name=name, earlywood_rgb=rgb[early], latewood_rgb=rgb[late],
                   source=f"{source}; colours: ISCC-NBS '{early}' / '{late}' (Centore 2016)")


#: The first six presets; their colours were read off photographs that are not recorded, so
#: they carry no citable source. Kept because blocks and tests name them.
_LEGACY: dict[str, Species] = {
    "oak": Species("oak", (0.80, 0.64, 0.44), (0.56, 0.40, 0.24), 0.5, 0.35, True, 0.3, 5.0, 0.07),
    "maple": Species("maple", (0.93, 0.84, 0.70), (0.82, 0.68, 0.50), 0.7, 0.06, False, 0.15, 4.0, 0.05),
    "walnut": Species("walnut", (0.52, 0.36, 0.25), (0.33, 0.21, 0.14), 0.55, 0.15, False, 0.25, 6.0, 0.08),
    "cherry": Species("cherry", (0.82, 0.56, 0.40), (0.66, 0.40, 0.26), 0.6, 0.06, False, 0.15, 5.0, 0.05),
    "pine": Species("pine", (0.93, 0.80, 0.58), (0.72, 0.48, 0.25), 0.45, 0.04, False, 0.2, 8.0, 0.05, 0.25),
    "spruce": Species("spruce", (0.94, 0.86, 0.70), (0.78, 0.60, 0.40), 0.5, 0.03, False, 0.2, 8.0, 0.04, 0.25),
}
_LEGACY = {k: replace(v, source="legacy: colours read off photographs of planed boards that are "
                      "not recorded (no citable source)") for k, v in _LEGACY.items()}

#: Presets whose colours come from a published description, each quoted in ``source``.
_CITED: dict[str, Species] = {s.name: s for s in (
    _cited("red-oak", "moderate reddish brown", "dark reddish brown", "oak",
           f"red oak group: 'The heartwood is brown with a tinge of red.' {_HANDBOOK}"),
    _cited("white-oak", "grayish brown", "dark grayish brown", "oak",
           f"white oak group: 'The heartwood is generally grayish brown.' {_HANDBOOK}"),
    _cited("black-walnut", "light brown", "dark brown", "walnut",
           f"'The heartwood of black walnut varies from light to dark brown' {_HANDBOOK}"),
    _cited("black-cherry", "light reddish brown", "dark reddish brown", "cherry",
           f"'The heartwood of black cherry varies from light to dark reddish brown' {_HANDBOOK}"),
    _cited("white-ash", "moderate brown", "dark brown", "oak",
           f"'Heartwood of commercial white ash is brown' {_HANDBOOK}"),
    _cited("sassafras", "grayish brown", "dark brown", "oak",
           f"'heartwood varies from dull grayish brown to dark brown' {_HANDBOOK}"),
    _cited("black-willow", "light reddish brown", "grayish brown", "walnut",
           f"'The heartwood of black willow is grayish brown or light reddish brown' {_HANDBOOK}"),
    _cited("buckeye", "yellowish white", "yellowish gray", "maple",
           f"'the creamy or yellowish white heartwood' {_HANDBOOK}"),
    _cited("ponderosa-pine", "light reddish brown", "moderate reddish brown", "pine",
           f"'The heartwood of ponderosa pine is light reddish brown' {_HANDBOOK}"),
    _cited("western-larch", "moderate yellowish brown", "dark yellowish brown", "pine",
           f"'The heartwood of western larch is yellowish brown' {_HANDBOOK}"),
    _cited("douglas-fir", "moderate reddish orange", "moderate red", "pine",
           "'The heartwood is orange red to red or sometimes yellowish.' US Navy, Naval "
           "Facilities Engineering Command, Wood Protection, NAVFAC MO-312, sec. 3, "
           "http://navalfacilities.tpub.com/mo312/mo3120059.htm"),
    _cited("engelmann-spruce", "pinkish white", "pinkish gray", "spruce",
           "'The heartwood of Engelmann spruce is nearly white with a slight tinge of red.' "
           "Biermann, C.J. (1996), Handbook of Pulping and Papermaking, 2nd ed., Academic Press, "
           "ch. 26, p. 565"),
)}

#: Every species preset: the legacy six and the cited ones (README, "Species presets").
SPECIES: dict[str, Species] = {**_LEGACY, **_CITED}


def get_species(species: Species | str) -> Species:
    """Return a :class:`Species` from a preset name or a Species: ``species`` is a key of
    :data:`SPECIES` (``"oak"``, ``"walnut"``, ...) or a :class:`Species`, returned as it is."""
    if isinstance(species, Species):
        return species
    # a list or dict asked with `in` raised a bare TypeError (unhashable)
    if not isinstance(species, str) or species not in SPECIES:
        raise WoodcamError(f"species must be one of the presets {', '.join(SPECIES)}; got {species!r}; "
                           "pass one of them (woodcam species lists them), or species=None for the "
                           "block's own")
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
        Fitted colour over the ring phase ``years mod 1`` (= sqrt(ARF)) in :data:`LUT_BINS`
        equal bins, for surfaces normal to X, Y, Z (block frame); ``None`` uses the
        species ramp with end-grain darkening. Rows with NaN fall back to the species ramp.
    knot_lut : (LUT_BINS, 3) float or None
        Fitted colour of knot wood over the knot's own ring phase (the field's years inside a
        knot run round its strand), any surface orientation. Where given, knot wood takes this
        colour, blended with the stem's by the field's knot weight, instead of the stem colour
        darkened by ``knots.alive_darkening`` (the photos' knots carry their own darkness and
        rings); dead knots are still darkened and outlined by ``knots``. ``None`` or NaN: the
        darkening of ``knots``.
    axis_exposure : (3, 2, 3) float or None
        Colour gain of the fitted ramps at the low and high face of each axis (block frame,
        per RGB channel), linearly interpolated along the axis between ``exposure_span_mm``
        and held beyond: the photos of opposite faces differ in exposure or wood colour (H11:
        clear-wood luminance 0.76 on top, 0.66 on the bottom), which one ramp per axis cannot
        show. Applies to axes with a fitted ramp; ``None``: gain 1.
    exposure_span_mm : (3, 2) float or None
        Coordinates (mm, block frame) of the low and high face of each axis, where
        ``axis_exposure``'s two gains hold; required with it.
    knots : KnotShading
        How knot wood is coloured on fields that report knot features
        (:mod:`woodcam.appearance.knots`: one shading for every renderer).
    seed : int
        Noise seed.
    knot_darkening_alive, knot_darkening_dead, dead_outline_rgb : optional
        Shorthands that replace those settings of ``knots`` (the CLI's ``--knot-darkening``
        and ``--knot-outline``).
    texture_frame : LogFrame or None
        The frame the wood's texture (pores, fibre streaks, end-grain mottling) is drawn in,
        placed in this block's frame (mm): a block cut out of another's wood (a sized built-in
        or log block, a block of a grown object, :mod:`woodcam.stock`) draws the other's (the
        object's) texture at the same wood point, so the same piece of wood has the same
        colours in both. ``None``: this block's frame.
        Set by the block spec, not an appearance parameter.
    """

    species: Species | str = "oak"
    axis_luts: np.ndarray | None = None
    knot_lut: np.ndarray | None = None
    axis_exposure: np.ndarray | None = None
    exposure_span_mm: np.ndarray | None = None
    knots: KnotShading = KnotShading()
    seed: int = 0
    knot_darkening_alive: InitVar[float | None] = None
    knot_darkening_dead: InitVar[float | None] = None
    dead_outline_rgb: InitVar[tuple[float, float, float] | None] = None
    texture_frame: LogFrame | None = None

    def __repr__(self) -> str:
        # arrays as shapes (summary_repr), and the species by its name: its ten numbers and its
        # source sentence made a knotty stock's Wood repr one line of ~1100 characters; the
        # optional tables left at their defaults (None, mostly) are left out
        text = summary_repr(self, skip_defaults=True)
        species = self.species
        if isinstance(species, Species):
            text = text.replace(f"species={species!r}", f"species=<Species {species.name!r}>", 1)
        return text

    def __post_init__(self, knot_darkening_alive=None, knot_darkening_dead=None,
                      dead_outline_rgb=None):
        object.__setattr__(self, "species", get_species(self.species))
        # 'a' was int()'s ValueError at the first colour, 2**70 an OverflowError of np.int64 and
        # 1.5 was read as seed 1; the compiled noise adds up to 2 to it in int64
        object.__setattr__(self, "seed", int(check_number(self.seed, "seed", lo=0, hi=2**62, integer=True,
                                                          fix="the colour noise's seed, e.g. seed=0")))
        check_texture_frame(self.texture_frame)
        if not isinstance(self.knots, KnotShading):  # a dict was an AttributeError at the first colour
            raise WoodcamError(f"knots must be a KnotShading; got {type(self.knots).__name__}; pass "
                               "KnotShading(alive_darkening=..., ...) or the knot_darkening_* keywords")
        changes = {k: v for k, v in (("alive_darkening", knot_darkening_alive),
                                     ("dead_darkening", knot_darkening_dead),
                                     ("outline_rgb", dead_outline_rgb)) if v is not None}
        if changes:
            object.__setattr__(self, "knots", replace(self.knots, **changes))
        # each parsed by _lut_array: 'abc' was numpy's bare ValueError, complex numbers were
        # taken as their real parts under numpy's ComplexWarning
        if self.axis_luts is not None:
            object.__setattr__(self, "axis_luts", _lut_array(self.axis_luts, "axis_luts", (3, LUT_BINS, 3)))
        if self.knot_lut is not None:
            object.__setattr__(self, "knot_lut", _lut_array(self.knot_lut, "knot_lut", (LUT_BINS, 3)))
        if (self.axis_exposure is None) != (self.exposure_span_mm is None):
            raise WoodcamError("axis_exposure and exposure_span_mm go together; got one without the "
                               "other: give both (ColorMapAppearance.fit_to_block fits them) or neither")
        if self.axis_exposure is not None:
            gains = _lut_array(self.axis_exposure, "axis_exposure", (3, 2, 3))
            span = _lut_array(self.exposure_span_mm, "exposure_span_mm", (3, 2))
            if not (np.all(np.isfinite(gains)) and np.all(gains >= 0) and np.all(np.isfinite(span))):
                raise WoodcamError("axis_exposure must hold finite gains >= 0 and exposure_span_mm finite "
                                   f"coordinates; got {gains.tolist()} and {span.tolist()}")
            object.__setattr__(self, "axis_exposure", gains)
            object.__setattr__(self, "exposure_span_mm", span)

    # -- the ramp -------------------------------------------------------------------------------

    def ramp(self, arf_values: ArrayLike) -> np.ndarray:
        """Species colour at ARF values ``(n,)`` -> ``(n, 3)`` float32 (side grain, no noise)."""
        s = self.species
        # None was an IndexError, 'a' numpy's ValueError
        a = real_numbers(arf_values, "arf_values", fix="e.g. [0.0, 0.5, 0.9]")
        if a.ndim != 1:
            raise WoodcamError(f"arf_values must be one ARF value per point, shape (n,); got shape {a.shape}; "
                               "e.g. [0.0, 0.5, 0.9]")
        t = _smoothstep(s.latewood_start, 1.0, a.astype(np.float32))[:, None]
        early = np.asarray(s.earlywood_rgb, np.float32)
        late = np.asarray(s.latewood_rgb, np.float32)
        return early + t * (late - early)

    # -- per-axis colourings ----------------------------------------------------------------------

    def axis_colors(self, field: GrowthFieldLike, points_mm: ArrayLike) -> np.ndarray:
        """The three per-axis colourings of eq. 10, shape ``(3, n, 3)``: normals X, Y, Z."""
        return self._shade(field, points_mm, None)

    def color(self, field: GrowthFieldLike, points_mm: ArrayLike, normals: ArrayLike) -> np.ndarray:
        """Colour ``(n, 3)`` in [0, 1] of surfaces at ``points_mm`` with unit ``normals``.

        The three per-axis colourings blended by eq. 10 (:func:`blend_axis_colors`), computed
        in one compiled pass per point.
        """
        p = check_points(points_mm)
        if not (isinstance(normals, np.ndarray) and normals.dtype == np.float32 and normals.shape == p.shape):
            # Anything but what Wood.color passes (float32 (n, 3), checked there) is checked here:
            # one normal for n points was read past its end by the compiled kernel (NaN or another
            # array's memory as colours), None was numba's TypingError, complex normals lost their
            # imaginary parts. wood.py imports this module, so its rule is imported here.
            from .wood import check_normals

            normals = check_normals(normals, p.shape)
        return self._shade(field, p, normals)

    def _shade(self, field, points_mm, normals):
        p = check_points(points_mm)
        s = self.species
        years, grain, knots = _field_sample(field, p)
        n = len(p)
        if knots is None:
            zeros = np.zeros(n, np.float32)
            knot = dead = outline = zeros
        else:
            knot, dead, outline = (np.asarray(knots[k], np.float32) for k in ("knot", "dead", "outline"))
        luts = self.axis_luts if self.axis_luts is not None else np.full((3, LUT_BINS, 3), np.nan, np.float32)
        lut_ok = np.array([np.all(np.isfinite(luts[k])) for k in range(3)])
        knot_lut = self.knot_lut if self.knot_lut is not None else np.full((LUT_BINS, 3), np.nan, np.float32)
        knot_lut_ok = bool(np.all(np.isfinite(knot_lut)))
        if self.axis_exposure is not None and self.exposure_span_mm is not None:
            gains, span = self.axis_exposure, self.exposure_span_mm
        else:
            gains, span = np.ones((3, 2, 3), np.float32), np.zeros((3, 2), np.float32)
        blend = normals is not None
        out = np.empty((1 if blend else 3, n, 3), np.float32)
        params = np.array([s.latewood_start, s.pore_contrast, float(s.ring_porous), s.pore_across_mm,
                           s.pore_along_mm, s.streak_contrast, s.endgrain_darkening,
                           s.endgrain_roughness, self.knots.alive_darkening,
                           self.knots.dead_darkening], np.float32)
        colours = np.array([s.earlywood_rgb, s.latewood_rgb, self.knots.outline_rgb], np.float32)
        grain = np.ascontiguousarray(grain, np.float32)
        p32 = p.astype(np.float32)
        # the texture is a function of the wood point: drawn in the frame of the block this one
        # was cut from (the fibre noise of a sized built-in was its own frame's: other colours)
        frame = self.texture_frame
        q, gq = (p32, grain) if frame is None else (
            frame.to_log(p).astype(np.float32), np.ascontiguousarray(frame.direction_to_log(grain), np.float32))
        _shade_kernel(arf(years).astype(np.float32), grain, p32, q, gq,
                      normals if blend else np.zeros((1, 3), np.float32),
                      knot, dead, outline, params, colours, np.nan_to_num(luts).astype(np.float32),
                      lut_ok, np.nan_to_num(knot_lut).astype(np.float32), knot_lut_ok,
                      gains, span, np.int64(self.seed), TABLE, blend, out)
        return out[0] if blend else out

    # -- fitting to photos ------------------------------------------------------------------------

    @classmethod
    def fit_to_block(cls, block, field, species="oak", *, anchor: RampAnchor = "auto",
                     **kwargs) -> "ColorMapAppearance":
        """Fit per-axis colour ramps (colour as a function of the ring phase ``years mod 1``,
        i.e. of sqrt(ARF)) to a block's face photos, from clear wood only (knots left out,
        :func:`_clear_wood`).

        ``anchor="field"``: for every face with a photo, the ring phase of ``field`` at each
        pixel centre is binned into :data:`LUT_BINS` equal bins and the mean photo colour per
        bin is taken; both faces of an axis are pooled. Bins no pixel falls in are filled by
        linear interpolation along the phase. Right when ``field`` puts its rings exactly on the photos'
        rings (a block's true field).

        ``anchor="ring_map"``: the same, after moving the field's ring phase on each face onto
        the face's own ring map (:func:`_registered_years`). A field fitted to ring maps puts
        its rings within a fraction of a ring of the photos' (0.1-0.2 of a ring on the Mokume
        cubes), enough to smear a latewood band over every ARF bin: the field-anchored ramp of
        a real block came out nearly flat (bakes without rings).

        ``"auto"`` (default): ``"field"`` when ``field`` is the block's true field or an axis's
        photo faces lack ring maps, else ``"ring_map"`` (per axis), as the neural appearance
        chooses its source. Axes without photos keep the species ramp. Raises if no face has
        a photo.

        With the ring-map anchor the axis's ring shape comes from its face with the strongest
        rings (:func:`_pooled_ring_shape`: a face whose fitted rings miss its photo's bins
        flat) and each face's exposure is fitted (``axis_exposure``). Where the field reports
        knots, knot wood gets a ramp of its own (``knot_lut``, :func:`_knot_lut`) from the
        photos' knot pixels; ``knot_lut=None`` keeps the ``knots`` darkening instead.
        """
        if anchor not in ("auto", "field", "ring_map"):
            raise WoodcamError(f"anchor must be one of auto, field, ring_map; got {anchor!r}")
        species = get_species(species)
        photo_faces = [f for f in block.faces.values() if f.photo is not None]
        if not photo_faces:
            raise WoodcamError(
                f"block {block.name!r} has no face photos to fit a colour map to; "
                "use a species preset instead (ColorMapAppearance(species=...))"
            )
        luts = np.full((3, LUT_BINS, 3), np.nan)
        centres = (np.arange(LUT_BINS) + 0.5) / LUT_BINS
        true_field = field is getattr(block, "true_field", None)
        knot_phase, knot_rgb, knot_ring, knot_registered = [], [], [], False
        exposure = np.ones((3, 2, 3))
        span = np.array([[0.0, float(v)] for v in block.size_mm])
        for k in range(3):
            faces = [f for f in photo_faces if FACE_AXIS[f.name] == k]
            if not faces:
                continue
            maps = all(f.ring_map is not None for f in faces)
            use_maps = anchor == "ring_map" or (anchor == "auto" and maps and not true_field)
            if use_maps and not maps:
                raise WoodcamError(
                    f"anchor='ring_map' needs a ring map on every photographed face; faces "
                    f"{[f.name for f in faces if f.ring_map is None]} of block {block.name!r} have none; "
                    "use anchor='field'"
                )
            luts[k], kp, kr, kb, gains = _field_lut(faces, field, block.size_mm, centres, register=use_maps)
            for coord, gain in gains:  # the face at 0 (low) or at the block's size (high)
                exposure[k, int(coord > span[k, 1] / 2)] = gain
            knot_phase.append(kp)
            knot_rgb.append(kr)
            knot_ring.append(kb)
            knot_registered |= use_maps and len(kp) > 0
        if "knot_lut" in kwargs:  # the caller's own knot ramp (None: the KnotShading darkening)
            knot_lut = kwargs.pop("knot_lut")
        else:
            knot_lut = _knot_lut(np.concatenate(knot_phase or [np.zeros(0)]),
                                 np.concatenate(knot_rgb or [np.zeros((0, 3))]),
                                 np.concatenate(knot_ring or [np.zeros((0, 3))]), luts, species,
                                 centres, matched=knot_registered)
        fitted_exposure = {"axis_exposure": exposure, "exposure_span_mm": span} if np.any(exposure != 1.0) else {}
        return cls(species=species, axis_luts=luts, knot_lut=knot_lut, **{**fitted_exposure, **kwargs})

    def with_params(self, **changes) -> "ColorMapAppearance":
        """Copy with some parameters changed."""
        return replace(self, **changes)


def _field_lut(faces, field, size_mm, centres, register: bool = False):
    """Mean photo colour per ring-phase bin of ``field`` over ``faces``, from clear wood
    (:func:`_clear_wood`), and the knot wood seen on them.

    With ``register`` (a fitted field), the field's ring phase is first moved onto each face's
    ring map (:func:`_registered_years`), the axis takes the ring shape of its face with the
    strongest rings (:func:`_pooled_ring_shape`), and each face gets an exposure gain.

    Returns ``(lut (LUT_BINS, 3), knot_phase (m,), knot_rgb (m, 3), knot_ring (m, 3),
    exposure)``: the stem ramp; for the ``m`` knot pixels (:func:`_knot_core`), their ring
    phase, photo colour and ring-scale part of it (the photo band-passed at
    :data:`RING_BAND_PX_PER_SIDE`; zeros without ``register``), for :func:`_knot_lut`; and
    each face's ``(coordinate along the axis in mm, gain (3,))``: its clear wood's mean photo
    colour over the mean the ramp gives the same pixels (empty without ``register``: a true
    field's photos are the ramp's own).
    """
    from scipy import ndimage

    per_face = []  # (sums, counts) of each face's clear wood per ring-phase bin
    knot_phase, knot_rgb, knot_ring = [np.zeros(0)], [np.zeros((0, 3))], [np.zeros((0, 3))]
    for face in faces:
        pts = face_pixel_points(face.name, face.shape, size_mm).reshape(-1, 3)
        g, knot = _years_and_knots(field, pts)
        if register:
            g = _registered_years(face, g.reshape(face.shape)).ravel()
        phase = np.mod(g, 1.0)
        clear = _clear_wood(face, knot, len(pts))
        rgb = face.photo.reshape(-1, 3).astype(float) / 255.0
        per_face.append(_binned(phase[clear], rgb[clear]))
        if knot is not None:
            core = _knot_core(face, knot)
            ring = np.zeros((int(core.sum()), 3))
            if register and core.any():
                px = max(face.shape) / 256.0
                photo = face.photo.astype(float) / 255.0
                fine, coarse = (ndimage.gaussian_filter(photo, (q * px, q * px, 0)) for q in RING_BAND_PX_PER_SIDE)
                ring = (fine - coarse).reshape(-1, 3)[core]
            knot_phase.append(phase[core])
            knot_rgb.append(rgb[core])
            knot_ring.append(ring)
    sums = sum(f[0] for f in per_face)
    counts = sum(f[1] for f in per_face)
    if register and len(per_face) > 1 and counts.all():
        sums = _pooled_ring_shape(per_face) * counts[:, None]
    lut = _binned_lut(sums, counts, centres)
    exposure = []
    if register and np.isfinite(lut).all():
        for face, (s, c) in zip(faces, per_face):
            if c.any():
                model = (c @ lut) / c.sum()
                coord = float(face_pixel_points(face.name, (1, 1), size_mm)[0, 0, FACE_AXIS[face.name]])
                exposure.append((coord, (s.sum(axis=0) / c.sum()) / np.maximum(model, 1e-6)))
    return (lut, np.concatenate(knot_phase), np.concatenate(knot_rgb), np.concatenate(knot_ring),
            exposure)


def _pooled_ring_shape(per_face) -> np.ndarray:
    """One ramp ``(LUT_BINS, 3)`` from the faces of an axis, each given as ``(sums (LUT_BINS, 3),
    counts (LUT_BINS,))`` of its clear-wood colours per ring-phase bin: the ring shape (colour
    less the face's mean) of the face with the strongest rings (rms of the shape's luminance
    over its pixels), on the mean colour of all the faces' pixels.

    Why: a face's registered phase still sits off its photo's rings, the more so where the
    fitted field misses them, and binned colours average towards the face's mean the further
    off it is: the face with the strongest ring shape is the one whose phase is least off.
    Pooled by pixel count, a face whose rings the field misses (H11's knotted faces C and F:
    their photos' rings sweep round the knot) averaged the other face's rings away, and the
    side faces baked nearly plain (H11's X ramp: 0.03 of luminance from ring to ring where its
    clear face alone shows 0.05). A least-squares blend of the faces' shapes (each damped by a
    gain of its own) drew 0.150 of luminance from ring to ring where the best face alone draws
    0.175, on a synthetic block whose two faces are off by different amounts
    (tests/appearance/test_colormap.py, the ring-map test).
    """
    luma = np.array([0.299, 0.587, 0.114])
    total = sum(s for s, _ in per_face)
    n = sum(c for _, c in per_face)
    best, best_amp = None, -1.0
    for s, c in per_face:
        if not c.any():
            continue
        d = s / np.maximum(c, 1.0)[:, None] - s.sum(axis=0) / c.sum()
        amp = float(np.sum(c * (d @ luma) ** 2) / c.sum())
        if amp > best_amp:
            best, best_amp = d, amp
    if best is None or not n.all():
        return total / np.maximum(n, 1.0)[:, None]
    return total.sum(axis=0) / n.sum() + best


def _knot_lut(phase, rgb, ring, stem_luts, species, centres, matched: bool) -> np.ndarray | None:
    """Colour of knot wood over its ring phase ``(LUT_BINS, 3)`` from the knot pixels' ring
    ``phase (m,)``, photo colour ``rgb (m, 3)`` and its ring-scale part ``ring (m, 3)``
    (:func:`_field_lut`); None without knot pixels.

    ``matched=False`` (the field's phase is the photo's: a true field): the mean colour per
    phase bin, as the stem ramp.

    ``matched=True`` (a fitted field): inside a knot the fitted rings do not sit on the photo's
    (H11: a knot fitted from its masks has its own ring count and centre; the ring maps have no
    lines there to register on), so the binned colour is the knot's mean in every bin: one flat
    dark ellipse. The knot's rings are instead drawn with the photos' own ring contrast at the
    stem's ring profile: the knot pixels sorted by the luminance of their ring-scale part are
    split into ``LUT_BINS`` equal groups, and the ``j``-th darkest group's mean ring part, added
    to the knots' mean colour, goes to the ``j``-th darkest bin of the stem ramp (a branch lays
    down earlywood and latewood as the stem does). The knot's colour and ring contrast are the
    photos'; where its rings fall is the field's. (The ring-scale part, not the whole colour:
    the knots' slow shading from rim to centre is no ring contrast, and drew rings twice as
    strong as H11's photos.)
    """
    if len(phase) == 0:
        return None
    if not matched:
        sums, counts = _binned(phase, rgb)
        return _binned_lut(sums, counts, centres)
    luma = np.array([0.299, 0.587, 0.114])
    ok = [k for k in range(3) if np.isfinite(stem_luts[k]).all()]
    if ok:
        profile = np.mean([stem_luts[k] @ luma for k in ok], axis=0)
    else:
        profile = ColorMapAppearance(species).ramp(centres ** 2) @ luma
    spec = np.fft.rfft(profile)
    spec[KNOT_PROFILE_HARMONICS + 1:] = 0.0  # the ring profile's shape, not its bin noise
    order = np.argsort(np.fft.irfft(spec, n=LUT_BINS), kind="stable")
    ring = ring - ring.mean(axis=0)  # (near a knot's rim the wide blur mixes in the lighter stem)
    groups = np.array_split(np.argsort(ring @ luma, kind="stable"), LUT_BINS)
    lut = np.empty((LUT_BINS, 3))
    lut[order] = rgb.mean(axis=0) + np.stack([ring[g].mean(axis=0) for g in groups])
    return np.clip(lut, 0.0, 1.0)


def _binned(phase, rgb):
    """``(sums (LUT_BINS, c), counts (LUT_BINS,))`` of colours ``rgb (m, c)`` per ring-phase
    bin of ``phase (m,)`` (years mod 1)."""
    b = np.minimum((np.mod(phase, 1.0) * LUT_BINS).astype(int), LUT_BINS - 1)
    counts = np.bincount(b, minlength=LUT_BINS).astype(float)
    sums = np.stack([np.bincount(b, rgb[:, c], minlength=LUT_BINS) for c in range(rgb.shape[1])], axis=1)
    return sums, counts


def _binned_lut(sums, counts, centres) -> np.ndarray:
    """``(LUT_BINS, 3)`` mean colour per bin; empty bins linearly interpolated along the phase,
    all NaN when no bin has a pixel."""
    if not counts.any():
        return np.full((LUT_BINS, 3), np.nan)
    ok = counts > 0
    mean = sums[ok] / counts[ok, None]
    return np.stack([np.interp(centres, centres[ok], mean[:, c]) for c in range(3)], axis=1)


def _knot_core(face, knot) -> np.ndarray:
    """``(n,)`` bool: knot wood of ``face``'s pixels for the knot ramp, the field's knot weight
    ``knot (n,)`` above :data:`KNOT_CORE_ABOVE`, within the face's ``knot_mask`` where it has one
    (a fitted knot may reach past the photo's knot)."""
    core = knot > KNOT_CORE_ABOVE
    mask = face.extras.get("knot_mask")
    if mask is not None and np.shape(mask) == tuple(face.shape):
        core &= np.asarray(mask, bool).ravel()
    return core


def _years_and_knots(field, points_mm):
    """``(years (n,), knot (n,) or None)`` of ``field`` at ``points_mm (n, 3)``: the growth
    time and, where the field has ``knot_features``, its knot weights. A knotted field that
    also answers ``evaluate`` gives both from one pass of its knot model (its ``__call__`` and
    ``knot_features`` are each a whole pass). A field with ``evaluate`` but no
    ``knot_features`` (a woodified field's obstacles) reports no knots here."""
    features = getattr(field, "knot_features", None)
    if not callable(features):
        return np.asarray(field(points_mm), float), None
    evaluate = getattr(field, "evaluate", None)
    if callable(evaluate):
        out = evaluate(points_mm)
        return np.asarray(out["years"], float), np.asarray(out["knot"], float)
    return np.asarray(field(points_mm), float), np.asarray(features(points_mm)["knot"], float)


def _clear_wood(face, knot, n: int) -> np.ndarray:
    """``(n,)`` bool over ``face``'s ``n`` pixels: True off any knot, by the face's
    ``knot_mask`` and the field's own knot weights ``knot (n,)`` where it reports them (else
    None; :func:`_years_and_knots`). The ramp is the colour of the stem's
    rings; knot wood is dark and has its own rings (a knot's ARF runs round its strand), so
    binning it by the stem's ARF only adds a dark cast spread over every bin (the ring contrast
    of H11's knotted faces halved and even changed sign), and the renderer darkens knots again
    on top (:class:`~woodcam.appearance.knots.KnotShading`)."""
    clear = np.ones(n, bool)
    mask = face.extras.get("knot_mask")
    if mask is not None and np.shape(mask) == tuple(face.shape):
        clear &= ~np.asarray(mask, bool).ravel()
    if knot is not None:
        clear &= knot < KNOT_FREE_BELOW
    return clear


def _registered_years(face, years: np.ndarray) -> np.ndarray:
    """``years (h, w)`` of a field on ``face``'s pixels, its ring phase moved onto the face's
    ring map (:func:`register_ring_phase` at the face's image scale)."""
    sigma = RING_REGISTRATION_BLUR_PX_PER_SIDE * max(face.shape) / 256.0
    return register_ring_phase(years, face.ring_map, sigma)


def register_ring_phase(years: np.ndarray, ring_map: np.ndarray, sigma_px: float) -> np.ndarray:
    """Growth-time image ``years (h, w)`` with its ring phase moved onto ``ring_map (h, w)``.

    On the ring map's lines (value > 0.5) the field should be at a whole year; the offset
    ``round(g) - g`` there is averaged around each pixel (circular mean, Gaussian window of
    ``sigma_px`` pixels) and added to ``g``. The field keeps the ring order and which side of a
    boundary is latewood (growth runs outward); the ring map says exactly where the boundary
    is. Far from any line the shift fades out. Returns ``years`` unchanged when the map has
    (almost) no lines.
    """
    from scipy import ndimage

    years = np.asarray(years, float)
    on = np.asarray(ring_map, float) > 0.5
    if on.sum() < 16:
        return years
    delta = np.where(on, np.round(years) - years, 0.0)
    z = np.where(on, np.exp(2j * np.pi * delta), 0.0)
    re = ndimage.gaussian_filter(z.real, sigma_px, mode="reflect")
    im = ndimage.gaussian_filter(z.imag, sigma_px, mode="reflect")
    weight = ndimage.gaussian_filter(on.astype(float), sigma_px, mode="reflect")
    shift = np.angle(re + 1j * im) / (2 * np.pi)
    return years + shift * np.clip(weight / (weight.max() + 1e-12) * 4.0, 0.0, 1.0)


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


@numba.njit(nogil=True, fastmath=True, cache=True)
def _shade_kernel(a, grain, p, q, gq, normals, knot, dead, outline, params, colours, luts, lut_ok,
                  knot_lut, knot_lut_ok, gains, span, seed, table, blend, out):  # pragma: no cover - compiled
    """Per point: ramp, pores and streaks, end grain per axis, knots, and eq. 10 (``blend``, by
    :func:`~woodcam.appearance.orientation.eq10_weights`, the one implementation).

    ``p``, ``grain`` (n, 3): points and fibre directions in the block frame (end grain,
    exposure); ``q``, ``gq`` (n, 3): the same in the texture's frame (the noise).

    One compiled pass instead of ~40 numpy array operations with their temporaries, which
    made colour lookup memory-bound. Writes the blend to ``out[0] (n, 3)`` when ``blend``,
    else the three per-axis colourings to ``out (3, n, 3)``.
    """
    lw_start, pore_c, ring_porous, p_across, p_along = params[0], params[1], params[2], params[3], params[4]
    streak_c, eg_dark, eg_rough, dark_alive, dark_dead = params[5], params[6], params[7], params[8], params[9]
    inv_a, inv_l = 1.0 / p_across, 1.0 / p_along
    inv_a4, inv_l4 = 0.25 * inv_a, 0.25 * inv_l
    nb = luts.shape[1]
    col = np.empty(3, np.float32)
    for i in range(a.shape[0]):
        # ramp between earlywood and latewood (smoothstep from latewood_start to 1)
        t = min(max((a[i] - lw_start) / (1.0 - lw_start), 0.0), 1.0)
        t = t * t * (3.0 - 2.0 * t)
        gx, gy, gz = gq[i, 0], gq[i, 1], gq[i, 2]
        px, py, pz = q[i, 0], q[i, 1], q[i, 2]
        along = px * gx + py * gy + pz * gz
        # one solid noise stretched along the grain: streaks on side grain, dots on end grain
        s1 = along * (inv_l - inv_a)
        fibre = noise_at(px * inv_a + s1 * gx, py * inv_a + s1 * gy, pz * inv_a + s1 * gz, table, seed)
        pores = max(fibre - 0.35, 0.0) / 0.65
        if ring_porous > 0.5:
            pores *= 1.0 - t
        s4 = along * (inv_l4 - inv_a4)
        streak = noise_at(px * inv_a4 + s4 * gx, py * inv_a4 + s4 * gy, pz * inv_a4 + s4 * gz,
                          table, seed + 1)
        shade = (1.0 + streak_c * streak) * (1.0 - pore_c * pores)
        rough = noise_at(2.0 * px * inv_a, 2.0 * py * inv_a, 2.0 * pz * inv_a, table, seed + 2)
        # knot wood darker, dead-knot outline drawn over (KnotShading.apply, appearance/knots.py)
        # (a fitted knot ramp already has the knot's darkness: only dead knots darken further)
        kfac = (1.0 - (0.0 if knot_lut_ok else dark_alive * knot[i])) * (1.0 - dark_dead * dead[i])
        ol = outline[i]
        # lut position (bin centres) for fitted ramps: bins of the ring phase sqrt(ARF); clamped
        # at both ends (not wrapped), so a true field's latewood -> earlywood step stays sharp
        tl = min(max(np.sqrt(a[i]) * nb - 0.5, 0.0), nb - 1.0)
        i0 = min(int(tl), nb - 2)
        fl = tl - i0
        if blend:
            w0, w1, w2 = eq10_weights(normals[i, 0], normals[i, 1], normals[i, 2])
            out[0, i, 0] = 0.0
            out[0, i, 1] = 0.0
            out[0, i, 2] = 0.0
        for k in range(3):
            g = abs(grain[i, k])  # 1 where a plane normal to axis k cuts the fibres across
            f = shade * (1.0 + eg_rough * g * rough) * kfac
            # exposure of the fitted ramp between the axis's two faces (gain 1 with none fitted)
            width = span[k, 1] - span[k, 0]
            u = 0.0 if width == 0.0 else min(max((p[i, k] - span[k, 0]) / width, 0.0), 1.0)
            for c in range(3):
                if lut_ok[k]:
                    v = luts[k, i0, c] * (1.0 - fl) + luts[k, i0 + 1, c] * fl
                else:
                    v = (colours[0, c] + t * (colours[1, c] - colours[0, c])) * (1.0 - eg_dark * g * g)
                if knot_lut_ok:
                    kv = knot_lut[i0, c] * (1.0 - fl) + knot_lut[i0 + 1, c] * fl
                    v = v * (1.0 - knot[i]) + kv * knot[i]
                if lut_ok[k]:
                    v = v * (gains[k, 0, c] * (1.0 - u) + gains[k, 1, c] * u)
                v = v * f
                v = v * (1.0 - ol) + colours[2, c] * ol
                col[c] = min(max(v, 0.0), 1.0)
            if blend:
                w = w0 if k == 0 else (w1 if k == 1 else w2)
                for c in range(3):
                    out[0, i, c] += w * col[c]
            else:
                for c in range(3):
                    out[k, i, c] = col[c]
