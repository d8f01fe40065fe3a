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
"""

from __future__ import annotations

from typing import Any
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np

from .._types import ArrayLike, PathLike
from ..errors import WoodcamError

ToolType = Literal["flat", "ball", "bull", "vbit"]
TOOL_TYPES: tuple[str, ...] = ("flat", "ball", "bull", "vbit")


@dataclass(frozen=True)
class Tool:
    """Base class: a tool of ``diameter_mm`` whose lower surface is :meth:`profile`."""

    diameter_mm: float

    kind = "tool"

    def __post_init__(self):
        if not (self.diameter_mm > 0 and math.isfinite(self.diameter_mm)):
            raise WoodcamError(f"{type(self).__name__}: diameter_mm must be a positive number, "
                               f"got {self.diameter_mm!r}; give the cutting diameter in mm")

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
        r = np.abs(np.asarray(r_mm, float))
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

    def solid(self, top_mm: float, segments: int = 64) -> Any:
        """The tool as a ``manifold3d.Manifold``: tip at the origin, up to ``z = top_mm``."""
        from manifold3d import CrossSection, Manifold

        # r = R sin(theta) samples densely where ball/bull profiles turn vertical; the polygon
        # is inscribed in the convex profile (sagitta < R (1 - cos(pi / 4 / (n - 1))) ~ 0.1 %).
        n = 24
        r = self.radius_mm * np.sin(np.linspace(0.0, 0.5 * np.pi, n))
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
        return f"flat:{self.diameter_mm:g}"

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
        return f"ball:{self.diameter_mm:g}"


@dataclass(frozen=True)
class BullNoseMill(Tool):
    """Bull nose: flat to ``R - rc``, then a torus of corner radius ``rc``."""

    corner_radius_mm: float = 1.0
    kind = "bull"

    def __post_init__(self):
        super().__post_init__()
        if not 0 < self.corner_radius_mm <= self.radius_mm:
            raise WoodcamError(f"BullNoseMill: corner_radius_mm must be in (0, diameter/2 = "
                               f"{self.radius_mm:g}], got {self.corner_radius_mm!r}; use "
                               "ball for rc = R or flat for rc = 0")

    def _h(self, r):
        rc = self.corner_radius_mm
        q = np.maximum(np.asarray(r, float) - (self.radius_mm - rc), 0.0)
        return rc - np.sqrt(np.maximum(rc * rc - q * q, 0.0))

    def _dh(self, r):
        rc = self.corner_radius_mm
        q = np.maximum(r - (self.radius_mm - rc), 0.0)
        return q / np.sqrt(np.maximum(rc * rc - q * q, 1e-30))

    def spec(self):
        return f"bull:{self.diameter_mm:g}:{self.corner_radius_mm:g}"


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
        return f"vbit:{self.angle_deg:g}:{self.diameter_mm:g}"


_SPEC_HELP = "write flat:D, ball:D, bull:D:RC or vbit:ANGLE:D (mm, degrees), e.g. ball:3"


def parse_tool_spec(spec: str) -> Tool:
    """Parse a tool spec such as ``flat:6.35``, ``ball:3``, ``bull:6:1``, ``vbit:60:12``."""
    parts = str(spec).strip().lower().split(":")
    kind = parts[0]
    try:
        nums = [float(p) for p in parts[1:]]
    except ValueError as err:
        raise WoodcamError(f"tool spec {spec!r}: numbers expected after the type; {_SPEC_HELP}"
                           ) from err
    want = {"flat": 1, "ball": 1, "bull": 2, "vbit": 2}
    if kind not in want:
        raise WoodcamError(f"tool spec {spec!r}: type must be one of {TOOL_TYPES}, got "
                           f"{kind!r}; {_SPEC_HELP}")
    if len(nums) != want[kind]:
        raise WoodcamError(f"tool spec {spec!r}: {kind} takes {want[kind]} number(s), got "
                           f"{len(nums)}; {_SPEC_HELP}")
    if kind == "flat":
        return FlatEndMill(nums[0])
    if kind == "ball":
        return BallEndMill(nums[0])
    if kind == "bull":
        return BullNoseMill(nums[0], corner_radius_mm=nums[1])
    return VBit(nums[1], angle_deg=nums[0])


def load_tool_table(path: PathLike) -> dict[int, Tool]:
    """Read a TOML tool table (module docstring) into ``{tool number: Tool}``."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except FileNotFoundError as err:
        raise WoodcamError(f"load_tool_table: path={str(path)!r} does not exist; pass a TOML "
                           "tool table") from err
    except tomllib.TOMLDecodeError as err:
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
        kind = str(entry.get("type", ""))
        d = entry.get("diameter_mm")
        if kind not in TOOL_TYPES or d is None:
            raise WoodcamError(f"load_tool_table: {path}: [tools.{key}] needs type (one of "
                               f"{TOOL_TYPES}) and diameter_mm, got {dict(entry)!r}")
        if kind == "flat":
            out[number] = FlatEndMill(float(d))
        elif kind == "ball":
            out[number] = BallEndMill(float(d))
        elif kind == "bull":
            out[number] = BullNoseMill(float(d), float(entry.get("corner_radius_mm", math.nan)))
        else:
            out[number] = VBit(float(d), float(entry.get("angle_deg", math.nan)))
    return out
