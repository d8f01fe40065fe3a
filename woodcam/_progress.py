"""Progress bars: tqdm with the project's defaults, in one place.

- **Only for work that lasts**: a bar appears after :data:`PROGRESS_DELAY_S` (the brief: bars on
  anything over about 2 s), so a step that ends sooner prints nothing (``make demo``'s log held
  a bar for every 0.02-0.3 s rasterisation).
- **Only on a terminal**: written to a file or a pipe (a log, CI), tqdm's redraws pile up on
  one line and its last state is printed twice, once by the last step and once by ``close``;
  there the bar is off (tqdm's own ``disable=None`` rule: the stream is not a tty). In a
  Jupyter notebook ``tqdm.auto`` draws its widget as before. Lines of a command's own
  (:func:`write`) are printed either way.
- On stderr (tqdm's default), so stdout stays the command's output.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
import functools
import time
from typing import Any

from . import _interrupt

#: Seconds before a bar is drawn: the brief's "progress bars on anything over ~2 s".
PROGRESS_DELAY_S = 2.0

_silenced = False  # inside silenced(True): no bar is drawn


@contextmanager
def silenced(on: bool = True) -> Iterator[None]:
    """No bar is drawn inside the block when ``on`` (a command's ``--quiet``), whichever library
    call draws it; lines of a command's own (:func:`write`) are printed as before."""
    global _silenced
    before, _silenced = _silenced, _silenced or on
    try:
        yield
    finally:
        _silenced = before


def progress_bar(iterable: Iterable | None = None, *, desc: str, unit: str, enabled: bool = True,
                 **kwargs: Any):
    """A ``tqdm.auto.tqdm`` over ``iterable`` (or with ``total=`` and manual ``update``) drawn
    on a terminal after :data:`PROGRESS_DELAY_S` only (module docstring); ``enabled=False``
    never draws it, nor does one inside :func:`silenced`. ``kwargs`` go to tqdm (``total``,
    ``initial``, ``leave``, ...). Each step, drawn or not, is a Ctrl-C checkpoint
    (:func:`woodcam._interrupt.check`)."""
    _interrupt.check()
    kwargs.setdefault("delay", PROGRESS_DELAY_S)
    return _bar_class()(iterable, desc=desc, unit=unit,
                        disable=None if enabled and not _silenced else True, **kwargs)


@functools.cache
def _bar_class():
    """``tqdm.auto.tqdm`` whose every step checks for a recorded Ctrl-C: the loops under a bar
    are where a command spends its time, so one a library swallowed ends the run there."""
    from tqdm.auto import tqdm

    class _Bar(tqdm):
        def __iter__(self):
            for item in super().__iter__():
                _interrupt.check()
                yield item

        def update(self, n=1):
            _interrupt.check()
            return super().update(n)

    return _Bar


def write(line: str, file=None) -> None:
    """Print ``line`` to ``file`` (default stdout) without breaking a bar being drawn
    (``tqdm.write``)."""
    from tqdm.auto import tqdm

    tqdm.write(line, file=file)


class StageBar:
    """A bar of one step per stage, for work that is not a loop (a bake: open the block, load
    the part, carve, bake, export...): its description names the stage running now.

    ``stages`` is the plan, in order (its length is the bar's total); :meth:`stage` wraps each
    as it runs. Drawn like
    :func:`progress_bar` (after :data:`PROGRESS_DELAY_S`, on a terminal only), but a timer draws
    it once the delay has passed even in the middle of a stage: tqdm draws a delayed bar only at
    its next step, and one stage (a fit, a neural training) can last minutes.
    """

    def __init__(self, stages: Sequence[str], *, desc: str, enabled: bool = True, **kwargs: Any):
        self.stages = list(stages)
        self.desc = desc
        self._delay = kwargs.setdefault("delay", PROGRESS_DELAY_S)
        self._t0 = time.monotonic()
        self.bar = progress_bar(total=len(self.stages), desc=desc, unit="stage", enabled=enabled,
                                **kwargs)
        self._timer = None
        if not self.bar.disable:
            import threading

            self._timer = threading.Timer(self._delay, self.bar.refresh)
            self._timer.daemon = True
            self._timer.start()

    @contextmanager
    def stage(self, name: str) -> Iterator[None]:
        """Run one stage of the plan: named in the bar while it runs, one step when it ends.
        A Ctrl-C checkpoint as it starts (the bar's step checks as it ends)."""
        _interrupt.check()
        # redrawn at once only where the bar is drawn already (past the delay)
        self.bar.set_description_str(f"{self.desc}: {name}",
                                     refresh=time.monotonic() - self._t0 >= self._delay)
        yield
        self.bar.update(1)

    def close(self) -> None:
        """Stop the timer and close the bar (left on screen when drawn, as tqdm's are)."""
        if self._timer is not None:
            self._timer.cancel()
        self.bar.set_description_str(self.desc, refresh=False)
        self.bar.close()

    def __enter__(self) -> StageBar:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


__all__: list[str] = []
