"""``woodcam gcode``: G-code + tools -> simulated stock -> baked wood preview (GLB, PNG).

Registered by :mod:`woodcam.cli` through :func:`register`; the parser's ``func`` is :func:`run`.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

from ..errors import UsageError, WoodcamError
from ..tolerances import IN_BLOCK_RTOL
from ..units import MM_PER_UNIT, fmt_length, fmt_volume
from .options import (add_input, part_suffixes, output_refused_at_the_door, BLOCK_SPEC_HELP, add_bake_options,
                      add_camera_option, add_max_triangles_option, add_out_option, add_units_option,
                      allow_negative_values, as_typed, camera_of, drop_earlier_output, remove_stale_outputs, sizes_type,
                      add_size_option, stock_options, vector_type)

_EXAMPLES = """\
examples:
  woodcam gcode toolpaths/vcarve_text.nc --tool vbit:60:12 --block builtin:flat-sawn \\
      --out out/vcarve_text.glb --screenshot out/vcarve_text.png
  woodcam gcode toolpaths/pocket_islands.nc --tools toolpaths/tools.toml \\
      --block builtin:quarter-sawn --out out/pocket.glb
  woodcam gcode prog.nc --tool 1=flat:6.35 --tool 2=ball:3 --block builtin:rift --out out/p.glb

Tool specs (diameters, corner radii and tips in --units, default mm; angles and the taper in
degrees): flat:D, ball:D, bull:D:CORNER_R, vbit:ANGLE:D, snub:ANGLE:D:TIP (engraving cone with a
flat tip), chamfer:ANGLE:D:TIP, taperball:D:TIP:TAPER (taper per side); prefix N= to give the
tool number of the program (T N M6). --tools reads a TOML tool table or a CAMotics JSON tool
table (its lengths in its own units). Work zero defaults to the stock's top-front-left corner
(G-code z = 0 on the top face).
"""


def register(subparsers) -> None:
    """Add the ``gcode`` subcommand to ``subparsers`` (an argparse sub-parsers action)."""
    p = subparsers.add_parser(
        "gcode", help="simulate a G-code program on a block and bake the carved wood",
        description="Read a 3-axis G-code program, remove the swept tools from the block on a "
        "height field, mesh the remaining stock and bake its wood texture.",
        epilog=_EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_input(p, "program", kind="file", type=Path, nargs="+",
                   help="G-code file(s) (.nc, .gcode, .ngc, .tap); several files of one job "
                   "(e.g. roughing then finishing) are simulated in sequence on the same stock")
    add_input(p, "--block", kind="block", required=True, help=BLOCK_SPEC_HELP)
    add_out_option(p, "the carved stock; beside it OUT.obj/.mtl, OUT_texture.png and, "
                   "with --screenshot, OUT_view.png", suffixes=(".glb",))
    p.add_argument("--tool", action="append", default=[], metavar="[N=]SPEC",
                   help="a tool, e.g. flat:6.35, ball:3, bull:6:1, vbit:60:12, 2=ball:3 "
                   "(repeatable; without N= the tools go to the program's tool numbers in "
                   "order of first use, across the files of a job); the reach for the flute/shank/holder checks as "
                   "flat:6:flute=22:shank=6:stickout=30:holder=35 (lengths in --units, "
                   "default mm). Default: none; give --tool or --tools")
    add_input(p, "--tools", kind="file", type=Path, default=None, metavar="TOML",
                   help="tool table file: TOML ([tools.N] type/diameter_mm/...) or a CAMotics "
                   "JSON tool table (.json)")
    # --cell-size, not --resolution: elsewhere --resolution is a cell COUNT (issue 17); the old
    # spelling still parses
    p.add_argument("--cell-size", "--resolution", dest="cell_size", type=float, default=0.1,
                   metavar="LEN", help="height-field cell size, a length in --units (default "
                   "0.1 mm; the old spelling --resolution still works)")
    p.add_argument("--work-offset", default=None, metavar="X,Y,Z", type=vector_type("--work-offset"),
                   help="block-frame position of G-code zero in --units (default 0,0,H: "
                   "top-front-left); negative values as --work-offset -14,5,3")
    p.add_argument("--start", default=None, metavar="X,Y,Z", type=vector_type("--start"),
                   help="machine position (G-code frame, in --units) before the first move, also the "
                   "G28/G30 home (default 0,0,10: 10 mm over the work zero)")
    p.add_argument("--machine-zero", default=None, metavar="X,Y,Z",
                   type=vector_type("--machine-zero", example="0,0,80"),
                   help="where the machine's own origin (G53 coordinates) lies in the G-code "
                   "frame (the frame of --start), in --units: LinuxCNC's G54 offset negated, "
                   "e.g. 0,0,80 when the work zero is 80 mm below the machine's Z home, so "
                   "'G53 G0 Z-5' goes to Z75. Default: not known; a G53 Z move (the posts' "
                   "'G53 G0 Z-5' retract) is then taken as a retract to the --start height "
                   "and G53 X/Y as if machine zero were G-code zero, each with a warning "
                   "naming the lines")
    p.add_argument("--dialect", choices=("linuxcnc", "grbl", "fanuc"), default="linuxcnc",
                   help="whose meaning the program has (default linuxcnc): linuxcnc and "
                   "fanuc run M98/M99 subprograms; grbl has no parameters, O-words or "
                   "subprograms; fanuc starts in G0, needs no M2, reads M98 P51000 as O1000 "
                   "five times and takes an O1000 label before or after its call")
    p.add_argument("--interpreter", choices=("woodcam", "linuxcnc"), default="woodcam",
                   help="read the program with woodcam's interpreter (default) or with "
                   "LinuxCNC's own (needs Debian's linuxcnc-uspace)")
    p.add_argument("--stock", default=None, metavar="WxDxH", type=sizes_type("--stock"),
                   help="stock size in --units cut from the block's wood (default: the block's "
                   "own size), e.g. 167x208x25; it must lie in the block (with --stock-origin)")
    p.add_argument("--stock-origin", default=None, metavar="X,Y,Z",
                   type=vector_type("--stock-origin"),
                   help="block-frame position (in --units) of the --stock's corner in the block's wood "
                   "(default 0,0,0)")
    p.add_argument("--until-line", type=int, default=None, metavar="N",
                   help="simulate the (last) program only as it runs up to and including line N "
                   "of its main program (default: all): a subroutine call (o100 call, M98) on a "
                   "line up to N brings all its moves, one after N none, wherever its body lies; "
                   "a line inside a body moves nothing")
    p.add_argument("--rapid-rate", type=float, default=5000.0, metavar="RATE",
                   help="machine rapid rate for the machining time estimate, --units per minute "
                   "(default 5000 mm/min)")
    add_camera_option(p, "; of the --screenshot, drawn from the baked texture without VTK: iso "
                      "and the sides with a cut plane, top without one. No bottom: the simulated "
                      "stock is a height field cut from above, its underside always the uncut face "
                      "(a through cut reaches Z = 0 but leaves no hole in it), so a bottom view "
                      "would show nothing of the job: through cuts show from the top and iso",
                      exclude=("bottom",))
    p.add_argument("--view", action="store_true",
                   help="after writing the files, open a window (needs a display) with the "
                   "stock, the toolpath and a slider that scrubs the simulation to any line "
                   "of the (last) program")
    p.add_argument("--no-overlay", action="store_true",
                   help="leave the toolpath (rapids red, feeds blue) out of the screenshot")
    add_input(p, "--part", kind="file", suffixes=part_suffixes, default=None, metavar="PART",
                   help="design part (STL/STEP/OBJ/GLB or a part script, block frame, mm): "
                   "report leftover and overcut volumes, gouges by line, and write a "
                   "deviation map (OUT with _deviation.png)")
    add_max_triangles_option(p, "the --part design")  # a mesh over it is simplified, said naming this option
    p.add_argument("--strict", action="store_true",
                   help="exit with status 3 when the reader or the simulation warned")
    p.add_argument("--mesh-tol", type=float, default=0.05, metavar="LEN",
                   help="merge nearly planar regions of the result mesh within this length in --units (default "
                   "0.05 mm: the 20,000-move raster's mesh shrinks from 2.0 M to 0.44 M "
                   "triangles, its volume moves by 0.0006 mm on average)")
    add_size_option(p)
    add_units_option(p, "gcode")
    add_bake_options(p)
    p.set_defaults(func=run)
    allow_negative_values(p)  # --work-offset -14,5,3



def _numbered_tools(args) -> dict:
    """The tools the command line numbers: the --tools table, then each --tool N=SPEC."""
    from ..toolpath.tools import load_tool_table
    from .options import parse_tool_option

    tools = dict(load_tool_table(args.tools)) if args.tools else {}
    for item in args.tool:  # read at the door already (options.check_values): a usage error there
        number, tool = parse_tool_option(item)
        if number is not None:
            tools[number] = tool
    return tools


def _unnumbered_diameters(args, program, diameters, text, earlier=()) -> dict:
    """The diameters (mm) of the tools without a number (--tool SPEC) by the tool numbers
    ``program`` gets them for (:func:`_tools_from_args`: the numbers it uses without a tool,
    in order; one tool alone is the tool of a program without a T word, tool 0), those not in
    ``diameters``; empty when the program says and prints nothing, where they would show
    (a DEBUG/PRINT of #5410, the loaded tool's diameter), unless LinuxCNC's interpreter reads
    its ``text`` and may read its tool table (its cutter compensation, G41/G42, offsets the
    path by the radius of the table's diameter: without it by none; a parameter such as
    #5410 in an expression: linuxcnc.may_read_tool_diameters), or when they do not fit
    (refused later, after its messages, by _tools_from_args). Not tool 0's: before the first
    M6 no tool is loaded and #5410 shows 0, as on LinuxCNC (interpreter.tool_entry_in_message)."""
    from ..toolpath.linuxcnc import may_read_tool_diameters
    from .options import parse_tool_option

    if not (program.messages or program.printed or (
            args.interpreter == "linuxcnc" and may_read_tool_diameters(text))) or all(
            parse_tool_option(item)[0] is not None for item in args.tool):
        return {}
    try:  # (``earlier``: the job's programs before it, whose tools come first)
        tools = _tools_from_args(args, [*earlier, program], more_to_come=True)
    except WoodcamError:
        return {}
    return {n: t.diameter_mm for n, t in tools.items() if n not in diameters and n != 0}


#: A --tool under this diameter (1/16 in) in a G20 program was likely typed in inches.
_INCH_TOOL_BELOW_MM = 1.6


def _warn_inch_sizes_read_as_mm(args, program, name: str) -> int:
    """Warn (and return 1) when ``program`` moves in inches (G20) and every ``--tool`` given
    is under 1.6 mm (1/16 in) across while ``--units`` is mm: the sizes were likely typed in
    the program's inches (``--tool flat:0.25`` read as 0.25 mm cut nothing to speak of, with no
    word); else 0. A --tools table says its own units (``diameter_mm``) and is not questioned."""
    from .options import parse_tool_option

    if args.units != "mm" or not args.tool or not program.inch.any():
        return 0
    if any(parse_tool_option(item)[1].diameter_mm >= _INCH_TOOL_BELOW_MM for item in args.tool):
        return 0
    first = int(program.line[program.inch][0])
    print(f"woodcam: warning: {name}: the program moves in inches (G20, from line {first}) but "
          f"every --tool is under {_INCH_TOOL_BELOW_MM} mm (1/16 in) across, read as mm "
          f"({', '.join(args.tool)}); if its sizes are inches, pass --units inch (it reads the "
          "--tool sizes and the other lengths typed in inches)", file=sys.stderr)
    return 1


def _warn_unused_numbered_tools(args, programs, tools: dict) -> int:
    """Warn, one line each, of the ``--tool N=SPEC`` whose number N no program of the job
    (``programs``, whole: --until-line does not cut a tool out of the job) calls; return how
    many. A mistyped number (``--tool 3=ball:3`` for the program's T2 with T2 also in a --tools
    table) was taken without a word, and the job cut with another tool. A --tools table's
    entries are not questioned: a shop's table lists every tool it has."""
    from .options import parse_tool_option

    called = {t for p in programs for t in p.tool.tolist()}
    if 0 in called and len(tools) == 1:  # a program that loads no tool: the only one (tool_lookup)
        called |= set(tools)
    used = ", ".join(f"T{t}" for t in sorted(called)) or "none"
    typed = {parse_tool_option(item)[0] for item in args.tool}
    # the number it was likely meant for: one the job calls that no --tool N= names yet
    meant = min(called - typed - {0}, default=min(called - {0}, default=0))
    n = 0
    for item in args.tool:
        number, _ = parse_tool_option(item)
        if number is None or number in called:
            continue
        spec = item.split("=", 1)[1]
        print(f"woodcam: warning: --tool {item}: the job never calls tool {number} (it uses "
              f"{used}), so this tool cuts nothing; if it is meant for one of those, give it that "
              f"number (e.g. --tool {meant}={spec}), else leave it out", file=sys.stderr)
        n += 1
    return n


def _tools_from_args(args, programs, *, more_to_come: bool = False) -> dict:
    """The tool table of the job's ``programs`` (one Program or the job's, in order): the
    numbered --tool/--tools entries, and the tools without a number on the tool numbers the
    job uses without a tool, in order of first use across its programs (a roughing file's T1,
    then a finishing file's T2: matched per file, '--tool flat:6 --tool ball:3' was '2 tools
    without numbers but the program uses 1'). ``more_to_come``: the programs are the first of
    the job, so more tools than numbers is no fault yet."""
    from .options import parse_tool_option

    programs = list(programs) if isinstance(programs, (list, tuple)) else [programs]
    tools = _numbered_tools(args)
    unnumbered = [tool for number, tool in map(parse_tool_option, args.tool) if number is None]
    if unnumbered:
        used = [t for t in dict.fromkeys(t for p in programs for t in p.tool.tolist())
                if t not in tools]
        if len(used) > 1 and 0 in used and all(p.tool_of_leading_rapids() is not None
                                               for p in programs if (p.tool == 0).any()):
            # T0 only rapids before the first M6 (Carbide Create's "G53 G0 Z-5", a G28): no tool
            # of its own; simulate gives those rapids the first tool loaded
            used.remove(0)
        if len(unnumbered) == 1 and len(used) <= 1:
            used = used or [0]
        if len(unnumbered) > len(used) and not more_to_come:
            typed = [item for item in args.tool if parse_tool_option(item)[0] is None]
            free = [n for n in range(1, 100000) if n not in tools and n not in used][:len(typed) - len(used)]
            example = " ".join(f"--tool {n}={item}" for n, item in zip([*used, *free], typed))
            raise WoodcamError(f"--tool: {len(unnumbered)} tools without numbers but the "
                               f"{'program uses' if len(programs) == 1 else 'programs use'} "
                               f"{len(used)} tool number(s) without a tool ({used}); each tool "
                               f"without a number takes the next of those; give numbers as N=SPEC, "
                               f"e.g. {example}, or leave out the tools "
                               f"{'it does' if len(programs) == 1 else 'they do'} not use")
        tools.update(zip(used, unnumbered))
    if not tools:
        raise WoodcamError("woodcam gcode: no tools given; pass --tool SPEC (e.g. --tool "
                           "flat:6.35) or --tools TABLE.toml")
    return tools


def run(args) -> int:
    """Run ``woodcam gcode``; prints the simulation report and what was written.

    Exit status 0, or 3 with ``--strict`` when the reader or the simulation warned."""
    import numpy as np

    from .._progress import StageBar, write
    from ..pipeline import check_outputs, preview_heightfield
    from ..stock import open_stock, resize_stock
    from ..toolpath.gcode import GcodeError, gcode_text, read_gcode
    from ..toolpath.simulate import simulate, tool_lookup

    if args.interpreter == "linuxcnc" and args.dialect != "linuxcnc":  # it was dropped without a word
        raise UsageError(f"--dialect must be linuxcnc with --interpreter linuxcnc (LinuxCNC's own interpreter "
                         f"reads LinuxCNC's G-code only); got --dialect {args.dialect}; leave out --interpreter "
                         f"to read the program as {args.dialect} does")
    if not args.tool and not args.tools:  # a usage error, before any program is read
        raise UsageError("woodcam gcode: no tools given; pass --tool SPEC (e.g. --tool flat:6.35) or "
                         "--tools TABLE.toml")
    with output_refused_at_the_door():  # the OBJ set beside the GLB, its view PNG
        check_outputs(args.out, obj=not args.no_obj, screenshot=args.screenshot or False)
    camera_of(args, bool(args.screenshot))  # a --camera without --screenshot warns before the work
    design = None
    if args.part:  # a missing or unreadable design part failed only after the whole simulation
        from .._atomic import check_output_path
        from ..cad import load_part

        with output_refused_at_the_door():
            check_output_path(_deviation_png(args.out), what="--out (its deviation PNG, with --part)")
        try:
            design = load_part(args.part, **({} if args.max_triangles is None
                                             else {"max_triangles": args.max_triangles}))
        except WoodcamError as err:
            raise WoodcamError(f"--part: {err}") from None
    if args.view:
        from ..view.scrub import check_display

        check_display()
    # The programs and their tools first: a missing program, a program without a cut or a bad
    # --tool/--tools was refused only after the block was opened (a photographed block's fit,
    # 20-30 s the first time).
    n_warn = 0
    programs = []  # (path, program as simulated, the whole program, seconds to read, tools)
    # what a (DEBUG,...) shows for #5410, the loaded tool's diameter in the machine's table
    diameters = {n: t.diameter_mm for n, t in _numbered_tools(args).items()}
    for k, path in enumerate(args.program):
        t0 = time.perf_counter()
        # read once: a program read again (below) is the same bytes, not the file as it is then
        text = gcode_text(path)
        try:
            program = read_gcode(text, source=str(path), start_mm=args.start,
                                 dialect=args.dialect, interpreter=args.interpreter,
                                 machine_zero_mm=args.machine_zero,
                                 tool_diameters_mm=diameters)
            more = _unnumbered_diameters(args, program, diameters, text,
                                         [q[2] for q in programs])
            if more:  # what its messages show for #5410 and LinuxCNC's G41/G42 offset: read
                # again with the tools it is given
                program = read_gcode(text, source=str(path), start_mm=args.start,
                                     dialect=args.dialect, interpreter=args.interpreter,
                                     machine_zero_mm=args.machine_zero,
                                     tool_diameters_mm={**diameters, **more})
        except GcodeError as err:  # which of the programs: "G-code line 5" alone does not say
            raise GcodeError(err.line, err.word, err.rule, err.fix, source=str(path)) from None
        t_read = time.perf_counter() - t0
        full = program  # the whole last program, for the window's slider
        if args.until_line is not None and k == len(args.program) - 1:
            program = program.until_line(args.until_line)
        for w in program.warnings:
            print(f"woodcam: warning: {path.name} {w}", file=sys.stderr)
        n_warn += len(program.warnings)
        # what the machine's screen would show the operator as the program runs: information,
        # not a warning (--strict does not count them)
        for m in program.messages:
            print(f"woodcam: message: {path.name} {m}", file=sys.stderr)
        # (PRINT,...): what LinuxCNC writes to the terminal it runs from, for the program's
        # author, never shown to the operator: its own label, so it is not read as a message
        for m in program.printed:
            print(f"woodcam: print: {path.name} {m}", file=sys.stderr)
        if not (program.kind == 1).any() and args.until_line is None:
            raise WoodcamError(f"woodcam gcode: {path} has no cutting move (G1/G2/G3 or a "
                               "drilling cycle); nothing to simulate. Check that it is the "
                               "program you meant")
        programs.append((path, program, full, t_read))
    # the tools without a number go to the whole job's tool numbers: cut short by --until-line
    # before its T2 M6, 'flat:6 ball:3' was '2 tools without numbers but the program uses 1',
    # so the run's own command line failed with the option added
    tools = _tools_from_args(args, [q[2] for q in programs])
    n_warn += _warn_unused_numbered_tools(args, [q[2] for q in programs], tools)
    for k, (path, program, full, t_read) in enumerate(programs):
        # a tool number without a tool was refused by simulate, after the block was opened and
        # the programs before it simulated, naming no file
        used = tool_lookup(program, tools, who=f"woodcam gcode {path.name}")
        # a cut narrower than two cells can fall between the cell centres and vanish (a 0.4 mm
        # slot on a 0.5 mm grid removed nothing, with no word)
        for t, tool in sorted(used.items()):
            if args.cell_size > tool.diameter_mm / 2:
                print(f"woodcam: warning: {path.name}: the grid ({fmt_length(args.cell_size, args.units)}) "
                      f"is coarser than half the diameter of T{t} ({fmt_length(tool.diameter_mm, args.units)}): "
                      f"its cuts can fall between the cell centres and vanish; use --cell-size "
                      f"{tool.diameter_mm / 2 / MM_PER_UNIT[args.units]:.2g} or finer", file=sys.stderr)
                n_warn += 1
        n_warn += _warn_inch_sizes_read_as_mm(args, program, path.name)
        step = program.stepover_mm(spacing_mm=args.cell_size)
        if step is not None and args.cell_size > step / 2:
            print(f"woodcam: warning: {path.name}: the grid ({fmt_length(args.cell_size, args.units)}) "
                  f"is coarser than half the step-over ({fmt_length(step, args.units)}): expect "
                  f"aliasing waves; use --cell-size {step / 2 / MM_PER_UNIT[args.units]:.2g} or finer",
                  file=sys.stderr)
            n_warn += 1
        programs[k] = (path, program, full, t_read, tools)
    # one bar for the whole run, as bake's: opening a photographed block can fit its rings
    # (20-30 s, once), the simulation draws its own bar below it, and the mesh, bake and view
    # took 5-10 s more with none
    stages = ["open block", *(f"simulate {Path(p).name}" for p in args.program),
              *(["deviation"] if design is not None else []), "mesh and bake",
              *(["render"] if args.screenshot else [])]
    bar = StageBar(stages, desc=f"gcode {Path(args.out).stem}", leave=False)
    try:
        with bar.stage("open block"):
            stock = open_stock(args.block, **stock_options(args))
            if args.stock or args.stock_origin:
                _check_stock_in_block(args, stock)
                stock = resize_stock(stock, args.stock or stock.size_mm, args.stock_origin or (0, 0, 0))
        offset = list(args.work_offset) if args.work_offset else None
        hm = None
        meta_programs, last = [], None
        hm_before = None  # the stock the last program starts from (the window's slider)
        for path, program, full, t_read, tools in programs:
            with bar.stage(f"simulate {Path(path).name}"):
                hm_before = hm
                res = simulate(program, tools, stock.size_mm, resolution_mm=args.cell_size,
                               work_offset_mm=offset, progress=True, initial_heightmap=hm,
                               track_lines=bool(args.part))
                hm = res.heightmap
                for issue in res.report:
                    write(f"woodcam: warning: {path.name} {issue}", file=sys.stderr)
                n_warn += len(res.report)
                times = program.machining_time_s(args.rapid_rate)
                s = res.stats
                write(f"{path.name}: {len(program)} moves read in {t_read:.2f} s, simulated on "
                      f"{s['grid'][1]}x{s['grid'][0]} cells in {s['wall_s']:.2f} s "
                      f"({s['moves_per_s']:.0f} moves/s), removed {fmt_volume(res.removed_volume_mm3, args.units)}, "
                      f"{len(res.report)} issue(s); machining time " + (", ".join(
                          f"T{t}: {fmt_hms(f + r)} ({fmt_hms(f)} feeding)" for t, (f, r) in times.items())
                          or f"{fmt_hms(0)} (no moves)"))  # (--until-line before the first move)
                # resolved, as the block spec (_specs.absolute_spec): the review page of the GLB, opened
                # from another folder, names the program that cut it (as typed it was relative to a
                # working folder the GLB does not record)
                meta_programs.append({"gcode": str(Path(path).resolve()),
                                      "tools": {str(t): v.spec() for t, v in sorted(tools.items())},
                                      "machining_time_s": sum(f + r for f, r in times.values()),
                                      "warnings": _issue_spots(program, res.report, stock.size_mm, offset, path.name)})
                last = (program, res)
        program, res = last
        if design is not None:
            with bar.stage("deviation"):
                from ..toolpath.deviation import deviation, deviation_png, fmt_depth

                dev = deviation(res, design)
                png = _deviation_png(args.out)
                write(f"deviation from {Path(args.part).name}: {dev.summary(units=args.units)}; "
                      f"map {png} (in mm)")
                for ln, d in dev.gouges[:12]:
                    write(f"woodcam: warning: line {ln}: gouge: cuts {fmt_depth(d, args.units)} "
                          "into the part", file=sys.stderr)
                n_warn += len(dev.gouges)
        meta = {"gcode": [m["gcode"] for m in meta_programs] if len(meta_programs) > 1
                else meta_programs[0]["gcode"],
                # the review page's G-code hotspots (it read this key, which nothing wrote)
                "warnings": [w for m in meta_programs for w in m["warnings"]][:200],
                "tools": {t: v for m in meta_programs for t, v in m["tools"].items()},
                "resolution_mm": float(np.mean(res.cell_mm)),
                "machining_time_s": sum(m["machining_time_s"] for m in meta_programs)}
        if args.until_line is not None:
            meta["until_line"] = args.until_line
        t1 = time.perf_counter()
        with bar.stage("mesh and bake"):
            out = preview_heightfield(res.heightmap, stock, args.out, texels_per_mm=args.texels_per_mm,
                                      flat_tol_mm=args.mesh_tol, obj=not args.no_obj, metadata=meta,
                                      obj_units=args.obj_units, obj_up=args.obj_up,
                                      max_atlas_px=args.max_atlas)
        t_bake = time.perf_counter() - t1
        if design is not None:
            # drawn once the GLB set is in place: written before it, a Ctrl-C while meshing and
            # baking left this cut's map beside the earlier run's GLB; the earlier run's map goes
            # first, or a Ctrl-C while drawing left it beside this run's GLB
            drop_earlier_output(png, Path(args.out))
            deviation_png(dev, png, title=f"{Path(args.part).name}:\n{dev.summary(gouges=False)}"
                          + (f", {len(dev.gouges)} gouging lines" if dev.gouges else ""))
            out.files["deviation"] = png
        if args.screenshot:
            with bar.stage("render"):
                _screenshot(args, stock, program, offset, out, res.heightmap)
    finally:
        bar.close()
    remove_stale_outputs(args.out, out.files, inputs=[*args.program, args.part])
    print(f"meshed and baked {out.triangles} triangles in {t_bake:.2f} s; wrote "
          + ", ".join(map(str, out.files.values())))
    if args.view:
        from ..view.scrub import gcode_window

        gcode_window(full, tools, stock, work_offset_mm=offset, resolution_mm=args.cell_size,
                     initial_heightmap=hm_before, until_line=args.until_line,
                     heightmap=res.heightmap)  # the stock it opens on: simulated already
    return 3 if args.strict and n_warn else 0


def _check_stock_in_block(args, block) -> None:
    """Refuse a ``--stock`` / ``--stock-origin`` that runs past ``block`` (the opened Stock,
    mm): the stock is wood of the block, ``[0,W] x [0,D] x [0,H]`` of its frame, not of the
    field outside it (for a fitted or grown block an extrapolation, wood the user does not
    have), as parquetry's leaves (:func:`woodcam.parquetry.job.check_leaves_in_block`). A usage
    error (exit 2) naming the sizes in ``--units`` and the fix."""
    from .._specs import parse_spec
    from ..units import fmt_point, fmt_size

    have = [float(v) for v in block.size_mm]
    size = [float(v) for v in (args.stock or have)]
    origin = [float(v) for v in (args.stock_origin or (0.0, 0.0, 0.0))]
    far = [o + s for o, s in zip(origin, size)]
    tol = IN_BLOCK_RTOL * max(have)
    if all(o >= -tol for o in origin) and all(f <= h + tol for f, h in zip(far, have)):
        return
    u = args.units
    k = MM_PER_UNIT[u]

    def typed(values, sep):  # as the option is typed: in --units, no unit symbol
        return sep.join(f"{v / k:.4g}" for v in values)

    fits = [h - max(o, 0.0) for h, o in zip(have, origin)]
    fix = (f"--stock {typed([min(s, f) for s, f in zip(size, fits)], 'x')} or smaller"
           + (" at that corner" if any(o > tol for o in origin) else "")
           if all(f > tol for f in fits) else "a --stock-origin inside the block")
    if any(o < -tol for o in origin):
        fix = f"--stock-origin {typed([max(o, 0.0) for o in origin], ',')} (in the block) and " + fix
    parsed = parse_spec(block.spec)
    if parsed.kind in ("builtin", "log") and not parsed.ops and all(o >= -tol for o in origin):
        base = parsed.base if parsed.size_mm is None else parsed.base[:parsed.base.rfind(":")]
        fix += f", or a block that holds it: --block {base}:{typed([max(h, f) for h, f in zip(have, far)], 'x')}"
    raise UsageError(
        f"--stock {fmt_size(size, u)} at --stock-origin {fmt_point(origin, u)} runs from "
        f"{fmt_point(origin, u)} to {fmt_point(far, u)}, past the {fmt_size(have, u)} block "
        f"{as_typed(args, 'block')} (its wood is (0, 0, 0) to {fmt_point(have, u)}): the stock must be wood of "
        f"the block, not of the field outside it; give {fix}")


def _issue_spots(program, issues, size_mm, offset, name: str) -> list[dict]:
    """The simulation's issues as ``{"message", "line", "at_mm"}``, block frame: where the
    simulation says the problem first happens (``Issue.at_mm``), else the middle of the first
    move of the issue's line (the work offset as simulate applies it)."""
    import dataclasses

    import numpy as np

    from ..units import filed

    off = np.array([0.0, 0.0, float(size_mm[2])]) if offset is None else np.asarray(offset, float)
    lines = np.asarray(program.line)
    mids = 0.5 * (np.asarray(program.start_mm) + np.asarray(program.end_mm)) + off
    out = []
    for issue in issues:
        at = np.flatnonzero(lines == issue.line)
        if issue.at_mm is not None or len(at):
            spot = list(issue.at_mm) if issue.at_mm is not None else mids[at[0]].tolist()
            # the file stays in mm under --units inch (the terminal's copy follows it)
            text = str(dataclasses.replace(issue, message=filed(issue.message)))
            out.append({"message": f"{name} {text}", "line": int(issue.line), "at_mm": spot})
    return out


def fmt_hms(seconds: float) -> str:
    """Seconds -> ``"h:mm:ss"`` (``"unbounded"`` for inf/nan), for machining times."""
    if not math.isfinite(seconds):  # a program that never ends (its own numbers: no traceback)
        return "unbounded"
    m, s = divmod(int(round(seconds)), 60)
    h, m = divmod(m, 60)
    return f"{h}:{m:02d}:{s:02d}"


def _deviation_png(out) -> Path:
    """Where ``--part``'s deviation map goes: OUT with ``_deviation.png``."""
    return Path(out).with_name(Path(out).stem + "_deviation.png")


def _screenshot(args, stock, program, offset, made, heightmap) -> None:
    """Render the stock with the toolpath over it (rapids red, feeds blue), block frame, from
    the preview's atlas (``made``: its :class:`PartPreview`), without VTK: the top view
    orthographic with numpy, the other views in perspective with the cut plane
    (:func:`woodcam.view.stockview.stock_view`)."""
    import numpy as np

    from ..pipeline import screenshot_path

    out = Path(args.out)
    png = screenshot_path(args.screenshot, out)
    drop_earlier_output(png, out)
    overlay = None
    if not args.no_overlay and len(program):
        off = np.asarray(offset if offset else (0.0, 0.0, stock.size_mm[2]), float)
        seg = np.stack([program.start_mm + off, program.end_mm + off], axis=1)
        feed = program.kind == 1
        overlay = [(seg[~feed], "red", 1.0), (seg[feed], "royalblue", 1.0)]
    camera = camera_of(args)
    if camera == "top":
        # seen from +Z the stock is its atlas's top chart: drawn with numpy
        from ..view.topview import write_top_view

        write_top_view(png, heightmap, stock.size_mm, made.chart_texels("top"), overlay=overlay)
    else:
        from ..view.stockview import write_stock_view

        write_stock_view(png, heightmap, stock.size_mm, made.texture, made.charts,
                         wood=stock.wood, camera=camera, overlay=overlay)
    made.files["png"] = png
