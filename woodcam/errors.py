"""Exceptions raised by woodcam.

Every error names the argument, the rule it broke, the value received and a fix. The CLI turns a
:class:`WoodcamError` into one clean line on stderr and a non-zero exit, never a traceback.
"""

from __future__ import annotations


class WoodcamError(ValueError):
    """Base class of the errors a user can cause and fix (bad input, bad option, missing extra)."""


class UsageError(WoodcamError):
    """The command line itself is wrong (an ``--out`` that breaks the output rule, options that
    contradict each other): caught before any work; the CLI exits 2, like argparse."""


class BlockSpecError(WoodcamError):
    """A block spec that breaks its grammar (:func:`woodcam._specs.parse_spec`); the message
    names the spec in mm. ``part`` says which part ("size": the base's ``:WxDxH``; "resize",
    "turn", "op": an operation not in the grammar; "log": ``log:LOG@KNOT``), ``text`` is that
    part as written and ``rule`` the message without the spec, so the command line can say it
    of its ``--block`` in the units typed; ``spec`` is the whole spec where the error knows it
    (a resize past its block, found when the block is opened: the command line tells a spec
    typed there, a usage error, from one a GLB recorded)."""

    def __init__(self, message: str, *, part: str = "", text: str = "", rule: str = "", spec: str = ""):
        super().__init__(message)
        self.part, self.text, self.rule, self.spec = part, text, rule, spec


class BlockFolderError(WoodcamError):
    """A folder given as a block that is none (no ``block.json``, no Mokume files: an empty
    folder, or one of face photos not yet made a block); ``folder`` is that folder, as given,
    so the command line names the argument that gave it (``--block``, ``--veneer-from``). The
    folder is there and a folder, so the door let it through: its contents are wrong (exit 1,
    as any input whose contents are bad)."""

    def __init__(self, message: str, *, folder=None):
        super().__init__(message)
        self.folder = folder


class MissingDependencyError(WoodcamError, ImportError):
    """An optional dependency is not installed; the message gives the install command."""


def require(module: str, extra: str, purpose: str):
    """Import an optional heavy module where it is used, failing with the install command.

    Parameters
    ----------
    module : str
        Importable module name, e.g. ``"build123d"``.
    extra : str
        The ``woodcam`` extra that installs it, e.g. ``"cad"``.
    purpose : str
        What the caller needs it for, shown in the error.
    """
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError as err:  # pragma: no cover - depends on the environment
        raise MissingDependencyError(
            f"{purpose} needs the optional package {module!r}, which is not installed; "
            f"install it with: pip install 'woodcam[{extra}]'"
        ) from err


def caused_by(err: BaseException | None, kind: type[BaseException]) -> bool:
    """Whether an exception of ``kind`` is ``err`` or among its causes (``__cause__``, else
    ``__context__``, followed to the end; a cycle stops): libraries re-raise what they caught as
    their own error (numba's compiler a Ctrl-C as a RuntimeError, pybind11's import an alarm as
    an ImportError)."""
    seen = set()
    while err is not None and id(err) not in seen:
        if isinstance(err, kind):
            return True
        seen.add(id(err))
        err = err.__cause__ or err.__context__
    return False


class WoodcamWarning(UserWarning):
    """Something the user should know about but woodcam could carry on with (e.g. a part that
    sticks out of the block is carved anyway and the lost volume is reported)."""
