"""The block frame, its six faces and the pixel <-> block mapping (``docs/conventions.md`` in code).

Block frame: origin at the block's bottom-front-left corner, ``+X`` right (width ``W``), ``+Y``
away from the viewer (depth ``D``), ``+Z`` up (height ``H``); the block is
``[0, W] x [0, D] x [0, H]`` in millimetres. Face images are seen from outside the block; pixel
``(row r, col c)`` of an ``n_rows x n_cols`` image has ``u = (c + 0.5) / n_cols`` and
``v = (r + 0.5) / n_rows`` and maps to the block by the table in :data:`_FACE_MAPS`.
Pixel coordinates here are continuous: pixel centres sit at integer ``(r, c)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, TypeVar, get_args

import numpy as np

from ._checks import as_floats, numbers_fix, received
from ._types import ArrayLike
from .errors import WoodcamError
from .units import say_length

_G = TypeVar("_G")  # a trimesh.Trimesh or trimesh.Scene, returned as given

FaceName = Literal["front", "top", "left", "bottom", "right", "back"]

#: The six faces in the conventions' order.
FACES: tuple[FaceName, ...] = get_args(FaceName)

#: The faces at each block axis' low and high end (x = 0 and W, y = 0 and D, z = 0 and H): what
#: the end thirds of the block, or of a part, along that axis are called.
AXIS_ENDS: tuple[tuple[FaceName, FaceName], ...] = (("left", "right"), ("front", "back"), ("bottom", "top"))

#: Mokume dataset letter of each face.
MOKUME_LETTER: dict[FaceName, str] = {
    "front": "A", "top": "B", "left": "C", "bottom": "D", "right": "E", "back": "F",
}
FACE_OF_LETTER: dict[str, FaceName] = {v: k for k, v in MOKUME_LETTER.items()}

#: Outward unit normal of each face in the block frame.
FACE_NORMAL: dict[FaceName, tuple[int, int, int]] = {
    "front": (0, -1, 0), "top": (0, 0, 1), "left": (-1, 0, 0),
    "bottom": (0, 0, -1), "right": (1, 0, 0), "back": (0, 1, 0),
}

#: Axis (0 = X, 1 = Y, 2 = Z) each face is perpendicular to.
FACE_AXIS: dict[FaceName, int] = {f: int(np.flatnonzero(n)[0]) for f, n in FACE_NORMAL.items()}

# For each face: (X, Y, Z) as affine functions of (u, v) in units of (W, D, H).
# Each entry is (constant, du coefficient, dv coefficient) for one block coordinate,
# straight from the table in conventions.md.
_FACE_MAPS: dict[FaceName, tuple[tuple[float, float, float], ...]] = {
    #          X               Y               Z
    "front":  ((0, 1, 0),     (0, 0, 0),      (1, 0, -1)),
    "back":   ((1, -1, 0),    (1, 0, 0),      (1, 0, -1)),
    "top":    ((0, 1, 0),     (1, 0, -1),     (1, 0, 0)),
    "bottom": ((0, 1, 0),     (0, 0, 1),      (0, 0, 0)),
    "left":   ((0, 0, 0),     (1, -1, 0),     (1, 0, -1)),
    "right":  ((1, 0, 0),     (0, 1, 0),      (1, 0, -1)),
}


def check_face(face: str) -> FaceName:
    """Return ``face`` as a :data:`FaceName`, accepting Mokume letters ``A``..``F`` too."""
    if face in FACES:
        return face  # type: ignore[return-value]
    if isinstance(face, str) and face.upper() in FACE_OF_LETTER:
        return FACE_OF_LETTER[face.upper()]
    raise WoodcamError(
        f"face must be one of {', '.join(FACES)} or a Mokume letter A-F; got {face!r}"
    )


def check_size(size_mm) -> np.ndarray:
    """Validate a block size ``(W, D, H)`` in mm and return it as a float array of shape (3,)."""
    size = as_floats(size_mm)
    if size is None or size.shape != (3,) or not np.all(np.isfinite(size)) or np.any(size <= 0):
        raise WoodcamError(
            f"size_mm must be three positive finite lengths (W, D, H) in mm; got {size_mm!r}; "
            "pass the block size, e.g. size_mm=(100, 80, 50)"
        )
    return size


def face_image_size_mm(face: str, size_mm) -> tuple[float, float]:
    """Physical ``(height, width)`` in mm that a face image of ``face`` covers (rows, cols)."""
    face = check_face(face)
    W, D, H = check_size(size_mm)
    return {
        "front": (H, W), "back": (H, W), "top": (D, W), "bottom": (D, W),
        "left": (H, D), "right": (H, D),
    }[face]


def _affine(face: FaceName, size) -> tuple[np.ndarray, np.ndarray]:
    """Return ``(A, b)`` with ``xyz = A @ (u, v) + b`` for one face; A is (3, 2), b is (3,)."""
    m = np.asarray(_FACE_MAPS[face], dtype=float)  # (3, 3): const, du, dv per coordinate
    return m[:, 1:] * size[:, None], m[:, 0] * size


def uv_to_block(face: str, u, v, size_mm) -> np.ndarray:
    """Map face coordinates ``u, v`` in [0, 1] (any broadcastable shapes) to block points.

    Returns
    -------
    points_mm : (..., 3) float
    """
    face = check_face(face)
    A, b = _affine(face, check_size(size_mm))
    uv = np.stack(np.broadcast_arrays(np.asarray(u, float), np.asarray(v, float)), axis=-1)
    return np.einsum("...j,kj->...k", uv, A) + b  # einsum: see LogFrame.to_log


def pixel_to_block(face: str, rows: ArrayLike, cols: ArrayLike, image_shape: ArrayLike,
                   size_mm: ArrayLike) -> np.ndarray:
    """Map continuous pixel coordinates of a face image to block points (mm).

    Parameters
    ----------
    face : FaceName or Mokume letter
    rows, cols : array_like
        Pixel coordinates, centre of pixel ``(r, c)`` at integer values; broadcast together.
    image_shape : (n_rows, n_cols)
    size_mm : (W, D, H)

    Returns
    -------
    points_mm : (..., 3) float, on the face plane.
    """
    n_rows, n_cols = _check_shape(image_shape)
    r, c = _pixel_coords(rows, "rows"), _pixel_coords(cols, "cols")
    try:  # rows of 2 and cols of 3 were numpy's broadcast ValueError from inside uv_to_block
        r, c = np.broadcast_arrays(r, c)
    except ValueError:
        raise WoodcamError(f"rows and cols must broadcast together (one pixel coordinate each); got "
                           f"shapes {r.shape} and {c.shape}; pass as many rows as cols") from None
    return uv_to_block(face, (c + 0.5) / n_cols, (r + 0.5) / n_rows, size_mm)


def _pixel_coords(value, name: str) -> np.ndarray:
    """Pixel coordinates ``rows``/``cols`` as a finite float array: a string was numpy's bare
    ValueError, a NaN a NaN point on the face."""
    a = as_floats(value)
    if a is None or not np.all(np.isfinite(a)):
        raise WoodcamError(f"{name} must be finite pixel coordinates (numbers); got {value!r:.80}; "
                           "pass the trace's points, e.g. points_px[:, 0] for rows")
    return a


def block_to_pixel(face: str, points_mm: ArrayLike, image_shape: ArrayLike,
                   size_mm: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Inverse of :func:`pixel_to_block`: project block points onto a face image.

    The coordinate normal to the face is ignored (orthographic projection along the normal).

    Parameters
    ----------
    face : FaceName or Mokume letter
        ``"front"``, ``"top"``, ... (:data:`FACES`) or ``"A"``-``"F"`` (:data:`MOKUME_LETTER`).
    points_mm : (..., 3) float
        Points in mm in the block frame (origin bottom-front-left, X width, Y depth, Z up).
    image_shape : (n_rows, n_cols)
        The face image's size in pixels.
    size_mm : (W, D, H)
        The block's size in mm.

    Returns
    -------
    rows, cols : (...,) float, continuous pixel coordinates.
    """
    face = check_face(face)
    n_rows, n_cols = _check_shape(image_shape)
    A, b = _affine(face, check_size(size_mm))
    p = as_floats(points_mm)
    if p is None or p.ndim == 0 or p.shape[-1] != 3:  # a scalar was an IndexError
        # the shape, not the points: a (100000, 2) array printed whole was the message
        got = f"shape {p.shape}" if p is not None and p.ndim and p.size else received(points_mm)
        rule = "have shape (..., 3) in mm" if p is not None else "be real numbers, shape (..., 3) in mm"
        raise WoodcamError(f"points_mm must {rule}; got {got}; "
                           + (numbers_fix(points_mm, "points_mm") or "pass block points, e.g. [[10, 20, 5]]"))
    if not np.all(np.isfinite(p)):  # a NaN point was a NaN pixel, passed on silently
        bad = np.argwhere(~np.isfinite(p))[0][:-1]
        raise WoodcamError(f"points_mm must be finite; point {tuple(int(i) for i in bad)} is "
                           f"{p[tuple(bad)].tolist()}; drop the points outside the block first")
    # Each column of A has exactly one non-zero entry, so (u, v) is read off two coordinates.
    iu, iv = int(np.flatnonzero(A[:, 0])[0]), int(np.flatnonzero(A[:, 1])[0])
    u = (p[..., iu] - b[iu]) / A[iu, 0]
    v = (p[..., iv] - b[iv]) / A[iv, 1]
    return v * n_rows - 0.5, u * n_cols - 0.5


def face_pixel_points(face: str, image_shape, size_mm) -> np.ndarray:
    """Block points (mm) of every pixel centre of a face image, shape ``(n_rows, n_cols, 3)``."""
    n_rows, n_cols = _check_shape(image_shape)
    # The map is affine in (row, col): the origin and two steps, broadcast (a BLAS matmul of
    # (n, 2) x (2, 3) is slow); tests/test_frames.py checks it against pixel_to_block.
    shape = (n_rows, n_cols)
    p0 = pixel_to_block(face, 0.0, 0.0, shape, size_mm)
    dr = pixel_to_block(face, 1.0, 0.0, shape, size_mm) - p0
    dc = pixel_to_block(face, 0.0, 1.0, shape, size_mm) - p0
    r = np.arange(n_rows, dtype=float)[:, None, None]
    c = np.arange(n_cols, dtype=float)[None, :, None]
    return p0 + r * dr + c * dc


def _check_shape(image_shape) -> tuple[int, int]:
    """``(n_rows, n_cols)`` of ``image_shape`` (an image's ``.shape``: extra channel counts are
    ignored), whole pixel counts > 0; a scalar, a NaN or 10.7 rows is refused, not truncated."""
    try:
        head = as_floats(tuple(image_shape)[:2])
    except TypeError:  # not iterable: a scalar
        head = None
    if head is None or head.shape != (2,) or not np.all(np.isfinite(head)) or np.any(head <= 0) \
            or np.any(head != np.round(head)):
        raise WoodcamError(f"image_shape must be (n_rows, n_cols), whole pixel counts > 0; got "
                           f"{image_shape!r}; pass the face image's .shape")
    return int(head[0]), int(head[1])


# -- the unfolded cross --------------------------------------------------------------------------

#: Grid cell (row, col) of each face in the unfolded cross: left|front|right|back in the middle
#: row, top above front, bottom below front.
CROSS_CELL: dict[FaceName, tuple[int, int]] = {
    "top": (0, 1), "left": (1, 0), "front": (1, 1), "right": (1, 2), "back": (1, 3),
    "bottom": (2, 1),
}


@dataclass(frozen=True)
class CrossLayout:
    """Pixel layout of the six faces in one unfolded-cross image at ``px_per_mm``.

    ``origin[face]`` is the (row, col) of the face image's top-left pixel in the cross image.
    """

    size_mm: tuple[float, float, float]
    px_per_mm: float

    def face_shape(self, face: FaceName) -> tuple[int, int]:
        h, w = face_image_size_mm(face, self.size_mm)
        return max(1, round(h * self.px_per_mm)), max(1, round(w * self.px_per_mm))

    @property
    def origin(self) -> dict[FaceName, tuple[int, int]]:
        W, D, H = (round(s * self.px_per_mm) for s in self.size_mm)
        col0 = {0: 0, 1: D, 2: D + W, 3: 2 * D + W}
        row0 = {0: 0, 1: D, 2: D + H}
        return {f: (row0[r], col0[c]) for f, (r, c) in CROSS_CELL.items()}

    @property
    def shape(self) -> tuple[int, int]:
        W, D, H = (round(s * self.px_per_mm) for s in self.size_mm)
        return 2 * D + H, 2 * D + 2 * W


def unfold_cross(images: dict, size_mm: ArrayLike, background: float | ArrayLike = 0) -> np.ndarray:
    """Lay six face images (dict face -> (h, w[, c]) array) out as one unfolded-cross image.

    All images must share one pixel density; faces that are absent stay ``background``.
    ``size_mm``: the block's ``(W, D, H)`` mm, which sets each face's place and extent in the
    cross (the density is read from the first image's width over its face's width in mm).
    """
    size = check_size(size_mm)
    if not isinstance(images, dict):
        raise WoodcamError(f"images must be a dict face name -> image; got {type(images).__name__}; "
                           "e.g. {'front': photo}")
    faces = {check_face(k): np.asarray(v) for k, v in images.items()}
    if not faces:
        raise WoodcamError("images must hold at least one face image; got an empty dict")
    f0, im0 = next(iter(faces.items()))
    for face, im in faces.items():
        # a NaN image was laid out as it was; one of strings or None failed deep in numpy
        if im.dtype.kind not in "buif" or (im.dtype.kind == "f" and not np.all(np.isfinite(im))):
            bad = int(np.sum(~np.isfinite(im))) if im.dtype.kind == "f" else None
            raise WoodcamError(f"image of face {face!r} must hold finite numbers; got " + (
                f"{bad} NaN/inf of {im.size} values; fill the missing pixels first (e.g. np.nan_to_num(image))"
                if bad is not None else f"dtype {im.dtype}; pass a numeric image array (uint8 or floats)"))
    for face, im in faces.items():  # a 1-D image, or grey beside RGB, failed deep in numpy
        if im.ndim not in (2, 3) or im.shape[2:] != im0.shape[2:]:
            raise WoodcamError(f"image of face {face!r} must be (h, w) or (h, w, c) with the channels of "
                               f"face {f0!r} {im0.shape[2:]}; got shape {im.shape}; convert all faces "
                               "to one kind (all grey or all RGB)")
    bg = as_floats(background)
    if bg is None or bg.ndim > 1 or (bg.ndim == 1 and bg.shape != im0.shape[2:]) or not np.all(np.isfinite(bg)):
        raise WoodcamError(f"background must be one value or one per channel {im0.shape[2:]}; got "
                           f"{background!r}; e.g. background=0")
    px_per_mm = im0.shape[1] / face_image_size_mm(f0, size)[1]
    layout = CrossLayout(tuple(size), px_per_mm)
    from .limits import check_grid

    # a thin 50000 x 100 px face of a flat block made a 14 GiB cross
    check_grid(layout.shape + im0.shape[2:], "the unfolded cross", itemsize=im0.dtype.itemsize)
    out = np.full(layout.shape + im0.shape[2:], background, dtype=im0.dtype)
    for face, im in faces.items():
        want = layout.face_shape(face)
        if im.shape[:2] != want and all(abs(a - b) <= max(2, 0.01 * b) for a, b in zip(im.shape[:2], want)):
            # a rounding apart, not another density: a face of round(43.5 mm x 5.9 px/mm) pixels
            # enlarged twice is a pixel off the slot of round(43.5 mm x 11.8 px/mm) (rings show
            # failed at its default zoom); cut or edge-pad the last row/column
            im = np.pad(im[:want[0], :want[1]], [(0, max(0, want[0] - im.shape[0])),
                                                 (0, max(0, want[1] - im.shape[1]))] + [(0, 0)] * (im.ndim - 2),
                        mode="edge")
        if im.shape[:2] != want:
            raise WoodcamError(
                f"image of face {face!r} must be {want[0]}x{want[1]} px to share the density "
                f"{px_per_mm:.3g} px/mm of face {f0!r}; got {im.shape[0]}x{im.shape[1]}"
            )
        r0, c0 = layout.origin[face]
        out[r0:r0 + want[0], c0:c0 + want[1]] = im
    return out


# ------------------------------------------------------------------ frames of exported files

#: Block frame (mm, Z up) -> glTF scene (m, Y up): ``p_gltf = BLOCK_TO_GLTF @ [p_mm, 1]``.
#: Block +X (width, right) stays +X, block +Z (up) becomes +Y, block +Y (away from the viewer)
#: becomes -Z (glTF cameras look down -Z, so -Z is "away"). Right-handed (determinant > 0).
BLOCK_TO_GLTF = np.array([[1e-3, 0.0, 0.0, 0.0],
                          [0.0, 0.0, 1e-3, 0.0],
                          [0.0, -1e-3, 0.0, 0.0],
                          [0.0, 0.0, 0.0, 1.0]])

#: A glTF file that woodcam did not write is in metres with +Y up by the glTF 2.0 spec, yet some
#: exporters write millimetres there anyway. A part whose largest side is under this many file
#: units is read as the spec says (under 1 mm no router carves a part; over 1 m is a table, not a
#: turned bowl): a trimesh 0.05 m box was read as a 0.05 mm speck, an empty preview and "too
#: small to carve". From it up the numbers are taken as millimetres, Z up, as stored.
FOREIGN_GLTF_METRES_BELOW = 1.0


def foreign_gltf_frame(extent: float, what: str) -> tuple[np.ndarray, str] | None:
    """For a glTF file not written by woodcam whose parts span ``extent`` file units along their
    longest side: ``(4x4 file -> block frame (mm, Z up), one-line note naming ``what``)`` when it
    is read as metres with +Y up (:data:`FOREIGN_GLTF_METRES_BELOW`), else None (mm, as stored)."""
    if not 0 < extent < FOREIGN_GLTF_METRES_BELOW:
        return None
    note = (f"{what} is a glTF that woodcam did not write and spans {extent:.4g} units: read as "
            f"metres with +Y up, as glTF specifies ({say_length(extent * 1e3, '.4g')} along its longest side); "
            f"a glTF whose part spans {FOREIGN_GLTF_METRES_BELOW:g} unit or more is read as millimetres, Z up")
    gltf_to_block = np.zeros((4, 4))
    gltf_to_block[:3, :3] = BLOCK_TO_GLTF[:3, :3].T * 1e6  # exact: 1e3 m -> mm, not inv()'s 999.99...
    gltf_to_block[3, 3] = 1.0
    return np.round(gltf_to_block, 9), note


def foreign_gltf_in_block_frame(geometry: _G, path, *, stacklevel: int = 2) -> _G:
    """``geometry`` (a ``trimesh.Trimesh`` or ``trimesh.Scene``) read from ``path``, a file
    woodcam did not write (the caller knows: ``woodcam.export.written_by_woodcam``, the GLB root
    node), in the block frame: a ``.glb``/``.gltf`` whose size says metres
    (:func:`foreign_gltf_frame`) is scaled to mm and turned from +Y up to Z up in place, with a
    WoodcamWarning that points ``stacklevel`` frames up from here (1: the caller, as
    ``warnings.warn`` counts from it); anything else is left as it is.
    Returns ``geometry``. The one home of that reading (export, view and cad parts)."""
    import warnings
    from pathlib import Path

    from .errors import WoodcamWarning

    path = Path(path)
    extents = geometry.extents  # None when empty
    if path.suffix.lower() not in (".glb", ".gltf") or extents is None:
        return geometry
    metres = foreign_gltf_frame(float(np.max(extents)), f"mesh file {str(path)!r}")
    if metres is not None:
        geometry.apply_transform(metres[0])
        warnings.warn(metres[1], WoodcamWarning, stacklevel=stacklevel + 1)
    return geometry


#: Name of the GLB root node that carries :data:`BLOCK_TO_GLTF` above the block-frame mesh.
GLTF_ROOT_NODE = "woodcam_block_frame"


#: GL buffer-view targets of vertex attributes and of indices (glTF 2.0 ``bufferView.target``).
_GL_ARRAY_BUFFER = 34962
_GL_ELEMENT_ARRAY_BUFFER = 34963


def stamp_gltf_asset(tree: dict) -> None:
    """Finish the glTF JSON ``tree`` of a GLB woodcam writes, in place. Every GLB woodcam writes
    passes its tree through here (a trimesh ``tree_postprocessor``): export_glb's (the bake's, the
    G-code's) and the log's (:func:`woodcam.logs.export_log_glb`, which lacked the targets below).

    - ``asset.generator`` names woodcam (and its version): the glTF 2.0 spec's "tool that
      generated this glTF model", which viewers and the Khronos validator show (trimesh, which
      serialises it, put its own project URL there);
    - every vertex-attribute and index buffer view gets its GL target (ARRAY_BUFFER /
      ELEMENT_ARRAY_BUFFER), which the Khronos validator asks for (BUFFER_VIEW_TARGET_MISSING).
    """
    from . import __version__

    tree.setdefault("asset", {"version": "2.0"})["generator"] = f"woodcam {__version__}"
    accessors = tree.get("accessors", [])
    views = tree.get("bufferViews", [])
    for mesh in tree.get("meshes", []):
        for prim in mesh.get("primitives", []):
            pairs = [(a, _GL_ARRAY_BUFFER) for a in prim.get("attributes", {}).values()]
            if "indices" in prim:
                pairs.append((prim["indices"], _GL_ELEMENT_ARRAY_BUFFER))
            for acc, target in pairs:
                view = accessors[acc].get("bufferView")
                if view is not None:
                    views[view]["target"] = target

#: First-line marker of an OBJ written by woodcam: ``# woodcam: units=m up=y ...``.
OBJ_HEADER = "# woodcam:"

ObjUnits = Literal["mm", "m"]
ObjUp = Literal["z", "y"]


def obj_transform(units: str, up: str) -> np.ndarray:
    """4x4 block frame (mm, Z up) -> OBJ file coordinates written with ``units`` and ``up``."""
    if units not in get_args(ObjUnits) or up not in get_args(ObjUp):
        raise WoodcamError(
            f"obj_transform: units must be one of {get_args(ObjUnits)} and up one of "
            f"{get_args(ObjUp)}; got units={units!r}, up={up!r}"
        )
    scale = 1e-3 if units == "m" else 1.0
    rot = BLOCK_TO_GLTF[:3, :3] * 1e3 if up == "y" else np.eye(3)
    out = np.eye(4)
    out[:3, :3] = rot * scale
    return out


def obj_header_transform(path) -> np.ndarray | None:
    """The :func:`obj_transform` recorded in a woodcam OBJ's first line, or None for an OBJ
    written by anything else."""
    with open(path, "r", errors="replace") as fh:
        first = fh.readline()
    if not first.startswith(OBJ_HEADER):
        return None
    fields = dict(item.split("=", 1) for item in first[len(OBJ_HEADER):].split() if "=" in item)
    units, up = fields.get("units"), fields.get("up")
    if units not in get_args(ObjUnits) or up not in get_args(ObjUp):
        raise WoodcamError(
            f"{str(path)!r} has a malformed woodcam header {first.strip()!r}; expected e.g. "
            "'# woodcam: units=m up=y'; re-export it with woodcam.export.export_obj"
        )
    return obj_transform(units, up)



def check_part_in_block(lo: ArrayLike, hi: ArrayLike, size_mm: ArrayLike, who: str, *,
                        shows: str, wholly_outside: Literal["error", "warn"] = "error",
                        stacklevel: int = 3) -> None:
    """The one check that a part drawn in its block lies in it: ``lo``, ``hi`` (3,) mm the
    part's bounding box and ``size_mm`` (3,) the block's, block frame (origin at the block's
    bottom-front-left corner). A part wholly outside is a WoodcamError (``wholly_outside=
    "error"``: review has no wood to show) or a warning (``"warn"``: preview still draws it);
    one reaching past a face by more than :data:`woodcam.tolerances.ON_FACE_TOL_MM` a
    WoodcamWarning saying how far past which faces (a GLB opened with another, smaller --block
    than it was baked from; another program's GLB), as :func:`woodcam.cad.carve.carve` says it
    for bake. ``who`` starts the messages (``"review: 'part.glb'"``); ``shows`` says what the
    view shows no wood in (``"the page's section"``, ``"the cut plane"``)."""
    import warnings

    from .errors import WoodcamWarning
    from .tolerances import ON_FACE_TOL_MM

    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    block = np.asarray(size_mm, dtype=float)

    def box(a, b):
        return f"{say_length(tuple(a.tolist()), '.4g', form='({}, {}, {})')} to " \
               f"{say_length(tuple(b.tolist()), '.4g', form='({}, {}, {})')}"

    where = f"the part's bounding box is {box(lo, hi)}, the block's {box(np.zeros(3), block)}"
    if (lo >= block - ON_FACE_TOL_MM).any() or (hi <= ON_FACE_TOL_MM).any():
        lost = "it has no wood of this block to show" if wholly_outside == "error" else \
            f"{shows} shows no wood of this block in it"
        said = (f"{who} lies outside its block: {where} (block frame: origin at the bottom-front-left corner); "
                f"{lost}: give the block it was baked from (--block), or bake it from this one (woodcam bake, "
                "which carves it from the block)")
        if wholly_outside == "error":
            raise WoodcamError(said)
        warnings.warn(said, WoodcamWarning, stacklevel=stacklevel)
        return
    past = []  # (mm, face) for each face the part reaches beyond
    for axis, (low, high) in enumerate((("left", "right"), ("front", "back"), ("bottom", "top"))):
        c = "xyz"[axis]
        if -lo[axis] > ON_FACE_TOL_MM:
            past.append((-lo[axis], f"its {low} face ({c} = 0)"))
        if hi[axis] - block[axis] > ON_FACE_TOL_MM:
            past.append((hi[axis] - block[axis], f"its {high} face ({c} = {say_length(block[axis], '.4g')})"))
    if past:
        said = ", ".join(f"{say_length(d, '.3g')} past {face}" for d, face in past)
        warnings.warn(
            f"{who} reaches outside its block, {said}: {where}; the part there would be carved from air, and "
            f"{shows} shows no wood of it; give the block it was baked from (--block), or bake it from this one "
            "(woodcam bake carves it from the block)", WoodcamWarning, stacklevel=stacklevel)
