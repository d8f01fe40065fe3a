"""Round trip of the seed's image encoding of a log (stem map + three knot maps)."""

import json

import numpy as np
import pytest

from woodcam.errors import WoodcamError
from woodcam.fields.knots import KnottedLogField
from woodcam.logs.maps import decode_maps, encode_maps, read_maps, write_maps


def _check_round_trip(log, back, params):
    h, r_min, r_max = params["height_mm"], params["r_min_mm"], params["r_max_mm"]
    # stem: pith within half an 8-bit step of r_min, radii within a step of (r_max - r_min)
    z = np.linspace(log.pith_z_mm[0], log.pith_z_mm[-1], 97)
    assert np.max(np.abs(back.pith_at(z) - log.pith_at(z))) < r_min / 255 * 0.5 + 0.3
    az = np.linspace(0, 2 * np.pi, 50, endpoint=False)
    zz, aa = np.meshgrid(z, az)
    err = np.abs(back.radius_at(zz.ravel(), aa.ravel()) - log.radius_at(zz.ravel(), aa.ravel()))
    # one quantisation step plus the resampling of a bumpy measured surface (512 x 128)
    assert np.median(err) < (r_max - r_min) / 255
    assert len(back.knots) == len(log.knots)
    col = r_max / 127
    dstep = params["diameter_max_mm"] / 255
    for a, b in zip(log.knots, back.knots):
        assert abs(a.z0_mm - b.z0_mm) <= h / 255 * 0.5 + 1e-6
        assert abs(np.angle(np.exp(1j * (a.azimuth0_rad - b.azimuth0_rad)))) <= np.pi / 255 + 1e-6
        assert abs(a.r_death_mm - b.r_death_mm) <= r_max / 255 * 0.5 + 1e-6
        assert abs(min(a.r_end_mm, r_max) - b.r_end_mm) <= col + 1e-6
        r = np.linspace(5, min(a.r_end_mm, b.r_end_mm) - 1, 20)
        za, wa = a.axis_at(r)
        zb, wb = b.axis_at(r)
        assert np.max(np.abs((za - a.z0_mm) - (zb - b.z0_mm))) <= r_min / 255 + 0.5
        assert np.max(np.abs((wa - a.azimuth0_rad) - (wb - b.azimuth0_rad))) <= np.pi / 255 + 0.01
        assert np.max(np.abs(a.diameter_at(r) - b.diameter_at(r))) <= dstep + 0.3


def test_round_trip_of_the_real_log(gran1, tmp_path):
    paths = write_maps(gran1, tmp_path)
    assert {p.name for p in paths.values()} == {"stem_map.png", "knot_height_map.png",
                                                 "knot_orientation_map.png", "knot_state_map.png",
                                                 "map_params.json"}
    back = read_maps(tmp_path)
    params = json.loads(paths["params"].read_text())
    assert params["n_knots"] == 108
    _check_round_trip(gran1, back, params)
    # the field of the decoded log: same rings away from the knots up to quantisation
    # (measured: clear wood 0.07 / 0.24 / 0.89 years at the 50th / 90th / 99th percentile; in
    # and near knots the 8-bit knot axes move knot edges by a millimetre, and a point that
    # changes sides jumps by decades: the tail is knots, asserted separately)
    f, g = KnottedLogField(gran1), KnottedLogField(back)
    rng = np.random.default_rng(0)
    p = rng.uniform([-100, -100, 100], [100, 100, 3800], (5000, 3))
    ef, eg = f.evaluate(p), g.evaluate(p)
    d = np.abs(ef["years"] - eg["years"])
    clear = (ef["knot"] < 0.01) & (eg["knot"] < 0.01)
    assert clear.mean() > 0.95
    p50, p90, p99 = np.percentile(d[clear], [50, 90, 99])
    assert p50 < 0.1 and p90 < 0.3 and p99 < 1.0, (p50, p90, p99)   # years, ring width 2 mm
    assert np.percentile(d, 95) < 0.5
    ka, kb = ef["knot"] > 0.5, eg["knot"] > 0.5
    assert ka.sum() >= 30 and (ka & kb).sum() >= 0.6 * ka.sum()      # knots stay where they were


def test_round_trip_in_memory_and_clockwise_columns(gran1):
    log = gran1.with_knots(gran1.knots[:10])
    maps, params = encode_maps(log, clockwise=True, row_height=3)
    assert maps["stem"].shape == (512, 128, 3) and maps["height"].shape == (30, 128, 3)
    _check_round_trip(log, decode_maps(maps, params), params)


def test_maps_without_diameter_channel_and_list_params(gran1):
    # the seed tool's own maps: no B channel in the state map, params as a 4-list
    log = gran1.with_knots(gran1.knots[:3])
    maps, params = encode_maps(log)
    maps["state"][:, :, 2] = 0
    back = decode_maps(maps, [params["r_min_mm"], params["r_max_mm"], params["height_mm"], 3])
    assert all(k.r_end_mm == pytest.approx(params["r_max_mm"]) for k in back.knots)
    assert all(k.diameter_at([100.0])[0] > 5 for k in back.knots)


def test_missing_maps_are_named(tmp_path):
    with pytest.raises(WoodcamError, match="knot_state_map.png") as err:
        read_maps(tmp_path)
    # and how to make one (sweep h6: the folder's lack alone was said)
    assert "write such a folder with 'woodcam log maps (LOG_FILE | --real) --out DIR'" in str(err.value)
    with pytest.raises(WoodcamError, match="height_mm"):
        decode_maps({}, {"r_min_mm": 1, "r_max_mm": 2})


def test_the_written_maps_hold_the_documented_layout(tmp_path):
    """The PNGs themselves, read with PIL, against the layout of woodcam.logs.maps on a log
    whose numbers are known: row 0 the butt end, columns counter-clockwise from +x, a
    counter-clockwise twist in G (an encoder and a decoder that both turned the columns the
    other way, or both put the top end in row 0, agreed with each other, not with the seed's
    files)."""
    from PIL import Image

    from woodcam.fields.skeleton import BranchStrand, LogSkeleton

    z = np.arange(0.0, 401.0, 10.0)                       # a 400 mm log
    az = 2 * np.pi * np.arange(36) / 36
    radii = 100 + 10 * np.sin(az)[None, :] + 0.05 * z[:, None]  # 90..130 mm, widest at +y, top
    pith = np.stack([np.linspace(-5, 5, len(z)), np.zeros(len(z))], 1)
    r = np.array([0.0, 50.0, 120.0])
    knot = BranchStrand(100.0, np.pi / 2, r, [0.0, 10.0, 20.0], [0.0, 0.3, 0.6],
                        [5.0, 15.0, 25.0], 120.0, 120.0)
    write_maps(LogSkeleton(z, pith, radii, (knot,)), tmp_path)
    png = {k: np.asarray(Image.open(tmp_path / f)).astype(int)
           for k, f in (("stem", "stem_map.png"), ("height", "knot_height_map.png"),
                        ("orientation", "knot_orientation_map.png"))}
    stem = png["stem"]
    rows, cols = stem.shape[:2]
    zi = np.arange(rows) * 400.0 / (rows - 1)
    om = 2 * np.pi * np.arange(cols) / cols
    want = np.rint((100 + 10 * np.sin(om)[None, :] + 0.05 * zi[:, None] - 90) / 40 * 255)
    assert np.abs(stem[:, :, 2] - want).max() <= 1     # B: outer radius over [r_min, r_max]
    assert stem[0, cols // 4, 2] > stem[0, 3 * cols // 4, 2] + 100   # +y wide, -y narrow
    # R: pith x minus the pith at mid-length over [-r_min/2, r_min/2]: -5 mm at the butt end
    assert stem[0, 0, 0] == round(40 / 90 * 255) and stem[-1, 0, 0] == round(50 / 90 * 255)
    assert (stem[:, :, 1] == 128).all()                 # G: pith y = 0 (127.5 rounds to even)
    h, o = png["height"][0], png["orientation"][0]
    assert (h[:, 0] == round(100 / 400 * 255)).all()    # R: start height over [0, h]
    assert (o[:, 0] == round(0.25 * 255)).all()         # R: start azimuth pi/2 over [0, 2 pi)
    d = np.arange(len(h)) * 130.0 / (len(h) - 1)       # columns: pith distance over [0, r_max]
    assert np.abs(h[:, 1] - np.rint(np.interp(d, r, [0, 10, 20]) / 90 * 255)).max() <= 1
    assert (h[:, 2] == 0).all()                         # the knot rises: no fall in B
    assert np.abs(o[:, 1] - np.rint(np.interp(d, r, [0, 0.3, 0.6]) / (np.pi / 2) * 255)).max() <= 1
    assert (o[:, 2] == 0).all()                         # the twist is counter-clockwise: G, not B


def test_a_log_without_knots_writes_and_reads_back_its_maps(tmp_path):
    """'woodcam log maps' of a knotless log was an internal error ("cannot write empty image":
    its knot maps had no row), after writing the stem map alone (sweep h6)."""
    from woodcam.fields.skeleton import simple_log

    log = simple_log(300.0, 80.0)
    write_maps(log, tmp_path / "m")
    back = read_maps(tmp_path / "m")
    assert back.knots == ()
    assert back.r_min_mm == pytest.approx(80.0, abs=0.5) and back.length_mm == pytest.approx(300.0)


@pytest.mark.parametrize("params, said", [
    ("{", "must be valid JSON"),                                    # was json's bare JSONDecodeError
    ('{"r_min_mm": NaN, "r_max_mm": 143, "height_mm": 3990}', "finite numbers"),
    ("5", "must be a JSON object"),                                  # was TypeError, an internal error
    ('{"r_min_mm": "a", "r_max_mm": 1, "height_mm": 1}', "r_min_mm must be a finite number > 0; got 'a'"),
    ('{"r_min_mm": 104, "r_max_mm": 143, "height_mm": 0}', "height_mm must be a finite number > 0"),
    ('{"r_min_mm": 104, "r_max_mm": 90, "height_mm": 400}', "r_max_mm must be a finite number >= 104"),
    ('{"r_min_mm": 104, "r_max_mm": 143, "height_mm": 400, "row_height": 0}', "row_height must be an integer >= 1"),
    ('{"r_min_mm": 104, "r_max_mm": 143, "height_mm": 400, "pith_mid_xy_mm": [1]}',
     "pith_mid_xy_mm must be 2 finite numbers; got [1]"),             # was read as (1, 1) without a word
])
def test_a_malformed_map_params_file_is_an_error_naming_the_folder_and_the_value(tmp_path, params, said):
    """'woodcam log render --maps DIR' with a damaged map_params.json was an internal error
    (JSONDecodeError; TypeError for a number; ZeroDivisionError for row_height 0), a NaN or a
    zero height the log's own error about its pith samples, and a one-number pith_mid_xy_mm was
    read as both coordinates (sweep h4)."""
    from woodcam.fields.skeleton import simple_log

    write_maps(simple_log(300.0, 80.0), tmp_path / "m")
    (tmp_path / "m" / "map_params.json").write_text(params)
    with pytest.raises(WoodcamError) as err:
        read_maps(tmp_path / "m")
    assert said in str(err.value) and str(tmp_path / "m") in str(err.value), err.value


def test_a_damaged_map_image_is_an_error_naming_it(tmp_path):
    """A map PNG that is no image was PIL's 'cannot identify image file', which the CLI's
    generic handler told to 'check the path, its permissions and the free space' (sweep h4)."""
    from woodcam.fields.skeleton import simple_log

    write_maps(simple_log(300.0, 80.0), tmp_path / "m")
    (tmp_path / "m" / "stem_map.png").write_text("garbage")
    with pytest.raises(WoodcamError, match=r"cannot decode the image stem_map.png .*'woodcam log maps"):
        read_maps(tmp_path / "m")
