"""``open_stock(spec, appearance="neural")``: built-in blocks learn from rendered photos; folders
without photos fall back to the colour map with a clear warning."""

import numpy as np
import pytest

from woodcam.appearance import ColorMapAppearance
from woodcam.appearance.neural import AppearanceFallbackWarning, NeuralAppearance
from woodcam.block import Block, Face
from woodcam.block.io import write_block
from woodcam.errors import WoodcamError, WoodcamWarning
from woodcam.fields import LogFrame
from woodcam.fields.radial import RadialScalingField
from woodcam.stock import open_stock


def test_unknown_appearance_is_refused():
    with pytest.raises(WoodcamError, match=r"appearance must be one of \['colormap', 'neural'\]"):
        open_stock("builtin:rift", appearance="photoreal")


def test_block_folder_without_photos_falls_back(tmp_path):
    field = RadialScalingField(LogFrame((-40.0, 20.0, 0.0), (0, 0, 1)), ring_width_mm=3.0)
    ring = np.zeros((8, 8), np.float32)
    block = Block((20, 20, 20), faces={"top": Face("top", (8, 8), ring_map=ring)}, true_field=field,
                  name="no-photos")
    write_block(block, tmp_path / "b")
    with pytest.warns(AppearanceFallbackWarning, match="no face photos"):
        stock = open_stock(str(tmp_path / "b"), appearance="neural")
    assert isinstance(stock.wood.appearance, ColorMapAppearance)


def test_a_fallback_names_the_neural_settings_it_ignores_and_records_the_colour_map(tmp_path):
    field = RadialScalingField(LogFrame((-40.0, 20.0, 0.0), (0, 0, 1)), ring_width_mm=3.0)
    block = Block((20, 20, 20), faces={"top": Face("top", (8, 8), ring_map=np.zeros((8, 8), np.float32))},
                  true_field=field, name="no-photos")
    write_block(block, tmp_path / "b")
    # --epochs and --quality were dropped without a word, and a GLB recorded "neural" with them
    with pytest.warns(AppearanceFallbackWarning, match=r"--quality draft, --epochs 5 \(neural training "
                      r"settings\) have no effect"):
        stock = open_stock(str(tmp_path / "b"), appearance="neural", quality="draft", epochs=5)
    assert isinstance(stock.wood.appearance, ColorMapAppearance)
    assert stock.meta["appearance"] == "colormap" and stock.meta["appearance_params"] == {}


def test_species_with_the_neural_appearance_warns_that_it_changes_nothing():
    # the neural volumes take every colour from the photos: --species walnut was dropped silently
    with pytest.warns(WoodcamWarning, match="--species walnut: the neural appearance learns every colour"):
        stock = open_stock("builtin:quarter-sawn:20x20x20", appearance="neural", species="walnut",
                           resolution=8, epochs=1, quality="draft", cache_dir=False, progress=False)
    assert isinstance(stock.wood.appearance, NeuralAppearance)


@pytest.mark.slow
def test_builtin_block_gets_neural_volumes(tmp_path):
    stock = open_stock("builtin:quarter-sawn", appearance="neural", resolution=32, quality="draft",
                       cache_dir=tmp_path, progress=False)
    app = stock.wood.appearance
    assert isinstance(app, NeuralAppearance) and app.volumes.volumes.shape[0] == 3
    assert stock.meta["appearance"] == "neural" and stock.meta["appearance_key"] == app.meta["key"]
    p = np.random.default_rng(0).uniform(0, 1, (100, 3)) * np.asarray(stock.size_mm)
    rgb = stock.wood.color(p, np.tile([0.0, 0.0, 1.0], (100, 1)))
    assert rgb.shape == (100, 3) and 0.2 < rgb.mean() < 0.95
