"""The Mokume sample reader: faces, maps and H11's knot in block coordinates."""

import os
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from woodcam.block import read_block, read_mokume, write_block
from woodcam.errors import WoodcamError
from woodcam.frames import FACES, pixel_to_block


def _mokume(sample: str) -> Path:
    root = Path(os.environ.get("WOODCAM_SHARED_DATA", Path(__file__).resolve().parents[2].parent / "shared" / "data"))
    folder = root / "mokume" / sample
    if not folder.is_dir():
        pytest.skip(f"Mokume sample {sample} not found under {root} (set WOODCAM_SHARED_DATA)")
    return folder


def test_reads_all_faces_as_stored():
    folder = _mokume("CN03")
    b = read_mokume(folder)
    assert b.size_mm == (50.0, 50.0, 50.0) and b.name == "CN03" and list(b.faces) == list(FACES)
    front = b.faces["front"]                                    # letter A
    assert np.array_equal(front.photo, np.asarray(Image.open(folder / "A_col.png").convert("RGB")))
    arl = np.asarray(Image.open(folder / "A_arl-unet.png"), dtype=float) / 255
    assert front.ring_map.dtype == np.float32 and np.abs(front.ring_map - arl).max() < 1e-6
    assert np.array_equal(b.faces["back"].photo, np.asarray(Image.open(folder / "F_col.png").convert("RGB")))
    assert not any("knot_mask" in f.extras for f in b.faces.values())
    assert read_mokume(folder, size_mm=(40, 40, 40)).size_mm == (40.0, 40.0, 40.0)


def test_h11_knot_on_left_and_back_at_the_back_left_edge():
    b = read_mokume(_mokume("H11"))
    W, D, H = b.size_mm
    with_knot = [n for n, f in b.faces.items() if "knot_mask" in f.extras]
    assert with_knot == ["left", "back"]                        # Mokume C and F
    centres = {}
    for name in with_knot:
        f = b.faces[name]
        rows, cols = np.nonzero(f.extras["knot_mask"])
        assert len(rows) >= 1
        centres[name] = pixel_to_block(name, rows.mean(), cols.mean(), f.shape, b.size_mm)
    left, back = centres["left"], centres["back"]
    assert left[0] == 0.0 and back[1] == D                      # on their faces
    assert left[1] > D / 2 and back[0] < W / 2                  # both towards the back-left edge
    assert left[2] < H / 2 and back[2] < H / 2                  # both low
    for p in (left, back):                                      # within half a side of that edge
        assert np.hypot(p[0] - 0.0, p[1] - D) < 0.5 * W
    # the masks mark the dark knot in the photos: darker than the face around it
    for name in with_knot:
        f = b.faces[name]
        lum = f.photo.astype(float).mean(axis=2)
        r, c = np.argwhere(f.extras["knot_mask"]).mean(axis=0)
        rr, cc = np.ogrid[:f.shape[0], :f.shape[1]]
        disc = (rr - r) ** 2 + (cc - c) ** 2 < 15 ** 2
        assert lum[disc].mean() < np.median(lum) - 15, name


def test_a_one_pixel_knot_mark_grows_to_the_dark_knot_around_it(tmp_path):
    """H11's knot masks mark one pixel per knot; the face's knot_mask is the dark disc of the
    photo around that pixel (connected to it: another dark patch on the face is not the knot)."""
    rr, cc = np.mgrid[:96, :128]
    knot = (rr - 40) ** 2 + (cc - 50) ** 2 < 20 ** 2
    other = (rr - 70) ** 2 + (cc - 110) ** 2 < 8 ** 2  # a dark patch of its own
    photo = np.full((96, 128, 3), 200, np.uint8)
    photo[knot | other] = 90
    mark = np.full((96, 128), 255, np.uint8)
    mark[40, 50] = 0
    Image.fromarray(photo).save(tmp_path / "C_col.png")
    Image.fromarray(mark).save(tmp_path / "C_knot.png")
    mask = read_mokume(tmp_path).faces["left"].extras["knot_mask"]
    assert mask[40, 50] and not (mask & other).any()
    assert (mask & knot).sum() / (mask | knot).sum() > 0.9  # the disc, not the one marked pixel


def test_mokume_block_survives_the_manifest_round_trip(tmp_path):
    b = read_mokume(_mokume("H11"))
    write_block(b, tmp_path, ring_map_bits=8)
    back = read_block(tmp_path)
    for name, f in b.faces.items():
        assert np.array_equal(back.faces[name].photo, f.photo)
        assert np.array_equal(back.faces[name].ring_map, f.ring_map)   # 8-bit maps come back exactly
    assert np.array_equal(back.faces["back"].extras["knot_mask"], b.faces["back"].extras["knot_mask"])


def test_mismatched_or_missing_images_raise(tmp_path):
    Image.fromarray(np.zeros((32, 32, 3), np.uint8)).save(tmp_path / "A_col.png")
    Image.fromarray(np.zeros((16, 32), np.uint8)).save(tmp_path / "A_arl-unet.png")
    with pytest.raises(WoodcamError, match=r"Mokume image A_\S+\.png must be 32x32 px like its face; got 16x32"):
        read_mokume(tmp_path)
    with pytest.raises(WoodcamError, match="must hold Mokume files like A_col.png"):
        read_mokume(tmp_path / "..")
    with pytest.raises(WoodcamError, match="is not a directory"):
        read_mokume(tmp_path / "nope")


def test_mokume_names_are_read_in_any_case(tmp_path, recwarn):
    """A Mokume sample's files renamed or unpacked upper-case (A_COL.PNG, A_ARL-UNET.PNG: a
    case-insensitive file system keeps them so, and opened them by the lower-case name): read on
    a case-sensitive one they were 'must hold Mokume files ... found none', and 'block from-photos'
    read A_COL.PNG as the front's photo but called A_ARL-UNET.PNG 'named for no face'. Now both
    read the names in any case, at one home (block.io.mokume_kind); two files of one kind whose
    names differ in case only are an error naming them."""
    from woodcam.block.photos import block_from_photos

    src = _mokume("H11")
    d = tmp_path / "H11"
    d.mkdir()
    for p in src.iterdir():
        (d / (p.name.upper() if p.stem[0] in "ACF" else p.name)).write_bytes(p.read_bytes())
    want, got = read_mokume(src), read_mokume(d)
    assert list(got.faces) == list(want.faces)
    for name, face in want.faces.items():
        assert np.array_equal(got.faces[name].photo, face.photo)
        assert np.array_equal(got.faces[name].ring_map, face.ring_map)
        assert sorted(got.faces[name].extras) == sorted(face.extras)
    block_from_photos(d, (50, 50, 50))
    said = [str(w.message) for w in recwarn]
    assert not any("named for no face" in m for m in said), said
    assert any("ring maps A_ARL-UNET.PNG, B_arl-unet.png" in m and "knot masks C_KNOT.PNG, F_KNOT.PNG are not read" in m
               for m in said), said
    (d / "A_col.png").write_bytes((src / "A_col.png").read_bytes())
    with pytest.raises(WoodcamError, match=r"holds 2 col files of face 'front' \(A_COL.PNG, A_col.png\), names "
                                           r"differing in case only; keep one, named A_col.png"):
        read_mokume(d)
