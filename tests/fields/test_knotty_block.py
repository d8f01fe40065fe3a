"""A block cut through a real knot: placement in the log and a carved part that shows it."""

import numpy as np
import pytest

from woodcam.fields.knots import KnottedLogField, block_at_knot, place_block_in_log


def test_block_front_face_is_centred_on_the_knot(gran1):
    f = KnottedLogField(gran1)
    size = (60.0, 50.0, 100.0)
    origin, R = block_at_knot(gran1, 52, size)
    pf = place_block_in_log(f, origin, R)
    # the knot's axis crosses the front face (Y = 0) at its centre; deeper in the block it is
    # where the data puts it (knot axis point at 25 mm less from the pith)
    front_r = min(gran1.knots[52].r_end_mm, gran1.r_min_mm) - 10.0
    mid = R.T @ (gran1.knot_point(52, [front_r - 25.0])[0] - origin)
    assert 20.0 < mid[1] < 30.0
    front = pf.evaluate(np.array([[30.0, 0.0, 50.0], mid, [5.0, 0.0, 5.0]]), directions=True)
    assert front["knot"][0] > 0.9 and front["knot"][1] > 0.9 and front["knot"][2] < 0.05
    # fibres inside the knot run through the block's depth (the knot axis ~ block Y)
    assert abs(front["direction"][0] @ [0, 1, 0]) > 0.9
    # away from the knot, fibres run along block Z (the log axis)
    assert abs(front["direction"][2] @ [0, 0, 1]) > 0.99


def test_carved_part_shows_the_knot(gran1):
    m3 = pytest.importorskip("manifold3d")
    f = KnottedLogField(gran1)
    origin, R = block_at_knot(gran1, 52, (60.0, 50.0, 100.0))
    pf = place_block_in_log(f, origin, R)
    box = m3.Manifold.cube((56.0, 46.0, 96.0)).translate((2.0, 2.0, 2.0))
    hole = m3.Manifold.cylinder(100.0, 10.0, circular_segments=48).rotate((0.0, 90.0, 0.0))
    part = box - hole.translate((-20.0, 25.0, 82.0))
    mesh = part.refine(40).to_mesh()
    v = np.asarray(mesh.vert_properties)[:, :3]
    feats = pf.knot_features(v)
    front = np.abs(v[:, 1] - 2.0) < 1e-6
    near = front & (np.hypot(v[:, 0] - 30.0, v[:, 2] - 50.0) < 8.0)
    far = front & (np.hypot(v[:, 0] - 30.0, v[:, 2] - 50.0) > 25.0)
    assert near.sum() > 10 and far.sum() > 10
    assert np.all(feats["knot"][near] > 0.8)         # knot wood where the knot crosses
    assert np.all(feats["knot"][far] < 0.2)          # clear wood elsewhere on that face


def test_a_point_past_the_bound_in_the_log_is_quoted_as_the_caller_gave_it():
    """A block-frame point within the 1 km bound that lands past it in the log frame (the
    knotty block's log origin sits 95 mm across its x) was refused by the log field's own
    door, quoting the log-frame point [95.0, -1000040.0, 315.7] and telling the caller, who
    gave block-frame points, to 'pass block-frame points'. Now the placement refuses it,
    quoting the block-frame point given, naming both frames; a log field called directly is
    told to pass log-frame points."""
    from woodcam.errors import WoodcamError
    from woodcam.fields import builtin_block

    field = builtin_block("knotty").field
    pts = np.array([[10.0, 20.0, 5.0], [-999990.0, 0.0, 0.0]])
    for call in (field, field.grain_direction, field.knot_features, field.evaluate):
        with pytest.raises(WoodcamError) as err:
            call(pts)
        msg = str(err.value)
        assert msg.startswith("points_mm (block frame) must lie, placed in the log, within 1e+06 mm"), msg
        assert "point 1 is [-999990.0, 0.0, 0.0] in the block frame, [95.0, -1000040.0, 315.685] in the log " \
               "frame" in msg, msg
    assert np.isfinite(field(pts[:1])).all()
    with pytest.raises(WoodcamError, match=r"point 0 is \[2000000.0, 0.0, 0.0\]; pass log-frame points in mm"):
        field.log_field(np.array([[2e6, 0.0, 0.0]]))
