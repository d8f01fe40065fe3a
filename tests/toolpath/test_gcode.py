"""G-code reader: modal state, arcs against analytic circles, units/incremental, errors."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from woodcam.errors import WoodcamError
from woodcam.toolpath import GcodeError, read_gcode
from woodcam.toolpath.gcode import DEFAULT_START_MM, FEED, RAPID, Program


def test_moves_kinds_feeds_lines():
    prog = read_gcode("G21 G90\nT3 M6\nS12000 M3\nG0 X10 Y20 Z5\nG1 Z-2 F300\nX30\n"
                      "Y25 F600\nG0 Z5\nM30\n")
    # the first rapid starts at the start position (DEFAULT_START_MM, 10 mm over work zero)
    np.testing.assert_allclose(prog.start_mm[0], DEFAULT_START_MM)
    np.testing.assert_allclose(prog.end_mm, [[10, 20, 5], [10, 20, -2], [30, 20, -2],
                                             [30, 25, -2], [30, 25, 5]])
    assert prog.kind.tolist() == [RAPID, FEED, FEED, FEED, RAPID]
    assert prog.line.tolist() == [4, 5, 6, 7, 8]
    assert prog.feed_mm_min.tolist() == [0, 300, 300, 600, 600]
    assert prog.tool.tolist() == [3] * 5 and prog.tool_numbers == [3]
    assert prog[2].kind == "feed" and prog[2].spindle_rpm == 12000 and prog[2].line == 6
    assert prog.warnings == []


def _arc_points(prog):
    """Vertices of the feed moves (the arc) of ``prog``."""
    f = prog.kind == FEED
    return np.vstack([prog.start_mm[f][:1], prog.end_mm[f]])


@pytest.mark.parametrize("cw", [True, False])
def test_ij_arc_lies_on_analytic_circle_with_chord_tolerance(cw):
    tol = 0.01
    code = "G2" if cw else "G3"
    prog = read_gcode(f"G90 G17 G0 X20 Y10 Z1\nG1 F100\n{code} X10 Y20 I-10 J0\n",
                      chord_tol_mm=tol)
    pts = _arc_points(prog)
    c = np.array([10.0, 10.0])
    r = np.hypot(*(pts[:, :2] - c).T)
    np.testing.assert_allclose(r, 10.0, atol=1e-12)  # every vertex on the circle
    mids = 0.5 * (prog.start_mm + prog.end_mm)[prog.kind == FEED][:, :2]
    sag = 10.0 - np.hypot(*(mids - c).T)
    assert sag.max() <= tol + 1e-12 and sag.max() > tol / 4  # not absurdly over-refined
    ang = np.unwrap(np.arctan2(*(pts[:, :2] - c).T[::-1]))
    sweep = ang[-1] - ang[0]
    # from (20,10) at 0 rad to (10,20) at 90 deg: CCW is +90 deg, CW the long way -270 deg
    assert sweep == pytest.approx(-1.5 * math.pi if cw else 0.5 * math.pi, abs=1e-9)
    assert np.all(np.diff(ang) < 0) if cw else np.all(np.diff(ang) > 0)


def test_full_circle_and_helix():
    prog = read_gcode("G0 X5 Y0 Z0\nG1 F100\nG3 X5 Y0 Z-3 I-5 J0\n", chord_tol_mm=0.005)
    pts = _arc_points(prog)
    ang = np.unwrap(np.arctan2(pts[:, 1], pts[:, 0]))
    assert ang[-1] - ang[0] == pytest.approx(2 * math.pi)
    np.testing.assert_allclose(np.hypot(pts[:, 0], pts[:, 1]), 5.0, atol=1e-12)
    # helix: z linear in the swept angle
    np.testing.assert_allclose(pts[:, 2], -3 * (ang - ang[0]) / (2 * math.pi), atol=1e-12)


@pytest.mark.parametrize("r_word, centre", [("R10", (20.0, 0.0)), ("R-10", (10.0, 10.0))])
def test_r_form_minor_and_major_arc(r_word, centre):
    # G2 from (10,0) to (20,10): R>0 is the short (90 deg) arc, R<0 the long (270 deg) one
    prog = read_gcode(f"G0 X10 Y0 Z0\nG1 F100\nG2 X20 Y10 {r_word}\n", chord_tol_mm=0.001)
    pts = _arc_points(prog)
    np.testing.assert_allclose(np.hypot(*(pts[:, :2] - centre).T), 10.0, atol=1e-9)
    ang = np.unwrap(np.arctan2(*(pts[:, :2] - centre).T[::-1]))
    assert ang[-1] - ang[0] == pytest.approx(-0.5 * math.pi if r_word == "R10" else -1.5 * math.pi)


@pytest.mark.parametrize("plane, words, centre_axes", [
    ("G18", "X10 Z0 I5 K0", (0, 2)),
    ("G19", "Y10 Z0 J5 K0", (1, 2)),
])
def test_arcs_in_xz_and_yz_planes(plane, words, centre_axes):
    prog = read_gcode(f"G0 X0 Y0 Z0\nG1 F100\n{plane} G2 {words}\n")
    pts = _arc_points(prog)
    a, b = centre_axes
    c = np.zeros(3)
    c[a] = 5.0
    np.testing.assert_allclose(np.linalg.norm(pts - c, axis=1), 5.0, atol=1e-12)
    other = 3 - a - b
    np.testing.assert_allclose(pts[:, other], 0.0)
    # RS274: G2 is clockwise seen from the plane's positive normal (+Y for G18, +X for G19).
    # Seen from +Y (Z up, X to the left) a clockwise half turn from X0 to X10 passes under
    # the centre (Z = -5); seen from +X (Z up, Y to the right) from Y0 to Y10 it passes over.
    mid = pts[len(pts) // 2]
    if plane == "G18":
        assert mid[2] < -4.9
    else:
        assert mid[2] > 4.9


def test_inch_and_incremental_equal_absolute_mm():
    mm = read_gcode("G21 G90\nG0 X25.4 Y12.7 Z5.08\nG1 Z-2.54 F254\nX50.8 Y25.4\n"
                    "G2 X76.2 Y25.4 I12.7 J0\nG0 Z5.08\n")
    inch = read_gcode("G20 G90\nG0 X1 Y0.5 Z0.2\nG1 Z-0.1 F10\nX2 Y1\n"
                      "G2 X3 Y1 I0.5 J0\nG0 Z0.2\n")
    inc = read_gcode("G21 G90\nG0 X25.4 Y12.7 Z5.08\nG91\nG1 Z-7.62 F254\nX25.4 Y12.7\n"
                     "G2 X25.4 Y0 I12.7 J0\nG0 Z7.62\n")
    for other in (inch, inc):
        assert len(other) == len(mm)
        np.testing.assert_allclose(other.start_mm, mm.start_mm, atol=1e-9)
        np.testing.assert_allclose(other.end_mm, mm.end_mm, atol=1e-9)
    np.testing.assert_allclose(inch.feed_mm_min, mm.feed_mm_min)


_UNITS_PROGRAM = ("G21 G90\nG0 X1 Y1 Z1\nG20 G1 X1 F10\nG0 X2\no100 sub\nG21\nG1 X3 F100\n"
                  "G2 X5 Y1 I1 J0\no100 endsub\no100 call\nG1 X4\nG20\nG1 Y2\nM2\n")
#: (line, inch) of _UNITS_PROGRAM's moves: a G20 on a move's own line counts for it, a G21
#: inside a subroutine for the rest of the call and after it, until the next G20
_UNITS_BY_LINE = [(2, False), (3, True), (4, True), (7, False), (8, False), (11, False),
                  (13, True)]


def test_each_move_records_the_units_it_was_programmed_in():
    """Program recorded no units: a G20 program given tool sizes in inches, read as mm, could
    not be told from a G21 one (the CLI's warning). Each move's ``inch`` is the G20 mode it was
    programmed in, and slices and ``until_line`` keep it."""
    prog = read_gcode(_UNITS_PROGRAM)
    assert sorted(set(zip(prog.line.tolist(), prog.inch.tolist()))) == _UNITS_BY_LINE
    assert prog.inch.dtype == bool and len(prog.inch) == len(prog)
    assert prog[1:3].inch.tolist() == [True, True]
    assert prog.until_line(4).inch.tolist() == [False, True, True]
    assert not read_gcode("G0 X1 Y1 Z1\nG1 Z-1 F100\n").inch.any()
    assert Program.from_arrays([[0, 0, 0]], [[1, 0, 0]]).inch.tolist() == [False]


def test_drilling_cycles_expand_to_moves():
    prog = read_gcode("G90 G0 X0 Y0 Z10\nG99 G81 X5 Y5 Z-3 R2 F100\nX15\nG80\n"
                      "G0 Z10\nG98 G83 X25 Y5 Z-6 R2 Q2.5\nG80\n")
    feeds = prog.end_mm[prog.kind == FEED]
    # G81: one feed to Z-3 per hole; G83: pecks to -0.5, -3, -5.5, -6
    np.testing.assert_allclose(feeds[:, 2], [-3, -3, -0.5, -3, -5.5, -6])
    np.testing.assert_allclose(feeds[:, :2], [[5, 5], [15, 5]] + [[25, 5]] * 4)
    assert prog.end_mm[-1].tolist() == [25, 5, 10]  # G98: back to the initial Z


@pytest.mark.parametrize("text, line, word", [
    ("G21\nG0 X0 Y0 Z5\nG38.2 Z0\n", 3, "G38.2"),
    ("G0 X0 Y0 Z5\nG1 X1..2 F100\n", 2, "."),
    ("G0 X0 Y0 Z5\nG1 A10 F100\n", 2, "A10"),
    ("G0 X0 Y0 Z5\nG1 X10\n", 2, "G1"),              # no feed rate yet
    ("G0 X0 Y0 Z0\nG1 F10\nG2 X10 Y0 I4 J0\n", 3, "G2"),  # radius mismatch
    ("G0 X0 Y0 Z0\nG1 F10\nG2 X0 Y0 R5\n", 3, "R5"),       # R-form full circle
    ("G0 G1 X1 Y1 Z1\n", 1, "G0 G1"),
    ("G0 X0 (open comment\n", 1, "(open comment"),
    ("G0 X0 Y0 Z0\nM98 P100\n", 2, "M98"),
    ("G0 X0\nG0 X[1 / [2 - 2]]\n", 2, "1 / 0"),
    ("N7 G0 X0 Y0 Z0\nN8 G1 F10 X1 Y1 Z1 X2\n", 2, "X2"),
    ("G0 X0\nG41 G1 X10 F100\n", 2, "G41"),           # cutter compensation: refused
    ("G0 X0\nO1001\nM98 P1001\n", 3, "M98 P1001"),     # LinuxCNC: the label follows the call
    ("G0 X0\nM98 P1\nM30\nO1\nG1 Y1 M99\n", 5, "M99"),  # a return first on its line
])
def test_malformed_and_unsupported_lines_name_line_and_word(text, line, word):
    with pytest.raises(GcodeError, match=rf"line {line}\b.*'{__import__('re').escape(word)}") as e:
        read_gcode(text)
    assert e.value.line == line


def test_reads_file(tmp_path):
    p = tmp_path / "a.nc"
    p.write_text("G0 X0 Y0 Z1\nG1 Z-1 F100\nM2\n")
    prog = read_gcode(p)
    assert len(prog) == 2 and prog.source == str(p)
    assert len(read_gcode(str(p))) == 2


def test_comments_block_delete_and_start_position():
    prog = read_gcode("%\n(header)\n; whole-line comment\nN10 G21 G90 G17 (modes) ; units\n"
                      "G0 Z5\nG0 X10 Y20\n/G1 Z-2 F300\nX30\nM30\nG1 X99\n",
                      start_mm=(1, 2, 30))
    # moves start at start_mm; the block-delete line runs (switch off); M30 ends reading
    np.testing.assert_allclose(prog.start_mm, [[1, 2, 30], [1, 2, 5], [10, 20, 5], [10, 20, -2]])
    np.testing.assert_allclose(prog.end_mm, [[1, 2, 5], [10, 20, 5], [10, 20, -2], [30, 20, -2]])
    assert prog.line.tolist() == [5, 6, 7, 8]
    assert prog.warnings == []


def test_cut_before_known_position_warns_with_line():
    prog = read_gcode("G21 G90\nG1 Z-1 F100\nG1 X10 Y10\nM2\n")
    assert prog.start_mm[0].tolist() == list(DEFAULT_START_MM)
    assert len(prog.warnings) == 1 and prog.warnings[0].startswith("line 2:")
    assert "XY" in prog.warnings[0]


def test_fanuc_program_number_g28_and_g53():
    prog = read_gcode("O1001\nG0 X10 Y10 Z5\nG1 Z-1 F100\nG91 G28 Z2\nG90\n"
                      "G53 G0 Z7\nG0 X20 Y10\nG1 Z-1\nM30\n", dialect="fanuc",
                      start_mm=(0, 0, 40), machine_zero_mm=(0, 0, 0))
    # G28 Z2 (incremental): rapid up 2 mm to the intermediate point, then Z to the home, which
    # woodcam keeps at the start position; G53 moves in machine coordinates (= G54 here: the
    # machine zero given at G-code zero)
    np.testing.assert_allclose(prog.end_mm, [[10, 10, 5], [10, 10, -1], [10, 10, 1],
                                             [10, 10, 40], [10, 10, 7], [20, 10, 7],
                                             [20, 10, -1]])
    assert prog.line.tolist() == [2, 3, 4, 4, 6, 7, 8]


#: Carbide Create (Shapeoko) begins and ends with "G53G0Z-5.000": 5 mm below the machine's Z
#: home, near the top of Z travel; the stock's top is G-code Z0.
CARBIDE = ("G90\nG21\nG53G0Z-5.000\nM6T1\nM03S18000\nG0X10.000Y10.000\nG0Z5.000\n"
           "G1Z-1.000F254.0\nG1X50.000F1016.0\nG0Z5.000\nG53G0Z-5.000\nM02\n")


def test_g53_retract_without_the_machine_zero_is_a_retract_and_is_warned():
    from woodcam.toolpath import FlatEndMill, simulate

    # machine zero taken at G-code zero, the retract rapided 5 mm into the stock (twice) and
    # every Carbide Create file reported rapid_through_stock
    prog = read_gcode(CARBIDE, start_mm=(0, 0, 10))
    res = simulate(prog, {1: FlatEndMill(3.175)}, (100, 80, 50), resolution_mm=0.5)
    assert [i.kind for i in res.report] == []
    assert prog.end_mm[prog.line == 11].tolist() == [[50, 10, 10]]  # up to the --start height
    assert prog.end_mm[:, 2].min() == -1
    g53 = [w for w in prog.warnings if "G53" in w]
    assert len(g53) == 1 and g53[0].startswith("line 3:") and "line(s) 3, 11:" in g53[0]
    assert "retract to Z10 mm" in g53[0] and "--machine-zero" in g53[0]
    # a retract never plunges: from above the start height the tool stays where it is; X/Y
    # cannot be placed without the machine zero: kept at G-code X/Y, warned apart
    prog = read_gcode("G0 X1 Y1 Z30\nG53 G0 Z-5\nG1 Z-1 F100\nG53 G0 Z0 X0\nM2\n",
                      start_mm=(0, 0, 10))
    assert prog.end_mm.tolist() == [[1, 1, 30], [1, 1, -1], [0, 1, 10]]
    assert [w.split(":")[0] for w in prog.warnings] == ["line 2", "line 4"]
    assert "line(s) 2, 4:" in prog.warnings[0] and "line(s) 4:" in prog.warnings[1]
    assert "X/Y" in prog.warnings[1]


def test_machine_zero_places_g53_as_linuxcnc_does():
    # LinuxCNC: machine = work + G54 offset, the offset being the work zero in machine
    # coordinates; the machine zero lies at -offset in the work frame. With the work zero 80 mm
    # below the Z home, G53 Z-5 is work Z75, G53 X7 work X17; "G10 L2 P1 X5" puts the work zero
    # at machine X5, i.e. G-code frame X15 (checked against LinuxCNC in the oracle test)
    prog = read_gcode(CARBIDE, start_mm=(0, 0, 10), machine_zero_mm=(0, 0, 80))
    assert prog.end_mm[prog.line == 11].tolist() == [[50, 10, 75]]
    assert prog.end_mm[0].tolist() == [0, 0, 75] and prog.warnings == []
    prog = read_gcode("G0 X1 Y2 Z3\nG53 G0 X7 Z-5\nG10 L2 P1 X5\nG0 X1\nG28\nG1 Z0 F9\nM2\n",
                      start_mm=(4, 5, 10), machine_zero_mm=(10, 20, 80))
    np.testing.assert_allclose(prog.end_mm, [[1, 2, 3], [17, 2, 75], [16, 2, 75], [4, 5, 10],
                                             [4, 5, 0]], atol=1e-12)
    # a string and a (1, 3) array were a bare ValueError and accepted (copied by hand)
    for bad in [(0, 80), "abc", [[0, 0, 1]]]:
        with pytest.raises(WoodcamError, match="machine_zero_mm must be three finite numbers"):
            read_gcode(CARBIDE, machine_zero_mm=bad)


CORPUS = sorted((Path(__file__).resolve().parents[2] / "toolpaths" / "corpus").glob("*.*[!y]"))


@pytest.mark.parametrize("path", CORPUS, ids=lambda p: p.name)
def test_corpus_programs_simulate_or_fail_with_their_reason(path):
    """Every corpus program either simulates (finite, something cut) or, for the err_* ones,
    is refused at the line its header comment names the reason of."""
    from woodcam.toolpath import parse_tool_spec, simulate

    if path.name.startswith("err_"):
        reason = path.read_text().splitlines()[0]
        with pytest.raises(GcodeError) as e:
            read_gcode(path, dialect="linuxcnc")
        assert e.value.line > 1, reason
        return
    dialect = "fanuc" if path.name.startswith("fanuc") else "linuxcnc"
    prog = read_gcode(path, dialect=dialect)
    assert (prog.kind == FEED).any()
    res = simulate(prog, parse_tool_spec("ball:6"), (120.0, 100.0, 50.0), resolution_mm=0.5,
                   work_offset_mm=(10.0, 10.0, 50.0))
    assert np.isfinite(res.heightmap).all()
    if (prog.end_mm[prog.kind == FEED, 2] < 0).any():  # (two language tests stay above)
        assert res.removed_volume_mm3 > 0


def test_a_program_file_without_a_gcode_suffix_is_read_as_a_file(tmp_path):
    """A one-line string naming an existing file is that file, whatever its suffix (posts
    write .out, .prg ...); before, its path was parsed as G-code."""
    p = tmp_path / "part.out"
    p.write_text("G21 G90\nG0 X1 Y2 Z3\n")
    prog = read_gcode(str(p))
    assert prog.source == str(p) and np.allclose(prog.end_mm[-1], (1, 2, 3))


def test_a_program_is_sliced_as_a_list_of_moves():
    """program[0:1] was a bare TypeError (numpy's 'only 0-dimensional arrays can be converted'),
    program[1.0] an IndexError about numpy indices: a slice is now a Program of those moves (its
    tools, source and warnings with them), an integer (a numpy one too) a Move, anything else a
    WoodcamError naming the index."""
    prog = read_gcode("T1 M6\nG0 X10 Y20 Z5\nG1 Z-2 F300\nT2 M6\nG1 X30\nG0 Z5\n")
    moves = prog.moves
    for sl in (slice(0, 1), slice(1, None), slice(None, None, -1), slice(-2, None), slice(3, 3)):
        part = prog[sl]
        assert isinstance(part, type(prog)) and part.moves == moves[sl], sl
        assert part.tool_numbers == sorted({m.tool for m in moves[sl]}) and part.source == prog.source
    assert prog[:2].tool_numbers == [1] and prog[1:].line.tolist() == [3, 5, 6]
    assert prog[np.int64(1)] == moves[1] and prog[-1] == moves[-1]
    for bad in (1.0, "a", True, None):
        with pytest.raises(WoodcamError, match=r"Program: a move index must be an integer or a slice; got "):
            prog[bad]


def test_a_file_that_is_not_gcode_text_is_refused_saying_what_it_is(tmp_path, capsys):
    """A PNG, an executable or a file saved as UTF-16 passed as the program was read as text:
    'woodcam gcode pic.nc' said "G-code line 6: '(\\x89...' ...: unclosed comment" with a wall of
    bytes, an ELF program the same at line 4. A file with a NUL byte (no G-code text has one)
    is refused now, saying what it starts with and what to pass instead."""
    from woodcam.cli import main

    png = tmp_path / "pic.nc"
    png.write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR" + bytes(range(256)) * 4)
    utf16 = tmp_path / "u16.nc"
    utf16.write_bytes("G21\nG1 X1 F100\nM2\n".encode("utf-16"))
    for path, what in ((png, "a binary file (an image, a program, a CAM project?), or G-code "
                              "damaged by the NUL on line 3 (LinuxCNC would drop the words after "
                              "it); pass the G-code file the CAM software's post-processor wrote"),
                       (utf16, "saved as UTF-16 (Windows' 'Unicode'); save it as UTF-8 or ASCII")):
        with pytest.raises(WoodcamError, match="is not G-code text") as e:
            read_gcode(path)
        assert str(e.value).startswith(f"{str(path)!r} is not G-code text: it holds NUL bytes "
                                       "(it starts b'") and what in str(e.value), str(e.value)
        assert main(["gcode", str(path), "--tool", "flat:3", "--block", "builtin:flat-sawn",
                     "--out", str(tmp_path / "o.glb")]) == 1
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "is not G-code text" in err and len(err) < 400, err
    assert not (tmp_path / "o.glb").exists()


def test_a_byte_that_is_no_utf8_outside_a_comment_says_so(tmp_path):
    """A degree sign saved as Latin-1 ('G0 X1 Y1 Z1 \\xb0') was refused as "bad character '\\ufffd'
    (a word is a letter and a value)", which says nothing of the byte; now the error says the
    file holds a byte of another encoding and how to fix it. In a comment it stays allowed."""
    prog = tmp_path / "deg.ngc"
    prog.write_bytes(b"G21 G90\nT1 M6\nG0 X1 Y1 Z1 \xb0\nG1 Z-1 F100\nM2\n")
    with pytest.raises(GcodeError, match=r"line 3: .*a byte that is no UTF-8 text, read as "
                       r"U\+FFFD .* Latin-1 or Windows-1252.*remove the character, or save the "
                       r"file as UTF-8"):
        read_gcode(prog)
    prog.write_bytes(b"G21 G90\nT1 M6\nG0 X1 Y1 Z1 (90\xb0)\nG1 Z-1 F100\nM2\n")
    assert len(read_gcode(prog)) == 2


# a slot subroutine at lines 1-5, called on line 8 (slot X10-X20), a rapid elsewhere on line 9,
# called again on line 10 (slot X30-X40)
SUB_SLOTS = ("o100 sub\nG0 X#1 Y10 Z1\nG1 Z-1 F300\nG1 X[#1+10]\nG0 Z5\no100 endsub\n"
             "G21 G90\no100 call [10]\nG0 X50 Y30 Z5\no100 call [30]\nM2\n")


def check_until_line_counts_a_call_s_moves_at_its_line(prog):
    """The known answer of ``until_line`` on :data:`SUB_SLOTS` (both interpreters)."""
    first = [(10.0, 10.0, 1.0), (10.0, 10.0, -1.0), (20.0, 10.0, -1.0), (20.0, 10.0, 5.0)]
    second = [(30.0, 10.0, 1.0), (30.0, 10.0, -1.0), (40.0, 10.0, -1.0), (40.0, 10.0, 5.0)]
    assert prog.ran_line.tolist() == [8] * 4 + [9] + [10] * 4
    assert prog.line.tolist() == [2, 3, 4, 5, 9, 2, 3, 4, 5]  # the lines they come from stay
    for n, want in ((7, []), (8, first), (9, first + [(50.0, 30.0, 5.0)]),
                    (10, first + [(50.0, 30.0, 5.0)] + second), (5, []), (3, [])):
        got = prog.until_line(n)
        np.testing.assert_allclose(got.end_mm.reshape(-1, 3), np.reshape(want, (-1, 3)),
                                   atol=1e-9, err_msg=str(n))
        assert got.ran_line.tolist() == prog.ran_line[:len(want)].tolist()
    np.testing.assert_allclose(prog.lines_between(8, 10).end_mm, [(50.0, 30.0, 5.0)] + second,
                               atol=1e-9)


def test_until_line_counts_a_subroutine_s_moves_at_the_line_that_called_it():
    """until_line kept moves by the line they came from: a subroutine defined at lines 1-5 and
    called on lines 8 and 10 had until_line(9) cut both slots (the second by the call on line
    10). Each move records the main-program line it ran under (ran_line), nested calls and M98
    subprograms at the outermost call's line, and until_line counts by it."""
    check_until_line_counts_a_call_s_moves_at_its_line(read_gcode(SUB_SLOTS))
    nested = read_gcode("o100 sub\nG1 X#1 F300\no100 endsub\no200 sub\no100 call [#1]\n"
                        "o100 call [#1+1]\no200 endsub\nG0 X0 Y0 Z0\no200 call [5]\n"
                        "G1 X20\no200 call [30]\nM2\n")
    assert nested.line.tolist() == [8, 2, 2, 10, 2, 2]
    assert nested.ran_line.tolist() == [8, 9, 9, 10, 11, 11]
    assert nested.until_line(10).end_mm[:, 0].tolist() == [0.0, 5.0, 6.0, 20.0]
    m98 = read_gcode("G21 G90 F300\nG0 X0 Y0 Z0\nM98 P1000\nG1 X40\nM98 P1000\nM30\n"
                     "O1000\nG91 G1 X5\nG90\nM99\n", dialect="fanuc")
    assert m98.line.tolist() == [2, 8, 4, 8] and m98.ran_line.tolist() == [2, 3, 4, 5]
    assert m98.until_line(4).end_mm[:, 0].tolist() == [0.0, 5.0, 40.0]
    assert read_gcode("G1 X1 F100\n").ran_line.tolist() == [1]
    assert Program.from_arrays([[0, 0, 0]], [[1, 0, 0]], line=3).ran_line.tolist() == [3]


def test_a_nul_byte_that_hides_words_is_refused_naming_its_line(tmp_path):
    """LinuxCNC reads a line only up to a NUL byte and drops the rest without a word
    (rs274: 'G1 X2\\0 Y3 F100' runs as 'G1 X2'): woodcam said "bad character '\\x00'" outside a
    comment and read a NUL inside one as text, where LinuxCNC says 'Unclosed comment found'.
    Both now name the line, the character and the words the NUL hides; NULs with nothing
    after them (a card's zero padding, a line ending in one) are read as LinuxCNC reads them,
    from text and from a file."""
    for text, line, col, hidden in (("G0 X1\nG1 X2\x00 Y3 F100\nM2\n", 2, 6, "'Y3 F100'"),
                                    ("G0 X1 (a\x00b)\nM2\n", 1, 9, "'b)'"),
                                    ("G0 X1\nM2\n\x00G1 X9\n", 3, 1, "'G1 X9'")):
        with pytest.raises(GcodeError) as e:
            read_gcode(text)
        assert e.value.line == line and e.value.word == "NUL", str(e.value)
        assert f"a NUL byte (character {col} of the line" in str(e.value)
        assert f"drops the rest, here {hidden}, without a word" in str(e.value)
    plain = read_gcode("G0 X1\nG1 X2 F100\nG1 Y5\nM2\n")
    for padded in ("G0 X1\nG1 X2 F100\x00\nG1 Y5\nM2\n", "G0 X1\nG1 X2 F100\nG1 Y5\nM2\n\x00\x00",
                   "G0 X1\nG1 X2 F100\n\x00 \x00\nG1 Y5\nM2\n"):
        prog = read_gcode(padded)
        assert np.array_equal(prog.end_mm, plain.end_mm) and prog.warnings == plain.warnings
    card = tmp_path / "card.nc"
    card.write_bytes(b"G0 X1\nG1 X2 F100\nG1 Y5\nM2\n" + b"\x00" * 512)
    assert np.array_equal(read_gcode(card).end_mm, plain.end_mm)
    card.write_bytes(b"G0 X1\nG1 X2\x00 Y3 F100\nM2\n")
    with pytest.raises(WoodcamError, match=r"or G-code damaged by the NUL on line 2 "):
        read_gcode(card)


def test_the_end_of_file_warning_names_the_files_last_line_as_rs274_quotes_it():
    """A program without M2/M30/'%' is warned of at the line rs274 quotes: the file's last.
    A repeat loop ending the file was warned at its first line (where the loop ended); a file
    of blank lines said 'no percent sign or program end' where rs274 says 'File ended with no
    percent sign' (it looks past blank lines for the opening '%')."""
    def end(text):
        w, = [w for w in read_gcode(text).warnings if "the file ends" in w]
        return w

    assert end("o1 repeat [2]\nG0 X1\no1 endrepeat\n").startswith("line 3: ")
    assert end("G0 X1\nG1 X2 F100\n(done)\n\n").startswith("line 4: ")
    assert end("G0 X1\nG1 X2 F100").startswith("line 2: ")
    for blank in ("", "\n\n", " \n"):
        assert end(blank).endswith("'File ended with no percent sign')"), blank
    assert end("(c)\n").endswith("'File ended with no percent sign or program end')")


def test_form_feed_and_vertical_tab_at_a_lines_end_are_blanks_as_in_linuxcnc():
    """LinuxCNC takes every C blank (form feed and vertical tab too) off a line's end before
    reading it: rs274 runs 'G0 X1\\f' and a line of a lone form feed (a page break some
    editors keep). woodcam refused them as "bad character '\\x0c'"; inside a line they are
    still refused, as LinuxCNC refuses them ('Bad character')."""
    plain = read_gcode("G0 X1\nG1 X2 F100\nM2\n")
    for text in ("G0 X1\f\nG1 X2 F100\nM2\n", "G0 X1 \v \nG1 X2 F100 (c)\f\r\nM2\n",
                 "G0 X1\n\f\nG1 X2 F100\nM2\n"):
        prog = read_gcode(text)
        assert np.array_equal(prog.end_mm, plain.end_mm), text
        assert [w.split(":", 1)[1] for w in prog.warnings] == [w.split(":", 1)[1] for w in plain.warnings]
    for text in ("G0\fX1\nM2\n", "\vG0 X1\nM2\n"):
        with pytest.raises(GcodeError, match="bad character"):
            read_gcode(text)
