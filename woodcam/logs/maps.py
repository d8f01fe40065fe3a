"""The seed's image encoding of a log: stem map and knot height / orientation / state maps.

Seed 003 ("input tree log data") stores a log in four 8-bit RGB images plus a few numbers, so
tools can exchange logs as pictures. :func:`write_maps` writes a :class:`~woodcam.fields.skeleton.LogSkeleton` in that
form, :func:`read_maps` reads it back (or maps made by another tool with the same layout).

Layout (``h`` = log length, ``r_min``/``r_max`` = smallest/largest outer radius, all mm; values
map linearly onto 0..255):

stem map (``stem_map.png``, ``rows x cols``, seed default 512 x 128)
    row ``i``: height ``z0 + i h / (rows - 1)`` (row 0 = butt end); column ``j``: azimuth
    ``2 pi j / cols`` counter-clockwise from ``+x`` (``clockwise=True`` for maps whose columns
    turn the other way, like the measured log's raw radii). R, G: pith ``x, y`` minus the pith
    at mid-length, over ``[-r_min/2, r_min/2]``; B: outer radius over ``[r_min, r_max]``.
knot maps (``knot_*_map.png``, one row per knot (``row_height`` rows each), ``cols`` columns)
    column ``j``: pith distance ``d = j r_max / (cols - 1)``.
    height map: R start height ``z0`` over ``[0, h]`` (from the butt end), G rise ``z+`` and
    B fall ``z-`` over ``[0, r_min]``.
    orientation map: R start azimuth ``omega0`` over ``[0, 2 pi)``, G counter-clockwise twist
    and B clockwise twist over ``[0, pi/2]``.
    state map: R 255 where the knot is alive at ``d``, G death distance over ``[0, r_max]``;
    B (woodcam's addition, 0 in the seed's maps) knot diameter over ``[0, diameter_max]``, 0
    beyond the knot's end. Without it the reader uses :data:`DEFAULT_DIAMETER` and
    ``r_end = r_max``.
``map_params.json``: ``r_min_mm``, ``r_max_mm``, ``height_mm``, ``n_knots`` (the seed tool's
four numbers) plus woodcam's ``z_start_mm``, ``pith_mid_xy_mm``, ``diameter_max_mm``,
``row_height``, ``clockwise``.

8-bit quantisation limits precision: a step is ``h/255`` in start height (15.7 mm for a 4 m
log), ``r_min/255`` in pith offset, rise and fall, ``2 pi/255`` in start azimuth. The woodcam log
file (JSON, :func:`~woodcam.logs.io.write_log`) is the lossless format.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .._atomic import atomic_path, write_text
from .._checks import check_bool, check_number, check_vector, received
from .._readers import read_json_file
from ..errors import WoodcamError
from ..fields.skeleton import BranchStrand, LogSkeleton
from .._types import PathLike

MAP_FILES = {"stem": "stem_map.png", "height": "knot_height_map.png",
             "orientation": "knot_orientation_map.png", "state": "knot_state_map.png",
             "params": "map_params.json"}

#: Diameter model (mm, of the pith distance r in mm) for knot maps without a diameter channel:
#: the median real-log knot (A = 0.2, B = -0.05 in ``A r^(1+B)``).
DEFAULT_DIAMETER = (0.2, -0.05)


def _q(x, lo, hi):
    """Quantise ``x`` in ``[lo, hi]`` to 0..255 (rounded, clipped)."""
    span = max(hi - lo, 1e-9)          # a round log has r_min == r_max
    return np.clip(np.rint((np.asarray(x, float) - lo) / span * 255.0), 0, 255)


def _dq(v, lo, hi):
    return lo + np.asarray(v, float) / 255.0 * (hi - lo)


def encode_maps(log: LogSkeleton, *, stem_shape=(512, 128), knot_columns: int = 128,
                row_height: int = 1, clockwise: bool = False) -> tuple[dict, dict]:
    """The four maps as ``uint8 (rows, cols, 3)`` arrays and the parameter dict."""
    rows, cols = stem_shape
    z_start = float(log.pith_z_mm[0])
    h = log.length_mm
    r_min, r_max = log.r_min_mm, log.r_max_mm
    mid = log.pith_at(np.array([z_start + h / 2]))[0]
    z = z_start + np.arange(rows) * h / (rows - 1)
    om = 2 * np.pi * np.arange(cols) / cols
    if clockwise:
        om = -om
    pxy = log.pith_at(z) - mid
    stem = np.zeros((rows, cols, 3))
    stem[:, :, 0] = _q(pxy[:, 0], -0.5 * r_min, 0.5 * r_min)[:, None]
    stem[:, :, 1] = _q(pxy[:, 1], -0.5 * r_min, 0.5 * r_min)[:, None]
    stem[:, :, 2] = _q(log.radius_at(np.repeat(z, cols), np.tile(om, rows)).reshape(rows, cols),
                       r_min, r_max)
    n = len(log.knots)
    d = np.arange(knot_columns) * r_max / (knot_columns - 1)
    dmax = float(max([k.diameter_mm.max() for k in log.knots] + [1.0]))
    # a log without knots keeps one blank row: a PNG has at least one (map_params' n_knots 0 says
    # it holds no knot; 'woodcam log maps' of a knotless log was "cannot write empty image")
    H = np.zeros((max(n, 1) * row_height, knot_columns, 3))
    O = np.zeros_like(H)
    S = np.zeros_like(H)
    for i, k in enumerate(log.knots):
        sl = slice(i * row_height, (i + 1) * row_height)
        rise = np.interp(d, k.r_mm, k.rise_mm)
        tw = np.interp(d, k.r_mm, k.twist_rad)
        H[sl, :, 0] = _q(k.z0_mm - z_start, 0.0, h)
        H[sl, :, 1] = _q(np.maximum(rise, 0), 0.0, r_min)
        H[sl, :, 2] = _q(np.maximum(-rise, 0), 0.0, r_min)
        O[sl, :, 0] = _q(np.mod(k.azimuth0_rad, 2 * np.pi), 0.0, 2 * np.pi)
        O[sl, :, 1] = _q(np.maximum(tw, 0), 0.0, 0.5 * np.pi)
        O[sl, :, 2] = _q(np.maximum(-tw, 0), 0.0, 0.5 * np.pi)
        S[sl, :, 0] = np.where(d < k.r_death_mm, 255, 0)
        S[sl, :, 1] = _q(k.r_death_mm, 0.0, r_max)
        diam = np.interp(d, k.r_mm, k.diameter_mm)
        qd = np.maximum(_q(diam, 0.0, dmax), 1)       # >= 1 inside the knot, so 0 means "ended"
        S[sl, :, 2] = np.where(d <= k.r_end_mm, qd, 0)
    params = {"r_min_mm": r_min, "r_max_mm": r_max, "height_mm": h, "n_knots": n,
              "z_start_mm": z_start, "pith_mid_xy_mm": [float(mid[0]), float(mid[1])],
              "diameter_max_mm": dmax, "row_height": row_height, "clockwise": clockwise,
              "name": log.name}
    maps = {"stem": stem, "height": H, "orientation": O, "state": S}
    return {k: v.astype(np.uint8) for k, v in maps.items()}, params


def write_maps(log: LogSkeleton, folder: PathLike, **kw) -> dict:
    """Write the maps of :func:`encode_maps` of ``log`` as PNGs plus ``map_params.json`` into
    ``folder`` (made if missing); ``kw`` go to :func:`encode_maps`. Returns ``{name: path}``."""
    from PIL import Image

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    maps, params = encode_maps(log, **kw)
    out = {}
    for k, a in maps.items():
        out[k] = folder / MAP_FILES[k]
        with atomic_path(out[k]) as tmp:
            Image.fromarray(a, "RGB").save(tmp)
    out["params"] = folder / MAP_FILES["params"]
    write_text(out["params"], json.dumps(params, indent=1))
    return out


def _map_params(params) -> dict:
    """``map_params.json``'s numbers checked (a JSON file, from anywhere: a string, a number or a
    text value was an internal error, NaN or a negative height the log's own error about its
    pith samples, a one-number ``pith_mid_xy_mm`` read as both coordinates without a word):
    ``r_min_mm``, ``r_max_mm`` (0 < r_min <= r_max) and ``height_mm`` (> 0) in mm, with
    woodcam's optional ``z_start_mm`` (finite), ``pith_mid_xy_mm`` (two finite numbers),
    ``diameter_max_mm`` (> 0), ``row_height`` (a whole number >= 1) and ``clockwise`` (a
    bool) at their defaults; the seed tool's four-number list is read as its dict."""
    if isinstance(params, (list, tuple)):
        params = dict(zip(("r_min_mm", "r_max_mm", "height_mm", "n_knots"), params))
    if not isinstance(params, dict):
        raise WoodcamError(f"map parameters must be a JSON object (r_min_mm, r_max_mm, height_mm, ...) or "
                           f"the seed's list of four numbers; got {received(params)}")
    missing = [k for k in ("r_min_mm", "r_max_mm", "height_mm") if k not in params]
    if missing:
        raise WoodcamError(f"map parameters lack {missing[0]!r}; give r_min_mm, r_max_mm and "
                           "height_mm (mm)")
    out = dict(params)
    r_min = out["r_min_mm"] = check_number(params["r_min_mm"], "map parameters' r_min_mm", lo=0, lo_open=True)
    out["r_max_mm"] = check_number(params["r_max_mm"], "map parameters' r_max_mm", lo=r_min,
                                   fix="the largest outer radius, >= r_min_mm")
    out["height_mm"] = check_number(params["height_mm"], "map parameters' height_mm", lo=0, lo_open=True)
    out["z_start_mm"] = check_number(params.get("z_start_mm", 0.0), "map parameters' z_start_mm")
    out["pith_mid_xy_mm"] = check_vector(params.get("pith_mid_xy_mm", (0.0, 0.0)),
                                         "map parameters' pith_mid_xy_mm", n=2)
    out["diameter_max_mm"] = check_number(params.get("diameter_max_mm", 1.0), "map parameters' diameter_max_mm",
                                          lo=0, lo_open=True)
    rh = params.get("row_height", 1)
    if isinstance(rh, float) and rh.is_integer():  # 3.0: a whole number, as n_knots takes it
        rh = int(rh)
    out["row_height"] = check_number(rh, "map parameters' row_height", lo=1, integer=True)
    out["clockwise"] = check_bool(params.get("clockwise", False), "map parameters' clockwise",
                                  fix="true or false")
    return out


def decode_maps(maps: dict, params: dict) -> LogSkeleton:
    """A :class:`Log` from map arrays (``uint8 (rows, cols, 3)``) and the parameter dict.

    ``params`` needs the seed's ``r_min_mm``, ``r_max_mm``, ``height_mm`` (a list
    ``[r_min, r_max, height, n_knots]``, the seed tool's ``map_params.json``, is accepted too).
    """
    params = _map_params(params)
    r_min, r_max, h = (params[k] for k in ("r_min_mm", "r_max_mm", "height_mm"))
    z_start, mid, rh = params["z_start_mm"], params["pith_mid_xy_mm"], params["row_height"]
    clockwise = params["clockwise"]
    stem = np.asarray(maps["stem"], float)
    if stem.ndim != 3 or stem.shape[2] < 3 or stem.shape[0] < 2:
        raise WoodcamError(f"stem map must be an RGB image with >= 2 rows; got {stem.shape}")
    rows, cols = stem.shape[:2]
    z = z_start + np.arange(rows) * h / (rows - 1)
    pxy = np.stack([_dq(stem[:, :, 0].mean(1), -0.5 * r_min, 0.5 * r_min),
                    _dq(stem[:, :, 1].mean(1), -0.5 * r_min, 0.5 * r_min)], axis=1) + mid
    radii = _dq(stem[:, :, 2], r_min, r_max)
    if clockwise:
        radii = radii[:, (-np.arange(cols)) % cols]
    H = np.asarray(maps["height"], float)
    O = np.asarray(maps["orientation"], float)
    S = np.asarray(maps["state"], float)
    if not (H.shape == O.shape == S.shape) or H.ndim != 3:
        raise WoodcamError(f"knot maps must share one shape (knots x columns x 3); got "
                           f"{H.shape}, {O.shape}, {S.shape}")
    n = H.shape[0] // rh
    if "n_knots" in params:  # fewer rows than knots is the maps' own; more: a knotless log's blank row
        nk = params["n_knots"]
        if isinstance(nk, bool) or not isinstance(nk, (int, float)) or not nk >= 0 or nk != int(nk):
            raise WoodcamError(f"map parameters' n_knots must be a whole number >= 0 (the knot rows); "
                               f"got {nk!r}")
        n = min(n, int(nk))
    kc = H.shape[1]
    if kc < 2:  # a column is a pith distance over [0, r_max]: one column spans none (0/0)
        raise WoodcamError(f"knot maps must have >= 2 columns (pith distances 0 .. r_max); got {kc}")
    d = np.arange(kc) * r_max / (kc - 1)
    dmax = params["diameter_max_mm"]
    knots = []
    for i in range(n):
        row = i * rh + rh // 2
        z0 = z_start + _dq(H[row, 0, 0], 0.0, h)
        rise = _dq(H[row, :, 1], 0, r_min) - _dq(H[row, :, 2], 0, r_min)
        w0 = _dq(O[row, 0, 0], 0.0, 2 * np.pi)
        tw = _dq(O[row, :, 1], 0, 0.5 * np.pi) - _dq(O[row, :, 2], 0, 0.5 * np.pi)
        r_death = _dq(S[row, 0, 1], 0.0, r_max)
        B = S[row, :, 2]
        if B.max() > 0:
            inside = np.nonzero(B > 0)[0]
            r_end = float(d[min(inside[-1], kc - 1)])
            diam = _dq(B, 0.0, dmax)
            diam[0] = 0.0
        else:
            r_end = r_max
            A, Bc = DEFAULT_DIAMETER
            diam = A * np.maximum(d, 1.0) ** (1 + Bc)
            diam[0] = 0.0
        rise = rise - rise[0]
        tw = tw - tw[0]
        knots.append(BranchStrand(float(z0), float(w0), d, rise, tw, diam, max(r_end, d[1]),
                          float(r_death)))
    return LogSkeleton(z, pxy, radii, tuple(knots), str(params.get("name", "log")))


def read_maps(folder: PathLike) -> LogSkeleton:
    """Read the maps written by :func:`write_maps` (same file names) from ``folder``."""
    from PIL import Image

    folder = Path(folder)
    missing = [f for f in MAP_FILES.values() if not (folder / f).is_file()]
    if missing:
        raise WoodcamError(f"map folder {str(folder)!r} lacks {missing}; it needs "
                           f"{sorted(MAP_FILES.values())}; write such a folder with 'woodcam log maps "
                           "(LOG_FILE | --real) --out DIR' (woodcam.logs.write_maps)")
    fix = "write such a folder with 'woodcam log maps (LOG_FILE | --real) --out DIR'"
    maps = {}
    for k, f in MAP_FILES.items():
        if k != "params":
            try:  # a damaged or foreign file was PIL's "cannot identify image file ... check the path"
                with Image.open(folder / f) as im:
                    maps[k] = np.asarray(im.convert("RGB"))
            except (OSError, ValueError, Image.DecompressionBombError) as err:
                raise WoodcamError(f"map folder {str(folder)!r}: cannot decode the image {f} ({err}); "
                                   f"{fix}") from err
    # strict JSON (NaN refused), and its errors name the file: json.loads' were internal errors
    params = read_json_file(folder / MAP_FILES["params"], "map parameters")
    try:
        return decode_maps(maps, params)
    except WoodcamError as err:  # decode_maps reads arrays and a dict, from anywhere: add the folder
        raise WoodcamError(f"map folder {str(folder)!r}: {err}; {fix}") from err
