"""Pictures and 3-D files of a generated log: GLB (surface + knots) and heightmap PNG.

Meshes are in the log frame (mm, ``z`` along the log, see :mod:`.generate`). The GLB follows
glTF's conventions (metres, +Y up) as every woodcam GLB does: the vertices stay in mm and one
root node carries :data:`~woodcam.frames.BLOCK_TO_GLTF` (scale 1/1000, ``z`` -> ``+Y``), so the
log stands upright at its true size in any viewer; the file's ``extras`` say so.
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal

import numpy as np
import trimesh

from .._atomic import atomic_path, write_bytes
from .._checks import png_path
from ..errors import WoodcamError
from ..frames import BLOCK_TO_GLTF, GLTF_ROOT_NODE, stamp_gltf_asset
from .generate import GeneratedKnot, GeneratedLog
from .._types import PathLike

#: Colours (RGBA, 0-255): debarked sapwood, a live (intergrown) knot, a dead (loose) knot.
SURFACE_RGBA = (222, 192, 140, 255)
LIVE_KNOT_RGBA = (150, 90, 40, 255)
DEAD_KNOT_RGBA = (60, 35, 20, 255)


def surface_mesh(log: GeneratedLog, *, max_rows: int = 400, max_cols: int = 180) -> trimesh.Trimesh:
    """Closed triangle mesh of the log surface from its heightmap (end caps as fans).

    The heightmap is subsampled to at most ``max_rows x max_cols`` (the first and last rows
    are always kept). Vertices: ``centreline(l) + R(l, theta) (cos theta, sin theta, 0)``.
    """
    hm = log.heightmap_mm
    n_l, n_t = hm.shape
    l_ax, t_ax = log.axes
    ri = np.unique(np.r_[np.arange(0, n_l, max(1, int(np.ceil(n_l / max_rows)))), n_l - 1])
    ci = np.arange(0, n_t, max(1, int(np.ceil(n_t / max_cols))))
    l, t, R = l_ax[ri], t_ax[ci], hm[np.ix_(ri, ci)]
    c = log.centreline.xy(l)
    nr, nc = len(l), len(t)
    v = np.stack([c[:, 0:1] + R * np.cos(t)[None, :], c[:, 1:2] + R * np.sin(t)[None, :],
                  np.broadcast_to(l[:, None], R.shape)], axis=-1).reshape(-1, 3)
    i = np.arange(nr - 1)[:, None] * nc
    j = np.arange(nc)[None, :]
    a, b = i + j, i + (j + 1) % nc
    quads = np.stack([a, b, b + nc, a + nc], axis=-1).reshape(-1, 4)
    faces = np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
    bottom, top = len(v), len(v) + 1
    v = np.vstack([v, [c[0, 0], c[0, 1], l[0]], [c[-1, 0], c[-1, 1], l[-1]]])
    jj = np.arange(nc)
    cap0 = np.stack([np.full(nc, bottom), (jj + 1) % nc, jj], axis=1)
    last = (nr - 1) * nc
    cap1 = np.stack([np.full(nc, top), last + jj, last + (jj + 1) % nc], axis=1)
    return trimesh.Trimesh(v, np.concatenate([faces, cap0, cap1]), process=False)


def _ellipse_tube(centres, tangents, r_h, r_v, n_around: int):
    """Vertices/faces of a capped tube with elliptic sections; ``centres (k, 3)``."""
    t = tangents / np.linalg.norm(tangents, axis=1, keepdims=True)
    e1 = np.cross(t, [0.0, 0.0, 1.0])
    bad = np.linalg.norm(e1, axis=1) < 1e-6
    e1[bad] = np.array([1.0, 0.0, 0.0])
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(e1, t)
    phi = np.linspace(0, 2 * np.pi, n_around, endpoint=False)[None, :, None]
    ring = centres[:, None, :] + (r_h[:, None, None] * np.cos(phi) * e1[:, None, :]
                                  + r_v[:, None, None] * np.sin(phi) * e2[:, None, :])
    k = len(centres)
    v = np.vstack([ring.reshape(-1, 3), centres[0], centres[-1]])
    i = np.arange(k - 1)[:, None] * n_around
    j = np.arange(n_around)[None, :]
    a, b = i + j, i + (j + 1) % n_around
    q = np.stack([a, b, b + n_around, a + n_around], axis=-1).reshape(-1, 4)
    jj = np.arange(n_around)
    c0 = np.stack([np.full(n_around, k * n_around), (jj + 1) % n_around, jj], axis=1)
    last = (k - 1) * n_around
    c1 = np.stack([np.full(n_around, k * n_around + 1), last + jj, last + (jj + 1) % n_around], axis=1)
    return v, np.concatenate([q[:, [0, 2, 1]], q[:, [0, 3, 2]], c0, c1])


def knot_mesh(knot: GeneratedKnot, *, n_along: int = 24, n_around: int = 12) -> tuple[trimesh.Trimesh, np.ndarray]:
    """Tapered elliptic tube of one knot from near the pith to its end, and its face colours.

    Faces past the death distance are coloured :data:`DEAD_KNOT_RGBA`, others
    :data:`LIVE_KNOT_RGBA`. Returns ``(mesh, face_rgba (f, 4) uint8)``.
    """
    rho = np.linspace(0.5, max(knot.end_mm, 1.0), n_along)
    c = knot.centerline(rho)
    tang = np.gradient(c, rho, axis=0)
    r = np.maximum(knot.radius(rho), 0.2)
    v, f = _ellipse_tube(c, tang, r, knot.knot.params.gamma * r, n_around)
    mesh = trimesh.Trimesh(v, f, process=False)
    # face's mean rho from its vertices' ring index (caps take their ring's value)
    ring_rho = np.r_[np.repeat(rho, n_around), rho[0], rho[-1]]
    dead = ring_rho[f].mean(axis=1) > knot.death_mm
    rgba = np.where(dead[:, None], np.array(DEAD_KNOT_RGBA), np.array(LIVE_KNOT_RGBA)).astype(np.uint8)
    return mesh, rgba


def knots_mesh(log: GeneratedLog, **kw) -> trimesh.Trimesh:
    """All knots of ``log`` as one mesh with per-face colours (live / dead)."""
    parts = [knot_mesh(k, **kw) for k in log.knots]
    if not parts:
        return trimesh.Trimesh()
    mesh = trimesh.util.concatenate([p[0] for p in parts])
    mesh.visual = trimesh.visual.ColorVisuals(mesh, face_colors=np.concatenate([p[1] for p in parts]))
    return mesh


def export_log_glb(log: GeneratedLog, path: PathLike, *, surface_alpha: float = 1.0, max_rows: int = 400,
                   max_cols: int = 180) -> Path:
    """Write ``log`` as a binary glTF: the surface mesh (node ``surface``) and the knots (``knots``).

    ``path``: the ``.glb`` file to write. ``surface_alpha`` < 1 makes the surface translucent
    (alpha blending) so the knots show. ``max_rows`` x ``max_cols``: the most heightmap rows
    (along the log) and columns (round it) the surface mesh keeps (:func:`surface_mesh`
    subsamples to them; default 400 x 180). Vertices in mm under a root node that makes them
    metres, +Y up (module docstring). Returns the path written.
    """
    if not (0.0 < surface_alpha <= 1.0):
        raise WoodcamError(f"surface_alpha must lie in (0, 1]; got {surface_alpha!r}")
    p = Path(path)
    if p.suffix.lower() != ".glb":
        raise WoodcamError(f"path must end in .glb; got {str(p)!r}")
    surf = surface_mesh(log, max_rows=max_rows, max_cols=max_cols)
    rgba = np.array(SURFACE_RGBA[:3] + (round(255 * surface_alpha),), dtype=float) / 255.0
    mat = trimesh.visual.material.PBRMaterial(
        baseColorFactor=rgba, metallicFactor=0.0, roughnessFactor=0.8,
        alphaMode="BLEND" if surface_alpha < 1 else "OPAQUE", doubleSided=surface_alpha < 1)
    surf.visual = trimesh.visual.TextureVisuals(material=mat)
    scene = trimesh.Scene()
    scene.graph.update(frame_from=scene.graph.base_frame, frame_to=GLTF_ROOT_NODE, matrix=BLOCK_TO_GLTF)
    scene.add_geometry(surf, node_name="surface", geom_name="surface", parent_node_name=GLTF_ROOT_NODE)
    km = knots_mesh(log)
    if len(km.faces):
        scene.add_geometry(km, node_name="knots", geom_name="knots", parent_node_name=GLTF_ROOT_NODE)
    # trimesh writes scene.metadata as the scene's extras
    scene.metadata.update({"units": "mm", "frame": "log frame, z along the log", "seed": log.seed,
                           "block_to_gltf": BLOCK_TO_GLTF.tolist()})
    p.parent.mkdir(parents=True, exist_ok=True)
    write_bytes(p, scene.export(file_type="glb", tree_postprocessor=stamp_gltf_asset))
    return p


def heightmap_image(log: GeneratedLog,
                    mode: Literal["height", "detail"] = "height") -> tuple[np.ndarray, tuple[float, float]]:
    """Heightmap as an image array ``(n_l, n_theta)`` in [0, 1] and its range in mm.

    Row 0 is the top of the log (``l = length``), so the picture stands like the log; columns
    run with azimuth from 0 to 2 pi. ``"height"``: the full radius; ``"detail"``: radius minus
    the smooth base (thickness + base shape), i.e. knot bumps and grain, on a range symmetric
    about 0.
    """
    hm = log.heightmap_mm
    if mode == "height":
        img = hm
        lo, hi = float(hm.min()), float(hm.max())
    elif mode == "detail":
        l, t = log.axes
        img = hm - (log.thickness(l)[:, None] + log.base.grid(l, t))
        hi = float(np.abs(img).max())
        lo = -hi
    else:
        raise WoodcamError(f"mode must be 'height' or 'detail'; got {mode!r}")
    span = hi - lo if hi > lo else 1.0
    return ((img - lo) / span)[::-1], (lo, hi)


def heightmap_png(log: GeneratedLog, path: PathLike, *, mode: Literal["height", "detail"] = "height") -> Path:
    """Write the heightmap of ``log`` (:func:`heightmap_image` in ``mode``: ``"height"``, the
    full radius, or ``"detail"``, radius minus the smooth base) as a 16-bit grey PNG at
    ``path`` (``.png``).

    Grey 0 and 65535 are the range's ends, stored in mm in the PNG text chunk
    ``woodcam:range_mm`` (``"lo hi"``) so the file decodes back to millimetres.
    """
    from PIL import Image, PngImagePlugin

    img, (lo, hi) = heightmap_image(log, mode)
    p = png_path(path, "heightmap_png: path")
    info = PngImagePlugin.PngInfo()
    info.add_text("woodcam:range_mm", f"{lo:.6f} {hi:.6f}")
    info.add_text("woodcam:mode", mode)
    p.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(p) as tmp:
        Image.fromarray(np.round(img * 65535).astype(np.uint16)).save(tmp, pnginfo=info)
    return p


def read_heightmap_png(path: PathLike) -> np.ndarray:
    """Decode the PNG ``path`` written by :func:`heightmap_png` back to mm, ``(n_l, n_theta)``,
    row 0 = ``l = 0``."""
    from PIL import Image

    with Image.open(path) as im:
        rng = im.text.get("woodcam:range_mm") if hasattr(im, "text") else None
        if rng is None:
            raise WoodcamError(f"{path} has no woodcam:range_mm text chunk; write it with heightmap_png")
        lo, hi = map(float, rng.split())
        a = np.asarray(im, dtype=float) / 65535.0
    return (lo + a * (hi - lo))[::-1]
