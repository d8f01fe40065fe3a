"""Synthetic blocks: cut a block out of a log, render its six faces, trace its rings.

Everything is in the block frame of ``docs/conventions.md`` (mm, origin bottom-front-left, X
width, Y depth, Z up) unless a name says ``log``: the log frame has ``z`` on the pith.
The growth-time field (GTF) gives years since the pith; ring boundaries are its integer
iso-surfaces and ``ARF = (GTF mod 1)^2`` (eq. 6 of seed 000).

- :mod:`~woodcam.synth.cut`: :func:`cut_block` places a log-frame field (any callable
  ``(n, 3) mm -> years``, pith on the log's ``z``; e.g. :class:`AnalyticLogField`, which lives
  in :mod:`woodcam.fields.analytic`) in a block frame for a sawing pattern;
  :func:`random_log_placement` draws one.
- :mod:`~woodcam.synth.block`: :func:`synth_block` renders a :class:`~woodcam.block.Block` from
  a block-frame field: face photos (:mod:`~woodcam.synth.photos`), ring traces on the field's
  integer iso-lines (:mod:`~woodcam.synth.traces`), ring maps
  (:func:`woodcam.fields.rings.ring_map`), annotation faults
  (:mod:`~woodcam.synth.degradation`), all set by a :class:`SynthSpec`
  (:mod:`~woodcam.synth.spec`, JSON round trips).
- :mod:`~woodcam.synth.dataset`: :func:`synth_benchmark_set` writes a reproducible set to disk.
- :mod:`~woodcam.synth.rings`: faces with known rings for the ring detector (evaluation and
  training data of :mod:`woodcam.detect`).

It sits above ``block/``, ``logs/`` and ``appearance/``: none of those imports it.
"""

from ..fields.analytic import AnalyticLogField
from ..fields.rings import MOKUME_RING_SIGMA_MM
from .block import synth_block
from .cut import PATTERNS, SawPattern, cut_block, knot_crosses, random_log_placement
from .dataset import (
           benchmark_set_block,
           knotted_log_field,
           synth_benchmark_set,
           time_synth_block,
)
from .rings import ring_eval_faces, ring_training_faces
from .spec import PhotoSpec, RingMapSpec, SynthSpec, TraceSpec

__all__ = ["MOKUME_RING_SIGMA_MM", "PATTERNS", "AnalyticLogField", "PhotoSpec", "RingMapSpec",
           "SawPattern", "SynthSpec", "TraceSpec", "benchmark_set_block", "cut_block", "knot_crosses",
           "knotted_log_field", "random_log_placement", "ring_eval_faces", "ring_training_faces",
           "synth_benchmark_set", "synth_block", "time_synth_block"]
