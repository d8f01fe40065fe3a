"""Bark on a grown surface: texture coordinates carried from the input, a solid bark, cracks.

An input with its own UVs keeps its picture: each grown vertex gets the UV of where it came
from on the input surface (:func:`woodcam.woodify.surfaces.trace_back`), so the image stays put
while the object grows (seed Fig. 4.6). An untextured input gets procedural bark,
:class:`SolidBark`, a solid texture round the stem axis baked into an atlas of even texel density
(:func:`woodcam.bake.bake`). Cracks are drawn either into such an atlas along their edges
(``"material"``, :func:`paint_crack_faces`; an input's own picture is moved into one first, no
coarser than it was, :func:`picture_density`) or cut into the geometry (``"groove"``,
:func:`groove`).
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from scipy import ndimage

from .._checks import check_number, check_vector

CrackRender = Literal["groove", "material"]
CRACK_RENDERS: tuple[str, ...] = ("groove", "material")


def stem_axis(mesh) -> np.ndarray:
    """Unit direction ``(3,)`` of a mesh's longest principal axis (area-weighted surface PCA):
    the stem of a trunk-like input, along which the bark's plates and the fibres run."""
    c = mesh.triangles_center
    w = mesh.area_faces
    mu = (c * w[:, None]).sum(0) / w.sum()
    d = c - mu
    cov = (d * w[:, None]).T @ d / w.sum()
    _, V = np.linalg.eigh(cov)
    a = V[:, -1]
    return a if a[np.argmax(np.abs(a))] > 0 else -a


class SolidBark:
    """Procedural bark as a solid texture round the stem: plates between furrows that run along
    ``axis``, repeating every ``period_mm`` in every direction.

    A picture laid on by surface coordinates squeezes wherever they degenerate: cylindrical
    coordinates map a flat lid (normal along the stem) and a rim grown from a sharp edge to a
    line, which drew the bark there as radial streaks several times the size of the plates on
    the stem. A solid texture has no coordinates to degenerate: every surface, flat or curved,
    cuts the same field, so the bark has the same feature size per mm everywhere (on the stem
    the plates' long side runs along it; a lid cuts across them). It is the ``wood`` of
    :func:`woodcam.bake.bake`: ``color(points_mm (n, 3), normals) -> (n, 3)`` RGB in [0, 1].
    """

    #: Voxels of the periodic noise across the stem (two axes) and along it: the plates are
    #: 1/160 of the period wide and 1/24 long (Gaussian sigma); the fine grain is smoothed by
    #: less than a voxel, so it is as fine as the voxels: 1/160 of the period across, 1/64 along.
    CELLS = (160, 160, 64)

    def __init__(self, axis, centre_mm, period_mm: float, seed: int = 0) -> None:
        """axis : (3,) stem direction, any length > 0; centre_mm : (3,) a point on the stem, mm;
        period_mm : the texture's period, mm > 0 (e.g. the stem's girth); seed : int."""
        up = check_vector(axis, "SolidBark: axis", unit=True, fix="give the stem's direction, e.g. (0, 0, 1)")
        centre = check_vector(centre_mm, "SolidBark: centre_mm", fix="give a point on the stem in mm")
        period = check_number(period_mm, "SolidBark: period_mm", lo=0.0, lo_open=True,
                              fix="give the bark's repeat in mm, e.g. the stem's girth")
        # numpy seeds are non-negative (seed=-1 was a bare ValueError of default_rng)
        seed = check_number(seed, "SolidBark: seed", lo=0, hi=2**32 - 1, integer=True, fix="e.g. 0")
        ref = np.array([1.0, 0.0, 0.0]) if abs(up[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        e1 = ref - up * (ref @ up)
        e1 /= np.linalg.norm(e1)
        self._frame = np.stack([e1, np.cross(up, e1), up])    # rows: across, across, along
        self._centre = centre
        self._period = period
        rng = np.random.default_rng(seed)
        n, _, m = self.CELLS
        plates = ndimage.gaussian_filter(rng.standard_normal(self.CELLS), (n / 160, n / 160, m / 24),
                                         mode="wrap")
        fine = ndimage.gaussian_filter(rng.standard_normal(self.CELLS), (n / 512, n / 512, m / 128),
                                       mode="wrap")
        self._plates = ((plates - plates.mean()) / (plates.std() + 1e-9)).astype(np.float32)
        self._fine = ((fine - fine.mean()) / (fine.std() + 1e-9)).astype(np.float32)

    def color(self, points_mm, normals=None) -> np.ndarray:
        """Bark colour ``(n, 3)`` float in [0, 1] at ``points_mm (n, 3)`` (normals unused)."""
        q = (np.asarray(points_mm, float) - self._centre) @ self._frame.T / self._period
        idx = (q * np.asarray(self.CELLS)).T
        plates = ndimage.map_coordinates(self._plates, idx, order=1, mode="grid-wrap")
        fine = ndimage.map_coordinates(self._fine, idx, order=1, mode="grid-wrap")
        furrow = np.clip(-plates - 0.3, 0, None)  # deep furrows where the plate field is low
        light = np.clip(0.65 + 0.12 * fine - 0.35 * np.tanh(furrow), 0, 1)
        base = np.array([112, 92, 74], float)
        grey = np.array([140, 134, 126], float)
        mix = np.clip(0.5 + 0.25 * plates, 0, 1)[:, None]
        rgb = (base * (1 - mix) + grey * mix) * light[:, None] * 1.5
        return np.clip(rgb / 255.0, 0.0, 1.0)


def textured_mesh(mesh, uv, image):
    """A copy of ``mesh`` with ``uv (n_vertices, 2)`` and ``image`` as its texture.

    Triangles whose ``u`` jumps across the wrap (``u`` near 0 and 1) get their own vertex copies
    with ``u + 1``, so the picture does not smear round the stem.
    """
    import trimesh
    from PIL import Image

    uv = np.asarray(uv, float)
    faces = mesh.faces.copy()
    corners = corner_uv(uv, faces)
    moved = corners[..., 0] > uv[faces, 0]  # the low corners of faces across the wrap (u + 1)
    new = faces[moved]
    verts = [mesh.vertices, mesh.vertices[new]]
    uvs = [uv, corners[moved]]
    faces[moved] = len(mesh.vertices) + np.arange(len(new))
    V = np.concatenate(verts)
    UV = np.concatenate(uvs)
    material = trimesh.visual.material.PBRMaterial(
        baseColorTexture=Image.fromarray(np.asarray(image, np.uint8)), roughnessFactor=0.95,
        metallicFactor=0.0)
    out = trimesh.Trimesh(V, faces, process=False,
                          visual=trimesh.visual.TextureVisuals(uv=UV, material=material))
    return out


#: Share of the surface (by area) on which an input's picture moved into an atlas is no
#: coarser than it was (:func:`picture_density`): the densest rest is left out so that a sliver
#: face (picture area on next to no surface) does not set the whole atlas's density.
PICTURE_DENSITY_SHARE = 0.95


def picture_density(mesh, corner_uv, image) -> float:
    """Texels per mm ``image (h, w, 3)`` has on ``mesh`` (mm) laid on by ``corner_uv (f, 3, 2)``,
    as its densest part asks: per face the square root of its picture area (texels, repeats
    counted) over its area, and of those the one :data:`PICTURE_DENSITY_SHARE` of the surface
    (by area) is at or under. An atlas of this density is no coarser than the picture on that
    share (an area mean was coarser wherever the input's UVs are denser than average)."""
    h, w = np.shape(image)[:2]
    c = np.asarray(corner_uv, float) * [w, h]
    a, b = c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]
    texels = 0.5 * np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
    area = np.asarray(mesh.area_faces, float)
    ok = area > 1e-12
    if not ok.any():
        return 0.0
    dens = np.sqrt(texels[ok] / area[ok])
    order = np.argsort(dens)
    cum = np.cumsum(area[ok][order])
    return float(dens[order][np.searchsorted(cum, PICTURE_DENSITY_SHARE * cum[-1])])


#: Texels per voxel of the growth grid in the procedural bark's atlas (see
#: :func:`woodcam.bake.bake`), and the width of a crack drawn into it, in voxels: the
#: cracks run along the grown surface's edges, about a voxel long, so finer would show nothing
#: the simulation knows.
BARK_TEXELS_PER_VOXEL = 4.0
CRACK_WIDTH_VOXELS = 0.5


def corner_uv(uv, faces) -> np.ndarray:
    """Per-face corner coordinates ``(f, 3, 2)`` of per-vertex ``uv (n, 2)`` that wrap in ``u``
    (a picture wrapped round the object, as a longitude-latitude map): a face across the wrap
    (``u`` near 0 and 1) has ``u + 1`` on its low corners (the one home of this rule:
    :func:`textured_mesh` splits those corners off), so the picture does not smear round the
    object."""
    c = np.asarray(uv, float)[np.asarray(faces)].copy()
    u = c[..., 0]
    seam = (u.max(1) - u.min(1)) > 0.5
    u[seam] = np.where(u[seam] < 0.5, u[seam] + 1.0, u[seam])
    return c


def paint_crack_faces(image, corner_xy, faces, edges, width_px: int) -> np.ndarray:
    """Draw crack edges ``(m, 2)`` (vertex indices of ``faces (f, 3)``) dark into an atlas whose
    faces have their own corner texel coordinates ``corner_xy (f, 3, 2)`` (x right, y down, texel
    corners at integers): each edge is drawn in every face that holds it, so a crack on a chart
    seam shows in both charts. In an atlas of even texel density (:func:`woodcam.bake.bake`)
    a crack covers the same share of the texture per mm of bark wherever it lies."""
    import cv2

    img = np.array(image, np.uint8, copy=True)
    faces = np.asarray(faces)
    edges = np.asarray(edges).reshape(-1, 2)
    if not len(edges):
        return img
    n = int(max(faces.max(), edges.max())) + 1
    pairs = faces[:, [[0, 1], [1, 2], [2, 0]]]                    # (f, 3, 2) vertices per side
    key = pairs.min(2).astype(np.int64) * n + pairs.max(2)
    want = edges.min(1).astype(np.int64) * n + edges.max(1)
    f, i = np.nonzero(np.isin(key, want))
    a = corner_xy[f, i] - 0.5                                     # cv2: pixel centres at integers
    b = corner_xy[f, (i + 1) % 3] - 0.5
    k = 16                                                        # 4 bits of sub-texel position
    for p, q in zip(np.round(a * k).astype(np.int64), np.round(b * k).astype(np.int64)):
        cv2.line(img, (int(p[0]), int(p[1])), (int(q[0]), int(q[1])), (28, 20, 14),
                 int(width_px), lineType=cv2.LINE_AA, shift=4)
    return img


def groove(mesh, crack_weight, depth_mm: float):
    """Cut cracks into the geometry: vertices move inward by ``depth_mm * crack_weight``."""
    out = mesh.copy()
    out.vertices = mesh.vertices - mesh.vertex_normals * (depth_mm * np.asarray(crack_weight))[:, None]
    return out
