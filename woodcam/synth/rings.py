"""Faces with known rings for the ring detector (:mod:`woodcam.detect`): evaluation and training.

Both render synthetic 50 mm cubes with :func:`~woodcam.synth.block.synth_block` from random logs
(:func:`~woodcam.synth.cut.random_log_placement`, every sawing pattern); the true ring lines are
the integer iso-lines of the true field. This sits here, above ``detect/``, because ``detect``
may not import ``synth`` (``tests/test_layering.py``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Literal

import numpy as np

from ..errors import WoodcamError
from ..fields.base import evaluate
from ..frames import FACES
from .block import synth_block
from .cut import PATTERNS, cut_block, random_log_placement
from .dataset import knotted_log_field
from .photos import _RealisticWood
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ..detect.learned import RingNetSpec
    from ..detect.quilt import QuiltSource


FaceStyle = Literal["plain", "realistic"]


def ring_eval_faces(seed: int, face_px: int = 256, size_mm: float = 50.0,
                    ring_width_range_mm: tuple[float, float] = (1.5, 6.0), faces: Sequence[str] = FACES,
                    style: FaceStyle = "plain") -> list:
    """Faces of one synthetic cube of ``size_mm`` drawn from ``np.random.default_rng(seed)``, as
    :class:`woodcam.detect.evaluate.SyntheticFace` (photo, true ring points every 0.5 px): a random
    eccentric, lobed log and sawing pattern, photos with camera noise, exposure variation,
    vignetting and lens blur (the synth defaults). Faces with fewer than two true rings are
    skipped.

    ``style``: ``"plain"``, the built-in wood colour (a smooth latewood ramp over the last 45 %
    of each ring); ``"realistic"``, :class:`woodcam.synth.photos._RealisticWood` (narrow softwood
    latewood or ring-porous oak, drawn by the seed's parity; rays, figure, faint rings).
    ``face_px``: each face's side in pixels (default 256); ``ring_width_range_mm``: (min, max)
    ring width at the cube, mm/year (log-uniform); ``faces``: the faces drawn (default all
    six)."""
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


def texture_sources(samples, progress: bool = False) -> list:
    """The texture sources of ``RingNetSpec.texture_samples``: per sample folder (relative to the
    shared data folder, ``$WOODCAM_SHARED_DATA``; a Mokume sample), its face photos prepared by
    :func:`woodcam.detect.quilt.quilt_source` (faces with too little usable phase left out)."""
    from pathlib import Path

    from .._progress import progress_bar
    from ..block.io import read_mokume
    from ..detect.quilt import SOURCE_MIN_SHARE, quilt_source
    from ..logs.io import shared_data_dir

    base = shared_data_dir()
    folders = [None if base is None else Path(base) / s for s in samples]
    missing = [s for s, f in zip(samples, folders) if f is None or not f.is_dir()]
    if missing:
        raise WoodcamError(f"ring net spec texture_samples {missing} not found under the shared data folder "
                           f"({base if base is not None else 'none found'}): the quilted styles read their real "
                           f"face photos when training; set WOODCAM_SHARED_DATA=/path/to/shared/data or "
                           f"train another style")
    groups = []
    for s, folder in progress_bar(list(zip(samples, folders)), desc="reading texture photos", unit="sample",
                                  enabled=progress):
        block = read_mokume(folder)
        group = []
        for name, f in block.faces.items():
            if f.photo is None:
                continue
            src = quilt_source(f.photo, 1.0 / min(block.face_pixel_size_mm(name)), f"{s} {name}")
            if src.valid.mean() >= SOURCE_MIN_SHARE:
                group.append(src)
        if not group:
            raise WoodcamError(f"ring net spec texture_samples: no face photo of {s!r} shows rings the "
                               f"classical detector can follow; leave it out")
        groups.append(group)
    return groups


def ring_training_faces(spec: RingNetSpec, progress: bool = False,
                        sources: Sequence[Sequence[QuiltSource]] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Training data of the learned ring detector for ``spec``
    (:class:`woodcam.detect.learned.RingNetSpec`): ``(inputs (n, h, w) float32, targets (n, h, w)
    float32)`` from ``spec.n_blocks`` synthetic 50 mm cubes, seeds ``[spec.seed, i, 7]`` (never
    the evaluation seeds), every fourth cut from a knotted log (seeds 001/003), photos augmented
    by :func:`woodcam.detect.learned.augment_photo`; targets ``exp(-(d / sigma)^2)`` of the
    distance ``d`` (px) to the true ring lines, ``sigma = spec.target_sigma_px``. The faces'
    colour is ``spec.style`` (:attr:`~woodcam.detect.learned.RingNetSpec.style`).

    ``sources``: for the quilted styles (:data:`woodcam.detect.learned.QUILTED_STYLES`), a list of
    groups (one per real cube), each a list of :class:`woodcam.detect.quilt.QuiltSource`; default
    :func:`texture_sources` of ``spec.texture_samples``. Cube ``i`` is drawn in
    :func:`woodcam.detect.learned.cube_style` ``(spec.style, i)``; a quilted one is painted by
    :func:`woodcam.detect.quilt.quilt_face` with the textures of group ``i % len(sources)``
    (one source face per synthetic face, drawn at random from the group). ``progress``: bars on
    stderr while texture photos are read and faces synthesised (off by default)."""
    from .._progress import progress_bar

    from ..detect.learned import QUILTED_STYLES, augment_photo, cube_style, net_input

    style = getattr(spec, "style", "plain")
    if style in QUILTED_STYLES and sources is None:
        sources = texture_sources(spec.texture_samples, progress)

    xs, ys = [], []
    for i in progress_bar(range(spec.n_blocks), desc="synthesising faces", unit="block", enabled=progress):
        rng = np.random.default_rng([spec.seed, i, 7])
        size = (50.0, 50.0, 50.0)
        kind = cube_style(style, i)
        pattern = PATTERNS[i % len(PATTERNS)]
        # quilted cubes: rings no narrower than the evaluation faces' 1.5 mm, so real texture is
        # not shrunk five-fold into noise (the real faces' spacings read 3-12 mm)
        widths = (1.5, 6.0) if kind == "quilted" else (0.8, 6.0)
        log, placement = random_log_placement(rng, pattern, size, widths)
        if i % 4 == 3:                     # a knotted log; the block kept inside it
            log = knotted_log_field(rng, widths)
            half_diag = 0.5 * math.hypot(size[0], size[1])
            r_in = float(getattr(getattr(log, "log", None), "r_min_mm", 100.0)) - half_diag - 5.0
            if placement["pattern"] != "pith-inside":
                placement["distance_mm"] = max(half_diag + 2.0, min(placement["distance_mm"], r_in))
        field = cut_block(log, size, **placement)
        wood = None
        quilted = kind == "quilted"
        if kind in ("realistic", "softwood"):
            # softwood and oak on alternate cubes (of the "realistic" ones; "softwood" cubes all softwood)
            wood = _RealisticWood(field, rng, "ring-porous" if i % 2 and kind == "realistic" else "softwood")
        block = synth_block(field, size, face_px=spec.face_px, rng=rng, seed=None, trace_faces=(),
                            ring_map_sigma_px=spec.target_sigma_px, ring_map_noise=0.0, wood=wood)
        for name, f in block.faces.items():
            photo = f.photo
            if quilted:
                from ..detect.quilt import quilt_face
                from ..frames import face_pixel_points

                group = sources[i % len(sources)]
                years = evaluate(field, face_pixel_points(name, f.shape, size).reshape(-1, 3)).reshape(f.shape)
                photo, _ = quilt_face(years, group[int(rng.integers(len(group)))], rng)
            xs.append(net_input(augment_photo(photo, rng)))
            ys.append(np.nan_to_num(f.ring_map, nan=0.0).astype(np.float32))
    return np.stack(xs), np.stack(ys)
