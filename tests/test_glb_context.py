"""A baked GLB keeps its context: block (absolute, content-hashed), species, appearance
parameters and placement; preview/review rebuild the same wood from any folder (issue 17)."""

from __future__ import annotations

import os
import shutil

import numpy as np
import pytest
import trimesh

from woodcam.cli.options import stock_of_glb
from woodcam.errors import WoodcamError, WoodcamWarning
from woodcam.export import read_glb_metadata
from woodcam.pipeline import preview_mesh
from woodcam.stock import open_stock


def _bake_in(folder, spec, **stock_kw):
    stock = open_stock(spec, **stock_kw)
    box = trimesh.creation.box((20.0, 16.0, 10.0))
    box.apply_translation([15.0, 12.0, 8.0])
    res = preview_mesh(box, stock, folder / "part.glb", texels_per_mm=1.0, obj=False,
                       screenshot=False)
    return stock, res.files["glb"]


def _same_wood(a, b):
    p = np.random.default_rng(0).uniform(0.5, 25.0, (400, 3))
    n = np.tile([0.0, 0.0, 1.0], (len(p), 1))
    np.testing.assert_allclose(a.wood.color(p, n), b.wood.color(p, n), atol=1e-6)


# the species is recorded and reopened with the GLB; on this photographed block it changes no
# colour, which open_stock says in a warning
@pytest.mark.filterwarnings("ignore:--species walnut:woodcam.errors.WoodcamWarning")
def test_a_glb_baked_from_a_relative_block_folder_reopens_from_another_folder(tmp_path, monkeypatch):
    from woodcam.block.io import write_block
    from woodcam.fields.builtin import builtin_block
    from woodcam.synth import synth_block

    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    work, elsewhere = tmp_path / "work", tmp_path / "elsewhere"
    work.mkdir(), elsewhere.mkdir()
    block = synth_block(builtin_block("flat-sawn").field, (30, 25, 20), face_px=48, seed=0)
    write_block(block, work / "myblock")
    monkeypatch.chdir(work)
    from pathlib import Path

    stock, glb = _bake_in(Path("."), "myblock", species="walnut",
                          knot_darkening_alive=0.6, knot_darkening_dead=0.7)
    glb = glb.resolve()
    meta = read_glb_metadata(glb)
    assert os.path.isabs(meta["block"]) and meta["block_digest"]
    assert meta["appearance"]["species"] == "walnut"
    assert meta["appearance"]["params"]["knot_darkening_alive"] == 0.6
    monkeypatch.chdir(elsewhere)
    again = stock_of_glb(glb)
    assert again.meta["species"] == "walnut"  # not the block's default oak
    _same_wood(stock, again)
    # a file it reads changes: a warning (a notes.txt woodcam never reads leaves it as baked:
    # tests/test_stock.py::test_a_file_woodcam_does_not_read_leaves_a_block_folders_digest);
    # the folder is gone: an error naming it
    manifest = work / "myblock" / "block.json"
    manifest.write_text(manifest.read_text() + "\n")
    with pytest.warns(WoodcamWarning, match="changed since part.glb was baked"):
        stock_of_glb(glb)
    shutil.rmtree(work / "myblock")
    with pytest.raises(WoodcamError, match="which is not there any more; pass --block"):
        stock_of_glb(glb)
    # a preview without a cut plane needs only the baked texture and the recorded block size: it
    # was refused for the missing folder
    from woodcam.cli import main

    shown = {}
    monkeypatch.setattr("woodcam.view.preview", lambda mesh, **kw: shown.update(kw, mesh=mesh))
    assert main(["preview", str(glb), "--no-cut", "--screenshot", str(elsewhere / "p.png")]) == 0
    assert shown["size_mm"] == stock.size_mm and shown["cut_plane"] is False
    assert shown.get("wood") is None


def test_a_synthetic_block_keeps_its_species_and_turns(tmp_path):
    stock, glb = _bake_in(tmp_path, "builtin:flat-sawn~z90", species="cherry")
    again = stock_of_glb(glb)
    assert again.spec == "builtin:flat-sawn~z90" and again.size_mm == stock.size_mm
    assert again.meta["species"] == "cherry"
    _same_wood(stock, again)


def test_a_resized_block_is_not_the_block_a_glb_was_baked_from(tmp_path, glb_with):
    """Review h15 item 5: spec_digest digested only the spec's base, so --block
    'builtin:flat-sawn[40x30x20]' for a GLB baked from 'builtin:flat-sawn' was taken without the
    'is not the block' warning; the turns and resizes are part of the block's identity."""
    import warnings

    from woodcam.stock import spec_digest

    meta = {"block": "builtin:flat-sawn", "block_digest": spec_digest("builtin:flat-sawn"),
            "size_mm": [100.0, 80.0, 50.0]}
    glb = glb_with(meta, tmp_path / "tray.glb")
    for other in ("builtin:flat-sawn[40x30x20]", "builtin:flat-sawn~z90"):
        with pytest.warns(WoodcamWarning, match="is not the block tray.glb was baked from"):
            stock_of_glb(glb, other)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        stock_of_glb(glb, "builtin:flat-sawn")  # the same block: no word
