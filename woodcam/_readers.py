"""Reading untrusted text files at the door: strict JSON (no NaN/Infinity, bounded nesting),
every failure a :class:`~woodcam.errors.WoodcamError` naming the file.

Used by every reader of user files (``block.json``, log files, true-field files); it sits at
the bottom of the import layering so ``fields`` and ``block`` can both use it.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from .errors import WoodcamError

__all__ = ["read_json_file", "strict_json_loads"]


def strict_json_loads(text: str, what: str) -> Any:
    """``json.loads`` that refuses NaN/Infinity and maps every failure to a WoodcamError."""
    def _no_constant(c):
        raise ValueError(f"non-finite number {c} is not allowed")

    try:
        return json.loads(text, parse_constant=_no_constant)
    except (ValueError, RecursionError) as err:  # JSONDecodeError is a ValueError
        raise WoodcamError(f"{what} must be valid JSON with finite numbers; {err}") from err


def read_json_file(path: Path, what: str) -> Any:
    """Read and strictly parse a JSON file; unreadable or non-UTF-8 files are WoodcamErrors."""
    try:
        text = Path(path).read_bytes().decode("utf-8")
    except OSError as err:
        raise WoodcamError(f"{what}: cannot read {str(path)!r} ({err.strerror})") from err
    except UnicodeDecodeError as err:
        raise WoodcamError(f"{what}: {str(path)!r} is not UTF-8 text ({err.reason})") from err
    return strict_json_loads(text, f"{what} {str(path)!r}")
