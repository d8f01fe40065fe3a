"""``woodcam rings detect|show`` and ``woodcam block from-photos``: rings and knots from photos.

Registered by :mod:`woodcam.cli` through :func:`register`; :mod:`woodcam.cli.block` adds
``from-photos`` to the ``block`` command with :func:`add_from_photos`.
"""

from __future__ import annotations

import shlex
from pathlib import Path

from ..errors import WoodcamError
from .options import add_input, add_check_layout_option, add_out_option, add_size_option, report_layout


def add_from_photos(sub) -> None:
    """Add ``from-photos`` to the ``block`` command's sub-parsers."""
    p = sub.add_parser("from-photos", help="make a block folder from six face photos",
                       description="Read six face photos named front.jpg, top.jpg, left.jpg, bottom.jpg, "
                       "right.jpg, back.jpg (or A..F / Mokume A_col.png ...), each cropped to its face and "
                       "seen from outside; check them against --size-mm; write a block folder with the "
                       "photos. Then run 'woodcam rings detect'.")
    add_input(p, "photos_dir", kind="folder", type=Path, help="folder with the six face photos")
    add_size_option(p, required=True)
    add_out_option(p, "the block folder: block.json and the face photos")
    p.add_argument("--partial", action="store_true", help="accept fewer than six faces (default: all six)")
    p.add_argument("--max-px-per-mm", type=float, default=None,
                   help="upper image density of the stored faces, px/mm (default 10)")


def run_from_photos(args) -> int:
    from ..block.io import write_block
    from ..block.photos import MAX_PX_PER_MM, block_from_photos, clear_stale_photos, written_photos
    from ..detect.block import detection_record

    block = block_from_photos(args.photos_dir, args.size_mm, partial=args.partial,
                              max_px_per_mm=MAX_PX_PER_MM if args.max_px_per_mm is None else args.max_px_per_mm,
                              progress=True)
    prior = detection_record(args.out)  # the block made again into its folder: its SVG corrections kept
    if prior:
        block.meta["detection_before"] = prior
    written = written_photos(args.out)  # an earlier run's photos, read before its manifest is written over
    write_block(block, args.out)
    from . import print_warnings

    print_warnings(clear_stale_photos(args.out, block, written))
    shapes = ", ".join(f"{n} {f.shape[1]}x{f.shape[0]}" for n, f in block.faces.items())
    ppm, photos_ppm = block.meta["px_per_mm"], block.meta["photos_px_per_mm"]
    # say when the photos held more: a 12 MP phone photo of a 50 mm face is 60 px/mm, stored at 10
    capped = (f", down from the photos' {photos_ppm:.2f} (the --max-px-per-mm cap, default {MAX_PX_PER_MM:g}: "
              f"rings 0.8 mm apart keep 8 px)" if photos_ppm > ppm * (1 + 1e-9) else "")
    out = shlex.quote(str(args.out))  # a command to paste: 'my block' was two arguments
    print(f"wrote {args.out} ({len(block.faces)} faces at {ppm:.2f} px/mm{capped}: {shapes}); "
          f"next: woodcam rings detect {out} --out {out}")
    return 0


def register(subparsers) -> None:
    """Add the ``rings`` command (``detect``, ``show``)."""
    p = subparsers.add_parser("rings", help="find rings and knots on a block's face photos; draw them")
    p.set_defaults(func=run)
    sub = p.add_subparsers(dest="rings_command", required=True, metavar="{detect,show}")

    d = sub.add_parser("detect", help="detect rings and knots on every face photo of a block",
                       description="Writes per face a ring map (<face>_ring_map.png), the ring traces as "
                       "SVG over the photo (<face>_traces.svg, editable in Inkscape: a corrected SVG is "
                       "kept and wins over detection next time) and, where a knot is found, a knot mask "
                       "(<face>_knot_mask.png, white = knot), and records them in block.json. BLOCK is a block "
                       "folder or a Mokume sample folder (its U-Net maps and knot masks are ignored: re-detected).")
    add_input(d, "block", kind="folder", type=Path, help="block folder (block.json) or Mokume sample folder")
    add_out_option(d, "the block folder with ring maps, SVG traces and knot masks (may be "
                   "BLOCK itself)")
    d.add_argument("--rule", choices=("dark-edge", "dark-line", "sharp-edge", "dark-centre"),
                   default="dark-edge",
                   help="ring line at the end of each dark band's darkest stretch on its sharp side "
                   "(default: the ring boundary), on the darkest line (where the Mokume maps put "
                   "it), on the band's sharper edge, or on the band's centre (the filter's phase alone)")
    d.add_argument("--detector", choices=("classical", "learned"), default=None,
                   help="classical: the weight-free quadrature-filter detector (default); learned: the "
                   "small net trained by 'woodcam train rings' (woodcam/models/rings.pt)")
    d.add_argument("--curved", action="store_true",
                   help="classical detector: place and order the rings by a Gabor filter that follows "
                   "each ring's curve (slower; default: off, the straight filter bank)")
    d.add_argument("--no-knots", action="store_true", help="do not detect knot masks")
    add_size_option(d)

    s = sub.add_parser("show", help="draw each face photo with the rings and knots found on it",
                       description="Unfolded cross of the face photos (2x) with ring traces (the pieces of one "
                       "ring share a colour), knot "
                       "outlines (yellow) and, for a Mokume folder, the U-Net map's ridge (cyan). A "
                       "Mokume folder is detected first (cached). Each face is named at its top-left corner "
                       "(front (A) ...).")
    add_input(s, "block", kind="folder", type=Path, help="block folder (after 'rings detect') or Mokume sample folder")
    add_out_option(s, "the photos with the rings and knots found", suffixes=(".png",))
    s.add_argument("--zoom", type=int, metavar="N", default=2,
                   help="enlargement: picture pixels per face pixel, a whole number (default 2)")
    add_check_layout_option(s)
    add_size_option(s)


def _knot_masks_said(manifest: Path, no_knots: bool) -> str:
    """The knot masks the written ``block.json`` lists, for the summary line: ``knot masks of
    left, top``, else why there is none (it said 'knot masks' of a block where no knot was found)."""
    import json

    faces = json.loads(manifest.read_text()).get("faces", {})
    with_mask = [name for name, face in faces.items() if "knot_mask" in (face.get("extras") or {})]
    if with_mask:
        return f"knot masks of {', '.join(with_mask)}"
    return "no knot mask: --no-knots" if no_knots else "no knot mask: no knot found"


def run(args) -> int:
    if args.rings_command == "detect":
        from ..detect.block import DEFAULT_DETECTOR, detect_folder

        manifest, msgs = detect_folder(args.block, args.out, rule=args.rule, knots=not args.no_knots,
                                       size_mm=args.size_mm, progress=True,
                                       detector=args.detector or DEFAULT_DETECTOR, curved=True if args.curved else None)
        from . import print_warnings

        print_warnings(msgs)  # on stderr as every command's (they were on stdout, among its output)
        print(f"wrote {manifest.parent} (ring maps, <face>_traces.svg, {_knot_masks_said(manifest, args.no_knots)})")
        return 0
    if args.rings_command == "show":
        import numpy as np
        from PIL import Image

        from .._atomic import atomic_path
        from ..block.io import MANIFEST, read_block_folder
        from ..detect.block import with_detected_rings
        from ..detect.show import ringless, rings_picture

        folder = Path(args.block)
        refs = None
        # the one reader of folders: a folder of the user's own photos was 'must hold Mokume
        # files like A_col.png', no word of 'block from-photos'
        block = read_block_folder(folder, args.size_mm)
        if (folder / MANIFEST).is_file() or folder.name == MANIFEST:
            if not any(f.has_rings for f in block.faces.values()):
                raise WoodcamError(f"block {str(folder)!r} has no rings yet; run 'woodcam rings detect "
                                   f"{folder} --out {folder}' first")
        else:
            mok = block
            refs = {n: f.ring_map for n, f in mok.faces.items() if f.ring_map is not None}
            for f in mok.faces.values():
                f.ring_map, f.traces = None, []
                f.extras.pop("knot_mask", None)
            block = with_detected_rings(mok, progress=True)
        if args.check_layout:
            report_layout(block)
        pic = rings_picture(block, zoom=args.zoom, references=refs)
        with atomic_path(args.out, mkdir=True) as tmp:
            Image.fromarray(np.asarray(pic)).save(tmp, format="PNG")
        # a face detection found no rings on was drawn as its bare photo, without a word
        bare = [n for n, f in block.faces.items() if ringless(f)]
        fix = (f": trace them in {', '.join(str(folder / f'{n}_traces.svg') for n in bare)}"
               if refs is None and folder.is_dir() else "")  # a block folder: its SVGs are read back
        print(f"wrote {args.out}" + (f" (no rings on {', '.join(bare)}{fix})" if bare else ""))
        return 0
    raise AssertionError(args.rings_command)
