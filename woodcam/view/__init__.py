"""The pyvista preview: a textured part inside its block, a cut plane showing the wood inside.

- :mod:`woodcam.view.section`: pure-numpy cut-plane geometry (plane basis, plane-box polygon,
  plane-mesh outline, signed distance to it); no VTK, testable alone.
- :mod:`woodcam.view.camera`: named view directions and tight framing.
- :mod:`woodcam.view.scene`: pyvista scene (part, block, cut plane), :class:`SceneOptions`,
  :func:`build_scene`, :func:`preview` (window or off-screen screenshot).
- :mod:`woodcam.view.stockview` / :mod:`woodcam.view.topview`: screenshots of a simulated
  height-field stock without VTK (numba z-buffer in perspective; numpy from above).
"""

from .camera import CAMERAS, Camera
from .scene import (BLOCK_OPACITY, OUTLINE_ACTOR, PART_ACTOR, SECTION_ACTOR,
                    SECTION_MAX_SAMPLES_INTERACTIVE, SECTION_MAX_SAMPLES_SCREENSHOT,
                    SECTION_RESOLUTION_MM, WASTE_ACTOR, CutPlaneCallback, SceneOptions,
                    block_outline, build_scene, cut_plane_image, mesh_to_pyvista, preview)

__all__ = ["BLOCK_OPACITY", "CAMERAS", "OUTLINE_ACTOR", "PART_ACTOR", "SECTION_ACTOR",
           "SECTION_MAX_SAMPLES_INTERACTIVE", "SECTION_MAX_SAMPLES_SCREENSHOT",
           "SECTION_RESOLUTION_MM", "WASTE_ACTOR", "Camera", "CutPlaneCallback", "SceneOptions",
           "block_outline", "build_scene", "cut_plane_image", "mesh_to_pyvista", "preview"]
