"""The public API (``woodcam.__all__``) is typed: every exported function and every public
method of an exported class annotates its parameters and its return value."""

import inspect

import woodcam


def _callables():
    for name in woodcam.__all__:
        obj = getattr(woodcam, name)
        if inspect.isfunction(obj):
            yield name, obj
        elif inspect.isclass(obj):
            for member, f in vars(obj).items():
                if inspect.isfunction(f) and (not member.startswith("_") or member in ("__init__", "__call__")):
                    yield f"{name}.{member}", f


def test_public_api_is_annotated():
    missing = []
    for name, f in _callables():
        sig = inspect.signature(f)
        bare = [p for p, v in sig.parameters.items()
                if v.annotation is inspect.Parameter.empty and p not in ("self", "cls")
                and v.kind not in (v.VAR_KEYWORD, v.VAR_POSITIONAL)]
        no_return = sig.return_annotation is inspect.Signature.empty and not name.endswith("__init__")
        if bare or no_return:
            missing.append(f"{name} ({f.__module__}): " + ", ".join(bare + (["return"] if no_return else [])))
    assert not missing, "add type hints:\n" + "\n".join(missing)


def test_every_export_resolves():
    for name in woodcam.__all__:
        assert getattr(woodcam, name) is not None, name


def test_a_public_name_that_is_also_a_submodule_stays_the_public_object():
    """Importing the submodule woodcam.bake bound the package attribute ``bake`` to the module,
    so ``from woodcam import bake`` gave a module ("'module' object is not callable") once
    anything had imported it; likewise ``benchmark``."""
    import importlib

    import woodcam

    for name in ("bake", "benchmark"):
        module = importlib.import_module(f"woodcam.{name}")
        assert callable(getattr(woodcam, name)) and getattr(woodcam, name) is not module
    from woodcam import bake

    assert bake is importlib.import_module("woodcam.bake").bake


# The classes that hold arrays, meshes or long lists: their repr names shapes, not contents.
# Parameter classes (Brush, GrowthSpeed, LogFrame, ParquetryParams, SceneOptions, Tool) keep
# the dataclass repr, whose every value is short and which reads back as the call.
_HOLDERS = ("BakeResult", "Block", "CarveResult", "ColorMapAppearance", "EvidenceFit", "Face",
            "GeneratedLog", "GridField", "LogSkeleton", "ParquetryJob", "ParquetryRun", "PartPreview",
            "Program", "RadialScalingField", "RingDetection", "RingTrace", "RunSummary", "SimResult",
            "StemField", "Stock", "Veneer", "Woodification")


def test_result_reprs_name_array_shapes_not_contents():
    """A notebook showed ``bake(...)`` as thousands of atlas pixels and ``read_gcode(...)`` as every
    segment's start point (BakeResult 'atlas=array([[[168, 134, 92], ...' over 40 lines): each
    holder's repr is one line, an array as its shape and dtype."""
    import dataclasses

    import numpy as np

    for name in _HOLDERS:
        cls = getattr(woodcam, name)
        obj = object.__new__(cls)  # every field a 100 x 100 array, no validation
        for f in dataclasses.fields(cls):
            object.__setattr__(obj, f.name, np.zeros((100, 100)))
        text = repr(obj)
        assert text.startswith(f"{name}(") and "\n" not in text and len(text) < 1000, (name, text[:300])
        assert "array(shape=(100, 100), dtype=float64)" in text, (name, text[:300])


def test_a_read_program_shows_its_shapes_and_source():
    program = woodcam.read_gcode("G21 G90\nG0 X0 Y0 Z5\nG1 Z-1 F100\nG1 X10\n" * 20)
    text = repr(program)
    assert "\n" not in text and "start_mm=array(shape=(" in text and ", dtype=float64)" in text


def test_short_repr_of_containers_and_plain_objects():
    from woodcam._repr import short

    assert short({"a": 1}) == "{'a': 1}" and short([1, 2]) == "[1, 2]"
    assert short({str(k): k for k in range(9)}) == "<dict of 9: '0', '1', '2', '3', '4', '5', ...>"
    assert short(list(range(50))) == "<list of 50 of int>"
    assert short(object()) == "<builtins.object>"
    import numpy as np

    assert short(np.float64(2.5)) == repr(np.float64(2.5)) and short(np.zeros((2, 3), np.uint8)) == \
        "array(shape=(2, 3), dtype=uint8)"


def test_evaluate_fit_is_annotated_as_what_it_returns():
    """evaluate_fit was annotated ``-> dict`` but returns ``(summary, scores)`` as its docstring
    says (a typed notebook's ``evaluate_fit(...)["matched_1"]`` passed mypy and failed at run
    time); each PlaneScore printed its distance arrays in full."""
    import typing

    from woodcam.inference.evaluate import PlaneScore, evaluate_fit

    hint = typing.get_type_hints(evaluate_fit)["return"]
    assert typing.get_origin(hint) is tuple, hint
    field = woodcam.builtin_block("flat-sawn").field
    summary, scores = evaluate_fit(field, field, (40, 30, 20), pixel_mm=1.0)
    assert isinstance(summary, dict) and all(isinstance(s, PlaneScore) for s in scores)
    text = repr(scores[0])
    assert "\n" not in text and "d_matched=array(shape=(" in text, text[:300]


def test_fields_and_wood_show_what_they_are():
    """Wood and the plain field classes printed '<woodcam.appearance.wood.Wood object at 0x...>'
    (a Stock's wood, a knotty block's PlacedField), and a radial field its two 360-sample radius
    functions in full (some 150 lines)."""
    import trimesh

    from woodcam.woodify import woodify

    texts = [repr(woodcam.open_stock("builtin:knotty").wood), repr(woodcam.builtin_block("flat-sawn").field),
             repr(woodify(trimesh.creation.icosphere(1, 10.0), 2, growth_mm=2, resolution=16).field)]
    for text in texts:
        assert "\n" not in text and " at 0x" not in text and len(text) < 2000, text[:300]
    assert texts[0].startswith("Wood(field=PlacedField(log_field=KnottedLogField(log=LogSkeleton(")
    assert "r_minus=RadiusFunction(samples=array(shape=(360,), dtype=float64))" in texts[1]
    assert texts[2].startswith("WoodifiedField(arrival_mm=array(shape=(16, 16, 16), dtype=float32)")
    assert "block_origin_mm=array([0.0, 0.0, 0.0])" in texts[2]


def test_an_appearance_shows_its_species_by_name():
    """A knotty stock's Wood repr was one line of 1098 characters, a third of it the Species'
    ten numbers and its source sentence, printed through the ColorMapAppearance."""
    text = repr(woodcam.open_stock("builtin:knotty").wood)
    assert "appearance=ColorMapAppearance(species=<Species 'spruce'>)" in text  # the Nones left out
    assert "earlywood_rgb" not in text and "source=" not in text and len(text) < 800, text
    assert repr(woodcam.ColorMapAppearance("walnut")) == "ColorMapAppearance(species=<Species 'walnut'>)"


def test_the_python_entry_points_the_readme_names_are_annotated():
    """The README sends a Python user to woodcam.woodify.woodify (and woodcam.pipeline.preview_part);
    woodify left mesh, up, obstacles, vertex_gain, vertex_direction and obstacle_names bare."""
    import importlib
    import re

    from pathlib import Path

    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    named = sorted(set(re.findall(r"`(woodcam(?:\.[a-z_]+){2,})\(", readme))
                   | {"woodcam.woodify.woodify", "woodcam.pipeline.preview_part"})
    missing = []
    for dotted in named:
        module, name = dotted.rsplit(".", 1)
        f = getattr(importlib.import_module(module), name)
        sig = inspect.signature(f)
        bare = [p for p, v in sig.parameters.items() if v.annotation is inspect.Parameter.empty
                and v.kind not in (v.VAR_KEYWORD, v.VAR_POSITIONAL)]
        if bare or sig.return_annotation is inspect.Signature.empty:
            missing.append(f"{dotted}: {bare}")
    assert not missing, "add type hints:\n" + "\n".join(missing)


# The calls of a notebook's walk through the pipeline (open a stock, carve and bake a part, read
# it back, simulate G-code, parquetry, fit and evaluate): their docstrings name every parameter.
_WALK = ("open_stock", "read_mokume", "load_part", "carve", "bake", "export_glb", "read_gcode", "simulate",
         "build_parquetry", "fit_block", "evaluate", "evaluate_fit", "block_to_pixel", "pixel_to_block",
         "preview_part", "preview_mesh")


def test_the_walk_through_calls_document_every_parameter():
    """preview_part's docstring named 7 of its parameters, preview_mesh's none of 11, evaluate's
    not ``points_mm`` (nor its unit and frame), block_to_pixel's none of its four, build_parquetry's
    not ``names``."""
    import re

    missing = []
    for name in _WALK:
        f = getattr(woodcam, name)
        doc = inspect.getdoc(f) or ""
        missing += [f"{name}: {p}" for p in inspect.signature(f).parameters
                    if not re.search(rf"\b{re.escape(p)}\b", doc)]
    assert not missing, "document:\n" + "\n".join(missing)
    assert "block frame" in inspect.getdoc(woodcam.evaluate) and "mm" in inspect.getdoc(woodcam.evaluate)


def _sub_package_functions():
    """``(qualified name, function)`` of each function a sub-package exports
    (woodcam/<pkg>/__init__.py ``__all__``), each function once."""
    import importlib
    import pkgutil

    seen = set()
    for info in pkgutil.iter_modules(woodcam.__path__):
        if not info.ispkg or info.name.startswith("_") or info.name == "examples":
            continue
        module = importlib.import_module(f"woodcam.{info.name}")
        for name in getattr(module, "__all__", ()):
            f = getattr(module, name)
            if inspect.isfunction(f) and f not in seen:
                seen.add(f)
                yield f"woodcam.{info.name}.{name}", f


def test_the_sub_packages_exports_are_annotated():
    """What a sub-package exports (woodcam/<pkg>/__init__.py __all__) is a Python door too, outside
    woodcam.__all__: 47 of them left parameters or the return bare (woodify.propagate,
    inference.score_face, logs.fit_*, view.build_scene, fields.check_points, ...)."""
    missing = []
    for qualified, f in _sub_package_functions():
        sig = inspect.signature(f)
        bare = [p for p, v in sig.parameters.items() if v.annotation is inspect.Parameter.empty
                and v.kind not in (v.VAR_KEYWORD, v.VAR_POSITIONAL)]
        if bare or sig.return_annotation is inspect.Signature.empty:
            missing.append(f"{qualified}: {bare}"
                           f"{' (no return)' if sig.return_annotation is inspect.Signature.empty else ''}")
    assert not missing, "add type hints:\n" + "\n".join(missing)


def test_every_public_callable_documents_every_parameter():
    """Beyond the walk's calls, 28 entries of woodcam.__all__ left parameters unnamed in their
    docstrings: mostly a plain ``path`` / ``folder`` / ``out_dir`` (load_textured, read_job,
    read_log, read_records, ...), and the fields of Program (tool_numbers, warnings, messages,
    printed), RingDetection (rule, warnings, order_map, ring_order), RunSummary (out_dir,
    engine, workers, total, skipped, done, wall_s) and PartPreview (meta_block, tessellation,
    atlas, charts, stages)."""
    import re

    missing = []
    for name in woodcam.__all__:
        obj = getattr(woodcam, name)
        if not (inspect.isfunction(obj) or inspect.isclass(obj)):
            continue
        doc = inspect.getdoc(obj) or ""
        if inspect.isclass(obj) and "__init__" in vars(obj) and vars(obj)["__init__"].__doc__:
            doc += vars(obj)["__init__"].__doc__
        try:
            params = inspect.signature(obj).parameters
        except (TypeError, ValueError):  # a class without a signature takes no documented fields
            continue
        missing += [f"{name}: {p}" for p in params if p not in ("self", "args", "kwargs")
                    and not re.search(rf"\b{re.escape(p)}\b", doc)]
    assert not missing, "document:\n" + "\n".join(missing)


def test_the_sub_packages_exports_document_every_parameter():
    """42 functions the sub-packages export (outside woodcam.__all__) left parameters unnamed in
    their docstrings: woodify.weibull_*'s shape, logs.fit_surface_base's l_mm and theta_rad,
    view.build_scene's mesh_or_path and size_mm, synth.benchmark_set_block's seven keywords, ..."""
    import re

    missing = []
    for qualified, f in _sub_package_functions():
        doc = inspect.getdoc(f) or ""
        missing += [f"{qualified}: {p}" for p in inspect.signature(f).parameters
                    if p not in ("self", "args", "kwargs") and not re.search(rf"\b{re.escape(p)}\b", doc)]
    assert not missing, "document:\n" + "\n".join(missing)


def test_a_woods_repr_is_short_with_plain_numbers():
    """A knotty stock's Wood repr was 754 characters: its LogFrame held numpy scalars
    ('axis=(np.float64(0.0), np.float64(-0.0), np.float64(1.0))') and points to 15 digits, and
    its ColorMapAppearance listed the eight optional fields left at None."""
    import numpy as np

    text = repr(woodcam.open_stock("builtin:knotty").wood)
    assert "np.float64" not in text and len(text) < 500, (len(text), text)
    assert "frame=LogFrame(pith_point_mm=(50, 95, -315.685), axis=(0, 0, 1), reference=(0, -1, 0))" in text, text
    assert "appearance=ColorMapAppearance(species=<Species 'spruce'>), threads=" in text, text
    frame = woodcam.LogFrame(np.array([1.0, 2.0, 3.0]), np.array([0.0, 0.0, 2.0]), np.array([1.0, 0.0, 0.0]))
    assert frame.axis == (0.0, 0.0, 2.0) and all(type(v) is float for v in frame.axis + frame.reference)
    assert frame == woodcam.LogFrame((1, 2, 3), (0, 0, 2), (1, 0, 0)) and hash(frame) == hash(
        woodcam.LogFrame((1, 2, 3), (0, 0, 2), (1, 0, 0)))
    assert repr(woodcam.ColorMapAppearance("walnut", seed=3)) == "ColorMapAppearance(species=<Species 'walnut'>, seed=3)"
