"""Block specs: built-in blocks, blocks cut through a knot of a log, clear errors."""

import numpy as np
import pytest

from woodcam.errors import WoodcamError
from woodcam.fields import block_at_knot, read_gran1
from woodcam.stock import open_stock


def test_builtin_spec_and_species_override():
    s = open_stock("builtin:rift", species="walnut")
    assert s.size_mm == (100.0, 80.0, 50.0) and s.meta["species"] == "walnut"
    assert s.meta["field"]["type"] == "radial"


def test_log_spec_puts_the_knot_on_the_front_face(shared_data):
    s = open_stock("log:gran1@52:60x40x30")
    assert s.size_mm == (60.0, 40.0, 30.0)
    # Front-face centre is on knot 52's axis: the knot feature is ~1 there, ~0 at the corners.
    f = s.wood.field.knot_features(np.array([[30.0, 0.0, 15.0], [1.0, 0.0, 1.0]]))
    assert f["knot"][0] > 0.9 and f["knot"][1] < 0.1
    log = read_gran1(shared_data / "trees")
    assert len(log.knots) == 108 and block_at_knot(log, 52, (60, 40, 30))[1].shape == (3, 3)


@pytest.mark.parametrize("spec, message", [
    ("log:gran1", "must read 'log:LOG@KNOT'"),
    ("log:gran1@x", "must read 'log:LOG@KNOT'"),
    ("log:gran1@1:10x10", "must read 'log:LOG@KNOT'"),
    ("log:/nowhere/log.json@1", "does not exist"),
    ("mystery", "neither 'builtin:NAME'"),
])
def test_bad_specs(spec, message):
    with pytest.raises(WoodcamError, match=message):
        open_stock(spec)
