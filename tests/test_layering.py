"""Dependencies point one way (../shared/docs/architecture.md), lazy imports included.

Every ``import`` / ``from ... import`` statement anywhere in a woodcam module (top level or
inside a function) is read with ``ast``; an import of another unit must go to a lower layer.
A unit is a subpackage (``woodcam/fields/``) or a top-level module (``woodcam/stock.py``). A new
unit must be given a layer here, which makes its place in the architecture a decision.
"""

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "woodcam"

#: Layer of each unit: a unit may import units of strictly lower layers only.
LAYERS: dict[str, int] = {
    # foundations: errors, tolerances, limits, atomic writes, content-keyed caches
    "errors": 0, "tolerances": 0, "_types": 0, "units": 0, "limits": 1, "_checks": 1, "_atomic": 1, "_cache": 2,
    "_repr": 0,                        # short reprs of the result classes (stdlib only)
    "_interrupt": 0,                   # Ctrl-C recorded, so one a library swallowed still ends the run
    "_specs": 2,                       # a block spec's grammar and the paths it names (errors, limits, units)
    "_readers": 2,                     # strict JSON and images of untrusted files (errors, limits)
    "_threads": 1,                     # BLAS thread limits for small linear algebra
    "_parallel": 1,                    # one fit on a machine's cores: forked pieces
    "_progress": 1,                    # progress bars (tqdm only), on a terminal
    "_xatlas_worker": 1,               # xatlas in a worker process (numpy + xatlas only)
    "_raster": 1,                      # numba rasteriser of the bake (numpy + numba only)
    "_manifold": 1,                    # a manifold3d Manifold -> its triangles (numpy + trimesh only)
    "frames": 3,                       # block frame, faces, pixel <-> block
    "fields": 4,                       # growth fields behind one protocol
    "block": 5,                        # Block, its faces, readers/writers (stores fields)
    "woodify": 5,                      # grown objects' fields (uses fields)
    "appearance": 6,                   # colour; reads a Block's photos
    "detect": 6,                       # rings and knots on photos (uses block)
    "logs": 7,                         # the log model; its section render uses appearance
    "inference": 7,                    # fits fields to blocks (uses block, fields, detect)
    # above: everything that consumes a Wood or a Block
    "cad": 8, "bake": 8, "export": 8, "toolpath": 8, "synth": 8, "parquetry": 8,
    "view": 9, "review": 9,            # view reads woodcam's own exports
    "stock": 10,                       # block spec -> Stock (synth, inference, appearance)
    "advise": 10,                      # placement advice and part reports (takes a Stock)
    "pipeline": 11, "demo": 12,
    "scale": 13,                       # runs any of them
    "benchmark": 14,                   # bench tasks and reports, run by scale
    "bench_realistic": 14,             # realistic-generator scoring per block (issue 12)
    "cli": 15,                         # the command, on top
    "__main__": 16,                    # python -m woodcam: runs the command
    "woodcam": 16,                     # the package's lazy re-exports
}
#: Data folders (no code).
DATA = {"models", "data", "examples"}  # examples: part scripts (cad_examples/ links here)


def _unit(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "woodcam"


def _imports(path: Path):
    """``(lineno, imported module)`` of every woodcam import in a file, lazy ones included."""
    rel = path.relative_to(PACKAGE.parent).with_suffix("").parts
    module = ".".join(rel[:-1] if rel[-1] == "__init__" else rel)
    package = module if path.name == "__init__.py" else module.rsplit(".", 1)[0]
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[:len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
                if node.module is None:  # "from .. import x": x may be a unit of its own
                    for alias in node.names:
                        yield node.lineno, f"{target}.{alias.name}"
                    continue
            else:
                target = node.module or ""
                if target == "woodcam":  # "from woodcam import _x": a unit, or the package's API
                    for alias in node.names:
                        unit = alias.name in _units_on_disk()
                        yield node.lineno, f"woodcam.{alias.name}" if unit else "woodcam"
                    continue
            # "from ..toolpath import _surface" imports the module woodcam.toolpath._surface
            subs = [f"{target}.{a.name}" for a in node.names if _is_module(f"{target}.{a.name}")]
            yield from ((node.lineno, sub) for sub in subs)
            if len(subs) < len(node.names):
                yield node.lineno, target
        elif isinstance(node, ast.Import):
            for alias in node.names:
                yield node.lineno, alias.name


def _is_module(dotted: str) -> bool:
    """Whether ``dotted`` (``woodcam.x.y``) is a module or package of woodcam on disk."""
    path = PACKAGE.parent.joinpath(*dotted.split("."))
    return dotted.startswith("woodcam.") and (path.with_suffix(".py").is_file()
                                              or (path / "__init__.py").is_file())


def _units_on_disk() -> set[str]:
    out = {p.stem for p in PACKAGE.glob("*.py") if p.stem != "__init__"}
    out |= {p.name for p in PACKAGE.iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    return out


def test_every_unit_has_a_layer():
    missing = sorted(_units_on_disk() - set(LAYERS) - DATA)
    assert not missing, f"give these units a layer in tests/test_layering.py: {missing}"


def _violations():
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE.parent).with_suffix("").parts
        source = _unit(".".join(rel))
        if source == "__init__":
            source = "woodcam"
        for line, target in _imports(path):
            if not (target == "woodcam" or target.startswith("woodcam.")):
                continue
            dest = _unit(target)
            if dest in DATA or dest == source or dest not in LAYERS or source not in LAYERS:
                continue  # unknown units fail test_every_unit_has_a_layer
            if LAYERS[dest] >= LAYERS[source]:
                found.append(f"{path.relative_to(PACKAGE.parent)}:{line}: {source} "
                             f"(layer {LAYERS[source]}) imports {target} (layer {LAYERS[dest]})")
    return found


def test_no_module_imports_one_above_it():
    assert not _violations(), "upward imports:\n" + "\n".join(_violations())


def test_the_walk_sees_lazy_imports(tmp_path, monkeypatch):
    """A function-level import counts: the check would catch fields importing synth lazily."""
    fake = tmp_path / "woodcam"
    (fake / "fields").mkdir(parents=True)
    (fake / "fields" / "__init__.py").write_text("")
    (fake / "fields" / "x.py").write_text("def f():\n    from ..synth import synth_block\n")
    monkeypatch.setattr(__import__(__name__), "PACKAGE", fake)
    expected = "woodcam/fields/x.py:2: fields (layer 4) imports woodcam.synth (layer 8)"
    assert _violations() == [expected]


def test_no_two_public_classes_share_a_name():
    """One concept, one name: a public class name is defined once in the package."""
    where: dict[str, list[str]] = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        for node in ast.parse(path.read_text(), str(path)).body:
            if isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
                where.setdefault(node.name, []).append(str(path.relative_to(PACKAGE.parent)))
    twice = {name: paths for name, paths in where.items() if len(paths) > 1}
    assert not twice, f"public classes defined more than once: {twice}"


def _private_imports():
    """Imports of a unit's private module (``woodcam.<unit>._x``, also as ``from
    ..<unit> import _x``) from another unit."""
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        source = _unit(".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts))
        for line, target in _imports(path):
            parts = target.split(".")
            if (parts[0] == "woodcam" and len(parts) > 2 and parts[1] != source
                    and any(p.startswith("_") and not p.startswith("__") for p in parts[2:])):
                found.append(f"{path.relative_to(PACKAGE.parent)}:{line}: {source} imports {target}")
    return found


def test_no_unit_imports_another_units_private_module():
    """A private module is its unit's business: synth imported woodcam.detect._quilt and view
    woodcam.toolpath._surface (now the public woodcam.detect.quilt and woodcam.toolpath.surface).
    What another unit needs is that unit's public API."""
    assert not _private_imports(), "private modules imported across units:\n" + "\n".join(_private_imports())
