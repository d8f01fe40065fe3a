"""Faces with known rings for the ring detector (:mod:`woodcam.detect`): evaluation and training.

Both render synthetic 50 mm cubes with :func:`~woodcam.synth.block.synth_block` from random logs
(:func:`~woodcam.synth.cut.random_log_placement`, every sawing pattern); the true ring lines are
the integer iso-lines of the true field. This sits here, above ``detect/``, because ``detect``
may not import ``synth`` (``tests/test_layering.py``).
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np

from ..errors import WoodcamError
from ..frames import FACES
from .block import synth_block
from .cut import PATTERNS, cut_block, random_log_placement
from .dataset import knotted_log_field
from .photos import _RealisticWood


FaceStyle = Literal["plain", "realistic"]


def ring_eval_faces(seed: int, face_px: int = 256, size_mm: float = 50.0,
                    ring_width_range_mm=(1.5, 6.0), faces=FACES, style: FaceStyle = "plain") -> list:
    """Faces of one synthetic cube of ``size_mm`` drawn from ``np.random.default_rng(seed)``, as
    :class:`woodcam.detect.evaluate.SyntheticFace` (photo, true ring points every 0.5 px): a random
    eccentric, lobed log and sawing pattern, photos with camera noise, exposure variation,
    vignetting and lens blur (the synth defaults). Faces with fewer than two true rings are
    skipped.

    ``style``: ``"plain"``, the built-in wood colour (a smooth latewood ramp over the last 45 %
    of each ring); ``"realistic"``, :class:`woodcam.synth.photos._RealisticWood` (narrow softwood
    latewood or ring-porous oak, drawn by the seed's parity; rays, figure, faint rings)."""
    from ..detect.evaluate import SyntheticFace, dense_polyline

    rng = np.random.default_rng(seed)
    pattern = PATTERNS[seed % len(PATTERNS)]
    size = (size_mm,) * 3
    log, placement = random_log_placement(rng, pattern, size, ring_width_range_mm)
    field = cut_block(log, size, **placement)
    if style not in ("plain", "realistic"):
        raise WoodcamError(f"style must be 'plain' or 'realistic'; got {style!r}")
    wood = None
    if style == "realistic":
        wood = _RealisticWood(field, rng, "ring-porous" if seed % 2 else "softwood")
    block = synth_block(field, size, face_px=face_px, rng=rng, seed=None, faces=faces,
                        ring_map_faces=(), name=f"synthetic-{seed}", wood=wood)
    px_mm = block.meta["px_per_mm"]
    out = []
    for name, f in block.faces.items():
        if len(f.traces) < 2:
            continue
        truth = np.concatenate([dense_polyline(t.points_px) for t in f.traces])
        out.append(SyntheticFace(f.photo, truth, px_mm, f"seed {seed} {pattern} {style} {name}"))
    return out


def ring_training_faces(spec, progress: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Training data of the learned ring detector for ``spec``
    (:class:`woodcam.detect.learned.RingNetSpec`): ``(inputs (n, h, w) float32, targets (n, h, w)
    float32)`` from ``spec.n_blocks`` synthetic 50 mm cubes, seeds ``[spec.seed, i, 7]`` (never
    the evaluation seeds), every fourth cut from a knotted log (seeds 001/003), photos augmented
    by :func:`woodcam.detect.learned.augment_photo`; targets ``exp(-(d / sigma)^2)`` of the
    distance ``d`` (px) to the true ring lines, ``sigma = spec.target_sigma_px``. The faces'
    colour is ``spec.style`` (:attr:`~woodcam.detect.learned.RingNetSpec.style`)."""
    from .._progress import progress_bar

    from ..detect.learned import augment_photo, net_input

    xs, ys = [], []
    for i in progress_bar(range(spec.n_blocks), desc="synthesising faces", unit="block", enabled=progress):
        rng = np.random.default_rng([spec.seed, i, 7])
        size = (50.0, 50.0, 50.0)
        pattern = PATTERNS[i % len(PATTERNS)]
        log, placement = random_log_placement(rng, pattern, size, (0.8, 6.0))
        if i % 4 == 3:                     # a knotted log; the block kept inside it
            log = knotted_log_field(rng, (0.8, 6.0))
            half_diag = 0.5 * math.hypot(size[0], size[1])
            r_in = float(getattr(getattr(log, "log", None), "r_min_mm", 100.0)) - half_diag - 5.0
            if placement["pattern"] != "pith-inside":
                placement["distance_mm"] = max(half_diag + 2.0, min(placement["distance_mm"], r_in))
        field = cut_block(log, size, **placement)
        style = getattr(spec, "style", "plain")
        wood = None
        if style == "realistic" or (style == "mixed" and i % 3):
            # softwood and oak on alternate cubes (of the realistic ones)
            wood = _RealisticWood(field, rng, "ring-porous" if i % 2 else "softwood")
        block = synth_block(field, size, face_px=spec.face_px, rng=rng, seed=None, trace_faces=(),
                            ring_map_sigma_px=spec.target_sigma_px, ring_map_noise=0.0, wood=wood)
        for f in block.faces.values():
            xs.append(net_input(augment_photo(f.photo, rng)))
            ys.append(np.nan_to_num(f.ring_map, nan=0.0).astype(np.float32))
    return np.stack(xs), np.stack(ys)
