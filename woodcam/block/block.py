"""A measured (or synthetic) block: its size, its six faces and, when known, its true field.

Face images follow ``docs/conventions.md``: each is seen from outside the block, pixel
``(row, col)`` maps to the block by :func:`woodcam.frames.pixel_to_block`. Ring traces are
polylines in continuous pixel coordinates ``(row, col)`` (pixel centres at integers) with an
optional integer year label counted outward from the pith. A ring map is a grey image in
[0, 1], bright on ring boundaries, with no year labels (the Mokume ``arl`` maps).
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._checks import as_floats, numbers_fix, received
from .._repr import summary_repr
from ..errors import WoodcamError
from ..frames import FACES, FaceName, check_face, check_size, face_image_size_mm, pixel_to_block


@dataclass(frozen=True)
class RingTrace:
    """One traced ring on a face.

    Attributes
    ----------
    points_px : (k, 2) float
        Polyline vertices as continuous pixel coordinates ``(row, col)``.
    year : int or None
        Growth year of the ring boundary (the integer iso-line ``GTF = year``), if labelled.
    ring : int or None
        Which ring of its face the trace is a piece of, when known without a year: pieces of one
        ring broken by a pore band, a knot or a gap share it (the ring detector links them by
        its phase order, :mod:`woodcam.detect.rings`), so the fitter gives them one growth time.
        An id relative to its face only (not a year, not comparable across faces).
    """

    __repr__ = summary_repr  # arrays as shapes: a notebook shows one line

    points_px: np.ndarray
    year: int | None = None
    ring: int | None = None

    def __post_init__(self):
        from ..limits import limit

        p = as_floats(self.points_px)
        if p is None:  # "ab"; complex points lost their imaginary parts under numpy's ComplexWarning
            fix = numbers_fix(self.points_px, "points_px")
            raise WoodcamError(f"points_px of a ring trace must be (row, col) real numbers, shape (k >= 2, 2); "
                               f"got {received(self.points_px)}" + (f"; {fix}" if fix else ""))
        if p.ndim != 2 or p.shape[1] != 2 or len(p) < 2:
            raise WoodcamError(
                f"points_px of a ring trace must have shape (k >= 2, 2) as (row, col); got {p.shape}"
            )
        if not np.all(np.isfinite(p)):
            raise WoodcamError("points_px of a ring trace must be finite; got NaN or inf")
        if len(p) > limit("MAX_TRACE_POINTS"):
            raise WoodcamError(f"a ring trace has {len(p)} points, more than the limit "
                               f"MAX_TRACE_POINTS = {limit('MAX_TRACE_POINTS'):.0f} points; simplify it or "
                               "raise the limit with WOODCAM_MAX_TRACE_POINTS=N")
        y = self.year
        if y is not None:
            top = limit("MAX_RING_YEAR")
            whole = isinstance(y, (int, np.integer)) or (isinstance(y, (float, np.floating))
                                                         and float(y).is_integer())
            if isinstance(y, bool) or not whole or not -top <= y <= top:
                raise WoodcamError(f"year of a ring trace must be an integer in [-{top:.0f}, "
                                   f"{top:.0f}] or None; got {y!r}")
            object.__setattr__(self, "year", int(y))
        k = self.ring
        if k is not None:
            if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 0:
                raise WoodcamError(f"ring of a ring trace must be a non-negative integer id or None; "
                                   f"got {k!r}")
            object.__setattr__(self, "ring", int(k))
        object.__setattr__(self, "points_px", p)



def trace_bounds_px(shape) -> tuple[np.ndarray, np.ndarray]:
    """``(lo, hi)`` ``(2,)`` (row, col) bounds of a trace's points on a face image of ``shape``:
    the image with half a face of slack, for traces drawn past an edge. The one rule of
    :class:`Face` and the ``block.json`` reader."""
    rows, cols = shape
    return np.array([-0.5 - 0.5 * rows, -0.5 - 0.5 * cols]), np.array([1.5 * rows - 0.5, 1.5 * cols - 0.5])


@dataclass
class Face:
    """What is known about one face of a block.

    Attributes
    ----------
    name : FaceName
    shape : (n_rows, n_cols)
        Pixel size of the face's images (photo and ring map share it); traces use it too.
    photo : (n_rows, n_cols, 3) uint8 or None
    traces : list of RingTrace
    ring_map : (n_rows, n_cols) float32 in [0, 1] or None
    extras : dict
        Other per-face data, e.g. ``"knot_mask"``: (n_rows, n_cols) bool, True on a knot
        (Mokume ``X_knot.png``), or ``"annotation"``: the raw Mokume ``X_ann.png``. Array
        values are written as PNG by :func:`woodcam.block.io.write_block`, others as JSON.
    """

    __repr__ = summary_repr  # arrays as shapes: a notebook shows one line

    name: FaceName
    shape: tuple[int, int]
    photo: np.ndarray | None = None
    traces: list[RingTrace] = field(default_factory=list)
    ring_map: np.ndarray | None = None
    extras: dict = field(default_factory=dict)

    def __post_init__(self):
        self.name = check_face(self.name)
        from ..limits import limit

        top = int(limit("MAX_FACE_PX"))
        shape = np.asarray(self.shape, dtype=object) if np.ndim(self.shape) == 1 else None
        # (0, 0) or (-3, 4) was accepted and written, (3,) an IndexError, (10.7, 10) cut to 10
        if shape is None or len(shape) != 2 or not all(
                isinstance(s, numbers.Real) and not isinstance(s, bool) and float(s).is_integer()
                and 1 <= s <= top for s in shape):
            raise WoodcamError(f"shape of face {self.name!r} must be two pixel counts (n_rows, n_cols), whole "
                               f"in [1, {top}]; got {self.shape!r}; pass the face image's shape[:2]")
        self.shape = (int(shape[0]), int(shape[1]))
        if isinstance(self.traces, (str, bytes, RingTrace, np.ndarray)) or not hasattr(self.traces, "__iter__"):
            # 5 was list()'s TypeError, an (n, 2) array a list of its rows refused as 'trace 0'
            raise WoodcamError(f"traces of face {self.name!r} must be a list of RingTrace; got "
                               f"{type(self.traces).__name__}; e.g. traces=[RingTrace(points_px)]")
        self.traces = list(self.traces)
        for k, t in enumerate(self.traces):
            if not isinstance(t, RingTrace):
                raise WoodcamError(f"trace {k} of face {self.name!r} must be a RingTrace; got "
                                   f"{type(t).__name__}; wrap its (row, col) points: RingTrace(points_px)")
        if self.traces:  # where read_block takes them (trace_bounds_px), all traces in one pass
            lo, hi = trace_bounds_px(self.shape)
            p = np.concatenate([np.asarray(t.points_px, float) for t in self.traces])
            out = ((p < lo) | (p > hi)).any(axis=1)
            if out.any():
                k = int(np.searchsorted(np.cumsum([len(t.points_px) for t in self.traces]), np.argmax(out), "right"))
                raise WoodcamError(f"trace {k} of face {self.name!r} lies beyond its {self.shape[0]}x{self.shape[1]} "
                                   "px image (more than half a face past an edge); check its (row, col) pixel "
                                   "coordinates")
        if self.photo is not None:
            self.photo = _check_image(self.photo, self.shape, 3, f"photo of face {self.name!r}")
        if self.ring_map is not None:
            self.ring_map = _check_image(self.ring_map, self.shape, 0, f"ring_map of face {self.name!r}")
        if not isinstance(self.extras, dict):  # a list was an AttributeError at the first .get
            raise WoodcamError(f"extras of face {self.name!r} must be a dict (e.g. {{'knot_mask': mask}}); got "
                               f"{type(self.extras).__name__}")

    @property
    def has_rings(self) -> bool:
        return bool(self.traces) or self.ring_map is not None


def _check_image(im, shape, channels: int, what: str) -> np.ndarray:
    a = np.asarray(im)
    want = tuple(shape) + ((channels,) if channels else ())
    if a.shape != want:
        raise WoodcamError(f"{what} must have shape {want} like the face; got {a.shape}")
    # a NaN ring map or a float photo in 0..255 was taken and read as rings/wood everywhere
    if a.dtype != np.uint8:
        if not np.issubdtype(a.dtype, np.floating):
            raise WoodcamError(f"{what} must be uint8 (0..255) or float (0..1); got dtype {a.dtype}")
        finite = np.isfinite(a)
        if not finite.all() or a.min() < -1e-3 or a.max() > 1 + 1e-3:
            lo, hi = (float(a[finite].min()), float(a[finite].max())) if finite.any() else (np.nan, np.nan)
            raise WoodcamError(f"{what} must hold finite values in [0, 1]; got range [{lo:g}, {hi:g}] with "
                               f"{int(np.sum(~finite))} non-finite; divide a 0..255 image by 255 (or pass uint8)")
    return a


@dataclass
class Block:
    """A block of wood in the block frame: ``[0, W] x [0, D] x [0, H]`` mm.

    Attributes
    ----------
    size_mm : (W, D, H) float
    faces : dict FaceName -> Face
        Only the faces something is known about; any subset of the six.
    true_field : growth field or None
        The true growth-time field in the block frame, for synthetic blocks.
    name : str
    meta : dict
        Free-form provenance (source folder, generator seed, sawing pattern, ...).
    """

    __repr__ = summary_repr  # arrays as shapes: a notebook shows one line

    size_mm: tuple[float, float, float]
    faces: dict[str, Face] = field(default_factory=dict)
    true_field: Any = None
    name: str = "block"
    meta: dict = field(default_factory=dict)

    def __post_init__(self):
        self.size_mm = tuple(float(s) for s in check_size(self.size_mm))
        from ..limits import limit

        # the name makes the file names of its outputs (leave_one_face_out's NAME_holdout.md,
        # benchmark's NAME_full.png): a name '../x' (a block.json's "name") wrote outside out_dir
        if not isinstance(self.name, str) or any(c in self.name for c in "/\\\0"):
            raise WoodcamError(f"Block.name must be a plain name, no path (it names the block's output files, "
                               f"e.g. NAME_holdout.md); got {self.name!r}; e.g. 'oak1'")
        if max(self.size_mm) > limit("MAX_BLOCK_SIZE_MM"):  # read_block refuses it
            raise WoodcamError(f"Block.size_mm must be at most {limit('MAX_BLOCK_SIZE_MM'):g} mm a side "
                               f"(raise it with WOODCAM_MAX_BLOCK_SIZE_MM=N); got {self.size_mm}")
        if not isinstance(self.faces, dict):
            raise WoodcamError(f"Block.faces must be a dict face name -> Face; got {type(self.faces).__name__}")
        if self.true_field is not None and not callable(self.true_field):  # 5 was saved as "truth not saved"
            raise WoodcamError(f"Block.true_field must be a growth field ((n, 3) mm -> years) or None; got "
                               f"{type(self.true_field).__name__}; e.g. builtin_block('flat-sawn').field")
        if not isinstance(self.meta, dict):  # a list was taken and failed at write_block or the fit
            raise WoodcamError(f"Block.meta must be a dict of block metadata; got {type(self.meta).__name__}")
        faces = {}
        for key, face in self.faces.items():
            if not isinstance(face, Face):
                raise WoodcamError(f"Block.faces[{key!r}] must be a Face; got {face!r}; build it with "
                                   f"Face({key!r}, shape) and its photo, traces or ring map")
            if check_face(key) != face.name:
                raise WoodcamError(f"faces[{key!r}] holds face {face.name!r}; keys must match Face.name")
            faces[face.name] = face
        self.faces = {f: faces[f] for f in FACES if f in faces}

    def _face(self, face: str) -> Face:
        """The :class:`Face` called ``face`` (a name or a Mokume letter), or a clear error."""
        name = check_face(face)
        if name not in self.faces:
            raise WoodcamError(f"face {face!r} is not known on block {self.name!r}; it has "
                               f"{', '.join(self.faces) or 'no faces'}; pass one of those")
        return self.faces[name]

    def face_pixel_size_mm(self, face: str) -> tuple[float, float]:
        """Size in mm of one pixel ``(row step, col step)`` of ``face``'s images."""
        f = self._face(face)
        h, w = face_image_size_mm(f.name, self.size_mm)
        return h / f.shape[0], w / f.shape[1]

    def trace_points_mm(self, faces: list[str] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """All traced ring vertices as block points with their years.

        Returns
        -------
        points_mm : (n, 3) float
        years : (n,) float, NaN for unlabelled traces
        """
        pts, yrs = [], []
        for name in faces or list(self.faces):
            f = self._face(name)
            for t in f.traces:
                pts.append(pixel_to_block(f.name, t.points_px[:, 0], t.points_px[:, 1], f.shape, self.size_mm))
                yrs.append(np.full(len(t.points_px), np.nan if t.year is None else float(t.year)))
        if not pts:
            return np.empty((0, 3)), np.empty(0)
        return np.concatenate(pts), np.concatenate(yrs)
