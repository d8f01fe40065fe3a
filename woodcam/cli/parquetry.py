"""``woodcam parquetry``: a target image rebuilt from veneers of real wood, with cut files.

Registered by :mod:`woodcam.cli` through :func:`register`; the sub-parser's ``func`` is
:func:`run`. Seed 002 (Iseringhausen et al., "Computational Parquetry"); defaults are its
Table 1.
"""

from __future__ import annotations

import argparse
import math
import warnings
from pathlib import Path

from ..errors import WoodcamWarning
from .options import SPECIES_HELP, add_input, add_out_option, add_units_option, as_typed, sizes_type, species_type

_EPILOG = """\
veneer sources (any number, mixed):
  --veneer SCAN.png[:DPI]            a scanned veneer at DPI (default 300); SCAN.png:4px/mm for
                                     px/mm; SCAN.png:300:MASK.png adds a usable-wood mask
  --veneer-from MOKUME_FOLDER        the six face photos of a Mokume sample (50 mm cube faces)
  --veneer-from BLOCK_SPEC           leaves sliced from a woodcam block or log (builtin:NAME,
                                     log:gran1@K, a block folder): --sheets of --sheet-size,
                                     --leaf-thickness + --saw-kerf apart (in --units),
                                     book-matched

examples:
  woodcam parquetry eye.png --veneer walnut.png:300 --veneer oak.png:300:oak_mask.png --out out/eye/
  woodcam parquetry eye.png --veneer-from ../shared/data/mokume/CN03 --veneer-from log:gran1@52 --out out/eye/
  woodcam parquetry --config job.json --out out/eye/

writes render.png, baseline.png, target_matched.png, assembly.svg, veneer_<id>.svg/.dxf,
result.json, panel.glb and job.json (the run as a job file) into --out, and lists them in
.woodcam-parquetry-files.json: a rerun removes the listed files it does not write again.
"""


#: The options that slice leaves from a --veneer-from block, and their defaults (mm): the
#: parser's defaults are None (not typed), so a value typed equal to its default still
#: overrides a --config job's blocks; these fill in the rest.
_SLICING = {"sheets": 2, "sheet_size": None, "leaf_thickness": 0.6, "saw_kerf": 0.4, "slice_axis": "y",
            "species": None}  # sheet_size None: 600x400 mm, or the block's face where smaller (job_veneers)


def register(subparsers) -> None:
    """Add the ``parquetry`` command."""
    p = subparsers.add_parser(
        "parquetry", help="rebuild a target image from veneers (cut files for a CNC router)",
        description="Computational parquetry (seed 002): cut a target image into patches, find "
        "each on the veneer sheets (intensity + edge features, 15 rotations, every piece of wood "
        "used once), cut seams, and write the panel, the cut files and a report.",
        epilog=_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.set_defaults(func=run)
    add_input(p, "target", kind="file", nargs="*", type=Path, help="target image(s); several are queued "
                   "together on the same wood (--queue); none: the --config job's targets")
    add_input(p, "--config", kind="file", type=Path, default=None, metavar="JOB.json",
                   help="a job file in the paper's layout (source_textures, targets, Table 1 keys); "
                   "options given here override it; its lengths are mm whatever --units (its *_mm keys, "
                   "its block specs' :WxDxH, as job.json is written) (default: none, the targets and "
                   "veneers given here)")
    add_out_option(p, "render.png, baseline.png, target_matched.png, assembly.svg, the cut files "
                      "veneer_<id>.svg/.dxf, result.json, panel.glb and job.json, listed in "
                      ".woodcam-parquetry-files.json")
    v = p.add_argument_group("veneers")
    add_input(v, "--veneer", kind="file", paths=_scan_paths, type=_scan_value, action="append", default=[],
              metavar="SCAN[:DPI][:MASK]",
                   help="scanned veneer image (repeatable; its id, in veneer_<id>.svg, is the file's "
                   "stem, numbered when two share one: oak-1, oak-2); resolution in dpi (default 300, with a warning "
                   "when the file states another, other than the 72/96 dpi cameras and editors write unmeasured) or "
                   "'Npx/mm'")
    add_input(v, "--veneer-from", kind="block", action="append", default=[], metavar="SPEC",
                   help="Mokume sample folder, or block spec to slice leaves from (repeatable; its "
                   ":WxDxH in --units, as bake --block; default: none, the veneers are the --veneer scans "
                   "and the --config job's)")
    v.add_argument("--sheets", type=int, default=None, metavar="N",
                   help="leaves per --veneer-from block (default 2)")
    v.add_argument("--sheet-size", default=None, metavar="WxH", type=sizes_type("--sheet-size", 2),
                   help="size of each sliced leaf in --units (default 600x400 mm, or the block's face where "
                   "smaller; a leaf larger than that face is refused: every sheet is wood of the block)")
    v.add_argument("--leaf-thickness", type=float, default=None, metavar="LEN",
                   help="sliced leaf thickness in --units (default 0.6 mm)")
    v.add_argument("--saw-kerf", type=float, default=None, metavar="LEN",
                   help="wood lost between sliced leaves in --units (default 0.4 mm)")
    v.add_argument("--slice-axis", choices=("x", "y", "z"), default=None,
                   help="normal of the slicing planes in the block frame (default y: leaves "
                   "parallel to the front face)")
    add_units_option(v, "parquetry")
    v.add_argument("--species", default=None, type=species_type,
                   help=SPECIES_HELP + "; of the --veneer-from leaves (default: each block's own)")
    t = p.add_argument_group("parameters (seed 002, Table 1)")
    t.add_argument("--w-intens", type=float, default=None, metavar="W",
                   help="intensity weight of eq. 1, in [0, 1] (default 0.5)")
    t.add_argument("--w-edge", type=float, default=None, metavar="W",
                   help="Sobel edge weight of eq. 1, in [0, 1] (default 0.5)")
    t.add_argument("--w-hist", type=float, default=None, metavar="W",
                   help="histogram-matching blend of eq. 2, in [0, 1] (default 0.5)")
    t.add_argument("--image-size-mm", type=float, default=None, metavar="MM",
                   help="panel's shorter side in mm, rounded to whole patches of --patch-mm (60 makes 56, "
                   "with a warning; default 360, which makes 364)")
    t.add_argument("--patch-mm", type=float, default=None, metavar="MM",
                   help="patch side in mm, the smallest with --n-adaptive (default 14)")
    t.add_argument("--n-adaptive", type=int, default=None, metavar="L",
                   help="adaptive levels: patches of patch-mm * 2^L split in four; the largest must fit "
                   "the panel's shorter side (at most 4 levels at the defaults: 16 patches of the 26; "
                   "default 0)")
    t.add_argument("--w-adaptive", type=float, default=None, metavar="W",
                   help="cost ratio: split when w_adaptive * (cost of the four) < cost of one "
                   "(default 1.2)")
    t.add_argument("--n-rot", type=int, default=None, metavar="N",
                   help="rotations of each sheet searched, 360/N degrees apart (default 15: every 24 degrees)")
    t.add_argument("--priority", choices=("saliency", "center"), default=None,
                   help="patch order: salient first (default) or from the centre out (Fig. 6)")
    t.add_argument("--queue", choices=("interleaved", "sequential"), default=None,
                   help="several targets: interleaved by priority (default) or one after the other")
    f = p.add_argument_group("matching and fabrication")
    f.add_argument("--px-per-mm", type=float, default=None, metavar="PX",
                   help="working resolution of matching and render.png (default 4 px/mm)")
    f.add_argument("--mode", choices=("fast", "exhaustive"), default=None,
                   help="fast: coarse-to-fine with exact re-ranking (default); exhaustive: every "
                   "position at full resolution")
    f.add_argument("--coarse-factor", type=int, default=None, metavar="N",
                   help="fast mode: the first search runs N times coarser than --px-per-mm "
                   "(default: auto, the smallest of 4, 8, 16 whose coarse search holds <= 4.5 M px; "
                   "16 for four 600x400 mm sheets at 4 px/mm)")
    f.add_argument("--w-struct", type=float, default=None, metavar="W",
                   help="weight of the structural re-rank of the cheapest candidates (SSIM's "
                   "contrast-structure on 7 x 7 windows of the target image's own pixels, unitless; "
                   "default 0.02; 0 = eq. 4 alone)")
    f.add_argument("--flat-detail", type=float, default=None, metavar="X",
                   help="where the target is flat, the fast search weighs the wood's fine detail "
                   "up to X times more, so calm wood is found (unitless, >= 1; default 3; 1 = off)")
    f.add_argument("--flat-rerank", type=int, default=None, metavar="N",
                   help="where the target is flat, up to N candidate placements per patch get the "
                   "structural re-rank instead of its 4 (woodcam.params.rerank of a job file; N >= "
                   "that count; default 12; 4 = off)")
    f.add_argument("--overlap-mm", type=float, default=None, metavar="MM",
                   help="patch overlap for seam cutting in mm (default min(--patch-mm / 4, "
                   "(--patch-mm - --min-piece-mm) / 2): 3.5 mm at their defaults); 0 = square pieces")
    f.add_argument("--no-seams", action="store_true", help="square pieces, no seam optimisation: matched and cut "
                   "with no overlap (--overlap-mm 0)")
    f.add_argument("--min-piece-mm", type=float, default=None, metavar="MM",
                   help="narrowest piece in mm (default 5, the paper's bound)")
    f.add_argument("--tool-diameter", type=float, default=None, metavar="LEN",
                   help="router bit diameter in --units: concave bends >= its radius, tool paths offset "
                   "by its radius (default 2 mm)")
    f.add_argument("--kerf-mm", type=float, default=None, metavar="MM",
                   help="wood lost between pieces on a sheet in mm (default: the --tool-diameter, 2 mm at "
                   "its default)")
    f.add_argument("--reuse-wood", action="store_true",
                   help="let pieces overlap on the sheets (an upper bound on quality; not cuttable)")
    f.add_argument("--no-glb", action="store_true", help="do not write panel.glb")
    f.add_argument("--quiet", action="store_true", help="no progress bars")


_OPTION_PARAMS = {"w_intens": "w_intens", "w_edge": "w_edge", "w_hist": "w_hist",
                  "image_size_mm": "image_size_mm", "patch_mm": "patch_mm", "n_adaptive": "n_adaptive",
                  "w_adaptive": "w_adaptive", "n_rot": "n_rot", "priority": "priority", "queue": "queue",
                  "px_per_mm": "px_per_mm", "mode": "mode", "coarse_factor": "coarse_factor",
                  "w_struct": "w_struct", "flat_detail": "flat_detail", "flat_rerank": "flat_rerank",
                  "overlap_mm": "overlap_mm",
                  "min_piece_mm": "min_piece_mm", "tool_diameter": "tool_diameter_mm",
                  "kerf_mm": "kerf_mm"}


def _scan_form(text: str) -> tuple[str, str, float | None, str | None]:
    """``--veneer SCAN[:DPI][:MASK]`` -> (scan, ``"dpi"`` or ``"px_per_mm"``, its value or None
    when not given, mask or None): the one reader of its form, for argparse (:func:`_scan_value`),
    the input door (:func:`_scan_paths`) and the job (:func:`_scan_entry`). A malformed value is
    an ``argparse.ArgumentTypeError``: a wrong command line (exit 2), before any work; too many
    ':' parts, a resolution that is no number, or not finite and > 0, were the run's error
    (exit 1, 0 and -300 dpi refused only when the job was read)."""
    parts = text.split(":")
    form = "give SCAN[:DPI][:MASK], e.g. oak.png:300 or oak.png:4px/mm:oak_mask.png"
    if len(parts) > 3:
        raise argparse.ArgumentTypeError(f"{text!r} has {len(parts)} ':' parts, at most 3 "
                                         f"(a path with ':' cannot be given here: rename it); {form}")
    if not parts[0]:
        raise argparse.ArgumentTypeError(f"{text!r} names no scan image; {form}")
    res = parts[1].lower() if len(parts) >= 2 else ""
    key = "px_per_mm" if res.endswith("px/mm") else "dpi"
    value = None
    if res:
        try:
            value = float(res.removesuffix("px/mm"))
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and value > 0):
            raise argparse.ArgumentTypeError(
                f"{text!r}: the resolution must be a DPI (e.g. 300) or Npx/mm (e.g. 4px/mm), "
                f"finite and > 0; got {parts[1]!r}; {form}")
    return parts[0], key, value, (parts[2] or None) if len(parts) == 3 else None


def _scan_value(text: str) -> str:
    """argparse ``type`` of ``--veneer``: ``text`` as given once :func:`_scan_form` reads it."""
    _scan_form(text)
    return text


def _scan_paths(text: str) -> list[str]:
    """The files a ``--veneer SCAN[:DPI][:MASK]`` names, the scan and its mask, for the input door
    (:func:`~woodcam.cli.options.check_inputs`)."""
    scan, _key, _value, mask = _scan_form(text)
    return [scan, *([mask] if mask else [])]


#: The resolution of a --veneer scan given none (and a file that states none).
_DEFAULT_DPI = 300.0


def _scan_entry(text: str) -> dict:
    """The job's scan entry of a ``--veneer`` value (:func:`_scan_form`), at 300 dpi when it
    gives no resolution."""
    scan, key, value, mask = _scan_form(text)
    entry: dict = {"texture": scan, "id": Path(scan).stem, key: _DEFAULT_DPI if value is None else value}
    if mask:
        entry["mask"] = mask
    if value is None:
        from ..parquetry.veneers import dpi_tag

        # the default 300 dpi over a scan that states its own resolution sized every piece
        # wrongly without a word (a 150 dpi scan cut at half size); a camera's or editor's
        # placeholder (72, 96 dpi) is no resolution, so never named as the fix
        tag = dpi_tag(scan)
        if tag is not None and abs(tag - entry["dpi"]) > 0.01 * entry["dpi"]:
            warnings.warn(f"--veneer {scan!r}: the file states {tag:.4g} dpi, but no resolution was "
                          f"given, so the default {entry['dpi']:g} dpi was used; give the resolution the "
                          f"sheet was scanned at: {scan}:{tag:.4g} if the file's is right, "
                          f"{scan}:{entry['dpi']:g} to keep the default",
                          WoodcamWarning, stacklevel=2)
    return entry


def _setting(args, params, dest: str, key: str) -> str | None:
    """How this run set parameter ``key`` (option ``dest``): the option as typed on the command
    line (in --units where it takes them), the job file's key and value (mm), or None: its
    default."""
    from ..parquetry.job import ParquetryParams
    from .options import as_typed

    if getattr(args, dest, None) is not None:
        return f"--{dest.replace('_', '-')} {as_typed(args, dest):g}"
    value = getattr(params, key)
    if args.config and value != getattr(ParquetryParams(), key):
        return f"woodcam.params.{key} {value:g} in {args.config}"
    return None


def _say_panel_rounding(args, params) -> None:
    """A WoodcamWarning when the panel's shorter side as made (whole patches,
    :attr:`~woodcam.parquetry.job.ParquetryParams.short_side_mm`) is not the one this run asked
    for: '--image-size-mm 60' made a 56 mm panel without a word. Said where the image size or
    the patch was set (an option, a job file's key); the paper's defaults (360 mm of 14 mm
    patches: 364) are the help's to say."""
    from ..units import say_length

    size = _setting(args, params, "image_size_mm", "image_size_mm")
    patch = _setting(args, params, "patch_mm", "patch_mm")
    made = params.short_side_mm
    if (size is None and patch is None) or math.isclose(made, params.image_size_mm):
        return
    n = params.short_cells
    other = n + 1 if made < params.image_size_mm else n - 1
    near = sorted({n, other} - {0})
    warnings.warn(f"{size or f'--image-size-mm default {params.image_size_mm:g}'} makes a panel whose shorter "
                  f"side is {say_length(made, 'g')}: {n} whole patch{'es' if n > 1 else ''} of "
                  f"{patch or f'--patch-mm default {params.patch_mm:g}'}; give --image-size-mm "
                  f"{' or '.join(f'{k * params.patch_mm:g}' for k in near)} (mm, whole patches) to say the size made",
                  WoodcamWarning, stacklevel=2)


def _say_job_lengths_in_mm(args, job) -> None:
    """A WoodcamWarning for each block spec of a ``--config`` job file whose lengths (its
    ``:WxDxH``, its resizes) are read in mm while ``--units`` is not mm: a job file's lengths
    are mm whatever ``--units`` (its ``*_mm`` keys, and its specs as ``job.json`` writes them,
    which ``--units inch`` would read 25.4 times too large), and ``--units`` reads the command
    line's only; 'builtin:flat-sawn:4x2x3' in a job file sliced a 4 x 2 x 3 mm block under
    ``--units inch`` without a word. The fix names the spec in mm of the inches meant."""
    from .._specs import format_spec, parse_spec
    from ..errors import BlockSpecError
    from ..units import MM_PER_UNIT

    if not args.config or args.units == "mm" or job.units_said:  # woodcam.units: "mm" said it
        return
    for i, b in enumerate(job.blocks):
        try:
            parsed = parse_spec(b["spec"])
        except BlockSpecError:  # refused, by the stock, as the block is opened
            continue
        if parsed.size_mm is None and not any(op[0] == "resize" for op in parsed.ops):
            continue  # no length in it: the same block in every unit
        try:
            in_mm = format_spec(parse_spec(b["spec"], mm_per_unit=MM_PER_UNIT[args.units]))
            meant = f"; if it means {'inches' if args.units == 'inch' else args.units}, write it in mm: {in_mm!r}"
        except BlockSpecError:
            meant = ""
        warnings.warn(f"--config {str(args.config)!r}: woodcam.blocks[{i}].spec {b['spec']!r} is read in mm, "
                      f"not in --units {args.units}: a job file's lengths are mm (its *_mm keys, its block "
                      f"specs' sizes, as job.json is written); --units reads the command line's only{meant}",
                      WoodcamWarning, stacklevel=2)


#: Share of a target's longer side that the panel's whole patches may cut off unsaid: the
#: default 360 mm panel (26 patches across the short side) cuts at most 1/39 = 2.6 %.
_CROP_SAID = 0.05


def _cells(aspect: float, short_cells: int) -> int:
    """Patches along the longer side of a panel of ``short_cells`` for a target of ``aspect``
    (long / short >= 1): whole ones, rounded down, as :func:`woodcam.parquetry.engine.prepare_target`
    lays them."""
    return max(1, int(aspect * short_cells + 1e-6))


def _say_target_crop(targets, names, params) -> None:
    """A WoodcamWarning for each target whose longer side the panel crops by more than
    :data:`_CROP_SAID`: the panel is whole patches, so the longer side is rounded down and the
    target cut centrally to it (a 120 x 80 px coffee at --image-size-mm 42 lost 11 % of its width
    without a word: 4 x 3 patches of 14 mm). Names a nearby --image-size-mm that cuts less, and
    the crop a user can make to choose what is left out."""
    n = params.short_cells
    for img, name in zip(targets, names):
        h, w = img.shape[:2]
        aspect = max(h, w) / min(h, w)
        long_cells = _cells(aspect, n)
        cut = 1.0 - long_cells / (aspect * n)
        if cut <= _CROP_SAID:
            continue
        side = "width" if w >= h else "height"
        cols, rows = (long_cells, n) if w >= h else (n, long_cells)
        each_mm = (aspect * n - long_cells) * params.patch_mm / 2
        better = sorted((1.0 - _cells(aspect, k) / (aspect * k), abs(k - n), k) for k in range(max(1, n - 3), n + 4)
                        if k != n)
        fix = (f"give --image-size-mm {better[0][2] * params.patch_mm:g} ({better[0][0]:.0%} cut), or "
               if better and better[0][0] < min(cut, _CROP_SAID) else "")
        warnings.warn(f"{name}: the panel is {cols} x {rows} whole patches of {params.patch_mm:g} mm "
                      f"({cols * params.patch_mm:g} x {rows * params.patch_mm:g} mm), so {cut:.0%} of the target's "
                      f"{side} is cut off, {each_mm:.1f} mm of panel at each end (the target is {w} x {h} px); "
                      f"{fix}crop the target to {cols}:{rows} yourself to choose what is left out",
                      WoodcamWarning, stacklevel=2)


def _default_panel_line(args, params) -> str | None:
    """The printed line that says the panel's size when neither the command line nor a job file
    set it (``--image-size-mm``, ``woodcam.params.image_size_mm``): the paper's 360 mm made
    every target a 364 mm panel, said only as a size in the summary, never as a choice the run
    made for the user; in ``--units`` (and mm, the summary's), None where the size was set
    (:func:`_say_panel_rounding` says that one where it differs)."""
    from ..units import message_unit, say_length

    if _setting(args, params, "image_size_mm", "image_size_mm") is not None:
        return None
    made = params.short_side_mm
    size = say_length(made, "g") + (f" ({made:g} mm)" if message_unit() != "mm" else "")
    return (f"panel: shorter side {size}, the default --image-size-mm {params.image_size_mm:g} (the paper's) in whole "
            f"patches of {params.patch_mm:g} mm, the target's aspect kept; give --image-size-mm (mm) to choose it")


def _sheet_too_small(err, args, params, defaulted: dict[str, tuple[str, str]]) -> str:
    """The engine's too-small-sheet error in the words of this run: the patch, overlap and
    kerf named as the user set them (the engine named the job file's patch_mm and kerf_mm,
    'a smaller kerf_mm' of a kerf the user never typed, --tool-diameter 100's), lengths in
    --units; the fix names the options (they override a job file's keys). ``defaulted``: the
    ids of the --veneer scans given no resolution, to their paths and pixels ('256 x 256'):
    such a sheet's size is its pixels at the default 300 dpi, and a photo of a 50 mm face (256
    px, 130 dpi) was refused as 21.8 mm with no word that the size was a guess."""
    from ..units import say_length

    patch = _setting(args, params, "patch_mm", "patch_mm") or f"--patch-mm default {params.patch_mm:g}"
    parts = [f"one patch ({patch})"]
    smaller = ["--patch-mm"]
    if params.overlap > 0:  # --no-seams, --overlap-mm 0: no overlap to name
        overlap = _setting(args, params, "overlap_mm", "overlap_mm") or f"--overlap-mm default {params.overlap:g}"
        parts.append(f"its overlap ({overlap})")
        smaller.append("--overlap-mm")
    kerf = _setting(args, params, "kerf_mm", "kerf_mm")
    if kerf is None:  # the kerf defaults to the bit's diameter: say so, and whose it is
        tool = (_setting(args, params, "tool_diameter", "tool_diameter_mm")
                or f"--tool-diameter default {say_length(params.tool_diameter_mm, 'g')}")
        kerf = f"--kerf-mm not given: the tool diameter, {tool}"
    parts.append(f"the kerf round it ({kerf})")
    scan = defaulted.get(err.veneer_id)
    size = say_length(err.size_mm, '.1f', ' x ')
    if scan is not None:
        size += (f" ({scan[1]} px at the default {_DEFAULT_DPI:g} dpi, as its --veneer gives no resolution; "
                 f"give the one it was scanned at: --veneer {scan[0]}:DPI)")
    return (f"veneer {err.veneer_id!r} is {size}, smaller than "
            f"{' with '.join(parts[:2]) if len(parts) == 3 else parts[0]} and {parts[-1]}: "
            f"{say_length(err.need_mm, 'g')} a side; use larger sheets, a smaller {' or '.join(smaller)}, "
            "or a smaller kerf (--kerf-mm, in mm)")


def run(args) -> int:
    """Run a parsed ``parquetry`` command; returns the exit status: 0, or
    :data:`~woodcam.cli.EXIT_CHECKS` when the wood ran out (what was made is written)."""
    import dataclasses

    from ..errors import UsageError, WoodcamError
    from ..parquetry.engine import SheetTooSmallError, build_parquetry
    from ..parquetry.job import (
        JobPathError,
        LeavesPastBlockError,
        ParquetryJob,
        job_targets,
        job_veneers,
        numbered_names,
        read_job,
    )
    from ..parquetry.output import format_summary, write_parquetry

    try:
        job = read_job(args.config) if args.config else ParquetryJob()
    except JobPathError as err:  # the job file is part of the command line: a path it names that
        # is not there is refused as the same path typed here (exit 2; it was exit 1)
        raise UsageError(f"--config of 'woodcam parquetry': {err}") from err
    _say_job_lengths_in_mm(args, job)
    # what to rebuild and from what, given by neither the command line nor a job file: a wrong
    # command line (exit 2), said before any work (it was exit 1, after the scans were read)
    if not (args.target or job.targets):
        raise UsageError("parquetry needs a target image (TARGET or a --config job with targets); "
                         "e.g. woodcam parquetry eye.png --veneer oak.png:300 --out out/eye/")
    if not (args.veneer or args.veneer_from or job.scans or job.mokume or job.blocks):
        raise UsageError("parquetry needs veneers: --veneer SCAN[:DPI], --veneer-from SPEC, or a "
                         "--config job with source_textures; e.g. --veneer-from builtin:flat-sawn")
    over = {name: getattr(args, opt) for opt, name in _OPTION_PARAMS.items()
            if getattr(args, opt) is not None}
    if args.reuse_wood:
        over["single_use"] = False
    if args.no_seams:  # square pieces: no overlap to match or cut (job.json then replays it)
        if over.get("overlap_mm"):
            warnings.warn(f"--overlap-mm {over['overlap_mm']:g} changes nothing with --no-seams: square "
                          "pieces are matched and cut without an overlap; drop one of them",
                          WoodcamWarning, stacklevel=2)
        over["overlap_mm"] = 0.0
    try:  # a job file's own parameters were checked as it was read: what fails now, the options made
        job.params = dataclasses.replace(job.params, **over).check()
    except WoodcamError as err:  # options that contradict each other: a wrong command line (exit 2)
        raise UsageError(str(err)) from err
    _say_panel_rounding(args, job.params)
    if args.target:
        job.targets = [{"filename": str(t), "scale": 1.0} for t in args.target]
    scans = [_scan_entry(s) for s in args.veneer]
    # scans of the same file name in two folders (a/oak.png, b/oak.png) were both 'oak', refused
    # as duplicate ids with no way to name them here: number them, oak-1 and oak-2
    for e, n in zip(scans, numbered_names([e["id"] for e in scans], [e["id"] for e in job.scans])):
        e["id"] = n
    job.scans = job.scans + scans
    no_dpi = {e["id"]: _scan_form(t)[0] for e, t in zip(scans, args.veneer) if _scan_form(t)[2] is None}
    # None: not typed (a value typed equal to its default, --sheets 2, is given all the same)
    given = [d for d in _SLICING if getattr(args, d) is not None]
    for d, default in _SLICING.items():
        if getattr(args, d) is None:
            setattr(args, d, default)
    # read as typed, in --units, at the door (sizes_type): its error quotes what was typed
    w, h = args.sheet_size or (None, None)
    # the slicing options given here override the job file's blocks too (--config's rule: options
    # given here override it); they were ignored there
    leaf = {"sheets": args.sheets, "width_mm": w, "height_mm": h, "thickness_mm": args.leaf_thickness,
            "kerf_mm": args.saw_kerf, "axis": args.slice_axis, "species": args.species}
    keys = {"sheets": ["sheets"], "sheet_size": ["width_mm", "height_mm"], "leaf_thickness": ["thickness_mm"],
            "saw_kerf": ["kerf_mm"], "slice_axis": ["axis"], "species": ["species"]}
    job.blocks = [{**b, **{k: leaf[k] for d in given for k in keys[d]}} for b in job.blocks]
    # the blocks whose leaves this command line sized (--veneer-from, or a job's blocks given
    # leaf options here): leaves past such a block are a wrong command line, exit 2
    sized_here = [b for b in job.blocks if set(given) - {"species"}]
    from ..block.io import mokume_kind  # a Mokume sample's names in any case, as block folders read them

    for spec in args.veneer_from:
        sp = Path(spec)
        if sp.is_dir() and any((kind := mokume_kind(p)) and kind[1] == "col" for p in sp.iterdir()):
            job.mokume.append(str(sp))
        else:
            job.blocks.append({"spec": spec, **{k: v for k, v in leaf.items() if v is not None or k == "species"}})
            sized_here.append(job.blocks[-1])
    if given and not job.blocks:  # nothing silently dropped
        sources = " and ".join(n for n, on in (("scans (--veneer)", job.scans),
                                               ("Mokume sample folders", job.mokume)) if on)
        warnings.warn(f"{', '.join('--' + d.replace('_', '-') for d in given)} slice leaves from blocks "
                      f"(--veneer-from BLOCK_SPEC) and none is given; the {sources or 'veneers'} are used "
                      "as they are, so these options change nothing here", WoodcamWarning, stacklevel=2)
    progress = not args.quiet
    targets, names = job_targets(job)
    from ..stock import open_stock

    try:
        veneers = job_veneers(job, open_stock=open_stock, progress=progress)
    except LeavesPastBlockError as err:  # a job file's own leaves: the file is wrong (exit 1)
        if any(err.entry is b for b in sized_here):
            # the spec as typed, not as --units turned it into mm (builtin:oak:4x3x2, inches)
            said = str(err)
            for mm, typed in zip(args.veneer_from, as_typed(args, "veneer_from")):
                said = said.replace(f"{mm}:", f"{typed}:").replace(f"{mm} ", f"{typed} ")
            raise UsageError(said) from err
        raise
    try:
        run_ = build_parquetry(targets, veneers, job.params, names=names, progress=progress,
                               seams=not args.no_seams)
    except SheetTooSmallError as err:
        defaulted = {v.id: (no_dpi[v.id], f"{v.rgb.shape[1]} x {v.rgb.shape[0]}") for v in veneers if v.id in no_dpi}
        raise WoodcamError(_sheet_too_small(err, args, job.params, defaulted)) from err
    _say_target_crop(targets, names, job.params)  # of a run made: an error is said alone
    glb_writer = None
    if not args.no_glb:
        from ..export import export_glb as glb_writer
    res = write_parquetry(run_, args.out, glb_writer=glb_writer, progress=progress, job=job)
    if line := _default_panel_line(args, job.params):
        print(line)
    print(format_summary(res["summary"], res["problems"]))
    print(f"wrote {len(res['files'])} files to {args.out}")
    from . import EXIT_CHECKS, EXIT_OK

    return EXIT_OK if run_.complete else EXIT_CHECKS
