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
