"""``woodcam eval realistic``: the ring-inference benchmark's main table (issue 12, part 6).

Registered by :mod:`woodcam.cli` through :func:`register`; nothing heavy at import.
"""

from __future__ import annotations

from pathlib import Path

from .options import add_confidence_option, add_out_option, comma_names, command_group, option_range


def register(subparsers) -> None:
    """Add ``eval realistic`` to the ``eval`` group."""
    evals = command_group(subparsers, "eval", help="score fitted rings (eval rings) or "
                          "appearance models (eval appearance)")
    r = evals.add_parser(
        "realistic", help="the main ring benchmark: realistic synthetic blocks (clear and knotted, "
        "30-80 mm), clean / noisy / ring-map traces, six and three faces",
        description="Regenerates blocks INDEX = 0..COUNT-1 of the realistic generator for SEED "
        "(woodcam.synth.benchmark_set_block; half knotted, each with a knot crossing it), fits "
        "each with every method and scores matched ring lines within 1 / 2 mm on seven interior "
        "cut planes. The table gives per scenario, face set and kind the mean with a 95 % "
        "bootstrap interval and the worst block; eq. 7-9 blocks are the sanity row. Per-block "
        "records go to OUT/records.json (woodcam.benchmark.score_block).")
    r.add_argument("--seed", type=int, metavar="N", required=True,
                   help="benchmark seed; use seeds never used while developing a fitter")
    r.add_argument("--count", type=int, metavar="N", default=6,
                   help=f"blocks per row, {option_range('count', 'eval')} (default 6)")
    r.add_argument("--methods", default="rbf,radial,evidence",
                   help="comma list of fitting methods from evidence, rbf, radial, neural, or all "
                   "(default rbf,radial,evidence)")
    r.add_argument("--scenarios", default="noisy",
                   help="comma list of clean, noisy, ring-maps (default noisy)")
    # --face-sets: sets of faces, not faces ('fit --faces front,top' names faces); the old
    # spelling --faces still parses to it
    r.add_argument("--face-sets", "--faces", dest="faces", default="full,three",
                   help="comma list of face sets: full (six faces), three (front, top, left) (default both; "
                   "the old spelling --faces still works)")
    r.add_argument("--eq79", type=int, metavar="N", default=2,
                   help="eq. 7-9 sanity blocks per scenario and face set (default 2; 0 skips)")
    r.add_argument("--face-px", type=int, metavar="PX", default=256,
                   help="face image pixels along the largest side (default 256)")
    r.add_argument("--plots", action="store_true", help="also write cut-plane PNGs per block")
    r.add_argument("--no-knot-bend", dest="knot_bend", action="store_false",
                   help="leave the stem with its knots' ring bend out of the evidence fit's hypotheses "
                        "(default: it competes wherever knot exits on two faces pin a knot)")
    r.add_argument("--no-knot-cones", dest="knot_cones", action="store_false",
                   help="knot strands from the exits' centroids and areas, as before FIT_VERSION 10 "
                        "(default: the cones fitted to every face's knot mask)")
    r.add_argument("--residual", action="store_true",
                   help="try the evidence fit's small-scale residual (a smooth correction within a few "
                        "mm of the faces, kept only where leave-one-face-out says it predicts; default off)")
    add_confidence_option(r, "; implies --plots")
    add_out_option(r, "table.md, records.json and cut-plane PNGs")
    r.set_defaults(func=run_realistic)


def run_realistic(args) -> int:
    import json

    from .._atomic import run_outputs, write_text
    from .._progress import progress_bar, write
    from ..bench_realistic import FACE_SETS, SCENARIOS, confidence_markdown, markdown, score_block, summarise

    from .fit import METHODS, warn_evidence_only

    # 'all' is every method, as in eval rings
    methods = comma_names(args.methods, "--methods", METHODS, all_=True) or list(METHODS)
    warn_evidence_only([o for o, on in (("--no-knot-bend", not args.knot_bend),
                                        ("--no-knot-cones", not args.knot_cones),
                                        ("--residual", args.residual), ("--confidence", args.confidence)) if on],
                       methods)
    scenarios = comma_names(args.scenarios, "--scenarios", tuple(SCENARIOS))
    faces = comma_names(args.faces, "--face-sets", tuple(FACE_SETS))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    tasks = [(kind, i, s, f) for s in scenarios for f in faces
             for kind, n in (("realistic", args.count), ("eq79", args.eq79)) for i in range(n)]
    rows = []
    plots = args.plots or args.confidence
    # one set, as eval rings' (whose table.md it replaces: one list of files): an interrupted
    # run left new PNGs and records.json beside an earlier run's table.md
    with run_outputs(out, kind="eval"):
        for kind, i, s, f in progress_bar(tasks, desc="benchmark blocks", unit="block"):
            row = score_block(args.seed, i, methods, s, f, kind, face_px=args.face_px, keep_lines=plots,
                              knot_bend=args.knot_bend, knot_cones=args.knot_cones, residual=args.residual)
            if plots:
                from ..inference.evaluate import plot_planes

                plot_planes(out / f"{row['name']}_{s}_{f}.png", row.pop("planes"),
                            title=f"{row['name']} ({row['kind']}, {s}, {f}): black = true rings",
                            confidence=args.confidence)
            rows.append(row)
            write(f"{row['name']} {row['kind']} {s} {f}: " + ", ".join(
                f"{m} {row[m]['matched_1']:.0f}/{row[m]['matched_2']:.0f}% {row[m]['fit_s']:.1f}s"
                for m in methods))
        write_text(out / "records.json", json.dumps(rows, indent=1))  # once: the set lands at the end
        table = markdown(summarise(rows, methods), methods)
        conf = confidence_markdown(rows, methods)
        if conf:
            table += ("\nConfidence of the fits that carry one, on their predicted ring lines (a "
                      "point is confident at >= 0.5):\n\n" + conf)
        write_text(out / "table.md", f"seed {args.seed}, {args.count} blocks per row, methods "
                   f"{', '.join(methods)}: matched ring lines within 1 / 2 mm on 7 cut planes\n\n" + table)
    print(table)
    print(f"wrote {out / 'table.md'} and {out / 'records.json'}")
    return 0
