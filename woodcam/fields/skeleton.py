"""The knot field's input: a log's skeleton (pith curve, outer surface, branch strands), in mm.

The knot model of seed 003 (Wood Knot Editor, after Larsson et al. 2022) takes a tree log's
"internal grafting skeleton" as input: the pith curve, the outer stem surface and one strand per
branch. This module holds only that description (:class:`LogSkeleton`, :class:`BranchStrand`);
reading and writing logs (the CT-measured spruce log, woodcam log files, the seed's image maps)
and the generator's logs live in :mod:`woodcam.logs`, which sits above ``fields``.

Log frame (mm): ``z`` runs along the log from its butt end (``z = 0``) to ``length_mm``; ``x, y``
are horizontal. Azimuths ``omega`` (radians) are measured counter-clockwise from ``+x`` about
``+z``. The pith is a curve ``(x, y)(z)``; the outer radius ``R(z, omega)`` is measured from the
pith point at the same height.

A knot (branch strand) leaves the pith at height ``z0_mm`` and azimuth ``azimuth0_rad``. At
distance ``r`` (mm) from the pith its axis sits at height ``z0 + rise(r)`` and azimuth
``azimuth0 + twist(r)`` (so the skeleton point is ``pith(z) + r (cos omega, sin omega)``); its
diameter there is ``diameter(r)``. The branch ends (is broken off or overgrown) at ``r_end_mm``
and died at ``r_death_mm``: beyond that distance the knot is a dead (loose) knot. The three
profiles are tabulated on a grid of pith distances ``r_mm`` (0 first, increasing), so logs made
by other tools (images, generators) and the parametric real-log knots share one form.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .._checks import as_floats, real_numbers
from .._repr import summary_repr
from .._types import ArrayLike
from ..errors import WoodcamError

#: Samples per knot profile when a knot is built from model coefficients.
KNOT_TABLE_SAMPLES = 96

#: Smallest pith distance (mm) used in ``ln r`` and ``r**B`` of the real-log knot model, whose
#: twist ``G ln r`` and diameter ``A r**(1+B)`` are singular or meaningless at the pith itself.
_R_FLOOR_MM = 1.0


@dataclass(frozen=True, eq=False)
class BranchStrand:
    """One branch strand of a log (see the module docstring for the geometry).

    Parameters
    ----------
    z0_mm : float
        Height where the knot leaves the pith, log frame, mm.
    azimuth0_rad : float
        Azimuth where it leaves the pith, radians counter-clockwise from ``+x``.
    r_mm : (m,) float
        Pith distances of the profile samples, mm; ``r_mm[0] == 0``, strictly increasing.
    rise_mm : (m,) float
        Height of the knot axis above ``z0_mm`` at each ``r_mm`` (negative: it goes down).
    twist_rad : (m,) float
        Azimuth of the knot axis minus ``azimuth0_rad`` at each ``r_mm``.
    diameter_mm : (m,) float
        Knot diameter at each ``r_mm`` (>= 0).
    r_end_mm : float
        Pith distance where the branch ends; beyond it the stem grew over the stub.
    r_death_mm : float
        Pith distance where the branch died; from there on it is a dead (loose) knot. Use a value
        ``>= r_end_mm`` for a knot alive to its end.
    coefficients : dict or None
        The real-log model coefficients ``A, B, D, E, G`` when built by :meth:`from_model`,
        kept so a log file can store the knot losslessly.
    """

    z0_mm: float
    azimuth0_rad: float
    r_mm: np.ndarray
    rise_mm: np.ndarray
    twist_rad: np.ndarray
    diameter_mm: np.ndarray
    r_end_mm: float
    r_death_mm: float
    coefficients: dict | None = field(default=None)

    def __post_init__(self):
        r = np.asarray(self.r_mm, float)
        arrs = {}
        for name in ("rise_mm", "twist_rad", "diameter_mm"):
            a = np.asarray(getattr(self, name), float)
            if a.shape != r.shape:
                raise WoodcamError(
                    f"BranchStrand.{name} must have the shape of r_mm {r.shape}; got {a.shape}; "
                    "tabulate all three profiles on the same pith distances")
            arrs[name] = a
        if r.ndim != 1 or len(r) < 2 or r[0] != 0.0 or np.any(np.diff(r) <= 0):
            raise WoodcamError(
                f"BranchStrand.r_mm must be 1-D, start at 0 and strictly increase; got {r[:4]}...; "
                "sample the profiles from the pith outward")
        if np.any(arrs["diameter_mm"] < 0) or not np.all(np.isfinite(r)):
            raise WoodcamError("BranchStrand.diameter_mm must be >= 0 and finite; got a negative value; "
                               "clip the diameter model at 0")
        bad = [k for k, a in arrs.items() if not np.all(np.isfinite(a))]
        bad += [k for k in ("z0_mm", "azimuth0_rad", "r_death_mm")
                if not np.isfinite(getattr(self, k))]
        if bad:
            raise WoodcamError(f"BranchStrand: {', '.join(bad)} must be finite; got NaN or inf")
        if not (0 < self.r_end_mm < np.inf):
            raise WoodcamError(f"BranchStrand.r_end_mm must be > 0 mm and finite; got {self.r_end_mm}")
        object.__setattr__(self, "r_mm", r)
        for k, v in arrs.items():
            object.__setattr__(self, k, v)

    @classmethod
    def from_model(cls, A, B, z0, D, E, w0, G, r_end, r_death, *, r_max_mm=None,
                   samples: int = KNOT_TABLE_SAMPLES) -> "BranchStrand":
        """A knot from one row ``[A, B, z0, D, E, w0, G, r_end, r_death]`` of the real log.

        Height at pith distance ``r``: ``z0 + D sqrt(r) + E r``; azimuth ``w0 + G ln r``;
        diameter ``A r**(1 + B)`` (mm). The data's README leaves the diameter model to be
        verified. This power law gives the measured log plausible spruce knots (median 18 mm,
        at most 29 mm at 100 mm from the pith, 39 mm at the bark; see
        ``docs/img/knot_diameters.png``); ``A r + B r^2`` and ``A r + B r^1.5`` go negative
        within the knots' length; ``A r + B r^2 / 100`` reaches 64 mm in a 125 mm-radius log.
        Independent check: the width of the bumps that knots leave on the measured bark spreads
        around ``A r^(1+B)`` at ``r_end`` by 0.33 (std of log ratio, 12 clear bumps) against 0.51
        for ``A r + B r^2 / 100`` (tests/fields/test_skeleton.py).
        ``r_death < 0.1`` means the branch died at once (treated as 0).
        """
        if not 2 <= samples <= 100_000:
            raise WoodcamError(f"BranchStrand.from_model: samples must be in [2, 100000]; got {samples}")
        r_top = float(max(r_end, r_max_mm or 0.0))
        # quadratic spacing: dense near the pith, where sqrt(r) and ln(r) bend most
        r = r_top * np.linspace(0.0, 1.0, samples) ** 2
        rr = np.maximum(r, _R_FLOOR_MM)
        rise = D * np.sqrt(r) + E * r
        twist = G * np.log(rr)
        diam = np.maximum(A * rr ** (1.0 + B), 0.0)
        diam[0] = 0.0 if samples > 1 else diam[0]
        rd = 0.0 if r_death < 0.1 else float(r_death)
        return cls(float(z0), float(w0), r, rise, twist, diam, float(r_end), rd,
                   coefficients={"A": float(A), "B": float(B), "D": float(D), "E": float(E),
                                 "G": float(G)})

    def axis_at(self, r_mm) -> tuple[np.ndarray, np.ndarray]:
        """Height (mm) and azimuth (rad) of the knot axis at pith distances ``r_mm (n,)``."""
        r = np.clip(np.asarray(r_mm, float), 0.0, self.r_mm[-1])
        return (self.z0_mm + np.interp(r, self.r_mm, self.rise_mm),
                self.azimuth0_rad + np.interp(r, self.r_mm, self.twist_rad))

    def diameter_at(self, r_mm) -> np.ndarray:
        """Knot diameter (mm) at pith distances ``r_mm (n,)``, before death shrinkage."""
        r = np.clip(np.asarray(r_mm, float), 0.0, self.r_mm[-1])
        return np.interp(r, self.r_mm, self.diameter_mm)

    def to_json(self) -> dict:
        d = {"z0_mm": self.z0_mm, "azimuth0_rad": self.azimuth0_rad,
             "r_end_mm": self.r_end_mm, "r_death_mm": self.r_death_mm}
        if self.coefficients is not None:
            d["model"] = dict(self.coefficients, r_max_mm=float(self.r_mm[-1]),
                              samples=len(self.r_mm))
        else:
            d["table"] = {"r_mm": self.r_mm.tolist(), "rise_mm": self.rise_mm.tolist(),
                          "twist_rad": self.twist_rad.tolist(),
                          "diameter_mm": self.diameter_mm.tolist()}
        return d

    @classmethod
    def from_json(cls, d: dict) -> "BranchStrand":
        try:
            if "model" in d:
                m = d["model"]
                return cls.from_model(m["A"], m["B"], d["z0_mm"], m["D"], m["E"],
                                      d["azimuth0_rad"], m["G"], d["r_end_mm"],
                                      d["r_death_mm"], r_max_mm=m.get("r_max_mm"),
                                      samples=int(m.get("samples", KNOT_TABLE_SAMPLES)))
            t = d["table"]
            return cls(float(d["z0_mm"]), float(d["azimuth0_rad"]), t["r_mm"], t["rise_mm"],
                       t["twist_rad"], t["diameter_mm"], float(d["r_end_mm"]),
                       float(d["r_death_mm"]))
        except KeyError as err:
            raise WoodcamError(
                f"knot entry is missing the key {err.args[0]!r}; a knot needs z0_mm, "
                "azimuth0_rad, r_end_mm, r_death_mm and either 'model' {A,B,D,E,G} or "
                "'table' {r_mm, rise_mm, twist_rad, diameter_mm}") from err


@dataclass(frozen=True, eq=False)
class LogSkeleton:
    """A tree log: pith curve, outer surface and knots (log frame, mm; module docstring).

    Parameters
    ----------
    pith_z_mm : (h,) float
        Heights of the pith samples, strictly increasing, mm.
    pith_xy_mm : (h, 2) float
        Pith position ``(x, y)`` at each height, mm.
    radii_mm : (h, a) float
        Outer radius from the pith point at each height (rows) and azimuth (columns); column
        ``j`` is at azimuth ``2 pi j / a`` counter-clockwise from ``+x``.
    knots : tuple of Knot
    name : str
    """

    __repr__ = summary_repr  # arrays as shapes: a notebook shows one line

    pith_z_mm: np.ndarray
    pith_xy_mm: np.ndarray
    radii_mm: np.ndarray
    knots: tuple = ()
    name: str = "log"

    def __post_init__(self):
        # a string or None was numpy's bare "could not convert" ValueError / TypeError, knots=5
        # tuple()'s TypeError, knots=[1] taken and an AttributeError in the first knot field
        z, xy, rad = (as_floats(getattr(self, name)) for name in ("pith_z_mm", "pith_xy_mm", "radii_mm"))
        for name, v, shape in (("pith_z_mm", z, "(h,) heights"), ("pith_xy_mm", xy, "(h, 2) pith points"),
                               ("radii_mm", rad, "(h, a) radii")):
            if v is None:
                raise WoodcamError(f"Log.{name} must be {shape} in mm (numbers); got {getattr(self, name)!r:.60}")
        try:
            knots = tuple(self.knots)
        except TypeError:
            knots = None
        if knots is None or not all(isinstance(k, BranchStrand) for k in knots):
            raise WoodcamError(f"Log.knots must be a sequence of woodcam.fields.skeleton.BranchStrand; got "
                               f"{self.knots!r:.60}; pass () for a log without knots")
        if z.ndim != 1 or len(z) < 2 or np.any(np.diff(z) <= 0):
            raise WoodcamError(f"Log.pith_z_mm must be 1-D, >= 2 samples, strictly increasing; "
                               f"got shape {z.shape}; sort the pith samples by height")
        if xy.shape != (len(z), 2):
            raise WoodcamError(f"Log.pith_xy_mm must have shape ({len(z)}, 2); got {xy.shape}")
        if not (np.all(np.isfinite(z)) and np.all(np.isfinite(xy)) and np.all(np.isfinite(rad))):
            raise WoodcamError("Log: pith_z_mm, pith_xy_mm and radii_mm must be finite; got NaN "
                               "or inf")
        if rad.ndim != 2 or rad.shape[0] != len(z) or rad.shape[1] < 4 or np.any(rad <= 0):
            raise WoodcamError(f"Log.radii_mm must be ({len(z)}, a>=4) positive radii; got "
                               f"shape {rad.shape}; give one row of azimuth radii per pith height")
        # the name becomes part of output file names (``woodcam log render``): a plain name,
        # never a path (a log file named "../../x" wrote outside --out)
        if not (isinstance(self.name, str) and re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9 ._+-]{0,99}", self.name)):
            raise WoodcamError(f"Log.name must be a plain name (letters, digits, space . _ + -, at most "
                               f"100, no path); got {self.name!r}")
        object.__setattr__(self, "pith_z_mm", z)
        object.__setattr__(self, "pith_xy_mm", xy)
        object.__setattr__(self, "radii_mm", rad)
        object.__setattr__(self, "knots", knots)

    @property
    def length_mm(self) -> float:
        return float(self.pith_z_mm[-1] - self.pith_z_mm[0])

    @property
    def r_min_mm(self) -> float:
        return float(self.radii_mm.min())

    @property
    def r_max_mm(self) -> float:
        return float(self.radii_mm.max())

    def pith_at(self, z_mm: ArrayLike) -> np.ndarray:
        """Pith ``(x, y)`` at heights ``z_mm (n,)`` -> ``(n, 2)`` mm (clamped at the ends)."""
        z = real_numbers(z_mm, "z_mm")
        return np.stack([np.interp(z, self.pith_z_mm, self.pith_xy_mm[:, 0]),
                         np.interp(z, self.pith_z_mm, self.pith_xy_mm[:, 1])], axis=-1)

    def radius_at(self, z_mm: ArrayLike, azimuth_rad: ArrayLike) -> np.ndarray:
        """Outer radius (mm) at heights ``z_mm (n,)`` and azimuths ``azimuth_rad (n,)``.

        Bilinear in (height, azimuth), periodic in azimuth, clamped in height.
        """
        # None or NaN was cast to a grid index (numpy's RuntimeWarning and another row's radius)
        z = real_numbers(z_mm, "z_mm", finite=True)
        a = self.radii_mm.shape[1]
        fz = np.interp(z, self.pith_z_mm, np.arange(len(self.pith_z_mm), dtype=float))
        iz = np.minimum(fz.astype(int), len(self.pith_z_mm) - 2)
        tz = fz - iz
        fa = np.mod(real_numbers(azimuth_rad, "azimuth_rad", finite=True), 2 * np.pi) * (a / (2 * np.pi))
        ia = np.floor(fa).astype(int) % a
        ta = fa - np.floor(fa)
        ia1 = (ia + 1) % a
        R = self.radii_mm
        r0 = R[iz, ia] * (1 - ta) + R[iz, ia1] * ta
        r1 = R[iz + 1, ia] * (1 - ta) + R[iz + 1, ia1] * ta
        return r0 * (1 - tz) + r1 * tz

    def knot_point(self, index: int, r_mm: ArrayLike) -> np.ndarray:
        """Log-frame points ``(n, 3)`` on knot ``index``'s axis at pith distances ``r_mm (n,)``."""
        k = self.knots[index]
        r = np.atleast_1d(real_numbers(r_mm, "r_mm"))
        z, w = k.axis_at(r)
        p = self.pith_at(z)
        return np.stack([p[:, 0] + r * np.cos(w), p[:, 1] + r * np.sin(w), z], axis=-1)

    def with_knots(self, knots: Sequence[BranchStrand]) -> "LogSkeleton":
        """The same stem with another set of knots (e.g. none, or the first n)."""
        return LogSkeleton(self.pith_z_mm, self.pith_xy_mm, self.radii_mm, tuple(knots), self.name)

    def to_json(self) -> dict:
        return {"format": "woodcam-log", "version": 1, "units": "mm", "name": self.name,
                "azimuth": "column j of radii_mm is at 2*pi*j/columns rad, ccw from +x",
                "pith_z_mm": self.pith_z_mm.tolist(), "pith_xy_mm": self.pith_xy_mm.tolist(),
                "radii_mm": self.radii_mm.tolist(), "knots": [k.to_json() for k in self.knots]}

    @classmethod
    def from_json(cls, d: dict) -> "LogSkeleton":
        if not isinstance(d, dict):
            raise WoodcamError(f"a log file must hold a JSON object; got {type(d).__name__}")
        if d.get("format") != "woodcam-log":
            raise WoodcamError(f"log file format must be 'woodcam-log'; got {d.get('format')!r}; "
                               "write the file with 'woodcam log export' (woodcam.logs.write_log)")
        if d.get("units", "mm") != "mm":  # it was read as mm whatever it said
            raise WoodcamError(f"log file units must be 'mm' (every length in millimetres); got "
                               f"{d.get('units')!r}; convert the file's lengths to mm")
        name = d.get("name", "log")
        try:
            return cls(d["pith_z_mm"], d["pith_xy_mm"], d["radii_mm"],
                       tuple(BranchStrand.from_json(k) for k in d.get("knots", [])),
                       name)
        except KeyError as err:
            raise WoodcamError(f"log file is missing the key {err.args[0]!r}; it needs "
                               "pith_z_mm, pith_xy_mm and radii_mm") from err
        except (TypeError, ValueError, IndexError, AttributeError, OverflowError) as err:
            if isinstance(err, WoodcamError):
                raise
            raise WoodcamError(f"log file has a value of the wrong type or shape ({type(err).__name__}: "
                               f"{err}); numbers and lists of numbers as 'woodcam log export' "
                               "(woodcam.logs.write_log) writes them") from err


def simple_log(length_mm: float = 600.0, radius_mm: float = 100.0, knots: Sequence[BranchStrand] = (), *,
               z_step_mm: float = 10.0, azimuths: int = 36, name: str = "simple") -> LogSkeleton:
    """A straight cylindrical log (pith on the ``z`` axis, constant radius) with ``knots``:
    the analytic test case and a starting point for hand-made logs.

    ``length_mm`` (> 0) long from ``z = 0``, sampled every ``z_step_mm`` along the pith;
    ``radius_mm`` (> 0) at each of ``azimuths`` directions round it (log frame, mm);
    ``knots``: a sequence of :class:`BranchStrand` (none by default); ``name``: the log's name."""
    if not (length_mm > 0 and radius_mm > 0):
        raise WoodcamError(f"length_mm and radius_mm must be > 0; got {length_mm}, {radius_mm}")
    z = np.arange(0.0, length_mm + 0.5 * z_step_mm, z_step_mm)
    return LogSkeleton(z, np.zeros((len(z), 2)), np.full((len(z), azimuths), float(radius_mm)),
               tuple(knots), name)
