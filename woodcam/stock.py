"""The stock a part is carved from: a block spec resolved to its size and its wood.

A block spec is a string the CLI and GLB metadata carry:

- ``builtin:NAME``: a built-in synthetic block (``woodcam blocks`` lists them).
- ``log:LOG@K`` or ``log:LOG@K:WxDxH``: a block cut tangentially through knot ``K`` of a
  knotted log, ``LOG`` being ``gran1`` (the CT-measured spruce log of the shared data) or a
  woodcam log file (``.json``); size default 100x80x50 mm, Z along the log.
- a block folder with a ``block.json`` manifest (real or synthetic): its true field if it has
  one, otherwise a field fitted to its rings (fit once, cached in the folder).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

from .appearance import ColorMapAppearance, Wood
from .errors import WoodcamError
from .fields.builtin import BUILTIN_NAMES, builtin_block

AppearanceKind = Literal["colormap"]


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
    appearance : "colormap"
    **appearance_params
        Passed to :class:`~woodcam.appearance.ColorMapAppearance` (e.g. knot darkening).
    """
    if appearance != "colormap":
        raise WoodcamError(f"appearance must be one of ['colormap']; got {appearance!r}")
    if spec.startswith("builtin:"):
        b = builtin_block(spec.split(":", 1)[1])
        app = ColorMapAppearance(species or b.species, **appearance_params)
        meta = {"species": app.species.name}
        if hasattr(b.field, "to_dict"):  # every built-in field is saveable
            meta["field"] = b.field.to_dict()
        return Stock(spec, b.size_mm, Wood(b.field, app), b.description, meta)
    if spec.startswith("log:"):
        return _open_log_block(spec, species, appearance_params)
    path = Path(spec)
    if path.is_dir() and (path / "block.json").is_file():
        return _open_block_folder(path, species, appearance_params)
    raise WoodcamError(
        f"block spec {spec!r} is neither 'builtin:NAME' (NAME one of {', '.join(BUILTIN_NAMES)}), "
        "'log:LOG@KNOT[:WxDxH]', nor a block folder with a block.json manifest"
    )


def _open_block_folder(path: Path, species, appearance_params) -> Stock:
    from .block.io import read_block  # block I/O sits beside; imported when a folder is used

    block = read_block(path)
    if block.true_field is None:
        raise WoodcamError(
            f"block folder {path} has no growth field yet; fit one with "
            f"'woodcam fit {path}' first"
        )
    field = block.true_field
    if any(f.photo is not None for f in block.faces.values()):
        app = ColorMapAppearance.fit_to_block(block, field, species or "oak", **appearance_params)
    else:
        app = ColorMapAppearance(species or "oak", **appearance_params)
    return Stock(str(path), block.size_mm, Wood(field, app), block.name, dict(block.meta))


def _open_log_block(spec: str, species, appearance_params) -> Stock:
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
    app = ColorMapAppearance(species or "spruce", **appearance_params)
    return Stock(spec, size_mm, Wood(field, app), f"block through knot {knot} of log {source}",
                 {"species": app.species.name})
