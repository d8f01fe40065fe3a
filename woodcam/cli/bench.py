"""``woodcam bench run | report``: seed 000's Table 1 on many synthetic blocks, on an engine.

Registered by :mod:`woodcam.cli` through :func:`register`.
"""

from __future__ import annotations

from pathlib import Path

from .options import add_input, add_engine_options, add_out_option, engine_options


def register(subparsers) -> None:
    """Add ``bench run`` and ``bench report``."""
    p = subparsers.add_parser(
        "bench", help="benchmark the ring fitters on many synthetic blocks (Table 1 with "
        "confidence intervals)")
    sub = p.add_subparsers(dest="bench_command", required=True, metavar="{run,report}")

    r = sub.add_parser("run", help="fit and score N synthetic blocks, one record per block "
                       "(resumable: run it again to finish a killed run)",
                       description="Block i of seed S is drawn from rng([S, i]) alone: half clear "
                       "(knot-free logs, four sawing patterns), half cut through a knot; 50 mm "
                       "cubes, rings 2-5 mm; every method fitted from all six faces (full) and "
                       "from front, top, left (partial), scored on seven interior cut planes. "
                       "About 40 CPU-s per block with the three methods.")
    r.add_argument("--blocks", type=int, required=True, metavar="N", help="number of blocks")
    r.add_argument("--seed", type=int, metavar="N", default=0, help="seed of the block set (default 0)")
    r.add_argument("--methods", default="rbf,radial,neural",
                   help="comma-separated fitting methods (default rbf,radial,neural)")
    add_out_option(r, "the run: run.json and records/ (rerun to resume)")
    r.add_argument("--knotted-fraction", type=float, default=None, metavar="F",
                   help="share of knotted blocks in [0, 1] (default 0.5)")
    r.add_argument("--face-px", type=int, default=None, metavar="PX",
                   help="pixels along a face side (default 256, 5.12 px/mm on 50 mm)")
    r.add_argument("--jitter-mm", type=float, default=None, metavar="MM",
                   help="std of the traced rings' displacement in mm (default 0: exact traces)")
    r.add_argument("--dropout", type=float, default=None, metavar="F",
                   help="share of traced ring length missing, in [0, 1] (default 0)")
    r.add_argument("--retries", type=int, metavar="N", default=2, help="extra attempts of a failing block (default 2)")
    r.add_argument("--quiet", action="store_true", help="no progress bar")
    add_engine_options(r)
    r.set_defaults(func=_run)

    t = sub.add_parser("report", help="Table-1 figures with bootstrap intervals, paired tests, "
                       "worst blocks and a gallery of their cut planes",
                       description="Reads a run folder; writes report.md, report.json, table1.png "
                       "and gallery/ (worst blocks and sample faces, regenerated from the seed).")
    add_input(t, "run_dir", kind="folder", type=Path, help="a folder written by `woodcam bench run`")
    add_out_option(t, "report.md, report.json, table1.png and gallery/")
    t.add_argument("--gallery", type=int, default=3, metavar="N",
                   help="worst blocks to redraw (default 3; each is refitted, ~40 CPU-s)")
    t.add_argument("--thumbnails", type=int, default=2, metavar="N",
                   help="sample blocks of each kind to draw (default 2)")
    t.add_argument("--quiet", action="store_true", help="no progress bar")
    t.set_defaults(func=_report)


def _run(args) -> int:
    from ..benchmark import run_bench
    from .fit import METHODS
    from .options import comma_names

    # read as fit's and eval's --methods are: a name that is no method was the library's
    # "methods must be ...; got 'bogus'" (exit 1, naming no option)
    methods = None if args.methods is None else comma_names(args.methods, "--methods", METHODS)
    settings = {"methods": methods, "knotted_fraction": args.knotted_fraction,
                "face_px": args.face_px, "trace_jitter_mm": args.jitter_mm,
                "trace_dropout": args.dropout}
    s = run_bench(args.out, args.blocks, args.seed, {k: v for k, v in settings.items() if v is not None},
                  retries=args.retries, progress=not args.quiet, **engine_options(args))
    print(s.line())
    from . import EXIT_CHECKS

    return 0 if s.failed == 0 else EXIT_CHECKS  # some blocks failed: see their records


def _report(args) -> int:
    from ..benchmark import bench_report

    s = bench_report(args.run_dir, args.out, gallery=args.gallery, thumbnails=args.thumbnails,
                     progress=not args.quiet)
    full = s["table"][s["face_sets"][0]]["all"]
    print(f"{s['blocks']} blocks ({s['clear']} clear, {s['knotted']} knotted); "
          f"{s['face_sets'][0]} same year <= 1 mm: " + ", ".join(
              f"{m} {v['matched_1'][0]:.1f} % [{v['matched_1'][1]:.1f}, {v['matched_1'][2]:.1f}]"
              for m, v in full.items()) + f"; wrote {args.out / 'report.md'}")
    return 0
