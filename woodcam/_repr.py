"""Short ``repr`` of the public result classes, for a notebook or a REPL.

A dataclass's own repr prints every field in full, so ``bake(...)`` showed thousands of
atlas pixels and ``read_gcode(...)`` every segment's start point before the one line that
says what the object is. :func:`summary_repr` writes arrays as their shape and dtype, long
containers as their length, and objects with the default ``<... at 0x...>`` repr by class
name; short values stay as they are.
"""

from __future__ import annotations

import dataclasses

_MAX_ITEMS = 6  # a container with more entries than this is summarised by its length
_MAX_CHARS = 120  # a value whose repr runs longer is summarised too (a notebook line)


def short(value: object) -> str:
    """``value``'s repr in at most about a line: an array as ``array(shape=(h, w, 3), dtype=uint8)``
    (one of up to 6 numbers as them, ``array([0.0, 0.0, 1.0])``),
    a long list, tuple or dict as its length (a dict with its first keys), an object whose class
    keeps ``object.__repr__`` as ``<ClassName>``."""
    shape, dtype = getattr(value, "shape", None), getattr(value, "dtype", None)
    if shape is not None and dtype is not None and hasattr(value, "__array__"):
        if getattr(value, "size", 2) == 1:
            return repr(value)
        if len(shape) == 1 and shape[0] <= _MAX_ITEMS:  # a point or a direction: its numbers
            return f"array({value.tolist()})"  # type: ignore[attr-defined]
        return f"array(shape={tuple(shape)}, dtype={dtype})"
    if isinstance(value, dict):
        if len(value) <= _MAX_ITEMS and len(text := repr(value)) <= _MAX_CHARS:
            return text
        keys = ", ".join(repr(k) for k in list(value)[:_MAX_ITEMS])
        more = ", ..." if len(value) > _MAX_ITEMS else ""
        return f"<dict of {len(value)}: {keys}{more}>"
    if isinstance(value, (list, tuple)):
        if len(value) <= _MAX_ITEMS and len(text := repr(value)) <= _MAX_CHARS:
            return text
        kind = type(value).__name__
        first = f" of {type(value[0]).__name__}" if value else ""
        return f"<{kind} of {len(value)}{first}>"
    if type(value).__repr__ is object.__repr__:
        return f"<{type(value).__module__}.{type(value).__qualname__}>"
    return repr(value)


def summary_repr(self: object, *, skip_defaults: bool = False) -> str:
    """A dataclass's repr with each shown field through :func:`short`: ``Name(a=..., b=...)``.
    Assign it as ``__repr__ = summary_repr`` in the class body (the dataclass then keeps it).
    ``skip_defaults=True`` leaves out the fields still at their declared default (a class with
    many optional tables, most of them None)."""
    parts = [f"{f.name}={short(getattr(self, f.name))}" for f in dataclasses.fields(self)  # type: ignore[arg-type]
             if f.repr and not (skip_defaults and _is_default(getattr(self, f.name), f))]
    return f"{type(self).__qualname__}({', '.join(parts)})"


def _is_default(value: object, f: dataclasses.Field) -> bool:
    """Whether ``value`` is field ``f``'s declared default: the same object, or an equal one of
    the same type that is not an array (an array's ``==`` is elementwise, never a yes or no)."""
    default = f.default
    if default is dataclasses.MISSING:
        return False
    if value is default:
        return True
    if type(value) is not type(default) or hasattr(value, "__array__"):
        return False
    try:
        return bool(value == default)
    except Exception:  # an __eq__ that cannot say: show the value
        return False


def attrs_repr(obj: object, names: tuple[str, ...]) -> str:
    """``Name(a=..., b=...)`` of the attributes ``names`` of a plain class, each through
    :func:`short` (for the classes that are not dataclasses: a field, :class:`~woodcam.Wood`)."""
    return f"{type(obj).__qualname__}({', '.join(f'{n}={short(getattr(obj, n, None))}' for n in names)})"
