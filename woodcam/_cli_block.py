"""``woodcam block ...``: synthesise a benchmark set of blocks, draw a block as an unfolded cross.

``woodcam.cli`` calls :func:`add_parser` with its sub-parsers and :func:`run` with the parsed
arguments when ``args.command == "block"``.
"""

from __future__ import annotations

import argparse
from pathlib import Path


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Add the ``block`` command (with ``synth`` and ``show``) to an argparse sub-parser set."""
    p = subparsers.add_parser("block", help="synthesise or show blocks (six face photos + rings)")
    p.set_defaults(func=run)          # woodcam.cli dispatches on args.func
    sub = p.add_subparsers(dest="block_command", required=True, metavar="{synth,show,from-photos}")

    s = sub.add_parser("synth", help="write a reproducible set of synthetic blocks")
    s.add_argument("--count", type=int, required=True, help="number of blocks")
    s.add_argument("--seed", type=int, default=0, help="random seed (same seed, same set)")
    s.add_argument("--out", type=Path, required=True, help="output folder (one sub-folder per block)")
    s.add_argument("--face-px", type=int, default=512, help="pixels along the largest face side")
    s.add_argument("--quiet", action="store_true", help="no progress bar")

    v = sub.add_parser("show", help="draw a block's faces as one unfolded-cross PNG")
    v.add_argument("folder", type=Path, help="block folder (block.json) or Mokume sample folder")
    v.add_argument("--out", type=Path, required=True, help="PNG to write")
    v.add_argument("--layer", choices=("photo", "ring_map", "both"), default="photo")
    v.add_argument("--no-traces", action="store_true", help="do not draw traced rings")
    v.add_argument("--size-mm", type=float, default=None,
                   help="cube side (mm) for a Mokume folder (default 50)")
    from ._cli_rings import add_from_photos

    add_from_photos(sub)
    return p


def run(args) -> int:
    """Run a parsed ``block`` command; returns the exit status."""
    if args.block_command == "synth":
        import json

        from .synth import knotted_log_field, synth_benchmark_set

        folders = synth_benchmark_set(args.out, args.count, args.seed, face_px=args.face_px,
                                      log_fields=knotted_log_field, progress=not args.quiet)
        index = json.loads((Path(args.out) / "index.json").read_text())
        knotted = sum(b["knotted"] for b in index["blocks"])
        print(f"wrote {len(folders)} blocks to {args.out} ({knotted} knotted; index.json lists them)")
        return 0
    if args.block_command == "show":
        from .block.io import MANIFEST, MOKUME_DEFAULT_SIZE_MM, read_block, read_mokume
        from .block.render import save_cross_png

        from .errors import WoodcamError

        folder = Path(args.folder)
        if not folder.exists():
            raise WoodcamError(
                f"folder must be a block folder (with {MANIFEST}) or a Mokume sample folder; "
                f"{str(folder)!r} does not exist"
            )
        if (folder / MANIFEST).exists() or folder.name == MANIFEST:
            block = read_block(folder)
        else:
            s = args.size_mm
            block = read_mokume(folder, MOKUME_DEFAULT_SIZE_MM if s is None else (s, s, s))
        save_cross_png(block, args.out, args.layer, traces=not args.no_traces)
        print(f"wrote {args.out}")
        return 0
    if args.block_command == "from-photos":
        from ._cli_rings import run_from_photos

        return run_from_photos(args)
    raise AssertionError(args.block_command)  # argparse restricts the choices


def main(argv=None) -> int:
    """Stand-alone entry (``python -m woodcam._cli_block block ...``) until ``woodcam.cli`` wires it."""
    from .errors import WoodcamError

    parser = argparse.ArgumentParser(prog="woodcam")
    sub = parser.add_subparsers(dest="command", required=True)
    add_parser(sub)
    args = parser.parse_args(argv)
    try:
        return args.func(args)        # as woodcam.cli dispatches
    except WoodcamError as err:
        import sys

        print(f"woodcam: error: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
