"""A block's faces as one unfolded-cross picture (photos or ring maps, traces drawn on top).

Layout from :func:`woodcam.frames.unfold_cross` (``docs/conventions.md``): left | front |
right | back in the middle row, top above front, bottom below front; each face seen from
outside the block.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from .._atomic import atomic_path
from ..errors import WoodcamError
from ..frames import MOKUME_LETTER, CrossLayout, FACES, face_image_size_mm, unfold_cross
from .block import Block

Layer = Literal["photo", "ring_map", "both"]

# Trace colours cycle with the year (unlabelled traces are white).
_PALETTE = np.array([
    (230, 25, 75), (60, 180, 75), (0, 130, 200), (245, 130, 48), (145, 30, 180),
    (70, 240, 240), (240, 50, 230), (210, 245, 60),
], dtype=np.uint8)


#: Height of a face's name on its picture, as a share of the face's shorter side (at least
#: :data:`LABEL_MIN_PX`): read at a glance on a 256 px face at --zoom 2, covering little of it.
LABEL_SHARE = 1 / 16
LABEL_MIN_PX = 10


def label_face(rgb: np.ndarray, face: str, note: str = "") -> np.ndarray:
    """``rgb`` (rows, cols, 3) uint8, a picture of ``face``, with the face's name and Mokume
    letter (``front (A)``), and ``note`` after it (``back (F): no photo``), in white on a dark box
    at its top-left corner: six unlabelled faces in a cross left the user to work out from
    ``docs/conventions.md`` which photo was which."""
    from PIL import Image, ImageDraw, ImageFont

    im = Image.fromarray(np.asarray(rgb, np.uint8))
    size = max(LABEL_MIN_PX, round(min(im.size) * LABEL_SHARE))
    font = ImageFont.load_default(size=size)
    draw = ImageDraw.Draw(im)
    pad = max(2, size // 4)
    text = (f"{face} ({MOKUME_LETTER[face]})" if face in MOKUME_LETTER else face) + (f": {note}" if note else "")
    x0, y0, x1, y1 = draw.textbbox((pad, pad), text, font=font)
    draw.rectangle((0, 0, x1 + pad, y1 + pad), fill=(24, 24, 24))
    draw.text((pad, pad), text, fill=(255, 255, 255), font=font)
    return np.asarray(im)


def missing_face(face: str, shape: tuple[int, int], background: int) -> np.ndarray:
    """The slot of a face the block has no photo of (``block from-photos --partial``), ``shape``
    (rows, cols), ``background`` grey and labelled ``back (F): no photo``: it was left blank and
    unnamed, a hole in the cross that could be a dark face or a drawing fault."""
    return label_face(np.full((*shape, 3), background, np.uint8), face, "no photo")


def _face_rgb(face, layer: str) -> np.ndarray | None:
    if layer == "photo" and face.photo is not None:
        return np.asarray(face.photo, dtype=np.uint8)
    if layer == "ring_map" and face.ring_map is not None:
        g = np.clip(np.round(np.asarray(face.ring_map, float) * 255), 0, 255).astype(np.uint8)
        return np.repeat(g[..., None], 3, axis=2)
    return None


def cross_image(block: Block, layer: Layer = "photo", *, traces: bool = True,
                px_per_mm: float | None = None, background: int = 24,
                line_width: int = 1) -> np.ndarray:
    """Unfolded-cross RGB picture ``(rows, cols, 3)`` uint8 of ``block``.

    Parameters
    ----------
    layer : "photo" | "ring_map" | "both"
        Face photos, ring maps, or both crosses stacked (photos above).
    traces : bool
        Draw the traced rings, coloured by year (white when unlabelled).
        Each face is named at its top-left corner (:func:`label_face`), a missing one as such
        (:func:`missing_face`).
    px_per_mm : float, optional
        Picture density; default the densest face's. Faces at another density are resampled.
    background : int
        Grey level of the cross's empty corners and of faces with nothing to show.
    """
    from PIL import Image, ImageDraw

    if layer not in ("photo", "ring_map", "both"):
        raise WoodcamError(f"layer must be 'photo', 'ring_map' or 'both'; got {layer!r}")
    if layer == "both":
        a = cross_image(block, "photo", traces=traces, px_per_mm=px_per_mm, background=background)
        b = cross_image(block, "ring_map", traces=traces, px_per_mm=px_per_mm, background=background)
        return np.concatenate([a, np.full((8,) + a.shape[1:], background, np.uint8), b], axis=0)
    if not block.faces:
        raise WoodcamError(f"block {block.name!r} must have at least one face to draw; it has none")
    if px_per_mm is None:
        px_per_mm = max(f.shape[1] / face_image_size_mm(n, block.size_mm)[1] for n, f in block.faces.items())
    # unfold_cross infers the density from the first face's width (front, in FACES order), so
    # snap the density to a whole number of pixels across W to keep every face shape consistent.
    W = block.size_mm[0]
    layout = CrossLayout(block.size_mm, max(1, round(W * float(px_per_mm))) / W)
    images = {}
    for name in FACES:
        shape = layout.face_shape(name)
        face = block.faces.get(name)
        rgb = None if face is None else _face_rgb(face, layer)
        im = Image.fromarray(rgb) if rgb is not None else Image.new("RGB", shape[::-1], (background,) * 3)
        if im.size != shape[::-1]:
            im = im.resize(shape[::-1], Image.BILINEAR)
        if traces and face is not None and face.traces:
            draw = ImageDraw.Draw(im)
            sr, sc = shape[0] / face.shape[0], shape[1] / face.shape[1]
            for t in face.traces:
                # pixel centres sit at integer coordinates; PIL's at +0.5
                xy = ((t.points_px[:, ::-1] + 0.5) * (sc, sr)).ravel().tolist()
                col = (255, 255, 255) if t.year is None else tuple(int(v) for v in _PALETTE[t.year % len(_PALETTE)])
                draw.line(xy, fill=col, width=line_width)
        images[name] = label_face(np.asarray(im), name) if face is not None else missing_face(name, shape, background)
    return unfold_cross(images, block.size_mm, background=background)


def save_cross_png(block: Block, path, layer: Layer = "photo", **kwargs) -> None:
    """Write :func:`cross_image` of ``block`` to ``path`` as PNG."""
    from PIL import Image

    with atomic_path(path, mkdir=True) as tmp:  # a missing --out folder failed after the work
        Image.fromarray(cross_image(block, layer, **kwargs)).save(tmp, format="PNG")
