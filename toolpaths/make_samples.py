"""Write the sample G-code programs of this folder (run: python toolpaths/make_samples.py).

Each program is what a CAM package would post for a 3-axis router (mm, G90, work zero on the
stock's top-front-left corner). The tools are in ``tools.toml``; the stocks are listed in
``README.md``. Kept as a script so the programs can be regenerated and read; the simulation
never imports it.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
SAFE = 5.0


def _f(v: float) -> str:
    s = f"{v:.3f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def relief_height(x, y):
    """Relief surface (mm, <= 0) of the raster sample on a 100 x 100 stock: a bowl with a rim
    and a ripple, deepest -18 mm."""
    r = np.hypot(x - 50.0, y - 50.0)
    bowl = -18.0 * np.clip(1 - (r / 38.0) ** 2, 0, None)
    ripple = -1.2 * np.cos(r / 3.0) * np.exp(-((r - 20) / 10) ** 2)
    return np.minimum(np.minimum(bowl + ripple, -0.5), 0.0) - 0.0 * x


def relief_raster(n_lines: int = 200, n_seg: int = 100, size=100.0, ball_d=6.0) -> str:
    """Ball-end 3D raster (finishing) of :func:`relief_height`: ``n_lines + 1`` zig-zag passes
    along X of ``n_seg`` moves each (20,100 cutting moves by default)."""
    out = ["%", "(relief bowl: ball-end 3D raster finish)", "(stock 100 x 100 x 30 mm, T2 = 6 mm ball)",
           "G21 G90 G17 G94", "T2 M6", "S18000 M3", f"G0 Z{_f(SAFE)}"]
    r = ball_d / 2
    ys = np.linspace(0, size, n_lines + 1)
    xs = np.linspace(-r, size + r, n_seg + 1)
    for k, y in enumerate(ys):
        xx = xs if k % 2 == 0 else xs[::-1]
        zz = relief_height(np.clip(xx, 0, size), np.full_like(xx, y))
        if k == 0:
            out += [f"G0 X{_f(xx[0])} Y{_f(y)}", f"G1 Z{_f(zz[0])} F800"]
        else:
            out.append(f"G1 Y{_f(y)} Z{_f(zz[0])}")
        out.append("F2500")
        out += [f"X{_f(x)} Z{_f(z)}" for x, z in zip(xx[1:], zz[1:])]
    out += [f"G0 Z{_f(SAFE)}", "M5", "M30", "%"]
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    (HERE / "relief_raster.nc").write_text(relief_raster())
