"""A growth field baked onto a coarse regular grid and read back by smooth interpolation.

Growth time is smooth away from the pith, so a slow field (a neural net, a knotted log) can be
sampled once on a grid of a few mm and interpolated everywhere else. Samples sit on the grid
NODES: node ``(i, j, k)`` is at ``origin_mm + (i, j, k) * spacing_mm``. Interpolation is a cubic
B-spline through the nodes (scipy's ``map_coordinates`` with prefiltered coefficients), which
is C2 so rings stay smooth; points beyond the grid clamp to its border ("nearest"). The ARF is
always computed from the interpolated growth time, never interpolated itself.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from dataclasses import field as dc_field
from pathlib import Path
from typing import Literal

import numpy as np

from .._checks import as_floats, check_number, check_vector, npz_path, numbers_fix, received
from .._readers import read_npz
from .._repr import summary_repr
from .._types import ArrayLike, PathLike
from ..errors import WoodcamError
from .base import check_points, evaluate

Interpolation = Literal["cubic", "linear"]
_ORDER = {"cubic": 3, "linear": 1}


def _spacing(spacing_mm) -> np.ndarray:
    """``(3,)`` node spacing from one number or three, each finite and > 0."""
    fix = "pass one spacing in mm or three (X, Y, Z), e.g. 2.0"
    if np.ndim(spacing_mm) == 0:
        return np.full(3, check_number(spacing_mm, "spacing_mm", lo=0, lo_open=True, fix=fix))
    sp = check_vector(spacing_mm, "spacing_mm", fix=fix)
    if np.any(sp <= 0):
        raise WoodcamError(f"spacing_mm must be > 0 along each axis; got {spacing_mm!r}; {fix}")
    return sp


#: Grid coordinates (in nodes) further than this outside a grid are moved in to it before
#: interpolation. scipy's ``map_coordinates`` turns coordinates into integers, and past 2**63 it
#: read another place of memory: a GridField gave 4.9e230 years at x = 1e20 mm and a cubic
#: WoodifiedField 0, where "nearest" promises the border's value. Beyond the spline's support (2
#: nodes) every point reads the border already, so moving it in keeps that value; points
#: within 2**30 nodes are not touched (the same result bit for bit).
FAR_NODES = 2.0 ** 30


def grid_coords(points_mm: np.ndarray, origin_mm, spacing_mm, shape) -> np.ndarray:
    """``(3, n)`` coordinates, in nodes, of ``points_mm (n, 3)`` on the grid of node ``(0, 0,
    0)`` at ``origin_mm``, ``spacing_mm`` apart, of ``shape`` nodes: what ``map_coordinates``
    takes, each at most :data:`FAR_NODES` outside the grid. The one home of a grid's index."""
    idx = (points_mm - np.asarray(origin_mm)) / np.asarray(spacing_mm)
    return np.clip(idx, -FAR_NODES, np.asarray(shape[:3]) - 1 + FAR_NODES).T


def _nodes_mm(origin_mm, spacing_mm, shape) -> np.ndarray:
    """``(prod(shape), 3)`` mm of a grid's nodes, C order (``ij`` indexing)."""
    axes = [origin_mm[i] + spacing_mm[i] * np.arange(shape[i]) for i in range(3)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)


@dataclass(frozen=True)
class GridField:
    """Growth time on grid nodes plus interpolation.

    Parameters
    ----------
    years : (nx, ny, nz) float
        Growth time at the nodes.
    origin_mm : (3,) float
        Block-frame position of node ``(0, 0, 0)``.
    spacing_mm : float or (3,) float
        Node spacing along X, Y, Z.
    interpolation : "cubic" or "linear"
    axis : (3,) float, non-zero
        The pith direction (block frame; default ``(0, 0, 1)``): the fibre direction
        :func:`woodcam.fields.base.grain_direction` gives everywhere in the field (kept as given;
        it normalises it).
    layers : dict name -> (nx, ny, nz) float, optional
        Further quantities on the same nodes, read by linear interpolation:
        ``"uncertainty"`` (years; how unsure a fit is of the growth time there, e.g. the spread
        of the hypotheses it could not tell apart; :meth:`uncertainty_years`) and ``"knot"``
        (0..1 knot darkening weight of knots fitted into the field; :meth:`knot_features`,
        present only with that layer, as appearances test ``hasattr(field, "knot_features")``).
    meta : dict
        Plain-JSON facts about how the field was made (fit method, evidence, warnings).
    """

    __repr__ = summary_repr  # arrays as shapes: a notebook shows one line

    years: np.ndarray
    origin_mm: tuple[float, float, float]
    spacing_mm: tuple[float, float, float]
    interpolation: Interpolation = "cubic"
    axis: tuple[float, float, float] = (0.0, 0.0, 1.0)
    layers: dict = dc_field(default_factory=dict, repr=False, compare=False)
    meta: dict = dc_field(default_factory=dict, repr=False, compare=False)
    _coeffs: np.ndarray = dc_field(init=False, repr=False, compare=False)

    def __post_init__(self):
        g = as_floats(self.years)  # a string was numpy's bare "could not convert string to float"
        if g is None or g.ndim != 3 or min(g.shape) < 2 or not np.all(np.isfinite(g)):
            got = received(self.years) if g is None else f"shape {g.shape}" + (
                "" if g.ndim != 3 or np.all(np.isfinite(g)) else f" with {int(np.sum(~np.isfinite(g)))} non-finite")
            fix = (numbers_fix(self.years, "years") if g is None else "") or \
                "e.g. years=np.zeros((4, 4, 4)), a real growth time at each node"
            raise WoodcamError(f"years must be a finite (nx, ny, nz) grid of real numbers, each >= 2; got {got}; {fix}")
        if not isinstance(self.layers, Mapping):  # a list was dict()'s bare TypeError
            raise WoodcamError(f"layers must be a dict {{name: grid shaped like years}}; got "
                               f"{type(self.layers).__name__}; e.g. layers={{'uncertainty': grid}} or leave it out")
        if not isinstance(self.meta, dict):  # a list was saved and read back, and failed at meta.get
            raise WoodcamError(f"meta must be a dict of field metadata; got {type(self.meta).__name__}; "
                               "e.g. meta={'method': 'radial'} or leave it out")
        if self.interpolation not in _ORDER:
            raise WoodcamError(f"interpolation must be one of {list(_ORDER)}; got {self.interpolation!r}")
        sp = _spacing(self.spacing_mm)
        origin = check_vector(self.origin_mm, "origin_mm", fix="pass the mm position of node (0, 0, 0)")
        # a zero or NaN axis made grain_direction NaN everywhere, silently
        check_vector(self.axis, "axis", unit=True, fix="pass the pith direction, e.g. (0, 0, 1)")
        axis = np.asarray(self.axis, float)  # kept as given: grain_direction normalises it
        object.__setattr__(self, "years", g)
        object.__setattr__(self, "spacing_mm", tuple(float(x) for x in sp))
        object.__setattr__(self, "origin_mm", tuple(float(x) for x in origin))
        object.__setattr__(self, "axis", tuple(float(x) for x in axis))
        layers = {}
        for name, v in dict(self.layers).items():
            u = as_floats(v)  # complex was numpy's ComplexWarning, text its bare ValueError
            if u is None or u.shape != g.shape or not np.all(np.isfinite(u)):
                got = received(v) if u is None else f"shape {u.shape}" + (
                    "" if u.shape != g.shape else f" with {int(np.sum(~np.isfinite(u)))} non-finite")
                raise WoodcamError(f"layer {name!r} must be a finite grid of real numbers shaped like years "
                                   f"{g.shape}; got {got}; pass one value per node of years")
            layers[str(name)] = u
        object.__setattr__(self, "layers", layers)
        order = _ORDER[self.interpolation]
        from scipy import ndimage  # here: importing it costs 0.3 s every CLI run pays

        coeffs = ndimage.spline_filter(g, order=order, mode="nearest") if order > 1 else g
        object.__setattr__(self, "_coeffs", coeffs)

    @classmethod
    def bake(cls, field, lo_mm, hi_mm, spacing_mm: float = 2.0, *, margin_nodes: int = 2,
             interpolation: Interpolation = "cubic", workers: int = 1) -> GridField:
        """Sample ``field`` on a grid covering the box ``[lo_mm, hi_mm]`` plus a margin.

        The margin keeps the spline's border handling away from the box, so interpolation
        inside the box is as good as in the middle of the grid. ``workers > 1``: a share of the
        nodes in a forked process, for a field safe to use after a fork
        (:func:`~woodcam.fields.base.evaluate`).
        """
        # 'a' was a bare ValueError, NaN a misleading grid-size message
        lo = check_vector(lo_mm, "lo_mm", fix="the box's low corner in mm, e.g. (0, 0, 0)")
        hi = check_vector(hi_mm, "hi_mm", fix="the box's high corner in mm, e.g. (50, 40, 30)")
        if np.any(hi <= lo):
            raise WoodcamError(f"hi_mm must exceed lo_mm on every axis; got lo_mm={lo_mm!r}, "
                               f"hi_mm={hi_mm!r}; swap them or widen the box")
        spacing_mm = check_number(spacing_mm, "spacing_mm", lo=0, lo_open=True,
                                  fix="pass one node spacing in mm, e.g. 2.0")
        margin_nodes = check_number(margin_nodes, "margin_nodes", lo=0, integer=True, fix="e.g. 2")
        n_float = np.ceil((hi - lo) / spacing_mm) + 1 + 2 * margin_nodes
        from ..limits import check_grid  # before allocating: 1e9 mm blocks must not reach numpy

        check_grid(n_float, "baking a field onto a grid", fix="use a coarser spacing_mm or a "
                   "smaller block")
        n = n_float.astype(int)
        origin = lo - margin_nodes * spacing_mm
        pts = _nodes_mm(origin, (spacing_mm,) * 3, n)
        years = evaluate(field, pts, workers=workers).reshape(tuple(n))
        axis = tuple(np.asarray(getattr(field, "axis", (0.0, 0.0, 1.0)), float))
        return cls(years, tuple(origin), (spacing_mm,) * 3, interpolation, axis)

    def nodes_mm(self) -> np.ndarray:
        """``(n, 3)`` block frame mm of the grid's nodes, in the order of ``years.ravel()``."""
        return _nodes_mm(self.origin_mm, self.spacing_mm, self.years.shape)

    def __call__(self, points_mm: ArrayLike) -> np.ndarray:
        """Interpolated growth time ``years : (n,)`` at ``points_mm : (n, 3)``."""
        p = check_points(points_mm)
        from scipy import ndimage

        return ndimage.map_coordinates(self._coeffs, grid_coords(p, self.origin_mm, self.spacing_mm, self.years.shape),
                                       order=_ORDER[self.interpolation], mode="nearest", prefilter=False)

    def uncertainty_years(self, points_mm: ArrayLike) -> np.ndarray:
        """``(n,)`` years of uncertainty at ``points_mm (n, 3)`` (linear interpolation of
        :attr:`uncertainty`; zeros when the field carries none)."""
        return self.layer("uncertainty", points_mm)

    def layer(self, name: str, points_mm: ArrayLike) -> np.ndarray:
        """``(n,)`` linear interpolation of layer ``name`` at ``points_mm (n, 3)`` (zeros when
        the field has no such layer)."""
        p = check_points(points_mm)
        if name not in self.layers:
            return np.zeros(len(p))
        from scipy import ndimage

        grid = self.layers[name]
        return ndimage.map_coordinates(grid, grid_coords(p, self.origin_mm, self.spacing_mm, grid.shape),
                                       order=1, mode="nearest")

    def __getattr__(self, name):
        # knot_features and evaluate (what the colour map asks of knotted fields) exist only
        # with a "knot" layer: appearances test hasattr
        if name in ("knot_features", "evaluate") and "knot" in self.__dict__.get("layers", {}):
            def knot_features(points_mm):
                k = np.clip(self.layer("knot", points_mm), 0.0, 1.0)
                # "dead" / "outline" layers (dead knots) read as zeros when absent
                return {"knot": k, "dead": np.clip(self.layer("dead", points_mm), 0.0, 1.0),
                        "outline": np.clip(self.layer("outline", points_mm), 0.0, 1.0)}

            def evaluate(points_mm, *, directions: bool = False):
                from .base import grain_direction

                out = {"years": self(points_mm), **knot_features(points_mm)}
                if directions:
                    out["direction"] = grain_direction(self, points_mm)
                return out
            return knot_features if name == "knot_features" else evaluate
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def save(self, path: PathLike) -> Path:
        """Write the grid to an ``.npz`` file; :meth:`load` restores it exactly. A ``path``
        without the suffix gets ``.npz`` appended; one ending in it in any case (``F.NPZ``, which
        ``woodcam fit --out`` takes) is written as named."""
        path = npz_path(path)
        import json

        from .._atomic import atomic_write

        extra = {f"layer_{k}": v for k, v in self.layers.items()}
        # a reader never sees half a file; `fit --out new/f.npz` failed after the fit
        with atomic_write(path, mkdir=True) as fh:
            np.savez_compressed(fh, years=self.years, origin_mm=self.origin_mm,
                                spacing_mm=self.spacing_mm, interpolation=self.interpolation,
                                axis=self.axis, meta=json.dumps(self.meta), **extra)
        return path

    @classmethod
    def load(cls, path) -> GridField:
        import json

        # with a fix ('woodcam eval rings --truth notes.json' said what it was not, not how to make one)
        with read_npz(path, "a woodcam grid field (.npz with 'years', 'origin_mm', 'spacing_mm')",
                      fix="give a field file as 'woodcam fit BLOCK --out FIELD.npz' writes it (GridField.save)") as z:
            meta = json.loads(str(z["meta"])) if "meta" in z.files else {}
            layers = {k[len("layer_"):]: z[k] for k in z.files if k.startswith("layer_")}
            return cls(z["years"], tuple(z["origin_mm"]), tuple(z["spacing_mm"]),
                       str(z["interpolation"]), tuple(z["axis"]), layers, meta)
