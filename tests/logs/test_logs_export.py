"""GLB and heightmap PNG of a generated log."""

import numpy as np
import pytest
import trimesh

from woodcam.errors import WoodcamError
from woodcam.logs.export import (DEAD_KNOT_RGBA, LIVE_KNOT_RGBA, export_log_glb, heightmap_image, heightmap_png,
                                 knots_mesh, read_heightmap_png, surface_mesh)
from woodcam.logs.generate import generate_log


@pytest.fixture(scope="module")
def log():
    return generate_log(4, length_mm=1200.0)


def test_surface_mesh_is_closed_and_has_the_log_volume(log):
    m = surface_mesh(log, max_rows=241, max_cols=360)
    assert m.is_watertight and m.is_winding_consistent
    # volume = integral of R^2/2 dtheta dl on the heightmap (trapezoid along l, polygon area)
    l, t = log.axes
    R = log.heightmap_mm
    poly_area = 0.5 * np.sum(R * np.roll(R, -1, axis=1), axis=1) * np.sin(2 * np.pi / R.shape[1])
    vol = np.trapezoid(poly_area, l)
    assert m.volume == pytest.approx(vol, rel=2e-3)
    assert m.bounds[0, 2] == 0.0 and m.bounds[1, 2] == pytest.approx(1200.0)


def test_glb_round_trip_holds_surface_and_coloured_knots(log, tmp_path):
    p = export_log_glb(log, tmp_path / "log.glb", surface_alpha=0.4)
    scene = trimesh.load(p)
    assert set(scene.geometry) == {"surface", "knots"}
    knots = scene.geometry["knots"]
    assert len(knots.faces) == len(knots_mesh(log).faces)
    colours = {tuple(c) for c in np.unique(knots.visual.face_colors, axis=0)}
    assert tuple(LIVE_KNOT_RGBA) in colours and tuple(DEAD_KNOT_RGBA) in colours
    # knots stay inside the log's length (with the knots' own radius as slack)
    assert knots.bounds[0, 2] > -40 and knots.bounds[1, 2] < 1240
    # glTF's conventions: metres and +Y up, so the 1200 mm log stands 1.2 units tall (it lay
    # 1200 units long along +Z, a 1.2 km log on its side); the extras are not nested twice
    lo, hi = scene.bounds
    assert lo[1] == pytest.approx(0.0, abs=1e-9) and hi[1] == pytest.approx(1.2, rel=1e-6)
    assert hi[0] - lo[0] < 0.5 and hi[2] - lo[2] < 0.5
    assert scene.metadata.get("units") == "mm" and "extras" not in scene.metadata
    # the asset names woodcam, as export_glb's do (it named trimesh, which serialised it)
    import woodcam
    from woodcam.export import glb_json

    asset = glb_json(p.read_bytes(), "log.glb")["asset"]
    assert asset == {"version": "2.0", "generator": f"woodcam {woodcam.__version__}"}


def test_heightmap_png_decodes_back_to_mm(log, tmp_path):
    p = heightmap_png(log, tmp_path / "hm.png")
    back = read_heightmap_png(p)
    span = log.heightmap_mm.max() - log.heightmap_mm.min()
    np.testing.assert_allclose(back, log.heightmap_mm, atol=span / 65535)
    # the file itself stands like the log: its row 0 is the top (l = length), grey 0 and 65535
    # the range's ends in its text chunk (a writer and a reader that both skipped the flip, or
    # both flipped twice, agreed with each other, not with the picture)
    from PIL import Image

    with Image.open(p) as im:
        lo, hi = map(float, im.text["woodcam:range_mm"].split())
        grey = np.asarray(im, dtype=float)
    assert (lo, hi) == pytest.approx((log.heightmap_mm.min(), log.heightmap_mm.max()), abs=1e-5)
    np.testing.assert_allclose(lo + grey / 65535 * (hi - lo), log.heightmap_mm[::-1],
                               atol=span / 65535 + 1e-5)
    assert abs(log.heightmap_mm[0].mean() - log.heightmap_mm[-1].mean()) > 100 * span / 65535
    img, (lo, hi) = heightmap_image(log, "detail")
    assert lo == -hi and img.min() >= 0 and img.max() <= 1


def test_exports_refuse_wrong_suffixes_and_modes(log, tmp_path):
    with pytest.raises(WoodcamError, match="must end in .glb"):
        export_log_glb(log, tmp_path / "log.gltf")
    with pytest.raises(WoodcamError, match="must end in .png"):
        heightmap_png(log, tmp_path / "hm.jpg")
    with pytest.raises(WoodcamError, match="mode must be 'height' or 'detail'"):
        heightmap_image(log, "relief")
    with pytest.raises(WoodcamError, match="surface_alpha must lie in"):
        export_log_glb(log, tmp_path / "log.glb", surface_alpha=0.0)


@pytest.mark.parametrize("alpha", [1.0, 0.4])
def test_log_glb_passes_the_khronos_validator_without_hints(log, tmp_path, alpha, gltf_validate):
    """The log GLB's buffer views named no GL target: the Khronos validator hinted
    BUFFER_VIEW_TARGET_MISSING on each of them, where the bake's GLB (export_glb) has none."""
    issues = gltf_validate(export_log_glb(log, tmp_path / "log.glb", surface_alpha=alpha))["issues"]
    assert issues["numErrors"] == 0 and issues["numWarnings"] == 0, issues["messages"]
    assert not [m for m in issues["messages"] if m["code"] == "BUFFER_VIEW_TARGET_MISSING"], issues["messages"]
    assert issues["numHints"] == 0, issues["messages"]
