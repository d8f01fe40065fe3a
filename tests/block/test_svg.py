"""Ring traces as SVG: round trip, editor-style files, scaling and refusals."""

import numpy as np
import pytest

from woodcam.block import Face, RingTrace
from woodcam.block.svg import read_traces_svg, write_traces_svg
from woodcam.errors import WoodcamError
from woodcam.synth import cut_block, synth_block


def test_round_trip_of_synthetic_traces(tmp_path):
    block = synth_block(cut_block(lambda p: np.hypot(p[:, 0], p[:, 1]) / 2.0, (30, 30, 30), "rift"),
                        (30, 30, 30), face_px=64, unlabelled_fraction=0.3, seed=1)
    face = block.faces["top"]
    path = write_traces_svg(face, tmp_path / "top.svg", photo_href="top_photo.png")
    back = read_traces_svg(path, face.shape)
    assert len(back) == len(face.traces) > 5
    for a, b in zip(face.traces, back):
        assert a.year == b.year
        np.testing.assert_allclose(b.points_px, a.points_px, atol=1e-9)
    assert any(t.year is None for t in back)
    # the photo underneath is an SVG 1.1 xlink:href (Inkscape before 1.3 ignores a plain href)
    import xml.etree.ElementTree as ET
    image = ET.parse(path).getroot().find("{http://www.w3.org/2000/svg}image")
    assert image.get("{http://www.w3.org/1999/xlink}href") == "top_photo.png"


def test_editor_style_svg(tmp_path):
    # an Inkscape-like file drawn at 2x the image scale, a layer with a translate, relative paths
    svg = """<?xml version="1.0"?>
<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"
     width="200" height="100" viewBox="0 0 200 100">
  <image href="front.png" width="200" height="100"/>
  <g inkscape:label="rings" transform="translate(10,0)">
    <path inkscape:label="year-7" d="m 0,20 10,0 h 10 v 10" />
    <path id="path12" d="M 50 60 L 70 60 Z" />
    <polyline data-year="3" points="1,1 3,1" transform="scale(2)"/>
    <line x1="0" y1="0" x2="0" y2="40" id="9"/>
  </g>
</svg>"""
    (tmp_path / "f.svg").write_text(svg)
    traces = read_traces_svg(tmp_path / "f.svg", (50, 100))     # image is half the SVG scale
    years = [t.year for t in traces]
    assert years == [7, None, 3, 9]
    # SVG (x, y) -> pixel: col = (x + 10) / 2 - 0.5, row = y / 2 - 0.5
    np.testing.assert_allclose(traces[0].points_px, [[9.5, 4.5], [9.5, 9.5], [9.5, 14.5], [14.5, 14.5]])
    np.testing.assert_allclose(traces[1].points_px, [[29.5, 29.5], [29.5, 39.5], [29.5, 29.5]])
    np.testing.assert_allclose(traces[2].points_px, [[0.5, 5.5], [0.5, 7.5]])


def test_a_path_of_several_subpaths_is_one_trace_each(tmp_path):
    """A ``<path>`` whose ``M``/``m`` starts a new stroke (an editor's combined path, or a ring
    redrawn in pieces) is one trace per subpath, each with the path's year: the jump between
    them is no part of any ring."""
    (tmp_path / "p.svg").write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" width="40" height="40">'
        '<path data-year="5" d="M 1,2 L 11,2 M 1,30 L 21,30 m 0,4 h 10"/></svg>')
    traces = read_traces_svg(tmp_path / "p.svg", (40, 40))
    assert [t.year for t in traces] == [5, 5, 5]
    # (x, y) -> (row, col) = (y - 0.5, x - 0.5)
    np.testing.assert_allclose(traces[0].points_px, [[1.5, 0.5], [1.5, 10.5]], atol=1e-12)
    np.testing.assert_allclose(traces[1].points_px, [[29.5, 0.5], [29.5, 20.5]], atol=1e-12)
    np.testing.assert_allclose(traces[2].points_px, [[33.5, 20.5], [33.5, 30.5]], atol=1e-12)


def test_bad_files_are_refused(tmp_path):
    """A file cut short and a data-year that is no integer are refused naming a fix (they named
    none: 'must be a readable SVG file; unclosed token: line 2, column 43848', of an Inkscape
    save cut short)."""
    (tmp_path / "bad.svg").write_text("<svg")
    with pytest.raises(WoodcamError, match="must be a readable SVG.*save it again from your SVG editor.*or "
                                           "delete it to have 'woodcam rings detect' trace the face afresh"):
        read_traces_svg(tmp_path / "bad.svg", (10, 10))
    (tmp_path / "y.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 10 10">'
                                    '<polyline data-year="x" points="0,0 1,1"/></svg>')
    with pytest.raises(WoodcamError, match="data-year must be an integer.*fix or delete the attribute"):
        read_traces_svg(tmp_path / "y.svg", (10, 10))


#: What Inkscape writes for a 60 x 40 mm face drawn over its photo: width/height in mm, a
#: viewBox of 10 user units per mm, sodipodi/inkscape metadata, layers with transforms and
#: curved strokes (cubic, quadratic, arc), a marker path in <defs> and a frame that is no trace.
INKSCAPE_SVG = """<?xml version="1.0" encoding="UTF-8" standalone="no"?>
<svg xmlns="http://www.w3.org/2000/svg" xmlns:svg="http://www.w3.org/2000/svg"
   xmlns:xlink="http://www.w3.org/1999/xlink"
   xmlns:sodipodi="http://sodipodi.sourceforge.net/DTD/sodipodi-0.dtd"
   xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"
   width="60mm" height="40mm" viewBox="0 0 600 400" version="1.1" id="svg8"
   inkscape:version="1.2.2 (b0a8486541, 2022-12-01)" sodipodi:docname="front_traces.svg">
  <sodipodi:namedview id="namedview1" pagecolor="#ffffff" inkscape:document-units="mm"
     inkscape:zoom="2" inkscape:current-layer="layer2"/>
  <defs id="defs2"><path id="marker-arrow" d="M 0,0 L 50,50"/></defs>
  <g inkscape:groupmode="layer" id="layer0" inkscape:label="photo" sodipodi:insensitive="true">
    <image xlink:href="front_photo.png" x="0" y="0" width="600" height="400" id="image1"/>
    <rect x="0" y="0" width="600" height="400" style="fill:none;stroke:#000" id="frame"/>
  </g>
  <g inkscape:groupmode="layer" id="layer1" inkscape:label="2019" transform="translate(100,50)">
    <path inkscape:label="year-4" sodipodi:nodetypes="cc" style="fill:none;stroke:#e6194b"
       d="M 0,0 C 100,0 200,100 200,200" id="path101"/>
    <path id="path102" d="m 0,300 q 100,-100 200,0" style="fill:none;stroke:#3cb44b"/>
    <g id="g7" transform="translate(300,200)">
      <path data-year="9" d="M 100,0 A 100,100 0 0 1 0,100" id="path103"/>
    </g>
  </g>
  <g inkscape:groupmode="layer" id="layer2" inkscape:label="turned"
     transform="matrix(0,1,-1,0,600,0)">
    <polyline id="year-11" points="10,20 30,20"/>
  </g>
</svg>
"""


def _face_mm(t):
    """Face millimetres (x from the left, y down from the top) of a trace on the 2 px/mm image."""
    return (t.points_px[:, ::-1] + 0.5) / 2.0


def test_inkscape_svg_with_curves_transforms_and_mm_units(tmp_path):
    (tmp_path / "front_traces.svg").write_text(INKSCAPE_SVG)
    traces = read_traces_svg(tmp_path / "front_traces.svg", (80, 120))  # 60 x 40 mm at 2 px/mm
    assert [t.year for t in traces] == [4, None, 9, 11]  # the layer label "2019" is not its strokes' year
    cubic, quad, arc, turned = (_face_mm(t) for t in traces)
    # cubic in the layer translated by (100, 50) user units = (10, 5) mm: its Bezier formula
    t = np.linspace(0, 1, 2001)[:, None]
    ctrl = np.array([[0, 0], [100, 0], [200, 100], [200, 200]]) / 10 + [10, 5]
    bez = ((1 - t) ** 3 * ctrl[0] + 3 * (1 - t) ** 2 * t * ctrl[1] + 3 * (1 - t) * t ** 2 * ctrl[2]
           + t ** 3 * ctrl[3])
    np.testing.assert_allclose(cubic[[0, -1]], [[10, 5], [30, 25]], atol=1e-9)
    assert np.linalg.norm(cubic[:, None] - bez[None], axis=2).min(1).max() < 0.01
    assert np.diff(cubic, axis=0).__abs__().max() <= 0.25 + 1e-9  # sampled every 0.5 px or finer
    # relative quadratic: from (0, 300) to (200, 300) with control (100, 200): y(x) is a parabola
    x = quad[:, 0] - 10
    np.testing.assert_allclose(quad[:, 1], 5 + 30 - 20 * (x / 20) * (1 - x / 20), atol=1e-9)
    np.testing.assert_allclose(quad[[0, -1], 0], [10, 30], atol=1e-9)
    # arc of radius 10 mm about (100 + 300, 50 + 200) user units = (40, 25) mm, a quarter turn
    np.testing.assert_allclose(np.hypot(*(arc - [40, 25]).T), 10.0, atol=1e-9)
    np.testing.assert_allclose(arc[[0, -1]], [[50, 25], [40, 35]], atol=1e-9)
    assert len(arc) > 30  # a 15.7 mm arc = 31 px: a curve, not its chord
    # the rotated layer: (x, y) -> (600 - y, x) user units
    np.testing.assert_allclose(turned, [[58, 1], [58, 3]], atol=1e-9)


def test_face_traces_written_in_pixel_units(tmp_path):
    face = Face("left", (20, 30), traces=[RingTrace(np.array([[0.0, 0.0], [19.0, 29.0]]), 4)])
    text = write_traces_svg(face, tmp_path / "l.svg").read_text()
    assert 'viewBox="0 0 30 20"' in text and 'points="0.5,0.5 29.5,19.5"' in text and 'data-year="4"' in text


def test_real_block_manifest_may_name_an_svg(tmp_path):
    import json

    from woodcam.block import read_block

    face = Face("top", (20, 30), traces=[RingTrace(np.array([[2.0, 3.0], [4.0, 25.0]]), 11)])
    write_traces_svg(face, tmp_path / "top_traces.svg")
    (tmp_path / "block.json").write_text(json.dumps({
        "format": "woodcam-block", "size_mm": [30, 20, 10],
        "faces": {"top": {"shape": [20, 30], "traces_svg": "top_traces.svg"}}}))
    t = read_block(tmp_path).faces["top"].traces
    assert len(t) == 1 and t[0].year == 11
    np.testing.assert_allclose(t[0].points_px, [[2, 3], [4, 25]], atol=1e-12)


def test_ring_ids_round_trip_and_bad_ones_are_refused(tmp_path):
    """The detector's face-local ring ids (pieces of one ring) survive the SVG; a bad
    ``data-ring`` is one clear error naming the attribute."""
    line = np.stack([np.full(5, 3.0), np.arange(5.0)], axis=1)
    face = Face("front", (20, 20), traces=[RingTrace(line, ring=4), RingTrace(line + [6, 0], ring=4),
                                           RingTrace(line + [12, 0])])
    back = read_traces_svg(write_traces_svg(face, tmp_path / "f.svg"), face.shape)
    assert [t.ring for t in back] == [4, 4, None]
    bad = tmp_path / "bad.svg"
    bad.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="20" height="20">'
                   '<polyline data-ring="x1" points="0,0 5,5"/></svg>')
    with pytest.raises(WoodcamError, match="data-ring must be a non-negative integer"):
        read_traces_svg(bad, (20, 20))
    with pytest.raises(WoodcamError, match="ring of a ring trace must be a non-negative integer"):
        RingTrace(line, ring=-1)


def test_bad_attributes_name_the_file_and_nan_in_a_path_is_refused(tmp_path):
    """A bad data-ring named neither the file nor the element (a block folder holds six SVGs); a
    NaN in a path's data was dropped and the numbers after it read on."""
    (tmp_path / "front_traces.svg").write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10">'
        '<polyline id="trace-3" points="0,0 5,5" data-ring="x1"/></svg>')
    with pytest.raises(WoodcamError, match=r"front_traces.svg', element trace-3: data-ring must be"):
        read_traces_svg(tmp_path / "front_traces.svg", (10, 10))
    (tmp_path / "p.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10">'
                                    '<path d="M 0,0 L nan,1 2,2"/></svg>')
    with pytest.raises(WoodcamError, match="a path's data must hold finite numbers"):
        read_traces_svg(tmp_path / "p.svg", (10, 10))


def test_a_stroke_past_the_face_is_refused_naming_the_svg_and_the_stroke(tmp_path):
    """A stroke drawn far past the face in Inkscape was refused only later, by the Face, as
    "trace 20 of face 'front' lies beyond its 256x256 px image (more than half a face past an
    edge); check its (row, col) pixel coordinates": no word of the SVG, the stroke or where it
    runs. Now the reader refuses it in the SVG's terms; a stroke within half a face of slack
    (drawn a little over an edge) is read."""
    svg = tmp_path / "front_traces.svg"
    svg.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="40" height="20" viewBox="0 0 40 20">'
                   '<path id="over" d="M -5,-5 L 45,25"/><path id="far" d="M 1,1 L 70,1"/></svg>')
    with pytest.raises(WoodcamError, match=r"front_traces.svg', element far: a stroke runs to \(70, 1\), more than "
                                           r"half the face past its edge \(the face spans 0..40 x 0..20 in the "
                                           r"drawing, its photo 40x20 px\); move the stroke onto the face or delete it"):
        read_traces_svg(svg, (20, 40))
    svg.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="40" height="20" viewBox="0 0 40 20">'
                   '<path id="over" d="M -5,-5 L 45,25"/></svg>')
    assert len(read_traces_svg(svg, (20, 40))) == 1


def test_a_page_grown_round_the_photo_moves_no_stroke(tmp_path):
    """The drawing's page was taken for the face: a page an editor grew round the photo
    (Inkscape's 'resize page to drawing' with a stroke past the photo's edge: viewBox
    '-10 -10 276 276') moved every stroke (reproduced: a stroke drawn at (20, 20) over the photo
    read at pixel (27.3, 27.3), not (19.5, 19.5)). Now the one <image>, the face photo the
    strokes are drawn over, is the face, its transforms applied; without one the page is."""
    svg = tmp_path / "front_traces.svg"
    strokes = '<g transform="translate(0,0)"><path d="M 20,20 L 60,60"/></g>'
    for page, image in (('width="276" height="276" viewBox="-10 -10 276 276"', 'x="0" y="0" width="256" height="256"'),
                        ('width="300mm" height="200mm" viewBox="0 0 300 200"',
                         'x="5" y="0" width="128" height="128" transform="scale(2)"')):
        svg.write_text(f'<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" {page}>'
                       f'<image xlink:href="front_photo.png" {image}/>{strokes}</svg>')
        (t,) = read_traces_svg(svg, (256, 256))
        want = [[19.5, 19.5], [59.5, 59.5]] if "-10" in page else [[19.5, 9.5], [59.5, 49.5]]
        np.testing.assert_allclose(t.points_px, want, atol=1e-9, err_msg=page)


def test_strokes_an_editor_hides_are_no_traces(tmp_path):
    """A stroke hidden in the editor (visibility:hidden, display:none, opacity 0, stroke:none, a
    transparent stroke or one of width 0; on itself or on a group round it) was read as a ring
    trace: a ring hidden instead of deleted still counted. Only the strokes shown are traces; a
    path with no stroke attribute at all (hand-written) still is one, as is a stroke made visible
    again inside a hidden group."""
    (tmp_path / "h.svg").write_text("""<?xml version="1.0"?>
<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100" viewBox="0 0 100 100">
 <style>.gone { visibility: hidden }</style>
 <polyline data-year="1" points="10,10 90,10" stroke="#000" fill="none"/>
 <polyline data-year="90" points="10,15 90,15" stroke="#000" visibility="hidden"/>
 <polyline data-year="91" points="10,20 90,20" style="stroke:#000;visibility:hidden"/>
 <polyline data-year="92" points="10,25 90,25" class="gone" stroke="#000"/>
 <polyline data-year="93" points="10,30 90,30" style="display:none;stroke:#000"/>
 <polyline data-year="94" points="10,35 90,35" stroke="#000" opacity="0"/>
 <polyline data-year="95" points="10,40 90,40" stroke="#000" stroke-opacity="0%"/>
 <polyline data-year="96" points="10,45 90,45" style="stroke:none;fill:none"/>
 <polyline data-year="97" points="10,50 90,50" stroke="transparent"/>
 <polyline data-year="98" points="10,55 90,55" stroke="#000" stroke-width="0"/>
 <path data-year="2" d="M 10,60 L 90,60"/>
 <g style="display:none"><polyline data-year="80" points="10,65 90,65" stroke="#000"/></g>
 <g visibility="hidden"><polyline data-year="81" points="10,70 90,70" stroke="#000"/>
   <polyline data-year="3" points="10,72 90,72" stroke="#000" visibility="visible"/></g>
 <g opacity="0"><polyline data-year="82" points="10,75 90,75" stroke="#000" opacity="1"/></g>
 <g stroke="none"><path data-year="83" d="M 10,80 L 90,80"/>
   <path data-year="4" d="M 10,82 L 90,82" stroke="red"/></g>
 <g opacity="0.5"><polyline data-year="5" points="10,85 90,85" stroke="#000"/></g>
</svg>""")
    traces = read_traces_svg(tmp_path / "h.svg", (100, 100))
    assert [t.year for t in traces] == [1, 2, 3, 4, 5]
    np.testing.assert_allclose([t.points_px[0, 0] for t in traces], [9.5, 59.5, 71.5, 81.5, 84.5])
