"""Ctrl-C ends the command, even where a library swallowed it.

Python turns SIGINT into a ``KeyboardInterrupt`` raised wherever the main thread happens to be.
In the first seconds of a command that is often inside an import, and libraries catch it there:
trimesh wraps its optional imports in ``except BaseException`` (so the bake went on and ended
with exit 0), scipy is left half-imported and fails later with ``NameError: _ndimage_api`` (an
error, exit 1). So the interrupt is also *recorded*:

* :func:`handling` -- the command's SIGINT handler for the length of a block (``woodcam.cli.main``):
  it sets the flag, then raises ``KeyboardInterrupt`` as Python's own handler does (an
  :class:`Interrupted`).
* :func:`check` -- a checkpoint: raises ``KeyboardInterrupt`` again once an interrupt was
  recorded. Called at the natural steps of the work (each progress-bar step and stage, each
  pipeline stage) and before every atomic file lands (:mod:`woodcam._atomic`), so a swallowed
  Ctrl-C stops the run promptly and writes nothing after it.
* :func:`requested` -- whether one was recorded: the CLI maps any end of the run after it (an
  exception of any kind, or a normal return) to the interrupt's exit status.
* :func:`say` -- the command's one line about it, printed once per command.

The process's own command (``handling(process=True)``, ``woodcam`` from a shell) keeps its
handler to the end of the process: Python's would come back as the command returns, and a
Ctrl-C in the process's last moments (threads joined, ``atexit`` callbacks, the interpreter
tearing down numba, scipy and torch: 0.3-0.5 s) then ended it by the signal itself (status -2 as
``subprocess`` sees it, 130 as a shell shows it, no line) or with a traceback. Once the command
has ended (:func:`ended`) a Ctrl-C ends the process at once: its line unless said, exit 130.
The interpreter's last phase runs no Python handler at all and would put SIGINT back to the
kernel's default (killed by the signal): from the last ``atexit`` callback on, SIGINT is ignored,
so a Ctrl-C there leaves the process to exit as the command ended (all its output written and
flushed by then). The interpreter's own start and ``import woodcam.cli`` (~0.1 s) come before
any handler of woodcam's and stay Python's.

Outside :func:`handling` (the library API, tests) the flag is never set and :func:`check` costs
one global read.
"""

from __future__ import annotations

import atexit
import contextlib
import os
import signal
import sys
import threading
from collections.abc import Iterator
from typing import NoReturn

#: The command's one line about an interrupt (standard error).
LINE = "woodcam: interrupted"
#: Its exit status, 128 + SIGINT as a shell reports a command that Ctrl-C ended.
EXIT_INTERRUPTED = 130

_requested = False
_said = False  # the line was printed for this command
_process = False  # the block is the process's own command: its handler stays to the end
_ended = False  # that command has ended: a Ctrl-C ends the process


class Interrupted(KeyboardInterrupt):
    """The ``KeyboardInterrupt`` a Ctrl-C raises inside :func:`handling` (and :func:`check`):
    caught as any ``KeyboardInterrupt``, but not one itself to CPython's exit. CPython 3.11
    (and later) marks the process "ended by an unhandled Ctrl-C" whenever an exact
    ``KeyboardInterrupt`` leaves code run from a string (``exec``/``eval`` of source, as numba,
    dataclasses and namedtuple do), even one caught later; ``python -m woodcam`` then killed
    itself by SIGINT after the command had printed its line and returned 130 (status -2 as
    ``subprocess`` sees it). The check is by identity, so a subclass never sets that mark."""


def requested() -> bool:
    """Whether a Ctrl-C arrived inside the current :func:`handling` block."""
    return _requested


def check() -> None:
    """Raise ``KeyboardInterrupt`` if a Ctrl-C was recorded (a library may have swallowed the
    first one). Only on the main thread, where Python delivers Ctrl-C itself: a worker thread
    raising it would die with a traceback instead of ending the command."""
    if _requested and threading.current_thread() is threading.main_thread():
        raise Interrupted


def say() -> None:
    """Print :data:`LINE` to standard error, once per command."""
    global _said
    if not _said:
        _said = True
        print(LINE, file=sys.stderr)


def ended() -> None:
    """The process's own command has ended (returned, or is leaving by an exception such as
    argparse's ``SystemExit``): from here a Ctrl-C ends the process at once (:func:`_leave`)
    instead of raising ``KeyboardInterrupt`` into the interpreter's exit. A no-op outside
    ``handling(process=True)``."""
    global _ended
    _ended = _process


def _leave() -> NoReturn:
    """End the process for a Ctrl-C after its command ended: the line unless the command said it,
    standard output flushed, exit 130 -- now, skipping the rest of the interpreter's exit (the
    threads it joins and the ``atexit`` callbacks: a Ctrl-C is how a user leaves one that
    hangs). The line is written straight to the descriptor where the stream is in use (the
    handler runs between two bytecodes of the main thread, which may be inside its write)."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    if not _said:
        try:
            sys.stderr.write(LINE + "\n")
            sys.stderr.flush()
        except Exception:  # noqa: BLE001 - a reentrant write, a closed stream: the bare descriptor
            with contextlib.suppress(OSError):
                os.write(2, (LINE + "\n").encode())
    os._exit(EXIT_INTERRUPTED)


def _ignore_from_here() -> None:
    """The last ``atexit`` callback of the process's command (registered as the command starts,
    so it runs after those registered during the work): SIGINT ignored from here, where Python
    would soon put the kernel's default back (see the module's docstring)."""
    if _ended and signal.getsignal(signal.SIGINT) is _on_sigint:
        signal.signal(signal.SIGINT, signal.SIG_IGN)


def _on_sigint(signum, frame) -> None:
    global _requested
    if _ended:
        _leave()
    _requested = True
    raise Interrupted


@contextlib.contextmanager
def handling(process: bool = False) -> Iterator[None]:
    """Record every Ctrl-C of the block (the flag starts clear) and restore the previous SIGINT
    handler and a clear flag at its end. A no-op off the main thread (signals cannot be handled
    there), and where SIGINT is not Python's own handler: a parent that ignored it (``nohup``,
    ``cmd &`` in a script) meant the command to run on through Ctrl-C, an embedding program's
    handler is its own (and one set outside Python reads as None, which cannot be restored).

    ``process``: the block is the process's own command (``woodcam`` run from a shell): the
    handler is kept after the block, to the process's end, and a Ctrl-C after :func:`ended`
    ends the process with exit 130 (see the module's docstring)."""
    global _requested, _said, _process, _ended
    _said = _ended = False
    if (threading.current_thread() is not threading.main_thread()
            or signal.getsignal(signal.SIGINT) is not signal.default_int_handler):
        yield
        return
    _requested, _process = False, process
    previous = signal.signal(signal.SIGINT, _on_sigint)
    if process:
        atexit.register(_ignore_from_here)
    stdout = sys.stdout
    if stdout is not None:  # None under pythonw, where print() writes nowhere
        sys.stdout = _MutedAfterCtrlC(stdout)  # type: ignore[assignment]
    try:
        yield
    finally:
        if isinstance(sys.stdout, _MutedAfterCtrlC) and sys.stdout.stream is stdout:
            sys.stdout = stdout
        if not process:
            signal.signal(signal.SIGINT, previous)
        _requested = False


class _MutedAfterCtrlC:
    """Standard output inside :func:`handling`: what is written goes through until a Ctrl-C is
    recorded, and is dropped after it. A library that swallows the Ctrl-C may say so on
    standard output: OCP's ``IVtk`` modules (imported by ``cadquery``) wrap ``import vtk``, 2 s,
    in a bare ``except`` that prints 'VTK not installed', so a Ctrl-C while a cadquery part
    script imported added that line to the command's one. An interrupted command's output is
    its one line (its work is dropped too). Everything else is the stream's own."""

    def __init__(self, stream) -> None:
        self.stream = stream

    def write(self, text: str) -> int:
        return len(text) if _requested else self.stream.write(text)

    def writelines(self, lines) -> None:
        for line in lines:
            self.write(line)

    def __getattr__(self, name: str):
        return getattr(self.stream, name)


@contextlib.contextmanager
def held() -> Iterator[None]:
    """Hold a Ctrl-C back for a short block that must finish whole (the renames of a set of
    outputs: microseconds): one arriving inside it is raised as the block ends, through the
    SIGINT handler that was in place (so :func:`handling` records it as before).

    The Python handler is swapped rather than the signal masked: ``pthread_sigmask`` blocks
    SIGINT for the calling thread only, and the kernel hands a process-wide SIGINT to any thread
    that has it unblocked (numba, OpenMP, torch, progress-bar threads); Python then runs its
    handler on the main thread mid-block all the same (seen: a set left as old, new, new).
    A no-op off the main thread, and where the handler was set outside Python (None: it could
    not be put back)."""
    previous = signal.getsignal(signal.SIGINT)
    if threading.current_thread() is not threading.main_thread() or previous is None:
        yield
        return
    caught: list = []
    signal.signal(signal.SIGINT, lambda signum, frame: caught.append(frame))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
        if caught and callable(previous):
            previous(signal.SIGINT, caught[0])
        elif caught and previous == signal.SIG_DFL:
            signal.raise_signal(signal.SIGINT)


__all__: list[str] = []
