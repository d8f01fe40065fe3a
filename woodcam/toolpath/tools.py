"""Cutting tools as exact radial profiles, tool specs (``ball:3``) and TOML tool tables.

A tool is a solid of revolution about its axis (vertical, 3-axis milling). Its lower surface is
``profile(r_mm) -> height above the tip (mm)`` for ``0 <= r <= radius_mm`` and ``+inf`` beyond;
above the cutting profile the tool is a cylinder of its full radius (the shank/flutes), so the
solid is convex. The tool tip (lowest point) is the controlled point of the G-code.

Every profile is convex and non-decreasing in ``r``; the sweep kernel of
:mod:`woodcam.toolpath.simulate` relies on it (the height of the swept lower envelope along a
straight move is then a convex 1-D minimisation, solved in closed form here).

Specs (all lengths are diameters in mm, angles the included angle in degrees)::

    flat:6.35        flat end mill, 6.35 mm diameter
    ball:3           ball end mill, 3 mm diameter
    bull:6:1         bull nose, 6 mm diameter, 1 mm corner radius
    vbit:60:12       V-bit, 60 deg included angle, 12 mm diameter
    flat:6:flute=22:stickout=30:holder=35
                     reach (optional, mm): flute length, shank diameter (shank=, default
                     the cutter's), tip-to-holder stick-out and holder diameter

Tool table (TOML, read with the standard library's ``tomllib``)::

    [tools.1]
    type = "flat"          # flat | ball | bull | vbit
    diameter_mm = 6.35
    [tools.2]
    type = "vbit"
    diameter_mm = 12
    angle_deg = 60
    [tools.3]
    type = "bull"
    diameter_mm = 6
    corner_radius_mm = 1
    flute_length_mm = 18       # optional reach: warned where the stock is deeper than the
    shank_diameter_mm = 6      # flutes or touches the shank or the holder
    stickout_mm = 30
    holder_diameter_mm = 35
"""

from __future__ import annotations

from typing import Any
import math
import numbers
import tomllib
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import Literal

import numpy as np

from .._checks import check_path, real_numbers
from .._types import ArrayLike, PathLike
from ..errors import WoodcamError, WoodcamWarning
from ..units import message_unit, message_units, say_length

ToolType = Literal["flat", "ball", "bull", "vbit", "snub", "chamfer", "taperball"]
TOOL_TYPES: tuple[str, ...] = ("flat", "ball", "bull", "vbit", "snub", "chamfer", "taperball")


#: Largest cutter diameter accepted (mm): a 1 m cutter is a typo, and the stock simulation's
#: footprint of one tool grows with its square.
MAX_TOOL_DIAMETER_MM = 1000.0


#: The reach fields of a tool (keyword-only, all optional, mm) and their spec/TOML names.
REACH_FIELDS = {"flute": "flute_length_mm", "shank": "shank_diameter_mm",
                "stickout": "stickout_mm", "holder": "holder_diameter_mm"}

#: A length field as a tool spec (``--tool``) names it, for messages in other units than mm.
_SPEC_WORDS = {"diameter_mm": "the diameter", "corner_radius_mm": "the corner radius",
               "tip_diameter_mm": "the tip diameter",
               **{f: f"{k}=" for k, f in REACH_FIELDS.items()}}


def _field(name: str) -> str:
    """A length field of a tool in a message: its keyword (``diameter_mm``) where messages speak
    mm (a library caller, a tool table, ``--units mm``), else as a ``--tool`` spec has it (``the
    diameter``, ``flute=``): ``diameter_mm`` beside a length in inches contradicted it."""
    return name if message_unit() == "mm" else _SPEC_WORDS.get(name, name)


def _got(v) -> str:
    """A value received for a length field, in the message units (:func:`say_length`)."""
    if isinstance(v, bool) or not isinstance(v, numbers.Real):
        return repr(v)
    return say_length(float(v), "g")


def _unit_word() -> str:
    return "mm" if message_unit() == "mm" else "inches"


@dataclass(frozen=True)
class Tool:
    """Base class: a tool of ``diameter_mm`` whose lower surface is :meth:`profile`.

    Reach (optional, keyword-only, mm): ``flute_length_mm`` how high above the tip the tool
    cuts; above it the tool is a non-cutting shank of ``shank_diameter_mm`` (default: the
    cutting diameter) up to ``stickout_mm`` (tip to the holder's face), where a holder (collet
    nut, chuck) of ``holder_diameter_mm`` begins. :func:`woodcam.toolpath.simulate` warns where
    the stock reaches above the flutes or into the shank or holder (:meth:`reach_parts`).
    """

    diameter_mm: float
    flute_length_mm: float | None = field(default=None, kw_only=True)
    shank_diameter_mm: float | None = field(default=None, kw_only=True)
    stickout_mm: float | None = field(default=None, kw_only=True)
    holder_diameter_mm: float | None = field(default=None, kw_only=True)

    kind = "tool"

    def __post_init__(self):
        if type(self) is Tool:  # the base has no profile: Tool(3) was accepted, then simulate's NotImplementedError
            raise WoodcamError("Tool is the base class of the cutters and has no profile; got Tool(...); "
                               "make one with parse_tool_spec('flat:6') or a subclass such as "
                               "woodcam.toolpath.FlatEndMill(6)")
        for f in fields(self):  # the subclasses' range checks compare: "60" was a bare TypeError
            v = getattr(self, f.name)
            if f.type == "float" and (isinstance(v, bool) or not isinstance(v, numbers.Real)):
                raise WoodcamError(f"{type(self).__name__}: {_field(f.name)} must be a number; got {v!r}; "
                                   f"give it in {_unit_word()} (angles in degrees)")
        d = self.diameter_mm
        if (isinstance(d, bool) or not isinstance(d, (int, float, np.number))
                or not (0 < d <= MAX_TOOL_DIAMETER_MM)):
            raise WoodcamError(f"{type(self).__name__}: {_field('diameter_mm')} must be a positive number in "
                               f"{say_length(MAX_TOOL_DIAMETER_MM, 'g', form='(0, {}]')}, got {_got(d)}; give "
                               f"the cutting diameter in {_unit_word()}")
        for name in REACH_FIELDS.values():
            v = getattr(self, name)
            if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float, np.number))
                                  or not 0 < v <= 10 * MAX_TOOL_DIAMETER_MM):
                raise WoodcamError(f"{type(self).__name__}: {_field(name)} must be "
                                   f"{'None or ' if _field(name) == name else ''}a positive length in "
                                   f"{say_length(10 * MAX_TOOL_DIAMETER_MM, 'g', form='(0, {}]')}, got {_got(v)}")
        fl, so = self.flute_length_mm, self.stickout_mm
        if fl is not None and so is not None and so < fl:
            raise WoodcamError(f"{type(self).__name__}: {_field('stickout_mm').rstrip('=')}={_got(so)} (tip "
                               f"to holder) is shorter than {_field('flute_length_mm').rstrip('=')}={_got(fl)}; "
                               "the holder would cover the flutes")
        if (self.holder_diameter_mm is None) != (so is None):
            raise WoodcamError(f"{type(self).__name__}: {_field('holder_diameter_mm')} and "
                               f"{_field('stickout_mm')} go together (the holder's size and where it "
                               f"starts above the tip); got {_got(self.holder_diameter_mm)} and {_got(so)}")

    def with_reach(self, **reach) -> "Tool":
        """This tool with reach fields replaced, e.g. ``with_reach(flute_length_mm=22)``."""
        return replace(self, **reach)

    def reach_parts(self) -> list[tuple[str, float, float]]:
        """The non-cutting parts as ``(name, radius_mm, bottom above the tip mm)``: the shank
        above the flutes (when ``flute_length_mm`` is known) and the holder (when
        ``stickout_mm``/``holder_diameter_mm`` are); empty when the tool carries no reach."""
        parts = []
        if self.flute_length_mm is not None:
            # a neck thinner than the cutter passes where the flutes cut: its own radius
            shank = self.shank_diameter_mm or self.diameter_mm
            parts.append(("shank", 0.5 * float(shank), float(self.flute_length_mm)))
        if self.stickout_mm is not None and self.holder_diameter_mm is not None:
            parts.append(("holder", 0.5 * float(self.holder_diameter_mm),
                          float(self.stickout_mm)))
        return parts

    def _reach_spec(self) -> str:
        return "".join(f":{key}={getattr(self, name):g}" for key, name in REACH_FIELDS.items()
                       if getattr(self, name) is not None)

    @property
    def radius_mm(self) -> float:
        return 0.5 * self.diameter_mm

    @property
    def profile_height_mm(self) -> float:
        """Height (mm) of the curved/conical part of the profile above the tip."""
        return float(self.profile(np.array([self.radius_mm]))[0])

    def profile(self, r_mm: ArrayLike) -> np.ndarray:
        """Height above the tip (mm) of the tool's lower surface at radius ``r_mm`` (any shape).

        ``+inf`` outside the tool (``r > radius_mm``).
        """
        r = np.abs(real_numbers(r_mm, "r_mm"))  # None was NaN: +inf, 'outside the tool', without a word
        out = self._h(np.minimum(r, self.radius_mm))
        return np.where(r <= self.radius_mm * (1 + 1e-12), out, np.inf)

    # -- sweep kernel ---------------------------------------------------------------------
    def _h(self, r):
        raise NotImplementedError

    def _dh(self, r):
        raise NotImplementedError

    def _sweep(self, along, d2, s, L, z0):
        """Lower envelope (mm) of the tool swept along a straight move, ``+inf`` where uncovered.

        ``along, d2 : (n, wy, wx)``: a cell's coordinate along the move's XY direction from its
        start and its squared distance from the move's XY line; ``s, L, z0 : (n, 1, 1)``: the
        slope dz/dl, XY length and start height. The envelope is
        ``min over t in [0, L], |t - along| <= sqrt(R^2 - d2) of z0 + s t + h(rho)``,
        ``rho^2 = d2 + (t - along)^2``, convex in ``t``; subclasses solve it in closed form.
        Generic version: bisection on the sign of the derivative.
        """
        R = self.radius_mm
        re = np.sqrt(np.maximum(R * R - d2, 0.0))
        lo = np.maximum(along - re, 0.0)
        hi = np.minimum(along + re, L)
        ok = (d2 <= R * R) & (lo <= hi)
        hi = np.maximum(hi, lo)
        d2c = np.maximum(d2, 0.0)
        if np.any(s):
            a, b = lo, hi
            # 30 halvings of an interval <= L + D: |t - t*| < 1e-9 (L + D), far below a cell.
            for _ in range(30):
                m = 0.5 * (a + b)
                w = m - along
                rho = np.sqrt(d2c + w * w)
                der = s + self._dh(np.minimum(rho, R)) * np.where(rho > 0, w / np.maximum(rho, 1e-30), 0.0)
                right = der > 0
                b = np.where(right, m, b)
                a = np.where(right, a, m)
            t = 0.5 * (a + b)
        else:  # horizontal move: minimum at the foot of the perpendicular (even in w)
            t = np.clip(along, lo, hi)
        w = t - along
        rho = np.sqrt(d2c + w * w)
        env = z0 + s * t + self._h(np.minimum(rho, R))
        return np.where(ok, env, np.inf)

    def spec(self) -> str:
        raise NotImplementedError

    def _kinks(self) -> list[float]:
        """Radii where the profile's slope jumps (kept as vertices of :meth:`solid`)."""
        return []

    def solid(self, top_mm: float, segments: int = 64) -> Any:
        """The tool as a ``manifold3d.Manifold``: tip at the origin, up to ``z = top_mm``."""
        from manifold3d import CrossSection, Manifold

        # r = R sin(theta) samples densely where ball/bull profiles turn vertical; the polygon
        # is inscribed in the convex profile (sagitta < R (1 - cos(pi / 4 / (n - 1))) ~ 0.1 %).
        n = 24
        r = self.radius_mm * np.sin(np.linspace(0.0, 0.5 * np.pi, n))
        r = np.unique(np.concatenate([r, self._kinks()]))  # a chord across a kink cuts it off
        h = self._h(r)
        top = max(float(top_mm), float(h[-1]) + 1e-3)
        poly = [(0.0, 0.0)] + [(float(a), float(b)) for a, b in zip(r[1:], h[1:])]
        poly += [(self.radius_mm, top), (0.0, top)]
        return Manifold.revolve(CrossSection([poly]), segments)


@dataclass(frozen=True)
class FlatEndMill(Tool):
    """Flat end mill: ``profile(r) = 0`` for ``r <= R``."""

    kind = "flat"

    def _h(self, r):
        return np.zeros_like(np.asarray(r, float))

    def _dh(self, r):
        return np.zeros_like(r)

    def _sweep(self, along, d2, s, L, z0):
        # z0 + s t on the chord |t - along| <= sqrt(R^2 - d2), t in [0, L]: the lowest end.
        R = self.radius_mm
        re = np.sqrt(np.maximum(R * R - d2, 0.0))
        lo = np.maximum(along - re, 0.0)
        hi = np.minimum(along + re, L)
        t = np.where(s > 0, lo, hi)
        return np.where((d2 <= R * R) & (lo <= hi), z0 + s * t, np.inf)

    def spec(self):
        return f"flat:{self.diameter_mm:g}" + self._reach_spec()

    def solid(self, top_mm, segments=64):
        from manifold3d import Manifold

        return Manifold.cylinder(max(float(top_mm), 1e-3), self.radius_mm, self.radius_mm,
                                 segments)


@dataclass(frozen=True)
class BallEndMill(Tool):
    """Ball end mill: ``profile(r) = R - sqrt(R^2 - r^2)``."""

    kind = "ball"

    def _h(self, r):
        R = self.radius_mm
        return R - np.sqrt(np.maximum(R * R - np.asarray(r, float) ** 2, 0.0))

    def _dh(self, r):
        R = self.radius_mm
        return r / np.sqrt(np.maximum(R * R - r * r, 1e-30))

    def _sweep(self, along, d2, s, L, z0):
        # Sphere centre on the line: tangent at w = t - along = -s Re / sqrt(1 + s^2),
        # Re^2 = R^2 - d2; then clip t to the move. Uncovered where Re^2 - w^2 < 0.
        R = self.radius_mm
        re2 = R * R - d2
        re = np.sqrt(np.maximum(re2, 0.0))
        t = np.clip(along - (s / np.sqrt(1.0 + s * s)) * re, 0.0, L)
        w = t - along
        q = re2 - w * w
        env = (z0 + R) + s * t - np.sqrt(np.maximum(q, 0.0))
        return np.where(q >= 0, env, np.inf)

    def spec(self):
        return f"ball:{self.diameter_mm:g}" + self._reach_spec()


@dataclass(frozen=True)
class BullNoseMill(Tool):
    """Bull nose: flat to ``R - rc``, then a torus of corner radius ``rc``."""

    corner_radius_mm: float = 1.0
    kind = "bull"

    def __post_init__(self):
        super().__post_init__()
        if not 0 < self.corner_radius_mm <= self.radius_mm:
            raise WoodcamError(f"BullNoseMill: {_field('corner_radius_mm')} must be in "
                               f"{say_length(self.radius_mm, 'g', form='(0, diameter/2 = {}]')}, got "
                               f"{_got(self.corner_radius_mm)}; use ball for rc = R or flat for rc = 0")

    def _h(self, r):
        rc = self.corner_radius_mm
        q = np.maximum(np.asarray(r, float) - (self.radius_mm - rc), 0.0)
        return rc - np.sqrt(np.maximum(rc * rc - q * q, 0.0))

    def _dh(self, r):
        rc = self.corner_radius_mm
        q = np.maximum(r - (self.radius_mm - rc), 0.0)
        return q / np.sqrt(np.maximum(rc * rc - q * q, 1e-30))

    def spec(self):
        return f"bull:{self.diameter_mm:g}:{self.corner_radius_mm:g}" + self._reach_spec()


@dataclass(frozen=True)
class VBit(Tool):
    """V-bit of included angle ``angle_deg``: ``profile(r) = r / tan(angle / 2)``."""

    angle_deg: float = 60.0
    kind = "vbit"

    def __post_init__(self):
        super().__post_init__()
        if not 0 < self.angle_deg < 180:
            raise WoodcamError(f"VBit: angle_deg (included angle) must be in (0, 180), got "
                               f"{self.angle_deg!r}; e.g. 60 or 90")

    @property
    def _k(self):
        return 1.0 / math.tan(math.radians(self.angle_deg) / 2)

    def _h(self, r):
        return self._k * np.asarray(r, float)

    def _dh(self, r):
        return np.full_like(r, self._k)

    def _sweep(self, along, d2, s, L, z0):
        # s + k w / rho = 0 -> w = -s d / sqrt(k^2 - s^2) when the move is shallower than the
        # cone (|s| < k); otherwise the minimum sits at the end of the interval.
        k, R = self._k, self.radius_mm
        d2c = np.maximum(d2, 0.0)
        re = np.sqrt(np.maximum(R * R - d2, 0.0))
        lo = np.maximum(along - re, 0.0)
        hi = np.minimum(along + re, L)
        ok = (d2 <= R * R) & (lo <= hi)
        w = -s * np.sqrt(d2c) / np.sqrt(np.maximum(k * k - s * s, 1e-30))
        w = np.where(np.abs(s) >= k, np.where(s > 0, -np.inf, np.inf), w)
        t = np.clip(along + w, lo, np.maximum(hi, lo))
        w = t - along
        env = z0 + s * t + k * np.sqrt(d2c + w * w)
        return np.where(ok, env, np.inf)

    def spec(self):
        return f"vbit:{self.angle_deg:g}:{self.diameter_mm:g}" + self._reach_spec()


@dataclass(frozen=True)
class SnubNoseVBit(Tool):
    """Engraving cone with a flat tip (snub nose): flat to ``tip_diameter_mm / 2``, then a
    cone of included angle ``angle_deg``: ``profile(r) = max(r - rt, 0) / tan(angle / 2)``."""

    angle_deg: float = 60.0
    tip_diameter_mm: float = 0.5
    kind = "snub"

    def __post_init__(self):
        super().__post_init__()
        if not 0 < self.angle_deg < 180:
            raise WoodcamError(f"{type(self).__name__}: angle_deg (included angle) must be in "
                               f"(0, 180), got {self.angle_deg!r}; e.g. 60 or 90")
        if not 0 <= self.tip_diameter_mm < self.diameter_mm:
            raise WoodcamError(f"{type(self).__name__}: {_field('tip_diameter_mm')} must be in "
                               f"{say_length(self.diameter_mm, 'g', form='[0, diameter = {})')}, got "
                               f"{_got(self.tip_diameter_mm)}")

    @property
    def _k(self):
        return 1.0 / math.tan(math.radians(self.angle_deg) / 2)

    def _h(self, r):
        return self._k * np.maximum(np.asarray(r, float) - 0.5 * self.tip_diameter_mm, 0.0)

    def _dh(self, r):
        return np.where(np.asarray(r) > 0.5 * self.tip_diameter_mm, self._k, 0.0)

    def _kinks(self):
        return [0.5 * self.tip_diameter_mm]

    def spec(self):
        return f"{self.kind}:{self.angle_deg:g}:{self.diameter_mm:g}:{self.tip_diameter_mm:g}" + self._reach_spec()


@dataclass(frozen=True)
class ChamferMill(SnubNoseVBit):
    """Chamfer mill: the same profile as :class:`SnubNoseVBit` (a cone over a flat tip)."""

    kind = "chamfer"


@dataclass(frozen=True)
class TaperedBallMill(Tool):
    """Tapered ball nose: a ball of ``tip_diameter_mm`` joined tangentially to a cone whose
    flanks lean ``taper_deg`` from the axis (per side), up to ``diameter_mm``."""

    tip_diameter_mm: float = 1.0
    taper_deg: float = 5.0
    kind = "taperball"

    def __post_init__(self):
        super().__post_init__()
        if not 0 < self.tip_diameter_mm <= self.diameter_mm:
            raise WoodcamError(f"TaperedBallMill: {_field('tip_diameter_mm')} must be in "
                               f"{say_length(self.diameter_mm, 'g', form='(0, diameter = {}]')}, got "
                               f"{_got(self.tip_diameter_mm)}")
        if not 0 < self.taper_deg < 90:
            raise WoodcamError(f"TaperedBallMill: taper_deg (per side) must be in (0, 90), got "
                               f"{self.taper_deg!r}; e.g. 3.6")

    def _parts(self):
        rb = 0.5 * self.tip_diameter_mm
        a = math.radians(self.taper_deg)
        rt = rb * math.cos(a)  # where the sphere's slope equals the flank's, 1 / tan(a)
        return rb, rt, rb - math.sqrt(rb * rb - rt * rt), 1.0 / math.tan(a)

    def _h(self, r):
        rb, rt, ht, k = self._parts()
        r = np.asarray(r, float)
        ball = rb - np.sqrt(np.maximum(rb * rb - np.minimum(r, rt) ** 2, 0.0))
        return np.where(r <= rt, ball, ht + k * (r - rt))

    def _dh(self, r):
        rb, rt, _, k = self._parts()
        r = np.asarray(r, float)
        q = np.minimum(r, rt)
        return np.where(r <= rt, q / np.sqrt(np.maximum(rb * rb - q * q, 1e-30)), k)

    def _kinks(self):
        return [self._parts()[1]]

    def spec(self):
        return f"taperball:{self.diameter_mm:g}:{self.tip_diameter_mm:g}:{self.taper_deg:g}" + self._reach_spec()


def _spec_help() -> str:
    # the lengths' unit is the message units': the CLI reads a --tool spec in --units
    # (it said "(mm, degrees)" under --units inch)
    return ("write flat:D, ball:D, bull:D:RC, vbit:ANGLE:D, snub:ANGLE:D:TIP, "
            f"chamfer:ANGLE:D:TIP or taperball:D:TIP:TAPER ({message_unit()}, degrees), e.g. ball:3; "
            "reach as :flute=L:shank=D:stickout=L:holder=D")


def parse_tool_spec(spec: str) -> Tool:
    """Parse a tool spec such as ``flat:6.35``, ``ball:3``, ``bull:6:1``, ``vbit:60:12``: lengths
    in mm (diameters; a bull nose's corner radius), a V-bit's included angle in degrees
    (module docstring)."""
    parts = str(spec).strip().lower().split(":")
    kind = parts[0]
    reach: dict[str, float] = {}
    for item in [p for p in parts[1:] if "=" in p]:
        key, _, val = item.partition("=")
        if key not in REACH_FIELDS:
            raise WoodcamError(f"tool spec {spec!r}: {key!r} is not one of {list(REACH_FIELDS)} "
                               f"(e.g. flat:6:flute=22:stickout=30:holder=35); {_spec_help()}")
        try:
            reach[REACH_FIELDS[key]] = float(val)
        except ValueError as err:
            raise WoodcamError(f"tool spec {spec!r}: {key}= needs a number of {message_unit()}, got {val!r}"
                               ) from err
    parts = [p for p in parts if "=" not in p]
    try:
        nums = [float(p) for p in parts[1:]]
    except ValueError as err:
        raise WoodcamError(f"tool spec {spec!r}: numbers expected after the type; {_spec_help()}"
                           ) from err
    want = {"flat": 1, "ball": 1, "bull": 2, "vbit": 2, "snub": 3, "chamfer": 3,
            "taperball": 3}
    if kind not in want:
        raise WoodcamError(f"tool spec {spec!r}: type must be one of {TOOL_TYPES}, got "
                           f"{kind!r}; {_spec_help()}")
    if len(nums) != want[kind]:
        raise WoodcamError(f"tool spec {spec!r}: {kind} takes {want[kind]} number(s), got "
                           f"{len(nums)}; {_spec_help()}")
    if kind == "flat":
        return FlatEndMill(nums[0], **reach)
    if kind == "ball":
        return BallEndMill(nums[0], **reach)
    if kind == "bull":
        return BullNoseMill(nums[0], corner_radius_mm=nums[1], **reach)
    if kind in ("snub", "chamfer"):
        cls = SnubNoseVBit if kind == "snub" else ChamferMill
        return cls(nums[1], angle_deg=nums[0], tip_diameter_mm=nums[2], **reach)
    if kind == "taperball":
        return TaperedBallMill(nums[0], tip_diameter_mm=nums[1], taper_deg=nums[2], **reach)
    return VBit(nums[1], angle_deg=nums[0], **reach)


def load_tool_table(path: PathLike) -> dict[int, Tool]:
    """Read a TOML tool table (module docstring; lengths in mm), or a CAMotics JSON tool table
    (:func:`load_camotics_tools`, converted from its units), into ``{tool number: Tool}``.
    ``path``: a ``.toml`` file, or a ``.json`` / ``.camotics`` file read as CAMotics' table."""
    path = check_path(path, "load_tool_table: path", fix="a TOML or CAMotics JSON tool table")
    if path.suffix.lower() in (".json", ".camotics"):
        return load_camotics_tools(path)
    try:
        data = tomllib.loads(path.read_bytes().decode("utf-8"))
    except FileNotFoundError as err:
        raise WoodcamError(f"load_tool_table: path={str(path)!r} does not exist; pass a TOML "
                           "tool table") from err
    except OSError as err:
        raise WoodcamError(f"load_tool_table: cannot read {str(path)!r} ({err.strerror}); pass "
                           "a TOML tool table file") from err
    except (tomllib.TOMLDecodeError, UnicodeDecodeError, RecursionError) as err:
        raise WoodcamError(f"load_tool_table: {path} is not valid TOML ({err}); fix the file"
                           ) from err
    table = data.get("tools")
    if not isinstance(table, dict) or not table:
        raise WoodcamError(f"load_tool_table: {path} has no [tools.N] tables; add e.g. "
                           "[tools.1] type = \"flat\" diameter_mm = 6.35")
    out: dict[int, Tool] = {}
    for key, entry in table.items():
        try:
            number = int(key)
        except ValueError as err:
            raise WoodcamError(f"load_tool_table: {path}: tool key {key!r} must be the tool "
                               "number, e.g. [tools.1]") from err
        if not 0 <= number <= 99999:
            raise WoodcamError(f"load_tool_table: {path}: tool number {key!r} must be in "
                               "[0, 99999]")
        if not isinstance(entry, dict):
            raise WoodcamError(f"load_tool_table: {path}: tools.{key} must be a table "
                               f"([tools.{key}] with type and diameter_mm), got {entry!r}")
        kind = entry.get("type")
        d = entry.get("diameter_mm")
        if kind not in TOOL_TYPES or d is None:
            raise WoodcamError(f"load_tool_table: {path}: [tools.{key}] needs type (one of "
                               f"{TOOL_TYPES}) and diameter_mm, got {dict(entry)!r}")
        # every key must mean something for this type: a typo (flute_length for flute_length_mm)
        # was ignored, which silently turned off the reach checks it was written for
        known = {"type", "diameter_mm", *REACH_FIELDS.values(), *_TYPE_KEYS.get(kind, ()), *_NOTE_KEYS}
        unknown = sorted(set(entry) - known)
        if unknown:
            raise WoodcamError(f"load_tool_table: {path}: [tools.{key}] (type {kind!r}) has unknown "
                               f"key(s) {unknown}; known: {sorted(known)}")
        missing = [k for k in _TYPE_KEYS.get(kind, ()) if k not in entry]
        if missing:  # read as NaN, the tool then said "angle_deg ... got nan" of a key never written
            raise WoodcamError(f"load_tool_table: {path}: [tools.{key}] (type {kind!r}) needs {missing}; "
                               f"e.g. angle_deg = 60 for a vbit")
        nums = {k: _number(entry[k], path, key, k) for k in ("diameter_mm", *REACH_FIELDS.values(),
                                                                 *_TYPE_KEYS.get(kind, ())) if k in entry}
        try:
            # the table's keys and numbers are mm whatever --units says: its errors too
            with message_units("mm"):
                out[number] = _table_tool(kind, nums)
        except WoodcamError as err:  # which entry of which table: the tool's words alone did not say
            raise WoodcamError(f"load_tool_table: {path}: [tools.{key}]: {err}") from None
    return out


def _table_tool(kind: str, nums: dict) -> "Tool":
    """The tool of one tool-table entry: its ``type`` and numbers by key (mm, degrees)."""
    d = nums["diameter_mm"]
    reach = {name: nums[name] for name in REACH_FIELDS.values() if name in nums}
    if kind == "flat":
        tool: Tool = FlatEndMill(d)
    elif kind == "ball":
        tool = BallEndMill(d)
    elif kind == "bull":
        tool = BullNoseMill(d, nums["corner_radius_mm"])
    elif kind in ("snub", "chamfer"):
        cls = SnubNoseVBit if kind == "snub" else ChamferMill
        tool = cls(d, angle_deg=nums["angle_deg"], tip_diameter_mm=nums["tip_diameter_mm"])
    elif kind == "taperball":
        tool = TaperedBallMill(d, tip_diameter_mm=nums["tip_diameter_mm"], taper_deg=nums["taper_deg"])
    else:
        tool = VBit(d, nums["angle_deg"])
    return tool.with_reach(**reach) if reach else tool


#: Keys a tool table may carry for people (read by no one).
_NOTE_KEYS = ("name", "description", "comment", "note", "vendor")
#: The keys each tool type reads beyond type, diameter_mm and the reach (load_tool_table).
_TYPE_KEYS = {"bull": ("corner_radius_mm",), "snub": ("angle_deg", "tip_diameter_mm"),
              "chamfer": ("angle_deg", "tip_diameter_mm"), "taperball": ("tip_diameter_mm", "taper_deg"),
              "vbit": ("angle_deg",)}


def _number(value, path, key, name) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise WoodcamError(f"load_tool_table: {path}: [tools.{key}] {name} must be a number, "
                           f"got {value!r}")
    return float(value)


#: CAMotics tool shapes and the woodcam tool they are (its ToolShape names, read in any case as
#: its enumeration parse does, with its aliases cylinder and cone).
_CAMOTICS_SHAPES = ("cylindrical", "ballnose", "conical", "snubnose")
_CAMOTICS_ALIASES = {"cylinder": "cylindrical", "cone": "conical"}
#: CAMotics' units (its Units names and aliases mm and inch, any case) -> mm per table unit.
_CAMOTICS_UNITS = {"metric": 1.0, "mm": 1.0, "imperial": 25.4, "inch": 25.4}
#: mm: the length CAMotics gives a tool table entry without "length" (Tool's constructor,
#: setLength(10) for the metric tool ToolTable::read builds before Tool::read reads the entry;
#: an imperial entry keeps it: 10 mm, not 10 in or 1 in). A cylindrical or ball-nose tool's
#: cutting length, a cone's height (with the diameter, its angle).
CAMOTICS_DEFAULT_LENGTH_MM = 10.0


def load_camotics_tools(path: PathLike) -> dict[int, Tool]:
    """Read a CAMotics tool table (the ``"tools"`` object of a ``.camotics`` project, or a JSON
    file holding it): ``{"1": {"units": "metric"|"imperial", "shape": "cylindrical"|"ballnose"|
    "conical"|"snubnose", "diameter": D, "length": L, "snub_diameter": d}}`` (CAMotics' own
    Tool::read: units and shapes in any case, units ``mm``/``inch`` and shapes ``cylinder``/
    ``cone`` as aliases; no units: metric). CAMotics defines a cone by its diameter and the
    length of its conical part: included angle ``2 atan((D - d) / 2 / L)``. ``length`` is the
    cutter's length from its tip, all CAMotics' tool body: woodcam's ``flute_length_mm`` (a cut
    deeper is warned: the shank rubs), for a cone too; without it the tool takes CAMotics' own
    default, :data:`CAMOTICS_DEFAULT_LENGTH_MM` (10 mm, in mm whatever the entry's units: its
    ToolTable::read builds a metric Tool, whose constructor sets it, before Tool::read reads the
    entry's units), a cone's angle from it too, said in one
    :class:`~woodcam.errors.WoodcamWarning` naming those tools and the length. An entry's
    ``"number"`` is its tool number, as in CAMotics (Tool::read, then ToolTable::set files it
    under that number), the key without one; two entries on one number are refused (CAMotics
    keeps the later one without a word). Lengths in the table's units; woodcam's tools in mm.
    ``path``: the ``.camotics`` project or ``.json`` file."""
    import json

    path = Path(path)
    try:
        data = json.loads(path.read_text())
    except FileNotFoundError as err:
        raise WoodcamError(f"load_camotics_tools: path={str(path)!r} does not exist") from err
    except json.JSONDecodeError as err:
        raise WoodcamError(f"load_camotics_tools: {path} is not valid JSON ({err})") from err
    table = data.get("tools", data) if isinstance(data, dict) else None
    if not isinstance(table, dict) or not table:
        raise WoodcamError(f"load_camotics_tools: {path} has no tools; expected "
                           '{"tools": {"1": {"shape": "cylindrical", "diameter": 6.35, ...}}}')
    out: dict[int, Tool] = {}
    filed: dict[int, str] = {}  # tool number -> the key of the entry that gave it
    no_length: list[str] = []  # the tools without a length, said once below
    for key, e in table.items():
        if not isinstance(e, dict) or not str(key).isdigit():
            raise WoodcamError(f"load_camotics_tools: {path}: tool {key!r} must be a number "
                               "with an object of shape/diameter/length")
        number = _camotics_number(e, key, path)
        if number in filed:
            raise WoodcamError(
                f"load_camotics_tools: {path}: tool {key} and tool {filed[number]} are both tool "
                f"{number} (an entry's \"number\" names its tool, the key without one; CAMotics "
                f"keeps the later one without a word); give each entry its own number")
        filed[number] = str(key)
        units = e.get("units", "metric")
        scale = _CAMOTICS_UNITS.get(units.lower()) if isinstance(units, str) else None
        if scale is None:  # 'Imperial' or 'inch', which CAMotics reads, were refused
            raise WoodcamError(f"load_camotics_tools: {path}: tool {key}: units must be "
                               f"metric or imperial (or mm, inch), got {units!r}")
        shape = str(e.get("shape", "")).lower()
        shape = _CAMOTICS_ALIASES.get(shape, shape)
        if shape in ("spheroid", "sphere"):
            raise WoodcamError(f"load_camotics_tools: {path}: tool {key}: shape {shape!r} (CAMotics' "
                               "lollipop / undercut cutter) has no woodcam tool; a 3-axis program "
                               "cuts with its lower half: give it as a ballnose of its diameter")
        if shape not in _CAMOTICS_SHAPES:
            raise WoodcamError(f"load_camotics_tools: {path}: tool {key}: shape {shape!r} is "
                               f"not one of {_CAMOTICS_SHAPES}")
        num = lambda k, default=math.nan: _number(e.get(k, default), path, key, k) * scale  # noqa: E731
        d = num("diameter")
        # CAMotics' "length" of a cylindrical or ball-nose tool is its cutting length; without
        # one, CAMotics cuts with its default (in mm, not scaled by the entry's units), so woodcam
        # simulates the tool CAMotics does rather than one of unlimited reach or none at all
        if "length" in e:
            flute = num("length")
        else:
            flute = CAMOTICS_DEFAULT_LENGTH_MM
            no_length.append(f"{number} ({shape})" if str(number) == str(key) else
                             f"{number} ({shape}, key {key!r})")
        reach = {"flute_length_mm": flute} if flute > 0 else {}
        if shape == "cylindrical":
            tool: Tool = FlatEndMill(d, **reach)
        elif shape == "ballnose":
            tool = BallEndMill(d, **reach)
        else:
            tip = num("snub_diameter", 0.0) if shape == "snubnose" else 0.0
            length = flute  # the cone's height: the entry's, else CAMotics' default (warned)
            if not length > 0:
                raise WoodcamError(f"load_camotics_tools: {path}: tool {key}: a {shape} tool "
                                   f"needs length > 0 (the cone's height), got {length!r}")
            angle = 2 * math.degrees(math.atan((d - tip) / 2 / length))
            # the cone is all of CAMotics' tool: deeper, a V-bit's shank rubs the wall (a
            # 60-degree V-bit cutting past its cone was simulated as if it cut there, no word)
            tool = SnubNoseVBit(d, angle_deg=angle, tip_diameter_mm=tip, **reach) if tip > 0 else \
                VBit(d, angle_deg=angle, **reach)
        out[number] = tool
    if no_length:
        import warnings

        warnings.warn(
            f"load_camotics_tools: {path}: tool{'s' if len(no_length) > 1 else ''} "
            f"{', '.join(no_length)} give{'' if len(no_length) > 1 else 's'} no \"length\": "
            f"{'each' if len(no_length) > 1 else 'it'} is taken as {CAMOTICS_DEFAULT_LENGTH_MM:g} mm "
            "long, as CAMotics takes it (its default, in mm whatever the entry's units; a cone's "
            "angle follows from it), the length past which a cut is warned (the shank rubbing); "
            "add \"length\": L, the cutting length (a cone's height) in the table's units",
            WoodcamWarning, stacklevel=2)
    return out


def _camotics_number(entry: dict, key: str, path: Path) -> int:
    """The tool number of the CAMotics tool table entry ``entry`` under ``key``: its
    ``"number"`` where it has one (CAMotics' Tool::read reads it over the key), else the key."""
    if "number" not in entry:
        return int(key)
    value = entry["number"]
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= 99999:
        raise WoodcamError(f"load_camotics_tools: {path}: tool {key}: \"number\" must be a tool "
                           f"number, a whole number 0..99999, got {value!r}; give the tool's "
                           "number or leave it out (the key is then the number)")
    return value
