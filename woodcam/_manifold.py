"""A manifold3d ``Manifold`` -> its triangles (vertices, faces) or a ``trimesh.Trimesh``: the one
conversion of woodcam (carve, write_stl, placement advice, woodify's parts, the toolpath
reference were each writing it, in float32 or float64).

Read in float64 (``to_mesh64``): manifold3d computes in double, and ``to_mesh`` rounded every
vertex to float32 (~1e-5 mm at 100 mm) before woodcam took it back to float64.
This module imports only numpy and trimesh.
"""

from __future__ import annotations

import numpy as np


def manifold_arrays(solid) -> tuple[np.ndarray, np.ndarray]:
    """``(vertices (n, 3) float64, faces (m, 3) int64)`` of the manifold3d ``Manifold``
    ``solid`` (its units, woodcam's mm), position properties only."""
    out = solid.to_mesh64()
    # copies, so the arrays do not keep manifold3d's Mesh64 buffers alive (nanobind reports such
    # buffers as leaks at interpreter exit)
    vertices = np.array(out.vert_properties[:, :3], dtype=np.float64, copy=True)
    faces = np.array(out.tri_verts, dtype=np.int64, copy=True)
    del out
    return vertices, faces


def manifold_to_trimesh(solid, *, process: bool = False):
    """The manifold3d ``Manifold`` ``solid`` as a ``trimesh.Trimesh`` of its triangles
    (:func:`manifold_arrays`); ``process``: trimesh's own clean-up (merging vertices), off by
    default as a manifold's vertices are already shared."""
    import trimesh

    vertices, faces = manifold_arrays(solid)
    return trimesh.Trimesh(vertices=vertices, faces=faces, process=process)
