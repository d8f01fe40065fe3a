"""Several placements of one part side by side, off screen: each part coloured by the wood it
would be cut from (``Wood.color`` at its vertices), inside its block's outline."""

from __future__ import annotations

from pathlib import Path

import numpy as np


#: Longest triangle edge (mm) of the rendered surface: its vertex colours show rings ~2 mm wide.
_EDGE_MM = 0.7
#: Top share of a panel's height kept clear for its title (up to three lines at font size 10).
_TITLE_SHARE = 0.16


def frame_panel(plotter, bounds) -> None:
    """Look at the box ``bounds`` (x0, x1, y0, y1, z0, z1, block frame, mm) from
    front-right-above in ``plotter``'s active panel, framed tightly below its title band
    (:data:`_TITLE_SHARE` of the panel's height)."""
    from .camera import frame_camera

    x0, y0, x1, y1 = plotter.renderer.GetViewport()  # share of the window
    w, h = (x1 - x0) * plotter.window_size[0], (y1 - y0) * plotter.window_size[1]  # px
    keep = 1.0 - _TITLE_SHARE
    angle = plotter.camera.view_angle  # vertical, degrees
    # frame into the band under the title: its height sees keep * tan(angle / 2) ...
    band = np.degrees(2.0 * np.arctan(keep * np.tan(np.radians(angle) / 2.0)))
    position, focal, up = frame_camera("iso", bounds, (w, keep * h), band)
    plotter.camera_position = [tuple(position), tuple(focal), tuple(up)]
    # ... and the off-axis window centre moves the framed view down to that band's middle
    plotter.camera.SetWindowCenter(0.0, _TITLE_SHARE)
    plotter.reset_camera_clipping_range()


def render_side_by_side(meshes, woods, size_mm, titles, png, *, panel_px: int = 420,
                        progress: bool = False) -> Path:
    """Render ``meshes[i]`` (trimesh, block frame, mm) coloured by ``woods[i].color`` at its
    vertices in panel ``i`` of one PNG, with the block outline and ``titles[i]`` above it;
    ``progress``: a bar over the panels."""
    from ..appearance.wood import vertex_color_normals, wood_colors
    from ..errors import require
    from .scene import _plotter, _prefer_egl_off_screen

    pv = require("pyvista", "view", "rendering placement pictures")
    import trimesh
    from .._atomic import atomic_path
    from .._progress import progress_bar

    _prefer_egl_off_screen()
    n = len(meshes)
    plotter = _plotter(pv, off_screen=True, shape=(1, n), window_size=(panel_px * n, panel_px), border=False)
    try:
        W, D, H = (float(v) for v in size_mm)
        for i, (mesh, wood, title) in enumerate(progress_bar(list(zip(meshes, woods, titles)), desc="rendering",
                                                            unit="panel", enabled=progress)):
            plotter.subplot(0, i)
            # vertex colours need vertices about every EDGE_MM: split long CAD triangles
            verts, tris = trimesh.remesh.subdivide_to_size(
                np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces), _EDGE_MM,
                max_iter=12)
            fine = trimesh.Trimesh(verts, tris, process=False)
            # a direction at every vertex: an unreferenced one or a degenerate triangle's
            # has none, which the wood refuses; wood_colors checks a user's wood's colours
            # (a NaN was drawn black, 0..255 white, a wrong shape was pyvista's ValueError)
            rgb = wood_colors(wood, verts, vertex_color_normals(fine))
            faces = np.column_stack([np.full(len(tris), 3), tris]).ravel()
            surf = pv.PolyData(verts, faces)
            surf["rgb"] = (np.clip(rgb, 0, 1) * 255).astype(np.uint8)
            plotter.add_mesh(surf, scalars="rgb", rgb=True, smooth_shading=False)
            plotter.add_mesh(pv.Box(bounds=(0, W, 0, D, 0, H)).outline(), color="black",
                             line_width=2)
            plotter.add_text(title, font_size=10, position="upper_left")
            # the block, and the part should it stick out
            lo = np.minimum(fine.bounds[0], 0.0)
            hi = np.maximum(fine.bounds[1], (W, D, H))
            frame_panel(plotter, np.column_stack([lo, hi]).ravel())
        path = Path(png)
        with atomic_path(path, mkdir=True) as tmp:
            plotter.screenshot(str(tmp))
        return path
    finally:
        plotter.close()
