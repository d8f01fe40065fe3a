"""``woodcam train gtf``: train the generic neural growth-time model (§3.2.2 of seed 000);
``woodcam train rings``: the small learned ring detector (:mod:`woodcam.detect.learned`)."""

from __future__ import annotations

from pathlib import Path

from ..errors import UsageError
from .options import add_input, add_engine_options, add_out_option, engine_given, engine_options, engine_requested


def register(subparsers) -> None:
    """Add ``train gtf`` and ``train rings``."""
    p = subparsers.add_parser("train", help="train a learned model (gtf: the generic neural growth field; "
                              "rings: the small ring detector)")
    p.add_argument("what", choices=["gtf", "rings"], help="which model to train")
    add_input(p, "--spec", kind="file", type=Path, default=None,
                   help="JSON spec of hyper-parameters, every key optional (default: the built-in defaults: "
                   "gtf's are the committed model's, 40,000 steps; rings' are a small run, 8 plain cubes and "
                   "1,500 steps, not the committed net's: for that pass woodcam/models/rings_spec.json)")
    add_out_option(p, "the spec, weights and training log (gtf: gtf_spec.json, gtf.pt, "
                   "gtf_train_log.csv and the checkpoint; rings: rings_spec.json, rings.pt, "
                   "rings_train_log.csv)")
    p.add_argument("--member", choices=["main", "quilted"], default=None,
                   help="rings only: which net of the OUT folder to write; main (default): rings.*; quilted: "
                   "rings_quilted.*, a second net (its --spec of a quilted style) whose probability the "
                   "learned detector averages with the main net's")
    p.add_argument("--steps", type=int, metavar="N", default=None,
                   help="stop after N training steps in total, counting a resumed gtf checkpoint's (default: "
                   "the spec's steps; gtf's learning-rate schedule still follows the spec's steps)")
    p.add_argument("--no-resume", action="store_true",
                   help="gtf only: start over instead of resuming OUT's checkpoint (gtf_checkpoint.pt); "
                   "train rings always starts over")
    add_engine_options(p)  # with --engine: the training set is made in shards of 256 fields
    p.set_defaults(func=run)


def run(args) -> int:
    if args.what == "rings":
        from ..detect.learned import RingNetSpec, check_member, check_trainable, train_ring_net

        if engine_requested(args) or args.no_resume:  # they were accepted and ignored
            given = [*engine_given(args), *(["--no-resume"] if args.no_resume else [])]
            raise UsageError("train rings runs in this process and always from scratch: the engine "
                             "options (--engine, --address, --workers, ...) and --no-resume are for "
                             f"'train gtf'; got {' '.join(given)}; leave them out")

        spec = RingNetSpec.load(args.spec) if args.spec is not None else RingNetSpec()
        if args.steps is not None:
            from dataclasses import replace

            spec = replace(spec, steps=args.steps)
        member = args.member or "main"
        check_member(spec, member, what="--member")   # before minutes of training faces
        check_trainable(spec)
        from ..synth.rings import ring_training_faces

        args.out.mkdir(parents=True, exist_ok=True)  # before minutes of training, not after

        # the training faces come from woodcam's own synthesis (synth sits above detect)
        x, y = ring_training_faces(spec, progress=True)
        r = train_ring_net(spec, x, y, args.out, progress=True, member=member)
        print(f"trained the ring net{'' if member == 'main' else ' member ' + member} ({r['params']} parameters) "
              f"{r['steps']} steps in {r['train_s']:.0f} s; "
              f"final loss {r['final_loss']:.4f}; wrote {args.out}")
        return 0
    if args.member is not None:        # accepted by the parser, no effect on gtf
        raise UsageError(f"--member {args.member} is for 'train rings' (the ring net's members); "
                           f"'train gtf' trains one model: leave it out")
    from ..fields.neural import GTFSpec, train_gtf

    spec = GTFSpec.load(args.spec) if args.spec is not None else GTFSpec()
    args.out.mkdir(parents=True, exist_ok=True)
    training_set = None
    if engine_requested(args):
        # the same training set, made in shards on an engine, kept in OUT/trainset/ (resumable);
        # made by train_gtf once it has checked the checkpoint: a run refused for another spec
        # built the shards (minutes) first
        from functools import partial

        from ..benchmark import make_training_set_many

        training_set = partial(make_training_set_many, spec, args.out / "trainset", **engine_options(args))
    r = train_gtf(spec, args.out, steps=args.steps, resume=not args.no_resume, progress=True,
                  training_set=training_set)
    print(f"trained {int(r['step'][-1]) if len(r['step']) else 0} steps in {r['train_s']:.0f} s; "
          f"final L1 {r['final_l1']:.5f} (normalised units), relative {100 * r['final_rel']:.2f} %; "
          f"wrote {args.out}")
    return 0
