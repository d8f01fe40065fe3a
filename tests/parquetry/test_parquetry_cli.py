"""``woodcam parquetry``: a small end-to-end run from scans and a job file, and one-line errors."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from woodcam.cli import main
from woodcam.errors import WoodcamError, WoodcamWarning


@pytest.fixture
def scans(tmp_path):
    """Two synthetic 'scans' at 50.8 dpi (2 px/mm): light and dark striped wood, one masked."""
    rng = np.random.default_rng(3)
    yy, xx = np.mgrid[0:240, 0:320]
    for name, base in (("light", 200), ("dark", 90)):
        stripes = 25 * np.sin(xx / 3.0 + 0.3 * np.sin(yy / 17.0)) + rng.normal(0, 4, xx.shape)
        g = np.clip(base + stripes, 0, 255).astype(np.uint8)
        Image.fromarray(np.stack([g, (g * 0.8).astype(np.uint8), (g * 0.6).astype(np.uint8)], 2)).save(
            tmp_path / f"{name}.png")
    mask = np.full((240, 320), 255, np.uint8)
    mask[:, :20] = 0                              # a clamp mark along one edge
    Image.fromarray(mask).save(tmp_path / "dark_mask.png")
    from skimage import data

    Image.fromarray(data.coffee()).save(tmp_path / "coffee.png")
    return tmp_path


def test_cli_run_writes_everything(scans, capsys):
    out = scans / "out"
    rc = main(["parquetry", str(scans / "coffee.png"), "--veneer", f"{scans / 'light.png'}:50.8",
               "--veneer", f"{scans / 'dark.png'}:2px/mm:{scans / 'dark_mask.png'}",
               "--image-size-mm", "56", "--px-per-mm", "2", "--out", str(out), "--quiet"])
    text = capsys.readouterr().out
    assert rc == 0, text
    assert "feature cost/px" in text and "0 pieces with problems" in text
    for name in ("render.png", "baseline.png", "target_matched.png", "assembly.svg", "panel.glb",
                 "result.json", "job.json", "veneer_light.svg", "veneer_light.dxf"):
        assert (out / name).is_file(), name
    # the --out help names what is written (it promised a panel.png that no run writes)
    import re

    from woodcam.cli import build_parser, _walk_options

    help_ = " ".join(next(a.help for path, a in _walk_options(build_parser())
                          if path == ["parquetry"] and "--out" in a.option_strings).split())
    for f in out.iterdir():
        name = re.sub(r"^veneer_.*\.(svg|dxf)$", "veneer_<id>.svg/.dxf", f.name)
        assert name in help_, (f.name, help_)
    assert "panel.png" not in help_
    result = json.loads((out / "result.json").read_text())
    assert result["summary"]["complete"] and len(result["patches"]) == 6 * 4
    # the time per patch was wall seconds alone ('0.107 s per patch'), beside the README's and the
    # bench's figures in CPU seconds; both are said, and stored
    summ = result["summary"]
    # each stored rounded (the total to 1 ms, the share to 0.1 ms): equal within both roundings
    assert abs(summ["cpu_seconds_per_patch"] - summ["match_cpu_seconds"] / 24) <= 0.0005 / 24 + 0.00005
    (said,) = [line for line in text.splitlines() if line.startswith("matching: ")]
    assert said == (f"matching: {summ['match_seconds']:.1f} s wall, {summ['match_cpu_seconds']:.1f} CPU-s; per patch "
                    f"{summ['seconds_per_patch']:.3f} s wall, {summ['cpu_seconds_per_patch']:.3f} CPU-s")
    # the job file written reruns the same job
    job = json.loads((out / "job.json").read_text())
    assert job["num_source_rotations"] == 15 and len(job["source_textures"]) == 2
    out2 = scans / "out2"
    assert main(["parquetry", "--config", str(out / "job.json"), "--out", str(out2), "--quiet",
                 "--no-glb"]) == 0
    again = json.loads((out2 / "result.json").read_text())
    assert [p["anchor_px"] for p in again["patches"]] == [p["anchor_px"] for p in result["patches"]]


@pytest.mark.parametrize("args, message, code", [
    # a missing target is a wrong command line, refused at the input door (exit 2; it was 1)
    (["{d}/nope.png", "--veneer", "{d}/light.png"], "TARGET of 'woodcam parquetry': '{d}/nope.png' does not exist", 2),
    (["{d}/coffee.png", "--veneer", "{d}/light.png:300:{d}/coffee.png"], "veneer 'light': its mask '{d}/coffee.png' "
     "is ", 1),
    (["{d}/coffee.png", "--veneer", "{d}/light.png:2000"], "smaller than one patch", 1),
    # no veneers on the command line and no job file: a wrong command line (exit 2; it was 1,
    # after the run had begun), as test_no_target_or_no_veneers_is_a_usage_error_before_any_work
    (["{d}/coffee.png"], "parquetry needs veneers", 2),
])
def test_cli_bad_input_is_one_line(scans, capsys, args, message, code):
    argv = ["parquetry"] + [a.format(d=scans) for a in args] + ["--out", str(scans / "o"), "--quiet"]
    assert main(argv) == code
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith("woodcam: error:") and message.format(d=scans) in err



@pytest.mark.parametrize("args, said", [
    (["--veneer-from", "builtin:flat-sawn"], "parquetry needs a target image (TARGET or a --config job with targets)"),
    (["{d}/coffee.png"], "parquetry needs veneers: --veneer SCAN[:DPI], --veneer-from SPEC, or a --config job"),
    (["--config", "{d}/job.json"], "parquetry needs veneers: "),  # the job file gives a target only
])
def test_no_target_or_no_veneers_is_a_usage_error_before_any_work(scans, capsys, monkeypatch, args, said):
    """``woodcam parquetry TARGET`` with no veneer, and no TARGET, exited 1 as a failed run,
    after the scans were read: what to rebuild and from what is the command line's (or a
    --config job file's) to give, so neither given is a wrong command line (exit 2), said before
    the job's sources are read."""
    (scans / "job.json").write_text(json.dumps({"targets": [{"filename": "coffee.png"}], "source_textures": []}))
    import woodcam.parquetry.job as job_module

    monkeypatch.setattr(job_module, "job_veneers", lambda *a, **k: pytest.fail("the veneers were read"))
    argv = ["parquetry"] + [a.format(d=scans) for a in args] + ["--out", str(scans / "o"), "--quiet"]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith("woodcam: error: ") and said in err, err
    assert not (scans / "o").exists()


@pytest.mark.parametrize("key, missing, entries, typed", [
    ("targets[0].filename", "nope.png", {"targets": [{"filename": "nope.png"}], "source_textures": [
        {"texture": "light.png", "dpi": 300}]}, ["{d}/nope.png", "--veneer", "{d}/light.png"]),
    ("source_textures[0].texture", "nope.png", {"source_textures": [{"texture": "nope.png", "dpi": 300}]},
     ["{d}/coffee.png", "--veneer", "{d}/nope.png:300"]),
    ("source_textures[0].mask", "nope.png", {"source_textures": [{"texture": "light.png", "dpi": 300, "mask": "nope.png"}]},
     ["{d}/coffee.png", "--veneer", "{d}/light.png:300:{d}/nope.png"]),
    ("woodcam.mokume[0]", "nope", {"woodcam": {"mokume": ["nope"]}}, ["{d}/coffee.png", "--veneer-from", "{d}/nope"]),
    ("woodcam.blocks[0].spec", "nope", {"woodcam": {"blocks": [{"spec": "nope"}]}},
     ["{d}/coffee.png", "--veneer-from", "{d}/nope"]),
    ("woodcam.blocks[0].spec", "nope/field.npz", {"woodcam": {"blocks": [{"spec": "woodify:nope/field.npz"}]}},
     ["{d}/coffee.png", "--veneer-from", "woodify:{d}/nope/field.npz"]),
])
def test_a_missing_path_in_a_config_job_is_a_usage_error_as_on_the_command_line(
        scans, capsys, monkeypatch, key, missing, entries, typed):
    """A --config job file naming a target, texture, mask, Mokume folder or block that is not
    there exited 1 (a block's after the job's scans were read) where the same path typed on the
    command line exits 2: the job file is part of the command line, so it is a usage error too,
    one line naming --config, the job file, the entry and the path, before any work."""
    import woodcam.parquetry.job as job_module

    job = scans / "job.json"
    job.write_text(json.dumps({"targets": [{"filename": "coffee.png"}], **entries}))
    monkeypatch.setattr(job_module, "job_veneers", lambda *a, **k: pytest.fail("the veneers were read"))
    out = scans / "o"
    for argv, said in ((typed, "does not exist"), (["--config", str(job)], f"--config of 'woodcam parquetry': job file "
                                                   f"{str(job)!r}: {key} ")):
        argv = ["parquetry"] + [a.format(d=scans) for a in argv] + ["--out", str(out), "--quiet"]
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith("woodcam: error: ") and said in err, err
        assert not out.exists()
    assert f"no such file {str(scans / missing)!r}" in err, err
    with pytest.raises(job_module.JobPathError) as raised:  # the library's: a plain WoodcamError
        job_module.read_job(job)
    assert isinstance(raised.value, WoodcamError) and raised.value.key == key


@pytest.mark.parametrize("value, said", [
    ("{d}/light.png:abc", "the resolution must be a DPI (e.g. 300) or Npx/mm (e.g. 4px/mm), finite and > 0; got 'abc'"),
    ("{d}/light.png:0", "finite and > 0; got '0'"),
    ("{d}/light.png:-300", "finite and > 0; got '-300'"),
    ("{d}/light.png:inf", "finite and > 0; got 'inf'"),
    ("{d}/light.png:nan", "finite and > 0; got 'nan'"),
    ("{d}/light.png:-2px/mm", "finite and > 0; got '-2px/mm'"),
    ("{d}/light.png:0px/mm", "finite and > 0; got '0px/mm'"),
    ("{d}/light.png:300:{d}/coffee.png:x", "has 4 ':' parts, at most 3"),
    (":300", "names no scan image"),
])
def test_a_malformed_veneer_is_a_usage_error_before_any_work(scans, capsys, value, said):
    """``--veneer SCAN:abc`` and ``SCAN:300:MASK:x`` exited 1 once the run had begun, and
    ``SCAN:0`` / ``SCAN:-300`` passed the command line and were refused only when the job was
    read (exit 1): a malformed value is a wrong command line (exit 2), said at the door."""
    argv = ["parquetry", str(scans / "coffee.png"), "--veneer", value.format(d=scans), "--out", str(scans / "o"),
            "--quiet"]
    with pytest.raises(SystemExit) as ended:  # argparse's door
        main(argv)
    assert ended.value.code == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith("woodcam parquetry: error: argument --veneer: ") and said in err, err
    assert "SCAN[:DPI][:MASK]" in err and not (scans / "o").exists()


@pytest.mark.parametrize("option, value, said", [
    ("--w-intens", "2", "--w-intens must be in [0, 1]; got 2.0"),
    ("--n-rot", "0", "--n-rot must be in [1, 360]; got 0"),
    ("--n-adaptive", "-1", "--n-adaptive must be in [0, 32]; got -1"),
    ("--w-struct", "-1", "--w-struct must be in [0, 1e+06]; got -1.0"),
    ("--flat-detail", "0.5", "--flat-detail must be in [1, 1e+06]; got 0.5"),
    ("--overlap-mm", "-1", "--overlap-mm must be in [0, 10000]; got -1.0"),
    # a bit of no width: tool paths on the outlines and no kerf between the pieces (exit 0)
    ("--tool-diameter", "0", "--tool-diameter must be in (0, 100]"),
    # options that contradict each other (errors.UsageError) exited 1, as a failed run
    ("--patch-mm", "4", "patch_mm must be at least min_piece_mm"),
    # up to 32 passed: 14 * 2^5 = 448 mm patches on a 364 mm panel made none of that size (the top
    # squares are clipped to the panel), and 2^32-cell squares were asked for
    ("--n-adaptive", "5", "n_adaptive (--n-adaptive) must be in [0, 4] here: its largest patch, patch_mm * "
                          "2^n_adaptive = 14 * 2^5 = 448 mm, must fit the panel's shorter side, 364 mm (26 patches: "
                          "image_size_mm 360 in whole patches); got 5; use --n-adaptive 4 or less"),
    ("--n-adaptive", "32", "must be in [0, 4] here"),
    # named the job file's parameter alone and gave no fix ('overlap_mm must be in [0, (patch_mm -
    # min_piece_mm) / 2 = 4.5] so fragments stay >= min_piece_mm wide; got 5')
    ("--overlap-mm", "5", "overlap_mm (--overlap-mm) must be in [0, (patch_mm - min_piece_mm) / 2 = (14 - 5) / 2 "
                          "= 4.5] mm so every piece stays >= min_piece_mm wide; got 5 mm; use --overlap-mm 4.5 or "
                          "less, a larger --patch-mm or a smaller --min-piece-mm"),
])
def test_a_table_1_parameter_out_of_range_is_a_usage_error_naming_the_option(scans, capsys, option, value, said):
    """Sweep h6: these exited 1 (a failed work, where the README's exit statuses give 2 for a wrong
    command line) and named the job file's parameter ('w_intens must be in [0, 1]'), not the option."""
    argv = ["parquetry", str(scans / "coffee.png"), "--veneer", str(scans / "light.png"), option, value,
            "--out", str(scans / "o"), "--quiet"]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith("woodcam: error:") and said in err
    assert not (scans / "o").exists()

def _small_run(scans, out, *extra):
    return main(["parquetry", str(scans / "coffee.png"), "--veneer", f"{scans / 'light.png'}:2px/mm",
                 "--veneer", f"{scans / 'dark.png'}:2px/mm", "--image-size-mm", "42", "--px-per-mm", "2",
                 "--no-seams", "--out", str(out), "--quiet", *extra])


def test_an_interrupted_rerun_leaves_the_previous_files_whole(scans, capsys, monkeypatch):
    """Ctrl-C while the cut files were written left a new render.png and assembly.svg beside
    the previous run's result.json and sheets."""
    import woodcam.parquetry.output as output
    from woodcam.cli import EXIT_INTERRUPTED

    out = scans / "out"
    assert _small_run(scans, out) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}

    def interrupted(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(output, "write_dxf", interrupted)
    assert _small_run(scans, out, "--n-rot", "4", "--priority", "center") == EXIT_INTERRUPTED
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before   # no file changed, none added


def test_a_rerun_leaves_no_sheet_of_the_earlier_run(scans, capsys):
    """A rerun into the same folder left the earlier run's veneer_<id>.svg/.dxf (sheets this
    run does not cut, which a router would cut all the same) and its panel.glb under --no-glb."""
    out = scans / "out"
    assert _small_run(scans, out) == 0
    assert (out / "veneer_dark.svg").is_file() and (out / "veneer_dark.dxf").is_file()
    (out / "notes.txt").write_text("mine")
    assert main(["parquetry", str(scans / "coffee.png"), "--veneer", f"{scans / 'light.png'}:2px/mm",
                 "--image-size-mm", "42", "--px-per-mm", "2", "--no-seams", "--no-glb", "--out", str(out),
                 "--quiet"]) == 0
    result = json.loads((out / "result.json").read_text())
    assert {p["sheet"] for p in result["patches"]} == {"light"}
    assert sorted(p.name for p in out.iterdir()) == [
        ".woodcam-parquetry-files.json", "assembly.svg", "baseline.png", "job.json", "notes.txt", "render.png", "result.json",
        "target_matched.png", "veneer_light.dxf", "veneer_light.svg"]
    # removed with a word: the files were deleted silently
    err = capsys.readouterr().err
    assert "woodcam: warning: removed 3 file(s) of an earlier run" in err
    assert "panel.glb, veneer_dark.svg, veneer_dark.dxf" in err


def test_a_sheet_no_piece_is_cut_from_has_no_cut_file_in_the_result(scans, capsys):
    """result.json named veneer_<id>.svg for every sheet, also one no piece is cut from (not
    written, and removed as an earlier run's): null for it."""
    Image.fromarray(np.full((60, 60, 3), 235, np.uint8)).save(scans / "white.png")
    out = scans / "out"
    assert main(["parquetry", str(scans / "white.png"), "--veneer", f"{scans / 'light.png'}:2px/mm",
                 "--veneer", f"{scans / 'dark.png'}:2px/mm", "--image-size-mm", "20", "--px-per-mm", "2",
                 "--no-seams", "--no-glb", "--out", str(out), "--quiet"]) == 0
    result = json.loads((out / "result.json").read_text())
    assert len(result["patches"]) == 1  # one patch: one sheet cut, the other not
    used = result["patches"][0]["sheet"]
    files = {v["id"]: v["file_svg"] for v in result["veneers"]}
    assert set(files) == {"light", "dark"} and files[used] == f"veneer_{used}.svg"
    assert (out / files[used]).is_file()
    assert [files[i] for i in files if i != used] == [None]


def test_leaf_slicing_options_reach_the_job_file_blocks_or_are_named(scans, capsys):
    """--sheets, --species, --sheet-size ... were ignored without a word with only scans, and
    did not reach the blocks of a --config job ('options given here override it')."""
    out = scans / "out"
    assert _small_run(scans, out, "--sheets", "5", "--species", "walnut") == 0
    err = capsys.readouterr().err
    assert "--sheets, --species slice leaves from blocks" in err and "scans (--veneer)" in err
    job = json.loads((out / "job.json").read_text())
    job["woodcam"]["blocks"] = [{"spec": "builtin:flat-sawn", "sheets": 2, "width_mm": 80, "height_mm": 48}]
    (scans / "job.json").write_text(json.dumps(job))
    assert main(["parquetry", "--config", str(scans / "job.json"), "--species", "walnut", "--sheets", "1",
                 "--sheet-size", "70x46", "--out", str(scans / "out2"), "--quiet", "--no-glb"]) == 0
    assert "change nothing" not in capsys.readouterr().err
    sliced = [v for v in json.loads((scans / "out2" / "result.json").read_text())["veneers"]
              if v["id"].startswith("builtin")]
    assert [(v["id"], v["size_mm"]) for v in sliced] == [("builtin-flat-sawn-walnut-00", [70.0, 46.0])]


def test_a_slicing_option_typed_at_its_default_still_overrides_the_job_file(scans, capsys):
    """--sheets 2 (the default's value) did not reach a --config job's block of one sheet: a
    typed value was told from the default by its value."""
    out = scans / "out"
    assert _small_run(scans, out) == 0
    job = json.loads((out / "job.json").read_text())
    job["woodcam"]["blocks"] = [{"spec": "builtin:flat-sawn", "sheets": 1, "width_mm": 70, "height_mm": 46}]
    (scans / "job.json").write_text(json.dumps(job))
    assert main(["parquetry", "--config", str(scans / "job.json"), "--sheets", "2",
                 "--out", str(scans / "out2"), "--quiet", "--no-glb"]) == 0
    sliced = [v["id"] for v in json.loads((scans / "out2" / "result.json").read_text())["veneers"]
              if v["id"].startswith("builtin")]
    assert len(sliced) == 2, sliced


def test_two_scans_of_the_same_file_name_get_their_own_sheets(scans, capsys):
    """a/oak.png and b/oak.png were both 'oak' and the run was refused ('veneer ids must be
    unique'), with no way to name a scan on the command line."""
    for name, src in (("a", "light"), ("b", "dark")):
        (scans / name).mkdir()
        (scans / name / "oak.png").write_bytes((scans / f"{src}.png").read_bytes())
    out = scans / "out"
    assert main(["parquetry", str(scans / "coffee.png"), "--veneer", f"{scans / 'a' / 'oak.png'}:2px/mm",
                 "--veneer", f"{scans / 'b' / 'oak.png'}:2px/mm", "--image-size-mm", "42", "--px-per-mm", "2",
                 "--no-seams", "--no-glb", "--out", str(out), "--quiet"]) == 0
    result = json.loads((out / "result.json").read_text())
    assert [(v["id"], v["source"].split("/")[-2]) for v in result["veneers"]] == [("oak-1", "a"), ("oak-2", "b")]
    assert {p["sheet"] for p in result["patches"]} == {"oak-1", "oak-2"}   # light and dark wood both used
    assert (out / "veneer_oak-1.svg").is_file() and (out / "veneer_oak-2.dxf").is_file()
    # the same block sliced twice gives the same leaves twice: refused, saying what to do
    assert main(["parquetry", str(scans / "coffee.png"), "--veneer-from", "builtin:flat-sawn",
                 "--veneer-from", "builtin:flat-sawn", "--sheet-size", "60x50", "--out", str(out), "--quiet"]) == 1
    assert "slice a block once, with more --sheets" in capsys.readouterr().err


def test_reused_wood_says_the_cut_files_cannot_be_cut(scans, capsys):
    """--reuse-wood wrote cut files whose pieces overlap on the sheets and printed '0 pieces
    with problems left', exit 0, without a word that they cannot be cut."""
    out = scans / "out"
    assert _small_run(scans, out, "--reuse-wood") == 0
    text = capsys.readouterr().out
    assert "pieces overlap on the veneer sheets, so the cut files cannot be cut" in text
    assert json.loads((out / "result.json").read_text())["summary"]["single_use"] is False


def test_a_scan_that_states_its_dpi_is_not_sized_by_the_default_without_a_word(scans, capsys):
    """--veneer SCAN without :DPI used 300 dpi over a scan tagged 101.6 dpi (every piece cut at a
    third of its size, silently): the tag is named with the fix; a typed :DPI says nothing."""
    Image.open(scans / "light.png").save(scans / "tagged.png", dpi=(101.6, 101.6))
    argv = ["parquetry", str(scans / "coffee.png"), "--image-size-mm", "28", "--px-per-mm", "2",
            "--no-glb", "--quiet", "--veneer", f"{scans / 'dark.png'}:2px/mm"]
    # sized at 300 dpi (27 x 20 mm) the sheet is too small for a patch with its overlap (25 mm;
    # a square piece of --no-seams, 18 mm, would fit): the warning says why
    assert main(argv + ["--veneer", str(scans / "tagged.png"), "--out", str(scans / "a")]) == 1
    err = capsys.readouterr().err
    assert "the file states 101.6 dpi, but no resolution was given, so the default 300 dpi was used; " \
           f"give the resolution the sheet was scanned at: {scans / 'tagged.png'}:101.6 if the file's" in err
    assert main(argv + ["--veneer", f"{scans / 'tagged.png'}:101.6", "--out", str(scans / "b")]) == 0
    assert "warning" not in capsys.readouterr().err


def test_a_placeholder_dpi_is_no_stated_resolution(scans):
    """A phone JPEG's EXIF/JFIF 72 dpi and a GIMP PNG's 72.009 (pHYs 2835 px/m) were read as
    the scan's resolution: the warning fired on ordinary files and its fix, SCAN:72, sized the
    sheet ~4x too large. 72 and 96 dpi (and their roundings) now state nothing."""
    from woodcam.parquetry.veneers import dpi_tag

    im = Image.open(scans / "light.png")
    for name, dpi in (("phone.jpg", 72), ("gimp.png", 72.009), ("win.png", 96.012), ("cm.jpg", 71.12),
                      ("scan.png", 75), ("scan2.png", 150)):
        im.convert("RGB").save(scans / name, dpi=(dpi, dpi))
    assert [dpi_tag(scans / n) for n in ("phone.jpg", "gimp.png", "win.png", "cm.jpg")] == [None] * 4
    assert round(dpi_tag(scans / "scan.png")) == 75 and round(dpi_tag(scans / "scan2.png")) == 150
    from woodcam.cli.parquetry import _scan_entry

    assert _scan_entry(str(scans / "phone.jpg"))["dpi"] == 300  # no warning (they are errors here)
    with pytest.warns(WoodcamWarning, match=r"states 150 dpi.*scan2.png:150 if the file's is right"):
        _scan_entry(str(scans / "scan2.png"))


def test_a_target_of_a_few_pixels_is_made_and_its_ssim_said_to_have_no_value(scans, capsys):
    """A 4 x 4 px target (pixel art: a pixel a patch) was matched, seamed and cut, then the
    summary's SSIM on the target's own pixels raised skimage's ValueError (fewer pixels than
    its 7 x 7 window): an internal error, nothing written. Now made, that SSIM n/a."""
    Image.fromarray(np.asarray(Image.open(scans / "coffee.png"))[::100, ::150][:4, :4]).save(
        scans / "tiny.png")
    out = scans / "out"
    assert main(["parquetry", str(scans / "tiny.png"), "--veneer", f"{scans / 'light.png'}:2px/mm",
                 "--veneer", f"{scans / 'dark.png'}:2px/mm", "--image-size-mm", "56", "--px-per-mm",
                 "2", "--no-glb", "--out", str(out), "--quiet"]) == 0
    text = capsys.readouterr().out
    assert "on the target's own 4 x 4 pixels" in text
    assert "SSIM n/a (fewer pixels than its 7 x 7 window)" in text
    panel = json.loads((out / "result.json").read_text())["summary"]["panels"][0]
    assert panel["ssim_native"] is None and panel["ssim_native_baseline"] is None
    assert panel["native_grid"] == "target" and panel["native_px"] == panel["target_px"] == [4, 4]
    assert 0 < panel["ssim"] <= 1 and len(panel["cells"]) == 2 and panel["patches"] == 16


def test_a_target_finer_than_the_working_grid_is_not_said_measured_on_its_own_pixels(scans, capsys):
    """coffee.png (400 x 600 px) on a 56 mm panel at 2 px/mm (a 112 px working grid): the
    'native' figures fall back to the working grid, yet the summary said they were 'on the
    target's own 600 x 400 pixels' and result.json's native_px gave the target's pixels. Now
    the line says its pixels are finer than the working grid, and native_px is the grid measured."""
    out = scans / "out"
    assert main(["parquetry", str(scans / "coffee.png"), "--veneer", f"{scans / 'light.png'}:2px/mm",
                 "--veneer", f"{scans / 'dark.png'}:2px/mm", "--image-size-mm", "56", "--px-per-mm",
                 "2", "--no-glb", "--out", str(out), "--quiet"]) == 0
    text = capsys.readouterr().out
    panel = json.loads((out / "result.json").read_text())["summary"]["panels"][0]
    working = [panel["cells"][0] * 28, panel["cells"][1] * 28]  # 14 mm patches at 2 px/mm
    assert panel["native_grid"] == "working" and panel["native_px"] == working
    assert panel["target_px"][0] == 400 and panel["target_px"][0] > working[0]
    assert panel["feature_cost_native"] == panel["feature_cost"] and panel["ssim_native"] == panel["ssim"]
    assert "on the target's own" not in text
    assert (f"the target's own {panel['target_px'][1]} x 400 pixels are finer than the "
            f"{working[1]} x {working[0]} px working grid") in text


def test_a_job_file_texture_without_an_id_is_named_by_its_file(scans, capsys):
    """The reference code's 'id' is optional, but a source texture without one was a KeyError
    from the CLI (an internal error); now its file's stem, as for --veneer. An id that is no
    name is refused naming the entry."""
    job = {"source_textures": [{"texture": "light.png", "dpi": 50.8}, {"texture": "dark.png", "dpi": 50.8}],
           "targets": [{"filename": "coffee.png", "scale": 1.0}]}
    (scans / "job.json").write_text(json.dumps(job))
    out = scans / "out"
    assert main(["parquetry", "--config", str(scans / "job.json"), "--image-size-mm", "42", "--px-per-mm",
                 "2", "--no-seams", "--no-glb", "--out", str(out), "--quiet"]) == 0
    assert [v["id"] for v in json.loads((out / "result.json").read_text())["veneers"]] == ["light", "dark"]
    job["source_textures"][0]["id"] = 5
    (scans / "job.json").write_text(json.dumps(job))
    assert main(["parquetry", "--config", str(scans / "job.json"), "--out", str(out), "--quiet"]) == 1
    assert "source_textures[0].id must be a name (a string, it names veneer_<id>.svg); got 5" in \
        capsys.readouterr().err


@pytest.mark.parametrize("bad", ["x/../../escape", "..\\escape", "a\nb"])
def test_a_veneer_id_that_is_no_file_name_part_is_refused(scans, capsys, bad):
    """A veneer's id names its cut files veneer_<id>.svg/.dxf in the output folder: a job file's
    "id": "x/../../escape" wrote them in its parent folder (making veneer_x/ on the way).
    Refused at the door, the job file's entry named and nothing written; the library door (build_parquetry) refuses the same; a dotted id
    that is one file-name part is fine."""
    from woodcam.parquetry import build_parquetry, load_scan

    job = {"source_textures": [{"texture": "light.png", "dpi": 50.8, "id": bad},
                               {"texture": "dark.png", "dpi": 50.8, "id": "dark"}],
           "targets": [{"filename": "coffee.png", "scale": 1.0}]}
    (scans / "job.json").write_text(json.dumps(job))
    out = scans / "deep" / "out"
    assert main(["parquetry", "--config", str(scans / "job.json"), "--image-size-mm", "42", "--px-per-mm",
                 "2", "--no-seams", "--no-glb", "--out", str(out), "--quiet"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "source_textures[0].id must be one file-name part" in err, err
    assert not (scans / "deep").exists() and not list(scans.rglob("*escape*"))
    light = load_scan(scans / "light.png", dpi=50.8, id="light")
    light.id = bad
    with pytest.raises(WoodcamError, match=r"veneers\[0\]\.id must be one file-name part"):
        build_parquetry([np.full((8, 8), 0.5, np.float32)], [light])
    job["source_textures"][0]["id"] = "oak.v2-1"
    (scans / "job.json").write_text(json.dumps(job))
    assert main(["parquetry", "--config", str(scans / "job.json"), "--image-size-mm", "42", "--px-per-mm",
                 "2", "--no-seams", "--no-glb", "--out", str(out), "--quiet"]) == 0
    assert [v["id"] for v in json.loads((out / "result.json").read_text())["veneers"]] == ["oak.v2-1", "dark"]


def test_veneer_ids_that_differ_only_in_case_are_refused(scans):
    """'Oak' and 'oak' passed the uniqueness check, yet name one veneer_oak.svg on a
    case-insensitive file system (one sheet's cut files over the other's)."""
    from woodcam.parquetry import build_parquetry, load_scan

    a = load_scan(scans / "light.png", dpi=50.8, id="Oak")
    b = load_scan(scans / "dark.png", dpi=50.8, id="oak")
    with pytest.raises(WoodcamError, match=r"unique, letter case aside .* got \['Oak', 'oak'\]"):
        build_parquetry([np.full((8, 8), 0.5, np.float32)], [a, b])


def test_the_job_file_of_a_run_with_relative_paths_reruns_from_anywhere(scans, capsys, monkeypatch):
    """job.json kept the paths as typed (coffee.png, relative to the working folder) and a job
    file's paths are read relative to its own folder: --config out/job.json looked for
    out/coffee.png ('No such file'). Now written absolute."""
    monkeypatch.chdir(scans)
    assert main(["parquetry", "coffee.png", "--veneer", "light.png:2px/mm:dark_mask.png", "--veneer",
                 "dark.png:2px/mm", "--image-size-mm", "42", "--px-per-mm", "2", "--no-seams", "--no-glb",
                 "--out", "out", "--quiet"]) == 0
    job = json.loads((scans / "out" / "job.json").read_text())
    assert job["targets"][0]["filename"] == str(scans / "coffee.png")
    assert job["source_textures"][0]["mask"] == str(scans / "dark_mask.png")
    (scans / "elsewhere").mkdir()
    monkeypatch.chdir(scans / "elsewhere")
    assert main(["parquetry", "--config", "../out/job.json", "--out", "again", "--quiet", "--no-glb"]) == 0
    first, again = (json.loads((scans / d / "result.json").read_text())["patches"]
                    for d in ("out", "elsewhere/again"))
    assert [p["anchor_px"] for p in again] == [p["anchor_px"] for p in first]


def test_sheet_size_errors_speak_the_units_it_was_typed_in(scans, capsys):
    """Under --units inch, '--sheet-size 0x1' said "takes WxH in mm ...; got '0x25.4'" (the size
    --units had turned into mm), and leaves past the block said "give --sheet-size 100x50 mm or
    smaller": typed as said, read as inches, 2540 x 1270 mm, refused again. Now the text as
    typed, the rule, the sizes and the fix in --units (a block spec's size too: --veneer-from
    reads it in --units), and the fix it gives is taken."""
    out = scans / "out"
    inch = ["--veneer-from", "builtin:flat-sawn", "--no-glb", "--units", "inch"]
    assert _small_run(scans, out, *inch, "--sheet-size", "0x1") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and ("--sheet-size takes WxH in inches (--units inch), 2 numbers in (0, 393.701] "
                                     "(raise it with WOODCAM_MAX_BLOCK_SIZE_MM=N), e.g. 2x2; got '0x1'") in err, err
    assert _small_run(scans, out, *inch, "--sheet-size", "100x50") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "leaves of 100 x 50 in (--sheet-size" in err, err
    assert "its 3.937 x 3.15 x 1.969 in block's face normal to y (--slice-axis) is 3.937 x 1.969 in" in err, err
    assert "(builtin:flat-sawn:100x3.14961x50)" in err, err  # in inches, as --veneer-from reads it
    fix = err.split("give --sheet-size ")[1].split(" in or smaller")[0]
    assert fix == "3.93701x1.968504", fix
    assert _small_run(scans, out, *inch, "--sheet-size", fix) == 0
    capsys.readouterr()
    assert _small_run(scans, out, *inch, "--sheets", "30", "--leaf-thickness", "0.1") == 2
    assert ("30 leaves (--sheets) of 0.1 in + 0.01575 in kerf, sliced from the middle of builtin:flat-sawn along y, "
            "reach 5.031 in into its 3.15 in: past its back face") in capsys.readouterr().err


def test_a_veneer_from_spec_size_is_read_in_units_as_bake_reads_its_block(scans, capsys):
    """'--veneer-from builtin:flat-sawn:4x3x2 --units inch' sliced a 4 x 3 x 2 mm block (the
    spec's :WxDxH read in mm whatever --units said) where 'bake --block' reads the same spec
    in inches. Now the spec is read in --units at the door, as bake's: its block is 4 x 3 x 2
    in, job.json keeps it in mm, its errors quote it as typed and speak inches."""
    out = scans / "out"
    inch = ["--no-glb", "--units", "inch"]
    assert _small_run(scans, out, *inch, "--veneer-from", "builtin:flat-sawn:4x3x2", "--sheet-size", "5x1") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and ("do not fit builtin:flat-sawn:4x3x2: its 4 x 3 x 2 in block's face normal "
                                     "to y (--slice-axis) is 4 x 2 in") in err, err
    assert _small_run(scans, out, *inch, "--veneer-from", "builtin:flat-sawn:4x3x2", "--sheet-size", "1x1") == 0
    capsys.readouterr()
    blocks = json.loads((out / "job.json").read_text())["woodcam"]["blocks"]
    assert [b["spec"] for b in blocks] == ["builtin:flat-sawn:101.6x76.2x50.8"], blocks
    assert _small_run(scans, out, *inch, "--veneer-from", "builtin:flat-sawn:0x1x1") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and ("--veneer-from builtin:flat-sawn:0x1x1: the size must be WxDxH in "
                                     "--units inch") in err, err


def test_a_scan_given_no_resolution_and_too_small_says_it_was_read_at_300_dpi(scans, capsys):
    """A --veneer given no resolution (a photo's file states none) is read at 300 dpi, and one
    then smaller than a patch was refused as '21.8 x 21.8 mm' (a Mokume face photo, 256 px of
    a 50 mm face) with no word that the size came of a default, not of the wood. Now its pixels
    and the default are said, with the fix; a resolution given says neither."""
    from skimage import data

    small = scans / "small.png"
    Image.fromarray(data.coffee()[:128, :96]).save(small)  # 96 x 128 px: 8.1 x 10.8 mm at 300 dpi (8.2 on the 4 px/mm grid)
    out = scans / "out"
    args = ["parquetry", str(scans / "coffee.png"), "--image-size-mm", "42", "--no-glb", "--quiet", "--out", str(out)]
    assert main([*args, "--veneer", str(small), "--veneer", f"{scans / 'light.png'}:2px/mm"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and (f"veneer 'small' is 8.2 x 10.8 mm (96 x 128 px at the default 300 dpi, as its "
                                     f"--veneer gives no resolution; give the one it was scanned at: --veneer "
                                     f"{small}:DPI), smaller than one patch") in err, err
    assert main([*args, "--veneer", f"{small}:300"]) == 1
    err = capsys.readouterr().err
    assert "veneer 'small' is 8.2 x 10.8 mm, smaller than one patch" in err and "default 300 dpi" not in err, err


def test_a_sheet_smaller_than_a_patch_names_what_the_user_set(scans, capsys):
    """'--tool-diameter 90' made every sheet smaller than one patch and the kerf round it, and
    the error said 'use ... a smaller patch_mm or a smaller kerf_mm': a job file's keys, and a
    kerf never typed (it defaults to the tool diameter). Now the options as typed (in
    --units), the job file's keys where it set them, and the defaults said as such."""
    out = scans / "out"
    assert _small_run(scans, out, "--no-glb", "--tool-diameter", "90") == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "patch_mm" not in err and "kerf_mm" not in err, err
    assert ("smaller than one patch (--patch-mm default 14) and the kerf round it (--kerf-mm not given: the "
            "tool diameter, --tool-diameter 90)") in err, err
    assert "use larger sheets, a smaller --patch-mm, or a smaller kerf (--kerf-mm, in mm)" in err, err
    assert _small_run(scans, out, "--no-glb", "--units", "inch", "--tool-diameter", "3.5") == 1
    err = capsys.readouterr().err
    assert "--tool-diameter 3.5)" in err and "veneer 'light' is 6.299 x 4.724 in" in err, err
    job = scans / "job.json"
    job.write_text(json.dumps({"targets": [{"filename": str(scans / "coffee.png")}],
                               "source_textures": [{"texture": str(scans / "light.png"), "px_per_mm": 2}],
                               "woodcam": {"params": {"kerf_mm": 90, "overlap_mm": 3, "image_size_mm": 42,
                                                      "px_per_mm": 2}}}))
    assert main(["parquetry", "--config", str(job), "--out", str(out), "--quiet", "--no-glb",
                 "--patch-mm", "20"]) == 1
    err = capsys.readouterr().err
    assert (f"one patch (--patch-mm 20) with its overlap (woodcam.params.overlap_mm 3 in {job}) and the kerf "
            f"round it (woodcam.params.kerf_mm 90 in {job})") in err, err


def test_leaves_beyond_their_block_are_refused_naming_the_sizes(scans, capsys):
    """'--veneer-from builtin:flat-sawn' sliced the default 600 x 400 mm leaves from its
    100 x 80 x 50 mm block, and any --sheet-size or --sheets past the block ran without a word:
    wood of the field outside the block, which the block does not hold (for a fitted or grown
    block an extrapolation). Now a leaf larger than the block's face, or leaves past its back
    face, are refused naming the sizes and the fix (also from a job file), and the default
    leaf is 600 x 400 mm or the block's face where smaller. Leaves the command line sized
    (--veneer-from, --sheet-size, --sheets, also over a job's blocks) are a usage error, exit 2
    and one line, as gcode --stock past its block (they exited 1); a job file's own, 1."""
    out = scans / "out"
    flat = ["--veneer-from", "builtin:flat-sawn", "--no-glb"]
    assert _small_run(scans, out, *flat, "--sheet-size", "120x40") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and ("leaves of 120 x 40 mm (--sheet-size; width_mm, height_mm in a job file) do not fit "
                                     "builtin:flat-sawn: its 100 x 80 x 50 mm block's face normal to y (--slice-axis) is "
                                     "100 x 50 mm") in err
    assert "give --sheet-size 100x40 mm or smaller, or a block of 120 x 80 x 50 mm that holds them " \
           "(builtin:flat-sawn:120x80x50)" in err
    assert _small_run(scans, out, *flat, "--sheet-size", "40x60", "--slice-axis", "z") == 0  # face 100 x 80
    capsys.readouterr()
    assert _small_run(scans, out, *flat, "--sheets", "60") == 2
    assert ("60 leaves (--sheets) of 0.6 mm + 0.4 mm kerf, sliced from the middle of builtin:flat-sawn along y, "
            "reach 99.6 mm into its 80 mm: past its back face") in capsys.readouterr().err
    job = json.loads((out / "job.json").read_text())
    job["woodcam"]["blocks"] = [{"spec": "builtin:flat-sawn", "sheets": 1, "width_mm": 80, "height_mm": 60}]
    (scans / "job.json").write_text(json.dumps(job))
    assert main(["parquetry", "--config", str(scans / "job.json"), "--out", str(scans / "out2"), "--quiet",
                 "--no-glb"]) == 1
    assert "leaves of 80 x 60 mm" in capsys.readouterr().err
    # the job's block given leaf options here: the command line sized them
    assert main(["parquetry", "--config", str(scans / "job.json"), "--out", str(scans / "out2"), "--quiet",
                 "--no-glb", "--sheets", "60", "--sheet-size", "40x40"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "60 leaves (--sheets)" in err, err
    # the default: the block's 100 x 50 mm face, not 600 x 400 mm of wood round it
    assert _small_run(scans, out, *flat) == 0
    result = json.loads((out / "result.json").read_text())
    assert [v["size_mm"] for v in result["veneers"] if v["id"].startswith("builtin")] == [[100.0, 50.0]] * 2


def test_no_seams_pieces_take_no_overlap_of_wood(scans, capsys):
    """--no-seams (README: '--no-seams or 0: square pieces') cut square 14 mm pieces but matched
    each with its 3.5 mm overlap, so every piece took 21 mm + kerf of the sheet: on the two
    100 x 50 mm leaves of builtin:flat-sawn the wood ran out at 10 of 16 cells where
    --overlap-mm 0, the same square pieces, placed 15. Now --no-seams is overlap 0 (job.json
    replays it), and an --overlap-mm given with it is said to change nothing."""
    Image.open(scans / "coffee.png").crop((100, 0, 500, 400)).save(scans / "square.png")

    def run(out, *extra):
        rc = main(["parquetry", str(scans / "square.png"), "--veneer-from", "builtin:flat-sawn",
                   "--image-size-mm", "56", "--no-glb", "--quiet", "--out", str(scans / out), *extra])
        return rc, json.loads((scans / out / "result.json").read_text())

    rc, seams = run("seams")
    rc_square, square = run("square", "--overlap-mm", "0")
    assert run("no_seams", "--no-seams")[0] == rc_square
    no_seams = json.loads((scans / "no_seams" / "result.json").read_text())
    assert no_seams["params"]["overlap_mm_used"] == 0
    assert no_seams["summary"]["placed_cells"] == square["summary"]["placed_cells"] > seams["summary"]["placed_cells"]
    assert [p["anchor_px"] for p in no_seams["patches"]] == [p["anchor_px"] for p in square["patches"]]
    assert json.loads((scans / "no_seams" / "job.json").read_text())["woodcam"]["params"]["overlap_mm"] == 0
    capsys.readouterr()
    run("no_seams", "--no-seams", "--overlap-mm", "2")
    assert ("woodcam: warning: --overlap-mm 2 changes nothing with --no-seams: square pieces are matched and "
            "cut without an overlap; drop one of them") in capsys.readouterr().err


@pytest.mark.parametrize("extra, said", [
    (["--image-size-mm", "60"], "--image-size-mm 60 makes a panel whose shorter side is 56 mm: 4 whole patches of "
                                "--patch-mm default 14; give --image-size-mm 56 or 70 (mm, whole patches)"),
    (["--image-size-mm", "60", "--units", "inch"], "--image-size-mm 60 makes a panel whose shorter side is 2.205 in: "),
    (["--patch-mm", "25"], "--image-size-mm default 360 makes a panel whose shorter side is 350 mm: 14 whole patches "
                           "of --patch-mm 25; give --image-size-mm 350 or 375"),
    (["--image-size-mm", "56"], None),  # whole patches: nothing to say
    (["--patch-mm", "20"], None),       # 360 = 18 patches of 20
])
def test_a_panel_rounded_to_whole_patches_is_said(scans, capsys, monkeypatch, extra, said):
    """'--image-size-mm 60' made a 56 mm panel (whole 14 mm patches) without a word: a warning
    names the option as set, the size made (in --units) and the whole-patch sizes to give."""
    import woodcam.parquetry.job as job_module

    def stop(*_a, **_k):  # the panel's size is known before the veneers are read: no run needed
        raise WoodcamError("stopped before the veneers")

    monkeypatch.setattr(job_module, "job_veneers", stop)
    assert main(["parquetry", str(scans / "coffee.png"), "--veneer", str(scans / "light.png"), *extra,
                 "--out", str(scans / "o"), "--quiet"]) == 1
    err = capsys.readouterr().err
    warned = [line for line in err.splitlines() if "makes a panel" in line]
    if said is None:
        assert warned == [], err
    else:
        assert len(warned) == 1 and warned[0].startswith(f"woodcam: warning: {said}"), err


def test_two_targets_of_the_same_file_name_get_names_one_can_foresee(scans, capsys):
    """a/cam64.png and b/cam64.png were written as render_cam640.png and render_cam641.png (the
    index glued to the stem), names no user could foresee, without a word. Now they are
    numbered as --veneer numbers its scans, cam64-1 and cam64-2, and a warning names each."""
    for name in ("a", "b"):
        (scans / name).mkdir()
        Image.open(scans / "coffee.png").resize((32, 24)).save(scans / name / "cam64.png")
    out = scans / "out"
    rc = main(["parquetry", str(scans / "a" / "cam64.png"), str(scans / "b" / "cam64.png"),
               "--veneer", f"{scans / 'light.png'}:2px/mm", "--image-size-mm", "14", "--px-per-mm", "2",
               "--n-rot", "1", "--no-seams", "--no-glb", "--out", str(out), "--quiet"])
    text = capsys.readouterr().err
    assert rc == 0, text
    assert "woodcam: warning: targets share a file name" in text and (f"{scans / 'a' / 'cam64.png'} as cam64-1; {scans / 'b' / 'cam64.png'} as cam64-2; rename the "
            "files to choose the names") in text, text
    assert sorted(f.name for f in out.glob("render_*.png")) == ["render_cam64-1.png", "render_cam64-2.png"]
    assert [p["name"] for p in json.loads((out / "result.json").read_text())["summary"]["panels"]] == \
        ["cam64-1", "cam64-2"]


def test_every_parquetry_option_says_its_default_and_unit():
    """'--veneer-from SPEC ... (default: not set)' and '--config JOB.json ... (default: not set)'
    said nothing of what the run takes without them; '--n-rot' ('rotations of each sheet') named
    no angle, '--overlap-mm's default '= 3.5' held only at the defaults of two other options."""
    import argparse

    from woodcam.cli import _walk_options, build_parser

    helps = {a.option_strings[-1]: " ".join((a.help or "").split())
             for path, a in _walk_options(build_parser()) if path == ["parquetry"]
             and not isinstance(a, (argparse._StoreTrueAction, argparse._HelpAction)) and not a.required}
    assert {"--config", "--veneer-from", "--n-rot", "--overlap-mm", "--kerf-mm"} <= set(helps), sorted(helps)
    unsaid = {o: h for o, h in helps.items() if "default" not in h.lower() or "not set" in h}
    assert not unsaid, unsaid
    assert "(default: none, the targets and veneers given here)" in helps["--config"]
    assert "default: none, the veneers are the --veneer scans and the --config job's" in helps["--veneer-from"]
    assert "360/N degrees apart, in [1, 360] (default 15: every 24 degrees)" in helps["--n-rot"]
    assert "3.5 mm at their defaults" in helps["--overlap-mm"]


def _but_the_cut(err: str) -> str:
    """``err`` without the warning that _small_run's coffee (3:2) is cut to its panel's 4 x 3
    patches of 42 mm (test_a_target_cut_to_whole_patches_is_said)."""
    return "".join(line for line in err.splitlines(keepends=True)
                   if not line.startswith("woodcam: warning: coffee: the panel is "))


def test_a_job_file_spec_is_read_in_mm_under_units_inch_and_said(scans, capsys):
    """A --config job file's 'builtin:flat-sawn:80x40x60' was read in mm under --units inch,
    where the same spec given as --veneer-from is read in inches, without a word. A job file's
    lengths are mm (its *_mm keys, its specs as job.json writes them): read so, and said under
    --units inch with the spec in mm of the inches it may have meant; nothing said in mm. The
    job.json woodcam writes says its unit (woodcam.units "mm"): its replay under --units inch
    warned of each spec too, and is silent now."""
    from woodcam.parquetry.job import read_job

    job = scans / "job.json"
    job.write_text(json.dumps({"targets": [{"filename": "coffee.png"}],
                               "woodcam": {"blocks": [{"spec": "builtin:flat-sawn:80x40x60"},
                                                      {"spec": "builtin:flat-sawn"}]}}))
    out = scans / "out"
    run = ["--config", str(job), "--sheets", "1", "--sheet-size", "1.5x1.5", "--no-glb"]
    assert _small_run(scans, out, *run, "--units", "inch") == 0
    err = _but_the_cut(capsys.readouterr().err)
    assert err.count("woodcam: warning:") == 1, err
    assert (f"--config {str(job)!r}: woodcam.blocks[0].spec 'builtin:flat-sawn:80x40x60' is read in mm, not in "
            "--units inch: a job file's lengths are mm (its *_mm keys, its block specs' sizes, as job.json is "
            "written); --units reads the command line's only; if it means inches, write it in mm: "
            "'builtin:flat-sawn:2032x1016x1524'") in err, err
    blocks = json.loads((out / "job.json").read_text())["woodcam"]["blocks"]
    assert blocks[0]["spec"] == "builtin:flat-sawn:80x40x60" and blocks[0]["width_mm"] == pytest.approx(38.1)
    assert _small_run(scans, scans / "out-mm", *run[:-3], "--sheet-size", "40x40", "--no-glb") == 0
    assert "warning" not in _but_the_cut(capsys.readouterr().err)
    # woodcam's own job.json says its lengths are mm: its replay under --units inch has nothing
    # to warn of (it warned of each spec, as the hand-written file's)
    written = json.loads((out / "job.json").read_text())
    assert main(["parquetry", "--config", str(out / "job.json"), "--out", str(scans / "out-replay"),
                 "--quiet", "--units", "inch", "--no-glb"]) == 0
    assert "warning" not in _but_the_cut(capsys.readouterr().err)
    assert written["woodcam"]["units"] == "mm"
    assert (json.loads((scans / "out-replay" / "job.json").read_text())["woodcam"]["blocks"]
            == written["woodcam"]["blocks"])
    # a hand-written file that says so is read alike; any other unit is refused
    said = scans / "said.json"
    said.write_text(json.dumps({"targets": [{"filename": "coffee.png"}],
                                "woodcam": {"units": "mm", "blocks": [{"spec": "builtin:flat-sawn:80x40x60"}]}}))
    assert read_job(said).units_said and not read_job(job).units_said
    said.write_text(json.dumps({"targets": [{"filename": "coffee.png"}], "woodcam": {"units": "inch"}}))
    with pytest.raises(WoodcamError, match=r"woodcam.units must be 'mm' .*; got 'inch'"):
        read_job(said)


def test_the_default_panel_size_is_said_and_too_little_wood_up_front(scans, capsys):
    """A run with no --image-size-mm made a 364 mm panel (the paper's 360 in whole 14 mm
    patches) said only as '364 x 546 mm' in the summary, in mm under --units inch, and a scan
    far too small for it went on to 'ran out of free wood' with no word of how much wood the
    panel takes. Now the default size is said as the run's choice, in --units, and the wood
    short of the panel is said before the matching, with what it takes."""
    out = scans / "out"
    rc = main(["parquetry", str(scans / "coffee.png"), "--veneer", f"{scans / 'light.png'}:2px/mm",
               "--px-per-mm", "2", "--n-rot", "1", "--no-glb", "--units", "inch", "--out", str(out), "--quiet"])
    cap = capsys.readouterr()
    assert rc == 3, cap
    assert ("panel: shorter side 14.33 in (364 mm), the default --image-size-mm 360 (the paper's) in whole patches "
            "of 14 mm, the target's aspect kept; give --image-size-mm (mm) to choose it") in cap.out, cap.out
    assert "coffee: 39 x 26 cells, 546 x 364 mm (21.5 x 14.33 in)," in cap.out, cap.out
    # the wood: 320 x 240 px at 2 px/mm less 2 px (half the default 2 mm kerf, the tool
    # diameter) at each edge, 316 x 236 px = 18644 mm^2; the panel's 39 x 26 cells of 28 px,
    # each window 7 px (3.5 mm) wider on the sides inside the panel: (37 * 42 + 2 * 35) x (24 *
    # 42 + 2 * 35) px, each window also grown by half the 4 px kerf: + 4 (h + w) + pi 4 px^2
    sw, sh = 37 * 42 + 2 * 35, 24 * 42 + 2 * 35
    wood = 316 * 236 / 4 / 25.4 ** 2
    need = (sw * sh + 4 * (39 * sh + 26 * sw) + 1014 * np.pi * 4) / 4 / 25.4 ** 2
    assert (f"woodcam: warning: the veneers cannot cover the panel (coffee 21.5 x 14.33 in): they hold {wood:.4g} "
            "in^2 of usable wood half the kerf in from its edges, and the 1014 patches of 0.5512 in, each piece with "
            "its 0.1378 in overlap and the 0.07874 in kerf round it, every piece of wood used once, take at least "
            f"{need:.4g} in^2, so at most {100 * wood / need:.2g}% of it can be "
            f"made; add at least {need - wood:.4g} in^2 of veneer, or make the panel smaller (image_size_mm, "
            "--image-size-mm)") in cap.err, cap.err
    assert "make the panel smaller (image_size_mm, --image-size-mm)" in cap.out
    # a size given, and wood enough: neither line
    assert _small_run(scans, out, "--no-glb") == 0
    cap = capsys.readouterr()
    assert "panel:" not in cap.out and "cannot cover" not in cap.err, cap


def _upper_cased_cn03(shared_data, tmp_path):
    """A copy of the Mokume sample CN03 with every file name upper-cased (``A_COL.PNG``), as a
    case-insensitive file system keeps a folder renamed or unpacked so."""
    import shutil

    src = shared_data / "mokume" / "CN03"
    if not src.is_dir():
        pytest.skip(f"Mokume sample CN03 not found under {shared_data}")
    folder = tmp_path / "CN03"
    folder.mkdir()
    for f in src.iterdir():
        shutil.copyfile(f, folder / f.name.upper())
    return folder


def test_mokume_veneers_read_a_sample_named_upper_case(shared_data, tmp_path):
    """mokume_veneers globbed '?_col.png' only: an upper-cased CN03 was "holds no face photos",
    while block folders read the names in any case (block.io.mokume_files, now the one home)."""
    from woodcam.parquetry.veneers import mokume_veneers

    got = mokume_veneers(_upper_cased_cn03(shared_data, tmp_path))
    want = mokume_veneers(shared_data / "mokume" / "CN03")
    assert [v.id for v in got] == [v.id for v in want] == [f"CN03-{x}" for x in "ABCDEF"]
    assert [Path(v.source).name for v in got] == [f"{x}_COL.PNG" for x in "ABCDEF"]
    for a, b in zip(got, want):
        assert a.px_per_mm == b.px_per_mm and np.array_equal(a.rgb, b.rgb)


def test_veneer_from_an_upper_case_mokume_folder_is_its_photos(shared_data, tmp_path, monkeypatch):
    """--veneer-from of an upper-cased Mokume folder was not seen as one (its '?_col.png' glob):
    it became a block spec, leaves sliced from the sample's fitted block instead of its six
    photos. Now it is a Mokume folder, as its lower-case original."""
    import woodcam.parquetry.job as job_module

    folder = _upper_cased_cn03(shared_data, tmp_path)
    seen = []

    def stop(job, **kw):
        seen.append((list(job.mokume), list(job.blocks)))
        raise WoodcamError("stop here")

    monkeypatch.setattr(job_module, "job_veneers", stop)
    target = tmp_path / "t.png"
    Image.fromarray(np.full((32, 32, 3), 128, np.uint8)).save(target)
    assert main(["parquetry", str(target), "--veneer-from", str(folder), "--out", str(tmp_path / "o"), "--quiet"]) != 0
    assert seen == [([str(folder)], [])]


def test_a_target_cut_to_whole_patches_is_said(scans, capsys):
    """The panel is whole patches, so a target's longer side is rounded down and cut centrally:
    coffee (600 x 400 px, 3:2) at --image-size-mm 42 made a 4 x 3 patch panel of 56 x 42 mm and
    lost 11 % of its width without a word (issue 19's walk-through). Said, with a nearby size
    that cuts nothing; a cut of whole patches (56 mm: 6 x 4) is not."""
    argv = ["parquetry", str(scans / "coffee.png"), "--veneer", f"{scans / 'light.png'}:50.8", "--veneer",
            f"{scans / 'dark.png'}:50.8", "--px-per-mm", "2", "--n-rot", "3", "--quiet", "--no-glb"]
    main(argv + ["--image-size-mm", "42", "--out", str(scans / "o42")])
    err = capsys.readouterr().err
    assert ("woodcam: warning: coffee: the panel is 4 x 3 whole patches of 14 mm (56 x 42 mm), so 11% of the "
            "target's width is cut off, 3.5 mm of panel at each end (the target is 600 x 400 px); give "
            "--image-size-mm 28 (0% cut), or crop the target to 4:3 yourself to choose what is left out") in err, err
    main(argv + ["--image-size-mm", "56", "--out", str(scans / "o56")])
    assert "is cut off" not in capsys.readouterr().err
