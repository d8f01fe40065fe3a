"""pyvista scene of a textured part inside its block: interactive window, cut plane, screenshot.

Data form. The part is a ``trimesh.Trimesh`` in the block frame (mm, ``docs/conventions.md``:
origin bottom-front-left, ``+X`` width ``W``, ``+Y`` depth ``D``, ``+Z`` up ``H``), usually with
``TextureVisuals`` (``uv : (n_vertices, 2)`` with ``v = 1`` at the top row of the image, and a
PIL material image), or a path to a file of :data:`MESH_SUFFIXES` holding one. The
block is the box ``[0, W] x [0, D] x [0, H]`` given by ``size_mm = (W, D, H)``. The optional
``wood`` answers ``wood.color(points_mm (n, 3), normals (n, 3)) -> rgb (n, 3)`` floats in
``[0, 1]`` (``docs/architecture.md``); the view never looks inside it.

What is drawn:

- the part with its texture (lit, smooth-shaded with sharp edges kept);
- the block as a translucent box with dark edges (:func:`block_outline`);
- with a wood, a cut plane: the wood of the whole block sampled on the plane
  (:func:`cut_plane_image`), opaque where the plane cuts the part and translucent in the waste
  around it, with the part clipped away on the side the plane's normal points to (toward the
  viewer): a cutaway, the part's textured surface behind, its inside wood on the plane.

Off-screen rendering (``screenshot=...``) needs no display; the interactive window adds a plane
widget whose callback (:class:`CutPlaneCallback`) is a plain object tests can call with an
origin and a normal.
"""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass, fields, replace
from pathlib import Path

import numpy as np

from .._types import ArrayLike, Mesh, PathLike, WoodLike
from ..errors import WoodcamError, require
from .._checks import as_floats, check_bool, check_number, check_vector, did_you_mean
from ..frames import check_size
from ..tolerances import ON_FACE_TOL_MM
from ..units import say_length
from .camera import UNCUT_CAMERAS, Camera, check_camera, default_cut_normal, set_camera
from .section import (
    box_section_uv,
    cut_segments,
    part_triangles,
    plane_basis,
    signed_row_distance,
)
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import pyvista as pv
    import trimesh

#: Default sample spacing (mm) of the wood on a cut plane: finer than a 0.5 mm latewood band.
SECTION_RESOLUTION_MM = 0.25

#: At most this many wood samples on the screenshot's cut plane (~0.5 s for a fast wood); a
#: larger section is sampled more coarsely than ``SECTION_RESOLUTION_MM``.
SECTION_MAX_SAMPLES_SCREENSHOT = 400_000

#: At most this many samples while dragging the interactive plane, so it follows the mouse.
SECTION_MAX_SAMPLES_INTERACTIVE = 60_000

#: Opacity of the block's translucent faces: enough to read the block, little enough to see
#: the part through it.
BLOCK_OPACITY = 0.15

#: The preview draws the block's faces and edges this share of the block's diagonal outside
#: the block: a part face on a block face would otherwise lie in the translucent face's plane,
#: and the two would fight for each pixel (a screen-door pattern). 5e-4 is 0.07 mm on a 100 mm
#: block, half a pixel in the 1280 px preview, and some 3x the 24-bit depth buffer's step at
#: the framed distance even with the near plane at far / 1000 (VTK keeps it much nearer).
BLOCK_OUTSET = 5e-4

#: The suffixes of the mesh files :func:`preview` reads (woodcam's own GLB/OBJ, another
#: program's file through trimesh): the one list of its reader and of ``woodcam preview``'s
#: input door (:func:`woodcam.cli.options.add_input`).
MESH_SUFFIXES = (".glb", ".gltf", ".obj", ".ply", ".stl", ".off")

#: Colours (RGB 0..1) of the block box, its edges, and a part that carries no texture.
BLOCK_COLOR = (0.80, 0.70, 0.55)
BLOCK_EDGE_COLOR = (0.25, 0.22, 0.20)
UNTEXTURED_PART_COLOR = (0.78, 0.62, 0.42)

#: Opacity of the waste wood on the cut plane (the section outside the part): the wood around
#: the part stays readable while the part's far half shows through it.
WASTE_OPACITY = 0.3

#: Overlay colours (RGB 0..255) by the names the CLI gives them (rapids red, feeds royalblue):
#: the name table's (matplotlib's, :func:`_named_rgb`) values, kept here so that `woodcam gcode`'s
#: numpy screenshot draws them without importing matplotlib (tests pin them to the table).
OVERLAY_COLORS = {"red": (255, 0, 0), "royalblue": (65, 105, 225)}

#: The colour rule of every view (pyvista's and matplotlib's), overlays and backgrounds alike,
#: said in errors.
COLOUR_RULE = ("a colour name matplotlib knows ('royalblue', 'tab:blue', 'xkcd:sky blue'), a hex string "
               "('#4169e1') or an RGB triple: whole numbers in 0..255, e.g. (65, 105, 225), or floats in "
               "0..1, e.g. (0.25, 0.41, 0.88) (a float anywhere in the triple makes it 0..1)")


def _named_rgb(colour: str, who: str, name: str) -> tuple[np.ndarray | None, str]:
    """A colour name or hex string as RGB 0..255 ``(3,)`` float by the one name table,
    matplotlib's (:func:`matplotlib.colors.to_rgba`: CSS4 names in any case, 'tab:' and 'xkcd:'
    names, '#rgb' / '#rrggbb' hex, grey levels '0.5'), or None and the fix to say. pyvista's
    own table gives the CSS4 names the same values; the numpy views knew only two names."""
    import re

    colors = require("matplotlib.colors", "view", f"{who}: the {name} {colour!r:.40}")
    if re.fullmatch(r"\s*C\d+\s*", colour):  # not a table entry: the style's colour cycle
        return None, ("'C0', 'C1', ... are the colours of matplotlib's style cycle, which the style "
                      "in use decides; give the colour's name, e.g. 'tab:blue'")
    try:
        rgba = colors.to_rgba(colour)
    except ValueError:
        table = [*colors.CSS4_COLORS, *colors.TABLEAU_COLORS, *colors.XKCD_COLORS]
        # 'royal blue', 'Royal_Blue' (pyvista's spellings of matplotlib's names) joined first
        close = did_you_mean(("".join(colour.lower().replace("_", " ").split()), colour.lower()), table, n=3)
        return None, (close or "give a CSS4 name, e.g. 'royalblue' (matplotlib.colors.CSS4_COLORS), or a triple")
    if rgba[3] < 1:  # 'none', '#ff000080': the views draw colours opaque
        return None, "the views draw colours opaque; give one without transparency, e.g. '#ff0000'"
    return 255 * np.asarray(rgba[:3], float), ""


def colour_rgb(colour, who: str, name: str = "overlay colour") -> np.ndarray:
    """A view's colour (an overlay's, a background's) as RGB 0..255 ``(3,)`` float: the one rule
    of every view (``who``: the function and ``name`` the argument, said in the error),
    :data:`COLOUR_RULE`:

    - a name or hex string of the one name table, matplotlib's (:func:`_named_rgb`), so a name
      draws the same colour in :func:`preview` and the numpy views (top_view and stock_view knew
      only "red" and "royalblue"; preview also took pyvista's own names and spellings, e.g.
      'banana', 'royal_blue', now refused with the close matches);
    - three whole numbers (int, numpy integer) in 0..255, as given;
    - three numbers with a float among them, in 0..1, times 255: (1.0, 0.0, 0.0) is red.

    pyvista read a float triple in 0..1 and the numpy views in 0..255, so (1.0, 0, 0) was red in
    :func:`preview` and nearly black in top_view/stock_view. Refused (WoodcamError naming the
    view, the argument, the rule, the value and a fix): None (no colour, in every view: there is
    no default colour; preview drew pyvista's theme colour, light blue by default, where the
    numpy views refused it), a name not in the table (with close matches), a float above 1
    ((255.0, 0, 0): no guess at which scale was meant), whole numbers of 0 and 1 only with a 1
    among them ((1, 0, 0) is nearly black in 0..255 but reads as red in 0..1), out of range, not
    three numbers, a bool.
    """
    if colour is None:
        fix = ("None is no colour (there is no default: a view would have to guess one); give one, "
               "e.g. 'royalblue' or (65, 105, 225)")
    elif isinstance(colour, str):
        if colour in OVERLAY_COLORS:
            return np.asarray(OVERLAY_COLORS[colour], float)
        named, fix = _named_rgb(colour, who, name)
        if named is not None:
            return named
    else:
        values = list(colour) if isinstance(colour, (tuple, list, np.ndarray)) else []
        numbers = len(values) == 3 and all(isinstance(v, (int, float, np.integer, np.floating))
                                           and not isinstance(v, (bool, np.bool_)) for v in values)
        rgb = np.asarray(values, float) if numbers else None
        whole = numbers and all(isinstance(v, (int, np.integer)) for v in values)
        fix = "give three numbers in one of those ranges, e.g. (255, 0, 0) or (1.0, 0.0, 0.0)"
        if rgb is not None and np.all(np.isfinite(rgb) & (rgb >= 0)):
            if whole and rgb.max() == 1:
                fix = ("ambiguous: whole numbers are read in 0..255 (nearly black here); for 0..1 "
                       f"write floats, e.g. {tuple(float(v) for v in rgb)}, for 0..255 e.g. "
                       f"{tuple(int(255 * v) for v in rgb)}")
            elif whole and rgb.max() <= 255:
                return rgb
            elif not whole and rgb.max() <= 1:
                return 255 * rgb
            elif not whole and rgb.max() <= 255:
                fix = (f"a triple with a float is read in 0..1; for 0..255 give whole numbers, e.g. "
                       f"{tuple(int(round(v)) for v in rgb)}, or divide by 255")
    raise WoodcamError(f"{who}: {name} must be {COLOUR_RULE}; got {colour!r:.60}; {fix}")


#: Colour and width (pixels) of the part's outline drawn on the cut plane.
OUTLINE_COLOR = (0.20, 0.12, 0.06)
OUTLINE_WIDTH = 3.0

#: Actor names, so that re-adding with the same name replaces (the cut-plane callback).
PART_ACTOR = "woodcam-part"
SECTION_ACTOR = "woodcam-section"
WASTE_ACTOR = "woodcam-section-waste"
OUTLINE_ACTOR = "woodcam-section-outline"

# The 12 edges of a box as pairs of corner indices; corner k has bits (x, y, z) = k's bits.
def _pyvista():
    return require("pyvista", "view", "the preview")


def load_viewer() -> None:
    """Import pyvista and VTK now, as :func:`preview` does first: seconds on a cold start (6-7 s
    measured), which a command shows a bar over (``woodcam preview``); missing, the error
    names the install command."""
    _pyvista()


def _plotter(pv, **kwargs):
    """A ``pv.Plotter(**kwargs)`` of woodcam's views, drawn with pyvista's own default theme
    (its DocumentTheme), never ``pyvista.global_theme``: a user's script that set
    ``pyvista.global_theme.lighting = False``, ``.show_edges``, ``.opacity`` or
    ``.transparent_background`` (or PYVISTA_PLOT_THEME) changed woodcam's pictures (flat, edged,
    see-through parts, a PNG of RGBA with no background) and the placement pictures' background."""
    return pv.Plotter(theme=pv.themes.DocumentTheme(), **kwargs)


# ---------------------------------------------------------------------------- input checks


def _check_wood(wood):
    if wood is not None and not callable(getattr(wood, "color", None)):
        raise WoodcamError(
            "wood must have a method color(points_mm (n, 3), normals (n, 3)) -> rgb (n, 3); "
            f"got {type(wood).__name__}; pass a woodcam Wood or wood=None"
        )
    return wood


def _check_size_with_wood(wood, size) -> None:
    if wood is not None and size is None:
        raise WoodcamError(
            "size_mm is needed with wood: the cut plane shows the wood inside the block "
            "[0, W] x [0, D] x [0, H]; pass size_mm=(W, D, H)"
        )


def _load_mesh(mesh_or_path):
    """A ``trimesh.Trimesh`` from a mesh, a scene or a path (scenes are concatenated)."""
    import trimesh

    # what the messages call it: the file as given (a command-line user typed it), else the mesh
    what = f"mesh file {str(mesh_or_path)!r}" if isinstance(mesh_or_path, (str, os.PathLike)) else \
        "mesh_or_path (the mesh given)"
    if isinstance(mesh_or_path, (str, os.PathLike)):
        path = Path(mesh_or_path)
        if not path.is_file():
            raise WoodcamError(
                f"mesh file {str(path)!r} does not exist; pass a {'/'.join(MESH_SUFFIXES)} file "
                "written by woodcam (e.g. out/part.glb) or a trimesh.Trimesh"
            )
        from woodcam.export import load_textured, written_by_woodcam
        from woodcam.frames import foreign_gltf_in_block_frame

        try:
            # woodcam's own GLB/OBJ are metres/Y-up on disk: load_textured returns the block frame;
            # another program's glTF is metres/Y-up too when its size says so
            ours = written_by_woodcam(path)
            loaded = load_textured(path) if ours else trimesh.load(path, force="mesh")
        except Exception as err:  # trimesh raises many types for unreadable files
            raise WoodcamError(
                f"mesh file {str(path)!r} could not be read as a mesh ({err}); "
                f"pass a {'/'.join(MESH_SUFFIXES)} file"
            ) from err
        mesh_or_path = loaded if ours else foreign_gltf_in_block_frame(loaded, path, stacklevel=2)
    if isinstance(mesh_or_path, trimesh.Scene):
        meshes = [g for g in mesh_or_path.dump() if isinstance(g, trimesh.Trimesh)]
        if not meshes:
            raise WoodcamError(f"{what} holds no triangle mesh; give a part with faces")
        mesh_or_path = meshes[0] if len(meshes) == 1 else trimesh.util.concatenate(meshes)
    if not isinstance(mesh_or_path, trimesh.Trimesh):
        raise WoodcamError(
            "mesh_or_path must be a trimesh.Trimesh, a trimesh.Scene or a path to a mesh file; "
            f"got {type(mesh_or_path).__name__}"
        )
    if len(mesh_or_path.faces) == 0:
        raise WoodcamError(f"{what} has no faces, nothing to preview; give a part with faces (an empty export: "
                           "export it again)")
    return mesh_or_path


# ---------------------------------------------------------------------------- geometry


def _material_image(material):
    """The colour image of a trimesh material (Simple: ``image``; PBR: ``baseColorTexture``)."""
    if material is None:
        return None
    image = getattr(material, "image", None)
    if image is None:
        image = getattr(material, "baseColorTexture", None)
    return image


def mesh_to_pyvista(mesh: Mesh | trimesh.Scene | PathLike) -> tuple[pv.PolyData, pv.Texture | None]:
    """Convert a trimesh mesh to pyvista, keeping its texture or colours.

    Parameters
    ----------
    mesh : trimesh.Trimesh, trimesh.Scene, str or Path
        Triangles in the block frame (mm); a scene's meshes are concatenated and a file is read
        as :func:`preview` reads it. With ``TextureVisuals`` (``uv : (n_vertices, 2)``,
        ``v = 1`` at the image's top row, material image as PIL), the uv become the polydata's
        active texture coordinates and the image a ``pv.Texture`` (VTK also puts ``v = 1`` at
        the top row, so the image is used as stored). Vertex or face colours become an ``RGB``
        uint8 point or cell array.

    Returns
    -------
    poly : pyvista.PolyData
        Points ``(n_vertices, 3)`` float64 mm, triangle faces.
    texture : pyvista.Texture or None
        The colour image, or None when the mesh has no textured material.
    """
    pv = _pyvista()
    mesh = _load_mesh(mesh)
    poly = pv.PolyData.from_regular_faces(
        np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces, dtype=np.int64)
    )
    texture = None
    visual = mesh.visual
    kind = getattr(visual, "kind", None)
    if kind == "texture":
        uv = getattr(visual, "uv", None)
        image = _material_image(getattr(visual, "material", None))
        if uv is not None and image is not None:
            uv = np.asarray(uv, dtype=float)
            if uv.shape != (len(mesh.vertices), 2):
                raise WoodcamError(
                    f"mesh.visual.uv must have shape (n_vertices, 2) = ({len(mesh.vertices)}, 2); "
                    f"got {uv.shape}; give one uv per vertex (split vertices on uv seams)"
                )
            poly.active_texture_coordinates = uv
            texture = pv.Texture(np.ascontiguousarray(np.asarray(image.convert("RGB"))))
            texture.interpolate = True
            texture.mipmap = True
    elif kind == "vertex":
        poly.point_data["RGB"] = np.asarray(visual.vertex_colors)[:, :3].astype(np.uint8)
    elif kind == "face":
        poly.cell_data["RGB"] = np.asarray(visual.face_colors)[:, :3].astype(np.uint8)
    return poly, texture


def block_outline(size_mm: ArrayLike, *, outset_mm: float = 0.0) -> tuple[pv.PolyData, pv.PolyData]:
    """The block ``[0, W] x [0, D] x [0, H]`` (``size_mm = (W, D, H)``, block frame, mm) as a box
    surface and its 12 edges, each face moved ``outset_mm`` outwards (mm; the preview's
    :data:`BLOCK_OUTSET`).

    Returns
    -------
    box : pyvista.PolyData
        The six faces; the preview draws them with opacity :data:`BLOCK_OPACITY`.
    edges : pyvista.PolyData
        The 12 edges as lines, drawn opaque in :data:`BLOCK_EDGE_COLOR`.
    """
    pv = _pyvista()
    w, d, h = check_size(size_mm)
    e = float(outset_mm)
    box = pv.Box(bounds=(-e, w + e, -e, d + e, -e, h + e))
    edges = box.extract_feature_edges(
        boundary_edges=False, feature_edges=True, manifold_edges=False, feature_angle=30.0
    )
    return box, edges


def _grid_polydata(pv, origin, u, v, u_range, v_range, n_u: int, n_v: int):
    """A regular quad grid of ``n_u x n_v`` points spanning the ranges along ``u`` and ``v``."""
    su = np.linspace(u_range[0], u_range[1], n_u)
    sv = np.linspace(v_range[0], v_range[1], n_v)
    gu, gv = np.meshgrid(su, sv, indexing="ij")                  # (n_u, n_v)
    points = origin + gu.reshape(-1, 1) * u + gv.reshape(-1, 1) * v
    idx = np.arange(n_u * n_v).reshape(n_u, n_v)
    quads = np.stack(
        [idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], axis=-1
    ).reshape(-1, 4)
    return pv.PolyData.from_regular_faces(points, quads)


def cut_plane_image(
    wood: WoodLike,
    size_mm: ArrayLike,
    origin: ArrayLike,
    normal: ArrayLike,
    resolution_mm: float = SECTION_RESOLUTION_MM,
    *,
    max_samples: int | None = None,
    part: Mesh | pv.PolyData | tuple[ArrayLike, ArrayLike] | None = None,
) -> pv.PolyData:
    """The wood on the part of a plane inside the block, as coloured polydata.

    The plane through ``origin`` with unit ``normal`` is sampled on a regular grid of spacing
    ``resolution_mm`` and clipped to the block ``[0, W] x [0, D] x [0, H]`` (the cut edges are
    exact: the clip puts points on the box faces). The wood is asked for its colour at every
    point with the plane normal as the surface normal.

    Parameters
    ----------
    wood : object with ``color(points_mm (n, 3), normals (n, 3)) -> rgb (n, 3)`` in [0, 1]
    size_mm : (3,) float
        Block size ``(W, D, H)`` mm.
    origin, normal : (3,) float
        A point of the plane (mm, block frame; it may lie outside the block) and its normal
        (any length, normalised here).
    resolution_mm : float
        Grid spacing, mm.
    max_samples : int, optional
        Coarsen the spacing when the grid would have more points than this.
    part : pyvista.PolyData, trimesh.Trimesh or (points (n, 3), triangles (m, 3)), optional
        A closed part surface (block frame, mm). The section is then split along the part's
        outline on the plane and its cells get ``"in_part"`` (1 inside the part, 0 in the
        waste around it). The outline is exact along the grid's rows and placed within one
        sample spacing across them.

    Returns
    -------
    pyvista.PolyData
        Points ``(n, 3)`` float64 mm inside the block; point array ``"RGB"`` ``(n, 3)`` uint8
        (``round(255 * wood.color)``, computed at the final points, so boundary points are
        exact too), the active scalars; with ``part``, cell array ``"in_part"``
        ``(n_cells,)`` uint8 and, if the plane cuts the part, field data ``"outline_mm"``
        ``(2 k, 3)``: the ends of the ``k`` segments where it cuts the part's triangles
        (pairs of rows); field data ``"normal"``
        ``(1, 3)`` and ``"resolution_mm"`` ``(1,)``. Empty (``n_points == 0``) when the plane
        misses the block.
    """
    pv = _pyvista()
    _check_wood(wood)
    if wood is None:
        raise WoodcamError("wood: cut_plane_image needs a wood to colour the plane; got None")
    size = check_size(size_mm)
    origin = check_vector(origin, "origin", unit=False)
    normal = check_vector(normal, "normal", unit=True)
    if not (isinstance(resolution_mm, (int, float)) and np.isfinite(resolution_mm)
            and resolution_mm > 0):
        raise WoodcamError(
            f"resolution_mm must be a positive number of mm; got {resolution_mm!r}; e.g. 0.25"
        )
    if max_samples is not None and (not isinstance(max_samples, (int, np.integer))
                                    or max_samples < 16):
        raise WoodcamError(
            f"max_samples must be an integer >= 16 or None; got {max_samples!r}; e.g. 60000"
        )

    u, v = plane_basis(normal)
    poly_uv = box_section_uv(size, origin, normal, u, v)
    if len(poly_uv) < 3:
        return pv.PolyData()
    lo, hi = poly_uv.min(axis=0), poly_uv.max(axis=0)
    extent = hi - lo
    if np.any(extent <= ON_FACE_TOL_MM):
        return pv.PolyData()
    step = float(resolution_mm)
    if max_samples is not None:
        # Each axis gets ceil(extent / step) + 1 <= extent / step + 2 points; the largest
        # t = 1 / step with (a t + 2)(b t + 2) <= max_samples solves a quadratic in t.
        a, b = extent
        t = (-2.0 * (a + b) + np.sqrt(4.0 * (a + b) ** 2 - 4.0 * a * b * (4.0 - max_samples))) \
            / (2.0 * a * b)
        step = max(step, 1.0 / t)
    n_u, n_v = (np.ceil(extent / step).astype(int) + 1).clip(min=2)
    section = _grid_polydata(pv, origin, u, v, (lo[0], hi[0]), (lo[1], hi[1]), n_u, n_v)
    segments = None
    if part is not None:
        segments = cut_segments(*part_triangles(part), origin, normal)
        ends = segments - origin
        seg_uv = np.stack([ends @ u, ends @ v], axis=-1)         # (k, 2, 2) mm
        su, sv = np.linspace(lo[0], hi[0], n_u), np.linspace(lo[1], hi[1], n_v)
        section.point_data["part_mm"] = signed_row_distance(seg_uv, su, sv).reshape(-1)

    # Clip to the box by the face planes the grid actually crosses (none when the normal is
    # a block axis: the grid rectangle is then the section itself).
    for axis in range(3):
        for bound, sign in ((0.0, -1.0), (size[axis], 1.0)):
            coord = section.points[:, axis]
            if np.all(sign * (coord - bound) <= ON_FACE_TOL_MM):
                continue
            plane_normal = np.zeros(3)
            plane_normal[axis] = sign
            plane_origin = np.zeros(3)
            plane_origin[axis] = bound
            section = section.clip(normal=plane_normal, origin=plane_origin, invert=True)
            if section.n_points == 0:
                return pv.PolyData()
    in_part = None
    if part is not None:
        inside, outside = section.clip_scalar(scalars="part_mm", value=0.0, invert=False,
                                              both=True)
        inside.cell_data["in_part"] = np.ones(inside.n_cells, np.uint8)
        outside.cell_data["in_part"] = np.zeros(outside.n_cells, np.uint8)
        section = pv.merge([d for d in (inside, outside) if d.n_cells], merge_points=True) \
            if inside.n_cells + outside.n_cells else pv.PolyData()
        if section.n_cells:
            in_part = np.asarray(section.cell_data["in_part"]).astype(np.uint8)
    if section.n_cells == 0:
        return pv.PolyData()
    points = np.clip(np.asarray(section.points, dtype=float), 0.0, size)
    from ..appearance.wood import wood_colors

    rgb = wood_colors(wood, points, normal)
    out = pv.PolyData(points, faces=section.faces)
    if in_part is not None:
        out.cell_data["in_part"] = in_part
    out.point_data["RGB"] = np.rint(rgb * 255.0).astype(np.uint8)
    out.set_active_scalars("RGB")
    out.field_data["normal"] = normal[None, :]
    out.field_data["resolution_mm"] = np.array([step])
    if segments is not None and len(segments):
        out.field_data["outline_mm"] = segments.reshape(-1, 3)
    return out


# ---------------------------------------------------------------------------- scene


def _add_part(plotter, part, texture, *, name: str = PART_ACTOR):
    """Add (or replace, by ``name``) the part with its texture or colours."""
    # Some ambient light keeps faces turned from the lights close to the wood's own colour
    # (the unlit cut plane shows that colour); diffuse and a little specular give the shape.
    style = dict(smooth_shading=True, split_sharp_edges=True, ambient=0.25, diffuse=0.8,
                 specular=0.15, specular_power=20.0, name=name, show_scalar_bar=False)
    if texture is not None and part.active_texture_coordinates is not None:
        return plotter.add_mesh(part, texture=texture, **style)
    if "RGB" in part.point_data or "RGB" in part.cell_data:
        return plotter.add_mesh(part, scalars="RGB", rgb=True, **style)
    return plotter.add_mesh(part, color=UNTEXTURED_PART_COLOR, **style)


def _add_block(plotter, size):
    box, edges = block_outline(size, outset_mm=BLOCK_OUTSET * float(np.linalg.norm(size)))
    plotter.add_mesh(box, color=BLOCK_COLOR, opacity=BLOCK_OPACITY, lighting=False,
                     name="woodcam-block", show_scalar_bar=False)
    plotter.add_mesh(edges, color=BLOCK_EDGE_COLOR, line_width=2, name="woodcam-block-edges",
                     show_scalar_bar=False)


class CutPlaneCallback:
    """Redraw the cut for a plane ``(normal, origin)``: a cutaway of the part in its block.

    The plane widget calls it as ``callback(normal, origin)`` while the plane is dragged; tests
    call it the same way on an off-screen plotter. Creating it adds the part (actor
    :data:`PART_ACTOR`) with a clipping plane on its mapper; each call moves that plane, so the
    part keeps only the side *opposite* the normal (the normal points at the viewer and at the
    half that is cut away; clipping on the GPU keeps texture seams and costs nothing). With a
    wood, each call also replaces the wood on the plane inside the block: where the plane cuts
    the part, opaque (actor :data:`SECTION_ACTOR`: the inside of the part, facing the viewer),
    around it the waste wood, translucent (actor :data:`WASTE_ACTOR`), and the part's outline
    on the plane as a dark line (actor :data:`OUTLINE_ACTOR`).

    Parameters
    ----------
    plotter : pyvista.Plotter
    part : pyvista.PolyData
        The whole part, as from :func:`mesh_to_pyvista` (closed, for the in/out split).
    texture : pyvista.Texture or None
    wood : object with ``color(points_mm, normals)``, or None (then only the part is clipped)
    size_mm : (3,) float or None
        Block size; needed with a wood.
    resolution_mm, max_samples
        Passed to :func:`cut_plane_image`.

    Attributes
    ----------
    clip_plane : vtkPlane
        The part's clipping plane (origin mm; its normal is minus the cut's normal).
    section : pyvista.PolyData or None
        The last wood section, whole (cell array ``"in_part"`` tells part from waste).
    shown : dict[str, pyvista.PolyData | None]
        What the last call drew under each actor name (:data:`SECTION_ACTOR`,
        :data:`WASTE_ACTOR`, :data:`OUTLINE_ACTOR`); None where that actor was removed.
        (Reading the meshes back through ``actor.mapper.dataset`` is unreliable in pyvista
        0.49: it reads empty once another mesh is added, although the picture is right.)
    """

    def __init__(self, plotter, part, texture, wood=None, size_mm=None, *,
                 resolution_mm: float = SECTION_RESOLUTION_MM, max_samples: int | None = None):
        _pyvista()  # a clear MissingDependencyError before vtk is touched
        from vtkmodules.vtkCommonDataModel import vtkPlane

        self.plotter = plotter
        self.part = part
        self.wood = _check_wood(wood)
        self.size_mm = None if size_mm is None else check_size(size_mm)
        _check_size_with_wood(wood, self.size_mm)
        self.resolution_mm = resolution_mm
        self.max_samples = max_samples
        self.section = None
        self.shown = {}
        self._triangles = part_triangles(part)                  # (points, triangles), once
        self.clip_plane = vtkPlane()
        self.part_actor = _add_part(plotter, part, texture)
        self.part_actor.mapper.AddClippingPlane(self.clip_plane)

    def __call__(self, normal, origin):
        """Move the cut to the plane; returns the section polydata (None without a wood)."""
        normal = check_vector(normal, "normal", unit=True)
        origin = check_vector(origin, "origin", unit=False)
        # vtkPlane clipping keeps points with plane_normal . (x - origin) >= 0.
        self.clip_plane.SetOrigin(*origin)
        self.clip_plane.SetNormal(*(-normal))
        if self.wood is None:
            return None
        section = cut_plane_image(self.wood, self.size_mm, origin, normal, self.resolution_mm,
                                  max_samples=self.max_samples, part=self._triangles)
        self.section = section
        in_part = (np.asarray(section.cell_data["in_part"]).astype(bool) if section.n_cells
                   else np.zeros(0, bool))
        # Unlit: the plane shows the wood's own colour, as a freshly planed face would.
        for name, cells, opacity in ((SECTION_ACTOR, in_part, 1.0),
                                     (WASTE_ACTOR, ~in_part, WASTE_OPACITY)):
            shown = section.remove_cells(~cells) if cells.any() else None
            self.shown[name] = shown
            if shown is not None:
                self.plotter.add_mesh(shown, scalars="RGB", rgb=True, lighting=False,
                                      opacity=opacity, name=name, show_scalar_bar=False)
            else:
                self.plotter.remove_actor(name, render=False)
        # The part's outline on the plane, so its inside stands out from the waste.
        segments = (np.asarray(section.field_data["outline_mm"]).reshape(-1, 2, 3)
                    if "outline_mm" in section.field_data else np.empty((0, 2, 3)))
        if len(segments):
            lines = np.hstack([np.full((len(segments), 1), 2),
                               np.arange(2 * len(segments)).reshape(-1, 2)]).ravel()
            outline = _pyvista().PolyData(segments.reshape(-1, 3), lines=lines)
            self.shown[OUTLINE_ACTOR] = outline
            self.plotter.add_mesh(outline, color=OUTLINE_COLOR, line_width=OUTLINE_WIDTH,
                                  lighting=False, name=OUTLINE_ACTOR, show_scalar_bar=False)
        else:
            self.shown[OUTLINE_ACTOR] = None
            self.plotter.remove_actor(OUTLINE_ACTOR, render=False)
        return section


def _display_available() -> bool:
    if sys.platform.startswith("linux"):
        return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    return True


def check_display(who: str, fix: str) -> None:
    """Raise a :class:`WoodcamError` when no interactive window can open (Linux without
    DISPLAY or WAYLAND_DISPLAY), before the work: ``who`` wants the window, ``fix`` says how to
    render a picture instead. The one rule of every window (:func:`preview`, ``woodcam gcode
    --view``, ``woodcam preview``, which opened its block and loaded pyvista before it was told)."""
    if not _display_available():
        raise WoodcamError(f"{who}: an interactive window needs a display, but neither DISPLAY nor "
                           f"WAYLAND_DISPLAY is set; {fix}")


def _prefer_egl_off_screen() -> None:
    """Off screen on Linux without a display, make VTK pick its EGL window directly.

    VTK 9.4+ otherwise tries X first and logs "bad X server connection" before falling back.
    An explicit ``VTK_DEFAULT_OPENGL_WINDOW`` from the user is left alone.
    """
    if (sys.platform.startswith("linux") and not _display_available()
            and "VTK_DEFAULT_OPENGL_WINDOW" not in os.environ):
        os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = "vtkEGLRenderWindow"


def check_background(value, who: str = "preview", name: str = "background"):
    """The scene's ``background`` checked at the door by the views' one colour rule
    (:func:`colour_rgb`), as stock_view's: returned as given (a sequence as a tuple; pyvista is
    handed :func:`_pyvista_rgb`'s floats). It had a rule of its own, pyvista's read of the
    value: whole (1, 0, 0) drew nearly black where the same triple is refused as an overlay
    colour, and a name went to pyvista's table. None, a number, NaN, (0.5, 0.5) or 'nope'
    reached VTK's renderer as pyvista's bare TypeError/ValueError, or (None) its default blue."""
    colour_rgb(value, who, name)
    if isinstance(value, str):
        return value
    return tuple(int(x) if isinstance(x, (int, np.integer)) else float(x) for x in value)


def _pyvista_rgb(colour, who: str, name: str) -> tuple[float, float, float]:
    """``colour`` by :func:`colour_rgb` as the floats in 0..1 handed to pyvista: a view's colour
    is read by the one rule, never by pyvista's own."""
    r, g, b = (float(c) / 255 for c in colour_rgb(colour, who, name))
    return r, g, b


@dataclass(frozen=True)
class SceneOptions:
    """How the scene is drawn: the keywords :func:`preview` and :func:`build_scene` share.

    Attributes
    ----------
    cut_plane : bool
        Interactive: add a plane widget that clips the part and shows the wood on the plane as
        it is dragged (without a wood it only clips the part). Screenshot with a wood: show one
        cut plane at ``cut_origin`` / ``cut_normal``.
    camera : "iso" | "top" | "front" | "back" | "left" | "right" | "bottom"
        View direction; "iso" looks from front-right-above.
    background : colour
        By the views' one colour rule (:func:`colour_rgb`: a name or hex string of matplotlib's
        table, "white", "#202020", whole numbers in 0..255 or floats in 0..1), as
        :func:`woodcam.view.stockview.stock_view`'s.
    cut_origin, cut_normal : (3,) float mm / direction, optional
        The initial cut plane; default the block centre and the block's longest axis facing
        the camera, signed toward it (the part's half on the camera side is cut away, so the
        plane shows its inside wood). The normal is normalised here. The "top" and "bottom"
        cameras show the part uncut unless one of the two is given (the plane widget then
        starts on the block face toward the camera), so that they show its top and underside.
    resolution_mm : float
        Sample spacing of the wood on the plane, mm (coarsened for very large sections).
    max_samples : int, optional
        Cap on wood samples per section (see :func:`cut_plane_image`); default
        :data:`SECTION_MAX_SAMPLES_INTERACTIVE` with the plane widget (it redraws while
        dragged), else :data:`SECTION_MAX_SAMPLES_SCREENSHOT`.

    The scene's messages give lengths in the message units (:func:`woodcam.units.message_units`,
    which the CLI sets to ``--units``), as every library message does.
    """

    cut_plane: bool = True
    camera: Camera = "iso"
    background: object = "white"
    cut_origin: tuple[float, float, float] | None = None
    cut_normal: tuple[float, float, float] | None = None
    resolution_mm: float = SECTION_RESOLUTION_MM
    max_samples: int | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "cut_plane", check_bool(self.cut_plane, "cut_plane"))
        check_camera(self.camera)
        object.__setattr__(self, "background", check_background(self.background))
        if self.cut_origin is not None:
            object.__setattr__(self, "cut_origin",
                               tuple(check_vector(self.cut_origin, "cut_origin", unit=False)))
        if self.cut_normal is not None:
            object.__setattr__(self, "cut_normal",
                               tuple(check_vector(self.cut_normal, "cut_normal", unit=True)))
        # resolution_mm=0 or NaN and max_samples=0 were taken and reached the section sampler
        object.__setattr__(self, "resolution_mm", check_number(
            self.resolution_mm, "resolution_mm", lo=0, lo_open=True,
            fix=f"the cut's sample spacing, e.g. {SECTION_RESOLUTION_MM}"))
        if self.max_samples is not None:
            object.__setattr__(self, "max_samples", int(check_number(
                self.max_samples, "max_samples", lo=1, integer=True, fix="a cap on the cut's samples, or None")))

    @classmethod
    def merged(cls, options: SceneOptions | None, keywords: dict) -> SceneOptions:
        """``options`` (default: all defaults) with ``keywords`` replacing fields by name."""
        names = {f.name for f in fields(cls)}
        unknown = sorted(set(keywords) - names)
        if unknown:
            raise WoodcamError(f"unknown scene option(s) {unknown}; the options are "
                               f"{sorted(names)} (woodcam.view.SceneOptions)")
        if options is not None and not isinstance(options, cls):  # a dict was an AttributeError ('camera')
            raise WoodcamError(f"options must be a woodcam.view.SceneOptions or None; got {type(options).__name__}; "
                               f"pass SceneOptions(**{{...}}) or the options as keywords (camera='top')")
        base = options if options is not None else cls()
        return replace(base, **keywords) if keywords else base

    def samples_cap(self, widget: bool) -> int:
        """The section's sample cap for a widget (interactive) or a one-off (screenshot) cut."""
        if self.max_samples is not None:
            return self.max_samples
        return SECTION_MAX_SAMPLES_INTERACTIVE if widget else SECTION_MAX_SAMPLES_SCREENSHOT


def build_scene(
    plotter: pv.Plotter,
    mesh_or_path: Mesh | trimesh.Scene | PathLike,
    *,
    wood: WoodLike | None = None,
    size_mm: ArrayLike | None = None,
    widget: bool = False,
    options: SceneOptions | None = None,
    **scene_options,
) -> CutPlaneCallback | None:
    """Fill a pyvista plotter with the part, the block and the cut plane; frame the camera.

    :func:`preview` calls this for both modes; it is public so that a notebook or a test can
    build the scene on its own plotter (off-screen plotters accept the plane widget too).

    Parameters
    ----------
    plotter : pyvista.Plotter
    mesh_or_path : trimesh.Trimesh, trimesh.Scene, str or Path
        The part in the block frame (mm), as :func:`preview` takes it.
    size_mm : (W, D, H) mm, optional
        The block, drawn as a translucent box; needed with ``wood``.
    widget : bool
        With ``cut_plane``: add the interactive plane widget (bounded by the block), whose
        callback redraws the cut as it is dragged. Without ``widget`` the cut is drawn once at
        ``cut_origin`` / ``cut_normal``, and only when a wood is given.
    options : SceneOptions, optional
        How to draw; ``**scene_options`` (any :class:`SceneOptions` field, e.g.
        ``camera="top"``) replace its fields.
    Other parameters as in :func:`preview`.

    Returns
    -------
    CutPlaneCallback or None
        The cut-plane callback when a cut is shown, else None.
    """
    opt = SceneOptions.merged(options, scene_options)
    _check_wood(wood)
    camera, cut_origin, cut_normal = opt.camera, opt.cut_origin, opt.cut_normal
    size = None if size_mm is None else check_size(size_mm)
    _check_size_with_wood(wood, size)
    part, texture = mesh_to_pyvista(mesh_or_path)
    bounds = (0.0, size[0], 0.0, size[1], 0.0, size[2]) if size is not None else part.bounds
    b = np.asarray(bounds, dtype=float).reshape(3, 2)
    origin = (b.mean(axis=1) if cut_origin is None
              else check_vector(cut_origin, "cut_origin", unit=False))
    normal = (default_cut_normal(camera, b[:, 1] - b[:, 0]) if cut_normal is None
              else check_vector(cut_normal, "cut_normal", unit=True))
    # top/bottom: the outside uncut unless a cut is asked for (camera.UNCUT_CAMERAS says why);
    # the widget starts on the face toward the camera, cutting nothing until it is dragged in
    uncut = camera in UNCUT_CAMERAS and cut_origin is None and cut_normal is None
    if uncut and widget:
        origin = origin.copy()
        origin[2] = b[2, 1] if normal[2] > 0 else b[2, 0]

    if opt.cut_plane and wood is not None and size is not None and (cut_origin is not None or cut_normal is not None):
        corners = np.stack(np.meshgrid(*b, indexing="ij"), axis=-1).reshape(-1, 3)
        side = (corners - origin) @ (np.asarray(normal, float) / np.linalg.norm(normal))
        if side.min() > 0.0 or side.max() < 0.0:
            # the picture showed the part uncut without a word (e.g. --cut-origin 500,0,0)
            import warnings

            from ..errors import WoodcamWarning

            warnings.warn(f"the cut plane through {say_length(origin, '.4g', form='({}, {}, {})')} with "
                          f"normal {tuple(round(float(v), 3) for v in normal)} misses the block (0 to "
                          f"{say_length(b[:, 1], '.4g')} along X, Y, Z), so nothing is cut; "
                          "give --cut-origin (cut_origin) a point inside the block", WoodcamWarning,
                          stacklevel=3)
    plotter.set_background(_pyvista_rgb(opt.background, "build_scene", "background"))
    if size is not None:
        _add_block(plotter, size)
    callback = None
    if opt.cut_plane and (widget or (wood is not None and not uncut)):
        callback = CutPlaneCallback(plotter, part, texture, wood, size,
                                    resolution_mm=opt.resolution_mm,
                                    max_samples=opt.samples_cap(widget))
        if widget:
            # The widget calls back once now, then at every move ("always": as it is dragged).
            plotter.add_plane_widget(callback, normal=normal, origin=origin, bounds=bounds,
                                     factor=1.0, interaction_event="always",
                                     outline_opacity=0.0)
        else:
            callback(normal, origin)
    else:
        _add_part(plotter, part, texture)
    # Frame the block and the part together (a part sticking out of its block stays in view).
    frame = np.stack([np.minimum(b[:, 0], np.asarray(part.bounds).reshape(3, 2)[:, 0]),
                      np.maximum(b[:, 1], np.asarray(part.bounds).reshape(3, 2)[:, 1])], axis=1)
    set_camera(plotter, camera, frame.ravel())
    return callback


def check_overlay(overlay) -> list[tuple[np.ndarray, object, float]]:
    """``overlay`` of :func:`preview` checked before a window opens: a list of ``(segments (k, 2, 3)
    finite mm, colour, width px > 0)``; returned with the segments as float arrays and a triple
    colour as floats in 0..1 (read by :func:`colour_rgb`, the numpy views' rule). A tuple of
    two, segments of another shape or NaN, a colour name pyvista did not know or a width of 0 or 'a'
    were bare unpacking/reshape errors or VTK's, after the scene was built."""
    if overlay is None:
        return []
    if isinstance(overlay, tuple) and len(overlay) == 3 and not isinstance(overlay[0], tuple):
        raise WoodcamError("overlay must be a list of (segments, colour, width) tuples; got one tuple; "
                           "pass [(segments, colour, width)]")
    try:
        items = list(overlay)
    except TypeError:
        items = None
    if items is None:
        raise WoodcamError(f"overlay must be a list of (segments, colour, width) tuples; got {overlay!r:.60}")
    out = []
    for i, item in enumerate(items):
        if not (isinstance(item, (tuple, list)) and len(item) == 3):
            raise WoodcamError(f"overlay[{i}] must be (segments (k, 2, 3) mm, colour, width px); got {item!r:.60}")
        segments, colour, width = item
        seg = as_floats(segments)
        if seg is None or (seg.size and (seg.ndim != 3 or seg.shape[1:] != (2, 3))) or not np.all(np.isfinite(seg)):
            got = f"shape {seg.shape}" if seg is not None and np.all(np.isfinite(seg)) else f"{segments!r:.60}"
            raise WoodcamError(f"overlay[{i}] segments must be a (k, 2, 3) array of finite mm (k line segments, "
                               f"start and end points in the block frame); got {got}")
        # by the numpy views' rule and name table (colour_rgb), handed to pyvista as floats in
        # 0..1: pyvista took (1.0, 0, 0) as red where top_view drew it nearly black, names of
        # its own table the numpy views refused, and None as its theme's colour
        colour = _pyvista_rgb(colour, "preview", f"overlay[{i}] colour")
        width = check_number(width, f"overlay[{i}] width", lo=0, lo_open=True, fix="line width in pixels, e.g. 2")
        out.append((seg.reshape(-1, 2, 3), colour, width))
    return out


def preview(
    mesh_or_path: Mesh | trimesh.Scene | PathLike,
    *,
    wood: WoodLike | None = None,
    size_mm: ArrayLike | None = None,
    screenshot: str | os.PathLike | None = None,
    window_size: tuple[int, int] = (1280, 960),
    options: SceneOptions | None = None,
    overlay: list[tuple] | None = None,
    **scene_options,
) -> Path | None:
    """Show a textured part inside its translucent block, or write a screenshot of it.

    Parameters
    ----------
    mesh_or_path : trimesh.Trimesh, trimesh.Scene, str or Path
        The part in the block frame (mm); a file is read with ``trimesh.load(force="mesh")``.
    wood : object with ``color(points_mm (n, 3), normals (n, 3)) -> rgb (n, 3)``, optional
        Colours the cut plane; without it there is no wood section.
    size_mm : (W, D, H) mm, optional
        The block; drawn as a translucent box. Needed with ``wood``. Without it the view frames
        the part's bounds.
    screenshot : path, optional
        Render off-screen (no display needed) and write this PNG; parent folders are created.
        Without it an interactive window opens (needs a display).
    window_size : (width, height) pixels
    options : SceneOptions, optional
        How to draw (cut plane, camera, background, initial cut, resolution);
        ``**scene_options`` (any :class:`SceneOptions` field, e.g. ``camera="top"``,
        ``cut_plane=False``) replace its fields.
    overlay : list of (segments (k, 2, 3) mm, colour, width px), optional
        Line segments drawn over the scene in the block frame (e.g. a toolpath: rapids and
        feeds in two colours, :func:`woodcam.toolpath.gcode.Program` moves). ``colour``: by
        :func:`colour_rgb`'s rule (a name or hex string of matplotlib's table, whole numbers
        in 0..255, floats in 0..1; None refused, as there), the same colour as top_view and
        stock_view draw.

    Returns
    -------
    Path or None
        The PNG written, or None after the interactive window closes.
    """
    pv = _pyvista()
    ws = np.asarray(window_size)
    if ws.shape != (2,) or not np.all(np.isfinite(ws)) or np.any(ws < 16) or np.any(ws % 1):
        raise WoodcamError(
            f"window_size must be two integers >= 16 (width, height) in pixels; got "
            f"{window_size!r}; e.g. (1280, 960)"
        )
    window_size = (int(ws[0]), int(ws[1]))
    if screenshot is not None and Path(screenshot).suffix.lower() != ".png":
        raise WoodcamError(
            f"screenshot must be a .png path; got {str(screenshot)!r}; e.g. out/part.png"
        )
    if screenshot is not None:  # before any rendering: not a folder, folder writable
        from .._atomic import check_output_path

        check_output_path(screenshot, what="screenshot", mkdir=True)
    if screenshot is None:
        check_display("preview", "render off-screen instead with screenshot='part.png' "
                      "(CLI: woodcam preview PART --screenshot part.png)")
    # Check the mesh and options before a window opens.
    opt = SceneOptions.merged(options, scene_options)
    overlay = check_overlay(overlay)
    _check_wood(wood)
    _check_size_with_wood(wood, None if size_mm is None else check_size(size_mm))
    mesh = _load_mesh(mesh_or_path)
    if size_mm is not None:
        # the part drawn reaching past its block (another --block than it was baked from) said
        # nothing here where review warned: one check, frames.check_part_in_block
        from ..frames import check_part_in_block

        who = (f"preview: {str(mesh_or_path)!r}" if isinstance(mesh_or_path, (str, os.PathLike))
               else "preview: the part")
        check_part_in_block(*np.asarray(mesh.bounds, dtype=float), check_size(size_mm), who,
                            shows="the cut plane", wholly_outside="warn")

    off_screen = screenshot is not None
    if off_screen:
        _prefer_egl_off_screen()
    plotter = _plotter(pv, off_screen=off_screen, window_size=window_size, title="woodcam preview")
    try:
        build_scene(plotter, mesh, wood=wood, size_mm=size_mm, widget=not off_screen, options=opt)
        for seg, colour, width in overlay:
            if len(seg):
                n = len(seg)
                cells = np.column_stack([np.full(n, 2), 2 * np.arange(n), 2 * np.arange(n) + 1])
                plotter.add_mesh(pv.PolyData(seg.reshape(-1, 3), lines=cells.ravel()),
                                 color=colour, line_width=width, render_lines_as_tubes=False)
        # Translucent block and waste wood over the part: sort them per pixel.
        plotter.enable_depth_peeling()
        plotter.enable_anti_aliasing("ssaa")
        if off_screen:
            from .._atomic import atomic_path

            path = Path(screenshot)
            with atomic_path(path, mkdir=True) as tmp:  # complete PNG or none
                plotter.screenshot(str(tmp))
            return path
        plotter.add_axes()
        add_view_keys(plotter, size_mm if size_mm is not None else mesh.bounds.T.ravel()[1::2])
        plotter.show()
        return None
    finally:
        plotter.close()


#: Keys of the interactive window (shown in its corner): view presets and toggles.
VIEW_KEYS = {"1": "front", "2": "top", "3": "left", "4": "right", "5": "iso"}
KEY_HELP = ("keys: 1 front  2 top  3 left  4 right  5 iso  o orthographic  h hide block  "
            "c cut face  r reset  q quit")


def add_view_keys(plotter, size_mm) -> None:
    """Key bindings and their on-screen help for the interactive window: view presets
    (:data:`VIEW_KEYS`), ``o`` orthographic on/off, ``h`` block and waste wood on/off, ``c`` the
    cut face (section, waste, outline) on/off."""
    W, D, H = (float(v) for v in size_mm)
    bounds = (0.0, W, 0.0, D, 0.0, H)

    def view(name):
        return lambda: (set_camera(plotter, name, bounds), plotter.render())

    def toggle(*names):
        def flip():
            actors = [plotter.actors[n] for n in names if n in plotter.actors]
            visible = not all(a.GetVisibility() for a in actors) if actors else True
            for a in actors:
                a.SetVisibility(visible)
            plotter.render()
        return flip

    def ortho():
        plotter.camera.parallel_projection = not plotter.camera.parallel_projection
        plotter.render()

    for key, name in VIEW_KEYS.items():
        plotter.add_key_event(key, view(name))
    plotter.add_key_event("o", ortho)
    plotter.add_key_event("h", toggle("woodcam-block", "woodcam-block-edges", WASTE_ACTOR))
    plotter.add_key_event("c", toggle(SECTION_ACTOR, WASTE_ACTOR, OUTLINE_ACTOR))
    plotter.add_text(KEY_HELP, position="lower_left", font_size=9, name="woodcam-keys")
