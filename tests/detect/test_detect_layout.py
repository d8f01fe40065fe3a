"""The face-layout check (:mod:`woodcam.detect.layout`): rings meet across the block's edges."""

from __future__ import annotations

import numpy as np
import pytest

from woodcam.block.block import Block, Face
from woodcam.detect.layout import LAYOUT_MARGIN, VARIANTS, check_face_layout


@pytest.fixture(scope="module")
def cube() -> Block:
    """A 50 mm flat-sawn cube of six 160 px photos, laid out as the conventions say."""
    from woodcam.synth import AnalyticLogField, cut_block, synth_block

    field = cut_block(AnalyticLogField(ring_width_mm=3.0, eccentricity=0.05), (50, 50, 50), "flat-sawn")
    return synth_block(field, (50, 50, 50), face_px=160, seed=4, ring_map_faces=())


def _with(block: Block, face: str, photo: np.ndarray) -> Block:
    faces = dict(block.faces)
    faces[face] = Face(face, photo.shape[:2], photo=np.ascontiguousarray(photo))
    return Block(block.size_mm, faces=faces, name=block.name, meta={"photos": {face: "top.jpg"}})


def test_a_correct_layout_is_not_flagged(cube):
    report = check_face_layout(cube)
    assert report.warnings == [] and report.corrections == {}
    assert set(report.faces) == set(cube.faces) and set(report.source.values()) == {"photo"}
    # every face meets its neighbours at least as well as laid out as in any variant, within the margin
    assert max(fl.margin for fl in report.faces.values()) < LAYOUT_MARGIN
    assert all(fl.edges == 4 and len(fl.scores) == 8 for fl in report.faces.values())


@pytest.mark.parametrize("face, turn, fix, says", [
    ("top", lambda a: np.rot90(a, -1), "rot90ccw", "looks turned 90 degrees clockwise"),
    ("bottom", lambda a: np.rot90(a, 2), "rot180", "looks turned 180 degrees"),
    ("right", lambda a: a[:, ::-1], "flip-lr", "looks mirrored left-right"),
    # every other wrong layout of a square face (on the top face, where none of them looks like
    # another on this cube: the end-grain faces' symmetric rings make e.g. rot90ccw and
    # transpose the same picture there)
    ("top", lambda a: np.rot90(a, 1), "rot90cw", "looks turned 90 degrees counter-clockwise"),
    ("top", lambda a: a[::-1], "flip-tb", "looks mirrored top-bottom"),
    ("top", lambda a: np.swapaxes(a, 0, 1), "transpose",
     "looks mirrored across its top-left to bottom-right diagonal"),
    ("top", lambda a: np.swapaxes(np.rot90(a, 2), 0, 1), "antitranspose",
     "looks mirrored across its top-right to bottom-left diagonal"),
])
def test_a_turned_or_mirrored_face_is_named_with_its_correction(cube, face, turn, fix, says):
    report = check_face_layout(_with(cube, face, turn(cube.faces[face].photo)))
    assert report.corrections == {face: fix}, report.warnings
    (msg,) = report.warnings
    assert msg.startswith(f"face {face!r} {says}: its rings meet its neighbours' along its 4 edges")
    # the path a user has: docs/conventions.md is no file of the repository (sweep h6)
    assert "the unfolded cross of ../shared/docs/conventions.md (README 'The block frame')" in msg
    assert "make the block again" in msg
    # the correction it names undoes the turn
    undone = VARIANTS[fix][0](turn(cube.faces[face].photo))
    assert np.array_equal(undone, cube.faces[face].photo)
    # and says it in words that undo the turn (the diagonal mirrors checked by hand: flip-lr
    # then rot90 is the transpose, flip-lr then rot90 clockwise the anti-transpose)
    does = {"rot90ccw": "turn its photo top.jpg 90 degrees counter-clockwise",
            "rot180": "turn its photo top.jpg 180 degrees",
            "rot90cw": "turn its photo top.jpg 90 degrees clockwise",
            "flip-lr": "flip its photo top.jpg left-right",
            "flip-tb": "flip its photo top.jpg top-bottom",
            "transpose": "flip its photo top.jpg left-right, then turn it 90 degrees counter-clockwise",
            "antitranspose": "flip its photo top.jpg left-right, then turn it 90 degrees clockwise"}
    assert f"as laid out); {does[fix]}" in msg, msg  # first, before any "(or ...: nearly as good)"


def test_a_non_square_face_is_tried_only_in_variants_keeping_its_shape(cube):
    from woodcam.synth import AnalyticLogField, cut_block, synth_block

    field = cut_block(AnalyticLogField(ring_width_mm=3.0), (60, 40, 30), "flat-sawn")
    # 3 px/mm along its 60 mm side, above LAYOUT_MIN_PX_PER_MM (150 px was 2.5: no longer judged)
    block = synth_block(field, (60, 40, 30), face_px=180, seed=1, ring_map_faces=())
    report = check_face_layout(block)
    assert report.warnings == []
    assert set(report.faces["top"].scores) == {"as laid out", "rot180", "flip-lr", "flip-tb"}
    turned = check_face_layout(_with(block, "top", np.rot90(block.faces["top"].photo, 2)))
    assert turned.corrections == {"top": "rot180"}


def test_faces_without_neighbours_or_images_are_not_scored(cube):
    lone = Block(cube.size_mm, faces={"top": cube.faces["top"], "bottom": cube.faces["bottom"]})
    report = check_face_layout(lone)
    assert report.faces == {} and report.warnings == []


def test_a_face_with_no_rings_found_is_not_called_mirrored(cube, capsys):
    """After detection, a face with no rings found (no ring map, no traces: a 20 x 20 px photo's)
    was still judged from its photo, and was said to 'look mirrored'. Its edges hold no rings to
    meet its neighbours': it is not scored, and is listed as not checked, with why."""
    from woodcam.cli.options import report_layout

    faces = {n: Face(n, f.shape, photo=f.photo, ring_map=np.zeros(f.shape, np.float32))
             for n, f in cube.faces.items()}
    meta = {"detection": {"faces": sorted(faces)}}  # detected: every face read from its photo
    # a face whose photo meets its neighbours only mirrored: with rings found on it, it is flagged
    mirrored = np.ascontiguousarray(cube.faces["right"].photo[:, ::-1])
    faces["right"] = Face("right", mirrored.shape[:2], photo=mirrored, ring_map=np.zeros(mirrored.shape[:2], np.float32))
    assert check_face_layout(Block(cube.size_mm, faces=dict(faces), meta=meta)).corrections == {"right": "flip-lr"}
    faces["right"] = Face("right", mirrored.shape[:2], photo=mirrored)  # no rings found on it
    detected = Block(cube.size_mm, faces=faces, meta=meta)
    report = check_face_layout(detected)
    assert report.warnings == [] and report.corrections == {}
    assert "right" not in report.faces and set(report.faces) == set(faces) - {"right"}
    assert report.unchecked == {"right": "no rings found on it"}
    report_layout(detected)
    assert capsys.readouterr().out == ("layout: 5 faces checked, none looks turned or mirrored; "
                                       "not checked: right (no rings found on it)\n")


def _resized(block: Block, px: int) -> Block:
    from PIL import Image

    faces = {n: Face(n, (px, px), photo=np.asarray(Image.fromarray(f.photo).resize((px, px), Image.LANCZOS)))
             for n, f in block.faces.items()}
    return Block(block.size_mm, faces=faces, name=block.name, meta={})


def test_a_face_too_coarse_to_judge_is_listed_not_called_turned(capsys):
    """Mokume CN03 resized to 64 px a side (1.28 px/mm), laid out right and with rings found on
    every face, was said to have its 'back' turned 90 degrees: at such a density the check's
    evidence is noise (LAYOUT_MIN_PX_PER_MM). Its faces are listed as not checked, with why and
    the size that would be; at 160 px (3.2 px/mm) it is checked and passes."""
    from woodcam.block.io import read_mokume
    from woodcam.cli.options import report_layout
    from woodcam.detect.block import photos_only

    from .test_detect_rings import _mokume

    cn03 = photos_only(read_mokume(_mokume("CN03"), (50.0, 50.0, 50.0)))
    small = _resized(cn03, 64)
    report = check_face_layout(small)
    assert report.corrections == {} and report.warnings == [] and report.faces == {}
    assert set(report.unchecked) == set(small.faces)
    assert report.unchecked["back"] == ("64 px a side is 1.28 px/mm, under the 2.75 px/mm the check needs "
                                        "(LAYOUT_MIN_PX_PER_MM): give its photo at least 138 px a side")
    report_layout(small)
    out = capsys.readouterr().out
    assert out == ("layout: not checked (no two neighbouring faces with a photo or ring map); not checked: "
                   f"{', '.join(small.faces)} ({report.unchecked['back']})\n"), out
    # a 40 mm cube at 48 px needs 110 px (not a float's 111)
    cube40 = Block((40.0, 40.0, 40.0), faces=_resized(cn03, 48).faces, meta={})
    assert check_face_layout(cube40).unchecked["top"].endswith("at least 110 px a side")
    fine = check_face_layout(_resized(cn03, 160))
    assert fine.unchecked == {} and fine.corrections == {} and len(fine.faces) == 6


def test_a_correct_synthetic_cube_at_2_5_px_per_mm_is_not_called_mirrored():
    """A quarter-sawn synthetic cube of 3 mm rings, laid out right and brought down to 125 px a
    side (2.50 px/mm, LANCZOS as 'block from-photos' resamples), had its 'right' face said to look
    mirrored top-bottom (+0.16 over its layout): the floor of 2.5 px/mm let it be judged
    (LAYOUT_MIN_PX_PER_MM, measured on 3 and 6 mm-ring cubes). It is listed as not checked; at
    138 px (2.76 px/mm) it is checked and passes."""
    from woodcam.synth import AnalyticLogField, cut_block, synth_block

    field = cut_block(AnalyticLogField(ring_width_mm=3.0, eccentricity=0.05), (50, 50, 50), "quarter-sawn")
    big = synth_block(field, (50, 50, 50), face_px=320, seed=29837, ring_map_faces=())
    report = check_face_layout(_resized(big, 125))
    assert report.corrections == {} and report.warnings == [], report.warnings
    assert set(report.unchecked) == set(big.faces) and "under the 2.75 px/mm" in report.unchecked["right"]
    fine = check_face_layout(_resized(big, 138))
    assert fine.unchecked == {} and fine.corrections == {} and len(fine.faces) == 6


def test_a_coarse_face_is_no_neighbour_but_the_others_are_still_judged(cube):
    """One face under the floor is listed; a turned face beside it is still found by its other edges."""
    from PIL import Image

    faces = dict(cube.faces)
    coarse = np.asarray(Image.fromarray(cube.faces["front"].photo).resize((64, 64), Image.LANCZOS))
    faces["front"] = Face("front", (64, 64), photo=coarse)
    turned = np.ascontiguousarray(np.rot90(cube.faces["top"].photo, -1))
    faces["top"] = Face("top", turned.shape[:2], photo=turned)
    report = check_face_layout(Block(cube.size_mm, faces=faces, meta={}))
    assert set(report.unchecked) == {"front"} and "front" not in report.faces
    assert report.corrections == {"top": "rot90ccw"}
    assert report.faces["top"].edges == 3


def test_a_correct_layout_at_a_phone_photos_density_is_not_called_mirrored():
    """Mokume H11 laid out right, brought up to 768 px a side (15.4 px/mm; 'block from-photos'
    stores phone photos at up to 10), had its 'front' said to look mirrored top-bottom (+0.18
    over its layout), and at 500 px from six JPEG phone-style photos too: the edge strip, 0.5-1.5
    px deep, closed in on the crop line as the density rose. It is now at least STRIP_MM deep
    (that depth at the 5.12 px/mm the margin was measured on): nothing is flagged, and a face
    turned 180 degrees is still found, with its fix, as at 256 px."""
    from woodcam.block.io import read_mokume
    from woodcam.detect.block import photos_only

    from .test_detect_rings import _mokume

    h11 = _resized(photos_only(read_mokume(_mokume("H11"), (50.0, 50.0, 50.0))), 768)
    report = check_face_layout(h11)
    assert report.corrections == {} and report.warnings == [], report.warnings
    assert len(report.faces) == 6 and max(fl.margin for fl in report.faces.values()) < LAYOUT_MARGIN - 0.05
    turned = _with(h11, "bottom", np.rot90(h11.faces["bottom"].photo, 2))
    assert check_face_layout(turned).corrections == {"bottom": "rot180"}
