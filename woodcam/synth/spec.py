"""The settings of :func:`woodcam.synth.synth_block` as spec dataclasses with JSON round trips.

``SynthSpec`` groups how a block is rendered (image density, faces) with three parts: the
camera (:class:`PhotoSpec`), the ring annotation and its faults (:class:`TraceSpec`) and the
ring maps (:class:`RingMapSpec`). ``to_dict``/``from_dict`` and ``save``/``load`` round-trip
through JSON as :class:`woodcam.fields.neural.GTFSpec` does; :meth:`SynthSpec.flat` gives the
flat keyword names ``synth_block`` has always accepted (``trace_dropout``, ``photo_noise``...),
which it still accepts and :meth:`SynthSpec.replace_flat` applies.
"""

from __future__ import annotations

import json
import numbers
from dataclasses import asdict, dataclass, field, fields, replace
from pathlib import Path

from .._checks import check_number
from ..errors import WoodcamError
from ..frames import FACES, check_face


def _label(owner: str, name: str) -> str:
    """A setting's name as the user may have given it: flat keyword and spec path."""
    flat = {v: k for k, v in FLAT_KEYWORDS.items()}.get((owner, name))
    return f"{flat} ({owner}.{name})" if flat else f"{owner}.{name}"


def _fraction(owner: str, name: str, value) -> None:
    if not (isinstance(value, (int, float)) and 0.0 <= value <= 1.0):
        raise WoodcamError(f"{_label(owner, name)} must be a fraction in [0, 1]; got {value!r}")


def _non_negative(owner: str, name: str, value) -> None:
    if not (isinstance(value, (int, float)) and value >= 0):
        raise WoodcamError(f"{_label(owner, name)} must be a number >= 0; got {value!r}")


@dataclass(frozen=True)
class PhotoSpec:
    """The camera of the face photos (all 0: exactly ``round(255 * color)``).

    noise : sensor noise std, fraction of full scale.
    variation : std of the per-face exposure (and about the vignetting strength).
    blur_px : Gaussian lens blur (px); also anti-aliases the latewood -> earlywood step.
    """

    noise: float = 0.012
    variation: float = 0.03
    blur_px: float = 0.6

    def __post_init__(self):
        for f in fields(self):
            _non_negative("photo", f.name, getattr(self, f.name))


@dataclass(frozen=True)
class TraceSpec:
    """Ring traces and the faults a human annotator makes.

    dropout : expected fraction of trace length removed, in pieces of ``dropout_chunk_mm``.
    jitter_mm : std (mm) of the perpendicular displacement of trace vertices, smoothed along
        the trace over ``jitter_corr_mm`` (0 = independent per vertex).
    mislabel_fraction : traces whose year is off by +-1.
    unlabelled_fraction : traces with ``year=None``.
    """

    dropout: float = 0.0
    dropout_chunk_mm: float = 3.0
    jitter_mm: float = 0.0
    jitter_corr_mm: float = 1.0
    mislabel_fraction: float = 0.0
    unlabelled_fraction: float = 0.0

    def __post_init__(self):
        for name in ("dropout", "mislabel_fraction", "unlabelled_fraction"):
            _fraction("traces", name, getattr(self, name))
        for name in ("jitter_mm", "jitter_corr_mm"):
            _non_negative("traces", name, getattr(self, name))
        if not self.dropout_chunk_mm > 0:
            raise WoodcamError(f"{_label('traces', 'dropout_chunk_mm')} must be > 0 mm; got "
                               f"{self.dropout_chunk_mm!r}")


@dataclass(frozen=True)
class RingMapSpec:
    """Ring maps ``exp(-(d / sigma)^2)`` plus noise.

    sigma_px : line width (px); None: :data:`woodcam.fields.rings.MOKUME_RING_SIGMA_MM` times
        the image density (the width of the Mokume U-Net maps).
    noise : additive noise std.
    """

    sigma_px: float | None = None
    noise: float = 0.02

    def __post_init__(self):
        _non_negative("ring_map", "noise", self.noise)
        if self.sigma_px is not None and not self.sigma_px > 0:
            raise WoodcamError(f"{_label('ring_map', 'sigma_px')} must be > 0 px or None; got "
                               f"{self.sigma_px!r}")


def _faces_or_none(owner: str, faces):
    return None if faces is None else tuple(check_face(f) for f in faces)


@dataclass(frozen=True)
class SynthSpec:
    """How :func:`~woodcam.synth.synth_block` renders a block.

    px_per_mm : image density; None: ``face_px / max(size_mm)`` (the largest face side gets
        ``face_px`` pixels). Face shapes follow :class:`woodcam.frames.CrossLayout`.
    faces : faces to render (photo); ``trace_faces`` / ``ring_map_faces`` (None: ``faces``)
        choose which carry traces / ring maps (partial annotation, e.g. three faces).
    seed : random seed (the same seed gives the same block).
    """

    px_per_mm: float | None = None
    face_px: int = 512
    faces: tuple[str, ...] = FACES
    trace_faces: tuple[str, ...] | None = None
    ring_map_faces: tuple[str, ...] | None = None
    seed: int | None = 0
    photo: PhotoSpec = field(default_factory=PhotoSpec)
    traces: TraceSpec = field(default_factory=TraceSpec)
    ring_map: RingMapSpec = field(default_factory=RingMapSpec)

    def __post_init__(self):
        for name in ("faces", "trace_faces", "ring_map_faces"):  # 'top' was read letter by letter ('t')
            if isinstance(getattr(self, name), str):
                raise WoodcamError(f"{name} must be a list of face names; got the string {getattr(self, name)!r}; "
                                   f"pass [{getattr(self, name)!r}]")
        object.__setattr__(self, "faces", tuple(check_face(f) for f in self.faces))
        object.__setattr__(self, "trace_faces", _faces_or_none("trace_faces", self.trace_faces))
        object.__setattr__(self, "ring_map_faces", _faces_or_none("ring_map_faces", self.ring_map_faces))
        if self.px_per_mm is None and not (isinstance(self.face_px, int) and self.face_px >= 2):
            raise WoodcamError(f"face_px must be >= 2 pixels; got {self.face_px!r}")
        if self.px_per_mm is not None and not (isinstance(self.px_per_mm, numbers.Real) and self.px_per_mm > 0):
            raise WoodcamError(f"px_per_mm must be > 0; got {self.px_per_mm!r}")  # '2' was a TypeError of '>'
        if self.seed is not None:  # 'a' was numpy's SeedSequence TypeError when rendering
            object.__setattr__(self, "seed", int(check_number(self.seed, "seed", lo=0, integer=True,
                                                              fix="same seed, same block; or None")))
        for name, kind in (("photo", PhotoSpec), ("traces", TraceSpec), ("ring_map", RingMapSpec)):
            v = getattr(self, name)
            if isinstance(v, dict):
                object.__setattr__(self, name, _from_dict(kind, v, f"synth spec {name}"))

    # -- JSON -------------------------------------------------------------------------------
    def to_dict(self) -> dict:
        d = asdict(self)
        for k in ("faces", "trace_faces", "ring_map_faces"):
            d[k] = None if d[k] is None else list(d[k])
        return d

    @classmethod
    def from_dict(cls, d: dict) -> SynthSpec:
        return _from_dict(cls, d, "synth spec")

    def save(self, path) -> Path:
        """Write the spec as JSON (atomically: :func:`woodcam._atomic.write_text`)."""
        from .._atomic import write_text

        return write_text(path, json.dumps(self.to_dict(), indent=2) + "\n", mkdir=True)

    @classmethod
    def load(cls, path) -> SynthSpec:
        from .._readers import read_json_object

        d = read_json_object(path, "synth spec")
        return cls.from_dict(d)

    # -- the flat keywords of synth_block ---------------------------------------------------
    def flat(self) -> dict:
        """The spec under the flat keyword names of :func:`~woodcam.synth.synth_block`."""
        out = {k: getattr(self, k) for k in ("px_per_mm", "face_px", "faces", "trace_faces",
                                             "ring_map_faces", "seed")}
        for key, (part, name) in FLAT_KEYWORDS.items():
            out[key] = getattr(getattr(self, part), name)
        return out

    def replace_flat(self, **keywords) -> SynthSpec:
        """A copy with flat keywords (``trace_dropout=0.2``, ``face_px=96``...) applied."""
        top = {k: keywords.pop(k) for k in list(keywords)
               if k in ("px_per_mm", "face_px", "faces", "trace_faces", "ring_map_faces", "seed")}
        parts: dict[str, dict] = {}
        for key in list(keywords):
            if key not in FLAT_KEYWORDS:
                known = sorted([*FLAT_KEYWORDS, "px_per_mm", "face_px", "faces", "trace_faces",
                                "ring_map_faces", "seed"])
                raise WoodcamError(f"synth_block got an unknown keyword {key!r}; the settings are "
                                   f"{', '.join(known)} (or spec=SynthSpec(...))")
            part, name = FLAT_KEYWORDS[key]
            parts.setdefault(part, {})[name] = keywords.pop(key)
        new = {part: replace(getattr(self, part), **vals) for part, vals in parts.items()}
        return replace(self, **top, **new)


#: Flat keyword of ``synth_block`` -> (part of :class:`SynthSpec`, field of that part).
FLAT_KEYWORDS: dict[str, tuple[str, str]] = {
    "photo_noise": ("photo", "noise"),
    "photo_variation": ("photo", "variation"),
    "photo_blur_px": ("photo", "blur_px"),
    "trace_dropout": ("traces", "dropout"),
    "trace_dropout_chunk_mm": ("traces", "dropout_chunk_mm"),
    "trace_jitter_mm": ("traces", "jitter_mm"),
    "trace_jitter_corr_mm": ("traces", "jitter_corr_mm"),
    "mislabel_fraction": ("traces", "mislabel_fraction"),
    "unlabelled_fraction": ("traces", "unlabelled_fraction"),
    "ring_map_sigma_px": ("ring_map", "sigma_px"),
    "ring_map_noise": ("ring_map", "noise"),
}


def _from_dict(cls, d: dict, what: str):
    if not isinstance(d, dict):
        raise WoodcamError(f"{what} must be a JSON object; got {type(d).__name__}")
    known = {f.name for f in fields(cls)}
    unknown = set(d) - known
    if unknown:
        raise WoodcamError(f"{what} has unknown keys {sorted(unknown)}; known: {sorted(known)}")
    return cls(**d)
