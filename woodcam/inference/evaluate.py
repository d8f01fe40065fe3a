"""Ring-line accuracy on interior cut planes: the metric of seed 000's Table 1 (section 4.3).

On a planar cut through the block, the *true* ring lines are the integer iso-lines of the true
growth field and the *predicted* ones those of a fitted field. The seed reports "the percentage
of points on the inferred annual rings within 1.0 and 2.0 mm from the ground truth", with rings
labelled by year. Here points are sampled every ``step_mm`` along the predicted lines and each is
counted as a hit when it lies within the threshold of the true line of the *same year*
(``matched``) or of *any* true line (``unmatched``, the looser reading). ``coverage`` is the
reverse share: true-line points within 1 mm of the predicted line of the same year, so a fit
that draws only a few, correct rings cannot score well unnoticed.

Cut planes are given by a block-frame point and a normal; each is sampled on a square grid of
``pixel_mm`` (0.1 mm by default) clipped to the block.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING
from dataclasses import dataclass, field as dc_field

import numpy as np

from .._atomic import output_folder, write_figure, write_text
from .._checks import check_bool, check_names, check_number, check_path
from .._repr import summary_repr
from .._types import ArrayLike, GrowthFieldLike, PathLike
from ..errors import WoodcamError, require
from ..fields.base import evaluate, has_uncertainty
from ..frames import check_size
from ..tolerances import EVAL_PIXEL_MM, EVAL_THRESHOLDS_MM
from ..fields.rings import ring_lines as _ring_lines

if TYPE_CHECKING:
    from ..block import Block


@dataclass(frozen=True)
class CutPlane:
    """A planar cut: passes through ``point`` (fractions of the block size) with normal ``normal``."""

    name: str
    point: tuple[float, float, float]
    normal: tuple[float, float, float]


#: Seven interior cuts of different orientations: the three axis planes off-centre and four
#: oblique planes, so a straight pith along any block axis is cut across, along and obliquely.
DEFAULT_PLANES: tuple[CutPlane, ...] = (
    CutPlane("z=0.5", (0.5, 0.5, 0.5), (0, 0, 1)),
    CutPlane("x=0.35", (0.35, 0.5, 0.5), (1, 0, 0)),
    CutPlane("y=0.65", (0.5, 0.65, 0.5), (0, 1, 0)),
    CutPlane("xy-diag", (0.5, 0.5, 0.5), (1, 1, 0)),
    CutPlane("xz-diag", (0.45, 0.5, 0.55), (1, 0, -1)),
    CutPlane("yz-diag", (0.5, 0.55, 0.45), (0, 1, 1)),
    CutPlane("xyz", (0.5, 0.5, 0.5), (1, 1, 1)),
)


@dataclass
class PlaneSample:
    """A cut plane sampled on a grid: ``points_mm (nr, nc, 3)`` and ``inside (nr, nc) bool``."""

    plane: CutPlane
    points_mm: np.ndarray
    inside: np.ndarray
    pixel_mm: float


def sample_plane(plane: CutPlane, size_mm, pixel_mm: float = EVAL_PIXEL_MM) -> PlaneSample:
    """Grid of block points on ``plane`` covering its intersection with the block."""
    size = check_size(size_mm)
    n = np.asarray(plane.normal, float)
    n /= np.linalg.norm(n)
    c = np.asarray(plane.point, float) * size
    helper = np.eye(3)[int(np.argmin(np.abs(n)))]
    e1 = np.cross(n, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    # Intersections of the 12 block edges with the plane bound the cut polygon.
    corners = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], float) * size
    hits = []
    for a in range(8):
        for b in range(a + 1, 8):
            if np.count_nonzero(corners[a] != corners[b]) != 1:
                continue
            da, db = (corners[a] - c) @ n, (corners[b] - c) @ n
            if da * db <= 0 and da != db:
                hits.append(corners[a] + (corners[b] - corners[a]) * da / (da - db))
    if len(hits) < 3:
        raise WoodcamError(f"cut plane {plane.name!r} does not cross the block {tuple(size)}")
    st = (np.asarray(hits) - c) @ np.stack([e1, e2]).T
    lo, hi = st.min(0), st.max(0)
    s = np.arange(lo[0], hi[0] + pixel_mm, pixel_mm)
    t = np.arange(lo[1], hi[1] + pixel_mm, pixel_mm)
    S, T = np.meshgrid(s, t, indexing="ij")
    pts = c + S[..., None] * e1 + T[..., None] * e2
    eps = 1e-9
    inside = np.all((pts >= -eps) & (pts <= size + eps), axis=-1)
    return PlaneSample(plane, pts, inside, pixel_mm)


def ring_lines(years_img: np.ndarray, inside: np.ndarray, pixel_mm: float, step_mm: float):
    """Integer iso-lines of a growth-time image, resampled every ``step_mm``
    (:func:`woodcam.fields.rings.ring_lines`).

    Returns
    -------
    points : (m, 2) float, plane coordinates in mm (row, col) * pixel_mm
    years : (m,) int, the year of the line each point is on
    """
    return _ring_lines(years_img, step_mm, inside=inside, spacing=pixel_mm)


def _nearest_distance(query, qyears, ref, ryears, match_years: bool) -> np.ndarray:
    from scipy.spatial import cKDTree

    d = np.full(len(query), np.inf)
    if not len(query) or not len(ref):
        return d
    if not match_years:
        return cKDTree(ref).query(query)[0]
    for y in np.unique(qyears):
        q, r = qyears == y, ryears == y
        if r.any():
            d[q] = cKDTree(ref[r]).query(query[q])[0]
    return d


@dataclass
class PlaneScore:
    """Distances for one plane and one fitted field (mm; inf where no true line of that year)."""

    __repr__ = summary_repr  # arrays as shapes: a notebook shows one line

    plane: str
    d_matched: np.ndarray
    d_unmatched: np.ndarray
    d_coverage: np.ndarray
    lines: dict = dc_field(default_factory=dict, repr=False)
    #: (m,) confidence in [0, 1] of the fit at its predicted-line points (parallel to
    #: ``d_matched``), or None when the fit carries no uncertainty (issue 12 part 5)
    confidence: np.ndarray | None = dc_field(default=None, repr=False)
    #: (nr, nc) confidence image of the plane (NaN outside the block), kept with ``keep_lines``
    confidence_img: np.ndarray | None = dc_field(default=None, repr=False)
    pixel_mm: float = EVAL_PIXEL_MM     # grid step of ``confidence_img``


def score_plane(true_field, fitted_field, sample: PlaneSample, step_mm: float | None = None,
                keep_lines: bool = False, true_lines=None) -> PlaneScore:
    """Compare ring lines of ``fitted_field`` with those of ``true_field`` on one sampled plane.

    ``true_lines`` may pass the true lines ``(points, years)`` precomputed by
    :func:`plane_lines` when several fields are scored on one plane.
    """
    tp, ty = plane_lines(true_field, sample, step_mm) if true_lines is None else true_lines
    pp, py = plane_lines(fitted_field, sample, step_mm)
    s = PlaneScore(
        sample.plane.name,
        _nearest_distance(pp, py, tp, ty, True),
        _nearest_distance(pp, py, tp, ty, False),
        _nearest_distance(tp, ty, pp, py, True),
    )
    if keep_lines:
        s.lines = {"true": (tp, ty), "fit": (pp, py)}
    if has_uncertainty(fitted_field):
        from .evidence import confidence

        s.confidence = confidence(fitted_field.uncertainty_years(_plane_points(sample, pp)))
        if keep_lines:
            img = np.full(sample.inside.shape, np.nan)
            img[sample.inside] = confidence(fitted_field.uncertainty_years(sample.points_mm[sample.inside]))
            s.confidence_img, s.pixel_mm = img, sample.pixel_mm
    return s


def _plane_points(sample: PlaneSample, plane_mm: np.ndarray) -> np.ndarray:
    """Block points ``(m, 3)`` of plane coordinates ``(m, 2)`` mm (row, col) of ``sample``
    (the sample grid is affine in its indices)."""
    p = sample.points_mm
    o = p[0, 0]
    dr = p[1, 0] - o if p.shape[0] > 1 else np.zeros(3)
    dc = p[0, 1] - o if p.shape[1] > 1 else np.zeros(3)
    ij = np.asarray(plane_mm, float).reshape(-1, 2) / sample.pixel_mm
    return o + ij[:, :1] * dr + ij[:, 1:] * dc


def plane_lines(field, sample: PlaneSample, step_mm: float | None = None):
    """Ring lines ``(points (m, 2) mm, years (m,))`` of ``field`` on a sampled plane."""
    step = sample.pixel_mm if step_mm is None else step_mm
    g = evaluate(field, sample.points_mm.reshape(-1, 3)).reshape(sample.inside.shape)
    bad = int(np.sum(~np.isfinite(g[sample.inside])))
    if bad:  # NaN years were int()'s ValueError in the iso-line tracer
        raise WoodcamError(f"field must give finite years in the block; it gave {bad} NaN/inf of "
                           f"{int(sample.inside.sum())} points of cut plane {sample.plane.name!r}")
    return ring_lines(g, sample.inside, sample.pixel_mm, step)


def summarise(scores: list[PlaneScore], thresholds=EVAL_THRESHOLDS_MM) -> dict:
    """Pool the points of several planes: percentages within each threshold.

    Returns a dict with ``matched_<t>``, ``unmatched_<t>`` (percent of predicted-line points) for
    each threshold ``t`` in mm, ``coverage_1`` (percent of true-line points within 1 mm of the
    same-year predicted line) and ``n_points``.
    """
    dm = np.concatenate([s.d_matched for s in scores]) if scores else np.empty(0)
    du = np.concatenate([s.d_unmatched for s in scores]) if scores else np.empty(0)
    dc = np.concatenate([s.d_coverage for s in scores]) if scores else np.empty(0)
    out = {"n_points": int(len(dm))}
    for t in thresholds:
        out[f"matched_{t:g}"] = 100.0 * np.mean(dm <= t) if len(dm) else 0.0
        out[f"unmatched_{t:g}"] = 100.0 * np.mean(du <= t) if len(du) else 0.0
    out["coverage_1"] = 100.0 * np.mean(dc <= 1.0) if len(dc) else 0.0
    if scores and all(s.confidence is not None for s in scores):
        out.update(confidence_summary(np.concatenate([s.confidence for s in scores]), dm))
    return out


#: A predicted-line point is "confident" at or above this :func:`~.evidence.confidence`
#: (an uncertainty of about 0.4 year): the split of :func:`confidence_summary`.
CONFIDENT_AT = 0.5


def confidence_summary(conf: np.ndarray, d_matched: np.ndarray) -> dict:
    """Does the fit know where it is wrong? ``conf (m,)`` confidence and ``d_matched (m,)`` mm
    error of the same predicted-line points. Returns ``confidence_mean``, ``confident_share``
    (percent of points with confidence >= :data:`CONFIDENT_AT`) and ``matched_2_confident`` /
    ``matched_2_unsure`` (percent within 2 mm among those points and the others; NaN for an
    empty side): a useful confidence has the first well above the second."""
    conf, d = np.asarray(conf, float), np.asarray(d_matched, float)
    sure = conf >= CONFIDENT_AT

    def share(sel):
        return float(100.0 * np.mean(d[sel] <= 2.0)) if sel.any() else float("nan")

    return {"confidence_mean": float(conf.mean()) if len(conf) else float("nan"),
            "confident_share": float(100.0 * sure.mean()) if len(conf) else float("nan"),
            "matched_2_confident": share(sure), "matched_2_unsure": share(~sure)}


def evaluate_fit(true_field: GrowthFieldLike, fitted_field: GrowthFieldLike, size_mm: ArrayLike,
                 planes: Sequence[CutPlane] = DEFAULT_PLANES, pixel_mm: float = EVAL_PIXEL_MM,
                 keep_lines: bool = False) -> tuple[dict, list[PlaneScore]]:
    """Table-1 accuracy of ``fitted_field`` against ``true_field`` on ``planes`` of a block.

    Parameters
    ----------
    true_field, fitted_field : growth fields
        Block-frame points ``(n, 3)`` mm -> ``years (n,)``.
    size_mm : (3,) float
        The block's W, D, H (mm); the planes' points are fractions of it.
    planes : sequence of CutPlane
        The cuts scored (default :data:`DEFAULT_PLANES`, seven).
    pixel_mm : float
        Sample spacing on each cut plane, mm.
    keep_lines : bool
        Keep each plane's ring lines in its score (for pictures).

    Returns
    -------
    summary : dict (see :func:`summarise`)
    scores : list of PlaneScore, one per plane
    """
    return evaluate_fits(true_field, {"fit": fitted_field}, size_mm, planes, pixel_mm, keep_lines)["fit"]


def evaluate_fits(true_field: GrowthFieldLike, fitted: dict[str, GrowthFieldLike], size_mm: ArrayLike,
                  planes: Sequence[CutPlane] = DEFAULT_PLANES, pixel_mm: float = EVAL_PIXEL_MM,
                  keep_lines: bool = False) -> dict[str, tuple[dict, list[PlaneScore]]]:
    """:func:`evaluate_fit` for several fields (dict name -> field) sharing the true lines.

    ``true_field`` and each field of ``fitted``: ``(n, 3) mm (block frame) -> (n,) years``;
    ``size_mm``: the block's ``(W, D, H)`` mm; ``planes``: the cut planes (default
    :data:`DEFAULT_PLANES`), sampled every ``pixel_mm`` mm (default 0.1); ``keep_lines``: keep
    each plane's ring lines in its :class:`PlaneScore` (for :func:`plot_planes`).

    Returns dict name -> ``(summary, scores)``.
    """
    # pixel_mm=0 or NaN was np.arange's ValueError, a plane that is not a CutPlane an AttributeError
    pixel_mm = check_number(pixel_mm, "pixel_mm", lo=0, lo_open=True,
                            fix=f"the cut planes' sample spacing in mm, e.g. {EVAL_PIXEL_MM}")
    keep_lines = check_bool(keep_lines, "keep_lines")
    check_size(size_mm)
    try:  # [] scored no plane and returned 0 % everywhere, as if no ring were missed
        plane_list = [] if isinstance(planes, (str, CutPlane)) else list(planes)
    except TypeError:
        plane_list = []
    if not plane_list:
        raise WoodcamError(f"planes must be a non-empty list of CutPlanes; got {planes!r:.60}; e.g. "
                           "[CutPlane('z=0.5', (0.5, 0.5, 0.5), (0, 0, 1))] or leave planes out for the seven of "
                           "Table 1")
    planes = plane_list
    for p in planes:
        if not isinstance(p, CutPlane):
            raise WoodcamError(f"planes must be CutPlanes; got {p!r:.60}; e.g. CutPlane('z=0.5', (0.5, 0.5, 0.5), "
                               "(0, 0, 1)) or leave planes out for the seven of Table 1")
    out = {name: [] for name in fitted}
    for p in planes:
        sample = sample_plane(p, size_mm, pixel_mm)
        truth = plane_lines(true_field, sample)
        for name, f in fitted.items():
            out[name].append(score_plane(true_field, f, sample, keep_lines=keep_lines, true_lines=truth))
    return {name: (summarise(sc), sc) for name, sc in out.items()}


def benchmark(blocks: Sequence[Block], methods: Sequence[str] = ("rbf", "radial"),
              face_sets: dict[str, Sequence[str] | None] | None = None, out_dir: PathLike | None = None,
              planes: Sequence[CutPlane] = DEFAULT_PLANES, pixel_mm: float = EVAL_PIXEL_MM,
              progress: Callable[[str], object] | None = None, confidence: bool = False) -> dict:
    """Fit every block with every method and face set, score them on the cut planes.

    Parameters
    ----------
    blocks : list of Block, each with a ``true_field``
    methods : fitting methods (see :data:`woodcam.inference.fit.METHODS`)
    face_sets : dict label -> list of faces or None (all); default ``{"full": None}``
    planes : cut planes to score on (:class:`CutPlane`, points as fractions of the block
        size; default :data:`DEFAULT_PLANES`)
    pixel_mm : sample spacing on each plane, mm (default 0.1, :data:`woodcam.tolerances.EVAL_PIXEL_MM`)
    out_dir : folder for ``table.md`` and one PNG per block and face set (predicted vs true
        ring lines on every plane); nothing is written when None.
    progress : optional callable taking one line of text per fit.
    confidence : draw the fits' per-point confidence under their lines in the PNGs
        (:func:`plot_planes`); the table gets the confidence summary of the methods whose fits
        carry one (:func:`confidence_summary`) either way.

    Returns
    -------
    dict face-set label -> list of rows ``{"name": block name, method: summary + fit_s}`` plus
    ``"table"``: the markdown text.
    """
    import time
    from pathlib import Path

    from ..block.block import Block
    from .fit import METHODS, fit_block

    confidence = check_bool(confidence, "confidence")
    # [] was an IndexError at the mean row, None a TypeError; methods [] a table of no method
    try:
        block_list = [] if isinstance(blocks, (str, Block)) else list(blocks)
    except TypeError:
        block_list = []
    if not block_list or not all(isinstance(b, Block) for b in block_list):
        raise WoodcamError(f"blocks must be a non-empty list of woodcam.block.Block; got {blocks!r:.60}; "
                           "e.g. [synth_block(...)] or [read_block('BLOCK')] with a true_field")
    blocks = block_list
    methods = check_names(methods, "methods", what="method names", known=METHODS)
    if face_sets is not None and not isinstance(face_sets, dict):
        raise WoodcamError(f"face_sets must be a dict label -> list of faces (or None for all), or None; "
                           f"got {type(face_sets).__name__}; e.g. {{'full': None, 'top+front': ['top', 'front']}}")
    if out_dir is not None:  # a file there was a FileExistsError after the first block's fits
        output_folder(check_path(out_dir, "out_dir"), "benchmark: out_dir", make=False)
    face_sets = {"full": None} if face_sets is None else face_sets
    result, tables = {}, []
    for label, faces in face_sets.items():
        rows = []
        for b in blocks:
            if b.true_field is None:
                raise WoodcamError(
                    f"block {b.name!r} has no true_field; evaluation needs the true growth field "
                    f"(a synthetic block, or pass --truth FIELD_FILE)"
                )
            fields, times = {}, {}
            for m in methods:
                t0 = time.perf_counter()
                fields[m] = fit_block(b, m, faces=faces)
                times[m] = time.perf_counter() - t0
            scored = evaluate_fits(b.true_field, fields, b.size_mm, planes, pixel_mm,
                                   keep_lines=out_dir is not None)
            row = {"name": b.name}
            for m in methods:
                row[m] = dict(scored[m][0], fit_s=times[m])
            rows.append(row)
            if progress:
                progress(f"{label} {b.name}: " + ", ".join(
                    f"{m} {row[m]['matched_1']:.1f}/{row[m]['matched_2']:.1f}% {times[m]:.1f}s" for m in methods))
            if out_dir is not None:
                output_folder(out_dir, "benchmark: out_dir")
                plot_planes(Path(out_dir) / f"{b.name}_{label}.png", {m: scored[m][1] for m in methods},
                            title=f"{b.name} ({label}): black = true rings, colour = fitted",
                            confidence=confidence)
        mean = {"name": "**mean**"}
        for m in methods:
            keys = rows[0][m].keys()
            mean[m] = {k: _finite_mean([r[m][k] for r in rows]) for k in keys}
        rows.append(mean)
        result[label] = rows
        tables.append(f"### {label} ({'all faces' if faces is None else ', '.join(faces)})\n\n"
                      + markdown_table(rows, list(methods)) + _confidence_table(rows, list(methods)))
    result["table"] = "\n\n".join(tables) + "\n"
    if out_dir is not None:
        write_text(Path(out_dir) / "table.md", result["table"])
    return result


#: The key of :func:`plot_planes`' panels, drawn under its title: a panel's 'radial z=0.5 /
#: 100% <1mm' said neither that the plane's numbers are fractions of the block nor what the % counts.
PLANES_KEY = ("plane through the point at these fractions of the block's width x, depth y, height z "
              "(diag: oblique);\n% of fitted ring-line points within 1 mm of the true line of the same year")


def plot_planes(path, scores_by_method: dict, title: str = "", confidence: bool = False):
    """Save a PNG: for each plane, true ring lines (black) under each method's lines (colour).

    scores_by_method : dict method -> list of PlaneScore made with ``keep_lines=True``.
    confidence : draw each fit's confidence under its lines where it carries one (red unsure,
        yellow, green sure: as ``woodcam preview --confidence``), with the within-2 mm shares of
        its confident and unsure line points in the title.
    """
    matplotlib = require("matplotlib", "view", "drawing cut-plane ring images")
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    methods = list(scores_by_method)
    n_planes = len(next(iter(scores_by_method.values())))
    fig, axes = plt.subplots(len(methods), n_planes, figsize=(2.6 * n_planes, 2.8 * len(methods)),
                             squeeze=False)
    colours = ["tab:red", "tab:blue", "tab:green", "tab:orange"]
    for r, m in enumerate(methods):
        for c, s in enumerate(scores_by_method[m]):
            ax = axes[r, c]
            tp, _ = s.lines["true"]
            pp, _ = s.lines["fit"]
            label = ""
            if confidence and s.confidence_img is not None:
                h, w = s.confidence_img.shape  # extent in plane mm, so the lines sit on it
                ax.imshow(s.confidence_img, cmap="RdYlGn", vmin=0, vmax=1, interpolation="nearest",
                          extent=(0, (w - 1) * s.pixel_mm, (h - 1) * s.pixel_mm, 0))
                cs = confidence_summary(s.confidence, s.d_matched)
                label = (f"\nsure {cs['confident_share']:.0f}%: {cs['matched_2_confident']:.0f}% / "
                         f"unsure {cs['matched_2_unsure']:.0f}% <2mm")
            ax.plot(tp[:, 1], tp[:, 0], ",", color="k", alpha=0.6)
            ax.plot(pp[:, 1], pp[:, 0], ",", color=colours[r % len(colours)])
            ok = np.mean(s.d_matched <= 1.0) * 100 if len(s.d_matched) else 0.0
            ax.set_title(f"{m} {s.plane}\n{ok:.0f}% <1mm{label}", fontsize=8)
            ax.set_aspect("equal")
            ax.invert_yaxis()
            ax.set_xticks([])
            ax.set_yticks([])
    fig.suptitle(f"{title}\n{PLANES_KEY}" if title else PLANES_KEY, fontsize=9)
    fig.tight_layout()
    write_figure(fig, path, dpi=110)
    plt.close(fig)
    return path


def _finite_mean(values) -> float:
    """Mean of the finite values (NaN when none: e.g. no unsure points on any block)."""
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    return float(v.mean()) if len(v) else float("nan")


def _confidence_table(rows: list[dict], methods: list[str]) -> str:
    """Markdown lines of :func:`confidence_summary` per block for the methods that carry one."""
    with_conf = [m for m in methods if "confidence_mean" in rows[0][m]]
    if not with_conf:
        return ""
    head = ["block", "method", "mean confidence", "confident points %", "≤2 mm, confident", "≤2 mm, unsure"]
    lines = ["", "", "Confidence on the predicted ring lines (confident at >= "
             f"{CONFIDENT_AT:g}):", "", "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for row in rows:
        for m in with_conf:
            c = row[m]
            lines.append(f"| {row['name']} | {m} | {c['confidence_mean']:.2f} | {c['confident_share']:.1f} | "
                         f"{c['matched_2_confident']:.1f} | {c['matched_2_unsure']:.1f} |")
    return "\n".join(lines)


def markdown_table(rows: list[dict], methods: list[str], thresholds=EVAL_THRESHOLDS_MM) -> str:
    """Markdown table: one row per entry of ``rows`` (dict with ``name`` and ``method -> summary``),
    columns: for each threshold, each method, year-matched then unmatched, then coverage."""
    head = ["block"]
    for kind in ("matched", "unmatched"):
        for t in thresholds:
            head += [f"{m} {kind} {t:g} mm" for m in methods]
    head += [f"{m} coverage 1 mm" for m in methods] + [f"{m} fit s" for m in methods]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for row in rows:
        cells = [str(row["name"])]
        for kind in ("matched", "unmatched"):
            for t in thresholds:
                vals = [row[m][f"{kind}_{t:g}"] for m in methods]
                best = max(vals)
                cells += [(f"**{v:.1f}**" if v == best and len(methods) > 1 else f"{v:.1f}") for v in vals]
        cells += [f"{row[m]['coverage_1']:.1f}" for m in methods]
        cells += [f"{row[m].get('fit_s', float('nan')):.2f}" for m in methods]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)
