"""The G-code window's line slider (woodcam.view.scrub), driven off screen through its
callback as the view-key tests drive the keys."""

from __future__ import annotations

import numpy as np
import pytest

from woodcam.errors import WoodcamError
from woodcam.toolpath import parse_tool_spec, read_gcode, simulate

pv = pytest.importorskip("pyvista")


class _Wood:
    def color(self, points_mm, normals):
        return np.full((len(points_mm), 3), 0.6)


class _Stock:
    size_mm = (60.0, 40.0, 20.0)
    wood = _Wood()


# three 20 mm slots, one per line pair: 5 mm deep each, 6 mm flat
PROG = ("M3 S9000 F600\nG0 X10 Y10 Z2\nG1 Z-5\nG1 X30\nG0 Z2\nG0 Y20\nG1 Z-5\nG1 X10\n"
        "G0 Z2\nG0 Y30\nG1 Z-5\nG1 X30\nG0 Z2\nM2\n")


def _removed(hm, res=0.5):
    return float((20.0 - hm).sum() * res * res)


def test_the_slider_scrubs_the_stock_to_any_line_forward_and_back():
    from woodcam.view.scrub import (DONE_ACTORS, STOCK_ACTOR, TIP_ACTOR, TODO_ACTOR,
                                    gcode_window)

    prog = read_gcode(PROG)
    tool = parse_tool_spec("flat:6")
    plotter, cb = gcode_window(prog, tool, _Stock(), resolution_mm=0.5, off_screen=True,
                               window_size=(320, 240))
    try:
        slider = plotter.widgets.slider_widgets[0]
        rep = slider.GetRepresentation()
        assert (rep.GetMinimumValue(), rep.GetMaximumValue()) == (2, 13)
        assert cb.line == 13 and STOCK_ACTOR in plotter.actors
        one = _removed(simulate(prog.until_line(4), tool, _Stock.size_mm,
                                resolution_mm=0.5).heightmap)
        for line, slots in ((4, 1), (12, 3), (8, 2), (3, None)):
            cb(line)
            want = simulate(prog.until_line(line), tool, _Stock.size_mm, resolution_mm=0.5)
            np.testing.assert_array_equal(cb.heightmap, want.heightmap)
            if slots:
                assert _removed(cb.heightmap) == pytest.approx(slots * one, rel=1e-6)
        cb(8)  # the tool tip sits at the end of line 8's move (X10 Y20 Z-5 -> block Z 15)
        tip = np.asarray(plotter.actors[TIP_ACTOR].GetMapper().GetInput().center)
        np.testing.assert_allclose(tip, (10.0, 20.0, 15.0), atol=1e-6)
        assert DONE_ACTORS[0] in plotter.actors and TODO_ACTOR in plotter.actors
        cb(13)
        assert TODO_ACTOR not in plotter.actors
        img = plotter.screenshot(return_img=True)
        assert img.shape[:2] == (240, 320) and img.std() > 5  # something drawn
    finally:
        plotter.close()


def test_a_window_without_a_display_is_a_clear_error(monkeypatch):
    import woodcam.view.scene as scene
    from woodcam.view.scrub import gcode_window

    monkeypatch.setattr(scene.sys, "platform", "linux")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    with pytest.raises(WoodcamError, match="needs a display"):
        gcode_window(read_gcode(PROG), parse_tool_spec("flat:6"), _Stock())


def test_gcode_view_without_a_display_fails_before_any_work(tmp_path, monkeypatch):
    from woodcam.cli import build_parser

    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setattr("woodcam.view.scene.sys.platform", "linux")
    prog = tmp_path / "p.nc"
    prog.write_text(PROG)
    args = build_parser().parse_args(["gcode", str(prog), "--block", "builtin:rift", "--out",
                                      str(tmp_path / "o.glb"), "--tool", "flat:6", "--view"])
    with pytest.raises(WoodcamError, match="needs a display"):
        args.func(args)
    assert not (tmp_path / "o.glb").exists()


def test_gcode_view_hands_the_whole_last_program_and_its_start_stock(tmp_path, monkeypatch):
    """``woodcam gcode A B --until-line 4 --view``: the window gets all of B (the slider can
    go past line 4), the stock A left as its start, and starts at line 4."""
    import woodcam.view.scrub as scrub
    from tests.toolpath.test_toolpath_cli import _parse, _stub_preview

    seen: dict = {}
    _stub_preview(monkeypatch, {})
    monkeypatch.setattr(scrub, "check_display", lambda: None)
    monkeypatch.setattr(scrub, "gcode_window", lambda program, tools, stock, **kw:
                        seen.update(program=program, kw=kw))
    first = tmp_path / "a.nc"
    first.write_text("M3 S9000 F600\nG0 X30 Y30 Z2\nG1 Z-3\nG1 X50\nG0 Z2\nM2\n")
    second = tmp_path / "b.nc"
    second.write_text(PROG)
    args = _parse([str(first), str(second), "--block", "builtin:flat-sawn", "--out",
                   str(tmp_path / "o.glb"), "--tool", "flat:6", "--cell-size", "0.5",
                   "--stock", "60x40x20", "--until-line", "4", "--view"])
    assert args.func(args) == 0
    assert int(seen["program"].line.max()) == 13 and seen["kw"]["until_line"] == 4
    start = seen["kw"]["initial_heightmap"]
    want = simulate(read_gcode(first.read_text()), parse_tool_spec("flat:6"), (60, 40, 20),
                    resolution_mm=0.5).heightmap
    np.testing.assert_array_equal(start, want)
    # and the stock at line 4 it opens on, simulated once by the CLI (not again in the window)
    at4 = simulate(read_gcode(PROG).until_line(4), parse_tool_spec("flat:6"), (60, 40, 20),
                   resolution_mm=0.5, initial_heightmap=want).heightmap
    np.testing.assert_array_equal(seen["kw"]["heightmap"], at4)


def test_the_window_opens_on_the_stock_it_is_given_without_simulating_again(monkeypatch):
    import importlib

    from woodcam.view.scrub import gcode_window

    sim = importlib.import_module("woodcam.toolpath.simulate")  # the package's name is the function

    prog = read_gcode(PROG)
    tool = parse_tool_spec("flat:6")
    at8 = simulate(prog.until_line(8), tool, _Stock.size_mm, resolution_mm=0.5).heightmap
    calls = []
    real = sim.simulate
    monkeypatch.setattr(sim, "simulate", lambda *a, **kw: calls.append(1) or real(*a, **kw))
    plotter, cb = gcode_window(prog, tool, _Stock(), resolution_mm=0.5, off_screen=True,
                               window_size=(160, 120), until_line=8, heightmap=at8)
    try:
        assert cb.line == 8 and not calls
        np.testing.assert_array_equal(cb.heightmap, at8)
        cb(12)  # forward from the given stock: only lines 9-12 are simulated
        assert len(calls) == 1
        want = simulate(prog.until_line(12), tool, _Stock.size_mm, resolution_mm=0.5)
        np.testing.assert_array_equal(cb.heightmap, want.heightmap)
    finally:
        plotter.close()


def test_done_feeds_are_blue_rapids_red_and_the_stock_wears_its_wood():
    """At line 8 of PROG the done moves are the feeds of lines 3, 4, 7, 8 (royalblue) and the
    rapids of lines 2, 5, 6 (red); the stock's vertices carry the wood's colour at their own
    block position (a wood whose colour is the position / size)."""
    from woodcam.view.scrub import DONE_ACTORS, _stock_polydata, gcode_window

    class CoordWood:
        def color(self, points_mm, normals):
            return np.clip(np.asarray(points_mm) / np.array(_Stock.size_mm), 0, 1)

    class CoordStock(_Stock):
        wood = CoordWood()

    plotter, cb = gcode_window(read_gcode(PROG), parse_tool_spec("flat:6"), CoordStock(),
                               resolution_mm=0.5, off_screen=True, window_size=(160, 120))
    try:
        cb(8)
        for name, n_lines, rgb in ((DONE_ACTORS[0], 4, (65, 105, 225)), (DONE_ACTORS[1], 3, (255, 0, 0))):
            actor = plotter.actors[name]
            assert actor.GetMapper().GetInput().n_lines == n_lines, name
            np.testing.assert_allclose(np.asarray(actor.GetProperty().GetColor()) * 255, rgb, atol=1)
        # the stock drawn is _stock_polydata of the heightmap at line 8
        stock = _stock_polydata(pv, cb.heightmap, _Stock.size_mm, CoordWood())
        pts = np.asarray(stock.points)
        assert pts[:, 2].min() == 0.0 and pts[:, 2].max() == 20.0 and (pts[:, 2] == 15.0).any()
        np.testing.assert_array_equal(np.asarray(stock.point_data["rgb"]),
                                      np.round(pts / np.array(_Stock.size_mm) * 255).astype(np.uint8))
    finally:
        plotter.close()


@pytest.mark.parametrize("colours, said", [
    ({"feeds": "royalblu"}, "gcode_window: colours['feeds'] must be a colour name matplotlib knows ('royalblue', "
                            "'tab:blue', 'xkcd:sky blue'), a hex string ('#4169e1') or an RGB triple"),
    ({"feeds": "royalblu"}, "; got 'royalblu'; did you mean 'royalblue' or 'xkcd:royal blue'?"),
    # pyvista's own spelling, which the other views refuse: refused here too, not drawn
    ({"tip": "royal_blue"}, "colours['tip'] must be a colour name matplotlib knows"),
    ({"tip": "royal_blue"}, "did you mean 'royalblue' or 'xkcd:royal blue' or 'aliceblue'?"),
    ({"todo": (1, 0, 0)}, "ambiguous: whole numbers are read in 0..255"),
    ({"rapid": "red"}, "gcode_window: colours has an unknown key 'rapid'; did you mean 'rapids'? the keys are "
                       "feeds, rapids, todo, tip"),
])
def test_the_windows_colours_are_read_by_the_views_one_colour_rule(colours, said):
    """The window handed its colour names straight to pyvista, whose table is not the views'
    (matplotlib's, woodcam.view.scene.colour_rgb): a typo was pyvista's bare ValueError, a name
    only pyvista knows was drawn where every other view refuses it, one only matplotlib knows
    ('xkcd:sky blue') refused. Now every colour goes through colour_rgb, before any window."""
    from woodcam.view.scrub import gcode_window

    with pytest.raises(WoodcamError) as err:
        gcode_window(read_gcode(PROG), parse_tool_spec("flat:6"), _Stock(), resolution_mm=0.5, off_screen=True,
                     window_size=(160, 120), colours=colours)
    assert said in str(err.value), err.value


def test_the_windows_colours_are_drawn_as_the_other_views_draw_them():
    """A name matplotlib knows and pyvista does not, a hex string and a 0..1 triple are drawn in
    colour_rgb's colour; the keys not given keep PATH_COLOURS."""
    from woodcam.view.scene import colour_rgb
    from woodcam.view.scrub import DONE_ACTORS, PATH_COLOURS, TIP_ACTOR, TODO_ACTOR, ScrubCallback, gcode_window

    colours = {"feeds": "xkcd:sky blue", "rapids": "#00ff00", "tip": (0.5, 0.25, 1.0)}
    plotter, cb = gcode_window(read_gcode(PROG), parse_tool_spec("flat:6"), _Stock(), resolution_mm=0.5,
                               off_screen=True, window_size=(160, 120), colours=colours)
    try:
        cb(8)
        for name, key in ((DONE_ACTORS[0], "feeds"), (DONE_ACTORS[1], "rapids"), (TODO_ACTOR, "todo"),
                          (TIP_ACTOR, "tip")):
            want = colour_rgb(colours.get(key, PATH_COLOURS[key]), "test")
            np.testing.assert_allclose(np.asarray(plotter.actors[name].GetProperty().GetColor()) * 255, want,
                                       atol=0.5, err_msg=name)
    finally:
        plotter.close()
    with pytest.raises(WoodcamError, match=r"^ScrubCallback: colours\['feeds'\] must be .*did you mean 'royalblue'"):
        ScrubCallback(None, read_gcode(PROG), parse_tool_spec("flat:6"), _Stock(), colours={"feeds": "royalblu"})


def test_the_stock_is_coloured_when_its_mesh_has_a_vertex_without_a_normal(monkeypatch):
    """The stock's vertices are coloured with normals the wood accepts (it refuses a zero one)
    whatever the height-field mesh holds: an unreferenced vertex (trimesh's normal there is
    zero) takes +Z; the others keep trimesh's."""
    import trimesh

    import woodcam as w
    import woodcam.toolpath.mesh
    from woodcam.view.scrub import _stock_polydata

    real = woodcam.toolpath.mesh.heightfield_mesh

    def with_a_stray_vertex(*args, **kwargs):
        mesh = real(*args, **kwargs)
        return trimesh.Trimesh(np.vstack([mesh.vertices, [[1.0, 1.0, 1.0]]]), mesh.faces, process=False)

    monkeypatch.setattr(woodcam.toolpath.mesh, "heightfield_mesh", with_a_stray_vertex)
    seen = []

    class Recording(w.Wood):
        def color(self, points_mm, normals):
            seen.append(np.array(normals))
            return super().color(points_mm, normals)

    wood = Recording(w.builtin_block("flat-sawn").field)
    poly = _stock_polydata(pv, np.full((8, 12), 20.0), _Stock.size_mm, wood)
    assert poly.n_points == len(seen[0]) and poly.point_data["rgb"].shape == (poly.n_points, 3)
    np.testing.assert_array_equal(seen[0][-1], [0.0, 0.0, 1.0])


def test_the_slider_counts_a_subroutine_s_moves_at_the_line_that_called_it():
    """The slider took a subroutine's moves at their lines in its body: a slot subroutine at
    lines 1-5 called on lines 8 and 10 showed both slots cut at line 9 (and its range began at
    line 2). Its lines are main-program lines: at 9 the first slot alone is cut and drawn done."""
    from woodcam.view.scrub import DONE_ACTORS, gcode_window

    prog = read_gcode("o100 sub\nG0 X#1 Y10 Z1\nG1 Z-3 F300\nG1 X[#1+10]\nG0 Z5\no100 endsub\n"
                      "G21 G90 M3 S9000\no100 call [10]\nG0 X50 Y30 Z5\no100 call [30]\nM2\n")
    tool = parse_tool_spec("flat:6")
    plotter, cb = gcode_window(prog, tool, _Stock(), resolution_mm=0.5, off_screen=True,
                               window_size=(160, 120), until_line=9)
    try:
        assert (cb.first_line, cb.last_line) == (8, 10)
        first = simulate(prog[:4], tool, _Stock.size_mm, resolution_mm=0.5).heightmap
        np.testing.assert_array_equal(cb.heightmap, first)
        assert _removed(cb.heightmap) > 0
        done = plotter.actors[DONE_ACTORS[0]].GetMapper().GetInput()
        assert done.bounds[1] == pytest.approx(20.0)  # the done feeds end at the first slot's X20
        cb(10)
        np.testing.assert_allclose(_removed(cb.heightmap), 2 * _removed(first), rtol=1e-6)
    finally:
        plotter.close()
