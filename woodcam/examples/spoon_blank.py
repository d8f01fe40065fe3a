"""Spoon blank (build123d): plan and side profiles intersected, bowl hollowed, handle tilted.

How a carver roughs out a spoon: saw the plan outline (bowl + tapering handle), saw the side
profile (bowl low, handle cranked up at ~14°), then hollow the bowl. The tilted handle and the
curved bowl underside cut across the growth rings at changing angles, so the ring pattern runs
out along the handle. Modelled in woodcam's block frame (mm, origin at the block's
bottom-front-left corner), spoon along X, in the demo block ``[0, 100] x [0, 80] x [0, 50]`` mm.

Run standalone: ``python cad_examples/spoon_blank.py [out.stl]`` writes ``spoon_blank.stl``
(default: in the current directory). woodcam loads the module-level ``part``.
"""

from __future__ import annotations

import math
import sys

from build123d import (
    Circle,
    Ellipse,
    Plane,
    Polygon,
    Polyline,
    Pos,
    Sphere,
    Spline,
    extrude,
    make_face,
    scale,
)

# ---- parameters (mm) ------------------------------------------------------------------------
BLOCK_MM = (100.0, 80.0, 50.0)  # demo block (W, D, H) the blank is placed in
AXIS_Y = 40.0                   # the spoon's centre line (along X) in the block frame
TIP_X, END_X = 4.0, 96.0        # tip of the bowl and end of the handle along X
BOWL_CENTER_X = 24.0            # bowl centre along X
BOWL_HALF_LENGTH = 20.0         # bowl outline semi-axis along X
BOWL_HALF_WIDTH = 15.0          # bowl outline semi-axis along Y
NECK_HALF_WIDTH = 5.0           # handle half width where it leaves the bowl
END_HALF_WIDTH = 8.0            # handle half width at its rounded end
RIM_Z = 26.0                    # height of the bowl's rim (flat top of the bowl)
BOWL_BOTTOM_Z = 12.0            # lowest point of the bowl's underside
HANDLE_ANGLE_DEG = 14.0         # crank of the handle above the bowl's rim plane
HANDLE_THICKNESS = 8.0          # vertical thickness of the handle
HOLLOW_DEPTH = 9.0              # depth of the hollow below the rim
WALL = 3.0                      # bowl wall left around the hollow, in plan


def make_spoon_blank():
    """Return the spoon blank as a build123d ``Part`` in the block frame (mm)."""
    neck_x = BOWL_CENTER_X + BOWL_HALF_LENGTH - 2.0
    # plan outline (XY), extruded through the block's height
    bowl_plan = Pos(BOWL_CENTER_X, AXIS_Y) * Ellipse(BOWL_HALF_LENGTH, BOWL_HALF_WIDTH)
    end_center_x = END_X - END_HALF_WIDTH
    handle_plan = Polygon(
        (neck_x - 6.0, AXIS_Y - NECK_HALF_WIDTH), (end_center_x, AXIS_Y - END_HALF_WIDTH),
        (end_center_x, AXIS_Y + END_HALF_WIDTH), (neck_x - 6.0, AXIS_Y + NECK_HALF_WIDTH),
        align=None,
    )
    end_plan = Pos(end_center_x, AXIS_Y) * Circle(END_HALF_WIDTH)
    plan = extrude(bowl_plan + handle_plan + end_plan, amount=BLOCK_MM[2])

    # side profile (XZ): underside curve of the bowl, then the cranked handle
    rise = math.tan(math.radians(HANDLE_ANGLE_DEG))
    handle_top_end = RIM_Z + rise * (END_X - neck_x)
    side_points_low = [
        (TIP_X - 1.0, RIM_Z - 4.0),
        (BOWL_CENTER_X, BOWL_BOTTOM_Z),
        (neck_x, RIM_Z - HANDLE_THICKNESS),
    ]
    side = Plane.XZ * make_face(
        [
            Spline(*side_points_low, tangents=((0.3, -1.0), (1.0, rise))),
            Polyline(
                side_points_low[-1],
                (END_X + 1.0, handle_top_end - HANDLE_THICKNESS + rise),
                (END_X + 1.0, handle_top_end + rise),
                (neck_x, RIM_Z),
                (TIP_X - 1.0, RIM_Z),
                side_points_low[0],
            ),
        ]
    )
    side = extrude(side, amount=BLOCK_MM[1], both=True)  # Plane.XZ normal is -Y

    hollow = Pos(BOWL_CENTER_X, AXIS_Y, RIM_Z) * scale(
        Sphere(1.0), by=(BOWL_HALF_LENGTH - WALL, BOWL_HALF_WIDTH - WALL, HOLLOW_DEPTH)
    )
    return (plan & side) - hollow


part = make_spoon_blank()


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else "spoon_blank.stl"
    from woodcam.cad import load_part
    from woodcam.export import write_stl

    # woodcam's STL writer: the part meshed as woodcam carves it, the file's 80-byte header
    # saying units=mm (STL has no unit field; the CAD kernel's own exporter said none)
    write_stl(load_part(part, tolerance_mm=0.05), out, note="spoon_blank.py part, block frame, Z up")
    bb = part.bounding_box()
    print(f"wrote {out}: volume {part.volume:.1f} mm^3, bounds {bb.min} .. {bb.max}")
