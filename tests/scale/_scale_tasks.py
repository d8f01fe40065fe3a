"""Cheap tasks for the task-runner tests: module-level, so worker processes can import them."""

from __future__ import annotations

import math
import os
import time
import uuid
from pathlib import Path


def value_of(key: str) -> float:
    """A deterministic function of the key alone."""
    i = int(key[1:])
    return sum(math.sin(k * (i + 1)) for k in range(2000))


def slow(key: str, log_dir: str, sleep_s: float = 0.3) -> dict:
    """Sleeps, then leaves a marker ``log_dir/<key>.<unique>`` saying it completed once."""
    time.sleep(sleep_s)
    v = value_of(key)
    Path(log_dir, f"{key}.{uuid.uuid4().hex}").touch()
    return {"value": v}


def flaky(key: str, log_dir: str) -> dict:
    """Marks every attempt; key ``k3`` always raises."""
    Path(log_dir, f"{key}.{uuid.uuid4().hex}").touch()
    if key == "k3":
        raise ValueError(f"task {key} refuses on purpose")
    return {"value": value_of(key)}


def spin(key: str, n: int) -> dict:
    """CPU-bound pure-Python work of ``n`` iterations (for speed-up and overhead figures)."""
    s = 0.0
    for k in range(n):
        s += math.sin(k)
    return {"s": s}


def where(key: str) -> dict:
    """The process that ran the task (for the separate-cluster test only)."""
    return {"pid": os.getpid(), "value": value_of(key)}


def hog(key: str, mb: int) -> dict:
    """Allocates and touches ``mb`` MiB."""
    buf = bytearray(mb * 1024 * 1024)
    return {"n": len(buf)}
