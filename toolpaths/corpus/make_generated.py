"""Write the generated members of the G-code corpus (deterministic: fixed seeds).

    python toolpaths/corpus/make_generated.py

Each program is a realistic shape a CAM post would emit: rasters, spirals of arcs, helical bores,
incremental zig-zags, hole patterns, a V-carve outline of many short moves, inch programs.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent


def _write(name: str, lines: list[str]) -> None:
    from woodcam._atomic import write_text

    write_text(HERE / name, "\n".join(lines) + "\n")


def raster(name, step, width, depth, seed):
    rng = np.random.default_rng(seed)
    out = [f"(generated raster, step {step} mm)", "G21 G90 G17", "T1 M6", "S18000 M3", "G0 Z5",
           "G0 X5 Y5", "G1 Z0 F500"]
    y, forward = 5.0, True
    while y <= 5 + width:
        xs = np.linspace(5, 75, 15)
        zs = depth * (0.5 + 0.5 * np.sin(xs / 9 + rng.uniform(0, 1)))
        for x, z in zip(xs if forward else xs[::-1], zs if forward else zs[::-1]):
            out.append(f"G1 X{x:.4f} Y{y:.4f} Z{z:.4f} F1800")
        y += step
        forward = not forward
    out += ["G0 Z5", "M5", "M30"]
    _write(name, out)


def spiral_arcs(name, turns, r0, pitch):
    out = ["(generated arc spiral)", "G21 G90 G17", "G0 Z5", f"G0 X{50 + r0:.4f} Y40",
           "G1 Z-1 F300"]
    r = r0
    for _ in range(turns):
        out.append(f"G3 X{50 - r - pitch / 2:.4f} Y40 I{-(r + pitch / 4):.4f} J0 F1200")
        r += pitch / 2
        out.append(f"G3 X{50 + r + pitch / 2:.4f} Y40 I{r + pitch / 4:.4f} J0")
        r += pitch / 2
    out += ["G0 Z5", "M2"]
    _write(name, out)


def helix_bore(name, holes):
    out = ["(generated helical bores)", "G21 G90 G17", "G0 Z5"]
    for i, (x, y) in enumerate(holes):
        out += [f"G0 X{x + 4:.3f} Y{y:.3f}", "G1 Z0 F300"]
        z = 0.0
        while z > -6:
            z -= 1.0
            out.append(f"G2 X{x + 4:.3f} Y{y:.3f} I-4 J0 Z{z:.3f} F900")
        out += [f"G2 X{x + 4:.3f} Y{y:.3f} I-4 J0", "G0 Z5"]
    out.append("M2")
    _write(name, out)


def zigzag_incremental(name):
    out = ["(generated incremental zig-zag)", "G21 G90", "G0 Z5", "G0 X10 Y10", "G1 Z-1 F300",
           "G91"]
    for k in range(20):
        out.append(f"G1 X{60 if k % 2 == 0 else -60} F1500")
        out.append("G1 Y2")
    out += ["G90", "G0 Z5", "M2"]
    _write(name, out)


def hole_pattern_loop(name, n, radius):
    out = ["(generated bolt circle with a loop and parameters)", "G21 G90 G17", "G0 Z10",
           f"#<n> = {n}", f"#<r> = {radius}", "#<i> = 0",
           "o1 while [#<i> LT #<n>]",
           "  #<a> = [360 / #<n> * #<i>]",
           "  G0 X[50 + #<r> * COS[#<a>]] Y[40 + #<r> * SIN[#<a>]]",
           "  G98 G81 Z-5 R2 F200",
           "  G80",
           "  #<i> = [#<i> + 1]",
           "o1 endwhile", "G0 Z20", "M2"]
    _write(name, out)


def vcarve_outline(name, n, seed):
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 2 * math.pi, n)
    r = 20 + 6 * np.sin(5 * t) + rng.normal(0, 0.2, n)
    x, y = 50 + r * np.cos(t), 40 + r * np.sin(t)
    z = -1 - 1.5 * (0.5 + 0.5 * np.cos(5 * t))
    out = ["(generated V-carve outline of many short moves)", "G21 G90", "T3 M6", "G0 Z5",
           f"G0 X{x[0]:.4f} Y{y[0]:.4f}", "G1 Z-1 F300"]
    out += [f"G1 X{a:.4f} Y{b:.4f} Z{c:.4f} F1500" for a, b, c in zip(x, y, z)]
    out += ["G0 Z5", "M30"]
    _write(name, out)


def inch_profile(name):
    out = ["(generated inch profile with R arcs)", "G20 G90 G17", "G0 Z0.2", "G0 X0.5 Y0.5",
           "G1 Z-0.05 F20", "G1 X2.5 F60", "G3 X3 Y1 R0.5", "G1 Y2", "G3 X2.5 Y2.5 R0.5",
           "G1 X0.5", "G3 X0 Y2 R0.5", "G1 Y1", "G3 X0.5 Y0.5 R0.5", "G0 Z0.2", "M2"]
    _write(name, out)


def pocket_sub_rows(name):
    out = ["(generated slots by a subroutine with arguments)", "G21 G90", "G0 Z5",
           "o<slot> sub", "  G0 X#1 Y#2", "  G1 Z#3 F300", "  G1 X[#1 + #4] F1200",
           "  G0 Z5", "o<slot> endsub"]
    for k in range(8):
        out.append(f"o<slot> call [10] [{8 + 8 * k}] [{-1 - 0.25 * k:.2f}] [{40 + 3 * k}]")
    out.append("M2")
    _write(name, out)


if __name__ == "__main__":
    raster("gen_raster_fine.ngc", 0.5, 20, -3, 1)
    raster("gen_raster_coarse.ngc", 2.0, 60, -6, 2)
    spiral_arcs("gen_spiral_arcs.ngc", 8, 2, 3)
    helix_bore("gen_helix_bores.ngc", [(20, 20), (50, 40), (80, 60)])
    zigzag_incremental("gen_zigzag_incremental.ngc")
    hole_pattern_loop("gen_bolt_circle.ngc", 8, 25)
    vcarve_outline("gen_vcarve_outline.ngc", 400, 3)
    inch_profile("gen_inch_profile.ngc")
    pocket_sub_rows("gen_slots_sub.ngc")
