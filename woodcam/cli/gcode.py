"""``woodcam gcode``: G-code + tools -> simulated stock -> baked wood preview (GLB, PNG).

Registered by :mod:`woodcam.cli` through :func:`register`; the parser's ``func`` is :func:`run`.
"""

from __future__ import annotations

import argparse
import math
import re
import sys
import time
from pathlib import Path

from ..errors import WoodcamError
from .options import BLOCK_SPEC_HELP, add_bake_options, stock_options, write_screenshot

_EXAMPLES = """\
examples:
  woodcam gcode toolpaths/vcarve_text.nc --tool vbit:60:12 --block builtin:flat-sawn \\
      --out out/vcarve_text.glb --screenshot out/vcarve_text.png
  woodcam gcode toolpaths/pocket_islands.nc --tools toolpaths/tools.toml \\
      --block builtin:quarter-sawn --out out/pocket.glb
  woodcam gcode prog.nc --tool 1=flat:6.35 --tool 2=ball:3 --block builtin:rift --out out/p.glb

Tool specs (diameters in mm, angles in degrees): flat:D, ball:D, bull:D:CORNER_R, vbit:ANGLE:D;
prefix N= to give the tool number of the program (T N M6). Work zero defaults to the stock's
top-front-left corner (G-code z = 0 on the top face).
"""


def register(subparsers) -> None:
    """Add the ``gcode`` subcommand to ``subparsers`` (an argparse sub-parsers action)."""
    p = subparsers.add_parser(
        "gcode", help="simulate a G-code program on a block and bake the carved wood",
        description="Read a 3-axis G-code program, remove the swept tools from the block on a "
        "height field, mesh the remaining stock and bake its wood texture.",
        epilog=_EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("program", type=Path, help="G-code file (.nc, .gcode, .ngc, .tap)")
    p.add_argument("--block", required=True, help=BLOCK_SPEC_HELP)
    p.add_argument("--out", type=Path, required=True, help="output .glb path")
    p.add_argument("--tool", action="append", default=[], metavar="[N=]SPEC",
                   help="a tool, e.g. flat:6.35, ball:3, bull:6:1, vbit:60:12, 2=ball:3 "
                   "(repeatable; without N= the tools go to the program's tool numbers in "
                   "order of first use)")
    p.add_argument("--tools", type=Path, default=None, metavar="TOML",
                   help="tool table file ([tools.N] type/diameter_mm/...)")
    p.add_argument("--resolution", type=float, default=0.1, metavar="MM",
                   help="height-field cell size (default 0.1 mm)")
    p.add_argument("--work-offset", default=None, metavar="X,Y,Z", type=_triple("--work-offset"),
                   help="block-frame position of G-code zero in mm (default 0,0,H: "
                   "top-front-left); negative values as --work-offset -14,5,3")
    p.add_argument("--start", default=None, metavar="X,Y,Z", type=_triple("--start"),
                   help="machine position (G-code frame, mm) before the first move, also the "
                   "G28/G30 home (default 0,0,10: 10 mm over the work zero)")
    p.add_argument("--dialect", choices=("linuxcnc", "grbl", "fanuc"), default="linuxcnc",
                   help="whose meaning the program has (default linuxcnc): grbl has no "
                   "parameters or O-words; fanuc reads O1234 program numbers")
    p.add_argument("--interpreter", choices=("woodcam", "linuxcnc"), default="woodcam",
                   help="read the program with woodcam's interpreter (default) or with "
                   "LinuxCNC's own (needs Debian's linuxcnc-uspace)")
    p.add_argument("--mesh-tol", type=float, default=0.05, metavar="MM",
                   help="merge nearly planar regions of the result mesh within this (default "
                   "0.05 mm: the 20,000-move raster's mesh shrinks from 2.0 M to 0.44 M "
                   "triangles, its volume moves by 0.0006 mm on average)")
    add_bake_options(p)
    p.set_defaults(func=run)
    # argparse takes "-14,5,3" for an option; a value that looks like numbers is a value
    p._negative_number_matcher = _NEGATIVE_VALUES


_NEGATIVE_VALUES = re.compile(r"^-[\d.][\d.,eE+-]*$")


def _triple(option: str):
    """argparse type: ``"X,Y,Z"`` -> three finite floats (mm), or a one-line error."""
    def parse(text: str) -> tuple[float, float, float]:
        try:
            vals = tuple(float(v) for v in text.split(","))
        except ValueError:
            vals = ()
        if len(vals) != 3 or not all(math.isfinite(v) for v in vals):
            raise argparse.ArgumentTypeError(f"{option} {text!r}: give three finite numbers "
                                             "X,Y,Z in mm, e.g. 0,0,50")
        return vals
    return parse


def _tools_from_args(args, program) -> dict:
    from ..toolpath.tools import load_tool_table, parse_tool_spec

    tools = dict(load_tool_table(args.tools)) if args.tools else {}
    unnumbered = []
    for item in args.tool:
        if "=" in item:
            num, spec = item.split("=", 1)
            try:
                tools[int(num)] = parse_tool_spec(spec)
            except ValueError as err:
                raise WoodcamError(f"--tool {item!r}: the part before '=' must be a tool "
                                   "number, e.g. 2=ball:3") from err
        else:
            unnumbered.append(parse_tool_spec(item))
    if unnumbered:
        used = [t for t in dict.fromkeys(program.tool.tolist()) if t not in tools]
        if len(unnumbered) == 1 and len(used) <= 1:
            used = used or [0]
        if len(unnumbered) > len(used):
            raise WoodcamError(f"--tool: {len(unnumbered)} tools without numbers but the program "
                               f"uses {len(used)} tool number(s) without a tool ({used}); give "
                               "numbers as N=SPEC")
        tools.update(zip(used, unnumbered))
    if not tools:
        raise WoodcamError("woodcam gcode: no tools given; pass --tool SPEC (e.g. --tool "
                           "flat:6.35) or --tools TABLE.toml")
    return tools


def run(args) -> int:
    """Run ``woodcam gcode``; prints the simulation report and what was written."""
    import numpy as np

    from ..pipeline import check_outputs, preview_heightfield
    from ..stock import open_stock
    from ..toolpath.gcode import read_gcode
    from ..toolpath.simulate import simulate

    check_outputs(args.out, obj=not args.no_obj, screenshot=args.screenshot or False)
    stock = open_stock(args.block, **stock_options(args))
    t0 = time.perf_counter()
    program = read_gcode(args.program, start_mm=args.start, dialect=args.dialect,
                         interpreter=args.interpreter)
    t_read = time.perf_counter() - t0
    for w in program.warnings:
        print(f"woodcam: warning: {args.program.name} {w}", file=sys.stderr)
    if not (program.kind == 1).any():
        raise WoodcamError(f"woodcam gcode: {args.program} has no cutting move (G1/G2/G3 or a "
                           "drilling cycle); nothing to simulate. Check that it is the "
                           "program you meant")
    tools = _tools_from_args(args, program)
    offset = list(args.work_offset) if args.work_offset else None
    res = simulate(program, tools, stock.size_mm, resolution_mm=args.resolution,
                   work_offset_mm=offset, progress=False)
    for issue in res.report:
        print(f"woodcam: warning: {args.program.name} {issue}", file=sys.stderr)
    meta = {"gcode": str(args.program),
            "tools": {str(k): v.spec() for k, v in sorted(tools.items())},
            "resolution_mm": float(np.mean(res.cell_mm))}
    t1 = time.perf_counter()
    out = preview_heightfield(res.heightmap, stock, args.out, texels_per_mm=args.texels_per_mm,
                              flat_tol_mm=args.mesh_tol, obj=not args.no_obj, metadata=meta,
                              obj_units=args.obj_units, obj_up=args.obj_up)
    t_bake = time.perf_counter() - t1
    write_screenshot(args, out.files, stock)
    s = res.stats
    print(f"{args.program.name}: {len(program)} moves read in {t_read:.2f} s, simulated on "
          f"{s['grid'][1]}x{s['grid'][0]} cells in {s['wall_s']:.2f} s "
          f"({s['moves_per_s']:.0f} moves/s), removed {res.removed_volume_mm3:.0f} mm^3, "
          f"meshed and baked {out.triangles} triangles in {t_bake:.2f} s, "
          f"{len(res.report)} issue(s); "
          "wrote " + ", ".join(map(str, out.files.values())))
    return 0
