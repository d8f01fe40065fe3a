"""woodcam.view.section: the cut-plane geometry in pure numpy, checked without VTK."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from woodcam.errors import WoodcamError
from woodcam._checks import check_vector
from woodcam.view.section import box_section_uv, cut_segments, plane_basis, signed_row_distance

SIZE = np.array([100.0, 80.0, 40.0])
REPO = Path(__file__).resolve().parents[1]


def test_section_module_loads_no_vtk():
    code = ("import sys, woodcam.view.section\n"
            "print(sorted(m for m in sys.modules if m.split('.')[0] in ('pyvista', 'vtk', "
            "'vtkmodules', 'trimesh')))")
    res = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True,
                         check=False)
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip() == "[]"


@pytest.mark.parametrize("normal", [(1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 2, 3), (-1, 0.5, 0.2)])
def test_plane_basis_is_right_handed_and_orthonormal(normal):
    n = check_vector(normal, "normal", unit=True)
    u, v = plane_basis(n)
    np.testing.assert_allclose([u @ u, v @ v, u @ v, u @ n, v @ n], [1, 1, 0, 0, 0], atol=1e-12)
    np.testing.assert_allclose(np.cross(u, v), n, atol=1e-12)


def test_box_section_areas_match_closed_form():
    # A plane normal to Z through the block: the W x D rectangle.
    n = np.array([0.0, 0.0, 1.0])
    u, v = plane_basis(n)
    uv = box_section_uv(SIZE, np.array([50.0, 40.0, 10.0]), n, u, v)
    assert ConvexHull(uv).volume == pytest.approx(100 * 80)
    # A 45-degree plane through the X axis cuts a D * sqrt(2) x W rectangle while it stays
    # within the block's height (here D = 80 > H = 40, so it leaves through the top: H * sqrt(2)).
    n = check_vector((0, -1, 1), "n", unit=True)
    u, v = plane_basis(n)
    uv = box_section_uv(SIZE, np.array([0.0, 0.0, 0.0]), n, u, v)
    assert ConvexHull(uv).volume == pytest.approx(100 * 40 * np.sqrt(2))
    # A plane outside the block misses it.
    assert len(box_section_uv(SIZE, np.array([0.0, 0.0, 100.0]), np.array([0, 0, 1.0]), u, v)) == 0


def _cube(lo, hi):
    bits = (np.arange(8)[:, None] >> np.arange(3)[None, :]) & 1
    pts = np.asarray(lo) + bits * (np.asarray(hi) - np.asarray(lo))
    return pts.astype(float), ConvexHull(pts).simplices


def test_cut_segments_and_signed_distance_of_a_cube():
    pts, tri = _cube((20, 20, 10), (60, 50, 30))
    origin, n = np.array([0.0, 0.0, 20.0]), np.array([0.0, 0.0, 1.0])
    seg = cut_segments(pts, tri, origin, n)
    assert seg.shape[1:] == (2, 3)
    np.testing.assert_allclose(seg[..., 2], 20.0)
    assert np.linalg.norm(seg[:, 1] - seg[:, 0], axis=1).sum() == pytest.approx(2 * (40 + 30))
    u, v = plane_basis(n)
    ends = seg - origin
    seg_uv = np.stack([ends @ u, ends @ v], axis=-1)
    su, sv = np.linspace(0, 100, 201), np.linspace(0, 80, 161)   # u = X, v = Y here
    d = signed_row_distance(seg_uv, su, sv)
    # rows are half-open in v (a row on the lower edge is in, one on the upper edge out)
    inside = (su[:, None] > 20) & (su[:, None] < 60) & (sv[None, :] >= 20) & (sv[None, :] < 50)
    assert np.array_equal(d > 0, inside)
    # exact along u: the distance of a row inside the square to its nearest side
    j = np.searchsorted(sv, 35.0)
    np.testing.assert_allclose(d[:, j][inside[:, j]],
                               np.minimum(su - 20, 60 - su)[inside[:, j]], atol=1e-9)


def test_bad_vectors_are_named():
    with pytest.raises(WoodcamError, match="normal must be a non-zero direction"):
        check_vector((0, 0, 0), "normal", unit=True)
    with pytest.raises(WoodcamError, match="origin must be three finite numbers"):
        check_vector((0, 1), "origin", unit=False)
