"""Knot strands fitted from a block's knot masks into its stem field (issue 12 part 3).

Each connected region of a face's ``extras["knot_mask"]`` is a knot's exit through that face: its
centroid (block frame) and equivalent radius ``sqrt(area / pi)``. A branch runs across the stem
(seed 003: from the pith outward, nearly perpendicular to it), so two exits on different faces
whose joining line makes more than :data:`~woodcam.tolerances.KNOT_PAIR_MIN_ANGLE_DEG` with the
stem's axis are one knot, the nearest pairs first (H11: faces C and F). A strand is the line
through its exits, extended across the block, with the radius linear between the exits' radii.
An unpaired exit gets a strand into the block along the face's inward normal made perpendicular
to the stem axis, with its own radius. The strands join the stem field through
:class:`woodcam.fields.knot_strands.StemWithKnots`.

Alive or dead (seed 003) is read from the face photo at each exit (:func:`exit_is_dead`): a dead
knot is ringed by bark, a dark line along its whole boundary; an alive knot's rings run on into
the stem's, so its boundary is no darker than its surroundings except where a ring happens to
cross it. A strand is dead when every exit of it is (the part of a branch past its death is
dead; a strand alive at one exit and dead at the other is kept alive: one flag per strand).
"""

from __future__ import annotations

import numpy as np

from ..fields.knot_strands import KnotStrand, StemWithKnots
from ..frames import FACE_NORMAL, pixel_to_block
from ..tolerances import (DEAD_KNOT_BANDS_MM, DEAD_KNOT_MIN_OUTLINED, DEAD_KNOT_SECTORS, KNOT_MIN_AREA_PX,
                          KNOT_MIN_AREA_SHARE, KNOT_PAIR_MIN_ANGLE_DEG)


def exit_is_dead(photo, region, pixel_mm: float) -> tuple[bool, float]:
    """Does a knot exit show a dead knot's bark ring? ``(dead, outlined share)``.

    photo : (h, w, 3) or (h, w) image of the face; region : (h, w) bool, the exit's mask;
    pixel_mm : pixel size. Around the region's centroid the boundary is cut into
    :data:`~woodcam.tolerances.DEAD_KNOT_SECTORS` sectors; a sector is outlined when the band
    just inside the boundary is darker than both the knot wood further in and the wood just
    outside (bands :data:`~woodcam.tolerances.DEAD_KNOT_BANDS_MM`) by 1 % of the photo's range.
    Dead when at least :data:`~woodcam.tolerances.DEAD_KNOT_MIN_OUTLINED` of the sectors are
    outlined (alive knots: a ring crossing the boundary darkens 0-20 % of them, measured on
    synthetic knots and H11).
    """
    from scipy import ndimage

    m = np.asarray(region, bool)
    lum = np.asarray(photo, float)
    lum = lum.mean(axis=2) if lum.ndim == 3 else lum
    if lum.shape != m.shape or not m.any() or m.all():
        return False, 0.0
    sd = (ndimage.distance_transform_edt(~m) - ndimage.distance_transform_edt(m)) * pixel_mm
    rr, cc = np.indices(m.shape)
    r0, c0 = np.argwhere(m).mean(axis=0)
    n = DEAD_KNOT_SECTORS
    sector = ((np.arctan2(rr - r0, cc - c0) + np.pi) / (2 * np.pi) * n).astype(int) % n
    (e0, e1), (i0, i1), (o0, o1) = DEAD_KNOT_BANDS_MM
    bands = [(sd > e0) & (sd <= e1), (sd > i0) & (sd <= i1), (sd > o0) & (sd <= o1)]
    margin = 0.01 * float(np.ptp(lum))
    outlined = []
    for k in range(n):
        sel = sector == k
        e, i, o = (lum[b & sel] for b in bands)
        if min(len(e), len(i), len(o)) >= 3:
            outlined.append(e.mean() < min(i.mean(), o.mean()) - margin)
    share = float(np.mean(outlined)) if outlined else 0.0
    return bool(share >= DEAD_KNOT_MIN_OUTLINED), share


def knot_exits(block, faces=None) -> list[dict]:
    """Knot exits on ``faces`` (default all): ``{"face", "centre_mm" (3,), "radius_mm", "dead",
    "outlined"}`` (:func:`exit_is_dead` on the face photo; alive without a photo)."""
    from scipy import ndimage

    out = []
    for name in (list(block.faces) if faces is None else faces):
        f = block.faces.get(name)
        mask = None if f is None else f.extras.get("knot_mask")
        if mask is None or not np.any(mask):
            continue
        px = min(block.face_pixel_size_mm(name))
        lab, n = ndimage.label(np.asarray(mask, bool))
        areas = np.bincount(lab.ravel())[1:]
        for i in range(1, n + 1):
            # speckle beside a knot (a detector's, or H11's grown mask) is not another knot
            if areas[i - 1] < max(KNOT_MIN_AREA_PX, KNOT_MIN_AREA_SHARE * areas.max()):
                continue
            region = lab == i
            rr, cc = np.nonzero(region)
            c = pixel_to_block(name, np.array([rr.mean()]), np.array([cc.mean()]), f.shape, block.size_mm)[0]
            dead, share = exit_is_dead(f.photo, region, px) if f.photo is not None else (False, 0.0)
            out.append({"face": name, "centre_mm": c, "radius_mm": float(np.sqrt(len(rr) / np.pi) * px),
                        "dead": dead, "outlined": share})
    return out


def fit_knot_strands(block, stem, faces=None) -> list[KnotStrand]:
    """Strands of the knots whose exits the masks show (module docstring)."""
    exits = knot_exits(block, faces)
    if not exits:
        return []
    axis = np.asarray(getattr(stem, "axis", (0.0, 0.0, 1.0)), float)
    axis /= np.linalg.norm(axis)
    length = float(np.linalg.norm(block.size_mm))
    pairs = []
    for i in range(len(exits)):
        for j in range(i + 1, len(exits)):
            if exits[i]["face"] == exits[j]["face"]:
                continue
            v = exits[j]["centre_mm"] - exits[i]["centre_mm"]
            dist = float(np.linalg.norm(v))
            if dist > 0 and abs(v @ axis) / dist < np.cos(np.deg2rad(KNOT_PAIR_MIN_ANGLE_DEG)):
                pairs.append((dist, i, j))
    used, strands = set(), []
    for dist, i, j in sorted(pairs):
        if i in used or j in used:
            continue
        used |= {i, j}
        a, b = exits[i], exits[j]
        u = (b["centre_mm"] - a["centre_mm"]) / dist
        # an oblique strand cuts a face in an ellipse of area pi R^2 / |cos(incidence)|
        ra, rb = (e["radius_mm"] * np.sqrt(max(abs(u @ np.asarray(FACE_NORMAL[e["face"]], float)), 0.2))
                  for e in (a, b))
        slope = (rb - ra) / dist
        lo, hi = 0.5 * min(ra, rb), 2.0 * max(ra, rb)
        strands.append(KnotStrand(tuple(a["centre_mm"] - u * length), tuple(b["centre_mm"] + u * length),
                                  float(np.clip(ra - slope * length, lo, hi)),
                                  float(np.clip(rb + slope * length, lo, hi)), dead=a["dead"] and b["dead"]))
    for k, e in enumerate(exits):
        if k in used:
            continue
        n = -np.asarray(FACE_NORMAL[e["face"]], float)  # into the block
        d = n - axis * (n @ axis)
        d = d / np.linalg.norm(d) if np.linalg.norm(d) > 0.3 else n
        strands.append(KnotStrand(tuple(e["centre_mm"] - 2.0 * d), tuple(e["centre_mm"] + length * d),
                                  e["radius_mm"], e["radius_mm"], dead=e["dead"]))
    return strands


def with_knots(block, stem, faces=None):
    """``(field, strands)``: ``stem`` with the masked knots joined in, or ``stem`` unchanged."""
    strands = fit_knot_strands(block, stem, faces)
    return (StemWithKnots(stem, strands) if strands else stem), strands


__all__ = ["exit_is_dead", "fit_knot_strands", "knot_exits", "with_knots"]
