"""Block folders: write/read round trips, precision, truth saving, and bad inputs."""

import json

import numpy as np
import pytest
from PIL import Image

from woodcam.block import Block, Face, RingTrace, block_from_images, read_block, write_block
from woodcam.errors import WoodcamError
from woodcam.synth import AnalyticLogField, cut_block, synth_block
from woodcam.tolerances import RING_MAP_QUANT_8BIT, RING_MAP_QUANT_16BIT

SIZE = (42.0, 36.0, 30.0)


@pytest.fixture(scope="module")
def block():
    field = cut_block(AnalyticLogField(ring_width_mm=2.2, eccentricity=0.1), SIZE, "rift", tilt_deg=2)
    b = synth_block(field, SIZE, face_px=64, trace_jitter_mm=0.1, unlabelled_fraction=0.3, seed=4,
                    meta={"note": "test", "numbers": np.arange(3)})
    b.faces["left"].extras["knot_mask"] = np.arange(np.prod(b.faces["left"].shape)).reshape(b.faces["left"].shape) % 7 == 0
    b.faces["left"].extras["comment"] = {"who": "test", "n": 2}
    return b


def _assert_same_traces(a, b):
    assert len(a) == len(b)
    for s, t in zip(a, b):
        assert s.year == t.year
        assert np.array_equal(s.points_px, t.points_px)   # exact: JSON keeps repr precision


@pytest.mark.parametrize("bits, tol", [(16, RING_MAP_QUANT_16BIT), (8, RING_MAP_QUANT_8BIT)])
def test_round_trip(tmp_path, block, bits, tol):
    write_block(block, tmp_path, ring_map_bits=bits)
    back = read_block(tmp_path)
    assert back.size_mm == block.size_mm and back.name == block.name
    assert back.meta == {**block.meta, "numbers": [0, 1, 2]}
    assert list(back.faces) == list(block.faces)
    for name, f in block.faces.items():
        g = back.faces[name]
        assert g.shape == f.shape
        assert g.photo.dtype == np.uint8 and np.array_equal(g.photo, f.photo)
        err = np.abs(g.ring_map.astype(float) - f.ring_map.astype(float)).max()
        assert err <= tol + 1e-7            # float32 storage of the map adds ~6e-8
        _assert_same_traces(f.traces, g.traces)
        # the files as any image program reads them, row 0 the face's top row (a writer and a
        # reader that both flipped an image agreed with each other, not with the file)
        assert np.array_equal(np.asarray(Image.open(tmp_path / f"{name}_photo.png")), f.photo)
        on_disk = np.asarray(Image.open(tmp_path / f"{name}_ring_map.png")).astype(float)
        assert on_disk.shape == f.shape
        assert np.abs(on_disk / (2 ** bits - 1) - f.ring_map).max() <= tol + 1e-7
    assert any(t.year is None for f in back.faces.values() for t in f.traces)
    assert np.array_equal(back.faces["left"].extras["knot_mask"], block.faces["left"].extras["knot_mask"])
    assert back.faces["left"].extras["comment"] == {"who": "test", "n": 2}
    # the analytic true field was saved and comes back identical
    p = np.random.default_rng(1).uniform(0, 30, (200, 3))
    assert np.array_equal(back.true_field(p), block.true_field(p))


def test_images_already_in_the_folder_are_named_not_written(tmp_path, block):
    """write_block(existing=...) names a face's ring map or PNG extra already in the folder (ring
    detection keeps a user's under the name block.json gave it), leaving the file as it is; the
    reader takes an 8-bit ring map's depth from the file; a name of no file is refused."""
    shape = block.faces["left"].shape
    rings = (np.arange(np.prod(shape)).reshape(shape) % 255).astype(np.uint8)
    Image.fromarray(rings).save(tmp_path / "mine.png")
    mask = np.zeros(shape, np.uint8)
    mask[10:20] = 255
    Image.fromarray(mask).save(tmp_path / "knots.png")
    before = {f: (tmp_path / f).read_bytes() for f in ("mine.png", "knots.png")}
    b = Block(block.size_mm, faces=dict(block.faces), name=block.name)
    f = b.faces["left"]
    b.faces["left"] = Face("left", f.shape, photo=f.photo, traces=f.traces, ring_map=rings / 255.0,
                           extras={**f.extras, "knot_mask": mask > 127})
    write_block(b, tmp_path, existing={"left": {"ring_map": "mine.png", "knot_mask": "knots.png"}})
    assert {f: (tmp_path / f).read_bytes() for f in before} == before
    assert not (tmp_path / "left_ring_map.png").exists() and not (tmp_path / "left_knot_mask.png").exists()
    back = read_block(tmp_path).faces["left"]
    assert np.allclose(back.ring_map, rings / 255.0, atol=1e-7) and np.array_equal(back.extras["knot_mask"], mask > 127)
    with pytest.raises(WoodcamError, match="existing ring_map of face 'left': 'gone.png' is not a file in"):
        write_block(b, tmp_path, existing={"left": {"ring_map": "gone.png"}})


@pytest.mark.parametrize("written, saved", [(16, 8), (8, 16)])
def test_a_ring_map_saved_at_another_depth_is_read_at_its_own(tmp_path, block, written, saved):
    """A ring map the user saved over the block's at another bit depth than block.json's
    ring_map_bits (an editor's 8-bit export over a 16-bit map) was scaled by the manifest's: an
    8-bit map under 16 came back 257 times too dark (white 0.0039) without a word, a 16-bit one
    under 8 was refused. The PNG's own depth is read, and a block written again from it and read
    back is the same map (within the written depth's half step)."""
    write_block(block, tmp_path / "a", ring_map_bits=written)
    shape = block.faces["top"].shape
    levels = (np.arange(np.prod(shape)).reshape(shape) * 7) % 256
    mine = levels.astype(np.uint8) if saved == 8 else (levels * 257).astype(np.uint16)
    Image.fromarray(mine).save(tmp_path / "a" / "top_ring_map.png")
    assert json.loads((tmp_path / "a" / "block.json").read_text())["faces"]["top"]["ring_map_bits"] == written
    back = read_block(tmp_path / "a")
    assert back.faces["top"].ring_map.dtype == np.float32
    assert np.array_equal(back.faces["top"].ring_map, (levels / 255.0).astype(np.float32))  # exact: k/255 = 257k/65535
    write_block(back, tmp_path / "b", ring_map_bits=written)
    again = read_block(tmp_path / "b").faces["top"].ring_map
    tol = RING_MAP_QUANT_16BIT if written == 16 else RING_MAP_QUANT_8BIT
    assert np.abs(again.astype(float) - levels / 255.0).max() <= tol + 1e-7


def test_16bit_is_finer_than_8bit(tmp_path, block):
    errs = []
    for bits in (8, 16):
        write_block(block, tmp_path / str(bits), ring_map_bits=bits)
        back = read_block(tmp_path / str(bits))
        errs.append(max(np.abs(back.faces[n].ring_map - block.faces[n].ring_map).max() for n in block.faces))
    assert errs[1] < errs[0] / 50


def test_unserialisable_truth_is_recorded_not_saved(tmp_path):
    b = synth_block(lambda p: np.hypot(p[:, 0] + 50, p[:, 1]) / 3.0, SIZE, face_px=24)
    write_block(b, tmp_path)
    m = json.loads((tmp_path / "block.json").read_text())
    assert m["true_field"]["saved"] is False and "truth not saved" in m["true_field"]["reason"]
    assert not (tmp_path / "true_field.json").exists()
    assert read_block(tmp_path).true_field is None


def test_real_block_manifest_written_by_hand(tmp_path):
    photo = np.random.default_rng(0).integers(0, 256, (20, 30, 3), dtype=np.uint8)
    Image.fromarray(photo).save(tmp_path / "front.png")
    (tmp_path / "block.json").write_text(json.dumps({
        "format": "woodcam-block", "version": 1, "name": "oak offcut", "size_mm": [60, 45, 40],
        "faces": {"front": {"shape": [20, 30], "photo": "front.png",
                            "traces": [{"year": None, "points_px": [[1, 2], [3, 4.5]]}]}}}))
    b = read_block(tmp_path / "block.json")
    assert b.size_mm == (60.0, 45.0, 40.0) and list(b.faces) == ["front"] and b.true_field is None
    assert np.array_equal(b.faces["front"].photo, photo)
    assert b.faces["front"].traces[0].year is None


def test_wrong_image_size_on_disk_raises(tmp_path, block):
    write_block(block, tmp_path)
    Image.fromarray(np.zeros((10, 11, 3), np.uint8)).save(tmp_path / "top_photo.png")
    with pytest.raises(WoodcamError, match=r"photo of face 'top' .* must be \d+x64 px like its face; got 10x11"):
        read_block(tmp_path)


def test_bad_inputs_raise(tmp_path, block):
    with pytest.raises(WoodcamError, match="must hold a block.json"):
        read_block(tmp_path)
    with pytest.raises(WoodcamError, match="ring_map_bits must be 8 or 16"):
        write_block(block, tmp_path, ring_map_bits=12)
    with pytest.raises(WoodcamError, match=r"ring_map of face 'front' must hold finite values in \[0, 1\]"):
        # refused where the face is made (tests/robust/test_api_doors.py), before write_block
        write_block(Block(SIZE, {"front": Face("front", (4, 4), ring_map=np.full((4, 4), 1.5))}), tmp_path / "x")
    with pytest.raises(WoodcamError, match="block.meta must be JSON-serialisable"):
        write_block(Block(SIZE, meta={"f": object()}), tmp_path / "y")
    with pytest.raises(WoodcamError, match="photo of face 'front' must be uint8"):
        write_block(Block(SIZE, {"front": Face("front", (2, 2), photo=np.zeros((2, 2, 3)))}), tmp_path / "z")
    write_block(block, tmp_path / "w")
    with pytest.raises(WoodcamError, match="already holds a block.json"):
        write_block(block, tmp_path / "w", overwrite=False)
    with pytest.raises(WoodcamError, match="points_px of a ring trace must have shape"):
        RingTrace(np.zeros((1, 2)), 3)


def test_block_from_images_of_a_real_block(tmp_path):
    rng = np.random.default_rng(0)
    top = rng.integers(0, 256, (30, 40, 3), dtype=np.uint8)
    Image.fromarray(top).save(tmp_path / "top.jpg.png")
    grey = rng.integers(0, 256, (20, 40), dtype=np.uint8)
    ring16 = rng.integers(0, 65536, (20, 40), dtype=np.uint16)
    b = block_from_images((40, 30, 20), photos={"B": tmp_path / "top.jpg.png", "front": grey},
                          ring_maps={"A": ring16}, name="walnut", meta={"camera": "phone"})
    assert list(b.faces) == ["front", "top"] and b.faces["top"].shape == (30, 40)
    assert np.array_equal(b.faces["top"].photo, top)
    assert np.array_equal(b.faces["front"].photo[..., 1], grey)
    np.testing.assert_allclose(b.faces["front"].ring_map, ring16 / 65535, atol=1e-7)
    write_block(b, tmp_path / "walnut")
    back = read_block(tmp_path / "walnut")
    assert np.array_equal(back.faces["top"].photo, top) and back.meta == {"camera": "phone"}
    with pytest.raises(WoodcamError, match=r"ring_map of face 'front' must be 20x40 px like its face; got 21x40"):
        block_from_images((40, 30, 20), photos={"front": grey}, ring_maps={"front": np.zeros((21, 40))})
    with pytest.raises(WoodcamError, match="photo of face 'top' must be an 8-bit RGB image"):
        block_from_images((40, 30, 20), photos={"top": np.zeros((4, 4, 3))})


def test_a_missing_block_folder_is_named_as_given(tmp_path):
    """It said ``folder '<parent>' must hold a block.json`` about the parent of the path."""
    missing = tmp_path / "no_such_block"
    with pytest.raises(WoodcamError, match=f"block folder '{missing}' does not exist"):
        read_block(missing)


def test_write_block_refuses_what_read_block_would_refuse(tmp_path):
    """These were written (over a good block folder, by default) and then refused by read_block,
    or came back changed: NaN in meta, a 20 m block, a face of 0 x 0 px, a trace far outside its
    face, a name that is not a string, an RGBA extra (read back as RGB)."""
    import numpy as np

    from woodcam.block import Block, Face, RingTrace, write_block
    from woodcam.errors import WoodcamError

    with pytest.raises(WoodcamError, match=r"block.meta must be JSON-serialisable"):
        write_block(Block((10, 10, 10), meta={"x": float("nan")}), tmp_path / "a")
    with pytest.raises(WoodcamError, match="at most 10000 mm a side"):
        Block((20000, 10, 10))
    with pytest.raises(WoodcamError, match="must be two pixel counts"):
        Face("top", (0, 0))
    with pytest.raises(WoodcamError, match="lies beyond its 4x4 px image"):
        Face("top", (4, 4), traces=[RingTrace([[0, 0], [100, 100]])])
    with pytest.raises(WoodcamError, match="Block.name must be a plain name, no path .*got 5"):
        Block((10, 10, 10), name=5)
    rgba = Face("top", (4, 4), extras={"paint": np.zeros((4, 4, 4), np.uint8)})
    with pytest.raises(WoodcamError, match=r"grey \(h, w\) or RGB \(h, w, 3\)"):
        write_block(Block((10, 10, 10), faces={"top": rgba}), tmp_path / "b")
    assert not (tmp_path / "a" / "block.json").exists() and not (tmp_path / "b" / "block.json").exists()


def test_a_ragged_saved_field_is_refused_with_one_fix_naming_the_file(tmp_path):
    """A ragged r_minus in a RadialScalingField state was a bare ValueError (only KeyError,
    TypeError and IndexError were caught), and the block reader's message offered two fixes."""
    from woodcam.fields import LogFrame
    from woodcam.fields.radial import RadialScalingField, RadiusFunction
    from woodcam.fields.state import field_from_state, field_to_state

    field = RadialScalingField(LogFrame((0, 0, -50), (0, 0, 1)), 3.0, RadiusFunction(np.ones(16)),
                               RadiusFunction(np.ones(16)))
    state = field_to_state(field)
    state["state"]["r_minus"] = [[1, 2], [3]]
    with pytest.raises(WoodcamError, match=r"incomplete or malformed \(ValueError: .*\); pass what "
                                           r"field_to_state returned for it$"):
        field_from_state(state)
    write_block(Block((10, 10, 10), true_field=field), tmp_path / "b")
    (saved,) = [p for p in (tmp_path / "b").iterdir() if p.suffix == ".json" and p.name != "block.json"]
    raw = json.loads(saved.read_text())
    raw["r_minus"] = [[1, 2], [3]]
    saved.write_text(json.dumps(raw))
    with pytest.raises(WoodcamError) as err:
        read_block(tmp_path / "b")
    msg = str(err.value)
    assert msg.startswith(f"true field {str(saved)!r}: the saved state of field type") and "ValueError" in msg
    assert msg.endswith(f"; write the block again (woodcam.block.write_block) to replace {saved.name}")
    assert msg.count("; ") == 1 and "drop the file" not in msg and "returned for it" not in msg


@pytest.mark.parametrize("name", ["../escaped", "a/b", "..\\x"])
def test_a_block_name_that_is_a_path_is_refused_before_it_names_a_file(tmp_path, name):
    """A block's name makes its output files' names (leave_one_face_out's NAME_holdout.md): a
    block.json "name" of '../escaped' wrote them outside out_dir."""
    with pytest.raises(WoodcamError, match=r"Block.name must be a plain name, no path .*got '.*'; e.g. 'oak1'"):
        Block((10, 10, 10), name=name)
    write_block(Block((10, 10, 10), name="plain"), tmp_path / "b")
    manifest = json.loads((tmp_path / "b" / "block.json").read_text())
    (tmp_path / "b" / "block.json").write_text(json.dumps({**manifest, "name": name}))
    with pytest.raises(WoodcamError, match="Block.name must be a plain name"):
        read_block(tmp_path / "b")



def test_rings_show_and_block_show_name_each_face():
    """'rings show' and 'block show' drew six photos in a cross with no word of which face was
    which (the user had to work it out from docs/conventions.md): each face present now carries
    its name and Mokume letter at its top-left corner, and an absent face's slot its name and
    'no photo' (it was an empty hole)."""
    from woodcam.block import Block, Face
    from woodcam.block.render import cross_image
    from woodcam.detect.show import rings_picture
    from woodcam.frames import FACES, CrossLayout

    grey = np.full((64, 64, 3), 150, np.uint8)
    block = Block((10.0, 10.0, 10.0), faces={f: Face(f, (64, 64), photo=grey) for f in FACES if f != "back"})
    for pic, zoom in ((rings_picture(block, zoom=2), 2), (cross_image(block), 1)):
        layout = CrossLayout((10.0, 10.0, 10.0), 6.4 * zoom)
        corners = {}
        for f in FACES:
            r, c = layout.origin[f]
            corner = pic[r:r + 16 * zoom // 2 + 8, c:c + 64 * zoom // 2]
            corners[f] = corner
        for f in FACES:
            if f == "back":
                from woodcam.block.render import missing_face

                r, c = layout.origin[f]
                h, w = layout.face_shape(f)
                assert np.array_equal(pic[r:r + h, c:c + w], missing_face(f, (h, w), 24)), "absent: 'no photo'"
                assert (corners[f] > 200).all(axis=2).any(), "an absent face is labelled"
                continue
            assert (corners[f] > 200).all(axis=2).any(), f"face {f!r} has no white label"
            assert (corners[f] < 40).all(axis=2).any(), f"face {f!r} has no dark label box"
        assert not np.array_equal(corners["front"], corners["top"]), "labels differ by face"
