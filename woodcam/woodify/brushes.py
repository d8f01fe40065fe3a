"""User-defined growth (seed 004 sec. 4.2.2): painted speed gains and growth directions.

A brush stroke is painted on the input surface: centre ``c`` (mm, object frame), radius ``r``
(mm), speed ``gain`` (1 = unchanged, 2 = twice as fast, 0.5 = half) and a growth
``direction`` with a ``strength`` in [0, 1) that bends the front towards it. Its weight at a
surface point ``y`` is the Gaussian fall-off ``G = exp(-|y - c|^2 / (2 r^2))``. The paint is
carried outward with the growth: a grid node takes the weights of its closest input-surface
point. With weights ``G_b`` the normal speed becomes

    g (1 + w . n),   g = prod_b (1 + (gain_b - 1) G_b),   w = delta up + sum_b strength_b G_b d_b

(``d_b`` unit). The same can come per vertex of the input mesh (``vertex_gain (n,)``,
``vertex_direction (n, 3)`` whose length is the strength), interpolated barycentrically.

JSON brush file: ``{"brushes": [{"centre_mm": [x, y, z], "radius_mm": r, "gain": 1.5,
"direction": [0, 0, 1], "strength": 0.3}, ...]}`` (``gain``, ``direction``, ``strength``
optional).
"""

from __future__ import annotations

import json
import numbers
from dataclasses import dataclass, fields

import numpy as np
from numpy.typing import ArrayLike

from .._checks import as_floats, check_path, check_vector, did_you_mean, received
from .._readers import read_json_file
from ..errors import WoodcamError
from ..fields.base import check_points
from .._types import PathLike


@dataclass(frozen=True)
class Brush:
    """One painted stroke (see module docstring); lengths in mm, object frame (the input mesh's).

    Attributes
    ----------
    centre_mm : (3,) float
        Centre of the stroke on (or near) the input surface, mm.
    radius_mm : float
        Gaussian fall-off radius ``r`` (mm), > 0.
    gain : float
        Speed gain at the centre, > 0 (1 = unchanged, 2 = twice as fast).
    direction : (3,) float
        Direction the front bends towards (normalised here), object frame.
    strength : float
        How far it bends, in [0, 1) (0 = not at all).
    """

    centre_mm: tuple[float, float, float]
    radius_mm: float
    gain: float = 1.0
    direction: tuple[float, float, float] = (0.0, 0.0, 1.0)
    strength: float = 0.0

    def __post_init__(self):
        # complex numbers lost their imaginary parts under numpy's ComplexWarning
        check_vector(self.centre_mm, "brush centre_mm", fix="the stroke's centre in mm, e.g. (0, 0, 10)")
        for name in ("radius_mm", "gain", "strength"):  # '5' was a TypeError of np.isfinite
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, numbers.Real):
                raise WoodcamError(f"brush {name} must be a number; got {v!r}; e.g. Brush((0, 0, 10), radius_mm=5)")
        if not (np.isfinite(self.radius_mm) and self.radius_mm > 0):
            raise WoodcamError(f"brush radius_mm must be > 0 (mm); got {self.radius_mm!r}; the stroke's reach in mm, "
                               "e.g. Brush((0, 0, 10), radius_mm=5)")
        if not (np.isfinite(self.gain) and self.gain > 0):
            raise WoodcamError(f"brush gain must be > 0 (1 = unchanged speed); got {self.gain!r}")
        if not 0.0 <= self.strength < 1.0:
            raise WoodcamError(f"brush strength must lie in [0, 1); got {self.strength!r}")
        # (inf, 0, 0) was taken as the direction (nan, nan, nan)
        d = check_vector(self.direction, "brush direction", unit=True, fix="e.g. direction=(0, 0, 1)")
        object.__setattr__(self, "direction", tuple(float(v) for v in d))

    def weight(self, points_mm: ArrayLike) -> np.ndarray:
        """Gaussian fall-off ``(n,)`` in [0, 1] at surface points ``(n, 3)`` (mm)."""
        # one point (3,) or a (n, 2) array broadcast into nonsense, NaN gave NaN weights, 'a'
        # was numpy's bare ValueError
        d2 = np.sum((check_points(points_mm) - np.asarray(self.centre_mm)) ** 2, axis=-1)
        return np.exp(-0.5 * d2 / self.radius_mm ** 2)


def load_brushes(path: PathLike) -> list[Brush]:
    """Read the JSON brush file ``path`` (module docstring): ``{"brushes": [...]}`` or the list
    alone."""
    path = check_path(path, "load_brushes: path", fix="pass the brush file, e.g. brushes.json")
    like = ('{"brushes": [{"centre_mm": [x, y, z], "radius_mm": r, "gain": 1.5, "direction": [0, 0, 1], '
            '"strength": 0.3}]}')
    doc = read_json_file(path, "brushes file")  # strict JSON, its errors naming the file
    items = doc.get("brushes") if isinstance(doc, dict) else doc
    if isinstance(doc, dict) and items is not None:
        _refuse_unknown_keys(doc, ("brushes",), f"brushes file {str(path)!r}", like)
    if not isinstance(items, list):
        got = "no 'brushes'" if items is None else type(items).__name__
        raise WoodcamError(f"brushes file {str(path)!r} must hold a list of brushes (or an object whose "
                           f"'brushes' is one); got {got}; write it like {like}")
    out = []
    for i, b in enumerate(items):
        if not isinstance(b, dict):
            raise WoodcamError(f"brushes file {str(path)!r}: brush {i} must be a JSON object; got "
                               f"{json.dumps(b)[:80]}; write it like {like}")
        # a misspelt key ('stregth') was dropped: the brush painted with the default instead
        _refuse_unknown_keys(b, [x.name for x in fields(Brush)], f"brushes file {str(path)!r}: brush {i}", like)
        try:  # numbers as written: "4" or true for a number were float()'s 4.0 and 1.0
            out.append(Brush(tuple(b["centre_mm"]), b["radius_mm"], b.get("gain", 1.0),
                             tuple(b.get("direction", (0.0, 0.0, 1.0))), b.get("strength", 0.0)))
        except (KeyError, TypeError, WoodcamError) as err:
            why = f"missing {err}" if isinstance(err, KeyError) else str(err)
            raise WoodcamError(f"brushes file {str(path)!r}: brush {i} ({json.dumps(b)[:80]}) must be like "
                               f"{like}: {why}") from err
    return out


def _refuse_unknown_keys(obj: dict, known, where: str, like: str) -> None:
    """A WoodcamError naming the first key of ``obj`` not in ``known``, the nearest known key and
    all of them: nothing a user wrote is silently dropped."""
    unknown = [k for k in obj if k not in known]
    if unknown:
        key = unknown[0]
        near = did_you_mean(key, known)
        hint = f"{near} " if near else ""
        raise WoodcamError(f"{where} has an unknown key {key!r}" + (f" (of {len(unknown)})" if len(unknown) > 1 else "")
                           + f"; {hint}the keys are {', '.join(sorted(known))}; write it like {like}")


def paint(origin_mm, brushes=(), *, vertex_gain=None, vertex_direction=None, mesh=None, tri=None):
    """Gain ``(n,)`` and added wind ``(n, 3)`` at input-surface points ``origin_mm (n, 3)``.

    ``vertex_gain`` / ``vertex_direction`` are per vertex of ``mesh``; ``tri (n,)`` gives the
    input triangle of each origin for their barycentric interpolation.
    """
    p = np.asarray(origin_mm, float)
    gain = np.ones(len(p))
    wind = np.zeros((len(p), 3))
    for b in brushes:
        G = b.weight(p)
        gain *= 1.0 + (b.gain - 1.0) * G
        wind += (b.strength * G)[:, None] * np.asarray(b.direction)
    if vertex_gain is not None or vertex_direction is not None:
        from .surfaces import barycentric_on, carry

        _, bary = barycentric_on(mesh, p, tri)
        vg, vd = check_vertex_paint(vertex_gain, vertex_direction, len(mesh.vertices))
        if vg is not None:
            gain *= carry(mesh, vg, tri, bary)
        if vd is not None:
            wind += carry(mesh, vd, tri, bary)
    return gain, wind


def check_vertex_paint(vertex_gain, vertex_direction,
                       n_vertices: int) -> tuple[np.ndarray | None, np.ndarray | None]:
    """``(vertex_gain (n,) float > 0 or None, vertex_direction (n, 3) finite float or None)``
    for a mesh of ``n_vertices``, or a clear error (a NaN gain was a bare ValueError deep in
    the grid sizing)."""
    vg = vd = None
    if vertex_gain is not None:
        vg = as_floats(vertex_gain)  # complex gains lost their imaginary parts (ComplexWarning)
        if vg is None or vg.shape != (n_vertices,) or not np.all(np.isfinite(vg) & (vg > 0)):
            got = received(vertex_gain) if vg is None else f"shape {vg.shape}" + (
                "" if vg.shape != (n_vertices,) else " with a value <= 0, NaN or inf")
            raise WoodcamError(f"vertex_gain must be {n_vertices} finite values > 0, one per vertex of "
                               f"the mesh; got {got}; e.g. np.ones(len(mesh.vertices))")
    if vertex_direction is not None:
        vd = as_floats(vertex_direction)
        if vd is None or vd.shape != (n_vertices, 3) or not np.all(np.isfinite(vd)):
            got = received(vertex_direction) if vd is None else f"shape {vd.shape}" + (
                "" if vd.shape != (n_vertices, 3) else " with NaN or inf")
            raise WoodcamError(f"vertex_direction must be finite real numbers with shape ({n_vertices}, 3), "
                               f"one wind vector per vertex of the mesh; got {got}")
    return vg, vd
