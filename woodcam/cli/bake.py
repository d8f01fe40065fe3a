"""``woodcam demo``, ``bake``, ``preview``, ``blocks`` and ``species``: carve a part, bake its
wood, look at it."""

from __future__ import annotations

import argparse
import shlex
from pathlib import Path

from ..errors import WoodcamError
from ..units import fmt_length, fmt_volume
from .options import (output_refused_at_the_door, BLOCK_SPEC_HELP, add_bake_options, add_input, part_suffixes,
                      CUT_VIEWS_NOTE, add_camera_option, add_max_triangles_option, add_out_option, add_units_option,
                      add_workers_option, allow_negative_values, apply_workers, as_typed, camera_of,
                      add_size_option, not_empty, remove_stale_outputs, stock_options, uses_settings, vector_type,
                      write_screenshot)


def _mesh_suffixes() -> tuple[str, ...]:
    """What preview reads (:data:`woodcam.view.scene.MESH_SUFFIXES`), for the input door."""
    from ..view.scene import MESH_SUFFIXES  # here only: --help imports no numpy

    return MESH_SUFFIXES


def register(subparsers) -> None:
    """Add ``demo``, ``bake``, ``preview``, ``blocks`` and ``species``."""
    p = subparsers.add_parser("demo", help="carve the example parts out of built-in blocks into --out",
                              description="Carve, bake, export (GLB, OBJ+MTL+PNG) and render the "
                              "example parts of cad_examples/ out of built-in synthetic blocks; "
                              "print stage times.")
    add_out_option(p, "per example part a GLB, OBJ+MTL+texture PNG, view PNG and part report",
                   default=Path("out"))
    p.add_argument("--quick", action="store_true", help="lower texture resolution (for CI)")
    add_bake_options(p, texels_default=None, screenshot=False)
    p.set_defaults(func=run_demo)

    p = subparsers.add_parser("bake", help="carve a part out of a block and bake its wood texture",
                              description="PART is a build123d/cadquery script defining `part`, "
                              "or a STEP/STL/OBJ/PLY/OFF/GLB file, modelled in the block frame (mm). "
                              "A .py part script is trusted code: it runs with your rights and "
                              "can read, write or delete your files, so only bake scripts you "
                              "wrote or have read (--timeout bounds its run time; it is not a "
                              "sandbox).")
    add_input(p, "part", kind="file", suffixes=part_suffixes,
              help="part file (.py script, .step/.stp, .stl, .obj, .ply, .off, .glb/.gltf)")
    add_input(p, "--block", kind="block", required=True, help=BLOCK_SPEC_HELP)
    add_out_option(p, "the baked part; beside it PART.obj/.mtl, PART_texture.png, the "
                   "part report PART_report.txt/.json and, with --screenshot, PART_view.png",
                   suffixes=(".glb",))
    p.add_argument("--tolerance", type=float, default=None, metavar="LEN",
                   help="tessellation chord tolerance for B-rep parts, a length in --units (default: scaled to "
                   "the part and the texel, min(a quarter texel, 0.1 %% of the part's bounding-box "
                   "diagonal): 0.025 mm for the demo bowl at 10 texels/mm)")
    p.add_argument("--timeout", type=float, default=None, metavar="S",
                   help="stop loading the part (running a trusted .py script, tessellating) "
                   "after S seconds (default: no limit)")
    p.add_argument("--place", action="append", default=[], metavar="OP",
                   help="place the part in the block before carving; repeatable, applied in "
                   "order: rotate:AXIS:DEG (about the part's centre), translate:X,Y,Z (in --units), "
                   "scale:S, center, drop (onto the bottom face), fit[:MARGIN] (scale into the "
                   "block, MARGIN in --units, default 2 mm). Turn the block instead with a spec ending in "
                   "~AXIS90 (e.g. builtin:flat-sawn~z90)")
    add_max_triangles_option(p)
    add_size_option(p)
    add_units_option(p, "bake")
    add_bake_options(p)
    add_camera_option(p, "; of the --screenshot" + CUT_VIEWS_NOTE)
    add_workers_option(p)
    p.set_defaults(func=run_bake)

    p = subparsers.add_parser("preview", help="view a baked part (window, or --screenshot PNG)",
                              description="Open a baked GLB/OBJ in a window with a cut-plane "
                              "widget that shows the wood inside the block; --screenshot renders "
                              "off-screen.")
    # its reader's suffixes at the door: 'preview some.dwg' exited 1 from the mesh reader
    add_input(p, "mesh", kind="file", suffixes=_mesh_suffixes, type=Path,
              help="baked .glb (or .obj; another program's .gltf, .ply, .stl or .off)")
    # the same [PNG] form as bake's and gcode's --screenshot (issue 17)
    p.add_argument("--screenshot", nargs="?", const=True, default=None, metavar="PNG",
                   type=not_empty(str, "a .png file name, or no value for the default"),
                   help="render off-screen to this PNG instead of opening a window (default "
                   "name: MESH with _view.png)")
    add_input(p, "--block", kind="block", default=None,
                   help=BLOCK_SPEC_HELP + ", for the cut plane (default: the one stored in the GLB)")
    add_camera_option(p, CUT_VIEWS_NOTE)
    p.add_argument("--no-cut", action="store_true",
                   help="no cut plane: the part alone in its translucent block")
    p.add_argument("--cut-origin", type=vector_type("--cut-origin"), default=None, metavar="X,Y,Z",
                   help="a point of the cut plane, block frame, in --units (default the block centre)")
    p.add_argument("--cut-normal", type=vector_type("--cut-normal", example="1,0,0", nonzero=True),
                   default=None, metavar="X,Y,Z",
                   help="the cut plane's normal, towards the side cut away (default: the block's "
                   "longest axis facing the camera). --camera top and bottom show no cut unless "
                   "--cut-origin or --cut-normal is given")
    allow_negative_values(p)
    add_size_option(p, of_glb=True)
    add_units_option(p, "preview")
    p.add_argument("--confidence", action="store_true",
                   help="colour the part by the fit's per-point confidence (red 0, yellow 0.5, green "
                   "1; spread of the accepted hypotheses and distance from observed faces) "
                   "instead of its wood")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=run_preview)

    p = subparsers.add_parser("blocks", help="list the built-in synthetic blocks")
    p.set_defaults(func=run_blocks)
    uses_settings(p)  # no WOODCAM_* setting: it lists, opens no block

    p = subparsers.add_parser("species", help="list the --species colour presets and their sources")
    p.set_defaults(func=run_species)
    uses_settings(p)


def run_demo(args: argparse.Namespace) -> int:
    from ..demo import run_demo as demo

    report = demo(args.out, quick=args.quick, texels_per_mm=args.texels_per_mm,
                  obj=not args.no_obj, **stock_options(args))
    for part in report.parts:
        remove_stale_outputs(part.files["glb"], part.files)
    print(report.summary())
    return 0


def run_bake(args: argparse.Namespace) -> int:
    from ..pipeline import check_outputs, preview_part
    from ..stock import open_stock
    from . import print_warnings

    from .._progress import StageBar
    from ..pipeline import part_stages

    with output_refused_at_the_door():  # the OBJ set beside the GLB, its view PNG
        check_outputs(args.out, obj=not args.no_obj, screenshot=getattr(args, "screenshot", None) or False)
    from ..cad.parts import check_part_path

    check_part_path(args.part)  # a missing part was said after the block was opened (its fit: 20-30 s)
    apply_workers(args)
    shot = bool(getattr(args, "screenshot", None))
    camera_of(args, shot)  # a --camera without --screenshot warns before the work
    # one bar for the whole run: opening the block can fit its rings (minutes, once), so it
    # opens after the part loaded: a script's typo was said after that wait
    stages = part_stages(shot)
    stages.insert(stages.index("load") + 1, "open block")
    opened = []

    def open_block():
        with bar.stage("open block"):
            opened.append(open_stock(args.block, **stock_options(args)))
        return opened[0]

    with StageBar(stages, desc=f"bake {Path(args.out).stem}", leave=False) as bar:
        res = preview_part(args.part, open_block, args.out, texels_per_mm=args.texels_per_mm,
                           tolerance_mm=args.tolerance, timeout_s=args.timeout, obj=not args.no_obj,
                           screenshot=False, progress=True, obj_units=args.obj_units, obj_up=args.obj_up,
                           max_triangles=args.max_triangles, max_atlas_px=args.max_atlas,
                           place=args.place, place_as_typed=as_typed(args, "place"), stages=bar,
                           units_fix="add --place scale:25.4 --place center (in metres: scale:1000)")
        if shot:
            with bar.stage("render"):
                write_screenshot(args, res.files, opened[0])
    remove_stale_outputs(args.out, res.files, inputs=[args.part])
    print_warnings(res.warnings)
    tess = res.tessellation
    if args.tolerance is not None and not tess.get("triangles"):  # nothing was tessellated: a mesh
        import warnings

        from ..errors import WoodcamWarning

        # --max-triangles is not: it simplifies a mesh over it (said by its own warning)
        warnings.warn(f"--tolerance sets how B-rep parts (build123d/cadquery solids, STEP) are meshed, but "
                      f"{args.part} is a triangle mesh, baked as it is: ignored; drop it (give "
                      "--max-triangles, or decimate the mesh in your CAD program, to bake it coarser)",
                      WoodcamWarning, stacklevel=2)
    mesh_note = ""
    if tess.get("tolerance_mm") and tess.get("triangles"):
        from ..tolerances import TESSELLATION_REL_TOL, TESSELLATION_TEXEL_FRACTION

        auto = str(tess.get("tolerance_rule", "")).startswith("auto")
        mesh_note = (f" (meshed at {fmt_length(tess['tolerance_mm'], args.units)} / "
                     f"{tess['angular_tolerance_deg']:.3g} deg"
                     + (f", scaled: min({TESSELLATION_TEXEL_FRACTION:g} texel, "
                        f"{100 * TESSELLATION_REL_TOL:g} % of the part's diagonal)" if auto else "")
                     + f"; budget {tess.get('max_triangles')} triangles)")
    simplified = tess.get("simplified")
    if simplified:  # a mesh part over the budget: said beside the count, as a B-rep's meshing is
        mesh_note = (f" (simplified from {simplified['from']} within "
                     f"{fmt_length(simplified['tolerance_mm'], args.units)}; budget {tess.get('max_triangles')} "
                     "triangles)")
    print(f"{res.name}: {res.triangles} triangles{mesh_note}, "
          f"{fmt_volume(res.volume_mm3, args.units)}, "
          f"{res.atlas}; wrote " + ", ".join(map(str, res.files.values())))
    if res.report:
        from ..advise import report_text

        # the warnings print_warnings said on stderr above are left out of the report printed
        # here (they stay in its files): 'part sticks out' was said twice, on stderr and stdout
        said = set(res.warnings)
        print(report_text({**res.report, "warnings": [w for w in res.report["warnings"] if w not in said]},
                          res.name, units=args.units))
    return 0


def run_preview(args: argparse.Namespace) -> int:
    from ..pipeline import screenshot_path
    from ..view import preview
    from .options import recorded_block_size, stock_of_glb

    if args.no_cut and (args.cut_origin is not None or args.cut_normal is not None):
        import warnings

        from ..errors import WoodcamWarning

        given = [o for o, v in (("--cut-origin", args.cut_origin), ("--cut-normal", args.cut_normal))
                 if v is not None]
        warnings.warn(f"{' and '.join(given)} place{'s' if len(given) == 1 else ''} the cut plane, which "
                      "--no-cut leaves out: "
                      "ignored; drop --no-cut to see that cut", WoodcamWarning, stacklevel=2)
    from .._progress import StageBar
    from ..view.scene import check_display, load_viewer

    shot = screenshot_path(args.screenshot, args.mesh)
    if not shot:  # before the block opens (a fit: seconds to minutes) and pyvista loads
        check_display("preview", "render a picture instead with: woodcam preview "
                      f"{shlex.quote(str(args.mesh))} --screenshot "
                      f"(writes {shlex.quote(str(screenshot_path(True, args.mesh)))})")
    # no cut plane, no wood shown inside: the baked texture and the block's recorded size are
    # all it needs (the block folder it was baked from may be gone, or slow to fit)
    bare = args.no_cut and not args.block and not args.confidence
    # one bar over the run: the block's field is fitted again where the cache lacks it (H11:
    # 20-30 s), pyvista and VTK import in seconds and a screenshot renders in seconds more (it
    # was 6-7 s with no word); closed before a window opens
    stages = [*([] if bare else ["open block"]), "load viewer", *(["render"] if shot else [])]
    with StageBar(stages, desc="preview", leave=False, enabled=not args.quiet) as bar:
        if bare:
            stock, size = None, recorded_block_size(args.mesh)
        else:
            with bar.stage("open block"):
                stock = stock_of_glb(args.mesh, args.block, units=args.units, typed=as_typed(args, "block"),
                                     size_mm=args.size_mm)
            size = stock.size_mm if stock else None
        wood = stock.wood if stock else None
        if args.confidence:
            from ..inference.evidence import ConfidenceWood

            if stock is None or not getattr(stock.wood, "has_uncertainty", False):
                got = (f"got the block {stock.spec!r}, whose field has no fit and so no uncertainty"
                       if stock is not None else f"got {str(args.mesh)!r}, which records no block")
                raise WoodcamError("--confidence needs a block whose field was fitted (a block folder "
                                   f"without a true field, or a Mokume folder); {got}; pass --block with "
                                   "such a block (e.g. --block ../shared/data/mokume/H11), or leave "
                                   "--confidence out")
            wood = ConfidenceWood(stock.wood)  # read where its years are (turned, resized)
        with bar.stage("load viewer"):
            load_viewer()

        def show():
            return preview(args.mesh, wood=wood, size_mm=size, screenshot=shot, camera=camera_of(args),
                           cut_plane=not args.no_cut, cut_origin=args.cut_origin, cut_normal=args.cut_normal)

        if shot:
            with bar.stage("render"):
                out = show()
    if not shot:
        out = show()  # the window, once the bar is gone
    if out:
        print(f"wrote {out}")
    return 0


def run_species(args: argparse.Namespace) -> int:
    from ..appearance import SPECIES

    for name, s in SPECIES.items():
        early, late = ("#" + "".join(f"{round(255 * v):02x}" for v in rgb)
                       for rgb in (s.earlywood_rgb, s.latewood_rgb))
        print(f"{name:<17} earlywood {early} latewood {late}  {s.source}")
    return 0


def run_blocks(args: argparse.Namespace) -> int:
    from ..fields.builtin import BUILTIN_NAMES, builtin_block

    for name in BUILTIN_NAMES:
        b = builtin_block(name)
        W, D, H = b.size_mm
        print(f"builtin:{name:<14} {W:g} x {D:g} x {H:g} mm  {b.species:<7} {b.description}")
    return 0
