"""The files and folders a block spec names (:mod:`woodcam.stock` describes the specs): plain
string and path handling, below every layer that records a spec (a GLB's metadata, a parquetry
job file's ``woodcam.blocks``), so each writes it from any working folder the same way."""

from __future__ import annotations

import re
from pathlib import Path

_NUM = r"(?:\d+(?:\.\d*)?|\.\d+)"
#: A turn ``~AXIS DEGREES`` (``~z90``, ``~x-90``) and a resize ``[WxDxH]`` / ``[WxDxH@X,Y,Z]``
#: (unit-free numbers, mm), as :func:`woodcam.stock.resize_stock` appends them: only these, so
#: a path's own ``~`` or ``[...]`` (``/data/~scan/oak``, ``blocks/oak[2]``) is no operation.
_ONE_OP = (rf"~[xyzXYZ][-+]?{_NUM}"
           rf"|\[{_NUM}[xX]{_NUM}[xX]{_NUM}(?:@[-+]?{_NUM},[-+]?{_NUM},[-+]?{_NUM})?\]")
#: A spec's trailing operations, applied in order.
_OPS = re.compile(rf"(?:{_ONE_OP})+$")
_OP = re.compile(_ONE_OP)
#: The end of a base that looks like a turn or resize but is none (``~q90``, ``[40x30]``):
#: :mod:`woodcam.stock` names it as a bad operation unless the base is an existing path.
LOOSE_OP = re.compile(r"(?:~[^~\[\]/]*|\[[^\[\]/]*\])$")


def _base_path(base: str) -> Path | None:
    """The file or folder the block ``base`` (a spec without its operations) names."""
    if base.startswith("log:"):
        source = base[len("log:"):].partition("@")[0]
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


def spec_path(spec: str) -> Path | None:
    """The file or folder a block ``spec`` names (a block or sample folder, a log file, a
    woodify field), as written; None for built-in blocks and the shared ``gran1`` log."""
    return _base_path(split_spec(spec)[0])


def absolute_spec(spec: str, folder: str | Path | None = None) -> str:
    """``spec`` with any folder, log file or woodify field it names made absolute, so a file
    that records it (a GLB, a job file) reopens the same block from any working folder. A
    relative path is taken from ``folder`` (a job file's own), by default the working folder."""
    base, ops = split_spec(spec)
    path = spec_path(base)
    if path is not None and folder is not None and not path.is_absolute():
        path = Path(folder) / path
    if path is not None and base.startswith("log:"):
        _, at, rest = base.partition("@")
        base = f"log:{path.resolve()}{at}{rest}"
    elif path is not None:
        base = f"{'woodify:' if base.startswith('woodify:') else ''}{path.resolve()}"
    return base + "".join(ops)
