"""``woodcam place``: where in this block should the part go?"""

from __future__ import annotations

import argparse
from pathlib import Path

from ..units import MM_PER_UNIT, TYPED_DECIMALS
from .options import (add_input, part_suffixes, output_refused_at_the_door, BLOCK_SPEC_HELP, add_max_triangles_option,
                      add_out_option, add_size_option, add_units_option, folder_size, place_op_in)


def register(subparsers) -> None:
    """Add ``place``."""
    p = subparsers.add_parser(
        "place", help="rank placements of a part in a block by knots, pith, end grain, runout",
        description="Search placements of PART in the block (the rotations allowed x positions "
        "where it fits) and rank them by what a woodworker cares about, each term reported "
        "separately (knots and pith on or just under the surface, end grain on the surface, "
        "grain runout along a long thin part). Each term is a share in [0, 1], lower is better: "
        "knots, the part's surface (and the wood 1 and 3 mm under it) inside a knot; pith, the same "
        "points within 2 years of the pith; end, the surface within 45 degrees of the fibres; runout, "
        "for a long thin part, the angle of its long axis to the fibres over 90 degrees times its "
        "elongation. score = 4 knots + 3 pith + 1 end + 2 runout, lower is better: the table's first "
        "row is the best placement. Writes OUT/placements.png (the best placements "
        "and the worst side by side) and OUT/placements.json; prints the table with the "
        "--place options that reproduce each placement in woodcam bake. A .py part script is "
        "trusted code: it runs with your rights, so only place scripts you wrote or have read "
        "(--timeout bounds its run time; it is not a sandbox).")
    add_input(p, "part", kind="file", suffixes=part_suffixes,
              help="part file (.py script, .step/.stp, .stl, .obj, .ply, .off, .glb/.gltf), block frame, mm")
    add_input(p, "--block", kind="block", required=True, help=BLOCK_SPEC_HELP)
    add_out_option(p, "placements.png and placements.json")
    p.add_argument("--timeout", type=float, default=None, metavar="S",  # bake's; place had none
                   help="stop loading the part (running a trusted .py script, tessellating) "
                   "after S seconds (default: no limit)")
    p.add_argument("--rotations", choices=("none", "z90", "all90"), default="z90",
                   help="orientations to try: none, quarter turns about z (default), or all 24 "
                   "axis-aligned ones")
    p.add_argument("--candidates", type=int, default=1000, metavar="N",
                   help="about how many placements to score (default 1000)")
    p.add_argument("--margin", type=float, default=1.0, metavar="LEN",
                   help="distance kept from the block faces, in --units (default 1 mm)")
    p.add_argument("--top", type=int, default=3, metavar="K",
                   help="placements printed in the table (and, at least ten, in placements.json); "
                   "the picture shows the best K, at most 10, and the worst (default 3)")
    add_max_triangles_option(p)  # a mesh over it was simplified, said with a fix place did not have
    add_size_option(p)
    add_units_option(p, "place")
    p.set_defaults(func=run_place)


def run_place(args: argparse.Namespace) -> int:
    import json

    from .._atomic import check_output_path, write_bytes
    from .._progress import StageBar
    from ..cad import load_part
    from ..advise import MAX_PANELS, advise_placement, render_advice
    from ..stock import open_stock

    out = Path(args.out)
    with output_refused_at_the_door():
        check_output_path(out / "placements.json", suffixes=(".json",), what="--out", mkdir=True)
    # one bar over the run, the orientations' and panels' own under it; the part is loaded
    # once for the search and the picture (a .py part runs its CAD: seconds), and first: a
    # script's typo or a damaged STEP was said after the block was opened (a fit of minutes)
    with StageBar(["load part", "open block", "score placements", "render"], desc="place",
                  leave=False) as bar:
        with bar.stage("load part"):
            part = load_part(args.part, timeout_s=args.timeout,
                             **({} if args.max_triangles is None else {"max_triangles": args.max_triangles}))
        with bar.stage("open block"):
            size = folder_size(args.block, args.size_mm)
            stock = open_stock(args.block, **({"size_mm": size} if size is not None else {}))
        with bar.stage("score placements"):
            advice = advise_placement(part, stock, rotations=args.rotations,
                                      candidates=args.candidates, margin_mm=args.margin, progress=True,
                                      source=args.part,  # its no-fit error named advise_placement
                                      units_fix="scale the part file by 25.4 in your CAD program (in metres: by 1000)")
        k = 1 / MM_PER_UNIT[args.units]
        record = {"block": args.block, "part": str(args.part), "candidates": advice.candidates,
                  "weights": advice.weights, "elongation": advice.elongation,
                  "ranked": [{"ops": p.ops, "score": p.score, **p.terms,
                              "matrix": p.matrix.tolist()} for p in advice.ranked[:max(args.top, 10)]]}
        write_bytes(out / "placements.json", json.dumps(record, indent=1).encode())
        with bar.stage("render"):
            png = render_advice(advice, part, stock, out / "placements.png", top=args.top, progress=True)
    # the --place ops to type back, rounded for the unit (--units inch: 1.9685, not 1.96850393701);
    # in inches the column says so, and how bake reads them: typed into 'woodcam bake' without
    # --units inch, translate:-0.95,... moved the part 0.95 mm (the numbers carried no unit)
    title = "place" if args.units == "mm" else f"place (lengths in inches: woodcam bake --units {args.units})"
    print(advice.table(args.top, op_text=lambda op: place_op_in(op, k, TYPED_DECIMALS[args.units]),
                       place_title=title))
    # a panel per placement up to --top 100000 took minutes: the picture stops at MAX_PANELS
    listed = min(args.top, len(advice.ranked))
    drawn = f" (the best {MAX_PANELS} and the worst; the table lists {listed})" if listed > MAX_PANELS else ""
    print(f"scored {advice.candidates} placements; wrote {png}{drawn} and {out / 'placements.json'}")
    return 0
