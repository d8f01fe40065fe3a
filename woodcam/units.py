"""Lengths in the user's unit: millimetres inside, ``mm`` or ``inch`` at the door.

Everything below the command line takes and returns millimetres (``docs/conventions.md``);
``woodcam --units inch`` converts the lengths a user types (``woodcam.cli.options``) and prints
summaries with :func:`fmt_length` / :func:`fmt_volume`. Files written stay in millimetres.

Messages (warnings, errors, G-code simulation issues) are written deep in the library, far from
``--units``: they write their lengths with :func:`say_length` / :func:`say_area` / :func:`say_volume`, which follow
the message units the command line sets for its run (:func:`message_units`); mm for a library
caller, so their text there is what it always was. A message that also goes into a file (the
part report) is made with :func:`said`, which keeps its text in mm for :func:`filed`.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Literal

Units = Literal["mm", "inch"]
#: Millimetres per unit (the inch is exactly 25.4 mm since 1959).
MM_PER_UNIT: dict[str, float] = {"mm": 1.0, "inch": 25.4}
_SYMBOL = {"mm": "mm", "inch": "in"}
#: Decimals of a length printed for the user to type back (``woodcam place``'s ``--place``
#: operations): mm to the micron (0.001 mm, the rounding of the placements themselves), inches to
#: the ten-thousandth (0.0001 in = 2.5 um), the last digit a machinist reads in each. Files written
#: keep their own precision.
TYPED_DECIMALS: dict[str, int] = {"mm": 3, "inch": 4}


def _lengths(mm, units: Units, spec: str, sep: str = "x", form: str | None = None) -> str:
    """Lengths given in mm (one, or a sequence), each written in ``units`` with the format
    ``spec``, joined by ``sep`` or put in ``form`` (one ``{}`` each), then the unit's symbol: the
    one writer of every ``fmt_*`` and ``say_*`` of lengths."""
    k = MM_PER_UNIT[units]
    # a 0-d array (np.float64(2) made one by arithmetic on arrays) is one length, not a
    # sequence; told by its ndim, not numpy, which `woodcam --help` (units via cli.options) must
    # not load
    one = getattr(mm, "ndim", None) == 0 or not hasattr(mm, "__iter__")
    texts = [f"{float(v) / k:{spec}}" for v in ([mm] if one else mm)]
    return (form.format(*texts) if form else sep.join(texts)) + f" {_SYMBOL[units]}"


def fmt_length(mm: float, units: Units = "mm", digits: int = 3) -> str:
    """A length given in mm, printed in ``units`` with its symbol:
    ``fmt_length(50.8, "inch") == "2 in"``."""
    return _lengths(mm, units, f".{digits}g")


def fmt_size(size_mm, units: Units = "mm", digits: int = 4) -> str:
    """A size ``(W, D, H)`` (or any lengths) given in mm, printed ``"WxDxH unit"`` in ``units``:
    ``fmt_size((101.6, 81.28, 50.8), "inch") == "4x3.2x2 in"``, as a block spec's size is typed."""
    return _lengths(size_mm, units, f".{digits}g")


def fmt_point(point_mm, units: Units = "mm", digits: int = 4) -> str:
    """A point given in mm, printed ``"(x, y, z) unit"`` in ``units``:
    ``fmt_point((508, 0, 12.7), "inch") == "(20, 0, 0.5) in"``."""
    return _lengths(point_mm, units, f".{digits}g", form="(" + ", ".join("{}" for _ in point_mm) + ")")


def fmt_span(lo_mm: float, hi_mm: float, units: Units = "mm", digits: int = 2) -> str:
    """A range of lengths given in mm, printed ``"lo-hi unit"`` in ``units``:
    ``fmt_span(1, 3) == "1-3 mm"``, ``fmt_span(1, 3, "inch") == "0.039-0.12 in"``."""
    return _lengths((lo_mm, hi_mm), units, f".{digits}g", "-")


def fmt_volume(mm3: float, units: Units = "mm") -> str:
    """A volume given in mm^3, printed in ``units``^3: ``"1234 mm^3"`` or ``"0.07531 in^3"``;
    under 1000 mm^3 four significant digits, as inches get (``"1.518 mm^3"``, not ``"2 mm^3"``);
    never in exponent form (a 60x50x20 in block's leftover was '6e+04 in^3')."""
    if units == "mm":
        return f"{mm3:.0f} mm^3" if abs(mm3) >= 1000 else f"{_no_exponent(mm3, '.4g')} mm^3"
    return f"{_no_exponent(mm3 / MM_PER_UNIT[units] ** 3, '.4g')} {_SYMBOL[units]}^3"


#: The unit messages speak in for this run (:func:`message_units`); a plain global, not a context
#: variable: messages are also written in worker threads, which a context variable does not reach.
_message_units: Units = "mm"


@contextmanager
def message_units(units: Units | None) -> Iterator[None]:
    """Within the block, :func:`say_length` / :func:`say_volume` write ``units`` (None: mm); the
    CLI sets it to ``--units`` for the whole run of a command."""
    global _message_units
    before, _message_units = _message_units, units or "mm"
    try:
        yield
    finally:
        _message_units = before


def message_unit() -> str:
    """The symbol of the message units (:func:`message_units`): ``"mm"``, or ``"in"`` under
    ``--units inch``, for a message that names the unit lengths are read in."""
    return _SYMBOL[_message_units]


def message_mm_per_unit() -> float:
    """Millimetres per message unit (:func:`message_units`): 1, or 25.4 under ``--units inch``,
    for a message that writes a spec's plain numbers as the user types them."""
    return MM_PER_UNIT[_message_units]


def say_length(mm, spec: str = ".3g", sep: str = "x", form: str | None = None, *,
               units: Units | None = None) -> str:
    """A length (or several) given in mm, for a message, in the message units
    (:func:`message_units`), one unit symbol after them: in mm with the format ``spec`` the
    message always used, in inches with four significant digits. Several are joined by ``sep``,
    or put in ``form`` (one ``{}`` each): ``say_length(4.6, ".3f") == "4.600 mm"``,
    ``say_length((1, 2, 3)) == "1x2x3 mm"``, ``say_length((1, 2), form="[{}, {}]") ==
    "[1, 2] mm"``; under ``--units inch`` ``"0.1811 in"``, ``"0.03937x0.07874x0.1181 in"``.
    ``units`` (a summary's, not a message's) overrides the message units."""
    units = units or _message_units
    return _lengths(mm, units, spec if units == "mm" else ".4g", sep, form)


def typed_length(mm: float, tol_mm: float, ok: Callable[[float], bool] | None = None) -> str:
    """A length given in mm as a number the user types in the message units
    (:func:`message_units`), as a spec a message offers: the shortest that reads back (times
    :func:`message_mm_per_unit`) within ``tol_mm`` of ``mm`` and, with ``ok``, whose read-back
    mm value ``ok`` accepts (a fix's resize must still fit its block); 12 significant digits
    when none does (``typed_length(100, 1e-4)`` under ``--units inch`` is
    ``"3.93701"``, not ``"3.93700787402"``; ``typed_length(38.1, 1e-4)`` ``"1.5"``)."""
    k = message_mm_per_unit()
    for decimals in range(13):  # fixed, never '4e+01' nor '1e-07' for 40 and about 0
        text = f"{mm / k:.{decimals}f}"
        text = "0" if float(text) == 0 else text  # not '-0'
        back = float(text) * k
        if abs(back - mm) <= tol_mm and (ok is None or ok(back)):
            return text
    return f"{mm / k:.12g}"


def say_volume(mm3: float, spec: str = ".4g", *, units: Units | None = None) -> str:
    """A volume given in mm^3, for a message, in the message units (:func:`message_units`) or
    ``units``: in mm^3 with the message's ``spec``, else :func:`fmt_volume`'s inches^3."""
    units = units or _message_units
    return f"{_no_exponent(mm3, spec)} mm^3" if units == "mm" else fmt_volume(mm3, units)


def _no_exponent(value: float, spec: str) -> str:
    """``value`` with ``spec``, never in exponent form: a large one written out as the rounded
    whole number it is (``.4g`` of 110000 mm^3 was '1.1e+05' beside '120000 mm^3' in one message,
    the part sticking out of its block), a small one as the decimals of its significant digits
    (a 1 mm^3 part baked under ``--units inch`` was '6.102e-05 in^3', now '0.00006102 in^3')."""
    text = f"{value:{spec}}"
    if "e+" in text:
        return f"{float(text):.0f}"
    if "e-" in text:
        mantissa, exponent = text.split("e-")
        decimals = len(mantissa.partition(".")[2]) + int(exponent)
        return f"{float(text):.{decimals}f}"
    return text


def say_area(mm2: float, spec: str = ".4g", *, units: Units | None = None) -> str:
    """An area given in mm^2, for a message, in the message units (:func:`message_units`) or
    ``units``: in mm^2 with the message's ``spec``, in inches^2 with four significant digits:
    ``say_area(645.16) == "645.2 mm^2"``, under ``--units inch`` ``"1 in^2"``."""
    units = units or _message_units
    if units == "mm":
        return f"{_no_exponent(mm2, spec)} mm^2"
    return f"{_no_exponent(mm2 / MM_PER_UNIT[units] ** 2, '.4g')} {_SYMBOL[units]}^2"


class _Said(str):
    """A message in the message units that keeps its text in mm (:func:`said`)."""

    in_mm: str


def said(make: Callable[[], str]) -> str:
    """The message ``make()`` builds (with :func:`say_length` ...) in the message units, keeping
    its text in mm for a file (:func:`filed`): files written stay in millimetres whatever
    ``--units`` says, while the same warning on the terminal follows it."""
    if _message_units == "mm":  # the same text either way: build it once
        return make()
    text = _Said(make())
    with message_units("mm"):
        text.in_mm = make()
    return text


def filed(message: str) -> str:
    """A message's text for a file: in mm when :func:`said` made it, else as it is."""
    return getattr(message, "in_mm", message)


def parse_lengths(text: str, n: int = 3, *, max_mm: float, cube: bool = False) -> tuple[float, ...] | None:
    """``"WxDxH"`` (``x``, ``×`` or ``,`` between them) -> ``n`` lengths in mm, each finite and in
    (0, ``max_mm``]; with ``cube`` one number is a cube's side. None when the text is not that:
    the caller names its option or spec in the error. The one parser of every size a user types
    (``--stock``, ``--size-mm``, ``--sheet-size``, a block spec's ``:WxDxH`` ...)."""
    try:
        vals = tuple(float(v) for v in re.split(r"[x×,]", str(text).lower()))
    except ValueError:
        return None
    if cube and len(vals) == 1:
        vals = vals * 3
    if len(vals) != n or not all(math.isfinite(v) and 0 < v <= max_mm for v in vals):
        return None
    return vals
