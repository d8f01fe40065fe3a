"""The growth-time field protocol, the annual-ring field and rigid placement of a log frame.

A growth-time field (GTF) maps points ``points_mm : (n, 3) float`` in the block frame (mm) to
``years : (n,) float``: growth time since the pith, 0 on the pith, growing outward. Ring
boundaries are its integer iso-surfaces. The annual-ring field is ``ARF = (GTF mod 1)^2``
(eq. 6 of seed 000): 0 at the start of earlywood, near 1 for latewood just before a boundary.

A field may also answer ``grain_direction(points_mm) -> (n, 3)`` unit vectors along the wood
fibres (the pith axis for a straight stem, the branch axis inside a knot); appearances use it
to tell end grain from side grain. :func:`grain_direction` falls back to the gradient-free
default of the field's ``axis`` attribute, else ``+Z``.
"""

from __future__ import annotations

from dataclasses import dataclass, field as dc_field
from typing import Protocol, runtime_checkable

import numpy as np

from .._checks import as_floats, check_number, check_vector, numbers_fix, received
from .._types import ArrayLike, GrowthFieldLike
from ..errors import WoodcamError
from ..tolerances import MAX_BATCH_POINTS, POINT_BOUND_MM


@runtime_checkable
class GrowthField(Protocol):
    """Anything callable as ``field(points_mm (n, 3)) -> years (n,)``: block-frame points in
    mm to growth time in years since the pith (see module docstring)."""

    def __call__(self, points_mm: np.ndarray) -> np.ndarray: ...


def check_points(points_mm: ArrayLike, name: str = "points_mm", *, frame: str = "block") -> np.ndarray:
    """Return ``points_mm`` as a float64 ``(n, 3)`` array of finite points within
    :data:`~woodcam.tolerances.POINT_BOUND_MM` of the origin, or raise a clear error.

    ``name`` is what the errors call the points (default ``"points_mm"``); ``frame`` names the
    frame the caller's points are in (``"block"``, or ``"log"`` for a
    log-frame field called directly), for the bound's fix: a log field was told to pass
    block-frame points."""
    p = as_floats(points_mm)
    if p is None:  # a ragged list was a bare ValueError; complex points lost their imaginary
        # parts under numpy's ComplexWarning, text '10' was 10.0 and None a NaN
        raise WoodcamError(f"{name} must be real numbers, shape (n, 3) in mm; got {received(points_mm)}; "
                           + (numbers_fix(points_mm, name) or "e.g. [[10, 20, 5]]"))
    if p.ndim != 2 or p.shape[1] != 3:
        raise WoodcamError(f"{name} must have shape (n, 3) in mm; got shape {p.shape}")
    if not np.isfinite(p).all():  # a NaN point was a ZeroDivisionError in a compiled kernel
        bad = int(np.argmin(np.isfinite(p).all(axis=1)))
        raise WoodcamError(f"{name} must be finite; point {bad} is {p[bad].tolist()}")
    far = np.abs(p) > POINT_BOUND_MM  # its square overflowed in the fields: inf years
    if far.any():
        bad = int(np.argmax(far.any(axis=1)))
        raise WoodcamError(f"{name} must lie within {POINT_BOUND_MM:g} mm ({POINT_BOUND_MM / 1e6:g} km) of the "
                           "origin on each axis; "
                           f"point {bad} is {p[bad].tolist()}; pass {frame}-frame points in mm (a unit or frame "
                           "mistake?)")
    return p


def evaluate(field: GrowthFieldLike, points_mm: ArrayLike, batch: int = MAX_BATCH_POINTS,
             workers: int = 1) -> np.ndarray:
    """Evaluate ``field`` on ``(n, 3)`` points in bounded batches; returns ``years : (n,)``.

    ``field`` is any growth field (``field(points_mm (n, 3)) -> years (n,)``, e.g. a
    ``Stock``'s ``wood.field`` or :func:`woodcam.fit_block`'s result); ``points_mm`` are
    ``(n, 3)`` finite points in mm in the block frame (``docs/conventions.md``: origin at the
    block's bottom-front-left corner, X width, Y depth, Z up); ``years`` is growth time since
    the pith (NaN where the field has no value, e.g. outside a fitted grid). ``batch``: points
    per call of ``field`` (bounds its memory).

    ``workers > 1``: the first share of the points is evaluated here while a forked process
    evaluates the rest (:func:`woodcam._parallel.beside`), for a large grid of a field that is
    safe to use after a fork (the fitted fields; not a torch net, whose thread pool is not).
    Each batch runs the same operations either way, so the result is the same bit for bit
    when a point's value does not depend on the other points of its batch."""
    p = check_points(points_mm)
    if not callable(field):  # was "'NoneType' object is not callable" from inside the loop
        raise WoodcamError(f"field must be a growth field ((n, 3) mm -> years); got {type(field).__name__}; "
                           "pass e.g. woodcam.builtin_block('flat-sawn').field")
    # batch=-1 returned np.empty's uninitialised memory as years (range(0, n, -1) is empty),
    # 0 and 1.5 were bare errors of range(); workers='2' a TypeError of the comparison
    batch = int(check_number(batch, "batch", lo=1, integer=True, fix=f"e.g. {MAX_BATCH_POINTS}"))
    workers = int(check_number(workers, "workers", lo=1, integer=True, fix="1 evaluates here, 2 forks one process"))
    if workers > 1 and len(p) > _FORK_MIN_POINTS:
        from .._parallel import beside

        cut = len(p) // 2 // _FORK_ALIGN * _FORK_ALIGN  # two halves: beside forks one piece
        rest, first = beside(lambda: evaluate(field, p[cut:], batch), lambda: evaluate(field, p[:cut], batch))
        return np.concatenate([first, rest])
    if len(p) <= batch:
        return _years_of(field, p)
    out = np.empty(len(p))
    for i in range(0, len(p), batch):
        out[i:i + batch] = _years_of(field, p[i:i + batch])
    return out


def _years_of(field, p: np.ndarray) -> np.ndarray:
    """``field(p)`` as ``(n,)`` float years: a field returning the wrong count or text was a
    bare reshape/float ValueError, naming neither the field nor what it returned."""
    g = as_floats(field(p))
    if g is None or g.size != len(p):
        got = "something that is not numbers" if g is None else f"shape {g.shape}"
        raise WoodcamError(f"field must return one growth time per point, (n,) = ({len(p)},); it returned {got}; "
                           f"check the field's __call__ ({type(field).__name__})")
    return g.reshape(len(p))


#: Points below which :func:`evaluate` does not fork: a fork and the copy of the result back
#: cost ~0.05 s, what a fitted field spends on ~10^4 points.
_FORK_MIN_POINTS = 1 << 16

#: The forked share starts at a multiple of this many points: fields evaluate in chunks (the
#: thin-plate RBF 256 points at a time) and BLAS' matrix-vector kernels take rows in blocks,
#: and a row's sum depends on where it falls in them (a cut at half a 91841/2 grid moved the
#: RBF's values by rounding); cut at a multiple of 2^14 every chunk and block is the serial one.
_FORK_ALIGN = 1 << 14


def has_uncertainty(field) -> bool:
    """Whether ``field`` is a fit that says where its rings are a guess: an ``uncertainty``
    layer (:func:`woodcam.inference.evidence.bake_evidence`) and ``uncertainty_years(points_mm
    (n, 3)) -> (n,)`` to read it. The one test of it (Wood.has_uncertainty, the fit reports)."""
    layers = getattr(field, "layers", None)
    return bool(layers) and "uncertainty" in layers and callable(getattr(field, "uncertainty_years", None))


def has_pith(field) -> bool:
    """Whether ``field``'s year 0 is a pith, the line its rings grow round (a stem's, a log's, a
    fitted block's): True unless the field says ``has_pith = False``. A woodified object's year 0
    is the surface of the mesh it grew from (:class:`woodcam.woodify.field.WoodifiedField`),
    not a pith that splits as it dries. The one test of it (Wood.has_pith, the part report)."""
    return bool(getattr(field, "has_pith", True))


def arf(years: ArrayLike) -> np.ndarray:
    """Annual-ring field from growth time: ``(years mod 1)^2`` (eq. 6 of seed 000).

    Always apply it to a (possibly interpolated) growth time, never interpolate its output:
    interpolating the ARF would blur the sharp latewood -> earlywood step at ring boundaries.
    ``years``: numbers of any shape (a NaN year, where a field is not defined, stays NaN).
    """
    try:
        kind = np.asarray(years).dtype.kind
    except (TypeError, ValueError):  # a ragged list
        kind = "O"
    g = as_floats(years) if kind in "iuf" else None
    if g is None:  # 'a' was numpy's bare "could not convert string to float"; None was NaN, '0.5' 0.25
        raise WoodcamError(f"years must be growth times (numbers, any shape); got {years!r:.60}; "
                           "pass field(points_mm) or evaluate(field, points_mm)")
    return np.mod(g, 1.0) ** 2


def rings_crossed(years: ArrayLike) -> int:
    """How many ring boundaries (whole years, where one year's wood meets the next: the ARF's
    latewood -> earlywood step) the growth times ``years (n,)`` cross: the integers ``k`` with
    ``min < k <= max`` over the finite values. 0: all of them lie in one growth layer, a
    surface there shows no ring, one flat colour (NaNs ignored; none finite: 0)."""
    g = as_floats(years)
    if g is None:
        raise WoodcamError(f"years must be growth times (numbers); got {years!r:.60}")
    g = g[np.isfinite(g)]
    return int(np.floor(g.max()) - np.floor(g.min())) if g.size else 0


def central_gradient(field: GrowthFieldLike, points_mm: ArrayLike,
                     step_mm: float) -> tuple[np.ndarray, np.ndarray]:
    """``(years (n,), gradient (n, 3) years/mm)`` of ``field`` at ``points_mm`` ``(n, 3)``:
    central differences over ``+-step_mm`` along X, Y, Z, all 7 n points in one call."""
    p = np.asarray(points_mm, dtype=float).reshape(-1, 3)
    offs = np.concatenate([np.eye(3), -np.eye(3)]) * step_mm
    g = np.asarray(field(np.concatenate([p] + [p + o for o in offs])), dtype=float).reshape(7, len(p))
    return g[0], (g[1:4] - g[4:7]).T / (2 * step_mm)


def grain_direction(field: GrowthFieldLike, points_mm: ArrayLike) -> np.ndarray:
    """Unit fibre directions ``(n, 3)`` of ``field`` at ``points_mm (n, 3)`` (mm, the field's frame:
    the block frame for a block's field), in that frame: the field's own ``grain_direction``,
    else its ``axis`` (else ``+Z``) at every point (see module docstring)."""
    p = check_points(points_mm)
    fn = getattr(field, "grain_direction", None)
    if fn is not None:
        return np.asarray(fn(p), dtype=float)
    if not callable(field):
        raise WoodcamError(f"field must be a growth field ((n, 3) mm -> years); got {type(field).__name__}")
    axis = np.asarray(getattr(field, "axis", (0.0, 0.0, 1.0)), dtype=float)
    return np.broadcast_to(axis / np.linalg.norm(axis), p.shape)


@dataclass(frozen=True)
class LogFrame:
    """Rigid placement of a log's own frame in the block frame.

    The log frame has its ``z`` axis on the pith, pointing along ``axis``; ``x`` points along
    ``reference`` made orthogonal to the axis; ``y = z x x``. The pith passes through
    ``pith_point_mm`` (block frame), which may lie outside the block.

    Parameters
    ----------
    pith_point_mm : (3,) float
        A point on the pith axis, block frame, mm; log-frame ``z = 0`` there.
    axis : (3,) float
        Direction of the pith axis (normalised here); need not be axis-aligned.
    reference : (3,) float
        Direction that becomes the log frame's ``+x`` (azimuth 0); default picks one.
    """

    pith_point_mm: tuple[float, float, float] = (0.0, 0.0, 0.0)
    axis: tuple[float, float, float] = (0.0, 0.0, 1.0)
    reference: tuple[float, float, float] | None = None
    _rot: np.ndarray = dc_field(init=False, repr=False, compare=False)

    def __post_init__(self):
        object.__setattr__(self, "pith_point_mm", tuple(float(x) for x in check_vector(
            self.pith_point_mm, "pith_point_mm", fix="pass a block-frame point on the pith, mm")))
        z = check_vector(self.axis, "axis", unit=True,
                         fix="pass the log axis as a block-frame direction, e.g. (0, 0, 1)")
        # axis and reference kept as given but as plain floats, as pith_point_mm: numpy scalars
        # (a placement's computed axis) printed as np.float64(0.0) in every Wood repr
        object.__setattr__(self, "axis", _plain(self.axis))
        ref = self.reference
        if ref is None:
            ref = (1.0, 0.0, 0.0) if abs(z[0]) < 0.9 else (0.0, 1.0, 0.0)
        x = check_vector(ref, "reference", unit=True,
                         fix="pass a block-frame direction across the axis, e.g. (1, 0, 0), or None")
        if self.reference is not None:
            object.__setattr__(self, "reference", _plain(self.reference))
        x = x - z * (x @ z)
        if np.linalg.norm(x) < 1e-9:
            raise WoodcamError(f"reference must not be parallel to axis; got {ref!r} and {self.axis!r}")
        x /= np.linalg.norm(x)
        y = np.cross(z, x)
        object.__setattr__(self, "_rot", np.stack([x, y, z]))  # rows: log axes in block frame

    def __repr__(self) -> str:
        # one short line inside a field's and a Wood's repr: six significant digits (1 um under
        # a metre), -0 as 0; the names carry the units (mm; axis and reference are directions)
        def vec(v: tuple[float, ...] | None) -> str:
            return "None" if v is None else f"({', '.join(f'{x + 0.0:.6g}' for x in v)})"
        return (f"LogFrame(pith_point_mm={vec(self.pith_point_mm)}, axis={vec(self.axis)}, "
                f"reference={vec(self.reference)})")

    @property
    def rotation(self) -> np.ndarray:
        """(3, 3) matrix whose rows are the log frame's x, y, z axes in the block frame."""
        return self._rot

    def to_log(self, points_mm: ArrayLike) -> np.ndarray:
        """Block-frame points ``(n, 3)`` -> log-frame points ``(n, 3)`` (mm).

        Raises a :class:`~woodcam.errors.WoodcamError` quoting the caller's block-frame point
        when one lands past :data:`~woodcam.tolerances.POINT_BOUND_MM` in the log frame: the
        log field's own check quoted the log-frame point and told the caller, who gave
        block-frame points, to 'pass block-frame points'."""
        p = check_points(points_mm)
        # einsum, not ``@``: OpenBLAS threading makes an (n, 3) x (3, 3) product up to 30x
        # slower on a busy 2-core machine, and this runs for every texel.
        q = np.einsum("ij,kj->ik", p - np.asarray(self.pith_point_mm, float), self._rot)
        if len(q) and np.abs(q).max() > POINT_BOUND_MM:  # a NaN-free p (checked): a NaN-free q
            bad = int(np.argmax((np.abs(q) > POINT_BOUND_MM).any(axis=1)))
            raise WoodcamError(
                f"points_mm (block frame) must lie, placed in the log, within {POINT_BOUND_MM:g} mm "
                f"({POINT_BOUND_MM / 1e6:g} km) of the log frame's origin on each of its axes (its pith passes "
                f"through {np.round(self.pith_point_mm, 3).tolist()} mm of the block frame); point {bad} is "
                f"{p[bad].tolist()} in the block frame, {np.round(q[bad], 3).tolist()} in the log frame; pass "
                "block-frame points in mm, near the block (a unit or frame mistake?)")
        return q

    def to_block(self, points_log_mm: ArrayLike) -> np.ndarray:
        """Log-frame points ``(n, 3)`` -> block-frame points ``(n, 3)`` (mm)."""
        p = check_points(points_log_mm, "points_log_mm", frame="log")
        return np.einsum("ij,jk->ik", p, self._rot) + np.asarray(self.pith_point_mm, float)

    def direction_to_block(self, dirs_log: ArrayLike) -> np.ndarray:
        """Rotate log-frame direction vectors ``(n, 3)`` into the block frame."""
        return np.einsum("ij,jk->ik", _directions(dirs_log, "dirs_log"), self._rot)

    def direction_to_log(self, dirs_mm: ArrayLike) -> np.ndarray:
        """Rotate block-frame direction vectors ``(n, 3)`` (fibres, normals) into the log frame."""
        return np.einsum("ij,kj->ik", _directions(dirs_mm, "dirs_mm"), self._rot)


def _plain(v: ArrayLike) -> tuple[float, float, float]:
    """A checked ``(3,)`` vector as a tuple of Python floats (not numpy scalars)."""
    x, y, z = (float(c) for c in np.asarray(v, dtype=float).ravel())
    return (x, y, z)


def _directions(value, name: str) -> np.ndarray:
    """Direction vectors ``(n, 3)`` as floats for :class:`LogFrame`'s rotations: None and (n, 2)
    were einsum's bare ValueErrors, 'abc' numpy's, complex vectors lost their imaginary parts
    under numpy's ComplexWarning. Not checked for finite values (a fibre direction may be NaN
    where a field is not defined, and stays NaN)."""
    a = as_floats(value)
    if a is None or a.ndim != 2 or a.shape[1] != 3:
        fix = numbers_fix(value, name) if a is None else ""
        raise WoodcamError(f"{name} must be direction vectors of real numbers, shape (n, 3); got "
                           f"{received(value) if a is None else f'shape {a.shape}'}; "
                           + (fix or "e.g. [[0, 0, 1]]"))
    return a


def check_texture_frame(frame) -> "LogFrame | None":
    """``frame`` as given when it is a :class:`LogFrame` or None, else a WoodcamError: the one
    check of a ``texture_frame`` (the frame a wood's texture is drawn in, placed in the block
    frame: the block a smaller one was cut from), for the colour map and the built-in photos."""
    if frame is not None and not isinstance(frame, LogFrame):
        raise WoodcamError(f"texture_frame must be a LogFrame (the frame the texture is drawn in, placed in "
                           f"the block frame) or None; got {type(frame).__name__}; pass the parent "
                           "block's LogFrame, or None for this block's own frame")
    return frame
