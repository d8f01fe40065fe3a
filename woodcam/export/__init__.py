"""Export textured meshes: binary glTF (GLB) with the texture embedded, and OBJ + MTL + PNG.

Data form
---------
Meshes are ``trimesh.Trimesh`` in the block frame, millimetres, with ``TextureVisuals`` (uv in
trimesh/OBJ convention, origin bottom-left; see :mod:`woodcam.bake`). Both formats are written by
trimesh's exporters; glTF has no unit field and is metres by convention, so the numbers are
written unchanged (mm) and ``woodcam`` metadata says ``"units": "mm"``.

Metadata
--------
``export_glb(..., metadata=...)`` stores a JSON object in the glTF scene's ``extras`` under the
key ``"woodcam"`` (``scenes[0].extras.woodcam``), e.g. the block spec and field info so that
``woodcam preview part.glb`` can rebuild the wood later. :func:`read_glb_metadata` reads it
back without trimesh by parsing the GLB's JSON chunk.
"""

from __future__ import annotations

import copy
import json
import struct
from pathlib import Path

import numpy as np

from woodcam._atomic import atomic_files, check_output_path, write_bytes
from woodcam.errors import WoodcamError

#: Key under the glTF scene ``extras`` that holds woodcam's metadata.
GLB_METADATA_KEY = "woodcam"

_GLB_MAGIC = 0x46546C67  # b"glTF" little-endian
_GLB_CHUNK_JSON = 0x4E4F534A  # b"JSON"
_GL_ARRAY_BUFFER = 34962
_GL_ELEMENT_ARRAY_BUFFER = 34963


def _require_textured(mesh, func: str):
    visual = getattr(mesh, "visual", None)
    material = getattr(visual, "material", None)
    uv = getattr(visual, "uv", None)
    if getattr(visual, "kind", None) != "texture" or uv is None or material is None:
        raise WoodcamError(
            f"{func}: mesh must carry a texture (trimesh TextureVisuals with uv and a material); "
            f"got visual kind {getattr(visual, 'kind', None)!r}; bake it first with "
            "woodcam.bake.bake(mesh, wood).mesh"
        )


def export_glb(mesh, path, metadata: dict | None = None) -> Path:
    """Write ``mesh`` as a binary glTF with its texture embedded.

    Parameters
    ----------
    mesh : trimesh.Trimesh
        Textured mesh (e.g. ``bake(...).mesh``), mm, block frame.
    path : str or Path
        Output ``.glb`` file; parent folders are created.
    metadata : dict or None
        JSON-serialisable data stored as ``scenes[0].extras["woodcam"]``.

    Returns
    -------
    Path
        The written file.
    """
    import trimesh
    from trimesh.exchange.gltf import export_glb as _trimesh_export_glb

    _require_textured(mesh, "export_glb")
    path = check_output_path(path, suffixes=(".glb",), what="export_glb: path", mkdir=True)
    payload = {"units": "mm", "frame": "block"}
    if metadata is not None:
        try:
            payload.update(json.loads(json.dumps(metadata)))
        except (TypeError, ValueError) as err:
            raise WoodcamError(
                f"export_glb: metadata must be JSON-serialisable; got {type(metadata).__name__} "
                f"({err}); convert arrays with .tolist() and paths with str()"
            ) from err

    def _add_extras(tree: dict) -> None:
        scene = tree["scenes"][tree.get("scene", 0)]
        extras = scene.setdefault("extras", {})
        extras[GLB_METADATA_KEY] = payload
        _set_buffer_view_targets(tree)

    scene = trimesh.Scene()
    scene.add_geometry(mesh, geom_name="part", node_name="part")
    data = _trimesh_export_glb(scene, tree_postprocessor=_add_extras)
    write_bytes(path, data)  # atomic: a complete GLB or none
    return path


def _set_buffer_view_targets(tree: dict) -> None:
    """Mark vertex-attribute and index buffer views with their GL target (ARRAY_BUFFER /
    ELEMENT_ARRAY_BUFFER), which the Khronos validator asks for (BUFFER_VIEW_TARGET_MISSING)."""
    accessors = tree.get("accessors", [])
    views = tree.get("bufferViews", [])
    for mesh in tree.get("meshes", []):
        for prim in mesh.get("primitives", []):
            pairs = [(a, _GL_ARRAY_BUFFER) for a in prim.get("attributes", {}).values()]
            if "indices" in prim:
                pairs.append((prim["indices"], _GL_ELEMENT_ARRAY_BUFFER))
            for acc, target in pairs:
                view = accessors[acc].get("bufferView")
                if view is not None:
                    views[view]["target"] = target


def export_obj(mesh, path) -> Path:
    """Write ``mesh`` as ``NAME.obj`` + ``NAME.mtl`` + ``NAME.png`` side by side.

    Parameters
    ----------
    mesh : trimesh.Trimesh
        Textured mesh, mm, block frame.
    path : str or Path
        Output ``.obj`` file; the material library and texture take its stem.

    Returns
    -------
    Path
        The written ``.obj`` file.
    """
    from trimesh.exchange.obj import export_obj as _trimesh_export_obj

    _require_textured(mesh, "export_obj")
    path = check_output_path(path, suffixes=(".obj",), what="export_obj: path", mkdir=True)
    stem = path.stem
    # trimesh names the image after the material: a shallow copy named after the file gives
    # NAME.png without touching the caller's mesh.
    out = mesh.copy(include_cache=False) if hasattr(mesh, "copy") else copy.copy(mesh)
    material = out.visual.material
    if hasattr(material, "to_simple"):
        material = material.to_simple()
    material = copy.copy(material)
    material.name = stem
    # Viewers multiply map_Kd by Kd: white keeps the baked colours as baked. Wood is matte.
    material.diffuse = np.array([255, 255, 255, 255], dtype=np.uint8)
    material.ambient = np.array([255, 255, 255, 255], dtype=np.uint8)
    material.specular = np.array([20, 20, 20, 255], dtype=np.uint8)
    if material.image is not None and material.image.format is None:
        material.image.format = "PNG"
    out.visual.material = material
    text, files = _trimesh_export_obj(
        out, include_texture=True, return_texture=True, mtl_name=f"{stem}.mtl"
    )
    # OBJ + MTL + PNG as one unit: all renamed into place only once every one is written, the
    # OBJ (which references the others) last.
    names = list(files)
    with atomic_files([path] + [path.parent / n for n in names]) as temps:
        temps[0].write_text(text)
        for tmp, name in zip(temps[1:], names):
            tmp.write_bytes(files[name])
    return path


def load_textured(path):
    """Load a GLB or OBJ written by this module as ONE textured ``trimesh.Trimesh``.

    Vertices are not merged (``process=False``), so the vertex count is the exported one.

    Raises
    ------
    WoodcamError
        If the file does not exist or holds not exactly one mesh.
    """
    import trimesh

    path = Path(path)
    if not path.is_file():
        raise WoodcamError(f"load_textured: no file at {str(path)!r}; check the path")
    loaded = trimesh.load(path, process=False, maintain_order=True)
    if isinstance(loaded, trimesh.Scene):
        geoms = list(loaded.geometry.values())
        if len(geoms) != 1:
            raise WoodcamError(
                f"load_textured: {str(path)!r} holds {len(geoms)} meshes; expected exactly one "
                "(files from woodcam.export hold one)"
            )
        node = loaded.graph.nodes_geometry[0]
        transform = loaded.graph[node][0]
        if np.allclose(transform, np.eye(4)):
            # files written here: keep the geometry as stored, with its NORMAL attribute
            loaded = geoms[0]
        else:  # someone else's file with a node transform: bake it into the vertices
            loaded = loaded.to_mesh()
    return loaded


def read_glb_metadata(path) -> dict:
    """Return the ``woodcam`` metadata stored by :func:`export_glb` (``{}`` if none).

    Parses the GLB header and JSON chunk directly (glTF 2.0 spec, "GLB File Format").
    """
    path = Path(path)
    data = path.read_bytes()
    if len(data) < 20:
        raise WoodcamError(f"read_glb_metadata: {str(path)!r} is too short to be a GLB file")
    magic, version, _length = struct.unpack_from("<III", data, 0)
    chunk_len, chunk_type = struct.unpack_from("<II", data, 12)
    if magic != _GLB_MAGIC or version != 2 or chunk_type != _GLB_CHUNK_JSON:
        raise WoodcamError(
            f"read_glb_metadata: {str(path)!r} is not a glTF 2.0 binary (magic {magic:#x}, "
            f"version {version}); pass a .glb written by woodcam.export.export_glb"
        )
    tree = json.loads(data[20:20 + chunk_len].decode("utf-8"))
    scenes = tree.get("scenes") or [{}]
    scene = scenes[tree.get("scene", 0)]
    return dict((scene.get("extras") or {}).get(GLB_METADATA_KEY, {}))
