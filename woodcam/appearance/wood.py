"""``Wood``: a growth field plus an appearance; the one seam everything downstream uses."""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from .._checks import as_floats, check_number, check_rotation, check_vector, numbers_fix, received
from .._repr import attrs_repr
from .._types import AppearanceLike, ArrayLike, GrowthFieldLike, WoodLike
from ..errors import WoodcamError
from ..fields.base import arf, check_points, evaluate, grain_direction, has_pith, has_uncertainty
from ..frames import FACE_NORMAL, FACES, check_face, check_size
from ..tolerances import COLOR_RANGE_TOL, MAX_BATCH_POINTS, MIN_NORMAL_LENGTH
from .colormap import ColorMapAppearance

#: Points per work item when colouring in parallel: big enough to amortise numpy's call
#: overhead, small enough that two threads stay busy and memory stays ~50 MB per item.
_CHUNK = 1 << 16


class Wood:
    """Wood with a growth field and an appearance.

    Parameters
    ----------
    field : growth field
        ``field(points_mm (n, 3)) -> years (n,)`` in the block frame.
    appearance : object with ``color(field, points_mm, normals) -> (n, 3)``
        Default: :class:`ColorMapAppearance` with the oak preset.
    threads : int or None
        Worker threads for :meth:`color` (numpy releases the GIL in its kernels);
        default: the number of CPU cores.

    A wood made by :meth:`turned` or :meth:`shifted` maps its points and normals back to the
    source block's frame before the field and the appearance see them.
    """

    def __init__(self, field: GrowthFieldLike, appearance: AppearanceLike | None = None, *, threads: int | None = None):
        if not callable(field):
            raise WoodcamError(f"field must be callable as field(points_mm) -> years; got {type(field).__name__}")
        # an appearance without color() (a species name, a number) was an AttributeError at the
        # first colour; threads='2' a TypeError of max(), -1 and 1.5 were taken as 1 thread
        if appearance is not None and not callable(getattr(appearance, "color", None)):
            raise WoodcamError(f"appearance must have a method color(field, points_mm, normals) -> rgb; got "
                               f"{appearance!r:.60}; pass a ColorMapAppearance (ColorMapAppearance('walnut') "
                               "for a species) or None for the oak preset")
        if threads is not None:
            threads = int(check_number(threads, "threads", lo=1, integer=True,
                                       fix="worker threads for color(), or None for one per CPU core"))
        self.field = field
        self.appearance = appearance if appearance is not None else ColorMapAppearance()
        self.threads = max(1, threads or os.cpu_count() or 1)
        #: (R (3, 3), t (3,)) with source point = R^T (p - t) (turns and shifts), or None (this
        #: block's own frame)
        self._turn: tuple[np.ndarray, np.ndarray] | None = None

    def __repr__(self) -> str:  # arrays as shapes: a notebook shows one line
        return attrs_repr(self, ('field', 'appearance', 'threads'))

    def turned(self, axis: str, quarter_turns: int, size_mm: ArrayLike) -> tuple["Wood", tuple]:
        """The same wood with the block turned ``quarter_turns`` x 90 degrees about the block
        axis ``axis`` (``"x"``, ``"y"`` or ``"z"``, right hand rule), e.g. to run the grain along
        another axis under a part that stays put.

        Parameters
        ----------
        axis : {"x", "y", "z"}
        quarter_turns : int
        size_mm : (3,) float
            The block's size (W, D, H) before turning.

        Returns
        -------
        (Wood, (W', D', H'))
            The turned wood, in the turned block's frame (origin at its bottom-front-left
            corner), and the turned block's size.
        """
        if axis not in ("x", "y", "z"):
            raise WoodcamError(f"turned: axis must be 'x', 'y' or 'z'; got {axis!r}; e.g. turned('z', 1, size)")
        k = check_number(quarter_turns, "turned: quarter_turns", integer=True,
                         fix="e.g. turned('z', 1, size)") % 4
        i, j = {"x": (1, 2), "y": (2, 0), "z": (0, 1)}[axis]  # cyclic: e_i -> e_j
        rot = np.eye(3)
        for _ in range(k):  # exact integer quarter turns: (e_i, e_j) -> (e_j, -e_i)
            step = np.eye(3)
            step[i, i] = step[j, j] = 0.0
            step[j, i], step[i, j] = 1.0, -1.0
            rot = step @ rot
        size = check_size(size_mm)  # (1, 1) was a reshape error
        corners = np.array(np.meshgrid(*[(0.0, v) for v in size], indexing="ij")).reshape(3, -1).T
        moved = corners @ rot.T
        shift = -moved.min(axis=0)
        out = Wood(self.field, self.appearance, threads=self.threads)
        inner = self._turn
        if inner is None:
            out._turn = (rot, shift)
        else:  # compose: new -> this wood's frame -> its source
            r0, t0 = inner
            out._turn = (rot @ r0, rot @ t0 + shift)
        new_size = tuple(float(v) for v in np.abs(rot) @ size)
        return out, new_size

    def shifted(self, origin_mm: ArrayLike) -> "Wood":
        """The same wood seen from a block whose corner sits at ``origin_mm (3,)`` (mm) of this
        wood's block frame: its point ``p`` is this wood's ``origin_mm + p`` for the growth field,
        the features and the colours alike (a smaller stock cut out of this one)."""
        o = check_vector(origin_mm, "shifted: origin_mm", fix="pass the corner's block-frame position, mm")
        out = Wood(self.field, self.appearance, threads=self.threads)
        rot, shift = self._turn if self._turn is not None else (np.eye(3), np.zeros(3))
        out._turn = (rot, shift - o)  # source = rot^T (p + o - shift)
        return out

    def rotated(self, rotation: ArrayLike, origin_mm: ArrayLike) -> "Wood":
        """The same wood seen from a block turned any way inside this one: its point ``p`` is
        this wood's ``origin_mm + rotation @ p`` (mm), its normals and fibres turned alike, for
        the growth field, the features and the colours (the appearance sees this wood's frame,
        so a cut turned by any angle shows this block's colours where it overlaps it).

        rotation : (3, 3) proper rotation; origin_mm : (3,) mm, in this wood's block frame."""
        R = check_rotation(rotation, "rotated: rotation")
        o = check_vector(origin_mm, "rotated: origin_mm", fix="the turned block's corner in this block, mm")
        out = Wood(self.field, self.appearance, threads=self.threads)
        r0, t0 = self._turn if self._turn is not None else (np.eye(3), np.zeros(3))
        # source = r0^T (R p + o - t0) = rot^T (p - shift)
        out._turn = (R.T @ r0, R.T @ (t0 - o))
        return out

    @property
    def in_source_frame(self) -> bool:
        """Whether this block is the source block itself (the one the field was fitted or grown
        in), not turned or cut out of it by :meth:`turned` or :meth:`shifted`."""
        return self._turn is None

    def to_source(self, points_mm: ArrayLike) -> np.ndarray:
        """``(n, 3)`` mm: this block's ``points_mm (n, 3)`` in the source block's frame (where
        the field, its photos and its faces are), as :meth:`years` reads them."""
        return self._to_source(check_points(points_mm))[0]

    def _to_source(self, points, normals=None):
        if self._turn is None:
            return points, normals
        rot, shift = self._turn
        p = ((points - shift) @ rot).astype(points.dtype, copy=False)
        n = None if normals is None else (normals @ rot).astype(normals.dtype, copy=False)
        return p, n

    def features(self, points_mm: ArrayLike) -> dict:
        """What a woodworker asks of the wood at ``points_mm (n, 3)`` (block frame, mm).

        Returns
        -------
        dict
            ``years (n,)`` growth time; ``knot (n,)`` in [0, 1], 1 inside a knot (0 for
            knot-free fields); ``grain (n, 3)`` unit fibre direction, block frame.
        """
        p, _ = self._to_source(check_points(points_mm))
        fn = getattr(self.field, "evaluate", None)
        if callable(fn):
            res = fn(p, directions=True)
            years = np.asarray(res["years"], dtype=float)
            knot = np.asarray(res.get("knot", np.zeros(len(p))), dtype=float)
            grain = np.asarray(res["direction"], dtype=float)
        else:
            years = evaluate(self.field, p)
            knot = np.zeros(len(p))
            grain = np.asarray(grain_direction(self.field, p), dtype=float)
        if self._turn is not None:
            grain = grain @ self._turn[0].T  # back into this (turned) block's frame
        return {"years": years, "knot": knot, "grain": grain}

    def years(self, points_mm: ArrayLike) -> np.ndarray:
        """Growth time ``(n,)`` in years at ``points_mm : (n, 3)``."""
        p, _ = self._to_source(check_points(points_mm))
        return evaluate(self.field, p)

    @property
    def has_pith(self) -> bool:
        """Whether the growth field's year 0 is a pith (not a grown object's input surface):
        :func:`woodcam.fields.base.has_pith`."""
        return has_pith(self.field)

    @property
    def has_uncertainty(self) -> bool:
        """Whether the growth field is a fit that says where its rings are a guess (an
        ``uncertainty`` layer, :func:`woodcam.inference.evidence.bake_evidence`, read by its
        ``uncertainty_years``): :func:`woodcam.fields.base.has_uncertainty`."""
        return has_uncertainty(self.field)

    def uncertainty_years(self, points_mm: ArrayLike) -> np.ndarray:
        """Years of uncertainty ``(n,)`` of a fitted field at ``points_mm : (n, 3)`` (block frame,
        mm), read where :meth:`years` reads (a turned or resized block's point is its source
        block's); zeros when the field carries none (a true field, a plain fit)."""
        p, _ = self._to_source(check_points(points_mm))
        if not self.has_uncertainty:
            return np.zeros(len(p))
        return np.asarray(self.field.uncertainty_years(p), dtype=float)  # type: ignore[attr-defined]

    def source_face(self, face: str) -> str:
        """The face of the source block (the one the field was fitted or grown in, whose photos
        name its faces) that faces the way this block's ``face`` does: ``face`` itself unless the
        wood is turned (a resized block's faces are parallel to its parent's)."""
        n = np.asarray(FACE_NORMAL[check_face(face)], float)
        if self._turn is not None:
            n = n @ self._turn[0]  # source direction = rot^T n
        return next(f for f in FACES if np.allclose(FACE_NORMAL[f], n))

    def arf(self, points_mm: ArrayLike) -> np.ndarray:
        """Annual-ring field ``(n,)`` in [0, 1) at ``points_mm`` (eq. 6 of seed 000)."""
        return arf(self.years(points_mm))

    def color(self, points_mm: ArrayLike, normals: ArrayLike) -> np.ndarray:
        """Surface colour ``rgb : (n, 3)`` float32 in [0, 1].

        Parameters
        ----------
        points_mm : (n, 3) float
            Surface points, block frame, mm.
        normals : (n, 3) float
            Unit outward surface normals at those points (block frame).

        The appearance's colours are checked (:func:`check_rgb`: shape, finite, in [0, 1]
        within :data:`~woodcam.tolerances.COLOR_RANGE_TOL`, then clipped) and computed in
        chunks on ``threads`` threads.
        """
        p = check_points(points_mm)
        n = check_normals(normals, p.shape)
        p, n = self._to_source(p, n)
        out = np.empty((len(p), 3), np.float32)
        starts = range(0, len(p), _CHUNK)

        def work(i):
            rgb = self.appearance.color(self.field, p[i:i + _CHUNK], n[i:i + _CHUNK])
            out[i:i + _CHUNK] = check_rgb(rgb, len(p[i:i + _CHUNK]), "appearance.color")

        if self.threads == 1 or len(p) <= _CHUNK:
            for i in starts:
                work(i)
        else:
            with ThreadPoolExecutor(self.threads) as pool:
                list(pool.map(work, starts))
        return out


def check_normals(normals, shape: tuple, dtype=np.float32) -> np.ndarray:
    """``normals`` as a ``shape`` (the points', ``(n, 3)``) array of ``dtype``, each finite and at
    least :data:`~woodcam.tolerances.MIN_NORMAL_LENGTH` long, or a WoodcamError naming the first
    that is not (a NaN or zero normal was coloured as an equal blend of the axes' colourings).
    float32 as given is not copied (the bake's hot path)."""
    # a string was numpy's bare ValueError, complex normals lost their imaginary parts under
    # numpy's ComplexWarning (a float array, the hot path, is taken as it is)
    real = normals if isinstance(normals, np.ndarray) and normals.dtype.kind in "biuf" else as_floats(normals)
    n = None if real is None else np.asarray(real, dtype=dtype)
    if n is None or n.shape != shape:
        fix = "" if n is not None else numbers_fix(normals, "normals")
        raise WoodcamError(f"normals must {'have' if n is not None else 'be real numbers with'} the shape of "
                           f"points_mm {shape}; got {n.shape if n is not None else received(normals, 40)}"
                           + (f"; {fix}" if fix else ""))
    length2 = np.einsum("ij,ij->i", n, n, dtype=np.float64)
    bad = ~(np.isfinite(length2) & (length2 >= MIN_NORMAL_LENGTH ** 2))
    if bad.any():
        i = int(np.argmax(bad))
        raise WoodcamError(f"normals must be finite, non-zero directions (outward surface normals, "
                           f"block frame); normal {i} is {n[i].tolist()} ({int(bad.sum())} of {len(n)} are "
                           f"NaN/inf or shorter than {MIN_NORMAL_LENGTH:g}); pass the surface's normals "
                           "(trimesh: mesh.face_normals; drop degenerate triangles first)")
    return n


def vertex_color_normals(mesh) -> np.ndarray:
    """Unit normals ``(n, 3)`` float64 at the vertices of a triangle ``mesh`` (trimesh), one a
    direction at every vertex, for colouring the vertices with ``wood.color`` (which refuses
    a zero normal, :func:`check_normals`).

    trimesh's ``vertex_normals`` where they are a direction; where they are not, the normal of
    the vertex's largest triangle (the two sides of a fin, whose normals cancel, or a vertex
    whose other triangles are degenerate), and +Z at a vertex no triangle of non-zero area uses
    (an unreferenced vertex, or one of zero-area triangles only: its colour is never drawn).
    A user's slightly dirty mesh (unreferenced vertices, a zero-area triangle, duplicate faces)
    is still coloured."""
    normals = np.array(mesh.vertex_normals, dtype=np.float64).reshape(-1, 3)
    length2 = np.einsum("ij,ij->i", normals, normals)
    bad = ~(np.isfinite(length2) & (length2 >= MIN_NORMAL_LENGTH ** 2))
    if not bad.any():
        return normals
    faces = np.asarray(mesh.faces, dtype=np.int64).reshape(-1, 3)
    face_normals = np.asarray(mesh.face_normals, dtype=np.float64).reshape(-1, 3)
    area = np.nan_to_num(np.asarray(mesh.area_faces, dtype=np.float64))
    fallback = np.zeros_like(normals)
    fallback[:, 2] = 1.0
    if len(faces):
        corner_vertex = faces.ravel()
        corner_face = np.repeat(np.arange(len(faces)), 3)
        order = np.lexsort((area[corner_face], corner_vertex))  # by vertex, then area
        v, f = corner_vertex[order], corner_face[order]
        largest = np.r_[v[1:] != v[:-1], True]                  # each vertex's last corner
        usable = largest & (area[f] > 0) & np.all(np.isfinite(face_normals[f]), axis=1) \
            & (np.einsum("ij,ij->i", face_normals[f], face_normals[f]) >= MIN_NORMAL_LENGTH ** 2)
        fallback[v[usable]] = face_normals[f[usable]]
    normals[bad] = fallback[bad]
    return normals


def check_rgb(rgb, n: int, who: str = "wood.color") -> np.ndarray:
    """The colour contract, checked in one place: ``(n, 3)`` finite, in [0, 1] (within
    :data:`~woodcam.tolerances.COLOR_RANGE_TOL`, then clipped). Returns float32 ``(n, 3)``."""
    out = np.asarray(rgb, dtype=np.float32)
    if out.shape != (n, 3):
        raise WoodcamError(f"{who} must return rgb of shape (n, 3) = ({n}, 3); got {out.shape}; "
                           "fix the appearance's color()")
    if not np.all(np.isfinite(out)):
        raise WoodcamError(f"{who} returned non-finite colours (NaN or inf); check the appearance "
                           "and that the points lie inside the block")
    lo, hi = float(out.min(initial=0.0)), float(out.max(initial=0.0))
    if lo < -COLOR_RANGE_TOL or hi > 1.0 + COLOR_RANGE_TOL:
        raise WoodcamError(f"{who} must return rgb in [0, 1]; got values in [{lo:.4g}, {hi:.4g}]; "
                           "divide 0..255 colours by 255")
    return np.clip(out, 0.0, 1.0)


def wood_colors(wood: WoodLike, points_mm: ArrayLike, normals: ArrayLike) -> np.ndarray:
    """``wood.color(points_mm (n, 3), normals (n, 3)) -> rgb (n, 3)`` float32 in [0, 1], checked.

    What every consumer of the seam calls (bake, view, export): a :class:`Wood` checks and
    batches its appearance itself; any other object with a ``color`` method (a test's analytic
    wood, a user's) is called in batches of :data:`~woodcam.tolerances.MAX_BATCH_POINTS` and
    checked by the same :func:`check_rgb`. ``normals`` may be one ``(3,)`` normal for all points.
    """
    if wood is None or not callable(getattr(wood, "color", None)):
        raise WoodcamError("wood must have a method color(points_mm (n, 3), normals (n, 3)) -> "
                           f"rgb (n, 3); got {type(wood).__name__}; pass a woodcam Wood")
    p = check_points(points_mm)
    nrm = as_floats(normals)
    if nrm is not None and nrm.shape == (3,):
        nrm = np.broadcast_to(nrm, p.shape)
    if isinstance(wood, Wood):
        # Wood.color checks the normals itself; checking here too doubled the bake's hot path.
        return wood.color(p, normals if nrm is None else nrm)
    nrm = check_normals(normals if nrm is None else nrm, p.shape, np.float64)
    out = np.empty((len(p), 3), np.float32)
    for s in range(0, len(p), MAX_BATCH_POINTS):
        q = p[s:s + MAX_BATCH_POINTS]
        out[s:s + len(q)] = check_rgb(wood.color(q, np.ascontiguousarray(nrm[s:s + len(q)])), len(q))
    return out
