"""Reading and writing blocks: the woodcam manifest folder and the Mokume sample layout.

A **block folder** (synthetic or real) holds one manifest ``block.json`` and PNG images::

    block.json                 manifest (below)
    front_photo.png            (n_rows, n_cols, 3) uint8 RGB photo, stored losslessly
    front_ring_map.png         ring map, 16-bit grey PNG by default (value = round(m * 65535))
    front_knot_mask.png        an array in Face.extras (bool masks as 0 / 255)
    true_field.json            only when the true field can be serialised (below)

Manifest (``"format": "woodcam-block"``, ``"version": 1``)::

    {"name": str, "size_mm": [W, D, H], "meta": {...},
     "faces": {"front": {"shape": [n_rows, n_cols],
                         "photo": "front_photo.png" | null,
                         "ring_map": "front_ring_map.png" | null,
                         "ring_map_bits": 16 | 8,             (the depth written; read: the PNG's own)
                         "traces": [{"year": int | null, "points_px": [[row, col], ...],
                                     "ring": int (optional)}, ...],
                         "traces_svg": "front_traces.svg",    (optional, read only: see below)
                         "extras": {"knot_mask": {"png": "front_knot_mask.png", "dtype": "bool"},
                                    "note": {"json": ...}}},
               ...},
     "true_field": {"saved": bool, "type": "module:QualName", "file": "true_field.json",
                    "reason": str}}

A hand-made manifest of a real block may also name an SVG per face (``"traces_svg"``) with
rings drawn over the photo in a vector editor (:mod:`woodcam.block.svg`); :func:`read_block`
adds those traces to the JSON ones. :func:`write_block` always writes traces as JSON.

Precision: photos and traces round-trip exactly (PNG is lossless; JSON floats are written with
``repr`` precision); a ring map in [0, 1] is quantised to ``ring_map_bits`` bits, so it comes
back within ``0.5 / (2**bits - 1)`` (:data:`woodcam.tolerances.RING_MAP_QUANT_16BIT`). It is read
back by the PNG's own bit depth (white = 255 or 65535), whatever ``ring_map_bits`` says: a map
the user saved since at another depth (an 8-bit export over a 16-bit map) is read as saved.

**True field.** A growth field is in general arbitrary code and is not serialised. It is saved
only when it has ``to_dict() -> dict`` (JSON-serialisable) and its class, which must live in a
``woodcam.*`` module, has ``from_dict(dict)``; then ``true_field.json`` holds the dict and the
manifest the class. Otherwise the manifest records ``"saved": false`` with the reason, and
:func:`read_block` returns ``true_field=None``. Real blocks simply have no true field.

**Mokume folders** (Larsson et al. 2025): ``X_col.png`` photo, ``X_arl-unet.png`` ring map,
optional ``X_ann.png`` and ``X_knot.png``, for letters ``X`` = ``A``..``F`` mapped to faces by
``docs/conventions.md``. See :func:`read_mokume`.
"""

from __future__ import annotations

import json
import os
import warnings
from collections.abc import Collection
from pathlib import Path
from typing import Literal

import numpy as np

from .._checks import check_bool, check_names, check_path
from .._types import ArrayLike, PathLike
from .._atomic import all_or_nothing, atomic_path, output_folder, write_text
from .._readers import photo_rgb8, read_image_file
from ..errors import BlockFolderError, WoodcamError, WoodcamWarning
from ..fields.state import field_from_state, field_type, jsonable
from ..frames import FACE_OF_LETTER, FACES, MOKUME_LETTER, check_size
from ..tolerances import KNOT_POINT_MAX_PX, KNOT_REGION_SMOOTH_PX
from .block import Block, Face, RingTrace

MANIFEST = "block.json"
FORMAT = "woodcam-block"
VERSION = 1

#: Default physical size of a Mokume cube (mm). The dataset normalises cubes by their largest
#: side and does not store the physical size; its cubes are roughly 50 mm hardwood/softwood
#: cubes, so 50 mm is the default here. Pass the real size when you know it.
MOKUME_DEFAULT_SIZE_MM = (50.0, 50.0, 50.0)
#: A Mokume sample's files beside a face's photo ``A_col.png``: ``A_arl-unet.png``, ... (ring
#: map, annual-ring map, knot mask).
MOKUME_MAP_KINDS = ("arl-unet", "ann", "knot")


# -- woodcam manifest folders --------------------------------------------------------------------

def write_block(block: Block, folder: PathLike, *, ring_map_bits: Literal[8, 16] = 16,
                overwrite: bool = True, traces_svg: dict[str, str] | None = None,
                existing: dict[str, dict[str, str]] | None = None) -> Path:
    """Write ``block`` to ``folder`` as ``block.json`` plus PNG images (see module docstring).

    Parameters
    ----------
    block : Block
    folder : path
        Created if missing.
    ring_map_bits : 8 or 16
        Ring-map PNG depth; 16 keeps maps within 7.6e-6 of the original, 8 within 2e-3.
    overwrite : bool
        If False, refuse to write into a folder that already holds a manifest.
    traces_svg : dict, optional
        face -> the name of an SVG of its traces already in ``folder``, recorded as the face's
        ``traces_svg`` (ring detection writes its SVGs first, so the manifest, written last,
        is complete in one step).
    existing : dict, optional
        face -> {``"ring_map"`` or an extras key: the name of an image already in ``folder``},
        named as the face's instead of written (ring detection keeps a user's image under the
        name block.json gave it, untouched); its ``ring_map_bits`` is left to the file's depth.

    Returns
    -------
    Path of the manifest.
    """
    if ring_map_bits not in (8, 16):
        raise WoodcamError(f"ring_map_bits must be 8 or 16; got {ring_map_bits!r}")
    if not isinstance(block, Block):  # None was an AttributeError ('faces')
        raise WoodcamError(f"block must be a woodcam.block.Block; got {type(block).__name__}; pass read_block(...), "
                           "builtin_block(...) or synth_block(...)")
    folder = check_path(folder, "write_block: folder", fix="the block folder to write, e.g. 'blocks/oak1'")
    overwrite = check_bool(overwrite, "write_block: overwrite")
    # a list of SVGs was ignored without a word, a list as existing an AttributeError ('items')
    if traces_svg is not None and not (isinstance(traces_svg, dict)
                                       and all(isinstance(v, str) for v in traces_svg.values())):
        raise WoodcamError(f"write_block: traces_svg must be a dict face -> SVG file name in the folder, or None; "
                           f"got {traces_svg!r:.60}; e.g. {{'front': 'front_traces.svg'}}")
    if existing is not None and not (isinstance(existing, dict) and all(
            isinstance(v, dict) and all(isinstance(f, str) for f in v.values()) for v in existing.values())):
        raise WoodcamError(f"write_block: existing must be a dict face -> {{'ring_map' or an extras key: file name}}, "
                           f"or None; got {existing!r:.60}; e.g. {{'front': {{'ring_map': 'front_rings.png'}}}}")
    output_folder(folder, "write_block: folder")
    manifest_path = folder / MANIFEST
    if manifest_path.exists() and not overwrite:
        raise WoodcamError(
            f"folder {str(folder)!r} already holds a {MANIFEST}; pass overwrite=True or pick a new folder"
        )
    # One set: the photos, maps and manifest land together or not at all. Written file by file,
    # a Ctrl-C of 'block from-photos' (or 'rings detect') into a block folder of an earlier run
    # left the new front photo beside the old faces and the old manifest's rings: a block of two
    # runs, read without a word.
    for name, named in (existing or {}).items():
        for key, fname in named.items():
            if not (folder / fname).is_file():
                raise WoodcamError(f"existing {key} of face {name!r}: {fname!r} is not a file in {str(folder)!r}; "
                                   "write the image first, or leave it out of existing")
    with all_or_nothing():
        faces = {}
        for name, face in block.faces.items():
            named = (existing or {}).get(name, {})
            entry: dict = {"shape": list(face.shape), "photo": None, "ring_map": None}
            if face.photo is not None:
                photo = np.asarray(face.photo)
                if photo.dtype != np.uint8:
                    raise WoodcamError(
                        f"photo of face {name!r} must be uint8 to be stored losslessly; got {photo.dtype}; "
                        "convert with np.clip(photo * 255, 0, 255).round().astype(np.uint8)"
                    )
                entry["photo"] = f"{name}_photo.png"
                _write_png(folder / entry["photo"], photo)
            if face.ring_map is not None and "ring_map" in named:
                entry["ring_map"] = named["ring_map"]  # the reader takes the bit depth of the file
            elif face.ring_map is not None:
                entry["ring_map"] = f"{name}_ring_map.png"
                entry["ring_map_bits"] = int(ring_map_bits)
                _write_png(folder / entry["ring_map"], _quantise(face.ring_map, ring_map_bits, name))
            entry["traces"] = [
                {"year": None if t.year is None else int(t.year), "points_px": t.points_px.tolist(),
                 **({} if t.ring is None else {"ring": int(t.ring)})}
                for t in face.traces
            ]
            extras = {}
            for key, value in face.extras.items():
                extras[key] = ({"png": named[key], "dtype": str(np.asarray(value).dtype)} if key in named
                               else _write_extra(folder, name, key, value))
            entry["extras"] = extras
            if traces_svg and name in traces_svg:
                if not (folder / traces_svg[name]).is_file():
                    raise WoodcamError(f"traces_svg of face {name!r}: {traces_svg[name]!r} is not a file in "
                                       f"{str(folder)!r}; write the SVG first")
                entry["traces_svg"] = traces_svg[name]
            faces[name] = entry
        manifest = {
            "format": FORMAT, "version": VERSION, "name": block.name,
            "size_mm": list(block.size_mm), "meta": jsonable(block.meta, "block.meta"),
            "faces": faces, "true_field": _write_field(block.true_field, folder),
        }
        write_text(manifest_path, json.dumps(manifest, indent=1))  # last: images are in place
    return manifest_path


def read_block(folder: PathLike, *, allow_outside: bool | None = None, regenerated: Collection[str] = ()) -> Block:
    """Read a block folder written by :func:`write_block` (or made by hand for a real block).

    ``regenerated``: names of files (a ring map, a PNG extra, a traces SVG) the manifest may name
    though they are gone, read as absent: ring detection's own files, which it writes again (a
    user deletes an edited one to let detection replace it); any other missing file is an error.

    Faces missing from the manifest are absent from the block; ``true_field`` is None unless the
    manifest says it was saved and its class can be restored. The manifest is checked at the
    door (:func:`woodcam.block._schema.check_manifest`: types, ranges, finite numbers) and every
    file it names must lie inside ``folder`` unless ``allow_outside`` (default: the
    ``WOODCAM_ALLOW_OUTSIDE_PATHS`` environment variable) says this manifest is trusted.
    """
    from .._readers import read_json_file
    from ._schema import check_manifest

    folder = check_path(folder, "read_block: folder", fix="a folder written by write_block, or its block.json")
    # None or 5 was "argument of type 'NoneType' is not iterable" at the first face's file
    regenerated = set(check_names(regenerated, "read_block: regenerated", what="file names", empty=True,
                                  fix="e.g. ['front_ring_map.png'], or () for none"))
    if allow_outside is not None:  # "false" was truthy: files outside the folder were read
        allow_outside = check_bool(allow_outside, "read_block: allow_outside",
                                   fix="pass True to trust this manifest, False, or None "
                                       "($WOODCAM_ALLOW_OUTSIDE_PATHS)")
    if not folder.exists():
        raise WoodcamError(f"block folder {str(folder)!r} does not exist; pass a folder written by "
                           "write_block or 'woodcam block synth/from-photos' (or its block.json)")
    path = folder / MANIFEST if folder.is_dir() else folder
    folder = path.parent
    if not path.is_file():
        raise WoodcamError(
            f"folder {str(folder)!r} must hold a {MANIFEST} manifest; none found. "
            "Use read_mokume() for a Mokume sample folder"
        )
    m = check_manifest(read_json_file(path, "block manifest"), folder, str(path), allow_outside)
    files = m["_paths"]
    faces = {}
    for name, entry in m.get("faces", {}).items():
        shape = tuple(int(v) for v in entry["shape"])
        photo = ring_map = None
        if entry.get("photo"):
            photo = photo_rgb8(_read_png(files[f"faces.{name}.photo"], f"photo of face {name!r}"))
            _check_shape(photo, shape, f"photo of face {name!r} ({entry['photo']})")
        def gone(key: str) -> bool:
            path = files.get(key)
            return path is not None and path.name in regenerated and not path.is_file()

        if entry.get("ring_map") and not gone(f"faces.{name}.ring_map"):
            raw = _read_png(files[f"faces.{name}.ring_map"], f"ring map of face {name!r}")
            if raw.ndim == 3:
                raw = raw[..., 0]
            _check_shape(raw, shape, f"ring map of face {name!r} ({entry['ring_map']})")
            ring_map = _ring_map_of(raw)
        traces = [RingTrace(np.asarray(t["points_px"], dtype=float), t.get("year"), t.get("ring"))
                  for t in entry.get("traces", [])]
        if entry.get("traces_svg") and not gone(f"faces.{name}.traces_svg"):
            from .svg import read_traces_svg

            traces += read_traces_svg(files[f"faces.{name}.traces_svg"], shape)
        extras = {k: _read_extra(files.get(f"faces.{name}.extras.{k}.png"), v, shape,
                                 f"extras[{k!r}] of face {name!r}")
                  for k, v in entry.get("extras", {}).items() if not gone(f"faces.{name}.extras.{k}.png")}
        faces[name] = Face(name, shape, photo=photo, traces=traces, ring_map=ring_map, extras=extras)
    return Block(
        tuple(float(v) for v in m["size_mm"]), faces=faces,
        true_field=_read_field(m.get("true_field"), files.get("true_field.file")),
        name=m.get("name", folder.name), meta=m.get("meta", {}),
    )


def _ring_map_of(raw: np.ndarray) -> np.ndarray:
    """A ring map ``(h, w)`` float32 in [0, 1] of a grey PNG's pixels ``raw`` (uint8 or uint16),
    scaled by the PNG's own bit depth (white = 255 or 65535). The manifest's ``ring_map_bits``
    says the depth :func:`write_block` wrote; a map the user saved since at another depth (an
    editor's 8-bit export over a 16-bit map) was scaled by the manifest's: an 8-bit map under 16
    was read 257 times too dark (white 0.0039) without a word, a 16-bit one under 8 refused."""
    top = 65535.0 if raw.dtype == np.uint16 else 255.0
    return (raw.astype(np.float64) / top).astype(np.float32)


def _quantise(ring_map, bits: int, name: str) -> np.ndarray:
    a = np.asarray(ring_map, dtype=np.float64)
    if not np.all(np.isfinite(a)) or a.min() < 0.0 or a.max() > 1.0:
        raise WoodcamError(
            f"ring_map of face {name!r} must hold finite values in [0, 1]; got range "
            f"[{np.nanmin(a):.3g}, {np.nanmax(a):.3g}]; clip it with np.clip(m, 0, 1)"
        )
    top = 2 ** bits - 1
    return np.round(a * top).astype(np.uint16 if bits == 16 else np.uint8)


def _write_extra(folder: Path, face: str, key: str, value) -> dict:
    if isinstance(value, np.ndarray):
        if not key.replace("_", "").replace("-", "").isalnum():
            raise WoodcamError(f"extras key {key!r} of face {face!r} must be alphanumeric with _ or -")
        fname = f"{face}_{key}.png"
        if value.dtype == bool:
            _write_png(folder / fname, value.astype(np.uint8) * 255)
        elif value.dtype in (np.uint8, np.uint16) and (value.ndim == 2 or (value.ndim == 3 and value.shape[2] == 3)):
            # grey or RGB only: the PNG reader gives RGBA back as RGB and grey + alpha as grey
            _write_png(folder / fname, value)
        else:
            raise WoodcamError(
                f"extras[{key!r}] of face {face!r} must be a bool, uint8 or uint16 image, grey (h, w) "
                f"or RGB (h, w, 3), to be stored as PNG; got dtype {value.dtype}, shape {value.shape}"
            )
        return {"png": fname, "dtype": str(value.dtype)}
    return {"json": jsonable(value, f"extras[{key!r}] of face {face!r}")}


def _read_extra(png: Path | None, entry: dict, shape, what: str):
    if "png" in entry:
        a = _read_png(png, what)
        _check_shape(a, shape, what)
        if entry.get("dtype") == "bool":
            return a > 127
        return a.astype(entry.get("dtype", str(a.dtype)), copy=False)
    return entry.get("json")


def _write_field(field, folder: Path) -> dict:
    target = folder / "true_field.json"
    if field is None:
        if target.exists():
            target.unlink()
        return {"saved": False, "reason": "the block has no true field"}
    kind = field_type(field)
    to_dict = getattr(field, "to_dict", None)
    from_dict = getattr(type(field), "from_dict", None)
    if to_dict is None or from_dict is None or not kind.startswith("woodcam."):
        if target.exists():
            target.unlink()
        return {"saved": False, "type": kind,
                "reason": "the field is not a woodcam class with to_dict()/from_dict(); truth not saved"}
    try:
        state = jsonable(to_dict(), "true_field.to_dict()")
    except (WoodcamError, TypeError, AttributeError) as err:
        # e.g. a placement wrapper around a field that itself cannot be serialised
        if target.exists():
            target.unlink()
        return {"saved": False, "type": kind, "reason": f"to_dict() failed: {err}"}
    write_text(target, json.dumps(state))
    return {"saved": True, "type": kind, "file": target.name}


def _read_field(entry, path: Path | None):
    if not entry or not entry.get("saved"):
        return None
    from .._readers import read_json_file

    state = read_json_file(path, "true field of the block")
    fix = f"write the block again (woodcam.block.write_block) to replace {path.name}"
    try:
        return field_from_state({"type": entry["type"], "state": state}, fix=fix)
    except WoodcamError as err:  # it says what is wrong, and the fix naming the file
        raise WoodcamError(f"true field {str(path)!r}: {err}") from err
    except (KeyError, TypeError, ValueError, IndexError, AttributeError) as err:
        raise WoodcamError(f"true field {str(path)!r} does not hold a valid {entry['type']} "
                           f"({type(err).__name__}: {err}); {fix}") from err


# -- images ---------------------------------------------------------------------------------------

def _write_png(path: Path, a: np.ndarray) -> None:
    from PIL import Image

    a = np.asarray(a)
    if a.dtype == np.uint16:
        if a.ndim != 2:
            raise WoodcamError(f"16-bit PNGs must be single-channel; got shape {a.shape} for {path.name}")
        img = Image.fromarray(a)  # PIL picks mode I;16 for 2-D uint16
    else:
        img = Image.fromarray(np.ascontiguousarray(a))
    with atomic_path(path) as tmp:  # a complete PNG or none
        img.save(tmp, format="PNG")


def _read_png(path: Path, what: str) -> np.ndarray:
    """An image file of a block folder, decoded (:func:`woodcam._readers.read_image_file`)."""
    if not path.is_file():
        raise WoodcamError(f"{what}: image file {str(path)!r} is listed but missing")
    return read_image_file(path, what)


def _check_shape(a: np.ndarray, shape, what: str) -> None:
    if tuple(a.shape[:2]) != tuple(shape):
        raise WoodcamError(
            f"{what} must be {shape[0]}x{shape[1]} px like its face; got {a.shape[0]}x{a.shape[1]}; "
            "resize the image or fix the face's shape"
        )


# -- Mokume sample folders -----------------------------------------------------------------------

def read_block_folder(folder: PathLike, size_mm: tuple[float, float, float] | None = None, *,
                      regenerated: Collection[str] = ()) -> Block:
    """Read a block folder of either kind: the one rule every reader of a folder uses.

    A folder with a ``block.json`` manifest (or the manifest's own path) is read by
    :func:`read_block`; any other folder is read as a Mokume sample folder by
    :func:`read_mokume`, with cube size ``size_mm`` (default :data:`MOKUME_DEFAULT_SIZE_MM`;
    ignored for a manifest folder, whose manifest records its size); ``regenerated`` as
    :func:`read_block`.

    Raises
    ------
    WoodcamError
        When the folder does not exist, or is neither kind (no manifest, no Mokume files).
    """
    folder = Path(folder)
    if folder.name == MANIFEST and folder.is_file():
        folder = folder.parent
    if not folder.is_dir():  # a photo given for its folder was said 'does not exist'
        raise WoodcamError(f"folder must be a block folder (with {MANIFEST}) or a Mokume sample "
                           f"folder; {str(folder)!r} "
                           f"{'is a file, not a folder' if folder.exists() else 'does not exist'}")
    if (folder / MANIFEST).is_file():
        block = read_block(folder, regenerated=regenerated)
        if size_mm is not None and tuple(map(float, size_mm)) != tuple(block.size_mm):
            # nothing silently dropped: --size-mm was accepted and ignored
            warnings.warn(f"--size-mm (size_mm {tuple(size_mm)}) is for Mokume sample folders; {str(folder)!r} "
                          f"records its own size {block.size_mm} mm, which is used", WoodcamWarning, stacklevel=2)
        return block
    if not any(p.exists() for face in FACES for p in mokume_files(folder, face).values()):
        from .photos import find_face_photos

        photos = find_face_photos(folder)
        if photos:  # a user's own photos, not yet a block: say how to make one
            raise BlockFolderError(
                f"folder {str(folder)!r} holds face photos ({', '.join(p.name for p in photos.values())}) but no "
                f"{MANIFEST}: make a block of them first: woodcam block from-photos {str(folder)!r} --size-mm "
                "WxDxH --out BLOCK_DIR", folder=folder)
        raise BlockFolderError(
            f"folder {str(folder)!r} is not a block: no {MANIFEST} (a block folder), no Mokume files like "
            "A_col.png or A_arl-unet.png, no face photos (front.jpg ...); make a block with woodcam block "
            "from-photos or woodcam block synth", folder=folder)
    return read_mokume(folder, MOKUME_DEFAULT_SIZE_MM if size_mm is None else tuple(size_mm))


def mokume_kind(path: Path) -> tuple[str, str] | None:
    """(face, kind) of a Mokume sample's file ``A_col.png``, ``A_arl-unet.png``, ``A_ann.png`` or
    ``A_knot.png`` (kind ``col`` or one of :data:`MOKUME_MAP_KINDS`), its name in any case: a
    case-insensitive file system (Windows, macOS) keeps ``A_ARL-UNET.PNG`` as renamed or unpacked,
    and opened it as ``A_arl-unet.png`` while the folder's listing called it named for no face;
    None for any other file."""
    letter, _, kind = path.stem.partition("_")
    face = FACE_OF_LETTER.get(letter.upper())
    kind = kind.lower()
    return (face, kind) if face and path.suffix.lower() == ".png" and kind in ("col", *MOKUME_MAP_KINDS) else None


def mokume_files(folder: Path, face: str) -> dict[str, Path]:
    """The files Mokume sample folder ``folder`` holds for ``face``, by kind (``A_col.png`` ...,
    in any case: :func:`mokume_kind`); two of one kind (``A_col.png`` and ``A_COL.PNG`` on a
    case-sensitive file system) are a WoodcamError naming them."""
    found: dict[str, list[Path]] = {}
    for p in sorted(folder.iterdir()):
        got = mokume_kind(p)
        if got and got[0] == face and p.is_file():
            found.setdefault(got[1], []).append(p)
    for kind, paths in found.items():
        if len(paths) > 1:
            raise WoodcamError(f"Mokume sample folder {str(folder)!r} holds {len(paths)} {kind} files of face "
                               f"{face!r} ({', '.join(p.name for p in paths)}), names differing in case only; keep "
                               f"one, named {MOKUME_LETTER[face]}_{kind}.png")
    return {k: found[k][0] for k in ("col", *MOKUME_MAP_KINDS) if k in found}  # the photo first: the shape's reference


#: Suffixes of the files a block folder's readers open besides those its manifest names: the
#: manifest and detection's record (.json), ring maps, masks and photos (the photo formats),
#: corrected traces (.svg). A file of another kind in the folder is never read.
_READ_SUFFIXES = (".json", ".svg")


def block_folder_files(folder: Path) -> list[Path]:
    """The files of the block or Mokume sample folder ``folder`` that woodcam may read, sorted:
    what :func:`woodcam.stock.spec_digest` hashes, so that a file woodcam never reads (the
    user's notes.txt, a README, an editor's .xcf) does not make a baked part's block "changed
    since baked". A Mokume folder: its sample files (:func:`mokume_kind`). A manifest folder:
    every file its ``block.json`` names (any suffix, inside the folder), and every file of a
    kind the readers open (:data:`_READ_SUFFIXES` and the photo formats): ring detection reads
    its record and the user's edited maps and SVGs by name. Hidden files are left out."""
    from .photos import PHOTO_SUFFIXES

    files = [p for p in folder.rglob("*") if p.is_file() and not p.name.startswith(".")]
    if not (folder / MANIFEST).is_file():
        return sorted(p for p in files if p.parent == folder and mokume_kind(p))
    named: set[Path] = set()
    try:
        from .._readers import read_json_file
        from ._schema import check_manifest

        m = check_manifest(read_json_file(folder / MANIFEST, "block manifest"), folder,
                           str(folder / MANIFEST), False)
        named = {Path(p).resolve() for p in m["_paths"].values()}
    except WoodcamError:  # reading the block says what is wrong; digest the readable kinds
        pass
    kinds = (*_READ_SUFFIXES, *PHOTO_SUFFIXES)
    return sorted(p for p in files if p.suffix.lower() in kinds or p.resolve() in named)


def read_mokume(folder: PathLike, size_mm: ArrayLike = MOKUME_DEFAULT_SIZE_MM, *, name: str | None = None) -> Block:
    """Read one Mokume sample folder (``X_col.png``, ``X_arl-unet.png``, ... for X = A..F).

    Parameters
    ----------
    folder : path
        A sample folder such as ``../shared/data/mokume/H11``.
    size_mm : (W, D, H)
        Physical size of the cube in mm, three equal sides (another size is refused). Mokume
        cubes are normalised by their largest side and the files do not record it, so it is an
        argument; default 50 mm cube (:data:`MOKUME_DEFAULT_SIZE_MM`).
    name : str, optional
        Block name; default the folder name.

    Returns
    -------
    Block
        One face per letter that has any file. ``photo`` from ``X_col.png`` (uint8 RGB);
        ``ring_map`` from ``X_arl-unet.png`` as float32 in [0, 1] (value / 255; the U-Net's
        ring localisation, no year labels); ``extras["knot_mask"]`` from ``X_knot.png``
        ((rows, cols) bool, True where the mask is dark: below the mid-grey between the
        image's min and max; a mask of a few pixels marks the knot's centre and is grown to
        the knot's dark region in the photo by :func:`knot_region`);
        ``extras["annotation"]`` from ``X_ann.png`` as stored (uint8).
        ``meta`` records the source folder and that the size was assumed.

    Raises
    ------
    WoodcamError
        When the folder has no Mokume files, or images of one face differ in size.
    """
    folder = check_path(folder, "read_mokume: folder", fix="a Mokume sample folder such as shared/data/mokume/H11")
    size = tuple(check_size(size_mm).tolist())  # -1 was "'int' object is not iterable", after every image was read
    if len(set(size)) != 1:
        # a Mokume sample is a cube photographed square on every face: 50x40x30 (as 'block
        # from-photos --size-mm' takes a size) gave faces of non-square pixels without a word
        side = max(size)
        raise WoodcamError(f"size_mm (--size-mm) {'x'.join(f'{v:g}' for v in size)} mm is no cube, and a Mokume "
                           f"sample folder ({str(folder)!r}) is a cube, its faces square photos: give the cube's "
                           f"side, one number, e.g. --size-mm {side:g}")
    if not folder.is_dir():
        raise WoodcamError(f"folder must be a Mokume sample folder; {str(folder)!r} is not a directory; give the "
                           "folder holding A_col.png .. F_col.png, e.g. shared/data/mokume/H11")
    faces = {}
    for face in FACES:
        letter = MOKUME_LETTER[face]
        files = mokume_files(folder, face)
        if not any(p.exists() for p in files.values()):
            continue
        images = {k: _read_png(p, f"Mokume {k} of face {letter}") for k, p in files.items() if p.exists()}
        shape = next(iter(images.values())).shape[:2]
        for k, a in images.items():
            _check_shape(a, shape, f"Mokume image {files[k].name}")
        photo = ring_map = None
        extras = {}
        if "col" in images:
            photo = photo_rgb8(images["col"])
        if "arl-unet" in images:
            a = images["arl-unet"]
            ring_map = _ring_map_of(a[..., 0] if a.ndim == 3 else a)
        if "knot" in images:
            a = images["knot"]
            a = a.mean(axis=2) if a.ndim == 3 else a.astype(float)
            lo, hi = float(a.min()), float(a.max())
            mask = a < 0.5 * (lo + hi) if hi > lo else np.zeros(a.shape, bool)
            if 0 < mask.sum() <= KNOT_POINT_MAX_PX and photo is not None:
                mask = knot_region(photo, mask)
            extras["knot_mask"] = mask
        if "ann" in images:
            extras["annotation"] = images["ann"]
        faces[face] = Face(face, shape, photo=photo, ring_map=ring_map, extras=extras)
    if not faces:
        raise WoodcamError(
            f"folder {str(folder)!r} must hold Mokume files like A_col.png or A_arl-unet.png; found none"
        )
    meta = {"source": "mokume", "folder": str(folder.resolve()),
            "size_assumed_mm": list(size),
            "note": "Mokume cubes are normalised; size_mm was given to read_mokume, not measured"}
    return Block(size, faces=faces, name=name or folder.name, meta=meta)


# -- real blocks from image files ----------------------------------------------------------------

def knot_region(photo: np.ndarray, seeds: np.ndarray) -> np.ndarray:
    """The knot around marked centre pixels: (h, w) bool, the connected region of the photo,
    grown from ``seeds`` ((h, w) bool), whose smoothed luminance is darker than halfway between
    the knot centre's and the face's median (H11's masks mark one pixel per knot; the knot
    itself is the dark disc of end-grain branch wood around it)."""
    from scipy import ndimage

    lum = np.asarray(photo, float)[..., :3] @ np.array([0.299, 0.587, 0.114])
    lum = ndimage.gaussian_filter(lum, KNOT_REGION_SMOOTH_PX)
    dark = lum < 0.5 * (lum[seeds].mean() + np.median(lum))
    lab, _ = ndimage.label(dark | seeds)
    return np.isin(lab, np.unique(lab[seeds]))


def _load_image(src, what: str) -> np.ndarray:
    if isinstance(src, (str, os.PathLike)):
        return _read_png(Path(src), what)  # PIL reads JPEG/TIFF/... the same way
    return np.asarray(src)


def block_from_images(size_mm: ArrayLike, photos: dict | None = None, ring_maps: dict | None = None, *,
                      name: str = "block", meta: dict | None = None) -> Block:
    """Build a (real) block from face images, ready for :func:`write_block`.

    Parameters
    ----------
    size_mm : (W, D, H)
        Measured block size in mm.
    photos : dict face -> path or (rows, cols, 3) uint8 array, optional
        Face photos, already rectified to the face and oriented as ``docs/conventions.md``
        says (seen from outside; Mokume letters ``A``..``F`` accepted as keys). Grey images
        are repeated to RGB.
    ring_maps : dict face -> path or (rows, cols) array, optional
        Ring maps: float arrays in [0, 1], or uint8 / uint16 images (scaled by 255 / 65535).
    name, meta
        Block name and provenance.

    Raises
    ------
    WoodcamError
        When a face's photo and ring map differ in size, or a photo is not uint8 RGB.
    """
    from ..frames import check_face

    images: dict[str, dict] = {}
    for kind, src_map in (("photo", photos or {}), ("ring_map", ring_maps or {})):
        for key, src in src_map.items():
            face = check_face(key)
            a = _load_image(src, f"{kind} of face {face!r}")
            if kind == "photo":
                if a.ndim == 2:
                    a = np.repeat(a[..., None], 3, axis=2)
                if a.ndim != 3 or a.shape[2] < 3 or a.dtype != np.uint8:
                    raise WoodcamError(
                        f"photo of face {face!r} must be an 8-bit RGB image (rows, cols, 3) uint8; "
                        f"got shape {a.shape}, dtype {a.dtype}"
                    )
                a = a[..., :3]
            else:
                if a.ndim == 3:
                    a = a[..., :3].mean(axis=2).astype(a.dtype)
                a = _ring_map_of(a) if a.dtype in (np.uint8, np.uint16) else np.asarray(a, dtype=np.float32)
            images.setdefault(face, {})[kind] = a
    faces = {}
    for face, imgs in images.items():
        shape = next(iter(imgs.values())).shape[:2]
        for kind, a in imgs.items():
            _check_shape(a, shape, f"{kind} of face {face!r}")
        faces[face] = Face(face, shape, photo=imgs.get("photo"), ring_map=imgs.get("ring_map"))
    return Block(tuple(size_mm), faces=faces, name=name, meta=dict(meta or {}))
