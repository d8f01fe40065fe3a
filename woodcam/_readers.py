"""Reading untrusted files at the door: strict JSON (no NaN/Infinity, bounded nesting) and
photos as every viewer shows them, every failure a :class:`~woodcam.errors.WoodcamError` naming
the file.

Used by every reader of user files (``block.json``, log files, true-field files, face photos,
veneer scans, parquetry targets); it sits at the bottom of the import layering so ``fields``,
``block`` and ``parquetry`` can all use it.
"""

from __future__ import annotations

import contextlib
import json
import re
import warnings
import zipfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from ._checks import check_path
from .errors import WoodcamError, require

__all__ = ["photo_rgb8", "read_image_file", "read_image_file_opacity", "read_json_file", "read_json_object", "read_npz",
           "read_photo_rgb", "strict_json_loads"]


def strict_json_loads(text: str, what: str) -> Any:
    """``json.loads`` that refuses NaN/Infinity and maps every failure to a WoodcamError."""
    def _no_constant(c):
        raise ValueError(f"non-finite number {c} is not allowed")

    try:
        return json.loads(text, parse_constant=_no_constant)
    except (ValueError, RecursionError) as err:  # JSONDecodeError is a ValueError
        raise WoodcamError(f"{what} must be valid JSON with finite numbers; {err}") from err


def read_json_file(path: Path, what: str) -> Any:
    """Read and strictly parse a JSON file; unreadable or non-UTF-8 files are WoodcamErrors."""
    try:
        text = Path(path).read_bytes().decode("utf-8")
    except OSError as err:
        raise WoodcamError(f"{what}: cannot read {str(path)!r} ({err.strerror})") from err
    except UnicodeDecodeError as err:
        raise WoodcamError(f"{what}: {str(path)!r} is not UTF-8 text ({err.reason})") from err
    return strict_json_loads(text, f"{what} {str(path)!r}")


def read_json_object(path, what: str) -> dict:
    """:func:`read_json_file` of a file that must hold a JSON object (a spec, a job): the dict,
    or a WoodcamError naming ``what``, the file and what it held instead."""
    d = read_json_file(Path(path), what)
    if not isinstance(d, dict):
        raise WoodcamError(f"{what} {str(path)!r} must hold a JSON object; got {type(d).__name__}")
    return d


@contextlib.contextmanager
def read_npz(path, what: str, fix: str = "") -> Iterator[Any]:
    """The open ``.npz`` archive of ``path`` (numpy's ``NpzFile``, no pickles) for the body of a
    ``with``. A missing, truncated or garbage file, a missing array or one the body refuses
    (``KeyError``, ``ValueError``, ``TypeError``) is a WoodcamError: ``PATH: not WHAT: why; FIX``.
    ``what`` names the kind of file and its rule, ``fix`` how to write it again. A truncated
    archive was numpy's ``BadZipFile`` (an internal error), a text file its "pickled data"
    message. ``path`` None or a number is refused as the argument ``path`` (it was read as the
    file ``None``: "None: not a woodcam grid field ...: expected str, bytes or os.PathLike")."""
    path = check_path(path, "path", fix=f"pass the path of {what}")
    try:
        with open(path, "rb") as fh:  # our own handle: np.load leaks it when the zip is truncated
            if not zipfile.is_zipfile(fh):
                raise ValueError("not a zip (.npz) archive: truncated by a crash or copy, or another kind of file")
            fh.seek(0)
            import numpy as np

            with np.load(fh, allow_pickle=False) as z:
                yield z
    except (OSError, KeyError, ValueError, TypeError, EOFError, zipfile.BadZipFile) as err:
        why = err.strerror if isinstance(err, OSError) and err.strerror else err
        raise WoodcamError(f"{path}: not {what}: {why}" + (f"; {fix}" if fix else "")) from err


#: What a photo's transparent pixels most likely are, and the fix (:func:`read_image_file`).
PHOTO_ALPHA_FIX = ("a cut-out?", "crop the image so every pixel is opaque, or flatten it onto its background")


def read_image_file(path: Path, what: str, alpha_fix: tuple[str, str] = PHOTO_ALPHA_FIX, *,
                    least: Callable[[int, int], tuple[int, int] | None] | None = None):
    """An image file decoded as every viewer shows it (:func:`read_image_file_opacity` without
    its opacity: transparent pixels are warned of with ``alpha_fix``)."""
    return read_image_file_opacity(path, what, alpha_fix, least=least)[0]


def read_image_file_opacity(path: Path, what: str, alpha_fix: tuple[str, str] | None = PHOTO_ALPHA_FIX, *,
                            least: Callable[[int, int], tuple[int, int] | None] | None = None):
    """``(image, opaque)``: ``opaque`` is ``(h, w) bool``, True where a pixel is fully opaque,
    or None for an image without transparency; ``alpha_fix`` None: the caller uses ``opaque``,
    so transparent pixels are not warned of.

    An image file decoded as every viewer shows it (its format told by its content, not its
    name), turned by its EXIF orientation tag (a phone stores a portrait photo as landscape
    pixels plus that tag: read raw it lies on its side, a face's rings turned 90 degrees) and
    converted to sRGB from the ICC profile it carries (:func:`_in_srgb`):
    ``(h, w)`` or ``(h, w, 3)`` uint8 for 8-bit modes, uint16 for 16-bit ones (values kept).
    Files over :data:`~woodcam.limits.MAX_IMAGE_PIXELS`, unreadable, truncated, animated (a
    GIF, PNG or WebP of several frames: which is the face?) or of unsupported modes are
    WoodcamErrors naming ``what`` and the file; transparent pixels (a cut-out) are read as the
    colour stored under them, with a WoodcamWarning saying ``alpha_fix``: (what they may be,
    the fix) for the image's use (a photo, a mask, a target).

    ``least``, when given, is called with the image's upright (rows, cols) before it is decoded
    and returns the least upright (rows, cols) its caller needs, or None for every pixel: a JPEG
    is then decoded at the smallest of 1/2, 1/4 or 1/8 of its size no smaller than that (the
    JPEG decoder's DCT scaling, Pillow's ``Image.draft``; other formats in full), a 30 MP photo
    stored at 0.3 MP decoded in a sixteenth of the time and memory."""
    from PIL import Image, ImageOps

    from .limits import limit

    cap = limit("MAX_IMAGE_PIXELS")

    def too_big(size: str) -> WoodcamError:
        return WoodcamError(f"{what}: {str(path)!r} is {size}, more than the limit MAX_IMAGE_PIXELS = "
                            f"{cap:.0f} pixels; downscale it, or raise the limit with WOODCAM_MAX_IMAGE_PIXELS=N")

    def damaged(err: Exception) -> WoodcamError:
        return WoodcamError(f"{what}: cannot decode the image {str(path)!r} ({err}); the file is damaged or "
                            "cannot be read as an image: pass a PNG, JPEG or TIFF file")

    # PIL's own bomb guard (89 Mpx, an error above 179 Mpx) came before woodcam's: a 200 Mpx
    # target within woodcam's limit was refused as "damaged", whatever WOODCAM_MAX_IMAGE_PIXELS
    # said; woodcam's limit is the guard (checked below from the header), PIL's set to it
    if Image.MAX_IMAGE_PIXELS is not None and Image.MAX_IMAGE_PIXELS < cap:
        Image.MAX_IMAGE_PIXELS = cap
    try:
        # by the content, not the name: phones and messengers save HEIC under a .jpg name (PIL
        # already tells a PNG named .jpg by its bytes; HEIF needs pillow-heif's opener)
        with open(path, "rb") as f:
            if f.read(12)[4:8] == b"ftyp":  # an ISO media file: HEIF, a phone camera's default format
                from pillow_heif import register_heif_opener

                register_heif_opener()  # libheif turns the pixels by the file's own rotation and resets the tag
        with warnings.catch_warnings(record=True) as said:
            # PIL says a damaged EXIF block (as the file opens, and again as it is turned) in
            # UserWarnings, which the CLI drops (it prints woodcam's own): said again below,
            # naming the file (:func:`_say_pil_warnings`); other warnings pass through as they were
            warnings.simplefilter("always", UserWarning)
            with Image.open(path) as im:
                if im.width * im.height > cap:
                    raise too_big(f"{im.width}x{im.height} px")
                # an animation's first frame was taken without a word; a phone's MPO JPEG (a depth
                # or gain map as its second image) is one photo and is read as such
                if getattr(im, "is_animated", False) and im.format in ("GIF", "PNG", "WEBP"):
                    raise WoodcamError(
                        f"{what}: {str(path)!r} is an animated {im.format} of {im.n_frames} frames, not one "
                        "photo; save the frame that shows the face as a still JPEG or PNG")
                exif = im.getexif()
                if least is not None:
                    _draft(im, least, exif.get(_EXIF_ORIENTATION))
                im.load()  # decode now: a truncated file fails here, inside the try
                # an EXIF block PIL read nothing from, and said nothing of
                unread = len(im.info.get("exif") or b"") if im.info.get("exif") and not exif else 0
                orientation = exif.get(_EXIF_ORIENTATION)
                # in place: a copy of an upright 48 MP photo (PIL's 4 bytes a pixel, 190 MB) made
                # for nothing raised a read's peak by a third
                ImageOps.exif_transpose(im, in_place=True)
                image, opaque = _image_array(_in_srgb(im, f"{what}: {str(path)!r}"), f"{what}: {str(path)!r}",
                                             alpha_fix)
                fmt = im.format
        _say_pil_warnings(said, f"{what}: {str(path)!r}", fmt, orientation, unread)
        return image, opaque
    except WoodcamError:
        raise
    except (Image.DecompressionBombError, Image.DecompressionBombWarning) as err:  # over the cap
        n = re.search(r"\((\d+) pixels\)", str(err))  # PIL's message holds the count
        raise too_big(f"{n.group(1) if n else 'too many'} pixels") from err
    except FileNotFoundError as err:  # not 'the file is damaged'
        raise WoodcamError(f"{what}: no such file {str(path)!r}; check the path") from err
    except OSError as err:
        if err.errno is None:  # PIL's own: unknown format, truncated data
            raise damaged(err) from err
        # the system's (no permission, a failing card or network share): the file may be fine,
        # and 'the file is damaged' sent the user to retake a good photo
        raise WoodcamError(f"{what}: cannot read {str(path)!r} ({err.strerror}); check the file's permissions "
                           "and that its disk or share is readable, or copy it elsewhere") from err
    except (SyntaxError, ValueError) as err:
        # PIL raises UnidentifiedImageError (an OSError, above) for 0-byte/unknown files, OSError for
        # truncated data, SyntaxError/ValueError for some malformed headers
        raise damaged(err) from err


#: The EXIF tag that says how a photo's pixels are to be turned to show it upright.
_EXIF_ORIENTATION = 0x0112


def _draft(im, least: Callable[[int, int], tuple[int, int] | None], orientation) -> None:
    """Have PIL image ``im`` (opened, not yet loaded), a JPEG, decoded at the least size ``least``
    asks (:func:`read_image_file`): ``least`` and its answer are upright, ``im`` as stored,
    turned a quarter by EXIF orientations 5 to 8. ``least`` is called whatever the format."""
    turned = orientation in (5, 6, 7, 8)
    rows, cols = (im.width, im.height) if turned else (im.height, im.width)
    want = least(rows, cols)
    # JPEG alone: pillow-heif's draft swaps in the file's embedded thumbnail, another encoding
    if want is not None and im.format in ("JPEG", "MPO") and (want[0] < rows or want[1] < cols):
        im.draft(None, (max(1, want[0]), max(1, want[1])) if turned else (max(1, want[1]), max(1, want[0])))


def _in_srgb(im, where: str):
    """PIL image ``im`` in sRGB, as a viewer shows it, when it carries an ICC colour profile of
    another space (an iPhone's Display P3, a camera's Adobe RGB, a print workflow's CMYK): its
    numbers were read as sRGB, a P3 face's wood duller and yellower than on screen (P3 (200,
    150, 100) is sRGB (210, 149, 91)). RGB(A) is converted in place (alpha kept), CMYK to RGB;
    an sRGB profile, grey and 16-bit images are left as they are. A profile that cannot be read
    is said (``where``: what and the file), the numbers read as sRGB."""
    icc = im.info.get("icc_profile")
    if not icc or im.mode not in ("RGB", "RGBA", "CMYK"):
        return im
    import io

    from PIL import ImageCms

    from .errors import WoodcamWarning

    try:
        profile = ImageCms.ImageCmsProfile(io.BytesIO(icc))
        space = profile.profile.xcolor_space.strip()
        if space != im.mode[:len(space)] or ImageCms.getProfileDescription(profile).strip().startswith("sRGB"):
            return im  # sRGB already; or a profile not of the image's space, which no viewer applies
        srgb = ImageCms.createProfile("sRGB")
        if im.mode == "CMYK":
            return ImageCms.profileToProfile(im, profile, srgb, outputMode="RGB")
        ImageCms.profileToProfile(im, profile, srgb, inPlace=True)
        return im
    except (OSError, ValueError, ImageCms.PyCMSError) as err:
        warnings.warn(f"{where} carries an ICC colour profile that cannot be read ({err}); its colours are read "
                      "as sRGB and may differ from what a viewer shows: export it again as sRGB", WoodcamWarning,
                      stacklevel=4)
        return im


def _say_pil_warnings(said, where: str, fmt: str | None, orientation, unread: int) -> None:
    """The warnings recorded while an image was read (``said``), each once: PIL's own (UserWarnings
    the CLI would drop) as WoodcamWarnings naming ``where`` (what and the file), those of a damaged
    EXIF block (and an EXIF block of ``unread`` bytes PIL read nothing from) in one saying what
    became of its orientation tag (a phone photo's only record of which way is up); others as
    they were."""
    from .errors import WoodcamWarning

    exif, other = [], []
    for w in said:
        if issubclass(w.category, UserWarning) and not issubclass(w.category, WoodcamWarning):
            text = str(w.message)
            # EXIF is a TIFF directory, parsed by PIL's TIFF reader: its words on a JPEG are the EXIF's
            mine = exif if fmt != "TIFF" and ("TiffImagePlugin" in w.filename or "exif" in text.lower()) else other
            if text not in mine:  # read as the file opens and again as it is turned: said twice
                mine.append(text)
        else:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    if unread:
        exif.append(f"none of its {unread} bytes could be read")
    if exif:
        turned = (f"its orientation tag ({orientation}) was read and applied" if orientation is not None else
                  "no orientation tag could be read from it, so the pixels are used as stored")
        warnings.warn(f"{where} has damaged EXIF data ({'; '.join(exif)}); {turned}: check that the image shows "
                      "the right way up, or save it again from a photo editor to rewrite its EXIF",
                      WoodcamWarning, stacklevel=3)
    for text in other:
        warnings.warn(f"{where}: {text} (said by the image library, Pillow)", WoodcamWarning, stacklevel=3)


def read_photo_rgb(path: Path, what: str, alpha_fix: tuple[str, str] = PHOTO_ALPHA_FIX, *,
                   least: Callable[[int, int], tuple[int, int] | None] | None = None):
    """``(h, w, 3) uint8`` RGB of the image file ``path`` (:func:`read_image_file`, ``least`` as
    there; grey repeated, 16-bit scaled by 1/257)."""
    return photo_rgb8(read_image_file(path, what, alpha_fix, least=least))


def photo_rgb8(a):
    """A decoded photo as (rows, cols, 3) uint8: grey repeated to RGB, 16-bit scaled by 1/257
    (65535 -> 255) rather than wrapped modulo 256 or clipped."""
    import numpy as np

    if a.dtype == np.uint16:
        a = np.round(a / 257.0).astype(np.uint8)
    if a.ndim == 2:
        a = np.repeat(a[..., None], 3, axis=2)
    return a[..., :3].astype(np.uint8, copy=False)


def _image_array(im, where: str, alpha_fix: tuple[str, str] | None = PHOTO_ALPHA_FIX):
    """A decoded PIL image as uint8 (8-bit modes) or uint16 (16-bit modes, values kept), and
    its opacity (:func:`_opacity`); ``where`` (what and the file) starts the message of an image
    that cannot be."""
    import numpy as np

    opaque = _opacity(im)
    share = 0.0 if opaque is None else 1.0 - float(np.mean(opaque))
    if share and alpha_fix is not None:  # the alpha was dropped without a word: a cut-out's background read as wood
        import warnings

        from .errors import WoodcamWarning

        warnings.warn(f"{where} has transparent pixels ({100 * share:.3g} % of them, {alpha_fix[0]}), read as "
                      f"the colour stored under them, the transparency dropped; {alpha_fix[1]}",
                      WoodcamWarning, stacklevel=3)
    if im.mode in ("I;16", "I;16B", "I;16L", "I;16N"):
        return np.asarray(im).astype(np.uint16), opaque
    if im.mode == "I":
        a = np.asarray(im)
        if a.size and (a.min() < 0 or a.max() > 65535):
            raise WoodcamError(f"{where} is a 32-bit integer image with values outside 0..65535 "
                               f"({a.min()}..{a.max()}); save it as 8- or 16-bit")
        return a.astype(np.uint16), opaque
    if im.mode in ("RGB;16", "RGBA;16") or im.mode.startswith(("F", "RGBa")):
        kind = " (floating point)" if im.mode.startswith("F") else ""
        raise WoodcamError(f"{where} has image mode {im.mode}{kind}, which is not supported; save it as an "
                           "8- or 16-bit PNG")
    if im.mode not in ("L", "RGB"):
        im = im.convert("RGB" if im.mode in ("P", "RGBA", "CMYK", "YCbCr", "LAB", "HSV", "PA")
                        else "L")
    return np.asarray(im), opaque


def _opacity(im):
    """``(h, w) bool``, True where a PIL image's pixel is fully opaque (alpha 255), or None for
    modes without alpha or a transparent colour."""
    import numpy as np

    if im.mode in ("RGBA", "LA", "PA"):
        alpha = im.getchannel("A")
    elif "transparency" in im.info and im.mode.startswith("I;16"):  # a 16-bit grey's colour key
        return np.asarray(im) != im.info["transparency"]
    elif "transparency" in im.info and im.mode in ("P", "L", "RGB"):  # a palette or colour key
        alpha = im.convert("RGBA").getchannel("A")
    else:
        return None
    return np.asarray(alpha) == 255


def check_state_shapes(expected: dict, state) -> None:
    """Raise ``ValueError`` in one line when the weights ``state`` are not of the net ``expected``
    (its ``state_dict()``): how many tensors are of another shape, missing or unexpected, and
    the first of them (torch's own error lists every tensor, 66 lines for a ring net of another
    width)."""
    if not isinstance(state, dict):
        raise ValueError(f"the weights are a {type(state).__name__}, not a state dict")
    shaped = [k for k in expected if k in state and tuple(state[k].shape) != tuple(expected[k].shape)]
    missing = [k for k in expected if k not in state]
    extra = [k for k in state if k not in expected]
    if not (shaped or missing or extra):
        return
    counts = ", ".join(f"{len(v)} {what}" for v, what in ((shaped, "of another shape"), (missing, "missing"),
                                                          (extra, "unexpected")) if v)
    first = (f"{shaped[0]!r} is {tuple(state[shaped[0]].shape)}, the spec's net has "
             f"{tuple(expected[shaped[0]].shape)}" if shaped else f"{(missing or extra)[0]!r}")
    raise ValueError(f"the weights are of another net than the spec (tensors {counts}; first {first})")


def torch_archive_problem(path) -> str | None:
    """Why the file ``path`` cannot be a ``torch.save`` file, a zip archive: ``"empty"``, ``"not
    a zip archive"`` (cut short by a crash or copy, or another kind of file), or None. Checked
    before ``torch.load``, whose errors for these say nothing useful (a bare ``EOFError``, a
    paragraph about miniz). An unreadable file is the ``OSError`` of opening it."""
    with open(path, "rb") as fh:
        if zipfile.is_zipfile(fh):
            return None
    return "empty" if Path(path).stat().st_size == 0 else "not a zip archive"


def torch_state(path, expected: dict, what: str = "torch weights") -> dict:
    """The tensors of the torch weights file ``path`` (``torch.save`` of a state dict), read with
    ``weights_only=True`` (a crafted pickle runs nothing) and checked against the net they are
    for, ``expected`` (its ``state_dict()``: names and shapes, :func:`check_state_shapes`).

    Any failure is a ``ValueError`` of one line saying why (the caller names the file and the
    fix, :func:`read_torch_state`): torch said ``EOFError`` with no text for an empty file,
    ``OSError: [Errno 22] Invalid argument`` or a paragraph about miniz for a cut one, and
    listed every tensor over many lines for another net's weights."""
    torch = require("torch", "learn", what)
    try:
        problem = torch_archive_problem(path)
        if problem:
            raise ValueError("the file is empty" if problem == "empty" else
                             "not a torch weights file (a zip archive): cut short by a crash or copy, "
                             "or another kind of file")
        state = torch.load(path, map_location="cpu", weights_only=True)
        check_state_shapes(expected, state)
    except Exception as err:  # torch raises RuntimeError, OSError, EOFError, UnpicklingError...
        why = (err.strerror if isinstance(err, OSError) and err.strerror else
               (str(err).strip().splitlines() or [type(err).__name__])[0])
        raise ValueError(why) from err
    return state


def read_torch_state(path, what: str, expected: dict, fix: str) -> dict:
    """:func:`torch_state` of ``path``, or one WoodcamError line: ``WHAT PATH cannot be loaded:
    why; FIX``. A missing, empty, cut or foreign file, or the weights of another net."""
    try:
        return torch_state(path, expected, what)
    except ValueError as err:
        raise WoodcamError(f"{what} {str(path)!r} cannot be loaded: {err}; {fix}") from err
