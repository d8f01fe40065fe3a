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
