"""``synth_block``: render a synthetic block (photos, traces, ring maps) from a true field."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from .._checks import check_bool
from .._types import ArrayLike, GrowthFieldLike, WoodLike
from ..appearance.wood import wood_colors
from ..block import Block, Face
from ..errors import WoodcamError
from ..fields.base import LogFrame, evaluate
from ..fields.rings import MOKUME_RING_SIGMA_MM, ring_map
from ..limits import check_limit
from ..frames import (
    FACE_NORMAL,
    CrossLayout,
    check_size,
    face_image_size_mm,
    face_pixel_points,
)
from .degradation import _dropout, _jitter, _mislabel
from .photos import _BuiltinWood, _camera
from .spec import SynthSpec
from .traces import _trace_face


def synth_block(field: GrowthFieldLike, size_mm: ArrayLike, spec: SynthSpec | None = None, *,
                wood: WoodLike | None = None,
                rng: np.random.Generator | None = None, name: str = "synthetic",
                meta: dict | None = None, knot_masks: bool = True,
                texture_frame: LogFrame | None = None, **settings) -> Block:
    """Render a synthetic :class:`Block` from a growth field placed in the block frame.

    Parameters
    ----------
    field : callable ``(n, 3) block mm -> (n,) years``
        The true growth-time field (e.g. from :func:`cut_block`); kept as ``block.true_field``.
    size_mm : (W, D, H)
    spec : SynthSpec, optional
        How to render (density, faces, camera, traces and their faults, ring maps); default
        ``SynthSpec()``. ``**settings`` are its flat keyword names, applied on top:
        ``px_per_mm``, ``face_px``, ``faces``, ``trace_faces``, ``ring_map_faces``, ``seed``,
        ``photo_noise``, ``photo_variation``, ``photo_blur_px``, ``trace_dropout``,
        ``trace_dropout_chunk_mm``, ``trace_jitter_mm``, ``trace_jitter_corr_mm``,
        ``mislabel_fraction``, ``unlabelled_fraction``, ``ring_map_sigma_px``,
        ``ring_map_noise`` (see :mod:`woodcam.synth.spec`).
    wood : object with ``color(points_mm (n, 3), normals (n, 3)) -> (n, 3) float [0, 1]``, optional
        The appearance (``woodcam.appearance.Wood``); it should wrap the same ``field``. None
        uses a built-in earlywood/latewood colour map of the field's ARF.
    rng : numpy Generator, optional
        Used instead of ``np.random.default_rng(spec.seed)``.
    name, meta
        Block name and extra metadata.
    knot_masks : for a field with ``knot_features`` (knotted logs), mark each face's knot wood
        (weight > 0.5) in ``extras["knot_mask"]``, as the knot masks of Mokume's H11.
    texture_frame : LogFrame, optional
        For the built-in colours (no ``wood``): the frame their fibre texture is drawn in,
        placed in the block frame; a block cut out of another's wood passes the other's (as
        ``ColorMapAppearance.texture_frame``), so its photos show the same wood as the other's.
        A given ``wood`` draws its own texture: passing both is refused.

    Returns
    -------
    Block
        With ``true_field=field`` and ``meta`` holding the generator settings (flat names).
        Clean traces (no jitter, no mislabelling) lie on the integer iso-lines within
        :data:`woodcam.tolerances.TRACE_ISO_TOL_YEARS` years.
    """
    # a dict spec, an int rng and a list meta were AttributeError/TypeError deep in the render
    if spec is not None and not isinstance(spec, SynthSpec):
        raise WoodcamError(f"spec must be a SynthSpec or None; got {type(spec).__name__}; pass "
                           "SynthSpec.from_dict(d), or the settings as keywords (face_px=64)")
    if rng is not None and not isinstance(rng, np.random.Generator):
        raise WoodcamError(f"rng must be a numpy Generator or None; got {rng!r:.40}; pass "
                           "np.random.default_rng(seed), or seed=... to let the spec make one")
    if meta is not None and not isinstance(meta, Mapping):
        raise WoodcamError(f"meta must be a dict of extra block metadata or None; got {type(meta).__name__}")
    knot_masks = check_bool(knot_masks, "knot_masks")
    spec = (SynthSpec() if spec is None else spec).replace_flat(**settings)
    size = check_size(size_mm)
    if not callable(field):
        raise WoodcamError(f"field must be callable (n, 3) mm -> years; got {type(field).__name__}")
    if wood is not None and not callable(getattr(wood, "color", None)):
        raise WoodcamError(
            f"wood must have a color(points_mm, normals) method; got {type(wood).__name__}"
        )
    if wood is not None and texture_frame is not None:
        raise WoodcamError("texture_frame is for the built-in colours; a given wood draws its own texture "
                           f"(got wood={type(wood).__name__} and a texture_frame); pass one of them")
    faces = list(spec.faces)
    trace_faces = set(faces if spec.trace_faces is None else spec.trace_faces)
    ring_map_faces = set(faces if spec.ring_map_faces is None else spec.ring_map_faces)
    px_per_mm = spec.face_px / float(size.max()) if spec.px_per_mm is None else spec.px_per_mm
    rng = np.random.default_rng(spec.seed) if rng is None else rng
    # A whole number of pixels across W: unfold_cross infers the density from the front face's
    # width, so this keeps all six face shapes consistent with it.
    px_per_mm = max(1, round(size[0] * float(px_per_mm))) / size[0]
    layout = CrossLayout(tuple(size), px_per_mm)
    # face_px=10**7 (or px_per_mm=1e7) was numpy's MemoryError of a 2 PiB pixel grid; a block
    # face holds at most MAX_FACE_PX a side (Face and read_block refuse more)
    side = max((max(layout.face_shape(f)) for f in faces), default=0)
    check_limit("MAX_FACE_PX", side, f"a face image of {side} px a side ({px_per_mm:.4g} px/mm on a "
                f"{float(size.max()):g} mm block)", fix="lower face_px or px_per_mm")
    sigma_px = spec.ring_map.sigma_px
    if sigma_px is None:
        sigma_px = MOKUME_RING_SIGMA_MM * px_per_mm
    ph, tr = spec.photo, spec.traces

    appearance = "builtin" if wood is None else type(wood).__name__
    wood = _BuiltinWood(field, rng, texture_frame=texture_frame) if wood is None else wood
    out = {}
    for face in faces:
        shape = layout.face_shape(face)
        hmm, wmm = face_image_size_mm(face, size)
        px_mm = (hmm / shape[0], wmm / shape[1])
        pts = face_pixel_points(face, shape, size).reshape(-1, 3)
        g = evaluate(field, pts)
        if not np.all(np.isfinite(g)):  # NaN years were int()'s ValueError in the iso-line tracer
            raise WoodcamError(f"field must give finite years on the block; it gave {int(np.sum(~np.isfinite(g)))} "
                               f"NaN/inf of {g.size} pixels of face {face!r}; check the field and that the "
                               "block lies where it is defined")
        normals = np.broadcast_to(np.asarray(FACE_NORMAL[face], float), pts.shape)
        if isinstance(wood, _BuiltinWood):
            gr, gc = np.gradient(g.reshape(shape))
            rgb = wood.color(pts, normals, years=g, years_per_px=np.hypot(gr, gc).ravel())
        else:
            # the checked seam: a user's wood's NaN or 0..255 colours made photos of them
            rgb = np.asarray(wood_colors(wood, pts, normals), dtype=float)
        photo = _camera(rgb.reshape(shape + (3,)), rng, ph.noise, ph.variation, ph.blur_px)
        g = g.reshape(shape)
        rmap = None
        if face in ring_map_faces:
            rmap = ring_map(g, sigma_px)
            if spec.ring_map.noise > 0:
                rmap = rmap + spec.ring_map.noise * rng.standard_normal(rmap.shape)
            rmap = np.clip(rmap, 0.0, 1.0).astype(np.float32)
        traces = []
        if face in trace_faces:
            traces = _trace_face(field, face, shape, size, g)
            if tr.dropout > 0:
                traces = _dropout(traces, px_mm, tr.dropout, tr.dropout_chunk_mm, rng)
            if tr.jitter_mm > 0:
                traces = _jitter(traces, px_mm, tr.jitter_mm, tr.jitter_corr_mm, rng)
            if tr.mislabel_fraction > 0 or tr.unlabelled_fraction > 0:
                traces = _mislabel(traces, tr.mislabel_fraction, tr.unlabelled_fraction, rng)
        extras = {}
        if knot_masks and hasattr(field, "knot_features"):
            # as a tracer (or the knot detector) marks the knots on a photo: knot wood
            extras["knot_mask"] = (np.asarray(field.knot_features(pts)["knot"]) > 0.5).reshape(shape)
        out[face] = Face(face, shape, photo=photo, traces=traces, ring_map=rmap, extras=extras)

    flat = spec.flat()
    settings_meta = {
        "generator": "woodcam.synth.synth_block", "seed": spec.seed,
        "px_per_mm": float(px_per_mm), "appearance": appearance,
        "trace_faces": sorted(trace_faces), "ring_map_faces": sorted(ring_map_faces),
        **{k: flat[k] for k in ("trace_dropout", "trace_dropout_chunk_mm", "trace_jitter_mm",
                                "trace_jitter_corr_mm", "mislabel_fraction", "unlabelled_fraction",
                                "photo_noise", "photo_variation", "photo_blur_px")},
        "ring_map_sigma_px": sigma_px, "ring_map_noise": spec.ring_map.noise,
    }
    return Block(tuple(size), faces=out, true_field=field, name=name, meta={**settings_meta, **(meta or {})})
