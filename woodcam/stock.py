"""The stock a part is carved from: a block spec resolved to its size and its wood.

A block spec is a string the CLI and GLB metadata carry:

- ``builtin:NAME``: a built-in synthetic block (``woodcam blocks`` lists them).
- ``log:LOG@K`` or ``log:LOG@K:WxDxH``: a block cut tangentially through knot ``K`` of a
  knotted log, ``LOG`` being ``gran1`` (the CT-measured spruce log of the shared data) or a
  woodcam log file (``.json``); size default 100x80x50 mm, Z along the log.
- a block folder with a ``block.json`` manifest (real or synthetic): its true field if it has
  one, otherwise a field fitted to its rings (fit once, cached in the folder).
- a Mokume sample folder (``A_col.png``, ``A_arl-unet.png``, ... as in the Mokume dataset): a
  cube of ``MOKUME_DEFAULT_SIZE_MM`` (50 mm) whose field is fitted to its ring maps, fit once
  and cached under ``$WOODCAM_CACHE_DIR`` / ``~/.cache/woodcam`` (the sample folder is left
  untouched: it is often read-only shared data).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

from .appearance import ColorMapAppearance, Wood
from .errors import WoodcamError
from .fields.builtin import BUILTIN_NAMES, builtin_block

AppearanceKind = Literal["colormap", "neural"]


@dataclass
class Stock:
    """A block to carve from.

    Attributes
    ----------
    spec : str
        The block spec it was opened from (stored in exported GLBs).
    size_mm : (W, D, H)
    wood : Wood
    description : str
    meta : dict
    """

    spec: str
    size_mm: tuple[float, float, float]
    wood: Wood
    description: str = ""
    meta: dict = field(default_factory=dict)


def open_stock(spec: str, *, species: str | None = None,
               appearance: AppearanceKind = "colormap", **appearance_params) -> Stock:
    """Resolve a block spec (see module docstring) to a :class:`Stock`.

    Parameters
    ----------
    spec : str
    species : str, optional
        Colour preset (``woodcam.appearance.SPECIES``); default: the block's own.
    appearance : "colormap" (fast, the default) or "neural"
        ``"neural"`` learns colour volumes from the block's face photos
        (:func:`~woodcam.appearance.neural.fit_neural_appearance`, cached on disk); a built-in
        block's photos are first rendered by :func:`woodcam.synth.synth_block`, and a block
        without photos falls back to the colour map with an ``AppearanceFallbackWarning``.
    **appearance_params
        Passed to :class:`~woodcam.appearance.ColorMapAppearance` (e.g. knot darkening), or for
        ``"neural"`` to ``fit_neural_appearance`` (``resolution``, ``quality``, ``epochs``,
        ``cache_dir``, ``progress``).
    """
    if appearance not in ("colormap", "neural"):
        raise WoodcamError(f"appearance must be one of ['colormap', 'neural']; got {appearance!r}")
    if spec.startswith("builtin:"):
        b = builtin_block(spec.split(":", 1)[1])
        return _synthetic_stock(spec, b.field, b.size_mm, species or b.species, b.description,
                                appearance, appearance_params)
    if spec.startswith("log:"):
        field, size_mm, description = _log_block_field(spec)
        return _synthetic_stock(spec, field, size_mm, species or "spruce", description,
                                appearance, appearance_params)
    path = Path(spec)
    if path.is_dir() and (path / "block.json").is_file():
        return _open_block_folder(path, species, appearance, appearance_params)
    if path.is_dir() and (any(path.glob("?_col.png")) or any(path.glob("?_arl-unet.png"))):
        return _open_mokume_folder(path, species, appearance, appearance_params)
    raise WoodcamError(
        f"block spec {spec!r} is neither 'builtin:NAME' (NAME one of {', '.join(BUILTIN_NAMES)}), "
        "'log:LOG@KNOT[:WxDxH]', a block folder with a block.json manifest, nor a Mokume sample "
        "folder (A_col.png, A_arl-unet.png, ...)"
    )


def _synthetic_stock(spec, field, size_mm, species, description, appearance, params) -> Stock:
    """A stock whose true field is known but which has no photos of its own."""
    from .fields.state import is_saveable

    meta = {"appearance": appearance}
    if is_saveable(field):
        meta["field"] = field.to_dict()
    if appearance == "neural":
        # The neural appearance learns from face photos: render them from the field first.
        from .appearance.neural import fit_neural_appearance
        from .synth import synth_block

        photos = synth_block(field, size_mm, face_px=256, seed=0, name=spec.replace(":", "-"))
        app = fit_neural_appearance(photos, field, **params)
        meta["appearance_key"] = app.meta.get("key")
    else:
        app = ColorMapAppearance(species, **params)
        meta["species"] = app.species.name
    return Stock(spec, tuple(size_mm), Wood(field, app), description, meta)


def fitted_field(block, folder: Path | None, method: str = "evidence"):
    """The growth field fitted to a block's rings, fitted once and cached.

    folder : the block folder: the cache ``<folder>/.woodcam-cache/field_<method>_v<N>.npz`` is
        reused while it is newer than the block's manifest (delete it, or rewrite the block, to
        fit again). None (a Mokume sample folder, which is never written to): cached under
        ``$WOODCAM_CACHE_DIR`` / ``~/.cache/woodcam`` keyed by the block's images and size.
    ``N`` is :data:`woodcam.inference.fit.FIT_VERSION`, so a changed fitter refits.
    """
    from .appearance.neural import default_cache_dir
    from .appearance.volumes import block_fingerprint
    from .fields.grid import GridField
    from .inference import fit_block
    from .inference.fit import FIT_VERSION

    if folder is None:
        cache = (default_cache_dir().parent / "fields"
                 / f"{block.name}-{block_fingerprint(block)[:16]}-{method}_v{FIT_VERSION}.npz")
        fresh = cache.is_file()
    else:
        cache = folder / ".woodcam-cache" / f"field_{method}_v{FIT_VERSION}.npz"
        fresh = cache.is_file() and cache.stat().st_mtime >= (folder / "block.json").stat().st_mtime
    if fresh:
        return GridField.load(cache)
    if not any(f.has_rings for f in block.faces.values()):
        raise WoodcamError(
            f"block {folder or block.name} has neither a true field nor traced rings or ring maps "
            "to fit one to; trace rings on at least one face (or use 'woodcam block synth')"
        )
    field = fit_block(block, method=method)
    cache.parent.mkdir(parents=True, exist_ok=True)
    field.save(cache)
    return field


def _open_mokume_folder(path: Path, species, appearance, appearance_params) -> Stock:
    from .block.io import read_mokume

    block = read_mokume(path)
    return _real_block_stock(str(path), block, fitted_field(block, None), species, appearance,
                             appearance_params, cache_dir=None)


def _open_block_folder(path: Path, species, appearance, appearance_params) -> Stock:
    from .block.io import read_block  # block I/O sits beside; imported when a folder is used

    block = read_block(path)
    field = block.true_field if block.true_field is not None else fitted_field(block, path)
    return _real_block_stock(str(path), block, field, species, appearance, appearance_params,
                             cache_dir=path / ".woodcam-cache")


def _real_block_stock(spec, block, field, species, appearance, appearance_params, cache_dir) -> Stock:
    if appearance == "neural":
        from .appearance.neural import block_appearance

        if cache_dir is not None:
            appearance_params.setdefault("cache_dir", cache_dir)
        app = block_appearance(block, field, "neural", species=species or "oak", **appearance_params)
    elif any(f.photo is not None for f in block.faces.values()):
        app = ColorMapAppearance.fit_to_block(block, field, species or "oak", **appearance_params)
    else:
        app = ColorMapAppearance(species or "oak", **appearance_params)
    return Stock(spec, block.size_mm, Wood(field, app), block.name, dict(block.meta))


def _log_block_field(spec: str):
    """``log:LOG@K[:WxDxH]`` -> (block-frame field, size_mm, description)."""
    from .fields import KnottedLogField, block_at_knot, place_block_in_log, read_gran1, read_log

    body = spec[len("log:"):]
    try:
        source, rest = body.split("@", 1)
        knot, _, size = rest.partition(":")
        knot = int(knot)
        size_mm = tuple(float(v) for v in size.lower().split("x")) if size else (100.0, 80.0, 50.0)
        if len(size_mm) != 3:
            raise ValueError(size)
    except ValueError as err:
        raise WoodcamError(
            f"log block spec {spec!r} must read 'log:LOG@KNOT' or 'log:LOG@KNOT:WxDxH' "
            "(e.g. log:gran1@52:100x80x50)"
        ) from err
    log = read_gran1() if source == "gran1" else read_log(source)
    if not 0 <= knot < len(log.knots):
        raise WoodcamError(f"knot index in {spec!r} must be 0..{len(log.knots) - 1}; got {knot}")
    field = place_block_in_log(KnottedLogField(log), *block_at_knot(log, knot, size_mm))
    return field, size_mm, f"block through knot {knot} of log {source}"
