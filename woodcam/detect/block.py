"""Rings and knots detected on every face of a block, written beside its photos, cached by content.

A block's faces after detection carry (pixels of each face image, ``docs/conventions.md``):

- ``traces``: the detected ring boundaries, unlabelled, sub-pixel polylines; in a block folder
  they live in ``<face>_traces.svg`` (one unit per pixel, drawn over ``<face>_photo.png``, editable
  in Inkscape) named by the manifest's ``"traces_svg"``, which :func:`woodcam.block.read_block`
  reads back;
- ``ring_map``: ``(h, w)`` float32 drawn from those traces (Mokume-like line width);
- ``extras["knot_mask"]``: ``(h, w)`` bool from :func:`woodcam.detect.knots.detect_knots`.

**A user's SVG wins.** The manifest records the SHA-256 of each SVG the detector wrote
(``meta["detection"]["svg_sha256"]``). When a face's SVG no longer matches (someone corrected it
in an editor), detecting again keeps that SVG, takes its traces as the face's rings and redraws
the ring map from them; only faces whose SVG is untouched (or missing) are detected afresh. It
also records a digest of each face photo traced (``meta["detection"]["photo_digest"]``): a
corrected SVG drawn over another photo than the face's now is refused, not kept.

**Its own files, and no others, are cleared or written over.** Detection writes per face
``<face>_traces.svg``, ``<face>_ring_map.png`` and ``<face>_knot_mask.png``; the manifest records
a digest of each (the SVGs' ``svg_sha256`` above, the images' ``meta["detection"]["file_digest"]``:
file name -> digest of its pixels as read back; :data:`DETECTED_IMAGES`). Detecting again into
the folder, such a file the new detection names no more (no rings or knot found on the face now,
or no such face) is removed when it is still the recorded one; one that is not (edited, made by
hand, or left by a run before the digests were recorded) is kept and said, unread only when the
block has no such face or it is one of those older runs'. An image the user edited since it was
recorded wins as a corrected SVG does, on a face where detection finds a knot (rings) again and
on one where it finds none (the user's is then the face's only one): it is kept and read as the
face's, and said, with how to let detection replace it, and it stays the user's on later runs
(not recorded as the detector's); a folder whose record has no digests (detected before they
were recorded) has its images written over.
A block folder with no detection recorded at all (the output with no manifest, or either the
source or the output with one 'block from-photos' wrote and no detection since) holds none of
the detector's files: a ring map, knot mask or ``<face>_traces.svg`` there (made by hand beside
the photos before detecting) is the user's, kept and used as an edited one is (the source's
carried into another ``--out``, over a detection recorded there), and said the same way. A ring
map, knot mask or traces SVG block.json names under another name than detection's
(``top_rings.png``) is the user's wherever it is (detection writes none of that name): kept
untouched, still named by the manifest, read as the face's and said alike (carried over under
its name into another ``--out``, and kept named through 'block from-photos' making the block
again into its folder: its record keeps the names). A user's file carried from the source into
another ``--out`` is recorded there by content (``meta["detection"]["carried"]``: name in
``--out`` -> digest): the next run into that ``--out`` takes whichever of the source's and the
copy was edited since, and refuses both edited since (:func:`_source_or_copy`).

**Photo-only blocks elsewhere** (``fit``, ``bake``, ``eval``): :func:`with_detected_rings`
detects the faces that have a photo but no rings, once, and caches the result in the ``detect``
folder of woodcam's cache (:mod:`woodcam._cache`: ``$WOODCAM_CACHE_DIR`` or platformdirs' user
cache), one ``.npz`` keyed by a digest of the photos, the block size, the rule, the detector and
:data:`DETECT_VERSION`, and each face in an entry of its own as ``rings detect`` caches it (below),
so a block with one photo retaken detects that face alone; the user's folder is never written to.
In a folder 'block from-photos'
made again (its manifest names none of the user's files; its record of the earlier detection
keeps them), the user's corrected SVGs and edited or named images of a face whose photo is
unchanged are read in over the detected ones and said, as the next detection keeps them, and
those of a face whose photo changed since are said unused, as the next detection refuses them
(:func:`_users_files_of_a_remade_block`). :func:`detect_folder` (``rings
detect``) caches each face of the classical detector there too (its photo, density, rule and
options): detecting a folder again, after one SVG was corrected or one photo changed, detects
only the faces whose photo is new.
"""

from __future__ import annotations

import copy
import hashlib
import json
import warnings
from collections.abc import Collection
from pathlib import Path
from typing import Literal

import numpy as np

from .._atomic import atomic_path, write_bytes
from .._cache import cache_dir, digest, entry_path, load_or_build
from ..block.block import Block, Face
from ..block.photos import photo_digest
from ..errors import WoodcamError, WoodcamWarning
from ..frames import FACES
from .knots import detect_knots
from .layout import NO_RINGS, check_face_layout
from .rings import DEFAULT_RULE, RING_MAP_SIGMA_MM, BoundaryRule, detect_rings, ring_map_from_traces

#: Bumped whenever detection results change, so cached detections are recomputed (3: traces
#: carry their face-local ring id, ``RingTrace.ring``; 4: the curved Gabor response and the
#: ``dark-edge`` rule by default; 5: the curved Gabor opt-in, after caches of 4 were written
#: with it on; 6: pieces cut at a snap jump shorter than a ring spacing dropped; 7: pieces lying
#: side by side never linked as one ring).
DETECT_VERSION = 7


#: Peak memory of the classical detector (:func:`~woodcam.detect.rings.detect_rings` and the knot
#: masks) per face pixel, bytes: measured (peak RSS over the imported package) on H11's front
#: face resampled to 512, 1024 and about 1500x2000 px at the Mokume scale (10-25 px/mm):
#: 360 MB, 1.33 GB and 3.9 GB; the bank's scales span a fixed ring-spacing ratio, so it does not
#: grow with the density. A 8000x6000 face (phone photos under --max-px-per-mm 100) asked for
#: ~60 GB and was killed, a 1500x2000 one took ~2 minutes.
DETECT_BYTES_PER_PX = 1300


Detector = Literal["classical", "learned"]
DETECTORS: tuple[str, ...] = ("classical", "learned")
#: The default detector, picked by the figures in README ("From photos alone").
DEFAULT_DETECTOR: Detector = "classical"


def _curved(curved: bool | None) -> bool:
    """Whether the classical detector uses the curved Gabor (``None``: the module default)."""
    from . import rings

    return rings.CURVED_GABOR if curved is None else bool(curved)


def detect_face(face: Face, px_per_mm: float, rule: BoundaryRule = DEFAULT_RULE,
                knots: bool = True, detector: Detector = DEFAULT_DETECTOR,
                curved: bool | None = None) -> tuple[Face, list[str]]:
    """Detect rings (and knots) on one face with a photo; returns a new Face and warnings.

    ``detector``: ``"classical"`` (:func:`~woodcam.detect.rings.detect_rings` with ``rule``) or
    ``"learned"`` (:func:`~woodcam.detect.learned.detect_rings_learned`, the committed net).
    ``curved``: the classical detector places and orders the rings by the curved Gabor's phase
    (:mod:`woodcam.detect.curved`); default (None) :data:`~woodcam.detect.rings.CURVED_GABOR`, off.
    The face's existing extras are kept; ``knot_mask`` is replaced by the detected one when
    ``knots`` (an empty mask is not stored).
    """
    if face.photo is None:
        raise WoodcamError(f"face {face.name!r} has no photo to detect rings on; add its photo")
    if detector not in DETECTORS:
        raise WoodcamError(f"detector must be one of {', '.join(DETECTORS)}; got {detector!r}")
    if curved and detector != "classical":
        raise WoodcamError(f"curved=True is an option of the classical detector; got detector={detector!r}: "
                           f"drop curved or use detector='classical'")
    if detector == "classical":
        _check_face_memory(face, px_per_mm)
    if detector == "learned":
        from .learned import detect_rings_learned

        det = detect_rings_learned(face.photo, px_per_mm=px_per_mm, name=face.name)
    else:
        det = detect_rings(face.photo, px_per_mm=px_per_mm, rule=rule, name=face.name, curved=curved)
    extras = dict(face.extras)
    if knots:
        mask = detect_knots(face.photo, px_per_mm, det.normal_rad)
        extras.pop("knot_mask", None)
        if mask.any():
            extras["knot_mask"] = mask
    ring_map = det.ring_map if det.traces else None
    return Face(face.name, face.shape, photo=face.photo, traces=list(det.traces), ring_map=ring_map,
                extras=extras), list(det.warnings)


def _check_face_memory(face: Face, px_per_mm: float) -> None:
    """Refuse, before any allocation, a face whose detection would need more memory than
    ``MAX_ALLOC_BYTES`` (:data:`DETECT_BYTES_PER_PX`): it was killed by the system or swapped for
    minutes, with nothing said. The fix names the density that fits."""
    import math

    from ..limits import check_limit, limit

    rows, cols = face.shape
    need = float(rows) * cols * DETECT_BYTES_PER_PX
    fits = math.floor(10 * px_per_mm * math.sqrt(limit("MAX_ALLOC_BYTES") / need)) / 10
    check_limit("MAX_ALLOC_BYTES", need,
                f"ring detection on face {face.name!r} ({cols}x{rows} px at {px_per_mm:.3g} px/mm; memory)",
                fix=f"make the block again with 'woodcam block from-photos ... --max-px-per-mm {fits:g}' or lower "
                "(the default 10 keeps rings 0.8 mm apart at 8 px)")


def _detect_face_cached(face: Face, px_per_mm: float, rule: BoundaryRule, knots: bool,
                        curved: bool | None) -> tuple[Face, list[str]]:
    """:func:`detect_face` (classical detector) of ``face``, cached by content: one entry per
    face photo, density, rule, curved, knots and :data:`DETECT_VERSION` in the ``detect`` cache.
    The face's other extras are kept as :func:`detect_face` keeps them."""
    _check_face_memory(face, px_per_mm)  # a cached face too: the limit holds whatever the cache holds

    def build():
        found, msgs = detect_face(Face(face.name, face.shape, photo=face.photo), px_per_mm, rule, knots,
                                  "classical", curved)
        return {face.name: found}, msgs

    key = digest("detect-face", DETECT_VERSION, rule, _curved(curved), "classical", bool(knots), float(px_per_mm),
                 np.asarray(face.photo))
    raw, hit = load_or_build(entry_path(cache_dir("detect"), face.name, key),
                             load=lambda p: _load_detection(p, {face.name: face.shape}), build=build,
                             save=_save_detection, what="ring detection")
    if hit:
        traces, ring_map, found = raw[0][face.name]
    else:
        f = raw[0][face.name]
        traces, ring_map, found = f.traces, f.ring_map, f.extras
    extras = dict(face.extras)
    if knots:
        extras.pop("knot_mask", None)
    return Face(face.name, face.shape, photo=face.photo, traces=list(traces), ring_map=ring_map,
                extras={**extras, **found}), list(raw[1])


def detect_block(block: Block, *, rule: BoundaryRule = DEFAULT_RULE, knots: bool = True,
                 faces=None, progress: bool = False,
                 detector: Detector = DEFAULT_DETECTOR, curved: bool | None = None,
                 cache: bool = False) -> tuple[Block, list[str]]:
    """A copy of ``block`` whose faces with photos carry detected rings and knot masks.

    ``faces``: only these faces (default all with a photo); the others are copied unchanged.
    ``curved``: as :func:`detect_face`. ``cache``: each face of the classical detector read from
    woodcam's cache when detected before (:func:`_detect_face_cached`).
    Returns the block and the warnings (each names its face).
    """
    from .._progress import progress_bar

    out = copy.copy(block)
    out.faces = dict(block.faces)
    out.meta = dict(block.meta)
    names = [n for n, f in block.faces.items() if f.photo is not None and (faces is None or n in faces)]
    if not names:
        raise WoodcamError(f"block {block.name!r} has no face photos to detect rings on; "
                           f"make the block with 'woodcam block from-photos'")
    msgs: list[str] = []
    for name in progress_bar(names, desc="detecting rings", unit="face", enabled=progress):
        px_mm = block.face_pixel_size_mm(name)
        if cache and detector == "classical":
            out.faces[name], w = _detect_face_cached(block.faces[name], 1.0 / min(px_mm), rule, knots, curved)
        else:
            out.faces[name], w = detect_face(block.faces[name], 1.0 / min(px_mm), rule, knots, detector, curved)
        msgs += w
    out.meta["detection"] = {"detector": detector, "version": DETECT_VERSION, "rule": rule,
                             "curved": _curved(curved), "faces": names}
    return out, msgs


# -- block folders ---------------------------------------------------------------------------------

def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _detection_record(folder: Path) -> dict:
    """What the last detection in block folder ``folder`` wrote: ``svg_sha256`` and
    ``photo_digest`` (face -> digest) and ``traces_svg`` (face -> SVG name), from its manifest;
    a manifest remade by ``block from-photos`` keeps them as ``meta["detection_before"]``
    (:func:`detection_record`). Empty when none was recorded."""
    from ..block.io import MANIFEST

    m = json.loads((folder / MANIFEST).read_text())
    meta = m.get("meta", {}) if isinstance(m, dict) else None
    faces = m.get("faces", {}) if isinstance(m, dict) else None
    if not (isinstance(meta, dict) and isinstance(faces, dict)
            and all(isinstance(e, dict) for e in faces.values())
            and isinstance(meta.get("detection") or {}, dict) and isinstance(meta.get("detection_before") or {}, dict)):
        raise ValueError("not an object with a 'meta' object and a 'faces' object of faces")
    if meta.get("detection"):
        return {**meta["detection"], "traces_svg": {n: e["traces_svg"] for n, e in faces.items()
                                                     if e.get("traces_svg")}}
    return meta.get("detection_before") or {}


def _readable_record(folder: Path) -> dict | None:
    """:func:`_detection_record` of a folder about to be written over; None, with a warning that
    it is overwritten, when its manifest is cut short or another JSON (it was an internal error
    of 'block from-photos' and of 'rings detect ... --out FOLDER')."""
    from ..block.io import MANIFEST

    try:
        return _detection_record(folder)
    except ValueError as err:
        warnings.warn(f"{str(folder / MANIFEST)!r} is no readable block manifest ({err}): it is "
                      "overwritten, and no corrected SVG it recorded is kept (the next 'rings detect' "
                      "draws every <face>_traces.svg there afresh; move a corrected one out first)",
                      WoodcamWarning, stacklevel=3)
        return None


def detection_record(folder) -> dict | None:
    """The detection record of the block folder ``folder`` (its SVGs' and photos' digests, the
    SVGs' names and, as ``named``, the files of the user's block.json names under other names than
    detection's; those still in the folder), for ``block from-photos`` to keep in the
    manifest it writes there (``meta["detection_before"]``); None without one.

    A block remade into its own folder (a photo turned, as the layout check asks) dropped the
    record, and the next 'rings detect' took the corrected SVGs for the detector's and
    overwrote them: kept, a correction of an unchanged photo stays and one of a changed photo is
    refused (:func:`detect_folder`)."""
    from ..block.io import MANIFEST

    folder = Path(folder)
    if not (folder / MANIFEST).is_file():
        return None
    rec = _readable_record(folder)
    if rec is None:
        return None
    svgs = {n: svg for n, svg in (rec.get("traces_svg") or {}).items()
            if isinstance(svg, str) and (folder / svg).is_file()}
    # the images the detection made stay on disk under a remade manifest (which names none):
    # their digests kept, the next detection clears those it does not write again
    images = _file_digests(rec)
    # the files block.json names under other names than detection's are the user's: the remade
    # manifest names none, so without their names here the next detection named its own ring
    # maps and knot masks and dropped the user's from the block without a word
    named: dict[str, dict[str, str]] = {}
    for (face, kind), rel in _named_users_files(folder).items():
        if (folder / rel).is_file():
            named.setdefault(face, {})[kind] = rel
    if not svgs and not images and not named:
        return None
    return {"traces_svg": svgs, "svg_sha256": rec.get("svg_sha256", {}),
            "photo_digest": rec.get("photo_digest", {}), "file_digest": images, "named": named,
            **({"carried": rec["carried"]} if isinstance(rec.get("carried"), dict) else {})}


def user_edited_faces(folder) -> dict[str, Path]:
    """Faces of a block folder whose ``<face>_traces.svg`` differs from what the detector wrote
    (a user corrected it) -> the SVG path."""
    folder = Path(folder)
    rec = _readable_record(folder)
    if rec is None:  # an --out folder whose manifest is unreadable: written over, as from-photos does
        return {}
    written = rec.get("svg_sha256", {})
    out = {}
    for name, svg in rec.get("traces_svg", {}).items():
        if svg and (folder / svg).is_file() and _sha256(folder / svg) != written.get(name):
            out[name] = folder / svg
    return out


def _unrecorded(folder: Path) -> bool:
    """Whether no detection is recorded in the block folder ``folder``: no manifest, or one with
    no detection record (kept or not; :func:`_detection_record`). Detection did not write the
    files of its names there (a user put hand-made ones beside the photos before ever detecting,
    or a sample came with them), so they are the user's (:func:`detect_folder`). An unreadable
    manifest is not: it is written over, as :func:`_readable_record` says."""
    from ..block.io import MANIFEST

    if not (folder / MANIFEST).is_file():
        return True
    try:
        return not _detection_record(folder)
    except (ValueError, OSError):
        return False


#: The files of a face detection writes, by kind, under their default names (:func:`_named_users_files`).
_DEFAULT_NAMES = {"traces_svg": "{}_traces.svg", "ring_map": "{}_ring_map.png", "knot_mask": "{}_knot_mask.png"}


def _named_users_files(folder: Path) -> dict[tuple[str, str], str]:
    """(face, kind) -> the name block.json in ``folder`` gives a face's traces SVG, ring map or
    knot mask (:data:`_DEFAULT_NAMES`) when it is not the name detection writes: detection never
    wrote such a file, so it is the user's, kept and used as one under the default name is
    (it was replaced in the manifest without a word). A manifest 'block from-photos' remade names
    them in its record of the earlier detection (``meta["detection_before"]["named"]``, face ->
    {kind: name}; :func:`detection_record`). Empty without a readable manifest."""
    from ..block.io import MANIFEST

    try:
        m = json.loads((folder / MANIFEST).read_text())
    except (OSError, ValueError):
        return {}
    faces = m.get("faces") if isinstance(m, dict) else None
    meta = m.get("meta") if isinstance(m, dict) else None
    before = (meta.get("detection_before") or {}) if isinstance(meta, dict) else {}
    kept = before.get("named") if isinstance(before, dict) else None
    found = {}
    faces = faces if isinstance(faces, dict) else {}
    # a face the remade block lacks (--partial without its photo) too: its files are said unused,
    # where they were left unnamed without a word
    gone = {n: {} for n in (kept if isinstance(kept, dict) else {}) if n in FACES and n not in faces}
    for name, e in [*faces.items(), *gone.items()]:
        if not isinstance(e, dict):
            continue
        knot = (e.get("extras") or {}).get("knot_mask") if isinstance(e.get("extras"), dict) else None
        was = kept.get(name) if isinstance(kept, dict) else None
        for kind, rel in (("traces_svg", e.get("traces_svg")), ("ring_map", e.get("ring_map")),
                          ("knot_mask", knot.get("png") if isinstance(knot, dict) else None)):
            if rel is None and isinstance(was, dict):
                rel = was.get(kind)
            if isinstance(rel, str) and rel and rel != _DEFAULT_NAMES[kind].format(name):
                found[name, kind] = rel
    return found


def _name_in(out: Path, path: Path) -> str:
    """The name the manifest in ``out`` gives the user's file ``path`` it keeps: its own, relative,
    when it lies in ``out``; else its file name, the copy's (:func:`detect_folder`)."""
    try:
        return path.resolve().relative_to(out.resolve()).as_posix()
    except ValueError:
        return path.name


def _named_why(default: str) -> str:
    """Why a file block.json names under another name than detection's is the user's."""
    return f"block.json names it for the face, and detection writes only {default}"


#: Why a file of detection's name in a folder with no detection recorded is the user's (:func:`_unrecorded`).
_NO_RECORD = "no detection is recorded in that folder, so detection did not write it"


#: The end of the kept line's fix in 'rings detect' (:func:`_kept_users_line`); fit, bake and
#: eval detect a photo-only face themselves, so theirs is :data:`_RUN_AGAIN`.
_DETECT_AGAIN = "run 'rings detect' again"
_RUN_AGAIN = "run again"


def _kept_users_line(name: str, kept: str, folder: Path, why: str, copy: Path | None = None,
                     again: str = _DETECT_AGAIN) -> str:
    """The one line saying face ``name``'s file of the user's (``kept``: "the edited PATH" ...),
    found in ``folder``, was kept over detection, ``why`` it is the user's, and how to let
    detection replace it (delete it and ``again``, what the command that says it takes):
    said alike of corrected SVGs, edited images and hand-made files.
    ``copy``: where it was carried into another ``--out``, which is never the detector's either,
    so it wins the next time unless deleted too (deleting the source's alone did nothing)."""
    where = (f"delete it (or move it out of {str(folder)!r})" if copy is None else
             f"delete it and its copy {copy} (or move them out of {str(folder)!r} and {str(copy.parent)!r})")
    return (f"face {name!r}: kept {kept} ({why}): it wins over detection; to let detection replace it, {where} "
            f"and {again}")


def _copy_name(out: Path, path: Path, name: str, kind: str, named: Collection[Path]) -> str:
    """The name in ``out`` of face ``name``'s image of ``kind`` of the user's, ``path``: one
    block.json names under another name than detection's (``named``) under that name
    (:func:`_name_in`), any other as the face's ``<face>_<kind>.png``."""
    return _name_in(out, path) if path in named else f"{name}_{kind}.png"


def _users_digest(path: Path, kind: str, shape) -> str:
    """Digest of the user's file ``path`` of ``kind`` (``"traces_svg"`` or :data:`DETECTED_IMAGES`)
    as the face takes it: an SVG's bytes (carried as they are), an image's pixels as read
    (:func:`_read_users_image`: an 8-bit map and its 16-bit copy in --out alike)."""
    if kind == "traces_svg":
        return _sha256(path)
    return digest(_read_users_image(path, kind, shape))


def _source_or_copy(block: Block, name: str, kind: str, source: Path | None, copy: Path, out: Path,
                    out_rec: dict) -> Path:
    """Which of face ``name``'s two files of ``kind`` of the user's wins: ``source`` (in the
    source folder; None when it holds none) or ``copy`` (in another ``--out`` folder ``out``, of
    record ``out_rec``). A copy an earlier run carried there won every run after, so an edit the user
    made in the source since was passed over without a word. Now the run's record of what it
    carried (``carried``: name in --out -> :func:`_users_digest`) tells which was edited since:
    that one wins (the source's is carried again); the same content, the source's (said with its
    copy). Both edited since, or two different files with no carry recorded, are refused in one
    line naming both: either may be the one the user means, and the source's would write over the
    other."""
    if source is None or name not in block.faces:
        return copy
    shape = block.faces[name].shape
    now_src, now_copy = _users_digest(source, kind, shape), _users_digest(copy, kind, shape)
    carried = out_rec.get("carried")
    was = carried.get(_name_in(out, copy)) if isinstance(carried, dict) else None
    if now_src == now_copy or now_copy == was:
        return source
    if now_src == was:
        return copy
    what = "traces SVG" if kind == "traces_svg" else DETECTED_IMAGES[kind][0]
    why = ("both were edited since an earlier 'rings detect' carried the one into the other" if was is not None else
           "no earlier 'rings detect' recorded carrying the one into the other")
    raise WoodcamError(f"face {name!r}: your {source} and {copy} in --out are both your {what} of the face and differ "
                       f"({why}): which is the face's? keep the one you mean: delete (or move out) the other and run "
                       "again")


def _copy_in(out: Path | None, path: Path, name: str) -> Path | None:
    """The copy in ``out`` of the user's file ``path`` kept under ``name`` there; None when it is
    that file itself (or no ``out``)."""
    if out is None or (out / name).resolve() == path.resolve():
        return None
    return out / name


#: The images detection writes per face (:mod:`woodcam.block.io` names them ``<face>_<kind>.png``),
#: recorded by digest so a rerun clears or writes over only its own (module docstring): kind ->
#: (what it is, in words; why a face has none after a detection).
DETECTED_IMAGES = {"ring_map": ("ring map", "no rings were found on it"),
                   "knot_mask": ("knot mask", "no knot was found on it")}


def _image(face: Face | None, kind: str):
    """Face ``face``'s image of ``kind`` (:data:`DETECTED_IMAGES`), or None."""
    if face is None:
        return None
    return face.ring_map if kind == "ring_map" else face.extras.get(kind)


def _pixels_digest(kind: str, image) -> str:
    """Digest of ``image`` of ``kind`` as :func:`~woodcam.block.io.write_block` stores it (a ring
    map 16-bit, a knot mask 0/255 read back as bool), what :func:`_file_digest` reads back."""
    from ..block.io import _quantise

    if kind == "ring_map":
        return digest(_quantise(image, 16, "ring map"))
    return digest(np.asarray(image, bool))


def _file_digest(path: Path, kind: str) -> str | None:
    """:func:`_pixels_digest` of the image file ``path``; None when it cannot be read as one."""
    from .._readers import read_image_file

    try:
        raw = read_image_file(path, DETECTED_IMAGES[kind][0])
    except WoodcamError:
        return None
    return digest(raw) if kind == "ring_map" else digest(np.asarray(raw > 127, bool))


def _read_users_image(path: Path, kind: str, shape) -> np.ndarray:
    """A user's image of ``kind`` as :func:`~woodcam.block.io.read_block` reads the face's."""
    from .._readers import read_image_file
    from ..block.io import _check_shape, _ring_map_of

    raw = read_image_file(path, f"the edited {path.name}")
    if raw.ndim == 3:
        raw = raw[..., 0]
    _check_shape(raw, shape, f"the edited {path}")
    if kind == "knot_mask":
        return raw > 127
    return _ring_map_of(raw)


def _file_digests(rec: dict | None) -> dict[str, str]:
    """file name -> digest of each image a detection record says the detector wrote (``file_digest``)."""
    got = (rec or {}).get("file_digest")
    return {n: d for n, d in got.items() if isinstance(d, str)} if isinstance(got, dict) else {}


def _prior_record(folder: Path) -> dict:
    """The detection record of the block folder ``folder``'s manifest; empty without one (an
    unreadable one is said by :func:`_readable_record` where it is read)."""
    from ..block.io import MANIFEST

    if not (folder / MANIFEST).is_file():
        return {}
    try:
        return _detection_record(folder)
    except (ValueError, OSError):
        return {}


def _edited_images(block: Block, folders: list[tuple[Path, dict, dict[tuple[str, str], str]]],
                   unrecorded: Collection[Path] = (),
                   changed: list[tuple[str, str, Path]] | None = None) -> dict[tuple[str, str], Path]:
    """(face, kind) -> the file of each image of ``block``'s faces in one of ``folders`` (folder,
    its record before this run; the output first) that is no longer the one the detector wrote
    there: a user edited it (or made it by hand beside a recorded detection). A record without
    digests (made before they were) has its images written over, as they were then. In the
    folders ``unrecorded`` (the source and output with no detection recorded, :func:`_unrecorded`)
    every such image is the user's: detection wrote none there, nor any the folder's block.json
    names under another name than its own (each folder's third item, :func:`_named_users_files`).

    Refused, as a corrected SVG is (:func:`_check_corrections_match_photos`), when the record
    says it was made over another photo than the face's now: it is not this photo's; with
    ``changed`` (fit, bake and eval of a remade block, :func:`_users_files_of_a_remade_block`)
    such an image is not refused but left out and listed there as (face, kind, file)."""
    found: dict[tuple[str, str], Path] = {}
    for name, f in block.faces.items():
        for kind, (what, _) in DETECTED_IMAGES.items():
            for folder, rec, named in folders:
                path = folder / named.get((name, kind), f"{name}_{kind}.png")
                if not path.is_file():  # one named and deleted: detection writes its own
                    path = folder / f"{name}_{kind}.png"
                mine = (name, kind) in named and path != folder / f"{name}_{kind}.png"
                if not mine and (("file_digest" not in rec and folder not in unrecorded) or not path.is_file()
                                 or _file_digest(path, kind) == _file_digests(rec).get(path.name)):
                    continue
                was = (rec.get("photo_digest") or {}).get(name)
                if was is not None and f.photo is not None and was != photo_digest(f.photo):
                    if changed is not None:
                        changed.append((name, kind, path))
                        break
                    raise WoodcamError(
                        f"face {name!r}: the edited {path} was made over another {name} photo than this block's "
                        f"(the photo changed since, or --out holds an earlier block's detection): it is not this "
                        f"photo's {what}, and detecting would write over it; {_move_out_fix(path)}")
                found[name, kind] = path
                break
    return found


def _keep_users_images(block: Block, edited: dict[tuple[str, str], Path],
                       unrecorded: Collection[Path] = (), named: Collection[Path] = (),
                       out: Path | None = None, again: str = _DETECT_AGAIN) -> tuple[set[tuple[str, str]], list[str]]:
    """Each image of ``block``'s faces (just detected) whose file the user edited (``edited``:
    :func:`_edited_images`; in ``unrecorded``, or ``named`` by block.json under another name than
    detection's (:func:`_named_users_files`), made by hand): the user's is read into ``block``
    as the face's, so it is what is written and read, as a corrected SVG wins; also on a face
    where detection made none of that kind (no knot or rings found, ``--no-knots``), where it was
    kept unread and the user told to name it in block.json. Returns the names of the files kept
    and the warnings."""
    kept: set[tuple[str, str]] = set()
    msgs = []
    for (name, kind), path in edited.items():
        f = block.faces[name]
        # on a face detection made none for, the user's is the only one: said, as it is all there is
        none = "" if _image(f, kind) is not None else "; detection made none for the face this time"
        mine = _read_users_image(path, kind, f.shape)
        block.faces[name] = (Face(name, f.shape, photo=f.photo, traces=f.traces, ring_map=mine, extras=f.extras)
                             if kind == "ring_map" else
                             Face(name, f.shape, photo=f.photo, traces=f.traces, ring_map=f.ring_map,
                                  extras={**f.extras, kind: mine}))
        kept.add((name, kind))
        why = (_named_why(_DEFAULT_NAMES[kind].format(name)) if path in named else
               _NO_RECORD if path.parent in unrecorded else
               f"it is not the {DETECTED_IMAGES[kind][0]} detection wrote there")
        mine = path in named or path.parent in unrecorded
        # carried into another --out: a named one under its own name, any other as the face's image
        copy = None if out is None else _copy_in(out, path, _copy_name(out, path, name, kind, named))
        msgs.append(_kept_users_line(name, f"your {path}" if mine else f"the edited {path}", path.parent, why + none,
                                     copy, again))
    return kept, msgs


def _clear_stale_files(out: Path, block: Block, before: dict, svgs: dict[str, str] | None = None,
                       existing: dict[str, dict[str, str]] | None = None) -> list[str]:
    """Remove each file of detection (``<face>_traces.svg``, :data:`DETECTED_IMAGES`) in ``out``
    that ``block`` (just written there) does not name, when it is the one the detector wrote
    (``before``: the folder's detection record before this run): a previous run's file of a face
    with no rings or knot found now, or no such face, or whose manifest names the user's file
    under another name (``svgs``: face -> its SVG's name, ``existing``: face -> {kind: name}, as
    given to :func:`~woodcam.block.io.write_block`), stayed beside the new manifest. Any other
    such file is kept and said, but a corrected SVG (said by its caller); returns the warnings."""
    ours_img, ours_svg = _file_digests(before), before.get("svg_sha256") or {}
    corrected = set((before.get("traces_svg") or {}).values())
    msgs = []
    for name in FACES:
        face = block.faces.get(name)
        svg = out / f"{name}_traces.svg"
        other = (svgs or {}).get(name, svg.name) if face is not None else svg.name
        if (face is None or other != svg.name) and svg.is_file():
            if isinstance(ours_svg, dict) and ours_svg.get(name) == _sha256(svg):
                svg.unlink()
            elif face is not None:
                msgs.append(f"face {name!r}: {svg.name} in {str(out)!r} is not read (block.json names {other} for "
                            f"the face), and is kept: it is not the SVG an earlier detection wrote; delete it, "
                            f"or move it out to keep it")
            elif svg.name not in corrected:
                msgs.append(f"face {name!r}: {svg.name} in {str(out)!r} is not read (the block has no such face, "
                            f"and block.json does not name it), and is kept: it is not the SVG an earlier "
                            f"detection wrote; delete it, or move it out to keep it")
        for kind, (what, why) in DETECTED_IMAGES.items():
            path = out / f"{name}_{kind}.png"
            elsewhere = ((existing or {}).get(name) or {}).get(kind)
            if not path.is_file() or (_image(face, kind) is not None and elsewhere is None):
                continue  # none, or this detection's own (written over), or the user's kept (read in)
            if ours_img.get(path.name) is not None and _file_digest(path, kind) == ours_img[path.name]:
                path.unlink()
                continue
            if elsewhere is not None:
                msgs.append(f"face {name!r}: {path.name} in {str(out)!r} is not read (block.json names {elsewhere} "
                            f"for the face), and is kept: it is not the {what} an earlier detection made; delete "
                            f"it, or move it out to keep it")
                continue
            # of a face the block lacks, naming it in block.json (and detecting with --no-knots) was
            # the fix said, which cannot be done: no face entry to name it in
            use = ("move it out to keep it" if face is None else
                   "to use it name it in block.json as the face's extras knot_mask and detect with --no-knots"
                   if kind == "knot_mask" else "to use it name it in block.json as the face's ring_map")
            why = why if face is not None else "the block has no such face"
            msgs.append(f"face {name!r}: {path.name} in {str(out)!r} is not read ({why} this time, and block.json does "
                        f"not name it), and is kept: it is not the {what} an earlier detection made (edited, made by "
                        f"hand, or from before woodcam recorded them); delete it, or {use}")
    return msgs


def _check_corrections_match_photos(block: Block, edited: dict[str, Path]) -> None:
    """Refuse a corrected SVG drawn over another photo than ``block``'s face photo now.

    Detecting a new block into the folder of an earlier one (``rings detect NEW --out OLD``), or
    a face photo replaced after its SVG was corrected, kept the old correction as the new
    photo's rings without a word (a face turned 90 degrees since took rings drawn across it).
    Its manifest records the digest of each face photo it traced (``photo_digest``); folders
    written before it was recorded cannot be checked."""
    for name, svg in edited.items():
        was = _prior_record(svg.parent).get("photo_digest", {}).get(name)
        photo = block.faces[name].photo
        if was is not None and photo is not None and was != photo_digest(photo):
            raise WoodcamError(
                f"face {name!r}: the corrected {svg} was traced over another {name} photo than this "
                f"block's (the photo changed since, or --out holds an earlier block's detection): its "
                f"rings are not this photo's, and detecting would overwrite the correction; {_move_out_fix(svg)}")


def _changed_photo_line(name: str, kept: str, path: Path, what: str) -> str:
    """The one line saying face ``name``'s file of the user's (``kept``: "the corrected PATH" ...;
    ``what``: "rings", "ring map" or "knot mask"), made over another photo than the face's now,
    is not used by fit, bake and eval (the face's are detected), with the fix 'rings detect' gives
    when it refuses it (:func:`_move_out_fix`): said alike of corrected SVGs and edited images."""
    made, its = (("traced", "its rings are not this photo's, so they are") if what == "rings" else
                 ("made", f"it is not this photo's {what}, so it is"))
    return (f"face {name!r}: {kept} was {made} over another {name} photo than this block's (the photo changed "
            f"since): {its} not used here ({name}'s {what} {'are' if what == 'rings' else 'is'} detected) and "
            f"'rings detect' will refuse it; {_move_out_fix(path)}")


def _move_out_fix(path: Path) -> str:
    """The fix for the user's file ``path`` made over another photo than its face's now (refused
    by 'rings detect', said by fit, bake and eval): one wording wherever it is given."""
    return f"move {path.name} out of {str(path.parent)!r} (or detect into another --out) and run again"


def _keep_users_svg(block: Block, name: str, svg: Path, named: bool, unrecorded: bool,
                    out: Path | None = None, again: str = _DETECT_AGAIN) -> tuple[list, str]:
    """Face ``name`` of ``block`` takes its rings from the user's SVG ``svg`` (corrected, made by
    hand, or ``named`` by block.json under another name; found in a folder with no detection
    ``unrecorded``): its traces and the ring map drawn from them, in place. Returns the traces and
    the line that says it (carried into ``out`` when another folder, :func:`_copy_in`)."""
    from ..block.svg import read_traces_svg

    f = block.faces[name]
    traces = read_traces_svg(svg, f.shape)
    px = 1.0 / min(block.face_pixel_size_mm(name))
    ring_map = ring_map_from_traces(traces, f.shape, RING_MAP_SIGMA_MM * px) if traces else None
    block.faces[name] = Face(name, f.shape, photo=f.photo, traces=list(traces), ring_map=ring_map, extras=f.extras)
    # the full path, as an image's: which of two folders (source, --out) it was kept from
    return traces, _kept_users_line(name, f"{'your' if named or unrecorded else 'the corrected'} {svg}",
                                    svg.parent, f"{len(traces)} trace{'' if len(traces) == 1 else 's'}; " + (
                                        _named_why(f"{name}_traces.svg") if named
                                        else _NO_RECORD if unrecorded
                                        else "it is not the SVG detection wrote there"),
                                    None if out is None else _copy_in(out, svg, _name_in(out, svg)), again)


def _users_files_of_a_remade_block(block: Block, folder: Path) -> list[str]:
    """The user's files in the block folder ``folder`` read into ``block`` (its faces just
    detected on their photos), as the next :func:`detect_folder` would keep them: a manifest
    'block from-photos' made again names none of them (its record of the earlier detection keeps
    them, :func:`detection_record`), so fit, bake and eval right after the remake detected every
    face and passed them over without a word. A corrected SVG (or one block.json named under
    another name) and an edited or named ring map or knot mask win, each face whose photo is the
    one they were made over; a changed photo's corrected SVG, edited ring map or knot mask is
    said unused, with the fix 'rings detect' gives when it refuses it (:func:`_changed_photo_line`).
    Returns the lines that say each."""
    rec = _prior_record(folder)
    if not rec:
        return []
    was = rec.get("photo_digest") or {}
    same = copy.copy(block)
    same.faces = {n: f for n, f in block.faces.items()
                  if f.photo is not None and was.get(n) in (None, photo_digest(f.photo))}
    named = _named_users_files(folder)
    svgs = {**user_edited_faces(folder), **{n: folder / rel for (n, kind), rel in named.items()
                                            if kind == "traces_svg" and (folder / rel).is_file()}}
    # deleted, the next fit (bake, eval) detects the face itself: no 'rings detect' needed
    msgs = [_keep_users_svg(same, n, svg, (n, "traces_svg") in named, False, again=_RUN_AGAIN)[1]
            for n, svg in svgs.items() if n in same.faces]
    # a changed photo's correction or edited image is not read in, and not passed over without a
    # word either (an edited ring map or knot mask was)
    msgs += [_changed_photo_line(n, f"{'your' if (n, 'traces_svg') in named else 'the corrected'} {svg}", svg, "rings")
             for n, svg in svgs.items()
             if n in block.faces and block.faces[n].photo is not None and n not in same.faces]
    photos = copy.copy(block)
    photos.faces = {n: f for n, f in block.faces.items() if f.photo is not None}
    changed: list[tuple[str, str, Path]] = []
    images = _edited_images(photos, [(folder, rec, named)], changed=changed)
    mine = {folder / rel for rel in named.values()}
    msgs += _keep_users_images(same, images, (), mine, again=_RUN_AGAIN)[1]
    msgs += [_changed_photo_line(n, f"{'your' if path in mine else 'the edited'} {path}", path,
                                 DETECTED_IMAGES[kind][0]) for n, kind, path in changed]
    block.faces.update(same.faces)
    return msgs


def detect_folder(src, out, *, rule: BoundaryRule = DEFAULT_RULE, knots: bool = True,
                  size_mm=None, progress: bool = False,
                  detector: Detector = DEFAULT_DETECTOR, curved: bool | None = None) -> tuple[Path, list[str]]:
    """Detect rings and knots on a block folder (or a Mokume sample folder, whose U-Net maps are
    ignored and re-detected from its photos) and write the result as a block folder ``out``.

    Faces whose SVG a user corrected (module docstring) keep it: their rings come from it.
    ``out`` may be ``src`` itself. ``curved``: as :func:`detect_face`. Returns the manifest path
    and the warnings.
    """
    from ..block.io import MANIFEST, read_block_folder, write_block
    from ..block.photos import mokume_maps, mokume_maps_said
    from ..block.svg import write_traces_svg

    src, out = Path(src), Path(out)
    if not src.is_dir():  # a photo given for its folder was said 'does not exist'
        raise WoodcamError(f"block folder {str(src)!r} "
                           f"{'is a file, not a folder' if src.exists() else 'does not exist'}; "
                           f"pass a block folder made by 'woodcam block from-photos' or a Mokume sample folder")
    # the one reader of folders: a folder of the user's own photos (front.jpg ...) was 'must hold a
    # block.json or Mokume files; found neither', no word of 'block from-photos'; it says so now.
    # It warns that a size_mm given for a block folder is not used.
    # a file of detection's the user deleted (to let detection replace an edited one, as the line
    # that kept it says) is written again, not 'listed but missing'
    # files block.json names under other names than detection's are the user's, as its own-named
    # ones are (they were replaced in the manifest without a word); one deleted is written again
    same = out.resolve() == src.resolve()
    named_src = _named_users_files(src)
    named_out = named_src if same else _named_users_files(out)
    block = read_block_folder(src, size_mm, regenerated={f"{n}_{k}.png" for n in FACES for k in DETECTED_IMAGES}
                              | {f"{n}_traces.svg" for n in FACES} | {Path(r).name for r in named_src.values()})
    named = {folder / rel for folder, names in ((src, named_src), (out, named_out)) for rel in names.values()}
    mokume_said = []
    if not (src / MANIFEST).is_file():  # a Mokume sample: re-detected from its photos alone
        for f in block.faces.values():
            f.ring_map, f.traces = None, []
            f.extras.pop("knot_mask", None)
        edited = {}
        maps = mokume_maps(src)  # said: the written knot masks and ring maps seemed Mokume's
        mokume_said = [mokume_maps_said(src, maps, "rings and knots are detected on its photos afresh")] if maps else []
    else:
        edited = user_edited_faces(src)
    # with no detection recorded in a block folder, the source or --out, a file of detection's
    # names there is the user's (traced by hand beside the photos before ever detecting): it was
    # written over without a word in --out, and passed over in the source of another --out (a
    # Mokume sample, no block.json, is re-detected from its photos alone, as documented)
    unrecorded = {f for f in {src, out} if _unrecorded(f) and (f == out or (f / MANIFEST).is_file())}

    def hand_made_svgs(folder: Path, named: dict[tuple[str, str], str]) -> dict[str, Path]:
        # (but where block.json names another SVG of the face: that one is the face's)
        return {n: folder / f"{n}_traces.svg" for n in block.faces if folder in unrecorded
                and (folder / f"{n}_traces.svg").is_file()
                and not ((n, "traces_svg") in named and (folder / named[n, "traces_svg"]).is_file())}

    edited.update({n: src / rel for (n, kind), rel in named_src.items()
                   if kind == "traces_svg" and (src / rel).is_file()})
    edited.update(hand_made_svgs(src, named_src))
    # the files the detector wrote, as the source and --out recorded them (before either is overwritten)
    src_rec = _prior_record(src)
    out_rec = src_rec if same else _prior_record(out)
    if not same:
        # corrections made in the output folder of an earlier run win too (only the source's
        # were looked for, and detection overwrote the ones in --out); where the source has the
        # user's own too, the one edited since the last carry wins (the copy won, stale)
        outs = user_edited_faces(out) if (out / MANIFEST).is_file() else {}
        outs.update({n: out / rel for (n, kind), rel in named_out.items()
                     if kind == "traces_svg" and (out / rel).is_file()})
        outs.update(hand_made_svgs(out, named_out))
        edited.update({n: _source_or_copy(block, n, "traces_svg", edited.get(n), svg, out, out_rec)
                       for n, svg in outs.items()})
    # a corrected SVG of a face the block no longer has (made again with --partial without it) was
    # an internal error (KeyError): it is left where it is, unused, and said
    unused = {n: svg for n, svg in edited.items() if n not in block.faces}
    unused_images = [(n, folder / rel) for folder, names in ((src, named_src), (out, named_out))
                     for (n, kind), rel in names.items()
                     if kind != "traces_svg" and n not in block.faces and (folder / rel).is_file()]
    edited = {n: svg for n, svg in edited.items() if n in block.faces}
    _check_corrections_match_photos(block, edited)
    # images the user edited since the detector wrote them, checked before any work as the SVGs
    # are; the source's and --out's of a face resolved as the SVGs are
    images = _edited_images(block, [(out, out_rec, named_out)], unrecorded)
    if not same:
        srcs = _edited_images(block, [(src, src_rec, named_src)], unrecorded)
        images = {(n, kind): (srcs[n, kind] if (n, kind) not in images else
                              _source_or_copy(block, n, kind, srcs.get((n, kind)), images[n, kind], out,
                                              out_rec))
                  for n in block.faces for kind in DETECTED_IMAGES if (n, kind) in images or (n, kind) in srcs}
    todo = [n for n, f in block.faces.items() if f.photo is not None and n not in edited]
    msgs: list[str] = [f"face {n!r}: the corrected {svg} is not used: the block has no {n} face (made "
                       f"without its photo); move it out of {str(svg.parent)!r} to keep it (a later detection "
                       f"of a {n} face writes over it)" for n, svg in unused.items()]
    msgs += [f"face {n!r}: your {path} is not used: the block has no {n} face (made without its photo); move it "
             f"out of {str(path.parent)!r} to keep it" for n, path in dict.fromkeys(unused_images)]
    msgs += mokume_said
    if todo:
        # cached by content: a second run, or one after a single SVG was corrected or a single
        # photo changed, detected every face afresh (a minute or two a large face)
        block, found = detect_block(block, rule=rule, knots=knots, faces=todo, progress=progress,
                                    detector=detector, curved=curved, cache=True)
        msgs += found
    else:
        block.meta = dict(block.meta)
    kept = {}
    for name, svg in edited.items():
        kept[name], said = _keep_users_svg(block, name, svg, svg in named, svg.parent in unrecorded, out)
        block.faces[name].traces = []  # written to the SVG, not the manifest (below)
        msgs.append(said)
    for name, f in block.faces.items():
        # a face with the user's ring map is not left without one (said as kept below)
        if f.photo is not None and not f.traces and name not in kept and (name, "ring_map") not in images:
            msgs.append(f"face {name!r}: no rings found; the face is left without a ring map "
                        f"(trace its rings in {name}_traces.svg if it has some)")
    det_traces = {n: f.traces for n, f in block.faces.items()}
    # The traces live in the SVGs (read back by read_block), not twice in the manifest.
    for f in block.faces.values():
        f.traces = []
    out.mkdir(parents=True, exist_ok=True)
    # the user's SVG carried over unchanged, and named by the manifest as it was (under any name)
    svg_names = {n: _name_in(out, svg) for n, svg in edited.items()}
    for name, svg in edited.items():
        if (out / svg_names[name]).resolve() != svg.resolve():
            write_bytes(out / svg_names[name], svg.read_bytes())
    # The SVGs first, the manifest last and in one step: a manifest written before its SVGs
    # (as it was) named no SVG until they were done, so a Ctrl-C in between made the next run
    # take the user's corrected SVG for the detector's and overwrite it. Interrupted now, the old
    # manifest stays, and a detector SVG written meanwhile differs from its recorded hash: it is
    # then kept as if corrected (a wrong label, never a lost edit).
    hashes = {}
    for name, f in block.faces.items():
        if name in kept:
            continue
        svg = out / f"{name}_traces.svg"
        with atomic_path(svg) as tmp:
            write_traces_svg(Face(name, f.shape, traces=det_traces.get(name, [])), tmp,
                             photo_href=f"{name}_photo.png" if f.photo is not None else None)
        hashes[name] = _sha256(svg)
    block.meta = dict(block.meta)
    block.meta.pop("detection_before", None)  # superseded by this detection's record
    det = dict(block.meta.get("detection") or {"detector": detector, "version": DETECT_VERSION, "rule": rule,
                                               "curved": _curved(curved)})
    det["svg_sha256"] = hashes
    det["photo_digest"] = {n: photo_digest(f.photo) for n, f in block.faces.items() if f.photo is not None}
    det["user_svg"] = sorted(kept)
    # an image the user edited since the detector wrote it wins as a corrected SVG does (it was
    # written over without a word): read in, written back as read, never recorded as the detector's
    users, said = _keep_users_images(block, images, unrecorded, named, out)
    msgs += said
    # a user's image block.json names under its own name stays named so, untouched (carried over
    # unchanged into another --out); one of detection's name is written back as read
    existing: dict[str, dict[str, str]] = {}
    for (name, kind), path in images.items():
        if (name, kind) in users and path in named:
            existing.setdefault(name, {})[kind] = rel = _name_in(out, path)
            if (out / rel).resolve() != path.resolve():
                write_bytes(out / rel, path.read_bytes())
    # the user's files carried from the source into another --out, by their content then: the
    # next run tells which of the two was edited since (:func:`_source_or_copy`); a copy that won
    # (edited since) keeps the record of its carry, so the source's edited since too is refused
    users_in_out = {_name_in(out, p) for p in [*edited.values(), *(images[k] for k in users)]
                    if (out / _name_in(out, p)).resolve() == p.resolve()}
    was_carried = out_rec.get("carried") if isinstance(out_rec.get("carried"), dict) else {}
    det["carried"] = {**{k: d for k, d in was_carried.items() if k in users_in_out and isinstance(d, str)},
                      **{svg_names[n]: _users_digest(svg, "traces_svg", block.faces[n].shape)
                         for n, svg in edited.items() if _copy_in(out, svg, svg_names[n]) is not None},
                      **{_copy_name(out, path, n, kind, named): _users_digest(path, kind, block.faces[n].shape)
                         for (n, kind), path in images.items()
                         if (n, kind) in users and _copy_in(out, path, _copy_name(out, path, n, kind, named))}}
    # the detector's images: this run's (ring maps of faces detected or drawn from a corrected
    # SVG, knot masks detected), and earlier ones kept unchanged (--no-knots, a corrected SVG's
    # face) that were its own; a user's is never recorded, so never cleared nor written over
    fresh = {"ring_map": set(todo) | set(kept), "knot_mask": set(todo) if knots else set()}
    before = _file_digests(src_rec)
    det["file_digest"] = {fname: d for n, f in block.faces.items() for kind in DETECTED_IMAGES
                          if (image := _image(f, kind)) is not None
                          for fname, d in [(f"{n}_{kind}.png", _pixels_digest(kind, image))]
                          if (n, kind) not in users and (n in fresh[kind] or before.get(fname) == d)}
    block.meta["detection"] = det
    # a face photographed turned or mirrored ruins the fit without a word otherwise; a face with no
    # rings found is not judged (its report.unchecked), and its 'no rings found' above says so
    layout = check_face_layout(block)
    msgs += layout.warnings
    # a face too coarse to judge is said, so the silence is not read as its layout holding
    msgs += [f"face {n!r}: not checked for a turned or mirrored photo: {why}"
             for n, why in layout.unchecked.items() if why != NO_RINGS]
    manifest = write_block(block, out, traces_svg={n: svg_names.get(n, f"{n}_traces.svg") for n in block.faces},
                           existing=existing)
    # after the manifest: interrupted before, a stale mask is unnamed, never read
    msgs += _clear_stale_files(out, block, out_rec, svg_names, existing)
    return manifest, msgs


# -- photo-only blocks for fit / bake / eval --------------------------------------------------------

def photos_only(block: Block) -> Block:
    """A copy of ``block`` keeping only its face photos (no traces, ring maps or knot masks):
    what detection starts from, e.g. to re-detect a Mokume sample."""
    out = copy.copy(block)
    out.faces = {n: Face(n, f.shape, photo=f.photo) for n, f in block.faces.items() if f.photo is not None}
    out.meta = dict(block.meta)
    return out


def needs_detection(block: Block) -> bool:
    """True when no face has rings (traces or a ring map) but some face has a photo."""
    return (not any(f.has_rings for f in block.faces.values())
            and any(f.photo is not None for f in block.faces.values()))


def _detection_key(block: Block, rule: str) -> str:
    return digest("detect", DETECT_VERSION, rule, _curved(None), DEFAULT_DETECTOR, list(block.size_mm),
                  {n: f.photo for n, f in block.faces.items() if f.photo is not None})


def _save_detection(value, tmp: Path) -> None:
    """One ``.npz``: per face its traces (vertices, lengths and ring ids, -1 for none), ring map
    (uint16) and knot mask."""
    faces, msgs = value
    arrays = {"warnings": np.array(json.dumps(msgs))}
    for n, f in faces.items():
        pts = [t.points_px for t in f.traces]
        arrays[f"{n}.points"] = np.concatenate(pts) if pts else np.zeros((0, 2))
        arrays[f"{n}.lengths"] = np.array([len(q) for q in pts], np.int64)
        arrays[f"{n}.rings"] = np.array([-1 if t.ring is None else t.ring for t in f.traces], np.int64)
        if f.ring_map is not None:
            arrays[f"{n}.ring_map"] = np.round(np.clip(f.ring_map, 0, 1) * 65535).astype(np.uint16)
        if "knot_mask" in f.extras:
            arrays[f"{n}.knot_mask"] = np.asarray(f.extras["knot_mask"], bool)
    with open(tmp, "wb") as fh:
        np.savez_compressed(fh, **arrays)


def _load_detection(path: Path, shapes: dict[str, tuple[int, int]]):
    """The faces (traces, ring map, knot mask) and warnings of a detection entry written by
    :func:`_save_detection`, for the faces ``shapes`` names (face -> its image's ``(rows, cols)``).
    An entry that does not fit them is broken (a ValueError or WoodcamError, so
    :func:`~woodcam._cache.load_or_build` discards it with a CacheWarning and detects again):
    other faces, a ring map or knot mask of another shape than its face's (every run failed on
    it, 'ring_map of face ... must have shape', until the cache was cleared), traces whose
    lengths do not add up to their points, or fewer ring ids than traces (the traces past them
    were dropped without a word). Each face is checked by :class:`Face`'s own rules."""
    from ..block.block import RingTrace

    with np.load(path) as z:
        msgs = json.loads(str(z["warnings"]))
        names = sorted({k.split(".")[0] for k in z.files if "." in k})
        if names != sorted(shapes):
            raise ValueError(f"it holds the faces {names}, not the {sorted(shapes)} detected")
        faces = {}
        for n in names:
            points, lengths = np.asarray(z[f"{n}.points"], float), np.asarray(z[f"{n}.lengths"])
            rings = np.asarray(z[f"{n}.rings"]) if f"{n}.rings" in z.files else np.full(len(lengths), -1)
            if (points.ndim != 2 or points.shape[1] != 2 or lengths.ndim != 1 or rings.shape != lengths.shape
                    or not np.issubdtype(lengths.dtype, np.integer) or not np.issubdtype(rings.dtype, np.integer)
                    or np.any(lengths < 2) or int(lengths.sum()) != len(points)):
                raise ValueError(f"face {n!r}: {len(lengths)} traces of lengths adding up to "
                                 f"{int(np.sum(lengths))}, {len(rings)} ring ids and points of shape {points.shape} "
                                 "do not match")
            traces = [RingTrace(q, ring=None if k < 0 else int(k))
                      for q, k in zip(np.split(points, np.cumsum(lengths)[:-1]), rings)]
            rm = z[f"{n}.ring_map"].astype(np.float32) / 65535 if f"{n}.ring_map" in z.files else None
            extras = {"knot_mask": z[f"{n}.knot_mask"]} if f"{n}.knot_mask" in z.files else {}
            if "knot_mask" in extras and np.shape(extras["knot_mask"]) != tuple(shapes[n]):
                raise ValueError(f"knot_mask of face {n!r} has shape {np.shape(extras['knot_mask'])}, not the "
                                 f"face's {tuple(shapes[n])}")
            Face(n, shapes[n], traces=traces, ring_map=rm)  # the face's own rules: ring map shape, trace bounds
            faces[n] = (traces, rm, extras)
    return faces, msgs


def with_detected_rings(block: Block, rule: BoundaryRule = DEFAULT_RULE, *, cache: bool = True,
                        progress: bool = False, folder=None) -> Block:
    """``block`` itself when it has rings; otherwise a copy with rings and knots detected on its
    photos, computed once and cached by content (module docstring; :mod:`woodcam._cache`).
    ``folder``: the block folder ``block`` was read from; the user's files a 'block from-photos'
    remake left unnamed there win over detection (:func:`_users_files_of_a_remade_block`).
    Warnings naming faces, and a face that looks turned or mirrored
    (:func:`~woodcam.detect.layout.check_face_layout`), are issued as
    :class:`~woodcam.errors.WoodcamWarning` each time."""
    if not needs_detection(block):
        return block

    def build():
        # each face through its own entry too (as 'rings detect' caches them): keyed by the whole
        # block alone, one photo retaken detected all six faces afresh in fit, bake and eval
        out, msgs = detect_block(block, rule=rule, progress=progress, cache=cache)
        return ({n: f for n, f in out.faces.items() if n in out.meta["detection"]["faces"]}, msgs)

    if cache:
        path = entry_path(cache_dir("detect"), block.name, _detection_key(block, rule))
        shapes = {n: f.shape for n, f in block.faces.items() if f.photo is not None}  # detect_block's faces
        raw, hit = load_or_build(path, load=lambda p: _load_detection(p, shapes), build=build, save=_save_detection,
                                 what="ring detection")
        if not hit:
            raw = ({n: (f.traces, f.ring_map, {k: v for k, v in f.extras.items() if k == "knot_mask"})
                    for n, f in raw[0].items()}, raw[1])
    else:
        faces, msgs = build()
        raw = ({n: (f.traces, f.ring_map, {k: v for k, v in f.extras.items() if k == "knot_mask"})
                for n, f in faces.items()}, msgs)
    faces, msgs = raw
    out = copy.copy(block)
    out.faces = dict(block.faces)
    for n, (traces, ring_map, extras) in faces.items():
        f = block.faces[n]
        out.faces[n] = Face(n, f.shape, photo=f.photo, traces=list(traces), ring_map=ring_map,
                            extras={**f.extras, **extras})
    out.meta = {**block.meta, "detection": {"detector": DEFAULT_DETECTOR, "version": DETECT_VERSION,
                                            "rule": rule, "faces": sorted(faces)}}
    # read from a block folder 'block from-photos' made again: the user's files there win
    msgs = [*msgs, *([] if folder is None else _users_files_of_a_remade_block(out, Path(folder)))]
    # A face photographed turned or mirrored ruins the fit without a word otherwise (detect_folder
    # checked; fit, bake, eval and open_stock came here). Checked on every call, cache hit too (a
    # cached entry made before the check would say nothing); the CLI prints a warning once.
    msgs = [*msgs, *check_face_layout(out).warnings]
    for w in msgs:
        warnings.warn(w, WoodcamWarning, stacklevel=2)
    return out


__all__ = ["DEFAULT_DETECTOR", "DETECTORS", "DETECT_VERSION", "Detector", "detect_block", "detect_face",
           "detect_folder", "needs_detection", "photos_only", "user_edited_faces", "with_detected_rings"]
