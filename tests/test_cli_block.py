"""``woodcam block synth`` and ``woodcam block show`` through the parser the CLI uses."""

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from woodcam.cli import main
from woodcam.block import read_block
from woodcam.block.render import label_face
from woodcam.errors import WoodcamError
from woodcam.frames import CrossLayout


def test_block_synth_then_show(tmp_path, capsys):
    out = tmp_path / "set"
    assert main(["block", "synth", "--count", "2", "--seed", "5", "--out", str(out),
                 "--face-px", "40", "--quiet"]) == 0
    index = json.loads((out / "index.json").read_text())
    assert [b["name"] for b in index["blocks"]] == ["block_0000", "block_0001"]
    block = read_block(out / "block_0001")
    png = tmp_path / "cross.png"
    assert main(["block", "show", str(out / "block_0001"), "--out", str(png), "--no-traces"]) == 0
    im = np.asarray(Image.open(png))
    layout = CrossLayout(block.size_mm, block.faces["front"].shape[1] / block.size_mm[0])
    assert im.shape == layout.shape + (3,)
    for name, face in block.faces.items():          # every face photo sits where the cross says, named
        r0, c0 = layout.origin[name]
        assert np.array_equal(im[r0:r0 + face.shape[0], c0:c0 + face.shape[1]], label_face(face.photo, name)), name
    # with traces drawn, pixels change only on the faces, on their rings: each face's changed
    # pixels lie along its traces (pixel (row, col) = points_px), and most trace points are drawn
    assert main(["block", "show", str(out / "block_0001"), "--out", str(png)]) == 0
    traced = np.asarray(Image.open(png))
    changed = (traced != im).any(axis=-1)
    assert changed.any()
    from scipy import ndimage

    on_faces = 0
    for name, face in block.faces.items():
        r0, c0 = layout.origin[name]
        here = changed[r0:r0 + face.shape[0], c0:c0 + face.shape[1]]
        near = np.zeros(face.shape, bool)
        pts = np.concatenate([t.points_px for t in face.traces]) if face.traces else np.zeros((0, 2))
        rc = np.clip(np.round(pts).astype(int), 0, np.array(face.shape) - 1)
        near[rc[:, 0], rc[:, 1]] = True
        assert not (here & ~ndimage.binary_dilation(near, iterations=2)).any(), name
        # the face's name box at its top-left corner is drawn over its traces
        boxed = np.argwhere((label_face(face.photo, name) != face.photo).any(axis=-1)).max(axis=0)
        rc = rc[(rc[:, 0] > boxed[0]) | (rc[:, 1] > boxed[1])]
        if len(rc):
            assert here[rc[:, 0], rc[:, 1]].mean() > 0.8, name
        on_faces += here.sum()
    assert on_faces == changed.sum() > 0
    assert main(["block", "show", str(out / "block_0001"), "--out", str(png), "--layer", "both"]) == 0
    assert np.asarray(Image.open(png)).shape == (2 * layout.shape[0] + 8, layout.shape[1], 3)


def test_block_errors_are_one_line(tmp_path, capsys):
    """An empty folder given as a block: one line naming the argument that gave it (the folder
    alone left a command of several block inputs to guess which), exit 1 as the README's exit
    statuses say of an input that is there and of its kind but whose contents are bad."""
    assert main(["block", "show", str(tmp_path), "--out", str(tmp_path / "x.png")]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"woodcam: error: BLOCK of 'woodcam block show': folder {str(tmp_path)!r} is not a block")
    assert err.count("\n") == 1
    assert "block.json" in err and "Mokume files" in err and "face photos" in err
    empty = tmp_path / "empty"
    empty.mkdir()
    Image.fromarray(np.full((32, 32, 3), 100, np.uint8)).save(tmp_path / "x.png")  # parquetry's design
    part = Path(__file__).parents[1] / "cad_examples" / "bowl.py"
    for argv, given in ((["bake", str(part), "--block", str(empty), "--out", str(tmp_path / "b.glb")],
                         "--block of 'woodcam bake'"),
                        (["fit", str(empty), "--out", str(tmp_path / "f.npz")], "BLOCK of 'woodcam fit'"),
                        (["parquetry", str(tmp_path / "x.png"), "--veneer-from", "builtin:flat-sawn",
                          "--veneer-from", str(empty), "--out", str(tmp_path / "pq")],
                         "--veneer-from of 'woodcam parquetry'")):
        assert main(argv) == 1, argv
        err = capsys.readouterr().err
        assert err.startswith(f"woodcam: error: {given}: folder {str(empty)!r} is not a block"), err
        assert err.count("\n") == 1


def test_a_folder_of_face_photos_is_told_to_become_a_block(tmp_path, capsys):
    """Photos named by face (here by Mokume letter, A.jpg ...) given where a block is wanted:
    the error says to run ``block from-photos`` on them (it said the folder lacked Mokume
    files, which a user with six photos cannot act on)."""
    for letter in "ABCDEF":
        Image.fromarray(np.full((32, 32, 3), 100, np.uint8)).save(tmp_path / f"{letter}.jpg")
    assert main(["block", "show", str(tmp_path), "--out", str(tmp_path / "x.png")]) == 1
    err = capsys.readouterr().err
    assert "holds face photos (A.jpg" in err and "woodcam block from-photos" in err and err.count("\n") == 1


def test_show_of_a_missing_folder_says_what_it_wants(tmp_path, capsys):
    assert main(["block", "show", str(tmp_path / "nope"), "--out", str(tmp_path / "x.png")]) == 2  # the input door's
    assert "a block folder with block.json or a Mokume sample folder" in capsys.readouterr().err


def test_block_synth_noise_options(tmp_path):
    """The benchmark's noise knobs reach the blocks: jitter/dropout/mislabels in the settings,
    ring maps only leaves no traces; bad ranges are refused with one line."""
    import json

    from woodcam.block.io import read_block

    out = tmp_path / "noisy"
    assert main(["block", "synth", "--count", "1", "--seed", "3", "--out", str(out), "--face-px", "40",
                 "--quiet", "--jitter-mm", "0.3", "--dropout", "0.2", "--mislabel", "0.03",
                 "--knotted-fraction", "0"]) == 0
    b = read_block(out / "block_0000")
    assert b.meta["trace_jitter_mm"] == 0.3 and b.meta["trace_dropout"] == 0.2
    assert b.meta["mislabel_fraction"] == 0.03 and not b.meta["knotted"]
    maps = tmp_path / "maps"
    assert main(["block", "synth", "--count", "1", "--seed", "3", "--out", str(maps), "--face-px", "40",
                 "--quiet", "--ring-maps-only", "--knotted-fraction", "0"]) == 0
    b = read_block(maps / "block_0000")
    assert all(not f.traces and f.ring_map is not None for f in b.faces.values())
    assert json.loads((maps / "index.json").read_text())["count"] == 1



@pytest.mark.parametrize("value", ["80,30", "nan,30", "-1,30", "0,30", "30", "30,1e300", "a,b"])
def test_block_synth_refuses_a_size_range_at_the_door(value, tmp_path, capsys):
    """--size-range-mm was read in the command: '80,30' and 'nan,30' exited 1, '-1,30' was
    argparse's 'expected one argument', '30,1e300' was taken. Now one usage line (exit 2) naming
    the rule, before any block is made."""
    from woodcam.cli import EXIT_USAGE

    capsys.readouterr()
    with pytest.raises(SystemExit) as exc:  # argparse's own exit
        main(["block", "synth", "--count", "1", "--out", str(tmp_path / "x"), "--size-range-mm", value])
    assert exc.value.code == EXIT_USAGE
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and ("--size-range-mm takes MIN,MAX in mm with 0 < MIN <= MAX <= 10000 "
                              "(raise it with WOODCAM_MAX_BLOCK_SIZE_MM=N), e.g. 30,80; "
                              f"got {value!r}") in err[0], err
    assert not (tmp_path / "x").exists()


def test_block_synth_noise_options_on_an_engine_write_the_same_blocks(tmp_path, capsys):
    """`block synth --engine` takes the benchmark's noise flags (issue 12 part 6) and writes
    the same noisy blocks, byte for byte, as the plain command; a bad fraction is refused at the
    door with one line."""
    from woodcam.cli import EXIT_USAGE

    flags = ["--count", "2", "--seed", "7", "--face-px", "40", "--quiet", "--jitter-mm", "0.3",
             "--dropout", "0.2", "--mislabel", "0.1", "--knotted-fraction", "0", "--size-range-mm", "30,40"]
    plain, eng = tmp_path / "plain", tmp_path / "engine"
    assert main(["block", "synth", *flags, "--out", str(plain)]) == 0
    assert main(["block", "synth", *flags, "--out", str(eng), "--engine", "local", "--workers", "1"]) == 0
    for name in ("block_0000", "block_0001"):
        files = sorted(p.relative_to(plain / name) for p in (plain / name).rglob("*") if p.is_file())
        assert files
        for rel in files:
            assert (plain / name / rel).read_bytes() == (eng / name / rel).read_bytes(), (name, rel)
        b = read_block(eng / name)
        assert b.meta["trace_jitter_mm"] == 0.3 and b.meta["mislabel_fraction"] == 0.1
        assert all(30 <= s <= 40 for s in b.size_mm)
    maps = tmp_path / "maps"
    assert main(["block", "synth", "--count", "1", "--seed", "7", "--face-px", "40", "--quiet",
                 "--ring-maps-only", "--out", str(maps), "--engine", "local", "--workers", "1"]) == 0
    assert all(not f.traces and f.ring_map is not None for f in read_block(maps / "block_0000").faces.values())
    capsys.readouterr()
    assert main(["block", "synth", "--count", "1", "--out", str(tmp_path / "bad"), "--engine", "local",
                 "--dropout", "1.5"]) == EXIT_USAGE
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["woodcam: error: --dropout must be in [0, 1]; got 1.5; see 'woodcam block synth --help' for its "
                   "meaning and default"]  # it named the parameter (trace_dropout), not the option


def test_block_synth_on_an_engine_into_a_set_of_another_seed_is_refused(tmp_path, capsys):
    """A second `block synth --engine` into the same folder with another seed found every
    block's record done, kept the first seed's blocks and wrote an index.json of the second."""
    from woodcam.cli import EXIT_USAGE

    out = tmp_path / "set"
    flags = ["--count", "1", "--face-px", "32", "--quiet", "--knotted-fraction", "0", "--workers", "1",
             "--out", str(out)]
    assert main(["block", "synth", "--seed", "1", *flags]) == 0
    first = (out / "block_0000" / "block.json").read_bytes()
    capsys.readouterr()
    # a wrong command line (an --out that holds another set): exit 2, one line with the fixes
    assert main(["block", "synth", "--seed", "2", *flags]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and ("another seed or settings (seed 1 there, 2 now); pick another --out, run "
                                     f"again with its options (--seed 1) to resume it, or delete {str(out)!r} "
                                     "to start over") in err, err
    # the --out given, not its hidden records folder ('delete .../set/.synth' lost the set's index)
    assert f"{str(out)!r} holds a run" in err and ".synth" not in err
    assert json.loads((out / "index.json").read_text())["seed"] == 1
    assert (out / "block_0000" / "block.json").read_bytes() == first
    # the same seed resumes; more blocks of it extend the set
    assert main(["block", "synth", "--seed", "1", *flags[2:], "--count", "2"]) == 0
    assert "1 already done, 1 computed" in capsys.readouterr().out


def test_block_synth_without_an_engine_into_an_engine_set_of_another_seed_is_refused(tmp_path, capsys):
    """'block synth --seed 2' (no engine) into a folder an engine run of seed 1 made overwrote its
    blocks and index.json without a word and left seed 1's records: a later engine run of seed 1
    found them done and kept seed 2's blocks as its own."""
    from woodcam.cli import EXIT_USAGE

    out = tmp_path / "set"
    flags = ["--count", "1", "--face-px", "32", "--quiet", "--knotted-fraction", "0", "--out", str(out)]
    assert main(["block", "synth", "--seed", "1", *flags, "--workers", "1"]) == 0
    first = (out / "block_0000" / "block.json").read_bytes()
    capsys.readouterr()
    # the engine path's rule, before any work: exit 2, one line naming the seed there and the fixes
    assert main(["block", "synth", "--seed", "2", *flags]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and (f"{str(out)!r} holds a run with another seed or settings (seed 1 there, "
                                     "2 now); pick another --out, run again with its options (--seed 1)") in err, err
    assert json.loads((out / "index.json").read_text())["seed"] == 1
    assert (out / "block_0000" / "block.json").read_bytes() == first
    # the same seed and settings without an engine rewrite the same set (bit for bit), the
    # engine's records still true of it
    assert main(["block", "synth", "--seed", "1", *flags]) == 0
    assert (out / "block_0000" / "block.json").read_bytes() == first
    # the reverse: an engine run into a folder the serial path filled with another seed holds no
    # record, so it makes every block anew
    other = tmp_path / "serial"
    flags2 = [*flags[:-1], str(other)]
    assert main(["block", "synth", "--seed", "2", *flags2]) == 0
    capsys.readouterr()
    assert main(["block", "synth", "--seed", "1", *flags2, "--workers", "1"]) == 0
    assert "0 already done, 1 computed" in capsys.readouterr().out
    assert (other / "block_0000" / "block.json").read_bytes() == first
    assert json.loads((other / "index.json").read_text())["seed"] == 1


def test_block_synth_says_why_a_block_failed(tmp_path, capsys):
    """'block synth --size-range-mm 10000,10000 --workers 1' printed '1 keys: ... 1 failed; ...'
    and exit 3 with no reason: the error was in OUT/.synth/records only."""
    out = tmp_path / "set"
    assert main(["block", "synth", "--count", "1", "--face-px", "16", "--quiet", "--knotted-fraction", "1",
                 "--workers", "1", "--size-range-mm", "10000,10000", "--out", str(out)]) == 3
    said = capsys.readouterr().out
    # the fix names the options that change it (it said 'use a smaller block or a log with longer
    # knots': no option of the command), and the parameters of the library call
    fix = ("no knot of this log crosses a 10000 x 10000 mm block after 60 tries; draw smaller blocks "
           "(size_range_mm is (10000, 10000); --size-range-mm of 'woodcam block synth', default 30,80) or "
           "fewer knotted ones (knotted_fraction is 1; --knotted-fraction, 0 for none)")
    assert "1 failed" in said and f"; block_0000 failed: WoodcamError: {fix}" in said, said
    # without an engine: the command's one line
    assert main(["block", "synth", "--count", "1", "--face-px", "16", "--quiet", "--knotted-fraction", "1",
                 "--size-range-mm", "10000,10000", "--out", str(tmp_path / "plain")]) == 1
    assert capsys.readouterr().err == f"woodcam: error: {fix}\n"


def test_a_benchmark_set_resumes_with_its_defaults_spelled_out(tmp_path):
    """block_options were stored as given: a rerun spelling out a default (size_range_mm
    [30, 80], as 'block synth --engine' does) was refused as a set of other settings."""
    from woodcam.benchmark import write_benchmark_set

    kw = dict(face_px=32, knotted=False, engine="local", workers=1, progress=False)
    write_benchmark_set(tmp_path / "set", 1, 4, **kw)
    summary, index = write_benchmark_set(tmp_path / "set", 1, 4, block_options={
        "size_range_mm": (30, 80), "knotted_fraction": 0.5, "trace_dropout": 0.0}, **kw)
    assert (summary.skipped, summary.done) == (1, 0) and index["size_range_mm"] == [30.0, 80.0]
    with pytest.raises(WoodcamError, match=r"block_options.trace_dropout 0.0 there, 0.2 now"):
        write_benchmark_set(tmp_path / "set", 1, 4, block_options={"trace_dropout": 0.2}, **kw)


def test_a_stopped_benchmark_set_block_leaves_no_folder(tmp_path, monkeypatch):
    """The block was written into .block_0000.<pid>.tmp and renamed: a Ctrl-C (or an error)
    part way left that folder, half written, for good (a rerun's pid differs)."""
    import woodcam.block.io as block_io
    from woodcam.benchmark import _synth_set_task

    real = block_io.write_block

    def half_then_stop(block, folder, **kw):
        Path(folder).mkdir(parents=True, exist_ok=True)  # as write_block does
        (Path(folder) / "front_photo.png").write_bytes(b"\x89PNG half")
        raise KeyboardInterrupt

    monkeypatch.setattr(block_io, "write_block", half_then_stop)
    with pytest.raises(KeyboardInterrupt):
        _synth_set_task("block_0000", 4, str(tmp_path), 32, False)
    assert list(tmp_path.iterdir()) == []
    monkeypatch.setattr(block_io, "write_block", real)
    _synth_set_task("block_0000", 4, str(tmp_path), 32, False)
    assert [p.name for p in tmp_path.iterdir()] == ["block_0000"]
    assert read_block(tmp_path / "block_0000").faces


def test_engine_options_alone_run_on_the_engine_and_train_rings_refuses_them(tmp_path, capsys):
    """'block synth --workers 2' ran serially in this process, as if --workers were not given;
    'train rings' accepted --address, --workers and --no-resume and used none of them. Refused as
    a wrong command line (exit 2; it was 1)."""
    from woodcam.cli import EXIT_USAGE

    assert main(["block", "synth", "--count", "1", "--seed", "3", "--out", str(tmp_path / "b"), "--face-px", "32",
                 "--quiet", "--workers", "1", "--knotted-fraction", "0"]) == 0
    assert "on local with 1 worker;" in capsys.readouterr().out
    for extra in (["--workers", "7"], ["--address", "tcp://127.0.0.1:9"], ["--no-resume"]):
        assert main(["train", "rings", "--out", str(tmp_path / "t"), *extra]) == EXIT_USAGE
        assert "are for 'train gtf'" in capsys.readouterr().err
    assert not (tmp_path / "t").exists()


def test_options_that_would_change_nothing_are_named(tmp_path, capsys, shared_data):
    """--size-mm on a block folder, and the leaf-slicing options with only Mokume veneers, were
    accepted and ignored without a word."""
    from woodcam.cli import EXIT_ERROR

    assert main(["block", "synth", "--count", "1", "--seed", "3", "--out", str(tmp_path / "b"), "--face-px", "32",
                 "--quiet", "--knotted-fraction", "0"]) == 0
    capsys.readouterr()
    assert main(["block", "show", str(tmp_path / "b" / "block_0000"), "--size-mm", "30",
                 "--out", str(tmp_path / "s.png")]) == 0
    assert "--size-mm (size_mm (30.0, 30.0, 30.0)) is for Mokume sample folders" in capsys.readouterr().err
    # a target that is no image: the run stops as it reads it, after the warning (no target at
    # all is now a wrong command line, refused before it: 260e4e0)
    (tmp_path / "t.png").write_bytes(b"no image")
    assert main(["parquetry", str(tmp_path / "t.png"), "--veneer-from", str(shared_data / "mokume" / "CN03"),
                 "--sheets", "3", "--slice-axis", "x", "--out", str(tmp_path / "pq")]) == EXIT_ERROR
    assert "--sheets, --slice-axis slice leaves from blocks" in capsys.readouterr().err


def test_block_show_makes_its_out_folder(tmp_path, capsys):
    """It did the work, then failed on a missing folder naming a hidden temporary file."""
    assert main(["block", "show", "builtin:flat-sawn", "--out", str(tmp_path / "new" / "deeper" / "s.png")]) == 0
    assert (tmp_path / "new" / "deeper" / "s.png").stat().st_size > 1000


def test_eval_rings_detect_on_a_block_with_a_true_field_says_it_is_not_used(tmp_path, capsys):
    """--detect re-detects real blocks only; on a synthetic block it was ignored without a word
    (the table was the run without it)."""
    assert main(["block", "synth", "--count", "1", "--seed", "3", "--out", str(tmp_path / "b"), "--face-px", "48",
                 "--quiet", "--knotted-fraction", "0"]) == 0
    capsys.readouterr()
    assert main(["eval", "rings", str(tmp_path / "b" / "block_0000"), "--methods", "radial", "--partial-faces",
                 "none", "--detect", "--out", str(tmp_path / "e")]) == 0
    assert "--detect re-detects the rings of real blocks only" in capsys.readouterr().err


def test_fit_says_an_unverified_fit_once(tmp_path, capsys):
    """'fit --faces top' printed 'only one face carries rings ...' twice: as the warning and again
    as the fit's summary."""
    assert main(["block", "synth", "--count", "1", "--seed", "3", "--out", str(tmp_path / "b"), "--face-px", "48",
                 "--quiet", "--knotted-fraction", "0"]) == 0
    capsys.readouterr()
    assert main(["fit", str(tmp_path / "b" / "block_0000"), "--faces", "top", "--out", str(tmp_path / "f.npz")]) == 0
    out = capsys.readouterr()
    assert (out.out + out.err).count("only one face carries rings") == 1


def test_trace_noise_with_ring_maps_only_is_named(tmp_path, capsys):
    """--ring-maps-only --jitter-mm 0.3 recorded a jitter in every block that nothing had."""
    assert main(["block", "synth", "--count", "1", "--seed", "3", "--out", str(tmp_path / "b"), "--face-px", "32",
                 "--quiet", "--knotted-fraction", "0", "--ring-maps-only", "--jitter-mm", "0.3"]) == 0
    assert "--jitter-mm act on traced rings; with --ring-maps-only" in capsys.readouterr().err


def test_size_mm_given_with_a_block_that_is_no_folder_is_said_to_be_ignored(tmp_path, capsys):
    """``block show builtin:flat-sawn --size-mm 30`` (fit, eval likewise) drew the 100 mm block
    without a word: --size-mm sizes Mokume sample folders only. Now a warning says it was
    ignored and how to size such a block."""
    capsys.readouterr()
    assert main(["block", "show", "builtin:flat-sawn", "--size-mm", "30", "--out", str(tmp_path / "s.png")]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["woodcam: warning: --size-mm 30 sizes Mokume sample folders only; 'builtin:flat-sawn' is no "
                   "folder and keeps its own size: ignored (a built-in or log block takes its size in the spec, "
                   "e.g. builtin:flat-sawn:40x40x40)"], err


def test_the_real_log_without_shared_data_is_pointed_at_each_callers_way(tmp_path, capsys, monkeypatch):
    """Without the shared data folder, the real log's error ended in "or pass folder=" on the
    command line too, which has no such option: a 'log:gran1@K' block says the spec's way (a log
    file of one's own), 'log render --real' its options, and read_gran1 keeps its folder=."""
    import woodcam.logs.io
    from woodcam.logs.io import read_gran1
    from woodcam.stock import open_stock

    monkeypatch.setattr(woodcam.logs.io, "shared_data_dir", lambda: None)
    need = "the real log needs the shared data folder (its trees/Gran_1_*.json), and none was found; " \
           "set WOODCAM_SHARED_DATA=/path/to/shared/data "
    with pytest.raises(WoodcamError) as err:
        read_gran1()
    assert str(err.value) == need + "or pass folder="
    spec_fix = "or cut the block from a log file of your own: 'log:LOG.json@10'"
    with pytest.raises(WoodcamError) as err:
        open_stock("log:gran1@10")
    assert str(err.value) == need + spec_fix
    for argv, fix in ((["fit", "log:gran1@10", "--out", str(tmp_path / "f.npz")], spec_fix),
                      (["bake", str(Path(__file__).parents[1] / "cad_examples" / "bowl.py"), "--block", "log:gran1@10", "--out",
                        str(tmp_path / "b.glb")], spec_fix),
                      (["log", "render", "--real", "--out", str(tmp_path / "r")],
                       "or give a LOG_FILE or --maps DIR instead of --real")):
        assert main(argv) == 1, argv
        err_text = capsys.readouterr().err
        assert err_text == f"woodcam: error: {need}{fix}\n", argv
        assert "folder=" not in err_text


def test_the_block_size_limit_variable_raises_a_typed_block_spec_at_the_door(monkeypatch):
    """$WOODCAM_MAX_BLOCK_SIZE_MM raised the limit for block.json only: a spec typed on the
    command line (and --size-range-mm) stayed within a fixed 10000 mm, the refusal not naming the
    variable. Now each reads the one limit when it checks, and its refusal names the variable."""
    import argparse

    from woodcam.cli.block import _size_range
    from woodcam.cli.options import _read_spec
    from woodcam.errors import UsageError

    spec = "builtin:flat-sawn:20000x80x50"
    monkeypatch.delenv("WOODCAM_MAX_BLOCK_SIZE_MM", raising=False)
    with pytest.raises(UsageError, match=r"<= 10000 mm \(raise it with WOODCAM_MAX_BLOCK_SIZE_MM=N\)"):
        _read_spec(spec, "mm")
    with pytest.raises(argparse.ArgumentTypeError, match="WOODCAM_MAX_BLOCK_SIZE_MM"):
        _size_range("30,20000")
    monkeypatch.setenv("WOODCAM_MAX_BLOCK_SIZE_MM", "30000")
    assert _read_spec(spec, "mm").size_mm == (20000.0, 80.0, 50.0)
    assert _size_range("30,20000") == (30.0, 20000.0)
    from woodcam.cli.options import option_bounds

    assert option_bounds("block_size", "woodify")[1] == option_bounds("stock", "gcode")[1] == 30000.0


def test_a_face_without_a_photo_is_a_labelled_slot_in_both_crosses():
    """A block made with --partial drew its missing face as a blank, unnamed hole in 'block show'
    and 'rings show' (a dark face? a drawing fault?). The slot is now named 'back (F): no photo'."""
    from woodcam.block.render import cross_image, missing_face
    from woodcam.detect.show import rings_picture
    from woodcam.synth import cut_block, synth_block

    block = synth_block(cut_block(lambda p: np.hypot(p[:, 0], p[:, 1]) / 2.0, (40, 30, 20), "rift"),
                        (40, 30, 20), face_px=40, seed=1)
    del block.faces["back"]
    for im, zoom in ((cross_image(block, traces=False), 1), (rings_picture(block, zoom=2), 2)):
        layout = CrossLayout(block.size_mm, zoom * block.faces["front"].shape[1] / block.size_mm[0])
        r0, c0 = layout.origin["back"]
        h, w = layout.face_shape("back")
        slot = im[r0:r0 + h, c0:c0 + w]
        assert np.array_equal(slot, missing_face("back", (h, w), 24)), zoom
        assert len(np.unique(slot.reshape(-1, 3), axis=0)) > 1  # the label is drawn
