"""Leave-one-face-out scoring of growth-field fits against real ring maps (issue 5, part 6).

A real block's inside is unknown, but each face's ring map is an independent measurement: fit on
five faces, predict the sixth, and compare the predicted ring lines (integer iso-lines of the
fitted growth time on that face) with the ring map's ridge (the one-pixel skeleton of its bright
ring boundaries). Two shares, in pixels of the face image, both higher-is-better:

- ``ridge_k``: ring-map ridge pixels within ``k`` px of a predicted ring line (are the real rings
  predicted?);
- ``line_k``: points on the predicted ring lines within ``k`` px of a ridge pixel (are the
  predicted rings real?).

``k`` = 1, 2 px (the issue's measure) and 5 px (~1 mm on a 256 px face of a 50 mm cube). Neither
needs year numbers (ring maps have none). Pixels on or near a knot mask are left out of
both, as they are left out of the fit (:data:`~woodcam.tolerances.KNOT_MASK_MARGIN_MM`). The same
scores for a fit on all six faces (the face is then part of the fit) bound what the ring maps'
own noise allows, and the held-out predictions moved by half a ring give the chance level.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING
import time
from dataclasses import dataclass, field as dc_field

import numpy as np

from .._atomic import output_folder, write_figure, write_text
from .._types import PathLike
from ..errors import WoodcamError, require
from .._checks import check_bool, check_names, check_path
from ..fields.base import arf, has_uncertainty
from ..fields.rings import ring_lines
from ..frames import face_pixel_points
from ..tolerances import HOLDOUT_LINE_STEP_PX, HOLDOUT_THRESHOLDS_PX, RING_MAP_THRESHOLD
from .fit import METHODS, fit_block
from .observations import _pixel_index, knot_exclusion
from .._types import GrowthFieldLike

if TYPE_CHECKING:
    from ..block import Block

#: Labels in results: the in-sample fit (all faces), and the chance control: every held-out
#: prediction moved by half a ring (right spacing and direction, rings where none are).
ALL_FACES = "all faces"
CONTROL = "held out, moved half a ring (chance)"
#: Issue 12 part 7: straight parallel rings with the held-out prediction's mean orientation and
#: spacing on the face (the least-squares plane of its growth time: fitted from the other faces,
#: like the prediction), at the best of :data:`STRAIGHT_PHASES` phases *chosen by the held-out
#: ring map itself* (so it is phase-free): what a fit scores by getting only orientation and
#: spacing right, with the phase given. A fit gets no such choice, so two more rows make the
#: comparison like for like: :data:`BEST_PHASE` (the prediction with the same choice of phase)
#: and :data:`STRAIGHT_OWN` (the straight rings at the prediction's own phase, the plane
#: unshifted).
STRAIGHT = "straight rings, same orientation and spacing, best phase"
BEST_PHASE = "held out, best phase (as the straight rings)"
STRAIGHT_OWN = "straight rings at the prediction's own phase"
STRAIGHT_PHASES = 10


def straight_rings(years: np.ndarray) -> np.ndarray:
    """The least-squares plane ``a + b row + c col`` through a face's growth time ``(h, w)``:
    straight parallel rings with its mean orientation and spacing."""
    h, w = years.shape
    r, c = np.meshgrid(np.arange(h, dtype=float), np.arange(w, dtype=float), indexing="ij")
    X = np.stack([np.ones(r.size), r.ravel(), c.ravel()], axis=1)
    coef = np.linalg.lstsq(X, years.ravel(), rcond=None)[0]
    return (X @ coef).reshape(h, w)


def _best_phase_score(face, years, ridge, excl, thresholds) -> FaceScore:
    """``years`` shifted by the best of :data:`STRAIGHT_PHASES` phases, judged by the face's own
    ridge pixels within 2 px (the oracle phase of the :data:`STRAIGHT` control)."""
    scores = [_score(face, years + ph, ridge, excl, thresholds)
              for ph in np.arange(STRAIGHT_PHASES) / STRAIGHT_PHASES]
    return max(scores, key=lambda sc: sc.shares.get("ridge_2", 0.0))


def ridge_pixels(ring_map: np.ndarray, threshold: float = RING_MAP_THRESHOLD,
                 exclude: np.ndarray | None = None) -> np.ndarray:
    """Ridge of a ring map: ``(k, 2)`` int pixel ``(row, col)`` of the skeleton of its ring pixels.

    ring_map : (h, w) float in [0, 1], bright on ring boundaries.
    exclude : optional (h, w) bool; ridge pixels there are dropped.
    """
    from skimage import morphology

    skel = morphology.skeletonize(np.asarray(ring_map, float) >= threshold)
    if exclude is not None:
        skel &= ~exclude
    return np.argwhere(skel)


def face_years(field, face: str, shape, size_mm) -> np.ndarray:
    """Growth time ``(h, w)`` of ``field`` at the pixel centres of a face image of ``shape``."""
    pts = face_pixel_points(face, shape, size_mm).reshape(-1, 3)
    return np.asarray(field(pts), float).reshape(shape)


def ring_lines_px(years_img: np.ndarray, step_px: float = HOLDOUT_LINE_STEP_PX,
                  exclude: np.ndarray | None = None) -> np.ndarray:
    """Points ``(m, 2)`` (row, col) every ``step_px`` along the integer iso-lines of ``years_img``
    (:func:`woodcam.fields.rings.ring_lines`).

    exclude : optional (h, w) bool; line points in those pixels are dropped.
    """
    y = np.asarray(years_img, float)
    if not np.isfinite(y).all():
        raise WoodcamError("the fitted growth time is not finite on the face; refit the block")
    pts, _ = ring_lines(y, step_px)
    if exclude is not None and len(pts):
        pts = pts[~exclude[_pixel_index(pts[:, 0], y.shape[0]), _pixel_index(pts[:, 1], y.shape[1])]]
    return pts


def _nearest(query: np.ndarray, ref: np.ndarray) -> np.ndarray:
    from scipy.spatial import cKDTree

    if len(query) == 0:
        return np.zeros(0)
    if len(ref) == 0:
        return np.full(len(query), np.inf)
    return cKDTree(ref).query(query)[0]


@dataclass
class FaceScore:
    """One face's agreement between a ring map and a fitted field's ring lines (see module doc)."""

    face: str
    shares: dict            # "ridge_1", "ridge_2", "line_1", "line_2" -> percent
    n_ridge: int
    n_line: int
    years: np.ndarray       # (h, w) fitted growth time on the face
    ridge: np.ndarray       # (k, 2) ridge pixels
    lines: np.ndarray       # (m, 2) predicted line points
    #: (h, w) confidence in [0, 1] of the fit on the face (:func:`~.evidence.confidence`), or
    #: None when the fit carries no uncertainty (only the evidence fit does)
    confidence_img: np.ndarray | None = dc_field(default=None, repr=False)

    def confidence_summary(self) -> dict | None:
        """:func:`~woodcam.inference.evaluate.confidence_summary` of the predicted line points:
        their confidence against whether a ring-map ridge pixel lies within 2 px of them (does
        the fit know where its held-out rings are wrong?); None without a confidence image."""
        if self.confidence_img is None:
            return None
        from .evaluate import confidence_summary

        h, w = self.confidence_img.shape
        conf = self.confidence_img[_pixel_index(self.lines[:, 0], h), _pixel_index(self.lines[:, 1], w)]
        return confidence_summary(conf, _nearest(self.lines, self.ridge.astype(float)))


def score_face(field: GrowthFieldLike, block: Block, face: str,
               thresholds: Sequence[float] = HOLDOUT_THRESHOLDS_PX) -> FaceScore:
    """Score ``field``'s ring lines on ``face`` of ``block`` against that face's ring map;
    ``thresholds``: the distances (px of the face image) a line may lie from the map's ridges
    and still count (default :data:`~woodcam.tolerances.HOLDOUT_THRESHOLDS_PX`, 1, 2 and 5 px)."""
    excl, ridge = _face_reference(block, face)
    f = block.faces[face]
    return _score(face, face_years(field, face, f.shape, block.size_mm), ridge, excl, thresholds)


def _face_reference(block, face: str):
    """``(knot exclusion or None, ridge pixels (k, 2))`` of a face's ring map: what every
    prediction of that face is scored against (the skeleton is computed once per face)."""
    f = block.faces.get(face)
    if f is None or f.ring_map is None:
        raise WoodcamError(f"face {face!r} of block {block.name!r} has no ring map to score against; "
                           f"score a face that has one")
    excl = knot_exclusion(f, min(block.face_pixel_size_mm(face)))
    return excl, ridge_pixels(f.ring_map, exclude=excl)


def _score(face: str, years: np.ndarray, ridge: np.ndarray, excl, thresholds) -> FaceScore:
    """Shares (module docstring) of the integer iso-lines of ``years (h, w)`` against ``ridge``."""
    lines = ring_lines_px(years, exclude=excl)
    d_ridge = _nearest(ridge.astype(float), lines)
    d_line = _nearest(lines, ridge.astype(float))
    shares = {}
    for t in thresholds:
        shares[f"ridge_{t:g}"] = float(np.mean(d_ridge <= t) * 100) if len(d_ridge) else 0.0
        shares[f"line_{t:g}"] = float(np.mean(d_line <= t) * 100) if len(d_line) else 0.0
    return FaceScore(face, shares, len(ridge), len(lines), years, ridge, lines)


def leave_one_face_out(block: Block, methods: Sequence[str] = ("rbf", "radial"),
                       out_dir: PathLike | None = None,
                       progress: Callable[[str], object] | None = None,
                       reference: Block | None = None, seed: int = 0, confidence: bool = False) -> dict:
    """Fit ``block`` on all faces but one for each face with a ring map, score the held-out face.

    Parameters
    ----------
    block : woodcam.block.Block with ring maps on at least two faces.
    reference : woodcam.block.Block, optional
        Score against this block's ring maps (and knot masks) instead of ``block``'s own: e.g.
        ``block`` holds rings detected on the photos (:mod:`woodcam.detect`) and ``reference``
        the Mokume maps of the same cube.
    methods : fitting methods (:data:`woodcam.inference.fit.METHODS`).
    out_dir : folder for ``{block}_{method}.png`` (per face: photo, ring map, predicted ARF,
        overlay of ridge and predicted lines) and ``{block}_holdout.md``; None writes nothing.
    progress : optional callable taking one line of text per fit.
    seed : the evidence fit's random seed (:func:`~woodcam.inference.fit.fit_block`; other
        methods ignore it): a real cube's held-out score can swing with it (H11, README).
    confidence : draw the held-out fits' per-point confidence under the overlay of each face in
        the PNGs (:func:`plot_holdout`); the table summarises it for the methods whose fits carry
        one (the evidence fit) either way, as :func:`~woodcam.inference.evaluate.benchmark` does.

    Returns
    -------
    dict with ``"held_out"``, :data:`CONTROL`, :data:`STRAIGHT`, :data:`BEST_PHASE`,
    :data:`STRAIGHT_OWN` and ``"all faces"``: each ``method -> list of FaceScore``;
    ``"fit_s"``: method -> mean held-out fit seconds; ``"table"``: markdown text.
    """
    from ..block.block import Block

    for name, b in (("block", block), ("reference", reference)):  # None was an AttributeError ('faces')
        if not isinstance(b, Block) and not (name == "reference" and b is None):
            raise WoodcamError(f"{name} must be a woodcam.block.Block; got {type(b).__name__}; pass read_block(...)"
                               + (" or None" if name == "reference" else ""))
    # 'radial' was read letter by letter ("method must be ...; got 'r'"), [] an IndexError at the table
    methods = check_names(methods, "methods", what="method names", known=METHODS)
    if progress is not None and not callable(progress):
        raise WoodcamError(f"progress must be a callable taking one line of text, or None; "
                           f"got {type(progress).__name__}")
    confidence = check_bool(confidence, "confidence")
    if out_dir is not None:  # a file there was a FileExistsError after all the fits
        output_folder(check_path(out_dir, "out_dir"), "leave_one_face_out: out_dir", make=False)
    ref_block = block if reference is None else reference
    faces = [n for n, f in block.faces.items() if f.has_rings and n in ref_block.faces
             and ref_block.faces[n].ring_map is not None]
    if len(faces) < 2:
        raise WoodcamError(f"block {block.name!r} has ring maps on {faces}; leave-one-face-out needs "
                           f"at least two faces with ring maps")
    refs = {face: _face_reference(ref_block, face) for face in faces}
    held = {m: [] for m in methods}
    control = {m: [] for m in methods}
    straight = {m: [] for m in methods}
    best_phase = {m: [] for m in methods}
    straight_own = {m: [] for m in methods}
    insample = {m: [] for m in methods}
    times = {m: [] for m in methods}
    for m in methods:
        full = fit_block(block, m, seed=seed)
        for face in faces:
            excl, ridge = refs[face]
            t0 = time.perf_counter()
            fit = fit_block(block, m, faces=[f for f in block.faces if f != face], seed=seed)
            times[m].append(time.perf_counter() - t0)
            shape = block.faces[face].shape
            years = face_years(fit, face, shape, block.size_mm)
            held[m].append(_score(face, years, ridge, excl, HOLDOUT_THRESHOLDS_PX))
            if has_uncertainty(fit):  # the evidence fit says where its rings are a guess
                from .evidence import confidence as confidence_of

                pts = face_pixel_points(face, shape, block.size_mm).reshape(-1, 3)
                held[m][-1].confidence_img = confidence_of(fit.uncertainty_years(pts)).reshape(shape)
            control[m].append(_score(face, years + 0.5, ridge, excl, HOLDOUT_THRESHOLDS_PX))
            plane = straight_rings(years)  # the STRAIGHT control at its best phase and at the prediction's own
            straight[m].append(_best_phase_score(face, plane, ridge, excl, HOLDOUT_THRESHOLDS_PX))
            best_phase[m].append(_best_phase_score(face, years, ridge, excl, HOLDOUT_THRESHOLDS_PX))
            straight_own[m].append(_score(face, plane, ridge, excl, HOLDOUT_THRESHOLDS_PX))
            insample[m].append(_score(face, face_years(full, face, shape, block.size_mm), ridge, excl,
                                      HOLDOUT_THRESHOLDS_PX))
            if progress:
                s = held[m][-1].shares
                progress(f"{block.name} {m} hold out {face}: ridge {s['ridge_1']:.0f}/{s['ridge_2']:.0f}%, "
                         f"line {s['line_1']:.0f}/{s['line_2']:.0f}% ({times[m][-1]:.1f} s)")
    res = {"held_out": held, CONTROL: control, STRAIGHT: straight, BEST_PHASE: best_phase,
           STRAIGHT_OWN: straight_own, ALL_FACES: insample,
           "fit_s": {m: float(np.mean(t)) for m, t in times.items()}}
    res["table"] = holdout_table(block.name, res, list(methods))
    if out_dir is not None:
        out = output_folder(out_dir, "leave_one_face_out: out_dir")
        write_text(out / f"{block.name}_holdout.md", res["table"])
        for m in methods:
            plot_holdout(out / f"{block.name}_{m}.png", block, held[m],
                         title=f"{block.name}, {m}: each face predicted from the other five", confidence=confidence)
    return res


def holdout_table(name: str, res: dict, methods: list[str], thresholds=HOLDOUT_THRESHOLDS_PX) -> str:
    """Markdown: one row per held-out face plus the mean, and the mean of the all-faces fit."""
    keys = [f"{k}_{t:g}" for k in ("ridge", "line") for t in thresholds]
    head = ["face"] + [f"{m} {k.replace('_', ' ≤ ')} px" for k in keys for m in methods]
    lines = [f"#### {name}", "", "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]

    def row(label, per_method):
        cells = [label]
        for k in keys:
            vals = [per_method[m][k] for m in methods]
            cells += [f"**{v:.1f}**" if len(methods) > 1 and v == max(vals) else f"{v:.1f}" for v in vals]
        return "| " + " | ".join(cells) + " |"

    held = res["held_out"]
    for i, sc in enumerate(held[methods[0]]):
        lines.append(row(sc.face, {m: held[m][i].shares for m in methods}))
    for label, part in (("**mean, held out**", held), (f"mean, {CONTROL}", res[CONTROL]),
                        (f"mean, {STRAIGHT}", res[STRAIGHT]) if STRAIGHT in res else (None, None),
                        (f"mean, {BEST_PHASE}", res[BEST_PHASE]) if BEST_PHASE in res else (None, None),
                        (f"mean, {STRAIGHT_OWN}", res[STRAIGHT_OWN]) if STRAIGHT_OWN in res else (None, None),
                        (f"mean, {ALL_FACES} (in-sample)", res[ALL_FACES])):
        if label is None:
            continue
        lines.append(row(label, {m: {k: float(np.mean([s.shares[k] for s in part[m]])) for k in keys}
                                 for m in methods}))
    lines.append("")
    lines.append("Mean held-out fit time: " + ", ".join(f"{m} {res['fit_s'][m]:.1f} s" for m in methods))
    sums = {m: [sc.confidence_summary() for sc in held[m]] for m in methods}
    with_conf = [m for m in methods if sums[m] and all(c is not None for c in sums[m])]
    if with_conf:  # as eval rings' cut-plane table: does the fit know where it is wrong?
        from .evaluate import CONFIDENT_AT

        head = ["face", "method", "mean confidence", "confident points %", "≤2 px, confident", "≤2 px, unsure"]
        lines += ["", f"Confidence on the held-out predicted ring lines (confident at >= {CONFIDENT_AT:g}; "
                  "line points within 2 px of a ring-map ridge pixel):", "",
                  "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        for m in with_conf:
            for sc, c in zip(held[m], sums[m]):
                lines.append(f"| {sc.face} | {m} | {c['confidence_mean']:.2f} | {c['confident_share']:.1f} | "
                             f"{c['matched_2_confident']:.1f} | {c['matched_2_unsure']:.1f} |")
    return "\n".join(lines) + "\n"


#: The key of :func:`plot_holdout`'s overlay and the shares under it, drawn under its title: the
#: PNG said none of it (what blue and red are, what "ridge 8/13%" counts).
HOLDOUT_KEY = ("overlay: grey ring map, blue its ridge, red the predicted ring lines, yellow round the knots "
               "(not scored)\nunder it: % of ridge / line points within 1 / 2 px of the other")


#: :func:`plot_holdout`'s column titles, in words: the third said "predicted ARF" (the
#: annual-ring field of eq. 6, (years mod 1)^2, a name from the papers no reader of the picture knows)
HOLDOUT_COLUMNS = ("photo", "ring map", "predicted rings (annual-ring field)", "overlay")


def plot_holdout(path, block, scores: list[FaceScore], title: str = "", confidence: bool = False):
    """PNG, one row per face: photo, ring map, predicted ARF (eq. 6), overlay (grey ring map,
    blue ridge pixels, red predicted ring lines, knot margin hatched out).

    confidence : draw the fit's confidence under the overlay where it carries one (red unsure,
        yellow, green sure: as the cut planes of :func:`~woodcam.inference.evaluate.plot_planes`),
        with the within-2 px shares of its confident and unsure line points under it."""
    matplotlib = require("matplotlib", "view", "drawing leave-one-face-out images")
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(scores), 4, figsize=(8.4, 2.2 * len(scores)), squeeze=False)
    for r, sc in enumerate(scores):
        f = block.faces[sc.face]
        panels = list(zip((f.photo, f.ring_map, arf(sc.years), f.ring_map), HOLDOUT_COLUMNS,
                          (None, "gray", "gray", "gray")))
        for c, (img, label, cmap) in enumerate(panels):
            ax = axes[r, c]
            if img is None:
                ax.text(0.5, 0.5, "no photo", ha="center", va="center")
            else:
                ax.imshow(img, cmap=cmap, vmin=0, vmax=1 if cmap else None,
                          alpha=0.5 if c == 3 else 1.0, interpolation="nearest")
            ax.set_xticks([])
            ax.set_yticks([])
            if c == 0:
                ax.set_ylabel(sc.face, fontsize=8)
            if r == 0:
                ax.set_title(label, fontsize=8)
        ax = axes[r, 3]
        label = ""
        if confidence and sc.confidence_img is not None:
            ax.imshow(sc.confidence_img, cmap="RdYlGn", vmin=0, vmax=1, interpolation="nearest", zorder=0)
            cs = sc.confidence_summary()
            label = (f"\nsure {cs['confident_share']:.0f}%: {cs['matched_2_confident']:.0f}% / "
                     f"unsure {cs['matched_2_unsure']:.0f}% line <2px")
            if r == 0:
                ax.set_title("overlay on confidence", fontsize=8)
        ax.plot(sc.ridge[:, 1], sc.ridge[:, 0], ",", color="tab:blue")
        ax.plot(sc.lines[:, 1], sc.lines[:, 0], ",", color="tab:red")
        excl = knot_exclusion(f, min(block.face_pixel_size_mm(sc.face)))
        if excl is not None:
            ax.contour(excl, levels=[0.5], colors="yellow", linewidths=0.6)
        s = sc.shares
        ax.set_xlabel(f"ridge {s['ridge_1']:.0f}/{s['ridge_2']:.0f}%  line {s['line_1']:.0f}/{s['line_2']:.0f}%"
                      + label, fontsize=7)
        ax.set_xlim(0, f.shape[1] - 1)
        ax.set_ylim(f.shape[0] - 1, 0)
    key = HOLDOUT_KEY + (" (confidence under it: red unsure, green sure)" if confidence else "")
    fig.suptitle(f"{title}\n{key}" if title else key, fontsize=7 if not title else 8)
    fig.tight_layout()
    write_figure(fig, path, dpi=100)
    plt.close(fig)
    return path


__all__ = ["ALL_FACES", "BEST_PHASE", "CONTROL", "HOLDOUT_COLUMNS", "STRAIGHT", "STRAIGHT_OWN", "FaceScore",
           "face_years", "holdout_table",
           "leave_one_face_out", "plot_holdout", "ridge_pixels", "ring_lines_px", "score_face",
           "straight_rings"]
