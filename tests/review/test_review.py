"""The one-file review page, loaded in headless Chromium from file:// with no network: the GLB
stands upright at its real size in three.js, and the section cap shows the wood inside."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
import trimesh
from PIL import Image
from scipy.ndimage import map_coordinates

from woodcam.bake import bake
from woodcam.errors import WoodcamError
from woodcam.export import export_glb
from woodcam.review import colour_volume, volume_cell_mm, write_review
from woodcam.stock import open_stock

#: The page shows the colour volume's trilinear sample: swiftshader's 8-bit texture filtering
#: and blending stay within a level (measured max 0.57/255).
CAP_VS_VOLUME_TOL = 1.5 / 255
#: ... and the volume is Wood.color on ~1 mm voxels: oak's rays and flecks blur (measured median
#: 6.9/255, 90th percentile 29/255 on builtin:flat-sawn).
CAP_VS_WOOD_MEDIAN_TOL = 12 / 255
#: The page may hold 3 MB besides the part's GLB (issue 16).
PAGE_BUDGET_BYTES = 3 * 2**20

_CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--use-angle=swiftshader",
                   "--enable-unsafe-swiftshader", "--disable-background-networking",
                   "--disable-component-update", "--disable-sync", "--no-first-run",
                   "--virtual-time-budget=60000"]


def _chromium() -> str:
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        pytest.skip("Chromium is not installed (Debian package 'chromium'; make test installs it "
                    "when it runs as root with apt): the review page test needs a browser")
    return exe


def _run(args, tmp_path):
    run = subprocess.run([_chromium(), *_CHROMIUM_FLAGS, f"--user-data-dir={tmp_path / 'profile'}",
                          *args], capture_output=True, text=True, timeout=180,
                         env={**os.environ, "HOME": str(tmp_path)})
    assert run.returncode == 0, run.stderr[-2000:]
    return run.stdout


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("review")
    stock = open_stock("builtin:flat-sawn")
    box = trimesh.creation.box((80.0, 60.0, 40.0))
    box.apply_translation([50.0, 40.0, 25.0])
    glb = export_glb(bake(box, stock.wood, texels_per_mm=2.0).mesh, tmp / "box.glb",
                     metadata={"block": stock.spec})
    out = write_review(glb, tmp / "review.html", wood=stock.wood, size_mm=stock.size_mm,
                       report={"block spec": stock.spec},
                       hotspots=[{"kind": "knot", "label": "test", "at_mm": [50, 40, 25]}])
    return stock, glb, out, tmp


def test_the_page_is_one_offline_file_within_budget(page):
    _, glb, out, _ = page
    text = out.read_text()
    assert not re.search(r"""(src|href)=["']https?:""", text), "the page must not fetch anything"
    assert "import " not in text.split("<script>")[-1][:200]  # bundled, not ES-module imports
    assert out.stat().st_size - 4 / 3 * glb.stat().st_size <= PAGE_BUDGET_BYTES


def test_three_js_shows_the_glb_upright_in_metres_with_normals(page, tmp_path):
    _, _, out, _ = page
    dom = _run(["--dump-dom", f"file://{out}#bare"], tmp_path)
    assert "<title>box: ready</title>" in dom, dom[:500]
    probe = re.search(r'id="probe"[^>]*', dom).group(0)
    lo = np.array(re.search(r'data-bbox-min="([^"]+)"', probe).group(1).split(","), float)
    hi = np.array(re.search(r'data-bbox-max="([^"]+)"', probe).group(1).split(","), float)
    # block x 10..90, y 10..70, z 5..45 mm -> glTF x, y = z (up), z = -y, in metres
    np.testing.assert_allclose(lo, [0.010, 0.005, -0.070], atol=1e-6)
    np.testing.assert_allclose(hi, [0.090, 0.045, -0.010], atol=1e-6)
    assert int(re.search(r'data-meshes-with-normals="(\d+)"', probe).group(1)) >= 1


def test_the_section_cap_shows_the_wood_inside(page, tmp_path):
    """Front orthographic view, cut at y = 40 mm: pixel (c, r) of the 1000 x 500 screenshot is
    block point (x, 40, z) with x = (c + .5) / 10, z = 50 - (r + .5) / 10 mm."""
    stock, _, out, _ = page
    png = tmp_path / "front.png"
    _run(["--window-size=1000,500", f"--screenshot={png}",
          f"file://{out}#bare&ortho&view=front&cut=y:40"], tmp_path)
    img = np.asarray(Image.open(png).convert("RGB"), dtype=float) / 255
    W, D, H = stock.size_mm
    rng = np.random.default_rng(0)
    cols = rng.integers(120, 880, 300)  # inside the box's section x 10..90, z 5..45
    rows = rng.integers(70, 430, 300)
    x, z = (cols + 0.5) * W / 1000, H - (rows + 0.5) * H / 500
    y = np.full_like(x, 40.0)
    shown = img[rows, cols]
    vol = colour_volume(stock.wood, stock.size_mm, "y", volume_cell_mm(stock.size_mm)) / 255
    nz, ny, nx, _ = vol.shape
    coords = [z / H * nz - 0.5, y / D * ny - 0.5, x / W * nx - 0.5]
    trilinear = np.stack([map_coordinates(vol[..., k], coords, order=1, mode="nearest")
                          for k in range(3)], axis=1)
    assert np.abs(shown - trilinear).max() <= CAP_VS_VOLUME_TOL
    exact = stock.wood.color(np.column_stack([x, y, z]), np.tile([0.0, 1.0, 0.0], (len(x), 1)))
    assert np.median(np.abs(shown - exact).max(axis=1)) <= CAP_VS_WOOD_MEDIAN_TOL
    # outside the part the cut shows nothing (black background in the bare view)
    assert img[20, 20].max() < 0.05 and img[480, 980].max() < 0.05


def test_review_errors_are_clear(page, tmp_path):
    stock, glb, _, _ = page
    with pytest.raises(WoodcamError, match="must be an existing .glb"):
        write_review(tmp_path / "missing.glb", tmp_path / "r.html", wood=stock.wood,
                     size_mm=stock.size_mm)
    with pytest.raises(WoodcamError, match=r"\.html"):
        write_review(glb, tmp_path / "r.txt", wood=stock.wood, size_mm=stock.size_mm)


def test_the_cli_writes_the_page_from_the_glbs_own_block(page, tmp_path, capsys):
    from woodcam.cli import main

    _, glb, _, _ = page
    assert main(["review", str(glb), "--out", str(tmp_path / "r.html"), "--voxels", "20000"]) == 0
    assert "wrote" in capsys.readouterr().out and (tmp_path / "r.html").stat().st_size > 1e5
    assert Path(tmp_path / "r.html").read_text().count("data:image/png;base64,") == 3
