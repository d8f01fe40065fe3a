"""Every numeric CLI option is finite and in range; output paths fail before any work."""

from __future__ import annotations

import time

import pytest

from woodcam.cli import EXIT_ERROR, EXIT_USAGE, main

BAKE = ["bake", "cad_examples/bowl.py", "--block", "builtin:flat-sawn"]
GCODE = ["gcode", "toolpaths/drilling.nc", "--block", "builtin:flat-sawn", "--out", "OUT/g.glb", "--no-obj",
         "--cell-size", "0.5"]


# each case with the exit status it gives: 2 (EXIT_USAGE) for a wrong command line (the --out
# rule, a number out of range, a malformed value quoted: "--tool 'flat:abc': ...", options that
# contradict each other, an input file that is not there), 1 (EXIT_ERROR) for failed work. The
# inputs named exist where a case is about another option: a missing one is refused first
# (woodcam.cli.options.check_inputs, tests/test_cli_inputs.py)
@pytest.mark.parametrize("argv, code, match", [
    (["gcode", "toolpaths/vcarve_text.nc", "--tool", "vbit:60:12", "--block", "builtin:flat-sawn",
      "--out", "OUT/x.glb", "--resolution", "1e-9"], EXIT_USAGE, r"--cell-size must be in \[0.005, 10\] mm; got 1e-09 mm"),
    ([*BAKE, "--out", "OUT/x.glb", "--tolerance", "0"], EXIT_USAGE, r"--tolerance must be in \(0, 10\] mm; got 0.0 mm"),
    # sweep h2: a non-finite number was told neither the range nor the help ("got nan" and no fix)
    ([*BAKE, "--out", "OUT/x.glb", "--tolerance", "nan"], EXIT_USAGE,
     r"--tolerance must be a finite number in \(0, 10\] mm; got nan mm; see 'woodcam bake --help' for its meaning and default$"),
    ([*BAKE, "--out", "OUT/x.glb", "--texels-per-mm", "inf"], EXIT_USAGE, r"--texels-per-mm must be a finite"),
    ([*BAKE, "--out", "OUT/x.glb", "--texels-per-mm", "1e6"], EXIT_USAGE, r"--texels-per-mm must be in"),
    ([*BAKE, "--out", "OUT/x.glb", "--timeout=-1"], EXIT_USAGE, r"--timeout must be in \(0"),
    (["block", "synth", "--count", "0", "--out", "OUT/b"], EXIT_USAGE, r"--count must be in \[1,"),
    # the whole largest seed, not '4.29497e+09'
    (["block", "synth", "--count", "1", "--seed=-1", "--out", "OUT/b"], EXIT_USAGE, r"--seed must be in \[0, 4294967295\]; got -1;"),
    (["block", "synth", "--count", "1", "--face-px", "100000000", "--out", "OUT/b"], EXIT_USAGE, r"--face-px must be in"),
    (["train", "gtf", "--steps", "0", "--out", "OUT/t"], EXIT_USAGE, r"--steps must be in \[1,"),
    ([*BAKE, "--out", "OUT/x.stl"], EXIT_USAGE, r"--out of 'woodcam bake' must end in .glb"),
    ([*BAKE, "--out", "OUT"], EXIT_USAGE, r"--out of 'woodcam bake' is a FILE ending in .glb; got .*a folder"),
    ([*BAKE, "--out", "OUT/dir.glb"], EXIT_USAGE, r"is a FILE ending in .glb; got .*dir.glb', a folder"),
    ([*BAKE, "--out", "OUT/file.txt/x.glb"], EXIT_USAGE, r"--out of .woodcam bake.: cannot make the folder .*file.txt. is a file"),
    ([*BAKE, "--out", "OUT/x.glb", "--screenshot", "OUT/x.jpg"], EXIT_USAGE, r"--screenshot of .woodcam bake. is a FILE ending in .png"),
    # a file beside the GLB that cannot be written: refused before the work as --out is (exit 2; was 1)
    ([*BAKE, "--out", "OUT/objdir/x.glb"], EXIT_USAGE, r"--out \(the OBJ beside the GLB; --no-obj skips it\): .*x.obj' is an "
     r"existing folder"),
    # an infinite machining time was an OverflowError traceback
    ([*GCODE, "--tool", "flat:6", "--start=1e300,0,0"], EXIT_USAGE, r"--start must be in \[-100000, 100000\] mm; got 1e\+300 mm"),
    ([*GCODE, "--tool", "flat:6", "--rapid-rate", "1e-320"], EXIT_USAGE, r"--rapid-rate must be in \[0.1, 1e\+06\]"),
    # a stock of 1e300 mm: the message printed a 300-digit grid (read at the door in --units)
    ([*GCODE, "--tool", "flat:6", "--stock", "1e300x10x10"], EXIT_USAGE,
     r"--stock takes WxDxH in mm, 3 numbers in \(0, 10000\] \(raise it with WOODCAM_MAX_BLOCK_SIZE_MM=N\), e.g. 50x50x50; got '1e300x10x10'$"),
    # in the units typed: it said 'in mm', read before --units was known
    ([*GCODE, "--tool", "flat:0.25", "--units", "inch", "--stock", "0x1x1"], EXIT_USAGE,
     r"--stock takes WxDxH in inches \(--units inch\), 3 numbers in \(0, 393.701\] \(raise it with WOODCAM_MAX_BLOCK_SIZE_MM=N\), e.g. 2x2x2; got '0x1x1'$"),
    # tracebacks (an allocation, OpenCV's assertion) or a run that never ended
    (["parquetry", "toolpaths/img/drilling.png", "--veneer-from", "builtin:flat-sawn", "--out", "OUT/pq", "--sheet-size", "1e300x10"], EXIT_USAGE,
     r"--sheet-size takes WxH in mm"),
    (["parquetry", "toolpaths/img/drilling.png", "--veneer-from", "builtin:flat-sawn", "--out", "OUT/pq", "--image-size-mm", "1e300"], EXIT_USAGE,
     r"--image-size-mm must be in \(0, 10000\]"),  # at the door since 2a3e399: a usage error
    (["parquetry", "toolpaths/img/drilling.png", "--veneer-from", "builtin:flat-sawn", "--out", "OUT/pq", "--image-size-mm", "5"], EXIT_USAGE,
     r"image_size_mm \(--image-size-mm\) must be in \[patch_mm = 14, 10000\] mm"),  # the patch rule: a usage error
    (["parquetry", "toolpaths/img/drilling.png", "--veneer-from", "builtin:flat-sawn", "--out", "OUT/pq", "--sheets", "1000000"], EXIT_USAGE,
     r"--sheets must be in \[1, 1000\]"),
    (["rings", "show", "OUT/none", "--out", "OUT/x.png", "--zoom", "1000000"], EXIT_USAGE, r"--zoom must be in \[1, 64\]"),
    # accepted: a block at -5 px/mm, or at 0 px/mm for a 1e300 mm cube
    (["block", "from-photos", "OUT", "--size-mm", "50", "--out", "OUT/fp", "--max-px-per-mm=-5"], EXIT_USAGE,
     r"--max-px-per-mm must be in \(0, 1000\]"),
    # empty or repeated lists were taken as the default (an empty benchmark table, exit 0)
    (["fit", "builtin:flat-sawn", "--faces", "", "--out", "OUT/f.npz"], EXIT_USAGE, r"--faces must be 'all' or a comma list"),
    (["fit", "builtin:flat-sawn", "--faces", "front,front", "--out", "OUT/f.npz"], EXIT_USAGE, r"--faces must be 'all'"),
    (["eval", "rings", "builtin:flat-sawn", "--methods", "", "--out", "OUT/e"], EXIT_USAGE, r"--methods must be 'all'"),
    (["eval", "realistic", "--seed", "5", "--methods", "", "--out", "OUT/e"], EXIT_USAGE, r"--methods must be 'all' or a comma list from"),
    (["bench", "report", "OUT", "--gallery", "-1", "--out", "OUT/r"], EXIT_USAGE, r"--gallery must be in \[0, 1000\]"),
    # options that contradict each other, or one missing: a wrong command line (they exited 1,
    # eval rings --truth after opening every block, gcode after reading the programs)
    (["log", "render", "--out", "OUT/lr"], EXIT_USAGE, r"give exactly one log: a LOG_FILE, --real or --maps DIR; got 0"),
    (["log", "render", "--real", "OUT/file.txt", "--out", "OUT/lr"], EXIT_USAGE, r"give exactly one log: .*; got 2"),
    (["eval", "rings", "builtin:flat-sawn", "--truth", "OUT/file.txt", "OUT/file.txt", "--out", "OUT/e"], EXIT_USAGE,
     r"--truth needs one field file per block: got 2 for 1 blocks; give one --truth FIELD.npz for each block, "
     r"in the blocks' order, or leave --truth out$"),
    (["block", "synth", "--count", "1", "--engine", "local", "--address", "tcp://127.0.0.1:1", "--out", "OUT/b"], EXIT_USAGE,
     r"--address needs --engine dask; got --engine local; use --engine dask, or leave --address out$"),
    (["train", "rings", "--no-resume", "--out", "OUT/t"], EXIT_USAGE,
     r"train rings runs in this process and always from scratch: .*; got --no-resume; leave them out$"),
    (["train", "rings", "--workers", "2", "--no-resume", "--out", "OUT/t"], EXIT_USAGE,
     r"train rings .*; got --workers --no-resume; leave them out$"),
    (["gcode", "toolpaths/drilling.nc", "--block", "builtin:flat-sawn", "--out", "OUT/g.glb"], EXIT_USAGE,
     r"woodcam gcode: no tools given; pass --tool SPEC"),
    # LinuxCNC's own interpreter read the program as LinuxCNC's, the --dialect dropped silently
    ([*GCODE, "--tool", "flat:6", "--interpreter", "linuxcnc", "--dialect", "grbl"], EXIT_USAGE,
     r"--dialect must be linuxcnc with --interpreter linuxcnc .*; got --dialect grbl; leave out --interpreter"),
    # a name that is no face or method was the library's words, naming no option, exit 1, some
    # after the block was opened ('face must be one of ...; got 'bogus'')
    (["fit", "builtin:flat-sawn", "--faces", "front,bogus", "--out", "OUT/f.npz"], EXIT_USAGE,
     r"--faces must be 'all' or a comma list of faces from front, top, left, bottom, right, back \(or Mokume "
     r"letters A-F\); got 'bogus'; e.g. --faces front,top$"),
    (["eval", "rings", "builtin:flat-sawn", "--partial-faces", "top,X", "--out", "OUT/e"], EXIT_USAGE,
     r"--partial-faces must be 'all' or a comma list of faces from .*; got 'X'; e.g. --partial-faces front,top$"),
    (["eval", "appearance", "builtin:flat-sawn", "--end-grain", "A,sides", "--out", "OUT/ea"], EXIT_USAGE,
     r"--end-grain must be a comma list of faces from .*; got 'sides'; e.g. --end-grain front,top$"),
    (["bench", "run", "--blocks", "1", "--methods", "rbf,bogus", "--out", "OUT/b"], EXIT_USAGE,
     r"--methods must be from evidence, rbf, radial, neural; got 'rbf,bogus', in which 'bogus' is none of "
     r"them; e.g. --methods evidence,rbf$"),
    (["eval", "realistic", "--seed", "1", "--scenarios", "bogus", "--out", "OUT/e"], EXIT_USAGE,
     r"--scenarios must be from clean, noisy, ring-maps; got 'bogus', in which 'bogus' is none of them; "
     r"e.g. --scenarios clean,noisy$"),
    # sweep h2: the names as typed (it was a Python list, "got ['evidnce']"), the near one offered
    (["eval", "rings", "builtin:flat-sawn", "--methods", "evidnce,rbf", "--out", "OUT/e"], EXIT_USAGE,
     r"--methods must be from evidence, rbf, radial, neural, or all; got 'evidnce,rbf', in which 'evidnce' is "
     r"none of them; did you mean 'evidence'\?$"),
    (["eval", "realistic", "--seed", "5", "--faces", "full,full", "--out", "OUT/e"], EXIT_USAGE,
     r"--face-sets must be a comma list from full, three, each name once; got 'full,full'"),
    # eval realistic dropped empty names ('rbf,,radial') where fit refused them: one parser now
    (["eval", "realistic", "--seed", "5", "--methods", "rbf,,radial", "--scenarios", "bogus", "--out", "OUT/e"], EXIT_USAGE,
     r"--methods must be 'all' or a comma list from evidence, rbf, radial, neural, each name once; got 'rbf,,radial'"),
    (["eval", "rings", "builtin:flat-sawn", "--methods", "radial,radial", "--out", "OUT/e"], EXIT_USAGE,
     r"--methods must be 'all' or a comma list from evidence, rbf, radial, neural, each name once"),
    (["block", "synth", "--count", "1", "--face-px", "8", "--out", "OUT/b"], EXIT_USAGE, r"--face-px must be in \[16,"),
    # they named the Python parameters (face_px, blocks, retries), exit 1, after writing run.json
    (["bench", "run", "--blocks", "1", "--face-px", "20", "--out", "OUT/b"], EXIT_USAGE, r"--face-px must be in \[32, 16384\]"),
    (["bench", "run", "--blocks", "0", "--out", "OUT/b"], EXIT_USAGE, r"--blocks must be in \[1,"),
    (["bench", "run", "--blocks", "1", "--retries", "-1", "--out", "OUT/b"], EXIT_USAGE, r"--retries must be in \[0, 100\]"),
    (["eval", "realistic", "--seed", "1", "--eq79", "-1", "--out", "OUT/e"], EXIT_USAGE, r"--eq79 must be in \[0, 1000\]"),
    # 100 mm of jitter failed every block with an unrelated message in its record
    (["block", "synth", "--count", "1", "--jitter-mm", "100", "--out", "OUT/b"], EXIT_USAGE, r"--jitter-mm must be in \[0, 10\]"),
    # it blamed the block spec for a missing file; then said so with exit 1, as the work failing
    (["review", "OUT/nope.glb", "--out", "OUT/r.html"], EXIT_USAGE, r"PART of 'woodcam review': '.*nope.glb' does not exist"),
    # in inches the error showed the value converted ("got 12.7" for 0.5 against a mm range)
    (["gcode", "toolpaths/drilling.nc", "--block", "builtin:flat-sawn", "--out", "OUT/g.glb", "--tool", "flat:6",
      "--units", "inch", "--mesh-tol", "0.5"], EXIT_USAGE,
     r"--mesh-tol must be in \(0, 10\] mm; got 0.5 inch = 12.7 mm"),
    # the errors named the Python parameters (trace_dropout (traces.dropout), thickness_mm, relief)
    (["block", "synth", "--count", "1", "--dropout", "2", "--out", "OUT/b"], EXIT_USAGE, r"--dropout must be in \[0, 1\]"),
    (["parquetry", "toolpaths/img/drilling.png", "--veneer-from", "builtin:flat-sawn", "--leaf-thickness", "-1", "--out", "OUT/pq"], EXIT_USAGE,
     r"--leaf-thickness must be in \(0, 100\]"),
    (["woodify", "x.stl", "--years", "3", "--relief", "2", "--out", "OUT/w"], EXIT_USAGE, r"--relief must be in \[0, 1\]"),
    # a bad spec after a good tool number was reported as a bad number
    ([*GCODE, "--tool", "5=flat:6:7"], EXIT_USAGE, r"--tool '5=flat:6:7': tool spec 'flat:6:7': flat takes 1 number"),
    # a malformed --place or --tool value, read by the library's parser after the door, exited 1
    ([*BAKE, "--out", "OUT/x.glb", "--place", "fit:abc"], EXIT_USAGE, r"--place 'fit:abc': 'abc' is not a finite number"),
    ([*BAKE, "--out", "OUT/x.glb", "--place", "rotate:q:90"], EXIT_USAGE, r"--place 'rotate:q:90': expected rotate:AXIS:DEG"),
    ([*BAKE, "--out", "OUT/x.glb", "--place", "center", "--place", "fit:-0.1"], EXIT_USAGE,
     r"--place 'fit:-0.1': a margin must be >= 0; got -0.1 mm"),
    ([*BAKE, "--out", "OUT/x.glb", "--place", "spin"], EXIT_USAGE, r"--place 'spin' is not a placement operation"),
    ([*GCODE, "--tool", "flat:abc"], EXIT_USAGE, r"--tool 'flat:abc': tool spec 'flat:abc': numbers expected after the type"),
    ([*GCODE, "--tool", "x=ball:3"], EXIT_USAGE, r"--tool 'x=ball:3': the part before '=' must be a tool number"),
    # a tool number out of a tool table's range, or one given twice (the last was taken silently)
    ([*GCODE, "--tool", "1000000=flat:6"], EXIT_USAGE, r"--tool '1000000=flat:6': the tool number must be in \[0, 99999\]; got 1000000; e.g. --tool 1=flat:6$"),
    ([*GCODE, "--tool", "1=flat:6", "--tool", "2=ball:3", "--tool", "1=ball:3"], EXIT_USAGE,
     r"--tool '1=ball:3': tool 1 is given twice \(also --tool '1=flat:6'\); give each tool number once"),
    ([*GCODE, "--tool", "flat:-1"], EXIT_USAGE, r"--tool 'flat:-1': FlatEndMill: diameter_mm must be a positive number"),
    ([*GCODE, "--tool", "flat:6", "--tool", "2=bull:6:9"], EXIT_USAGE, r"--tool '2=bull:6:9': BullNoseMill: corner_radius_mm"),
    # in inches: the spec as typed, and as read in mm where only that breaks a rule
    ([*GCODE[:-1], "0.02", "--units", "inch", "--tool", "flat:0.25:0.5"], EXIT_USAGE,
     r"--tool 'flat:0.25:0.5': tool spec 'flat:0.25:0.5': flat takes 1 number\(s\), got 2; .*\(in, degrees\)"),
    ([*GCODE[:-1], "0.02", "--units", "inch", "--tool", "flat:0.25:flute=x"], EXIT_USAGE,
     r"--tool 'flat:0.25:flute=x': tool spec 'flat:0.25:flute=x': flute= needs a number of in, got 'x'"),
    ([*GCODE, "--tool", "flat:6:7"], EXIT_USAGE, r"--tool 'flat:6:7': tool spec 'flat:6:7': flat takes 1 number\(s\), got 2; .*\(mm, degrees\)"),
    # a tool's rule in inches is said in inches, of the spec as typed (it compared 2000 in with
    # 1000 mm, "got 2000.0"; then said it of the spec read in mm, "(read as 'flat:50800' in mm)
    # ... (0, 1000] mm, got 50800", beside a spec the user typed in inches)
    ([*GCODE[:-1], "0.02", "--units", "inch", "--tool", "flat:50"], EXIT_USAGE,
     r"--tool 'flat:50': FlatEndMill: the diameter must be a positive number in \(0, 39.37\] in, got 50 in; "
     r"give the cutting diameter in inches$"),
    ([*GCODE[:-1], "0.02", "--units", "inch", "--tool", "flat:2000"], EXIT_USAGE,
     r"--tool 'flat:2000': FlatEndMill: the diameter must be a positive number in \(0, 39.37\] in, got 2000 in"),
    ([*GCODE[:-1], "0.02", "--units", "inch", "--tool", "bull:0.5:0.3"], EXIT_USAGE,
     r"--tool 'bull:0.5:0.3': BullNoseMill: the corner radius must be in \(0, diameter/2 = 0.25\] in, got 0.3 in;"),
])
def test_bad_options_fail_fast_with_one_line(argv, code, match, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(__import__("pathlib").Path(__file__).resolve().parents[2])
    out = tmp_path / "out"
    (out / "dir.glb").mkdir(parents=True)
    (out / "file.txt").write_text("")
    (out / "objdir" / "x.obj").mkdir(parents=True)
    argv = [a.replace("OUT", str(out)) for a in argv]
    t0 = time.perf_counter()
    assert main(argv) == code
    assert time.perf_counter() - t0 < 30.0  # refused before any fitting or baking (minutes)
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("woodcam: error: ")
    assert __import__("re").search(match, err), err


@pytest.mark.parametrize("argv, module, run, said", [
    (["block", "synth", "--count", "100001", "--out", "OUT/b"], "block", "run",
     "--count must be in [1, 100000]; got 100001; see 'woodcam block synth --help'"),
    (["eval", "realistic", "--seed", "1", "--count", "1001", "--out", "OUT/e"], "eval_bench", "run_realistic",
     "--count must be in [1, 1000]; got 1001; see 'woodcam eval realistic --help'"),
])
def test_a_count_of_days_of_work_is_refused(argv, module, run, said, tmp_path, capsys, monkeypatch):
    """'block synth --count' took up to 1e6 blocks: 8.5 MB and ~4 CPU-s each at the default 512 px,
    8.5 TB and weeks; 'eval realistic --count' 1e6 blocks a row, each fitted by every method on
    this machine: years. Refused before any work (the command's work stands in here: it ran)."""
    import importlib

    monkeypatch.setattr(importlib.import_module(f"woodcam.cli.{module}"), run, lambda args: 0)
    assert main([a.replace("OUT", str(tmp_path)) for a in argv]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"woodcam: error: {said}"), err


@pytest.mark.parametrize("argv, said", [
    (["gcode", "toolpaths/drilling.nc", "--block", "builtin:flat-sawn", "--out", "OUT/g.glb"],
     "woodcam gcode: no tools given; pass --tool SPEC"),
    (["log", "export", "--real", "--maps", "toolpaths", "--out", "OUT/l.json"],
     "give exactly one log: a LOG_FILE, --real or --maps DIR; got 2"),
    (["log", "maps", "--out", "OUT/m"], "give exactly one log: a LOG_FILE, --real or --maps DIR; got 0"),
])
def test_a_commands_own_usage_checks_come_before_any_work(argv, said, tmp_path, capsys, monkeypatch):
    """Test only: the usage checks the commands make themselves (gcode's no tools, log's one log)
    refuse the command line (exit 2, one line) before the program,
    the block, the log or the photos are read, and write nothing: the steps that read them fail
    the test if reached."""
    from importlib import import_module

    def reached(*_a, **_k):
        raise AssertionError("work done before the usage check")

    for mod, name in (("toolpath.gcode", "read_gcode"), ("toolpath.simulate", "simulate"),
                      ("stock", "open_stock"), ("logs.io", "read_log"), ("logs.io", "read_gran1"),
                      ("logs.maps", "read_maps"), ("block.photos", "block_from_photos")):
        monkeypatch.setattr(import_module(f"woodcam.{mod}"), name, reached)
    monkeypatch.chdir(__import__("pathlib").Path(__file__).resolve().parents[2])
    out = tmp_path / "out"
    assert main([a.replace("OUT", str(out)) for a in argv]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and said in err, err
    assert not out.exists()


@pytest.mark.parametrize("argv, said", [
    (["bench", "run", "--blocks", "1", "--out", "OUT/b", "--memory-limit-mb", "100"],
     "--memory-limit-mb must be in [256, 1048576]; got 100; see 'woodcam bench run --help'"),
    (["block", "synth", "--count", "1", "--out", "OUT/b", "--memory-limit-mb", "255"],
     "--memory-limit-mb must be in [256, 1048576]; got 255; see 'woodcam block synth --help'"),
    (["bench", "run", "--blocks", "1", "--out", "OUT/b", "--address", "foo"],
     "--address must be a Dask scheduler address like tcp://HOST:8786; got 'foo'"),
    (["bench", "run", "--blocks", "1", "--out", "OUT/b", "--address", "tcp://127.0.0.1:9", "--workers", "2"],
     "--workers cannot be given with --address: the cluster at tcp://127.0.0.1:9 has its own workers; got "
     "--workers 2; leave --workers out"),
])
def test_the_engine_options_are_checked_at_the_door_with_the_librarys_rules(argv, said, tmp_path, capsys):
    """'--memory-limit-mb 100' passed the CLI's range [64, 1048576] and was refused by run_many's
    own (>= 256); a malformed --address and --workers with --address were run_many's errors too:
    each exited 1 naming the Python parameter (memory_limit_mb, address, workers), bench run after
    writing its run.json (sweep h4). Now one range for both, and a usage error before any file."""
    out = tmp_path / "out"
    assert main([a.replace("OUT", str(out)) for a in argv]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"woodcam: error: {said}"), err
    assert not out.exists()


@pytest.mark.parametrize("value", ["nan,nan,nan", "0,0,inf", "1,2"])
def test_work_offset_must_be_three_finite_numbers(value, capsys):
    """Issue 15: `--work-offset nan,nan,nan` exited 0 (and cut nothing)."""
    with pytest.raises(SystemExit) as exc:
        main(["gcode", "toolpaths/vcarve_text.nc", "--tool", "vbit:60:12", "--block",
              "builtin:flat-sawn", "--out", "x.glb", f"--work-offset={value}"])
    assert exc.value.code == 2
    assert "finite numbers X,Y,Z" in capsys.readouterr().err


@pytest.mark.parametrize("argv, prog", [
    (["bake"], "woodcam bake"),  # required arguments missing
    (["bake", "x.py", "--block", "builtin:flat-sawn", "--out", "x.glb", "--tolerance", "abc"], "woodcam bake"),
    (["nosuch"], "woodcam"),  # an unknown command
    (["block", "synth", "--count", "x"], "woodcam block synth"),
    # sweep h2: an argument no parser takes was said by the top parser, pointing at 'woodcam
    # --help', which lists none of the command's options; now the command's, with the near option
    (["block", "show", "builtin:rift", "--out", "x.png", "--bogus"], "woodcam block show"),
    (["cache", "info", "extra"], "woodcam cache info"),
    (["bake", "x.py", "--block", "builtin:rift", "--out", "x.glb", "--tolerence", "0.1"], "woodcam bake"),
])
def test_usage_errors_are_one_line_with_a_pointer_to_help(argv, prog, capsys):
    """argparse's own errors printed the whole usage block (up to 15 lines) before the error."""
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == EXIT_USAGE
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    assert err.startswith(f"{prog}: error: ") and err.rstrip().endswith(f"(see '{prog} --help')"), err
    if "--tolerence" in argv:
        assert "unrecognized arguments: --tolerence 0.1; did you mean --tolerance? (see" in err, err
    if "--bogus" in argv:
        assert "did you mean" not in err, err  # every option shares its dashes: no false match


def test_an_unexpected_error_is_one_line_and_a_wrapped_ctrl_c_is_an_interrupt(monkeypatch, capsys):
    """The last net of the CLI: an exception no door foresaw printed a traceback, and a Ctrl-C that
    numba's compiler re-raised as a RuntimeError was a traceback with exit 1."""
    import woodcam.cli.bake as bake_cli

    def boom(args):
        raise ValueError("x" * 1000)

    def wrapped_interrupt(args):
        import warnings

        from woodcam.errors import WoodcamWarning

        warnings.warn("a warning of the work before the interrupt", WoodcamWarning)
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as err:
            raise RuntimeError("no compiled object yet") from err

    monkeypatch.setattr(bake_cli, "run_blocks", boom)
    monkeypatch.delenv("WOODCAM_DEBUG", raising=False)
    assert main(["blocks"]) == EXIT_ERROR
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("woodcam: error: internal error (ValueError: xxx")
    assert "WOODCAM_DEBUG=1" in err and len(err) < 500
    monkeypatch.setenv("WOODCAM_DEBUG", "1")
    with pytest.raises(ValueError):
        main(["blocks"])
    monkeypatch.setattr(bake_cli, "run_blocks", wrapped_interrupt)
    assert main(["blocks"]) == 130
    assert capsys.readouterr().err == "woodcam: interrupted\n"  # one line: the warning is not printed after it


def test_ctrl_c_while_a_part_script_imports_a_pybind11_module_is_an_interrupt(tmp_path, capsys):
    """Ctrl-C while bowl.py imported build123d: OCP (pybind11) turns the KeyboardInterrupt into
    'ImportError: initialization failed', and bake said 'part script ... failed with ImportError:
    ...; fix the script', exit 1. It is an interrupt: exit 130, one line."""
    script = tmp_path / "part.py"
    script.write_text("raise ImportError('initialization failed') from KeyboardInterrupt()\n")
    capsys.readouterr()
    assert main(["bake", str(script), "--block", "builtin:flat-sawn", "--out", str(tmp_path / "p.glb")]) == 130
    assert capsys.readouterr().err == "woodcam: interrupted\n"


def _swallowed_ctrl_c():
    """Ctrl-C landing inside a library that swallows it: trimesh wraps its imports in
    ``except BaseException``, so the KeyboardInterrupt never reaches the command."""
    import os
    import signal

    try:
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(5)  # the signal's handler runs here
    except BaseException:  # noqa: BLE001 - what the library does
        pass


@pytest.mark.parametrize("after", ["returns", "writes", "mangled"])
def test_a_ctrl_c_a_library_swallowed_still_ends_the_command(after, monkeypatch, tmp_path, capsys):
    """Ctrl-C in the first seconds of a bake could land in trimesh's imports and be swallowed:
    the bake went on and ended with exit 0 (its files written), or scipy, left half-imported,
    failed later with 'NameError: _ndimage_api' (exit 1). The interrupt is recorded: no file
    lands after it, and however the run ends it is an interrupt, exit 130, one line."""
    import warnings

    import woodcam.cli.bake as bake_cli
    from woodcam import _atomic
    from woodcam.errors import WoodcamWarning

    out = tmp_path / "part.glb"

    def command(args):
        warnings.warn("a warning of the work before the interrupt", WoodcamWarning)
        _swallowed_ctrl_c()
        if after == "writes":
            _atomic.write_text(out, "written after the Ctrl-C")
        if after == "mangled":
            raise NameError("name '_ndimage_api' is not defined")
        return 0

    monkeypatch.setattr(bake_cli, "run_blocks", command)
    capsys.readouterr()
    assert main(["blocks"]) == 130
    assert capsys.readouterr().err == "woodcam: interrupted\n"
    assert not out.exists() and list(tmp_path.iterdir()) == []  # no file, no temporary
    import signal

    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # pytest's own again


def test_a_command_whose_parent_ignored_ctrl_c_runs_on_through_it():
    """A parent that set SIGINT to be ignored (``nohup``, ``cmd &`` in a script) means the command
    runs on through Ctrl-C, as Python leaves it: woodcam installed its own handler anyway and
    ended with 'interrupted', exit 130. It leaves the ignore in place, before, during and after."""
    import subprocess
    import sys

    code = (
        "import os, signal, time\n"
        "signal.signal(signal.SIGINT, signal.SIG_IGN)\n"
        "import woodcam.cli.bake as bake_cli\n"
        "from woodcam.cli import main\n"
        "def command(args):\n"
        "    os.kill(os.getpid(), signal.SIGINT)\n"
        "    time.sleep(0.2)\n"
        "    return 0\n"
        "bake_cli.run_blocks = command\n"
        "rc = main(['blocks'])\n"
        "print(rc, signal.getsignal(signal.SIGINT) is signal.SIG_IGN)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["0", "True"]
    assert "interrupted" not in done.stderr


def _run_as_the_process(tmp_path, body: str, command: str = "    return 0\n"):
    """Run ``woodcam blocks`` as ``python -m`` runs it (the process's own command) with
    ``command`` in place of the blocks listing, then ``body`` (which ends the module); returns
    (exit status, stdout, stderr)."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    (tmp_path / "ctrl_c_case.py").write_text(
        "import atexit, os, signal, sys, threading, time\n"
        "import woodcam.cli.bake as bake_cli\n"
        "from woodcam.cli import main\n"
        "def command(args):\n"
        "    print('output')\n"
        f"{command}"
        "bake_cli.run_blocks = command\n"
        "sys.argv = ['woodcam', 'blocks']\n"
        f"{body}")
    repo = Path(__file__).resolve().parents[2]
    env = dict(os.environ, PYTHONPATH=f"{repo}{os.pathsep}{tmp_path}")
    done = subprocess.run([sys.executable, "-m", "ctrl_c_case"], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=120)
    return done.returncode, done.stdout, done.stderr


_CTRL_C = "os.kill(os.getpid(), signal.SIGINT); time.sleep(2)"


def test_ctrl_c_inside_code_run_from_a_string_is_an_interrupt_of_python_dash_m(tmp_path):
    """A Ctrl-C landing in code run from a string (numba's compiler, dataclasses, namedtuple:
    exec of source) printed 'woodcam: interrupted', returned 130, and then 'python -m woodcam'
    killed itself by SIGINT (status -2): CPython marks the process so whenever an exact
    KeyboardInterrupt leaves such code, even one caught later. Seen in 1 of 50 Ctrl-Cs of
    'python -m woodcam blocks'."""
    rc, out, err = _run_as_the_process(
        tmp_path, "sys.exit(main())\n", f"    exec({_CTRL_C!r})\n    return 0\n")
    assert (rc, out, err) == (130, "output\n", "woodcam: interrupted\n")


@pytest.mark.parametrize("when", ["returned", "atexit", "joined thread"])
def test_ctrl_c_as_the_process_exits_after_its_command_is_an_interrupt(when, tmp_path):
    """A Ctrl-C after the command returned, while the process exits (threads joined, atexit
    callbacks, the interpreter tearing down numba, scipy and torch: 0.3-0.5 s of a 2 s
    'woodcam blocks'), ended it by SIGINT (status -2, a traceback or nothing), or with a
    traceback 'Exception ignored in atexit callback' and exit 0: Python's own handler was back.
    It ends the process at once: exit 130, one line after the command's output."""
    command = {
        "returned": "    return 0\n",
        "atexit": f"    atexit.register(lambda: ({_CTRL_C.replace('; ', ', ')}))\n    return 0\n",
        "joined thread": "    threading.Thread(target=lambda: (time.sleep(0.3), os.kill(os.getpid(), "
                         "signal.SIGINT), time.sleep(5))).start()\n    return 0\n",
    }[when]
    body = ("rc = main()\n" + (f"{_CTRL_C}\n" if when == "returned" else "") + "sys.exit(rc)\n")
    t0 = time.perf_counter()
    rc, out, err = _run_as_the_process(tmp_path, body, command)
    assert (rc, out, err) == (130, "output\n", "woodcam: interrupted\n")
    assert time.perf_counter() - t0 < 30  # at once: not after the thread's 5 s sleep (with slack)


def test_ctrl_c_in_the_interpreters_last_teardown_is_ignored(tmp_path):
    """The interpreter's last phase (its modules torn down, after every atexit callback) runs no
    Python handler and puts SIGINT back to the kernel's default: a Ctrl-C there killed the
    process by the signal (status -2, no line) after its output was written and flushed. From
    woodcam's last atexit callback on SIGINT is ignored: the process exits as its command ended."""
    command = ("    class Late:\n"
               f"        def __del__(self): {_CTRL_C}\n"
               "    sys.modules['late_holder'] = type(sys)('late_holder')\n"
               "    sys.modules['late_holder'].late = Late()  # freed as the modules are torn down\n"
               "    return 0\n")
    rc, out, err = _run_as_the_process(tmp_path, "sys.exit(main())\n", command)
    assert (rc, out, err) == (0, "output\n", "")


def test_what_a_library_prints_as_it_swallows_a_ctrl_c_is_not_printed(monkeypatch, capsys):
    """A library that swallows a Ctrl-C may say so on standard output: the command's output
    after the interrupt is dropped, its output before it kept, and its one line on stderr."""
    import woodcam.cli.bake as bake_cli

    def command(args):
        print("output")
        try:
            _swallowed_ctrl_c()
        finally:
            print("VTK not installed")  # what OCP's IVtk modules print
        return 0

    monkeypatch.setattr(bake_cli, "run_blocks", command)
    capsys.readouterr()
    assert main(["blocks"]) == 130
    assert capsys.readouterr() == ("output\n", "woodcam: interrupted\n")
    print("after")  # standard output is the stream's own again
    assert capsys.readouterr().out == "after\n"


def test_ctrl_c_while_cadquery_imports_vtk_is_one_line(tmp_path):
    """A Ctrl-C while a cadquery part script imported cadquery (its OCP.IVtkOCC imports vtk, 2 s,
    inside a bare except) printed 'VTK not installed' on stdout besides 'woodcam: interrupted'."""
    import importlib.util

    if importlib.util.find_spec("OCP") is None or importlib.util.find_spec("vtk") is None:
        pytest.skip("OCP and vtk are not installed (pip install woodcam[cad,view])")
    command = ("    class Hook:\n"
               "        def find_spec(self, name, path=None, target=None):\n"
               "            if name == 'vtk':  # Ctrl-C as OCP's IVtk module imports vtk\n"
               "                sys.meta_path.remove(self)\n"
               "                os.kill(os.getpid(), signal.SIGINT)\n"
               "    sys.meta_path.insert(0, Hook())\n"
               "    import OCP.IVtkOCC\n"
               "    return 0\n")
    rc, out, err = _run_as_the_process(tmp_path, "sys.exit(main())\n", command)
    assert (rc, out, err) == (130, "output\n", "woodcam: interrupted\n")


def test_the_interrupt_flag_lives_for_one_command_only(monkeypatch, capsys):
    """The flag is clear at each command's start and after its end, so a Ctrl-C of one run never
    ends the next (main() runs many times in one process: tests, notebooks), and outside a
    command the checkpoints never raise."""
    import woodcam.cli.bake as bake_cli
    from woodcam import _interrupt

    monkeypatch.setattr(bake_cli, "run_blocks", lambda args: (_swallowed_ctrl_c(), 0)[1])
    assert main(["blocks"]) == 130
    assert not _interrupt.requested()
    _interrupt.check()  # no raise outside a command
    monkeypatch.setattr(bake_cli, "run_blocks", lambda args: 0)
    assert main(["blocks"]) == 0
    capsys.readouterr()


@pytest.mark.parametrize("var,value,message", [
    ("WOODCAM_CACHE_MAX_MB", "abc", "WOODCAM_CACHE_MAX_MB must be a number of MiB > 0; got 'abc'; e.g. export "
     "WOODCAM_CACHE_MAX_MB=4096"),
    ("WOODCAM_MAX_GRID_CELLS", "abc", "WOODCAM_MAX_GRID_CELLS must be a positive number; got 'abc'; e.g. export "
     "WOODCAM_MAX_GRID_CELLS=400000000, or unset it for the default 2e+08"),
    ("WOODCAM_WORKERS", "0", "WOODCAM_WORKERS must be an integer >= 1"),
])
def test_a_malformed_woodcam_setting_is_refused_before_the_work(var, value, message, tmp_path, monkeypatch, capsys):
    """Each WOODCAM_* setting was read where it is used: 'WOODCAM_CACHE_MAX_MB=abc woodcam fit
    builtin:rift --method radial --out f.npz' fitted for seconds, stored the field in the cache,
    then failed and wrote no --out (and passed silently once the field was cached)."""
    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setenv(var, value)
    out = tmp_path / "f.npz"
    assert main(["fit", "builtin:rift", "--method", "radial", "--out", str(out)]) == EXIT_ERROR
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith(f"woodcam: error: {message}"), err
    assert not out.exists() and not (tmp_path / "cache").exists()  # no work was done


@pytest.mark.parametrize("var,value,works,refused", [
    ("WOODCAM_WORKERS", "abc", [["cache", "clear"], ["cache", "info"], ["blocks"], ["species"]], []),
    ("WOODCAM_MAX_GRID_CELLS", "abc", [["cache", "clear"], ["cache", "info"], ["blocks"]], []),
    ("WOODCAM_CACHE_MAX_MB", "abc", [["cache", "clear"], ["blocks"]], [["cache", "info"]]),
    ("WOODCAM_CACHE_DIR", "FILE", [["blocks"]], [["cache", "clear"], ["cache", "info"],
                                                 ["fit", "builtin:rift", "--method", "radial", "--out", "OUT"]]),
])
def test_a_malformed_woodcam_setting_is_refused_only_by_the_commands_that_read_it(
        var, value, works, refused, tmp_path, monkeypatch, capsys):
    """Every command read every WOODCAM_* setting: 'WOODCAM_WORKERS=abc woodcam cache clear'
    (and 'blocks', 'cache info') exited 1 on a setting it never reads, so a broken fit setting
    kept the cache from being cleared; a WOODCAM_CACHE_DIR naming a file was read by none
    ('cache clear' said "deleted 0 entries (0.0 MiB) from FILE", a fit warned and refitted
    every run). Now each command checks the settings it reads (uses_settings), and those one
    line naming the variable, its rule, its value and a fix."""
    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    if value == "FILE":
        value = str(tmp_path / "file")
        (tmp_path / "file").write_text("x")
    monkeypatch.setenv(var, value)
    for argv in works:
        assert main(argv) == 0, argv
        assert capsys.readouterr().err == "", argv
    for argv in refused:
        argv = [str(tmp_path / "f.npz") if a == "OUT" else a for a in argv]
        assert main(argv) == EXIT_ERROR, argv
        err = capsys.readouterr().err.splitlines()
        assert len(err) == 1 and err[0].startswith(f"woodcam: error: {var} must be ") and repr(value) in err[0], err
    assert not (tmp_path / "f.npz").exists()
    if var == "WOODCAM_CACHE_DIR":
        assert "must be a folder" in err[0] and "unset it" in err[0], err


def test_workers_on_the_command_line_overrides_a_malformed_woodcam_workers(tmp_path, monkeypatch):
    """--workers sets the fit's cores for the run (apply_workers): the environment's is not read."""
    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setenv("WOODCAM_WORKERS", "0")
    assert main(["fit", "builtin:rift", "--method", "radial", "--workers", "1", "--out", str(tmp_path / "f.npz")]) == 0


def test_a_log_blocks_knot_the_log_lacks_is_a_wrong_command_line(tmp_path, monkeypatch, capsys):
    """'bake PART --block log:gran1@999' exited 1 ('knot index in ... must be 0..107; got 999'):
    a spec that names no block is a wrong command line (exit 2, README), said of the argument
    that gave it: --block, or the positional BLOCK of fit, eval rings and block show."""
    from woodcam.fields.skeleton import BranchStrand, simple_log
    from woodcam.logs.io import write_log

    knot = BranchStrand.from_model(0.25, 0.0, 300.0, 0.0, 0.0, 0.0, 0.0, 100.0, 45.0)
    write_log(simple_log(knots=[knot]), tmp_path / "l.json")
    monkeypatch.chdir(tmp_path)
    rule = "the knot index must be 0..0 (log l.json has 1 knot); got 3; e.g. 'log:l.json@0'"
    (tmp_path / "p.stl").write_text("solid p\nendsolid p\n")
    for argv, said in [
        (["preview", "p.stl", "--block", "log:l.json@3~z90", "--screenshot", "s.png"], "--block log:l.json@3~z90"),
        (["fit", "log:l.json@3", "--method", "radial", "--out", "f.npz"], "BLOCK of 'woodcam fit' (block spec 'log:l.json@3')"),
        (["eval", "rings", "builtin:rift", "log:l.json@3", "--out", "ev"],
         "BLOCK of 'woodcam eval rings' (block spec 'log:l.json@3')"),
    ]:
        assert main(argv) == EXIT_USAGE, argv
        assert capsys.readouterr().err.splitlines() == [f"woodcam: error: {said}: {rule}"], argv


def test_a_command_without_standard_output_runs(monkeypatch, capsys):
    """A command started with standard output closed ('woodcam blocks >&-': sys.stdout is None)
    ended with 'woodcam: error: internal error (AttributeError: 'NoneType' object has no
    attribute 'flush'); this is a woodcam bug ...', exit 1. print() writes nowhere there, and so
    does the command: exit 0."""
    import sys

    monkeypatch.setattr(sys, "stdout", None)
    assert main(["blocks"]) == 0
    assert sys.stdout is None
