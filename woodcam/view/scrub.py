"""The G-code window: the simulated stock with its toolpath, and a slider that scrubs the
simulation to any source line.

:class:`ScrubCallback` is what the slider calls with a line number: it simulates the program up
to that line (forward from the last state when the slider moves forward, from the start stock
when it moves back: the height field only ever loses material), meshes the height field at the
window's grid (:data:`WINDOW_GRID_CELLS` cells across, block means), colours
its vertices with the wood, and replaces the stock actor; the toolpath is drawn done (blue
feeds, red rapids) up to the line and grey after it, with the tool tip marked. Everything but
the window itself runs off screen, so the tests drive the callback directly.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import WoodcamError

#: Actor names of the G-code window.
STOCK_ACTOR = "woodcam-gcode-stock"
DONE_ACTORS = ("woodcam-path-feeds", "woodcam-path-rapids")
TODO_ACTOR = "woodcam-path-todo"
TIP_ACTOR = "woodcam-tool-tip"
#: Cells across the stock mesh of the window (a 1280-pixel window shows about this many).
WINDOW_GRID_CELLS = 400
#: The window's colours (``colours=`` replaces any of them), read by the views' one colour rule
#: (:func:`woodcam.view.scene.colour_rgb`), never by pyvista's own: done feeds and rapids (as
#: the screenshots' overlay), the moves still to come (drawn half transparent), the tool tip.
PATH_COLOURS = {"feeds": "royalblue", "rapids": "red", "todo": "lightgrey", "tip": "orange"}


def _path_colours(colours, who: str) -> dict[str, tuple[float, float, float]]:
    """:data:`PATH_COLOURS` with ``colours`` (a dict of some of its keys, or None) in their
    place, each as the 0..1 floats handed to pyvista by :func:`woodcam.view.scene.colour_rgb`'s
    rule (a name pyvista alone knows, 'royal_blue', is refused with the close matches, as in
    the other views; one matplotlib alone knows, 'xkcd:sky blue', is drawn). A WoodcamError
    naming ``who``, the key and the value, with the close key for one not in the table. The
    window handed its names straight to pyvista."""
    from .._checks import did_you_mean
    from .scene import _pyvista_rgb

    if colours is None:
        colours = {}
    if not isinstance(colours, dict):
        raise WoodcamError(f"{who}: colours must be a dict of some of {', '.join(PATH_COLOURS)} to a colour, "
                           f"e.g. {{'feeds': 'tab:blue'}}; got {colours!r:.60}")
    unknown = [k for k in colours if k not in PATH_COLOURS]
    if unknown:
        near = did_you_mean(str(unknown[0]), PATH_COLOURS)
        raise WoodcamError(f"{who}: colours has an unknown key {unknown[0]!r}; "
                           + (f"{near} " if near else "") + f"the keys are {', '.join(PATH_COLOURS)}")
    return {key: _pyvista_rgb(colours.get(key, default), who, f"colours[{key!r}]")
            for key, default in PATH_COLOURS.items()}


class ScrubCallback:
    """Slider callback: ``callback(line)`` shows the stock as simulated up to main-program
    ``line`` (:meth:`.Program.until_line`: a subroutine's moves at their call's line).

    ``program`` (a :class:`woodcam.toolpath.Program`), ``tools`` as
    :func:`woodcam.toolpath.simulate` takes them, the ``stock`` (size and wood), the G-code
    zero's block-frame position ``work_offset_mm`` and the simulation's ``resolution_mm``;
    ``initial_heightmap`` is the stock earlier programs of the job left; ``heightmap``, when
    given, the stock already simulated up to source line ``line`` (the last line when None; the
    CLI has it), so a first call at that line draws it without simulating the program again.
    ``colours`` replaces some of :data:`PATH_COLOURS` (:func:`_path_colours`).
    After a call, :attr:`line` is the line shown and :attr:`heightmap` its stock.
    """

    def __init__(self, plotter, program, tools, stock, *, work_offset_mm=None,
                 resolution_mm: float = 0.1, initial_heightmap=None, heightmap=None,
                 line: int | None = None, colours: dict | None = None):
        if not len(program):
            raise WoodcamError("ScrubCallback: the program has no moves; nothing to scrub")
        self.colours = _path_colours(colours, "ScrubCallback")
        self.plotter = plotter
        self.program = program
        self.tools = tools
        self.size_mm = tuple(float(v) for v in stock.size_mm)
        self.wood = stock.wood
        self.offset = (np.array([0.0, 0.0, self.size_mm[2]]) if work_offset_mm is None
                       else np.asarray(work_offset_mm, float))
        self.resolution_mm = float(resolution_mm)
        self.start = initial_heightmap
        self.line: int | None = None
        self.heightmap = None
        seg = np.stack([program.start_mm + self.offset, program.end_mm + self.offset], axis=1)
        self._seg = seg
        # the slider is a main-program line: a subroutine's moves count at their call's (ran_line)
        self.first_line, self.last_line = int(program.ran_line.min()), int(program.ran_line.max())
        if heightmap is not None:  # the stock at ``line`` (lines past the last: the last's)
            self.heightmap = np.asarray(heightmap, float)
            self.line = self.last_line if line is None else min(int(line), self.last_line)

    def __call__(self, value) -> None:
        from ..toolpath.simulate import simulate

        line = int(round(float(value)))
        line = min(max(line, self.first_line), self.last_line)
        forward = self.line is not None and line >= self.line
        moves = self.program.lines_between(self.line if forward else None, line)
        hm = self.heightmap if forward else self.start
        if len(moves):
            hm = simulate(moves, self.tools, self.size_mm, resolution_mm=self.resolution_mm,
                          work_offset_mm=self.offset, initial_heightmap=hm).heightmap
        elif hm is None:
            nx = max(1, round(self.size_mm[0] / self.resolution_mm))
            ny = max(1, round(self.size_mm[1] / self.resolution_mm))
            hm = np.full((ny, nx), self.size_mm[2])
        self.heightmap, self.line = hm, line
        self._draw()

    def _draw(self) -> None:
        import pyvista as pv

        p = self.plotter
        p.add_mesh(_stock_polydata(pv, self.heightmap, self.size_mm, self.wood), scalars="rgb",
                   rgb=True, name=STOCK_ACTOR, smooth_shading=False, ambient=0.3,
                   diffuse=0.7, specular=0.05)
        done = self.program.ran_line <= self.line
        feed = self.program.kind == 1
        for name, sel, colour in ((DONE_ACTORS[0], done & feed, self.colours["feeds"]),
                                  (DONE_ACTORS[1], done & ~feed, self.colours["rapids"]),
                                  (TODO_ACTOR, ~done, self.colours["todo"])):
            if sel.any():
                p.add_mesh(_lines(pv, self._seg[sel]), color=colour, line_width=1.0,
                           name=name, opacity=1.0 if name != TODO_ACTOR else 0.5)
            else:
                p.remove_actor(name)
        k = np.flatnonzero(done)
        if len(k):
            tip = self._seg[k[-1], 1]
            p.add_mesh(pv.Sphere(radius=0.01 * max(self.size_mm), center=tip), color=self.colours["tip"],
                       name=TIP_ACTOR)
        else:
            p.remove_actor(TIP_ACTOR)


def _lines(pv, seg):
    n = len(seg)
    cells = np.column_stack([np.full(n, 2), 2 * np.arange(n), 2 * np.arange(n) + 1])
    return pv.PolyData(seg.reshape(-1, 3), lines=cells.ravel())


def _stock_polydata(pv, heightmap, size_mm, wood):
    """The stock below ``heightmap`` meshed at :data:`WINDOW_GRID_CELLS` cells across, its
    vertices coloured by ``wood`` (point array ``"rgb"``, uint8)."""
    from ..appearance.wood import vertex_color_normals, wood_colors
    from ..toolpath.mesh import heightfield_mesh

    hm = np.asarray(heightmap, float)
    k = max(1, math.ceil(max(hm.shape) / WINDOW_GRID_CELLS))
    if k > 1:
        ny, nx = (-(-n // k) for n in hm.shape)
        pad = np.pad(hm, ((0, ny * k - hm.shape[0]), (0, nx * k - hm.shape[1])), mode="edge")
        hm = pad.reshape(ny, k, nx, k).mean(axis=(1, 3))
    # no planar merging: vertex colours interpolated over a merged fan would draw stars
    mesh = heightfield_mesh(hm, size_mm, flat_tol_mm=-1.0)
    v = np.asarray(mesh.vertices)
    # the checked seam: a user's wood's NaN or 0..255 colours were drawn black or white
    rgb = np.asarray(wood_colors(wood, v, vertex_color_normals(mesh)), float)
    faces = np.column_stack([np.full(len(mesh.faces), 3), mesh.faces]).ravel()
    poly = pv.PolyData(v, faces)
    poly.point_data["rgb"] = np.round(np.clip(rgb, 0, 1) * 255).astype(np.uint8)
    return poly


def add_line_slider(plotter, callback: ScrubCallback, *, value: int | None = None):
    """Add the slider (source line, first to last) that drives ``callback``; it is called once
    now with ``value`` (default: the last line)."""
    start = callback.last_line if value is None else int(value)
    return plotter.add_slider_widget(
        callback, rng=[callback.first_line, callback.last_line], value=start,
        title="G-code line", pointa=(0.25, 0.92), pointb=(0.95, 0.92), fmt="%.0f",
        style="modern", interaction_event="end")


def check_display() -> None:
    """Raise a :class:`WoodcamError` when no window can open (no display): before the work."""
    from .scene import check_display as check

    check("woodcam gcode --view", "render a picture instead with --screenshot (and --until-line N "
          "for a scrubbed frame)")


def gcode_window(program, tools, stock, *, work_offset_mm=None, resolution_mm: float = 0.1,
                 initial_heightmap=None, until_line: int | None = None, heightmap=None,
                 window_size: tuple[int, int] = (1280, 960), off_screen: bool = False,
                 colours: dict | None = None):
    """Open the G-code window (stock, toolpath, line slider, view keys) at ``until_line`` (the
    last line when None); returns ``(plotter, callback)`` after it closes. ``heightmap``: the
    stock already simulated up to ``until_line``, shown first without simulating again
    (:class:`ScrubCallback`). ``off_screen`` builds it without showing (tests drive the
    :class:`ScrubCallback` as the slider would). ``colours`` replaces some of
    :data:`PATH_COLOURS`, checked before the window opens (:func:`_path_colours`)."""
    from .camera import set_camera
    from .scene import _plotter, _pyvista, add_view_keys

    pv = _pyvista()
    colours = _path_colours(colours, "gcode_window")  # before any window
    if not off_screen:
        check_display()
    plotter = _plotter(pv, off_screen=off_screen, window_size=window_size, title="woodcam gcode")
    callback = ScrubCallback(plotter, program, tools, stock, work_offset_mm=work_offset_mm,
                             resolution_mm=resolution_mm, initial_heightmap=initial_heightmap,
                             heightmap=heightmap, line=until_line, colours=colours)
    add_line_slider(plotter, callback, value=until_line)
    W, D, H = callback.size_mm
    set_camera(plotter, "iso", (0.0, W, 0.0, D, 0.0, H))
    add_view_keys(plotter, callback.size_mm)
    plotter.add_axes()
    if not off_screen:
        plotter.show()
    return plotter, callback
