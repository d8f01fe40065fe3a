"""`woodcam log ...`: sections through knotted logs and log-file conversion (CLI glue only).

Registered by :mod:`woodcam.cli` through :func:`register`; the parser sets ``func=run``.

    woodcam log render [LOG_FILE | --real | --maps DIR] --out DIR [options]
    woodcam log maps   [LOG_FILE | --real] --out DIR        # write the seed's image maps
    woodcam log export --real --out FILE.json               # write a woodcam log file
"""

from __future__ import annotations

from pathlib import Path

from ..errors import UsageError, WoodcamError
from .options import add_input, SPECIES_HELP, add_knot_options, add_out_option, knot_shading, species_type


def register(subparsers) -> None:
    """Add the ``log`` command (with ``render``, ``maps``, ``export``) to ``subparsers``."""
    p = subparsers.add_parser("log", help="knotted logs: render sections, convert log files")
    # named by its choices, as block's and bench's: 'woodcam log' said "required: log_command"
    sub = p.add_subparsers(dest="log_command", required=True, metavar="{render,maps,export}")

    def source(sp):
        add_input(sp, "log_file", kind="file", nargs="?", help="woodcam log file (JSON, mm)")
        sp.add_argument("--real", action="store_true",
                        help="the CT-measured spruce log Gran_1 of the shared data")
        add_input(sp, "--maps", kind="folder", metavar="DIR",
                        help="a folder of seed image maps (stem_map.png, knot_*_map.png, ...)")

    r = sub.add_parser("render", help="PNG sections: a tangential board and an end-grain disc")
    source(r)
    add_out_option(r, "one PNG per section")
    r.add_argument("--ring-width", type=float, default=2.0, help="mm per year (default 2)")
    r.add_argument("--px-per-mm", type=float, default=2.0, help="resolution in pixels per mm (default 2)")
    r.add_argument("--supersample", type=int, metavar="N", default=2,
                   help="samples per pixel side, averaged (default 2; knot rings alias)")
    r.add_argument("--board", nargs=3, type=float, metavar=("Z_MM", "AZIMUTH_DEG", "OFFSET_MM"),
                   help="tangential board: centre height along the log (mm), facing azimuth "
                        "(degrees) and distance from the pith (mm) (default: the board through the "
                        "most knots, 60 mm from the pith or 0.6 of a thinner log's smallest radius, "
                        "600 mm long or a shorter log's length)")
    r.add_argument("--disc", type=float, metavar="Z_MM",
                   help="height along the log of the end-grain disc, mm (default: the log's biggest "
                   "whorl, where most knots leave the pith; the middle of a log without knots)")
    r.add_argument("--radial", nargs=2, type=float, metavar=("Z_MM", "AZIMUTH_DEG"),
                   help="also a quarter-sawn section through the pith at height Z_MM (mm) and azimuth "
                   "AZIMUTH_DEG (degrees); knots show as spikes (default: none)")
    r.add_argument("--k-stem", type=float, default=1.5,
                   help="smoothness exponent k of the rings' smooth minimum outside knots, a number in "
                   "(0, 1000], no unit; low: wide distortion round a knot (seed 003 sec. 4.2.1; default 1.5)")
    r.add_argument("--k-knot", type=float, default=5.0,
                   help="the same inside knots, in (0, 1000]; high: a crisp knot edge (default 5)")
    add_knot_options(r)
    r.add_argument("--species", default="spruce", type=species_type,
                   help=SPECIES_HELP + " (default spruce, the real log's)")
    r.add_argument("--outline-mm", type=float, default=1.0,
                   help="dead-knot outline thickness (mm)")
    r.set_defaults(func=run)

    m = sub.add_parser("maps", help="write the seed's image maps of a log")
    source(m)
    add_out_option(m, "the seed's image maps (PNG)")
    m.set_defaults(func=run)

    e = sub.add_parser("export", help="write a log as a woodcam log file (JSON)")
    source(e)
    add_out_option(e, "the woodcam log file", suffixes=(".json",))
    e.set_defaults(func=run)


def _load(args):
    from ..logs.io import gran1_folder, read_gran1, read_log
    from ..logs.maps import read_maps

    given = [x for x in (args.log_file, args.real or None, args.maps) if x]
    if len(given) != 1:
        raise UsageError("give exactly one log: a LOG_FILE, --real or --maps DIR; got "
                           f"{len(given)}")
    if args.real:
        return read_gran1(gran1_folder("or give a LOG_FILE or --maps DIR instead of --real"))
    if args.maps:
        return read_maps(args.maps)
    return read_log(args.log_file)


def run(args) -> int:
    """Run ``woodcam log <command>``; prints "wrote PATH" for each file written, returns the exit code."""
    import numpy as np

    log = _load(args)
    out = Path(args.out)
    if args.log_command == "export":
        from ..logs.io import write_log

        print(f"wrote {write_log(log, out)}")  # as every command says what it wrote
        return 0
    if args.log_command == "maps":
        from ..logs.maps import write_maps

        for path in write_maps(log, out).values():  # a line a file, as render and export say them
            print(f"wrote {path}")
        return 0
    from ..fields.knots import KnotParams, KnottedLogField
    from ..logs import render as lr

    params = KnotParams(k_stem=args.k_stem, k_knot=args.k_knot, outline_mm=args.outline_mm)
    knots = knot_shading(args)
    field = KnottedLogField(log, ring_width_mm=args.ring_width, params=params)
    secs = lr.default_sections(log, px_per_mm=args.px_per_mm)
    try:  # a --board, --disc or --radial height (or offset) out of the log's range: a wrong command
        # line, known once the log is read (it exited 1, as a failure of the work)
        if args.board:
            z, az, off = args.board
            secs[0] = lr.tangential_board(log, z, np.radians(az), off, px_per_mm=args.px_per_mm)
        if args.disc is not None:
            secs[1] = lr.end_grain_disc(log, args.disc, px_per_mm=args.px_per_mm)
        if args.radial:
            z, az = args.radial
            secs.append(lr.radial_section(log, z, np.radians(az), px_per_mm=args.px_per_mm))
    except WoodcamError as err:
        raise UsageError(f"{log.name}: {err}") from err
    from .._progress import progress_bar, write

    for s in progress_bar(secs, desc="rendering sections", unit="section"):  # ~9 s each at 8 px/mm
        img = lr.render_section(field, s, supersample=args.supersample, species=args.species,
                                knots=knots)
        # each as it lands (~9 s apart), "wrote PATH" as export, maps and every command say it
        write(f"wrote {lr.save_png(img, out / f'{log.name}_{s.name}.png')}")
    return 0
