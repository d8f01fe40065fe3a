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


def test_curves_and_bad_files_are_refused(tmp_path):
    (tmp_path / "c.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 10 10">'
                                    '<path d="M 0 0 C 1 1 2 2 3 3"/></svg>')
    with pytest.raises(WoodcamError, match="command 'C' .*Flatten Beziers"):
        read_traces_svg(tmp_path / "c.svg", (10, 10))
    (tmp_path / "bad.svg").write_text("<svg")
    with pytest.raises(WoodcamError, match="must be a readable SVG"):
        read_traces_svg(tmp_path / "bad.svg", (10, 10))
    (tmp_path / "y.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 10 10">'
                                    '<polyline data-year="x" points="0,0 1,1"/></svg>')
    with pytest.raises(WoodcamError, match="data-year must be an integer"):
        read_traces_svg(tmp_path / "y.svg", (10, 10))


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
