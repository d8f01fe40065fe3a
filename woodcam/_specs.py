"""The files and folders a block spec names (:mod:`woodcam.stock` describes the specs): plain
string and path handling, below every layer that records a spec (a GLB's metadata, a parquetry
job file's ``woodcam.blocks``), so each writes it from any working folder the same way."""

from __future__ import annotations

import re
from pathlib import Path

#: A spec's trailing operations, applied in order: turns ``~AXIS90`` and the resizes
#: ``[WxDxH]`` / ``[WxDxH@X,Y,Z]`` that :func:`woodcam.stock.resize_stock` appends.
_OPS = re.compile(r"(?:~[^~\[\]]*|\[[^\[\]]*\])+$")
_OP = re.compile(r"~[^~\[\]]*|\[[^\[\]]*\]")


def split_spec(spec: str) -> tuple[str, list[str]]:
    """``"BASE~z90[40x30x20@5,5,5]"`` -> ``("BASE", ["~z90", "[40x30x20@5,5,5]"])``: the block
    a spec names and its trailing turns and resizes, as written."""
    text = str(spec)
    m = _OPS.search(text)
    return (text, []) if m is None else (text[:m.start()], _OP.findall(m.group()))


def spec_path(spec: str) -> Path | None:
    """The file or folder a block ``spec`` names (a block or sample folder, a log file, a
    woodify field), as written; None for built-in blocks and the shared ``gran1`` log."""
    base = split_spec(spec)[0]
    if base.startswith("log:"):
        source = base[len("log:"):].partition("@")[0]
        return Path(source) if source.lower().endswith(".json") else None
    if base.startswith("woodify:"):
        return Path(base[len("woodify:"):])
    return None if base.startswith("builtin:") else Path(base)


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
