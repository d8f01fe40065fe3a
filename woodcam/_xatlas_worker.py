"""xatlas charting and packing, run in a child process.

xatlas is native code and can crash the whole interpreter (measured: a segmentation fault on a
closed 82k-triangle icosphere, whatever the chart options, while each half of it unwraps fine).
:func:`woodcam.bake.bake` therefore calls :func:`layout` in a worker process: a crash there
ends in a clear error or a retry with the surface cut into pieces, never in a dead ``woodcam``.
This module imports only numpy and xatlas, so the worker starts fast.
"""

from __future__ import annotations

import numpy as np


def layout(verts: np.ndarray, faces: np.ndarray, pieces: list[np.ndarray], *,
           max_chart_area: float, max_iterations: int, texels_per_mm: float, padding: int):
    """Chart and pack ``pieces`` of one surface into ONE atlas.

    Parameters
    ----------
    verts : (n, 3) float32, mm
    faces : (f, 3) uint32
    pieces : list of (k_i,) int
        Face indices of each piece (together every face once); xatlas sees each as a mesh.
    max_chart_area : float
        xatlas ``ChartOptions.max_chart_area`` in mm^2 (0: no cap).
    max_iterations : int
        xatlas ``ChartOptions.max_iterations``.
    texels_per_mm, padding :
        xatlas ``PackOptions.texels_per_unit`` (one unit is a mm) and ``padding`` (texels).

    Returns
    -------
    vmap : (m,) int64
        Input vertex of every output vertex.
    out_faces : (f, 3) int64
        Output faces in the INPUT face order.
    uv : (m, 2) float64
        xatlas uv, normalised by the atlas size.
    width, height : int
        Atlas size in texels.
    """
    import xatlas

    atlas = xatlas.Atlas()
    local_vertices = []
    for piece in pieces:
        used, local = np.unique(faces[piece], return_inverse=True)
        local_vertices.append(used)
        atlas.add_mesh(np.ascontiguousarray(verts[used]),
                       np.ascontiguousarray(local.reshape(-1, 3), dtype=np.uint32))
    chart_options = xatlas.ChartOptions()
    chart_options.max_iterations = int(max_iterations)
    if max_chart_area > 0:
        chart_options.max_chart_area = float(max_chart_area)
    pack_options = xatlas.PackOptions()
    pack_options.resolution = 0  # one atlas, its size decided by texels_per_unit
    pack_options.texels_per_unit = float(texels_per_mm)
    pack_options.padding = int(padding)
    pack_options.bilinear = True
    atlas.generate(chart_options, pack_options)
    if atlas.atlas_count != 1:
        raise RuntimeError(f"xatlas made {atlas.atlas_count} atlases; expected 1")
    vmaps, uvs = [], []
    out_faces = np.empty((len(faces), 3), dtype=np.int64)
    offset = 0
    for i, piece in enumerate(pieces):
        vmapping, indices, uv = atlas[i]
        vmaps.append(local_vertices[i][np.asarray(vmapping, dtype=np.int64)])
        uvs.append(np.asarray(uv, dtype=np.float64))
        out_faces[piece] = np.asarray(indices, dtype=np.int64) + offset
        offset += len(vmapping)
    return (np.concatenate(vmaps), out_faces, np.concatenate(uvs), int(atlas.width),
            int(atlas.height))


def pack(uv_mm: np.ndarray, faces: np.ndarray, *, texels_per_mm: float, padding: int):
    """Pack charts whose parameterisation the caller made (no xatlas charting): ``uv_mm (k, 2)``
    float32 chart coordinates in mm (one vertex per chart corner; faces of different charts
    share no vertex) and ``faces (f, 3)`` uint32 into them. xatlas takes every UV island as one
    chart, rotates and packs it at ``texels_per_mm`` with ``padding`` texels between charts.

    Returns ``vmap (m,)`` (uv vertex of every output vertex), ``out_faces (f, 3)`` in the input
    face order, ``uv (m, 2)`` normalised by the atlas size, ``width``, ``height``.
    """
    import xatlas

    atlas = xatlas.Atlas()
    atlas.add_uv_mesh(np.ascontiguousarray(uv_mm, dtype=np.float32),
                      np.ascontiguousarray(faces, dtype=np.uint32))
    pack_options = xatlas.PackOptions()
    pack_options.resolution = 0
    pack_options.texels_per_unit = float(texels_per_mm)
    pack_options.padding = int(padding)
    pack_options.bilinear = True
    atlas.generate(xatlas.ChartOptions(), pack_options)
    if atlas.atlas_count != 1:
        raise RuntimeError(f"xatlas made {atlas.atlas_count} atlases; expected 1")
    vmapping, indices, uv = atlas[0]
    return (np.asarray(vmapping, dtype=np.int64), np.asarray(indices, dtype=np.int64),
            np.asarray(uv, dtype=np.float64), int(atlas.width), int(atlas.height))


def run_pack(*args, **kwargs):
    """What the worker runs for :func:`pack` (looked up when called, as :func:`run_layout`)."""
    return pack(*args, **kwargs)


def run_layout(*args, **kwargs):
    """What the worker process runs: :func:`layout`, looked up when called (so a test can put a
    crashing stand-in in its place before the worker is forked)."""
    return layout(*args, **kwargs)


def die_with_parent() -> None:
    """Worker initializer: ask Linux to kill this process when its parent dies (a woodcam killed
    during a long packing left its worker running for minutes at gigabytes; prctl
    PR_SET_PDEATHSIG, SIGKILL). Elsewhere it does nothing."""
    import ctypes
    import signal
    import sys

    if sys.platform.startswith("linux"):
        try:
            ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, int(signal.SIGKILL), 0, 0, 0)  # 1: PR_SET_PDEATHSIG
        except OSError:  # no libc by that name (musl): the worker just may outlive a killed parent
            pass
