"""The height-field preview: planar charts instead of a generic unwrap (issue 18, part 7)."""

from __future__ import annotations

import numpy as np
import pytest

from woodcam.pipeline import bake_heightfield
from woodcam.toolpath import parse_tool_spec, read_gcode, simulate
from woodcam.toolpath.mesh import HeightfieldCharts

W, D, H = 40.0, 30.0, 20.0


class _CoordWood:
    """Colour = the point's block-frame position scaled to [0, 1]: texels say where they are."""

    def color(self, points_mm, normals):
        return np.clip(np.asarray(points_mm) / np.array([W, D, H]), 0, 1)


@pytest.fixture(scope="module")
def sim():
    prog = read_gcode("G0 X10 Y10 Z5\nG1 Z-6 F300\nG2 X10 Y10 I6 J0\nG1 X30 Y20 Z-2\n"
                      "G0 Z5\nM2\n")
    return simulate(prog, parse_tool_spec("ball:4"), (W, D, H), resolution_mm=0.25)


def test_texels_sit_on_the_mesh_and_vertices_sample_their_own_colour(sim):
    tpm = 4.0
    b = bake_heightfield(sim.heightmap, sim.size_mm, _CoordWood(), texels_per_mm=tpm,
                         flat_tol_mm=0.01)
    mesh = b.mesh
    h, w = b.atlas.shape[:2]
    uv = np.asarray(mesh.visual.uv)
    px = np.clip((uv[:, 0] * w).astype(int), 0, w - 1)
    py = np.clip(((1 - uv[:, 1]) * h).astype(int), 0, h - 1)
    rgb = b.atlas[py, px] / 255.0
    want = np.asarray(mesh.vertices) / np.array([W, D, H])
    # a vertex's texel is within half a texel of it (0.125 mm at 4 texels/mm); the height moves
    # by at most the slope times that, and colours are quantised to 1/255
    err_mm = np.abs(rgb - want) * np.array([W, D, H])
    assert np.percentile(err_mm, 99, axis=0).max() < 1.0
    assert np.median(err_mm) < 0.2


def test_mesh_is_closed_with_the_heightfield_volume_and_unit_normals(sim):
    b = bake_heightfield(sim.heightmap, sim.size_mm, _CoordWood(), texels_per_mm=2.0)
    m = b.mesh.copy()
    m.merge_vertices(merge_tex=True, merge_norm=True)
    assert m.is_watertight
    volume = W * D * H - sim.removed_volume_mm3
    assert m.volume == pytest.approx(volume, rel=1e-9)
    n = np.asarray(b.mesh.vertex_normals)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-9)
    charts = sum(w * h for _, _, w, h, _, _ in
                 HeightfieldCharts(sim.heightmap, sim.size_mm, 2.0).charts.values())
    assert b.coverage_mask.sum() == charts  # every chart texel painted, padding only dilated


def test_density_is_lowered_to_fit_the_atlas(sim):
    with pytest.warns(UserWarning, match="lowered"):
        b = bake_heightfield(sim.heightmap, sim.size_mm, _CoordWood(), texels_per_mm=100.0,
                             max_atlas_px=1024)
    assert max(b.atlas.shape[:2]) <= 1024 and b.texels_per_mm < 100


def test_gutters_are_the_nearest_chart_texel_within_half_the_gap(sim):
    """The rectangles' gutter fill paints what the exact nearest-texel transform paints in
    the ring a bilinear or mip-mapped lookup of a chart reaches (3 texels)."""
    from scipy import ndimage

    from woodcam.bake import _dilate

    b = bake_heightfield(sim.heightmap, sim.size_mm, _CoordWood(), texels_per_mm=4.0)
    cov = b.coverage_mask
    raw = np.where(cov[..., None], b.atlas, 0).astype(np.uint8)
    exact = _dilate(raw, cov)
    ring = ndimage.binary_dilation(cov, iterations=3) & ~cov
    assert ring.sum() > 1000
    np.testing.assert_array_equal(b.atlas[ring], exact[ring])
    np.testing.assert_array_equal(b.atlas[cov], raw[cov])
    assert not (b.atlas == 0).all(axis=-1).any()  # no black texel left anywhere


def test_shading_normals_follow_the_faces_at_a_cuts_rim(tmp_path):
    """The top's shading normals were the grid's central differences, one per vertex: at a
    pocket's rim (and its floor's edge) the vertex normal leans half-way down the wall, so the
    flat top and floor beside it shaded as a slope (woodcam gcode pocket_islands.nc: 0.84 % of
    the GLB's area had a corner with normal . face normal < 0.5, profile_tabs.nc 5.8 %). Such
    corners get their own vertex with their side's normal now, in the GLB too; smooth regions
    (a ball cut) keep one vertex each."""
    import trimesh

    from woodcam.export import export_glb

    prog = read_gcode("G0 X10 Y8 Z5\nG1 Z-6 F300\nG1 X30\nG1 Y22\nG1 X10\nG1 Y8\nG0 Z5\n"
                      "G0 X20 Y15\nG1 Z-3\nG0 Z5\nM2\n")
    res = simulate(prog, parse_tool_spec("flat:6"), (W, D, H), resolution_mm=0.25)
    b = bake_heightfield(res.heightmap, res.size_mm, _CoordWood(), texels_per_mm=2.0)
    glb = export_glb(b.mesh, tmp_path / "cut.glb", normals="mesh")
    m = next(iter(trimesh.load(glb, process=False).geometry.values()))
    for mesh in (b.mesh, m):
        d = np.einsum("fkj,fj->fk", np.asarray(mesh.vertex_normals)[mesh.faces], mesh.face_normals)
        assert d.min() > 0.5, d.min()
    np.testing.assert_allclose(np.linalg.norm(m.vertex_normals, axis=1), 1.0, atol=1e-6)
    # the split corners sit where they did, with their texels
    welded = b.mesh.copy()
    welded.merge_vertices(merge_tex=True, merge_norm=True)
    assert welded.is_watertight
    assert welded.volume == pytest.approx(W * D * H - res.removed_volume_mm3, rel=1e-9)
    bowl = simulate(read_gcode("G0 X20 Y15 Z5\nG1 Z-6 F300\nG0 Z5\nM2\n"),
                    parse_tool_spec("ball:20"), (W, D, H), resolution_mm=0.25)
    plain = bake_heightfield(bowl.heightmap, bowl.size_mm, _CoordWood(), texels_per_mm=2.0)
    v = np.asarray(plain.mesh.vertices)
    # the bowl below its rim (not the block's walls and bottom): smooth, no vertex split
    inside = v[(v[:, 2] < H - 1.0) & (np.hypot(v[:, 0] - 20, v[:, 1] - 15) < 8)]
    assert len(inside) > 100 and len(np.unique(inside, axis=0)) == len(inside)
    assert len(v) - len(np.unique(v, axis=0)) > 50  # its rim's are
