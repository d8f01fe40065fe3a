"""Vectorised OBJ text: numbers formatted in bulk with numpy, one ``bytes`` per block.

Why by hand: trimesh's OBJ exporter (and ``numpy.savetxt``) format every number through Python's
``str.format``; on the 400,000-triangle G-code preview that was ~4 of its ~15 CPU seconds. Here
a block of ``n`` rows becomes one ``(n, width)`` character matrix built with integer arithmetic
and a keep-mask that drops the leading zeros, so the cost is a few numpy passes over the bytes.
The text is the same OBJ (``v``/``vt``/``vn`` fixed-point with ``decimals`` digits, ``f a/b/c``
1-based) that any OBJ reader parses; trimesh reads it back to the same numbers (tested).
"""

from __future__ import annotations

import numpy as np

_ZERO = ord("0")


def _digits(q: np.ndarray, width: int) -> np.ndarray:
    """Decimal digits of non-negative ``q : (m,) int64`` as ``(m, width) uint8`` ASCII,
    most significant first (leading zeros included)."""
    pow10 = 10 ** np.arange(width - 1, -1, -1, dtype=np.int64)
    return ((q[:, None] // pow10) % 10 + _ZERO).astype(np.uint8)


def _ndigits(vmax: int) -> int:
    return max(1, len(str(int(vmax))))


def _number_fields(values: np.ndarray, decimals: int):
    """Fixed-point fields of ``values : (n, k)``: ``(chars (n, k, w) uint8, keep (n, k, w))``.

    Each field is ``[-]INT.FRAC`` with ``decimals`` fraction digits; leading zeros of the
    integer part (but its last digit) and the sign of values that round to zero are masked out.
    """
    v = np.asarray(values, np.float64)
    n, k = v.shape
    big = float(np.abs(v).max(initial=0.0))
    while decimals > 0 and big * 10.0 ** decimals >= 2.0 ** 62:  # int64 fixed point
        decimals -= 1
    scale = 10 ** decimals
    q = np.rint(np.abs(v) * scale).astype(np.int64).ravel()
    ip, fp = np.divmod(q, scale)
    wi = _ndigits(ip.max(initial=0))
    w = 1 + wi + 1 + decimals
    chars = np.empty((n * k, w), np.uint8)
    chars[:, 0] = ord("-")
    chars[:, 1: 1 + wi] = _digits(ip, wi)
    chars[:, 1 + wi] = ord(".")
    if decimals:
        chars[:, 2 + wi:] = _digits(fp, decimals)
    keep = np.ones((n * k, w), bool)
    keep[:, 0] = (v.ravel() < 0) & (q > 0)
    # integer digits before the first significant one go (keep at least the units digit)
    lead = np.cumsum(chars[:, 1: wi] != _ZERO, axis=1) > 0
    keep[:, 1: wi] = lead
    return chars.reshape(n, k, w), keep.reshape(n, k, w)


def _int_fields(values: np.ndarray):
    """Decimal fields of non-negative ints ``values : (n, k)`` without leading zeros."""
    v = np.asarray(values, np.int64)
    n, k = v.shape
    w = _ndigits(v.max(initial=0))
    chars = _digits(v.ravel(), w)
    keep = np.ones_like(chars, bool)
    keep[:, :-1] = np.cumsum(chars[:, :-1] != _ZERO, axis=1) > 0
    return chars.reshape(n, k, w), keep.reshape(n, k, w)


def _join(prefix: bytes, chars: np.ndarray, keep: np.ndarray, sep: bytes) -> bytes:
    """Rows ``prefix FIELD sep FIELD ... \\n`` from ``(n, k, w)`` fields and their keep-mask."""
    n, k, w = chars.shape
    if n == 0:
        return b""
    p, s = np.frombuffer(prefix, np.uint8), np.frombuffer(sep, np.uint8)
    # each field is preceded by the row prefix (first) or the separator (others)
    lead_w = max(len(p), len(s))
    cell = np.zeros((n, k, lead_w + w), np.uint8)
    ckeep = np.zeros((n, k, lead_w + w), bool)
    cell[:, 0, lead_w - len(p): lead_w] = p
    ckeep[:, 0, lead_w - len(p): lead_w] = True
    cell[:, 1:, lead_w - len(s): lead_w] = s
    ckeep[:, 1:, lead_w - len(s): lead_w] = True
    cell[:, :, lead_w:] = chars
    ckeep[:, :, lead_w:] = keep
    row = np.concatenate([cell.reshape(n, -1), np.full((n, 1), ord("\n"), np.uint8)], axis=1)
    rkeep = np.concatenate([ckeep.reshape(n, -1), np.ones((n, 1), bool)], axis=1)
    return row[rkeep].tobytes()


def obj_body(vertices, uv, normals, faces, *, decimals: int = 9) -> bytes:
    """``v``, ``vt``, ``vn`` and ``f`` lines of one textured mesh.

    ``vertices, normals : (n, 3)``, ``uv : (n, 2)`` share one index per vertex (as
    :func:`woodcam.bake.bake` meshes do), so each face corner is ``i/i/i`` (1-based);
    ``faces : (m, 3)`` int. Coordinates carry ``decimals`` fraction digits; ``vt`` and ``vn``
    carry 9 (unit range)."""
    parts = []
    for prefix, values, digits in ((b"v ", vertices, decimals), (b"vt ", uv, 9),
                                   (b"vn ", normals, 9)):
        if values is not None:
            chars, keep = _number_fields(values, digits)
            parts.append(_join(prefix, chars, keep, b" "))
    chars, keep = _int_fields(np.asarray(faces, np.int64) + 1)  # (m, 3, w)
    if uv is not None and normals is not None:
        copies, sep = 3, b"/"  # a/a/a
    elif uv is not None:
        copies, sep = 2, b"/"  # a/a
    elif normals is not None:
        copies, sep = 2, b"//"  # a//a
    else:
        copies, sep = 1, b""
    m = chars.shape[0]
    s = np.broadcast_to(np.frombuffer(sep, np.uint8), (m, 3, len(sep)))
    s_keep = np.ones((m, 3, len(sep)), bool)
    pieces, masks = [chars], [keep]
    for _ in range(copies - 1):
        pieces += [s, chars]
        masks += [s_keep, keep]
    parts.append(_join(b"f ", np.concatenate(pieces, axis=2), np.concatenate(masks, axis=2),
                       b" "))
    return b"".join(parts)
