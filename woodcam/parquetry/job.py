"""Parquetry parameters (seed 002, Table 1) and the job file of the paper's reference code.

The job layout is WoodPixel's JSON::

    {"source_textures": [{"texture": "scan.jpg", "mask": "mask.png", "id": "oak", "scale": 1.0,
                          "dpi": 300.0}],
     "targets": [{"filename": "eye.png", "scale": 1.0, "dpi": 300.0}],
     "num_source_rotations": 15, "patch_levels": 0, "patch_quality_factor": 1.2,
     "weight_intensity": 0.5, "weight_sobel": 0.5, "histogram_matching": 0.5,
     "sort_patches_saliency": true, ...}

with woodcam's own keys (Table 1 names in mm, fabrication, veneers sliced from blocks) under
``"woodcam"``. Relative paths are relative to the job file. A texture's resolution is
``dpi / 25.4 * scale`` px/mm. A job file's lengths are mm; ``"woodcam": {"units": "mm"}``
(the only unit it may name; :func:`write_job` writes it) says so.
"""

from __future__ import annotations

import json
import math
import numbers
import re
import warnings
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path
from typing import Literal

import numpy as np

from .._checks import check_path
from .._repr import summary_repr
from .._specs import absolute_spec, spec_path
from ..errors import WoodcamError, WoodcamWarning
from ..limits import limit
from ..tolerances import IN_BLOCK_RTOL
from ..units import message_unit, say_length, typed_length

Priority = Literal["saliency", "center"]

#: Largest coarse search (pixels over all sheets and rotations) the automatic coarse factor
#: allows: one such search (two feature channels) takes ~0.03 CPU-s on the 2-core machine.
AUTO_COARSE_PX = 4_500_000
QueueOrder = Literal["interleaved", "sequential"]


@dataclass
class ParquetryParams:
    """Every knob of a parquetry run; defaults are the paper's Table 1 where it has one.

    w_intens, w_edge : feature weights of eq. 1 (Table 1: 0.5, 0.5)
    w_hist : histogram-matching blend of eq. 2 (Table 1: 0.5)
    image_size_mm : the panel's shorter side (Table 1: 360 mm)
    patch_mm : smallest patch side (Table 1: 14 mm)
    n_adaptive, w_adaptive : adaptive levels and quality factor (Table 1: 0, 1.2); a patch of
        side ``patch_mm * 2**L`` splits into four when ``w_adaptive * (sum of their costs)`` is
        below its own cost
    n_rot : rotated copies of each sheet (sec. 3.2: 15)
    priority : "saliency" (fine-grained centre-surround saliency) or "center" (Fig. 6)
    queue : several targets "interleaved" by saliency or "sequential" (Fig. 14)
    px_per_mm : working resolution of sheets and target for matching
    overlap_mm : how far patches grow into their neighbours for seam cutting (eq. 8-9); None:
        ``min(patch_mm / 4, (patch_mm - min_piece_mm) / 2)``, which keeps every fragment at
        least ``min_piece_mm`` wide by construction; 0: square patches, no seams
    min_piece_mm : narrowest fragment that can be cut and handled (the paper's 5 mm bound)
    tool_diameter_mm : router bit; concave corners are at least its radius
    kerf_mm : wood lost between two pieces on a sheet (default: the tool diameter)
    mode : "fast" (coarse-to-fine, exact re-ranking) or "exhaustive"
    coarse_factor, top_k : the fast mode's pyramid factor and re-ranked candidates; None
        chooses the smallest of 4, 8, 16 whose coarse search holds at most
        ``AUTO_COARSE_PX`` pixels (the four 600 x 400 mm sheets at 4 px/mm of the issue's
        workload get 16)
    single_use : every piece of veneer is cut once (the paper's constraint; default True);
        False gives the unconstrained matcher, wood reused, an upper bound of the quality
    w_struct : weight of the structural term (SSIM's contrast-structure, 7 x 7 windows of the
        target image's own pixels, the wood area-averaged to them) that re-ranks the ``rerank``
        cheapest distinct free candidates of eq. 4 (woodcam's addition; 0: eq. 4 alone).
        0.02 raised SSIM by 0.01-0.02 on the skimage targets at an unchanged feature cost
        (tests/bench/test_parquetry_bench.py)
    flat_detail, flat_rerank : where the target is flat (the share of its 7 x 7 windows on
        its own pixels with a variance below SSIM's C2), the fast coarse search weighs its
        detail-amplitude channel up to ``flat_detail`` times (calm wood is ranked in) and up to
        ``flat_rerank`` candidates are re-ranked; 1.0 and ``rerank`` turn both off (woodcam's
        addition; README, "flat windows"). Defaults 3 and 12: tuned on crops of moon and
        clock only, they narrow the SSIM gap to the baseline on all four bar targets at eq. 8
        +1-2 %, keep the speed workload under 0.05 CPU-s per patch and fast mode within 5 %
        of the exhaustive search's cost (4.9 % at 4 px/mm; tests/bench)
    """

    w_intens: float = 0.5
    w_edge: float = 0.5
    w_hist: float = 0.5
    image_size_mm: float = 360.0
    patch_mm: float = 14.0
    n_adaptive: int = 0
    w_adaptive: float = 1.2
    n_rot: int = 15
    priority: Priority = "saliency"
    queue: QueueOrder = "interleaved"
    px_per_mm: float = 4.0
    overlap_mm: float | None = None
    min_piece_mm: float = 5.0
    tool_diameter_mm: float = 2.0
    kerf_mm: float | None = None
    mode: Literal["fast", "exhaustive"] = "fast"
    coarse_factor: int | None = None
    top_k: int = 12
    single_use: bool = True
    w_struct: float = 0.02
    rerank: int = 4
    flat_detail: float = 3.0
    flat_rerank: int = 12

    def __post_init__(self) -> None:
        # checked when made, as every door: ParquetryParams(patch_mm='14') or n_rot=0 was taken
        # and failed (or ran) only when a run called check()
        self.check()

    def check(self, *, said: _Said | None = None) -> ParquetryParams:
        """Validate (done when made; call again after changing a field); returns self.
        ``said``: how the errors name the parameters (:func:`read_job` names a job file's keys);
        default: their Python names, with the command line's options in the fixes."""
        n = said or _Said()
        for f in fields(self):  # the types first: a job file's "abc" or NaN fails here, by name
            setattr(self, f.name, _check_type(n.where + n.typed(f.name), getattr(self, f.name), str(f.type),
                                              fix=n.default_fix(f.name, f.default)))
        if not 1 <= self.n_rot <= 360:  # 1e9 filled the memory before the search's own estimate
            raise n.error(f"{n('n_rot')} must be in [1, 360] (rotated copies of each sheet, sec. 3.2); "
                          f"got {self.n_rot}")
        if not 0 < self.px_per_mm <= 50:  # 200 px/mm asked OpenCV for 1.6 GB on a 100 mm veneer
            raise n.error(f"{n('px_per_mm')} must be in (0, 50] (the working resolution; 4 is the paper's "
                          f"scale); got {self.px_per_mm}")
        if self.min_piece_mm < 0:
            raise n.error(f"{n('min_piece_mm')} must be >= 0 mm; got {self.min_piece_mm}")
        for name in ("w_intens", "w_edge", "w_hist"):
            v = getattr(self, name)
            if not 0.0 <= v <= 1.0:
                raise n.error(f"{n(name)} must be in [0, 1] (eq. 1-2 of seed 002); got {v}")
        if self.w_intens + self.w_edge <= 0:
            raise n.error(f"{n('w_intens')} + {n('w_edge')} must be > 0; both are 0, nothing would be matched")
        if self.patch_mm < self.min_piece_mm:
            raise n.error(
                f"{n('patch_mm')} must be at least {n('min_piece_mm')} = {self.min_piece_mm:g} mm (the smallest "
                f"piece that can be cut and assembled); got {self.patch_mm:g} mm; use a larger "
                f"{n.opt('patch_mm')} or lower {n.opt('min_piece_mm')}")
        cap = limit("MAX_BLOCK_SIZE_MM")
        if not self.patch_mm <= self.image_size_mm <= cap:  # 1e300 reached OpenCV's assertion
            raise n.error(f"{n('image_size_mm', opt=True)} must be in [{n('patch_mm')} = {self.patch_mm:g}, "
                          f"{cap:g}] mm; got {self.image_size_mm:g}; raise it with WOODCAM_MAX_BLOCK_SIZE_MM=N")
        if self.n_adaptive < 0 or self.w_adaptive <= 0:
            raise n.error(f"{n('n_adaptive')} must be >= 0 and {n('w_adaptive')} > 0; got {self.n_adaptive}, "
                          f"{self.w_adaptive}")
        if self.priority not in ("saliency", "center"):
            raise n.error(f"{n('priority')} must be one of ['saliency', 'center']; got {self.priority!r}")
        if self.queue not in ("interleaved", "sequential"):
            raise n.error(f"{n('queue')} must be one of ['interleaved', 'sequential']; got {self.queue!r}")
        if self.mode not in ("fast", "exhaustive"):
            raise n.error(f"{n('mode')} must be one of ['fast', 'exhaustive']; got {self.mode!r}")
        if self.px_per_mm <= 0 or (self.kerf_mm or 0) < 0:
            raise n.error(f"{n('px_per_mm')} must be > 0 and {n('kerf_mm')} >= 0; got "
                          f"{self.px_per_mm}, {self.kerf_mm}")
        if not self.tool_diameter_mm > 0:  # 0: tool paths on the outlines, no kerf between pieces
            raise n.error(f"{n('tool_diameter_mm', opt=True)} must be > 0 mm: the router bit cuts a "
                          f"groove that wide, and its paths are offset by half of it; got "
                          f"{self.tool_diameter_mm:g}; give the bit's diameter, e.g. 2 (set {n('kerf_mm')} "
                          "apart for the wood lost between pieces)")
        if self.w_struct < 0 or self.rerank < 1:
            raise n.error(f"{n('w_struct')} must be >= 0 and {n('rerank')} >= 1; got {self.w_struct}, "
                          f"{self.rerank}")
        if self.flat_detail < 1.0:
            raise n.error(f"{n('flat_detail', opt=True)} must be >= 1; got {self.flat_detail}; use "
                          f"{n.value('flat_detail', 1)} to turn the flat-window weighting off")
        # the one floor of flat_rerank (the CLI's range leaves it here): the candidates the
        # structural re-rank takes anyway, rerank
        if self.flat_rerank < self.rerank:
            raise n.error(f"{n('flat_rerank', opt=True)} must be >= {n('rerank')} = {self.rerank} (the "
                          f"candidates every patch re-ranks); got {self.flat_rerank}; use "
                          f"{n.value('flat_rerank', self.rerank)} to turn the flat-window re-rank off")
        if (self.coarse_factor is not None and self.coarse_factor < 1) or self.top_k < 1:
            raise n.error(f"{n('coarse_factor')} and {n('top_k')} must be >= 1; got {self.coarse_factor}, "
                          f"{self.top_k}")
        if self.patch_px < 4:
            raise n.error(f"{n('patch_mm')} * {n('px_per_mm')} must give at least 4 px; got {self.patch_px}; "
                          f"raise {n('px_per_mm')}")
        # after patch_px: a patch of no size has no cells to count
        if self.n_adaptive > self.max_adaptive:  # compared in levels: a job file may hold any int
            largest = f"{self.patch_mm * 2.0 ** self.n_adaptive:g} mm" if self.n_adaptive <= 64 else "beyond any panel"
            raise n.error(
                f"{n('n_adaptive', opt=True)} must be in [0, {self.max_adaptive}] here: its largest patch, "
                f"{n('patch_mm')} * 2^{n('n_adaptive')} = {self.patch_mm:g} * 2^{self.n_adaptive} = {largest}, must "
                f"fit the panel's shorter side, {self.short_side_mm:g} mm ({self.short_cells} patches: "
                f"{n('image_size_mm')} {self.image_size_mm:g} in whole patches); got {self.n_adaptive}; use "
                f"{n.setting('n_adaptive', self.max_adaptive)} or less, or a larger {n.opt('image_size_mm')}")
        o = self.overlap
        if o < 0 or 2 * o > self.patch_mm - self.min_piece_mm + 1e-9:
            most = (self.patch_mm - self.min_piece_mm) / 2
            raise n.error(
                f"{n('overlap_mm', opt=True)} must be in [0, ({n('patch_mm')} - {n('min_piece_mm')}) / 2 = "
                f"({self.patch_mm:g} - {self.min_piece_mm:g}) / 2 = {most:g}] mm so every piece stays >= "
                f"{n('min_piece_mm')} wide; got {o:g} mm; "
                f"use {n.setting('overlap_mm', most)} or less, a larger {n.opt('patch_mm')} or a smaller "
                f"{n.opt('min_piece_mm')}")
        return self

    @property
    def overlap(self) -> float:
        """Overlap in mm (see ``overlap_mm``)."""
        if self.overlap_mm is not None:
            return float(self.overlap_mm)
        return max(0.0, min(self.patch_mm / 4.0, (self.patch_mm - self.min_piece_mm) / 2.0))

    def coarse_factor_for(self, sheet_px: int) -> int:
        """The fast mode's coarse factor for sheets of ``sheet_px`` pixels in all (working
        resolution, unrotated): ``coarse_factor`` when set, else automatic (see above)."""
        if self.coarse_factor is not None:
            return int(self.coarse_factor)
        # rotated canvases are ~1.5 times the sheet's area on average over the angles
        total = 1.5 * sheet_px * self.n_rot
        return next((f for f in (4, 8) if total / f ** 2 <= AUTO_COARSE_PX), 16)

    @property
    def kerf(self) -> float:
        return self.tool_diameter_mm if self.kerf_mm is None else float(self.kerf_mm)

    @property
    def patch_px(self) -> int:
        return round(self.patch_mm * self.px_per_mm)

    @property
    def short_cells(self) -> int:
        """Patches along the panel's shorter side: ``image_size_mm`` rounded to whole patches
        (the panel is made of whole cells: :func:`woodcam.parquetry.engine.prepare_target`)."""
        return max(1, round(self.image_size_mm / self.patch_mm))

    @property
    def short_side_mm(self) -> float:
        """The panel's shorter side as made: :attr:`short_cells` cells of :attr:`patch_px`
        working pixels (``image_size_mm`` 60 of 14 mm patches makes 56)."""
        return self.short_cells * self.patch_px / self.px_per_mm

    @property
    def max_adaptive(self) -> int:
        """The most adaptive levels the panel holds: the engine's top squares, ``2**n_adaptive``
        cells a side, are at most the panel's shorter side (:attr:`short_cells`), so a level
        beyond makes no patch of ``patch_mm * 2**n_adaptive``."""
        return self.short_cells.bit_length() - 1

    @property
    def overlap_px(self) -> int:
        return round(self.overlap * self.px_per_mm)


#: The command-line option of each parameter the Python messages name in their fixes.
_OPTIONS = {"image_size_mm": "--image-size-mm", "patch_mm": "--patch-mm", "min_piece_mm": "--min-piece-mm",
            "overlap_mm": "--overlap-mm", "n_adaptive": "--n-adaptive", "tool_diameter_mm": "--tool-diameter",
            "flat_detail": "--flat-detail", "flat_rerank": "--flat-rerank"}


class _Said:
    """How :meth:`ParquetryParams.check` names a parameter, and a setting of it in a fix.

    Default: the Python keyword (``patch_mm``), the command-line option beside it or in a fix
    (``overlap_mm (--overlap-mm)``, ``use --overlap-mm 4.5``), and ``patch_mm=14.0`` for a
    default. With ``where`` (a job file, ``"job file 'job.json': "``) and ``keys`` (parameter ->
    the key the file wrote it under: ``num_source_rotations``, else ``woodcam.params.<name>``):
    the file and its JSON keys only (``use woodcam.params.overlap_mm 4.5``); a job-file
    user was told a Python keyword (``n_rot=15``) for a key the file spells otherwise."""

    def __init__(self, where: str = "", keys: dict[str, str] | None = None):
        self.where, self.keys = where, keys

    def __call__(self, name: str, *, opt: bool = False) -> str:
        """The parameter ``name`` as the subject of a rule (``opt``: with its option, in Python's)."""
        if self.keys is not None:
            return self.keys.get(name, f"woodcam.params.{name}")
        return f"{name} ({_OPTIONS[name]})" if opt else name

    def typed(self, name: str) -> str:
        """The subject of a type error (Python: 'parquetry parameter n_rot')."""
        return self(name) if self.keys is not None else f"parquetry parameter {name}"

    def opt(self, name: str) -> str:
        """The thing to change in a fix: the option (Python's messages) or the job file's key."""
        return self(name) if self.keys is not None else _OPTIONS[name]

    def setting(self, name: str, value: float) -> str:
        """``name`` set to ``value`` in a fix: ``--overlap-mm 4.5``, ``woodcam.params.overlap_mm 4.5``."""
        return f"{_OPTIONS[name] if self.keys is None else self(name)} {value:g}"

    def value(self, name: str, value: float) -> str:
        """``value`` for ``name`` in a fix: the number alone (Python's messages), or as :meth:`setting`."""
        return f"{value:g}" if self.keys is None else self.setting(name, value)

    def default_fix(self, name: str, default: object) -> str:
        """The fix of a value of the wrong type: leave it out for its default."""
        if self.keys is None:
            return f"leave it out for the default, {name}={default!r}"
        return "remove the key for the default" + ("" if default is None else f", {json.dumps(default)}")

    def error(self, message: str) -> WoodcamError:
        return WoodcamError(self.where + message)


def _check_type(what: str, v, annotation: str, fix: str = ""):
    """``v`` checked against the dataclass field type ``annotation`` (a string: ``float``,
    ``int | None``, ``bool``, a Literal alias): numbers finite, ints whole (returned as int:
    JSON may write 15.0), bools true bools; else a WoodcamError naming ``what``, ending with
    ``fix`` when given."""
    if v is None and "None" in annotation:
        return v
    kind = annotation.split("|")[0].strip()
    # numpy scalars are numbers and bools (np.float32(4) was 'must be a finite number'); they
    # come back as Python's, which a job file's JSON can hold
    if kind == "bool":
        ok = isinstance(v, (bool, np.bool_))
    elif kind in ("float", "int"):
        ok = isinstance(v, numbers.Real) and not isinstance(v, bool) and math.isfinite(v) \
            and (kind == "float" or float(v).is_integer())
    else:  # a Literal: its own check below names the choices
        return v
    if not ok:
        rule = {"bool": "true or false", "float": "a finite number", "int": "a whole number"}[kind]
        raise WoodcamError(f"{what} must be {rule}; got {v!r}" + (f"; {fix}" if fix else ""))
    if kind == "bool":
        return bool(v)
    return int(v) if kind == "int" else (v if isinstance(v, (int, float)) else float(v))


def _entries(d: dict, key: str, where: str, need: str | None) -> list[dict]:
    """``d[key]`` of a job file: a list of JSON objects (missing: empty), each with a string
    ``need`` and its numbers ``dpi``, ``scale``, ``px_per_mm`` finite and > 0 where given."""
    items = d.get(key, [])
    if not isinstance(items, list):
        raise WoodcamError(f"{where} {key!r} must be a list of objects; got {type(items).__name__}")
    for i, t in enumerate(items):
        if not isinstance(t, dict):
            raise WoodcamError(f"{where} {key}[{i}] must be an object; got {t!r}")
        if need is not None and not (isinstance(t.get(need), str) and t[need]):
            raise WoodcamError(f"{where} {key}[{i}] needs a {need!r} path; got {t.get(need)!r}")
        for num in ("dpi", "scale", "px_per_mm"):
            if t.get(num) is not None:
                _check_type(f"{where} {key}[{i}].{num}", t[num], "float")
                if t[num] <= 0:
                    raise WoodcamError(f"{where} {key}[{i}].{num} must be > 0; got {t[num]!r}")
    return items


# The reference code's keys for Table 1 / sec. 3.2 parameters.
_PAPER_KEYS = {"num_source_rotations": "n_rot", "patch_levels": "n_adaptive",
               "patch_quality_factor": "w_adaptive", "weight_intensity": "w_intens",
               "weight_sobel": "w_edge", "histogram_matching": "w_hist"}
#: The reference code's keys woodcam reads no value from, and why: a job file holding them
#: (its sample does) is said to, not silently run otherwise than the reference code would.
_PAPER_UNUSED = {
    "min_patch_size": "woodcam's patch side is patch_mm: woodcam.params.patch_mm, --patch-mm"}
#: The reference code's keys that it ignores too (deprecated): accepted without a word, as the
#: run is the reference code's either way.
_PAPER_IGNORED = {"downsample"}
#: Its Gabor-filter keys: no effect there either while weight_gabor is 0.
_GABOR = ("weight_gabor", "filter_resolution", "num_filter_directions", "filter_bandwidth_octaves")
_TOP_KEYS = {"source_textures", "targets", "woodcam", "sort_patches_saliency", *_PAPER_KEYS,
             *_PAPER_UNUSED, *_PAPER_IGNORED, *_GABOR}
_ENTRY_KEYS = {"source_textures": {"texture", "mask", "id", "scale", "dpi", "px_per_mm", "markers_pixel",
                                   "json"},
               "targets": {"filename", "scale", "dpi", "morphed_grid"}}
#: The keys of a ``woodcam.blocks`` entry (:func:`job_veneers` reads them).
_BLOCK_KEYS = {"spec", "sheets", "width_mm", "height_mm", "thickness_mm", "kerf_mm", "axis", "species", "id"}


#: Most leaves a ``woodcam.blocks`` entry may slice, as ``woodcam parquetry --sheets`` (1e6 ran
#: on, memory growing).
_MAX_SHEETS = 1000


def _check_block_entry(b: dict, at: str) -> None:
    """A job file's ``woodcam.blocks`` entry (its numbers' types checked) checked at the door in
    the file's words, ``at`` naming it (``"job file 'job.json': woodcam.blocks[0]"``): the spec's
    grammar and built-in name (a spec naming no file; files are found by :func:`read_job`), the
    leaves' ranges, the axis and the species. They were said when the leaves were cut, in
    Python's words and without the file: '"sheets": 0' as 'n_sheets must be an integer >= 1;
    got 0; e.g. 4', '"species": "purple"' ending 'or species=None for the block's own',
    '"spec": "builtin:nope"' as 'unknown built-in block 'nope'; ...'."""
    spec = b["spec"]
    if spec_path(str(spec)) is None:
        from .._specs import parse_spec
        from ..fields.builtin import check_builtin_name

        try:
            parsed = parse_spec(str(spec))
            if parsed.kind == "builtin":
                check_builtin_name(parsed.source)
        except WoodcamError as err:
            said = str(err).removeprefix(f"block spec {spec!r}: ")
            raise WoodcamError(f"{at}.spec {spec!r}: {said}") from None
    if "sheets" in b and not 1 <= b["sheets"] <= _MAX_SHEETS:
        raise WoodcamError(f"{at}.sheets must be in [1, {_MAX_SHEETS}] (leaves sliced from the block); got "
                           f"{b['sheets']!r}; e.g. 2, or remove the key for the default, 2")
    for num, rule in (("width_mm", "> 0"), ("height_mm", "> 0"), ("thickness_mm", "> 0"), ("kerf_mm", ">= 0")):
        v = b.get(num)
        if v is not None and not (v > 0 if rule == "> 0" else v >= 0):
            what = {"width_mm": "a leaf's width", "height_mm": "a leaf's height", "thickness_mm": "a leaf's thickness",
                    "kerf_mm": "the saw kerf between leaves"}[num]
            raise WoodcamError(f"{at}.{num} must be {rule} mm ({what}); got {v!r}; remove the key for the default")
    if "axis" in b and b["axis"] not in ("x", "y", "z"):
        raise WoodcamError(f"{at}.axis must be \"x\", \"y\" or \"z\" (the normal of the slicing planes, block "
                           f"frame); got {b['axis']!r}; remove the key for the default, \"y\"")
    if b.get("species") is not None:
        from ..appearance import SPECIES

        if not isinstance(b["species"], str) or b["species"] not in SPECIES:
            raise WoodcamError(f"{at}.species must be one of the presets {', '.join(SPECIES)}; got "
                               f"{b['species']!r}; give one of them ('woodcam species' lists them), or null "
                               "for the block's own")


def _refuse_unknown_keys(where: str, objects: list[tuple[str, dict, set[str]]], why: str) -> None:
    """The one check of a job file's keys: ``objects`` are ``(at, object, known keys)``, ``at``
    the object's place in the file (``""`` at the top, ``"targets[0]."``); the first key, in
    that order and sorted, that is not known is refused as ``key {at}'k' is unknown ({why})``
    with the keys known there (a typo was ignored and the run took the default)."""
    for at, obj, known in objects:
        unknown = sorted(set(obj) - known)
        if unknown:
            raise WoodcamError(f"{where} key {at}{unknown[0]!r} is unknown ({why}); the known ones "
                               f"there: {', '.join(sorted(known))}")


def _unused_keys(d: dict, where: str) -> None:
    """Refuse keys of a job file that neither woodcam nor the reference code reads (a typo:
    ``num_source_rotation`` was ignored), warn of those it reads that woodcam has no use for."""
    objects = [("", d, _TOP_KEYS)]
    for key in ("source_textures", "targets"):
        for i, t in enumerate(d.get(key, [])):
            objects.append((f"{key}[{i}].", t, _ENTRY_KEYS[key]))
            if key == "source_textures" and "json" in t:
                raise WoodcamError(f"{where} {key}[{i}] describes its texture in another file ('json': "
                                   f"{t['json']!r}), which woodcam does not read; give its 'texture', "
                                   "'dpi' and 'mask' in this entry")
    _refuse_unknown_keys(where, objects, "neither woodcam nor the reference code reads it")
    said = [f"{k} ({why})" for k, why in _PAPER_UNUSED.items() if k in d]
    if d.get("weight_gabor"):
        said.append(f"weight_gabor = {d['weight_gabor']!r} (woodcam matches intensity and Sobel edges, "
                    "eq. 1 without the Gabor term)")
    for i, t in enumerate(d.get("targets", [])):
        if t.get("dpi") is not None or t.get("scale", 1.0) != 1.0:
            said.append(f"targets[{i}] dpi and scale (the panel's shorter side is image_size_mm: "
                        "woodcam.params.image_size_mm, --image-size-mm)")
        if "morphed_grid" in t:
            said.append(f"targets[{i}].morphed_grid (woodcam cuts a square grid of patches)")
    said += [f"source_textures[{i}].markers_pixel (woodcam's cut files carry no registration marks)"
             for i, t in enumerate(d.get("source_textures", [])) if "markers_pixel" in t]
    if said:
        warnings.warn(f"{where} woodcam reads no value from {'; '.join(said)}; the run may differ from "
                      "the reference code's: remove these keys, or set what woodcam reads instead",
                      WoodcamWarning, stacklevel=3)


@dataclass
class ParquetryJob:
    """A job: veneer sources, targets and parameters.

    scans : ``[{"texture", "mask", "id", "scale", "dpi"}]`` as in the paper's layout (paths)
    blocks : ``[{"spec", "sheets", "width_mm", "height_mm", "thickness_mm", "kerf_mm", "axis"}]``
        veneers sliced from woodcam blocks / logs (woodcam's extension)
    mokume : Mokume sample folders used as veneers (their face photos)
    targets : ``[{"filename", "scale", "dpi"}]``
    params : :class:`ParquetryParams`, the run's knobs (default: all their defaults)
    units_said : the job file said its lengths are mm (``"units"`` under ``"woodcam"``, as
        :func:`write_job` writes it), so ``--units inch`` leaves its lengths alone (as commented
        below)
    """

    __repr__ = summary_repr  # arrays as shapes: a notebook shows one line

    scans: list[dict] = field(default_factory=list)
    blocks: list[dict] = field(default_factory=list)
    mokume: list[str] = field(default_factory=list)
    targets: list[dict] = field(default_factory=list)
    params: ParquetryParams = field(default_factory=ParquetryParams)
    #: whether the job file says its lengths are mm (``woodcam.units``, which :func:`write_job`
    #: writes): nothing in it is ambiguous under ``--units inch``
    units_said: bool = False

    def __post_init__(self):
        # a string of scans, a dict of params or a target that is no dict was taken and failed in
        # write_job or the run as a bare TypeError ('string indices must be integers', 'asdict()')
        import os

        for name, key, example in (("scans", "texture", "{'texture': 'oak.png', 'dpi': 300}"),
                                   ("blocks", "spec", "{'spec': 'builtin:flat-sawn', 'sheets': 4}"),
                                   ("targets", "filename", "{'filename': 'moon.png', 'dpi': 300}")):
            value = getattr(self, name)
            if not isinstance(value, list) or not all(isinstance(d, dict) and key in d for d in value):
                raise WoodcamError(f"ParquetryJob.{name} must be a list of dicts, each with {key!r}; got "
                                   f"{value!r:.60}; e.g. [{example}]")
        if not isinstance(self.mokume, list) or not all(isinstance(m, (str, os.PathLike)) for m in self.mokume):
            raise WoodcamError(f"ParquetryJob.mokume must be a list of Mokume sample folders; got {self.mokume!r:.60}")
        if not isinstance(self.params, ParquetryParams):
            raise WoodcamError(f"ParquetryJob.params must be a ParquetryParams; got {type(self.params).__name__}; "
                               "e.g. ParquetryParams(patch_mm=10)")


class JobPathError(WoodcamError):
    """A path a job file names (a target, a texture or its mask, a Mokume folder, a block spec's
    folder or file) that does not exist (:func:`read_job`): ``job`` the job file, ``key`` the
    entry (``source_textures[0].texture``), ``path`` as written. ``woodcam parquetry --config``
    says it as a wrong command line (exit 2), as the same path typed there; a script's job file
    is no command line, so the library raises this plain WoodcamError."""

    def __init__(self, message: str, *, job: str = "", key: str = "", path: str = ""):
        super().__init__(message)
        self.job, self.key, self.path = job, key, path


def read_job(path: str | Path) -> ParquetryJob:
    """Read a job file (paper layout + ``"woodcam"`` extras); paths resolved against its folder.
    ``path``: the job's JSON file."""
    from .._readers import read_json_object

    p = check_path(path, "read_job: path", fix="a parquetry job file (JSON)")
    d = read_json_object(p, "parquetry job file")
    where = f"job file {str(p)!r}:"
    if "targets" not in d:
        raise WoodcamError(f"{where} needs 'targets' (and 'source_textures' or woodcam.blocks); see "
                           "woodcam.parquetry.job")
    extra = d.get("woodcam", {}) or {}
    if not isinstance(extra, dict) or not isinstance(extra.get("params", {}), dict):
        raise WoodcamError(f"{where} 'woodcam' and 'woodcam.params' must be objects; got {extra!r}")
    unknown = sorted(set(extra) - {"params", "blocks", "mokume", "units"})
    if unknown:  # {"woodcam": {"image_size_mm": 50}} was ignored: a parameter belongs in params
        raise WoodcamError(f"{where} key woodcam.{unknown[0]} is unknown; the 'woodcam' object holds "
                           "params, blocks, mokume and units (parameters go in woodcam.params)")
    # the unit of the file's lengths, said (write_job writes it): mm, the only one a job file has
    if "units" in extra and extra["units"] != "mm":
        raise WoodcamError(f"{where} woodcam.units must be 'mm' (a job file's lengths are mm: its *_mm keys, "
                           f"its block specs' sizes); got {extra['units']!r}; write the lengths in mm and "
                           "'units': 'mm', or leave the key out")
    mokume = extra.get("mokume", [])
    if not isinstance(mokume, list) or not all(isinstance(m, str) for m in mokume):
        raise WoodcamError(f"{where} 'woodcam.mokume' must be a list of folder paths; got {mokume!r}")
    _entries(d, "source_textures", where, None)  # lists of objects, before their keys are read
    _entries(d, "targets", where, None)
    _unused_keys(d, where)
    targets = _entries(d, "targets", where, "filename")
    scans = _entries(d, "source_textures", where, "texture")
    blocks = _entries(extra, "blocks", f"{where} woodcam", "spec")
    # a typo ("sheet": 3) ran with the default
    _refuse_unknown_keys(where, [(f"woodcam.blocks[{i}].", b, _BLOCK_KEYS) for i, b in enumerate(blocks)],
                         "woodcam reads no such key")
    for i, t in enumerate(scans):  # px_per_mm won and the dpi or scale was dropped without a word
        if t.get("px_per_mm") is not None and (t.get("dpi") is not None or t.get("scale") is not None):
            raise WoodcamError(f"{where} source_textures[{i}] gives px_per_mm ({t['px_per_mm']!r}) and "
                               f"dpi/scale ({t.get('dpi')!r}/{t.get('scale')!r}); the resolution is one or "
                               "the other: keep px_per_mm alone, or dpi (times scale)")
    for i, b in enumerate(blocks):  # the leaves' numbers (slice_veneers checks their ranges)
        for num, kind in (("sheets", "int"), ("width_mm", "float"), ("height_mm", "float"),
                          ("thickness_mm", "float"), ("kerf_mm", "float")):
            if num in b:
                _check_type(f"{where} woodcam.blocks[{i}].{num}", b[num], kind)
        _check_block_entry(b, f"{where} woodcam.blocks[{i}]")
    base = p.parent
    names = {f.name for f in fields(ParquetryParams)}
    kw = {}
    keys = {}  # each parameter by the key the file wrote it under, for check()'s errors
    for k, v in d.items():
        if k in _PAPER_KEYS:
            kw[_PAPER_KEYS[k]] = v
            keys[_PAPER_KEYS[k]] = k
        elif k == "sort_patches_saliency":  # "no" was read as true
            kw["priority"] = "saliency" if _check_type(f"{where} {k}", v, "bool") else "center"
            keys["priority"] = k
    for k, v in extra.get("params", {}).items():
        if k not in names:
            raise WoodcamError(f"{where} key woodcam.params.{k} is unknown; known: {sorted(names)}")
        kw[k] = v
        keys.pop(k, None)  # woodcam.params wins over the paper's key (the order kw was filled in)

    # checked in the file's words (its keys, its path), not as ParquetryParams(**kw) would say it
    params = ParquetryParams()
    for k, v in kw.items():
        setattr(params, k, v)
    params.check(said=_Said(f"{where} ", keys))

    def _abs(s):
        return str((base / s).resolve()) if s else s

    # the types first: the file-exists check below joins each path to the job's folder ({"mask": 5}
    # was a TypeError there)
    for i, t in enumerate(scans):
        if t.get("mask") is not None and not isinstance(t["mask"], str):
            raise WoodcamError(f"{where} source_textures[{i}].mask must be a path or null; got {t['mask']!r}")
        if t.get("id") is not None:
            from .veneers import check_veneer_id

            check_veneer_id(t["id"], f"{where} source_textures[{i}].id")
    # found at the door, each named by its entry: a missing file was 'cannot decode the image ...
    # the file is damaged' after the job's other files were read
    named = [(f"source_textures[{i}].{k}", t.get(k), t.get(k)) for i, t in enumerate(scans)
             for k in ("texture", "mask")]
    named += [(f"targets[{i}].filename", t["filename"], t["filename"]) for i, t in enumerate(targets)]
    named += [(f"woodcam.mokume[{i}]", m, m) for i, m in enumerate(mokume)]
    # a block spec's folder, log or woodify file: it was the block's opening error, after the
    # job's scans were read (a built-in block or the shared log names none)
    named += [(f"woodcam.blocks[{i}].spec", b["spec"], str(spec_path(str(b["spec"])) or ""))
              for i, b in enumerate(blocks)]
    for key, s, p_ in named:
        if p_ and not Path(_abs(p_)).exists():
            here = (f"; {p_!r} is there from the working folder: give the path from the job file's folder, "
                    "or an absolute one") if not Path(p_).is_absolute() and Path(p_).exists() else ""
            raise JobPathError(f"{where} {key} {s!r}: no such file {_abs(p_)!r} (a job file's paths are "
                               f"relative to its folder){here or '; check the path'}", job=str(p), key=key, path=s)
        # an image that is a folder was 'cannot read ... (Is a directory); check the file's
        # permissions' once the run read it; a Mokume sample that is a file the same (a block
        # spec's path may be either: its opening says)
        folder = key.startswith("woodcam.mokume")
        if p_ and not key.startswith("woodcam.blocks") and Path(_abs(p_)).is_dir() != folder:
            raise JobPathError(f"{where} {key} {s!r}: {_abs(p_)!r} is a {'file' if folder else 'folder'}; it must be "
                               + ("a Mokume sample folder (its A_col.png .. F_col.png)" if folder else
                                  "an image file (PNG, JPEG or TIFF)"), job=str(p), key=key, path=s)

    # the reference code's id is optional: the file's stem, as for --veneer (a texture without
    # one was a KeyError from the CLI)
    scans = [dict(t, texture=_abs(t["texture"]), mask=_abs(t.get("mask")),
                  id=t.get("id") or Path(t["texture"]).stem) for t in scans]
    targets = [dict(t, filename=_abs(t["filename"])) for t in targets]
    mokume = [_abs(m) for m in mokume]
    # a block folder, log:PATH or woodify:PATH as the textures: from the job file's folder
    blocks = [dict(b, spec=absolute_spec(b["spec"], base)) for b in blocks]
    return ParquetryJob(scans, blocks, mokume, targets, params, units_said="units" in extra)


def write_job(job: ParquetryJob, path: str | Path) -> Path:
    """Write a job file in the paper's layout (woodcam-only keys under ``"woodcam"``), atomically.
    Its paths are written absolute: the job's are relative to the working folder (as given on
    the command line), a job file's to its own folder. ``path``: the JSON file to write
    (e.g. ``job.json``); returns it."""
    from .._atomic import write_text

    if not isinstance(job, ParquetryJob):  # None was an AttributeError ('params')
        raise WoodcamError(f"job must be a ParquetryJob; got {type(job).__name__}; read one with read_job(path)")
    path = check_path(path, "write_job: path", fix="e.g. 'job.json'")

    def _abs(s):  # coffee.png typed in the working folder was read back as OUT/coffee.png
        return str(Path(s).absolute()) if s else s

    prm = asdict(job.params)
    d = {"source_textures": [dict(t, texture=_abs(t["texture"]), **({"mask": _abs(t["mask"])} if "mask" in t
                                                                     else {})) for t in job.scans],
         "targets": [dict(t, filename=_abs(t["filename"])) for t in job.targets]}
    for k, name in _PAPER_KEYS.items():
        d[k] = prm[name]
    d["sort_patches_saliency"] = job.params.priority == "saliency"
    # "units": its lengths (the *_mm keys, the block specs' :WxDxH and resizes) are mm, said so a
    # replay under --units inch has nothing to warn of
    d["woodcam"] = {"units": "mm", "params": prm,
                    "blocks": [dict(b, spec=absolute_spec(b["spec"])) for b in job.blocks],
                    "mokume": [_abs(m) for m in job.mokume]}
    return write_text(path, json.dumps(d, indent=2), mkdir=True)


#: Size (width, height) mm of a sliced leaf when none is given: this, or the block's face
#: where it is smaller.
DEFAULT_LEAF_MM = (600.0, 400.0)


class LeavesPastBlockError(WoodcamError):
    """Leaves that run past the block they are sliced from (:func:`check_leaves_in_block`);
    ``entry`` is the job's ``woodcam.blocks`` entry they were asked by (set by
    :func:`job_veneers`), so the command line tells leaves its options sized (a usage error)
    from a job file's own."""

    entry: dict | None = None


def check_leaves_in_block(stock, n_sheets: int, width_mm: float | None, height_mm: float | None,
                          thickness_mm: float, kerf_mm: float, axis: str) -> tuple[float, float]:
    """The ``(width, height)`` mm of ``n_sheets`` leaves sliced from ``stock`` normal to
    ``axis`` (as :func:`~woodcam.parquetry.veneers.slice_veneers` lays them: from the block's
    middle plane, ``thickness + kerf`` apart), refused where they would run past the block.

    Every sheet is wood of the block: a leaf larger than the block's face normal to ``axis``,
    or leaves reaching past its back face, would be wood of the field outside it (for a fitted
    or grown block an extrapolation, wood the user does not have). A size not given (None) is
    :data:`DEFAULT_LEAF_MM`, or the face where it is smaller. Numbers are checked by
    ``slice_veneers``; an axis other than x, y, z is left to it."""
    from .veneers import PLANE_AXES

    if axis not in ("x", "y", "z"):
        return (float(width_mm or DEFAULT_LEAF_MM[0]), float(height_mm or DEFAULT_LEAF_MM[1]))
    size = [float(v) for v in stock.size_mm]
    ax = "xyz".index(axis)
    right, down = PLANE_AXES[ax]
    face = (size[right], size[down])
    w = min(DEFAULT_LEAF_MM[0], face[0]) if width_mm is None else float(width_mm)
    h = min(DEFAULT_LEAF_MM[1], face[1]) if height_mm is None else float(height_mm)
    # lengths in the message units (--units): the fix '--sheet-size 100x50 mm', typed as it
    # said under --units inch, was 2540 x 1270 mm, refused again; so is a block spec's size
    # (--veneer-from reads its :WxDxH in --units, as bake --block does)
    block = say_length(size, "g", sep=" x ")
    tol = IN_BLOCK_RTOL * max(size)
    if w > face[0] + tol or h > face[1] + tol:
        need = list(size)
        need[right], need[down] = max(size[right], w), max(size[down], h)
        bigger = "x".join(typed_length(v, tol) for v in need)
        fits = [typed_length(min(v, f), tol, lambda back, f=f: back <= f + tol)
                for v, f in ((w, face[0]), (h, face[1]))]
        raise LeavesPastBlockError(
            f"leaves of {say_length((w, h), 'g', sep=' x ')} (--sheet-size; width_mm, height_mm in a job file) "
            f"do not fit {stock.spec}: its {block} block's face normal to {axis} (--slice-axis) is "
            f"{say_length(face, 'g', sep=' x ')}, and every sheet must be wood of the block, not of the field "
            f"outside it; give --sheet-size {'x'.join(fits)} {message_unit()} or smaller"
            + (f", or a block of {say_length(need, 'g', sep=' x ')} that holds them ({spec}:{bigger})"
               if re.fullmatch(r"builtin:[a-z-]+", spec := str(stock.spec))
               else f", or a block of {say_length(need, 'g', sep=' x ')} that holds them"
               if spec.startswith(("builtin:", "log:"))
               else " (a block folder or a grown block holds only its own wood)"))
    pitch = thickness_mm + kerf_mm
    reach = size[ax] / 2 + (n_sheets - 1) * pitch + thickness_mm
    if n_sheets >= 1 and thickness_mm > 0 and pitch > 0 and reach > size[ax] + tol:
        most = max(0, int((size[ax] / 2 - thickness_mm) // pitch) + 1)
        raise LeavesPastBlockError(
            f"{n_sheets} leaves (--sheets) of {say_length(thickness_mm, 'g')} + {say_length(kerf_mm, 'g')} kerf, "
            f"sliced from the middle of {stock.spec} along {axis}, reach {say_length(reach, 'g')} into its "
            f"{say_length(size[ax], 'g')}: past its back face, wood of the field outside the {block} block; "
            f"give --sheets {most} or fewer, thinner leaves or kerf, or a deeper block")
    return w, h


def job_veneers(job: ParquetryJob, open_stock=None, progress: bool = False) -> list:
    """The job's veneer sheets: scans (``dpi / 25.4 * scale`` px/mm), Mokume photos and leaves
    sliced from woodcam blocks (``{"spec", "sheets", "width_mm", "height_mm", "thickness_mm",
    "kerf_mm", "axis", "species"}``), resampled later to the working resolution.

    open_stock : ``open_stock(spec, species=...) -> Stock`` (``woodcam.open_stock``), needed when
        the job slices blocks; the stock layer sits above this package, so the caller passes it.
    """
    from .veneers import MM_PER_INCH, load_scan, mokume_veneers, slice_veneers

    out = []
    for t in job.scans:
        if "texture" not in t:
            raise WoodcamError(f"source_textures entry {t} needs a 'texture' path")
        if t.get("px_per_mm") is not None:
            ppm = float(t["px_per_mm"])
        elif t.get("dpi") is not None:
            ppm = float(t["dpi"]) / MM_PER_INCH * float(t.get("scale", 1.0))
        else:
            raise WoodcamError(f"source texture {t['texture']!r} needs 'dpi' (or 'px_per_mm'); got neither")
        out.append(load_scan(t["texture"], px_per_mm=ppm, mask=t.get("mask") or None, id=t.get("id")))
    for m in job.mokume:
        out += mokume_veneers(m)
    for b in job.blocks:
        if open_stock is None:
            raise WoodcamError("job_veneers: this job slices blocks; pass open_stock="
                               "woodcam.open_stock")
        if "spec" not in b:
            raise WoodcamError(f"woodcam.blocks entry {b} needs a 'spec' (e.g. builtin:flat-sawn)")
        stock = open_stock(b["spec"], species=b.get("species"))
        n, axis = int(b.get("sheets", 2)), b.get("axis", "y")
        thickness, kerf = float(b.get("thickness_mm", 0.6)), float(b.get("kerf_mm", 0.4))
        try:
            size = check_leaves_in_block(stock, n, b.get("width_mm"), b.get("height_mm"), thickness, kerf, axis)
        except LeavesPastBlockError as err:
            err.entry = b  # whose leaves: the command line's options or a job file's own
            raise
        out += slice_veneers(stock, n, size, thickness_mm=thickness, kerf_mm=kerf, px_per_mm=job.params.px_per_mm,
                             axis=axis, progress=progress,
                             id_prefix=b.get("id") or (stock.spec.replace(":", "-").replace("/", "-").strip("-.")
                                                       + (f"-{b['species']}" if b.get("species") else "")))
    return out


def numbered_names(names: Sequence[str], kept: Sequence[str] = ()) -> list[str]:
    """``names`` with each one that occurs more than once, among them or in ``kept`` (names kept
    as they are: a job file's scan ids), numbered in the order given, ``oak-1``, ``oak-2``,
    skipping a number a name here or in ``kept`` already holds: the one rule of the targets'
    names (:func:`job_targets`) and of the ``--veneer`` scans' ids."""
    from collections import Counter

    count, taken = Counter([*names, *kept]), {*names, *kept}
    out = []
    for n in names:
        if count[n] > 1:
            k = 1
            while f"{n}-{k}" in taken:
                k += 1
            n = f"{n}-{k}"
            taken.add(n)
        out.append(n)
    return out


def job_targets(job: ParquetryJob) -> tuple[list, list[str]]:
    """The job's target images ``(h, w, 3)`` float RGB and their names (file stems, in the
    output files' names: ``render_<name>.png``). Targets of the same stem in two folders
    (``a/cam.png``, ``b/cam.png``) are numbered in the order given, ``cam-1``, ``cam-2`` (as
    ``--veneer`` numbers its scans; a number another target's stem already holds is skipped),
    said in a WoodcamWarning; the index was glued to the stem of all of them, ``cam640`` and
    ``cam641`` of two ``cam64.png``, names no user could foresee."""
    from .veneers import TARGET_ALPHA_FIX, read_image

    imgs, stems = [], []
    for t in job.targets:
        if "filename" not in t:
            raise WoodcamError(f"targets entry {t} needs a 'filename'")
        imgs.append(read_image(t["filename"], "target image", TARGET_ALPHA_FIX))
        stems.append(Path(t["filename"]).stem)
    names = numbered_names(stems)
    renamed = [f"{t['filename']} as {n}" for t, s, n in zip(job.targets, stems, names) if n != s]
    if renamed:
        warnings.warn(f"targets share a file name, so each is named with a number (render_<name>.png, "
                      f"assembly_<name>.svg, result.json): {'; '.join(renamed)}; rename the files to choose "
                      "the names", WoodcamWarning, stacklevel=2)
    return imgs, names
