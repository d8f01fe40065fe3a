"""Reproducible sets of synthetic blocks on disk (``woodcam block synth``)."""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from .._atomic import write_text
from ..block import Block
from ..block.io import write_block
from ..errors import WoodcamError
from ..fields.analytic import AnalyticLogField
from .block import synth_block
from .cut import PATTERNS, _place_through_knot, cut_block, random_log_placement
from .degradation import _check_fraction
from .._types import PathLike
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ..fields import KnottedLogField


def benchmark_set_block(seed: int, index: int, *, face_px: int = 512,
                        size_range_mm: tuple[float, float] = (30.0, 80.0),
                        ring_width_range_mm: tuple[float, float] = (1.5, 6.0),
                        log_fields: Callable[[np.random.Generator], object] | None = None,
                        knotted_fraction: float = 0.5,
                        wood_factory: Callable[[object], object] | None = None,
                        **synth_kwargs) -> tuple[Block, dict]:
    """Block ``index`` of the set :func:`synth_benchmark_set` writes for ``seed``, alone.

    Drawn from ``np.random.default_rng([seed, index])`` only, so it is the same block whichever
    process makes it and whatever else is made. Returns the block and its index entry (name,
    size, knotted, ring width, placement). ``face_px``, ``size_range_mm``,
    ``ring_width_range_mm``, ``log_fields``, ``knotted_fraction``, ``wood_factory`` and
    ``synth_kwargs`` are :func:`synth_benchmark_set`'s: the face images' pixels along the block's longest side, the
    (min, max) block side and ring width (mm), the knotted-log factory and the share of knotted
    blocks, the appearance factory, and further :func:`synth_block` arguments.
    """
    i = int(index)
    rng = np.random.default_rng([int(seed), i])
    pattern = PATTERNS[i % len(PATTERNS)]
    size = tuple(float(v) for v in np.round(rng.uniform(*size_range_mm, size=3) * 2) / 2)
    log, placement = random_log_placement(rng, pattern, size, ring_width_range_mm)
    knotted = log_fields is not None and rng.uniform() < knotted_fraction
    if knotted:
        log = log_fields(rng)
        # the fix names this function's parameters and the options of 'woodcam block synth'
        # that set them: 'a smaller block or a log with longer knots' named neither
        lo, hi = (float(v) for v in size_range_mm)
        fix = (f"draw smaller blocks (size_range_mm is ({lo:g}, {hi:g}); --size-range-mm of 'woodcam block "
               f"synth', default 30,80) or fewer knotted ones (knotted_fraction is {knotted_fraction:g}; "
               "--knotted-fraction, 0 for none)")
        field, placement = _place_through_knot(rng, log, placement, size, fix=fix)
    else:
        field = cut_block(log, size, **placement)
    name = f"block_{i:04d}"
    info = {"name": name, "index": i, "size_mm": list(size), "knotted": bool(knotted),
            # a knotted log's rings are as wide at the block as anywhere (KnottedLogField):
            # the index gave null for them, as if the width were unknown
            "ring_width_mm": float(log.ring_width_at(placement["distance_mm"])),
            **{k: (float(v) if isinstance(v, (float, np.floating)) else v) for k, v in placement.items()}}
    wood = None if wood_factory is None else wood_factory(field)
    block = synth_block(field, size, wood=wood, face_px=face_px, rng=rng, seed=None, name=name,
                        meta={"benchmark_seed": int(seed), **info}, **synth_kwargs)
    return block, info


def check_no_stale_blocks(out_dir: Path, count: int, seed: int) -> None:
    """Refuse, before any work, a set of ``count`` blocks into a folder whose ``index.json`` lists
    blocks it would not replace: they stayed beside the new ones, under an index that no longer
    named them (``--count 1 --seed 5`` into a folder of 2 blocks of seed 0 left block_0001 of
    seed 0 there, which a ``block_*`` glob still found). A set as large or larger replaces every
    block listed, so a rerun, or one with another seed, is written."""
    from ..errors import UsageError

    path = out_dir / "index.json"
    try:
        old = json.loads(path.read_text()) if path.is_file() else {}
    except (OSError, ValueError):
        return  # not one of our indexes: nothing known to go stale
    blocks = old.get("blocks") if isinstance(old, dict) else None
    names = [b.get("name") for b in blocks if isinstance(b, dict)] if isinstance(blocks, list) else []
    kept = sorted(n for n in names if isinstance(n, str) and n.startswith("block_")
                  and n[6:].isdigit() and int(n[6:]) >= count and (out_dir / n).is_dir())
    if kept:
        raise UsageError(
            f"{str(out_dir)!r} holds a set of {len(names)} synthetic blocks (seed {old.get('seed')!r}); "
            f"{count} block{'' if count == 1 else 's'} of seed {seed} written there would leave "
            f"{', '.join(kept[:3])}{' ...' if len(kept) > 3 else ''} of the old set beside them; "
            f"choose an empty output folder, or delete {str(out_dir)!r} first")


def synth_benchmark_set(out_dir: PathLike, count: int, seed: int, *, face_px: int = 512,
                        size_range_mm: tuple[float, float] = (30.0, 80.0),
                        ring_width_range_mm: tuple[float, float] = (1.5, 6.0),
                        log_fields: Callable[[np.random.Generator], object] | None = None,
                        knotted_fraction: float = 0.5, wood_factory: Callable[[object], object] | None = None,
                        progress: bool = True, **synth_kwargs) -> list[Path]:
    """Write ``count`` synthetic blocks to ``out_dir/block_0000`` ... plus ``out_dir/index.json``.

    Block ``i`` is drawn from ``np.random.default_rng([seed, i])`` alone, so any block of a set
    can be regenerated without the others and the set is reproducible. Sawing patterns cycle
    through :data:`PATTERNS`; each side is uniform in ``size_range_mm`` (0.5 mm steps); ring
    width at the block is log-uniform in ``ring_width_range_mm``.

    Parameters
    ----------
    face_px : int
        Pixels of the face photos and ring maps along the block's longest side (their
        ``px_per_mm`` is ``face_px / max(size)``; default 512).
    progress : bool
        A bar on stderr, one step per block (default True).
    log_fields : callable ``rng -> log-frame field``, optional
        Factory of knotted log fields (pith on log ``z``). When given, a block is knotted with
        probability ``knotted_fraction``, and a knotted block is cut with a knot crossing it
        (:func:`~woodcam.synth.cut.knot_crosses` on the true field, asserted).
    wood_factory : callable ``block-frame field -> wood``, optional
        Appearance for each block (e.g. ``lambda f: woodcam.appearance.Wood(f, ...)``); default
        the built-in colour map.
    synth_kwargs
        Passed to :func:`synth_block` (e.g. ``trace_dropout``); default clean full annotation.

    Returns
    -------
    list of Path
        The block folders, in order.
    """
    from .._progress import progress_bar

    if count < 1:
        raise WoodcamError(f"count must be >= 1; got {count!r}")
    _check_fraction("knotted_fraction", knotted_fraction)
    out_dir = Path(out_dir)
    check_no_stale_blocks(out_dir, count, seed)
    out_dir.mkdir(parents=True, exist_ok=True)
    index = {"format": "woodcam-benchmark", "version": 1, "seed": int(seed), "count": int(count),
             "face_px": int(face_px), "size_range_mm": list(size_range_mm),
             "ring_width_range_mm": list(ring_width_range_mm),
             "knotted_available": log_fields is not None, "blocks": []}
    folders = []
    for i in progress_bar(range(count), desc="synthesising blocks", unit="block", enabled=progress):
        block, info = benchmark_set_block(
            seed, i, face_px=face_px, size_range_mm=size_range_mm,
            ring_width_range_mm=ring_width_range_mm, log_fields=log_fields,
            knotted_fraction=knotted_fraction, wood_factory=wood_factory, **synth_kwargs)
        folder = out_dir / info["name"]
        write_block(block, folder)
        folders.append(folder)
        index["blocks"].append(info)
    write_text(out_dir / "index.json", json.dumps(index, indent=1))  # atomic
    return folders


def knotted_log_field(rng: np.random.Generator, ring_width_range_mm: tuple[float, float] = (1.5, 6.0), *,
                      length_mm: float = 1200.0) -> KnottedLogField:
    """A knotted log field (log frame) from the log generator of seed 001 (``woodcam.logs``),
    turned into the stem + knot field of seed 003; ring width log-uniform in the range.
    The factory :func:`synth_benchmark_set` takes as ``log_fields``. ``rng`` draws the log's
    seed and the width; ``ring_width_range_mm``: (min, max) ring width, mm/year; ``length_mm``:
    the log's length (default 1200 mm)."""
    from ..fields import KnottedLogField
    from ..logs import generate_log

    gen = generate_log(int(rng.integers(1 << 31)), length_mm=length_mm)
    width = math.exp(rng.uniform(*np.log(ring_width_range_mm)))
    return KnottedLogField(gen.to_skeleton(), ring_width_mm=width)


def time_synth_block(face_px: int = 512, repeats: int = 1) -> float:
    """Seconds to synthesise one cube block with six ``face_px``-square faces (built-in colour),
    the best of ``repeats`` runs."""
    log = AnalyticLogField(ring_width_mm=3.0, width_slope_per_mm=0.001, eccentricity=0.1, lobe_amplitude=0.02)
    field = cut_block(log, (50, 50, 50), "rift")
    best = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        synth_block(field, (50, 50, 50), face_px=face_px, seed=0)
        best = min(best, time.perf_counter() - t0)
    return best
