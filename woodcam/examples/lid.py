"""Box lid with a raised panel (build123d): wide 30° bevels cut across the growth rings.

A classic raised-panel lid: a flat plate with rounded corners, a lip underneath that drops into
the box, and a raised field in the middle whose four wide bevels slope at 30° to the top face.
The bevels slice through the rings at a shallow angle, so they show stretched, flame-like ring
patterns (a good test for a wood texture). Modelled in woodcam's block frame (mm, origin at the
block's bottom-front-left corner) and centred in the demo block ``[0, 100] x [0, 80] x [0, 50]``.

Run standalone: ``python cad_examples/lid.py [out.stl]`` writes ``lid.stl`` (default: in the
current directory). woodcam loads the module-level ``part``.
"""

from __future__ import annotations

import math
import sys

from build123d import (
    Plane,
    Pos,
    Rectangle,
    RectangleRounded,
    extrude,
    fillet,
    loft,
)

# ---- parameters (mm) ------------------------------------------------------------------------
BLOCK_MM = (100.0, 80.0, 50.0)  # demo block (W, D, H) the lid is placed in
CENTER_XY = (50.0, 40.0)        # lid centre in the block frame
BASE_Z = 14.0                   # underside of the lip above the block bottom
PLATE_SIZE = (92.0, 72.0)       # plate footprint (X, Y)
PLATE_THICKNESS = 8.0
PLATE_CORNER_RADIUS = 6.0
PLATE_EDGE_FILLET = 2.0         # round-over on the plate's outer top edge
LIP_INSET = 4.0                 # the lip sits this far inside the plate edge (box wall)
LIP_HEIGHT = 4.0
PANEL_MARGIN = 6.0              # flat plate margin between the plate edge and the bevels
BEVEL_RUN = 14.0                # horizontal width of each bevel
BEVEL_ANGLE_DEG = 30.0          # bevel slope against the plate's top face


def make_lid():
    """Return the lid as a build123d ``Part`` in the block frame (mm), lid centre at origin XY."""
    px, py = PLATE_SIZE
    lip_corner_radius = PLATE_CORNER_RADIUS - LIP_INSET + 2.0  # a box's inside corner radius
    lip = extrude(
        RectangleRounded(px - 2 * LIP_INSET, py - 2 * LIP_INSET, lip_corner_radius),
        amount=LIP_HEIGHT,
    )
    plate = Pos(0, 0, LIP_HEIGHT) * extrude(
        RectangleRounded(px, py, PLATE_CORNER_RADIUS), amount=PLATE_THICKNESS
    )
    plate = fillet(plate.edges().group_by()[-1], radius=PLATE_EDGE_FILLET)  # top face's edges

    z_plate_top = LIP_HEIGHT + PLATE_THICKNESS
    rise = BEVEL_RUN * math.tan(math.radians(BEVEL_ANGLE_DEG))
    bx, by = px - 2 * PANEL_MARGIN, py - 2 * PANEL_MARGIN
    # start the panel 0.5 mm inside the plate so the union is one clean solid
    panel = loft(
        [
            Plane.XY.offset(z_plate_top - 0.5) * Rectangle(bx, by),
            Plane.XY.offset(z_plate_top) * Rectangle(bx, by),
            Plane.XY.offset(z_plate_top + rise) * Rectangle(bx - 2 * BEVEL_RUN, by - 2 * BEVEL_RUN),
        ],
        ruled=True,
    )
    lid = lip + plate + panel
    return Pos(CENTER_XY[0], CENTER_XY[1], BASE_Z) * lid


part = make_lid()


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else "lid.stl"
    from woodcam.cad import load_part
    from woodcam.export import write_stl

    # woodcam's STL writer: the part meshed as woodcam carves it, the file's 80-byte header
    # saying units=mm (STL has no unit field; the CAD kernel's own exporter said none)
    write_stl(load_part(part, tolerance_mm=0.05), out, note="lid.py part, block frame, Z up")
    bb = part.bounding_box()
    print(f"wrote {out}: volume {part.volume:.1f} mm^3, bounds {bb.min} .. {bb.max}")
