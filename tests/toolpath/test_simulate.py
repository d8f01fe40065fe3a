"""Simulation: analytic cuts, exact manifold3d reference, equivalent programs, issue report,
result mesh."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.ndimage import maximum_filter, minimum_filter

from woodcam.errors import WoodcamError
from woodcam.toolpath import (BallEndMill, FlatEndMill, Program, parse_tool_spec, read_gcode,
                              simulate)
from woodcam.toolpath.reference import manifold_heightmap, reference_stock

SIZE = (40.0, 30.0, 12.0)


def test_flat_slot_matches_analytic_volume_and_depth():
    # 6 mm flat end mill, 20 mm slot, 3 mm deep: volume = 3 (20 * 6 + pi 3^2)
    prog = read_gcode("G0 X10 Y15 Z2 M3 S12000\nG1 Z-3 F300\nX30\nG0 Z2\n")
    res = simulate(prog, FlatEndMill(6), SIZE, resolution_mm=0.05)
    exact = 3 * (20 * 6 + math.pi * 9)
    assert res.removed_volume_mm3 == pytest.approx(exact, rel=2e-3)
    x, y = res.cell_centres_mm
    assert res.heightmap[np.searchsorted(y, 15), np.searchsorted(x, 20)] == pytest.approx(9.0)
    assert res.heightmap[np.searchsorted(y, 15), np.searchsorted(x, 5)] == SIZE[2]
    assert res.report == []


def test_ball_plunge_is_a_hemisphere():
    prog = read_gcode("G0 X20 Y15 Z2\nG1 Z-3 F300\nG0 Z2\n")
    res = simulate(prog, BallEndMill(6), SIZE, resolution_mm=0.05)
    assert res.removed_volume_mm3 == pytest.approx(2 / 3 * math.pi * 27, rel=3e-3)
    x, y = res.cell_centres_mm
    X, Y = np.meshgrid(x, y)
    r2 = (X - 20) ** 2 + (Y - 15) ** 2
    inside = r2 < 9
    np.testing.assert_allclose(res.heightmap[inside], 12 - np.sqrt(9 - r2[inside]), atol=1e-5)


SMALL = """G21 G90 G17
T1 M6
G0 Z3
G0 X8 Y8
G1 Z-2.5 F400
G1 X30 Y10 Z-4
G2 X30 Y22 I0 J6 Z-3
G1 X12 Y20
G3 X8 Y8 R7.5
G1 X8 Y8 Z-5.5
G0 Z3
"""


@pytest.mark.parametrize("spec", ["flat:6", "ball:6", "bull:6:1.5", "vbit:60:8",
                                  "snub:60:6:1", "taperball:6:1.5:10"])
def test_against_exact_manifold_reference(spec):
    """Removed volume within 0.5 % and height within one cell of the exact boolean result."""
    prog = read_gcode(SMALL, chord_tol_mm=0.05)  # few chords: the reference stays fast
    tool = parse_tool_spec(spec)
    res = simulate(prog, tool, SIZE, resolution_mm=0.1)
    ref = reference_stock(prog, tool, SIZE, segments=96)
    v_ref = np.prod(SIZE) - ref.volume()
    assert res.removed_volume_mm3 == pytest.approx(v_ref, rel=5e-3)
    h_ref = manifold_heightmap(ref, SIZE, res.heightmap.shape)
    # within one cell: the simulated height lies within the exact heights of the 3x3
    # neighbourhood (at vertical walls the exact height jumps inside a cell)
    hi = maximum_filter(h_ref, 3, mode="nearest")
    lo = minimum_filter(h_ref, 3, mode="nearest")
    dev = np.maximum(res.heightmap - hi, lo - res.heightmap)
    # 96-gon reference vs exact circle: R (1 - cos(pi/96)) < 2e-3 mm radially, times the
    # flank slope in height for steep cones (the tapered ball's 10 deg flanks: 1/tan 10 = 5.7)
    assert dev.max() <= 2e-3 * (5.7 if spec.startswith("taperball") else 1.0)
    # and away from walls (neighbourhood spread < 0.05 mm) the heights agree pointwise
    smooth = (hi - lo) < 0.05
    assert np.abs(res.heightmap - h_ref)[smooth].max() <= 0.05


def _inch_incremental_variants():
    mm = ("G21 G90\nG0 X10 Y10 Z2\nG1 Z-2.54 F300\nX35.4 Y10\nG2 X35.4 Y22.7 I0 J6.35\n"
          "G1 X10\nG0 Z2\n")
    inch = ("G20 G90\nG0 X{} Y{} Z{}\nG1 Z-0.1 F12\nX{} Y{}\nG2 X{} Y{} I0 J0.25\nG1 X{}\n"
            "G0 Z{}\n").format(*(v / 25.4 for v in (10, 10, 2, 35.4, 10, 35.4, 22.7, 10, 2)))
    inc = ("G21 G90\nG0 X10 Y10 Z2\nG91\nG1 Z-4.54 F300\nX25.4\nG2 X0 Y12.7 I0 J6.35\n"
           "G1 X-25.4\nG0 Z4.54\n")
    return mm, inch, inc


def test_inch_and_incremental_give_the_same_stock():
    mm, inch, inc = _inch_incremental_variants()
    tool = BallEndMill(4)
    ref = simulate(read_gcode(mm), tool, SIZE).heightmap
    for text in (inch, inc):
        np.testing.assert_allclose(simulate(read_gcode(text), tool, SIZE).heightmap, ref,
                                   atol=1e-5)


def test_report_names_lines():
    text = ("G0 X5 Y5 Z2 M3 S9000\n"  # 1
            "G1 Z-1 F300\n"          # 2
            "G0 X20\n"               # 3 rapid through stock
            "G1 Z-13\n"              # 4 below the bottom (stock is 12 high)
            "G0 Z2\n"                # 5
            "G0 X-10\n"              # 6
            "G1 Z-1\n"               # 7 feed below the top outside the stock
            "G1 X3\n"                # 8 cuts in from outside
            "G0 Z2\n")
    res = simulate(read_gcode(text), FlatEndMill(4), SIZE)
    got = {(i.kind, i.line, i.last_line) for i in res.report}
    assert got == {("rapid_through_stock", 3, 3), ("below_stock_bottom", 4, 4),
                   ("cut_outside_stock", 7, 8)}  # adjacent lines of one kind are merged
    assert "lines 7-8: cut_outside_stock" in [str(i)[:28] for i in res.report]
    assert "cuts up to 1.000 mm" in next(str(i) for i in res.report if i.line == 3)
    assert res.heightmap.min() == 0.0  # clamped to the stock bottom


@pytest.mark.parametrize("tool, enters_at_x", [(FlatEndMill(4), -2.0),  # closed-form sweep
                                                (parse_tool_spec("vbit:90:8"), -3.0)])
def test_an_issue_is_placed_where_it_first_happens(tool, enters_at_x):
    """A G-code issue's spot (the review page's hotspot) stood at the end of the first move of
    its line: a rapid crossing the stock was marked where it left it, 60 mm away. Now where the
    problem first happens: the rapid where the tool meets the stock, the plunge where the tip
    goes through the bottom."""
    from woodcam.cli.gcode import _issue_spots

    text = ("G0 X-20 Y15 Z2 M3 S9000\n"  # 1
            "G0 Z-3\n"                    # 2 down beside the stock
            "G0 X60\n"                    # 3 rapid through it at Z-3 (block Z9)
            "G0 Z2\n"                     # 4
            "G0 X20 Y25\n"                # 5
            "G1 Z-13 F300\n"              # 6 plunge 1 mm through the bottom (block Z0)
            "G0 Z2\nM2\n")
    prog = read_gcode(text)
    res = simulate(prog, tool, SIZE, resolution_mm=0.2)
    spots = {s["line"]: s["at_mm"] for s in _issue_spots(prog, res.report, SIZE, None, "p.nc")}
    assert sorted(spots) == [3, 6]
    # the tool's edge meets the stock's face X0 when its axis is at X = -radius at the top
    # of the cut (the flat: -2; the 90-degree V-bit 3 mm deep: -3), to one cell
    x, y, z = spots[3]
    assert enters_at_x - 0.05 <= x <= enters_at_x + 0.2 + 0.05 and (y, z) == (15, 9)
    assert spots[6] == pytest.approx([20, 25, 0])
    assert [i.at_mm for i in res.report] == [tuple(spots[3]), tuple(spots[6])]


def test_rapid_into_an_already_cut_pocket_is_not_reported():
    text = "G0 X10 Y10 Z2 M3 S9000\nG1 Z-3 F300\nX20\nG0 Z2\nG0 X10\nG0 Z-2\nG1 Z-4\nG0 Z2\n"
    res = simulate(read_gcode(text), FlatEndMill(4), SIZE)
    assert res.report == []


def test_work_offset_moves_the_cut():
    prog = read_gcode("G0 X0 Y0 Z2\nG1 Z-2 F100\nG0 Z2\n")
    a = simulate(prog, FlatEndMill(4), SIZE, work_offset_mm=(20, 15, 12))
    x, y = a.cell_centres_mm
    assert a.heightmap[np.searchsorted(y, 15), np.searchsorted(x, 20)] == pytest.approx(10)
    b = simulate(prog, FlatEndMill(4), SIZE, work_offset_mm=(20, 15, 0))  # zero on the bottom
    assert b.heightmap.min() == 0.0 and any(i.kind == "below_stock_bottom" for i in b.report)


def test_tool_table_lookup_and_missing_tool():
    prog = read_gcode("T1 M6\nG0 X5 Y5 Z2\nG1 Z-1 F100\nG0 Z2\nT4 M6\nG0 X20\nG1 Z-1\nG0 Z2\n")
    res = simulate(prog, {1: FlatEndMill(2), 4: FlatEndMill(8)}, SIZE, resolution_mm=0.05)
    assert res.removed_volume_mm3 == pytest.approx(math.pi * (1 + 16), rel=5e-3)
    with pytest.raises(WoodcamError, match=r"uses tool 4 \(first at line 6\)"):
        simulate(prog, {1: FlatEndMill(2)}, SIZE)


def test_mesh_is_watertight_with_volume_of_the_height_field():
    prog = read_gcode(SMALL)
    res = simulate(prog, parse_tool_spec("bull:6:1.5"), SIZE, resolution_mm=0.2)
    full = res.to_mesh(flat_tol_mm=-1.0)  # no merging at all
    mesh = res.to_mesh()
    for m in (full, mesh):
        assert m.is_watertight and m.is_winding_consistent
        np.testing.assert_allclose(m.bounds, [[0, 0, 0], SIZE], atol=1e-12)
    # cell-centre vertices + edge rows: the mesh volume is exactly the midpoint-rule integral
    stock = np.prod(SIZE) - res.removed_volume_mm3
    assert full.volume == pytest.approx(stock, rel=1e-12)
    assert mesh.volume == pytest.approx(stock, rel=1e-12)
    assert len(mesh.faces) < 0.6 * len(full.faces)  # the untouched top is merged
    rough = res.to_mesh(flat_tol_mm=0.05)
    assert rough.is_watertight and len(rough.faces) < len(mesh.faces)
    assert rough.volume == pytest.approx(stock, rel=2e-3)


def test_program_from_arrays_and_errors():
    prog = Program.from_arrays([[5, 5, 1]], [[5, 5, -1]])
    res = simulate(prog, FlatEndMill(2), SIZE)
    assert res.removed_volume_mm3 == pytest.approx(math.pi, rel=2e-2)
    with pytest.raises(WoodcamError, match="size_mm must be"):
        simulate(prog, FlatEndMill(2), (10, 10))
    with pytest.raises(WoodcamError, match="resolution_mm must be a finite number > 0; got 0"):
        simulate(prog, FlatEndMill(2), SIZE, resolution_mm=0)
    with pytest.raises(WoodcamError, match="tools must be a Tool"):
        simulate(prog, "flat:2", SIZE)


def test_long_reports_are_summarised():
    # 30 rapids through the stock on non-adjacent lines: 12 listed, the rest in one entry
    lines = ["G0 X2 Y5 Z2", "G1 Z-1 F300"]
    for k in range(30):
        lines += [f"G0 X{3 + k}", f"G1 Y{6 - (k % 2)}"]
    res = simulate(read_gcode("\n".join(lines)), FlatEndMill(1), SIZE)
    rap = [i for i in res.report if i.kind == "rapid_through_stock"]
    assert len(rap) == 13 and [i.line for i in rap[:12]] == list(range(3, 27, 2))
    assert "and 18 more lines like this, the last at line 61" in rap[-1].message


def test_mesh_of_a_through_cut_stays_closed():
    # a slot cut through the whole 12 mm: the top lies on the bottom there (zero thickness)
    res = simulate(read_gcode("G0 X10 Y15 Z2\nG1 Z-12.5 F300\nX30\nG0 Z2\n"), FlatEndMill(6),
                   SIZE, resolution_mm=0.2)
    assert (res.heightmap == 0).sum() > 0
    mesh = res.to_mesh()
    assert mesh.is_watertight
    assert mesh.volume == pytest.approx(np.prod(SIZE) - res.removed_volume_mm3, rel=1e-12)


def test_spindle_off_and_tool_without_m6_are_reported_with_lines():
    prog = read_gcode("G0 X10 Y10 Z2\nG1 Z-2 F300\nM3 S9000\nG1 X20\nM5\nG1 Y20\n"
                      "T2\nG1 X10\nM2\n")
    res = simulate(prog, FlatEndMill(4), SIZE)
    assert {(i.kind, i.line) for i in res.report} == {("spindle_off", 2), ("spindle_off", 6)}
    assert prog.tool.tolist() == [0] * len(prog)  # T2 without M6: the loaded tool cuts on
    assert [w for w in prog.warnings if "without M6" in w][0].startswith("line 8:")


def test_a_tool_change_stops_the_spindle_as_linuxcnc_does():
    # LinuxCNC stops the spindle at M6 (its interpreter reports it stopped; an M3 on the M6
    # line starts it again): woodcam kept it turning, so T2's cuts without a new M3 were not
    # reported; fanuc and grbl keep their old reading
    text = ("G0 X10 Y10 Z2\nT1 M6\nS9000 M3\nG1 Z-2 F300\nG0 Z2\nT2 M6\nG1 Z-2\nG1 X20\n"
            "G0 Z2\nT3 M6 M3\nG1 Z-2\nM2\n")
    prog = read_gcode(text)
    assert prog.spindle_rpm[prog.kind != 0].tolist() == [9000, 0, 0, 9000]
    res = simulate(prog, FlatEndMill(4), SIZE)
    assert [(i.kind, i.line, i.last_line) for i in res.report] == [("spindle_off", 7, 8)]
    assert "since a tool change" in res.report[0].message
    assert (read_gcode(text, dialect="fanuc").spindle_rpm[prog.kind != 0] == 9000).all()


@pytest.mark.parametrize("tool", [BallEndMill(6), FlatEndMill(4), "vbit:60:6", "vbit:150:8",
                                  "bull:6:1", "bull:6:2.9", "bull:8:0.1", "snub:90:6:1", "snub:150:8:1", "chamfer:60:8:0.5",
                                  "taperball:6:1:5"])
def test_compiled_sweeps_match_the_numpy_envelopes(tool, monkeypatch):
    """Every tool type runs through the one-pass numba kernel (woodcam.toolpath._sweep); the
    numpy window path (Tool._sweep, kept for tool types the kernel does not know) gives the
    same stock (within its float32 round-off), the same issues and the same covered cells on
    random ramps (some steeper than a V-bit's cone), plunges, slanted moves and a rapid
    through the stock."""

    import sys

    # the module (woodcam.toolpath.simulate the attribute is the function)
    sim_mod = sys.modules["woodcam.toolpath.simulate"]
    tool = parse_tool_spec(tool) if isinstance(tool, str) else tool
    assert sim_mod._compiled_profile(tool) is not None
    rng = np.random.default_rng(3)
    pts = np.column_stack([rng.uniform(-5, 45, 120), rng.uniform(-5, 35, 120),
                           rng.uniform(-6, 1, 120)])
    pts[7::7, :2] = pts[6:-1:7, :2]  # plunges: the XY of the point before
    lines = ["G0 X0 Y0 Z5 M3 S12000", "G1 F800"]
    lines += [f"X{x:.3f} Y{y:.3f} Z{z:.3f}" for x, y, z in pts]
    lines += ["G0 X20 Y15 Z-1", "G0 Z5", "M2"]  # the last rapid runs through the stock
    prog = read_gcode("\n".join(lines))
    fast = simulate(prog, tool, SIZE, resolution_mm=0.2, track_lines=True)
    monkeypatch.setattr(sim_mod, "_COMPILED", {})
    slow = simulate(prog, tool, SIZE, resolution_mm=0.2, track_lines=True)
    np.testing.assert_allclose(fast.heightmap, slow.heightmap, atol=1e-4)
    assert [str(i) for i in fast.report] == [str(i) for i in slow.report]
    assert any(i.kind == "rapid_through_stock" for i in fast.report)
    assert fast.stats["cell_updates"] == slow.stats["cell_updates"]
    # the cells the two paths credit to different lines are ties: each line's own move alone
    # reaches the final height there (float32 against float64 picks one or the other)
    jj, ii = np.nonzero(fast.line_map != slow.line_map)
    assert len(jj) < 0.1 * np.count_nonzero(fast.line_map)
    for j, i in list(zip(jj, ii))[:: max(1, len(jj) // 12)]:
        for ln in (fast.line_map[j, i], slow.line_map[j, i]):
            alone = simulate(prog.lines_between(ln - 1, ln), tool, SIZE, resolution_mm=0.2)
            assert alone.heightmap[j, i] == pytest.approx(fast.heightmap[j, i], abs=1e-4)


def test_a_program_of_t0_rapids_only_is_refused_clearly():
    """Every move T0 and none fed, with a table of two tools: the "T0 only rapids before the
    first M6" rule indexed the first tool loaded, of which there is none (IndexError)."""
    prog = read_gcode("G0 X1 Z5\nM2")
    with pytest.raises(WoodcamError, match=r"uses tool 0 \(first at line 1\) but tools has \[1, 2\]"):
        simulate(prog, {1: FlatEndMill(2), 2: FlatEndMill(4)}, SIZE)
    assert prog.tool_of_leading_rapids() is None
    lead = read_gcode("G0 Z5\nT2 M6\nG0 X5 Y5\nG1 Z-1 F100\nM2")
    assert lead.tool_of_leading_rapids() == 2
    res = simulate(lead, {1: FlatEndMill(2), 2: FlatEndMill(4)}, SIZE, resolution_mm=0.1)
    assert res.removed_volume_mm3 == pytest.approx(4 * math.pi, rel=2e-2)


@pytest.mark.parametrize("spec, deepest", [("flat:3", "5.000"),  # the compiled sweep
                                           ("vbit:90:6", "4.671")])  # its tip between cells
def test_a_rapid_through_the_stock_and_a_cut_outside_it_quote_their_worst_line(spec, deepest):
    """A run of rapids into the stock and a run of cuts outside it quoted their first line:
    'cuts up to 1.000 mm' of rapids going 5 mm deep, 'z = -1.000 mm' of cuts going to -4 mm.
    Each says its worst line now (as below_stock_bottom), at its first line's place."""
    prog = read_gcode("G21 G90\nM3 S9000\nG0 X10 Y10 Z5\nG0 Z-1\nG0 X20 Z-5\nG0 Z5\n"
                      "G0 X-5 Y20\nG1 Z-1 F300\nG1 Y25 Z-4\nG1 Y30 Z-2\nG0 Z5\nM2\n")
    res = simulate(prog, {0: parse_tool_spec(spec)}, (60.0, 40.0, 20.0), resolution_mm=0.5)
    rapid, outside = res.report
    assert (str(rapid), str(outside)) == (
        f"lines 4-5: rapid_through_stock: rapid move (G0) cuts up to {deepest} mm into the stock",
        "lines 8-10: cut_outside_stock: tool T0 is below the stock top (z = -4.000 mm) with its "
        "footprint outside the stock")
    assert rapid.at_mm is not None and rapid.at_mm[:2] == pytest.approx((10, 10))  # line 4's
    assert outside.at_mm == pytest.approx((-5, 20, 22))  # the middle of line 8's plunge


def test_a_cut_through_the_bottom_says_how_far_below_it_goes_at_worst():
    """A helix and the lines after it going 2-2.5 mm through the stock's bottom (a through
    cut into the spoilboard) were warned with the first chord that went through: '0.016 mm
    below the stock bottom'. The run of lines says its deepest point now, and still marks
    where the tool first went through."""
    prog = ("G21 G90\nT1 M6\nM3 S9000\nG0 X30 Y20 Z5\nG1 Z-18 F300\nG2 X30 Y20 Z-22 I0 J-4 P4\n"
            "G1 X40 Z-21\nG1 X50 Z-22.5\nG0 Z5\nM30\n")
    res = simulate(read_gcode(prog), parse_tool_spec("flat:3"), (60.0, 40.0, 20.0),
                   resolution_mm=0.2)
    (issue,) = res.report
    assert (issue.kind, issue.line, issue.last_line) == ("below_stock_bottom", 6, 8)
    assert issue.message == ("tool tip at z = -22.500 mm (G-code frame), 2.500 mm below the "
                             "stock bottom")
    assert issue.at_mm is not None and abs(issue.at_mm[2]) < 1e-9  # where it first went through
    one = simulate(read_gcode(prog.replace("G1 X40 Z-21\nG1 X50 Z-22.5\n", "")),
                   parse_tool_spec("flat:3"), (60.0, 40.0, 20.0), resolution_mm=0.2).report
    assert [(i.line, i.message) for i in one] == [
        (6, "tool tip at z = -22.000 mm (G-code frame), 2.000 mm below the stock bottom")]


def test_too_fine_a_grid_says_the_finest_that_fits():
    """woodcam gcode --cell-size 0.005 on a 100 x 80 mm block said 'simulate: 20000 x 16000
    cells is too many for resolution_mm=0.005; use a coarser resolution': neither the option
    the user typed nor how coarse. It names both, the limit, and the finest cell that fits."""
    import re

    from woodcam.toolpath.simulate import _MAX_CELLS

    prog = read_gcode("G0 X1 Y1 Z1\nG1 Z-1 F100\nM2\n")
    for (W, D), res in (((100.0, 80.0), 0.005), ((3000.0, 10.0), 1e-4), ((99.0, 99.0), 1e-4)):
        with pytest.raises(WoodcamError, match=r"resolution_mm \(--cell-size\) .* cells of the "
                           r".* stock, more than the 134,217,728 the height field holds") as e:
            simulate(prog, FlatEndMill(3), (W, D, 5.0), resolution_mm=res)
        fine = float(re.search(r"use ([0-9.]+) mm or coarser", str(e.value)).group(1))
        cells = lambda r: max(1, round(W / r)) * max(1, round(D / r))  # noqa: E731
        step = 10 ** (math.floor(math.log10(fine)) - 1)
        assert cells(fine) <= _MAX_CELLS < cells(fine - step), (W, D, fine)


def test_the_bull_noses_contact_solve_finds_the_lowest_point():
    """The compiled kernel's bull nose solves its contact quartic (_sweep._bull_reach) where it
    bisected 30 times: over random corner radii, slopes (shallow to 10:1) and distances from
    the move's line, the |w| it returns reaches the minimum of the ramp's climb against the
    profile, -s |w| + h(sqrt(d^2 + w^2)), to 1e-9 mm against a dense search."""
    from woodcam.toolpath._sweep import BULL, _bull_reach, _h

    rng = np.random.default_rng(5)
    R = 3.0
    for _ in range(400):
        rc = float(rng.choice([0.05, 0.5, 1.0, 2.5, 3.0]))
        s = float(rng.choice([1e-4, 0.05, 0.3, 1.0, 10.0])) * rng.uniform(0.5, 1.5)
        d = float(rng.uniform(0, R)) if rng.random() < 0.9 else float(rng.choice([0.0, R - rc, R]))
        prm = np.array([rc, 0.0, 0.0, 0.0])
        w = _bull_reach(rc, R, s, d)
        assert 0.0 <= w <= math.sqrt(max(R * R - d * d, 0.0)) + 1e-12
        f = lambda x: -s * x + _h(BULL, prm, R, min(math.hypot(d, x), R))  # noqa: E731
        grid = np.linspace(0.0, math.sqrt(max(R * R - d * d, 0.0)), 4001)
        best = min(f(float(x)) for x in grid)
        # the grid's own spacing (<= 0.75 um) bounds how far its best is above the true one
        assert f(w) <= best + 1e-9, (rc, s, d, w)


def test_the_cell_size_is_plain_floats():
    """cell_mm was (np.float64(0.5), np.float64(0.5)), and so it showed in a notebook's repr of the
    result, beside size_mm's plain (100.0, 80.0, 50.0)."""
    res = simulate(read_gcode("G0 X10 Y15 Z2\nG1 Z-1 F300\nX30\n"), FlatEndMill(6), SIZE, resolution_mm=0.5)
    assert all(type(v) is float for v in (*res.cell_mm, *res.size_mm)), res.cell_mm
    assert "cell_mm=(0.5, 0.5)" in repr(res)
