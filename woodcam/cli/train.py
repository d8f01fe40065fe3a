"""``woodcam train gtf``: train the generic neural growth-time model (§3.2.2 of seed 000)."""

from __future__ import annotations

from pathlib import Path


def register(subparsers) -> None:
    """Add ``train gtf``."""
    p = subparsers.add_parser("train", help="train a learned model (gtf: the generic neural growth field)")
    p.add_argument("what", choices=["gtf"], help="which model to train")
    p.add_argument("--spec", type=Path, default=None,
                   help="JSON spec of hyper-parameters (default: the built-in defaults)")
    p.add_argument("--out", type=Path, required=True,
                   help="folder for gtf_spec.json, gtf.pt, gtf_train_log.csv and the checkpoint")
    p.add_argument("--steps", type=int, default=None, help="stop after N steps in total (default: spec.steps)")
    p.add_argument("--no-resume", action="store_true", help="start over instead of resuming the checkpoint")
    p.set_defaults(func=run)


def run(args) -> int:
    from ..fields.neural import GTFSpec, train_gtf

    spec = GTFSpec.load(args.spec) if args.spec is not None else GTFSpec()
    r = train_gtf(spec, args.out, steps=args.steps, resume=not args.no_resume, progress=True)
    print(f"trained {int(r['step'][-1]) if len(r['step']) else 0} steps in {r['train_s']:.0f} s; "
          f"final L1 {r['final_l1']:.5f} (normalised units), relative {100 * r['final_rel']:.2f} %; "
          f"wrote {args.out}")
    return 0
