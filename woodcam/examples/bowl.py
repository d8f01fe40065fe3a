"""Turned bowl (build123d): a revolved profile with a foot ring, a recessed base and a round rim.

A small fruit/salad-style bowl as it comes off the lathe: the outside is a smooth ogee-free curve
from the foot ring up to the rim, the inside follows it at a constant-ish wall thickness, the rim
is a full round, and the base is recessed inside the foot ring so it sits on the ring. Axis
vertical (+Z), modelled in woodcam's block frame (mm, origin at the block's bottom-front-left
corner) and centred in the demo block ``[0, 100] x [0, 80] x [0, 50]`` mm.

Run standalone: ``python cad_examples/bowl.py [out.stl]`` writes ``bowl.stl`` (default: in the
current directory). woodcam loads the module-level ``part``.
"""

from __future__ import annotations

import sys

from build123d import (
    Axis,
    BuildLine,
    BuildPart,
    BuildSketch,
    Line,
    Plane,
    Pos,
    Spline,
    ThreePointArc,
    make_face,
    revolve,
)

# ---- parameters (mm) ------------------------------------------------------------------------
BLOCK_MM = (100.0, 80.0, 50.0)  # demo block (W, D, H) the bowl is placed in
CENTER_XY = (50.0, 40.0)        # bowl axis in the block frame
BASE_Z = 4.0                    # underside of the foot ring above the block bottom
RIM_RADIUS = 37.0               # outer rim radius (diameter 74)
HEIGHT = 42.0                   # foot ring underside to top of rim
WALL = 5.0                      # wall thickness at the rim (the rim bead is a full round)
FOOT_OUTER_RADIUS = 22.0        # foot ring outer radius
FOOT_INNER_RADIUS = 16.0        # foot ring inner radius (recessed base inside it)
FOOT_HEIGHT = 4.0               # foot ring height before the outer curve starts
BASE_RECESS = 2.0               # depth of the recess under the base, inside the foot ring
FLOOR_THICKNESS = 7.0           # solid wood between the recess and the inside floor


def make_bowl():
    """Return the bowl as a build123d ``Part`` in the block frame (mm)."""
    r_rim_out = RIM_RADIUS
    r_rim_in = RIM_RADIUS - WALL
    z_rim = HEIGHT - WALL / 2  # centre height of the rim's full round
    z_floor = BASE_RECESS + FLOOR_THICKNESS

    with BuildPart() as bowl:
        with BuildSketch(Plane.XZ):  # sketch x = radius, sketch y = height (block Z)
            with BuildLine():
                Line((0, BASE_RECESS), (FOOT_INNER_RADIUS, BASE_RECESS))
                Line((FOOT_INNER_RADIUS, BASE_RECESS), (FOOT_INNER_RADIUS, 0))
                Line((FOOT_INNER_RADIUS, 0), (FOOT_OUTER_RADIUS, 0))
                Line((FOOT_OUTER_RADIUS, 0), (FOOT_OUTER_RADIUS, FOOT_HEIGHT))
                # outside curve: leaves the foot ring flaring outward, ends vertical at the rim
                Spline(
                    (FOOT_OUTER_RADIUS, FOOT_HEIGHT),
                    (r_rim_out - 2.0, HEIGHT * 0.55),
                    (r_rim_out, z_rim),
                    tangents=((1.0, 0.35), (0.0, 1.0)),
                )
                ThreePointArc((r_rim_out, z_rim), (r_rim_out - WALL / 2, HEIGHT), (r_rim_in, z_rim))
                # inside curve: from the rim down to a flat-ish floor on the axis
                Spline(
                    (r_rim_in, z_rim),
                    (r_rim_in - 3.0, HEIGHT * 0.5),
                    (FOOT_OUTER_RADIUS - 3.0, z_floor + 2.0),
                    (0, z_floor),
                    tangents=((0.0, -1.0), (-1.0, 0.0)),
                )
                Line((0, z_floor), (0, BASE_RECESS))
            make_face()
        revolve(axis=Axis.Z)
    return Pos(CENTER_XY[0], CENTER_XY[1], BASE_Z) * bowl.part


part = make_bowl()


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else "bowl.stl"
    from woodcam.cad import load_part
    from woodcam.export import write_stl

    # woodcam's STL writer: the part meshed as woodcam carves it, the file's 80-byte header
    # saying units=mm (STL has no unit field; the CAD kernel's own exporter said none)
    write_stl(load_part(part, tolerance_mm=0.05), out, note="bowl.py part, block frame, Z up")
    bb = part.bounding_box()
    print(f"wrote {out}: volume {part.volume:.1f} mm^3, bounds {bb.min} .. {bb.max}")
