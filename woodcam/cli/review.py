"""``woodcam review``: one self-contained HTML page to review a baked part in any browser."""

from __future__ import annotations

import argparse
import shlex
from pathlib import Path

from .options import add_input, BLOCK_SPEC_HELP, add_out_option, add_units_option


def _glb_suffixes() -> tuple[str, ...]:
    """What review reads (:data:`woodcam.review.PART_SUFFIXES`), for the input door."""
    from ..review import PART_SUFFIXES  # here only: --help imports no numpy

    return PART_SUFFIXES


def register(subparsers) -> None:
    """Add ``review``."""
    p = subparsers.add_parser(
        "review", help="write a one-file review page (3-D view, live section of the wood, "
        "measurement, photos, report) of a baked GLB",
        description="Write ONE offline HTML file (no network, opens from disk in any browser "
        "with WebGL 2): the part, orbit/pan/zoom and front/top/iso views, a section plane whose "
        "cut face shows the wood inside the block, two-click measurement in mm, the block's face "
        "photos and the bake report, knot and G-code hotspots; printable as a shop sheet.")
    add_input(p, "part", kind="file", suffixes=_glb_suffixes, type=Path,
              help="baked .glb (from woodcam bake or woodcam gcode)")
    add_input(p, "--block", kind="block", default=None,
                   help=BLOCK_SPEC_HELP + " (default: the one stored in the GLB)")
    add_out_option(p, "one self-contained page", suffixes=(".html",))
    p.add_argument("--voxels", type=int, default=None, metavar="N",
                   help="voxels of each of the three colour volumes behind the section cap "
                   "(default 400000: ~1 mm voxels on a 100x80x50 mm block; the page also holds the "
                   "part's texture: ~10 MB for the demo bowl)")
    add_units_option(p, "review")
    p.set_defaults(func=run_review)


def run_review(args: argparse.Namespace) -> int:
    from .._progress import StageBar
    from ..errors import WoodcamError
    from ..export import read_glb_metadata
    from .options import as_typed, stock_of_glb

    meta = read_glb_metadata(args.part)
    if meta.get("kind") == "parquetry panel":  # --block would put one block's wood under the cut
        raise WoodcamError(
            f"review: {str(args.part)!r} is a parquetry panel (veneer pieces from several sheets, each "
            "turned its own way), not a part cut from one block, so the page's section has no wood "
            f"to show; view it with: woodcam preview {shlex.quote(str(args.part))}")
    # one bar for the run, as bake's: the block's field is fitted again where the cache lacks it
    # (H11: 20-30 s), and opening the block, reading the part and its knots took 5 s more before
    # the colour volumes' bar, with none
    with StageBar(["open block", "hotspots", "page"], desc="review", leave=False) as bar:
        with bar.stage("open block"):
            stock = stock_of_glb(args.part, args.block, units=args.units, typed=as_typed(args, "block"))
        out = _page(args, meta, stock, bar)
    print(f"wrote {out} ({out.stat().st_size / 2**20:.1f} MiB)")
    return 0


def _page(args: argparse.Namespace, meta: dict, stock, bar) -> Path:
    """``review``'s work after the block is open: the report rows, the hotspots and the page."""
    from ..errors import WoodcamError
    from ..review import VOLUME_VOXELS, write_review

    if stock is None:
        field = args.part.parent / "field.npz"
        if "woodify" in meta and field.is_file():  # woodify's grown.glb: its field lies beside it
            raise WoodcamError(
                f"review: {str(args.part)!r} (woodify's grown object) records no block spec; pass "
                f"--block woodify:{field} (the growth field woodify wrote beside it)")
        raise WoodcamError(f"review: {str(args.part)!r} records no block spec; pass --block SPEC")
    spec = stock.spec
    from ..stock import species_text

    report = {"block spec": spec, "species": species_text(stock.meta)}
    if isinstance(meta.get("report"), dict):  # the bake's part report (volume, yield, warnings)
        report.update(_report_rows(meta["report"], args.part))
    report.update(_recorded_rows(meta))
    report.update(_gcode_run_rows(meta))
    from ..advise import knot_spots
    from ..export import load_textured

    with bar.stage("hotspots"):
        hotspots = knot_spots(load_textured(args.part), stock.wood)
        hotspots += _gcode_spots(meta, args.part)
    with bar.stage("page"):
        photos = None
        if Path(spec).is_dir():  # a block or Mokume folder: show its face photos
            from ..stock import open_block

            block, _ = open_block(spec)
            photos = {face: f.photo for face, f in block.faces.items()
                      if getattr(f, "photo", None) is not None}
        return write_review(args.part, args.out, wood=stock.wood, size_mm=stock.size_mm,
                            report=report, photos=photos, hotspots=hotspots,
                            voxels=args.voxels or VOLUME_VOXELS, progress=True)


def _gcode_spots(meta: dict, glb: Path) -> list[dict]:
    """The G-code warnings with a position recorded in the GLB's metadata, as hotspots; those
    whose ``at_mm`` is not three finite numbers (GLB metadata is untrusted: an edited or foreign
    file; one such warning broke the whole page) are left out with a warning."""
    import warnings

    import numpy as np

    from .._checks import as_floats
    from ..errors import WoodcamWarning

    recorded = meta.get("warnings")
    spots, bad = [], 0
    for w in recorded if isinstance(recorded, list) else []:
        if not (isinstance(w, dict) and "at_mm" in w):
            continue
        at = as_floats(w["at_mm"])
        if at is None or at.shape != (3,) or not np.all(np.isfinite(at)):
            bad += 1
            continue
        spots.append({"kind": "gcode", "label": str(w.get("message", "")), "at_mm": at.tolist()})
    if bad:
        warnings.warn(f"{str(glb)!r}: {bad} G-code warning(s) in its metadata have no position as three "
                      "numbers (at_mm); the page leaves them out. Run woodcam gcode again to have them",
                      WoodcamWarning, stacklevel=2)
    return spots


def _report_rows(bake_report: dict, glb: Path) -> dict:
    """The bake report's rows for the page, in mm as the page says (``--units`` reads the
    lengths typed, not this table); ``{}`` with a warning for a malformed report (GLB metadata is
    untrusted: an edited or foreign file)."""
    import warnings

    from ..advise import report_rows
    from ..errors import WoodcamWarning

    try:
        return report_rows(bake_report, units="mm")
    except (KeyError, TypeError, ValueError, AttributeError, IndexError) as err:
        warnings.warn(f"{str(glb)!r}: the bake report in its metadata is malformed ({type(err).__name__}: "
                      f"{err}); the page shows no report rows. Re-bake the part to have them",
                      WoodcamWarning, stacklevel=2)
        return {}


def _recorded_rows(meta: dict) -> dict:
    """The bake's settings recorded in its GLB as rows a reader takes in (they were the metadata
    as stored: a row 'texels_per_mm', and the placement as one JSON blob of 16-digit matrix
    entries): ``texture`` in texels/mm, ``G-code`` the program(s), ``placement`` the ``--place``
    operations (in mm, as recorded) and the part-to-block matrix's rows to 4 significant digits.
    A value of another form (GLB metadata is untrusted) is shown as the JSON it is."""
    rows: dict = {}
    t = meta.get("texels_per_mm")
    if isinstance(t, (int, float)) and not isinstance(t, bool):
        rows["texture"] = f"{t:g} texels/mm"
    elif "texels_per_mm" in meta:
        rows["texels_per_mm"] = meta["texels_per_mm"]
    g = meta.get("gcode")
    if isinstance(g, list) and all(isinstance(v, str) for v in g):
        rows["G-code"] = ", ".join(g)
    elif "gcode" in meta:
        rows["G-code"] = g
    place = meta.get("placement")
    ops = place.get("ops") if isinstance(place, dict) else None
    matrix = place.get("matrix") if isinstance(place, dict) else None
    try:
        import numpy as np

        m = np.asarray(matrix, dtype=float)
        ok = (isinstance(ops, list) and all(isinstance(o, str) for o in ops)
              and m.shape == (4, 4) and bool(np.isfinite(m).all()))
    except (TypeError, ValueError):
        ok = False
    if ok:
        lines = "; ".join("[" + ", ".join(f"{v:.4g}" for v in row) + "]" for row in m[:3] + 0.0)
        rows["placement"] = (" ".join(f"--place {o}" for o in ops)
                             + f" (part to block, mm: {lines})")
    elif place is not None:
        rows["placement"] = place
    return rows


def _gcode_run_rows(meta: dict) -> dict:
    """The rows of a ``woodcam gcode`` run recorded in its GLB (none for a baked part): the
    tools by number with their specs and the machining time estimate, for the page and its
    printed shop sheet."""
    from .gcode import fmt_hms

    rows = {}
    tools = meta.get("tools")
    if isinstance(tools, dict) and tools:
        order = sorted(tools, key=lambda t: (not str(t).isdigit(), int(t) if str(t).isdigit() else 0, str(t)))
        rows["tools (--tool specs, mm)"] = ", ".join(f"T{t} {tools[t]}" for t in order)
    t = meta.get("machining_time_s")
    if isinstance(t, (int, float)) and not isinstance(t, bool) and t >= 0:
        rows["machining time"] = (f"{fmt_hms(t)} (estimate from the programmed feeds and the rapid "
                                  "rate, no acceleration: real jobs take longer)")
    return rows
