"""Is each face laid out as the conventions say? Rings meet across the block's edges.

A ring boundary that reaches an edge of the block goes on over it, so along each of the 12
edges the ring crossings seen on the two faces meeting there coincide (``docs/conventions.md``:
"edges that touch in the unfolded cross touch on the block"). A face photographed mirrored or
turned 90/180 degrees breaks that on all its edges at once, and on a cube the aspect check of
:func:`woodcam.block.photos.block_from_photos` cannot see it.

For each pair of faces meeting at an edge, each face's image (its ring map, or its photo's
luminance: :func:`check_face_layout`) is read along a thin strip beside the shared edge
(:data:`STRIP_PX`, at least :data:`STRIP_MM`, mapped by :func:`woodcam.frames.block_to_pixel`)
into a 1-D profile over mm along the edge; the two profiles are band-passed and scored by their
normalised cross-correlation, the best within +-:data:`SHIFT_MM`.
A face's score is the mean over its edges. Each face is scored as laid out and in the other
dihedral variants (turned 90/180/270 degrees, mirrored; a non-square face only those keeping its
shape), its neighbours as laid out; :func:`check_face_layout` says which face would fit better
turned, when by more than :data:`LAYOUT_MARGIN`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..block.block import Block
from ..frames import FACE_AXIS, FACE_NORMAL, FaceName, block_to_pixel
from ..tolerances import LAYOUT_MIN_PX_PER_MM
from .rings import luminance

#: Depths (pixels of the face image) inside a face at which its edge strip is read, averaged:
#: off the outermost pixels of a crop, yet near enough that a ring crossing the edge obliquely
#: has not moved far along it (measured: README "From photos alone").
STRIP_PX = (0.5, 1.5)
#: ... and at least these depths (mm): STRIP_PX on the 5.12 px/mm Mokume faces the margin was
#: measured on. In pixels alone the strip closed in on the crop line as the density rose, and
#: correct layouts drifted to false alarms: Mokume H11 resized to 500 and 768 px a side
#: (10 and 15.4 px/mm; 10 is what 'block from-photos' stores a phone photo at) scored front
#: flipped top-bottom +0.14 and +0.18 over its layout (flagged at 768, and at 500 from six
#: JPEG phone-style photos), and found 10 and 9 of its 18 wrong layouts (13 at 256 px). At
#: these depths both samples score as at 256 px at every density: none flagged, CN03 16 and
#: H11 13 of 18 wrong layouts found at 256, 500 and 768 px.
STRIP_MM = (0.5 / 5.12, 1.5 / 5.12)
#: Largest shift (mm) between two faces' profiles along an edge that still counts as meeting:
#: the strip depth times an oblique ring's slope, and a photo cropped a little off.
SHIFT_MM = 1.0
#: Profiles are high-passed by subtracting a Gaussian of this sigma (mm): light falling off across
#: a photo, and a face's colour apart from its neighbour's, are not rings.
DETREND_MM = 3.0
#: ... and smoothed by a Gaussian of this sigma (mm): a photo's grain and pores are not rings.
SMOOTH_MM = 0.2
#: Profile sampling step along an edge, mm.
STEP_MM = 0.1
#: A variant of a face must beat its layout by more than this mean edge correlation to be
#: reported. Measured (README "From photos alone"): faces laid out right reach at most -0.02
#: (Mokume CN03, H11, photos) and +0.11 (synthetic blocks): 0.15 keeps a margin against false alarms.
LAYOUT_MARGIN = 0.15
#: Another correction scoring within this of the best is named beside it: on a nearly symmetric
#: face (rings mirrored in its own midline) turning 180 degrees and flipping look alike.
NEAR = 0.05

#: Dihedral variants of a face image: key -> (the *correction*, a function of an (h, w[, c])
#: image; whether it keeps a non-square image's shape). The image as stored, so corrected, is the
#: face as the conventions lay it out.
VARIANTS: dict[str, tuple] = {
    "as laid out": (lambda a: a, True),
    "rot90ccw": (lambda a: np.rot90(a, 1), False),
    "rot180": (lambda a: np.rot90(a, 2), True),
    "rot90cw": (lambda a: np.rot90(a, -1), False),
    "flip-lr": (lambda a: a[:, ::-1], True),
    "flip-tb": (lambda a: a[::-1], True),
    "transpose": (lambda a: np.swapaxes(a, 0, 1), False),
    "antitranspose": (lambda a: np.swapaxes(np.rot90(a, 2), 0, 1), False),
}
#: Per correction: (how the stored photo looks, what to do to it: ``{it}`` is the photo).
_SAY = {
    "rot90ccw": ("turned 90 degrees clockwise", "turn {it} 90 degrees counter-clockwise"),
    "rot180": ("turned 180 degrees", "turn {it} 180 degrees"),
    "rot90cw": ("turned 90 degrees counter-clockwise", "turn {it} 90 degrees clockwise"),
    "flip-lr": ("mirrored left-right", "flip {it} left-right"),
    "flip-tb": ("mirrored top-bottom", "flip {it} top-bottom"),
    "transpose": ("mirrored across its top-left to bottom-right diagonal",
                  "flip {it} left-right, then turn it 90 degrees counter-clockwise"),
    "antitranspose": ("mirrored across its top-right to bottom-left diagonal",
                      "flip {it} left-right, then turn it 90 degrees clockwise"),
}


@dataclass(frozen=True)
class FaceLayout:
    """How well one face's edges meet its neighbours', as laid out and in each allowed variant.

    Attributes
    ----------
    face : FaceName
    scores : dict variant name -> mean edge correlation in [-1, 1] (``"as laid out"`` first).
    edges : number of edges scored (neighbours with an image).
    """

    face: FaceName
    scores: dict[str, float]
    edges: int

    @property
    def as_laid_out(self) -> float:
        return self.scores["as laid out"]

    @property
    def best(self) -> tuple[str, float]:
        """The best variant other than the layout, and its score."""
        name = max((k for k in self.scores if k != "as laid out"), key=self.scores.__getitem__)
        return name, self.scores[name]

    @property
    def margin(self) -> float:
        """Best variant's score minus the layout's (> 0: a variant meets the neighbours better)."""
        return self.best[1] - self.as_laid_out


@dataclass(frozen=True)
class LayoutReport:
    """Result of :func:`check_face_layout`.

    Attributes
    ----------
    faces : face -> :class:`FaceLayout`, every face scored as laid out.
    source : face -> ``"ring map"`` or ``"photo"``: what the face was read from.
    corrections : face -> key of :data:`VARIANTS` to apply to it, for each face flagged.
    warnings : one line per face flagged, clearest first.
    unchecked : face -> why it was not scored though it has a photo or ring map (detection found no
        rings on it; its image is too coarse for the check, under :data:`LAYOUT_MIN_PX_PER_MM`).
    """

    faces: dict[FaceName, FaceLayout]
    source: dict[FaceName, str]
    corrections: dict[FaceName, str] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    unchecked: dict[FaceName, str] = field(default_factory=dict)


#: Why a face detection found no rings on is not checked (:attr:`LayoutReport.unchecked`).
NO_RINGS = "no rings found on it"


def _no_ring_evidence(face, detected: bool) -> bool:
    """Detection ran (``detected``) and found no rings on ``face``'s photo: no ring map, no trace."""
    return detected and face.photo is not None and face.ring_map is None and not face.traces


def _too_coarse(block: Block, name: FaceName) -> str | None:
    """Why face ``name``'s image is too coarse for its edges to be compared, or None: fewer than
    :data:`LAYOUT_MIN_PX_PER_MM` pixels a mm along its coarser axis. Below it, correct faces of
    Mokume CN03 and synthetic cubes scored a turned or mirrored variant past
    :data:`LAYOUT_MARGIN` (CN03 resized to 64 px a side: 'back looks turned 90 degrees'), with
    rings found on every face: a false alarm, where 'not checked' is the truth."""
    f = block.faces[name]
    if f.photo is None and f.ring_map is None:
        return None
    px_mm = 1.0 / max(block.face_pixel_size_mm(name))
    if px_mm >= LAYOUT_MIN_PX_PER_MM:
        return None
    # rounded first: 2.75 px/mm over a 40 mm side is 110 px, not the 111 of a float's last bit
    need = int(np.ceil(round(LAYOUT_MIN_PX_PER_MM / px_mm * min(f.shape), 6)))
    h, w = f.shape[:2]
    side = f"{h} px a side" if h == w else f"{h}x{w} px"
    return (f"{side} is {px_mm:.2f} px/mm, under the {LAYOUT_MIN_PX_PER_MM:g} px/mm the check needs "
            f"(LAYOUT_MIN_PX_PER_MM): give its photo at least {need} px {'a' if h == w else 'on its shorter'} side")


def _face_signal(face, detected: bool) -> tuple[np.ndarray, str] | None:
    """``(image, what)`` a face is read from, or None: its ring map, unless the map was drawn from
    detected traces (``detected``) and the face has a photo, else its photo's luminance; None too
    for a face detection found no rings on (:func:`_no_ring_evidence`).

    Detected traces stop a few pixels short of a face's edges, where this check looks: with such
    maps wrong layouts of Mokume CN03 and H11 went unseen (README "From photos alone"). A face
    with no rings found has nothing along its edges to meet its neighbours' but grain, blur or
    noise: a 20 x 20 px photo's was 'looks mirrored left-right', a verdict with no rings behind it."""
    if _no_ring_evidence(face, detected):
        return None
    if face.ring_map is not None and not (detected and face.photo is not None):
        return np.asarray(face.ring_map, np.float32), "ring map"
    if face.photo is not None:
        return luminance(face.photo), "photo"
    return None


def _strip_points(a: FaceName, b: FaceName, size: np.ndarray, shape) -> np.ndarray:
    """Points (len(STRIP_PX), n, 3) mm inside face ``a`` (image ``shape``) beside the edge where it
    meets face ``b``: the edge, sampled every :data:`STEP_MM` along it, moved away from ``b`` by
    :data:`STRIP_PX` pixels of ``a``, at least :data:`STRIP_MM`."""
    ia, ib = FACE_AXIS[a], FACE_AXIS[b]
    k = 3 - ia - ib                      # the axis the edge runs along
    t = np.arange(0.5 * STEP_MM, size[k], STEP_MM)
    p = np.zeros((len(t), 3))
    p[:, k] = t
    p[:, ia] = size[ia] if FACE_NORMAL[a][ia] > 0 else 0.0
    p[:, ib] = size[ib] if FACE_NORMAL[b][ib] > 0 else 0.0
    inward = -np.asarray(FACE_NORMAL[b], float)
    # pixels per mm across the edge, from the face's own pixel mapping
    px_per_mm = np.hypot(*np.subtract(block_to_pixel(a, p[0] + inward, shape, size),
                                      block_to_pixel(a, p[0], shape, size)))
    depth_mm = np.maximum(np.asarray(STRIP_PX) / px_per_mm, STRIP_MM)
    return p[None] + depth_mm[:, None, None] * inward


def _profile(image: np.ndarray, face: FaceName, strip: np.ndarray, size: np.ndarray) -> np.ndarray:
    """``image`` of ``face`` read at the strip points (d, n, 3) mm (bilinear), averaged over the
    depths, smoothed over :data:`SMOOTH_MM` and high-passed (:data:`DETREND_MM`): shape (n,)."""
    from scipy.ndimage import gaussian_filter1d, map_coordinates

    rows, cols = block_to_pixel(face, strip, image.shape, size)
    v = map_coordinates(image, [rows.ravel(), cols.ravel()], order=1, mode="nearest")
    prof = gaussian_filter1d(v.reshape(rows.shape).mean(axis=0), SMOOTH_MM / STEP_MM, mode="nearest")
    return prof - gaussian_filter1d(prof, DETREND_MM / STEP_MM, mode="nearest")


def _agreement(p: np.ndarray, q: np.ndarray) -> float:
    """Best normalised cross-correlation of two profiles (n,) within +-:data:`SHIFT_MM`; 0 when
    either is flat (nothing to compare)."""
    best = None
    m = int(round(SHIFT_MM / STEP_MM))
    for s in range(-m, m + 1):
        x, y = (p[s:], q[:len(q) - s]) if s >= 0 else (p[:s], q[-s:])
        x, y = x - x.mean(), y - y.mean()
        den = float(np.sqrt((x * x).sum() * (y * y).sum()))
        if den > 1e-12 * len(x):
            r = float((x * y).sum()) / den
            best = r if best is None else max(best, r)
    return 0.0 if best is None else best


def _neighbours(face: FaceName) -> list[FaceName]:
    """The four faces that share an edge with ``face``."""
    return [g for g in FACE_AXIS if FACE_AXIS[g] != FACE_AXIS[face]]


def check_face_layout(block: Block, margin: float = LAYOUT_MARGIN) -> LayoutReport:
    """Score how each face's rings meet its neighbours' across the block's edges (module
    docstring); a warning for each face that a turned or mirrored variant of it fits better than
    its layout by more than ``margin`` (mean edge correlation), saying what to do.

    Faces are read from their ring maps, or their photos' luminance (without a ring map, or when
    the block's maps were drawn from detected traces: ``block.meta["detection"]``); faces with
    neither, faces detection found no rings on and faces under :data:`LAYOUT_MIN_PX_PER_MM`
    (both listed in ``unchecked``, with why), and faces with no neighbour to compare with, are
    not scored.
    Returns a :class:`LayoutReport`; it warns nothing itself (the caller prints or warns).
    """
    size = np.asarray(block.size_mm, float)
    detected = bool(block.meta.get("detection"))
    unchecked = {n: NO_RINGS for n, f in block.faces.items() if _no_ring_evidence(f, detected)}
    # a face too coarse to judge is no neighbour to judge others by either
    unchecked.update({n: why for n in block.faces if n not in unchecked and (why := _too_coarse(block, n))})
    signal = {n: s for n, f in block.faces.items()
              if n not in unchecked and (s := _face_signal(f, detected)) is not None}
    images = {n: s[0] for n, s in signal.items()}
    first = _score_faces(images, size)
    # One turned face lowers its neighbours' scores too (one edge of their four): correct the
    # clearest face first, score again, and stop when no face is clearly better turned.
    layouts, warnings, corrections = first, [], {}
    photos = block.meta.get("photos") or {}
    for _ in range(len(images)):
        flagged = [fl for fl in layouts.values() if fl.margin > margin]
        if not flagged:
            break
        fl = max(flagged, key=lambda f: f.margin)
        variant, score = fl.best
        near = [k for k, v in fl.scores.items() if k not in ("as laid out", variant) and v > score - NEAR]
        also = "".join(f" (or {_SAY[k][1].format(it='it')}: nearly as good)" for k in near)
        it = f"its photo {photos[fl.face]}" if isinstance(photos.get(fl.face), str) else "its photo"
        warnings.append(
            f"face {fl.face!r} looks {_SAY[variant][0]}: its rings meet its neighbours' along its "
            f"{fl.edges} edges only when corrected (mean edge correlation {score:.2f}, {fl.as_laid_out:.2f} "
            f"as laid out); {_SAY[variant][1].format(it=it)}{also}, so that it is seen from outside and "
            f"laid out as in the unfolded cross of ../shared/docs/conventions.md (README 'The block "
            f"frame'), and make the block again")
        corrections[fl.face] = variant
        images[fl.face] = np.ascontiguousarray(VARIANTS[variant][0](images[fl.face]))
        layouts = {n: v for n, v in _score_faces(images, size).items() if n not in corrections}
    return LayoutReport(first, {n: s[1] for n, s in signal.items()}, corrections, warnings, unchecked)


def _score_faces(images: dict, size: np.ndarray) -> dict[FaceName, FaceLayout]:
    """:class:`FaceLayout` of each face in ``images`` (face -> (h, w) float image) that has a
    neighbour there, its neighbours as laid out."""
    laid: dict[tuple, np.ndarray] = {}   # (face, neighbour) -> profile as laid out

    def profile(face, other, image):
        return _profile(image, face, _strip_points(face, other, size, image.shape), size)

    faces: dict[FaceName, FaceLayout] = {}
    for name, image in images.items():
        nbrs = [g for g in _neighbours(name) if g in images]
        if not nbrs:
            continue
        scores = {}
        for variant, (correct, keeps_shape) in VARIANTS.items():
            if not keeps_shape and image.shape[0] != image.shape[1]:
                continue    # a non-square face turned 90 degrees fails the aspect check instead
            im = np.ascontiguousarray(correct(image))
            edge = []
            for g in nbrs:
                if (g, name) not in laid:
                    laid[g, name] = profile(g, name, images[g])
                edge.append(_agreement(profile(name, g, im), laid[g, name]))
            scores[variant] = float(np.mean(edge))
        faces[name] = FaceLayout(name, scores, len(nbrs))
    return faces
