"""Built-in named synthetic blocks with analytic growth fields (for the demo and the tests).

Every built-in block is ``100 x 80 x 50`` mm (W x D x H) with a radial-scaling field of eq. 7-9
of seed 000 whose radius functions come from a fixed seed, so the truth is known exactly:

- ``flat-sawn``: pith 120 mm below the block, running along X and tilted 4 deg, so the top face
  shows the cathedral arches of a flat-sawn board and the left/right faces show end grain.
- ``quarter-sawn``: pith 150 mm in front of the block at mid-height, along X: straight parallel
  rings on the top face, end grain on left/right.
- ``rift``: pith 110 mm below and in front (about 45 deg to the faces), along X.
- ``pith-inside``: pith vertical through the block slightly off-centre (a turning blank cut
  from the heart): concentric rings on top and bottom, end grain there.
- ``knotty``: a block of a synthetic spruce log with a whorl of branches (the knot model of
  seed 003), the log running up its Z (the 50 mm height): end grain on top and bottom (a tray
  or pocket cut into the top floors in end grain), a tangential front face 95 mm from the pith
  with an alive knot through it and a dead one beside it, near-radial left and right faces.
- ``fast-grown``: a flitch of a fast-grown (plantation) tree, 10 mm rings, the pith 500 mm
  behind its middle plane, along X: its front-parallel leaves are flat-sawn with even bands
  tens of mm wide, the calm wood a parquetry maker keeps for plain areas (``woodcam
  parquetry --veneer-from builtin:fast-grown``). The ring width is an assumption (no measured
  tree), at the wide end of plantation growth.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import WoodcamError
from .base import LogFrame
from .radial import RadialScalingField

#: Size (W, D, H) in mm of every built-in block.
BUILTIN_SIZE_MM = (100.0, 80.0, 50.0)


@dataclass(frozen=True)
class BuiltinBlock:
    """A named synthetic block: size ``size_mm (3,)`` (W, D, H mm), true growth ``field``
    (block-frame points ``(n, 3)`` mm -> ``years (n,)``), suggested species, one-line summary."""

    name: str
    size_mm: tuple[float, float, float]
    field: object
    species: str
    description: str


def _tilted_x(deg: float) -> tuple[float, float, float]:
    a = np.radians(deg)
    return (float(np.cos(a)), 0.0, float(np.sin(a)))


# name -> (pith point, axis, ring width mm, species, seed, description)
_SPECS = {
    "flat-sawn": ((0.0, 40.0, -120.0), _tilted_x(4.0), 3.0, "oak", 1,
                  "flat-sawn board, pith 120 mm below, cathedral arches on top"),
    "quarter-sawn": ((0.0, -150.0, 25.0), (1.0, 0.0, 0.0), 2.5, "oak", 2,
                     "quarter-sawn board, straight rings on top, pith 150 mm in front"),
    "rift": ((0.0, -80.0, -80.0), (1.0, 0.0, 0.0), 3.0, "maple", 3,
             "rift-sawn board, rings at about 45 deg on the end faces"),
    "pith-inside": ((54.0, 43.0, 0.0), (0.03, -0.02, 1.0), 3.5, "pine", 4,
                    "turning blank with the pith inside, vertical"),
    "fast-grown": ((0.0, -460.0, 25.0), (1.0, 0.0, 0.0), 10.0, "maple", 5,
                   "fast-grown flitch, 10 mm rings, pith 500 mm behind: calm flat-sawn leaves"),
}

#: Names of the built-in blocks.
BUILTIN_NAMES: tuple[str, ...] = tuple(_SPECS) + ("knotty",)


def _knotty_block() -> BuiltinBlock:
    """A 100 x 80 x 50 mm block beside a whorl of a straight synthetic log, the log along its Z
    (:func:`~woodcam.fields.knots.block_at_knot`): end grain on top and bottom, the front face
    tangential through knot 0."""
    from .knots import KnottedLogField, block_at_knot, place_block_in_log
    from .skeleton import BranchStrand, simple_log

    r = np.linspace(0.0, 160.0, 33)
    knots = []
    for i, (az_deg, death_mm) in enumerate([(0.0, 200.0), (28.0, 45.0), (150.0, 200.0), (260.0, 60.0)]):
        knots.append(BranchStrand(
            z0_mm=300.0 + 6.0 * i, azimuth0_rad=np.radians(az_deg), r_mm=r,
            rise_mm=22.0 * np.sqrt(r / 10.0) * 0.6, twist_rad=0.0 * r,
            diameter_mm=np.minimum(3.0 + 0.16 * r, 24.0), r_end_mm=150.0, r_death_mm=death_mm))
    log = simple_log(600.0, 160.0, knots, name="builtin-knotty")
    origin, rotation = block_at_knot(log, 0, BUILTIN_SIZE_MM, front_r_mm=95.0)
    field = place_block_in_log(KnottedLogField(log, ring_width_mm=2.2), origin, rotation)
    return BuiltinBlock("knotty", BUILTIN_SIZE_MM, field, "spruce",
                        "knotted log's block, log along z: end grain on top, alive and dead knots in front")


def check_builtin_name(name: str) -> None:
    """A WoodcamError for a ``name`` no built-in block has: the names, and the nearest one when
    it looks like a typo (``knoty``); the one message of :func:`builtin_block` and of the
    command line's door (:func:`woodcam.cli.options.check_inputs`)."""
    if name in BUILTIN_NAMES:
        return
    from .._checks import did_you_mean

    near = did_you_mean(str(name), BUILTIN_NAMES, show=lambda b: f"'builtin:{b}'")
    raise WoodcamError(f"unknown built-in block {name!r}; choose one of: {', '.join(BUILTIN_NAMES)}"
                       + (f"; {near}" if near else ""))


def builtin_block(name: str) -> BuiltinBlock:
    """Return the built-in block ``name`` (see :data:`BUILTIN_NAMES`): its ``size_mm (3,)``
    (W, D, H mm), its true growth ``field`` (block-frame points ``(n, 3)`` mm -> ``years
    (n,)``), suggested species and one-line description (:class:`BuiltinBlock`)."""
    check_builtin_name(name)
    if name == "knotty":
        return _knotty_block()
    pith, axis, ring_w, species, seed, desc = _SPECS[name]
    rng = np.random.default_rng(seed)
    frame = LogFrame(pith, axis)
    # Gentler than the seed's training distribution (sigma 0.1 over the block): real stems vary
    # little over 100 mm, so sigma 0.06 and a 200 mm blend length read as one tree.
    field = RadialScalingField.random(frame, ring_w, rng, sigma=0.06, half_length_mm=200.0)
    # Put the axial blend's centre in the middle of the block so both radius functions show.
    centre = np.asarray(BUILTIN_SIZE_MM) / 2
    z_mid = float((centre - np.asarray(pith)) @ frame.rotation[2])
    frame = LogFrame(tuple(np.asarray(pith) + z_mid * frame.rotation[2]), axis)
    field = RadialScalingField(frame, ring_w, field.r_minus, field.r_plus, 200.0)
    return BuiltinBlock(name, BUILTIN_SIZE_MM, field, species, desc)
