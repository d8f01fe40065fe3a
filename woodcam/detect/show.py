"""The check picture of a detection: every face's photo with the rings and knots found on it.

Faces are laid out as the unfolded cross of ``docs/conventions.md`` (left | front | right | back,
top above front, bottom below front), enlarged ``zoom`` times so one-pixel lines stay visible.
Drawn on each photo: the ring traces (red; pieces the detector linked into one ring,
``RingTrace.ring``, share one of :data:`RING_RGBS`, neighbouring ids differ, so a wrong link
shows as a colour jumping between lines), the knot masks' outlines (yellow) and, when a
reference ring map is given (e.g. Mokume's U-Net map), its ridge (cyan dots); the face's name
and Mokume letter at its top-left corner (:func:`woodcam.block.render.label_face`); a face the
block has no photo of is a labelled blank (``back (F): no photo``), and a photo with no ring traced
or mapped on it says so (``back (F): no rings``, :func:`ringless`).
"""

from __future__ import annotations

import numpy as np

from ..errors import WoodcamError
from ..frames import unfold_cross

TRACE_RGB = (230, 30, 30)
#: Colours of linked ring pieces, by ring id (cycled): warm, apart from the knot yellow and the
#: reference cyan.
RING_RGBS = ((230, 30, 30), (255, 140, 0), (255, 60, 200), (255, 255, 255))
KNOT_RGB = (255, 220, 0)
REFERENCE_RGB = (0, 230, 255)


def ringless(face) -> bool:
    """Whether ``face`` has a photo but neither ring traces nor a ring map: detection found no
    rings on it (it warned), and its picture showed the bare photo, like a face not yet looked at."""
    return face.photo is not None and not face.traces and face.ring_map is None


def face_picture(face, zoom: int = 2, reference_map: np.ndarray | None = None) -> np.ndarray:
    """``(h * zoom, w * zoom, 3)`` uint8: one face's photo with its traces, knots and reference,
    named at its top-left corner (``: no rings`` after the name when :func:`ringless`)."""
    from PIL import Image, ImageDraw
    from scipy import ndimage

    from ..block.render import label_face

    from .score import reference_ridge

    h, w = face.shape
    base = face.photo if face.photo is not None else np.full((h, w, 3), 40, np.uint8)
    im = Image.fromarray(np.asarray(base, np.uint8)).resize((w * zoom, h * zoom), Image.NEAREST)
    a = np.asarray(im).copy()
    if reference_map is not None:
        rr, cc = reference_ridge(reference_map).T
        a[rr * zoom + zoom // 2, cc * zoom + zoom // 2] = REFERENCE_RGB
    mask = face.extras.get("knot_mask")
    if mask is not None and np.any(mask):
        big = np.kron(np.asarray(mask, np.uint8), np.ones((zoom, zoom), np.uint8)).astype(bool)
        edge = big & ~ndimage.binary_erosion(big, iterations=max(1, zoom // 2))
        a[edge] = KNOT_RGB
    im = Image.fromarray(a)
    draw = ImageDraw.Draw(im)
    for t in face.traces:
        xy = ((t.points_px[:, ::-1] + 0.5) * zoom).ravel().tolist()
        rgb = TRACE_RGB if t.ring is None else RING_RGBS[t.ring % len(RING_RGBS)]
        draw.line(xy, fill=rgb, width=max(1, zoom // 2))
    return label_face(np.asarray(im), face.name, "no rings" if ringless(face) else "")


def rings_picture(block, zoom: int = 2, references: dict | None = None) -> np.ndarray:
    """The unfolded cross of :func:`face_picture` of every face of ``block`` (uint8 RGB).

    ``references``: optional face -> reference ring map ``(h, w)`` drawn as its ridge.
    """
    if not block.faces:
        raise WoodcamError(f"block {block.name!r} has no faces to show")
    if zoom < 1:
        raise WoodcamError(f"zoom (--zoom) must be a whole number >= 1; got {zoom!r}")
    from ..limits import check_limit

    # the cross of six faces is about 4 x 3 faces: refuse before PIL allocates it (--zoom 1e6
    # was a MemoryError traceback)
    px = 12 * max(f.shape[0] * f.shape[1] for f in block.faces.values()) * float(zoom) ** 2
    check_limit("MAX_IMAGE_PIXELS", px, f"the picture at --zoom {zoom}", fix="lower --zoom")
    from ..block.render import missing_face
    from ..frames import FACES, CrossLayout, face_image_size_mm

    refs = references or {}
    images = {n: face_picture(f, zoom, refs.get(n)) for n, f in block.faces.items()}
    first, im = next(iter(images.items()))
    layout = CrossLayout(block.size_mm, im.shape[1] / face_image_size_mm(first, block.size_mm)[1])
    images.update({n: missing_face(n, layout.face_shape(n), 24) for n in FACES if n not in images})
    return unfold_cross(images, block.size_mm, background=24)
