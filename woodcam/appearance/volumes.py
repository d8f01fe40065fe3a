"""Colour volumes: per-axis translation networks run over axis-aligned slices (seed 000, 3.3.1).

A :class:`VolumeGrid` covers the block ``[0, W] x [0, D] x [0, H]`` with ``shape = (nx, ny, nz)``
cells of (nearly) equal size, ``resolution`` cells along the longest side; samples sit on
cell centres ``((i + 0.5) W / nx, ...)``. A colour volume is ``(nx, ny, nz, 3)`` uint8 sRGB.
:class:`ColorVolumes` holds three of them (``RGB_YZ``, ``RGB_ZX``, ``RGB_XY``: the colour
of surfaces normal to X, Y, Z, the order of eq. 10's weights in
:func:`~woodcam.appearance.orientation.axis_weights`) or one (orientation-agnostic).

Canonical images
----------------
A network for axis ``k`` always sees images in one orientation, whichever face or slice they
come from: for in-plane axes ``(a, b)`` = (Y, Z) for X, (X, Z) for Y, (X, Y) for Z, image rows run
along ``b`` descending and columns along ``a`` ascending (the right, front and top faces as
photographed; left, back and bottom photos are mirrored into it). Face photos are resampled
to the grid's cell size, so a network trained on faces sees slices at the scale it learnt.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

import numba
import numpy as np

from ..errors import WoodcamError
from ..fields.base import arf, check_points, evaluate
from ..fields.rings import MOKUME_RING_SIGMA_MM, ring_map
from ..frames import FACE_AXIS, FACE_NORMAL, block_to_pixel, check_size
from .noise import value_noise

#: In-plane axes (a, b) of the canonical image of each block axis.
PLANE_AXES: dict[int, tuple[int, int]] = {0: (1, 2), 1: (0, 2), 2: (0, 1)}

#: Width (mm) of the ring lines of Mokume's U-Net ring maps, for ring-map-like images of a field.
RING_MAP_SIGMA_MM = MOKUME_RING_SIGMA_MM

#: Largest allowed volume resolution (cells along the longest side): 256^3 x 3 x 3 bytes = 150 MB.
MAX_RESOLUTION = 256


@dataclass(frozen=True)
class VolumeGrid:
    """Cell-centred grid over the block (see module docstring).

    Attributes
    ----------
    size_mm : (W, D, H)
    resolution : int
        Cells along the longest block side.
    """

    size_mm: tuple[float, float, float]
    resolution: int = 128

    def __post_init__(self):
        object.__setattr__(self, "size_mm", tuple(float(s) for s in check_size(self.size_mm)))
        if not 4 <= int(self.resolution) <= MAX_RESOLUTION:
            raise WoodcamError(
                f"resolution must be an integer in [4, {MAX_RESOLUTION}] cells along the longest "
                f"side; got {self.resolution!r}"
            )
        object.__setattr__(self, "resolution", int(self.resolution))

    @property
    def shape(self) -> tuple[int, int, int]:
        cell = max(self.size_mm) / self.resolution
        return tuple(max(2, int(round(s / cell))) for s in self.size_mm)

    @property
    def cell_mm(self) -> np.ndarray:
        """Cell size ``(3,)`` mm along X, Y, Z."""
        return np.asarray(self.size_mm) / np.asarray(self.shape)

    def centres(self, axis: int) -> np.ndarray:
        """Cell-centre coordinates (mm) along block axis ``axis``."""
        return (np.arange(self.shape[axis]) + 0.5) * self.cell_mm[axis]

    def points(self) -> np.ndarray:
        """All cell centres, ``(nx, ny, nz, 3)`` float32 mm."""
        x, y, z = np.meshgrid(*(self.centres(k).astype(np.float32) for k in range(3)), indexing="ij")
        return np.stack([x, y, z], axis=-1)

    def image_shape(self, axis: int) -> tuple[int, int]:
        """Canonical image shape ``(rows, cols)`` of a slice normal to ``axis``."""
        a, b = PLANE_AXES[axis]
        return self.shape[b], self.shape[a]

    def face_points(self, face: str) -> np.ndarray:
        """Block points ``(rows, cols, 3)`` mm of the canonical image of ``face`` on its plane."""
        k = FACE_AXIS[face]
        a, b = PLANE_AXES[k]
        pa = self.centres(a)
        pb = self.centres(b)[::-1]
        out = np.empty((len(pb), len(pa), 3))
        out[..., a] = pa[None, :]
        out[..., b] = pb[:, None]
        out[..., k] = 0.0 if sum(FACE_NORMAL[face]) < 0 else self.size_mm[k]
        return out

    def to_images(self, vol: np.ndarray, axis: int) -> np.ndarray:
        """Slices of ``vol (nx, ny, nz, ...)`` normal to ``axis`` as canonical images
        ``(n_axis, rows, cols, ...)`` (a view)."""
        a, b = PLANE_AXES[axis]
        v = np.moveaxis(vol, (axis, b, a), (0, 1, 2))
        return v[:, ::-1]

    def from_images(self, images: np.ndarray, axis: int) -> np.ndarray:
        """Inverse of :meth:`to_images`: ``(n_axis, rows, cols, ...)`` -> ``(nx, ny, nz, ...)``."""
        a, b = PLANE_AXES[axis]
        return np.moveaxis(images[:, ::-1], (0, 1, 2), (axis, b, a))

    def to_dict(self) -> dict:
        return {"size_mm": list(self.size_mm), "resolution": self.resolution}


# -- input channels ----------------------------------------------------------------------------------

def ring_map_like(years_img: np.ndarray, cell_mm: float, sigma_mm: float = RING_MAP_SIGMA_MM) -> np.ndarray:
    """Mokume-style ring map of growth-time images ``(..., h, w)`` on cells of ``cell_mm``:
    :func:`woodcam.fields.rings.ring_map` with the line width in mm."""
    return ring_map(years_img, sigma_mm, cell_mm)


def input_channels(ring: np.ndarray, points_mm: np.ndarray | None, spec) -> np.ndarray:
    """Stack network inputs ``(..., c, h, w)`` from ring images ``(..., h, w)`` and the images'
    block points ``(..., h, w, 3)`` (for the solid-noise channel when ``spec.noise``)."""
    ring = np.asarray(ring, np.float32)
    chans = [ring]
    if spec.noise:
        if points_mm is None:
            raise WoodcamError("points_mm are needed for the noise channel (spec.noise=True)")
        q = np.asarray(points_mm, np.float32).reshape(-1, 3) / np.float32(spec.noise_mm)
        chans.append(value_noise(q, spec.seed + 7).reshape(ring.shape))
    return np.stack(chans, axis=-3)


def _resample(image: np.ndarray, face: str, face_shape, size_mm, points: np.ndarray, cell_mm: float):
    """Bilinear samples of a face image ``(rows, cols[, ch])`` at block ``points (h, w, 3)``,
    low-passed first when the grid is coarser than the image (no aliasing of fine grain)."""
    from scipy import ndimage

    img = np.asarray(image, np.float32)
    rows, cols = block_to_pixel(face, points, face_shape, size_mm)
    px_mm = max(size_mm[i] for i in range(3) if i != FACE_AXIS[face]) / max(face_shape)
    sigma = 0.5 * max(0.0, cell_mm / px_mm - 1.0)
    chans = img[..., None] if img.ndim == 2 else img
    out = np.empty(points.shape[:2] + (chans.shape[2],), np.float32)
    for c in range(chans.shape[2]):
        ch = ndimage.gaussian_filter(chans[..., c], sigma) if sigma > 0.05 else chans[..., c]
        out[..., c] = ndimage.map_coordinates(ch, [rows, cols], order=1, mode="nearest")
    return out[..., 0] if img.ndim == 2 else out


def face_pair(block, face: str, grid: VolumeGrid, spec, field=None, source="arf"):
    """One training pair of ``face``: ``(inputs (c, h, w), photo (h, w, 3), mask (h, w))``.

    ``source="arf"`` takes the ring channel from ``field`` (eq. 6 ARF at the face's grid
    points); ``"ring_map"`` resamples the face's own ring map, which lies exactly on the photo's
    rings even where a fitted field is off (a face without one gets :func:`ring_map_like` of
    ``field``). Photos are resampled to the grid's cell size.
    """
    f = block.faces[face]
    pts = grid.face_points(face)
    cell = float(grid.cell_mm[list(PLANE_AXES[FACE_AXIS[face]])].mean())
    if source not in ("arf", "ring_map"):
        raise WoodcamError(f"source must be 'arf' or 'ring_map'; got {source!r}")
    if source == "ring_map" and f.ring_map is not None:
        ring = _resample(f.ring_map, face, f.shape, block.size_mm, pts, cell)
    elif field is None:
        raise WoodcamError(
            f"face {face!r} needs a field for source={source!r}"
            + (" (it has no ring map)" if source == "ring_map" else "")
            + "; pass field= or use source='ring_map' on faces with ring maps"
        )
    else:
        g = evaluate(field, pts.reshape(-1, 3)).reshape(pts.shape[:2])
        ring = arf(g) if source == "arf" else ring_map_like(g, cell)
    x = input_channels(ring, pts, spec)
    photo = None
    if f.photo is not None:
        photo = _resample(f.photo.astype(np.float32) / 255.0, face, f.shape, block.size_mm, pts, cell)
    # Every pixel is learnt from, knots included: the ARF / ring map carries their distortion.
    mask = np.ones(ring.shape, bool)
    return x, photo, mask


# -- the volumes -------------------------------------------------------------------------------------

@dataclass
class ColorVolumes:
    """Three (or one) uint8 colour volumes on one grid, with optional sub-cell detail.

    Attributes
    ----------
    grid : VolumeGrid
    volumes : (k, nx, ny, nz, 3) uint8, k = 3 (RGB_YZ, RGB_ZX, RGB_XY) or 1 (agnostic)
    meta : dict
        Settings, timings and the cache key.
    guides : (k, nx, ny, nz) float32 or None (float16 on disk)
        The networks' ring input at the cell centres (the ARF, or the ring-map-like image of
        each slice): the guide of the sub-cell detail.
    slopes : (k, nx, ny, nz, 3) float32 or None (float16 on disk)
        Local slope of colour over guide (:func:`guide_slopes`). With both, :meth:`sample`
        adds ``slope * (guide at the point - interpolated guide)``: the volume gives the colour
        of the cells, the field's exact rings at the point the detail inside them.
    """

    grid: VolumeGrid
    volumes: np.ndarray
    meta: dict
    guides: np.ndarray | None = None
    slopes: np.ndarray | None = None

    def __post_init__(self):
        v = np.asarray(self.volumes)
        if v.dtype != np.uint8 or v.ndim != 5 or v.shape[0] not in (1, 3) or v.shape[1:] != self.grid.shape + (3,):
            raise WoodcamError(
                f"volumes must be uint8 of shape (1 or 3, {', '.join(map(str, self.grid.shape))}, 3); "
                f"got {v.dtype} {v.shape}"
            )
        self.volumes = v
        if (self.guides is None) != (self.slopes is None):
            raise WoodcamError("guides and slopes must be given together (or neither) for sub-cell detail")
        if self.guides is not None:
            # float32 in memory: numpy's float16 arithmetic is emulated and made lookups ~3x slower.
            self.guides = np.asarray(self.guides, np.float32)
            self.slopes = np.asarray(self.slopes, np.float32)
            if self.guides.shape != v.shape[:4] or self.slopes.shape != v.shape:
                raise WoodcamError(
                    f"guides must have shape {v.shape[:4]} and slopes {v.shape}; got "
                    f"{self.guides.shape} and {self.slopes.shape}"
                )

    @property
    def has_detail(self) -> bool:
        return self.guides is not None

    def sample(self, points_mm, index: int, guide=None) -> np.ndarray:
        """Trilinear colour ``(n, 3)`` float32 in [0, 1] of volume ``index`` at ``points_mm``.

        Points outside the cell centres clamp to the border cells (a face lies half a cell
        outside the outermost centres). With ``guide (n,)`` (the networks' ring input at the
        points themselves) and sub-cell detail stored, the detail is added (:meth:`_detailed`).
        """
        p = check_points(points_mm)
        corners = self._corners(p)
        if guide is None or not self.has_detail:
            return _trilinear(self.volumes[index], corners) * np.float32(1.0 / 255.0)
        return self._detailed(index, corners, np.asarray(guide, np.float32))

    def _detailed(self, index: int, corners, guide: np.ndarray) -> np.ndarray:
        """Guided-filter upsampling (He et al. 2013): the trilinear colour plus the trilinear
        slope times the difference between the point's own guide and the trilinear guide, so a
        ring boundary falls exactly where the field puts it instead of being smeared over a
        cell. (A joint-bilateral variant that drops corners across a boundary scored a little
        better on synthetic profiles but showed cell-sized kinks in latewood bands on bevels.)"""
        idx, w = corners
        out = np.empty((len(guide), 3), np.float32)
        _detailed_kernel(idx, w, self.volumes[index].reshape(-1, 3), self.guides[index].reshape(-1),
                         self.slopes[index].reshape(-1, 3), np.ascontiguousarray(guide, np.float32), out)
        return out

    def _corners(self, p):
        """Flat cell indices ``(8, n)`` of the 8 corners around each point and their trilinear
        weights ``(8, n)`` float32, shared by every volume of the grid."""
        shape = np.asarray(self.grid.shape)
        t = p / self.grid.cell_mm - 0.5
        t = np.clip(t, 0.0, shape - 1.0)
        i0 = np.minimum(t.astype(np.int64), shape - 2)
        f = (t - i0).astype(np.float32)
        base = (i0[:, 0] * shape[1] + i0[:, 1]) * shape[2] + i0[:, 2]
        idx = np.empty((8, len(p)), np.int64)
        w = np.empty((8, len(p)), np.float32)
        k = 0
        for dx in (0, 1):
            wx = f[:, 0] if dx else 1 - f[:, 0]
            for dy in (0, 1):
                wy = f[:, 1] if dy else 1 - f[:, 1]
                for dz in (0, 1):
                    wz = f[:, 2] if dz else 1 - f[:, 2]
                    idx[k] = base + (dx * shape[1] + dy) * shape[2] + dz
                    w[k] = wx * wy * wz
                    k += 1
        return idx, w

    def save(self, path) -> Path:
        from .._atomic import atomic_write

        path = Path(path)
        extra = {} if not self.has_detail else {"guides": self.guides.astype(np.float16),
                                                 "slopes": self.slopes.astype(np.float16)}
        # unique temporary + rename: a reader never sees half a file, two writers never mix;
        # an open file, so np.savez writes at ``path`` whatever its suffix (given a path not
        # ending in .npz it wrote ``<path>.npz``)
        with atomic_write(path, "wb", mkdir=True) as fh:
            np.savez(fh, volumes=self.volumes, grid=json.dumps(self.grid.to_dict()),
                     meta=json.dumps(self.meta), **extra)
        return path

    @classmethod
    def load(cls, path) -> "ColorVolumes":
        # our own handle: np.load leaks it when the zip is truncated
        with open(path, "rb") as fh, np.load(fh, allow_pickle=False) as z:
            g = json.loads(str(z["grid"]))
            detail = {k: z[k] for k in ("guides", "slopes") if k in z.files}
            return cls(VolumeGrid(tuple(g["size_mm"]), g["resolution"]), z["volumes"],
                       json.loads(str(z["meta"])), **detail)


def _trilinear(vol: np.ndarray, corners) -> np.ndarray:
    """Trilinear samples ``(n, c)`` float32 of ``vol (nx, ny, nz, c)`` (any dtype) at the
    corners of :meth:`ColorVolumes._corners`."""
    idx, w = corners
    flat = vol.reshape(-1, vol.shape[-1])
    out = np.zeros((idx.shape[1], vol.shape[-1]), np.float32)
    # Hand-written rather than scipy.ndimage.map_coordinates: one gather per corner for all
    # channels of a uint8 / float32 volume, without converting the volume to float; the corner
    # indices are computed once per lookup and shared by colour, guide and slopes.
    for k in range(8):
        out += w[k][:, None] * flat[idx[k]]
    return out


@numba.njit(nogil=True, fastmath=True, cache=True)
def _detailed_kernel(idx, w, vol, guides, slopes, guide, out):  # pragma: no cover - compiled
    """Per point, the detailed lookup of :meth:`ColorVolumes._detailed` in one compiled pass
    (in numpy, gathering the 8 corners of three arrays made it 2-3x slower than trilinear).

    idx, w : (8, n) flat corner indices and trilinear weights; vol : (m, 3) uint8;
    guides : (m,) float32; slopes : (m, 3) float32; guide : (n,) float32; out : (n, 3) float32.
    """
    for i in range(guide.shape[0]):
        c0 = 0.0
        c1 = 0.0
        c2 = 0.0
        s0 = 0.0
        s1 = 0.0
        s2 = 0.0
        g = 0.0
        for k in range(8):
            j = idx[k, i]
            wk = w[k, i]
            c0 += wk * vol[j, 0]
            c1 += wk * vol[j, 1]
            c2 += wk * vol[j, 2]
            s0 += wk * slopes[j, 0]
            s1 += wk * slopes[j, 1]
            s2 += wk * slopes[j, 2]
            g += wk * guides[j]
        d = guide[i] - g
        out[i, 0] = min(max(c0 * (1.0 / 255.0) + s0 * d, 0.0), 1.0)
        out[i, 1] = min(max(c1 * (1.0 / 255.0) + s1 * d, 0.0), 1.0)
        out[i, 2] = min(max(c2 * (1.0 / 255.0) + s2 * d, 0.0), 1.0)


#: Half-width (cells) of the window of the colour-over-guide regression of :func:`guide_slopes`.
DETAIL_RADIUS_CELLS = 1

#: Regulariser (guide units squared) of that regression: where the guide hardly varies within
#: the window (variance below ~1e-3, i.e. no ring edge and a ring wider than ~20 cells) the slope
#: fades to 0, so flat wood gets no detail from noise.
DETAIL_EPS = 1e-3


def guide_slopes(colour: np.ndarray, guide: np.ndarray, radius: int = DETAIL_RADIUS_CELLS,
                 eps: float = DETAIL_EPS) -> np.ndarray:
    """Local linear regression of colour on the guide, the guided filter of He et al. (2013):
    per cell, ``cov(guide, colour) / (var(guide) + eps)`` over the ``(2 radius + 1)^3`` cells
    around it, box-averaged once more (the filter's mean of coefficients).

    Parameters
    ----------
    colour : (nx, ny, nz, 3) uint8 or float in [0, 1] (uint8 is divided by 255)
    guide : (nx, ny, nz) float

    Returns
    -------
    (nx, ny, nz, 3) float32, colour units per guide unit.
    """
    from scipy import ndimage

    size = 2 * int(radius) + 1
    c = np.asarray(colour, np.float32)
    if np.asarray(colour).dtype == np.uint8:
        c = c / np.float32(255.0)
    g = np.asarray(guide, np.float32)

    def box(a):
        return ndimage.uniform_filter(a, size, mode="nearest")

    mg = box(g)
    var = box(g * g) - mg * mg
    out = np.empty(c.shape, np.float32)
    for k in range(c.shape[-1]):
        ck = c[..., k]
        out[..., k] = box((box(g * ck) - mg * box(ck)) / (np.maximum(var, 0.0) + np.float32(eps)))
    return out


def years_volume(field, grid: VolumeGrid) -> np.ndarray:
    """Growth time at every cell centre, ``(nx, ny, nz)`` float64 (evaluated in batches)."""
    pts = grid.points()
    return evaluate(field, pts.reshape(-1, 3)).reshape(grid.shape)


def translate_volume(net, years: np.ndarray, grid: VolumeGrid, axis: int, source: str = "arf",
                     chunk: int = 16, return_guide: bool = False):
    """Run ``net`` over every slice normal to ``axis`` -> ``(nx, ny, nz, 3)`` uint8.

    ``years`` is the growth-time volume of :func:`years_volume`; the ring channel is its ARF
    (``source="arf"``) or a ring-map-like image of each slice (``"ring_map"``). With
    ``return_guide``, also that ring channel as a volume ``(nx, ny, nz)`` float16.
    """
    g_img = grid.to_images(years, axis)
    p_img = grid.to_images(grid.points(), axis)
    cell = float(grid.cell_mm[list(PLANE_AXES[axis])].mean())
    out = np.empty(g_img.shape + (3,), np.uint8)
    guide = np.empty(g_img.shape, np.float16) if return_guide else None
    for i in range(0, len(g_img), chunk):
        g = g_img[i:i + chunk]
        ring = arf(g) if source == "arf" else ring_map_like(g, cell)
        if return_guide:
            guide[i:i + chunk] = ring
        x = input_channels(ring, p_img[i:i + chunk], net.spec)
        out[i:i + chunk] = np.clip(net(x) * 255.0 + 0.5, 0, 255).astype(np.uint8)
    vol = np.ascontiguousarray(grid.from_images(out, axis))
    if return_guide:
        return vol, np.ascontiguousarray(grid.from_images(guide, axis))
    return vol


def point_guide(field, points_mm: np.ndarray, axis: int, source: str, cell_mm: float,
                years: np.ndarray | None = None) -> np.ndarray:
    """The networks' ring input at exact points ``(n,)``: the ARF of ``field`` there
    (``source="arf"``), or the ring-map-like value of :func:`ring_map_like` with the growth-time
    gradient in the plane normal to ``axis`` (central differences of a tenth of a cell), as on
    the slices the volume of that axis was made from."""
    p = check_points(points_mm)
    g = evaluate(field, p) if years is None else np.asarray(years, np.float64)
    if source == "arf":
        return arf(g).astype(np.float32)
    h = 0.1 * cell_mm
    grad2 = np.zeros(len(p))
    for a in PLANE_AXES[axis]:
        d = np.zeros(3)
        d[a] = h
        grad2 += ((evaluate(field, p + d) - evaluate(field, p - d)) / (2 * h)) ** 2
    dist = np.abs(g - np.round(g)) / np.maximum(np.sqrt(grad2), 1e-9)
    return np.exp(-((dist / RING_MAP_SIGMA_MM) ** 2)).astype(np.float32)


# -- cache keys ----------------------------------------------------------------------------------------

def field_fingerprint(field, size_mm, n: int = 2048) -> str:
    """A digest of any field callable: its growth time at fixed pseudo-random block points
    (rounded to 1e-6 years), so two fields that agree there share cached volumes."""
    pts = np.random.default_rng(918273).uniform(0, 1, (n, 3)) * np.asarray(check_size(size_mm))
    g = np.round(evaluate(field, pts), 6)
    return hashlib.sha256(g.astype("<f8").tobytes()).hexdigest()


def block_fingerprint(block) -> str:
    """A digest of everything a block's faces hold: its size, and per face the photo, ring map,
    ring traces (points, years and ring ids: pieces sharing an id are one ring to the fitter)
    and extras (knot masks, annotations), so any edit that could change a fit or an appearance
    changes the digest."""
    from .._cache import digest

    faces = []
    for name, f in block.faces.items():
        traces = [(t.points_px, -1 if t.year is None else int(t.year), -1 if t.ring is None else int(t.ring))
                  for t in f.traces]
        extras = {k: (v if isinstance(v, np.ndarray) else json.dumps(v, sort_keys=True, default=str))
                  for k, v in f.extras.items()}
        faces.append((name, list(f.shape), f.photo, f.ring_map, traces, extras))
    return digest(np.asarray(block.size_mm, "<f8"), faces, length=64)


def cache_key(block, field, settings: dict) -> str:
    """Key of a block's colour volumes: block images, field and settings."""
    doc = json.dumps({"block": block_fingerprint(block), "field": field_fingerprint(field, block.size_mm),
                      "settings": settings}, sort_keys=True)
    return hashlib.sha256(doc.encode()).hexdigest()[:20]
