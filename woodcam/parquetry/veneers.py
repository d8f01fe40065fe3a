"""Veneer sheets: the wood a parquetry is cut from (seed 002, sec. 3.1).

A :class:`Veneer` is a flat sheet seen from its show face: ``rgb (h, w, 3)`` float32 in [0, 1],
``mask (h, w)`` bool (True = usable wood), ``px_per_mm``. Sheet frame: x to the right, y down
(as in SVG), millimetres, origin at the sheet's top-left corner; pixel ``(r, c)`` covers
``[c, c + 1] x [r, r + 1] / px_per_mm``.

Three sources:

- :func:`load_scan`: a scanned veneer (image + dpi or px/mm + optional mask image);
- :func:`slice_veneers`: leaves sliced from any woodcam block spec or log (``Wood.color`` on a
  sequence of parallel planes at a pitch of thickness + kerf), every other leaf turned over so
  neighbours are book-matched;
- :func:`mokume_veneers`: the six face photos of a Mokume sample folder.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Literal, Protocol

import numpy as np

from .._checks import as_floats, check_bool, check_number, check_path, check_vector
from .._readers import PHOTO_ALPHA_FIX, photo_rgb8, read_image_file_opacity, read_photo_rgb
from .._repr import summary_repr
from ..errors import WoodcamError
from ..fields.base import rings_crossed


class StockLike(Protocol):
    """What :func:`slice_veneers` needs of a :class:`woodcam.stock.Stock` (the stock layer sits
    above this package, so it is described here rather than imported)."""

    spec: str
    size_mm: tuple[float, float, float]
    wood: object

MM_PER_INCH = 25.4

SliceAxis = Literal["x", "y", "z"]

#: Block axes of a sliced sheet's x (right) and y (down), by the index of the slicing
#: planes' normal (0, 1, 2 = x, y, z): the sheet reads like the block face with that normal
#: in docs/conventions.md.
PLANE_AXES = {0: (1, 2), 1: (0, 2), 2: (0, 1)}


@dataclass
class Veneer:
    """One veneer sheet.

    Attributes
    ----------
    id : str
        Unique name; engraved on the cut files (``veneer_<id>.svg``).
    rgb : (h, w, 3) float32
        Show-face colour in [0, 1], row 0 at the top of the sheet.
    px_per_mm : float
    mask : (h, w) bool
        True where the wood may be used (no background, cracks, screw holes).
    source : str
        Where it came from (file path, block spec + plane), for result.json.
    sheet_mm : (width, height) mm or None
        The sheet's real size when its whole pixel count at ``px_per_mm`` rounds it (a resampled
        scan, a leaf of a size given in mm): the rgb then spans exactly this size, each pixel
        ``sheet_mm / (w, h)`` mm, within half a pixel of ``1 / px_per_mm``. None: ``(w, h) /
        px_per_mm`` exactly.
    """

    __repr__ = summary_repr  # arrays as shapes: a notebook shows one line

    id: str
    rgb: np.ndarray
    px_per_mm: float
    mask: np.ndarray
    source: str = ""
    sheet_mm: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        # checked when made (a veneer of a user's own arrays too): a (h, w) grey rgb, 0..255
        # floats, NaN, a mask of another size or px_per_mm=0 reached the matcher as OpenCV's
        # or numpy's bare errors, or ran on colours out of range
        check_veneer_id(self.id, "veneer id")
        who = f"veneer {self.id!r}"
        rgb = (self.rgb if isinstance(self.rgb, np.ndarray) and self.rgb.dtype == np.float32  # no copy of a scan
               else as_floats(self.rgb))
        if rgb is None or rgb.ndim != 3 or rgb.shape[2] != 3 or 0 in rgb.shape:
            raise WoodcamError(f"{who}: rgb must be an (h, w, 3) RGB image; got "
                               f"{'shape ' + str(rgb.shape) if rgb is not None else repr(self.rgb)[:40]}; "
                               "repeat a grey image into three channels (np.dstack([grey] * 3))")
        rgb = rgb.astype(np.float32, copy=False)
        lo, hi = float(rgb.min()), float(rgb.max())
        if not (np.isfinite(lo) and np.isfinite(hi) and lo >= 0.0 and hi <= 1.0):
            raise WoodcamError(f"{who}: rgb must hold finite values in [0, 1]; got range [{lo:.4g}, {hi:.4g}]; "
                               "divide 0..255 colours by 255")
        self.rgb = rgb
        self.px_per_mm = check_number(self.px_per_mm, f"{who}: px_per_mm", lo=0, lo_open=True,
                                      fix="the sheet's resolution, e.g. 4 (dpi / 25.4)")
        mask = np.asarray(self.mask)
        if mask.dtype != bool and not (np.issubdtype(mask.dtype, np.number) and np.all(np.isfinite(mask))):
            raise WoodcamError(f"{who}: mask must be an (h, w) bool array (True = usable wood); got dtype {mask.dtype}")
        if mask.shape != rgb.shape[:2]:
            got = f"{mask.shape[1]}x{mask.shape[0]}" if mask.ndim == 2 else f"shape {mask.shape}"
            raise WoodcamError(
                f"{who}: the mask must have the image's size {rgb.shape[1]}x{rgb.shape[0]} px; got {got}; "
                "resample the mask to the scan")
        self.mask = mask.astype(bool, copy=False)
        if not isinstance(self.source, str):
            raise WoodcamError(f"{who}: source must be a string (where the sheet came from); got {self.source!r:.40}")
        if self.sheet_mm is not None:
            self.sheet_mm = tuple(float(v) for v in check_vector(
                self.sheet_mm, f"{who}: sheet_mm", n=2, fix="(width, height) in mm, or None"))
            if min(self.sheet_mm) <= 0:
                raise WoodcamError(f"{who}: sheet_mm must be (width, height) > 0 mm; got {self.sheet_mm}")

    @property
    def size_mm(self) -> tuple[float, float]:
        """``(width, height)`` of the sheet in mm (its real size, not the pixel grid's)."""
        if self.sheet_mm is not None:
            return float(self.sheet_mm[0]), float(self.sheet_mm[1])
        h, w = self.rgb.shape[:2]
        return w / self.px_per_mm, h / self.px_per_mm

    def pixel_scale(self) -> tuple[float, float]:
        """``(x, y)`` real mm of one pixel times ``px_per_mm``: 1 on an exact grid, within half a
        pixel over the sheet of 1 on a rounded one. Sheet mm counted in pixels of
        ``1 / px_per_mm`` times this are real mm on the sheet (the cut files' coordinates)."""
        h, w = self.rgb.shape[:2]
        W, H = self.size_mm
        return W * self.px_per_mm / w, H * self.px_per_mm / h

    def resampled(self, px_per_mm: float) -> Veneer:
        """The same sheet at another resolution (area-averaged down, bilinear up)."""
        import cv2

        if abs(px_per_mm - self.px_per_mm) < 1e-9 * px_per_mm:
            return self
        h, w = self.rgb.shape[:2]
        f = px_per_mm / self.px_per_mm
        nw, nh = max(1, round(w * f)), max(1, round(h * f))
        interp = cv2.INTER_AREA if f < 1 else cv2.INTER_LINEAR
        rgb = cv2.resize(self.rgb, (nw, nh), interpolation=interp)
        # A resampled pixel is usable only if all the wood it averages was usable.
        m = cv2.resize(self.mask.astype(np.float32), (nw, nh), interpolation=interp) > 1 - 1e-4
        # the pixel count is rounded: the sheet's real size stays what it was (a 256 px scan at
        # 50 dpi is 130.048 mm, not the 520 px / 4 = 130.000 mm of its working grid)
        return Veneer(self.id, np.clip(rgb, 0, 1).astype(np.float32), px_per_mm, m, self.source,
                      self.size_mm)


def check_veneer_id(value, where: str) -> str:
    """``value`` as a veneer id: it names the sheet's cut files ``veneer_<id>.svg`` / ``.dxf`` in
    the output folder, so it must be a non-empty string that is one file-name part: no ``/`` or
    ``\\`` and no control character (a job file's ``"id": "x/../../x"`` wrote its cut files
    in the output folder's parent, making ``veneer_x/`` on the way).
    ``where`` names the value in the message."""
    if not isinstance(value, str) or not value:
        raise WoodcamError(f"{where} must be a name (a string, it names veneer_<id>.svg); "
                           f"got {value!r}")
    bad = sorted({c for c in value if c in "/\\" or ord(c) < 32 or ord(c) == 127})
    if bad:
        raise WoodcamError(f"{where} must be one file-name part (it names veneer_<id>.svg in the output "
                           f"folder): no '/', '\\' or control characters; got {value!r}, which has "
                           f"{''.join(bad)!r}; use letters, digits, '-', '_' or '.'")
    return value


def _check(v: Veneer) -> Veneer:
    """A veneer a loader made (its arrays checked when made): one with usable wood."""
    if not v.mask.any():
        raise WoodcamError(f"veneer {v.id!r} has zero usable wood (its mask is empty); "
                           "check the mask (white = usable wood)")
    return v


#: A target's transparent pixels and the fix (:func:`woodcam._readers.read_image_file`).
TARGET_ALPHA_FIX = ("a logo or cut-out?", "flatten it onto the background you want the panel to show")
#: A veneer mask's transparent pixels and the fix: the mask is read by its colour alone.
MASK_ALPHA_FIX = ("transparency does not mark wood as unusable",
                  "paint unusable wood black and usable wood white, every pixel opaque")


def read_image(path, what: str = "image", alpha_fix: tuple[str, str] = PHOTO_ALPHA_FIX) -> np.ndarray:
    """Read an image file as ``(h, w, 3)`` float32 RGB in [0, 1] (grey is repeated), upright as
    its EXIF orientation says (:func:`woodcam._readers.read_photo_rgb`; ``alpha_fix`` as there)."""
    return _float_rgb(read_photo_rgb(Path(path), what, alpha_fix))


def _float_rgb(rgb8: np.ndarray) -> np.ndarray:
    """``(h, w, 3)`` uint8 as float32 in [0, 1]."""
    # one pass into one float array: astype then / 255 made two (a 100 Mpx target peaked at
    # 2.4 GB and spent 10 s there); float32 arithmetic both ways, so the same values
    out = np.empty(rgb8.shape, np.float32)
    return np.divide(rgb8, np.float32(255.0), out=out)


def dpi_tag(path: str | Path) -> float | None:
    """The resolution a scan file states (PNG pHYs, JPEG/TIFF density), dpi, or None when it
    states none, states a placeholder (72 or 96 dpi: :data:`~woodcam.tolerances.DPI_PLACEHOLDERS`,
    what cameras and editors write without measuring) or cannot be read (reading it properly is
    :func:`load_scan`'s business)."""
    from PIL import Image

    from ..tolerances import DPI_PLACEHOLDER_TOL, DPI_PLACEHOLDERS

    try:
        with Image.open(path) as im:
            tag = im.info.get("dpi")
    except Exception:  # noqa: BLE001 - any unreadable file: the scan's own reader says why
        return None
    try:
        dpi = float(tag[0])
    except (TypeError, ValueError, IndexError):
        return None
    if not np.isfinite(dpi) or dpi <= 1 or any(abs(dpi - p) <= DPI_PLACEHOLDER_TOL for p in DPI_PLACEHOLDERS):
        return None
    return dpi


def load_scan(path: str | Path, *, dpi: float | None = None, px_per_mm: float | None = None,
              mask: str | Path | np.ndarray | None = None, id: str | None = None) -> Veneer:
    """A scanned veneer.

    Parameters
    ----------
    path : image file (PNG/JPEG/TIFF)
    dpi, px_per_mm : float
        Scan resolution; exactly one of them (``px_per_mm = dpi / 25.4``).
    mask : image file or ``(h, w)`` bool array, optional
        Usable wood (white / True); must have the scan's size. Default: the whole sheet. A
        scan's pixels that are not fully opaque (a cut-out's background) are never usable wood.
    id : str, optional
        Default: the file's stem.
    """
    path = check_path(path, "load_scan: path", fix="a PNG, JPEG or TIFF scan of the veneer")
    if (dpi is None) == (px_per_mm is None):
        raise WoodcamError(f"scan {str(path)!r}: give exactly one of dpi or px_per_mm; got "
                           f"dpi={dpi}, px_per_mm={px_per_mm} (e.g. SCAN.png:300 for 300 dpi)")
    ppm = (check_number(px_per_mm, "px_per_mm", lo=0, lo_open=True, fix="e.g. 11.8 (300 dpi)") if px_per_mm is not None
           else check_number(dpi, "dpi", lo=0, lo_open=True, fix="the scan's resolution, e.g. 300") / MM_PER_INCH)
    # a cut-out scan's transparent pixels are no wood (its background): they were read as the
    # colour stored under them, and pieces were cut from them
    image, opaque = read_image_file_opacity(path, "veneer scan", None)
    rgb = _float_rgb(photo_rgb8(image))
    vid = id or Path(path).stem
    mask_file = None
    if mask is None:
        m = np.ones(rgb.shape[:2], bool)
    elif isinstance(mask, (np.ndarray, list)):
        m = np.asarray(mask)
        if m.dtype != bool and not (np.issubdtype(m.dtype, np.number) and np.all(np.isfinite(m))):
            # NaN was True (usable wood) silently, a list Path()'s TypeError
            raise WoodcamError(f"load_scan: mask must be an (h, w) bool array (True = usable wood) or an image file; "
                               f"got dtype {m.dtype}" + (" with NaN/inf" if np.issubdtype(m.dtype, np.number) else ""))
        m = m.astype(bool)
    else:
        # white where the mean of R, G, B over 255 is above 0.5, on the 8-bit values: the float
        # image (12 bytes a pixel) of a scan-sized mask was made only to be thresholded
        mask_file = check_path(mask, "load_scan: mask", fix="an image file or an (h, w) bool array")
        m = read_photo_rgb(mask_file, "veneer mask", MASK_ALPHA_FIX).sum(axis=2, dtype=np.uint16) > 382
        if m.shape != rgb.shape[:2]:  # both files named: Veneer's own check knows neither
            raise WoodcamError(
                f"veneer {vid!r}: its mask {str(mask_file)!r} is {m.shape[1]}x{m.shape[0]} px and its scan "
                f"{str(path)!r} {rgb.shape[1]}x{rgb.shape[0]} px; the mask must have the scan's size (one mask "
                "pixel per scan pixel); resample the mask to the scan")
    if opaque is not None and m.shape == opaque.shape:  # a mask array of another size: Veneer says so
        m = m & opaque
    if m.shape == rgb.shape[:2] and not m.any():
        # said by what emptied it: 'its mask is empty; check the mask' was said of a scan given
        # no mask whose pixels are all transparent
        if mask_file is not None:
            why = (f"its mask {str(mask_file)!r} has no white pixel" + (" where the scan is opaque"
                   if opaque is not None and not opaque.all() else "")
                   + " (white, a mean of R, G and B above half, marks usable wood); paint the usable wood "
                   "white, or give no mask for the whole sheet")
        elif mask is not None:
            why = "its mask array is False everywhere (True marks usable wood)"
        else:
            why = (f"every pixel of the scan {str(path)!r} is transparent (a cut-out's background is no "
                   "wood); give the scan with its wood opaque")
        raise WoodcamError(f"veneer {vid!r} has zero usable wood: {why}")
    return _check(Veneer(vid, rgb, ppm, m, str(path)))


def mokume_veneers(folder: str | Path, size_mm: float = 50.0) -> list[Veneer]:
    """The face photos ``A_col.png`` .. ``F_col.png`` of a Mokume sample as veneers, their names
    in any case (``A_COL.PNG``; :func:`woodcam.block.io.mokume_files`, the one reader of a
    Mokume sample's names: only lower-case ones were found here).

    ``folder``: the sample's folder (e.g. ``shared/data/mokume/H11``). The cubes are ``size_mm``
    on a side (the dataset does not store it; woodcam's Mokume
    default is 50 mm), so a 256 px photo is ``256 / size_mm`` px/mm.
    """
    folder = check_path(folder, "mokume_veneers: folder", fix="a Mokume sample folder such as shared/data/mokume/H11")
    # 0 was a ZeroDivisionError, NaN refused as the veneer's 'px_per_mm'
    size_mm = check_number(size_mm, "size_mm", lo=0, lo_open=True, fix="the cube's side in mm, e.g. 50")
    from ..block.io import mokume_files
    from ..frames import FACES, MOKUME_LETTER

    photos = {MOKUME_LETTER[face]: files["col"] for face in FACES
              if "col" in (files := mokume_files(folder, face) if folder.is_dir() else {})}
    if not photos:
        raise WoodcamError(f"Mokume folder {str(folder)!r} holds no face photos (A_col.png .. "
                           "F_col.png); pass a Mokume sample folder")
    out = []
    for letter, f in sorted(photos.items()):
        rgb = read_image(f, "Mokume photo")
        out.append(_check(Veneer(f"{folder.name}-{letter}", rgb, rgb.shape[1] / size_mm,
                                 np.ones(rgb.shape[:2], bool), str(f))))
    return out


def slice_veneers(stock: StockLike, n_sheets: int, size_mm: tuple[float, float], *,
                  thickness_mm: float = 0.6, kerf_mm: float = 0.4, px_per_mm: float = 4.0,
                  axis: SliceAxis = "y", start_mm: float | None = None,
                  id_prefix: str | None = None, progress: bool = False,
                  supersample: int = 3, adaptive: bool = True) -> list[Veneer]:
    """Leaves sliced from a woodcam block or log, coloured by its ``Wood``.

    Leaf ``k`` is the slab between ``s_k = start + k (thickness + kerf)`` and ``s_k + thickness``
    along ``axis`` (block frame). Even leaves show the face at ``s_k`` (looking along +axis),
    odd leaves are turned over and show the face at ``s_k + thickness`` mirrored left-right:
    neighbours are book-matched, as a veneer slicer's leaves are laid out. The sheet covers
    ``size_mm = (width, height)`` mm of the plane starting at the block's origin corner. It
    slices where it is told: a sheet larger than the block's face, or a plane past its back
    face, is wood of the field beyond the block (for a ``builtin:`` or ``log:`` field the same
    tree's larger flitch; for a fitted or grown block an extrapolation, wood the block does
    not hold). ``woodcam parquetry`` and job files refuse such leaves
    (:func:`woodcam.parquetry.job.check_leaves_in_block`): every sheet is wood of the block.

    Parameters
    ----------
    stock : :class:`woodcam.stock.Stock` (``woodcam.open_stock(spec)``: the stock layer sits
        above this package, so the caller opens it)
    n_sheets : int
    size_mm : (width, height) mm of each sheet
    thickness_mm, kerf_mm : leaf thickness and the saw kerf between leaves (mm)
    px_per_mm : sheet resolution
    axis : "x", "y" or "z": the normal of the slicing planes
    start_mm : first plane along ``axis`` (default: the middle of the block)
    id_prefix : leaf ``k``'s id is ``f"{id_prefix}-{k:02d}"``; default the stock's spec with
        ``:``, ``/`` and ``\\`` made ``-`` (``builtin:flat-sawn``: ``builtin-flat-sawn-00``, ...)
    progress : a bar on stderr, one step per sheet (off by default)
    supersample : each pixel is the mean of ``supersample x supersample`` point samples of
        ``Wood.color`` over its square, as a scanner integrates over its pixel. One sample per
        pixel aliases the 0.1-0.3 mm latewood lines into stair-steps at 4 px/mm, which adds
        ~20 % of Sobel energy (eq. 1's edge channel) that no real veneer has; 3 is within 2 %
        of 8 in that energy (woodcam's walnut, maple, oak, cherry at 4 px/mm). Only pixels
        where the wood varies at their scale are supersampled, and across the grain only
        where it runs along a pixel axis (see :func:`_supersampled`).
    adaptive : False takes all ``supersample^2`` samples of every pixel (about three times
        the cost; the adaptive sheets differ from it by ~3e-4 on average and carry 0.4-1 %
        more Sobel energy: walnut, maple, oak, cherry at 4 px/mm).
    """
    if not hasattr(stock, "wood") or not hasattr(stock, "size_mm"):
        raise WoodcamError(f"stock must be a woodcam Stock (woodcam.open_stock(spec)); got "
                           f"{type(stock).__name__}")
    # each number by name: n_sheets=1.5 or '2', size_mm of 1 or 3 numbers, a NaN size or
    # px_per_mm and a string start_mm were bare TypeError/ValueError; a NaN thickness, kerf or
    # start_mm was refused as NaN 'points_mm'; supersample=1.5 ran as 1
    n_sheets = int(check_number(n_sheets, "n_sheets", lo=1, integer=True, fix="e.g. 4"))
    thickness_mm = check_number(thickness_mm, "thickness_mm", lo=0, lo_open=True, fix="leaf thickness, e.g. 0.6")
    kerf_mm = check_number(kerf_mm, "kerf_mm", lo=0, fix="saw kerf between leaves, e.g. 0.4")
    px_per_mm = check_number(px_per_mm, "px_per_mm", lo=0, lo_open=True, fix="sheet resolution, e.g. 4")
    if start_mm is not None:
        start_mm = check_number(start_mm, "start_mm", fix="the first plane along axis, mm, or None for the middle")
    if axis not in ("x", "y", "z"):
        raise WoodcamError(f"axis must be one of ['x', 'y', 'z']; got {axis!r}")
    ss = int(check_number(supersample, "supersample", lo=1, hi=16, integer=True, fix="e.g. 3"))
    progress, adaptive = check_bool(progress, "progress"), check_bool(adaptive, "adaptive")
    size = check_vector(size_mm, "size_mm", n=2, fix="(width, height) of each sheet in mm, e.g. (200, 100)")
    w_mm, h_mm = float(size[0]), float(size[1])
    nw, nh = round(w_mm * px_per_mm), round(h_mm * px_per_mm)
    if nw < 1 or nh < 1:
        raise WoodcamError(f"size_mm must give at least one pixel at {px_per_mm} px/mm; got {size_mm}")
    from ..limits import check_grid, check_limit

    # what is held: every leaf an RGB float32 image, and one leaf's working arrays while it is
    # sampled (1e300 mm sheets were a traceback). The ss x ss samples of a pixel are summed as
    # they come, never held: counting them as cells refused the README's own default (two
    # 600 x 400 mm leaves at 4 px/mm, 207 M 'cells' for 23 M held)
    what = f"{n_sheets} leaves of {w_mm:g} x {h_mm:g} mm at {px_per_mm:g} px/mm"
    fix = "use smaller or fewer sheets (--sheet-size, --sheets) or a lower px_per_mm"
    check_grid((n_sheets, nh, nw, 3), what, itemsize=4, fix=fix)
    check_limit("MAX_ALLOC_BYTES", float(nh) * nw * (n_sheets * 12 + _WORK_BYTES_PER_PX),
                f"{what} (memory)", fix)
    ax = "xyz".index(axis)
    # In-plane directions: sheet x (right) and sheet y (down) as block axes, chosen so the
    # sheet reads like the block face with that normal in docs/conventions.md.
    right, down_axis = PLANE_AXES[ax]
    pitch = thickness_mm + kerf_mm
    start = stock.size_mm[ax] / 2.0 if start_mm is None else float(start_mm)
    top = stock.size_mm[down_axis] if down_axis == 2 else 0.0
    prefix = id_prefix or stock.spec.replace(":", "-").replace("/", "-").replace("\\", "-").strip("-.")
    sheets, flat = [], []

    def plane_points(s, u_mm, v_mm):
        """Block-frame points ``(n, 3)`` of sheet points ``(u, v)`` mm (1-d arrays) of plane ``s``."""
        pts = np.empty((u_mm.size, 3), np.float64)
        pts[:, ax] = s
        pts[:, right] = u_mm
        # Z grows up while sheet rows grow down; other axes run with the rows.
        pts[:, down_axis] = (top - v_mm) if down_axis == 2 else v_mm
        return pts

    from ..appearance.wood import wood_colors  # the checked seam: a user's wood's colours

    years_of = getattr(stock.wood, "years", None)
    it = range(n_sheets)
    if progress:
        from .._progress import progress_bar

        it = progress_bar(it, desc="slicing veneers", unit="sheet")
    for k in it:
        turned = k % 2 == 1
        s = start + k * pitch + (thickness_mm if turned else 0.0)

        def colour(u_mm, v_mm, s=s, turned=turned):
            """``Wood.color`` at sheet points ``(u, v)`` mm (1-d arrays) of plane ``s``:
            ``(n, 3)`` float32, evaluated :data:`_SAMPLES_PER_CALL` points at a time."""
            out = np.empty((u_mm.size, 3), np.float32)
            normal = np.zeros(3)
            normal[ax] = 1.0 if turned else -1.0
            for a in range(0, u_mm.size, _SAMPLES_PER_CALL):
                b = min(u_mm.size, a + _SAMPLES_PER_CALL)
                pts = plane_points(s, u_mm[a:b], v_mm[a:b])
                normals = np.broadcast_to(normal, pts.shape)
                out[a:b] = wood_colors(stock.wood, pts, normals)
            return out

        # nw x nh pixels span the sheet exactly (8 in at 4 px/mm: 813 px of 0.24993 mm)
        rgb = _supersampled(colour, nh, nw, (w_mm / nw, h_mm / nh), ss, adaptive)
        if turned:
            rgb = rgb[:, ::-1]
        if callable(years_of):  # a leaf in one growth layer is one flat colour: said below
            u, v = (g.ravel() for g in np.meshgrid(np.linspace(0, w_mm, 33), np.linspace(0, h_mm, 33)))
            years = np.asarray(years_of(plane_points(s, u, v)), float)
            if rings_crossed(years) == 0:
                flat.append(f"leaf {k} at {axis}={s:g} mm (years {np.nanmin(years):.3g} to {np.nanmax(years):.3g})")
        sheets.append(_check(Veneer(f"{prefix}-{k:02d}", np.ascontiguousarray(rgb, np.float32),
                                    float(px_per_mm), np.ones((nh, nw), bool),
                                    f"{stock.spec} leaf {k} at {axis}={s:g} mm"
                                    + (" (turned over)" if turned else ""), (float(w_mm), float(h_mm)))))
    if flat:  # the wood the user slices should show its rings, or say why it does not
        import warnings

        from ..errors import WoodcamWarning

        warnings.warn(f"veneers of {stock.spec}: {len(flat)} of {n_sheets} leaves lie in one growth layer and show "
                      f"no ring, one flat colour: {'; '.join(flat[:3])}{'; ...' if len(flat) > 3 else ''}; slice "
                      f"across the rings (another axis than {axis}, --slice-axis), larger leaves (--sheet-size), or "
                      "from wood of more years", WoodcamWarning, stacklevel=2)
    return sheets


#: Bytes per pixel of the one leaf :func:`slice_veneers` is sampling, beside the leaves kept
#: (12 a pixel): the centres' coordinates (float64, 16), their colours (12), the pixels to
#: refine and their sums (float64, up to 24 and 16 of index), the variation maps (~24).
_WORK_BYTES_PER_PX = 96

#: Points per ``Wood.color`` call in :func:`slice_veneers` (positions, normals and colours of
#: a call take ~70 MB).
_SAMPLES_PER_CALL = 1_000_000

#: How much stronger (Sobel of the centre samples' luma) the variation along one pixel axis
#: must be than along the other for :func:`_supersampled` to sample that pixel across it only;
#: 6 (an angle within ~10 degrees of the axis) where 3 gave 1.5 times the Sobel-energy
#: excess for 10 % fewer samples.
_ONE_D = 6.0


def _supersampled(colour, nh: int, nw: int, pixel_mm: tuple[float, float], ss: int,
                  adaptive: bool = True) -> np.ndarray:
    """A sheet ``(nh, nw, 3)`` float32 whose pixels are the mean of ``ss x ss`` point samples
    of ``colour(u_mm, v_mm)`` over their rectangles of ``pixel_mm = (pu, pv)`` mm (sample
    ``(i, j)`` of pixel ``(r, c)`` at ``((c + (j + 0.5) / ss) pu, (r + (i + 0.5) / ss) pv)``).

    adaptive : first every pixel's centre is sampled. A pixel whose 3 x 3 neighbourhood of
        centres varies by at most :data:`~woodcam.tolerances.PARQUETRY_SUPERSAMPLE_TOL` keeps
        its centre (the wood is smooth over it). Where the variation runs along one pixel axis
        (Sobel of the centres' luma ``_ONE_D`` times stronger along it than across: latewood
        lines and pores lying along the other axis, as in most of a sliced leaf) the pixel
        gets the ``ss`` samples of its middle row or column, across the lines; only the rest
        gets all ``ss^2``. About a third of the samples of full supersampling.
    """
    import cv2

    from ..tolerances import PARQUETRY_SUPERSAMPLE_TOL

    pu, pv = pixel_mm
    uc = (np.arange(nw) + 0.5) * pu
    vc = (np.arange(nh) + 0.5) * pv
    t = [(j + 0.5) / ss - 0.5 for j in range(ss)]
    if not adaptive:
        cu, cv_ = np.meshgrid(uc, vc)
        cu, cv_ = cu.ravel(), cv_.ravel()
        acc = np.zeros((cu.size, 3))
        for dv in t:
            for du in t:
                acc += colour(cu + du * pu, cv_ + dv * pv)
        return (acc / (ss * ss)).reshape(nh, nw, 3).astype(np.float32)
    cu, cv_ = np.meshgrid(uc, vc)
    rgb = colour(cu.ravel(), cv_.ravel()).reshape(nh, nw, 3)
    if ss == 1:
        return rgb
    box = np.ones((3, 3), np.uint8)
    spread = (cv2.dilate(rgb, box) - cv2.erode(rgb, box)).max(axis=2)
    luma = rgb @ np.array([0.299, 0.587, 0.114], np.float32)
    gx = np.abs(cv2.Sobel(luma, cv2.CV_32F, 1, 0, ksize=3))
    gy = np.abs(cv2.Sobel(luma, cv2.CV_32F, 0, 1, ksize=3))
    need = spread > PARQUETRY_SUPERSAMPLE_TOL
    across_x = need & (gx > _ONE_D * gy)
    across_y = need & (gy > _ONE_D * gx)
    full = need & ~across_x & ~across_y
    sets = ((full, [(du, dv) for dv in t for du in t]), (across_x, [(du, 0.0) for du in t]),
            (across_y, [(0.0, dv) for dv in t]))
    for mask, offs in sets:
        rr, cc = np.nonzero(mask)
        if rr.size == 0:
            continue
        acc = np.zeros((rr.size, 3))
        for du, dv in offs:
            # the centre (odd ss) was sampled already
            acc += rgb[rr, cc] if du == dv == 0.0 else colour(uc[cc] + du * pu, vc[rr] + dv * pv)
        rgb[rr, cc] = (acc / len(offs)).astype(np.float32)
    return rgb
