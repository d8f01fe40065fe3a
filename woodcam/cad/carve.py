"""Carving: the part intersected with the block, as a watertight mesh in the block frame (mm).

The block is the box ``[0, W] x [0, D] x [0, H]`` of ``docs/conventions.md`` (origin at the
bottom-front-left corner, X width, Y depth, Z up). Carving is the exact boolean
``part ∩ block`` computed by manifold3d, so the result is always a closed, oriented 2-manifold.

- A part that misses the block entirely (empty intersection) is an error.
- A part that sticks out of the block is carved anyway; the volume outside the block is reported
  in :attr:`CarveResult.warnings` and emitted as a :class:`woodcam.errors.WoodcamWarning`.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._manifold import manifold_to_trimesh
from .._repr import summary_repr
from .._types import ArrayLike
from ..errors import WoodcamError, WoodcamWarning
from ..frames import FOREIGN_GLTF_METRES_BELOW, check_size
from ..tolerances import INCHES_BELOW_MM, OUTSIDE_VOLUME_EPS_MM3, TESSELLATION_ANGLE_DEG
from ..units import MM_PER_UNIT, message_units, said, say_length, say_volume
from .parts import SCRIPT_SUFFIXES, STEP_SUFFIXES, load_part


@dataclass(frozen=True)
class CarveResult:
    """The carved part.

    Attributes
    ----------
    mesh : trimesh.Trimesh
        Watertight triangle mesh of ``part ∩ block``, block frame, mm (vertices ``(n, 3)``
        float64, faces ``(m, 3)`` int64, outward normals). Built without vertex merging, so its
        topology is exactly manifold3d's.
    manifold : manifold3d.Manifold
        The same solid as a manifold, for further booleans.
    volume_mm3 : float
        Volume of the carved solid (mm^3).
    part_volume_mm3 : float
        Volume of the whole part before carving (mm^3).
    outside_volume_mm3 : float
        ``part_volume_mm3 - volume_mm3``: volume of the part outside the block (mm^3), clipped
        at 0 (boolean round-off can make it slightly negative).
    warnings : list of str
        Human-readable warnings (e.g. the part sticks out of the block).
    size_mm : (3,) tuple of float
        Block size ``(W, D, H)`` in mm the part was carved from.
    """

    __repr__ = summary_repr  # arrays as shapes: a notebook shows one line

    mesh: Any
    manifold: Any
    volume_mm3: float
    part_volume_mm3: float
    outside_volume_mm3: float
    warnings: list[str] = field(default_factory=list)
    size_mm: tuple[float, float, float] = (0.0, 0.0, 0.0)


#: How a library caller scales a part read 25.4 x too small (:func:`units_hint`'s default fix).
UNITS_FIX = ("scale it before carving: woodcam.cad.place.place_part(part, ['scale:25.4', 'center'], "
             "size_mm) (in metres: 'scale:1000')")


def carve(
    part: Any,
    size_mm: ArrayLike,
    *,
    tolerance_mm: float | None = None,
    angular_tolerance_deg: float = TESSELLATION_ANGLE_DEG,
    units_fix: str = UNITS_FIX,
    source: Any = None,
) -> CarveResult:
    """Carve ``part`` out of the block ``[0, W] x [0, D] x [0, H]`` (block frame, mm).

    Parameters
    ----------
    part : manifold3d.Manifold or any source :func:`woodcam.cad.load_part` accepts
        The part in the block frame, mm. Non-manifold sources are loaded with ``load_part``
        using the tolerances below.
    size_mm : (3,) sequence of float
        Block size ``(W, D, H)`` in mm, each finite and > 0.
    tolerance_mm, angular_tolerance_deg : float (tolerance_mm None: scaled to the part)
        Tessellation tolerances passed to :func:`load_part` for B-rep sources.
    units_fix : str
        How to scale the part, in the warning of a part in inches (:func:`units_hint`; default
        for a library caller: ``place_part`` ops).
    source : any source :func:`load_part` takes, or None
        What ``part`` was loaded from (a path, a build123d object), when ``part`` is already
        loaded: it words the units note (:func:`units_note`). None: ``part`` itself.

    Returns
    -------
    CarveResult
        The carved mesh and manifold, volumes and warnings.

    Raises
    ------
    WoodcamError
        If ``size_mm`` is not three positive finite lengths, or the part does not intersect the
        block (the message gives both bounding boxes).

    Warns
    -----
    WoodcamWarning
        If more than ``OUTSIDE_VOLUME_EPS_MM3`` of the part lies outside the block; the part is
        carved anyway and the message gives the outside volume in mm^3 and percent.
        If the part, 25.4 times larger, would still fit the block (a part file in inches, read
        as mm): the message says how to scale it.
    """
    import manifold3d

    size = tuple(float(v) for v in check_size(size_mm))
    why, redo = units_note(part if source is None else source)
    # load_part also validates a Manifold (status, emptiness, orientation) without copying it
    solid = load_part(part, tolerance_mm=tolerance_mm, angular_tolerance_deg=angular_tolerance_deg)

    block = manifold3d.Manifold.cube(size)
    carved = solid ^ block
    part_volume = float(solid.volume())
    volume = float(carved.volume()) if not carved.is_empty() else 0.0
    if part_volume <= OUTSIDE_VOLUME_EPS_MM3:  # it was told it misses the block, "move it by (0, 0, 0)"
        # a 0.2 m part exported in metres is read as 0.2 mm: said with its size, what it would
        # measure in metres and in inches, and how to scale it (only 'check its units' before)
        lo, hi = _bounds(solid)
        extent = hi - lo
        with message_units("mm"):  # the file's own numbers, read as mm whatever --units says
            raise WoodcamError(
                f"the part's volume is {say_volume(part_volume, '.3g')} (it measures "
                f"{say_length(extent, '.3g')}), too small to carve; check its units: {why}, so a part "
                f"modelled in metres would be "
                f"{say_length(extent * 1e3, '.3g')}, in inches {say_length(extent * MM_PER_UNIT['inch'], '.3g')}: "
                f"{units_fix}")
    if carved.is_empty() or volume <= OUTSIDE_VOLUME_EPS_MM3:
        lo, hi = _bounds(solid)
        raise WoodcamError(
            f"part does not intersect the block: the part's bounding box is "
            f"{_fmt_box(lo, hi)} but the block is {_fmt_box(np.zeros(3), np.array(size))} "
            f"(block frame: origin at the bottom-front-left corner); model the part in the block "
            f"frame, e.g. move it by "
            f"{say_length(np.array(size) / 2 - (lo + hi) / 2, '.4g', form='({}, {}, {})')} to centre "
            f"it, or give the right block size"
        )

    outside = max(part_volume - volume, 0.0)
    messages: list[str] = []
    if outside > OUTSIDE_VOLUME_EPS_MM3:
        lo, hi = _bounds(solid)
        message = said(lambda: (  # the part report (a file) keeps it in mm
            f"part sticks out of the block: {say_volume(outside, '.4g')} "
            f"({100.0 * outside / part_volume:.3g} % of the part's {say_volume(part_volume, '.6g')}) lies "
            f"outside and is not carved; part bounding box {_fmt_box(lo, hi)}, block "
            f"{_fmt_box(np.zeros(3), np.array(size))}; move the part or use a larger block"
        ))
        messages.append(message)
        warnings.warn(message, WoodcamWarning, stacklevel=2)
    message = units_hint(*_bounds(solid), size, units_fix, source=part if source is None else source)
    if message:
        messages.append(message)
        warnings.warn(message, WoodcamWarning, stacklevel=2)

    mesh = manifold_to_trimesh(carved)
    return CarveResult(
        mesh=mesh,
        manifold=carved,
        volume_mm3=volume,
        part_volume_mm3=part_volume,
        outside_volume_mm3=outside,
        warnings=messages,
        size_mm=size,
    )


def units_note(source: Any, unit: str = "inches", noun: str = "part") -> tuple[str, str]:
    """``(why, redo)``: why a part from ``source`` (a path, or an object :func:`load_part`
    takes) is read as millimetres, and how to save it right, true of its kind: the inch
    warning said 'STL, OBJ and PLY carry no units' of a STEP file (which carries its units,
    converted to mm) and of a build123d script. ``unit``: the unit it looks drawn in
    (``inches``, ``metres``), which a STEP file's words name. ``noun``: what the file is
    (``part``; ``obstacle`` for ``woodify --obstacle``, whose note said "part files are read as
    millimetres")."""
    from pathlib import Path

    if isinstance(source, (str, Path)):
        suffix = Path(source).suffix.lower()
        kind = "step" if suffix in STEP_SUFFIXES else "script" if suffix in SCRIPT_SUFFIXES else "mesh"
    else:
        module = type(source).__module__ or ""
        kind = "script" if module.startswith(("build123d", "cadquery", "OCP")) else "mesh"
    if kind == "step":
        return ("a STEP file names its units and is converted from them to millimetres, so it "
                f"was saved this small (as one drawn in {unit} under a millimetre setting is)",
                f"re-export it with its units set to {unit}")
    if kind == "script":
        script = "a part script" if noun == "part" else f"the {noun}'s script"
        return (f"lengths in {script} or a build123d/cadquery shape carry no units and are read "
                "as millimetres",
                "write its lengths in mm")
    return f"{noun} files are read as millimetres (STL, OBJ and PLY carry no units)", "export it in mm"


def units_hint(lo, hi, size_mm: ArrayLike | None, fix: str = UNITS_FIX, *,
               source: Any = None, inches: bool = True, noun: str = "part") -> str | None:
    """What to say when a part with bounds ``lo, hi (3,)`` mm would still fit the block
    ``size_mm (3,)`` 25.4 times larger (None otherwise): STL, OBJ and PLY carry no units, so a part
    exported in inches is read 25.4 x too small and carved or placed as a speck. Its lengths
    are in mm under every ``--units``: they are the file's own numbers.

    Without a block (``size_mm`` None: ``woodcam woodify`` grows a part alone) the part's own
    size decides, along its longest side: under :data:`woodcam.frames.FOREIGN_GLTF_METRES_BELOW`
    mm (no router carves anything smaller; the size below which a foreign glTF is read as
    metres) it is taken for a part in metres, 1000 x too small; under
    :data:`woodcam.tolerances.INCHES_BELOW_MM` (a 1/4-inch router bit's width) for a part in
    inches, 25.4 x too small (it was grown silently).

    fix : how the caller's user scales the part by 25.4 (the command's option, or the library
        call); the CLI's ``--place`` is no use to ``woodcam place`` or a library caller. Without
        a block, where to scale it: the message says ``scale it by 1000`` or ``by 25.4``, then
        ``fix``, then how to save it right (:func:`units_note`'s, of the unit it looks drawn in).
    source : what the part was loaded from (a path, an object), for :func:`units_note`; None:
        a mesh.
    inches : without a block, whether a size under :data:`~woodcam.tolerances.INCHES_BELOW_MM`
        says inches (False: only the metres check; ``woodify --obstacle``, where a 5 mm pin is
        a real obstacle beside a real part).
    noun : what the message calls the thing measured without a block ("part", or "obstacle" for
        ``woodify --obstacle``: "--obstacle 'pin.stl': the part is only ..." named the wrong one),
        and its files (:func:`units_note`) and why its size is implausible: a part is carved, an
        obstacle grown around."""
    extent = np.asarray(hi, dtype=float) - np.asarray(lo, dtype=float)
    with message_units("mm"):  # about the file's own numbers, read as mm whatever --units says
        if size_mm is None:
            longest = float(np.max(extent))
            # an obstacle is grown around, not carved: its reason says so (it said "nothing that
            # small is carved" and "a router bit is wider" of a woodify --obstacle)
            part = noun == "part"
            if 0 < longest < FOREIGN_GLTF_METRES_BELOW:
                unit, factor = "metres", 1e3
                small = "nothing that small is carved" if part else "nothing that small bends the rings"
            elif inches and 0 < longest < INCHES_BELOW_MM:  # a 4-inch bowl saved in inches grew as a 4 mm speck
                unit, factor = "inches", MM_PER_UNIT["inch"]
                small = (f"a {INCHES_BELOW_MM:g} mm (1/4-inch) router bit is wider than its longest side" if part
                         else f"its longest side, as the part's, is under {INCHES_BELOW_MM:g} mm (1/4 inch)")
            else:
                return None
            why, redo = units_note(source, unit, noun)
            return (f"the {noun} is only {say_length(extent, '.3g')}: {why}, and {small}; "
                    f"it looks modelled in {unit} ({factor:g} times larger: "
                    f"{say_length(extent * factor, '.3g')}): scale it by {factor:g} {fix}, or {redo}")
        why, redo = units_note(source)
        size = np.asarray(size_mm, dtype=float)
        if not np.all(np.sort(extent) * MM_PER_UNIT["inch"] <= np.sort(size)):
            return None
        return (f"the part is only {say_length(extent, '.3g')} in the "
                f"{say_length(size, 'g')} block: 25.4 times larger it would still fit. "
                f"{why[0].upper()}{why[1:]}; if it was modelled in inches {fix}, or {redo}")


def _bounds(solid) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned bounds ``(lo (3,), hi (3,))`` of a manifold, mm."""
    box = np.asarray(solid.bounding_box(), dtype=np.float64)
    return box[:3], box[3:]


def _fmt_box(lo, hi) -> str:
    """``"[x0, x1] x [y0, y1] x [z0, z1] mm"`` (in the message units)."""
    return say_length([v for a, b in zip(lo, hi) for v in (a, b)], ".4g",
                      form="[{}, {}] x [{}, {}] x [{}, {}]")
