"""Ring observations of a block gathered for fitting: points on ring boundaries, block frame.

Each observation is a point ``points_mm : (n, 3)`` on a ring boundary (an integer iso-surface of
the growth field), grouped by ``group : (n,) int`` (one group per traced polyline, per set of unlabelled
pieces of one ring of a face that share a ``RingTrace.ring`` id, or per connected ring-map
component: all points of a group lie on one ring) with ``years : (n,) float``
(NaN where unlabelled). ``face : (n,) int`` indexes :data:`woodcam.frames.FACES`.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import WoodcamError, WoodcamWarning
from ..fields.rings import resample_polyline
from ..frames import FACES, check_face, face_image_size_mm, pixel_to_block
from ..tolerances import (FACE_PIXEL_ASPECT_RTOL, KNOT_MASK_MARGIN_MM, RING_MAP_MAX_WIDTH_FACTOR,
                          RING_MAP_MIN_PIECE_PX, RING_MAP_THRESHOLD, TRACE_SAMPLE_STEP_MM)
from collections.abc import Sequence
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ..block import Block


@dataclass
class RingObservations:
    """Ring-boundary points of a block (see module docstring for shapes and frames)."""

    points_mm: np.ndarray
    years: np.ndarray
    group: np.ndarray
    face: np.ndarray

    @property
    def labelled(self) -> bool:
        """True when every point carries a year label."""
        return bool(len(self.years)) and bool(np.all(np.isfinite(self.years)))

    @property
    def n_groups(self) -> int:
        return int(self.group.max()) + 1 if len(self.group) else 0

    def subset(self, mask) -> "RingObservations":
        m = np.asarray(mask)
        _, g = np.unique(self.group[m], return_inverse=True)
        return RingObservations(self.points_mm[m], self.years[m], g, self.face[m])


def knot_exclusion(face, pixel_mm: float) -> np.ndarray | None:
    """(h, w) bool: pixels on or within :data:`KNOT_MASK_MARGIN_MM` of ``face.extras["knot_mask"]``
    (None without a mask), for square pixels of ``pixel_mm``. Ring pixels there are not
    observations of the stem's growth field."""
    mask = face.extras.get("knot_mask")
    if mask is None or not np.any(mask):
        return None
    from scipy import ndimage

    outside = ndimage.distance_transform_edt(~np.asarray(mask, bool))
    return outside * pixel_mm <= KNOT_MASK_MARGIN_MM


def _pixel_index(coord: np.ndarray, n: int) -> np.ndarray:
    """Nearest pixel index of continuous pixel coordinates, clipped to ``[0, n)``."""
    return np.clip(np.round(coord).astype(int), 0, n - 1)


def _ring_map_components(ring_map: np.ndarray, threshold: float, exclude=None):
    """Ring lines of a ring map -> list of ``(k, 2)`` pixel (row, col) arrays, one per ring piece;
    ``exclude``: optional (h, w) bool of pixels to leave out.

    The bright pixels are thinned to their one-pixel skeleton (a ring boundary is a line, not
    the 3-8 px band the U-Net paints), skeleton pixels where the band is wider than
    :data:`~woodcam.tolerances.RING_MAP_MAX_WIDTH_FACTOR` times the face's median band width are
    dropped (blobs where the map is unsure: H11's face A has 20-40 px blocks spanning several
    rings), and the skeleton is cut at its junctions, where two rings touch: a connected bright
    component is one group, i.e. one ring, to the fit, so one that bridges rings forces them to
    one year (on H11 such blobs halved the numbered ring count).
    """
    from scipy import ndimage
    from skimage import morphology

    mask = np.asarray(ring_map, float) >= threshold
    if exclude is not None:
        mask &= ~exclude
    if not mask.any():
        return []
    width = 2.0 * ndimage.distance_transform_edt(mask)
    skel = morphology.skeletonize(mask)
    if skel.any():
        skel &= width <= RING_MAP_MAX_WIDTH_FACTOR * np.median(width[skel])
    neighbours = ndimage.convolve(skel.astype(np.int32), np.ones((3, 3), np.int32), mode="constant") - 1
    junction = skel & (neighbours > 2)
    skel &= ~ndimage.binary_dilation(junction, structure=np.ones((3, 3)))
    lab, n = ndimage.label(skel, structure=np.ones((3, 3)))
    if n == 0:
        return []
    rows, cols = np.nonzero(lab)
    ids = lab[rows, cols]
    order = np.argsort(ids, kind="stable")
    splits = np.flatnonzero(np.diff(ids[order])) + 1
    comps = np.split(np.stack([rows[order], cols[order]], axis=1).astype(float), splits)
    return [c for c in comps if len(c) >= RING_MAP_MIN_PIECE_PX]


def gather_observations(block: Block, faces: Sequence[str] | None = None, step_mm: float = TRACE_SAMPLE_STEP_MM,
                        ring_map_threshold: float = RING_MAP_THRESHOLD) -> RingObservations:
    """Collect ring-boundary points from ``block``'s traces (preferred) or ring maps.

    Parameters
    ----------
    block : woodcam.block.Block
    faces : list of face names or Mokume letters, optional
        Use only these faces (partial annotation); default all faces the block has.
    step_mm : spacing (mm) at which traces are resampled, so long and densely traced rings do
        not outweigh the others and fits stay fast.
    ring_map_threshold : ring-map pixels at or above this grey value are ring pixels.

    Ring-map pixels and trace points on or near a face's ``extras["knot_mask"]``
    (:func:`knot_exclusion`) are left out.

    Raises
    ------
    WoodcamError
        When a face name does not exist or is not on the block, or no ring is found.
    """
    names = list(block.faces) if faces is None else [check_face(f) for f in faces]
    missing = [f for f in names if f not in block.faces]
    if missing:
        raise WoodcamError(
            f"faces {missing} are not on block {block.name!r}, which has {list(block.faces)}; "
            f"pass a subset of those"
        )
    pts, yrs, grp, fc = [], [], [], []
    g = 0
    for name in names:
        f = block.faces[name]
        dr, dc = block.face_pixel_size_mm(name)
        if abs(dr - dc) > FACE_PIXEL_ASPECT_RTOL * max(dr, dc):
            h, w = face_image_size_mm(name, block.size_mm)
            raise WoodcamError(
                f"face {name!r} is {f.shape[0]}x{f.shape[1]} px but covers {h:g}x{w:g} mm of block "
                f"{block.name!r} (size_mm {block.size_mm}): its pixels would be {dr:.3g}x{dc:.3g} mm, "
                f"not square; check size_mm or crop the face image to the face"
            )
        excl = knot_exclusion(f, min(dr, dc))
        if f.traces:
            polys = [(t.points_px, t.year, t.ring) for t in f.traces]
            px_step = step_mm / max(min(dr, dc), 1e-12)
            polys = [(resample_polyline(p, px_step), y, k) for p, y, k in polys]
            if excl is not None:  # traced knot rings, or stem rings bent round the knot
                polys = [(p[~excl[_pixel_index(p[:, 0], f.shape[0]), _pixel_index(p[:, 1], f.shape[1])]], y, k)
                         for p, y, k in polys]
                polys = [(p, y, k) for p, y, k in polys if len(p)]
        elif f.ring_map is not None:
            comps = _ring_map_components(f.ring_map, ring_map_threshold, excl)
            stride = max(1, int(round(step_mm / max(min(dr, dc), 1e-12))))
            # one-pixel ring lines, kept every half step (0.25 mm): twice the traces' density,
            # about what the old blob sampling gave, which the neural fit's year-free gap term
            # (midpoints between neighbouring rings) was tuned on
            polys = [(c[::max(1, stride // 2)] if len(c) > 4 * stride else c, None, None) for c in comps]
        else:
            if faces is not None:  # asked for by name and left out without a word
                warnings.warn(f"face {name!r} of block {block.name!r} has no traced rings and no ring map: it is "
                              "not used; trace its rings (or detect them on its photo)", WoodcamWarning,
                              stacklevel=2)
            continue
        # unlabelled pieces of one ring of this face (RingTrace.ring) are one group: one level
        ring_group: dict[int, int] = {}
        for p, year, ring in polys:
            if year is None and ring is not None:
                if ring not in ring_group:
                    ring_group[ring] = g
                    g += 1
                gi = ring_group[ring]
            else:
                gi = g
                g += 1
            pts.append(pixel_to_block(name, p[:, 0], p[:, 1], f.shape, block.size_mm))
            yrs.append(np.full(len(p), np.nan if year is None else float(year)))
            grp.append(np.full(len(p), gi))
            fc.append(np.full(len(p), FACES.index(name)))
    if not pts:
        raise WoodcamError(
            f"block {block.name!r} has no ring traces or ring-map rings on faces {names}; "
            f"trace at least one ring (or give a ring map) on at least one face"
        )
    obs = RingObservations(np.concatenate(pts), np.concatenate(yrs), np.concatenate(grp), np.concatenate(fc))
    lab = np.isfinite(obs.years)
    if lab.any() and not lab.all():
        # Mixed input: the years of labelled traces pin the field, so where they are most of the
        # rings the labelled traces alone are fitted. Where they are few, the labels are dropped
        # instead: one data-year on one stroke threw away every other ring of the block (97 of
        # 4664 points kept, a field of one year), without a word. Either way it is said.
        share = float(lab.mean())
        if share >= 0.5:
            obs = obs.subset(lab)
            what = "only the labelled ones are fitted"
        else:
            obs = RingObservations(obs.points_mm, np.full(len(obs.years), np.nan), obs.group, obs.face)
            what = "the labels are ignored and every ring is numbered by the fit"
        warnings.warn(f"block {block.name!r}: {100 * share:.0f} % of the ring points carry a year label "
                      f"(data-year) and the rest none; {what}; label every ring or none", WoodcamWarning,
                      stacklevel=2)
    return obs
