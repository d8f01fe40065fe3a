"""Serving tray / large coaster (cadquery): rounded rectangle with a pocket and chamfered edges.

The kind of part a CNC router cuts from a board every day: a rounded-rectangle blank, a pocket
with rounded corners and a filleted floor (a ball-nose finish), 45° chamfers on both top edges
of the rim and a small chamfer on the bottom edge. Modelled in woodcam's block frame (mm, origin
at the block's bottom-front-left corner) and centred in the demo block
``[0, 100] x [0, 80] x [0, 50]`` mm.

Run standalone: ``python cad_examples/tray.py [out.stl]`` writes ``tray.stl`` (default: in the
current directory). woodcam loads the module-level ``part``.
"""

from __future__ import annotations

import sys

import cadquery as cq

# ---- parameters (mm) ------------------------------------------------------------------------
BLOCK_MM = (100.0, 80.0, 50.0)  # demo block (W, D, H) the tray is placed in
CENTER_XY = (50.0, 40.0)        # tray centre in the block frame
BASE_Z = 16.0                   # underside of the tray above the block bottom
LENGTH = 90.0                   # along X
WIDTH = 70.0                    # along Y
THICKNESS = 18.0                # along Z
CORNER_RADIUS = 10.0            # outer corner radius (plan view)
RIM = 7.0                       # rim width around the pocket
POCKET_DEPTH = 12.0             # pocket depth from the top face
POCKET_CORNER_RADIUS = CORNER_RADIUS - RIM + 1.0  # >= a 6 mm end mill's radius
POCKET_FLOOR_FILLET = 3.0       # ball-nose radius where the pocket floor meets its walls
TOP_CHAMFER = 2.5               # 45° chamfer on both top edges of the rim
BOTTOM_CHAMFER = 1.0            # 45° chamfer on the outer bottom edge


def make_tray() -> cq.Workplane:
    """Return the tray as a cadquery ``Workplane`` holding one solid, block frame (mm)."""
    blank = (
        cq.Workplane("XY")
        .box(LENGTH, WIDTH, THICKNESS, centered=(True, True, False))
        .edges("|Z")
        .fillet(CORNER_RADIUS)
    )
    pocket = (
        cq.Workplane("XY", origin=(0, 0, THICKNESS - POCKET_DEPTH))
        .box(LENGTH - 2 * RIM, WIDTH - 2 * RIM, POCKET_DEPTH + 1.0, centered=(True, True, False))
        .edges("|Z")
        .fillet(POCKET_CORNER_RADIUS)
        .faces("<Z")
        .edges()
        .fillet(POCKET_FLOOR_FILLET)
    )
    tray = blank.cut(pocket)
    # both edges of the rim's top face: the outer edge and the pocket opening
    tray = tray.faces(">Z").chamfer(TOP_CHAMFER)
    tray = tray.faces("<Z").chamfer(BOTTOM_CHAMFER)
    return tray.translate((CENTER_XY[0], CENTER_XY[1], BASE_Z))


part = make_tray()


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else "tray.stl"
    from woodcam.cad import load_part
    from woodcam.export import write_stl

    # woodcam's STL writer: the part meshed as woodcam carves it, the file's 80-byte header
    # saying units=mm (STL has no unit field; the CAD kernel's own exporter said none)
    write_stl(load_part(part, tolerance_mm=0.05), out, note="tray.py part, block frame, Z up")
    bb = part.val().BoundingBox()
    print(f"wrote {out}: volume {part.val().Volume():.1f} mm^3, bounds "
          f"({bb.xmin:.2f}, {bb.ymin:.2f}, {bb.zmin:.2f}) .. "
          f"({bb.xmax:.2f}, {bb.ymax:.2f}, {bb.zmax:.2f})")
