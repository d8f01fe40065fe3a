"""A block folder from six face photos: find them by name, check them, write the block.

Photos are files in one folder named by face: ``front.jpg``, ``top.png``, ... (any of
``.jpg .jpeg .png .tif .tiff .bmp .webp .heic .heif .gif``, any case), or by Mokume letter (``A.jpg`` ... or the
Mokume sample names ``A_col.png`` ...). Each must already be rectified to its face (cropped to
the face's edges, seen from outside, oriented as ``docs/conventions.md`` says).

Checks, each failing with one message naming the face: every face present (or ``partial``);
one file per face; the image's aspect (rows / cols) within :data:`~woodcam.tolerances.FACE_PIXEL_ASPECT_RTOL`
of the face's in ``size_mm``; not blank (luminance spread below :data:`BLANK_STD`), not over- or
under-exposed (more than :data:`CLIPPED_SHARE` of the pixels at the ends of the range).
Faces are resampled to one density (the lowest of the photos', at most ``max_px_per_mm``), so
the faces unfold into one cross and ring widths are alike in pixels.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._readers import read_photo_rgb
from ..errors import WoodcamError
from ..frames import (
    FACE_OF_LETTER,
    FACES,
    MOKUME_LETTER,
    check_size,
    face_image_size_mm,
)
from ..tolerances import FACE_PIXEL_ASPECT_RTOL
from .block import Block, Face

PHOTO_SUFFIXES = (".jpg", ".jpeg", ".png", ".tif", ".tiff", ".bmp", ".webp", ".heic", ".heif", ".gif")
#: A photo whose luminance standard deviation is below this (fraction of full scale) is blank.
BLANK_STD = 0.01
#: A photo with more than this share of pixels at <= 3 or >= 252 (of 255) is badly exposed.
CLIPPED_SHARE = 0.4
#: Default upper density (px/mm): 10 px/mm keeps 0.1 mm detail (rings are >= 0.8 mm) and a
#: 50 mm face at 500 px, which the ring detector handles in about a second.
MAX_PX_PER_MM = 10.0


def find_face_photos(folder) -> dict[str, Path]:
    """Face name -> photo path for the photos in ``folder`` (module docstring for the names)."""
    folder = Path(folder)
    if not folder.is_dir():
        raise WoodcamError(f"PHOTOS_DIR must be a folder of face photos; {str(folder)!r} is not a folder")
    found: dict[str, list[Path]] = {}
    for p in sorted(folder.iterdir()):
        if p.suffix.lower() not in PHOTO_SUFFIXES or not p.is_file():
            continue
        stem = p.stem.lower()
        stem = stem.removesuffix("_col")
        face = stem if stem in FACES else FACE_OF_LETTER.get(stem.upper()) if len(stem) == 1 else None
        if face:
            found.setdefault(face, []).append(p)
    dup = {f: [q.name for q in ps] for f, ps in found.items() if len(ps) > 1}
    if dup:
        raise WoodcamError(f"each face needs exactly one photo; found several for {dup}; keep one per face")
    return {f: ps[0] for f, ps in found.items()}


def _check_exposure(face: str, photo: np.ndarray, path: Path) -> None:
    lum = photo[..., :3].astype(np.float32) @ np.array([0.299, 0.587, 0.114], np.float32)
    # the exposure first: an all-white photo is over-exposed, not "blank" (it was called blank)
    high, low = float(np.mean(lum >= 252)), float(np.mean(lum <= 3))
    if high > CLIPPED_SHARE:
        raise WoodcamError(f"photo of face {face!r} ({path.name}) is over-exposed ({100 * high:.0f} % of "
                           f"pixels white); retake it with less light or a shorter exposure")
    if low > CLIPPED_SHARE:
        raise WoodcamError(f"photo of face {face!r} ({path.name}) is under-exposed ({100 * low:.0f} % of "
                           f"pixels black); retake it with more light")
    if float(lum.std()) / 255.0 < BLANK_STD:
        raise WoodcamError(f"photo of face {face!r} ({path.name}) is blank (luminance spread "
                           f"{lum.std() / 255:.3f} < {BLANK_STD}); retake it with the face in view")


def _aspect_misfit(face: str, path: Path, shape, h_mm: float, w_mm: float) -> str:
    """What is wrong with a photo of ``shape`` (rows, cols, ...) for a face ``w_mm`` x ``h_mm``:
    its size, the face's, and the height a crop of its width would have (or that it is turned)."""
    rows, cols = shape[:2]
    want, got = h_mm / w_mm, rows / cols
    what = f"face {face!r} ({path.name}) is {cols}x{rows} px (aspect {got:.3f}) for {w_mm:g}x{h_mm:g} mm ({want:.3f})"
    if want != 1.0 and abs(got * want - 1.0) <= FACE_PIXEL_ASPECT_RTOL:
        return f"{what}, turned 90 degrees: turn it upright as docs/conventions.md lays the face out"
    if got > want:
        return f"{what}, about {cols}x{round(cols * want)} px when cropped"
    return f"{what}, about {round(rows / want)}x{rows} px when cropped"

def block_from_photos(folder, size_mm, *, partial: bool = False, max_px_per_mm: float = MAX_PX_PER_MM,
                      name: str | None = None) -> Block:
    """Read and check the face photos in ``folder`` (module docstring) -> a :class:`Block` with
    photos only, ready for :func:`woodcam.block.write_block` and ring detection.

    Parameters
    ----------
    folder : path of the photos.
    size_mm : (W, D, H) measured block size in mm.
    partial : accept fewer than six faces.
    max_px_per_mm : upper density of the stored faces (px/mm).
    """
    from PIL import Image

    size = check_size(size_mm)
    photos = find_face_photos(folder)
    missing = [f for f in FACES if f not in photos]
    if not photos:
        raise WoodcamError(f"no face photos found in {str(folder)!r}: name them front.jpg, top.jpg, left.jpg, "
                           f"bottom.jpg, right.jpg, back.jpg (or A..F, or Mokume A_col.png ...)")
    if missing and not partial:
        raise WoodcamError(f"missing face photos: {', '.join(missing)} (found {', '.join(photos)}); add "
                           f"{', '.join(f + '.jpg' for f in missing)} (or Mokume letters "
                           f"{', '.join(MOKUME_LETTER[f] for f in missing)}), or pass --partial")
    images, density, misfit = {}, [], []
    for face, path in photos.items():
        a = read_photo_rgb(path, f"photo of face {face!r}")
        _check_exposure(face, a, path)
        h_mm, w_mm = face_image_size_mm(face, size)
        want, got = h_mm / w_mm, a.shape[0] / a.shape[1]
        if abs(got - want) > FACE_PIXEL_ASPECT_RTOL * want:
            misfit.append(_aspect_misfit(face, path, a.shape, h_mm, w_mm))
            continue
        if min(a.shape[:2]) < 16:  # an 8 x 8 px photo was enlarged and recorded at a density it lacks
            raise WoodcamError(f"photo of face {face!r} ({path.name}) is {a.shape[1]}x{a.shape[0]} px: too small to "
                               "hold rings; give at least 16 px a side (a phone photo has thousands)")
        images[face] = a
        density.append(min(a.shape[0] / h_mm, a.shape[1] / w_mm))
    if misfit:  # all of them at once: photos not cropped to the face are seldom alone
        raise WoodcamError(
            f"{'photo does' if len(misfit) == 1 else f'{len(misfit)} photos do'} not fit the block's faces for "
            f"--size-mm {size[0]:g}x{size[1]:g}x{size[2]:g}: {'; '.join(misfit)}; crop each photo to its face's "
            "edges, the wood alone with no table or background round it (a photo editor's perspective crop also "
            "squares up a face taken at an angle), or check --size-mm")
    ppm = min(min(density), max_px_per_mm)
    faces = {}
    for face, a in images.items():
        h_mm, w_mm = face_image_size_mm(face, size)
        shape = (max(16, round(h_mm * ppm)), max(16, round(w_mm * ppm)))
        if a.shape[:2] != shape:
            a = np.asarray(Image.fromarray(a).resize(shape[::-1], Image.LANCZOS))
        faces[face] = Face(face, shape, photo=a)
    meta = {"source": "photos", "photos_dir": str(Path(folder).resolve()), "px_per_mm": float(ppm),
            "photos": {f: p.name for f, p in photos.items()}}
    return Block(tuple(size), faces=faces, name=name or Path(folder).name, meta=meta)
