"""Leave-one-face-out evaluation of appearance models (``woodcam eval appearance``).

For each face with a photo: train without it, synthesise it from its ring image (the field's
ARF, or for a real block without a fitted field its ring map), and compare with its photo, for

- ``neural``: the orientation-dependent model, the network of the face's axis (trained on the
  other face of that axis; with ``finetune_epochs > 0`` fine-tuned on it from the network
  trained on all remaining faces);
- ``agnostic``: one network trained on all remaining faces, used for every orientation (the
  orientation-agnostic variant of seed 000's Fig. 13);
- ``colormap``: the photo-fitted colour map (:meth:`ColorMapAppearance.fit_to_block` on the
  remaining faces) when a field is known; without a field, its analogue on the ring map: per
  axis, the mean photo colour as a function of the ring-map value.

Measures need no pretrained network; all compare images ``(h, w, 3)`` float in [0, 1]:
:func:`histogram_distance` (colour distribution), :func:`spectrum_distance` (radially averaged
power spectrum of the luminance: ring and grain frequencies), :func:`patch_distance` (local
statistics) and the aligned per-pixel ``l1`` (the ring geometry is the same by construction).
Lower is better for all.
"""

from __future__ import annotations

from dataclasses import dataclass, field as dc_field, replace

import numpy as np

from .._atomic import atomic_path
from ..errors import WoodcamError
from ..frames import FACE_AXIS, FACE_NORMAL
from .colormap import ColorMapAppearance
from .neural import photo_faces
from .translation import Quality, train_translation, translation_spec
from .volumes import VolumeGrid, face_pair
from .wood import wood_colors

MODELS: tuple[str, ...] = ("neural", "agnostic", "colormap")
METRICS: tuple[str, ...] = ("histogram", "spectrum", "patch", "l1")

_QUANTILES = np.linspace(0.005, 0.995, 100)
_LUMA = np.array([0.299, 0.587, 0.114])


def _check_pair(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    if a.ndim != 3 or a.shape[2] != 3 or a.shape != b.shape:
        raise WoodcamError(f"images must both be (h, w, 3) of one shape; got {a.shape} and {b.shape}")
    return a, b


def histogram_distance(a, b) -> float:
    """Mean over R, G, B of the 1-D Wasserstein-1 distance of the colour distributions
    (via 100 quantiles), in colour units [0, 1]: a uniform shift by ``s`` gives ``s``."""
    a, b = _check_pair(a, b)
    qa = np.quantile(a.reshape(-1, 3), _QUANTILES, axis=0)
    qb = np.quantile(b.reshape(-1, 3), _QUANTILES, axis=0)
    return float(np.abs(qa - qb).mean())


def radial_power_spectrum(image) -> np.ndarray:
    """Radially averaged power spectrum of an image's luminance, ``(min(h, w) // 2 - 1,)``:
    mean removed, Hann window, power per pixel, bins of integer radius 1 .. Nyquist."""
    im = np.asarray(image, float)
    y = im @ _LUMA if im.ndim == 3 else im
    h, w = y.shape
    y = (y - y.mean()) * np.outer(np.hanning(h), np.hanning(w))
    p = np.abs(np.fft.fftshift(np.fft.fft2(y))) ** 2 / (h * w)
    fy = (np.arange(h) - h // 2) / h
    fx = (np.arange(w) - w // 2) / w
    r = np.hypot(fy[:, None], fx[None, :]) * min(h, w)  # radius in cycles per min side
    nb = min(h, w) // 2
    idx = np.rint(r).astype(int)
    ok = (idx >= 1) & (idx < nb)
    return np.bincount(idx[ok], p[ok], nb)[1:] / np.maximum(np.bincount(idx[ok], minlength=nb)[1:], 1)


def spectrum_distance(a, b) -> float:
    """Mean absolute difference of the log10 radially averaged power spectra (decades)."""
    a, b = _check_pair(a, b)
    pa, pb = radial_power_spectrum(a), radial_power_spectrum(b)
    eps = 1e-10
    return float(np.abs(np.log10(pa + eps) - np.log10(pb + eps)).mean())


def _patch_features(im, patch: int) -> np.ndarray:
    h, w = (im.shape[0] // patch) * patch, (im.shape[1] // patch) * patch
    im = im[:h, :w]
    y = im @ _LUMA
    gy, gx = np.abs(np.diff(y, axis=0, append=y[-1:])), np.abs(np.diff(y, axis=1, append=y[:, -1:]))

    def blocks(a):
        return a.reshape(h // patch, patch, w // patch, patch, *a.shape[2:]).swapaxes(1, 2).reshape(
            (h // patch) * (w // patch), patch * patch, *a.shape[2:])

    rgb = blocks(im).mean(axis=1)
    return np.column_stack([rgb, blocks(y).std(axis=1), blocks(gx).mean(axis=1), blocks(gy).mean(axis=1)])


def patch_distance(a, b, patch: int = 8) -> float:
    """Patch-statistics distance: per ``patch x patch`` block, mean RGB, luminance std and mean
    absolute luminance gradient along rows and columns; the mean over these six features of the
    1-D Wasserstein-1 distance between the two images' feature distributions."""
    a, b = _check_pair(a, b)
    fa, fb = _patch_features(a, patch), _patch_features(b, patch)
    return float(np.abs(np.quantile(fa, _QUANTILES, axis=0) - np.quantile(fb, _QUANTILES, axis=0)).mean())


def image_scores(pred, photo) -> dict:
    """All measures of :data:`METRICS` for one predicted image against its photo."""
    return {"histogram": histogram_distance(pred, photo), "spectrum": spectrum_distance(pred, photo),
            "patch": patch_distance(pred, photo), "l1": float(np.abs(np.asarray(pred, float) - photo).mean())}


@dataclass
class FaceEval:
    """Leave-one-out result of one face.

    Attributes
    ----------
    face : str
    end_grain : bool or None
        Whether the face shows end grain (``None`` when unknown).
    photo : (h, w, 3) float, the held-out photo at the evaluation grid.
    predictions : dict model -> (h, w, 3) float
    scores : dict model -> dict metric -> float
    """

    face: str
    end_grain: bool | None
    photo: np.ndarray
    predictions: dict = dc_field(default_factory=dict)
    scores: dict = dc_field(default_factory=dict)


def _without_photo(block, face):
    faces = {n: (replace(f, photo=None) if n == face else f) for n, f in block.faces.items()}
    return replace(block, faces=faces)


def _ring_lut_prediction(train_pairs, x, bins: int = 32) -> np.ndarray:
    """Colour as a function of the ring channel, binned means over the training pairs."""
    v = np.concatenate([p[0][0].ravel() for p in train_pairs])
    c = np.concatenate([p[1].reshape(-1, 3) for p in train_pairs])
    b = np.minimum((np.clip(v, 0, 1) * bins).astype(int), bins - 1)
    n = np.bincount(b, minlength=bins)
    lut = np.stack([np.bincount(b, c[:, k], bins) for k in range(3)], 1) / np.maximum(n, 1)[:, None]
    ok = n > 0
    centres = (np.arange(bins) + 0.5) / bins
    lut = np.stack([np.interp(centres, centres[ok], lut[ok, k]) for k in range(3)], 1)
    t = np.minimum((np.clip(x[0], 0, 1) * bins).astype(int), bins - 1)
    return lut[t]


#: Points along each side of the grid :func:`end_grain_faces` samples a face on (cell centres).
END_GRAIN_GRID = 9


def end_grain_faces(field, size_mm, threshold: float = 0.7) -> dict:
    """Per face of a block of ``size_mm`` (3,) mm: True when the grain runs within ~45 deg of
    the face's normal (``|grain . normal| > threshold``) on more than half of a
    :data:`END_GRAIN_GRID` x :data:`END_GRAIN_GRID` grid of points over the face (block frame).
    The face centre alone decided: builtin:knotty's front, side grain on 95 % of it, was 'end
    grain' because a knot, whose fibres leave the face, crosses it at the centre."""
    from ..fields.base import grain_direction

    size = np.asarray(size_mm, float)
    t = (np.arange(END_GRAIN_GRID) + 0.5) / END_GRAIN_GRID
    out = {}
    for face, normal in FACE_NORMAL.items():
        n = np.asarray(normal, float)
        u, v = (i for i in range(3) if n[i] == 0)  # the face's two in-plane axes
        a, b = np.meshgrid(t * size[u], t * size[v], indexing="ij")
        p = np.tile(size / 2 + n * size / 2, (a.size, 1))  # the face's plane
        p[:, u], p[:, v] = a.ravel(), b.ravel()
        g = grain_direction(field, p)
        out[face] = bool(np.mean(np.abs(g @ n) > threshold) > 0.5)
    return out


def leave_one_face_out(block, field=None, *, resolution: int = 128, quality: Quality = "normal",
                       epochs: int | None = None, seed: int = 0, faces=None, end_grain=None,
                       species: str = "oak", progress: bool = True, threads: int | None = 1,
                       finetune_epochs: int | None = None, augment: bool | None = None,
                       source: str | None = None) -> list[FaceEval]:
    """Leave-one-face-out evaluation of the models in :data:`MODELS` (module docstring).

    Parameters
    ----------
    block : Block with photos on at least two faces.
    field : growth field or None (None: ring maps are the networks' input; the block needs them).
    resolution : cells along the longest side of the evaluation grid (the volume's resolution).
    faces : faces to hold out (default all with a photo).
    end_grain : dict face -> bool, optional; default from the field's grain direction, else unknown.
    finetune_epochs : overrides the spec's (0: per-axis networks from scratch, the seed's way).
    augment : overrides the spec's (mirrored training patches).
    source : the networks' ring input, "arf" or "ring_map" (see
        :func:`~.neural.fit_neural_appearance`); default "arf" with a field, "ring_map" without.
        A real block evaluated with its fitted field and "ring_map" learns as ``woodcam bake``
        does (``source="auto"``) and scores the photo-fitted colour map of that field.

    Returns
    -------
    list of FaceEval
    """
    source = source or ("arf" if field is not None else "ring_map")
    usable = [f for f in photo_faces(block) if source != "ring_map" or block.faces[f].ring_map is not None]
    if len(usable) < 2:
        raise WoodcamError(
            f"block {block.name!r} needs photos (and, without a field, ring maps) on at least two faces "
            f"for a leave-one-face-out evaluation; got {usable}"
        )
    grid = VolumeGrid(block.size_mm, resolution)
    extra = {} if finetune_epochs is None else {"finetune_epochs": int(finetune_epochs)}
    if augment is not None:
        extra["augment"] = bool(augment)
    spec = translation_spec(quality, epochs, seed, **extra)
    pairs = {f: face_pair(block, f, grid, spec, field=field, source=source) for f in usable}
    if end_grain is None:
        end_grain = end_grain_faces(field, block.size_mm) if field is not None else {}
    nets = {}

    def net_for(train_faces, init_faces=None):
        key = (tuple(sorted(train_faces)), tuple(sorted(init_faces or ())))
        if key not in nets:
            init = net_for(init_faces) if init_faces else None
            nets[key] = train_translation([pairs[f] for f in key[0]], spec, progress=progress, init=init,
                                          desc=f"eval: train on {'+'.join(key[0])}", threads=threads)
        return nets[key]

    from .._progress import progress_bar

    out = []
    # a bar over the held-out faces: each trains up to three nets, whose own bars come and go
    for f in progress_bar(list(faces or usable), desc=f"eval {block.name}: held-out faces", unit="face",
                          enabled=progress):
        x, photo, _ = pairs[f]
        rest = [g for g in usable if g != f]
        same = [g for g in rest if FACE_AXIS[g] == FACE_AXIS[f]]
        ev = FaceEval(f, end_grain.get(f), photo)
        if same:
            ev.predictions["neural"] = net_for(same, rest if spec.finetune_epochs > 0 else None)(x)
        ev.predictions["agnostic"] = net_for(rest)(x)
        if field is not None:
            cm = ColorMapAppearance.fit_to_block(_without_photo(block, f), field, species)
            pts = grid.face_points(f)
            normals = np.broadcast_to(np.asarray(FACE_NORMAL[f], float), pts.shape).reshape(-1, 3)
            ev.predictions["colormap"] = cm.color(field, pts.reshape(-1, 3), normals).reshape(photo.shape)
        else:
            ev.predictions["colormap"] = _ring_lut_prediction([pairs[g] for g in (same or rest)], x)
        ev.scores = {m: image_scores(p, photo) for m, p in ev.predictions.items()}
        out.append(ev)
    return out


def summarise(results: list[FaceEval]) -> dict:
    """Mean of each measure per model, over all faces and over end-grain faces; and the count of
    faces where neural beats colormap and agnostic on each measure."""
    summary = {}
    for subset, keep in (("all", lambda r: True), ("end_grain", lambda r: r.end_grain),
                         ("side_grain", lambda r: r.end_grain is False)):
        rs = [r for r in results if keep(r)]
        if not rs:
            continue
        s = {"faces": [r.face for r in rs]}
        for m in MODELS:
            have = [r for r in rs if m in r.scores]
            if have:
                s[m] = {k: float(np.mean([r.scores[m][k] for r in have])) for k in METRICS}
        for other in ("colormap", "agnostic"):
            both = [r for r in rs if "neural" in r.scores and other in r.scores]
            s[f"neural_beats_{other}"] = {
                k: f"{sum(r.scores['neural'][k] < r.scores[other][k] for r in both)}/{len(both)}"
                for k in METRICS}
        summary[subset] = s
    return summary


def _side_by_side_layout(results: list[FaceEval], title: str = ""):
    """Where everything of :func:`side_by_side` goes: ``((width, height), items)``, each item
    ``("text", (x0, y0, x1, y1), (x, y, str))`` (the ink's box, the text drawn at ``(x, y)``) or
    ``("image", (x0, y0, x1, y1), (h, w, 3) float)`` (already zoomed to its box); pixels.

    Columns are as wide as their widest image or label, so no two items overlap at any image
    size (at ``--resolution 48`` the faces were 24-48 px wide and the scores, drawn one photo's
    width apart, overlapped); images under 64 px are zoomed by a whole factor so that the wood
    shows.
    """
    from PIL import Image, ImageDraw, ImageFont

    font = ImageFont.load_default()
    probe = ImageDraw.Draw(Image.new("RGB", (1, 1)))

    def text(x: int, y: int, s: str):
        return ("text", tuple(int(v) for v in probe.textbbox((x, y), s, font=font)), (x, y, s))

    def width(s: str) -> int:
        return int(np.ceil(probe.textbbox((0, 0), s, font=font)[2]))

    pad, gap = 4, 8
    line = int(probe.textbbox((0, 0), "Ag|(/", font=font)[3]) + 3
    zoom = max(1, -(-64 // max(max(r.photo.shape[:2]) for r in results)))
    grains = {True: "end grain", False: "side grain", None: "grain ?"}
    rows = []  # per face: (labels, image) per column, photo then each model
    for r in results:
        row = [(["photo"], r.photo)]
        for m in MODELS:
            sc = r.scores.get(m)
            row.append(([m, f"{sc['histogram']:.3f}/{sc['spectrum']:.2f}/{sc['patch']:.3f}" if sc
                         else "not run"], r.predictions.get(m, np.ones_like(r.photo))))
        rows.append(row)
    left = max(width(t) for r in results for t in (r.face, f"({grains[r.end_grain]})"))
    col_w = [max(max(max(width(t) for t in labels), im.shape[1] * zoom) for labels, im in column)
             for column in zip(*rows)]
    xs = [pad + left + gap]
    for w in col_w[:-1]:
        xs.append(xs[-1] + w + gap)
    header = [title, "under each model: histogram / spectrum / patch distance to the photo, lower is better"]
    items = [text(pad, pad + i * line, t) for i, t in enumerate(header) if t]
    y = pad + len(header) * line + gap
    for r, row in zip(results, rows):
        items += [text(pad, y, r.face), text(pad, y + line, f"({grains[r.end_grain]})")]
        tallest = 0
        for x, (labels, im) in zip(xs, row):
            items += [text(x, y + i * line, t) for i, t in enumerate(labels)]
            big = np.repeat(np.repeat(np.asarray(im, float), zoom, axis=0), zoom, axis=1)
            items.append(("image", (x, y + 2 * line, x + big.shape[1], y + 2 * line + big.shape[0]), big))
            tallest = max(tallest, big.shape[0])
        y += 2 * line + tallest + gap
    return (max(box[2] for _, box, _ in items) + pad, y - gap + pad), items


def side_by_side(results: list[FaceEval], path, title: str = "") -> None:
    """One PNG: a row per face, photo | neural | agnostic | colormap, each labelled with its
    model and scores (placed by :func:`_side_by_side_layout`)."""
    from PIL import Image, ImageDraw, ImageFont

    from .._checks import png_path

    path = png_path(path, "side_by_side: path")  # at the door, before the figure is drawn
    (w, h), items = _side_by_side_layout(results, title)
    canvas = np.ones((h, w, 3))
    for kind, (x0, y0, x1, y1), what in items:
        if kind == "image":
            canvas[y0:y1, x0:x1] = what
    img = Image.fromarray((np.clip(canvas, 0, 1) * 255 + 0.5).astype(np.uint8))
    draw, font = ImageDraw.Draw(img), ImageFont.load_default()
    for kind, _, what in items:
        if kind == "text":
            x, y, s = what
            draw.text((x, y), s, fill=(0, 0, 0), font=font)
    with atomic_path(path) as tmp:  # a complete image or none
        img.save(tmp)


# -- looking at a whole block: parts carved from it ------------------------------------------------

def _view_basis(view):
    v = np.asarray(view, float)
    v = v / np.linalg.norm(v)
    up = np.array([0.0, 0.0, 1.0]) if abs(v[2]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(up, v)
    e1 /= np.linalg.norm(e1)
    return v, e1, np.cross(v, e1)


def render_sphere(wood, size_mm, px: int = 256, view=(1.0, -1.3, 0.9), radius_frac: float = 0.45,
                  light=(0.4, -0.6, 1.0)) -> np.ndarray:
    """Orthographic picture ``(px, px, 3)`` float of a sphere carved from the block's centre.

    ``view`` points from the sphere to the camera; white background; Lambert shading
    ``0.65 + 0.35 n.l`` so the colour of the wood dominates.
    """
    size = np.asarray(size_mm, float)
    c, r = size / 2, radius_frac * size.min()
    v, e1, e2 = _view_basis(view)
    s = (np.arange(px) + 0.5) / px * 2 - 1
    u, w = np.meshgrid(s, -s)
    inside = u ** 2 + w ** 2 < 1
    depth = np.sqrt(np.clip(1 - u ** 2 - w ** 2, 0, 1))
    n = u[..., None] * e1 + w[..., None] * e2 + depth[..., None] * v
    pts = c + r * n[inside]
    rgb = wood_colors(wood, pts, n[inside])
    lgt = np.asarray(light, float) / np.linalg.norm(light)
    shade = 0.65 + 0.35 * np.clip(n[inside] @ lgt, 0, 1)
    out = np.ones((px, px, 3))
    out[inside] = np.clip(rgb * shade[:, None], 0, 1)
    return out


def render_plane(wood, size_mm, normal=(1.0, 1.0, 1.0), px: int = 256) -> np.ndarray:
    """The cut surface ``(px, px, 3)`` float of the plane through the block centre with ``normal``
    (white outside the block), seen along the normal."""
    size = np.asarray(size_mm, float)
    v, e1, e2 = _view_basis(normal)
    half = 0.5 * np.linalg.norm(size)
    s = ((np.arange(px) + 0.5) / px * 2 - 1) * half
    u, w = np.meshgrid(s, -s)
    pts = size / 2 + u[..., None] * e1 + w[..., None] * e2
    inside = np.all((pts >= 0) & (pts <= size), axis=-1)
    out = np.ones((px, px, 3))
    out[inside] = wood_colors(wood, pts[inside], v)
    return out
