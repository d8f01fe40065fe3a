"""File writes of the parquetry outputs, through :mod:`woodcam._atomic` (temp file in the same
folder, fsync, rename; the files get the user's usual permissions)."""

from __future__ import annotations

from pathlib import Path

from .._atomic import write_bytes


def atomic_write_bytes(path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically, making its folder if needed."""
    return write_bytes(path, data, mkdir=True)


def atomic_write_text(path, text: str) -> Path:
    return atomic_write_bytes(path, text.encode("utf-8"))


def atomic_write_png(path, rgb) -> Path:
    """``rgb (h, w, 3)`` float in [0, 1] or uint8 -> PNG."""
    import io

    import numpy as np
    from PIL import Image

    a = np.asarray(rgb)
    if a.dtype != np.uint8:
        a = (np.clip(a, 0, 1) * 255 + 0.5).astype(np.uint8)
    buf = io.BytesIO()
    Image.fromarray(a).save(buf, format="PNG")
    return atomic_write_bytes(path, buf.getvalue())
