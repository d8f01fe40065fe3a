"""The stock a part is carved from: a block spec resolved to its size and its wood.

A block spec is a string the CLI and GLB metadata carry:

- ``builtin:NAME``: a built-in synthetic block (``woodcam blocks`` lists them).
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
        if hasattr(b.field, "to_dict"):
            meta["field"] = b.field.to_dict()
        return Stock(spec, b.size_mm, Wood(b.field, app), b.description, meta)
    path = Path(spec)
    if path.is_dir() and (path / "block.json").is_file():
        return _open_block_folder(path, species, appearance_params)
    raise WoodcamError(
        f"block spec {spec!r} is neither 'builtin:NAME' (NAME one of {', '.join(BUILTIN_NAMES)}) "
        "nor a block folder with a block.json manifest"
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
