"""Ring traces as SVG: draw or correct them over a face photo in any vector editor (Inkscape).

An SVG here covers one face image: its ``viewBox`` spans the image, ``(0, 0)`` at the image's
top-left pixel corner, one unit per pixel when written by :func:`write_traces_svg`. So a trace
vertex at continuous pixel ``(row, col)`` (pixel centres at integers, as in
:mod:`woodcam.block.block`) sits at SVG ``(x, y) = (col + 0.5, row + 0.5)``.

Reading goes through svgelements (a maintained SVG library), so whatever an editor writes lands
where it is drawn: ``<path>`` (every command, curves ``C S Q T A`` included, sampled every
:data:`~woodcam.tolerances.SVG_CURVE_STEP_PX` image pixels), ``<polyline>``, ``<polygon>`` and
``<line>``; transforms on the shapes and on the layer groups around them; ``width``/``height``
in any unit (``mm``, ``in``, ``px``) with or without a ``viewBox``. The face photo's ``<image>``
(the SVG's one image, as written) is mapped onto the face image, so a page an editor grew or
moved round it changes nothing; without one image, the drawing's width and height are. Strokes
the editor hides (``visibility:hidden``, ``display:none``, ``opacity:0``, ``stroke:none``, ...:
:func:`_shown_shapes`) are no traces. A stroke's year comes from its own ``data-year``
attribute, or an ``id`` / ``inkscape:label`` such as ``year-12`` or ``12``; otherwise the trace
is unlabelled (a layer's label is not a year of the strokes in it). A stroke's ``data-ring``
(written by the ring detector: pieces of one ring share it, see :class:`RingTrace`) is kept;
give a redrawn piece the same ``data-ring`` as the rest of its ring, or delete the attribute.
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from .._atomic import atomic_path
from ..errors import WoodcamError
from .block import Face, RingTrace, trace_bounds_px

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
    root = ET.Element("svg", {"xmlns": _SVG_NS, "xmlns:xlink": "http://www.w3.org/1999/xlink",
                              "width": str(cols), "height": str(rows), "viewBox": f"0 0 {cols} {rows}"})
    if photo_href:
        # xlink:href, not SVG 2's plain href: SVG 1.1 readers (Inkscape before 1.3) see only the
        # former, and every browser and SVG 2 reader still reads it
        ET.SubElement(root, "image", {"xlink:href": photo_href, "x": "0", "y": "0",
                                      "width": str(cols), "height": str(rows)})
    group = ET.SubElement(root, "g", {"id": f"rings-{face.name}", "fill": "none",
                                      "stroke-width": f"{stroke_px:g}"})
    for i, t in enumerate(face.traces):
        pts = " ".join(f"{c!r},{r!r}" for r, c in (t.points_px + 0.5).tolist())
        attrs = {"points": pts, "id": f"trace-{i}",
                 "stroke": "#ffffff" if t.year is None else _PALETTE[t.year % len(_PALETTE)]}
        if t.year is not None:
            attrs["data-year"] = str(int(t.year))
        if t.ring is not None:
            attrs["data-ring"] = str(int(t.ring))
        ET.SubElement(group, "polyline", attrs)
    path = Path(path)
    with atomic_path(path) as tmp:
        ET.ElementTree(root).write(tmp, encoding="utf-8", xml_declaration=True)
    return path


def read_traces_svg(path, shape) -> list[RingTrace]:
    """Read ring traces drawn over a face image of ``shape = (rows, cols)`` pixels.

    The face photo's ``<image>`` (the SVG's one image; without one, its drawing area:
    ``width``/``height`` in any unit, through its ``viewBox``) is mapped onto the image, so an
    SVG drawn at another scale or in mm, or whose page was grown round the photo, still lands on
    the right pixels.

    Returns
    -------
    list of RingTrace
        Points as continuous pixel ``(row, col)``, in document order; strokes with fewer than
        two points are skipped.
    """
    import svgelements

    try:
        svg = svgelements.SVG.parse(str(path), reify=True)
    except (ET.ParseError, OSError, ValueError) as err:
        # a file cut short (an editor's crash, a copy interrupted) was named with no way out
        raise WoodcamError(f"{str(path)!r} must be a readable SVG file; {err}; save it again from your SVG "
                           "editor (Inkscape: File > Save), or delete it to have 'woodcam rings detect' trace "
                           "the face afresh") from err
    rows, cols = int(shape[0]), int(shape[1])
    if not (svg.width and svg.height and svg.width > 0 and svg.height > 0):
        raise WoodcamError(f"{str(path)!r} has no drawing size: give the <svg> a viewBox or a "
                           "width and height")
    # document units -> image pixels: the face photo's rectangle where the SVG holds one image (the
    # photo the strokes are drawn over), else the drawing's page. The page alone misplaced every
    # stroke once an editor grew the page round the photo (Inkscape's 'resize page to drawing'
    # with a stroke past the photo's edge): a stroke drawn at (20, 20) on the photo was read at
    # pixel (27.3, 27.3) of a page grown by 10 on each side.
    origin, extent = np.zeros(2), np.array([svg.width, svg.height], float)
    photo = _photo_rect([el for el in svg.elements() if isinstance(el, svgelements.Image)])
    if photo is not None:
        origin, extent = photo
    scale = np.array([cols, rows]) / extent
    lo, hi = trace_bounds_px((rows, cols))
    traces: list[RingTrace] = []
    for el in _shown_shapes(svg):
        if not isinstance(el, (svgelements.Path, svgelements.Polyline, svgelements.SimpleLine)):
            continue  # Polygon is a Polyline; rects, circles, images and text are no traces
        try:  # the file and the element in the message: a folder has six SVGs
            year = _year(el.values.get("attributes", {}))
            ring = _ring(el.values.get("attributes", {}))
        except WoodcamError as err:
            raise WoodcamError(f"{str(path)!r}, element {el.values.get('id') or type(el).__name__}: {err}") from err
        if isinstance(el, svgelements.Polyline):
            _check_points_attribute(el.values.get("points"), path)
        elif isinstance(el, svgelements.Path) and re.search(r"nan|inf", str(el.values.get("d", "")), re.IGNORECASE):
            # svgelements drops the token and reads on, as in a polyline's points
            raise WoodcamError(f"{str(path)!r}: a path's data must hold finite numbers; got "
                               f"{str(el.values.get('d'))[:80]!r}")
        path_ = el if isinstance(el, svgelements.Path) else svgelements.Path(el)
        for xy in _polylines(path_, scale):
            if len(xy) >= 2:
                px = (xy - origin) * scale
                rc = np.stack([px[:, 1] - 0.5, px[:, 0] - 0.5], axis=1)
                # the Face's rule (trace_bounds_px), said here in the SVG's terms: it was 'trace 20 of
                # face 'front' lies beyond its 256x256 px image; check its (row, col) pixel coordinates'
                out = ((rc < lo) | (rc > hi)).any(axis=1)
                if out.any():
                    x, y = xy[int(np.argmax(out))]
                    raise WoodcamError(
                        f"{str(path)!r}, element {el.values.get('id') or type(el).__name__}: a stroke runs to "
                        f"({x:.6g}, {y:.6g}), more than half the face past its edge (the face spans "
                        f"{origin[0]:g}..{origin[0] + extent[0]:g} x {origin[1]:g}..{origin[1] + extent[1]:g} in the "
                        f"drawing, its photo {cols}x{rows} px); move the stroke onto the face or delete it")
                traces.append(RingTrace(rc, year, ring))
    return traces


def _opacity(value, what: float) -> float:
    """An ``opacity`` / ``stroke-opacity`` value (``0.5``, ``50%``) as a number; ``what`` when
    there is none or it is no number (a browser ignores it too)."""
    if value is None:
        return what
    text = str(value).strip()
    try:
        v = float(text[:-1]) / 100.0 if text.endswith("%") else float(text)
    except ValueError:
        return what
    return v if math.isfinite(v) else what


def _shown_shapes(group, stroke: str | None = None, opacity: float = 1.0):
    """The shapes under svgelements ``group`` (document order) whose stroke an editor shows: not
    ``visibility:hidden`` (or ``collapse``), not at ``opacity`` 0 (its own times its groups'),
    nor with ``stroke:none`` given (its own or its group's), a transparent stroke
    (``stroke-opacity:0``, ``transparent``) or ``stroke-width:0``. Strokes an editor hides were
    read as ring traces (a ring hidden instead of deleted counted). svgelements itself leaves out
    ``display:none`` (the element or a group round it, Inkscape's hidden layers) and ``<defs>``.
    A stroke with no ``stroke`` at all (a hand-written ``<path d="..."/>``) is a trace, as before:
    svgelements says ``none`` for it too, so only a ``stroke`` the file gives is read here."""
    import svgelements

    for el in group:
        attributes = getattr(el, "values", {}).get("attributes", {})
        own_stroke = attributes.get("stroke", stroke)
        own_opacity = opacity * _opacity(attributes.get("opacity"), 1.0)
        if isinstance(el, (svgelements.Group, svgelements.Use)):
            yield from _shown_shapes(el, own_stroke, own_opacity)
            continue
        values = getattr(el, "values", {})
        colour = getattr(el, "stroke", None)
        width = getattr(el, "stroke_width", None)
        if (str(values.get("visibility", "visible")).strip().lower() in ("hidden", "collapse")
                or own_opacity <= 0.0
                or (own_stroke is not None and own_stroke.strip().lower() == "none")
                or _opacity(values.get("stroke-opacity"), 1.0) <= 0.0
                or (own_stroke is not None and colour is not None and colour.value is not None and colour.alpha == 0)
                or (width is not None and width <= 0.0)):
            continue
        yield el


def _photo_rect(images: list) -> tuple[np.ndarray, np.ndarray] | None:
    """``(origin, extent)`` ``(2,)`` (x, y) in document units of the one image of an SVG (the face
    photo :func:`write_traces_svg` puts under the strokes), its transforms applied; None without
    exactly one image of positive size, or for one turned or skewed (the page is then the face)."""
    if len(images) != 1:
        return None
    im = images[0]
    w, h = float(im.width or 0), float(im.height or 0)
    m = im.transform
    if not (w > 0 and h > 0) or abs(m.b) > 1e-9 or abs(m.c) > 1e-9 or m.a <= 0 or m.d <= 0:
        return None
    x0, y0 = float(im.x or 0), float(im.y or 0)
    origin = np.array([m.a * x0 + m.e, m.d * y0 + m.f])
    return origin, np.array([m.a * w, m.d * h])


def _check_points_attribute(points, path) -> None:
    """A polyline's ``points`` are pairs of finite numbers: svgelements skips a token it cannot
    read ("nan") and pairs the numbers after it anew, so "0,0 nan,1 2,2" came back as the points
    (0, 0) and (1, 2)."""
    if points is None:
        return
    tokens = [t for t in re.split(r"[\s,]+", str(points).strip()) if t]
    try:
        ok = len(tokens) % 2 == 0 and all(math.isfinite(float(t)) for t in tokens)
    except ValueError:
        ok = False
    if not ok:
        raise WoodcamError(f"{str(path)!r}: a polyline's points must be pairs of finite numbers "
                           f"'x,y x,y ...'; got {str(points)[:80]!r}")


def _polylines(path, scale: np.ndarray) -> list[np.ndarray]:
    """``(k, 2)`` document-unit polylines of an svgelements Path: one per subpath, curves
    sampled every :data:`~woodcam.tolerances.SVG_CURVE_STEP_PX` image pixels or finer."""
    import svgelements

    from ..limits import check_limit
    from ..tolerances import SVG_CURVE_STEP_PX

    lines: list[np.ndarray] = []
    cur: list[np.ndarray] = []
    for seg in path:
        if isinstance(seg, svgelements.Move):
            if len(cur) >= 2:
                lines.append(np.vstack(cur))
            cur = [np.array([[seg.end.x, seg.end.y]])]
            continue
        if not cur:  # a segment before any move (svgelements starts paths with one)
            cur = [np.array([[seg.start.x, seg.start.y]])]
        if isinstance(seg, (svgelements.Line, svgelements.Close)):
            cur.append(np.array([[seg.end.x, seg.end.y]]))
        else:  # CubicBezier, QuadraticBezier, Arc: sample along the curve
            length_px = seg.length(error=1e-6) * float(scale.max())
            n = max(2, int(math.ceil(length_px / SVG_CURVE_STEP_PX)) + 1) if math.isfinite(length_px) else -1
            # a 150-byte curve with control points at 1e9 px asked for 30 GiB of samples
            check_limit("MAX_TRACE_POINTS", n if n > 0 else math.inf,
                        f"a curve of {length_px:.4g} px in the SVG", fix="redraw it inside the face")
            cur.append(np.asarray(seg.npoint(np.linspace(0.0, 1.0, n)), float)[1:])
    if len(cur) >= 2:
        lines.append(np.vstack(cur))
    return lines


def _ring(attributes: dict) -> int | None:
    """The face-local ring id of an element's ``data-ring`` attribute (:class:`RingTrace`)."""
    v = attributes.get("data-ring")
    if v is None:
        return None
    if not re.fullmatch(r"\s*\d+\s*", v):
        raise WoodcamError(f"data-ring must be a non-negative integer (the ring a piece belongs to); "
                           f"got {v!r}: fix or delete the attribute")
    return int(v)


def _year(attributes: dict) -> int | None:
    """The year an element's own attributes give it (``data-year``, ``inkscape:label``, ``id``)."""
    for key in ("data-year", _INKSCAPE_LABEL, "id"):
        v = attributes.get(key)
        if v is None:
            continue
        m = re.fullmatch(r"\s*(?:year[-_ ]?)?(-?\d+)\s*", v, flags=re.IGNORECASE)
        if m:
            return int(m.group(1))
        if key == "data-year":
            raise WoodcamError(f"data-year must be an integer (the ring's year); got {v!r}: fix or delete the "
                               "attribute")
    return None
