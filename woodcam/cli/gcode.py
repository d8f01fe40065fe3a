"""``woodcam gcode``: G-code + tools -> simulated stock -> baked wood preview (GLB, PNG).

Registered by :mod:`woodcam.cli` through :func:`register`; the parser's ``func`` is :func:`run`.
"""

from __future__ import annotations

import argparse
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
    p.add_argument("--work-offset", default=None, metavar="X,Y,Z",
                   help="block-frame position of G-code zero (default 0,0,H: top-front-left)")
    p.add_argument("--mesh-tol", type=float, default=0.01, metavar="MM",
                   help="merge nearly planar regions of the result mesh within this (default "
                   "0.01 mm)")
    add_bake_options(p)
    p.set_defaults(func=run)


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

    from ..pipeline import preview_mesh
    from ..stock import open_stock
    from ..toolpath.gcode import read_gcode
    from ..toolpath.simulate import simulate

    stock = open_stock(args.block, **stock_options(args))
    t0 = time.perf_counter()
    program = read_gcode(args.program)
    t_read = time.perf_counter() - t0
    tools = _tools_from_args(args, program)
    offset = None
    if args.work_offset:
        try:
            offset = [float(v) for v in args.work_offset.split(",")]
            assert len(offset) == 3
        except (ValueError, AssertionError) as err:
            raise WoodcamError(f"--work-offset {args.work_offset!r}: give three numbers X,Y,Z "
                               "in mm, e.g. 0,0,50") from err
    res = simulate(program, tools, stock.size_mm, resolution_mm=args.resolution,
                   work_offset_mm=offset, progress=False)
    t1 = time.perf_counter()
    mesh = res.to_mesh(flat_tol_mm=args.mesh_tol)
    t_mesh = time.perf_counter() - t1
    for issue in res.report:
        print(f"woodcam: warning: {args.program.name} {issue}", file=sys.stderr)
    meta = {"gcode": str(args.program),
            "tools": {str(k): v.spec() for k, v in sorted(tools.items())},
            "resolution_mm": float(np.mean(res.cell_mm))}
    out = preview_mesh(mesh, stock, args.out, texels_per_mm=args.texels_per_mm,
                       obj=not args.no_obj, screenshot=False, progress=True, metadata=meta,
                       obj_units=args.obj_units, obj_up=args.obj_up, max_atlas_px=args.max_atlas)
    write_screenshot(args, out.files, stock)
    s = res.stats
    print(f"{args.program.name}: {len(program)} moves read in {t_read:.2f} s, simulated on "
          f"{s['grid'][1]}x{s['grid'][0]} cells in {s['wall_s']:.2f} s "
          f"({s['moves_per_s']:.0f} moves/s), removed {res.removed_volume_mm3:.0f} mm^3, "
          f"mesh {len(mesh.faces)} triangles in {t_mesh:.2f} s, {len(res.report)} issue(s); "
          "wrote " + ", ".join(map(str, out.files.values())))
    return 0
