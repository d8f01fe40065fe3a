"""``woodcam block from-photos``, ``woodcam rings detect|show`` and photo-only blocks in ``fit``."""

from __future__ import annotations

import json
import re
import warnings
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from woodcam.block import read_block
from woodcam.cli import EXIT_ERROR, EXIT_USAGE, main
from woodcam.errors import WoodcamWarning
from woodcam.frames import FACES


@pytest.fixture(scope="module")
def synth_photos(tmp_path_factory) -> Path:
    """Six 160 px face photos of a synthetic rift-sawn 50 mm cube, named front.png ..."""
    from woodcam.synth import AnalyticLogField, cut_block, synth_block

    field = cut_block(AnalyticLogField(ring_width_mm=3.0, eccentricity=0.05), (50, 50, 50), "rift")
    block = synth_block(field, (50, 50, 50), face_px=160, seed=4, ring_map_faces=())
    folder = tmp_path_factory.mktemp("photos")
    for name, f in block.faces.items():
        Image.fromarray(f.photo).save(folder / f"{name}.png")
    return folder


def _run(capsys, *argv) -> tuple[int, str, str]:
    rc = main([str(a) for a in argv])
    out = capsys.readouterr()
    return rc, out.out, out.err


def _copy(src: Path, dst: Path, skip=()) -> Path:
    dst.mkdir()
    for p in src.iterdir():
        if p.stem not in skip:
            (dst / p.name).write_bytes(p.read_bytes())
    return dst


def test_from_photos_detect_show_and_fit(synth_photos, tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    blk = tmp_path / "blk"
    rc, _out, err = _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50x50x50", "--out", blk)
    assert rc == 0, err
    b = read_block(blk)
    assert list(b.faces) == list(FACES) and all(f.photo is not None and not f.has_rings for f in b.faces.values())
    # fit on the photo-only folder: detection runs once, cached outside the folder
    before = sorted(p.name for p in blk.iterdir())
    rc, _out, err = _run(capsys, "fit", blk, "--out", tmp_path / "f.npz")
    assert rc == 0, err
    assert sorted(p.name for p in blk.iterdir()) == before
    # one entry for the block, and one per face (a photo retaken re-detects its face alone)
    assert len(list((tmp_path / "cache" / "detect").glob("*.npz"))) == 1 + len(FACES)
    # the cached detection keeps which pieces are one ring (RingTrace.ring)
    from woodcam.detect.block import with_detected_rings

    fresh = with_detected_rings(read_block(blk), cache=False)
    cached = with_detected_rings(read_block(blk))
    for name in FACES:
        rings = [t.ring for t in fresh.faces[name].traces]
        assert [t.ring for t in cached.faces[name].traces] == rings and None not in rings, name
    # detect into the folder: ring maps, SVG traces read back, knot-free
    rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", blk)
    assert rc == 0, err
    b = read_block(blk)
    for name, f in b.faces.items():
        assert (blk / f"{name}_traces.svg").is_file()
        assert f.traces and f.ring_map is not None and f.ring_map.max() > 0.99, name
        assert [t.ring for t in f.traces] == [t.ring for t in fresh.faces[name].traces], name
        assert "knot_mask" not in f.extras
    rc, _out, err = _run(capsys, "rings", "show", blk, "--out", tmp_path / "check.png")
    assert rc == 0, err
    with Image.open(tmp_path / "check.png") as im:
        assert im.size == (4 * 2 * 160, 3 * 2 * 160)


def test_from_photos_prints_a_next_command_that_pastes(synth_photos, tmp_path, capsys):
    """'next: woodcam rings detect my block --out my block' was four words where two paths were
    meant: the shell split the folder name."""
    import shlex

    blk = tmp_path / "my blöck"
    rc, out, _err = _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50", "--out", blk)
    assert rc == 0
    assert shlex.split(out.split("next: ")[1]) == ["woodcam", "rings", "detect", str(blk), "--out", str(blk)]


def test_size_mm_on_a_block_folder_is_said_to_be_unused(synth_photos, tmp_path, capsys):
    """rings detect / rings show BLOCKDIR --size-mm 30 exited 0 without a word while the block kept
    its own 50 mm (block show and fit warned)."""
    blk = tmp_path / "blk"
    assert _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50", "--out", blk)[0] == 0
    for size, argv in (("30", ("rings", "detect", blk, "--out", blk, "--no-knots")),
                       ("40", ("rings", "show", blk, "--out", tmp_path / "s.png"))):
        rc, _out, err = _run(capsys, *argv, "--size-mm", size)
        said = f"--size-mm (size_mm ({size}.0, {size}.0, {size}.0)) is for Mokume sample folders"
        assert rc == 0 and said in err and "(50.0, 50.0, 50.0) mm, which is used" in err, (argv, err)
    assert read_block(blk).size_mm == (50.0, 50.0, 50.0)


def test_corrected_svg_wins_over_detection(synth_photos, tmp_path, capsys):
    blk = tmp_path / "blk"
    assert _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50", "--out", blk)[0] == 0
    assert _run(capsys, "rings", "detect", blk, "--out", blk)[0] == 0
    # the user redraws the front face's rings as one straight line (Inkscape writes paths)
    svg = blk / "front_traces.svg"
    svg.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="160" height="160" viewBox="0 0 160 160">'
                   '<path d="M 10.5,20.5 L 150.5,20.5" data-year="3"/></svg>')
    rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", blk)
    # named by its path as an edited image is, its one trace in the singular
    assert rc == 0 and f"kept the corrected {svg} (1 trace; it is not the SVG detection wrote there)" in err, err
    b = read_block(blk)
    tr = b.faces["front"].traces
    assert len(tr) == 1 and tr[0].year == 3 and np.allclose(tr[0].points_px, [[20, 10], [20, 150]])
    assert b.faces["front"].ring_map[20, 80] > 0.99 and b.faces["front"].ring_map[60, 80] < 0.01
    assert len(b.faces["top"].traces) > 1            # the other faces are detected again
    assert json.loads((blk / "block.json").read_text())["meta"]["detection"]["user_svg"] == ["front"]


def test_a_corrected_svg_survives_an_interrupted_detection(synth_photos, tmp_path, capsys, monkeypatch):
    """A Ctrl-C of 'rings detect X --out X' after its manifest was written and before its SVGs
    were: the manifest then named no SVG, and the next run overwrote the user's correction."""
    import woodcam.block.svg as svg_mod

    blk = tmp_path / "blk"
    assert _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50", "--out", blk)[0] == 0
    assert _run(capsys, "rings", "detect", blk, "--out", blk)[0] == 0
    mine = ('<svg xmlns="http://www.w3.org/2000/svg" width="160" height="160" viewBox="0 0 160 160">'
            '<path d="M 10.5,20.5 L 150.5,20.5" data-year="3"/></svg>')
    (blk / "front_traces.svg").write_text(mine)
    real, calls = svg_mod.write_traces_svg, []

    def interrupted(*a, **k):  # Ctrl-C while the second face's SVG is written
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(*a, **k)

    monkeypatch.setattr(svg_mod, "write_traces_svg", interrupted)
    assert _run(capsys, "rings", "detect", blk, "--out", blk)[0] == 130
    monkeypatch.setattr(svg_mod, "write_traces_svg", real)
    rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", blk)
    assert rc == 0 and f"kept the corrected {blk / 'front_traces.svg'} (1 trace; " in err
    assert (blk / "front_traces.svg").read_text() == mine


def test_a_corrected_svg_in_another_out_folder_is_kept(synth_photos, tmp_path, capsys):
    """'rings detect SRC --out OTHER' looked for corrections in SRC only, and overwrote the one
    the user had made in OTHER."""
    blk, det = tmp_path / "blk", tmp_path / "det"
    assert _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50", "--out", blk)[0] == 0
    assert _run(capsys, "rings", "detect", blk, "--out", det)[0] == 0
    mine = ('<svg xmlns="http://www.w3.org/2000/svg" width="160" height="160" viewBox="0 0 160 160">'
            '<path d="M 10.5,20.5 L 150.5,20.5" data-year="3"/></svg>')
    (det / "front_traces.svg").write_text(mine)
    rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", det)
    assert rc == 0 and f"kept the corrected {det / 'front_traces.svg'} (1 trace; " in err
    assert (det / "front_traces.svg").read_text() == mine


def test_a_corrected_svg_drawn_over_another_photo_is_refused(synth_photos, tmp_path, capsys):
    """'rings detect NEW --out OLD' kept the SVG corrected over OLD's front photo as the rings of
    NEW's front photo (H11 with its front turned 90 degrees took rings drawn across it), with
    only 'kept the corrected front_traces.svg'. Now it is refused, naming the face, the SVG and
    the fix, and nothing in OLD is touched; the same photos keep the correction."""
    old, new, det = tmp_path / "old", tmp_path / "new", tmp_path / "det"
    turned = _copy(synth_photos, tmp_path / "turned")
    Image.open(turned / "front.png").rotate(90).save(turned / "front.png")
    assert _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50", "--out", old)[0] == 0
    assert _run(capsys, "block", "from-photos", turned, "--size-mm", "50", "--out", new)[0] == 0
    assert _run(capsys, "rings", "detect", old, "--out", det)[0] == 0
    mine = ('<svg xmlns="http://www.w3.org/2000/svg" width="160" height="160" viewBox="0 0 160 160">'
            '<path d="M 10.5,20.5 L 150.5,20.5" data-year="3"/></svg>')
    (det / "front_traces.svg").write_text(mine)
    before = {p.name: p.read_bytes() for p in det.iterdir()}
    rc, out, err = _run(capsys, "rings", "detect", new, "--out", det)
    assert rc == EXIT_ERROR and "kept the corrected" not in out + err
    assert (f"face 'front': the corrected {det / 'front_traces.svg'} was traced over another front photo "
            "than this block's") in err
    assert "move front_traces.svg out of" in err and "detect into another --out" in err
    assert {p.name: p.read_bytes() for p in det.iterdir()} == before
    # the photos it was drawn over: kept, as before
    rc, _out, err = _run(capsys, "rings", "detect", old, "--out", det)
    assert rc == 0 and f"kept the corrected {det / 'front_traces.svg'} (1 trace; " in err
    assert (det / "front_traces.svg").read_text() == mine


def test_an_interrupted_from_photos_leaves_the_earlier_block_whole(synth_photos, tmp_path, capsys, monkeypatch):
    """A Ctrl-C of 'block from-photos NEW --out BLK' into the block folder of an earlier run, once
    its first photo was written: BLK held the new front photo beside the old faces and the old
    manifest (with the old run's rings), a block of two runs read without a word. The photos,
    maps and manifest now land together: interrupted, BLK is the earlier block byte for byte."""
    import woodcam.block.io as io_mod

    blk = tmp_path / "blk"
    turned = _copy(synth_photos, tmp_path / "turned")
    Image.open(turned / "front.png").rotate(90).save(turned / "front.png")
    assert _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50", "--out", blk)[0] == 0
    assert _run(capsys, "rings", "detect", blk, "--out", blk)[0] == 0
    before = {p.name: p.read_bytes() for p in blk.iterdir()}
    real, calls = io_mod._write_png, []

    def interrupted(path, a):  # Ctrl-C while the second photo is written
        calls.append(path.name)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(path, a)

    monkeypatch.setattr(io_mod, "_write_png", interrupted)
    assert _run(capsys, "block", "from-photos", turned, "--size-mm", "50", "--out", blk)[0] == 130
    assert calls == ["front_photo.png", "top_photo.png"]
    assert {p.name: p.read_bytes() for p in blk.iterdir()} == before  # no mix, no temporary file
    monkeypatch.setattr(io_mod, "_write_png", real)
    assert _run(capsys, "block", "from-photos", turned, "--size-mm", "50", "--out", blk)[0] == 0
    new = np.asarray(Image.open(turned / "front.png").convert("RGB"))
    assert np.array_equal(read_block(blk).faces["front"].photo, new)  # the new block, whole


def test_a_block_made_again_in_its_folder_keeps_its_corrected_svgs(synth_photos, tmp_path, capsys):
    """The layout check says "turn its photo top.png ... and make the block again": remade with
    'block from-photos' into its folder, the block's manifest dropped the detection's record and
    the next 'rings detect' took the corrected front SVG for the detector's and overwrote it
    without a word. The record is kept: the correction of the unchanged front photo stays; one
    of a photo that changed is refused, not overwritten."""
    blk = tmp_path / "blk"
    turned = _copy(synth_photos, tmp_path / "turned")
    Image.open(turned / "top.png").rotate(90).save(turned / "top.png")
    assert _run(capsys, "block", "from-photos", turned, "--size-mm", "50", "--out", blk)[0] == 0
    assert _run(capsys, "rings", "detect", blk, "--out", blk)[0] == 0
    mine = ('<svg xmlns="http://www.w3.org/2000/svg" width="160" height="160" viewBox="0 0 160 160">'
            '<path d="M 10.5,20.5 L 150.5,20.5" data-year="3"/></svg>')
    (blk / "front_traces.svg").write_text(mine)
    (blk / "top_traces.svg").write_text(mine)
    assert _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50", "--out", blk)[0] == 0
    assert read_block(blk).faces["front"].traces == []  # no rings before 'rings detect'
    rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", blk)
    assert rc == EXIT_ERROR and "face 'top': the corrected" in err and "traced over another top photo" in err
    assert (blk / "front_traces.svg").read_text() == mine and (blk / "top_traces.svg").read_text() == mine
    (blk / "top_traces.svg").unlink()  # as the error says
    rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", blk)
    assert rc == 0 and f"kept the corrected {blk / 'front_traces.svg'} (1 trace; " in err and "top_traces" not in err
    assert (blk / "front_traces.svg").read_text() == mine
    assert len(read_block(blk).faces["top"].traces) > 1  # detected afresh on the new top photo


def test_a_corrected_svg_of_a_face_the_block_no_longer_has_is_left_and_said(synth_photos, tmp_path, capsys):
    """A block made again into its folder with --partial and without a face whose SVG was
    corrected, or 'rings detect NEW --out OLD' where OLD holds such a face's correction, ended
    'rings detect' as an internal error (KeyError: 'back'). The SVG is left untouched and said."""
    mine = ('<svg xmlns="http://www.w3.org/2000/svg" width="160" height="160" viewBox="0 0 160 160">'
            '<path d="M 10.5,20.5 L 150.5,20.5"/></svg>')
    five = _copy(synth_photos, tmp_path / "five", skip=("back",))
    new = tmp_path / "new"
    assert _run(capsys, "block", "from-photos", five, "--size-mm", "50", "--partial", "--out", new)[0] == 0
    for again in (True, False):
        blk = tmp_path / f"blk{again}"
        assert _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50", "--out", blk)[0] == 0
        assert _run(capsys, "rings", "detect", blk, "--out", blk, "--no-knots")[0] == 0
        (blk / "back_traces.svg").write_text(mine)
        if again:  # made again in its folder without the back photo
            assert _run(capsys, "block", "from-photos", five, "--size-mm", "50", "--partial", "--out", blk)[0] == 0
        rc, _out, err = _run(capsys, "rings", "detect", blk if again else new, "--out", blk, "--no-knots")
        assert rc == 0, err
        assert (f"woodcam: warning: face 'back': the corrected {blk / 'back_traces.svg'} is not used: the block "
                f"has no back face (made without its photo); move it out of '{blk}' to keep it") in err, err
        assert (blk / "back_traces.svg").read_text() == mine and "back" not in read_block(blk).faces


def test_a_face_too_large_to_detect_is_refused_before_allocating_with_the_density_that_fits(
        synth_photos, tmp_path, capsys, monkeypatch):
    """A block of phone photos under a high --max-px-per-mm (8000x6000 px faces) made rings detect
    ask for ~60 GB and be killed, a 1500x2000 px face took 4 GB and minutes, nothing said ahead.
    Now a face over MAX_ALLOC_BYTES (DETECT_BYTES_PER_PX a pixel) is refused before any work,
    naming the face, its size and density, and the --max-px-per-mm that fits; that one passes."""
    from woodcam.detect.block import DETECT_BYTES_PER_PX

    blk = tmp_path / "blk"
    assert _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50", "--out", blk)[0] == 0
    monkeypatch.setenv("WOODCAM_MAX_ALLOC_BYTES", "2e7")  # 160 x 160 px faces need 33 MB
    assert 160 * 160 * DETECT_BYTES_PER_PX > 2e7 > 120 * 120 * DETECT_BYTES_PER_PX
    rc, out, err = _run(capsys, "rings", "detect", blk, "--out", blk)
    assert rc == EXIT_ERROR and out == "" and err.count("\n") == 1, err
    assert ("ring detection on face 'front' (160x160 px at 3.2 px/mm; memory) needs 3.328e+07 bytes (31.7 MiB), more than "
            "the limit MAX_ALLOC_BYTES = 2e+07 bytes (19.1 MiB); make the block again with 'woodcam block from-photos ... "
            "--max-px-per-mm 2.4' or lower") in err, err
    assert not (blk / "front_traces.svg").exists()
    assert _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50", "--max-px-per-mm", "2.4",
                "--out", blk)[0] == 0
    rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", blk, "--no-knots")
    assert rc == 0, err


def test_a_block_made_into_a_folder_with_an_unreadable_manifest_is_written(synth_photos, tmp_path, capsys):
    """Review of 1507a56: 'block from-photos' reads the detection record of the block folder it
    writes into, and a block.json there that is not a block manifest (cut short, or another
    JSON) ended the command as an internal error, where it was overwritten before. It is
    overwritten again, with a warning that no SVG correction could be kept from it."""
    for text in ('{"format": "woodcam-block", "faces": {', "[1, 2]", '{"meta": [], "faces": []}'):
        blk = tmp_path / f"blk{len(text)}"
        blk.mkdir()
        (blk / "block.json").write_text(text)
        rc, _out, err = _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50", "--out", blk)
        assert rc == 0, err
        assert re.search(r"woodcam: warning: '.*block.json' is no readable block manifest .*no corrected SVG", err), err
        assert sorted(read_block(blk).faces) == ["back", "bottom", "front", "left", "right", "top"]


def test_rings_detect_into_a_folder_with_an_unreadable_manifest_writes_over_it(synth_photos, tmp_path, capsys):
    """'rings detect BLOCK --out OUT' looks for SVG corrections in OUT, and a block.json there cut
    short or another JSON ended the command as an internal error (JSONDecodeError from
    user_edited_faces). As 'block from-photos' does (574bdb5): a warning, and the block written."""
    blk = tmp_path / "blk"
    assert _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50", "--out", blk)[0] == 0
    for text in ('{"format": "woodcam-block", "faces": {', "[1, 2]"):
        out = tmp_path / f"out{len(text)}"
        out.mkdir()
        (out / "block.json").write_text(text)
        rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", out, "--no-knots")
        assert rc == 0, err
        assert re.search(r"woodcam: warning: '.*block.json' is no readable block manifest .*no corrected SVG", err), err
        b = read_block(out)
        assert sorted(b.faces) == ["back", "bottom", "front", "left", "right", "top"]
        assert all((out / f"{n}_traces.svg").is_file() for n in b.faces)


def test_rings_show_names_a_face_with_no_rings(synth_photos, tmp_path, capsys, monkeypatch):
    """A face detection found no rings on (warned at 'rings detect') was drawn by 'rings show' as
    its bare photo under its plain name, like any face, and 'wrote check.png' said nothing of it:
    the check picture let an empty face pass for one not looked at. Its label now reads
    'back (F): no rings' and the line names it with the SVG to trace it in."""
    from woodcam.block.render import label_face
    from woodcam.detect.show import face_picture

    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    photos = _copy(synth_photos, tmp_path / "photos", skip=("back",))
    rng = np.random.default_rng(3)  # smooth end grain: a slight gradient and sensor noise, no rings
    plain = 150 + 10 * np.linspace(0, 1, 160)[:, None, None] + rng.normal(0, 3, (160, 160, 3))
    Image.fromarray(np.clip(plain, 0, 255).astype(np.uint8)).save(photos / "back.png")
    blk = tmp_path / "blk"
    assert _run(capsys, "block", "from-photos", photos, "--size-mm", "50", "--out", blk)[0] == 0
    rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", blk)
    assert rc == 0 and "face 'back': no rings found" in err, err
    rc, out, err = _run(capsys, "rings", "show", blk, "--out", tmp_path / "check.png")
    assert rc == 0, err
    assert out.strip() == (f"wrote {tmp_path / 'check.png'} (no rings on back: trace them in "
                           f"{blk / 'back_traces.svg'})"), out
    b = read_block(blk)
    back, front = b.faces["back"], b.faces["front"]
    zoomed = np.asarray(Image.fromarray(back.photo).resize((320, 320), Image.NEAREST))
    assert np.array_equal(face_picture(back), label_face(zoomed, "back", "no rings"))
    assert front.traces and not np.array_equal(face_picture(front)[:40], label_face(
        np.asarray(Image.fromarray(front.photo).resize((320, 320), Image.NEAREST)), "front", "no rings")[:40])


def test_the_detection_cache_stays_in_the_cache_whatever_the_block_is_named(synth_photos, tmp_path, monkeypatch):
    """A block named "../../escaped/evil" cached its detection outside the cache folder, and a
    name of 250 characters failed with 'File name too long'."""
    from woodcam.block.photos import block_from_photos
    from woodcam.detect.block import with_detected_rings

    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    block = block_from_photos(synth_photos, (50.0, 50.0, 50.0))
    for name in ("../../escaped/evil", "L" * 250):
        block.name = name
        assert with_detected_rings(block).faces["top"].traces
    assert not (tmp_path / "escaped").exists()
    files = [p for p in (tmp_path / "cache").rglob("*") if p.is_file()]
    assert files and all(p.parent == tmp_path / "cache" / "detect" for p in files)


def test_mokume_folder_is_redetected(tmp_path, capsys):
    """... and its own ring maps and knot masks, passed over without a word (the knot masks
    written seemed Mokume's), are named in one warning with what is used instead."""
    from .test_detect_rings import _mokume

    src = _mokume("H11")
    rc, _out, err = _run(capsys, "rings", "detect", src, "--out", tmp_path / "h11")
    assert rc == 0, err
    (line,) = err.splitlines()
    assert line == (f"woodcam: warning: '{src}': Mokume's ring maps A_arl-unet.png, B_arl-unet.png, C_arl-unet.png, "
                    "D_arl-unet.png, E_arl-unet.png, F_arl-unet.png and knot masks C_knot.png, F_knot.png are not "
                    "read: rings and knots are detected on its photos afresh; to use Mokume's maps instead, give the "
                    f"sample folder itself to fit, bake or eval ({src} --size-mm SIDE, a Mokume sample being a cube; bake "
                    "reads it as a 50 mm cube)"), line
    b = read_block(tmp_path / "h11")
    assert set(b.faces) == set(FACES)
    assert {n for n, f in b.faces.items() if "knot_mask" in f.extras} >= {"left", "back"}


def test_from_photos_of_a_mokume_folder_names_the_maps_it_does_not_read(tmp_path, capsys):
    """'block from-photos H11' read the six A_col.png ... and passed over Mokume's six ring maps
    (A_arl-unet.png ...) and two knot masks (C_knot.png, F_knot.png) without a word; the block
    holds the photos alone. One warning names them, what is used instead and how to use them."""
    from .test_detect_rings import _mokume

    src = _mokume("H11")
    rc, out, err = _run(capsys, "block", "from-photos", src, "--size-mm", "50", "--out", tmp_path / "b")
    assert rc == 0 and out.startswith("wrote "), err
    (line,) = err.splitlines()
    assert line.startswith(f"woodcam: warning: '{src}': Mokume's ring maps A_arl-unet.png, B_arl-unet.png, "
                           "C_arl-unet.png, D_arl-unet.png, E_arl-unet.png, F_arl-unet.png and knot masks "
                           "C_knot.png, F_knot.png are not read"), line
    assert "'woodcam rings detect' finds the rings and knots on them" in line
    assert f"give the sample folder itself to fit, bake or eval ({src} --size-mm SIDE, a Mokume sample" in line
    b = read_block(tmp_path / "b")
    assert all(f.photo is not None and f.ring_map is None and not f.extras for f in b.faces.values())
    # a folder of photos alone says nothing
    photos = tmp_path / "photos"
    photos.mkdir()
    for p in src.glob("*_col.png"):
        (photos / p.name).write_bytes(p.read_bytes())
    rc, _out, err = _run(capsys, "block", "from-photos", photos, "--size-mm", "50", "--out", tmp_path / "c")
    assert rc == 0 and err == "", err


def test_the_missing_face_error_lists_the_found_faces_in_the_conventions_order(synth_photos, tmp_path, capsys):
    """'found back, bottom, left, right, top': the files' order, not the faces' (frames.FACES)."""
    rc, _out, err = _run(capsys, "block", "from-photos", _copy(synth_photos, tmp_path / "a", skip=("front",)),
                        "--size-mm", "50", "--out", tmp_path / "o")
    assert rc == EXIT_ERROR and "missing face photos: front (found top, left, bottom, right, back);" in err, err
    assert FACES == ("front", "top", "left", "bottom", "right", "back")  # the order said above


def test_bad_photo_folders_give_one_clear_line(synth_photos, tmp_path, capsys):
    rc, _out, err = _run(capsys, "block", "from-photos", _copy(synth_photos, tmp_path / "a", skip=("back",)),
                        "--size-mm", "50x50x50", "--out", tmp_path / "o")
    assert rc == EXIT_ERROR and "missing face photos: back" in err and err.count("\n") == 1
    d = _copy(synth_photos, tmp_path / "b")
    with Image.open(d / "top.png") as im:
        im.resize((160, 120)).save(d / "top.png")
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50x50x50", "--out", tmp_path / "o")
    assert rc == EXIT_ERROR and "face 'top'" in err and "aspect" in err
    d = _copy(synth_photos, tmp_path / "c")
    Image.fromarray(np.full((160, 160, 3), 128, np.uint8)).save(d / "left.png")
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50x50x50", "--out", tmp_path / "o")
    assert rc == EXIT_ERROR and "face 'left'" in err and "blank" in err
    Image.fromarray(np.full((160, 160, 3), 255, np.uint8)).save(d / "left.png")  # it was called blank
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50x50x50", "--out", tmp_path / "o")
    assert rc == EXIT_ERROR and "face 'left'" in err and "over-exposed" in err
    d = _copy(synth_photos, tmp_path / "d")
    with Image.open(d / "right.png") as im:
        a = np.asarray(im).copy()
    a[:110] = 255
    Image.fromarray(a).save(d / "right.png")
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50x50x50", "--out", tmp_path / "o")
    assert rc == EXIT_ERROR and "face 'right'" in err and "over-exposed" in err
    with pytest.raises(SystemExit) as exc:  # a wrong command line, refused by argparse before any photo is read
        _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50x0x50", "--out", tmp_path / "o")
    assert exc.value.code == EXIT_USAGE and "--size-mm" in capsys.readouterr().err


def test_phone_photos_are_read_upright_by_their_exif_orientation(synth_photos, tmp_path, capsys):
    """A phone stores a portrait photo as landscape pixels plus an EXIF orientation tag that
    every viewer honours; read raw, the face's rings were turned 90 degrees (on a cube silently).
    The front photo saved that way (pixels turned a quarter, tag 6 = turn them clockwise to
    view) reads back as the upright photo. Checked by breaking it: without the EXIF turn the
    face differs from the upright photo by 27 grey levels on average, with it by JPEG noise."""
    d = _copy(synth_photos, tmp_path / "exif", skip=("front",))
    with Image.open(synth_photos / "front.png") as im:
        upright = np.asarray(im.convert("RGB"))
    exif = Image.Exif()
    exif[0x0112] = 6  # Orientation: rotate 90 degrees clockwise to display
    Image.fromarray(np.rot90(upright).copy()).save(d / "front.jpg", quality=95, exif=exif)
    blk = tmp_path / "blk"
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50x50x50", "--out", blk)
    assert rc == 0, err
    got = read_block(blk).faces["front"].photo.astype(float)
    assert got.shape == upright.shape
    assert np.abs(got - upright).mean() < 3.0
    assert np.abs(got - np.rot90(upright)).mean() > 10.0


def test_a_photo_with_damaged_exif_is_named_in_a_warning(synth_photos, tmp_path, capsys):
    """A photo whose EXIF block is damaged: Pillow's warning ('Tag data larger than file') was a
    UserWarning, which the CLI drops, so the user never heard that the photo's record of which
    way is up may be lost. Now a warning on stderr names the face's file and what became of its
    orientation tag: read and applied (here, tag 6 before the damaged description), or not read
    at all (an EXIF block Pillow reads nothing from, and says nothing of)."""
    d = _copy(synth_photos, tmp_path / "exif", skip=("front", "top"))
    with Image.open(synth_photos / "front.png") as im:
        upright = np.asarray(im.convert("RGB"))
    exif = Image.Exif()
    exif[0x0112] = 6  # Orientation: rotate 90 degrees clockwise to display
    exif[0x010E] = "x" * 200  # ImageDescription, stored after the tags: cut off below
    Image.fromarray(np.rot90(upright).copy()).save(d / "front.jpg", quality=95, exif=exif.tobytes()[:-150])
    with Image.open(synth_photos / "top.png") as im:
        im.convert("RGB").save(d / "top.jpg", quality=95, exif=b"Exif\x00\x00" + b"\x13" * 40)
    blk = tmp_path / "blk"
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--out", blk)
    assert rc == 0, err
    lines = err.splitlines()
    front = [w for w in lines if "front.jpg" in w]
    assert front == [f"woodcam: warning: photo of face 'front': {str(d / 'front.jpg')!r} has damaged EXIF data "
                     "(Tag data larger than file. Skipping tag 270); its orientation tag (6) was read and applied: "
                     "check that the image shows the right way up, or save it again from a photo editor to "
                     "rewrite its EXIF"], err
    (top,) = [w for w in lines if "top.jpg" in w]
    assert "has damaged EXIF data (none of its 46 bytes could be read); no orientation tag could be read" in top
    # the orientation still applied: the front reads back upright
    assert np.abs(read_block(blk).faces["front"].photo.astype(float) - upright).mean() < 3.0


def test_heic_photos_are_read(synth_photos, tmp_path, capsys):
    """HEIC, a phone camera's default format, is read (pillow-heif's opener; libheif applies the
    file's own rotation). Checked by breaking it: without ``.heic`` among the photo suffixes the
    front face is missing (in a fresh process without the opener PIL cannot identify the file)."""
    import pillow_heif

    d = _copy(synth_photos, tmp_path / "heic", skip=("front",))
    with Image.open(synth_photos / "front.png") as im:
        upright = np.asarray(im.convert("RGB"))
    pillow_heif.from_pillow(Image.fromarray(upright)).save(d / "front.heic", quality=95)
    blk = tmp_path / "blk"
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50x50x50", "--out", blk)
    assert rc == 0, err
    got = read_block(blk).faces["front"].photo.astype(float)
    assert got.shape == upright.shape and np.abs(got - upright).mean() < 4.0


def test_photos_are_read_by_their_content_not_their_name(synth_photos, tmp_path, capsys, monkeypatch):
    """Phones and messengers save HEIC under a ``.jpg`` name: it was refused as 'cannot decode'
    (pillow-heif's opener was registered for a ``.heic`` or ``.heif`` name only). A PNG named
    ``.jpg`` is read too. The opener is taken out of PIL first, as in a fresh process."""
    import pillow_heif

    monkeypatch.setattr(Image, "ID", [i for i in Image.ID if i not in ("HEIF", "AVIF")])
    for key in ("HEIF", "AVIF"):
        monkeypatch.delitem(Image.OPEN, key, raising=False)
    d = _copy(synth_photos, tmp_path / "named", skip=("front", "top"))
    upright = {}
    for name in ("front", "top"):
        with Image.open(synth_photos / f"{name}.png") as im:
            upright[name] = np.asarray(im.convert("RGB"))
    pillow_heif.from_pillow(Image.fromarray(upright["front"])).save(d / "front.jpg", quality=95)
    Image.fromarray(upright["top"]).save(d / "top.jpg", format="PNG")
    assert (d / "front.jpg").read_bytes()[4:8] == b"ftyp"
    blk = tmp_path / "blk"
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50x50x50", "--out", blk)
    assert rc == 0, err
    faces = read_block(blk).faces
    assert np.abs(faces["front"].photo.astype(float) - upright["front"]).mean() < 4.0
    assert np.array_equal(faces["top"].photo, upright["top"])


def test_jpegs_saved_as_jfif_and_avif_photos_are_found(synth_photos, tmp_path, capsys):
    """A browser or phone saves JPEGs as ``front.jfif`` (or ``.jpe``): the file was passed over
    without a word (not a photo suffix, so not even named as a stray) and the face called
    missing. AVIF, a phone camera's newer format, is found too where Pillow reads it."""
    from PIL import features

    d = _copy(synth_photos, tmp_path / "jfif", skip=("front", "top", "left"))
    for name, suffix, fmt in (("front", "jfif", "JPEG"), ("top", "JPE", "JPEG"), ("left", "avif", "AVIF")):
        if fmt == "AVIF" and not features.check("avif"):
            fmt = "PNG"  # this Pillow has no AVIF: the name is still found, the content read
        with Image.open(synth_photos / f"{name}.png") as im:
            im.convert("RGB").save(d / f"{name}.{suffix}", format=fmt, quality=95)
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--out", tmp_path / "o")
    assert rc == 0 and not err, err
    assert read_block(tmp_path / "o").meta["photos"] == {
        **{f: f"{f}.png" for f in FACES}, "front": "front.jfif", "top": "top.JPE", "left": "left.avif"}


def test_a_cut_out_photo_with_transparent_pixels_is_said(synth_photos, tmp_path, capsys):
    """A phone's cut-out of the block (a PNG with a transparent background round it) had its
    alpha dropped without a word: the background was read as the colour stored under it (black
    here) and taken for wood. Now the transparent share is named with the fix; an opaque RGBA
    PNG is read without a word."""
    d = _copy(synth_photos, tmp_path / "alpha", skip=("front", "top"))
    for name in ("front", "top"):
        with Image.open(synth_photos / f"{name}.png") as im:
            rgba = np.dstack([np.asarray(im.convert("RGB")), np.full((160, 160), 255, np.uint8)])
        if name == "front":  # the lower 10 rows cut away, transparent black
            rgba[150:] = 0
        Image.fromarray(rgba).save(d / f"{name}.png")
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--out", tmp_path / "o")
    # the black band is background beside the face too (sweep h3: a border on one side is said)
    assert rc == 0 and err.count("warning") == 2, err
    assert "photo of face 'front': " in err and "front.png' has transparent pixels (6.25 % of them" in err
    assert "crop the image so every pixel is opaque" in err
    assert "face 'front' (front.png) has a uniform border unlike the wood on its bottom side" in err


def test_a_16_bit_photo_is_scaled_not_clipped(synth_photos, tmp_path, capsys):
    """A 16-bit grey export (a raw developer's TIFF or PNG) reads as the same grey at 8 bits;
    converted raw, every value above 255 clipped to white and the face was refused as
    blank. Checked by breaking it: with the old ``convert("RGB")`` this fails."""
    d = _copy(synth_photos, tmp_path / "16", skip=("top",))
    with Image.open(synth_photos / "top.png") as im:
        grey = np.asarray(im.convert("L"))
    Image.fromarray(grey.astype(np.uint16) * 257).save(d / "top.png")
    with Image.open(d / "top.png") as im:
        assert im.mode.startswith("I;16")
    blk = tmp_path / "blk"
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50x50x50", "--out", blk)
    assert rc == 0, err
    got = read_block(blk).faces["top"].photo
    assert np.abs(got[..., 0].astype(int) - grey).max() <= 1


def _matrix_icc(name: str, primaries, gamma: float = 2.2) -> bytes:
    """An ICC v2 RGB display profile: ``primaries`` ((3, 3) D50-adapted XYZ of red, green, blue),
    one gamma for the three channels, a D50 white."""
    import struct

    def s15(v):
        return struct.pack(">i", round(v * 65536))

    def xyz(v):
        return b"XYZ " + bytes(4) + b"".join(s15(c) for c in v)

    d50 = (0.9642, 1.0, 0.8249)
    text = name.encode() + b"\0"
    curve = b"curv" + bytes(4) + struct.pack(">IH", 1, round(gamma * 256)) + bytes(2)
    tags = [(b"desc", b"desc" + bytes(4) + struct.pack(">I", len(text)) + text + bytes(78)), (b"wtpt", xyz(d50)),
            (b"rXYZ", xyz(primaries[0])), (b"gXYZ", xyz(primaries[1])), (b"bXYZ", xyz(primaries[2])),
            (b"rTRC", curve), (b"gTRC", curve), (b"bTRC", curve), (b"cprt", b"text" + bytes(4) + b"none\0")]
    start = 128 + 4 + 12 * len(tags)
    table, data = b"", b""
    for sig, body in tags:
        body += bytes(-len(body) % 4)
        table += sig + struct.pack(">II", start + len(data), len(body))
        data += body
    header = (struct.pack(">I", start + len(data)) + bytes(4) + struct.pack(">I", 0x02100000) + b"mntrRGB XYZ "
              + struct.pack(">6H", 2024, 1, 1, 0, 0, 0) + b"acsp" + bytes(28) + b"".join(s15(c) for c in d50)
              + bytes(48))
    return header + struct.pack(">I", len(tags)) + table + data


#: Display P3's primaries, D50-adapted (as Apple's profile gives them).
_P3 = ((0.515102, 0.241196, -0.001050), (0.291965, 0.692239, 0.041882), (0.157153, 0.066574, 0.784378))


def test_a_photo_with_a_display_p3_profile_is_read_as_a_viewer_shows_it(synth_photos, tmp_path, capsys):
    """An iPhone stores its photos' colours as Display P3 numbers with that ICC profile; they were
    read as sRGB numbers, the face's wood duller than every viewer shows it (the mean red of
    H11's front, so stored, 226.3 for 233.1). Now a profile of another space is converted to
    sRGB (RGB with alpha kept, CMYK too); an sRGB-tagged photo is read as it is, and a profile
    that cannot be read is said, the numbers read as sRGB."""
    import io

    from PIL import ImageCms

    icc = _matrix_icc("Display P3 (test)", _P3)
    p3 = ImageCms.ImageCmsProfile(io.BytesIO(icc))
    d = _copy(synth_photos, tmp_path / "p3")
    for name in ("front", "top"):  # what a P3 camera stores for these colours
        with Image.open(synth_photos / f"{name}.png") as im:
            shown = im.convert("RGB")
        stored = ImageCms.profileToProfile(shown, ImageCms.createProfile("sRGB"), p3)
        if name == "top":  # with an alpha channel, all opaque
            stored = stored.convert("RGBA")
        stored.save(d / f"{name}.png", icc_profile=icc)
    srgb = ImageCms.ImageCmsProfile(ImageCms.createProfile("sRGB")).tobytes()
    with Image.open(synth_photos / "left.png") as im:
        im.save(d / "left.png", icc_profile=srgb)
    with Image.open(synth_photos / "right.png") as im:
        im.save(d / "right.png", icc_profile=b"not a profile" * 20)
    blk = tmp_path / "blk"
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--out", blk)
    assert rc == 0, err
    faces = read_block(blk).faces
    for name in ("front", "top", "left", "right"):
        with Image.open(synth_photos / f"{name}.png") as im:
            shown = np.asarray(im.convert("RGB"), int)
        diff = np.abs(faces[name].photo.astype(int) - shown)
        # P3 and back through 8 bits: a level or two; read raw, the front was 4.7 levels off on average
        assert diff.mean() < 0.8 and diff.max() <= 3 if name in ("front", "top") else diff.max() == 0, (name, diff.mean())
    (line,) = err.splitlines()
    assert line.startswith(f"woodcam: warning: photo of face 'right': '{d / 'right.png'}' carries an ICC colour "
                           "profile that cannot be read (") and line.endswith("export it again as sRGB"), line


def test_a_greyscale_photo_among_colour_ones_is_said(synth_photos, tmp_path, capsys):
    """A face photographed with a phone's mono filter, or scanned in grey, was read as grey RGB
    beside five colour photos without a word, and the wood's colours fitted to it. Now it is
    named (a grey image file, or grey saved as RGB); all six grey is the user's choice, unsaid."""
    d = _copy(synth_photos, tmp_path / "g")
    with Image.open(synth_photos / "right.png") as im:
        im.convert("L").save(d / "right.png")
    with Image.open(synth_photos / "top.png") as im:
        im.convert("L").convert("RGB").save(d / "top.jpg", quality=90)
    (d / "top.png").unlink()
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--out", tmp_path / "o")
    assert rc == 0, err
    (line,) = err.splitlines()
    assert line == ("woodcam: warning: photos of faces 'top' (top.jpg), 'right' (right.png) are greyscale, the "
                    "other faces' in colour: the wood's colours are fitted from every face photo, these grey; "
                    "export or retake them in colour"), line
    for p in list(d.iterdir()):
        with Image.open(p) as im:
            im.convert("L").save(d / f"{p.stem}.png")
    (d / "top.jpg").unlink()
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--out", tmp_path / "o")
    assert rc == 0 and err == "", err


def test_rings_detect_and_show_on_a_folder_of_photos_say_to_make_a_block_first(synth_photos, tmp_path, capsys):
    """'rings detect PHOTOS' (the user's own front.jpg ..., before 'block from-photos') was 'must
    hold a block.json or Mokume files; found neither' and 'rings show PHOTOS' 'must hold Mokume
    files like A_col.png': no word of the command that makes a block of them. Both read folders
    through block.io.read_block_folder now, which names the photos and the command."""
    for argv in (("detect", synth_photos, "--out", tmp_path / "o"), ("show", synth_photos, "--out", tmp_path / "o.png")):
        rc, out, err = _run(capsys, "rings", *argv)
        assert rc == EXIT_ERROR and out == "" and err.count("\n") == 1, err
        assert "holds face photos (front.png, top.png, left.png, bottom.png, right.png, back.png)" in err and "but no block.json" in err, err
        assert f"make a block of them first: woodcam block from-photos '{synth_photos}' --size-mm WxDxH" in err, err
    assert not (tmp_path / "o").exists() and not (tmp_path / "o.png").exists()


def _ringless_bottom_block(synth_photos, tmp_path, capsys, size_mm: str):
    """A block folder ``tmp_path/blk`` from the synthetic photos ('block from-photos', cube side
    ``size_mm``) whose bottom photo is a noisy grey gradient: no rings to find there."""
    d = _copy(synth_photos, tmp_path / "p")
    rng = np.random.default_rng(0)
    grad = np.linspace(90, 170, 160)[None, :, None] + 4 * rng.standard_normal((160, 160, 3))
    Image.fromarray(np.clip(np.broadcast_to(grad, (160, 160, 3)), 0, 255).astype(np.uint8)).save(d / "bottom.png")
    blk = tmp_path / "blk"
    assert _run(capsys, "block", "from-photos", d, "--size-mm", size_mm, "--out", blk)[0] == 0
    return blk


def test_face_without_rings_is_named(synth_photos, tmp_path, capsys):
    blk = _ringless_bottom_block(synth_photos, tmp_path, capsys, "50")
    rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", blk)
    assert rc == 0 and "face 'bottom'" in err
    b = read_block(blk)
    assert b.faces["bottom"].ring_map is None or not b.faces["bottom"].traces


def test_rings_detect_warns_on_stderr_as_every_command(synth_photos, tmp_path, capsys):
    """rings detect printed its warnings (a face without rings, a kept SVG, a turned face) on
    stdout among its output, where from-photos, block show and every other command print them
    on stderr: 'rings detect ... > log' hid nothing and kept them out of the log."""
    d = _copy(synth_photos, tmp_path / "p")
    grad = np.linspace(90, 170, 160)[None, :, None] + 4 * np.random.default_rng(0).standard_normal((160, 160, 3))
    Image.fromarray(np.clip(np.broadcast_to(grad, (160, 160, 3)), 0, 255).astype(np.uint8)).save(d / "bottom.png")
    blk = tmp_path / "blk"
    assert _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--out", blk)[0] == 0
    rc, out, err = _run(capsys, "rings", "detect", blk, "--out", blk)
    assert rc == 0 and out == f"wrote {blk} (ring maps, <face>_traces.svg, no knot mask: no knot found)\n", out
    assert "woodcam: warning: face 'bottom': no rings found" in err


def test_curved_option_reaches_the_detector(synth_photos, tmp_path, capsys):
    """``rings detect --curved``: the traces written are those of ``detect_rings(curved=True)``
    (which differ from the straight bank's on this face), and the manifest says so."""
    from woodcam.detect.rings import detect_rings

    blk = tmp_path / "blk"
    rc, _out, err = _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50x50x50", "--out", blk)
    assert rc == 0, err
    rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", blk, "--curved", "--no-knots")
    assert rc == 0, err
    b = read_block(blk)
    assert json.loads((blk / "block.json").read_text())["meta"]["detection"]["curved"] is True
    face = b.faces["top"]
    px_mm = 1.0 / min(b.face_pixel_size_mm("top"))
    curved = detect_rings(face.photo, px_per_mm=px_mm, curved=True).traces
    straight = detect_rings(face.photo, px_per_mm=px_mm, curved=False).traces
    got = np.concatenate([t.points_px for t in face.traces])
    want = np.concatenate([t.points_px for t in curved])
    assert got.shape == want.shape and np.allclose(got, want, atol=0.01)
    other = np.concatenate([t.points_px for t in straight])
    assert other.shape != want.shape or not np.allclose(other, want, atol=0.01)
    rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", tmp_path / "x", "--curved", "--detector", "learned")
    assert rc != 0 and "curved" in err and err.count("\n") == 1, err


def test_gif_photos_are_read(synth_photos, tmp_path, capsys):
    """A face photo named top.gif was not found ("no face photos found, name them front.jpg ...")."""
    d = _copy(synth_photos, tmp_path / "g")
    with Image.open(d / "top.png") as im:
        im.convert("P", palette=Image.ADAPTIVE).save(d / "top.gif")
    (d / "top.png").unlink()
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--out", tmp_path / "o")
    assert rc == 0, err
    assert read_block(tmp_path / "o").faces["top"].photo.shape == (160, 160, 3)


def test_a_photo_too_small_for_rings_is_refused(synth_photos, tmp_path, capsys):
    """An 8 x 8 px face photo was enlarged to 16 x 16 and recorded at a density it lacks; detection
    then 'found' rings on it."""
    d = _copy(synth_photos, tmp_path / "t")
    with Image.open(d / "top.png") as im:
        im.resize((8, 8)).save(d / "top.png")
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--out", tmp_path / "o")
    assert rc == EXIT_ERROR and "face 'top'" in err and "8x8 px: too small to hold rings" in err


def test_a_photo_too_small_to_hold_rings_is_refused_with_the_minimum(synth_photos, tmp_path, capsys):
    """A 20 x 20 px face photo (0.4 px/mm on a 50 mm cube, rings under a pixel apart) passed the
    door; detection then read its noise and warned that a face with no rings 'looks mirrored'.
    Now one line names the face, the size received and the minimum, and nothing is written."""
    d = _copy(synth_photos, tmp_path / "t")
    with Image.open(d / "left.png") as im:
        im.resize((20, 20), Image.LANCZOS).save(d / "left.png")
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--out", tmp_path / "o")
    assert rc == EXIT_ERROR and err.count("\n") == 1, err
    assert "face 'left' (left.png) is 20x20 px: too small to hold rings" in err
    from woodcam.tolerances import MIN_FACE_PHOTO_PX

    assert f"give at least {MIN_FACE_PHOTO_PX} px a side" in err and MIN_FACE_PHOTO_PX > 20
    assert not (tmp_path / "o").exists()


def _knotted_block_folder(synth_photos, tmp_path, capsys):
    """A block folder ``tmp_path/blk`` made by 'block from-photos' of the synthetic photos with
    an analytic knot on the left face (its photos in ``tmp_path/knotted``); returns it and the --size-mm arguments that made it."""
    from .test_detect_knots import _face_with_knot

    knotted = _copy(synth_photos, tmp_path / "knotted")
    Image.fromarray(_face_with_knot(160)[0]).save(knotted / "left.png")
    blk = tmp_path / "blk"
    size = ("--size-mm", "32")  # 5 px/mm, where the analytic knot is found
    assert _run(capsys, "block", "from-photos", knotted, *size, "--out", blk)[0] == 0
    return blk, size


def test_rings_detect_says_which_faces_got_a_knot_mask(synth_photos, tmp_path, capsys, monkeypatch):
    """rings detect's summary said 'knot masks' of every block, also of one where no knot was
    found and no mask written, and under --no-knots. Now it names the faces whose mask block.json
    lists, or says there is none and why."""
    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    blk, _size = _knotted_block_folder(synth_photos, tmp_path, capsys)
    rc, out, err = _run(capsys, "rings", "detect", blk, "--out", blk)
    assert rc == 0, err
    masked = [n for n, f in read_block(blk).faces.items() if "knot_mask" in f.extras]
    assert masked and sorted(p.name for p in blk.glob("*_knot_mask.png")) == sorted(f"{n}_knot_mask.png" for n in masked)
    assert out == f"wrote {blk} (ring maps, <face>_traces.svg, knot masks of {', '.join(masked)})\n", out
    clear = tmp_path / "clear"
    assert _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50", "--out", clear)[0] == 0
    rc, out, err = _run(capsys, "rings", "detect", clear, "--out", clear, "--no-knots")
    assert rc == 0 and not list(clear.glob("*_knot_mask.png")), err
    assert out == f"wrote {clear} (ring maps, <face>_traces.svg, no knot mask: --no-knots)\n", out


def test_a_rerun_clears_its_own_stale_knot_masks_and_keeps_a_users(synth_photos, tmp_path, capsys, monkeypatch):
    """A face's knot mask from an earlier detection (left_knot_mask.png) stayed in the block
    folder after the block was remade from new photos and detected again with no knot on that
    face: a file of the old run beside the new manifest. Now the detector's own mask (its digest
    recorded) is removed; a mask the user put there (top_knot_mask.png) is kept, said, and read as
    the face's though no knot is found on it (the user's wins)."""
    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    blk, size = _knotted_block_folder(synth_photos, tmp_path, capsys)
    rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", blk)
    assert rc == 0, err
    assert (blk / "left_knot_mask.png").is_file() and "knot_mask" in read_block(blk).faces["left"].extras
    mine = np.zeros((160, 160), np.uint8)
    mine[20:40, 30:60] = 255
    Image.fromarray(mine).save(blk / "top_knot_mask.png")  # the user's own
    # the block made again from knot-free photos into its folder, and detected again
    assert _run(capsys, "block", "from-photos", synth_photos, *size, "--out", blk)[0] == 0
    rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", blk)
    assert rc == 0, err
    assert not (blk / "left_knot_mask.png").exists()
    with Image.open(blk / "top_knot_mask.png") as im:
        assert np.array_equal(np.asarray(im), mine)
    # the user's, on a face with no knot found, is the face's (it was kept unread)
    assert [n for n, f in read_block(blk).faces.items() if "knot_mask" in f.extras] == ["top"]
    assert np.array_equal(read_block(blk).faces["top"].extras["knot_mask"], mine > 127)
    said = [w for w in err.splitlines() if "knot_mask.png" in w]
    assert len(said) == 1, said
    assert said[0].startswith(f"woodcam: warning: face 'top': kept the edited {blk / 'top_knot_mask.png'} ("), said
    assert "detection made none for the face this time" in said[0], said


def test_a_rerun_clears_its_own_stale_ring_maps_and_svgs_and_keeps_a_users(synth_photos, tmp_path, capsys, monkeypatch):
    """The block remade into its folder without its back photo (--partial) and detected again:
    back_ring_map.png and back_traces.svg of the earlier detection stayed beside the new manifest,
    as knot masks did. Every file detection writes is recorded and cleared alike; a ring map the
    user edited (front's, whose face is gone too in the second remake) is kept and said."""
    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    blk = tmp_path / "blk"
    assert _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50", "--out", blk)[0] == 0
    assert _run(capsys, "rings", "detect", blk, "--out", blk)[0] == 0
    assert (blk / "back_ring_map.png").is_file() and (blk / "front_ring_map.png").is_file()
    mine = np.zeros((160, 160), np.uint8)
    mine[::8] = 255
    Image.fromarray(mine).save(blk / "front_ring_map.png")  # the user's own rings, drawn over it
    Image.fromarray(mine).save(blk / "front_knot_mask.png")  # and a knot mask of the user's
    five = _copy(synth_photos, tmp_path / "five", skip=("back", "front"))
    assert _run(capsys, "block", "from-photos", five, "--size-mm", "50", "--partial", "--out", blk)[0] == 0
    rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", blk)
    assert rc == 0, err
    assert not (blk / "back_ring_map.png").exists() and not (blk / "back_traces.svg").exists()
    assert set(read_block(blk).faces) == {"top", "bottom", "left", "right"}
    with Image.open(blk / "front_ring_map.png") as im:
        assert np.array_equal(np.asarray(im), mine)
    said = [w for w in err.splitlines() if "_ring_map.png" in w or "_traces.svg" in w]
    assert len(said) == 1 and said[0].startswith("woodcam: warning: face 'front': front_ring_map.png in "), said
    assert "is not read (the block has no such face this time" in said[0] and "is kept" in said[0]
    # a face the block lacks has no entry to name a file in: the fix fits (it said to name it in
    # block.json, a knot mask 'and detect with --no-knots')
    (knot,) = [w for w in err.splitlines() if "front_knot_mask.png" in w]
    for line in (said[0], knot):
        assert line.endswith("; delete it, or move it out to keep it") and "block.json as" not in line, line


def test_an_edited_knot_mask_or_ring_map_wins_over_a_rerun_as_a_corrected_svg_does(synth_photos, tmp_path, capsys,
                                                                                     monkeypatch):
    """A knot mask the user edited (left_knot_mask.png: the knot drawn larger) was written over
    without a word by a rerun that found the knot again, where a corrected SVG is kept. Now an
    edited mask or ring map is kept and read as the face's, said with how to let detection
    replace it; it stays the user's on later runs, one made over another photo is refused, and
    once deleted detection writes its own."""
    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    blk, size = _knotted_block_folder(synth_photos, tmp_path, capsys)
    assert _run(capsys, "rings", "detect", blk, "--out", blk)[0] == 0
    detected = read_block(blk).faces
    mask = np.zeros((160, 160), np.uint8)
    mask[60:140, 20:120] = 255
    Image.fromarray(mask).save(blk / "left_knot_mask.png")
    rings = np.zeros((160, 160), np.uint16)
    rings[:, ::10] = 65535
    Image.fromarray(rings).save(blk / "top_ring_map.png")
    for _ in range(2):  # kept, and not taken for the detector's the next time
        rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", blk)
        assert rc == 0, err
        faces = read_block(blk).faces
        assert np.array_equal(faces["left"].extras["knot_mask"], mask > 127), err
        assert np.array_equal(faces["top"].ring_map, rings / 65535.0)
        for f in ("left_knot_mask.png", "top_ring_map.png"):
            (line,) = [w for w in err.splitlines() if f in w]
            assert f"kept the edited {blk / f} (it is not the " in line, line
            assert "it wins over detection; to let detection replace it, delete it" in line
    (blk / "left_knot_mask.png").unlink()  # the manifest names them: detection writes them again
    (blk / "top_ring_map.png").unlink()
    rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", blk)
    assert rc == 0 and "kept the edited" not in err, err
    faces = read_block(blk).faces
    assert np.array_equal(faces["left"].extras["knot_mask"], detected["left"].extras["knot_mask"])
    assert np.allclose(faces["top"].ring_map, detected["top"].ring_map)
    # an edit made over another photo than the face's now is refused, as a corrected SVG is
    Image.fromarray(mask).save(blk / "left_knot_mask.png")
    turned = _copy(tmp_path / "knotted", tmp_path / "turned")
    Image.open(turned / "left.png").rotate(180).save(turned / "left.png")
    assert _run(capsys, "block", "from-photos", turned, *size, "--out", blk)[0] == 0
    rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", blk)
    assert rc == EXIT_ERROR and f"face 'left': the edited {blk / 'left_knot_mask.png'} was made over another left photo" in err
    with Image.open(blk / "left_knot_mask.png") as im:
        assert np.array_equal(np.asarray(im), mask)


def _hand_made_files():
    """A user's hand-made files of a 160 px face: a knot mask (a rectangle, uint8 0/255), a ring
    map (16-bit, a ring every 10 px) and a traces SVG of one line."""
    mask = np.zeros((160, 160), np.uint8)
    mask[60:140, 20:120] = 255
    rings = np.zeros((160, 160), np.uint16)
    rings[:, ::10] = 65535
    svg = ('<svg xmlns="http://www.w3.org/2000/svg" width="160" height="160" viewBox="0 0 160 160">'
           '<path d="M 10.5,20.5 L 150.5,20.5"/></svg>')
    return mask, rings, svg


def _reads_hand_made(faces, err):
    """``faces`` (read back after a detection) hold :func:`_hand_made_files`' knot mask on the
    left, ring map on the top and one-line traces on the front; the top's traces are detected."""
    mask, rings, _svg = _hand_made_files()
    assert np.array_equal(faces["left"].extras["knot_mask"], mask > 127), err
    assert np.array_equal(faces["top"].ring_map, rings / 65535.0), err
    assert len(faces["front"].traces) == 1 and len(faces["top"].traces) > 1, err


def _deleted_are_detected_again(capsys, blk, mine, detected):
    """The user's files ``mine`` (names in ``blk``) deleted, as the kept line says: a rerun keeps
    nothing and the left knot mask, top ring map and front traces are the detector's
    (``detected``: the faces of a detection of the same photos)."""
    for f in mine:
        (blk / f).unlink()
    rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", blk)
    assert rc == 0 and " kept " not in err, err
    faces = read_block(blk).faces
    assert np.array_equal(faces["left"].extras["knot_mask"], detected["left"].extras["knot_mask"])
    assert np.allclose(faces["top"].ring_map, detected["top"].ring_map)
    assert len(faces["front"].traces) == len(detected["front"].traces)


def test_hand_made_files_in_a_folder_never_detected_are_kept_and_used(synth_photos, tmp_path, capsys, monkeypatch):
    """A knot mask, ring map and traced SVG the user put beside the photos before ever running
    detection (block.json records none) were written over without a word: only files whose
    digest a detection recorded were told from the user's. Now, with no detection recorded in
    --out, such a file is the user's: kept, read as the face's, said in one line with how to let
    detection replace it; it stays the user's on a rerun; deleted, detection writes its own. The
    same holds in another --out folder with no block.json."""
    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    blk, _size = _knotted_block_folder(synth_photos, tmp_path, capsys)
    fresh = tmp_path / "fresh"  # the detector's own files, for comparison
    assert _run(capsys, "rings", "detect", blk, "--out", fresh)[0] == 0
    detected = read_block(fresh).faces
    assert "knot_mask" in detected["left"].extras  # the rerun finds the knot: the mask is its to write
    mask, rings, svg = _hand_made_files()
    other = tmp_path / "other"
    other.mkdir()
    for folder in (blk, other):
        Image.fromarray(mask).save(folder / "left_knot_mask.png")
        Image.fromarray(rings).save(folder / "top_ring_map.png")
        (folder / "front_traces.svg").write_text(svg)
    mine = {f: (blk / f).read_bytes() for f in ("left_knot_mask.png", "top_ring_map.png", "front_traces.svg")}
    for out in (blk, blk, other):  # the first run, a rerun (now recorded), and another --out
        rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", out)
        assert rc == 0, err
        assert {f: (out / f).read_bytes() for f in mine} == mine
        faces = read_block(out).faces
        _reads_hand_made(faces, err)
        for f in mine:
            (line,) = [w for w in err.splitlines() if f in w]
            assert line.startswith("woodcam: warning: face '") and " kept " in line, line
            # in another --out the same file in both is BLK's with its copy: deleting OTHER's alone
            # (as was said) let BLK's win the next run
            where = (f"delete it (or move it out of {str(out)!r})" if out == blk else
                     f"delete it and its copy {out / f} (or move them out of {str(blk)!r} and {str(out)!r})")
            assert f"it wins over detection; to let detection replace it, {where} and run 'rings detect' again" in line, line
    _deleted_are_detected_again(capsys, blk, mine, detected)


def test_a_users_knot_mask_or_ring_map_on_a_face_detection_finds_none_on_is_used(synth_photos, tmp_path, capsys,
                                                                                  monkeypatch):
    """A knot mask (ring map) of the user's, hand-made or edited, on a face where detection finds
    no knot (no rings) was kept but not read: the user was told to name it in block.json and
    detect with --no-knots, where on a face with a knot found it wins. Now it wins there too:
    kept, named by the manifest as the face's (so 'fit' reads it), said in the one line, and not
    said to leave the face without a ring map; on a rerun it is still the user's."""
    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    blk = _ringless_bottom_block(synth_photos, tmp_path, capsys, "32")
    mask, rings, _svg = _hand_made_files()
    Image.fromarray(mask).save(blk / "top_knot_mask.png")
    Image.fromarray(rings).save(blk / "bottom_ring_map.png")
    for how in ("your", "the edited"):  # hand-made before any detection, then the user's on a rerun
        rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", blk)
        assert rc == 0, err
        faces = read_block(blk).faces
        assert np.array_equal(faces["top"].extras["knot_mask"], mask > 127), err
        assert np.array_equal(faces["bottom"].ring_map, rings / 65535.0) and not faces["bottom"].traces
        entries = json.loads((blk / "block.json").read_text())["faces"]
        assert entries["top"]["extras"]["knot_mask"]["png"] == "top_knot_mask.png"
        assert entries["bottom"]["ring_map"] == "bottom_ring_map.png"
        for f in ("top_knot_mask.png", "bottom_ring_map.png"):
            (line,) = [w for w in err.splitlines() if f in w]
            assert f" kept {how} {blk / f} (" in line and "detection made none for the face this time" in line, line
            assert "it wins over detection; to let detection replace it, delete it" in line, line
        assert "is not read" not in err and "no rings found" not in err, err
    assert "knot_mask" not in json.loads((blk / "block.json").read_text())["meta"]["detection"]["file_digest"]


def test_files_block_json_names_under_other_names_are_the_users_and_kept(synth_photos, tmp_path, capsys, monkeypatch):
    """block.json naming a face's ring map, knot mask or traces SVG under another name than
    detection's (top_rings.png, left_knot.png, front_mine.svg) had detection replace them in the
    manifest without a word (the files left unnamed), and a kept SVG named front_traces.svg in
    the manifest whatever it was called (the detector's old one, when there). Now such a file is
    the user's, as one under detection's name is: kept untouched, still named, read as the face's,
    said in one line; the detector's own files of those faces are cleared; detected into another
    --out it is carried over under its name; deleted, detection writes its own."""
    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    blk, _size = _knotted_block_folder(synth_photos, tmp_path, capsys)
    mask, rings, svg = _hand_made_files()
    names = {("left", "knot"): "left_knot.png", ("top", "rings"): "top_rings.png", ("front", "svg"): "front_mine.svg"}

    def point_at_mine(folder):
        Image.fromarray(mask).save(folder / "left_knot.png")
        Image.fromarray(rings).save(folder / "top_rings.png")
        (folder / "front_mine.svg").write_text(svg)
        m = json.loads((folder / "block.json").read_text())
        m["faces"]["left"]["extras"]["knot_mask"] = {"png": "left_knot.png", "dtype": "bool"}
        m["faces"]["top"].update(ring_map="top_rings.png", ring_map_bits=16)
        m["faces"]["front"]["traces_svg"] = "front_mine.svg"
        (folder / "block.json").write_text(json.dumps(m))
        return {f: (folder / f).read_bytes() for f in names.values()}

    def check(folder, err, mine):
        assert {f: (folder / f).read_bytes() for f in mine} == mine
        entries = json.loads((folder / "block.json").read_text())["faces"]
        assert entries["left"]["extras"]["knot_mask"]["png"] == "left_knot.png"
        assert entries["top"]["ring_map"] == "top_rings.png" and entries["front"]["traces_svg"] == "front_mine.svg"
        faces = read_block(folder).faces
        _reads_hand_made(faces, err)
        for f in mine:
            (line,) = [w for w in err.splitlines() if f in w]
            assert " kept your " in line and "block.json names it for the face, and detection writes only " in line
            assert f"/{f} (" in line, line  # by its path, an SVG as an image
            assert "it wins over detection; to let detection replace it, delete it" in line, line
        assert not any((folder / f).exists() for f in ("left_knot_mask.png", "top_ring_map.png", "front_traces.svg"))

    fresh = tmp_path / "fresh"  # never detected: block.json from 'block from-photos'
    _copy(blk, fresh)
    mine = point_at_mine(fresh)
    rc, _out, err = _run(capsys, "rings", "detect", fresh, "--out", fresh)
    assert rc == 0, err
    check(fresh, err, mine)
    # detected before: the detector's own files of those faces are cleared, the user's named
    assert _run(capsys, "rings", "detect", blk, "--out", blk)[0] == 0
    detected = read_block(blk).faces
    mine = point_at_mine(blk)
    for out in (blk, blk, tmp_path / "other"):  # twice in place (the user's still on the second), another --out
        rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", out)
        assert rc == 0, err
        check(out, err, mine)
    _deleted_are_detected_again(capsys, blk, mine, detected)


def test_a_missing_or_file_input_is_one_line_that_says_which(synth_photos, tmp_path, capsys):
    """A photo given where the block folder goes ('rings detect front.png', 'rings show
    front.png') was said not to exist, though it is right there; a missing folder is still said
    missing. Each is one line and, as every command's missing input or one of the wrong kind, a
    wrong command line (exit 2; it was 1, the work failing)."""
    photo = synth_photos / "front.png"
    missing = tmp_path / "nope"
    is_file = f"{str(photo)!r} is a file; it must be an existing FOLDER; did you mean its folder {str(synth_photos)!r}?"
    for argv, says in (
            (("rings", "detect", photo, "--out", tmp_path / "o"), f"BLOCK of 'woodcam rings detect': {is_file}"),
            (("rings", "show", photo, "--out", tmp_path / "o.png"), f"BLOCK of 'woodcam rings show': {is_file}"),
            (("rings", "detect", missing, "--out", tmp_path / "o"), f"{str(missing)!r} does not exist; it must be an "
             "existing FOLDER"),
            (("rings", "show", missing, "--out", tmp_path / "o.png"), f"{str(missing)!r} does not exist"),
            (("block", "from-photos", missing, "--size-mm", "50", "--out", tmp_path / "o"),
             f"PHOTOS_DIR of 'woodcam block from-photos': {str(missing)!r} does not exist")):
        rc, _out, err = _run(capsys, *argv)
        assert rc == EXIT_USAGE and err.count("\n") == 1 and says in err, (argv, err)
    assert not (tmp_path / "o").exists() and not (tmp_path / "o.png").exists()


def test_a_photo_the_system_cannot_read_is_not_called_damaged(synth_photos, tmp_path, capsys, monkeypatch):
    """A photo the system would not let be read (no permission: copied off a camera card or a
    locked share; an I/O error of a failing card) was 'cannot decode the image ... the file is
    damaged or cannot be read as an image: pass a PNG, JPEG or TIFF file', sending the user to
    retake a good photo. Now the system's reason and the fix; a damaged file is still damaged."""
    import builtins

    import woodcam._readers as readers

    def locked(path, *args, **kwargs):
        if Path(path).name == "front.png":
            raise PermissionError(13, "Permission denied", str(path))
        return builtins.open(path, *args, **kwargs)

    monkeypatch.setattr(readers, "open", locked, raising=False)
    rc, out, err = _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50", "--out", tmp_path / "o")
    assert rc == EXIT_ERROR and out == "" and err.count("\n") == 1, err
    assert (f"photo of face 'front': cannot read '{synth_photos / 'front.png'}' (Permission denied); check the "
            "file's permissions and that its disk or share is readable") in err, err
    assert "damaged" not in err
    monkeypatch.undo()
    d = _copy(synth_photos, tmp_path / "d")
    (d / "front.png").write_bytes((d / "front.png").read_bytes()[:300])
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--out", tmp_path / "o")
    assert rc == EXIT_ERROR and "photo of face 'front': cannot decode the image" in err and "damaged" in err, err


def test_two_photos_of_one_face_are_named_with_why_a_letter_is_that_face(synth_photos, tmp_path, capsys):
    """front.png beside A.png (a Mokume letter, which is the front) was 'found several for
    {'front': ['A.png', 'front.png']}', a dict repr with no word of why A.png is the front."""
    d = _copy(synth_photos, tmp_path / "d")
    (d / "A.png").write_bytes((d / "front.png").read_bytes())
    (d / "Top.PNG").write_bytes((d / "top.png").read_bytes())
    rc, out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--out", tmp_path / "o")
    assert rc == EXIT_ERROR and out == "" and err.count("\n") == 1, err
    assert (f"each face needs exactly one photo in '{d}'; found 2 for front: A.png (Mokume's letter A for front), "
            "front.png; 2 for top: Top.PNG, top.png; keep one photo per face and move the others out of the "
            "folder") in err, err


def test_an_animated_photo_is_refused_naming_face_and_file(synth_photos, tmp_path, capsys):
    """An animated GIF or WebP (a phone's burst or live-photo export) was read as its first
    frame without a word: here a grey frame, refused as 'blank', and a first frame of another
    face would have been taken for this one. A phone's MPO JPEG (a second, depth image) is
    one photo and is read."""
    d = _copy(synth_photos, tmp_path / "anim", skip=("front",))
    with Image.open(synth_photos / "front.png") as im:
        upright = im.convert("RGB")
    grey = Image.new("RGB", upright.size, (128, 128, 128))
    grey.save(d / "front.webp", save_all=True, append_images=[upright], lossless=True)
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--out", tmp_path / "o")
    assert rc == EXIT_ERROR and err.count("\n") == 1, err
    assert "face 'front'" in err and "front.webp" in err and "animated WEBP of 2 frames" in err
    (d / "front.webp").unlink()
    upright.save(d / "front.jpg", format="MPO", save_all=True, append_images=[upright.resize((40, 40))])
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--out", tmp_path / "o")
    assert rc == 0, err


def test_an_unsupported_image_mode_names_the_face_and_file(synth_photos, tmp_path, capsys):
    """A 32-bit float TIFF was refused as 'image mode F is not supported' without saying which
    face or file."""
    d = _copy(synth_photos, tmp_path / "f", skip=("left",))
    with Image.open(synth_photos / "left.png") as im:
        Image.fromarray(np.asarray(im.convert("L"), np.float32) / 255).save(d / "left.tif")
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--out", tmp_path / "o")
    assert rc == EXIT_ERROR and err.count("\n") == 1, err
    assert "face 'left'" in err and "left.tif" in err and "mode F" in err


def test_photos_not_cropped_to_their_faces_are_all_named_with_the_fix(synth_photos, tmp_path, capsys):
    """Photos with background round the face were refused one face per run ('crop the photo to
    the face'), and a photo turned a quarter the same way. Now one line names every face that
    does not fit, the size its crop would have, a turned photo as turned, and how to crop."""
    d = _copy(synth_photos, tmp_path / "uncropped")
    for name in ("front", "top"):      # 20 px of table to each side, none above and below
        with Image.open(d / f"{name}.png") as im:
            a = np.asarray(im.convert("RGB"))
        Image.fromarray(np.pad(a, ((0, 0), (20, 20), (0, 0)), constant_values=200)).save(d / f"{name}.png")
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--out", tmp_path / "o")
    assert rc == EXIT_ERROR and err.count("\n") == 1, err
    assert "2 photos" in err and "face 'front' (front.png)" in err and "face 'top' (top.png)" in err
    assert "200x160 px" in err and "about 160x160 px when cropped" in err and "to its face's edges" in err
    d = _copy(synth_photos, tmp_path / "turned", skip=("front", "top", "bottom", "right", "back"))
    with Image.open(d / "left.png") as im:      # a 50 x 40 mm left face, 160 x 128 px, turned a quarter
        im.resize((128, 160)).save(d / "left.png")
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50x50x40", "--partial", "--out", tmp_path / "o")
    assert rc == EXIT_ERROR and "photo does not fit" in err and "face 'left' (left.png)" in err, err
    assert "turned 90 degrees" in err


def test_photos_of_sides_typed_in_another_order_are_told_the_order(synth_photos, tmp_path, capsys):
    """A 60x40x30 mm block given as --size-mm 60x30x40 (height and depth swapped) was refused
    as six photos not cropped to their faces, two of them 'turned 90 degrees', with the fix to
    crop them. When every photo fits the sides in another order, that order is said instead."""
    from woodcam.frames import face_image_size_mm

    d = tmp_path / "p"
    d.mkdir()
    for f in FACES:  # each face's photo at its aspect, 4 px/mm
        h, w = face_image_size_mm(f, (60, 40, 30))
        with Image.open(synth_photos / f"{f}.png") as im:
            im.resize((round(4 * w), round(4 * h))).save(d / f"{f}.png")
    for typed in ("60x30x40", "30x40x60", "40x60x30"):
        rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", typed, "--out", tmp_path / "o")
        assert rc == EXIT_ERROR and err.count("\n") == 1, err
        assert (f"6 photos do not fit the block's faces for --size-mm {typed}, but all 6 fit --size-mm 60x40x30: "
                "were the sides typed in another order? --size-mm is WxDxH, the width (left to right seen from "
                "the front), depth (front to back) and height") in err, err
        assert err.rstrip().endswith("run again with --size-mm 60x40x30") and "crop" not in err, err
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "60x40x30", "--out", tmp_path / "o")
    assert rc == 0, err
    # photos that fit no order of the sides are told to be cropped, as before
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "60x60x30", "--out", tmp_path / "o")
    assert rc == EXIT_ERROR and "another order" not in err and "crop each photo" in err, err


def test_a_photo_with_background_all_round_is_said(synth_photos, tmp_path, capsys):
    """A photo not cropped to its face but with even margins of background round the block keeps
    the face's aspect and passed without a word (the table's grey became the face's edge). Now a
    near-uniform border unlike the wood on all four sides is warned of, naming the face and the
    fix; Mokume's real faces (cropped) and woodcam's synthetic ones are not."""
    import warnings

    from woodcam.block.photos import block_from_photos

    from .test_detect_rings import _mokume

    d = _copy(synth_photos, tmp_path / "margins")
    with Image.open(d / "front.png") as im:  # the face in 136 px, 12 px of table round it
        face = np.asarray(im.convert("RGB").resize((136, 136), Image.LANCZOS)).astype(float)
    rng = np.random.default_rng(0)
    table = 120.0 + 10.0 * np.linspace(-1, 1, 160)[:, None, None] + 2.0 * rng.standard_normal((160, 160, 3))
    table[12:148, 12:148] = face
    Image.fromarray(np.clip(np.round(table), 0, 255).astype(np.uint8)).save(d / "front.jpg", quality=90)
    (d / "front.png").unlink()
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--out", tmp_path / "o")
    assert rc == 0 and err.count("warning") == 1, err
    assert "face 'front' (front.jpg) has a uniform border unlike the wood on all four sides" in err
    assert "top 7 %" in err and "crop the photo to the face's edges" in err
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        block_from_photos(synth_photos, (50, 50, 50))
        # (the samples' ring maps beside their photos are said, not read: no border)
        warnings.filterwarnings("ignore", r".*Mokume's ring maps .* are not read", WoodcamWarning)
        for sample in ("CN03", "H11"):
            block_from_photos(_mokume(sample), (50, 50, 50))


def test_a_photo_with_background_on_one_side_is_said(synth_photos, tmp_path, capsys):
    """Sweep h3 item 2: only a border on all four sides was said; a photo cropped off the face's
    centre, a dark strip of background down its left side (its aspect kept), passed without a
    word. Now each side is judged on its own and the warning names the face and the side."""
    d = _copy(synth_photos, tmp_path / "strip")
    with Image.open(d / "front.png") as im:
        a = np.asarray(im.convert("RGB")).copy()
    rng = np.random.default_rng(0)  # 14 px of a dark mat, a little sensor noise
    a[:, :14] = np.clip(30 + 2 * rng.standard_normal((160, 14, 3)), 0, 255).astype(np.uint8)
    Image.fromarray(a).save(d / "front.png")
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--out", tmp_path / "o")
    assert rc == 0 and err.count("warning") == 1, err
    assert ("photo of face 'front' (front.png) has a uniform border unlike the wood on its left side "
            "(left 9 % of its width): background beside the face?") in err, err
    assert "crop the photo to the face's edges" in err
    a[:16] = a[:16, :1]  # and along the top: the mat's corner
    Image.fromarray(a).save(d / "front.png")
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--out", tmp_path / "o2")
    assert rc == 0 and "on its top and left sides (top 9 % of its height, left 8 % of its width)" in err, err


def test_large_photos_are_brought_to_the_cap_one_at_a_time_under_a_bar(synth_photos, tmp_path, capsys, monkeypatch):
    """Six phone photos were all held at full size, and a float copy of each one's three channels
    made for the exposure check, before any was resampled: six 48 MP photos took 1.8 GB, 35 s
    without a progress bar. Now each is brought down to the --max-px-per-mm cap as it is read
    (the faces written are the same), under a 'reading photos' bar."""
    import tracemalloc

    from woodcam import _progress
    from woodcam.block.photos import block_from_photos

    d = tmp_path / "big"
    d.mkdir()
    for p in synth_photos.iterdir():
        with Image.open(p) as im:
            im.convert("RGB").resize((1200, 1200), Image.BILINEAR).save(d / p.name, compress_level=1)
    one_photo = 1200 * 1200 * 3
    # the modules' first import (2 MB, half a photo) is no photo's: run alone, the test failed
    block_from_photos(synth_photos, (50, 50, 50))
    tracemalloc.start()
    try:
        block = block_from_photos(d, (50, 50, 50), max_px_per_mm=2.0)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert all(f.photo.shape == (100, 100, 3) for f in block.faces.values())
    assert peak < 2.5 * one_photo, f"peak {peak / one_photo:.1f} photos"
    bars = []

    def bar(iterable=None, **kw):
        bars.append(kw)
        return iterable

    monkeypatch.setattr(_progress, "progress_bar", bar)
    rc, _out, err = _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50", "--out", tmp_path / "o")
    assert rc == 0, err
    assert [(b["desc"], b["enabled"]) for b in bars] == [("reading photos", True)]


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="reads the peak memory from /proc")
def test_reading_a_phone_photo_makes_no_copy_of_it_for_nothing(tmp_path):
    """Reading a 12 MP photo peaked at 4.7 times its pixels: the EXIF turn copied an upright
    photo whole (PIL's 4 bytes a pixel) before any was needed; turned in place, 3.3 times.
    Measured in a fresh process (its peak resident memory, which tracemalloc cannot see: PIL's
    memory is its own)."""
    import subprocess
    import sys

    rng = np.random.default_rng(0)
    small = Image.fromarray((rng.random((30, 40, 3)) * 255).astype(np.uint8))
    small.resize((4000, 3000), Image.BILINEAR).save(tmp_path / "front.jpg", quality=90)
    small.save(tmp_path / "tiny.jpg")
    code = (
        "from woodcam._readers import read_photo_rgb\n"
        "def peak():\n"
        "    return int(next(s for s in open('/proc/self/status') if s.startswith('VmHWM')).split()[1]) * 1024\n"
        f"read_photo_rgb({str(tmp_path / 'tiny.jpg')!r}, 'x')\n"
        "base = peak()\n"
        f"a = read_photo_rgb({str(tmp_path / 'front.jpg')!r}, 'x')\n"
        "print((peak() - base) / a.nbytes)\n")
    res = subprocess.run([sys.executable, "-c", code], cwd=Path(__file__).resolve().parents[2],
                         capture_output=True, text=True, check=False)
    assert res.returncode == 0, res.stderr
    assert float(res.stdout) < 4.0, f"peak {float(res.stdout):.2f} photos"


def test_a_face_is_resampled_once_whatever_the_other_photos_densities(synth_photos, tmp_path):
    """A photo denser than --max-px-per-mm was brought down to the cap as it was read and again
    to the set's density when another photo lay below the cap: resampled twice, its face differed
    from the one written when no cap applies. Now a face's pixels depend on the other photos only
    through the common density: byte-identical with and without the cap, and equal to one Lanczos
    resampling of its original."""
    from woodcam.block.photos import block_from_photos

    d = _copy(synth_photos, tmp_path / "mixed")
    with Image.open(d / "front.png") as im:  # 8 px/mm, above the cap of 4
        big = np.asarray(im.convert("RGB").resize((400, 400), Image.BICUBIC))
    Image.fromarray(big).save(d / "front.png")
    with Image.open(d / "top.png") as im:    # 3 px/mm, below it: the set's density
        im.resize((150, 150), Image.LANCZOS).save(d / "top.png")
    capped = block_from_photos(d, (50, 50, 50), max_px_per_mm=4.0)
    free = block_from_photos(d, (50, 50, 50), max_px_per_mm=100.0)  # one photo denser than the rest: no warning
    assert capped.meta["px_per_mm"] == free.meta["px_per_mm"] == 3.0
    once = np.asarray(Image.fromarray(big).resize((150, 150), Image.LANCZOS))
    for face in FACES:
        assert np.array_equal(capped.faces[face].photo, free.faces[face].photo), face
    assert np.array_equal(capped.faces["front"].photo, once)


def test_from_photos_says_when_the_photos_are_brought_down_to_the_cap(synth_photos, tmp_path, capsys):
    """Phone photos far denser than --max-px-per-mm were stored at the cap with only 'faces at
    10.00 px/mm' said: nothing told that the photos held more, or which option keeps it."""
    rc, out, err = _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50", "--max-px-per-mm", "2",
                        "--out", tmp_path / "o")
    assert rc == 0, err
    assert "faces at 2.00 px/mm, down from the photos' 3.20 (the --max-px-per-mm cap" in out
    assert read_block(tmp_path / "o").meta["photos_px_per_mm"] == pytest.approx(3.2)
    rc, out, err = _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50", "--out", tmp_path / "p")
    assert rc == 0 and "faces at 3.20 px/mm:" in out and "down from" not in out, out + err


def test_from_photos_names_the_photo_that_brings_every_face_down(synth_photos, tmp_path, capsys):
    """One photo taken from afar (or at a low resolution) brought all six faces down to its
    density without a word of which (reproduced: CN03's front resized to 100 px beside five of
    256 px -> 'wrote o (6 faces at 2.00 px/mm: front 100x100, top 100x100, ...)', nothing
    else). Now a warning names the face, its photo and density; a spread within DENSITY_SPREAD,
    the other photos brought down to the cap anyway, or one photo denser than the rest (test
    above) is not said."""
    from woodcam.block.photos import DENSITY_SPREAD

    d = _copy(synth_photos, tmp_path / "low")
    with Image.open(d / "front.png") as im:  # 1.6 px/mm beside the others' 3.2
        im.resize((80, 80), Image.LANCZOS).save(d / "front.png")
    rc, out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--out", tmp_path / "o")
    assert rc == 0 and "faces at 1.60 px/mm" in out, out + err
    assert err.count("warning") == 1 and ("photo of face 'front' (front.png, 1.60 px/mm) holds far less than the "
                                          "other photos' 3.20 px/mm (their median): all faces are stored at one density, "
                                          "1.60 px/mm, so the others lose their detail; retake it closer") in err, err
    assert 3.2 / 1.6 > DENSITY_SPREAD
    rc, out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--max-px-per-mm", "2",
                        "--out", tmp_path / "p")  # the others brought down to the cap of 2 anyway
    assert rc == 0 and "warning" not in err, err


def test_a_face_photo_in_a_format_woodcam_cannot_read_is_named(synth_photos, tmp_path, capsys):
    """A face's photo in a format woodcam does not read (a phone's RAW front.dng, a front.psd) was
    passed over without a word (reproduced: CN03's photos with A.jpg renamed front.dng -> 'missing
    face photos: front (found top, ...); add front.jpg (or Mokume letters A), or pass --partial',
    front.dng right there; with --partial the face was left out silently). Now the error names
    the file and the formats read, and --partial warns that its face is left out; a file of that
    name beside a face's readable photo (a front.xmp sidecar) is no matter."""
    d = _copy(synth_photos, tmp_path / "raw", skip=("front",))
    (d / "front.dng").write_bytes(b"II*\0raw")
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--out", tmp_path / "o")
    assert rc == EXIT_ERROR and err.count("\n") == 1, err
    assert "missing face photos: front (found " in err, err
    assert ("); front.dng is named for face front but not in a format woodcam reads (.jpg .jpeg") in err, err
    assert "export it as JPEG or PNG (front.jpg)" in err, err
    rc, out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--partial", "--out", tmp_path / "p")
    assert rc == 0 and "5 faces" in out, out + err
    assert err.count("warning") == 1 and "front.dng is named for face front but not in a format" in err, err
    assert "its face is left out" in err, err
    (d / "front.dng").unlink()
    (d / "top.xmp").write_text("<x/>")  # a sidecar beside top.png
    rc, out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--partial", "--out", tmp_path / "q")
    assert rc == 0 and "warning" not in err, err


def test_photos_named_for_no_face_are_said(synth_photos, tmp_path, capsys):
    """'top face.jpg' or IMG_1234.JPG beside the face photos were passed over without a word: the
    missing-face error did not say they were there, and with --partial the face was just left out.
    Hidden files (.DS_Store, macOS ._front.png), other files and a Mokume sample's maps are not photos."""
    d = _copy(synth_photos, tmp_path / "n", skip=("top",))
    (d / "top face.png").write_bytes((synth_photos / "top.png").read_bytes())
    (d / "._front.png").write_bytes(b"\0\5\26\7")
    (d / "A_arl-unet.png").write_bytes((synth_photos / "top.png").read_bytes())
    for junk in ("Thumbs.db", ".DS_Store", "notes.txt"):
        (d / junk).write_text("x")
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--out", tmp_path / "o")
    assert rc == EXIT_ERROR and err.count("\n") == 1, err
    assert "missing face photos: top" in err and "top face.png is named for no face" in err
    assert "._front" not in err and "arl-unet" not in err
    rc, _out, err = _run(capsys, "block", "from-photos", d, "--size-mm", "50", "--partial", "--out", tmp_path / "o")
    # the Mokume map in a warning of its own (not read: the block holds the photos alone)
    assert rc == 0 and err.count("warning") == 2, err
    assert "top face.png is named for no face, so not read" in err and "._front" not in err
    assert "Mokume's ring map A_arl-unet.png is not read" in err and "named for no face, so not read; " \
        "rename" in [w for w in err.splitlines() if "top face" in w][0]
    from woodcam.block.photos import block_from_photos

    with pytest.warns(WoodcamWarning) as said:
        assert "top" not in block_from_photos(d, (50, 50, 50), partial=True).faces
    assert [str(w.message).split(": ", 1)[1][:40] for w in said] == [
        "top face.png is named for no face, so no", "Mokume's ring map A_arl-unet.png is not "]


def test_a_block_folder_given_as_photos_is_named_and_its_own_images_are_no_strays(synth_photos, tmp_path, capsys):
    """'block from-photos BLOCK' (a block folder, whose photos are front_photo.png ...) was 'no face
    photos found; back_photo.png, ... are named for no face: name them front.jpg ...', and a block
    made into its photos folder (--out PHOTOS) and made again warned that its own front_photo.png
    ... were 'named for no face, so not read; rename a face's photo front.jpg'."""
    photos = _copy(synth_photos, tmp_path / "photos")
    blk = tmp_path / "blk"
    assert _run(capsys, "block", "from-photos", photos, "--size-mm", "50", "--out", blk)[0] == 0
    rc, out, err = _run(capsys, "block", "from-photos", blk, "--size-mm", "50", "--out", tmp_path / "again")
    assert rc == EXIT_ERROR and out == "" and err.count("\n") == 1, err
    assert (f"PHOTOS_DIR '{blk}' is a block folder (block.json, back_photo.png ...), not a folder of face photos: "
            f"detect its rings with woodcam rings detect {blk} --out {blk}, or give the folder of the original "
            "photos") in err, err
    assert "named for no face" not in err
    for _ in range(2):  # the second run reads a folder holding the first's block too
        rc, _out, err = _run(capsys, "block", "from-photos", photos, "--size-mm", "50", "--out", photos)
        assert rc == 0 and err == "", err
    assert set(read_block(photos).faces) == set(FACES)
    (photos / "IMG_0001.png").write_bytes((photos / "top.png").read_bytes())  # a user's stray is still said
    rc, _out, err = _run(capsys, "block", "from-photos", photos, "--size-mm", "50", "--out", photos)
    assert rc == 0 and "IMG_0001.png is named for no face" in err and "_photo" not in err, err


def test_rings_detect_warns_of_a_face_photographed_turned(tmp_path, capsys, synth_photos):
    """A cube's top photo turned 90 degrees passes the aspect check; rings detect names it and the
    fix, and block show --check-layout does too (and says so when all is well)."""
    photos = _copy(synth_photos, tmp_path / "photos")
    top = Image.open(photos / "top.png")
    top.rotate(-90).save(photos / "top.png")          # PIL: negative angles turn clockwise
    blk = tmp_path / "blk"
    assert _run(capsys, "block", "from-photos", photos, "--size-mm", "50", "--out", blk)[0] == 0
    rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", blk)
    assert rc == 0
    assert ("woodcam: warning: face 'top' looks turned 90 degrees clockwise: its rings meet its "
            "neighbours' along its 4 edges only when corrected") in err
    assert "turn its photo top.png 90 degrees counter-clockwise" in err
    rc, _, err = _run(capsys, "block", "show", blk, "--check-layout", "--out", tmp_path / "x.png")
    assert rc == 0 and "woodcam: warning: face 'top' looks turned 90 degrees clockwise" in err
    top.save(photos / "top.png")
    good = tmp_path / "good"
    assert _run(capsys, "block", "from-photos", photos, "--size-mm", "50", "--out", good)[0] == 0
    rc, out, err = _run(capsys, "rings", "detect", good, "--out", good)
    assert rc == 0 and "looks turned" not in out + err
    rc, out, _ = _run(capsys, "block", "show", good, "--check-layout", "--out", tmp_path / "y.png")
    assert rc == 0 and "layout: 6 faces checked, none looks turned or mirrored" in out


def test_a_photo_only_block_with_a_turned_face_warns_wherever_it_is_detected(tmp_path, capsys, monkeypatch,
                                                                             synth_photos):
    """fit, bake, eval and open_stock detect a photo-only folder through with_detected_rings,
    which did not check the layout (only rings detect did): a turned face ruined the fit without
    a word. Now it warns each time (the cached detection too); the CLI says it once."""
    import warnings

    from woodcam.block.photos import block_from_photos
    from woodcam.detect.block import with_detected_rings

    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    photos = _copy(synth_photos, tmp_path / "photos")
    Image.open(photos / "top.png").rotate(-90).save(photos / "top.png")
    block = block_from_photos(photos, (50.0, 50.0, 50.0))
    for run in ("detected", "cache hit"):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            with_detected_rings(block)
        turned = [str(w.message) for w in caught if "looks turned" in str(w.message)]
        assert len(turned) == 1 and turned[0].startswith("face 'top' looks turned 90 degrees clockwise"), run
    blk = tmp_path / "blk"
    assert _run(capsys, "block", "from-photos", photos, "--size-mm", "50", "--out", blk)[0] == 0
    rc, _, err = _run(capsys, "block", "show", blk, "--check-layout", "--out", tmp_path / "x.png")
    assert rc == 0 and err.count("face 'top' looks turned 90 degrees clockwise") == 1, err


def test_rings_detect_again_detects_only_the_faces_whose_photo_changed(synth_photos, tmp_path, capsys, monkeypatch):
    """'rings detect' detected every face afresh on every run: run again (after correcting one SVG,
    or one photo changed) it took as long as the first (a minute or two a large face). Each face
    is cached by its photo, density, rule and options; the folder written is byte for byte the
    same as a fresh detection's."""
    import woodcam.detect.block as det

    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    calls = []
    real = det.detect_rings
    monkeypatch.setattr(det, "detect_rings", lambda photo, **kw: calls.append(kw["name"]) or real(photo, **kw))
    blk = tmp_path / "blk"
    assert _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50", "--out", blk)[0] == 0

    def detect(out, *extra):
        calls.clear()
        rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", tmp_path / out, *extra)
        assert rc == 0, err
        return {p.name: p.read_bytes() for p in (tmp_path / out).iterdir()}

    first = detect("o1")
    assert sorted(calls) == sorted(FACES)
    assert detect("o2") == first and calls == []  # nothing new: nothing detected, the same files
    with Image.open(blk / "front_photo.png") as im:
        im.transpose(Image.Transpose.FLIP_LEFT_RIGHT).save(blk / "front_photo.png")
    changed = detect("o3")
    assert calls == ["front"] and changed["front_traces.svg"] != first["front_traces.svg"]
    assert all(changed[n] == first[n] for n in first if n.startswith(("top", "left", "bottom", "right", "back")))
    detect("o4", "--rule", "dark-line")
    assert sorted(calls) == sorted(FACES)  # another rule: detected afresh


def test_the_detection_cache_is_keyed_by_the_photos_and_the_rule(tmp_path, monkeypatch):
    """The cached detection of a photo-only block is the detection of these photos with this rule:
    a block whose photo changed, or asked with another rule, is detected afresh (its own entry),
    and the same photos and rule read the entry back. Known answers: each against a detection
    run without the cache."""
    import warnings

    from woodcam.detect.block import photos_only, with_detected_rings
    from woodcam.synth import AnalyticLogField, cut_block, synth_block

    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))

    def block(ring_width_mm):
        field = cut_block(AnalyticLogField(ring_width_mm=ring_width_mm), (30, 30, 30), "rift")
        b = synth_block(field, (30, 30, 30), face_px=96, seed=4, ring_map_faces=())
        return photos_only(b)

    first, other = block(3.0), block(4.5)
    changed = photos_only(first)
    changed.faces["front"] = other.faces["front"]  # one photo replaced

    def traces(b, **kw):
        with warnings.catch_warnings():  # faces with little ring evidence are named; not tested here
            warnings.simplefilter("ignore", WoodcamWarning)
            out = with_detected_rings(b, **kw)
        return {n: [t.points_px.tolist() for t in f.traces] for n, f in out.faces.items()}

    # the blocks' entries (each face has one of its own too, named by the face)
    entries = lambda: sorted(p for p in (tmp_path / "cache" / "detect").glob("*.npz")  # noqa: E731
                             if p.name.partition("-")[0] not in FACES)
    base = traces(first)
    assert len(entries()) == 1 and base == traces(first, cache=False)
    assert traces(changed) == traces(changed, cache=False) != base
    assert len(entries()) == 2
    assert traces(first, rule="dark-line") == traces(first, rule="dark-line", cache=False) != base
    assert len(entries()) == 3
    assert traces(photos_only(first)) == base and len(entries()) == 3  # the same content: read back


def test_fit_bake_and_eval_detect_again_only_the_face_whose_photo_changed(tmp_path, monkeypatch):
    """A photo-only block's detection (fit, bake, eval: with_detected_rings) was cached by the
    whole block alone: one photo retaken, all six faces were detected afresh (CN03 from six
    photos: 3.3 s again for one changed face, as long as the first run). Each face is now cached
    by its own photo too, as 'rings detect' caches it: the changed face alone is detected, and
    the answer is a fresh detection's."""
    import woodcam.detect.block as det
    from woodcam.detect.block import photos_only, with_detected_rings
    from woodcam.synth import AnalyticLogField, cut_block, synth_block

    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    calls: list[str] = []
    real = det.detect_rings
    monkeypatch.setattr(det, "detect_rings", lambda photo, **kw: calls.append(kw["name"]) or real(photo, **kw))

    def block(ring_width_mm):
        field = cut_block(AnalyticLogField(ring_width_mm=ring_width_mm), (30, 30, 30), "rift")
        return photos_only(synth_block(field, (30, 30, 30), face_px=96, seed=4, ring_map_faces=()))

    def traces(b, **kw):
        calls.clear()
        with warnings.catch_warnings():  # faces with little ring evidence are named; not tested here
            warnings.simplefilter("ignore", WoodcamWarning)
            out = with_detected_rings(b, **kw)
        return {n: [t.points_px.tolist() for t in f.traces] for n, f in out.faces.items()}

    first = block(3.0)
    traces(first)
    assert sorted(calls) == sorted(FACES)
    changed = photos_only(first)
    changed.faces["front"] = block(4.5).faces["front"]  # one photo retaken
    got = traces(changed)
    assert calls == ["front"]
    assert got == traces(changed, cache=False)


@pytest.mark.parametrize("cache, damage", [(c, d) for c in ("per face", "per block")
                                           for d in ("ring_map rows", "ring ids", "knot_mask", "trace lengths")]
                         + [("per block", "another face")])
def test_a_detection_entry_that_does_not_fit_its_faces_is_rebuilt(tmp_path, monkeypatch, damage, cache):
    """A cached detection that is a valid .npz but holds arrays of other shapes than its faces
    (a ring map of 5 rows) failed every run ('ring_map of face 'top' must have shape (64, 64)
    like the face; got (5, 64)') until 'woodcam cache clear', and fewer ring ids than traces
    dropped the traces past them without a word; an entry of the block holding a face the block
    has not was a KeyError (an internal error). Now such an entry is broken like a truncated
    one: one CacheWarning, detected again, the fresh detection's answer, then read back."""
    from woodcam._cache import CacheWarning, cache_dir
    from woodcam.detect.block import detect_block, photos_only, with_detected_rings
    from woodcam.synth import AnalyticLogField, cut_block, synth_block

    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    field = cut_block(AnalyticLogField(ring_width_mm=3.0), (30, 30, 30), "rift")
    block = photos_only(synth_block(field, (30, 30, 30), face_px=64, seed=4, ring_map_faces=()))
    block.faces = {"top": block.faces["top"]}

    def detect():
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            out = (detect_block(block, cache=True)[0] if cache == "per face" else with_detected_rings(block))
        f = out.faces["top"]
        seen = ([t.points_px.tolist() for t in f.traces], [t.ring for t in f.traces], f.ring_map.tolist(),
                np.asarray(f.extras.get("knot_mask", False)).tolist())
        return seen, [str(w.message) for w in said if issubclass(w.category, CacheWarning)]

    fresh, said = detect()
    assert said == [] and len(fresh[0]) > 2
    read_back = detect()  # the ring map is kept as uint16 levels
    assert read_back[1] == [] and read_back[0][:2] == fresh[:2]
    # the entry of the face, or of the block (beside which with_detected_rings keeps the face's too)
    [entry] = [p for p in cache_dir("detect").glob("*.npz") if (p.name.partition("-")[0] == "top") == (cache == "per face")]
    with np.load(entry) as z:
        arrays = dict(z)
    if damage == "ring_map rows":
        arrays["top.ring_map"] = arrays["top.ring_map"][:5]
    elif damage == "ring ids":
        arrays["top.rings"] = arrays["top.rings"][:2]
    elif damage == "knot_mask":
        arrays["top.knot_mask"] = np.zeros((5, 64), bool)
    elif damage == "trace lengths":
        arrays["top.lengths"] = arrays["top.lengths"][:-1]
    else:
        arrays.update({k.replace("top.", "left."): v for k, v in arrays.items() if k.startswith("top.")})
    np.savez(entry, **arrays)
    again, said = detect()
    assert len(said) == 1 and said[0].startswith(f"ring detection: discarded the unreadable cache entry {str(entry)!r}")
    # the block's entry is rebuilt from its face's, intact (ring map as read back: uint16 levels)
    assert again == (fresh if cache == "per face" else read_back[0])
    assert detect() == read_back  # the rebuilt entry is read back


def test_a_partial_rerun_removes_the_photo_it_wrote_of_a_face_left_out(synth_photos, tmp_path, capsys):
    """'block from-photos --partial' into the folder of an earlier run with the face left out:
    its left_photo.png stayed beside the new manifest, unread (read_block named five faces), a
    face the folder seemed to have. Now the rerun removes it when it is the photo woodcam wrote
    (its recorded digest), and keeps and says one it did not write (an edited photo)."""
    five = _copy(synth_photos, tmp_path / "five", skip=("left",))
    blk = tmp_path / "blk"
    assert _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50", "--out", blk)[0] == 0
    assert (blk / "left_photo.png").is_file()
    rc, _out, err = _run(capsys, "block", "from-photos", five, "--size-mm", "50", "--out", blk, "--partial")
    assert rc == 0 and "left_photo.png" not in err, err
    assert not (blk / "left_photo.png").exists()
    assert sorted(read_block(blk).faces) == sorted(f for f in FACES if f != "left")
    assert sorted(p.name for p in blk.iterdir()) == sorted(["block.json"] + [f"{f}_photo.png" for f in FACES
                                                                              if f != "left"])
    # a photo woodcam did not write (edited since) is kept, and said
    again = tmp_path / "again"
    assert _run(capsys, "block", "from-photos", synth_photos, "--size-mm", "50", "--out", again)[0] == 0
    edited = np.asarray(Image.open(again / "left_photo.png")).copy()
    edited[:10] = 0
    Image.fromarray(edited).save(again / "left_photo.png")
    rc, _out, err = _run(capsys, "block", "from-photos", five, "--size-mm", "50", "--out", again, "--partial")
    assert rc == 0 and (again / "left_photo.png").is_file()
    assert (f"woodcam: warning: face 'left': left_photo.png in {str(again)!r} is not read (the block has no left "
            "face now, and block.json does not name it), and is kept: it is not the photo an earlier run wrote") in err


def test_a_block_made_again_in_its_folder_keeps_the_users_named_images(synth_photos, tmp_path, capsys, monkeypatch):
    """'block from-photos' remaking a block folder kept the record of its detection (so a
    corrected SVG, under any name, stayed the face's) but not the ring maps and knot masks
    block.json named under other names than detection's (top_rings.png, left_knot.png): the
    next 'rings detect' named the detector's top_ring_map.png and left_knot_mask.png, the
    user's files left unnamed, dropped from the block without a word. Now the record carries
    their names, and detection keeps them named, read as the face's and said; a user's
    default-named one (an edited bottom_ring_map.png) stays the face's too."""
    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    blk, size = _knotted_block_folder(synth_photos, tmp_path, capsys)
    assert _run(capsys, "rings", "detect", blk, "--out", blk)[0] == 0
    mask, rings, svg = _hand_made_files()
    Image.fromarray(mask).save(blk / "left_knot.png")
    Image.fromarray(rings).save(blk / "top_rings.png")
    (blk / "front_mine.svg").write_text(svg)
    edited = rings[:, ::-1].copy()
    Image.fromarray(edited).save(blk / "bottom_ring_map.png")  # the detector's, edited by the user
    m = json.loads((blk / "block.json").read_text())
    m["faces"]["left"]["extras"]["knot_mask"] = {"png": "left_knot.png", "dtype": "bool"}
    m["faces"]["top"].update(ring_map="top_rings.png", ring_map_bits=16)
    m["faces"]["front"]["traces_svg"] = "front_mine.svg"
    (blk / "block.json").write_text(json.dumps(m))
    mine = {f: (blk / f).read_bytes() for f in ("left_knot.png", "top_rings.png", "front_mine.svg",
                                                 "bottom_ring_map.png")}
    for remake in (False, True, True):  # detected, then the block made again (twice) and detected
        if remake:
            rc, _out, err = _run(capsys, "block", "from-photos", tmp_path / "knotted", *size, "--out", blk)
            assert rc == 0, err
        rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", blk)
        assert rc == 0, err
        assert {f: (blk / f).read_bytes() for f in mine} == mine
        entries = json.loads((blk / "block.json").read_text())["faces"]
        assert entries["left"]["extras"]["knot_mask"]["png"] == "left_knot.png", err
        assert entries["top"]["ring_map"] == "top_rings.png" and entries["front"]["traces_svg"] == "front_mine.svg"
        assert entries["bottom"]["ring_map"] == "bottom_ring_map.png"
        faces = read_block(blk).faces
        assert np.array_equal(faces["left"].extras["knot_mask"], mask > 127)
        assert np.array_equal(faces["top"].ring_map, rings / 65535.0)
        assert np.array_equal(faces["bottom"].ring_map, edited / 65535.0)
        assert len(faces["front"].traces) == 1
        for f in mine:
            (line,) = [w for w in err.splitlines() if f in w]
            how = "the edited" if f.startswith("bottom") else "your"
            assert f" kept {how} {blk / f} (" in line and "it wins over detection" in line, line
        assert not any((blk / f).exists() for f in ("left_knot_mask.png", "top_ring_map.png", "front_traces.svg"))
    # made again without its left photo: the left face's named mask is not the block's now, said
    # (it was left unnamed without a word), and kept
    five = _copy(tmp_path / "knotted", tmp_path / "five", skip=("left",))
    assert _run(capsys, "block", "from-photos", five, *size, "--partial", "--out", blk)[0] == 0
    rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", blk)
    assert rc == 0, err
    assert (blk / "left_knot.png").read_bytes() == mine["left_knot.png"]
    (line,) = [w for w in err.splitlines() if "left_knot.png" in w]
    assert line == (f"woodcam: warning: face 'left': your {blk / 'left_knot.png'} is not used: the block has no left "
                    f"face (made without its photo); move it out of {str(blk)!r} to keep it"), line


def test_hand_made_files_beside_the_photos_win_whatever_the_out_folder(synth_photos, tmp_path, capsys, monkeypatch):
    """'rings detect BLK --out OUT' with OUT another folder looked for hand-made files (no
    detection ever recorded) in OUT alone: a knot mask, ring map and traced SVG the user made
    beside the photos in BLK were passed over, OUT given the detector's. Now a folder of either
    with no detection recorded holds the user's files: BLK's win (over OUT's own detection too)
    and are carried into OUT as edited ones are, said by their path in BLK."""
    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    blk, _size = _knotted_block_folder(synth_photos, tmp_path, capsys)
    out = tmp_path / "out"
    assert _run(capsys, "rings", "detect", blk, "--out", out)[0] == 0  # OUT detected, BLK never
    assert "knot_mask" in read_block(out).faces["left"].extras
    mask, rings, svg = _hand_made_files()
    Image.fromarray(mask).save(blk / "left_knot_mask.png")
    Image.fromarray(rings).save(blk / "top_ring_map.png")
    (blk / "front_traces.svg").write_text(svg)
    mine = {f: (blk / f).read_bytes() for f in ("left_knot_mask.png", "top_ring_map.png", "front_traces.svg")}
    for folder in (out, tmp_path / "new"):  # over OUT's earlier detection, and into a new OUT
        rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", folder)
        assert rc == 0, err
        assert {f: (blk / f).read_bytes() for f in mine} == mine
        faces = read_block(folder).faces
        _reads_hand_made(faces, err)
        for f in mine:
            (line,) = [w for w in err.splitlines() if f in w]
            assert f" kept your {blk / f} (" in line and "no detection is recorded in that folder" in line, line
            # its copy in OUT is the user's too (never recorded as the detector's): deleting the
            # one in BLK alone, as the line said, let the copy win the next run
            assert (f"to let detection replace it, delete it and its copy {folder / f} (or move them out of "
                    f"{str(blk)!r} and {str(folder)!r}) and run 'rings detect' again") in line, line
    for f in mine:  # as the line says: both deleted, detection writes its own
        (blk / f).unlink()
        (out / f).unlink()
    rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", out)
    assert rc == 0 and " kept " not in err, err
    faces = read_block(out).faces
    assert not np.array_equal(faces["left"].extras["knot_mask"], mask > 127)
    assert len(faces["front"].traces) > 1


def test_fit_right_after_a_remake_reads_the_users_files(synth_photos, tmp_path, capsys, monkeypatch):
    """Between 'block from-photos' making a block again into its folder and the next 'rings
    detect', the remade manifest names none of the user's files: 'fit BLK' (bake, eval) detected
    every face itself and used none of them (a corrected front_traces.svg, a knot mask block.json
    named left_knot.png, an edited bottom_ring_map.png), without a word. Now the photo-only path
    reads the saved record: the user's files of a face whose photo is unchanged win, as the next
    'rings detect' would have them, and the kept lines' fix is theirs ('run again', not 'rings
    detect''s)."""
    from woodcam.stock import open_block

    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    blk, size = _knotted_block_folder(synth_photos, tmp_path, capsys)
    assert _run(capsys, "rings", "detect", blk, "--out", blk)[0] == 0
    mask, rings, svg = _hand_made_files()
    Image.fromarray(mask).save(blk / "left_knot.png")
    (blk / "front_traces.svg").write_text(svg)  # the detector's, corrected
    Image.fromarray(rings).save(blk / "bottom_ring_map.png")  # the detector's, edited
    m = json.loads((blk / "block.json").read_text())
    m["faces"]["left"]["extras"]["knot_mask"] = {"png": "left_knot.png", "dtype": "bool"}
    (blk / "block.json").write_text(json.dumps(m))
    assert _run(capsys, "block", "from-photos", tmp_path / "knotted", *size, "--out", blk)[0] == 0
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        block, _field = open_block(str(blk))
    lines = [str(w.message) for w in said]
    assert len(block.faces["front"].traces) == 1, lines
    assert np.array_equal(block.faces["left"].extras["knot_mask"], mask > 127)
    assert np.array_equal(block.faces["bottom"].ring_map, rings / 65535.0)
    assert len(block.faces["top"].traces) > 1  # detected, as before
    for kept in (f"the corrected {blk / 'front_traces.svg'} (1 trace; ", f"your {blk / 'left_knot.png'} (",
                 f"the edited {blk / 'bottom_ring_map.png'} ("):
        (line,) = [w for w in lines if f" kept {kept}" in w]
        assert "it wins over detection" in line, line
        # the fix is the command's own: deleted, the next fit (bake, eval) detects the face itself
        # (it said "run 'rings detect' again", the advice of 'rings detect')
        assert line.endswith(f"delete it (or move it out of {str(blk)!r}) and run again"), line
    # a face photo changed since (turned): its correction is not this photo's, so not used (the
    # next 'rings detect' refuses it, as it did), and said so, with 'rings detect''s fix; an
    # edited ring map of a turned face alike (it was passed over without a word)
    turned = _copy(tmp_path / "knotted", tmp_path / "turned")
    Image.open(turned / "front.png").rotate(90).save(turned / "front.png")
    Image.open(turned / "bottom.png").rotate(90).save(turned / "bottom.png")
    assert _run(capsys, "block", "from-photos", turned, *size, "--out", blk)[0] == 0
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        block, _field = open_block(str(blk))
    assert len(block.faces["front"].traces) > 1
    (line,) = [str(w.message) for w in said if "front_traces" in str(w.message)]
    assert line.startswith(f"face 'front': the corrected {blk / 'front_traces.svg'} was traced over another front "
                           f"photo than this block's (the photo changed since)"), line
    assert "not used here" in line and line.endswith(
        f"move front_traces.svg out of {str(blk)!r} (or detect into another --out) and run again"), line
    assert not np.array_equal(block.faces["bottom"].ring_map, rings / 65535.0)  # detected
    (line,) = [str(w.message) for w in said if "bottom_ring_map" in str(w.message)]
    assert line.startswith(f"face 'bottom': the edited {blk / 'bottom_ring_map.png'} was made over another bottom "
                           f"photo than this block's (the photo changed since): it is not this photo's ring map"), line
    assert "not used here" in line and line.endswith(
        f"move bottom_ring_map.png out of {str(blk)!r} (or detect into another --out) and run again"), line
    assert all(issubclass(w.category, WoodcamWarning) for w in said)
    assert np.array_equal(block.faces["left"].extras["knot_mask"], mask > 127)


def _svg_of(n: int) -> str:
    """A user's traces SVG of a 160 px face: ``n`` straight lines, 10 px apart."""
    return ('<svg xmlns="http://www.w3.org/2000/svg" width="160" height="160" viewBox="0 0 160 160">'
            + "".join(f'<path d="M 10.5,{20.5 + 10 * k} L 150.5,{20.5 + 10 * k}"/>' for k in range(n)) + "</svg>")


def test_the_users_file_edited_since_it_was_carried_into_another_out_wins(synth_photos, tmp_path, capsys, monkeypatch):
    """'rings detect SRC --out OTHER' carries the user's corrected SVG and edited ring map of SRC
    into OTHER; the copies then won every later run, so the user's next edit in SRC was passed over
    (reproduced: front_traces.svg of SRC corrected again to 2 traces, OTHER kept 1, said as 'kept
    the corrected OTHER/front_traces.svg'). Now the one edited since the carry wins: SRC's is
    carried again, OTHER's copy edited there is kept; both edited since is refused in one line
    naming both, and deleting one (as it says) settles it."""
    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    blk, _size = _knotted_block_folder(synth_photos, tmp_path, capsys)
    other = tmp_path / "other"
    assert _run(capsys, "rings", "detect", blk, "--out", blk)[0] == 0
    maps = [np.zeros((160, 160), np.uint8) for _ in range(3)]  # 8-bit: its 16-bit copy in OTHER is the same map
    for k, m in enumerate(maps):
        m[:, k::7] = 255
    svg, ring_map = blk / "front_traces.svg", blk / "bottom_ring_map.png"
    svg.write_text(_svg_of(1))
    Image.fromarray(maps[0]).save(ring_map)

    def detect(n_traces, bottom):
        rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", other)
        assert rc == 0, err
        faces = read_block(other).faces
        assert len(faces["front"].traces) == n_traces, err
        assert np.array_equal(faces["bottom"].ring_map, maps[bottom] / 255.0), err
        return err

    err = detect(1, 0)
    # the user edits the source: its files win, carried again over the copies
    svg.write_text(_svg_of(2))
    Image.fromarray(maps[1]).save(ring_map)
    err = detect(2, 1)
    for f in (svg, ring_map):
        (line,) = [w for w in err.splitlines() if " kept the " in w and f.name in w]
        assert f" {f} (" in line and f"delete it and its copy {other / f.name} " in line, line
    # the user edits the copies in OTHER: they win, the source's (unchanged since) is not carried
    (other / svg.name).write_text(_svg_of(3))
    Image.fromarray(maps[2]).save(other / ring_map.name)
    err = detect(3, 2)
    assert f"kept the corrected {other / svg.name} (3 traces;" in err and svg.read_text() == _svg_of(2), err
    # both edited since the carry: refused, one line naming both, nothing written
    svg.write_text(_svg_of(4))
    rc, _out, err = _run(capsys, "rings", "detect", blk, "--out", other)
    assert rc == EXIT_ERROR and err.count("\n") == 1, err
    assert (f"face 'front': your {svg} and {other / svg.name} in --out are both your traces SVG of the face and "
            f"differ (both were edited since an earlier 'rings detect' carried the one into the other)") in err, err
    assert "delete (or move out) the other and run again" in err and (other / svg.name).read_text() == _svg_of(3)
    (other / svg.name).unlink()  # as it says: the source's then wins
    detect(4, 2)


def test_rings_detect_help_names_every_file_it_writes(capsys):
    """'rings detect --help' named the ring map and SVG files but only 'knot masks' (no file
    name, no word of which value is the knot: Mokume's masks are dark where the knot is, the
    detector's white) nor block.json, and said of a Mokume folder only that its U-Net maps are
    re-detected (its knot masks are too)."""
    with pytest.raises(SystemExit):
        main(["rings", "detect", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    for said in ("<face>_ring_map.png", "<face>_traces.svg", "<face>_knot_mask.png, white = knot", "block.json",
                 "its U-Net maps and knot masks are ignored: re-detected"):
        assert said in text, said


def test_a_dense_jpeg_is_decoded_reduced_turned_and_in_srgb(synth_photos, tmp_path, monkeypatch):
    """Six 30 MP phone JPEGs took 14 s and 500 MB for faces of 0.3 MP, each decoded in full and
    then resampled. Now a JPEG denser than the stored face is decoded at 1/2, 1/4 or 1/8 of its
    size (the JPEG decoder's DCT scaling), keeping DRAFT_MARGIN times the face's pixels, then
    resampled: the face within resampling error of the full decode's, still turned by its EXIF
    orientation and converted from its ICC profile. ``least`` is asked with the upright size."""
    import io

    from PIL import ImageCms, JpegImagePlugin

    from woodcam._readers import read_photo_rgb
    from woodcam.block.photos import DRAFT_MARGIN, _resampled, block_from_photos

    p3 = ImageCms.ImageCmsProfile(io.BytesIO(icc := _matrix_icc("Display P3 (test)", _P3)))
    d = _copy(synth_photos, tmp_path / "dense")
    with Image.open(d / "front.png") as im:  # 32 px/mm: 8 times the cap of 4
        shown = im.convert("RGB").resize((1600, 1600), Image.BICUBIC)
    stored = ImageCms.profileToProfile(shown, ImageCms.createProfile("sRGB"), p3)
    exif = Image.Exif()
    exif[0x0112] = 6  # turn clockwise to view: stored a quarter turn back
    Image.fromarray(np.rot90(np.asarray(stored)).copy()).save(d / "front.jpg", quality=95, exif=exif,
                                                                icc_profile=icc)
    (d / "front.png").unlink()
    drafts = []
    draft = JpegImagePlugin.JpegImageFile.draft

    def spy(im, mode, size):
        drafts.append((im.size, size))
        got = draft(im, mode, size)
        drafts.append(im.size)
        return got

    monkeypatch.setattr(JpegImagePlugin.JpegImageFile, "draft", spy)
    got = block_from_photos(d, (50, 50, 50), max_px_per_mm=4.0).faces["front"].photo.astype(int)
    # read at the cap (200 px), then again at the other photos' 3.2 px/mm (160 px): both at 1/4
    assert drafts == [((1600, 1600), (200 * DRAFT_MARGIN,) * 2), (400, 400),
                      ((1600, 1600), (160 * DRAFT_MARGIN,) * 2), (400, 400)], drafts
    monkeypatch.undo()
    full = _resampled(read_photo_rgb(d / "front.jpg", "x"), (160, 160)).astype(int)  # decoded in full
    diff = np.abs(got - full)
    assert diff.mean() < 0.5 and diff.max() <= 4, (diff.mean(), diff.max())
    upright = np.asarray(shown.resize((160, 160), Image.LANCZOS), int)
    assert np.abs(got - upright).mean() < 1.0  # turned and in sRGB (0.36 levels off)
    assert np.abs(got - np.rot90(upright)).mean() > 10.0
    asked = []
    Image.fromarray(np.zeros((600, 1000, 3), np.uint8)).save(tmp_path / "wide.jpg", exif=exif)
    a = read_photo_rgb(tmp_path / "wide.jpg", "x", least=lambda rows, cols: asked.append((rows, cols)) or (250, 150))
    assert asked == [(1000, 600)] and a.shape == (250, 150, 3)


def test_a_heic_photo_is_read_in_full_not_by_its_thumbnail(tmp_path):
    """A JPEG is decoded reduced where fewer pixels suffice; pillow-heif's draft, asked the same,
    swaps in the HEIC's embedded thumbnail (another, smaller encoding of the photo, an iPhone's
    320 px, enough under a low --max-px-per-mm). A HEIC is read in full, and ``least`` is still
    asked."""
    import pillow_heif

    from woodcam._readers import read_photo_rgb

    pillow_heif.register_heif_opener()
    rng = np.random.default_rng(0)
    Image.fromarray((rng.random((60, 80, 3)) * 255).astype(np.uint8)).resize((1600, 1200), Image.BICUBIC).save(
        tmp_path / "front.heic", quality=90, thumbnails=[800])
    asked = []
    a = read_photo_rgb(tmp_path / "front.heic", "x", least=lambda rows, cols: asked.append((rows, cols)) or (300, 400))
    assert asked == [(1200, 1600)] and a.shape == (1200, 1600, 3)
