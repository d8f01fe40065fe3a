"""Door checks of the public API's plain arguments: one number, one vector, one path.

A wrong type or shape must fail where it enters, as a :class:`~woodcam.errors.WoodcamError`
naming the argument, the rule, the value received and a fix, not as a bare ``TypeError`` or
broadcast error three calls down (or, worse, as a NaN result). Richer checks (points, sizes,
image shapes) live in their own modules (:func:`woodcam.fields.base.check_points`,
:func:`woodcam.frames.check_size`) and parse their input with :func:`as_floats`, as
:func:`check_vector` does.
"""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np

from .errors import WoodcamError
from .tolerances import UNIT_LENGTH_TOL


def did_you_mean(given: str | Iterable[str], names: Iterable[str], *, n: int = 1,
                 show: Callable[[str], str] = repr) -> str:
    """``"did you mean X?"`` (``n`` > 1: ``"X or Y?"``) of the ``names`` closest to ``given``
    (:func:`difflib.get_close_matches`, its 0.6 cutoff), each written by ``show``, or ``""``
    when none is close: the one home of every near-name suggestion (a built-in block, a file
    beside a missing one, a colour, a brush key). ``given`` may be several spellings, tried in
    turn until one has a close name."""
    import difflib

    names = list(names)
    for text in [given] if isinstance(given, str) else given:
        near = difflib.get_close_matches(text, names, n=n)
        if near:
            return f"did you mean {' or '.join(map(show, near))}?"
    return ""


def _fail(name: str, rule: str, value, fix: str):
    raise WoodcamError(f"{name} must be {rule}; got {received(value)}" + (f"; {fix}" if fix else ""))


def _real(x) -> bool:
    """A real number of any Python or numpy type (int, float, Fraction, Decimal, np.float32,
    bool): not a complex number, a string or None."""
    return isinstance(x, numbers.Number) and (isinstance(x, numbers.Real) or not isinstance(x, numbers.Complex))


def as_floats(value) -> np.ndarray | None:
    """``value`` as a float array of any shape, or None where it is not real numbers: a string
    such as ``'a'``, a ragged list, and (numpy converts them) complex numbers (whose imaginary
    part was dropped with only numpy's ComplexWarning), numeric strings (``'10'`` was 10.0),
    None (NaN) or dates. The caller refuses it with its own message, saying what it got with
    :func:`received`."""
    try:
        a = np.asarray(value)
    except (TypeError, ValueError):  # a ragged list
        return None
    if a.dtype.kind == "O":  # Python numbers past int64, Fractions, Decimals; or None, text, complex
        if not all(map(_real, a.flat)):
            return None
    elif a.dtype.kind not in "biuf":  # c complex, U/S text, M/m dates, V records
        return None
    try:
        return a.astype(float, copy=False)
    except (TypeError, ValueError, OverflowError):
        return None


def real_numbers(value, name: str, *, finite: bool = False, fix: str = "") -> np.ndarray:
    """``value`` (real numbers of any shape: a number, a list, an array) as floats, or the
    WoodcamError naming ``name``: the one rule of an argument that is numbers and nothing more
    (a growth time, an axial position, a radius). ``np.asarray(value, float)`` took None as NaN
    (a NaN answer without a word), complex numbers as their real parts (numpy's ComplexWarning
    only) and 'abc' as numpy's bare ValueError. NaN and inf pass: each method says what they
    give; ``finite=True`` refuses them (a value that indexes a grid: NaN was cast to an
    integer, numpy's RuntimeWarning and another cell's value)."""
    a = as_floats(value)
    if a is None:
        fix = numbers_fix(value, name) or fix or f"e.g. {name}=10.0 or an array of them"
        raise WoodcamError(f"{name} must be real numbers (any shape); got {received(value)}; {fix}")
    if finite and not np.all(np.isfinite(a)):
        bad = a.ravel()[np.argmin(np.isfinite(a).ravel())]
        raise WoodcamError(f"{name} must be finite real numbers; got {bad} among {a.size}"
                           + (f"; {fix}" if fix else ""))
    return a


def received(value, limit: int = 80) -> str:
    """What the user passed, for an error's "got ...": an array's kind, dtype and shape (a
    complex or text array of 10^5 points printed whole was the message), else its repr cut to
    ``limit`` characters."""
    if isinstance(value, np.ndarray):
        kind = {"c": "complex numbers", "U": "text", "S": "bytes", "O": "Python objects",
                "M": "dates", "m": "time spans", "V": "records"}.get(value.dtype.kind, "numbers")
        return f"an array of {kind} (dtype {value.dtype}, shape {value.shape})"
    text = repr(value)
    return text if len(text) <= limit else text[:limit] + "..."


def not_a_mesh(what: str, value: object, fix: str, *, loads: bool = True) -> WoodcamError:
    """The error for ``value`` given where a ``trimesh.Trimesh`` is taken: ``what`` names the
    argument; a path (str or Path) is shown and, with ``loads``, told to be loaded first (a
    notebook passes the file name, as the command line takes it); otherwise ``fix`` ends it."""
    got = type(value).__name__
    if isinstance(value, (str, os.PathLike)):
        got += f" {received(os.fspath(value))}"
        if loads:
            fix = f"load the file first: trimesh.load({os.fspath(value)!r}, force='mesh')"
    return WoodcamError(f"{what} must be a trimesh.Trimesh; got {got}; {fix}")


def numbers_fix(value, name: str) -> str:
    """The fix of a ``value`` that :func:`as_floats` refused for its kind of elements: complex
    numbers -> take the real parts if meant, text -> convert it; ``""`` for anything else (the
    caller gives its own example)."""
    try:
        kind = np.asarray(value).dtype.kind
    except (TypeError, ValueError):
        return ""
    if kind == "c":
        return f"pass real numbers (e.g. np.real({name}) if the imaginary parts are all zero)"
    if kind in "US":
        return f"convert the text to numbers first, e.g. np.asarray({name}, dtype=float)"
    return ""


def check_number(value, name: str, *, lo: float | None = None, hi: float | None = None,
                 lo_open: bool = False, integer: bool = False, fix: str = "") -> float:
    """``value`` as a float (an int with ``integer=True``) that is finite and in the range.

    ``lo``/``hi`` are inclusive bounds (``lo_open=True``: ``> lo``). A bool, a string or an
    array is refused even where Python would convert it; numpy scalars are accepted.
    """
    kind = "an integer" if integer else "a finite number"
    rule = kind
    if lo is not None and hi is not None:
        rule += f" in {'(' if lo_open else '['}{lo:g}, {hi:g}]"
    elif lo is not None:
        rule += f" {'>' if lo_open else '>='} {lo:g}"
    elif hi is not None:
        rule += f" <= {hi:g}"
    ok_type = numbers.Integral if integer else numbers.Real
    if isinstance(value, bool) or not isinstance(value, ok_type):
        _fail(name, rule, value, fix)
    v = int(value) if integer else float(value)
    if not math.isfinite(v) or (lo is not None and (v <= lo if lo_open else v < lo)) \
            or (hi is not None and v > hi):
        _fail(name, rule, value, fix)
    return v


def check_bool(value, name: str, *, fix: str = "") -> bool:
    """``value`` as a ``bool``: ``True``/``False`` or a numpy bool. A string (``"false"`` is
    truthy), a number or None is refused: each was taken as its truth value without a word."""
    if not isinstance(value, (bool, np.bool_)):
        _fail(name, "True or False", value, fix or f"pass {name}=True or {name}=False")
    return bool(value)


def check_vector(value, name: str, *, n: int = 3, unit: bool = False, fix: str = "") -> np.ndarray:
    """``value`` as a float ``(n,)`` array of finite numbers; ``unit=True``: a non-zero
    direction, returned normalised to length 1, or as given when it is of length 1 to rounding
    (:data:`~woodcam.tolerances.UNIT_LENGTH_TOL`), so normalising a normalised vector is the
    identity: an object that stores its normalised direction is rebuilt from it exactly."""
    what = "three finite numbers (x, y, z)" if n == 3 else f"{n} finite numbers"
    v = as_floats(value)
    if v is None or v.shape != (n,) or not np.all(np.isfinite(v)):
        _fail(name, what, value, fix)
    if unit:
        length = float(np.linalg.norm(v))
        if length < 1e-12:
            _fail(name, "a non-zero direction", value,
                  fix or f"e.g. {name}=({', '.join(['1'] + ['0'] * (n - 1))})")
        # of length 1 to rounding: kept, as a second division moved its last bits (a copy: not
        # the caller's own array, as the division returned none)
        v = v / length if abs(length - 1.0) > UNIT_LENGTH_TOL else v.copy()
    return v


def check_rotation(value, name: str, *, fix: str = "build it with scipy Rotation (.as_matrix())") -> np.ndarray:
    """``value`` as a proper rotation, a float ``(3, 3)`` array: finite, orthonormal (to 1e-6)
    and of determinant +1. The one rule of every rotation a user passes (a string was numpy's
    bare ValueError, a reflection turned the wood inside out)."""
    R = as_floats(value)
    if R is None or R.shape != (3, 3) or not np.all(np.isfinite(R)) or not np.allclose(R @ R.T, np.eye(3), atol=1e-6) \
            or np.linalg.det(R) < 0:
        _fail(name, "a proper 3x3 rotation matrix (orthonormal, det +1)", value, fix)
    return R


def check_names(value, name: str, *, what: str, known: Iterable[str] | None = None,
                empty: bool = False, fix: str = "") -> list[str]:
    """``value`` as a non-empty list of names (each a ``str``; with ``known``: each one of
    them; ``empty=True``: an empty collection too). A string was read letter by letter
    (``'radial'`` as ``'r'``, ``'a'``...), an empty list or None ran no work and returned an
    empty table or failed on an IndexError later."""
    if isinstance(value, str):
        raise WoodcamError(f"{name} must be a list of {what}; got the string {value!r}; pass [{value!r}]")
    try:
        names = list(value)
    except TypeError:  # None, a number
        names = None
    choices = list(known) if known is not None else []
    example = fix or (f"e.g. {name}=[{choices[0]!r}]" if choices else "")
    if names is None or (not names and not empty) or not all(isinstance(n, str) for n in names):
        _fail(name, f"a {'' if empty else 'non-empty '}list of {what}", value, example)
    unknown = [n for n in names if known is not None and n not in choices]
    if unknown:
        near = did_you_mean(unknown[0], choices)
        raise WoodcamError(f"{name} must be {what} from {', '.join(choices)}; got {unknown[0]!r}"
                           + (f"; {near}" if near else ""))
    return names


def check_path(value, name: str, *, fix: str = "") -> Path:
    """``value`` (a ``str`` or ``os.PathLike``, not empty) as a ``Path``. None, a number or a
    list was ``Path()``'s bare TypeError ("expected str, bytes or os.PathLike object")."""
    if isinstance(value, bool) or not isinstance(value, (str, os.PathLike)) or str(value) == "":
        _fail(name, "a file path (str or pathlib.Path)", value, fix)
    return Path(value)


def png_path(path, name: str) -> Path:
    """``path`` (:func:`check_path`) as a PNG file to write: ending in ``.png`` in any case,
    refused otherwise with the name to give (PIL picks the format from the suffix: a name
    without one failed in the temporary's ``.tmp`` as "unknown file extension: .tmp"). The one
    rule of the PNG writers that take a path."""
    p = check_path(path, name, fix="a .png file path")
    if p.suffix.lower() != ".png":
        good = p.with_suffix(".png") if p.suffix else p.with_name(p.name + ".png")
        raise WoodcamError(f"{name} must end in .png (a PNG image is written); got {str(path)!r}; "
                           f"e.g. {str(good)!r}")
    return p


def npz_path(path) -> Path:
    """``path`` as the ``.npz`` file numpy writes: ``.npz`` appended to a name without that
    suffix; one ending in it in any case (``F.NPZ``, which ``--out`` takes) kept as named (it
    became ``F.NPZ.npz`` beside the name asked for). The one rule of every ``.npz`` writer."""
    path = Path(path)
    return path if path.suffix.lower() == ".npz" else path.with_suffix(path.suffix + ".npz")
