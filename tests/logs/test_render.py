"""Planar sections through a log and the `woodcam log` command."""

import re

import numpy as np
import pytest
from PIL import Image

from woodcam.cli import build_parser
from woodcam.errors import WoodcamError
from woodcam.fields.knots import KnottedLogField
from woodcam.fields.skeleton import BranchStrand, simple_log
from woodcam.logs import render as lr
from woodcam.logs.io import write_log


def _log():
    k = BranchStrand.from_model(0.25, 0.0, 300.0, 0.0, 0.0, 0.0, 0.0, 100.0, 45.0)   # dies at 45 mm
    return simple_log(knots=[k])


def test_section_pixel_centres():
    s = lr.Section((0, 0, 0), (1, 0, 0), (0, -1, 0), (10, 5), 2.0)
    p = s.points()
    assert p.shape == (10, 20, 3)
    assert np.allclose(p[0, 0], [0.25, -0.25, 0]) and np.allclose(p[-1, -1], [9.75, -4.75, 0])


def test_board_shows_the_knot_where_it_crosses():
    log = _log()
    f = KnottedLogField(log)
    s = lr.tangential_board(log, 300.0, 0.0, 70.0, length_mm=100, width_mm=60, px_per_mm=2)
    img = lr.render_section(f, s).astype(float)
    assert img.shape == (120, 200, 3)
    # the knot crosses the board (plane x = 70) at z = 300, y = 0: the image centre
    centre = img[55:65, 95:105].mean()
    clear = img[55:65, 10:20].mean()
    assert centre < 0.8 * clear                     # knot wood is darker
    # dead at 70 mm: a dark outline ring ~5.6 mm (0.125 * 45) from the centre
    ring = img[60, 100 + 9:100 + 14].min()
    assert ring < 0.45 * clear


def test_radial_section_shows_the_knot_as_a_spike_from_the_pith():
    log = _log()
    s = lr.radial_section(log, 300.0, 0.0, length_mm=100, px_per_mm=1.0, margin_mm=0.0)
    f = KnottedLogField(log)
    P = s.points()
    kn = f.knot_features(P.reshape(-1, 3))["knot"].reshape(P.shape[:2])
    # rows: from x = +100 (row 0) through the pith (row 100) to x = -100; column 50: z = 300
    assert kn[100 - 60, 50] > 0.9 and kn[100 - 90, 50] > 0.9      # along the knot axis
    assert kn[100 + 60, 50] < 0.01 and kn[100 - 60, 20] < 0.01     # opposite side, beside it


def test_disc_background_outside_the_log():
    log = _log()
    s = lr.end_grain_disc(log, 100.0, px_per_mm=1.0)
    img = lr.render_section(KnottedLogField(log), s)
    bg = (np.array(lr.BACKGROUND_RGB) * 255 + 0.5).astype(np.uint8)
    assert np.array_equal(img[0, 0], bg) and not np.array_equal(img[105, 105], bg)
    with pytest.raises(WoodcamError, match="z_mm"):
        lr.end_grain_disc(log, 5000.0)


def test_sections_off_the_log_are_refused_by_name():
    """--board 1e9 0 60 rendered a board a million metres up a 600 mm log (exit 0); --radial 1e300 0
    overflowed (a traceback); --px-per-mm 1000 asked for 1.57 TiB; an azimuth of 1e300 degrees
    made a file name too long."""
    log = _log()  # 600 mm long, 100 mm radius
    with pytest.raises(WoodcamError, match=r"--board Z AZ OFF\) must lie in the log, \[0, 600\] mm"):
        lr.tangential_board(log, 1e9, 0.0, 60.0)
    with pytest.raises(WoodcamError, match=r"offset_mm \(--board Z AZ OFF\) must be within the log's radius"):
        lr.tangential_board(log, 300.0, 0.0, 1e6)
    with pytest.raises(WoodcamError, match=r"--radial Z AZ\) must lie in the log"):
        lr.radial_section(log, 1e300, 0.0)
    with pytest.raises(WoodcamError, match="MAX_GRID_CELLS.*lower --px-per-mm"):
        lr.radial_section(log, 300.0, 0.0, px_per_mm=1000.0).points()
    assert lr.radial_section(log, 300.0, np.radians(1e300)).name.startswith("radial_z300_az")
    assert len(lr.radial_section(log, 300.0, np.radians(-90.0)).name) < 20
    assert lr.radial_section(log, 300.0, np.radians(-90.0)).name == "radial_z300_az270"


def test_a_section_too_fine_names_the_px_per_mm_and_supersample_given():
    """'log render --px-per-mm 50 --supersample 4' was refused as 'the section ... at 200 px/mm',
    a number nobody typed, with 'lower --px-per-mm' as the only way out."""
    section = lr.radial_section(_log(), 300.0, 0.0, px_per_mm=50.0)
    with pytest.raises(WoodcamError, match=r"at 50 px/mm with 4x4 samples a pixel \(--supersample 4\) "
                       r"\(a 42000x60000x3 grid\).*MAX_GRID_CELLS.*; lower --px-per-mm or --supersample;"):
        lr.render_section(KnottedLogField(_log()), section, supersample=4)
    with pytest.raises(WoodcamError, match=r"at 50 px/mm \(a 10500x15000x3 grid\).*; lower --px-per-mm;"):
        lr.render_section(KnottedLogField(_log()), section)


def test_a_section_past_the_logs_end_says_which_part_is_background():
    """--board 3900 0 60 on the 3990 mm log drew its last 210 mm as background without a word."""
    from woodcam.errors import WoodcamWarning

    log = _log()  # 600 mm long
    with pytest.warns(WoodcamWarning, match=r"the board \(--board Z AZ OFF, 200 mm long\) spans z 450\.\.650 mm.*"
                      r"its right 50 mm \(z > 600 mm\) is drawn as background; a centre height in \[100, 500\]"):
        s = lr.tangential_board(log, 550.0, 0.0, 60.0, length_mm=200, width_mm=40, px_per_mm=0.5)
    img = lr.render_section(KnottedLogField(log), s)
    bg = (np.array(lr.BACKGROUND_RGB) * 255 + 0.5).astype(np.uint8)
    assert (img[:, -20:] == bg).all() and not (img[:, :70] == bg).all()  # the right 50 mm: 25 px
    with pytest.warns(WoodcamWarning, match=r"radial section \(--radial Z AZ.*its left 50 mm \(z < 0 mm\)"):
        lr.radial_section(log, 100.0, 0.0, length_mm=300)
    with pytest.warns(WoodcamWarning, match="left 100 mm.*and its right 100 mm.*the log is only 600 mm long"):
        lr.tangential_board(log, 300.0, 0.0, 60.0, length_mm=800)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lr.tangential_board(log, 500.0, 0.0, 60.0, length_mm=200)  # inside, to its end: no word


def test_a_log_file_names_no_path_and_says_mm(tmp_path):
    """A log file named "../../escaped" made 'log render' write outside --out; "units": "inch"
    was read as mm without a word."""
    import json

    from woodcam.logs.io import read_log

    d = json.loads(write_log(_log(), tmp_path / "log.json").read_text())
    for name in ("../../escaped", "/etc/x", "", "a/b"):
        (tmp_path / "bad.json").write_text(json.dumps(dict(d, name=name)))
        with pytest.raises(WoodcamError, match="name must be a plain name"):
            read_log(tmp_path / "bad.json")
    (tmp_path / "inch.json").write_text(json.dumps(dict(d, units="inch")))
    with pytest.raises(WoodcamError, match="units must be 'mm'"):
        read_log(tmp_path / "inch.json")
    (tmp_path / "ok.json").write_text(json.dumps(dict(d, name="Gran 1.b-2")))
    assert read_log(tmp_path / "ok.json").name == "Gran 1.b-2"


def _parse(argv):
    return build_parser().parse_args(argv)


def test_cli_renders_a_log_file(tmp_path, capsys):
    path = write_log(_log(), tmp_path / "log.json")
    args = _parse(["log", "render", str(path), "--out", str(tmp_path / "out"),
                   "--px-per-mm", "1", "--disc", "300", "--radial", "300", "0"])
    assert args.func(args) == 0
    pngs = sorted((tmp_path / "out").glob("*.png"))
    assert len(pngs) == 3
    # "wrote PATH" a file, as export and every command say it (it printed the bare paths)
    assert sorted(capsys.readouterr().out.splitlines()) == [f"wrote {p}" for p in pngs]
    for p in pngs:
        with Image.open(p) as im:
            assert im.mode == "RGB"


def test_cli_maps_and_export_round_trip(tmp_path, capsys):
    src = write_log(_log(), tmp_path / "log.json")
    a = _parse(["log", "maps", str(src), "--out", str(tmp_path / "maps")])
    assert a.func(a) == 0
    maps = sorted((tmp_path / "maps").iterdir())  # the PNGs and map_params.json
    assert maps and sorted(capsys.readouterr().out.splitlines()) == [f"wrote {p}" for p in maps]
    # into a folder not made yet, as every other FILE output (it failed: no such file)
    b = _parse(["log", "export", "--maps", str(tmp_path / "maps"), "--out",
                str(tmp_path / "new" / "back.json")])
    assert b.func(b) == 0
    # "wrote PATH", as bake, preview, fit and block say (it printed the bare path)
    assert capsys.readouterr().out == f"wrote {tmp_path / 'new' / 'back.json'}\n"
    from woodcam.logs.io import read_log

    log, back = _log(), read_log(tmp_path / "new" / "back.json")
    assert len(back.knots) == len(log.knots) == 1           # the knot survives the maps
    k, kb = log.knots[0], back.knots[0]
    assert abs(kb.z0_mm - k.z0_mm) < 3.0 and abs(kb.r_death_mm - k.r_death_mm) < 3.0
    r = np.array([20.0, 40.0])
    np.testing.assert_allclose(kb.axis_at(r)[0], k.axis_at(r)[0], atol=3.0)


@pytest.mark.parametrize("option, said", [
    (["--disc", "5000"], r"the disc's height z_mm \(--disc\) must lie in the log, \[0, 600\] mm along it; got 5000"),
    (["--radial", "-5", "0"], r"\(--radial Z AZ\) must lie in the log, \[0, 600\] mm along it; got -5"),
    (["--board", "700", "0", "60"], r"\(--board Z AZ OFF\) must lie in the log, \[0, 600\] mm along it; got 700"),
])
def test_cli_a_section_outside_the_log_is_a_usage_error(tmp_path, capsys, option, said):
    """'log render LOG --disc 5000' (or a --radial / --board height) outside the log's
    [0, 600] mm exited 1, as a failure of the work, after the log was read: a value out of the
    log's range is a wrong command line, exit 2, one line naming the range; nothing written."""
    from woodcam.cli import main

    path = write_log(_log(), tmp_path / "log.json")
    assert main(["log", "render", str(path), "--out", str(tmp_path / "out"), "--px-per-mm", "0.5",
                 *option]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and re.search(said, err), err
    assert not list(tmp_path.glob("out/*.png"))


def test_cli_needs_exactly_one_log(tmp_path):
    args = _parse(["log", "render", "--out", str(tmp_path)])
    with pytest.raises(WoodcamError, match="exactly one log"):
        args.func(args)


def test_supersampling_keeps_the_shape_for_odd_sizes():
    log = _log()
    s = lr.end_grain_disc(log, 100.0, px_per_mm=2.0, margin_mm=3.375)   # 593.5 mm -> rounding
    f = KnottedLogField(log)
    a = lr.render_section(f, s)
    b = lr.render_section(f, s, supersample=2)
    assert a.shape == b.shape
    # away from rings' sharp steps the average matches the single sample closely
    assert np.median(np.abs(a.astype(int) - b.astype(int))) <= 12


def test_the_default_board_of_a_thin_short_log_lies_in_it(tmp_path, capsys):
    """A log 40 mm in radius was refused by a --board nobody typed ('|offset| < 40 mm; got 60'),
    and one 300 mm long got a 600 mm board, half background, warned of as '--board' (sweep h6)."""
    import warnings

    path = write_log(simple_log(300.0, 40.0), tmp_path / "thin.json")
    args = _parse(["log", "render", str(path), "--out", str(tmp_path / "out"), "--px-per-mm", "1"])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no past-the-end warning either
        assert args.func(args) == 0
    board = next((tmp_path / "out").glob("*_board_*.png"))
    assert board.name == "simple_board_z150_az0_off24.png"  # 0.6 x 40 mm from the pith, mid-log
    with Image.open(board) as im:
        assert im.size == (300, 120)  # the log's 300 mm at 1 px/mm, 120 mm wide
    # a log thicker than 100 mm keeps the 60 mm, 600 mm board
    board = lr.default_sections(simple_log(1000.0, 120.0))[0]
    assert board.name.endswith("_off60") and board.size_mm == (600.0, 120.0)
