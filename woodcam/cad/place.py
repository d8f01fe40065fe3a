"""Placing a part in the block: a short list of operations, applied in order, as one rigid (or
uniformly scaled) transform of the block frame.

Data form
---------
A placement is a sequence of operation strings, as given to ``--place`` (repeatable):

=====================  ==========================================================================
``rotate:AXIS:DEG``    rotate about the block axis ``x``, ``y`` or ``z`` through the centre of the
                       part's bounding box, ``DEG`` degrees (right hand rule, -360 to 360)
``translate:X,Y,Z``    move by ``(X, Y, Z)`` mm
``scale:S``            scale uniformly by ``S`` (> 0) about the bounding-box centre
``center``             move the bounding-box centre to the block centre
``drop``               move down so the part rests on the block's bottom face (min z = 0)
``fit[:MARGIN]``       scale uniformly (down or up) so the bounding box fits the block with
                       ``MARGIN`` mm (default 2; less than half the block's smallest side) on
                       every side, and centre it
=====================  ==========================================================================

:func:`place_part` returns the placed solid and the 4 x 4 matrix (block frame, mm) that maps the
part as loaded to the part as placed; bakes record it so the placement can be reproduced.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ..errors import WoodcamError
from ..units import message_unit, say_length, typed_length

#: Default margin (mm) ``fit`` keeps to every block face.
FIT_MARGIN_MM = 2.0

_AXES = {"x": 0, "y": 1, "z": 2}

_HELP = ("rotate:AXIS:DEG, translate:X,Y,Z, scale:S, center, drop or fit[:MARGIN] (e.g. "
         "--place rotate:x:90 --place center --place drop)")


def _rotation(axis: int, deg: float) -> np.ndarray:
    """Right-handed rotation about block axis ``axis`` (0, 1, 2 = x, y, z) by ``deg`` degrees."""
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    # the cyclic pair (e_i turns towards e_j): y needs (z, x); the ascending (x, z) turned it
    # left-handed
    i, j = (axis + 1) % 3, (axis + 2) % 3
    r = np.eye(3)
    r[i, i], r[i, j], r[j, i], r[j, j] = c, -s, s, c
    return r


def _about(centre: np.ndarray, linear: np.ndarray) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3] = linear
    m[:3, 3] = centre - linear @ centre
    return m


def _translate(offset) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = offset
    return m


def _number(text: str, op: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise WoodcamError(f"--place {op!r}: {text!r} is not a finite number; use {_HELP}")
    return value


def placement_matrix(ops: Sequence[str], bounds_mm, size_mm, *,
                     as_typed: Sequence[str] | None = None) -> np.ndarray:
    """The 4 x 4 transform (block frame, mm) of the operations ``ops`` applied in order to a
    part whose bounding box is ``bounds_mm (2, 3)``, in a block of ``size_mm (3,)``.
    ``as_typed``: the same operations as the user typed them, quoted in the errors (the CLI's
    ``--place`` in ``--units``: "--place 'fit:1.5'", not its 'fit:38.1' mm); default ``ops``."""
    lo, hi = (np.asarray(b, dtype=float) for b in np.asarray(bounds_mm, dtype=float))
    size = np.asarray(size_mm, dtype=float)
    total = np.eye(4)
    for name, value, op in parse_place(ops, as_typed=as_typed):
        # ``op`` (as typed) is what the errors quote; ``value`` (mm) is what is computed
        centre = (lo + hi) / 2
        if name == "rotate":
            axis, deg = value
            step = _about(centre, _rotation(axis, deg))
        elif name == "translate":
            step = _translate(value)
        elif name == "scale":
            step = _about(centre, np.eye(3) * value)
        elif name == "center":
            step = _translate(size / 2 - centre)
        elif name == "drop":
            step = _translate([0.0, 0.0, -lo[2]])
        else:  # fit
            margin = value
            room = size - 2 * margin
            if np.any(room <= 0):
                half = float(np.min(size)) / 2  # the margin that leaves the part no size
                raise WoodcamError(f"--place {op!r}: a margin of {say_length(margin, 'g')} leaves no room in the "
                                   f"{say_length(size, 'g')} block; a margin must be less than half its "
                                   f"smallest side: write fit:MARGIN with MARGIN below "
                                   f"{typed_length(half, 0.05, ok=lambda v: v <= half)} {message_unit()}, "
                                   f"or fit for {say_length(FIT_MARGIN_MM, 'g')}")
            factor = float(np.min(room / np.maximum(hi - lo, 1e-12)))
            step = _translate(size / 2 - centre) @ _about(centre, np.eye(3) * factor)
        total = step @ total
        corners = np.array(np.meshgrid(*zip(lo, hi), indexing="ij")).reshape(3, -1).T
        moved = corners @ step[:3, :3].T + step[:3, 3]
        lo, hi = moved.min(axis=0), moved.max(axis=0)
    return total


def parse_place(ops: Sequence[str], *, as_typed: Sequence[str] | None = None) -> list[tuple]:
    """The placement ``ops`` read and checked without a part or a block: one ``(name, value,
    op as typed)`` per operation, ``value`` ``(axis index, degrees)`` for rotate, the move
    ``[X, Y, Z]`` mm for translate, the factor for scale, the margin mm for fit, None for center
    and drop. A WoodcamError quoting ``as_typed`` (default ``ops``) for a malformed one, so a
    command can refuse it before it opens the block (a fit of minutes) and loads the part."""
    if as_typed is not None and len(as_typed) != len(ops):
        raise WoodcamError(f"placement_matrix: as_typed must hold one text per operation ({len(ops)}); "
                           f"got {len(as_typed)}: {list(as_typed)!r}; pass the ops as typed, or leave it out")
    out: list[tuple] = []
    for mm_op, op in zip(ops, ops if as_typed is None else as_typed):
        name, _, arg = str(mm_op).strip().partition(":")
        name = name.lower()
        value: object = None
        if name == "rotate":
            axis, _, deg = arg.partition(":")
            if axis.lower() not in _AXES or not deg:
                raise WoodcamError(f"--place {op!r}: expected rotate:AXIS:DEG with AXIS x, y or z; "
                                   f"use {_HELP}")
            angle = _number(deg, op)
            if abs(angle) > 360:  # 1e308 was taken (and turned the part by float noise): a typo
                raise WoodcamError(f"--place {op!r}: an angle must be within a full turn, -360 to 360 "
                                   f"degrees; got {angle:g}; write it modulo 360 (e.g. rotate:z:90 for 450)")
            value = (_AXES[axis.lower()], angle)
        elif name == "translate":
            parts = arg.split(",")
            if len(parts) != 3:
                raise WoodcamError(f"--place {op!r}: expected translate:X,Y,Z (in --units on the command "
                                   f"line, mm in the library); use {_HELP}")
            value = [_number(p, op) for p in parts]
            if max(abs(v) for v in value) > 1e5:  # 1e300 made the part's volume 0 ("inside-out?")
                raise WoodcamError(f"--place {op!r}: a move must stay within 100 m (1e5 mm)")
        elif name == "scale":
            value = _number(arg, op)
            if not 0 < value <= 1000:  # 1e300 overflowed the volume to NaN: the warnings vanished
                raise WoodcamError(f"--place {op!r}: the scale must be in (0, 1000]; got {value:g}")
        elif name in ("center", "drop") and not arg:
            pass
        elif name == "fit":
            value = _number(arg, op) if arg else FIT_MARGIN_MM
            if value < 0:
                raise WoodcamError(f"--place {op!r}: a margin must be >= 0; got {say_length(value, 'g')}; "
                                   f"write fit:0 for none, or fit for {say_length(FIT_MARGIN_MM, 'g')}")
        else:  # 'centre', the spelling of woodcam's own help ('the block centre'), was told only the list
            from .._checks import did_you_mean

            near = did_you_mean(name, ("rotate", "translate", "scale", "center", "drop", "fit"))
            raise WoodcamError(f"--place {op!r} is not a placement operation; {near + ' ' if near else ''}"
                               f"use {_HELP}")
        out.append((name, value, op))
    return out


def place_part(solid, ops: Sequence[str], size_mm, *, as_typed: Sequence[str] | None = None):
    """Apply the placement ``ops`` to ``solid`` (a ``manifold3d.Manifold``, block frame, mm);
    ``as_typed``: the ops as typed, for the errors (:func:`placement_matrix`).

    Returns
    -------
    (manifold3d.Manifold, (4, 4) float)
        The placed solid and the transform applied.
    """
    if not ops:
        return solid, np.eye(4)
    bounds = np.asarray(solid.bounding_box(), dtype=float).reshape(2, 3)
    matrix = placement_matrix(ops, bounds, size_mm, as_typed=as_typed)
    return solid.transform(matrix[:3, :].tolist()), matrix
