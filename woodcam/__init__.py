"""woodcam: CNC cut preview for solid wood.

Photograph a block, infer its growth rings, carve a part out of it and see the wood on every
surface before a single cut. Lengths are millimetres, growth time is years, points are in the
block frame of ``docs/conventions.md`` (origin bottom-front-left, X width, Y depth, Z up).

The pipeline, one name per stage::

    stock = open_stock("builtin:flat-sawn")          # block size + Wood(field, appearance)
    carved = carve(load_part("bowl.py"), stock.size_mm)
    baked = bake(carved.mesh, stock.wood, texels_per_mm=10)
    export_glb(baked.mesh, "bowl.glb"); preview("bowl.glb", wood=stock.wood, size_mm=stock.size_mm)
"""

import importlib
import sys
import types

# Public names and the module each lives in. They load on first use (PEP 562), so
# ``import woodcam`` and ``woodcam --help`` stay fast while trimesh, scipy and numba load later.
_EXPORTS = {
    ".appearance": ["SPECIES", "ColorMapAppearance", "Wood"],
    ".bake": ["BakeResult", "bake"],
    ".bench_realistic": ["score_block"],
    ".benchmark": ["bench_block", "bench_report", "run_bench"],
    ".block": ["Block", "Face", "RingTrace", "read_block", "read_mokume", "write_block"],
    ".cad": ["CarveResult", "auto_tolerance_mm", "carve", "load_part"],
    ".detect": ["RingDetection", "detect_rings"],
    ".errors": ["MissingDependencyError", "UsageError", "WoodcamError", "WoodcamWarning"],
    ".export": ["export_glb", "export_obj", "load_textured", "read_glb_metadata", "crease_normals",
                  "written_by_woodcam", "BLOCK_TO_GLTF"],
    ".fields": ["GridField", "GrowthField", "KnottedLogField", "LogFrame", "LogSkeleton",
                "PlacedField", "RadialScalingField", "arf", "builtin_block", "evaluate",
                "grain_direction"],
    ".frames": ["FACES", "FACE_NORMAL", "MOKUME_LETTER", "block_to_pixel", "pixel_to_block",
                "unfold_cross"],
    ".inference": ["EvidenceFit", "StemField", "benchmark", "evaluate_fit", "fit_block", "fit_evidence",
                   "fit_stem", "leave_one_face_out"],
    ".logs": ["GeneratedLog", "generate_log", "read_gran1", "read_log", "write_log"],
    ".parquetry": ["ParquetryJob", "ParquetryParams", "ParquetryRun", "Veneer", "build_parquetry",
                   "load_scan", "mokume_veneers", "read_job", "repair_fabricability",
                   "slice_veneers", "write_job", "write_parquetry"],
    ".pipeline": ["PartPreview", "preview_mesh", "preview_part"],
    ".scale": ["RunSummary", "read_records", "run_many"],
    ".stock": ["Stock", "open_stock"],
    ".synth": ["cut_block", "synth_block"],
    ".toolpath": ["Program", "SimResult", "Tool", "load_tool_table", "parse_tool_spec",
                  "read_gcode", "simulate"],
    ".view": ["SceneOptions", "preview"],
    ".woodify": ["Brush", "GrowthSpeed", "Woodification", "WoodifiedField"],  # woodify.woodify()
}
_WHERE = {name: mod for mod, names in _EXPORTS.items() for name in names}

__version__ = "0.1.0"
__all__ = sorted(_WHERE)


class _Package(types.ModuleType):
    """The ``woodcam`` module's class: importing the submodule ``woodcam.bake`` (or
    ``woodcam.benchmark``) makes Python bind the package attribute of that name to the
    submodule, so ``from woodcam import bake`` gave the module, not the function, as soon as
    anything had imported it ("'module' object is not callable"). The public name wins: the
    submodule stays in ``sys.modules`` (``importlib.import_module("woodcam.bake")``)."""

    def __setattr__(self, name, value):
        if name in _WHERE and isinstance(value, types.ModuleType) and value.__name__ == f"{__name__}.{name}":
            value = getattr(importlib.import_module(_WHERE[name], __name__), name)
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package


def __getattr__(name: str):
    if name in _WHERE:
        value = getattr(importlib.import_module(_WHERE[name], __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'woodcam' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__))
