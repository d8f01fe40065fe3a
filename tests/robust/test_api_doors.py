"""The doors of the public API: what an entry point cannot use is refused with a WoodcamError that
names it (found by a sweep of bad inputs: these raised AttributeError or a 1.5 TiB MemoryError)."""

from __future__ import annotations

import functools

import numpy as np
import pytest

from woodcam.errors import WoodcamError


def test_fit_block_refuses_what_is_not_a_block():
    from woodcam import fit_block

    with pytest.raises(WoodcamError, match="block must be a woodcam.block.Block.*got NoneType"):
        fit_block(None, "radial")


def test_a_log_too_long_to_hold_is_refused_before_allocating():
    from woodcam import generate_log

    with pytest.raises(WoodcamError, match="surface height map .*MAX_GRID_CELLS.*WOODCAM_MAX_GRID_CELLS"):
        generate_log(seed=1, length_mm=1e12)


def test_crease_normals_refuses_what_is_not_a_mesh():
    from woodcam import crease_normals

    with pytest.raises(WoodcamError, match="mesh must be a trimesh.Trimesh; got NoneType"):
        crease_normals(None)


def test_grain_direction_refuses_what_is_not_a_field():
    import numpy as np

    from woodcam import grain_direction

    with pytest.raises(WoodcamError, match="field must be a growth field.*got NoneType"):
        grain_direction(None, np.zeros((2, 3)))


def test_sizes_that_cannot_be_held_are_refused_before_allocating():
    """rings_picture(zoom=1e6) was a MemoryError from PIL; slice_veneers of 1e300 mm sheets a
    ValueError from numpy; woodify(growth_mm=1e20) a ZeroDivisionError deep in the rasteriser."""
    import numpy as np
    import trimesh

    from woodcam.detect.show import rings_picture
    from woodcam.parquetry import slice_veneers
    from woodcam.stock import open_stock
    from woodcam.synth import cut_block, synth_block
    from woodcam.woodify import woodify

    block = synth_block(cut_block(lambda p: np.hypot(p[:, 0], p[:, 1]) / 2.0, (20, 20, 20), "rift"),
                        (20, 20, 20), face_px=32, seed=1)
    with pytest.raises(WoodcamError, match="the picture at --zoom 1000000 .*MAX_IMAGE_PIXELS"):
        rings_picture(block, zoom=1_000_000)
    with pytest.raises(WoodcamError, match="leaves of 1e\\+300 x 10 mm .*MAX_GRID_CELLS"):
        slice_veneers(open_stock("builtin:flat-sawn"), 2, (1e300, 10.0), px_per_mm=1.0)
    with pytest.raises(WoodcamError, match="growth_mm must be in \\(0, 10000\\]"):
        woodify(trimesh.creation.icosphere(radius=5.0), 3.0, growth_mm=1e20)


def test_small_inputs_that_asked_for_gigabytes_or_hung_are_refused(tmp_path):
    """A 150-byte SVG curve asked for 30 GiB of samples; a thin 5 MB face image a 14 GiB unfolded
    cross; detect_rings at 1e6 px/mm blurred for ever; a NaN point was a ZeroDivisionError in a
    compiled kernel."""
    import numpy as np

    from woodcam import detect_rings, unfold_cross
    from woodcam.block.svg import read_traces_svg
    from woodcam.fields import builtin_block

    (tmp_path / "h.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 10 10" width="10" '
                                    'height="10"><path d="M0,0 C1e9,1e9 -1e9,1e9 10,10"/></svg>')
    with pytest.raises(WoodcamError, match="a curve of .* px in the SVG .*MAX_TRACE_POINTS"):
        read_traces_svg(tmp_path / "h.svg", (10, 10))
    with pytest.raises(WoodcamError, match="the unfolded cross .*MAX_GRID_CELLS"):
        unfold_cross({"front": np.ones((50000, 100), np.uint8)}, (1, 500, 500))
    photo = np.random.default_rng(0).integers(0, 255, (51, 64, 3), dtype=np.uint8)
    for ppm in (1e6, -1.0, float("nan")):
        with pytest.raises(WoodcamError, match=r"px_per_mm of face 'face' must be a number in \(0, 1000\]"):
            detect_rings(photo, px_per_mm=ppm)
    with pytest.raises(WoodcamError, match="too small to hold a ring"):
        detect_rings(photo, px_per_mm=500.0)
    field = builtin_block("flat-sawn").field
    for bad in ([[np.nan, 40, 25]], [[1.0, np.inf, 2.0]]):
        with pytest.raises(WoodcamError, match="points_mm must be finite; point 0 is"):
            field(np.asarray(bad))


def test_numpy_scalars_are_numbers_and_a_polyline_of_nan_is_refused(tmp_path):
    """bake(texels_per_mm=np.float32(2)) and read_gcode(chord_tol_mm=np.float32(0.01)) were refused
    as not numbers; a polyline "0,0 nan,1 2,2" was read as the points (0, 0) and (1, 2)."""
    import numpy as np
    import trimesh

    from woodcam import bake, read_gcode
    from woodcam.block.svg import read_traces_svg

    class Grey:
        def color(self, points_mm, normals):
            return np.full((len(points_mm), 3), 0.5)

    box = trimesh.creation.box((10, 10, 10))
    assert len(bake(box, Grey(), texels_per_mm=np.float32(2.0)).mesh.faces) == 12
    assert len(read_gcode("G1 X1 F100\n", chord_tol_mm=np.float32(0.01))) == 1
    (tmp_path / "t.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10">'
                                    '<polyline points="0,0 nan,1 2,2"/></svg>')
    with pytest.raises(WoodcamError, match="a polyline's points must be pairs of finite numbers"):
        read_traces_svg(tmp_path / "t.svg", (10, 10))


def test_simulate_refuses_sizes_it_cannot_use():
    """size_mm=(inf, 10, 10) was an OverflowError, a string size a ValueError, a string
    resolution a TypeError, a two-number work offset a broadcast ValueError."""
    from woodcam import read_gcode
    from woodcam.toolpath import FlatEndMill
    from woodcam.toolpath.simulate import simulate

    prog = read_gcode("G1 X5 Y5 Z-1 F100\n")
    tools = {0: FlatEndMill(3.0)}
    for kw in (dict(size_mm=(float("inf"), 10, 10)), dict(size_mm="abc"), dict(resolution_mm="x"),
               dict(work_offset_mm=(0, 0))):
        args = dict(size_mm=(10, 10, 10), resolution_mm=0.5) | kw
        with pytest.raises(WoodcamError, match="simulate: "):
            simulate(prog, tools, args.pop("size_mm"), **args)


def test_a_fit_from_one_face_warns_and_rbf_says_why_it_cannot():
    """'woodcam fit --faces front' ended in an internal error (LinAlgError: a thin-plate spline's
    linear tail is singular on the points of one plane) where the README promises a warning."""
    import warnings

    from woodcam.errors import WoodcamWarning
    from woodcam.fields import builtin_block
    from woodcam.inference.fit import fit_block
    from woodcam.synth import synth_block

    block = synth_block(builtin_block("flat-sawn").field, (40, 30, 20), face_px=64, seed=0)
    with pytest.warns(WoodcamWarning, match="only one face carries rings"):
        field = fit_block(block, "evidence", faces=["top"])
    assert field.meta["unverified"] and field.meta["chosen"] == "radial"
    with pytest.raises(WoodcamError, match="'rbf' needs rings on at least two faces"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fit_block(block, "rbf", faces=["top"])


def _wrong_types_and_shapes():
    """``(id, call, match)``: each call raised a bare TypeError/ValueError/IndexError/KeyError/
    AttributeError/ZeroDivisionError, or was silently accepted (marked *), before its door check."""
    import numpy as np

    import woodcam as w
    from woodcam import frames
    from woodcam.block.block import Block, Face, RingTrace
    from woodcam.cad.parts import auto_tolerance_mm
    from woodcam.fields import builtin_block
    from woodcam.fields.base import LogFrame
    from woodcam.fields.grid import GridField
    from woodcam.fields.state import field_from_state
    from woodcam.toolpath.tools import VBit

    fld = builtin_block("flat-sawn").field
    g3 = np.zeros((3, 3, 3))
    return [
        ("grid origin of 2 *", lambda: GridField(g3, (0, 0), 1), "origin_mm must be three finite numbers"),
        ("grid spacing of 2", lambda: GridField(g3, (0, 0, 0), (1, 1)), "spacing_mm must be three finite"),
        ("grid zero axis *", lambda: GridField(g3, (0, 0, 0), 1, axis=(0, 0, 0)), "axis must be a non-zero"),
        ("grid NaN axis *", lambda: GridField(g3, (0, 0, 0), 1, axis=(np.nan, 0, 0)), "axis must be three finite"),
        ("grid.bake array spacing", lambda: GridField.bake(fld, (0, 0, 0), (9, 9, 9), np.ones(2)),
         "spacing_mm must be a finite number > 0"),
        ("grid.bake str spacing", lambda: GridField.bake(fld, (0, 0, 0), (9, 9, 9), "a"), "spacing_mm must be"),
        ("grid.bake margin", lambda: GridField.bake(fld, (0, 0, 0), (9, 9, 9), 1, margin_nodes=-6),
         "margin_nodes must be an integer >= 0"),
        ("logframe pith of 2", lambda: LogFrame((0, 0)).to_log(np.zeros((1, 3))), "pith_point_mm must be three"),
        ("logframe NaN pith *", lambda: LogFrame((np.nan, 0, 0)), "pith_point_mm must be three finite"),
        ("face shape of 1", lambda: Face("top", (3,)), "shape of face 'top' must be two pixel counts"),
        ("face shape 10.7 *", lambda: Face("top", (10.7, 10)), "shape of face 'top' must be two pixel counts"),
        ("face trace not a RingTrace", lambda: Face("top", (8, 8), traces=[np.zeros((2, 2))]),
         "trace 0 of face 'top' must be a RingTrace"),
        ("block face not a Face", lambda: Block((10, 10, 10), faces={"top": 5}), r"Block.faces\['top'\] must be a Face"),
        ("missing face", lambda: Block((10, 10, 10)).face_pixel_size_mm("top"), "face 'top' is not known on block"),
        ("trace of letters", lambda: RingTrace("ab"), "points_px of a ring trace must be"),
        ("trace of complex points *", lambda: RingTrace(np.zeros((3, 2)) + 1j),
         r"points_px of a ring trace must be \(row, col\) real numbers, shape \(k >= 2, 2\); got an array of "
         r"complex numbers \(dtype complex128, shape \(3, 2\)\); pass real numbers \(e\.g\. np\.real\(points_px\)"),
        ("trace with None", lambda: RingTrace([[0, 0], [1, None]]), r"\(row, col\) real numbers.*got \[\[0, 0\], \[1, None\]\]"),
        ("image_shape scalar", lambda: frames.pixel_to_block("top", 1, 1, 5, (9, 9, 9)), "image_shape must be"),
        ("image_shape NaN", lambda: frames.pixel_to_block("top", 1, 1, (np.nan, 9), (9, 9, 9)), "image_shape must be"),
        ("image_shape 10.7 *", lambda: frames.pixel_to_block("top", 1, 1, (10.7, 9), (9, 9, 9)), "image_shape must be"),
        ("block_to_pixel scalar", lambda: frames.block_to_pixel("top", 5.0, (9, 9), (9, 9, 9)),
         r"points_mm must have shape \(\.\.\., 3\)"),
        ("unfold 1-D image", lambda: w.unfold_cross({"front": np.ones(10)}, (10, 10, 10)), "image of face 'front'"),
        ("unfold grey beside RGB", lambda: w.unfold_cross({"front": np.ones((10, 10)), "top": np.ones((10, 10, 3))},
                                                          (10, 10, 10)), "image of face 'top'"),
        ("unfold background of 2", lambda: w.unfold_cross({"front": np.ones((10, 10, 3))}, (10, 10, 10), (1, 2)),
         "background must be one value or one per channel"),
        ("unfold list", lambda: w.unfold_cross([np.ones((10, 10))], (10, 10, 10)), "images must be a dict"),
        ("auto tolerance 0 texels", lambda: auto_tolerance_mm(10, texels_per_mm=0), "texels_per_mm must be"),
        ("auto tolerance NaN *", lambda: auto_tolerance_mm(np.nan), "diagonal_mm must be"),
        ("auto tolerance < 0 *", lambda: auto_tolerance_mm(-5), "diagonal_mm must be"),
        ("auto tolerance 0 *", lambda: auto_tolerance_mm(0), r"diagonal_mm must be a finite number > 0; got 0"),
        ("turned size of 2", lambda: w.Wood(fld).turned("z", 1, (1, 1)), "size_mm must be three"),
        ("turned quarter_turns str", lambda: w.Wood(fld).turned("z", "a", (9, 9, 9)), "quarter_turns must be"),
        ("open_stock unknown keyword", lambda: w.open_stock("builtin:flat-sawn", foo=1),
         "appearance_params must be parameters of the colormap appearance.*'foo'"),
        ("field state missing keys", lambda: field_from_state({"type": "woodcam.fields.radial:RadialScalingField",
                                                               "state": {}}), "saved state of field type"),
        ("field state a list", lambda: field_from_state([1, 2]), "a saved field must be a dict"),
        ("vbit angle str", lambda: VBit(6, angle_deg="60"), "angle_deg must be a number"),
        ("generate_log seed str", lambda: w.generate_log("a"), "seed must be an integer"),
        ("machining time str", lambda: w.read_gcode("G1 X10 F100\n").machining_time_s("a"),
         "rapid_mm_min must be a finite number"),
    ]


@pytest.mark.parametrize("name, call, match", _wrong_types_and_shapes(), ids=lambda v: v if isinstance(v, str) else "")
def test_wrong_types_and_shapes_are_refused_naming_the_argument(name, call, match):
    with pytest.raises(WoodcamError, match=match):
        call()


def test_woodify_refuses_a_string_resolution_and_nan_vertex_gains():
    import numpy as np
    import trimesh

    from woodcam.woodify import woodify

    ball = trimesh.creation.icosphere(radius=10)
    with pytest.raises(WoodcamError, match="resolution must be an integer in"):
        woodify(ball, 2, resolution="32")
    with pytest.raises(WoodcamError, match="vertex_gain must be .* finite values > 0"):
        woodify(ball, 2, resolution=32, vertex_gain=np.full(len(ball.vertices), np.nan))


def _library_door_sweep():
    """``(id, call, match)`` from a sweep of the library doors with the mistakes a user makes (a
    wrong shape, NaN, a string for a number, a wrong kind of object): each raised a bare
    TypeError/ValueError/AttributeError/IndexError/ZeroDivisionError, returned garbage (marked *)
    or named the wrong argument (marked !) before its door check."""
    import numpy as np

    import woodcam as w

    fld = w.builtin_block("flat-sawn").field
    pts = np.array([[5.0, 5.0, 5.0], [1.0, 2.0, 3.0]])
    return [
        ("evaluate batch -1 *", lambda: w.evaluate(fld, pts, batch=-1), "batch must be an integer >= 1; got -1"),
        ("evaluate batch 0", lambda: w.evaluate(fld, pts, batch=0), "batch must be an integer >= 1; got 0"),
        ("evaluate batch 1.5", lambda: w.evaluate(fld, pts, batch=1.5), "batch must be an integer >= 1; got 1.5"),
        ("evaluate workers str", lambda: w.evaluate(fld, pts, workers="2"), "workers must be an integer >= 1; got '2'"),
        ("evaluate field None", lambda: w.evaluate(None, pts), "field must be a growth field .*got NoneType"),
        ("GridField.bake field str", lambda: w.GridField.bake("oak", (0, 0, 0), (9, 9, 9), 3),
         "field must be a growth field .*got str"),
        ("block_to_pixel NaN point *", lambda: w.block_to_pixel("top", [[np.nan, 1, 1]], (10, 10), (10, 10, 10)),
         r"points_mm must be finite; point \(0,\) is \[nan, 1.0, 1.0\]"),
        ("pixel_to_block NaN row *", lambda: w.pixel_to_block("top", [np.nan], [1], (10, 10), (10, 10, 10)),
         r"rows must be finite pixel coordinates .*got \[nan\]"),
        ("pixel_to_block str cols", lambda: w.pixel_to_block("top", [1], "a", (10, 10), (10, 10, 10)),
         "cols must be finite pixel coordinates .*got 'a'"),
        ("pixel_to_block 2 rows 3 cols", lambda: w.pixel_to_block("top", [1, 2], [1, 2, 3], (10, 10), (10, 10, 10)),
         r"rows and cols must broadcast together .*shapes \(2,\) and \(3,\)"),
        ("radial frame None", lambda: w.RadialScalingField(None), "frame must be a woodcam.fields.LogFrame; got NoneType"),
        ("radial r_minus array", lambda: w.RadialScalingField(w.LogFrame(), r_minus=np.ones(5)),
         "r_minus must be a RadiusFunction; got ndarray"),
        ("radial ring width str", lambda: w.RadialScalingField(w.LogFrame(), ring_width_mm="3"),
         "ring_width_mm must be a finite number > 0; got '3'"),
        ("radial NaN age *", lambda: w.RadialScalingField(w.LogFrame(), age_offset_years=np.nan),
         "age_offset_years must be a finite number; got nan"),
        ("grid years str", lambda: w.GridField("abc", (0, 0, 0), 1), "years must be a finite .*got 'abc'"),
        ("grid years NaN", lambda: w.GridField(np.full((3, 3, 3), np.nan), (0, 0, 0), 1),
         r"years must be a finite .*got shape \(3, 3, 3\) with 27 non-finite"),
        ("grid meta list *", lambda: w.GridField(np.zeros((3, 3, 3)), (0, 0, 0), 1, meta=[1]),
         "meta must be a dict of field metadata; got list"),
        ("grid layers list", lambda: w.GridField(np.zeros((3, 3, 3)), (0, 0, 0), 1, layers=[np.zeros((3, 3, 3))]),
         "layers must be a dict .*got list"),
        ("wood appearance a species name", lambda: w.Wood(fld, appearance="oak"),
         r"appearance must have a method color.*got 'oak'.*ColorMapAppearance\('walnut'\)"),
        ("wood threads str", lambda: w.Wood(fld, threads="2"), "threads must be an integer >= 1; got '2'"),
        ("wood threads -1 *", lambda: w.Wood(fld, threads=-1), "threads must be an integer >= 1; got -1"),
        ("colormap seed str", lambda: w.ColorMapAppearance(seed="a"), "seed must be an integer in \\[0, .*got 'a'"),
        ("colormap seed 2**70", lambda: w.ColorMapAppearance(seed=2**70), "seed must be an integer in .*got 1180591620717411303424"),
        ("colormap seed 1.5 *", lambda: w.ColorMapAppearance(seed=1.5), "seed must be an integer in .*got 1.5"),
        ("open_stock seed str", lambda: w.open_stock("builtin:flat-sawn", seed="a"), "seed must be an integer in .*got 'a'"),
        ("cut_block NaN distance !", lambda: w.cut_block(fld, (20, 20, 20), distance_mm=np.nan),
         "distance_mm must be a finite number >= 0; got nan"),
        ("cut_block NaN angle !", lambda: w.cut_block(fld, (20, 20, 20), angle_deg=np.nan),
         "angle_deg must be a finite number; got nan"),
        ("cut_block NaN tilt !", lambda: w.cut_block(fld, (20, 20, 20), tilt_deg=np.nan), "tilt_deg must be a finite number; got nan"),
        ("cut_block inf height !", lambda: w.cut_block(fld, (20, 20, 20), height_mm=np.inf),
         "height_mm must be a finite number; got inf"),
        ("cut_block str azimuth", lambda: w.cut_block(fld, (20, 20, 20), azimuth_deg="a"),
         "azimuth_deg must be a finite number; got 'a'"),
        ("cut_block tuple log_frame", lambda: w.cut_block(fld, (20, 20, 20), log_frame=(0, 0, 1)),
         "log_frame must be a woodcam.fields.LogFrame or None; got tuple"),
        ("synth spec dict", lambda: w.synth_block(fld, (20, 20, 20), {"face_px": 16}), "spec must be a SynthSpec or None; got dict"),
        ("synth rng int", lambda: w.synth_block(fld, (20, 20, 20), face_px=16, rng=1), "rng must be a numpy Generator or None; got 1"),
        ("synth meta list", lambda: w.synth_block(fld, (20, 20, 20), face_px=16, meta=[1]),
         "meta must be a dict of extra block metadata or None; got list"),
        ("synth seed str", lambda: w.synth_block(fld, (20, 20, 20), face_px=16, seed="a"), "seed must be an integer >= 0; got 'a'"),
        ("synth NaN field", lambda: w.synth_block(lambda p: np.full(len(p), np.nan), (20, 20, 20), face_px=16),
         "field must give finite years on the block; it gave 256 NaN/inf of 256 pixels of face 'front'"),
        ("brush radius str", lambda: w.Brush((0, 0, 0), "5"), "brush radius_mm must be a number; got '5'"),
        ("growth speed velocity str", lambda: w.GrowthSpeed("1", 1), "velocity_mm must be a number; got '1'"),
        ("generate_log length str", lambda: w.generate_log(1, length_mm="200"), "length_mm must be a number > 100 mm; got '200'"),
        ("generate_log stats None", lambda: w.generate_log(1, length_mm=200, stats=None),
         "stats must be a woodcam.logs.generate.LogStats; got NoneType"),
        ("generate_log heightmap of 1", lambda: w.generate_log(1, length_mm=200, heightmap_shape=(10,)),
         r"heightmap_shape must be two whole counts .*got \(10,\)"),
        ("generate_log heightmap str", lambda: w.generate_log(1, length_mm=200, heightmap_shape="ab"),
         "heightmap_shape must be two whole counts .*got 'ab'"),
        ("knotted table_samples 0", lambda: w.KnottedLogField(_small_log(), table_samples=0),
         "table_samples must be an integer >= 2; got 0"),
        ("knotted table_samples 1", lambda: w.KnottedLogField(_small_log(), table_samples=1),
         "table_samples must be an integer >= 2; got 1"),
        ("knotted ring width str", lambda: w.KnottedLogField(_small_log(), ring_width_mm="2"),
         "ring_width_mm must be a finite number > 0; got '2'"),
        ("knotted smoothing (0, -1) *", lambda: w.KnottedLogField(_small_log(), surface_smoothing=(0, -1)),
         r"surface_smoothing must be two window sizes >= 1 .*got \(0, -1\)"),
        ("knotted chunk 0 *", lambda: w.KnottedLogField(_small_log(), chunk=0), "chunk must be an integer >= 1; got 0"),
        ("read_log None", lambda: w.read_log(None), r"read_log: path must be a file path \(str or pathlib.Path\); got None"),
        ("write_log path None", lambda: w.write_log(_small_log(), None), "write_log: path must be a file path .*got None"),
        ("write_log log None", lambda: w.write_log(None, "l.json"), "log must be a woodcam.fields.skeleton.LogSkeleton; got NoneType"),
        ("load_textured None", lambda: w.load_textured(None), "load_textured: path must be a file path .*got None"),
        ("export_glb path None", lambda: w.export_glb(_baked_box(), None), "export_glb: path must be a file path .*got None"),
        ("export_obj path 5", lambda: w.export_obj(_baked_box(), 5), "export_obj: path must be a file path .*got 5"),
        ("load_tool_table None", lambda: w.load_tool_table(None), "load_tool_table: path must be a file path .*got None"),
        ("load_scan None", lambda: w.load_scan(None, dpi=300), "load_scan: path must be a file path .*got None"),
        ("read_gcode None !", lambda: w.read_gcode(None), "read_gcode: text_or_path must be the program text .*got None"),
        ("read_gcode start str", lambda: w.read_gcode("G1 X1 F100\n", start_mm="abc"),
         "read_gcode: start_mm must be three finite numbers .*got 'abc'"),
        ("Tool base class *", lambda: w.Tool(3.0), r"Tool is the base class .*parse_tool_spec\('flat:6'\)"),
        ("simulate resolution True *", lambda: w.simulate(w.read_gcode("G1 X5 F100\n"), w.parse_tool_spec("flat:3"),
                                                          (10, 10, 10), resolution_mm=True),
         "simulate: resolution_mm must be a finite number > 0; got True"),
        ("simulate resolution '0.5' *", lambda: w.simulate(w.read_gcode("G1 X5 F100\n"), w.parse_tool_spec("flat:3"),
                                                           (10, 10, 10), resolution_mm="0.5"),
         "simulate: resolution_mm must be a finite number > 0; got '0.5'"),
        ("simulate G-code text", lambda: w.simulate("G1 X5 F100\n", w.parse_tool_spec("flat:3"), (10, 10, 10)),
         r"simulate: program must be a Program; got str; .*read_gcode"),
        ("simulate str heightmap", lambda: w.simulate(w.read_gcode("G1 X5 F100\n"), w.parse_tool_spec("flat:3"),
                                                      (10, 10, 10), resolution_mm=0.5, initial_heightmap="a"),
         r"simulate: initial_heightmap must be a finite \(20, 20\) array .*got 'a'"),
        ("parquetry params dict", lambda: w.build_parquetry(_target(), [_veneer()], {"patch_mm": 4}),
         "params must be a ParquetryParams or None; got dict"),
        ("parquetry 1-D target", lambda: w.build_parquetry(np.ones(10), [_veneer()], _small_params()),
         r"target 0 must be an \(h, w, 3\) RGB or \(h, w\) grey image; got shape \(10,\)"),
        ("parquetry empty target", lambda: w.build_parquetry(np.zeros((0, 0, 3)), [_veneer()], _small_params()),
         r"target 0 must be .*got shape \(0, 0, 3\)"),
        ("parquetry 0..255 float target *", lambda: w.build_parquetry(_target() * 255, [_veneer()], _small_params()),
         r"target 0 must hold finite values in \[0, 1\]; got range \[.*, 25\d.*\] with 0 non-finite"),
        ("parquetry NaN target *", lambda: w.build_parquetry(np.full((20, 20, 3), np.nan), [_veneer()], _small_params()),
         r"target 0 must hold finite values .*got range \[nan, nan\] with 1200 non-finite"),
        ("parquetry path target", lambda: w.build_parquetry("moon.png", [_veneer()], _small_params()),
         "targets must be images .*not a path; got 'moon.png'"),
        ("parquetry array veneer", lambda: w.build_parquetry(_target(), [np.zeros((10, 10, 3))], _small_params()),
         r"veneers\[0\] must be a Veneer; got ndarray"),
        ("parquetry names short", lambda: w.build_parquetry([_target(), _target()], [_veneer()], _small_params(), names=["a"]),
         r"names must be one name per target \(2\); got \['a'\]"),
        ("slice n_sheets 1.5", lambda: w.slice_veneers(_stock(), 1.5, (10, 10), px_per_mm=1), "n_sheets must be an integer >= 1; got 1.5"),
        ("slice size of 3", lambda: w.slice_veneers(_stock(), 2, (10, 10, 10), px_per_mm=1),
         r"size_mm must be 2 finite numbers; got \(10, 10, 10\)"),
        ("slice NaN size", lambda: w.slice_veneers(_stock(), 2, (np.nan, 10), px_per_mm=1), "size_mm must be 2 finite numbers; got"),
        ("slice NaN px_per_mm", lambda: w.slice_veneers(_stock(), 2, (10, 10), px_per_mm=np.nan),
         "px_per_mm must be a finite number > 0; got nan"),
        ("slice NaN thickness !", lambda: w.slice_veneers(_stock(), 2, (10, 10), thickness_mm=np.nan, px_per_mm=1),
         "thickness_mm must be a finite number > 0; got nan"),
        ("slice str start", lambda: w.slice_veneers(_stock(), 2, (10, 10), px_per_mm=1, start_mm="a"),
         "start_mm must be a finite number; got 'a'"),
        ("slice supersample 1.5 *", lambda: w.slice_veneers(_stock(), 2, (10, 10), px_per_mm=1, supersample=1.5),
         r"supersample must be an integer in \[1, 16\]; got 1.5"),
        ("load_scan dpi 'x'", lambda: w.load_scan(_scan_file(), dpi="x"), "dpi must be a finite number > 0; got 'x'"),
        ("fit_block faces a string !", lambda: w.fit_block(w.Block((10, 10, 10)), "radial", faces="top"),
         r"faces must be a list of face names or None; got the string 'top'; pass \['top'\]"),
        ("detect_rings wavelength scalar", lambda: w.detect_rings(_photo(), px_per_mm=5, wavelength_range_px=5),
         "wavelength_range_px must be \\(min, max\\) px; got 5"),
        ("detect_rings wavelength str", lambda: w.detect_rings(_photo(), px_per_mm=5, wavelength_range_px=("a", "b")),
         r"wavelength_range_px must be \(min, max\) px; got \('a', 'b'\)"),
        ("load_part report list", lambda: w.load_part(_cube(), report=[]), "report must be a dict .*got list"),
        ("read_block None", lambda: w.read_block(None), "read_block: folder must be a file path .*got None"),
        ("write_block None", lambda: w.write_block(None, "b"), "block must be a woodcam.block.Block; got NoneType"),
        ("write_block folder None", lambda: w.write_block(w.Block((10, 10, 10)), None),
         "write_block: folder must be a file path .*got None"),
        ("write_block traces_svg list *", lambda: w.write_block(w.Block((10, 10, 10)), _tmp(), traces_svg=["front.svg"]),
         r"write_block: traces_svg must be a dict face -> SVG file name in the folder, or None; got \['front.svg'\]"),
        ("write_block existing list", lambda: w.write_block(w.Block((10, 10, 10)), _tmp(), existing=[1]),
         r"write_block: existing must be a dict face -> .*got \[1\]"),
        ("read_mokume None", lambda: w.read_mokume(None), "read_mokume: folder must be a file path .*got None"),
        ("read_job None", lambda: w.read_job(None), "read_job: path must be a file path .*got None"),
        ("job scans a string", lambda: w.ParquetryJob(scans="oak.png"),
         r"ParquetryJob.scans must be a list of dicts, each with 'texture'; got 'oak.png'; e.g. \[\{'texture'"),
        ("job target an int", lambda: w.ParquetryJob(targets=[5]), "ParquetryJob.targets must be a list of dicts, each with 'filename'; got \\[5\\]"),
        ("job params a dict", lambda: w.ParquetryJob(params={}), "ParquetryJob.params must be a ParquetryParams; got dict"),
        ("job mokume of ints", lambda: w.ParquetryJob(mokume=[3]), "ParquetryJob.mokume must be a list of Mokume sample folders"),
        ("write_job None", lambda: w.write_job(None, "j.json"), "job must be a ParquetryJob; got NoneType"),
        ("read_records None", lambda: w.read_records(None), "read_records: out_dir must be a file path .*got None"),
        ("repair_fabricability None", lambda: w.repair_fabricability(None),
         "repair_fabricability: run must be a ParquetryRun; got NoneType"),
        ("write_parquetry None", lambda: w.write_parquetry(None, "out"), "write_parquetry: run must be a ParquetryRun; got NoneType"),
        ("fit_stem size of 2", lambda: w.fit_stem(_obs(), (40, 30)), r"size_mm must be three positive .*got \(40, 30\)"),
        ("fit_stem K str", lambda: w.fit_stem(_obs(), (40, 30, 20), K="4"), "K must be an integer >= 0; got '4'"),
        ("fit_stem M -1", lambda: w.fit_stem(_obs(), (40, 30, 20), M=-1), "M must be an integer >= 0; got -1"),
        ("fit_stem n_search 0", lambda: w.fit_stem(_obs(), (40, 30, 20), n_search=0), "n_search must be an integer >= 20; got 0"),
        ("fit_stem n_starts 0 *", lambda: w.fit_stem(_obs(), (40, 30, 20), n_starts=0), "n_starts must be an integer >= 1; got 0"),
        ("fit_stem workers 0 *", lambda: w.fit_stem(_obs(), (40, 30, 20), workers=0), "workers must be an integer >= 1; got 0"),
        ("fit_stem seed str", lambda: w.fit_stem(_obs(), (40, 30, 20), seed="a"), "seed must be an integer >= 0; got 'a'"),
        ("fit_stem init int", lambda: w.fit_stem(_obs(), (40, 30, 20), init=5), "init must be a StemField .*got int"),
        ("fit_stem base_axes (k, 2)", lambda: w.fit_stem(_obs(), (40, 30, 20), base_axes=[[0, 1]]),
         r"base_axes must be finite non-zero directions, one \(3,\) or \(k, 3\); got \[\[0, 1\]\]; e.g. base_axes="),
        ("fit_stem zero base axis", lambda: w.fit_stem(_obs(), (40, 30, 20), base_axes=(0, 0, 0)),
         r"base_axes must be finite non-zero directions.*got \(0, 0, 0\)"),
        ("fit_stem base_axes str", lambda: w.fit_stem(_obs(), (40, 30, 20), base_axes="z"),
         "base_axes must be finite non-zero directions.*got 'z'"),
        ("fit_stem offset_years str", lambda: w.fit_stem(_obs(), (40, 30, 20), offset_years="a"),
         r"offset_years must be \d+ finite years, one per observation; got 'a'"),
        ("fit_stem NaN tilt", lambda: w.fit_stem(_obs(), (40, 30, 20), tilt_prior_deg=np.nan),
         "tilt_prior_deg must be a finite number > 0; got nan"),
        ("fit_evidence obs None", lambda: w.fit_evidence(None, (40, 30, 20)), "obs must be RingObservations .*got NoneType"),
        ("fit_evidence NaN size", lambda: w.fit_evidence(_obs(), (np.nan, 30, 20)),
         r"size_mm must be three positive finite lengths \(W, D, H\) in mm; got \(nan, 30, 20\)"),
        ("fit_evidence size of 2", lambda: w.fit_evidence(_obs(), (40, 30)), r"size_mm must be three positive .*got \(40, 30\)"),
        ("fit_evidence NaN n_basins", lambda: w.fit_evidence(_obs(), (40, 30, 20), n_basins=np.nan),
         "n_basins must be an integer >= 1; got nan; the pith-axis basins"),
        ("fit_evidence n_basins 0 *", lambda: w.fit_evidence(_obs(), (40, 30, 20), n_basins=0),
         "n_basins must be an integer >= 1; got 0"),
        ("fit_evidence seed str", lambda: w.fit_evidence(_obs(), (40, 30, 20), seed="a"), "seed must be an integer >= 0; got 'a'"),
        ("fit_evidence workers 0", lambda: w.fit_evidence(_obs(), (40, 30, 20), workers=0), "workers must be an integer >= 1; got 0"),
        ("evaluate_fit pixel 0", lambda: w.evaluate_fit(fld, fld, (40, 30, 20), pixel_mm=0), "pixel_mm must be a finite number > 0; got 0"),
        ("evaluate_fit NaN pixel", lambda: w.evaluate_fit(fld, fld, (40, 30, 20), pixel_mm=np.nan),
         "pixel_mm must be a finite number > 0; got nan"),
        ("evaluate_fit plane of 1", lambda: w.evaluate_fit(fld, fld, (40, 30, 20), planes=[1]), "planes must be CutPlanes; got 1"),
        ("evaluate_fit NaN field", lambda: w.evaluate_fit(fld, lambda p: np.full(len(p), np.nan), (40, 30, 20), pixel_mm=1),
         "field must give finite years in the block; it gave \\d+ NaN/inf of \\d+ points of cut plane 'z=0.5'"),
        ("evaluate_fit no planes *", lambda: w.evaluate_fit(fld, fld, (40, 30, 20), planes=[]),
         r"planes must be a non-empty list of CutPlanes; got \[\]; e.g. \[CutPlane\("),
        ("evaluate_fit planes None", lambda: w.evaluate_fit(fld, fld, (40, 30, 20), planes=None),
         "planes must be a non-empty list of CutPlanes; got None"),
        ("benchmark no blocks", lambda: w.benchmark([]), r"blocks must be a non-empty list of woodcam.block.Block; got \[\]"),
        ("benchmark blocks None", lambda: w.benchmark(None), "blocks must be a non-empty list of woodcam.block.Block; got None"),
        ("benchmark one block", lambda: w.benchmark(w.Block((9, 9, 9))), "blocks must be a non-empty list of woodcam.block.Block"),
        ("benchmark no methods *", lambda: w.benchmark([_synth()], methods=[]),
         r"methods must be a non-empty list of method names; got \[\]; e.g. methods=\['evidence'\]"),
        ("benchmark unknown method", lambda: w.benchmark([_synth()], methods=["radial", "radiall"]),
         "methods must be method names from evidence, rbf, radial, neural; got 'radiall'; did you mean 'radial'"),
        ("benchmark face_sets list", lambda: w.benchmark([_synth()], methods=["radial"], face_sets=[None]),
         "face_sets must be a dict label -> list of faces .*got list"),
        ("leave_one_face_out no methods", lambda: w.leave_one_face_out(_synth(), methods=[]),
         r"methods must be a non-empty list of method names; got \[\]"),
        ("leave_one_face_out methods None", lambda: w.leave_one_face_out(_synth(), methods=None),
         "methods must be a non-empty list of method names; got None"),
        ("leave_one_face_out None", lambda: w.leave_one_face_out(None), "block must be a woodcam.block.Block; got NoneType"),
        ("leave_one_face_out reference 5", lambda: w.leave_one_face_out(w.Block((9, 9, 9)), reference=5),
         "reference must be a woodcam.block.Block; got int"),
        ("leave_one_face_out methods str !", lambda: w.leave_one_face_out(w.Block((9, 9, 9)), methods="radial"),
         r"methods must be a list of method names; got the string 'radial'; pass \['radial'\]"),
        ("leave_one_face_out progress 5", lambda: w.leave_one_face_out(w.Block((9, 9, 9)), progress=5),
         "progress must be a callable .*got int"),
        ("preview_mesh None", lambda: w.preview_mesh(None, _stock(), "p.glb", obj=False, screenshot=False),
         "mesh must be a trimesh.Trimesh .*got NoneType"),
        ("preview_mesh stock None", lambda: w.preview_mesh(_cube(), None, "p.glb", obj=False, screenshot=False),
         "stock must be a woodcam Stock; got NoneType"),
        ("preview_mesh out None", lambda: w.preview_mesh(_cube(), _stock(), None, obj=False, screenshot=False),
         "--out must be a file path .*got None"),
        ("preview_mesh metadata list", lambda: w.preview_mesh(_cube(), _stock(), _tmp() / "p.glb", metadata=[1], obj=False,
                                                              screenshot=False),
         "metadata must be a dict of extra GLB metadata or None; got list"),
        ("preview_mesh result int", lambda: w.preview_mesh(_cube(), _stock(), _tmp() / "p.glb", result=5, obj=False,
                                                           screenshot=False),
         "result must be a PartPreview to fill .*or None; got int"),
        ("preview_part stock None", lambda: w.preview_part(_cube(), None, "p.glb", obj=False, screenshot=False),
         "stock must be a woodcam Stock; got NoneType"),
        ("preview_part max_triangles 0 *", lambda: w.preview_part(_cube(), _stock(), _tmp() / "p.glb", max_triangles=0, obj=False,
                                                                  screenshot=False),
         "max_triangles must be an integer >= 100 or None; got 0"),
        ("preview_part place str !", lambda: w.preview_part(_cube(), _stock(), "p.glb", place="center", obj=False,
                                                            screenshot=False),
         r"place must be a list of placement operations; got the string 'center'; pass \['center'\]"),
        ("preview options a dict", lambda: w.preview(_cube(), screenshot=_tmp() / "s.png", options={"camera": "top"}),
         r"options must be a woodcam.view.SceneOptions or None; got dict; pass SceneOptions\(\*\*\{...\}\)"),
        ("scene resolution 0 *", lambda: w.SceneOptions(resolution_mm=0), "resolution_mm must be a finite number > 0; got 0"),
        ("scene resolution NaN *", lambda: w.SceneOptions(resolution_mm=np.nan), "resolution_mm must be a finite number > 0; got nan"),
        ("scene max_samples 0 *", lambda: w.SceneOptions(max_samples=0), "max_samples must be an integer >= 1; got 0"),
        ("block true_field an int *", lambda: w.Block((10, 10, 10), true_field=5),
         r"Block.true_field must be a growth field \(\(n, 3\) mm -> years\) or None; got int"),
        ("block meta list *", lambda: w.Block((10, 10, 10), meta=[1]), "Block.meta must be a dict of block metadata; got list"),
        ("face traces an int", lambda: w.Face("top", (8, 8), traces=5),
         r"traces of face 'top' must be a list of RingTrace; got int; e.g. traces=\[RingTrace\(points_px\)\]"),
        ("face traces one RingTrace", lambda: w.Face("top", (8, 8), traces=w.RingTrace([[1, 1], [2, 2]])),
         "traces of face 'top' must be a list of RingTrace; got RingTrace"),
        ("face extras list *", lambda: w.Face("top", (8, 8), extras=[1]), "extras of face 'top' must be a dict .*got list"),
        ("face NaN ring map *", lambda: w.Face("top", (8, 8), ring_map=np.full((8, 8), np.nan)),
         r"ring_map of face 'top' must hold finite values in \[0, 1\]; got range \[nan, nan\] with 64 non-finite"),
        ("face photo 0..255 float *", lambda: w.Face("top", (8, 8), photo=np.full((8, 8, 3), 200.0)),
         r"photo of face 'top' must hold finite values in \[0, 1\]; got range \[200, 200\]"),
        ("face photo of ints", lambda: w.Face("top", (8, 8), photo=np.full((8, 8, 3), 200)),
         "photo of face 'top' must be uint8 .*got dtype int64"),
        ("arf str", lambda: w.arf("a"), "years must be growth times .*got 'a'"),
        ("arf None *", lambda: w.arf(None), r"years must be growth times \(numbers, any shape\); got None; pass field"),
        ("arf str number *", lambda: w.arf("0.5"), "years must be growth times .*got '0.5'"),
        ("arf list with None *", lambda: w.arf([1.0, None]), r"years must be growth times .*got \[1.0, None\]"),
        ("unfold_cross NaN image *", lambda: w.unfold_cross({"front": np.full((4, 10), np.nan)}, (50, 20, 20)),
         "image of face 'front' must hold finite numbers; got 40 NaN/inf of 40 values; fill the missing pixels"),
        ("unfold_cross one inf value *", lambda: w.unfold_cross(
            {"top": np.zeros((8, 10, 3)), "front": np.where(np.arange(240).reshape(8, 10, 3) == 70, np.inf, 0.0)},
            (50, 40, 40)), "image of face 'front' must hold finite numbers; got 1 NaN/inf of 240 values"),
        ("unfold_cross image of strings", lambda: w.unfold_cross({"front": np.full((4, 10), "a")}, (50, 20, 20)),
         r"image of face 'front' must hold finite numbers; got dtype <U1; pass a numeric image"),
        ("run_bench seed str", lambda: w.run_bench(_tmp() / "rb", 1, "a", progress=False),
         "seed must be an integer >= 0; got 'a'; the bench's seed"),
        ("run_bench start -1 *", lambda: w.run_bench(_tmp() / "rb", 1, 1, start=-1, progress=False),
         "start must be an integer >= 0; got -1"),
        ("run_bench blocks True *", lambda: w.run_bench(_tmp() / "rb", True, 1, progress=False),
         "blocks must be an integer >= 1; got True"),
        ("run_bench settings list", lambda: w.run_bench(_tmp() / "rb", 1, 1, [1], progress=False),
         r"settings must be a dict of bench settings to override, or None; got \[1\]"),
        ("run_bench NaN size *", lambda: w.run_bench(_tmp() / "rb", 1, 1, {"size_mm": [np.nan, 20, 20]}, progress=False),
         r"size_mm must be three positive finite lengths \(W, D, H\) in mm; got \[nan, 20, 20\]"),
        ("run_bench reversed ring widths *", lambda: w.run_bench(_tmp() / "rb", 1, 1, {"ring_width_range_mm": [3, 1]},
                                                                 progress=False),
         r"ring_width_range_mm must be two ring widths 0 < min <= max in mm; got \[3, 1\]"),
        ("run_bench knotted_fraction str", lambda: w.run_bench(_tmp() / "rb", 1, 1, {"knotted_fraction": "a"}, progress=False),
         r"knotted_fraction must be a finite number in \[0, 1\]; got 'a'"),
        ("run_bench face_sets list", lambda: w.run_bench(_tmp() / "rb", 1, 1, {"face_sets": [1]}, progress=False),
         r"face_sets must be a dict label -> list of faces .*got \[1\]"),
        ("run_bench jitter str", lambda: w.run_bench(_tmp() / "rb", 1, 1, {"trace_jitter_mm": "a"}, progress=False),
         "trace_jitter_mm must be a finite number >= 0; got 'a'"),
        ("bench_block seed str", lambda: w.bench_block("a", 0, {}), "seed must be an integer >= 0; got 'a'"),
        ("bench_block index -1", lambda: w.bench_block(1, -1, {}), "index must be an integer >= 0; got -1"),
        ("bench_block settings None", lambda: w.bench_block(1, 0, None),
         r"settings must be the dict of every bench setting \(bench_settings\(...\)\); got None"),
        ("run_many fn None *", lambda: w.run_many(None, ["a"], "runs", progress=False), "fn must be a callable .*got NoneType"),
        ("run_many retries True *", lambda: w.run_many(str, ["a"], "runs", retries=True, progress=False),
         "retries must be an integer >= 0; got True"),
        ("run_many workers True *", lambda: w.run_many(str, ["a"], "runs", workers=True, progress=False),
         "workers must be an integer >= 1; got True"),
        ("run_many memory str", lambda: w.run_many(str, ["a"], "runs", memory_limit_mb="1e3", progress=False),
         "memory_limit_mb must be a finite number >= 256; got '1e3'"),
        ("run_many NaN connect timeout *", lambda: w.run_many(str, ["a"], _tmp(), connect_timeout_s=np.nan, progress=False),
         "connect_timeout_s must be a finite number > 0; got nan; seconds to wait for a Dask scheduler"),
        ("run_many connect timeout 0 *", lambda: w.run_many(str, ["a"], _tmp(), engine="dask", address="tcp://127.0.0.1:1",
                                                            connect_timeout_s=0, progress=False),
         "connect_timeout_s must be a finite number > 0; got 0"),
        ("run_many keys None", lambda: w.run_many(str, None, "runs", progress=False), "keys must be an iterable of keys .*got None"),
        ("run_many keys str *", lambda: w.run_many(str, "abc", "runs", progress=False),
         r"keys must be an iterable .*got 'abc'; pass \['abc'\]"),
        ("load_scan NaN mask *", lambda: w.load_scan(_scan_file(), dpi=300, mask=np.full((40, 40), np.nan)),
         "load_scan: mask must be an \\(h, w\\) bool array .*got dtype float64 with NaN/inf"),
        ("open_stock None !", lambda: w.open_stock(None), "spec must be a block spec .*got None"),
        ("open_stock empty !", lambda: w.open_stock(""), "spec must be a block spec .*got ''"),
        ("open_stock int !", lambda: w.open_stock(5), "spec must be a block spec .*got 5"),
        ("read_glb_metadata None", lambda: w.read_glb_metadata(None), "read_glb_metadata: path must be a file path .*got None"),
        ("written_by_woodcam None", lambda: w.written_by_woodcam(None), "written_by_woodcam: path must be a file path .*got None"),
        ("read_gran1 5", lambda: w.read_gran1(5), "read_gran1: folder must be a file path .*got 5"),
        ("placed rotation str", lambda: w.PlacedField(fld, (0, 0, 0), "abc"), "rotation must be a proper 3x3 .*got 'abc'"),
        ("wood rotated str", lambda: w.Wood(fld).rotated("abc", (0, 0, 0)),
         r"rotated: rotation must be a proper 3x3 rotation matrix \(orthonormal, det \+1\); got 'abc'; build it with scipy"),
        ("wood rotated reflection", lambda: w.Wood(fld).rotated(np.diag([1.0, 1.0, -1.0]), (0, 0, 0)),
         "rotated: rotation must be a proper 3x3 rotation matrix"),
        ("woodified rotation str", lambda: _woodified(rotation="abc"),
         r"rotation must be a proper 3x3 rotation matrix \(orthonormal, det \+1\); got 'abc'"),
        ("woodified NaN rotation", lambda: _woodified(rotation=np.full((3, 3), np.nan)), "rotation must be a proper 3x3"),
        ("placed origin str", lambda: w.PlacedField(fld, "abc"), "origin_mm must be a 3-vector .*got 'abc'"),
        ("evaluate a field of the wrong count", lambda: w.evaluate(lambda p: np.zeros(5), pts),
         r"field must return one growth time per point, \(n,\) = \(2,\); it returned shape \(5,\)"),
        ("evaluate a field of text", lambda: w.evaluate(lambda p: "a", pts),
         "field must return one growth time per point.*returned something that is not numbers"),
        ("wood normals str", lambda: w.Wood(fld).color(pts, "b"), r"normals must be real numbers with the shape of points_mm \(2, 3\); got 'b'"),
        ("synth faces str !", lambda: w.synth_block(fld, (20, 20, 20), face_px=16, faces="top"),
         r"faces must be a list of face names; got the string 'top'; pass \['top'\]"),
        ("synth face_px past the face limit", lambda: w.synth_block(fld, (20, 20, 20), face_px=10**7),
         "a face image of 10000000 px a side .* more than the limit MAX_FACE_PX = 1.638e\\+04 px a side; lower face_px or px_per_mm; "
         "if this is intended, raise the limit with WOODCAM_MAX_FACE_PX="),
        ("synth px_per_mm past the face limit", lambda: w.synth_block(fld, (20, 20, 20), px_per_mm=1e7),
         r"a face image of 200000000 px a side \(1e\+07 px/mm on a 20 mm block\) needs .*MAX_FACE_PX"),
        ("synth px_per_mm str", lambda: w.synth_block(fld, (20, 20, 20), px_per_mm="2"), "px_per_mm must be > 0; got '2'"),
        ("woodify brush of 5", lambda: _woodify(brushes=[5]), r"brushes must be a list of woodcam.woodify.Brush; got \[5\]"),
        ("woodified speed None", lambda: w.WoodifiedField(np.zeros((3, 3, 3)), (0, 0, 0), 1.0, None, 1.0),
         "speed must be a GrowthSpeed; got NoneType"),
        ("woodified spacing 0 !", lambda: w.WoodifiedField(np.zeros((3, 3, 3)), (0, 0, 0), 0.0, w.GrowthSpeed(1, 1), 1.0),
         "spacing_mm must be a finite number > 0; got 0.0"),
        ("woodified NaN years_final *", lambda: _woodified(years_final=np.nan),
         "years_final must be a finite number >= 0; got nan; the last simulated year"),
        ("woodified str years_final", lambda: _woodified(years_final="a"), "years_final must be a finite number >= 0; got 'a'"),
        ("woodified NaN block origin *", lambda: _woodified(block_origin_mm=(np.nan, 0, 0)),
         r"block_origin_mm must be three finite numbers \(x, y, z\); got \(nan, 0, 0\)"),
        ("woodified str block origin", lambda: _woodified(block_origin_mm="abc"), "block_origin_mm must be three finite numbers"),
        ("woodified zero stem axis", lambda: _woodified(stem_axis=(0, 0, 0)),
         r"stem_axis must be a non-zero direction; got \(0, 0, 0\)"),
        ("woodified NaN stem axis *", lambda: _woodified(stem_axis=(np.nan, 0, 1)), "stem_axis must be three finite numbers"),
        ("woodified NaN block size *", lambda: _woodified(block_size_mm=(np.nan, 1, 1)),
         r"block_size_mm must be three finite sizes > 0 \(W, D, H mm\); got \(nan, 1, 1\)"),
        ("woodified obstacles of another grid *", lambda: _woodified(obstacle_sdf_mm=np.zeros((2, 2, 2))),
         r"obstacle_sdf_mm must be the signed distances on the arrival grid's nodes, shape \(3, 3, 3\); got shape \(2, 2, 2\)"),
        ("knotted params dict", lambda: w.KnottedLogField(_small_log(), params={}), "params must be a KnotParams or None; got dict"),
        ("colormap knots dict", lambda: w.ColorMapAppearance(knots={}), "knots must be a KnotShading; got dict"),
        ("mokume_veneers size 0", lambda: w.mokume_veneers(_scan_file().parent, size_mm=0), "size_mm must be a finite number > 0; got 0"),
        ("mokume_veneers NaN size !", lambda: w.mokume_veneers(_scan_file().parent, size_mm=np.nan),
         "size_mm must be a finite number > 0; got nan"),
        ("mokume_veneers None", lambda: w.mokume_veneers(None), "mokume_veneers: folder must be a file path .*got None"),
        ("read_mokume size -1", lambda: w.read_mokume(_mokume_folder(), size_mm=-1),
         r"size_mm must be three positive finite lengths \(W, D, H\) in mm; got -1"),
        ("read_mokume size complex", lambda: w.read_mokume(_mokume_folder(), size_mm=1 + 1j), r"size_mm must be three .*got \(1\+1j\)"),
        ("woodification origins NaN", lambda: _woodify().origins([[np.nan, 0.0, 6.0]]),
         r"points_mm must be finite; point 0 is \[nan, 0.0, 6.0\]"),
        ("woodification origins (n, 2)", lambda: _woodify().origins(np.zeros((2, 2))),
         r"points_mm must have shape \(n, 3\) in mm; got shape \(2, 2\)"),
        ("evidence uncertainty NaN *", lambda: _evidence_fit(1).uncertainty_years([[np.nan, 1.0, 1.0]]),
         r"points_mm must be finite; point 0 is \[nan, 1.0, 1.0\]"),
        ("evidence uncertainty (n, 2) *", lambda: _evidence_fit(1).uncertainty_years(np.zeros((2, 2))),
         r"points_mm must have shape \(n, 3\) in mm; got shape \(2, 2\)"),
        ("evidence uncertainty str", lambda: _evidence_fit(2).uncertainty_years("a"),
         "points_mm must be real numbers, shape \\(n, 3\\) in mm; got 'a'"),
    ]


def _evidence_fit(accepted: int):
    """An EvidenceFit of two built-in fields with ``accepted`` (1 or 2) hypotheses accepted
    (one: the uncertainty is 0 everywhere without evaluating the fields)."""
    import woodcam as w

    a, b = w.builtin_block("flat-sawn").field, w.builtin_block("rift").field
    return w.EvidenceFit(a, "a", {}, False, accepted < 2, ["a", "b"][:accepted], "", {"a": a, "b": b})


def _tmp():
    """A new empty temporary folder of this process."""
    import tempfile
    from pathlib import Path

    return Path(tempfile.mkdtemp(prefix="woodcam-doors-"))


def _woodified(**kw):
    """A WoodifiedField of a 3 x 3 x 3 arrival grid, 1 mm apart, ``kw`` changed."""
    import numpy as np

    import woodcam as w

    args = dict(years_final=1.0) | kw
    return w.WoodifiedField(np.arange(27.0).reshape(3, 3, 3), (0, 0, 0), 1.0, w.GrowthSpeed(10, 1), **args)


def _woodify(**kw):
    """woodify() of a 5 mm ball, 2 years, on a 16-node grid (a fraction of a second)."""
    import trimesh

    from woodcam.woodify import woodify

    return woodify(trimesh.creation.icosphere(radius=5), 2.0, resolution=16, **kw)


@functools.lru_cache(maxsize=1)
def _synth():
    """A small synthetic flat-sawn block with its true field (one render)."""
    import woodcam as w

    return w.synth_block(w.builtin_block("flat-sawn").field, (40, 30, 20), face_px=32, seed=0)


@functools.lru_cache(maxsize=1)
def _obs():
    """The labelled ring observations of a small synthetic flat-sawn block (one render)."""
    import woodcam as w
    from woodcam.inference.observations import gather_observations

    return gather_observations(w.synth_block(w.builtin_block("flat-sawn").field, (40, 30, 20), face_px=32, seed=0))


def _photo():
    """A 64 x 64 px RGB noise photo (seeded)."""
    import numpy as np

    return np.random.default_rng(0).integers(0, 255, (64, 64, 3), dtype=np.uint8)


def _cube():
    import trimesh

    return trimesh.creation.box((10, 10, 10))


def _stock():
    import woodcam as w

    return w.open_stock("builtin:flat-sawn")


def _target():
    """A 20 x 20 px RGB target in [0, 1] (seeded noise)."""
    import numpy as np

    return np.random.default_rng(1).random((20, 20, 3))


def _veneer():
    """A 80 x 80 px sheet at 4 px/mm (seeded noise): 20 x 20 mm, enough wood for the 8 x 8 mm
    panel of :func:`_small_params` with each piece's overlap and kerf, so a valid job is not
    warned of too little wood."""
    import numpy as np

    from woodcam.parquetry import Veneer

    rgb = np.random.default_rng(0).random((80, 80, 3)).astype(np.float32)
    return Veneer("v", rgb, 4.0, np.ones((80, 80), bool), "noise")


@functools.lru_cache(maxsize=1)
def _parquetry_run():
    """A run of one 20 x 20 px target from one noise sheet (small parameters)."""
    import woodcam as w

    return w.build_parquetry(_target(), [_veneer()], _small_params())


def _small_params():
    import woodcam as w

    return w.ParquetryParams(image_size_mm=10, patch_mm=4, px_per_mm=2, n_rot=2, min_piece_mm=1,
                             tool_diameter_mm=0.5)


def _scan_file():
    """A 40 x 40 px PNG scan in a temporary folder of this process."""
    import tempfile
    from pathlib import Path

    import numpy as np
    from PIL import Image

    path = Path(tempfile.mkdtemp(prefix="woodcam-doors-")) / "scan.png"
    Image.fromarray(np.random.default_rng(0).integers(0, 255, (40, 40, 3), dtype=np.uint8)).save(path)
    return path


def _mokume_folder():
    """A Mokume sample folder of one face: A_col.png, the 40 x 40 px scan of :func:`_scan_file`."""
    scan = _scan_file()
    scan.rename(scan.with_name("A_col.png"))
    return scan.parent


def _baked_box():
    """A 10 mm cube baked grey at 1 texel/mm: what export_glb and export_obj take."""
    import numpy as np
    import trimesh

    import woodcam as w

    class Grey:
        def color(self, points_mm, normals):
            return np.full((len(points_mm), 3), 0.5)

    return w.bake(trimesh.creation.box((10, 10, 10)), Grey(), texels_per_mm=1).mesh


def _small_log():
    """A 200 mm generated spruce log (knots and all): the input of KnottedLogField."""
    import woodcam as w

    return w.generate_log(1, length_mm=200).to_skeleton()


@pytest.mark.parametrize("name, call, match", _library_door_sweep(), ids=lambda v: v if isinstance(v, str) else "")
def test_library_doors_refuse_a_users_mistakes_naming_the_argument(name, call, match):
    with pytest.raises(WoodcamError, match=match):
        call()


def _library_door_valid_calls():
    """``(id, call, check)``: the valid call beside each refused one still works (ints where
    floats, numpy scalars, lists for arrays), checked against a known answer."""
    import numpy as np

    import woodcam as w

    fld = w.builtin_block("flat-sawn").field
    pts = np.array([[5.0, 5.0, 5.0], [1.0, 2.0, 3.0]])
    whole = fld(pts)
    return [
        ("evaluate in batches of 1", lambda: w.evaluate(fld, pts, batch=1), lambda r: np.array_equal(r, whole)),
        ("evaluate numpy batch", lambda: w.evaluate(fld, pts.tolist(), batch=np.int64(5), workers=np.int32(1)),
         lambda r: np.array_equal(r, whole)),
        ("pixel_to_block of block_to_pixel", lambda: w.pixel_to_block(
            "top", *w.block_to_pixel("top", [[2.5, 7.5, 10]], (10, 20), (10, 10, 10)), (10, 20), [10, 10, 10]),
         lambda r: np.allclose(r, [[2.5, 7.5, 10.0]])),
        ("pixel_to_block one row many cols", lambda: w.pixel_to_block("top", 0, [0, 19], (10, 20), (10, 10, 10)),
         lambda r: np.allclose(r, [[0.25, 9.5, 10.0], [9.75, 9.5, 10.0]])),
        ("radial of ints", lambda: w.RadialScalingField(w.LogFrame(), ring_width_mm=2, age_offset_years=np.float32(1))(
            [[3, 4, 0]]), lambda r: np.allclose(r, [1 + 5 / 2])),
        ("grid of lists", lambda: w.GridField(np.arange(27.0).reshape(3, 3, 3).tolist(), [0, 0, 0], 1,
                                              interpolation="linear", layers={"u": np.ones((3, 3, 3))})([[1, 1, 1]]),
         lambda r: np.allclose(r, [13.0])),
        ("wood of a numpy seed and threads", lambda: w.Wood(fld, w.ColorMapAppearance(seed=np.int64(3)), threads=np.int32(2))
         .color(pts, [[0, 0, 1]] * 2), lambda r: np.array_equal(r, w.Wood(fld, w.ColorMapAppearance(seed=3), threads=1)
                                                                  .color(pts, [[0, 0, 1]] * 2))),
        ("cut_block of ints", lambda: w.cut_block(lambda p: np.hypot(p[:, 0], p[:, 1]), (20, 20, 20), "quarter-sawn",
                                                  distance_mm=40, azimuth_deg=np.float32(0), tilt_deg=0)([[10, 10, 10]]),
         lambda r: np.allclose(r, [40.0])),
        ("synth of a numpy seed and a generator", lambda: w.synth_block(fld, [16, 16, 16], face_px=16, seed=np.int64(2),
                                                                     rng=np.random.default_rng(2), meta={"k": 1}),
         lambda b: b.size_mm == (16.0, 16.0, 16.0) and b.faces["front"].photo.shape == (16, 16, 3) and b.meta["k"] == 1),
        ("brush of ints", lambda: w.Brush([0, 0, 0], 5, gain=2, strength=np.float32(0.5)).weight([[5, 0, 0]]),
         lambda r: np.allclose(r, [np.exp(-0.5)])),
        ("growth speed of ints", lambda: w.GrowthSpeed(20, 30, shape=2, eccentricity=0).velocity_mm, lambda r: r == 20),
        ("generate_log of a numpy heightmap shape", lambda: w.generate_log(1, length_mm=200, heightmap_shape=(
            np.int64(41), 360)).heightmap_mm.shape, lambda r: r == (41, 360)),
        ("knotted of ints", lambda: w.KnottedLogField(_small_log(), ring_width_mm=2, surface_smoothing=[1, 1], chunk=64,
                                                      table_samples=np.int64(32))([[0, 0, 50]]),
         lambda r: r.shape == (1,) and np.isfinite(r).all()),
        ("parquetry of a uint8 target and numpy params", lambda: w.build_parquetry(
            (_target() * 255).astype(np.uint8), [_veneer()], w.ParquetryParams(
                image_size_mm=np.float32(10), patch_mm=4, px_per_mm=2, n_rot=np.int64(2), min_piece_mm=1,
                tool_diameter_mm=0.5, single_use=np.bool_(True))),
         lambda r: r.panels[0].target_rgb.shape == (16, 16, 3) and type(r.params.n_rot) is int
         and type(r.params.image_size_mm) is float and r.params.single_use is True
         and np.allclose(r.panels[0].target_rgb, w.build_parquetry((_target() * 255).astype(np.uint8) / 255.0, [_veneer()],
                                                            _small_params()).panels[0].target_rgb)),
        ("slice of ints and a list size", lambda: w.slice_veneers(_stock(), np.int64(2), [10, 5], px_per_mm=1,
                                                                  start_mm=40, supersample=np.int32(1)),
         lambda r: len(r) == 2 and r[0].rgb.shape == (5, 10, 3)),
        ("detect_rings of a list wavelength range", lambda: w.detect_rings(_photo(), px_per_mm=5, wavelength_range_px=[4, 20]),
         lambda r: r.ring_map.shape == (64, 64)),
        ("load_part fills a report", lambda: (lambda rep: (w.load_part(_cube(), report=rep), rep)[1])({}),
         lambda rep: isinstance(rep, dict) and len(rep) > 0),
        ("fit_stem of numpy ints and a list size", lambda: w.fit_stem(
            _obs(), [40, 30, 20], K=np.int64(2), n_search=np.int32(60), n_fit=60, n_starts=1, n_final=1, seed=np.int64(0),
            history=False)(np.array([[20.0, 15.0, 10.0]])), lambda r: r.shape == (1,) and np.isfinite(r).all()),
        ("evaluate_fit of a field against itself", lambda: w.evaluate_fit(fld, fld, [40, 30, 20], pixel_mm=1)[0],
         lambda summary: summary["matched_1"] == 100.0),
        ("scene options of numpy numbers", lambda: w.SceneOptions(resolution_mm=np.float32(0.5), max_samples=np.int64(1000)),
         lambda o: o.resolution_mm == 0.5 and o.max_samples == 1000 and o.samples_cap(True) == 1000),
        ("face of a uint8 photo and a float ring map", lambda: w.Face("top", [8, 8], photo=np.full((8, 8, 3), 200, np.uint8),
                                                                     ring_map=np.full((8, 8), 0.5, np.float32), extras={"k": 1}),
         lambda f: f.shape == (8, 8) and f.has_rings and f.photo.dtype == np.uint8),
        ("arf of a list", lambda: w.arf([0.5, 2.25]), lambda r: np.allclose(r, [0.25, 0.0625])),
        ("load_scan of a list mask", lambda: w.load_scan(_scan_file(), px_per_mm=4, mask=[[i < 20] * 40 for i in range(40)]).mask,
         lambda m: m.shape == (40, 40) and m[:20].all() and not m[20:].any()),
        ("woodify of one brush", lambda: _woodify(brushes=w.Brush((0, 0, 5), 2, gain=2)).field(np.array([[0.0, 0.0, 0.0]])),
         lambda r: r.shape == (1,) and np.isfinite(r).all()),
        ("read_gcode of a list start", lambda: w.read_gcode("G1 X1 F100\n", start_mm=[0, 0, 5]).start_mm.tolist(),
         lambda r: r == [[0.0, 0.0, 5.0]]),
    ]


@pytest.mark.parametrize("name, call, check", _library_door_valid_calls(), ids=lambda v: v if isinstance(v, str) else "")
def test_library_doors_still_take_a_valid_call(name, call, check):
    assert check(call())


def test_a_path_door_takes_a_str_and_a_path_like(tmp_path):
    """The path doors refuse None and numbers (above) but take str and any os.PathLike: a log
    written and read back is the same log; a G-code file given as a PathLike is read as a file."""
    import os

    import numpy as np

    import woodcam as w

    class Where(os.PathLike):
        def __init__(self, p):
            self.p = p

        def __fspath__(self):
            return str(self.p)

    log = _small_log()
    back = w.read_log(w.write_log(log, str(tmp_path / "l.json")))
    assert np.array_equal(back.radii_mm, log.radii_mm) and np.array_equal(back.pith_z_mm, log.pith_z_mm)
    (tmp_path / "p.nc").write_text("G1 X3 F100\n")
    prog = w.read_gcode(Where(tmp_path / "p.nc"))
    assert prog.source == str(tmp_path / "p.nc") and prog.end_mm[-1, 0] == 3.0


def test_simulate_takes_a_list_heightmap_and_leaves_the_callers_array_alone():
    """The valid call beside the refused ones: a flat 3 mm end mill 1 mm deep along Y = 5 mm of a
    10 mm stock cuts the cells within 1.5 mm of it to 9 mm; the stock given as a list (the
    same heights) gives the same cut, and a float array given is not cut in place."""
    import numpy as np

    import woodcam as w

    prog = w.read_gcode("G0 X-3 Y5 Z2\nG1 Z-1 F100\nG1 X13\n")  # Z 0: the stock top
    tool = w.parse_tool_spec("flat:3")
    fresh = w.simulate(prog, tool, (10, 10, 10), resolution_mm=0.5).heightmap
    ys = (np.arange(20) + 0.5) * 0.5
    assert np.array_equal(fresh[np.abs(ys - 5) < 1.4], np.full(((np.abs(ys - 5) < 1.4).sum(), 20), 9.0))
    assert np.array_equal(fresh[np.abs(ys - 5) > 1.6], np.full(((np.abs(ys - 5) > 1.6).sum(), 20), 10.0))
    stock = np.full((20, 20), 10.0)
    again = w.simulate(prog, {0: tool}, (10, 10, 10), resolution_mm=0.5, initial_heightmap=stock.tolist()).heightmap
    assert np.array_equal(again, fresh)
    w.simulate(prog, tool, (10, 10, 10), resolution_mm=0.5, initial_heightmap=stock)
    assert np.all(stock == 10.0)


def test_a_block_and_a_job_written_to_a_path_like_read_back(tmp_path):
    """The valid calls beside the refused ones: write_block/read_block and write_job/read_job
    round-trip through a pathlib.Path and a str."""
    import numpy as np

    import woodcam as w
    from woodcam.parquetry import ParquetryJob

    block = w.synth_block(w.builtin_block("rift").field, (16, 12, 8), face_px=16, seed=0)
    back = w.read_block(w.write_block(block, tmp_path / "b").parent)
    assert back.size_mm == (16.0, 12.0, 8.0)
    assert np.array_equal(back.faces["top"].photo, block.faces["top"].photo)
    job = ParquetryJob([], [], [], [], _small_params())
    again = w.read_job(str(w.write_job(job, str(tmp_path / "j.json"))))
    assert again.params.patch_mm == 4 and again.params.n_rot == 2


def test_a_tool_table_names_the_key_a_tool_type_needs(tmp_path):
    """A vbit without angle_deg was read as NaN and refused as "VBit: angle_deg ... got nan" (a
    value never written); the valid table beside it reads as the tools it describes."""
    import woodcam as w

    (tmp_path / "t.toml").write_text('[tools.1]\ntype = "vbit"\ndiameter_mm = 6\n')
    with pytest.raises(WoodcamError, match=r"\[tools.1\] \(type 'vbit'\) needs \['angle_deg'\]"):
        w.load_tool_table(tmp_path / "t.toml")
    (tmp_path / "t.toml").write_text('[tools.1]\ntype = "vbit"\ndiameter_mm = 6\nangle_deg = 90\n'
                                     '[tools.2]\ntype = "bull"\ndiameter_mm = 6\ncorner_radius_mm = 1\n')
    tools = w.load_tool_table(str(tmp_path / "t.toml"))
    assert tools[1].spec() == "vbit:90:6" and tools[2].spec() == w.parse_tool_spec("bull:6:1").spec()


def _bool_doors():
    """``(id, call with the bool option given as "false")``: every bool option of the public API.
    Each took the string as its truth value (True) without a word; read_block's allow_outside
    so read files outside the block folder."""
    import numpy as np

    import woodcam as w

    fld = w.builtin_block("flat-sawn").field
    pts = np.array([[5.0, 5.0, 5.0]])
    no = "false"
    return [
        ("KnottedLogField.evaluate directions", lambda: w.KnottedLogField(_small_log()).evaluate([[0, 0, 50]], directions=no)),
        ("WoodifiedField.evaluate directions", lambda: _woodify().field.evaluate(pts * 0, directions=no)),
        ("bake progress", lambda: w.bake(_cube(), w.Wood(fld), texels_per_mm=1, progress=no)),
        ("bench_report progress", lambda: w.bench_report("no-run", "no-out", progress=no)),
        ("benchmark confidence", lambda: w.benchmark([], confidence=no)),
        ("build_parquetry progress", lambda: w.build_parquetry(_target(), [_veneer()], _small_params(), progress=no)),
        ("build_parquetry seams", lambda: w.build_parquetry(_target(), [_veneer()], _small_params(), seams=no)),
        ("build_parquetry repair", lambda: w.build_parquetry(_target(), [_veneer()], _small_params(), repair=no)),
        ("detect_rings curved", lambda: w.detect_rings(_photo(), px_per_mm=5, curved=no)),
        ("evaluate_fit keep_lines", lambda: w.evaluate_fit(fld, fld, (40, 30, 20), keep_lines=no)),
        ("fit_block baked", lambda: w.fit_block(w.Block((10, 10, 10)), "radial", baked=no)),
        ("fit_block knot_bend", lambda: w.fit_block(w.Block((10, 10, 10)), "radial", knot_bend=no)),
        ("fit_block knot_cones", lambda: w.fit_block(w.Block((10, 10, 10)), "radial", knot_cones=no)),
        ("fit_block residual", lambda: w.fit_block(w.Block((10, 10, 10)), "radial", residual=no)),
        ("fit_evidence warn", lambda: w.fit_evidence(_obs(), (40, 30, 20), warn=no)),
        ("fit_evidence residual", lambda: w.fit_evidence(_obs(), (40, 30, 20), residual=no)),
        ("fit_stem history", lambda: w.fit_stem(_obs(), (40, 30, 20), history=no)),
        ("fit_stem outward", lambda: w.fit_stem(_obs(), (40, 30, 20), outward=no)),
        ("open_stock species_given", lambda: w.open_stock("builtin:flat-sawn", species_given=no)),
        ("preview_mesh obj", lambda: w.preview_mesh(_cube(), _stock(), "p.glb", obj=no)),
        ("preview_mesh progress", lambda: w.preview_mesh(_cube(), _stock(), "p.glb", progress=no)),
        ("preview_mesh part_report", lambda: w.preview_mesh(_cube(), _stock(), "p.glb", part_report=no)),
        ("preview_part obj", lambda: w.preview_part(_cube(), _stock(), "p.glb", obj=no)),
        ("preview_part progress", lambda: w.preview_part(_cube(), _stock(), "p.glb", progress=no)),
        ("read_block allow_outside", lambda: w.read_block("no-block", allow_outside=no)),
        ("read_gran1 centre", lambda: w.read_gran1("no-trees", centre=no)),
        ("run_many progress", lambda: w.run_many(str, ["a"], "no-runs", progress=no)),
        ("score_block keep_lines", lambda: w.score_block(0, 0, keep_lines=no)),
        ("score_block knot_bend", lambda: w.score_block(0, 0, knot_bend=no)),
        ("score_block knot_cones", lambda: w.score_block(0, 0, knot_cones=no)),
        ("score_block residual", lambda: w.score_block(0, 0, residual=no)),
        ("simulate progress", lambda: w.simulate(w.read_gcode("G1 X5 F100\n"), w.parse_tool_spec("flat:3"), (10, 10, 10),
                                                 progress=no)),
        ("simulate track_lines", lambda: w.simulate(w.read_gcode("G1 X5 F100\n"), w.parse_tool_spec("flat:3"),
                                                    (10, 10, 10), track_lines=no)),
        ("slice_veneers progress", lambda: w.slice_veneers(_stock(), 2, (10, 10), px_per_mm=1, progress=no)),
        ("slice_veneers adaptive", lambda: w.slice_veneers(_stock(), 2, (10, 10), px_per_mm=1, adaptive=no)),
        ("synth_block knot_masks", lambda: w.synth_block(fld, (20, 20, 20), face_px=16, knot_masks=no)),
        ("write_block overwrite", lambda: w.write_block(w.Block((10, 10, 10)), "no-block", overwrite=no)),
        ("write_parquetry progress", lambda: w.write_parquetry(_small_run(), "no-out", progress=no)),
        ("SceneOptions cut_plane", lambda: w.SceneOptions(cut_plane=no)),
        ("ParquetryParams single_use", lambda: w.ParquetryParams(single_use=no).check()),
    ]


@functools.lru_cache(maxsize=1)
def _small_run():
    import woodcam as w

    return w.build_parquetry(_target(), [_veneer()], _small_params())


@pytest.mark.parametrize("name, call", _bool_doors(), ids=lambda v: v if isinstance(v, str) else "")
def test_bool_options_refuse_a_truthy_string(name, call, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # a door that let the call through would write here
    option = name.split()[-1]
    with pytest.raises(WoodcamError, match=rf"{option} must be (True or False|true or false); got 'false'"):
        call()
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # refused before anything was made


def test_bool_options_take_numpy_bools():
    """The valid call beside the refused ones: a numpy bool is a bool (a mask's .any(), a
    table's column), and the option does what it says."""
    import numpy as np

    import woodcam as w

    assert w.SceneOptions(cut_plane=np.bool_(False)).cut_plane is False
    out = w.KnottedLogField(_small_log()).evaluate([[0, 0, 50]], directions=np.bool_(True))
    assert out["direction"].shape == (1, 3)
    assert "direction" not in w.KnottedLogField(_small_log()).evaluate([[0, 0, 50]], directions=False)


def test_wood_color_refuses_normals_that_are_no_direction():
    """Wood.color with a NaN, inf or zero normal returned colours (eq. 10's equal blend of the
    three axes' colourings) without a word; wood_colors, the seam of bake and view, did for any
    wood. A normal of any length > 0 is a direction: the same colour as the unit one."""
    import numpy as np

    import woodcam as w
    from woodcam.appearance.wood import wood_colors

    wood = w.Wood(w.builtin_block("flat-sawn").field)
    pts = np.array([[5.0, 5.0, 5.0], [1.0, 2.0, 3.0]])
    for bad, said in (([[np.nan, 0, 1], [0, 0, 1]], r"normal 0 is \[nan, 0.0, 1.0\] \(1 of 2"),
                      ([[0, 0, 1], [0, 0, 0]], r"normal 1 is \[0.0, 0.0, 0.0\] \(1 of 2"),
                      ([[0, 0, 1e-30]] * 2, r"normal 0 is .*\(2 of 2 are NaN/inf or shorter than 1e-06\)"),
                      ([[np.inf, 0, 0], [0, 0, 1]], r"normal 0 is \[inf, 0.0, 0.0\]")):
        with pytest.raises(WoodcamError, match="normals must be finite, non-zero directions .*" + said):
            wood.color(pts, bad)

    class Grey:
        def color(self, points_mm, normals):
            return np.full((len(points_mm), 3), 0.5)

    with pytest.raises(WoodcamError, match=r"normals must be finite, non-zero directions .*normal 0 is \[0.0, 0.0, 0.0\]"):
        wood_colors(Grey(), pts, (0, 0, 0))
    assert np.array_equal(wood.color(pts, [[0, 0, 5], [3, 0, 0]]), wood.color(pts, [[0, 0, 1], [1, 0, 0]]))
    assert np.array_equal(wood_colors(wood, pts, (0, 0, 1)), wood.color(pts, [[0, 0, 1]] * 2))


def _bad_woods():
    """User woods breaking the colour contract: 0..255 colours, NaN, one value a point."""
    import numpy as np

    class Wood255:
        def color(self, points_mm, normals):
            return np.full((len(points_mm), 3), 200.0)

    class WoodNaN:
        def color(self, points_mm, normals):
            return np.full((len(points_mm), 3), np.nan)

    class WoodFlat:
        def color(self, points_mm, normals):
            return np.zeros(len(points_mm))

    return [(Wood255(), r"wood\.color must return rgb in \[0, 1\]; got values in \[0, 200\]"),
            (WoodNaN(), r"wood\.color returned non-finite colours"),
            (WoodFlat(), r"wood\.color must return rgb of shape \(n, 3\) = \(\d+, 3\); got \(\d+,\)")]


def _colour_consumers():
    """Every consumer of a wood outside bake/view/export, each given ``wood``: the G-code
    window's stock, the placement panels, the review's colour volumes, veneers, synthetic
    photos, the appearance evaluation's pictures."""
    import tempfile
    from pathlib import Path

    import numpy as np

    def scrub(wood):
        import pyvista as pv

        from woodcam.view.scrub import _stock_polydata

        return _stock_polydata(pv, np.full((8, 12), 20.0), (60.0, 40.0, 20.0), wood)

    def compare(wood):
        from woodcam.view.compare import render_side_by_side

        png = Path(tempfile.mkdtemp(prefix="woodcam-doors-")) / "panels.png"
        box = _cube()
        box.apply_translation((10.0, 10.0, 10.0))
        return render_side_by_side([box], [wood], (20.0, 20.0, 20.0), ["box"], png, panel_px=48)

    def review(wood):
        from woodcam.review import colour_volume

        return colour_volume(wood, (20.0, 20.0, 20.0), "x", 5.0)

    def veneers(wood):
        import woodcam as w

        return w.slice_veneers(w.Stock("mine", (20.0, 20.0, 20.0), wood), 1, (10.0, 10.0), px_per_mm=1.0)

    def synth(wood):
        import woodcam as w

        cut = w.cut_block(lambda p: np.hypot(p[:, 0], p[:, 1]) / 2.0, (20, 20, 20), "rift")
        return w.synth_block(cut, (20, 20, 20), face_px=16, seed=1, wood=wood)

    def sphere(wood):
        from woodcam.appearance.evaluation import render_sphere

        return render_sphere(wood, (20.0, 20.0, 20.0), px=16)

    def plane(wood):
        from woodcam.appearance.evaluation import render_plane

        return render_plane(wood, (20.0, 20.0, 20.0), px=16)

    return {f.__name__: f for f in (scrub, compare, review, veneers, synth, sphere, plane)}


@pytest.mark.parametrize("bad", range(3), ids=["0..255", "nan", "flat"])
@pytest.mark.parametrize("consumer", ["scrub", "compare", "review", "veneers", "synth", "sphere", "plane"])
def test_every_consumer_of_a_users_wood_checks_its_colours(consumer, bad):
    """The G-code window, the placement panels, the review page, veneers, synthetic photos and
    the evaluation pictures called wood.color directly, not the checked seam wood_colors of
    bake/view/export: a user's wood's 0..255 colours were drawn white, NaN black (or numpy's
    cast warning), a wrong shape was numpy's or pyvista's ValueError. Each now refuses as
    wood_colors does."""
    if consumer in ("scrub", "compare"):
        pytest.importorskip("pyvista")
    wood, said = _bad_woods()[bad]
    with pytest.raises(WoodcamError, match=said):
        _colour_consumers()[consumer](wood)


def test_a_smooth_bake_where_vertex_normals_cancel_takes_the_triangles_normal():
    """Vertex normals that cancel (the two sides of a fin share vertices) interpolate to no
    direction, which the wood now refuses: the smooth bake takes the triangle's own normal
    there, so it paints what the face bake paints."""
    import numpy as np
    import trimesh

    import woodcam as w

    wood = w.Wood(w.builtin_block("flat-sawn").field)
    fin = trimesh.Trimesh(np.array([[5, 5, 5], [15, 5, 5], [5, 15, 5]], float), [[0, 1, 2], [0, 2, 1]], process=False)
    assert np.allclose(fin.vertex_normals, 0)
    smooth = w.bake(fin, wood, texels_per_mm=2, normals="smooth").atlas
    face = w.bake(fin, wood, texels_per_mm=2, normals="face").atlas
    assert smooth.shape == face.shape and np.array_equal(smooth, face)


@pytest.mark.parametrize("kw, said", [
    (dict(rgb=np.zeros((10, 10))), r"rgb must be an \(h, w, 3\) RGB image; got shape \(10, 10\)"),
    (dict(rgb="abc"), r"rgb must be an \(h, w, 3\) RGB image; got 'abc'"),
    (dict(rgb=np.zeros((0, 0, 3))), r"rgb must be an \(h, w, 3\) RGB image; got shape \(0, 0, 3\)"),
    (dict(rgb=np.full((10, 10, 3), 200.0)), r"rgb must hold finite values in \[0, 1\]; got range \[200, 200\]; divide"),
    (dict(rgb=np.full((10, 10, 3), np.nan)), r"rgb must hold finite values in \[0, 1\]; got range \[nan, nan\]"),
    (dict(px_per_mm=0), r"veneer 'v': px_per_mm must be a finite number > 0; got 0"),
    (dict(px_per_mm="4"), r"veneer 'v': px_per_mm must be a finite number > 0; got '4'"),
    (dict(mask=np.ones((5, 5), bool)), r"the mask must have the image's size 10x10 px; got 5x5"),
    (dict(mask=np.ones(100, bool)), r"the mask must have the image's size 10x10 px; got shape \(100,\)"),
    (dict(mask=np.full((10, 10), np.nan)), r"mask must be an \(h, w\) bool array .*got dtype float64"),
    (dict(id=""), "veneer id must be a name"),
    (dict(id="a/b"), "veneer id must be one file-name part"),
    (dict(source=5), "source must be a string .*got 5"),
    (dict(sheet_mm=(10, -1)), r"sheet_mm must be \(width, height\) > 0 mm; got \(10.0, -1.0\)"),
    (dict(sheet_mm=(10,)), r"sheet_mm must be 2 finite numbers; got \(10,\)"),
])
def test_a_veneer_is_checked_when_made(kw, said):
    """Veneer(...) of a user's own arrays was not checked (only the loaders checked theirs): a grey
    (h, w) image, 0..255 floats, NaN, a mask of another size or px_per_mm=0 reached the matcher
    as OpenCV's or numpy's bare errors, or ran on colours out of range."""
    import numpy as np

    from woodcam.parquetry import Veneer

    args = dict(id="v", rgb=np.full((10, 10, 3), 0.5, np.float32), px_per_mm=4.0, mask=np.ones((10, 10), bool)) | kw
    with pytest.raises(WoodcamError, match=said):
        Veneer(**args)


def test_a_veneer_of_lists_and_numbers_is_made_as_arrays():
    """The valid call beside the refused ones: lists and a 0/1 mask are taken as the arrays they
    are, a float32 sheet is not copied."""
    import numpy as np

    from woodcam.parquetry import Veneer

    rgb = np.full((4, 6, 3), 0.25, np.float32)
    v = Veneer("v", rgb, np.int64(2), [[1, 0, 1, 1, 1, 1]] * 4, "mine", [3, 2])
    assert v.rgb is rgb and v.mask.dtype == bool and v.mask.sum() == 20 and v.px_per_mm == 2.0
    assert v.size_mm == (3.0, 2.0) and Veneer("w", rgb.tolist(), 2, np.ones((4, 6), bool)).rgb.dtype == np.float32


def test_brush_weight_and_direction_are_checked():
    """Brush.weight took one point (3,) as a scalar, broadcast an (n, 2) array, gave NaN weights
    for NaN points and numpy's bare ValueError for 'a'; direction (inf, 0, 0) was kept as
    (nan, nan, nan). The valid call: exp(-d^2 / 2 r^2) at distance d, a direction made unit."""
    import woodcam as w

    b = w.Brush((0, 0, 0), 5)
    for pts, said in (([1, 2, 3], r"got shape \(3,\)"), ([[1, 2]], r"got shape \(1, 2\)"),
                      ([[np.nan, 0, 0]], r"be finite; point 0 is \[nan, 0.0, 0.0\]"),
                      ("a", "got 'a'")):
        with pytest.raises(WoodcamError, match="points_mm must .*" + said):
            b.weight(pts)
    with pytest.raises(WoodcamError, match=r"brush direction must be three finite numbers .*got \(inf, 0, 0\)"):
        w.Brush((0, 0, 0), 5, direction=(np.inf, 0, 0))
    assert np.allclose(b.weight([[5, 0, 0], [0, 0, 0]]), [np.exp(-0.5), 1.0])
    assert w.Brush((0, 0, 0), 5, direction=(0, 0, 2)).direction == (0.0, 0.0, 1.0)


@pytest.mark.parametrize("normals", ["face", "smooth"])
def test_a_slightly_dirty_mesh_still_bakes(normals):
    """The wood refuses a zero normal; trimesh gives one to an unreferenced vertex and to a
    zero-area triangle. Neither reaches the wood from the bake (a zero-area triangle paints no
    texel, an unreferenced vertex none either): the dirty mesh bakes as the clean one."""
    import numpy as np
    import trimesh

    import woodcam as w

    wood = w.Wood(w.builtin_block("flat-sawn").field)
    box = trimesh.creation.box(extents=(10.0, 10.0, 10.0))
    box.apply_translation((15.0, 15.0, 15.0))
    v, f = np.asarray(box.vertices), np.asarray(box.faces)
    a, b = f[0, 0], f[0, 1]
    dirty = trimesh.Trimesh(np.vstack([v, [(v[a] + v[b]) / 2, [3.0, 3.0, 3.0]]]),
                            np.vstack([f, [[a, 8, b]], f[:1]]), process=False)
    assert (np.linalg.norm(dirty.vertex_normals, axis=1) == 0).sum() == 2
    baked = w.bake(dirty, wood, texels_per_mm=1, normals=normals)
    assert baked.coverage_mask.any() and len(baked.mesh.faces) == len(dirty.faces)


def test_read_gran1_checks_its_arguments_before_seeking_the_shared_data(monkeypatch):
    """read_gran1(centre='false') on a machine without the shared data folder said "the real
    log needs the shared data folder" (the centre was checked only after): the argument's own
    mistake comes first."""
    import woodcam as w
    import woodcam.logs.io

    monkeypatch.setattr(woodcam.logs.io, "shared_data_dir", lambda: None)
    with pytest.raises(WoodcamError, match="read_gran1: centre must be True or False; got 'false'"):
        w.read_gran1(centre="false")
    with pytest.raises(WoodcamError, match="the real log needs the shared data folder"):
        w.read_gran1(centre=False)


def test_read_gran1_reads_its_files_as_every_json_file_is(tmp_path):
    """read_gran1 read its three files with json.loads(read_text()): bad JSON was a bare
    JSONDecodeError, knot rows of 3 numbers a TypeError of from_model, a file given as the folder
    a NotADirectoryError, a NaN in the knots was taken. Now read_json_file and a check of each
    table's form, naming the file; a log of no knots is read."""
    import json

    import woodcam as w

    files = {"Gran_1_pith.json": [[0, 0, 0], [1, 1, 100]], "Gran_1_radii.json": [[50] * 8] * 2,
             "Gran_1_knots.json": []}
    for name, value in files.items():
        (tmp_path / name).write_text(json.dumps(value))
    log = w.read_gran1(tmp_path)
    assert log.knots == () and log.radii_mm.shape == (2, 8)
    np.testing.assert_array_equal(log.pith_xy_mm, [[-1, -1], [0, 0]])
    for name, text, said in (("Gran_1_pith.json", "[[0, 0", "read_gran1: file '.*Gran_1_pith.json' must be valid JSON"),
                             ("Gran_1_knots.json", "[[1, 2, 3]]", r"read_gran1: '.*Gran_1_knots.json' must hold one row "
                                                                  r"\[A, B, .* per knot \(finite numbers\); got shape \(1, 3\)"),
                             ("Gran_1_knots.json", "[[1, 2, 3, 4, 5, 6, 7, 8, NaN]]", "must be valid JSON with finite numbers; non-finite"),
                             ("Gran_1_pith.json", '{"z": 1}', "Gran_1_pith.json' must hold rows .*; got other JSON"),
                             ("Gran_1_pith.json", "[[0, 0, 0]]", r"must hold rows \[x, y, z\] mm of the pith, two or more .*got shape \(1, 3\)")):
        with pytest.raises(WoodcamError, match=said):
            (tmp_path / name).write_text(text)
            w.read_gran1(tmp_path)
        (tmp_path / name).write_text(json.dumps(files[name]))
    with pytest.raises(WoodcamError, match="folder '.*Gran_1_pith.json' lacks Gran_1_pith.json; point it at shared/data/trees"):
        w.read_gran1(tmp_path / "Gran_1_pith.json")


@pytest.mark.parametrize("wood", [None, "oak", 3.0, object()], ids=["None", "str", "number", "object"])
def test_a_stock_built_by_hand_refuses_what_is_no_wood(wood):
    """Stock(...) took any wood: None or a name ('oak') failed far away, in placement an
    AttributeError ('features'), in a drawing a refusal naming no Stock. Now the stock itself
    refuses it naming the argument, the kind given and the fix; a user's wood that is drawn
    (color) or read (features) only is still a stock."""
    import woodcam as w
    from woodcam.stock import Stock

    with pytest.raises(WoodcamError, match=rf"Stock: wood must be a woodcam Wood .*; got {type(wood).__name__}; "
                                           r"pass Wood\(field\) or open the stock with open_stock"):
        Stock("mine", (20.0, 20.0, 20.0), wood)

    class Drawn:
        def color(self, p, n):
            return np.full((len(p), 3), 0.5)

    class Read:
        def features(self, p):
            return {"years": np.zeros(len(p))}

    for ok in (Drawn(), Read(), w.open_stock("builtin:flat-sawn").wood):
        assert Stock("mine", (20.0, 20.0, 20.0), ok).wood is ok


@pytest.mark.parametrize("writer", ["write_block", "leave_one_face_out", "benchmark", "run_many", "write_parquetry"])
def test_an_output_folder_that_is_a_file_is_refused_naming_it(writer, tmp_path):
    """A file given as the folder to write (or a file in its way) was Path.mkdir's bare
    FileExistsError / NotADirectoryError; leave_one_face_out raised it after all its fits."""
    import woodcam as w

    (tmp_path / "photo.png").write_bytes(b"x")
    for out in (tmp_path / "photo.png", tmp_path / "photo.png" / "sub"):
        call = {"write_block": lambda: w.write_block(_synth(), out),
                "leave_one_face_out": lambda: w.leave_one_face_out(_synth(), ["radial"], out_dir=out),
                "benchmark": lambda: w.benchmark([_synth()], ["radial"], out_dir=out),
                "run_many": lambda: w.run_many(str, ["a"], out, progress=False),
                "write_parquetry": lambda: w.write_parquetry(_parquetry_run(), out)}[writer]
        with pytest.raises(WoodcamError, match=f"{writer}: (folder|out_dir): cannot make the folder .*photo.png.* is a file; "
                                               "choose an output folder"):
            call()


@pytest.mark.parametrize("kw, said", [
    ({"size_mm": (np.nan, 1, 1)}, r"size_mm must be three positive finite lengths \(W, D, H\) in mm; got \(nan, 1, 1\)"),
    ({"size_mm": (0, 1, 1)}, r"size_mm must be three positive .*got \(0, 1, 1\)"),
    ({"size_mm": (1, 1)}, r"size_mm must be three positive .*got \(1, 1\)"),
    ({"spec": 5}, r"Stock: spec must be the block spec text \(e.g. 'builtin:flat-sawn'\); got 5"),
    ({"meta": [1]}, "Stock: meta must be a dict of stock metadata; got list"),
    ({"description": None}, "Stock: description must be a string; got None"),
], ids=["NaN size", "zero size", "size of 2", "spec int", "meta list", "description None"])
def test_a_stock_built_by_hand_refuses_a_size_or_text_it_cannot_use(kw, said):
    """Stock(...) took a NaN, zero or (2,) size, a spec that is no text and a meta list without a
    word; each failed (or drew NaN) far away, in the carve, the bake or the GLB's metadata."""
    from woodcam import Stock, Wood, builtin_block

    args = {"spec": "mine", "size_mm": (20.0, 20.0, 20.0), "wood": Wood(builtin_block("flat-sawn").field)} | kw
    with pytest.raises(WoodcamError, match=said):
        Stock(**args)



def _points_doors():
    """``(id, door)``: every public door that takes ``points_mm``, as a function of the points
    (each refuses what :func:`woodcam.fields.base.check_points` refuses)."""
    import numpy as np

    import woodcam as w
    from woodcam.appearance.wood import wood_colors

    fld = w.builtin_block("flat-sawn").field
    wood = w.Wood(fld)
    up = np.array([[0.0, 0.0, 1.0]])
    stem = w.StemField(np.array([20.0, 15.0, 10.0]), np.array([0.0, 0.0, 1.0]), 50.0, np.zeros((2, 3)), 0, 0, 2,
                       np.array([0.5]), np.array([0.0]), 10.0)
    grid = w.GridField.bake(fld, (0, 0, 0), (10, 10, 10), 4)
    return [
        ("evaluate", lambda p: w.evaluate(fld, p)),
        ("grain_direction", lambda p: w.grain_direction(fld, p)),
        ("RadialScalingField", fld),
        ("RadialScalingField.grain_direction", fld.grain_direction),
        ("GridField", grid),
        ("PlacedField", w.PlacedField(fld)),
        ("StemField", stem),
        ("StemField.grain_direction", stem.grain_direction),
        ("StemField.pith_distance_mm", stem.pith_distance_mm),
        ("EvidenceFit", _evidence_fit(2)),
        ("EvidenceFit.uncertainty_years", _evidence_fit(2).uncertainty_years),
        ("WoodifiedField", _woodified()),
        ("WoodifiedField.evaluate", _woodified().evaluate),
        ("WoodifiedField.grain_direction", _woodified().grain_direction),
        ("Wood.years", wood.years),
        ("Wood.arf", wood.arf),
        ("Wood.features", wood.features),
        ("Wood.uncertainty_years", wood.uncertainty_years),
        ("Wood.to_source", wood.to_source),
        ("Wood.color", lambda p: wood.color(p, up)),
        ("wood_colors", lambda p: wood_colors(wood, p, up)),
        ("ColorMapAppearance.color", lambda p: w.ColorMapAppearance().color(fld, p, up)),
        ("Brush.weight", w.Brush((0, 0, 0), 5).weight),
        ("block_to_pixel", lambda p: w.block_to_pixel("top", p, (10, 10), (10, 10, 10))),
        ("LogFrame.to_log", w.LogFrame().to_log),
        ("WoodifiedField.arrival", _woodified().arrival),
        ("WoodifiedField.no_wood", _woodified().no_wood),
        ("WoodifiedField.to_object", _woodified().to_object),
        # built when called: a log and a woodify run are not made while the tests are collected
        ("KnottedLogField", lambda p: w.KnottedLogField(_small_log())(p)),
        ("Woodification.origins", lambda p: _woodify().origins(p)),
    ]


@pytest.mark.parametrize("name, door", _points_doors(), ids=lambda v: v if isinstance(v, str) else "")
@pytest.mark.parametrize("points, said", [
    (np.array([[1.0, 2.0, 3.0]]) + 1j, r"got an array of complex numbers \(dtype complex128, shape \(1, 3\)\); "
                                       r"pass real numbers \(e\.g\. np\.real\(points_mm\)"),
    (np.array([["1", "2", "3"]]), r"got an array of text \(dtype <U1, shape \(1, 3\)\); convert the text"),
    ([[None, 2.0, 3.0]], r"got \[\[None, 2\.0, 3\.0\]\]"),
], ids=["complex", "text", "None"])
def test_every_points_door_refuses_complex_text_and_none(name, door, points, said):
    """Complex points lost their imaginary parts with only numpy's ComplexWarning (an error under
    this suite's filterwarnings, a warning and a wrong answer in a script), text '1' was 1.0 and
    None a NaN point: each door now refuses them as not real numbers, saying what it got."""
    with pytest.raises(WoodcamError, match=r"points_mm must be real numbers, shape \((n|\.\.\.), 3\) in mm; " + said):
        door(points)


def test_complex_normals_and_exact_object_numbers():
    """Complex normals lost their imaginary parts like complex points; an object array of real
    Python numbers (a Fraction, an int past int64) is still numbers."""
    from fractions import Fraction

    import woodcam as w

    wood = w.Wood(w.builtin_block("flat-sawn").field)
    with pytest.raises(WoodcamError, match=r"normals must be real numbers with the shape of points_mm \(1, 3\); "
                                           r"got an array of complex numbers .*np\.real\(normals\)"):
        wood.color([[1.0, 2.0, 3.0]], np.array([[0.0, 0.0, 1.0]]) + 0j)
    exact = np.array([[Fraction(1), 2, 3]], dtype=object)
    assert np.array_equal(w.evaluate(wood.field, exact), w.evaluate(wood.field, [[1.0, 2.0, 3.0]]))


def test_woodify_paint_refuses_complex_numbers():
    """Brush(centre_mm=complex) and woodify(vertex_gain=/vertex_direction= complex) took the real
    parts under numpy's ComplexWarning alone (a painted stroke where the user's numbers did not
    put it); now each is refused naming the argument."""
    import trimesh

    import woodcam as w
    from woodcam.woodify import woodify

    with pytest.raises(WoodcamError, match=r"brush centre_mm must be three finite numbers \(x, y, z\); got "
                                           r"an array of complex numbers \(dtype complex128, shape \(3,\)\)"):
        w.Brush(np.array([0.0, 0.0, 0.0]) + 1j, 5)
    ball = trimesh.creation.icosphere(radius=5, subdivisions=2)
    n = len(ball.vertices)
    with pytest.raises(WoodcamError, match=rf"vertex_gain must be {n} finite values > 0, one per vertex of the "
                                           rf"mesh; got an array of complex numbers \(dtype complex128, shape \({n},\)\)"):
        woodify(ball, 2, resolution=16, vertex_gain=np.ones(n) + 1j)
    with pytest.raises(WoodcamError, match=rf"vertex_direction must be finite real numbers with shape \({n}, 3\), "
                                           r"one wind vector per vertex of the mesh; got an array of complex numbers"):
        woodify(ball, 2, resolution=16, vertex_direction=np.zeros((n, 3)) + 1j)


def test_growth_speed_methods_refuse_none_and_complex():
    """GrowthSpeed.tau(None) was NaN, .years(None) NaN and .speed(None) 0 mm/year, without a word
    (np.asarray(None, float) is NaN); complex years lost their imaginary parts under numpy's
    ComplexWarning. The valid calls beside them keep their answers."""
    import woodcam as w

    gs = w.GrowthSpeed(10, 2)
    for call, name in ((lambda: gs.tau(None), "years"), (lambda: gs.years(None), "tau_mm"),
                       (lambda: gs.speed(None), "years"), (lambda: gs.speed(1.0, [None, 0, 1]), "normals")):
        with pytest.raises(WoodcamError, match=rf"{name} must be real numbers \(any shape\); got \[?None"):
            call()
    with pytest.raises(WoodcamError, match=r"years must be real numbers .*complex numbers .*np\.real\(years\)"):
        gs.tau(np.array([1.0 + 1j]))
    assert gs.years(gs.tau(3.0)) == pytest.approx(3.0, abs=1e-9)
    assert np.array_equal(gs.speed([1, 2]), gs.speed(np.array([1.0, 2.0])))


def test_simulate_refuses_a_complex_stock_size_and_work_offset():
    """simulate(size_mm=complex) and work_offset_mm=complex were taken as their real parts under
    numpy's ComplexWarning alone; a valid size given as a list still simulates."""
    import woodcam as w

    prog = w.read_gcode("G0 X-3 Y5 Z2\nG1 Z-1 F100\nG1 X13\n")
    tool = w.parse_tool_spec("flat:3")
    with pytest.raises(WoodcamError, match=r"simulate: size_mm must be \(W, D, H\) finite and > 0 in mm, got "
                                           r"array\(\[10\.\+1\.j"):
        w.simulate(prog, tool, np.array([10.0, 10.0, 10.0]) + 1j, resolution_mm=0.5)
    with pytest.raises(WoodcamError, match=r"simulate: work_offset_mm must be three finite numbers \(X, Y, Z\) "
                                           r"in mm; got array\(\[0\.\+1\.j"):
        w.simulate(prog, tool, (10, 10, 10), resolution_mm=0.5, work_offset_mm=np.zeros(3) + 1j)
    assert w.simulate(prog, tool, [10, 10, 10], resolution_mm=0.5).heightmap.shape == (20, 20)


@pytest.mark.parametrize("kw, match", [
    ({"block_size_mm": "abc"}, r"block_size_mm must be three finite sizes > 0 \(W, D, H mm\); got 'abc'"),
    ({"block_size_mm": np.ones(3) + 1j}, r"block_size_mm must be three finite sizes > 0 .*got an array of complex numbers \(dtype complex128, shape \(3,\)\)"),
    ({"block_size_mm": (1, 1, np.inf)}, r"block_size_mm must be three finite sizes > 0 .*got \(1, 1, inf\)"),
    ({"block_size_mm": (1, 1, 1), "block_centre_mm": "a"}, r"block_centre_mm must be three finite numbers .*got 'a'"),
    ({"block_size_mm": (1, 1, 1), "block_centre_mm": (0, 0)}, r"block_centre_mm must be three finite numbers .*got \(0, 0\)"),
    ({"block_size_mm": (1, 1, 1), "rotation": "a"}, r"rotation must be a proper 3x3 rotation matrix .*got 'a'"),
], ids=["size str", "size complex", "size inf", "centre str", "centre of 2", "rotation str"])
def test_woodified_field_placed_checks_its_block(kw, match):
    """WoodifiedField.placed parsed its block with bare numpy calls: 'abc', a 2-vector centre and a
    string rotation were numpy's ValueErrors, a complex size its ComplexWarning (the real parts
    taken), an infinite size a matmul warning and a NaN origin. Now the constructor's rules, at
    the door; the valid call beside them places the block."""
    with pytest.raises(WoodcamError, match=match):
        _woodified().placed(**kw)
    placed = _woodified().placed([1, 1, 1], block_centre_mm=[1, 1, 1])
    assert placed.block_size_mm == (1.0, 1.0, 1.0) and np.array_equal(placed.block_origin_mm, [0.5, 0.5, 0.5])


def test_woodified_field_refuses_an_arrival_grid_of_complex_numbers():
    """arrival_mm of complex numbers was read as its real parts under numpy's ComplexWarning, and
    'abc' was numpy's bare ValueError."""
    import woodcam as w

    for grid, got in ((np.zeros((3, 3, 3)) + 1j, r"an array of complex numbers \(dtype complex128, shape \(3, 3, 3\)\)"),
                      ("abc", "'abc'")):
        with pytest.raises(WoodcamError, match=r"arrival_mm must be an \(nx, ny, nz\) grid of real numbers, each >= 2; "
                                               rf"got {got}"):
            w.WoodifiedField(grid, (0, 0, 0), 1.0, w.GrowthSpeed(10, 1), years_final=1.0)


@pytest.mark.parametrize("up, got", [
    (np.array([0.0, 0.0, 1.0]) + 1j, r"an array of complex numbers \(dtype complex128, shape \(3,\)\)"), ("abc", "'abc'"), ((0, 0, 0), r"\(0, 0, 0\)"),
], ids=["complex", "str", "zero"])
def test_growth_speed_up_is_a_direction(up, got):
    """GrowthSpeed(up=complex) was float()'s bare TypeError and up='abc' numpy's ValueError (its
    own parser, _unit3); now the one rule of a direction (check_vector), and a valid up is made
    unit as before."""
    import woodcam as w

    with pytest.raises(WoodcamError, match=rf"up must be (three finite numbers \(x, y, z\)|a non-zero direction); got {got}"):
        w.GrowthSpeed(10, 2, up=up)
    assert w.GrowthSpeed(10, 2, up=(0, 0, 2)).up == (0.0, 0.0, 1.0)


@pytest.mark.parametrize("dirs, got", [
    (None, "None"), ("abc", "'abc'"), (np.zeros((2, 2)), r"shape \(2, 2\)"),
    (np.zeros((1, 3)) + 1j, r"an array of complex numbers \(dtype complex128, shape \(1, 3\)\)"),
], ids=["None", "str", "(n, 2)", "complex"])
def test_log_frame_rotates_only_direction_vectors(dirs, got):
    """LogFrame.direction_to_block/direction_to_log gave einsum's bare ValueErrors for None and
    (n, 2), numpy's for 'abc', and took complex vectors' real parts under the ComplexWarning; a
    direction turned there and back is itself, and a NaN direction stays NaN."""
    import woodcam as w

    frame = w.LogFrame((1, 2, 3), (1, 0, 0))
    for turn, name in ((frame.direction_to_block, "dirs_log"), (frame.direction_to_log, "dirs_mm")):
        with pytest.raises(WoodcamError, match=rf"{name} must be direction vectors of real numbers, shape \(n, 3\); got {got}"):
            turn(dirs)
    assert np.allclose(frame.direction_to_log(frame.direction_to_block([[0, 0, 1]])), [[0, 0, 1]])
    assert np.isnan(frame.direction_to_log([[np.nan, 0.0, 1.0]])).all()


def test_log_accessors_take_real_numbers_and_grid_lookups_finite_ones():
    """LogSkeleton.pith_at/radius_at/knot_point and GeneratedLog.base_radius/outer_radius read
    their numbers with np.asarray(float): None was NaN (pith_at(None) -> [nan, nan] without a
    word), 'abc' numpy's bare ValueError, complex numbers their real parts under numpy's
    ComplexWarning, and a NaN height or azimuth of the radius lookups was cast to a grid index
    (numpy's RuntimeWarning and another cell's radius). The valid calls keep their answers."""
    import woodcam as w

    log = w.generate_log(1, length_mm=200)
    sk = log.to_skeleton()
    calls = {"pith_at": (sk.pith_at, "z_mm"), "radius_at": (lambda v: sk.radius_at(v, 0.0), "z_mm"),
             "radius_at azimuth": (lambda v: sk.radius_at(10.0, v), "azimuth_rad"),
             "knot_point": (lambda v: sk.knot_point(0, v), "r_mm"),
             "base_radius": (lambda v: log.base_radius(v, 0.0), "l_mm"),
             "outer_radius": (lambda v: log.outer_radius(v, 0.0), "l_mm")}
    for call, name in calls.values():
        for bad, got in ((None, "None"), ("abc", "'abc'"), (np.array([1.0 + 1j]), "an array of complex numbers")):
            with pytest.raises(WoodcamError, match=rf"{name} must be real numbers \(any shape\); got {got}"):
                call(bad)
    for call, name in (calls["radius_at"], calls["radius_at azimuth"], calls["outer_radius"]):
        with pytest.raises(WoodcamError, match=rf"{name} must be finite real numbers; got nan among 1"):
            call(np.nan)
    assert np.isnan(sk.pith_at(np.nan)).all()  # NaN in, NaN out: pith_at indexes no grid
    assert np.array_equal(sk.radius_at([10.0, 20.0], 0.0), [sk.radius_at(10.0, 0.0), sk.radius_at(20.0, 0)])
    assert np.allclose(log.outer_radius([10.0], [0.0]), sk.radius_at(10.0, 0.0))


def test_stem_pith_tool_profile_and_ramp_take_real_numbers():
    """StemField.pith_mm(None) was a NaN pith point and Tool.profile(None) +inf ('outside the
    tool'), each without a word; ColorMapAppearance.ramp(None) an IndexError; 'a' was numpy's
    bare ValueError and complex numbers their real parts under numpy's ComplexWarning for all
    three. The valid calls keep their answers."""
    import woodcam as w

    stem = w.StemField(np.array([20.0, 15.0, 10.0]), np.array([0.0, 0.0, 1.0]), 50.0, np.zeros((2, 3)), 0, 0, 2,
                       np.array([0.5]), np.array([0.0]), 10.0)
    ball = w.parse_tool_spec("ball:6")
    app = w.ColorMapAppearance()
    for call, name in ((stem.pith_mm, "t_mm"), (ball.profile, "r_mm"), (app.ramp, "arf_values")):
        for bad, got in ((None, "None"), ("a", "'a'"), (np.array([1.0 + 1j]), "an array of complex numbers")):
            with pytest.raises(WoodcamError, match=rf"{name} must be real numbers \(any shape\); got {got}"):
                call(bad)
    with pytest.raises(WoodcamError, match=r"arf_values must be one ARF value per point, shape \(n,\); got shape \(\)"):
        app.ramp(0.5)
    assert np.array_equal(stem.pith_mm([0, 10]), [[20, 15, 10], [20, 15, 20]])
    assert ball.profile([0.0])[0] == 0.0 and ball.profile([5.0])[0] == np.inf
    assert app.ramp([0.0, 0.95]).shape == (2, 3)


@pytest.mark.parametrize("as_path", [False, True])
def test_a_file_name_where_a_mesh_is_taken_is_told_to_be_loaded(as_path):
    """A notebook passes the file name, as the command line takes it: woodify('x.stl', 5) said
    "mesh must be a trimesh.Trimesh; got str" (no value, no fix), bake('x.stl', wood) "got str
    with 0 faces", export_glb('x', ...) "got str"."""
    from pathlib import Path

    import trimesh

    from woodcam import bake, crease_normals, export_glb, open_stock
    from woodcam.woodify import woodify

    name = Path("part.stl") if as_path else "part.stl"
    load = r"got (str|PosixPath) 'part.stl'; load the file first: trimesh.load\('part.stl', force='mesh'\)"
    with pytest.raises(WoodcamError, match="^mesh must be a trimesh.Trimesh; " + load):
        woodify(name, 5, growth_mm=2, resolution=16)
    with pytest.raises(WoodcamError, match=r"^obstacles\[0\] must be a trimesh.Trimesh; " + load):
        woodify(trimesh.creation.icosphere(1, 10.0), 5, growth_mm=2, resolution=16, obstacles=[name])
    with pytest.raises(WoodcamError, match="^bake: mesh must be a trimesh.Trimesh; " + load):
        bake(name, open_stock("builtin:flat-sawn").wood)
    with pytest.raises(WoodcamError, match="^crease_normals: mesh must be a trimesh.Trimesh; " + load):
        crease_normals(name)
    with pytest.raises(WoodcamError, match=r"^export_glb: mesh must be a trimesh.Trimesh; got (str|PosixPath) "
                       r"'part.stl'; pass the baked surface: bake\(mesh, wood\).mesh .*load_textured"):
        export_glb(name, "out.glb")


def test_refusals_a_notebook_walk_met_without_a_fix_now_say_one(tmp_path):
    """Each said the rule and the value and stopped: ParquetryParams(px_per_mm=nan) "parquetry
    parameter px_per_mm must be a finite number; got nan", Brush(..., -1) "brush radius_mm must be
    > 0 (mm); got -1", read_mokume('/nope') "... '/nope' is not a directory", read_glb_metadata of
    a missing file "GLB file '...': cannot read it (No such file or directory)"."""
    import woodcam as w

    cases = [
        (lambda: w.ParquetryParams(px_per_mm=float("nan")),
         r"px_per_mm must be a finite number; got nan; leave it out for the default, px_per_mm=4.0"),
        (lambda: w.Brush((0, 0, 0), -1), r"radius_mm must be > 0 \(mm\); got -1; .*radius_mm=5"),
        (lambda: w.read_mokume(tmp_path / "nope"), r"is not a directory; give the folder holding A_col.png"),
        (lambda: w.read_glb_metadata(tmp_path / "nope.glb"), r"cannot read it \(.*\); check the path"),
    ]
    for call, said in cases:
        with pytest.raises(WoodcamError, match=said):
            call()
