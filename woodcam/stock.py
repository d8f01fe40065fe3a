"""The stock a part is carved from: a block spec resolved to its size and its wood.

A block spec is a string the CLI and GLB metadata carry:

- ``builtin:NAME`` or ``builtin:NAME:WxDxH``: a built-in synthetic block (``woodcam blocks``
  lists them) of its own size or of ``W x D x H`` mm, cut from the same wood round the same
  centre (e.g. ``builtin:flat-sawn:300x120x40``), colours included.
- ``log:LOG@K`` or ``log:LOG@K:WxDxH``: a block cut tangentially through knot ``K`` of a
  knotted log, ``LOG`` being ``gran1`` (the CT-measured spruce log of the shared data) or a
  woodcam log file (``.json``); size default 100x80x50 mm, Z along the log; every size has the
  default block's colours where they overlap (the same piece of the log).
- ``woodify:PATH/field.npz``: a block cut out of a grown object (``woodcam woodify``); size
  and position are the placement stored in the file (``--block-size``, ``--block-centre``); its
  texture is drawn in the grown object's frame, so every placement has the object's colours.
- a block folder with a ``block.json`` manifest (real or synthetic): its true field if it has
  one, otherwise a field fitted to its rings (fit once, cached in the user cache folder); a
  folder of photos only (``woodcam block from-photos``) first gets its rings detected on the
  photos (:func:`woodcam.detect.block.with_detected_rings`, cached by content in the user cache).
- a Mokume sample folder (``A_col.png``, ``A_arl-unet.png``, ... as in the Mokume dataset): a
  cube of ``MOKUME_DEFAULT_SIZE_MM`` (50 mm) whose field is fitted to its ring maps, fit once
  and cached.

Any spec may end in turns of the block under the part, ``~AXIS90`` (a multiple of 90 degrees
about the block axis ``x``, ``y`` or ``z``; chainable, e.g. ``builtin:flat-sawn~z90`` runs the
grain along Y): the block's size axes swap accordingly and the wood turns with it. It may also
end in resizes, ``[WxDxH]`` or ``[WxDxH@X,Y,Z]``: a ``W x D x H`` mm block cut from the block
before it with its corner at ``X, Y, Z`` mm of that block's frame, inside that block
(:func:`check_resize_in_block`; :func:`resize_stock`, what
``woodcam gcode --stock --stock-origin`` records in its GLB, so ``woodcam preview`` reopens
it). Turns and resizes apply in the order written. Their numbers are plain numbers (a sign and
an exponent allowed, as in ``:WxDxH``), with no spaces. One reader parses this grammar,
:func:`woodcam._specs.parse_spec` (the command line's ``--block`` check and ``--units``
conversion too), and :func:`woodcam._specs.format_spec` writes it back.

Fitted fields and neural colour volumes are cached under ``$WOODCAM_CACHE_DIR`` or the user
cache folder (``$XDG_CACHE_HOME/woodcam``, ``~/.cache/woodcam``), keyed by the block's content:
block and sample folders are only read, never written (they are often read-only shared data).
"""

from __future__ import annotations

import dataclasses
import os
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np

from ._checks import check_bool
from ._repr import summary_repr
from ._specs import ParsedSpec, check_read_as_is, format_op, parse_spec
from .appearance import ColorMapAppearance, NeuralAppearance, Wood, get_species
from .errors import BlockSpecError, WoodcamError, WoodcamWarning
from .fields.base import has_uncertainty
from .fields.builtin import BUILTIN_NAMES, builtin_block
from .frames import check_size

AppearanceKind = Literal["colormap", "neural"]


#: The colour preset of a block whose species nobody gave (a block or Mokume folder, a woodify
#: block): its colours only, never a claim about the wood (:func:`species_text`).
DEFAULT_SPECIES = "oak"


def species_text(meta: dict) -> str:
    """A stock's species as the review page and the bake's metadata say it (the one wording):
    the preset's name, or, for a block nobody gave a species (``meta["species_stated"]`` False),
    ``"not given (oak colours)"``: the default preset colours it, it is no claim about the wood.
    ``""`` where no species is recorded (a neural appearance)."""
    species = meta.get("species")
    if not species:
        return ""
    return str(species) if meta.get("species_stated", True) is not False else f"not given ({species} colours)"


@dataclass
class Stock:
    """A block to carve from.

    Attributes
    ----------
    spec : str
        The block spec it was opened from (stored in exported GLBs).
    size_mm : (W, D, H) float
        Block size in mm: width along X, depth along Y, height along Z of the block frame
        (origin at its bottom-front-left corner, ``docs/conventions.md``).
    wood : Wood
        Its growth field (block-frame points in mm -> years) and appearance.
    description : str
    meta : dict
    """

    __repr__ = summary_repr  # arrays as shapes: a notebook shows one line

    spec: str
    size_mm: tuple[float, float, float]
    wood: Wood
    description: str = ""
    meta: dict = field(default_factory=dict)

    def __post_init__(self):
        # the door of a stock built by hand: None or a name ('oak') was taken and failed far
        # away, an AttributeError in placement ('features') or a refusal in the first drawing.
        # A user's analytic wood is drawn (color, the seam) or read (features), not both.
        if not any(callable(getattr(self.wood, m, None)) for m in ("color", "features")):
            raise WoodcamError(f"Stock: wood must be a woodcam Wood (or have a method color(points_mm (n, 3), "
                               f"normals (n, 3)) -> rgb (n, 3) or features(points_mm (n, 3)) -> dict); got "
                               f"{type(self.wood).__name__}; pass Wood(field) or open the stock with open_stock")
        # a NaN, zero or (2,) size was taken and failed (or drew NaN) in the carve or the bake; a
        # spec that is no text was written into the GLB's metadata, a meta list failed there
        check_size(self.size_mm)
        if not isinstance(self.spec, str):
            raise WoodcamError(f"Stock: spec must be the block spec text (e.g. 'builtin:flat-sawn'); "
                               f"got {self.spec!r:.60}")
        if not isinstance(self.description, str):
            raise WoodcamError(f"Stock: description must be a string; got {self.description!r:.60}")
        if not isinstance(self.meta, dict):
            raise WoodcamError(f"Stock: meta must be a dict of stock metadata; got {type(self.meta).__name__}")


def resize_stock(stock: Stock, size_mm, origin_mm=(0.0, 0.0, 0.0)) -> Stock:
    """A ``W x D x H`` stock cut from ``stock``'s wood with its corner at ``origin_mm`` (block
    frame, mm): any size and position in the block, ``[0,W] x [0,D] x [0,H]`` of ``stock``
    (:func:`check_resize_in_block`; a larger block is a larger base, ``builtin:NAME:WxDxH``).
    ``size_mm`` > 0 and ``origin_mm`` finite, in mm."""
    size = np.asarray(size_mm, float).reshape(-1)
    origin = np.asarray(origin_mm, float).reshape(-1)
    if size.shape != (3,) or not (np.isfinite(size).all() and (size > 0).all()):
        raise WoodcamError(f"resize_stock: size_mm must be three finite numbers > 0 (W, D, H "
                           f"in mm), got {size_mm!r}; e.g. (167, 208, 25)")
    if origin.shape != (3,) or not np.isfinite(origin).all():
        raise WoodcamError(f"resize_stock: origin_mm must be three finite numbers (mm), got "
                           f"{origin_mm!r}; e.g. (0, 0, 0)")
    try:  # what the block is, for the fix a refusal names ('test' or the like: a folder, no fix)
        parsed: ParsedSpec | None = parse_spec(stock.spec)
    except WoodcamError:
        parsed = None
    check_resize_in_block(stock.spec, stock.size_mm, size, origin, parsed)
    return _cut(stock, size, origin)


def _cut(stock: Stock, size: np.ndarray, origin: np.ndarray) -> Stock:
    """:func:`resize_stock` past its doors: ``size`` (3,) and ``origin`` (3,) mm, checked and
    inside the block (open_stock checks its spec's resizes itself, naming the spec as typed)."""
    W, D, H = size.tolist()
    # written as the spec reader reads it back (12 digits: ':g' rounded 0.1234567 to 0.123457,
    # and its '1e-05' was no operation to the reader)
    spec = stock.spec + format_op(("resize", (W, D, H), tuple(origin.tolist())))
    if origin.any() and not isinstance(stock.wood, Wood):
        raise WoodcamError(f"resize_stock: stock.wood must be a woodcam Wood (its growth field and colours "
                           f"move with the origin); got {type(stock.wood).__name__}; open the stock with open_stock")
    # the wood itself moved, not only its colours: a wrapper shifted color() and left the growth
    # field (wood.years, wood.features) the parent's at the stock's own points. Shifted at the
    # origin too: the wood then knows it is a cut piece (Wood.in_source_frame), not the fitted
    # block whose photos name the faces (the uncertainty advice named them as this stock's)
    wood = stock.wood.shifted(origin) if isinstance(stock.wood, Wood) else stock.wood
    return Stock(spec, (W, D, H), wood, stock.description,
                 {**stock.meta, "parent_size_mm": list(stock.size_mm),
                  "origin_mm": origin.tolist()})


def check_resize_in_block(spec: str, block_size_mm, size_mm, origin_mm,
                          parsed: ParsedSpec | None = None) -> None:
    """Refuse a resize of ``size_mm`` at ``origin_mm`` (mm) that runs past the block before it,
    ``[0,W] x [0,D] x [0,H]`` of ``block_size_mm``: a resize is wood of that block, not of the
    field outside it (for a fitted block an extrapolation, wood the user does not have), as
    ``gcode --stock`` and parquetry's leaves. A :class:`~woodcam.errors.BlockSpecError`
    (``part`` "resize", ``spec``) naming ``spec``, the resize's extent, the block's and the fix;
    ``parsed``: the spec of the block before the resize, where a larger base may hold it."""
    have = np.asarray(block_size_mm, float)
    size, origin = np.asarray(size_mm, float), np.asarray(origin_mm, float)
    far = origin + size
    from .tolerances import IN_BLOCK_RTOL

    tol = IN_BLOCK_RTOL * float(have.max())  # a stock written back with 12 digits still fits

    def inside(lo, hi, block) -> bool:
        return bool((lo >= -tol).all() and (hi <= block + tol).all())

    if inside(origin, far, have):
        return
    from .limits import limit
    from .tolerances import ON_FACE_TOL_MM
    from .units import message_mm_per_unit, say_length, typed_length

    def point(v):
        return say_length(tuple(float(x) for x in v), ".4g", form="(" + ", ".join("{}" for _ in v) + ")")

    def typed(values, ok=lambda i, v: True) -> tuple[list[str], np.ndarray]:
        """Each length (mm) as the user types it (--units inch: the shortest number that reads
        back within ON_FACE_TOL_MM, not 12 digits) and ``ok(axis, mm read back)``; and the mm
        values they read back, what the suggested spec opens to."""
        texts = [typed_length(float(v), ON_FACE_TOL_MM, lambda b, i=i: ok(i, b)) for i, v in enumerate(values)]
        return texts, np.array([float(t) for t in texts]) * message_mm_per_unit()

    def op_text(size_texts, origin_texts) -> str:  # format_op's grammar, numbers as typed
        at = "@" + ",".join(origin_texts) if any(float(t) for t in origin_texts) else ""
        return f"[{'x'.join(size_texts)}{at}]"

    size_t, size_b = typed(size)
    op = op_text(size_t, typed(origin)[0])
    # a fix must open to what it says: each number chosen so the read-back resize is inside
    corner_t, corner_b = typed(np.maximum(origin, 0.0), lambda i, b: b >= 0.0)
    fits = have - corner_b
    if (fits > tol).all():
        fit_t, _ = typed(np.minimum(size, fits), lambda i, b: 0 < b <= fits[i] + tol)
        fix = f"a resize that fits, {op_text(fit_t, corner_t)} or smaller"
    else:
        fix = "a resize whose corner is inside the block"
    if parsed is not None and parsed.kind == "builtin" and not parsed.ops:
        # A sized built-in block is cut round the whole block's centre (_builtin), so its
        # corner moves by half the change of size: a base of S1 holds the wood asked, origin..far
        # of the S0 block, where S1/2 reaches both ends from the shared centre, and the resize's
        # corner in it is origin + (S1 - S0) / 2 (the same wood, not the same numbers).
        need = np.maximum(have, 2 * np.maximum(have / 2 - origin, far - have / 2))
        cap = limit("MAX_BLOCK_SIZE_MM")
        base_t, base_b = typed(need, lambda i, b: b <= cap)
        at = origin + (base_b - have) / 2
        at_t, at_b = typed(at, lambda i, b: b >= -tol and b + size_b[i] <= base_b[i] + tol)
        if (need > cap).any():
            # said, not dropped: the user looking for the larger base learns there is none
            fix += (f" (no built-in block holds the same wood: it would be {say_length(tuple(need.tolist()), '.6g')}, "
                    f"past the {say_length(cap, 'g')} limit of a block's side, "
                    "raise it with WOODCAM_MAX_BLOCK_SIZE_MM=N)")
        elif (base_b <= cap).all() and inside(at_b, at_b + size_b, base_b):
            base = parsed.base if parsed.size_mm is None else parsed.base[:parsed.base.rfind(":")]
            fix += f", or a block that holds the same wood: {base}:{'x'.join(base_t)}{op_text(size_t, at_t)}"
    elif parsed is not None and parsed.kind == "log" and not parsed.ops:
        # a larger log block is placed anew through its knot (its front face, at a depth that
        # follows its size): no larger base holds this block's wood where it is
        fix += " (a larger log block is cut anew through its knot, not round this one)"
    elif parsed is not None and parsed.kind in ("folder", "woodify"):
        fix += " (a block folder or a grown block holds only its own wood)"
    rule = (f"the resize {op} runs from {point(origin)} to {point(far)}, past the "
            f"{say_length(tuple(have.tolist()), '.4g')} block before it (its wood is (0, 0, 0) to "
            f"{point(have)}): a resize is wood of the block, not of the field outside it; give {fix}")
    raise BlockSpecError(f"block spec {spec!r}: {rule}", part="resize", text=op, rule=rule, spec=spec)


def open_stock(spec: str, *, species: str | None = None,
               appearance: AppearanceKind = "colormap", species_given: bool = True,
               size_mm: float | tuple[float, float, float] | None = None,
               **appearance_params) -> Stock:
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
    species_given : bool
        False: ``species`` is one recorded earlier (a baked GLB's), not asked for now, so a
        block whose photos set every colour is opened without the warning that the species
        changes nothing.
    size_mm : float or (W, D, H), optional
        Size in mm of a Mokume sample folder, as :func:`open_block` takes it (its files carry no
        size; default a 50 mm cube; one number a cube's side, another shape refused), before the
        spec's turns and resizes. A block folder records its own size (a warning says so when
        this differs); any other spec takes its size in the spec and refuses this.
    **appearance_params
        Passed to :class:`~woodcam.appearance.ColorMapAppearance` (e.g. knot darkening), or for
        ``"neural"`` to ``fit_neural_appearance`` (``resolution``, ``quality``, ``epochs``,
        ``cache_dir``, ``progress``).
    """
    if appearance not in ("colormap", "neural"):
        raise WoodcamError(f"appearance must be one of ['colormap', 'neural']; got {appearance!r}")
    species_given = check_bool(species_given, "species_given")
    if species is not None and species_given:
        # '' was read as "no species" and the default preset used without a word; a species
        # recorded earlier (species_given False: a baked GLB's, '' where none) is the bake's own
        get_species(species)
    # None was read as the spec 'None' and '' as the folder '.', neither the value given
    if not isinstance(spec, (str, os.PathLike)) or not str(spec).strip():
        raise WoodcamError(f"spec must be a block spec (str): 'builtin:NAME', 'log:LOG@KNOT', 'woodify:PATH' or "
                           f"a block folder; got {spec!r}; e.g. open_stock('builtin:flat-sawn')")
    parsed = parse_spec(spec)
    # the bake of a built-in block kept its own size without a word
    _check_size_for_spec(spec, parsed, size_mm)
    # built-in, log and woodify blocks have no photos: their colour map is the constructor's
    # (a folder's photos are known once it is read: _real_block_stock checks again)
    _check_appearance_params(appearance, appearance_params, photos=parsed.kind == "folder",
                             where=f"block spec {parsed.base!r}")
    stock = _open_base_stock(parsed, species, appearance, appearance_params, species_given, size_mm)
    if species is not None and species_given and stock.meta.get("appearance") == "neural":
        # nothing silently dropped: the neural volumes take every colour from the photos
        warnings.warn(f"--species {species}: the neural appearance learns every colour from the block's "
                      "photos; the species changes nothing (it colours --appearance colormap)",
                      WoodcamWarning, stacklevel=2)
    # a neural appearance that fell back to the colour map (a block without photos) used none of
    # its parameters: a GLB recording them reopened as "neural" and warned again in preview/review
    used = appearance_params if stock.meta.get("appearance") == appearance else {}
    stock.meta["appearance_params"] = {k: (list(v) if isinstance(v, tuple) else v)
                                       for k, v in used.items()
                                       if isinstance(v, (int, float, str, tuple, list))}
    if not parsed.ops:
        return stock
    turns = []
    for i, op in enumerate(parsed.ops):  # in the order written: a resize of a turned block is cut in the turned frame
        if op[0] == "resize":  # named as given (the stock's own spec lacks the turns before it)
            size, origin = np.asarray(op[1], float), np.asarray(op[2], float)  # checked by parse_spec
            check_resize_in_block(str(spec), stock.size_mm, size, origin,
                                  dataclasses.replace(parsed, ops=parsed.ops[:i]))
            stock = _cut(stock, size, origin)  # not resize_stock: its spec parsed and checked again
        else:
            wood, size = stock.wood.turned(op[1], op[2], stock.size_mm)
            turns.append(op[1:])
            stock = Stock(stock.spec, size, wood, stock.description, {**stock.meta, "turns": list(turns)})
    stock.spec = spec  # as given (resize_stock writes its numbers with :g)
    return stock


def _check_size_for_spec(spec, parsed: ParsedSpec, size_mm) -> None:
    """Refuse ``size_mm`` for a spec that is no folder (:func:`open_stock`, :func:`open_block`):
    a built-in, log or woodify block takes its size in the spec."""
    if size_mm is not None and parsed.kind != "folder":
        raise WoodcamError(f"size_mm (--size-mm) sizes a Mokume sample folder only; block spec {str(spec)!r} is "
                           f"a {parsed.kind} block, whose size is in the spec (e.g. builtin:flat-sawn:40x40x40); "
                           "leave size_mm out")


def _check_appearance_params(appearance: str, params: dict, *, photos: bool = True,
                             where: str = "") -> None:
    """Refuse a keyword the chosen appearance does not take, before any fit (``foo=1`` was a
    bare TypeError deep inside, after the block was read).

    photos : whether the stock's colour map is fitted to face photos
        (:meth:`ColorMapAppearance.fit_to_block`, which also takes ``anchor``); a stock without
        photos (built-in, log and woodify blocks, a folder without photos) calls the
        :class:`ColorMapAppearance` constructor alone. Ignored for ``"neural"``.
    where : what the stock is, named in the message (e.g. ``"block spec 'builtin:flat-sawn'"``).
    """
    from collections.abc import Callable
    import inspect

    # set by the block spec (the wood's frame: a sized, turned or log block's colours are its
    # parent's), never an appearance parameter of the caller's
    by_spec = {"texture_frame"}
    targets: list[Callable]
    if appearance == "neural":
        from .appearance.neural import fit_neural_appearance

        targets = [fit_neural_appearance]
    elif photos:  # a block's photos go through fit_to_block (anchor=) to the constructor
        targets = [ColorMapAppearance, ColorMapAppearance.fit_to_block]
    else:
        targets = [ColorMapAppearance]
    taken = {k for t in targets for k, p in inspect.signature(t).parameters.items()
             if p.kind is not p.VAR_KEYWORD} - {"self", "cls", "species", "block", "field"} - by_spec
    unknown = sorted(set(params) - taken)
    if unknown:
        without = appearance != "neural" and not photos
        kind = f"{appearance} appearance" + (" of a stock without photos" if without else "")
        got = ", ".join(repr(k) for k in unknown)
        photo_only = [k for k in unknown
                      if without and k in inspect.signature(ColorMapAppearance.fit_to_block).parameters]
        fixes = [f"{', '.join(photo_only)} fit{'s' if len(photo_only) == 1 else ''} colours to face "
                 f"photos, which {where or 'this stock'} has none of: drop {'it' if len(photo_only) == 1 else 'them'}"
                 ] if photo_only else []
        spec_set = [k for k in unknown if k in by_spec]
        if spec_set:
            fixes.append(f"{', '.join(spec_set)} is set by the block spec, not an appearance parameter: "
                         "drop it (a sized, turned or resized spec keeps the parent block's colours)")
        misspelt = [k for k in unknown if k not in photo_only and k not in by_spec]
        if misspelt:
            fixes.append(f"check the spelling of {', '.join(repr(k) for k in misspelt)}")
        fix = "; ".join(fixes)
        raise WoodcamError(f"open_stock: appearance_params must be parameters of the {kind} "
                           f"({', '.join(sorted(taken))}); got {got}; {fix}")


def spec_digest(spec: str) -> str:
    """Content identity of the block ``spec`` names: a digest of the files woodcam reads from a
    block or sample folder (:func:`woodcam.block.io.block_folder_files`: names and contents;
    the user's notes.txt dropped in made every part baked from it "changed since baked"), of a
    log file or woodify field, or of the spec itself for synthetic blocks, and of its turns and
    resizes: a resized block is not the block it was cut from (a block without them, or a folder
    holding only files woodcam reads, keeps the digest it always had)."""
    from . import __version__
    from ._cache import digest

    parsed = parse_spec(spec)
    path = parsed.path
    if path is not None and path.is_dir():
        from .block.io import block_folder_files

        files = block_folder_files(path)
        content = digest([(str(p.relative_to(path)), p) for p in files])
    elif path is not None and path.is_file():
        content = digest(path)
    else:
        content = digest(parsed.base, __version__)
    # the parsed operations: '~Z90' and '~z90.0' are one turn (a list's repr, as it always was)
    return digest(content, repr(list(parsed.ops))) if parsed.ops else content


def _builtin(parsed: ParsedSpec):
    """``builtin:NAME`` or ``builtin:NAME:WxDxH`` -> ``(BuiltinBlock, field, size_mm)``; a given
    size cuts a block of that size from the same wood, centred where the built-in block's centre
    is."""
    b = builtin_block(parsed.source)
    if parsed.size_mm is None:
        return b, b.field, tuple(b.size_mm)
    size = parsed.size_mm
    from .fields.placement import PlacedField

    offset = (np.asarray(b.size_mm, dtype=float) - np.asarray(size)) / 2
    return b, PlacedField(b.field, origin_mm=offset), size


def _open_base_stock(parsed: ParsedSpec, species, appearance, appearance_params,
                     species_given=True, size_mm=None) -> Stock:
    """The stock ``parsed``'s base names, before its turns and resizes; ``size_mm`` a folder's
    (:func:`open_stock`)."""
    spec = parsed.base
    if parsed.kind == "builtin":
        b, field, size = _builtin(parsed)
        return _synthetic_stock(spec, field, size, species or b.species, b.description,
                                appearance, appearance_params, _texture_frame(parsed, field))
    if parsed.kind == "log":
        field, size_mm, description, frame = _log_block_field(parsed)
        return _synthetic_stock(spec, field, size_mm, species or "spruce", description,
                                appearance, appearance_params, frame)
    if parsed.kind == "woodify":
        field, size_mm, description = _woodify_field(parsed)
        if np.allclose(field.rotation, np.eye(3)):
            return _synthetic_stock(spec, field, size_mm, species or DEFAULT_SPECIES, description,
                                    appearance, appearance_params, _texture_frame(parsed, field),
                                    stated=species is not None)
        # A block placed turned in the grown object (WoodifiedField.placed(rotation=)): its wood
        # is that of the object-aligned box round it, seen turned (Wood.rotated). Coloured in its
        # own frame, eq. 10's per-axis blend and end grain followed the turned block's axes: the
        # same object point 4/255 off at a 30 degree turn about the stem and up to 40/255 tilted.
        R, o = field.rotation, field.block_origin_mm
        corners = np.array(np.meshgrid(*[(0.0, v) for v in size_mm], indexing="ij")).reshape(3, -1).T
        pts = o + corners @ R.T
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        box = field.placed(tuple(hi - lo), tuple((lo + hi) / 2))
        aligned = _synthetic_stock(spec, box, tuple(float(v) for v in hi - lo), species or DEFAULT_SPECIES,
                                   description, appearance, appearance_params, _texture_frame(parsed, box),
                                   stated=species is not None)
        return Stock(spec, tuple(size_mm), aligned.wood.rotated(R, o - lo), description, aligned.meta)
    path = _existing_folder(spec)
    if (path / "block.json").is_file():
        return _open_block_folder(path, species, appearance, appearance_params, species_given, size_mm)
    return _open_mokume_folder(path, species, appearance, appearance_params, species_given, size_mm)


def open_block(spec: str, *, size_mm: float | tuple[float, float, float] | None = None, face_px: int = 256):
    """Resolve a block spec to ``(block, field)``: the one block resolver of every command.

    Parameters
    ----------
    spec : str
        As :func:`open_stock`: ``builtin:NAME`` and ``log:LOG@K[:WxDxH]`` give a synthetic
        block whose six face photos, ring maps and traces are rendered by
        :func:`woodcam.synth.synth_block` (seed 0) from the true field; a folder is read by
        :func:`woodcam.block.io.read_block_folder` (block folder or Mokume sample folder); a
        folder of photos only gets its rings detected (cached, :mod:`woodcam.detect.block`).
    size_mm : float or (W, D, H), optional
        Size in mm of a Mokume sample folder (its files carry no size; default a 50 mm cube), one
        number a cube's side; a Mokume sample is a cube, so another size is refused there. Any
        other spec takes its size in the spec and refuses this, as :func:`open_stock` does.
    face_px : int
        Pixels along the largest face side of a synthetic block's photos.

    Returns
    -------
    (Block, field or None)
        The field is the block's true field where one is known (synthetic blocks, block
        folders that store one), else None: no field is fitted here.
    """
    check_read_as_is(spec)  # no turn or resize: this command reads the block as it is
    parsed = parse_spec(spec)  # a loose end ('[40x30]') named as the bad operation it is
    _check_size_for_spec(spec, parsed, size_mm)     # it was dropped without a word
    if parsed.kind != "folder":
        from .synth import synth_block

        if parsed.kind == "builtin":
            b, field, size = _builtin(parsed)
            name = b.name if tuple(size) == tuple(b.size_mm) else spec.replace(":", "-")
            frame = _texture_frame(parsed, field)
        elif parsed.kind == "woodify":
            field, size, _ = _woodify_field(parsed)
            name = "woodify-" + Path(parsed.source).parent.name
            frame = _texture_frame(parsed, field)
        else:
            field, size, _, frame = _log_block_field(parsed)
            name = spec.replace(":", "-").replace("/", "_")
        return synth_block(field, size, face_px=face_px, seed=0, name=name, texture_frame=frame), field
    from .block.io import read_block_folder

    from .detect.block import with_detected_rings

    folder = _existing_folder(spec)
    block = read_block_folder(folder, _sides(size_mm))
    # A block of photos only: rings detected once, cached by content outside the folder (the
    # user's files a 'block from-photos' remake left unnamed in it read in)
    block = with_detected_rings(block, progress=True, folder=folder)
    return block, block.true_field


def _woodify_field(parsed: ParsedSpec):
    """``woodify:PATH/field.npz`` -> (field, size_mm, description): the block stored in it."""
    from .fields.base import rings_crossed
    from .woodify.field import WoodifiedField

    path = parsed.source
    field = WoodifiedField.load(path)
    # a block inside one growth layer was one flat colour without a word: its years on a
    # 9 x 9 x 9 lattice of the block (corners and faces included) cross no whole year
    lattice = np.stack(np.meshgrid(*[np.linspace(0.0, v, 9) for v in field.block_size_mm], indexing="ij"), -1)
    years = field(lattice.reshape(-1, 3))
    if rings_crossed(years) == 0:
        size = " x ".join(f"{v:.4g}" for v in field.block_size_mm)
        warnings.warn(f"block {parsed.base}: its {size} mm of wood lie in one growth layer (years "
                      f"{years.min():.3g} to {years.max():.3g} of the {field.years_final:g} grown), so it shows no "
                      "ring, one flat colour; cut a block that reaches across a ring (woodcam woodify --block-size "
                      "larger, or --block-centre nearer the bark) or grow more years (--years)",
                      WoodcamWarning, stacklevel=3)
    return field, field.block_size_mm, f"block cut from an object grown {field.years_final:g} years ({path})"


def _existing_folder(spec: str) -> Path:
    """The folder a non-builtin, non-log spec names, or the error listing every kind of spec."""
    path = Path(spec)
    if path.name == "block.json" and path.is_file():
        path = path.parent
    if not path.is_dir():
        raise WoodcamError(
            f"block spec {spec!r} is neither 'builtin:NAME' (NAME one of "
            f"{', '.join(BUILTIN_NAMES)}), 'log:LOG@KNOT[:WxDxH]', 'woodify:PATH/field.npz', nor an "
            "existing folder: a block "
            "folder (with block.json) or a Mokume sample folder (A_col.png, A_arl-unet.png, ...)"
        )
    return path


def _synthetic_stock(spec, field, size_mm, species, description, appearance, params,
                     texture_frame=None, stated=True) -> Stock:
    """A stock whose true field is known but which has no photos of its own; ``texture_frame``
    (a :class:`~woodcam.fields.base.LogFrame` or None, :func:`_texture_frame`) is the colour
    map's (:class:`ColorMapAppearance`) and the neural appearance's synthetic photos'.
    stated : False where ``species`` is only :data:`DEFAULT_SPECIES` (:func:`species_text`)."""
    from .fields.state import is_saveable

    meta = {"appearance": appearance}
    if is_saveable(field):
        meta["field"] = field.to_dict()
    if appearance == "neural":
        # The neural appearance learns from face photos: render them from the field first.
        from .appearance.neural import fit_neural_appearance
        from .synth import synth_block

        # in the texture frame of the block cut from: a sized block's photos (and so its
        # learned colours) are the whole block's at the same wood point
        photos = synth_block(field, size_mm, face_px=256, seed=0, name=spec.replace(":", "-"),
                             texture_frame=texture_frame)
        app = fit_neural_appearance(photos, field, **params)
        meta["appearance_key"] = app.meta.get("key")
    else:
        app = ColorMapAppearance(species, **params, texture_frame=texture_frame)
        meta["species"] = app.species.name
        meta["species_stated"] = bool(stated)
    return Stock(spec, tuple(size_mm), Wood(field, app), description, meta)


def fitted_field(block, folder: Path | None = None, method: str = "evidence", faces=None):
    """The growth field fitted to a block's rings, fitted once and cached.

    The cache entry lives in the user cache folder (:func:`woodcam._cache.cache_dir`
    ``("fields")``), never in the block's own folder (which may be read-only shared data), and is
    keyed by a digest of everything the fit reads: size, photos, ring maps, traces and knot masks
    (:func:`~woodcam.appearance.volumes.block_fingerprint`), the method (for ``"neural"``, with
    the packaged GTF model's spec and weights files), and
    :data:`woodcam.inference.fit.FIT_VERSION` with the package version. An edited block is a
    new entry; an unreadable entry is discarded with a warning and refitted; concurrent first
    runs fit once (a lock) and share the result.

    folder : the block folder, only named in errors (None for a Mokume sample).
    faces : the faces to fit to (:func:`~woodcam.inference.fit_block`'s ``faces``, part of the
        key); None, every face (the field ``bake``, ``preview`` and ``woodcam fit`` share).
    """

    from . import __version__
    from ._cache import cache_dir, digest, entry_path, load_or_build
    from .appearance.volumes import block_fingerprint
    from .fields.grid import GridField
    from .inference import fit_block
    from .inference.fit import FIT_VERSION

    if not any(f.has_rings for f in block.faces.values()):
        raise WoodcamError(
            f"block {folder or block.name} has neither a true field nor traced rings or ring maps "
            "to fit one to; trace rings on at least one face (or use 'woodcam block synth')"
        )
    # the neural fit decodes with the packaged GTF model: weights retrained or restored into
    # woodcam/models are another fit (the entry made with the old weights was reused); the other
    # methods' keys are as they were
    model: tuple = ()
    if method == "neural":
        from .fields.neural import MODELS_DIR, SPEC_NAME, WEIGHTS_NAME

        model = ("gtf", *(p if p.is_file() else "missing" for p in (MODELS_DIR / SPEC_NAME, MODELS_DIR / WEIGHTS_NAME)))
    # every face: the key it always had (the entries fitted before stay valid)
    key = digest(block_fingerprint(block), method, FIT_VERSION, __version__, *model,
                 *(() if faces is None else ("faces", list(faces))))
    path = entry_path(cache_dir("fields"), block.name, f"{method}-{key}")
    field, hit = load_or_build(path, load=GridField.load,
                               build=lambda: fit_block(block, method=method, faces=faces),
                               save=lambda f, tmp: f.save(tmp), what=f"fitted field of block {block.name!r}")
    meta = getattr(field, "meta", None)
    meta = meta if isinstance(meta, dict) else {}
    if has_uncertainty(field) and "size_mm" not in meta:
        # an evidence fit cached before bake_evidence recorded the box its faces are named in
        # (the same cache key): the block it is keyed by. uncertainty_report measured a cut
        # stock's nearest face in the stock's own box without it, and named the wrong one.
        meta["size_mm"] = [float(v) for v in block.size_mm]
    if hit and (meta.get("contradicted") or meta.get("unverified")):
        # the fit warned when it was made; a cached fit is the same fit and must say so again
        # (it was silent on every later run, and for the second of two concurrent ones)
        warnings.warn(str(meta.get("message", "")), WoodcamWarning, stacklevel=2)
    return field


def _sides(size_mm) -> tuple[float, float, float] | None:
    """``size_mm`` (None, a cube's side or (W, D, H)) as :func:`woodcam.block.io.read_block_folder`
    takes it; its values are checked there."""
    if size_mm is None:
        return None
    sides = [float(v) for v in np.broadcast_to(np.asarray(size_mm, float), (3,))]
    return (sides[0], sides[1], sides[2])


def _open_mokume_folder(path: Path, species, appearance, appearance_params, species_given=True,
                        size_mm=None) -> Stock:
    from .block.io import read_block_folder

    block = read_block_folder(path, _sides(size_mm))
    stock = _real_block_stock(str(path), block, fitted_field(block, None), species, appearance,
                              appearance_params, cache_dir=None, species_given=species_given)
    # the sample's own size (its files carry none), kept through turns and resizes: a baked GLB
    # records it (woodcam.pipeline) so that preview and review reopen the same wood
    stock.meta["sample_size_mm"] = [float(v) for v in block.size_mm]
    return stock


def _open_block_folder(path: Path, species, appearance, appearance_params, species_given=True,
                       size_mm=None) -> Stock:
    from .block.io import read_block_folder  # imported when a folder is used

    from .detect.block import with_detected_rings

    # A block of photos only: rings detected once, cached by content outside the folder (the
    # user's files a 'block from-photos' remake left unnamed in it read in); a size given is
    # warned of by the reader (the folder records its own)
    block = with_detected_rings(read_block_folder(path, _sides(size_mm)), progress=True, folder=path)
    field = block.true_field if block.true_field is not None else fitted_field(block, path)
    return _real_block_stock(str(path), block, field, species, appearance, appearance_params,
                             cache_dir=None, species_given=species_given)


def _real_block_stock(spec, block, field, species, appearance, appearance_params, cache_dir,
                      species_given=True) -> Stock:
    if appearance == "neural":
        from .appearance.neural import block_appearance

        if cache_dir is not None:
            appearance_params.setdefault("cache_dir", cache_dir)
        app = block_appearance(block, field, "neural", species=species or DEFAULT_SPECIES, **appearance_params)
    elif any(f.photo is not None for f in block.faces.values()):
        from .frames import FACE_AXIS

        axes = {FACE_AXIS[n] for n, f in block.faces.items() if f.photo is not None}
        # nothing silently dropped: photos set every colour
        if species is not None and species_given and len(axes) == 3:
            warnings.warn(f"--species {species}: block {block.name!r} has photos along all three axes, and its "
                          "colours are fitted to them; the species changes nothing here (it colours the axes "
                          "without photos)", WoodcamWarning, stacklevel=2)
        app = ColorMapAppearance.fit_to_block(block, field, species or DEFAULT_SPECIES, **appearance_params)
    else:
        _check_appearance_params(appearance, appearance_params, photos=False, where=f"block {block.name!r}")
        app = ColorMapAppearance(species or DEFAULT_SPECIES, **appearance_params)
    # the kind used, not the one asked for: "neural" falls back to the colour map without photos
    meta = {**dict(block.meta), "species": species or DEFAULT_SPECIES, "species_stated": species is not None,
            "appearance": "neural" if isinstance(app, NeuralAppearance) else "colormap"}
    return Stock(spec, block.size_mm, Wood(field, app), block.name, meta)


#: Size (W, D, H) mm of ``log:LOG@K`` without a size; every size through a knot draws its texture.
_LOG_BLOCK_SIZE_MM = (100.0, 80.0, 50.0)


def _log_block_field(parsed: ParsedSpec):
    """``log:LOG@K[:WxDxH]`` -> (block-frame field, size_mm, description, texture_frame): the
    texture frame is that of ``log:LOG@K`` (the block of the default size through the same knot)
    placed in this block's frame, None for the default size itself. Every size of block through
    a knot draws the default block's texture, so the same piece of the log has the same colours
    in each."""
    from .fields import KnottedLogField, block_at_knot, place_block_in_log
    from .logs.io import gran1_folder, read_gran1, read_log

    source, knot, spec = parsed.source, parsed.knot, parsed.base
    assert knot is not None  # parse_spec reads a log block's knot
    size_mm = parsed.size_mm or _LOG_BLOCK_SIZE_MM
    # a spec has no folder= to pass (read_gran1's own fix): it says the spec's way
    log = read_gran1(gran1_folder(f"or cut the block from a log file of your own: "
                                  f"'log:LOG.json@{knot}'")) \
        if source == "gran1" else read_log(source)
    if not 0 <= knot < len(log.knots):
        # a spec that names no block: the command line says it of its --block, exit 2 (it exited 1)
        if not log.knots:  # "must be 0..-1 ...; e.g. '@0'" offered the index it refused
            rule = (f"log {source} has no knots, and a log block is cut through one; give a log with "
                    "knots (e.g. 'log:gran1@0') or cut a builtin block (e.g. 'builtin:flat-sawn')")
            raise BlockSpecError(f"block spec {spec!r}: {rule}", part="log", text=f"@{knot}", rule=rule,
                                 spec=parsed.spec)
        rule = (f"the knot index must be 0..{len(log.knots) - 1} (log {source} has {len(log.knots)} "
                f"knot{'' if len(log.knots) == 1 else 's'}); got {knot}; e.g. '{spec[:spec.rfind('@')]}@0'")
        raise BlockSpecError(f"knot index in {spec!r} must be 0..{len(log.knots) - 1}; got {knot}",
                             part="log", text=f"@{knot}", rule=rule, spec=parsed.spec)
    placement = block_at_knot(log, knot, size_mm)
    _check_block_in_log(parsed, log, placement, size_mm)
    log_field = KnottedLogField(log)
    field = place_block_in_log(log_field, *placement)
    frame = None
    if parsed.size_mm is not None:  # the same log, read once: the default block's placement through the knot
        default = place_block_in_log(log_field, *block_at_knot(log, knot, _LOG_BLOCK_SIZE_MM))
        frame = _frame_in(field.frame, default.frame)
    return field, size_mm, f"block through knot {knot} of log {source}", frame


#: Share of a log block outside its log (past the bark or the log's ends) above which the spec
#: is refused (most of it would be extrapolated wood) or warned of (a corner in the bark is wane).
_LOG_BLOCK_OUTSIDE_REFUSED, _LOG_BLOCK_OUTSIDE_WARNED = 0.5, 0.05


def _check_block_in_log(parsed: ParsedSpec, log, placement, size_mm) -> None:
    """Refuse a ``log:LOG@K:WxDxH`` block mostly outside its log, warn of one partly outside:
    the field there is extrapolated, wood no log holds (a 1000 mm cube through a knot of the
    143 mm-radius Gran_1 was drawn without a word, 97 % of it made-up rings)."""
    from .fields.knots import share_outside_log

    share = share_outside_log(log, *placement, size_mm)
    if share <= _LOG_BLOCK_OUTSIDE_WARNED:
        return
    W, D, H = (float(v) for v in size_mm)
    where = (f"{100 * share:.0f} % of the {W:g} x {D:g} x {H:g} mm block through knot {parsed.knot} lies "
             f"outside log {parsed.source} (radius {log.r_min_mm:.0f}-{log.r_max_mm:.0f} mm, "
             f"{log.length_mm:.0f} mm long): the wood there is extrapolated")
    if share > _LOG_BLOCK_OUTSIDE_REFUSED:
        rule = (f"the block must lie mostly inside the log; {where}; give a smaller WxDxH "
                f"(e.g. the default {'x'.join(f'{v:g}' for v in _LOG_BLOCK_SIZE_MM)})")
        raise BlockSpecError(f"block spec {parsed.spec!r}: {rule}", part="size", text=f"{W:g}x{D:g}x{H:g}",
                             rule=rule, spec=parsed.spec)
    warnings.warn(f"block spec {parsed.spec!r}: {where}; a smaller WxDxH stays inside it",
                  WoodcamWarning, stacklevel=4)


def _texture_frame(parsed: ParsedSpec, field):
    """The frame a built-in or woodify block's texture is drawn in (colour map and synthetic
    photos alike), placed in its block frame, or None (its own): a sized built-in draws the whole
    block's, a woodify block the grown object's (two blocks placed differently in the same
    object, --block-size, --block-centre). The same wood has the same colours however it is cut.
    (A log block's frame, the default-size block's through the same knot, comes with the block
    from :func:`_log_block_field`, which reads the log once.)"""
    if parsed.kind == "builtin":  # a size given: the PlacedField of _builtin in the whole block
        return None if parsed.size_mm is None else field.frame
    if parsed.kind == "woodify":
        return field.object_frame
    raise ValueError(f"_texture_frame: no texture frame rule for {parsed.spec!r} (log blocks: "
                     "_log_block_field)")  # a programming error, never a user's input


def _frame_in(here, there):
    """The frame ``there`` (a block's LogFrame in the log) placed in the frame of the block whose
    LogFrame in the same log is ``here``; None when they are the same block frame."""
    from .fields.base import LogFrame

    if here == there:
        return None
    # block point p -> log point rot_h (p - c_h) -> default block point rot_t^T (...) + c_t
    rot = there.rotation.T @ here.rotation
    centre = np.asarray(here.pith_point_mm, float) - rot.T @ np.asarray(there.pith_point_mm, float)
    return LogFrame(tuple(centre), tuple(rot[2]), tuple(rot[0]))
