"""Part sources -> one watertight :class:`manifold3d.Manifold` in the block frame, millimetres.

A *part* is the solid a woodworker wants to cut out of the block. It is modelled directly in the
block frame of ``docs/conventions.md`` (origin at the block's bottom-front-left corner, X width,
Y depth, Z up, mm); woodcam never moves or scales it.

Accepted sources (:func:`load_part`):

- a build123d ``Part`` / ``Solid`` / ``Compound`` (any ``build123d`` ``Shape``), or a
  ``BuildPart`` builder (its ``.part`` is used);
- a cadquery ``Workplane`` (all solids on its stack) or ``Shape``;
- a ``trimesh.Trimesh`` or ``trimesh.Scene``;
- a ``manifold3d.Manifold``;
- a list or tuple of any of these (incl. a build123d ``ShapeList``): their union;
- a path (``str`` / ``Path``) to ``.step``/``.stp`` (B-rep, read with OpenCascade),
  ``.stl``/``.obj``/``.ply``/``.off``/``.glb``/``.gltf`` (meshes, read with trimesh, coordinates taken as mm in the
  block frame as stored: no unit or Y-up conversion; except woodcam's own GLB/OBJ, put back in
  the block frame, and another program's glTF whose part spans under 1 unit, read as the glTF
  spec's metres with +Y up, with a warning), or a ``.py`` script that defines a
  module-level ``part`` (any of the objects above) or, as in CQ-editor, passes it to
  ``show_object`` (several calls: their union; what is shown wins over ``part``);
- a cadquery ``Assembly`` (its parts where it places them).

B-rep shapes (build123d, cadquery, STEP) are tessellated with OpenCascade's
``BRepMesh_IncrementalMesh`` at a chord tolerance (mm) and an angular tolerance (degrees at this
API, radians inside), on a copy of the shape so an earlier, coarser triangulation cached on the
user's shape never leaks in. Each solid becomes its own manifold and the solids are unioned, so
solids that touch or overlap still give one valid manifold.
"""

from __future__ import annotations

import contextlib
import math
import runpy
import sys
import threading
from collections.abc import MutableMapping
from dataclasses import dataclass, field
from numbers import Integral, Real
from pathlib import Path
from typing import Any

import numpy as np

from .._checks import check_number
from ..errors import WoodcamError, caused_by, require
from ..units import said, say_length, say_volume
from ..tolerances import (
    MAX_PART_TRIANGLES,
    MESH_SIMPLIFY_MAX_REL_TOL,
    TESSELLATION_ANGLE_DEG,
    TESSELLATION_MIN_TOL_MM,
    TESSELLATION_REL_TOL,
    TESSELLATION_TEXEL_FRACTION,
    TESSELLATION_TOL_MM,
)

#: Texel density (texels per mm) the default tessellation assumes when load_part is not told
#: the bake's: woodcam bake's default.
_DEFAULT_TEXELS_PER_MM = 10.0

#: Re-meshing rounds of the triangle budget, and the loosest angular tolerance it goes to
#: (below the 30 degree crease angle of the exported normals, so curved faces stay smooth).
_BUDGET_TRIES = 3
_MAX_BUDGET_ANGLE_DEG = 20.0
#: Simplification rounds of a mesh part over the triangle budget: each loosens the tolerance by
#: the overshoot, at least by 1.25 (1.25^24 = 211: a quarter texel to 5 mm); the tolerance's
#: cap (MESH_SIMPLIFY_MAX_REL_TOL) ends it sooner.
_MESH_BUDGET_TRIES = 24
_MESH_BUDGET_MIN_STEP = 1.25  # doubling overshot: 5120 -> 1364 -> 608 triangles for a budget of 1000

#: File suffixes :func:`load_part` reads, by kind.
STEP_SUFFIXES = (".step", ".stp")
MESH_SUFFIXES = (".stl", ".obj", ".ply", ".off", ".glb", ".gltf")
SCRIPT_SUFFIXES = (".py",)
SUPPORTED_SUFFIXES = STEP_SUFFIXES + MESH_SUFFIXES + SCRIPT_SUFFIXES


def auto_tolerance_mm(diagonal_mm: float, texels_per_mm: float = _DEFAULT_TEXELS_PER_MM) -> float:
    """Default chord tolerance (mm) for a part whose bounding-box diagonal is ``diagonal_mm``,
    baked at ``texels_per_mm``: ``min(TESSELLATION_TEXEL_FRACTION / texels_per_mm,
    TESSELLATION_REL_TOL * diagonal_mm)``, at least ``TESSELLATION_MIN_TOL_MM``: well under a
    texel, and finer still on small parts (reasons in :mod:`woodcam.tolerances`). The 113 mm
    demo bowl at 10 texels/mm: 0.025 mm; a 17 mm knob: 0.017 mm; a 2 m table top at 2
    texels/mm: 0.125 mm."""
    texels_per_mm = check_number(texels_per_mm, "auto_tolerance_mm: texels_per_mm", lo=0, lo_open=True,
                                 fix="the bake's texel density, e.g. 10")
    # 0 gave the floor, 0.002 mm, for a part of no size: no part, a size of the wrong thing
    diagonal_mm = check_number(diagonal_mm, "auto_tolerance_mm: diagonal_mm", lo=0, lo_open=True,
                               fix="the part's bounding-box diagonal in mm")
    return _auto_tolerance(diagonal_mm, texels_per_mm)


def _auto_tolerance(diagonal_mm: float, texels_per_mm: float) -> float:
    """:func:`auto_tolerance_mm`'s rule, unchecked (a B-rep with no box measures 0: the floor)."""
    texel_limit = TESSELLATION_TEXEL_FRACTION / texels_per_mm
    return max(TESSELLATION_MIN_TOL_MM, min(texel_limit, TESSELLATION_REL_TOL * diagonal_mm))


def load_part(
    source: Any,
    *,
    tolerance_mm: float | None = None,
    angular_tolerance_deg: float = TESSELLATION_ANGLE_DEG,
    timeout_s: float | None = None,
    max_triangles: int | None = MAX_PART_TRIANGLES,
    report: dict | None = None,
    texels_per_mm: float = _DEFAULT_TEXELS_PER_MM,
) -> Any:
    """Turn a part source into one watertight manifold in the block frame (mm).

    A ``.py`` part script is **trusted code**: it runs inside this process with your rights
    (it can read, write and delete your files). Only load scripts you wrote or have read.

    Parameters
    ----------
    source : build123d Shape | BuildPart | cadquery Workplane | Shape | Assembly | trimesh.Trimesh
        | trimesh.Scene | manifold3d.Manifold | list of these | str | Path
        The part, modelled in the block frame in millimetres, or a path to a ``.step``/``.stp``,
        ``.stl``, ``.obj``, ``.ply``, ``.off``, ``.glb``/``.gltf`` file or a ``.py`` script defining ``part``
        or passing it to ``show_object`` (CQ-editor's convention: the union of the shown
        objects, which win over ``part``; a ``part`` not among them is named in a warning)
        (run with ``runpy`` under the name ``"__woodcam_part__"``, so its
        ``if __name__ == "__main__":`` block does not run; its folder is on ``sys.path``
        meanwhile so it can import helpers next to it).
    tolerance_mm : float or None
        Chord tolerance (mm, > 0) for tessellating B-rep sources: the largest distance between
        the true surface and its triangles. None (default): :func:`auto_tolerance_mm` of each
        B-rep's bounding-box diagonal and ``texels_per_mm``. Ignored for mesh sources.
    angular_tolerance_deg : float
        Angular tolerance (degrees, in (0, 90]) for tessellating B-rep sources: the largest
        normal jump between neighbouring triangles on a curved face. Ignored for meshes.
    timeout_s : float, optional
        Stop loading (running a script, tessellating) after this many seconds with a
        WoodcamError. POSIX main thread only (``SIGALRM``); it is checked between Python
        statements, so one long OCCT call finishes before it fires. Not a sandbox.
    max_triangles : int or None
        Triangle budget of the part (default :data:`woodcam.tolerances.MAX_PART_TRIANGLES`):
        above it a B-rep source is re-meshed with looser tolerances, and a mesh source (a mesh
        file, a trimesh or manifold3d object) is simplified by manifold3d's
        ``Manifold.simplify`` (the solid stays a valid manifold; its surfaces move by less than
        the tolerance said); either is stated in ``report["notes"]``. None keeps every triangle.
    report : dict or None
        Filled with the tolerances used (``tolerance_mm``, ``angular_tolerance_deg``, and
        ``tolerance_rule``: how the chord tolerance was chosen), the triangle count, the
        budget, notes about re-meshing and ``simplified``: ``{"from": n, "to": m,
        "tolerance_mm": t}`` for a mesh simplified to the budget, else None.
    texels_per_mm : float
        Texel density of the bake the part is meant for (> 0); sets the default tolerance.

    Returns
    -------
    manifold3d.Manifold
        Non-empty, valid (oriented 2-manifold) solid with positive volume, block frame, mm.

    Raises
    ------
    WoodcamError
        For an unsupported object or suffix, a missing or unreadable file, a script that fails
        or neither defines ``part`` nor calls ``show_object`` (with a build123d/cadquery object,
        a cadquery ``Assembly``, a mesh or a manifold), empty geometry, or a mesh that is not a closed solid even
        after repair (hole filling, normal fixing).
    """
    if tolerance_mm is not None and not (isinstance(tolerance_mm, Real)
                                         and math.isfinite(tolerance_mm) and tolerance_mm > 0):
        raise WoodcamError(
            f"tolerance_mm must be a finite number > 0 (chord tolerance in mm) or None (scaled "
            f"to the part and the texel), got {tolerance_mm!r}; use e.g. {TESSELLATION_TOL_MM}"
        )
    if not (isinstance(texels_per_mm, Real) and math.isfinite(texels_per_mm)
            and texels_per_mm > 0):
        raise WoodcamError(f"texels_per_mm must be a finite number > 0 (the bake's texel "
                           f"density), got {texels_per_mm!r}; use e.g. 10")
    if not (isinstance(angular_tolerance_deg, Real) and 0 < angular_tolerance_deg <= 90):
        raise WoodcamError(
            f"angular_tolerance_deg must be in (0, 90] degrees, got {angular_tolerance_deg!r}; "
            f"use e.g. {TESSELLATION_ANGLE_DEG}"
        )
    if timeout_s is not None and not (isinstance(timeout_s, Real) and math.isfinite(timeout_s)
                                      and timeout_s > 0):
        raise WoodcamError(f"timeout_s must be a finite number of seconds > 0 or None; got "
                           f"{timeout_s!r}")
    if report is not None and not isinstance(report, MutableMapping):  # [] was an AttributeError after the load
        raise WoodcamError(f"report must be a dict to fill with the tessellation notes, or None; got "
                           f"{type(report).__name__}; pass report={{}}")
    tess = _Tessellation(None if tolerance_mm is None else float(tolerance_mm),
                         math.radians(angular_tolerance_deg), _check_budget(max_triangles),
                         texels_per_mm=float(texels_per_mm))
    with _time_limit(timeout_s, source):
        solid = tess.fit_mesh(_load(source, tess, origin="part"), f"part {str(source)[:200]!r}"
                              if isinstance(source, (str, Path)) else "the part")
    if report is not None:
        report.update(tess.report())
    elif tess.simplified:  # no report to say it in (woodcam place, woodify, gcode): a warning
        import warnings

        from ..errors import WoodcamWarning

        warnings.warn(WoodcamWarning(str(tess.notes[-1])), stacklevel=2)
    return solid


class _PartTimeout(BaseException):
    """Raised by the alarm; a BaseException so a script's ``except Exception`` cannot eat it."""


@contextlib.contextmanager
def _time_limit(seconds: float | None, source):
    """Raise a WoodcamError if the block runs longer than ``seconds`` (SIGALRM timer)."""
    import signal
    import threading

    if seconds is None:
        yield
        return
    if not hasattr(signal, "setitimer") or threading.current_thread() is not threading.main_thread():
        raise WoodcamError("timeout_s needs the main thread of a POSIX process (SIGALRM); "
                           "run without a timeout here")

    def _alarm(signum, frame):
        raise _PartTimeout

    old = signal.signal(signal.SIGALRM, _alarm)
    # fires again every 0.25 s after the deadline: a library that swallowed the first raise
    # (an import's ``except BaseException``) does not get the script off the hook
    signal.setitimer(signal.ITIMER_REAL, float(seconds), 0.25)
    try:
        yield
    except _PartTimeout:
        raise WoodcamError(f"loading the part {str(source)[:200]!r} took longer than the timeout "
                           f"of {seconds:g} s; raise --timeout or check the script for an endless "
                           "loop") from None
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


# --------------------------------------------------------------------------------- dispatch


def _load(source: Any, tess: "_Tessellation", origin: str):
    """Dispatch on the source's type; ``origin`` names the source in error messages."""
    import manifold3d
    import trimesh

    from .._interrupt import check

    check()  # trimesh's imports swallow a Ctrl-C (except BaseException): end before the script runs
    if source is None:
        raise WoodcamError(
            f"{origin} is None; the script or builder produced no shape: make sure it builds "
            f"a solid and assigns it"
        )
    if isinstance(source, (manifold3d.Manifold, trimesh.Trimesh, trimesh.Scene)):
        tess.mesh_input = True  # its triangles are the source's: the budget simplifies them
    if isinstance(source, manifold3d.Manifold):
        return _check_manifold(source, origin)
    if isinstance(source, trimesh.Trimesh):
        return _manifold_from_trimesh(source, origin)
    if isinstance(source, trimesh.Scene):
        return _manifold_from_scene(source, origin)
    if isinstance(source, (str, Path)):
        return _load_path(Path(source), tess)

    if isinstance(source, (list, tuple)):  # incl. build123d ShapeList: union of the items
        if not source:
            raise WoodcamError(f"{origin} is an empty {type(source).__name__}; pass a solid")
        return _union([_load(item, tess, f"{origin}[{i}]")
                       for i, item in enumerate(source)], origin)

    # the CAD kernels are only imported when the object already comes from one of them
    module = type(source).__module__ or ""
    if module.startswith("build123d"):
        bd = require("build123d", "cad", "loading build123d parts")
        if isinstance(source, bd.Shape):  # Part, Solid, Compound, ...
            return _manifold_from_topods(source.wrapped, tess, origin)
        if isinstance(source, bd.BuildPart):
            return _load(source.part, tess, f"{origin} (BuildPart.part)")
    if module.startswith("cadquery"):
        cq = require("cadquery", "cad", "loading cadquery parts")
        if isinstance(source, cq.Workplane):  # every Shape on the stack
            shapes = [v.wrapped for v in source.vals() if isinstance(v, cq.Shape)]
            if not shapes:
                raise WoodcamError(
                    f"{origin}: the cadquery Workplane holds no shape (its stack is "
                    f"{source.vals()!r}); build a solid first, e.g. .box(...) or .extrude(...)"
                )
            return _union([_manifold_from_topods(s, tess, origin) for s in shapes],
                          origin)
        if isinstance(source, cq.Shape):
            return _manifold_from_topods(source.wrapped, tess, origin)
        if isinstance(source, cq.Assembly):  # every part where the assembly puts it
            return _manifold_from_topods(source.toCompound().wrapped, tess, origin)
    if module.startswith("OCP") and hasattr(source, "ShapeType"):  # raw TopoDS_Shape
        return _manifold_from_topods(source, tess, origin)

    raise WoodcamError(
        f"{origin}: cannot use an object of type {type(source).__module__}."
        f"{type(source).__qualname__} as a part; pass a build123d Part/Solid/Compound, a cadquery "
        f"Workplane/Shape/Assembly, a trimesh.Trimesh, a manifold3d.Manifold, or a path to a file with "
        f"suffix {', '.join(SUPPORTED_SUFFIXES)}"
    )


def check_part_path(path) -> Path:
    """``path`` as a part file :func:`load_part` can read (a supported suffix, an existing file),
    else a WoodcamError saying what to do; for a command to check before its slow work (the
    block's fit)."""
    path = Path(path)
    if path.suffix.lower() not in SUPPORTED_SUFFIXES:
        raise WoodcamError(
            f"part file {str(path)!r} has unsupported suffix {path.suffix!r}; use one of "
            f"{', '.join(SUPPORTED_SUFFIXES)} (export the part from your CAD program as STEP or "
            f"STL)"
        )
    if not path.is_file():
        raise WoodcamError(
            f"part file {str(path)!r} does not exist or is not a file; check the path"
        )
    return path


def _load_path(path: Path, tess: "_Tessellation"):
    """Read a part file; the suffix picks the reader."""
    suffix = check_part_path(path).suffix.lower()
    if suffix in SCRIPT_SUFFIXES:
        return _load_script(path, tess)
    if path.stat().st_size == 0:  # was 'contains no triangles: ... not a valid mesh' or a parser status
        raise WoodcamError(
            f"part file {str(path)!r} is empty (0 bytes): the export was cut short or failed; export "
            f"the part from your CAD program again")
    if suffix in STEP_SUFFIXES:
        return _load_step(path, tess)
    tess.mesh_input = True
    return _load_mesh_file(path)


class _ScriptOutput:
    """A part script's stdout while it runs: each line to stderr, after the script's name
    (``bowl.py: wall 4 mm``). Its prints went to stdout among the command's own output (the
    summary line a shell script reads, ``woodcam place``'s table); CQ-editor shows them in its
    log panel, apart from the part: here they stay on the terminal, apart from woodcam's
    output and named. ``log()`` (CQ-editor's) writes here too."""

    def __init__(self, name: str):
        self.prefix, self.pending = f"{name}: ", ""

    def write(self, text: str) -> int:
        from .._interrupt import requested

        if requested():  # a library that swallowed a Ctrl-C saying so ('VTK not installed'): dropped,
            return len(text)  # as woodcam's stdout drops it (woodcam._interrupt._MutedAfterCtrlC)
        *lines, self.pending = (self.pending + text).split("\n")
        for line in lines:
            self._say(line)
        return len(text)

    def _say(self, line: str) -> None:
        from .._progress import write

        # past a progress bar being drawn (tqdm.write), not into its line; sys.stderr looked up
        # now: the one in use (a test's capture, a redirect)
        write(f"{self.prefix}{line}", file=sys.stderr)

    def flush(self) -> None:
        if self.pending:  # a last print without its newline (print(..., end=""))
            self._say(self.pending)
            self.pending = ""
        sys.stderr.flush()

    def isatty(self) -> bool:
        return False


def _load_script(path: Path, tess: "_Tessellation"):
    """Run a part script (``runpy``, not as ``__main__``) and load what it passes to
    ``show_object`` (their union), else its module-level ``part``: any object :func:`_load`
    takes (build123d, cadquery Workplane/Shape/Assembly, trimesh, manifold3d)."""
    folder = str(path.resolve().parent)
    shown: list = []

    names: list = []

    def show_object(obj, name=None, *args, **kwargs):  # CQ-editor's and cq-cli's way to give the result
        shown.append(obj)
        names.append(name)

    # CQ-editor's other two names for its scripts (a script calling them failed with NameError):
    # debug() draws a helper shape in translucent red, not the part; log() writes a line to its log
    def debug(obj, *args, **kwargs):
        pass

    def log(message, *args, **kwargs):
        print(message)  # to the script's output, as its prints (stderr, prefixed: _ScriptOutput)

    def show(*objs, names=None, **kwargs):  # ocp_vscode's (the OCP CAD viewer of build123d's docs)
        names = list(names) if isinstance(names, (list, tuple)) else [names] * len(objs)
        for obj, name in zip(objs, names + [None] * len(objs)):
            show_object(obj, name)

    sys.path.insert(0, folder)  # like `python script.py`: helpers next to the script import
    viewer = sys.modules.get("ocp_vscode")
    # build123d scripts import ocp_vscode's show() to see the part in VS Code: it failed with
    # ModuleNotFoundError (or, installed, sent the part to a viewer port and woodcam got nothing)
    sys.modules["ocp_vscode"] = _viewer_stand_in(show, show_object)
    output = _ScriptOutput(path.name)
    try:
        with contextlib.redirect_stdout(output):
            namespace = runpy.run_path(str(path), init_globals={"show_object": show_object, "debug": debug,
                                                                "log": log},
                                       run_name="__woodcam_part__")
    except SystemExit as err:
        raise WoodcamError(
            f"part script {str(path)!r} called sys.exit({err.code!r}) while being loaded; "
            f"guard command-line code with `if __name__ == \"__main__\":`"
        ) from err
    except Exception as err:
        if caused_by(err, _PartTimeout):  # a library turned the alarm into its own error (pybind11's import:
            raise _PartTimeout from err  # 'ImportError: initialization failed', said as the script's fault)
        line = _script_line(err, path)
        cq = (" (CQ-editor imports cadquery as `cq` for its scripts: add `import cadquery as cq`)"
              if isinstance(err, NameError) and err.name == "cq" else "")
        raise WoodcamError(
            f"part script {str(path)!r} failed{line} with {type(err).__name__}: {err}{cq}; run it with "
            f"`python {path}` to see the traceback and fix the script"
        ) from err
    finally:
        output.flush()
        if folder in sys.path:
            sys.path.remove(folder)
        if viewer is None:
            sys.modules.pop("ocp_vscode", None)
        else:
            sys.modules["ocp_vscode"] = viewer
    if shown:
        # What the script shows is what its author saw in CQ-editor: it wins over a `part`
        # variable, which may be a loop variable (`for part in parts: show_object(part)` loaded
        # only the last) or an intermediate; a `part` not among them is named, not dropped.
        if "part" in namespace and not any(namespace["part"] is obj for obj in shown):
            import warnings

            from ..errors import WoodcamWarning

            warnings.warn(WoodcamWarning(
                f"part script {str(path)!r} defines `part` and passes {len(shown)} other "
                f"object{'s' if len(shown) > 1 else ''} to show_object: loaded what it shows (as "
                f"CQ-editor does), not `part`; to load `part`, pass it to show_object too or "
                f"remove the show_object calls"), stacklevel=5)
        flat = [_without_volume(obj) for obj in shown]
        if any(flat) and not all(flat):
            # CQ-editor shows a sketch or a wire beside the solid; the union refused the script
            # for it ('cannot use an object of type cadquery.sketch.Sketch'): left out, and said
            import warnings

            from ..errors import WoodcamWarning

            left = [f"show_object[{i}]" + (f" ({names[i]!r})" if names[i] else "")
                    + f", a {type(obj).__module__.split('.')[0]} {type(obj).__name__}"
                    for i, (obj, f) in enumerate(zip(shown, flat)) if f]
            warnings.warn(WoodcamWarning(
                f"part script {str(path)!r} shows {len(left)} object{'s' if len(left) > 1 else ''} with no "
                f"volume ({'; '.join(left)}): left out of the part, carved what it shows with volume; "
                f"if one belongs to the part, extrude it into a solid"), stacklevel=5)
            shown = [obj for obj, f in zip(shown, flat) if not f]
        part = shown[0] if len(shown) == 1 else shown
        origin = f"what script {str(path)!r} passes to show_object"
    elif "part" not in namespace:
        shapes = _shapes_in(namespace)
        end = " at the end of the script"
        fix = ("it defines `result` (cadquery's convention): add `part = result` or "
               f"`show_object(result)`{end}" if "result" in namespace else
               # a script of `box = ...; lid = ...` was told to add `part = Box(10, 10, 10)`
               f"it defines {_say_shapes(namespace, shapes)}: add `part = {shapes[0]}`{end}" if len(shapes) == 1 else
               f"it defines {_say_shapes(namespace, shapes)}: add `part = [{', '.join(shapes)}]` (their "
               f"union) or pass the one you mean to show_object{end}" if shapes else
               # a part built under the guard was told to add `part = Box(10, 10, 10)`
               "its `if __name__ == \"__main__\":` block does not run when woodcam loads the script (as when "
               "it is imported): build `part` at module level, outside that block" if _has_main_guard(path) else
               "add e.g. `part = Box(10, 10, 10)` (a build123d/cadquery solid, trimesh mesh or "
               f"manifold){end}")
        raise WoodcamError(
            f"part script {str(path)!r} does not define a module-level variable `part` nor "
            f"call show_object; {fix}"
        )
    else:
        part = namespace["part"]
        origin = f"`part` of script {str(path)!r}"
    if isinstance(part, (str, Path)):
        raise WoodcamError(
            f"{origin} is a path ({str(part)!r}), but a script must define the part itself; "
            f"load the file in the script (e.g. build123d import_step) or pass the path directly"
        )
    return _load(part, tess, origin=origin)


class _Anything:
    """Whatever a script takes from the viewer besides show: a call that does nothing, with
    attributes of its own kind (``set_defaults(...)``, ``Camera.ISO``)."""

    def __call__(self, *args, **kwargs):
        return None

    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        return self


def _viewer_stand_in(show, show_object):
    """A module standing in for ``ocp_vscode`` while a part script runs: its ``show`` and
    ``show_object`` give the shapes to woodcam as CQ-editor's ``show_object`` does."""
    import types

    module = types.ModuleType("ocp_vscode", "woodcam's stand-in for the OCP CAD viewer: show() gives the part")
    module.show = show  # type: ignore[attr-defined]
    module.show_object = show_object  # type: ignore[attr-defined]
    module.__all__ = ["show", "show_object", "show_all", "set_port", "set_defaults", "reset_show",  # type: ignore[attr-defined]
                      "show_clear", "Camera", "Collapse"]
    module.__getattr__ = lambda name: _Anything()  # type: ignore[method-assign]
    return module


#: Objects of the CAD kernels that are never a solid (their names in build123d and cadquery).
_NO_VOLUME_TYPES = frozenset({"Sketch", "BuildSketch", "BuildLine", "Location", "Vector", "Plane", "Axis"})


def _without_volume(obj) -> bool:
    """Whether ``obj``, something a script shows, is a build123d or cadquery object that holds no
    solid nor shell (a sketch, face, wire, edge, point, location, or a Workplane of them); False
    for anything else (the loader judges it)."""
    module = (type(obj).__module__ or "").split(".")[0]
    if module not in ("build123d", "cadquery"):
        return False
    if type(obj).__name__ in _NO_VOLUME_TYPES:
        return True
    items = obj.vals() if type(obj).__name__ == "Workplane" else [obj]
    from OCP.TopAbs import TopAbs_SHELL, TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS_Shape

    for item in items:
        wrapped = getattr(item, "wrapped", None)
        if type(item).__name__ in _NO_VOLUME_TYPES or (isinstance(wrapped, TopoDS_Shape) and (
                wrapped.IsNull() or not (TopExp_Explorer(wrapped, TopAbs_SOLID).More()
                                         or TopExp_Explorer(wrapped, TopAbs_SHELL).More()))):
            continue
        return False  # a solid, or something the loader judges
    return True


def _has_main_guard(path: Path) -> bool:
    """Whether the script ``path`` has a module-level ``if __name__ == "__main__":`` block."""
    import ast

    try:
        tree = ast.parse(path.read_bytes())
    except (SyntaxError, ValueError, OSError):
        return False
    return any(isinstance(node, ast.If) and "__main__" in ast.dump(node.test) and "__name__" in ast.dump(node.test)
               for node in tree.body)


def _script_line(err: BaseException, path: Path) -> str:
    """`` at line N`` of the script ``path`` where ``err`` was raised (the last of its frames in
    the traceback: the call into a library or a helper module), or ``""`` (a SyntaxError says
    its own line)."""
    import traceback

    script = path.resolve()
    lines = [frame.lineno for frame in traceback.extract_tb(err.__traceback__)
             if frame.filename and Path(frame.filename).resolve() == script]
    return f" at line {lines[-1]}" if lines and lines[-1] else ""


#: Modules whose objects :func:`_load` takes as a part.
_PART_MODULES = ("build123d", "cadquery", "trimesh", "manifold3d", "OCP")


def _shapes_in(namespace: dict) -> list[str]:
    """Names of a script's module-level objects that could be its part (from a CAD or mesh
    library, not a module, class or function), in the order the script defines them."""
    import inspect

    return [name for name, value in namespace.items()
            if not name.startswith("_") and not inspect.ismodule(value) and not inspect.isclass(value)
            and not inspect.isroutine(value)
            and (type(value).__module__ or "").split(".")[0] in _PART_MODULES][:8]


def _say_shapes(namespace: dict, names: list[str]) -> str:
    """``build123d Part `box`, build123d Part `lid``` (type and name of each)."""
    return ", ".join(f"{(type(namespace[n]).__module__ or '').split('.')[0]} {type(namespace[n]).__name__} "
                     f"`{n}`" for n in names)


def _load_step(path: Path, tess: "_Tessellation"):
    """Read a STEP file with OpenCascade (lengths converted to mm by the reader)."""
    require("OCP", "cad", "reading STEP parts")
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPControl import STEPControl_Reader

    reader = STEPControl_Reader()
    with _occt_messages() as said:
        status = reader.ReadFile(str(path))
        if status == IFSelect_RetDone:
            reader.TransferRoots()
    if status != IFSelect_RetDone:
        why = next((line for line in said() if "ERR" in line), None)
        why = (f"OpenCascade: {why.replace('ERR StepFile : ', '')}" if why else
               f"OpenCascade status {getattr(status, 'name', status)}")
        raise WoodcamError(
            f"part file {str(path)!r} is not a readable STEP file ({why}); re-export it from your "
            f"CAD program as STEP AP203/AP214"
        )
    shape = reader.OneShape()
    if shape is None or shape.IsNull():
        raise WoodcamError(
            f"part file {str(path)!r} holds no shape; re-export the part as a solid"
        )
    return _manifold_from_topods(shape, tess, origin=f"STEP file {str(path)!r}")


#: Held over :func:`_occt_messages`' swap of OpenCascade's printers, which are global (one
#: messenger per process): two threads reading STEP at once each took the other's temporary
#: printer for the old ones and put it back, its file deleted, in place of the terminal's.
_OCCT_MESSAGES_LOCK = threading.Lock()


@contextlib.contextmanager
def _occt_messages():
    """Route OpenCascade's messages (its STEP parser prints them to stdout, in red, after
    woodcam's own error line) to a temporary file meanwhile; yields a function returning their
    lines, stripped of the ``****`` frame, once the block is over."""
    import os
    import re
    import tempfile

    from OCP.Message import Message, Message_Gravity, Message_PrinterOStream

    messenger = Message.DefaultMessenger_s()
    lines: list[str] = []
    with _OCCT_MESSAGES_LOCK, tempfile.TemporaryDirectory(prefix="woodcam-occt-") as folder:
        log = os.path.join(folder, "occt.log")
        printers = list(messenger.Printers())
        printer = Message_PrinterOStream(log, False, Message_Gravity.Message_Warning)
        for old in printers:
            messenger.RemovePrinter(old)
        messenger.AddPrinter(printer)
        try:
            yield lambda: lines
        finally:
            messenger.RemovePrinter(printer)
            for old in printers:
                messenger.AddPrinter(old)
            del printer  # closes (flushes) its file
            with contextlib.suppress(OSError):
                with open(log, encoding="utf-8", errors="replace") as fh:
                    lines.extend(re.sub(r"\s+", " ", line.strip(" *\n")) for line in fh if line.strip(" *\n"))


def _load_mesh_file(path: Path):
    """Read an STL/OBJ/GLB/glTF file with trimesh; every mesh in it becomes one solid."""
    import trimesh

    origin = f"mesh file {str(path)!r}"
    try:
        scene = trimesh.load_scene(str(path), file_type=path.suffix.lower().lstrip("."))
    except Exception as err:
        raise WoodcamError(
            f"{origin} could not be read as {path.suffix.upper().lstrip('.')} "
            f"({type(err).__name__}: {err}); check that it is a mesh file and re-export it"
        ) from err
    if path.suffix.lower() == ".stl" and not any(len(getattr(g, "faces", ())) for g in scene.geometry.values()):
        scene = _binary_stl_miscounted(path, origin) or scene
    _undo_woodcam_export_frame(scene, path)
    return _manifold_from_scene(scene, origin)


#: A binary STL: an 80-byte header, the triangle count (uint32), then 50 bytes a triangle.
_STL_HEADER_BYTES = 84
_STL_TRIANGLE = np.dtype([("normal", "<f4", (3,)), ("corners", "<f4", (3, 3)), ("attribute", "<u2")])


def _binary_stl_miscounted(path: Path, origin: str):
    """A binary STL whose header's triangle count disagrees with its size (some exporters write
    0 or leave it stale), read by its size with a warning: trimesh read no triangles from it and
    woodcam said the file held none. None if the file is not such an STL."""
    import trimesh

    size = path.stat().st_size
    held, rest = divmod(size - _STL_HEADER_BYTES, _STL_TRIANGLE.itemsize)
    if size < _STL_HEADER_BYTES + _STL_TRIANGLE.itemsize or rest:
        return None
    with open(path, "rb") as fh:
        head = fh.read(_STL_HEADER_BYTES)
    stated = int.from_bytes(head[80:84], "little")
    if stated == held:
        return None
    corners = np.fromfile(path, dtype=_STL_TRIANGLE, count=held, offset=_STL_HEADER_BYTES)["corners"]
    import warnings

    from ..errors import WoodcamWarning

    warnings.warn(WoodcamWarning(
        f"{origin} is a binary STL whose header says {stated} triangles but whose size holds {held}; "
        f"woodcam read the {held} (check the part, or export it again)"), stacklevel=4)
    mesh = trimesh.Trimesh(vertices=corners.reshape(-1, 3).astype(np.float64),
                           faces=np.arange(3 * held).reshape(-1, 3), process=False)
    return trimesh.Scene(mesh)


def _undo_woodcam_export_frame(scene, path: Path) -> None:
    """A GLB/OBJ written by woodcam is metres and Y up on disk (glTF/OBJ conventions); put it
    back in the block frame (mm, Z up) so re-baking an exported part lands where it was cut.
    Another program's glTF is metres and Y up too when its size says so
    (:func:`woodcam.frames.foreign_gltf_in_block_frame`)."""
    from woodcam.frames import GLTF_ROOT_NODE, foreign_gltf_in_block_frame, obj_header_transform

    if GLTF_ROOT_NODE in scene.graph.nodes:
        scene.graph.update(frame_to=GLTF_ROOT_NODE, matrix=np.eye(4))
    elif path.suffix.lower() in (".glb", ".gltf"):
        foreign_gltf_in_block_frame(scene, path, stacklevel=4)
    elif path.suffix.lower() == ".obj":
        recorded = obj_header_transform(path)
        if recorded is not None:
            scene.apply_transform(np.linalg.inv(recorded))


# --------------------------------------------------------------------------------- meshes


def _manifold_from_scene(scene, origin: str):
    """Union of every triangle mesh of a trimesh Scene, transforms applied."""
    import trimesh

    meshes = [g for g in scene.dump() if isinstance(g, trimesh.Trimesh) and len(g.faces)]
    if not meshes:
        raise WoodcamError(
            f"{origin} contains no triangles: it is empty or not a valid mesh (geometry found: "
            f"{[type(g).__name__ for g in scene.geometry.values()]}); it must hold a closed "
            f"triangle mesh of the part: re-export it as a binary STL, OBJ or GLB"
        )
    return _union([_manifold_from_trimesh(m, origin) for m in meshes], origin)


def drop_degenerate_faces(welded, origin: str, *, stacklevel: int = 3) -> np.ndarray:
    """Drop from ``welded`` (a trimesh whose vertices are welded by position), in place, the
    triangles that enclose nothing: those with a repeated corner and the copies of a triangle
    written more than once (warned of, naming ``origin``). Returns the mask of the triangles
    kept, ``(f,) bool`` over the triangles given (their order is kept), so that a textured copy
    of the same triangles can drop the same ones.

    Welding collapses the fans at B-rep poles (a sphere's degenerate edges) and an exporter's
    zero-length slivers into triangles with a repeated vertex, whose edges are then used three
    or four times; a triangle written twice (some exporters do) leaves its edges used four
    times. Either was refused as open or non-manifold edges, with no word of the cause. The
    one cleaning of a welded mesh: ``woodcam bake`` (:func:`load_part`) and ``woodcam woodify``
    read a mesh file through it."""
    f = np.asarray(welded.faces)
    kept = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])
    if not kept.all():
        welded.update_faces(kept)
        welded.remove_unreferenced_vertices()
    unique = welded.unique_faces()
    if not unique.all():
        import warnings

        from ..errors import WoodcamWarning

        warnings.warn(WoodcamWarning(
            f"{origin} has {int(np.count_nonzero(~unique))} duplicate triangles (the same three "
            "corners twice); woodcam dropped the copies (the solid is unchanged)"),
            stacklevel=stacklevel)
        welded.update_faces(unique)
        welded.remove_unreferenced_vertices()
        kept[np.flatnonzero(kept)[~unique]] = False
    return kept


def _manifold_from_trimesh(mesh, origin: str):
    """Weld, repair if needed (fill holes, fix normals) and convert a trimesh to a manifold."""
    import trimesh

    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    faces = np.asarray(mesh.faces, dtype=np.int64)
    if len(faces) == 0:
        raise WoodcamError(f"{origin} has no triangles; the part must be a closed solid")
    if not np.all(np.isfinite(vertices)):
        raise WoodcamError(
            f"{origin} has non-finite (NaN/inf) vertex coordinates; fix the mesh export"
        )
    # Fresh mesh without visuals: processing welds vertices by position only (UV/normal seams
    # in OBJ/GLB would otherwise split the surface) and drops degenerate faces.
    welded = trimesh.Trimesh(vertices=vertices, faces=faces, process=True)
    drop_degenerate_faces(welded, origin, stacklevel=4)
    if not welded.is_watertight:
        # Closed by flat fans, one per hole, and said so: trimesh's fill_holes turned a box
        # missing one side into an 833 mm^3 solid instead of 1000 without a word (issue 15).
        welded = _close_holes(welded, origin)
    if not welded.is_winding_consistent:
        trimesh.repair.fix_winding(welded)
    if not welded.is_watertight:
        counts = np.bincount(welded.edges_unique_inverse, minlength=len(welded.edges_unique))
        shared = int(np.count_nonzero(counts > 2))
        if shared:  # two bodies touching along an edge were told to 'export a solid, not surfaces'
            raise WoodcamError(
                f"{origin} is not a 2-manifold mesh: {shared} edge{'s' if shared > 1 else ''} "
                f"{'are' if shared > 1 else 'is'} shared by more than two triangles (bodies touching along "
                f"an edge, or a surface inside the solid), {int(np.count_nonzero(counts == 1))} open; "
                f"make the bodies overlap or move them apart in your CAD program, or repair the mesh (e.g. "
                f"MeshLab's 'Repair non Manifold Edges')")
        raise WoodcamError(
            f"{origin} is not a closed (watertight) mesh, even after filling holes: it has "
            f"{int(np.count_nonzero(counts == 1))} open edges; close the mesh in your CAD "
            f"program (export a solid, not surfaces) or repair it (e.g. Meshmixer, MeshLab)"
        )
    return _manifold_from_shells(welded, origin)


def _manifold_from_shells(mesh, origin: str):
    """The solid a closed, consistently wound ``mesh`` (block frame, mm) encloses, one shell
    per face-connected component; a mesh whose shells sum to a negative volume is inside out
    and turned.

    Shells are applied largest (by absolute volume) first: an outward one adds, an inward one
    (a cavity) subtracts, so bodies that overlap (an assembly exported as one STL) are unioned
    instead of counted twice and carved as stacked surfaces, and a hollow part keeps its void.
    An inward shell that is not inside what is solid so far is a body with flipped normals: it
    is added."""
    import manifold3d
    import trimesh

    faces = np.asarray(mesh.faces)
    labels = trimesh.graph.connected_component_labels(mesh.face_adjacency, node_count=len(faces))
    tri = np.asarray(mesh.vertices)[faces]
    signed = np.bincount(labels, np.einsum("ij,ij->i", tri[:, 0],
                                           np.cross(tri[:, 1], tri[:, 2])) / 6)
    if signed.sum() < 0:  # the whole mesh inside out (trimesh's volume divides by it: no 0)
        faces, signed = faces[:, ::-1], -signed
    if len(signed) == 1:
        return _manifold_from_arrays(mesh.vertices, faces, origin)
    shells = []
    for k in np.argsort(-np.abs(signed), kind="stable"):
        own = faces[labels == k]
        used, local = np.unique(own if signed[k] > 0 else own[:, ::-1], return_inverse=True)
        shells.append((signed[k] > 0, _manifold_from_arrays(
            np.asarray(mesh.vertices)[used], local.reshape(-1, 3), origin)))
    if all(outward for outward, _ in shells):  # no cavity: one batch union
        return _union([shell for _, shell in shells], origin)
    solid = manifold3d.Manifold()
    for outward, shell in shells:
        inside = not outward and (shell - solid).volume() <= 1e-6 * shell.volume()
        solid = solid - shell if inside else solid + shell
    return _check_manifold(solid, origin)


def _close_holes(mesh, origin: str):
    """Close every hole of an open mesh with a fan from the centroid of its boundary loop and
    warn with what was added; returns a new mesh (the input if it has no boundary loop).

    A fan is exact for a flat hole (a missing box side comes back as the flat side), and the
    user is told, since no repair can know the part; a hole that is not flat has no obvious cap
    and is refused.
    Boundary loops are the connected components of the edges used by one face only; each
    boundary edge ``a -> b`` (as its face runs it) is capped by the triangle ``(b, a, centroid)``
    so the caps are wound like their neighbours."""
    import trimesh
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    counts = np.bincount(mesh.edges_unique_inverse, minlength=len(mesh.edges_unique))
    edges = np.asarray(mesh.edges)  # directed, as each face runs them
    boundary = edges[counts[mesh.edges_unique_inverse] == 1]
    if len(boundary) == 0 or np.any(counts > 2):
        return mesh  # non-manifold edges: not a hole problem; the caller refuses it
    n = len(mesh.vertices)
    graph = coo_matrix((np.ones(len(boundary)), (boundary[:, 0], boundary[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    loops, loop_of_edge = np.unique(label[boundary[:, 0]], return_inverse=True)
    used = np.unique(boundary)
    sums = np.zeros((len(loops), 3))
    np.add.at(sums, np.searchsorted(loops, label[used]), mesh.vertices[used])
    loop_index = np.searchsorted(loops, label[used])
    centroids = sums / np.bincount(loop_index)[:, None]
    for k in range(len(loops)):  # a few holes at most: a loop over holes, not points
        pts = mesh.vertices[used[loop_index == k]] - centroids[k]
        extent = float(np.abs(pts).max())
        if len(pts) > 3 and np.linalg.svd(pts, compute_uv=False)[-1] > 1e-6 * extent * np.sqrt(len(pts)):
            raise WoodcamError(
                f"{origin} is not a closed (watertight) mesh: it has {len(boundary)} open edges "
                f"in {len(loops)} hole(s), and hole {k + 1} ({len(pts)} corners) is not flat, so "
                "no cap is the obvious one (different caps give different solids); close the "
                "mesh in your CAD program (export a solid, not surfaces) or repair it (e.g. "
                "Meshmixer, MeshLab)")
    caps = np.column_stack([boundary[:, 1], boundary[:, 0], n + loop_of_edge])
    closed = trimesh.Trimesh(np.vstack([mesh.vertices, centroids]),
                             np.vstack([mesh.faces, caps]), process=False)
    tri = closed.vertices[closed.faces]
    vol = abs(float(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum()) / 6)
    size = float(np.ptp(mesh.vertices, axis=0).max())
    if vol <= 1e-9 * size**3:  # an open surface capped by itself encloses nothing
        return mesh
    if closed.is_watertight:
        import warnings

        from ..errors import WoodcamWarning

        warnings.warn(WoodcamWarning(
            f"{origin} was not closed: {len(boundary)} open edges in {len(loops)} hole(s); "
            f"woodcam capped each hole flat ({len(caps)} triangles added), giving a solid of "
            f"{say_volume(vol, '.6g')}. Check that this is the part you meant, or export a closed solid"),
            stacklevel=4)
    return closed


def _manifold_from_arrays(vertices, faces, origin: str):
    """Build a manifold from ``vertices (n, 3) float mm`` and ``faces (m, 3) int``."""
    import manifold3d

    mesh = manifold3d.Mesh64(
        vert_properties=np.ascontiguousarray(vertices, dtype=np.float64),
        tri_verts=np.ascontiguousarray(faces, dtype=np.uint64),
    )
    solid = manifold3d.Manifold(mesh)
    if solid.status() != manifold3d.Error.NoError:
        mesh.merge()  # best effort: weld open edges within manifold's own tolerance
        solid = manifold3d.Manifold(mesh)
    return _check_manifold(solid, origin)


def _check_manifold(solid, origin: str):
    """Reject errored, empty or inside-out manifolds."""
    import manifold3d

    status = solid.status()
    if status != manifold3d.Error.NoError:
        raise WoodcamError(
            f"{origin} is not a valid closed solid (manifold3d reports {status.name}); the mesh "
            f"must be a watertight, consistently oriented 2-manifold: re-export it as a solid"
        )
    if solid.is_empty():
        raise WoodcamError(
            f"{origin} is empty (no triangles or zero volume); the part must be a solid with "
            f"volume"
        )
    if solid.volume() <= 0:
        raise WoodcamError(
            f"{origin} has non-positive volume {say_volume(solid.volume(), '.6g')} (inside-out normals?); "
            f"flip its faces so normals point outward"
        )
    return solid


def _union(solids: list, origin: str):
    """Boolean union of a non-empty list of manifolds."""
    import manifold3d

    solid = solids[0] if len(solids) == 1 else manifold3d.Manifold.batch_boolean(
        solids, manifold3d.OpType.Add)
    return _check_manifold(solid, origin)


# --------------------------------------------------------------------------------- B-reps


def _manifold_from_topods(shape, tess: "_Tessellation", origin: str):
    """Tessellate an OpenCascade ``TopoDS_Shape`` solid by solid and union the pieces."""
    require("OCP", "cad", "tessellating B-rep parts")
    from OCP.TopAbs import TopAbs_SHELL, TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer

    if shape is None or shape.IsNull():
        raise WoodcamError(f"{origin} is an empty (null) shape; build a solid first")
    def explore(kind, avoid=None):
        explorer = TopExp_Explorer(shape, kind) if avoid is None else TopExp_Explorer(shape, kind, avoid)
        found = []
        while explorer.More():
            found.append(explorer.Current())
            explorer.Next()
        return found

    solids = explore(TopAbs_SOLID)
    # shells outside every solid: with no solid, a surface model (STEP from SketchUp, Blender or
    # a mesh tool) bounds the part with them, meshed like a mesh file (closed, or holes capped
    # with a warning); beside solids they may be construction surfaces: left out, and said
    shells = explore(TopAbs_SHELL, TopAbs_SOLID)
    if solids and shells:
        import warnings

        from ..errors import WoodcamWarning

        many = len(shells) > 1
        warnings.warn(WoodcamWarning(
            f"{origin} holds {len(solids)} solid{'s' if len(solids) > 1 else ''} and {len(shells)} "
            f"shell{'s' if many else ''} (surface bod{'ies' if many else 'y'}) outside any solid: carved "
            f"the solids only, {'those' if many else 'the'} {len(shells)} shell{'s' if many else ''} left "
            f"out; if {'they belong' if many else 'it belongs'} to the part, sew "
            f"{'them' if many else 'it'} into a solid in your CAD program"),
            stacklevel=5)
    solids = solids or shells
    if not solids:
        raise WoodcamError(
            f"{origin} contains no solid nor shell (only faces, wires or an empty compound); "
            f"extrude, revolve or thicken it into a solid"
        )
    meshes = tess.mesh_solids(solids, origin)
    pieces = [_manifold_from_trimesh(_trimesh(v, f), origin) for v, f in meshes]
    return _union(pieces, origin)


def _trimesh(vertices, faces):
    import trimesh

    return trimesh.Trimesh(vertices=vertices, faces=faces, process=False)


@dataclass
class _Tessellation:
    """Tessellation settings of one :func:`load_part` call and what they produced.

    ``mesh_solids`` meshes B-rep solids at ``tol_mm`` / ``ang_rad``; when the triangles exceed
    ``max_triangles`` it re-meshes with both tolerances loosened by the overshoot (chord error
    falls with the square of the triangle count along a curve, so loosening by the ratio lands
    near the budget) and says so in :meth:`report`."""

    tol_mm: float | None  # None: auto_tolerance_mm of each B-rep
    ang_rad: float
    max_triangles: int | None
    texels_per_mm: float = _DEFAULT_TEXELS_PER_MM
    triangles: int = 0
    notes: list = field(default_factory=list)
    used_tol_mm: float = 0.0
    used_ang_rad: float = 0.0
    rule: str = ""
    mesh_input: bool = False  # a mesh (file, trimesh, manifold) was among the sources
    simplified: dict | None = None  # fit_mesh's {"from", "to", "tolerance_mm"}

    def mesh_solids(self, solids, origin: str):
        if self.tol_mm is None:
            diagonal = _diagonal_mm(solids)
            tol_mm = _auto_tolerance(diagonal, self.texels_per_mm)
            self.rule = (f"auto: min({TESSELLATION_TEXEL_FRACTION:g} texel = "
                         f"{say_length(TESSELLATION_TEXEL_FRACTION / self.texels_per_mm, '.3g')}, "
                         f"{TESSELLATION_REL_TOL:g} x the {say_length(diagonal, '.4g')} diagonal = "
                         f"{say_length(TESSELLATION_REL_TOL * diagonal, '.3g')})")
        else:
            tol_mm = self.tol_mm
            self.rule = "given"
        ang_rad = self.ang_rad
        first = None
        tries = 0
        for _ in range(_BUDGET_TRIES + 1):
            tries += 1
            meshes = [_tessellate_solid(solid, tol_mm, ang_rad) for solid in solids]
            for _vertices, faces in meshes:
                if len(faces) == 0:
                    raise WoodcamError(f"{origin} has a solid that tessellates to no triangles")
            count = sum(len(f) for _v, f in meshes)
            first = first or (count, tol_mm, math.degrees(ang_rad))
            if self.max_triangles is None or count <= self.max_triangles or tries > _BUDGET_TRIES:
                break
            ratio = count / self.max_triangles
            tol_mm *= ratio
            ang_rad = min(math.radians(_MAX_BUDGET_ANGLE_DEG), ang_rad * math.sqrt(ratio))
        self.used_tol_mm, self.used_ang_rad = tol_mm, ang_rad
        if tries > 1:
            self.notes.append(said(lambda: (  # the part report (a file) keeps it in mm
                f"{origin}: {first[0]} triangles at {say_length(first[1], '.3g')} / {first[2]:.3g} deg "
                f"exceeded max_triangles={self.max_triangles}; re-meshed to {count} triangles at "
                f"{say_length(tol_mm, '.3g')} / {math.degrees(ang_rad):.3g} deg"
                + ("" if count <= self.max_triangles else
                   " (still over: the angular tolerance stops at "
                   f"{_MAX_BUDGET_ANGLE_DEG:g} deg; raise --max-triangles or simplify the part)"))))
        self.triangles += count
        return meshes

    def fit_mesh(self, solid, origin: str):
        """``solid`` (a manifold) within ``max_triangles`` where a mesh source gave triangles:
        a 1.3 M-triangle STL baked in ~100 s and 3.5 GB, the budget bounding B-reps only.
        manifold3d's ``simplify(tol)`` (the maintained simplifier at hand, fast_simplification,
        open3d and pymeshlab not being dependencies; it keeps the solid a valid manifold, which
        quadric decimation does not promise) from a quarter texel (:func:`_auto_tolerance`),
        the tolerance loosened by the overshoot (triangles fall about as 1 / tolerance on a
        curved surface), at least by :data:`_MESH_BUDGET_MIN_STEP`, until the count fits; said
        in :meth:`report`'s notes with both counts. A part that does not fit by
        :data:`~woodcam.tolerances.MESH_SIMPLIFY_MAX_REL_TOL` of its diagonal, or that would lose
        a body, is a WoodcamError naming --max-triangles and the counts."""
        count = solid.num_tri()
        if not self.mesh_input or self.max_triangles is None or count <= self.max_triangles:
            return solid
        box = solid.bounding_box()
        diagonal = math.dist(box[:3], box[3:])
        cap = MESH_SIMPLIFY_MAX_REL_TOL * diagonal
        tol = min(cap, _auto_tolerance(diagonal, self.texels_per_mm))
        simple, bodies = solid, None
        for _ in range(_MESH_BUDGET_TRIES):
            simple = solid.simplify(tol)
            left = simple.num_tri()
            if left <= self.max_triangles:
                bodies = (len(solid.decompose()), len(simple.decompose()))
                if bodies[1] == bodies[0]:
                    break
            if tol >= cap or (bodies and bodies[1] != bodies[0]):
                break
            tol = min(cap, tol * max(_MESH_BUDGET_MIN_STEP, left / self.max_triangles))
        if left > self.max_triangles or (bodies and bodies[1] != bodies[0]):
            lost = f" and lost {bodies[0] - bodies[1]} of its {bodies[0]} bodies" if bodies else ""
            raise WoodcamError(
                f"{origin} has {count} triangles, over max_triangles (--max-triangles) = {self.max_triangles}, "
                f"and simplifying it by up to {say_length(tol, '.3g')} ({100 * MESH_SIMPLIFY_MAX_REL_TOL:g} % of its "
                f"diagonal at most) left {left}{lost}; raise --max-triangles to {count} to bake it whole, or "
                "simplify it in your CAD program")
        made = simple.num_tri()
        self.simplified = {"from": count, "to": made, "tolerance_mm": tol}
        self.notes.append(said(lambda: (
            f"{origin}: {count} triangles exceeded max_triangles={self.max_triangles} (--max-triangles); "
            f"simplified to {made} triangles, surfaces moved by less than {say_length(tol, '.3g')} "
            f"(raise --max-triangles to keep more)")))
        return _check_manifold(simple, origin)

    def report(self) -> dict:
        meshed = self.triangles > 0
        return {"tolerance_mm": self.used_tol_mm if meshed else self.tol_mm,
                "angular_tolerance_deg": math.degrees(self.used_ang_rad if meshed
                                                      else self.ang_rad),
                "tolerance_rule": self.rule, "texels_per_mm": self.texels_per_mm,
                "triangles": self.triangles, "max_triangles": self.max_triangles,
                "simplified": self.simplified, "notes": list(self.notes)}


def _diagonal_mm(solids) -> float:
    """Bounding-box diagonal (mm) of OpenCascade solids (exact box, not the control points)."""
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib

    box = Bnd_Box()
    for solid in solids:
        BRepBndLib.AddOptimal_s(solid, box, False, False)
    if box.IsVoid():
        return 0.0
    x0, y0, z0, x1, y1, z1 = box.Get()
    return math.sqrt((x1 - x0) ** 2 + (y1 - y0) ** 2 + (z1 - z0) ** 2)


def _check_budget(max_triangles):
    if max_triangles is None:
        return None
    if not (isinstance(max_triangles, Integral) and max_triangles >= 100):
        raise WoodcamError(
            f"max_triangles must be an integer >= 100 or None; got {max_triangles!r}; use e.g. "
            f"{MAX_PART_TRIANGLES}"
        )
    return int(max_triangles)


def _tessellate_solid(solid, tol_mm: float, ang_rad: float):
    """Mesh one solid with ``BRepMesh_IncrementalMesh``; returns ``(n, 3)`` mm and ``(m, 3)``.

    The solid is copied first (``BRepBuilderAPI_Copy`` without its mesh) so the tolerances
    given here always apply: OpenCascade otherwise keeps an existing triangulation that is
    finer than asked. Faces are meshed with shared edge discretisations, so vertices on an edge
    coincide exactly and welding by position closes the mesh. Per-node reads are a Python loop
    because OCP exposes no array view of ``Poly_Triangulation`` (same approach as build123d's
    ``Shape.tessellate``); it costs ~1 s per 100k triangles.
    """
    from OCP.BRep import BRep_Tool
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Copy
    from OCP.BRepMesh import BRepMesh_IncrementalMesh
    from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopLoc import TopLoc_Location
    from OCP.TopoDS import TopoDS

    copy = BRepBuilderAPI_Copy(solid, True, False).Shape()
    BRepMesh_IncrementalMesh(copy, tol_mm, False, ang_rad, True)

    all_vertices, all_faces, offset = [], [], 0
    explorer = TopExp_Explorer(copy, TopAbs_FACE)
    while explorer.More():
        face = TopoDS.Face_s(explorer.Current())
        explorer.Next()
        location = TopLoc_Location()
        poly = BRep_Tool.Triangulation_s(face, location)
        if poly is None:
            continue
        trsf = location.Transformation()
        nodes = np.array(
            [poly.Node(i).Transformed(trsf).Coord() for i in range(1, poly.NbNodes() + 1)],
            dtype=np.float64,
        ).reshape(-1, 3)
        tris = np.array(
            [poly.Triangle(i).Get() for i in range(1, poly.NbTriangles() + 1)], dtype=np.int64
        ).reshape(-1, 3) - 1
        if face.Orientation() == TopAbs_REVERSED:
            tris = tris[:, ::-1]
        all_vertices.append(nodes)
        all_faces.append(tris + offset)
        offset += len(nodes)
    if not all_faces:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    return np.concatenate(all_vertices), np.concatenate(all_faces)
