"""Write the sample G-code programs of this folder (run: python toolpaths/make_samples.py).

Each program is what a CAM package would post for a 3-axis router: mm, G90, work zero on the
stock's top-front-left corner, for the built-in 100 x 80 x 50 mm blocks (``woodcam blocks``).
The tools are in ``tools.toml``. Kept as a script so the programs can be regenerated and read;
the simulation never imports it (the benchmark does, for :func:`relief_raster`).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
W, D, H = 100.0, 80.0, 50.0
SAFE = 5.0


def _f(v: float) -> str:
    s = f"{v:.3f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def _head(title: str, tool: int, comment: str) -> list[str]:
    return ["%", f"({title})", f"({comment})", "G21 G90 G17 G94", f"T{tool} M6", "S18000 M3",
            f"G0 Z{_f(SAFE)}"]


def _tail() -> list[str]:
    return [f"G0 Z{_f(SAFE)}", "M5", "M30", "%"]


# -- 1. pocket with islands ------------------------------------------------------------------
def pocket_islands() -> str:
    """70 x 50 mm pocket, 8 mm deep in two 4 mm levels, around a round island (r 9) and a
    rectangular island (14 x 22); 6.35 mm flat end mill, zig-zag clearing + contour passes."""
    t_r = 6.35 / 2
    x0, x1, y0, y1 = 15.0, 85.0, 15.0, 65.0             # pocket walls
    circ = (38.0, 40.0, 9.0)                             # round island
    rect = (58.0, 72.0, 29.0, 51.0)                      # rectangular island
    out = _head("pocket with two islands", 1, "block 100 x 80 x 50, T1 = 6.35 mm flat")
    step = 0.45 * 6.35
    for depth in (-4.0, -8.0):
        ys = np.arange(y0 + t_r + 0.3, y1 - t_r - 0.3 + 1e-9, step)
        for k, y in enumerate(ys):
            # free intervals of the line y inside the pocket, outside the grown islands
            cuts = [(x0 + t_r + 0.3, x1 - t_r - 0.3)]
            cx, cy, cr = circ
            if abs(y - cy) < cr + t_r + 0.3:
                h = math.sqrt((cr + t_r + 0.3) ** 2 - (y - cy) ** 2)
                cuts = _split(cuts, cx - h, cx + h)
            if rect[2] - t_r - 0.3 < y < rect[3] + t_r + 0.3:
                cuts = _split(cuts, rect[0] - t_r - 0.3, rect[1] + t_r + 0.3)
            for a, b in (cuts if k % 2 == 0 else [(b, a) for a, b in cuts[::-1]]):
                out += [f"G0 X{_f(a)} Y{_f(y)}", f"G1 Z{_f(depth)} F400",
                        f"G1 X{_f(b)} F1800", "G0 Z1"]
            out.append(f"G0 Z{_f(SAFE)}")
        # contour of the pocket walls (climb: clockwise inside a pocket), rounded corners = tool
        xa, xb, ya, yb = x0 + t_r, x1 - t_r, y0 + t_r, y1 - t_r
        out += [f"G0 X{_f(xa)} Y{_f((ya + yb) / 2)}", f"G1 Z{_f(depth)} F400",
                f"G1 Y{_f(yb)} F1500", f"X{_f(xb)}", f"Y{_f(ya)}", f"X{_f(xa)}",
                f"Y{_f((ya + yb) / 2)}", f"G0 Z{_f(SAFE)}"]
        # round island: full circle with I/J
        r = cr + t_r
        out += [f"G0 X{_f(cx + r)} Y{_f(cy)}", f"G1 Z{_f(depth)} F400",
                f"G3 X{_f(cx + r)} Y{_f(cy)} I{_f(-r)} J0 F1500", f"G0 Z{_f(SAFE)}"]
        # rectangular island: sides offset by the tool radius, corners as R-form arcs
        ra, rb, rc_, rd = rect
        out += [f"G0 X{_f(ra)} Y{_f(rc_ - t_r)}", f"G1 Z{_f(depth)} F400",
                f"G1 X{_f(rb)} F1500", f"G3 X{_f(rb + t_r)} Y{_f(rc_)} R{_f(t_r)}",
                f"G1 Y{_f(rd)}", f"G3 X{_f(rb)} Y{_f(rd + t_r)} R{_f(t_r)}",
                f"G1 X{_f(ra)}", f"G3 X{_f(ra - t_r)} Y{_f(rd)} R{_f(t_r)}",
                f"G1 Y{_f(rc_)}", f"G3 X{_f(ra)} Y{_f(rc_ - t_r)} R{_f(t_r)}",
                f"G0 Z{_f(SAFE)}"]
    return "\n".join(out + _tail()) + "\n"


def _split(intervals, a, b):
    out = []
    for lo, hi in intervals:
        if b <= lo or a >= hi:
            out.append((lo, hi))
            continue
        if a > lo:
            out.append((lo, a))
        if b < hi:
            out.append((b, hi))
    return out


# -- 2. profile cut-out with tabs -------------------------------------------------------------
def profile_tabs() -> str:
    """Cut a 64 x 44 mm plaque with 10 mm corner radii out of the block, 5 mm passes down to
    -50.5 (through), four 8 mm wide tabs 4 mm high on the last passes; 6.35 mm flat end mill on
    the outside of the line (climb: counter-clockwise around the part)."""
    t_r = 6.35 / 2
    cx, cy, hw, hh, rc = 50.0, 40.0, 32.0, 22.0, 10.0
    r = rc + t_r
    xa, xb, ya, yb = cx - hw - t_r, cx + hw + t_r, cy - hh - t_r, cy + hh + t_r
    tab_w, tab_top = 8.0 + 2 * t_r, -H + 4.0
    out = _head("profile cut-out with tabs", 1, "block 100 x 80 x 50, T1 = 6.35 mm flat")
    out += [f"G0 X{_f(cx)} Y{_f(ya)}"]
    depths = list(np.arange(-5.0, -H - 0.5, -5.0)) + [-H - 0.5]
    for z in depths:
        tabs = z < tab_top
        out.append(f"G1 Z{_f(z)} F300")

        def side(p_from, p_to, axis, tab=True):
            # straight side with a tab in its middle when this pass is below the tab top
            if not (tabs and tab):
                return [f"G1 {axis}{_f(p_to)} F1500"]
            mid = 0.5 * (p_from + p_to)
            sgn = 1 if p_to > p_from else -1
            a, b = mid - sgn * tab_w / 2, mid + sgn * tab_w / 2
            return [f"G1 {axis}{_f(a)} F1500", f"G1 Z{_f(tab_top)}", f"G1 {axis}{_f(b)}",
                    f"G1 Z{_f(z)}", f"G1 {axis}{_f(p_to)}"]

        # start mid bottom side, go counter-clockwise: +X along the bottom
        out += side(cx, cx + hw - rc, "X")
        out.append(f"G3 X{_f(xb)} Y{_f(cy - hh + rc)} I0 J{_f(r)}")
        out += side(cy - hh + rc, cy + hh - rc, "Y")
        out.append(f"G3 X{_f(cx + hw - rc)} Y{_f(yb)} I{_f(-r)} J0")
        out += side(cx + hw - rc, cx - hw + rc, "X")
        out.append(f"G3 X{_f(xa)} Y{_f(cy + hh - rc)} I0 J{_f(-r)}")
        out += side(cy + hh - rc, cy - hh + rc, "Y")
        out.append(f"G3 X{_f(cx - hw + rc)} Y{_f(ya)} I{_f(r)} J0")
        out += side(cx - hw + rc, cx, "X", tab=False)  # bottom side: one tab, on its right half
    return "\n".join(out + _tail()) + "\n"


# -- 3. ball-end 3D raster ------------------------------------------------------------------
def relief_height(x, y, w=W, d=D):
    """Relief surface (mm, <= -0.5) of the raster sample: a bowl with a ripple ring."""
    r = np.hypot((x - w / 2) / (w / 2), (y - d / 2) / (d / 2))
    bowl = -16.0 * np.clip(1 - (r / 0.8) ** 2, 0, None)
    ripple = -1.2 * np.cos(r * 40.0) * np.exp(-((r - 0.45) / 0.2) ** 2)
    return np.minimum(bowl + ripple, -0.5)


def relief_raster(w: float = W, d: float = D, stepover: float = 0.5, n_seg: int = 100,
                  ball_d: float = 6.0, tool: int = 2) -> str:
    """Ball-end 3D raster finish of :func:`relief_height`: zig-zag passes along X every
    ``stepover`` mm, ``n_seg`` moves each (100 x 100 mm, 0.5 mm: 201 x 100 = 20,100 moves)."""
    out = _head("relief bowl: ball-end 3D raster finish", tool,
                f"stock {w:g} x {d:g}, T{tool} = {ball_d:g} mm ball")
    r = ball_d / 2
    ys = np.linspace(0, d, int(round(d / stepover)) + 1)
    xs = np.linspace(-r, w + r, n_seg + 1)
    for k, y in enumerate(ys):
        xx = xs if k % 2 == 0 else xs[::-1]
        zz = relief_height(np.clip(xx, 0, w), np.full_like(xx, y), w, d)
        if k == 0:
            out += [f"G0 X{_f(xx[0])} Y{_f(y)}", f"G1 Z{_f(zz[0])} F800"]
        else:
            out.append(f"G1 Y{_f(y)} Z{_f(zz[0])}")
        out.append("F2500")
        out += [f"X{_f(x)} Z{_f(z)}" for x, z in zip(xx[1:], zz[1:])]
    return "\n".join(out + _tail()) + "\n"


# -- 4. V-carved text ---------------------------------------------------------------------------
def vcarve_text() -> str:
    """'WOOD' in single-stroke letters 30 mm high, V-carved 3 mm deep (3.5 mm wide grooves)
    with a 60 deg V-bit; the O's are full circles (I/J), the D's bowl a half circle (R)."""
    z = -3.0
    y0, y1 = 25.0, 55.0
    out = _head("V-carved text WOOD", 3, "block 100 x 80 x 50, T3 = 60 deg V-bit, 12 mm")

    def stroke(points):
        (x, y), rest = points[0], points[1:]
        o = [f"G0 X{_f(x)} Y{_f(y)}", f"G1 Z{_f(z)} F300"]
        o += [f"G1 X{_f(px)} Y{_f(py)} F1200" for px, py in rest]
        return o + [f"G0 Z{_f(2.0)}"]

    # W: 8..30
    out += stroke([(8, y1), (14, y0), (19, y1 - 12), (24, y0), (30, y1)])
    # O centred at 43 and 66, radius 9 (x 34..52, 57..75)
    for cx in (43.0, 64.0):
        out += [f"G0 X{_f(cx + 9)} Y{_f((y0 + y1) / 2)}", f"G1 Z{_f(z)} F300",
                f"G2 X{_f(cx + 9)} Y{_f((y0 + y1) / 2)} I-9 J0 F1200", f"G0 Z{_f(2.0)}"]
    # D: stem at 78, bowl radius 15 (x up to 93)
    out += [f"G0 X78 Y{_f(y0)}", f"G1 Z{_f(z)} F300", f"G1 Y{_f(y1)} F1200",
            f"G2 X78 Y{_f(y0)} R15", f"G0 Z{_f(2.0)}"]
    return "\n".join(out + _tail()) + "\n"


# -- 5. drilling cycle ----------------------------------------------------------------------
def drilling() -> str:
    """Two rows of holes: four 12 mm deep with G81, four 30 mm deep pecked with G83 (Q 6);
    5 mm twist drill (118 deg point); the reader expands the cycles into rapid/feed moves."""
    out = _head("drilling cycles G81 and G83", 5, "block 100 x 80 x 50, T5 = 5 mm drill")
    out += ["G0 X20 Y25", "G99 G81 X20 Y25 Z-12 R2 F250", "X40", "X60", "X80", "G80",
            "G0 Z5", "G98 G83 X20 Y55 Z-30 R2 Q6 F250", "X40", "X60", "X80", "G80"]
    return "\n".join(out + _tail()) + "\n"


SAMPLES = {"pocket_islands": pocket_islands, "profile_tabs": profile_tabs,
           "relief_raster": relief_raster, "vcarve_text": vcarve_text, "drilling": drilling}

if __name__ == "__main__":
    for name, make in SAMPLES.items():
        (HERE / f"{name}.nc").write_text(make())
        print("wrote", HERE / f"{name}.nc")
