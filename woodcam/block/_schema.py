"""The ``block.json`` schema, checked at the door: types, ranges, required keys, finite numbers,
file references confined to the block folder.

:func:`check_manifest` walks a parsed manifest once and raises
:class:`~woodcam.errors.WoodcamError` naming the key path (``faces.top.traces[3].year``), the
rule, the value received and a fix, so nothing downstream meets a string where a number belongs,
a NaN, a year of 1e12 or a ring-map depth of 0 bits. Written by hand rather than with a JSON
Schema library because the rules that matter most are not expressible there: file references
resolved against the folder (symlinks included) and size limits that depend on other keys.

Limits (:mod:`woodcam.limits`): ``MAX_BLOCK_SIZE_MM``, ``MAX_FACE_PX``, ``MAX_TRACE_POINTS``,
``MAX_RING_YEAR``; each error names the limit.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

from ..errors import WoodcamError
from ..frames import FACES
from .block import trace_bounds_px

#: Environment variable that lets manifests name files outside their folder (absolute or ``..``).
ALLOW_OUTSIDE_ENV = "WOODCAM_ALLOW_OUTSIDE_PATHS"


def allow_outside_default() -> bool:
    return os.environ.get(ALLOW_OUTSIDE_ENV, "") not in ("", "0", "false", "no")


def confined_path(folder: Path, rel: Any, where: str, allow_outside: bool = False) -> Path:
    """``folder / rel`` after checking that ``rel`` is a relative file name that stays inside
    ``folder`` (no absolute path, no ``..``, no symlink leading out), unless ``allow_outside``."""
    if not isinstance(rel, str) or not rel or "\x00" in rel:
        raise WoodcamError(f"{where} must be a file name (string) relative to the block folder; "
                           f"got {rel!r}")
    p = Path(rel)
    if allow_outside:
        return p if p.is_absolute() else folder / p
    if p.is_absolute() or ".." in p.parts:
        raise WoodcamError(
            f"{where} = {rel!r} points outside the block folder {str(folder)!r}; manifests may "
            f"only name files inside their folder (copy the file in, or set {ALLOW_OUTSIDE_ENV}=1 "
            "/ pass allow_outside=True if you trust this manifest)")
    full = folder / p
    root = folder.resolve()
    try:
        full.resolve().relative_to(root)
    except ValueError:
        raise WoodcamError(
            f"{where} = {rel!r} is a link leading outside the block folder {str(folder)!r}; "
            f"copy the file in, or set {ALLOW_OUTSIDE_ENV}=1 if you trust this manifest") from None
    return full


class _Checker:
    def __init__(self, src: str):
        self.src = src

    def fail(self, where: str, rule: str, value: Any, fix: str = "") -> None:
        shown = repr(value)
        if len(shown) > 80:
            shown = shown[:77] + "..."
        raise WoodcamError(f"{self.src}: {where} {rule}; got {shown}" + (f"; {fix}" if fix else ""))

    def obj(self, v, where) -> dict:
        if not isinstance(v, dict):
            self.fail(where, "must be a JSON object", v)
        return v

    def lst(self, v, where, max_len: int | None = None, limit_name: str = "") -> list:
        if not isinstance(v, list):
            self.fail(where, "must be a JSON list", v)
        if max_len is not None and len(v) > max_len:
            self.fail(where, f"must have at most {max_len} items (limit {limit_name})",
                      f"{len(v)} items", f"raise it with WOODCAM_{limit_name}=N if this is intended")
        return v

    def num(self, v, where, lo=-math.inf, hi=math.inf, lo_open=False) -> float:
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            self.fail(where, "must be a number", v)
        try:
            f = float(v)
        except OverflowError:
            f = math.inf
        if not math.isfinite(f):
            self.fail(where, "must be a finite number", v)
        if f < lo or f > hi or (lo_open and f <= lo):
            self.fail(where, f"must be in {'(' if lo_open else '['}{lo:g}, {hi:g}]", v)
        return f

    def int_(self, v, where, lo: int, hi: int) -> int:
        if isinstance(v, bool) or not isinstance(v, int):
            if isinstance(v, float) and v.is_integer() and math.isfinite(v):
                v = int(v)
            else:
                self.fail(where, "must be an integer", v)
        if not lo <= v <= hi:
            self.fail(where, f"must be an integer in [{lo}, {hi}]", v)
        return v

    def opt_str(self, v, where) -> str | None:
        if v is not None and not isinstance(v, str):
            self.fail(where, "must be a string or null", v)
        return v or None


def check_manifest(m: Any, folder: Path, src: str, allow_outside: bool | None = None) -> dict:
    """Validate a parsed ``block.json`` (see :mod:`woodcam.block.io` for the format) and return
    it with every file reference replaced by its checked absolute ``Path`` under ``"_paths"``.

    Raises WoodcamError on the first problem, naming its key path.
    """
    from ..limits import limit
    from .io import FORMAT, VERSION

    MAX_BLOCK_SIZE_MM, MAX_FACE_PX = limit("MAX_BLOCK_SIZE_MM"), int(limit("MAX_FACE_PX"))
    MAX_RING_YEAR, MAX_TRACE_POINTS = int(limit("MAX_RING_YEAR")), int(limit("MAX_TRACE_POINTS"))

    if allow_outside is None:
        allow_outside = allow_outside_default()
    c = _Checker(src)
    c.obj(m, "the manifest")
    if m.get("format") != FORMAT:
        c.fail('"format"', f'must be "{FORMAT}"', m.get("format"))
    if "version" in m:
        c.int_(m["version"], '"version"', 1, VERSION)
    if "name" in m and not isinstance(m["name"], str):
        c.fail('"name"', "must be a string", m["name"])
    if "size_mm" not in m:
        c.fail('"size_mm"', "is required: the block's [W, D, H] in mm", None)
    size = c.lst(m["size_mm"], '"size_mm"')
    if len(size) != 3:
        c.fail('"size_mm"', "must be [W, D, H]", size)
    for i, s in enumerate(size):
        c.num(s, f"size_mm[{i}]", 0.0, MAX_BLOCK_SIZE_MM, lo_open=True)
    if "meta" in m:
        c.obj(m["meta"], '"meta"')
    paths: dict[str, Path] = {}

    def ref(rel, where):
        paths[where] = confined_path(folder, rel, f"{src}: {where}", allow_outside)

    faces = c.obj(m.get("faces", {}), '"faces"')
    for name, entry in faces.items():
        w = f"faces.{name}"
        if name not in FACES:
            c.fail(f'face name "{name}"', f"must be one of {', '.join(FACES)}", name)
        c.obj(entry, w)
        if "shape" not in entry:
            c.fail(f"{w}.shape", "is required: [n_rows, n_cols] in pixels", None)
        shape = c.lst(entry["shape"], f"{w}.shape")
        if len(shape) != 2:
            c.fail(f"{w}.shape", "must be [n_rows, n_cols]", shape)
        rows, cols = (c.int_(v, f"{w}.shape[{i}]", 1, MAX_FACE_PX) for i, v in enumerate(shape))
        for key in ("photo", "ring_map", "traces_svg"):
            if c.opt_str(entry.get(key), f"{w}.{key}"):
                ref(entry[key], f"{w}.{key}")
        if entry.get("ring_map") and "ring_map_bits" in entry:
            bits = entry["ring_map_bits"]
            if isinstance(bits, bool) or bits not in (8, 16):
                c.fail(f"{w}.ring_map_bits", "must be 8 or 16 (the PNG's bit depth)", bits)
        traces = c.lst(entry.get("traces", []), f"{w}.traces")
        (lo_r, lo_c), (hi_r, hi_c) = (b.tolist() for b in trace_bounds_px((rows, cols)))
        for k, t in enumerate(traces):
            tw = f"{w}.traces[{k}]"
            c.obj(t, tw)
            year = t.get("year")
            if year is not None:
                c.int_(year, f"{tw}.year", -MAX_RING_YEAR, MAX_RING_YEAR)
            if "points_px" not in t:
                c.fail(f"{tw}.points_px", "is required: [[row, col], ...]", None)
            pts = c.lst(t["points_px"], f"{tw}.points_px", MAX_TRACE_POINTS, "MAX_TRACE_POINTS")
            if len(pts) < 2:
                c.fail(f"{tw}.points_px", "must hold at least 2 points", pts)
            for j, p in enumerate(pts):
                if not isinstance(p, list) or len(p) != 2:
                    c.fail(f"{tw}.points_px[{j}]", "must be [row, col]", p)
                # within the face image, with half a face of slack for traces drawn past an edge
                c.num(p[0], f"{tw}.points_px[{j}][0] (row)", lo_r, hi_r)
                c.num(p[1], f"{tw}.points_px[{j}][1] (col)", lo_c, hi_c)
        extras = c.obj(entry.get("extras", {}), f"{w}.extras")
        for key, ex in extras.items():
            ew = f"{w}.extras.{key}"
            c.obj(ex, ew)
            if "png" in ex:
                ref(ex["png"], f"{ew}.png")
                if ex.get("dtype", "uint8") not in ("bool", "uint8", "uint16"):
                    c.fail(f"{ew}.dtype", "must be bool, uint8 or uint16", ex.get("dtype"))
            elif "json" not in ex:
                c.fail(ew, 'must hold "png" (an image file) or "json" (a value)', ex)
    tf = m.get("true_field")
    if tf is not None:
        c.obj(tf, '"true_field"')
        if tf.get("saved"):
            kind = tf.get("type")
            if not isinstance(kind, str) or not kind.startswith("woodcam."):
                c.fail("true_field.type", 'must name a woodcam class ("woodcam.module:Class")', kind)
            ref(tf.get("file"), "true_field.file")
    out = dict(m)
    out["_paths"] = paths
    return out
