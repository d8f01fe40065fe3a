"""Face photos of a synthetic block: the built-in wood colour and the camera that photographs it."""

from __future__ import annotations

import numpy as np

from ..appearance.colormap import get_species
from ..fields.base import LogFrame, arf, check_points, check_texture_frame, evaluate, grain_direction

#: Species whose earlywood/latewood colours the built-in photos use (the one colour table,
#: :data:`woodcam.appearance.SPECIES`).
BUILTIN_PHOTO_SPECIES = "pine"


class _BuiltinWood:
    """Built-in appearance (used when no ``wood`` is given): ``color(points_mm, normals)``.

    Earlywood -> latewood by the field's ARF (eq. 6 of seed 000) with a smooth latewood band
    over about the last 30 % of each ring, a per-ring tone, end grain (|fibre . normal| near 1)
    a little darker, and a fibre texture: smooth 3-D noise stretched along the fibres
    (``_FIBRE_SCALES_MM``: streaks on side grain, pores on end grain). All random parts are
    drawn once per block, so the six faces agree where they meet.

    ``texture_frame`` (a :class:`~woodcam.fields.base.LogFrame` placed in the block frame, or
    None for the block's own): the frame the fibre texture is drawn in. A block cut out of
    another's wood draws the other's (``ColorMapAppearance.texture_frame``), so its photos are
    the other's at the same wood point.
    """

    #: (across-fibre, along-fibre) noise scales (mm) and weights of the fibre texture octaves.
    _FIBRE_SCALES_MM = ((0.22, 6.0, 0.6), (0.9, 25.0, 0.4))
    _FIBRE_AMPLITUDE = 0.05

    def __init__(self, field, rng: np.random.Generator, lattice: int = 64,
                 species: str = BUILTIN_PHOTO_SPECIES, texture_frame: LogFrame | None = None):
        s = get_species(species)
        self.texture_frame = check_texture_frame(texture_frame)
        self.earlywood = np.asarray(s.earlywood_rgb, float)
        self.latewood = np.asarray(s.latewood_rgb, float)
        self.field = field
        self.phase = rng.uniform(0, 2 * np.pi)
        self.lattice = [rng.standard_normal((lattice,) * 3).astype(np.float32) for _ in self._FIBRE_SCALES_MM]
        self.offsets = rng.uniform(0, lattice, (len(self._FIBRE_SCALES_MM), 3))

    def _fibre_texture(self, p: np.ndarray, fib: np.ndarray) -> np.ndarray:
        from scipy.ndimage import map_coordinates

        frame = self.texture_frame
        if frame is not None:  # the wood point and fibre in the frame of the block cut from
            p, fib = frame.to_log(p), frame.direction_to_log(fib)
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
        rgb = self.earlywood + late[:, None] * (self.latewood - self.earlywood)
        rgb = rgb * (tone * tex * (1.0 - 0.15 * end_grain))[:, None]
        return np.clip(rgb, 0.0, 1.0)


class _RealisticWood(_BuiltinWood):
    """Face colour closer to the real Mokume photos than :class:`_BuiltinWood` (the ring
    detector's realistic evaluation and training faces, :func:`woodcam.synth.ring_eval_faces`).

    What the real faces show and the built-in colour lacks:

    - ``"softwood"`` (spruce, H11): the latewood is a narrow dark line, 10-25 % of a ring, whose
      density rises to the ring boundary and drops there at once, so the darkest line of a ring
      *is* its boundary; faint rings (contrast drawn per ring) beside strong ones;
    - ``"ring-porous"`` (oak, CN03): a dark band of large earlywood pores starts at the ring
      boundary (sharp) and fades over 15-30 % of the ring; the pores are specks (pore noise,
      stretched along the fibres), the latewood between is lighter;
    - both: rays (thin streaks across the rings, a little lighter) and a broad figure (a slow
      colour drift across the face) and a stronger lighting gradient than the camera's vignette.
    """

    def __init__(self, field, rng: np.random.Generator, style: str = "softwood", lattice: int = 64):
        super().__init__(field, rng, lattice=lattice,
                         species="oak" if style == "ring-porous" else BUILTIN_PHOTO_SPECIES)
        self.style = style
        self.band = rng.uniform(0.10, 0.25) if style == "softwood" else rng.uniform(0.15, 0.30)
        self.ring_contrast = rng.uniform(0.35, 1.0, 4096)       # per ring: faint and strong rings
        self.pores = rng.standard_normal((lattice,) * 3).astype(np.float32)
        self.rays = rng.standard_normal((lattice,) * 3).astype(np.float32)
        self.figure = rng.standard_normal((8,) * 3).astype(np.float32)
        self.ray_strength = rng.uniform(0.0, 0.08)
        self.figure_strength = rng.uniform(0.0, 0.12)

    def _noise(self, grid, q) -> np.ndarray:
        from scipy.ndimage import map_coordinates

        return map_coordinates(grid, q.T, order=1, mode="grid-wrap")

    def color(self, points_mm, normals, years=None, years_per_px=None) -> np.ndarray:
        p = check_points(points_mm)
        years = evaluate(self.field, p) if years is None else years
        fib = np.asarray(grain_direction(self.field, p), dtype=float)
        end_grain = np.abs((fib * np.asarray(normals, float)).sum(1))
        frac = years - np.floor(years)
        ring = np.floor(years).astype(np.int64)
        k = self.ring_contrast[np.mod(ring, len(self.ring_contrast))]
        w = np.maximum(np.asarray(years_per_px, float), 1e-6) if years_per_px is not None else np.full(len(p), 1e-6)
        along = (p * fib).sum(1, keepdims=True)
        if self.style == "softwood":
            # latewood: density rising over the last `band` of the ring, darkest at its boundary;
            # the step at the boundary anti-aliased over one pixel (box filter of the pixel)
            x = np.clip((frac - (1.0 - self.band)) / self.band, 0.0, 1.0)
            before = np.clip((1.0 - frac) / w + 0.5, 0.0, 1.0)
            prev = np.clip(0.5 - frac / w, 0.0, 1.0)
            dark = x ** 1.5 * before * (1.0 - prev) + prev
            dark = dark * k
        else:
            # earlywood pore band: from the boundary (sharp) fading over `band` of the ring
            after = np.clip(frac / w + 0.5, 0.0, 1.0)             # anti-aliased start
            fade = np.exp(-np.clip(frac, 0, None) / self.band)
            q = p / 0.35 - (1.0 / 0.35 - 1.0 / 1.5) * along * fib + 7.0
            pores = np.clip(0.6 + 0.8 * self._noise(self.pores, q), 0.0, 1.5)   # specks
            dark = np.clip(after * fade * pores, 0.0, 1.2) * k
        # rays: thin streaks across the rings (radial plates: long along the fibre and the ray,
        # thin across); a little lighter
        qr = p / 0.25 - (1.0 / 0.25 - 1.0 / 3.0) * along * fib + 3.0
        rays = np.clip(self._noise(self.rays, qr) - 1.2, 0.0, None)
        figure = self._noise(self.figure, p / 20.0 + 1.0)
        ring_tone = 1.0 + 0.04 * np.sin(ring * 2.399 + self.phase)
        tex = 1.0 + self._FIBRE_AMPLITUDE * self._fibre_texture(p, fib)
        rgb = self.earlywood + dark[:, None] * (self.latewood - self.earlywood)
        shade = ring_tone * tex * (1.0 - 0.15 * end_grain) * (1.0 + self.ray_strength * rays) \
            * (1.0 + self.figure_strength * figure)
        return np.clip(rgb * shade[:, None], 0.0, 1.0)


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
