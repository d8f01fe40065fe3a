"""The demo's overview picture (woodcam.demo.render_overview)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
from PIL import Image

import woodcam.view
from woodcam.demo import render_overview


def test_the_overview_tiles_are_drawn_outside_the_out_folder(tmp_path, monkeypatch):
    """Each part's tile was drawn as <out>/_<part>_tile.png and deleted: a file of the user's of
    that name there was written over and deleted, and a run stopped between the two left one."""
    drawn = []

    def fake_preview(glb, *, screenshot, window_size, cut_plane):
        drawn.append(screenshot)
        Image.fromarray(np.full((window_size[1], window_size[0], 3), 200, np.uint8)).save(screenshot)

    monkeypatch.setattr(woodcam.view, "preview", fake_preview)
    mine = tmp_path / "_bowl_tile.png"
    mine.write_bytes(b"the user's own file")
    parts = [SimpleNamespace(name=n, files={"glb": tmp_path / f"{n}.glb"}) for n in ("bowl", "lid")]
    out = render_overview(parts, tmp_path / "demo.png", tile_px=(16, 12))
    with Image.open(out) as im:
        assert im.size == (32, 12)
    assert mine.read_bytes() == b"the user's own file"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["_bowl_tile.png", "demo.png"]
    assert all(tmp_path not in d.parents for d in drawn)
