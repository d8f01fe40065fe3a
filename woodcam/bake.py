"""Texture baking: UV-unwrap a carved mesh and paint the wood's colour into a texture atlas.

Data form
---------
* Meshes are in the block frame, millimetres (``docs/conventions.md``).
* The wood is any object with ``color(points_mm: (n, 3) float, normals: (n, 3) float unit)
  -> (n, 3) float RGB in [0, 1]`` (seed 000, eq. 10 is one such appearance: a normal-weighted
  blend of three colour volumes). The baker never looks inside it.
* The atlas is an image ``(h, w, 3) uint8``; row 0 is the TOP row of the image file. Colours
  are stored as ``round(255 * rgb)``: ``wood.color`` is taken to return display (sRGB-encoded)
  values, which is how glTF and OBJ viewers read a base-colour texture.

Texel / UV convention (the "v flip")
------------------------------------
Texel ``(row r, col c)`` of an atlas of ``h x w`` texels covers ``[c, c + 1] x [r, r + 1]`` in
texel coordinates ``(x, y)``; its centre is ``(c + 0.5, r + 0.5)``.  The mesh carries trimesh /
OBJ texture coordinates, origin at the image's bottom-left::

    u = x / w,        v = 1 - y / h          (centre of texel (r, c): u = (c + .5) / w,
                                                                   v = 1 - (r + .5) / h)

trimesh's glTF exporter writes ``(u, 1 - v)``, i.e. glTF's top-left origin, so GLB viewers and
OBJ viewers both sample texel (r, c) at the same surface point.

Pipeline (each step timed in :attr:`BakeResult.timings`)
--------------------------------------------------------
1. ``unwrap``: xatlas charts + packing at ``texels_per_unit = texels_per_mm`` (the mesh is in mm,
   so one xatlas "unit" is a millimetre), one atlas, charts ``padding_px`` texels apart.
2. ``rasterise``: every triangle is rasterised conservatively in texel space: triangles are
   grouped by bounding-box size and each group is tested as one broadcast numpy array
   (triangles x rows x cols) of edge functions (no per-texel Python loop). A texel is painted
   when its centre lies within L-infinity distance 1 (+ a 0.02 texel margin) of the triangle,
   which covers every texel bilinear sampling at any point of the triangle can read. A texel
   whose centre lies inside a triangle takes that triangle; a texel only in border rings takes the
   nearest triangle and the triangle's affine map is extrapolated to it (a point in the
   triangle's plane at most ~1.5 texels outside it).
3. ``color``: 3D point and normal of every painted texel -> ``wood.color`` in bounded batches.
4. ``dilate``: every unpainted texel takes the colour of its nearest painted texel (exact
   Euclidean distance transform), so no mip level ever averages in black.
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field
from typing import Any, Literal, get_args

import numpy as np

from woodcam.errors import WoodcamError, WoodcamWarning
from woodcam.tolerances import (
    ATLAS_PADDING_PX,
    MAX_BATCH_POINTS,
    MIN_UV_AREA_TEXELS2,
    RASTER_MARGIN_TEXELS,
)

NormalsMode = Literal["face", "smooth"]

#: Fraction of the atlas xatlas fills with charts at 8 px padding (measured 0.5-0.85 on
#: spheres and carved boxes); used only to predict the atlas side before unwrapping.
_PACK_EFFICIENCY = 0.6

#: Upper bound on the area of one xatlas chart as a fraction of the surface area, via
#: ``ChartOptions.max_chart_area`` (0: no cap). Measured UV fill / xatlas CPU-s at 10 texels/mm
#: (bowl 32k triangles; lid 12k; 20k icosphere): uncapped 0.59 / 4.0, 0.57 / 0.9, 0.61 / 2.3;
#: cap 1/32 0.39 / 2.4, 0.50 / 1.2, 0.55 / 0.8; the earlier cap of 256 x the median face
#: made CAD parts (triangle areas vary by orders of magnitude) into ~1,100 sliver charts
#: filling 0.15. Fill is what the texel budget buys, so no cap; the triangle budget of
#: load_part bounds the unwrap time instead.
_CHART_AREA_FRACTION = 0.0

#: xatlas ``ChartOptions.max_iterations``: one pass of chart growing (see above).
_CHART_ITERATIONS = 0

#: Run xatlas in this process (no crash guard); for debugging only.
_XATLAS_IN_PROCESS = False

#: When xatlas' packed atlas overshoots ``max_atlas_px`` by a factor down to this, the layout is
#: scaled down instead of re-unwrapped: chart gaps shrink from ``padding_px`` to at worst
#: 0.85 x ``padding_px`` (never below _MIN_PADDING_PX), and xatlas' ~1 s is not repeated.
_MIN_RESCALE = 0.85

#: Smallest gap (texels) between charts: each chart needs its own 1-texel ring for bilinear
#: sampling, so two charts need 2 texels between them.
_MIN_PADDING_PX = 2

#: (triangle, texel) candidate pairs processed per rasterisation chunk: bounds peak memory to
#: roughly 40 bytes x this (~170 MB).
_RASTER_CHUNK_PAIRS = 1 << 22

#: Side (texels) of the square tiles large or sliver triangles are rasterised in. Measured
#: (CPU s, rasterising a 20k-triangle sphere at 2k^2 / an 8.8k-triangle carved block at 1k^2,
#: with every triangle above 8 texels tiled): tile 4: 0.67 / 0.48, 8: 0.45 / 0.34,
#: 16: 0.35 / 0.49 (slivers waste most of a big tile).
_TILE = 8

#: Triangles whose expanded bounding box is at most this many texels both ways, and which fill
#: at least _SMALL_MIN_FILL of it, are rasterised as one block each (grouped by block size);
#: the rest (big faces, slivers of CAD triangle fans) go through culled tiles.
_SMALL_BBOX = 16
_SMALL_MIN_FILL = 0.2

#: Atlas width and height are rounded up to a multiple of this, so mip levels 1..3 halve exactly.
_ATLAS_SIZE_MULTIPLE = 8


@dataclass
class BakeResult:
    """What :func:`bake` returns.

    Attributes
    ----------
    mesh : trimesh.Trimesh
        The input surface with vertices split at UV seams (as xatlas returns them), mm, block
        frame, ``visual = TextureVisuals(uv (m, 2), material=PBRMaterial(baseColorTexture=PIL))``;
        faces in the input's order. With ``normals="smooth"`` its ``vertex_normals`` are the
        input's (seam-free shading).
    atlas : (h, w, 3) uint8
        The baked, dilated texture; row 0 is the image's top row.
    coverage_mask : (h, w) bool
        Texels painted from a triangle (before dilation); the rest are dilation fill.
    texels_per_mm : float
        Texel density actually used (lower than asked when the atlas would exceed
        ``max_atlas_px``; then ``warnings`` says so).
    timings : dict[str, float]
        Seconds per step: ``unwrap``, ``rasterise``, ``color``, ``dilate``, ``total``.
    warnings : list[str]
        Human-readable messages about anything the baker changed from what was asked.
    vertex_map : (m,) int
        Index of the input vertex each output vertex came from.
    uv_fill : float
        Share of the atlas covered by the triangles' texel-space area (packing efficiency).
    """

    mesh: Any
    atlas: np.ndarray
    coverage_mask: np.ndarray
    texels_per_mm: float
    timings: dict[str, float]
    warnings: list[str] = field(default_factory=list)
    vertex_map: np.ndarray | None = None
    uv_fill: float = 0.0

    @property
    def gpu_bytes(self) -> int:
        """GPU memory of the texture as an RGBA8 image with its mip chain (x 4/3)."""
        h, w = self.atlas.shape[:2]
        return int(h * w * 4 * 4 / 3)

    def summary(self) -> str:
        """One line: atlas size, fill, texel density and GPU memory."""
        h, w = self.atlas.shape[:2]
        return (f"atlas {w}x{h}, UV fill {100 * self.uv_fill:.0f} %, "
                f"{self.texels_per_mm:.3g} texels/mm, GPU {self.gpu_bytes / 2**20:.0f} MiB")


def bake(
    mesh,
    wood,
    *,
    texels_per_mm: float = 10.0,
    max_atlas_px: int = 4096,
    padding_px: int = ATLAS_PADDING_PX,
    normals: NormalsMode = "face",
    progress: bool = False,
) -> BakeResult:
    """Unwrap ``mesh`` and bake ``wood.color`` into a texture atlas.

    Parameters
    ----------
    mesh : trimesh.Trimesh
        Triangle surface in the block frame, mm (e.g. a carved part).
    wood : object with ``color(points_mm (n, 3), normals (n, 3)) -> (n, 3) RGB in [0, 1]``
    texels_per_mm : float
        Wanted texel density (texels per mm along the surface), > 0.
    max_atlas_px : int
        Largest allowed atlas side in texels; the density is lowered (with a warning) to fit.
    padding_px : int
        Texels between charts in the atlas, >= 2 (with 0 or 1 a texel between two charts would
        need two colours: measured errors reach the bound's limit). 8 keeps mip levels 1-2 inside
        one chart's dilation.
    normals : {"face", "smooth"}
        Normal passed to ``wood.color``: the flat triangle normal (right for CAD parts with sharp
        edges), or trimesh's vertex normal of the INPUT mesh (before the seam split) interpolated
        barycentrically and renormalised (for smooth organic surfaces).
    progress : bool
        Show a tqdm bar over the rasterisation groups.

    Returns
    -------
    BakeResult
    """
    import trimesh

    from .appearance.wood import wood_colors  # the one check of the colour contract

    t_start = time.perf_counter()
    _check_args(mesh, wood, texels_per_mm, max_atlas_px, padding_px, normals)
    messages: list[str] = []
    timings: dict[str, float] = {}

    # ---- 1. unwrap -------------------------------------------------------------------------
    t0 = time.perf_counter()
    vmap, faces, xy, width, height, tpm = _unwrap(mesh, float(texels_per_mm), int(max_atlas_px),
                                                  int(padding_px), messages)
    timings["unwrap"] = time.perf_counter() - t0
    img_w = _round_up(width, _ATLAS_SIZE_MULTIPLE)
    img_h = _round_up(height, _ATLAS_SIZE_MULTIPLE)

    # ---- 2. rasterise ----------------------------------------------------------------------
    t0 = time.perf_counter()
    tri_of_texel = _rasterise(xy, faces, img_w, img_h, progress=progress)
    painted = np.flatnonzero(tri_of_texel >= 0)
    tri = tri_of_texel[painted]
    timings["rasterise"] = time.perf_counter() - t0

    # ---- 3. colour -------------------------------------------------------------------------
    t0 = time.perf_counter()
    verts = np.asarray(mesh.vertices, dtype=np.float64)[vmap]
    point_map = _affine_maps(xy, faces, verts)
    if normals == "face":
        # xatlas keeps face order, so output face i is input face i.
        face_normals = np.asarray(mesh.face_normals, dtype=np.float64)
    else:
        normal_map = _affine_maps(xy, faces, np.asarray(mesh.vertex_normals,
                                                         dtype=np.float64)[vmap])
    atlas = np.zeros((img_h * img_w, 3), dtype=np.uint8)
    # Batches of MAX_BATCH_POINTS texels: bounded memory, arrays that stay in cache.
    for s in range(0, len(painted), MAX_BATCH_POINTS):
        idx = painted[s:s + MAX_BATCH_POINTS]
        t = tri[s:s + MAX_BATCH_POINTS]
        cx = (idx % img_w + 0.5)[:, None]
        cy = (idx // img_w + 0.5)[:, None]
        points = _apply_affine(point_map, t, cx, cy)
        if normals == "face":
            nrm = face_normals[t]
        else:
            nrm = _apply_affine(normal_map, t, cx, cy)
            nrm /= np.maximum(np.linalg.norm(nrm, axis=1, keepdims=True), 1e-12)
        rgb = wood_colors(wood, points, nrm)
        atlas[idx] = np.round(np.clip(rgb, 0.0, 1.0) * 255.0).astype(np.uint8)
    atlas = atlas.reshape(img_h, img_w, 3)
    coverage = (tri_of_texel >= 0).reshape(img_h, img_w)
    timings["color"] = time.perf_counter() - t0

    # ---- 4. dilate -------------------------------------------------------------------------
    t0 = time.perf_counter()
    atlas = _dilate(atlas, coverage)
    timings["dilate"] = time.perf_counter() - t0

    uv = np.column_stack([xy[:, 0] / img_w, 1.0 - xy[:, 1] / img_h])
    out = _textured_mesh(trimesh, verts, faces, uv, atlas)
    if normals == "smooth":
        # Shading normals from the unsplit input, so viewers show no shading seam where xatlas
        # split vertices (normals recomputed on the split mesh differ on each side of a seam).
        # The GLB exporter writes them as NORMAL; "face" mode leaves them out (flat shading).
        out.vertex_normals = np.asarray(mesh.vertex_normals, dtype=np.float64)[vmap]
    timings["total"] = time.perf_counter() - t_start
    for msg in messages:
        warnings.warn(msg, WoodcamWarning, stacklevel=2)
    return BakeResult(
        mesh=out,
        atlas=atlas,
        coverage_mask=coverage,
        texels_per_mm=tpm,
        timings=timings,
        warnings=messages,
        vertex_map=vmap,
        uv_fill=_uv_fill(xy, faces, img_w, img_h),
    )


def bake_charts(mesh, uv_px, size_px, texels, wood, *, texels_per_mm: float,
                vertex_normals=None, messages=(), fill_gutters=None) -> BakeResult:
    """Bake ``wood.color`` into an atlas whose charts the caller already knows (no unwrap, no
    rasterisation): ``mesh`` with per-vertex texel coordinates ``uv_px : (n, 2)`` (x right, y
    down, pixel corners at integers) in an atlas of ``size_px = (width, height)``, and
    ``texels``, an iterable of ``(flat texel indices (k,), points_mm (k, 3), normals (k, 3))``
    giving every chart texel's point and normal. Used for the height-field stock of a G-code
    preview (:class:`woodcam.toolpath.mesh.HeightfieldCharts`), whose top is textured by its own
    planar parameterisation. ``vertex_normals`` (optional, (n, 3)) are kept on the result mesh
    for export; ``fill_gutters(atlas, coverage) -> atlas`` (optional) paints the texels outside
    the charts when the caller knows a cheaper way than the nearest-texel transform (the
    height field's rectangles); the rest as :func:`bake`."""
    import trimesh

    from .appearance.wood import wood_colors  # the one check of the colour contract

    t_start = time.perf_counter()
    timings: dict[str, float] = {}
    w, h = (int(v) for v in size_px)
    atlas = np.zeros((h * w, 3), np.uint8)
    coverage = np.zeros(h * w, bool)
    for idx, pts, nrm in texels:
        for s in range(0, len(idx), MAX_BATCH_POINTS):
            sl = slice(s, s + MAX_BATCH_POINTS)
            rgb = wood_colors(wood, pts[sl], nrm[sl])
            atlas[idx[sl]] = np.round(np.clip(rgb, 0.0, 1.0) * 255.0).astype(np.uint8)
        coverage[idx] = True
    atlas = atlas.reshape(h, w, 3)
    coverage = coverage.reshape(h, w)
    timings["color"] = time.perf_counter() - t_start
    t0 = time.perf_counter()
    atlas = fill_gutters(atlas, coverage) if fill_gutters is not None else _dilate(atlas, coverage)
    timings["dilate"] = time.perf_counter() - t0
    uv_px = np.asarray(uv_px, float)
    uv = np.column_stack([uv_px[:, 0] / w, 1.0 - uv_px[:, 1] / h])
    out = _textured_mesh(trimesh, np.asarray(mesh.vertices), np.asarray(mesh.faces), uv, atlas)
    if vertex_normals is not None:
        out.vertex_normals = vertex_normals  # exported as is (export normals="mesh")
    timings["total"] = time.perf_counter() - t_start
    messages = list(messages)
    for msg in messages:
        warnings.warn(msg, WoodcamWarning, stacklevel=2)
    return BakeResult(mesh=out, atlas=atlas, coverage_mask=coverage,
                      texels_per_mm=float(texels_per_mm), timings=timings, warnings=messages,
                      uv_fill=float(coverage.mean()))


# ------------------------------------------------------------------------------------------------
# helpers


def _check_args(mesh, wood, texels_per_mm, max_atlas_px, padding_px, normals) -> None:
    faces = getattr(mesh, "faces", None)
    if faces is None or len(faces) == 0:
        raise WoodcamError(
            f"bake: mesh must be a trimesh.Trimesh with at least one triangle; got "
            f"{type(mesh).__name__} with {0 if faces is None else len(faces)} faces; pass the "
            "carved part's surface mesh"
        )
    if not callable(getattr(wood, "color", None)):
        raise WoodcamError(
            f"bake: wood must have a method color(points_mm, normals) -> rgb; got "
            f"{type(wood).__name__}; pass a woodcam.appearance.Wood or any object with .color"
        )
    if not (isinstance(texels_per_mm, (int, float)) and math.isfinite(texels_per_mm)
            and texels_per_mm > 0):
        raise WoodcamError(
            f"bake: texels_per_mm must be a finite number > 0; got {texels_per_mm!r}; "
            "use e.g. 10 (0.1 mm texels)"
        )
    if not isinstance(max_atlas_px, (int, np.integer)) or max_atlas_px < 64:
        raise WoodcamError(
            f"bake: max_atlas_px must be an integer >= 64; got {max_atlas_px!r}; use e.g. 4096"
        )
    if not isinstance(padding_px, (int, np.integer)) or padding_px < _MIN_PADDING_PX:
        raise WoodcamError(
            f"bake: padding_px must be an integer >= 2 (each chart needs its own 1-texel ring "
            f"for bilinear sampling, so charts must be 2 texels apart); got {padding_px!r}; use "
            f"e.g. {ATLAS_PADDING_PX}"
        )
    if normals not in get_args(NormalsMode):
        raise WoodcamError(
            f"bake: normals must be one of {get_args(NormalsMode)}; got {normals!r}"
        )


def _round_up(n: int, k: int) -> int:
    return int(-(-int(n) // k) * k)


def _unwrap(mesh, tpm: float, max_px: int, padding: int, messages: list[str]):
    """xatlas charts + packing into ONE atlas whose sides are <= ``max_px``.

    Returns ``vmap (m,) int``, ``faces (f, 3) int``, ``xy (m, 2) float64`` texel coordinates,
    atlas ``width``, ``height`` (texels) and the density used (texels / mm).
    """
    # The image side is later rounded up to a multiple of _ATLAS_SIZE_MULTIPLE: stay below.
    max_px = max_px // _ATLAS_SIZE_MULTIPLE * _ATLAS_SIZE_MULTIPLE
    verts = np.ascontiguousarray(mesh.vertices, dtype=np.float32)
    faces_in = np.ascontiguousarray(mesh.faces, dtype=np.uint32)
    area = float(mesh.area)
    asked = tpm
    # Predict the side from surface area and density; lower the density before unwrapping so a
    # huge request never makes xatlas allocate a huge packing bitmap.
    predicted = math.sqrt(area * tpm * tpm / _PACK_EFFICIENCY) + 2 * padding
    if predicted > max_px:
        tpm = tpm * (max_px - 2 * padding) / (predicted - 2 * padding) * 0.97
    chart_cap = _chart_area_cap(mesh)
    pieces = [np.arange(len(faces_in))]

    for _attempt in range(4):
        vmap, faces, uv, width, height, pieces = _layout_guarded(
            verts, faces_in, pieces, chart_cap, tpm, padding, messages)
        scale = max_px / max(width, height)
        if scale >= _MIN_RESCALE and scale * padding >= _MIN_PADDING_PX:
            break
        tpm *= (max_px - 2 * padding) / (max(width, height) - 2 * padding) * 0.97
    else:  # pragma: no cover - xatlas overshooting four times in a row
        raise WoodcamError(
            f"bake: could not fit the atlas into max_atlas_px={max_px} (last {width}x{height} at "
            f"{tpm:.3g} texels/mm); raise max_atlas_px or lower texels_per_mm"
        )
    # xatlas-python normalises by the atlas size; back to texel coordinates (float64).
    xy = np.asarray(uv, dtype=np.float64) * np.array([width, height], dtype=np.float64)
    if scale < 1.0:
        # A slight overshoot: shrink the packed layout instead of re-running xatlas (~1 s).
        xy *= scale
        width = min(max_px, math.ceil(width * scale))
        height = min(max_px, math.ceil(height * scale))
        tpm *= scale
    if tpm < asked:
        messages.append(
            f"bake: texels_per_mm lowered from {asked:g} to {tpm:.4g} (texel {1 / tpm:.3g} mm) "
            f"so the {area:.0f} mm^2 surface fits a {width}x{height} atlas within "
            f"max_atlas_px={max_px}; raise max_atlas_px for finer texels"
        )
    return vmap.astype(np.int64), faces.astype(np.int64), xy, width, height, float(tpm)


def _uv_fill(xy: np.ndarray, faces: np.ndarray, width: int, height: int) -> float:
    """Texel-space triangle area over the atlas area."""
    p = xy[faces]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    return float(0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]).sum() / (width * height))


def _chart_area_cap(mesh) -> float:
    """xatlas ``max_chart_area`` (mm^2, 0: none) for ``mesh``: :data:`_CHART_AREA_FRACTION`."""
    return float(_CHART_AREA_FRACTION * float(mesh.area))


def _split_pieces(verts: np.ndarray, faces: np.ndarray, n: int) -> list[np.ndarray]:
    """``n`` pieces of about equal face count, cut across the longest axis of the surface."""
    centres = verts[faces].mean(axis=1)
    axis = int(np.argmax(np.ptp(centres, axis=0)))
    return [np.sort(p) for p in np.array_split(np.argsort(centres[:, axis], kind="stable"), n)]


def _layout_guarded(verts, faces, pieces, chart_cap, tpm, padding, messages):
    """:func:`woodcam._xatlas_worker.layout` in a worker process. When xatlas dies natively
    (segfault), retry with the surface cut into 2, 4, 8 pieces (seams are invisible after the
    conservative rasterisation and dilation); if every try dies, one clear error."""
    import concurrent.futures as cf
    import multiprocessing as mp

    import woodcam._xatlas_worker as _xatlas_worker

    if _XATLAS_IN_PROCESS:  # pragma: no cover - debugging aid
        return (*_xatlas_worker.layout(verts, faces, pieces, max_chart_area=chart_cap,
                                       max_iterations=_CHART_ITERATIONS, texels_per_mm=tpm,
                                       padding=padding), pieces)
    # fork: the worker needs no fresh interpreter (spawn/forkserver re-import the caller's
    # __main__, which re-runs a user's script that has no ``if __name__ == "__main__"`` guard),
    # and it runs only xatlas' own threads and numpy, none of the parent's thread pools.
    context = mp.get_context("fork")
    tries = [pieces] + [_split_pieces(verts, faces, n) for n in (2, 4, 8) if n > len(pieces)]
    for attempt in tries:
        with cf.ProcessPoolExecutor(max_workers=1, mp_context=context) as pool:
            job = pool.submit(_xatlas_worker.run_layout, verts, faces, attempt,
                              max_chart_area=chart_cap, max_iterations=_CHART_ITERATIONS,
                              texels_per_mm=float(tpm), padding=int(padding))
            try:
                return (*job.result(), attempt)
            except cf.process.BrokenProcessPool:
                messages.append(
                    f"bake: xatlas crashed unwrapping the surface in {len(attempt)} piece(s); "
                    f"retried in {2 * len(attempt)} pieces")
            except RuntimeError as err:
                raise WoodcamError(f"bake: the UV unwrap failed ({err})") from err
    raise WoodcamError(
        f"bake: xatlas crashed (native fault) unwrapping this {len(faces)}-triangle surface, "
        f"also when cut into up to {len(tries[-1])} pieces; simplify or re-mesh the part "
        "(e.g. trimesh simplify_quadric_decimation, or a coarser --tolerance)"
    )


def _triangle_frames(xy: np.ndarray, faces: np.ndarray):
    """Per-triangle texel-space data: origin p0 (f, 2), inverse edge matrix (f, 2, 2), double
    signed area (f,), and validity (f,) bool (non-degenerate in UV)."""
    p = xy[faces]  # (f, 3, 2)
    e1 = p[:, 1] - p[:, 0]
    e2 = p[:, 2] - p[:, 0]
    det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    valid = np.abs(det) > 2.0 * MIN_UV_AREA_TEXELS2
    inv_det = np.where(valid, 1.0 / np.where(valid, det, 1.0), 0.0)
    # (l1, l2) = inv([e1 e2]) @ (x - p0)
    minv = np.empty((len(faces), 2, 2))
    minv[:, 0, 0] = e2[:, 1] * inv_det
    minv[:, 0, 1] = -e2[:, 0] * inv_det
    minv[:, 1, 0] = -e1[:, 1] * inv_det
    minv[:, 1, 1] = e1[:, 0] * inv_det
    return p, minv, det, valid


def _rasterise(xy: np.ndarray, faces: np.ndarray, width: int, height: int, *,
               progress: bool = False) -> np.ndarray:
    """Conservative rasterisation of all triangles in texel space.

    Parameters
    ----------
    xy : (m, 2) float64
        Vertex texel coordinates (x right, y down; texel (r, c) centre at (c + .5, r + .5)).
    faces : (f, 3) int
    width, height : int
        Atlas size in texels.

    Returns
    -------
    (height * width,) int64
        Triangle painting each texel (row-major), -1 where none. A texel whose centre is inside
        (or on the edge of) a triangle takes that triangle; otherwise, if its centre is within
        L-infinity distance 1 of some triangles (the bilinear footprint: the Minkowski sum of the
        triangle and the square [-1, 1]^2, i.e. each edge pushed out by |n_x| + |n_y| plus the
        bounding box grown by 1), the one with the smallest outward edge distance.

    Notes
    -----
    Small compact triangles (bounding box <= ``_SMALL_BBOX`` texels both ways and at least
    ``_SMALL_MIN_FILL`` of it covered) are grouped by bounding-box size, so each group is one
    broadcast array ``(triangles, 3 edges, rows, cols)``. The others (big faces, long slivers of
    CAD triangle fans, whose bounding box is mostly empty) are cut into
    ``_TILE x _TILE`` tiles; tiles the expanded triangle cannot reach are culled with the same
    edge test at the tile centre widened by the tile's half-extent, and the rest are tested as
    one group of equal-size blocks. No per-texel Python loop. The edge tests run in float32
    (texel coordinates <= 2^13 keep ~1e-3 texel precision, inside ``RASTER_MARGIN_TEXELS``);
    the owners' points are recomputed in float64.
    """
    p, minv, det, valid = _triangle_frames(xy, faces)
    # Edge opposite vertex i runs p[(i+1)%3] -> p[(i+2)%3]. Height of vertex i over it, and the
    # support of the square [-reach, reach]^2 along its unit normal (reach (|n_x| + |n_y|)).
    edges = np.stack([p[:, 2] - p[:, 1], p[:, 0] - p[:, 2], p[:, 1] - p[:, 0]], axis=1)
    lengths = np.maximum(np.linalg.norm(edges, axis=2), 1e-300)  # (f, 3)
    heights = np.abs(det)[:, None] / lengths
    support = (np.abs(edges[..., 0]) + np.abs(edges[..., 1])) / lengths

    reach = 1.0 + RASTER_MARGIN_TEXELS  # footprint half-width, texels
    lo = p.min(axis=1)
    hi = p.max(axis=1)
    c0 = np.clip(np.ceil(lo[:, 0] - 0.5 - reach), 0, width - 1).astype(np.int64)
    c1 = np.clip(np.floor(hi[:, 0] - 0.5 + reach), 0, width - 1).astype(np.int64)
    r0 = np.clip(np.ceil(lo[:, 1] - 0.5 - reach), 0, height - 1).astype(np.int64)
    r1 = np.clip(np.floor(hi[:, 1] - 0.5 + reach), 0, height - 1).astype(np.int64)
    bw = c1 - c0 + 1
    bh = r1 - r0 + 1

    # Outward edge distance o_i = -l_i * h_i is affine in the texel centre; write it relative to
    # the centre of the bbox's first texel: o_i = base_i + gx_i * j_col + gy_i * j_row.
    grad_l1 = minv[:, 0, :]
    grad_l2 = minv[:, 1, :]
    grad_l = np.stack([-(grad_l1 + grad_l2), grad_l1, grad_l2], axis=1)  # (f, 3 edges, 2)
    d0 = np.column_stack([c0 + 0.5 - p[:, 0, 0], r0 + 0.5 - p[:, 0, 1]])
    l_first = np.column_stack([np.zeros(len(faces)), (minv @ d0[:, :, None])[:, :, 0]])
    l_first[:, 0] = 1.0 - l_first[:, 1] - l_first[:, 2]
    base = (-l_first * heights).astype(np.float32)  # (f, 3)
    gx = (-grad_l[..., 0] * heights).astype(np.float32)
    gy = (-grad_l[..., 1] * heights).astype(np.float32)
    sup = (support * reach).astype(np.float32)

    state = _RasterState(owner=np.full(height * width, -1, dtype=np.int64), width=width)

    # -- small triangles: one broadcast block per bounding-box size ------------------------------
    fill = 0.5 * np.abs(det) / (bw * bh)  # triangle area / bounding-box area
    is_small = valid & (bw <= _SMALL_BBOX) & (bh <= _SMALL_BBOX) & (fill >= _SMALL_MIN_FILL)
    small = np.flatnonzero(is_small)
    key = bw[small] * (_SMALL_BBOX + 1) + bh[small]
    order = np.argsort(key, kind="stable")
    cuts = np.flatnonzero(np.diff(key[order])) + 1
    groups = np.split(small[order], cuts) if len(small) else []
    # -- large triangles: (triangle, tile) pairs that survive culling ----------------------------
    large = np.flatnonzero(valid & ~is_small)
    tiles = _cull_tiles(large, bw, bh, base, gx, gy, sup)

    work = [("group", g) for g in groups] + [("tiles", tiles)] if len(tiles[0]) else \
        [("group", g) for g in groups]
    if progress:
        from tqdm import tqdm

        work = tqdm(work, desc="rasterise", unit="block")
    for kind, item in work:
        if kind == "group":
            tri = item
            gw, gh = int(bw[tri[0]]), int(bh[tri[0]])
            _test_blocks(state, tri, r0[tri], c0[tri], base[tri], gx[tri], gy[tri], sup[tri],
                         gh, gw, None, None)
        else:
            tri, ty, tx = item
            off_r = ty * _TILE
            off_c = tx * _TILE
            tile_base = base[tri] + gx[tri] * off_c[:, None] + gy[tri] * off_r[:, None]
            _test_blocks(state, tri, r0[tri] + off_r, c0[tri] + off_c, tile_base, gx[tri],
                         gy[tri], sup[tri], _TILE, _TILE, r1[tri], c1[tri])
    return state.finish()


class _RasterState:
    """Owner image being filled plus the border (ring) candidates collected so far."""

    def __init__(self, owner: np.ndarray, width: int):
        self.owner = owner
        self.width = width
        self.border_idx: list[np.ndarray] = []
        self.border_tri: list[np.ndarray] = []
        self.border_out: list[np.ndarray] = []

    def finish(self) -> np.ndarray:
        """Give each unowned texel with ring candidates the nearest candidate triangle."""
        owner = self.owner
        if self.border_idx:
            bidx = np.concatenate(self.border_idx)
            btri = np.concatenate(self.border_tri)
            bout = np.concatenate(self.border_out)
            keep = owner[bidx] < 0
            bidx, btri, bout = bidx[keep], btri[keep], bout[keep]
            if len(bidx):
                order = np.lexsort((bout, bidx))  # by texel, then nearest triangle first
                bidx, btri = bidx[order], btri[order]
                first = np.ones(len(bidx), dtype=bool)
                first[1:] = bidx[1:] != bidx[:-1]
                owner[bidx[first]] = btri[first]
        return owner


def _cull_tiles(large, bw, bh, base, gx, gy, sup):
    """(triangle, tile row, tile col) of the ``_TILE``-square tiles of each large triangle's
    bounding box that its footprint can reach: min over the tile of every outward edge distance
    (centre value minus |gx| + |gy| times the half-extent) is within the edge's support."""
    ntx = -(-bw[large] // _TILE)
    nty = -(-bh[large] // _TILE)
    n = ntx * nty
    if len(large) == 0 or n.sum() == 0:
        empty = np.zeros(0, dtype=np.int64)
        return empty, empty, empty
    tri = np.repeat(large, n)
    k = np.arange(int(n.sum()), dtype=np.int64) - np.repeat(np.cumsum(n) - n, n)
    w = np.repeat(ntx, n)
    tx = k % w
    ty = k // w
    half = (_TILE - 1) / 2.0
    centre = (base[tri] + gx[tri] * (tx * _TILE + half)[:, None]
              + gy[tri] * (ty * _TILE + half)[:, None])
    extent = (np.abs(gx[tri]) + np.abs(gy[tri])) * half
    keep = np.all(centre - extent <= sup[tri] + 1e-4, axis=1)
    return tri[keep], ty[keep], tx[keep]


def _test_blocks(state, tri, row0, col0, base, gx, gy, sup, gh, gw, row_max, col_max):
    """Edge-test blocks of ``gh x gw`` texels starting at (row0, col0) for triangles ``tri``
    (all (g,) / (g, 3) arrays), in chunks of about ``_RASTER_CHUNK_PAIRS`` texels; record inside
    owners in ``state.owner`` and ring candidates in ``state``. ``row_max``/``col_max`` (g,)
    clip blocks that run past the triangle's expanded bounding box (tiles), or None."""
    per_chunk = max(1, _RASTER_CHUNK_PAIRS // (gw * gh))
    jx = np.arange(gw, dtype=np.float32)[None, None, None, :]
    jy = np.arange(gh, dtype=np.float32)[None, None, :, None]
    ix = np.arange(gw)[None, None, :]
    iy = np.arange(gh)[None, :, None]
    width = state.width
    for s in range(0, len(tri), per_chunk):
        sl = slice(s, s + per_chunk)
        t = tri[sl]
        o = (base[sl][:, :, None, None] + gx[sl][:, :, None, None] * jx
             + gy[sl][:, :, None, None] * jy)  # (g, 3, gh, gw)
        out = o.max(axis=1)  # (g, gh, gw)
        ok = np.all(o <= sup[sl][:, :, None, None], axis=1)
        if row_max is not None:
            ok &= (row0[sl][:, None, None] + iy <= row_max[sl][:, None, None])
            ok &= (col0[sl][:, None, None] + ix <= col_max[sl][:, None, None])
        inside = ok & (out <= 1e-6)
        ring = ok & ~inside
        g, yy, xx = np.nonzero(inside)
        state.owner[(row0[sl][g] + yy) * width + col0[sl][g] + xx] = t[g]
        g, yy, xx = np.nonzero(ring)
        state.border_idx.append((row0[sl][g] + yy) * width + col0[sl][g] + xx)
        state.border_tri.append(t[g])
        state.border_out.append(out[g, yy, xx])


def _affine_maps(xy, faces, values):
    """Per-triangle affine maps from texel coordinates to per-vertex ``values (m, d)``:
    ``value(x, y) = origin + jac_x * x + jac_y * y`` (barycentric interpolation inside the
    triangle, linear extrapolation of the same map outside it). Returns three (f, d) arrays, so
    each texel later costs three gathers instead of a (k, 3, d) corner array."""
    p, minv, _, _ = _triangle_frames(xy, faces)
    v = values[faces]  # (f, 3, d)
    e1 = v[:, 1] - v[:, 0]
    e2 = v[:, 2] - v[:, 0]
    jac_x = e1 * minv[:, 0, 0, None] + e2 * minv[:, 1, 0, None]
    jac_y = e1 * minv[:, 0, 1, None] + e2 * minv[:, 1, 1, None]
    origin = v[:, 0] - jac_x * p[:, 0, 0, None] - jac_y * p[:, 0, 1, None]
    return origin, jac_x, jac_y


def _apply_affine(maps, tri, cx, cy) -> np.ndarray:
    """Evaluate :func:`_affine_maps` of triangles ``tri (k,)`` at texel centres
    ``cx, cy (k, 1)``; (k, d) float64."""
    origin, jac_x, jac_y = maps
    return origin[tri] + jac_x[tri] * cx + jac_y[tri] * cy


def _dilate(atlas: np.ndarray, coverage: np.ndarray) -> np.ndarray:
    """Fill every unpainted texel with the colour of its nearest painted texel (exact EDT).

    Filling the whole atlas (not just ``padding_px`` rings) costs the same with a distance
    transform and guarantees that no mip level averages in black.
    """
    if coverage.all() or not coverage.any():
        return atlas
    from scipy.ndimage import distance_transform_edt

    rows, cols = distance_transform_edt(~coverage, return_distances=False, return_indices=True)
    return atlas[rows, cols]


def _textured_mesh(trimesh, verts, faces, uv, atlas):
    from PIL import Image

    material = trimesh.visual.material.PBRMaterial(
        name="wood",
        baseColorTexture=Image.fromarray(atlas),
        metallicFactor=0.0,  # wood is a dielectric
        roughnessFactor=0.8,  # unfinished / satin wood; a viewer-side choice, not measured
    )
    visual = trimesh.visual.TextureVisuals(uv=uv, material=material)
    return trimesh.Trimesh(vertices=verts, faces=faces, visual=visual, process=False)
