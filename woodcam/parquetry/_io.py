"""The PNG writer of the parquetry outputs (text outputs use :func:`woodcam._atomic.write_text`
directly): through :mod:`woodcam._atomic`, so complete or absent, with the user's usual
permissions."""

from __future__ import annotations

from pathlib import Path

from .._atomic import write_bytes


def atomic_write_png(path, rgb) -> Path:
    """``rgb (h, w, 3)`` float in [0, 1] or uint8 -> PNG at ``path`` (its folder made if needed)."""
    import io

    import numpy as np
    from PIL import Image

    a = np.asarray(rgb)
    if a.dtype != np.uint8:
        a = (np.clip(a, 0, 1) * 255 + 0.5).astype(np.uint8)
    buf = io.BytesIO()
    Image.fromarray(a).save(buf, format="PNG")
    return write_bytes(path, buf.getvalue(), mkdir=True)
