"""Reading and writing logs: the CT-measured Norway spruce log of ``shared/data/trees/``
(:func:`read_gran1`) and the woodcam log file (JSON, :func:`read_log` / :func:`write_log`).

A log read here is a :class:`woodcam.fields.skeleton.LogSkeleton`, the knot field's input.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

from .._checks import as_floats, check_bool, check_path
from .._readers import read_json_file
from .._types import PathLike
from ..errors import WoodcamError
from ..fields.skeleton import BranchStrand, LogSkeleton


def shared_data_dir() -> Path | None:
    """The shared reference-data folder (``$WOODCAM_SHARED_DATA`` or ``<repo>/../shared/data``).

    Returns ``None`` when neither exists (a user's machine): callers then skip or ask for a path.
    """
    env = os.environ.get("WOODCAM_SHARED_DATA")
    cands = [Path(env)] if env else []
    cands.append(Path(__file__).resolve().parents[3] / "shared" / "data")
    for c in cands:
        if c.is_dir():
            return c
    return None


def gran1_folder(fix: str) -> Path:
    """The folder of the real log's files (``<shared data>/trees``, read by :func:`read_gran1`),
    or the error that there is no shared data folder, ending in ``fix``: how the caller's user
    points at the files otherwise (``read_gran1``'s ``folder=``; on the command line, which has
    no such option, a log file of their own), so each says its own way."""
    base = shared_data_dir()
    if base is None:
        raise WoodcamError(f"the real log needs the shared data folder (its trees/Gran_1_*.json), and none "
                           f"was found; set WOODCAM_SHARED_DATA=/path/to/shared/data {fix}")
    return base / "trees"


def write_log(log: LogSkeleton, path: PathLike) -> Path:
    """Write ``log`` as a woodcam log file (JSON, every length in mm, the log's own frame: z
    along the pith, :class:`~woodcam.fields.skeleton.LogSkeleton`); returns the path."""
    from .._atomic import write_text

    if not isinstance(log, LogSkeleton):  # None was an AttributeError ('to_json')
        raise WoodcamError(f"log must be a woodcam.fields.skeleton.LogSkeleton; got {type(log).__name__}; "
                           "pass read_log(...), read_gran1() or generate_log(...).to_skeleton()")
    return write_text(check_path(path, "write_log: path", fix="e.g. 'logs/spruce.json'"),
                      json.dumps(log.to_json()), mkdir=True)


def read_log(path: PathLike) -> LogSkeleton:
    """Read a woodcam log file written by :func:`write_log` (or by hand, same keys) as a
    :class:`~woodcam.fields.skeleton.LogSkeleton` (log frame, mm). ``path``: the JSON log file."""
    path = check_path(path, "read_log: path", fix="a JSON log file written by write_log")
    if not path.is_file():
        raise WoodcamError(f"log file {str(path)!r} does not exist; give a path to a JSON file "
                           "written by woodcam (or use the real log: --real)")
    try:
        d = read_json_file(path, "log file")  # its errors name the file
    except WoodcamError as err:  # but gave no fix: 'log render photo.png' said "... is not UTF-8 text"
        raise WoodcamError(f"{err}; give a woodcam log file (JSON, as 'woodcam log export' writes), or --real "
                           "for the measured log") from err
    try:
        return LogSkeleton.from_json(d)
    except WoodcamError as err:  # from_json's do not: it reads a dict, from anywhere
        raise WoodcamError(f"{str(path)!r}: {err}") from err


def read_gran1(folder: PathLike | None = None, *, centre: bool = True) -> LogSkeleton:
    """Read the CT-measured Norway spruce log "Gran_1" of ``shared/data/trees/``.

    Parameters
    ----------
    folder : path or None
        Folder with ``Gran_1_pith.json``, ``Gran_1_radii.json``, ``Gran_1_knots.json``;
        default ``<shared data>/trees``.
    centre : bool
        Shift ``x, y`` so the pith at mid-length is at the origin (as the seed's stem map does).

    Notes
    -----
    Azimuth convention of the radii, checked against the data: a knot's axis at its end
    distance ``r_end`` lands on the measured outer surface (median |r_end - R| = 1.6 mm over
    the 98 knots ending beyond 100 mm) only when radii column ``j`` is read at azimuth
    ``-j`` degrees; counter-clockwise ``+j`` gives 4.0 mm and the seed shader's
    ``atan(x, y)`` reading 6.6 mm. The radii are therefore flipped to this module's
    counter-clockwise convention. The knot coefficients are in radians and mm.
    """
    centre = check_bool(centre, "read_gran1: centre")  # the arguments before the data folder is sought
    if folder is None:
        folder = gran1_folder("or pass folder=")
    folder = check_path(folder, "read_gran1: folder", fix="shared/data/trees, or None for the shared data folder's")
    def table(name: str, what: str, columns: int | None, min_rows: int) -> np.ndarray:
        # read as every JSON file is (bad JSON, NaN or a folder given as the file were bare errors)
        path = folder / name
        if not path.is_file():
            raise WoodcamError(f"folder {str(folder)!r} lacks {name}; point it at shared/data/trees")
        a = as_floats(read_json_file(path, "read_gran1: file"))
        if a is not None and a.size == 0 and min_rows == 0 and columns is not None:  # a log without knots
            a = a.reshape(0, columns)
        if a is None or a.ndim != 2 or len(a) < min_rows or (columns is not None and a.shape[1] != columns) \
                or not np.all(np.isfinite(a)):
            raise WoodcamError(f"read_gran1: {str(path)!r} must hold {what} (finite numbers); got "
                               f"{'shape ' + str(a.shape) if a is not None else 'other JSON'}; point the "
                               "folder at shared/data/trees")
        return a

    pith = table("Gran_1_pith.json", "rows [x, y, z] mm of the pith, two or more", 3, 2)
    radii = table("Gran_1_radii.json", "one row of radii (mm) per pith row", None, 2)
    rows = table("Gran_1_knots.json", "one row [A, B, z0, D, E, w0, G, r_end, r_death] per knot", 9, 0)
    xy = pith[:, :2].copy()
    if centre:
        xy -= xy[len(xy) // 2]
    a = radii.shape[1]
    radii_ccw = radii[:, (-np.arange(a)) % a]  # column j (ccw +j deg) <- data column -j
    r_max = float(radii.max())
    knots = tuple(BranchStrand.from_model(*row, r_max_mm=r_max) for row in rows)
    return LogSkeleton(pith[:, 2], xy, radii_ccw, knots, "Gran_1")
