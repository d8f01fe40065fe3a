"""Write a real-sized relief job: a 167 x 208 mm carved panel finished by an OpenCAMLib
drop-cutter raster (run: python toolpaths/make_relief_job.py OUT_DIR).

The panel (a raised rosette in a sunken field with a moulded border, 12 mm of relief in a
25 mm board) is triangulated at 2 mm as an STL (OpenCAMLib drops a cutter ~20x slower on
the 1 mm one: ~5 s per pass), and OpenCAMLib's ``PathDropCutter`` (PyPI
``opencamlib``) drops a 3 mm ball along X every ``stepover`` mm, sampled every ``sampling`` mm:
with the defaults (0.5 mm, 1.0 mm) 417 passes of 168 points, ~70,000 moves, which is the size
of the largest public relief programs (issue 18). The program is posted as a LinuxCNC post
would write it: mm, G90, work zero on the board's top-front-left corner (so Z is negative), T1
a 3 mm ball. Nothing here is imported by woodcam; the benchmark runs it.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

W, D, H = 167.0, 208.0, 25.0
RELIEF_MM = 12.0


def panel_height(x, y):
    """Board-frame top of the carved panel (mm) at ``x, y``: a moulded border, a sunken field
    and a rosette of eight petals around a boss."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    field = H - RELIEF_MM
    inset = np.minimum.reduce([x, W - x, y, D - y])  # distance into the board from its edge
    border = np.where(inset < 12.0, H - 2.0 * (1 - np.cos(np.pi * np.clip(inset, 0, 12) / 12)),
                      field)
    cx, cy = W / 2, D / 2
    r = np.hypot(x - cx, y - cy)
    a = np.arctan2(y - cy, x - cx)
    petal = np.clip(1 - r / (55 + 18 * np.cos(8 * a)), 0, None) ** 0.6
    boss = np.clip(1 - (r / 16) ** 2, 0, None) ** 0.5
    rosette = field + 9.0 * petal + 2.5 * boss + 0.4 * np.sin(r / 2.5) * (petal > 0)
    return np.maximum(np.where(inset < 12.0, border, field), np.minimum(rosette, H - 0.5))


def panel_stl(path, step_mm: float = 2.0, *, solid: bool = False) -> Path:
    """The panel's top surface, triangulated every ``step_mm``, as an STL at ``path``;
    ``solid``: closed by four walls and a bottom at Z = 0 (the design part for ``--part``)."""
    import trimesh

    nx, ny = int(round(W / step_mm)) + 1, int(round(D / step_mm)) + 1
    X, Y = np.meshgrid(np.linspace(0, W, nx), np.linspace(0, D, ny))
    Z = panel_height(X, Y)
    a = (np.arange(ny - 1)[:, None] * nx + np.arange(nx - 1)[None, :]).ravel()
    faces = np.concatenate([np.c_[a, a + 1, a + nx + 1], np.c_[a, a + nx + 1, a + nx]])
    verts = np.c_[X.ravel(), Y.ravel(), Z.ravel()]
    if solid:  # boundary ring (counter-clockwise from above), its copy at Z = 0, a bottom fan
        vid = np.arange(nx * ny).reshape(ny, nx)
        ring = np.concatenate([vid[0, :-1], vid[:-1, -1], vid[-1, :0:-1], vid[:0:-1, 0]])
        n, base = len(ring), len(verts)
        low = base + np.arange(n)
        verts = np.vstack([verts, np.c_[verts[ring, :2], np.zeros(n)], [[W / 2, D / 2, 0]]])
        nr, nl = np.roll(ring, -1), np.roll(low, -1)
        faces = np.vstack([faces, np.c_[low, nl, nr], np.c_[low, nr, ring],
                           np.c_[np.full(n, base + n), nl, low]])
    mesh = trimesh.Trimesh(verts, faces)
    if solid:
        assert mesh.is_watertight and mesh.volume > 0
    mesh.export(path)
    return Path(path)


def relief_job(stl_path, *, ball_d: float = 3.0, stepover: float = 0.5,
               sampling: float = 1.0) -> str:
    """G-code of the OpenCAMLib drop-cutter raster over ``stl_path`` (zig-zag along X)."""
    import opencamlib as ocl

    surf = ocl.STLSurf()
    ocl.STLReader(str(stl_path), surf)
    cutter = ocl.BallCutter(ball_d, 30)  # kept alive: OpenCAMLib holds a raw pointer to it
    pdc = ocl.PathDropCutter()
    pdc.setSTL(surf)
    pdc.setCutter(cutter)
    pdc.setSampling(sampling)
    pdc.setZ(0)
    f = lambda v: f"{v:.4f}".rstrip("0").rstrip(".")  # noqa: E731
    out = ["%", "(relief panel 167 x 208 mm: OpenCAMLib drop-cutter raster)",
           f"(T1 = {ball_d:g} mm ball, step-over {stepover:g} mm)", "G21 G90 G17 G94 G54",
           "T1 M6", "S18000 M3", "G0 Z5"]
    for k, y in enumerate(np.arange(0.0, D + 1e-9, stepover)):
        path = ocl.Path()
        a, b = (0.0, W) if k % 2 == 0 else (W, 0.0)
        path.append(ocl.Line(ocl.Point(a, float(y), 0), ocl.Point(b, float(y), 0)))
        pdc.setPath(path)
        pdc.run()
        pts = [(p.x, p.y, p.z - H) for p in pdc.getCLPoints()]  # work zero on the top
        if k == 0:
            out += [f"G0 X{f(pts[0][0])} Y{f(pts[0][1])}", f"G1 Z{f(pts[0][2])} F1200", "F3000"]
        else:
            out.append(f"G1 X{f(pts[0][0])} Y{f(pts[0][1])} Z{f(pts[0][2])}")
        out += [f"X{f(x)} Z{f(z)}" for x, _, z in pts[1:]]
    return "\n".join(out + ["G0 Z5", "M5", "M30", "%"]) + "\n"


if __name__ == "__main__":
    folder = Path(sys.argv[1] if len(sys.argv) > 1 and sys.argv[1][0] != "-" else ".")
    folder.mkdir(parents=True, exist_ok=True)
    stl = panel_stl(folder / "relief_panel.stl")
    part = panel_stl(folder / "relief_panel_part.stl", solid=True)
    if "--part-only" not in sys.argv:
        (folder / "relief_panel.ngc").write_text(relief_job(stl))
    print(f"wrote {stl}, {part} and {folder / 'relief_panel.ngc'}")
