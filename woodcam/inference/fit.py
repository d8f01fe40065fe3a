"""Fit a growth field to a block's ring annotations: the method registry and :func:`fit_block`."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Literal, get_args

import numpy as np

from .._checks import check_bool
from .._types import GrowthFieldLike
from ..errors import WoodcamError
from .baked import bake
from .observations import gather_observations
from .radial import fit_radial, number_observations
from .rbf import fit_rbf

if TYPE_CHECKING:
    from ..block import Block

Method = Literal["evidence", "rbf", "radial", "neural"]
METHODS: tuple[str, ...] = get_args(Method)

#: Bumped whenever a fitter changes what it returns for the same block, so fields cached by
#: :func:`woodcam.stock.fitted_field` are refitted (2: growth history, knot masks, year-free neural;
#: 3: the evidence-chosen default, uncertainty and fit facts saved with the grid; 4: dense knots;
#: 5: ring maps read as one-pixel lines, dead knots, uncertainty round knots; 6: the stem
#: hypothesis and per-fold pith refits in the evidence fit; 7: knot strands end at the pith, one-exit
#: strands run toward it and keep the stem's ring spacing; 8: unlabelled rings numbered by the pith
#: basin whose numbering makes neighbouring rings one year apart; 9: the knots' ring bend on by
#: default, competing while the evidence keeps its stem; 10: knot strands from the cones fitted to
#: the masks by default, and a refinement chosen only when it beats every plain hypothesis by more
#: than the accept margin; 11: year-labelled rings fitted and judged on the years given, not on
#: the radial fit's renumbering of them; 12: knot cones fitted with their analytic Jacobian, the
#: same choices and scores on the dev and validation blocks but cones that differ within the
#: fit's tolerance; 13: a refinement takes its base's place where the base is the best plain
#: hypothesis, unless it misses more than twice what the base misses; 14: the radial axis
#: searches of year-labelled rings take the exact variable-projection Jacobian instead of forward
#: differences, the same optima to rounding: 95 of the 96 fresh-seed fits the same to 0.1 point,
#: one block 0.1 point apart; the chosen field's cones fitted on one BLAS thread, as the folds';
#: 15: the knots' bend with a residual competes as a plain hypothesis, and the bend's fold fits
#: start from its all-faces fit, :func:`woodcam.inference.knots.knot_bend_recipes`; 16: a knot
#: strand guessed from one exit marks its knot in the chosen field and leaves its years; 17: knot
#: exits paired in the order of how near their line passes the fitted pith, and an exit near the
#: pith may be two knots' of a whorl, :func:`woodcam.inference.knots.strands_from_exits`; 18: a
#: knot seen at one exit is the ray from the fitted pith through it, its rise read from the rings,
#: and bends them, :func:`woodcam.inference.knots.fit_knotted_stem`; 19: its rises are searched
#: wherever some rise of the grid has a ray, not only where the ray across the stem has one; 20:
#: a fold's knot cones start from the all-faces fit's only, so the folds, refitted in forks, do
#: not depend on each other, :func:`woodcam.inference.knots.knot_bend_recipes`; 21: a baked
#: thin-plate spline of face points is interpolated deeper than 5 mm, :mod:`woodcam.inference.baked`;
#: 22: a knot seen at one exit whose ray would leave by a photographed face showing no knot there
#: ends before that face instead of having no ray, :func:`woodcam.inference.knots._pith_ray`;
#: 23: the knots' bend starts from a stem whose growth time rises away from its pith where the
#: plain stem's falls, :func:`woodcam.inference.knots.fit_knotted_stem`; 24: unlabelled rings whose
#: pith search finds no basin numbering half the neighbouring rings one year apart are searched
#: again on other point subsets, :func:`woodcam.inference.radial._numbered_basins`; 25: a knot
#: seen at one end (a block corner or edge) ends before a photographed face that shows no knot
#: where its cone would come out, as a one-exit ray does, and a cone thinning away from the pith
#: is kept as the masks show it, :func:`woodcam.inference.knots.strands_from_exits`; 26: knot ends
#: are paired otherwise than in that order where the other pairing's cones cut the masks better
#: and its bend fits the rings better, :func:`woodcam.inference.knots.fit_knotted_stem`; 27: a
#: block whose ring points are mostly unlabelled fits them all with the labels dropped (a few
#: year labels threw the other rings away), :func:`woodcam.inference.observations.gather_observations`,
#: and rings on one face only leave RBF out of the evidence fit; fits of blocks all labelled or
#: all unlabelled on two or more faces, every benchmark block, are those of 26).
FIT_VERSION = 27


def fit_block(block: Block, method: Method = "evidence", faces: Sequence[str] | None = None,
              baked: bool = True, knot_bend: bool = True, knot_cones: bool = True,
              residual: bool = False, seed: int = 0) -> GrowthFieldLike:
    """Infer a block's growth field from the rings on its faces.

    Parameters
    ----------
    block : woodcam.block.Block
    method : "evidence" (the default: several hypotheses, radial pith basins, RBF, a radial
        stem with a residual and the stem model of :mod:`woodcam.inference.stem`, chosen by how
        well each predicts the faces it was not fitted to; a choice the held-out faces
        contradict raises a WoodcamWarning and is flagged in ``field.meta``; the baked grid
        carries the per-point ``uncertainty``, see :mod:`woodcam.inference.evidence`) or "rbf"
        (seed 000's baseline: thin-plate RBF of labelled ring points; unlabelled rings are
        numbered by the radial fit first) or "radial"
        (ours: pith axis + smooth inverse ring width by least squares; also numbers unlabelled
        traces and ring maps) or "neural" (seed 000's eq. 5: the packaged generic neural GTF,
        latent code and cut-out transform fitted to labelled traces; unlabelled traces and ring
        maps are numbered by the radial fitter, then refined with a year-free periodic loss;
        needs torch).
    faces : list of face names / Mokume letters, optional; default every face of the block.
    baked : return the field baked to a 1 mm grid (:class:`woodcam.fields.GridField`, fast,
        saveable with ``.save(path)``) rather than the raw fitted callable.
    knot_bend : evidence only: the stem with its knots' ring bend (seed 003's join fitted with
        the stem, :func:`woodcam.inference.knots.fit_knotted_stem`) competes as one more
        hypothesis wherever the masks show a knot (a strand pinned by exits on two faces, or a
        knot seen at one exit as a ray from the pith whose rise the rings choose:
        :func:`woodcam.inference.knots.knot_bend_recipes`). It refines
        the stem: it competes only while the held-out faces keep the plain stem within
        :data:`~woodcam.tolerances.EVIDENCE_REFINE_BASE_MARGIN` of the best hypothesis, and
        is chosen when it beats every plain hypothesis by more than
        :data:`~woodcam.tolerances.EVIDENCE_REFINE_GAIN_MARGIN`, which keeps H11's held-out
        faces where they were without the bend, or in the stem's place where the stem is the
        best plain hypothesis and the bend misses at most
        :data:`~woodcam.tolerances.EVIDENCE_REFINE_MISS_RATIO` times what it misses
        (:func:`woodcam.inference.evidence.choose`; README). The same bend with a residual on
        it (``"stem + knot bend + residual"``, a smoothed thin-plate RBF of what the bend leaves
        on the faces) competes as a plain hypothesis where four or more faces carry rings
        (FIT_VERSION 15: the cone bend misfits the faces near its exits while its inside is
        right). ``False`` leaves both out.
    knot_cones : evidence only (default True): each knot's strand and radius are the cone fitted
        to every face's knot mask, exits touching across a block edge one knot end
        (:func:`woodcam.inference.knots.strands_from_exits`); ``False``: the line through two
        exits' centroids with radii from their areas (FIT_VERSION 9). Seed 63311, knotted blocks,
        within 1 / 2 mm: six faces 62.0 / 76.3 -> 66.3 / 81.5, three faces 41.6 / 61.2 -> 46.4 /
        65.7; H11's knot IoU 0.82 / 0.86 -> 0.91 / 0.91. Its bend is a refinement of the stem
        chosen only when it beats every plain hypothesis by more than
        :data:`~woodcam.tolerances.EVIDENCE_REFINE_GAIN_MARGIN` (without that rule one of H11's
        folds chose it and the held-out faces fell from 1.59 to 1.04 x chance; README).
    residual : evidence only, opt-in: the small-scale residual of issue 12 part 4
        (``fit_evidence(residual=True)``), a smooth correction near the faces on top of the
        chosen field, kept only where leave-one-face-out says it predicts; the grid's
        ``meta["residual"]`` says whether it was kept and why (README).
    seed : evidence only: the random seed of its held-out points, fitting subsets and starts
        (the stem's and its knots' bend's too). Real cubes' held-out figures are worth
        reporting over several (H11's ratio to chance, FIT_VERSION 24: 1.62, 1.50, 1.10, 1.07x
        with seeds 0-3; README, "H11's held-out figure is a matter of seed" and "A pith search
        that misses on one subset of the points").
    Returns
    -------
    field : callable ``(n, 3) mm -> (n,) years`` in the block frame.
    """
    from ..block.block import Block

    if not isinstance(block, Block):
        raise WoodcamError(f"block must be a woodcam.block.Block (read_block, builtin_block, synth_block); "
                           f"got {type(block).__name__}")
    if method not in METHODS:
        raise WoodcamError(f"method must be one of {', '.join(METHODS)}; got {method!r}")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise WoodcamError(f"seed must be an integer >= 0 (the evidence fit's random seed); got {seed!r}")
    baked, knot_bend, knot_cones, residual = (check_bool(v, n) for n, v in (
        ("baked", baked), ("knot_bend", knot_bend), ("knot_cones", knot_cones), ("residual", residual)))
    if isinstance(faces, str):  # 'top' was read letter by letter: "face must be ...; got 't'"
        raise WoodcamError(f"faces must be a list of face names or None; got the string {faces!r}; "
                           f"pass [{faces!r}]")
    if method == "neural":
        from .neural import fit_neural  # torch loads only here

        return fit_neural(block, faces=faces)  # always baked to a grid (the net is slow)
    obs = gather_observations(block, faces)
    if method == "evidence":
        from ..tolerances import KNOT_BEND_RESIDUAL_MIN_FACES
        from .evidence import bake_evidence, fit_evidence
        from .knots import knot_bend_recipes, knot_exits, with_knots

        # the stem with the rings bent round its knots competes as more hypotheses
        exits = knot_exits(block, faces)  # once: their cone fits are remembered with them
        used = sorted({int(i) for i in np.unique(obs.face)})
        stem, recipes, refines = (knot_bend_recipes(block.size_mm, exits, seed=seed, cones=knot_cones,
                                                    residual=len(used) >= KNOT_BEND_RESIDUAL_MIN_FACES)
                                  if knot_bend else (None, None, None))
        ev = fit_evidence(obs, block.size_mm, recipes=recipes, stem=stem, refines=refines,
                          residual=residual, seed=seed)
        # a stem with its knots holds them already; a residual on it hands its base's on
        # (:class:`~woodcam.fields.residual.ResidualField`)
        strands = getattr(ev.field, "strands", None)
        if strands is None:
            ev.field, strands = with_knots(block, ev.field, faces, knot_cones, exits)  # knots from the masks (part 3)
        return bake_evidence(ev, block.size_mm, used, strands) if baked else ev
    # the radial fit's start and basin descents and the grid bake on the fit's cores, as the
    # evidence fit's (woodcam._parallel, the same field bit for bit): 'fit --method radial
    # --workers N' ran them on one whatever N was
    from .._parallel import fit_workers

    workers = fit_workers()
    if method == "rbf":
        if not obs.labelled:  # the seed's RBF needs years: number the rings as the radial fit does
            obs = number_observations(obs, fit_radial(obs, block.size_mm, workers=workers))
        field = fit_rbf(obs)
    else:
        field = fit_radial(obs, block.size_mm, workers=workers)
    return bake(field, block.size_mm, workers=workers) if baked else field


__all__ = ["FIT_VERSION", "METHODS", "Method", "fit_block"]
