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

from collections.abc import Iterable
from typing import Any

#: Seconds before a bar is drawn: the brief's "progress bars on anything over ~2 s".
PROGRESS_DELAY_S = 2.0


def progress_bar(iterable: Iterable | None = None, *, desc: str, unit: str, enabled: bool = True,
                 **kwargs: Any):
    """A ``tqdm.auto.tqdm`` over ``iterable`` (or with ``total=`` and manual ``update``) drawn
    on a terminal after :data:`PROGRESS_DELAY_S` only (module docstring); ``enabled=False``
    never draws it. ``kwargs`` go to tqdm (``total``, ``initial``, ``leave``, ...)."""
    from tqdm.auto import tqdm

    kwargs.setdefault("delay", PROGRESS_DELAY_S)
    return tqdm(iterable, desc=desc, unit=unit, disable=None if enabled else True, **kwargs)


def write(line: str) -> None:
    """Print ``line`` to stdout without breaking a bar being drawn (``tqdm.write``)."""
    from tqdm.auto import tqdm

    tqdm.write(line)


__all__: list[str] = []
