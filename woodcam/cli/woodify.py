"""``woodcam woodify``: grow a mesh like a tree and write its field, surfaces, sections and bark.

Writes into ``--out``: ``field.npz`` (the grown object's growth field; a block spec
``woodify:OUT/field.npz`` for ``bake``/``gcode``/``preview``), ``grown.glb`` (final surface,
bark-textured, with cracks), ``surface_yNN.stl`` (watertight grown surfaces at chosen years, mm
in the input mesh's frame, as their STL headers say), ``section_xz.png`` / ``section_xy.png``
(ring sections through the block centre, seed Fig. 5.1, a scale bar in --units below each) and
``woodify.json`` (parameters, grid, solver, timings). Every file is written atomically.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from .._specs import WOODIFY_FIELD_FILE
from ..errors import UsageError, WoodcamError
from ..tolerances import DEFAULT_MAX_ATLAS_PX
from ..units import MM_PER_UNIT, TYPED_DECIMALS, say_length, typed_length
from .options import (add_input, add_max_atlas_option, add_max_triangles_option, add_out_option, add_units_option,
                      as_typed, part_suffixes, place_op_in, sizes_type, vector_type)


def register(subparsers) -> argparse.ArgumentParser:
    """Add the ``woodify`` command."""
    p = subparsers.add_parser(
        "woodify", help="grow a mesh like a tree: rings, obstacles, bark and cracks (seed 004)",
        description="Grow a watertight part or mesh outward year by year (Weibull speed, "
        "eccentricity, obstacles, brushes), then write its growth field (usable as --block "
        "woodify:OUT/field.npz), grown surfaces, ring sections and a bark-textured grown.glb. "
        "Lengths in mm (the options' in --units), time in years.")
    add_input(p, "part", kind="file", suffixes=_part_suffixes,
              help="input: a .py part script, .step, or a closed .stl/.obj/.ply/.glb mesh "
                   "(read as mm whatever --units says, a STEP from its own units; one under 1 mm long gets a "
                   "warning that it looks saved in metres, one under 6.35 mm that it looks saved in inches); a "
                   "PLY may paint growth per vertex: properties gain (speed gain) and dir_x, dir_y, dir_z "
                   "(growth direction, length = strength < 1)")
    p.add_argument("--years", type=float, required=True, help="years to grow")
    add_out_option(p, "field.npz, grown.glb, surfaces and section PNGs, woodify.json, listed in "
                      ".woodcam-woodify-files.json")
    p.add_argument("--growth", type=float, default=None, metavar="LEN",
                   help="how far a flat surface grows in --years (in --units); default a quarter of the "
                   "input's largest side")
    p.add_argument("--time-scale", type=float, default=None, metavar="YEARS",
                   help="Weibull time scale lambda (years); default --years")
    p.add_argument("--shape", type=float, default=2.0, help="Weibull shape c of eq. 4.1 (default 2)")
    p.add_argument("--eccentricity", type=float, default=0.0,
                   help="delta in (-1, 1): speed (1 + delta n.up) (default 0)")
    p.add_argument("--up", default="0,0,1", metavar="X,Y,Z",
                   type=vector_type("--up", example="0,0,1", nonzero=True),
                   help="direction the eccentric growth favours (unit-normalised; default 0,0,1)")
    add_input(p, "--obstacle", kind="file", suffixes=_part_suffixes, type=Path, action="append", default=[],
                   metavar="MESH", help="closed obstacle mesh or part (read as mm; one under 1 mm long gets the "
              "metres warning, one under 6.35 mm the inches one only where the part is that small too); repeatable")
    add_input(p, "--brushes", kind="file", type=Path, default=None, metavar="JSON",
                   help="growth brushes (centre_mm, radius_mm, gain, direction, strength)")
    p.add_argument("--resolution", type=int, metavar="N", default=128,
                   help="grid nodes along the longest side (default 128); a run takes about "
                   "180 bytes a grid node, and a grid over WOODCAM_MAX_ALLOC_BYTES (4 GiB) is refused, naming the "
                   "finest resolution that fits")
    p.add_argument("--method", choices=("auto", "fmm", "offset", "anisotropic"), default="auto",
                   help="front solver (default auto: fmm if isotropic, offset for eccentricity "
                   "without obstacles, anisotropic otherwise)")
    p.add_argument("--surface-years", default=None, metavar="Y1,Y2,..",
                   help="also write watertight surfaces at these years (default: quarters of --years)")
    p.add_argument("--block-size", default=None, metavar="WxDxH", type=sizes_type("--block-size"),
                   help="size of the block cut from the grown object (in --units); default the grown "
                   "object's bounding box")
    p.add_argument("--block-centre", default=None, metavar="X,Y,Z", type=vector_type("--block-centre"),
                   help="centre of that block in the input's frame (in --units); default the grown "
                   "object's bounding-box centre; one outside the grown object's box is refused (write "
                   "--block-centre=-9,0,35 when the first value is negative)")
    p.add_argument("--cracks", choices=("none", "stress", "vertical", "horizontal", "random"),
                   default="stress", help="bark crack pattern (default stress: natural directions)")
    p.add_argument("--crack-region", default=None, metavar="X,Y,Z,R",
                   type=vector_type("--crack-region", "X,Y,Z,R", "0,0,50,10"),
                   help="only crack within this sphere (centre and radius in --units; default: none, cracks "
                   "anywhere on the bark)")
    add_units_option(p, "woodify")
    p.add_argument("--crack-years", type=int, metavar="N", default=None,
                   help="last years simulated for cracks, at most --years (default 5, or the whole "
                   "years grown when fewer; under a year's growth, from the input on)")
    p.add_argument("--crack-render", choices=("groove", "material"), default=None,
                   help="draw cracks into the bark texture (material, default) or cut them as grooves")
    p.add_argument("--crack-threshold", type=float, default=None,
                   help="separation eigenvalue that opens a crack (a triangle's area times its bark strain per "
                   "length at unit stiffness, so in mm; default 2x the median of the first simulated year)")
    p.add_argument("--relief", type=float, default=None,
                   help="stress left next to a new crack, in [0, 1] (0 removes all; default 0.3)")
    p.add_argument("--seed", type=int, metavar="N", default=0,
                   help="random seed of the procedural bark and random cracks (default 0)")
    add_max_atlas_option(p, given_only=True)  # None unless typed: a kept picture warns
    # load_part's budget simplified a script, STEP or union over it with a warning naming this
    # option, which woodify lacked; a file of one mesh is grown as it is (its picture, its
    # painted growth per vertex kept), as before
    add_max_triangles_option(p, "the part and each --obstacle read as a part (a .py script, .step, or a file of "
                             "several meshes, grown as their union; a file of one mesh keeps every triangle, and "
                             "its picture and painted growth with them)", mesh="such a union of meshes (GLB, OBJ)")
    p.set_defaults(func=run)
    return p


#: The mesh files :func:`_load_mesh` reads with trimesh (painted PLYs and OFFs included); any
#: other part goes to :func:`woodcam.cad.load_part`.
_MESH_SUFFIXES = (".stl", ".obj", ".ply", ".glb", ".gltf", ".off")


def _part_suffixes() -> tuple[str, ...]:
    """The suffixes a part or ``--obstacle`` may have: :data:`_MESH_SUFFIXES` and
    :func:`~woodcam.cli.options.part_suffixes` (the input door's list)."""
    return tuple(dict.fromkeys((*_MESH_SUFFIXES, *part_suffixes())))


def _load_mesh(path: str, what: str = "part", max_triangles: int | None = None, inches: bool = True):
    """(watertight geometry, textured original or None) from a part or mesh file; ``what`` names
    it in messages (``part``, ``--obstacle``). ``max_triangles`` (``--max-triangles``; None:
    load_part's default) bounds what :func:`woodcam.cad.load_part` reads: a script, a STEP, a
    file of several meshes; a file of one mesh keeps every triangle. ``inches``: whether its size
    alone may say it was saved in inches (:func:`_warn_units`)."""
    import trimesh

    pth = Path(path)
    if pth.suffix.lower() in _MESH_SUFFIXES:
        try:
            if pth.suffix.lower() in (".glb", ".gltf", ".obj") and _mesh_count(pth) > 1:
                return _several_meshes(pth, what, max_triangles, inches)
            if pth.suffix.lower() in (".glb", ".gltf", ".obj"):
                from ..export import load_textured  # undoes woodcam's glTF/OBJ frame

                loaded = load_textured(pth)
            elif pth.suffix.lower() == ".ply":
                loaded = trimesh.load(pth, force="mesh", process=False)  # keep vertex order
            else:
                loaded = trimesh.load(pth, force="mesh", process=False)  # NaN kept: named below
        except WoodcamError:
            raise
        except Exception as err:  # trimesh raises many kinds for unreadable files
            raise WoodcamError(f"{what} {path!r} could not be read as a mesh: {err}") from err
        _check_mesh_values(loaded, path, what)
        if max_triangles is not None and len(loaded.faces) > max_triangles:
            import warnings

            from ..errors import WoodcamWarning

            # the budget bounds what load_part reads: given for one mesh, it was taken to have done so
            warnings.warn(f"{what} {path!r} has {len(loaded.faces)} triangles, over --max-triangles {max_triangles}, "
                          "and grows with every one: a file of one mesh is read as it is (its picture and painted "
                          "growth kept with its triangles); simplify it in your CAD program if the growth is slow",
                          WoodcamWarning, stacklevel=3)
        textured = loaded if getattr(loaded.visual, "uv", None) is not None else None
        _warn_units(loaded, path, what, inches)
        paint = _ply_paint(loaded, path)
        if paint:
            if not loaded.is_watertight:
                raise WoodcamError(
                    f"{what} {path!r} carries growth attributes per vertex, so it must be watertight "
                    "as stored (shared vertices), without merging; weld its vertices first")
            return loaded, None, paint
        geom, kept = _welded_closed(loaded, f"{what} {path!r}", kept=True)
        if textured is not None and not kept.all():  # its picture on the triangles that grow
            textured = textured.copy()
            textured.update_faces(kept)
        if textured is not None and len(geom.faces) != len(textured.faces):
            textured = None
        return geom, textured, {}
    from .._manifold import manifold_to_trimesh
    from ..cad import load_part

    geom = manifold_to_trimesh(load_part(path, **_budget(max_triangles)), process=True)
    _warn_units(geom, path, what, inches)  # a script's or STEP's size as a mesh's (units_note's words of its kind)
    return geom, None, {}


def _budget(max_triangles: int | None) -> dict:
    """load_part's ``max_triangles`` keyword where ``--max-triangles`` was given (its own default
    otherwise)."""
    return {} if max_triangles is None else {"max_triangles": max_triangles}


def _welded_closed(mesh, name: str, fix: str | None = None, *, kept: bool = False):
    """``mesh`` welded (by position, texture and normal seams too) as the growth reads it, its
    triangles that enclose nothing dropped as ``woodcam bake`` drops them
    (:func:`woodcam.cad.parts.drop_degenerate_faces`: a repeated corner, a triangle written
    twice, which were refused as open edges), refused unless closed (the growth's own
    check_watertight) with ``name`` (the option and the file): the growth said 'obstacles[0]
    must be watertight' of an open --obstacle, and 'mesh ...' of the part, naming neither. The
    one check of a file's meshes, one or several; ``fix`` replaces the growth's repair hint
    where the caller knows the cause. ``kept``: also return the mask ``(f,) bool`` of
    ``mesh``'s triangles kept."""
    import trimesh

    from ..cad.parts import drop_degenerate_faces
    from ..woodify.front import check_watertight

    geom = trimesh.Trimesh(mesh.vertices, mesh.faces, process=True)
    geom.merge_vertices(merge_tex=True, merge_norm=True)
    mask = drop_degenerate_faces(geom, name, stacklevel=5)
    closed = check_watertight(geom, name, fix=fix)
    return (closed, mask) if kept else closed


def _check_mesh_values(mesh, path: str, what: str) -> None:
    """One error for a mesh file with no triangles (an empty STL was an internal error) or a
    vertex that is not a number (its triangles were dropped as the mesh was welded, and the rest
    refused as not watertight, naming neither the NaN nor the file)."""
    import numpy as np

    faces = getattr(mesh, "faces", None)
    if faces is None or len(faces) == 0:
        raise WoodcamError(f"{what} {path!r} holds no triangles (an empty file, or points only); "
                           "give a closed (watertight) triangle mesh")
    bad = ~np.isfinite(np.asarray(mesh.vertices, float)).all(axis=1)
    if bad.any():
        raise WoodcamError(f"{what} {path!r} has {int(bad.sum())} of {len(bad)} vertices that are not "
                           "finite numbers (NaN or inf); fix the mesh in the program that wrote it "
                           "and export it again")


def _mesh_count(path: Path) -> int:
    """Placed mesh instances in a GLB/glTF/OBJ file (a mesh placed twice counts twice)."""
    import trimesh

    scene = trimesh.load_scene(str(path), file_type=path.suffix.lower().lstrip("."))
    return sum(isinstance(scene.geometry.get(scene.graph[n][1]), trimesh.Trimesh)
               for n in scene.graph.nodes_geometry)


def _several_meshes(path: Path, what: str, max_triangles: int | None = None, inches: bool = True):
    """(geometry, None, {}) of a file of several meshes: their union as one closed solid, read
    as a part (:func:`woodcam.cad.load_part`, woodcam's own glTF/OBJ frame undone); only the
    first of them grew before (load_textured's refusal for a GLB, a mesh placed twice read as
    its first placement). Their pictures are not carried (one bark picture, one set of UVs)."""
    import warnings

    import trimesh

    from .._manifold import manifold_to_trimesh
    from ..cad import load_part
    from ..errors import WoodcamWarning

    scene = trimesh.load_scene(str(path), file_type=path.suffix.lower().lstrip("."))
    placed = dict.fromkeys(scene.graph[n][1] for n in scene.graph.nodes_geometry)
    meshes = {k: scene.geometry[k] for k in placed
              if isinstance(scene.geometry.get(k), trimesh.Trimesh)}
    # each as a one-mesh file is checked: load_part capped an open one's flat hole (a
    # one-mesh file is refused) and refused another as 'mesh file ...', not naming the option
    for key, mesh in meshes.items():
        _welded_closed(mesh, f"{what} {str(path)!r} (its mesh {key!r})")
    if any(getattr(getattr(g, "visual", None), "uv", None) is not None for g in meshes.values()):
        warnings.warn(f"{what} {str(path)!r} holds {_mesh_count(path)} meshes: they grow as one solid "
                      "(their union), and their pictures are not carried to the bark (procedural bark "
                      "instead); join them into one textured mesh to keep a picture", WoodcamWarning, stacklevel=3)
    # the union too: two closed meshes touching along an edge share it four times, which the
    # growth refused as 'mesh must be watertight' / 'obstacles[0] ...'; each mesh is closed
    # here, so hole filling is not the fix (it suggested trimesh.repair.fill_holes)
    geom = _welded_closed(manifold_to_trimesh(load_part(path, **_budget(max_triangles)), process=True),
                          f"{what} {str(path)!r} (the union of its {len(meshes)} meshes)",
                          fix="each mesh is closed, but they touch along an edge or at a vertex, "
                          "so their union is not a manifold solid (non-manifold union); separate "
                          "them (leave a gap) or merge them into one solid in the CAD program, "
                          "and export again")
    _warn_units(geom, str(path), what, inches)
    return geom, None, {}


def _warn_units(mesh, path: str, what: str = "part", inches: bool = True) -> None:
    """Warn when a part's size says it was saved in metres or inches: it is read as mm, and a
    40 mm box saved as 0.04 grew, silently, into a 0.06 mm speck, a 4-inch bowl saved as 4
    into a 4 mm one (woodcam.cad.carve.units_hint, its size alone: there is no block; in the
    words of the file's kind, woodcam.cad.carve.units_note: a mesh, a script, a STEP).
    ``inches`` False: the metres check only (an --obstacle beside a part of real size: see
    :func:`_obstacle_inches`)."""
    import warnings

    from ..cad.carve import units_hint
    from ..errors import WoodcamWarning

    lo, hi = mesh.bounds
    noun = "obstacle" if what == "--obstacle" else "part"
    # the fix names the file's own thing too: an obstacle's said "never the part's own"
    hint = units_hint(lo, hi, None, "in your CAD program (--units converts only the lengths typed as options, "
                      f"never the {noun}'s own)", source=path, inches=inches, noun=noun)
    if hint:
        warnings.warn(f"{what} {path!r}: {hint}", WoodcamWarning, stacklevel=3)


def _obstacle_inches(part) -> bool:
    """Whether an ``--obstacle``'s size alone may say it was saved in inches: only where the
    part's may, its longest side under :data:`woodcam.tolerances.INCHES_BELOW_MM` (the scene
    looks saved in inches). An obstacle is judged beside the part it stands by, not as a part
    carved alone: a 5 mm pin by a 40 mm part is a real obstacle, and was warned of as a
    5-inch one."""
    import numpy as np

    from ..tolerances import INCHES_BELOW_MM

    lo, hi = part.bounds
    return float(np.max(np.asarray(hi) - np.asarray(lo))) < INCHES_BELOW_MM


def _ply_paint(mesh, path) -> dict:
    """Painted growth from a PLY's vertex properties: ``gain`` (speed gain > 0) and
    ``dir_x, dir_y, dir_z`` (growth direction, its length the strength < 1), seed sec. 4.2.2."""
    import numpy as np

    raw = mesh.metadata.get("_ply_raw", {}).get("vertex", {}).get("data")
    names = () if raw is None or raw.dtype.names is None else raw.dtype.names
    out = {}
    if "gain" in names:
        out["vertex_gain"] = np.asarray(raw["gain"], float).reshape(-1)
    if all(k in names for k in ("dir_x", "dir_y", "dir_z")):
        out["vertex_direction"] = np.stack([np.asarray(raw[k], float).reshape(-1)
                                            for k in ("dir_x", "dir_y", "dir_z")], axis=1)
    for k, v in out.items():
        if len(v) != len(mesh.vertices):
            raise WoodcamError(f"part {path!r}: vertex property {k} has {len(v)} values for "
                               f"{len(mesh.vertices)} vertices")
    return out


def _atomic(path: Path, write) -> Path:
    """Call ``write(tmp_path)`` and move the temporary file onto ``path`` (woodcam._atomic)."""
    from .._atomic import atomic_path

    with atomic_path(path, mkdir=True) as tmp:
        write(tmp)
    return Path(path)


def _write_outputs(res, out, *, textured=None, surface_years=(), block_size_mm=None,
                  block_centre_mm=None, cracks="stress", crack_region=None, crack_years=5,
                  crack_render="material", crack_threshold=None, relief=0.3, seed=0,
                  max_atlas_px=None, units="mm", atomic=_atomic, stage=None):
    """Write the products of a :class:`~woodcam.woodify.Woodification` into ``out`` (module
    docstring); returns (files written, summary dict). ``max_atlas_px``: the bark atlas's
    largest side, None for :data:`~woodcam.tolerances.DEFAULT_MAX_ATLAS_PX` (a value given where
    no atlas is baked warns). ``units``: of the ring sections' scale bars ("mm" or "inch", the
    run's --units). ``stage(name)``: a context manager round
    each of "surface and cracks", "bark and surfaces" and "ring sections" (a
    :meth:`woodcam._progress.StageBar.stage`; default none)."""
    from contextlib import nullcontext
    import numpy as np
    from PIL import Image

    from ..export import export_glb, stl_bytes
    from ..woodify.bark import (
        BARK_TEXELS_PER_VOXEL,
        CRACK_WIDTH_VOXELS,
        SolidBark,
        corner_uv,
        groove,
        paint_crack_faces,
        picture_density,
        textured_mesh,
    )
    from ..woodify.cracks import simulate_cracks
    from ..woodify.surfaces import barycentric_on, carry, section_image, with_scale_bar

    stage = stage or (lambda name: nullcontext())
    out = Path(out)
    files = []
    Y = res.years
    summary = {"years": Y, "speed": res.speed.to_dict(), "method": res.front.method,
               "grid": {"shape": list(res.front.grid.shape), "spacing_mm": res.front.grid.spacing_mm,
                        "origin_mm": list(res.front.grid.origin_mm)},
               "timings": dict(res.timings)}
    with stage("surface and cracks"):
        t = time.perf_counter()
        crack_edges = np.zeros((0, 2), int)
        if cracks != "none":
            n = int(crack_years)
            if n < 1:
                raise WoodcamError(f"crack_years (--crack-years) must be >= 1; got {crack_years!r}")
            ys = [max(Y - n + k, 0.0) for k in range(n + 1)]
            ys = sorted(set(ys))
            cs = simulate_cracks(res, ys, pattern=cracks, region=crack_region, threshold=crack_threshold,
                                 relief=relief, seed=seed)
            mesh, origins, tri = cs.mesh, cs.origins_mm, cs.tri
            crack_edges = cs.crack_edges
            summary["cracks"] = {"pattern": cracks, "log": cs.log, "count": len(cs.crack_directions),
                                 "render": crack_render}
        else:
            mesh = res.surface(Y)
            origins, tri = res.origins(mesh.vertices)
        summary["timings"]["cracks_s" if cracks != "none" else "surface_s"] = time.perf_counter() - t
    with stage("bark and surfaces"):
        # persistent texture: the input's own UVs and image, else solid bark (below)
        image = None
        if textured is not None:
            _, bary = barycentric_on(textured, origins, tri)
            uv = carry(textured, textured.visual.uv, tri, bary)
            mat = textured.visual.material
            img = getattr(mat, "baseColorTexture", None) or getattr(mat, "image", None)
            image = np.asarray(img.convert("RGB")) if img is not None else None
        procedural = image is None
        h = res.front.grid.spacing_mm
        if crack_render == "groove" and len(crack_edges):
            width = np.zeros(len(mesh.vertices))
            width[crack_edges.ravel()] = 1.0
            mesh = groove(mesh, width, 0.6 * h)
        painted = crack_render == "material" and len(crack_edges) > 0
        if procedural or painted:
            # Bark as a solid texture round the stem, baked into an atlas of even texel density:
            # a picture laid on by cylindrical coordinates was squeezed to a line on every face
            # that does not face away from the stem (a flat lid, a rim grown from a sharp edge),
            # which showed as radial streaks and drew cracks there into one band. Now the
            # bark's plates and a crack's share of the bark per mm are the same wherever they lie.
            # An input's own picture is moved into such an atlas too when cracks are drawn into
            # it: drawn into the picture at its own scale, a crack was as many mm wide as its
            # texels (2 px of a 256 px picture round a trunk: 1.3 mm) and piled up where the
            # input's UVs squeeze (a lid on one row), showing 2.3x the crack share of the same
            # cracks on the untextured input. Never coarser than the picture was (on 95 % of
            # the surface: picture_density; the atlas limit may still lower it, with a warning).
            from ..bake import bake, rebake_texture

            tpm = BARK_TEXELS_PER_VOXEL / h
            atlas_px = DEFAULT_MAX_ATLAS_PX if max_atlas_px is None else max_atlas_px
            if procedural:
                up = res.field.stem_axis
                c = res.mesh.centroid
                d = np.asarray(res.mesh.vertices) - c
                girth = 2 * np.pi * max(float(np.linalg.norm(d - np.outer(d @ up, up), axis=1).mean()), 1e-3)
                baked = bake(mesh, SolidBark(up, c, girth, seed), texels_per_mm=tpm,
                             max_atlas_px=atlas_px)
            else:
                corners = corner_uv(uv, mesh.faces)
                baked = rebake_texture(mesh, corners, image,
                                       texels_per_mm=max(tpm, picture_density(mesh, corners, image)),
                                       max_atlas_px=atlas_px)
            bark = baked.mesh
            if painted:
                atlas = np.asarray(bark.visual.material.baseColorTexture)
                ah, aw = atlas.shape[:2]
                xy = np.asarray(bark.visual.uv) * [aw, ah]
                xy[:, 1] = ah - xy[:, 1]
                width_px = max(1, round(CRACK_WIDTH_VOXELS * h * baked.texels_per_mm))
                atlas = paint_crack_faces(atlas, xy[bark.faces], mesh.faces, crack_edges, width_px)
                bark.visual.material.baseColorTexture = Image.fromarray(atlas)
        else:
            # the input's own picture and coordinates stay as they were given
            if max_atlas_px is not None:  # given (even as the default's 4096) for nothing
                import warnings

                from ..errors import WoodcamWarning

                warnings.warn(
                    f"woodify: --max-atlas {max_atlas_px} has no effect: the input's own picture "
                    f"is kept as given (no crack is drawn into it); drop --max-atlas",
                    WoodcamWarning, stacklevel=2)
            bark = textured_mesh(mesh, uv, image)
        # the block cut from the grown object: default its bounding box
        lo, hi = mesh.bounds
        size = tuple(hi - lo) if block_size_mm is None else tuple(block_size_mm)
        centre = tuple((lo + hi) / 2) if block_centre_mm is None else tuple(block_centre_mm)
        _say_block_past_the_wood(lo, hi, size, centre, res.front.grid.spacing_mm, Y,
                                 block_size_mm is not None, block_centre_mm is not None)
        placed = res.field.placed(size, centre)
        # a woodcam GLB is in the block frame (its metadata says so, and `review --block
        # woodify:field.npz` reads it so): object = block_origin + R @ block, so block = R^T (object
        # - block_origin); the origin is kept in the metadata to put it back over the input mesh
        bark.vertices = placed.to_block(bark.vertices)
        # export_glb writes atomically itself (through atomic(), its temporary would be renamed
        # before export_glb's own one, inside the caller's all_or_nothing)
        files.append(export_glb(bark, out / "grown.glb", metadata={
            "woodify": {"years": Y, "speed": res.speed.to_dict(),
                        "block_origin_mm": placed.block_origin_mm.tolist(),
                        "block_rotation": placed.rotation.tolist()}}))
        files.append(placed.save(out / WOODIFY_FIELD_FILE))
        # the input's frame -> the block frame: a part is modelled in the block frame, as for
        # every block; this translate puts the input where it grew (WoodifiedField.to_block)
        summary["block"] = {"size_mm": list(size), "centre_mm": list(centre),
                            "input_translate_mm": placed.to_block(np.zeros((1, 3)))[0].tolist()}
        for y in surface_years:
            surf = res.surface(float(y))
            note = f"woodify surface at year {float(y):g}, in the input mesh's frame"
            files.append(atomic(out / f"surface_y{float(y):g}.stl",
                                lambda p, s=surf, n=note: p.write_bytes(stl_bytes(s, n))))
    with stage("ring sections"):
        # ring sections through the block centre (seed Fig. 5.1)
        g = res.front.grid
        ext = (np.asarray(g.shape) - 1) * g.spacing_mm
        o = np.asarray(g.origin_mm)
        cc = np.asarray(centre)
        px = 640
        f = res.field

        def inside(p):
            return f.arrival(p) <= 0

        for name, (a, b) in {"xz": (0, 2), "xy": (0, 1)}.items():
            origin = cc.copy()
            origin[a], origin[b] = o[a], o[b]
            u = np.zeros(3)
            v = np.zeros(3)
            u[a], v[b] = ext[a], ext[b]
            rows = max(int(px * ext[b] / ext[a]), 16)
            img = section_image(f, f.no_wood, inside, origin, u, v, (rows, px), years_final=Y)
            # a scale bar below it (a round length in --units): the picture alone told no size
            img, _ = with_scale_bar(img, ext[a] / px, units)
            files.append(atomic(out / f"section_{name}.png",
                                lambda p, im=img: Image.fromarray(im).save(p, format="PNG")))
    return files, summary


def _say_block_past_the_wood(lo, hi, size, centre, spacing_mm: float, years: float, size_given: bool,
                             centre_given: bool) -> None:
    """A WoodcamWarning when the block cut from the grown object (``size`` about ``centre``, mm)
    reaches more than a grid step past the grown object's box ``lo``..``hi``: that part of it is
    air round the object, wood never grown, which field.npz fills with years past those grown (a
    100 mm part carved 500 mm out in a --block-size 1000x1000x1000 of a 30 mm grown ball baked
    as plain straight grain, with no word). The centre's own check (``_check_block_centre``)
    refuses a centre outside the box."""
    import warnings

    import numpy as np

    from ..errors import WoodcamWarning

    lo, hi, c, half = (np.asarray(v, float) for v in (lo, hi, centre, np.asarray(size, float) / 2))
    past = float(np.max(np.maximum(lo - (c - half), (c + half) - hi)))
    if past <= spacing_mm:
        return
    room = 2 * np.maximum(np.minimum(c - lo, hi - c), 0.0)
    opts = " and ".join(o for o, on in (("--block-size", size_given), ("--block-centre", centre_given)) if on)
    box = say_length([v for pair in zip(lo, hi) for v in pair], ".4g", form="x [{}, {}], y [{}, {}], z [{}, {}]")
    warnings.warn(
        f"the block cut from the grown object ({say_length(size, '.4g', ' x ')} about "
        f"{say_length(np.round(c, 3) + 0.0, '.4g', ',')}, {opts}) reaches {say_length(past, '.4g')} past the grown "
        f"object's box ({box}): that part of it is air round the object, wood never grown, which field.npz fills "
        f"with years past the {years:g} grown (a bake shows wood there); keep the block within that box "
        f"(--block-size at most {say_length(room, '.4g', 'x')} about that centre), or leave {opts} out for the "
        "grown object's own box", WoodcamWarning, stacklevel=2)


def _check_block_centre(res, args) -> None:
    """A ``--block-centre`` outside the grown object's box is refused (exit 2): its block was cut
    from the air round the object, a ``field.npz`` of wood never grown (a bake from it said
    "years 18.6 to 18.6 of the 5 grown"), and the ring sections drawn through that centre were
    blank PNGs. Checked after the growth, the only time the grown box is known, before the
    crack stage and any file is written."""
    import numpy as np

    if args.block_centre is None:  # the default is the grown object's own centre
        return
    g = res.front.grid
    wood = res.front.arrival_mm <= res.tau(res.years)
    if not wood.any():  # nothing grown to cut from: the growth's own checks say why
        return
    lo, hi = np.empty(3), np.empty(3)
    for ax in range(3):
        idx = np.flatnonzero(wood.any(axis=tuple(a for a in range(3) if a != ax)))
        lo[ax] = g.origin_mm[ax] + idx[0] * g.spacing_mm
        hi[ax] = g.origin_mm[ax] + idx[-1] * g.spacing_mm
    # the grown surface lies between the outermost wood node and the next node out: said half
    # a spacing out, a centre taken up to a whole spacing out (the surface may reach that far)
    c = np.asarray(args.block_centre, float)
    if np.all((c >= lo - g.spacing_mm) & (c <= hi + g.spacing_mm)):
        return
    lo, hi = lo - g.spacing_mm / 2, hi + g.spacing_mm / 2
    typed = ",".join(f"{v:g}" for v in as_typed(args, "block_centre"))
    box = say_length([v for pair in zip(lo, hi) for v in pair], ".4g",
                     form="x [{}, {}], y [{}, {}], z [{}, {}]")
    centre = ",".join(typed_length(v, 0.5 * g.spacing_mm) for v in (lo + hi) / 2)
    raise UsageError(f"--block-centre {typed}: the block's centre lies outside the grown object's "
                     f"box ({box}), so its block would be cut from the air round the object, wood "
                     f"never grown, and the ring sections through it would show none; give a centre "
                     f"within that box, e.g. --block-centre={centre} near its middle, or leave --block-centre "
                     "out for the grown object's own centre")


def run(args) -> int:
    """Run a parsed ``woodify`` command; returns the exit status."""
    import numpy as np
    from .._progress import StageBar

    from ..woodify import load_brushes, woodify

    t0 = time.perf_counter()
    if not (np.isfinite(args.years) and args.years > 0):
        raise WoodcamError(f"--years must be > 0 (years to grow); got {args.years:g}")
    # every option checked before the growth (minutes on a fine grid); a wrong one is a wrong
    # command line (exit 2, as the ranges of RANGES), not a failed run
    if args.surface_years:
        try:
            years = [float(v) for v in args.surface_years.split(",")]
        except ValueError:
            years = [-1.0]
        if not all(0 <= y <= args.years for y in years):
            raise UsageError(f"--surface-years takes comma-separated years in [0, {args.years:g}] "
                             f"(--years); got {args.surface_years!r}; e.g. --surface-years "
                             f"{args.years / 2:g},{args.years:g}")
        # one file a year (surface_y<year:g>.stl): a year given twice was grown and written twice
        # and listed twice; two years of one name overwrote each other
        names = {}
        for y in years:
            if names.setdefault(f"{y:g}", y) != y:
                raise UsageError(f"--surface-years {names[f'{y:g}']!r} and {y!r} would both be written as "
                                 f"surface_y{y:g}.stl; give years that differ in their first 6 digits")
        years = list(names.values())
    else:
        years = [args.years * k / 4 for k in (1, 2, 3)]
    # the options that shape the cracks (None: not typed) were dropped without a word by
    # --cracks none, which draws none: a user who typed them took them to have done something
    crack_opts = ("crack_years", "crack_region", "crack_render", "crack_threshold", "relief")
    if args.cracks == "none" and any(getattr(args, d) is not None for d in crack_opts):
        import warnings

        from ..errors import WoodcamWarning

        typed = ", ".join("--" + d.replace("_", "-") for d in crack_opts if getattr(args, d) is not None)
        warnings.warn(f"{typed} shape the bark's cracks, and --cracks none draws none, so they change "
                      "nothing here; drop them, or give a crack pattern (--cracks stress, the default)",
                      WoodcamWarning, stacklevel=2)
    args.crack_render = args.crack_render or "material"
    args.relief = 0.3 if args.relief is None else args.relief
    # the crack stage simulates the last --crack-years of the growth: more than were grown began
    # before the input existed (silently clamped to year 0); the default is 5 or every year grown
    if args.crack_years is None:
        args.crack_years = min(5, max(1, int(args.years)))
    elif args.cracks != "none" and args.crack_years > args.years:
        fix = (f"give --crack-years {int(args.years)} or fewer, or grow longer" if args.years >= 1 else
               "leave --crack-years out (under a year's growth the cracks grow from the input on)")
        raise UsageError(f"--crack-years must be at most --years ({args.years:g}): it simulates the last "
                         f"years of the growth; got {args.crack_years}; {fix}")
    region = args.crack_region
    if region is not None and not region[3] > 0:
        raise UsageError(f"--crack-region X,Y,Z,R needs a radius R > 0; got R = {say_length(region[3], 'g')}; "
                         "e.g. --crack-region 0,0,50,10, or leave it out for cracks anywhere on the bark")
    from .._atomic import all_or_nothing, manifest_path, remove_stale

    # A bar of stages whose timer draws it 2 s in even mid-stage: the bar of plain updates this
    # was drew nothing until a stage ended (a 13 s growth on a 160^3 grid showed none at all).
    with StageBar(["read the mesh", "grow", "surface and cracks", "bark and surfaces", "ring sections"],
                  desc="woodify", leave=False) as bar:
        with bar.stage("read the mesh"):
            mesh, textured, painted = _load_mesh(args.part, max_triangles=args.max_triangles)
            inches = _obstacle_inches(mesh)  # a small obstacle by a part of real size is a real one
            obstacles = [_load_mesh(str(o), "--obstacle", args.max_triangles, inches)[0] for o in args.obstacle]
            brushes = load_brushes(args.brushes) if args.brushes else ()
        with bar.stage("grow"):
            res = woodify(mesh, args.years, growth_mm=args.growth, time_scale_years=args.time_scale,
                          shape=args.shape, eccentricity=args.eccentricity, up=args.up,
                          obstacles=obstacles, brushes=brushes, resolution=args.resolution,
                          obstacle_names=[f"--obstacle {str(o)!r}" for o in args.obstacle],
                          method=args.method, **painted)
            _check_block_centre(res, args)
        # one unit: a Ctrl-C leaves the last run's products, never new ones beside old ones (a
        # grown.glb of 13 years beside a woodify.json of 11)
        with all_or_nothing():
            files, summary = _write_outputs(
                res, args.out, textured=textured, surface_years=years, block_size_mm=args.block_size,
                block_centre_mm=args.block_centre, cracks=args.cracks, crack_region=region,
                crack_years=args.crack_years, crack_render=args.crack_render,
                crack_threshold=args.crack_threshold, relief=args.relief, seed=args.seed,
                max_atlas_px=args.max_atlas, units=args.units,
                atomic=_atomic, stage=bar.stage)
            summary["total_s"] = time.perf_counter() - t0
            summary["input"] = str(args.part)
            _atomic(Path(args.out) / "woodify.json",
                    lambda p: p.write_text(json.dumps(summary, indent=1, default=float)))
    files = [*files, Path(args.out) / "woodify.json"]  # the summary names every file written
    # an earlier run's surfaces at other years are not this run's: they went on piling up
    remove_stale(args.out, ["surface_y*.stl"], files, kind="woodify")
    files.append(manifest_path(args.out, "woodify"))  # the list of them, for the next run
    print(f"grew {args.part} for {args.years:g} years on a {'x'.join(map(str, res.front.grid.shape))} "
          f"grid ({res.front.method}, {summary['total_s']:.1f} s); wrote "
          + ", ".join(str(f) for f in files))
    # the grown input is in its own frame, the block's corner away: the translate that bakes it
    # where it grew (its rings the ones it grew with) is said, in --units as place's --place ops
    shift = place_op_in("translate:" + ",".join(f"{v:.12g}" for v in summary["block"]["input_translate_mm"]),
                        1 / MM_PER_UNIT[args.units], TYPED_DECIMALS[args.units])
    units = " --units inch" if args.units == "inch" else ""
    print(f"carve from it with: woodcam bake PART{units} --block woodify:{Path(args.out) / WOODIFY_FIELD_FILE} "
          f"--out PART.glb (PART in the block frame; to carve {args.part} where it grew, its surface the year-0 "
          f"ring, add --place {shift})")
    return 0
