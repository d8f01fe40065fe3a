"""The cut-preview pipeline: part -> carved in the stock -> baked wood texture -> files.

Every front end (``woodcam bake``, ``woodcam demo``, ``woodcam gcode``) runs the same stages;
:class:`PartPreview` keeps what each produced and how long it took.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from ._repr import summary_repr
from ._types import Mesh, PathLike
from .errors import WoodcamError
from .stock import Stock
from .tolerances import DEFAULT_MAX_ATLAS_PX

if TYPE_CHECKING:
    import numpy as np

    from ._progress import StageBar


@dataclass
class PartPreview:
    """Result of :func:`preview_mesh` / :func:`preview_part`.

    Attributes
    ----------
    name : str
    volume_mm3 : float
        Volume of the carved part.
    triangles : int
    atlas_px : (h, w)
    files : dict kind -> Path, every file written ("glb", "obj", "mtl", "texture", "report",
        "report_json", "png"; the CLI adds "deviation", gcode's map, and "list",
        the list of them, ``woodcam.cli.options.remove_stale_outputs``)
    timings_s : dict stage -> seconds
    warnings : list of str
    meta_block : str
        The block spec the part was previewed in, set by a caller that knows it (the demo's
        table); ``""`` otherwise.
    tessellation : dict
        :func:`preview_part`: what :func:`woodcam.cad.load_part` put in its ``report``
        (tolerances used, triangle count and budget, ``simplified``, ``notes``); empty for
        :func:`preview_mesh`.
    atlas : str
        One line on the baked texture atlas (:meth:`woodcam.bake.BakeResult.summary`: size, UV
        fill, texels/mm, GPU memory).
    report : dict
        With ``part_report``: :func:`woodcam.advise.part_report` of the part in its block
        (volume, yield, knots, pith, end grain, warnings); empty otherwise.
    texture, charts : see the comment on them below (height-field previews only).
    stages : the progress bar each :meth:`stage` advances, or None (no bar).
    """

    __repr__ = summary_repr  # arrays as shapes: a notebook shows one line

    name: str
    volume_mm3: float = 0.0
    triangles: int = 0
    atlas_px: tuple[int, int] = (0, 0)
    files: dict = field(default_factory=dict)
    timings_s: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    meta_block: str = ""
    tessellation: dict = field(default_factory=dict)
    atlas: str = ""
    report: dict = field(default_factory=dict)
    #: a height-field preview's baked atlas ((h, w, 3) uint8) and its charts (name -> (x0, y0,
    #: width, height, span u mm, span v mm) px, :class:`woodcam.toolpath.mesh.HeightfieldCharts`):
    #: what :func:`woodcam.view.stockview.stock_view` and the top view draw; None otherwise
    texture: object = None
    charts: object = None
    #: the :class:`woodcam._progress.StageBar` each :meth:`stage` advances (None: no bar)
    stages: StageBar | None = field(default=None, repr=False, compare=False)

    def chart_texels(self, name: str) -> np.ndarray:
        """The ``(h, w, 3) uint8`` texels of chart ``name`` ("top": the stock seen from +Z, row
        0 at Y = D) of a height-field preview's atlas."""
        x0, y0, w, h = (int(v) for v in self.charts[name][:4])
        return self.texture[y0:y0 + h, x0:x0 + w]

    @contextmanager
    def stage(self, name: str) -> Iterator[None]:
        """Time stage ``name`` into :attr:`timings_s` (and run it as a step of :attr:`stages`).
        A Ctrl-C checkpoint as it starts (:func:`woodcam._interrupt.check`)."""
        from ._interrupt import check

        check()
        t0 = time.perf_counter()
        if self.stages is None:
            yield
        else:
            with self.stages.stage(name):
                yield
        self.timings_s[name] = self.timings_s.get(name, 0.0) + time.perf_counter() - t0


def part_stages(screenshot: bool) -> list[str]:
    """The stages :func:`preview_part` runs, in order (:attr:`PartPreview.stages`' plan)."""
    return ["load", "carve", "bake", "report", "export"] + (["render"] if screenshot else [])


def screenshot_path(screenshot: bool | str | Path | None, beside: Path) -> Path | None:
    """Where ``--screenshot`` writes: ``None`` when not asked, NAME_view.png beside ``beside``
    (the GLB or mesh) when given without a name, else the name given."""
    if not screenshot:
        return None
    if screenshot is True:
        return beside.with_name(beside.stem + "_view.png")
    return Path(screenshot)


def check_outputs(out_glb, *, obj: bool = True, screenshot: bool | str | Path = False,
                  what: str = "--out") -> Path:
    """Check every file a preview will write *before* any work: ``out_glb`` ends in ``.glb``,
    is not a folder, its folder exists (created if missing) and is writable; likewise the
    ``.obj``/``.mtl``/``.png`` beside it when ``obj``, and the rendered ``*_view.png`` (or the
    given screenshot path). Returns ``out_glb`` as a Path; raises WoodcamError naming the path."""
    from ._atomic import check_output_path
    from ._checks import check_path
    from .export import obj_siblings

    out_glb = check_output_path(check_path(out_glb, what, fix="e.g. 'out/part.glb'"), suffixes=(".glb",),
                                what=what, mkdir=True)
    if obj:
        for sibling in (out_glb.with_suffix(".obj"), *obj_siblings(out_glb.with_suffix(".obj"))):
            suffix = sibling.suffix
            check_output_path(sibling, what=f"{what} (the {suffix[1:].upper()} "
                              "beside the GLB; --no-obj skips it)")
    if screenshot is True:
        check_output_path(screenshot_path(True, out_glb), what=f"{what} (its view PNG)")
    elif screenshot:
        check_output_path(screenshot, suffixes=(".png",), what="--screenshot", mkdir=True)
    return out_glb


def _check_flags(obj, screenshot, progress) -> tuple[bool, bool | Path, bool]:
    """A preview's switches: ``obj`` and ``progress`` True or False (``"false"`` was truthy),
    ``screenshot`` True, False or a ``.png`` path (a number was Path's bare TypeError)."""
    from ._checks import check_bool, check_path

    if isinstance(screenshot, bool) or type(screenshot).__name__ == "bool_":
        screenshot = bool(screenshot)
    else:
        screenshot = check_path(screenshot, "screenshot",
                                fix="True (a *_view.png beside the GLB), False, or a .png path")
    return check_bool(obj, "obj"), screenshot, check_bool(progress, "progress")


def _check_stock(stock) -> None:
    """``stock`` must be a :class:`Stock` (None was an AttributeError, 'size_mm' or 'wood')."""
    if not isinstance(stock, Stock):
        raise WoodcamError(f"stock must be a woodcam Stock; got {type(stock).__name__}; pass "
                           "woodcam.open_stock('builtin:flat-sawn')")


def _check_metadata(metadata) -> None:
    """``metadata`` (extra GLB metadata) a dict or None: a list was a TypeError of ``**``
    after the whole bake."""
    if metadata is not None and not isinstance(metadata, dict):
        raise WoodcamError(f"metadata must be a dict of extra GLB metadata or None; got {type(metadata).__name__}; "
                           "e.g. metadata={'part': 'bowl'}")


def preview_part(source: object, stock: Stock | Callable[[], Stock], out_glb: PathLike, *, texels_per_mm: float = 10.0,
                 tolerance_mm: float | None = None, obj: bool = True,
                 screenshot: bool = True, progress: bool = False, obj_units: str = "m",
                 obj_up: str = "y", max_triangles: int | None = None,
                 max_atlas_px: int = DEFAULT_MAX_ATLAS_PX, place: list[str] | tuple = (),
                 place_as_typed: list[str] | None = None,
                 timeout_s: float | None = None, stages: StageBar | None = None,
                 units_fix: str = "add 'scale:25.4' and 'center' to place (in metres: 'scale:1000')"
                 ) -> PartPreview:
    """Carve ``source`` (anything :func:`woodcam.cad.load_part` takes) out of ``stock``, bake it
    and write ``out_glb`` (+ ``.obj``/``.mtl``/``.png`` and a rendered ``*_view.png``).

    Parameters
    ----------
    source : part
        A ``.py``/``.step``/``.stl``/... path or a CAD object, in mm in the block frame.
    stock : Stock or callable
        The block (:func:`woodcam.open_stock`), or a function returning it (below).
    out_glb, texels_per_mm, obj, screenshot, progress, obj_units, obj_up, max_atlas_px
        As :func:`preview_mesh` takes them: the ``.glb`` to write (the other files take its
        stem), the texture density (texels per mm), the OBJ and the rendered view beside it, a
        progress bar (off by default), the OBJ's unit and up axis, the largest texture side.
    tolerance_mm : float, optional
        Chord tolerance of the CAD tessellation, mm; default scaled to the part and the texel.
    max_triangles : int, optional
        The tessellation's triangle budget (default :data:`woodcam.tolerances.MAX_PART_TRIANGLES`).

    ``place`` lists placement operations applied to the loaded part before carving
    (:mod:`woodcam.cad.place`, e.g. ``["rotate:x:90", "center", "drop"]``); the resulting
    4 x 4 matrix is recorded in the GLB metadata as ``placement``; ``place_as_typed``: the same
    operations as the user typed them, for its errors (the CLI's, in ``--units``). A ``.py`` source is trusted
    code run with your rights; ``timeout_s`` bounds its loading. ``units_fix``: how to scale a part
    in inches, in its warning (:func:`woodcam.cad.carve.units_hint`; the CLI names ``--place``).

    ``progress`` draws a bar of its stages (:func:`part_stages`) on a terminal, or advances
    ``stages`` (a :class:`woodcam._progress.StageBar` whose plan holds them) when given.

    ``stock`` may be a function of no argument returning the :class:`Stock`, called once the
    part is loaded: a script's typo or a damaged part file is then said before the block is
    opened (a ring fit: minutes), as ``woodcam bake`` does."""
    from .cad import carve, load_part
    from .tolerances import MAX_PART_TRIANGLES

    if not callable(stock):
        _check_stock(stock)
    obj, screenshot, progress = _check_flags(obj, screenshot, progress)
    if isinstance(place, str):  # 'center' was read letter by letter: "--place 'c' is not a placement"
        raise WoodcamError(f"place must be a list of placement operations; got the string {place!r}; pass [{place!r}]")
    out_glb = check_outputs(out_glb, obj=obj, screenshot=screenshot)  # before minutes of work
    result = PartPreview(out_glb.stem, stages=stages)
    if progress and stages is None:  # a bar of its own
        from ._progress import StageBar

        result.stages = StageBar(part_stages(screenshot), desc=out_glb.stem, leave=False)
    try:
        with result.stage("load"):
            part = load_part(source, tolerance_mm=tolerance_mm, texels_per_mm=texels_per_mm,
                             timeout_s=timeout_s,
                             # 0 fell back to the default budget without a word (load_part refuses it)
                             max_triangles=MAX_PART_TRIANGLES if max_triangles is None else max_triangles,
                             report=result.tessellation)
        result.warnings += list(result.tessellation.get("notes", []))
        if callable(stock):  # opened after the part loaded (bake: a typo was said after the fit)
            stock = stock()
            _check_stock(stock)
        metadata = None
        if place:
            from .cad.place import place_part

            part, matrix = place_part(part, list(place), stock.size_mm, as_typed=place_as_typed)
            metadata = {"placement": {"ops": list(place), "matrix": matrix.tolist()}}
        with result.stage("carve"):
            carved = carve(part, stock.size_mm, units_fix=units_fix, source=source)
        result.warnings += list(carved.warnings)
        return preview_mesh(carved.mesh, stock, out_glb, texels_per_mm=texels_per_mm, obj=obj,
                            part_report=True,
                            screenshot=screenshot, progress=progress, result=result,
                            obj_units=obj_units, obj_up=obj_up, max_atlas_px=max_atlas_px,
                            metadata=metadata)
    finally:
        if stages is None and result.stages is not None:
            result.stages.close()
            result.stages = None


def preview_mesh(mesh: Mesh, stock: Stock, out_glb: PathLike, *, texels_per_mm: float = 10.0, obj: bool = True,
                 screenshot: bool = True, progress: bool = False,
                 result: PartPreview | None = None, metadata: dict | None = None,
                 obj_units: str = "m", obj_up: str = "y",
                 max_atlas_px: int = DEFAULT_MAX_ATLAS_PX, part_report: bool = False) -> PartPreview:
    """Bake an already carved watertight ``mesh`` (block frame, mm) and write the files: the GLB
    in metres, Y up (glTF's convention); the OBJ in ``obj_units`` with ``obj_up`` up.

    Parameters
    ----------
    mesh : trimesh.Trimesh
        The carved part's surface (``carve(part, stock.size_mm).mesh``), block frame, mm.
    stock : Stock
        The block it is carved from (:func:`woodcam.open_stock`): its wood colours the texture.
    out_glb : path
        The ``.glb`` to write (its folder is made); the other files take its stem.
    texels_per_mm : float
        Texture density of the bake (texels per mm of surface; 10 = 0.1 mm texels).
    obj : bool
        Also write ``NAME.obj`` with its ``.mtl`` and texture PNG beside ``out_glb``.
    screenshot : bool
        Also render the view off screen to ``NAME_view.png`` beside ``out_glb``.
    progress : bool
        A progress bar on stderr, on a terminal only; off by default.
    obj_units, obj_up : str
        The OBJ's length unit (``"m"``, ``"mm"``, ...) and up axis (``"y"`` or ``"z"``); the GLB is
        always metres, Y up, as glTF specifies.
    max_atlas_px : int
        The largest texture side in pixels; a larger bake lowers ``texels_per_mm`` and says so.
    result : PartPreview, optional
        A result to fill in (its timings and warnings so far) instead of a new one.
    metadata : dict, optional
        JSON-serialisable extras stored in the GLB's ``woodcam`` metadata (:func:`read_glb_metadata`).
    part_report : bool
        Also write the part report (knots, pith, end grain, grain runout) beside ``out_glb``.
    """
    import trimesh

    from .bake import bake

    _check_stock(stock)
    if not isinstance(mesh, trimesh.Trimesh):  # None was an AttributeError ('volume')
        raise WoodcamError(f"mesh must be a trimesh.Trimesh (a carved part's surface); got {type(mesh).__name__}; "
                           "pass carve(part, stock.size_mm).mesh")
    obj, screenshot, progress = _check_flags(obj, screenshot, progress)
    from ._checks import check_bool

    part_report = check_bool(part_report, "part_report")
    _check_metadata(metadata)
    if result is not None and not isinstance(result, PartPreview):  # 5 was an AttributeError after the checks
        raise WoodcamError(f"result must be a PartPreview to fill (its timings, warnings) or None; got "
                           f"{type(result).__name__}")
    out_glb = check_outputs(out_glb, obj=obj, screenshot=screenshot)
    result = result or PartPreview(out_glb.stem)
    result.volume_mm3 = abs(float(mesh.volume))  # as the part report's (advise.part_report)
    result.triangles = int(len(mesh.faces))
    with result.stage("bake"):
        baked = bake(mesh, stock.wood, texels_per_mm=texels_per_mm, progress=progress,
                     max_atlas_px=max_atlas_px)
    return _write_preview(baked, stock, out_glb, result, obj=obj, screenshot=screenshot,
                          metadata=metadata, obj_units=obj_units, obj_up=obj_up,
                          normals="crease", report_mesh=mesh if part_report else None)


def preview_heightfield(heightmap, stock: Stock, out_glb, *, texels_per_mm: float = 10.0,
                        flat_tol_mm: float = 0.01, obj: bool = True, screenshot: bool = False,
                        metadata: dict | None = None, obj_units: str = "m",
                        obj_up: str = "y", max_atlas_px: int = DEFAULT_MAX_ATLAS_PX) -> PartPreview:
    """:func:`preview_mesh` for a simulated stock ``heightmap : (ny, nx)`` (block-frame Z, mm,
    over the stock's XY): meshed and baked by its own planar charts
    (:func:`woodcam.bake.bake_heightfield`), no generic unwrap. The result keeps the atlas and
    its charts (``texture``, ``charts``) for views drawn from them; ``screenshot`` draws the
    iso view with :func:`woodcam.view.stockview.write_stock_view` (no VTK)."""
    import numpy as np

    _check_metadata(metadata)
    out_glb = check_outputs(out_glb, obj=obj, screenshot=screenshot)
    result = PartPreview(out_glb.stem)
    with result.stage("bake"):
        baked = bake_heightfield(heightmap, stock.size_mm, stock.wood,
                                 texels_per_mm=texels_per_mm, flat_tol_mm=flat_tol_mm,
                                 max_atlas_px=max_atlas_px)
    W, D, H = stock.size_mm
    cell = W * D / np.asarray(heightmap).size
    result.volume_mm3 = float(np.asarray(heightmap, float).sum() * cell)
    result.triangles = int(len(baked.mesh.faces))
    # the height-field bake sets its shading normals from the grid: no crease computation
    result = _write_preview(baked, stock, out_glb, result, obj=obj, screenshot=False,
                            metadata=metadata, obj_units=obj_units, obj_up=obj_up,
                            normals="mesh", report_mesh=None)
    from .toolpath.mesh import HeightfieldCharts

    result.texture = baked.atlas
    result.charts = HeightfieldCharts(np.zeros((1, 1)), stock.size_mm,
                                      baked.texels_per_mm).charts
    if screenshot:
        from .view.stockview import write_stock_view

        png = screenshot_path(True, out_glb)
        with result.stage("render"):
            write_stock_view(png, heightmap, stock.size_mm, result.texture, result.charts,
                             wood=stock.wood)
        result.files["png"] = png
    return result


def bake_heightfield(heightmap, size_mm, wood, *, texels_per_mm: float = 10.0,
                     flat_tol_mm: float = 1e-9, max_atlas_px: int = DEFAULT_MAX_ATLAS_PX):
    """Mesh and bake a height-field stock (:mod:`woodcam.toolpath.simulate`) without a
    generic unwrap: a :class:`woodcam.bake.BakeResult`.

    The remaining stock's top is a height field over XY, so it is textured by its own planar
    parameterisation (:class:`woodcam.toolpath.mesh.HeightfieldCharts`: top, bottom and four
    walls as six rectangles), flat regions are merged by ``flat_tol_mm``
    (:func:`woodcam.toolpath.mesh.heightfield_mesh`), and each texel's point and normal come
    from the grid directly (:func:`woodcam.bake.bake_charts`): no xatlas unwrap and no
    triangle rasterisation (on the 20,000-move raster those were 75 % of the preview's time).
    ``heightmap : (ny, nx)`` block-frame Z (mm), ``size_mm = (W, D, H)``; ``wood`` as
    :func:`woodcam.bake.bake`. The density is lowered (with a warning) so the atlas stays
    within ``max_atlas_px`` on a side.
    """
    import math

    import numpy as np

    from .bake import bake_charts
    from .errors import WoodcamError
    from .toolpath.mesh import HeightfieldCharts, heightfield_mesh_charts

    if not (math.isfinite(texels_per_mm) and texels_per_mm > 0):
        raise WoodcamError(f"bake_heightfield: texels_per_mm must be a finite number > 0, got "
                           f"{texels_per_mm!r}; use e.g. 10")
    messages: list[str] = []
    tpm = float(texels_per_mm)
    side = max(HeightfieldCharts(np.zeros((1, 1)), size_mm, tpm).size_px)
    if side > max_atlas_px:
        while side > max_atlas_px:  # the chart padding does not scale: a few rounds
            tpm *= 0.99 * max_atlas_px / side
            side = max(HeightfieldCharts(np.zeros((1, 1)), size_mm, tpm).size_px)
        messages.append(f"bake_heightfield: texels_per_mm lowered from {texels_per_mm:g} to "
                        f"{tpm:.3g} so the atlas fits {max_atlas_px} px (max_atlas_px)")
    mesh, uv_px, charts, vnormals = heightfield_mesh_charts(heightmap, size_mm, tpm,
                                                            flat_tol_mm=flat_tol_mm)
    return bake_charts(mesh, uv_px, charts.size_px, charts.texel_points(), wood,
                       texels_per_mm=tpm, vertex_normals=vnormals, messages=messages,
                       fill_gutters=charts.fill_gutters)


def _write_preview(baked, stock, out_glb, result, *, obj, screenshot, metadata, obj_units,
                   obj_up, normals, report_mesh) -> PartPreview:
    """Write the baked mesh's GLB (and OBJ, screenshot, and the part report of
    ``report_mesh`` when given) with the stock's metadata."""
    from .export import export_glb, export_obj

    from .advise import reads_wood
    from .appearance.wood import Wood

    mesh = report_mesh
    part_report = report_mesh is not None
    if part_report and not reads_wood(stock.wood):
        # a user's wood that only draws colours is a stock to bake and view; the report reads
        # knots, pith and fibres it has not got (it failed as the uncertainty line's "field must
        # be callable ... got Grey", nothing written)
        import warnings

        from .errors import WoodcamWarning

        warnings.warn(f"{result.name}: no part report (knots, pith, end grain, grain runout): stock.wood "
                      f"({type(stock.wood).__name__}) only draws colours, it has no features(points_mm) to "
                      "read them from; the part is baked with its colours; for the report open the stock "
                      "with open_stock or pass Wood(field)", WoodcamWarning, stacklevel=4)
        part_report = False
    result.atlas_px = tuple(baked.atlas.shape[:2])
    result.atlas = baked.summary()
    from .inference.evidence import uncertainty_report

    surface = mesh if mesh is not None else baked.mesh  # the part, else what was baked
    # a fitted field says where its rings are a guess (issue 12 part 5); only that is a warning.
    # A user's own wood (no Wood: its colours or features) holds no fit to doubt
    rings_line = uncertainty_report(stock.wood, surface.vertices, stock.size_mm, result.name,
                                    confident_line=False) if isinstance(stock.wood, Wood) else None
    if rings_line:
        result.warnings.append(rings_line)
    filed_report = result.report
    if part_report:
        import json

        from ._atomic import write_bytes
        from .advise import part_report as _part_report
        from .advise import report_text
        from .units import filed

        with result.stage("report"):
            result.report = _part_report(mesh, stock)
            if rings_line:
                result.report.setdefault("warnings", []).append(rings_line)
            for w in result.warnings:  # the carve's ("part sticks out of the block") were on stderr only
                if w not in result.report.setdefault("warnings", []):
                    result.report["warnings"].append(w)
            # the files stay in mm (woodcam.units.filed); result.report, which the CLI prints,
            # keeps the warnings as they were said, in --units
            filed_report = {**result.report, "warnings": [filed(w) for w in result.report["warnings"]]}
            stem = out_glb.with_name(out_glb.stem + "_report")
            # written with the GLB (below), as one set: an interrupted export left this part's
            # report beside the previous run's GLB
            report_bytes = {"report": (report_text(filed_report, out_glb.stem) + "\n").encode(),
                            "report_json": json.dumps(filed_report, indent=1).encode()}
        result.files["report"] = stem.with_suffix(".txt")
        result.files["report_json"] = stem.with_suffix(".json")
    result.warnings += list(getattr(baked, "warnings", []))
    from ._specs import absolute_spec
    from .stock import spec_digest

    meta = {"block": absolute_spec(stock.spec), "block_digest": spec_digest(stock.spec),
            "size_mm": list(stock.size_mm),
            # a Mokume sample's size (its files carry none): stock_of_glb reopens it so
            **({"sample_size_mm": stock.meta["sample_size_mm"]} if "sample_size_mm" in stock.meta else {}),
            "appearance": {"kind": stock.meta.get("appearance", "colormap"),
                           "species": stock.meta.get("species"),
                           # False: the species is only the default preset's colours (a block
                           # nobody gave one); stock_of_glb reopens it so (stock.species_text)
                           "species_stated": stock.meta.get("species_stated", True) is not False,
                           "params": stock.meta.get("appearance_params", {})},
            **(metadata or {}),
            "texels_per_mm": float(baked.texels_per_mm)}
    if result.report:  # the review page shows it (volume, yield, "part sticks out", ...)
        meta["report"] = filed_report
    from ._atomic import all_or_nothing

    with result.stage("export"), all_or_nothing():  # GLB + OBJ + MTL + PNG appear as one set
        shaded = baked.mesh
        if obj and normals == "crease":  # split the crease normals once for both files
            from .export import crease_normals

            shaded, normals = crease_normals(baked.mesh), "mesh"
        result.files["glb"] = Path(export_glb(shaded, out_glb, metadata=meta,
                                              normals=normals) or out_glb)
        if part_report:
            for kind, data in report_bytes.items():
                write_bytes(result.files[kind], data)
        if obj:
            obj_path = out_glb.with_suffix(".obj")
            result.files["obj"] = Path(export_obj(shaded, obj_path, units=obj_units,
                                                  up=obj_up, normals=normals) or obj_path)
            from .export import obj_siblings

            result.files["mtl"], result.files["texture"] = obj_siblings(result.files["obj"])
    if screenshot:
        _render_screenshot(baked.mesh, stock, out_glb, result)
    return result


def _render_screenshot(mesh, stock: Stock, out_glb: Path, result: PartPreview) -> None:
    """Render ``mesh`` in ``stock`` off-screen to OUT_view.png beside ``out_glb``."""
    from .view import preview

    png = screenshot_path(True, out_glb)
    with result.stage("render"):
        preview(mesh, wood=stock.wood, size_mm=stock.size_mm, screenshot=png)
    result.files["png"] = png
