"""The ``woodcam`` command: parses, calls the API, prints. Errors become one line and exit 2."""

from __future__ import annotations

import argparse
import importlib
import sys
import warnings
from pathlib import Path

from .errors import WoodcamError

#: Modules that add their own subcommands through ``add_parser(subparsers)`` / ``run(args)``.
_COMMAND_MODULES: tuple[str, ...] = ("woodcam._cli_block", "woodcam._cli_log", "woodcam._cli_appearance", "woodcam._cli_fit",
                                     "woodcam._cli_train", "woodcam._cli_rings",
                                     "woodcam.toolpath.cli")

_EPILOG = """\
Block specs: 'builtin:NAME' (see 'woodcam blocks'), 'log:gran1@K[:WxDxH]', a block folder with a
block.json, or a Mokume sample folder (six photos and ring maps of a 50 mm cube).
Units are millimetres; the block frame has its origin at the bottom-front-left corner,
X to the right (width), Y away from the viewer (depth), Z up (height).

examples:
  woodcam demo --out out/
  woodcam bake cad_examples/bowl.py --block builtin:flat-sawn --out out/bowl.glb
  woodcam preview out/bowl.glb --screenshot out/bowl.png
  woodcam gcode toolpaths/vcarve_text.nc --tool vbit:60:12 --block builtin:flat-sawn \
      --out out/vcarve_text.glb --screenshot
"""


def _add_appearance(p: argparse.ArgumentParser) -> None:
    p.add_argument("--appearance", choices=("colormap", "neural"), default="colormap",
                   help="colormap: fast colour-of-ring model (default); neural: colour volumes "
                   "learnt from the block's photos per axis (seed 000 sec. 3.3, cached on disk)")
    p.add_argument("--quality", choices=("draft", "normal", "high"), default=None,
                   help="training effort of the neural appearance (default normal)")
    p.add_argument("--epochs", type=int, default=None, help="override the neural training epochs")
    p.add_argument("--knot-darkening", default=None, metavar="ALIVE,DEAD",
                   help="colour map: relative darkening of alive and dead knot wood, each in "
                   "[0, 1] (default 0.25,0.45)")
    p.add_argument("--knot-outline", default=None, metavar="R,G,B",
                   help="colour map: colour of the bark ring round dead knots, each in [0, 1] "
                   "(default 0.16,0.10,0.06)")


def _floats(text: str, n: int, option: str) -> tuple[float, ...]:
    """``"a,b,..."`` -> n floats in [0, 1], or a WoodcamError naming the option."""
    try:
        vals = tuple(float(v) for v in text.split(","))
    except ValueError:
        vals = ()
    if len(vals) != n or not all(0.0 <= v <= 1.0 for v in vals):
        raise WoodcamError(f"{option} takes {n} comma-separated numbers in [0, 1]; got {text!r}")
    return vals


def _appearance_params(args) -> dict:
    knots = {}
    if args.knot_darkening is not None:
        knots["knot_darkening_alive"], knots["knot_darkening_dead"] = _floats(
            args.knot_darkening, 2, "--knot-darkening")
    if args.knot_outline is not None:
        knots["dead_outline_rgb"] = _floats(args.knot_outline, 3, "--knot-outline")
    if args.appearance != "neural":
        if args.quality or args.epochs:
            raise WoodcamError("--quality and --epochs apply to --appearance neural only; "
                               f"got --appearance {args.appearance}")
        return knots
    if knots:
        raise WoodcamError("--knot-darkening and --knot-outline apply to --appearance colormap "
                           "only (the neural appearance learns knot colours from the photos)")
    return {k: v for k, v in (("quality", args.quality), ("epochs", args.epochs)) if v is not None}


def _add_common_bake(p: argparse.ArgumentParser) -> None:
    p.add_argument("--texels-per-mm", type=float, default=10.0, metavar="T",
                   help="texture resolution on the part's surface (default 10 = 0.1 mm texels)")
    p.add_argument("--species", default=None,
                   help="colour preset (oak, maple, walnut, cherry, pine, spruce); default: the block's")
    p.add_argument("--no-obj", action="store_true", help="write only the GLB, not OBJ+MTL+PNG")
    p.add_argument("--screenshot", type=Path, default=None, metavar="PNG",
                   help="also render the result to this PNG (no display needed)")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="woodcam", description="CNC cut preview for solid wood: carve a part out of a "
        "block whose growth rings are known and see the wood on every surface.",
        epilog=_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True

    p = sub.add_parser("demo", help="carve the example parts out of built-in blocks into --out",
                       description="Carve, bake, export (GLB, OBJ+MTL+PNG) and render the example "
                       "parts of cad_examples/ out of built-in synthetic blocks; print stage times.")
    p.add_argument("--out", type=Path, default=Path("out"), help="output folder (default out/)")
    p.add_argument("--quick", action="store_true", help="lower texture resolution (for CI)")
    p.add_argument("--texels-per-mm", type=float, default=None, metavar="T",
                   help="texture resolution (default 10, or 4 with --quick)")
    p.add_argument("--appearance", choices=("colormap", "neural"), default="colormap",
                   help="colormap (fast, default) or neural (learnt colour volumes, cached)")
    p.set_defaults(func=_cmd_demo)

    p = sub.add_parser("bake", help="carve a part out of a block and bake its wood texture",
                       description="PART is a build123d/cadquery script defining `part`, or a "
                       "STEP/STL/OBJ/GLB file, modelled in the block frame (mm).")
    p.add_argument("part", help="part file (.py script, .step, .stl, .obj, .glb)")
    p.add_argument("--block", required=True, help="block spec: builtin:NAME, log:gran1@K, a block folder, or a Mokume "
                   "sample folder (a 50 mm cube)")
    p.add_argument("--out", type=Path, required=True, help="output .glb path")
    p.add_argument("--tolerance", type=float, default=None, metavar="MM",
                   help="tessellation chord tolerance for B-rep parts (default 0.05 mm)")
    _add_common_bake(p)
    _add_appearance(p)
    p.set_defaults(func=_cmd_bake)

    p = sub.add_parser("preview", help="view a baked part (window, or --screenshot PNG)",
                       description="Open a baked GLB/OBJ in a window with a cut-plane widget "
                       "that shows the wood inside the block; --screenshot renders off-screen.")
    p.add_argument("mesh", type=Path, help="baked .glb (or .obj)")
    p.add_argument("--screenshot", type=Path, default=None, metavar="PNG",
                   help="render to this PNG instead of opening a window")
    p.add_argument("--block", default=None,
                   help="block spec for the cut plane (default: the one stored in the GLB)")
    p.set_defaults(func=_cmd_preview)

    p = sub.add_parser("blocks", help="list the built-in synthetic blocks")
    p.set_defaults(func=_cmd_blocks)

    for name in _COMMAND_MODULES:
        importlib.import_module(name).add_parser(sub)
    return parser


_printed: set[str] = set()


def _print_warnings(items) -> None:
    """Print each warning once, even when it arrives both as a Python warning and in a report."""
    for w in items:
        if w not in _printed:
            _printed.add(w)
            print(f"woodcam: warning: {w}", file=sys.stderr)


def _cmd_demo(args) -> int:
    from .demo import run_demo

    report = run_demo(args.out, quick=args.quick, texels_per_mm=args.texels_per_mm,
                      appearance=args.appearance)
    print(report.summary())
    return 0


def _cmd_bake(args) -> int:
    from .pipeline import preview_part
    from .stock import open_stock

    stock = open_stock(args.block, species=args.species, appearance=args.appearance,
                       **_appearance_params(args))
    res = preview_part(args.part, stock, args.out, texels_per_mm=args.texels_per_mm,
                       tolerance_mm=args.tolerance, obj=not args.no_obj, screenshot=False,
                       progress=True)
    if args.screenshot:
        from .view import preview

        preview(res.files["glb"], wood=stock.wood, size_mm=stock.size_mm, screenshot=args.screenshot)
        res.files["png"] = args.screenshot
    _print_warnings(res.warnings)
    print(f"{res.name}: {res.triangles} triangles, {res.volume_mm3:.0f} mm^3, atlas "
          f"{res.atlas_px[1]}x{res.atlas_px[0]}; wrote " + ", ".join(map(str, res.files.values())))
    return 0


def _cmd_preview(args) -> int:
    from .export import read_glb_metadata
    from .stock import open_stock
    from .view import preview

    spec = args.block
    if spec is None and args.mesh.suffix.lower() == ".glb":
        spec = read_glb_metadata(args.mesh).get("block")
    stock = open_stock(spec) if spec else None
    out = preview(args.mesh, wood=stock.wood if stock else None,
                  size_mm=stock.size_mm if stock else None, screenshot=args.screenshot)
    if out:
        print(f"wrote {out}")
    return 0


def _cmd_blocks(args) -> int:
    from .fields.builtin import BUILTIN_NAMES, builtin_block

    for name in BUILTIN_NAMES:
        b = builtin_block(name)
        W, D, H = b.size_mm
        print(f"builtin:{name:<14} {W:g} x {D:g} x {H:g} mm  {b.species:<7} {b.description}")
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``woodcam`` console script."""
    parser = build_parser()
    args = parser.parse_args(argv)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            rc = args.func(args)
        except WoodcamError as err:
            print(f"woodcam: error: {err}", file=sys.stderr)
            return 2
        except KeyboardInterrupt:
            print("woodcam: interrupted", file=sys.stderr)
            return 130
        finally:
            _print_warnings(str(w.message) for w in caught if _is_ours(w))
    return rc


def _is_ours(w) -> bool:
    """Warnings woodcam raised itself (its warning classes live in woodcam modules)."""
    return getattr(w.category, "__module__", "").startswith("woodcam")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
