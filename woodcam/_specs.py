"""A block spec's grammar (:mod:`woodcam.stock` describes the specs), in one home: read once by
:func:`parse_spec` into a :class:`ParsedSpec` (the stock's reader and the command line's door
check and ``--units`` conversion all read that), written back by :func:`format_spec`, and the
files and folders a spec names: plain strings, numbers and paths, below every layer that
records a spec (a GLB's metadata, a parquetry job file's ``woodcam.blocks``), so each writes it
from any working folder the same way. Lengths in a :class:`ParsedSpec` are millimetres."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

from .errors import BlockSpecError, WoodcamError
from .limits import limit
from .units import parse_lengths

#: A number of an operation, signed, as a block's ``:WxDxH`` reads it (``+40``, ``1e2``, ``.5``)
#: and as :func:`format_op` may write it (``1e-05``); a size's sign is checked when it is read.
_NUM = r"[-+]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?"
#: A turn ``~AXIS DEGREES`` (``~z90``, ``~x-90``) and a resize ``[WxDxH]`` / ``[WxDxH@X,Y,Z]``
#: (unit-free numbers, mm), as :func:`woodcam.stock.resize_stock` appends them: only these, so
#: a path's own ``~`` or ``[...]`` (``/data/~scan/oak``, ``blocks/oak[2]``) is no operation.
_ONE_OP = (rf"~[xyzXYZ]{_NUM}"
           rf"|\[{_NUM}[xX]{_NUM}[xX]{_NUM}(?:@{_NUM},{_NUM},{_NUM})?\]")
#: A spec's trailing operations, applied in order.
_OPS = re.compile(rf"(?:{_ONE_OP})+$")
_OP = re.compile(_ONE_OP)
#: The end of a base that looks like a turn or resize but is none (``~q90``, ``[40x30]``):
#: named as a bad operation unless the base is an existing path.
_LOOSE_OP = re.compile(r"(?:~[^~\[\]/]*|\[[^\[\]/]*\])$")

#: The file ``woodcam woodify`` writes its field to, in its --out folder: what a
#: ``woodify:DIR/field.npz`` spec names (the input door offers it for a spec naming DIR).
WOODIFY_FIELD_FILE = "field.npz"

SpecKind = Literal["builtin", "log", "woodify", "folder"]
#: What part of a spec broke its grammar (:class:`woodcam.errors.BlockSpecError` ``part``).
SpecPart = Literal["size", "resize", "turn", "op", "log"]


@dataclass(frozen=True)
class ParsedSpec:
    """A block spec read once (:func:`parse_spec`); :func:`format_spec` writes it back.

    Attributes
    ----------
    spec : str
        The spec as given.
    base : str
        The block it names without its turns and resizes (:func:`split_spec`), as written.
    kind : "builtin", "log", "woodify" or "folder"
        ``folder`` is any other base: a block folder or a Mokume sample folder (checked when
        the block is read, not here).
    source : str
        The built-in block's NAME; the log's LOG (``gran1`` or a ``.json`` file); the woodify
        field file; the folder, as written.
    knot : int or None
        A log block's knot index (its range is the log's: checked when the log is read).
    size_mm : (W, D, H) float or None
        The base's own ``:WxDxH`` in mm (built-in and log blocks); None: the block's own size.
    ops : tuple of ``("turn", axis, quarters)`` and ``("resize", size_mm, origin_mm)``
        The turns (``axis`` "x", "y" or "z", ``quarters`` an int, +90 degrees each by the
        right-hand rule) and resizes (``size_mm (W, D, H)``, ``origin_mm (X, Y, Z)``: the corner
        in the frame of the block before it) in the order written. Their ``repr`` as a list is
        part of :func:`woodcam.stock.spec_digest` (GLBs record it): keep the tuple form.
    """

    spec: str
    base: str
    kind: SpecKind
    source: str
    knot: int | None
    size_mm: tuple[float, float, float] | None
    ops: tuple[tuple, ...]

    @property
    def path(self) -> Path | None:
        """The file or folder the base names (:func:`spec_path`), None for a built-in block or
        the shared ``gran1`` log."""
        return _base_path(self.base)


def _error(spec: str, rule: str, *, part: SpecPart, text: str) -> BlockSpecError:
    """The error of a spec that breaks ``rule`` in its ``part`` written ``text``."""
    return BlockSpecError(f"block spec {spec!r}: {rule}", part=part, text=text, rule=rule)


def _base_path(base: str) -> Path | None:
    """The file or folder the block ``base`` (a spec without its operations) names."""
    if base.startswith("log:"):  # the knot after the last '@': a folder 'u@host' is the path's
        body = base[len("log:"):]
        source = body[:body.rfind("@")] if "@" in body else body
        return Path(source) if source.lower().endswith(".json") else None
    if base.startswith("woodify:"):
        return Path(base[len("woodify:"):])
    return None if base.startswith("builtin:") else Path(base)


def split_spec(spec: str) -> tuple[str, list[str]]:
    """``"BASE~z90[40x30x20@5,5,5]"`` -> ``("BASE", ["~z90", "[40x30x20@5,5,5]"])``: the block
    a spec names and its trailing turns and resizes, as written; the longest base that is an
    existing file or folder keeps what it ends with (a folder named ``oak~z90``)."""
    text = str(spec)
    m = _OPS.search(text)
    ops = [] if m is None else _OP.findall(m.group())
    end = len(text)
    for k in range(len(ops), 0, -1):  # the whole spec first, then fewer of its ends kept
        path = None if text.startswith("log:") else _base_path(text[:end])
        if path is not None and path.exists():
            return text[:end], ops[k:]
        end -= len(ops[k - 1])
    return text[:end], ops


def check_read_as_is(spec: str) -> None:
    """Refuse a turn or resize on ``spec`` given to a command that reads the block as it is
    (``fit``, ``eval``, ``block show``): a WoodcamError naming them and the spec to give. The one
    home of the rule: the stock's :func:`woodcam.stock.open_block` and the command line's door
    (:func:`woodcam.cli.options.check_inputs`, exit 2) both call it. Named before the operations
    are read: such a command takes none, however written ("unknown built-in block
    'flat-sawn~z90'" was said)."""
    base, ops = split_spec(spec)
    if ops:
        kinds = sorted({"a turn" if op.startswith("~") else "a resize" for op in ops}, reverse=True)
        raise WoodcamError(
            f"block spec {spec!r}: {' and '.join(kinds)} ('{''.join(ops)}') is for the commands "
            f"that carve a part from the block (bake, gcode, place, preview, review and parquetry's "
            f"--veneer-from); this one reads the block as it is: give {base!r}")


def spec_path(spec: str) -> Path | None:
    """The file or folder a block ``spec`` names (a block or sample folder, a log file, a
    woodify field), as written; None for built-in blocks and the shared ``gran1`` log."""
    return _base_path(split_spec(spec)[0])


def parse_spec(spec: str, *, mm_per_unit: float = 1.0) -> ParsedSpec:
    """Read a block spec (see :mod:`woodcam.stock`) into a :class:`ParsedSpec`: the one reader
    of its grammar. Its lengths are read in a unit of ``mm_per_unit`` mm (the command line's
    ``--units``; 1: mm), each side in (0, :data:`~woodcam.limits.MAX_BLOCK_SIZE_MM`] once in
    mm, and returned in mm. What needs the block's data (a built-in NAME, a folder, a log file
    and its knot range) is checked when the block is read.

    Raises :class:`~woodcam.errors.BlockSpecError` (a WoodcamError naming the spec, the rule
    and a fix, its message in mm) whose ``part`` and ``text`` let the command line say it in
    the units typed.
    """
    text = str(spec)
    base, texts = split_spec(text)
    loose = _LOOSE_OP.search(base)
    path = _base_path(base)
    bad = loose.group() if loose and not (path is not None and path.exists()) else None
    if bad:  # not a turn or resize as written (~q90, [40x30]): named below as one, not a path
        texts = [bad, *texts]
    ops = tuple(_parse_op(op, text, mm_per_unit) for op in texts)
    if bad:  # read above, yet not in the grammar
        raise _error(text, f"{bad!r} is neither a turn ~AXIS then degrees nor a resize "
                             "[WxDxH] or [WxDxH@X,Y,Z] (plain numbers, mm), e.g. "
                             "'builtin:knotty~z90[40x30x20@5,5,5]'", part="op", text=bad)
    kind: SpecKind
    knot: int | None = None
    size_text = ""
    if base.startswith("builtin:"):
        kind = "builtin"
        source, _, size_text = base[len("builtin:"):].partition(":")
    elif base.startswith("log:"):
        kind = "log"
        # the knot after the last '@' (a log file in a folder 'u@host' was 'log:u' knot 'host/...')
        source, at, rest = base[len("log:"):].rpartition("@")
        knot_text, _, size_text = rest.partition(":")
        try:
            if not at:
                raise ValueError("no '@'")
            knot = int(knot_text)
        except ValueError as err:
            raise _error(base, "a log block must read 'log:LOG@KNOT' or 'log:LOG@KNOT:WxDxH' "
                                 "(e.g. log:gran1@52:100x80x50)", part="log", text=base) from err
    elif base.startswith("woodify:"):
        kind, source = "woodify", base[len("woodify:"):]
    else:
        kind, source = "folder", base
    # 0x0x0, NaN, 1e9 were accepted as a log block's size
    size = _parse_size(size_text, base, mm_per_unit, "size", size_text) if size_text else None
    return ParsedSpec(text, base, kind, source, knot, size, ops)


def _parse_op(op: str, spec: str, mm_per_unit: float) -> tuple:
    """One turn ``~AXIS DEG`` -> ``("turn", axis, quarters)`` or resize ``[WxDxH@X,Y,Z]`` ->
    ``("resize", size_mm, origin_mm)`` of ``spec``, its lengths read in ``mm_per_unit`` mm."""
    if op.startswith("["):
        size_text, at, origin_text = op[1:-1].partition("@")
        size = _parse_size(size_text, spec, mm_per_unit, "resize", op)
        try:
            origin = tuple(float(v) * mm_per_unit for v in origin_text.split(",")) if at else (0.0, 0.0, 0.0)
        except ValueError:
            origin = ()
        if len(origin) != 3 or not all(math.isfinite(v) for v in origin):
            raise _error(spec, "a resize must be [WxDxH] or [WxDxH@X,Y,Z] (the corner in mm of "
                                 f"the block before it), got {op}, e.g. 'builtin:knotty[40x30x20@5,5,5]'",
                                 part="resize", text=op)
        return ("resize", size, origin)
    part = op[1:]
    axis, deg = part[:1].lower(), part[1:]
    try:
        quarter, rest = divmod(float(deg), 90.0)
    except ValueError:
        quarter, rest = 0, 1.0
    if axis not in ("x", "y", "z") or rest != 0.0:
        raise _error(spec, f"turn '~{part}' must be ~AXIS then a multiple of 90 degrees "
                             "(AXIS x, y or z), e.g. 'builtin:flat-sawn~z90'", part="turn", text=op)
    return ("turn", axis, int(quarter))


def _parse_size(text: str, spec: str, mm_per_unit: float, part: SpecPart, part_text: str
                ) -> tuple[float, float, float]:
    """A spec's ``WxDxH`` read in ``mm_per_unit`` mm -> mm, each side at most
    :data:`woodcam.limits.MAX_BLOCK_SIZE_MM` mm."""
    cap = limit("MAX_BLOCK_SIZE_MM")
    size = parse_lengths(text, 3, max_mm=cap / mm_per_unit)
    if size is None:
        raise _error(spec, f"the size must be WxDxH in mm, each > 0 and <= {cap:g} "
                             f"(raise it with WOODCAM_MAX_BLOCK_SIZE_MM=N); got {text!r}, e.g. 300x120x40",
                     part=part, text=part_text)
    W, D, H = (v * mm_per_unit for v in size)
    return W, D, H


def _num(v: float) -> str:
    """A length in a written spec: 12 significant digits, what a float typed or converted
    from inches needs (``:g``'s six rounded 0.1234567 mm to 0.123457)."""
    return f"{v:.12g}"


def format_op(op: tuple) -> str:
    """One operation of :attr:`ParsedSpec.ops` written as a spec writes it: ``("turn", "z",
    1)`` -> ``"~z90"``, ``("resize", (40, 30, 20), (5, 5, 5))`` -> ``"[40x30x20@5,5,5]"``
    (no ``@`` at the origin ``(0, 0, 0)``), lengths in mm."""
    if op[0] == "turn":
        return f"~{op[1]}{90 * op[2]}"
    size, origin = op[1], op[2]
    at = f"@{','.join(_num(v) for v in origin)}" if any(origin) else ""
    return f"[{'x'.join(_num(v) for v in size)}{at}]"


def format_spec(parsed: ParsedSpec) -> str:
    """The spec ``parsed`` reads, written with its lengths in mm (what ``--units inch`` hands
    the stock): ``parse_spec("builtin:knotty:4x3x2~z90[1x1x1@0.5,0,0]", mm_per_unit=25.4)`` ->
    ``"builtin:knotty:101.6x76.2x50.8~z90[25.4x25.4x25.4@12.7,0,0]"``."""
    if parsed.kind == "builtin":
        head = f"builtin:{parsed.source}"
    elif parsed.kind == "log":
        head = f"log:{parsed.source}@{parsed.knot}"
    else:  # a woodify field or a folder: the base as written
        head = parsed.base
    size = "" if parsed.size_mm is None else ":" + "x".join(_num(v) for v in parsed.size_mm)
    return head + size + "".join(format_op(op) for op in parsed.ops)


def absolute_spec(spec: str, folder: str | Path | None = None) -> str:
    """``spec`` with any folder, log file or woodify field it names made absolute, so a file
    that records it (a GLB, a job file) reopens the same block from any working folder. A
    relative path is taken from ``folder`` (a job file's own), by default the working folder."""
    base, ops = split_spec(spec)
    path = _base_path(base)
    if path is not None and folder is not None and not path.is_absolute():
        path = Path(folder) / path
    if path is not None and base.startswith("log:"):
        _, at, rest = base.rpartition("@")
        base = f"log:{path.resolve()}{at}{rest}"
    elif path is not None:
        base = f"{'woodify:' if base.startswith('woodify:') else ''}{path.resolve()}"
    return base + "".join(ops)
