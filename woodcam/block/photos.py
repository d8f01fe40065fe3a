"""A block folder from six face photos: find them by name, check them, write the block.

Photos are files in one folder named by face: ``front.jpg``, ``top.png``, ... (any of
``.jpg .jpeg .jfif .jpe .png .tif .tiff .bmp .webp .heic .heif .avif .gif``, any case; read by their
content, whatever the suffix says), or by Mokume letter (``A.jpg`` ... or the
Mokume sample names ``A_col.png`` ...). Each must already be rectified to its face (cropped to
the face's edges, seen from outside, oriented as ``docs/conventions.md`` says).

Checks, each failing with one message naming the faces at fault: every face present (or
``partial``); one file per face; the image's aspect (rows / cols) within
:data:`~woodcam.tolerances.FACE_PIXEL_ASPECT_RTOL` of the face's in ``size_mm`` (every misfit in
one message: photos not cropped to their face are seldom alone); at least
:data:`~woodcam.tolerances.MIN_FACE_PHOTO_PX` px a side; not blank (luminance spread
below :data:`BLANK_STD`), not over- or under-exposed (more than :data:`CLIPPED_SHARE` of the
pixels at the ends of the range). An image file named for no face is named in a warning (or in
the error when faces are missing), never passed over silently; so is a photo with a near-uniform
border unlike the wood on any side (:func:`_uniform_border`: background round the face in
the face's proportions keeps its aspect, a strip beside a face cropped off its centre too); so
are a Mokume sample's ring maps and knot masks beside its photos (:func:`mokume_maps`), not read.
Faces are resampled to one density (the lowest of the photos', at most ``max_px_per_mm``), so
the faces unfold into one cross and ring widths are alike in pixels; each once, from its
original, so a face's pixels depend on the other photos only through that density. A photo
that brings the others down by more than :data:`DENSITY_SPREAD` is named in a warning; so is a greyscale
photo among colour ones (:data:`GREY_CHROMA`).
"""

from __future__ import annotations

import shlex
import warnings
from pathlib import Path
from typing import NamedTuple

import numpy as np

from .._readers import read_photo_rgb
from ..errors import WoodcamError, WoodcamWarning
from ..frames import (
    FACE_OF_LETTER,
    FACES,
    MOKUME_LETTER,
    check_size,
    face_image_size_mm,
)
from ..tolerances import FACE_PIXEL_ASPECT_RTOL, MIN_FACE_PHOTO_PX
from .block import Block, Face

# .jfif and .jpe: JPEGs as browsers and some phones save them (a front.jfif was passed over
# without a word); .avif: a phone camera's newer format (Pillow reads it)
PHOTO_SUFFIXES = (".jpg", ".jpeg", ".jfif", ".jpe", ".png", ".tif", ".tiff", ".bmp", ".webp", ".heic", ".heif",
                  ".avif", ".gif")
#: A photo whose luminance standard deviation is below this (fraction of full scale) is blank.
BLANK_STD = 0.01
#: A photo with more than this share of pixels at <= 3 or >= 252 (of 255) is badly exposed.
CLIPPED_SHARE = 0.4
#: A photo's edge line is background-like where it varies (std, after a straight-line trend such
#: as light falling off is taken out, of the smoothed grey) by less than this share of the wood's
#: median line; Mokume's faces and woodcam's synthetic ones stay above 0.5 on all four sides.
BORDER_TEXTURE_RATIO = 0.3
#: ... and its mean colour is within this (of 255, any channel) of the outermost line's: a
#: background band (a mat, a scanner lid) keeps one colour line after line, where a face's edge
#: lines drift with its rings. Set with BORDER_COLOUR_STEP on the 12 Mokume face photos (and
#: their x2 and x0.5 rescales), 126 synthetic faces and 174 copies of them given a border:
#: the faces unflagged, the borders found; a review flagged 0 of 108 Mokume variants.
BORDER_COLOUR_TOL = 10.0
#: A border all round is said when its mean colour differs from the inside's by more than this
#: (of 255, any channel): a band of the wood's own colour is wood to the eye as to the detector,
#: and at 15 no calibration face above (BORDER_COLOUR_TOL) was flagged.
BORDER_COLOUR_STEP = 15.0
#: A photo whose density is under the photos' median (at most the cap) by more than this factor
#: is warned of: every face is stored at the lowest density, so one photo taken from afar or
#: at a low resolution brought the other five down with it, without a word of which.
DENSITY_SPREAD = 1.5
#: A photo whose pixels' channels differ (max - min, of 255) by less than this on average is
#: greyscale: the 12 Mokume face photos differ by 45-70, woodcam's synthetic faces by 80-95,
#: a grey photo saved as RGB (a phone's mono filter, a scanner's grey mode) by 0-1.
GREY_CHROMA = 3.0
#: A JPEG photo denser than the stored face is decoded reduced (1/2, 1/4, 1/8: the JPEG
#: decoder's DCT scaling) to no fewer than this many times the face's pixels a side, which the
#: Lanczos resampling then brings to the face: on six 30 MP photos stored at 0.3 MP the faces
#: differ from the full decode's by 0.18 levels on average, 2 at most (at 1, 0.57 and 40:
#: the DCT's box-like reduction aliases fine rings); DEVELOPERS.md has the measurement.
DRAFT_MARGIN = 2
#: Default upper density (px/mm): 10 px/mm keeps 0.1 mm detail (rings are >= 0.8 mm) and a
#: 50 mm face at 500 px, which the ring detector handles in about a second.
MAX_PX_PER_MM = 10.0


def _image_files(folder: Path) -> list[Path]:
    """The files in ``folder`` with a photo suffix (:data:`PHOTO_SUFFIXES`), sorted; hidden ones
    (macOS ``._front.jpg`` resource forks) left out."""
    return [p for p in sorted(folder.iterdir())
            if p.suffix.lower() in PHOTO_SUFFIXES and not p.name.startswith(".") and p.is_file()]


def _face_of(path: Path) -> str | None:
    """The face a photo file is named for (module docstring), or None."""
    stem = path.stem.lower().removesuffix("_col")
    return stem if stem in FACES else FACE_OF_LETTER.get(stem.upper()) if len(stem) == 1 else None


def _block_files(folder: Path) -> list[Path]:
    """The images a block folder's manifest names in ``folder`` (``front_photo.png``,
    ``front_ring_map.png``, ``front_knot_mask.png`` ...: ``<face>_<what>.png`` beside a
    ``block.json``); none without a manifest."""
    from .io import MANIFEST

    if not (folder / MANIFEST).is_file():
        return []
    return [p for p in _image_files(folder) if p.suffix == ".png" and p.stem.partition("_")[0] in FACES
            and p.stem.partition("_")[2]]


def _mokume_map_kind(path: Path) -> str | None:
    """The kind (:data:`~woodcam.block.io.MOKUME_MAP_KINDS`) of a Mokume sample's map or mask
    ``A_arl-unet.png``, ``A_ann.png``, ``A_knot.png`` (in any case: :func:`~woodcam.block.io.mokume_kind`);
    None for any other file."""
    from .io import mokume_kind

    got = mokume_kind(path)
    return got[1] if got and got[1] != "col" else None


def mokume_maps(folder) -> list[Path]:
    """A Mokume sample's ring maps, annotations and knot masks in ``folder`` (``A_arl-unet.png``,
    ``A_ann.png``, ``A_knot.png``): ``block from-photos`` reads the photos alone, and said nothing
    of them (:func:`block_from_photos` now names them)."""
    return [p for p in _image_files(Path(folder)) if _mokume_map_kind(p)]


def mokume_maps_said(folder, paths: list[Path], instead: str) -> str:
    """The warning for :func:`mokume_maps` ``paths`` of sample folder ``folder``: which are not
    read, what is used ``instead`` (words), how to use them."""
    what = {"arl-unet": "ring map", "knot": "knot mask", "ann": "annotation"}
    kinds = [(what[k], [p.name for p in paths if _mokume_map_kind(p) == k]) for k in what]
    said = " and ".join(f"{kind}{'s' if len(names) > 1 else ''} {', '.join(names)}" for kind, names in kinds if names)
    return (f"{str(folder)!r}: Mokume's {said} {'is' if len(paths) == 1 else 'are'} not read: {instead}; to use "
            f"Mokume's maps instead, give the sample folder itself to fit, bake or eval "
            f"({shlex.quote(str(folder))} --size-mm SIDE, a Mokume sample being a cube; bake reads it as a 50 mm "
            f"cube)")


def stray_photos(folder) -> list[Path]:
    """Image files in ``folder`` named for no face (``IMG_1234.jpg``, ``front face.jpg``); a
    Mokume sample's maps and masks (:func:`mokume_maps`) and a block folder's own images
    (:func:`_block_files`: the photos folder made the block's ``--out``) are not."""
    block = set(_block_files(Path(folder)))
    return [p for p in _image_files(Path(folder))
            if _face_of(p) is None and not _mokume_map_kind(p) and p not in block]


def unreadable_photos(folder, photos: dict[str, Path]) -> list[Path]:
    """Files in ``folder`` named for a face that ``photos`` (:func:`find_face_photos`) has no photo
    of, in a format woodcam does not read (``front.dng``, ``front.psd``: a suffix not in
    :data:`PHOTO_SUFFIXES`); hidden ones left out. Such a face was 'missing: add front.jpg' with
    its photo right there, or left out without a word under ``--partial``."""
    return [p for p in sorted(Path(folder).iterdir()) if p.is_file() and not p.name.startswith(".")
            and p.suffix.lower() not in PHOTO_SUFFIXES and _face_of(p) not in (None, *photos)]


def _unreadable_said(paths: list[Path]) -> str:
    """What is wrong with :func:`unreadable_photos` ``paths`` and the fix, for a message."""
    one, faces = len(paths) == 1, sorted({str(_face_of(p)) for p in paths}, key=FACES.index)
    return (f"{', '.join(p.name for p in paths)} {'is' if one else 'are'} "
            f"named for face{'s' if len(faces) > 1 else ''} "
            f"{', '.join(faces)} but not in a format woodcam reads ({' '.join(PHOTO_SUFFIXES)}): export "
            f"{'it' if one else 'them'} as JPEG or PNG ({', '.join(f + '.jpg' for f in faces)})")


def find_face_photos(folder) -> dict[str, Path]:
    """Face name -> photo path for the photos in ``folder`` (module docstring for the names)."""
    folder = Path(folder)
    if not folder.is_dir():
        raise WoodcamError(f"PHOTOS_DIR must be a folder of face photos; {str(folder)!r} is not a folder")
    found: dict[str, list[Path]] = {}
    for p in _image_files(folder):
        face = _face_of(p)
        if face:
            found.setdefault(face, []).append(p)
    dup = {f: ps for f, ps in found.items() if len(ps) > 1}
    if dup:
        # a face's files said as a dict repr ({'front': ['A.png', 'front.png']}), no word of why
        # A.png is the front's: a Mokume letter beside a face name is the usual cause
        def why(p: Path) -> str:
            stem = p.stem.lower().removesuffix("_col")
            return f" (Mokume's letter {stem.upper()} for {_face_of(p)})" if len(stem) == 1 else ""

        said = "; ".join(f"{len(ps)} for {f}: {', '.join(q.name + why(q) for q in ps)}" for f, ps in dup.items())
        raise WoodcamError(f"each face needs exactly one photo in {str(folder)!r}; found {said}; keep one photo "
                           "per face and move the others out of the folder")
    # in the conventions' order (frames.FACES), not the files' ('found back, bottom, left ...')
    return {f: found[f][0] for f in FACES if f in found}


def _check_exposure(face: str, photo: np.ndarray, path: Path) -> None:
    # the histogram of the grey (ITU-R 601 weights, rounded to 0..255), a band of rows at a
    # time: a float copy of a 48 MP photo's three channels took 580 MB for three numbers
    hist = np.zeros(256, np.int64)
    weights = np.array([299, 587, 114], np.uint32)
    for r in range(0, photo.shape[0], 256):
        lum = (photo[r:r + 256, :, :3] @ weights + 500) // 1000
        hist += np.bincount(lum.ravel(), minlength=256)
    share = hist / hist.sum()
    # the exposure first: an all-white photo is over-exposed, not "blank" (it was called blank)
    high, low = float(share[252:].sum()), float(share[:4].sum())
    if high > CLIPPED_SHARE:
        raise WoodcamError(f"photo of face {face!r} ({path.name}) is over-exposed ({100 * high:.0f} % of "
                           f"pixels white); retake it with less light or a shorter exposure")
    if low > CLIPPED_SHARE:
        raise WoodcamError(f"photo of face {face!r} ({path.name}) is under-exposed ({100 * low:.0f} % of "
                           f"pixels black); retake it with more light")
    v = np.arange(256.0)
    spread = float(np.sqrt(share @ (v - share @ v) ** 2)) / 255.0
    if spread < BLANK_STD:
        raise WoodcamError(f"photo of face {face!r} ({path.name}) is blank (luminance spread "
                           f"{spread:.3f} < {BLANK_STD}); retake it with the face in view")


def _is_grey(photo: np.ndarray) -> bool:
    """Whether ``photo`` (rows, cols, 3) uint8 is greyscale (:data:`GREY_CHROMA`)."""
    chroma = photo.max(axis=2).astype(np.int16) - photo.min(axis=2)
    return float(chroma.mean()) < GREY_CHROMA


def _line_texture(lum: np.ndarray) -> np.ndarray:
    """(rows,) std along each row of ``lum`` (rows, cols) after its straight-line fit: light
    falling off across a table is no texture."""
    x = np.linspace(-1.0, 1.0, lum.shape[1], dtype=np.float32)
    resid = lum - lum.mean(1, keepdims=True) - np.outer(lum @ x / (x @ x), x)
    return resid.std(1)


def _uniform_border(a: np.ndarray) -> tuple[float, float, float, float] | None:
    """The widths of a border round ``a`` (rows, cols, 3) uint8 unlike the wood inside, as shares
    of its (height, height, width, width) at (top, bottom, left, right), 0 on a side without one:
    a photo taken with background round the face, or beside it, and so not cropped to it; None
    when no side has one. A side's border is at least 2 px and 1 % of near-uniform lines
    (:data:`BORDER_TEXTURE_RATIO`, :data:`BORDER_COLOUR_TOL`) whose colour differs from the
    inside's by :data:`BORDER_COLOUR_STEP`. A face's edge lines vary as its inside does (the
    calibration faces stay above 0.5 of the wood's texture on every side), so a cropped face is
    not taken for one; a strip on one side only (the photo cropped off the face's centre) is one."""
    from scipy.ndimage import gaussian_filter

    rgb = a.astype(np.float32)
    # smoothed: sensor and JPEG noise is texture at the pixel scale, where the wood has little
    lum = gaussian_filter(rgb @ np.array([0.299, 0.587, 0.114], np.float32), 1.5)
    h, w = lum.shape
    tex_r, tex_c = _line_texture(lum), _line_texture(lum.T)
    wood = min(np.median(tex_r[h // 4: 3 * h // 4 + 1]), np.median(tex_c[w // 4: 3 * w // 4 + 1]))
    mean_r, mean_c = rgb.mean(1), rgb.mean(0)
    widths = []
    for tex, mean in ((tex_r, mean_r), (tex_r[::-1], mean_r[::-1]), (tex_c, mean_c), (tex_c[::-1], mean_c[::-1])):
        n = len(tex) // 4  # a border wider than a quarter is no face with background round it
        flat = (tex[:n] < BORDER_TEXTURE_RATIO * wood) & (np.abs(mean[:n] - mean[0]).max(1) < BORDER_COLOUR_TOL)
        k = n if flat.all() else int(np.argmin(flat))
        widths.append(k if k >= max(2, 0.01 * len(tex)) else 0)
    top, bottom, left, right = widths
    inside = rgb[top:h - bottom, left:w - right].reshape(-1, 3).mean(0)
    bands = (rgb[:top], rgb[h - bottom:], rgb[:, :left], rgb[:, w - right:])
    # each side's band on its own: a strip of the wood's own colour is wood to the eye as to
    # the detector, whatever the other sides hold
    found = [k if k and np.abs(band.reshape(-1, 3).mean(0) - inside).max() > BORDER_COLOUR_STEP else 0
             for k, band in zip(widths, bands)]
    if not any(found):
        return None
    return found[0] / h, found[1] / h, found[2] / w, found[3] / w


def _face_shape(face: str, size, px_per_mm: float) -> tuple[int, int]:
    """(rows, cols) of ``face``'s image at ``px_per_mm`` (at least 16 px a side)."""
    h_mm, w_mm = face_image_size_mm(face, size)
    return max(16, round(h_mm * px_per_mm)), max(16, round(w_mm * px_per_mm))


def _resampled(a: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """``a`` (rows, cols, 3) uint8 resampled (Lanczos) to ``shape`` (rows, cols), or ``a`` itself."""
    from PIL import Image

    return a if a.shape[:2] == shape else np.asarray(Image.fromarray(a).resize(shape[::-1], Image.LANCZOS))


def _aspect_misfit(face: str, path: Path, shape, h_mm: float, w_mm: float) -> str:
    """What is wrong with a photo of ``shape`` (rows, cols, ...) for a face ``w_mm`` x ``h_mm``:
    its size, the face's, and the height a crop of its width would have (or that it is turned)."""
    rows, cols = shape[:2]
    want, got = h_mm / w_mm, rows / cols
    what = f"face {face!r} ({path.name}) is {cols}x{rows} px (aspect {got:.3f}) for {w_mm:g}x{h_mm:g} mm ({want:.3f})"
    if want != 1.0 and abs(got * want - 1.0) <= FACE_PIXEL_ASPECT_RTOL:
        return f"{what}, turned 90 degrees: turn it upright as ../shared/docs/conventions.md lays the face out"
    if got > want:
        return f"{what}, about {cols}x{round(cols * want)} px when cropped"
    return f"{what}, about {round(rows / want)}x{rows} px when cropped"


def _fits(face: str, shape, size) -> bool:
    """Whether a photo of ``shape`` (rows, cols, ...) has the aspect of ``face`` of a block of
    ``size`` (W, D, H) mm, within :data:`~woodcam.tolerances.FACE_PIXEL_ASPECT_RTOL`."""
    h_mm, w_mm = face_image_size_mm(face, size)
    want = h_mm / w_mm
    return abs(shape[0] / shape[1] - want) <= FACE_PIXEL_ASPECT_RTOL * want


def _sizes_the_photos_fit(shapes: dict[str, tuple[int, int]], size) -> list[tuple[float, float, float]]:
    """The orders of ``size``'s sides, other than the given one, whose faces every photo
    (``shapes``: face -> (rows, cols)) fits: the sides typed in another order than W x D x H made
    every photo 'not cropped to its face', and the fix said was to crop them."""
    from itertools import permutations

    given = tuple(map(float, size))
    return [s for s in dict.fromkeys(permutations(given)) if s != given
            and all(_fits(face, shape, s) for face, shape in shapes.items())]


class _Misfit(NamedTuple):
    """A photo whose aspect does not fit its face: what is wrong (:func:`_aspect_misfit`) and its
    (rows, cols)."""
    said: str
    shape: tuple[int, int]


def _read_face_photo(face: str, path: Path, size, max_px_per_mm: float) -> tuple[np.ndarray, float] | _Misfit:
    """The checked photo of ``face`` brought down to ``max_px_per_mm`` if denser, and its own
    density (px/mm); or, when its aspect does not fit the face, what is wrong (:class:`_Misfit`).
    A function, so the full-size photo is freed before the next is read: six 48 MP photos held
    at once took 1.8 GB. A JPEG denser than ``max_px_per_mm`` is decoded at 1/2, 1/4 or 1/8 of
    its size where that keeps :data:`DRAFT_MARGIN` times the stored face's pixels (six 30 MP
    photos took 14 s and 500 MB, decoded in full for 0.3 MP faces; DEVELOPERS.md)."""
    h_mm, w_mm = face_image_size_mm(face, size)
    target = _face_shape(face, size, max_px_per_mm)
    full: list[tuple[int, int]] = []  # the photo's own (rows, cols), whatever size it is decoded at

    def least(rows: int, cols: int) -> tuple[int, int] | None:
        full.append((rows, cols))
        dense = min(rows / h_mm, cols / w_mm) > max_px_per_mm
        return ((DRAFT_MARGIN * target[0], DRAFT_MARGIN * target[1]) if dense and _fits(face, (rows, cols), size)
                else None)

    a = read_photo_rgb(path, f"photo of face {face!r}", least=least)
    _check_exposure(face, a, path)
    shape = full[0] if full else a.shape[:2]
    if not _fits(face, shape, size):
        return _Misfit(_aspect_misfit(face, path, shape, h_mm, w_mm), (shape[0], shape[1]))
    # an 8 x 8 px photo was enlarged and recorded at a density it lacks; a 20 x 20 px one passed
    # and detection read its noise as rings (a false 'looks mirrored')
    if min(shape) < MIN_FACE_PHOTO_PX:
        raise WoodcamError(f"photo of face {face!r} ({path.name}) is {shape[1]}x{shape[0]} px: too small to "
                           f"hold rings; give at least {MIN_FACE_PHOTO_PX} px a side (MIN_FACE_PHOTO_PX; a phone "
                           "photo has thousands)")
    px_mm = min(shape[0] / h_mm, shape[1] / w_mm)
    return (_resampled(a, target) if px_mm > max_px_per_mm else a), px_mm


def block_from_photos(folder, size_mm, *, partial: bool = False, max_px_per_mm: float = MAX_PX_PER_MM,
                      name: str | None = None, progress: bool = False) -> Block:
    """Read and check the face photos in ``folder`` (module docstring) -> a :class:`Block` with
    photos only, ready for :func:`woodcam.block.write_block` and ring detection.

    Parameters
    ----------
    folder : path of the photos.
    size_mm : (W, D, H) measured block size in mm.
    partial : accept fewer than six faces.
    max_px_per_mm : upper density of the stored faces (px/mm).
    progress : a bar over the photos (phone photos of 12-48 MP take a second or more each).
    """
    from .._progress import progress_bar

    size = check_size(size_mm)
    photos = find_face_photos(folder)
    missing = [f for f in FACES if f not in photos]
    stray = [p.name for p in stray_photos(folder)]
    # a photo named for no face was passed over without a word (with --partial, its face was left out)
    unnamed = f"{', '.join(stray)} {'is' if len(stray) == 1 else 'are'} named for no face"
    if not photos and _block_files(Path(folder)):  # its front_photo.png ... were 'named for no face: rename'
        raise WoodcamError(
            f"PHOTOS_DIR {str(folder)!r} is a block folder "
            f"(block.json, {_block_files(Path(folder))[0].name} ...), not a "
            f"folder of face photos: detect its rings with woodcam rings detect {shlex.quote(str(folder))} --out "
            f"{shlex.quote(str(folder))}, or give the folder of the original photos (front.jpg ...) to make it again")
    if not photos:
        raise WoodcamError(f"no face photos found in {str(folder)!r}{'; ' + unnamed if stray else ''}: "
                           f"name them front.jpg, top.jpg, "
                           f"left.jpg, bottom.jpg, right.jpg, back.jpg (or A..F, or Mokume A_col.png ...)")
    unreadable = unreadable_photos(folder, photos)
    if missing and not partial:
        raise WoodcamError(f"missing face photos: {', '.join(missing)} (found {', '.join(photos)})"
                           f"{'; ' + _unreadable_said(unreadable) if unreadable else ''}"
                           f"{'; ' + unnamed if stray else ''}; add "
                           f"{', '.join(f + '.jpg' for f in missing)} (or Mokume letters "
                           f"{', '.join(MOKUME_LETTER[f] for f in missing)}), or pass --partial")
    if unreadable:  # with --partial: their faces left out
        left = "its face is" if len(unreadable) == 1 else "their faces are"
        warnings.warn(f"{str(folder)!r}: {_unreadable_said(unreadable)}; {left} left out", WoodcamWarning,
                      stacklevel=2)
    if stray:
        warnings.warn(f"{str(folder)!r}: {unnamed}, so not read; rename a face's photo front.jpg, top.jpg, "
                      "left.jpg, bottom.jpg, right.jpg or back.jpg (or A..F)", WoodcamWarning, stacklevel=2)
    maps = mokume_maps(folder)
    if maps:  # passed over without a word: a Mokume folder's ring maps and knot masks seemed read
        warnings.warn(mokume_maps_said(folder, maps, "a block made from photos holds the photos alone, and "
                                       "'woodcam rings detect' finds the rings and knots on them"),
                      WoodcamWarning, stacklevel=2)
    images, density, misfit = {}, {}, []
    shapes: dict[str, tuple[int, int]] = {}
    for face, path in progress_bar(photos.items(), desc="reading photos", unit="photo", enabled=progress):
        got = _read_face_photo(face, path, size, max_px_per_mm)
        if isinstance(got, _Misfit):
            misfit.append(got.said)
            shapes[face] = got.shape
        else:
            images[face], density[face] = got
            shapes[face] = got[0].shape[:2]
    if misfit:  # all of them at once: photos not cropped to the face are seldom alone
        mm = "x".join(f"{v:g}" for v in size)
        head = (f"{'photo does' if len(misfit) == 1 else f'{len(misfit)} photos do'} not fit the block's faces for "
                f"--size-mm {mm}")
        # one photo alone that fits another order is more likely turned or cropped (its message says)
        fit = _sizes_the_photos_fit(shapes, size) if len(misfit) > 1 else []
        if fit:  # every photo fits the sides in another order: no photo to crop
            said = " or ".join(f"--size-mm {'x'.join(f'{v:g}' for v in s)}" for s in fit)
            raise WoodcamError(
                f"{head}, but all {len(shapes)} fit {said}: were the sides typed in another order? --size-mm is "
                f"WxDxH, the width (left to right seen from the front), depth (front to back) and height, as "
                f"../shared/docs/conventions.md lays the faces out; run again with {said}")
        raise WoodcamError(
            f"{head}: {'; '.join(misfit)}; crop each photo to its face's "
            "edges, the wood alone with no table or background round it (a photo editor's perspective crop also "
            "squares up a face taken at an angle), or check --size-mm")
    ppm = min(min(density.values()), max_px_per_mm)
    # against the photos' median (at most the cap): one photo denser than the rest is no fault of theirs
    typical = min(float(np.median(list(density.values()))), max_px_per_mm)
    low = [f for f in images if density[f] * DENSITY_SPREAD < typical]
    if low:
        said = ", ".join(f"{f!r} ({photos[f].name}, {density[f]:.2f} px/mm)" for f in low)
        one = len(low) == 1
        warnings.warn(
            f"{'photo of face' if one else 'photos of faces'} {said} {'holds' if one else 'hold'} far less "
            f"than the other photos' {typical:.2f} px/mm (their median): all faces are stored at one density, "
            f"{ppm:.2f} px/mm, "
            f"so the others lose their detail; retake {'it' if one else 'them'} closer or at a higher "
            "resolution", WoodcamWarning, stacklevel=2)
    # a photo brought down to the cap while another lies below it is read again and resampled
    # once, from its original: resampled twice (to the cap, then to ppm), a face's pixels
    # depended on the other photos' densities beyond the common target density
    again = [f for f in images if density[f] > max_px_per_mm > ppm]
    for face in progress_bar(again, desc="re-reading photos", unit="photo", enabled=progress) if again else ():
        images[face] = None  # freed before its original is read again
        again_read = _read_face_photo(face, photos[face], size, ppm)
        assert not isinstance(again_read, _Misfit)  # its aspect passed on the first read
        images[face] = again_read[0]
    faces = {}
    for face, a in images.items():
        shape = _face_shape(face, size, ppm)
        faces[face] = Face(face, shape, photo=_resampled(a, shape))
        border = _uniform_border(faces[face].photo)
        if border:  # margins in the face's proportions keep its aspect and passed silently
            sides = [(side, share) for side, share in zip(("top", "bottom", "left", "right"), border) if share]
            where = "all four sides" if len(sides) == 4 else \
                f"its {' and '.join(side for side, _ in sides)} side{'s' if len(sides) > 1 else ''}"
            shares = ", ".join(f"{side} {100 * share:.0f} % of its {'height' if side in ('top', 'bottom') else 'width'}"
                               for side, share in sides)
            warnings.warn(
                f"photo of face {face!r} ({photos[face].name}) has a uniform border unlike the wood on {where} "
                f"({shares}): background {'round' if len(sides) == 4 else 'beside'} the face? crop the photo "
                "to the face's edges, the wood alone", WoodcamWarning, stacklevel=2)
    grey = [f for f, face in faces.items() if _is_grey(face.photo)]
    if grey and len(grey) < len(faces):  # read as grey RGB beside colour photos, without a word
        one = len(grey) == 1
        warnings.warn(
            f"{'photo of face' if one else 'photos of faces'} {', '.join(f'{f!r} ({photos[f].name})' for f in grey)} "
            f"{'is' if one else 'are'} greyscale, the other faces' in colour: the wood's colours are fitted from "
            f"every face photo, {'this one' if one else 'these'} grey; export or retake {'it' if one else 'them'} "
            "in colour", WoodcamWarning, stacklevel=2)
    meta = {"source": "photos", "photos_dir": str(Path(folder).resolve()), "px_per_mm": float(ppm),
            "photos_px_per_mm": float(min(density.values())),
            "photos": {f: p.name for f, p in photos.items()},
            # what this run writes as <face>_photo.png: a rerun with a face fewer removes only its own
            "photo_digest": {f: photo_digest(face.photo) for f, face in faces.items()}}
    return Block(tuple(size), faces=faces, name=name or Path(folder).name, meta=meta)


def photo_digest(photo) -> str:
    """Digest of a face photo's pixels as stored in a block folder: what ``block from-photos``
    records of the photos it writes, and a detection of the photos it traces (what a corrected
    SVG is drawn over), so either record tells a photo woodcam wrote."""
    from .._cache import digest

    return digest(np.asarray(photo))


def written_photos(folder) -> dict[str, str]:
    """Face -> recorded digest of each ``<face>_photo.png`` the manifest of block folder
    ``folder`` names and woodcam recorded writing (``block from-photos``' ``meta["photo_digest"]``
    or a detection's ``photo_digest``); {} without a readable manifest. Read before the folder
    is written over, for :func:`clear_stale_photos`."""
    import json

    from .io import MANIFEST

    try:
        m = json.loads((Path(folder) / MANIFEST).read_text())
    except (OSError, ValueError):  # none, or one 'block from-photos' overwrites (it says so)
        return {}
    meta, faces = (m.get("meta"), m.get("faces")) if isinstance(m, dict) else (None, None)
    if not (isinstance(meta, dict) and isinstance(faces, dict)):
        return {}
    said = {}
    for rec in (meta.get("photo_digest"), (meta.get("detection") or {}).get("photo_digest"),
                (meta.get("detection_before") or {}).get("photo_digest")):
        said.update({f: d for f, d in (rec if isinstance(rec, dict) else {}).items()
                     if isinstance(d, str) and f not in said})
    return {f: said.get(f, "") for f, e in faces.items()
            if f in FACES and isinstance(e, dict) and e.get("photo") == f"{f}_photo.png"}


def clear_stale_photos(folder, block: Block, before: dict[str, str]) -> list[str]:
    """Remove each ``<face>_photo.png`` in block folder ``folder`` (``block`` just written there)
    of a face ``block`` has no more (``block from-photos --partial`` after a run with that face)
    when it is still the photo woodcam wrote (``before``: :func:`written_photos` of the folder
    before this run, its pixels' digest the recorded one): it stayed beside the new manifest,
    unread, a face the block seemed to have. One woodcam did not write (edited, or from before
    the digests were recorded) is kept and said; returns those warnings."""
    from .io import _read_png
    from .._readers import photo_rgb8

    msgs = []
    for face in FACES:
        path = Path(folder) / f"{face}_photo.png"
        if face in block.faces or face not in before or not path.is_file():
            continue
        try:
            ours = (bool(before[face])
                    and photo_digest(photo_rgb8(_read_png(path, f"photo of face {face!r}"))) == before[face])
        except WoodcamError:  # no longer an image: not the one woodcam wrote
            ours = False
        if ours:
            path.unlink()
            continue
        msgs.append(f"face {face!r}: {path.name} in {str(folder)!r} is not read (the block has no {face} face now, "
                    f"and block.json does not name it), and is kept: it is not the photo an earlier run wrote "
                    f"(edited, or from before woodcam recorded them); delete it, or move it out to keep it")
    return msgs
