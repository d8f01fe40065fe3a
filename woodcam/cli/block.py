"""``woodcam block ...``: synthesise a benchmark set of blocks, draw a block as an unfolded cross.

Registered by :mod:`woodcam.cli` through :func:`register`; each sub-parser's ``func`` is :func:`run`.
"""

from __future__ import annotations

from pathlib import Path

from .options import (add_block_argument, add_check_layout_option, add_engine_options, add_out_option,
                      add_size_option, allow_negative_values, engine_options, engine_requested, open_block,
                      option_range, report_layout)


def _size_range(text: str) -> tuple[float, float]:
    """argparse ``type`` of ``--size-range-mm``: ``MIN,MAX`` in mm, finite, 0 < MIN <= MAX <=
    :data:`~woodcam.limits.MAX_BLOCK_SIZE_MM`, else a usage error (exit 2). It was read in the
    command (exit 1: '80,30', 'nan,30'; '-1,30' was argparse's 'expected one argument')."""
    import argparse
    import math

    from ..limits import limit

    try:
        lo, hi = (float(v) for v in text.split(","))
    except ValueError:
        lo = hi = math.nan
    cap = limit("MAX_BLOCK_SIZE_MM")
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo <= hi <= cap):
        raise argparse.ArgumentTypeError(f"--size-range-mm takes MIN,MAX in mm with 0 < MIN <= MAX <= "
                                         f"{cap:g} (raise it with WOODCAM_MAX_BLOCK_SIZE_MM=N), e.g. 30,80; "
                                         f"got {text!r}")
    return lo, hi


def register(subparsers) -> None:
    """Add the ``block`` command (with ``synth``, ``show`` and ``from-photos``) to an argparse sub-parser set."""
    p = subparsers.add_parser("block", help="synthesise or show blocks (six face photos + rings)")
    p.set_defaults(func=run)          # woodcam.cli dispatches on args.func
    sub = p.add_subparsers(dest="block_command", required=True, metavar="{synth,show,from-photos}")

    s = sub.add_parser("synth", help="write a reproducible set of synthetic blocks")
    # the ranges said in the help, as the other options' (a fraction, a side in mm) are
    s.add_argument("--count", type=int, metavar="N", required=True,
                   help=f"number of blocks, {option_range('count', 'block')}")
    s.add_argument("--seed", type=int, metavar="N", default=0,
                   help=f"random seed (same seed, same set), an integer {option_range('seed')}")
    add_out_option(s, "one block sub-folder per block and index.json")
    s.add_argument("--face-px", type=int, metavar="PX", default=512,
                   help=f"pixels along the largest face side, {option_range('face_px')}")
    s.add_argument("--quiet", action="store_true", help="no progress bar")
    s.add_argument("--jitter-mm", type=float, default=0.0,
                   help="std (mm) of the traces' perpendicular jitter, smoothed over 1 mm (default 0)")
    s.add_argument("--dropout", type=float, default=0.0,
                   help="fraction of trace length removed, in pieces of --dropout-chunk-mm (default 0)")
    s.add_argument("--dropout-chunk-mm", type=float, default=10.0,
                   help="length (mm) of each removed trace piece (default 10)")
    s.add_argument("--mislabel", type=float, default=0.0,
                   help="fraction of traces whose year is off by +-1 (default 0)")
    s.add_argument("--ring-maps-only", action="store_true",
                   help="no traces: faces carry ring maps only (unlabelled rings, as Mokume's cubes)")
    s.add_argument("--knotted-fraction", type=float, default=0.5,
                   help="share of blocks cut from knotted logs, each with a knot crossing it (default 0.5)")
    s.add_argument("--size-range-mm", default="30,80", type=_size_range, metavar="MIN,MAX",
                   help="MIN,MAX block side in mm, each side uniform in it (default 30,80)")
    add_engine_options(s)
    allow_negative_values(s)  # --size-range-mm -1,30: the range's words, not 'expected one argument'

    v = sub.add_parser("show", help="draw a block's faces as one unfolded-cross PNG")
    add_block_argument(v, option=False)
    add_out_option(v, "the unfolded faces (--layer) with their traced rings", suffixes=(".png",))
    v.add_argument("--layer", choices=("photo", "ring_map", "both"), default="photo",
                   help="what to draw: the face photos, the ring maps, or both (the photos' cross above "
                   "the ring maps') (default photo)")
    v.add_argument("--no-traces", action="store_true", help="do not draw traced rings")
    add_check_layout_option(v)
    add_size_option(v)

    from .rings import add_from_photos

    add_from_photos(sub)


def run(args) -> int:
    """Run a parsed ``block`` command; returns the exit status."""
    if args.block_command == "synth":
        import json

        from ..synth import knotted_log_field, synth_benchmark_set

        lo, hi = args.size_range_mm  # read at the door (_size_range)
        noise = {"trace_jitter_mm": args.jitter_mm, "trace_dropout": args.dropout,
                 "trace_dropout_chunk_mm": args.dropout_chunk_mm, "mislabel_fraction": args.mislabel}
        if args.ring_maps_only:
            noise["trace_faces"] = []
            given = [o for o, v in (("--jitter-mm", args.jitter_mm), ("--dropout", args.dropout),
                                    ("--mislabel", args.mislabel)) if v]
            if given:  # recorded in the blocks' metadata, yet they act on traces only
                import warnings

                from ..errors import WoodcamWarning

                warnings.warn(f"{', '.join(given)} act on traced rings; with --ring-maps-only no trace is written, "
                              "so they change nothing", WoodcamWarning, stacklevel=2)
        opts = {"size_range_mm": (lo, hi), "knotted_fraction": args.knotted_fraction, **noise}
        if engine_requested(args):
            # one task per block: the same blocks as without an engine (noise included),
            # resumable (a record per block), on an engine
            from ..benchmark import write_benchmark_set

            summary, index = write_benchmark_set(args.out, args.count, args.seed, face_px=args.face_px,
                                                 block_options=opts, progress=not args.quiet,
                                                 **engine_options(args))
            knotted = sum(b["knotted"] for b in index["blocks"])
            print(f"wrote {_blocks(len(index['blocks']))} to {args.out} ({knotted} knotted; "
                  f"index.json lists them); {summary.line()}")
            from . import EXIT_CHECKS

            return 0 if summary.failed == 0 else EXIT_CHECKS  # some blocks failed
        from ..benchmark import check_benchmark_set_out

        # an engine run's set of another seed there: its records would keep these blocks as its own
        check_benchmark_set_out(args.out, args.seed, face_px=args.face_px, block_options=opts)
        folders = synth_benchmark_set(args.out, args.count, args.seed, face_px=args.face_px,
                                      size_range_mm=(lo, hi), log_fields=knotted_log_field,
                                      knotted_fraction=args.knotted_fraction,
                                      progress=not args.quiet, **noise)
        index = json.loads((Path(args.out) / "index.json").read_text())
        knotted = sum(b["knotted"] for b in index["blocks"])
        print(f"wrote {_blocks(len(folders))} to {args.out} ({knotted} knotted; index.json lists them)")
        return 0
    if args.block_command == "show":
        from ..block.render import save_cross_png

        block, _ = open_block(args.block, args.size_mm)
        if args.check_layout:
            report_layout(block)
        save_cross_png(block, args.out, args.layer, traces=not args.no_traces)
        print(f"wrote {args.out}")
        return 0
    if args.block_command == "from-photos":
        from .rings import run_from_photos

        return run_from_photos(args)
    raise AssertionError(args.block_command)  # argparse restricts the choices


def _blocks(n: int) -> str:
    """``"1 block"``, ``"2 blocks"``: block synth's summary line said "wrote 1 blocks"."""
    return f"{n} block{'' if n == 1 else 's'}"
