"""``woodcam eval appearance``: leave-one-face-out evaluation of the appearance models.

Registered by :mod:`woodcam.cli` through :func:`register` (the old ``eval-appearance`` spelling
is an alias). Each BLOCK is resolved by :func:`woodcam.stock.open_block`: ``builtin:NAME`` (its
face photos rendered by ``woodcam.synth`` with the synthetic wood, so no appearance model is
judged on its own renderings), a Mokume sample folder (ring maps are the networks' input: no
fitted field is needed) or a block folder (its true field if it has one, else its ring maps).
"""

from __future__ import annotations

import json

from .._atomic import write_text
from .options import (QUALITY_EPOCHS_HELP, add_block_argument, add_out_option, add_size_option, command_group,
                      face_names, open_block)


def register(subparsers) -> None:
    """Add ``eval appearance``."""
    evals = command_group(subparsers, "eval", help="score fitted rings (eval rings) or "
                          "appearance models (eval appearance)")
    p = evals.add_parser(
        "appearance", help="leave-one-face-out test of the neural vs colour-map appearance",
        description="Hold out each face in turn, learn the appearance from the others, synthesise "
        "the held-out face from its rings and compare it with its photo (colour histogram, "
        "power spectrum and patch-statistics distances; lower is better). Writes a side-by-side "
        "PNG per block and results.json.")
    add_block_argument(p, option=False, nargs="+")
    add_out_option(p, "results.json and one side-by-side PNG per block")
    add_size_option(p)
    p.add_argument("--resolution", type=int, metavar="N", default=128,
                   help="grid cells along the longest side (default 128)")
    p.add_argument("--quality", choices=("draft", "normal", "high"), default="normal",
                   help="training effort of the neural appearance (default normal)")
    p.add_argument("--epochs", type=int, default=None, metavar="N",
                   help=f"training epochs (default: --quality's, {QUALITY_EPOCHS_HELP})")
    p.add_argument("--finetune-epochs", type=int, default=None, metavar="N",
                   help="per-axis networks fine-tuned N epochs from the all-faces network "
                   "(default 2; 0 trains each axis from scratch, as seed 000 does)")
    p.add_argument("--augment", action="store_true",
                   help="train on randomly mirrored patches too (measured on H11/CN03: no better)")
    p.add_argument("--seed", type=int, metavar="N", default=0, help="random seed (default 0)")
    p.add_argument("--end-grain", default=None, metavar="FACES",
                   help="comma-separated end-grain faces (default: from the field; unknown without one)")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    p.set_defaults(func=run)


def run(args) -> int:
    """Run ``eval appearance``; returns the exit status."""
    from .._atomic import run_outputs

    if args.end_grain:  # before any block is read
        face_names(args.end_grain, "--end-grain")
    args.out.mkdir(parents=True, exist_ok=True)
    with run_outputs(args.out, kind="eval-appearance"):  # one set; an earlier run's other blocks go
        _run(args)
    print(f"wrote {args.out / 'results.json'} and one PNG per block")
    return 0


def _run(args) -> None:
    """``eval appearance``' work: each block's faces held out, a PNG each and results.json."""
    from ..appearance.evaluation import (
        MODELS,
        leave_one_face_out,
        side_by_side,
        summarise,
    )
    from ..frames import check_face

    report = {}
    for spec in args.block:
        block, field = open_block(spec, args.size_mm)
        end_grain = None
        if args.end_grain:
            eg = {check_face(f) for f in face_names(args.end_grain, "--end-grain") or ()}
            end_grain = {f: f in eg for f in block.faces}
        res = leave_one_face_out(block, field, resolution=args.resolution, quality=args.quality,
                                 epochs=args.epochs, seed=args.seed, end_grain=end_grain,
                                 finetune_epochs=args.finetune_epochs,
                                 augment=True if getattr(args, "augment", False) else None,
                                 progress=not args.quiet)
        name = block.name.replace("/", "_")
        side_by_side(res, args.out / f"{name}.png",
                     title=holdout_title(block.name, field is not None))
        report[block.name] = {"faces": {r.face: {"end_grain": r.end_grain, "scores": r.scores} for r in res},
                              "summary": summarise(res)}
        s = report[block.name]["summary"]["all"]
        print(f"{block.name}: " + "; ".join(
            f"{m} hist {s[m]['histogram']:.3f} spec {s[m]['spectrum']:.3f} patch {s[m]['patch']:.3f}"
            for m in MODELS if m in s))
    write_text(args.out / "results.json", json.dumps(report, indent=1))


def holdout_title(name: str, field: bool) -> str:
    """The title of 'eval appearance's picture of block ``name``, whose networks took the rings
    of a field (``field``) or the block's ring map: in words (it said "ARF of field input", the
    papers' abbreviation of the annual-ring field)."""
    return f"{name}: held-out faces (input: {'the rings of the field' if field else 'the ring map'})"
