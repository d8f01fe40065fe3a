"""Resource limits: guards that stop one absurd number from hanging or exhausting the machine.

Each limit has a reason and can be raised for one run with an environment variable
``WOODCAM_<NAME>`` (e.g. ``WOODCAM_MAX_GRID_CELLS=400000000``); the error that a guard raises
names the limit, the value asked for and that variable. :func:`limit` reads the effective value.
"""

from __future__ import annotations

import math
import os

from .errors import WoodcamError

#: Longest block side (mm). 10 m is longer than any sawn log; 1e9 mm is a typo, not a block.
MAX_BLOCK_SIZE_MM = 10_000.0

#: Pixels along one side of a face image. 16384 px is 0.003 mm/px on a 50 mm face, far past
#: any photo; beyond it decoding alone needs gigabytes.
MAX_FACE_PX = 16_384

#: Total pixels of one image file we decode (PIL's own bomb guard is 179 Mpx): 16384^2.
MAX_IMAGE_PIXELS = 16_384 * 16_384

#: Points of one ring trace. A hand trace has hundreds; a detector's a few thousand per ring.
MAX_TRACE_POINTS = 1_000_000

#: Largest |year| label of a ring. The oldest known trees are ~5000 years old.
MAX_RING_YEAR = 10_000

#: Nodes of one 3-D grid (fitted field, colour volume, stock height field) = 8 bytes each in
#: float64: 200 M nodes are 1.6 GB, about the most one step may hold on a 16 GB laptop.
MAX_GRID_CELLS = 200_000_000

#: Bytes one array allocation may ask for before we refuse (estimated ahead of allocating).
MAX_ALLOC_BYTES = 4 * 1024**3

#: Voxels of each of the review page's three colour volumes (woodcam.review, ``review --voxels``),
#: the one home of the range both read: 8 M RGB voxels a volume is ~70 MB of page before PNG
#: compression; under 1000 the section cap is a few blurred cells. Not a MAX_ guard: no
#: environment variable raises it.
REVIEW_VOXELS_RANGE = (1_000, 8_000_000)

#: Grid nodes along the longest side of a woodify grid (``woodify(resolution=)``, ``woodcam
#: woodify --resolution``), the one home of the range both read: 1024^3 nodes is the most one
#: arrival-time grid may hold; under 16 the input is a few nodes across. Not a MAX_ guard: the
#: memory a grid needs is (MAX_GRID_CELLS, MAX_ALLOC_BYTES at woodcam.woodify.grow's
#: WOODIFY_BYTES_PER_NODE), so 1024 passes for a slender input and not for a cube.
WOODIFY_RESOLUTION_RANGE = (16, 1024)

#: MiB of memory per engine worker (woodcam.scale.run_many's ``memory_limit_mb``, the
#: ``--memory-limit-mb`` of bench run, block synth and train), the one home of the range both
#: read: a Python worker alone needs ~100 MiB and a bench task ~1 GiB, so under 256 every task
#: dies of MemoryError (the library refuses it); 1 TiB, beyond any machine's RAM, bounds only
#: what the CLI takes (a typo's extra zeros). The CLI said 64 and the library 256: 64..255
#: passed the door, wrote bench run's run.json and exited 1 naming the Python parameter.
WORKER_MEMORY_MB_RANGE = (256, 1_048_576)

_DEFAULTS = {name: value for name, value in globals().items() if name.startswith("MAX_")}

#: What each limit counts, said after its numbers: 'needs 1.074e+09, more than the limit
#: MAX_GRID_CELLS = 2e+08' left a user to guess whether they were nodes, bytes or pixels.
#: A grid's cells are the values it holds (every channel of every node).
UNITS = {"MAX_BLOCK_SIZE_MM": "mm", "MAX_FACE_PX": "px a side", "MAX_IMAGE_PIXELS": "pixels",
         "MAX_TRACE_POINTS": "points", "MAX_RING_YEAR": "years", "MAX_GRID_CELLS": "grid cells",
         "MAX_ALLOC_BYTES": "bytes"}


def limit(name: str) -> float:
    """The effective value of limit ``name`` (``"MAX_GRID_CELLS"``): ``$WOODCAM_<NAME>`` if set
    to a positive finite number, else the default above."""
    if name not in _DEFAULTS:
        raise WoodcamError(f"limit: unknown limit {name!r}; one of {', '.join(sorted(_DEFAULTS))}")
    raw = os.environ.get(f"WOODCAM_{name}")
    if raw is None:
        return _DEFAULTS[name]
    try:
        value = float(raw)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise WoodcamError(f"WOODCAM_{name} must be a positive number; got {raw!r}; e.g. export "
                           f"WOODCAM_{name}={2 * _DEFAULTS[name]:.0f}, or unset it for the default "
                           f"{_DEFAULTS[name]:g}")
    return type(_DEFAULTS[name])(value)


def check_all() -> None:
    """Read every limit's ``$WOODCAM_<NAME>`` (:func:`limit`): a malformed one raises its error
    now. ``woodcam`` calls it before a command's work: read only when a guard ran, after the
    work before it (a fit of seconds to minutes), 'WOODCAM_MAX_GRID_CELLS=abc' failed late."""
    for name in _DEFAULTS:
        limit(name)


def check_limit(name: str, value: float, what: str, fix: str = "") -> None:
    """Raise a WoodcamError if ``value`` exceeds limit ``name``, naming ``what`` needs it, the
    limit, and how to raise it."""
    top = limit(name)
    if not value <= top:  # also refuses NaN
        raise WoodcamError(
            f"{what} needs {_amount(name, value)}, more than the limit {name} = {_amount(name, top)}"
            + (f"; {fix}" if fix else "")
            + f"; if this is intended, raise the limit with WOODCAM_{name}={2 * value:.3g}")


def _amount(name: str, value: float) -> str:
    """``value`` of limit ``name`` with its unit: '1.074e+09 grid cells', '4.295e+09 bytes
    (4 GiB)'."""
    text = f"{value:.4g} {UNITS[name]}"
    if name == "MAX_ALLOC_BYTES" and math.isfinite(value):
        size, unit = next(((value / 1024**k, u) for k, u in ((4, "TiB"), (3, "GiB"), (2, "MiB"), (1, "KiB"))
                           if value >= 1024**k), (value, "B"))
        text += f" ({size:.3g} {unit})" if unit != "B" else ""
    return text


def check_grid(shape, what: str, *, itemsize: int = 8, fix: str = "") -> None:
    """Guard a grid allocation of ``shape`` (cells) before it happens: cell count and bytes."""
    cells = math.prod(float(s) for s in shape)
    check_limit("MAX_GRID_CELLS", cells, f"{what} (a {'x'.join(f'{s:.0f}' for s in shape)} grid)", fix)
    check_limit("MAX_ALLOC_BYTES", cells * itemsize, f"{what} (memory)", fix)
