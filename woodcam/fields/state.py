"""Saving and restoring fields as JSON: ``{"type": "module:QualName", "state": to_dict()}``.

Only woodcam's own classes with ``to_dict()`` / ``from_dict()`` are saved, and only they are
restored: a manifest must never make woodcam import arbitrary code.
"""

from __future__ import annotations

import importlib
import json
import os
from pathlib import Path

import numpy as np

from ..errors import WoodcamError
from .._types import GrowthFieldLike


def field_type(obj) -> str:
    """``"module:QualName"`` of an object's class."""
    cls = type(obj)
    return f"{cls.__module__}:{cls.__qualname__}"


def jsonable(obj, what: str):
    """Convert numpy scalars/arrays inside ``obj`` to plain JSON types, or raise naming ``what``."""
    def default(o):
        if isinstance(o, np.generic):
            return o.item()
        if isinstance(o, np.ndarray):
            return o.tolist()
        if isinstance(o, (Path, os.PathLike)):
            return str(o)
        if isinstance(o, (set, tuple)):
            return list(o)
        raise TypeError(type(o).__name__)
    try:
        # strict: a NaN is written as a bare NaN, which read_block (strict JSON) then refuses
        return json.loads(json.dumps(obj, default=default, allow_nan=False))
    except (TypeError, ValueError) as err:
        raise WoodcamError(
            f"{what} must be JSON-serialisable (numbers, strings, lists, dicts, numpy arrays); "
            f"found a {err}"
        ) from err


def is_saveable(field) -> bool:
    """Whether :func:`field_to_state` can save ``field``."""
    return (field_type(field).startswith("woodcam.") and hasattr(field, "to_dict")
            and hasattr(type(field), "from_dict"))


def field_to_state(field: GrowthFieldLike) -> dict:
    """``{"type": "module:QualName", "state": field.to_dict()}`` for a woodcam field class."""
    kind = field_type(field)
    if not is_saveable(field):
        raise WoodcamError(
            f"field of type {kind!r} must be a woodcam class with to_dict()/from_dict() to be saved"
        )
    return {"type": kind, "state": jsonable(field.to_dict(), f"{kind}.to_dict()")}


#: Classes that moved, under the names older saved files carry (read without importing the old,
#: higher module: ``fields`` never imports ``synth``).
_MOVED = {"woodcam.synth:AnalyticLogField": "woodcam.fields.analytic:AnalyticLogField"}


def field_from_state(d: dict, *, fix: str | None = None) -> GrowthFieldLike:
    """Inverse of :func:`field_to_state`.

    fix : the fix a malformed ``d`` is refused with (a type this version lacks says "upgrade
        woodcam" whatever it is); default for a library caller ("pass what field_to_state
        returned"). A reader of a file passes one naming the file.
    """
    if not (isinstance(d, dict) and isinstance(d.get("type"), str) and isinstance(d.get("state"), dict)):
        raise WoodcamError(f"a saved field must be a dict {{'type': 'module:Class', 'state': {{...}}}}; got "
                           f"{d!r:.200}; {fix or 'pass what field_to_state returned'}")
    kind = _MOVED.get(d["type"], d["type"])
    module, _, qualname = kind.partition(":")
    if not module.startswith("woodcam."):
        raise WoodcamError(f"field type must be a woodcam class; got {kind!r}; "
                           f"{fix or 'pass what field_to_state returned'}")
    try:
        obj = importlib.import_module(module)
        for part in qualname.split("."):
            obj = getattr(obj, part)
    except (ImportError, AttributeError) as err:
        raise WoodcamError(
            f"field type {kind!r} cannot be imported from this woodcam version; upgrade woodcam "
            "or drop the saved field"
        ) from err
    try:
        return obj.from_dict(d["state"])
    except WoodcamError:  # a ValueError too: already says what is wrong
        raise
    except (KeyError, TypeError, IndexError, ValueError, AttributeError) as err:
        # a state missing a key, of the wrong kind, or ragged (np.asarray of [[1, 2], [3]])
        raise WoodcamError(f"the saved state of field type {kind!r} is incomplete or malformed "
                           f"({type(err).__name__}: {err}); "
                           f"{fix or 'pass what field_to_state returned for it'}") from err
