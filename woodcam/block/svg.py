"""Ring traces as SVG: draw or correct them over a face photo in any vector editor (Inkscape).

An SVG here covers one face image: its ``viewBox`` spans the image, ``(0, 0)`` at the image's
top-left pixel corner, one unit per pixel when written by :func:`write_traces_svg`. So a trace
vertex at continuous pixel ``(row, col)`` (pixel centres at integers, as in
:mod:`woodcam.block.block`) sits at SVG ``(x, y) = (col + 0.5, row + 0.5)``.

Reading accepts what editors write for straight strokes: ``<polyline>``, ``<polygon>``,
``<line>`` and ``<path>`` with ``M L H V Z`` commands (absolute or relative), under groups with
``translate`` / ``scale`` / ``matrix`` / ``rotate`` transforms. A stroke's year comes from a
``data-year`` attribute, or an ``id`` / ``inkscape:label`` such as ``year-12`` or ``12``;
otherwise the trace is unlabelled. Curves (``C S Q T A``) are refused with a fix: draw with
straight segments, or flatten the path in the editor (Inkscape: Extensions > Modify Path >
Flatten Beziers).
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from .._atomic import atomic_path
from ..errors import WoodcamError
from .block import Face, RingTrace

_SVG_NS = "http://www.w3.org/2000/svg"
_INKSCAPE_LABEL = "{http://www.inkscape.org/namespaces/inkscape}label"
_PALETTE = ("#e6194b", "#3cb44b", "#0082c8", "#f58230", "#911eb4", "#46f0f0", "#f032e6", "#d2f53c")


def write_traces_svg(face: Face, path, *, photo_href: str | None = None, stroke_px: float = 1.0) -> Path:
    """Write ``face``'s traces as an SVG the size of its images, optionally over its photo.

    Parameters
    ----------
    face : Face
    path : output ``.svg`` path
    photo_href : str, optional
        Image to show underneath (a path relative to the SVG, e.g. ``"front_photo.png"``).
    stroke_px : float
        Stroke width in pixels.
    """
    rows, cols = face.shape
    root = ET.Element("svg", {"xmlns": _SVG_NS, "width": str(cols), "height": str(rows),
                              "viewBox": f"0 0 {cols} {rows}"})
    if photo_href:
        ET.SubElement(root, "image", {"href": photo_href, "x": "0", "y": "0",
                                      "width": str(cols), "height": str(rows)})
    group = ET.SubElement(root, "g", {"id": f"rings-{face.name}", "fill": "none",
                                      "stroke-width": f"{stroke_px:g}"})
    for i, t in enumerate(face.traces):
        pts = " ".join(f"{c!r},{r!r}" for r, c in (t.points_px + 0.5).tolist())
        attrs = {"points": pts, "id": f"trace-{i}",
                 "stroke": "#ffffff" if t.year is None else _PALETTE[t.year % len(_PALETTE)]}
        if t.year is not None:
            attrs["data-year"] = str(int(t.year))
        ET.SubElement(group, "polyline", attrs)
    path = Path(path)
    with atomic_path(path) as tmp:
        ET.ElementTree(root).write(tmp, encoding="utf-8", xml_declaration=True)
    return path


def read_traces_svg(path, shape) -> list[RingTrace]:
    """Read ring traces drawn over a face image of ``shape = (rows, cols)`` pixels.

    The SVG's ``viewBox`` (or ``width``/``height``) is mapped onto the image, so an SVG drawn
    at another scale still lands on the right pixels.

    Returns
    -------
    list of RingTrace
        Points as continuous pixel ``(row, col)``; strokes with fewer than two points are
        skipped.
    """
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError) as err:
        raise WoodcamError(f"{str(path)!r} must be a readable SVG file; {err}") from err
    rows, cols = int(shape[0]), int(shape[1])
    vb = root.get("viewBox")
    if vb:
        x0, y0, w, h = (float(v) for v in re.split(r"[\s,]+", vb.strip()))
    else:
        x0 = y0 = 0.0
        w, h = _length(root.get("width"), cols), _length(root.get("height"), rows)
    # SVG user units -> pixel (col, row): col = (x - x0) * cols / w - 0.5
    to_px = np.array([[cols / w, 0, -x0 * cols / w], [0, rows / h, -y0 * rows / h], [0, 0, 1]])
    traces: list[RingTrace] = []
    _walk(root, to_px, traces)
    return traces


def _length(value, default: float) -> float:
    if not value:
        return float(default)
    m = re.match(r"\s*([-+0-9.eE]+)", value)
    return float(m.group(1)) if m else float(default)


def _local(tag: str) -> str:
    return tag.rsplit("}", 1)[-1]


def _transform(text: str | None) -> np.ndarray:
    """3x3 affine matrix of an SVG ``transform`` attribute."""
    m = np.eye(3)
    if not text:
        return m
    for name, args in re.findall(r"(\w+)\s*\(([^)]*)\)", text):
        a = [float(v) for v in re.split(r"[\s,]+", args.strip()) if v]
        if name == "translate":
            t = np.array([[1, 0, a[0]], [0, 1, a[1] if len(a) > 1 else 0.0], [0, 0, 1]])
        elif name == "scale":
            t = np.diag([a[0], a[1] if len(a) > 1 else a[0], 1.0])
        elif name == "matrix":
            t = np.array([[a[0], a[2], a[4]], [a[1], a[3], a[5]], [0, 0, 1]])
        elif name == "rotate":
            c, s = math.cos(math.radians(a[0])), math.sin(math.radians(a[0]))
            t = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
            if len(a) == 3:
                t = _transform(f"translate({a[1]},{a[2]})") @ t @ _transform(f"translate({-a[1]},{-a[2]})")
        else:
            raise WoodcamError(f"SVG transform {name!r} is not supported; use translate, scale, matrix or rotate")
        m = m @ t
    return m


def _year(el) -> int | None:
    for key in ("data-year", _INKSCAPE_LABEL, "id"):
        v = el.get(key)
        if v is None:
            continue
        m = re.fullmatch(r"\s*(?:year[-_ ]?)?(-?\d+)\s*", v, flags=re.IGNORECASE)
        if m:
            return int(m.group(1))
        if key == "data-year":
            raise WoodcamError(f"data-year must be an integer; got {v!r}")
    return None


def _numbers(text: str) -> list[float]:
    return [float(v) for v in re.findall(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?", text or "")]


def _path_points(d: str) -> list[np.ndarray]:
    """Polylines ``(k, 2)`` (x, y) of an SVG path made of straight segments."""
    tokens = re.findall(r"[A-Za-z]|[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?", d)
    lines, cur, pos, start, cmd, i = [], [], np.zeros(2), np.zeros(2), None, 0
    while i < len(tokens):
        tok = tokens[i]
        if tok.isalpha():
            cmd = tok
            i += 1
            if cmd in "Zz":
                if cur:
                    cur.append(start.copy())
                    lines.append(np.array(cur))
                    cur = []
                pos = start.copy()
                continue
            if cmd.upper() not in "MLHV":
                raise WoodcamError(
                    f"SVG path command {cmd!r} (a curve) is not supported for ring traces; draw "
                    "with straight segments or flatten the path (Inkscape: Extensions > Modify "
                    "Path > Flatten Beziers)"
                )
            continue
        if cmd is None:
            raise WoodcamError(f"SVG path data must start with a command; got {d[:20]!r}")
        rel = cmd.islower()
        c = cmd.upper()
        if c in "ML":
            xy = np.array([float(tokens[i]), float(tokens[i + 1])])
            i += 2
            pos = pos + xy if rel else xy
            if c == "M":
                if len(cur) >= 2:
                    lines.append(np.array(cur))
                cur, start = [pos.copy()], pos.copy()
                cmd = "l" if rel else "L"          # implicit lineto after a moveto
                continue
        else:  # H or V
            v = float(tokens[i])
            i += 1
            k = 0 if c == "H" else 1
            pos = pos.copy()
            pos[k] = pos[k] + v if rel else v
        cur.append(pos.copy())
    if len(cur) >= 2:
        lines.append(np.array(cur))
    return lines


def _walk(el, m: np.ndarray, out: list[RingTrace]) -> None:
    m = m @ _transform(el.get("transform"))
    tag = _local(el.tag)
    polylines: list[np.ndarray] = []
    if tag in ("polyline", "polygon"):
        v = _numbers(el.get("points"))
        p = np.array(v[: len(v) // 2 * 2]).reshape(-1, 2)
        polylines = [np.vstack([p, p[:1]]) if tag == "polygon" and len(p) else p]
    elif tag == "line":
        polylines = [np.array([[float(el.get(k, 0)) for k in ("x1", "y1")],
                               [float(el.get(k, 0)) for k in ("x2", "y2")]])]
    elif tag == "path":
        polylines = _path_points(el.get("d", ""))
    elif tag in ("image", "defs", "metadata", "title", "desc"):
        return
    if polylines:
        year = _year(el)
        for p in polylines:
            if len(p) < 2:
                continue
            xy = p @ m[:2, :2].T + m[:2, 2]
            out.append(RingTrace(np.stack([xy[:, 1] - 0.5, xy[:, 0] - 0.5], axis=1), year))
    for child in el:
        _walk(child, m, out)
