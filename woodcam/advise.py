"""Placement advice: where in this block should the part go?

Searches placements of a part in a block -- the rotations the user allows times translations
on a grid over every position where the part's bounding box fits -- and ranks them by what a
woodworker cares about, each term reported on its own (all in [0, 1], lower is better):

``knots``      share of the part's surface (and the wood 1 and 3 mm under it) inside a knot
``pith``       share of the same points within :data:`PITH_YEARS` of the pith (the pith
               splits and checks as it dries); none in wood without a pith (a woodified
               object, whose year 0 is the mesh it grew from: :func:`_pith`)
``end_grain``  share of the surface area whose normal is within 45 degrees of the fibres:
               end grain finishes darker and rougher
``runout``     for long thin parts only: the angle between the part's long axis and the mean
               fibre direction over 90 degrees, times the part's elongation (short grain
               across a thin section is where it breaks)

``score`` is their weighted sum (:data:`DEFAULT_WEIGHTS`). Every candidate is scored from the
same sample of surface points (area-weighted) evaluated through :meth:`Wood.features`, all
candidates of one rotation in one vectorised batch.

The winning transform is expressed as ``--place`` operations (:mod:`woodcam.cad.place`):
``rotate:AXIS:DEG`` steps and one ``translate:X,Y,Z``, so ``woodcam bake --place ...`` reproduces
it.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .errors import WoodcamError, WoodcamWarning
from .frames import AXIS_ENDS
from .units import Units, fmt_span, fmt_volume, say_length

#: Points within this many years of the pith count as pith (juvenile wood and the pith itself).
PITH_YEARS = 2.0
#: Depths (mm) under the surface sampled besides the surface itself: a knot 1-3 mm under a
#: visible face shows after sanding or finishing cuts.
SUBSURFACE_MM = (1.0, 3.0)
#: Weights of the terms in ``score``; knots and pith matter most to a woodworker.
DEFAULT_WEIGHTS = {"knots": 4.0, "pith": 3.0, "end_grain": 1.0, "runout": 2.0}
#: Allowed rotation sets: none, quarter turns about z, or all 24 axis-aligned orientations.
ROTATION_SETS = ("none", "z90", "all90")


@dataclass
class Placement:
    """One candidate: its ``--place`` operations, transform and scores."""

    ops: list[str]
    matrix: np.ndarray
    terms: dict[str, float]
    score: float


@dataclass
class PlacementAdvice:
    """What :func:`advise_placement` returns: candidates ranked best first."""

    ranked: list[Placement]
    candidates: int
    elongation: float
    weights: dict[str, float] = field(default_factory=dict)

    def table(self, top: int = 5, op_text: Callable[[str], str] = str, place_title: str = "place") -> str:
        """The top placements as text, one line each, with every term; ``op_text`` writes each
        --place operation (e.g. its lengths in the user's unit), under the column title
        ``place_title`` (which says that unit where it is not mm)."""
        lines = [f"{'rank':>4} {'score':>6} {'knots':>6} {'pith':>6} {'end':>6} {'runout':>6}  {place_title}"]
        for i, p in enumerate(self.ranked[:top], 1):
            t = p.terms
            lines.append(f"{i:>4} {p.score:6.3f} {t['knots']:6.3f} {t['pith']:6.3f} "
                         f"{t['end_grain']:6.3f} {t['runout']:6.3f}  "
                         + " ".join(f"--place {op_text(o)}" for o in p.ops))
        return "\n".join(lines)


def _orientations(rotations: str) -> list[tuple[list[str], np.ndarray]]:
    """(ops, 3x3 matrix) of every allowed orientation, duplicates removed."""
    from .cad.place import _rotation

    if rotations not in ROTATION_SETS:
        raise WoodcamError(f"rotations must be one of {ROTATION_SETS}; got {rotations!r}")
    if rotations == "none":
        return [([], np.eye(3))]
    if rotations == "z90":
        return [([f"rotate:z:{90 * k}"] if k else [], _rotation(2, 90.0 * k)) for k in range(4)]
    seen, out = set(), []
    for ax, ay, az in itertools.product(range(4), repeat=3):
        m = _rotation(2, 90.0 * az) @ _rotation(1, 90.0 * ay) @ _rotation(0, 90.0 * ax)
        key = tuple(np.round(m).astype(int).ravel())
        if key in seen:
            continue
        seen.add(key)
        ops = [f"rotate:{a}:{90 * k}" for a, k in (("x", ax), ("y", ay), ("z", az)) if k]
        out.append((ops, m))
    return out


def _part_mesh(part):
    """Any part source -> its surface as a ``trimesh.Trimesh`` (block frame, mm)."""
    from ._manifold import manifold_to_trimesh
    from .cad import load_part

    return manifold_to_trimesh(load_part(part))


def reads_wood(wood) -> bool:
    """Whether ``wood`` has the growth field the advice reads (``features``: knots, years,
    grain): False for a user's wood that only draws colours (``color``), a stock to bake and
    view that :func:`part_report` and :func:`advise_placement` refuse."""
    return callable(getattr(wood, "features", None))


def _features_of(wood, who: str, arg: str):
    """``wood.features``, the growth field every placement term is read from (knots, years,
    grain), or a refusal: a user's wood that only draws (``color``) is a stock to bake and view,
    but it has no knots, pith or fibres to score, and failed deep in the scoring as an
    AttributeError ('features')."""
    features = getattr(wood, "features", None)
    if not reads_wood(wood):
        raise WoodcamError(f"{who}: {arg} must read the wood, a method features(points_mm (n, 3)) -> dict with "
                           f"'knot', 'years' and 'grain' (the knots, pith and fibres it scores); got "
                           f"{type(wood).__name__}, which only draws colours; open the stock with open_stock "
                           "or pass Wood(field)")
    return features


def _pith(wood, years: np.ndarray, knot: np.ndarray) -> np.ndarray:
    """Where points of ``years`` (any shape) are pith: within :data:`PITH_YEARS` of year 0 and
    not in a knot ``knot`` (same shape; inside a knot, years count along the branch: its own
    pith is knot, not stem pith). Nowhere in wood without a pith (``wood.has_pith`` False: a
    woodified object, whose year 0 is the surface it grew from; its part report warned 'the
    pith reaches the part: expect checks' of the input mesh)."""
    if not getattr(wood, "has_pith", True):  # a user's Wood-like without the property: a stem's
        return np.zeros(years.shape, dtype=bool)
    return (years < PITH_YEARS) & ~knot


def _sample(mesh, count: int, rng):
    """Area-weighted surface points and normals of ``mesh`` (block frame, mm)."""
    areas = np.asarray(mesh.area_faces, dtype=float)
    tri = rng.choice(len(areas), size=count, p=areas / areas.sum())
    u, v = rng.random(count), rng.random(count)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    corners = np.asarray(mesh.vertices)[np.asarray(mesh.faces)[tri]]
    points = corners[:, 0] + u[:, None] * (corners[:, 1] - corners[:, 0]) \
        + v[:, None] * (corners[:, 2] - corners[:, 0])
    return points, np.asarray(mesh.face_normals)[tri]


def advise_placement(part, stock, *, rotations: str = "z90", candidates: int = 1000,
                     margin_mm: float = 1.0, samples: int = 1500,
                     weights: dict[str, float] | None = None, seed: int = 0,
                     progress: bool = False, source: object = None,
                     units_fix: str = ("scale it first: woodcam.cad.place.place_part(part, ['scale:25.4'], "
                                       "stock.size_mm) (in metres: 'scale:1000')")) -> PlacementAdvice:
    """Rank placements of ``part`` in ``stock`` (see module docstring).

    Parameters
    ----------
    part : manifold3d.Manifold or any source :func:`woodcam.cad.load_part` takes
        The part as modelled (block frame, mm); its position is only the starting point.
    stock : woodcam.stock.Stock
    rotations : {"none", "z90", "all90"}
        Orientations to try (about the part's bounding-box centre).
    candidates : int
        About how many placements to score in all (split over the orientations).
    margin_mm : float
        Smallest distance kept between the part's bounding box and the block faces.
    samples : int
        Surface points per candidate (each also sampled 1 and 3 mm under the surface).
    weights : dict, optional
        Term weights; default :data:`DEFAULT_WEIGHTS`.
    seed : int
        Seed of the surface sample.
    progress : bool
        A progress bar over the orientations (:func:`woodcam._progress.progress_bar`).
    source : str, Path or None
        The part as the user gave it (``woodcam place``: the PART path as typed), when ``part``
        is already loaded: the error of a part that fits nowhere names it (else it says
        ``advise_placement: the part``), and the warning of a part in inches says what its
        kind carries (:func:`woodcam.cad.carve.units_note`).
    units_fix : str
        How to scale the part, in the warning of a part in inches
        (:func:`woodcam.cad.carve.units_hint`; ``woodcam place`` names the CAD program).
    """
    from ._progress import progress_bar

    if not (isinstance(candidates, int) and 1 <= candidates <= 1_000_000):
        raise WoodcamError(f"candidates must be an integer in [1, 1e6]; got {candidates!r}")
    if not (math.isfinite(margin_mm) and margin_mm >= 0):
        raise WoodcamError(f"margin_mm must be a finite number >= 0; got {margin_mm!r}")
    w = {**DEFAULT_WEIGHTS, **(weights or {})}
    features = _features_of(stock.wood, "advise_placement", "stock.wood")  # before the part is loaded
    mesh = _part_mesh(part)
    rng = np.random.default_rng(seed)
    pts, nrm = _sample(mesh, samples, rng)
    depth_pts = np.concatenate([pts] + [pts - d * nrm for d in SUBSURFACE_MM])
    lo, hi = mesh.bounds
    centre = (lo + hi) / 2
    from .cad.carve import units_hint

    hint = units_hint(lo, hi, stock.size_mm, units_fix, source=part if source is None else source)
    if hint:  # ranking a speck's placements is no answer for a part exported in inches
        import warnings

        warnings.warn(hint, WoodcamWarning, stacklevel=2)
    # the part's long axis and how long-and-thin it is (principal axes of the surface sample)
    long_axis, _, elongation = _long_axis(pts)
    size = np.asarray(stock.size_mm, dtype=float)
    # the candidates are split over the orientations the part fits in: split over all of them,
    # a long part scored a fraction of what was asked (the spoon blank in the knotty block, 2 of 4
    # quarter turns fitting: 432 of 1000; a 90 mm stick with all90, 8 of 24: 216)
    fitting = [(ops, rot, np.abs(rot) @ (hi - lo)) for ops, rot in _orientations(rotations)]
    fitting = [(ops, rot, ext) for ops, rot, ext in fitting if np.all(size - 2 * margin_mm - ext >= -1e-9)]
    per = max(1, candidates // max(1, len(fitting)))
    ranked: list[Placement] = []
    for ops, rot, ext in progress_bar(fitting, desc="scoring placements", unit="orientation", enabled=progress):
        local = depth_pts - centre
        room = size - 2 * margin_mm - ext  # free room of the rotated bounding box, >= 0 (fits)
        # translation grid: about `per` positions spread over the free room
        free_axes = room > 1e-9
        k = max(1, int(round(per ** (1.0 / max(1, free_axes.sum())))))
        grids = [np.linspace(margin_mm + e / 2, margin_mm + e / 2 + r, k) if f else
                 np.array([margin_mm + e / 2 + max(r, 0.0) / 2])
                 for e, r, f in zip(ext, room, free_axes)]
        centres = np.stack(np.meshgrid(*grids, indexing="ij"), axis=-1).reshape(-1, 3)
        turned = local @ rot.T
        n_rot = nrm @ rot.T
        axis_rot = rot @ long_axis
        points = (turned[None] + centres[:, None]).reshape(-1, 3)
        feats = features(points)
        n_pts = len(turned)
        knot = feats["knot"].reshape(len(centres), n_pts) > 0.5
        pith = _pith(stock.wood, feats["years"].reshape(len(centres), n_pts), knot)
        grain = feats["grain"].reshape(len(centres), n_pts, 3)[:, :len(pts)]
        end = np.abs(np.einsum("cij,ij->ci", grain, n_rot)) > math.cos(math.radians(45))
        mean_grain = grain.mean(axis=1)
        mean_grain /= np.maximum(np.linalg.norm(mean_grain, axis=1, keepdims=True), 1e-12)
        runout = np.degrees(np.arccos(np.clip(np.abs(mean_grain @ axis_rot), 0, 1))) / 90.0
        terms = {"knots": knot.mean(axis=1), "pith": pith.mean(axis=1),
                 "end_grain": end.mean(axis=1), "runout": runout * elongation}
        score = sum(w[name] * value for name, value in terms.items())
        for i, c in enumerate(centres):
            move = c - rot @ centre  # p -> rot (p - centre) + c
            matrix = np.eye(4)
            matrix[:3, :3], matrix[:3, 3] = rot, move
            # rotations act about the bounding-box centre; then one translation lands it
            shift = c - centre
            ranked.append(Placement(
                ops=[*ops, "translate:" + ",".join(f"{v:.3f}" for v in shift)],
                matrix=matrix, terms={n: float(v[i]) for n, v in terms.items()},
                score=float(score[i])))
    if not ranked:
        raise WoodcamError(
            f"{'advise_placement: the part' if source is None else f'part {str(source)!r}'} "
            f"({say_length(hi - lo, '.1f')}) fits the "
            f"{say_length(size, 'g')} block in none of the '{rotations}' "
            f"orientations with a {say_length(margin_mm, 'g')} margin; "
            f"{_no_fit_fixes(hi - lo, size, rotations, margin_mm)}")
    ranked.sort(key=lambda p: p.score)
    return PlacementAdvice(ranked, len(ranked), elongation, w)


def _no_fit_fixes(extent, size, rotations: str, margin_mm: float) -> str:
    """The fixes of a part (bounding box ``extent``, mm) that fits the block ``size`` in none of
    the ``rotations`` orientations with ``margin_mm``, those only that make it fit: more
    rotations where one of all 24 fits, a margin where a smaller one fits (the largest, as a
    number to type), and always the block that holds the part as modelled. The error offered
    all90 and a smaller margin to a part longer than every side of the block."""
    from .units import message_unit, typed_length

    def room(rot):  # the margin the part has in orientation rot (negative: it sticks out)
        return float(np.min((size - np.abs(rot) @ extent) / 2))

    fixes = []
    if rotations != "all90" and max(room(rot) for _, rot in _orientations("all90")) >= margin_mm - 1e-9:
        fixes.append("allow more rotations (--rotations all90)")
    best = max(room(rot) for _, rot in _orientations(rotations))
    if best >= 0:
        fixes.append(f"a margin of at most {typed_length(best, 0.05, ok=lambda v: v <= best)} "
                     f"{message_unit()} (--margin)")
    need = np.maximum(size, extent + 2 * margin_mm)
    block = "x".join(typed_length(n, 0.05, ok=lambda v, n=n: v >= n) for n in need)
    fixes.append(f"a bigger block (at least {block} {message_unit()} for the part as modelled with the "
                 "margin; a built-in block takes it as builtin:NAME:WxDxH)")
    return ", ".join(fixes[:-1]) + (" or " if len(fixes) > 1 else "") + fixes[-1]


#: The most best placements :func:`render_advice` draws (and the worst beside them): ``place
#: --top 100000`` drew a panel per placement, about 1.5 s each, into a picture too wide to read.
MAX_PANELS = 10


def render_advice(advice: PlacementAdvice, part, stock, png, *, top: int = 3, progress: bool = False):
    """The ``top`` best placements (at most :data:`MAX_PANELS`) and the worst side by side in one
    PNG (see :mod:`woodcam.view.compare`); ``progress``: a bar over the panels (about 1.5 s each)."""
    from .view.compare import render_side_by_side

    base = _part_mesh(part)
    meshes, titles = [], []
    shown = [(f"#{i}", p) for i, p in enumerate(advice.ranked[:min(top, MAX_PANELS)], 1)]
    for label, p in [*shown, ("worst:", advice.ranked[-1])]:
        m = base.copy()
        m.apply_transform(p.matrix)
        meshes.append(m)
        t = p.terms  # every panel names the same terms
        titles.append(f"{label} score {p.score:.2f}\nknots {t['knots']:.2f} pith {t['pith']:.2f}\n"
                      f"end grain {t['end_grain']:.2f} runout {t['runout']:.2f}")
    return render_side_by_side(meshes, [stock.wood] * len(meshes), stock.size_mm, titles, png, progress=progress)


#: A region of a long thin part whose fibres cross its long axis by more than this is short
#: grain: it breaks along the fibres under a small load.
SHORT_GRAIN_DEG = 30.0
#: Regions the part report splits a part into along its long axis.
REPORT_REGIONS = 3


def _long_axis(pts: np.ndarray) -> tuple[np.ndarray, int, float]:
    """The long axis of points ``pts`` ((n, 3) mm; principal axes of their covariance) ->
    ``(axis, block_axis, elongation)``: the unit ``axis`` (3,) pointed + along the block axis it
    runs nearest, that axis' index ``block_axis`` (0 x, 1 y, 2 z) and how long-and-thin the
    points are (1 - sqrt(second eigenvalue / largest), in [0, 1])."""
    evals, evecs = np.linalg.eigh(np.cov((pts - pts.mean(axis=0)).T))
    # eigh's sign is arbitrary: the same bowl baked at 5 and at 10 texels/mm had its knots in the
    # "last third" and then the "first", with nothing to say which end was which. Pointed to
    # + along the block axis it runs nearest, part_report's thirds are named by the block's ends.
    ax = int(np.argmax(np.abs(evecs[:, -1])))
    elongation = float(1.0 - math.sqrt(max(evals[1], 0.0) / max(evals[2], 1e-12)))
    return evecs[:, -1] * np.sign(evecs[ax, -1]), ax, elongation


def part_report(mesh, stock, *, samples: int = 4000, seed: int = 0) -> dict:
    """What the wood will do in ``mesh`` (a carved part, block frame, mm) as placed.

    Returns a JSON-able dict: ``volume_mm3``, ``yield`` (part / block volume), the terms of
    :func:`advise_placement` for this placement (``knots`` and ``pith``: shares of the surface
    and the wood :data:`SUBSURFACE_MM` under it together, ``end_grain``: share of the surface),
    ``knots_surface`` (the knot share of the surface alone, which the warning quotes),
    ``elongation``, and ``regions``: the part cut into :data:`REPORT_REGIONS` slabs along its
    long axis, named by the block's ends along the block axis nearest it (``"left third"``,
    ``"middle third"``, ``"right third"``; :data:`woodcam.frames.AXIS_ENDS`), each with its mean
    fibre direction, runout angle (degrees) and knot share (the surface and the wood under it, as
    ``knots``); plus ``warnings`` in words (short grain,
    knots or pith on the surface). Shares are fractions in [0, 1].
    """
    features = _features_of(stock.wood, "part_report", "stock.wood")
    rng = np.random.default_rng(seed)
    pts, nrm = _sample(mesh, samples, rng)
    depth = np.concatenate([pts] + [pts - d * nrm for d in SUBSURFACE_MM])
    feats = features(depth)
    grain = feats["grain"][:len(pts)]
    knot = feats["knot"].reshape(len(SUBSURFACE_MM) + 1, len(pts)) > 0.5
    pith = _pith(stock.wood, feats["years"].reshape(len(SUBSURFACE_MM) + 1, len(pts)), knot)
    long_axis, ax, elongation = _long_axis(pts)
    end = np.abs(np.einsum("ij,ij->i", grain, nrm)) > math.cos(math.radians(45))
    t = (pts - pts.mean(axis=0)) @ long_axis
    edges = np.quantile(t, np.linspace(0, 1, REPORT_REGIONS + 1))
    region = np.clip(np.searchsorted(edges, t, side="right") - 1, 0, REPORT_REGIONS - 1)
    regions, warnings = [], []
    names = (f"{AXIS_ENDS[ax][0]} third", "middle third", f"{AXIS_ENDS[ax][1]} third")
    for r in range(REPORT_REGIONS):
        sel = region == r
        g = grain[sel].mean(axis=0)
        g /= max(np.linalg.norm(g), 1e-12)
        angle = float(np.degrees(np.arccos(min(1.0, abs(float(g @ long_axis))))))
        k = float(knot[:, sel].mean())
        regions.append({"region": names[r], "grain": [round(float(v), 4) for v in g],
                        "runout_deg": round(angle, 1), "knots": round(k, 4)})
        if elongation > 0.5 and angle > SHORT_GRAIN_DEG:
            warnings.append(f"short grain in the {names[r]} along the part: fibres cross its "
                            f"long axis at {angle:.0f} deg (a thin section there may break)")
    if knot[0].any():
        warnings.append(f"knots show on {100 * knot[0].mean():.1f} % of the surface")
    elif knot.any():
        warnings.append(_subsurface_knot_warning("mm"))
    if pith.any():
        warnings.append(f"the pith (within {PITH_YEARS:g} years) reaches the part: expect checks")
    volume = float(abs(mesh.volume))
    block = float(np.prod(stock.size_mm))
    # the mesh's volume as the bake's summary prints it (PartPreview.volume_mm3, the same mesh):
    # to 7 significant digits, not to 0.1 mm^3, which moved a 1.53 mm^3 part by 2 % ("9.154e-05
    # in^3" in the report under "9.337e-05 in^3" in the summary)
    return {"volume_mm3": float(f"{volume:.7g}"), "yield": round(volume / block, 4),
            "knots": round(float(knot.mean()), 4), "knots_surface": round(float(knot[0].mean()), 4),
            "pith": round(float(pith.mean()), 4),
            "end_grain": round(float(end.mean()), 4), "elongation": round(elongation, 3),
            "regions": regions, "warnings": warnings}


def _subsurface_knot_warning(units: Units) -> str:
    return f"a knot lies {fmt_span(*SUBSURFACE_MM, units)} under the surface (it may show after sanding)"


def report_text(report: dict, name: str, units: Units = "mm") -> str:
    """The part report as a few lines of text; the volume and the depths under the surface
    (:data:`SUBSURFACE_MM`) in ``units``."""
    under = f"the wood {fmt_span(*SUBSURFACE_MM, units)} under it"
    # the surface's knot share first: the warning below quotes it, and the one number counting
    # the wood under the surface too read as a contradiction of it (knots 19.8 % beside "knots
    # show on 15.3 % of the surface")
    knots = f"{100 * report['knots']:.1f} %"
    if "knots_surface" in report:  # reports written before it had the one number
        knots = f"{100 * report['knots_surface']:.1f} % of the surface ({knots} with {under})"
    lines = [f"{name}: {fmt_volume(report['volume_mm3'], units)}, yield {100 * report['yield']:.1f} % of "
             f"the block; end grain {100 * report['end_grain']:.0f} % of the surface; knots "
             f"{knots}, pith {100 * report['pith']:.1f} % of the surface and {under}"]
    for r in report["regions"]:
        lines.append(f"  {r['region']:<13} grain ({', '.join(f'{v:+.2f}' for v in r['grain'])}) "
                     f"runout {r['runout_deg']:.0f} deg, knots {100 * r['knots']:.1f} % with "
                     f"{under}")  # not the surface share the first line leads with
    # part_report writes its one warning with a length in mm (a report file keeps mm): it is said
    # in ``units`` here; the library's warnings (the carve's) come in the message units already
    # in the report a bake returns, in mm in its files (woodcam.units.said / filed)
    lines += [f"  warning: {_subsurface_knot_warning(units) if w == _subsurface_knot_warning('mm') else w}"
              for w in report["warnings"]]
    return "\n".join(lines)


def report_rows(report: dict, units: Units = "mm") -> dict[str, str]:
    """:func:`report_text`'s lines as label -> text rows (the review page's table): "part",
    one per region, then "warning 1", "warning 2", ..."""
    first, *rest = report_text(report, "", units).splitlines()
    rows = {"part": first.removeprefix(": ")}
    for r, line in zip(report["regions"], rest):
        rows[r["region"]] = line.strip().removeprefix(r["region"]).strip()
    rows.update({f"warning {i}": w for i, w in enumerate(report["warnings"], 1)})
    return rows


def knot_spots(mesh, wood, *, samples: int = 20000, link_mm: float = 2.0, seed: int = 0) -> list[dict]:
    """Where knots come through the surface of ``mesh`` (block frame, mm): one entry per
    connected patch of knot wood, ``{"kind": "knot", "label": str, "at_mm": [x, y, z]}`` (the
    patch's centroid, snapped to the nearest surface sample), largest first; for hotspots."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    features = _features_of(wood, "knot_spots", "wood")
    rng = np.random.default_rng(seed)
    pts, _ = _sample(mesh, samples, rng)
    inside = features(pts)["knot"] > 0.5
    p = pts[inside]
    if len(p) == 0:
        return []
    pairs = cKDTree(p).query_pairs(link_mm, output_type="ndarray")
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(p), len(p)))
    n, label = connected_components(graph, directed=False)
    area_per_sample = float(mesh.area) / samples
    spots = []
    for k in range(n):
        members = p[label == k]
        if len(members) < 5:  # a few stray samples: not a visible knot
            continue
        centre = members.mean(axis=0)
        at = members[np.argmin(np.linalg.norm(members - centre, axis=1))]
        spots.append({"kind": "knot", "at_mm": [round(float(v), 2) for v in at],
                      "label": f"through the surface, ~{len(members) * area_per_sample:.0f} mm^2",
                      "_size": len(members)})
    spots.sort(key=lambda s: -s["_size"])
    for s in spots:
        del s["_size"]
    return spots
