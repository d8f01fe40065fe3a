"""Every file woodcam writes goes through :mod:`woodcam._atomic` (temp + rename).

A static check over the package's source: a writer that opens its target directly leaves a
truncated file behind on Ctrl-C or a crash (the brief: "every file write is atomic"), and a
sweep found a dozen that did (the ring net's spec, weights and training log, the copy of a
user's corrected SVG, matplotlib figures, the bench report, hand-made temp + rename). The rule: ``open(..., "w"/"a"/"x")``, ``Path.write_text``,
``Path.write_bytes``, matplotlib's ``savefig``, ``np.save*``, ``torch.save`` and PIL's
``Image.save`` may only write to a temporary of ``with atomic_path(...) as tmp`` /
``atomic_files(...)`` / ``atomic_write(...)`` in the same function (or its parameter ``tmp``, the
caller's temporary) or, for PIL, to an ``io.BytesIO``; everything else calls
``woodcam._atomic.write_text`` / ``write_bytes``, and no writer renames a temporary of its own
(``tempfile.mkstemp``, ``os.replace``: the parquetry outputs were written so, with mode 0600,
unreadable to anyone else). A PIL save is known by what is statically visible: a ``.save()``
given ``format=``, or called on ``Image.fromarray/open/new(...)`` or on a name such as ``img``.
"""

from __future__ import annotations

import ast
from pathlib import Path

import woodcam

PACKAGE = Path(woodcam.__file__).parent
_ATOMIC_CONTEXTS = {"atomic_path", "atomic_files"}
_NUMPY_SAVES = {"save", "savez", "savez_compressed"}
#: Receivers of ``.save()`` taken for a PIL image: calls that make one, names that hold one.
_PIL_MAKERS = {"fromarray", "open", "new", "convert", "resize", "crop", "rotate", "transpose"}
_PIL_NAMES = {"img", "image", "im", "pic", "photo", "picture", "sheet", "strip", "thumb"}
#: Modules whose writes are not woodcam's outputs, each with why.
_NOT_OUTPUTS = {
    "_atomic.py": "the helpers themselves",
    "toolpath/linuxcnc.py": "the program handed to LinuxCNC, in a private temporary directory",
    "toolpath/_linuxcnc_driver.py": "LinuxCNC's ini, parameter and tool files, in that directory",
}
#: Single writes allowed elsewhere, each with why: (module, what) -> reason. None now: a whole
#: block folder of a benchmark set is swapped into place by _atomic.atomic_folder.
_ALLOWED: dict[tuple[str, str], str] = {}


def _callee(node: ast.expr) -> str:
    if isinstance(node, ast.Name):
        return node.id
    if isinstance(node, ast.Attribute):
        return node.attr
    return ""


def _bound_temporaries(tree: ast.AST, names: set[str]) -> set[str]:
    """Names that hold an atomic temporary: bound by ``with atomic_path(...) as name`` /
    ``atomic_files(...) as names`` / ``atomic_write(...) as fh``, by ``with open(temporary) as
    fh``, by a ``for`` loop over temporaries, or the parameter of a ``lambda`` handed to an
    ``..._atomic..`` helper (which calls it with its temporary), within ``tree`` (a function: its
    own temporaries); ``names``: those known before (a function's parameter ``tmp``)."""
    names = set(names)
    for _ in range(3):  # a file opened on a temporary, a loop over them: bound after the first pass
        for node in ast.walk(tree):
            if isinstance(node, (ast.With, ast.AsyncWith)):
                for item in node.items:
                    expr, var = item.context_expr, item.optional_vars
                    if not (isinstance(expr, ast.Call) and isinstance(var, ast.Name)):
                        continue
                    name = _callee(expr.func)
                    if name in _ATOMIC_CONTEXTS or name == "atomic_write" or \
                            (name == "open" and expr.args and _is_temporary(expr.args[0], names)):
                        names.add(var.id)
            elif isinstance(node, ast.For) and any(_is_temporary(n, names) for n in ast.walk(node.iter)):
                names |= {n.id for n in ast.walk(node.target) if isinstance(n, ast.Name)}
            elif isinstance(node, ast.Call) and "atomic" in _callee(node.func):
                for arg in node.args:
                    if isinstance(arg, ast.Lambda):
                        names |= {a.arg for a in arg.args.args}
    return names


def _in_memory_buffers(tree: ast.AST) -> set[str]:
    """Names bound to ``io.BytesIO()`` in ``tree``: a PIL save there writes no file."""
    return {t.id for node in ast.walk(tree) if isinstance(node, ast.Assign)
            and isinstance(node.value, ast.Call) and _callee(node.value.func) == "BytesIO"
            for t in node.targets if isinstance(t, ast.Name)}


def _pil_save(call: ast.Call) -> bool:
    """``call`` is ``<image>.save(file, ...)`` (not ``type(image).save(image, file)``, whose first
    argument is the image, nor a class's own ``save(path)`` method on another object)."""
    f = call.func
    if not (isinstance(f, ast.Attribute) and f.attr == "save" and call.args):
        return False
    receiver = f.value
    if isinstance(receiver, ast.Call) and _callee(receiver.func) == "type":
        return False
    return (any(k.arg == "format" for k in call.keywords)
            or (isinstance(receiver, ast.Call) and _callee(receiver.func) in _PIL_MAKERS)
            or (isinstance(receiver, ast.Name) and receiver.id in _PIL_NAMES))


def _is_temporary(node: ast.expr | None, temps: set[str]) -> bool:
    if isinstance(node, ast.Call) and _callee(node.func) in ("str", "fspath") and len(node.args) == 1:
        node = node.args[0]  # str(tmp): pyvista's screenshot takes a string
    if isinstance(node, ast.Subscript):
        node = node.value
    return isinstance(node, ast.Name) and node.id in temps


def _write_mode(call: ast.Call) -> bool:
    mode = call.args[1] if len(call.args) > 1 else next((k.value for k in call.keywords if k.arg == "mode"), None)
    return isinstance(mode, ast.Constant) and isinstance(mode.value, str) and any(c in mode.value for c in "wax+")


def _writes(scope: ast.AST):
    """``(call, target, what)`` of the write calls in ``scope`` (not inside functions nested in it)."""
    todo = list(ast.iter_child_nodes(scope))
    while todo:
        node = todo.pop()
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue  # its own scope
        todo += ast.iter_child_nodes(node)
        if not isinstance(node, ast.Call):
            continue
        f = node.func
        if isinstance(f, ast.Name) and f.id == "open" and node.args and _write_mode(node):
            yield node, node.args[0], "open(..., write mode)"
        elif isinstance(f, ast.Attribute) and f.attr in ("write_text", "write_bytes"):
            yield node, f.value, f".{f.attr}()"
        elif isinstance(f, ast.Attribute) and f.attr == "savefig" and node.args:
            yield node, node.args[0], ".savefig()"
        elif _pil_save(node):
            yield node, node.args[0], "Image.save()"
        elif isinstance(f, ast.Attribute) and isinstance(f.value, ast.Name) and f.value.id in ("np", "numpy") \
                and f.attr in _NUMPY_SAVES and node.args:
            yield node, node.args[0], f"np.{f.attr}()"
        elif isinstance(f, ast.Attribute) and isinstance(f.value, ast.Name) and f.value.id == "torch" \
                and f.attr == "save" and len(node.args) > 1:
            yield node, node.args[1], "torch.save()"
        elif isinstance(f, ast.Attribute) and isinstance(f.value, ast.Name) and f.value.id == "shutil" \
                and f.attr in ("copy", "copy2", "copyfile", "move", "copytree") and len(node.args) > 1:
            yield node, node.args[1], f"shutil.{f.attr}()"
        elif isinstance(f, ast.Attribute) and f.attr in ("screenshot", "export", "saveas", "to_file") \
                and node.args:  # pyvista, trimesh (mesh.export(path)), ezdxf, others given a path
            yield node, node.args[0], f".{f.attr}()"
        elif isinstance(f, ast.Attribute) and isinstance(f.value, ast.Name) and \
                (f.value.id, f.attr) in (("os", "replace"), ("os", "rename"), ("tempfile", "mkstemp")):
            yield node, None, f"{f.value.id}.{f.attr}()"  # a temp + rename of its own: _atomic's job
        elif isinstance(f, ast.Attribute) and f.attr in ("replace", "rename") and isinstance(f.value, ast.Name) \
                and "tmp" in f.value.id and len(node.args) == 1:
            yield node, None, f".{f.attr}() of a temporary"


def raw_writes(source: str) -> list[tuple[int, str]]:
    """``(line, what)`` of every write in ``source`` that does not go to an atomic temporary of
    its own function (a parameter named ``tmp`` is the caller's temporary, by convention)."""
    tree = ast.parse(source)
    found = []
    for scope in [tree] + [n for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))]:
        params = () if isinstance(scope, ast.Module) else scope.args.args + scope.args.kwonlyargs
        temps = _bound_temporaries(scope, {a.arg for a in params if a.arg == "tmp"}) | _in_memory_buffers(scope)
        found += [(call.lineno, what) for call, target, what in _writes(scope)
                  if target is None or not _is_temporary(target, temps)]
    return sorted(found)


def test_the_check_finds_a_direct_write_and_passes_an_atomic_one():
    bad = ("from pathlib import Path\nPath('x').write_text('a')\nwith open('y', 'w') as fh: pass\nnp.save('z', a)\n"
           "def f(p):\n    with atomic_path(p) as tmp:\n        pass\n"
           "def g(out):\n    tmp = out / '.x.tmp'\n    tmp.write_text('a')\n    fig.savefig(out)\n"
           "    tmp.replace(out)\n    fd, t = tempfile.mkstemp()\n    os.replace(t, out)\n"
           "def k(out, a):\n    Image.fromarray(a).save(out)\n    img.save(out / 'x.png')\n"
           "    Image.open(out).save(out, format='PNG')\n"
           "def m(out, mesh, plotter, doc):\n    shutil.copy('a.png', out)\n    mesh.export(out)\n"
           "    plotter.screenshot(str(out))\n    doc.saveas(out)\n")
    assert [w for _, w in raw_writes(bad)] == [".write_text()", "open(..., write mode)", "np.save()", ".write_text()",
                                               ".savefig()", ".replace() of a temporary", "tempfile.mkstemp()",
                                               "os.replace()", "Image.save()", "Image.save()", "Image.save()",
                                               "shutil.copy()", ".export()", ".screenshot()", ".saveas()"]
    good = ("with atomic_path(p) as tmp:\n    tmp.write_text('a')\n    np.savez(tmp, a=1)\n"
            "with atomic_files([p, q]) as temps:\n    open(temps[0], 'wb').close()\n"
            "with atomic_write(p) as fh:\n    np.savez_compressed(fh, a=1)\n"
            "with atomic_path(p) as tmp, open(tmp, 'wb') as fh:\n    np.save(fh, a)\n"
            "for t in temps[1:]:\n    t.write_bytes(b'')\n"
            "_atomic(p, lambda q: q.write_text('a'))\n"
            "with open(p) as fh: pass\nwrite_text(p, 'a')\n"
            "def h(value, tmp):\n    np.savez(tmp, a=value)\n"
            "def k(p, a):\n    buf = io.BytesIO()\n    Image.fromarray(a).save(buf, format='PNG')\n"
            "    with atomic_path(p) as tmp:\n        img.save(tmp)\n    spec.save(p)\n"
            "    type(img).save(img, p, format='PNG')\n"
            "with atomic_path(p) as tmp:\n    plotter.screenshot(str(tmp))\n    mesh.export(tmp)\n"
            "data = scene.export(file_type='glb')\n")
    assert raw_writes(good) == []


def test_every_file_write_in_the_package_is_atomic():
    offenders = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).as_posix()
        if rel in _NOT_OUTPUTS or rel.startswith("examples/"):  # users' standalone scripts write as they like
            continue
        offenders += [f"{rel}:{line}: {what}" for line, what in raw_writes(path.read_text(encoding="utf-8"))
                      if (rel, what) not in _ALLOWED]
    assert not offenders, "writes that bypass woodcam._atomic (use write_text/write_bytes/atomic_path):\n" + \
        "\n".join(offenders)
