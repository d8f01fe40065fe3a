"""Computational parquetry (seed 002, Iseringhausen et al.): a target image rebuilt from veneer
sheets of real wood, every piece used once, with cut files a CNC router can follow.

Layers: :mod:`.veneers` (sheets: scans, slices of a woodcam Wood, Mokume photos), :mod:`.job`
(parameters, Table 1; the paper's JSON job), :mod:`.features` (eq. 1-2), :mod:`.matching`
(eq. 3-4, single use), :mod:`.engine` (priority queue, adaptive patches, render),
:mod:`.seams` (eq. 8-9), :mod:`.cutpaths` (Bézier cut paths, SVG/DXF, fabricability),
:mod:`.output` (the files of a run).
"""

from .engine import (
           Parquetry,
           ParquetryRun,
           Patch,
           build_parquetry,
           feature_cost,
           repair_fabricability,
           ssim_vs_matched,
)
from .job import ParquetryJob, ParquetryParams, read_job, write_job
from .output import write_parquetry
from .veneers import Veneer, load_scan, mokume_veneers, slice_veneers

__all__ = ["Parquetry", "ParquetryJob", "ParquetryParams", "ParquetryRun", "Patch", "Veneer",
           "build_parquetry", "feature_cost", "load_scan", "mokume_veneers", "read_job",
           "repair_fabricability",
           "slice_veneers", "ssim_vs_matched", "write_job", "write_parquetry"]
