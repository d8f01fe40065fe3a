"""Cut paths: every piece's outline as cubic Béziers, SVG and DXF files, fabricability checks.

Geometry is in millimetres. Panel frame: x right, y down, origin at the panel's top-left
corner (as SVG). Sheet frame: the same on each veneer sheet (see :mod:`.veneers`). DXF files
have y up (CAD convention): a DXF point is ``(x, sheet_height - y)``; :func:`read_dxf_pieces`
undoes it.

An outline is a closed list of segments ``("C", p0, p1, p2, p3)`` (cubic Bézier) or
``("L", p0, p1)`` (line), points ``(2,)`` float mm, each starting where the previous ends.
Seams are C1 splines (G1 everywhere along a seam); corners occur only where seams cross or meet
the panel border, and there the piece is convex (it turns the same way as its outline).

Fabricability for a router (which seed 002 does not check): every piece is at least
``min_piece_mm`` wide (a disc of that diameter rolls through all of it, up to its convex
corners), and no concave stretch of its outline bends tighter than the tool radius.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from xml.sax.saxutils import escape

import numpy as np

from ..errors import WoodcamError
from ..tolerances import PARQUETRY_CORNER_SIN, PARQUETRY_CURVATURE_SLACK, PARQUETRY_WIDTH_TOL_MM
from ..units import say_area, say_length

#: Bézier segments are flattened at this many points for areas, offsets and raster checks;
#: a 2 mm seam segment bends < 0.2 mm, so 8 points keep chords within ~3 um of the curve.
_FLATTEN = 8

#: Shortest seam segment (pixels) written to a cut file (see _line_segments).
_MIN_SEG_PX = 0.5

#: Points per segment when reading files back for raster checks: a 2 mm seam segment bent to
#: a 2.5 mm radius then deviates < 0.3 um from its chords, far below a pixel.
_READ_FLATTEN = 32


@dataclass
class Piece:
    """One piece to cut: a patch's fragment.

    id : the patch id (engraved)
    sheet : index of its veneer sheet
    outline_panel : segments in panel mm
    outline_sheet : the same segments in real sheet mm (a rigid motion of the panel outline,
        scaled by :meth:`~woodcam.parquetry.veneers.Veneer.pixel_scale`: at most half a pixel
        over the sheet where its pixel count was rounded)
    """

    id: int
    sheet: int
    outline_panel: list
    outline_sheet: list
    problems: list[str] = field(default_factory=list)


def _line_segments(line, a: float, b: float, ppm: float, axis: str) -> list:
    """Béziers of a seam line from parameter a to b (pixels), in mm; exact for the spline."""
    lo, hi = min(a, b), max(a, b)
    # Knots closer than _MIN_SEG_PX to an end are dropped: a sliver segment's handles would be
    # shorter than the files' rounding and its tangent meaningless. The Hermite cubic over the
    # merged interval then departs from the spline by far less than a micrometre.
    ks = line.knots[(line.knots > lo + _MIN_SEG_PX) & (line.knots < hi - _MIN_SEG_PX)]
    ts = np.concatenate([[lo], ks, [hi]])
    segs = []
    for t0, t1 in itertools.pairwise(ts):
        h = t1 - t0
        v0, v1 = float(line(t0)), float(line(t1))
        d0, d1 = float(line.spline(t0, 1)), float(line.spline(t1, 1))
        pts = [(v0, t0), (v0 + d0 * h / 3, t0 + h / 3), (v1 - d1 * h / 3, t1 - h / 3), (v1, t1)]
        pts = [np.array(q if axis == "v" else q[::-1], float) / ppm for q in pts]
        segs.append(("C", *pts))
    if a > b:
        segs = [("C", s[4], s[3], s[2], s[1]) for s in reversed(segs)]
    return segs


def _crossing(vl, hl) -> tuple[float, float]:
    """Point where vertical line x = X(y) meets horizontal line y = Y(x): the fixed point of
    y -> Y(X(y)), a contraction since both seams have slopes well below 1."""
    x = float(np.mean(vl(vl.knots)))
    y = float(hl(x))
    for _ in range(100):
        x2 = float(vl(y))
        y2 = float(hl(x2))
        done = abs(x2 - x) + abs(y2 - y) < 1e-10
        x, y = x2, y2
        if done:
            break
    return x, y


def panel_outlines(p, px_per_mm: float) -> dict[int, list]:
    """Outline (panel mm) of every placed patch of a panel, from its seam curves."""
    from .seams import grid_lines

    vls, hls = grid_lines(p)
    H, W = p.matched.shape
    rows, cols = p.cells.shape

    # Straight grid lines carry their nominal position as the spline value; parameter of a
    # vertical line is y, of a horizontal line x.
    def vertex(r: int, k: int) -> tuple[float, float]:
        if 0 < r < rows and 0 < k < cols:
            return _crossing(vls[k - 1], hls[r - 1])
        if 0 < k < cols:           # top or bottom border
            y = 0.0 if r == 0 else float(H)
            return float(vls[k - 1](y)), y
        if 0 < r < rows:           # left or right border
            x = 0.0 if k == 0 else float(W)
            return x, float(hls[r - 1](x))
        return (0.0 if k == 0 else float(W)), (0.0 if r == 0 else float(H))

    def side_h(r: int, k0: int, k1: int) -> list:
        """Along horizontal grid line r from vertex (r, k0) to (r, k1)."""
        a, b = vertex(r, k0), vertex(r, k1)
        if r == 0 or r == rows:
            return [("L", np.array(a) / px_per_mm, np.array(b) / px_per_mm)]
        return _line_segments(hls[r - 1], a[0], b[0], px_per_mm, "h")

    def side_v(k: int, r0: int, r1: int) -> list:
        a, b = vertex(r0, k), vertex(r1, k)
        if k == 0 or k == cols:
            return [("L", np.array(a) / px_per_mm, np.array(b) / px_per_mm)]
        return _line_segments(vls[k - 1], a[1], b[1], px_per_mm, "v")

    out = {}
    for q in p.patches:
        r0, c0, n = q.row, q.col, q.cells
        segs = []
        for k in range(c0, c0 + n):
            segs += side_h(r0, k, k + 1)
        for r in range(r0, r0 + n):
            segs += side_v(c0 + n, r, r + 1)
        for k in range(c0 + n, c0, -1):
            segs += side_h(r0 + n, k, k - 1)
        for r in range(r0 + n, r0, -1):
            segs += side_v(c0, r, r - 1)
        out[q.id] = segs
    return out


def transform_outline(segs: list, affine: np.ndarray) -> list:
    """Apply a ``(2, 3)`` affine to every control point (exact for Béziers)."""
    a, t = affine[:, :2], affine[:, 2]
    return [(s[0], *[a @ q + t for q in s[1:]]) for s in segs]


def flatten(segs: list, n: int = _FLATTEN) -> np.ndarray:
    """Closed outline -> polygon ``(m, 2)`` (no repeated closing point): a line's start point,
    ``n`` points of each cubic Bézier ``("C", p0, p1, p2, p3)`` (``t = 0, 1/n, ..``).

    All the curves at once (the outlines of a panel's pieces are flattened four times each
    for the cut files; a loop of small numpy sums per curve was 2 % of a parquetry run, 4 s):
    each point is the same Bernstein sum in the same order, so the same bits."""
    ts = np.linspace(0, 1, n, endpoint=False)
    is_curve = np.array([s[0] != "L" for s in segs], bool)
    if not is_curve.any():
        return np.concatenate([s[1][None] for s in segs])
    count = np.where(is_curve, n, 1)
    first = np.cumsum(count) - count
    ctrl = np.array([s[1:5] for s in segs if s[0] != "L"], float)  # (k, 4, 2)
    lines = [s[1] for s in segs if s[0] == "L"]
    out = np.empty((int(count.sum()), 2), np.result_type(float, *lines))
    if lines:
        out[first[~is_curve]] = lines
    u = 1 - ts
    w = [(u ** 3)[:, None], (3 * u * u * ts)[:, None], (3 * u * ts * ts)[:, None], (ts ** 3)[:, None]]
    out[first[is_curve][:, None] + np.arange(n)] = (w[0] * ctrl[:, None, 0] + w[1] * ctrl[:, None, 1]
                                                     + w[2] * ctrl[:, None, 2] + w[3] * ctrl[:, None, 3])
    return out


def _turns(segs: list):
    """Each joint between consecutive segments of a closed outline: ``(point (2,), sin, cos)``
    of the turn from the end tangent of one segment to the start tangent of the next
    (joints with a degenerate tangent are skipped)."""
    for a, b in zip(segs, segs[1:] + segs[:1]):
        ta = a[-1] - a[-2]
        tb = b[2] - b[1]
        na, nb = np.linalg.norm(ta), np.linalg.norm(tb)
        if na < 1e-12 or nb < 1e-12:
            continue
        yield b[1], float(ta[0] * tb[1] - ta[1] * tb[0]) / (na * nb), float(np.dot(ta, tb)) / (na * nb)


def _corners(segs: list, orient: float) -> list[tuple[np.ndarray, float]]:
    """Corners of an outline: ``[(point (2,), interior angle rad)]`` where the tangent jumps;
    ``orient`` is the sign of the outline's signed area. Convex corners have angle < pi."""
    out = []
    for point, cr, dot in _turns(segs):
        if abs(cr) > PARQUETRY_CORNER_SIN or dot < 0:
            turn = np.arctan2(abs(cr), dot)
            out.append((np.asarray(point, float), np.pi - turn if orient * cr > 0 else np.pi + turn))
    return out


def _signed_area(poly: np.ndarray) -> float:
    x, y = poly[:, 0], poly[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def check_piece(segs: list, min_piece_mm: float, tool_radius_mm: float) -> list[str]:
    """Fabricability problems of one outline (empty list: fine). See module docstring."""
    from shapely.geometry import Point, Polygon
    from shapely.ops import unary_union

    problems = []
    poly = flatten(segs)
    shp = Polygon(poly)
    if not shp.is_valid or shp.area <= 0:
        return ["outline is not a simple closed curve"]
    r = min_piece_mm / 2.0
    orient = np.sign(_signed_area(poly))
    inner = shp.buffer(-r * (1 - 1e-6))
    if inner.is_empty or inner.geom_type != "Polygon":
        problems.append(f"narrower than min_piece_mm = {say_length(min_piece_mm, 'g')} (a disc of that "
                        "diameter does not fit, or the piece has a neck)")
    else:
        # What a disc of diameter min_piece_mm cannot reach must be corner tips only: every
        # such bit has to touch one of the outline's corners (where seams cross or meet the
        # border); a thin sliver or strip along a seam touches none.
        from shapely.geometry import Point

        opened = inner.buffer(r * (1 - 1e-6), quad_segs=32)
        lost = shp.difference(opened)
        # A disc of radius r cannot reach the tip of a convex corner of interior angle theta:
        # between straight edges that tip lies within r / tan(theta / 2) of the corner; seams
        # bending outward next to it (no tighter than r) add at most about another r.
        # Anything else it cannot reach is narrower than min_piece_mm (a sliver, a tongue).
        tips = [Point(*q).buffer(r / np.tan(th / 2) + r + PARQUETRY_WIDTH_TOL_MM)
                for q, th in _corners(segs, orient) if th < np.pi]
        reach = opened.union(unary_union(tips)) if tips else opened
        thin = lost.difference(reach)
        thin_parts = [g for g in getattr(thin, "geoms", [thin])
                      if g.area > 1e-4 and not g.buffer(-PARQUETRY_WIDTH_TOL_MM).is_empty]
        if thin_parts:
            problems.append(f"{say_area(sum(g.area for g in thin_parts), '.2f')} of it is narrower than "
                            f"min_piece_mm = {say_length(min_piece_mm, 'g')} away from its corners")
    # Concave bends: orientation sign s = +1 for a counter-clockwise outline in a y-up sense.
    worst = np.inf
    t = np.linspace(0, 1, 17)
    for s in segs:
        if s[0] != "C":
            continue
        p0, p1, p2, p3 = s[1:]
        u = 1 - t
        d1 = (3 * u * u)[:, None] * (p1 - p0) + (6 * u * t)[:, None] * (p2 - p1) + (3 * t * t)[:, None] * (p3 - p2)
        d2 = (6 * u)[:, None] * (p2 - 2 * p1 + p0) + (6 * t)[:, None] * (p3 - 2 * p2 + p1)
        cross = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
        speed = np.linalg.norm(d1, axis=1)
        k = cross / np.maximum(speed, 1e-12) ** 3
        concave = orient * k < 0
        if concave.any():
            worst = min(worst, float(1.0 / np.max(np.abs(k[concave]))) if np.max(np.abs(k[concave])) > 0 else np.inf)
    # Corners between segments: a concave corner (turning against the outline) is a violation.
    if any(orient * cr < -PARQUETRY_CORNER_SIN for _, cr, _ in _turns(segs)):
        worst = 0.0
    if tool_radius_mm > 0 and worst < PARQUETRY_CURVATURE_SLACK * tool_radius_mm:
        problems.append(f"concave bend of radius {say_length(worst, '.2f')}, tighter than the tool radius "
                        f"{say_length(tool_radius_mm, 'g')}")
    return problems


def tool_path(segs: list, tool_radius_mm: float) -> np.ndarray:
    """Tool-centre path ``(m, 2)`` mm round a piece cut from outside: the outline offset
    outward by the tool radius (round joins), closed polygon without repeated end point."""
    from shapely.geometry import Polygon

    shp = Polygon(flatten(segs))
    if tool_radius_mm <= 0:
        return np.asarray(shp.exterior.coords)[:-1]
    g = shp.buffer(tool_radius_mm, join_style="round", quad_segs=8)
    return np.asarray(g.exterior.coords)[:-1]


# -- SVG ------------------------------------------------------------------------------------
def _fmt(p) -> str:
    return f"{p[0]:.5f},{p[1]:.5f}"


def path_d(segs: list) -> str:
    d = [f"M {_fmt(segs[0][1])}"]
    for s in segs:
        if s[0] == "L":
            d.append(f"L {_fmt(s[2])}")
        else:
            d.append(f"C {_fmt(s[2])} {_fmt(s[3])} {_fmt(s[4])}")
    d.append("Z")
    return " ".join(d)


def svg_document(width_mm: float, height_mm: float, pieces: list[tuple[int, list]],
                 tool_radius_mm: float = 0.0, background: str | None = None,
                 title: str = "") -> str:
    """SVG in mm: layer ``cut`` (piece outlines, one ``<path id="piece-N">`` each), layer
    ``toolpath`` (compensated tool-centre paths) when the tool radius is > 0, layer
    ``engrave`` (piece ids at the centroids)."""
    from shapely.geometry import Polygon

    out = [(f'<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" '
           f'width="{width_mm:.3f}mm" height="{height_mm:.3f}mm" '
           f'viewBox="0 0 {width_mm:.4f} {height_mm:.4f}">'), f"<title>{escape(title)}</title>"]
    if background:
        out.append(background)
    out.append('<g id="cut" fill="none" stroke="#d00" stroke-width="0.2">')
    for pid, segs in pieces:
        out.append(f'<path id="piece-{pid}" d="{path_d(segs)}"/>')
    out.append("</g>")
    if tool_radius_mm > 0:
        out.append('<g id="toolpath" fill="none" stroke="#06c" stroke-width="0.1">')
        for pid, segs in pieces:
            tp = tool_path(segs, tool_radius_mm)
            out.append(f'<polygon id="tool-{pid}" points="{" ".join(_fmt(q) for q in tp)}"/>')
        out.append("</g>")
    out.append('<g id="engrave" fill="#000" font-family="sans-serif" text-anchor="middle">')
    for pid, segs in pieces:
        c = Polygon(flatten(segs)).representative_point()
        out.append(f'<text x="{c.x:.3f}" y="{c.y + 1.0:.3f}" font-size="3">{pid}</text>')
    out.append("</g></svg>")
    return "\n".join(out)


def read_svg_pieces(path) -> dict[int, np.ndarray]:
    """Piece outlines parsed back from an SVG written here (svgelements), flattened:
    ``{id: (m, 2) mm}``."""
    import svgelements

    svg = svgelements.SVG.parse(str(path), ppi=25.4)   # ppi 25.4: one user unit = 1 mm
    out = {}
    for el in svg.elements():
        if isinstance(el, svgelements.Path) and str(el.id).startswith("piece-"):
            pts = []
            for seg in el.segments():
                if isinstance(seg, svgelements.Move):
                    continue
                if isinstance(seg, svgelements.Close):
                    continue
                ts = np.linspace(0, 1, _READ_FLATTEN, endpoint=False)
                pts.extend([(q.x, q.y) for q in (seg.point(t) for t in ts)])
            out[int(str(el.id).split("-", 1)[1])] = np.array(pts)
    return out


def read_svg_segments(path) -> dict[int, list]:
    """Piece outlines parsed back as segments (for the curvature check)."""
    import svgelements

    svg = svgelements.SVG.parse(str(path), ppi=25.4)
    out = {}
    for el in svg.elements():
        if isinstance(el, svgelements.Path) and str(el.id).startswith("piece-"):
            segs = []
            for seg in el.segments():
                if isinstance(seg, svgelements.CubicBezier):
                    segs.append(("C", *[np.array([q.x, q.y])
                                        for q in (seg.start, seg.control1, seg.control2, seg.end)]))
                elif isinstance(seg, (svgelements.Line, svgelements.Close)) and seg.start != seg.end:
                    segs.append(("L", np.array([seg.start.x, seg.start.y]), np.array([seg.end.x, seg.end.y])))
            out[int(str(el.id).split("-", 1)[1])] = segs
    return out


# -- DXF ------------------------------------------------------------------------------------
def write_dxf(path, height_mm: float, pieces: list[tuple[int, list]], tool_radius_mm: float = 0.0):
    """DXF (R2010, mm, y up): each outline on its own layer ``PIECE_<id>`` (SPLINE/LINE
    entities of one closed ezdxf path, xdata-free: the layer names the piece), layer TOOLPATH
    (compensated polylines), layer ENGRAVE (ids as TEXT, placed as the SVG's: centred on their
    baseline 1 mm below the piece's inner point); the header's extents are the drawing's."""
    import ezdxf
    from ezdxf import bbox
    from ezdxf import path as dpath
    from ezdxf import units
    from ezdxf.enums import TextEntityAlignment
    from shapely.geometry import Polygon

    from .._atomic import write_text

    doc = ezdxf.new("R2010")
    doc.units = units.MM
    msp = doc.modelspace()

    def fl(q):
        return (float(q[0]), float(height_mm - q[1]))

    # every layer the entities name is in the LAYER table (AUDIT in CAD programs reports the
    # missing ones): the pieces' below, TOOLPATH and ENGRAVE here
    for name in (["TOOLPATH"] if tool_radius_mm > 0 else []) + (["ENGRAVE"] if pieces else []):
        doc.layers.add(name)
    for pid, segs in pieces:
        layer = f"PIECE_{pid}"
        doc.layers.add(layer)
        pth = dpath.Path(fl(segs[0][1]))
        for s in segs:
            if s[0] == "L":
                pth.line_to(fl(s[2]))
            else:
                pth.curve4_to(fl(s[4]), fl(s[2]), fl(s[3]))
        dpath.render_splines_and_polylines(msp, [pth], dxfattribs={"layer": layer})
        if tool_radius_mm > 0:
            msp.add_lwpolyline([fl(q) for q in tool_path(segs, tool_radius_mm)], close=True,
                               dxfattribs={"layer": "TOOLPATH"})
        c = Polygon(flatten(segs)).representative_point()
        msp.add_text(str(pid), height=3, dxfattribs={"layer": "ENGRAVE"}).set_placement(
            fl((c.x, c.y + 1.0)), align=TextEntityAlignment.CENTER)
    ext = bbox.extents(msp, fast=True)  # viewers that zoom to the header's extents need them
    if ext.has_data:  # ezdxf writes the header's $EXTMIN/$EXTMAX from the modelspace's own
        msp.dxf.extmin, msp.dxf.extmax = ext.extmin, ext.extmax
    import io

    buf = io.StringIO()
    doc.write(buf)
    return write_text(path, buf.getvalue(), mkdir=True)


def read_dxf_pieces(path, height_mm: float) -> dict[int, np.ndarray]:
    """Piece outlines parsed back from a DXF written here (ezdxf): ``{id: (m, 2) mm}``, y down."""
    import ezdxf
    from ezdxf import path as dpath

    try:
        doc = ezdxf.readfile(str(path))
    except (OSError, ezdxf.DXFStructureError) as err:
        raise WoodcamError(f"DXF {str(path)!r} cannot be read ({err})") from err
    pts: dict[int, list] = {}
    for e in doc.modelspace():
        layer = e.dxf.layer
        if not layer.startswith("PIECE_"):
            continue
        pid = int(layer.split("_", 1)[1])
        v = [(q.x, height_mm - q.y) for q in dpath.make_path(e).flattening(0.0005)]
        pts.setdefault(pid, []).append(v)
    out = {}
    for pid, chains in pts.items():
        # Chain the entities (they were written in order, each starting where one ended).
        poly = []
        for ch in chains:
            poly.extend(ch if not poly else ch[1:])
        out[pid] = np.array(poly[:-1] if np.allclose(poly[0], poly[-1]) else poly)
    return out


def rasterise(polys: dict[int, np.ndarray], shape_hw, px_per_mm: float) -> np.ndarray:
    """How many outlines cover each pixel centre: ``(h, w)`` int (pixel (r, c) centred at
    ``((c + 0.5), (r + 0.5)) / px_per_mm`` mm)."""
    from skimage.measure import points_in_poly

    n = np.zeros(shape_hw, np.int32)
    h, w = shape_hw
    for poly in polys.values():
        q = poly * px_per_mm - 0.5
        # Exact crossing-number test on the pixel centres of the bounding box (skimage.draw's
        # polygon is approximate within a fraction of a pixel of the outline).
        c0, r0 = np.maximum(np.floor(q.min(0)).astype(int), 0)
        c1, r1 = np.minimum(np.ceil(q.max(0)).astype(int) + 1, (w, h))
        if c1 <= c0 or r1 <= r0:
            continue
        rr, cc = np.mgrid[r0:r1, c0:c1]
        inside = points_in_poly(np.c_[cc.ravel(), rr.ravel()].astype(float), q).reshape(rr.shape)
        n[r0:r1, c0:c1] += inside
    return n
