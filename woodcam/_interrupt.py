"""Ctrl-C ends the command, even where a library swallowed it.

Python turns SIGINT into a ``KeyboardInterrupt`` raised wherever the main thread happens to be.
In the first seconds of a command that is often inside an import, and libraries catch it there:
trimesh wraps its optional imports in ``except BaseException`` (so the bake went on and ended
with exit 0), scipy is left half-imported and fails later with ``NameError: _ndimage_api`` (an
error, exit 1). So the interrupt is also *recorded*:

* :func:`handling` -- the command's SIGINT handler for the length of a block (``woodcam.cli.main``):
  it sets the flag, then raises ``KeyboardInterrupt`` as Python's own handler does.
* :func:`check` -- a checkpoint: raises ``KeyboardInterrupt`` again once an interrupt was
  recorded. Called at the natural steps of the work (each progress-bar step and stage, each
  pipeline stage) and before every atomic file lands (:mod:`woodcam._atomic`), so a swallowed
  Ctrl-C stops the run promptly and writes nothing after it.
* :func:`requested` -- whether one was recorded: the CLI maps any end of the run after it (an
  exception of any kind, or a normal return) to the interrupt's exit status.

Outside :func:`handling` (the library API, tests) the flag is never set and :func:`check` costs
one global read.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator

_requested = False


def requested() -> bool:
    """Whether a Ctrl-C arrived inside the current :func:`handling` block."""
    return _requested


def check() -> None:
    """Raise ``KeyboardInterrupt`` if a Ctrl-C was recorded (a library may have swallowed the
    first one). Only on the main thread, where Python delivers Ctrl-C itself: a worker thread
    raising it would die with a traceback instead of ending the command."""
    if _requested and threading.current_thread() is threading.main_thread():
        raise KeyboardInterrupt


def _on_sigint(signum, frame) -> None:
    global _requested
    _requested = True
    raise KeyboardInterrupt


@contextlib.contextmanager
def handling() -> Iterator[None]:
    """Record every Ctrl-C of the block (the flag starts clear) and restore the previous SIGINT
    handler and a clear flag at its end. A no-op off the main thread (signals cannot be handled
    there), and where SIGINT is not Python's own handler: a parent that ignored it (``nohup``,
    ``cmd &`` in a script) meant the command to run on through Ctrl-C, an embedding program's
    handler is its own (and one set outside Python reads as None, which cannot be restored)."""
    global _requested
    if (threading.current_thread() is not threading.main_thread()
            or signal.getsignal(signal.SIGINT) is not signal.default_int_handler):
        yield
        return
    _requested = False
    previous = signal.signal(signal.SIGINT, _on_sigint)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
        _requested = False


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
