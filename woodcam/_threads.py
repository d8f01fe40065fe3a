"""Thread limits for small linear algebra and small torch nets.

On a busy 2-core machine OpenBLAS' worker threads spin against each other on small systems:
measured 40x slower for the radial fit's normal equations (0.2 s vs 5 ms per solve) and 0.79
vs 0.02 CPU-s for the built-in blocks' Laplacian smoother (a 360 x 350 least squares), which
every ``woodcam gcode``/``bake`` run of a built-in block pays once.
"""

from __future__ import annotations

import contextlib
import functools
from collections.abc import Callable
from typing import Any, TypeVar, cast


def one_blas_thread():
    """A context manager limiting BLAS to one thread (threadpoolctl); without threadpoolctl
    nothing is limited."""
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # pragma: no cover - depends on the environment
        return contextlib.nullcontext()
    return threadpool_limits(1, user_api="blas")


@contextlib.contextmanager
def torch_threads(torch, n: int):
    """Run the block with torch on ``n`` intra-op threads, then restore its setting (a small net
    on a loaded 2-core machine spends several times the CPU on two threads)."""
    old = torch.get_num_threads()
    torch.set_num_threads(int(n))
    try:
        yield
    finally:
        torch.set_num_threads(old)


_F = TypeVar("_F", bound=Callable[..., Any])


def restores_torch_threads(fn: _F) -> _F:
    """Decorate a trainer that sets torch's intra-op threads for its run (one thread on a shared
    machine): the caller's setting is put back when it returns or raises. The trainers set it
    and left it, so a notebook's torch work after ``train_gtf`` ran on one thread for good."""
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        try:
            import torch
        except ImportError:       # the trainer says what to install
            return fn(*args, **kwargs)
        old = torch.get_num_threads()
        try:
            return fn(*args, **kwargs)
        finally:
            torch.set_num_threads(old)

    return cast(_F, wrapper)
