"""Every input path of every command goes through one door (``woodcam.cli.options.add_input`` /
``check_inputs``): a path that is not there, or a folder where a file is read (a file where a
folder is), is a wrong command line, exit 2, one line naming the argument and the path, before
any work. They exited 1, each command's own message, some after the block was opened."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

import woodcam.cli as cli

REPO = Path(__file__).resolve().parents[1]

#: (command, argument) -> a command line whose argument ARG is the path under test; FILE is an
#: existing file (the other inputs, there), OUT an output folder.
CASES: dict[tuple[str, str], list[str]] = {
    ("bake", "PART"): ["bake", "ARG", "--block", "builtin:flat-sawn", "--out", "OUT/b.glb"],
    ("bake", "--block"): ["bake", "FILE.stl", "--block", "ARG", "--out", "OUT/b.glb"],
    ("preview", "MESH"): ["preview", "ARG", "--screenshot", "OUT/p.png"],
    ("preview", "--block"): ["preview", "FILE.glb", "--block", "ARG", "--screenshot", "OUT/p.png"],
    ("gcode", "PROGRAM"): ["gcode", "FILE", "ARG", "--tool", "flat:6", "--block", "builtin:flat-sawn",
                           "--out", "OUT/g.glb"],
    ("gcode", "--block"): ["gcode", "FILE", "--tool", "flat:6", "--block", "ARG", "--out", "OUT/g.glb"],
    ("gcode", "--tools"): ["gcode", "FILE", "--tools", "ARG", "--block", "builtin:flat-sawn", "--out", "OUT/g.glb"],
    ("gcode", "--part"): ["gcode", "FILE", "--tool", "flat:6", "--part", "ARG", "--block", "builtin:flat-sawn",
                          "--out", "OUT/g.glb"],
    ("review", "PART"): ["review", "ARG", "--out", "OUT/r.html"],
    ("review", "--block"): ["review", "FILE.glb", "--block", "ARG", "--out", "OUT/r.html"],
    ("place", "PART"): ["place", "ARG", "--block", "builtin:flat-sawn", "--out", "OUT/p"],
    ("place", "--block"): ["place", "FILE.stl", "--block", "ARG", "--out", "OUT/p"],
    ("block show", "BLOCK"): ["block", "show", "ARG", "--out", "OUT/s.png"],
    ("block from-photos", "PHOTOS_DIR"): ["block", "from-photos", "ARG", "--size-mm", "50", "--out", "OUT/fp"],
    ("rings detect", "BLOCK"): ["rings", "detect", "ARG", "--out", "OUT/rd"],
    ("rings show", "BLOCK"): ["rings", "show", "ARG", "--out", "OUT/rs.png"],
    ("log render", "LOG_FILE"): ["log", "render", "ARG", "--out", "OUT/lr"],
    ("log render", "--maps"): ["log", "render", "--maps", "ARG", "--out", "OUT/lr"],
    ("log maps", "LOG_FILE"): ["log", "maps", "ARG", "--out", "OUT/lm"],
    ("log maps", "--maps"): ["log", "maps", "--maps", "ARG", "--out", "OUT/lm"],
    ("log export", "LOG_FILE"): ["log", "export", "ARG", "--out", "OUT/le.json"],
    ("log export", "--maps"): ["log", "export", "--maps", "ARG", "--out", "OUT/le.json"],
    ("fit", "BLOCK"): ["fit", "ARG", "--out", "OUT/f.npz"],
    ("eval rings", "BLOCK"): ["eval", "rings", "builtin:rift", "ARG", "--out", "OUT/e"],
    ("eval rings", "--truth"): ["eval", "rings", "builtin:rift", "--truth", "ARG", "--out", "OUT/e"],
    ("eval appearance", "BLOCK"): ["eval", "appearance", "ARG", "--out", "OUT/ea"],
    ("train", "--spec"): ["train", "gtf", "--spec", "ARG", "--out", "OUT/t"],
    ("bench report", "RUN_DIR"): ["bench", "report", "ARG", "--out", "OUT/br"],
    ("woodify", "PART"): ["woodify", "ARG", "--years", "3", "--out", "OUT/w"],
    ("woodify", "--obstacle"): ["woodify", "FILE.stl", "--years", "3", "--obstacle", "FILE.stl", "--obstacle", "ARG",
                                "--out", "OUT/w"],
    ("woodify", "--brushes"): ["woodify", "FILE.stl", "--years", "3", "--brushes", "ARG", "--out", "OUT/w"],
    ("parquetry", "TARGET"): ["parquetry", "FILE", "ARG", "--veneer-from", "builtin:flat-sawn", "--out", "OUT/pq"],
    ("parquetry", "--config"): ["parquetry", "--config", "ARG", "--out", "OUT/pq"],
    ("parquetry", "--veneer"): ["parquetry", "FILE", "--veneer", "ARG:300", "--out", "OUT/pq"],
    ("parquetry", "--veneer-from"): ["parquetry", "FILE", "--veneer-from", "ARG", "--out", "OUT/pq"],
}


def _leaf_parsers():
    """(command, parser) of every command that runs (no sub-commands of its own)."""
    for path, _help, sp in cli._commands(cli.build_parser()):
        if not any(isinstance(a, argparse._SubParsersAction) for a in sp._actions):
            yield " ".join(path), sp


def _registered() -> dict[tuple[str, str], str]:
    """(command, argument) -> kind of every input path that goes through the door."""
    return {(command, arg.name): arg.kind for command, sp in _leaf_parsers()
            for arg in sp.get_default("_inputs") or ()}


def _looks_like_a_path(action: argparse.Action) -> bool:
    """An argument that reads a path: a positional that is no choice (``train gtf``), a Path,
    a block spec, or one whose metavar names a file or folder. Outputs have their own door."""
    if action.dest in ("out", "screenshot", "help"):
        return False
    metavar = str(action.metavar or "")
    return ((not action.option_strings and not action.choices) or action.type is Path or action.dest == "block"
            or metavar in ("DIR", "FILE", "JSON", "TOML", "MESH", "PART", "SPEC", "JOB.json") or "SCAN" in metavar)


def test_every_input_path_goes_through_the_door_and_has_a_case():
    """A command added with a path argument that skips add_input fails here, as one added with
    no case below."""
    registered = _registered()
    paths = {(command, next((f for f in a.option_strings if f.startswith("--")), a.dest.upper()))
             for command, sp in _leaf_parsers() for a in sp._actions if _looks_like_a_path(a)}
    assert paths - set(registered) == set(), "path arguments not added with options.add_input"
    assert set(registered) == set(CASES), "add a case to CASES for each input path"


def _refused_at_the_door(key, given: Path | str, tmp_path: Path, capsys, monkeypatch) -> str:
    """Run CASES[key] with ARG = ``given`` (FILE.SUFFIX an existing file of that suffix, FILE a
    .txt); assert it is refused before any work, exit 2, one line naming the argument and
    nothing written; returns the line."""
    out = tmp_path / "out"

    def existing(match: re.Match) -> str:
        path = tmp_path / "in" / f"file{match.group(1) or '.txt'}"
        path.write_text("x")
        return str(path)

    argv = [re.sub(r"FILE(\.\w+)?", existing, a.replace("ARG", str(given)).replace("OUT", str(out)))
            for a in CASES[key]]
    build = cli.build_parser

    def no_work(args):  # the door refuses the path before the command runs
        pytest.fail(f"{key} ran with {given}")

    def parser_that_does_no_work():
        parser = build()
        for _path, _help, sp in cli._commands(parser):
            if sp.get_default("func") is not None:
                sp.set_defaults(func=no_work)
        return parser

    monkeypatch.setattr(cli, "build_parser", parser_that_does_no_work)
    capsys.readouterr()
    assert cli.main(argv) == cli.EXIT_USAGE
    got = capsys.readouterr()
    command, name = key
    assert got.out == "" and got.err.count("\n") == 1 and "Traceback" not in got.err, got.err
    assert got.err.startswith(f"woodcam: error: {name} of 'woodcam {command}'"), got.err
    assert not out.exists()  # nothing written
    return got.err


@pytest.mark.parametrize("wrong", ["missing", "wrong kind"])
@pytest.mark.parametrize("key", sorted(CASES), ids=lambda k: f"{k[0]} {k[1]}")
def test_a_missing_or_wrong_kind_input_is_a_usage_error_before_any_work(key, wrong, tmp_path, capsys, monkeypatch):
    kind = _registered().get(key, "file")
    given = tmp_path / "in" / ("nope" if wrong == "missing" else "there")
    given.parent.mkdir()
    if wrong == "wrong kind" and kind == "file":  # a folder where a file is read
        given.mkdir()
    elif wrong == "wrong kind":  # a file where a folder (a block folder) is
        given.write_text("x")
    err = _refused_at_the_door(key, given, tmp_path, capsys, monkeypatch)
    said = "does not exist" if wrong == "missing" else f"is a {'folder' if kind == 'file' else 'file'}"
    assert f"{str(given)!r} {said}; it must be an existing " in err, err


def _suffixed() -> dict[tuple[str, str], tuple[str, ...]]:
    """(command, argument) -> the suffixes its reader takes, each from the reader's own list:
    every input FILE whose reader refuses a suffix (the audit: the others read any name, their
    contents decide, as a G-code program, a TOML tool table or a JSON file)."""
    from woodcam.cad.parts import SUPPORTED_SUFFIXES
    from woodcam.cli.woodify import _MESH_SUFFIXES
    from woodcam.review import PART_SUFFIXES
    from woodcam.view.scene import MESH_SUFFIXES

    woodify = (*_MESH_SUFFIXES, *(s for s in SUPPORTED_SUFFIXES if s not in _MESH_SUFFIXES))
    return {("bake", "PART"): SUPPORTED_SUFFIXES, ("place", "PART"): SUPPORTED_SUFFIXES,
            ("gcode", "--part"): SUPPORTED_SUFFIXES, ("woodify", "PART"): woodify,
            ("woodify", "--obstacle"): woodify, ("review", "PART"): PART_SUFFIXES,
            ("preview", "MESH"): MESH_SUFFIXES}


def test_every_input_file_whose_reader_takes_some_suffixes_says_which_at_the_door():
    """The door's list of each argument is its reader's, no second list."""
    registered = {(command, arg.name): arg.suffixes() for command, sp in _leaf_parsers()
                  for arg in sp.get_default("_inputs") or () if arg.suffixes}
    assert registered == _suffixed()


@pytest.mark.parametrize("key", sorted(_suffixed()), ids=lambda k: f"{k[0]} {k[1]}")
def test_an_input_file_of_a_suffix_its_command_cannot_read_is_a_usage_error_before_any_work(
        key, tmp_path, capsys, monkeypatch):
    """'woodcam bake part.dwg' exited 1 from the part loader, once the command ran (place and
    gcode --part after the block was opened, woodify after its checks; 'woodcam preview
    some.dwg' from the mesh reader, '... could not read a mesh ...'): a file the command
    cannot read by its suffix is a wrong command line. The refusal names the argument, the
    suffix and the suffixes the reader takes."""
    given = tmp_path / "in" / "there.dwg"
    given.parent.mkdir()
    given.write_text("x")
    err = _refused_at_the_door(key, given, tmp_path, capsys, monkeypatch)
    assert f"{str(given)!r} has suffix '.dwg', which it cannot read; it must end in " \
           f"{', '.join(_suffixed()[key])}; " in err, err


@pytest.mark.parametrize("key", sorted(k for k, kind in _registered().items() if kind == "block"),
                         ids=lambda k: f"{k[0]} {k[1]}")
@pytest.mark.parametrize("spec, said", [
    ("builtin:knoty", "unknown built-in block 'knoty'; choose one of: flat-sawn, quarter-sawn, rift, "
                      "pith-inside, fast-grown, knotty; did you mean 'builtin:knotty'? ('woodcam blocks' lists them)"),
    ("builtin:oak-burl", "unknown built-in block 'oak-burl'; choose one of: "),
])
def test_a_block_spec_of_no_path_that_names_no_block_is_a_usage_error_before_any_work(
        key, spec, said, tmp_path, capsys, monkeypatch):
    """'--block builtin:knoty' (and a 'log:' spec without its knot) passed the door, which checks
    paths only, and exited 1 when the block was opened, after the part was loaded or the run
    begun, with no near name: a wrong command line (exit 2), with the built-in block meant."""
    (tmp_path / "in").mkdir()
    err = _refused_at_the_door(key, spec, tmp_path, capsys, monkeypatch)
    assert f"(block spec {spec!r}): {said}" in err, err


def test_a_malformed_block_spec_of_no_path_is_a_usage_error_where_no_units_read_it(tmp_path, capsys, monkeypatch):
    """A command without --units had no door read its spec ('fit log:gran1' exited 1 when the
    block was opened); those with --units read it in lengths_to_mm (exit 2 already)."""
    (tmp_path / "in").mkdir()
    err = _refused_at_the_door(("fit", "BLOCK"), "log:gran1", tmp_path, capsys, monkeypatch)
    assert "(block spec 'log:gran1'): a log block must read 'log:LOG@KNOT' or 'log:LOG@KNOT:WxDxH'" in err, err


#: The block arguments of the commands that read a block as it is (no turn, no resize).
_READ_AS_IS = {("fit", "BLOCK"), ("eval rings", "BLOCK"), ("eval appearance", "BLOCK"), ("block show", "BLOCK")}


def test_the_commands_that_read_a_block_as_it_is_say_so_at_the_door():
    """Every block argument is either carved from (a turn, a resize taken) or read as it is."""
    as_is = {(command, arg.name) for command, sp in _leaf_parsers()
             for arg in sp.get_default("_inputs") or () if arg.as_is}
    assert as_is == _READ_AS_IS


@pytest.mark.parametrize("key", sorted(_READ_AS_IS), ids=lambda k: f"{k[0]} {k[1]}")
@pytest.mark.parametrize("spec, said", [
    ("builtin:flat-sawn~z90", "a turn ('~z90') is for the commands that carve a part from the block (bake, gcode, "
                              "place, preview, review and parquetry's --veneer-from); this one reads the block as "
                              "it is: give 'builtin:flat-sawn'"),
    ("builtin:knotty[40x30x20]", "a resize ('[40x30x20]') is for the commands that carve a part"),
    ("{in}/blk~x90[10x10x10]", "a turn and a resize ('~x90[10x10x10]') is for the commands"),
])
def test_a_turn_or_resize_on_a_block_read_as_it_is_is_a_usage_error_before_any_work(
        key, spec, said, tmp_path, capsys, monkeypatch):
    """'woodcam fit builtin:flat-sawn~z90' (eval, block show) exited 1 when the block was opened
    (the stock's words, after the run began): a turn or resize such a command cannot take is a
    wrong command line, exit 2 at the door, in the same words."""
    (tmp_path / "in").mkdir()
    spec = spec.format(**{"in": tmp_path / "in"})
    err = _refused_at_the_door(key, spec, tmp_path, capsys, monkeypatch)
    assert f"(block spec {spec!r}): {said}" in err, err


@pytest.mark.parametrize("key", sorted(k for k, kind in _registered().items() if kind == "block"),
                         ids=lambda k: f"{k[0]} {k[1]}")
def test_a_woodify_spec_naming_the_folder_of_a_field_offers_the_field_file(key, tmp_path, capsys, monkeypatch):
    """'--block woodify:DIR' (woodcam woodify's --out folder) said only "give the file itself, not
    the folder it is in": the door names the file woodify wrote there, as the spec to give; a
    folder without one keeps the general words."""
    grown = tmp_path / "in" / "grown"
    grown.mkdir(parents=True)
    err = _refused_at_the_door(key, f"woodify:{grown}", tmp_path, capsys, monkeypatch)
    assert err.rstrip().endswith("give the file itself, not the folder it is in"), err
    (grown / "field.npz").write_bytes(b"")  # what woodcam woodify writes (_specs.WOODIFY_FIELD_FILE)
    err = _refused_at_the_door(key, f"woodify:{grown}", tmp_path, capsys, monkeypatch)
    assert f"{str(grown)!r} is a folder; it must be an existing FILE" in err, err
    assert err.rstrip().endswith(f"did you mean 'woodify:{grown / 'field.npz'}'?"), err
