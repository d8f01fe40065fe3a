"""Export textured meshes: binary glTF (GLB) with the texture embedded, and OBJ + MTL + PNG.

Data form
---------
Meshes are ``trimesh.Trimesh`` in the block frame, millimetres, Z up, with ``TextureVisuals``
(uv in trimesh/OBJ convention, origin bottom-left; see :mod:`woodcam.bake`). Both formats are
written by trimesh's exporters and follow their consumers' conventions:

* **GLB** (glTF 2.0 is metres, +Y up, +Z towards the viewer): the vertex buffer keeps the block
  frame in mm and one root node carries :data:`BLOCK_TO_GLTF` (scale 1/1000 and the rotation
  block ``(x, y, z)`` -> glTF ``(x, z, -y)``), so Blender, three.js and every other viewer show
  the part upright at its real size, and the block frame stays exactly recoverable (the matrix
  is also recorded in the metadata). The texture has an explicit clamp-to-edge sampler.
* **OBJ** has no unit or axis field: ``units`` (``"m"`` default, what Blender and most DCC tools
  assume) and ``up`` (``"y"`` default, the OBJ habit) are chosen by the caller and written in a
  ``# woodcam:`` header comment that :func:`load_textured` reads back.
* **Normals**: smooth shading normals split at a crease angle (:data:`woodcam.tolerances.
  CREASE_ANGLE_DEG`, 30 deg): corners whose faces meet at a sharper edge get their own vertex.

Metadata
--------
``export_glb(..., metadata=...)`` stores a JSON object in the glTF scene's ``extras`` under the
key ``"woodcam"`` (``scenes[0].extras.woodcam``), e.g. the block spec and field info so that
``woodcam preview part.glb`` can rebuild the wood later. :func:`read_glb_metadata` reads it
back without trimesh by parsing the GLB's JSON chunk.
"""

from __future__ import annotations

from .._types import Mesh, PathLike

import copy
import json
import math
import re
import struct
from pathlib import Path
from typing import get_args

import numpy as np

from woodcam._atomic import atomic_files, check_output_path, write_bytes
from woodcam._checks import check_number, check_path, not_a_mesh
from woodcam.errors import WoodcamError
from woodcam.frames import (BLOCK_TO_GLTF, GLTF_ROOT_NODE, OBJ_HEADER, ObjUnits, ObjUp,
                            foreign_gltf_in_block_frame, obj_header_transform, obj_transform,
                            stamp_gltf_asset)

#: Key under the glTF scene ``extras`` that holds woodcam's metadata.
GLB_METADATA_KEY = "woodcam"

_GLB_MAGIC = 0x46546C67  # b"glTF" little-endian
_GLB_CHUNK_JSON = 0x4E4F534A  # b"JSON"
_GL_LINEAR = 9729
_GL_LINEAR_MIPMAP_LINEAR = 9987
_GL_CLAMP_TO_EDGE, _GL_REPEAT = 33071, 10497

#: zlib level of the texture PNG: level 1 encodes the bowl's 2k^2 atlas in 0.21 CPU-s (3.2 MB),
#: PIL's default 6 in 0.76-0.96 s (2.9 MB); the GLB and the OBJ's PNG share one encoding.
_PNG_COMPRESS_LEVEL = 1

#: The last texture encoded: {content digest: PNG bytes} (one entry; export_glb and export_obj
#: of the same baked mesh encode it once).
_PNG_CACHE: dict[bytes, bytes] = {}



def _png_bytes(image) -> bytes:
    """``image`` (PIL) as PNG bytes at :data:`_PNG_COMPRESS_LEVEL`, cached by content."""
    import hashlib
    import io

    digest = hashlib.blake2b(image.tobytes(), digest_size=20)
    digest.update(f"{image.mode} {image.size}".encode())
    key = digest.digest()
    if key not in _PNG_CACHE:
        buffer = io.BytesIO()
        image.save(buffer, format="PNG", compress_level=_PNG_COMPRESS_LEVEL)
        _PNG_CACHE.clear()
        _PNG_CACHE[key] = buffer.getvalue()
    return _PNG_CACHE[key]


def _with_encoded_texture(mesh, attribute: str):
    """Point ``mesh.visual.material.<attribute>`` (a COPY of the material) at a copy of its image
    whose ``save(..., format="PNG")`` writes :func:`_png_bytes`: trimesh's GLB exporter calls
    ``image.save`` and would encode the atlas again at zlib level 6 (the OBJ writer takes
    :func:`_png_bytes` itself)."""
    material = copy.copy(mesh.visual.material)
    image = getattr(material, attribute, None)
    if image is None or not hasattr(image, "tobytes"):
        return
    data = _png_bytes(image)
    encoded = image.copy()
    encoded.format = None

    def save(fp, format=None, **params):
        if str(format).upper() != "PNG" or params:
            return type(image).save(encoded, fp, format=format, **params)
        fp.write(data)
        return None

    encoded.save = save
    setattr(material, attribute, encoded)
    mesh.visual.material = material


def _require_textured(mesh, func: str):
    """The door of both writers: a textured trimesh with at least one triangle and finite
    vertices (an empty mesh was numpy's ValueError under ``normals="mesh"``, a NaN vertex a
    file written without a word, NaN in its positions)."""
    import trimesh

    if not isinstance(mesh, trimesh.Trimesh):
        raise not_a_mesh(f"{func}: mesh", mesh, "pass the baked surface: bake(mesh, wood).mesh (a file woodcam "
                         "wrote reads back with load_textured(path))", loads=False)
    if len(mesh.faces) == 0:
        raise WoodcamError(f"{func}: mesh has no triangles ({len(mesh.vertices)} vertices); nothing to "
                           "write; pass a surface with at least one triangle")
    bad = ~np.isfinite(np.asarray(mesh.vertices, float)).all(axis=1)
    if bad.any():
        raise WoodcamError(f"{func}: mesh has {int(bad.sum())} of {len(bad)} vertices that are not finite "
                           "numbers (NaN or inf); no viewer can read them back; fix or drop those vertices")
    visual = getattr(mesh, "visual", None)
    material = getattr(visual, "material", None)
    uv = getattr(visual, "uv", None)
    if getattr(visual, "kind", None) != "texture" or uv is None or material is None:
        raise WoodcamError(
            f"{func}: mesh must carry a texture (trimesh TextureVisuals with uv and a material); "
            f"got visual kind {getattr(visual, 'kind', None)!r}; bake it first with "
            "woodcam.bake.bake(mesh, wood).mesh"
        )


def crease_normals(mesh: Mesh, crease_angle_deg: float | None = None) -> Mesh:
    """Split ``mesh``'s vertices where faces meet at an edge sharper than the crease angle and
    give every vertex a smooth shading normal.

    Parameters
    ----------
    mesh : trimesh.Trimesh
        Triangle mesh (mm); its texture (``visual.uv`` + material) is carried over.
    crease_angle_deg : float or None
        Faces round a position whose normals differ by less than this share a normal (their
        area-weighted mean); default :data:`woodcam.tolerances.CREASE_ANGLE_DEG`.

    Returns
    -------
    trimesh.Trimesh
        Same triangles and corner positions/uv in the same face order, vertices split where a
        corner needs another normal, ``vertex_normals (m, 3)`` unit.

    Notes
    -----
    Positions, not vertex indices, decide which faces meet (the baked mesh is split at UV seams,
    and a seam must not become a shading seam). Vectorised: a sparse corner x corner matrix of
    "same position and within the crease angle" times the angle-weighted face normals.
    """
    import trimesh
    from scipy import sparse

    from woodcam.tolerances import CREASE_ANGLE_DEG, CREASE_WELD_MM

    if not isinstance(mesh, trimesh.Trimesh):
        raise not_a_mesh("crease_normals: mesh", mesh, "pass a surface mesh, e.g. bake(mesh, wood).mesh")
    # a string ('30') was float()'s number without a word
    angle = CREASE_ANGLE_DEG if crease_angle_deg is None else check_number(
        crease_angle_deg, "crease_normals: crease_angle_deg", lo=0.0, hi=180.0,
        fix="use e.g. 30 (degrees; 0 = flat shading, 180 = smooth everywhere)")
    if len(mesh.faces) == 0:
        raise WoodcamError("crease_normals: mesh has no triangles; pass a surface with at least one")
    verts = np.asarray(mesh.vertices, dtype=np.float64)
    faces = np.asarray(mesh.faces, dtype=np.int64)
    n_faces = len(faces)
    corners = faces.reshape(-1)
    face_of_corner = np.repeat(np.arange(n_faces), 3)
    cross = np.cross(verts[faces[:, 1]] - verts[faces[:, 0]], verts[faces[:, 2]] - verts[faces[:, 0]])
    area2 = np.linalg.norm(cross, axis=1)
    # a zero-area face (collinear corners) has no normal of its own: it counts for nothing and
    # its corners take the smooth normal of every face at their position (below)
    flat = area2 <= 1e-14 * max(float(area2.max(initial=0.0)), 1e-300)
    unit = np.where(flat[:, None], 0.0, cross / np.maximum(area2, 1e-300)[:, None])
    # position id of every corner (welded at CREASE_WELD_MM)
    keys = np.round(verts / CREASE_WELD_MM).astype(np.int64)
    _, pos_of_vertex = np.unique(keys, axis=0, return_inverse=True)
    pos = pos_of_vertex.reshape(-1)[corners]
    n_corners = len(corners)
    incidence = sparse.csr_matrix((np.ones(n_corners), (np.arange(n_corners), pos)),
                                  shape=(n_corners, int(pos.max()) + 1))
    same = (incidence @ incidence.T).tocoo()
    a, b = same.row, same.col
    cos = np.einsum("ij,ij->i", unit[face_of_corner[a]], unit[face_of_corner[b]])
    keep = (cos >= math.cos(math.radians(angle)) - 1e-12) | flat[face_of_corner[a]]
    a, b = a[keep], b[keep]
    # Angle-weighted normals (Thuerrner & Wuethrich 1998): each neighbour corner weighs its
    # face's normal by its own corner angle, so the result does not depend on how a flat
    # region happens to be triangulated (area weights tilt a box corner towards the face
    # that has two triangles there).
    tri = verts[faces]
    e1 = np.roll(tri, -1, axis=1) - tri
    e2 = np.roll(tri, 1, axis=1) - tri
    cos_corner = np.einsum("fij,fij->fi", e1, e2) / np.maximum(
        np.linalg.norm(e1, axis=2) * np.linalg.norm(e2, axis=2), 1e-300)
    corner_angle = np.arccos(np.clip(cos_corner, -1.0, 1.0)).reshape(-1)
    weighted = unit[face_of_corner] * corner_angle[:, None]
    normal = np.zeros((n_corners, 3))
    for k in range(3):
        normal[:, k] = np.bincount(a, weights=weighted[b, k], minlength=n_corners)
    length = np.linalg.norm(normal, axis=1)
    # no face with a normal at this position (an isolated zero-area face): any unit vector
    # beats the zero one glTF forbids (ACCESSOR_VECTOR3_NON_UNIT)
    normal[length < 1e-300] = (0.0, 0.0, 1.0)
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    # one output vertex per (input vertex, normal)
    qn = np.round(normal * 1e6).astype(np.int64)
    table = np.column_stack([corners, qn])
    _, first, new_index = np.unique(table, axis=0, return_index=True, return_inverse=True)
    new_index = new_index.reshape(-1)
    src = corners[first]
    out_visual = None
    visual = getattr(mesh, "visual", None)
    if getattr(visual, "kind", None) == "texture" and getattr(visual, "uv", None) is not None:
        out_visual = trimesh.visual.TextureVisuals(uv=np.asarray(visual.uv)[src],
                                                   material=visual.material)
    out = trimesh.Trimesh(vertices=verts[src], faces=new_index.reshape(-1, 3), visual=out_visual,
                          process=False)
    out.vertex_normals = normal[first]
    return out


def export_glb(mesh: Mesh, path: PathLike, metadata: dict | None = None, *,
               crease_angle_deg: float | None = None, normals: str = "crease") -> Path:
    """Write ``mesh`` as a binary glTF (metres, Y up) with its texture embedded.

    Parameters
    ----------
    mesh : trimesh.Trimesh
        Textured mesh (e.g. ``bake(...).mesh``), mm, block frame.
    path : str or Path
        Output ``.glb`` file; parent folders are created.
    metadata : dict or None
        JSON-serialisable data stored as ``scenes[0].extras["woodcam"]``.
    crease_angle_deg : float or None
        Shading normals: smooth across edges flatter than this, split at sharper ones (default
        :data:`woodcam.tolerances.CREASE_ANGLE_DEG`); see :func:`crease_normals`.
    normals : {"crease", "mesh"}
        ``"mesh"``: write the mesh's own ``vertex_normals`` (a caller that knows them, e.g. the
        height-field preview, skips the crease computation: 14 s and 3 GB on 1M triangles).

    Returns
    -------
    Path
        The written file. Its scene has one root node ``woodcam_block_frame`` with matrix
        :data:`BLOCK_TO_GLTF` above the mesh node (vertices in block-frame mm); the mesh and its
        node are named after the file's stem (``bowl`` for ``bowl.glb``).
    """
    import trimesh
    from trimesh.exchange.gltf import export_glb as _trimesh_export_glb

    _require_textured(mesh, "export_glb")
    # check_path first (None: Path()'s TypeError)
    path = check_output_path(check_path(path, "export_glb: path", fix="e.g. 'out/part.glb'"),
                             suffixes=(".glb",), what="export_glb: path", mkdir=True)
    payload = {"units": "mm", "frame": "block", "block_to_gltf": BLOCK_TO_GLTF.tolist()}
    if metadata is not None:
        clash = sorted(k for k in (metadata if isinstance(metadata, dict) else {})
                       if k in payload and metadata[k] != payload[k])
        if clash:  # the file's own contract: readers trust "frame" to undo the root transform
            raise WoodcamError(f"export_glb: metadata may not change {clash}; export_glb writes them "
                               "itself (vertices in block-frame mm under BLOCK_TO_GLTF); use other keys")
        try:  # strict: NaN would be written as a bare NaN, which no JSON reader accepts
            payload.update(json.loads(json.dumps(metadata, allow_nan=False)))
        except (TypeError, ValueError) as err:
            raise WoodcamError(
                f"export_glb: metadata must be JSON-serialisable; got {type(metadata).__name__} "
                f"({err}); convert arrays with .tolist() and paths with str()"
            ) from err

    def _add_extras(tree: dict) -> None:
        stamp_gltf_asset(tree)
        scene = tree["scenes"][tree.get("scene", 0)]
        extras = scene.setdefault("extras", {})
        extras[GLB_METADATA_KEY] = payload
        nodes = tree.setdefault("nodes", [])
        nodes.append({"name": GLTF_ROOT_NODE, "children": list(scene.get("nodes", [])),
                      # glTF matrices are column-major
                      "matrix": [float(v) for v in BLOCK_TO_GLTF.T.reshape(-1)]})
        scene["nodes"] = [len(nodes) - 1]
        tree["samplers"] = [{"magFilter": _GL_LINEAR, "minFilter": _GL_LINEAR_MIPMAP_LINEAR,
                             "wrapS": wrap[0], "wrapT": wrap[1]}]
        for texture in tree.get("textures", []):
            texture["sampler"] = 0

    shaded = _shaded(mesh, crease_angle_deg, normals, "export_glb")
    # an atlas (a bake) lies in [0, 1] and is clamped, so its border texels never bleed across;
    # coordinates beyond it mean a repeating picture (woodify's bark wraps round the stem with
    # u + 1 on the seam triangles), which clamping would smear
    uv = np.asarray(shaded.visual.uv, float)
    wrap = [_GL_REPEAT if len(uv) and (uv[:, k].min() < -1e-9 or uv[:, k].max() > 1 + 1e-9)
            else _GL_CLAMP_TO_EDGE for k in (0, 1)]
    _with_encoded_texture(shaded, "baseColorTexture")
    scene = trimesh.Scene()
    # named after the file, as an OBJ's object is (it has no 'o' line: importers take the file
    # name): two parts imported into one Blender scene were 'part' and 'part.001'
    scene.add_geometry(shaded, geom_name=path.stem, node_name=path.stem)
    data = _trimesh_export_glb(scene, include_normals=True, tree_postprocessor=_add_extras)
    write_bytes(path, data)  # atomic: a complete GLB or none
    return path


def _shaded(mesh, crease_angle_deg, normals: str, what: str):
    """The mesh to write with its shading normals: crease normals, or the mesh's own made unit
    (glTF requires a unit NORMAL, ACCESSOR_VECTOR3_NON_UNIT: a dirty mesh's unreferenced vertex
    or one of zero-area triangles only has trimesh's zero normal, which
    :func:`~woodcam.appearance.wood.vertex_color_normals` replaces with a direction)."""
    if normals == "crease":
        return crease_normals(mesh, crease_angle_deg)
    if normals != "mesh":
        raise WoodcamError(f"{what}: normals must be 'crease' or 'mesh'; got {normals!r}")
    from woodcam.appearance.wood import vertex_color_normals

    vn = vertex_color_normals(mesh)
    vn = vn / np.linalg.norm(vn, axis=1)[:, None]
    out = mesh.copy()
    out.vertex_normals = vn
    return out


def obj_siblings(obj_path: PathLike) -> tuple[Path, Path]:
    """The MTL and texture files :func:`export_obj` writes beside ``obj_path``: ``NAME.mtl`` and
    ``NAME_texture.png``, whitespace in NAME made ``_`` (``mtllib`` is a list of names split at
    whitespace, ``usemtl`` one token and ``map_Kd``'s file its last: a reader takes "my tray.mtl"
    for the two files "my" and "tray.mtl")."""
    path = Path(obj_path)
    name = re.sub(r"\s", "_", path.stem)
    return path.with_name(f"{name}.mtl"), path.with_name(f"{name}_texture.png")


def written_obj_set(obj_path: PathLike) -> list[Path]:
    """The files of the OBJ set :func:`export_obj` wrote at ``obj_path`` (the OBJ, its MTL and
    texture: :func:`obj_siblings`) that exist, when the OBJ there is woodcam's (its first line is
    export_obj's ``# woodcam:`` header, read by :func:`woodcam.frames.obj_header_transform`);
    ``[]`` for no OBJ, another program's or one whose header was edited out of shape (a part
    file of the user's must never be taken for an earlier run's output)."""
    path = Path(obj_path)
    try:
        ours = obj_header_transform(path) is not None
    except (OSError, WoodcamError):
        return []
    return [p for p in (path, *obj_siblings(path)) if p.is_file()] if ours else []


def export_obj(mesh: Mesh, path: PathLike, *, units: ObjUnits = "m", up: ObjUp = "y",
               crease_angle_deg: float | None = None, normals: str = "crease") -> Path:
    """Write ``mesh`` as ``NAME.obj`` + ``NAME.mtl`` + ``NAME_texture.png`` side by side (the
    last two with whitespace in NAME made ``_``: :func:`obj_siblings`).

    Parameters
    ----------
    mesh : trimesh.Trimesh
        Textured mesh, mm, block frame.
    path : str or Path
        Output ``.obj`` file; the material library and texture take its stem.
    units : {"m", "mm"}
        Length unit of the written coordinates. OBJ has no unit field; ``"m"`` (default) is what
        Blender and most viewers assume, ``"mm"`` what CAM tools and slicers assume.
    up : {"y", "z"}
        Up axis of the written coordinates: ``"y"`` (default, the OBJ habit: block ``(x, y, z)``
        is written as ``(x, z, -y)``) or ``"z"`` (the block frame unchanged).
    crease_angle_deg : float or None
        Shading normals (``vn``) split at sharper edges; see :func:`crease_normals`.
    normals : {"crease", "mesh"}
        As :func:`export_glb`.

    Returns
    -------
    Path
        The written ``.obj`` file. Its first line records units and up axis
        (``# woodcam: units=m up=y``) so :func:`load_textured` returns the block frame.
    """
    _require_textured(mesh, "export_obj")
    # check_path first (None: Path()'s TypeError)
    path = check_output_path(check_path(path, "export_obj: path", fix="e.g. 'out/part.obj'"),
                             suffixes=(".obj",), what="export_obj: path", mkdir=True)
    if units not in get_args(ObjUnits):
        raise WoodcamError(f"export_obj: units must be one of {get_args(ObjUnits)}; got {units!r}")
    if up not in get_args(ObjUp):
        raise WoodcamError(f"export_obj: up must be one of {get_args(ObjUp)}; got {up!r}")
    from ._obj_text import obj_blocks

    mtl_path, tex_path = obj_siblings(path)
    stem = mtl_path.stem
    out = _shaded(mesh, crease_angle_deg, normals, "export_obj")
    transform = obj_transform(units, up)
    # einsum, not "@": BLAS multiplies an (n, 3) by a 3 x 3 ~10x slower (0.1 CPU-s per
    # 400,000 rows, its threads spinning)
    m = transform[:3, :3]
    verts = np.einsum("ij,kj->ik", np.asarray(out.vertices, np.float64), m)
    vn = np.einsum("ij,kj->ik", np.asarray(out.vertex_normals, np.float64),
                   m / np.linalg.norm(transform[:3, 0]))
    material = out.visual.material
    image = getattr(material, "image", None) or getattr(material, "baseColorTexture", None)
    # NAME_texture.png, not NAME.png: a screenshot named after the part must never overwrite
    # the texture (issue 17: 'woodcam preview bowl.glb --screenshot bowl.png' did)
    tex = tex_path.stem
    # Viewers multiply map_Kd by Kd: white keeps the baked colours as baked. Wood is matte.
    mtl = (f"newmtl {tex}\nKa 1.00000000 1.00000000 1.00000000\nKd 1.00000000 1.00000000 "
           f"1.00000000\nKs 0.07843137 0.07843137 0.07843137\nNs 1.00000000\n")
    files = {}
    if image is not None:
        mtl += f"map_Kd {tex}.png\n"
        files[f"{tex}.png"] = _png_bytes(image)
    files[f"{stem}.mtl"] = mtl.encode()
    header = (f"{OBJ_HEADER} units={units} up={up} (block frame: mm, Z up; "
              f"see woodcam.export.export_obj)\nmtllib {stem}.mtl\nusemtl {tex}\n")
    # millimetre digits: 1e-9 m = 1e-6 mm either way
    blocks = obj_blocks(verts, np.asarray(out.visual.uv, np.float64), vn, np.asarray(out.faces),
                        decimals=9 if units == "m" else 6)
    # OBJ + MTL + PNG as one unit: all renamed into place only once every one is written, the
    # OBJ (which references the others) last.
    names = list(files)
    with atomic_files([path] + [path.parent / n for n in names]) as temps:
        with open(temps[0], "wb") as fh:
            fh.write(header.encode())
            for block in blocks:  # one block in memory at a time
                fh.write(block)
                del block
        for tmp, name in zip(temps[1:], names):
            tmp.write_bytes(files[name])
    return path


#: First bytes of the 80-byte header of a binary STL written by :func:`stl_bytes`.
STL_HEADER = b"woodcam: units=mm"


def stl_bytes(mesh: Mesh, note: str = "") -> bytes:
    """``mesh`` (trimesh, mm) as a binary STL whose 80-byte header states its unit:
    ``woodcam: units=mm <note>`` (STL has no unit field; trimesh leaves the header zeros, and a
    reader then guesses; the header must not start with ``solid``, which marks ASCII STL).
    ``note`` (ASCII, e.g. the frame) is cut to fit."""
    from trimesh.exchange.stl import export_stl

    data = export_stl(mesh)
    text = (STL_HEADER + b" " + note.encode("ascii", "replace")).strip()[:80]
    return text.ljust(80, b" ") + data[80:]


def write_stl(mesh, path: PathLike, note: str = "") -> Path:
    """Write ``mesh`` (mm) atomically to ``path`` as :func:`stl_bytes` makes it, its header
    stating ``units=mm``: the one STL writer of woodcam and its example scripts (a CAD kernel's
    own exporter wrote 'STL Exported by Open CASCADE Technology', no unit). ``mesh`` is a
    trimesh mesh or a manifold3d ``Manifold`` (what :func:`woodcam.cad.load_part` returns: the
    part as woodcam carves it). Missing parent folders are created, as :func:`export_glb` and
    :func:`export_obj` create theirs."""
    import trimesh

    path = check_output_path(check_path(path, "write_stl: path", fix="e.g. 'out/part.stl'"),
                             suffixes=(".stl",), what="write_stl: path", mkdir=True)
    if hasattr(mesh, "to_mesh64"):  # a manifold3d Manifold
        from .._manifold import manifold_to_trimesh

        mesh = manifold_to_trimesh(mesh)
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise WoodcamError(f"write_stl: mesh must be a trimesh.Trimesh or manifold3d.Manifold with "
                           f"triangles; got {type(mesh).__name__}; e.g. write_stl(load_part(part), 'part.stl')")
    return write_bytes(path, stl_bytes(mesh, note))


def load_textured(path: PathLike) -> Mesh:
    """Load a GLB or OBJ written by this module as ONE textured ``trimesh.Trimesh`` in the block
    frame (mm, Z up): the GLB root transform and the OBJ's recorded units/up axis are undone.
    Other files come back as their node transforms place them, except another program's
    glTF/GLB whose part spans under 1 unit: read as metres with +Y up, as glTF specifies, and
    returned in mm, Z up, with a WoodcamWarning (:func:`woodcam.frames.foreign_gltf_in_block_frame`).

    ``path``: the .glb or .obj file (an OBJ's .mtl and texture read from beside it).

    Vertices are not merged (``process=False``), so the vertex count is the exported one.

    Raises
    ------
    WoodcamError
        If the file does not exist or holds not exactly one mesh.
    """
    import trimesh

    path = check_path(path, "load_textured: path", fix="a GLB or OBJ written by woodcam")
    if not path.is_file():
        raise WoodcamError(f"load_textured: no file at {str(path)!r}; check the path")
    try:
        loaded = trimesh.load(path, process=False, maintain_order=True)
    except Exception as err:  # noqa: BLE001 - trimesh raises anything on a damaged file
        raise WoodcamError(f"load_textured: {str(path)!r} cannot be read as a mesh ({type(err).__name__}: "
                           f"{str(err)[:200]}); is it a GLB or OBJ written by woodcam?") from err
    if not isinstance(loaded, (trimesh.Trimesh, trimesh.Scene)) or (
            isinstance(loaded, trimesh.Trimesh) and len(loaded.faces) == 0) or (
            isinstance(loaded, trimesh.Scene) and not loaded.geometry):
        raise WoodcamError(f"load_textured: {str(path)!r} holds no triangle mesh (a "
                           f"{type(loaded).__name__}); pass a GLB or OBJ written by woodcam")
    if path.suffix.lower() == ".obj" and not isinstance(loaded, trimesh.Scene):
        recorded = obj_header_transform(path)
        if recorded is not None:
            inverse = np.linalg.inv(recorded)
            normals = np.asarray(loaded.vertex_normals, dtype=np.float64)
            loaded.vertices = np.asarray(loaded.vertices) @ inverse[:3, :3].T
            loaded.vertex_normals = normals @ inverse[:3, :3].T / np.linalg.norm(inverse[:3, 0])
        return loaded
    if isinstance(loaded, trimesh.Scene):
        geoms = list(loaded.geometry.values())
        # placed instances, not stored meshes: one mesh placed twice came back as its first
        # placement alone, the other dropped without a word
        placed = len(loaded.graph.nodes_geometry)
        if len(geoms) != 1 or placed != 1:
            raise WoodcamError(
                f"load_textured: {str(path)!r} holds {len(geoms)} meshes placed {placed} times; "
                "expected exactly one mesh placed once (files from woodcam.export hold one); "
                "join them into one mesh in your modelling program"
            )
        node = loaded.graph.nodes_geometry[0]
        transform = loaded.graph[node][0]
        if np.allclose(transform, np.eye(4)) or (
                path.suffix.lower() == ".glb" and np.allclose(transform, BLOCK_TO_GLTF)
                and read_glb_metadata(path).get("frame") == "block"):
            # files written here: the vertex buffer is the block frame (mm); keep it as stored,
            # with its NORMAL attribute
            loaded = geoms[0]
        else:  # someone else's file with a node transform: bake it into the vertices
            loaded = loaded.to_mesh()
        if not written_by_woodcam(path):  # someone else's glTF: metres, Y up when its size says so
            loaded = foreign_gltf_in_block_frame(loaded, path, stacklevel=2)
    return loaded


def written_by_woodcam(path: PathLike) -> bool:
    """True for a GLB or OBJ written by :func:`export_glb` / :func:`export_obj` (then
    :func:`load_textured` returns it in the block frame); False for any other file.
    ``path``: the .glb or .obj file (any other suffix: False)."""
    path = check_path(path, "written_by_woodcam: path", fix="a .glb file")
    suffix = path.suffix.lower()
    try:
        if suffix == ".glb":
            return read_glb_metadata(path).get("frame") == "block"
        if suffix == ".obj":
            return obj_header_transform(path) is not None
    except (OSError, WoodcamError, ValueError):
        return False
    return False


def glb_json(data: bytes, where: str) -> dict:
    """The glTF JSON of the GLB file bytes ``data`` (glTF 2.0 spec, "GLB File Format": a 12-byte
    header, then the JSON chunk's length and type), read without decoding its binary chunk (a
    texture's megabytes); a :class:`WoodcamError` beginning with ``where`` (what reads, the file)
    for anything that is no glTF 2.0 binary or a malformed JSON chunk."""
    if len(data) < 20:
        raise WoodcamError(f"{where} is {len(data)} bytes, too short to be a GLB file "
                           f"(its headers alone take 20); pass a .glb written by woodcam bake or another glTF exporter")
    magic, version, _length = struct.unpack_from("<III", data, 0)
    chunk_len, chunk_type = struct.unpack_from("<II", data, 12)
    if magic != _GLB_MAGIC or version != 2 or chunk_type != _GLB_CHUNK_JSON:
        raise WoodcamError(
            f"{where} is not a glTF 2.0 binary (magic {magic:#x}, "
            f"version {version}); pass a .glb written by woodcam bake or another glTF exporter"
        )
    bad = f"{where} has a malformed glTF JSON chunk"
    if 20 + chunk_len > len(data):
        raise WoodcamError(f"{bad}: it claims {chunk_len} bytes but the file ends first")
    try:
        tree = json.loads(data[20:20 + chunk_len].decode("utf-8"))
    except (UnicodeDecodeError, ValueError, RecursionError) as err:
        raise WoodcamError(f"{bad} ({err})") from err
    if not isinstance(tree, dict):
        raise WoodcamError(f"{bad}: a JSON object is required, got {type(tree).__name__}")
    return tree


def read_glb_metadata(path: PathLike) -> dict:
    """Return the ``woodcam`` metadata stored by :func:`export_glb` (``{}`` if none) of the
    GLB file ``path``.

    Parses the GLB header and JSON chunk directly (glTF 2.0 spec, "GLB File Format").
    """
    path = check_path(path, "read_glb_metadata: path", fix="a .glb file")
    try:
        data = path.read_bytes()
    except OSError as err:
        raise WoodcamError(f"GLB file {str(path)!r}: cannot read it ({err.strerror}); check the path: a .glb "
                           "written by woodcam bake or export_glb") from err
    # the file as the user gave it, not this function's name (a command-line user read
    # "read_glb_metadata: 'x.glb' is 3 bytes ..." of the file they typed)
    tree = glb_json(data, f"GLB file {str(path)!r}")
    bad = f"GLB file {str(path)!r} has a malformed glTF JSON chunk"
    scenes = tree.get("scenes") or [{}]
    index = tree.get("scene", 0)
    if (not isinstance(scenes, list) or isinstance(index, bool) or not isinstance(index, int)
            or not 0 <= index < len(scenes) or not isinstance(scenes[index], dict)):
        raise WoodcamError(f"{bad}: scenes/scene do not name a scene object")
    extras = scenes[index].get("extras") or {}
    meta = extras.get(GLB_METADATA_KEY, {}) if isinstance(extras, dict) else None
    if not isinstance(meta, dict):
        raise WoodcamError(f"{bad}: scene extras.{GLB_METADATA_KEY} must be a JSON object")
    return dict(meta)
