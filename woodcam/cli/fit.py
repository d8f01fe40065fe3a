"""``woodcam fit`` and ``woodcam eval rings``: infer a block's growth field; score ring fits.

Registered by :mod:`woodcam.cli` through :func:`register`; each sub-parser sets ``func``.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import UsageError
from .options import (add_input, add_block_argument, add_confidence_option, add_out_option, add_size_option,
                      add_workers_option, apply_workers, comma_names, command_group, face_names, open_block)

#: Faces used for "partial annotation": three faces meeting at the front-top-left corner, half
#: of the block's surface (seed 000, section 4.3 traces "half of the block only").
PARTIAL_FACES = ("front", "top", "left")


#: The fitting methods of :data:`woodcam.inference.fit.METHODS`, spelled out here so that
#: ``woodcam --help`` need not import the fitters (numpy, scipy); a test keeps the two equal.
METHODS = ("evidence", "rbf", "radial", "neural")


def register(subparsers) -> None:
    """Add ``fit`` and ``eval rings`` (``eval DIRS`` still means ``eval rings DIRS``)."""
    p = subparsers.add_parser("fit", help="infer a block's growth field from its traced faces")
    add_block_argument(p, option=False)
    p.add_argument("--method", default="evidence", choices=METHODS,
                   help="rbf: seed 000's RBF baseline (unlabelled rings numbered by the radial fit); "
                   "neural: seed 000's eq. 5 with the generic neural field (needs torch); radial: "
                   "our pith axis, ring-width shape and growth history by least squares; evidence "
                   "(default): radial pith hypotheses, RBF and radial + residual, chosen by how well "
                   "each predicts the faces it was not fitted to (warns when they contradict it)")
    p.add_argument("--faces", default=None, help="comma-separated faces to use, from front, top, left, "
                   "bottom, right, back (default: all)")
    add_size_option(p)
    add_workers_option(p, note=" (evidence, radial and rbf; neural uses one and warns)")
    add_out_option(p, "the fitted field as a grid", suffixes=(".npz",))
    p.set_defaults(func=run_fit)

    evals = command_group(subparsers, "eval", help="score fitted rings (eval rings) or "
                          "appearance models (eval appearance)")
    e = evals.add_parser(
        "rings", help="score fits on interior cut planes (seed 000, Table 1) or, for real blocks, "
        "by predicting each face from the others",
        description="Blocks with a known true field (synthetic blocks, or --truth) are scored like "
        "seed 000's Table 1: share of predicted ring-line points within 1 / 2 mm of the true line "
        "of the same year (and of any year) on seven interior cut planes, for all faces and for "
        "the partial face set. Blocks without one (real photographed blocks, Mokume folders) are "
        "scored leave-one-face-out: each face with a ring map is predicted from the others and "
        "its ring-map ridge compared with the predicted ring lines (share within 1, 2 and 5 px, "
        "both ways).")
    add_block_argument(e, option=False, nargs="+")
    add_size_option(e)
    add_input(e, "--truth", kind="file", type=Path, nargs="*", default=None,
                   help="true field files (.npz), one per block; default: each block's own")
    e.add_argument("--methods", default="rbf,radial",
                   help=f"comma list of {', '.join(METHODS)}, or all (default rbf,radial)")
    e.add_argument("--partial-faces", default=",".join(PARTIAL_FACES),
                   help="faces of the partial-annotation run ('none' to skip it)")
    e.add_argument("--detect", action="store_true",
                   help="real blocks: fit from rings detected on the photos (woodcam.detect) and score "
                   "against the block's own ring maps (e.g. the Mokume U-Net maps) as the reference")
    e.add_argument("--seed", type=int, metavar="N", default=None,
                   help="real blocks: the evidence fit's random seed (held-out points, fitting subsets; "
                   "default 0; the other methods draw nothing at random, and --seed without evidence in "
                   "--methods is warned of); a real cube's held-out score can swing with it, so compare several")
    add_confidence_option(e, where="the cut-plane PNGs and, for real blocks, under each held-out face's overlay",
                          tables="table.md and BLOCK_holdout.md summarise")
    add_out_option(e, "table.md and cut-plane PNGs")
    e.set_defaults(func=run_eval)


def warn_evidence_only(given: list[str], methods) -> None:
    """Warn, before the work, that the options ``given`` (as typed: ``--seed 3``, ``--residual``)
    act on the evidence fit only (:func:`woodcam.inference.fit.fit_block`'s ``seed``,
    ``knot_bend``, ``knot_cones``, ``residual``; ``--confidence`` draws its per-point confidence,
    which no other fit carries) when ``methods`` lacks it: they were accepted
    and changed nothing, without a word (``eval rings --seed`` with the default rbf,radial,
    ``eval realistic --methods radial --residual``)."""
    if not given or "evidence" in methods:
        return
    import warnings

    from ..errors import WoodcamWarning

    one = len(given) == 1
    warnings.warn(f"{' and '.join(given)} act{'s' if one else ''} on the evidence fit only, and --methods "
                  f"{','.join(methods)} has none: {'it changes' if one else 'they change'} nothing; add "
                  f"evidence to --methods (e.g. --methods evidence,{','.join(methods)}) or drop "
                  f"{'it' if one else 'them'}", WoodcamWarning, stacklevel=3)


def run_fit(args) -> int:
    from .._progress import StageBar
    from ..stock import fitted_field

    faces = None if args.faces is None else face_names(args.faces, "--faces", all_=True)  # before the block is read
    apply_workers(args)
    if args.workers is not None and args.method == "neural":  # before the work: nothing silently dropped
        import warnings

        from ..errors import WoodcamWarning

        # torch's own thread pool is not safe to fork (woodcam.fields.base.evaluate)
        warnings.warn(f"--workers {args.workers} acts on the evidence, radial and rbf fits only, and "
                      "--method neural runs in one process: it changes nothing; drop it or use another "
                      "--method (e.g. --method radial)", WoodcamWarning, stacklevel=2)
    # one bar for the run, as bake's: the evidence fit of a real cube lasts 20-30 s (H11 from its
    # photos, 2 cores) and a photo-only block is detected first; it ran without a bar
    with StageBar(["open block", "fit", "write"], desc="fit", leave=False) as bar:
        with bar.stage("open block"):
            block, _ = open_block(args.block, args.size_mm)
        with bar.stage("fit"):
            # the content-keyed cache bake and preview fit through (woodcam.stock.fitted_field):
            # a photographed block's evidence fit (~30 s) was redone on every run, and bake then
            # fitted it once more; a block with a true field is fitted all the same (fit is asked to)
            folder = Path(args.block) if Path(args.block).is_dir() else None  # named in its errors
            field = fitted_field(block, folder, args.method, faces=faces)
        with bar.stage("write"):
            path = field.save(args.out)
    print(f"wrote {path} ({args.method} fit of {block.name}, grid {field.years.shape}, "
          f"{field.spacing_mm[0]:g} mm)")
    if field.meta.get("message") and not (field.meta.get("contradicted") or field.meta.get("unverified")):
        print(field.meta["message"])  # a contradicted or unverified fit said it as a warning already
    return 0


def run_eval(args) -> int:
    from ..fields.grid import GridField

    # 'all' is every method (it gave the default rbf,radial)
    methods = comma_names(args.methods, "--methods", METHODS, all_=True) or list(METHODS)
    partial = (None if args.partial_faces.lower() == "none"
               else face_names(args.partial_faces, "--partial-faces", all_=True))
    if args.truth and len(args.truth) != len(args.block):  # before the blocks are opened (a fit each)
        raise UsageError(f"--truth needs one field file per block: got {len(args.truth)} for "
                         f"{len(args.block)} blocks; give one --truth FIELD.npz for each block, in the "
                         "blocks' order, or leave --truth out")
    blocks = [open_block(p, args.size_mm)[0] for p in args.block]
    if args.truth:
        for b, t in zip(blocks, args.truth):
            b.true_field = GridField.load(t)
    from .._atomic import run_outputs

    # one set: a Ctrl-C left block_0000_full.png alone, and a rerun mixed its files with an
    # earlier run's table and pictures (eval realistic writes table.md too: one list)
    with run_outputs(args.out, kind="eval") as written:
        _run_eval(args, blocks, methods, partial)
    # once the set has landed, as eval appearance and eval realistic say it, and by the files'
    # own names (not 'cut-plane images'); the list file of the set is bookkeeping, not an output
    print("wrote " + ", ".join(str(p) for p in written))
    return 0


def _run_eval(args, blocks, methods, partial) -> None:
    """``eval rings``' work: the known blocks on cut planes, the others held out face by face."""
    from ..inference.evaluate import benchmark

    known = [b for b in blocks if b.true_field is not None]
    real = [b for b in blocks if b.true_field is None]
    if args.seed is not None and not real:  # before the work: nothing silently dropped
        import warnings

        from ..errors import WoodcamWarning

        warnings.warn(f"--seed {args.seed} seeds the held-out scoring of real blocks only; "
                      f"{', '.join(b.name for b in known)} have a true field and are scored on cut "
                      "planes, which it does not change", WoodcamWarning, stacklevel=2)
    # the other fitters draw nothing at random and carry no per-point confidence
    warn_evidence_only(([f"--seed {args.seed}"] if args.seed is not None and real else [])
                       + (["--confidence"] if args.confidence else []), methods)
    if known:
        sets = {"full": None}
        if args.partial_faces.lower() != "none":
            sets["partial"] = partial
        res = benchmark(known, methods, sets, out_dir=args.out, progress=print, confidence=args.confidence)
        print(res["table"])
    if args.detect and known:  # nothing silently dropped
        import warnings

        from ..errors import WoodcamWarning

        warnings.warn(f"--detect re-detects the rings of real blocks only; {', '.join(b.name for b in known)} "
                      "have a true field and are scored on their own traces", WoodcamWarning, stacklevel=2)
    if real:
        from ..inference.holdout import leave_one_face_out

        for b in real:
            print(f"{b.name}: no true field; scoring each face predicted from the others")
            fit_on, ref = b, None
            if args.detect:
                from ..detect.block import photos_only, with_detected_rings

                fit_on, ref = with_detected_rings(photos_only(b), progress=True), b
                fit_on.name = f"{b.name}-detected"
                print(f"{b.name}: fitting from rings detected on its photos, scored against its own maps")
            res = leave_one_face_out(fit_on, methods, out_dir=args.out, progress=print, reference=ref,
                                     seed=0 if args.seed is None else args.seed, confidence=args.confidence)
            print(res["table"])
