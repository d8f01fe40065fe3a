"""Tests of woodcam.export: GLB and OBJ+MTL+PNG round trips, metadata, Khronos validation."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
import trimesh

from woodcam.bake import bake
from woodcam.errors import WoodcamError
from woodcam.export import export_glb, export_obj, load_textured, read_glb_metadata

_REPO = Path(__file__).resolve().parents[2]
_VALIDATOR_JS = _REPO / "tests" / "_gltf_validate.js"
_NODE_MODULES = Path(
    os.environ.get("WOODCAM_NODE_MODULES", _REPO / ".cache" / "node" / "node_modules")
)


class _Wood:
    def color(self, points_mm, normals):
        return 0.5 + 0.3 * np.sin(points_mm / 5.0) + 0.1 * normals


@pytest.fixture(scope="module")
def baked():
    block = trimesh.creation.box((30.0, 20.0, 16.0))
    block.apply_translation([15.0, 10.0, 8.0])
    hole = trimesh.creation.cylinder(radius=5.0, height=30.0, sections=32)
    hole.apply_translation([15.0, 10.0, 8.0])
    part = trimesh.boolean.difference([block, hole], engine="manifold")
    return bake(part, _Wood(), texels_per_mm=3.0)


def _same_texture(loaded, result):
    material = loaded.visual.material
    image = getattr(material, "baseColorTexture", None) or getattr(material, "image", None)
    assert image is not None, "reloaded mesh has no texture image"
    np.testing.assert_array_equal(np.asarray(image.convert("RGB")), result.atlas)


def test_glb_reloads_with_texture_uv_and_vertex_count(baked, tmp_path):
    path = export_glb(baked.mesh, tmp_path / "part.glb")
    loaded = load_textured(path)
    assert len(loaded.vertices) == len(baked.mesh.vertices)
    assert len(loaded.faces) == len(baked.mesh.faces)
    np.testing.assert_allclose(loaded.vertices, baked.mesh.vertices, atol=1e-4)  # float32 file
    np.testing.assert_allclose(loaded.visual.uv, baked.mesh.visual.uv, atol=1e-6)
    _same_texture(loaded, baked)


def test_obj_writes_obj_mtl_png_named_after_the_obj_and_reloads(baked, tmp_path):
    path = export_obj(baked.mesh, tmp_path / "sub" / "bowl.obj")
    names = sorted(p.name for p in path.parent.iterdir())
    assert names == ["bowl.mtl", "bowl.obj", "bowl.png"]
    mtl = (path.parent / "bowl.mtl").read_text()
    assert "map_Kd bowl.png" in mtl
    assert "Kd 1.00000000 1.00000000 1.00000000" in mtl  # texture not darkened by Kd
    loaded = load_textured(path)
    assert len(loaded.vertices) == len(baked.mesh.vertices)
    assert len(loaded.faces) == len(baked.mesh.faces)
    np.testing.assert_allclose(loaded.visual.uv, baked.mesh.visual.uv, atol=1e-7)
    _same_texture(loaded, baked)
    # the caller's mesh keeps its own material name
    assert baked.mesh.visual.material.name == "wood"


def test_glb_keeps_seam_free_smooth_normals(tmp_path):
    sphere = trimesh.creation.icosphere(subdivisions=2, radius=10.0)
    result = bake(sphere, _Wood(), texels_per_mm=2.0, normals="smooth")
    path = export_glb(result.mesh, tmp_path / "sphere.glb")
    loaded = load_textured(path)
    expected = sphere.vertex_normals[result.vertex_map]
    np.testing.assert_allclose(loaded.vertex_normals, expected, atol=1e-5)
    # on a sphere the smooth normal is the radial direction, also across UV seams
    radial = loaded.vertices / np.linalg.norm(loaded.vertices, axis=1, keepdims=True)
    assert np.min(np.sum(loaded.vertex_normals * radial, axis=1)) > 0.99


def test_glb_metadata_round_trip(baked, tmp_path):
    meta = {"block": {"size_mm": [30.0, 20.0, 16.0], "species": "oak"}, "field": {"kind": "radial"}}
    path = export_glb(baked.mesh, tmp_path / "meta.glb", metadata=meta)
    got = read_glb_metadata(path)
    assert got["block"] == meta["block"] and got["field"] == meta["field"]
    assert got["units"] == "mm"
    plain = export_glb(baked.mesh, tmp_path / "plain.glb")
    assert read_glb_metadata(plain) == {"units": "mm", "frame": "block"}


def test_export_errors_are_clear(baked, tmp_path):
    with pytest.raises(WoodcamError, match="path must end in .glb"):
        export_glb(baked.mesh, tmp_path / "x.obj")
    with pytest.raises(WoodcamError, match="path must end in .obj"):
        export_obj(baked.mesh, tmp_path / "x.glb")
    with pytest.raises(WoodcamError, match="metadata must be JSON-serialisable"):
        export_glb(baked.mesh, tmp_path / "x.glb", metadata={"a": object()})
    with pytest.raises(WoodcamError, match="mesh must carry a texture"):
        export_glb(trimesh.creation.box(), tmp_path / "x.glb")
    with pytest.raises(WoodcamError, match="is not a glTF 2.0 binary"):
        (tmp_path / "bad.glb").write_bytes(b"\0" * 32)
        read_glb_metadata(tmp_path / "bad.glb")
    with pytest.raises(WoodcamError, match="no file at"):
        load_textured(tmp_path / "missing.glb")


def _validate(path: Path) -> dict:
    node = shutil.which("node")
    if node is None:
        pytest.skip("node is not installed; the Khronos glTF validator runs on node")
    if not (_NODE_MODULES / "gltf-validator").is_dir():
        pytest.skip(
            f"npm package gltf-validator missing under {_NODE_MODULES}; install with "
            "npm install --prefix .cache/node gltf-validator (make test does)"
        )
    run = subprocess.run(
        [node, str(_VALIDATOR_JS), str(path)],
        capture_output=True, text=True, timeout=120,
        env={**os.environ, "NODE_PATH": str(_NODE_MODULES)},
    )
    assert run.returncode == 0, run.stderr
    return json.loads(run.stdout)


@pytest.mark.parametrize("normals", ["face", "smooth"])
def test_glb_passes_the_khronos_validator(baked, tmp_path, normals):
    if normals == "face":
        mesh = baked.mesh  # no NORMAL attribute: viewers shade flat
    else:
        sphere = trimesh.creation.icosphere(subdivisions=2, radius=10.0)
        mesh = bake(sphere, _Wood(), texels_per_mm=2.0, normals="smooth").mesh  # with NORMAL
    path = export_glb(mesh, tmp_path / "valid.glb", metadata={"block": {"size_mm": [30, 20, 16]}})
    report = _validate(path)
    issues = report["issues"]
    errors = [m for m in issues["messages"] if m["severity"] == 0]
    assert issues["numErrors"] == 0, errors
    assert issues["numWarnings"] == 0, issues["messages"]
    info = report["info"]
    assert info["materialCount"] == 1 and info["hasTextures"]
