"""``--size-mm``: one option, one parser, one help in every command that takes a block size.

It was a Mokume cube's side (one number) in fit, eval rings, eval appearance, block show,
rings detect and rings show, and W x D x H in block from-photos: ``50x40x30`` copied from
one to another was refused, with two different rules said.
"""

from __future__ import annotations

import argparse

import numpy as np
import pytest
from PIL import Image

from woodcam.cli import EXIT_ERROR, EXIT_USAGE, build_parser, main

#: Every command with --size-mm, its other arguments (SRC: a folder, OUT: an output).
COMMANDS = {
    "fit": ["fit", "SRC", "--out", "OUT/f.npz"],
    "eval rings": ["eval", "rings", "SRC", "--out", "OUT/e"],
    "eval appearance": ["eval", "appearance", "SRC", "--out", "OUT/a"],
    "block show": ["block", "show", "SRC", "--out", "OUT/s.png"],
    "rings detect": ["rings", "detect", "SRC", "--out", "OUT/d"],
    "rings show": ["rings", "show", "SRC", "--out", "OUT/r.png"],
    "block from-photos": ["block", "from-photos", "SRC", "--out", "OUT/b"],
}


def _argv(name, src, out, size):
    return [a.replace("SRC", str(src)).replace("OUT", str(out)) for a in COMMANDS[name]] + [f"--size-mm={size}"]


def _size_action(parser, words):
    for w in words:
        parser = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices[w]
    return next(a for a in parser._actions if a.dest == "size_mm")


def test_every_size_mm_option_is_the_one_option():
    """Every command's --size-mm has the one help (units, frame, both spellings) and metavar."""
    from woodcam.cli.options import SIZE_MM_HELP

    parser = build_parser()
    for name in COMMANDS:
        a = _size_action(parser, name.split())
        assert a.help.startswith(SIZE_MM_HELP) and a.metavar == "SIZE", (name, a.help)
        assert a.required == (name == "block from-photos"), name
        assert "default 50" in a.help or a.required, (name, a.help)


@pytest.mark.parametrize("name", list(COMMANDS))
@pytest.mark.parametrize("text, size", [("50", (50.0, 50.0, 50.0)), ("50x40x30", (50.0, 40.0, 30.0)),
                                        ("50x50x50", (50.0, 50.0, 50.0)), ("12.5,20,30", (12.5, 20.0, 30.0))])
def test_size_mm_takes_a_cube_side_or_w_x_d_x_h_in_every_command(name, text, size):
    args = build_parser().parse_args(_argv(name, "src", "out", text))
    assert args.size_mm == size


@pytest.mark.parametrize("name", list(COMMANDS))
@pytest.mark.parametrize("text", ["50x40", "abc", "0", "-inf", "1e9", "50x0x3", "2in"])
def test_a_wrong_size_mm_is_one_line_naming_the_value(name, text, tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:  # argparse's usage error
        main(_argv(name, tmp_path / "src", tmp_path / "out", text))
    out, err = capsys.readouterr()
    assert exc.value.code == EXIT_USAGE and out == "" and err.count("\n") == 1, err
    assert ("--size-mm takes a block size in mm, one number (a cube's side, e.g. 50) or W x D x H (e.g. 50x40x30), "
            f"each in (0, 10000] (raise it with WOODCAM_MAX_BLOCK_SIZE_MM=N); got {text!r}") in err, err
    assert not (tmp_path / "out").exists()


@pytest.fixture
def mokume(tmp_path):
    """A tiny Mokume sample folder: six square face photos A_col.png ... F_col.png."""
    d = tmp_path / "H00"
    d.mkdir()
    rng = np.random.default_rng(0)
    for letter in "ABCDEF":
        Image.fromarray(rng.integers(0, 255, (16, 16, 3), dtype=np.uint8)).save(d / f"{letter}_col.png")
    return d


@pytest.mark.parametrize("name", [n for n in COMMANDS if n != "block from-photos"])
def test_a_mokume_folder_refuses_a_size_that_is_no_cube(name, mokume, tmp_path, capsys):
    """A Mokume sample is a cube photographed square on every face: 50x40x30 gave faces of
    non-square pixels without a word; one line says so and gives the cube's side to type."""
    rc = main(_argv(name, mokume, tmp_path / "out", "50x40x30"))
    out, err = capsys.readouterr()
    assert rc == EXIT_ERROR and err.count("\n") == 1, err
    assert err == (f"woodcam: error: size_mm (--size-mm) 50x40x30 mm is no cube, and a Mokume sample folder "
                   f"({str(mokume)!r}) is a cube, its faces square photos: give the cube's side, one number, e.g. "
                   "--size-mm 50\n")
    assert not any((tmp_path / "out").rglob("*.*"))  # nothing written (eval appearance makes its folder first)


def test_a_mokume_folder_reads_a_cube_typed_either_way(mokume):
    from woodcam.block.io import read_block_folder

    for text in ("40", "40x40x40"):
        args = build_parser().parse_args(_argv("rings show", mokume, "out", text))
        assert read_block_folder(args.block, args.size_mm).size_mm == (40.0,) * 3


#: The commands that carve from a block (or show one carved) and size a Mokume folder as fit does.
CARVING = {
    "bake": ["bake", "part.stl", "--block", "SRC", "--out", "OUT/p.glb"],
    "gcode": ["gcode", "p.nc", "--tool", "flat:6", "--block", "SRC", "--out", "OUT/p.glb"],
    "place": ["place", "part.stl", "--block", "SRC", "--out", "OUT/pl"],
    "preview": ["preview", "OUT/p.glb", "--block", "SRC"],
}


@pytest.mark.parametrize("name", list(CARVING))
def test_the_carving_commands_take_the_one_size_mm(name):
    """bake, gcode, place and preview read a Mokume folder as "a 50 mm cube" and could not size
    it, while fit, eval, rings and block took --size-mm."""
    from woodcam.cli.options import SIZE_MM_HELP

    a = _size_action(build_parser(), [name])
    assert a.help.startswith(SIZE_MM_HELP) and a.metavar == "SIZE" and not a.required, a.help
    argv = [w.replace("SRC", "src").replace("OUT", "out") for w in CARVING[name]]
    assert build_parser().parse_args([*argv, "--size-mm", "40"]).size_mm == (40.0,) * 3


@pytest.fixture
def cn03(shared_data, monkeypatch, tmp_path):
    """The Mokume sample CN03, its field a built-in block's (the real fit takes ~10-30 s a size,
    and what is tested here is which size the sample is read at, not the fit)."""
    folder = shared_data / "mokume" / "CN03"
    if not folder.is_dir():
        pytest.skip(f"Mokume sample CN03 not found at {folder}")
    from woodcam.fields.builtin import builtin_block

    field = builtin_block("flat-sawn").field
    sizes = []

    def fitted(block, folder=None, *args, **kwargs):
        sizes.append(tuple(block.size_mm))
        return field

    monkeypatch.setattr("woodcam.stock.fitted_field", fitted)
    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    return folder, sizes


def test_a_mokume_folder_is_baked_and_previewed_at_its_size_mm(cn03, tmp_path, capsys):
    """'bake part.stl --block mokume/CN03' baked a 50 mm cube whatever the sample's size; with
    --size-mm 40 it is a 40 mm cube, the GLB records the sample's size, and preview/review of
    the GLB (its recorded block, or the same folder as --block) reopen the sample at 40 mm,
    not 50 (other wood). A turn keeps the sample's size."""
    import trimesh

    from woodcam.cli.options import stock_of_glb
    from woodcam.export import read_glb_metadata

    folder, sizes = cn03
    box = trimesh.creation.box((10, 10, 10))
    box.apply_translation((20, 20, 20))
    box.export(tmp_path / "part.stl")
    glb = tmp_path / "p.glb"
    assert main(["bake", str(tmp_path / "part.stl"), "--block", f"{folder}~z90", "--size-mm", "40",
                 "--texels-per-mm", "0.5", "--no-obj", "--out", str(glb)]) == 0
    capsys.readouterr()
    meta = read_glb_metadata(glb)
    assert meta["size_mm"] == [40.0] * 3 and meta["sample_size_mm"] == [40.0] * 3, meta
    assert sizes == [(40.0,) * 3]
    assert stock_of_glb(glb).size_mm == (40.0,) * 3  # the recorded block
    assert stock_of_glb(glb, f"{folder}~z90").size_mm == (40.0,) * 3  # the same block, as --block
    assert sizes[1:] == [(40.0,) * 3] * 2
    # another size asked for is another block: said, as another folder is
    with pytest.warns(Warning, match=r"is not the block p\.glb was baked from"):
        assert stock_of_glb(glb, f"{folder}~z90", size_mm=(30.0,) * 3).size_mm == (30.0,) * 3


def test_a_size_mm_a_command_cannot_use_is_said(cn03, tmp_path, monkeypatch, capsys):
    """--size-mm with a built-in block is ignored with a warning (one home: fit's words); a
    Mokume folder refuses a size that is no cube; place and gcode pass it to the stock."""
    from woodcam import stock as stock_module
    from woodcam.errors import WoodcamError

    folder, _ = cn03
    with pytest.raises(WoodcamError, match="sizes a Mokume sample folder only; block spec 'builtin:flat-sawn'"):
        stock_module.open_stock("builtin:flat-sawn", size_mm=40)
    with pytest.raises(WoodcamError, match="50x40x30 mm is no cube"):
        stock_module.open_stock(str(folder), size_mm=(50, 40, 30))
    seen = []

    def fake_open_stock(spec, **kwargs):
        seen.append((spec, kwargs.get("size_mm")))
        raise WoodcamError("stop here")

    monkeypatch.setattr(stock_module, "open_stock", fake_open_stock)
    import trimesh

    trimesh.creation.box((10, 10, 10)).export(tmp_path / "part.stl")
    assert main(["place", str(tmp_path / "part.stl"), "--block", str(folder), "--size-mm", "40",
                 "--out", str(tmp_path / "pl")]) == EXIT_ERROR
    assert main(["bake", str(tmp_path / "part.stl"), "--block", "builtin:flat-sawn", "--size-mm", "40",
                 "--out", str(tmp_path / "p.glb")]) == EXIT_ERROR
    err = capsys.readouterr().err
    assert seen == [(str(folder), (40.0,) * 3), ("builtin:flat-sawn", None)], seen
    assert ("--size-mm 40 sizes Mokume sample folders only; 'builtin:flat-sawn' is no folder and keeps its own "
            "size: ignored") in err, err


def test_library_open_block_refuses_a_size_mm_as_open_stock_does():
    """woodcam.stock.open_block('builtin:flat-sawn', size_mm=40) returned the 50 mm block with
    size_mm dropped without a word (open_stock refused it; the CLI warns via folder_size)."""
    from woodcam.errors import WoodcamError
    from woodcam.stock import open_block

    with pytest.raises(WoodcamError, match=r"size_mm \(--size-mm\) sizes a Mokume sample folder only; "
                                           r"block spec 'builtin:flat-sawn' is a builtin block"):
        open_block("builtin:flat-sawn", size_mm=40, face_px=16)
