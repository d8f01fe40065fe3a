"""The one ``--out`` rule (woodcam.cli.options.OUT_RULE), checked for EVERY command: a path with a
file suffix is a file, anything else a folder; the wrong kind or suffix is refused before any
work with one line and exit 2."""

from __future__ import annotations

import argparse

import pytest

from woodcam.cli import EXIT_USAGE, build_parser, main
from woodcam.cli.options import FILE_SUFFIXES, OUT_RULE, block_size_mm, check_out
from woodcam.errors import UsageError


def _commands_with_out():
    """(command path, parser) for every (sub-)command that has an --out option."""
    stack = [([], build_parser())]
    while stack:
        path, p = stack.pop()
        for action in p._actions:
            if isinstance(action, argparse._SubParsersAction):
                stack += [([*path, name], sp) for name, sp in action.choices.items()
                          if name not in ("eval-appearance",)]
            elif "--out" in action.option_strings:
                yield path, p


COMMANDS = sorted(_commands_with_out(), key=lambda c: c[0])


def _argv(path, p, out):
    """A command line for ``path`` with every required argument filled by a dummy value (the
    --out rule runs before anything reads them)."""
    argv = list(path)
    for a in p._actions:
        if a.option_strings and (not a.required or "--out" in a.option_strings):
            continue
        if isinstance(a, (argparse._HelpAction, argparse._SubParsersAction)):
            continue
        value = (a.choices[0] if a.choices else "1" if a.type in (int, float, block_size_mm)
                 else "does-not-exist")
        argv += ([a.option_strings[-1]] if a.option_strings else []) + [str(value)]
    return argv + ["--out", str(out)]


def test_every_command_with_out_declares_its_kind():
    assert len(COMMANDS) >= 20, [c[0] for c in COMMANDS]
    for path, p in COMMANDS:
        suffixes = p.get_default("_out_suffixes")
        assert suffixes is not None, f"woodcam {' '.join(path)}: --out must use add_out_option"
        assert set(suffixes) <= FILE_SUFFIXES
        out = next(a for a in p._actions if "--out" in a.option_strings)
        assert ("FILE ending in" if suffixes else "FOLDER") in out.help, (path, out.help)


@pytest.mark.parametrize("path,p", COMMANDS, ids=[" ".join(c[0]) for c in COMMANDS])
def test_wrong_kind_is_refused_before_work(path, p, tmp_path, capsys):
    suffixes = p.get_default("_out_suffixes")
    wrong = tmp_path / ("a_folder" if suffixes else "result.png")
    capsys.readouterr()
    assert main(_argv(path, p, wrong)) == EXIT_USAGE
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"woodcam: error: --out of 'woodcam {' '.join(path)}'"), err
    assert ("is a FILE" if suffixes else "is a FOLDER") in err[0]
    assert not wrong.exists() and list(tmp_path.iterdir()) == []  # nothing was done
    right = tmp_path / ("x" + suffixes[0] if suffixes else "x_folder")
    check_out(build_parser().parse_args(_argv(path, p, right)))  # the right kind passes


def test_file_command_refuses_wrong_suffix_and_existing_folder(tmp_path, capsys):
    assert main(["bake", "x.py", "--block", "builtin:flat-sawn", "--out",
                 str(tmp_path / "bowl.obj")]) == EXIT_USAGE
    assert "must end in .glb" in capsys.readouterr().err
    folder = tmp_path / "bowl.glb"
    folder.mkdir()
    with pytest.raises(UsageError, match="is a FILE ending in .glb; got .*a folder"):
        check_out(build_parser().parse_args(["bake", "x.py", "--block", "b", "--out", str(folder)]))


def test_a_file_out_whose_suffix_slipped_is_offered_the_right_suffix(tmp_path, capsys):
    """'fit --out f.npy' and 'review --out page.htm' were told they named a folder, with
    'f.npy/part.npz' as the fix; a name with a suffix-like end is offered its name with the
    command's suffix first, the folder reading second. A name without one stays a folder."""
    out = tmp_path / "f.npy"
    assert main(["fit", "builtin:rift", "--out", str(out)]) == EXIT_USAGE
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"woodcam: error: --out of 'woodcam fit' must end in .npz; got {str(out)!r}, whose suffix "
                   f"'.npy' is none of them; give e.g. {str(tmp_path / 'f.npz')!r} (or "
                   f"{str(out / 'part.npz')!r} to write into a folder {str(out)!r})"], err
    assert list(tmp_path.iterdir()) == []
    for name in ("page.htm", "page.HTM"):
        with pytest.raises(UsageError, match=r"must end in .html; got .*, whose suffix '\.(htm|HTM)' .* e\.g\. '.*page\.html'"):
            check_out(build_parser().parse_args(["review", "p.glb", "--out", str(tmp_path / name)]))
    for name in ("run.2", "a_folder"):  # no suffix a user types for a file: a folder, as before
        with pytest.raises(UsageError, match="is a FILE ending in .html; got .*a folder"):
            check_out(build_parser().parse_args(["review", "p.glb", "--out", str(tmp_path / name)]))


def test_a_file_out_named_without_its_suffix_is_offered_the_file_too(tmp_path, capsys):
    """'bake bowl.py --out tray' (no folder 'tray') was told 'tray' is a folder and offered only
    'tray/part.glb'; the file 'tray.glb' is as likely meant, and offered too. An existing
    folder is said as before."""
    out = tmp_path / "tray"
    assert main(["bake", "x.py", "--block", "builtin:flat-sawn", "--out", str(out)]) == EXIT_USAGE
    assert capsys.readouterr().err == (f"woodcam: error: --out of 'woodcam bake' is a FILE ending in .glb; got "
                                       f"{str(out)!r}, a folder name; give a file name such as "
                                       f"{str(out / 'part.glb')!r}, or {str(tmp_path / 'tray.glb')!r}\n")
    out.mkdir()
    assert main(["bake", "x.py", "--block", "builtin:flat-sawn", "--out", str(out)]) == EXIT_USAGE
    assert capsys.readouterr().err.endswith(f"got {str(out)!r}, a folder; give a file name such as "
                                            f"{str(out / 'part.glb')!r}\n")


@pytest.mark.parametrize("argv", [["review", "p.glb"], ["log", "export", "--real"]])
def test_a_file_out_naming_an_existing_file_without_the_suffix_is_offered_the_suffix(argv, tmp_path):
    """'woodcam review p.glb --out notes' with a file 'notes' there: "got 'notes', a folder; give a
    file name such as 'notes/part.html'", a path that cannot be made under the file (sweep h4)."""
    f = tmp_path / "notes"
    f.write_text("")
    suffix = ".html" if argv[0] == "review" else ".json"
    with pytest.raises(UsageError) as err:
        check_out(build_parser().parse_args([*argv, "--out", str(f)]))
    assert str(err.value).endswith(f"is a FILE ending in {suffix}; got {str(f)!r}, an existing file without that "
                                   f"suffix; give e.g. {str(f) + suffix!r}"), err.value


def test_folder_command_refuses_an_existing_file(tmp_path):
    f = tmp_path / "place_here"
    f.write_text("")
    with pytest.raises(UsageError, match="is a FOLDER .*an existing file"):
        check_out(build_parser().parse_args(["place", "p.py", "--block", "b", "--out", str(f)]))


def test_rule_is_in_the_main_help(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert " ".join(OUT_RULE.split()) in text


FOLDER_COMMANDS = [c for c in COMMANDS if not c[1].get_default("_out_suffixes")]


@pytest.mark.parametrize("path,p", FOLDER_COMMANDS, ids=[" ".join(c[0]) for c in FOLDER_COMMANDS])
def test_a_folder_that_cannot_be_made_is_refused_before_work(path, p, tmp_path, capsys):
    """``train rings --out`` under a file trained for minutes, then failed with a traceback."""
    blocker = tmp_path / "a_file"
    blocker.write_text("")
    capsys.readouterr()
    assert main(_argv(path, p, blocker / "sub")) == EXIT_USAGE
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"cannot make the folder '{blocker / 'sub'}'" in err[0] and "is a file" in err[0], err


@pytest.mark.parametrize("path,p", FOLDER_COMMANDS, ids=[" ".join(c[0]) for c in FOLDER_COMMANDS])
def test_an_existing_folder_that_cannot_be_written_is_refused_in_bakes_words(path, p, capsys):
    """Sweep h8 item 3: ``rings detect BLOCK --out EXISTING_READ_ONLY_FOLDER`` said 'cannot make
    the folder', of a folder that exists; it is not writable, said as a FILE --out's folder is
    (test_a_file_in_a_folder_that_cannot_be_written_is_refused_before_work). It exited 1 where
    a folder that cannot be made exited 2, the same fix (another --out): a usage error, exit 2."""
    capsys.readouterr()
    assert main(_argv(path, p, "/proc/self")) == EXIT_USAGE  # read-only even for root
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"woodcam: error: --out of 'woodcam {' '.join(path)}': the folder '/proc/self' is not "
                   "writable (No such file or directory); choose an output folder you can write to"], err


@pytest.mark.parametrize("path,p", COMMANDS, ids=[" ".join(c[0]) for c in COMMANDS])
def test_a_folder_to_make_under_one_that_cannot_be_written_is_refused_before_work(path, p, capsys):
    """'woodcam review part.glb --out /proc/sub/x.html' did the work, then exited 1 ('review
    --out: cannot create the folder ...'); 'block synth --out /proc/sub' and 'fit --out
    /proc/sub/f.npz' said 'No such file or directory (/proc/sub)', exit 1: the door asked
    os.access() of '/proc', which says yes to root. A real probe: exit 2, one line naming --out,
    the folder, the reason and a fix, as every other unwritable --out."""
    suffixes = p.get_default("_out_suffixes")
    out = "/proc/sub/k" + suffixes[0] if suffixes else "/proc/sub/k"  # /proc: read-only even for root
    capsys.readouterr()
    assert main(_argv(path, p, out)) == EXIT_USAGE
    err = capsys.readouterr().err.strip().splitlines()
    folder = "/proc/sub" if suffixes else "/proc/sub/k"
    assert err == [f"woodcam: error: --out of 'woodcam {' '.join(path)}': cannot make the folder '{folder}': "
                   "'/proc' is not writable (No such file or directory); choose an output folder you can "
                   "write to"], err


def test_a_refusal_by_the_system_is_one_line_not_a_traceback(monkeypatch, capsys):
    import errno

    import woodcam.cli.options as options

    def full(args):
        raise OSError(errno.ENOSPC, "No space left on device", "out/bowl.glb")

    monkeypatch.setattr(options, "check_numbers", full)
    assert main(["bake", "x.py", "--block", "builtin:flat-sawn", "--out", "out/bowl.glb"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["woodcam: error: No space left on device (out/bowl.glb); check the path, its permissions "
                   "and the free space"]


FILE_COMMANDS = [c for c in COMMANDS if c[1].get_default("_out_suffixes")]


@pytest.mark.parametrize("path,p", FILE_COMMANDS, ids=[" ".join(c[0]) for c in FILE_COMMANDS])
def test_a_file_in_a_folder_that_cannot_be_written_is_refused_before_work(path, p, capsys):
    """Sweep h5 item 8: ``block show --out /proc/k.png`` did the work, then failed naming its
    temporary file ('/proc/.k.png.13252-6nk58k2c.tmp.png'). Exit 2, as a folder that cannot be
    made (it was 1)."""
    out = "/proc/self/k" + p.get_default("_out_suffixes")[0]  # read-only even for root
    capsys.readouterr()
    assert main(_argv(path, p, out)) == EXIT_USAGE
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"woodcam: error: --out of 'woodcam {' '.join(path)}': the folder '/proc/self' is not "
                   "writable (No such file or directory); choose an output folder you can write to"], err


@pytest.mark.parametrize("path,p", FILE_COMMANDS, ids=[" ".join(c[0]) for c in FILE_COMMANDS])
def test_a_file_under_a_file_is_refused_before_work(path, p, tmp_path, capsys):
    """``block show --out afile/sub/x.png`` drew the block, then failed with 'Not a directory
    (afile/sub)', naming no option; ``fit`` fitted first. The missing folder is made later, so
    its nearest existing ancestor must be a folder."""
    blocker = tmp_path / "a_file"
    blocker.write_text("")
    out = blocker / "sub" / ("x" + p.get_default("_out_suffixes")[0])
    capsys.readouterr()
    assert main(_argv(path, p, out)) == EXIT_USAGE
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"woodcam: error: --out of 'woodcam {' '.join(path)}': cannot make the folder "
                   f"'{out.parent}': '{blocker}' is a file; choose an output folder you can write to"], err


SCREENSHOT_COMMANDS = {"bake": ["bake", "x.py", "--block", "builtin:flat-sawn", "--out", "OUT/b.glb"],
                       "gcode": ["gcode", "x.nc", "--block", "builtin:flat-sawn", "--out", "OUT/g.glb"],
                       "preview": ["preview", "x.glb"]}


@pytest.mark.parametrize("command", sorted(SCREENSHOT_COMMANDS))
@pytest.mark.parametrize("shot,says", [("view.jpg", "not a .png name"), ("a_folder", "an existing folder"),
                                       ("a_file/sub/v.png", "is a file")])
def test_a_named_screenshot_that_cannot_be_written_is_refused_before_work(command, shot, says, tmp_path, capsys):
    """'--screenshot x.jpg' was refused after the bake (or, in preview, after the block was read)
    with exit 1 and, in preview, without the option's dashes ('screenshot must be a .png path')."""
    (tmp_path / "a_folder").mkdir()
    (tmp_path / "a_file").write_text("")
    argv = [a.replace("OUT", str(tmp_path)) for a in SCREENSHOT_COMMANDS[command]]
    capsys.readouterr()
    assert main([*argv, "--screenshot", str(tmp_path / shot)]) == EXIT_USAGE
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"woodcam: error: --screenshot of 'woodcam {command}'"), err
    assert says in err[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_file", "a_folder"]  # nothing was done


def test_previews_name_less_screenshot_beside_mesh_is_checked_before_work(tmp_path, capsys, monkeypatch):
    """preview MESH --screenshot writes MESH_view.png; when that is a folder it was refused only
    after the block was read (exit 1, 'screenshot: ...'): now at the door, as a named one."""
    import woodcam.cli.options as options

    mesh = tmp_path / "part.glb"
    mesh.write_bytes(b"glTF")
    (tmp_path / "part_view.png").mkdir()
    monkeypatch.setattr(options, "stock_of_glb", lambda *a, **k: pytest.fail("the block was read"))
    capsys.readouterr()
    assert main(["preview", str(mesh), "--screenshot"]) == EXIT_USAGE
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"woodcam: error: --screenshot of 'woodcam preview' is a FILE ending in .png; got "
                   f"{str(tmp_path / 'part_view.png')!r}, an existing folder (--screenshot without a "
                   f"name writes MESH_view.png); give e.g. {str(tmp_path / 'part_view.png' / 'view.png')!r}"]


@pytest.mark.parametrize("argv, beside", [
    (["gcode", "REPO/toolpaths/drilling.nc", "--block", "builtin:flat-sawn", "--tool", "flat:6", "--part",
      "REPO/cad_examples/bowl.py", "--out", "OUT/g.glb"], "g_deviation.png"),
    (["place", "REPO/cad_examples/bowl.py", "--block", "builtin:flat-sawn", "--out", "OUT"], "placements.json"),
    (["bake", "REPO/cad_examples/bowl.py", "--block", "builtin:flat-sawn", "--out", "OUT/b.glb"], "b.mtl"),
])
def test_a_file_written_beside_out_that_cannot_be_written_is_a_usage_error(argv, beside, tmp_path, capsys):
    """The files a command writes beside its --out (gcode's deviation PNG, place's
    placements.json, bake's OBJ set) are checked before any work; one that is a folder exited 1
    where --out itself exited 2 for the same fix (another --out). The inputs exist: a missing
    one is refused before (the input door, tests/test_cli_inputs.py)."""
    from pathlib import Path

    repo = str(Path(__file__).resolve().parents[1])
    (tmp_path / beside).mkdir()
    capsys.readouterr()
    assert main([a.replace("OUT", str(tmp_path)).replace("REPO", repo) for a in argv]) == EXIT_USAGE
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("woodcam: error: --out") and "is an existing folder" in err[0], err
    assert sorted(p.name for p in tmp_path.iterdir()) == [beside]  # nothing was done


@pytest.mark.parametrize("path,p", COMMANDS, ids=[" ".join(c[0]) for c in COMMANDS])
def test_an_empty_out_is_refused_not_taken_as_the_current_folder(path, p, tmp_path, monkeypatch, capsys):
    """Path('') is '.': 'woodcam place PART --block B --out ""' wrote placements.png and
    placements.json into the current folder with exit 0, and a FILE --out said "got '.', a
    folder". An empty --out is now a wrong command line (exit 2), one line, nothing written."""
    monkeypatch.chdir(tmp_path)
    argv = _argv(path, p, "X")
    argv[-1] = ""
    with pytest.raises(SystemExit) as exc:
        main(argv)
    err = capsys.readouterr().err
    assert exc.value.code == EXIT_USAGE and err.count("\n") == 1, err
    assert "argument --out: got an empty value ''; give the output " in err, err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("argv,name,what", [
    (["place", "", "--block", "builtin:rift", "--out", "pl"], "part", "a FILE path"),
    (["fit", "", "--out", "f.npz"], "block", "a block spec"),
    (["bake", "p.stl", "--block", "", "--out", "t.glb"], "--block", "a block spec"),
    (["preview", "p.glb", "--screenshot", ""], "--screenshot", "a .png file name"),
    (["rings", "detect", " ", "--out", "r"], "block", "a FOLDER path"),
])
def test_an_empty_input_path_or_spec_is_refused(argv, name, what, tmp_path, monkeypatch, capsys):
    """'fit ""' read the current folder as a block ('folder '.' is not a block', exit 1), 'bake
    --block ""' failed in the library in the API's words ('spec must be a block spec (str) ...
    e.g. open_stock(...)', exit 1): an empty path or spec is a wrong command line."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exc:
        main(argv)
    err = capsys.readouterr().err
    assert exc.value.code == EXIT_USAGE and err.count("\n") == 1, err
    assert f"argument {name}: got an empty value " in err and f"; give {what}" in err, err


@pytest.mark.parametrize("command", ["eval appearance", "place"])
def test_a_failed_run_leaves_no_empty_folder_it_made(tmp_path, capsys, command):
    """'eval appearance BLOCK --out new/dir' made new/dir before reading its block, and 'place'
    made its --out before loading its part: a failed read (an empty folder as the block, a
    damaged STL) exited 1 and left the folders there, empty. A folder that was there before
    stays, and so does one the run wrote a file into."""
    empty = tmp_path / "emptyblock"
    empty.mkdir()
    (tmp_path / "bad.stl").write_text("solid nothing here\n")
    out = tmp_path / "new" / "deep"
    argv = {"eval appearance": ["eval", "appearance", str(empty), "--out", str(out)],
            "place": ["place", str(tmp_path / "bad.stl"), "--block", "builtin:flat-sawn", "--out", str(out)]}[command]
    assert main(argv) == 1
    assert "woodcam: error:" in capsys.readouterr().err
    assert not (tmp_path / "new").exists()
    (tmp_path / "new").mkdir()  # there before the run: kept
    assert main(argv) == 1 and (tmp_path / "new").is_dir() and not out.exists()


def test_the_folders_a_failed_run_made_are_removed_only_where_empty(tmp_path):
    """remove_empty_folders takes back the empty folders under those absent_output_folders
    found absent, deepest first; a folder holding a file (written before the failure) stays."""
    from woodcam.cli.options import absent_output_folders, remove_empty_folders

    args = argparse.Namespace(out=tmp_path / "a" / "b" / "run.glb", _out_suffixes=(".glb",),
                              screenshot=str(tmp_path / "shots" / "v.png"))
    tops = absent_output_folders(args)
    assert tops == [tmp_path / "a", tmp_path / "shots"]
    (tmp_path / "a" / "b" / "c").mkdir(parents=True)
    (tmp_path / "shots" / "x").mkdir(parents=True)
    (tmp_path / "shots" / "x" / "kept.txt").write_text("a file the run wrote")
    remove_empty_folders(tops)
    assert not (tmp_path / "a").exists()
    assert (tmp_path / "shots" / "x" / "kept.txt").is_file()
